/* Scene defaults and format-independent validation. */
#include <stdio.h>
#include <string.h>

#include "navcore/nav_array.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_track.h"

bool nav_scene_gnss_pvt_fixes(const nav_scene *sc) {
  return sc && sc->navigation.scheme == NAV_SCHEME_INS_GNSS && sc->gnss.enabled && sc->gnss.constellation.enabled &&
         sc->gnss.constellation.fixes == NAV_GNSS_FIXES_PVT;
}

nav_scene nav_scene_default(void) {
  nav_scene s;
  memset(&s, 0, sizeof s);
  s.format_version = NAV_SCENE_FORMAT_VERSION;
  snprintf(s.name, sizeof s.name, "%s", "unnamed");
  s.earth.model = NAV_EARTH_FLAT;
  s.earth.origin_lat_rad = 45.0 * NAV_DEG2RAD;
  s.earth.origin_lon_rad = 0.0;
  s.earth.origin_h_m = 0.0;
  s.earth.flat_gravity_mps2 = 9.80665; /* standard gravity g0 (numerics.md 0.4) */

  /* The T3.1 trajectory of numerics.md section 3.3. */
  s.trajectory.type = NAV_TRAJ_PARAMETRIC;
  s.trajectory.duration_s = 20.0;
  s.trajectory.initial_attitude.roll_rad = 0.0;
  s.trajectory.initial_attitude.pitch_rad = 0.0;
  s.trajectory.initial_attitude.yaw_rad = 0.0;
  nav_traj_parametric *p = &s.trajectory.parametric;
  p->r0_m = nav_vec3_make(0.0, 0.0, 0.0);
  p->v0_mps = nav_vec3_make(10.0, 0.0, 0.0);
  p->a_mps2 = nav_vec3_make(0.1, 0.05, 0.0);
  p->b_m = nav_vec3_make(1.0, 1.0, 0.5);
  p->c_hz = nav_vec3_make(0.1, 0.2, 0.3);
  p->d_rad = nav_vec3_make(0.0, 0.5, 1.0);
  p->wa_rps = nav_vec3_make(0.01, 0.02, 0.05);
  p->wb_rps = nav_vec3_make(0.3, 0.2, 0.1);
  p->wc_hz = nav_vec3_make(0.5, 0.7, 0.3);
  p->wd_rad = nav_vec3_make(0.0, 1.0, 2.0);
  p->attitude_mode = NAV_ATT_RATE_MAGNUS;
  p->magnus_substeps = 8;

  /* Test motions: the inputs of numerics.md T5.1, T5.2, T5.3, T5.5; a 1000 m loop at 100 m/s. */
  nav_traj_test_motion *tm = &s.trajectory.test_motion;
  tm->kind = NAV_TEST_MOTION_STATIONARY;
  tm->cone_half_angle_rad = 1.0 * NAV_DEG2RAD;
  tm->cone_rate_rps = NAV_TWO_PI * 10.0;
  tm->scull_angle_rad = 1.0 * NAV_DEG2RAD;
  tm->scull_accel_mps2 = 10.0;
  tm->scull_rate_rps = NAV_TWO_PI * 10.0;
  tm->spin_rate_rps = NAV_TWO_PI * 20.0;
  tm->spin_axis_b = nav_vec3_make(1.0, 2.0, 3.0);
  tm->gc_height_m = 1000.0;
  tm->gc_speed_mps = 250.0;
  tm->gc_start_angle_rad = 88.0 * NAV_DEG2RAD;
  tm->gc_lon_rad = 0.0;
  tm->loop_speed_mps = 100.0;
  tm->loop_pitch_rate_rps = 0.1;

  /* Waypoints and segment scripts (trajectory-models work). Waypoint limits suit a road vehicle;
   * segment limits are gnss-ins-sim's "high_mobility" (1 m/s^2, 0.5 rad/s^2, 2 rad/s) plus jerk
   * limits, which gnss-ins-sim does not have. */
  s.trajectory.waypoints.timing = NAV_WP_TIMING_SPEED;
  s.trajectory.waypoints.attitude_mode = NAV_WP_ATT_GROUND;
  s.trajectory.waypoints.limits = (nav_traj_limits){2.0, 2.0, 3.0, 0.5, 0.5, 2.0};
  s.trajectory.segments.limits = (nav_traj_limits){1.0, 2.0, 10.0, 2.0, 0.5, 2.0};
  for (int i = 0; i < NAV_MAX_SEGMENTS; ++i) s.trajectory.segments.items[i].gnss_visible = true;

  /* Recorded reference (nav_track.h): 4 knots per second follows a road vehicle's manoeuvres
   * (bandwidth ~2 Hz) and fits 300 s in the scene; 1 cm / 1 cm/s weigh position and velocity
   * alike for a reference solution of RTK quality. No samples until a file is loaded. */
  s.trajectory.recorded.format = NAV_RECORDED_KF_GINS_NAV;
  s.trajectory.recorded.knot_rate_hz = 4.0;
  s.trajectory.recorded.pos_sd_m = 0.01;
  s.trajectory.recorded.vel_sd_mps = 0.01;

  s.imu.rate_hz = 100.0;
  s.imu.quadrature_nodes = 6;
  s.navigation.algorithm = NAV_MECH_FIRST_ORDER;
  s.output.rate_hz = 10.0;
  s.simulation.seed = 1;
  s.simulation.runs = 1;
  s.simulation.threads = 0;
  s.imu.model = nav_imu_model_config_default();
  s.gnss.enabled = false;
  s.gnss.model = nav_gnss_model_config_default();
  s.gnss.constellation = nav_gnss_constellation_config_default();
  s.navigation.scheme = NAV_SCHEME_FREE_INS;
  s.navigation.aid_vertical = false;
  /* Gyro-free INS: the cube of numerics.md 1.6 (r = 0.1 m), ideal sensors, perfect initial rate. */
  s.array.layout = NAV_ARRAY_LAYOUT_CUBE6;
  s.array.radius_m = 0.1;
  s.array.custom_count = 0;
  s.array.accel = nav_array_error_config_default();
  s.array.initial_rate_sd_rps = nav_vec3_zero();
  return s;
}

/* Prefix the sensor validators' relative paths with their scene section. */
typedef struct prefixed {
  const char *prefix;
  nav_scene_issue_fn report;
  void *user;
  int count;
} prefixed;

static void report_prefixed(void *user, const char *path, const char *message) {
  prefixed *p = user;
  char full[256];
  snprintf(full, sizeof full, "%s%s", p->prefix, path);
  p->count++;
  if (p->report) p->report(p->user, full, message);
}

typedef struct checker {
  nav_scene_issue_fn report;
  void *user;
  int count;
} checker;

static void issue(checker *c, const char *path, const char *fmt, double v) {
  char msg[256];
  snprintf(msg, sizeof msg, fmt, v);
  c->count++;
  if (c->report) c->report(c->user, path, msg);
}

static void issue_text(checker *c, const char *path, const char *msg) {
  c->count++;
  if (c->report) c->report(c->user, path, msg);
}

static void check_finite(checker *c, const char *path, double v) {
  if (!isfinite(v)) issue(c, path, "must be a finite number (got %g)", v);
}

static void check_positive(checker *c, const char *path, double v, double max) {
  if (!isfinite(v)) issue(c, path, "must be a finite number (got %g)", v);
  else if (!(v > 0.0)) issue(c, path, "must be > 0 (got %g)", v);
  else if (v > max) issue(c, path, "must be <= %g", max);
}

static void check_vec(checker *c, const char *path, nav_vec3 v) {
  char p[128];
  for (int i = 0; i < 3; ++i) {
    snprintf(p, sizeof p, "%s[%d]", path, i);
    check_finite(c, p, nav_vec3_get(v, i));
  }
}

/* Test motions: only the fields of the selected kind are checked (as testmotion.c uses them). */
static void check_test_motion(checker *c, const nav_scene *s) {
  const nav_traj_test_motion *m = &s->trajectory.test_motion;
  switch (m->kind) {
  case NAV_TEST_MOTION_STATIONARY: break;
  case NAV_TEST_MOTION_CONING:
    if (!(m->cone_half_angle_rad > 0.0 && m->cone_half_angle_rad <= 0.5 * NAV_PI))
      issue(c, "trajectory.test_motion.cone_half_angle_rad", "must be in (0, 90] deg (got %g deg)",
            m->cone_half_angle_rad * NAV_RAD2DEG);
    check_finite(c, "trajectory.test_motion.cone_rate_rps", m->cone_rate_rps);
    break;
  case NAV_TEST_MOTION_SCULLING:
    if (!(fabs(m->scull_angle_rad) <= 0.5 * NAV_PI))
      issue(c, "trajectory.test_motion.scull_angle_rad", "must be within [-90, 90] deg (got %g deg)",
            m->scull_angle_rad * NAV_RAD2DEG);
    check_finite(c, "trajectory.test_motion.scull_accel_mps2", m->scull_accel_mps2);
    check_positive(c, "trajectory.test_motion.scull_rate_rps", m->scull_rate_rps, 1.0e6);
    break;
  case NAV_TEST_MOTION_SPIN:
    check_finite(c, "trajectory.test_motion.spin_rate_rps", m->spin_rate_rps);
    check_vec(c, "trajectory.test_motion.spin_axis_b", m->spin_axis_b);
    if (nav_vec3_isfinite(m->spin_axis_b) && !(nav_vec3_norm(m->spin_axis_b) > 0.0))
      issue(c, "trajectory.test_motion.spin_axis_b", "must be a non-zero vector (got norm %g)",
            nav_vec3_norm(m->spin_axis_b));
    break;
  case NAV_TEST_MOTION_POLAR_GREAT_CIRCLE:
    if (s->earth.model != NAV_EARTH_WGS84)
      issue(c, "trajectory.test_motion.kind", "polar_great_circle is defined in ECEF and needs earth.model wgs84 (got model %g)",
            (double)s->earth.model);
    if (!(m->gc_height_m > -0.5 * NAV_WGS84_B_M && m->gc_height_m < 1.0e8))
      issue(c, "trajectory.test_motion.gc_height_m", "must be within (-3.2e6, 1e8) m (got %g)", m->gc_height_m);
    check_finite(c, "trajectory.test_motion.gc_speed_mps", m->gc_speed_mps);
    check_finite(c, "trajectory.test_motion.gc_start_angle_rad", m->gc_start_angle_rad);
    check_finite(c, "trajectory.test_motion.gc_lon_rad", m->gc_lon_rad);
    break;
  case NAV_TEST_MOTION_VERTICAL_LOOP:
    check_finite(c, "trajectory.test_motion.loop_speed_mps", m->loop_speed_mps);
    if (!(isfinite(m->loop_pitch_rate_rps) && m->loop_pitch_rate_rps != 0.0))
      issue(c, "trajectory.test_motion.loop_pitch_rate_rps", "must be a finite non-zero rate (got %g rad/s)",
            m->loop_pitch_rate_rps);
    break;
  default:
    issue(c, "trajectory.test_motion.kind", "unknown test motion %g", (double)m->kind);
    break;
  }
}

/* Waypoints and segment scripts: simple field ranges only (feasibility is checked by the planner,
 * which names the waypoint or segment and the limit). */
static void check_limits(checker *c, const char *base, const nav_traj_limits *l) {
  char p[160];
  const double v[6] = {l->max_accel_mps2, l->max_jerk_mps3,      l->max_lateral_accel_mps2,
                       l->max_rate_rps,   l->max_ang_accel_rps2, l->max_ang_jerk_rps3};
  static const char *const names[6] = {"max_accel_mps2", "max_jerk_mps3",      "max_lateral_accel_mps2",
                                       "max_rate_rps",   "max_ang_accel_rps2", "max_ang_jerk_rps3"};
  for (int i = 0; i < 6; ++i) {
    snprintf(p, sizeof p, "%s.limits.%s", base, names[i]);
    if (!(v[i] > 0.0)) issue(c, p, "must be > 0 (got %g)", v[i]);
  }
}

static void check_waypoints(checker *c, const nav_traj_waypoints *w) {
  char p[160];
  if (w->count < 2 || w->count > NAV_MAX_WAYPOINTS) {
    issue(c, "trajectory.waypoints.points", "needs 2 to 1000 waypoints (got %g)", (double)w->count);
    return;
  }
  if (w->timing != NAV_WP_TIMING_SPEED && w->timing != NAV_WP_TIMING_TIME)
    issue(c, "trajectory.waypoints.timing", "unknown timing %g", (double)w->timing);
  if ((int)w->attitude_mode < 0 || (int)w->attitude_mode > (int)NAV_WP_ATT_EULER)
    issue(c, "trajectory.waypoints.attitude_mode", "unknown attitude mode %g", (double)w->attitude_mode);
  if (!(w->hold_start_s >= 0.0 && w->hold_start_s <= NAV_SCENE_MAX_DURATION_S))
    issue(c, "trajectory.waypoints.hold_start_s", "must be within [0, 1e7] s (got %g)", w->hold_start_s);
  if (!(w->hold_end_s >= 0.0 && w->hold_end_s <= NAV_SCENE_MAX_DURATION_S))
    issue(c, "trajectory.waypoints.hold_end_s", "must be within [0, 1e7] s (got %g)", w->hold_end_s);
  if (!(w->cruise_mps >= 0.0 && w->cruise_mps <= 1.0e5))
    issue(c, "trajectory.waypoints.cruise_mps", "must be within [0, 1e5] m/s (got %g)", w->cruise_mps);
  check_limits(c, "trajectory.waypoints", &w->limits);
  for (int i = 0; i < w->count; ++i) {
    const nav_waypoint *q = &w->points[i];
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].r_ned_m", i);
    check_vec(c, p, q->r_ned_m);
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].speed_mps", i);
    if (!(q->speed_mps >= 0.0 && q->speed_mps <= 1.0e5))
      issue(c, p, "must be within [0, 1e5] m/s (got %g)", q->speed_mps);
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].time_s", i);
    if (!(q->time_s >= 0.0 && q->time_s <= NAV_SCENE_MAX_DURATION_S))
      issue(c, p, "must be within [0, 1e7] s (got %g)", q->time_s);
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].hold_s", i);
    if (!(q->hold_s >= 0.0 && q->hold_s <= NAV_SCENE_MAX_DURATION_S))
      issue(c, p, "must be within [0, 1e7] s (got %g)", q->hold_s);
    else if (q->hold_s > 0.0 && (i == 0 || i == w->count - 1))
      issue(c, p,
            i == 0 ? "is for interior waypoints; use trajectory.waypoints.hold_start_s (got %g s)"
                   : "is for interior waypoints; use trajectory.waypoints.hold_end_s (got %g s)",
            q->hold_s);
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].attitude.roll_deg", i);
    check_finite(c, p, q->attitude.roll_rad);
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].attitude.pitch_deg", i);
    if (!(fabs(q->attitude.pitch_rad) <= 0.5 * NAV_PI))
      issue(c, p, "must be within [-90, 90] deg (got %g deg)", q->attitude.pitch_rad * NAV_RAD2DEG);
    snprintf(p, sizeof p, "trajectory.waypoints.points[%d].attitude.yaw_deg", i);
    check_finite(c, p, q->attitude.yaw_rad);
  }
}

static void check_segments(checker *c, const nav_traj_segments *s) {
  char p[160];
  if (s->count < 1 || s->count > NAV_MAX_SEGMENTS) {
    issue(c, "trajectory.segments.items", "needs 1 to 2000 segments (got %g)", (double)s->count);
    return;
  }
  check_vec(c, "trajectory.segments.r0_ned_m", s->r0_ned_m);
  check_vec(c, "trajectory.segments.v0_b_mps", s->v0_b_mps);
  check_limits(c, "trajectory.segments", &s->limits);
  for (int i = 0; i < s->count; ++i) {
    const nav_segment *g = &s->items[i];
    if ((int)g->kind < (int)NAV_SEG_HOLD || (int)g->kind > (int)NAV_SEG_MOTION_REL_ABS) {
      snprintf(p, sizeof p, "trajectory.segments.items[%d].kind", i);
      issue(c, p, "unknown segment kind %g", (double)g->kind);
      continue;
    }
    snprintf(p, sizeof p, "trajectory.segments.items[%d].duration_s", i);
    if (!(g->duration_s >= 0.0 && g->duration_s <= NAV_SCENE_MAX_DURATION_S))
      issue(c, p, "must be within [0, 1e7] s (got %g)", g->duration_s);
    const double v[] = {
        g->yaw_rad,   g->pitch_rad, g->roll_rad,  g->yaw_rate_rps,   g->pitch_rate_rps, g->roll_rate_rps,
        g->v_b_mps.x, g->v_b_mps.y, g->v_b_mps.z, g->accel_b_mps2.x, g->accel_b_mps2.y, g->accel_b_mps2.z,
        g->speed_mps, g->height_m,  g->turns,     g->length_m,       g->spacing_m};
    for (size_t k = 0; k < sizeof v / sizeof v[0]; ++k)
      if (!isfinite(v[k])) {
        snprintf(p, sizeof p, "trajectory.segments.items[%d]", i);
        issue(c, p, "every number must be finite (found %g)", v[k]);
        break;
      }
    if (g->kind == NAV_SEG_CIRCLE || g->kind == NAV_SEG_FIGURE_EIGHT || g->kind == NAV_SEG_HELIX) {
      snprintf(p, sizeof p, "trajectory.segments.items[%d].radius_m", i);
      if (!(g->radius_m > 0.0 && g->radius_m <= 1.0e7))
        issue(c, p, "must be within (0, 1e7] m (got %g)", g->radius_m);
    }
    if (g->kind == NAV_SEG_LAWNMOWER) {
      snprintf(p, sizeof p, "trajectory.segments.items[%d].legs", i);
      if (g->legs < 1 || g->legs > 100000)
        issue(c, p, "must be an integer in [1, 100000] (got %g)", (double)g->legs);
      snprintf(p, sizeof p, "trajectory.segments.items[%d].length_m", i);
      if (!(g->length_m >= 0.0)) issue(c, p, "must be >= 0 (got %g)", g->length_m);
    }
  }
}

/* The accelerometer array of the gyro-free scheme (checked whatever the scheme, like the IMU). */
static void check_array(checker *c, const nav_scene_array *a, nav_scene_issue_fn report, void *user) {
  char p[160];
  if ((int)a->layout < (int)NAV_ARRAY_LAYOUT_CUBE6 || (int)a->layout > (int)NAV_ARRAY_LAYOUT_CUSTOM)
    issue(c, "array.layout", "unknown array layout %g", (double)a->layout);
  check_positive(c, "array.radius_m", a->radius_m, 100.0);
  for (int i = 0; i < 3; ++i) {
    snprintf(p, sizeof p, "array.initial_rate_sd_rps[%d]", i);
    const double v = nav_vec3_get(a->initial_rate_sd_rps, i);
    if (!(isfinite(v) && v >= 0.0)) issue(c, p, "must be finite and >= 0 (got %g)", v);
  }
  {
    prefixed pa = {"array.accel.", report, user, 0};
    if (nav_array_error_config_validate(&a->accel, report_prefixed, &pa) != NAV_OK && pa.count == 0)
      issue_text(c, "array.accel", "invalid accelerometer error model");
    c->count += pa.count;
  }
  if (a->layout != NAV_ARRAY_LAYOUT_CUSTOM) return;
  if (a->custom_count < NAV_ARRAY_MIN_SENSORS || a->custom_count > NAV_ARRAY_MAX_SENSORS) {
    issue(c, "array.sensors", "a custom layout needs 6 to 16 sensors (got %g)", (double)a->custom_count);
    return;
  }
  const int before = c->count;
  for (int i = 0; i < a->custom_count; ++i) {
    snprintf(p, sizeof p, "array.sensors[%d].r_bs_b_m", i);
    check_vec(c, p, a->custom[i].r_bs_b_m);
    snprintf(p, sizeof p, "array.sensors[%d].n_s_b", i);
    check_vec(c, p, a->custom[i].n_s_b);
    const double nn = nav_vec3_norm(a->custom[i].n_s_b);
    if (nav_vec3_isfinite(a->custom[i].n_s_b) && !(nn > 0.0 && isfinite(nn)))
      issue(c, p, "the sensitive axis must be a non-zero vector (got norm %g)", nn);
  }
  if (c->count != before) return;
  /* The layout must determine f and omega_dot: H of full rank and well conditioned (E1.23). */
  nav_accel_array arr;
  nav_array_geometry geo;
  if (nav_array_layout_from_scene(a, &arr) != NAV_OK || nav_array_geometry_compute(&arr, &geo) != NAV_OK)
    issue_text(c, "array.sensors",
               "the sensors cannot determine specific force and angular acceleration: H (E1.23) is singular "
               "or its condition number exceeds 1e8 (e.g. parallel axes, or every axis along its lever arm)");
}

/* Recorded reference: the settings, and a fitted model (nav_track_fit) consistent with them. */
static void check_recorded(checker *c, const nav_scene *s) {
  const nav_traj_recorded *r = &s->trajectory.recorded;
  if (s->earth.model != NAV_EARTH_WGS84)
    issue_text(c, "trajectory.type", "recorded is a geodetic trajectory and needs earth.model: wgs84");
  if (r->format != NAV_RECORDED_KF_GINS_NAV) issue(c, "trajectory.recorded.format", "unknown format %g", (double)r->format);
  if (!(r->knot_rate_hz > 0.0 && r->knot_rate_hz <= 1000.0))
    issue(c, "trajectory.recorded.knot_rate_hz", "must be within (0, 1000] Hz (got %g)", r->knot_rate_hz);
  check_positive(c, "trajectory.recorded.pos_sd_m", r->pos_sd_m, 1.0e6);
  check_positive(c, "trajectory.recorded.vel_sd_mps", r->vel_sd_mps, 1.0e6);
  if ((r->window & NAV_RECORDED_HAS_START) && !isfinite(r->start_s))
    issue(c, "trajectory.recorded.start_s", "must be a finite number (got %g)", r->start_s);
  if ((r->window & NAV_RECORDED_HAS_END) && !isfinite(r->end_s))
    issue(c, "trajectory.recorded.end_s", "must be a finite number (got %g)", r->end_s);
  if ((r->window & NAV_RECORDED_HAS_START) && (r->window & NAV_RECORDED_HAS_END) && !(r->end_s > r->start_s))
    issue(c, "trajectory.recorded.end_s", "must be later than start_s (got %g s)", r->end_s);
  if (r->count < 6 || r->count > NAV_RECORDED_MAX_CTRL || r->ctrl_ned_m == NULL || r->ctrl_q == NULL) {
    issue(c, "trajectory.recorded.file", "no fitted samples (%g control points); load the file with navcore_io "
          "or fit samples with nav_track_fit", (double)r->count);
    return;
  }
  bool finite = isfinite(r->t0_s) && isfinite(r->span_s) && isfinite(r->ref_lat_rad) && isfinite(r->ref_lon_rad) &&
                isfinite(r->ref_h_m) && isfinite(r->knot_dt_s);
  for (int i = 0; i < r->count && finite; ++i)
    finite = nav_vec3_isfinite(r->ctrl_ned_m[i]) && isfinite(r->ctrl_q[i].w) && isfinite(r->ctrl_q[i].x) &&
             isfinite(r->ctrl_q[i].y) && isfinite(r->ctrl_q[i].z);
  if (!finite) {
    issue_text(c, "trajectory.recorded.file", "the fitted model is not finite");
    return;
  }
  if (!(r->span_s > 0.0) || !(r->knot_dt_s > 0.0) || (double)(r->count - 5) * r->knot_dt_s < r->span_s * (1.0 - 1e-12))
    issue(c, "trajectory.recorded.file", "the fitted model does not cover its span of %g s", r->span_s);
  if (!(fabs(r->ref_lat_rad) <= 89.0 * NAV_DEG2RAD))
    issue(c, "trajectory.recorded.file", "the recorded trajectory starts at latitude %g deg; it must stay within "
          "89 deg of the equator", r->ref_lat_rad * NAV_RAD2DEG);
  /* The model continues smoothly a little beyond the data, but it is not data there. */
  if (isfinite(s->trajectory.duration_s) && s->trajectory.duration_s > r->span_s * (1.0 + 1e-12) + 1e-9)
    issue(c, "trajectory.duration_s", "must not exceed the recorded span of %.9g s", r->span_s);
}

nav_status nav_scene_validate(const nav_scene *scene, nav_scene_issue_fn report, void *user) {
  checker c = {report, user, 0};
  if (!scene) return NAV_ERR_INVALID_ARG;
  const nav_scene *s = scene;
  if (s->format_version < 1 || s->format_version > NAV_SCENE_FORMAT_VERSION)
    issue(&c, "format_version", "unsupported format version %g (this navsim reads version 1)",
          (double)s->format_version);

  if (s->earth.model != NAV_EARTH_FLAT && s->earth.model != NAV_EARTH_WGS84)
    issue(&c, "earth.model", "unknown Earth model %g", (double)s->earth.model);
  if (!(fabs(s->earth.origin_lat_rad) <= 0.5 * NAV_PI))
    issue(&c, "earth.origin.lat_deg", "latitude must be within [-90, 90] deg (got %g deg)",
          s->earth.origin_lat_rad * NAV_RAD2DEG);
  check_finite(&c, "earth.origin.lon_deg", s->earth.origin_lon_rad);
  if (!(s->earth.origin_h_m >= -1.0e5 && s->earth.origin_h_m <= 1.0e8))
    issue(&c, "earth.origin.h_m", "height must be within [-1e5, 1e8] m (got %g)", s->earth.origin_h_m);
  if (s->earth.model == NAV_EARTH_FLAT) check_positive(&c, "earth.gravity_mps2", s->earth.flat_gravity_mps2, 1.0e3);
  if (s->earth.gravity_model != NAV_GRAVITY_NORMAL && s->earth.gravity_model != NAV_GRAVITY_J2)
    issue(&c, "earth.gravity_model", "unknown gravity model %g", (double)s->earth.gravity_model);

  check_positive(&c, "trajectory.duration_s", s->trajectory.duration_s, NAV_SCENE_MAX_DURATION_S);
  check_finite(&c, "trajectory.initial_attitude.roll_deg", s->trajectory.initial_attitude.roll_rad);
  check_finite(&c, "trajectory.initial_attitude.pitch_deg", s->trajectory.initial_attitude.pitch_rad);
  check_finite(&c, "trajectory.initial_attitude.yaw_deg", s->trajectory.initial_attitude.yaw_rad);
  if (s->trajectory.type == NAV_TRAJ_PARAMETRIC) {
    const nav_traj_parametric *p = &s->trajectory.parametric;
    check_vec(&c, "trajectory.parametric.R0_m", p->r0_m);
    check_vec(&c, "trajectory.parametric.V0_mps", p->v0_mps);
    check_vec(&c, "trajectory.parametric.A_mps2", p->a_mps2);
    check_vec(&c, "trajectory.parametric.B_m", p->b_m);
    check_vec(&c, "trajectory.parametric.C_hz", p->c_hz);
    check_vec(&c, "trajectory.parametric.D_rad", p->d_rad);
    check_vec(&c, "trajectory.parametric.rate.a_rps", p->wa_rps);
    check_vec(&c, "trajectory.parametric.rate.b_rps", p->wb_rps);
    check_vec(&c, "trajectory.parametric.rate.c_hz", p->wc_hz);
    check_vec(&c, "trajectory.parametric.rate.d_rad", p->wd_rad);
    if (p->magnus_substeps < 1 || p->magnus_substeps > 1024)
      issue(&c, "trajectory.parametric.magnus_substeps", "must be an integer in [1, 1024] (got %g)",
            (double)p->magnus_substeps);
  } else if (s->trajectory.type == NAV_TRAJ_TEST_MOTION) {
    check_test_motion(&c, s);
  } else if (s->trajectory.type == NAV_TRAJ_WAYPOINTS) {
    check_waypoints(&c, &s->trajectory.waypoints);
  } else if (s->trajectory.type == NAV_TRAJ_SEGMENTS) {
    check_segments(&c, &s->trajectory.segments);
  } else if (s->trajectory.type == NAV_TRAJ_RECORDED) {
    check_recorded(&c, s);
  } else {
    issue(&c, "trajectory.type", "unknown trajectory type %g", (double)s->trajectory.type);
  }

  check_positive(&c, "imu.rate_hz", s->imu.rate_hz, NAV_SCENE_MAX_RATE_HZ);
  if (s->imu.quadrature_nodes < 1 || s->imu.quadrature_nodes > 16)
    issue(&c, "imu.quadrature_nodes", "must be an integer in [1, 16] (got %g)", (double)s->imu.quadrature_nodes);
  if (isfinite(s->imu.rate_hz) && isfinite(s->trajectory.duration_s) && s->imu.rate_hz > 0.0 &&
      s->trajectory.duration_s * s->imu.rate_hz > (double)NAV_SCENE_MAX_SAMPLES)
    issue(&c, "imu.rate_hz", "duration x rate exceeds the limit of %.0f IMU samples per run",
          (double)NAV_SCENE_MAX_SAMPLES);
  if (isfinite(s->imu.rate_hz) && isfinite(s->trajectory.duration_s) && s->imu.rate_hz > 0.0 &&
      s->trajectory.duration_s * s->imu.rate_hz < 1.0)
    issue(&c, "trajectory.duration_s", "is shorter than one IMU interval (%g samples)",
          s->trajectory.duration_s * s->imu.rate_hz);

  if (s->navigation.algorithm != NAV_MECH_FIRST_ORDER && s->navigation.algorithm != NAV_MECH_HIGH_ORDER)
    issue(&c, "navigation.algorithm", "unknown algorithm %g", (double)s->navigation.algorithm);
  if (s->navigation.frame != NAV_MECH_NED && s->navigation.frame != NAV_MECH_ECEF)
    issue(&c, "navigation.frame", "unknown mechanization frame %g", (double)s->navigation.frame);

  check_positive(&c, "output.rate_hz", s->output.rate_hz, NAV_SCENE_MAX_RATE_HZ);
  if (isfinite(s->output.rate_hz) && isfinite(s->imu.rate_hz) && s->output.rate_hz > s->imu.rate_hz)
    issue(&c, "output.rate_hz", "must not exceed imu.rate_hz (%g Hz)", s->imu.rate_hz);

  {
    prefixed pi = {"imu.", report, user, 0};
    if (nav_imu_model_config_validate(&s->imu.model, report_prefixed, &pi) != NAV_OK && pi.count == 0)
      issue_text(&c, "imu", "invalid IMU error model");
    c.count += pi.count;
    if (s->gnss.enabled) {
      prefixed pg = {"gnss.", report, user, 0};
      if (nav_gnss_model_config_validate(&s->gnss.model, report_prefixed, &pg) != NAV_OK && pg.count == 0)
        issue_text(&c, "gnss", "invalid GNSS receiver model");
      c.count += pg.count;
    }
    if (s->gnss.constellation.enabled) {
      prefixed pc = {"gnss.constellation.", report, user, 0};
      if (nav_gnss_constellation_config_validate(&s->gnss.constellation, report_prefixed, &pc) != NAV_OK &&
          pc.count == 0)
        issue_text(&c, "gnss.constellation", "invalid GNSS constellation");
      c.count += pc.count;
    }
  }
  check_vec(&c, "initial_errors.position_m", s->initial_errors.pos_sd_m);
  check_vec(&c, "initial_errors.velocity_mps", s->initial_errors.vel_sd_mps);
  check_vec(&c, "initial_errors.attitude_deg", s->initial_errors.att_sd_rad);
  if (s->navigation.scheme != NAV_SCHEME_FREE_INS && s->navigation.scheme != NAV_SCHEME_INS_GNSS &&
      s->navigation.scheme != NAV_SCHEME_GYRO_FREE && s->navigation.scheme != NAV_SCHEME_GYRO_FREE_GNSS &&
      s->navigation.scheme != NAV_SCHEME_INS_GNSS_TIGHT)
    issue(&c, "navigation.scheme", "unknown navigation scheme %g", (double)s->navigation.scheme);
  if (s->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
    /* The receiver section gives the epochs (update_rate_hz), the outages and the lever arm; the
     * constellation section the satellites and the raw-measurement errors. */
    if (!s->gnss.enabled)
      issue_text(&c, "navigation.scheme", "ins_gnss_tight needs a GNSS receiver: set gnss.enabled: true");
    if (!s->gnss.constellation.enabled)
      issue_text(&c, "navigation.scheme",
                 "ins_gnss_tight needs satellites: add a gnss.constellation section (docs/ins-gnss-tight.md)");
    if (s->earth.model != NAV_EARTH_WGS84)
      issue_text(&c, "navigation.scheme", "ins_gnss_tight needs the wgs84 Earth model");
    if (s->navigation.aid_vertical)
      issue_text(&c, "navigation.aid_vertical", "applies to the free INS only; ins_gnss_tight is aided by GNSS");
  }
  if (s->navigation.scheme == NAV_SCHEME_GYRO_FREE && s->navigation.aid_vertical)
    issue_text(&c, "navigation.aid_vertical", "applies to the free INS only, not to gyro_free");
  check_array(&c, &s->array, report, user);
  if (s->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS) {
    if (!s->gnss.enabled)
      issue_text(&c, "navigation.scheme", "gyro_free_gnss needs a GNSS receiver: set gnss.enabled: true");
    if (s->earth.model != NAV_EARTH_WGS84)
      issue_text(&c, "navigation.scheme", "gyro_free_gnss needs the wgs84 Earth model");
    if (s->navigation.aid_vertical)
      issue_text(&c, "navigation.aid_vertical", "applies to the free INS only; gyro_free_gnss is aided by GNSS");
    /* The filter has no scale-factor states (docs/gyro-free-gnss.md section 6): an unmodelled
     * error would make it overconfident, so refuse it rather than report inconsistent sigmas. */
    if (s->array.accel.terms & NAV_IMU_TERM_SCALE_FACTOR)
      issue_text(&c, "array.accel", "gyro_free_gnss does not estimate accelerometer scale factors: turn the "
                                    "scale-factor term off");
  }
  if (s->navigation.scheme == NAV_SCHEME_INS_GNSS && !s->gnss.enabled)
    issue_text(&c, "navigation.scheme", "ins_gnss needs a GNSS receiver: set gnss.enabled: true");
  if (s->gnss.file[0] != '\0' && s->navigation.scheme != NAV_SCHEME_INS_GNSS &&
      s->navigation.scheme != NAV_SCHEME_GYRO_FREE_GNSS)
    issue_text(&c, "gnss.file", "recorded GNSS fixes aid the ins_gnss and gyro_free_gnss schemes only: set "
                                "navigation.scheme, or remove gnss.file");
  if (memchr(s->gnss.file, '\0', sizeof s->gnss.file) == NULL)
    issue_text(&c, "gnss.file", "the path is not NUL-terminated");
  if (s->navigation.scheme == NAV_SCHEME_INS_GNSS && s->earth.model != NAV_EARTH_WGS84)
    issue_text(&c, "navigation.scheme", "ins_gnss needs the wgs84 Earth model");
  if (s->navigation.scheme == NAV_SCHEME_INS_GNSS && s->navigation.aid_vertical)
    issue_text(&c, "navigation.aid_vertical", "applies to the free INS only; ins_gnss is aided by GNSS");
  if (s->navigation.smoother && s->navigation.scheme != NAV_SCHEME_INS_GNSS)
    issue_text(&c, "navigation.smoother", "applies to the ins_gnss scheme only (the RTS smoother needs the filter)");
  if (s->simulation.threads < 0 || s->simulation.threads > 256)
    issue(&c, "simulation.threads", "must be an integer in [0, 256] (got %g)", (double)s->simulation.threads);
  if (s->simulation.runs < 1 || s->simulation.runs > NAV_SCENE_MAX_RUNS)
    issue(&c, "simulation.runs", "must be an integer in [1, 1000000] (got %g)", (double)s->simulation.runs);
  {
    /* requirements (nav_requirements.h) */
    prefixed pr = {"", report, user, 0};
    if (nav_requirements_validate(s->requirements, s->n_requirements, report_prefixed, &pr) != NAV_OK &&
        pr.count == 0)
      issue_text(&c, "requirements", "invalid requirements");
    c.count += pr.count;
  }
  return c.count ? NAV_ERR_INVALID_ARG : NAV_OK;
}

const char *nav_earth_model_name(nav_earth_model m) {
  switch (m) {
  case NAV_EARTH_FLAT: return "flat";
  case NAV_EARTH_WGS84: return "wgs84";
  }
  return "unknown";
}

const char *nav_mech_algorithm_name(nav_mech_algorithm a) {
  switch (a) {
  case NAV_MECH_FIRST_ORDER: return "first_order";
  case NAV_MECH_HIGH_ORDER: return "high_order";
  }
  return "unknown";
}

const char *nav_gravity_model_name(nav_gravity_model g) {
  switch (g) {
  case NAV_GRAVITY_NORMAL: return "normal";
  case NAV_GRAVITY_J2: return "j2";
  }
  return "unknown";
}

const char *nav_nav_scheme_name(nav_nav_scheme s) {
  switch (s) {
  case NAV_SCHEME_FREE_INS: return "free_ins";
  case NAV_SCHEME_INS_GNSS: return "ins_gnss";
  case NAV_SCHEME_GYRO_FREE: return "gyro_free";
  case NAV_SCHEME_GYRO_FREE_GNSS: return "gyro_free_gnss";
  case NAV_SCHEME_INS_GNSS_TIGHT: return "ins_gnss_tight";
  }
  return "unknown";
}

const char *nav_array_layout_kind_name(nav_array_layout_kind k) {
  switch (k) {
  case NAV_ARRAY_LAYOUT_CUBE6: return "cube6";
  case NAV_ARRAY_LAYOUT_NINE: return "nine";
  case NAV_ARRAY_LAYOUT_TWELVE: return "twelve";
  case NAV_ARRAY_LAYOUT_CUSTOM: return "custom";
  }
  return "unknown";
}

const char *nav_mech_frame_name(nav_mech_frame f) {
  switch (f) {
  case NAV_MECH_NED: return "ned";
  case NAV_MECH_ECEF: return "ecef";
  }
  return "unknown";
}

const char *nav_traj_type_name(nav_traj_type t) {
  switch (t) {
  case NAV_TRAJ_PARAMETRIC: return "parametric";
  case NAV_TRAJ_WAYPOINTS: return "waypoints";
  case NAV_TRAJ_SEGMENTS: return "segments";
  case NAV_TRAJ_TEST_MOTION: return "test_motion";
  case NAV_TRAJ_RECORDED: return "recorded";
  }
  return "unknown";
}

/* ------------------------------------------------------------------ ownership (nav_scene.h) */

void nav_scene_release(nav_scene *scene) {
  if (scene) nav_traj_recorded_release(&scene->trajectory.recorded);
}

nav_status nav_scene_copy(nav_scene *dst, const nav_scene *src) {
  if (!dst || !src) return NAV_ERR_INVALID_ARG;
  if (dst == src) return NAV_OK;
  *dst = *src;
  return nav_traj_recorded_copy(&dst->trajectory.recorded, &src->trajectory.recorded);
}
