/**
 * @file nav_sensors.h
 * @brief Sensor error models: IMU (gyro and accelerometer triads), GNSS receiver, datasheet unit
 *        conversions, the bias-instability to Gauss-Markov mapping, and the Allan deviation.
 *
 * Pipeline position (style.md section 1): truth (ideal increments, reference states) -> **sensors**
 * -> navigation. The models read ideal records and emit measured records; the navigation never
 * sees the truth. The per-run error realisations (true biases, scale factors, misalignments, GNSS
 * errors) are readable through getters for the error stage and for filter validation only.
 *
 * @par IMU measurement model (numerics.md E2.3, Groves 2nd ed. section 4.4)
 * Per sample interval (t_(k-1), t_k] of length dt, per triad, in sensor = body axes:
 *
 *     dv~     = (I + M_a) dv     + int b_a dt            + W_a
 *     dtheta~ = (I + M_g) dtheta + int b_g dt + G_g dv  + W_g
 *
 * then saturation (clip to +/- range dt) and quantisation (E2.8, residual carried), in that order,
 * as in a real sensor (the analogue rate saturates, the integrated count is quantised). Here
 * - M = diag(s) + off-diagonal misalignment m_ij (unitless), drawn once per run;
 * - b = b_0 (turn-on, drawn once per run) + b_GM(t) (first-order Gauss-Markov) + b_RW(t) (random
 *   walk); int b dt is the exact integral of the continuous bias over the interval (see below);
 * - G_g is the gyro g-sensitivity [rad/s per m/s^2], applied to the *true* dv;
 * - W ~ N(0, N^2 dt) per axis, N the ARW [rad/sqrt(s)] or VRW [m/s/sqrt(s)] coefficient, so the
 *   statistics of the output do not depend on the sample rate.
 *
 * @par Bias discretisation: exact integral, not a point sample
 * The increment must contain the integral of the bias over the interval. For the Gauss-Markov
 * bias (db/dt = -b/T + w, E[w w] = q delta, q = 2 sigma^2 / T) the pair (b_k, I_k = integral of
 * b over the interval) is jointly Gaussian given b_(k-1), and is drawn exactly (Van Loan's
 * integral in closed form, numerics.md 6.3 [VL]):
 *
 *     b_k = phi b_(k-1) + e1,   I_k = T (1 - phi) b_(k-1) + e2,   phi = exp(-dt / T)
 *     Var e1 = sigma^2 (1 - phi^2)              (this is E2.4: b_k is exactly the paper's recursion)
 *     Cov(e1, e2) = sigma^2 T (1 - phi)^2
 *     Var e2 = 2 sigma^2 T^2 f(dt/T),  f(x) = x - 3/2 + 2 exp(-x) - exp(-2x)/2
 *
 * and for the random walk (db/dt = w, E[w w] = K^2 delta):
 *
 *     b_k = b_(k-1) + e1,   I_k = b_(k-1) dt + e2,
 *     Var e1 = K^2 dt,  Cov = K^2 dt^2 / 2,  Var e2 = K^2 dt^3 / 3.
 *
 * Each pair is drawn from two normals of the term's own per-axis stream (Cholesky factor of the
 * 2x2 covariance). Consequences: the bias state b_k follows E2.4/E2.7 exactly (stationary start
 * E2.5 for the GM, b_RW(0) = 0 for the random walk); the measured increments are exact samples
 * of the continuous-time model, so the Allan deviation of the output equals the continuous-time
 * formula (E2.6, K sqrt(tau/3)) at every tau = m dt including tau = dt, and a run at 100 Hz and
 * one at 1 kHz have identical statistics over any common averaging time. A point-sampled bias
 * (b_k dt) would instead give sqrt(1 - phi) at tau = dt (numerics.md T2.2 note). Cost: two
 * normals per axis per sample for each of these two terms.
 *
 * @par Random streams (numerics.md 2.1, T2.6)
 * Every term has its own nav_rng stream per axis, named nav_rng_stream_id(kind, channel) with the
 * kinds of nav_rng.h (NAV_RNG_STREAM_GYRO_NOISE, ..._BIAS_TURN_ON, ..._BIAS_GM, ..._BIAS_RW,
 * ..._SCALE_FACTOR, ..._MISALIGNMENT, ..._G_SENSITIVITY and the ACCEL_ kinds), channel = axis
 * 0/1/2 for vector terms and 3 i + j for matrix element (i, j). Per-run constants are drawn at
 * create time, the GM start value is the first draw of its stream. Switching a term on or off, or
 * changing its parameters, therefore never changes another term's (or another axis') realisation.
 *
 * @par Enable masks
 * Every term is switched by a bit of the triad's @c terms mask (::nav_imu_term); a term whose bit
 * is clear is not evaluated at all and its fields are ignored (not even validated). A term whose
 * bit is set with a zero sigma is valid and contributes exactly zero, while still consuming its
 * own stream, which is what T2.6 uses to prove stream independence. No field value ever means
 * "off". Each enabled term costs one branch per sample, then straight-line per-axis arithmetic.
 *
 * @par Example: an ADIS16465-class gyro triad at 200 Hz
 * @code
 * nav_imu_model_config cfg = nav_imu_model_config_default();
 * const nav_gm_params gm = nav_gm_from_bias_instability(nav_unit_deg_per_h_to_rps(2.0), 300.0,
 *                                                       NAV_BI_ALLAN_PEAK);
 * cfg.gyro.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM;
 * const double n = nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.15);
 * cfg.gyro.arw_rad_per_sqrt_s = nav_vec3_make(n, n, n);
 * cfg.gyro.bias_gm_sd_rps = nav_vec3_make(gm.sigma, gm.sigma, gm.sigma);
 * cfg.gyro.bias_gm_tau_s = nav_vec3_make(gm.tau_s, gm.tau_s, gm.tau_s);
 * nav_imu_model *imu = NULL;
 * if (nav_imu_model_create(&cfg, seed, run, &imu) != NAV_OK) { ... }
 * nav_imu_increment ideal, meas;   // ideal from nav_truth_imu()
 * if (nav_imu_model_apply(imu, &ideal, &meas) != NAV_OK) { ... }
 * nav_imu_model_destroy(imu);
 * @endcode
 *
 * @par Threading
 * Models are not synchronised: one thread per object. Different objects are independent. The
 * free functions (units, Allan, mapping) are pure and thread-safe.
 */
#ifndef NAV_SENSORS_H
#define NAV_SENSORS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "nav_earth.h"
#include "nav_export.h"
#include "nav_frames.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_sensor_config.h"
#include "nav_status.h"
#include "nav_traj.h"
#include "nav_truth.h"

NAV_BEGIN_DECLS

/* ============================================================================ unit conversions */

/**
 * @name Datasheet units to SI (numerics.md 2.2 and 2.4; IEEE Std 952-1997 Annex C, IEEE Std
 * 1293-1998). These are the only conversions from datasheet units in navcore; navcore_io and the
 * apps call them at the input edge. "g" units use standard gravity g0 = NAV_G0_MPS2 = 9.80665
 * m/s^2 (numerics.md 0.4), never local gravity. A datasheet "noise density" is taken as the
 * two-sided density N itself (industry practice, numerics.md 2.2: ARW [deg/sqrt(h)] = 60 x
 * density [deg/s/sqrt(Hz)]). All functions are pure, exact up to one rounding per factor, and
 * accept any finite value (negative values are converted as such).
 * @{
 */

/** Degrees to radians. */
static inline double nav_unit_deg_to_rad(double deg) {
  return deg * (NAV_PI / 180.0);
}
/** Milliradians to radians (misalignment, numerics.md 2.1: mrad x 1e-3). */
static inline double nav_unit_mrad_to_rad(double mrad) {
  return mrad * 1e-3;
}
/** Parts per million to a unitless ratio (scale factor, numerics.md 2.1: ppm x 1e-6). */
static inline double nav_unit_ppm_to_ratio(double ppm) {
  return ppm * 1e-6;
}
/** Rate deg/s to rad/s (gyro range, turn-on bias in deg/s). */
static inline double nav_unit_deg_per_s_to_rps(double dps) {
  return dps * (NAV_PI / 180.0);
}
/** Rate deg/h to rad/s (bias, bias instability): x (pi/180)/3600. 1 deg/h = 4.84814e-6 rad/s. */
static inline double nav_unit_deg_per_h_to_rps(double dph) {
  return dph * (NAV_PI / 180.0) / 3600.0;
}
/**
 * Angle random walk deg/sqrt(h) to rad/sqrt(s): x (pi/180)/60 (numerics.md 2.2).
 * Example: 0.15 deg/sqrt(h) = 4.36332e-5 rad/sqrt(s).
 */
static inline double nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(double x) {
  return x * (NAV_PI / 180.0) / 60.0;
}
/**
 * Rate noise density deg/s/sqrt(Hz) to rad/sqrt(s): x pi/180 (numerics.md 2.2).
 * Example: 0.007 deg/s/sqrt(Hz) = 1.22173e-4 rad/sqrt(s) (= 0.42 deg/sqrt(h)).
 */
static inline double nav_unit_deg_per_s_per_sqrt_hz_to_rad_per_sqrt_s(double x) {
  return x * (NAV_PI / 180.0);
}
/** Rate noise density deg/h/sqrt(Hz) to rad/sqrt(s): x (pi/180)/3600 (numerics.md 2.2). */
static inline double nav_unit_deg_per_h_per_sqrt_hz_to_rad_per_sqrt_s(double x) {
  return x * (NAV_PI / 180.0) / 3600.0;
}
/**
 * Rate random walk deg/h/sqrt(h) to rad/s/sqrt(s): x (pi/180)/3600/60 (numerics.md 2.4, E2.7).
 */
static inline double nav_unit_deg_per_h_per_sqrt_h_to_rps_per_sqrt_s(double x) {
  return x * (NAV_PI / 180.0) / 3600.0 / 60.0;
}
/** Gyro g-sensitivity deg/h/g to rad/s per m/s^2: x (pi/180)/3600/g0. */
static inline double nav_unit_deg_per_h_per_g_to_rps_per_mps2(double x) {
  return x * (NAV_PI / 180.0) / 3600.0 / NAV_G0_MPS2;
}
/**
 * Velocity random walk m/s/sqrt(h) to m/s/sqrt(s): x / 60 (numerics.md 2.2).
 * Example: 0.07 m/s/sqrt(h) = 1.16667e-3 m/s/sqrt(s).
 */
static inline double nav_unit_mps_per_sqrt_h_to_mps_per_sqrt_s(double x) {
  return x / 60.0;
}
/**
 * Velocity random walk ft/s/sqrt(h) to m/s/sqrt(s): x 0.3048/60 (numerics.md 2.2; 1 ft = 0.3048 m
 * exactly). Example: 0.065 ft/s/sqrt(h) = 3.302e-4 m/s/sqrt(s).
 */
static inline double nav_unit_ft_per_s_per_sqrt_h_to_mps_per_sqrt_s(double x) {
  return x * 0.3048 / 60.0;
}
/** Acceleration g to m/s^2: x g0 (accelerometer range). */
static inline double nav_unit_g_to_mps2(double g) {
  return g * NAV_G0_MPS2;
}
/** Acceleration mg to m/s^2: x 1e-3 g0 (turn-on bias). 1 mg = 9.80665e-3 m/s^2. */
static inline double nav_unit_mg_to_mps2(double mg) {
  return mg * 1e-3 * NAV_G0_MPS2;
}
/** Acceleration ug to m/s^2: x 1e-6 g0 (bias instability). 1 ug = 9.80665e-6 m/s^2. */
static inline double nav_unit_ug_to_mps2(double ug) {
  return ug * 1e-6 * NAV_G0_MPS2;
}
/**
 * Acceleration noise density ug/sqrt(Hz) to m/s/sqrt(s) (= m/s^2/sqrt(Hz)): x 1e-6 g0
 * (numerics.md 2.2). Example: 100 ug/sqrt(Hz) = 9.80665e-4 m/s/sqrt(s) (= 0.0588 m/s/sqrt(h)).
 */
static inline double nav_unit_ug_per_sqrt_hz_to_mps_per_sqrt_s(double x) {
  return x * 1e-6 * NAV_G0_MPS2;
}
/** Acceleration random walk m/s^2/sqrt(h) to m/s^2/sqrt(s): x / 60 (E2.7 units). */
static inline double nav_unit_mps2_per_sqrt_h_to_mps2_per_sqrt_s(double x) {
  return x / 60.0;
}

/**
 * GNSS accuracy figures to a 1-sigma per-axis standard deviation (numerics.md section 7; circular
 * normal with equal per-axis sigma): CEP = 1.1774 sigma (sqrt(2 ln 2)), 2D 95 % radius = 2.4477
 * sigma (sqrt(-2 ln 0.05)), 1D 95 % = 1.96 sigma (1.959964).
 */
static inline double nav_unit_cep_to_sigma_m(double cep_m) {
  return cep_m / 1.1774100225154747;
}
/** 2D 95 % horizontal radius to per-axis sigma: / sqrt(-2 ln 0.05) = / 2.4477468. */
static inline double nav_unit_h95_to_sigma_m(double r95_m) {
  return r95_m / 2.4477468306808166;
}
/** 1D 95 % (e.g. vertical) to sigma: / 1.959964 (normal 97.5 % quantile). */
static inline double nav_unit_v95_to_sigma_m(double v95_m) {
  return v95_m / 1.959963984540054;
}
/** @} */

/* ============================================================ bias instability -> Gauss-Markov */

/**
 * Location of the maximum of the first-order GM Allan deviation (E2.6), as a multiple of the
 * correlation time T: tau_peak = 1.8926 T. Computed here by golden-section maximisation of E2.6
 * in double precision (numerics.md 2.3 quotes 1.8926, verified).
 */
#define NAV_GM_ALLAN_PEAK_TAU_RATIO 1.892617797645221
/** Maximum of the GM Allan deviation divided by sigma: 0.61736 (same computation; numerics.md 2.3). */
#define NAV_GM_ALLAN_PEAK_SIGMA_RATIO 0.6173642831444413

/** How a datasheet bias instability B maps to the sigma of a first-order GM bias. */
typedef enum nav_bi_convention {
  /**
   * sigma = B / 0.61736 = 1.620 B, so that the model's Allan deviation peaks at B (numerics.md 2.3;
   * Allan-peak matching). B is the Allan-deviation floor as ADI, Safran Sensonor and Honeywell
   * quote it.
   */
  NAV_BI_ALLAN_PEAK = 0,
  /** sigma = B (the KF-GINS and gnss-ins-sim convention; the Allan peak is then 0.617 B). */
  NAV_BI_SIGMA_EQUALS_B = 1
} nav_bi_convention;

/** Parameters of a first-order Gauss-Markov process. */
typedef struct nav_gm_params {
  double sigma; /**< stationary standard deviation, in the unit of the B it came from */
  double tau_s; /**< correlation time T [s] */
} nav_gm_params;

/**
 * GM parameters from a datasheet bias instability (numerics.md 2.3 and section 7).
 *
 * T = tau_min / 1.8926 in both conventions: the GM's Allan peak is placed where the real curve
 * has its floor; only sigma differs (see ::nav_bi_convention). A single GM reproduces a flicker
 * floor over about one decade of tau only.
 *
 * @param[in] b_instability B, any unit (rad/s or m/s^2 normally); >= 0.
 * @param[in] tau_min_s     location of the Allan-deviation minimum [s], > 0. If the datasheet does
 *                          not give it, numerics.md 2.3 suggests 100-1000 s for MEMS and 1-4 h for
 *                          FOG/RLG.
 * @param[in] convention    sigma mapping.
 * @return {sigma, tau_s}. Pure; NaN in gives NaN out; an unknown convention gives NaN sigma.
 */
NAV_API nav_gm_params nav_gm_from_bias_instability(double b_instability, double tau_min_s,
                                                   nav_bi_convention convention);

/**
 * GM sigma from a bias instability B under @p convention (the sigma part of
 * nav_gm_from_bias_instability(), for callers that know T itself, e.g. a catalog correlation
 * time). @return B / 0.61736 or B; NaN for an unknown convention.
 */
NAV_API double nav_gm_sigma_from_bias_instability(double b_instability, nav_bi_convention convention);

/** Name of a convention as written in scene files and the catalog tool ("allan_peak", "sigma_equals_b"). */
NAV_API const char *nav_bi_convention_name(nav_bi_convention c);

/* ======================================================================== IMU error model */

/** The ideal IMU: every term off, every value 0. Override fields from here (style.md 6). */
NAV_API nav_imu_model_config nav_imu_model_config_default(void);

/**
 * Check a configuration: unknown term bits, G_SENSITIVITY in the accelerometer mask, non-finite or
 * negative values of enabled terms, GM T <= 0 or infinite, quantisation step or range <= 0,
 * non-zero misalignment diagonals. Fields of disabled terms are not checked.
 * @param[in] cfg    the configuration
 * @param[in] report called once per problem with a field path such as "gyro.bias_gm_tau_s[1]"
 *                   (relative to the configuration; prefix "imu." when it comes from a scene) and
 *                   a message saying what is expected. May be NULL.
 * @param[in] user   passed to @p report
 * @return NAV_OK, or NAV_ERR_INVALID_ARG if anything was reported or @p cfg is NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_imu_model_config_validate(const nav_imu_model_config *cfg,
                                                               nav_scene_issue_fn report, void *user);

/** An IMU error model with its per-run constants and in-run states. Opaque. */
typedef struct nav_imu_model nav_imu_model;

/**
 * Create the error model of Monte Carlo run @p run: draws every per-run constant (turn-on biases,
 * scale factors, misalignments, g-sensitivity, the GM start values) from its own stream
 * (seed, run, nav_rng_stream_id(kind, channel)). Allocates once; nothing is allocated later.
 * @param[in]  cfg  configuration (copied; not kept)
 * @param[in]  seed scene seed
 * @param[in]  run  Monte Carlo run index
 * @param[out] out  the new model; written only on NAV_OK. Destroy with nav_imu_model_destroy().
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL argument or invalid configuration: call
 *         nav_imu_model_config_validate() for the reasons); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_imu_model_create(const nav_imu_model_config *cfg, uint64_t seed,
                                                      uint64_t run, nav_imu_model **out);

/** Destroy a model; accepts NULL. */
NAV_API void nav_imu_model_destroy(nav_imu_model *model);

/**
 * Apply the errors to one ideal increment (the next interval; calls must follow the sample order).
 *
 * The bias processes advance by @c ideal->dt_s. Coefficients depending on dt are computed when dt
 * changes (once for a constant-rate IMU) and cached. Never allocates.
 *
 * @param[in,out] model the model; its bias states advance
 * @param[in]     ideal ideal increments over (t_s - dt_s, t_s]: dtheta_b_rad [rad], dv_b_mps [m/s],
 *                      body axes; dt_s > 0 [s]
 * @param[out]    measured k, t_s, dt_s copied; dtheta_b_rad and dv_b_mps with errors. May alias
 *                      @p ideal. Written only on NAV_OK.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, dt_s not finite and > 0); NAV_ERR_NUMERIC (non-finite
 *         increment). On error the model is unchanged and nav_imu_model_last_error() says why.
 */
NAV_API NAV_NODISCARD nav_status nav_imu_model_apply(nav_imu_model *model, const nav_imu_increment *ideal,
                                                     nav_imu_increment *measured);

/** Per-run constants of a model (drawn at create). */
typedef struct nav_imu_run_constants {
  nav_vec3 gyro_bias_turn_on_rps;   /**< b_0,g [rad/s] (0 when the term is off) */
  nav_vec3 accel_bias_turn_on_mps2; /**< b_0,a [m/s^2] */
  nav_mat3 M_g;                     /**< gyro scale factor (diagonal) and misalignment, unitless */
  nav_mat3 M_a;                     /**< accelerometer M, unitless */
  nav_mat3 G_g_rps_per_mps2;        /**< gyro g-sensitivity [rad/s per m/s^2] */
} nav_imu_run_constants;

/** Saturation flags of the last sample (::nav_imu_bias_state.saturated): bit = sensor axis. */
enum {
  NAV_IMU_SAT_GYRO_X = 1u << 0,
  NAV_IMU_SAT_GYRO_Y = 1u << 1,
  NAV_IMU_SAT_GYRO_Z = 1u << 2,
  NAV_IMU_SAT_ACCEL_X = 1u << 3,
  NAV_IMU_SAT_ACCEL_Y = 1u << 4,
  NAV_IMU_SAT_ACCEL_Z = 1u << 5
};

/**
 * True bias states after the last applied sample (at t_k), for the error stage and filter
 * validation only. Before the first sample they hold the t = 0 values (GM start draw, RW 0).
 */
typedef struct nav_imu_bias_state {
  int64_t k;                  /**< index of the last applied sample (-1 before the first) */
  double t_s;                 /**< its time (0 before the first) */
  nav_vec3 gyro_gm_rps;       /**< GM bias state b_GM(t_k) [rad/s] */
  nav_vec3 gyro_rw_rps;       /**< random-walk bias state b_RW(t_k) [rad/s] */
  nav_vec3 gyro_rps;          /**< total bias b_0 + b_GM + b_RW at t_k [rad/s] */
  nav_vec3 gyro_mean_rps;     /**< total bias averaged over the last interval = its contribution / dt */
  nav_vec3 accel_gm_mps2;     /**< accelerometer GM state [m/s^2] */
  nav_vec3 accel_rw_mps2;     /**< accelerometer random-walk state [m/s^2] */
  nav_vec3 accel_mps2;        /**< total accelerometer bias at t_k [m/s^2] */
  nav_vec3 accel_mean_mps2;   /**< interval average [m/s^2] */
  unsigned saturated;         /**< NAV_IMU_SAT_* bits of the last sample */
  uint64_t saturated_samples; /**< samples with at least one saturated axis so far */
} nav_imu_bias_state;

/**
 * The per-run constants. @return a borrowed pointer, valid until nav_imu_model_destroy(); the
 * constants never change. NULL for a NULL model.
 */
NAV_API const nav_imu_run_constants *nav_imu_model_constants(const nav_imu_model *model);

/**
 * The true bias states after the last sample. @return a borrowed pointer, valid (and updated in
 * place) until the next nav_imu_model_apply() or destroy; copy it to keep it. NULL for NULL.
 */
NAV_API const nav_imu_bias_state *nav_imu_model_bias(const nav_imu_model *model);

/** Last error message of @p model ("" if none). Borrowed; valid until the next call on the model. */
NAV_API const char *nav_imu_model_last_error(const nav_imu_model *model);

/* ======================================================================== GNSS receiver model */

/** A perfect 1 Hz receiver at the IMU (no terms, no lever arm, no outage, latency 0, model sigmas). */
NAV_API nav_gnss_model_config nav_gnss_model_config_default(void);

/**
 * Check a GNSS configuration (paths such as "pos_gm_tau_s[2]", "outages[3].t1_s"; prefix "gnss."
 * in scenes). @return NAV_OK or NAV_ERR_INVALID_ARG (also for NULL @p cfg). @p report may be NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_model_config_validate(const nav_gnss_model_config *cfg,
                                                                nav_scene_issue_fn report, void *user);

/** One GNSS fix: the measured antenna position and velocity at its time of validity. */
typedef struct nav_gnss_fix {
  int64_t epoch;       /**< epoch index j */
  double t_s;          /**< time of validity j / update_rate_hz [s] */
  double t_avail_s;    /**< time the fix becomes available: t_s + latency_s [s] */
  nav_geodetic pos;    /**< measured antenna position (flat Earth: tangent-plane mapping through the
                            scene origin, as nav_frame_view()) */
  nav_vec3 r_fa_f_m;   /**< the same point in the scene frame F (l or ECEF) [m] */
  nav_vec3 v_fa_n_mps; /**< measured antenna velocity relative to F, resolved in local NED [m/s] */
  nav_vec3 pos_sd_m;   /**< reported 1-sigma of the position error, N/E/D [m] */
  nav_vec3 vel_sd_mps; /**< reported 1-sigma of the velocity error, N/E/D [m/s] */
} nav_gnss_fix;

/** True errors of the last epoch (validation only): measured minus true antenna, N/E/D. */
typedef struct nav_gnss_error_state {
  int64_t epoch;     /**< last epoch processed (-1 before the first) */
  nav_vec3 pos_gm_m; /**< GM part of the position error [m] */
  nav_vec3 pos_m;    /**< total position error [m] */
  nav_vec3 vel_mps;  /**< velocity error [m/s] */
} nav_gnss_error_state;

/** A GNSS receiver model. Opaque. */
typedef struct nav_gnss_model nav_gnss_model;

/**
 * Create the receiver model of Monte Carlo run @p run (streams NAV_RNG_STREAM_GNSS_POS channels
 * 0-2 for the GM, 3-5 for white position noise; NAV_RNG_STREAM_GNSS_VEL channels 0-2).
 * @param[in]  cfg   configuration (copied)
 * @param[in]  frame the scene frame F the truth states are expressed in (copied); see nav_frames.h
 * @param[in]  seed  scene seed
 * @param[in]  run   Monte Carlo run
 * @param[out] out   new model, written only on NAV_OK
 * @return NAV_OK, NAV_ERR_INVALID_ARG (NULL or invalid configuration), NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_model_create(const nav_gnss_model_config *cfg,
                                                       const nav_frame *frame, uint64_t seed, uint64_t run,
                                                       nav_gnss_model **out);

/** Destroy; accepts NULL. */
NAV_API void nav_gnss_model_destroy(nav_gnss_model *model);

/** Time of validity of epoch @p epoch: epoch / update_rate_hz [s] (one rounding, never accumulated). */
NAV_API double nav_gnss_model_epoch_time_s(const nav_gnss_model *model, int64_t epoch);

/**
 * Measure epoch @p epoch from the body's true state at its time of validity.
 *
 * The antenna is at r_fa_f = r_fb_f + C_b_f r_ba_b, moving with v_fa_f = v_fb_f + C_b_f (w_fb_b x
 * r_ba_b) (rigid body, relative to F; numerics.md E6.3-E6.4 in F). The N/E/D errors are added in
 * the local-level frame at the antenna and mapped back to F and geodetic coordinates exactly
 * (valid at the poles with F = ECEF).
 *
 * Epochs must increase; skipped epochs (including outage epochs the caller does not ask for) are
 * still drawn internally, so the error at epoch j depends only on (seed, run, j) and the
 * configuration, never on which epochs were requested. Outages: for an epoch inside an outage
 * the processes advance, *has_fix is false and @p fix is not written.
 *
 * @param[in,out] model  the model
 * @param[in]     epoch  j >= 0, greater than the previous call's
 * @param[in]     truth  true body state in F at t = epoch time (|truth->t_s - t| <= 1 us is checked);
 *                       uses r_fb_f_m, v_fb_f_mps, q_b_f, w_fb_b_rps
 * @param[out]    fix    the fix when *has_fix
 * @param[out]    has_fix true when a fix was produced
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, negative epoch, time mismatch); NAV_ERR_STATE (epoch
 *         not increasing); NAV_ERR_NUMERIC (non-finite truth). nav_gnss_model_last_error() says why.
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_model_measure(nav_gnss_model *model, int64_t epoch,
                                                        const nav_traj_state *truth, nav_gnss_fix *fix,
                                                        bool *has_fix);

/** True errors of the last processed epoch. Borrowed; valid until the next measure or destroy. */
NAV_API const nav_gnss_error_state *nav_gnss_model_errors(const nav_gnss_model *model);

/** Last error message ("" if none). Borrowed; valid until the next call on the model. */
NAV_API const char *nav_gnss_model_last_error(const nav_gnss_model *model);

/* ======================================================================== Allan deviation */

/**
 * Overlapping Allan deviation of a rate series (numerics.md 2.5, IEEE Std 952-1997 Annex C;
 * Riley, NIST SP 1065 eq. 14).
 *
 * With the phase theta_0 = 0, theta_j = sum_{i<j} (y_i - ybar) dt (j = 1..n; the mean ybar is
 * removed first, which changes nothing mathematically because second differences cancel a linear
 * phase, but keeps the cumulative sum small), for each cluster size m:
 *
 *     sigma_A^2(m dt) = sum_{j=0}^{n-2m} (theta_{j+2m} - 2 theta_{j+m} + theta_j)^2 / (2 (m dt)^2 (n + 1 -
 * 2m))
 *
 * O(n) per cluster size, no allocation.
 *
 * @param[in]  rate     n samples of a rate (any unit u; e.g. gyro increments / dt in rad/s)
 * @param[in]  n        number of samples, >= 2
 * @param[in]  dt_s     sample interval [s], finite and > 0 (tau_i = m[i] dt_s; the deviation
 *                      itself depends only on m)
 * @param[in]  m        n_m cluster sizes, each in [1, n/2]
 * @param[in]  n_m      number of cluster sizes (0 is allowed: nothing to do)
 * @param[out] work     caller workspace of n + 1 doubles (the cumulative sum); overwritten
 * @param[out] adev_out n_m Allan deviations [u], in the order of @p m. Written only on NAV_OK.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL pointer with n_m > 0, n < 2, bad dt_s, m out of range);
 *         NAV_ERR_NUMERIC (non-finite sample). Thread-safe (no shared state).
 */
NAV_API NAV_NODISCARD nav_status nav_allan_overlapping(const double *rate, size_t n, double dt_s,
                                                       const size_t *m, size_t n_m, double *work,
                                                       double *adev_out);

/**
 * Log-spaced cluster sizes for an Allan plot: the distinct values of round(10^(i / per_decade)),
 * i = 0, 1, ..., not above m_max (always starting with 1).
 * @param[in]  m_max      largest cluster size (for n samples at most n / 2; n / 10 keeps the
 *                        relative uncertainty of the last point under about 25 %), >= 1
 * @param[in]  per_decade points per decade, 1..100
 * @param[out] m_out      receives the sizes in increasing order; NULL to only count
 * @param[in]  capacity   capacity of @p m_out
 * @param[out] count      number of sizes (also when @p m_out is NULL or too small)
 * @return NAV_OK; NAV_ERR_OUT_OF_RANGE if capacity is too small (nothing written to m_out);
 *         NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_allan_log_clusters(size_t m_max, unsigned per_decade, size_t *m_out,
                                                        size_t capacity, size_t *count);

/**
 * Approximate relative 1-sigma uncertainty of an Allan *deviation* estimate from n samples at
 * cluster size m: 1 / sqrt(2 (n / m - 1)) (numerics.md 2.5, IEEE Std 952-1997 Annex C; exact for
 * the non-overlapping estimator, conservative for the overlapping one). @return +inf when
 * n <= m.
 */
NAV_API double nav_allan_rel_uncertainty(size_t n, size_t m);

NAV_END_DECLS

#endif /* NAV_SENSORS_H */
