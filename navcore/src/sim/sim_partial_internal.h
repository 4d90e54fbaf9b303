/* Private to navcore's sim module: the hook through which sim_partial.c runs a range of Monte
 * Carlo runs or merges the per-run tables of several ranges (sim.c calls it). */
#ifndef NAV_SIM_PARTIAL_INTERNAL_H
#define NAV_SIM_PARTIAL_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "navcore/nav_sim.h"

/** The per-run tables of a job (sim.c's layout), borrowed for the duration of the hook call. */
typedef struct nav_sim_tables {
  long runs;                /**< runs of the whole job */
  int n_metrics;            /**< planes of metrics */
  int64_t stats_per_run;    /**< values per run and metric */
  int64_t n_out;            /**< output epochs per run */
  int env_values;           /**< values per run and output epoch in env */
  double *metrics;          /**< [n_metrics][runs][stats_per_run] */
  double *env;              /**< [runs][n_out][env_values], or NULL (too large: no envelopes) */
  nav_epoch_errors *final;  /**< [runs] */
  int64_t *samples_done;    /**< [runs] */
  nav_status *status;       /**< [runs] */
  /** navigation.smoother: values per run and plane of sm_metrics (0: no smoothing) */
  int64_t sm_per_run;
  double *sm_metrics;       /**< [2 n_metrics][runs][sm_per_run] (smoothed, then forward), or NULL */
  int64_t *sm_bytes;        /**< [runs] smoother memory per run, or NULL */
} nav_sim_tables;

/**
 * Range hook of nav_sim_run (inactive when !active): run only runs [r0, r1) (run 0, when in the
 * range, on the calling thread with the record callback, as always), then call @p tables with
 * the job's tables; when it returns NAV_OK and @p reduce, reduce the statistics as usual (over
 * every run of the job), else return after it without touching the summary.
 */
typedef struct nav_sim_range_hook {
  bool active;
  long r0, r1;
  bool reduce;
  nav_status (*tables)(void *user, nav_sim_tables *t);
  void *user;
} nav_sim_range_hook;

/** Install (or, with NULL, remove) the range hook of @p sim. */
void nav_sim_set_range_hook(nav_sim *sim, const nav_sim_range_hook *hook);

#endif /* NAV_SIM_PARTIAL_INTERNAL_H */
