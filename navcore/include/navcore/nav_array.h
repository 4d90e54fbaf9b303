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
 * The geometry functions are pure (implemented in src/analytic/analytic.c, since they also feed
 * the analytical error estimate of nav_analytic.h); the truth generator ::nav_array_truth is a
 * stateful object (src/truth/array_ideal.c), not synchronised: one thread per object.
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
#define NAV_ARRAY_MAX_SENSORS 16
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

NAV_END_DECLS

#endif /* NAV_ARRAY_H */
