/*
 * Numerical guards of the INS/GNSS filter in the hard cases (issue 10): tiny and huge noise,
 * cm-level RTK updates on a filter started with metres of uncertainty, 180 deg initial heading
 * uncertainty, and all of them at once. After every predict and update the covariance must be
 * finite, exactly symmetric (the filter symmetrises it) and positive definite (our own Cholesky
 * here, independent of the filter's), and the state finite - or the call must return
 * NAV_ERR_NUMERIC with a message, leaving the previous P intact. Never a silent NaN.
 *
 * The end-to-end part runs the same hard cases as scenes through nav_sim (INS/GNSS Monte Carlo):
 * the run either completes with finite statistics or reports NAV_ERR_NUMERIC naming the time.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_filter.h"
#include "navcore/nav_io.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sim.h"

#define NMAX 24

typedef struct hard_case {
  const char *name;
  nav_filter_config cfg;
  double fix_dt_s;  /* GNSS fix interval */
  double pos_sd_m;  /* measurement noise of the fixes */
  double vel_sd_mps;
  double duration_s;
  double dt_s; /* IMU interval */
  bool turning; /* heading rate, so the 180 deg heading uncertainty becomes observable */
} hard_case;

/* Cholesky of an n x n symmetric matrix; false if not positive definite. Independent of the
 * filter's own factorisation. */
static bool spd(const double *P, size_t n, double *min_pivot_rel) {
  double L[NMAX * NMAX];
  double worst = INFINITY;
  for (size_t j = 0; j < n; ++j) {
    double d = P[j * n + j];
    for (size_t k = 0; k < j; ++k) d -= L[j * n + k] * L[j * n + k];
    if (!(d > 0.0) || !isfinite(d)) return false;
    const double rel = d / P[j * n + j];
    if (rel < worst) worst = rel;
    L[j * n + j] = sqrt(d);
    for (size_t i = j + 1; i < n; ++i) {
      double s = P[i * n + j];
      for (size_t k = 0; k < j; ++k) s -= L[i * n + k] * L[j * n + k];
      L[i * n + j] = s / L[j * n + j];
    }
  }
  *min_pivot_rel = worst;
  return true;
}

typedef struct guard_stats {
  long predicts, updates, numeric_errors;
  double min_pivot_rel;
  double max_pos_sd_m, min_pos_sd_m;
  double final_heading_sd_rad;
} guard_stats;

/* P finite, exactly symmetric, positive definite; x finite. */
static void check_filter(const nav_filter *kf, size_t n, const char *what, double t, guard_stats *gs) {
  const double *P = nav_filter_get_cov(kf);
  const double *x = nav_filter_get_state(kf);
  for (size_t i = 0; i < n; ++i) {
    if (!isfinite(x[i])) fail_msg("%s: x[%zu] = %g at t = %.3f s (silent non-finite state)", what, i, x[i], t);
    for (size_t j = 0; j < n; ++j) {
      if (!isfinite(P[i * n + j])) fail_msg("%s: P[%zu][%zu] = %g at t = %.3f s", what, i, j, P[i * n + j], t);
      if (P[i * n + j] != P[j * n + i])
        fail_msg("%s: P not symmetric at t = %.3f s: P[%zu][%zu] = %.17g, P[%zu][%zu] = %.17g", what, t, i, j,
                 P[i * n + j], j, i, P[j * n + i]);
    }
  }
  double piv = 0.0;
  if (!spd(P, n, &piv)) fail_msg("%s: P is not positive definite at t = %.3f s", what, t);
  if (piv < gs->min_pivot_rel) gs->min_pivot_rel = piv;
  const double sd = sqrt(P[0]);
  if (sd > gs->max_pos_sd_m) gs->max_pos_sd_m = sd;
  if (sd < gs->min_pos_sd_m) gs->min_pos_sd_m = sd;
}

/* A NAV_ERR_NUMERIC must come with a message and leave a valid P. */
static void on_status(nav_status st, const nav_filter *kf, size_t n, const char *what, double t, guard_stats *gs) {
  if (st == NAV_OK) return;
  if (st != NAV_ERR_NUMERIC)
    fail_msg("%s: status %s at t = %.3f s: %s", what, nav_status_str(st), t, nav_filter_last_error(kf));
  const char *msg = nav_filter_last_error(kf);
  if (!msg || !msg[0]) fail_msg("%s: NAV_ERR_NUMERIC without a message at t = %.3f s", what, t);
  ++gs->numeric_errors;
  check_filter(kf, n, what, t, gs); /* "x and P unchanged": still valid */
}

static void run_case(const hard_case *hc, guard_stats *gs) {
  memset(gs, 0, sizeof *gs);
  gs->min_pivot_rel = INFINITY;
  gs->min_pos_sd_m = INFINITY;
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_config_validate(&hc->cfg, NULL, NULL), NAV_OK);
  assert_int_equal(nav_filter_create(&hc->cfg, &kf), NAV_OK);
  const size_t n = nav_filter_get_layout(kf).n_states;
  assert_true(n <= NMAX);
  nav_rng rng;
  nav_rng_init(&rng, 42, 0, 0);
  const double lat = 45.0 * NAV_DEG2RAD;
  const long steps = lround(hc->duration_s / hc->dt_s);
  const long fix_every = lround(hc->fix_dt_s / hc->dt_s);
  const double g = 9.80665;
  check_filter(kf, n, hc->name, 0.0, gs);
  for (long k = 1; k <= steps; ++k) {
    const double t = (double)k * hc->dt_s;
    /* A vehicle at 10 m/s, turning at 10 deg/s when asked (a circle), level. */
    const double yaw = hc->turning ? 10.0 * NAV_DEG2RAD * t : 0.0;
    const double wz = hc->turning ? 10.0 * NAV_DEG2RAD : 0.0;
    nav_filter_nav nav;
    memset(&nav, 0, sizeof nav);
    nav.lat_rad = lat;
    nav.h_m = 100.0;
    nav.v_eb_n_mps = nav_vec3_make(10.0 * cos(yaw), 10.0 * sin(yaw), 0.0);
    nav.C_b_n = nav_euler_to_dcm((nav_euler){0.0, 0.0, yaw});
    nav.f_ib_b_mps2 = nav_vec3_make(0.0, 10.0 * wz, -g);
    nav.w_ib_b_rps = nav_vec3_make(0.0, 0.0, wz);
    nav_status st = nav_filter_predict(kf, &nav, hc->dt_s);
    ++gs->predicts;
    on_status(st, kf, n, hc->name, t, gs);
    check_filter(kf, n, hc->name, t, gs);
    if (k % fix_every == 0) {
      const nav_vec3 zp = nav_vec3_scale(nav_rng_gauss_vec3(&rng), hc->pos_sd_m);
      const nav_vec3 rp = nav_vec3_make(hc->pos_sd_m * hc->pos_sd_m, hc->pos_sd_m * hc->pos_sd_m,
                                        hc->pos_sd_m * hc->pos_sd_m);
      st = nav_filter_update_gnss_pos(kf, &nav, zp, &rp, nav_vec3_make(0.5, 0.0, -1.0));
      ++gs->updates;
      on_status(st, kf, n, hc->name, t, gs);
      check_filter(kf, n, hc->name, t, gs);
      if (hc->vel_sd_mps > 0.0) {
        const nav_vec3 zv = nav_vec3_scale(nav_rng_gauss_vec3(&rng), hc->vel_sd_mps);
        const double v2 = hc->vel_sd_mps * hc->vel_sd_mps;
        const nav_vec3 rv = nav_vec3_make(v2, v2, v2);
        st = nav_filter_update_gnss_vel(kf, &nav, zv, &rv, nav_vec3_make(0.5, 0.0, -1.0));
        ++gs->updates;
        on_status(st, kf, n, hc->name, t, gs);
        check_filter(kf, n, hc->name, t, gs);
      }
      /* Closed loop: the INS absorbs the estimate. */
      assert_int_equal(nav_filter_reset_errors(kf), NAV_OK);
    }
  }
  const double *P = nav_filter_get_cov(kf);
  gs->final_heading_sd_rad = sqrt(P[(NAV_FILTER_IDX_PHI + 2) * n + NAV_FILTER_IDX_PHI + 2]);
  printf("%-28s %ld predicts, %ld updates, %ld NAV_ERR_NUMERIC; position sd %.3g .. %.3g m, final heading sd "
         "%.3g deg, smallest Cholesky pivot ratio %.3g\n",
         hc->name, gs->predicts, gs->updates, gs->numeric_errors, gs->min_pos_sd_m, gs->max_pos_sd_m,
         gs->final_heading_sd_rad * NAV_RAD2DEG, gs->min_pivot_rel);
  nav_filter_destroy(kf);
}

static nav_vec3 v3(double a) { return nav_vec3_make(a, a, a); }

static hard_case base_case(const char *name) {
  hard_case hc;
  memset(&hc, 0, sizeof hc);
  hc.name = name;
  hc.cfg = nav_filter_config_default();
  hc.fix_dt_s = 1.0;
  hc.pos_sd_m = 1.0;
  hc.vel_sd_mps = 0.05;
  hc.duration_s = 120.0;
  hc.dt_s = 0.01;
  return hc;
}

static void test_tiny_noise(void **state) {
  (void)state;
  hard_case hc = base_case("tiny noise");
  hc.cfg.gyro_arw_rad_per_sqrt_s = v3(1e-12);
  hc.cfg.accel_vrw_mps_per_sqrt_s = v3(1e-12);
  hc.cfg.gyro_bias_gm_sd_rps = v3(1e-14);
  hc.cfg.accel_bias_gm_sd_mps2 = v3(1e-12);
  hc.cfg.init.pos_sd_m = v3(1e-4);
  hc.cfg.init.vel_sd_mps = v3(1e-6);
  hc.cfg.init.att_sd_rad = v3(1e-9);
  hc.cfg.init.gyro_bias_sd_rps = v3(1e-14);
  hc.cfg.init.accel_bias_sd_mps2 = v3(1e-12);
  hc.pos_sd_m = 1e-4;
  hc.vel_sd_mps = 1e-6;
  guard_stats gs;
  run_case(&hc, &gs);
  assert_true(gs.min_pos_sd_m > 0.0);
}

static void test_huge_noise(void **state) {
  (void)state;
  hard_case hc = base_case("huge noise");
  hc.cfg.gyro_arw_rad_per_sqrt_s = v3(0.1);
  hc.cfg.accel_vrw_mps_per_sqrt_s = v3(10.0);
  hc.cfg.gyro_bias_gm_sd_rps = v3(0.1);
  hc.cfg.accel_bias_gm_sd_mps2 = v3(5.0);
  hc.cfg.init.pos_sd_m = v3(1e4);
  hc.cfg.init.vel_sd_mps = v3(100.0);
  hc.cfg.init.att_sd_rad = v3(1.0);
  hc.cfg.init.gyro_bias_sd_rps = v3(0.1);
  hc.cfg.init.accel_bias_sd_mps2 = v3(5.0);
  hc.pos_sd_m = 100.0;
  hc.vel_sd_mps = 10.0;
  guard_stats gs;
  run_case(&hc, &gs);
}

static void test_rtk_cm(void **state) {
  (void)state;
  /* A tactical IMU started with 10 m / 1 m/s / 5 deg uncertainty, RTK at 10 Hz: 1 cm, 5 mm/s. */
  hard_case hc = base_case("cm-level RTK");
  hc.cfg.init.pos_sd_m = v3(10.0);
  hc.cfg.init.vel_sd_mps = v3(1.0);
  hc.cfg.init.att_sd_rad = v3(5.0 * NAV_DEG2RAD);
  hc.fix_dt_s = 0.1;
  hc.pos_sd_m = 0.01;
  hc.vel_sd_mps = 0.005;
  hc.turning = true;
  guard_stats gs;
  run_case(&hc, &gs);
  /* The fixes pin the position to the cm level (not a tolerance: the filter's own steady state
     must lie below the measurement sigma with 10 Hz fixes). */
  const nav_filter_config *c = &hc.cfg;
  (void)c;
  assert_true(gs.min_pos_sd_m < hc.pos_sd_m);
}

static void test_heading_180(void **state) {
  (void)state;
  hard_case hc = base_case("180 deg heading sd");
  hc.cfg.init.att_sd_rad = nav_vec3_make(1.0 * NAV_DEG2RAD, 1.0 * NAV_DEG2RAD, NAV_PI);
  hc.turning = true;
  guard_stats gs;
  run_case(&hc, &gs);
  /* The turn makes heading observable: the filter must have reduced it. */
  assert_true(gs.final_heading_sd_rad < NAV_PI);
}

static void test_all_at_once(void **state) {
  (void)state;
  /* Extremes together: 180 deg heading, km-level P0, RTK updates, tiny process noise, 24 states. */
  hard_case hc = base_case("all at once (24 states)");
  hc.cfg.states = NAV_FILTER_STATE_SCALE_FACTORS | NAV_FILTER_STATE_GNSS_POS_GM;
  hc.cfg.gyro_arw_rad_per_sqrt_s = v3(1e-10);
  hc.cfg.accel_vrw_mps_per_sqrt_s = v3(1e-10);
  hc.cfg.init.pos_sd_m = v3(1e3);
  hc.cfg.init.vel_sd_mps = v3(10.0);
  hc.cfg.init.att_sd_rad = nav_vec3_make(0.1, 0.1, NAV_PI);
  hc.cfg.gnss_pos_gm_sd_m = v3(0.01);
  hc.fix_dt_s = 0.1;
  hc.pos_sd_m = 0.01;
  hc.vel_sd_mps = 0.005;
  hc.turning = true;
  guard_stats gs;
  run_case(&hc, &gs);
}

/* ---------------------------------------------------------------- end to end */

static void ignore_diag(void *user, const nav_diag *d) {
  char buf[2048];
  nav_diag_format(d, buf, sizeof buf);
  fprintf(stderr, "%s\n", buf);
  (void)user;
}

/* An INS/GNSS Monte Carlo run of @p yaml (then @p tweak, if any, applied to the scene read):
 * completes with finite statistics, or reports NAV_ERR_NUMERIC with the time in its message. */
static void run_scene(const char *name, const char *yaml, void (*tweak)(nav_scene *)) {
  nav_scene sc;
  assert_int_equal(nav_scene_read_string(yaml, strlen(yaml), name, &sc, ignore_diag, NULL), NAV_OK);
  if (tweak) tweak(&sc);
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = 2;
  nav_sim_summary sum;
  const nav_status st = nav_sim_run(sim, &o, &sum);
  if (st == NAV_OK) {
    const double v[] = {sum.stats.pos_err_h_m.rms, sum.stats.pos_err_v_m.rms, sum.stats.vel_err_mps.rms,
                        sum.stats.att_err_rad.rms, sum.final_rms.pos_err_h_m, sum.final.pos_err_h_m};
    for (size_t i = 0; i < sizeof v / sizeof *v; ++i)
      if (!isfinite(v[i])) fail_msg("%s: statistic %zu is %g after NAV_OK (silent non-finite)", name, i, v[i]);
    printf("%-28s %ld runs: horizontal RMS %.4g m, final RMS %.4g m, yaw RMS %.4g deg\n", name, sum.runs,
           sum.stats.pos_err_h_m.rms, sum.final_rms.pos_err_h_m, sum.stats.yaw_err_rad.rms * NAV_RAD2DEG);
  } else {
    if (st != NAV_ERR_NUMERIC) fail_msg("%s: %s: %s", name, nav_status_str(st), nav_sim_last_error(sim));
    const char *msg = nav_sim_last_error(sim);
    if (!strstr(msg, "t =")) fail_msg("%s: NAV_ERR_NUMERIC without the time: \"%s\"", name, msg);
    printf("%-28s NAV_ERR_NUMERIC: %s\n", name, msg);
  }
  nav_sim_destroy(sim);
}

#define SCENE_HEAD                                                                                     \
  "format_version: 1\n"                                                                                \
  "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 200}}\n"                               \
  "trajectory:\n"                                                                                      \
  "  type: waypoints\n"                                                                                \
  "  initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 0}\n"                                      \
  "  waypoints:\n"                                                                                     \
  "    timing: speed\n"                                                                                \
  "    attitude_mode: ground\n"                                                                        \
  "    points:\n"                                                                                      \
  "      - {ned_m: [0, 0, 0], speed_mps: 10}\n"                                                        \
  "      - {ned_m: [200, 0, 0], speed_mps: 10}\n"                                                      \
  "      - {ned_m: [200, 200, 0], speed_mps: 10}\n"                                                    \
  "      - {ned_m: [0, 200, 0], speed_mps: 10}\n"                                                      \
  "navigation: {scheme: ins_gnss, algorithm: high_order, frame: ned}\n"                                \
  "output: {rate_hz: 10}\n"                                                                            \
  "simulation: {seed: 3, runs: 8}\n"

static void test_scene_heading_180_rtk(void **state) {
  (void)state;
  run_scene("scene: 180 deg heading, RTK",
            SCENE_HEAD "imu:\n  rate_hz: 100\n  catalog: \"Safran Sensonor STIM300\"\n"
                       "gnss:\n  enabled: true\n  update_rate_hz: 10\n  position_white_sigma_m: [0.01, 0.01, 0.02]\n"
                       "  reported_sigma: {position_m: [0.01, 0.01, 0.02], velocity_mps: [0.01, 0.01, 0.01]}\n"
                       "initial_errors: {position_m: [1, 1, 1], velocity_mps: 0.1, attitude_deg: [1, 1, 180]}\n",
            NULL);
}

/* Noise above what a scene file may give (navcore/io/scene_bounds.h: ARW <= 100 deg/sqrt(h), VRW
 * <= 10 m/s/sqrt(h)): ARW 500 deg/sqrt(h) and VRW 1 m/s/sqrt(s), set on the scene read as a
 * program using the library may, with the reader's own unit factors. */
static void huge_noise(nav_scene *sc) {
  sc->imu.model.gyro.arw_rad_per_sqrt_s = v3(500.0 * (NAV_DEG2RAD / 60.0));
  sc->imu.model.accel.vrw_mps_per_sqrt_s = v3(1.0);
}

static void test_scene_huge_noise(void **state) {
  (void)state;
  run_scene("scene: huge noise",
            SCENE_HEAD "imu:\n  rate_hz: 100\n  gyro: {arw_deg_per_sqrt_h: 100, bias_turn_on_deg_per_h: 10000}\n"
                       "  accel: {vrw_mps_per_sqrt_s: 0.1, bias_turn_on_mg: 500}\n"
                       "gnss:\n  enabled: true\n  update_rate_hz: 1\n  position_white_sigma_m: [50, 50, 100]\n"
                       "  reported_sigma: {position_m: [50, 50, 100], velocity_mps: [1, 1, 1]}\n"
                       "initial_errors: {position_m: [100, 100, 100], velocity_mps: 10, attitude_deg: [10, 10, 180]}\n",
            huge_noise);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tiny_noise),
      cmocka_unit_test(test_huge_noise),
      cmocka_unit_test(test_rtk_cm),
      cmocka_unit_test(test_heading_180),
      cmocka_unit_test(test_all_at_once),
      cmocka_unit_test(test_scene_heading_180_rtk),
      cmocka_unit_test(test_scene_huge_noise),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
