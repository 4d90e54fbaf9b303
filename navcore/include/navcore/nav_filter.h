/**
 * @file nav_filter.h
 * @brief Loosely coupled INS/GNSS error-state extended Kalman filter (NED, phi-angle) and
 *        covariance analysis (numerics.md section 6).
 *
 * Error state (numerics.md 6.1), in this order, with the named index constants below:
 *
 * | block  | index               | size | meaning                                                 | unit  |
 * |--------|---------------------|------|---------------------------------------------------------|-------|
 * | dr     | NAV_FILTER_IDX_DR   | 3    | position error, computed - true, N/E/D metres           | m     |
 * | dv     | NAV_FILTER_IDX_DV   | 3    | velocity error v_eb_n, computed - true                  | m/s   |
 * | phi    | NAV_FILTER_IDX_PHI  | 3    | attitude error: C_b_n(comp) = (I - [phi x]) C_b_n(true) | rad   |
 * | b_g    | NAV_FILTER_IDX_BG   | 3    | residual gyro bias in the compensated rate              | rad/s |
 * | b_a    | NAV_FILTER_IDX_BA   | 3    | residual accelerometer bias in the compensated force    | m/s^2 |
 * | s_g    | NAV_FILTER_IDX_SG   | 3    | residual gyro scale factor (optional)                   | -     |
 * | s_a    | NAV_FILTER_IDX_SA   | 3    | residual accelerometer scale factor (optional)          | -     |
 * | e_gnss | layout.idx_gnss_pos | 3    | GNSS position error, Gauss-Markov, N/E/D (optional)     | m     |
 * | clk    | layout.idx_clock    | 2    | receiver clock bias c dt_r and drift (optional, tight)  | m, m/s|
 * | isb    | layout.idx_isb      | 1    | GLONASS - GPS inter-system bias (optional, tight)       | m     |
 *
 * The receiver-clock and inter-system-bias states (docs/ins-gnss-tight.md) are total quantities,
 * not errors of an INS quantity: the feedback reset leaves them, like the GNSS GM states.
 *
 * dr is (d lat (R_M + h), d lon (R_N + h) cos lat, -d h). The phi convention is numerics.md
 * (E0.1): [SHIN] and KF-GINS; Groves' delta_psi is -phi. The sensor states are what is still
 * left in the compensated IMU data: omega(compensated) = omega + b_g + diag(omega) s_g and
 * f(compensated) = f + b_a + diag(f) s_a, so the INS adds them to its own estimates on feedback.
 *
 * Model (numerics.md 6.1-6.3): F exactly as in 6.1 (identical to [SHIN] ch. 3 and KF-GINS
 * gi_engine.cpp); process noise from the IMU specification (6.2): VRW q = N_a^2, ARW q = N_g^2,
 * Gauss-Markov bias q = 2 sigma^2 / T with F = -1/T, random walk q = K^2 with F = 0, random
 * constant q = 0. Discretisation by Van Loan (E6.1, through the matrix exponential of
 * nav_filter's own Pade implementation) or the second-order form (E6.2).
 *
 * Measurement updates (6.4-6.5): GNSS antenna position and velocity with the lever arm, one
 * 3-vector update each (not sequential), K from a Cholesky solve with S = H P H^T + R (never an
 * explicit inverse), Joseph form (E6.5), P symmetrised after every covariance propagation and
 * update. Every updated P is proved positive definite by a Cholesky factorisation; every
 * propagated P is checked for non-finite entries and a non-positive diagonal, and proved positive
 * definite by the Cholesky factorisation at least every 16th covariance step (a propagation
 * cannot make a positive definite P indefinite except by rounding, so a lost definiteness is
 * reported at most 15 covariance steps late, or by the next update). Any failure is
 * NAV_ERR_NUMERIC with a message and leaves x and P as they were. Nothing is clamped.
 *
 * Covariance analysis (6.6): drive the same object with the reference (true) trajectory in
 * nav_filter_nav and zero measurements; P, S and K do not depend on z. See the second example.
 *
 * Memory: everything is allocated by nav_filter_create(); predict and update never allocate.
 * Threading: a nav_filter is not synchronised (one thread at a time); the pure functions
 * (nav_filter_apply_correction(), the residual helpers) are thread-safe.
 *
 * Example (closed loop; the INS side is pseudo-code):
 * @code
 *   nav_filter_config cfg = nav_filter_config_default();
 *   cfg.gyro_arw_rad_per_sqrt_s = nav_vec3_make(4.363e-5, 4.363e-5, 4.363e-5);
 *   nav_filter *kf = NULL;
 *   if (nav_filter_create(&cfg, &kf) != NAV_OK) return;
 *   for each IMU interval k:
 *     ins_step(...);                                  // mechanize with compensated increments
 *     nav_filter_nav nav = {lat, h, v_n, C_b_n, dv/dt, dtheta/dt};   // computed state, end of k
 *     if (nav_filter_predict(kf, &nav, dt_s) != NAV_OK) puts(nav_filter_last_error(kf));
 *     if (a GNSS fix is valid at t_k) {
 *       nav_vec3 z = nav_filter_gnss_pos_residual(ins_pos, nav.C_b_n, l_ba_b_m, fix.pos);
 *       nav_vec3 r = {sdN * sdN, sdE * sdE, sdD * sdD};
 *       if (nav_filter_update_gnss_pos(kf, &nav, z, &r, l_ba_b_m) != NAV_OK) ...;
 *       nav_filter_error dx;
 *       nav_filter_get_error(kf, &dx);
 *       nav_filter_apply_correction(&ins_state, &ins_state, &dx);   // r, v, C, biases
 *       (void)nav_filter_reset_errors(kf);
 *     }
 *   nav_filter_destroy(kf);
 * @endcode
 *
 * Example (covariance analysis along a reference trajectory, numerics.md T6.3):
 * @code
 *   cfg.discretisation = NAV_FILTER_DISC_VAN_LOAN;
 *   nav_filter_create(&cfg, &kf);
 *   for (k = 1; k <= 12000; ++k) {
 *     nav_filter_nav ref = truth_at(k * 0.01);         // lat, h, v, C, f_b, w_ib_b of the truth
 *     nav_filter_predict(kf, &ref, 0.01);
 *   }
 *   nav_filter_flush(kf);                                // only needed with cov_decimation > 1
 *   double sd_n = sqrt(nav_filter_get_cov(kf)[0]);       // north position sigma [m]
 * @endcode
 */
#ifndef NAV_FILTER_H
#define NAV_FILTER_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_earth.h"
#include "nav_export.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/* ---------------------------------------------------------------- state layout */

/** @name Error-state indices (first element of each 3-vector block).
 *  The first five blocks are always present; SG/SA exist only with
 *  NAV_FILTER_STATE_SCALE_FACTORS; the GNSS position-error block follows the last IMU block
 *  (index 15 or 21, see nav_filter_layout.idx_gnss_pos).
 * @{ */
#define NAV_FILTER_IDX_DR 0
#define NAV_FILTER_IDX_DV 3
#define NAV_FILTER_IDX_PHI 6
#define NAV_FILTER_IDX_BG 9
#define NAV_FILTER_IDX_BA 12
#define NAV_FILTER_IDX_SG 15
#define NAV_FILTER_IDX_SA 18
/** @} */

/** Number of states of the core model (dr, dv, phi, b_g, b_a). */
#define NAV_FILTER_N_CORE 15
/** Largest state count: core + scale factors + GNSS position GM (or receiver clock and inter-system
 *  bias). Arrays are sized for it. */
#define NAV_FILTER_MAX_STATES 24
/** Largest measurement dimension accepted by nav_filter_update_linear(). */
#define NAV_FILTER_MAX_MEAS 6

/** Optional state blocks, OR-ed into nav_filter_config.states. */
typedef enum nav_filter_state_option {
  NAV_FILTER_STATE_SCALE_FACTORS = 1u << 0, /**< append s_g, s_a (21 states) */
  NAV_FILTER_STATE_GNSS_POS_GM = 1u << 1,   /**< append 3 GNSS position GM error states */
  /** append the receiver clock: bias c dt_r [m] and drift c dt_r' [m/s], the two-state model
   *  b' = d + w_f, d' = w_g (tightly coupled filter; not with NAV_FILTER_STATE_GNSS_POS_GM) */
  NAV_FILTER_STATE_RX_CLOCK = 1u << 2,
  /** append the GLONASS - GPS inter-system bias [m], a random constant (needs RX_CLOCK) */
  NAV_FILTER_STATE_RX_ISB = 1u << 3
} nav_filter_state_option;

/** Where the blocks of a configured filter live. Plain value. */
typedef struct nav_filter_layout {
  size_t n_states;        /**< 15, 18, 21 or 24; with the receiver clock 17 or 18, 23 or 24 */
  bool has_scale_factors; /**< s_g at NAV_FILTER_IDX_SG, s_a at NAV_FILTER_IDX_SA */
  bool has_gnss_pos_gm;   /**< GNSS position-error block present at idx_gnss_pos */
  size_t idx_gnss_pos;    /**< first index of the GNSS block; meaningful only if has_gnss_pos_gm */
  bool has_rx_clock;      /**< receiver clock bias at idx_clock, drift at idx_clock + 1 */
  size_t idx_clock;       /**< meaningful only if has_rx_clock */
  bool has_isb;           /**< GLONASS inter-system bias at idx_isb */
  size_t idx_isb;         /**< meaningful only if has_isb */
  size_t n_ins;           /**< the INS error blocks [0, n_ins) that the feedback reset zeroes (15 or 21) */
} nav_filter_layout;

/* ---------------------------------------------------------------- configuration */

/** Discretisation of the continuous model over one covariance step (numerics.md 6.3). */
typedef enum nav_filter_discretisation {
  /**
   * E6.2: Phi = I + F T + F^2 T^2/2, Q_d = (Phi G Q_c G^T Phi^T + G Q_c G^T) T/2, computed over
   * the non-zeros of F and fused into a single P sandwich. The default, because at IMU rates it
   * is as accurate as Van Loan for every purpose here at an eighth of the cost: on T6.3
   * (dt = 0.01 s) the position sigmas differ from Van Loan by 6e-8 relative; with
   * cov_decimation 20 (T = 0.2 s) by 2.4e-5. numerics.md 6.3 rates it adequate for T <= 0.1 s.
   */
  NAV_FILTER_DISC_SECOND_ORDER = 0,
  /**
   * E6.1: exact for F constant over the step, through the matrix exponential of the 2n x 2n
   * Van Loan matrix (scaling and squaring with Pade approximants, Higham 2005). About 8.5 times
   * the cost of the second-order form per covariance step (n = 15 and 24); the reference
   * discretisation, and the right choice for long covariance steps (cov_decimation > 1), where
   * its cost is amortised.
   */
  NAV_FILTER_DISC_VAN_LOAN = 1
} nav_filter_discretisation;

/** Process terms of an IMU bias or scale-factor triad, OR-ed into the *_terms fields. No bit
 *  set means a random constant (F = 0, q = 0; only its initial sigma matters). */
typedef enum nav_filter_process_term {
  NAV_FILTER_PROC_GM = 1u << 0, /**< first-order Gauss-Markov: F = -1/T, q = 2 sigma^2 / T */
  NAV_FILTER_PROC_RW = 1u << 1  /**< random walk: q = K^2 (combined with GM, q adds up) */
} nav_filter_process_term;

/**
 * Initial one-sigma errors (P0 is diagonal; for a full P0 use nav_filter_set_cov()). Every value
 * must be finite and > 0 for the blocks that exist (P0 must be positive definite).
 */
typedef struct nav_filter_init_sd {
  nav_vec3 pos_sd_m;           /**< dr, N/E/D [m] */
  nav_vec3 vel_sd_mps;         /**< dv, N/E/D [m/s] */
  nav_vec3 att_sd_rad;         /**< phi, N/E/D [rad] (roll/pitch-like, roll/pitch-like, heading) */
  nav_vec3 gyro_bias_sd_rps;   /**< b_g, body axes [rad/s] */
  nav_vec3 accel_bias_sd_mps2; /**< b_a, body axes [m/s^2] */
  nav_vec3 gyro_sf_sd;         /**< s_g, unitless (1e-6 = 1 ppm) */
  nav_vec3 accel_sf_sd;        /**< s_a, unitless */
  nav_vec3 gnss_pos_sd_m;      /**< GNSS position error, N/E/D [m] */
  double clock_bias_sd_m;      /**< receiver clock bias c dt_r [m] (RX_CLOCK) */
  double clock_drift_sd_mps;   /**< receiver clock drift [m/s] (RX_CLOCK) */
  double isb_sd_m;             /**< inter-system bias [m] (RX_ISB) */
} nav_filter_init_sd;

/**
 * Filter configuration, SI throughout; body axes for the IMU terms, N/E/D for GNSS terms.
 * Start from nav_filter_config_default() and override fields (style.md 6).
 */
typedef struct nav_filter_config {
  unsigned states;                          /**< OR of ::nav_filter_state_option; 0: 15 states */
  nav_filter_discretisation discretisation; /**< default NAV_FILTER_DISC_SECOND_ORDER */
  /**
   * Covariance decimation N >= 1: P (and x) are propagated once every N calls of
   * nav_filter_predict(), over the whole interval T with the selected discretisation applied to
   * the interval mean of F and of G Q_c G^T. The blocks of F that change at IMU rate are linear
   * in C_b_n (f^n x, C_b_n, C_b_n diag(f or w)) and are integrated exactly from per-step sums;
   * the Earth-rate, transport and curvature blocks depend on lat, h and v only and are evaluated
   * at their interval means (second-order accurate for the mean F); G Q_c G^T is q T I for
   * isotropic noise, else summed per step. The calls in between cost ~150 instructions. With
   * Van Loan the result equals the product of the per-step transitions when F is constant, and
   * the noise is transported across the interval (not just summed); with the second-order form
   * the truncation grows as (|F| T)^3. Measured on T6.3 (sigma_N up to 120 s, relative to
   * undecimated Van Loan): Van Loan N = 10, 20: 5e-13; second order N = 10: 6e-6, N = 20:
   * 2.4e-5. On the long-drive replay (200 Hz) N = 1..20 change the horizontal RMS, yaw RMS
   * and outage-end errors by < 1e-4 relative, N = 200 (1 s) by 3e-3 (navsim bench). An update,
   * nav_filter_flush() or nav_filter_set_cov() first completes the pending partial step, so
   * updates always apply to a current P. Default 1.
   */
  unsigned cov_decimation;

  nav_vec3 gyro_arw_rad_per_sqrt_s;  /**< ARW N_g per axis [rad/sqrt(s)], >= 0 */
  nav_vec3 accel_vrw_mps_per_sqrt_s; /**< VRW N_a per axis [m/s/sqrt(s)], >= 0 */

  unsigned gyro_bias_terms;               /**< OR of ::nav_filter_process_term */
  nav_vec3 gyro_bias_gm_sd_rps;           /**< GM: stationary sigma [rad/s], >= 0 */
  nav_vec3 gyro_bias_gm_tau_s;            /**< GM: correlation time T [s], > 0, finite */
  nav_vec3 gyro_bias_rw_rps_per_sqrt_s;   /**< RW: K [rad/s/sqrt(s)], >= 0 */
  unsigned accel_bias_terms;              /**< OR of ::nav_filter_process_term */
  nav_vec3 accel_bias_gm_sd_mps2;         /**< GM: stationary sigma [m/s^2], >= 0 */
  nav_vec3 accel_bias_gm_tau_s;           /**< GM: correlation time T [s], > 0, finite */
  nav_vec3 accel_bias_rw_mps2_per_sqrt_s; /**< RW: K [m/s^2/sqrt(s)], >= 0 */

  unsigned gyro_sf_terms;         /**< scale factors: OR of ::nav_filter_process_term */
  nav_vec3 gyro_sf_gm_sd;         /**< GM sigma, unitless */
  nav_vec3 gyro_sf_gm_tau_s;      /**< GM correlation time [s] */
  nav_vec3 gyro_sf_rw_per_sqrt_s; /**< RW K [1/sqrt(s)] */
  unsigned accel_sf_terms;
  nav_vec3 accel_sf_gm_sd;
  nav_vec3 accel_sf_gm_tau_s;
  nav_vec3 accel_sf_rw_per_sqrt_s;

  nav_vec3 gnss_pos_gm_sd_m;  /**< GNSS GM states: stationary sigma, N/E/D [m], >= 0 */
  nav_vec3 gnss_pos_gm_tau_s; /**< GNSS GM states: correlation time [s], > 0, finite */

  /** RX_CLOCK: spectral densities of the two-state clock model (docs/ins-gnss-tight.md 2.3):
   *  white frequency noise on the bias, q_f = c^2 h_0 / 2 [m^2/s], and random-walk frequency
   *  noise on the drift, q_g = 2 pi^2 c^2 h_-2 [m^2/s^3], from the oscillator's Allan (power-law)
   *  coefficients h_0 and h_-2 (Brown and Hwang, Introduction to Random Signals and Applied
   *  Kalman Filtering, 4th ed., section 9.3). Each >= 0. */
  double clock_bias_q_m2ps;
  double clock_drift_q_m2ps3;

  nav_filter_init_sd init; /**< P0 (diagonal) */

  nav_vec3 gnss_pos_sd_m;   /**< default R of position updates: sigma N/E/D [m], > 0 */
  nav_vec3 gnss_vel_sd_mps; /**< default R of velocity updates: sigma N/E/D [m/s], > 0 */
} nav_filter_config;

/**
 * Defaults: 15 states, second-order discretisation, cov_decimation 1; a tactical-grade IMU
 * (the numerics.md T6.3 unit): ARW 0.15 deg/sqrt(h) = 4.36332e-5 rad/sqrt(s), VRW 0.07 m/s/sqrt(h)
 * = 1.16667e-3 m/s/sqrt(s), GM biases 0.5 deg/h and 0.05 mg with T = 3600 s, no scale-factor
 * process; P0 1 m, 0.1 m/s, 0.1 deg (N, E) and 1 deg (D), biases at their GM sigma, scale
 * factors 100 ppm, GNSS GM 1 m; GNSS GM process sigma 1 m, T = 300 s; R sigmas 1.5, 1.5, 3 m
 * and 0.05 m/s; receiver clock (when its states are chosen) of a low-quality TCXO (h_0 = 2e-19 s,
 * h_-2 = 2e-20 /s) with 100 m, 10 m/s and 10 m (inter-system bias) initial sigmas.
 */
NAV_API nav_filter_config nav_filter_config_default(void);

/**
 * Check a configuration. Problems reported: unknown state or term bits, unknown
 * discretisation, cov_decimation 0, negative or non-finite noise values, GM T <= 0 or infinite
 * where GM is selected, non-positive or non-finite initial sigmas and default R sigmas of the
 * blocks that exist.
 * @param[in] cfg    configuration
 * @param[in] report called once per problem with a field path ("init.att_sd_rad[2]") and a
 *                   message; may be NULL
 * @param[in] user   passed to @p report
 * @return NAV_OK, or NAV_ERR_INVALID_ARG if anything was reported or @p cfg is NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_config_validate(const nav_filter_config *cfg,
                                                            nav_scene_issue_fn report, void *user);

/* ---------------------------------------------------------------- object */

/** The filter. Opaque. */
typedef struct nav_filter nav_filter;

/**
 * What F, G and H need from the navigation solution (all computed by the INS, never truth,
 * except in covariance analysis where the reference trajectory is used).
 */
typedef struct nav_filter_nav {
  double lat_rad;       /**< geodetic latitude [rad], |lat| < pi/2 (cos lat >= 1e-6) */
  double h_m;           /**< ellipsoidal height [m] */
  nav_vec3 v_eb_n_mps;  /**< velocity relative to the Earth, NED [m/s] */
  nav_mat3 C_b_n;       /**< attitude, body to NED */
  nav_vec3 f_ib_b_mps2; /**< compensated specific force, body axes [m/s^2] (mean over the step) */
  nav_vec3 w_ib_b_rps;  /**< compensated angular rate, body axes [rad/s] (mean over the step) */
} nav_filter_nav;

/**
 * Create a filter with x = 0 and P = P0 (diagonal, from cfg->init).
 * @param[in]  cfg configuration (copied)
 * @param[out] out the new filter; destroy with nav_filter_destroy()
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, or nav_filter_config_validate() fails);
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_create(const nav_filter_config *cfg, nav_filter **out);

/** Destroy; accepts NULL. */
NAV_API void nav_filter_destroy(nav_filter *f);

/** Layout of the configured state (indices of the optional blocks). */
NAV_API nav_filter_layout nav_filter_get_layout(const nav_filter *f);

/**
 * Time update over one IMU interval: x <- Phi x, P <- Phi P Phi^T + Q_d (numerics.md 6.3), with
 * F and G evaluated at @p nav. With cov_decimation N > 1 the covariance is propagated on every
 * N-th call (see nav_filter_config.cov_decimation); nav_filter_get_cov() then returns P at the
 * last covariance step.
 * @param[in] f    filter
 * @param[in] nav  navigation state for the linearisation (end or middle of the interval)
 * @param[in] dt_s interval [s], finite and > 0
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, dt_s <= 0); NAV_ERR_OUT_OF_RANGE (cos(lat) <
 *         1e-6: the NED model is singular at the poles); NAV_ERR_NUMERIC (a non-finite input,
 *         the matrix exponential failing, or a propagated P that is not finite, has a
 *         non-positive diagonal entry, or, at the full check of every 16th covariance step, is
 *         not positive definite). On error x, P and the pending accumulation are unchanged and
 *         nav_filter_last_error() says why.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_predict(nav_filter *f, const nav_filter_nav *nav, double dt_s);

/**
 * Complete a pending partial covariance step (cov_decimation > 1); no-op when none is pending.
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL; NAV_ERR_NUMERIC as nav_filter_predict().
 */
NAV_API NAV_NODISCARD nav_status nav_filter_flush(nav_filter *f);

/**
 * GNSS position update (numerics.md E6.3): z = D (r_ant,INS - r_GNSS) in N/E/D metres,
 * H = [I, 0, [(C_b_n l) x], 0, 0, (0, 0), (-I for the GNSS GM block)].
 * @param[in] f          filter
 * @param[in] nav        navigation state at the epoch (C_b_n is used)
 * @param[in] z_pos_ned_m measurement, e.g. from nav_filter_gnss_pos_residual() [m]
 * @param[in] r_diag_m2  R diagonal N/E/D [m^2], each > 0; NULL: the config's gnss_pos_sd_m^2
 * @param[in] l_ba_b_m   lever arm, antenna relative to the IMU, body axes [m]
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL f/nav, R <= 0); NAV_ERR_OUT_OF_RANGE (cos(lat) <
 *         1e-6); NAV_ERR_NUMERIC (non-finite input, S or the updated P not positive definite).
 *         Invalid inputs are rejected before anything changes. With valid inputs a pending
 *         decimated propagation is completed first; if the update itself then fails, x and P are
 *         those of that completed propagation.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_update_gnss_pos(nav_filter *f, const nav_filter_nav *nav,
                                                            nav_vec3 z_pos_ned_m, const nav_vec3 *r_diag_m2,
                                                            nav_vec3 l_ba_b_m);

/**
 * GNSS velocity update (numerics.md E6.4): z = v_ant,INS - v_GNSS [m/s] with
 * v_ant = v + C_b_n (w_ib_b x l) - w_ie_n x (C_b_n l), and
 * H = [0, I, [(C_b_n (w_ib_b x l)) x] - [w_ie_n x][(C_b_n l) x], -C_b_n [l x], 0,
 *      (-C_b_n [l x] diag(w_ib_b), 0), (0)].
 * The Earth-rate part of the attitude column (< 1e-7 m/s per rad and m, dropped in E6.4) is kept
 * because it is free and makes H the exact Jacobian of the measurement function.
 * @param[in] r_diag_m2s2 R diagonal N/E/D [m^2/s^2], each > 0; NULL: the config's gnss_vel_sd_mps^2
 * Other parameters, returns and error behaviour as nav_filter_update_gnss_pos(); nav->lat_rad,
 * C_b_n and w_ib_b_rps are used.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_update_gnss_vel(nav_filter *f, const nav_filter_nav *nav,
                                                            nav_vec3 z_vel_ned_mps,
                                                            const nav_vec3 *r_diag_m2s2, nav_vec3 l_ba_b_m);

/**
 * Generic linear update z = H x + v, v ~ N(0, R), by the same algorithm (Cholesky of S, Joseph).
 * @param[in] m  measurement dimension, 1..NAV_FILTER_MAX_MEAS
 * @param[in] H  m x n row-major (n = layout.n_states)
 * @param[in] z  m measurements
 * @param[in] R  m x m symmetric positive-definite noise covariance (row-major)
 * @return as nav_filter_update_gnss_pos(); NAV_ERR_INVALID_ARG for m out of range.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_update_linear(nav_filter *f, size_t m, const double *H,
                                                          const double *z, const double *R);

/**
 * The normalised innovation squared y^T S^-1 y, y = z - H x, S = H P H^T + R, of a linear
 * measurement without applying it (innovation gating before nav_filter_update_linear()). A
 * pending decimated propagation is completed first (as an update would).
 * @param[out] nis_out the NIS (chi-square with m degrees of freedom when the model holds)
 * @return as nav_filter_update_linear(); x and P are not changed by the test itself.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_nis(nav_filter *f, size_t m, const double *H, const double *z,
                                                const double *R, double *nis_out);

/**
 * Zero the error states that the INS absorbs on feedback (dr, dv, phi, b_g, b_a, s_g, s_a),
 * keeping P (first-order reset, numerics.md 6.5). The GNSS position-error states are not fed
 * back to the INS and keep their estimate.
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_reset_errors(nav_filter *f);

/**
 * Replace P (e.g. a full P0 for covariance analysis). A pending partial covariance step is
 * completed first.
 * @param[in] P n x n row-major; must be finite, symmetric to 1e-12 relative (it is then
 *              symmetrised exactly) and positive definite
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, not symmetric); NAV_ERR_NUMERIC (non-finite or not
 *         positive definite: P is left unchanged).
 */
NAV_API NAV_NODISCARD nav_status nav_filter_set_cov(nav_filter *f, const double *P);

/**
 * State estimate x (n doubles, order of the IDX constants; borrowed, valid until the next
 * non-const call or destroy). With cov_decimation > 1, x and P are those of the last covariance
 * step; nav_filter_flush() brings them to the current epoch.
 */
NAV_API const double *nav_filter_get_state(const nav_filter *f);

/** Covariance P (n x n row-major; borrowed, valid until the next non-const call or destroy; see
 *  nav_filter_get_state() about cov_decimation). */
NAV_API const double *nav_filter_get_cov(const nav_filter *f);

/** The error estimate by block. Plain value. Blocks absent from the layout are zero. */
typedef struct nav_filter_error {
  nav_vec3 dr_ned_m;   /**< position error, N/E/D [m] */
  nav_vec3 dv_n_mps;   /**< velocity error, N/E/D [m/s] */
  nav_vec3 phi_rad;    /**< attitude error (E0.1), NED [rad] */
  nav_vec3 b_g_rps;    /**< residual gyro bias, body [rad/s] */
  nav_vec3 b_a_mps2;   /**< residual accelerometer bias, body [m/s^2] */
  nav_vec3 s_g;        /**< residual gyro scale factor (0 if absent) */
  nav_vec3 s_a;        /**< residual accelerometer scale factor (0 if absent) */
  nav_vec3 gnss_pos_m; /**< GNSS position error estimate, N/E/D [m] (0 if absent) */
} nav_filter_error;

/**
 * Unpack x into named blocks.
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_filter_get_error(const nav_filter *f, nav_filter_error *out);

/** The last measurement update. Plain value, inside the filter. */
typedef struct nav_filter_innovation {
  size_t m;                                            /**< dimension; 0 before the first update */
  double y[NAV_FILTER_MAX_MEAS];                       /**< innovation z - H x_minus */
  double S[NAV_FILTER_MAX_MEAS * NAV_FILTER_MAX_MEAS]; /**< H P_minus H^T + R, m x m row-major */
  double nis;                                          /**< y^T S^-1 y (numerics.md T6.5) */
} nav_filter_innovation;

/** Innovation of the last successful update (borrowed; valid until the next non-const call). */
NAV_API const nav_filter_innovation *nav_filter_last_innovation(const nav_filter *f);

/** Detailed message of the last failure ("" if none). Borrowed, like the other getters. */
NAV_API const char *nav_filter_last_error(const nav_filter *f);

/* ---------------------------------------------------------------- pure helpers */

/** INS state in NED terms plus the INS's accumulated sensor-error estimates. Plain value. */
typedef struct nav_filter_ins_state {
  double lat_rad, lon_rad, h_m; /**< geodetic position [rad, rad, m] */
  nav_vec3 v_eb_n_mps;          /**< velocity, NED [m/s] */
  nav_quat q_b_n;               /**< attitude */
  nav_vec3 b_g_rps;             /**< gyro bias estimate subtracted from the raw rate [rad/s] */
  nav_vec3 b_a_mps2;            /**< accelerometer bias estimate [m/s^2] */
  nav_vec3 s_g;                 /**< gyro scale-factor estimate (unitless) */
  nav_vec3 s_a;                 /**< accelerometer scale-factor estimate (unitless) */
} nav_filter_ins_state;

/**
 * Closed-loop feedback (numerics.md 6.5): lat -= dr_N/(R_M + h), lon -= dr_E/((R_N + h) cos lat),
 * h += dr_D (D^-1 at the INS position), v -= dv, C_b_n <- exp([phi x]) C_b_n (as
 * q_b_n <- q(phi) (x) q_b_n, normalised), b += db, s += ds. The GNSS block is ignored.
 * Pure, thread-safe; NaN propagates. @p out may alias @p in. Longitude is wrapped to (-pi, pi].
 * @param[out] out corrected state
 * @param[in]  in  INS state before the correction
 * @param[in]  dx  estimated errors (nav_filter_get_error())
 */
NAV_API void nav_filter_apply_correction(nav_filter_ins_state *out, const nav_filter_ins_state *in,
                                         const nav_filter_error *dx);

/**
 * Position measurement of E6.3: z = D (r_ant,INS - r_GNSS) with r_ant,INS = r_IMU + D^-1 C_b_n l
 * and D = diag(R_M + h, (R_N + h) cos lat, -1) at the INS position; the longitude difference is
 * wrapped. Pure; NaN propagates.
 * @param[in] ins_pos   INS (IMU) position
 * @param[in] C_b_n     INS attitude
 * @param[in] l_ba_b_m  lever arm, antenna relative to the IMU, body axes [m]
 * @param[in] gnss_pos  measured antenna position
 * @return z_pos_ned_m [m]
 */
NAV_API nav_vec3 nav_filter_gnss_pos_residual(nav_geodetic ins_pos, nav_mat3 C_b_n, nav_vec3 l_ba_b_m,
                                              nav_geodetic gnss_pos);

/**
 * Velocity measurement of E6.4: z = v + C_b_n (w_ib_b x l) - w_ie_n x (C_b_n l) - v_GNSS. Pure.
 * @param[in] nav           INS state (lat_rad, v_eb_n_mps, C_b_n, w_ib_b_rps are used)
 * @param[in] l_ba_b_m      lever arm [m]
 * @param[in] v_gnss_n_mps  measured antenna velocity, NED [m/s]
 * @return z_vel_ned_mps [m/s]
 */
NAV_API nav_vec3 nav_filter_gnss_vel_residual(const nav_filter_nav *nav, nav_vec3 l_ba_b_m,
                                              nav_vec3 v_gnss_n_mps);

NAV_END_DECLS

#endif /* NAV_FILTER_H */
