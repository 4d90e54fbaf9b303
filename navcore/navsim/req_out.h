/*
 * Requirement verdicts for the navsim commands that do not run nav_sim (replay): the output-epoch
 * errors are buffered (one run, 10 Hz epochs: small) and evaluated once the GNSS gaps are known.
 */
#ifndef NAVSIM_REQ_OUT_H
#define NAVSIM_REQ_OUT_H

#include <stddef.h>

#include "navcore/nav_errors.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_requirements.h"

typedef struct navsim_req_buffer {
  nav_epoch_errors *e;
  size_t n, cap;
  bool failed; /* out of memory */
} navsim_req_buffer;

/** Append one epoch (errors in the file time base). */
void navsim_req_buffer_add(navsim_req_buffer *b, const nav_epoch_errors *e);
void navsim_req_buffer_free(navsim_req_buffer *b);

/**
 * Verdicts of @p reqs over the buffered epochs of a replay: times relative to the initial epoch
 * (time_s of at_time counts from it), the GNSS outages are the replay's gaps (from the last fix
 * before a gap to the first fix after it; an open gap to the last epoch).
 */
nav_status navsim_req_replay_verdicts(const nav_requirement *reqs, int n, const navsim_req_buffer *b,
                                      const nav_replay_summary *sum, nav_requirement_verdict *out);

#endif
