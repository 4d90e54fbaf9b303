/**
 * @file nav_motiondef.h
 * @brief navcore_io: import of gnss-ins-sim motion-definition files (motion_def*.csv) as
 *        segment scripts, and the duration a waypoint or segment script takes.
 *
 * File format (Aceinna gnss-ins-sim, demo_motion_def_files): comma-separated; line 1 is a header,
 * line 2 the initial state
 *   lat (deg), lon (deg), alt (m), vx_body, vy_body, vz_body (m/s), yaw, pitch, roll (deg),
 * line 3 a header, then one command per line:
 *   type, yaw, pitch, roll, vx_body, vy_body, vz_body, duration (s), GPS visibility
 * with type 1 = Euler-angle rates (deg/s) and body-velocity rates (m/s^2) for exactly duration;
 * 2 = absolute attitude and velocity; 3 = attitude change and velocity change; 4 = absolute
 * attitude, velocity change; 5 = attitude change, absolute velocity (types 2-5 end when
 * converged, duration is the maximum). When the command header names "(rad)" units (the Komatsu
 * profiles), angles are read in radians.
 *
 * Mapping: each command becomes one nav_segment (NAV_SEG_MOTION_RATES .. MOTION_REL_ABS) with
 * gnss-ins-sim's "high_mobility" limits (max acceleration 1 m/s^2, max angular acceleration
 * 0.5 rad/s^2, max angular rate 2 rad/s) plus the jerk limits of the segment defaults, and
 * allow_unconverged set (a type 2-5 command that cannot converge within its duration makes the
 * largest part of its change that fits, as gnss-ins-sim's ends unconverged). The initial yaw is
 * wrapped to (-180, 180] deg; absolute attitude commands are shifted by the same multiple of 360
 * deg so every commanded change stays what the file meant. Transitions are smoothed (see
 * segments.c), so the script takes a little longer or shorter than in gnss-ins-sim.
 */
#ifndef NAV_MOTIONDEF_H
#define NAV_MOTIONDEF_H

#include <stddef.h>

#include "nav_export.h"
#include "nav_io.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/**
 * Read a gnss-ins-sim motion-definition file into the trajectory of @p scene.
 *
 * Fills scene->trajectory (type NAV_TRAJ_SEGMENTS, the segments, initial_attitude, duration_s =
 * the length of the planned script) and scene->earth.origin_lat_rad / origin_lon_rad /
 * origin_h_m; every other field (Earth model, IMU, navigation, ...) is kept. The script is
 * planned once to check that it is feasible and to measure its length.
 * Example:
 * @code
 *   nav_scene sc = nav_scene_default();
 *   sc.earth.model = NAV_EARTH_WGS84;
 *   if (nav_motiondef_read_file("motion_def-long_drive.csv", &sc, print_diag, NULL) == NAV_OK)
 *     printf("%.3f s\n", sc.trajectory.duration_s);
 * @endcode
 * @param[in]     path   file to read
 * @param[in,out] scene  written only on NAV_OK
 * @param[in]     report receives one nav_diag (FILE:LINE:COL, field path
 * "trajectory.segments.items[i].<field>") per problem (may be NULL)
 * @param[in]     user   passed to @p report
 * @return NAV_OK; NAV_ERR_IO (unreadable file); NAV_ERR_PARSE (malformed lines, too many
 *         commands, or a command the planner rejects; each reported); NAV_ERR_INVALID_ARG (NULL);
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_motiondef_read_file(const char *path, nav_scene *scene,
                                                         nav_diag_fn report, void *user);

/** As nav_motiondef_read_file(), from memory; @p display_name is FILE in the diagnostics. */
NAV_API NAV_NODISCARD nav_status nav_motiondef_read_string(const char *text, size_t len,
                                                           const char *display_name, nav_scene *scene,
                                                           nav_diag_fn report, void *user);

/** What planning a waypoint or segment script found. */
typedef struct nav_script_summary {
  double duration_s;     /**< time from t = 0 to the end of the script (holds included) [s] */
  int items;             /**< waypoints or segments */
  int unconverged;       /**< segment scripts: motion commands of types 2-5 that ended unconverged */
  int first_unconverged; /**< index of the first of them; -1 if none */
  int shortened_ramps;   /**< segment scripts with fit_rate_ramps: rate-step ramps shortened to fit their
                              segments, which exceed the angular-acceleration/jerk limits there */
  double max_ramp_ang_accel_rps2; /**< largest Euler-angle acceleration of a rate-step ramp [rad/s^2] */
} nav_script_summary;

/**
 * Plan the waypoint or segment trajectory of @p scene and report its length, so a reader can set
 * trajectory.duration_s to it.
 * @param[in]  scene    scene whose trajectory type is NAV_TRAJ_WAYPOINTS or NAV_TRAJ_SEGMENTS
 * @param[out] out      the summary (written only on NAV_OK)
 * @param[out] msg      on failure, what is wrong (naming the waypoint/segment and the limit); may be NULL
 * @return NAV_OK; NAV_ERR_INVALID_ARG (other trajectory type, or infeasible script); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_motiondef_script_summary(const nav_scene *scene, nav_script_summary *out,
                                                              char *msg, size_t msg_size);

NAV_END_DECLS

#endif /* NAV_MOTIONDEF_H */
