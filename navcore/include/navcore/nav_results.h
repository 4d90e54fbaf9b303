/**
 * @file nav_results.h
 * @brief navcore_io: result directories that appear only when complete, and the CSV / JSON
 *        exporters of a run.
 *
 * A result directory is built under a hidden temporary name next to its final place and
 * renamed into place by nav_resultdir_commit(); an interrupted run leaves at most a hidden
 * ".NAME.tmp-PID-XXXXXX" directory, never a half-written DIR.
 *
 * Nothing that navsim did not write is ever deleted. Each committed directory holds a manifest,
 * ".navsim-result", listing every file navsim wrote in it (tools that add files to a result
 * later append them with nav_resultdir_record()). An existing DIR is replaced only when it is
 * absent, an empty directory, or a directory whose manifest lists every file in it; a symbolic
 * link, a file, or a directory holding anything else is refused before any work, or with
 * NAV_RESULTDIR_FORCE renamed aside to "DIR.old-YYYYmmddTHHMMSS" at commit (moved, not deleted).
 * A previous result is removed file by file from its manifest, never through a link.
 */
#ifndef NAV_RESULTS_H
#define NAV_RESULTS_H

#include <stddef.h>
#include <stdio.h>

#include "nav_export.h"
#include "nav_scene.h"
#include "nav_sim.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

typedef struct nav_resultdir nav_resultdir;

/** Flag of nav_resultdir_open: move whatever is at the final path aside at commit instead of
 *  refusing it. */
#define NAV_RESULTDIR_FORCE 1u

/** May @p final_dir receive a result? NAV_OK: it is absent, an empty directory, or a navsim
 *  result directory holding only files navsim wrote. NAV_ERR_INVALID_ARG: an empty or unusable
 *  name, a symbolic link, a file, or a directory holding anything else; NAV_ERR_IO: it cannot be
 *  examined. On failure @p msg (may be NULL) says what is there and how to proceed. */
NAV_API NAV_NODISCARD nav_status nav_resultdir_check(const char *final_dir, char *msg, size_t msg_cap);
/** Start a result directory whose final path is @p final_dir (parents are created), after
 *  nav_resultdir_check() (skipped for an existing path with NAV_RESULTDIR_FORCE in @p flags).
 *  On failure @p msg says why: NAV_ERR_INVALID_ARG refused, NAV_ERR_IO cannot create. */
NAV_API NAV_NODISCARD nav_status nav_resultdir_open(const char *final_dir, unsigned flags, nav_resultdir **out,
                                                    char *msg, size_t msg_cap);
/** nav_resultdir_open(final_dir, 0, out, NULL, 0). */
NAV_API NAV_NODISCARD nav_status nav_resultdir_begin(const char *final_dir, nav_resultdir **out);
/** Full path of @p file_name inside the temporary directory (borrowed until the next call);
 *  NULL if the path would be too long. */
NAV_API const char *nav_resultdir_file(nav_resultdir *rd, const char *file_name);
/** Write the manifest, flush to disk and rename into place; frees @p rd whatever the outcome.
 *  The final path is checked again: when it no longer accepts a result (and FORCE was not
 *  given), it is left untouched, the result is kept at "DIR.new-PID" and NAV_ERR_INVALID_ARG is
 *  returned. @p msg (may be NULL) says why on failure, and on success says where a previous
 *  content was moved aside ("" when nothing was). */
NAV_API NAV_NODISCARD nav_status nav_resultdir_commit_msg(nav_resultdir *rd, char *msg, size_t msg_cap);
/** nav_resultdir_commit_msg(rd, NULL, 0). */
NAV_API NAV_NODISCARD nav_status nav_resultdir_commit(nav_resultdir *rd);
/** Remove the temporary directory; frees @p rd. Accepts NULL. */
NAV_API void nav_resultdir_abort(nav_resultdir *rd);
/** Add @p rel_path (relative, no "." or "..") to the manifest of the committed result directory
 *  @p result_dir, for a file a later tool wrote into it (a rendered image, a report, exported
 *  tracks). NAV_ERR_INVALID_ARG when @p result_dir is not a navsim result directory. */
NAV_API nav_status nav_resultdir_record(const char *result_dir, const char *rel_path);

/** Which of the per-epoch CSV tables. Headers carry units in the column names. */
/** NAV_CSV_NAV_SMOOTHED: the NAV_CSV_NAV columns of an RTS-smoothed solution plus the smoothed and
 *  forward 1-sigma of position N/E/D and yaw (sd_n_m ... fwd_sd_yaw_deg; records with sd_smoothed
 *  and sd_forward, i.e. from nav_sim_options.smoothed_record). */
typedef enum nav_csv_table {
  NAV_CSV_TRUTH = 0,
  NAV_CSV_NAV = 1,
  NAV_CSV_ERRORS = 2,
  NAV_CSV_NAV_SMOOTHED = 3
} nav_csv_table;

/** Write the header line of @p table. */
NAV_API NAV_NODISCARD nav_status nav_csv_write_header(FILE *f, nav_csv_table table);
/** Write one row of @p table from a record (all values at full double precision). */
NAV_API NAV_NODISCARD nav_status nav_csv_write_row(FILE *f, nav_csv_table table, const nav_sim_record *r);

/** What summary.json reports besides the simulation summary. */
typedef struct nav_run_info {
  const char *scene_file;
  uint64_t seed;
  bool ideal;
  double wall_s;
  const nav_requirement_verdict *requirements; /**< verdicts for summary.json "requirements" (may be NULL) */
  int n_requirements;
} nav_run_info;

/** Write summary.json for a run. */
NAV_API NAV_NODISCARD nav_status nav_summary_write_json(const char *path, const nav_scene *scene,
                                                        const nav_run_info *info, const nav_sim_summary *sum);

/** @p s as a JSON string literal (quotes, backslashes and control characters escaped; other bytes
 *  as they are); NULL is written as "". */
NAV_API void nav_json_write_string(FILE *f, const char *s);

/**
 * Write requirement verdicts as a JSON list (the "requirements" value of summary.json: objects
 * {id, metric, statistic, limit, unit, value, pass, samples} plus time_s for at_time and
 * outages [{t0_s, t1_s, t_s, value}] for outage_end; value null when not evaluated). The list
 * starts at the current position; items are indented by @p indent + 2 spaces.
 */
NAV_API NAV_NODISCARD nav_status nav_requirements_write_json(FILE *f, const nav_requirement_verdict *v, int count,
                                                             int indent);
/** Terminal summary of the verdicts: "requirements N of M pass" and one line per requirement. */
NAV_API void nav_requirements_print(FILE *f, const nav_requirement_verdict *v, int count);

/**
 * As nav_requirements_print(), with every time shown (at_time, the run's span, outage intervals
 * and the epochs of their values) plus @p t_offset_s: navsim replay shows them in the recorded
 * files' time base (its verdicts count from the first IMU epoch).
 */
NAV_API void nav_requirements_print_at(FILE *f, const nav_requirement_verdict *v, int count, double t_offset_s);

/** Bytes nav_format_g17() may write, its terminator included. */
#define NAV_FORMAT_G17_SIZE 32

/**
 * @p x as printf("%.17g", x) writes it, byte for byte (the exact fast path of the CSV writers,
 * several times faster than glibc's printf), into @p buf of at least NAV_FORMAT_G17_SIZE bytes,
 * NUL-terminated. @return its length.
 */
NAV_API int nav_format_g17(char *buf, double x);

NAV_END_DECLS

#endif /* NAV_RESULTS_H */
