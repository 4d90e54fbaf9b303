/**
 * @file nav_io.h
 * @brief navcore_io: scene files (YAML) in and out, with precise error locations.
 *
 * Every problem found in a scene file is reported as one nav_diag, which formats as
 *   FILE:LINE:COL: error: <field path>: <what is wrong and what is expected>
 * Lines and columns are 1-based. Reading never crashes on bad input and never aborts at the
 * first problem: it reports every problem it can find (up to NAV_DIAG_MAX_PER_FILE).
 */
#ifndef NAV_IO_H
#define NAV_IO_H

#include <stddef.h>
#include <stdio.h>

#include "nav_export.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

#define NAV_DIAG_MAX_PER_FILE 100

/** One diagnostic about an input file. */
typedef struct nav_diag {
  char file[512];     /**< file name as given by the caller */
  int line;           /**< 1-based; 0 when the problem is not tied to a place (e.g. unreadable file) */
  int col;            /**< 1-based; 0 when line is 0 */
  char path[256];     /**< field path, e.g. "trajectory.parametric.C_hz[2]"; "" for the whole file */
  char message[512];  /**< what is wrong and what is expected */
} nav_diag;

/** Receives one diagnostic; @p d is valid only during the call. */
typedef void (*nav_diag_fn)(void *user, const nav_diag *d);

/** Format @p d as "FILE:LINE:COL: error: PATH: MESSAGE" into @p buf (always NUL-terminated). */
NAV_API void nav_diag_format(const nav_diag *d, char *buf, size_t size);

/**
 * Read and validate a scene file.
 * @param[in]  path    file to read
 * @param[out] out     the scene; written only on NAV_OK. It then owns the control points of a
 *                     recorded reference: release it with nav_scene_release() when done
 *                     (nav_scene.h; nothing to free for other trajectories, but always safe)
 * @param[in]  report  receives each diagnostic (may be NULL)
 * @param[in]  user    passed to @p report
 * @return NAV_OK; NAV_ERR_IO if the file cannot be read; NAV_ERR_PARSE if it is not a valid
 *         scene (at least one diagnostic was reported); NAV_ERR_INVALID_ARG for NULL arguments.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_read_file(const char *path, nav_scene *out, nav_diag_fn report,
                                                     void *user);

/**
 * As nav_scene_read_file, for a scene that is about to be simulated (navsim check, run, estimate,
 * budget, select, sweep): when the file states a trajectory, its requirements must also be
 * evaluable on the run (nav_requirements_check_scene: no at_time after the end, no outage_end
 * without an outage), each problem reported at the requirement's place. Without a trajectory
 * the file is a filter configuration (navsim replay --scene) and this check does not apply.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_read_file_to_run(const char *path, nav_scene *out, nav_diag_fn report,
                                                            void *user);

/** As nav_scene_read_file, from memory; @p display_name is used as FILE in diagnostics. */
NAV_API NAV_NODISCARD nav_status nav_scene_read_string(const char *text, size_t len, const char *display_name,
                                                       nav_scene *out, nav_diag_fn report, void *user);

/**
 * Write @p scene as a complete YAML scene file (current format_version, every field explicit, in
 * the units of the reader), atomically: a temporary file is written, flushed and renamed.
 * @return NAV_OK, NAV_ERR_IO, NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_write_file(const char *path, const nav_scene *scene);

/**
 * The text nav_scene_write_file would write for @p scene, in memory: to validate a scene exactly
 * as a file reader will see it (nav_scene_read_string) before anything is written.
 * @param[out] text NUL-terminated, malloc'd (the caller frees it); NULL on failure
 * @param[out] len  its length in bytes (may be NULL)
 * @return NAV_OK, NAV_ERR_NO_MEMORY, NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_write_string(const nav_scene *scene, char **text, size_t *len);

/**
 * Open @p path for reading, refusing at once anything that is not a regular file.
 *
 * A FIFO, a character or block device, a directory or a socket is refused without reading from
 * it and without blocking: the file is opened with O_NONBLOCK (a FIFO with no writer would
 * otherwise block the open), checked with fstat, and only a regular file is handed back, in
 * blocking mode. Every reader of navcore_io, navsim and navview opens its input files here.
 * @param[in]  path      the file
 * @param[out] out       the stream ("rb"); written only on NAV_OK; the caller fcloses it
 * @param[out] why       on failure, what is wrong, e.g. "cannot open the file: No such file or
 *                       directory" or "cannot read the file: it is a FIFO (named pipe), not a
 *                       regular file" (may be NULL)
 * @param[in]  why_size  capacity of @p why
 * @return NAV_OK; NAV_ERR_IO when the file cannot be opened (missing, no permission);
 *         NAV_ERR_PARSE when it exists but is not a regular file (the input is wrong);
 *         NAV_ERR_INVALID_ARG for NULL arguments.
 */
NAV_API NAV_NODISCARD nav_status nav_io_fopen_regular(const char *path, FILE **out, char *why,
                                                      size_t why_size);

NAV_END_DECLS

#endif /* NAV_IO_H */
