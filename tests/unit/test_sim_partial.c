/*
 * Monte Carlo jobs split into ranges (nav_sim_partial.h, the navcore side of navsim under MPI):
 * runs [r0, r1) simulated separately (any thread count), packed, unpacked and merged in run order
 * give bit for bit the summary, envelopes and final errors of one nav_sim_run over every run; the
 * merge refuses partials that do not tile the job, and unpack refuses bytes that are no partial.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_io.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_sim_partial.h"

typedef struct outcome {
  nav_sim_summary sum;
  nav_sim_envelope_point *env;
  size_t n_env;
  nav_sim_run_final *fin;
  size_t n_fin;
} outcome;

static void keep(nav_sim *sim, const nav_sim_summary *sum, outcome *o) {
  o->sum = *sum;
  const nav_sim_envelope_point *e = nav_sim_envelope(sim, &o->n_env);
  const nav_sim_run_final *f = nav_sim_finals(sim, &o->n_fin);
  o->env = o->n_env ? malloc(o->n_env * sizeof *o->env) : NULL;
  o->fin = o->n_fin ? malloc(o->n_fin * sizeof *o->fin) : NULL;
  if (o->n_env) memcpy(o->env, e, o->n_env * sizeof *e);
  if (o->n_fin) memcpy(o->fin, f, o->n_fin * sizeof *f);
}

static void release(outcome *o) {
  free(o->env);
  free(o->fin);
}

static nav_scene load(const char *name, long runs) {
  char path[1024];
  snprintf(path, sizeof path, "%s/scenes/%s", NAV_SOURCE_DIR, name);
  nav_scene sc;
  assert_int_equal(nav_scene_read_file(path, &sc, NULL, NULL), NAV_OK);
  sc.simulation.runs = runs;
  return sc;
}

static void reference(const nav_scene *sc, int threads, outcome *o) {
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options opt = nav_sim_options_default();
  opt.threads = threads;
  nav_sim_summary sum;
  const nav_status st = nav_sim_run(sim, &opt, &sum);
  if (st != NAV_OK) fail_msg("nav_sim_run: %s: %s", nav_status_str(st), nav_sim_last_error(sim));
  keep(sim, &sum, o);
  nav_sim_destroy(sim);
}

/* Each range on its own nav_sim (as on its own rank), packed and unpacked, then merged. */
static void split(const nav_scene *sc, const long *bounds, size_t n_ranges, const int *threads, outcome *o) {
  nav_sim_partial **parts = calloc(n_ranges, sizeof *parts);
  assert_non_null(parts);
  for (size_t q = 0; q < n_ranges; ++q) {
    nav_sim *sim = NULL;
    assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
    nav_sim_options opt = nav_sim_options_default();
    opt.threads = threads[q];
    nav_sim_partial *p = NULL;
    const nav_status st = nav_sim_run_partial(sim, &opt, bounds[q], bounds[q + 1], &p);
    if (st != NAV_OK) fail_msg("nav_sim_run_partial: %s: %s", nav_status_str(st), nav_sim_last_error(sim));
    long r0 = -1, r1 = -1;
    nav_sim_partial_range(p, &r0, &r1);
    assert_int_equal(r0, bounds[q]);
    assert_int_equal(r1, bounds[q + 1]);
    size_t size = 0;
    const void *bytes = nav_sim_partial_bytes(p, &size);
    assert_int_equal(nav_sim_partial_unpack(bytes, size, &parts[q]), NAV_OK);
    nav_sim_partial_destroy(p);
    nav_sim_destroy(sim);
  }
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options opt = nav_sim_options_default();
  nav_sim_summary sum;
  const nav_status st = nav_sim_merge(sim, &opt, (const nav_sim_partial *const *)parts, n_ranges, &sum);
  if (st != NAV_OK) fail_msg("nav_sim_merge: %s: %s", nav_status_str(st), nav_sim_last_error(sim));
  keep(sim, &sum, o);
  /* Gaps, overlaps and a wrong order are refused. */
  if (n_ranges >= 2) {
    const nav_sim_partial *swapped[2] = {parts[1], parts[0]};
    assert_int_equal(nav_sim_merge(sim, &opt, swapped, 2, &sum), NAV_ERR_INVALID_ARG);
    assert_int_equal(nav_sim_merge(sim, &opt, (const nav_sim_partial *const *)parts, n_ranges - 1, &sum),
                     NAV_ERR_INVALID_ARG);
    assert_true(nav_sim_last_error(sim)[0] != '\0');
  }
  nav_sim_destroy(sim);
  for (size_t q = 0; q < n_ranges; ++q) nav_sim_partial_destroy(parts[q]);
  free(parts);
}

static void same_double(double a, double b, const char *what) {
  if (memcmp(&a, &b, sizeof a) != 0) fail_msg("%s: %.17g (split) != %.17g (single run)", what, a, b);
}

static void same_stat(nav_stat a, nav_stat b, const char *what) {
  same_double(a.rms, b.rms, what);
  same_double(a.max, b.max, what);
  same_double(a.p95, b.p95, what);
}

static void assert_identical(const outcome *a, const outcome *b) {
  assert_int_equal(a->sum.runs, b->sum.runs);
  assert_int_equal(a->sum.imu_samples, b->sum.imu_samples);
  assert_int_equal(a->sum.stats_epochs, b->sum.stats_epochs);
  assert_false(a->sum.partial);
  same_stat(a->sum.stats.pos_err_h_m, b->sum.stats.pos_err_h_m, "stats.pos_err_h_m");
  same_stat(a->sum.stats.pos_err_v_m, b->sum.stats.pos_err_v_m, "stats.pos_err_v_m");
  same_stat(a->sum.stats.vel_err_mps, b->sum.stats.vel_err_mps, "stats.vel_err_mps");
  same_stat(a->sum.stats.att_err_rad, b->sum.stats.att_err_rad, "stats.att_err_rad");
  same_stat(a->sum.stats.yaw_err_rad, b->sum.stats.yaw_err_rad, "stats.yaw_err_rad");
  same_double(a->sum.final.pos_err_h_m, b->sum.final.pos_err_h_m, "final.pos_err_h_m");
  same_double(a->sum.final_rms.pos_err_h_m, b->sum.final_rms.pos_err_h_m, "final_rms.pos_err_h_m");
  same_double(a->sum.final_rms.att_err_rad, b->sum.final_rms.att_err_rad, "final_rms.att_err_rad");
  assert_int_equal(a->n_env, b->n_env);
  assert_true(a->n_env > 0);
  assert_memory_equal(a->env, b->env, a->n_env * sizeof *a->env);
  assert_int_equal(a->n_fin, b->n_fin);
  for (size_t i = 0; i < a->n_fin; ++i) {
    assert_int_equal(a->fin[i].run, b->fin[i].run);
    assert_memory_equal(&a->fin[i].err, &b->fin[i].err, sizeof a->fin[i].err);
  }
}

/* Free INS with sensor errors: 7 runs as 3 uneven ranges with 1, 2 and 3 threads. */
static void test_free_ins_split_is_bit_identical(void **state) {
  (void)state;
  nav_scene sc = load("paper-parametric.yaml", 7);
  /* Initial errors drawn per run: the runs differ. */
  sc.initial_errors.pos_sd_m = nav_vec3_make(1.0, 2.0, 3.0);
  sc.initial_errors.vel_sd_mps = nav_vec3_make(0.1, 0.1, 0.05);
  sc.initial_errors.att_sd_rad = nav_vec3_make(1e-3, 1e-3, 5e-3);
  outcome ref, got;
  reference(&sc, 2, &ref);
  const long bounds[4] = {0, 2, 3, 7};
  const int threads[3] = {1, 2, 3};
  split(&sc, bounds, 3, threads, &got);
  assert_identical(&got, &ref);
  release(&ref);
  release(&got);
}

/* INS/GNSS with outages (filter sigmas and NEES in the envelopes): 4 runs as 2 ranges. */
static void test_ins_gnss_split_is_bit_identical(void **state) {
  (void)state;
  const nav_scene sc = load("urban-drive.yaml", 4);
  outcome ref, got;
  reference(&sc, 1, &ref);
  const long bounds[3] = {0, 1, 4};
  const int threads[2] = {1, 2};
  split(&sc, bounds, 2, threads, &got);
  assert_identical(&got, &ref);
  release(&ref);
  release(&got);
}

static void test_unpack_refuses_other_bytes(void **state) {
  (void)state;
  nav_sim_partial *p = NULL;
  unsigned char junk[512];
  memset(junk, 0x5a, sizeof junk);
  assert_int_equal(nav_sim_partial_unpack(junk, sizeof junk, &p), NAV_ERR_PARSE);
  assert_null(p);
  assert_int_equal(nav_sim_partial_unpack(junk, 3, &p), NAV_ERR_PARSE);
  /* A real partial, truncated by one byte. */
  nav_scene sc = load("paper-parametric.yaml", 3);
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options opt = nav_sim_options_default();
  nav_sim_partial *good = NULL;
  assert_int_equal(nav_sim_run_partial(sim, &opt, 1, 2, &good), NAV_OK);
  size_t size = 0;
  const void *bytes = nav_sim_partial_bytes(good, &size);
  assert_true(size > 64);
  assert_int_equal(nav_sim_partial_unpack(bytes, size - 1, &p), NAV_ERR_PARSE);
  assert_int_equal(nav_sim_partial_unpack(bytes, size, &p), NAV_OK);
  nav_sim_partial_destroy(p);
  nav_sim_partial_destroy(good);
  nav_sim_destroy(sim);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_free_ins_split_is_bit_identical),
      cmocka_unit_test(test_ins_gnss_split_is_bit_identical),
      cmocka_unit_test(test_unpack_refuses_other_bytes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
