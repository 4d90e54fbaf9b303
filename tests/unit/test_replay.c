/*
 * navcore_io recorded data (nav_recorded.h): the KF-GINS text readers (valid input, every
 * malformed case with its line, column and message, streaming across buffer refills, files and
 * loaders) and the replay engine of `navsim replay` end to end on a 50 s vendored slice of the
 * gnss-ins-sim long_drive data (tests/data/replay/README.md).
 */
#define _POSIX_C_SOURCE 200809L

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_io.h"
#include "navcore/nav_recorded.h"

#define REPLAY_DIR NAV_TEST_DATA_DIR "/replay/"
#define SLICE_IMU REPLAY_DIR "IMU-100195-100245.txt"
#define SLICE_IMU_IDEAL REPLAY_DIR "IMU_ideal-100195-100245.txt"
#define SLICE_GNSS REPLAY_DIR "GNSS-100195-100245.txt"
#define SLICE_TRUTH REPLAY_DIR "truth-100195-100245-20Hz.nav"
#define SLICE_SCENE REPLAY_DIR "long-drive.yaml"

/* ---------------------------------------------------------------- helpers */

static nav_rec_reader *open_text(const char *text, size_t len, nav_rec_format fmt) {
  nav_rec_reader *r = NULL;
  assert_int_equal(nav_rec_reader_open_memory(text, len, "mem.txt", fmt, &r), NAV_OK);
  return r;
}

/* Read one record of any format. */
static nav_status read_any(nav_rec_reader *r, nav_rec_format fmt, bool *got) {
  nav_imu_increment a;
  nav_ins_gnss_fix g;
  nav_rec_pva p;
  switch (fmt) {
  case NAV_REC_IMU: return nav_rec_read_imu(r, &a, got);
  case NAV_REC_GNSS: return nav_rec_read_gnss(r, &g, got);
  default: return nav_rec_read_pva(r, &p, got);
  }
}

/*
 * Read @p text until the reader fails; the failure must be NAV_ERR_PARSE at @p line:@p col with
 * @p path (exact) and a message containing @p msg_part. The error is sticky.
 */
static void expect_parse_error_len(const char *text, size_t len, nav_rec_format fmt, int line, int col,
                                   const char *path, const char *msg_part) {
  nav_rec_reader *r = open_text(text, len, fmt);
  bool got = true;
  nav_status st = NAV_OK;
  int guard = 0;
  while (st == NAV_OK && got && guard++ < 100)
    st = read_any(r, fmt, &got);
  const nav_diag *d = nav_rec_reader_diag(r);
  char shown[2048];
  nav_diag_format(d, shown, sizeof shown);
  if (st != NAV_ERR_PARSE || d->line != line || d->col != col || strcmp(d->path, path) != 0 ||
      strstr(d->message, msg_part) == NULL)
    fail_msg("status %d, got \"%s\"; expected %d:%d path \"%s\" message containing \"%s\"", (int)st, shown,
             line, col, path, msg_part);
  /* Sticky: the same status again, no record. */
  got = true;
  assert_int_equal(read_any(r, fmt, &got), NAV_ERR_PARSE);
  assert_false(got);
  nav_rec_reader_destroy(r);
}

static void expect_parse_error(const char *text, nav_rec_format fmt, int line, int col, const char *path,
                               const char *msg_part) {
  expect_parse_error_len(text, strlen(text), fmt, line, col, path, msg_part);
}

static void write_file(const char *path, const char *text) {
  FILE *f = fopen(path, "wb");
  assert_non_null(f);
  assert_int_equal(fputs(text, f) >= 0, 1);
  assert_int_equal(fclose(f), 0);
}

static void temp_path(char *buf, size_t size, const char *name) {
  snprintf(buf, size, "/tmp/test_replay.%ld.%s", (long)getpid(), name);
}

static nav_scene *load_scene(const char *path) {
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(path, sc, NULL, NULL), NAV_OK);
  return sc;
}

/* The replay settings of the slice: the long-drive.yaml tuning (as KF-GINS was configured). */
static nav_replay_config slice_config(bool with_gnss) {
  nav_scene *sc = load_scene(SLICE_SCENE);
  nav_replay_config c = nav_replay_config_default();
  c.nav = nav_ins_gnss_config_from_scene(sc);
  free(sc);
  c.imu_path = with_gnss ? SLICE_IMU : SLICE_IMU_IDEAL;
  c.gnss_path = with_gnss ? SLICE_GNSS : NULL;
  c.ref_path = SLICE_TRUTH;
  return c;
}

static void print_diag_msg(const nav_diag *d) {
  char line[2048];
  nav_diag_format(d, line, sizeof line);
  print_message("  %s\n", line);
}

/* ---------------------------------------------------------------- readers: valid input */

static void test_imu_valid(void **state) {
  (void)state;
  const char *text = "# KF-GINS IMU increments\r\n"
                     "\n"
                     "100.000 1e-3 -2e-3 3.5e-3 0.01 -0.02 -0.049\r\n"
                     "   100.005\t1.0E-3 0 0 0 0 -0.049   \n"
                     "  \t \n"
                     "100.010 +1 -1 .5 5. 0 0";
  nav_rec_reader *r = open_text(text, strlen(text), NAV_REC_IMU);
  nav_imu_increment m;
  bool got = false;
  assert_int_equal(nav_rec_reader_line(r), 0);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_true(got);
  assert_int_equal(m.k, 0);
  assert_near(m.t_s, 100.0, 0.0);
  assert_near(m.dt_s, 0.0, 0.0); /* the first interval starts before the file */
  assert_vec3_near(m.dtheta_b_rad, nav_vec3_make(1e-3, -2e-3, 3.5e-3), 0.0);
  assert_vec3_near(m.dv_b_mps, nav_vec3_make(0.01, -0.02, -0.049), 0.0);
  assert_int_equal(nav_rec_reader_line(r), 3);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_true(got);
  assert_int_equal(m.k, 1);
  assert_near(m.dt_s, 0.005, 1e-12);
  assert_int_equal(nav_rec_reader_line(r), 4);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_true(got);
  assert_int_equal(m.k, 2);
  assert_near(m.t_s, 100.01, 0.0);
  assert_vec3_near(m.dtheta_b_rad, nav_vec3_make(1.0, -1.0, 0.5), 0.0);
  assert_vec3_near(m.dv_b_mps, nav_vec3_make(5.0, 0.0, 0.0), 0.0);
  assert_int_equal(nav_rec_reader_line(r), 6);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_false(got);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK); /* the end is stable */
  assert_false(got);
  assert_near(nav_rec_reader_fraction(r), 1.0, 0.0);
  assert_string_equal(nav_rec_reader_diag(r)->message, "");
  nav_rec_reader_destroy(r);
}

static void test_gnss_valid_7_and_13(void **state) {
  (void)state;
  /* The first rows of KF-GINS GNSS-RTK.txt (7 columns, trailing blanks) ... */
  const char *t7 = "456250.000    30.4447858054   114.4718661162     21.095    0.010    0.009    0.019 \n"
                   "456251.000    30.4447857891   200.0     21.091    0.010    0.009    0.019 \n";
  nav_rec_reader *r = open_text(t7, strlen(t7), NAV_REC_GNSS);
  nav_ins_gnss_fix f;
  bool got = false;
  assert_int_equal(nav_rec_read_gnss(r, &f, &got), NAV_OK);
  assert_true(got);
  assert_near(f.t_s, 456250.0, 0.0);
  assert_near(f.pos.lat_rad, 30.4447858054 * NAV_DEG2RAD, 1e-15);
  assert_near(f.pos.lon_rad, 114.4718661162 * NAV_DEG2RAD, 1e-15);
  assert_near(f.pos.h_m, 21.095, 0.0);
  assert_vec3_near(f.pos_sd_m, nav_vec3_make(0.010, 0.009, 0.019), 0.0);
  assert_false(f.has_vel);
  assert_int_equal(nav_rec_read_gnss(r, &f, &got), NAV_OK);
  assert_true(got);
  assert_near(f.pos.lon_rad, -160.0 * NAV_DEG2RAD, 1e-15); /* 200 deg wrapped to (-180, 180] */
  nav_rec_reader_destroy(r);

  /* ... and of KF-GINS-Matlab GNSS-POSVEL.txt (13 columns, degrees). */
  const char *t13 =
      "116450.000000   30.5284656653  114.3557363642 20.65300000 0.01000000 0.01100000 0.05400000 "
      "0.01200000 0.03600000 0.12800000 0.03500000 0.04800000 0.16100000\n";
  r = open_text(t13, strlen(t13), NAV_REC_GNSS);
  assert_int_equal(nav_rec_read_gnss(r, &f, &got), NAV_OK);
  assert_true(got);
  assert_true(f.has_vel);
  assert_near(f.pos.lat_rad, 30.5284656653 * NAV_DEG2RAD, 1e-15);
  assert_vec3_near(f.pos_sd_m, nav_vec3_make(0.010, 0.011, 0.054), 0.0);
  assert_vec3_near(f.v_n_mps, nav_vec3_make(0.012, 0.036, 0.128), 0.0);
  assert_vec3_near(f.vel_sd_mps, nav_vec3_make(0.035, 0.048, 0.161), 0.0);
  nav_rec_reader_destroy(r);
}

static void test_pva_valid_and_state(void **state) {
  (void)state;
  const char *text =
      "0    116454.000000 30.5284623915   114.3557363038  21.0190  1.0   -2.0   0.5  -0.22993   "
      "0.23987    359.50004 \n";
  nav_rec_reader *r = open_text(text, strlen(text), NAV_REC_PVA);
  nav_rec_pva p;
  bool got = false;
  assert_int_equal(nav_rec_read_pva(r, &p, &got), NAV_OK);
  assert_true(got);
  nav_rec_reader_destroy(r);
  assert_int_equal(p.week, 0);
  assert_near(p.t_s, 116454.0, 0.0);
  assert_near(p.att.roll_rad, -0.22993 * NAV_DEG2RAD, 1e-15);
  assert_near(p.att.pitch_rad, 0.23987 * NAV_DEG2RAD, 1e-15);
  assert_near(p.att.yaw_rad, -0.49996 * NAV_DEG2RAD, 1e-13); /* 359.50004 deg wrapped */

  /* The ECEF state reproduces the row: position, NED velocity and Euler angles. */
  const nav_traj_state s = nav_rec_pva_to_state(&p);
  assert_vec3_near(s.r_fb_f_m, nav_earth_geodetic_to_ecef(p.pos), 0.0);
  nav_frame fr;
  memset(&fr, 0, sizeof fr);
  fr.model = NAV_EARTH_WGS84;
  fr.origin = p.pos;
  fr.m_per_rad_lat = nav_earth_radius_meridian_m(p.pos.lat_rad) + p.pos.h_m;
  fr.m_per_rad_lon = (nav_earth_radius_prime_vertical_m(p.pos.lat_rad) + p.pos.h_m) * cos(p.pos.lat_rad);
  const nav_local_view v = nav_frame_view(&fr, s.r_fb_f_m, s.v_fb_f_mps, s.q_b_f);
  assert_near(v.pos.lat_rad, p.pos.lat_rad, 1e-12);
  assert_near(v.pos.h_m, p.pos.h_m, 1e-6);
  assert_vec3_near(v.v_n_mps, p.v_n_mps, 1e-12);
  const nav_euler e = nav_quat_to_euler(v.q_b_n, NULL);
  assert_near(e.roll_rad, p.att.roll_rad, 1e-12);
  assert_near(e.pitch_rad, p.att.pitch_rad, 1e-12);
  assert_near(e.yaw_rad, p.att.yaw_rad, 1e-12);
}

/* More than one 256 KiB buffer: lines straddle refills, CR-LF and no final line end. */
static void test_streaming_across_refills(void **state) {
  (void)state;
  const int n = 15000;
  const size_t cap = (size_t)n * 80 + 1;
  char *text = malloc(cap);
  assert_non_null(text);
  size_t len = 0;
  for (int k = 0; k < n; ++k)
    /* dv x = k / 2 and y = -(k / 2 + 0.5): exact, and within the reader's 1e4 m/s bound */
    len += (size_t)snprintf(text + len, cap - len, "%.3f 0 0.25 0 %.1f -%.1f -0.049%s", 1000.0 + 0.005 * k,
                            0.5 * k, 0.5 * k + 0.5, k + 1 == n ? "" : (k % 3 == 0 ? "\r\n" : "\n"));
  assert_true(len > 2 * 256 * 1024);
  nav_rec_reader *r = open_text(text, len, NAV_REC_IMU);
  nav_imu_increment m;
  bool got = false;
  int count = 0;
  while (nav_rec_read_imu(r, &m, &got) == NAV_OK && got) {
    if (m.k != count || m.dv_b_mps.x != 0.5 * count || m.dv_b_mps.y != -0.5 * count - 0.5 ||
        m.dtheta_b_rad.y != 0.25 || fabs(m.t_s - (1000.0 + 0.005 * count)) > 1e-9)
      fail_msg("record %d: k %lld t %.6f dv (%g, %g)", count, (long long)m.k, m.t_s, m.dv_b_mps.x,
               m.dv_b_mps.y);
    ++count;
  }
  assert_string_equal(nav_rec_reader_diag(r)->message, "");
  assert_int_equal(count, n);
  assert_int_equal(nav_rec_reader_line(r), n);
  nav_rec_reader_destroy(r);
  free(text);
}

/* A GUI may set a locale with a decimal comma: the files still use decimal points. */
static void test_numbers_ignore_process_locale(void **state) {
  (void)state;
  static const char *const names[] = {"de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8",
                                      "ru_RU.UTF-8"};
  const char *set = NULL;
  for (size_t i = 0; i < sizeof names / sizeof names[0] && set == NULL; ++i)
    set = setlocale(LC_NUMERIC, names[i]);
  if (set == NULL) {
    print_message("[ SKIPPED  ] no locale with a decimal comma is installed\n");
    skip();
  }
  const char *text = "100.5 0.25 0 0 0 0 -0.049\n";
  nav_rec_reader *r = open_text(text, strlen(text), NAV_REC_IMU);
  nav_imu_increment m;
  bool got = false;
  const nav_status st = nav_rec_read_imu(r, &m, &got);
  nav_rec_reader_destroy(r);
  setlocale(LC_NUMERIC, "C");
  assert_int_equal(st, NAV_OK);
  assert_true(got);
  assert_near(m.t_s, 100.5, 0.0);
  assert_near(m.dtheta_b_rad.x, 0.25, 0.0);
}

static void test_empty_and_comment_only(void **state) {
  (void)state;
  const char *texts[3] = {"", "# only a comment\n\n   \n", "\n"};
  for (int i = 0; i < 3; ++i) {
    nav_rec_reader *r = open_text(texts[i], strlen(texts[i]), NAV_REC_GNSS);
    nav_ins_gnss_fix f;
    bool got = true;
    assert_int_equal(nav_rec_read_gnss(r, &f, &got), NAV_OK);
    assert_false(got);
    nav_rec_reader_destroy(r);
  }
}

/* A last line without a line end is read, and reported as possibly cut (its line number), only
 * once it has been read; a file ending in a line end is not. */
static void test_cut_last_line(void **state) {
  (void)state;
  const char cut[] = "1 0 0 0 0 0 0\n# c\n2 0 0 0 0 0 0.0049";
  const char whole[] = "1 0 0 0 0 0 0\n# c\n2 0 0 0 0 0 0.0049\n";
  nav_rec_reader *r = open_text(cut, sizeof cut - 1, NAV_REC_IMU);
  nav_imu_increment m;
  bool got = false;
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_true(got);
  assert_int_equal(nav_rec_reader_cut_line(r), 0);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_true(got);
  assert_true(m.dv_b_mps.z == 0.0049);
  assert_int_equal(nav_rec_reader_cut_line(r), 3);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_false(got);
  assert_int_equal(nav_rec_reader_cut_line(r), 3);
  nav_rec_reader_destroy(r);
  r = open_text(whole, sizeof whole - 1, NAV_REC_IMU);
  do
    assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  while (got);
  assert_int_equal(nav_rec_reader_cut_line(r), 0);
  nav_rec_reader_destroy(r);
}

/* ---------------------------------------------------------------- readers: malformed input */

static void test_imu_malformed(void **state) {
  (void)state;
  expect_parse_error("1 2 3\n", NAV_REC_IMU, 1, 6, "", "expected 7 columns (t_s, dtheta x/y/z [rad]");
  expect_parse_error("1 2 3\n", NAV_REC_IMU, 1, 6, "", "found 3");
  expect_parse_error("1 2 3 4 5 6 7 8\n", NAV_REC_IMU, 1, 15, "", "found 8");
  expect_parse_error("# c\n\n1 2 x 4 5 6 7\n", NAV_REC_IMU, 3, 5, "column 3 (dtheta_y_rad)",
                     "expected a number, found \"x\"");
  expect_parse_error("1 2 3 NaN 5 6 7\n", NAV_REC_IMU, 1, 7, "column 4 (dtheta_z_rad)",
                     "expected a finite number, found \"NaN\"");
  expect_parse_error("1 2 3 4 -inf 6 7\n", NAV_REC_IMU, 1, 9, "column 5 (dvel_x_mps)",
                     "expected a finite number");
  expect_parse_error("1 2 3 4 1e999 6 7\n", NAV_REC_IMU, 1, 9, "column 5 (dvel_x_mps)", "out of the range");
  expect_parse_error("1 0x10 3 4 5 6 7\n", NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)", "expected a number");
  expect_parse_error("1 1.2.3 3 4 5 6 7\n", NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)",
                     "expected a number, found \"1.2.3\"");
  expect_parse_error("1,2,3,4,5,6,7\n", NAV_REC_IMU, 1, 1, "column 1 (t_s)", "expected a number");
  expect_parse_error("t dtheta_x dtheta_y dtheta_z dv_x dv_y dv_z\n", NAV_REC_IMU, 1, 1, "column 1 (t_s)",
                     "(a header line must start with '#')");
  /* Not increments: a GNSS file given as the IMU file, rates in deg/s. */
  expect_parse_error("456250.000 30.4447858054 114.4718661162 21.095 0.010 0.009 0.019\n", NAV_REC_IMU, 1, 12,
                     "column 2 (dtheta_x_rad)", "angle increment 30.4447858 rad exceeds pi");
  expect_parse_error("1 0 0 -3.5 0 0 -0.049\n", NAV_REC_IMU, 1, 7, "column 4 (dtheta_z_rad)",
                     "(not a rate, not degrees)");
  /* Time must strictly increase: equal, then decreasing. */
  expect_parse_error("1 2 3 0 5 6 7\n1 2 3 0 5 6 7\n", NAV_REC_IMU, 2, 1, "column 1 (t_s)",
                     "time must increase from record to record: 1.000000 s is not after 1.000000 s (line 1)");
  expect_parse_error("2 0 0 0 0 0 0\n\n  1.5 0 0 0 0 0 0\n", NAV_REC_IMU, 3, 3, "column 1 (t_s)",
                     "1.500000 s is not after 2.000000 s (line 1)");
  /* Bytes that are not UTF-8 are shown as '?', well-formed characters as they are, and a
   * shortened excerpt never cuts a multi-byte character (the message stays valid UTF-8). */
  expect_parse_error("1 \xff\xfe\xc3 3 4 5 6 7\n", NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)",
                     "expected a number, found \"???\"");
  expect_parse_error("1 \xc3\xa9t\xc3\xa9 3 4 5 6 7\n", NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)",
                     "expected a number, found \"\xc3\xa9t\xc3\xa9\"");
  expect_parse_error("1 \xed\xa0\x80 3 4 5 6 7\n", NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)",
                     "found \"???\"");
  expect_parse_error("1 x\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9"
                     "\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9 3 4 5 6 7\n",
                     NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)",
                     "found \"x\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9\xc3\xa9"
                     "\xc3\xa9\xc3\xa9\xc3\xa9...\"");
  /* A NUL byte inside a field (binary data). */
  const char nul[] = "1 2\0003 4 5 6 7 8\n";
  expect_parse_error_len(nul, sizeof nul - 1, NAV_REC_IMU, 1, 3, "column 2 (dtheta_x_rad)",
                         "expected a number");
  /* A line longer than NAV_REC_MAX_LINE. */
  char *big = malloc(NAV_REC_MAX_LINE + 100);
  assert_non_null(big);
  memset(big, '1', NAV_REC_MAX_LINE + 50);
  big[NAV_REC_MAX_LINE + 50] = '\n';
  expect_parse_error_len(big, NAV_REC_MAX_LINE + 51, NAV_REC_IMU, 1, NAV_REC_MAX_LINE + 1, "",
                         "line longer than 4096");
  free(big);
}

static void test_gnss_malformed(void **state) {
  (void)state;
  expect_parse_error("1 30 114 20 0.1 0.1 0.2 0 0\n", NAV_REC_GNSS, 1, 28, "",
                     "or 13 (the same, then velocity");
  expect_parse_error("1 30 114 20 0.1 0.1 0.2\n2 30 114 20 0.1 0.1 0.2 0 0 0 0.1 0.1 0.1\n", NAV_REC_GNSS, 2,
                     25, "", "expected 7 columns like the first record of the file, found 13");
  expect_parse_error("1 91 114 20 0.1 0.1 0.2\n", NAV_REC_GNSS, 1, 3, "column 2 (lat_deg)",
                     "latitude 91 deg outside [-90, 90]");
  expect_parse_error("1 30 400 20 0.1 0.1 0.2\n", NAV_REC_GNSS, 1, 6, "column 3 (lon_deg)",
                     "longitude 400 deg outside [-180, 360]");
  expect_parse_error("1 30 114 20 0.1 0.1 -0.2\n", NAV_REC_GNSS, 1, 21, "column 7 (sd_d_m)",
                     "standard deviation -0.2 is negative");
  expect_parse_error("1 30 114 20 0.1 0.1 0.2 0 0 0 0.1 -1 0.1\n", NAV_REC_GNSS, 1, 35,
                     "column 12 (vel_sd_e_mps)", "is negative");
  expect_parse_error("5 30 114 20 0.1 0.1 0.2\n4 30 114 20 0.1 0.1 0.2\n", NAV_REC_GNSS, 2, 1,
                     "column 1 (t_s)", "time must increase");
}

static void test_pva_malformed(void **state) {
  (void)state;
  const char *ok_tail = " 1 30 114 20 0 0 0 0 0 0\n";
  char text[256];
  snprintf(text, sizeof text, "1.5%s", ok_tail);
  expect_parse_error(text, NAV_REC_PVA, 1, 1, "column 1 (week)", "GPS week 1.5: expected an integer >= 0");
  expect_parse_error("0 1 30 114 20 0 0 0 0 91 0\n", NAV_REC_PVA, 1, 23, "column 10 (pitch_deg)",
                     "pitch 91 deg outside [-90, 90]");
  expect_parse_error("0 1 30 114 20 0 0 0 -181 0 0\n", NAV_REC_PVA, 1, 21, "column 9 (roll_deg)",
                     "roll -181 deg");
  expect_parse_error("0 1 30 114 20 0 0 0 0 0 361\n", NAV_REC_PVA, 1, 25, "column 11 (yaw_deg)",
                     "yaw 361 deg outside [-180, 360]");
  expect_parse_error("0 1 30 114 20 0 0 0 0 0\n", NAV_REC_PVA, 1, 24, "", "expected 11 columns (week, t_s");
  expect_parse_error("0 1 30 114 20 0 0 0 0 0 0\n0 1 30 114 20 0 0 0 0 0 0\n", NAV_REC_PVA, 2, 3,
                     "column 2 (t_s)", "time must increase");
}

static void test_reader_misuse(void **state) {
  (void)state;
  const char *text = "1 2 3 4 5 6 7\n";
  nav_rec_reader *r = open_text(text, strlen(text), NAV_REC_IMU);
  nav_ins_gnss_fix f;
  bool got = true;
  assert_int_equal(nav_rec_read_gnss(r, &f, &got), NAV_ERR_INVALID_ARG); /* an IMU reader */
  assert_int_equal(nav_rec_read_imu(r, NULL, &got), NAV_ERR_INVALID_ARG);
  nav_rec_reader_destroy(r);
  nav_rec_reader_destroy(NULL);
  assert_int_equal(nav_rec_reader_open_memory(text, 1, "x", (nav_rec_format)7, &r), NAV_ERR_INVALID_ARG);
  nav_diag d;
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_rec_reader_open("/nonexistent/dir/IMU.txt", NAV_REC_IMU, &r, &d), NAV_ERR_IO);
  assert_int_equal(d.line, 0);
  assert_string_equal(d.file, "/nonexistent/dir/IMU.txt");
  assert_non_null(strstr(d.message, "cannot open the IMU file"));
}

/* A real file: the formatted diagnostic is FILE:LINE:COL: error: COLUMN: MESSAGE. */
static void test_file_diagnostic_format(void **state) {
  (void)state;
  char path[256];
  temp_path(path, sizeof path, "bad-imu.txt");
  write_file(path, "# header\n100.000 0 0 0 0 0 -0.049\n100.005 0 x 0 0 0 -0.049\n");
  nav_rec_reader *r = NULL;
  nav_diag d;
  assert_int_equal(nav_rec_reader_open(path, NAV_REC_IMU, &r, &d), NAV_OK);
  nav_imu_increment m;
  bool got = false;
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_OK);
  assert_true(got);
  assert_int_equal(nav_rec_read_imu(r, &m, &got), NAV_ERR_PARSE);
  char line[2048], expected[1024];
  nav_diag_format(nav_rec_reader_diag(r), line, sizeof line);
  snprintf(expected, sizeof expected,
           "%s:3:11: error: column 3 (dtheta_y_rad): expected a number, found \"x\"", path);
  assert_string_equal(line, expected);
  nav_rec_reader_destroy(r);
  unlink(path);
}

static void test_loaders_capacity(void **state) {
  (void)state;
  char path[256];
  temp_path(path, sizeof path, "gnss.txt");
  write_file(path, "1 30 114 20 0.1 0.1 0.2\n2 30 114 20 0.1 0.1 0.2\n3 30 114 20 0.1 0.1 0.2\n");
  nav_ins_gnss_fix f[3];
  size_t n = 99;
  nav_diag d;
  assert_int_equal(nav_rec_load_gnss(path, f, 3, &n, &d), NAV_OK);
  assert_int_equal(n, 3);
  assert_near(f[2].t_s, 3.0, 0.0);
  n = 99;
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_rec_load_gnss(path, f, 2, &n, &d), NAV_ERR_OUT_OF_RANGE);
  assert_int_equal(n, 99); /* untouched on failure */
  assert_non_null(strstr(d.message, "more than 2 records"));
  assert_int_equal(d.line, 3);
  /* A parse error comes back with its place. */
  write_file(path, "1 30 114 20 0.1 0.1 0.2\n2 30 114 20 0.1 0.1\n");
  assert_int_equal(nav_rec_load_gnss(path, f, 3, &n, &d), NAV_ERR_PARSE);
  assert_int_equal(d.line, 2);
  assert_non_null(strstr(d.message, "found 6"));
  unlink(path);
}

/* ---------------------------------------------------------------- replay end to end */

typedef struct rec_count {
  int records, with_ref, updates;
  int stop_after; /* 0: never */
} rec_count;

static nav_callback_result count_records(void *user, const nav_replay_record *r) {
  rec_count *c = user;
  c->records++;
  if (r->ref && r->err) c->with_ref++;
  if (r->gnss_update) c->updates++;
  return (c->stop_after > 0 && c->records >= c->stop_after) ? NAV_STOP : NAV_CONTINUE;
}

static void print_stats(const char *what, const nav_replay_stats *s) {
  print_message(
      "  %s: %ld epochs; horiz. pos RMS %.4f max %.4f m; vert. pos RMS %.4f max %.4f m; horiz. vel "
      "RMS %.5f max %.5f m/s; vert. vel RMS %.5f m/s; roll/pitch/yaw RMS %.2e/%.2e/%.2e deg, yaw max "
      "%.2e deg\n",
      what, s->epochs, s->pos_h_m.rms, s->pos_h_m.max, s->pos_v_m.rms, s->pos_v_m.max, s->vel_h_mps.rms,
      s->vel_h_mps.max, s->vel_v_mps.rms, s->roll_rad.rms * NAV_RAD2DEG, s->pitch_rad.rms * NAV_RAD2DEG,
      s->yaw_rad.rms * NAV_RAD2DEG, s->yaw_rad.max * NAV_RAD2DEG);
}

/*
 * Closed loop on the 50 s slice (start at rest, accelerate, 70 deg turn, accelerate to 10 m/s).
 * The fixes have white noise of 0.02 m per horizontal axis and 0.05 m vertically (README), and
 * the filter starts from the exact reference with the KF-GINS initial sigmas of the same size.
 * A filter that averages fixes through the IMU must do at least as well as a single fix:
 * horizontal RMS below 0.05 m (the 2-D RMS of one fix is 0.028 m; 0.05 m leaves room for the
 * turn), horizontal max below 0.15 m, vertical RMS below 0.10 m (2x the fix sigma). Velocity
 * and heading: the fixes constrain them to about 0.02 m/s and the initial heading sigma is
 * 0.2 deg. Measured: 0.022 / 0.061 m, 0.035 m, 0.009 m/s, yaw RMS 0.033 deg.
 */
static void test_replay_slice_closed_loop(void **state) {
  (void)state;
  nav_replay_config c = slice_config(true);
  rec_count rc = {0, 0, 0, 0};
  c.record = count_records;
  c.user = &rc;
  nav_replay_summary s;
  nav_diag d;
  memset(&d, 0, sizeof d);
  const nav_status st = nav_replay_run(&c, &s, &d);
  if (st != NAV_OK) print_diag_msg(&d);
  assert_int_equal(st, NAV_OK);
  print_stats("closed loop, 50 s slice", &s.stats);
  assert_false(s.free_ins);
  assert_near(s.t_first_s, 100195.0, 1e-9);
  assert_near(s.t_last_s, 100245.0, 1e-9);
  assert_int_equal(s.imu_records, 10001);
  assert_int_equal(s.imu_steps, 10000);
  assert_int_equal(s.imu_gaps, 0);
  assert_int_equal(s.ref_rows, 1001);
  assert_int_equal(s.ref_unmatched, 0);
  assert_int_equal(s.stats.epochs, 1000); /* every 20 Hz reference row after the initial one */
  assert_int_equal(s.gnss_records, 51);
  assert_int_equal(s.gnss_before_start, 1); /* the fix at the initial epoch */
  assert_int_equal(s.gnss_applied, 50);
  assert_int_equal(s.gnss_dropped, 0);
  assert_int_equal(s.gnss_unmatched, 0);
  assert_int_equal(s.gap_count, 0);
  assert_false(s.partial);
  /* 10 Hz output: the initial epoch (a multiple of 0.1 s) and 500 more, each with a reference. */
  assert_int_equal(rc.records, 501);
  assert_int_equal(rc.with_ref, 501);
  assert_int_equal(rc.updates, 50);
  assert_int_equal(s.stats_output.epochs, 500);
  assert_true(s.stats.pos_h_m.rms < 0.05);
  assert_true(s.stats.pos_h_m.max < 0.15);
  assert_true(s.stats.pos_v_m.rms < 0.10);
  assert_true(s.stats.vel_h_mps.rms < 0.03);
  assert_true(s.stats.vel_v_mps.rms < 0.03);
  assert_true(s.stats.yaw_rad.rms * NAV_RAD2DEG < 0.2);
  assert_true(s.stats.roll_rad.rms * NAV_RAD2DEG < 0.05);
  assert_true(s.stats.pitch_rad.rms * NAV_RAD2DEG < 0.05);
}

/*
 * Free-inertial replay of the simulator's error-free IMU. The README: gnss-ins-sim integrates its
 * truth with first-order Euler steps, so a rigorous mechanization departs from it by a steady
 * velocity offset (about 1 cm/s over the whole 965 s run). Per step, the truth adds C_b_n(k)
 * dv_k, with the attitude at the START of the interval, where a mechanization rotates dv by the
 * attitude in mid-interval (rotation compensation): they differ by 1/2 |dtheta_k x dv_k| at
 * most. So the velocity offset is bounded by B_v(t) = sum 1/2 |dtheta x dv| up to t, computed
 * here from the vendored ideal increments. The truth's position is also Euler (p += v(k) dt)
 * where ours is trapezoidal: 1/2 dt |v(t) - v(0)| more. The horizontal position error is then
 * bounded by 1/2 dt max|v| + sum B_v(t_k) dt. Attitude has no such term: the README says it
 * agrees exactly, and within 1e-4 deg here.
 */
static void test_replay_slice_free_ins_ideal(void **state) {
  (void)state;
  const size_t cap = 10001;
  nav_imu_increment *imu = malloc(cap * sizeof *imu);
  nav_rec_pva *ref = malloc(1001 * sizeof *ref);
  assert_non_null(imu);
  assert_non_null(ref);
  size_t n = 0, n_ref = 0;
  nav_diag d;
  assert_int_equal(nav_rec_load_imu(SLICE_IMU_IDEAL, imu, cap, &n, &d), NAV_OK);
  assert_int_equal(n, cap);
  assert_int_equal(nav_rec_load_pva(SLICE_TRUTH, ref, 1001, &n_ref, &d), NAV_OK);
  double b_v = 0.0, b_p = 0.0, v_max = 0.0;
  for (size_t k = 1; k < n; ++k) {
    b_v += 0.5 * nav_vec3_norm(nav_vec3_cross(imu[k].dtheta_b_rad, imu[k].dv_b_mps));
    b_p += b_v * imu[k].dt_s;
  }
  for (size_t k = 0; k < n_ref; ++k)
    v_max = fmax(v_max, hypot(ref[k].v_n_mps.x, ref[k].v_n_mps.y));
  b_p += 0.5 * imu[1].dt_s * v_max;
  free(imu);
  free(ref);

  nav_replay_config c = slice_config(false);
  nav_replay_summary s;
  memset(&d, 0, sizeof d);
  const nav_status st = nav_replay_run(&c, &s, &d);
  if (st != NAV_OK) print_diag_msg(&d);
  assert_int_equal(st, NAV_OK);
  print_stats("free INS, ideal IMU, 50 s slice", &s.stats);
  print_message(
      "  truth-inconsistency bounds: velocity %.5f m/s, horizontal position %.4f m (measured %.5f m/s, "
      "%.4f m; mean velocity error N/E %.5f/%.5f m/s)\n",
      b_v, b_p, s.stats.vel_h_mps.max, s.stats.pos_h_m.max, s.stats.vel_mean_n_mps.x,
      s.stats.vel_mean_n_mps.y);
  assert_true(s.free_ins);
  assert_int_equal(s.stats.epochs, 1000);
  assert_true(s.stats.vel_h_mps.max <= b_v);
  assert_true(s.stats.pos_h_m.max <= b_p);
  /* Level motion at h = 0: no vertical term in the bound; the free vertical channel grows as
   * exp(t / 570 s), so 50 s cannot turn the 1e-6 m/s-level differences into 1 cm. */
  assert_true(s.stats.pos_v_m.max < 0.01);
  assert_true(s.stats.att_rad.max * NAV_RAD2DEG < 1e-4);
}

/*
 * 13-column GNSS (position + velocity, as KF-GINS-Matlab's GNSS-POSVEL.txt): the slice's fixes
 * with the reference velocity at the fix time and a stated sigma of 0.05 m/s. The velocity
 * updates are applied (has_vel) and the velocity error stays within the closed-loop bounds.
 */
static void test_replay_slice_gnss_velocity(void **state) {
  (void)state;
  nav_ins_gnss_fix fixes[64];
  nav_rec_pva *ref = malloc(1001 * sizeof *ref);
  assert_non_null(ref);
  size_t n_fix = 0, n_ref = 0;
  nav_diag d;
  assert_int_equal(nav_rec_load_gnss(SLICE_GNSS, fixes, 64, &n_fix, &d), NAV_OK);
  assert_int_equal(nav_rec_load_pva(SLICE_TRUTH, ref, 1001, &n_ref, &d), NAV_OK);
  char path[256];
  temp_path(path, sizeof path, "gnss13.txt");
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  size_t j = 0;
  for (size_t i = 0; i < n_fix; ++i) {
    while (j < n_ref && ref[j].t_s < fixes[i].t_s - 1e-6)
      ++j;
    assert_true(j < n_ref);
    const nav_ins_gnss_fix *x = &fixes[i];
    fprintf(f, "%.3f %.11f %.11f %.4f %.3f %.3f %.3f %.6f %.6f %.6f 0.05 0.05 0.05\n", x->t_s,
            x->pos.lat_rad * NAV_RAD2DEG, x->pos.lon_rad * NAV_RAD2DEG, x->pos.h_m, x->pos_sd_m.x,
            x->pos_sd_m.y, x->pos_sd_m.z, ref[j].v_n_mps.x, ref[j].v_n_mps.y, ref[j].v_n_mps.z);
  }
  assert_int_equal(fclose(f), 0);
  free(ref);
  nav_replay_config c = slice_config(true);
  c.gnss_path = path;
  nav_replay_summary s;
  memset(&d, 0, sizeof d);
  const nav_status st = nav_replay_run(&c, &s, &d);
  if (st != NAV_OK) print_diag_msg(&d);
  assert_int_equal(st, NAV_OK);
  print_stats("closed loop with GNSS velocity, 50 s slice", &s.stats);
  assert_true(s.gnss_has_vel);
  assert_int_equal(s.gnss_applied, 50);
  assert_true(s.stats.pos_h_m.rms < 0.05);
  assert_true(s.stats.vel_h_mps.rms < 0.03);
  assert_true(s.stats.vel_v_mps.rms < 0.03);
  unlink(path);
}

/* A requested outage: the fixes are dropped, the gap is found and scored at its end. */
static void test_replay_slice_outage(void **state) {
  (void)state;
  nav_replay_config c = slice_config(true);
  c.outage_count = 1;
  c.outages[0].t0_s = 100220.0;
  c.outages[0].t1_s = 100235.0;
  nav_replay_summary s;
  nav_diag d;
  memset(&d, 0, sizeof d);
  const nav_status st = nav_replay_run(&c, &s, &d);
  if (st != NAV_OK) print_diag_msg(&d);
  assert_int_equal(st, NAV_OK);
  assert_int_equal(s.gnss_dropped, 15);
  assert_int_equal(s.gnss_applied, 35);
  assert_int_equal(s.gap_count, 1);
  assert_near(s.gaps[0].t0_s, 100219.0, 1e-9);
  assert_near(s.gaps[0].t1_s, 100235.0, 1e-9);
  assert_false(s.gaps[0].open);
  assert_true(s.gaps[0].has_end_errors);
  print_message("  16 s outage: horizontal error at its end %.3f m, vertical %.3f m\n", s.gaps[0].pos_h_end_m,
                s.gaps[0].pos_v_end_m);
  /* 16 s of free inertial: VRW 0.1 m/s/sqrt(h) gives 1.67e-3 * 16^1.5 / sqrt(3) = 0.06 m per axis;
   * a residual accel bias of 1e-3 m/s^2 another 0.13 m; a 0.2 deg heading error at 10 m/s 0.06 m. */
  assert_true(s.gaps[0].pos_h_end_m < 0.5);
  assert_true(s.gaps[0].pos_h_max_m >= s.gaps[0].pos_h_end_m);
  assert_true(s.gaps[0].pos_v_end_m < 0.5);

  /* An outage reaching the end of the run is an open gap. */
  c.outages[0].t0_s = 100240.0;
  c.outages[0].t1_s = 100300.0;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_OK);
  assert_int_equal(s.gap_count, 1);
  assert_true(s.gaps[0].open);
  assert_near(s.gaps[0].t0_s, 100239.0, 1e-9);
  assert_near(s.gaps[0].t1_s, 100245.0, 1e-9);
}

/* --start / --end: the initial epoch is the first IMU epoch in the window with a reference row. */
static void test_replay_window(void **state) {
  (void)state;
  nav_replay_config c = slice_config(true);
  c.has_start = true;
  c.t_start_s = 100200.001; /* between reference rows: the next one (100200.050) starts */
  c.has_end = true;
  c.t_end_s = 100210.0;
  nav_replay_summary s;
  nav_diag d;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_OK);
  assert_near(s.t_first_s, 100200.05, 1e-9);
  assert_near(s.t_last_s, 100210.0, 1e-9);
  assert_int_equal(s.imu_steps, 1990);
  assert_int_equal(s.stats.epochs, 199);
  assert_int_equal(s.gnss_applied, 10);
}

static void test_replay_errors(void **state) {
  (void)state;
  nav_replay_summary s;
  nav_diag d;
  /* No IMU epoch in the window. */
  nav_replay_config c = slice_config(true);
  c.has_start = true;
  c.t_start_s = 100300.0;
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(d.message, "no IMU epoch in the time window coincides with a row of the reference"));
  /* Settings. */
  c = slice_config(true);
  c.imu_path = NULL;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_INVALID_ARG);
  c = slice_config(true);
  c.nav.ins.earth_model = NAV_EARTH_FLAT;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(d.message, "WGS-84"));
  c = slice_config(true);
  c.outage_count = 1;
  c.outages[0].t0_s = 5.0;
  c.outages[0].t1_s = 5.0;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_INVALID_ARG);
  /* A malformed IMU file: the reader's place comes back. */
  char path[256];
  temp_path(path, sizeof path, "imu-bad.txt");
  write_file(path, "100195.000000 0 0 0 0 0 -0.049\n100195.005000 0 0 0 0 0 -0.049\n"
                   "100195.010000 0 0 0 0 0 -0.049\n100195.015000 0 0 0 0 0\n");
  c = slice_config(true);
  c.imu_path = path;
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_PARSE);
  assert_string_equal(d.file, path);
  assert_int_equal(d.line, 4);
  assert_non_null(strstr(d.message, "expected 7 columns"));
  unlink(path);
  /* An empty reference: nothing to start from. */
  temp_path(path, sizeof path, "empty.nav");
  write_file(path, "# no rows\n");
  c = slice_config(true);
  c.ref_path = path;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(d.message, "the initial state is taken from the reference"));
  unlink(path);
  /* A missing reference file. */
  c = slice_config(true);
  c.ref_path = "/nonexistent/truth.nav";
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_IO);
  assert_non_null(strstr(d.message, "cannot open the .nav file"));
}

static void test_replay_cancel(void **state) {
  (void)state;
  nav_replay_config c = slice_config(true);
  rec_count rc = {0, 0, 0, 5};
  c.record = count_records;
  c.user = &rc;
  nav_replay_summary s;
  nav_diag d;
  assert_int_equal(nav_replay_run(&c, &s, &d), NAV_ERR_CANCELLED);
  assert_true(s.partial);
  assert_int_equal(rc.records, 5);
  assert_near(s.t_last_s, 100195.4, 1e-9);
}

/* The peer scorer: the reference against itself is exact; a shifted copy shows the shift. */
static void test_score_pva(void **state) {
  (void)state;
  nav_replay_stats s;
  nav_diag d;
  assert_int_equal(nav_replay_score_pva(SLICE_TRUTH, SLICE_TRUTH, false, 0.0, false, 0.0, 1e-4, &s, &d),
                   NAV_OK);
  assert_int_equal(s.epochs, 1001);
  assert_near(s.pos_h_m.max, 0.0, 1e-9);
  assert_near(s.vel_h_mps.max, 0.0, 1e-12);
  assert_near(s.yaw_rad.max, 0.0, 1e-12);
  /* Every row 1e-5 deg of latitude north (1.11 m) and 0.5 deg of yaw off, in a window. */
  char path[256];
  temp_path(path, sizeof path, "peer.nav");
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  nav_rec_reader *r = NULL;
  assert_int_equal(nav_rec_reader_open(SLICE_TRUTH, NAV_REC_PVA, &r, &d), NAV_OK);
  nav_rec_pva p;
  bool got = false;
  while (nav_rec_read_pva(r, &p, &got) == NAV_OK && got)
    fprintf(f, "0 %.6f %.11f %.11f %.4f %.6f %.6f %.6f %.6f %.6f %.6f\n", p.t_s,
            p.pos.lat_rad * NAV_RAD2DEG + 1e-5, p.pos.lon_rad * NAV_RAD2DEG, p.pos.h_m, p.v_n_mps.x,
            p.v_n_mps.y, p.v_n_mps.z, p.att.roll_rad * NAV_RAD2DEG, p.att.pitch_rad * NAV_RAD2DEG,
            nav_wrap_two_pi(p.att.yaw_rad) * NAV_RAD2DEG + 0.5);
  nav_rec_reader_destroy(r);
  assert_int_equal(fclose(f), 0);
  assert_int_equal(nav_replay_score_pva(SLICE_TRUTH, path, true, 100200.0, true, 100210.0, 1e-4, &s, &d),
                   NAV_OK);
  assert_int_equal(s.epochs, 201);
  const double dn = 1e-5 * NAV_DEG2RAD * (nav_earth_radius_meridian_m(31.5 * NAV_DEG2RAD));
  assert_near(s.pos_h_m.rms, dn, 0.01);
  assert_near(s.pos_mean_n_m.x, dn, 0.01);
  assert_near(s.yaw_rad.rms * NAV_RAD2DEG, 0.5, 1e-5);
  unlink(path);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_imu_valid),
      cmocka_unit_test(test_gnss_valid_7_and_13),
      cmocka_unit_test(test_pva_valid_and_state),
      cmocka_unit_test(test_streaming_across_refills),
      cmocka_unit_test(test_numbers_ignore_process_locale),
      cmocka_unit_test(test_empty_and_comment_only),
      cmocka_unit_test(test_cut_last_line),
      cmocka_unit_test(test_imu_malformed),
      cmocka_unit_test(test_gnss_malformed),
      cmocka_unit_test(test_pva_malformed),
      cmocka_unit_test(test_reader_misuse),
      cmocka_unit_test(test_file_diagnostic_format),
      cmocka_unit_test(test_loaders_capacity),
      cmocka_unit_test(test_replay_slice_closed_loop),
      cmocka_unit_test(test_replay_slice_free_ins_ideal),
      cmocka_unit_test(test_replay_slice_gnss_velocity),
      cmocka_unit_test(test_replay_slice_outage),
      cmocka_unit_test(test_replay_window),
      cmocka_unit_test(test_replay_errors),
      cmocka_unit_test(test_replay_cancel),
      cmocka_unit_test(test_score_pva),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
