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

#define WORK NAV_TEST_WORK_DIR
#define DATA NAV_TEST_DATA_DIR "/replay/"
#define SLICE                                                                                                \
  "--imu '" DATA "IMU-100195-100245.txt' --gnss '" DATA "GNSS-100195-100245.txt' --truth '" DATA             \
  "truth-100195-100245-20Hz.nav' --scene '" DATA "long-drive.yaml' --outage 100215.5:100230.5"

static char g_out[1 << 16], g_err[1 << 14];

static void slurp(const char *path, char *buf, size_t cap) {
  buf[0] = '\0';
  FILE *f = fopen(path, "r");
  if (!f) return;
  const size_t n = fread(buf, 1, cap - 1, f);
  buf[n] = '\0';
  fclose(f);
}

static int navsim(const char *args) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >'%s/stdout.txt' 2>'%s/stderr.txt'", WORK, NAVSIM_EXE, args,
           WORK, WORK);
  const int st = system(cmd);
  slurp(WORK "/stdout.txt", g_out, sizeof g_out);
  slurp(WORK "/stderr.txt", g_err, sizeof g_err);
  return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static int setup(void **state) {
  (void)state;
  return system("rm -rf '" WORK "' && mkdir -p '" WORK "'") == 0 ? 0 : -1;
}

static void test_bad_options(void **state) {
  (void)state;
  assert_int_equal(navsim("replay " SLICE " --smooth-group 0 --out bad"), 2);
  assert_non_null(strstr(g_err, "--smooth-group"));
  assert_int_equal(navsim("replay " SLICE " --smooth-group"), 2);
}

static void test_smoothed_outputs(void **state) {
  (void)state;
  assert_int_equal(navsim("replay " SLICE " --smooth --out sm"), 0);
  assert_non_null(strstr(g_out, "RTS smoother"));
  static char csv[1 << 20];
  slurp(WORK "/sm/nav_smoothed.csv", csv, sizeof csv);
  assert_true(strncmp(csv, "t_s,lat_deg,lon_deg,h_m,", 24) == 0);
  long rows = 0;
  for (const char *p = csv; *p; ++p)
    rows += *p == '\n';
  /* 10 Hz over 50 s plus the initial epoch, and the header. */
  assert_int_equal(rows, 502);
  static char js[1 << 16];
  slurp(WORK "/sm/summary.json", js, sizeof js);
  const char *s = strstr(js, "\"stats_smoothed\"");
  assert_non_null(s);
  assert_non_null(strstr(s, "\"pos_err_h_m\""));
  assert_non_null(strstr(s, "\"forward_same_epochs\""));
  assert_non_null(strstr(s, "\"smoothed_end_pos_err_h_m\""));
  assert_non_null(strstr(s, "\"backward_wall_s\""));
  /* Without --smooth: no smoothed outputs. */
  assert_int_equal(navsim("replay " SLICE " --out plain"), 0);
  slurp(WORK "/plain/summary.json", js, sizeof js);
  assert_null(strstr(js, "stats_smoothed"));
  slurp(WORK "/plain/nav_smoothed.csv", csv, sizeof csv);
  assert_int_equal(csv[0], '\0');
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_options),
      cmocka_unit_test(test_smoothed_outputs),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
