/*
 * navsim on the gyro-free/GNSS car (scenes/gyro-free-gnss-car.yaml, issue 21 "done when"):
 * `navsim run` with the scene's 200 runs writes mc_stats.csv whose 9-state NEES is inside its 95 %
 * band on >= 90 % of the epochs, and whose RMS over the runs of north, east and down position
 * agrees with the covariance analysis of `navsim estimate` (estimate.csv) inside the 99 % band of
 * chi2(200) at ten epochs spread over the run, the last epoch of the 8 s outage (107.9 s)
 * included (at least 28 of the 30 ratios: 0.3 expected outside by chance, epochs correlated).
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
#define SCENE NAV_SOURCE_DIR "/scenes/gyro-free-gnss-car.yaml"

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

static void test_car_run_agrees_with_estimate(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "estimate '%s' --out est", SCENE);
  if (r->code != 0) fail_msg("estimate: %d\n%s", r->code, r->err);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --threads 2 --quiet --out run", SCENE);
  if (r->code != 0) fail_msg("run: %d\n%s", r->code, r->err);
  nav_table est, mc;
  nav_table_read(WORK "/est/estimate.csv", &est);
  nav_table_read(WORK "/run/mc_stats.csv", &mc);
  const double M = 200.0;
  char js[8192];
  nav_test_slurp(WORK "/run/summary.json", js, sizeof js);
  nav_test_assert_matches(js, "\"runs\": 200");
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
  print_message("mc_stats NEES (9 states, 200 runs): mean %.3f, %d of %d epochs in [%.3f, %.3f]\n", mean9 / mc.nrow, in9,
                mc.nrow, lo9, hi9);
  assert_true((double)in9 >= 0.9 * (double)mc.nrow);
  /* RMS over the runs against the covariance analysis: ten epochs, the outage's last included. */
  const double lo = sqrt(nav_chi2_over_k(M, -2.5758)), hi = sqrt(nav_chi2_over_k(M, 2.5758));
  const double times[10] = {15.0, 40.0, 60.0, 80.0, 100.0, 104.0, 107.9, 140.0, 170.0, 200.0};
  const char *rms[3] = {"pos_rms_n_m", "pos_rms_e_m", "pos_rms_d_m"};
  const char *sd[3] = {"cov_pos_n_sd_m", "cov_pos_e_sd_m", "cov_pos_d_sd_m"};
  int inside = 0;
  for (int i = 0; i < 10; ++i) {
    const int rm = nav_table_row_at(&mc, times[i]), re = nav_table_row_at(&est, times[i]);
    assert_true(rm >= 0 && re >= 0);
    double ratio[3];
    for (int c = 0; c < 3; ++c) {
      ratio[c] = nav_table_at(&mc, rm, nav_table_col(&mc, rms[c])) / nav_table_at(&est, re, nav_table_col(&est, sd[c]));
      inside += ratio[c] > lo && ratio[c] < hi;
    }
    print_message("t = %6.1f s: RMS / covariance sigma N %.3f E %.3f D %.3f\n", times[i], ratio[0], ratio[1], ratio[2]);
  }
  print_message("%d of 30 ratios in the 99 %% band [%.3f, %.3f]\n", inside, lo, hi);
  assert_true(inside >= 28);
  free(est.v);
  free(mc.v);
}

/*
 * navsim select --schemes ins_gnss,gyro_free_gnss over every catalog IMU (one receiver, to keep
 * the test short): ranking.csv ranks both schemes, one row per IMU and scheme, with finite
 * predicted values for every requirement.
 */
static void test_select_both_schemes(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                                        "select '%s' --schemes ins_gnss,gyro_free_gnss --receivers 'standalone SPS typical "
                                        "(single-frequency code, open sky)' --runs 10 --out sel",
                                        SCENE);
  if (r->code != 0 && r->code != 3) fail_msg("select: %d\n%s", r->code, r->err);
  char *csv = nav_test_slurp_alloc(WORK "/sel/ranking.csv");
  assert_non_null(csv);
  int n_ins = 0, n_gf = 0;
  for (char *line = strtok(csv, "\n"); line; line = strtok(NULL, "\n")) {
    if (strstr(line, ",gyro_free_gnss,")) ++n_gf;
    else if (strstr(line, ",ins_gnss,")) ++n_ins;
    if (strstr(line, "nan")) fail_msg("non-finite value in ranking.csv: %s", line);
  }
  free(csv);
  char cat[65536];
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "catalog --imu --csv");
  assert_int_equal(r->code, 0);
  snprintf(cat, sizeof cat, "%s", r->out);
  int n_imu = -1; /* header */
  for (const char *p = cat; *p; ++p) n_imu += *p == '\n';
  print_message("select: %d ins_gnss and %d gyro_free_gnss rows for %d catalog IMUs\n", n_ins, n_gf, n_imu);
  assert_true(n_imu > 0);
  assert_int_equal(n_ins, n_imu);
  assert_int_equal(n_gf, n_imu);
}

/*
 * navsim sweep --predict of the car's array noise density: the outage-end requirement has a
 * threshold between two grid points, and every predicted value is finite.
 */
static void test_sweep_noise_threshold(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(
      NAVSIM_EXE, WORK, NULL,
      "sweep '%s' --param array.accel.noise_density_ug_per_sqrt_hz=10:1000:9:log --predict --quiet --out sw", SCENE);
  if (r->code != 0) fail_msg("sweep: %d\n%s", r->code, r->err);
  char buf[8192];
  nav_test_slurp(WORK "/sw/sweep.csv", buf, sizeof buf);
  assert_null(strstr(buf, "nan"));
  nav_test_slurp(WORK "/sw/thresholds.csv", buf, sizeof buf);
  print_message("%s", buf);
  nav_test_assert_matches(buf, "h-outage-end,4,m,array.accel.noise_density_ug_per_sqrt_hz,[0-9.]+,interpolated,31.62[0-9]*,56.23");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_car_run_agrees_with_estimate),
      cmocka_unit_test(test_select_both_schemes),
      cmocka_unit_test(test_sweep_noise_threshold),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
