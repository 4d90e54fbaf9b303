/*
 * What navsim replay prints (issue 18, "Real data in and out"), on the shared gnss-ins-sim long
 * drive with references slower than the IMU, made here from its 200 Hz truth.nav:
 *  - a 1 Hz reference at half seconds (no row at the epochs just before the fixes): the gap
 *    table and the smoother's gap lines used to print "-" and "nan"; now they say that the end is
 *    not scored and why; no "nan", no "-" cell anywhere;
 *  - a 1 Hz reference at whole seconds with the full GNSS (no gaps): no gap rows of "-";
 *  - free INS: no peer column without figures (pyins has none for it);
 *  - one time base: the outage lines of the requirements are in the files' time (seconds of
 *    week), the offset from the scene's requirement times shown once ("times" line); an
 *    outage_end requirement without an outage is "N/A ... not evaluated" with the reason.
 * Skipped only when the shared data set is absent.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <regex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define DATA NAV_SHARED_DIR "/data/gnss-ins-sim-long-drive/"
#define SCENE NAV_SOURCE_DIR "/scenes/long-drive-replay.yaml"

static void skip_without_data(void) {
  if (access(DATA "IMU.txt", R_OK) != 0 || access(DATA "GNSS_outage.txt", R_OK) != 0 ||
      access(DATA "truth.nav", R_OK) != 0) {
    print_message("shared data set %s not present: skipped\n", DATA);
    skip();
  }
}

/* The rows of truth.nav whose time has the fractional part @p frac (to 0.1 ms), into WORK/name. */
static void decimate(const char *name, double frac) {
  FILE *in = fopen(DATA "truth.nav", "r");
  assert_non_null(in);
  char path[600];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  FILE *out = fopen(path, "w");
  assert_non_null(out);
  char line[512];
  long rows = 0;
  while (fgets(line, sizeof line, in)) {
    char *end = NULL;
    (void)strtol(line, &end, 10);
    const double t = strtod(end, NULL);
    if (fabs(t - floor(t) - frac) < 1e-4) {
      fputs(line, out);
      rows++;
    }
  }
  fclose(in);
  fclose(out);
  assert_true(rows > 900);
}

/* No "nan" and no cell that is a lone "-" in @p text. */
static void assert_no_placeholders(const char *text) {
  if (strstr(text, "nan")) fail_msg("\"nan\" printed:\n%s", text);
  regex_t re;
  assert_int_equal(regcomp(&re, "(^| )-( |$)", REG_EXTENDED | REG_NEWLINE), 0);
  regmatch_t m;
  const int found = regexec(&re, text, 1, &m, 0);
  regfree(&re);
  if (found == 0) fail_msg("a \"-\" cell printed at byte %d:\n%s", (int)m.rm_so, text);
}

static int count(const char *text, const char *what) {
  int n = 0;
  for (const char *p = strstr(text, what); p; p = strstr(p + 1, what))
    ++n;
  return n;
}

static void half_second_reference(void **state) {
  (void)state;
  skip_without_data();
  decimate("half.nav", 0.5);
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "replay --imu '" DATA "IMU.txt' --gnss '" DATA "GNSS_outage.txt' --truth "
                        "'%s/half.nav' --scene '" SCENE "' --smooth --out '%s/half'",
                        WORK, WORK);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  assert_no_placeholders(r->out);
  nav_test_assert_matches(r->out, "100299\\.000 +100360\\.000 +no ref\\. row +no ref\\. row +[0-9.]+\n");
  nav_test_assert_matches(
      r->out, "gap 100299\\.000\\.\\.100360\\.000 s: end horiz\\. not scored \\(no reference row");
  /* The files' time base everywhere, the offset once. */
  assert_int_equal(count(r->out, "count from the first IMU epoch, t = 100000.500 s"), 1);
  nav_test_assert_matches(r->out,
                          "outage \\[100299\\.000, 100360\\.000\\) s: [0-9.]+ m at t = 100359\\.500 s");
  nav_test_assert_matches(r->out, "outage \\[100599\\.000, 100660\\.000\\) s: ");
}

static void whole_second_reference_no_gaps(void **state) {
  (void)state;
  skip_without_data();
  decimate("whole.nav", 0.0);
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                                        "replay --imu '" DATA "IMU.txt' --gnss '" DATA "GNSS.txt' --truth "
                                        "'%s/whole.nav' --scene '" SCENE "' --out '%s/whole'",
                                        WORK, WORK);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  assert_no_placeholders(r->out);
  assert_null(strstr(r->out, "gap 1 end"));
  nav_test_assert_matches(r->out,
                          "N/A +h-outage-end +horizontal_position outage_end: not evaluated: the run has no "
                          "GNSS outage");
  assert_null(strstr(r->out, "PASS  h-outage-end"));
}

static void free_ins_no_empty_column(void **state) {
  (void)state;
  skip_without_data();
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "replay --imu '" DATA "IMU.txt' --truth '%s/whole.nav' --out '%s/free'", WORK, WORK);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  assert_no_placeholders(r->out);
  nav_test_assert_matches(r->out, "\n +navsim +KF-GINS\n");
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(half_second_reference),
      cmocka_unit_test(whole_second_reference_no_gaps),
      cmocka_unit_test(free_ins_no_empty_column),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
