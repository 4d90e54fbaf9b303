/**
 * @file nav_analytic.h
 * @brief Analytical (preliminary) error estimates: the paper's first main idea, with the
 *        corrections of numerics.md section 1 and Appendix A.
 *
 * Contents, each function citing its equation:
 * - integrated-noise kernels (E1.1, E1.2) and first-order Gauss-Markov variances I1-I3
 *   (E1.3-E1.5, with series branches where the closed forms cancel);
 * - the free-inertial gyro INS, per level axis, term by term (E1.6-E1.17) and combined (E1.21);
 * - Schuler-bounded single-channel solutions (E1.18-E1.20);
 * - the gyro-free six-accelerometer INS error growth (E1.25-E1.28, geometry factors from H,
 *   nav_array.h) with the corrected 1/252 coefficient;
 * - THE PAPER'S ORIGINAL formulas (1) and (2), wrong coefficients and linear bias + noise sums
 *   included, as separately named functions nav_analytic_paper_*, for the comparison tables only;
 * - nav_analytic_estimate(): sigma(t) curves of position, velocity and attitude for a gyro INS
 *   and a gyro-free INS from IMU specifications (what `navsim estimate` prints).
 *
 * Conventions. SI throughout; "per axis" means one level channel (north or east) of a level,
 * slowly moving vehicle with small angles (numerics.md 1.2 validity: no Schuler feedback, so
 * within 1 % for t < 280 s; small angles below ~0.05 rad). Noise is specified by its density N
 * (white noise of two-sided PSD N^2: N [unit sqrt(s)] = per-sample sd x sqrt(dt), E1.2). Bias
 * terms are deterministic responses to the given bias value; when the value is the standard
 * deviation of a zero-mean random constant, the same number is that term's one-sigma, which is
 * how E1.21 and nav_analytic_estimate() combine them (root-sum-square). Leaf functions return
 * values and document their domain (NaN propagates); functions taking structs check them.
 *
 * Pure functions: no state, thread-safe.
 */
#ifndef NAV_ANALYTIC_H
#define NAV_ANALYTIC_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_array.h"
#include "nav_export.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/* ================================================================== E1.1-E1.2 kernels */

/**
 * One-sigma of x(t) = int_0^t h(t-s) e(s) ds for white noise e of density N, with the kernel of
 * m successive integrations h(u) = u^(m-1)/(m-1)! (E1.1):
 * Var = N^2 t^(2m-1) / ((2m-1) ((m-1)!)^2), i.e. N^2 t, t^3/3, t^5/20, t^7/252 for m = 1..4.
 * @param[in] density  N [unit sqrt(s)], >= 0
 * @param[in] t_s      time >= 0 [s]
 * @param[in] m        number of integrations, 1..8
 * @return the standard deviation [unit s^(m-1)]; NaN for m outside 1..8.
 */
NAV_API double nav_analytic_white_sd(double density, double t_s, int m);

/**
 * Response of m successive integrations to a constant b: b t^m / m! (E1.1, deterministic column).
 * @return [unit s^m]; NaN for m outside 1..8.
 */
NAV_API double nav_analytic_bias_response(double b, double t_s, int m);

/**
 * Noise density of a per-sample white sequence (each sample the average over its interval,
 * E1.2): N = sigma sqrt(dt).
 * @param[in] sigma  per-sample standard deviation [unit]
 * @param[in] dt_s   sample interval [s]
 * @return N [unit sqrt(s)].
 */
NAV_API double nav_analytic_density_from_sample_sd(double sigma, double dt_s);

/* ================================================================== E1.3-E1.5 Gauss-Markov */

/**
 * Below this value of t / T the GM variances are evaluated by their power series in x = t/T.
 *
 * Reason: the closed forms E1.3-E1.5 subtract terms of order 1 (times T^k) to leave results of
 * order x^2, x^4 and x^6, so their relative rounding error grows like eps/x, eps/x^4 and
 * eps/x^6 (times small constants). numerics.md 1.1 puts the switch at x ~ 1e-3; that is enough
 * for I1 but not for I2 and I3: measured at x = 1e-3, the closed forms are off by 6e-11 (I1),
 * 1e-4 (I2) and 100 % (I3). At x = 1 the closed forms lose at most about one digit, and the
 * series, alternating with factorial denominators, converges to round-off in about 25 terms;
 * both branches agree there to 5e-15 (tested in test_analytic).
 */
#define NAV_ANALYTIC_GM_SERIES_X 1.0

/** Which branch nav_analytic_gm_var() uses. */
typedef enum nav_analytic_gm_method {
  NAV_ANALYTIC_GM_AUTO = 0,        /**< series below NAV_ANALYTIC_GM_SERIES_X, closed form above */
  NAV_ANALYTIC_GM_CLOSED_FORM = 1, /**< always E1.3-E1.5 as printed (tests, demonstrations) */
  NAV_ANALYTIC_GM_SERIES = 2       /**< always the series (accurate for x <~ 5; slow beyond) */
} nav_analytic_gm_method;

/**
 * Variance of the m-fold integral of a stationary first-order Gauss-Markov process with
 * variance sigma^2 and correlation time T (autocorrelation sigma^2 exp(-|tau|/T)), E1.3-E1.5:
 *   I1 = 2 sigma^2 T^2 (x - 1 + e^-x),
 *   I2 = (sigma^2 T^4 / 3) (2x^3 - 3x^2 + 6 - 6 e^-x (1 + x)),
 *   I3 = (sigma^2 T^6 / 60) (6x^5 - 15x^4 + 20x^3 - 120 + e^-x (120 + 120x + 60x^2)),   x = t/T.
 * Series (derived by expanding e^-x; the low-order terms cancel exactly):
 *   I1 = 2 sigma^2 T^2 sum_{k>=2} (-x)^k / k!,
 *   I2 = 2 sigma^2 T^4 sum_{k>=4} (-1)^k (k-1) x^k / k!,
 *   I3 = sigma^2 T^6 sum_{k>=6} (-1)^k (k-1)(k-2) x^k / k!.
 * Limits: t << T: sigma^2 t^2, sigma^2 t^4/4, sigma^2 t^6/36; t >> T: white noise with q = 2 sigma^2 T.
 * @param[in] m        1, 2 or 3 (I1, I2, I3)
 * @param[in] sigma    process standard deviation [unit]
 * @param[in] tau_s    correlation time T > 0 [s]
 * @param[in] t_s      time >= 0 [s]
 * @param[in] method   branch selection
 * @return the variance [unit^2 s^(2m)]; NaN outside the domain (m, T <= 0, t < 0, bad method).
 */
NAV_API double nav_analytic_gm_var(int m, double sigma, double tau_s, double t_s,
                                   nav_analytic_gm_method method);
/** I1(t) of E1.3 (automatic branch). */
NAV_API double nav_analytic_gm_var_i1(double sigma, double tau_s, double t_s);
/** I2(t) of E1.4 (automatic branch). */
NAV_API double nav_analytic_gm_var_i2(double sigma, double tau_s, double t_s);
/** I3(t) of E1.5 (automatic branch). */
NAV_API double nav_analytic_gm_var_i3(double sigma, double tau_s, double t_s);

/* ================================================================== E1.6-E1.17, E1.21 gyro INS */

/**
 * Per-axis error sources of a free-inertial gyro INS (numerics.md 1.2), SI. A zero field
 * switches its term off. Every value is >= 0 (a standard deviation or the magnitude of a
 * constant).
 */
typedef struct nav_analytic_imu_spec {
  double g_mps2;                        /**< gravity magnitude g [m/s^2] */
  double init_pos_sd_m;                 /**< E1.6 initial position error dr0 [m] */
  double init_vel_sd_mps;               /**< E1.7 initial velocity error dv0 [m/s] */
  double init_tilt_sd_rad;              /**< E1.8 initial tilt psi0 [rad] */
  double init_heading_sd_rad;           /**< E1.9 initial heading error psiD [rad] */
  double horiz_accel_mps2;              /**< E1.9 horizontal acceleration a_h it multiplies [m/s^2] */
  double accel_bias_mps2;               /**< E1.10 accelerometer bias b_a [m/s^2] */
  double accel_vrw_mps_per_sqrt_s;      /**< E1.11 accelerometer white noise N_a [m/s/sqrt(s)] */
  double accel_gm_sd_mps2;              /**< E1.12 accelerometer GM bias sigma_ba [m/s^2] */
  double accel_gm_tau_s;                /**< E1.12 its correlation time T_a [s] (> 0 if sd > 0) */
  double accel_bias_rw_mps2_per_sqrt_s; /**< E1.13 accelerometer bias random walk K_a [m/s^2/sqrt(s)] */
  double gyro_bias_rps;                 /**< E1.14 gyro bias b_g [rad/s] */
  double gyro_arw_rad_per_sqrt_s;       /**< E1.15 gyro white noise (ARW) N_g [rad/sqrt(s)] */
  double gyro_gm_sd_rps;                /**< E1.16 gyro GM bias sigma_bg [rad/s] */
  double gyro_gm_tau_s;                 /**< E1.16 its correlation time T_g [s] (> 0 if sd > 0) */
  double gyro_rrw_rps_per_sqrt_s;       /**< E1.17 gyro rate random walk K_g [rad/s/sqrt(s)] */
} nav_analytic_imu_spec;

/** All error sources zero, g = NAV_G0_MPS2 (9.80665 m/s^2). */
NAV_API nav_analytic_imu_spec nav_analytic_imu_spec_default(void);

/** The rows of the gyro INS table (numerics.md 1.2). Values are frozen (array indices). */
typedef enum nav_analytic_term_id {
  NAV_ANALYTIC_TERM_INIT_POS = 0,      /**< E1.6 */
  NAV_ANALYTIC_TERM_INIT_VEL = 1,      /**< E1.7 */
  NAV_ANALYTIC_TERM_INIT_TILT = 2,     /**< E1.8 */
  NAV_ANALYTIC_TERM_INIT_HEADING = 3,  /**< E1.9 */
  NAV_ANALYTIC_TERM_ACCEL_BIAS = 4,    /**< E1.10 */
  NAV_ANALYTIC_TERM_ACCEL_NOISE = 5,   /**< E1.11 */
  NAV_ANALYTIC_TERM_ACCEL_GM = 6,      /**< E1.12 */
  NAV_ANALYTIC_TERM_ACCEL_BIAS_RW = 7, /**< E1.13 */
  NAV_ANALYTIC_TERM_GYRO_BIAS = 8,     /**< E1.14 */
  NAV_ANALYTIC_TERM_GYRO_NOISE = 9,    /**< E1.15 */
  NAV_ANALYTIC_TERM_GYRO_GM = 10,      /**< E1.16 */
  NAV_ANALYTIC_TERM_GYRO_RRW = 11,     /**< E1.17 */
  NAV_ANALYTIC_TERM_COUNT = 12
} nav_analytic_term_id;

/** Short label of a table row, e.g. "E1.10 accel bias"; "?" for an unknown id. Static string. */
NAV_API const char *nav_analytic_term_name(nav_analytic_term_id id);
/** True for the rows that are random processes (noise, GM, random walk): always one-sigma.
 *  The other rows are deterministic responses to a constant (one-sigma if it is a random constant). */
NAV_API bool nav_analytic_term_is_process(nav_analytic_term_id id);

/** Attitude, velocity and position error of one axis (one term, or a combination). */
typedef struct nav_analytic_axis_error {
  double att_rad;
  double vel_mps;
  double pos_m;
} nav_analytic_axis_error;

/** The gyro INS table at one time. */
typedef struct nav_analytic_gyro_ins_table {
  double t_s;
  nav_analytic_axis_error term[NAV_ANALYTIC_TERM_COUNT]; /**< each row separately (E1.6-E1.17) */
  nav_analytic_axis_error rss;                           /**< root-sum-square of all rows (E1.21) */
} nav_analytic_gyro_ins_table;

/**
 * Evaluate the per-axis gyro INS table E1.6-E1.17 and its RSS E1.21 at time @p t_s.
 * E1.21 (position column): sigma_r^2 = dr0^2 + dv0^2 t^2 + (g psi0)^2 t^4/4 + b_a^2 t^4/4
 * + N_a^2 t^3/3 + g^2 b_g^2 t^6/36 + g^2 N_g^2 t^5/20 + (heading, GM and random-walk rows).
 * @param[in]  spec  error sources (all finite and >= 0; tau > 0 where the GM sd is > 0)
 * @param[in]  t_s   time since alignment, >= 0 [s]
 * @param[out] out   the table (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL, negative or non-finite inputs.
 */
NAV_API NAV_NODISCARD nav_status nav_analytic_gyro_ins_table_eval(const nav_analytic_imu_spec *spec,
                                                                  double t_s,
                                                                  nav_analytic_gyro_ins_table *out);

/* ================================================================== E1.18-E1.20 Schuler */

/** One level channel at rest with Schuler feedback (numerics.md 1.3). Signed values. */
typedef struct nav_analytic_schuler_channel {
  double g_mps2;          /**< local gravity g [m/s^2] */
  double radius_m;        /**< R = sqrt(R_M R_N) + h [m] (nav_analytic_schuler_radius_m()) */
  double dr0_m;           /**< initial position error of the channel [m] */
  double dv0_mps;         /**< initial velocity error of the channel [m/s] */
  double accel_bias_mps2; /**< level accelerometer bias in n: b_aN (north) or b_aE (east) [m/s^2] */
  double tilt0_rad;       /**< phi_E0 (north channel) or phi_N0 (east channel), phi-angle E0.1 [rad] */
  double gyro_bias_rps;   /**< level gyro bias in n: b_gE (north) or b_gN (east) [rad/s] */
} nav_analytic_schuler_channel;

/** Position and velocity error of one channel. */
typedef struct nav_analytic_schuler_error {
  double pos_m;
  double vel_mps;
} nav_analytic_schuler_error;

/** Schuler radius R = sqrt(R_M R_N) + h [m] (numerics.md 1.3; 6 378 101 m at 45 deg, h = 0). */
NAV_API double nav_analytic_schuler_radius_m(double lat_rad, double h_m);
/** Schuler frequency omega_s = sqrt(g / R) [rad/s]; the period is 2 pi / omega_s. */
NAV_API double nav_analytic_schuler_rate_rps(double g_mps2, double radius_m);

/**
 * North channel (E1.18, E1.20):
 *   dr_N = dr0 + dv0 sin(ws t)/ws + (b_aN + g phi_E0) (R/g)(1 - cos ws t) - b_gE R (t - sin(ws t)/ws),
 *   dv_N = dv0 cos(ws t) + (b_aN + g phi_E0) sin(ws t)/ws - b_gE R (1 - cos ws t).
 * Evaluated through sinc-type coefficients (nav_sinc() etc.), so it is exact also for ws t -> 0,
 * where it reduces to the table E1.6-E1.14.
 * @return the errors; NaN propagates (leaf maths).
 */
NAV_API nav_analytic_schuler_error nav_analytic_schuler_north(const nav_analytic_schuler_channel *ch,
                                                              double t_s);
/**
 * East channel (E1.19 and its time derivative):
 *   dr_E = dr0 + dv0 sin(ws t)/ws + (b_aE - g phi_N0) (R/g)(1 - cos ws t) + b_gN R (t - sin(ws t)/ws),
 *   dv_E = dv0 cos(ws t) + (b_aE - g phi_N0) sin(ws t)/ws + b_gN R (1 - cos ws t).
 */
NAV_API nav_analytic_schuler_error nav_analytic_schuler_east(const nav_analytic_schuler_channel *ch,
                                                             double t_s);

/* ================================================================== E1.25-E1.28 gyro-free INS */

/** Inputs of the gyro-free error chain (numerics.md 1.5), SI. */
typedef struct nav_analytic_gyrofree_spec {
  double g_mps2;                     /**< gravity g [m/s^2] */
  double r_m;                        /**< arm length r [m] (the r_ref of the geometry) */
  double kappa_w;                    /**< omega_dot geometry factor kappa (1/sqrt 2 cube; 1 paper) */
  double kappa_f;                    /**< specific-force geometry factor kappa_f */
  double accel_bias_mps2;            /**< bias b of every accelerometer (the bias column) [m/s^2] */
  double accel_noise_mps_per_sqrt_s; /**< noise density N = sigma sqrt(dt) (E1.2) [m/s/sqrt(s)] */
} nav_analytic_gyrofree_spec;

/**
 * Per-axis gyro-free errors: "bias" columns deterministic for the common bias b (magnitudes; for
 * the cube a common b gives omega_dot = -(1/sqrt 2) b/r, f = +(1/sqrt 2) b), "sd" columns
 * one-sigma for the noise.
 */
typedef struct nav_analytic_gyrofree_errors {
  double rate_bias_rps;  /**< E1.25 kappa b t / r */
  double rate_sd_rps;    /**< E1.25 kappa sigma sqrt(t dt) / r */
  double att_bias_rad;   /**< E1.26 kappa b t^2 / (2 r) */
  double att_sd_rad;     /**< E1.26 kappa sigma sqrt(t^3 dt / 3) / r */
  double grav_bias_mps2; /**< E1.27 g * att_bias (small angles only) */
  double grav_sd_mps2;   /**< E1.27 g * att_sd */
  /** velocity: kappa_f b t + g kappa b t^3 / (6 r) (E1.1 applied to the chain of E1.28, one
   *  integration less) */
  double vel_bias_mps;
  /** velocity: sqrt(kappa_f^2 sigma^2 dt t + (g kappa sigma / r)^2 dt t^5 / 20) */
  double vel_sd_mps;
  double pos_bias_m; /**< E1.28 kappa_f b t^2/2 + g kappa b t^4 / (24 r) */
  double pos_sd_m;   /**< E1.28 sqrt(kappa_f^2 sigma^2 dt t^3/3 + (g kappa sigma / r)^2 dt t^7 / 252) */
} nav_analytic_gyrofree_errors;

/**
 * Evaluate E1.25-E1.28 (corrected: geometry factors from H, 1/252, bias and noise separate).
 * @param[in]  spec  finite inputs, r > 0, the rest >= 0
 * @param[in]  t_s   time >= 0 [s]
 * @param[out] out   the errors (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL or out-of-domain inputs.
 */
NAV_API NAV_NODISCARD nav_status nav_analytic_gyrofree_eval(const nav_analytic_gyrofree_spec *spec,
                                                            double t_s, nav_analytic_gyrofree_errors *out);

/**
 * Gyro-free spec of an array: kappa_w = max_j kappa_w[j], kappa_f = max_j kappa_f[j] (the worst
 * axis; all equal for the cube), r = r_ref.
 * @param[in]  geom  from nav_array_geometry_compute()
 * @param[in]  g_mps2, accel_bias_mps2, accel_noise_mps_per_sqrt_s  as in the spec
 * @param[out] out   the spec
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_analytic_gyrofree_spec_from_geometry(const nav_array_geometry *geom,
                                                                          double g_mps2,
                                                                          double accel_bias_mps2,
                                                                          double accel_noise_mps_per_sqrt_s,
                                                                          nav_analytic_gyrofree_spec *out);

/* ================================================================== the paper's formulas (WRONG) */

/**
 * THE PAPER'S formula (1), gyro-free position error, as printed (for comparison tables only):
 *   sigma_r = b (g t^4/(24 r) + t^2/2) + sigma sqrt(t^3 dt/3 + (g/r)^2 t^7 dt / 630).
 * Errors (numerics.md 1.5, Appendix A): 1/630 must be 1/252 (four-fold integration of white
 * noise, E1.1); the geometry factors kappa, kappa_f are taken as 1 (1/sqrt 2 for the cube); bias
 * and noise are added linearly (a bound, not a standard deviation). Use
 * nav_analytic_gyrofree_eval() instead.
 * @param[in] b_mps2      accelerometer bias [m/s^2]
 * @param[in] sigma_mps2  per-sample accelerometer noise sd [m/s^2]
 * @param[in] r_m         arm length [m]
 * @param[in] dt_s        sample interval [s]
 * @param[in] g_mps2      gravity [m/s^2]
 * @param[in] t_s         time [s]
 * @return the paper's sigma_r [m].
 */
NAV_API double nav_analytic_paper_gyrofree_position_sigma_630(double b_mps2, double sigma_mps2, double r_m,
                                                              double dt_s, double g_mps2, double t_s);
/** The noise part of THE PAPER'S formula (1) alone (wrong /630, kappa = 1):
 *  sigma sqrt(t^3 dt/3 + (g/r)^2 t^7 dt/630) [m]. */
NAV_API double nav_analytic_paper_gyrofree_position_noise_630(double sigma_mps2, double r_m, double dt_s,
                                                              double g_mps2, double t_s);

/** Coriolis vibratory-gyro scale 2 w r [m/s] (numerics.md 1.4 reading of the paper's (2)). */
NAV_API double nav_analytic_coriolis_scale_mps(double drive_rate_rps, double drive_amplitude_m);

/**
 * Bias part of THE PAPER'S formula (2), gyro INS: b_a (g t^3 / (12 w r) + t^2/2) [m]. Correct
 * under the Coriolis reading b_g = b_a / (2 w r) (it is E1.10 + E1.14); deterministic.
 * @param[in] b_a_mps2          accelerometer (and gyro sense-channel) bias [m/s^2]
 * @param[in] drive_rate_rps    w, the gyro's drive angular frequency [rad/s]
 * @param[in] drive_amplitude_m r, the drive amplitude [m]
 */
NAV_API double nav_analytic_paper_gyro_ins_position_bias(double b_a_mps2, double drive_rate_rps,
                                                         double drive_amplitude_m, double g_mps2, double t_s);
/**
 * Noise part of THE PAPER'S formula (2) as printed (WRONG coefficient /30):
 * sigma_a sqrt(t^3 dt/3 + g^2/(2 w r)^2 t^5 dt / 30) [m]. Underestimates the gyro term by
 * sqrt(30/20) = 1.22; see nav_analytic_coriolis_gyro_ins_position_noise().
 */
NAV_API double nav_analytic_paper_gyro_ins_position_noise_30(double sigma_a_mps2, double drive_rate_rps,
                                                             double drive_amplitude_m, double dt_s,
                                                             double g_mps2, double t_s);
/**
 * THE PAPER'S formula (2) total: bias part + noise part with /30 (linear sum; WRONG on both
 * counts, comparison only) [m].
 */
NAV_API double nav_analytic_paper_gyro_ins_position_sigma_30(double b_a_mps2, double sigma_a_mps2,
                                                             double drive_rate_rps, double drive_amplitude_m,
                                                             double dt_s, double g_mps2, double t_s);
/**
 * Corrected noise of the paper's gyro INS under the Coriolis reading (E1.11 + E1.15 with
 * sigma_g = sigma_a / (2 w r)): sigma_a sqrt(t^3 dt/3 + g^2/(2 w r)^2 t^5 dt / 20) [m].
 */
NAV_API double nav_analytic_coriolis_gyro_ins_position_noise(double sigma_a_mps2, double drive_rate_rps,
                                                             double drive_amplitude_m, double dt_s,
                                                             double g_mps2, double t_s);

/* ================================================================== preliminary estimate */

/** Inputs of the preliminary estimate (the paper's "preliminary analysis", section III.A). */
typedef struct nav_analytic_estimate_config {
  /** Gyro INS error sources, per axis (E1.6-E1.17). g, the initial position, velocity and tilt
   *  errors are shared with the gyro-free INS. */
  nav_analytic_imu_spec imu;
  /** Also evaluate the gyro-free INS (needs a valid @c array). */
  bool with_gyrofree;
  /** Accelerometer array of the gyro-free INS; kappa and r come from its H (E1.23-E1.25). */
  nav_accel_array array;
  /** Bias of each array accelerometer: standard deviation of a zero-mean random constant,
   *  independent between sensors [m/s^2]. */
  double array_accel_bias_mps2;
  /** White-noise density of each array accelerometer, N = sigma sqrt(dt) [m/s/sqrt(s)]. */
  double array_accel_noise_mps_per_sqrt_s;
  /** Initial angular-rate error of the gyro-free INS (the array cannot observe omega) [rad/s]. */
  double array_init_rate_sd_rps;
} nav_analytic_estimate_config;

/** Defaults: nav_analytic_imu_spec_default(), no gyro-free INS, cube array with r = 0.1 m,
 *  zero array errors. */
NAV_API nav_analytic_estimate_config nav_analytic_estimate_config_default(void);

/** One-sigma errors per level axis. */
typedef struct nav_analytic_sigma {
  double att_sd_rad;
  double vel_sd_mps;
  double pos_sd_m;
} nav_analytic_sigma;

/** One point of the sigma(t) curves. */
typedef struct nav_analytic_estimate_point {
  double t_s;
  /** Gyro INS, E1.21 (RSS of every row of E1.6-E1.17). */
  nav_analytic_sigma gyro_ins;
  /** Gyro INS short-time table valid to 1 % (no Schuler feedback): (omega_s t)^2 / 12 < 0.01
   *  with omega_s = sqrt(g / a_WGS84), i.e. t < ~280 s (numerics.md 1.2 (ii)). */
  bool gyro_ins_short_time_ok;
  /**
   * Gyro-free INS (valid only if with_gyrofree): RSS of the initial position, velocity and tilt
   * errors (E1.6-E1.8), the initial rate error (att w0 t, vel g w0 t^2/2, pos g w0 t^3/6), the
   * bias chain E1.25-E1.28 (as a random constant: its f and omega_dot parts combined by RSS, exact
   * when H^+ H^+T is block diagonal as for the cube) and the noise chain E1.25-E1.28, all with the
   * worst-axis kappa of the array.
   */
  nav_analytic_sigma gyrofree;
  /** The paper's formula (1) with the same b, sigma (kappa = 1, /630, linear sum) [m], for the
   *  comparison column (dt-free: sigma^2 dt = N^2). */
  double gyrofree_paper_pos_m;
  /** Gyro-free small-angle condition: attitude sd < 0.05 rad (numerics.md 1.5 item 4). */
  bool gyrofree_small_angle_ok;
} nav_analytic_estimate_point;

/**
 * Fill sigma(t) curves of position, velocity and attitude for a gyro INS and (optionally) a
 * gyro-free INS at the caller's times.
 * @param[in]  cfg    configuration
 * @param[in]  t_s    @p count times >= 0 [s] (any order)
 * @param[in]  count  number of times (0 is allowed: nothing is written)
 * @param[out] out    caller buffer of @p count points (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL with count > 0, negative or non-finite inputs, bad
 *         layout); NAV_ERR_NUMERIC (singular array layout).
 *
 * Example:
 * @code
 *   nav_analytic_estimate_config cfg = nav_analytic_estimate_config_default();
 *   cfg.imu.accel_bias_mps2 = 1e-3 * NAV_G0_MPS2;            // 1 mg
 *   cfg.imu.gyro_bias_rps = 10.0 * NAV_DEG2RAD / 3600.0;     // 10 deg/h
 *   cfg.with_gyrofree = true;                                // cube, r = 0.1 m
 *   cfg.array_accel_bias_mps2 = 1e-3 * NAV_G0_MPS2;
 *   double t[3] = {1.0, 10.0, 60.0};
 *   nav_analytic_estimate_point p[3];
 *   if (nav_analytic_estimate(&cfg, t, 3, p) == NAV_OK) { ... p[i].gyro_ins.pos_sd_m ... }
 * @endcode
 */
NAV_API NAV_NODISCARD nav_status nav_analytic_estimate(const nav_analytic_estimate_config *cfg,
                                                       const double *t_s, size_t count,
                                                       nav_analytic_estimate_point *out);

NAV_END_DECLS

#endif /* NAV_ANALYTIC_H */
