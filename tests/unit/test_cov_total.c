/*
 * nav_sim_covariance_total (the one-pass covariance analysis behind navsim estimate): its filter
 * points are nav_sim_covariance's bit for bit; its total points (the filter plus the truth's
 * scale factors as consider states, carried as a sensitivity beside the filter) agree with the
 * budget's total filter (nav_budget_covariance, a filter of n + 6 states) within 1e-9 relative
 * at every epoch; and the verdicts predicted from them agree with nav_req_predict_scene within
 * 1e-9 relative. On INS/GNSS with and without covariance decimation, with GNSS error states
 * (urban-drive), on a free INS through a turn, on a scheme without consider states (bit for bit)
 * and refused for PVT fixes.
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
#include "navcore/nav_requirements.h"
#include "navcore/nav_sim.h"

#define MAXP 8192

static const char k_ins_gnss[] =
    "format_version: 1\n"
    "name: total-ins-gnss\n"
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
    "  gyro: {bias_turn_on_deg_per_h: 100, rrw_deg_per_h_per_sqrt_h: 20, scale_factor_ppm: 3000}\n"
    "  accel: {bias_turn_on_mg: 1, scale_factor_ppm: 2000}\n"
    "gnss:\n"
    "  enabled: true\n"
    "  catalog: \"SBAS (WAAS/EGNOS class)\"\n"
    "  position_white_sigma_m: [0.3, 0.3, 0.5]\n"
    "  lever_arm_b_m: [0.5, 0.2, -1]\n"
    "  outages: [[25, 40]]\n"
    "initial_errors: {position_m: [2, 2, 4], velocity_mps: 0.1, attitude_deg: [0.5, 0.5, 2]}\n"
    "navigation: {scheme: ins_gnss, algorithm: high_order%s}\n"
    "output: {rate_hz: 10}\n"
    "requirements:\n"
    "  - {id: h-end, metric: horizontal_position, statistic: outage_end, limit: 5, unit: m}\n"
    "  - {id: h-rms, metric: horizontal_position, statistic: rms, limit: 5, unit: m}\n"
    "  - {id: h-cep95, metric: horizontal_position, statistic: cep95, limit: 5, unit: m}\n"
    "  - {id: v-p95, metric: vertical_position, statistic: p95, limit: 5, unit: m}\n"
    "  - {id: vel, metric: velocity, statistic: rms, limit: 1, unit: m/s}\n"
    "  - {id: yaw-30, metric: yaw, statistic: at_time, time_s: 30, limit: 1, unit: deg}\n"
    "  - {id: p3, metric: position_3d, statistic: rms, limit: 9, unit: m}\n";

static const char k_turn[] = "format_version: 1\n"
                             "name: total-turn\n"
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
                             "  accel: {vrw_m_per_s_per_sqrt_h: 0.05, scale_factor_ppm: 800}\n"
                             "initial_errors: {position_m: 1, velocity_mps: 0.02, attitude_deg: 0.02}\n"
                             "navigation: {scheme: free_ins, algorithm: high_order}\n"
                             "output: {rate_hz: 10}\n"
                             "requirements:\n"
                             "  - {id: h-end, metric: horizontal_position, statistic: at_time, time_s: 61.1875, "
                             "limit: 10, unit: m}\n"
                             "  - {id: yaw-rms, metric: yaw, statistic: rms, limit: 1, unit: deg}\n"
                             "  - {id: h-cep50, metric: horizontal_position, statistic: cep50, limit: 5, unit: m}\n";

static void print_diag(void *user, const nav_diag *d) {
  (void)user;
  char line[1200];
  nav_diag_format(d, line, sizeof line);
  print_message("%s\n", line);
}

static nav_scene *read_text(const char *text) {
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_string(text, strlen(text), "total.yaml", sc, print_diag, NULL), NAV_OK);
  return sc;
}

static nav_scene *read_file(const char *name) {
  char path[512];
  snprintf(path, sizeof path, "%s/scenes/%s", NAV_SOURCE_DIR, name);
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(path, sc, print_diag, NULL), NAV_OK);
  return sc;
}

typedef struct pts {
  nav_cov_point a[MAXP]; /* nav_sim_covariance */
  nav_cov_point f[MAXP]; /* nav_sim_covariance_total: filter */
  nav_cov_point t[MAXP]; /* nav_sim_covariance_total: total */
  nav_budget_diag b[MAXP];
  size_t na, nf, nb;
} pts;

static nav_callback_result keep_a(void *user, const nav_cov_point *p) {
  pts *k = user;
  if (k->na == MAXP) return NAV_STOP;
  k->a[k->na++] = *p;
  return NAV_CONTINUE;
}

static nav_callback_result keep_ft(void *user, const nav_cov_point *f, const nav_cov_point *t) {
  pts *k = user;
  if (k->nf == MAXP) return NAV_STOP;
  k->f[k->nf] = *f;
  k->t[k->nf++] = *t;
  return NAV_CONTINUE;
}

static nav_callback_result keep_b(void *user, const nav_budget_epoch *e) {
  pts *k = user;
  if (k->nb == MAXP) return NAV_STOP;
  k->b[k->nb++] = e->total;
  return NAV_CONTINUE;
}

static double rel(double a, double b) {
  if (a == b) return 0.0;
  return fabs(a - b) / fmax(fabs(a), fabs(b));
}

/* Runs both analyses of @p sc; with @p budget, the totals against nav_budget_covariance's at
 * every epoch; the verdicts against nav_req_predict_scene. Returns the largest relative
 * difference of the total points (0 without @p budget) and of the verdict values. */
static void check(const char *label, nav_scene *sc, bool budget, double *worst_pt, double *worst_v) {
  pts *k = calloc(1, sizeof *k);
  assert_non_null(k);
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  assert_int_equal(nav_sim_covariance(sim, keep_a, k), NAV_OK);
  nav_status st = nav_sim_covariance_total(sim, keep_ft, k);
  if (st != NAV_OK) fail_msg("%s: %s", label, nav_sim_last_error(sim));
  nav_sim_destroy(sim);
  assert_true(k->na > 10 && k->na < MAXP);
  assert_int_equal(k->na, k->nf);
  assert_memory_equal(k->a, k->f, k->na * sizeof k->a[0]);
  *worst_pt = 0.0;
  if (budget) {
    char msg[256];
    st = nav_budget_covariance(sc, keep_b, k, NULL, msg, sizeof msg);
    if (st != NAV_OK) fail_msg("%s: budget: %s", label, msg);
    assert_int_equal(k->nb, k->nf);
    for (size_t i = 0; i < k->nb; ++i) {
      const nav_cov_point *t = &k->t[i];
      const double *v = k->b[i].v;
      const double mine[9] = {t->pos_sd_n_m.x,   t->pos_sd_n_m.y,   t->pos_sd_n_m.z,
                              t->vel_sd_n_mps.x, t->vel_sd_n_mps.y, t->vel_sd_n_mps.z,
                              t->att_sd_rad.x,   t->att_sd_rad.y,   t->att_sd_rad.z};
      for (int j = 0; j < 9; ++j) *worst_pt = fmax(*worst_pt, rel(mine[j], sqrt(v[j])));
      *worst_pt = fmax(*worst_pt, rel(t->pos_h_sd_m, hypot(sqrt(v[0]), sqrt(v[1]))));
    }
  }
  const int nr = sc->n_requirements;
  nav_requirement_verdict *old = calloc((size_t)nr, sizeof *old), *now = calloc((size_t)nr, sizeof *now);
  assert_non_null(old);
  assert_non_null(now);
  assert_int_equal(nav_req_predict_scene(sc, old), NAV_OK);
  assert_int_equal(nav_req_predict_scene_total_points_threads(sc, k->t, k->nf, 2, now), NAV_OK);
  *worst_v = 0.0;
  for (int r = 0; r < nr; ++r) {
    assert_int_equal(old[r].evaluated, now[r].evaluated);
    assert_int_equal(old[r].pass, now[r].pass);
    assert_int_equal(old[r].samples, now[r].samples);
    assert_int_equal(old[r].outage_count, now[r].outage_count);
    if (old[r].evaluated) *worst_v = fmax(*worst_v, rel(old[r].value, now[r].value));
    for (int o = 0; o < old[r].outage_count; ++o)
      if (!isnan(old[r].outage_value[o])) *worst_v = fmax(*worst_v, rel(old[r].outage_value[o], now[r].outage_value[o]));
  }
  print_message("%-34s %5zu epochs: total points %.3g, verdicts %.3g (largest relative difference)\n", label, k->nf,
                *worst_pt, *worst_v);
  free(old);
  free(now);
  free(k);
}

static nav_scene *ins_gnss_scene(const char *nav_extra) {
  char text[sizeof k_ins_gnss + 64];
  snprintf(text, sizeof text, k_ins_gnss, nav_extra);
  return read_text(text);
}

/* INS/GNSS with scale factors in the truth: consider states, every covariance step and every
 * fifth (decimated: the interval sums), and with the filter estimating them (none). */
static void test_ins_gnss_consider(void **state) {
  (void)state;
  const char *const extra[3] = {"", ", cov_decimation: 5", ", estimate_scale_factors: true"};
  for (int v = 0; v < 3; ++v) {
    nav_scene *sc = ins_gnss_scene(extra[v]);
    double wp, wv;
    char label[64];
    snprintf(label, sizeof label, "ins_gnss%s", extra[v]);
    check(label, sc, true, &wp, &wv);
    assert_true(wp <= 1e-9);
    assert_true(wv <= 1e-9);
    nav_scene_release(sc);
    free(sc);
  }
}

/* Free INS through a turn: consider states without updates. */
static void test_free_ins_consider(void **state) {
  (void)state;
  nav_scene *sc = read_text(k_turn);
  double wp, wv;
  check("free_ins", sc, true, &wp, &wv);
  assert_true(wp <= 1e-9);
  assert_true(wv <= 1e-9);
  nav_scene_release(sc);
  free(sc);
}

/* urban-drive: catalog parts, GNSS error states (18-state filter, the consider states between
 * the biases and the GNSS block), outages; the verdicts (outage_end, cep95). */
static void test_urban_drive(void **state) {
  (void)state;
  nav_scene *sc = read_file("urban-drive.yaml");
  double wp, wv;
  check("urban-drive", sc, false, &wp, &wv);
  assert_true(wv <= 1e-9);
  nav_scene_release(sc);
  free(sc);
}

/* gyro_free_gnss has no consider states: total = filter, the verdicts bit for bit. PVT fixes
 * (urban-canyon) are refused: their budget model is not the filter's. */
static void test_other_schemes(void **state) {
  (void)state;
  nav_scene *sc = read_file("gyro-free-gnss-car.yaml");
  double wp, wv;
  check("gyro-free-gnss-car", sc, false, &wp, &wv);
  assert_true(wv == 0.0);
  nav_scene_release(sc);
  free(sc);
  sc = read_file("urban-canyon.yaml");
  assert_true(nav_scene_gnss_pvt_fixes(sc));
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  pts *k = calloc(1, sizeof *k);
  assert_non_null(k);
  assert_int_equal(nav_sim_covariance_total(sim, keep_ft, k), NAV_ERR_INVALID_ARG);
  assert_int_equal(k->nf, 0);
  assert_non_null(strstr(nav_sim_last_error(sim), "pvt"));
  assert_int_equal(nav_sim_covariance_total(sim, NULL, k), NAV_ERR_INVALID_ARG);
  nav_sim_destroy(sim);
  free(k);
  nav_scene_release(sc);
  free(sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_ins_gnss_consider),
      cmocka_unit_test(test_free_ins_consider),
      cmocka_unit_test(test_urban_drive),
      cmocka_unit_test(test_other_schemes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
