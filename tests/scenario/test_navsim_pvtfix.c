/*
 * The loosely coupled INS/GNSS on least-squares PVT fixes (issue 22 item 4):
 * scenes/urban-canyon.yaml has gnss.constellation.fixes: pvt, so its fixes are the position and
 * range-rate velocity solutions of the simulated pseudoranges of the satellites in view (none
 * below four, i.e. none in the 60 s canyon with 3 satellites), with R = sigma^2 (H'H)^-1.
 * - navsim run (100 Monte Carlo runs) is bit-identical with 1 and 2 threads (mc_stats, mc_final);
 * - its 9-state NEES is inside the 95 % band of chi2(9 x 100) / 100 on >= 90 % of the epochs;
 * - the RMS over the runs of north, east and down position agrees with the filter's own mean
 *   reported sigma and with the covariance analysis (navsim estimate, R from the geometry of the
 *   satellites the reference sees) inside the 99 % band of chi2(100) at ten epochs, the canyon's
 *   end included (>= 28 of 30 each);
 * - before the canyon the horizontal RMS is below the receiver's own sigma x RMS(HDOP) bound of a
 *   single fix (the filter averages the fixes: 3 m code noise, HDOP from gnss_dop.csv);
 * - `navsim schema` documents gnss.constellation.fixes.
 * The comparison with the tightly coupled scheme at the canyon's end is test_navsim_tight's.
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
#define LOOSE NAV_SOURCE_DIR "/scenes/urban-canyon.yaml"

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

static void loose_on_pvt_fixes(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --threads 2 --quiet --out t2", LOOSE);
  if (r->code != 0) fail_msg("run: %d\n%s", r->code, r->err);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --threads 1 --quiet --out t1", LOOSE);
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
  char js[16384];
  nav_test_slurp(WORK "/t2/summary.json", js, sizeof js);
  nav_test_assert_matches(js, "\"runs\": 100");
  /* No gnss.csv: its writer evaluates the receiver model, whose fixes the filter never saw. */
  {
    FILE *g = fopen(WORK "/t2/gnss.csv", "r");
    if (g != NULL) {
      fclose(g);
      fail_msg("a fixes: pvt run wrote gnss.csv (the receiver model's fixes, not the PVT's)");
    }
    g = fopen(WORK "/t2/gnss_outages.csv", "r");
    assert_non_null(g);
    fclose(g);
  }
  nav_table mc, dop;
  nav_table_read(WORK "/t2/mc_stats.csv", &mc);
  nav_table_read(WORK "/t2/gnss_dop.csv", &dop);
  const double M = 100.0;
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
  print_message("loose on PVT fixes, NEES (9 states, 100 runs): mean %.3f, %d of %d epochs (%.1f %%) in [%.3f, %.3f]\n",
                mean9 / mc.nrow, in9, mc.nrow, 100.0 * in9 / mc.nrow, lo9, hi9);
  assert_true((double)in9 >= 0.9 * (double)mc.nrow);
  /* RMS over the runs against the filter's mean reported sigma. */
  const double lo = sqrt(nav_chi2_over_k(M, -2.5758)), hi = sqrt(nav_chi2_over_k(M, 2.5758));
  const double times[10] = {10.0, 30.0, 45.0, 60.0, 80.0, 99.9, 110.0, 130.0, 150.0, 170.0};
  const char *rms[3] = {"pos_rms_n_m", "pos_rms_e_m", "pos_rms_d_m"};
  const char *sd[3] = {"pos_sd_reported_n_m", "pos_sd_reported_e_m", "pos_sd_reported_d_m"};
  const char *cov_sd[3] = {"cov_pos_n_sd_m", "cov_pos_e_sd_m", "cov_pos_d_sd_m"};
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "estimate '%s' --out est", LOOSE);
  if (r->code != 0) fail_msg("estimate: %d\n%s", r->code, r->err);
  nav_table est;
  nav_table_read(WORK "/est/estimate.csv", &est);
  int inside = 0, inside_cov = 0;
  for (int i = 0; i < 10; ++i) {
    const int rm = nav_table_row_at(&mc, times[i]), re = nav_table_row_at(&est, times[i]);
    assert_true(rm >= 0 && re >= 0);
    double ratio[3], rc[3];
    for (int c = 0; c < 3; ++c) {
      ratio[c] = nav_table_at(&mc, rm, nav_table_col(&mc, rms[c])) / nav_table_at(&mc, rm, nav_table_col(&mc, sd[c]));
      rc[c] = nav_table_at(&mc, rm, nav_table_col(&mc, rms[c])) / nav_table_at(&est, re, nav_table_col(&est, cov_sd[c]));
      inside += ratio[c] > lo && ratio[c] < hi;
      inside_cov += rc[c] > lo && rc[c] < hi;
    }
    print_message("t = %6.1f s: RMS / filter sigma N %.3f E %.3f D %.3f; RMS / covariance analysis N %.3f E %.3f "
                  "D %.3f\n",
                  times[i], ratio[0], ratio[1], ratio[2], rc[0], rc[1], rc[2]);
  }
  print_message("%d (filter sigma) and %d (covariance analysis) of 30 ratios in the 99 %% band [%.3f, %.3f]\n",
                inside, inside_cov, lo, hi);
  assert_true(inside >= 28);
  assert_true(inside_cov >= 28);
  free(est.v);
  /* Before the canyon the filtered horizontal error is below one fix's sigma HDOP (3 m code). */
  const int rb = nav_table_row_at(&mc, 39.9), db = nav_table_row_at(&dop, 39.9), re = nav_table_row_at(&mc, 99.9);
  assert_true(rb >= 0 && db >= 0 && re >= 0);
  const double h_before = nav_table_at(&mc, rb, nav_table_col(&mc, "pos_h_rms_m")), hdop = nav_table_at(&dop, db, nav_table_col(&dop, "hdop"));
  print_message("t = 39.9 s: horizontal RMS %.2f m, one fix's sigma HDOP %.2f m; canyon end (99.9 s): %.2f m RMS "
                "(max %.2f m)\n",
                h_before, 3.0 * hdop, nav_table_at(&mc, re, nav_table_col(&mc, "pos_h_rms_m")), nav_table_at(&mc, re, nav_table_col(&mc, "pos_h_max_m")));
  assert_true(hdop > 0.0 && h_before < 3.0 * hdop);
  free(mc.v);
  free(dop.v);
}

/* The scene option is in the schema with its values and a doc line. */
static void schema_has_fixes(void **state) {
  (void)state;
  /* The schema is larger than the captured stdout: the whole file the runner wrote. */
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "schema");
  if (r->code != 0) fail_msg("schema: %d\n%s", r->code, r->err);
  char *js = nav_test_slurp_alloc(WORK "/stdout.txt");
  assert_non_null(js);
  const char *p = strstr(js, "\"fixes\"");
  if (!p) fail_msg("no \"fixes\" key in navsim schema");
  const char *q = strstr(p, "least-squares PVT");
  const char *e1 = strstr(p, "\"pvt\""), *e2 = strstr(p, "\"model\"");
  assert_non_null(q);
  assert_non_null(e1);
  assert_non_null(e2);
  assert_true(q - p < 1000 && e1 - p < 1000 && e2 - p < 1000);
  free(js);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(loose_on_pvt_fixes),
      cmocka_unit_test(schema_has_fixes),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
