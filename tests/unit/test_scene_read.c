/*
 * navcore_io scene files, format_version 1: reading the canonical scene and its variants, one
 * test per kind of error (exact line, column, field path and message), several errors in one
 * file, validation messages placed in the file, hostile input, and bit-exact write/read round
 * trips.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "nav_test.h"
#include "navcore/nav_io.h"

#define SCENES_DIR NAV_TEST_DATA_DIR "/scenes/"

/* ---------------------------------------------------------------- helpers */

typedef struct diag_log {
  int n;
  nav_diag d[NAV_DIAG_MAX_PER_FILE + 1];
} diag_log;

static void collect(void *user, const nav_diag *d) {
  diag_log *log = user;
  if (log->n < (int)(sizeof log->d / sizeof log->d[0])) log->d[log->n] = *d;
  log->n++;
}

static void print_log(const diag_log *log) {
  char line[2048];
  for (int i = 0; i < log->n && i < NAV_DIAG_MAX_PER_FILE; ++i) {
    nav_diag_format(&log->d[i], line, sizeof line);
    print_message("  [%d] %s\n", i, line);
  }
}

static nav_status read_text(const char *text, nav_scene *out, diag_log *log) {
  memset(log, 0, sizeof *log);
  return nav_scene_read_string(text, strlen(text), "test.yaml", out, collect, log);
}

static nav_status read_path(const char *path, nav_scene *out, diag_log *log) {
  memset(log, 0, sizeof *log);
  return nav_scene_read_file(path, out, collect, log);
}

/* Diagnostic @p i is at line:col, with this path and a message containing @p part. */
static void expect_diag(const diag_log *log, int i, int line, int col, const char *path, const char *part) {
  if (i >= log->n) {
    print_log(log);
    fail_msg("expected a diagnostic #%d, got %d diagnostics", i, log->n);
  }
  const nav_diag *d = &log->d[i];
  if (d->line != line || d->col != col || strcmp(d->path, path) != 0 || strstr(d->message, part) == NULL) {
    print_log(log);
    fail_msg("diagnostic #%d: got %d:%d path \"%s\" message \"%s\"; expected %d:%d path \"%s\" message with "
             "\"%s\"",
             i, d->line, d->col, d->path, d->message, line, col, path, part);
  }
}

/* Exactly one diagnostic, as described. */
static void expect_one(const char *text, int line, int col, const char *path, const char *part) {
  diag_log log;
  nav_scene s;
  const nav_status st = read_text(text, &s, &log);
  if (st != NAV_ERR_PARSE || log.n != 1) {
    print_log(&log);
    fail_msg("status %s with %d diagnostics for:\n%s", nav_status_str(st), log.n, text);
  }
  expect_diag(&log, 0, line, col, path, part);
}

static nav_scene read_ok(const char *text) {
  diag_log log;
  nav_scene s;
  memset(&s, 0, sizeof s);
  const nav_status st = read_text(text, &s, &log);
  if (st != NAV_OK) {
    print_log(&log);
    fail_msg("status %s for:\n%s", nav_status_str(st), text);
  }
  return s;
}

static int same_double(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

#define assert_same_double(a, b)                                                                             \
  do {                                                                                                       \
    const double sa_ = (a), sb_ = (b);                                                                       \
    if (!same_double(sa_, sb_)) fail_msg("%s = %.17g differs from %.17g (bit for bit)", #a, sa_, sb_);       \
  } while (0)
#define assert_same_vec3(a, b)                                                                               \
  do {                                                                                                       \
    assert_same_double((a).x, (b).x);                                                                        \
    assert_same_double((a).y, (b).y);                                                                        \
    assert_same_double((a).z, (b).z);                                                                        \
  } while (0)

/* Every field of two scenes is identical, doubles bit for bit. */
static void assert_scene_same(const nav_scene *a, const nav_scene *b) {
  assert_int_equal(a->format_version, b->format_version);
  assert_string_equal(a->name, b->name);
  assert_int_equal(a->earth.model, b->earth.model);
  assert_same_double(a->earth.origin_lat_rad, b->earth.origin_lat_rad);
  assert_same_double(a->earth.origin_lon_rad, b->earth.origin_lon_rad);
  assert_same_double(a->earth.origin_h_m, b->earth.origin_h_m);
  assert_same_double(a->earth.flat_gravity_mps2, b->earth.flat_gravity_mps2);
  assert_int_equal(a->trajectory.type, b->trajectory.type);
  assert_same_double(a->trajectory.duration_s, b->trajectory.duration_s);
  assert_same_double(a->trajectory.initial_attitude.roll_rad, b->trajectory.initial_attitude.roll_rad);
  assert_same_double(a->trajectory.initial_attitude.pitch_rad, b->trajectory.initial_attitude.pitch_rad);
  assert_same_double(a->trajectory.initial_attitude.yaw_rad, b->trajectory.initial_attitude.yaw_rad);
  const nav_traj_parametric *p = &a->trajectory.parametric, *q = &b->trajectory.parametric;
  assert_same_vec3(p->r0_m, q->r0_m);
  assert_same_vec3(p->v0_mps, q->v0_mps);
  assert_same_vec3(p->a_mps2, q->a_mps2);
  assert_same_vec3(p->b_m, q->b_m);
  assert_same_vec3(p->c_hz, q->c_hz);
  assert_same_vec3(p->d_rad, q->d_rad);
  assert_same_vec3(p->wa_rps, q->wa_rps);
  assert_same_vec3(p->wb_rps, q->wb_rps);
  assert_same_vec3(p->wc_hz, q->wc_hz);
  assert_same_vec3(p->wd_rad, q->wd_rad);
  assert_int_equal(p->attitude_mode, q->attitude_mode);
  assert_int_equal(p->magnus_substeps, q->magnus_substeps);
  assert_same_double(a->imu.rate_hz, b->imu.rate_hz);
  assert_int_equal(a->imu.quadrature_nodes, b->imu.quadrature_nodes);
  assert_int_equal(a->navigation.algorithm, b->navigation.algorithm);
  assert_same_double(a->output.rate_hz, b->output.rate_hz);
  assert_true(a->simulation.seed == b->simulation.seed);
  assert_int_equal(a->simulation.runs, b->simulation.runs);
}

/* A private directory for written files, removed with its content by rm_dir. */
static void make_dir(char *buf, size_t size) {
  snprintf(buf, size, "/tmp/test_scene_read.XXXXXX");
  assert_non_null(mkdtemp(buf));
}

static int count_entries(const char *dir) {
  DIR *d = opendir(dir);
  int n = 0;
  assert_non_null(d);
  for (struct dirent *e = readdir(d); e != NULL; e = readdir(d))
    if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0) ++n;
  closedir(d);
  return n;
}

static void rm_dir(const char *dir) {
  DIR *d = opendir(dir);
  char path[1024];
  if (d == NULL) return;
  for (struct dirent *e = readdir(d); e != NULL; e = readdir(d)) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
    unlink(path);
  }
  closedir(d);
  rmdir(dir);
}

static char *slurp(const char *path) {
  FILE *fp = fopen(path, "rb");
  assert_non_null(fp);
  static char buf[1 << 16];
  const size_t n = fread(buf, 1, sizeof buf - 1, fp);
  fclose(fp);
  buf[n] = '\0';
  return buf;
}

/* ---------------------------------------------------------------- valid files */

static void test_canonical_paper_parametric(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  const nav_status st = read_path(NAV_SOURCE_DIR "/scenes/paper-parametric.yaml", &s, &log);
  if (st != NAV_OK) print_log(&log);
  assert_int_equal(st, NAV_OK);
  assert_int_equal(log.n, 0);
  const double tol = 1e-15; /* exact decimal inputs: only the degree conversion rounds */
  assert_int_equal(s.format_version, 1);
  assert_string_equal(s.name, "paper-parametric");
  assert_int_equal(s.earth.model, NAV_EARTH_FLAT);
  assert_near(s.earth.origin_lat_rad, 45.0 * NAV_PI / 180.0, tol);
  assert_near(s.earth.origin_lon_rad, 0.0, tol);
  assert_near(s.earth.origin_h_m, 0.0, tol);
  assert_near(s.earth.flat_gravity_mps2, 9.80665, tol);
  assert_int_equal(s.trajectory.type, NAV_TRAJ_PARAMETRIC);
  assert_near(s.trajectory.duration_s, 20.0, tol);
  assert_near(s.trajectory.initial_attitude.roll_rad, 0.0, tol);
  assert_near(s.trajectory.initial_attitude.pitch_rad, 0.0, tol);
  assert_near(s.trajectory.initial_attitude.yaw_rad, 0.0, tol);
  const nav_traj_parametric *p = &s.trajectory.parametric;
  assert_vec3_near(p->r0_m, nav_vec3_make(0, 0, 0), tol);
  assert_vec3_near(p->v0_mps, nav_vec3_make(10, 0, 0), tol);
  assert_vec3_near(p->a_mps2, nav_vec3_make(0.1, 0.05, 0), tol);
  assert_vec3_near(p->b_m, nav_vec3_make(1, 1, 0.5), tol);
  assert_vec3_near(p->c_hz, nav_vec3_make(0.1, 0.2, 0.3), tol);
  assert_vec3_near(p->d_rad, nav_vec3_make(0, 0.5, 1), tol);
  assert_vec3_near(p->wa_rps, nav_vec3_make(0.01, 0.02, 0.05), tol);
  assert_vec3_near(p->wb_rps, nav_vec3_make(0.3, 0.2, 0.1), tol);
  assert_vec3_near(p->wc_hz, nav_vec3_make(0.5, 0.7, 0.3), tol);
  assert_vec3_near(p->wd_rad, nav_vec3_make(0, 1, 2), tol);
  assert_int_equal(p->attitude_mode, NAV_ATT_RATE_MAGNUS);
  assert_int_equal(p->magnus_substeps, 8);
  assert_near(s.imu.rate_hz, 100.0, tol);
  assert_int_equal(s.imu.quadrature_nodes, 6);
  assert_int_equal(s.navigation.algorithm, NAV_MECH_FIRST_ORDER);
  assert_near(s.output.rate_hz, 10.0, tol);
  assert_true(s.simulation.seed == 1u);
  assert_int_equal(s.simulation.runs, 1);
}

static void test_minimal_gives_defaults(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "valid-minimal.yaml", &s, &log), NAV_OK);
  const nav_scene def = nav_scene_default();
  assert_scene_same(&s, &def);
  /* Empty sections (every key commented out) are allowed and keep the defaults. */
  s = read_ok("format_version: 1\nimu:\noutput: {}\n");
  assert_scene_same(&s, &def);
}

static void test_variants_in_other_units(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  const nav_status st = read_path(SCENES_DIR "valid-variants.yaml", &s, &log);
  if (st != NAV_OK) print_log(&log);
  assert_int_equal(st, NAV_OK);
  const double d2r = NAV_PI / 180.0, tol = 1e-15;
  assert_string_equal(s.name, "variants: quoted");
  assert_near(s.earth.origin_lat_rad, 0.5, tol);
  assert_near(s.earth.origin_lon_rad, -120.5 * d2r, tol);
  assert_near(s.earth.origin_h_m, 1000.0, tol);
  assert_near(s.earth.flat_gravity_mps2, 9.81, tol);
  assert_near(s.trajectory.duration_s, 15.0, tol);
  assert_near(s.trajectory.initial_attitude.roll_rad, 0.1, tol);
  assert_near(s.trajectory.initial_attitude.pitch_rad, -10.0 * d2r, tol);
  assert_near(s.trajectory.initial_attitude.yaw_rad, -3.0, tol);
  const nav_traj_parametric *p = &s.trajectory.parametric;
  assert_vec3_near(p->r0_m, nav_vec3_make(1, 2, 3), tol);
  assert_vec3_near(p->v0_mps, nav_vec3_make(0.5, -0.5, 1), tol);
  assert_vec3_near(p->b_m, nav_vec3_make(0.5, 1, 2), tol);
  assert_vec3_near(p->c_hz, nav_vec3_make(1e-3, 2e-3, 0), tol);
  assert_vec3_near(p->d_rad, nav_vec3_make(NAV_PI / 2, NAV_PI, -NAV_PI / 4), tol);
  assert_vec3_near(p->wa_rps, nav_vec3_make(1 * d2r, 2 * d2r, 3 * d2r), tol);
  assert_vec3_near(p->wb_rps, nav_vec3_make(10 * d2r, 20 * d2r, 30 * d2r), tol);
  assert_vec3_near(p->wc_hz, nav_vec3_make(0.1, 0.2, 0.3), tol);
  assert_vec3_near(p->wd_rad, nav_vec3_make(0, NAV_PI / 2, NAV_PI), tol);
  assert_int_equal(p->magnus_substeps, 4);
  assert_near(s.imu.rate_hz, 200.0, tol);
  assert_int_equal(s.imu.quadrature_nodes, 3);
  assert_int_equal(s.navigation.algorithm, NAV_MECH_HIGH_ORDER);
  assert_near(s.output.rate_hz, 20.0, tol);
  assert_true(s.simulation.seed == UINT64_MAX);
  assert_int_equal(s.simulation.runs, 10);
}

static void test_read_string_numbers_and_styles(void **state) {
  (void)state;
  nav_scene s = read_ok("format_version: 1\nsimulation: {seed: 0x10, runs: +3}\n");
  assert_true(s.simulation.seed == 16u);
  assert_int_equal(s.simulation.runs, 3);
  s = read_ok("format_version: 1\nsimulation:\n  seed: 0o17\n");
  assert_true(s.simulation.seed == 15u);
  s = read_ok("\xEF\xBB\xBF# BOM, comments and a document marker\n---\nformat_version: 1 # one\n"
              "imu: {rate_hz: 1e3}\noutput: {rate_hz: 2.5E+1}\n...\n");
  assert_near(s.imu.rate_hz, 1000.0, 0.0);
  assert_near(s.output.rate_hz, 25.0, 0.0);
  s = read_ok("format_version: 1\n\"name\": 'single ''quoted'''\n");
  assert_string_equal(s.name, "single 'quoted'");
  s = read_ok("format_version: 1\nname: 123\n"); /* a plain scalar name is a string */
  assert_string_equal(s.name, "123");
  s = read_ok("format_version: 1\ntrajectory:\n  initial_attitude: {yaw_deg: -0.0}\n");
  assert_true(signbit(s.trajectory.initial_attitude.yaw_rad));
  s = read_ok("format_version: 1\nearth: {origin: {lat_deg: -90, lon_rad: 3.0}}\n");
  assert_near(s.earth.origin_lat_rad, -NAV_PI / 2, 1e-15);
  assert_near(s.earth.origin_lon_rad, 3.0, 0.0);
}

/* ---------------------------------------------------------------- one error each */

static void test_unknown_key_did_you_mean(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "invalid-unknown-key.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 3, 3, "imu.rat_hz", "unknown key \"rat_hz\"; did you mean \"rate_hz\"?");
  assert_string_equal(log.d[0].file, SCENES_DIR "invalid-unknown-key.yaml");

  expect_one("format_version: 1\nnavigaton:\n  algorithm: high_order\n", 2, 1, "navigaton",
             "did you mean \"navigation\"?");
  expect_one("format_version: 1\nimu:\n  Rate_HZ: 100\n", 3, 3, "imu.Rate_HZ", "did you mean \"rate_hz\"?");
  /* A missing unit suffix suggests the spellings with units. */
  expect_one("format_version: 1\nimu: {rate: 100}\n", 2, 7, "imu.rate", "did you mean \"rate_hz\"?");
  expect_one("format_version: 1\nearth:\n  origin: {lat: 45}\n", 3, 12, "earth.origin.lat",
             "did you mean \"lat_deg\" or \"lat_rad\"?");
  /* Nothing close: the valid keys of that level are listed. */
  expect_one(
      "format_version: 1\nsensors: {}\n", 2, 1, "sensors",
      "unknown key \"sensors\"; expected one of: format_version, name, earth, trajectory, imu, gnss, "
      "initial_errors, navigation, output, simulation");
}

static void test_wrong_types(void **state) {
  (void)state;
  expect_one("format_version: 1\nimu:\n  rate_hz: abc\n", 3, 12, "imu.rate_hz",
             "expected a number, got \"abc\"");
  expect_one("format_version: 1\nimu:\n  rate_hz: true\n", 3, 12, "imu.rate_hz",
             "expected a number, got the boolean \"true\"");
  expect_one("format_version: 1\nimu:\n  rate_hz: \"100\"\n", 3, 12, "imu.rate_hz",
             "expected a number, got the quoted string \"100\"");
  /* An empty value has no position of its own: the key is reported. */
  expect_one("format_version: 1\nimu:\n  rate_hz:\n", 3, 3, "imu.rate_hz", "expected a number, got null");
  expect_one("format_version: 1\nimu:\n  rate_hz: [1]\n", 3, 12, "imu.rate_hz",
             "expected a number, got a sequence");
  /* Mapping where a scalar is expected, and the other way round. */
  expect_one("format_version: 1\nnavigation:\n  algorithm: {a: 1}\n", 3, 14, "navigation.algorithm",
             "expected one of: first_order, high_order; got a mapping");
  expect_one("format_version: 1\nimu: 5\n", 2, 6, "imu",
             "expected a mapping with keys rate_hz, quadrature_nodes, bias_convention, catalog, gyro, accel, off; "
             "got \"5\"");
  expect_one("format_version: 1\nname: [a, b]\n", 2, 7, "name", "expected a string, got a sequence");
  expect_one("format_version: 1\nimu:\n  quadrature_nodes: 2.5\n", 3, 21, "imu.quadrature_nodes",
             "expected an integer, got \"2.5\"");
  expect_one("format_version: 1\n? [a, b]\n: 1\n", 2, 3, "", "expected a key name, got a sequence");
  expect_one("- 1\n- 2\n", 1, 1, "", "expected a mapping of scene keys");
}

static void test_vectors(void **state) {
  (void)state;
  expect_one("format_version: 1\ntrajectory:\n  parametric:\n    C_hz: [0.1, 0.2]\n", 4, 11,
             "trajectory.parametric.C_hz", "expected a sequence of 3 numbers, got 2");
  expect_one("format_version: 1\ntrajectory:\n  parametric:\n    C_hz: [1, 2, 3, 4]\n", 4, 11,
             "trajectory.parametric.C_hz", "expected a sequence of 3 numbers, got 4");
  expect_one("format_version: 1\ntrajectory:\n  parametric:\n    C_hz: [0.1, 0.2, abc]\n", 4, 22,
             "trajectory.parametric.C_hz[2]", "expected a number, got \"abc\"");
  expect_one("format_version: 1\ntrajectory:\n  parametric:\n    C_hz: 0.1\n", 4, 11,
             "trajectory.parametric.C_hz", "expected a sequence of 3 numbers, got \"0.1\"");
  expect_one(
      "format_version: 1\ntrajectory:\n  parametric:\n    rate:\n      b_dps:\n        - 1\n        - .nan\n"
      "        - 3\n",
      7, 11, "trajectory.parametric.rate.b_dps[1]", "must be finite (got .nan)");
}

static void test_bad_enum(void **state) {
  (void)state;
  expect_one("format_version: 1\nearth:\n  model: flot\n", 3, 10, "earth.model",
             "expected one of: flat, wgs84; got \"flot\"");
  expect_one("format_version: 1\ntrajectory: {type: spline}\n", 2, 20, "trajectory.type",
             "expected one of: parametric, waypoints, segments, test_motion, motion_def; got \"spline\"");
  expect_one("format_version: 1\ntrajectory:\n  parametric: {attitude: Magnus}\n", 3, 26,
             "trajectory.parametric.attitude", "expected one of: magnus; got \"Magnus\"");
}

static void test_out_of_range(void **state) {
  (void)state;
  expect_one("format_version: 1\nimu:\n  rate_hz: -5\n", 3, 12, "imu.rate_hz", "must be > 0 (got -5)");
  expect_one("format_version: 1\nimu:\n  rate_hz: 1e6\n", 3, 12, "imu.rate_hz",
             "must be <= 100000 (got 1e6)");
  expect_one("format_version: 1\ntrajectory:\n  duration_s: 0\n", 3, 15, "trajectory.duration_s",
             "must be > 0 (got 0)");
  expect_one("format_version: 1\ntrajectory:\n  duration_s: -.inf\n", 3, 15, "trajectory.duration_s",
             "must be finite (got -.inf)");
  expect_one("format_version: 1\nearth:\n  gravity_mps2: 1e999\n", 3, 17, "earth.gravity_mps2",
             "number is too large for a double (got \"1e999\")");
  expect_one("format_version: 1\nsimulation:\n  runs: 0\n", 3, 9, "simulation.runs", "must be >= 1 (got 0)");
  expect_one("format_version: 1\nsimulation:\n  runs: 1000001\n", 3, 9, "simulation.runs",
             "must be <= 1000000 (got 1000001)");
  expect_one("format_version: 1\nsimulation:\n  runs: 1.0\n", 3, 9, "simulation.runs",
             "expected an integer, got \"1.0\"");
  expect_one("format_version: 1\nimu:\n  quadrature_nodes: 99999999999\n", 3, 21, "imu.quadrature_nodes",
             "must be in [-2147483648, 2147483647] (got 99999999999)");
}

static void test_seed(void **state) {
  (void)state;
  expect_one("format_version: 1\nsimulation:\n  seed: -1\n", 3, 9, "simulation.seed",
             "must be >= 0 (got -1)");
  expect_one("format_version: 1\nsimulation:\n  seed: 1.5\n", 3, 9, "simulation.seed",
             "expected an integer, got \"1.5\"");
  expect_one("format_version: 1\nsimulation:\n  seed: 18446744073709551616\n", 3, 9, "simulation.seed",
             "must be <= 18446744073709551615 (got 18446744073709551616)");
  expect_one("format_version: 1\nsimulation:\n  seed: 1e3\n", 3, 9, "simulation.seed",
             "expected an integer, got \"1e3\"");
  const nav_scene s = read_ok("format_version: 1\nsimulation:\n  seed: 0\n");
  assert_true(s.simulation.seed == 0u);
}

static void test_deg_and_rad_both_given(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "invalid-deg-and-rad.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 5, 5, "trajectory.initial_attitude.roll_rad",
              "both \"roll_deg\" and \"roll_rad\" are given; give only one of them");
  expect_one(
      "format_version: 1\ntrajectory:\n  parametric:\n    rate: {d_deg: [0, 0, 0], d_rad: [0, 0, 0]}\n", 4,
      30, "trajectory.parametric.rate.d_rad", "both \"d_deg\" and \"d_rad\" are given");
}

static void test_duplicate_key(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "invalid-duplicate-key.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 4, 3, "output.rate_hz", "duplicate key \"rate_hz\" (first given at line 3, column 3)");
  expect_one("format_version: 1\nimu: {}\nimu: {}\n", 3, 1, "imu",
             "duplicate key \"imu\" (first given at line 2");
  expect_one("format_version: 1\nformat_version: 1\n", 2, 1, "format_version",
             "duplicate key \"format_version\"");
}

static void test_yaml_syntax_error(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "invalid-syntax.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 4, 26, "", "YAML syntax error: flow sequence with invalid extra closing bracket");
  /* libfyaml's own position: just after the opening quote. */
  expect_one("format_version: 1\nname: \"abc\n", 2, 8, "",
             "YAML syntax error: double-quoted scalar without closing quote");
  expect_one("format_version: 1\n  imu: 2\n", 1, 17, "", "YAML syntax error: ");
  /* Two documents in one file. */
  expect_one("format_version: 1\n---\nformat_version: 1\n", 2, 1, "", "a single YAML document");
}

static void test_format_version(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  /* A newer file: one message naming the supported versions, nothing about its unknown keys. */
  assert_int_equal(read_path(SCENES_DIR "invalid-format-version.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 2, 17, "format_version", "format_version 7 is newer than this program supports");
  expect_diag(&log, 0, 2, 17, "format_version", "supported versions: 1");
  expect_one("format_version: 0\n", 1, 17, "format_version", "must be >= 1 (got 0)");
  expect_one("format_version: one\n", 1, 17, "format_version", "expected an integer, got \"one\"");
  /* Required: a file without it is reported at the top-level mapping. */
  expect_one("imu:\n  rate_hz: 100\n", 1, 1, "format_version", "missing required key \"format_version\"");
}

static void test_empty_and_binary(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "invalid-empty.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 1, 1, "", "the file is empty");
  expect_one("# only a comment\n\n", 1, 1, "", "the file is empty");
  expect_one("---\n", 1, 1, "", "the file is empty");
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_scene_read_string(NULL, 0, NULL, &s, collect, &log), NAV_ERR_PARSE);
  expect_diag(&log, 0, 1, 1, "", "the file is empty");
  assert_string_equal(log.d[0].file, "<string>");

  assert_int_equal(read_path(SCENES_DIR "invalid-binary.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 1, 1, "", "not valid UTF-8 (byte 0x89)");
  expect_one("format_version: 1\nname: caf\xC3\x28\n", 2, 10, "", "not valid UTF-8 (byte 0xc3)");
  expect_one("format_version: 1\nname: \xED\xA0\x80\n", 2, 7, "",
             "not valid UTF-8 (byte 0xed)");                                      /* surrogate */
  expect_one("format_version: 1\nname: \xC0\xAF\n", 2, 7, "", "not valid UTF-8"); /* overlong '/' */
  expect_one("format_version: 1\nname: \"\xC3\xA9t\xC3\xA9\"\x01\n", 2, 12, "",
             "binary data (control byte 0x01)");
  /* A NUL byte inside the text. */
  static const char nul[] = "format_version: 1\0\n";
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_scene_read_string(nul, sizeof nul - 1, "nul.yaml", &s, collect, &log), NAV_ERR_PARSE);
  expect_diag(&log, 0, 1, 18, "", "binary data (control byte 0x00)");
  /* A NUL smuggled in through an escape is refused as a control character. */
  expect_one("format_version: 1\nname: \"a\\0b\"\n", 2, 7, "name", "must not contain control characters");
}

static void test_missing_file_is_io_error(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "does-not-exist.yaml", &s, &log), NAV_ERR_IO);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 0, 0, "", "cannot open the file: No such file or directory");
  assert_int_equal(read_path(SCENES_DIR, &s, &log), NAV_ERR_IO);
  expect_diag(&log, 0, 0, 0, "", "it is a directory");
  /* NULL arguments and no callback. */
  assert_int_equal(nav_scene_read_file(NULL, &s, NULL, NULL), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_scene_read_file(SCENES_DIR "valid-minimal.yaml", NULL, NULL, NULL),
                   NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_scene_read_string(NULL, 3, "x", &s, NULL, NULL), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_scene_read_file(SCENES_DIR "invalid-many.yaml", &s, NULL, NULL), NAV_ERR_PARSE);
}

static void test_outputs_untouched_on_error(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  memset(&s, 0x5A, sizeof s);
  assert_int_equal(read_text("format_version: 1\nimu: {rate_hz: -1}\n", &s, &log), NAV_ERR_PARSE);
  const unsigned char *b = (const unsigned char *)&s;
  for (size_t i = 0; i < sizeof s; ++i)
    assert_int_equal(b[i], 0x5A);
}

/* ---------------------------------------------------------------- several errors, validation */

static void test_many_errors_in_one_file(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  assert_int_equal(read_path(SCENES_DIR "invalid-many.yaml", &s, &log), NAV_ERR_PARSE);
  if (log.n != 12) print_log(&log);
  assert_int_equal(log.n, 12);
  expect_diag(&log, 0, 4, 10, "earth.model", "expected one of: flat, wgs84; got \"flot\"");
  expect_diag(&log, 1, 5, 25, "earth.origin.lat_rad", "both \"lat_deg\" and \"lat_rad\" are given");
  expect_diag(&log, 2, 6, 17, "earth.gravity_mps2", "expected a number, got \"abc\"");
  expect_diag(&log, 3, 8, 15, "trajectory.duration_s", "must be > 0 (got -5)");
  expect_diag(&log, 4, 10, 11, "trajectory.parametric.C_hz", "expected a sequence of 3 numbers, got 2");
  expect_diag(&log, 5, 11, 16, "trajectory.parametric.D_rad[1]", "expected a number, got \"x\"");
  expect_diag(&log, 6, 13, 14, "trajectory.parametric.rate.a_rps",
              "expected a sequence of 3 numbers, got a mapping");
  expect_diag(&log, 7, 15, 12, "imu.rate_hz", "must be finite (got .inf)");
  expect_diag(&log, 8, 16, 3, "imu.rat_hz", "did you mean \"rate_hz\"?");
  expect_diag(&log, 9, 17, 3, "imu.rate_hz", "duplicate key \"rate_hz\" (first given at line 15, column 3)");
  expect_diag(&log, 10, 19, 9, "simulation.seed", "must be >= 0 (got -1)");
  expect_diag(&log, 11, 20, 9, "simulation.runs", "must be >= 1 (got 0)");
}

static void test_validation_messages_are_placed(void **state) {
  (void)state;
  /* Cross-field check of nav_scene_validate, placed at the value of the path it names. */
  expect_one("format_version: 1\nimu:\n  rate_hz: 100\noutput:\n  rate_hz: 200\n", 5, 12, "output.rate_hz",
             "imu.rate_hz");
  /* A range only validation knows, on an integer field. */
  expect_one("format_version: 1\nimu:\n  quadrature_nodes: 0\n", 3, 21, "imu.quadrature_nodes", "must be");
  /* Validation names lat_deg; the file wrote lat_rad: the value is still found. */
  expect_one("format_version: 1\nearth:\n  origin: {lat_rad: 2.0}\n", 3, 21, "earth.origin.lat_deg", "90");
  /* The path is not in the file: its nearest parent is, else line 0. */
  expect_one("format_version: 1\nimu: {rate_hz: 5}\noutput:\n", 3, 1, "output.rate_hz", "imu.rate_hz");
  expect_one("format_version: 1\nimu: {rate_hz: 5}\n", 0, 0, "output.rate_hz", "imu.rate_hz");
}

static void test_diag_format(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  char line[2048];
  assert_int_equal(read_text("format_version: 1\nimu:\n  rat_hz: 100\n", &s, &log), NAV_ERR_PARSE);
  nav_diag_format(&log.d[0], line, sizeof line);
  assert_string_equal(line,
                      "test.yaml:3:3: error: imu.rat_hz: unknown key \"rat_hz\"; did you mean \"rate_hz\"?");
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "a.yaml");
  snprintf(d.message, sizeof d.message, "cannot open");
  nav_diag_format(&d, line, sizeof line);
  assert_string_equal(line, "a.yaml: error: cannot open");
  d.line = 2;
  d.col = 5;
  nav_diag_format(&d, line, sizeof line);
  assert_string_equal(line, "a.yaml:2:5: error: cannot open");
  char small[8];
  nav_diag_format(&d, small, sizeof small);
  assert_string_equal(small, "a.yaml:");
}

/* ---------------------------------------------------------------- hostile input */

static void test_aliases_tags_and_bombs(void **state) {
  (void)state;
  expect_one("format_version: 1\nimu: &a\n  rate_hz: 100\noutput: *a\n", 4, 9, "output",
             "aliases (*a) are not supported");
  expect_one("format_version: 1\nimu:\n  rate_hz: !!float 100\n", 3, 20, "imu.rate_hz", "YAML tags");
  /* Billion laughs: aliases are never expanded, so this costs nothing. */
  static const char bomb[] = "format_version: 1\n"
                             "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n"
                             "b: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\n"
                             "c: &c [*b, *b, *b, *b, *b, *b, *b, *b, *b]\n"
                             "d: &d [*c, *c, *c, *c, *c, *c, *c, *c, *c]\n"
                             "e: &e [*d, *d, *d, *d, *d, *d, *d, *d, *d]\n"
                             "f: &f [*e, *e, *e, *e, *e, *e, *e, *e, *e]\n"
                             "g: &g [*f, *f, *f, *f, *f, *f, *f, *f, *f]\n"
                             "h: &h [*g, *g, *g, *g, *g, *g, *g, *g, *g]\n"
                             "i: &i [*h, *h, *h, *h, *h, *h, *h, *h, *h]\n"
                             "imu: *i\n";
  diag_log log;
  nav_scene s;
  assert_int_equal(read_text(bomb, &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 10);
  expect_diag(&log, 9, 11, 6, "imu", "aliases (*i) are not supported");
}

static void test_deep_nesting_and_size_limits(void **state) {
  (void)state;
  const size_t depth = 100000;
  char *text = malloc(depth * 2 + 64);
  assert_non_null(text);
  size_t n = (size_t)snprintf(text, 64, "format_version: 1\nx: ");
  memset(text + n, '[', depth);
  memset(text + n + depth, ']', depth);
  text[n + 2 * depth] = '\0';
  /* The top-level mapping is level 1, so the 64th '[' (column 4 + 63) is one level too deep. */
  expect_one(text, 2, 67, "", "nesting is deeper than 64 levels");
  free(text);

  const size_t big = (size_t)16 * 1024 * 1024 + 1;
  char *huge = malloc(big);
  assert_non_null(huge);
  memset(huge, ' ', big);
  diag_log log;
  nav_scene s;
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_scene_read_string(huge, big, "huge.yaml", &s, collect, &log), NAV_ERR_PARSE);
  free(huge);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 0, 0, "", "limited to 16777216 bytes (16 MiB)");
  /* The same for a file, refused from its size before it is read. */
  char dir[64], path[128];
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/huge.yaml", dir);
  FILE *fp = fopen(path, "wb");
  assert_non_null(fp);
  assert_int_equal(ftruncate(fileno(fp), (off_t)big + 1000), 0);
  fclose(fp);
  assert_int_equal(read_path(path, &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 0, 0, "", "the file is too large (16778217 bytes)");
  rm_dir(dir);

  /* At most NAV_DIAG_MAX_PER_FILE diagnostics, the last saying that the list was cut. */
  char *many = malloc(200 * 16 + 32);
  assert_non_null(many);
  n = (size_t)sprintf(many, "format_version: 1\n");
  for (int i = 0; i < 200; ++i)
    n += (size_t)sprintf(many + n, "k%03d: 1\n", i);
  assert_int_equal(read_text(many, &s, &log), NAV_ERR_PARSE);
  free(many);
  assert_int_equal(log.n, NAV_DIAG_MAX_PER_FILE);
  expect_diag(&log, NAV_DIAG_MAX_PER_FILE - 2, 100, 1, "k098", "unknown key");
  expect_diag(&log, NAV_DIAG_MAX_PER_FILE - 1, 0, 0, "", "too many problems");
}

static void test_long_values_are_cut_in_messages(void **state) {
  (void)state;
  char text[512];
  char word[201];
  memset(word, 'x', 200);
  word[200] = '\0';
  snprintf(text, sizeof text, "format_version: 1\nimu: {rate_hz: %s}\n", word);
  expect_one(text, 2, 16, "imu.rate_hz",
             "expected a number, got \"xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...\"");
  char name[200];
  memset(name, 'n', 150);
  name[150] = '\0';
  snprintf(text, sizeof text, "format_version: 1\nname: %s\n", name);
  expect_one(text, 2, 7, "name", "is too long (150 bytes); at most 127 bytes are allowed");
}

/* ---------------------------------------------------------------- writing */

static void test_round_trip_canonical(void **state) {
  (void)state;
  char dir[64], path[128];
  diag_log log;
  nav_scene a, b, c;
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/out.yaml", dir);
  assert_int_equal(read_path(NAV_SOURCE_DIR "/scenes/paper-parametric.yaml", &a, &log), NAV_OK);
  assert_int_equal(nav_scene_write_file(path, &a), NAV_OK);
  assert_int_equal(count_entries(dir), 1); /* no temporary file left behind */
  const nav_status st = read_path(path, &b, &log);
  if (st != NAV_OK) print_log(&log);
  assert_int_equal(st, NAV_OK);
  assert_scene_same(&a, &b);
  /* The same schema and units as the example: degrees where it uses degrees. */
  const char *text = slurp(path);
  assert_non_null(strstr(text, "format_version: 1\n"));
  assert_non_null(strstr(text, "name: \"paper-parametric\"\n"));
  assert_non_null(strstr(text, "  origin: {lat_deg: 45, lon_deg: 0, h_m: 0}\n"));
  assert_non_null(strstr(text, "  initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 0}\n"));
  assert_non_null(strstr(text, "    C_hz: [0.1, 0.2, 0.3]\n"));
  assert_non_null(strstr(text, "      a_rps: [0.01, 0.02, 0.05]\n"));
  assert_non_null(strstr(text, "  algorithm: first_order  # first_order | high_order\n"));
  assert_non_null(strstr(text, "  seed: 1\n"));
  /* Writing again over the file replaces it and still reads back identically. */
  assert_int_equal(nav_scene_write_file(path, &b), NAV_OK);
  assert_int_equal(read_path(path, &c, &log), NAV_OK);
  assert_scene_same(&a, &c);
  assert_int_equal(count_entries(dir), 1);
  rm_dir(dir);
}

/* splitmix64 (Steele, Lea, Flood 2014): a self-contained stream for the property test. */
static uint64_t splitmix64(uint64_t *x) {
  uint64_t z = (*x += 0x9E3779B97F4A7C15u);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9u;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBu;
  return z ^ (z >> 31);
}
static double uniform(uint64_t *x) {
  return (double)(splitmix64(x) >> 11) * 0x1.0p-53;
}
/* A double of random sign, mantissa and decimal magnitude (1e-6 .. 1e6). */
static double any_double(uint64_t *x) {
  const double m = uniform(x) - 0.5;
  return m * pow(10.0, floor(uniform(x) * 13.0) - 6.0);
}
static nav_vec3 any_vec3(uint64_t *x) {
  const double a = any_double(x), b = any_double(x), c = any_double(x);
  return nav_vec3_make(a, b, c);
}

static void test_round_trip_random_bit_exact(void **state) {
  (void)state;
  char dir[64], path[128];
  diag_log log;
  const uint64_t seed = 0x5EED5CE4Eu;
  uint64_t x = seed;
  nav_test_print_seed("test_round_trip_random_bit_exact", seed);
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/rt.yaml", dir);
  for (int k = 0; k < 40; ++k) {
    nav_scene a = nav_scene_default(), b;
    /* Arbitrary radians: most have no exact decimal-degree spelling and fall back to _rad. */
    a.earth.origin_lat_rad = (uniform(&x) - 0.5) * 0.999 * NAV_PI;
    a.earth.origin_lon_rad = (uniform(&x) - 0.5) * 2.0 * NAV_PI;
    a.earth.origin_h_m = (uniform(&x) - 0.5) * 2.0e4;
    a.earth.flat_gravity_mps2 = 9.0 + uniform(&x);
    a.trajectory.duration_s = 1.0 + 100.0 * uniform(&x);
    a.trajectory.initial_attitude.roll_rad = any_double(&x);
    a.trajectory.initial_attitude.pitch_rad = k == 0 ? -0.0 : any_double(&x);
    a.trajectory.initial_attitude.yaw_rad = k == 1 ? 5e-324 : any_double(&x);
    nav_traj_parametric *p = &a.trajectory.parametric;
    p->r0_m = any_vec3(&x);
    p->v0_mps = any_vec3(&x);
    p->a_mps2 = any_vec3(&x);
    p->b_m = any_vec3(&x);
    p->c_hz = any_vec3(&x);
    p->d_rad = any_vec3(&x);
    p->wa_rps = any_vec3(&x);
    p->wb_rps = any_vec3(&x);
    p->wc_hz = any_vec3(&x);
    p->wd_rad = any_vec3(&x);
    p->magnus_substeps = 1 + (int)(splitmix64(&x) % 64);
    a.imu.rate_hz = 50.0 + 1000.0 * uniform(&x);
    a.imu.quadrature_nodes = 1 + (int)(splitmix64(&x) % 8);
    a.navigation.algorithm = (splitmix64(&x) & 1) ? NAV_MECH_HIGH_ORDER : NAV_MECH_FIRST_ORDER;
    a.output.rate_hz = 1.0 + 40.0 * uniform(&x);
    a.simulation.seed = splitmix64(&x);
    a.simulation.runs = 1 + (long)(splitmix64(&x) % 1000);
    snprintf(a.name, sizeof a.name, "run \"%d\" \\ %s", k, k % 2 ? "caf\xC3\xA9" : "colon: # hash");
    assert_int_equal(nav_scene_write_file(path, &a), NAV_OK);
    const nav_status st = read_path(path, &b, &log);
    if (st != NAV_OK) {
      print_log(&log);
      fail_msg("case %d: %s", k, slurp(path));
    }
    assert_scene_same(&a, &b);
  }
  assert_int_equal(count_entries(dir), 1);
  rm_dir(dir);
}

static void test_write_errors(void **state) {
  (void)state;
  const nav_scene s = nav_scene_default();
  nav_scene bad = s;
  char dir[64], path[128];
  assert_int_equal(nav_scene_write_file("/nonexistent-dir/x/scene.yaml", &s), NAV_ERR_IO);
  assert_int_equal(nav_scene_write_file(NULL, &s), NAV_ERR_INVALID_ARG);
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/s.yaml", dir);
  assert_int_equal(nav_scene_write_file(path, NULL), NAV_ERR_INVALID_ARG);
  /* An enum value without a name cannot be written; nothing is left behind. */
  bad.earth.model = (nav_earth_model)42;
  assert_int_equal(nav_scene_write_file(path, &bad), NAV_ERR_INVALID_ARG);
  assert_int_equal(count_entries(dir), 0);
  rm_dir(dir);
}

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
  const nav_scene s = read_ok("format_version: 1\nimu: {rate_hz: 123.5}\n");
  setlocale(LC_NUMERIC, "C");
  assert_near(s.imu.rate_hz, 123.5, 0.0);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_canonical_paper_parametric),
      cmocka_unit_test(test_minimal_gives_defaults),
      cmocka_unit_test(test_variants_in_other_units),
      cmocka_unit_test(test_read_string_numbers_and_styles),
      cmocka_unit_test(test_unknown_key_did_you_mean),
      cmocka_unit_test(test_wrong_types),
      cmocka_unit_test(test_vectors),
      cmocka_unit_test(test_bad_enum),
      cmocka_unit_test(test_out_of_range),
      cmocka_unit_test(test_seed),
      cmocka_unit_test(test_deg_and_rad_both_given),
      cmocka_unit_test(test_duplicate_key),
      cmocka_unit_test(test_yaml_syntax_error),
      cmocka_unit_test(test_format_version),
      cmocka_unit_test(test_empty_and_binary),
      cmocka_unit_test(test_missing_file_is_io_error),
      cmocka_unit_test(test_outputs_untouched_on_error),
      cmocka_unit_test(test_many_errors_in_one_file),
      cmocka_unit_test(test_validation_messages_are_placed),
      cmocka_unit_test(test_diag_format),
      cmocka_unit_test(test_aliases_tags_and_bombs),
      cmocka_unit_test(test_deep_nesting_and_size_limits),
      cmocka_unit_test(test_long_values_are_cut_in_messages),
      cmocka_unit_test(test_round_trip_canonical),
      cmocka_unit_test(test_round_trip_random_bit_exact),
      cmocka_unit_test(test_write_errors),
      cmocka_unit_test(test_numbers_ignore_process_locale),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
