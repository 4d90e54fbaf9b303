/**
 * @file nav_sensor_config.h
 * @brief Configuration value types of the IMU and GNSS receiver error models (SI units).
 *
 * Kept apart from nav_sensors.h (the model objects) so that the scene (nav_scene.h) can hold
 * them by value without an include cycle. Datasheet units are converted once, in navcore_io.
 */
#ifndef NAV_SENSOR_CONFIG_H
#define NAV_SENSOR_CONFIG_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_export.h"
#include "nav_math.h"

NAV_BEGIN_DECLS

/** IMU error terms, one bit each, in ::nav_gyro_error_config.terms / ::nav_accel_error_config.terms. */
typedef enum nav_imu_term {
  NAV_IMU_TERM_BIAS_TURN_ON = 1u << 0,  /**< b_0 = fixed + sd u, drawn once per run */
  NAV_IMU_TERM_BIAS_GM = 1u << 1,       /**< first-order Gauss-Markov in-run bias (E2.4-E2.6) */
  NAV_IMU_TERM_BIAS_RW = 1u << 2,       /**< bias random walk (E2.7) */
  NAV_IMU_TERM_NOISE = 1u << 3,         /**< white noise, ARW / VRW (E2.3) */
  NAV_IMU_TERM_SCALE_FACTOR = 1u << 4,  /**< diagonal of M: fixed + sd u, once per run */
  NAV_IMU_TERM_MISALIGNMENT = 1u << 5,  /**< off-diagonal of M: fixed + sd u, once per run */
  NAV_IMU_TERM_G_SENSITIVITY = 1u << 6, /**< gyro only: G_g dv, fixed + sd u, once per run */
  NAV_IMU_TERM_QUANTISATION = 1u << 7,  /**< increment quantisation with carried residual (E2.8) */
  NAV_IMU_TERM_SATURATION = 1u << 8     /**< clip the increment to +/- range dt, flag it */
} nav_imu_term;

/** Every gyro term. */
#define NAV_IMU_TERMS_GYRO_ALL 0x1FFu
/** Every accelerometer term (no g-sensitivity). */
#define NAV_IMU_TERMS_ACCEL_ALL (0x1FFu & ~(unsigned)NAV_IMU_TERM_G_SENSITIVITY)

/**
 * Gyro triad error parameters, SI, sensor axes x/y/z (= body FRD). Per-run random constants are
 * value = fixed + sd u, u ~ N(0, 1) from the term's own stream; set sd to 0 for a known unit, fixed
 * to 0 for a population. Fields of terms whose bit is clear in @c terms are ignored.
 */
typedef struct nav_gyro_error_config {
  unsigned terms;                  /**< OR of ::nav_imu_term */
  nav_vec3 bias_turn_on_fixed_rps; /**< BIAS_TURN_ON: deterministic part of b_0 [rad/s] */
  nav_vec3 bias_turn_on_sd_rps;    /**< BIAS_TURN_ON: 1-sigma of b_0 [rad/s], >= 0 */
  nav_vec3 bias_gm_sd_rps;         /**< BIAS_GM: stationary sigma [rad/s], >= 0 */
  nav_vec3 bias_gm_tau_s;          /**< BIAS_GM: correlation time T [s], > 0, finite */
  nav_vec3 bias_rw_rps_per_sqrt_s; /**< BIAS_RW: rate random walk K [rad/s/sqrt(s)], >= 0 */
  nav_vec3 arw_rad_per_sqrt_s;     /**< NOISE: angle random walk N [rad/sqrt(s)], >= 0 */
  nav_vec3 scale_factor_fixed;     /**< SCALE_FACTOR: deterministic s_i (unitless; 1e-6 = 1 ppm) */
  nav_vec3 scale_factor_sd;        /**< SCALE_FACTOR: 1-sigma of s_i (unitless), >= 0 */
  nav_mat3 misalignment_fixed_rad; /**< MISALIGNMENT: deterministic m_ij [rad]; diagonal must be 0 */
  nav_mat3 misalignment_sd_rad;    /**< MISALIGNMENT: 1-sigma of m_ij [rad], >= 0; diagonal must be 0 */
  nav_mat3 g_sensitivity_fixed_rps_per_mps2; /**< G_SENSITIVITY: deterministic G_g [rad/s per m/s^2]; full
                                                  matrix, diagonal only for per-axis data */
  nav_mat3 g_sensitivity_sd_rps_per_mps2;    /**< G_SENSITIVITY: 1-sigma of each element, >= 0 */
  nav_vec3 quant_step_rad;                   /**< QUANTISATION: angle increment LSB [rad], > 0 */
  nav_vec3 range_rps; /**< SATURATION: measurement range |omega| <= range [rad/s], > 0 */
} nav_gyro_error_config;

/** Accelerometer triad error parameters, SI, sensor axes; as ::nav_gyro_error_config. */
typedef struct nav_accel_error_config {
  unsigned terms;                   /**< OR of ::nav_imu_term (G_SENSITIVITY is invalid here) */
  nav_vec3 bias_turn_on_fixed_mps2; /**< BIAS_TURN_ON: deterministic part of b_0 [m/s^2] */
  nav_vec3 bias_turn_on_sd_mps2;    /**< BIAS_TURN_ON: 1-sigma of b_0 [m/s^2], >= 0 */
  nav_vec3 bias_gm_sd_mps2;         /**< BIAS_GM: stationary sigma [m/s^2], >= 0 */
  nav_vec3 bias_gm_tau_s;           /**< BIAS_GM: correlation time T [s], > 0, finite */
  nav_vec3 bias_rw_mps2_per_sqrt_s; /**< BIAS_RW: acceleration random walk K [m/s^2/sqrt(s)], >= 0 */
  nav_vec3 vrw_mps_per_sqrt_s;      /**< NOISE: velocity random walk N [m/s/sqrt(s)], >= 0 */
  nav_vec3 scale_factor_fixed;      /**< SCALE_FACTOR: deterministic s_i (unitless) */
  nav_vec3 scale_factor_sd;         /**< SCALE_FACTOR: 1-sigma of s_i (unitless), >= 0 */
  nav_mat3 misalignment_fixed_rad;  /**< MISALIGNMENT: deterministic m_ij [rad]; diagonal must be 0 */
  nav_mat3 misalignment_sd_rad;     /**< MISALIGNMENT: 1-sigma of m_ij [rad]; diagonal must be 0 */
  nav_vec3 quant_step_mps;          /**< QUANTISATION: velocity increment LSB [m/s], > 0 */
  nav_vec3 range_mps2;              /**< SATURATION: range |f| <= range [m/s^2], > 0 */
} nav_accel_error_config;

/** IMU error model configuration: one gyro and one accelerometer triad. */
typedef struct nav_imu_model_config {
  nav_gyro_error_config gyro;
  nav_accel_error_config accel;
} nav_imu_model_config;

/** Maximum number of outage intervals in one configuration (kept inline: configs are values). */
#define NAV_GNSS_MAX_OUTAGES 32

/** A GNSS outage: no fix has its time of validity in [t0_s, t1_s). */
typedef struct nav_gnss_outage {
  double t0_s; /**< start [s] from the scene epoch */
  double t1_s; /**< end [s], > t0_s */
} nav_gnss_outage;

/** GNSS error terms, one bit each, in ::nav_gnss_model_config.terms. */
typedef enum nav_gnss_term {
  NAV_GNSS_TERM_POS_GM = 1u << 0,    /**< correlated position error, GM per N/E/D axis */
  NAV_GNSS_TERM_POS_WHITE = 1u << 1, /**< white position error per N/E/D axis */
  NAV_GNSS_TERM_VEL_WHITE = 1u << 2  /**< white velocity error per N/E/D axis */
} nav_gnss_term;

/** Every GNSS term. */
#define NAV_GNSS_TERMS_ALL 0x7u

/**
 * GNSS receiver model (numerics.md section 7 "GNSS receiver models", 6.4): fixes at
 * update_rate_hz of the antenna phase centre, with a per-axis N/E/D position error = GM(sigma,
 * tau) + white, and white velocity error.
 *
 * The GM position error at epoch spacing dt_e = 1 / update_rate_hz follows E2.4 with
 * phi = exp(-dt_e / tau) and a stationary start. tau = 0 is not a special value: it is the limit
 * phi = 0 of the same recursion, i.e. white noise with the same sigma (the catalog's convention).
 */
typedef struct nav_gnss_model_config {
  unsigned terms;               /**< OR of ::nav_gnss_term */
  double update_rate_hz;        /**< fix rate, > 0; epoch j has time of validity j / update_rate_hz */
  double latency_s;             /**< >= 0: a fix becomes available at t_s + latency_s */
  nav_vec3 pos_gm_sd_m;         /**< POS_GM: sigma per N/E/D axis [m], >= 0 */
  nav_vec3 pos_gm_tau_s;        /**< POS_GM: correlation time per axis [s], >= 0 (0: white) */
  nav_vec3 pos_white_sd_m;      /**< POS_WHITE: sigma per N/E/D axis [m], >= 0 */
  nav_vec3 vel_sd_mps;          /**< VEL_WHITE: sigma per N/E/D axis [m/s], >= 0 */
  nav_vec3 r_ba_b_m;            /**< lever arm: antenna phase centre a relative to the IMU b, body axes [m] */
  bool report_model_sigmas;     /**< true: fixes report the model's sigmas; false: the two fields below */
  nav_vec3 reported_pos_sd_m;   /**< reported 1-sigma N/E/D [m] when !report_model_sigmas, >= 0 */
  nav_vec3 reported_vel_sd_mps; /**< reported 1-sigma N/E/D [m/s] when !report_model_sigmas, >= 0 */
  size_t outage_count;          /**< number of valid entries in @c outages, <= NAV_GNSS_MAX_OUTAGES */
  nav_gnss_outage outages[NAV_GNSS_MAX_OUTAGES]; /**< outage intervals (any order, may overlap) */
} nav_gnss_model_config;

NAV_END_DECLS

#endif /* NAV_SENSOR_CONFIG_H */
