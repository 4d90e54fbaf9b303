/*
 * Error budget (nav_budget.h): on an INS/GNSS scene with an outage and every kind of source,
 * the per-source variances add up to the total of the full model within 1e-9 relative at every
 * epoch and for every requirement, and the total is the covariance analysis of the simulation
 * (nav_sim_covariance); on a free INS, a Monte Carlo with the gyro turn-on bias alone agrees with
 * that source's share of the full budget within the chi-square band of the mean square.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_budget.h"
#include "navcore/nav_io.h"
#include "navcore/nav_sim.h"

static const char k_ins_gnss[] =
    "format_version: 1\n"
    "name: budget-ins-gnss\n"
    "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 200}}\n"
    "trajectory:\n"
    "  type: segments\n"
    "  initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 30}\n"
    "  segments:\n"
    "    r0_ned_m: [0, 0, 0]\n"
    "    v0_b_mps: [10, 0, 0]\n"
    "    limits: {max_accel_mps2: 2, max_jerk_mps3: 2, max_lateral_accel_mps2: 3,\n"
    "             max_rate_dps: 20, max_ang_accel_dps2: 20, max_ang_jerk_dps3: 60}\n"
    "    items:\n"
    "      - {kind: hold, duration_s: 20}\n"
    "      - {kind: turn, yaw_deg: 90}\n"
    "      - {kind: hold, duration_s: 30}\n"
    "imu:\n"
    "  rate_hz: 100\n"
    "  catalog: \"Xsens MTi-300\"\n"
    "  gyro: {bias_turn_on_deg_per_h: 100, rrw_deg_per_h_per_sqrt_h: 20}\n"
    "  accel: {bias_turn_on_mg: 1}\n"
    "gnss:\n"
    "  enabled: true\n"
    "  catalog: \"SBAS (WAAS/EGNOS class)\"\n"
    "  position_white_sigma_m: [0.3, 0.3, 0.5]\n"
    "  lever_arm_b_m: [0.5, 0.2, -1]\n"
    "  outages: [[25, 40]]\n"
    "initial_errors: {position_m: [2, 2, 4], velocity_mps: 0.1, attitude_deg: [0.5, 0.5, 2]}\n"
    "navigation: {scheme: ins_gnss, algorithm: high_order}\n"
    "output: {rate_hz: 10}\n"
    "requirements:\n"
    "  - {id: h-end, metric: horizontal_position, statistic: outage_end, limit: 5, unit: m}\n"
    "  - {id: h-rms, metric: horizontal_position, statistic: rms, limit: 5, unit: m}\n"
    "  - {id: v-p95, metric: vertical_position, statistic: p95, limit: 5, unit: m}\n"
    "  - {id: vel, metric: velocity, statistic: rms, limit: 1, unit: m/s}\n"
    "  - {id: yaw-30, metric: yaw, statistic: at_time, time_s: 30, limit: 1, unit: deg}\n"
    "  - {id: rp, metric: roll_pitch, statistic: max, limit: 1, unit: deg}\n"
    "  - {id: p3, metric: position_3d, statistic: rms, limit: 9, unit: m}\n";

static void print_diag(void *user, const nav_diag *d) {
  (void)user;
  char line[1200];
  nav_diag_format(d, line, sizeof line);
  print_message("%s\n", line);
}

static nav_scene *read_scene(const char *text) {
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_string(text, strlen(text), "budget.yaml", sc, print_diag, NULL), NAV_OK);
  return sc;
}

typedef struct sum_check {
  long epochs;
  double worst_rel; /* largest |sum of sources - total| / total over epochs and diagonal entries */
  nav_budget_epoch last;
} sum_check;

static nav_callback_result on_epoch(void *user, const nav_budget_epoch *e) {
  sum_check *c = user;
  for (int i = 0; i < 9; ++i) {
    double s = 0.0;
    for (int k = 0; k < NAV_BUDGET_SOURCE_COUNT; ++k) s += e->source[k].v[i];
    const double rel = fabs(s - e->total.v[i]) / e->total.v[i];
    if (!(rel <= c->worst_rel)) c->worst_rel = rel; /* NaN propagates as a failure */
  }
  c->epochs++;
  c->last = *e;
  return NAV_CONTINUE;
}

typedef struct cov_keep {
  nav_cov_point *p;
  size_t n, cap;
} cov_keep;

static nav_callback_result keep(void *user, const nav_cov_point *p) {
  cov_keep *k = user;
  if (k->n < k->cap) k->p[k->n++] = *p;
  return NAV_CONTINUE;
}

static void test_shares_add_up_ins_gnss(void **state) {
  (void)state;
  nav_scene *sc = read_scene(k_ins_gnss);
  sum_check c;
  memset(&c, 0, sizeof c);
  unsigned active = 0;
  char msg[256];
  const nav_status st = nav_budget_covariance(sc, on_epoch, &c, &active, msg, sizeof msg);
  if (st != NAV_OK) fail_msg("budget: %s", msg);
  print_message("%ld epochs, largest relative difference of the summed sources %.3g\n", c.epochs, c.worst_rel);
  assert_true(c.epochs > 100);
  assert_true(c.worst_rel <= 1e-9);
  /* Every kind of source of the scene is there. */
  const int expect[] = {NAV_BUDGET_GYRO_ARW,           NAV_BUDGET_GYRO_BIAS_INSTABILITY, NAV_BUDGET_GYRO_RATE_RW,
                        NAV_BUDGET_GYRO_TURN_ON_BIAS,  NAV_BUDGET_ACCEL_VRW,             NAV_BUDGET_ACCEL_TURN_ON_BIAS,
                        NAV_BUDGET_INITIAL_POSITION,   NAV_BUDGET_INITIAL_VELOCITY,      NAV_BUDGET_INITIAL_ATTITUDE,
                        NAV_BUDGET_GNSS_POS_NOISE,     NAV_BUDGET_GNSS_VEL_NOISE};
  for (size_t i = 0; i < sizeof expect / sizeof *expect; ++i)
    if (!(active & (1u << expect[i]))) fail_msg("source %s missing", nav_budget_source_name(expect[i]));

  /* The total is the simulation's covariance analysis (same model, gains and updates). */
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  cov_keep k = {calloc(4096, sizeof(nav_cov_point)), 0, 4096};
  assert_non_null(k.p);
  assert_int_equal(nav_sim_covariance(sim, keep, &k), NAV_OK);
  nav_sim_destroy(sim);
  assert_int_equal((long)k.n, c.epochs);
  const nav_cov_point *p = &k.p[k.n - 1];
  assert_near(p->t_s, c.last.t_s, 1e-9);
  assert_rel_near(sqrt(c.last.total.v[0]), p->pos_sd_n_m.x, 1e-6);
  assert_rel_near(sqrt(c.last.total.v[2]), p->pos_sd_n_m.z, 1e-6);
  assert_rel_near(sqrt(c.last.total.v[4]), p->vel_sd_n_mps.y, 1e-6);
  assert_rel_near(sqrt(c.last.total.v[8]), p->att_sd_rad.z, 1e-6);
  free(k.p);

  /* Per requirement: the source mean squares add up to the total. */
  nav_budget_result r[NAV_SCENE_MAX_REQUIREMENTS];
  assert_int_equal(nav_budget_requirements(sc, sc->requirements, sc->n_requirements, r, msg, sizeof msg), NAV_OK);
  for (int i = 0; i < sc->n_requirements; ++i) {
    double s = 0.0;
    for (int q = 0; q < NAV_BUDGET_SOURCE_COUNT; ++q) s += r[i].source_ms[q];
    print_message("%-6s total %.6g, sum of %d sources %.6g\n", r[i].req.id, r[i].total_ms,
                  __builtin_popcount(r[i].active), s);
    assert_true(r[i].total_ms > 0.0);
    assert_rel_near(s, r[i].total_ms, 1e-9);
  }
  assert_near(r[0].t_s, 39.9, 1e-9); /* the last 10 Hz epoch inside [25, 40) */
  assert_near(r[4].t_s, 30.0, 1e-9);
  free(sc);
}

/* A free INS on WGS-84, 120 s, with several sources; the Monte Carlo has the gyro turn-on bias
 * alone (other terms off, perfect initial state) and 200 runs. */
static const char k_free_ins[] = "format_version: 1\n"
                                 "name: budget-free-ins\n"
                                 "earth: {model: wgs84, origin: {lat_deg: 30, lon_deg: 0, h_m: 0}}\n"
                                 "trajectory:\n"
                                 "  type: segments\n"
                                 "  initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 60}\n"
                                 "  segments:\n"
                                 "    v0_b_mps: [15, 0, 0]\n"
                                 "    items:\n"
                                 "      - {kind: hold, duration_s: 120}\n"
                                 "imu:\n"
                                 "  rate_hz: 100\n"
                                 "  gyro: {bias_turn_on_deg_per_h: 10, arw_deg_per_sqrt_h: 0.2}\n"
                                 "  accel: {bias_turn_on_mg: 0.5, vrw_m_per_s_per_sqrt_h: 0.05}\n"
                                 "initial_errors: {position_m: 1, velocity_mps: 0.05, attitude_deg: 0.05}\n"
                                 "navigation: {scheme: free_ins, algorithm: high_order}\n"
                                 "output: {rate_hz: 10}\n"
                                 "simulation: {seed: 11, runs: 200}\n"
                                 "requirements:\n"
                                 "  - {id: h-end, metric: horizontal_position, statistic: at_time, time_s: 120, "
                                 "limit: 10, unit: m}\n";

/* Chi-square quantile (Wilson-Hilferty), k degrees of freedom, standard normal quantile z. */
static double chi2_quantile(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + z * sqrt(a);
  return k * c * c * c;
}

static void test_single_source_monte_carlo(void **state) {
  (void)state;
  nav_scene *sc = read_scene(k_free_ins);
  nav_budget_result r;
  char msg[256];
  assert_int_equal(nav_budget_requirements(sc, sc->requirements, 1, &r, msg, sizeof msg), NAV_OK);
  assert_near(r.t_s, 120.0, 1e-9);
  const double var_cov = r.source_ms[NAV_BUDGET_GYRO_TURN_ON_BIAS];
  print_message("covariance: gyro turn-on bias %.4g m RMS of %.4g m total (share %.3f)\n", sqrt(var_cov),
                sqrt(r.total_ms), var_cov / r.total_ms);
  assert_true(var_cov / r.total_ms > 0.05 && var_cov / r.total_ms < 0.95); /* a real mixture */

  /* Monte Carlo with that source alone. */
  sc->imu.model.gyro.terms = NAV_IMU_TERM_BIAS_TURN_ON;
  sc->imu.model.accel.terms = 0;
  sc->initial_errors.pos_sd_m = nav_vec3_zero();
  sc->initial_errors.vel_sd_mps = nav_vec3_zero();
  sc->initial_errors.att_sd_rad = nav_vec3_zero();
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = 2;
  nav_sim_summary sum;
  assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_OK);
  size_t nf = 0;
  const nav_sim_run_final *fin = nav_sim_finals(sim, &nf);
  assert_int_equal((long)nf, 200);
  double ms = 0.0;
  for (size_t i = 0; i < nf; ++i) {
    assert_near(fin[i].err.t_s, 120.0, 1e-9);
    ms += fin[i].err.pos_err_h_m * fin[i].err.pos_err_h_m;
  }
  ms /= (double)nf;
  nav_sim_destroy(sim);
  /* h^2 = dN^2 + dE^2 of zero-mean Gaussians: between 200 and 400 degrees of freedom; the band
   * with 200 (the wider one) at 99.9 % two-sided. */
  const double lo = chi2_quantile(200.0, -3.2905) / 200.0, hi = chi2_quantile(200.0, 3.2905) / 200.0;
  print_message("Monte Carlo (200 runs, gyro turn-on bias alone): %.4g m RMS; ratio of mean squares %.4f, band "
                "[%.3f, %.3f]\n",
                sqrt(ms), ms / var_cov, lo, hi);
  assert_true(ms / var_cov >= lo && ms / var_cov <= hi);
  free(sc);
}


/* Scale factors the filter does not estimate are consider states: on the INS/GNSS scene with
 * gyro and accelerometer scale factors the sources still add up, the scale-factor sources are
 * there, and the other sources add up to the navigation filter's own covariance. */
static void test_scale_factor_consider_states(void **state) {
  (void)state;
  char text[sizeof k_ins_gnss + 200];
  snprintf(text, sizeof text, "%s", k_ins_gnss);
  char *g = strstr(text, "  gyro: {bias_turn_on_deg_per_h: 100,");
  assert_non_null(g);
  /* insert the scale factors into the gyro and accel flow mappings */
  static const char gyro_old[] = "  gyro: {bias_turn_on_deg_per_h: 100, rrw_deg_per_h_per_sqrt_h: 20}\n"
                                 "  accel: {bias_turn_on_mg: 1}\n";
  static const char gyro_new[] = "  gyro: {bias_turn_on_deg_per_h: 100, rrw_deg_per_h_per_sqrt_h: 20, scale_factor_ppm: 3000}\n"
                                 "  accel: {bias_turn_on_mg: 1, scale_factor_ppm: 2000}\n";
  char *at = strstr(text, gyro_old);
  assert_non_null(at);
  char out[sizeof text + 200];
  snprintf(out, sizeof out, "%.*s%s%s", (int)(at - text), text, gyro_new, at + strlen(gyro_old));
  nav_scene *sc = read_scene(out);
  sum_check c;
  memset(&c, 0, sizeof c);
  unsigned active = 0;
  char msg[256];
  const nav_status st = nav_budget_covariance(sc, on_epoch, &c, &active, msg, sizeof msg);
  if (st != NAV_OK) fail_msg("budget: %s", msg);
  print_message("with scale factors: largest relative difference of the summed sources %.3g\n", c.worst_rel);
  assert_true(c.worst_rel <= 1e-9);
  assert_true(active & (1u << NAV_BUDGET_GYRO_SCALE_FACTOR));
  assert_true(active & (1u << NAV_BUDGET_ACCEL_SCALE_FACTOR));
  /* Without the scale-factor sources: the navigation filter's covariance. */
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  cov_keep k = {calloc(4096, sizeof(nav_cov_point)), 0, 4096};
  assert_non_null(k.p);
  assert_int_equal(nav_sim_covariance(sim, keep, &k), NAV_OK);
  nav_sim_destroy(sim);
  const nav_cov_point *p = &k.p[k.n - 1];
  const nav_budget_diag *tot = &c.last.total;
  const nav_budget_diag *sg = &c.last.source[NAV_BUDGET_GYRO_SCALE_FACTOR];
  const nav_budget_diag *sa = &c.last.source[NAV_BUDGET_ACCEL_SCALE_FACTOR];
  const double n_var = tot->v[0] - sg->v[0] - sa->v[0], d_var = tot->v[2] - sg->v[2] - sa->v[2];
  print_message("final north sigma: filter %.6g m, budget without scale factors %.6g m, with %.6g m\n",
                p->pos_sd_n_m.x, sqrt(n_var), sqrt(tot->v[0]));
  assert_rel_near(sqrt(n_var), p->pos_sd_n_m.x, 1e-6);
  assert_rel_near(sqrt(d_var), p->pos_sd_n_m.z, 1e-6);
  assert_true(sg->v[8] > 0.0 && sa->v[0] > 0.0);
  free(k.p);
  free(sc);
}

/* Free INS through a 180 deg turn: the heading error of a gyro scale factor, checked by Monte
 * Carlo with that source alone (200 runs) against its share of the covariance budget. The
 * requirements are at the end of the run (61.1875 s: the planned length of the segments; a time
 * after the end is refused by the scene check, issue 25). */
static const char k_turn[] = "format_version: 1\n"
                             "name: budget-turn\n"
                             "earth: {model: wgs84, origin: {lat_deg: 30, lon_deg: 0, h_m: 0}}\n"
                             "trajectory:\n"
                             "  type: segments\n"
                             "  segments:\n"
                             "    v0_b_mps: [10, 0, 0]\n"
                             "    limits: {max_accel_mps2: 2, max_jerk_mps3: 2, max_lateral_accel_mps2: 4,\n"
                             "             max_rate_dps: 20, max_ang_accel_dps2: 20, max_ang_jerk_dps3: 60}\n"
                             "    items:\n"
                             "      - {kind: hold, duration_s: 10}\n"
                             "      - {kind: turn, yaw_deg: 180}\n"
                             "      - {kind: hold, duration_s: 40}\n"
                             "imu:\n"
                             "  rate_hz: 100\n"
                             "  gyro: {scale_factor_ppm: 5000, arw_deg_per_sqrt_h: 0.5}\n"
                             "  accel: {vrw_m_per_s_per_sqrt_h: 0.05}\n"
                             "initial_errors: {position_m: 1, velocity_mps: 0.02, attitude_deg: 0.02}\n"
                             "navigation: {scheme: free_ins, algorithm: high_order}\n"
                             "output: {rate_hz: 10}\n"
                             "simulation: {seed: 17, runs: 200}\n"
                             "requirements:\n"
                             "  - {id: h-end, metric: horizontal_position, statistic: at_time, time_s: 61.1875, "
                             "limit: 10, unit: m}\n"
                             "  - {id: yaw-end, metric: yaw, statistic: at_time, time_s: 61.1875, limit: 1, unit: deg}\n";

static void test_scale_factor_monte_carlo(void **state) {
  (void)state;
  nav_scene *sc = read_scene(k_turn);
  nav_budget_result r[2];
  char msg[256];
  assert_int_equal(nav_budget_requirements(sc, sc->requirements, 2, r, msg, sizeof msg), NAV_OK);
  const double var_h = r[0].source_ms[NAV_BUDGET_GYRO_SCALE_FACTOR], var_y = r[1].source_ms[NAV_BUDGET_GYRO_SCALE_FACTOR];
  print_message("covariance at %.1f s: gyro scale factor %.4g m of %.4g m, yaw %.4g deg of %.4g deg\n", r[0].t_s,
                sqrt(var_h), sqrt(r[0].total_ms), sqrt(var_y) * 180.0 / NAV_PI, sqrt(r[1].total_ms) * 180.0 / NAV_PI);
  assert_true(var_h / r[0].total_ms > 0.05 && var_h / r[0].total_ms < 0.95);
  sc->imu.model.gyro.terms = NAV_IMU_TERM_SCALE_FACTOR;
  sc->imu.model.accel.terms = 0;
  sc->initial_errors.pos_sd_m = nav_vec3_zero();
  sc->initial_errors.vel_sd_mps = nav_vec3_zero();
  sc->initial_errors.att_sd_rad = nav_vec3_zero();
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = 2;
  nav_sim_summary sum;
  assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_OK);
  size_t nf = 0;
  const nav_sim_run_final *fin = nav_sim_finals(sim, &nf);
  assert_int_equal((long)nf, 200);
  double ms_h = 0.0, ms_y = 0.0;
  for (size_t i = 0; i < nf; ++i) {
    assert_near(fin[i].err.t_s, r[0].t_s, 1e-6);
    ms_h += fin[i].err.pos_err_h_m * fin[i].err.pos_err_h_m;
    ms_y += fin[i].err.euler_err.yaw_rad * fin[i].err.euler_err.yaw_rad;
  }
  ms_h /= (double)nf;
  ms_y /= (double)nf;
  nav_sim_destroy(sim);
  const double lo = chi2_quantile(200.0, -3.2905) / 200.0, hi = chi2_quantile(200.0, 3.2905) / 200.0;
  print_message("Monte Carlo (200 runs, gyro scale factor alone): ratio of mean squares horizontal %.4f, yaw %.4f, "
                "band [%.3f, %.3f]\n",
                ms_h / var_h, ms_y / var_y, lo, hi);
  assert_true(ms_h / var_h >= lo && ms_h / var_h <= hi);
  assert_true(ms_y / var_y >= lo && ms_y / var_y <= hi);
  free(sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_shares_add_up_ins_gnss),
      cmocka_unit_test(test_single_source_monte_carlo),
      cmocka_unit_test(test_scale_factor_consider_states),
      cmocka_unit_test(test_scale_factor_monte_carlo),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
