/**
 * @file nav_array.h
 * @brief Distributed accelerometer arrays (the gyro-free INS): layout, measurement matrix H and
 *        its (pseudo-)inverse with geometry factors, and exact ideal array increments from the
 *        reference trajectory.
 *
 * Model (numerics.md 1.5). Accelerometer i sits at body position r_i = r_bs_b_m[i] relative to
 * the array centre O (the body origin, the point the trajectory describes) with unit sensitive
 * axis n_i = n_s_b[i]. Its ideal reading is (E1.22)
 *
 *     A_i = n_i . f + (r_i x n_i) . omega_dot + n_i . (omega x (omega x r_i)),
 *
 * with f = f_ib_b the specific force at O, omega = omega_ib_b and omega_dot its time derivative
 * (body axes); the gravitation gradient over r_i (1.5e-7 m/s^2 per 0.1 m) is neglected. Stacked,
 * A = H [f; omega_dot] + c(omega) (E1.23) with H = [n_i^T, (r_i x n_i)^T] (N x 6). The array
 * determines f and omega_dot; omega itself must be integrated (nav_gyrofree.h).
 *
 * Layouts: the cube of numerics.md 1.5, a nine- and a twelve-sensor layout, or any N = 6..16
 * sensors (nav_accel_array filled by the caller, or a scene's custom layout); geometry factors of
 * the built-in ones (r = arm; kappa for omega_dot, kappa_f for f, per axis):
 *
 * | layout | N | omega_dot noise     | f noise         | f, omega_dot correlated | H^+ annihilates c |
 * |--------|---|---------------------|-----------------|-------------------------|-------------------|
 * | cube6  | 6 | 0.7071 sigma / r    | 0.7071 sigma    | no                      | yes               |
 * | nine   | 9 | 0.9129 sigma / r    | 0.7454 sigma    | yes                     | no (iterated)     |
 * | twelve |12 | 0.5 sigma / r       | 0.5 sigma       | no                      | yes               |
 *
 * The error model ::nav_array_model gives each sensor its own bias, Gauss-Markov bias, white
 * noise and scale factor (below).
 *
 * The geometry functions are pure (implemented in src/analytic/analytic.c, since they also feed
 * the analytical error estimate of nav_analytic.h; the nine- and twelve-sensor and scene layouts
 * in src/truth/array_ideal.c); the truth generator ::nav_array_truth and the error model
 * ::nav_array_model (src/sensors/array_model.c) are stateful objects, not synchronised: one
 * thread per object.
 */
#ifndef NAV_ARRAY_H
#define NAV_ARRAY_H

#include <stddef.h>
#include <stdint.h>

#include "nav_export.h"
#include "nav_frames.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"
#include "nav_traj.h"

NAV_BEGIN_DECLS

/** Fewest accelerometers that can determine f and omega_dot (6 unknowns). */
#define NAV_ARRAY_MIN_SENSORS 6
/** Capacity of the fixed-size array descriptions (no allocation anywhere in the array code). */
#define NAV_ARRAY_MAX_SENSORS NAV_SCENE_ARRAY_MAX_SENSORS
/**
 * Largest accepted 2-norm condition number of the column-scaled H (H with its omega_dot columns
 * divided by the reference arm r_ref, so that the number does not depend on the unit of length;
 * the cube layout gives exactly 1). Beyond 1e8 the solution loses more than half of the double
 * digits and the noise gain (kappa) exceeds 1e8: such a layout is rejected as singular.
 */
#define NAV_ARRAY_MAX_COND 1e8
/**
 * Tolerance on |n_i| - 1 for a sensitive axis to count as a unit vector; within it the axis is
 * renormalised, beyond it the layout is rejected (NAV_ERR_INVALID_ARG).
 */
#define NAV_ARRAY_AXIS_UNIT_TOL 1e-6

/** An accelerometer array: N sensors with lever arms and sensitive axes in body axes. */
typedef struct nav_accel_array {
  int n_sensors;                            /**< N, NAV_ARRAY_MIN_SENSORS..NAV_ARRAY_MAX_SENSORS */
  nav_vec3 r_bs_b_m[NAV_ARRAY_MAX_SENSORS]; /**< position of sensor i relative to O, body axes [m] */
  nav_vec3 n_s_b[NAV_ARRAY_MAX_SENSORS];    /**< unit sensitive axis of sensor i, body axes [-] */
} nav_accel_array;

/**
 * The cube layout of numerics.md 1.5 (Chen-Lee-DeBra type): six sensors at the face centres of a
 * cube, distance @p r_m from O, sensitive axes along face diagonals (s = 1/sqrt 2):
 * r_i/r = (+-1,0,0), (0,+-1,0), (0,0,+-1); n_i/s = (0,1,1), (0,1,-1), (1,0,1), (-1,0,1),
 * (1,1,0), (1,-1,0). Its inverse is E1.24, det H = 8 r^3, kappa = kappa_f = 1/sqrt 2.
 * @param[in]  r_m  arm length r > 0 [m]
 * @param[out] out  the layout (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL or r not finite and positive.
 */
NAV_API NAV_NODISCARD nav_status nav_array_cube_layout(double r_m, nav_accel_array *out);

/**
 * The nine-accelerometer layout of Padgaonkar, Krieger and King (J. Appl. Mech. 42(3), 1975,
 * "3-2-2-2"): a triad at O (sensors 0-2 along x, y, z) and two sensors at distance @p r_m on each
 * positive axis, measuring the two directions across the arm:
 * sensors 3, 4 at (r,0,0) along y, z; 5, 6 at (0,r,0) along x, z; 7, 8 at (0,0,r) along x, y.
 * Geometry (derived from H^T H = [[3I, r K], [r K^T, 2r^2 I]], K = [k x], k = -(1,1,1)):
 * (H^T H)^-1 has the diagonal 5/9 (f) and 5/(6 r^2) (omega_dot), so the noise gains are
 * sigma_f = sqrt(5/9) sigma = 0.745 sigma and sigma_omega_dot = sqrt(5/6) sigma / r = 0.913 sigma / r
 * per axis, i.e. kappa_f = 0.745 and kappa = 0.913 relative to r (0.745 relative to the geometry's
 * r_ref = r sqrt(2/3)); the f and omega_dot estimates are correlated. For omega_dot it is worse
 * than the cube (the central triad sees no rotation). The original's merit is a closed-form
 * estimator of omega_dot that needs no omega (noise sigma / r, kappa = 1); the least-squares H^+
 * used here has less noise but does not annihilate c(omega), so the gyro-free INS iterates its
 * implicit rate (nav_gyrofree_config.max_iterations).
 * @param[in]  r_m  arm length r > 0 [m]
 * @param[out] out  the layout (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL or r not finite and positive.
 */
NAV_API NAV_NODISCARD nav_status nav_array_nine_layout(double r_m, nav_accel_array *out);

/**
 * The twelve-accelerometer layout: two sensors at each face centre of the cube (distance r from
 * O), along both face diagonals, i.e. a dual-axis sensor measuring the whole tangential
 * acceleration there; equivalently the cube layout (sensors 0-5, nav_array_cube_layout()) plus
 * its mirror pattern (sensors 6-11, s = 1/sqrt 2): r_i/r = (+-1,0,0), (0,+-1,0), (0,0,+-1) as
 * for 0-5; n_i/s = (0,1,-1), (0,1,1), (1,0,-1), (1,0,1), (1,-1,0), (1,1,0).
 * Geometry: each axis is tangential at four faces, so H^T H = diag(4 I, 4 r^2 I):
 * kappa = kappa_f = 1/2 (the cube's 1/sqrt 2 divided by sqrt 2 for twice the sensors), f and
 * omega_dot uncorrelated, and the omega_dot rows annihilate c(omega) as for the cube
 * (sum over faces of r_f x c_f = 2 r^2 sum_j w_j e_j x w = 2 r^2 w x w = 0).
 * @param[in]  r_m  arm length r > 0 [m]
 * @param[out] out  the layout (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL or r not finite and positive.
 */
NAV_API NAV_NODISCARD nav_status nav_array_twelve_layout(double r_m, nav_accel_array *out);

/**
 * The layout of a scene's array section: the built-in kind with arm radius_m, or the custom
 * sensors with their axes normalised to unit length.
 * @param[in]  sa   the scene's array section
 * @param[out] out  the layout (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, unknown kind, radius not finite and positive, custom
 *         count outside [6, 16], non-finite values or a zero axis). Does not check conditioning:
 *         call nav_array_geometry_compute() for that.
 */
NAV_API NAV_NODISCARD nav_status nav_array_layout_from_scene(const nav_scene_array *sa, nav_accel_array *out);

/**
 * Measurement matrix, its pseudo-inverse and the geometry factors of an array (E1.23-E1.25).
 * All matrices are row-major; the unknown vector is x = [f_ib_b (m/s^2); omega_dot_ib_b (rad/s^2)].
 */
typedef struct nav_array_geometry {
  int n_sensors;
  /** Reference arm r [m]: root-mean-square of |r_i| (= r for the cube). Only kappa / r enters
   *  the error formulas; r_ref fixes how the product is split. */
  double r_ref_m;
  /** H (E1.23), row i = [n_i^T, (r_i x n_i)^T]; columns 3..5 in m. Rows >= N are zero. */
  double h[NAV_ARRAY_MAX_SENSORS][6];
  /** H^+ = (H^T H)^-1 H^T (unweighted least squares; H^-1 when N = 6): rows 0..2 map readings to f
   *  [-], rows 3..5 to omega_dot [1/m]. Columns >= N are zero. */
  double h_pinv[6][NAV_ARRAY_MAX_SENSORS];
  /** H^+ H^+T = (H^T H)^-1: covariance of x per unit variance of independent, equal sensor noise. */
  double cov[6][6];
  /** kappa_j = r_ref sqrt(cov[3+j][3+j]) (numerics.md 1.5): omega_dot noise sd = kappa_j sigma / r. */
  double kappa_w[3];
  /** kappa_f_j = sqrt(cov[j][j]): specific-force noise sd = kappa_f_j sigma. */
  double kappa_f[3];
  /** 2-norm condition number of the column-scaled H (see NAV_ARRAY_MAX_COND). */
  double cond;
} nav_array_geometry;

/**
 * Build H, check its rank and conditioning, and compute H^+, (H^T H)^-1 and kappa (E1.23-E1.25).
 * The pseudo-inverse comes from a one-sided Jacobi SVD of the column-scaled H, so the rank test
 * sees the true singular values (not their squares, as normal equations would).
 * @param[in]  array  the layout; axes must be unit vectors within NAV_ARRAY_AXIS_UNIT_TOL
 * @param[out] out    the geometry (untouched on error)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, N outside [6, 16], non-finite values, non-unit axis,
 *         all sensors at O); NAV_ERR_NUMERIC when H is singular or its scaled condition number
 *         exceeds NAV_ARRAY_MAX_COND (e.g. all axes parallel, or all n_i parallel to r_i);
 *         NAV_ERR_NOT_CONVERGED if the SVD sweeps do not converge (not observed in practice).
 */
NAV_API NAV_NODISCARD nav_status nav_array_geometry_compute(const nav_accel_array *array,
                                                            nav_array_geometry *out);

/**
 * det H of a six-sensor array [m^3] (LU with partial pivoting); 8 r^3 for the cube layout.
 * @return NAV_OK; NAV_ERR_INVALID_ARG for NULL or N != 6 (H is not square).
 */
NAV_API NAV_NODISCARD nav_status nav_array_h_det(const nav_accel_array *array, double *det_m3);

/**
 * Centripetal part of E1.22: c_i = n_i . (omega x (omega x r_i))
 * = (n_i . omega)(r_i . omega) - (n_i . r_i)|omega|^2 [m/s^2], for i < N.
 * Leaf maths: no checks, NaN propagates. @p c_mps2 has room for array->n_sensors values.
 */
NAV_API void nav_array_centripetal(const nav_accel_array *array, nav_vec3 w_ib_b_rps, double *c_mps2);

/**
 * Ideal readings A_i (E1.22 without bias and noise) [m/s^2] for i < N.
 * @param[in] f_ib_b_mps2   specific force at O, body axes
 * @param[in] w_ib_b_rps    angular rate, body axes
 * @param[in] dw_ib_b_rps2  angular acceleration (body-frame derivative of w_ib_b), body axes
 * @param[out] a_mps2       N readings
 */
NAV_API void nav_array_readings(const nav_accel_array *array, nav_vec3 f_ib_b_mps2, nav_vec3 w_ib_b_rps,
                                nav_vec3 dw_ib_b_rps2, double *a_mps2);

/* ------------------------------------------------------------------ exact ideal increments */

/** One array record: the integral of each reading A_i over (t_s - dt_s, t_s]. */
typedef struct nav_array_increment {
  int64_t k;                            /**< sample index; t_s = k dt */
  double t_s;                           /**< end of the interval [s] */
  double dt_s;                          /**< interval length [s] */
  int n_sensors;                        /**< N; entries >= N are zero */
  double dv_mps[NAV_ARRAY_MAX_SENSORS]; /**< integral of A_i over the interval [m/s] */
} nav_array_increment;

/**
 * Exact ideal array increments from a scene's reference trajectory (the array analogue of
 * ::nav_truth). Owns its trajectory and a copy of the layout.
 */
typedef struct nav_array_truth nav_array_truth;

/**
 * Create the array truth generator of a validated scene.
 * Each increment is the integral of E1.22 over the sample interval by n-point Gauss-Legendre
 * quadrature (n = scene->imu.quadrature_nodes), with f, omega and omega_dot taken from the
 * trajectory at the nodes:
 * - flat Earth: f_b = C_l_b (a_l - g_l), omega = omega_lb_b, omega_dot = its derivative;
 * - WGS-84 (E3.7-E3.8): f_b = C_e_b (a_e + 2 omega_ie_e x v_e - g_e(r_e)),
 *   omega_ib_b = C_e_b omega_ie_e + omega_eb_b and
 *   omega_dot_ib_b = omega_dot_eb_b - omega_eb_b x (C_e_b omega_ie_e), the same gravity model as
 *   ::nav_truth.
 * @param[in]  scene  validated scene (copied as needed; not kept)
 * @param[in]  array  layout (copied); checked as by nav_array_geometry_compute()
 * @param[out] out    the generator; destroy with nav_array_truth_destroy()
 * @param[out] msg    what is wrong on failure (may be NULL)
 * @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_NUMERIC (singular layout); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_array_truth_create_msg(const nav_scene *scene,
                                                            const nav_accel_array *array,
                                                            nav_array_truth **out, char *msg,
                                                            size_t msg_size);
/** As nav_array_truth_create_msg() without a message. */
NAV_API NAV_NODISCARD nav_status nav_array_truth_create(const nav_scene *scene, const nav_accel_array *array,
                                                        nav_array_truth **out);
/** Destroy; accepts NULL. */
NAV_API void nav_array_truth_destroy(nav_array_truth *truth);

/**
 * Ideal array increments over [t_(k-1), t_k], t_k = k dt (k >= 1).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, k < 1); trajectory errors. @p out untouched on error.
 */
NAV_API NAV_NODISCARD nav_status nav_array_truth_sample(nav_array_truth *truth, int64_t k,
                                                        nav_array_increment *out);

/** Reference state at @p t_s (an evaluation of the owned trajectory). */
NAV_API NAV_NODISCARD nav_status nav_array_truth_state(nav_array_truth *truth, double t_s,
                                                       nav_traj_state *out);

/**
 * True angular rate omega_ib_b [rad/s] at @p t_s (flat Earth: omega_lb_b; WGS-84: including the
 * Earth rate), e.g. to give a gyro-free INS a perfect initial rate in tests.
 */
NAV_API NAV_NODISCARD nav_status nav_array_truth_rate(nav_array_truth *truth, double t_s,
                                                      nav_vec3 *w_ib_b_rps);

/** Sample interval [s] (1 / scene imu.rate_hz). */
NAV_API double nav_array_truth_dt(const nav_array_truth *truth);
/** Number of samples in the scene duration: floor(duration / dt + 1e-9). */
NAV_API int64_t nav_array_truth_sample_count(const nav_array_truth *truth);
/** The scene frame the states refer to. */
NAV_API nav_frame nav_array_truth_frame(const nav_array_truth *truth);
/** The layout (borrowed; valid until destroy). */
NAV_API const nav_accel_array *nav_array_truth_layout(const nav_array_truth *truth);

/* ------------------------------------------------------------------ array error model */

/**
 * @name Accelerometer-array error model
 * Each accelerometer of the array has its own error terms with the figures of a
 * ::nav_array_error_config (the same for every sensor) and its own realisation. Per sample
 * interval (t_(k-1), t_k] of length dt, sensor i (numerics.md E2.3 for one axis):
 *
 *     dA~_i = (1 + s_i) dA_i + int (b0_i + b_GM,i(t)) dt + W_i,   W_i ~ N(0, N^2 dt),
 *
 * with s_i ~ N(0, scale_factor_sd^2) and b0_i ~ N(0, bias_turn_on_sd^2) drawn once per run, the
 * Gauss-Markov bias stationary from t = 0 and its integral drawn exactly with the bias step
 * (the pair discretisation documented in nav_sensors.h), so the statistics of the output do not
 * depend on the sample rate, as for ::nav_imu_model.
 *
 * Streams (nav_rng.h: "the accelerometer index for a distributed accelerometer array"): sensor i
 * uses nav_rng_stream_id(kind, i) with kind NAV_RNG_STREAM_ACCEL_BIAS_TURN_ON (b0_i, first draw),
 * NAV_RNG_STREAM_ACCEL_SCALE_FACTOR (s_i, first draw), NAV_RNG_STREAM_ACCEL_BIAS_GM (start value,
 * then two normals per sample: bias step, integral) and NAV_RNG_STREAM_ACCEL_NOISE (one normal per
 * sample). Switching a term or a sensor on or off never changes another's realisation. In a
 * gyro-free run there is no accelerometer triad, so these streams are not shared with one.
 * @{
 */

/** Every term off (an ideal array). */
NAV_API nav_array_error_config nav_array_error_config_default(void);

/** Terms the array model supports. */
#define NAV_ARRAY_TERMS_ALL                                                                                  \
  ((unsigned)NAV_IMU_TERM_BIAS_TURN_ON | (unsigned)NAV_IMU_TERM_BIAS_GM | (unsigned)NAV_IMU_TERM_NOISE |     \
   (unsigned)NAV_IMU_TERM_SCALE_FACTOR)

/**
 * Check an array error configuration: unknown or unsupported term bits, negative or non-finite
 * sigmas of enabled terms, GM T not finite and positive. Fields of disabled terms are ignored.
 * @param[in] report called once per problem with a path relative to the configuration
 *                   ("bias_gm_tau_s"; the scene prefixes "array.accel.") and a message; may be NULL
 * @return NAV_OK, or NAV_ERR_INVALID_ARG if anything was reported or @p cfg is NULL.
 */
NAV_API NAV_NODISCARD nav_status nav_array_error_config_validate(const nav_array_error_config *cfg,
                                                                 nav_scene_issue_fn report, void *user);

/** The error model of one array in one Monte Carlo run. Opaque; one thread per object. */
typedef struct nav_array_model nav_array_model;

/**
 * Create the model of run @p run: draws every per-run constant. The only allocation.
 * @param[in]  cfg        error terms (copied); must pass nav_array_error_config_validate()
 * @param[in]  n_sensors  N, 1..NAV_ARRAY_MAX_SENSORS
 * @param[in]  seed, run  stream keys (nav_rng_init())
 * @param[out] out        the model; destroy with nav_array_model_destroy()
 * @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_array_model_create(const nav_array_error_config *cfg, int n_sensors,
                                                        uint64_t seed, uint64_t run, nav_array_model **out);
/** Destroy; accepts NULL. */
NAV_API void nav_array_model_destroy(nav_array_model *model);

/**
 * Apply the errors to one interval's ideal increments (in place allowed: @p measured may be
 * @p ideal). Allocation-free.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, sensor count differs from the model's, dt not
 *         finite and positive); NAV_ERR_NUMERIC (non-finite ideal increment). @p measured is
 *         untouched on error.
 */
NAV_API NAV_NODISCARD nav_status nav_array_model_apply(nav_array_model *model,
                                                       const nav_array_increment *ideal,
                                                       nav_array_increment *measured);

/** Turn-on bias b0_i of sensor @p i [m/s^2] (0 when the term is off or i is out of range). */
NAV_API double nav_array_model_bias_turn_on(const nav_array_model *model, int i);
/** Scale-factor error s_i of sensor @p i [-] (0 when the term is off or i is out of range). */
NAV_API double nav_array_model_scale_factor(const nav_array_model *model, int i);
/** Current Gauss-Markov bias b_GM,i of sensor @p i [m/s^2] (0 when off or out of range). */
NAV_API double nav_array_model_bias_gm(const nav_array_model *model, int i);
/** @} */

NAV_END_DECLS

#endif /* NAV_ARRAY_H */
