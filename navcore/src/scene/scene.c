/* Scene defaults and format-independent validation. */
#include <stdio.h>
#include <string.h>

#include "navcore/nav_scene.h"

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

  s.imu.rate_hz = 100.0;
  s.imu.quadrature_nodes = 6;
  s.navigation.algorithm = NAV_MECH_FIRST_ORDER;
  s.output.rate_hz = 10.0;
  s.simulation.seed = 1;
  s.simulation.runs = 1;
  return s;
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
  } else if (s->trajectory.type != NAV_TRAJ_WAYPOINTS && s->trajectory.type != NAV_TRAJ_SEGMENTS &&
             s->trajectory.type != NAV_TRAJ_TEST_MOTION) {
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

  if (s->simulation.runs < 1 || s->simulation.runs > NAV_SCENE_MAX_RUNS)
    issue(&c, "simulation.runs", "must be an integer in [1, 1000000] (got %g)", (double)s->simulation.runs);
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
  }
  return "unknown";
}
