/*
 * Issue 21 item 3, the user's side: the accelerometer parts for arrays through navsim. `navsim
 * catalog --accel` lists every part with its datasheet figures and its source (and says which
 * rows are unverified); a scene selects a part with array.catalog, which `navsim estimate`
 * turns into a different prediction; an unknown part and a part whose scale factor the
 * gyro-free/GNSS filter cannot take are clear errors at FILE:LINE:COL, exit 2.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

/* The car scene of issue 21 with its typed array terms replaced by @p array_lines. */
static void write_car(const char *name, const char *array_lines) {
  char *car = nav_test_slurp_alloc(NAV_SOURCE_DIR "/scenes/gyro-free-gnss-car.yaml");
  assert_non_null(car);
  const char *from = strstr(car, "array:\n");
  const char *to = strstr(car, "  initial_rate_sd_dps:");
  assert_non_null(from);
  assert_non_null(to);
  const size_t n = strlen(car) + strlen(array_lines) + 64;
  char *out = malloc(n);
  assert_non_null(out);
  snprintf(out, n, "%.*sarray:\n%s%s", (int)(from - car), car, array_lines, to);
  nav_test_write_file(WORK, name, out);
  free(out);
  free(car);
}

static void test_catalog_lists_parts_with_sources(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "catalog --accel");
  assert_int_equal(r->code, 0);
  /* Every row of the file, by name, and its source line. */
  char *csv = nav_test_slurp_alloc(NAV_SOURCE_DIR "/resources/accel_catalog.csv");
  assert_non_null(csv);
  int rows = 0;
  for (char *line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
    char name[128];
    const char *s = line + 1;
    const size_t k = strcspn(s, ",");
    assert_true(k > 0 && k < sizeof name);
    memcpy(name, s, k);
    name[k] = '\0';
    char want[256];
    snprintf(want, sizeof want, "\n  %s [line %d, verified: ", name, rows + 2);
    if (!strstr(r->out, want)) fail_msg("navsim catalog --accel has no source line for %s", name);
    ++rows;
  }
  free(csv);
  assert_true(rows >= 6);
  nav_test_assert_matches(r->out,
                          "^Safran Colibrys MS1010 +tactical MEMS +\\| +10 +- +34 +15 +1\\.2 +120 \\|");
  nav_test_assert_matches(r->out,
                          "MS1010 \\[line [0-9]+, verified: yes\\]: Safran Colibrys MS1000 data sheet");
  nav_test_assert_matches(r->out, "^Honeywell QA-2000 Q-Flex .*NO \\(unverified\\)$");
  /* CSV in SI: the model of each part. */
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "catalog --accel --csv");
  assert_int_equal(r->code, 0);
  nav_test_assert_matches(r->out, "^part,grade,range_g,bandwidth_hz,vrw_mps_per_sqrt_s,");
  nav_test_assert_matches(r->out, "^Safran Colibrys MS1010,tactical MEMS,10,,0\\.0003334261,");
  /* One table per CSV. */
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "catalog --accel --imu --csv");
  assert_int_equal(r->code, 2);
}

static double outage_end_m(const char *out) {
  const char *p = strstr(out, "horizontal_position outage_end = ");
  assert_non_null(p);
  return strtod(p + strlen("horizontal_position outage_end = "), NULL);
}

/* The part fills the array's terms: two parts of one family predict different outage ends, in
   the order of their noise (MS1002: 7 ug/rtHz; MS1010: 34 ug/rtHz). */
static void test_part_changes_prediction(void **state) {
  (void)state;
  write_car("ms1002.yaml", "  layout: cube6\n  radius_m: 0.5\n  catalog: Safran Colibrys MS1002\n"
                           "  accel: {off: [scale_factor]}\n");
  write_car("ms1010.yaml", "  layout: cube6\n  radius_m: 0.5\n  catalog: Safran Colibrys MS1010\n"
                           "  accel: {off: [scale_factor]}\n");
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "estimate ms1002.yaml --out est-ms1002");
  assert_int_equal(r->code, 0);
  const double h2 = outage_end_m(r->out);
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "estimate ms1010.yaml --out est-ms1010");
  assert_int_equal(r->code, 0);
  const double h10 = outage_end_m(r->out);
  print_message("predicted horizontal error at the outage end: MS1002 %.3f m, MS1010 %.3f m\n", h2, h10);
  assert_true(h2 > 0.0 && h10 > 1.2 * h2);
  /* Typed terms override the part: the MS1010 with the MS1002's noise comes close to the MS1002. */
  write_car("ms1010-quiet.yaml", "  layout: cube6\n  radius_m: 0.5\n  catalog: Safran Colibrys MS1010\n"
                                 "  accel: {off: [scale_factor], noise_density_ug_per_sqrt_hz: 7}\n");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "estimate ms1010-quiet.yaml --out est-quiet");
  assert_int_equal(r->code, 0);
  const double hq = outage_end_m(r->out);
  assert_true(hq < h10 && hq >= h2);
}

static void test_part_errors(void **state) {
  (void)state;
  write_car("unknown.yaml", "  layout: cube6\n  radius_m: 0.5\n  catalog: Safran Colibrys MS1011\n");
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check unknown.yaml");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "^unknown\\.yaml:53:12: error: array\\.catalog: unknown accelerometer part "
                                  "\"Safran Colibrys MS1011\"; did you mean \"Safran Colibrys MS1010\"\\?");
  write_car("unknown2.yaml", "  layout: cube6\n  radius_m: 0.5\n  catalog: ADXL999\n");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check unknown2.yaml");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err,
                          "^unknown2\\.yaml:53:12: error: array\\.catalog: unknown accelerometer part "
                          "\"ADXL999\"; `navsim catalog --accel` lists the [0-9]+ entries of ");
  /* The part's scale factor is a term the gyro-free/GNSS filter refuses: said where, and how. */
  write_car("sf.yaml", "  layout: cube6\n  radius_m: 0.5\n  catalog: Safran Colibrys MS1010\n");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check sf.yaml");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err,
                          "^sf\\.yaml:[0-9]+:[0-9]+: error: array\\.accel: gyro_free_gnss does not estimate "
                          "accelerometer scale factors: turn the scale-factor term off");
}

/* select --schemes ins_gnss,gyro_free_gnss --array-parts: the gyro-free/GNSS configurations range
   over the array parts (N sensors x the part's cost), the gyro INS/GNSS ones over the IMUs. */
static void test_select_over_parts(void **state) {
  (void)state;
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "select '%s/scenes/gyro-free-gnss-car.yaml' --schemes ins_gnss,gyro_free_gnss --imus "
                        "'Safran Sensonor STIM300' "
                        "--receivers 'standalone SPS typical (single-frequency code, open sky)' "
                        "--array-parts 'Safran Colibrys MS1002,Safran Colibrys MS1010' --runs 4 --out sel",
                        NAV_SOURCE_DIR);
  if (r->code != 0) fail_msg("select exit %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out,
                          "2 array parts \\(gyro_free_gnss, 6 sensors each\\) x 1 receiver x 2 schemes = 3 "
                          "configurations");
  char *rank = nav_test_slurp_alloc(WORK "/sel/ranking.csv");
  assert_non_null(rank);
  nav_test_assert_matches(
      rank, "^[0-9]+,\"Safran Colibrys MS1002\",\"standalone SPS[^\"]*\",gyro_free_gnss,2,1,2,1830,");
  nav_test_assert_matches(
      rank, "^[0-9]+,\"Safran Colibrys MS1010\",\"standalone SPS[^\"]*\",gyro_free_gnss,2,1,2,1830,");
  nav_test_assert_matches(
      rank, "^[0-9]+,\"Safran Sensonor STIM300\",\"standalone SPS[^\"]*\",ins_gnss,3,1,3,3030,");
  free(rank);
  char *rec = nav_test_slurp_alloc(WORK "/sel/recommended.yaml");
  assert_non_null(rec);
  nav_test_assert_matches(rec, "^  catalog: \"Safran Colibrys MS1002\""); /* the cheapest passing array */
  free(rec);
  r = nav_test_run_clif(
      NAVSIM_EXE, WORK, NULL,
      "select '%s/scenes/gyro-free-gnss-car.yaml' --schemes gyro_free_gnss --array-parts MS1011 "
      "--out sel2",
      NAV_SOURCE_DIR);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "--array-parts: unknown accelerometer part \"MS1011\"");
  r = nav_test_run_clif(
      NAVSIM_EXE, WORK, NULL,
      "select '%s/scenes/gyro-free-gnss-car.yaml' --schemes ins_gnss --array-parts all --out sel3",
      NAV_SOURCE_DIR);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "--array-parts applies to the gyro_free_gnss scheme");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_catalog_lists_parts_with_sources),
      cmocka_unit_test(test_part_changes_prediction),
      cmocka_unit_test(test_part_errors),
      cmocka_unit_test(test_select_over_parts),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
