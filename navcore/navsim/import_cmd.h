/* navsim import / export: GPX, KML and motion-definition tracks in, KML and CSV tracks out
 * (see import_cmd.c). */
#ifndef NAVSIM_IMPORT_CMD_H
#define NAVSIM_IMPORT_CMD_H

#include <stdbool.h>

#include "navcore/nav_results.h"
#include "navcore/nav_scene.h"

/** Run `navsim import ARGS`; returns the process exit code. */
int navsim_import(int argc, char **argv);

/** Run `navsim export ARGS`; returns the process exit code. */
int navsim_export(int argc, char **argv);

/**
 * `navsim run --kml`: in the (temporary) result directory @p rd, whose truth.csv, nav.csv and
 * (INS/GNSS) gnss.csv are complete, write tracks.kml and tracks.csv, named after the final
 * directory @p out_dir (as navsim export names them). @return 0, or 1 after printing what failed.
 */
int navsim_run_tracks(nav_resultdir *rd, const char *out_dir);

#endif /* NAVSIM_IMPORT_CMD_H */
