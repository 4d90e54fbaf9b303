/**
 * @file nav_sim_outcome.h
 * @brief What a Monte Carlo job gives (summary, envelopes, final errors), kept after its nav_sim is
 *        gone, the job run whole or split into ranges and merged, and the bit-for-bit comparison
 *        of two such outcomes: shared by the tests that check that the way a job is run
 *        (threads, ranges, runs in lockstep) does not change a bit (test_sim_partial,
 *        test_sim_lanes).
 *
 * Include after <cmocka.h>; the test links navcore_io (load() reads scenes/).
 */
#ifndef NAV_SIM_OUTCOME_H
#define NAV_SIM_OUTCOME_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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

static inline void keep(nav_sim *sim, const nav_sim_summary *sum, outcome *o) {
  o->sum = *sum;
  const nav_sim_envelope_point *e = nav_sim_envelope(sim, &o->n_env);
  const nav_sim_run_final *f = nav_sim_finals(sim, &o->n_fin);
  o->env = o->n_env ? malloc(o->n_env * sizeof *o->env) : NULL;
  o->fin = o->n_fin ? malloc(o->n_fin * sizeof *o->fin) : NULL;
  if (o->n_env) memcpy(o->env, e, o->n_env * sizeof *e);
  if (o->n_fin) memcpy(o->fin, f, o->n_fin * sizeof *f);
}

static inline void release(outcome *o) {
  free(o->env);
  free(o->fin);
}

/* A scene of scenes/ with @p runs Monte Carlo runs. */
static inline nav_scene load(const char *name, long runs) {
  char path[1024];
  snprintf(path, sizeof path, "%s/scenes/%s", NAV_SOURCE_DIR, name);
  nav_scene sc;
  assert_int_equal(nav_scene_read_file(path, &sc, NULL, NULL), NAV_OK);
  sc.simulation.runs = runs;
  return sc;
}

/* One nav_sim_run of the whole job on @p threads threads (nav_sim_options.lanes = @p lanes). */
static inline void reference_lanes(const nav_scene *sc, int threads, int lanes, outcome *o) {
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options opt = nav_sim_options_default();
  opt.threads = threads;
  opt.lanes = lanes;
  nav_sim_summary sum;
  const nav_status st = nav_sim_run(sim, &opt, &sum);
  if (st != NAV_OK) fail_msg("nav_sim_run: %s: %s", nav_status_str(st), nav_sim_last_error(sim));
  keep(sim, &sum, o);
  nav_sim_destroy(sim);
}

static inline void reference(const nav_scene *sc, int threads, outcome *o) {
  reference_lanes(sc, threads, 0, o);
}

/* Each range on its own nav_sim (as on its own rank), packed and unpacked, then merged. */
static inline void split(const nav_scene *sc, const long *bounds, size_t n_ranges, const int *threads,
                         outcome *o) {
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
  for (size_t q = 0; q < n_ranges; ++q)
    nav_sim_partial_destroy(parts[q]);
  free(parts);
}

static inline void same_double(double a, double b, const char *what) {
  if (memcmp(&a, &b, sizeof a) != 0) fail_msg("%s: %.17g != %.17g (the single run)", what, a, b);
}

static inline void same_stat(nav_stat a, nav_stat b, const char *what) {
  same_double(a.rms, b.rms, what);
  same_double(a.max, b.max, what);
  same_double(a.p95, b.p95, what);
}

static inline void assert_identical(const outcome *a, const outcome *b) {
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

#endif /* NAV_SIM_OUTCOME_H */
