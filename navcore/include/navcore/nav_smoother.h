/**
 * @file nav_smoother.h
 * @brief Rauch-Tung-Striebel fixed-interval smoother (backward pass) for the closed-loop
 *        error-state INS/GNSS filter of nav_filter.h (numerics.md section 6).
 *
 * The forward filter is closed loop: after every GNSS update the estimated errors are fed back
 * into the navigation solution (the "nominal" state) and the error state is reset to zero (first
 * order reset: P unchanged). A textbook RTS smoother over the error state alone would smooth a
 * state that is zero at almost every epoch. The smoother therefore records, while the forward
 * filter runs, what the backward pass needs at a sparse set of RECORD EPOCHS (every measurement
 * epoch and every epoch the caller marks, e.g. the 10 Hz output epochs), never per IMU step:
 *
 * | per record k            | meaning                                                              |
 * |-------------------------|----------------------------------------------------------------------|
 * | t_k, nominal_k          | time and the nominal (INS) state AFTER any feedback at the epoch      |
 * | x_k                     | filter error state after the reset (zero except GNSS GM states)       |
 * | d_k                     | the correction fed back at k: error state before minus after reset    |
 * | P_k                     | a-posteriori covariance (filter's P after the update; else propagated)|
 * | Phi_k, Q_k              | transition and process noise from record k-1 to k                     |
 *
 * Phi_k and Q_k are accumulated along the recorded nominal trajectory from the same
 * linearisation points the filter used (nav_filter_nav of every IMU step): F dt and G Q_c G^T dt
 * are summed over groups of nav_smoother_config.group_steps IMU steps, each group is discretised
 * by the second-order form E6.2 (Phi_g = I + A + A^2/2 with A = sum F dt; Q_g from the fused
 * E6.2, exactly as the filter's own covariance step), and the groups are chained:
 *     Phi <- Phi_g Phi,   Q <- Phi_g Q Phi_g^T + Q_g.
 * With group_steps = 1 this is the filter's default discretisation step for step; the a-priori
 * covariance at record k is P_k^- = Phi_k P_(k-1) Phi_k^T + Q_k (the smoother's own propagation,
 * which equals the filter's prior up to rounding when the filter uses the second-order form
 * without decimation, and to the discretisation difference otherwise). Between measurement
 * epochs the recorded P_k is that propagation (no update happened).
 *
 * Error definitions (nav_filter.h): dx = computed - true, on the nominal state after feedback.
 * The prior of record k+1 is taken about the nominal BEFORE the feedback at k+1, which differs
 * from the recorded one by the correction: dx(before) = dx(after) + d_(k+1) (first-order reset,
 * the reset Jacobian is the identity, as in the filter). Backward recursion (RTS, e.g. [G] ch. 3,
 * [BS] 8.6), from x_s(N) = x_N, P_s(N) = P_N:
 *     P^-      = Phi P_k Phi^T + Q                                  (Phi, Q: Phi_(k+1), Q_(k+1))
 *     C        = P_k Phi^T (P^-)^-1                                 (Cholesky solve, no inverse)
 *     x_s(k)   = x_k + C (x_s(k+1) + d_(k+1) - Phi x_k)
 *     P_s(k)   = (I - C Phi) P_k (I - C Phi)^T + C (Q + P_s(k+1)) C^T
 * The covariance line is the Joseph-like form of P_k + C (P_s(k+1) - P^-) C^T (equal in exact
 * arithmetic, since C P^- C^T = C Phi P_k): a sum of positive semi-definite terms, so rounding
 * cannot make P_s indefinite. The smoothed navigation state is the recorded nominal corrected by
 * x_s(k) with nav_filter_apply_correction() (position, velocity, attitude, biases).
 *
 * Because the chain of record epochs is a Markov chain (the composition of the transitions over
 * any sub-interval is their product, the noise their transported sum), adding or removing
 * record epochs without a measurement changes no smoothed value at the remaining epochs except
 * for the group boundaries of the discretisation (none with group_steps = 1).
 *
 * Memory: per record n^2 (Phi) + n (n + 1) (Q and P, packed upper triangles) + 4 n doubles plus
 * the nominal state: 4.3 KiB at n = 15. Recording the 10 Hz output epochs of a 965 s drive is
 * 9652 records, 41 MiB; at the 1 Hz measurement epochs only, 4.1 MiB. Storage grows by 1.5x
 * (amortised; no allocation per IMU step). Forward-time cost (instruction counts, n = 15): one
 * F and G Q_c G^T per IMU step plus the sparse group products, about 8.4k instructions per IMU
 * step with group_steps = 10 and 50k with group_steps = 1 (a filter predict is 25-50k); a mark
 * about 40k. Backward pass: seven dense n x n products, a Cholesky factorisation and solve per
 * record, about 160k instructions (1.7e9 for the long drive's 9652 records, 0.3-0.5 s).
 *
 * Use (closed loop with nav_ins_gnss, which calls nav_smoother_step() and nav_smoother_update()
 * itself when nav_ins_gnss_config.smoother is set):
 * @code
 *   nav_smoother_config sc = nav_smoother_config_default();
 *   sc.filter = ig_cfg.filter;                      // the forward filter's model
 *   nav_smoother *sm = NULL;
 *   if (nav_smoother_create(&sc, &sm) != NAV_OK) return;
 *   ig_cfg.smoother = sm;                           // borrowed by nav_ins_gnss
 *   nav_ins_gnss_create(&ig_cfg, &s0, &ig);         // records epoch 0
 *   for each IMU step: nav_ins_gnss_step(); fixes: nav_ins_gnss_update();
 *                      at output epochs: nav_smoother_mark(sm);
 *   if (nav_smoother_run(sm) != NAV_OK) puts(nav_smoother_last_error(sm));
 *   for (size_t k = 0; k < nav_smoother_count(sm); ++k) {
 *     nav_smoother_epoch e;
 *     nav_smoother_get(sm, k, &e);                  // e.smoothed, e.sd_smoothed[0..n-1]
 *   }
 *   nav_ins_gnss_destroy(ig); nav_smoother_destroy(sm);
 * @endcode
 *
 * Threading: one thread at a time per object. Errors: NAV_ERR_NUMERIC for non-finite inputs and
 * for an a-priori covariance that is not positive definite, with a message naming the epoch
 * (nav_smoother_last_error()).
 */
#ifndef NAV_SMOOTHER_H
#define NAV_SMOOTHER_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_export.h"
#include "nav_filter.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Smoother settings. Start from nav_smoother_config_default(). */
typedef struct nav_smoother_config {
  /** The forward filter's configuration (validated as by nav_filter_create()). Only the state
   *  layout and the process model (noise densities, bias and GNSS-error processes) are used: P0
   *  comes with nav_smoother_begin(), and the filter's discretisation and cov_decimation do not
   *  matter (the smoother has its own, group_steps). */
  nav_filter_config filter;
  /**
   * IMU steps per discretisation group (>= 1, default 1). 1: the transition is the product of
   * the per-step second-order transitions (the filter's own default step); N > 1: F dt and
   * G Q_c G^T dt are summed over N steps (never across a record epoch) and discretised once,
   * like nav_filter_config.cov_decimation, about N times cheaper in forward time with an
   * O((|F| N dt)^3) truncation.
   */
  unsigned group_steps;
} nav_smoother_config;

/** Defaults: nav_filter_config_default(), group_steps 1. */
NAV_API nav_smoother_config nav_smoother_config_default(void);

/** The smoother (recorder + backward pass). Opaque. */
typedef struct nav_smoother nav_smoother;

/**
 * Create an empty smoother.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, group_steps 0, nav_filter_config_validate()
 *         fails); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_create(const nav_smoother_config *cfg, nav_smoother **out);

/** Destroy; accepts NULL. */
NAV_API void nav_smoother_destroy(nav_smoother *s);

/**
 * Start recording (record 0): clears any previous recording and results.
 * @param[in] t_s     time [s]
 * @param[in] nominal navigation state (geodetic, NED velocity, q_b_n, bias estimates)
 * @param[in] P       initial covariance, n x n row-major (n = layout.n_states); symmetric
 * @param[in] x       initial error state, n values (NULL: zero)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_NUMERIC (non-finite); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_begin(nav_smoother *s, double t_s,
                                                    const nav_filter_ins_state *nominal, const double *P,
                                                    const double *x);

/**
 * One IMU step of the forward run: accumulate the transition and process noise of the step
 * (F and G Q_c G^T at @p nav, the filter's linearisation point) and remember @p nominal as the
 * current navigation state (for a later nav_smoother_mark()).
 * @param[in] t_s     time at the end of the step [s]
 * @param[in] nav     the filter's linearisation point of the step (nav_filter_predict() input)
 * @param[in] dt_s    step [s], > 0
 * @param[in] nominal navigation state at the end of the step
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, dt_s <= 0); NAV_ERR_STATE (before begin);
 *         NAV_ERR_NUMERIC (non-finite inputs or accumulated matrices); NAV_ERR_OUT_OF_RANGE
 *         (|lat| too close to a pole for the NED model).
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_step(nav_smoother *s, double t_s, const nav_filter_nav *nav,
                                                   double dt_s, const nav_filter_ins_state *nominal);

/**
 * A measurement update with closed-loop feedback at the current step: record (or complete the
 * record of this step) with the filter's a-posteriori covariance, its error state after the
 * reset and the correction fed back. Several updates at the same step accumulate their
 * corrections (first order).
 * @param[in] nominal    navigation state after the feedback (bias estimates included)
 * @param[in] P          filter covariance after the update, n x n row-major
 * @param[in] x_after    filter error state after the reset (n values; NULL: zero)
 * @param[in] correction the error state fed back and removed by the reset: before minus after
 *                       (n values; NULL: zero)
 * @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_STATE (before begin); NAV_ERR_NUMERIC;
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_update(nav_smoother *s, const nav_filter_ins_state *nominal,
                                                     const double *P, const double *x_after,
                                                     const double *correction);

/**
 * Make the current step a record epoch (e.g. an output epoch) with the nominal of the last
 * nav_smoother_step(); a no-op when the step is already recorded.
 * @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_STATE (before begin); NAV_ERR_NUMERIC
 *         (propagated covariance not finite); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_mark(nav_smoother *s);

/**
 * Backward pass over all records so far (may be called again after more recording).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_STATE (nothing recorded);
 *         NAV_ERR_NUMERIC (an a-priori covariance not positive definite, a non-finite or
 *         non-positive smoothed variance; the message names the record time);
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_run(nav_smoother *s);

/** Number of records. */
NAV_API size_t nav_smoother_count(const nav_smoother *s);

/** Layout of the recorded error state. */
NAV_API nav_filter_layout nav_smoother_layout(const nav_smoother *s);

/** One record with its forward and smoothed values. Plain value. */
typedef struct nav_smoother_epoch {
  double t_s;                                /**< time [s] */
  bool measured;                             /**< a measurement update happened at this epoch */
  nav_filter_ins_state forward;              /**< forward (filtered, after feedback) state */
  nav_filter_ins_state smoothed;             /**< forward corrected by the smoothed errors */
  nav_filter_error dx_smoothed;              /**< smoothed error of the forward state */
  double sd_forward[NAV_FILTER_MAX_STATES];  /**< sqrt(diag P) of the forward filter */
  double sd_smoothed[NAV_FILTER_MAX_STATES]; /**< sqrt(diag P_s) */
} nav_smoother_epoch;

/**
 * Record @p k (0 .. count - 1). The smoothed fields are those of the last nav_smoother_run()
 * (NAN for records made after it, or before any run).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_OUT_OF_RANGE (k >= count).
 */
NAV_API NAV_NODISCARD nav_status nav_smoother_get(const nav_smoother *s, size_t k, nav_smoother_epoch *out);

/** Bytes held by the recording and the results (for memory reports). */
NAV_API size_t nav_smoother_memory_bytes(const nav_smoother *s);

/** Last failure message ("" if none). Borrowed, valid until the next non-const call. */
NAV_API const char *nav_smoother_last_error(const nav_smoother *s);

NAV_END_DECLS

#endif /* NAV_SMOOTHER_H */
