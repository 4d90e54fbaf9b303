/*
 * navsim run on scenes with navigation.smoother (ins_gnss): nav_smoothed.csv and
 * smoothed_errors.csv (run 0, RTS-smoothed, same columns as nav.csv / errors.csv) from the
 * nav_sim_options.smoothed_record callback, and the terminal line of the smoothed statistics.
 * ("stats_smoothed" in summary.json is written by nav_summary_write_json from the summary.)
 */
#ifndef NAVSIM_RUN_SMOOTH_OUT_H
#define NAVSIM_RUN_SMOOTH_OUT_H

#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"

typedef struct navsim_run_smooth navsim_run_smooth;

/* Open both files in the temporary result directory and write their headers. */
nav_status navsim_run_smooth_begin(nav_resultdir *rd, navsim_run_smooth **out);

/* One smoothed output epoch of run 0 (nav_sim_options.smoothed_record). */
nav_status navsim_run_smooth_record(navsim_run_smooth *o, const nav_sim_record *r);

/* Close both files; NAV_ERR_IO when a write failed. Frees @p o (NULL: NAV_OK). */
nav_status navsim_run_smooth_end(navsim_run_smooth *o);

/* Close without checking and free (error paths); accepts NULL. */
void navsim_run_smooth_abort(navsim_run_smooth *o);

/* Terminal lines: forward vs smoothed at the output epochs (when sum->has_smoothed). */
void navsim_run_smooth_print(const nav_sim_summary *sum);

#endif
