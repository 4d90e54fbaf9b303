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
#include "nav_sim_outcome.h"

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
