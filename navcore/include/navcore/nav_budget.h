/**
 * @file nav_budget.h
 * @brief Error budget: the contribution of each error source to each requirement's metric, by
 *        covariance analysis with one source on at a time (linearisable schemes: ins_gnss and
 *        free_ins on WGS-84).
 *
 * Method (numerics.md 6.6 extended). The error model of the scheme is linear: with the filter
 * gains K fixed, the covariance obeys
 *   P+ = A P- A^T + K R K^T (A = I - K H),   P(k+1) = Phi P Phi^T + Q_d,
 * which is linear in (P0, Q, R). The gains are those of the full model (every source on: the
 * filter the user configured), computed along the reference trajectory as nav_sim_covariance()
 * does; then each source s propagates its own (P0_s, Q_s, R_s) through the same Phi, A and K.
 * The sources partition P0, Q and R exactly, so their covariances add up to the total:
 * sum_s P_s = P (to rounding). Scale factors of the truth that the filter does not estimate are
 * carried as "consider" states: the error model gains the 6 scale-factor states (random
 * constants, P0 = sd^2 + fixed^2) that the gains never correct (K has zero rows there), so their
 * effect through F and the velocity-update H is in the budget, and the total then exceeds the
 * filter's own covariance (nav_sim_covariance) by exactly their contribution. Sources that are
 * not in the linear model (misalignment, g-sensitivity, quantisation of the truth) are listed by
 * nav_budget_unmodelled_terms() and need Monte Carlo.
 *
 * A requirement's share: its metric's mean square E[m^2] is linear in the diagonal of P
 * (horizontal: P_NN + P_EE; vertical: P_DD; position_3d, velocity: the trace of the block; yaw:
 * P_phiD; roll_pitch: P_phiN + P_phiE), evaluated over the requirement's epochs: every output
 * epoch for rms, max, p95, cep (the mean of E[m^2]; quantiles are budgeted through the mean
 * square, since variances add and quantiles do not), the nearest epoch for at_time, and for
 * outage_end the last epoch inside the outage where the total is largest.
 *
 * Implementation: one nav_filter for the full model and one per source s carrying the full model
 * plus that source once more (P0 + P0_s, q + q_s, R + R_s: the source's noise parameters scaled
 * by sqrt 2), propagated with the full model's K; its P minus the full P is P_s, exactly by
 * linearity. (A filter with the source alone would be singular, and the filter API checks that
 * P is positive definite; this one is as well conditioned as the full model.)
 */
#ifndef NAV_BUDGET_H
#define NAV_BUDGET_H

#include <stddef.h>

#include "nav_export.h"
#include "nav_requirements.h"
#include "nav_scene.h"
#include "nav_sim.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Error sources of the covariance budget. */
typedef enum nav_budget_source {
  NAV_BUDGET_GYRO_ARW = 0,           /**< gyro angle random walk (white rate noise) */
  NAV_BUDGET_GYRO_BIAS_INSTABILITY,  /**< gyro Gauss-Markov bias (bias instability): P0 and Q */
  NAV_BUDGET_GYRO_RATE_RW,           /**< gyro rate random walk */
  NAV_BUDGET_GYRO_TURN_ON_BIAS,      /**< gyro turn-on bias (random constant, fixed part included) */
  NAV_BUDGET_ACCEL_VRW,              /**< accelerometer velocity random walk */
  NAV_BUDGET_ACCEL_BIAS_INSTABILITY, /**< accelerometer Gauss-Markov bias */
  NAV_BUDGET_ACCEL_RW,               /**< accelerometer random walk */
  NAV_BUDGET_ACCEL_TURN_ON_BIAS,     /**< accelerometer turn-on bias */
  NAV_BUDGET_INITIAL_POSITION,       /**< initial position error */
  NAV_BUDGET_INITIAL_VELOCITY,       /**< initial velocity error */
  NAV_BUDGET_INITIAL_ATTITUDE,       /**< initial attitude error */
  NAV_BUDGET_GNSS_POS_NOISE,         /**< GNSS white position noise */
  NAV_BUDGET_GNSS_POS_CORRELATED,    /**< GNSS correlated (Gauss-Markov) position error */
  NAV_BUDGET_GNSS_VEL_NOISE,         /**< GNSS velocity noise */
  NAV_BUDGET_FLOORS,                 /**< the filter's floors on P0 and R (perfect-sensor guards) */
  NAV_BUDGET_GYRO_SCALE_FACTOR,      /**< gyro scale factor (random constant, fixed part included) */
  NAV_BUDGET_ACCEL_SCALE_FACTOR      /**< accelerometer scale factor */
} nav_budget_source;
#define NAV_BUDGET_SOURCE_COUNT 17

/** Name as written in budget.csv ("gyro_arw", "gnss_pos_correlated", ...). */
NAV_API const char *nav_budget_source_name(nav_budget_source s);

/** Diagonal of the navigation part of P: dr N/E/D [m^2], dv N/E/D [m^2/s^2], phi N/E/D [rad^2]. */
typedef struct nav_budget_diag {
  double v[9];
} nav_budget_diag;

/** One output epoch of the budget. */
typedef struct nav_budget_epoch {
  double t_s;
  nav_budget_diag total;                            /**< full model (nav_sim_covariance, plus the
                                                         scale-factor consider states if any) */
  nav_budget_diag source[NAV_BUDGET_SOURCE_COUNT]; /**< contribution of each source */
} nav_budget_epoch;

typedef nav_callback_result (*nav_budget_fn)(void *user, const nav_budget_epoch *e);

/**
 * Run the per-source covariance analysis of @p scene; @p fn receives every output epoch.
 * @param[out] active  may be NULL: bit s set when source s has a non-zero input in the scene
 * @param[out] msg     reason of a failure (may be NULL)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (flat Earth, gyro_free scheme); NAV_ERR_CANCELLED when
 *         @p fn stops; the filter's statuses.
 */
NAV_API NAV_NODISCARD nav_status nav_budget_covariance(const nav_scene *scene, nav_budget_fn fn, void *user,
                                                       unsigned *active, char *msg, size_t msg_size);

/** E[metric^2] (SI^2) from a diagonal (see the file comment). */
NAV_API double nav_budget_mean_square(nav_req_metric m, const nav_budget_diag *d);

/** Budget of one requirement. */
typedef struct nav_budget_result {
  nav_requirement req;
  double t_s;                                     /**< epoch used (at_time, outage_end), NaN: all */
  double total_ms;                                /**< total E[m^2], SI^2 */
  double source_ms[NAV_BUDGET_SOURCE_COUNT];      /**< each source's E[m^2], SI^2 */
  unsigned active;                                /**< sources present in the scene */
} nav_budget_result;

/**
 * Budget of @p count requirements of @p scene (nav_budget_covariance() plus the reduction of the
 * file comment). @p outages as nav_req_scene_outages() gives them.
 */
NAV_API NAV_NODISCARD nav_status nav_budget_requirements(const nav_scene *scene, const nav_requirement *reqs,
                                                         int count, nav_budget_result *out, char *msg,
                                                         size_t msg_size);

/**
 * IMU terms of @p scene that the covariance model does not carry (OR of nav_imu_term, gyro in
 * the low 16 bits, accelerometer shifted by 16): their contribution is not in the budget.
 */
NAV_API unsigned nav_budget_unmodelled_terms(const nav_scene *scene);

NAV_END_DECLS

#endif /* NAV_BUDGET_H */
