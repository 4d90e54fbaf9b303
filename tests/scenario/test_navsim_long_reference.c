/*
 * Recorded references of any length and rate (issue 18, item 3; docs/recorded-fit.md): the fitted
 * control points live on the heap, not in the scene value, so the 1280-point cap of the scene is
 * gone.
 *
 *  - A one-hour 10 Hz reference made here from a library scene's truth: scenes/bench-mc-1h.yaml
 *    (a 3.5 km lawnmower survey, more than an hour) is run with its output at 10 Hz, its
 *    truth.csv is written as a KF-GINS .nav file, and a scene with that file as its recorded
 *    reference and knots at 10 Hz (more than 36 000 control points) is checked and run: the
 *    terminal and summary.json report the fit residuals; no knots-outrun warning (knots at the
 *    sample rate); the run's truth follows the source truth to 1 cm at every second of the hour.
 *  - The shared ADIS16465 reference (../shared/data/kfgins-matlab-dataset2-adis16465/truth.nav,
 *    the whole file) with knots at its own 10 Hz runs and reports its residuals; the vendored
 *    300 s slice of it at 10 Hz knots (3005 control points) is covered by test_recorded.
 *
 * NAVSIM_EXE, NAV_TEST_WORK_DIR and NAV_SOURCE_DIR come from the compile definitions.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define SOURCE_SCENE NAV_SOURCE_DIR "/scenes/bench-mc-1h.yaml"
#define SHARED_ADIS NAV_SHARED_DIR "/data/kfgins-matlab-dataset2-adis16465/truth.nav"
#define TRUTH_COLS 13 /* t_s, lat, lon, h, pos N E D, vel N E D, roll, pitch, yaw */
#define D2R (3.14159265358979323846 / 180.0)

/* Rows of a CSV file with a header line: the first TRUTH_COLS numbers of each. */
static double *load_truth(const char *path, size_t *rows) {
  char *text = nav_test_slurp_alloc(path);
  if (!text) fail_msg("cannot read %s", path);
  size_t cap = 4096, n = 0;
  double *v = malloc(cap * TRUTH_COLS * sizeof *v);
  assert_non_null(v);
  char *p = strchr(text, '\n');
  p = p ? p + 1 : text + strlen(text);
  while (*p) {
    if (n == cap) {
      cap *= 2;
      v = realloc(v, cap * TRUTH_COLS * sizeof *v);
      assert_non_null(v);
    }
    char *q = p;
    for (int c = 0; c < TRUTH_COLS; ++c) {
      char *end = NULL;
      v[n * TRUTH_COLS + (size_t)c] = strtod(q, &end);
      if (end == q) fail_msg("%s: row %zu: column %d is not a number", path, n + 1, c + 1);
      q = end;
      if (*q == ',') ++q;
    }
    ++n;
    char *eol = strchr(p, '\n');
    if (!eol) break;
    p = eol + 1;
  }
  free(text);
  *rows = n;
  return v;
}

/* The number after "KEY": in a JSON text (the first occurrence), NAN when absent. */
static double json_number(const char *text, const char *key) {
  char pat[128];
  snprintf(pat, sizeof pat, "\"%s\":", key);
  const char *p = strstr(text, pat);
  return p ? strtod(p + strlen(pat), NULL) : NAN;
}

/* Horizontal distance between two positions in degrees, metres on a 6 371 km sphere (well below
 * the 1 cm this is compared with for differences of a few millimetres). */
static double horiz_m(double lat1, double lon1, double lat2, double lon2) {
  const double dn = (lat2 - lat1) * D2R * 6.371e6;
  const double de = (lon2 - lon1) * D2R * 6.371e6 * cos(lat1 * D2R);
  return hypot(dn, de);
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

static void test_one_hour_10hz(void **state) {
  (void)state;
  /* 1. The library scene, output at 10 Hz, one run. */
  char *scene = nav_test_slurp_alloc(SOURCE_SCENE);
  assert_non_null(scene);
  char *out = strstr(scene, "output:\n  rate_hz: 1\n");
  if (!out) fail_msg("%s: no \"output:\\n  rate_hz: 1\" to change", SOURCE_SCENE);
  const size_t head = (size_t)(out - scene);
  char *variant = malloc(strlen(scene) + 16);
  assert_non_null(variant);
  snprintf(variant, strlen(scene) + 16, "%.*soutput:\n  rate_hz: 10\n%s", (int)head, scene,
           out + strlen("output:\n  rate_hz: 1\n"));
  nav_test_write_file(WORK, "hour-source.yaml", variant);
  free(variant);
  free(scene);
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "run hour-source.yaml --runs 1 --out src --quiet");
  if (r->code != 0) fail_msg("source run: exit %d\n%s", r->code, r->err);

  /* 2. Its truth as a KF-GINS .nav file (GPS week 2300, seconds of week from 100000 s). */
  size_t n = 0;
  double *t = load_truth(WORK "/src/truth.csv", &n);
  assert_true(n > 2);
  const double span = t[(n - 1) * TRUTH_COLS] - t[0];
  const double rate = (double)(n - 1) / span;
  print_message("source truth: %zu rows over %.1f s (%.4f Hz)\n", n, span, rate);
  assert_true(span >= 3600.0);
  /* Rows every 0.1 s; the last may be closer (the scene's end is not on the 10 Hz grid). */
  for (size_t i = 1; i + 1 < n; ++i)
    assert_true(fabs(t[i * TRUTH_COLS] - t[(i - 1) * TRUTH_COLS] - 0.1) < 1e-9);
  assert_true(t[(n - 1) * TRUTH_COLS] - t[(n - 2) * TRUTH_COLS] <= 0.1 + 1e-9);
  FILE *f = fopen(WORK "/hour.nav", "w");
  assert_non_null(f);
  for (size_t i = 0; i < n; ++i) {
    const double *x = &t[i * TRUTH_COLS];
    fprintf(f, "2300 %.6f %.12f %.12f %.6f %.6f %.6f %.6f %.9f %.9f %.9f\n", 100000.0 + x[0], x[1], x[2], x[3], x[7],
            x[8], x[9], x[10], x[11], x[12]);
  }
  assert_int_equal(fclose(f), 0);

  /* 3. The recorded scene: knots at 10 Hz. */
  nav_test_write_file(WORK, "hour.yaml",
                      "format_version: 1\nname: hour-recorded\nearth: {model: wgs84}\n"
                      "trajectory:\n  type: recorded\n"
                      "  recorded: {file: hour.nav, format: kf_gins_nav, knot_rate_hz: 10, pos_sd_m: 0.01, "
                      "vel_sd_mps: 0.01}\n"
                      "imu: {rate_hz: 100}\nnavigation: {scheme: free_ins, algorithm: high_order, frame: ned}\n"
                      "output: {rate_hz: 1}\nsimulation: {seed: 1, runs: 1, threads: 1}\n");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check hour.yaml");
  if (r->code != 0) fail_msg("check: exit %d\n%s", r->code, r->err);
  print_message("%s", r->out);
  char pat[200];
  snprintf(pat, sizeof pat, "recorded [^ ]*hour\\.nav: %zu samples fitted; residuals of the fit: position RMS [0-9.e+-]+ m",
           n);
  nav_test_assert_matches(r->out, pat);
  assert_null(strstr(r->err, "outrun"));

  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "run hour.yaml --out rec");
  if (r->code != 0) fail_msg("run: exit %d\n%s", r->code, r->err);
  nav_test_assert_matches(r->out, pat);
  nav_test_assert_matches(r->out, "simulated  1 run of 3[6-9][0-9][0-9]\\.[0-9]+ s");
  char *sum = nav_test_slurp_alloc(WORK "/rec/summary.json");
  assert_non_null(sum);
  const char *fit = strstr(sum, "\"recorded_fit\"");
  assert_non_null(fit);
  assert_true(json_number(fit, "samples") == (double)n);
  const double pos_rms = json_number(fit, "pos_rms_m"), vel_rms = json_number(fit, "vel_rms_mps");
  const double att_rms = json_number(fit, "att_rms_deg");
  print_message("one hour at 10 Hz, 10 Hz knots (%.0f control points): residuals position RMS %.3g mm, velocity RMS "
                "%.3g mm/s, attitude RMS %.3g deg\n",
                ceil(span * 10.0 - 1e-9) + 5.0, pos_rms * 1e3, vel_rms * 1e3, att_rms);
  /* A smooth jerk-limited path written with 1e-12 deg, 1 um and 1e-6 m/s: the residuals are
   * the spline's and the rounding's, far below a centimetre. */
  assert_true(pos_rms >= 0.0 && pos_rms < 0.01);
  assert_true(vel_rms >= 0.0 && vel_rms < 0.01);
  assert_null(strstr(fit, "\"warning\""));
  free(sum);

  /* The same reference with knots at 20 Hz, twice the sample rate: the knots-outrun warning. */
  char *yaml = nav_test_slurp_alloc(WORK "/hour.yaml");
  assert_non_null(yaml);
  char *k = strstr(yaml, "knot_rate_hz: 10");
  assert_non_null(k);
  k[14] = '2'; /* "knot_rate_hz: 20" */
  nav_test_write_file(WORK, "hour20.yaml", yaml);
  free(yaml);
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check hour20.yaml");
  if (r->code != 0) fail_msg("check at 20 Hz knots: exit %d\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, "warning: trajectory\\.recorded: .*outrun the samples");

  /* 4. The run's truth (1 Hz) against the source truth at the same times, over the whole hour. */
  size_t m = 0;
  double *u = load_truth(WORK "/rec/truth.csv", &m);
  assert_true(m > 3600);
  double worst = 0.0, t_worst = 0.0;
  size_t compared = 0;
  for (size_t i = 0; i < m; ++i) {
    const double *y = &u[i * TRUTH_COLS];
    const size_t j = (size_t)llround(y[0] * 10.0);
    assert_true(j < n);
    const double *x = &t[j * TRUTH_COLS];
    assert_true(fabs(x[0] - y[0]) < 1e-6);
    const double d = horiz_m(x[1], x[2], y[1], y[2]);
    if (d > worst) {
      worst = d;
      t_worst = y[0];
    }
    ++compared;
  }
  print_message("run truth vs source truth: %zu epochs, largest horizontal difference %.3g mm at t = %.0f s\n",
                compared, worst * 1e3, t_worst);
  assert_true(u[(m - 1) * TRUTH_COLS] >= 3600.0);
  assert_true(worst < 0.01);
  free(u);
  free(t);
}

static void test_shared_adis_10hz_knots(void **state) {
  (void)state;
  FILE *probe = fopen(SHARED_ADIS, "r");
  if (!probe) {
    print_message("skipped: %s is not here\n", SHARED_ADIS);
    skip();
  }
  size_t lines = 0;
  for (int c = fgetc(probe); c != EOF; c = fgetc(probe))
    if (c == '\n') ++lines;
  fclose(probe);
  char text[1024];
  snprintf(text, sizeof text,
           "format_version: 1\nname: adis-10hz-knots\nearth: {model: wgs84}\n"
           "trajectory:\n  type: recorded\n"
           "  recorded: {file: %s, format: kf_gins_nav, knot_rate_hz: 10, pos_sd_m: 0.01, vel_sd_mps: 0.01}\n"
           "imu: {rate_hz: 100}\nnavigation: {scheme: free_ins, algorithm: high_order, frame: ned}\n"
           "output: {rate_hz: 1}\nsimulation: {seed: 1, runs: 1, threads: 1}\n",
           SHARED_ADIS);
  nav_test_write_file(WORK, "adis.yaml", text);
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "run adis.yaml --out adis");
  if (r->code != 0) fail_msg("run: exit %d\n%s", r->code, r->err);
  print_message("%s", r->out);
  char pat[160];
  snprintf(pat, sizeof pat, "truth\\.nav: %zu samples fitted; residuals of the fit: position RMS [0-9.e+-]+ m", lines);
  nav_test_assert_matches(r->out, pat);
  char *sum = nav_test_slurp_alloc(WORK "/adis/summary.json");
  assert_non_null(sum);
  const char *fit = strstr(sum, "\"recorded_fit\"");
  assert_non_null(fit);
  const double span = json_number(sum, "duration_s");
  print_message("shared ADIS16465 reference: %zu samples over %.1f s, 10 Hz knots: %.0f control points\n", lines, span,
                ceil(span * 10.0 - 1e-9) + 5.0);
  assert_true(ceil(span * 10.0 - 1e-9) + 5.0 > 1280.0); /* beyond the old cap */
  assert_true(json_number(fit, "samples") == (double)lines);
  assert_true(json_number(fit, "pos_rms_m") >= 0.0);
  free(sum);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_one_hour_10hz),
      cmocka_unit_test(test_shared_adis_10hz_knots),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
