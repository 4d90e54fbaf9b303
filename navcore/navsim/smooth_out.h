/*
 * navsim replay --smooth: the RTS smoother (nav_smoother.h) attached to the replay, its backward
 * pass after the forward run, nav_smoothed.csv and the "stats_smoothed" block of summary.json.
 */
#ifndef NAVSIM_SMOOTH_OUT_H
#define NAVSIM_SMOOTH_OUT_H

#include <stdio.h>

#include "navcore/nav_recorded.h"
#include "navcore/nav_smoother.h"

typedef struct smooth_out smooth_out;

/* Create the recorder for the filter @p fc; *sm is the smoother to put in nav_ins_gnss_config. */
nav_status smooth_out_create(const nav_filter_config *fc, unsigned group_steps, smooth_out **out,
                             nav_smoother **sm);
void smooth_out_destroy(smooth_out *o);

/* Call from the replay's record callback (every output epoch): marks the epoch and keeps the
 * reference and the forward errors for the scoring. */
nav_status smooth_out_on_record(smooth_out *o, const nav_replay_record *r);

/* Backward pass (timed), scoring against the kept references, and nav_smoothed.csv at
 * @p csv_path. Prints a message to stderr on failure. */
nav_status smooth_out_finish(smooth_out *o, const nav_replay_summary *sum, const char *csv_path);

/* `  "stats_smoothed": {...},` (with the trailing comma and newline). */
void smooth_out_json(const smooth_out *o, FILE *f);

/* Terminal table: forward vs smoothed. */
void smooth_out_print(const smooth_out *o);

#endif
