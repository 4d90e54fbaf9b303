/*
 * Small helpers shared by the navsim commands: option words, number parsing, diagnostics on
 * stderr, wall clock, JSON text. One copy here instead of one per command file; the messages
 * they print are part of the navsim contract (tests/scenario/test_navsim_*.c).
 */
#ifndef NAVSIM_CLI_UTIL_H
#define NAVSIM_CLI_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "navcore/nav_io.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"

/* "-h" or "--help". */
bool navsim_is_help(const char *arg);

/* Monotonic wall clock [s] (for elapsed times only). */
double navsim_now_s(void);

/* Diagnostics sink for nav_diag_fn callbacks: navsim_print_diag prints each diagnostic on stderr
 * as one line (nav_diag_format), followed by " CONTEXT" when context is set, and counts it. */
typedef struct navsim_diag_sink {
  int count;
  const char *context; /* NULL: nothing appended */
} navsim_diag_sink;

/* nav_diag_fn: @p user is a navsim_diag_sink or NULL (print only). */
void navsim_print_diag(void *user, const nav_diag *d);

/* nav_scene_read_file with navsim_print_diag; "PATH: error: STATUS" on stderr when the reader
 * reported nothing. @return the exit code: 0 read, 2 invalid scene (NAV_ERR_PARSE), 1 otherwise. */
int navsim_load_scene(const char *path, nav_scene *scene);

/* For a recorded-reference scene (trajectory.type recorded): one line on @p f with the residuals
 * of its spline fit against the recorded samples (issue 25); nothing for other scenes. @p label
 * starts the line ("reference  " or "PATH: "). */
void navsim_print_recorded_fit(FILE *f, const char *label, const nav_scene *scene);

/* gnss.file of @p scene (none: EXIT_OK, nothing done): load the recorded fixes
 * (nav_gnss_file_load) and attach them to @p sim. Problems go to stderr as "CMD: FILE:LINE:COL:
 * ..."; returns EXIT_OK, 2 (a bad file) or 1. @p count receives the number of fixes (may be NULL). */
int navsim_attach_gnss_file(const char *cmd, const nav_scene *scene, nav_sim *sim, size_t *count);

/* gnss.file with a covariance analysis (estimate, budget): a warning on stderr that it uses the
 * receiver model's epochs and sigmas, not the file's fixes (docs/gnss-file.md). */
void navsim_warn_gnss_file_model(const char *cmd, const char *scene_path, const nav_scene *scene);

/* gnss.file: "LABEL<file> (N fixes, scene time = file time - T0 s; the file's sigmas ...)" on @p f. */
void navsim_print_gnss_file(FILE *f, const char *label, const nav_scene *scene);

/* Decimal digits only (no sign, no blanks), within uint64_t. */
bool navsim_parse_u64(const char *s, uint64_t *out);

/* The whole text is one finite number (strtod syntax). */
bool navsim_parse_double(const char *s, double *out);

/* A finite number > 0, or >= 0 with @p allow_zero. */
bool navsim_parse_positive(const char *s, double *out, bool allow_zero);

/* The whole text is one integer (strtol syntax) in [lo, hi]. */
bool navsim_parse_long(const char *s, long lo, long hi, long *out);

/* argv[i] is an option taking a value: true when argv[i + 1] exists, else prints
 * "navsim CMD: OPT needs a value" on stderr and returns false. */
bool navsim_need_value(const char *cmd, int argc, int i, const char *opt);

/* Prints "navsim CMD: unknown option "OPT" (see navsim CMD --help)" on stderr. @return 2. */
int navsim_unknown_option(const char *cmd, const char *opt);

/* A command-line word that no option of CMD took: "-X..." is an unknown option
 * (navsim_unknown_option), anything else the SCENE, of which only one may be given ("navsim CMD:
 * only one SCENE may be given"). @return 0 (stored in *scene) or the exit code 2. */
int navsim_scene_arg(const char *cmd, const char *arg, const char **scene);

/* @p name made safe as a file or directory name: characters other than [A-Za-z0-9._-] become
 * '_'; empty, "." or ".." become @p fallback. */
void navsim_safe_name(char *out, size_t cap, const char *name, const char *fallback);

/* The help text of --out and --force, shared by every command that writes a result directory. */
#define NAVSIM_OUT_HELP                                                                                    \
  "An existing --out DIR is replaced only when it is a result directory navsim wrote holding nothing\n"   \
  "else; a file, a symbolic link or any other directory is refused (exit 2) before any work.\n"           \
  "--force moves whatever is at DIR aside to DIR.old-YYYYmmddTHHMMSS instead (nothing is deleted).\n"

/* --out DIR of navsim CMD, checked before any work (nav_resultdir_check): 0 when DIR may receive
 * the result (absent, empty, or a result directory navsim wrote) or @p force is set and DIR
 * exists; else "navsim CMD: --out: WHAT IS THERE: HOW TO PROCEED" on stderr and the exit code
 * (2 refused, 1 cannot be examined). Nothing is created. */
int navsim_out_check(const char *cmd, const char *dir, bool force);

/* nav_resultdir_open with the same messages as navsim_out_check. @return 0 or the exit code. */
int navsim_out_begin(const char *cmd, const char *dir, bool force, nav_resultdir **rd);

/* nav_resultdir_commit_msg; prints "navsim CMD: MSG" on stderr when the commit failed or moved a
 * previous content aside. @return 0, or the exit code (2 when DIR stopped accepting the result
 * meanwhile: the result is kept beside it; 1 on I/O failure). */
int navsim_out_commit(const char *cmd, nav_resultdir *rd);

/* The files of a result directory that navsim and navview read (summary.json, truth.csv, nav.csv,
 * errors.csv, ...): each one that exists but is not a regular file (a FIFO, a device, a directory)
 * is reported as "DIR/NAME: error: cannot read the file: it is a FIFO (named pipe), not a regular
 * file", at once, before anything reads (a FIFO would block the reader).
 * @return 0 when there is none, else 2 (the exit code of invalid input). */
int navsim_refuse_special_result_files(const char *dir);

/* A JSON number with @p digits significant digits ("%.*g"); non-finite values print null. */
void navsim_json_number(FILE *f, double v, int digits);

#endif /* NAVSIM_CLI_UTIL_H */
