/*
 * Requirements (nav_requirements.h): statistics with known answers on constructed error series
 * (RMS, max, p95, at_time, outage_end, CEP50/CEP95 of a circular Gaussian), order independence,
 * the histogram beyond the exact budget, validation, and the scene-file syntax (errors with
 * FILE:LINE:COL and did-you-mean, exact round trip).
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
#include <unistd.h>

#include "nav_test.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_io.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"

static nav_requirement req(const char *id, nav_req_metric m, nav_req_statistic s, double limit, nav_req_unit u) {
  nav_requirement q;
  memset(&q, 0, sizeof q);
  snprintf(q.id, sizeof q.id, "%s", id);
  q.metric = m;
  q.statistic = s;
  q.limit = limit;
  q.unit = u;
  q.time_s = NAN;
  return q;
}

/* An epoch with horizontal error h along the direction angle a (N = h cos a, E = h sin a). */
static nav_epoch_errors epoch_h(double t, double h, double a) {
  nav_epoch_errors e;
  memset(&e, 0, sizeof e);
  e.t_s = t;
  e.pos_err_n_m = nav_vec3_make(h * cos(a), h * sin(a), 0.0);
  e.pos_err_h_m = h;
  return e;
}

/* Feed one run of epochs. */
static void feed_run(nav_req_evaluator *ev, long run, const nav_epoch_errors *e, size_t n) {
  nav_req_run *r = NULL;
  assert_int_equal(nav_req_run_begin(ev, run, &r), NAV_OK);
  for (size_t i = 0; i < n; ++i) assert_int_equal(nav_req_run_add(r, &e[i]), NAV_OK);
  assert_int_equal(nav_req_run_end(ev, r), NAV_OK);
}

static void test_names_and_units(void **state) {
  (void)state;
  for (int i = 0; i < NAV_REQ_METRIC_COUNT; ++i) {
    nav_req_metric m;
    assert_true(nav_req_metric_from_name(nav_req_metric_name((nav_req_metric)i), &m));
    assert_int_equal((int)m, i);
  }
  for (int i = 0; i < NAV_REQ_STATISTIC_COUNT; ++i) {
    nav_req_statistic s;
    assert_true(nav_req_statistic_from_name(nav_req_statistic_name((nav_req_statistic)i), &s));
    assert_int_equal((int)s, i);
  }
  for (int i = 0; i < NAV_REQ_UNIT_COUNT; ++i) {
    nav_req_unit u;
    assert_true(nav_req_unit_from_name(nav_req_unit_name((nav_req_unit)i), &u));
    assert_int_equal((int)u, i);
  }
  assert_false(nav_req_metric_from_name("horizontal", NULL));
  assert_string_equal(nav_req_unit_name(NAV_REQ_UNIT_MPS), "m/s");
  assert_near(nav_req_unit_to_si(NAV_REQ_UNIT_ARCMIN) * 60.0, nav_req_unit_to_si(NAV_REQ_UNIT_DEG), 1e-18);
  assert_near(nav_req_unit_to_si(NAV_REQ_UNIT_ARCSEC) * 3600.0, NAV_PI / 180.0, 1e-18);
  assert_near(nav_req_unit_to_si(NAV_REQ_UNIT_CM), 0.01, 0.0);

  /* Metrics of one epoch. */
  nav_epoch_errors e;
  memset(&e, 0, sizeof e);
  e.pos_err_n_m = nav_vec3_make(3.0, -4.0, 12.0);
  e.vel_err_n_mps = nav_vec3_make(-2.0, 3.0, 6.0);
  e.euler_err.roll_rad = 0.01;
  e.euler_err.pitch_rad = -0.03;
  e.euler_err.yaw_rad = -0.2;
  assert_near(nav_req_metric_value(NAV_REQ_HORIZONTAL_POSITION, &e), 5.0, 1e-15);
  assert_near(nav_req_metric_value(NAV_REQ_VERTICAL_POSITION, &e), 12.0, 0.0);
  assert_near(nav_req_metric_value(NAV_REQ_POSITION_3D, &e), 13.0, 1e-14);
  assert_near(nav_req_metric_value(NAV_REQ_VELOCITY, &e), 7.0, 1e-15);
  assert_near(nav_req_metric_value(NAV_REQ_ROLL_PITCH, &e), 0.03, 0.0);
  assert_near(nav_req_metric_value(NAV_REQ_YAW, &e), 0.2, 0.0);
}

/* h = 1, 2, ..., 100 m over 4 runs of 25 epochs, fed in two different run orders:
 * rms = sqrt(338350 / 100), max = 100, p95 (nearest rank 95) = 95 m = 9500 cm. */
static void test_rms_max_p95_known(void **state) {
  (void)state;
  nav_requirement q[4] = {
      req("rms", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_RMS, 60.0, NAV_REQ_UNIT_M),
      req("max", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_MAX, 99.0, NAV_REQ_UNIT_M),
      req("p95", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_P95, 9500.0, NAV_REQ_UNIT_CM),
      req("p95km", NAV_REQ_POSITION_3D, NAV_REQ_P95, 0.094, NAV_REQ_UNIT_KM),
  };
  nav_requirement_verdict v[2][4];
  const long order[2][4] = {{0, 1, 2, 3}, {3, 1, 0, 2}};
  for (int o = 0; o < 2; ++o) {
    nav_req_evaluator *ev = NULL;
    assert_int_equal(nav_req_evaluator_create(q, 4, 4, NULL, 0, &ev), NAV_OK);
    assert_int_equal(nav_req_evaluator_count(ev), 4);
    for (int k = 0; k < 4; ++k) {
      const long run = order[o][k];
      nav_epoch_errors e[25];
      /* run r holds h = r + 1, r + 5, ...: every value once over the runs */
      for (int i = 0; i < 25; ++i) e[i] = epoch_h(0.1 * i, (double)(run + 1 + 4 * i), 0.7 * i);
      feed_run(ev, run, e, 25);
    }
    assert_int_equal(nav_req_evaluator_finish(ev, v[o]), NAV_OK);
    nav_req_evaluator_destroy(ev);
  }
  assert_rel_near(v[0][0].value, sqrt(338350.0 / 100.0), 1e-15);
  assert_true(v[0][0].pass); /* 58.17 <= 60 */
  assert_int_equal(v[0][0].samples, 100);
  assert_near(v[0][1].value, 100.0, 1e-13);
  assert_false(v[0][1].pass);
  assert_near(v[0][2].value, 9500.0, 1e-10);
  assert_true(v[0][2].pass); /* equal to the limit passes */
  assert_near(v[0][3].value, 0.095, 1e-15);
  assert_false(v[0][3].pass);
  /* Bit-identical whatever the order of the runs. */
  for (int i = 0; i < 4; ++i) assert_memory_equal(&v[0][i].value, &v[1][i].value, sizeof(double));
  assert_true(nav_req_all_pass(v[0], 1));
  assert_false(nav_req_all_pass(v[0], 4));
}

/* at_time: epochs t = 0..10 s; the nearest epoch to 6.2 s is 6 s, a tie at 2.5 s takes 2 s. */
static void test_at_time_known(void **state) {
  (void)state;
  nav_requirement q[3] = {req("t62", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_AT_TIME, 10.0, NAV_REQ_UNIT_M),
                          req("t25", NAV_REQ_VELOCITY, NAV_REQ_AT_TIME, 1.0, NAV_REQ_UNIT_CMPS),
                          req("t99", NAV_REQ_YAW, NAV_REQ_AT_TIME, 1.0, NAV_REQ_UNIT_DEG)};
  q[0].time_s = 6.2;
  q[1].time_s = 2.5;
  q[2].time_s = 10.4; /* past the last epoch (10 s) by less than half the spacing: that epoch */
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create(q, 3, 2, NULL, 0, &ev), NAV_OK);
  for (long run = 0; run < 2; ++run) {
    nav_epoch_errors e[11];
    for (int i = 0; i <= 10; ++i) {
      /* run 0: h = t, run 1: h = 2 t; velocity (t/100) m/s (run 1 doubled); yaw t mrad */
      e[i] = epoch_h((double)i, (double)(run + 1) * i, 0.3);
      e[i].vel_err_n_mps = nav_vec3_make(0.0, 0.0, (double)(run + 1) * i / 100.0);
      e[i].euler_err.yaw_rad = -(double)i * 1e-3 * (double)(run + 1);
    }
    feed_run(ev, run, e, 11);
  }
  nav_requirement_verdict v[3];
  assert_int_equal(nav_req_evaluator_finish(ev, v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  assert_near(v[0].at_time_s, 6.0, 0.0);
  assert_rel_near(v[0].value, sqrt((36.0 + 144.0) / 2.0), 1e-15);
  assert_true(v[0].pass);
  assert_near(v[1].at_time_s, 2.0, 0.0);
  assert_rel_near(v[1].value, sqrt((4.0 + 16.0) / 2.0), 1e-14); /* cm/s */
  assert_false(v[1].pass);
  assert_near(v[2].at_time_s, 10.0, 0.0);
  assert_rel_near(v[2].value, sqrt((0.01 * 0.01 + 0.02 * 0.02) / 2.0) * 180.0 / NAV_PI, 1e-14);
  assert_true(v[2].pass);
  assert_int_equal(v[2].na_reason, NAV_REQ_NA_NONE);
}

/* Issue 25: an at_time requirement after the end (or before the start) of the run is not
 * evaluated at the nearest epoch: it is "not evaluated", never a pass, with the run's span. */
static void test_issue_25_at_time_outside_run(void **state) {
  (void)state;
  nav_requirement q[3] = {req("late", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_AT_TIME, 1000.0, NAV_REQ_UNIT_KM),
                          req("edge", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_AT_TIME, 1000.0, NAV_REQ_UNIT_KM),
                          req("early", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_AT_TIME, 1000.0, NAV_REQ_UNIT_KM)};
  q[0].time_s = 1e6;  /* the issue's case: 1e6 s on a 10 s run */
  q[1].time_s = 10.6; /* more than half a spacing (0.5 s) after the last epoch */
  q[2].time_s = 0.4;  /* the run starts at 1 s: more than half a spacing before it */
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create(q, 3, 1, NULL, 0, &ev), NAV_OK);
  nav_epoch_errors e[10];
  for (int i = 0; i < 10; ++i) e[i] = epoch_h((double)(i + 1), 0.001, 0.0);
  feed_run(ev, 0, e, 10);
  nav_requirement_verdict v[3];
  assert_int_equal(nav_req_evaluator_finish(ev, v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  for (int i = 0; i < 3; ++i) {
    assert_false(v[i].evaluated);
    assert_false(v[i].pass);
    assert_true(isnan(v[i].value));
    assert_int_equal(v[i].na_reason, NAV_REQ_NA_TIME_OUTSIDE);
    assert_near(v[i].span_t0_s, 1.0, 0.0);
    assert_near(v[i].span_t1_s, 10.0, 0.0);
    assert_near(v[i].at_time_s, q[i].time_s, 0.0);
    assert_false(nav_req_all_pass(&v[i], 1));
  }
  /* The prediction from covariance points applies the same rule. */
  nav_cov_point pts[10];
  memset(pts, 0, sizeof pts);
  for (int i = 0; i < 10; ++i) {
    pts[i].t_s = (double)(i + 1);
    pts[i].pos_sd_n_m = nav_vec3_make(1.0, 1.0, 1.0);
  }
  assert_int_equal(nav_req_predict(q, 3, pts, 10, NULL, 0, v), NAV_OK);
  for (int i = 0; i < 3; ++i) {
    assert_false(v[i].evaluated);
    assert_false(v[i].pass);
    assert_int_equal(v[i].na_reason, NAV_REQ_NA_TIME_OUTSIDE);
  }
}

/* outage_end: outages [2, 5) and [7, 9.5) on epochs t = 0..10 s: last epochs 4 s and 9 s; an
 * outage between epochs is reported without a value. */
static void test_outage_end_known(void **state) {
  (void)state;
  nav_requirement q = req("h-end", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_OUTAGE_END, 12.0, NAV_REQ_UNIT_M);
  const nav_req_interval out[3] = {{2.0, 5.0}, {7.0, 9.5}, {10.2, 10.6}};
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create(&q, 1, 2, out, 3, &ev), NAV_OK);
  for (long run = 1; run >= 0; --run) {
    nav_epoch_errors e[11];
    for (int i = 0; i <= 10; ++i) e[i] = epoch_h((double)i, (double)(run + 1) * i, 1.0);
    feed_run(ev, run, e, 11);
  }
  nav_requirement_verdict v;
  assert_int_equal(nav_req_evaluator_finish(ev, &v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  assert_int_equal(v.outage_count, 3);
  assert_near(v.outage_end_t_s[0], 4.0, 0.0);
  assert_near(v.outage_end_t_s[1], 9.0, 0.0);
  assert_rel_near(v.outage_value[0], sqrt((16.0 + 64.0) / 2.0), 1e-15);
  assert_rel_near(v.outage_value[1], sqrt((81.0 + 324.0) / 2.0), 1e-15);
  assert_true(isnan(v.outage_value[2]));
  assert_rel_near(v.value, sqrt(202.5), 1e-15);
  assert_false(v.pass); /* 14.2 > 12 */
  assert_true(v.evaluated);

  /* No outage at all: not evaluated, and not a pass either (issue 25: nothing pretended). */
  assert_int_equal(nav_req_evaluator_create(&q, 1, 1, NULL, 0, &ev), NAV_OK);
  nav_epoch_errors e = epoch_h(0.0, 1.0, 0.0);
  feed_run(ev, 0, &e, 1);
  assert_int_equal(nav_req_evaluator_finish(ev, &v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  assert_false(v.evaluated);
  assert_false(v.pass);
  assert_int_equal(v.na_reason, NAV_REQ_NA_NO_OUTAGE);
  assert_true(isnan(v.value));
  /* Outages without an epoch inside: not evaluated, fails. */
  const nav_req_interval late = {20.0, 30.0};
  assert_int_equal(nav_req_evaluator_create(&q, 1, 1, &late, 1, &ev), NAV_OK);
  feed_run(ev, 0, &e, 1);
  assert_int_equal(nav_req_evaluator_finish(ev, &v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  assert_false(v.evaluated);
  assert_false(v.pass);
  /* Any other statistic without data fails. */
  nav_requirement q2 = req("rms", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_RMS, 12.0, NAV_REQ_UNIT_M);
  assert_int_equal(nav_req_evaluator_create(&q2, 1, 1, NULL, 0, &ev), NAV_OK);
  assert_int_equal(nav_req_evaluator_finish(ev, &v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  assert_false(v.evaluated);
  assert_false(v.pass);
}

/* CEP of a circular Gaussian (sigma per axis): CEP50 = sigma sqrt(2 ln 2) = 1.1774 sigma,
 * CEP95 = sigma sqrt(2 ln 20) = 2.4477 sigma. Deterministic points: radii at the Rayleigh
 * quantiles (i - 1/2) / N, golden-angle directions, spread over 8 runs fed out of order. */
static void test_cep_circular_gaussian(void **state) {
  (void)state;
  const double sigma = 3.0;
  const int N = 40000, runs = 8, per = N / runs;
  nav_requirement q[3] = {req("cep50", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP50, 3.6, NAV_REQ_UNIT_M),
                          req("cep95", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP95, 7.0, NAV_REQ_UNIT_M),
                          req("rms", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_RMS, 1.0, NAV_REQ_UNIT_M)};
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create(q, 3, runs, NULL, 0, &ev), NAV_OK);
  nav_epoch_errors *e = malloc((size_t)per * sizeof *e);
  assert_non_null(e);
  const long order[8] = {5, 0, 7, 2, 1, 6, 3, 4};
  for (int k = 0; k < runs; ++k) {
    const long run = order[k];
    for (int j = 0; j < per; ++j) {
      const int i = (int)run + runs * j; /* 0..N-1 */
      const double p = (i + 0.5) / N;
      const double r = sigma * sqrt(-2.0 * log1p(-p));
      e[j] = epoch_h(0.01 * j, r, 2.399963229728653 * i);
    }
    feed_run(ev, run, e, (size_t)per);
  }
  free(e);
  nav_requirement_verdict v[3];
  assert_int_equal(nav_req_evaluator_finish(ev, v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  /* nearest rank k = N/2 and 0.95 N: the point with p = (k - 1/2) / N */
  const double k50 = N / 2, k95 = 0.95 * N;
  assert_rel_near(v[0].value, sigma * sqrt(-2.0 * log1p(-(k50 - 0.5) / N)), 1e-12);
  assert_rel_near(v[1].value, sigma * sqrt(-2.0 * log1p(-(k95 - 0.5) / N)), 1e-12);
  assert_rel_near(v[0].value, 1.1774 * sigma, 1e-4);
  assert_rel_near(v[1].value, 2.4477 * sigma, 1e-4);
  assert_true(v[0].pass);  /* 3.532 <= 3.6 */
  assert_false(v[1].pass); /* 7.343 > 7 */
  /* and the RMS radius of the sample is sigma sqrt 2 (to the quantile-grid discretisation) */
  assert_rel_near(v[2].value, sigma * sqrt(2.0), 2e-3);
}

/* Beyond the exact budget the quantile comes from the log histogram: relative error below half
 * a bin width. h_i = (i + 1) mm, i < 4.5e6 in 5 runs: p95 (nearest rank) = 4275 m exactly. */
static void test_quantile_histogram_beyond_budget(void **state) {
  (void)state;
  const long n = 4500000, runs = 5, per = n / runs;
  assert_true(n > NAV_REQ_EXACT_BUDGET);
  nav_requirement q = req("p95", NAV_REQ_VERTICAL_POSITION, NAV_REQ_P95, 5000.0, NAV_REQ_UNIT_M);
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create(&q, 1, runs, NULL, 0, &ev), NAV_OK);
  for (long run = 0; run < runs; ++run) {
    nav_req_run *r = NULL;
    assert_int_equal(nav_req_run_begin(ev, run, &r), NAV_OK);
    nav_epoch_errors e;
    memset(&e, 0, sizeof e);
    for (long j = 0; j < per; ++j) {
      e.t_s = (double)j;
      e.pos_err_n_m.z = -1e-3 * (double)(run * per + j + 1);
      assert_int_equal(nav_req_run_add(r, &e), NAV_OK);
    }
    assert_int_equal(nav_req_run_end(ev, r), NAV_OK);
  }
  nav_requirement_verdict v;
  assert_int_equal(nav_req_evaluator_finish(ev, &v), NAV_OK);
  nav_req_evaluator_destroy(ev);
  const double exact = 1e-3 * (double)((n * 95 + 99) / 100);
  assert_rel_near(v.value, exact, 0.5 * NAV_REQ_HIST_REL_WIDTH);
  assert_true(v.pass);
  assert_int_equal(v.samples, n);
}

typedef struct issues {
  int n;
  char text[16][200];
} issues;

static void collect(void *user, const char *path, const char *message) {
  issues *is = user;
  if (is->n < 16) snprintf(is->text[is->n], sizeof is->text[0], "%s: %s", path, message);
  is->n++;
}

static bool has_issue(const issues *is, const char *prefix) {
  for (int i = 0; i < is->n && i < 16; ++i)
    if (strncmp(is->text[i], prefix, strlen(prefix)) == 0) return true;
  return false;
}

static void test_validate(void **state) {
  (void)state;
  nav_requirement q[6] = {
      req("ok.1_a-b", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP95, 5.0, NAV_REQ_UNIT_M),
      req("ok.1_a-b", NAV_REQ_YAW, NAV_REQ_RMS, 1.0, NAV_REQ_UNIT_DEG),   /* duplicate id */
      req("v", NAV_REQ_VELOCITY, NAV_REQ_MAX, 1.0, NAV_REQ_UNIT_M),        /* wrong unit */
      req("cep", NAV_REQ_VERTICAL_POSITION, NAV_REQ_CEP50, 1.0, NAV_REQ_UNIT_M), /* cep not horizontal */
      req("t", NAV_REQ_ROLL_PITCH, NAV_REQ_AT_TIME, 0.0, NAV_REQ_UNIT_ARCMIN),   /* no time_s, limit 0 */
      req("a b", NAV_REQ_ROLL_PITCH, NAV_REQ_RMS, 1.0, NAV_REQ_UNIT_MRAD),       /* bad id */
  };
  issues is = {0};
  assert_int_equal(nav_requirements_validate(q, 1, collect, &is), NAV_OK);
  assert_int_equal(is.n, 0);
  assert_int_equal(nav_requirements_validate(q, 6, collect, &is), NAV_ERR_INVALID_ARG);
  assert_true(has_issue(&is, "requirements[1].id: "));
  assert_true(has_issue(&is, "requirements[2].unit: m is not a unit of velocity"));
  assert_true(has_issue(&is, "requirements[3].statistic: cep50 applies to metric horizontal_position"));
  assert_true(has_issue(&is, "requirements[4].time_s: "));
  assert_true(has_issue(&is, "requirements[4].limit: "));
  assert_true(has_issue(&is, "requirements[5].id: "));
  assert_int_equal(is.n, 6);
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create(q, 6, 1, NULL, 0, &ev), NAV_ERR_INVALID_ARG);
  assert_null(ev);
}

/* ---------------------------------------------------------------- scene files */

typedef struct diags {
  int n;
  char text[16][600];
} diags;

static void on_diag(void *user, const nav_diag *d) {
  diags *ds = user;
  if (ds->n < 16) nav_diag_format(d, ds->text[ds->n], sizeof ds->text[0]);
  ds->n++;
}

static const char *find_diag(const diags *ds, const char *needle) {
  for (int i = 0; i < ds->n && i < 16; ++i)
    if (strstr(ds->text[i], needle)) return ds->text[i];
  return NULL;
}

/* Issue 25: navsim check refuses requirements the scene's run cannot evaluate, at their place in
 * the file: an at_time after the end, an outage_end without an outage (none given, none within
 * the run, or no GNSS at all). A scene without a trajectory (the filter configuration of navsim
 * replay) is not checked: its requirements apply to recorded data. */
/* Read @p text as the file DIR/@p name through nav_scene_read_file_to_run (as navsim check,
 * run and estimate do); the diagnostics name the file by its path. */
static nav_status read_to_run(const char *dir, const char *name, const char *text, nav_scene *s, diags *ds) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(text, f);
  assert_int_equal(fclose(f), 0);
  ds->n = 0;
  const nav_status st = nav_scene_read_file_to_run(path, s, on_diag, ds);
  remove(path);
  return st;
}

static void test_issue_25_scene_requirements_evaluable(void **state) {
  (void)state;
  static const char bad[] = "format_version: 1\n"
                            "earth: {model: wgs84}\n"
                            "trajectory: {type: parametric, duration_s: 39.8}\n"
                            "gnss: {enabled: true, outages: [[50, 60]]}\n"
                            "navigation: {scheme: ins_gnss}\n"
                            "requirements:\n"
                            "  - {id: late, metric: horizontal_position, statistic: at_time, time_s: 1e6, limit: 1, unit: m}\n"
                            "  - {id: end, metric: horizontal_position, statistic: at_time, time_s: 39.8, limit: 1, unit: m}\n"
                            "  - {id: out, metric: horizontal_position, statistic: outage_end, limit: 1, unit: m}\n";
  char dir[] = "/tmp/nav_req_run_XXXXXX";
  assert_non_null(mkdtemp(dir));
  nav_scene *s = malloc(sizeof *s);
  assert_non_null(s);
  diags ds = {0};
  /* The library reader accepts it (a scene may be edited before it is run)... */
  assert_int_equal(nav_scene_read_string(bad, strlen(bad), "req.yaml", s, on_diag, &ds), NAV_OK);
  /* ...the reader of a scene to run does not. */
  assert_int_equal(read_to_run(dir, "req.yaml", bad, s, &ds), NAV_ERR_PARSE);
  assert_int_equal(ds.n, 2);
  const char *m = find_diag(&ds, "requirements[0].time_s");
  assert_non_null(m);
  assert_non_null(strstr(m, "req.yaml:7:73: error: requirements[0].time_s: 1e+06 s is after the end of the run"));
  assert_null(find_diag(&ds, "requirements[1]"));
  m = find_diag(&ds, "requirements[2].statistic");
  assert_non_null(m);
  assert_non_null(strstr(m, "req.yaml:9:"));
  assert_non_null(strstr(m, "every outage starts after its end"));

  static const char none[] = "format_version: 1\n"
                             "trajectory: {type: parametric, duration_s: 20}\n"
                             "requirements:\n"
                             "  - {id: out, metric: horizontal_position, statistic: outage_end, limit: 1, unit: m}\n";
  assert_int_equal(read_to_run(dir, "none.yaml", none, s, &ds), NAV_ERR_PARSE);
  m = find_diag(&ds, "requirements[0].statistic");
  assert_non_null(m);
  assert_non_null(strstr(m, "outage_end needs a GNSS outage"));

  /* Without a trajectory: accepted (navsim replay --scene). */
  static const char replay_cfg[] = "format_version: 1\n"
                                   "requirements:\n"
                                   "  - {id: out, metric: horizontal_position, statistic: outage_end, limit: 1, unit: m}\n"
                                   "  - {id: late, metric: yaw, statistic: at_time, time_s: 500, limit: 1, unit: deg}\n";
  assert_int_equal(read_to_run(dir, "cfg.yaml", replay_cfg, s, &ds), NAV_OK);
  free(s);
  assert_int_equal(rmdir(dir), 0);
}

static void test_scene_errors(void **state) {
  (void)state;
  static const char text[] = "format_version: 1\n"
                             "requirements:\n"
                             "  - {id: a, metric: horizontal_position, statistic: rms, limit: 1, unit: m}\n"
                             "  - {id: b, metric: yaw, statistic: max, limit: 1, unit: arcmin}\n"
                             "  - {id: c, metric: horizontal_positon, statistic: p96, limit: 1, unit: mps}\n"
                             "  - {id: d, metric: velocity, statistic: rms, limit: 0.5, unit: m/s, time_s: 3}\n"
                             "  - {id: e, metric: velocity, statistic: at_time, limit: 1, unit: m/s}\n"
                             "  - {id: a, metric: velocity, statistic: rms, unit: m/s}\n";
  nav_scene s;
  diags ds = {0};
  assert_int_equal(nav_scene_read_string(text, strlen(text), "req.yaml", &s, on_diag, &ds), NAV_ERR_PARSE);
  const char *m = find_diag(&ds, "requirements[2].metric");
  assert_non_null(m);
  assert_non_null(strstr(m, "req.yaml:5:21: error: requirements[2].metric: expected one of"));
  assert_non_null(strstr(m, "did you mean \"horizontal_position\""));
  m = find_diag(&ds, "requirements[2].statistic");
  assert_non_null(m);
  assert_non_null(strstr(m, "did you mean \"p95\""));
  m = find_diag(&ds, "requirements[2].unit");
  assert_non_null(m);
  assert_non_null(strstr(m, "did you mean \"m/s\""));
  m = find_diag(&ds, "requirements[3].time_s");
  assert_non_null(m);
  assert_non_null(strstr(m, "req.yaml:6:"));
  assert_non_null(strstr(m, "at_time only"));
  m = find_diag(&ds, "requirements[5].limit");
  assert_non_null(m);
  assert_non_null(strstr(m, "missing required key"));

  /* Errors found by nav_scene_validate are placed at the field too. */
  static const char text2[] = "format_version: 1\n"
                              "requirements:\n"
                              "  - id: a\n"
                              "    metric: yaw\n"
                              "    statistic: at_time\n"
                              "    limit: 1\n"
                              "    unit: m\n"
                              "  - {id: a, metric: vertical_position, statistic: cep95, limit: 1, unit: m}\n";
  memset(&ds, 0, sizeof ds);
  assert_int_equal(nav_scene_read_string(text2, strlen(text2), "r2.yaml", &s, on_diag, &ds), NAV_ERR_PARSE);
  m = find_diag(&ds, "requirements[0].unit");
  assert_non_null(m);
  assert_non_null(strstr(m, "r2.yaml:7:11: error: requirements[0].unit: m is not a unit of yaw"));
  assert_non_null(find_diag(&ds, "requirements[0].time_s: statistic at_time needs time_s"));
  assert_non_null(find_diag(&ds, "requirements[1].id: \"a\" is already the id of requirements[0]"));
  assert_non_null(find_diag(&ds, "requirements[1].statistic: cep95 applies to metric horizontal_position only"));
}

static char *read_all(const char *path) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  static char buf[1 << 20];
  const size_t n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = '\0';
  fclose(f);
  char *copy = malloc(n + 1);
  if (copy) memcpy(copy, buf, n + 1);
  return copy;
}

static void test_scene_round_trip(void **state) {
  (void)state;
  static const char text[] = "format_version: 1\n"
                             "requirements:\n"
                             "  - id: h-outage-end\n"
                             "    metric: horizontal_position\n"
                             "    statistic: outage_end\n"
                             "    limit: 5.0\n"
                             "    unit: m\n"
                             "  - {id: yaw.300, metric: yaw, statistic: at_time, time_s: 300.1, limit: 0.1, unit: deg}\n"
                             "  - {id: cep_95, metric: horizontal_position, statistic: cep95, limit: 0.3, unit: cm}\n"
                             "  - {id: v, metric: velocity, statistic: p95, limit: 1e-3, unit: cm/s}\n"
                             "  - {id: rp, metric: roll_pitch, statistic: max, limit: 0.7, unit: arcsec}\n"
                             "  - {id: t0, metric: position_3d, statistic: at_time, time_s: 0, limit: 2, unit: km}\n";
  nav_scene a, b;
  diags ds = {0};
  assert_int_equal(nav_scene_read_string(text, strlen(text), "rt.yaml", &a, on_diag, &ds), NAV_OK);
  assert_int_equal(a.n_requirements, 6);
  assert_string_equal(a.requirements[1].id, "yaw.300");
  assert_int_equal(a.requirements[1].statistic, NAV_REQ_AT_TIME);
  assert_near(a.requirements[1].time_s, 300.1, 0.0);
  assert_int_equal(a.requirements[3].unit, NAV_REQ_UNIT_CMPS);
  assert_near(a.requirements[3].limit, 1e-3, 0.0);
  assert_true(isnan(a.requirements[0].time_s));
  char dir[] = "/tmp/nav_req_rt_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char p1[256], p2[256];
  snprintf(p1, sizeof p1, "%s/a.yaml", dir);
  snprintf(p2, sizeof p2, "%s/b.yaml", dir);
  assert_int_equal(nav_scene_write_file(p1, &a), NAV_OK);
  const nav_status rst = nav_scene_read_file(p1, &b, on_diag, &ds);
  for (int i = 0; i < ds.n && i < 16; ++i) print_message("%s\n", ds.text[i]);
  assert_int_equal(rst, NAV_OK);
  assert_int_equal(ds.n, 0);
  assert_int_equal(b.n_requirements, a.n_requirements);
  for (int i = 0; i < a.n_requirements; ++i) {
    assert_string_equal(a.requirements[i].id, b.requirements[i].id);
    assert_int_equal(a.requirements[i].metric, b.requirements[i].metric);
    assert_int_equal(a.requirements[i].statistic, b.requirements[i].statistic);
    assert_int_equal(a.requirements[i].unit, b.requirements[i].unit);
    assert_memory_equal(&a.requirements[i].limit, &b.requirements[i].limit, sizeof(double));
    assert_memory_equal(&a.requirements[i].time_s, &b.requirements[i].time_s, sizeof(double));
  }
  assert_int_equal(nav_scene_write_file(p2, &b), NAV_OK);
  char *t1 = read_all(p1), *t2 = read_all(p2);
  assert_non_null(t1);
  assert_non_null(t2);
  assert_string_equal(t1, t2);
  assert_non_null(strstr(t1, "requirements:\n  - {id: \"h-outage-end\", metric: horizontal_position"));
  free(t1);
  free(t2);
  unlink(p1);
  unlink(p2);
  rmdir(dir);

  /* A scene without requirements writes none. */
  nav_scene d = nav_scene_default();
  assert_int_equal(d.n_requirements, 0);
}


/* Prediction from sigmas: a circular Gaussian (sigma per axis) at every epoch gives CEP50 =
 * sigma sqrt(2 ln 2), CEP95 = sigma sqrt(2 ln 20), horizontal RMS = sigma sqrt 2; the vertical
 * p95 of N(0, sD^2) is 1.959964 sD; a degenerate ellipse (sE = 0) gives the 1-D quantile. */
static void test_predict_known(void **state) {
  (void)state;
  const double sigma = 2.0, sd = 3.0;
  nav_cov_point pts[50];
  memset(pts, 0, sizeof pts);
  for (int i = 0; i < 50; ++i) {
    pts[i].t_s = i;
    pts[i].pos_sd_n_m = nav_vec3_make(sigma, sigma, sd);
    pts[i].pos_h_sd_m = sigma * sqrt(2.0);
    pts[i].att_sd_rad = nav_vec3_make(0.0, 0.0, 1e-3 * (i < 25 ? 1.0 : 2.0));
  }
  nav_requirement q[7] = {req("c50", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP50, 5.0, NAV_REQ_UNIT_M),
                          req("c95", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP95, 5.0, NAV_REQ_UNIT_M),
                          req("rms", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_RMS, 5.0, NAV_REQ_UNIT_M),
                          req("v95", NAV_REQ_VERTICAL_POSITION, NAV_REQ_P95, 5.0, NAV_REQ_UNIT_M),
                          req("max", NAV_REQ_VERTICAL_POSITION, NAV_REQ_MAX, 5.0, NAV_REQ_UNIT_M),
                          req("end", NAV_REQ_YAW, NAV_REQ_OUTAGE_END, 0.1, NAV_REQ_UNIT_DEG),
                          req("yaw", NAV_REQ_YAW, NAV_REQ_RMS, 1.0, NAV_REQ_UNIT_MRAD)};
  const nav_req_interval out[2] = {{10.0, 20.0}, {30.5, 40.0}};
  nav_requirement_verdict v[7];
  assert_int_equal(nav_req_predict(q, 7, pts, 50, out, 2, v), NAV_OK);
  assert_rel_near(v[0].value, sigma * sqrt(2.0 * log(2.0)), 1e-7);
  assert_true(v[0].pass);
  assert_rel_near(v[1].value, sigma * sqrt(2.0 * log(20.0)), 1e-7);
  assert_true(v[1].pass); /* 4.895 <= 5 */
  assert_rel_near(v[2].value, sigma * sqrt(2.0), 1e-15);
  assert_rel_near(v[3].value, 1.959963984540054 * sd, 1e-7);
  assert_false(v[3].pass);
  assert_false(v[4].evaluated);
  assert_false(v[4].pass);
  assert_near(v[5].outage_end_t_s[0], 19.0, 0.0);
  assert_near(v[5].outage_end_t_s[1], 39.0, 0.0);
  assert_rel_near(v[5].outage_value[0], 1e-3 * 180.0 / NAV_PI, 1e-14);
  assert_rel_near(v[5].value, 2e-3 * 180.0 / NAV_PI, 1e-14);
  assert_rel_near(v[6].value, sqrt(2.5), 1e-14); /* mrad */
  /* Degenerate ellipse: the horizontal radius is |N(0, sigma^2)|. */
  for (int i = 0; i < 50; ++i) pts[i].pos_sd_n_m.y = 0.0;
  assert_int_equal(nav_req_predict(q, 2, pts, 50, NULL, 0, v), NAV_OK);
  assert_rel_near(v[1].value, 1.959963984540054 * sigma, 1e-7);
  /* Slightly elliptical: between the 1-D and the circular answers, and continuous. */
  for (int i = 0; i < 50; ++i) pts[i].pos_sd_n_m.y = 0.5 * sigma;
  assert_int_equal(nav_req_predict(q, 2, pts, 50, NULL, 0, v), NAV_OK);
  assert_true(v[1].value > 1.959963984540054 * sigma && v[1].value < sigma * sqrt(2.0 * log(20.0)));
}

typedef struct pts_buf {
  nav_cov_point p[4096];
  size_t n;
} pts_buf;

static nav_callback_result keep_pt(void *user, const nav_cov_point *p) {
  pts_buf *b = user;
  if (b->n == sizeof b->p / sizeof b->p[0]) return NAV_STOP;
  b->p[b->n++] = *p;
  return NAV_CONTINUE;
}

/* nav_req_predict_scene_points with the points of nav_sim_covariance gives the verdicts of
 * nav_req_predict_scene bit for bit (navsim estimate passes the points of its own analysis). */
static void test_predict_scene_points(void **state) {
  (void)state;
  nav_scene *sc = malloc(sizeof *sc);
  pts_buf *b = calloc(1, sizeof *b);
  assert_non_null(sc);
  assert_non_null(b);
  assert_int_equal(nav_scene_read_file(NAV_SOURCE_DIR "/scenes/gyro-free-gnss-car.yaml", sc, NULL, NULL), NAV_OK);
  assert_true(nav_req_predict_scene_uses_sim_covariance(sc));
  assert_true(sc->n_requirements >= 2 && sc->n_requirements <= 8);
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  assert_int_equal(nav_sim_covariance(sim, keep_pt, b), NAV_OK);
  nav_sim_destroy(sim);
  assert_true(b->n > 100 && b->n < sizeof b->p / sizeof b->p[0]);
  nav_requirement_verdict a[8], c[8];
  assert_int_equal(nav_req_predict_scene(sc, a), NAV_OK);
  assert_int_equal(nav_req_predict_scene_points(sc, b->p, b->n, c), NAV_OK);
  assert_memory_equal(a, c, (size_t)sc->n_requirements * sizeof a[0]);
  int quantiles = 0;
  for (int i = 0; i < sc->n_requirements; ++i)
    if (a[i].statistic == NAV_REQ_CEP95) {
      ++quantiles;
      assert_true(a[i].evaluated && isfinite(a[i].value) && a[i].value > 0.0);
    }
  assert_int_equal(quantiles, 1);
  /* A scheme whose prediction is not nav_sim_covariance's (ins_gnss: the budget's total filter). */
  sc->navigation.scheme = NAV_SCHEME_INS_GNSS;
  assert_false(nav_req_predict_scene_uses_sim_covariance(sc));
  assert_int_equal(nav_req_predict_scene_points(sc, b->p, b->n, c), NAV_ERR_INVALID_ARG);
  assert_false(nav_req_predict_scene_uses_sim_covariance(NULL));
  free(b);
  free(sc);
}

/* nav_req_predict_threads: the quantile statistics bit-identical for 1, 2, 3 and 7 threads, on
 * 1000 epochs whose sigmas vary (circular, elliptical, degenerate; a jump half-way), and with a
 * few epochs (no helpers); the values equal nav_req_predict's. */
static void test_predict_threads(void **state) {
  (void)state;
  enum { N = 1000 };
  nav_cov_point *pts = calloc(N, sizeof *pts);
  assert_non_null(pts);
  for (int i = 0; i < N; ++i) {
    const double g = 1.0 + 0.5 * sin(0.01 * i) + (i >= N / 2 ? 3.0 : 0.0);
    pts[i].t_s = 0.1 * i;
    pts[i].pos_sd_n_m = nav_vec3_make(g, i % 97 == 0 ? 0.0 : g * (0.3 + 0.7 * (i % 7) / 6.0), 2.0 * g);
    pts[i].pos_h_sd_m = hypot(pts[i].pos_sd_n_m.x, pts[i].pos_sd_n_m.y);
    pts[i].att_sd_rad = nav_vec3_make(0.0, 0.0, 1e-3 * g);
  }
  nav_requirement q[4] = {req("c50", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP50, 5.0, NAV_REQ_UNIT_M),
                          req("c95", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP95, 5.0, NAV_REQ_UNIT_M),
                          req("v95", NAV_REQ_VERTICAL_POSITION, NAV_REQ_P95, 5.0, NAV_REQ_UNIT_M),
                          req("y95", NAV_REQ_YAW, NAV_REQ_P95, 1.0, NAV_REQ_UNIT_MRAD)};
  const size_t counts[2] = {N, 40};
  for (int c = 0; c < 2; ++c) {
    nav_requirement_verdict one[4], many[4];
    assert_int_equal(nav_req_predict(q, 4, pts, counts[c], NULL, 0, one), NAV_OK);
    for (int k = 0; k < 4; ++k) assert_true(one[k].evaluated && one[k].value > 0.0);
    const int threads[4] = {1, 2, 3, 7};
    for (int t = 0; t < 4; ++t) {
      memset(many, 0x5a, sizeof many);
      assert_int_equal(nav_req_predict_threads(q, 4, pts, counts[c], NULL, 0, threads[t], many), NAV_OK);
      for (int k = 0; k < 4; ++k) {
        assert_memory_equal(&one[k].value, &many[k].value, sizeof one[k].value);
        assert_int_equal(one[k].pass, many[k].pass);
        assert_int_equal(one[k].samples, many[k].samples);
      }
    }
  }
  free(pts);
}



/* ---- cep of covariance points against independent references (docs/estimate-cep.md) ---- */

/* A covariance point with horizontal sigmas (a north, b east). */
static nav_cov_point cep_point(double a, double b) {
  nav_cov_point p;
  memset(&p, 0, sizeof p);
  p.pos_sd_n_m = nav_vec3_make(a, b, 1.0);
  p.pos_h_sd_m = hypot(a, b);
  p.att_sd_rad = nav_vec3_make(0.0, 0.0, 1e-3);
  return p;
}

/* The predicted cep50 (k = 0) and cep95 (k = 1) of @p n points, with @p threads threads. */
static void predict_ceps(const nav_cov_point *pts, size_t n, int threads, double out[2]) {
  nav_requirement q[2] = {req("c50", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP50, 5.0, NAV_REQ_UNIT_M),
                          req("c95", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_CEP95, 5.0, NAV_REQ_UNIT_M)};
  nav_requirement_verdict v[2];
  assert_int_equal(nav_req_predict_threads(q, 2, pts, n, NULL, 0, threads, v), NAV_OK);
  for (int k = 0; k < 2; ++k) {
    assert_true(v[k].evaluated);
    out[k] = v[k].value;
  }
}

/* Reference P(hypot(x, y) <= r), x ~ N(0, a^2), y ~ N(0, b^2), a >= b: x = r sin u,
 * P = int_{-pi/2}^{pi/2} phi(r sin u / a) / a erf(r cos u / (sqrt 2 b)) r cos u du, composite
 * Simpson on m intervals (a formula independent of the library's polar trapezoid). */
static double ref_cdf_radius(double r, double a, double b, int m) {
  const double h = NAV_PI / m;
  double sum = 0.0;
  for (int i = 0; i <= m; ++i) {
    const double u = -0.5 * NAV_PI + h * i, x = r * sin(u), c = r * cos(u);
    const double f = exp(-0.5 * (x / a) * (x / a)) / (a * sqrt(2.0 * NAV_PI)) * erf(c / (sqrt(2.0) * b)) * c;
    sum += f * ((i == 0 || i == m) ? 1.0 : (i % 2 ? 4.0 : 2.0));
  }
  return sum * h / 3.0;
}

/* Smallest r with the mean of the reference CDFs >= q, by bisection to the last bits. */
static double ref_quantile(const double *a, const double *b, int n, double q, int m) {
  double lo = 0.0, hi = 0.0;
  for (int i = 0; i < n; ++i) hi = fmax(hi, 10.0 * a[i]);
  for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    double s = 0.0;
    for (int i = 0; i < n; ++i) s += ref_cdf_radius(mid, a[i], b[i], m);
    if (s / n >= q) hi = mid;
    else lo = mid;
  }
  return hi;
}

/* Circular points: cep = a sqrt(-2 ln(1 - q)) exactly (Rayleigh). */
static void test_cep_predict_circular(void **state) {
  (void)state;
  const double sig[3] = {1e-3, 1.0, 250.0};
  for (int i = 0; i < 3; ++i) {
    const nav_cov_point p = cep_point(sig[i], sig[i]);
    double c[2];
    predict_ceps(&p, 1, 1, c);
    assert_true(fabs(c[0] / (sig[i] * sqrt(2.0 * log(2.0))) - 1.0) < 1e-13);
    assert_true(fabs(c[1] / (sig[i] * sqrt(-2.0 * log(0.05))) - 1.0) < 1e-13);
  }
}

/* Nearly 1-D points (b = 1e-7 a, the polar sum with thousands of nodes): cep = the quantile of
 * |N(0, a^2)| (the y part moves it by ~(b / r)^2 = 1e-14 relative), found by bisection on erf. */
static void test_cep_predict_one_dimensional_limit(void **state) {
  (void)state;
  const double a = 3.0, qs[2] = {0.5, 0.95};
  const nav_cov_point p = cep_point(a, 1e-7 * a), p_swapped = cep_point(1e-7 * a, a);
  double c[2], cs[2];
  predict_ceps(&p, 1, 1, c);
  predict_ceps(&p_swapped, 1, 1, cs);
  for (int k = 0; k < 2; ++k) {
    double lo = 0.0, hi = 10.0 * a;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (erf(mid / (sqrt(2.0) * a)) >= qs[k]) hi = mid;
      else lo = mid;
    }
    assert_true(fabs(c[k] / hi - 1.0) < 1e-12);
    assert_true(fabs(cs[k] / hi - 1.0) < 1e-12);
  }
}

/* Eccentric single points (a / b = 1.5 .. 1000) and a mixture of them against the bisection on
 * the reference CDF with 40 000 Simpson intervals. */
static void test_cep_predict_eccentric_reference(void **state) {
  (void)state;
  const double a[5] = {2.0, 1.0, 0.5, 4.0, 1.0}, b[5] = {2.0 / 1.5, 0.1, 0.005, 0.004, 0.7};
  const double qs[2] = {0.5, 0.95};
  nav_cov_point pts[5];
  for (int i = 0; i < 5; ++i) {
    pts[i] = cep_point(a[i], b[i]);
    double c[2];
    predict_ceps(&pts[i], 1, 1, c);
    for (int k = 0; k < 2; ++k) {
      const double ref = ref_quantile(&a[i], &b[i], 1, qs[k], 40000);
      assert_true(fabs(c[k] / ref - 1.0) < 1e-11);
    }
  }
  double c[2];
  predict_ceps(pts, 5, 1, c);
  for (int k = 0; k < 2; ++k) {
    const double ref = ref_quantile(a, b, 5, qs[k], 40000);
    assert_true(fabs(c[k] / ref - 1.0) < 1e-11);
  }
}

/* 1 and 3 threads give the same cep bits on 600 points of varied eccentricity. */
static void test_cep_predict_threads_identical(void **state) {
  (void)state;
  enum { N = 600 };
  nav_cov_point *pts = calloc(N, sizeof *pts);
  assert_non_null(pts);
  for (int i = 0; i < N; ++i) {
    const double a = 1.0 + 0.8 * sin(0.05 * i);
    pts[i] = cep_point(a, a * pow(10.0, -(i % 5)));
  }
  double one[2], three[2];
  predict_ceps(pts, N, 1, one);
  predict_ceps(pts, N, 3, three);
  assert_memory_equal(one, three, sizeof one);
  free(pts);
}

/* The outages of a scene as the simulation applies them: gnss.outages plus the segments with
 * gnss_visible: false (merged when they touch). */
static void test_scene_outages(void **state) {
  (void)state;
  static const char text[] = "format_version: 1\n"
                             "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 0}}\n"
                             "trajectory:\n"
                             "  type: segments\n"
                             "  segments:\n"
                             "    v0_b_mps: [5, 0, 0]\n"
                             "    items:\n"
                             "      - {kind: hold, duration_s: 10}\n"
                             "      - {kind: hold, duration_s: 5, gnss_visible: false}\n"
                             "      - {kind: hold, duration_s: 3, gnss_visible: false}\n"
                             "      - {kind: hold, duration_s: 12}\n"
                             "gnss: {enabled: true, outages: [[25, 27]]}\n"
                             "navigation: {scheme: ins_gnss}\n"
                             "requirements:\n"
                             "  - {id: e, metric: horizontal_position, statistic: outage_end, limit: 1, unit: m}\n";
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  diags ds = {0};
  assert_int_equal(nav_scene_read_string(text, strlen(text), "o.yaml", sc, on_diag, &ds), NAV_OK);
  nav_req_interval iv[8];
  int n = 0;
  assert_int_equal(nav_req_scene_outages(sc, iv, 8, &n), NAV_OK);
  assert_int_equal(n, 2);
  double t0[2] = {iv[0].t0_s, iv[1].t0_s}, t1[2] = {iv[0].t1_s, iv[1].t1_s};
  const int a = t0[0] < t0[1] ? 0 : 1, b = 1 - a;
  assert_near(t0[a], 10.0, 1e-9);
  assert_near(t1[a], 18.0, 1e-9);
  assert_near(t0[b], 25.0, 0.0);
  assert_near(t1[b], 27.0, 0.0);
  nav_req_evaluator *ev = NULL;
  assert_int_equal(nav_req_evaluator_create_for_scene(sc, false, &ev), NAV_OK);
  nav_req_evaluator_destroy(ev);
  free(sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_names_and_units),
      cmocka_unit_test(test_rms_max_p95_known),
      cmocka_unit_test(test_at_time_known),
      cmocka_unit_test(test_issue_25_at_time_outside_run),
      cmocka_unit_test(test_issue_25_scene_requirements_evaluable),
      cmocka_unit_test(test_outage_end_known),
      cmocka_unit_test(test_cep_circular_gaussian),
      cmocka_unit_test(test_quantile_histogram_beyond_budget),
      cmocka_unit_test(test_predict_known),
      cmocka_unit_test(test_validate),
      cmocka_unit_test(test_scene_errors),
      cmocka_unit_test(test_scene_round_trip),
      cmocka_unit_test(test_scene_outages),
      cmocka_unit_test(test_predict_scene_points),
      cmocka_unit_test(test_predict_threads),
      cmocka_unit_test(test_cep_predict_circular),
      cmocka_unit_test(test_cep_predict_one_dimensional_limit),
      cmocka_unit_test(test_cep_predict_eccentric_reference),
      cmocka_unit_test(test_cep_predict_threads_identical),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
