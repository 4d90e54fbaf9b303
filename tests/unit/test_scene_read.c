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
#include "navcore/nav_array.h"
#include "navcore/nav_catalog.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_io.h"
#include "navcore/nav_motiondef.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_sensors.h"
#include "scene_bounds.h"

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

#define assert_same_mat3(a, b)                                                                               \
  do {                                                                                                       \
    for (int i_ = 0; i_ < 3; ++i_)                                                                           \
      for (int j_ = 0; j_ < 3; ++j_)                                                                         \
        assert_same_double((a).m[i_][j_], (b).m[i_][j_]);                                                    \
  } while (0)
#define assert_same_euler(a, b)                                                                              \
  do {                                                                                                       \
    assert_same_double((a).roll_rad, (b).roll_rad);                                                          \
    assert_same_double((a).pitch_rad, (b).pitch_rad);                                                        \
    assert_same_double((a).yaw_rad, (b).yaw_rad);                                                            \
  } while (0)

static void assert_limits_same(const nav_traj_limits *a, const nav_traj_limits *b) {
  assert_same_double(a->max_accel_mps2, b->max_accel_mps2);
  assert_same_double(a->max_jerk_mps3, b->max_jerk_mps3);
  assert_same_double(a->max_lateral_accel_mps2, b->max_lateral_accel_mps2);
  assert_same_double(a->max_rate_rps, b->max_rate_rps);
  assert_same_double(a->max_ang_accel_rps2, b->max_ang_accel_rps2);
  assert_same_double(a->max_ang_jerk_rps3, b->max_ang_jerk_rps3);
}

static void assert_gyro_same(const nav_gyro_error_config *a, const nav_gyro_error_config *b) {
  assert_int_equal(a->terms, b->terms);
  assert_same_vec3(a->bias_turn_on_fixed_rps, b->bias_turn_on_fixed_rps);
  assert_same_vec3(a->bias_turn_on_sd_rps, b->bias_turn_on_sd_rps);
  assert_same_vec3(a->bias_gm_sd_rps, b->bias_gm_sd_rps);
  assert_same_vec3(a->bias_gm_tau_s, b->bias_gm_tau_s);
  assert_same_vec3(a->bias_rw_rps_per_sqrt_s, b->bias_rw_rps_per_sqrt_s);
  assert_same_vec3(a->arw_rad_per_sqrt_s, b->arw_rad_per_sqrt_s);
  assert_same_vec3(a->scale_factor_fixed, b->scale_factor_fixed);
  assert_same_vec3(a->scale_factor_sd, b->scale_factor_sd);
  assert_same_mat3(a->misalignment_fixed_rad, b->misalignment_fixed_rad);
  assert_same_mat3(a->misalignment_sd_rad, b->misalignment_sd_rad);
  assert_same_mat3(a->g_sensitivity_fixed_rps_per_mps2, b->g_sensitivity_fixed_rps_per_mps2);
  assert_same_mat3(a->g_sensitivity_sd_rps_per_mps2, b->g_sensitivity_sd_rps_per_mps2);
  assert_same_vec3(a->quant_step_rad, b->quant_step_rad);
  assert_same_vec3(a->range_rps, b->range_rps);
}

static void assert_accel_same(const nav_accel_error_config *a, const nav_accel_error_config *b) {
  assert_int_equal(a->terms, b->terms);
  assert_same_vec3(a->bias_turn_on_fixed_mps2, b->bias_turn_on_fixed_mps2);
  assert_same_vec3(a->bias_turn_on_sd_mps2, b->bias_turn_on_sd_mps2);
  assert_same_vec3(a->bias_gm_sd_mps2, b->bias_gm_sd_mps2);
  assert_same_vec3(a->bias_gm_tau_s, b->bias_gm_tau_s);
  assert_same_vec3(a->bias_rw_mps2_per_sqrt_s, b->bias_rw_mps2_per_sqrt_s);
  assert_same_vec3(a->vrw_mps_per_sqrt_s, b->vrw_mps_per_sqrt_s);
  assert_same_vec3(a->scale_factor_fixed, b->scale_factor_fixed);
  assert_same_vec3(a->scale_factor_sd, b->scale_factor_sd);
  assert_same_mat3(a->misalignment_fixed_rad, b->misalignment_fixed_rad);
  assert_same_mat3(a->misalignment_sd_rad, b->misalignment_sd_rad);
  assert_same_vec3(a->quant_step_mps, b->quant_step_mps);
  assert_same_vec3(a->range_mps2, b->range_mps2);
}

static void assert_gnss_same(const nav_gnss_model_config *a, const nav_gnss_model_config *b) {
  assert_int_equal(a->terms, b->terms);
  assert_same_double(a->update_rate_hz, b->update_rate_hz);
  assert_same_double(a->latency_s, b->latency_s);
  assert_same_vec3(a->pos_gm_sd_m, b->pos_gm_sd_m);
  assert_same_vec3(a->pos_gm_tau_s, b->pos_gm_tau_s);
  assert_same_vec3(a->pos_white_sd_m, b->pos_white_sd_m);
  assert_same_vec3(a->vel_sd_mps, b->vel_sd_mps);
  assert_same_vec3(a->r_ba_b_m, b->r_ba_b_m);
  assert_int_equal(a->report_model_sigmas, b->report_model_sigmas);
  assert_same_vec3(a->reported_pos_sd_m, b->reported_pos_sd_m);
  assert_same_vec3(a->reported_vel_sd_mps, b->reported_vel_sd_mps);
  assert_int_equal(a->outage_count, b->outage_count);
  for (size_t i = 0; i < a->outage_count && i < NAV_GNSS_MAX_OUTAGES; ++i) {
    assert_same_double(a->outages[i].t0_s, b->outages[i].t0_s);
    assert_same_double(a->outages[i].t1_s, b->outages[i].t1_s);
  }
}

/* The accelerometer array of the gyro-free scheme, bit for bit. */
static void assert_array_same(const nav_scene_array *a, const nav_scene_array *b) {
  assert_int_equal(a->layout, b->layout);
  assert_string_equal(a->catalog, b->catalog);
  assert_same_double(a->radius_m, b->radius_m);
  assert_int_equal(a->custom_count, b->custom_count);
  for (int i = 0; i < a->custom_count && i < NAV_SCENE_ARRAY_MAX_SENSORS; ++i) {
    assert_same_vec3(a->custom[i].r_bs_b_m, b->custom[i].r_bs_b_m);
    assert_same_vec3(a->custom[i].n_s_b, b->custom[i].n_s_b);
  }
  assert_int_equal(a->accel.terms, b->accel.terms);
  assert_same_double(a->accel.bias_turn_on_sd_mps2, b->accel.bias_turn_on_sd_mps2);
  assert_same_double(a->accel.bias_gm_sd_mps2, b->accel.bias_gm_sd_mps2);
  assert_same_double(a->accel.bias_gm_tau_s, b->accel.bias_gm_tau_s);
  assert_same_double(a->accel.vrw_mps_per_sqrt_s, b->accel.vrw_mps_per_sqrt_s);
  assert_same_double(a->accel.scale_factor_sd, b->accel.scale_factor_sd);
  assert_same_vec3(a->initial_rate_sd_rps, b->initial_rate_sd_rps);
}

/* Every field of two scenes is identical, doubles bit for bit (list slots beyond the counts are
   unused and not compared). */
static void assert_scene_same(const nav_scene *a, const nav_scene *b) {
  assert_int_equal(a->format_version, b->format_version);
  assert_string_equal(a->name, b->name);
  assert_int_equal(a->earth.model, b->earth.model);
  assert_same_double(a->earth.origin_lat_rad, b->earth.origin_lat_rad);
  assert_same_double(a->earth.origin_lon_rad, b->earth.origin_lon_rad);
  assert_same_double(a->earth.origin_h_m, b->earth.origin_h_m);
  assert_same_double(a->earth.flat_gravity_mps2, b->earth.flat_gravity_mps2);
  assert_int_equal(a->earth.gravity_model, b->earth.gravity_model);

  const nav_scene_trajectory *ta = &a->trajectory, *tb = &b->trajectory;
  assert_int_equal(ta->type, tb->type);
  assert_same_double(ta->duration_s, tb->duration_s);
  assert_same_euler(ta->initial_attitude, tb->initial_attitude);
  const nav_traj_parametric *p = &ta->parametric, *q = &tb->parametric;
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

  const nav_traj_test_motion *ma = &ta->test_motion, *mb = &tb->test_motion;
  assert_int_equal(ma->kind, mb->kind);
  assert_same_double(ma->cone_half_angle_rad, mb->cone_half_angle_rad);
  assert_same_double(ma->cone_rate_rps, mb->cone_rate_rps);
  assert_same_double(ma->scull_angle_rad, mb->scull_angle_rad);
  assert_same_double(ma->scull_accel_mps2, mb->scull_accel_mps2);
  assert_same_double(ma->scull_rate_rps, mb->scull_rate_rps);
  assert_same_double(ma->spin_rate_rps, mb->spin_rate_rps);
  assert_same_vec3(ma->spin_axis_b, mb->spin_axis_b);
  assert_same_double(ma->gc_height_m, mb->gc_height_m);
  assert_same_double(ma->gc_speed_mps, mb->gc_speed_mps);
  assert_same_double(ma->gc_start_angle_rad, mb->gc_start_angle_rad);
  assert_same_double(ma->gc_lon_rad, mb->gc_lon_rad);
  assert_same_double(ma->loop_speed_mps, mb->loop_speed_mps);
  assert_same_double(ma->loop_pitch_rate_rps, mb->loop_pitch_rate_rps);

  const nav_traj_waypoints *wa = &ta->waypoints, *wb = &tb->waypoints;
  assert_int_equal(wa->count, wb->count);
  assert_int_equal(wa->timing, wb->timing);
  assert_int_equal(wa->attitude_mode, wb->attitude_mode);
  assert_same_double(wa->hold_start_s, wb->hold_start_s);
  assert_same_double(wa->hold_end_s, wb->hold_end_s);
  assert_same_double(wa->cruise_mps, wb->cruise_mps);
  assert_limits_same(&wa->limits, &wb->limits);
  for (int i = 0; i < wa->count && i < NAV_MAX_WAYPOINTS; ++i) {
    assert_same_vec3(wa->points[i].r_ned_m, wb->points[i].r_ned_m);
    assert_same_double(wa->points[i].speed_mps, wb->points[i].speed_mps);
    assert_same_double(wa->points[i].time_s, wb->points[i].time_s);
    assert_same_euler(wa->points[i].attitude, wb->points[i].attitude);
    assert_same_double(wa->points[i].hold_s, wb->points[i].hold_s);
  }

  const nav_traj_segments *sa = &ta->segments, *sb = &tb->segments;
  assert_int_equal(sa->count, sb->count);
  assert_int_equal(sa->allow_unconverged, sb->allow_unconverged);
  assert_int_equal(sa->fit_rate_ramps, sb->fit_rate_ramps);
  assert_same_vec3(sa->r0_ned_m, sb->r0_ned_m);
  assert_same_vec3(sa->v0_b_mps, sb->v0_b_mps);
  assert_limits_same(&sa->limits, &sb->limits);
  for (int i = 0; i < sa->count && i < NAV_MAX_SEGMENTS; ++i) {
    const nav_segment *g = &sa->items[i], *h = &sb->items[i];
    assert_int_equal(g->kind, h->kind);
    assert_int_equal(g->coordinated, h->coordinated);
    assert_int_equal(g->gnss_visible, h->gnss_visible);
    assert_int_equal(g->legs, h->legs);
    assert_same_double(g->duration_s, h->duration_s);
    assert_same_double(g->yaw_rad, h->yaw_rad);
    assert_same_double(g->pitch_rad, h->pitch_rad);
    assert_same_double(g->roll_rad, h->roll_rad);
    assert_same_double(g->yaw_rate_rps, h->yaw_rate_rps);
    assert_same_double(g->pitch_rate_rps, h->pitch_rate_rps);
    assert_same_double(g->roll_rate_rps, h->roll_rate_rps);
    assert_same_vec3(g->v_b_mps, h->v_b_mps);
    assert_same_vec3(g->accel_b_mps2, h->accel_b_mps2);
    assert_same_double(g->speed_mps, h->speed_mps);
    assert_same_double(g->height_m, h->height_m);
    assert_same_double(g->radius_m, h->radius_m);
    assert_same_double(g->turns, h->turns);
    assert_same_double(g->length_m, h->length_m);
    assert_same_double(g->spacing_m, h->spacing_m);
  }

  assert_same_double(a->imu.rate_hz, b->imu.rate_hz);
  assert_int_equal(a->imu.quadrature_nodes, b->imu.quadrature_nodes);
  assert_string_equal(a->imu.catalog, b->imu.catalog);
  assert_gyro_same(&a->imu.model.gyro, &b->imu.model.gyro);
  assert_accel_same(&a->imu.model.accel, &b->imu.model.accel);
  assert_int_equal(a->gnss.enabled, b->gnss.enabled);
  assert_string_equal(a->gnss.catalog, b->gnss.catalog);
  assert_gnss_same(&a->gnss.model, &b->gnss.model);
  assert_same_vec3(a->initial_errors.pos_sd_m, b->initial_errors.pos_sd_m);
  assert_same_vec3(a->initial_errors.vel_sd_mps, b->initial_errors.vel_sd_mps);
  assert_same_vec3(a->initial_errors.att_sd_rad, b->initial_errors.att_sd_rad);
  assert_int_equal(a->navigation.scheme, b->navigation.scheme);
  assert_int_equal(a->navigation.algorithm, b->navigation.algorithm);
  assert_int_equal(a->navigation.frame, b->navigation.frame);
  assert_int_equal(a->navigation.aid_vertical, b->navigation.aid_vertical);
  assert_int_equal(a->navigation.cov_decimation, b->navigation.cov_decimation);
  assert_int_equal(a->navigation.estimate_scale_factors, b->navigation.estimate_scale_factors);
  assert_int_equal(a->navigation.smoother, b->navigation.smoother);
  assert_int_equal(a->n_requirements, b->n_requirements);
  for (int i = 0; i < a->n_requirements && i < NAV_SCENE_MAX_REQUIREMENTS; ++i) {
    const nav_requirement *qa = &a->requirements[i], *qb = &b->requirements[i];
    assert_string_equal(qa->id, qb->id);
    assert_int_equal(qa->metric, qb->metric);
    assert_int_equal(qa->statistic, qb->statistic);
    assert_same_double(qa->limit, qb->limit);
    assert_int_equal(qa->unit, qb->unit);
    assert_same_double(qa->time_s, qb->time_s);
  }
  assert_array_same(&a->array, &b->array);
  assert_same_double(a->output.rate_hz, b->output.rate_hz);
  assert_true(a->simulation.seed == b->simulation.seed);
  assert_int_equal(a->simulation.runs, b->simulation.runs);
  assert_int_equal(a->simulation.threads, b->simulation.threads);
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
  /* Runs of escaped quotes (libfyaml 0.7.12 gets these wrong; the reader decodes them itself). */
  s = read_ok("format_version: 1\nname: 'ab''''cd'\n");
  assert_string_equal(s.name, "ab''cd");
  s = read_ok("format_version: 1\nname: ''''''''''''\n");
  assert_string_equal(s.name, "'''''");
  s = read_ok("format_version: 1\nname: ''\n");
  assert_string_equal(s.name, "");
  /* Line folding in a single-quoted scalar: one break is a space, two are a newline, white
     space around breaks goes, the first line's leading and the last line's trailing stay. */
  s = read_ok("format_version: 1\nname: ' a \t\n    b\r\n  c '\n");
  assert_string_equal(s.name, " a b c ");
  /* Two breaks (one of them a white-space line) fold to a newline, which a name refuses. */
  expect_one("format_version: 1\nname: ' a\n\n   \n  c'\n", 2, 7, "name", "control characters (byte 0x0a)");
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
  expect_one("format_version: 1\nsensors: {}\n", 2, 1, "sensors",
             "unknown key \"sensors\"; expected one of: format_version, name, earth, trajectory, imu, gnss, "
             "array, initial_errors, navigation, output, simulation");
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
  expect_one(
      "format_version: 1\nimu: 5\n", 2, 6, "imu",
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
             "expected one of: parametric, waypoints, segments, test_motion, motion_def, recorded; got \"spline\"");
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
  expect_one("format_version: 1\ntrajectory:\n  type: waypoints\n  waypoints:\n    cruise_mps: -1\n"
             "    points: [{ned_m: [0, 0, 0]}, {ned_m: [10, 0, 0]}]\n",
             5, 17,
             "trajectory.waypoints.cruise_mps", "must be >= 0 (got -1)");
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
  /* A directory is the user's mistake, not an I/O failure: refused as input (exit 2 in navsim). */
  assert_int_equal(read_path(SCENES_DIR, &s, &log), NAV_ERR_PARSE);
  expect_diag(&log, 0, 0, 0, "", "cannot read the file: it is a directory, not a regular file");
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
  /* The path is not in the file: its nearest parent is, else the other field the message names
     (imu.rate_hz, at 2:16), else format_version: every diagnostic has a place. */
  expect_one("format_version: 1\nimu: {rate_hz: 5}\noutput:\n", 3, 1, "output.rate_hz", "imu.rate_hz");
  expect_one("format_version: 1\nimu: {rate_hz: 5}\n", 2, 16, "output.rate_hz", "imu.rate_hz");
  expect_one("format_version: 1\nimu: {rate_hz: 0.01}\noutput: {rate_hz: 0.01}\n", 1, 17, "trajectory.duration_s", "shorter than one IMU interval");
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

/* ---------------------------------------------------------------- trajectories */

/* Tolerance for a datasheet-unit conversion against a hand value: one or two roundings. */
#define REL_CONV 4e-16

/* hold_s: a stop at an interior waypoint, read, counted in the planned duration, checked. */
static void test_waypoint_hold_s(void **state) {
  (void)state;
  static const char *const head = "format_version: 1\n"
                                  "trajectory:\n"
                                  "  type: waypoints\n"
                                  "  waypoints:\n"
                                  "    cruise_mps: 5\n"
                                  "    points:\n";
  char text[1024];
  snprintf(text, sizeof text,
           "%s"
           "      - {ned_m: [0, 0, 0], speed_mps: 0}\n"
           "      - {ned_m: [100, 0, 0], speed_mps: 0, hold_s: 12.5}\n"
           "      - {ned_m: [100, 100, 0], speed_mps: 0}\n",
           head);
  nav_scene s = read_ok(text);
  assert_near(s.trajectory.waypoints.points[1].hold_s, 12.5, 0.0);
  assert_near(s.trajectory.waypoints.points[0].hold_s, 0.0, 0.0);
  const double with_hold = s.trajectory.duration_s;
  snprintf(text, sizeof text,
           "%s"
           "      - {ned_m: [0, 0, 0], speed_mps: 0}\n"
           "      - {ned_m: [100, 0, 0], speed_mps: 0, hold_s: 20.5}\n"
           "      - {ned_m: [100, 100, 0], speed_mps: 0}\n",
           head);
  s = read_ok(text);
  assert_near(s.trajectory.duration_s - with_hold, 8.0, 1e-9);
  /* Bounds from the table, and the ends. */
  snprintf(text, sizeof text,
           "%s"
           "      - {ned_m: [0, 0, 0], speed_mps: 0}\n"
           "      - {ned_m: [100, 0, 0], speed_mps: 0, hold_s: -1}\n"
           "      - {ned_m: [100, 100, 0], speed_mps: 0}\n",
           head);
  expect_one(text, 8, 52, "trajectory.waypoints.points[1].hold_s", ">= 0"); /* at the value */
  snprintf(text, sizeof text,
           "%s"
           "      - {ned_m: [0, 0, 0], speed_mps: 0, hold_s: 3}\n"
           "      - {ned_m: [100, 0, 0], speed_mps: 0, hold_s: 2}\n"
           "      - {ned_m: [100, 100, 0], speed_mps: 0}\n",
           head);
  diag_log log;
  nav_scene bad;
  assert_int_equal(read_text(text, &bad, &log), NAV_ERR_PARSE);
  bool found = false;
  for (int i = 0; i < log.n; ++i)
    found = found || strstr(log.d[i].message, "hold_start_s") != NULL;
  if (!found) {
    print_log(&log);
    fail_msg("no diagnostic names hold_start_s");
  }
}

static void test_waypoints(void **state) {
  (void)state;
  const double d2r = NAV_PI / 180.0;
  nav_scene s =
      read_ok("format_version: 1\n"
              "trajectory:\n"
              "  type: waypoints\n"
              "  waypoints:\n"
              "    timing: speed\n"
              "    attitude_mode: euler\n"
              "    hold_start_s: 2\n"
              "    hold_end_s: 3\n"
              "    cruise_mps: 7.5\n"
              "    limits: {max_accel_mps2: 1.5, max_jerk_mps3: 2, max_lateral_accel_mps2: 2.5,\n"
              "             max_rate_dps: 20, max_ang_accel_dps2: 10, max_ang_jerk_rps3: 0.5}\n"
              "    points:\n"
              "      - {ned_m: [0, 0, 0], speed_mps: 0, attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 0}}\n"
              "      - {ned_m: [100, 0, -10], speed_mps: 5, attitude: {yaw_deg: 10}}\n"
              "      - {ned_m: [200, 50, -10], speed_mps: 0, attitude: {yaw_rad: 0.5}}\n");
  const nav_traj_waypoints *w = &s.trajectory.waypoints;
  assert_int_equal(s.trajectory.type, NAV_TRAJ_WAYPOINTS);
  assert_int_equal(w->count, 3);
  assert_int_equal(w->timing, NAV_WP_TIMING_SPEED);
  assert_int_equal(w->attitude_mode, NAV_WP_ATT_EULER);
  assert_near(w->hold_start_s, 2.0, 0.0);
  assert_near(w->hold_end_s, 3.0, 0.0);
  assert_near(w->cruise_mps, 7.5, 0.0);
  assert_near(w->limits.max_accel_mps2, 1.5, 0.0);
  assert_near(w->limits.max_jerk_mps3, 2.0, 0.0);
  assert_near(w->limits.max_lateral_accel_mps2, 2.5, 0.0);
  assert_rel_near(w->limits.max_rate_rps, 0.3490658503988659, REL_CONV); /* 20 deg/s */
  assert_rel_near(w->limits.max_ang_accel_rps2, 0.17453292519943295, REL_CONV);
  assert_near(w->limits.max_ang_jerk_rps3, 0.5, 0.0);
  assert_vec3_near(w->points[1].r_ned_m, nav_vec3_make(100, 0, -10), 0.0);
  assert_near(w->points[1].speed_mps, 5.0, 0.0);
  assert_rel_near(w->points[1].attitude.yaw_rad, 10 * d2r, REL_CONV);
  assert_near(w->points[2].attitude.yaw_rad, 0.5, 0.0);
  /* No duration_s: the length of the planned script. */
  nav_script_summary sum;
  assert_int_equal(nav_motiondef_script_summary(&s, &sum, NULL, 0), NAV_OK);
  assert_same_double(s.trajectory.duration_s, sum.duration_s);
  assert_true(s.trajectory.duration_s > 5.0);

  /* Timing by time: speed only at the ends; an explicit duration longer than the script. */
  s = read_ok("format_version: 1\n"
              "trajectory:\n"
              "  type: waypoints\n"
              "  duration_s: 100\n"
              "  waypoints:\n"
              "    timing: time\n"
              "    attitude_mode: aircraft\n"
              "    points:\n"
              "      - {ned_m: [0, 0, 0], speed_mps: 10, time_s: 0}\n"
              "      - {ned_m: [200, 0, 0], time_s: 20}\n"
              "      - {ned_m: [200, 200, 0], speed_mps: 10, time_s: 40}\n");
  assert_int_equal(s.trajectory.waypoints.timing, NAV_WP_TIMING_TIME);
  assert_int_equal(s.trajectory.waypoints.attitude_mode, NAV_WP_ATT_AIRCRAFT);
  assert_near(s.trajectory.waypoints.points[2].time_s, 40.0, 0.0);
  assert_near(s.trajectory.duration_s, 100.0, 0.0);
}

static void test_geodetic_waypoints_any_order(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  const nav_status st = read_path(SCENES_DIR "valid-trajectory-first.yaml", &s, &log);
  if (st != NAV_OK) print_log(&log);
  assert_int_equal(st, NAV_OK);
  /* Converted with the Earth section that follows the trajectory in the file. */
  const nav_frame fr = nav_frame_from_scene(&s);
  const nav_geodetic p1 = {45.001 * NAV_PI / 180.0, 0.0, 0.0};
  assert_same_vec3(s.trajectory.waypoints.points[1].r_ned_m, nav_frame_geodetic_to_local(&fr, p1));
  /* Hand value: 0.001 deg of latitude at 45 deg is R_M(45 deg) x 1.745e-5 = 6367381.8 m x
     1.7453293e-5 rad = 111.13 m north (the tangent plane differs by < 1 mm over 111 m). */
  assert_near(s.trajectory.waypoints.points[0].r_ned_m.x, 0.0, 1e-9);
  assert_near(s.trajectory.waypoints.points[1].r_ned_m.x, 111.13, 0.01);
  assert_near(s.trajectory.waypoints.points[1].r_ned_m.y, 0.0, 1e-9);
  /* lon_rad 2e-5 at 45 deg: (R_N + h) cos(lat) x 2e-5 = 6388838 x 0.7071 x 2e-5 = 90.35 m east;
     h_m -10: 10 m down. */
  assert_near(s.trajectory.waypoints.points[2].r_ned_m.y, 90.35, 0.02);
  assert_near(s.trajectory.waypoints.points[2].r_ned_m.z, 10.0, 0.01);
}

static void test_segment_kinds(void **state) {
  (void)state;
  const double d2r = NAV_PI / 180.0;
  const nav_scene s = read_ok(
      "format_version: 1\n"
      "earth: {model: wgs84}\n"
      "trajectory:\n"
      "  type: segments\n"
      "  segments:\n"
      "    r0_ned_m: [1, 2, -3]\n"
      "    v0_b_mps: [20, 0, 0]\n"
      "    allow_unconverged: true\n"
      "    fit_rate_ramps: false\n"
      "    limits: {max_accel_mps2: 2, max_jerk_mps3: 4, max_lateral_accel_mps2: 10, max_rate_dps: 30,\n"
      "             max_ang_accel_dps2: 20, max_ang_jerk_dps3: 60}\n"
      "    items:\n"
      "      - {kind: hold, duration_s: 5, gnss_visible: false}\n"
      "      - {kind: accelerate, speed_mps: 25}\n"
      "      - {kind: turn, yaw_deg: 90, yaw_rate_dps: 10}\n"
      "      - {kind: coordinated_turn, yaw_deg: -45, yaw_rate_rps: 0.1}\n"
      "      - {kind: climb, height_m: 100, pitch_deg: 5}\n"
      "      - {kind: circle, radius_m: 200, turns: 1, coordinated: true}\n"
      "      - {kind: figure_eight, radius_m: 150, turns: 1}\n"
      "      - {kind: helix, radius_m: 300, turns: 0.5, pitch_deg: -2}\n"
      "      - {kind: lawnmower, legs: 3, length_m: 100, spacing_m: -150}\n"
      "      - {kind: motion_rates, yaw_rate_dps: 1, pitch_rate_dps: 0, roll_rate_dps: 0,\n"
      "         accel_b_mps2: [0.1, 0, 0], duration_s: 4}\n"
      "      - {kind: motion_abs_abs, yaw_deg: 0, pitch_deg: 0, roll_deg: 0, v_b_mps: [20, 0, 0], "
      "duration_s: 60}\n"
      "      - {kind: motion_rel_rel, yaw_deg: 10, pitch_deg: 0, roll_deg: 0, v_b_mps: [1, 0, 0], "
      "duration_s: 30}\n"
      "      - {kind: motion_abs_rel, yaw_deg: 20, pitch_deg: 0, roll_deg: 0, v_b_mps: [-1, 0, 0], "
      "duration_s: 30}\n"
      "      - {kind: motion_rel_abs, yaw_rad: -0.1, pitch_deg: 0, roll_deg: 0, v_b_mps: [15, 0, 0],\n"
      "         duration_s: 30}\n");
  const nav_traj_segments *S = &s.trajectory.segments;
  const nav_segment *g = S->items;
  assert_int_equal(S->count, 14);
  assert_vec3_near(S->r0_ned_m, nav_vec3_make(1, 2, -3), 0.0);
  assert_vec3_near(S->v0_b_mps, nav_vec3_make(20, 0, 0), 0.0);
  assert_true(S->allow_unconverged);
  assert_false(S->fit_rate_ramps);
  assert_rel_near(S->limits.max_ang_jerk_rps3, 1.0471975511965976, REL_CONV); /* 60 deg/s^3 */
  static const nav_segment_kind kinds[14] = {
      NAV_SEG_HOLD,           NAV_SEG_ACCELERATE,    NAV_SEG_TURN,           NAV_SEG_COORD_TURN,
      NAV_SEG_CLIMB,          NAV_SEG_CIRCLE,        NAV_SEG_FIGURE_EIGHT,   NAV_SEG_HELIX,
      NAV_SEG_LAWNMOWER,      NAV_SEG_MOTION_RATES,  NAV_SEG_MOTION_ABS_ABS, NAV_SEG_MOTION_REL_REL,
      NAV_SEG_MOTION_ABS_REL, NAV_SEG_MOTION_REL_ABS};
  for (int i = 0; i < 14; ++i)
    assert_int_equal(g[i].kind, kinds[i]);
  assert_near(g[0].duration_s, 5.0, 0.0);
  assert_false(g[0].gnss_visible);
  assert_true(g[1].gnss_visible);
  assert_near(g[1].speed_mps, 25.0, 0.0);
  assert_rel_near(g[2].yaw_rad, NAV_PI / 2, REL_CONV);
  assert_rel_near(g[2].yaw_rate_rps, 10 * d2r, REL_CONV);
  assert_false(g[2].coordinated);
  assert_rel_near(g[3].yaw_rad, -NAV_PI / 4, REL_CONV);
  assert_near(g[3].yaw_rate_rps, 0.1, 0.0);
  assert_near(g[4].height_m, 100.0, 0.0);
  assert_rel_near(g[4].pitch_rad, 5 * d2r, REL_CONV);
  assert_near(g[5].radius_m, 200.0, 0.0);
  assert_near(g[5].turns, 1.0, 0.0);
  assert_true(g[5].coordinated);
  assert_near(g[7].turns, 0.5, 0.0);
  assert_rel_near(g[7].pitch_rad, -2 * d2r, REL_CONV);
  assert_int_equal(g[8].legs, 3);
  assert_near(g[8].length_m, 100.0, 0.0);
  assert_near(g[8].spacing_m, -150.0, 0.0);
  assert_rel_near(g[9].yaw_rate_rps, d2r, REL_CONV);
  assert_vec3_near(g[9].accel_b_mps2, nav_vec3_make(0.1, 0, 0), 0.0);
  assert_near(g[9].duration_s, 4.0, 0.0);
  assert_vec3_near(g[10].v_b_mps, nav_vec3_make(20, 0, 0), 0.0);
  assert_near(g[10].duration_s, 60.0, 0.0);
  assert_rel_near(g[12].yaw_rad, 20 * d2r, REL_CONV);
  assert_near(g[13].yaw_rad, -0.1, 0.0);
  nav_script_summary sum;
  assert_int_equal(nav_motiondef_script_summary(&s, &sum, NULL, 0), NAV_OK);
  assert_same_double(s.trajectory.duration_s, sum.duration_s);
}

static void test_test_motions(void **state) {
  (void)state;
  const double d2r = NAV_PI / 180.0;
  nav_scene s = read_ok("format_version: 1\ntrajectory:\n  type: test_motion\n  test_motion:\n"
                        "    kind: coning\n    cone_half_angle_deg: 2\n    cone_rate_hz: 10\n");
  assert_int_equal(s.trajectory.type, NAV_TRAJ_TEST_MOTION);
  assert_int_equal(s.trajectory.test_motion.kind, NAV_TEST_MOTION_CONING);
  assert_rel_near(s.trajectory.test_motion.cone_half_angle_rad, 2 * d2r, REL_CONV);
  assert_rel_near(s.trajectory.test_motion.cone_rate_rps, 62.83185307179586, REL_CONV); /* 10 Hz */
  assert_near(s.trajectory.duration_s, 20.0, 0.0); /* not a script: the default */
  s = read_ok("format_version: 1\ntrajectory:\n  type: test_motion\n  duration_s: 5\n"
              "  test_motion: {kind: spin, spin_rate_rpm: 1200, spin_axis_b: [0, 0, 1]}\n");
  assert_rel_near(s.trajectory.test_motion.spin_rate_rps, 125.66370614359172, REL_CONV); /* 1200 rpm */
  assert_vec3_near(s.trajectory.test_motion.spin_axis_b, nav_vec3_make(0, 0, 1), 0.0);
  s = read_ok(
      "format_version: 1\ntrajectory:\n  type: test_motion\n"
      "  test_motion: {kind: sculling, scull_angle_rad: 0.1, scull_accel_mps2: 3, scull_rate_dps: 720}\n");
  assert_near(s.trajectory.test_motion.scull_angle_rad, 0.1, 0.0);
  assert_near(s.trajectory.test_motion.scull_accel_mps2, 3.0, 0.0);
  assert_rel_near(s.trajectory.test_motion.scull_rate_rps, 4 * NAV_PI, REL_CONV);
  s = read_ok("format_version: 1\nearth: {model: wgs84}\ntrajectory:\n  type: test_motion\n"
              "  test_motion: {kind: polar_great_circle, gc_height_m: 9000, gc_speed_mps: 240,\n"
              "                gc_start_angle_deg: 85, gc_lon_deg: -30}\n");
  assert_near(s.trajectory.test_motion.gc_height_m, 9000.0, 0.0);
  assert_near(s.trajectory.test_motion.gc_speed_mps, 240.0, 0.0);
  assert_rel_near(s.trajectory.test_motion.gc_start_angle_rad, 85 * d2r, REL_CONV);
  assert_rel_near(s.trajectory.test_motion.gc_lon_rad, -30 * d2r, REL_CONV);
  s = read_ok("format_version: 1\ntrajectory:\n  type: test_motion\n"
              "  test_motion: {kind: vertical_loop, loop_speed_mps: 50, loop_pitch_rate_dps: -9}\n");
  assert_near(s.trajectory.test_motion.loop_speed_mps, 50.0, 0.0);
  assert_rel_near(s.trajectory.test_motion.loop_pitch_rate_rps, -9 * d2r, REL_CONV);
  s = read_ok("format_version: 1\ntrajectory: {type: test_motion, test_motion: {kind: stationary}}\n");
  assert_int_equal(s.trajectory.test_motion.kind, NAV_TEST_MOTION_STATIONARY);
}

static void test_motion_def_import(void **state) {
  (void)state;
  diag_log log;
  nav_scene s, direct = nav_scene_default();
  const nav_status st = read_path(SCENES_DIR "valid-motion-def.yaml", &s, &log);
  if (st != NAV_OK) print_log(&log);
  assert_int_equal(st, NAV_OK);
  /* The same as importing the file directly; only the explicit duration differs. */
  direct.earth.model = NAV_EARTH_WGS84;
  snprintf(direct.name, sizeof direct.name, "motion def");
  assert_int_equal(nav_motiondef_read_file(NAV_SOURCE_DIR "/resources/motion_defs/motion_def-90deg_turn.csv",
                                           &direct, NULL, NULL),
                   NAV_OK);
  assert_true(direct.trajectory.duration_s < 30.0);
  direct.trajectory.duration_s = 30.0;
  assert_int_equal(s.trajectory.type, NAV_TRAJ_SEGMENTS);
  assert_int_equal(s.trajectory.segments.count, 3);
  assert_scene_same(&s, &direct);
  assert_rel_near(s.earth.origin_lat_rad, 31.9965 * NAV_PI / 180.0, REL_CONV);
}

static void test_duration_auto(void **state) {
  (void)state;
  static const char *const base = "format_version: 1\n"
                                  "trajectory:\n"
                                  "  type: segments\n"
                                  "  %s\n"
                                  "  segments:\n"
                                  "    v0_b_mps: [10, 0, 0]\n"
                                  "    items: [{kind: hold, duration_s: 7}, {kind: turn, yaw_deg: 30}]\n";
  char text[512];
  snprintf(text, sizeof text, base, "duration_s: auto");
  const nav_scene a = read_ok(text);
  snprintf(text, sizeof text, base, "initial_attitude: {yaw_deg: 0}"); /* no duration_s */
  const nav_scene b = read_ok(text);
  snprintf(text, sizeof text, base, "duration_s: 3");
  const nav_scene c = read_ok(text);
  assert_same_double(a.trajectory.duration_s, b.trajectory.duration_s);
  assert_true(a.trajectory.duration_s > 7.0);
  assert_near(c.trajectory.duration_s, 3.0, 0.0); /* shorter than the script: the run ends early */
}

/* ---------------------------------------------------------------- sensors, initial errors */

static void test_sensor_units(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  const nav_status st = read_path(SCENES_DIR "valid-sensors.yaml", &s, &log);
  if (st != NAV_OK) print_log(&log);
  assert_int_equal(st, NAV_OK);
  const nav_gyro_error_config *g = &s.imu.model.gyro;
  const nav_accel_error_config *a = &s.imu.model.accel;
  /* Hand values: deg/sqrt(h) x (pi/180)/60, deg/h x (pi/180)/3600, ... (nav_sensors.h). */
  assert_int_equal(g->terms, NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM |
                                 NAV_IMU_TERM_BIAS_RW | NAV_IMU_TERM_SCALE_FACTOR |
                                 NAV_IMU_TERM_MISALIGNMENT | NAV_IMU_TERM_G_SENSITIVITY |
                                 NAV_IMU_TERM_SATURATION);
  assert_rel_near(g->arw_rad_per_sqrt_s.y, 4.3633231299858234e-05, REL_CONV); /* 0.15 deg/sqrt(h) */
  assert_rel_near(g->bias_turn_on_sd_rps.x, 4.84813681109536e-05, REL_CONV);  /* 10 deg/h */
  assert_rel_near(g->bias_turn_on_sd_rps.y, 9.69627362219072e-05, REL_CONV);
  assert_rel_near(g->bias_turn_on_sd_rps.z, 1.454441043328608e-04, REL_CONV);
  assert_rel_near(g->bias_turn_on_fixed_rps.z, 0.008726646259971648, REL_CONV); /* 0.5 deg/s */
  /* sigma_equals_b: sigma = B = 2 deg/h; T = 300 s / 1.892617797645221. */
  assert_rel_near(g->bias_gm_sd_rps.x, 9.69627362219072e-06, REL_CONV);
  assert_rel_near(g->bias_gm_tau_s.z, 158.51060915376442, REL_CONV);
  assert_rel_near(g->bias_rw_rps_per_sqrt_s.x, 4.040114009246133e-08, REL_CONV); /* 0.5 deg/h/sqrt(h) */
  assert_vec3_near(g->scale_factor_sd, nav_vec3_make(5e-4, 5e-4, 5e-4), 1e-19);
  assert_vec3_near(g->scale_factor_fixed, nav_vec3_make(1e-4, -2e-4, 3e-4), 1e-19);
  const nav_mat3 mis = {{{0, 5e-4, 5e-4}, {5e-4, 0, 5e-4}, {5e-4, 5e-4, 0}}};
  assert_mat3_near(g->misalignment_sd_rad, mis, 1e-19);
  const nav_mat3 gs = {
      {{4.94372370900905e-06, 0, 0}, {0, 9.8874474180181e-06, 0}, {0, 0, 1.483117112702715e-05}}};
  assert_mat3_near(g->g_sensitivity_sd_rps_per_mps2, gs, 1e-20);             /* deg/h/g x (pi/180)/3600/g0 */
  assert_vec3_near(g->quant_step_rad, nav_vec3_make(1e-7, 1e-7, 1e-7), 0.0); /* kept while off */
  assert_rel_near(g->range_rps.x, 7.853981633974483, REL_CONV);              /* 450 deg/s */
  assert_int_equal(a->terms, NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM |
                                 NAV_IMU_TERM_BIAS_RW | NAV_IMU_TERM_MISALIGNMENT |
                                 NAV_IMU_TERM_QUANTISATION | NAV_IMU_TERM_SATURATION);
  assert_rel_near(a->vrw_mps_per_sqrt_s.x, 9.80665e-4, REL_CONV);  /* 100 ug/sqrt(Hz) */
  assert_rel_near(a->bias_turn_on_sd_mps2.x, 0.0196133, REL_CONV); /* 2 mg */
  assert_rel_near(a->bias_gm_sd_mps2.y, 4.903325e-4, REL_CONV);    /* 50 ug */
  assert_near(a->bias_gm_tau_s.y, 600.0, 0.0);
  assert_rel_near(a->bias_rw_mps2_per_sqrt_s.z, 1.6666666666666667e-05, REL_CONV); /* 0.001 m/s^2/sqrt(h) */
  const nav_mat3 mf = {{{0, 1e-3, 2e-3}, {3e-3, 0, 4e-3}, {5e-3, 6e-3, 0}}};
  assert_mat3_near(a->misalignment_fixed_rad, mf, 1e-18);
  assert_near(a->quant_step_mps.x, 1e-5, 0.0);
  assert_rel_near(a->range_mps2.y, 156.9064, REL_CONV); /* 16 g */

  const nav_gnss_model_config *n = &s.gnss.model;
  assert_true(s.gnss.enabled);
  assert_int_equal(n->terms, NAV_GNSS_TERM_POS_GM | NAV_GNSS_TERM_POS_WHITE | NAV_GNSS_TERM_VEL_WHITE);
  assert_near(n->update_rate_hz, 5.0, 0.0);
  assert_near(n->latency_s, 0.1, 0.0);
  assert_vec3_near(n->pos_gm_sd_m, nav_vec3_make(1.5, 1.5, 3), 0.0);
  assert_vec3_near(n->pos_gm_tau_s, nav_vec3_make(100, 100, 100), 0.0);
  assert_vec3_near(n->pos_white_sd_m, nav_vec3_make(0.5, 0.5, 0.5), 0.0);
  assert_vec3_near(n->vel_sd_mps, nav_vec3_make(0.05, 0.05, 0.05), 0.0);
  assert_vec3_near(n->r_ba_b_m, nav_vec3_make(0.1, 0.2, -0.3), 0.0);
  assert_int_equal(n->outage_count, 2);
  assert_near(n->outages[1].t0_s, 300.5, 0.0);
  assert_near(n->outages[1].t1_s, 360.0, 0.0);
  assert_false(n->report_model_sigmas);
  assert_vec3_near(n->reported_pos_sd_m, nav_vec3_make(2, 2, 4), 0.0);
  assert_vec3_near(n->reported_vel_sd_mps, nav_vec3_make(0.1, 0.1, 0.1), 0.0);

  assert_vec3_near(s.initial_errors.pos_sd_m, nav_vec3_make(1, 2, 3), 0.0);
  assert_vec3_near(s.initial_errors.vel_sd_mps, nav_vec3_make(0.05, 0.05, 0.05), 0.0);
  assert_rel_near(s.initial_errors.att_sd_rad.z, NAV_PI / 180.0, REL_CONV);
  assert_int_equal(s.navigation.scheme, NAV_SCHEME_INS_GNSS);
  assert_int_equal(s.navigation.frame, NAV_MECH_ECEF);
  assert_false(s.navigation.aid_vertical);
  assert_int_equal(s.simulation.threads, 4);

  /* Defaults: a perfect IMU, no receiver, no initial errors. */
  s = read_ok("format_version: 1\n");
  assert_int_equal(s.imu.model.gyro.terms, 0);
  assert_int_equal(s.imu.model.accel.terms, 0);
  assert_false(s.gnss.enabled);
  assert_true(s.gnss.model.report_model_sigmas);
  assert_int_equal(s.navigation.scheme, NAV_SCHEME_FREE_INS);
}

static void test_bias_instability_conventions(void **state) {
  (void)state;
  /* Default allan_peak: sigma = B / 0.6173642831444413 (numerics.md 2.3). */
  nav_scene s =
      read_ok("format_version: 1\nimu:\n  accel: {bias_instability_ug: 50, bias_instability_tau_min_s: "
              "[300, 600, 900]}\n");
  assert_rel_near(s.imu.model.accel.bias_gm_sd_mps2.x, 0.0007942352892567314, 1e-15);
  assert_rel_near(s.imu.model.accel.bias_gm_tau_s.y, 600.0 / 1.892617797645221, 1e-15);
  assert_true(s.imu.model.accel.terms & NAV_IMU_TERM_BIAS_GM);
  /* Per-axis instability with the rad/s spelling, sigma_equals_b, keys in any order. */
  s = read_ok(
      "format_version: 1\nimu:\n  gyro: {bias_instability_tau_min_s: 100, bias_instability_rps: [1e-6, 2e-6, "
      "3e-6]}\n  bias_convention: sigma_equals_b\n");
  assert_vec3_near(s.imu.model.gyro.bias_gm_sd_rps, nav_vec3_make(1e-6, 2e-6, 3e-6), 0.0);
  /* A scalar applies to all three axes; "off" clears the terms of both triads. */
  s = read_ok("format_version: 1\nimu:\n  off: [noise]\n  gyro: {arw_rad_per_sqrt_s: 1e-4}\n"
              "  accel: {vrw_m_per_s_per_sqrt_h: 0.06}\n");
  assert_vec3_near(s.imu.model.gyro.arw_rad_per_sqrt_s, nav_vec3_make(1e-4, 1e-4, 1e-4), 0.0);
  assert_rel_near(s.imu.model.accel.vrw_mps_per_sqrt_s.z, 0.001, 1e-15);
  assert_int_equal(s.imu.model.gyro.terms, 0);
  assert_int_equal(s.imu.model.accel.terms, 0);
}

/* The IMU catalog row as nav_catalog_load converts it. */
static nav_imu_model_config catalog_imu(const char *name, nav_bi_convention conv) {
  nav_catalog *cat = NULL;
  nav_catalog_options opt = nav_catalog_options_default();
  opt.convention = conv;
  assert_int_equal(nav_catalog_load(NAV_SOURCE_DIR "/resources/imu_catalog.csv", &opt, &cat, NULL, NULL),
                   NAV_OK);
  const nav_catalog_imu_entry *e = nav_catalog_find_imu(cat, name);
  assert_non_null(e);
  const nav_imu_model_config cfg = e->config;
  nav_catalog_destroy(cat);
  return cfg;
}

static void test_imu_catalog(void **state) {
  (void)state;
  nav_scene s = read_ok("format_version: 1\nimu: {catalog: adis16465-1}\n");
  assert_string_equal(s.imu.catalog, "ADIS16465-1");
  nav_imu_model_config cfg = catalog_imu("ADIS16465-1", NAV_BI_ALLAN_PEAK);
  assert_gyro_same(&s.imu.model.gyro, &cfg.gyro);
  assert_accel_same(&s.imu.model.accel, &cfg.accel);
  /* The catalog is the base whatever its place among the keys; the other keys override it. */
  s = read_ok("format_version: 1\nimu:\n  gyro: {arw_deg_per_sqrt_h: 0.2}\n  off: [accel.bias_gm]\n"
              "  bias_convention: sigma_equals_b\n  catalog: \"Xsens MTi-300\"\n");
  cfg = catalog_imu("Xsens MTi-300", NAV_BI_SIGMA_EQUALS_B);
  assert_rel_near(s.imu.model.gyro.arw_rad_per_sqrt_s.x, 0.2 * NAV_PI / 180.0 / 60.0, REL_CONV);
  assert_same_vec3(s.imu.model.gyro.bias_gm_sd_rps, cfg.gyro.bias_gm_sd_rps);
  assert_int_equal(s.imu.model.gyro.terms, cfg.gyro.terms);
  assert_int_equal(s.imu.model.accel.terms, cfg.accel.terms & ~(unsigned)NAV_IMU_TERM_BIAS_GM);
  assert_same_vec3(s.imu.model.accel.bias_gm_sd_mps2, cfg.accel.bias_gm_sd_mps2); /* kept, but off */
  assert_same_vec3(s.imu.model.accel.vrw_mps_per_sqrt_s, cfg.accel.vrw_mps_per_sqrt_s);
}

/* Issue 21 item 3: array.catalog fills the array's per-sensor terms with the part's datasheet
 * figures in SI, whatever its place among the keys; the accel keys override it, "off" removes a
 * term; an unknown part is an error at its FILE:LINE:COL. */
static void test_array_catalog(void **state) {
  (void)state;
  nav_catalog *cat = NULL;
  assert_int_equal(nav_catalog_load(NAV_SOURCE_DIR "/resources/accel_catalog.csv", NULL, &cat, NULL, NULL),
                   NAV_OK);
  const nav_catalog_accel_entry *e = nav_catalog_find_accel(cat, "Safran Colibrys MS1010");
  assert_non_null(e);
  nav_scene s =
      read_ok("format_version: 1\narray: {layout: cube6, radius_m: 0.3, catalog: safran colibrys ms1010}\n");
  assert_string_equal(s.array.catalog, "Safran Colibrys MS1010");
  assert_int_equal(s.array.accel.terms, e->config.terms);
  assert_same_double(s.array.accel.vrw_mps_per_sqrt_s, e->config.vrw_mps_per_sqrt_s);
  assert_rel_near(s.array.accel.vrw_mps_per_sqrt_s, 34e-6 * 9.80665, 1e-12); /* MS1010: 34 ug/rtHz */
  assert_same_double(s.array.accel.bias_gm_sd_mps2, e->config.bias_gm_sd_mps2);
  assert_same_double(s.array.accel.bias_gm_tau_s, e->config.bias_gm_tau_s);
  assert_rel_near(s.array.accel.bias_turn_on_sd_mps2, 1.2e-3 * 9.80665, 1e-12); /* 1.2 mg */
  assert_rel_near(s.array.accel.scale_factor_sd, 120e-6, 1e-12);                /* 120 ppm */
  /* Typed values override the part; the part is read first even when written last. */
  s = read_ok("format_version: 1\narray:\n  accel: {noise_density_ug_per_sqrt_hz: 20, off: [scale_factor]}\n"
              "  catalog: Safran Colibrys MS1010\n");
  assert_rel_near(s.array.accel.vrw_mps_per_sqrt_s, 20e-6 * 9.80665, 1e-15);
  assert_int_equal(s.array.accel.terms, e->config.terms & ~(unsigned)NAV_IMU_TERM_SCALE_FACTOR);
  assert_same_double(s.array.accel.bias_turn_on_sd_mps2, e->config.bias_turn_on_sd_mps2);
  /* Written and read back: the part's name and the overrides survive. */
  char *text = NULL;
  size_t len = 0;
  assert_int_equal(nav_scene_write_string(&s, &text, &len), NAV_OK);
  assert_non_null(strstr(text, "catalog: \"Safran Colibrys MS1010\""));
  nav_scene back = read_ok(text);
  free(text);
  assert_string_equal(back.array.catalog, s.array.catalog);
  assert_int_equal(back.array.accel.terms, s.array.accel.terms);
  assert_same_double(back.array.accel.vrw_mps_per_sqrt_s, s.array.accel.vrw_mps_per_sqrt_s);
  nav_catalog_destroy(cat);
  expect_one("format_version: 1\narray:\n  catalog: MS1011\n", 3, 12, "array.catalog",
             "unknown accelerometer part \"MS1011\"");
  expect_one("format_version: 1\narray:\n  catalog: [1]\n", 3, 12, "array.catalog",
             "an accelerometer part from resources/accel_catalog.csv");
}

static void test_gnss_catalog(void **state) {
  (void)state;
  nav_scene s =
      read_ok("format_version: 1\ngnss:\n  enabled: true\n  catalog: rtk fixed\n  update_rate_hz: 5\n"
              "  off: [velocity]\n");
  nav_catalog *cat = NULL;
  assert_int_equal(nav_catalog_load(NAV_SOURCE_DIR "/resources/gnss_receivers.csv", NULL, &cat, NULL, NULL),
                   NAV_OK);
  const nav_catalog_gnss_entry *e = nav_catalog_find_gnss(cat, "RTK fixed");
  assert_non_null(e);
  assert_string_equal(s.gnss.catalog, "RTK fixed");
  assert_same_vec3(s.gnss.model.pos_gm_sd_m, e->config.pos_gm_sd_m);
  assert_same_vec3(s.gnss.model.pos_gm_tau_s, e->config.pos_gm_tau_s);
  assert_int_equal(s.gnss.model.terms, e->config.terms & ~(unsigned)NAV_GNSS_TERM_VEL_WHITE);
  assert_near(s.gnss.model.update_rate_hz, 5.0, 0.0);
  nav_catalog_destroy(cat);
}

/* ---------------------------------------------------------------- plausibility bounds (scene_bounds.h) */

/* Each bounded quantity: its value at the bound is accepted in the primary unit, just above is
   refused with the bound in the message, at FILE:LINE:COL of the value; the other spellings carry
   the same bound converted; signed (fixed) values are bounded in magnitude. */
static void test_sensor_bounds(void **state) {
  (void)state;
  static const struct {
    const char *section, *key; /* imu.gyro / imu.accel / gnss / array.accel */
    double bound;
    const char *shown; /* the bound as the message prints it */
    const char *tail;  /* keys the value needs, after it */
  } k[] = {
      {"imu:\n  gyro:\n", "arw_deg_per_sqrt_h", NAV_SCENE_MAX_GYRO_ARW_DEG_PER_SQRT_H, "100", NULL},
      {"imu:\n  gyro:\n", "bias_turn_on_deg_per_h", NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H, "360000", NULL},
      {"imu:\n  gyro:\n", "bias_gm_sigma_deg_per_h", NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H, "360000",
       "    bias_gm_tau_s: 100\n"},
      {"imu:\n  gyro:\n", "rrw_deg_per_h_per_sqrt_h", NAV_SCENE_MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H, "360000",
       NULL},
      {"imu:\n  gyro:\n", "scale_factor_ppm", NAV_SCENE_MAX_SCALE_FACTOR_PPM, "1000000", NULL},
      {"imu:\n  gyro:\n", "misalignment_mrad", NAV_SCENE_MAX_MISALIGNMENT_MRAD, "100", NULL},
      {"imu:\n  gyro:\n", "g_sensitivity_deg_per_h_per_g", NAV_SCENE_MAX_G_SENSITIVITY_DEG_PER_H_PER_G,
       "36000", NULL},
      {"imu:\n  accel:\n", "vrw_m_per_s_per_sqrt_h", NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H, "10", NULL},
      {"imu:\n  accel:\n", "bias_turn_on_mg", NAV_SCENE_MAX_ACCEL_BIAS_MG, "1000", NULL},
      {"imu:\n  accel:\n", "bias_rw_m_per_s2_per_sqrt_h", NAV_SCENE_MAX_ACCEL_BIAS_RW_M_PER_S2_PER_SQRT_H,
       "10", NULL},
      {"imu:\n  accel:\n", "scale_factor_ppm", NAV_SCENE_MAX_SCALE_FACTOR_PPM, "1000000", NULL},
      {"imu:\n  accel:\n", "misalignment_mrad", NAV_SCENE_MAX_MISALIGNMENT_MRAD, "100", NULL},
      {"gnss:\n  enabled: true\n", "position_sigma_m", NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, "1000", NULL},
      {"gnss:\n  enabled: true\n", "position_white_sigma_m", NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, "1000",
       NULL},
      {"gnss:\n  enabled: true\n", "velocity_sigma_mps", NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS, "100", NULL},
      {"gnss:\n  enabled: true\n", "latency_s", NAV_SCENE_MAX_GNSS_LATENCY_S, "10", NULL},
      {"array:\n  accel:\n", "vrw_m_per_s_per_sqrt_h", NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H, "10",
       NULL},
      {"array:\n  accel:\n", "bias_turn_on_mg", NAV_SCENE_MAX_ACCEL_BIAS_MG, "1000", NULL},
  };
  for (size_t i = 0; i < sizeof k / sizeof k[0]; ++i) {
    const bool gnss = k[i].section[0] == 'g';
    const char *indent = gnss ? "  " : "    ";
    char text[512], path[128], got[96];
    const char *where = gnss                     ? "gnss"
                        : k[i].section[0] == 'a' ? "array.accel"
                        : k[i].section[7] == 'g' ? "imu.gyro"
                                                 : "imu.accel";
    snprintf(path, sizeof path, "%s.%s", where, k[i].key);
    const char *tail = k[i].tail ? k[i].tail : "";
    snprintf(text, sizeof text, "format_version: 1\n%s%s%s: %.17g\n%s", k[i].section, indent, k[i].key,
             k[i].bound, tail);
    (void)read_ok(text);
    const double above = k[i].bound * (1.0 + 1e-9);
    snprintf(text, sizeof text, "format_version: 1\n%s%s%s: %.17g\n%s", k[i].section, indent, k[i].key, above,
             tail);
    snprintf(got, sizeof got, "must be <= %s (got %.17g)", k[i].shown, above);
    expect_one(text, 4, (int)(strlen(indent) + strlen(k[i].key) + 3), path, got); /* after "KEY: " */
  }
  /* The other spellings: the same bound, converted to their unit. */
  const double arw_max_rps = nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(NAV_SCENE_MAX_GYRO_ARW_DEG_PER_SQRT_H);
  char text[256];
  snprintf(text, sizeof text, "format_version: 1\nimu:\n  gyro:\n    arw_rad_per_sqrt_s: %.17g\n",
           arw_max_rps);
  nav_scene s = read_ok(text);
  assert_rel_near(s.imu.model.gyro.arw_rad_per_sqrt_s.x, arw_max_rps, 1e-15);
  snprintf(text, sizeof text, "format_version: 1\nimu:\n  gyro:\n    arw_rad_per_sqrt_s: %.17g\n",
           arw_max_rps * 1.000001);
  expect_one(text, 4, 25, "imu.gyro.arw_rad_per_sqrt_s", "must be <= 0.0290888208665721");
  (void)read_ok(
      "format_version: 1\nimu:\n  gyro:\n    bias_turn_on_dps: 100\n    noise_density_deg_per_s_per_sqrt_hz: "
      "1.6\n  accel:\n    noise_density_ug_per_sqrt_hz: 16995\n    bias_turn_on_mps2: 9.8\n");
  expect_one("format_version: 1\nimu:\n  gyro:\n    bias_turn_on_dps: 100.001\n", 4, 23,
             "imu.gyro.bias_turn_on_dps", "must be <= 100");
  expect_one("format_version: 1\nimu:\n  accel:\n    noise_density_ug_per_sqrt_hz: 17000\n", 4, 35,
             "imu.accel.noise_density_ug_per_sqrt_hz", "must be <= 16995.27");
  expect_one("format_version: 1\nimu:\n  accel:\n    bias_turn_on_mps2: 9.81\n", 4, 24,
             "imu.accel.bias_turn_on_mps2", "must be <= 9.80665");
  /* Signed values within [-bound, bound]; the failing component is named. */
  (void)read_ok("format_version: 1\nimu:\n  gyro:\n    bias_turn_on_fixed_dps: [-100, 0, 100]\n"
                "    scale_factor_fixed_ppm: [-1e6, 0, 1e6]\n  accel:\n    bias_turn_on_fixed_mg: -1000\n");
  expect_one("format_version: 1\nimu:\n  gyro:\n    bias_turn_on_fixed_dps: [0, -1e6, 0]\n", 4, 33,
             "imu.gyro.bias_turn_on_fixed_dps[1]", "must be >= -100 (got -1e6)");
  expect_one(
      "format_version: 1\nimu:\n  accel:\n    misalignment_fixed_mrad: [[0, 1, 2], [3, 0, 4], [5, 101, 0]]\n",
      4, 57, "imu.accel.misalignment_fixed_mrad[2][1]", "must be <= 100 (got 101)");
  /* Bias instability: half the bias bound, so that its GM sigma (B / 0.6648) stays within it. */
  expect_one("format_version: 1\nimu:\n  gyro:\n    bias_instability_deg_per_h: 2e5\n"
             "    bias_instability_tau_min_s: 300\n",
             4, 33, "imu.gyro.bias_instability_deg_per_h", "must be <= 180000 (got 2e5)");
  s = read_ok("format_version: 1\nimu:\n  gyro:\n    bias_instability_deg_per_h: 180000\n"
              "    bias_instability_tau_min_s: 300\n");
  assert_true(s.imu.model.gyro.bias_gm_sd_rps.x <=
              nav_unit_deg_per_h_to_rps(NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H));
  /* The reported sigmas of a receiver. */
  expect_one(
      "format_version: 1\ngnss:\n  enabled: true\n  reported_sigma: {position_m: 1, velocity_mps: 1e10}\n", 4,
      49, "gnss.reported_sigma.velocity_mps", "must be <= 100 (got 1e10)");
}

/* Issue 25: the bounds of initial errors, start velocities, the lever arm and the fix rate
   (scene_bounds.h): the bound itself is accepted, above it is refused at the value with the
   bound in the message; the tilt bound applies about north and east only (a 180 deg heading
   sigma, an unknown heading, stays valid), named by component. */
static void test_issue_25_initial_error_bounds(void **state) {
  (void)state;
  nav_scene s = read_ok("format_version: 1\ninitial_errors:\n  position_m: 1e5\n  velocity_mps: 1000\n"
                        "  attitude_deg: [90, 90, 180]\ngnss:\n  enabled: true\n  update_rate_hz: 1000\n"
                        "  lever_arm_b_m: [-1000, 0, 1000]\n");
  assert_near(s.initial_errors.att_sd_rad.z, NAV_PI, 1e-15);
  (void)read_ok("format_version: 1\ninitial_errors: {attitude_rad: [1.5707963267948966, 0, 3.141592653589793]}\n");
  (void)read_ok("format_version: 1\ntrajectory:\n  type: segments\n  segments:\n    v0_b_mps: [1e5, 0, -1e5]\n"
                "    items: [{kind: hold, duration_s: 1}]\n");
  expect_one("format_version: 1\ninitial_errors:\n  attitude_deg: [1, 91, 3]\n", 3, 21, "initial_errors.attitude_deg[1]",
             "the tilt about east must be <= 90 deg (got 91)");
  expect_one("format_version: 1\ninitial_errors:\n  attitude_rad: 1.6\n", 3, 17, "initial_errors.attitude_rad",
             "the tilt about north must be <= 1.57079633 rad (got 1.6)");
  expect_one("format_version: 1\ninitial_errors:\n  attitude_deg: [1, 1, 181]\n", 3, 24,
             "initial_errors.attitude_deg[2]", "must be <= 180 (got 181)");
  expect_one("format_version: 1\ninitial_errors:\n  velocity_mps: [0, 1001, 0]\n", 3, 21,
             "initial_errors.velocity_mps[1]", "must be <= 1000 (got 1001)");
  expect_one("format_version: 1\ngnss:\n  enabled: true\n  lever_arm_b_m: [0, -1001, 0]\n", 4, 22,
             "gnss.lever_arm_b_m[1]", "must be >= -1000 (got -1001)");
  expect_one("format_version: 1\ntrajectory:\n  type: segments\n  segments:\n    v0_b_mps: [2e5, 0, 0]\n"
             "    items: [{kind: hold, duration_s: 1}]\n",
             5, 16, "trajectory.segments.v0_b_mps[0]", "must be <= 100000 (got 2e5)");
  expect_one("format_version: 1\narray:\n  initial_rate_sd_dps: 101\n", 3, 24, "array.initial_rate_sd_dps",
             "must be <= 100 (got 101)");
  /* Every speed of a trajectory: segment targets and the test motions too. */
  expect_one("format_version: 1\ntrajectory:\n  type: segments\n  segments:\n    items:\n"
             "      - {kind: accelerate, speed_mps: 1e20}\n",
             6, 39, "trajectory.segments.items[0].speed_mps", "must be <= 100000 (got 1e20)");
  expect_one("format_version: 1\ntrajectory:\n  type: test_motion\n  duration_s: 10\n"
             "  test_motion: {kind: vertical_loop, loop_speed_mps: -2e5}\n",
             5, 54, "trajectory.test_motion.loop_speed_mps", "must be >= -100000 (got -2e5)");
}

/* Every row of both catalogs, written out key by key (no catalog name), reads back within the
   bounds and unchanged: the bounds never refuse a catalogued sensor. */
static void test_catalog_rows_within_bounds(void **state) {
  (void)state;
  char dir[64], path[128], text[512];
  diag_log log;
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/row.yaml", dir);
  nav_scene *a = malloc(sizeof *a), *b = malloc(sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  for (int kind = 0; kind < 3; ++kind) { /* IMU, GNSS receiver, array accelerometer part */
    nav_catalog *cat = NULL;
    assert_int_equal(nav_catalog_load(kind == 0   ? NAV_SOURCE_DIR "/resources/imu_catalog.csv"
                                      : kind == 1 ? NAV_SOURCE_DIR "/resources/gnss_receivers.csv"
                                                  : NAV_SOURCE_DIR "/resources/accel_catalog.csv",
                                      NULL, &cat, NULL, NULL),
                     NAV_OK);
    const size_t n = nav_catalog_count(cat);
    assert_true(n >= (kind == 0 ? 10u : 5u));
    for (size_t i = 0; i < n; ++i) {
      const char *name = kind == 0   ? nav_catalog_imu_at(cat, i)->name
                         : kind == 1 ? nav_catalog_gnss_at(cat, i)->name
                                     : nav_catalog_accel_at(cat, i)->name;
      if (kind == 0)
        snprintf(text, sizeof text, "format_version: 1\nimu:\n  catalog: \"%s\"\n", name);
      else if (kind == 1)
        snprintf(text, sizeof text, "format_version: 1\ngnss:\n  enabled: true\n  catalog: \"%s\"\n", name);
      else
        snprintf(text, sizeof text, "format_version: 1\narray:\n  catalog: \"%s\"\n", name);
      nav_status st = read_text(text, a, &log);
      if (st != NAV_OK) {
        print_log(&log);
        fail_msg("catalog row \"%s\" does not read", name);
      }
      a->imu.catalog[0] = '\0';
      a->gnss.catalog[0] = '\0';
      a->array.catalog[0] = '\0';
      assert_int_equal(nav_scene_write_file(path, a), NAV_OK);
      st = read_path(path, b, &log);
      if (st != NAV_OK) {
        print_log(&log);
        fail_msg("catalog row \"%s\" written key by key does not read back:\n%s", name, slurp(path));
      }
      assert_scene_same(a, b);
    }
    nav_catalog_destroy(cat);
  }
  rm_dir(dir);
  free(a);
  free(b);
}

/* ---------------------------------------------------------------- errors of the new sections */

static void test_trajectory_errors(void **state) {
  (void)state;
  static const char head[] = "format_version: 1\n"
                             "trajectory:\n"
                             "  type: segments\n"
                             "  segments:\n"
                             "    v0_b_mps: [10, 0, 0]\n"
                             "    items:\n";
  char text[1024];
  /* Unknown segment kind: did you mean, among the kinds. */
  snprintf(text, sizeof text, "%s      - {kind: helx, radius_m: 100, turns: 1}\n", head);
  expect_one(
      text, 7, 16, "trajectory.segments.items[0].kind",
      "expected one of: hold, accelerate, turn, coordinated_turn, climb, circle, figure_eight, helix, "
      "lawnmower, motion_rates, motion_abs_abs, motion_rel_rel, motion_abs_rel, motion_rel_abs; got \"helx\" "
      "(did you mean \"helix\"?)");
  /* Unknown key of a kind: did you mean among that kind's keys, else its keys listed. */
  snprintf(text, sizeof text, "%s      - {kind: circle, radus_m: 100, turns: 1}\n", head);
  expect_one(text, 7, 24, "trajectory.segments.items[0].radus_m", "did you mean \"radius_m\"?");
  snprintf(text, sizeof text, "%s      - {kind: turn, radius_m: 100}\n", head);
  expect_one(text, 7, 22, "trajectory.segments.items[0].radius_m",
             "unknown key \"radius_m\"; expected one of: kind, yaw_deg, yaw_rad, yaw_rate_dps, yaw_rate_rps, "
             "coordinated, gnss_visible");
  snprintf(text, sizeof text, "%s      - {radius_m: 100}\n", head);
  expect_one(text, 7, 9, "trajectory.segments.items[0].kind", "missing required key \"kind\"");
  /* The planner's verdict, placed at the segment. */
  snprintf(text, sizeof text,
           "%s      - {kind: hold, duration_s: 1}\n      - {kind: circle, radius_m: 1, turns: 1}\n", head);
  expect_one(text, 8, 9, "trajectory.segments.items[1]", "segment 1 (circle)");

  /* Waypoints: no position, two positions, a partial geodetic one. */
  static const char wp[] = "format_version: 1\n"
                           "trajectory:\n"
                           "  type: waypoints\n"
                           "  waypoints:\n"
                           "    points:\n"
                           "      - {ned_m: [0, 0, 0], speed_mps: 0}\n";
  snprintf(text, sizeof text, "%s      - {speed_mps: 3}\n", wp);
  expect_one(text, 7, 9, "trajectory.waypoints.points[1]", "the waypoint has no position");
  snprintf(text, sizeof text, "%s      - {ned_m: [10, 0, 0], lat_deg: 45, lon_deg: 0, h_m: 0}\n", wp);
  expect_one(text, 7, 29, "trajectory.waypoints.points[1].lat_deg",
             "the waypoint position is given twice: use either ned_m: [N, E, D] or lat_deg, lon_deg and h_m");
  snprintf(text, sizeof text, "%s      - {lat_deg: 45, h_m: 0}\n", wp);
  expect_one(text, 7, 9, "trajectory.waypoints.points[1]",
             "needs lat_deg, lon_deg and h_m (lon_deg is missing)");
  snprintf(text, sizeof text, "%s      - {lat_deg: 91, lon_deg: 0, h_m: 0}\n", wp);
  expect_one(text, 7, 19, "trajectory.waypoints.points[1].lat_deg", "must be <= 90 (got 91)");
  snprintf(text, sizeof text, "%s      - 5\n", wp);
  expect_one(text, 7, 9, "trajectory.waypoints.points[1]", "expected a waypoint");

  /* duration_s auto only for scripts; test motions have per-kind keys too. */
  expect_one("format_version: 1\ntrajectory: {duration_s: auto}\n", 2, 26, "trajectory.duration_s",
             "auto is the length of a waypoint or segment script; trajectory.type parametric needs a number");
  expect_one(
      "format_version: 1\ntrajectory:\n  type: test_motion\n  test_motion: {kind: spin, cone_rate_hz: 5}\n",
      4, 29, "trajectory.test_motion.cone_rate_hz", "unknown key \"cone_rate_hz\"");
  /* A validation message about the SI field, placed at the key that gave it in degrees. */
  expect_one("format_version: 1\ntrajectory:\n  type: test_motion\n"
             "  test_motion: {kind: coning, cone_half_angle_deg: 100}\n",
             4, 52, "trajectory.test_motion.cone_half_angle_rad", "must be in (0, 90] deg (got 100 deg)");
}

static void test_sensor_errors(void **state) {
  (void)state;
  /* Unknown catalog part: did you mean among the catalog's names. */
  expect_one("format_version: 1\nimu:\n  catalog: ADIS16456-1\n", 3, 12, "imu.catalog",
             "unknown IMU \"ADIS16456-1\"; did you mean \"ADIS16465-1\"?");
  expect_one("format_version: 1\ngnss:\n  catalog: \"RTK\"\n", 3, 12, "gnss.catalog",
             "unknown GNSS receiver \"RTK\"; `navsim catalog --gnss` lists the");
  /* Outages: t1 > t0, at most NAV_GNSS_MAX_OUTAGES. */
  expect_one("format_version: 1\ngnss:\n  outages: [[10, 20], [30, 30]]\n", 3, 28, "gnss.outages[1][1]",
             "the end t1_s = 30 must be after the start t0_s = 30");
  expect_one("format_version: 1\ngnss:\n  outages: [[10, 20, 30]]\n", 3, 13, "gnss.outages[0]",
             "expected [t0_s, t1_s], got a sequence");
  /* Bias instability needs its Allan-minimum time, and excludes the GM keys. */
  expect_one("format_version: 1\nimu:\n  gyro:\n    bias_instability_deg_per_h: 2\n", 4, 5,
             "imu.gyro.bias_instability_deg_per_h", "needs bias_instability_tau_min_s too");
  expect_one("format_version: 1\nimu:\n  accel: {bias_instability_ug: 2, bias_instability_tau_min_s: 100, "
             "bias_gm_tau_s: 5}\n",
             3, 68, "imu.accel.bias_gm_tau_s", "the Gauss-Markov bias is given twice");
  /* Datasheet ranges in file units; both spellings of one quantity. */
  expect_one("format_version: 1\nimu:\n  gyro: {arw_deg_per_sqrt_h: -0.1}\n", 3, 30,
             "imu.gyro.arw_deg_per_sqrt_h", "must be >= 0 (got -0.1)");
  expect_one("format_version: 1\nimu:\n  accel: {range_g: [16, 0, 16]}\n", 3, 25, "imu.accel.range_g[1]",
             "must be > 0 (got 0)");
  expect_one("format_version: 1\nimu:\n  gyro: {range_dps: 100, range_rps: 2}\n", 3, 26, "imu.gyro.range_rps",
             "both \"range_dps\" and \"range_rps\" are given");
  expect_one("format_version: 1\nimu:\n  gyro: {misalignment_mrad: [1, 2]}\n", 3, 29,
             "imu.gyro.misalignment_mrad",
             "expected a number (every off-diagonal element) or 3 rows of 3 numbers, got 2 items");
  /* "off": did you mean, and gyro-only terms. */
  expect_one("format_version: 1\nimu:\n  off: [gyro.nose]\n", 3, 9, "imu.off[0]",
             "unknown term \"gyro.nose\"; did you mean \"gyro.noise\"?");
  expect_one("format_version: 1\nimu:\n  off: accel.g_sensitivity\n", 3, 8, "imu.off",
             "g_sensitivity is a gyro term");
  expect_one("format_version: 1\ngnss:\n  reported_sigma: modle\n", 3, 19, "gnss.reported_sigma",
             "expected \"model\" or {position_m: [N, E, D], velocity_mps: [N, E, D]}");
  expect_one("format_version: 1\nnavigation: {aid_vertical: yes}\n", 2, 28, "navigation.aid_vertical",
             "expected true or false, got the boolean \"yes\"");
  /* Validation of the sensor model, placed at the key that set it. */
  expect_one("format_version: 1\nearth: {model: wgs84}\nnavigation: {scheme: ins_gnss}\n", 3, 22,
             "navigation.scheme", "ins_gnss needs a GNSS receiver");
}

/* ---------------------------------------------------------------- gyro-free array */

static const char k_custom_array[] = "format_version: 1\n"
                                     "navigation: {scheme: gyro_free}\n"
                                     "array:\n"
                                     "  layout: custom\n"
                                     "  sensors:\n"
                                     "    - {position_m: [0.1, 0, 0], axis: [0, 1, 1]}\n"
                                     "    - {position_m: [-0.1, 0, 0], axis: [0, 1, -1]}\n"
                                     "    - {position_m: [0, 0.1, 0], axis: [1, 0, 1]}\n"
                                     "    - {position_m: [0, -0.1, 0], axis: [-1, 0, 1]}\n"
                                     "    - {position_m: [0, 0, 0.1], axis: [1, 1, 0]}\n"
                                     "    - {position_m: [0, 0, -0.1], axis: [1, -1, 0]}\n"
                                     "  accel: {noise_density_ug_per_sqrt_hz: 100, bias_gm_sigma_mps2: 2e-4, "
                                     "bias_gm_tau_s: 60}\n"
                                     "  initial_rate_sd_rps: [1e-3, 2e-3, 0]\n";

static void test_gyro_free_array(void **state) {
  (void)state;
  /* Built-in layout, datasheet units converted once (nav_unit_* factors), one number per term. */
  nav_scene s = read_ok("format_version: 1\n"
                        "navigation: {scheme: gyro_free, algorithm: high_order}\n"
                        "array:\n"
                        "  layout: twelve\n"
                        "  radius_m: 0.25\n"
                        "  accel: {bias_turn_on_mg: 1, bias_gm_sigma_ug: 20, bias_gm_tau_s: 300,\n"
                        "          vrw_m_per_s_per_sqrt_h: 0.06, scale_factor_ppm: 300}\n"
                        "  initial_rate_sd_dps: 0.01\n");
  assert_int_equal(s.navigation.scheme, NAV_SCHEME_GYRO_FREE);
  assert_int_equal(s.array.layout, NAV_ARRAY_LAYOUT_TWELVE);
  assert_same_double(s.array.radius_m, 0.25);
  assert_int_equal(s.array.custom_count, 0);
  assert_int_equal(s.array.accel.terms, NAV_ARRAY_TERMS_ALL);
  assert_same_double(s.array.accel.bias_turn_on_sd_mps2, 1.0 * (1e-3 * NAV_G0_MPS2));
  assert_same_double(s.array.accel.bias_gm_sd_mps2, 20.0 * (1e-6 * NAV_G0_MPS2));
  assert_same_double(s.array.accel.bias_gm_tau_s, 300.0);
  assert_same_double(s.array.accel.vrw_mps_per_sqrt_s, 0.06 * (1.0 / 60.0));
  assert_same_double(s.array.accel.scale_factor_sd, 300.0 * 1e-6);
  assert_same_double(s.array.initial_rate_sd_rps.z, 0.01 * NAV_DEG2RAD);
  /* Defaults: the cube, r = 0.1 m, ideal sensors; the scheme stays free_ins. */
  s = read_ok("format_version: 1\narray:\n");
  assert_int_equal(s.navigation.scheme, NAV_SCHEME_FREE_INS);
  assert_int_equal(s.array.layout, NAV_ARRAY_LAYOUT_CUBE6);
  assert_same_double(s.array.radius_m, 0.1);
  assert_int_equal(s.array.accel.terms, 0);
  /* A custom layout: axes kept as written (normalised where used), SI spellings. */
  s = read_ok(k_custom_array);
  assert_int_equal(s.array.layout, NAV_ARRAY_LAYOUT_CUSTOM);
  assert_int_equal(s.array.custom_count, 6);
  assert_same_vec3(s.array.custom[3].r_bs_b_m, nav_vec3_make(0.0, -0.1, 0.0));
  assert_same_vec3(s.array.custom[3].n_s_b, nav_vec3_make(-1.0, 0.0, 1.0));
  assert_int_equal(s.array.accel.terms, NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM);
  assert_same_double(s.array.accel.vrw_mps_per_sqrt_s, 100.0 * (1e-6 * NAV_G0_MPS2));
  assert_same_double(s.array.accel.bias_gm_sd_mps2, 2e-4);
  assert_same_vec3(s.array.initial_rate_sd_rps, nav_vec3_make(1e-3, 2e-3, 0.0));

  /* One problem each, at its place. */
  expect_one("format_version: 1\narray: {layout: cubee}\n", 2, 17, "array.layout",
             "expected one of: cube6, nine, twelve, custom; got \"cubee\" (did you mean \"cube6\"?)");
  expect_one("format_version: 1\narray: {radius_m: 0}\n", 2, 19, "array.radius_m", "must be > 0 (got 0)");
  expect_one("format_version: 1\narray: {sensors: {position_m: [0, 0, 0]}}\n", 2, 18, "array.sensors",
             "expected a list of sensors (- {position_m: [x, y, z], axis: [x, y, z]})");
  expect_one("format_version: 1\narray:\n  sensors:\n    - {position_m: [0.1, 0, 0]}\n", 4, 7,
             "array.sensors[0].axis", "missing required key \"axis\"");
  expect_one(
      "format_version: 1\narray: {layout: custom, sensors: [{position_m: [1, 0, 0], axis: [0, 1, 0]}]}\n", 2,
      34, "array.sensors", "a custom layout needs 6 to 16 sensors (got 1)");
  expect_one("format_version: 1\narray: {accel: {bias_gm_tau_s: 0}}\n", 2, 32, "array.accel.bias_gm_tau_s",
             "must be > 0 (got 0)");
  expect_one("format_version: 1\narray: {accel: {vrw_m_per_s_per_sqrt_h: 0.1, vrw_mps_per_sqrt_s: 1e-3}}\n",
             2, 46, "array.accel.vrw_mps_per_sqrt_s",
             "both \"vrw_m_per_s_per_sqrt_h\" and \"vrw_mps_per_sqrt_s\" are given");
  expect_one("format_version: 1\narray: {accel: {off: [nose]}}\n", 2, 23, "array.accel.off[0]",
             "unknown term \"nose\"; did you mean \"noise\"?");
  expect_one("format_version: 1\narray: {initial_rate_sd_dps: [0.1, -1, 0]}\n", 2, 36,
             "array.initial_rate_sd_dps[1]", "must be >= 0 (got -1)");
  expect_one("format_version: 1\nnavigation: {scheme: gyro_free, aid_vertical: true}\n", 2, 47,
             "navigation.aid_vertical", "applies to the free INS only, not to gyro_free");
  /* Validation of the layout, placed at the sensors: every axis along its lever arm. */
  expect_one(
      "format_version: 1\narray:\n  layout: custom\n  sensors:\n"
      "    - {position_m: [0.1, 0, 0], axis: [1, 0, 0]}\n    - {position_m: [-0.1, 0, 0], axis: [1, 0, 0]}\n"
      "    - {position_m: [0, 0.1, 0], axis: [0, 1, 0]}\n    - {position_m: [0, -0.1, 0], axis: [0, 1, 0]}\n"
      "    - {position_m: [0, 0, 0.1], axis: [0, 0, 1]}\n    - {position_m: [0, 0, -0.1], axis: [0, 0, 1]}\n",
      5, 5, "array.sensors", "H (E1.23) is singular or its condition number exceeds 1e8");
  expect_one(
      "format_version: 1\narray:\n  layout: custom\n  sensors:\n"
      "    - {position_m: [0.1, 0, 0], axis: [0, 0, 0]}\n    - {position_m: [-0.1, 0, 0], axis: [0, 1, -1]}\n"
      "    - {position_m: [0, 0.1, 0], axis: [1, 0, 1]}\n    - {position_m: [0, -0.1, 0], axis: [-1, 0, 1]}\n"
      "    - {position_m: [0, 0, 0.1], axis: [1, 1, 0]}\n    - {position_m: [0, 0, -0.1], axis: [1, -1, "
      "0]}\n",
      5, 39, "array.sensors[0].n_s_b", "the sensitive axis must be a non-zero vector (got norm 0)");

  /* Round trip, bit for bit: a custom layout with awkward numbers, a term on with every value
     at its default (written through its first key), and a term off with values ("off" list). */
  char dir[64], path[128];
  diag_log log;
  nav_scene *a = malloc(sizeof *a), *b = malloc(sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  *a = read_ok(k_custom_array);
  a->array.custom_count = 7;
  a->array.custom[6].r_bs_b_m = nav_vec3_make(0.1 / 3.0, -2e-17, 0.07);
  a->array.custom[6].n_s_b = nav_vec3_make(1.0 / 3.0, 0.0, -NAV_PI);
  a->array.accel.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON;
  a->array.accel.bias_turn_on_sd_mps2 = 0.0;
  a->array.accel.bias_gm_sd_mps2 = 1.2345e-4; /* GM off, values kept */
  a->array.accel.vrw_mps_per_sqrt_s = 0.1 / 7.0;
  a->array.initial_rate_sd_rps = nav_vec3_make(1e-3 * NAV_DEG2RAD, 0.3, 0.3);
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/gf.yaml", dir);
  assert_int_equal(nav_scene_write_file(path, a), NAV_OK);
  const nav_status st = read_path(path, b, &log);
  if (st != NAV_OK) {
    print_log(&log);
    fail_msg("written back does not read:\n%s", slurp(path));
  }
  assert_scene_same(a, b);
  const char *text = slurp(path);
  assert_non_null(strstr(text, "  scheme: gyro_free  #"));
  assert_non_null(strstr(text, "\narray:\n  layout: custom  #"));
  assert_non_null(strstr(text, "\n    - {position_m: [0.1, 0, 0], axis: [0, 1, 1]}\n"));
  assert_non_null(strstr(text, "    off: [bias_gm]"));
  assert_non_null(strstr(text, "    bias_turn_on_mg: 0"));
  /* A scene that does not use the array and keeps its defaults has no array section. */
  *a = nav_scene_default();
  assert_int_equal(nav_scene_write_file(path, a), NAV_OK);
  assert_null(strstr(slurp(path), "array:"));
  rm_dir(dir);
  free(a);
  free(b);
}

static void test_motion_def_errors(void **state) {
  (void)state;
  diag_log log;
  nav_scene s;
  /* A missing file: the message names the resolved path. */
  assert_int_equal(read_path(SCENES_DIR "invalid-motion-def-missing.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 5, 22, "trajectory.motion_def.file",
              "cannot read the motion-definition file \"" NAV_TEST_DATA_DIR
              "/scenes/no-such-motion.csv\": No such file or directory");
  /* The file sets the origin: earth.origin as well is an error. */
  assert_int_equal(read_path(SCENES_DIR "invalid-motion-def-origin.yaml", &s, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  expect_diag(&log, 0, 4, 11, "earth.origin",
              "the motion-definition file (trajectory.motion_def.file) sets the origin; remove earth.origin");
  /* From memory: a relative path resolves against the directory of the display name. */
  static const char text[] = "format_version: 1\ntrajectory:\n  type: motion_def\n  motion_def:\n"
                             "    file: ../../../resources/motion_defs/motion_def-90deg_turn.csv\n";
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_scene_read_string(text, strlen(text), SCENES_DIR "mem.yaml", &s, collect, &log),
                   NAV_OK);
  assert_int_equal(s.trajectory.segments.count, 3);
  /* The file also sets the initial attitude and the segment script. */
  expect_one("format_version: 1\nearth: {model: wgs84}\ntrajectory:\n  type: motion_def\n"
             "  initial_attitude: {yaw_deg: 3}\n"
             "  motion_def: {file: " NAV_SOURCE_DIR "/resources/motion_defs/motion_def-90deg_turn.csv}\n",
             5, 21, "trajectory.initial_attitude",
             "the motion-definition file (trajectory.motion_def.file) sets the initial attitude");
  /* Flags stricter than the import's: the planner's verdict, placed at the file. */
  expect_one("format_version: 1\nearth: {model: wgs84}\ntrajectory:\n  type: motion_def\n"
             "  motion_def:\n    file: " NAV_SOURCE_DIR "/resources/motion_defs/motion_def-long_drive.csv\n"
             "    allow_unconverged: false\n",
             6, 11, "trajectory.motion_def.file",
             "with the allow_unconverged / fit_rate_ramps given: segment 13 (motion type 5)");
  /* The section without the type, the type without the section, a malformed file. */
  expect_one("format_version: 1\ntrajectory:\n  motion_def: {file: x.csv}\n", 3, 15, "trajectory.motion_def",
             "is read only with trajectory.type: motion_def (type is parametric)");
  expect_one("format_version: 1\ntrajectory: {type: motion_def}\n", 2, 20, "trajectory.type",
             "motion_def needs trajectory.motion_def: {file: PATH}");
  expect_one("format_version: 1\ntrajectory: {type: motion_def, motion_def: {fit_rate_ramps: true}}\n", 2, 44,
             "trajectory.motion_def.file", "missing required key \"file\"");
}

/* ---------------------------------------------------------------- the scene library */

/* Every scene of scenes/ is valid, and writing then reading it gives the same scene, bit for
   bit; writing that again gives the same text. */
static void test_scene_library_round_trip(void **state) {
  (void)state;
  char dir[64], out[128], out2[128], path[512];
  diag_log log;
  nav_scene *a = malloc(sizeof *a), *b = malloc(sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  make_dir(dir, sizeof dir);
  snprintf(out, sizeof out, "%s/rt.yaml", dir);
  snprintf(out2, sizeof out2, "%s/rt2.yaml", dir);
  DIR *d = opendir(NAV_SOURCE_DIR "/scenes");
  assert_non_null(d);
  int n = 0;
  for (struct dirent *e = readdir(d); e != NULL; e = readdir(d)) {
    const size_t len = strlen(e->d_name);
    if (len < 6 || strcmp(e->d_name + len - 5, ".yaml") != 0) continue;
    snprintf(path, sizeof path, "%s/scenes/%s", NAV_SOURCE_DIR, e->d_name);
    nav_status st = read_path(path, a, &log);
    if (st != NAV_OK) {
      print_log(&log);
      fail_msg("%s does not pass validation", path);
    }
    assert_int_equal(nav_scene_write_file(out, a), NAV_OK);
    st = read_path(out, b, &log);
    if (st != NAV_OK) {
      print_log(&log);
      fail_msg("%s written back does not read:\n%s", path, slurp(out));
    }
    print_message("[ SCENE    ] %s\n", e->d_name);
    assert_scene_same(a, b);
    assert_int_equal(nav_scene_write_file(out2, b), NAV_OK);
    char *first = strdup(slurp(out));
    assert_non_null(first);
    assert_string_equal(first, slurp(out2));
    free(first);
    nav_scene_release(a); /* a recorded reference's control points (docs/recorded-fit.md) */
    nav_scene_release(b);
    ++n;
  }
  closedir(d);
  assert_true(n >= 11);
  rm_dir(dir);
  free(a);
  free(b);
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
/* >= 0; one case in four with three equal components (written as one number). */
static nav_vec3 nonneg_vec3(uint64_t *x) {
  if (splitmix64(x) % 4 == 0) {
    const double v = fabs(any_double(x));
    return nav_vec3_make(v, v, v);
  }
  const nav_vec3 v = any_vec3(x);
  return nav_vec3_make(fabs(v.x), fabs(v.y), fabs(v.z));
}
static nav_vec3 positive_vec3(uint64_t *x) {
  const nav_vec3 v = nonneg_vec3(x);
  return nav_vec3_make(v.x + 1e-3, v.y + 1e-3, v.z + 1e-3);
}
/* A matrix with a zero diagonal (misalignment), or a full one; >= 0 for standard deviations. */
static nav_mat3 any_mat3(uint64_t *x, bool zero_diagonal, bool nonneg) {
  nav_mat3 m;
  const bool same = splitmix64(x) % 3 == 0;
  const double v = any_double(x);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double e = same ? v : any_double(x);
      m.m[i][j] = zero_diagonal && i == j ? 0.0 : nonneg ? fabs(e) : e;
    }
  return m;
}

/* The plausibility bounds of the reader (scene_bounds.h), in SI, with a factor 2 of margin (the
   writer may choose another unit). A drawn value above one is divided by 1000 until it fits:
   the draws themselves, and so every other field, stay those of before the bounds. */
static double fit(double v, double bound_si) {
  while (fabs(v) > 0.5 * bound_si)
    v /= 1000.0;
  return v;
}
static nav_vec3 fit3(nav_vec3 v, double bound_si) {
  return nav_vec3_make(fit(v.x, bound_si), fit(v.y, bound_si), fit(v.z, bound_si));
}
static nav_mat3 fit33(nav_mat3 m, double bound_si) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      m.m[i][j] = fit(m.m[i][j], bound_si);
  return m;
}
#define B_GYRO_BIAS nav_unit_deg_per_h_to_rps(NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H)
#define B_ACCEL_BIAS nav_unit_mg_to_mps2(NAV_SCENE_MAX_ACCEL_BIAS_MG)
#define B_SF nav_unit_ppm_to_ratio(NAV_SCENE_MAX_SCALE_FACTOR_PPM)
#define B_MIS nav_unit_mrad_to_rad(NAV_SCENE_MAX_MISALIGNMENT_MRAD)
#define B_GSENS nav_unit_deg_per_h_per_g_to_rps_per_mps2(NAV_SCENE_MAX_G_SENSITIVITY_DEG_PER_H_PER_G)

/* Random values for every field, each term on or off at random: a term that is off but holds
   values is written with an "off" entry. */
static void random_imu(uint64_t *x, nav_imu_model_config *m) {
  nav_gyro_error_config *g = &m->gyro;
  nav_accel_error_config *a = &m->accel;
  g->terms = (unsigned)splitmix64(x) & NAV_IMU_TERMS_GYRO_ALL;
  a->terms = (unsigned)splitmix64(x) & NAV_IMU_TERMS_ACCEL_ALL;
  g->bias_turn_on_fixed_rps = fit3(any_vec3(x), B_GYRO_BIAS);
  g->bias_turn_on_sd_rps = fit3(nonneg_vec3(x), B_GYRO_BIAS);
  g->bias_gm_sd_rps = fit3(nonneg_vec3(x), B_GYRO_BIAS);
  g->bias_gm_tau_s = positive_vec3(x);
  g->bias_rw_rps_per_sqrt_s =
      fit3(nonneg_vec3(x),
           nav_unit_deg_per_h_per_sqrt_h_to_rps_per_sqrt_s(NAV_SCENE_MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H));
  g->arw_rad_per_sqrt_s =
      fit3(nonneg_vec3(x), nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(NAV_SCENE_MAX_GYRO_ARW_DEG_PER_SQRT_H));
  g->scale_factor_fixed = fit3(any_vec3(x), B_SF);
  g->scale_factor_sd = fit3(nonneg_vec3(x), B_SF);
  g->misalignment_fixed_rad = fit33(any_mat3(x, true, false), B_MIS);
  g->misalignment_sd_rad = fit33(any_mat3(x, true, true), B_MIS);
  g->g_sensitivity_fixed_rps_per_mps2 = fit33(any_mat3(x, false, false), B_GSENS);
  g->g_sensitivity_sd_rps_per_mps2 = fit33(any_mat3(x, false, true), B_GSENS);
  g->quant_step_rad = positive_vec3(x);
  g->range_rps = positive_vec3(x);
  a->bias_turn_on_fixed_mps2 = fit3(any_vec3(x), B_ACCEL_BIAS);
  a->bias_turn_on_sd_mps2 = fit3(nonneg_vec3(x), B_ACCEL_BIAS);
  a->bias_gm_sd_mps2 = fit3(nonneg_vec3(x), B_ACCEL_BIAS);
  a->bias_gm_tau_s = positive_vec3(x);
  a->bias_rw_mps2_per_sqrt_s =
      fit3(nonneg_vec3(x),
           nav_unit_mps2_per_sqrt_h_to_mps2_per_sqrt_s(NAV_SCENE_MAX_ACCEL_BIAS_RW_M_PER_S2_PER_SQRT_H));
  a->vrw_mps_per_sqrt_s = fit3(
      nonneg_vec3(x), nav_unit_mps_per_sqrt_h_to_mps_per_sqrt_s(NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H));
  a->scale_factor_fixed = fit3(any_vec3(x), B_SF);
  a->scale_factor_sd = fit3(nonneg_vec3(x), B_SF);
  a->misalignment_fixed_rad = fit33(any_mat3(x, true, false), B_MIS);
  a->misalignment_sd_rad = fit33(any_mat3(x, true, true), B_MIS);
  a->quant_step_mps = positive_vec3(x);
  a->range_mps2 = positive_vec3(x);
}

static void random_gnss(uint64_t *x, nav_scene_gnss *n) {
  nav_gnss_model_config *m = &n->model;
  n->enabled = splitmix64(x) & 1;
  m->terms = (unsigned)splitmix64(x) & NAV_GNSS_TERMS_ALL;
  m->update_rate_hz = 0.1 + 20.0 * uniform(x);
  m->latency_s = uniform(x);
  m->pos_gm_sd_m = fit3(nonneg_vec3(x), NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M);
  m->pos_gm_tau_s = nonneg_vec3(x);
  m->pos_white_sd_m = fit3(nonneg_vec3(x), NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M);
  m->vel_sd_mps = fit3(nonneg_vec3(x), NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS);
  m->r_ba_b_m = fit3(any_vec3(x), NAV_SCENE_MAX_LEVER_ARM_M);
  m->report_model_sigmas = splitmix64(x) & 1;
  if (!m->report_model_sigmas) {
    m->reported_pos_sd_m = fit3(nonneg_vec3(x), NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M);
    m->reported_vel_sd_mps = fit3(nonneg_vec3(x), NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS);
  }
  m->outage_count = (size_t)(splitmix64(x) % 4);
  for (size_t i = 0; i < m->outage_count; ++i) {
    m->outages[i].t0_s = 1000.0 * uniform(x);
    m->outages[i].t1_s = m->outages[i].t0_s + 1e-3 + 100.0 * uniform(x);
  }
}

/* Trajectory sections of types the scene does not use (written because they differ from the
   defaults); the test motion gets random values for its kind's parameters only, which are all
   that is written. */
static void random_trajectories(uint64_t *x, nav_scene_trajectory *t) {
  nav_traj_waypoints *w = &t->waypoints;
  w->timing = (nav_wp_timing)(splitmix64(x) % 2);
  w->attitude_mode = (nav_wp_attitude_mode)(splitmix64(x) % 4);
  w->hold_start_s = 10.0 * uniform(x);
  w->hold_end_s = 10.0 * uniform(x);
  w->cruise_mps = splitmix64(x) % 2 ? 30.0 * uniform(x) : 0.0;
  w->limits.max_rate_rps = 0.01 + uniform(x);
  w->limits.max_ang_accel_rps2 = 0.01 + uniform(x);
  w->count = (int)(splitmix64(x) % 4);
  for (int i = 0; i < w->count; ++i) {
    w->points[i].r_ned_m = any_vec3(x);
    w->points[i].speed_mps = fabs(any_double(x));
    w->points[i].time_s = fabs(any_double(x));
    w->points[i].attitude = (nav_euler){any_double(x), any_double(x), any_double(x)};
    /* From a value already drawn, so the random stream of the other fields is unchanged. */
    w->points[i].hold_s = i % 2 ? fmin(w->points[i].time_s, 1e6) : 0.0;
  }
  nav_traj_segments *s = &t->segments;
  s->allow_unconverged = splitmix64(x) & 1;
  s->fit_rate_ramps = splitmix64(x) & 1;
  s->r0_ned_m = any_vec3(x);
  s->v0_b_mps = fit3(any_vec3(x), NAV_SCENE_MAX_SPEED_MPS);
  s->limits.max_ang_jerk_rps3 = 0.01 + uniform(x);
  s->count = (int)(splitmix64(x) % 6);
  for (int i = 0; i < s->count; ++i) {
    nav_segment *g = &s->items[i];
    g->kind = (nav_segment_kind)(splitmix64(x) % 14);
    g->gnss_visible = splitmix64(x) & 1;
    g->coordinated = g->kind != NAV_SEG_HOLD && g->kind != NAV_SEG_ACCELERATE &&
                     g->kind != NAV_SEG_COORD_TURN && g->kind != NAV_SEG_CLIMB && (splitmix64(x) & 1);
    switch (g->kind) {
    case NAV_SEG_HOLD: g->duration_s = 100.0 * uniform(x); break;
    case NAV_SEG_ACCELERATE: g->speed_mps = fit(any_double(x), NAV_SCENE_MAX_SPEED_MPS); break;
    case NAV_SEG_TURN:
    case NAV_SEG_COORD_TURN:
      g->yaw_rad = any_double(x);
      g->yaw_rate_rps = any_double(x);
      break;
    case NAV_SEG_CLIMB:
      g->height_m = any_double(x);
      g->pitch_rad = any_double(x);
      break;
    case NAV_SEG_HELIX: g->pitch_rad = any_double(x); /* fall through */
    case NAV_SEG_CIRCLE:
    case NAV_SEG_FIGURE_EIGHT:
      g->radius_m = 1.0 + fabs(any_double(x));
      g->turns = any_double(x);
      break;
    case NAV_SEG_LAWNMOWER:
      g->legs = 1 + (int)(splitmix64(x) % 10);
      g->length_m = fabs(any_double(x));
      g->spacing_m = any_double(x);
      break;
    case NAV_SEG_MOTION_RATES:
      g->yaw_rate_rps = any_double(x);
      g->pitch_rate_rps = any_double(x);
      g->roll_rate_rps = any_double(x);
      g->accel_b_mps2 = any_vec3(x);
      g->duration_s = 100.0 * uniform(x);
      break;
    default:
      g->yaw_rad = any_double(x);
      g->pitch_rad = any_double(x);
      g->roll_rad = any_double(x);
      g->v_b_mps = any_vec3(x);
      g->duration_s = 100.0 * uniform(x);
      break;
    }
  }
  nav_traj_test_motion *m = &t->test_motion;
  m->kind = (nav_test_motion_kind)(splitmix64(x) % 6);
  switch (m->kind) {
  case NAV_TEST_MOTION_CONING:
    m->cone_half_angle_rad = any_double(x);
    m->cone_rate_rps = any_double(x);
    break;
  case NAV_TEST_MOTION_SCULLING:
    m->scull_angle_rad = any_double(x);
    m->scull_accel_mps2 = any_double(x);
    m->scull_rate_rps = any_double(x);
    break;
  case NAV_TEST_MOTION_SPIN:
    m->spin_rate_rps = any_double(x);
    m->spin_axis_b = any_vec3(x);
    break;
  case NAV_TEST_MOTION_POLAR_GREAT_CIRCLE:
    m->gc_height_m = any_double(x);
    m->gc_speed_mps = fit(any_double(x), NAV_SCENE_MAX_SPEED_MPS);
    m->gc_start_angle_rad = any_double(x);
    m->gc_lon_rad = any_double(x);
    break;
  case NAV_TEST_MOTION_VERTICAL_LOOP:
    m->loop_speed_mps = fit(any_double(x), NAV_SCENE_MAX_SPEED_MPS);
    m->loop_pitch_rate_rps = any_double(x);
    break;
  default: break;
  }
}

/* A random array section (any layout; custom sensors kept even when the layout is built in). */
static void random_array(uint64_t *x, nav_scene_array *a) {
  a->layout = (nav_array_layout_kind)(splitmix64(x) % 4);
  a->radius_m = 0.01 + uniform(x);
  a->custom_count = (int)(splitmix64(x) % (NAV_SCENE_ARRAY_MAX_SENSORS + 1));
  if (a->layout == NAV_ARRAY_LAYOUT_CUSTOM) a->custom_count = 6 + (int)(splitmix64(x) % 11);
  /* Generic positions and axes within a metre: H well conditioned (a custom layout is checked). */
  for (int i = 0; i < a->custom_count; ++i) {
    a->custom[i].r_bs_b_m = nav_vec3_make(uniform(x) - 0.5, uniform(x) - 0.5, uniform(x) - 0.5);
    a->custom[i].n_s_b = nav_vec3_make(uniform(x) - 0.5, uniform(x) - 0.5, 0.1 + uniform(x));
  }
  a->accel.terms = (unsigned)splitmix64(x) & NAV_ARRAY_TERMS_ALL;
  a->accel.bias_turn_on_sd_mps2 = uniform(x) * 1e-2;
  a->accel.bias_gm_sd_mps2 = uniform(x) * 1e-3;
  a->accel.bias_gm_tau_s = 1.0 + 1000.0 * uniform(x);
  a->accel.vrw_mps_per_sqrt_s = uniform(x) * 1e-3;
  a->accel.scale_factor_sd = uniform(x) * 1e-3;
  a->initial_rate_sd_rps = fit3(nonneg_vec3(x), NAV_SCENE_MAX_INITIAL_RATE_SD_DPS * NAV_DEG2RAD);
}

/* Random navigation options of the ins_gnss filter (the smoother only with ins_gnss, as the
   checks require) and 0 to NAV_SCENE_MAX_REQUIREMENTS random valid requirements: every metric,
   statistic and unit, the unit of the metric's quantity, cep only on horizontal_position, time_s
   only with at_time. */
static void random_navigation_and_requirements(uint64_t *x, nav_scene *s, int k) {
  s->navigation.cov_decimation = (int)(splitmix64(x) % 1001);
  s->navigation.estimate_scale_factors = splitmix64(x) & 1;
  s->navigation.smoother = s->navigation.scheme == NAV_SCHEME_INS_GNSS && (splitmix64(x) & 1);
  s->n_requirements = k == 2 ? NAV_SCENE_MAX_REQUIREMENTS : (int)(splitmix64(x) % 6);
  static const char id_chars[] = "abcXYZ019_.-";
  for (int i = 0; i < s->n_requirements; ++i) {
    nav_requirement *q = &s->requirements[i];
    memset(q, 0, sizeof *q);
    int n = snprintf(q->id, sizeof q->id, "r%d", i); /* unique; random characters after it */
    const int extra = (int)(splitmix64(x) % 40);
    for (int c = 0; c < extra && n + 1 < NAV_REQ_ID_MAX; ++c)
      q->id[n++] = id_chars[splitmix64(x) % 12];
    q->id[n] = '\0';
    q->statistic = (nav_req_statistic)(splitmix64(x) % NAV_REQ_STATISTIC_COUNT);
    q->metric = q->statistic == NAV_REQ_CEP50 || q->statistic == NAV_REQ_CEP95
                    ? NAV_REQ_HORIZONTAL_POSITION
                    : (nav_req_metric)(splitmix64(x) % NAV_REQ_METRIC_COUNT);
    do {
      q->unit = (nav_req_unit)(splitmix64(x) % NAV_REQ_UNIT_COUNT);
    } while (nav_req_unit_quantity(q->unit) != nav_req_metric_quantity(q->metric));
    q->limit = 1e-6 + fabs(any_double(x));
    q->time_s = q->statistic == NAV_REQ_AT_TIME ? fabs(any_double(x)) : NAN;
  }
}

static void test_round_trip_random_bit_exact(void **state) {
  (void)state;
  char dir[64], path[128];
  diag_log log;
  const uint64_t seed = 0x5EED5CE4Eu;
  uint64_t x = seed;
  nav_scene *ap = malloc(sizeof *ap), *bp = malloc(sizeof *bp);
  assert_non_null(ap);
  assert_non_null(bp);
  nav_test_print_seed("test_round_trip_random_bit_exact", seed);
  make_dir(dir, sizeof dir);
  snprintf(path, sizeof path, "%s/rt.yaml", dir);
  int smoothers = 0, sf_states = 0, decimated = 0, stats[NAV_REQ_STATISTIC_COUNT] = {0};
  for (int k = 0; k < 40; ++k) {
    nav_scene *a = ap, *b = bp;
    *a = nav_scene_default();
    /* Arbitrary radians: most have no exact decimal-degree spelling and fall back to _rad. */
    a->earth.model = (splitmix64(&x) & 1) ? NAV_EARTH_WGS84 : NAV_EARTH_FLAT;
    a->earth.gravity_model = (splitmix64(&x) & 1) ? NAV_GRAVITY_J2 : NAV_GRAVITY_NORMAL;
    a->earth.origin_lat_rad = (uniform(&x) - 0.5) * 0.999 * NAV_PI;
    a->earth.origin_lon_rad = (uniform(&x) - 0.5) * 2.0 * NAV_PI;
    a->earth.origin_h_m = (uniform(&x) - 0.5) * 2.0e4;
    a->earth.flat_gravity_mps2 = 9.0 + uniform(&x);
    a->trajectory.duration_s = 1.0 + 100.0 * uniform(&x);
    a->trajectory.initial_attitude.roll_rad = any_double(&x);
    a->trajectory.initial_attitude.pitch_rad = k == 0 ? -0.0 : any_double(&x);
    a->trajectory.initial_attitude.yaw_rad = k == 1 ? 5e-324 : any_double(&x);
    nav_traj_parametric *p = &a->trajectory.parametric;
    p->r0_m = any_vec3(&x);
    p->v0_mps = fit3(any_vec3(&x), NAV_SCENE_MAX_SPEED_MPS);
    p->a_mps2 = any_vec3(&x);
    p->b_m = any_vec3(&x);
    p->c_hz = any_vec3(&x);
    p->d_rad = any_vec3(&x);
    p->wa_rps = any_vec3(&x);
    p->wb_rps = any_vec3(&x);
    p->wc_hz = any_vec3(&x);
    p->wd_rad = any_vec3(&x);
    p->magnus_substeps = 1 + (int)(splitmix64(&x) % 64);
    random_trajectories(&x, &a->trajectory);
    a->imu.rate_hz = 50.0 + 1000.0 * uniform(&x);
    a->imu.quadrature_nodes = 1 + (int)(splitmix64(&x) % 8);
    random_imu(&x, &a->imu.model);
    random_gnss(&x, &a->gnss);
    a->initial_errors.pos_sd_m = fit3(nonneg_vec3(&x), NAV_SCENE_MAX_INITIAL_POSITION_SD_M);
    a->initial_errors.vel_sd_mps = fit3(nonneg_vec3(&x), NAV_SCENE_MAX_INITIAL_VELOCITY_SD_MPS);
    {
      const nav_vec3 att = nonneg_vec3(&x); /* tilt about N and E, heading about D */
      a->initial_errors.att_sd_rad = nav_vec3_make(fit(att.x, NAV_SCENE_MAX_INITIAL_TILT_SD_DEG * NAV_DEG2RAD),
                                                   fit(att.y, NAV_SCENE_MAX_INITIAL_TILT_SD_DEG * NAV_DEG2RAD),
                                                   fit(att.z, NAV_SCENE_MAX_INITIAL_HEADING_SD_DEG * NAV_DEG2RAD));
    }
    a->navigation.scheme = a->gnss.enabled && a->earth.model == NAV_EARTH_WGS84 && (splitmix64(&x) & 1)
                               ? NAV_SCHEME_INS_GNSS
                               : NAV_SCHEME_FREE_INS;
    a->navigation.algorithm = (splitmix64(&x) & 1) ? NAV_MECH_HIGH_ORDER : NAV_MECH_FIRST_ORDER;
    a->navigation.frame = (splitmix64(&x) & 1) ? NAV_MECH_ECEF : NAV_MECH_NED;
    a->navigation.aid_vertical = a->navigation.scheme == NAV_SCHEME_FREE_INS && (splitmix64(&x) & 1);
    {
      /* The array from its own stream, so the draws of the other fields are those of before. */
      uint64_t xa = seed + 0xA77A1u * (uint64_t)(k + 1);
      random_array(&xa, &a->array);
      if (a->navigation.scheme == NAV_SCHEME_FREE_INS && (splitmix64(&xa) & 1)) {
        a->navigation.scheme = NAV_SCHEME_GYRO_FREE;
        a->navigation.aid_vertical = false;
      }
    }
    {
      /* Navigation options and requirements from their own stream too. */
      uint64_t xn = seed + 0x4E5Au * (uint64_t)(k + 1);
      random_navigation_and_requirements(&xn, a, k);
      smoothers += a->navigation.smoother;
      sf_states += a->navigation.estimate_scale_factors;
      decimated += a->navigation.cov_decimation > 1;
      for (int i = 0; i < a->n_requirements; ++i)
        ++stats[a->requirements[i].statistic];
    }
    a->output.rate_hz = 1.0 + 40.0 * uniform(&x);
    a->simulation.seed = splitmix64(&x);
    a->simulation.runs = 1 + (long)(splitmix64(&x) % 1000);
    a->simulation.threads = (int)(splitmix64(&x) % 257);
    snprintf(a->name, sizeof a->name, "run \"%d\" \\ %s", k, k % 2 ? "caf\xC3\xA9" : "colon: # hash");
    assert_int_equal(nav_scene_write_file(path, a), NAV_OK);
    const nav_status st = read_path(path, b, &log);
    if (st != NAV_OK) {
      print_log(&log);
      fail_msg("case %d: %s", k, slurp(path));
    }
    assert_scene_same(a, b);
  }
  /* The new fields were exercised: each option on in some cases, every statistic drawn. */
  assert_true(smoothers > 0 && sf_states > 0 && decimated > 0);
  for (int s = 0; s < NAV_REQ_STATISTIC_COUNT; ++s)
    if (stats[s] == 0) fail_msg("statistic %d never drawn", s);
  assert_int_equal(count_entries(dir), 1);
  rm_dir(dir);
  free(ap);
  free(bp);
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
      cmocka_unit_test(test_waypoints),
      cmocka_unit_test(test_waypoint_hold_s),
      cmocka_unit_test(test_geodetic_waypoints_any_order),
      cmocka_unit_test(test_segment_kinds),
      cmocka_unit_test(test_test_motions),
      cmocka_unit_test(test_motion_def_import),
      cmocka_unit_test(test_duration_auto),
      cmocka_unit_test(test_sensor_units),
      cmocka_unit_test(test_bias_instability_conventions),
      cmocka_unit_test(test_imu_catalog),
      cmocka_unit_test(test_gnss_catalog),
      cmocka_unit_test(test_array_catalog),
      cmocka_unit_test(test_sensor_bounds),
      cmocka_unit_test(test_issue_25_initial_error_bounds),
      cmocka_unit_test(test_catalog_rows_within_bounds),
      cmocka_unit_test(test_trajectory_errors),
      cmocka_unit_test(test_sensor_errors),
      cmocka_unit_test(test_motion_def_errors),
      cmocka_unit_test(test_gyro_free_array),
      cmocka_unit_test(test_scene_library_round_trip),
      cmocka_unit_test(test_round_trip_canonical),
      cmocka_unit_test(test_round_trip_random_bit_exact),
      cmocka_unit_test(test_write_errors),
      cmocka_unit_test(test_numbers_ignore_process_locale),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
