/*
 * Recorded reference trajectories (nav_track.h, recorded.c, track_io.c, trajectory.type recorded):
 *   - analytic derivatives of the model (lat/lon/h rates and accelerations, omega_nb_b and its
 *     derivative) against central differences, at knots and between them;
 *   - continuity of position, velocity, acceleration, jerk, attitude, rate and angular
 *     acceleration across every knot (the splines are C4);
 *   - exactness: a quadratic geodetic path with constant attitude is reproduced to round-off; a
 *     smooth synthetic drive across the antimeridian with the heading through +-180 deg to the
 *     stated bounds;
 *   - fit residuals on the vendored KF-GINS slice (tests/data/recorded) below stated bounds;
 *   - closure: exact ideal IMU + high-order WGS-84 mechanization (NED and ECEF) along the
 *     recorded path for 300 s;
 *   - diagnostics: malformed files (FILE:LINE:COL), settings the fit cannot honour, scene-level
 *     errors, and the write/read round trip of a recorded scene (bit-identical model).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_ins.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_io.h"
#include "navcore/nav_track.h"
#include "navcore/nav_track_io.h"
#include "navcore/nav_truth.h"
#include "traj/traj_internal.h"

#define SLICE NAV_TEST_DATA_DIR "/recorded/adis16465-truth-116454-116754.nav"
#define SCENE NAV_SOURCE_DIR "/scenes/recorded-adis16465.yaml"
#define D2R NAV_DEG2RAD

/* ------------------------------------------------------------------ helpers */

typedef struct diag_log {
  int n;
  nav_diag d[8];
} diag_log;

static void collect(void *user, const nav_diag *d) {
  diag_log *log = user;
  if (log->n < 8) log->d[log->n] = *d;
  log->n++;
}

static void print_log(const diag_log *log) {
  for (int i = 0; i < log->n && i < 8; ++i) {
    char line[1400];
    nav_diag_format(&log->d[i], line, sizeof line);
    print_message("%s\n", line);
  }
}

static nav_scene *new_scene(void) {
  nav_scene *s = malloc(sizeof *s);
  assert_non_null(s);
  *s = nav_scene_default();
  s->earth.model = NAV_EARTH_WGS84;
  s->trajectory.type = NAV_TRAJ_RECORDED;
  return s;
}

/* The vendored slice fitted with the scene defaults (4 Hz knots, 1 cm, 1 cm/s). */
static nav_scene *slice_scene(nav_track_sample **samples, size_t *n) {
  diag_log log = {0};
  assert_int_equal(
      nav_track_read_file(SLICE, NAV_RECORDED_KF_GINS_NAV, 0, 0.0, 0.0, "f", samples, n, collect, &log),
      NAV_OK);
  nav_scene *s = new_scene();
  char msg[256];
  if (nav_track_fit(&s->trajectory.recorded, *samples, *n, msg, sizeof msg) != NAV_OK)
    fail_msg("fit: %s", msg);
  s->trajectory.duration_s = s->trajectory.recorded.span_s;
  assert_int_equal(nav_track_set_scene_start(&s->trajectory.recorded, s, true), NAV_OK);
  return s;
}

static void create_model(const nav_scene *s, nav_traj_model *m) {
  char msg[256];
  if (nav_traj_recorded_create(s, 0.005, m, msg, sizeof msg) != NAV_OK) fail_msg("model: %s", msg);
  assert_non_null(m->eval_geodetic);
}

static nav_geo_kin geo(const nav_traj_model *m, double t) {
  nav_geo_kin g;
  assert_int_equal(m->eval_geodetic(m->self, t, &g), NAV_OK);
  return g;
}

/* Body rate from the attitude by central differences: C^T C' = [w x] <=> w = 2 vec(conj(q) q'). */
static nav_vec3 rate_fd(const nav_traj_model *m, double t, double h) {
  const nav_quat q = geo(m, t).q_b_n;
  nav_quat qp = geo(m, t + h).q_b_n, qm = geo(m, t - h).q_b_n;
  if (qp.w * q.w + qp.x * q.x + qp.y * q.y + qp.z * q.z < 0.0) qp = (nav_quat){-qp.w, -qp.x, -qp.y, -qp.z};
  if (qm.w * q.w + qm.x * q.x + qm.y * q.y + qm.z * q.z < 0.0) qm = (nav_quat){-qm.w, -qm.x, -qm.y, -qm.z};
  const nav_quat dq = {(qp.w - qm.w) / (2 * h), (qp.x - qm.x) / (2 * h), (qp.y - qm.y) / (2 * h),
                       (qp.z - qm.z) / (2 * h)};
  const nav_quat a = nav_quat_mul(nav_quat_conj(q), dq);
  return nav_vec3_make(2 * a.x, 2 * a.y, 2 * a.z);
}

static nav_vec3 vsub(nav_vec3 a, nav_vec3 b) {
  return nav_vec3_sub(a, b);
}
static nav_vec3 vfd(nav_vec3 p, nav_vec3 m, double h) {
  return nav_vec3_scale(nav_vec3_sub(p, m), 0.5 / h);
}

/* Curvilinear metres per radian at a latitude/height, to express geodetic rates in m/s. */
static nav_vec3 metric(const nav_geo_kin *g, nav_vec3 d) {
  const double lat = g->pos.lat_rad, h = g->pos.h_m;
  return nav_vec3_make(d.x * (nav_earth_radius_meridian_m(lat) + h),
                       d.y * (nav_earth_radius_prime_vertical_m(lat) + h) * cos(lat), d.z);
}

/* ------------------------------------------------------------------ derivatives */

/*
 * Analytic derivatives against central differences on the real-data fit, at knots, just
 * either side of them and between them. Each quantity is differenced with steps h and h/2
 * (h = 2 ms) and Richardson-extrapolated, (4 D(h/2) - D(h)) / 3, which cancels the h^2
 * truncation term, so what is left is O(h^4) plus round-off:
 *   velocity (from lat/lon/h): round-off eps x 6.4e6 m / 2 ms x 5/3 = 1e-6 m/s dominates;
 *   acceleration (from the analytic velocity), rate (from the quaternion) and angular
 *   acceleration (from the analytic rate): round-off ~1e-13 and the h^4 terms, which vanish
 *   inside a knot interval (quintic pieces) but not for stencils straddling a knot, where the
 *   fifth derivative of the C4 spline jumps: error ~ jump x h^3 ~ 1e-8.
 * The plain central differences (h = 1 ms) are also bounded, by h^2 / 6 times the next
 * derivative as measured on this fit (snap and w''' <~ 100 per s^4).
 */
typedef struct fd4 {
  nav_vec3 v, a, w, dw; /* central differences with one step */
} fd4;

static fd4 central(const nav_traj_model *m, double t, double h) {
  const nav_geo_kin g = geo(m, t), gp = geo(m, t + h), gm = geo(m, t - h);
  const nav_vec3 pp =
      nav_vec3_make(gp.pos.lat_rad - g.pos.lat_rad, gp.pos.lon_rad - g.pos.lon_rad, gp.pos.h_m - g.pos.h_m);
  const nav_vec3 pm =
      nav_vec3_make(gm.pos.lat_rad - g.pos.lat_rad, gm.pos.lon_rad - g.pos.lon_rad, gm.pos.h_m - g.pos.h_m);
  fd4 f;
  f.v = metric(&g, vfd(pp, pm, h));
  f.a = metric(&g, vfd(gp.dpos, gm.dpos, h));
  f.w = rate_fd(m, t, h);
  f.dw = vfd(gp.w_nb_b_rps, gm.w_nb_b_rps, h);
  return f;
}

static nav_vec3 richardson(nav_vec3 coarse, nav_vec3 fine) {
  return nav_vec3_scale(nav_vec3_sub(nav_vec3_scale(fine, 4.0), coarse), 1.0 / 3.0);
}

static void test_derivatives(void **state) {
  (void)state;
  nav_track_sample *samples = NULL;
  size_t n = 0;
  nav_scene *s = slice_scene(&samples, &n);
  nav_traj_model m;
  create_model(s, &m);
  const double dt = s->trajectory.recorded.knot_dt_s, h = 2e-3;
  double worst[4] = {0, 0, 0, 0}, plain[4] = {0, 0, 0, 0};
  int checked = 0;
  for (int k = 1; k < s->trajectory.recorded.count - 6; k += 7) {
    const double tk = k * dt;
    const double ts[5] = {tk, tk - 3e-3, tk + 3e-3, tk + 0.37 * dt, tk + 0.81 * dt};
    for (int i = 0; i < 5; ++i) {
      const double t = ts[i];
      const nav_geo_kin g = geo(&m, t);
      const fd4 c = central(&m, t, h), f = central(&m, t, h / 2);
      const nav_vec3 exact[4] = {metric(&g, g.dpos), metric(&g, g.ddpos), g.w_nb_b_rps, g.dw_nb_b_rps2};
      const nav_vec3 rc[4] = {richardson(c.v, f.v), richardson(c.a, f.a), richardson(c.w, f.w),
                              richardson(c.dw, f.dw)};
      const nav_vec3 pc[4] = {f.v, f.a, f.w, f.dw};
      for (int q = 0; q < 4; ++q) {
        worst[q] = fmax(worst[q], nav_vec3_norm(vsub(rc[q], exact[q])));
        plain[q] = fmax(plain[q], nav_vec3_norm(vsub(pc[q], exact[q])));
      }
      ++checked;
    }
  }
  print_message(
      "derivatives vs central differences at %d times, Richardson (h = 2, 1 ms): v %.2e m/s, a %.2e "
      "m/s^2, w %.2e rad/s, dw %.2e rad/s^2; plain (h = 1 ms): %.2e, %.2e, %.2e, %.2e\n",
      checked, worst[0], worst[1], worst[2], worst[3], plain[0], plain[1], plain[2], plain[3]);
  assert_true(checked > 800);
  assert_near(worst[0], 0.0, 2e-6);
  assert_near(worst[1], 0.0, 1e-7);
  assert_near(worst[2], 0.0, 1e-9);
  assert_near(worst[3], 0.0, 1e-7);
  assert_near(plain[0], 0.0, 3e-6);
  assert_near(plain[1], 0.0, 2e-5);
  assert_near(plain[2], 0.0, 2e-5);
  assert_near(plain[3], 0.0, 2e-5);
  /* The ECEF state of nav_traj agrees with the geodetic kinematics: v_e = d r_e / dt. */
  nav_traj *tr = NULL;
  char msg[256];
  if (nav_traj_create_msg(s, 0.005, &tr, msg, sizeof msg) != NAV_OK) fail_msg("%s", msg);
  double worst_e = 0.0;
  for (double t = 0.5; t < s->trajectory.recorded.span_s; t += 3.7) {
    nav_traj_state a, b, c;
    assert_int_equal(nav_traj_eval(tr, t, &a), NAV_OK);
    assert_int_equal(nav_traj_eval(tr, t + h, &b), NAV_OK);
    assert_int_equal(nav_traj_eval(tr, t - h, &c), NAV_OK);
    worst_e =
        fmax(worst_e, nav_vec3_norm(vsub(vfd(vsub(b.r_fb_f_m, a.r_fb_f_m), vsub(c.r_fb_f_m, a.r_fb_f_m), h),
                                         a.v_fb_f_mps)));
  }
  print_message("ECEF: |d r_e / dt - v_e| <= %.2e m/s\n", worst_e);
  /* h = 2 ms: a few ulps of 6.4e6 m (~3e-9 m) in the geodetic -> ECEF conversion / 4 ms ~ 1e-6 m/s,
   * plus the truncation h^2 / 6 x jerk (<~ 2 m/s^3) ~ 1.3e-6 m/s. */
  assert_near(worst_e, 0.0, 5e-6);
  nav_traj_destroy(tr);
  m.destroy(m.self);
  free(samples);
  nav_scene_release(s);
  free(s);
}

/* ------------------------------------------------------------------ continuity */

/*
 * Across every knot t_k, values just before (t_k - d) and just after (t_k + d) differ by the
 * derivative times 2d only, d = 1e-7 s; the jerk (one-sided differences of the acceleration over
 * 1e-4 s on each side) and the derivative of the angular acceleration likewise agree. A jump of
 * the jerk at a knot (a C2 spline) would show as |j+ - j-| ~ the snap x knot spacing, 1e-2..1 m/s^3.
 */
static void test_continuity(void **state) {
  (void)state;
  nav_track_sample *samples = NULL;
  size_t n = 0;
  nav_scene *s = slice_scene(&samples, &n);
  nav_traj_model m;
  create_model(s, &m);
  const nav_traj_recorded *r = &s->trajectory.recorded;
  const double d = 1e-7, e = 1e-4;
  double jump[6] = {0, 0, 0, 0, 0, 0};
  for (int k = 1; k < r->count - 5; ++k) {
    const double tk = k * r->knot_dt_s;
    const nav_geo_kin a = geo(&m, tk - d), b = geo(&m, tk + d);
    const nav_vec3 dp = metric(&a, nav_vec3_make(b.pos.lat_rad - a.pos.lat_rad, b.pos.lon_rad - a.pos.lon_rad,
                                                 b.pos.h_m - a.pos.h_m));
    jump[0] = fmax(jump[0], nav_vec3_norm(dp));
    jump[1] = fmax(jump[1], nav_vec3_norm(metric(&a, vsub(b.dpos, a.dpos))));
    jump[2] = fmax(jump[2], nav_vec3_norm(metric(&a, vsub(b.ddpos, a.ddpos))));
    jump[3] = fmax(jump[3], nav_quat_angle_between(a.q_b_n, b.q_b_n));
    jump[3] = fmax(jump[3], nav_vec3_norm(vsub(b.w_nb_b_rps, a.w_nb_b_rps)));
    jump[4] = fmax(jump[4], nav_vec3_norm(vsub(b.dw_nb_b_rps2, a.dw_nb_b_rps2)));
    /* Jerk and d(dw)/dt from each side. */
    const nav_geo_kin am = geo(&m, tk - e), bp = geo(&m, tk + e), c = geo(&m, tk);
    const nav_vec3 j_left = nav_vec3_scale(metric(&c, vsub(c.ddpos, am.ddpos)), 1.0 / e);
    const nav_vec3 j_right = nav_vec3_scale(metric(&c, vsub(bp.ddpos, c.ddpos)), 1.0 / e);
    const nav_vec3 w3_left = nav_vec3_scale(vsub(c.dw_nb_b_rps2, am.dw_nb_b_rps2), 1.0 / e);
    const nav_vec3 w3_right = nav_vec3_scale(vsub(bp.dw_nb_b_rps2, c.dw_nb_b_rps2), 1.0 / e);
    jump[5] = fmax(jump[5], nav_vec3_norm(vsub(j_right, j_left)) + nav_vec3_norm(vsub(w3_right, w3_left)));
  }
  print_message(
      "largest change across a knot (+-0.1 us): position %.2e m, velocity %.2e m/s, acceleration %.2e "
      "m/s^2, attitude/rate %.2e, angular acceleration %.2e rad/s^2; jerk + d(dw)/dt one-sided "
      "difference %.2e\n",
      jump[0], jump[1], jump[2], jump[3], jump[4], jump[5]);
  /* Bounds: speed <= 2 m/s, |a| <= 2 m/s^2, jerk <= 20 m/s^3, w <= 1 rad/s ... times 2d = 2e-7 s,
   * plus round-off of the geodetic differences (lat ulp x 6.4e6 m = 7e-10 m). */
  assert_near(jump[0], 0.0, 1e-6);
  assert_near(jump[1], 0.0, 1e-6);
  assert_near(jump[2], 0.0, 1e-5);
  assert_near(jump[3], 0.0, 1e-6);
  assert_near(jump[4], 0.0, 1e-4);
  /* One-sided differences over 1e-4 s differ by snap x 1e-4 s (snap <~ 100 m/s^4 here). */
  assert_near(jump[5], 0.0, 2e-2);
  m.destroy(m.self);
  free(samples);
  nav_scene_release(s);
  free(s);
}

/* ------------------------------------------------------------------ exactness */

/* Synthetic path in the model's own curvilinear coordinates from (lat0, lon0, h0), sampled. */
typedef struct synth {
  double lat0, lon0, h0;
  double radius_m, rate_rps; /* circle N = R sin(W t), E = R (1 - cos(W t)) */
  nav_vec3 quad_a;           /* + a t^2 per axis (N, E, D) */
  nav_vec3 lin_v;            /* + v t per axis */
  bool attitude_varies;      /* heading along the track + roll/pitch sines; else fixed */
  double yaw0_rad;           /* heading offset */
} synth;

static nav_track_sample synth_at(const synth *p, double t) {
  const double m_lat = nav_earth_radius_meridian_m(p->lat0) + p->h0;
  const double m_lon = (nav_earth_radius_prime_vertical_m(p->lat0) + p->h0) * cos(p->lat0);
  const double W = p->rate_rps, R = p->radius_m;
  const nav_vec3 r = nav_vec3_make(R * sin(W * t) + p->quad_a.x * t * t + p->lin_v.x * t,
                                   R * (1.0 - cos(W * t)) + p->quad_a.y * t * t + p->lin_v.y * t,
                                   p->quad_a.z * t * t + p->lin_v.z * t);
  const nav_vec3 v =
      nav_vec3_make(R * W * cos(W * t) + 2 * p->quad_a.x * t + p->lin_v.x,
                    R * W * sin(W * t) + 2 * p->quad_a.y * t + p->lin_v.y, 2 * p->quad_a.z * t + p->lin_v.z);
  nav_track_sample s;
  s.t_s = 1000.0 + t;
  s.pos.lat_rad = p->lat0 + r.x / m_lat;
  s.pos.lon_rad = nav_earth_wrap_lon(p->lon0 + r.y / m_lon);
  s.pos.h_m = p->h0 - r.z;
  /* E3.9 at the sample's own latitude and height: v_n = [(R_M + h) lat', (R_N + h) cos lat lon', -h']. */
  const double lat = s.pos.lat_rad, h = s.pos.h_m;
  s.v_n_mps = nav_vec3_make((nav_earth_radius_meridian_m(lat) + h) * v.x / m_lat,
                            (nav_earth_radius_prime_vertical_m(lat) + h) * cos(lat) * v.y / m_lon, v.z);
  if (p->attitude_varies) {
    s.att.yaw_rad = nav_wrap_pi(p->yaw0_rad + atan2(v.y, v.x));
    s.att.pitch_rad = 0.03 * cos(0.4 * t);
    s.att.roll_rad = 0.05 * sin(0.7 * t);
  } else {
    s.att = (nav_euler){0.1, -0.2, p->yaw0_rad};
  }
  return s;
}

static nav_track_sample *synth_samples(const synth *p, double rate_hz, double span_s, size_t *n) {
  const size_t count = (size_t)(span_s * rate_hz) + 1;
  nav_track_sample *s = malloc(count * sizeof *s);
  assert_non_null(s);
  for (size_t i = 0; i < count; ++i)
    s[i] = synth_at(p, (double)i / rate_hz);
  *n = count;
  return s;
}

static void test_exactness(void **state) {
  (void)state;
  nav_traj_recorded *r = malloc(sizeof *r);
  assert_non_null(r);
  char msg[256];
  /* 1. Quadratic in curvilinear coordinates, constant attitude: inside the spline space and
   *    free of the penalty (third differences of a quadratic vanish): round-off only. */
  const synth quad = {0.7, 2.0, 150.0, 0.0, 0.0, {0.2, -0.1, 0.05}, {3.0, 4.0, -0.5}, false, 0.3};
  size_t n = 0;
  nav_track_sample *s = synth_samples(&quad, 7.0, 60.0, &n);
  *r = nav_scene_default().trajectory.recorded;
  assert_int_equal(nav_track_fit(r, s, n, msg, sizeof msg), NAV_OK);
  print_message("quadratic path, constant attitude: pos %.2e m, vel %.2e m/s, att %.2e rad (max)\n",
                r->fit.pos_max_m, r->fit.vel_max_mps, r->fit.att_max_rad);
  assert_near(r->fit.pos_max_m, 0.0, 1e-7);
  assert_near(r->fit.vel_max_mps, 0.0, 1e-8);
  assert_near(r->fit.att_max_rad, 0.0, 1e-12);
  /* Between samples too. */
  for (double t = 0.05; t < 60.0; t += 1.234) {
    nav_track_sample e, x = synth_at(&quad, t);
    assert_int_equal(nav_track_eval(r, t, &e), NAV_OK);
    assert_near(e.t_s, x.t_s, 1e-9);
    assert_near((e.pos.lat_rad - x.pos.lat_rad) * 6.4e6, 0.0, 1e-7);
    assert_near(remainder(e.pos.lon_rad - x.pos.lon_rad, NAV_TWO_PI) * 6.4e6, 0.0, 1e-7);
    assert_vec3_near(e.v_n_mps, x.v_n_mps, 1e-8);
  }
  free(s);

  /* 2. A 5 m/s circle of radius 50 m across the antimeridian, heading along the track through
   *    +-180 deg, roll and pitch oscillating (periods 9 s and 16 s), 10 Hz samples, 4 Hz knots.
   *    Smooth motion far below the knot bandwidth: the residual is the spline approximation
   *    error, bounded here by 1 mm, 1 mm/s and 0.01 deg. */
  const synth circle = {-0.6, NAV_PI - 2.0e-6, 50.0, 50.0, 0.1, {0, 0, 0}, {0, 0, -0.2}, true, 2.5};
  s = synth_samples(&circle, 10.0, 120.0, &n);
  nav_traj_recorded_release(r);
  *r = nav_scene_default().trajectory.recorded;
  assert_int_equal(nav_track_fit(r, s, n, msg, sizeof msg), NAV_OK);
  bool crossed_lon = false, crossed_yaw = false;
  for (size_t i = 1; i < n; ++i) {
    crossed_lon |= fabs(s[i].pos.lon_rad - s[i - 1].pos.lon_rad) > NAV_PI;
    crossed_yaw |= fabs(s[i].att.yaw_rad - s[i - 1].att.yaw_rad) > NAV_PI;
  }
  assert_true(crossed_lon && crossed_yaw);
  print_message(
      "circle across the antimeridian, heading through +-180 deg: pos %.2e m, vel %.2e m/s, att %.2e deg "
      "(max)\n",
      r->fit.pos_max_m, r->fit.vel_max_mps, r->fit.att_max_rad / D2R);
  assert_near(r->fit.pos_max_m, 0.0, 1e-3);
  assert_near(r->fit.vel_max_mps, 0.0, 1e-3);
  assert_near(r->fit.att_max_rad, 0.0, 0.01 * D2R);
  /* nav_track_residuals on the same samples is the fit's own report. */
  nav_recorded_fit_stats f;
  assert_int_equal(nav_track_residuals(r, s, n, &f), NAV_OK);
  assert_int_equal(f.samples, (long)n);
  assert_near(f.pos_rms_m, r->fit.pos_rms_m, 0.0);
  assert_near(f.att_max_rad, r->fit.att_max_rad, 0.0);
  free(s);
  nav_traj_recorded_release(r);
  free(r);
}

/* ------------------------------------------------------------------ residuals on real data */

/*
 * The vendored slice at the scene's settings (4 Hz knots, 1 cm / 1 cm/s). The data are not
 * self-consistent (README: finite-difference velocities differ from the recorded ones by
 * 1.7 cm/s RMS, 20 cm/s across the first row; attitude moves up to 0.7 deg between rows), so
 * the bounds are the measured figures (printed) with about 30 % margin, not round-off.
 */
static void test_fit_residuals(void **state) {
  (void)state;
  nav_track_sample *samples = NULL;
  size_t n = 0;
  nav_scene *s = slice_scene(&samples, &n);
  const nav_recorded_fit_stats *f = &s->trajectory.recorded.fit;
  print_message(
      "KF-GINS dataset 2, first 300 s, %ld samples, 4 Hz knots (%d control points): position RMS %.2f mm "
      "(h %.2f, v %.2f), max %.1f mm at %.2f s; velocity RMS %.1f mm/s, max %.0f mm/s at %.2f s; attitude "
      "RMS %.3f deg, max %.3f deg at %.2f s\n",
      f->samples, s->trajectory.recorded.count, f->pos_rms_m * 1e3, f->pos_h_rms_m * 1e3,
      f->pos_v_rms_m * 1e3, f->pos_max_m * 1e3, f->pos_max_t_s, f->vel_rms_mps * 1e3, f->vel_max_mps * 1e3,
      f->vel_max_t_s, f->att_rms_rad / D2R, f->att_max_rad / D2R, f->att_max_t_s);
  assert_int_equal(f->samples, 3300);
  assert_int_equal(s->trajectory.recorded.count, 1205);
  assert_true(f->pos_rms_m < 0.005 && f->pos_max_m < 0.027);
  assert_true(f->vel_rms_mps < 0.042 && f->vel_max_mps < 0.18);
  assert_true(f->att_rms_rad < 0.095 * D2R && f->att_max_rad < 0.45 * D2R);
  /* Irregular 10 Hz steps: the longest is one step (README). */
  assert_true(f->max_gap_s > 0.099 && f->max_gap_s < 0.101);
  /* The largest position residual is the first row, the configured initial state (README). */
  assert_near(f->pos_max_t_s, 0.0, 0.0);
  /* Lower knot rates smooth more: the residuals grow monotonically. */
  double prev = 0.0;
  const double rates[3] = {4.0, 2.0, 1.0};
  for (int i = 0; i < 3; ++i) {
    nav_traj_recorded *r = malloc(sizeof *r);
    assert_non_null(r);
    *r = s->trajectory.recorded;
    r->knot_rate_hz = rates[i];
    char msg[256];
    assert_int_equal(nav_track_fit(r, samples, n, msg, sizeof msg), NAV_OK);
    print_message("  knot rate %.0f Hz: position RMS %.2f mm, velocity RMS %.1f mm/s, attitude RMS %.3f deg "
                  "(max %.3f)\n",
                  rates[i], r->fit.pos_rms_m * 1e3, r->fit.vel_rms_mps * 1e3, r->fit.att_rms_rad / D2R,
                  r->fit.att_max_rad / D2R);
    assert_true(r->fit.att_rms_rad >= prev);
    prev = r->fit.att_rms_rad;
    nav_traj_recorded_release(r);
    free(r);
  }
  free(samples);
  nav_scene_release(s);
  free(s);
}

/* ------------------------------------------------------------------ closure */

typedef struct closure {
  double pos_h_m, pos_v_m, vel_mps, att_rad, max_pos_h_m;
} closure;

static closure run_closure(const nav_scene *s, nav_mech_frame frame) {
  nav_truth *truth = NULL;
  nav_ins *ins = NULL;
  char msg[256];
  closure c = {0, 0, 0, 0, 0};
  nav_ins_config cfg = nav_ins_config_default();
  cfg.earth_model = NAV_EARTH_WGS84;
  cfg.algorithm = NAV_MECH_HIGH_ORDER;
  cfg.mech_frame = frame;
  cfg.gravity_model = s->earth.gravity_model;
  if (nav_truth_create_msg(s, &truth, msg, sizeof msg) != NAV_OK) fail_msg("truth: %s", msg);
  nav_traj_state ts;
  assert_int_equal(nav_truth_state(truth, 0.0, &ts), NAV_OK);
  const nav_ins_state s0 = {0.0, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f};
  assert_int_equal(nav_ins_create(&cfg, &s0, &ins), NAV_OK);
  const nav_frame fr = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  for (int64_t k = 1; k <= n; ++k) {
    nav_imu_increment imu;
    assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
    assert_int_equal(nav_ins_step(ins, &imu), NAV_OK);
    if (k % 200 == 0 || k == n) {
      assert_int_equal(nav_truth_state(truth, imu.t_s, &ts), NAV_OK);
      const nav_epoch_errors e = nav_errors_compute(&fr, &ts, nav_ins_get_state(ins));
      c.max_pos_h_m = fmax(c.max_pos_h_m, e.pos_err_h_m);
      if (k == n) {
        c.pos_h_m = e.pos_err_h_m;
        c.pos_v_m = e.pos_err_v_m;
        c.vel_mps = e.vel_err_mps;
        c.att_rad = e.att_err_rad;
      }
    }
  }
  nav_ins_destroy(ins);
  nav_truth_destroy(truth);
  return c;
}

/*
 * Perfect sensors along the recorded path (the scene of the library: 300 s, 200 Hz, 6-node
 * Gauss-Legendre increments, normal gravity) through the high-order mechanization in NED and in
 * ECEF. Target (issue 3): <= 1 cm after 300 s; the model is C4 and slow (<= 1.6 m/s, rates
 * <~ 0.5 rad/s), so the algorithm's truncation error is microns: the bound is 0.1 mm.
 */
static void test_closure(void **state) {
  (void)state;
  nav_scene *s = malloc(sizeof *s);
  assert_non_null(s);
  diag_log log = {0};
  if (nav_scene_read_file(SCENE, s, collect, &log) != NAV_OK) {
    print_log(&log);
    fail_msg("cannot read %s", SCENE);
  }
  assert_int_equal(s->trajectory.type, NAV_TRAJ_RECORDED);
  assert_near(s->imu.rate_hz, 200.0, 0.0);
  const nav_mech_frame frames[2] = {NAV_MECH_NED, NAV_MECH_ECEF};
  for (int i = 0; i < 2; ++i) {
    const closure c = run_closure(s, frames[i]);
    print_message(
        "closure along the recorded path, %s, %.2f s at 200 Hz, high order: pos h %.2e m (max %.2e), v "
        "%.2e m, vel %.2e m/s, att %.2e rad\n",
        nav_mech_frame_name(frames[i]), s->trajectory.duration_s, c.pos_h_m, c.max_pos_h_m, c.pos_v_m,
        c.vel_mps, c.att_rad);
    assert_true(c.max_pos_h_m <= 1e-4);
    assert_true(c.pos_v_m <= 1e-4);
    assert_true(c.vel_mps <= 1e-6);
    assert_true(c.att_rad <= 1e-8);
  }
  nav_scene_release(s);
  free(s);
}

/* ------------------------------------------------------------------ diagnostics */

static void read_bad(const char *text, int line, int col, const char *needle) {
  diag_log log = {0};
  nav_track_sample *out = NULL;
  size_t n = 0;
  const nav_status st = nav_track_read_string(text, strlen(text), "bad.nav", NAV_RECORDED_KF_GINS_NAV, 0, 0.0,
                                              0.0, "trajectory.recorded.file", &out, &n, collect, &log);
  if (st != NAV_ERR_PARSE || log.n < 1) {
    print_log(&log);
    fail_msg("expected a parse error for:\n%s", text);
  }
  char buf[1400];
  nav_diag_format(&log.d[0], buf, sizeof buf);
  print_message("%s\n", buf);
  assert_string_equal(log.d[0].file, "bad.nav");
  assert_string_equal(log.d[0].path, "trajectory.recorded.file");
  assert_int_equal(log.d[0].line, line);
  assert_int_equal(log.d[0].col, col);
  if (!strstr(log.d[0].message, needle)) fail_msg("message \"%s\" lacks \"%s\"", log.d[0].message, needle);
}

#define ROW1 "0 100.0 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 179.5\n"

static void test_malformed_files(void **state) {
  (void)state;
  /* Good input with comments, blank lines and CR-LF. */
  const char *good =
      "# week t lat lon h vn ve vd roll pitch yaw\n\n" ROW1 "0 100.1 30.5 114.3 21.0 0.1 0.2 0.0 0.5 "
      "-0.2 -179.5\r\n  \t\n0 100.2 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 359\n";
  nav_track_sample *out = NULL;
  size_t n = 0;
  diag_log log = {0};
  assert_int_equal(nav_track_read_string(good, strlen(good), "good.nav", NAV_RECORDED_KF_GINS_NAV, 0, 0, 0,
                                         "x", &out, &n, collect, &log),
                   NAV_OK);
  assert_int_equal(n, 3);
  assert_near(out[0].pos.lat_rad, 30.5 * D2R, 1e-15);
  assert_near(out[1].att.yaw_rad, -179.5 * D2R, 1e-15);
  assert_near(out[2].att.yaw_rad, -1.0 * D2R, 1e-15); /* 359 deg wrapped */
  assert_vec3_near(out[0].v_n_mps, nav_vec3_make(0.1, 0.2, 0.0), 0.0);
  free(out);
  /* Window. */
  assert_int_equal(nav_track_read_string(good, strlen(good), "good.nav", NAV_RECORDED_KF_GINS_NAV,
                                         NAV_RECORDED_HAS_START, 100.05, 0, "x", &out, &n, collect, &log),
                   NAV_OK);
  assert_int_equal(n, 2);
  assert_near(out[0].t_s, 100.1, 0.0);
  free(out);

  read_bad(ROW1 "0 100.1 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2\n", 2, 45, "missing yaw [deg]");
  read_bad(ROW1 "0 100.1 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 1 7\n", 2, 48, "unexpected field \"7\"");
  read_bad(ROW1 "0 100.1 30.5 114.3 21,0 0.1 0.2 0.0 0.5 -0.2 1\n", 2, 20,
           "height [m]: \"21,0\" is not a finite");
  read_bad(ROW1 "0 100.1 30.5 nan 21.0 0.1 0.2 0.0 0.5 -0.2 1\n", 2, 14, "longitude [deg]: \"nan\"");
  read_bad(ROW1 "0 100.0 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 1\n", 2, 3, "does not increase (line 1");
  read_bad(ROW1 "0 100.1 95.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 1\n", 2, 9, "latitude [deg]: 95.5 is outside");
  read_bad(ROW1 "0 100.1 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -91 1\n", 2, 41, "pitch [deg]");
  read_bad("", 0, 0, "no samples");
  read_bad("# only a comment\n" ROW1, 0, 0, "at least 2");
  /* Window with fewer than 2 samples names the file's span. */
  log.n = 0;
  assert_int_equal(nav_track_read_string(good, strlen(good), "good.nav", NAV_RECORDED_KF_GINS_NAV,
                                         NAV_RECORDED_HAS_START | NAV_RECORDED_HAS_END, 200, 300, "x", &out,
                                         &n, collect, &log),
                   NAV_ERR_PARSE);
  assert_non_null(strstr(log.d[0].message, "covers 100 to 100.2 s"));
  /* Missing file. */
  log.n = 0;
  assert_int_equal(nav_track_read_file("/nonexistent/x.nav", NAV_RECORDED_KF_GINS_NAV, 0, 0, 0, "x", &out, &n,
                                       collect, &log),
                   NAV_ERR_IO);
  assert_int_equal(log.n, 1);
}

/* Issue 25: a position that jumps beyond what the recorded velocities allow (1 deg of latitude,
 * 111 km, in 0.1 s at 0.2 m/s) is refused at the later sample's latitude, not smoothed over by
 * the fit; a small offset within 1 m + 100 m/s^2 x dt^2 / 4 is accepted. */
static void test_issue_25_position_jump(void **state) {
  (void)state;
  read_bad(ROW1 "0 100.1 30.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 179.5\n"
                "0 100.2 31.5 114.3 21.0 0.1 0.2 0.0 0.5 -0.2 179.5\n",
           3, 9, "the position jumps 110");
  /* A height step of 2 m in 0.1 s (bound 1.25 m) is a jump; 1 m is not. */
  read_bad(ROW1 "0 100.1 30.5 114.3 23.0 0.1 0.2 0.0 0.5 -0.2 179.5\n", 2, 9, "exceeds 1.25 m");
  const char *ok = ROW1 "0 100.1 30.5 114.3 22.0 0.1 0.2 0.0 0.5 -0.2 179.5\n";
  nav_track_sample *out = NULL;
  size_t n = 0;
  diag_log log = {0};
  assert_int_equal(nav_track_read_string(ok, strlen(ok), "ok.nav", NAV_RECORDED_KF_GINS_NAV, 0, 0, 0, "x", &out, &n,
                                         collect, &log),
                   NAV_OK);
  assert_int_equal(n, 2);
  free(out);
  /* The recorded reference of the test data (real vehicle, 10 Hz) passes: tests/data/recorded. */
  assert_int_equal(nav_track_read_file(NAV_TEST_DATA_DIR "/recorded/adis16465-truth-116454-116754.nav",
                                       NAV_RECORDED_KF_GINS_NAV, 0, 0, 0, "x", &out, &n, collect, &log),
                   NAV_OK);
  assert_true(n > 2000);
  free(out);
}

/* What the fit refuses, with the sample or limit named. */
static void test_fit_refusals(void **state) {
  (void)state;
  nav_traj_recorded *r = malloc(sizeof *r);
  assert_non_null(r);
  char msg[256];
  const synth circle = {0.5, 0.2, 10.0, 50.0, 0.1, {0, 0, 0}, {0, 0, 0}, true, 0.0};
  size_t n = 0;
  nav_track_sample *s = synth_samples(&circle, 10.0, 400.0, &n);
  *r = nav_scene_default().trajectory.recorded;
  /* 400 s x 4 Hz + 5 = 1605 control points: beyond the 1280 that the scene value once held, on
   * the heap now (issue 18). */
  assert_int_equal(nav_track_fit(r, s, n, msg, sizeof msg), NAV_OK);
  assert_int_equal(r->count, 1605);
  const nav_vec3 *const ctrl_before = r->ctrl_ned_m;
  /* The cap on the memory a file may ask for: 5000 s at 1000 Hz needs 5 000 005 control points,
   * more than NAV_RECORDED_MAX_CTRL (4 000 000); the largest rate that fits is named. Refused
   * before anything is allocated; r keeps its model. */
  size_t n_long = 0;
  nav_track_sample *s_long = synth_samples(&circle, 0.2, 5000.0, &n_long);
  r->knot_rate_hz = 1000.0;
  assert_int_equal(nav_track_fit(r, s_long, n_long, msg, sizeof msg), NAV_ERR_OUT_OF_RANGE);
  print_message("%s\n", msg);
  assert_non_null(strstr(msg, "knot_rate_hz <= 799.9"));
  assert_int_equal(r->count, 1605); /* untouched */
  assert_ptr_equal(r->ctrl_ned_m, ctrl_before);
  free(s_long);
  nav_traj_recorded_release(r);
  assert_int_equal(r->count, 0);
  assert_null(r->ctrl_ned_m);
  assert_null(r->ctrl_q);
  nav_traj_recorded_release(r); /* twice: a no-op */
  r->knot_rate_hz = 3.1875;
  assert_int_equal(nav_track_fit(r, s, n, msg, sizeof msg), NAV_OK);
  assert_int_equal(r->count, 1280);
  /* Attitude jumping 120 deg between samples. */
  nav_traj_recorded *r2 = malloc(sizeof *r2);
  assert_non_null(r2);
  *r2 = nav_scene_default().trajectory.recorded;
  s[11].att.yaw_rad += 2.1;
  assert_int_equal(nav_track_fit(r2, s, 50, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "samples 10 and 11"));
  s[11].att.yaw_rad -= 2.1;
  /* Times not increasing, non-finite, polar latitude, bad settings. */
  s[5].t_s = s[4].t_s;
  assert_int_equal(nav_track_fit(r2, s, 50, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "sample 5"));
  s[5].t_s = s[4].t_s + 0.1;
  s[7].v_n_mps.y = NAN;
  assert_int_equal(nav_track_fit(r2, s, 50, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  s[7].v_n_mps.y = 0.0;
  s[8].pos.lat_rad = 89.5 * D2R;
  assert_int_equal(nav_track_fit(r2, s, 50, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "89 deg"));
  s[8] = synth_at(&circle, 0.8);
  r2->knot_rate_hz = 0.0;
  assert_int_equal(nav_track_fit(r2, s, 50, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  r2->knot_rate_hz = 4.0;
  assert_int_equal(nav_track_fit(r2, s, 1, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_track_fit(r2, s, 50, msg, sizeof msg), NAV_OK);
  /* A model that was never fitted is refused by the trajectory and by validation. */
  nav_scene *sc = new_scene();
  nav_traj *tr = NULL;
  assert_int_equal(nav_traj_create_msg(sc, 0.01, &tr, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "no fitted samples"));
  assert_int_equal(nav_scene_validate(sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  /* Fitted, but on a flat Earth: a geodetic model needs WGS-84. */
  sc->trajectory.recorded = *r2;
  sc->trajectory.duration_s = r2->span_s;
  assert_int_equal(nav_scene_validate(sc, NULL, NULL), NAV_OK);
  sc->earth.model = NAV_EARTH_FLAT;
  assert_int_equal(nav_scene_validate(sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_traj_create_msg(sc, 0.01, &tr, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "wgs84"));
  sc->earth.model = NAV_EARTH_WGS84;
  sc->trajectory.duration_s = r2->span_s + 1.0;
  assert_int_equal(nav_scene_validate(sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  free(sc); /* a plain copy of r2: r2 owns the control points */
  free(s);
  nav_traj_recorded_release(r2);
  free(r2);
  nav_traj_recorded_release(r);
  free(r);
}

/* ------------------------------------------------------------------ scene files */

static char g_dir[64];

static void write_text(const char *name, const char *text) {
  char path[256];
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  fputs(text, f);
  fclose(f);
}

static nav_status read_scene(const char *name, nav_scene *s, diag_log *log) {
  char path[256];
  snprintf(path, sizeof path, "%s/%s", g_dir, name);
  log->n = 0;
  return nav_scene_read_file(path, s, collect, log);
}

#define HEAD "format_version: 1\nearth: {model: wgs84}\ntrajectory:\n  type: recorded\n"

static void expect_error(const char *name, const char *text, const char *file_suffix, int line, int col,
                         const char *path, const char *needle) {
  nav_scene *s = malloc(sizeof *s);
  assert_non_null(s);
  diag_log log = {0};
  write_text(name, text);
  const nav_status st = read_scene(name, s, &log);
  if (st != NAV_ERR_PARSE || log.n < 1) {
    print_log(&log);
    fail_msg("%s: expected a parse error", name);
  }
  char buf[1400];
  nav_diag_format(&log.d[0], buf, sizeof buf);
  print_message("%s\n", buf);
  const size_t lf = strlen(log.d[0].file), ls = strlen(file_suffix);
  if (!(lf >= ls && strcmp(log.d[0].file + lf - ls, file_suffix) == 0))
    fail_msg("%s: diagnostic file \"%s\" does not end with \"%s\"", name, log.d[0].file, file_suffix);
  assert_int_equal(log.d[0].line, line);
  assert_int_equal(log.d[0].col, col);
  assert_string_equal(log.d[0].path, path);
  if (!strstr(log.d[0].message, needle)) fail_msg("message \"%s\" lacks \"%s\"", log.d[0].message, needle);
  free(s);
}

static void test_scene_files(void **state) {
  (void)state;
  snprintf(g_dir, sizeof g_dir, "/tmp/nav_test_recorded_XXXXXX");
  assert_non_null(mkdtemp(g_dir));
  nav_scene *a = malloc(sizeof *a), *b = malloc(sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  diag_log log = {0};

  /* A malformed data file: its own FILE:LINE:COL, then the scene's summary. */
  write_text("bad.nav", ROW1 "0 100.1 30.5 114.3 21.0 0.1 0.2 0.0 0.5 x 1\n");
  expect_error("s1.yaml", HEAD "  recorded: {file: bad.nav}\n", "/bad.nav", 2, 41, "trajectory.recorded.file",
               "pitch [deg]: \"x\" is not a finite number");
  /* Missing file, relative to the scene's directory. */
  expect_error("s2.yaml", HEAD "  recorded:\n    file: nothere.nav\n", "s2.yaml", 6, 11,
               "trajectory.recorded.file", "nothere.nav\": No such file");
  /* Knots at the slice's own 10 Hz: 3005 control points, more than the 1280 the scene value once
   * held (issue 18): read, fitted, and a trajectory made from it (the cap on the count is tested
   * in test_fit_refusals). */
  write_text("s3.yaml", HEAD "  recorded:\n    file: " SLICE "\n    knot_rate_hz: 10\n");
  if (read_scene("s3.yaml", a, &log) != NAV_OK) {
    print_log(&log);
    fail_msg("s3.yaml: 10 Hz knots");
  }
  assert_int_equal(a->trajectory.recorded.count, 3005);
  assert_int_equal(a->trajectory.recorded.fit.samples, 3300);
  assert_non_null(a->trajectory.recorded.ctrl_ned_m);
  print_message("slice at 10 Hz knots: %d control points; residuals position RMS %.3g mm, velocity RMS %.3g mm/s, "
                "attitude RMS %.3g deg\n",
                a->trajectory.recorded.count, a->trajectory.recorded.fit.pos_rms_m * 1e3,
                a->trajectory.recorded.fit.vel_rms_mps * 1e3, a->trajectory.recorded.fit.att_rms_rad / D2R);
  nav_scene_release(a);
  /* The file sets the initial attitude. */
  expect_error("s4.yaml", HEAD "  initial_attitude: {yaw_deg: 3}\n  recorded: {file: " SLICE "}\n", "s4.yaml",
               5, 21, "trajectory.initial_attitude", "sets the initial attitude");
  /* duration_s beyond the recorded span. */
  expect_error("s5.yaml", HEAD "  duration_s: 400\n  recorded: {file: " SLICE "}\n", "s5.yaml", 5, 15,
               "trajectory.duration_s", "must not exceed the recorded span");
  /* Flat Earth. */
  expect_error("s6.yaml", "format_version: 1\ntrajectory:\n  type: recorded\n  recorded: {file: " SLICE "}\n",
               "s6.yaml", 3, 9, "trajectory.type", "needs earth.model: wgs84");
  /* No recorded section; file missing from it. */
  expect_error("s7.yaml", HEAD, "s7.yaml", 4, 9, "trajectory.type", "needs trajectory.recorded");
  expect_error("s8.yaml", HEAD "  recorded: {knot_rate_hz: 2}\n", "s8.yaml", 5, 13,
               "trajectory.recorded.file", "missing required key \"file\"");
  /* Window with start_s > end_s. */
  expect_error("s9.yaml", HEAD "  recorded: {file: " SLICE ", start_s: 116600, end_s: 116500}\n", "s9.yaml",
               5, (int)sizeof("  recorded: {file: " SLICE ", start_s: 116600, end_s: "),
               "trajectory.recorded.end_s", "must be later than start_s");
  /* A window with fewer than 2 samples: the data file's span is named. */
  expect_error("s10.yaml", HEAD "  recorded: {file: " SLICE ", start_s: 116800}\n", SLICE, 0, 0,
               "trajectory.recorded.file", "at least 2 are needed (the file covers 116454 to 116753.99 s)");

  /* A window and an explicit origin: scene time 0 is the first sample at or after start_s. */
  write_text("w.yaml",
             "format_version: 1\nearth: {model: wgs84, origin: {lat_deg: 30, lon_deg: 114, h_m: 0}}\n"
             "trajectory:\n  type: recorded\n  duration_s: 50\n  recorded: {file: " SLICE
             ", start_s: 116500, end_s: 116600.5, knot_rate_hz: 2}\n");
  if (read_scene("w.yaml", a, &log) != NAV_OK) {
    print_log(&log);
    fail_msg("w.yaml");
  }
  const nav_traj_recorded *R = &a->trajectory.recorded;
  assert_true(R->t0_s >= 116500.0 && R->t0_s < 116500.2);
  assert_true(R->span_s > 100.0 && R->span_s <= 100.5);
  assert_near(a->trajectory.duration_s, 50.0, 0.0);
  assert_near(a->earth.origin_lat_rad, 30.0 * D2R, 1e-15);
  assert_int_equal(R->window, NAV_RECORDED_HAS_START | NAV_RECORDED_HAS_END);
  assert_int_equal(R->count, (int)ceil(R->span_s * 2.0 - 1e-9) + 5);
  nav_scene_release(a); /* a is read again below */

  /* The library scene: origin and attitude from the first sample, duration auto = span, the
   * file stored resolved; writing and reading back gives the same model bit for bit. */
  assert_int_equal(nav_scene_read_file(SCENE, a, collect, &log), NAV_OK);
  R = &a->trajectory.recorded;
  assert_near(a->trajectory.duration_s, R->span_s, 0.0);
  assert_near(R->span_s, 116753.990201 - 116454.0, 1e-6);
  /* The origin is the fit at t = 0, within the fit's residual of the first sample. */
  assert_true(fabs(a->earth.origin_lat_rad - R->ref_lat_rad) * 6.4e6 <= R->fit.pos_max_m);
  assert_true(R->file[0] == '/');
  assert_non_null(strstr(R->file, "tests/data/recorded/adis16465-truth-116454-116754.nav"));
  assert_true(fabs(a->trajectory.initial_attitude.yaw_rad - 179.5 * D2R) < 0.1 * D2R);
  char out[128], out2[128];
  snprintf(out, sizeof out, "%s/rt.yaml", g_dir);
  snprintf(out2, sizeof out2, "%s/rt2.yaml", g_dir);
  assert_int_equal(nav_scene_write_file(out, a), NAV_OK);
  if (nav_scene_read_file(out, b, collect, &log) != NAV_OK) {
    print_log(&log);
    fail_msg("written scene does not read back");
  }
  /* The same model bit for bit: the record with its control-point pointers set aside, and the
   * control points themselves (each scene owns its own). */
  {
    nav_traj_recorded ra, rb;
    memcpy(&ra, &a->trajectory.recorded, sizeof ra); /* byte copies: padding included */
    memcpy(&rb, &b->trajectory.recorded, sizeof rb);
    assert_int_equal(ra.count, rb.count);
    assert_true(ra.ctrl_ned_m != rb.ctrl_ned_m);
    assert_int_equal(memcmp(ra.ctrl_ned_m, rb.ctrl_ned_m, (size_t)ra.count * sizeof *ra.ctrl_ned_m), 0);
    assert_int_equal(memcmp(ra.ctrl_q, rb.ctrl_q, (size_t)ra.count * sizeof *ra.ctrl_q), 0);
    ra.ctrl_ned_m = rb.ctrl_ned_m = NULL;
    ra.ctrl_q = rb.ctrl_q = NULL;
    assert_int_equal(memcmp(&ra, &rb, sizeof ra), 0);
  }
  assert_int_equal(memcmp(&a->earth, &b->earth, sizeof a->earth), 0);
  assert_int_equal(memcmp(&a->trajectory.initial_attitude, &b->trajectory.initial_attitude,
                          sizeof a->trajectory.initial_attitude),
                   0);
  assert_int_equal(nav_scene_write_file(out2, b), NAV_OK);

  /* Clean up the directory. */
  const char *names[] = {"bad.nav", "s1.yaml", "s2.yaml", "s3.yaml",  "s4.yaml", "s5.yaml", "s6.yaml",
                         "s7.yaml", "s8.yaml", "s9.yaml", "s10.yaml", "w.yaml",  "rt.yaml", "rt2.yaml"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
    char p[256];
    snprintf(p, sizeof p, "%s/%s", g_dir, names[i]);
    remove(p);
  }
  assert_int_equal(rmdir(g_dir), 0);
  nav_scene_release(a);
  nav_scene_release(b);
  free(a);
  free(b);
}

/* Issue 18: knots faster than the samples fit every sample exactly (residuals ~0) with nothing
 * between them; nav_track_warnings says so. The vendored slice (about 11 rows per second) at
 * 4 Hz knots draws no warning; its rows at whole seconds (1 Hz with gaps) at 4 Hz knots draw the
 * knots-outrun warning (and, here, the jerk warning), at 0.5 Hz knots not the outrun one. */
static void test_issue_18_knots_outrun_samples(void **state) {
  (void)state;
  nav_track_sample *samples = NULL;
  size_t n = 0;
  nav_scene *s = slice_scene(&samples, &n);
  char msg[1200];
  const nav_traj_recorded *r = &s->trajectory.recorded;
  assert_near(r->fit.sample_rate_hz, (double)(n - 1) / r->span_s, 1e-12);
  assert_true(r->fit.rec_acc_max_mps2 > 0.0);
  const unsigned w0 = nav_track_warnings(r, msg, sizeof msg);
  print_message("10 Hz samples, 4 Hz knots: warnings %#x \"%s\"; fitted acc max %.3g, recorded %.3g m/s^2\n", w0, msg,
                r->fit.fit_acc_max_mps2, r->fit.rec_acc_max_mps2);
  assert_int_equal(w0, 0);
  assert_string_equal(msg, "");
  size_t m = 0;
  for (size_t i = 0; i < n; ++i)
    if (samples[i].t_s == floor(samples[i].t_s)) samples[m++] = samples[i];
  assert_true(m > 100);
  nav_traj_recorded *d = malloc(sizeof *d);
  assert_non_null(d);
  *d = nav_scene_default().trajectory.recorded;
  d->knot_rate_hz = 4.0;
  assert_int_equal(nav_track_fit(d, samples, m, msg, sizeof msg), NAV_OK);
  const unsigned w1 = nav_track_warnings(d, msg, sizeof msg);
  print_message("1 Hz samples, 4 Hz knots: residual max %.2e m; warnings %#x \"%s\"\n", d->fit.pos_max_m, w1, msg);
  assert_true(d->fit.sample_rate_hz < 1.0);
  assert_true((w1 & NAV_TRACK_WARN_KNOTS_OUTRUN) != 0);
  assert_non_null(strstr(msg, "outrun the samples"));
  d->knot_rate_hz = 0.5;
  nav_traj_recorded_release(d); /* d owned the 4 Hz model (nav_track_fit does not free it) */
  assert_int_equal(nav_track_fit(d, samples, m, msg, sizeof msg), NAV_OK);
  const unsigned w2 = nav_track_warnings(d, msg, sizeof msg);
  print_message("1 Hz samples, 0.5 Hz knots: residual max %.3g m; warnings %#x\n", d->fit.pos_max_m, w2);
  assert_int_equal(w2 & NAV_TRACK_WARN_KNOTS_OUTRUN, 0);
  nav_traj_recorded_release(d);
  free(d);
  free(samples);
  nav_scene_release(s);
  free(s);
}

/* Ownership of the control points (issue 18): a deep copy outlives its source, the trajectory
 * object and the simulation keep their own copy, release frees and is safe twice. Run in the
 * sanitizer build, LeakSanitizer checks that nothing is lost. */
static void test_ownership(void **state) {
  (void)state;
  nav_track_sample *samples = NULL;
  size_t n = 0;
  nav_scene *s = slice_scene(&samples, &n);
  free(samples);
  nav_scene *c = malloc(sizeof *c);
  assert_non_null(c);
  assert_int_equal(nav_scene_copy(c, s), NAV_OK);
  const nav_traj_recorded *rs = &s->trajectory.recorded, *rc = &c->trajectory.recorded;
  assert_int_equal(rc->count, rs->count);
  assert_true(rc->ctrl_ned_m != rs->ctrl_ned_m && rc->ctrl_q != rs->ctrl_q);
  assert_int_equal(memcmp(rc->ctrl_ned_m, rs->ctrl_ned_m, (size_t)rs->count * sizeof *rs->ctrl_ned_m), 0);
  assert_int_equal(memcmp(rc->ctrl_q, rs->ctrl_q, (size_t)rs->count * sizeof *rs->ctrl_q), 0);
  /* What the source gives before it goes, the copy, the trajectory and the simulation give after. */
  nav_track_sample before, after;
  const double t = 0.75 * rs->span_s;
  assert_int_equal(nav_track_eval(rs, t, &before), NAV_OK);
  nav_traj_model m;
  create_model(s, &m);
  nav_geo_kin g_before = geo(&m, t);
  s->trajectory.duration_s = 2.0; /* a short run for the simulation below */
  s->imu.rate_hz = 100.0;
  s->output.rate_hz = 10.0;
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(s, &sim), NAV_OK);
  nav_scene_release(s);
  assert_int_equal(s->trajectory.recorded.count, 0);
  assert_null(s->trajectory.recorded.ctrl_ned_m);
  nav_scene_release(s); /* twice: a no-op */
  assert_int_equal(nav_scene_validate(s, NULL, NULL), NAV_ERR_INVALID_ARG); /* no model any more */
  assert_int_equal(nav_track_eval(rc, t, &after), NAV_OK);
  assert_int_equal(memcmp(&before, &after, sizeof before), 0);
  const nav_geo_kin g_after = geo(&m, t);
  assert_int_equal(memcmp(&g_before.pos, &g_after.pos, sizeof g_before.pos), 0);
  m.destroy(m.self);
  nav_sim_summary sum;
  memset(&sum, 0, sizeof sum);
  nav_sim_options opt;
  memset(&opt, 0, sizeof opt);
  opt.threads = 1;
  assert_int_equal(nav_sim_run(sim, &opt, &sum), NAV_OK);
  assert_true(sum.imu_samples > 0);
  nav_sim_destroy(sim);
  /* A copy of a scene without heap data, and NULL arguments. */
  nav_scene *d = malloc(sizeof *d);
  assert_non_null(d);
  assert_int_equal(nav_scene_copy(d, s), NAV_OK);
  assert_null(d->trajectory.recorded.ctrl_ned_m);
  assert_int_equal(nav_scene_copy(NULL, s), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_traj_recorded_copy(&d->trajectory.recorded, NULL), NAV_ERR_INVALID_ARG);
  nav_scene_release(NULL);
  nav_traj_recorded_release(NULL);
  nav_scene_release(d);
  nav_scene_release(c);
  free(d);
  free(c);
  free(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_derivatives),  cmocka_unit_test(test_continuity),
      cmocka_unit_test(test_exactness),    cmocka_unit_test(test_fit_residuals),
      cmocka_unit_test(test_closure),      cmocka_unit_test(test_malformed_files),
      cmocka_unit_test(test_ownership),
      cmocka_unit_test(test_issue_25_position_jump),
      cmocka_unit_test(test_fit_refusals), cmocka_unit_test(test_scene_files),
      cmocka_unit_test(test_issue_18_knots_outrun_samples),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
