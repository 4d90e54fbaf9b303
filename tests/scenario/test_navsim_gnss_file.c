/*
 * Contract of gnss.file (issue 18, "Real data in and out"; docs/gnss-file.md): recorded GNSS
 * fixes in KF-GINS text drive the INS/GNSS filter instead of the receiver model.
 *
 *  - scenes/gnss-file-adis16465.yaml (the real ADIS16465 drive's recorded reference and its real
 *    RTK fixes, a simulated catalog ADIS16465) runs; the terminal and summary.json say that the
 *    GNSS came from a file; gnss.csv holds the file's fixes in the run, none inside the scene's
 *    outage; at the fixes' epochs the horizontal error against the reference has an RMS below
 *    three times the RMS of the fixes' own horizontal sigmas (the bound comes from the file).
 *  - The same drive with every fix moved 10 m north: the solution follows the fixes (the mean
 *    north error at the fix epochs is 10 m within the same bound), so the file's fixes, at the
 *    file's times, are what the filter used.
 *  - A 7-column file with a simulated reference (stationary): the first fix is at scene time 0.
 *  - A malformed line is an error at FILE:LINE:COL with exit 2 and no result directory; a scheme
 *    without GNSS aiding refuses gnss.file (exit 2).
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
#define SCENE NAV_SOURCE_DIR "/scenes/gnss-file-adis16465.yaml"
#define REF NAV_SOURCE_DIR "/tests/data/recorded/adis16465-truth-116454-116754.nav"
#define GNSS NAV_SOURCE_DIR "/tests/data/recorded/adis16465-gnss-posvel.txt"
#define PI 3.14159265358979323846

/* Rows of a CSV file with a header: @p cols numbers each (the first cols columns). */
typedef struct table {
  double *v;
  size_t rows, cols;
} table;

static table load_csv(const char *path, size_t cols) {
  table t = {NULL, 0, cols};
  char *text = nav_test_slurp_alloc(path);
  if (!text) fail_msg("cannot read %s", path);
  size_t cap = 256;
  t.v = malloc(cap * cols * sizeof *t.v);
  assert_non_null(t.v);
  char *p = strchr(text, '\n');
  p = p ? p + 1 : text + strlen(text);
  while (*p) {
    char *eol = strchr(p, '\n');
    if (eol) *eol = '\0';
    if (*p) {
      if (t.rows == cap) {
        cap *= 2;
        t.v = realloc(t.v, cap * cols * sizeof *t.v);
        assert_non_null(t.v);
      }
      char *q = p;
      for (size_t c = 0; c < cols; ++c) {
        char *end = NULL;
        t.v[t.rows * cols + c] = strtod(q, &end);
        if (end == q) fail_msg("%s: row %zu: column %zu is not a number", path, t.rows + 1, c + 1);
        q = end;
        if (*q == ',') ++q;
      }
      t.rows++;
    }
    if (!eol) break;
    p = eol + 1;
  }
  free(text);
  return t;
}

static double at(const table *t, size_t r, size_t c) {
  return t->v[r * t->cols + c];
}

/* Errors of run 0 at the epochs of gnss.csv (the applied fixes; output rate 10 Hz holds them). */
typedef struct fix_stats {
  size_t fixes, matched, in_outage;
  double h_rms_m, n_mean_m, sigma_h_rms_m;
} fix_stats;

static fix_stats fix_epoch_errors(const char *dir, double out_t0, double out_t1) {
  char path[600];
  snprintf(path, sizeof path, "%s/gnss.csv", dir);
  table g = load_csv(path, 10);
  snprintf(path, sizeof path, "%s/errors.csv", dir);
  table e = load_csv(path, 5);
  fix_stats s = {g.rows, 0, 0, 0.0, 0.0, 0.0};
  double h2 = 0.0, n = 0.0, s2 = 0.0;
  size_t j = 0;
  for (size_t i = 0; i < g.rows; ++i) {
    const double t = at(&g, i, 0);
    if (t >= out_t0 && t < out_t1) s.in_outage++;
    s2 += pow(at(&g, i, 7), 2) + pow(at(&g, i, 8), 2);
    while (j < e.rows && at(&e, j, 0) < t - 1e-6)
      ++j;
    if (j == e.rows || fabs(at(&e, j, 0) - t) > 1e-6) continue;
    s.matched++;
    h2 += pow(at(&e, j, 4), 2);
    n += at(&e, j, 1);
  }
  if (s.matched > 0) {
    s.h_rms_m = sqrt(h2 / (double)s.matched);
    s.n_mean_m = n / (double)s.matched;
  }
  if (g.rows > 0) s.sigma_h_rms_m = sqrt(s2 / (double)g.rows);
  free(g.v);
  free(e.v);
  return s;
}

/* The integer after "key": in @p json (first occurrence), or -1. */
static long json_long(const char *json, const char *key) {
  char pat[128];
  snprintf(pat, sizeof pat, "\"%s\": ", key);
  const char *p = strstr(json, pat);
  return p ? strtol(p + strlen(pat), NULL, 10) : -1;
}

static void test_real_drive(void **state) {
  (void)state;
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --runs 1 --out '%s/real'", SCENE, WORK);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  nav_test_assert_matches(
      r->out, "gnss +recorded fixes from .*adis16465-gnss-posvel\\.txt: 203 fixes \\(position \\+ "
              "velocity\\).*scene time = file time - 116454\\.000 s");
  char *summary = nav_test_slurp_alloc(WORK "/real/summary.json");
  assert_non_null(summary);
  nav_test_assert_matches(
      summary, "\"gnss_source\": \\{\"kind\": \"file\", \"file\": \"[^\"]*adis16465-gnss-posvel\\.txt\"");
  const long used = json_long(summary, "fixes_in_run_outside_outages");
  free(summary);
  const fix_stats s = fix_epoch_errors(WORK "/real", 20.0, 45.0);
  /* Every applied fix is in gnss.csv and at an output epoch; none in the outage [20, 45) s. */
  assert_int_equal((long)s.fixes, used);
  assert_true(s.fixes > 100);
  assert_int_equal(s.matched, s.fixes);
  assert_int_equal(s.in_outage, 0);
  /* The fixes' sigmas say how well the reference can be followed: RTK level, 0.25 m RMS here. */
  const double bound = 3.0 * s.sigma_h_rms_m;
  print_message("horizontal error at %zu fix epochs: RMS %.3f m; bound 3 x RMS fix sigma = %.3f m\n",
                s.matched, s.h_rms_m, bound);
  assert_true(s.h_rms_m > 0.0);
  assert_true(s.h_rms_m < bound);
  /* summary.json "setup" and the report state what produced the run (issue 18). */
  summary = nav_test_slurp_alloc(WORK "/real/summary.json");
  assert_non_null(summary);
  nav_test_assert_matches(
      summary, "\"setup\": \\{\"scheme\": \"ins_gnss\",\n +\"imu\": \\{\"catalog\": \"ADIS16465-1\"");
  nav_test_assert_matches(summary, "\"  +arw_deg_per_sqrt_h: 0\\.15\"");
  nav_test_assert_matches(summary, "\"receiver\": \\{\"source\": \"file\"");
  nav_test_assert_matches(summary, "\"outages_s\": \\[\\[20, 45\\]\\]");
  free(summary);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "report '%s/real' --out '%s/rep'", WORK, WORK);
  char *page = nav_test_slurp_alloc(WORK "/rep/report.html");
  if (!page) fail_msg("no report.html (exit %d): %s", r->code, r->err);
  nav_test_assert_matches(page, "<h2>Setup</h2>");
  nav_test_assert_matches(page, "navigation scheme</th><td class=\"l\">ins_gnss<");
  nav_test_assert_matches(page, "IMU</th><td class=\"l\">ADIS16465-1<pre>");
  nav_test_assert_matches(page, "arw_deg_per_sqrt_h: 0\\.15\n");
  nav_test_assert_matches(page, "recorded fixes from a file");
  nav_test_assert_matches(page, "GNSS outages \\[s\\]</th><td class=\"l\">\\[\\[20, 45\\]\\]<");
  nav_test_assert_matches(page, "lever arm.*<td class=\"l\">-0\\.37, 0\\.008, 0\\.353<");
  nav_test_assert_matches(page, "seed</th><td class=\"l\">1<");
  nav_test_assert_matches(page, "Recorded reference: fit residuals");
  nav_test_assert_matches(page, "<td class=\"l\">position</td><td>[0-9.e-]+</td><td>[0-9.e-]+</td>");
  free(page);
}

/* WGS-84 meridian radius of curvature at latitude @p lat [rad] (Groves 2.105). */
static double meridian_radius(double lat) {
  const double a = 6378137.0, e2 = 6.69437999014e-3;
  const double s = sin(lat);
  return a * (1.0 - e2) / pow(1.0 - e2 * s * s, 1.5);
}

/* @p scene_text with every occurrence of @p from replaced by @p to (malloc'd). */
static char *replace_all(const char *text, const char *from, const char *to) {
  size_t n = 0;
  for (const char *p = strstr(text, from); p; p = strstr(p + strlen(from), from))
    ++n;
  char *out = malloc(strlen(text) + n * strlen(to) + 1);
  assert_non_null(out);
  char *o = out;
  const char *p = text;
  for (const char *q = strstr(p, from); q; q = strstr(p, from)) {
    memcpy(o, p, (size_t)(q - p));
    o += q - p;
    memcpy(o, to, strlen(to));
    o += strlen(to);
    p = q + strlen(from);
  }
  strcpy(o, p);
  return out;
}

/* The example scene with its two data files at absolute paths and gnss.file = @p gnss_file. */
static void write_scene(const char *name, const char *gnss_file) {
  char *text = nav_test_slurp_alloc(SCENE);
  assert_non_null(text);
  char *a = replace_all(text, "../tests/data/recorded/adis16465-truth-116454-116754.nav", REF);
  char *b = replace_all(a, "../tests/data/recorded/adis16465-gnss-posvel.txt", gnss_file);
  nav_test_write_file(WORK, name, b);
  free(text);
  free(a);
  free(b);
}

static void test_fixes_drive_the_filter(void **state) {
  (void)state;
  /* Every fix moved north by 10 m (latitude + 10 m / M(lat)); the rest of each line as written. */
  char *text = nav_test_slurp_alloc(GNSS);
  assert_non_null(text);
  FILE *f = fopen(WORK "/shifted.txt", "w");
  assert_non_null(f);
  for (char *line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
    char *end = NULL;
    const double t = strtod(line, &end);
    char *rest = NULL;
    const double lat = strtod(end, &rest);
    const double lat2 = lat + 10.0 / meridian_radius(lat * PI / 180.0) * 180.0 / PI;
    fprintf(f, "%.6f %.12f%s\n", t, lat2, rest);
  }
  fclose(f);
  free(text);
  write_scene("shifted.yaml", WORK "/shifted.txt");
  nav_cli_result *r = nav_test_run_clif(
      NAVSIM_EXE, WORK, NULL, "run '%s/shifted.yaml' --runs 1 --quiet --out '%s/shifted'", WORK, WORK);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  const fix_stats s = fix_epoch_errors(WORK "/shifted", 20.0, 45.0);
  const double bound = 3.0 * s.sigma_h_rms_m;
  print_message("10 m north shift: mean north error at %zu fixes %.3f m (bound %.3f m)\n", s.matched,
                s.n_mean_m, bound);
  assert_near(s.n_mean_m, 10.0, bound);
}

static void test_simulated_reference_7_columns(void **state) {
  (void)state;
  /* Position-only fixes of a car standing still at the origin, 1 Hz from file time 500000 s:
   * scene time = file time - 500000 s (the first fix). */
  FILE *f = fopen(WORK "/still.txt", "w");
  assert_non_null(f);
  for (int k = 0; k <= 60; ++k)
    fprintf(f, "%d.000 30.5 114.3 20.0 0.02 0.02 0.05\n", 500000 + k);
  fclose(f);
  nav_test_write_file(
      WORK, "still.yaml",
      "format_version: 1\nname: still\nearth: {model: wgs84, origin: {lat_deg: 30.5, lon_deg: 114.3, "
      "h_m: 20}}\ntrajectory:\n  type: test_motion\n  duration_s: 60\n  initial_attitude: {roll_deg: 0, "
      "pitch_deg: 0, yaw_deg: 0}\n  test_motion: {kind: stationary}\n"
      "imu: {rate_hz: 100, catalog: \"ADIS16465-1\"}\ngnss: {enabled: true, file: still.txt}\n"
      "navigation: {scheme: ins_gnss}\noutput: {rate_hz: 1}\nsimulation: {seed: 3, runs: 1}\n");
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s/still.yaml' --out '%s/still'", WORK, WORK);
  if (r->code != 0) fail_msg("exit %d: %s %s", r->code, r->out, r->err);
  nav_test_assert_matches(r->out,
                          "61 fixes \\(position\\), file time 500000\\.000 to 500060\\.000 s; scene time = "
                          "file time - 500000\\.000 s \\(the first fix at scene time 0\\)");
  const fix_stats s = fix_epoch_errors(WORK "/still", 1e9, 1e9);
  assert_int_equal(s.fixes, 61);
  assert_int_equal(s.matched, 61);
  assert_true(s.h_rms_m < 3.0 * s.sigma_h_rms_m);
}

static void test_bad_input(void **state) {
  (void)state;
  nav_test_write_file(WORK, "bad.txt",
                      "116454.0 30.5284656653 114.3557363642 20.65 0.01 0.011 0.054\n"
                      "116455.0 30.5284656653 north 20.65 0.01 0.011 0.054\n");
  write_scene("bad.yaml", WORK "/bad.txt");
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s/bad.yaml' --out '%s/bad'", WORK, WORK);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "bad\\.txt:2:[0-9]+: ");
  assert_false(nav_test_is_file(WORK "/bad/summary.json"));
  /* The free INS takes no fixes. */
  char *text = nav_test_slurp_alloc(WORK "/bad.yaml");
  assert_non_null(text);
  char *a = replace_all(text, "scheme: ins_gnss", "scheme: free_ins");
  char *b = replace_all(a, WORK "/bad.txt", GNSS);
  nav_test_write_file(WORK, "free.yaml", b);
  free(text);
  free(a);
  free(b);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "check '%s/free.yaml'", WORK);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "gnss\\.file.*ins_gnss and gyro_free_gnss schemes only");
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_real_drive),
      cmocka_unit_test(test_fixes_drive_the_filter),
      cmocka_unit_test(test_simulated_reference_7_columns),
      cmocka_unit_test(test_bad_input),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
