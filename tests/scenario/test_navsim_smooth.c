/*
 * The `navsim replay --smooth` contract: option errors (exit 2), nav_smoothed.csv and the
 * "stats_smoothed" block of summary.json, on the vendored 50 s slice of the long drive with a
 * 15 s GNSS gap. The figures themselves are checked by test_smoother.
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
#include <sys/wait.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define DATA NAV_TEST_DATA_DIR "/replay/"
#define SLICE                                                                                                \
  "--imu '" DATA "IMU-100195-100245.txt' --gnss '" DATA "GNSS-100195-100245.txt' --truth '" DATA             \
  "truth-100195-100245-20Hz.nav' --scene '" DATA "long-drive.yaml' --outage 100215.5:100230.5"

/* Run "navsim ARGS" in WORK; both streams captured in g_r. @return the exit code. */
static const nav_cli_result *g_r;
static int navsim(const char *args) {
  g_r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, args);
  return g_r->code;
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

static void test_bad_options(void **state) {
  (void)state;
  assert_int_equal(navsim("replay " SLICE " --smooth-group 0 --out bad"), 2);
  assert_non_null(strstr(g_r->err, "--smooth-group"));
  assert_int_equal(navsim("replay " SLICE " --smooth-group"), 2);
}

static void test_smoothed_outputs(void **state) {
  (void)state;
  assert_int_equal(navsim("replay " SLICE " --smooth --out sm"), 0);
  assert_non_null(strstr(g_r->out, "RTS smoother"));
  static char csv[1 << 20];
  nav_test_slurp(WORK "/sm/nav_smoothed.csv", csv, sizeof csv);
  assert_true(strncmp(csv, "t_s,lat_deg,lon_deg,h_m,", 24) == 0);
  long rows = 0;
  for (const char *p = csv; *p; ++p)
    rows += *p == '\n';
  /* 10 Hz over 50 s plus the initial epoch, and the header. */
  assert_int_equal(rows, 502);
  static char js[1 << 16];
  nav_test_slurp(WORK "/sm/summary.json", js, sizeof js);
  const char *s = strstr(js, "\"stats_smoothed\"");
  assert_non_null(s);
  assert_non_null(strstr(s, "\"pos_err_h_m\""));
  assert_non_null(strstr(s, "\"forward_same_epochs\""));
  assert_non_null(strstr(s, "\"smoothed_end_pos_err_h_m\""));
  assert_non_null(strstr(s, "\"backward_wall_s\""));
  /* Without --smooth: no smoothed outputs. */
  assert_int_equal(navsim("replay " SLICE " --out plain"), 0);
  nav_test_slurp(WORK "/plain/summary.json", js, sizeof js);
  assert_null(strstr(js, "stats_smoothed"));
  nav_test_slurp(WORK "/plain/nav_smoothed.csv", csv, sizeof csv);
  assert_int_equal(csv[0], '\0');
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_options),
      cmocka_unit_test(test_smoothed_outputs),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
