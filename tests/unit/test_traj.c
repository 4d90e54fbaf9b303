/*
 * Waypoint and segment-script trajectories (waypoints.c, segments.c, kinematics.c) and the
 * gnss-ins-sim motion-definition import (motiondef.c):
 *   - analytic derivatives against central differences (v, a, w_nb_b, dw_nb_b, C^T C_dot = [w x]),
 *     at many times including every transition;
 *   - continuity of position, velocity, acceleration, attitude, rate and angular acceleration
 *     across every transition;
 *   - limits (acceleration, jerk, turn rate, lateral acceleration, angular acceleration) sampled
 *     densely;
 *   - infeasible input gives an error naming the waypoint/segment and the limit;
 *   - attitude modes; waypoint geometry and timing;
 *   - motion_def-long_drive.csv imports with the file's start state;
 *   - closure: exact ideal IMU + strapdown reproduce the trajectory (flat Earth; WGS-84 when the
 *     WGS-84 mechanization is available).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_ins.h"
#include "navcore/nav_motiondef.h"
#include "navcore/nav_truth.h"
#include "traj/traj_kin_internal.h"

#define LONG_DRIVE NAV_SOURCE_DIR "/resources/motion_defs/motion_def-long_drive.csv"
#define D2R NAV_DEG2RAD

/* ------------------------------------------------------------------ helpers */

static nav_scene *new_scene(void) {
  nav_scene *s = malloc(sizeof *s);
  assert_non_null(s);
  *s = nav_scene_default();
  return s;
}

static void add_wp(nav_scene *s, double n, double e, double d, double speed) {
  nav_waypoint *p = &s->trajectory.waypoints.points[s->trajectory.waypoints.count++];
  memset(p, 0, sizeof *p);
  p->r_ned_m = nav_vec3_make(n, e, d);
  p->speed_mps = speed;
}

static nav_segment *add_seg(nav_scene *s, nav_segment_kind kind) {
  nav_segment *g = &s->trajectory.segments.items[s->trajectory.segments.count++];
  memset(g, 0, sizeof *g);
  g->kind = kind;
  g->gnss_visible = true;
  return g;
}

/* A car driving a figure-eight through 8 waypoints (two lobes of 150 m x 150 m), starting and
 * ending at rest with holds, speeds 6-10 m/s. */
static nav_scene *car_figure_eight(nav_wp_attitude_mode mode) {
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_WAYPOINTS;
  nav_traj_waypoints *w = &s->trajectory.waypoints;
  w->attitude_mode = mode;
  w->hold_start_s = 2.0;
  w->hold_end_s = 3.0;
  add_wp(s, 0, 0, 0, 0);
  add_wp(s, 150, 0, 0, 8);
  add_wp(s, 150, 150, 0, 6);
  add_wp(s, 0, 150, 0, 8);
  add_wp(s, 0, 300, -4, 10); /* a gentle slope: pitch from slope */
  add_wp(s, 150, 300, -4, 6);
  add_wp(s, 150, 150, 0, 8);
  add_wp(s, 0, 150, 0, 0);
  return s;
}

static void create_model(const nav_scene *s, nav_traj_model *m) {
  char msg[512];
  nav_status st = s->trajectory.type == NAV_TRAJ_WAYPOINTS
                      ? nav_traj_waypoints_create(s, 0.01, m, msg, sizeof msg)
                      : nav_traj_segments_create(s, 0.01, m, msg, sizeof msg);
  if (st != NAV_OK) fail_msg("create failed: %s", msg);
}

static size_t model_breaks(const nav_scene *s, const nav_traj_model *m, double *out, size_t cap) {
  return s->trajectory.type == NAV_TRAJ_WAYPOINTS ? nav_traj_waypoints_breaks(m->self, out, cap)
                                                  : nav_traj_segments_breaks(m->self, out, cap);
}

static nav_local_kin kin_at(const nav_traj_model *m, double t) {
  nav_local_kin k;
  assert_int_equal(m->eval_local(m->self, t, &k), NAV_OK);
  return k;
}

static nav_vec3 vee(nav_mat3 W) {
  return nav_vec3_make(W.m[2][1], W.m[0][2], W.m[1][0]);
}

typedef struct mismatch {
  double v, a, w, dw, skew;
} mismatch;

/* Analytic derivatives against central differences at t. Translation: h = 1e-4 s (truncation
 * h^2/6 x jerk < 1e-8, rounding eps |r| / h < 1e-8 for |r| < 5 km). Rotation: h = 1e-5 s, because
 * the fourth derivative of the rate inside a short ramp, 840 dr / T^4, reaches ~1e4 rad/s^5
 * (h^2/6 x that = 2e-7 at 1e-5 s), while rounding eps |w| / h stays ~1e-11. */
static void check_derivatives_at(const nav_traj_model *m, double t, mismatch *worst) {
  const double h = 1e-4, ha = 1e-5;
  const nav_local_kin k = kin_at(m, t), kp = kin_at(m, t + h), km = kin_at(m, t - h);
  const nav_local_kin ap = kin_at(m, t + ha), am = kin_at(m, t - ha);
  const nav_vec3 v_fd = nav_vec3_scale(nav_vec3_sub(kp.r_ned_m, km.r_ned_m), 0.5 / h);
  const nav_vec3 a_fd = nav_vec3_scale(nav_vec3_sub(kp.v_ned_mps, km.v_ned_mps), 0.5 / h);
  const nav_vec3 dw_fd = nav_vec3_scale(nav_vec3_sub(ap.w_nb_b_rps, am.w_nb_b_rps), 0.5 / ha);
  const nav_mat3 C = nav_quat_to_dcm(k.q_b_n);
  const nav_mat3 Cd = nav_mat3_scale(
      nav_mat3_add(nav_quat_to_dcm(ap.q_b_n), nav_mat3_scale(nav_quat_to_dcm(am.q_b_n), -1.0)), 0.5 / ha);
  const nav_mat3 W = nav_mat3_tmul(C, Cd);
  const double ev = nav_vec3_norm(nav_vec3_sub(k.v_ned_mps, v_fd));
  const double ea = nav_vec3_norm(nav_vec3_sub(k.a_ned_mps2, a_fd));
  const double ew = nav_vec3_norm(nav_vec3_sub(vee(W), k.w_nb_b_rps));
  const double edw = nav_vec3_norm(nav_vec3_sub(k.dw_nb_b_rps2, dw_fd));
  /* C^T C_dot must be skew-symmetric. */
  const double es = fabs(W.m[0][0]) + fabs(W.m[1][1]) + fabs(W.m[2][2]) + fabs(W.m[0][1] + W.m[1][0]) +
                    fabs(W.m[0][2] + W.m[2][0]) + fabs(W.m[1][2] + W.m[2][1]);
  if (ev > worst->v) worst->v = ev;
  if (ea > worst->a) worst->a = ea;
  if (ew > worst->w) worst->w = ew;
  if (edw > worst->dw) worst->dw = edw;
  if (es > worst->skew) worst->skew = es;
  if (!(ev < 1e-6 && ea < 1e-6 && ew < 1e-7 && edw < 1e-6 && es < 1e-7))
    fail_msg("derivative mismatch at t = %.9f s: v %.3g m/s, a %.3g m/s^2, w %.3g rad/s, dw %.3g rad/s^2, "
             "skew %.3g",
             t, ev, ea, ew, edw, es);
}

/* Continuity across t. r, v, w: the change over [t - d, t + d] (d = 1e-7 s) minus what the
 * derivative predicts is at rounding level. a, q, dw (whose derivatives are not returned): the
 * change over 2d must be ~10x smaller than over 20d, as for any continuous function; a step
 * (e.g. of angular acceleration) would be the same size over both. */
static double jump_ratio(double small, double large) {
  return small <= 1e-12 ? 0.0 : small / large;
}

static void check_continuity_at(const nav_traj_model *m, double t) {
  const double d = 1e-7, D = 1e-6;
  const nav_local_kin a = kin_at(m, t - d), b = kin_at(m, t + d), c = kin_at(m, t);
  const nav_local_kin A = kin_at(m, t - D), B = kin_at(m, t + D);
  const double dr = nav_vec3_norm(nav_vec3_axpy(nav_vec3_sub(b.r_ned_m, a.r_ned_m), -2 * d, c.v_ned_mps));
  const double dv =
      nav_vec3_norm(nav_vec3_axpy(nav_vec3_sub(b.v_ned_mps, a.v_ned_mps), -2 * d, c.a_ned_mps2));
  const double dw =
      nav_vec3_norm(nav_vec3_axpy(nav_vec3_sub(b.w_nb_b_rps, a.w_nb_b_rps), -2 * d, c.dw_nb_b_rps2));
  const double ja = jump_ratio(nav_vec3_norm(nav_vec3_sub(b.a_ned_mps2, a.a_ned_mps2)),
                               nav_vec3_norm(nav_vec3_sub(B.a_ned_mps2, A.a_ned_mps2)));
  const double jq =
      jump_ratio(nav_quat_angle_between(a.q_b_n, b.q_b_n), nav_quat_angle_between(A.q_b_n, B.q_b_n));
  const double jdw = jump_ratio(nav_vec3_norm(nav_vec3_sub(b.dw_nb_b_rps2, a.dw_nb_b_rps2)),
                                nav_vec3_norm(nav_vec3_sub(B.dw_nb_b_rps2, A.dw_nb_b_rps2)));
  if (!(dr < 1e-9 && dv < 1e-10 && dw < 1e-10 && ja < 0.15 && jq < 0.15 && jdw < 0.15))
    fail_msg("discontinuity at t = %.9f s: r %.3g, v %.3g, w %.3g; jump ratios a %.3g, q %.3g, dw %.3g", t,
             dr, dv, dw, ja, jq, jdw);
}

/* Derivatives at every transition (and just off it) and on a grid; continuity at every
 * transition. Returns the worst mismatches. */
static mismatch check_model(const nav_scene *s, const nav_traj_model *m, double grid_step_s) {
  mismatch worst = {0, 0, 0, 0, 0};
  enum { CAP = 20000 };
  double *br = malloc(CAP * sizeof *br);
  assert_non_null(br);
  const size_t nb = model_breaks(s, m, br, CAP);
  assert_true(nb < CAP);
  for (size_t i = 0; i < nb; ++i) {
    if (br[i] < 0.001 || br[i] > m->duration_s + 0.5) continue;
    check_derivatives_at(m, br[i], &worst);
    check_derivatives_at(m, br[i] + 3.3e-3, &worst);
    check_derivatives_at(m, br[i] - 3.3e-3, &worst);
    check_continuity_at(m, br[i]);
  }
  for (double t = 0.0123; t < m->duration_s; t += grid_step_s)
    check_derivatives_at(m, t, &worst);
  free(br);
  return worst;
}

typedef struct diag_log {
  int n;
  nav_diag first;
} diag_log;

static void log_diag(void *user, const nav_diag *d) {
  diag_log *l = user;
  if (l->n == 0) l->first = *d;
  l->n++;
}

/* ------------------------------------------------------------------ building blocks */

/* Jets: derivatives of a composite expression against central differences. */
static double jet_fun(double t) {
  const double x = 1.0 + 0.3 * t + 0.1 * t * t, y = 0.5 - 0.2 * t * t * t;
  return atan2(y, x) + sqrt(x) * sin(y) + atan(x * y);
}

static nav_jet jet_fun_jet(double t) {
  const nav_jet x = nav_jet_make(1.0 + 0.3 * t + 0.1 * t * t, 0.3 + 0.2 * t, 0.2, 0.0);
  const nav_jet y = nav_jet_make(0.5 - 0.2 * t * t * t, -0.6 * t * t, -1.2 * t, -1.2);
  return nav_jet_add(nav_jet_add(nav_jet_atan2(y, x), nav_jet_mul(nav_jet_sqrt(x), nav_jet_sin(y))),
                     nav_jet_atan(nav_jet_mul(x, y)));
}

static void test_jets(void **state) {
  (void)state;
  for (double t = -0.9; t < 1.0; t += 0.37) {
    const nav_jet j = jet_fun_jet(t);
    const double h = 1e-3, h1 = 1e-5;
    const double f[5] = {jet_fun(t - 2 * h), jet_fun(t - h), jet_fun(t), jet_fun(t + h), jet_fun(t + 2 * h)};
    assert_near(j.d[0], f[2], 1e-15);
    assert_near(j.d[1], (jet_fun(t + h1) - jet_fun(t - h1)) / (2 * h1), 1e-9);
    assert_near(j.d[2], (f[3] - 2 * f[2] + f[1]) / (h * h), 1e-5);
    assert_near(j.d[3], (f[4] - 2 * f[3] + 2 * f[1] - f[0]) / (2 * h * h * h), 1e-3);
    /* cos via the chain rule too. */
    const nav_jet c = nav_jet_cos(j), s2 = nav_jet_sin(j);
    const nav_jet one = nav_jet_add(nav_jet_mul(c, c), nav_jet_mul(s2, s2));
    assert_near(one.d[0], 1.0, 1e-15);
    assert_near(one.d[1], 0.0, 1e-13);
    assert_near(one.d[2], 0.0, 1e-12);
    assert_near(one.d[3], 0.0, 1e-11);
  }
}

/* Moves: exact displacement, limits at their peaks, truncation fits the budget; a channel's
 * integral is consistent with its value. */
static void test_moves_and_channels(void **state) {
  (void)state;
  const nav_kin_lim lim = {2.0, 0.5, 2.0};
  const double deltas[] = {1e-4, 0.01, 0.3, 1.2217, 3.0, -7.0, 40.0};
  for (size_t i = 0; i < sizeof deltas / sizeof deltas[0]; ++i) {
    const nav_kin_move mv = nav_kin_plan_move(deltas[i], &lim);
    const double T = nav_kin_move_duration(&mv);
    assert_rel_near(nav_kin_move_eval(&mv, T).d[0], deltas[i], 1e-14);
    assert_rel_near(nav_kin_move_eval(&mv, T * (1.0 - 1e-12)).d[0], deltas[i], 1e-9);
    double r = 0, r1 = 0, r2 = 0;
    for (double t = 0; t <= T; t += T / 4000.0) {
      const nav_jet j = nav_kin_move_eval(&mv, t);
      r = fmax(r, fabs(j.d[1]));
      r1 = fmax(r1, fabs(j.d[2]));
      r2 = fmax(r2, fabs(j.d[3]));
    }
    assert_true(r <= lim.r_max * (1 + 1e-12));
    assert_true(r1 <= lim.d1_max * (1 + 1e-9));
    assert_true(r2 <= lim.d2_max * (1 + 1e-6));
    /* Minimum time: at least one limit is reached (to the sampling resolution). */
    assert_true(r > lim.r_max * 0.999 || r1 > lim.d1_max * 0.999 || r2 > lim.d2_max * 0.999);
    bool trunc = false;
    const nav_kin_move tm = nav_kin_plan_move_within(deltas[i], 0.5 * T, &lim, &trunc);
    assert_true(trunc);
    assert_rel_near(nav_kin_move_duration(&tm), 0.5 * T, 1e-12);
    assert_true(fabs(tm.delta) < fabs(deltas[i]));
    assert_true(tm.delta * deltas[i] > 0.0);
  }
  /* Channel: y' = x, x' = r, r' by differences. */
  nav_kin_channel c;
  nav_kin_channel_init(&c, 2.0, 0.5);
  assert_int_equal(nav_kin_channel_add_step(&c, 1.0, 0.7, 1.5), NAV_OK);
  assert_int_equal(nav_kin_channel_add_step(&c, 3.0, 1.1, -2.5), NAV_OK);
  assert_int_equal(nav_kin_channel_add_step(&c, 2.0, 1.0, 1.0), NAV_ERR_INVALID_ARG); /* overlaps */
  for (double t = -0.5; t < 6.0; t += 0.0731) {
    const double h = 1e-5;
    const nav_jet y = nav_kin_channel_eval_integral(&c, t);
    const nav_jet x = nav_kin_channel_eval(&c, t);
    assert_near(y.d[1], x.d[0], 1e-14);
    assert_near(
        x.d[0],
        (nav_kin_channel_eval_integral(&c, t + h).d[0] - nav_kin_channel_eval_integral(&c, t - h).d[0]) /
            (2 * h),
        1e-8);
    assert_near(x.d[1],
                (nav_kin_channel_eval(&c, t + h).d[0] - nav_kin_channel_eval(&c, t - h).d[0]) / (2 * h),
                1e-8);
    assert_near(x.d[2],
                (nav_kin_channel_eval(&c, t + h).d[1] - nav_kin_channel_eval(&c, t - h).d[1]) / (2 * h),
                1e-7);
  }
  assert_near(nav_kin_channel_final_rate(&c), 0.5 + 1.5 - 2.5, 1e-15);
  nav_kin_channel_free(&c);
}

/* ------------------------------------------------------------------ waypoints */

static void test_waypoints_derivatives(void **state) {
  (void)state;
  const nav_wp_attitude_mode modes[4] = {NAV_WP_ATT_GROUND, NAV_WP_ATT_AIRCRAFT, NAV_WP_ATT_EULER,
                                         NAV_WP_ATT_FIXED};
  for (int i = 0; i < 4; ++i) {
    nav_scene *s = car_figure_eight(modes[i]);
    if (modes[i] == NAV_WP_ATT_EULER)
      for (int k = 0; k < s->trajectory.waypoints.count; ++k) {
        nav_euler *e = &s->trajectory.waypoints.points[k].attitude;
        e->roll_rad = 0.05 * k * D2R;
        e->pitch_rad = (k % 3 - 1) * 2.0 * D2R;
        e->yaw_rad = remainder(170.0 * k * D2R, NAV_TWO_PI); /* crosses +/-180 deg */
      }
    s->trajectory.initial_attitude = (nav_euler){0.1, -0.2, 2.0};
    assert_int_equal(nav_scene_validate(s, NULL, NULL), NAV_OK);
    nav_traj_model m;
    create_model(s, &m);
    const mismatch w = check_model(s, &m, 0.0937);
    print_message("waypoints mode %d: %.2f s; worst |v-fd| %.2e m/s, |a-fd| %.2e m/s^2, |w-fd| %.2e rad/s, "
                  "|dw-fd| %.2e rad/s^2, skew %.2e\n",
                  (int)modes[i], m.duration_s, w.v, w.a, w.w, w.dw, w.skew);
    m.destroy(m.self);
    free(s);
  }
}

/* The path lies on the legs between the turns, passes each waypoint mid-turn on the bisector,
 * and arrival times are met in timing "time". */
static void test_waypoints_geometry_and_timing(void **state) {
  (void)state;
  nav_scene *s = car_figure_eight(NAV_WP_ATT_GROUND);
  nav_traj_model m;
  create_model(s, &m);
  const nav_traj_waypoints *W = &s->trajectory.waypoints;
  double tw[NAV_MAX_WAYPOINTS];
  assert_int_equal(nav_traj_waypoints_times(m.self, tw, NAV_MAX_WAYPOINTS), (size_t)W->count);
  assert_near(tw[0], W->hold_start_s, 0.0);
  /* Start and end exactly at the first and last waypoint (within the quadrature's rounding). */
  assert_vec3_near(kin_at(&m, 0.0).r_ned_m, W->points[0].r_ned_m, 1e-12);
  assert_vec3_near(kin_at(&m, m.duration_s).r_ned_m, W->points[W->count - 1].r_ned_m, 1e-9);
  assert_vec3_near(kin_at(&m, m.duration_s).v_ned_mps, nav_vec3_zero(), 1e-12);
  double worst_leg = 0.0;
  for (int i = 1; i + 1 < W->count; ++i) {
    /* Mid-turn: on the bisector of the corner, velocity parallel to u_prev + u_next. */
    const nav_vec3 P = W->points[i].r_ned_m;
    const nav_vec3 up = nav_vec3_sub(P, W->points[i - 1].r_ned_m),
                   un = nav_vec3_sub(W->points[i + 1].r_ned_m, P);
    const nav_vec3 bis = nav_vec3_add(nav_vec3_scale(up, 1.0 / nav_vec3_norm(up)),
                                      nav_vec3_scale(un, 1.0 / nav_vec3_norm(un)));
    const nav_local_kin k = kin_at(&m, tw[i]);
    const nav_vec3 c = nav_vec3_cross(k.v_ned_mps, bis);
    assert_true(nav_vec3_norm(c) < 1e-9 * nav_vec3_norm(k.v_ned_mps) * nav_vec3_norm(bis));
    /* Equal distances to the two legs' lines (symmetric turn). */
    const nav_vec3 rp = nav_vec3_sub(k.r_ned_m, P);
    const double d1 = nav_vec3_norm(nav_vec3_cross(rp, nav_vec3_scale(up, 1.0 / nav_vec3_norm(up))));
    const double d2 = nav_vec3_norm(nav_vec3_cross(rp, nav_vec3_scale(un, 1.0 / nav_vec3_norm(un))));
    assert_near(d1, d2, 1e-9);
    /* Halfway between the waypoint times the vehicle is on the leg (i-1, i) line. */
    const nav_local_kin q = kin_at(&m, 0.5 * (tw[i - 1] + tw[i]));
    const nav_vec3 rq = nav_vec3_sub(q.r_ned_m, W->points[i - 1].r_ned_m);
    const double off = nav_vec3_norm(nav_vec3_cross(rq, nav_vec3_scale(up, 1.0 / nav_vec3_norm(up))));
    if (off > worst_leg) worst_leg = off;
  }
  print_message("waypoint path: largest distance from the leg line at mid-leg %.2e m\n", worst_leg);
  assert_true(worst_leg < 1e-9);
  m.destroy(m.self);

  /* Timing "time": pass the waypoints at the given times (those of the speed profile, 10 %
   * slower). */
  s->trajectory.waypoints.timing = NAV_WP_TIMING_TIME;
  double times[8];
  for (int i = 0; i < 8; ++i)
    times[i] = 1.1 * (tw[i] - tw[0]);
  for (int i = 0; i < 8; ++i)
    s->trajectory.waypoints.points[i].time_s = times[i];
  create_model(s, &m);
  assert_int_equal(nav_traj_waypoints_times(m.self, tw, NAV_MAX_WAYPOINTS), 8u);
  for (int i = 0; i < 8; ++i)
    assert_near(tw[i], s->trajectory.waypoints.hold_start_s + times[i], 1e-9);
  (void)check_model(s, &m, 0.31);
  m.destroy(m.self);
  free(s);
}

/* Limits sampled every 5 ms on a level course (where turn rate = heading rate). */
static void test_waypoints_limits(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_WAYPOINTS;
  nav_traj_waypoints *W = &s->trajectory.waypoints;
  W->hold_start_s = 1.0;
  W->hold_end_s = 1.0;
  add_wp(s, 0, 0, 0, 0);
  add_wp(s, 600, 0, 0, 15);
  add_wp(s, 600, 450, 0, 8);
  add_wp(s, 150, 540, 0, 12);
  add_wp(s, 360, 900, 0, 20);
  add_wp(s, 1200, 900, 0, 0);
  const nav_traj_limits L = W->limits;
  nav_traj_model m;
  create_model(s, &m);
  double a_tan = 0, a_lat = 0, jerk = 0, rate = 0, racc = 0, V_max = 0;
  const double dt = 0.005, h = 1e-4;
  for (double t = 0.0; t <= m.duration_s; t += dt) {
    const nav_local_kin k = kin_at(&m, t);
    const double V = nav_vec3_norm(k.v_ned_mps);
    V_max = fmax(V_max, V);
    const nav_vec3 j =
        nav_vec3_scale(nav_vec3_sub(kin_at(&m, t + h).a_ned_mps2, kin_at(&m, t - h).a_ned_mps2), 0.5 / h);
    jerk = fmax(jerk, nav_vec3_norm(j));
    if (V > 1e-6) {
      const nav_vec3 tv = nav_vec3_scale(k.v_ned_mps, 1.0 / V);
      const double at = nav_vec3_dot(k.a_ned_mps2, tv);
      a_tan = fmax(a_tan, fabs(at));
      a_lat = fmax(a_lat, nav_vec3_norm(nav_vec3_axpy(k.a_ned_mps2, -at, tv)));
    }
    rate = fmax(rate, fabs(k.w_nb_b_rps.z));
    racc = fmax(racc, fabs(k.dw_nb_b_rps2.z));
  }
  print_message("waypoint limits: |a_tan| %.4f <= %.4g, |a_lat| %.4f <= %.4g, |jerk| %.4f <= %.4g, "
                "turn rate %.4f <= %.4g, turn accel %.4f <= %.4g (V max %.2f m/s, %.1f s)\n",
                a_tan, L.max_accel_mps2, a_lat, L.max_lateral_accel_mps2, jerk, L.max_jerk_mps3, rate,
                L.max_rate_rps, racc, L.max_ang_accel_rps2, V_max, m.duration_s);
  assert_true(a_tan <= L.max_accel_mps2 * (1 + 1e-9));
  assert_true(a_lat <= L.max_lateral_accel_mps2 * (1 + 1e-9));
  assert_true(jerk <= L.max_jerk_mps3 * (1 + 1e-6));
  assert_true(rate <= L.max_rate_rps * (1 + 1e-9));
  assert_true(racc <= L.max_ang_accel_rps2 * (1 + 1e-9));
  /* The limits are used, not just respected. */
  assert_true(a_tan > 0.95 * L.max_accel_mps2);
  assert_true(jerk > 0.9 * L.max_jerk_mps3);
  m.destroy(m.self);
  free(s);
}

/* Ground: heading = track angle, pitch = slope, roll = 0. Aircraft: the same with bank
 * atan(V psi_dot / g). Fixed: the initial attitude. Euler: the waypoint attitude at its time. */
static void test_attitude_modes(void **state) {
  (void)state;
  const double g = 9.80665;
  for (int mode = 0; mode < 4; ++mode) {
    nav_scene *s = car_figure_eight((nav_wp_attitude_mode)mode);
    s->trajectory.initial_attitude = (nav_euler){0.1, -0.2, 2.0};
    for (int k = 0; k < s->trajectory.waypoints.count; ++k)
      s->trajectory.waypoints.points[k].attitude =
          (nav_euler){0.02 * k, -0.01 * k, remainder(1.1 * k, NAV_TWO_PI)};
    nav_traj_model m;
    create_model(s, &m);
    double worst = 0.0, bank_max = 0.0;
    for (double t = 0.0; t <= m.duration_s; t += 0.01) {
      const nav_local_kin k = kin_at(&m, t);
      bool lock = false;
      const nav_euler e = nav_quat_to_euler(k.q_b_n, &lock);
      const nav_vec3 v = k.v_ned_mps, a = k.a_ned_mps2;
      const double vh2 = v.x * v.x + v.y * v.y;
      if (mode == NAV_WP_ATT_GROUND || mode == NAV_WP_ATT_AIRCRAFT) {
        if (vh2 < 1e-6) continue;
        const double track = atan2(v.y, v.x), slope = atan2(-v.z, sqrt(vh2));
        const double psi_dot = (v.x * a.y - v.y * a.x) / vh2;
        const double bank = mode == NAV_WP_ATT_AIRCRAFT ? atan(nav_vec3_norm(v) * psi_dot / g) : 0.0;
        bank_max = fmax(bank_max, fabs(bank));
        worst = fmax(worst, fabs(remainder(e.yaw_rad - track, NAV_TWO_PI)));
        worst = fmax(worst, fabs(e.pitch_rad - slope));
        worst = fmax(worst, fabs(e.roll_rad - bank));
      } else if (mode == NAV_WP_ATT_FIXED) {
        worst =
            fmax(worst, nav_quat_angle_between(k.q_b_n, nav_euler_to_quat(s->trajectory.initial_attitude)));
        assert_vec3_near(k.w_nb_b_rps, nav_vec3_zero(), 0.0);
      }
    }
    if (mode == NAV_WP_ATT_EULER) {
      double tw[16];
      assert_int_equal(nav_traj_waypoints_times(m.self, tw, 16), 8u);
      for (int i = 0; i < 8; ++i)
        worst = fmax(worst,
                     nav_quat_angle_between(kin_at(&m, tw[i]).q_b_n,
                                            nav_euler_to_quat(s->trajectory.waypoints.points[i].attitude)));
    }
    print_message("attitude mode %d: worst angle mismatch %.2e rad (max bank %.2f deg)\n", mode, worst,
                  bank_max * NAV_RAD2DEG);
    assert_true(worst < 1e-12);
    if (mode == NAV_WP_ATT_AIRCRAFT) assert_true(bank_max > 5.0 * D2R);
    m.destroy(m.self);
    free(s);
  }
}

/* An error message contains all of the given substrings. */
static void expect_wp_error(nav_scene *s, int bad_expected, const char *sub1, const char *sub2) {
  char msg[512];
  nav_traj_model m;
  nav_traj_script_info info;
  int bad = -2;
  assert_int_equal(nav_traj_waypoints_create(s, 0.01, &m, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  print_message("  expected error: %s\n", msg);
  if (!strstr(msg, sub1) || (sub2 && !strstr(msg, sub2)))
    fail_msg("message \"%s\" lacks \"%s\"/\"%s\"", msg, sub1, sub2);
  assert_int_equal(nav_traj_waypoints_plan_info(s, &info, &bad, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_int_equal(bad, bad_expected);
}

static nav_scene *square(double side, double speed) {
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_WAYPOINTS;
  add_wp(s, 0, 0, 0, 0);
  add_wp(s, side, 0, 0, speed);
  add_wp(s, side, side, 0, speed);
  add_wp(s, 0, side, 0, 0);
  return s;
}

/* A leg between two stops (timing speed): rise to cruise_mps, cruise, stop at the next waypoint;
 * a leg too short for the cruise speed peaks lower, with no cruise. Without cruise_mps such a leg
 * is an error that names the field. */
static void test_waypoints_between_stops(void **state) {
  (void)state;
  for (int c = 0; c < 2; ++c) {
    const double leg = c == 0 ? 400.0 : 20.0, cruise = 10.0;
    nav_scene *s = new_scene();
    s->trajectory.type = NAV_TRAJ_WAYPOINTS;
    nav_traj_waypoints *W = &s->trajectory.waypoints;
    W->hold_start_s = 2.0;
    W->hold_end_s = 1.0;
    add_wp(s, 0, 0, 0, 0);
    add_wp(s, 0.6 * leg, 0.8 * leg, 0, 0);
    if (c == 0) expect_wp_error(s, 1, "the speed is 0 at both ends of leg 0-1", "trajectory.waypoints.cruise_mps");
    W->cruise_mps = cruise;
    const nav_traj_limits L = W->limits;
    nav_traj_model m;
    create_model(s, &m);
    const double dt = 0.005, h = 1e-4;
    double V_max = 0.0, t_peak = 0.0, a_max = 0.0, jerk = 0.0, V_min = 0.0;
    for (double t = 0.0; t <= m.duration_s; t += dt) {
      const nav_local_kin k = kin_at(&m, t);
      const double V = nav_vec3_norm(k.v_ned_mps);
      /* Along the leg, never backwards. */
      const double along = (0.6 * k.v_ned_mps.x + 0.8 * k.v_ned_mps.y);
      V_min = fmin(V_min, along);
      if (V > V_max) {
        V_max = V;
        t_peak = t;
      }
      a_max = fmax(a_max, nav_vec3_norm(k.a_ned_mps2));
      const nav_vec3 j =
          nav_vec3_scale(nav_vec3_sub(kin_at(&m, t + h).a_ned_mps2, kin_at(&m, t - h).a_ned_mps2), 0.5 / h);
      jerk = fmax(jerk, nav_vec3_norm(j));
    }
    const nav_local_kin end = kin_at(&m, m.duration_s);
    const double t_mid = W->hold_start_s + 0.5 * (m.duration_s - W->hold_start_s - W->hold_end_s);
    print_message("between stops, %.0f m leg: peak %.6f m/s (cruise_mps %g), |a| %.4f <= %g, |jerk| %.4f <= %g, "
                  "motion %.3f s\n",
                  leg, V_max, cruise, a_max, L.max_accel_mps2, jerk, L.max_jerk_mps3,
                  m.duration_s - W->hold_start_s - W->hold_end_s);
    assert_vec3_near(end.r_ned_m, W->points[1].r_ned_m, 1e-9);
    assert_vec3_near(end.v_ned_mps, nav_vec3_zero(), 1e-12);
    assert_true(V_min >= -1e-12);
    assert_true(a_max <= L.max_accel_mps2 * (1 + 1e-9));
    assert_true(jerk <= L.max_jerk_mps3 * (1 + 1e-6));
    if (c == 0) {
      /* The cruise speed is reached and held: 400 m at 10 m/s with two ramps. */
      assert_near(V_max, cruise, 1e-9);
      assert_near(nav_vec3_norm(kin_at(&m, t_mid).v_ned_mps), cruise, 1e-9);
    } else {
      /* 20 m is too short for 10 m/s (each ramp of 0 -> 10 m/s covers 30 m at 2 m/s^2, 2 m/s^3): the
         peak is lower and reached at mid-leg with no cruise (still rising 0.5 s before). */
      assert_true(V_max < 0.9 * cruise && V_max > 1.0);
      assert_true(fabs(t_peak - t_mid) <= dt);
      assert_near(nav_vec3_norm(kin_at(&m, t_mid).v_ned_mps), V_max, 1e-6 * V_max);
      const double v_before = nav_vec3_norm(kin_at(&m, t_mid - 0.5).v_ned_mps);
      print_message("  speed 0.5 s before mid-leg %.6f m/s\n", v_before);
      assert_true(v_before < V_max * (1 - 1e-3));
    }
    m.destroy(m.self);
    free(s);
  }
}

static void test_waypoints_infeasible(void **state) {
  (void)state;
  nav_scene *s;
  /* Turn too tight for the legs. */
  s = square(12.0, 20.0);
  s->trajectory.waypoints.points[1].r_ned_m.x = 300.0;
  s->trajectory.waypoints.points[2].r_ned_m = nav_vec3_make(300.0, 12.0, 0.0);
  s->trajectory.waypoints.points[3].r_ned_m = nav_vec3_make(0.0, 12.0, 0.0);
  s->trajectory.waypoints.limits.max_lateral_accel_mps2 = 10.0;
  s->trajectory.waypoints.limits.max_jerk_mps3 = 50.0;
  expect_wp_error(s, 1, "waypoint 1: turn of 90 deg at 20 m/s needs radius", "but leg 1-2 is only 12 m long");
  free(s);
  /* Coincident waypoints. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.points[2].r_ned_m = s->trajectory.waypoints.points[1].r_ned_m;
  expect_wp_error(s, 2, "waypoint 2 coincides with waypoint 1", NULL);
  free(s);
  /* Speed that cannot be reached within a leg (straight course). */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.points[1].speed_mps = 30.0;
  s->trajectory.waypoints.points[2].r_ned_m = nav_vec3_make(200.0, 0.0, 0.0);
  s->trajectory.waypoints.points[3].r_ned_m = nav_vec3_make(700.0, 0.0, 0.0);
  expect_wp_error(s, 1, "waypoint 1: the speed change from 0 to 30 m/s needs", "max_accel_mps2 2");
  free(s);
  /* Reversal. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.points[2].r_ned_m = nav_vec3_make(50.0, 0.0, 0.0);
  expect_wp_error(s, 1, "waypoint 1: the path reverses direction", NULL);
  free(s);
  /* Turn at zero speed. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.points[2].speed_mps = 0.0;
  expect_wp_error(s, 2, "waypoint 2: a turn of 90 deg needs speed > 0", NULL);
  free(s);
  /* Too many / too few waypoints. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.count = NAV_MAX_WAYPOINTS + 1;
  expect_wp_error(s, -1, "needs 2 to 1000 waypoints (got 1001)", NULL);
  s->trajectory.waypoints.count = 1;
  expect_wp_error(s, -1, "needs 2 to 1000 waypoints (got 1)", NULL);
  free(s);
  /* Hold with a moving start. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.points[0].speed_mps = 3.0;
  s->trajectory.waypoints.hold_start_s = 5.0;
  expect_wp_error(s, 0, "waypoint 0: hold_start_s 5 s needs speed 0", NULL);
  free(s);
  /* Arrival time that cannot be met. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.timing = NAV_WP_TIMING_TIME;
  const double times[4] = {0.0, 5.0, 40.0, 60.0};
  for (int i = 0; i < 4; ++i)
    s->trajectory.waypoints.points[i].time_s = times[i];
  expect_wp_error(s, 1, "waypoint 1: time_s 5 s cannot be met", "max_accel_mps2");
  free(s);
  /* Attitude profile beyond the limits. */
  s = square(100.0, 10.0);
  s->trajectory.waypoints.points[0].speed_mps = 10.0;
  s->trajectory.waypoints.points[1].r_ned_m = nav_vec3_make(20.0, 0.0, 0.0);
  s->trajectory.waypoints.points[2].r_ned_m = nav_vec3_make(40.0, 0.0, 0.0);
  s->trajectory.waypoints.points[3].r_ned_m = nav_vec3_make(500.0, 0.0, 0.0);
  s->trajectory.waypoints.attitude_mode = NAV_WP_ATT_EULER;
  s->trajectory.waypoints.points[1].attitude.roll_rad = 1.0;
  expect_wp_error(s, 1, "waypoint 1: the roll change of 57.3 deg from waypoint 0 in 2 s needs max_rate_rps 1",
                  "but the limit is 0.5");
  free(s);
  /* Too steep for the ground mode. */
  s = square(100.0, 5.0);
  s->trajectory.waypoints.points[1].r_ned_m.z = -1000.0;
  expect_wp_error(s, 1, "leg 0-1 climbs at", "undefined beyond 80 deg");
  free(s);
}

/* Field-range validation with YAML field paths. */
typedef struct issue_log {
  int n;
  char path[8][128];
} issue_log;

static void log_issue(void *user, const char *path, const char *message) {
  issue_log *l = user;
  (void)message;
  if (l->n < 8) snprintf(l->path[l->n], sizeof l->path[0], "%s", path);
  l->n++;
}

static void test_scene_validate(void **state) {
  (void)state;
  nav_scene *s = square(100.0, 5.0);
  issue_log log = {0, {{0}}};
  assert_int_equal(nav_scene_validate(s, log_issue, &log), NAV_OK);
  s->trajectory.waypoints.points[3].speed_mps = -1.0;
  s->trajectory.waypoints.limits.max_jerk_mps3 = 0.0;
  assert_int_equal(nav_scene_validate(s, log_issue, &log), NAV_ERR_INVALID_ARG);
  assert_int_equal(log.n, 2);
  assert_string_equal(log.path[0], "trajectory.waypoints.limits.max_jerk_mps3");
  assert_string_equal(log.path[1], "trajectory.waypoints.points[3].speed_mps");
  s->trajectory.type = NAV_TRAJ_SEGMENTS;
  s->trajectory.segments.count = 1;
  s->trajectory.segments.items[0].kind = NAV_SEG_CIRCLE;
  s->trajectory.segments.items[0].radius_m = -2.0;
  log.n = 0;
  assert_int_equal(nav_scene_validate(s, log_issue, &log), NAV_ERR_INVALID_ARG);
  assert_int_equal(log.n, 1);
  assert_string_equal(log.path[0], "trajectory.segments.items[0].radius_m");
  /* The scene stays plain data well under 1 MB. */
  assert_true(sizeof(nav_scene) < 512 * 1024);
  free(s);
}

/* ------------------------------------------------------------------ segment scripts */

/* Every kind in one script: a ground start, then flight manoeuvres with coordinated turns. */
static nav_scene *all_kinds_script(void) {
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_SEGMENTS;
  s->trajectory.initial_attitude = (nav_euler){0.0, 0.0, 30.0 * D2R};
  nav_segment *g;
  g = add_seg(s, NAV_SEG_HOLD);
  g->duration_s = 3.0;
  g = add_seg(s, NAV_SEG_ACCELERATE);
  g->speed_mps = 12.0;
  g = add_seg(s, NAV_SEG_TURN);
  g->yaw_rad = 90.0 * D2R;
  g->yaw_rate_rps = 0.3;
  /* gnss-ins-sim type 1 with step changes of turn rate, smoothed by centred ramps. */
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->yaw_rate_rps = 10.0 * D2R;
  g->duration_s = 3.0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->yaw_rate_rps = -5.0 * D2R;
  g->accel_b_mps2 = nav_vec3_make(0.5, 0.0, 0.0);
  g->duration_s = 4.0;
  g = add_seg(s, NAV_SEG_MOTION_REL_ABS);
  g->yaw_rad = -40.0 * D2R;
  g->v_b_mps = nav_vec3_make(20.0, 0.0, 0.0);
  g->duration_s = 60.0;
  g = add_seg(s, NAV_SEG_CLIMB);
  g->height_m = 60.0;
  g->pitch_rad = 8.0 * D2R;
  g = add_seg(s, NAV_SEG_COORD_TURN);
  g->yaw_rad = -120.0 * D2R;
  g->yaw_rate_rps = 0.2;
  g = add_seg(s, NAV_SEG_CIRCLE);
  g->radius_m = 150.0;
  g->turns = 1.0;
  g->coordinated = true;
  g = add_seg(s, NAV_SEG_FIGURE_EIGHT);
  g->radius_m = 120.0;
  g->turns = 1.0;
  g->coordinated = true;
  g = add_seg(s, NAV_SEG_HELIX);
  g->radius_m = 200.0;
  g->turns = 1.5;
  g->pitch_rad = 5.0 * D2R;
  g->coordinated = true;
  g = add_seg(s, NAV_SEG_LAWNMOWER);
  g->legs = 4;
  g->length_m = 300.0;
  g->spacing_m = 100.0;
  g->coordinated = true;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->roll_rate_rps = 5.0 * D2R;
  g->pitch_rate_rps = -1.0 * D2R;
  g->duration_s = 4.0;
  g = add_seg(s, NAV_SEG_MOTION_ABS_ABS);
  g->yaw_rad = 10.0 * D2R;
  g->v_b_mps = nav_vec3_make(15.0, 1.0, 0.0);
  g->duration_s = 60.0;
  g = add_seg(s, NAV_SEG_MOTION_REL_REL);
  g->pitch_rad = 3.0 * D2R;
  g->v_b_mps = nav_vec3_make(-2.0, -1.0, 0.0);
  g->duration_s = 60.0;
  g = add_seg(s, NAV_SEG_MOTION_ABS_REL);
  g->yaw_rad = 0.0;
  g->pitch_rad = 0.0;
  g->v_b_mps = nav_vec3_make(-13.0, 0.0, 0.0);
  g->duration_s = 60.0;
  g = add_seg(s, NAV_SEG_HOLD);
  g->duration_s = 2.0;
  return s;
}

static void test_segments_derivatives(void **state) {
  (void)state;
  nav_scene *s = all_kinds_script();
  assert_int_equal(nav_scene_validate(s, NULL, NULL), NAV_OK);
  nav_traj_model m;
  create_model(s, &m);
  const mismatch w = check_model(s, &m, 0.0731);
  print_message("segments: %.2f s; worst |v-fd| %.2e m/s, |a-fd| %.2e m/s^2, |w-fd| %.2e rad/s, |dw-fd| %.2e "
                "rad/s^2, skew %.2e\n",
                m.duration_s, w.v, w.a, w.w, w.dw, w.skew);
  /* Position is the integral of the analytic velocity: compare r(t) - r(0) with an independent
   * composite 16-point Gauss-Legendre integration on 0.05 s pieces (which straddle the model's
   * checkpoints and breaks, so it is only accurate to ~1e-9 m there). */
  {
    double x[16], wgt[16];
    assert_int_equal(nav_gauss_legendre(16, x, wgt), NAV_OK);
    nav_vec3 r = kin_at(&m, 0.0).r_ned_m;
    double worst = 0.0, w_max = 0.0, dw_max = 0.0;
    const double hp = 0.05;
    for (int i = 0; (i + 1) * hp <= m.duration_s; ++i) {
      const double a = i * hp, mid = a + 0.5 * hp;
      for (int j = 0; j < 16; ++j)
        r = nav_vec3_axpy(r, 0.5 * hp * wgt[j], kin_at(&m, mid + 0.5 * hp * x[j]).v_ned_mps);
      const nav_local_kin k = kin_at(&m, a + hp);
      worst = fmax(worst, nav_vec3_norm(nav_vec3_sub(r, k.r_ned_m)));
      w_max = fmax(w_max, nav_vec3_norm(k.w_nb_b_rps));
      dw_max = fmax(dw_max, nav_vec3_norm(k.dw_nb_b_rps2));
    }
    print_message(
        "segments: position vs independent quadrature of v over %.0f s: %.2e m; max |w_nb_b| %.3f rad/s, "
        "max |dw_nb_b| %.3f rad/s^2\n",
        m.duration_s, worst, w_max, dw_max);
    assert_true(worst < 1e-6);
    /* Euler rates <= 2 rad/s and Euler accelerations <= 0.5 rad/s^2 per axis bound the body rate
     * and angular acceleration (E3.4; with the coordinated-bank limits). */
    assert_true(w_max <= 2.0 * sqrt(3.0));
    assert_true(dw_max <= 2.0);
  }
  /* Every segment boundary: the state carries over (continuity checked above); the script ends
   * at rest, level. */
  const nav_local_kin e = kin_at(&m, m.duration_s);
  assert_vec3_near(e.v_ned_mps, nav_vec3_zero(), 1e-12);
  assert_vec3_near(e.w_nb_b_rps, nav_vec3_zero(), 1e-12);
  bool lock = false;
  const nav_euler eu = nav_quat_to_euler(e.q_b_n, &lock);
  /* The last manoeuvre (type 4) sets the absolute attitude (0, 0, 0). */
  assert_near(eu.pitch_rad, 0.0, 1e-12);
  assert_near(eu.roll_rad, 0.0, 1e-12);
  assert_near(eu.yaw_rad, 0.0, 1e-12);
  m.destroy(m.self);
  free(s);
}

/* Segment semantics: hold, accelerate, turn by an angle, climb to a height, circle closes,
 * lawnmower spacing, coordinated bank. */
static void test_segments_semantics(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_SEGMENTS;
  nav_segment *g;
  g = add_seg(s, NAV_SEG_HOLD);
  g->duration_s = 5.0;
  g = add_seg(s, NAV_SEG_ACCELERATE);
  g->speed_mps = 25.0;
  g = add_seg(s, NAV_SEG_CLIMB);
  g->height_m = 100.0;
  g->pitch_rad = 10.0 * D2R;
  g = add_seg(s, NAV_SEG_CIRCLE);
  g->radius_m = 250.0;
  g->turns = 1.0;
  g->coordinated = true;
  g = add_seg(s, NAV_SEG_LAWNMOWER);
  g->legs = 3;
  g->length_m = 200.0;
  g->spacing_m = -150.0;
  nav_traj_model m;
  create_model(s, &m);
  double B[8];
  assert_int_equal(nav_traj_segments_boundaries(m.self, B, 8), 6u);
  /* Hold: at rest for 5 s. */
  assert_near(B[1], 5.0, 0.0);
  assert_vec3_near(kin_at(&m, 4.0).v_ned_mps, nav_vec3_zero(), 0.0);
  /* Accelerate: 25 m/s at its end, with the limits of the defaults (1 m/s^2, 2 m/s^3). */
  assert_near(nav_vec3_norm(kin_at(&m, B[2]).v_ned_mps), 25.0, 1e-12);
  assert_near(B[2] - B[1], 25.0 + 2.1875 / 2.0, 1e-9);
  /* Climb: exactly 100 m up, level again. */
  assert_near(kin_at(&m, B[2]).r_ned_m.z - kin_at(&m, B[3]).r_ned_m.z, 100.0, 1e-8);
  assert_near(kin_at(&m, B[3]).v_ned_mps.z, 0.0, 1e-12);
  /* Circle: one full turn brings the heading back; coordinated bank atan(V w / g) mid-circle. */
  const nav_local_kin c0 = kin_at(&m, B[3]), c1 = kin_at(&m, B[4]), cm = kin_at(&m, 0.5 * (B[3] + B[4]));
  assert_vec3_near(c1.v_ned_mps, c0.v_ned_mps, 1e-9);
  bool lock = false;
  const nav_euler em = nav_quat_to_euler(cm.q_b_n, &lock);
  const double wz = (cm.v_ned_mps.x * cm.a_ned_mps2.y - cm.v_ned_mps.y * cm.a_ned_mps2.x) /
                    (cm.v_ned_mps.x * cm.v_ned_mps.x + cm.v_ned_mps.y * cm.v_ned_mps.y);
  assert_near(wz, 25.0 / 250.0, 1e-9); /* cruise turn rate V / R */
  assert_near(em.roll_rad, atan(25.0 * wz / s->earth.flat_gravity_mps2), 1e-12);
  /* Lawnmower: legs 150 m apart (to the left), antiparallel. */
  const nav_local_kin l0 = kin_at(&m, B[4] + 1.0);
  const nav_vec3 u0 = nav_vec3_scale(l0.v_ned_mps, 1.0 / nav_vec3_norm(l0.v_ned_mps));
  const double t_leg = 200.0 / 25.0;
  /* Middle of the second leg: find it as the mean of the turn ends from the boundaries. */
  const double t_turn = (B[5] - B[4] - 3.0 * t_leg) / 2.0;
  const nav_local_kin l1 = kin_at(&m, B[4] + t_leg + t_turn + 1.0);
  assert_vec3_near(nav_vec3_scale(l1.v_ned_mps, 1.0 / 25.0), nav_vec3_scale(u0, -1.0), 1e-9);
  const nav_vec3 d = nav_vec3_sub(l1.r_ned_m, l0.r_ned_m);
  const nav_vec3 left = nav_vec3_make(u0.y, -u0.x, 0.0); /* NED: left of the track */
  assert_near(nav_vec3_dot(d, left), 150.0, 1e-6);
  print_message(
      "segments semantics: durations hold %.3f, accelerate %.3f, climb %.3f, circle %.3f, lawnmower %.3f s\n",
      B[1] - B[0], B[2] - B[1], B[3] - B[2], B[4] - B[3], B[5] - B[4]);
  m.destroy(m.self);

  /* Type-1 rate steps: centred ramps integrate to the steps, so outside the ramp windows the
   * heading is exactly that of the step profile (here +30 deg, -20 deg: 10 deg at the end). */
  s->trajectory.segments.count = 0;
  s->trajectory.segments.v0_b_mps = nav_vec3_make(10.0, 0.0, 0.0);
  g = add_seg(s, NAV_SEG_HOLD);
  g->duration_s = 1.0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->yaw_rate_rps = 10.0 * D2R;
  g->duration_s = 3.0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->yaw_rate_rps = -5.0 * D2R;
  g->duration_s = 4.0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->duration_s = 5.0;
  create_model(s, &m);
  assert_near(m.duration_s, 13.0, 0.0);
  const double checks[3][2] = {{0.5, 0.0}, {2.5, 15.0}, {12.5, 10.0}}; /* (t, yaw deg) outside the ramps */
  for (int i = 0; i < 3; ++i) {
    const nav_euler e = nav_quat_to_euler(kin_at(&m, checks[i][0]).q_b_n, &lock);
    assert_near(e.yaw_rad, checks[i][1] * D2R, 1e-13);
  }
  m.destroy(m.self);
  free(s);
}

static void expect_seg_error(nav_scene *s, int bad_expected, const char *sub1, const char *sub2) {
  char msg[512];
  nav_traj_model m;
  nav_traj_script_info info;
  int bad = -2;
  assert_int_equal(nav_traj_segments_create(s, 0.01, &m, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  print_message("  expected error: %s\n", msg);
  if (!strstr(msg, sub1) || (sub2 && !strstr(msg, sub2)))
    fail_msg("message \"%s\" lacks \"%s\"/\"%s\"", msg, sub1, sub2);
  assert_int_equal(nav_traj_segments_plan_info(s, &info, &bad, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_int_equal(bad, bad_expected);
}

static void test_segments_infeasible(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_SEGMENTS;
  nav_segment *g = add_seg(s, NAV_SEG_HOLD);
  g->duration_s = 1.0;
  g = add_seg(s, NAV_SEG_MOTION_REL_ABS);
  g->v_b_mps.x = 10.0;
  g->duration_s = 5.0;
  /* Type 5 that cannot converge in its duration (strict script). */
  expect_seg_error(s, 1, "segment 1 (motion type 5): a body-x velocity change of 10 m/s needs",
                   "max_accel_mps2 1");
  /* gnss-ins-sim's rule: ends unconverged, reported. */
  s->trajectory.segments.allow_unconverged = true;
  nav_traj_script_info info;
  int bad = -2;
  char msg[512];
  assert_int_equal(nav_traj_segments_plan_info(s, &info, &bad, msg, sizeof msg), NAV_OK);
  assert_int_equal(info.unconverged, 1);
  assert_int_equal(info.first_unconverged, 1);
  s->trajectory.segments.allow_unconverged = false;
  /* Step in turn rate whose ramp does not fit in a short type-1 segment. */
  s->trajectory.segments.count = 0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->duration_s = 10.0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->yaw_rate_rps = 0.5;
  g->duration_s = 1.0;
  g = add_seg(s, NAV_SEG_MOTION_RATES);
  g->duration_s = 10.0;
  expect_seg_error(s, 1, "segment 1 (motion type 1): its rate-step ramps need", "max_ang_accel_rps2 0.5");
  s->trajectory.segments.fit_rate_ramps = true;
  assert_int_equal(nav_traj_segments_plan_info(s, &info, &bad, msg, sizeof msg), NAV_OK);
  assert_int_equal(info.shortened_ramps, 2);
  print_message("  fitted ramps: largest Euler-angle acceleration %.3f rad/s^2\n",
                info.max_ramp_ang_accel_rps2);
  s->trajectory.segments.fit_rate_ramps = false;
  /* Turn faster than the limits; circle needing too much lateral acceleration; lawnmower too tight. */
  s->trajectory.segments.count = 0;
  s->trajectory.segments.v0_b_mps = nav_vec3_make(30.0, 0, 0);
  g = add_seg(s, NAV_SEG_TURN);
  g->yaw_rad = 1.0;
  g->yaw_rate_rps = 3.0;
  expect_seg_error(s, 0, "segment 0 (turn): turn rate 171.9 deg/s exceeds max_rate_rps 2", NULL);
  g->kind = NAV_SEG_CIRCLE;
  g->radius_m = 50.0;
  g->turns = 1.0;
  expect_seg_error(s, 0, "segment 0 (circle): turn rate",
                   "needs lateral acceleration 18 m/s^2 but max_lateral_accel_mps2 is 10");
  g->kind = NAV_SEG_LAWNMOWER;
  g->legs = 3;
  g->length_m = 100.0;
  g->spacing_m = 20.0;
  expect_seg_error(s, 0, "segment 0 (lawnmower): a U-turn at 30 m/s spans at least", "but spacing_m is 20");
  g->kind = NAV_SEG_CLIMB;
  g->height_m = 2.0;
  g->pitch_rad = 20.0 * D2R;
  expect_seg_error(
      s, 0, "segment 0 (climb): a height change of 2 m at flight-path angle 20 deg needs at least", NULL);
  s->trajectory.segments.v0_b_mps = nav_vec3_zero();
  g->kind = NAV_SEG_CIRCLE;
  expect_seg_error(s, 0, "segment 0 (circle): needs forward speed", NULL);
  s->trajectory.segments.count = NAV_MAX_SEGMENTS + 1;
  expect_seg_error(s, -1, "needs 1 to 2000 segments (got 2001)", NULL);
  free(s);
}

/* ------------------------------------------------------------------ motion definitions */

static void test_motiondef_long_drive(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  s->earth.model = NAV_EARTH_WGS84;
  diag_log log = {0, {{0}, 0, 0, {0}, {0}}};
  assert_int_equal(nav_motiondef_read_file(LONG_DRIVE, s, log_diag, &log), NAV_OK);
  assert_int_equal(log.n, 0);
  assert_int_equal(s->trajectory.type, NAV_TRAJ_SEGMENTS);
  assert_int_equal(s->trajectory.segments.count, 58);
  assert_int_equal(s->earth.model, NAV_EARTH_WGS84); /* kept */
  assert_near(s->earth.origin_lat_rad, 31.508183 * D2R, 1e-15);
  assert_near(s->earth.origin_lon_rad, 120.401989 * D2R, 1e-15);
  assert_near(s->earth.origin_h_m, 0.0, 0.0);
  assert_near(s->trajectory.initial_attitude.yaw_rad, -177.0 * D2R, 1e-14);
  assert_int_equal(s->trajectory.segments.items[0].kind, NAV_SEG_MOTION_RATES);
  assert_near(s->trajectory.segments.items[0].duration_s, 200.0, 0.0);
  assert_int_equal(s->trajectory.segments.items[2].kind, NAV_SEG_MOTION_REL_ABS);
  assert_near(s->trajectory.segments.items[2].yaw_rad, -70.0 * D2R, 1e-15);
  assert_near(s->trajectory.segments.items[2].v_b_mps.x, 5.0, 0.0);
  assert_int_equal(s->trajectory.segments.items[11].kind, NAV_SEG_MOTION_REL_REL);
  assert_true(s->trajectory.segments.allow_unconverged);
  assert_true(s->trajectory.segments.fit_rate_ramps);
  {
    /* gnss-ins-sim's high_mobility, equal to the segment defaults. */
    const nav_traj_limits a = s->trajectory.segments.limits;
    const nav_traj_limits b = nav_scene_default().trajectory.segments.limits;
    assert_near(a.max_accel_mps2, 1.0, 0.0);
    assert_near(a.max_ang_accel_rps2, 0.5, 0.0);
    assert_near(a.max_rate_rps, 2.0, 0.0);
    assert_memory_equal(&a, &b, sizeof a);
  }
  assert_int_equal(nav_scene_validate(s, NULL, NULL), NAV_OK);
  nav_script_summary sum;
  char msg[256];
  assert_int_equal(nav_motiondef_script_summary(s, &sum, msg, sizeof msg), NAV_OK);
  print_message(
      "long drive: %d commands, 1410 s commanded, %.3f s planned (gnss-ins-sim: 965.18 s); %d unconverged "
      "(first: command %d), %d shortened ramps, largest ramp Euler acceleration %.3f rad/s^2\n",
      sum.items, sum.duration_s, sum.unconverged, sum.first_unconverged, sum.shortened_ramps,
      sum.max_ramp_ang_accel_rps2);
  assert_near(sum.duration_s, s->trajectory.duration_s, 0.0);
  assert_true(sum.duration_s > 700.0 && sum.duration_s < 1410.0);
  /* The start state matches the file: at rest at the origin, yaw 183 deg. */
  nav_traj *tr = NULL;
  assert_int_equal(nav_traj_create(s, 0.005, &tr), NAV_OK);
  nav_traj_state st0;
  assert_int_equal(nav_traj_eval(tr, 0.0, &st0), NAV_OK);
  const nav_frame fr = nav_traj_frame(tr);
  const nav_local_view v0 = nav_frame_view(&fr, st0.r_fb_f_m, st0.v_fb_f_mps, st0.q_b_f);
  assert_near(v0.pos.lat_rad, 31.508183 * D2R, 1e-14);
  assert_near(v0.pos.lon_rad, 120.401989 * D2R, 1e-14);
  assert_near(v0.pos.h_m, 0.0, 1e-6);
  assert_vec3_near(v0.v_n_mps, nav_vec3_zero(), 0.0);
  assert_quat_near(v0.q_b_n, nav_euler_to_quat((nav_euler){0.0, 0.0, 183.0 * D2R}), 1e-12);
  nav_traj_destroy(tr);

  /* Limits over the whole drive (level drive: yaw rate = w_z, along-track acceleration = u'). */
  nav_traj_model m;
  s->earth.model = NAV_EARTH_FLAT;
  create_model(s, &m);
  double a_max = 0, j_max = 0, w_max = 0, dw_max = 0;
  const double h = 1e-4;
  for (double t = 0.0; t <= m.duration_s; t += 0.005) {
    const nav_local_kin k = kin_at(&m, t);
    const double V = nav_vec3_norm(k.v_ned_mps);
    double at = 0.0, jt = 0.0;
    if (V > 1e-9) {
      at = nav_vec3_dot(k.a_ned_mps2, k.v_ned_mps) / V;
      const nav_local_kin kp = kin_at(&m, t + h), km = kin_at(&m, t - h);
      jt = (nav_vec3_dot(kp.a_ned_mps2, kp.v_ned_mps) / nav_vec3_norm(kp.v_ned_mps) -
            nav_vec3_dot(km.a_ned_mps2, km.v_ned_mps) / nav_vec3_norm(km.v_ned_mps)) /
           (2 * h);
    }
    a_max = fmax(a_max, fabs(at));
    j_max = fmax(j_max, fabs(jt));
    w_max = fmax(w_max, fabs(k.w_nb_b_rps.z));
    dw_max = fmax(dw_max, fabs(k.dw_nb_b_rps2.z));
  }
  print_message("long drive limits: |u'| %.4f m/s^2 (1), |u''| %.4f m/s^3 (2), |yaw rate| %.4f rad/s (2), "
                "|yaw accel| %.4f rad/s^2 (0.5)\n",
                a_max, j_max, w_max, dw_max);
  assert_true(a_max <= 1.0 + 1e-9);
  assert_true(j_max <= 2.0 * (1 + 1e-6));
  assert_true(w_max <= 2.0);
  assert_true(dw_max <= 0.5 * (1 + 1e-9));
  const mismatch w = check_model(s, &m, 0.5);
  print_message("long drive derivatives: |v-fd| %.2e, |a-fd| %.2e, |w-fd| %.2e, |dw-fd| %.2e, skew %.2e\n",
                w.v, w.a, w.w, w.dw, w.skew);
  m.destroy(m.self);
  free(s);
}

static void expect_md_error(const char *text, int line, int col, const char *path, const char *sub) {
  nav_scene *s = new_scene();
  diag_log log = {0, {{0}, 0, 0, {0}, {0}}};
  const nav_status st = nav_motiondef_read_string(text, strlen(text), "t.csv", s, log_diag, &log);
  assert_int_equal(st, NAV_ERR_PARSE);
  assert_true(log.n >= 1);
  char buf[1400];
  nav_diag_format(&log.first, buf, sizeof buf);
  print_message("  expected diagnostic: %s\n", buf);
  assert_int_equal(log.first.line, line);
  assert_int_equal(log.first.col, col);
  assert_string_equal(log.first.path, path);
  if (!strstr(log.first.message, sub)) fail_msg("message \"%s\" lacks \"%s\"", log.first.message, sub);
  assert_int_equal(s->trajectory.type, NAV_TRAJ_PARAMETRIC); /* untouched */
  free(s);
}

#define MD_HEAD                                                                                              \
  "ini lat (deg),ini lon (deg),ini alt (m),ini vx_body (m/s),ini vy_body (m/s),ini vz_body (m/s),ini yaw "   \
  "(deg),ini pitch (deg),ini roll (deg)\n"
#define MD_INIT "32,120,0,0,0,0,0,0,0\n"
#define MD_CMDH                                                                                              \
  "command type,yaw (deg),pitch (deg),roll (deg),vx_body (m/s),vy_body (m/s),vz_body (m/s),command "         \
  "duration (s),GPS visibility\n"

static void test_motiondef_errors(void **state) {
  (void)state;
  expect_md_error(MD_HEAD MD_INIT MD_CMDH "1,0,0,0,0,0,0,10,1\n1,0,0,x,0,0,0,10,1\n", 5, 7,
                  "trajectory.segments.items[1].roll_rate_rps", "expected a finite number, got \"x\"");
  expect_md_error(MD_HEAD MD_INIT MD_CMDH "1,0,0,0,0,0,0,10\n", 4, 17, "",
                  "expected 9 comma-separated values, found 8");
  expect_md_error(MD_HEAD MD_INIT MD_CMDH "7,0,0,0,0,0,0,10,1\n", 4, 1, "trajectory.segments.items[0].kind",
                  "command type must be 1, 2, 3, 4 or 5 (got 7)");
  expect_md_error(MD_HEAD MD_INIT MD_CMDH "1,0,0,0,0,0,0,-3,1\n", 4, 15,
                  "trajectory.segments.items[0].duration_s", "command duration must be >= 0 s");
  expect_md_error(MD_HEAD "95,120,0,0,0,0,0,0,0\n" MD_CMDH "1,0,0,0,0,0,0,10,1\n", 2, 1,
                  "earth.origin.lat_deg", "latitude must be within [-90, 90] deg");
  expect_md_error(MD_INIT MD_CMDH, 1, 1, "", "expected the header of the initial state");
  expect_md_error(MD_HEAD MD_INIT MD_CMDH, 3, 1, "", "the file ends before any command");
  /* A command the planner rejects is reported at its line with the planner's message. */
  expect_md_error(MD_HEAD MD_INIT MD_CMDH "1,0,0,0,0,0,0,10,1\n1,0,0,0,0,0,0,2e7,1\n", 5, 1,
                  "trajectory.segments.items[1]", "duration_s must be within [0, 1e+07] s");
  /* CRLF, blank lines and radians headers are accepted. */
  nav_scene *s = new_scene();
  const char *ok = MD_HEAD "\r\n32,120,5,1,0,0,90,0,0\r\n"
                           "command type,yaw (rad),pitch (rad),roll (rad),vx,vy,vz,duration,reserved\r\n"
                           "1,0.1,0,0,0,0,0,10,0\r\n\r\n";
  diag_log log = {0, {{0}, 0, 0, {0}, {0}}};
  assert_int_equal(nav_motiondef_read_string(ok, strlen(ok), "ok.csv", s, log_diag, &log), NAV_OK);
  assert_near(s->trajectory.segments.items[0].yaw_rate_rps, 0.1, 0.0);
  assert_false(s->trajectory.segments.items[0].gnss_visible);
  assert_near(s->trajectory.duration_s, 10.0, 1e-12);
  assert_near(s->trajectory.segments.v0_b_mps.x, 1.0, 0.0);
  assert_near(s->earth.origin_h_m, 5.0, 0.0);
  /* Missing file. */
  log.n = 0;
  assert_int_equal(nav_motiondef_read_file(NAV_SOURCE_DIR "/no/such/file.csv", s, log_diag, &log),
                   NAV_ERR_IO);
  assert_int_equal(log.n, 1);
  free(s);
}

/* Every shipped gnss-ins-sim profile with at most NAV_MAX_SEGMENTS commands imports. */
static void test_motiondef_all_files(void **state) {
  (void)state;
  static const char *const files[] = {"motion_def-0to100.csv",
                                      "motion_def-0to100_sample_by_sample.csv",
                                      "motion_def-100to0.csv",
                                      "motion_def-3d.csv",
                                      "motion_def-90deg_turn.csv",
                                      "motion_def-Allan.csv",
                                      "motion_def-Holland_tunnel.csv",
                                      "motion_def-ins.csv",
                                      "motion_def-long_drive.csv",
                                      "motion_def-static.csv",
                                      "motion_def.csv",
                                      "motion_def_mag_cal.csv"};
  nav_scene *s = new_scene();
  for (size_t i = 0; i < sizeof files / sizeof files[0]; ++i) {
    char path[512];
    snprintf(path, sizeof path, "%s/resources/motion_defs/%s", NAV_SOURCE_DIR, files[i]);
    *s = nav_scene_default();
    diag_log log = {0, {{0}, 0, 0, {0}, {0}}};
    const nav_status st = nav_motiondef_read_file(path, s, log_diag, &log);
    if (st != NAV_OK) {
      char buf[1400];
      nav_diag_format(&log.first, buf, sizeof buf);
      fail_msg("%s: %s", files[i], buf);
    }
    nav_script_summary sum;
    char msg[256];
    assert_int_equal(nav_motiondef_script_summary(s, &sum, msg, sizeof msg), NAV_OK);
    print_message("  %-40s %4d commands, %8.3f s, %d unconverged, %d shortened ramps\n", files[i], sum.items,
                  sum.duration_s, sum.unconverged, sum.shortened_ramps);
  }
  /* The Komatsu profiles (one command per sample) exceed NAV_MAX_SEGMENTS: a clear error. */
  diag_log log = {0, {{0}, 0, 0, {0}, {0}}};
  assert_int_equal(nav_motiondef_read_file(
                       NAV_SOURCE_DIR "/resources/motion_defs/motion_def-Komatsu_loaded_-5_0.csv", s,
                       log_diag, &log),
                   NAV_ERR_PARSE);
  assert_non_null(strstr(log.first.message, "at most 2000"));
  free(s);
}

/* ------------------------------------------------------------------ closure */

typedef struct closure {
  double pos_h_m, pos_v_m, vel_mps, att_rad, max_pos_h_m;
} closure;

/* Ideal IMU + strapdown over the whole scene; errors at the end. */
static closure run_closure(const nav_scene *s, nav_ins_config cfg, bool aid_vertical) {
  nav_truth *truth = NULL;
  nav_ins *ins = NULL;
  char msg[256];
  closure c = {0, 0, 0, 0, 0};
  if (nav_truth_create_msg(s, &truth, msg, sizeof msg) != NAV_OK) fail_msg("truth: %s", msg);
  nav_traj_state ts;
  assert_int_equal(nav_truth_state(truth, 0.0, &ts), NAV_OK);
  nav_ins_state s0 = {0.0, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f};
  assert_int_equal(nav_ins_create(&cfg, &s0, &ins), NAV_OK);
  const nav_frame fr = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  for (int64_t k = 1; k <= n; ++k) {
    nav_imu_increment imu;
    assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
    assert_int_equal(nav_ins_step(ins, &imu), NAV_OK);
    if (aid_vertical || k % 200 == 0 || k == n) {
      assert_int_equal(nav_truth_state(truth, imu.t_s, &ts), NAV_OK);
      if (aid_vertical) {
        const nav_local_view v = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
        assert_int_equal(nav_ins_aid_vertical(ins, v.pos.h_m, v.v_n_mps.z), NAV_OK);
      }
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

static void test_closure_flat(void **state) {
  (void)state;
  nav_ins_config cfg = nav_ins_config_default();
  cfg.algorithm = NAV_MECH_HIGH_ORDER;
  /* Waypoint car (ground) at 100 Hz. */
  nav_scene *s = car_figure_eight(NAV_WP_ATT_AIRCRAFT);
  s->navigation.algorithm = NAV_MECH_HIGH_ORDER;
  nav_script_summary sum;
  char msg[256];
  assert_int_equal(nav_motiondef_script_summary(s, &sum, msg, sizeof msg), NAV_OK);
  s->trajectory.duration_s = sum.duration_s;
  closure c = run_closure(s, cfg, false);
  print_message(
      "flat closure, waypoint figure-eight (aircraft attitude), %.1f s at 100 Hz, high order: pos %.2e m "
      "(max %.2e), vel %.2e m/s, att %.2e rad\n",
      sum.duration_s, c.pos_h_m + c.pos_v_m, c.max_pos_h_m, c.vel_mps, c.att_rad);
  assert_true(c.pos_h_m < 1e-4 && c.pos_v_m < 1e-4 && c.vel_mps < 1e-5 && c.att_rad < 1e-7);
  free(s);
  /* Segment script with every kind at 100 Hz. */
  s = all_kinds_script();
  assert_int_equal(nav_motiondef_script_summary(s, &sum, msg, sizeof msg), NAV_OK);
  s->trajectory.duration_s = sum.duration_s;
  c = run_closure(s, cfg, false);
  print_message("flat closure, all-kinds segment script, %.1f s at 100 Hz, high order: pos h %.2e m v %.2e m "
                "(max h %.2e), vel %.2e m/s, att %.2e rad\n",
                sum.duration_s, c.pos_h_m, c.pos_v_m, c.max_pos_h_m, c.vel_mps, c.att_rad);
  assert_true(c.pos_h_m < 1e-3 && c.pos_v_m < 1e-3 && c.vel_mps < 1e-5 && c.att_rad < 1e-7);
  free(s);
}

/* The long drive on flat Earth at 200 Hz, algorithm high_order. */
static void test_closure_flat_long_drive(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  assert_int_equal(nav_motiondef_read_file(LONG_DRIVE, s, NULL, NULL), NAV_OK);
  s->earth.model = NAV_EARTH_FLAT;
  s->imu.rate_hz = 200.0;
  s->navigation.algorithm = NAV_MECH_HIGH_ORDER;
  nav_ins_config cfg = nav_ins_config_default();
  cfg.algorithm = NAV_MECH_HIGH_ORDER;
  const closure c = run_closure(s, cfg, false);
  print_message(
      "flat closure, long drive, %.2f s at 200 Hz, high order: pos h %.3e m (max %.3e), v %.3e m, vel "
      "%.2e m/s, att %.2e rad\n",
      s->trajectory.duration_s, c.pos_h_m, c.max_pos_h_m, c.pos_v_m, c.vel_mps, c.att_rad);
  assert_true(c.pos_h_m < 1e-3);
  free(s);
}

/* numerics / issue target: the WGS-84 long drive closes to <= 1 mm horizontally. */
static void test_closure_wgs84_long_drive(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  s->earth.model = NAV_EARTH_WGS84;
  assert_int_equal(nav_motiondef_read_file(LONG_DRIVE, s, NULL, NULL), NAV_OK);
  s->imu.rate_hz = 200.0;
  s->navigation.algorithm = NAV_MECH_HIGH_ORDER;
  const nav_mech_frame frames[2] = {NAV_MECH_NED, NAV_MECH_ECEF};
  for (int i = 0; i < 2; ++i) {
    nav_ins_config cfg = nav_ins_config_default();
    cfg.earth_model = NAV_EARTH_WGS84;
    cfg.algorithm = NAV_MECH_HIGH_ORDER;
    cfg.mech_frame = frames[i];
    cfg.gravity_model = s->earth.gravity_model;
    nav_ins *probe = NULL;
    const nav_ins_state z = {0.0, nav_vec3_make(NAV_WGS84_A_M, 0, 0), nav_vec3_zero(), nav_quat_identity()};
    if (nav_ins_create(&cfg, &z, &probe) != NAV_OK) {
      print_message("WGS-84 mechanization (%s) not available yet: skipped\n", nav_mech_frame_name(frames[i]));
      free(s);
      skip();
    }
    nav_ins_destroy(probe);
    const closure c = run_closure(s, cfg, false);
    print_message(
        "WGS-84 closure, long drive, %s, %.2f s at 200 Hz, high order: pos h %.3e m (max %.3e), v %.3e m, "
        "vel %.2e m/s, att %.2e rad\n",
        nav_mech_frame_name(frames[i]), s->trajectory.duration_s, c.pos_h_m, c.max_pos_h_m, c.pos_v_m,
        c.vel_mps, c.att_rad);
    assert_true(c.pos_h_m <= 1e-3);
  }
  free(s);
}

/* ------------------------------------------------------------------ stops (hold_s) */

/* A car with three interior stops (hold_s): one on a straight line, one at a right-angle corner
 * (turned in place during the hold) and one where the path reverses (turned in place by 180 deg),
 * and a last leg between two stops (cruise_mps). */
static nav_scene *car_with_stops(nav_wp_attitude_mode mode) {
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_WAYPOINTS;
  nav_traj_waypoints *w = &s->trajectory.waypoints;
  w->attitude_mode = mode;
  w->hold_start_s = 2.0;
  w->hold_end_s = 3.0;
  w->cruise_mps = 5.0;
  add_wp(s, 0, 0, 0, 0);
  add_wp(s, 100, 0, 0, 8);
  add_wp(s, 200, 0, 0, 0); /* stop, straight on */
  w->points[2].hold_s = 5.0;
  add_wp(s, 300, 0, -2, 0); /* stop at a corner (and a slope before it) */
  w->points[3].hold_s = 10.0;
  add_wp(s, 300, 150, -2, 7);
  add_wp(s, 300, 300, -2, 0); /* stop and turn back */
  w->points[5].hold_s = 12.0;
  add_wp(s, 300, 200, -2, 0);
  return s;
}

static void test_waypoints_stops(void **state) {
  (void)state;
  const nav_wp_attitude_mode modes[3] = {NAV_WP_ATT_GROUND, NAV_WP_ATT_AIRCRAFT, NAV_WP_ATT_EULER};
  for (int mi = 0; mi < 3; ++mi) {
    nav_scene *s = car_with_stops(modes[mi]);
    const nav_traj_waypoints *W = &s->trajectory.waypoints;
    if (modes[mi] == NAV_WP_ATT_EULER)
      for (int k = 0; k < W->count; ++k)
        s->trajectory.waypoints.points[k].attitude =
            (nav_euler){0.02 * k, -0.01 * k, remainder(1.3 * k, NAV_TWO_PI)};
    assert_int_equal(nav_scene_validate(s, NULL, NULL), NAV_OK);
    nav_traj_model m;
    create_model(s, &m);
    const mismatch mm = check_model(s, &m, 0.0937);
    double tw[NAV_MAX_WAYPOINTS];
    assert_int_equal(nav_traj_waypoints_times(m.self, tw, NAV_MAX_WAYPOINTS), (size_t)W->count);
    print_message(
        "stops, mode %d: %.3f s; arrivals %.3f %.3f %.3f s; worst |v-fd| %.2e, |a-fd| %.2e, |w-fd| %.2e, "
        "|dw-fd| %.2e\n",
        (int)modes[mi], m.duration_s, tw[2], tw[3], tw[5], mm.v, mm.a, mm.w, mm.dw);
    /* At rest on the waypoint for the whole hold, moving just outside it. */
    for (int i = 2; i <= 5; ++i) {
      const double hold = W->points[i].hold_s;
      if (!(hold > 0.0)) continue;
      double att_change = 0.0;
      const nav_local_kin k0 = kin_at(&m, tw[i]);
      for (double t = tw[i]; t <= tw[i] + hold; t += 0.01) {
        const nav_local_kin k = kin_at(&m, t);
        assert_vec3_near(k.r_ned_m, W->points[i].r_ned_m, 1e-6);
        assert_vec3_near(k.v_ned_mps, nav_vec3_zero(), 1e-12);
        assert_vec3_near(k.a_ned_mps2, nav_vec3_zero(), 1e-12);
        att_change = fmax(att_change, nav_quat_angle_between(k.q_b_n, k0.q_b_n));
      }
      assert_true(nav_vec3_norm(kin_at(&m, tw[i] - 0.5).v_ned_mps) > 1e-3);
      assert_true(nav_vec3_norm(kin_at(&m, tw[i] + hold + 0.5).v_ned_mps) > 1e-3);
      const nav_local_kin k1 = kin_at(&m, tw[i] + hold);
      print_message("  stop %d: %.1f s at rest, attitude turned %.2f deg in place\n", i, hold,
                    nav_quat_angle_between(k1.q_b_n, k0.q_b_n) / D2R);
      if (modes[mi] == NAV_WP_ATT_GROUND) {
        /* Arrives with the heading of the leg before, leaves with that of the leg after. */
        const nav_vec3 a = nav_vec3_sub(W->points[i].r_ned_m, W->points[i - 1].r_ned_m);
        const nav_vec3 b = nav_vec3_sub(W->points[i + 1].r_ned_m, W->points[i].r_ned_m);
        const nav_euler e0 = nav_quat_to_euler(k0.q_b_n, NULL), e1 = nav_quat_to_euler(k1.q_b_n, NULL);
        assert_near(remainder(e0.yaw_rad - atan2(a.y, a.x), NAV_TWO_PI), 0.0, 1e-9);
        assert_near(remainder(e1.yaw_rad - atan2(b.y, b.x), NAV_TWO_PI), 0.0, 1e-9);
      }
      if (modes[mi] == NAV_WP_ATT_EULER) {
        /* The attitude is held at the stop. */
        assert_true(att_change < 1e-12);
      }
    }
    /* Each second added to every hold adds exactly one second per stop. */
    nav_scene *s2 = car_with_stops(modes[mi]);
    if (modes[mi] == NAV_WP_ATT_EULER)
      for (int k = 0; k < W->count; ++k)
        s2->trajectory.waypoints.points[k].attitude = W->points[k].attitude;
    for (int i = 1; i + 1 < s2->trajectory.waypoints.count; ++i)
      if (s2->trajectory.waypoints.points[i].hold_s > 0.0) s2->trajectory.waypoints.points[i].hold_s += 1.0;
    nav_traj_script_info info;
    char msg[512];
    assert_int_equal(nav_traj_waypoints_plan_info(s2, &info, NULL, msg, sizeof msg), NAV_OK);
    assert_near(info.duration_s - m.duration_s, 3.0, 1e-9);
    free(s2);
    m.destroy(m.self);
    free(s);
  }
}

/* Timing time with a stop: time_s is the arrival, the next leg starts after hold_s. */
static void test_waypoints_stops_timed(void **state) {
  (void)state;
  nav_scene *s = new_scene();
  s->trajectory.type = NAV_TRAJ_WAYPOINTS;
  nav_traj_waypoints *W = &s->trajectory.waypoints;
  W->timing = NAV_WP_TIMING_TIME;
  W->hold_start_s = 1.0;
  add_wp(s, 0, 0, 0, 0);
  add_wp(s, 150, 0, 0, 0);
  add_wp(s, 150, 150, 0, 0);
  add_wp(s, 300, 150, 0, 0);
  W->points[1].time_s = 25.0;
  W->points[2].time_s = 60.0; /* arrives at 60 s, leaves at 68 s */
  W->points[2].hold_s = 8.0;
  W->points[3].time_s = 100.0;
  nav_traj_model m;
  create_model(s, &m);
  double tw[NAV_MAX_WAYPOINTS];
  assert_int_equal(nav_traj_waypoints_times(m.self, tw, NAV_MAX_WAYPOINTS), 4u);
  for (int i = 0; i < 4; ++i)
    assert_near(tw[i], W->hold_start_s + W->points[i].time_s, 1e-6);
  assert_near(m.duration_s, 101.0, 1e-6);
  for (double t = tw[2]; t <= tw[2] + 8.0; t += 0.05)
    assert_vec3_near(kin_at(&m, t).v_ned_mps, nav_vec3_zero(), 1e-12);
  m.destroy(m.self);

  /* Errors: a hold with a speed, a hold on the first waypoint, a hold too short to turn in place. */
  W->timing = NAV_WP_TIMING_SPEED;
  W->cruise_mps = 5.0;
  W->points[1].speed_mps = 5.0;
  W->points[2].speed_mps = 3.0;
  expect_wp_error(s, 2, "waypoint 2: hold_s 8 s needs speed 0", NULL);
  W->points[2].speed_mps = 0.0;
  W->points[2].hold_s = 0.5;
  expect_wp_error(s, 2, "turning 90 deg in place takes", "longer than hold_s 0.5 s");
  W->points[2].hold_s = 8.0;
  W->points[0].hold_s = 1.0;
  expect_wp_error(s, 0, "hold_s is for interior waypoints", "hold_start_s");
  free(s);
}

static void test_closure_stops(void **state) {
  (void)state;
  nav_ins_config cfg = nav_ins_config_default();
  cfg.algorithm = NAV_MECH_HIGH_ORDER;
  const nav_wp_attitude_mode modes[2] = {NAV_WP_ATT_GROUND, NAV_WP_ATT_AIRCRAFT};
  for (int mi = 0; mi < 2; ++mi) {
    nav_scene *s = car_with_stops(modes[mi]);
    s->navigation.algorithm = NAV_MECH_HIGH_ORDER;
    nav_script_summary sum;
    char msg[256];
    assert_int_equal(nav_motiondef_script_summary(s, &sum, msg, sizeof msg), NAV_OK);
    s->trajectory.duration_s = sum.duration_s;
    const closure c = run_closure(s, cfg, false);
    print_message(
        "flat closure, waypoints with 3 stops (mode %d), %.1f s at 100 Hz, high order: pos h %.2e m v "
        "%.2e m (max h %.2e), vel %.2e m/s, att %.2e rad\n",
        (int)modes[mi], sum.duration_s, c.pos_h_m, c.pos_v_m, c.max_pos_h_m, c.vel_mps, c.att_rad);
    assert_true(c.pos_h_m < 1e-4 && c.pos_v_m < 1e-4 && c.vel_mps < 1e-5 && c.att_rad < 1e-7);
    free(s);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_jets),
      cmocka_unit_test(test_moves_and_channels),
      cmocka_unit_test(test_waypoints_derivatives),
      cmocka_unit_test(test_waypoints_geometry_and_timing),
      cmocka_unit_test(test_waypoints_limits),
      cmocka_unit_test(test_attitude_modes),
      cmocka_unit_test(test_waypoints_infeasible),
      cmocka_unit_test(test_waypoints_between_stops),
      cmocka_unit_test(test_scene_validate),
      cmocka_unit_test(test_segments_derivatives),
      cmocka_unit_test(test_segments_semantics),
      cmocka_unit_test(test_segments_infeasible),
      cmocka_unit_test(test_motiondef_long_drive),
      cmocka_unit_test(test_motiondef_errors),
      cmocka_unit_test(test_motiondef_all_files),
      cmocka_unit_test(test_closure_flat),
      cmocka_unit_test(test_closure_flat_long_drive),
      cmocka_unit_test(test_closure_wgs84_long_drive),
      cmocka_unit_test(test_waypoints_stops),
      cmocka_unit_test(test_waypoints_stops_timed),
      cmocka_unit_test(test_closure_stops),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
