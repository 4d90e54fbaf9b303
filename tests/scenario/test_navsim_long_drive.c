/*
 * Acceptance test of the INS/GNSS replay against the peer figures (issue 5): `navsim replay` of
 * the shared gnss-ins-sim long drive (../shared/data/gnss-ins-sim-long-drive, 193 034 IMU epochs)
 * with the library scene scenes/long-drive-replay.yaml, exactly as the README's tour runs it.
 * Limits are the targets, set by the peers (README of the data set):
 *   full GNSS (GNSS.txt):        horizontal position RMS <= 0.022 m, yaw RMS <= 0.05 deg
 *                                (KF-GINS 0.0219 m / 0.0488 deg, pyins 0.0222 m / 0.0492 deg);
 *   GNSS_outage.txt (2 x 60 s):  horizontal error at the end of each outage <= 7.2 m and <= 1.4 m
 *                                (KF-GINS 7.19 / 1.38 m, pyins 6.74 / 0.97 m).
 *                                vertical error max/RMS as KF-GINS's 0.276 / 0.041 m (to 5 / 1 mm:
 *                                the same filter model, scale factors as Gauss-Markov processes).
 * "End of the outage" is the IMU epoch of the first fix after the gap, before that fix is applied
 * (summary.json gnss_gaps[].pos_err_h_end_m), the largest error of the gap.
 * The figures are read from summary.json and printed; nothing here is a stored result.
 * Skipped only when the shared data set is absent.
 *
 * NAVSIM_EXE, NAV_TEST_WORK_DIR, NAV_SOURCE_DIR and NAV_SHARED_DIR come from the compile definitions.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define DATA NAV_SHARED_DIR "/data/gnss-ins-sim-long-drive/"

/* Runs the replay of one GNSS file into WORK/<out>; returns summary.json (caller frees). */
static char *replay(const char *gnss_file, const char *out) {
  char cmd[4096];
  snprintf(cmd, sizeof cmd,
           "mkdir -p '%s' && cd '%s' && '%s' replay --imu '" DATA "IMU.txt' --gnss '" DATA
           "%s' --truth '" DATA "truth.nav' --scene '" NAV_SOURCE_DIR
           "/scenes/long-drive-replay.yaml' --out '%s' --quiet > '%s.log' 2>&1",
           WORK, WORK, NAVSIM_EXE, gnss_file, out, out);
  const int st = system(cmd);
  if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
    char log[1024];
    snprintf(log, sizeof log, "%s/%s.log", WORK, out);
    char *text = nav_test_slurp_alloc(log);
    fail_msg("navsim replay --gnss %s exited %d:\n%s", gnss_file, WIFEXITED(st) ? WEXITSTATUS(st) : -1,
             text ? text : "(no log)");
  }
  char path[1024];
  snprintf(path, sizeof path, "%s/%s/summary.json", WORK, out);
  char *json = nav_test_slurp_alloc(path);
  assert_non_null(json);
  return json;
}

/* The number after `key` (e.g. "\"rms\": ") searched from `from`; fails when absent. */
static double number_after(const char *from, const char *key, const char **next) {
  const char *p = from ? strstr(from, key) : NULL;
  if (!p) fail_msg("summary.json: no %s", key);
  p += strlen(key);
  char *end = NULL;
  const double v = strtod(p, &end);
  if (end == p) fail_msg("summary.json: %s is not followed by a number", key);
  if (next) *next = end;
  return v;
}

static void skip_without_data(void) {
  if (access(DATA "IMU.txt", R_OK) != 0 || access(DATA "GNSS_outage.txt", R_OK) != 0 ||
      access(DATA "truth.nav", R_OK) != 0) {
    print_message("shared data set %s not present: skipped\n", DATA);
    skip();
  }
}

static void full_gnss_meets_peer_figures(void **state) {
  (void)state;
  skip_without_data();
  char *json = replay("GNSS.txt", "full");
  assert_non_null(strstr(json, "\"partial\": false"));
  assert_non_null(strstr(json, "\"imu_steps\": 193034"));
  const char *h = strstr(json, "\"pos_err_h_m\": {");
  const char *yaw = strstr(json, "\"yaw_err_deg\": {");
  const double h_rms = number_after(h, "\"rms\": ", NULL);
  const double yaw_rms = number_after(yaw, "\"rms\": ", NULL);
  print_message("long drive, full GNSS: horizontal RMS %.5f m (<= 0.022; KF-GINS 0.0219), yaw RMS %.5f deg "
                "(<= 0.05; KF-GINS 0.0488)\n",
                h_rms, yaw_rms);
  assert_true(isfinite(h_rms) && h_rms > 0.0);
  assert_true(h_rms <= 0.022);
  assert_true(yaw_rms <= 0.05);
  free(json);
}

static void outage_ends_meet_peer_figures(void **state) {
  (void)state;
  skip_without_data();
  char *json = replay("GNSS_outage.txt", "outage");
  assert_non_null(strstr(json, "\"partial\": false"));
  const char *gaps = strstr(json, "\"gnss_gaps\": {\"count\": 2,");
  if (!gaps) fail_msg("summary.json: expected exactly two GNSS gaps:\n%.400s", strstr(json, "\"gnss_gaps\""));
  const char *p = gaps;
  const double t0 = number_after(p, "\"t0_s\": ", &p);
  const double end1 = number_after(p, "\"pos_err_h_end_m\": ", &p);
  const double t0b = number_after(p, "\"t0_s\": ", &p);
  const double end2 = number_after(p, "\"pos_err_h_end_m\": ", &p);
  print_message("long drive, GNSS_outage.txt: outage ends %.3f m (gap from %.0f s; <= 7.2, KF-GINS 7.19) and "
                "%.3f m (gap from %.0f s; <= 1.4, KF-GINS 1.38)\n",
                end1, t0, end2, t0b);
  /* The data's outages: no fixes 100300..100359 s and 100600..100659 s. */
  assert_true(fabs(t0 - 100299.0) < 1e-6 && fabs(t0b - 100599.0) < 1e-6);
  /* An outage end must be metres, not a reset error: guards against scoring after the update. */
  assert_true(end1 > 1.0 && end2 > 0.1);
  assert_true(end1 <= 7.2);
  assert_true(end2 <= 1.4);
  /* The scene's own requirement verdict agrees. */
  const char *req = strstr(json, "\"id\": \"h-outage-end\"");
  assert_non_null(req);
  assert_non_null(strstr(req, "\"pass\": true"));
  /* The vertical channel inside the outages (issue 23 item 4): with KF-GINS's own model of the
   * scale-factor states (Gauss-Markov, 1 h: navigation.scale_factor_gm_tau_s) our vertical error
   * is KF-GINS's (max 0.276 m, RMS 0.041 m over all epochs, data set README); with random-constant
   * scale factors it was 0.396 m / 0.052 m. */
  const char *v = strstr(json, "\"pos_err_v_m\": {");
  const double v_rms = number_after(v, "\"rms\": ", NULL);
  const double v_max = number_after(v, "\"max\": ", NULL);
  print_message("long drive, GNSS_outage.txt: vertical RMS %.4f m (KF-GINS 0.041), max %.4f m (KF-GINS 0.276)\n",
                v_rms, v_max);
  assert_true(fabs(v_max - 0.276) <= 0.005);
  assert_true(fabs(v_rms - 0.041) <= 0.001);
  free(json);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(full_gnss_meets_peer_figures),
      cmocka_unit_test(outage_ends_meet_peer_figures),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
