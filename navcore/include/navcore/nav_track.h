/**
 * @file nav_track.h
 * @brief Recorded reference trajectories: a sampled real path (time, position, velocity,
 *        attitude) fitted by smooth splines whose derivatives are exact, so that ideal IMU
 *        readings can be generated along it (trajectory.type recorded).
 *
 * The model (recorded.c) is a least-squares fit of uniform quintic B-splines with knots at
 * knot_rate_hz (numerics.md section 3.2: truth defined analytically, derivatives never
 * finite-differenced):
 *   - position: curvilinear N, E, D metres from the first sample, fitted to the recorded
 *     positions (weight 1 / pos_sd_m^2) and to the recorded velocities converted to
 *     d(N, E, D)/dt (weight 1 / vel_sd_mps^2); lat, lon, h follow by an affine map, so
 *     v_n = [(R_M + h) lat', (R_N + h) cos(lat) lon', -h'] holds exactly (E3.9);
 *   - attitude: q_b_n = p / |p|, p(t) a 4-vector B-spline fitted to the recorded attitude
 *     quaternions made sign-continuous; omega_nb_b = 2 vec(conj(p) (x) p') / |p|^2 exactly;
 *   - a third-difference penalty of 1e-6 times one sample's weight on the control points makes
 *     the normal equations definite when knots have no samples (gaps, knots faster than the
 *     samples) and bridges gaps quadratically; elsewhere it moves the fit by far less than the
 *     residuals.
 * Position and attitude are C4: velocity, acceleration, angular rate and angular acceleration
 * are continuous, and the WGS-84 embedding of traj.c turns them into the ECEF state.
 *
 * The fit is defined by its control points, on the heap and owned by the nav_traj_recorded that
 * nav_track_fit() filled (nav_traj_recorded_release(), nav_traj_recorded_copy(); a scene's by
 * nav_scene_release(), nav_scene_copy()); the trajectory object (nav_traj) keeps a copy of its
 * own. knot_rate_hz x span + 5 must not exceed NAV_RECORDED_MAX_CTRL. The knot rate is the
 * bandwidth of the model: motion faster than about knot_rate_hz / 2 is smoothed away and shows
 * in the fit residuals.
 *
 * Limits: |latitude| <= 89 deg on every sample (the curvilinear longitude scale vanishes at
 * the poles); consecutive attitude samples less than 90 deg apart (the sign of a quaternion is
 * made continuous from sample to sample); times strictly increasing.
 *
 * Example (navcore only, samples from anywhere):
 * @code
 *   nav_scene *s = malloc(sizeof *s);
 *   *s = nav_scene_default();
 *   s->earth.model = NAV_EARTH_WGS84;
 *   s->trajectory.type = NAV_TRAJ_RECORDED;
 *   s->trajectory.recorded.knot_rate_hz = 4.0;
 *   char msg[256];
 *   if (nav_track_fit(&s->trajectory.recorded, samples, n, msg, sizeof msg) != NAV_OK) fail(msg);
 *   s->trajectory.duration_s = s->trajectory.recorded.span_s;
 *   if (nav_track_set_scene_start(&s->trajectory.recorded, s, true) != NAV_OK) fail("");  // origin, attitude
 *   printf("fit: %.3f m RMS\n", s->trajectory.recorded.fit.pos_rms_m);
 *   nav_scene_release(s);  // the control points
 *   free(s);
 * @endcode
 */
#ifndef NAV_TRACK_H
#define NAV_TRACK_H

#include <stddef.h>

#include "nav_earth.h"
#include "nav_export.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** One recorded sample (SI, radians). */
typedef struct nav_track_sample {
  double t_s;       /**< time, in the file's time base [s] */
  nav_geodetic pos; /**< latitude, longitude [rad], ellipsoidal height [m] */
  nav_vec3 v_n_mps; /**< velocity relative to the Earth, N, E, D [m/s] */
  nav_euler att;    /**< ZYX Euler angles of C_b_n [rad] */
} nav_track_sample;

/** Largest |latitude| of a recorded sample [rad] (89 deg). */
#define NAV_TRACK_MAX_ABS_LAT_RAD (89.0 * NAV_DEG2RAD)

/**
 * Fit the model of @p rec to samples.
 *
 * Reads the settings knot_rate_hz, pos_sd_m and vel_sd_mps of @p rec; writes its fitted part
 * (t0_s, span_s, ref_*, knot_dt_s, count, ctrl_ned_m, ctrl_q) and @c fit, the residuals against
 * these samples (nav_track_residuals()). The settings file, format, window, start_s and end_s
 * are not used (the caller selected the samples). Deterministic: the same samples and settings
 * give bit-identical control points. Allocates O(n + count) temporary memory.
 *
 * @param[in,out] rec      settings in, model out; left untouched on failure. On success it owns
 *                         new control points (release them with nav_traj_recorded_release()).
 *                         The ones it pointed to before are not freed (@p rec may be a plain copy
 *                         of another record, to refit with other settings): release them first
 *                         when @p rec owned them.
 * @param[in]     samples  @p n samples, times strictly increasing, all finite
 * @param[in]     n        at least 2
 * @param[out]    msg      on failure, what is wrong (naming the sample index and the limit);
 *                         may be NULL
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, n < 2, bad settings, a sample not finite or out of
 *         range, times not increasing, attitude samples 90 deg or more apart);
 *         NAV_ERR_OUT_OF_RANGE (more than NAV_RECORDED_MAX_CTRL control points needed: the
 *         message gives the largest knot rate that fits); NAV_ERR_NUMERIC (the normal equations
 *         are not definite, or the attitude spline nearly vanishes: knots too sparse for the
 *         rotation); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_track_fit(nav_traj_recorded *rec, const nav_track_sample *samples,
                                               size_t n, char *msg, size_t msg_size);

/**
 * Residuals of the fitted model of @p rec against any samples (for instance the full file
 * when only a window was fitted; samples outside the fitted span are compared with the
 * polynomial continuation). Times are the file's; the statistics report scene times.
 * @param[out] out  statistics over the @p n samples (written on NAV_OK)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, n = 0, model not fitted, a sample not finite).
 */
NAV_API NAV_NODISCARD nav_status nav_track_residuals(const nav_traj_recorded *rec,
                                                     const nav_track_sample *samples, size_t n,
                                                     nav_recorded_fit_stats *out);

/**
 * The model of @p rec at scene time @p t_s as a sample (file time base, position, NED velocity,
 * Euler angles). Leaf function for displays, exports and tests; the trajectory itself is
 * evaluated through nav_traj.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, not fitted, t_s not finite).
 */
NAV_API NAV_NODISCARD nav_status nav_track_eval(const nav_traj_recorded *rec, double t_s,
                                                nav_track_sample *out);

/**
 * Set the Earth origin of @p scene (earth.origin_*) to the model's position at t = 0 and
 * trajectory.initial_attitude to its attitude there (what navcore_io does when the scene file
 * gives no earth.origin; the initial attitude is always the recorded one).
 * @param[in] origin_too false: set only the initial attitude
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, not fitted).
 */
NAV_API NAV_NODISCARD nav_status nav_track_set_scene_start(const nav_traj_recorded *rec, nav_scene *scene,
                                                           bool origin_too);

/**
 * Warnings about the fitted model of @p rec from its fit statistics (docs/recorded-fit.md):
 * NAV_TRACK_WARN_KNOTS_OUTRUN when knot_rate_hz exceeds the mean sample rate (the spline then
 * has freedom between samples that no sample constrains); NAV_TRACK_WARN_ACCEL when the largest
 * fitted acceleration exceeds 1.5 x the largest the recorded velocities show plus 0.1 m/s^2;
 * NAV_TRACK_WARN_JERK likewise for the jerk (1.5 x plus 0.5 m/s^3).
 * @param[out] msg  "" or one sentence per warning, each naming the figures and what to change
 *                  (may be NULL)
 * @return the NAV_TRACK_WARN_* bits (0: none, or not fitted).
 */
NAV_API unsigned nav_track_warnings(const nav_traj_recorded *rec, char *msg, size_t msg_size);

/**
 * Free the control points @p rec owns and mark it not fitted (count 0, pointers NULL); the
 * settings and the fit statistics stay. No-op on NULL or an unfitted @p rec; safe twice.
 */
NAV_API void nav_traj_recorded_release(nav_traj_recorded *rec);

/**
 * @p dst = @p src with control points of its own (deep copy). @p dst is overwritten without
 * being released. On failure @p dst is @p src without the model (count 0, pointers NULL).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_traj_recorded_copy(nav_traj_recorded *dst, const nav_traj_recorded *src);

/** Name of a format as written in scene files ("kf_gins_nav"). */
NAV_API const char *nav_recorded_format_name(nav_recorded_format f);

NAV_END_DECLS

#endif /* NAV_TRACK_H */
