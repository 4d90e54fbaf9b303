/*
 * Scene files: the trajectory section (trajectory.*) of the schema, with its custom fields (the
 * waypoint and segment lists, the kind-dependent mappings of segments and test motions, duration_s
 * "auto") and what needs the whole file (nav_io_traj_finish). Read and write functions sit next to
 * the tables they serve; the generic machinery is in scene_read.c and scene_write.c.
 *
 *   trajectory:
 *     type: parametric | waypoints | segments | test_motion | motion_def | recorded
 *     duration_s: 120            # or auto (the default for waypoints, segments and motion_def)
 *     initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 90}
 *     parametric: {...}          # the paper's formula (3)
 *     waypoints: {timing, attitude_mode, hold_start_s, hold_end_s, cruise_mps, limits, points: [...]}
 *     segments: {r0_ned_m, v0_b_mps, allow_unconverged, fit_rate_ramps, limits, items: [...]}
 *     test_motion: {kind: coning, ...the parameters of that kind}
 *     motion_def: {file: PATH, allow_unconverged, fit_rate_ramps}
 *     recorded: {file: PATH, format: kf_gins_nav, start_s, end_s, knot_rate_hz, pos_sd_m, vel_sd_mps}
 *
 * duration_s. A waypoint or segment script has a natural length (nav_motiondef_script_summary);
 * "auto", or no duration_s at all, uses it. A longer explicit duration is allowed: after the end
 * of the script a segment script keeps its final rates (a vehicle moving at the end continues)
 * and a waypoint trajectory continues as its last piece (straight at the final speed, or at rest
 * after hold_end_s). A shorter one ends the run early.
 *
 * motion_def. The gnss-ins-sim motion-definition file (a path relative to the scene file's
 * directory, or absolute) is imported when the whole scene has been read (nav_motiondef_read_file):
 * it sets the segment script, the initial attitude and the Earth origin, so giving
 * earth.origin, trajectory.initial_attitude or trajectory.segments as well is an error. The
 * scene keeps no reference to the file: the writer writes the imported script as
 * type: segments (nav_scene has no field for the file name).
 *
 * recorded. The recorded reference file (relative to the scene file's directory, or absolute) is
 * read when the whole scene has been read (nav_track_read_file: malformed lines are reported as
 * FILE:LINE:COL) and fitted (nav_track_fit); the scene keeps the fitted model and the settings,
 * with the file name resolved to an absolute path, which the writer writes back (the fit is
 * deterministic, so reading the written scene gives the same model). The file sets the initial
 * attitude (giving trajectory.initial_attitude as well is an error) and, unless earth.origin is
 * given, the Earth origin: both are the model's state at the first sample. duration_s auto (or
 * absent) is the recorded span; a number must not exceed it.
 *
 * Waypoints given as lat/lon/h are converted to local NED with the scene's frame
 * (nav_frame_geodetic_to_local(nav_frame_from_scene(scene))) once the whole file, and so the
 * Earth section wherever it is, has been read; the writer writes the converted ned_m.
 */
#define _XOPEN_SOURCE 700 /* realpath */

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navcore/nav_frames.h"
#include "navcore/nav_motiondef.h"
#include "navcore/nav_track_io.h"
#include "scene_bounds.h"
#include "scene_io_internal.h"
#include "navcore/nav_traj.h"

#define OFF(member) offsetof(nav_scene, member)
#define SOFF(member) offsetof(nav_io_read_state, member)
#define WOFF(member) offsetof(nav_waypoint, member)
#define GOFF(member) offsetof(nav_segment, member)
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))
#define SECTION_OF(name, fields) static const nav_io_section name = {fields, COUNT(fields), NULL}

_Static_assert(sizeof(nav_wp_timing) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_wp_attitude_mode) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_segment_kind) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_test_motion_kind) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_recorded_format) == sizeof(int), "enum storage");

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

static bool same_vec3(nav_vec3 a, nav_vec3 b) {
  return same_bits(a.x, b.x) && same_bits(a.y, b.y) && same_bits(a.z, b.z);
}

/* Writer: a field that is written only when it differs from its default. */
static bool if_changed(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w;
  return !nav_io_field_same(f, base, def);
}

/* Writer: a section without storage in the scene (trajectory.motion_def). */
static bool never(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w;
  (void)f;
  (void)base;
  (void)def;
  return false;
}

/* One double (a base-relative offset) in a unit; the angle and rate spellings. */
#define D(k, off, sc, fl, ...)                                                                               \
  { .key = (k), .kind = NAV_IO_DOUBLE, .flags = (fl), .offset = (off), .scale = (sc), __VA_ARGS__ }
#define ANGLE(name, off, text)                                                                               \
  D(name "_deg", off, NAV_DEG2RAD, NAV_IO_FINITE, .doc = (text)),                                            \
      D(name "_rad", off, 1.0, NAV_IO_FINITE | NAV_IO_ALT, .doc = (text))
#define RATE(name, off, text)                                                                                \
  D(name "_dps", off, NAV_DEG2RAD, NAV_IO_FINITE, .doc = (text)),                                            \
      D(name "_rps", off, 1.0, NAV_IO_FINITE | NAV_IO_ALT, .doc = (text))
/* A rate that may also be given in Hz (cycles per second); written so when that is shorter. */
#define RATE_HZ_ALT(name, off, text)                                                                         \
  RATE(name, off, text),                                                                                     \
      D(name "_hz", off, NAV_TWO_PI, NAV_IO_FINITE | NAV_IO_ALT | NAV_IO_WRITE_ALT, .doc = (text))
#define NONNEG (NAV_IO_FINITE | NAV_IO_MIN_GE)
#define POSITIVE (NAV_IO_FINITE | NAV_IO_MIN_GT)
/* A speed within the plausibility bound of scene_bounds.h, in magnitude. */
#define SPEED(k, off, d)                                                                                     \
  {                                                                                                          \
    .key = (k), .kind = NAV_IO_DOUBLE, .flags = NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE,               \
    .offset = (off), .scale = 1.0, .min = -NAV_SCENE_MAX_SPEED_MPS, .max = NAV_SCENE_MAX_SPEED_MPS,          \
    .doc = (d)                                                                                               \
  }

/* ================================================================ initial attitude, parametric */

static const nav_io_field k_attitude[] = {
    ANGLE("roll", OFF(trajectory.initial_attitude.roll_rad), "initial roll of the reference (ZYX Euler)"),
    ANGLE("pitch", OFF(trajectory.initial_attitude.pitch_rad), "initial pitch of the reference (ZYX Euler)"),
    ANGLE("yaw", OFF(trajectory.initial_attitude.yaw_rad),
          "initial heading of the reference (ZYX Euler, from north)"),
};
SECTION_OF(k_attitude_section, k_attitude);

#define PV(k, member, sc, fl, d)                                                                             \
  {                                                                                                          \
    .key = (k), .kind = NAV_IO_VEC3, .flags = NAV_IO_FINITE | (fl),                                          \
    .offset = OFF(trajectory.parametric.member), .scale = (sc), .doc = (d)                                   \
  }

static const nav_io_field k_rate[] = {
    PV("a_rps", wa_rps, 1.0, 0, "angular rate law: constant term a per axis (w = a + b sin(2 pi c t + d))"),
    PV("a_dps", wa_rps, NAV_DEG2RAD, NAV_IO_ALT, NULL),
    PV("b_rps", wb_rps, 1.0, 0, "angular rate law: amplitude b per axis"),
    PV("b_dps", wb_rps, NAV_DEG2RAD, NAV_IO_ALT, NULL),
    PV("c_hz", wc_hz, 1.0, 0, "angular rate law: frequency c per axis"),
    PV("d_rad", wd_rad, 1.0, 0, "angular rate law: phase d per axis"),
    PV("d_deg", wd_rad, NAV_DEG2RAD, NAV_IO_ALT, NULL),
};
SECTION_OF(k_rate_section, k_rate);

static const nav_io_enum_value k_attitude_modes[] = {{"magnus", NAV_ATT_RATE_MAGNUS}, {NULL, 0}};

static const nav_io_field k_parametric[] = {
    PV("R0_m", r0_m, 1.0, 0, "position law: start position R0 per axis (paper's formula 3)"),
    /* Start velocity within the speed bound (scene_bounds.h), each component. */
    {.key = "V0_mps",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(trajectory.parametric.v0_mps),
     .scale = 1.0,
     .min = -NAV_SCENE_MAX_SPEED_MPS,
     .max = NAV_SCENE_MAX_SPEED_MPS,
     .doc = "position law: start velocity V0 per axis"},
    PV("A_mps2", a_mps2, 1.0, 0, "position law: constant acceleration A per axis"),
    PV("B_m", b_m, 1.0, 0, "position law: oscillation amplitude B per axis"),
    PV("C_hz", c_hz, 1.0, 0, "position law: oscillation frequency C per axis"),
    PV("D_rad", d_rad, 1.0, 0, "position law: oscillation phase D per axis"),
    PV("D_deg", d_rad, NAV_DEG2RAD, NAV_IO_ALT, NULL),
    {.key = "rate",
     .kind = NAV_IO_SECTION,
     .section = &k_rate_section,
     .doc = "angular rate law of the body, per axis"},
    {.key = "attitude",
     .kind = NAV_IO_ENUM,
     .offset = OFF(trajectory.parametric.attitude_mode),
     .enums = k_attitude_modes,
     .doc = "how the attitude follows from the rate law: magnus (Magnus expansion of the rate)"},
    /* Ranges of integers that only the simulation constrains are left to nav_scene_validate. */
    {.key = "magnus_substeps",
     .kind = NAV_IO_INT,
     .offset = OFF(trajectory.parametric.magnus_substeps),
     .doc = "sub-steps of the Magnus integration per IMU interval"},
};
SECTION_OF(k_parametric_section, k_parametric);

/* ================================================================ limits */

#define LIMITS(name, base)                                                                                   \
  static const nav_io_field name##_fields[] = {                                                              \
      D("max_accel_mps2", OFF(base.max_accel_mps2), 1.0, POSITIVE,                                           \
        .doc = "largest acceleration the planner may use"),                                                  \
      D("max_jerk_mps3", OFF(base.max_jerk_mps3), 1.0, POSITIVE, .doc = "largest jerk the planner may use"), \
      D("max_lateral_accel_mps2", OFF(base.max_lateral_accel_mps2), 1.0, POSITIVE,                           \
        .doc = "largest lateral (turn) acceleration"),                                                       \
      D("max_rate_dps", OFF(base.max_rate_rps), NAV_DEG2RAD, POSITIVE, .doc = "largest turn rate"),          \
      D("max_rate_rps", OFF(base.max_rate_rps), 1.0, POSITIVE | NAV_IO_ALT, .doc = "largest turn rate"),     \
      D("max_ang_accel_dps2", OFF(base.max_ang_accel_rps2), NAV_DEG2RAD, POSITIVE,                           \
        .doc = "largest angular acceleration"),                                                              \
      D("max_ang_accel_rps2", OFF(base.max_ang_accel_rps2), 1.0, POSITIVE | NAV_IO_ALT,                      \
        .doc = "largest angular acceleration"),                                                              \
      D("max_ang_jerk_dps3", OFF(base.max_ang_jerk_rps3), NAV_DEG2RAD, POSITIVE,                             \
        .doc = "largest angular jerk"),                                                                      \
      D("max_ang_jerk_rps3", OFF(base.max_ang_jerk_rps3), 1.0, POSITIVE | NAV_IO_ALT,                        \
        .doc = "largest angular jerk"),                                                                      \
  };                                                                                                         \
  SECTION_OF(name, name##_fields)

LIMITS(k_wp_limits_section, trajectory.waypoints.limits);
LIMITS(k_seg_limits_section, trajectory.segments.limits);

/* ================================================================ waypoints */

static bool wp_speed_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                             const void *def) {
  return w->scene->trajectory.waypoints.timing == NAV_WP_TIMING_SPEED || !nav_io_field_same(f, base, def);
}
static bool wp_time_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                            const void *def) {
  return w->scene->trajectory.waypoints.timing == NAV_WP_TIMING_TIME || !nav_io_field_same(f, base, def);
}
static bool wp_attitude_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                const void *def) {
  return w->scene->trajectory.waypoints.attitude_mode == NAV_WP_ATT_EULER || !nav_io_field_same(f, base, def);
}
static void finish_point(nav_io_reader *r, const nav_io_node *map, void *base);

static const nav_io_field k_wp_attitude[] = {
    ANGLE("roll", WOFF(attitude.roll_rad), "roll at the waypoint (attitude_mode euler)"),
    ANGLE("pitch", WOFF(attitude.pitch_rad), "pitch at the waypoint (attitude_mode euler)"),
    ANGLE("yaw", WOFF(attitude.yaw_rad), "heading at the waypoint (attitude_mode euler)"),
};
SECTION_OF(k_wp_attitude_section, k_wp_attitude);

/* One waypoint (base: nav_waypoint). lat/lon/h go to the reader state and are converted later. */
static const nav_io_field k_point[] = {
    {.key = "ned_m",
     .doc = "waypoint position in the local NED frame (or lat/lon/h)",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE,
     .offset = WOFF(r_ned_m),
     .scale = 1.0,
     .mark_as = "r_ned_m"},
    {.key = "lat_deg",
     .doc = "waypoint latitude (with lon and h, instead of ned_m)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_STATE | NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = SOFF(llh[0]),
     .scale = NAV_DEG2RAD,
     .min = -90.0,
     .max = 90.0},
    {.key = "lat_rad",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_STATE | NAV_IO_ALT | NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = SOFF(llh[0]),
     .scale = 1.0,
     .min = -NAV_PI / 2,
     .max = NAV_PI / 2},
    D("lon_deg", SOFF(llh[1]), NAV_DEG2RAD, NAV_IO_STATE | NAV_IO_FINITE,
      .doc = "waypoint longitude (with lat and h, instead of ned_m)"),
    D("lon_rad", SOFF(llh[1]), 1.0, NAV_IO_STATE | NAV_IO_FINITE | NAV_IO_ALT, .doc = NULL),
    D("h_m", SOFF(llh[2]), 1.0, NAV_IO_STATE | NAV_IO_FINITE,
      .doc = "waypoint ellipsoidal height (with lat and lon)"),
    {.key = "speed_mps",
     .doc = "speed at the waypoint (timing speed)",
     .kind = NAV_IO_DOUBLE,
     .flags = NONNEG,
     .offset = WOFF(speed_mps),
     .scale = 1.0,
     .write_if = wp_speed_written},
    {.key = "time_s",
     .doc = "time at the waypoint after the start of the motion (timing time)",
     .kind = NAV_IO_DOUBLE,
     .flags = NONNEG,
     .offset = WOFF(time_s),
     .scale = 1.0,
     .write_if = wp_time_written},
    {.key = "hold_s",
     .doc = "stationary time at an interior waypoint: the vehicle stops there (speed 0) this long and turns "
            "in place within it",
     .kind = NAV_IO_DOUBLE,
     .flags = NONNEG | NAV_IO_MAX_LE,
     .offset = WOFF(hold_s),
     .scale = 1.0,
     .max = NAV_SCENE_MAX_DURATION_S,
     .write_if = if_changed},
    {.key = "attitude",
     .kind = NAV_IO_SECTION,
     .flags = NAV_IO_FLOW,
     .section = &k_wp_attitude_section,
     .doc = "attitude at the waypoint (attitude_mode euler)",
     .write_if = wp_attitude_written},
};
static const nav_io_section k_point_section = {k_point, COUNT(k_point), finish_point};

/* After one waypoint: exactly one way of giving its position. */
static void finish_point(nav_io_reader *r, const nav_io_node *map, void *base) {
  nav_io_read_state *st = nav_io_reader_state(r);
  const nav_io_node *k_ned = NULL, *k_lat = NULL, *k_lon = NULL, *k_h = NULL, *k = NULL;
  if (!nav_io_node_is_map(map)) return;
  nav_io_map_get(map, "ned_m", &k_ned);
  if (nav_io_map_get(map, "lat_deg", &k) != NULL || nav_io_map_get(map, "lat_rad", &k) != NULL) k_lat = k;
  if (nav_io_map_get(map, "lon_deg", &k) != NULL || nav_io_map_get(map, "lon_rad", &k) != NULL) k_lon = k;
  nav_io_map_get(map, "h_m", &k_h);
  const nav_io_node *geo = k_lat != NULL ? k_lat : k_lon != NULL ? k_lon : k_h;
  if (k_ned != NULL && geo != NULL) {
    size_t len = 0;
    const char *t = nav_io_node_text(geo, &len);
    const size_t saved = nav_io_path_push_key(r, t);
    nav_io_reader_error(
        r, geo, NULL,
        "the waypoint position is given twice: use either ned_m: [N, E, D] or lat_deg, lon_deg "
        "and h_m");
    nav_io_path_pop(r, saved);
    return;
  }
  if (k_ned == NULL && geo == NULL) {
    nav_io_reader_error(r, map, NULL,
                        "the waypoint has no position: give ned_m: [N, E, D] (local NED from the origin) or "
                        "lat_deg, lon_deg and h_m");
    return;
  }
  if (geo == NULL) return;
  if (k_lat == NULL || k_lon == NULL || k_h == NULL) {
    nav_io_reader_error(r, map, NULL, "a geodetic waypoint needs lat_deg, lon_deg and h_m (%s missing)",
                        k_lat == NULL   ? "lat_deg is"
                        : k_lon == NULL ? "lon_deg is"
                                        : "h_m is");
    return;
  }
  const nav_waypoint *points = st->scene->trajectory.waypoints.points;
  const int index = (int)((const nav_waypoint *)base - points);
  if (st->ngeo == st->cap_geo) {
    const size_t cap = st->cap_geo ? 2 * st->cap_geo : 16;
    nav_io_geo_point *g = realloc(st->geo, cap * sizeof *g);
    if (g == NULL) {
      nav_io_reader_error(r, map, NULL, "out of memory");
      return;
    }
    st->geo = g;
    st->cap_geo = cap;
  }
  nav_io_geo_point *g = &st->geo[st->ngeo++];
  g->index = index;
  memcpy(g->llh, st->llh, sizeof g->llh);
}

static void read_points(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                        void *base) {
  nav_traj_waypoints *W = (nav_traj_waypoints *)((char *)base + f->offset);
  nav_io_read_state *st = nav_io_reader_state(r);
  if (nav_io_reject_special(r, key, v)) return;
  if (!nav_io_node_is_seq(v)) {
    nav_io_expected(r, key, v, "a list of waypoints (- {ned_m: [N, E, D], speed_mps: V})");
    return;
  }
  const size_t n = nav_io_node_count(v);
  if (n > NAV_MAX_WAYPOINTS) {
    nav_io_reader_error(r, v, key, "at most %d waypoints are supported (got %zu)", NAV_MAX_WAYPOINTS, n);
    return;
  }
  W->count = (int)n;
  size_t i = 0;
  for (const nav_io_node *item = nav_io_node_child(v); item != NULL; item = nav_io_node_next(item), ++i) {
    const size_t saved = nav_io_path_push_index(r, i);
    nav_io_mark(r, item, v);
    st->llh[0] = st->llh[1] = st->llh[2] = 0.0;
    if (nav_io_reject_special(r, v, item)) {
      /* reported */
    } else if (!nav_io_node_is_map(item)) {
      nav_io_expected(r, v, item, "a waypoint ({ned_m: [N, E, D], ...} or {lat_deg, lon_deg, h_m, ...})");
    } else {
      nav_io_read_section(r, &k_point_section, v, item, &W->points[i]);
    }
    nav_io_path_pop(r, saved);
  }
}

static nav_status write_points(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  const nav_traj_waypoints *W = (const nav_traj_waypoints *)((const char *)base + f->offset);
  static const nav_waypoint zero; /* the default of every waypoint */
  if (W->count <= 0) return nav_io_writef(w, " []");
  nav_status st = NAV_OK;
  for (int i = 0; i < W->count && i < NAV_MAX_WAYPOINTS && st == NAV_OK; ++i) {
    st = nav_io_writef(w, "\n%*s- ", indent + 2, "");
    if (st == NAV_OK) st = nav_io_write_flow(w, &k_point_section, &W->points[i], &zero);
  }
  return st;
}

static bool same_point(const nav_waypoint *a, const nav_waypoint *b) {
  return same_vec3(a->r_ned_m, b->r_ned_m) && same_bits(a->speed_mps, b->speed_mps) &&
         same_bits(a->time_s, b->time_s) && same_bits(a->attitude.roll_rad, b->attitude.roll_rad) &&
         same_bits(a->attitude.pitch_rad, b->attitude.pitch_rad) &&
         same_bits(a->attitude.yaw_rad, b->attitude.yaw_rad) && same_bits(a->hold_s, b->hold_s);
}

static bool same_points(const nav_io_field *f, const void *a, const void *b) {
  const nav_traj_waypoints *A = (const nav_traj_waypoints *)((const char *)a + f->offset);
  const nav_traj_waypoints *B = (const nav_traj_waypoints *)((const char *)b + f->offset);
  if (A->count != B->count) return false;
  for (int i = 0; i < A->count && i < NAV_MAX_WAYPOINTS; ++i)
    if (!same_point(&A->points[i], &B->points[i])) return false;
  return true;
}

static const nav_io_enum_value k_timings[] = {
    {"speed", NAV_WP_TIMING_SPEED}, {"time", NAV_WP_TIMING_TIME}, {NULL, 0}};
static const nav_io_enum_value k_wp_attitude_modes[] = {{"ground", NAV_WP_ATT_GROUND},
                                                        {"aircraft", NAV_WP_ATT_AIRCRAFT},
                                                        {"fixed", NAV_WP_ATT_FIXED},
                                                        {"euler", NAV_WP_ATT_EULER},
                                                        {NULL, 0}};

static const nav_io_field k_waypoints[] = {
    {.key = "timing",
     .doc = "how the motion between waypoints is timed",
     .kind = NAV_IO_ENUM,
     .offset = OFF(trajectory.waypoints.timing),
     .enums = k_timings,
     .comment = "speed: speed_mps at every waypoint; time: time_s at every waypoint"},
    {.key = "attitude_mode",
     .doc = "how the attitude follows the path: ground, aircraft (banked), fixed or euler (per waypoint)",
     .kind = NAV_IO_ENUM,
     .offset = OFF(trajectory.waypoints.attitude_mode),
     .enums = k_wp_attitude_modes},
    D("hold_start_s", OFF(trajectory.waypoints.hold_start_s), 1.0, NONNEG,
      .doc = "stationary time before the motion"),
    D("hold_end_s", OFF(trajectory.waypoints.hold_end_s), 1.0, NONNEG,
      .doc = "stationary time after the motion"),
    {.key = "cruise_mps",
     .doc = "speed between two stops (timing speed)",
     .kind = NAV_IO_DOUBLE,
     .flags = NONNEG,
     .offset = OFF(trajectory.waypoints.cruise_mps),
     .scale = 1.0,
     .write_if = if_changed,
     .comment = "speed between two stops (timing speed)"},
    {.key = "limits",
     .doc = "dynamic limits the planner respects",
     .kind = NAV_IO_SECTION,
     .flags = NAV_IO_FLOW,
     .section = &k_wp_limits_section},
    {.key = "points",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(trajectory.waypoints),
     .read = read_points,
     .write = write_points,
     .same = same_points,
     .doc = "waypoints: a position (ned_m, or lat/lon/h), and speed_mps or time_s by the timing",
     .items = &k_point_section,
     .max_items = NAV_MAX_WAYPOINTS},
};
SECTION_OF(k_waypoints_section, k_waypoints);

/* ================================================================ kind-dependent mappings */

/* Kind-dependent mappings: nav_io_kinded (scene_io_internal.h). */
typedef nav_io_kinded kinded;

static void read_kinded(nav_io_reader *r, const kinded *kd, const nav_io_node *key, const nav_io_node *v,
                        void *base) {
  char list[256];
  size_t l = 0;
  list[0] = '\0';
  for (size_t i = 0; kd->kinds[i].name != NULL; ++i) {
    const int n = snprintf(list + l, sizeof list - l, "%s%s", i ? ", " : "", kd->kinds[i].name);
    if (n > 0 && (size_t)n < sizeof list - l) l += (size_t)n;
  }
  if (nav_io_reject_special(r, key, v)) return;
  if (!nav_io_node_is_map(v)) {
    char what[320];
    snprintf(what, sizeof what, "a mapping with kind: (%s) and that kind's keys", list);
    nav_io_expected(r, key, v, what);
    return;
  }
  const nav_io_node *kkey = NULL;
  const nav_io_node *kv = nav_io_map_get(v, "kind", &kkey);
  const size_t saved = nav_io_path_push_key(r, "kind");
  if (kv == NULL) {
    nav_io_reader_error(r, v, key, "missing required key \"kind\" (one of: %s)", list);
    nav_io_path_pop(r, saved);
    return;
  }
  int kind = 0;
  const bool ok = nav_io_read_enum_value(r, kd->kinds, kkey, kv, &kind);
  nav_io_path_pop(r, saved);
  /* An unknown kind: its keys cannot be checked against anything sensible. */
  if (!ok || kind < 0 || (size_t)kind >= kd->nsections) return;
  nav_io_read_section(r, kd->sections[kind], key, v, base);
}

static const nav_io_section *kinded_section(const kinded *kd, const void *base) {
  const int kind = *(const int *)((const char *)base + kd->kind_offset);
  return kind >= 0 && (size_t)kind < kd->nsections ? kd->sections[kind] : NULL;
}

/* ---------------------------------------------------------------- segments */

static const nav_io_enum_value k_seg_kinds[] = {{"hold", NAV_SEG_HOLD},
                                                {"accelerate", NAV_SEG_ACCELERATE},
                                                {"turn", NAV_SEG_TURN},
                                                {"coordinated_turn", NAV_SEG_COORD_TURN},
                                                {"climb", NAV_SEG_CLIMB},
                                                {"circle", NAV_SEG_CIRCLE},
                                                {"figure_eight", NAV_SEG_FIGURE_EIGHT},
                                                {"helix", NAV_SEG_HELIX},
                                                {"lawnmower", NAV_SEG_LAWNMOWER},
                                                {"motion_rates", NAV_SEG_MOTION_RATES},
                                                {"motion_abs_abs", NAV_SEG_MOTION_ABS_ABS},
                                                {"motion_rel_rel", NAV_SEG_MOTION_REL_REL},
                                                {"motion_abs_rel", NAV_SEG_MOTION_ABS_REL},
                                                {"motion_rel_abs", NAV_SEG_MOTION_REL_ABS},
                                                {NULL, 0}};

/* Keys shared by the segment kinds (base: nav_segment). */
#define SEG_KIND                                                                                             \
  {                                                                                                          \
    .key = "kind", .kind = NAV_IO_ENUM, .offset = GOFF(kind), .enums = k_seg_kinds,                          \
    .doc = "what the segment does"                                                                           \
  }
#define SEG_DURATION                                                                                         \
  {                                                                                                          \
    .key = "duration_s", .kind = NAV_IO_DOUBLE, .flags = NONNEG | NAV_IO_MAX_LE, .offset = GOFF(duration_s), \
    .scale = 1.0, .max = NAV_SCENE_MAX_DURATION_S,                                                           \
    .doc = "duration (motion_abs/rel kinds: the most it may take)"                                           \
  }
#define SEG_COORDINATED                                                                                      \
  {                                                                                                          \
    .key = "coordinated", .kind = NAV_IO_BOOL, .offset = GOFF(coordinated), .write_if = if_changed,          \
    .doc = "bank into turns (roll = atan(V yaw rate / g))"                                                   \
  }
#define SEG_GNSS_VISIBLE                                                                                     \
  {                                                                                                          \
    .key = "gnss_visible", .kind = NAV_IO_BOOL, .offset = GOFF(gnss_visible), .write_if = if_changed,        \
    .doc = "GNSS visible during the segment (motion-definition column, for outages)"                         \
  }
#define SEG_V3(k, member, d)                                                                                 \
  {                                                                                                          \
    .key = (k), .kind = NAV_IO_VEC3, .flags = NAV_IO_FINITE, .offset = GOFF(member), .scale = 1.0,           \
    .doc = (d)                                                                                               \
  }

static const nav_io_field k_seg_hold[] = {SEG_KIND, SEG_DURATION, SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_accelerate[] = {
    SEG_KIND, SPEED("speed_mps", GOFF(speed_mps), "speed at the end of the segment"), SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_turn[] = {
    SEG_KIND, ANGLE("yaw", GOFF(yaw_rad), "heading change of the turn (+ = right)"),
    RATE("yaw_rate", GOFF(yaw_rate_rps), "turn rate (0: the largest the limits allow)"), SEG_COORDINATED,
    SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_coord_turn[] = {
    SEG_KIND, ANGLE("yaw", GOFF(yaw_rad), "heading change of the turn (+ = right)"),
    RATE("yaw_rate", GOFF(yaw_rate_rps), "turn rate (0: the largest the limits allow)"), SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_climb[] = {
    SEG_KIND, D("height_m", GOFF(height_m), 1.0, NAV_IO_FINITE, .doc = "height gained (+ = up)"),
    ANGLE("pitch", GOFF(pitch_rad), "flight-path angle of the climb"), SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_circle[] = {
    SEG_KIND, D("radius_m", GOFF(radius_m), 1.0, POSITIVE, .doc = "turn radius"),
    D("turns", GOFF(turns), 1.0, NAV_IO_FINITE, .unit = "1",
      .doc = "number of turns (+ = right; figure_eight: per lobe)"),
    SEG_COORDINATED, SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_helix[] = {
    SEG_KIND,
    D("radius_m", GOFF(radius_m), 1.0, POSITIVE, .doc = "turn radius"),
    D("turns", GOFF(turns), 1.0, NAV_IO_FINITE, .unit = "1",
      .doc = "number of turns (+ = right; figure_eight: per lobe)"),
    ANGLE("pitch", GOFF(pitch_rad), "flight-path angle of the helix (+ = climbing)"),
    SEG_COORDINATED,
    SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_lawnmower[] = {
    SEG_KIND,
    {.key = "legs",
     .kind = NAV_IO_INT,
     .flags = NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = GOFF(legs),
     .min = 1.0,
     .max = 100000.0,
     .doc = "number of straight legs"},
    D("length_m", GOFF(length_m), 1.0, NONNEG, .doc = "straight length of each leg"),
    D("spacing_m", GOFF(spacing_m), 1.0, NAV_IO_FINITE,
      .doc = "distance between legs (+ = first turn right)"),
    SEG_COORDINATED,
    SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_rates[] = {
    SEG_KIND,
    RATE("yaw_rate", GOFF(yaw_rate_rps), "yaw rate held over the segment"),
    RATE("pitch_rate", GOFF(pitch_rate_rps), "pitch rate held over the segment"),
    RATE("roll_rate", GOFF(roll_rate_rps), "roll rate held over the segment"),
    SEG_V3("accel_b_mps2", accel_b_mps2, "body-axis acceleration held over the segment"),
    SEG_DURATION,
    SEG_COORDINATED,
    SEG_GNSS_VISIBLE};
static const nav_io_field k_seg_motion[] = {
    SEG_KIND,
    ANGLE("yaw", GOFF(yaw_rad), "yaw command: absolute or change, by the kind (gnss-ins-sim types 2-5)"),
    ANGLE("pitch", GOFF(pitch_rad), "pitch command: absolute or change, by the kind"),
    ANGLE("roll", GOFF(roll_rad), "roll command: absolute or change, by the kind"),
    SEG_V3("v_b_mps", v_b_mps, "body velocity command: absolute or change, by the kind"),
    SEG_DURATION,
    SEG_COORDINATED,
    SEG_GNSS_VISIBLE};
SECTION_OF(k_seg_hold_section, k_seg_hold);
SECTION_OF(k_seg_accelerate_section, k_seg_accelerate);
SECTION_OF(k_seg_turn_section, k_seg_turn);
SECTION_OF(k_seg_coord_turn_section, k_seg_coord_turn);
SECTION_OF(k_seg_climb_section, k_seg_climb);
SECTION_OF(k_seg_circle_section, k_seg_circle);
SECTION_OF(k_seg_helix_section, k_seg_helix);
SECTION_OF(k_seg_lawnmower_section, k_seg_lawnmower);
SECTION_OF(k_seg_rates_section, k_seg_rates);
SECTION_OF(k_seg_motion_section, k_seg_motion);

static const nav_io_section *const k_seg_sections[] = {
    [NAV_SEG_HOLD] = &k_seg_hold_section,
    [NAV_SEG_ACCELERATE] = &k_seg_accelerate_section,
    [NAV_SEG_TURN] = &k_seg_turn_section,
    [NAV_SEG_COORD_TURN] = &k_seg_coord_turn_section,
    [NAV_SEG_CLIMB] = &k_seg_climb_section,
    [NAV_SEG_CIRCLE] = &k_seg_circle_section,
    [NAV_SEG_FIGURE_EIGHT] = &k_seg_circle_section,
    [NAV_SEG_HELIX] = &k_seg_helix_section,
    [NAV_SEG_LAWNMOWER] = &k_seg_lawnmower_section,
    [NAV_SEG_MOTION_RATES] = &k_seg_rates_section,
    [NAV_SEG_MOTION_ABS_ABS] = &k_seg_motion_section,
    [NAV_SEG_MOTION_REL_REL] = &k_seg_motion_section,
    [NAV_SEG_MOTION_ABS_REL] = &k_seg_motion_section,
    [NAV_SEG_MOTION_REL_ABS] = &k_seg_motion_section,
};
static const kinded k_seg_kinded = {k_seg_kinds, k_seg_sections, COUNT(k_seg_sections), GOFF(kind)};

/* A fresh segment: what nav_scene_default() holds in every slot. */
static nav_segment default_segment(void) {
  nav_segment g;
  memset(&g, 0, sizeof g);
  g.gnss_visible = true;
  return g;
}

static void read_items(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                       void *base) {
  nav_traj_segments *S = (nav_traj_segments *)((char *)base + f->offset);
  if (nav_io_reject_special(r, key, v)) return;
  if (!nav_io_node_is_seq(v)) {
    nav_io_expected(r, key, v, "a list of segments (- {kind: hold, duration_s: 10})");
    return;
  }
  const size_t n = nav_io_node_count(v);
  if (n > NAV_MAX_SEGMENTS) {
    nav_io_reader_error(r, v, key, "at most %d segments are supported (got %zu)", NAV_MAX_SEGMENTS, n);
    return;
  }
  S->count = (int)n;
  size_t i = 0;
  for (const nav_io_node *item = nav_io_node_child(v); item != NULL; item = nav_io_node_next(item), ++i) {
    const size_t saved = nav_io_path_push_index(r, i);
    nav_io_mark(r, item, v);
    S->items[i] = default_segment();
    read_kinded(r, &k_seg_kinded, v, item, &S->items[i]);
    nav_io_path_pop(r, saved);
  }
}

static nav_status write_items(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  const nav_traj_segments *S = (const nav_traj_segments *)((const char *)base + f->offset);
  const nav_segment def = default_segment();
  if (S->count <= 0) return nav_io_writef(w, " []");
  nav_status st = NAV_OK;
  for (int i = 0; i < S->count && i < NAV_MAX_SEGMENTS && st == NAV_OK; ++i) {
    const nav_io_section *sec = kinded_section(&k_seg_kinded, &S->items[i]);
    if (sec == NULL) return NAV_ERR_INVALID_ARG; /* not a segment kind: nothing to write */
    st = nav_io_writef(w, "\n%*s- ", indent + 2, "");
    if (st == NAV_OK) st = nav_io_write_flow(w, sec, &S->items[i], &def);
  }
  return st;
}

static bool same_segment(const nav_segment *a, const nav_segment *b) {
  return a->kind == b->kind && a->coordinated == b->coordinated && a->gnss_visible == b->gnss_visible &&
         a->legs == b->legs && same_bits(a->duration_s, b->duration_s) && same_bits(a->yaw_rad, b->yaw_rad) &&
         same_bits(a->pitch_rad, b->pitch_rad) && same_bits(a->roll_rad, b->roll_rad) &&
         same_bits(a->yaw_rate_rps, b->yaw_rate_rps) && same_bits(a->pitch_rate_rps, b->pitch_rate_rps) &&
         same_bits(a->roll_rate_rps, b->roll_rate_rps) && same_vec3(a->v_b_mps, b->v_b_mps) &&
         same_vec3(a->accel_b_mps2, b->accel_b_mps2) && same_bits(a->speed_mps, b->speed_mps) &&
         same_bits(a->height_m, b->height_m) && same_bits(a->radius_m, b->radius_m) &&
         same_bits(a->turns, b->turns) && same_bits(a->length_m, b->length_m) &&
         same_bits(a->spacing_m, b->spacing_m);
}

static bool same_items(const nav_io_field *f, const void *a, const void *b) {
  const nav_traj_segments *A = (const nav_traj_segments *)((const char *)a + f->offset);
  const nav_traj_segments *B = (const nav_traj_segments *)((const char *)b + f->offset);
  if (A->count != B->count) return false;
  for (int i = 0; i < A->count && i < NAV_MAX_SEGMENTS; ++i)
    if (!same_segment(&A->items[i], &B->items[i])) return false;
  return true;
}

static const nav_io_field k_segments[] = {
    {.key = "r0_ned_m",
     .doc = "start position in the local NED frame",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE,
     .offset = OFF(trajectory.segments.r0_ned_m),
     .scale = 1.0,
     .comment = "start position, local NED"},
    {.key = "v0_b_mps",
     .doc = "start velocity in body axes",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(trajectory.segments.v0_b_mps),
     .scale = 1.0,
     .min = -NAV_SCENE_MAX_SPEED_MPS,
     .max = NAV_SCENE_MAX_SPEED_MPS,
     .comment = "start velocity, body axes"},
    {.key = "allow_unconverged",
     .doc = "accept a segment whose planner did not converge (kept as planned)",
     .kind = NAV_IO_BOOL,
     .offset = OFF(trajectory.segments.allow_unconverged)},
    {.key = "fit_rate_ramps",
     .doc = "fit the rate ramps of a motion definition instead of stepping them",
     .kind = NAV_IO_BOOL,
     .offset = OFF(trajectory.segments.fit_rate_ramps)},
    {.key = "limits",
     .doc = "dynamic limits the planner respects",
     .kind = NAV_IO_SECTION,
     .flags = NAV_IO_FLOW,
     .section = &k_seg_limits_section},
    {.key = "items",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(trajectory.segments),
     .read = read_items,
     .write = write_items,
     .same = same_items,
     .doc = "the segments, flown in order; each a kind and that kind's keys",
     .kinded = &k_seg_kinded,
     .items_kinded = true,
     .max_items = NAV_MAX_SEGMENTS},
};
SECTION_OF(k_segments_section, k_segments);

/* ---------------------------------------------------------------- test motions */

#define TM(member) OFF(trajectory.test_motion.member)
static const nav_io_enum_value k_tm_kinds[] = {{"stationary", NAV_TEST_MOTION_STATIONARY},
                                               {"coning", NAV_TEST_MOTION_CONING},
                                               {"sculling", NAV_TEST_MOTION_SCULLING},
                                               {"spin", NAV_TEST_MOTION_SPIN},
                                               {"polar_great_circle", NAV_TEST_MOTION_POLAR_GREAT_CIRCLE},
                                               {"vertical_loop", NAV_TEST_MOTION_VERTICAL_LOOP},
                                               {NULL, 0}};
#define TM_KIND                                                                                              \
  { .key = "kind", .kind = NAV_IO_ENUM, .offset = TM(kind), .enums = k_tm_kinds, .doc = "which test motion" }

static const nav_io_field k_tm_stationary[] = {TM_KIND};
static const nav_io_field k_tm_coning[] = {
    TM_KIND, ANGLE("cone_half_angle", TM(cone_half_angle_rad), "half angle of the coning cone"),
    RATE_HZ_ALT("cone_rate", TM(cone_rate_rps), "coning frequency")};
static const nav_io_field k_tm_sculling[] = {
    TM_KIND, ANGLE("scull_angle", TM(scull_angle_rad), "angular amplitude of the sculling motion"),
    D("scull_accel_mps2", TM(scull_accel_mps2), 1.0, NAV_IO_FINITE,
      .doc = "acceleration amplitude of the sculling motion"),
    RATE_HZ_ALT("scull_rate", TM(scull_rate_rps), "sculling frequency")};
static const nav_io_field k_tm_spin[] = {
    TM_KIND,
    RATE_HZ_ALT("spin_rate", TM(spin_rate_rps), "spin rate about the spin axis"),
    D("spin_rate_rpm", TM(spin_rate_rps), NAV_TWO_PI / 60.0, NAV_IO_FINITE | NAV_IO_ALT | NAV_IO_WRITE_ALT,
      .doc = "spin rate about the spin axis"),
    {.key = "spin_axis_b",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE,
     .offset = TM(spin_axis_b),
     .scale = 1.0,
     .comment = "body axes; any non-zero length",
     .unit = "1",
     .doc = "spin axis in body axes (any non-zero length)"}};
static const nav_io_field k_tm_great_circle[] = {
    TM_KIND,
    D("gc_height_m", TM(gc_height_m), 1.0, NAV_IO_FINITE,
      .doc = "height of the great circle above the ellipsoid"),
    SPEED("gc_speed_mps", TM(gc_speed_mps), "speed along the great circle"),
    ANGLE("gc_start_angle", TM(gc_start_angle_rad), "geocentric angle from the equator at t = 0"),
    ANGLE("gc_lon", TM(gc_lon_rad), "longitude of the meridian plane")};
static const nav_io_field k_tm_loop[] = {
    TM_KIND, SPEED("loop_speed_mps", TM(loop_speed_mps), "speed around the loop"),
    RATE("loop_pitch_rate", TM(loop_pitch_rate_rps), "pitch rate around the loop")};
SECTION_OF(k_tm_stationary_section, k_tm_stationary);
SECTION_OF(k_tm_coning_section, k_tm_coning);
SECTION_OF(k_tm_sculling_section, k_tm_sculling);
SECTION_OF(k_tm_spin_section, k_tm_spin);
SECTION_OF(k_tm_great_circle_section, k_tm_great_circle);
SECTION_OF(k_tm_loop_section, k_tm_loop);
static const nav_io_section *const k_tm_sections[] = {
    [NAV_TEST_MOTION_STATIONARY] = &k_tm_stationary_section,
    [NAV_TEST_MOTION_CONING] = &k_tm_coning_section,
    [NAV_TEST_MOTION_SCULLING] = &k_tm_sculling_section,
    [NAV_TEST_MOTION_SPIN] = &k_tm_spin_section,
    [NAV_TEST_MOTION_POLAR_GREAT_CIRCLE] = &k_tm_great_circle_section,
    [NAV_TEST_MOTION_VERTICAL_LOOP] = &k_tm_loop_section,
};
static const kinded k_tm_kinded = {k_tm_kinds, k_tm_sections, COUNT(k_tm_sections), TM(kind)};

static void read_test_motion(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                             const nav_io_node *v, void *base) {
  (void)f;
  read_kinded(r, &k_tm_kinded, key, v, base);
}

static nav_status write_test_motion(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)f;
  const nav_io_section *sec = kinded_section(&k_tm_kinded, base);
  if (sec == NULL) return NAV_ERR_INVALID_ARG;
  return nav_io_write_lines(w, sec, base, w->def, indent + 2);
}

static bool same_test_motion(const nav_io_field *f, const void *a, const void *b) {
  (void)f;
  const nav_traj_test_motion *A = &((const nav_scene *)a)->trajectory.test_motion;
  const nav_traj_test_motion *B = &((const nav_scene *)b)->trajectory.test_motion;
  return A->kind == B->kind && same_bits(A->cone_half_angle_rad, B->cone_half_angle_rad) &&
         same_bits(A->cone_rate_rps, B->cone_rate_rps) && same_bits(A->scull_angle_rad, B->scull_angle_rad) &&
         same_bits(A->scull_accel_mps2, B->scull_accel_mps2) &&
         same_bits(A->scull_rate_rps, B->scull_rate_rps) && same_bits(A->spin_rate_rps, B->spin_rate_rps) &&
         same_vec3(A->spin_axis_b, B->spin_axis_b) && same_bits(A->gc_height_m, B->gc_height_m) &&
         same_bits(A->gc_speed_mps, B->gc_speed_mps) &&
         same_bits(A->gc_start_angle_rad, B->gc_start_angle_rad) && same_bits(A->gc_lon_rad, B->gc_lon_rad) &&
         same_bits(A->loop_speed_mps, B->loop_speed_mps) &&
         same_bits(A->loop_pitch_rate_rps, B->loop_pitch_rate_rps);
}

/* ================================================================ motion_def, duration, type */

static const nav_io_field k_motion_def[] = {
    {.key = "file",
     .doc = "file of the trajectory (relative to the scene file)",
     .kind = NAV_IO_STRING,
     .flags = NAV_IO_STATE | NAV_IO_REQUIRED,
     .offset = SOFF(md_file),
     .size = NAV_IO_PATH_MAX},
    {.key = "allow_unconverged",
     .doc = "accept a segment whose planner did not converge (kept as planned)",
     .kind = NAV_IO_BOOL,
     .flags = NAV_IO_STATE,
     .offset = SOFF(md_allow_unconverged)},
    {.key = "fit_rate_ramps",
     .doc = "fit the rate ramps of a motion definition instead of stepping them",
     .kind = NAV_IO_BOOL,
     .flags = NAV_IO_STATE,
     .offset = SOFF(md_fit_rate_ramps)},
};
SECTION_OF(k_motion_def_section, k_motion_def);

/* trajectory.recorded: settings only; the file is read and fitted after the whole scene. */
#define RO(member) OFF(trajectory.recorded.member)
static const nav_io_enum_value k_recorded_formats[] = {{"kf_gins_nav", NAV_RECORDED_KF_GINS_NAV}, {NULL, 0}};
static const nav_io_field k_recorded[] = {
    {.key = "file",
     .doc = "file of the trajectory (relative to the scene file)",
     .kind = NAV_IO_STRING,
     .flags = NAV_IO_REQUIRED,
     .offset = RO(file),
     .size = NAV_RECORDED_PATH_MAX},
    {.key = "format",
     .doc = "format of the recorded file",
     .kind = NAV_IO_ENUM,
     .offset = RO(format),
     .enums = k_recorded_formats},
    {.key = "start_s",
     .doc = "first recorded time used (file time base)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = RO(start_s),
     .scale = 1.0,
     .bit = NAV_RECORDED_HAS_START,
     .bits_offset = RO(window),
     .comment = "file time base"},
    {.key = "end_s",
     .doc = "last recorded time used (file time base)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = RO(end_s),
     .scale = 1.0,
     .bit = NAV_RECORDED_HAS_END,
     .bits_offset = RO(window)},
    {.key = "knot_rate_hz",
     .doc = "B-spline knots per second of the fit (its bandwidth)",
     .kind = NAV_IO_DOUBLE,
     .flags = POSITIVE | NAV_IO_MAX_LE,
     .offset = RO(knot_rate_hz),
     .scale = 1.0,
     .min = 0.0,
     .max = 1000.0},
    D("pos_sd_m", RO(pos_sd_m), 1.0, POSITIVE,
      .doc = "fit weight of a recorded position (1 / sigma^2 per axis)"),
    D("vel_sd_mps", RO(vel_sd_mps), 1.0, POSITIVE,
      .doc = "fit weight of a recorded velocity (1 / sigma^2 per axis)"),
};
SECTION_OF(k_recorded_section, k_recorded);

/* duration_s: a number of seconds, or auto (the length of a waypoint or segment script). */
static void read_duration(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                          const nav_io_node *v, void *base) {
  nav_io_read_state *st = nav_io_reader_state(r);
  if (nav_io_node_text_is(v, "auto")) {
    st->duration_auto = true;
    st->duration_auto_given = true;
    return;
  }
  double d = 0.0;
  if (!nav_io_read_number(r, key, v, &d) || !nav_io_check_number(r, f, key, v, d)) return;
  *(double *)((char *)base + f->offset) = d;
  st->duration_auto = false;
}

static nav_status write_duration(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)indent;
  const nav_status st = nav_io_writef(w, " ");
  return st != NAV_OK ? st : nav_io_write_double(w, *(const double *)((const char *)base + f->offset));
}

static bool same_duration(const nav_io_field *f, const void *a, const void *b) {
  return same_bits(*(const double *)((const char *)a + f->offset),
                   *(const double *)((const char *)b + f->offset));
}

/* A number within the descriptor's bounds, or the word auto (the bounds apply to numbers only). */
static void schema_duration(nav_io_json *j, const nav_io_field *f) {
  nav_io_json_key(j, "type");
  nav_io_json_raw(j, "[\"number\", \"string\"]");
  nav_io_json_key(j, "pattern");
  nav_io_json_string(j, "^auto$");
  nav_io_json_key(j, "exclusiveMinimum");
  nav_io_json_number(j, f->min);
  nav_io_json_key(j, "maximum");
  nav_io_json_number(j, f->max);
}

/* Sections of trajectory types: the selected one always, the others when they hold non-defaults. */
static bool type_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  nav_traj_type t = NAV_TRAJ_PARAMETRIC;
  if (f->section == &k_waypoints_section)
    t = NAV_TRAJ_WAYPOINTS;
  else if (f->section == &k_segments_section)
    t = NAV_TRAJ_SEGMENTS;
  else if (f->section == &k_recorded_section)
    t = NAV_TRAJ_RECORDED;
  else if (f->kind == NAV_IO_CUSTOM)
    t = NAV_TRAJ_TEST_MOTION;
  return w->scene->trajectory.type == t || !nav_io_field_same(f, base, def);
}

static const nav_io_enum_value k_traj_types[] = {
    {"parametric", NAV_TRAJ_PARAMETRIC},    {"waypoints", NAV_TRAJ_WAYPOINTS},
    {"segments", NAV_TRAJ_SEGMENTS},        {"test_motion", NAV_TRAJ_TEST_MOTION},
    {"motion_def", NAV_IO_TRAJ_MOTION_DEF}, {"recorded", NAV_TRAJ_RECORDED}, {NULL, 0}};

/* The initial attitude of a recorded trajectory is the recorded one: not written. */
static bool attitude_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)f;
  (void)base;
  (void)def;
  return w->scene->trajectory.type != NAV_TRAJ_RECORDED;
}

static const nav_io_field k_trajectory[] = {
    {.key = "type",
     .doc = "which trajectory model the scene uses",
     .kind = NAV_IO_ENUM,
     .offset = OFF(trajectory.type),
     .enums = k_traj_types},
    {.key = "duration_s",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GT | NAV_IO_MAX_LE,
     .offset = OFF(trajectory.duration_s),
     .scale = 1.0,
     .min = 0.0,
     .max = NAV_SCENE_MAX_DURATION_S,
     .read = read_duration,
     .write = write_duration,
     .same = same_duration,
     .doc = "length of the trajectory, or auto: the length of a waypoint or segment script",
     .schema = schema_duration},
    {.key = "initial_attitude",
     .doc = "attitude of the reference at t = 0 (parametric, segments, test motions)",
     .kind = NAV_IO_SECTION,
     .flags = NAV_IO_FLOW,
     .section = &k_attitude_section,
     .write_if = attitude_written},
    {.key = "parametric",
     .doc = "the paper's parametric trajectory: position and rate laws (type parametric)",
     .kind = NAV_IO_SECTION,
     .section = &k_parametric_section,
     .write_if = type_written},
    {.key = "waypoints",
     .doc = "a path through waypoints with speeds or times (type waypoints)",
     .kind = NAV_IO_SECTION,
     .section = &k_waypoints_section,
     .write_if = type_written},
    {.key = "segments",
     .doc = "a script of segments: hold, accelerate, turn, climb, ... (type segments)",
     .kind = NAV_IO_SECTION,
     .section = &k_segments_section,
     .write_if = type_written},
    {.key = "test_motion",
     .kind = NAV_IO_CUSTOM,
     .read = read_test_motion,
     .write = write_test_motion,
     .same = same_test_motion,
     .write_if = type_written,
     .doc = "a test motion (type test_motion): its kind and that kind's keys",
     .kinded = &k_tm_kinded},
    {.key = "motion_def",
     .doc = "a gnss-ins-sim motion definition file, imported as segments (type motion_def)",
     .kind = NAV_IO_SECTION,
     .section = &k_motion_def_section,
     .write_if = never},
    {.key = "recorded",
     .doc = "a recorded reference trajectory fitted by a B-spline (type recorded)",
     .kind = NAV_IO_SECTION,
     .section = &k_recorded_section,
     .write_if = type_written},
};
const nav_io_section nav_io_trajectory_section = {k_trajectory, COUNT(k_trajectory), NULL};

/* ================================================================ after the whole file */

/* Files a scene names (scene_io_internal.h): relative to the scene file's directory. */
bool nav_io_resolve_path(char *out, size_t size, const char *scene_file, bool is_path, const char *file) {
  const char *slash = scene_file != NULL ? strrchr(scene_file, '/') : NULL;
  if (file[0] == '/' || (slash == NULL && !is_path)) return snprintf(out, size, "%s", file) < (int)size;
  char dir[NAV_IO_PATH_MAX];
  const int n = slash == NULL ? snprintf(dir, sizeof dir, ".")
                              : snprintf(dir, sizeof dir, "%.*s",
                                         slash == scene_file ? 1 : (int)(slash - scene_file), scene_file);
  if (n < 0 || n >= (int)sizeof dir) return false;
  char *abs = realpath(dir, NULL);
  const char *d = abs != NULL ? abs : dir;
  const int m = snprintf(out, size, "%s%s%s", d, strcmp(d, "/") == 0 ? "" : "/", file);
  free(abs);
  return m >= 0 && m < (int)size;
}

void nav_io_forward_diag(void *user, const nav_diag *d) {
  nav_io_reader_forward(user, d);
}

/* Import trajectory.motion_def.file; false after a reported problem. */
static bool import_motion_def(nav_io_reader *r, const nav_io_node *root, nav_scene *scene) {
  nav_io_read_state *st = nav_io_reader_state(r);
  const nav_io_node *traj = nav_io_map_get(root, "trajectory", NULL);
  const nav_io_node *earth = nav_io_map_get(root, "earth", NULL);
  if (nav_io_map_get(traj, "motion_def", NULL) == NULL) {
    nav_io_reader_error_at_path(r, "trajectory.type",
                                "motion_def needs trajectory.motion_def: {file: PATH} (a gnss-ins-sim "
                                "motion-definition CSV, relative to this file)");
    return false;
  }
  if (st->md_file[0] == '\0') return false; /* missing or rejected: reported */
  bool ok = true;
  /* The file sets what these would set: giving both is ambiguous. */
  if (nav_io_map_get(earth, "origin", NULL) != NULL) {
    nav_io_reader_error_at_path(
        r, "earth.origin",
        "the motion-definition file (trajectory.motion_def.file) sets the origin; remove "
        "earth.origin");
    ok = false;
  }
  if (nav_io_map_get(traj, "initial_attitude", NULL) != NULL) {
    nav_io_reader_error_at_path(r, "trajectory.initial_attitude",
                                "the motion-definition file (trajectory.motion_def.file) sets the initial "
                                "attitude; remove trajectory.initial_attitude");
    ok = false;
  }
  if (nav_io_map_get(traj, "segments", NULL) != NULL) {
    nav_io_reader_error_at_path(
        r, "trajectory.segments",
        "the motion-definition file (trajectory.motion_def.file) is the segment script; "
        "remove trajectory.segments or use trajectory.type: segments");
    ok = false;
  }
  char path[3 * NAV_IO_PATH_MAX];
  if (!nav_io_resolve_path(path, sizeof path, st->file, st->file_is_path, st->md_file)) {
    nav_io_reader_error_at_path(r, "trajectory.motion_def.file",
                                "the path of the motion-definition file is too long");
    return false;
  }
  struct stat sb;
  const bool exists = stat(path, &sb) == 0;
  const int err = errno;
  if (!exists || !S_ISREG(sb.st_mode)) {
    char why[128];
    if (exists)
      snprintf(why, sizeof why, "not a regular file");
    else if (strerror_r(err, why, sizeof why) != 0)
      snprintf(why, sizeof why, "error %d", err);
    nav_io_reader_error_at_path(r, "trajectory.motion_def.file",
                                "cannot read the motion-definition file \"%s\": %s", path, why);
    return false;
  }
  if (!ok) return false;
  const bool explicit_duration = !st->duration_auto;
  const double duration_s = scene->trajectory.duration_s;
  const nav_status s = nav_motiondef_read_file(path, scene, nav_io_forward_diag, r);
  if (s != NAV_OK) {
    nav_io_reader_error_at_path(r, "trajectory.motion_def.file",
                                "the motion-definition file \"%s\" was not imported (%s; see its messages)",
                                path, nav_status_str(s));
    return false;
  }
  if (explicit_duration) scene->trajectory.duration_s = duration_s;
  scene->trajectory.segments.allow_unconverged = st->md_allow_unconverged;
  scene->trajectory.segments.fit_rate_ramps = st->md_fit_rate_ramps;
  return true;
}

/* Read and fit trajectory.recorded.file (type recorded); false after a reported problem. */
static bool load_recorded(nav_io_reader *r, const nav_io_node *root, nav_scene *scene) {
  nav_io_read_state *st = nav_io_reader_state(r);
  nav_traj_recorded *R = &scene->trajectory.recorded;
  const nav_io_node *traj = nav_io_map_get(root, "trajectory", NULL);
  const nav_io_node *earth = nav_io_map_get(root, "earth", NULL);
  if (nav_io_map_get(traj, "recorded", NULL) == NULL) {
    nav_io_reader_error_at_path(r, "trajectory.type",
                                "recorded needs trajectory.recorded: {file: PATH} (a recorded reference, "
                                "relative to this file)");
    return false;
  }
  if (R->file[0] == '\0') return false; /* missing or rejected: reported */
  bool ok = true;
  if ((R->window & NAV_RECORDED_HAS_START) && (R->window & NAV_RECORDED_HAS_END) && !(R->end_s > R->start_s)) {
    nav_io_reader_error_at_path(r, "trajectory.recorded.end_s", "must be later than start_s (got %.17g s, start_s %.17g s)",
                                R->end_s, R->start_s);
    ok = false;
  }
  if (nav_io_map_get(traj, "initial_attitude", NULL) != NULL) {
    nav_io_reader_error_at_path(r, "trajectory.initial_attitude",
                                "the recorded file (trajectory.recorded.file) sets the initial attitude; remove "
                                "trajectory.initial_attitude");
    ok = false;
  }
  char path[3 * NAV_IO_PATH_MAX];
  if (!nav_io_resolve_path(path, sizeof path, st->file, st->file_is_path, R->file) ||
      strlen(path) >= sizeof R->file) {
    nav_io_reader_error_at_path(r, "trajectory.recorded.file", "the path of the recorded file is too long");
    return false;
  }
  struct stat sb;
  const bool exists = stat(path, &sb) == 0;
  const int err = errno;
  if (!exists || !S_ISREG(sb.st_mode)) {
    char why[128];
    if (exists)
      snprintf(why, sizeof why, "not a regular file");
    else if (strerror_r(err, why, sizeof why) != 0)
      snprintf(why, sizeof why, "error %d", err);
    nav_io_reader_error_at_path(r, "trajectory.recorded.file", "cannot read the recorded file \"%s\": %s", path,
                                why);
    return false;
  }
  if (!ok) return false;
  /* The canonical name (no "dir/../"), which the scene keeps and the writer writes. */
  char *canonical = realpath(path, NULL);
  if (canonical != NULL && strlen(canonical) < sizeof path) snprintf(path, sizeof path, "%s", canonical);
  free(canonical);
  nav_track_sample *samples = NULL;
  size_t n = 0;
  const nav_status s = nav_track_read_file(path, R->format, R->window, R->start_s, R->end_s,
                                           "trajectory.recorded.file", &samples, &n, nav_io_forward_diag, r);
  if (s != NAV_OK) {
    nav_io_reader_error_at_path(r, "trajectory.recorded.file",
                                "the recorded file \"%s\" was not loaded (%s; see its messages)", path,
                                nav_status_str(s));
    return false;
  }
  char msg[sizeof(((nav_diag *)0)->message) - 64];
  const nav_status fs = nav_track_fit(R, samples, n, msg, sizeof msg);
  free(samples);
  if (fs != NAV_OK) {
    nav_io_reader_error_at_path(r, fs == NAV_ERR_OUT_OF_RANGE ? "trajectory.recorded.knot_rate_hz"
                                                             : "trajectory.recorded.file",
                                "cannot fit the recorded samples: %s",
                                fs == NAV_ERR_NO_MEMORY ? "out of memory" : msg);
    return false;
  }
  const size_t path_len = strlen(path);
  if (path_len >= sizeof R->file) {
    nav_io_reader_error_at_path(r, "trajectory.recorded.file", "the path of the recorded file is too long");
    return false;
  }
  memcpy(R->file, path, path_len + 1);
  if (nav_track_set_scene_start(R, scene, nav_io_map_get(earth, "origin", NULL) == NULL) != NAV_OK) return false;
  if (st->duration_auto) scene->trajectory.duration_s = R->span_s;
  return true;
}

void nav_io_traj_finish(nav_io_reader *r, const nav_io_node *root, nav_scene *scene) {
  nav_io_read_state *st = nav_io_reader_state(r);
  nav_scene_trajectory *T = &scene->trajectory;
  const nav_io_node *traj = nav_io_map_get(root, "trajectory", NULL);

  /* 1. Geodetic waypoints, now that the Earth and its origin are known. */
  if (st->ngeo > 0) {
    const nav_frame fr = nav_frame_from_scene(scene);
    for (size_t i = 0; i < st->ngeo; ++i) {
      const nav_geodetic p = {st->geo[i].llh[0], st->geo[i].llh[1], st->geo[i].llh[2]};
      if (st->geo[i].index >= 0 && st->geo[i].index < NAV_MAX_WAYPOINTS)
        T->waypoints.points[st->geo[i].index].r_ned_m = nav_frame_geodetic_to_local(&fr, p);
    }
  }

  /* 2. A motion-definition import. On failure the type falls back to parametric, so that
        validation does not add messages about an empty segment script (the scene is rejected). */
  bool imported_as_is = false;
  const bool imported = (int)T->type == NAV_IO_TRAJ_MOTION_DEF;
  if (imported) {
    const int before = nav_io_reader_count(r);
    if (import_motion_def(r, root, scene) && nav_io_reader_count(r) == before) {
      imported_as_is = T->segments.allow_unconverged && T->segments.fit_rate_ramps;
    } else {
      T->type = NAV_TRAJ_PARAMETRIC;
      return;
    }
  } else if (nav_io_map_get(traj, "motion_def", NULL) != NULL) {
    nav_io_reader_error_at_path(r, "trajectory.motion_def",
                                "is read only with trajectory.type: motion_def (type is %s)",
                                nav_traj_type_name(T->type));
  }

  /* 3. A recorded reference: read and fit the file. On failure the type falls back to
        parametric, so that validation does not add a message about the missing fit (the scene
        is rejected). */
  if (T->type == NAV_TRAJ_RECORDED) {
    if (!load_recorded(r, root, scene)) T->type = NAV_TRAJ_PARAMETRIC;
    return;
  }

  /* 4. Scripts: plan once for the feasibility check (naming the waypoint or segment) and for
        duration_s auto. An import with its own flags was planned by the import already. */
  const bool script = T->type == NAV_TRAJ_WAYPOINTS || T->type == NAV_TRAJ_SEGMENTS;
  if (!script) {
    if (st->duration_auto_given)
      nav_io_reader_error_at_path(
          r, "trajectory.duration_s",
          "auto is the length of a waypoint or segment script; trajectory.type %s needs a "
          "number of seconds",
          nav_traj_type_name(T->type));
    return;
  }
  if (imported_as_is || nav_io_reader_count(r) > 0) return;
  nav_traj_script_info info;
  int bad = -1;
  char msg[sizeof(((nav_diag *)0)->message)];
  const bool wp = T->type == NAV_TRAJ_WAYPOINTS;
  const nav_status ps = wp ? nav_traj_waypoints_plan_info(scene, &info, &bad, msg, sizeof msg)
                           : nav_traj_segments_plan_info(scene, &info, &bad, msg, sizeof msg);
  if (ps != NAV_OK && imported) {
    /* The segments are not in the scene file: the message names the file and the segment. */
    nav_io_reader_error_at_path(r, "trajectory.motion_def.file",
                                "with the allow_unconverged / fit_rate_ramps given: %s",
                                ps == NAV_ERR_NO_MEMORY ? "out of memory" : msg);
    return;
  }
  if (ps != NAV_OK) {
    char path[96];
    const char *text = ps == NAV_ERR_NO_MEMORY ? "out of memory" : msg;
    if (bad >= 0)
      snprintf(path, sizeof path, "trajectory.%s[%d]", wp ? "waypoints.points" : "segments.items", bad);
    else
      snprintf(path, sizeof path, "trajectory.%s", wp ? "waypoints" : "segments");
    /* The planner's own messages may start with their field path ("trajectory.segments.limits: ...");
       that path goes into the diagnostic's path, so it is not printed twice. */
    const size_t pl = strlen(path);
    const char *colon = strstr(text, ": ");
    if (colon != NULL && strncmp(text, path, pl) == 0 && (text[pl] == ':' || text[pl] == '.' || text[pl] == '[') &&
        memchr(text, ' ', (size_t)(colon - text)) == NULL && (size_t)(colon - text) < sizeof path) {
      snprintf(path, sizeof path, "%.*s", (int)(colon - text), text);
      text = colon + 2;
    }
    nav_io_reader_error_at_path(r, path, "%s", text);
    return;
  }
  if (st->duration_auto) T->duration_s = info.duration_s;
}
