/**
 * @file nav_scene.h
 * @brief The scene: everything one simulation needs, as plain C structs in SI units.
 *
 * navcore_io fills it from a YAML scene file (datasheet units converted once there); the
 * editor fills it from its panels. nav_scene_default() gives every field its default, and
 * nav_scene_validate() performs the cross-field checks that do not depend on the file format,
 * so `navsim check`, the editor panels and the core report the same messages.
 *
 * Field paths used in validation messages are the YAML paths of the scene file, e.g.
 * "trajectory.parametric.C_hz[2]", so navcore_io can attach file:line:col to them.
 */
#ifndef NAV_SCENE_H
#define NAV_SCENE_H

#include <stdint.h>

#include "nav_export.h"
#include "nav_math.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Current scene format version written by navcore_io; older versions are accepted. */
#define NAV_SCENE_FORMAT_VERSION 1
#define NAV_SCENE_NAME_MAX 128

/** Hard limits that keep memory bounded (documented in the README). */
#define NAV_SCENE_MAX_SAMPLES 2000000000LL /**< IMU samples per run */
#define NAV_SCENE_MAX_RUNS 1000000L       /**< Monte Carlo runs per process */
#define NAV_SCENE_MAX_RATE_HZ 100000.0    /**< IMU / output rate */
#define NAV_SCENE_MAX_DURATION_S 1.0e7    /**< about 116 days */

/** Earth model used consistently by truth generation and mechanization. */
typedef enum nav_earth_model {
  NAV_EARTH_FLAT = 0, /**< flat, non-rotating l frame (NED at the origin) with uniform gravity */
  NAV_EARTH_WGS84 = 1 /**< WGS-84 ellipsoid, Earth rate, transport rate, normal gravity */
} nav_earth_model;

/** Gravity model of the WGS-84 Earth (truth and mechanization always use the same one). */
typedef enum nav_gravity_model {
  NAV_GRAVITY_NORMAL = 0, /**< Somigliana normal gravity with the height series (numerics.md E3.10-E3.11) */
  NAV_GRAVITY_J2 = 1      /**< J2 gravitation minus centrifugal, valid everywhere incl. the poles (E3.12) */
} nav_gravity_model;

/** Trajectory model. */
typedef enum nav_traj_type {
  NAV_TRAJ_PARAMETRIC = 0, /**< the paper's formula (3), numerics.md section 3.1 */
  NAV_TRAJ_WAYPOINTS = 1,  /**< smooth path through waypoints with a speed profile */
  NAV_TRAJ_SEGMENTS = 2,   /**< segment script (hold, accelerate, turn, climb, ...); motion-definition imports */
  NAV_TRAJ_TEST_MOTION = 3 /**< test motions with known answers (stationary, coning, sculling, spin, great circle) */
} nav_traj_type;

/** How the attitude of the parametric trajectory is defined. */
typedef enum nav_attitude_mode {
  NAV_ATT_RATE_MAGNUS = 0 /**< Option B: omega(t) integrated by 4th-order Magnus on a sub-grid */
} nav_attitude_mode;

/** Strapdown mechanization algorithm (numerics.md section 4). */
typedef enum nav_mech_algorithm {
  NAV_MECH_FIRST_ORDER = 0, /**< (a) phi = dtheta, 1/2 dtheta x dv, trapezoidal position */
  NAV_MECH_HIGH_ORDER = 1   /**< (b) two-sample coning, exact rotation compensation, sculling */
} nav_mech_algorithm;

/**
 * The paper's parametric trajectory (formula (3), numerics.md E3.1-E3.2), element-wise per axis
 * of the scene frame l (NED at the origin):
 *   R(t) = R0 + V0 t + A t^2 + B sin(2 pi C t + D)
 *   omega_lb_b(t) = a + b sin(2 pi c t + d)   (body rate, body axes)
 */
typedef struct nav_traj_parametric {
  nav_vec3 r0_m;
  nav_vec3 v0_mps;
  nav_vec3 a_mps2;   /**< A: note R contains A t^2, so the acceleration is 2A */
  nav_vec3 b_m;
  nav_vec3 c_hz;
  nav_vec3 d_rad;
  nav_vec3 wa_rps;   /**< a */
  nav_vec3 wb_rps;   /**< b */
  nav_vec3 wc_hz;    /**< c */
  nav_vec3 wd_rad;   /**< d */
  nav_attitude_mode attitude_mode;
  int magnus_substeps; /**< sub-grid h_s = dt / magnus_substeps (default 8) */
} nav_traj_parametric;

/* ==== BEGIN test motions (owned by the mechanization / hard-cases work) ==== */
typedef struct nav_traj_test_motion {
  int reserved;
} nav_traj_test_motion;
/* ==== END test motions ==== */

/* ==== BEGIN waypoints and segment scripts (owned by the trajectory-models work) ==== */
typedef struct nav_traj_waypoints {
  int reserved;
} nav_traj_waypoints;

typedef struct nav_traj_segments {
  int reserved;
} nav_traj_segments;
/* ==== END waypoints and segment scripts ==== */

typedef struct nav_scene_trajectory {
  nav_traj_type type;
  double duration_s;
  nav_euler initial_attitude; /**< C_b_n at t = 0 (flat Earth: C_b_l) */
  nav_traj_parametric parametric;
  nav_traj_test_motion test_motion;
  nav_traj_waypoints waypoints;
  nav_traj_segments segments;
} nav_scene_trajectory;

typedef struct nav_scene_earth {
  nav_earth_model model;
  double origin_lat_rad;
  double origin_lon_rad;
  double origin_h_m;
  double flat_gravity_mps2; /**< magnitude of the uniform gravity of the flat model (down) */
  nav_gravity_model gravity_model; /**< WGS-84 model only */
} nav_scene_earth;

typedef struct nav_scene_imu {
  double rate_hz;
  int quadrature_nodes; /**< Gauss-Legendre nodes for ideal increments (1..8, default 6) */
} nav_scene_imu;

/** Frame the WGS-84 mechanization integrates in. */
typedef enum nav_mech_frame {
  NAV_MECH_NED = 0, /**< local-level NED (latitude, longitude, height); refuses |lat| -> 90 deg */
  NAV_MECH_ECEF = 1 /**< Earth-fixed: no singularity anywhere, works over the poles */
} nav_mech_frame;

typedef struct nav_scene_navigation {
  nav_mech_algorithm algorithm;
  nav_mech_frame frame; /**< WGS-84 only */
} nav_scene_navigation;

typedef struct nav_scene_output {
  double rate_hz; /**< rate of truth.csv / nav.csv / errors.csv records */
} nav_scene_output;

typedef struct nav_scene_simulation {
  uint64_t seed;
  long runs;
} nav_scene_simulation;

/** A complete scene. Plain data: copy it by assignment. */
typedef struct nav_scene {
  int format_version;
  char name[NAV_SCENE_NAME_MAX];
  nav_scene_earth earth;
  nav_scene_trajectory trajectory;
  nav_scene_imu imu;
  nav_scene_navigation navigation;
  nav_scene_output output;
  nav_scene_simulation simulation;
} nav_scene;

/** @return a scene with every field at its default (T3.1 parametric trajectory, flat Earth). */
NAV_API nav_scene nav_scene_default(void);

/**
 * Callback receiving one validation problem: @p path is the scene-file field path
 * ("imu.rate_hz"), @p message says what is wrong and what is expected. Both are valid only
 * during the call.
 */
typedef void (*nav_scene_issue_fn)(void *user, const char *path, const char *message);

/**
 * Check a scene for values the simulation cannot run: non-finite numbers, non-positive rates or
 * durations, sample counts above the limits, inconsistent combinations.
 * @param[in] scene the scene
 * @param[in] report called once per problem (may be NULL)
 * @param[in] user   passed to @p report
 * @return NAV_OK if valid, NAV_ERR_INVALID_ARG if any problem was reported (or scene is NULL).
 */
NAV_API NAV_NODISCARD nav_status nav_scene_validate(const nav_scene *scene, nav_scene_issue_fn report,
                                                    void *user);

/** Name of an enum value as written in scene files ("flat", "wgs84", ...). */
NAV_API const char *nav_earth_model_name(nav_earth_model m);
NAV_API const char *nav_mech_algorithm_name(nav_mech_algorithm a);
NAV_API const char *nav_traj_type_name(nav_traj_type t);
NAV_API const char *nav_gravity_model_name(nav_gravity_model g);
NAV_API const char *nav_mech_frame_name(nav_mech_frame f);

NAV_END_DECLS

#endif /* NAV_SCENE_H */
