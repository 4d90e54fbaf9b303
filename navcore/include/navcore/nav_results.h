/**
 * @file nav_results.h
 * @brief navcore_io: result directories that appear only when complete, and the CSV / JSON
 *        exporters of a run.
 *
 * A result directory is built under a hidden temporary name next to its final place and
 * renamed into place by nav_resultdir_commit(); an interrupted run leaves at most a hidden
 * ".NAME.tmp-XXXXXX" directory, never a half-written DIR. An existing DIR is replaced only at
 * commit time.
 */
#ifndef NAV_RESULTS_H
#define NAV_RESULTS_H

#include <stdio.h>

#include "nav_export.h"
#include "nav_scene.h"
#include "nav_sim.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

typedef struct nav_resultdir nav_resultdir;

/** Start a result directory whose final path is @p final_dir (parents are created). */
NAV_API NAV_NODISCARD nav_status nav_resultdir_begin(const char *final_dir, nav_resultdir **out);
/** Full path of @p file_name inside the temporary directory (borrowed until the next call);
 *  NULL if the path would be too long. */
NAV_API const char *nav_resultdir_file(nav_resultdir *rd, const char *file_name);
/** Flush to disk and rename into place; frees @p rd whatever the outcome. */
NAV_API NAV_NODISCARD nav_status nav_resultdir_commit(nav_resultdir *rd);
/** Remove the temporary directory; frees @p rd. Accepts NULL. */
NAV_API void nav_resultdir_abort(nav_resultdir *rd);

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

NAV_END_DECLS

#endif /* NAV_RESULTS_H */
