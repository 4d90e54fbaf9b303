/**
 * @file nav_sim_partial.h
 * @brief Monte Carlo campaigns split into ranges of runs (for distributed runs, e.g. navsim
 *        under MPI): simulate runs [r0, r1) into a mergeable partial, then merge the partials
 *        of every range, in run order, into the summary, envelopes and final errors that
 *        nav_sim_run() would have produced — bit for bit, for any split and thread count.
 *
 * A run depends only on the scene and its index, and nav_sim_run() reduces the statistics over
 * the per-run tables in run order after all runs; a partial carries the rows of its runs of those
 * tables, and the merge fills them in and runs the same reduction. navcore has no MPI: the caller
 * moves the packed bytes (nav_sim_partial_bytes / nav_sim_partial_unpack) between processes.
 * Packed partials are for the same build on the same architecture (checked by a header).
 *
 * Example (two ranges on one machine):
 * @code
 *   nav_sim_partial *p[2];
 *   nav_sim_run_partial(sim, &o, 0, 500, &p[0]);   // run 0 here: records go to o.record
 *   nav_sim_run_partial(sim2, &o2, 500, 1000, &p[1]);
 *   nav_sim_summary sum;
 *   nav_sim_merge(sim, &o, (const nav_sim_partial *const *)p, 2, &sum);
 * @endcode
 */
#ifndef NAV_SIM_PARTIAL_H
#define NAV_SIM_PARTIAL_H

#include <stddef.h>

#include "nav_export.h"
#include "nav_sim.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Per-run results of a range of runs of a Monte Carlo job. */
typedef struct nav_sim_partial nav_sim_partial;

/**
 * Simulate runs [@p r0, @p r1) of the scene's job (clamped to [0, runs); --ideal jobs have one
 * run) with @p opts (threads, callbacks: run 0, when in the range, runs on the calling thread
 * with the record callback, as in nav_sim_run). The summary is not computed: merge the partials.
 * @return NAV_OK; the statuses of nav_sim_run (NAV_ERR_CANCELLED is a failure here).
 */
NAV_API NAV_NODISCARD nav_status nav_sim_run_partial(nav_sim *sim, const nav_sim_options *opts, long r0, long r1,
                                                     nav_sim_partial **out);

/** Runs covered by @p p: [*r0, *r1). */
NAV_API void nav_sim_partial_range(const nav_sim_partial *p, long *r0, long *r1);

/** The packed bytes of @p p (borrowed; valid while @p p lives). */
NAV_API const void *nav_sim_partial_bytes(const nav_sim_partial *p, size_t *size);

/**
 * A partial from packed bytes (copied).
 * @return NAV_OK; NAV_ERR_PARSE when the bytes are not a packed partial of this build.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_partial_unpack(const void *bytes, size_t size, nav_sim_partial **out);

NAV_API void nav_sim_partial_destroy(nav_sim_partial *p);

/**
 * Merge the partials of one job, given in run order and covering [0, runs) without gap or
 * overlap, into the summary (and the envelopes and finals of @p sim) exactly as nav_sim_run()
 * computes them. No run is simulated; @p opts->progress may be called.
 * @return NAV_OK; NAV_ERR_INVALID_ARG when the partials do not tile the job or belong to another
 *         scene layout; the statistics' statuses.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_merge(nav_sim *sim, const nav_sim_options *opts,
                                               const nav_sim_partial *const *parts, size_t count,
                                               nav_sim_summary *out);

NAV_END_DECLS

#endif /* NAV_SIM_PARTIAL_H */
