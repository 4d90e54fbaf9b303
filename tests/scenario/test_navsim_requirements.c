/*
 * navsim contract for requirements: verdicts in summary.json ("requirements": a list of {id,
 * metric, statistic, limit, unit, value, pass}) and in the terminal summary; `navsim run` exits 0
 * whether or not they pass, `--strict` exits 3 when one fails; invalid requirements exit 2 with
 * FILE:LINE:COL; verdicts do not depend on the thread count.
 *
 * NAVSIM_EXE and NAV_TEST_WORK_DIR come from the compile definitions.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <regex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
/* Run "navsim ARGS" in WORK; both streams captured. */
#define navsim(args) nav_test_run_cli(NAVSIM_EXE, WORK, NULL, (args))

/* The "requirements" list of a summary.json (from its key to the end). */
static const char *requirements_of(const char *json) {
  const char *p = strstr(json, "\"requirements\": [");
  if (!p) fail_msg("summary.json has no \"requirements\" list:\n%s", json);
  return p;
}

/* A short flat-Earth free-INS scene with a catalog IMU (errors clearly above zero), 4 runs. */
#define SCENE_HEAD                                                                                                   \
  "format_version: 1\n"                                                                                              \
  "name: req-contract\n"                                                                                             \
  "trajectory:\n"                                                                                                    \
  "  type: parametric\n"                                                                                             \
  "  duration_s: 10\n"                                                                                               \
  "imu:\n"                                                                                                           \
  "  rate_hz: 100\n"                                                                                                 \
  "  catalog: \"Xsens MTi-300\"\n"                                                                                   \
  "initial_errors: {position_m: 1, velocity_mps: 0.1, attitude_deg: 0.1}\n"                                          \
  "output: {rate_hz: 10}\n"                                                                                          \
  "simulation: {seed: 3, runs: 4}\n"

static int setup(void **state) {
  (void)state;
  if (nav_test_fresh_dir(WORK) != 0) return -1;
  nav_test_write_file(WORK, "pass.yaml",
                      SCENE_HEAD
                      "requirements:\n"
                      "  - {id: h-rms, metric: horizontal_position, statistic: rms, limit: 10, unit: km}\n"
                      "  - {id: yaw-max, metric: yaw, statistic: max, limit: 180, unit: deg}\n");
  nav_test_write_file(WORK, "fail.yaml",
                      SCENE_HEAD
                      "requirements:\n"
                      "  - {id: h-rms, metric: horizontal_position, statistic: rms, limit: 10, unit: km}\n"
                      "  - {id: v-tiny, metric: velocity, statistic: p95, limit: 1e-9, unit: cm/s}\n");
  return 0;
}

static void test_help_mentions_strict(void **state) {
  (void)state;
  nav_cli_result *r = navsim("run --help");
  assert_int_equal(r->code, 0);
  assert_non_null(strstr(r->out, "--strict"));
  assert_non_null(strstr(r->out, "3"));
}

static void test_passing_requirements(void **state) {
  (void)state;
  nav_cli_result *r = navsim("run pass.yaml --out pass-out --strict --threads 1");
  if (r->code != 0) fail_msg("navsim run --strict of a passing scene exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^requirements 2 of 2 pass$");
  nav_test_assert_matches(r->out, "^  PASS  h-rms +horizontal_position rms = [0-9.e+-]+ km <= 10 km$");
  static char js[65536];
  nav_test_slurp(WORK "/pass-out/summary.json", js, sizeof js);
  const char *q = requirements_of(js);
  nav_test_assert_matches(
      q, "\\{\"id\": \"h-rms\", \"metric\": \"horizontal_position\", \"statistic\": \"rms\", "
         "\"limit\": 10, \"unit\": \"km\", \"value\": [0-9.e+-]+, \"pass\": true");
  nav_test_assert_matches(
      q, "\\{\"id\": \"yaw-max\", \"metric\": \"yaw\", \"statistic\": \"max\", \"limit\": 180, "
         "\"unit\": \"deg\", \"value\": [0-9.e+-]+, \"pass\": true");
}

static void test_failing_requirement_exit_codes(void **state) {
  (void)state;
  /* Without --strict: exit 0, the failure in the summary and on the terminal. */
  nav_cli_result *r = navsim("run fail.yaml --out fail-out");
  if (r->code != 0) fail_msg("navsim run of a failing scene exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^requirements 1 of 2 pass$");
  nav_test_assert_matches(r->out, "^  FAIL  v-tiny +velocity p95 = [0-9.e+-]+ cm/s > 1e-09 cm/s$");
  static char js[65536];
  nav_test_slurp(WORK "/fail-out/summary.json", js, sizeof js);
  nav_test_assert_matches(requirements_of(js), "\"id\": \"v-tiny\".*\"pass\": false");
  /* --strict: exit 3, the results are still written. */
  r = navsim("run fail.yaml --out fail-strict --strict");
  assert_int_equal(r->code, 3);
  nav_test_slurp(WORK "/fail-strict/summary.json", js, sizeof js);
  nav_test_assert_matches(requirements_of(js), "\"id\": \"v-tiny\".*\"pass\": false");
  /* --strict --quiet: nothing on stdout, the failing verdict on stderr. */
  r = navsim("run fail.yaml --out fail-quiet --strict --quiet");
  assert_int_equal(r->code, 3);
  assert_string_equal(r->out, "");
  assert_non_null(strstr(r->err, "FAIL  v-tiny"));
}

static void test_verdicts_independent_of_threads(void **state) {
  (void)state;
  nav_cli_result *r = navsim("run fail.yaml --out t1 --threads 1 --quiet");
  assert_int_equal(r->code, 0);
  r = navsim("run fail.yaml --out t2 --threads 2 --quiet");
  assert_int_equal(r->code, 0);
  static char a[65536], b[65536];
  nav_test_slurp(WORK "/t1/summary.json", a, sizeof a);
  nav_test_slurp(WORK "/t2/summary.json", b, sizeof b);
  assert_string_equal(requirements_of(a), requirements_of(b));
}

static void test_invalid_requirements_exit_2(void **state) {
  (void)state;
  nav_test_write_file(WORK, "bad.yaml",
                      SCENE_HEAD "requirements:\n"
                                 "  - {id: x, metric: velocity, statistic: rms, limit: 1, unit: m/s}\n"
                                 "  - {id: y, metric: velocity, statistic: rms, limit: 1, unit: m/s}\n"
                                 "  - {id: z, metric: speed, statistic: rms, limit: 1, unit: m/s}\n");
  nav_cli_result *r = navsim("run bad.yaml --out bad-out --strict");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "^bad\\.yaml:15:21: error: requirements\\[2\\]\\.metric: expected one of");
  struct stat s;
  assert_int_not_equal(stat(WORK "/bad-out", &s), 0);
  r = navsim("check bad.yaml");
  assert_int_equal(r->code, 2);
}


/* navsim replay with a scene that has requirements: verdicts over the replayed epochs, the GNSS
 * gaps as the outages (times from the initial epoch). */
static void test_replay_verdicts(void **state) {
  (void)state;
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "cp '%s/replay/long-drive.yaml' '%s/slice.yaml' && printf '%s' >> '%s/slice.yaml'",
           NAV_TEST_DATA_DIR, WORK,
           "\nrequirements:\n"
           "  - {id: h-end, metric: horizontal_position, statistic: outage_end, limit: 5, unit: m}\n"
           "  - {id: h-tiny, metric: horizontal_position, statistic: rms, limit: 1e-6, unit: m}\n",
           WORK);
  assert_int_equal(system(cmd), 0);
  nav_cli_result *r =
      navsim("replay --imu '" NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt' --gnss '" NAV_TEST_DATA_DIR
             "/replay/GNSS-100195-100245.txt' --truth '" NAV_TEST_DATA_DIR
             "/replay/truth-100195-100245-20Hz.nav' --scene slice.yaml --outage 100220:100230 --peers none "
             "--out replay-out");
  if (r->code != 0) fail_msg("navsim replay exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^requirements 1 of 2 pass$");
  nav_test_assert_matches(r->out, "^  PASS  h-end +horizontal_position outage_end = [0-9.e+-]+ m <= 5 m$");
  /* Issue 18: replay shows the outage in the files' time base (seconds of week), not from the
   * replay's start (was [2x, 3x) s). */
  nav_test_assert_matches(r->out, "^        outage \\[1002[12][0-9.]+, 10023[0-9.]+\\) s: ");
  nav_test_assert_matches(r->out, "^  FAIL  h-tiny ");
  static char js[262144];
  nav_test_slurp(WORK "/replay-out/summary.json", js, sizeof js);
  const char *q = requirements_of(js);
  nav_test_assert_matches(
      q, "\"id\": \"h-end\", \"metric\": \"horizontal_position\", \"statistic\": \"outage_end\", "
         "\"limit\": 5, \"unit\": \"m\", \"value\": [0-9.e+-]+, \"pass\": true, \"samples\": 1, "
         "\"outages\": \\[\\{\"t0_s\": 2[0-9.]+, \"t1_s\": 3[0-9.]+, \"t_s\": ");
  nav_test_assert_matches(q, "\"id\": \"h-tiny\".*\"pass\": false");
}

/* Issue 25: a replay whose window holds no GNSS fix (the only one is at the initial epoch) is a
 * free-inertial run: labelled so, and outage_end (whose outages need fixes) is not evaluated,
 * nor is an at_time after the end; neither is a PASS. */
static void test_issue_25_replay_no_fix_applied(void **state) {
  (void)state;
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "cp '%s/replay/long-drive.yaml' '%s/nofix.yaml' && printf '%s' >> '%s/nofix.yaml'",
           NAV_TEST_DATA_DIR, WORK,
           "\nrequirements:\n"
           "  - {id: h-end, metric: horizontal_position, statistic: outage_end, limit: 5, unit: m}\n"
           "  - {id: h-late, metric: horizontal_position, statistic: at_time, time_s: 1e6, limit: 1, unit: km}\n"
           "  - {id: h-rms, metric: horizontal_position, statistic: rms, limit: 1, unit: km}\n",
           WORK);
  assert_int_equal(system(cmd), 0);
  nav_cli_result *r =
      navsim("replay --imu '" NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt' --gnss '" NAV_TEST_DATA_DIR
             "/replay/GNSS-100195-100245.txt' --truth '" NAV_TEST_DATA_DIR
             "/replay/truth-100195-100245-20Hz.nav' --scene nofix.yaml --end 100195.5 --peers none "
             "--out nofix-out");
  if (r->code != 0) fail_msg("navsim replay exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^gnss +0 fixes applied");
  nav_test_assert_matches(r->out, "^case +no GNSS fix applied$");
  nav_test_assert_matches(r->out, "^requirements 1 of 3 pass, 2 not evaluated$");
  nav_test_assert_matches(r->out, "^  N/A   h-end +horizontal_position outage_end: not evaluated: no GNSS fix was "
                                  "applied \\(limit 5 m\\)$");
  /* Issue 18: in the files' time base (the scene's t = 1e6 s counts from the first IMU epoch). */
  nav_test_assert_matches(r->out, "^  N/A   h-late +horizontal_position at_time: not evaluated: t = 1100195\\.000 s "
                                  "lies outside the run's epochs \\[100195\\.000, 100195\\.500\\] s");
  nav_test_assert_matches(r->out, "^  PASS  h-rms ");
  if (strstr(r->out, "full GNSS")) fail_msg("a run without a fix is labelled full GNSS:\n%s", r->out);
  static char js[262144];
  nav_test_slurp(WORK "/nofix-out/summary.json", js, sizeof js);
  nav_test_assert_matches(js, "\"case\": \"no GNSS fix applied\"");
  const char *q = requirements_of(js);
  nav_test_assert_matches(q, "\"id\": \"h-end\".*\"value\": null, \"pass\": false, \"samples\": 0, "
                             "\"evaluated\": false, \"reason\": \"no GNSS fix was applied\"");
  nav_test_assert_matches(q, "\"id\": \"h-late\".*\"pass\": false.*\"evaluated\": false");
}

/* Issue 25: a replay with no epoch to score (one IMU line, or a window that ends before the
 * second IMU epoch) is refused with exit 2, saying what was processed; no result directory. */
static void test_issue_25_replay_no_scored_epoch(void **state) {
  (void)state;
  char cmd[1024];
  snprintf(cmd, sizeof cmd, "head -1 '%s/replay/IMU-100195-100245.txt' > '%s/imu-one.txt'", NAV_TEST_DATA_DIR, WORK);
  assert_int_equal(system(cmd), 0);
  static const char *const imus[2] = {"imu-one.txt", NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt"};
  static const char *const extra[2] = {"", " --end 100195.004"};
  for (int k = 0; k < 2; ++k) {
    nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                                          "replay --imu '%s' --gnss '" NAV_TEST_DATA_DIR
                                          "/replay/GNSS-100195-100245.txt' --truth '" NAV_TEST_DATA_DIR
                                          "/replay/truth-100195-100245-20Hz.nav' --peers none --out empty-out%s",
                                          imus[k], extra[k]);
    if (r->code != 2) fail_msg("replay with nothing to score (%s%s) exited %d:\n%s", imus[k], extra[k], r->code, r->out);
    nav_test_assert_matches(r->err, "error: no epoch to score: 0 IMU step\\(s\\) processed from 100195.000 to "
                                    "100195.000 s");
    if (strstr(r->out, "PASS") || strstr(r->out, "scored epochs")) fail_msg("statistics printed:\n%s", r->out);
    struct stat sb;
    if (stat(WORK "/empty-out", &sb) == 0) fail_msg("a refused replay wrote its result directory");
  }
}

/* Issue 25: a requirement at_time 1e6 s on a 10 s scene, or outage_end without an outage, is
 * refused before any work by check, run, estimate and budget, at its place in the file (exit 2);
 * none of them writes a result. */
static void test_issue_25_unevaluable_requirements_refused(void **state) {
  (void)state;
  nav_test_write_file(WORK, "late.yaml",
                      SCENE_HEAD "requirements:\n"
                                 "  - {id: h-late, metric: horizontal_position, statistic: at_time, time_s: 1e6, "
                                 "limit: 1, unit: m}\n");
  nav_test_write_file(WORK, "noout.yaml",
                      SCENE_HEAD "requirements:\n"
                                 "  - {id: h-out, metric: horizontal_position, statistic: outage_end, limit: 1, unit: m}\n");
  static const char *const cmds[4] = {"check", "run", "estimate", "budget"};
  for (int k = 0; k < 4; ++k) {
    nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "%s late.yaml%s", cmds[k],
                                          k == 0 ? "" : " --out late-out");
    if (r->code != 2) fail_msg("navsim %s late.yaml exited %d:\n%s\n%s", cmds[k], r->code, r->out, r->err);
    nav_test_assert_matches(r->err, "^late\\.yaml:13:75: error: requirements\\[0\\]\\.time_s: 1e\\+06 s is after the "
                                    "end of the run \\(trajectory duration 10 s\\)");
    r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "%s noout.yaml%s", cmds[k], k == 0 ? "" : " --out late-out");
    if (r->code != 2) fail_msg("navsim %s noout.yaml exited %d:\n%s", cmds[k], r->code, r->err);
    nav_test_assert_matches(r->err, "^noout\\.yaml:13:[0-9]+: error: requirements\\[0\\]\\.statistic: outage_end needs "
                                    "a GNSS outage, and navigation\\.scheme free_ins has no GNSS");
    struct stat sb;
    if (stat(WORK "/late-out", &sb) == 0) fail_msg("navsim %s wrote a result for a refused scene", cmds[k]);
  }
}

/* navsim estimate: the requirements of estimate.json predicted from the covariance analysis
 * (wgs84 scenes); null values where there is none (flat Earth) or the statistic is not
 * predictable (max). */
static void test_estimate_predictions(void **state) {
  (void)state;
  nav_test_write_file(
      WORK, "est.yaml",
      "format_version: 1\n"
      "name: est\n"
      "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 200}}\n"
      "trajectory:\n"
      "  type: segments\n"
      "  segments:\n"
      "    v0_b_mps: [10, 0, 0]\n"
      "    items:\n"
      "      - {kind: hold, duration_s: 60}\n"
      "imu: {rate_hz: 100, catalog: \"Xsens MTi-300\"}\n"
      "gnss: {enabled: true, catalog: \"SBAS (WAAS/EGNOS class)\", outages: [[20, 40]]}\n"
      "initial_errors: {position_m: 2, velocity_mps: 0.1, attitude_deg: [0.5, 0.5, 2]}\n"
      "navigation: {scheme: ins_gnss}\n"
      "output: {rate_hz: 10}\n"
      "requirements:\n"
      "  - {id: h-end, metric: horizontal_position, statistic: outage_end, limit: 50, unit: m}\n"
      "  - {id: h-max, metric: horizontal_position, statistic: max, limit: 50, unit: m}\n");
  nav_cli_result *r = navsim("estimate est.yaml --out est-out");
  if (r->code != 0) fail_msg("navsim estimate exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^  PASS  h-end +horizontal_position outage_end = [0-9.e+-]+ m <= 50 m$");
  nav_test_assert_matches(r->out, "^  N/A   h-max ");
  static char js[1 << 20];
  nav_test_slurp(WORK "/est-out/estimate.json", js, sizeof js);
  const char *q = requirements_of(js);
  nav_test_assert_matches(
      q, "\"id\": \"h-end\", \"metric\": \"horizontal_position\", \"statistic\": \"outage_end\", "
         "\"limit\": 50, \"unit\": \"m\", \"value\": [0-9.e+-]+, \"pass\": true, \"samples\": 1, "
         "\"outages\": \\[\\{\"t0_s\": 20, \"t1_s\": 40, \"t_s\": 39\\.[89]");
  nav_test_assert_matches(q, "\"id\": \"h-max\", .*\"value\": null, \"pass\": false");
  /* Flat Earth: no covariance analysis, nothing predicted. */
  r = navsim("estimate fail.yaml --out est-flat");
  assert_int_equal(r->code, 0);
  nav_test_slurp(WORK "/est-flat/estimate.json", js, sizeof js);
  nav_test_assert_matches(requirements_of(js), "\"id\": \"v-tiny\", .*\"value\": null, \"pass\": false");
}

/* navsim estimate --threads N and --no-csv: estimate.json (with a cep95 predicted by the threaded
 * quadrature over 601 epochs) and estimate.csv byte-identical for 1, 2 and 3 threads; --no-csv
 * writes the same estimate.json and no estimate.csv; a bad thread count is refused (exit 2). */
static void test_estimate_threads_identical(void **state) {
  (void)state;
  nav_test_write_file(
      WORK, "estq.yaml",
      "format_version: 1\n"
      "name: estq\n"
      "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 200}}\n"
      "trajectory:\n"
      "  type: segments\n"
      "  segments:\n"
      "    v0_b_mps: [10, 0, 0]\n"
      "    items:\n"
      "      - {kind: hold, duration_s: 60}\n"
      "imu: {rate_hz: 100, catalog: \"Xsens MTi-300\"}\n"
      "gnss: {enabled: true, catalog: \"SBAS (WAAS/EGNOS class)\", outages: [[20, 40]]}\n"
      "initial_errors: {position_m: 2, velocity_mps: 0.1, attitude_deg: [0.5, 0.5, 2]}\n"
      "navigation: {scheme: ins_gnss}\n"
      "output: {rate_hz: 10}\n"
      "requirements:\n"
      "  - {id: h-end, metric: horizontal_position, statistic: outage_end, limit: 50, unit: m}\n"
      "  - {id: h-cep, metric: horizontal_position, statistic: cep95, limit: 50, unit: m}\n"
      "  - {id: v-p95, metric: vertical_position, statistic: p95, limit: 50, unit: m}\n");
  static const char *const runs[4] = {"estimate estq.yaml --out estq-1 --threads 1",
                                      "estimate estq.yaml --out estq-2 --threads 2",
                                      "estimate estq.yaml --out estq-3 --threads 3",
                                      "estimate estq.yaml --out estq-n --threads 2 --no-csv"};
  for (int i = 0; i < 4; ++i) {
    nav_cli_result *r = navsim(runs[i]);
    if (r->code != 0) fail_msg("navsim %s exited %d: %s", runs[i], r->code, r->err);
  }
  size_t l1 = 0, lk = 0;
  char *j1 = nav_test_slurp_len(WORK "/estq-1/estimate.json", &l1);
  char *c1 = nav_test_slurp_len(WORK "/estq-1/estimate.csv", &lk);
  assert_non_null(j1);
  assert_non_null(c1);
  nav_test_assert_matches(requirements_of(j1), "\"id\": \"h-cep\", .*\"value\": [0-9.e+-]+, \"pass\": true");
  static const char *const dirs[3] = {WORK "/estq-2", WORK "/estq-3", WORK "/estq-n"};
  for (int i = 0; i < 3; ++i) {
    char path[512];
    size_t l = 0;
    snprintf(path, sizeof path, "%s/estimate.json", dirs[i]);
    char *j = nav_test_slurp_len(path, &l);
    assert_non_null(j);
    assert_int_equal(l, l1);
    assert_memory_equal(j, j1, l1);
    free(j);
    snprintf(path, sizeof path, "%s/estimate.csv", dirs[i]);
    if (i < 2) {
      char *c = nav_test_slurp_len(path, &l);
      assert_non_null(c);
      assert_int_equal(l, lk);
      assert_memory_equal(c, c1, lk);
      free(c);
    } else {
      assert_int_equal(access(path, F_OK), -1); /* --no-csv */
    }
  }
  free(j1);
  free(c1);
  assert_int_equal(navsim("estimate estq.yaml --out estq-bad --threads 0")->code, 2);
  assert_int_equal(navsim("estimate estq.yaml --out estq-bad --threads two")->code, 2);
}


/* navsim budget: budget.csv sorted by share within each requirement, the shares of each
 * requirement summing to 1 (covariance); a flat-Earth scene by Monte Carlo. Runs after
 * test_estimate_predictions (its est.yaml). */
static void test_budget_cli(void **state) {
  (void)state;
  nav_cli_result *r = navsim("budget est.yaml --out budget-out");
  if (r->code != 0) fail_msg("navsim budget exited %d: %s", r->code, r->err);
  nav_test_assert_matches(
      r->out,
      "^h-end  horizontal_position outage_end: predicted [0-9.e+-]+ m \\(limit 50 m\\) at t = 39\\.9 s$");
  FILE *f = fopen(WORK "/budget-out/budget.csv", "r");
  assert_non_null(f);
  char line[512];
  assert_non_null(fgets(line, sizeof line, f));
  assert_string_equal(line, "requirement,metric,statistic,source,contribution,unit,variance,share,method\n");
  double sum[2] = {0.0, 0.0}, prev[2] = {2.0, 2.0};
  int rows[2] = {0, 0};
  while (fgets(line, sizeof line, f)) {
    char id[64], metric[64], stat[64], src[64], unit[16];
    double contrib, var, share;
    if (sscanf(line, "%63[^,],%63[^,],%63[^,],%63[^,],%lf,%15[^,],%lf,%lf,covariance", id, metric, stat, src, &contrib,
               unit, &var, &share) != 8)
      fail_msg("bad budget.csv row: %s", line);
    const int k = strcmp(id, "h-end") == 0 ? 0 : 1;
    assert_true(share <= prev[k]); /* sorted by share */
    prev[k] = share;
    assert_rel_near(contrib * contrib, var, 1e-12);
    sum[k] += share;
    rows[k]++;
  }
  fclose(f);
  assert_true(rows[0] >= 8 && rows[1] >= 8);
  assert_near(sum[0], 1.0, 1e-9);
  assert_near(sum[1], 1.0, 1e-9);
  /* The flat-Earth free INS is outside the covariance model: Monte Carlo with each source alone. */
  r = navsim("budget fail.yaml --out budget-flat --runs 8");
  if (r->code != 0) fail_msg("navsim budget (Monte Carlo) exited %d: %s", r->code, r->err);
  assert_non_null(strstr(r->out, "Monte Carlo budget"));
  f = fopen(WORK "/budget-flat/budget.csv", "r");
  assert_non_null(f);
  assert_non_null(fgets(line, sizeof line, f));
  int n = 0;
  double total = 0.0;
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, "h-rms,", 6) != 0) continue;
    assert_non_null(strstr(line, ",monte_carlo\n"));
    const char *c = strrchr(line, ',');
    const char *b = c - 1;
    while (b > line && *b != ',') --b;
    total += strtod(b + 1, NULL);
    ++n;
  }
  fclose(f);
  assert_true(n >= 5); /* catalog gyro and accel terms, initial position, velocity, attitude */
  assert_near(total, 1.0, 1e-9);
  assert_int_equal(navsim("budget fail.yaml --runs 0")->code, 2);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_help_mentions_strict),
      cmocka_unit_test(test_passing_requirements),
      cmocka_unit_test(test_failing_requirement_exit_codes),
      cmocka_unit_test(test_verdicts_independent_of_threads),
      cmocka_unit_test(test_invalid_requirements_exit_2),
      cmocka_unit_test(test_replay_verdicts),
      cmocka_unit_test(test_issue_25_replay_no_fix_applied),
      cmocka_unit_test(test_issue_25_replay_no_scored_epoch),
      cmocka_unit_test(test_issue_25_unevaluable_requirements_refused),
      cmocka_unit_test(test_estimate_predictions),
      cmocka_unit_test(test_estimate_threads_identical),
      cmocka_unit_test(test_budget_cli),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
