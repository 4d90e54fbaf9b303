/*
 * Nothing pretended (issue 25). Damaged result directories: `navsim report` and `navsim export`
 * read a result directory that navsim wrote; when one of its files was cut or replaced, they say
 * which file and where, with exit 2, instead of a page that says "The scene states no
 * requirements" or a shortened track. Every case starts from a fresh copy of one good result.
 * Recorded references: `navsim check` and `navsim run` report the residuals of the spline fit
 * (terminal and summary.json "recorded_fit").
 *
 * NAVSIM_EXE, NAV_SOURCE_DIR and NAV_TEST_WORK_DIR come from the build.
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

static int setup(void **state) {
  (void)state;
  if (nav_test_fresh_dir(WORK) != 0) return -1;
  /* One run of the urban drive (WGS-84, INS/GNSS, requirements that fail): about a second. */
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL,
                                       "run '" NAV_SOURCE_DIR "/scenes/urban-drive.yaml' --runs 1 --quiet --out good");
  if (r->code != 0) {
    fprintf(stderr, "setup: navsim run exited %d: %s\n", r->code, r->err);
    return -1;
  }
  return 0;
}

/* A fresh copy of the good result as WORK/d, then the shell command @p damage run in WORK. */
static void fresh_copy(const char *damage) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "cd '%s' && rm -rf d && cp -r good d && %s", WORK, damage);
  assert_int_equal(system(cmd), 0);
}

static bool exists(const char *path) {
  struct stat sb;
  return stat(path, &sb) == 0;
}

/* report of a summary.json cut at 500 bytes: exit 2 naming the file, its line and column, and
 * the byte where it ends; no page (which would say the scene states no requirements). */
static void test_issue_25_report_truncated_summary(void **state) {
  (void)state;
  fresh_copy("head -c 500 good/summary.json > d/summary.json");
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "report d");
  if (r->code != 2) fail_msg("report of a cut summary.json exited %d:\n%s\n%s", r->code, r->out, r->err);
  nav_test_assert_matches(r->err, "^d/summary\\.json:[0-9]+:[0-9]+: error: truncated JSON: the file ends at byte 500 ");
  if (strstr(r->out, "no requirements") || strstr(r->err, "no requirements")) fail_msg("pretended: %s", r->out);
  if (exists(WORK "/d/report")) fail_msg("a refused report wrote d/report");
  /* Invalid in the middle (a byte replaced): its place. */
  fresh_copy("sed -i 's/\"seed\"/seed/' d/summary.json");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "report d");
  if (r->code != 2) fail_msg("report of an invalid summary.json exited %d:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, "^d/summary\\.json:4:3: error: invalid JSON at byte [0-9]+ of [0-9]+: expected a key");
}

static void test_issue_25_report_missing_summary(void **state) {
  (void)state;
  fresh_copy("rm d/summary.json");
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "report d");
  if (r->code != 2) fail_msg("report without summary.json exited %d:\n%s", r->code, r->err);
  nav_test_assert_matches(r->err, "^d/summary\\.json: error: missing: ");
  if (exists(WORK "/d/report")) fail_msg("a refused report wrote d/report");
}

/* export of a truth.csv cut after row 521 (whole lines), cut mid-line, replaced by a directory,
 * or only its header; and of a cut nav.csv: exit 2 with the file and the line, no tracks. */
static void test_issue_25_export_truncated_tracks(void **state) {
  (void)state;
  static const struct {
    const char *damage, *pattern;
  } k_cases[] = {
      {"head -521 good/truth.csv > d/truth.csv",
       "^d/truth\\.csv:521: error: the track ends at t = 51\\.9 s but the run ends at 513 s \\(summary\\.json "
       "final\\.t_s\\): the file was cut short$"},
      {"head -c 40000 good/truth.csv > d/truth.csv",
       "^d/truth\\.csv:[0-9]+:[0-9]+: error: the last line has no line end: the file was cut short"},
      /* (the wording of the readers' general refusal of non-regular files may replace this one) */
      {"rm d/truth.csv && mkdir d/truth.csv", "^d/truth\\.csv: error: .*a directory"},
      {"head -1 good/truth.csv > d/truth.csv", "^d/truth\\.csv:1:1: error: no data row after the header"},
      {"head -2000 good/nav.csv > d/nav.csv", "^d/nav\\.csv:2000: error: the track ends at t = "},
  };
  for (size_t k = 0; k < sizeof k_cases / sizeof k_cases[0]; ++k) {
    fresh_copy(k_cases[k].damage);
    nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "export d");
    if (r->code != 2) fail_msg("export after \"%s\" exited %d:\n%s\n%s", k_cases[k].damage, r->code, r->out, r->err);
    nav_test_assert_matches(r->err, k_cases[k].pattern);
    if (exists(WORK "/d/tracks.kml") || exists(WORK "/d/tracks.csv"))
      fail_msg("export after \"%s\" wrote tracks", k_cases[k].damage);
  }
  /* The good directory still exports. */
  fresh_copy("true");
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "export d");
  if (r->code != 0) fail_msg("export of the good result exited %d:\n%s", r->code, r->err);
}

/* The fit residuals of a recorded reference, on the terminal of check and run and in summary.json:
 * the KF-GINS dataset 2 reference is fitted to centimetres (the figures themselves are
 * test_recorded's; here they must be reported, finite and of that size). */
static void test_issue_25_recorded_fit_residuals(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check '" NAV_SOURCE_DIR "/scenes/recorded-adis16465.yaml'");
  if (r->code != 0) fail_msg("check exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "recorded-adis16465\\.yaml: recorded .*adis16465-truth-116454-116754\\.nav: 3300 "
                                  "samples fitted; residuals of the fit: position RMS [0-9.e-]+ m \\(horizontal "
                                  "[0-9.e-]+, vertical [0-9.e-]+\\), max [0-9.e-]+ m at t = [0-9.]+ s; velocity RMS");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL,
                       "run '" NAV_SOURCE_DIR "/scenes/recorded-adis16465.yaml' --ideal --out rec");
  if (r->code != 0) fail_msg("run exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^reference  recorded .*: 3300 samples fitted; residuals of the fit: position RMS ");
  char *js = nav_test_slurp_alloc(WORK "/rec/summary.json");
  assert_non_null(js);
  nav_test_assert_matches(js, "\"recorded_fit\": \\{\"file\": \"[^\"]*adis16465-truth-116454-116754\\.nav\", "
                              "\"samples\": 3300, \"pos_rms_m\": ");
  const char *p = strstr(js, "\"pos_rms_m\": ");
  assert_non_null(p);
  const double pos_rms = strtod(p + strlen("\"pos_rms_m\": "), NULL);
  if (!(pos_rms > 0.0 && pos_rms < 0.01)) fail_msg("pos_rms_m = %g: expected a centimetre-level fit", pos_rms);
  p = strstr(js, "\"att_max_deg\": ");
  assert_non_null(p);
  const double att_max = strtod(p + strlen("\"att_max_deg\": "), NULL);
  if (!(att_max > 0.0 && att_max < 1.0)) fail_msg("att_max_deg = %g", att_max);
  free(js);
}

/* A replay window whose one scored epoch (t0 + 0.05 s) is not an output epoch (every 0.1 s): the
 * statistics at the output epochs have no epoch, and are printed "-" and written null, not 0. */
static void test_issue_25_replay_statistics_of_no_epoch(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_cli(
      NAVSIM_EXE, WORK, NULL,
      "replay --imu '" NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt' --gnss '" NAV_TEST_DATA_DIR
      "/replay/GNSS-100195-100245.txt' --truth '" NAV_TEST_DATA_DIR "/replay/truth-100195-100245-20Hz.nav' --end "
      "100195.05 --peer self='" NAV_TEST_DATA_DIR "/replay/truth-100195-100245-20Hz.nav' --peers none --out few");
  if (r->code != 0) fail_msg("replay exited %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "^scored epochs +1 +0 +2$");
  nav_test_assert_matches(r->out, "^horiz\\. pos RMS \\[m\\] +[0-9.e+-]+ +- +0$");
  char *js = nav_test_slurp_alloc(WORK "/few/summary.json");
  assert_non_null(js);
  nav_test_assert_matches(js, "\"errors_at_output_epochs\": \\{\n +\"epochs\": 0,\n +\"pos_err_h_m\": \\{\"rms\": null, "
                              "\"max\": null, \"t_max_s\": null\\}");
  free(js);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_issue_25_report_truncated_summary),
      cmocka_unit_test(test_issue_25_report_missing_summary),
      cmocka_unit_test(test_issue_25_export_truncated_tracks),
      cmocka_unit_test(test_issue_25_recorded_fit_residuals),
      cmocka_unit_test(test_issue_25_replay_statistics_of_no_epoch),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
