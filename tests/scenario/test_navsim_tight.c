/*
 * The tightly coupled INS/GNSS through the urban canyon (issue 22 "done when"):
 * scenes/urban-canyon-tight.yaml (3 GPS satellites in view for the 60 s canyon, t = 40..100 s)
 * with its 100 Monte Carlo runs, and scenes/urban-canyon.yaml (the loosely coupled filter on fixes
 * from the least-squares PVT of the simulated pseudoranges, no fix below four satellites) with 100
 * runs.
 * - navsim run of the tight scene is bit-identical with 1 and 2 threads (mc_stats, mc_final);
 * - its 9-state NEES (mc_stats.csv) is inside the 95 % band of chi2(9 x 100) / 100 on >= 90 % of
 *   the epochs;
 * - the RMS over the runs of north, east and down position agrees with the covariance analysis of
 *   navsim estimate (estimate.csv) and with the filter's own mean reported sigma inside the 99 %
 *   band of chi2(100) at ten epochs, the canyon's last (99.9 s) included (>= 28 of 30 ratios
 *   each: 0.3 expected outside by chance, epochs correlated);
 * - at the canyon's end the tight filter's horizontal RMS error is below the loose one's.
 * Bands from Wilson-Hilferty (numerics.md T6.5, T6.6).
 */
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
#include "navsim_cli.h"
#include "nav_test_table.h"

#define WORK NAV_TEST_WORK_DIR
#define TIGHT NAV_SOURCE_DIR "/scenes/urban-canyon-tight.yaml"
#define LOOSE NAV_SOURCE_DIR "/scenes/urban-canyon.yaml"

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

/* Ratios RMS / sigma of N, E, D at the ten epochs, counted inside the 99 % band of chi2(M). */
static int ratios_inside(const nav_table *mc, const nav_table *ref, const char *const sd[3], const char *what,
                         double M) {
  const double lo = sqrt(nav_chi2_over_k(M, -2.5758)), hi = sqrt(nav_chi2_over_k(M, 2.5758));
  const double times[10] = {10.0, 30.0, 45.0, 60.0, 80.0, 99.9, 110.0, 130.0, 150.0, 170.0};
  const char *rms[3] = {"pos_rms_n_m", "pos_rms_e_m", "pos_rms_d_m"};
  int inside = 0;
  for (int i = 0; i < 10; ++i) {
    const int rm = nav_table_row_at(mc, times[i]), re = nav_table_row_at(ref, times[i]);
    assert_true(rm >= 0 && re >= 0);
    double ratio[3];
    for (int c = 0; c < 3; ++c) {
      ratio[c] = nav_table_at(mc, rm, nav_table_col(mc, rms[c])) / nav_table_at(ref, re, nav_table_col(ref, sd[c]));
      inside += ratio[c] > lo && ratio[c] < hi;
    }
    print_message("t = %6.1f s: RMS / %s N %.3f E %.3f D %.3f\n", times[i], what, ratio[0], ratio[1],
                  ratio[2]);
  }
  print_message("%d of 30 ratios in the 99 %% band [%.3f, %.3f]\n", inside, lo, hi);
  return inside;
}

static void test_tight_canyon(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "estimate '%s' --out est", TIGHT);
  if (r->code != 0) fail_msg("estimate: %d\n%s", r->code, r->err);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --threads 2 --quiet --out t2", TIGHT);
  if (r->code != 0) fail_msg("run: %d\n%s", r->code, r->err);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --threads 1 --quiet --out t1", TIGHT);
  if (r->code != 0) fail_msg("run --threads 1: %d\n%s", r->code, r->err);
  const char *files[2] = {"mc_stats.csv", "mc_final.csv"};
  for (int i = 0; i < 2; ++i) {
    char p1[512], p2[512];
    snprintf(p1, sizeof p1, "%s/t1/%s", WORK, files[i]);
    snprintf(p2, sizeof p2, "%s/t2/%s", WORK, files[i]);
    char *a = nav_test_slurp_alloc(p1), *b = nav_test_slurp_alloc(p2);
    assert_non_null(a);
    assert_non_null(b);
    if (strcmp(a, b) != 0) fail_msg("%s differs between 1 and 2 threads", files[i]);
    free(a);
    free(b);
  }
  nav_table est, mc;
  nav_table_read(WORK "/est/estimate.csv", &est);
  nav_table_read(WORK "/t2/mc_stats.csv", &mc);
  const double M = 100.0;
  char js[16384];
  nav_test_slurp(WORK "/t2/summary.json", js, sizeof js);
  nav_test_assert_matches(js, "\"runs\": 100");
  /* NEES */
  const int cn = nav_table_col(&mc, "nees9_mean");
  const double lo9 = 9.0 * nav_chi2_over_k(9.0 * M, -1.96), hi9 = 9.0 * nav_chi2_over_k(9.0 * M, 1.96);
  int in9 = 0;
  double mean9 = 0.0;
  for (int i = 0; i < mc.nrow; ++i) {
    const double v = nav_table_at(&mc, i, cn);
    in9 += v > lo9 && v < hi9;
    mean9 += v;
  }
  print_message("mc_stats NEES (9 states, 100 runs): mean %.3f, %d of %d epochs (%.1f %%) in [%.3f, %.3f]\n",
                mean9 / mc.nrow, in9, mc.nrow, 100.0 * in9 / mc.nrow, lo9, hi9);
  assert_true((double)in9 >= 0.9 * (double)mc.nrow);
  /* RMS over the runs against the covariance analysis and against the filter's own sigma. */
  const char *cov_sd[3] = {"cov_pos_n_sd_m", "cov_pos_e_sd_m", "cov_pos_d_sd_m"};
  const char *kf_sd[3] = {"pos_sd_reported_n_m", "pos_sd_reported_e_m", "pos_sd_reported_d_m"};
  assert_true(ratios_inside(&mc, &est, cov_sd, "covariance analysis", M) >= 28);
  assert_true(ratios_inside(&mc, &mc, kf_sd, "filter sigma", M) >= 28);
  /* Tight against loose at the canyon's end. */
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --runs 100 --threads 2 --quiet --out loose", LOOSE);
  if (r->code != 0) fail_msg("run loose: %d\n%s", r->code, r->err);
  nav_table lo;
  nav_table_read(WORK "/loose/mc_stats.csv", &lo);
  const int rt = nav_table_row_at(&mc, 99.9), rl = nav_table_row_at(&lo, 99.9), rb = nav_table_row_at(&lo, 39.9);
  assert_true(rt >= 0 && rl >= 0 && rb >= 0);
  const double h_t = nav_table_at(&mc, rt, nav_table_col(&mc, "pos_h_rms_m")), h_l = nav_table_at(&lo, rl, nav_table_col(&lo, "pos_h_rms_m"));
  print_message(
      "canyon end (t = 99.9 s), horizontal RMS over 100 runs: tight %.2f m (max %.2f m), loose %.2f m "
      "(max %.2f m); before the canyon (39.9 s): tight %.2f m, loose %.2f m\n",
      h_t, nav_table_at(&mc, rt, nav_table_col(&mc, "pos_h_max_m")), h_l, nav_table_at(&lo, rl, nav_table_col(&lo, "pos_h_max_m")),
      nav_table_at(&mc, nav_table_row_at(&mc, 39.9), nav_table_col(&mc, "pos_h_rms_m")), nav_table_at(&lo, rb, nav_table_col(&lo, "pos_h_rms_m")));
  assert_true(h_t < h_l);
  free(est.v);
  free(mc.v);
  free(lo.v);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_tight_canyon),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
