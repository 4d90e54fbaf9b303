/**
 * @file nav_truth.h
 * @brief Exact ideal sensors: IMU increments integrated from the reference trajectory.
 *
 * The gyro increment is the integral of the body angular rate over the sample interval (closed
 * form where the model has one); the accelerometer increment is the integral of the specific
 * force in body axes, f_b = C_l_b (a_l - g_l), by n-point Gauss-Legendre quadrature with the
 * attitude at each node taken from the trajectory (numerics.md section 3.1). Increments are what
 * an integrating IMU outputs; the mechanization's coning/sculling terms convert them.
 */
#ifndef NAV_TRUTH_H
#define NAV_TRUTH_H

#include <stddef.h>
#include <stdint.h>

#include "nav_export.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"
#include "nav_traj.h"

NAV_BEGIN_DECLS

#define NAV_GL_MAX_NODES 16

/** One IMU record: increments over the interval (t_s - dt, t_s]. */
typedef struct nav_imu_increment {
  int64_t k;             /**< sample index; t_s = k * dt */
  double t_s;            /**< end of the interval */
  double dt_s;           /**< interval length */
  nav_vec3 dtheta_b_rad; /**< integral of omega_ib_b (flat Earth: omega_lb_b) */
  nav_vec3 dv_b_mps;     /**< integral of the specific force f_ib_b */
} nav_imu_increment;

/** Owns its trajectory; one thread at a time. */
typedef struct nav_truth nav_truth;

/** Create the truth generator of a validated scene. */
NAV_API NAV_NODISCARD nav_status nav_truth_create(const nav_scene *scene, nav_truth **out);
NAV_API void nav_truth_destroy(nav_truth *truth);

/** Ideal increments over [t_(k-1), t_k], t_k = k dt (k >= 1). NAV_ERR_NUMERIC when the
 *  trajectory yields a non-finite increment (numerical guard; *out untouched). */
NAV_API NAV_NODISCARD nav_status nav_truth_imu(nav_truth *truth, int64_t k, nav_imu_increment *out);

/** Reference state at t_s (a borrowed evaluation of the owned trajectory). NAV_ERR_NUMERIC when
 *  the position, velocity or attitude evaluates non-finite (numerical guard). */
NAV_API NAV_NODISCARD nav_status nav_truth_state(nav_truth *truth, double t_s, nav_traj_state *out);

/**
 * Sample k >= 1 for a caller that wants every sample in order (a whole-run truth, an export):
 * the reference state at t_k = k dt and the ideal increments over [t_(k-1), t_k], as
 * nav_truth_state(k dt) and nav_truth_imu(k) but with their work shared (nav_traj_sample): the
 * increment has the same numbers; the state's position, for segment-script and waypoint
 * trajectories, is the chain of interval quadratures of the velocity restarted every 64 samples
 * from the exact position, which differs from nav_truth_state's by rounding-level amounts (at most
 * 3.5e-9 m over the library's scenes; docs/truth-generation-speed.md). The state at t_0 is
 * nav_truth_state(0).
 * Results depend only on k, never on earlier calls; walking k = 1, 2, ... is the fast case.
 * NAV_ERR_NUMERIC as the two functions it replaces (outputs untouched).
 */
NAV_API NAV_NODISCARD nav_status nav_truth_sample(nav_truth *truth, int64_t k, nav_traj_state *state,
                                                  nav_imu_increment *imu);

/** IMU interval [s]. */
NAV_API double nav_truth_dt(const nav_truth *truth);
/** Number of IMU samples in the scene duration: floor(duration / dt + 1e-9). */
NAV_API int64_t nav_truth_sample_count(const nav_truth *truth);
/** The scene frame (flat l or ECEF) the states and increments refer to. */
NAV_API nav_frame nav_truth_frame(const nav_truth *truth);

/** As nav_truth_create(); on failure writes what is wrong into @p msg (may be NULL). */
NAV_API NAV_NODISCARD nav_status nav_truth_create_msg(const nav_scene *scene, nav_truth **out, char *msg,
                                                      size_t msg_size);

/**
 * Gravity (gravitation plus centrifugal) in ECEF at r_eb_e [m/s^2] for the WGS-84 gravity
 * model @p model; the truth generator and the mechanization share this function.
 */
NAV_API nav_vec3 nav_gravity_e_mps2(nav_gravity_model model, nav_vec3 r_eb_e_m);

/**
 * Gauss-Legendre nodes and weights on [-1, 1] for n = 1..NAV_GL_MAX_NODES points, computed by
 * Newton iteration on P_n to machine precision. Pure function; thread-safe.
 */
NAV_API NAV_NODISCARD nav_status nav_gauss_legendre(int n, double *nodes, double *weights);

NAV_END_DECLS

#endif /* NAV_TRUTH_H */
