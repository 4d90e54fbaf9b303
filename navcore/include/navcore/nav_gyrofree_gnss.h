/**
 * @file nav_gyrofree_gnss.h
 * @brief Gyro-free (accelerometer-array) INS aided by GNSS: loosely coupled error-state Kalman
 *        filter with lever arm, in closed loop (docs/gyro-free-gnss.md has the derivation).
 *
 * Error state, in this order, with the named index constants below:
 *
 * | block  | index              | size | meaning                                                  | unit    |
 * |--------|--------------------|------|----------------------------------------------------------|---------|
 * | dr     | NAV_GFG_IDX_DR     | 3    | position error, computed - true, N/E/D metres            | m       |
 * | dv     | NAV_GFG_IDX_DV     | 3    | velocity error v_eb_n, computed - true                   | m/s     |
 * | phi    | NAV_GFG_IDX_PHI    | 3    | attitude error, C_b_n(comp) = (I - [phi x]) C_b_n(true)  | rad     |
 * | dw     | NAV_GFG_IDX_DW     | 3    | angular-rate error omega_ib_b, computed - true, body     | rad/s   |
 * | beta_f | NAV_GFG_IDX_BF     | 3    | specific-force bias left in H^+ dA / dt, body            | m/s^2   |
 * | beta_w | NAV_GFG_IDX_BW     | 3    | angular-acceleration bias left in H^+ dA / dt, body      | rad/s^2 |
 * | beta_c | 18 (optional)      | 6    | constant (turn-on) part of beta_f, beta_w when the sensors also have a Gauss-Markov bias | |
 * | e_gnss | 18 or 24 (optional)| 3    | GNSS position error, Gauss-Markov, N/E/D                 | m       |
 *
 * With both a turn-on and a Gauss-Markov bias per sensor, beta_f and beta_w carry the
 * Gauss-Markov part and beta_c the constant part (one Gauss-Markov state of the combined sigma
 * would let the constant part decay: overconfident); nav_gfg_filter_idx_const_bias() and
 * nav_gfg_filter_idx_gnss() give where the optional blocks are.
 *
 * The six bias states are the combinations beta = H^+ b of the N per-sensor biases b: exactly
 * the part of b that reaches the navigation (the rest, N - 6 dimensions, is annihilated by H^+
 * and is neither observable nor needed). For six sensors beta and b are one-to-one.
 *
 * Continuous model (docs/gyro-free-gnss.md section 2): the gyro INS model of numerics.md 6.1
 * with the rate error dw in place of the gyro bias and beta_f in place of the accelerometer bias,
 * plus the terms of the array:
 *   dv_dot  += -C_b_n D_f J_c(w) dw + C_b_n w_f            (centripetal compensation uses the estimated rate)
 *   dw_dot   = beta_w - D_w J_c(w) dw + w_w                (the array integrates angular acceleration)
 *   beta_dot = -beta / T + w_b  (per-sensor Gauss-Markov bias), 0 for random constants,
 * with D = H^+ = [D_f; D_w], J_c = dc/dw the Jacobian of the centripetal readings, and the white
 * noises [w_f; w_w] = D w (covariance N^2 (H^T H)^-1, f and omega_dot parts correlated unless the
 * layout is symmetric) and w_b with covariance (2 sigma^2 / T) (H^T H)^-1.
 *
 * Discretisation: second order (numerics.md E6.2) per array interval, fused as
 * P <- Phi (P + Q_c dt/2) Phi^T + Q_c dt/2. Updates: GNSS antenna position and velocity with the
 * lever arm (E6.3-E6.4 with dw in the place of the gyro bias), K through a Cholesky solve of S,
 * Joseph form, P symmetrised after every step and update and checked by a Cholesky factorisation;
 * any failure is NAV_ERR_NUMERIC and leaves x and P as they were. Nothing is clamped.
 *
 * Covariance analysis: drive a ::nav_gfg_filter with the reference trajectory in nav_filter_nav
 * and zero measurements (P, S and K do not depend on z).
 *
 * Memory: allocated by the create functions only. Threading: one thread per object.
 */
#ifndef NAV_GYROFREE_GNSS_H
#define NAV_GYROFREE_GNSS_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_array.h"
#include "nav_export.h"
#include "nav_filter.h"
#include "nav_gyrofree.h"
#include "nav_ins_gnss.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** @name Error-state indices (first element of each 3-vector block). @{ */
#define NAV_GFG_IDX_DR 0
#define NAV_GFG_IDX_DV 3
#define NAV_GFG_IDX_PHI 6
#define NAV_GFG_IDX_DW 9
#define NAV_GFG_IDX_BF 12
#define NAV_GFG_IDX_BW 15
/** @} */
/** States of the core model (dr, dv, phi, dw, beta_f, beta_w). */
#define NAV_GFG_N_CORE 18
/** Largest state count (core + constant-bias block + GNSS position Gauss-Markov). */
#define NAV_GFG_MAX_STATES 27

/** Filter configuration, SI. Start from nav_gfg_filter_config_default(). */
typedef struct nav_gfg_filter_config {
  nav_accel_array array;          /**< the layout (copied; checked by nav_array_geometry_compute()) */
  double vrw_mps_per_sqrt_s;      /**< per-sensor white-noise density N [m/s/sqrt(s)], >= 0 */
  double bias_const_sd_mps2;      /**< per-sensor random-constant (turn-on) bias sigma [m/s^2], >= 0 */
  bool bias_gm;                   /**< per-sensor Gauss-Markov bias present */
  double bias_gm_sd_mps2;         /**< its stationary sigma [m/s^2], >= 0 */
  double bias_gm_tau_s;           /**< its correlation time T [s], > 0, finite */
  double bias_sd_floor_mps2;      /**< lower bound of the per-sensor bias sigma in P0 (> 0) */
  nav_vec3 pos_sd_m;              /**< P0: position N/E/D [m], > 0 */
  nav_vec3 vel_sd_mps;            /**< P0: velocity N/E/D [m/s], > 0 */
  nav_vec3 att_sd_rad;            /**< P0: attitude N/E/D [rad], > 0 */
  nav_vec3 rate_sd_rps;           /**< P0: angular-rate error, body [rad/s], > 0 */
  bool gnss_gm;                   /**< append three GNSS position Gauss-Markov states */
  nav_vec3 gnss_gm_sd_m;          /**< their stationary sigma N/E/D [m], > 0 when on */
  nav_vec3 gnss_gm_tau_s;         /**< their correlation time [s], > 0, finite when on */
} nav_gfg_filter_config;

/** Defaults: cube layout r = 0.1 m, perfect sensors (no noise, no bias) with a bias floor of
 *  1e-5 m/s^2 (about 1 ug); P0 1 m, 0.1 m/s, 1 mrad, 1e-3 rad/s; no GNSS states. */
NAV_API nav_gfg_filter_config nav_gfg_filter_config_default(void);

/** The error-state filter. Opaque. */
typedef struct nav_gfg_filter nav_gfg_filter;

/**
 * Create with x = 0 and P = P0 (diagonal blocks; the bias block (sigma_c^2 + sigma_gm^2)
 * (H^T H)^-1, floored; split into sigma_gm^2 (H^T H)^-1 on beta and sigma_c^2 (H^T H)^-1 on beta_c
 * when both parts are present).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, bad value); NAV_ERR_NUMERIC (singular layout);
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_gfg_filter_create(const nav_gfg_filter_config *cfg, nav_gfg_filter **out);
/** Destroy; accepts NULL. */
NAV_API void nav_gfg_filter_destroy(nav_gfg_filter *f);
/** Number of states: 18, 21, 24 or 27. */
NAV_API size_t nav_gfg_filter_n_states(const nav_gfg_filter *f);
/** First index of the GNSS Gauss-Markov block (18 or 24), 0 when there is none. */
NAV_API size_t nav_gfg_filter_idx_gnss(const nav_gfg_filter *f);
/** First index of the constant-bias block beta_c (18), 0 when there is none. */
NAV_API size_t nav_gfg_filter_idx_const_bias(const nav_gfg_filter *f);
/** The estimated bias combinations beta (6: f [m/s^2], omega_dot [rad/s^2]): beta_f, beta_w plus
 *  beta_c when present. NULL-safe. */
NAV_API void nav_gfg_filter_bias_estimate(const nav_gfg_filter *f, double beta[6]);

/**
 * Time update over one array interval at the linearisation point @p nav (its f_ib_b_mps2 is the
 * compensated mean specific force, w_ib_b_rps the estimated angular rate).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, dt_s not finite and positive); NAV_ERR_OUT_OF_RANGE
 *         (cos lat < 1e-6); NAV_ERR_NUMERIC (non-finite input, P not positive definite: x and P
 *         unchanged).
 */
NAV_API NAV_NODISCARD nav_status nav_gfg_filter_predict(nav_gfg_filter *f, const nav_filter_nav *nav, double dt_s);

/**
 * GNSS antenna position update, z = D (r_ant,INS - r_GNSS) [m] (nav_filter_gnss_pos_residual()),
 * R = diag(@p r_diag_m2) [m^2], lever arm @p l_ba_b_m [m, body].
 * @return as nav_gfg_filter_predict(); x and P unchanged on error.
 */
NAV_API NAV_NODISCARD nav_status nav_gfg_filter_update_pos(nav_gfg_filter *f, const nav_filter_nav *nav,
                                                           nav_vec3 z_pos_ned_m, nav_vec3 r_diag_m2,
                                                           nav_vec3 l_ba_b_m);
/**
 * GNSS antenna velocity update, z = v_ant,INS - v_GNSS [m/s] (nav_filter_gnss_vel_residual());
 * @p nav->w_ib_b_rps must be the rate at the fix epoch. Returns as nav_gfg_filter_update_pos().
 */
NAV_API NAV_NODISCARD nav_status nav_gfg_filter_update_vel(nav_gfg_filter *f, const nav_filter_nav *nav,
                                                           nav_vec3 z_vel_ned_mps, nav_vec3 r_diag_m2s2,
                                                           nav_vec3 l_ba_b_m);
/** Zero the states the INS absorbs on feedback (0..17, and beta_c); P is kept (first-order reset). */
NAV_API void nav_gfg_filter_reset_errors(nav_gfg_filter *f);
/** x (n doubles; borrowed, valid until the next non-const call or destroy). */
NAV_API const double *nav_gfg_filter_state(const nav_gfg_filter *f);
/** P (n x n row-major; borrowed, as nav_gfg_filter_state()). */
NAV_API const double *nav_gfg_filter_cov(const nav_gfg_filter *f);
/** NIS y^T S^-1 y of the last update (0 before any). */
NAV_API double nav_gfg_filter_last_nis(const nav_gfg_filter *f);
/** The geometry of the layout (borrowed). */
NAV_API const nav_array_geometry *nav_gfg_filter_geometry(const nav_gfg_filter *f);
/** Message of the last failure ("" if none). */
NAV_API const char *nav_gfg_filter_last_error(const nav_gfg_filter *f);

/* ------------------------------------------------------------------ closed loop */

typedef struct nav_gyrofree_gnss_config {
  nav_gyrofree_config gf;        /**< array INS (gf.ins.earth_model must be NAV_EARTH_WGS84) */
  nav_gfg_filter_config filter;  /**< error-state filter (its array is replaced by gf.array) */
  nav_vec3 r_ba_b_m;             /**< GNSS antenna relative to the array centre, body axes [m] */
  double pos_sd_floor_m;         /**< lower bound of the position sigma in R [m] */
  double vel_sd_floor_mps;       /**< lower bound of the velocity sigma in R [m/s] */
} nav_gyrofree_gnss_config;

/**
 * The configuration of a scene's gyro_free_gnss scheme: the array layout and strapdown settings,
 * the filter's sensor model from array.accel (noise density, turn-on bias as a random constant,
 * GM bias), P0 from initial_errors and array.initial_rate_sd_dps (floored so that P0 is positive
 * definite for perfect sensors), GNSS GM states when the receiver's tau exceeds ten update
 * intervals (as nav_ins_gnss_config_from_scene()). The layout is left empty (n_sensors 0) when
 * the scene's array section is invalid; create then fails.
 */
NAV_API nav_gyrofree_gnss_config nav_gyrofree_gnss_config_from_scene(const nav_scene *scene);

typedef struct nav_gyrofree_gnss nav_gyrofree_gnss;

/**
 * Create with the initial state in F = ECEF and the initial rate estimate omega_ib_b [rad/s].
 * @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_NUMERIC; NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_gnss_create(const nav_gyrofree_gnss_config *cfg,
                                                          const nav_ins_state *initial, nav_vec3 w_ib_b0_rps,
                                                          nav_gyrofree_gnss **out);
NAV_API void nav_gyrofree_gnss_destroy(nav_gyrofree_gnss *x);
/** One array interval of measured increments: compensated array INS step, then filter predict. */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_gnss_step(nav_gyrofree_gnss *x, const nav_array_increment *inc);
/** One GNSS fix at the current epoch: position (and velocity) update, feedback, reset. */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_gnss_update(nav_gyrofree_gnss *x, const nav_ins_gnss_fix *fix);
/** Navigation state in F = ECEF (borrowed). */
NAV_API const nav_ins_state *nav_gyrofree_gnss_state(const nav_gyrofree_gnss *x);
/** Current angular-rate estimate [rad/s]. */
NAV_API nav_vec3 nav_gyrofree_gnss_rate(const nav_gyrofree_gnss *x);
/** Current bias compensation beta (6 values: f [m/s^2], omega_dot [rad/s^2]); NULL-safe. */
NAV_API void nav_gyrofree_gnss_compensation(const nav_gyrofree_gnss *x, double beta[6]);
/** The equivalent IMU increment of the last step (borrowed). */
NAV_API const nav_imu_increment *nav_gyrofree_gnss_last_increment(const nav_gyrofree_gnss *x);
/** The filter (borrowed). */
NAV_API const nav_gfg_filter *nav_gyrofree_gnss_filter(const nav_gyrofree_gnss *x);
/** Number of GNSS fixes applied. */
NAV_API long nav_gyrofree_gnss_updates(const nav_gyrofree_gnss *x);
/** Last failure message ("" if none). */
NAV_API const char *nav_gyrofree_gnss_last_error(const nav_gyrofree_gnss *x);

NAV_END_DECLS

#endif /* NAV_GYROFREE_GNSS_H */
