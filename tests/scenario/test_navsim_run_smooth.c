/*
 * Smoothing in simulations (scene option navigation.smoother, ins_gnss only): `navsim run` on a
 * small INS/GNSS drive with a 30 s GNSS outage writes nav_smoothed.csv and smoothed_errors.csv
 * (run 0, the columns of nav.csv and errors.csv) and "stats_smoothed" in summary.json; the
 * smoothed horizontal RMS is below the forward one; every output is identical for --threads 1
 * and 2; the option on a free INS is a check error; the option survives a write/read round trip.
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

#include "navcore/nav_io.h"
#include "navcore/nav_scene.h"
#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR

static const char *k_scene_head =
    "format_version: 1\n"
    "name: smooth-small\n"
    "earth:\n"
    "  model: wgs84\n"
    "  origin: {lat_deg: 52.52, lon_deg: 13.405, h_m: 35}\n"
    "trajectory:\n"
    "  type: waypoints\n"
    "  initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 90}\n"
    "  waypoints:\n"
    "    timing: speed\n"
    "    attitude_mode: ground\n"
    "    hold_start_s: 20\n"
    "    hold_end_s: 2\n"
    "    limits: {max_accel_mps2: 2, max_jerk_mps3: 2, max_lateral_accel_mps2: 3,\n"
    "             max_rate_dps: 30, max_ang_accel_dps2: 30, max_ang_jerk_dps3: 120}\n"
    "    points:\n"
    "      - {ned_m: [0, 0, 0], speed_mps: 0}\n"
    "      - {ned_m: [0, 300, 0], speed_mps: 12}\n"
    "      - {ned_m: [300, 300, 0], speed_mps: 8}\n"
    "      - {ned_m: [300, 0, 0], speed_mps: 12}\n"
    "      - {ned_m: [300, -100, 0], speed_mps: 0}\n"
    "imu:\n"
    "  rate_hz: 100\n"
    "  catalog: \"Xsens MTi-300\"\n"
    "  gyro:\n"
    "    bias_turn_on_deg_per_h: 200\n"
    "  accel:\n"
    "    bias_turn_on_mg: 2\n"
    "gnss:\n"
    "  enabled: true\n"
    "  catalog: \"standalone SPS typical (single-frequency code, open sky)\"\n"
    "  lever_arm_b_m: [0.5, 0, -1.2]\n"
    "  outages: [[40, 70]]\n"
    "initial_errors:\n"
    "  position_m: [2, 2, 4]\n"
    "  velocity_mps: 0.1\n"
    "  attitude_deg: [0.5, 0.5, 3]\n"
    "output:\n"
    "  rate_hz: 10\n"
    "simulation:\n"
    "  seed: 11\n"
    "  runs: 3\n";

static void write_scene(const char *name, const char *navigation) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(k_scene_head, f);
  fputs(navigation, f);
  assert_int_equal(fclose(f), 0);
}

/* Run "navsim ARGS" in WORK; both streams captured in g_r. @return the exit code. */
static const nav_cli_result *g_r;
static int navsim(const char *args) {
  g_r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, args);
  return g_r->code;
}

static int setup(void **state) {
  (void)state;
  if (nav_test_fresh_dir(WORK) != 0) return -1;
  return 0;
}

/* The "rms" of "key" after the first occurrence of "after" in a JSON text. */
static double json_rms(const char *text, const char *after, const char *key) {
  const char *p = strstr(text, after);
  assert_non_null(p);
  p = strstr(p, key);
  assert_non_null(p);
  p = strstr(p, "\"rms\": ");
  assert_non_null(p);
  return strtod(p + 7, NULL);
}

static long lines(const char *s) {
  long n = 0;
  for (; *s; ++s)
    n += *s == '\n';
  return n;
}

static size_t header_len(const char *s) {
  const char *nl = strchr(s, '\n');
  return nl ? (size_t)(nl - s) : strlen(s);
}

/* The @p n files named @p files are identical in WORK/<a> and WORK/<b>; @p what says between what. */
static void assert_same_files(const char *a, const char *b, const char *const *files, size_t n, const char *what) {
  for (size_t i = 0; i < n; ++i) {
    char pa[512], pb[512];
    snprintf(pa, sizeof pa, "%s/%s/%s", WORK, a, files[i]);
    snprintf(pb, sizeof pb, "%s/%s/%s", WORK, b, files[i]);
    char *x = nav_test_slurp_alloc(pa), *y = nav_test_slurp_alloc(pb);
    assert_non_null(x);
    assert_non_null(y);
    if (strcmp(x, y) != 0) fail_msg("%s differs %s", files[i], what);
    free(x);
    free(y);
  }
}

static void test_run_writes_smoothed_results(void **state) {
  (void)state;
  write_scene("smooth.yaml", "navigation:\n  scheme: ins_gnss\n  smoother: true\n");
  assert_int_equal(navsim("run smooth.yaml --threads 1 --out t1 -q"), 0);
  char *nav = nav_test_slurp_alloc(WORK "/t1/nav.csv"), *err = nav_test_slurp_alloc(WORK "/t1/errors.csv");
  char *snav = nav_test_slurp_alloc(WORK "/t1/nav_smoothed.csv");
  char *serr = nav_test_slurp_alloc(WORK "/t1/smoothed_errors.csv");
  assert_non_null(nav);
  assert_non_null(err);
  assert_non_null(snav);
  assert_non_null(serr);
  /* The forward files' columns (nav_smoothed.csv adds the smoothed and forward sigmas) and the same
   * epochs. */
  static const char sigmas[] = ",sd_n_m,sd_e_m,sd_d_m,fwd_sd_n_m,fwd_sd_e_m,fwd_sd_d_m,sd_yaw_deg,fwd_sd_yaw_deg";
  assert_int_equal(header_len(snav), header_len(nav) + strlen(sigmas));
  assert_memory_equal(snav, nav, header_len(nav));
  assert_memory_equal(snav + header_len(nav), sigmas, strlen(sigmas));
  /* Smoothed sigmas never exceed the forward ones (the backward pass only adds information). */
  {
    long rows = 0;
    double fwd_max = 0.0, sm_at_max = 0.0;
    for (const char *p = strchr(snav, '\n'); p && p[1]; p = strchr(p + 1, '\n')) {
      const char *q = p + 1;
      for (int c = 0; c < 13; ++c) q = strchr(q, ',') + 1;
      double v[8];
      for (int c = 0; c < 8; ++c) {
        char *end = NULL;
        v[c] = strtod(q, &end);
        q = end + 1;
      }
      for (int c = 0; c < 3; ++c) assert_true(v[c] > 0.0 && v[c] <= v[3 + c] * (1.0 + 1e-9));
      assert_true(v[6] > 0.0 && v[6] <= v[7] * (1.0 + 1e-9));
      rows++;
      if (v[3] > fwd_max) {
        fwd_max = v[3];
        sm_at_max = v[0];
      }
    }
    /* Deep in the GNSS outage the forward sigma peaks; there the smoother, which also has the fixes
     * after the outage, knows the position much better. */
    print_message("nav_smoothed.csv: %ld rows; largest forward north sigma %.3g m, smoothed there %.3g m\n", rows,
                  fwd_max, sm_at_max);
    assert_true(sm_at_max < 0.5 * fwd_max);
  }
  assert_int_equal(header_len(serr), header_len(err));
  assert_memory_equal(serr, err, header_len(err));
  assert_int_equal(lines(snav), lines(nav));
  assert_int_equal(lines(serr), lines(err));
  assert_true(lines(snav) > 1000);
  /* The smoothed solution differs from the forward one (the smoother did something). */
  assert_true(strcmp(snav, nav) != 0);
  char *js = nav_test_slurp_alloc(WORK "/t1/summary.json");
  assert_non_null(js);
  assert_non_null(strstr(js, "\"stats_smoothed\""));
  assert_non_null(strstr(js, "\"smoother_bytes_max\""));
  const double sm_h = json_rms(js, "\"stats_smoothed\"", "\"pos_err_h_m\"");
  const double fw_h = json_rms(js, "\"forward_same_epochs\"", "\"pos_err_h_m\"");
  const double fw_all = json_rms(js, "\"stats\"", "\"pos_err_h_m\"");
  const double sm_v = json_rms(js, "\"stats_smoothed\"", "\"vel_err_mps\"");
  const double fw_v = json_rms(js, "\"forward_same_epochs\"", "\"vel_err_mps\"");
  print_message("horizontal RMS forward %.4g m (IMU epochs %.4g m), smoothed %.4g m; velocity %.4g -> %.4g m/s\n",
                fw_h, fw_all, sm_h, fw_v, sm_v);
  assert_true(sm_h > 0.0);
  assert_true(sm_h < fw_h);
  assert_true(sm_h < fw_all);
  assert_true(sm_v < fw_v);

  /* Two threads: every result identical (the wall time aside). */
  assert_int_equal(navsim("run smooth.yaml --threads 2 --out t2 -q"), 0);
  static const char *files[] = {"nav.csv", "errors.csv", "nav_smoothed.csv", "smoothed_errors.csv", "mc_final.csv",
                                "mc_stats.csv"};
  assert_same_files("t1", "t2", files, sizeof files / sizeof files[0], "between --threads 1 and 2");
  char *js2 = nav_test_slurp_alloc(WORK "/t2/summary.json");
  assert_non_null(js2);
  const char *b1 = strstr(js, "\"stats\""), *b2 = strstr(js2, "\"stats\"");
  const char *e1 = strstr(js, "\"requirements\""), *e2 = strstr(js2, "\"requirements\"");
  assert_non_null(b1);
  assert_non_null(b2);
  assert_non_null(e1);
  assert_non_null(e2);
  assert_int_equal(e1 - b1, e2 - b2);
  assert_memory_equal(b1, b2, (size_t)(e1 - b1));
  free(js2);
  free(js);
  free(nav);
  free(err);
  free(snav);
  free(serr);
}

#ifdef MPIEXEC
/* Under mpirun (2 ranks): the same smoothed files and statistics as the threaded run (the
 * smoothed tables travel in the partial results, sim_partial.c). */
static void test_mpi_same_as_threads(void **state) {
  (void)state;
  write_scene("smooth.yaml", "navigation:\n  scheme: ins_gnss\n  smoother: true\n");
  assert_int_equal(navsim("run smooth.yaml --threads 1 --out m1 -q"), 0);
  char cmd[4096];
  snprintf(cmd, sizeof cmd,
           "cd '%s' && timeout 300 '%s' --allow-run-as-root --oversubscribe -np 2 '%s' run smooth.yaml --threads 1 "
           "--out mpi -q >'%s/mpi.txt' 2>&1",
           WORK, MPIEXEC, NAVSIM_EXE, WORK);
  const int st = system(cmd);
  assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  static const char *files[] = {"nav_smoothed.csv", "smoothed_errors.csv", "mc_final.csv"};
  assert_same_files("m1", "mpi", files, sizeof files / sizeof files[0], "between threads and MPI");
  char *j1 = nav_test_slurp_alloc(WORK "/m1/summary.json");
  char *j2 = nav_test_slurp_alloc(WORK "/mpi/summary.json");
  assert_non_null(j1);
  assert_non_null(j2);
  const char *b1 = strstr(j1, "\"stats_smoothed\""), *b2 = strstr(j2, "\"stats_smoothed\"");
  const char *e1 = strstr(j1, "\"requirements\""), *e2 = strstr(j2, "\"requirements\"");
  assert_non_null(b1);
  assert_non_null(b2);
  assert_int_equal(e1 - b1, e2 - b2);
  assert_memory_equal(b1, b2, (size_t)(e1 - b1));
  free(j1);
  free(j2);
}
#endif

static void test_run_without_smoother(void **state) {
  (void)state;
  write_scene("plain.yaml", "navigation:\n  scheme: ins_gnss\n");
  assert_int_equal(navsim("run plain.yaml --runs 1 --out plain -q"), 0);
  char *js = nav_test_slurp_alloc(WORK "/plain/summary.json");
  assert_non_null(js);
  assert_null(strstr(js, "stats_smoothed"));
  free(js);
  char *x = nav_test_slurp_alloc(WORK "/plain/nav_smoothed.csv");
  assert_null(x);
  x = nav_test_slurp_alloc(WORK "/plain/smoothed_errors.csv");
  assert_null(x);
}

static void test_smoother_needs_ins_gnss(void **state) {
  (void)state;
  write_scene("free.yaml", "navigation:\n  scheme: free_ins\n  smoother: true\n");
  assert_int_equal(navsim("check free.yaml"), 2);
  assert_non_null(strstr(g_r->err, "navigation.smoother"));
  assert_non_null(strstr(g_r->err, "ins_gnss"));
  assert_int_equal(navsim("run free.yaml --out free"), 2);
  assert_non_null(strstr(g_r->err, "navigation.smoother"));
  /* Not a boolean: a reader error naming the field. */
  write_scene("bad.yaml", "navigation:\n  scheme: ins_gnss\n  smoother: maybe\n");
  assert_int_equal(navsim("check bad.yaml"), 2);
  assert_non_null(strstr(g_r->err, "smoother"));
}

static void test_scene_round_trip(void **state) {
  (void)state;
  write_scene("rt.yaml", "navigation:\n  scheme: ins_gnss\n  smoother: true\n");
  nav_scene a, b;
  assert_int_equal(nav_scene_read_file(WORK "/rt.yaml", &a, NULL, NULL), NAV_OK);
  assert_true(a.navigation.smoother);
  assert_int_equal(nav_scene_write_file(WORK "/rt-out.yaml", &a), NAV_OK);
  char *text = nav_test_slurp_alloc(WORK "/rt-out.yaml");
  assert_non_null(text);
  assert_non_null(strstr(text, "smoother: true"));
  free(text);
  assert_int_equal(nav_scene_read_file(WORK "/rt-out.yaml", &b, NULL, NULL), NAV_OK);
  assert_true(b.navigation.smoother);
  assert_int_equal(a.navigation.scheme, b.navigation.scheme);
  assert_int_equal(a.navigation.algorithm, b.navigation.algorithm);
  assert_int_equal(a.navigation.frame, b.navigation.frame);
  assert_int_equal(a.navigation.aid_vertical, b.navigation.aid_vertical);
  assert_int_equal(a.navigation.cov_decimation, b.navigation.cov_decimation);
  assert_int_equal(a.navigation.estimate_scale_factors, b.navigation.estimate_scale_factors);
  /* And false stays false. */
  a.navigation.smoother = false;
  assert_int_equal(nav_scene_write_file(WORK "/rt-out.yaml", &a), NAV_OK);
  assert_int_equal(nav_scene_read_file(WORK "/rt-out.yaml", &b, NULL, NULL), NAV_OK);
  assert_false(b.navigation.smoother);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_run_writes_smoothed_results),
#ifdef MPIEXEC
      cmocka_unit_test(test_mpi_same_as_threads),
#endif
      cmocka_unit_test(test_run_without_smoother),
      cmocka_unit_test(test_smoother_needs_ins_gnss),
      cmocka_unit_test(test_scene_round_trip),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
