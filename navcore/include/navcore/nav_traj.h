/**
 * @file nav_traj.h
 * @brief Reference trajectories: position, velocity, acceleration, attitude, angular rate and
 *        angular acceleration as smooth functions of time (analytic derivatives).
 *
 * A trajectory is an opaque, stateful object: models whose attitude is defined by integrating
 * an angular rate (the paper's Option B) keep a cache of the integrated attitude so that a run
 * walking forward in time costs O(1) per evaluation. Evaluation at an earlier time than the
 * cache restarts from the nearest stored checkpoint. Not thread-safe: one thread per object.
 */
#ifndef NAV_TRAJ_H
#define NAV_TRAJ_H

#include "nav_export.h"
#include "nav_frames.h"
#include <stddef.h>
#include <stdint.h>

#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/**
 * Kinematic state of the body at one time in the scene's reference frame F (nav_frames.h):
 * F = l on flat Earth, F = e (ECEF) on WGS-84.
 */
typedef struct nav_traj_state {
  double t_s;
  nav_vec3 r_fb_f_m;     /**< position of the body (IMU) in F [m] */
  nav_vec3 v_fb_f_mps;   /**< velocity relative to F, resolved in F [m/s] */
  nav_vec3 a_fb_f_mps2;  /**< acceleration relative to F, resolved in F [m/s^2] */
  nav_quat q_b_f;        /**< attitude, body FRD to F */
  nav_vec3 w_fb_b_rps;   /**< angular rate of b relative to F, body axes [rad/s] */
  nav_vec3 dw_fb_b_rps2; /**< its time derivative in body axes [rad/s^2] */
} nav_traj_state;

typedef struct nav_traj nav_traj;

/**
 * Create the trajectory a scene describes.
 * @param[in]  scene   validated scene (copied; not kept)
 * @param[in]  dt_s    IMU sample interval: rate-defined attitude is integrated on a sub-grid of
 *                     dt_s / substeps aligned with the samples
 * @param[out] out     new trajectory; destroy with nav_traj_destroy
 * @return NAV_OK, NAV_ERR_INVALID_ARG, NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_traj_create(const nav_scene *scene, double dt_s, nav_traj **out);
/** Destroy; accepts NULL. */
NAV_API void nav_traj_destroy(nav_traj *traj);

/**
 * Evaluate the trajectory at @p t_s in [0, duration] (it is defined, and smooth, slightly
 * beyond both ends too, which the quadrature of the last interval never needs).
 * @return NAV_OK, NAV_ERR_INVALID_ARG (NULL or non-finite t).
 */
NAV_API NAV_NODISCARD nav_status nav_traj_eval(nav_traj *traj, double t_s, nav_traj_state *out);

/**
 * Exact integral of the body angular rate relative to F over [t0_s, t1_s] (on flat Earth, the
 * ideal gyro increment) when the model has a closed form and F = l; otherwise
 * @p has_closed_form is false and the caller integrates numerically.
 */
NAV_API NAV_NODISCARD nav_status nav_traj_rate_integral(const nav_traj *traj, double t0_s, double t1_s,
                                                        nav_vec3 *out, bool *has_closed_form);

/**
 * Ideal inertial sensor rates at @p t_s: specific force f_ib_b [m/s^2] and angular rate
 * omega_ib_b [rad/s], body axes, with the scene's Earth and gravity model (flat: uniform
 * gravity, non-rotating l; WGS-84: Earth rate, transport rate, normal or J2 gravity, computed in
 * the NED form E3.9 for local models and the ECEF form E3.7-E3.8 for ECEF models).
 */
NAV_API NAV_NODISCARD nav_status nav_traj_inertial(nav_traj *traj, double t_s, nav_vec3 *f_ib_b_mps2,
                                                   nav_vec3 *w_ib_b_rps);

/**
 * Ideal IMU increments over [t0_s, t1_s]: the integrals of f_ib_b [m/s^2 -> m/s] and omega_ib_b
 * [rad/s -> rad] (body axes, the model of nav_traj_inertial) by the quadrature rule with @p n
 * nodes @p x (ascending, on [-1, 1]) and weights @p w, e.g. from nav_gauss_legendre. Equal to
 * summing nav_traj_inertial at the nodes up to rounding, but evaluated for the whole interval
 * at once, which is several times faster (shared lookups and trigonometry, no angular
 * acceleration). The results depend only on the arguments, never on earlier calls; walking
 * forward over the sample grid t_k = k dt (dt of the create call) is the fast case.
 * @param[in]  traj          trajectory (its caches are updated)
 * @param[in]  t0_s, t1_s    interval [s]
 * @param[in]  n             node count, 1..16
 * @param[in]  x, w          nodes and weights on [-1, 1] (n each)
 * @param[out] dv_b_mps      integral of the specific force, body axes [m/s]
 * @param[out] dtheta_b_rad  integral of the angular rate omega_ib_b, body axes [rad]
 * @return NAV_OK, NAV_ERR_INVALID_ARG (NULL, n out of range, non-finite times), or the model's
 *         status (NAV_ERR_OUT_OF_RANGE before the start of a rate-integrated attitude).
 */
NAV_API NAV_NODISCARD nav_status nav_traj_inertial_increment(nav_traj *traj, double t0_s, double t1_s, int n,
                                                             const double *x, const double *w,
                                                             nav_vec3 *dv_b_mps, nav_vec3 *dtheta_b_rad);

/**
 * Sample k of the grid t_k = k dt (dt of the create call, k >= 1) for a caller that walks the
 * samples in order: the state at t_k and the increments over [t_(k-1), t_k] of
 * nav_traj_inertial_increment (the same numbers). The two share work: for models whose position
 * is the integral of their velocity (segment scripts, waypoints) the position of the state is the
 * position chain R(k) that the increment computes anyway, R(k) = R(k-1) + the rule's integral of
 * the velocity over the interval, restarted from the model's own position at every 64th sample
 * (it differs from nav_traj_eval's position by rounding: at most 3.5e-9 m, a few ulp of an ECEF
 * coordinate, over the library's scenes; docs/truth-generation-speed.md); every other field, and the whole state of other models, has the numbers of
 * nav_traj_eval(t_k). The results depend only on k and the rule, never on earlier calls; walking
 * k = 1, 2, ... is the fast case.
 * @return as nav_traj_inertial_increment (NAV_ERR_INVALID_ARG also for k < 1).
 */
NAV_API NAV_NODISCARD nav_status nav_traj_sample(nav_traj *traj, int64_t k, int n, const double *x,
                                                 const double *w, nav_traj_state *state, nav_vec3 *dv_b_mps,
                                                 nav_vec3 *dtheta_b_rad);

/** Duration of the trajectory [s]. */
NAV_API double nav_traj_duration(const nav_traj *traj);

/** The scene frame the states are expressed in. */
NAV_API nav_frame nav_traj_frame(const nav_traj *traj);

/**
 * As nav_traj_create(); on failure also writes into @p msg (may be NULL) what is wrong, naming
 * the offending waypoint, segment or field and the limit (infeasible input is an error, never a
 * silent distortion).
 */
NAV_API NAV_NODISCARD nav_status nav_traj_create_msg(const nav_scene *scene, double dt_s, nav_traj **out,
                                                     char *msg, size_t msg_size);

/** Summary of a planned waypoint or segment script (nav_traj_*_plan_info). */
typedef struct nav_traj_script_info {
  double duration_s;     /**< natural length of the script [s] */
  int unconverged;       /**< motion commands of types 2-5 that ended unconverged */
  int first_unconverged; /**< index of the first of them, -1 if none */
  int shortened_ramps;   /**< rate-step ramps shortened to fit, exceeding the limits */
  double max_ramp_ang_accel_rps2; /**< largest Euler-angle acceleration of any rate-step ramp [rad/s^2] */
} nav_traj_script_info;

/**
 * Plan the segment script of @p scene (trajectory type segments) without building positions:
 * its natural duration and what the planner had to give up.
 * @param[in]  scene      scene with a segment script
 * @param[out] info       the plan's summary (written on NAV_OK)
 * @param[out] bad_index  on failure the offending segment, -1 when not tied to one
 * @param[out] msg        on failure what is wrong (may be NULL)
 * @return NAV_OK, NAV_ERR_INVALID_ARG (infeasible script), NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_traj_segments_plan_info(const nav_scene *scene, nav_traj_script_info *info,
                                                             int *bad_index, char *msg, size_t msg_size);
/** As nav_traj_segments_plan_info() for a waypoint list (@p bad_index = the offending waypoint). */
NAV_API NAV_NODISCARD nav_status nav_traj_waypoints_plan_info(const nav_scene *scene, nav_traj_script_info *info,
                                                              int *bad_index, char *msg, size_t msg_size);

NAV_END_DECLS

#endif /* NAV_TRAJ_H */
