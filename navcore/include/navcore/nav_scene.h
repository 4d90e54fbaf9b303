/**
 * @file nav_scene.h
 * @brief The scene: everything one simulation needs, as plain C structs in SI units.
 *
 * navcore_io fills it from a YAML scene file (datasheet units converted once there); the
 * editor fills it from its panels. nav_scene_default() gives every field its default, and
 * nav_scene_validate() performs the cross-field checks that do not depend on the file format,
 * so `navsim check`, the editor panels and the core report the same messages.
 *
 * One part lives on the heap: the control points of a fitted recorded reference
 * (trajectory.recorded). A scene that a reader or nav_track_fit() filled owns them; release it
 * with nav_scene_release(), deep-copy it with nav_scene_copy(); a plain struct copy is a
 * borrowed view (docs/recorded-fit.md, "Ownership of the control points").
 *
 * Field paths used in validation messages are the YAML paths of the scene file, e.g.
 * "trajectory.parametric.C_hz[2]", so navcore_io can attach file:line:col to them.
 */
#ifndef NAV_SCENE_H
#define NAV_SCENE_H

#include <stdint.h>

#include "nav_export.h"
#include "nav_gnss_sat.h"
#include "nav_math.h"
#include "nav_requirements.h"
#include "nav_sensor_config.h"
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
  NAV_TRAJ_TEST_MOTION = 3, /**< test motions with known answers (stationary, coning, sculling, spin, great circle) */
  NAV_TRAJ_RECORDED = 4     /**< a recorded reference (time, position, velocity, attitude) fitted by splines */
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
/**
 * Test motions with known answers (numerics.md section 5; testmotion.c). All are smooth with
 * analytic derivatives (angular acceleration included). Unless stated otherwise the body stays
 * at the scene origin, and its attitude relative to local level is
 *   q_b_n(t) = R (x) q_m(t),  R constant, chosen so that q_b_n(0) = trajectory.initial_attitude,
 * where q_m(t) is the motion's own rotation; the body rate is that of q_m. On the flat Earth
 * the closed-form gyro increments (E5.2 and its analogues) are available to nav_truth.
 */
typedef enum nav_test_motion_kind {
  /** At rest at the scene origin with trajectory.initial_attitude (T5.4). */
  NAV_TEST_MOTION_STATIONARY = 0,
  /** Classic coning (5.1): q_m = [cos(beta/2), 0, sin(beta/2) cos(Omega t), sin(beta/2) sin(Omega t)];
   *  the body x axis sweeps a cone of half-angle beta about the x axis of R. */
  NAV_TEST_MOTION_CONING = 1,
  /** Sculling (5.2): rocking q_m = rotation about body x by theta0 sin(Omega t) with the in-phase
   *  specific force (0, A sin(Omega t), 0) in body axes. On the flat Earth the uniform gravity is
   *  added to the kinematic acceleration so that the specific force is exactly that vibration
   *  (the body falls freely plus the vibration and the rectified drift A J1(theta0) along the
   *  z axis of R); on WGS-84 the kinematic acceleration is the vibration alone. */
  NAV_TEST_MOTION_SCULLING = 2,
  /** Constant-axis spin (5.3): body rate spin_rate_rps about the fixed body axis spin_axis_b. */
  NAV_TEST_MOTION_SPIN = 3,
  /** Great-circle flight over the pole (5.5; WGS-84 only, defined in ECEF): constant geocentric
   *  radius a + gc_height_m and speed along the meridian plane gc_lon_rad, geocentric angle from
   *  the equator u = gc_start_angle_rad + (V/R) t (through the pole when u crosses pi/2). Body
   *  x along the velocity, z to the Earth centre, then rotated by trajectory.initial_attitude
   *  (roll, pitch, yaw relative to that path frame). */
  NAV_TEST_MOTION_POLAR_GREAT_CIRCLE = 4,
  /** Vertical loop: constant speed loop_speed_mps along body x and constant pitch rate
   *  loop_pitch_rate_rps about body y (radius V / rate), in the plane of R's x and z axes,
   *  starting at the origin along R's x axis. With a level initial attitude the pitch passes
   *  +90 deg at a quarter loop and -90 deg at three quarters (gimbal lock of Euler angles; the
   *  attitude is a quaternion throughout). */
  NAV_TEST_MOTION_VERTICAL_LOOP = 5
} nav_test_motion_kind;

/** Parameters of the test motions (SI). Only the fields of the selected kind are used. */
typedef struct nav_traj_test_motion {
  nav_test_motion_kind kind;
  double cone_half_angle_rad; /**< coning: beta, in (0, pi/2] */
  double cone_rate_rps;       /**< coning: Omega, rate at which the cone is swept */
  double scull_angle_rad;     /**< sculling: theta0, amplitude of the rocking, |theta0| <= pi/2 */
  double scull_accel_mps2;    /**< sculling: A, amplitude of the specific force along body y */
  double scull_rate_rps;      /**< sculling: Omega (> 0) */
  double spin_rate_rps;       /**< spin: rate about the axis */
  nav_vec3 spin_axis_b;       /**< spin: axis in body axes (normalised by the model; non-zero) */
  double gc_height_m;         /**< great circle: radius a + gc_height_m */
  double gc_speed_mps;        /**< great circle: speed V */
  double gc_start_angle_rad;  /**< great circle: u at t = 0 (geocentric angle from the equator) */
  double gc_lon_rad;          /**< great circle: longitude of the meridian plane */
  double loop_speed_mps;      /**< vertical loop: speed V */
  double loop_pitch_rate_rps; /**< vertical loop: pitch rate (non-zero; negative = push-over loop) */
} nav_traj_test_motion;

/** Name of a test-motion kind as written in scene files ("stationary", "coning", ...). */
NAV_API const char *nav_test_motion_kind_name(nav_test_motion_kind k);
/* ==== END test motions ==== */

/* ==== BEGIN waypoints and segment scripts (owned by the trajectory-models work) ==== */
#define NAV_MAX_WAYPOINTS 1000 /**< waypoints per trajectory */
#define NAV_MAX_SEGMENTS 2000  /**< segments per script (a motion-definition file has one per command) */

/**
 * Vehicle limits respected by the waypoint and segment planners (magnitudes, SI). Every
 * transition is a septic smoothstep ramp (traj_kin_internal.h), so rates, accelerations and
 * their derivatives are continuous and bounded by these values.
 */
typedef struct nav_traj_limits {
  /** Waypoints: |dV/dt| along the path; segments: each body-velocity component. */
  double max_accel_mps2;
  /** Waypoints: |jerk| (along and across the path); segments: d/dt of each body acceleration. */
  double max_jerk_mps3;
  /** V x turn rate in turns (waypoints; segment turns, circles, helices, lawnmowers). */
  double max_lateral_accel_mps2;
  double max_rate_rps;       /**< waypoints: turn rate; segments: each Euler-angle rate of a manoeuvre */
  double max_ang_accel_rps2; /**< d/dt of the turn / Euler-angle rate */
  double max_ang_jerk_rps3;  /**< d2/dt2 of the turn / Euler-angle rate */
} nav_traj_limits;

/** How a waypoint trajectory defines the attitude. */
typedef enum nav_wp_attitude_mode {
  NAV_WP_ATT_GROUND = 0,   /**< heading along the track, pitch from the slope, roll 0 */
  NAV_WP_ATT_AIRCRAFT = 1, /**< velocity-aligned, coordinated-turn bank roll = atan(V psi_dot / g) */
  NAV_WP_ATT_FIXED = 2,    /**< constant: trajectory.initial_attitude */
  NAV_WP_ATT_EULER = 3     /**< per-waypoint Euler angles, interpolated smoothly between waypoint times */
} nav_wp_attitude_mode;

/** What fixes the timing of a waypoint trajectory. */
typedef enum nav_wp_timing {
  NAV_WP_TIMING_SPEED = 0, /**< speed_mps at every waypoint */
  NAV_WP_TIMING_TIME = 1   /**< time_s at every waypoint; speed_mps only at the first and the last */
} nav_wp_timing;

/** One waypoint. */
typedef struct nav_waypoint {
  nav_vec3 r_ned_m;   /**< position, local N/E/D offsets from the scene origin [m] (curvilinear on WGS-84) */
  double speed_mps;   /**< speed at the waypoint [m/s] (>= 0; > 0 where the path turns) */
  double time_s;      /**< timing time: time from the start of the motion (after hold_start_s) at which the
                           vehicle passes the waypoint (mid-turn); 0 at the first waypoint */
  nav_euler attitude; /**< attitude mode euler: attitude C_b_n at the waypoint */
  /** Stationary time at an interior waypoint [s] (>= 0; 0: none). With hold_s > 0 the vehicle
      stops at the waypoint (speed 0: timing speed needs speed_mps 0 there, timing time sets it)
      and stays hold_s; time_s is then its arrival; where the path turns there, the vehicle turns
      in place, centred in the hold (its duration within max_rate_rps, max_ang_accel_rps2,
      max_ang_jerk_rps3 must fit in hold_s). The first and the last waypoint use hold_start_s
      and hold_end_s instead. */
  double hold_s;
} nav_waypoint;

/**
 * A path through waypoints (waypoints.c). Straight legs are joined at interior waypoints by
 * planar fly-by turns whose curvature rises and falls by septic smoothsteps (a smooth
 * clothoid-like blend: position C4, turn rate C3); speed changes happen on the straight parts,
 * turns are flown at the waypoint's speed. Infeasible input is an error naming the waypoint and
 * the limit, never a silent distortion.
 */
typedef struct nav_traj_waypoints {
  int count; /**< number of points used, 2..NAV_MAX_WAYPOINTS */
  nav_wp_timing timing;
  nav_wp_attitude_mode attitude_mode;
  double hold_start_s; /**< stationary time before the motion (needs speed 0 at the first waypoint) */
  double hold_end_s;   /**< stationary time after it (needs speed 0 at the last waypoint) */
  double cruise_mps;   /**< timing speed: speed on a leg between two stops (speed 0 at both ends),
                            less where the leg is too short; 0: such a leg is an error */
  nav_traj_limits limits;
  nav_waypoint points[NAV_MAX_WAYPOINTS];
} nav_traj_waypoints;

/**
 * Segment kinds. Field use per kind (unused fields are ignored):
 * - HOLD: duration_s. All rates zero: a moving vehicle continues straight at constant velocity.
 * - ACCELERATE: speed_mps, the body-x speed to reach.
 * - TURN, COORD_TURN: yaw_rad (heading change, + = right), yaw_rate_rps (peak rate; 0 = the
 *   largest the limits allow). COORD_TURN banks (coordinated).
 * - CLIMB: height_m (height change, + = up) at flight-path angle |pitch_rad|.
 * - CIRCLE: radius_m, turns (+ = right). FIGURE_EIGHT: radius_m, turns per lobe (sign: first lobe).
 * - HELIX: radius_m, turns (+ = right), pitch_rad (flight-path angle, + = climbing).
 * - LAWNMOWER: legs, length_m (straight part of each leg), spacing_m (+ = first turn right).
 * - MOTION_RATES (gnss-ins-sim type 1): yaw/pitch/roll_rate_rps and accel_b_mps2 for exactly
 *   duration_s.
 * - MOTION_ABS_ABS / REL_REL / ABS_REL / REL_ABS (gnss-ins-sim types 2, 3, 4, 5): yaw/pitch/roll_rad
 *   and v_b_mps, absolute or relative (attitude first, velocity second); they end when converged,
 *   duration_s is the maximum time. Euler angles are not wrapped (gnss-ins-sim semantics).
 * The kinds that turn need a positive body-x speed.
 */
typedef enum nav_segment_kind {
  NAV_SEG_HOLD = 0,
  NAV_SEG_ACCELERATE = 1,
  NAV_SEG_TURN = 2,
  NAV_SEG_COORD_TURN = 3,
  NAV_SEG_CLIMB = 4,
  NAV_SEG_CIRCLE = 5,
  NAV_SEG_FIGURE_EIGHT = 6,
  NAV_SEG_HELIX = 7,
  NAV_SEG_LAWNMOWER = 8,
  NAV_SEG_MOTION_RATES = 9,
  NAV_SEG_MOTION_ABS_ABS = 10,
  NAV_SEG_MOTION_REL_REL = 11,
  NAV_SEG_MOTION_ABS_REL = 12,
  NAV_SEG_MOTION_REL_ABS = 13
} nav_segment_kind;

/** One segment of a script; see nav_segment_kind for which fields each kind reads. */
typedef struct nav_segment {
  nav_segment_kind kind;
  bool coordinated;  /**< bank into turns: roll += atan(u psi_dot / g) (implied by COORD_TURN) */
  bool gnss_visible; /**< motion-definition GPS-visibility column, kept for outage modelling */
  int legs;          /**< LAWNMOWER: number of straight legs (>= 1) */
  double duration_s; /**< HOLD, MOTION_RATES: exact; MOTION_ABS_ABS .. REL_ABS: maximum */
  double yaw_rad, pitch_rad, roll_rad;                /**< attitude command or change */
  double yaw_rate_rps, pitch_rate_rps, roll_rate_rps; /**< Euler-angle rates (MOTION_RATES; TURN peak rate) */
  nav_vec3 v_b_mps;      /**< body velocity command or change (MOTION_ABS_ABS .. REL_ABS) */
  nav_vec3 accel_b_mps2; /**< body-velocity rates (MOTION_RATES) */
  double speed_mps;      /**< ACCELERATE: target body-x speed */
  double height_m;       /**< CLIMB: height change */
  double radius_m;       /**< CIRCLE, FIGURE_EIGHT, HELIX: horizontal turn radius */
  double turns;          /**< CIRCLE, FIGURE_EIGHT, HELIX: number of turns (signed) */
  double length_m;       /**< LAWNMOWER: straight length of each leg */
  double spacing_m;      /**< LAWNMOWER: distance between legs (signed) */
} nav_segment;

/**
 * A segment script (segments.c). Each segment starts from the end state of the previous one.
 * Rate steps between MOTION_RATES/HOLD segments are ramped over documented ramp times centred on
 * the boundary (so a level segment changes the state by exactly rate x duration_s); every other
 * kind is a rest-to-rest manoeuvre planned within the limits. The script starts with the rates of
 * its first segment; after its end the final rates continue. The initial attitude is
 * trajectory.initial_attitude.
 */
typedef struct nav_traj_segments {
  int count; /**< number of segments used, 1..NAV_MAX_SEGMENTS */
  /**
   * MOTION types 2-5 that cannot converge within duration_s make the largest part of their change
   * that fits and end unconverged (gnss-ins-sim's rule; set by the motion-definition import).
   * false: that is an error naming the segment and the limit.
   */
  bool allow_unconverged;
  /**
   * A rate-step ramp too long to fit (each half of a ramp may use at most half of the adjacent
   * HOLD/MOTION_RATES segment) is shortened to fit, exceeding max_ang_accel/max_ang_jerk/max_jerk
   * there, and zero-length HOLD/MOTION_RATES segments are skipped (gnss-ins-sim does not limit
   * type-1 steps; set by the import; nav_motiondef_script_summary counts them). false: both are
   * errors naming the segment and the limit.
   */
  bool fit_rate_ramps;
  nav_vec3 r0_ned_m; /**< start position, local NED [m] */
  nav_vec3 v0_b_mps; /**< start velocity in body axes [m/s] */
  nav_traj_limits limits;
  nav_segment items[NAV_MAX_SEGMENTS];
} nav_traj_segments;
/* ==== END waypoints and segment scripts ==== */

/* ==== BEGIN recorded reference (owned by the recorded-trajectory work; nav_track.h) ==== */
/**
 * Most B-spline control points of a recorded trajectory: knot_rate_hz x span_s + 5 must fit.
 * The control points live on the heap (nav_traj_recorded.ctrl_ned_m), not in the scene value;
 * this cap only bounds the memory a scene file can ask for (56 bytes per point, 224 MB here:
 * a day at 46 Hz knots, a one-hour reference at 1000 Hz).
 */
#define NAV_RECORDED_MAX_CTRL 4000000
/** Longest recorded-file path kept in the scene [bytes, with the NUL]. */
#define NAV_RECORDED_PATH_MAX 1024

/** Format of a recorded reference file. */
typedef enum nav_recorded_format {
  /** KF-GINS / i2Nav .nav: 11 whitespace-separated columns per line: GPS week, GPS seconds of
   *  week [s], latitude [deg], longitude [deg], ellipsoidal height [m], velocity N, E, D [m/s],
   *  roll, pitch, yaw [deg] (ZYX Euler angles of C_b_n, body forward-right-down). */
  NAV_RECORDED_KF_GINS_NAV = 0
} nav_recorded_format;

/** trajectory.recorded.window bits: which ends of the time window were given. */
enum {
  NAV_RECORDED_HAS_START = 1u << 0, /**< start_s given */
  NAV_RECORDED_HAS_END = 1u << 1    /**< end_s given */
};

/**
 * How well the fitted model reproduces recorded samples (nav_track_residuals()). Position and
 * velocity differences are model minus record resolved in NED at the recorded position,
 * attitude is the rotation angle between the two attitudes.
 */
typedef struct nav_recorded_fit_stats {
  long samples;        /**< samples compared (0: no fit yet) */
  double pos_rms_m;    /**< RMS of |dr| (3-D) [m] */
  double pos_max_m;    /**< largest |dr| [m] */
  double pos_max_t_s;  /**< its time, scene time base [s] */
  double pos_h_rms_m;  /**< RMS of hypot(dN, dE) [m] */
  double pos_v_rms_m;  /**< RMS of |dD| [m] */
  double vel_rms_mps;  /**< RMS of |dv| (3-D) [m/s] */
  double vel_max_mps;  /**< largest |dv| [m/s] */
  double vel_max_t_s;  /**< its time [s] */
  double att_rms_rad;  /**< RMS of the rotation angle [rad] */
  double att_max_rad;  /**< largest rotation angle [rad] */
  double att_max_t_s;  /**< its time [s] */
  double max_gap_s;    /**< longest time between consecutive samples [s]: the model bridges gaps
                            smoothly (quadratically where no sample constrains it) */
  double max_gap_t_s;  /**< scene time of the sample that ends that gap [s] */
  /* ---- plausibility of the model's dynamics (nav_track_residuals; docs/recorded-fit.md) */
  double sample_rate_hz;     /**< mean sample rate: (samples - 1) / span [Hz] */
  double fit_acc_max_mps2;   /**< largest |d2 r/dt2| of the position spline at the samples and
                                  midway between them [m/s^2] */
  double fit_acc_max_t_s;    /**< its time [s] */
  double rec_acc_max_mps2;   /**< largest |dv / dt| of the recorded velocities over steps of at
                                  least half the mean sample spacing [m/s^2] */
  double fit_jerk_max_mps3;  /**< largest |d3 r/dt3| of the spline at the same times [m/s^3] */
  double fit_jerk_max_t_s;   /**< its time [s] */
  double rec_jerk_max_mps3;  /**< largest change of those recorded accelerations per second [m/s^3] */
} nav_recorded_fit_stats;

/** Warnings about a fitted recorded reference (nav_track_warnings()). */
enum {
  NAV_TRACK_WARN_KNOTS_OUTRUN = 1u << 0, /**< knot_rate_hz above the mean sample rate */
  NAV_TRACK_WARN_ACCEL = 1u << 1,        /**< fitted acceleration beyond what the velocities support */
  NAV_TRACK_WARN_JERK = 1u << 2          /**< fitted jerk beyond what the velocities support */
};

/**
 * A recorded reference trajectory (recorded.c, nav_track.h). The settings come from the scene
 * file; the model is a least-squares fit of the recorded samples made when the scene is read
 * (nav_track_fit()), kept here as uniform quintic B-spline control points:
 *   - position: curvilinear N, E, D metres from the reference point (lat = ref_lat + N / m_lat,
 *     lon = ref_lon + E / m_lon, h = ref_h - D, with m_lat = R_M(ref_lat) + ref_h and m_lon =
 *     (R_N(ref_lat) + ref_h) cos(ref_lat)), fitted to the recorded positions and velocities;
 *   - attitude: q_b_n = p / |p| with p a 4-vector spline fitted to the recorded attitude
 *     quaternions (made sign-continuous).
 * Both are C4, so velocity, acceleration, angular rate and angular acceleration are analytic
 * and continuous. Scene time 0 is the first recorded sample in the window (file time t0_s).
 * The recorded samples themselves are not kept. The control points are on the heap, owned as
 * described at ctrl_ned_m (docs/recorded-fit.md, "Ownership of the control points").
 */
typedef struct nav_traj_recorded {
  /* ---- settings (scene file) */
  char file[NAV_RECORDED_PATH_MAX]; /**< the recorded file; navcore_io stores it resolved (absolute) */
  nav_recorded_format format;
  unsigned window;      /**< NAV_RECORDED_HAS_START / _HAS_END */
  double start_s;       /**< first sample time to use, file time base [s] (if HAS_START) */
  double end_s;         /**< last sample time to use, file time base [s] (if HAS_END) */
  double knot_rate_hz;  /**< B-spline knots per second (the bandwidth of the model) */
  double pos_sd_m;      /**< fit weight of a recorded position: 1 / pos_sd_m^2 per axis */
  double vel_sd_mps;    /**< fit weight of a recorded velocity: 1 / vel_sd_mps^2 per axis */
  /* ---- fitted model (nav_track_fit; not in the scene file) */
  double t0_s;          /**< file time of scene time 0 [s] */
  double span_s;        /**< last minus first sample time in the window [s] */
  double ref_lat_rad;   /**< origin of the curvilinear coordinates: the first sample [rad] */
  double ref_lon_rad;   /**< [rad] */
  double ref_h_m;       /**< ellipsoidal height [m] */
  double knot_dt_s;     /**< knot spacing [s] */
  int count;            /**< control points (knot intervals + 5); 0: not fitted */
  /** Position control points [m], @c count of them, on the heap. One allocation holds them and
   *  ctrl_q; the nav_traj_recorded (and so the nav_scene) that nav_track_fit() or a reader
   *  filled owns it: release it with nav_scene_release() / nav_traj_recorded_release(), copy
   *  it with nav_scene_copy() / nav_traj_recorded_copy(). A plain struct copy (s2 = s1) is a
   *  borrowed view, valid while the owner is alive and unchanged; it must not be released.
   *  NULL when not fitted. */
  nav_vec3 *ctrl_ned_m;
  nav_quat *ctrl_q;     /**< attitude control points (not unit), @c count of them, same block */
  nav_recorded_fit_stats fit; /**< residuals against the samples of the fit */
} nav_traj_recorded;
/* ==== END recorded reference ==== */

typedef struct nav_scene_trajectory {
  nav_traj_type type;
  double duration_s;
  nav_euler initial_attitude; /**< C_b_n at t = 0 (flat Earth: C_b_l) */
  nav_traj_parametric parametric;
  nav_traj_test_motion test_motion;
  nav_traj_waypoints waypoints;
  nav_traj_segments segments;
  nav_traj_recorded recorded;
} nav_scene_trajectory;

typedef struct nav_scene_earth {
  nav_earth_model model;
  double origin_lat_rad;
  double origin_lon_rad;
  double origin_h_m;
  double flat_gravity_mps2; /**< magnitude of the uniform gravity of the flat model (down) */
  nav_gravity_model gravity_model; /**< WGS-84 model only */
} nav_scene_earth;

#define NAV_SCENE_CATALOG_NAME_MAX 96

typedef struct nav_scene_imu {
  double rate_hz;
  int quadrature_nodes;       /**< Gauss-Legendre nodes for ideal increments (1..16, default 6) */
  char catalog[NAV_SCENE_CATALOG_NAME_MAX]; /**< catalog part the model started from ("" = none) */
  nav_imu_model_config model; /**< error model in SI (terms off by default: a perfect IMU) */
} nav_scene_imu;

/** GNSS receiver of an integrated scheme. */
typedef struct nav_scene_gnss {
  bool enabled;
  char catalog[NAV_SCENE_CATALOG_NAME_MAX];
  nav_gnss_model_config model;
  /** Satellites along the trajectory (issue 22): visibility and DOP outputs; independent of
   *  @c enabled (the receiver model of the integrated schemes). */
  nav_gnss_constellation_config constellation;
  /** gnss.file: recorded fixes (KF-GINS GNSS text, 7 or 13 columns) that replace the receiver
   *  model's fixes; "" for none. navcore_io stores it resolved (absolute). navcore reads no
   *  file: the caller loads it (nav_gnss_file_load(), nav_recorded.h) and attaches the fixes to
   *  the simulation (nav_sim_set_gnss_fixes()). Time base: docs/gnss-file.md. */
  char file[NAV_RECORDED_PATH_MAX];
} nav_scene_gnss;

/** Initial navigation errors, drawn once per Monte Carlo run (1-sigma, zero mean). */
typedef struct nav_scene_initial_errors {
  nav_vec3 pos_sd_m;    /**< north, east, down [m] */
  nav_vec3 vel_sd_mps;  /**< north, east, down [m/s] */
  nav_vec3 att_sd_rad;  /**< about north, east, down (phi-angle, numerics.md E0.1) [rad] */
} nav_scene_initial_errors;

/** Frame the WGS-84 mechanization integrates in. */
typedef enum nav_mech_frame {
  NAV_MECH_NED = 0, /**< local-level NED (latitude, longitude, height); refuses |lat| -> 90 deg */
  NAV_MECH_ECEF = 1 /**< Earth-fixed: no singularity anywhere, works over the poles */
} nav_mech_frame;

/** Navigation scheme (architecture.md section 1). */
typedef enum nav_nav_scheme {
  NAV_SCHEME_FREE_INS = 0, /**< free-inertial strapdown INS (gyros + accelerometers) */
  NAV_SCHEME_INS_GNSS = 1, /**< loosely coupled INS/GNSS error-state Kalman filter */
  /** Gyro-free INS from the accelerometer array of the scene's @c array section (nav_gyrofree.h,
   *  numerics.md 1.5); the imu section's triads are not used, only imu.rate_hz and
   *  imu.quadrature_nodes. */
  NAV_SCHEME_GYRO_FREE = 2,
  /** The gyro-free INS of the @c array section aided by the @c gnss receiver: loosely coupled
   *  error-state filter in closed loop (nav_gyrofree_gnss.h, docs/gyro-free-gnss.md); WGS-84. */
  NAV_SCHEME_GYRO_FREE_GNSS = 3,
  /** Tightly coupled INS/GNSS: the loosely coupled filter's INS error states with receiver clock
   *  (and GLONASS inter-system bias) states, updated by the pseudoranges and range rates of the
   *  satellites of gnss.constellation in view (nav_ins_gnss.h, docs/ins-gnss-tight.md); works
   *  with any number of satellites; WGS-84. */
  NAV_SCHEME_INS_GNSS_TIGHT = 4
} nav_nav_scheme;

typedef struct nav_scene_navigation {
  nav_nav_scheme scheme;
  nav_mech_algorithm algorithm;
  nav_mech_frame frame; /**< WGS-84 only */
  bool aid_vertical;    /**< free INS: height and vertical velocity from the reference (baro-like aiding) */
  /** ins_gnss: propagate the filter covariance once every this many IMU steps
   *  (nav_filter_config.cov_decimation; 0, the default, or 1: every step). */
  int cov_decimation;
  /** ins_gnss: estimate gyro and accelerometer scale factors (21-state filter); their initial
   *  sigma is the scene's scale-factor sigma (with its fixed part), random constants. */
  bool estimate_scale_factors;
  /** ins_gnss with estimate_scale_factors: 0 (default): the scale-factor states are random
   *  constants; > 0: first-order Gauss-Markov processes with this correlation time [s] and the
   *  scene's scale-factor sigma as their stationary sigma (KF-GINS's model: corrtime with
   *  gsstd/asstd). With f_z near -g the z accelerometer scale factor acts as a second vertical
   *  bias, so this choice decides how fast the filter follows a drifting vertical bias. */
  double scale_factor_gm_tau_s;
  /** ins_gnss only: every Monte Carlo run also runs the RTS smoother (nav_smoother.h) over its
   *  output and GNSS epochs; smoothed errors at the output epochs (nav_sim.h). Default false.
   *  Memory per run in flight (one per thread): one record per output or GNSS epoch, about
   *  7 KiB at 18 states (38 MiB for the 513 s urban-drive at 10 Hz output); never per IMU step. */
  bool smoother;
} nav_scene_navigation;

typedef struct nav_scene_output {
  double rate_hz; /**< rate of truth.csv / nav.csv / errors.csv records */
} nav_scene_output;

typedef struct nav_scene_simulation {
  uint64_t seed;
  long runs;
  int threads; /**< worker threads for Monte Carlo (0 = one per core); results do not depend on it */
} nav_scene_simulation;

/* ==== BEGIN accelerometer array (gyro-free INS) ==== */
/** Most accelerometers in an array (the same as NAV_ARRAY_MAX_SENSORS of nav_array.h). */
#define NAV_SCENE_ARRAY_MAX_SENSORS 16

/**
 * Built-in accelerometer-array layouts (nav_array.h documents each geometry and its geometry
 * factors kappa; r = nav_scene_array.radius_m).
 */
typedef enum nav_array_layout_kind {
  NAV_ARRAY_LAYOUT_CUBE6 = 0,  /**< six sensors at the cube's face centres, axes along face diagonals
                                    (numerics.md 1.5): kappa = kappa_f = 1/sqrt 2 */
  NAV_ARRAY_LAYOUT_NINE = 1,   /**< nine: a triad at the centre and two sensors on each axis at r
                                    (Padgaonkar 3-2-2-2) */
  NAV_ARRAY_LAYOUT_TWELVE = 2, /**< twelve: both face diagonals at each face centre (two cubes):
                                    kappa = kappa_f = 1/2 */
  NAV_ARRAY_LAYOUT_CUSTOM = 3  /**< positions and axes of nav_scene_array.custom */
} nav_array_layout_kind;

/** One accelerometer of a user-defined array. */
typedef struct nav_scene_array_sensor {
  nav_vec3 r_bs_b_m; /**< position relative to the array centre O (the body origin), body axes [m] */
  nav_vec3 n_s_b;    /**< sensitive axis, body axes; any non-zero length (normalised when used) */
} nav_scene_array_sensor;

/**
 * Error terms of every accelerometer of an array (the same figures for each sensor; each sensor
 * draws its own realisation from its own streams). A term is used only when its bit
 * (::nav_imu_term: BIAS_TURN_ON, BIAS_GM, NOISE, SCALE_FACTOR) is set in @c terms; the fields of
 * a clear bit are ignored. Per sample interval dt, sensor i (the model of nav_sensors.h, one axis):
 *   dA~_i = (1 + s_i) dA_i + int (b0_i + b_GM,i) dt + W_i,   W_i ~ N(0, N^2 dt).
 */
typedef struct nav_array_error_config {
  unsigned terms;              /**< OR of NAV_IMU_TERM_BIAS_TURN_ON | _BIAS_GM | _NOISE | _SCALE_FACTOR */
  double bias_turn_on_sd_mps2; /**< BIAS_TURN_ON: 1-sigma of b0_i (zero mean) [m/s^2], >= 0 */
  double bias_gm_sd_mps2;      /**< BIAS_GM: stationary sigma [m/s^2], >= 0 */
  double bias_gm_tau_s;        /**< BIAS_GM: correlation time T [s], > 0, finite */
  double vrw_mps_per_sqrt_s;   /**< NOISE: white-noise density N [m/s/sqrt(s)], >= 0 */
  double scale_factor_sd;      /**< SCALE_FACTOR: 1-sigma of s_i (zero mean, unitless), >= 0 */
} nav_array_error_config;

/**
 * The accelerometer array of the gyro-free scheme (NAV_SCHEME_GYRO_FREE). Its sample rate and
 * quadrature are those of the imu section. Random streams (nav_rng.h): sensor i uses the
 * NAV_RNG_STREAM_ACCEL_* kinds with channel i; the initial angular-rate error of body axis j uses
 * NAV_RNG_STREAM_INIT_ATT with channel 3 + j (channels 0-2 are the initial attitude error).
 */
typedef struct nav_scene_array {
  nav_array_layout_kind layout;
  /** Part of resources/accel_catalog.csv whose figures filled @c accel before the scene's own
   *  accel keys overrode them ("" = none); the same part for every sensor. */
  char catalog[NAV_SCENE_CATALOG_NAME_MAX];
  double radius_m;  /**< arm r of the built-in layouts [m], > 0 (not used by CUSTOM) */
  int custom_count; /**< CUSTOM: number of sensors, 6..NAV_SCENE_ARRAY_MAX_SENSORS */
  nav_scene_array_sensor custom[NAV_SCENE_ARRAY_MAX_SENSORS]; /**< CUSTOM: the sensors */
  nav_array_error_config accel;                               /**< per-sensor error terms */
  /** 1-sigma error of the initial angular rate omega_ib_b given to the gyro-free INS (the array
   *  cannot observe the rate), per body axis [rad/s], >= 0; drawn once per run, zero mean. */
  nav_vec3 initial_rate_sd_rps;
} nav_scene_array;
/* ==== END accelerometer array ==== */

/** A complete scene. Plain data: copy it by assignment. */
typedef struct nav_scene {
  int format_version;
  char name[NAV_SCENE_NAME_MAX];
  nav_scene_earth earth;
  nav_scene_trajectory trajectory;
  nav_scene_imu imu;
  nav_scene_gnss gnss;
  nav_scene_array array; /**< accelerometer array of the gyro-free scheme */
  nav_scene_initial_errors initial_errors;
  nav_scene_navigation navigation;
  nav_scene_output output;
  nav_scene_simulation simulation;
  /* ==== BEGIN requirements (owned by the requirements work; nav_requirements.h) ==== */
  int n_requirements;                                   /**< 0..NAV_SCENE_MAX_REQUIREMENTS */
  nav_requirement requirements[NAV_SCENE_MAX_REQUIREMENTS]; /**< accuracy requirements, file order */
  /* ==== END requirements ==== */
} nav_scene;

/** @return a scene with every field at its default (T3.1 parametric trajectory, flat Earth). */
NAV_API nav_scene nav_scene_default(void);

/** Whether the loosely coupled scheme takes its fixes from the least-squares PVT of the simulated
 *  raw measurements: scheme ins_gnss with gnss.enabled and gnss.constellation.fixes: pvt. Leaf. */
NAV_API bool nav_scene_gnss_pvt_fixes(const nav_scene *scene);

/**
 * Free the heap data a scene owns (the control points of a fitted recorded reference,
 * trajectory.recorded) and mark that model not fitted (count 0, pointers NULL). Every scene
 * filled by a reader (nav_scene_read_file and friends), by nav_track_fit() or by
 * nav_scene_copy() is released once when no longer needed; a plain struct copy of it is a
 * borrowed view and is not. No-op on NULL and on a scene without heap data (every
 * nav_scene_default() scene); releasing twice is safe.
 */
NAV_API void nav_scene_release(nav_scene *scene);

/**
 * Copy @p src into @p dst with heap data of its own (a deep copy of the recorded control
 * points), so that @p dst outlives @p src. @p dst is overwritten without being released: release
 * it first if it owned data. On failure @p dst is a copy without the recorded model (not fitted).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_copy(nav_scene *dst, const nav_scene *src);

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
NAV_API const char *nav_nav_scheme_name(nav_nav_scheme s);
NAV_API const char *nav_array_layout_kind_name(nav_array_layout_kind k);

NAV_END_DECLS

#endif /* NAV_SCENE_H */
