/*
 * Issue 25, "errors where the input is": bad input is reported where it is - a FILE:LINE:COL in
 * the file the user gave, or the command-line argument it came from - with exit 2, before any
 * work and without replacing anything:
 *   - navsim sweep: a grid value is named by its --param and grid point, a problem in the file is
 *     placed in the file as written (not in the edited text the reader sees), every grid point is
 *     checked before the first is computed, and one field given twice is refused;
 *   - navsim import: the scene is validated before it is written; a refused import leaves an
 *     existing scene byte-identical and points into the track file;
 *   - navsim replay: recorded values that would make the filter non-finite are reported at
 *     FILE:LINE:COL before the run.
 *
 * NAVSIM_EXE, NAV_TEST_DATA_DIR and NAV_TEST_WORK_DIR come from the build.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define navsim(...) nav_test_run_clif(NAVSIM_EXE, WORK, NULL, __VA_ARGS__)

/* Flow mappings and a comment: the libfyaml-emitted text the reader sees has other lines. */
static const char k_sweep_scene[] =
    "# sweep input errors (issue 25)\n"
    "format_version: 1\n"
    "name: sweep-input\n"
    "earth: {model: flat, origin: {lat_deg: 45, lon_deg: 0, h_m: 0}}\n"
    "trajectory: {type: parametric, duration_s: 10}\n"
    "imu:\n"
    "  rate_hz: 100\n"
    "  catalog: \"Xsens MTi-300\"\n"
    "initial_errors: {position_m: 1, velocity_mps: 0.1, attitude_deg: 0.1}\n"
    "output: {rate_hz: 10}\n"
    "simulation: {seed: 3, runs: 2}\n"
    "requirements:\n"
    "  - {id: h-rms, metric: horizontal_position, statistic: rms, limit: 10, unit: km}\n";

static int setup(void **state) {
  (void)state;
  if (nav_test_fresh_dir(WORK) != 0) return -1;
  nav_test_write_file(WORK, "sweep.yaml", k_sweep_scene);
  return 0;
}

static bool exists(const char *name) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  struct stat st;
  return stat(path, &st) == 0;
}

/* A grid value from the command line is named by its --param, value and point; the bad point is
   the last, and no point before it is computed (it used to be found after them, at
   "sweep.yaml:13:12" in this 13-line file). */
static void test_issue_25_sweep_grid_value_named_before_work(void **state) {
  (void)state;
  nav_cli_result *r = navsim("sweep sweep.yaml --param imu.rate_hz=100:-1:3 --runs 1 --out sw1");
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, "^navsim sweep: --param imu\\.rate_hz: grid value -1 at point 3: must be > 0");
  if (strstr(r->err, "sweep.yaml:")) fail_msg("a grid value was placed in the file:\n%s", r->err);
  if (strstr(r->out, "point ")) fail_msg("grid points were computed before the bad one was found:\n%s", r->out);
  nav_test_assert_matches(r->err, "^navsim sweep: 1 of 3 grid points is not a valid scene; nothing was computed$");
  assert_false(exists("sw1"));
}

/* A problem of the file that a grid value exposes is placed in the file as the user wrote it. */
static void test_issue_25_sweep_file_location(void **state) {
  (void)state;
  nav_cli_result *r = navsim("sweep sweep.yaml --param imu.rate_hz=5:5:1 --runs 1 --out sw2");
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  /* output: {rate_hz: 10} is line 10; its value at column 19 */
  nav_test_assert_matches(r->err, "^sweep\\.yaml:10:19: error: output\\.rate_hz: must not exceed imu\\.rate_hz \\(5 Hz\\) "
                                  "\\(grid point 1: --param imu\\.rate_hz=5\\)$");
  assert_false(exists("sw2"));
  /* The same scene with valid grid values still sweeps. */
  r = navsim("sweep sweep.yaml --param imu.rate_hz=100:50:2 --runs 1 --out sw3");
  if (r->code != 0) fail_msg("exit %d; stderr:\n%s", r->code, r->err);
  assert_true(exists("sw3/sweep.csv"));
}

/* Two --param with one path: refused (the first used to be ignored silently). */
static void test_issue_25_sweep_duplicate_param(void **state) {
  (void)state;
  nav_cli_result *r =
      navsim("sweep sweep.yaml --param imu.rate_hz=100:200:2 --param imu.rate_hz=50:50:1 --runs 1 --out sw4");
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, "^navsim sweep: --param imu\\.rate_hz and --param imu\\.rate_hz set the same field");
  r = navsim("sweep sweep.yaml --param initial_errors.attitude_deg=0.1:0.2:2 "
             "--param initial_errors.attitude_deg[2]=1:1:1 --runs 1 --out sw4");
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, "set the same field");
  assert_false(exists("sw4"));
}

/* A track that gives an invalid scene: exit 2 at the track point, and the existing scene is
   left byte-identical (it used to be replaced by a scene that fails check, exit 1); a valid
   track still replaces it. */
static void test_issue_25_import_never_replaces_a_valid_scene(void **state) {
  (void)state;
  static const char *bad[] = {"round-the-world.gpx", "ele-huge.gpx"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    nav_test_write_file(WORK, "mine.yaml", k_sweep_scene);
    nav_cli_result *r = navsim("import '%s/hostile/tracks/%s' --out mine.yaml", NAV_TEST_DATA_DIR, bad[i]);
    if (r->code != 2) fail_msg("import %s: exit %d, expected 2; stderr:\n%s", bad[i], r->code, r->err);
    char pattern[256];
    snprintf(pattern, sizeof pattern, "^[^ ]*/hostile/tracks/%s:[0-9]+:[0-9]+: error: ", bad[i]);
    nav_test_assert_matches(r->err, pattern);
    char *now = nav_test_slurp_alloc(WORK "/mine.yaml");
    assert_non_null(now);
    if (strcmp(now, k_sweep_scene) != 0) fail_msg("import %s replaced the existing scene:\n%s", bad[i], now);
    free(now);
  }
  /* --accept-distance: this plan strays 7.8 m from the track, beyond the default 5 m (issue 18). */
  nav_cli_result *r = navsim("import '%s/tracks/drive.gpx' --accept-distance --out mine.yaml", NAV_TEST_DATA_DIR);
  if (r->code != 0) fail_msg("import drive.gpx: exit %d; stderr:\n%s", r->code, r->err);
  char *now = nav_test_slurp_alloc(WORK "/mine.yaml");
  assert_non_null(now);
  assert_non_null(strstr(now, "type: waypoints"));
  free(now);
}

/* A GNSS fix whose sigma would make the filter's R infinite (it gave exit 1 "R[0] = inf is not
   finite"), placed after the end of the IMU data: the whole file is checked before the run, so it
   is reported at FILE:LINE:COL with exit 2 although the run would never reach it, and no result
   directory appears. */
static void test_issue_25_replay_values_checked_before_the_run(void **state) {
  (void)state;
  char *good = nav_test_slurp_alloc(NAV_TEST_DATA_DIR "/replay/GNSS-100195-100245.txt");
  assert_non_null(good);
  int lines = 0;
  for (const char *p = good; *p; ++p) lines += *p == '\n';
  const size_t n = strlen(good);
  char *text = malloc(n + 256);
  assert_non_null(text);
  snprintf(text, n + 256, "%s100300.000 31.50818332870 120.40198876855 -0.0488 1e300 0.020 0.050\n", good);
  nav_test_write_file(WORK, "gnss-late-huge.txt", text);
  free(text);
  free(good);
  nav_cli_result *r = navsim("replay --imu '%s/replay/IMU-100195-100245.txt' --gnss gnss-late-huge.txt "
                             "--truth '%s/replay/truth-100195-100245-20Hz.nav' --out rp --quiet",
                             NAV_TEST_DATA_DIR, NAV_TEST_DATA_DIR);
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  char pattern[256];
  snprintf(pattern, sizeof pattern,
           "^gnss-late-huge\\.txt:%d:51: error: column 5 \\(sd_n_m\\): standard deviation 1e\\+300 m exceeds 1000 m",
           lines + 1);
  nav_test_assert_matches(r->err, pattern);
  assert_false(exists("rp"));
}

/* Issue 23: the IMU file is read while the navigation already runs on its first records. A bad
   record in its last line still gives the report of the check before the run - FILE:LINE:COL,
   exit 2 - and nothing reaches the disk: no result directory, not even the missing parents of
   --out. With the GNSS file bad as well, the IMU file's error is the one reported, as when the IMU
   file was checked first; a bad scene, read while the IMU file is, is reported alone. A good run into
   the same --out then works. */
static void test_issue_23_replay_imu_read_during_the_run(void **state) {
  (void)state;
  char *good = nav_test_slurp_alloc(NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt");
  assert_non_null(good);
  int lines = 0;
  for (const char *p = good; *p; ++p) lines += *p == '\n';
  const size_t n = strlen(good);
  char *text = malloc(n + 256);
  assert_non_null(text);
  snprintf(text, n + 256, "%s100300.000000 1e-6 2e-6 3e-6 0.1 0.2 9.8e\n", good);
  nav_test_write_file(WORK, "imu-late-bad.txt", text);
  free(text);
  free(good);
  char pattern[256];
  snprintf(pattern, sizeof pattern,
           "^imu-late-bad\\.txt:%d:38: error: column 7 \\(dvel_z_mps\\): expected a number, found \"9\\.8e\"", lines + 1);
  nav_cli_result *r = navsim("replay --imu imu-late-bad.txt --gnss '%s/replay/GNSS-100195-100245.txt' "
                             "--truth '%s/replay/truth-100195-100245-20Hz.nav' --out late/deeper/rp --quiet",
                             NAV_TEST_DATA_DIR, NAV_TEST_DATA_DIR);
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, pattern);
  assert_false(exists("late"));
  /* GNSS file bad too (a sigma of 1e300 in its first record): the IMU file's error comes first. */
  nav_test_write_file(WORK, "gnss-bad-first.txt",
                      "100195.000 31.50818332870 120.40198876855 -0.0488 1e300 0.020 0.050\n");
  r = navsim("replay --imu imu-late-bad.txt --gnss gnss-bad-first.txt "
             "--truth '%s/replay/truth-100195-100245-20Hz.nav' --out late/deeper/rp --quiet",
             NAV_TEST_DATA_DIR);
  if (r->code != 2) fail_msg("exit %d, expected 2; stderr:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, pattern);
  if (strstr(r->err, "gnss-bad-first")) fail_msg("the GNSS error was reported first:\n%s", r->err);
  assert_false(exists("late"));
  /* The IMU file starts being read before the scene: a bad scene is still the error reported, alone
     and first, whether the IMU file is bad or missing, and nothing is written. */
  nav_test_write_file(WORK, "bad-scene.yaml", "format_version: 1\nnavigation:\n  algorithm: bogus\n");
  const char *imus[2] = {"imu-late-bad.txt", "no-such-imu.txt"};
  for (int k = 0; k < 2; ++k) {
    r = navsim("replay --imu %s --gnss gnss-bad-first.txt --truth '%s/replay/truth-100195-100245-20Hz.nav' "
               "--scene bad-scene.yaml --out late/deeper/rp --quiet",
               imus[k], NAV_TEST_DATA_DIR);
    if (r->code != 2) fail_msg("%s: exit %d, expected 2; stderr:\n%s", imus[k], r->code, r->err);
    nav_test_assert_matches(r->err, "^bad-scene\\.yaml:3:14: error: navigation\\.algorithm: ");
    if (strstr(r->err, "imu") || strstr(r->err, "gnss-bad-first"))
      fail_msg("%s: an input other than the scene reported:\n%s", imus[k], r->err);
    assert_false(exists("late"));
  }
  /* A good scene: the missing IMU file is reported then (before the bad GNSS file). */
  r = navsim("replay --imu no-such-imu.txt --gnss gnss-bad-first.txt --truth '%s/replay/truth-100195-100245-20Hz.nav' "
             "--out late/deeper/rp --quiet",
             NAV_TEST_DATA_DIR);
  if (r->code == 0) fail_msg("exit 0 with a missing IMU file; stderr:\n%s", r->err);
  nav_test_assert_matches(r->err, "^no-such-imu\\.txt: error: cannot open the IMU file");
  if (strstr(r->err, "gnss-bad-first")) fail_msg("the GNSS error was reported:\n%s", r->err);
  assert_false(exists("late"));
  /* The good file: the result directory appears, with its files. */
  r = navsim("replay --imu '%s/replay/IMU-100195-100245.txt' --gnss '%s/replay/GNSS-100195-100245.txt' "
             "--truth '%s/replay/truth-100195-100245-20Hz.nav' --out late/deeper/rp --quiet",
             NAV_TEST_DATA_DIR, NAV_TEST_DATA_DIR, NAV_TEST_DATA_DIR);
  if (r->code != 0) fail_msg("exit %d, expected 0; stderr:\n%s", r->code, r->err);
  assert_true(exists("late/deeper/rp/nav.csv"));
  assert_true(exists("late/deeper/rp/summary.json"));
}

/* The "stats" block of replay's summary.json (from its key to the next top-level key). */
static char *stats_block(const char *summary_path) {
  char *js = nav_test_slurp_alloc(summary_path);
  assert_non_null(js);
  const char *a = strstr(js, "\n  \"stats\": {");
  assert_non_null(a);
  const char *b = strstr(a, "\n  \"final\": {");
  assert_non_null(b);
  char *out = malloc((size_t)(b - a) + 1);
  assert_non_null(out);
  memcpy(out, a, (size_t)(b - a));
  out[b - a] = '\0';
  free(js);
  return out;
}

/* Issue 23: the "stats" accumulators are made before the run when the IMU file's size bounds its
   record count below NAV_SIM_METRIC_MAX_VALUES (stride 1), else the values wait for the count at
   the file's end. The same records with 30 MB of comment lines before them take the second path
   (the size allows more than 2 million records) and must give the same block and the same rows. */
static void test_issue_23_replay_stats_either_path(void **state) {
  (void)state;
  char *good = nav_test_slurp_alloc(NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt");
  assert_non_null(good);
  const size_t n = strlen(good);
  const char pad[] = "# padding to make the file large without records (navsim replay's statistics path)\n";
  const size_t pn = sizeof pad - 1, lines = (30u << 20) / pn + 1;
  char *text = malloc(lines * pn + n + 1);
  assert_non_null(text);
  for (size_t i = 0; i < lines; ++i) memcpy(text + i * pn, pad, pn);
  memcpy(text + lines * pn, good, n + 1);
  nav_test_write_file(WORK, "imu-padded.txt", text);
  free(text);
  free(good);
  const char *imus[2] = {"'" NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt'", "imu-padded.txt"};
  const char *outs[2] = {"stats-plain", "stats-padded"};
  for (int k = 0; k < 2; ++k) {
    nav_cli_result *r = navsim("replay --imu %s --gnss '%s/replay/GNSS-100195-100245.txt' "
                               "--truth '%s/replay/truth-100195-100245-20Hz.nav' --init none --out %s --quiet",
                               imus[k], NAV_TEST_DATA_DIR, NAV_TEST_DATA_DIR, outs[k]);
    if (r->code != 0) fail_msg("%s: exit %d; stderr:\n%s", imus[k], r->code, r->err);
  }
  char *a = stats_block(WORK "/stats-plain/summary.json"), *b = stats_block(WORK "/stats-padded/summary.json");
  if (strcmp(a, b) != 0) fail_msg("the stats blocks differ:\n%s\n---\n%s", a, b);
  assert_non_null(strstr(a, "\"stride\": 1,"));
  free(a);
  free(b);
  static const char *const files[3] = {"errors.csv", "nav.csv", "truth.csv"};
  for (int i = 0; i < 3; ++i) {
    char pa[1024], pb[1024];
    snprintf(pa, sizeof pa, "%s/stats-plain/%s", WORK, files[i]);
    snprintf(pb, sizeof pb, "%s/stats-padded/%s", WORK, files[i]);
    char *ta = nav_test_slurp_alloc(pa), *tb = nav_test_slurp_alloc(pb);
    assert_non_null(ta);
    assert_non_null(tb);
    if (strcmp(ta, tb) != 0) fail_msg("%s differs between the two paths", files[i]);
    free(ta);
    free(tb);
  }
  char big[1024];
  snprintf(big, sizeof big, "%s/imu-padded.txt", WORK);
  (void)remove(big);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_issue_25_sweep_grid_value_named_before_work),
      cmocka_unit_test(test_issue_25_sweep_file_location),
      cmocka_unit_test(test_issue_25_sweep_duplicate_param),
      cmocka_unit_test(test_issue_25_import_never_replaces_a_valid_scene),
      cmocka_unit_test(test_issue_25_replay_values_checked_before_the_run),
      cmocka_unit_test(test_issue_23_replay_imu_read_during_the_run),
      cmocka_unit_test(test_issue_23_replay_stats_either_path),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
