/*
 * navsim bench's verdicts (issue 23 item 5) fed made-up figures: a target is met only by a
 * measured figure within its bound; a capped run's lower bound decides only a failure; a
 * projection is never a verdict; MPI scaling needs >= 1.8x and at least 4 cores for 2 ranks of 1
 * thread ("not measurable here" on the 2-core machine, where the issue saw 0.56x and 0.94x
 * called "met"); a peer's figure says whether it was measured in this run or published, and where.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <string.h>

#include "bench_verdict.h"

static void test_bounds(void **state) {
  (void)state;
  assert_int_equal(bench_verdict_at_most(0.14, 0.15, false), BENCH_MET);
  assert_int_equal(bench_verdict_at_most(0.15, 0.15, false), BENCH_MET);
  assert_int_equal(bench_verdict_at_most(0.389, 0.15, false), BENCH_NOT_MET);
  assert_int_equal(bench_verdict_at_most(NAN, 0.15, false), BENCH_NOT_MEASURED);
  assert_int_equal(bench_verdict_at_most(INFINITY, 0.15, false), BENCH_NOT_MEASURED);
  /* A campaign stopped at its cap after 50 s is a lower bound: it cannot show <= 60 s. */
  assert_int_equal(bench_verdict_at_most(50.0, 60.0, true), BENCH_NOT_MEASURED);
  assert_int_equal(bench_verdict_at_most(147.8, 60.0, true), BENCH_NOT_MET);
  assert_int_equal(bench_verdict_at_least(5.78e6, 5e6), BENCH_MET);
  assert_int_equal(bench_verdict_at_least(4.9e6, 5e6), BENCH_NOT_MET);
  assert_int_equal(bench_verdict_at_least(NAN, 5e6), BENCH_NOT_MEASURED);
  assert_string_equal(bench_verdict_text(BENCH_MET), "**met**");
  assert_string_equal(bench_verdict_text(BENCH_NOT_MET), "**not met**");
  assert_string_equal(bench_verdict_text(BENCH_NOT_MEASURED), "not measured");
  assert_string_equal(bench_verdict_text(BENCH_NOT_MEASURABLE), "not measurable here");
}

static void test_mpi(void **state) {
  (void)state;
  double s = 0.0;
  /* The figures on the 2-core machine: 0.56x and 0.94x were reported as met. */
  assert_int_equal(bench_verdict_mpi(7.93, 7.93 / 0.56, 1, 2, &s), BENCH_NOT_MEASURABLE);
  assert_true(fabs(s - 0.56) < 1e-12);
  assert_int_equal(bench_verdict_mpi(7.93, 7.93 / 0.94, 1, 2, &s), BENCH_NOT_MEASURABLE);
  /* Even a good speed-up does not count where the ranks share the cores. */
  assert_int_equal(bench_verdict_mpi(10.0, 5.0, 1, 2, &s), BENCH_NOT_MEASURABLE);
  assert_int_equal(bench_verdict_mpi(10.0, 5.0, 1, 3, &s), BENCH_NOT_MEASURABLE);
  /* On enough cores: >= 1.8x met, below not met; threads per rank count. */
  assert_int_equal(bench_verdict_mpi(10.0, 5.2, 1, 4, &s), BENCH_MET);
  assert_true(fabs(s - 10.0 / 5.2) < 1e-12);
  assert_int_equal(bench_verdict_mpi(10.0, 10.0 / 1.8, 1, 4, &s), BENCH_MET);
  assert_int_equal(bench_verdict_mpi(10.0, 6.0, 1, 8, &s), BENCH_NOT_MET);
  assert_int_equal(bench_verdict_mpi(10.0, 5.2, 2, 4, &s), BENCH_NOT_MEASURABLE);
  assert_int_equal(bench_verdict_mpi(10.0, 5.2, 2, 8, &s), BENCH_MET);
  /* Missing runs. */
  assert_int_equal(bench_verdict_mpi(NAN, 5.0, 1, 16, &s), BENCH_NOT_MEASURED);
  assert_true(isnan(s));
  assert_int_equal(bench_verdict_mpi(10.0, 0.0, 1, 16, NULL), BENCH_NOT_MEASURED);
}

static void test_peer_labels(void **state) {
  (void)state;
  char buf[400];
  const bench_peer published = {"KF-GINS", 3.3, 0.0219, false, "data set README: 2-core AMD EPYC"};
  bench_peer_text(buf, sizeof buf, &published, 0.389);
  assert_non_null(strstr(buf, "KF-GINS 3.3 s published (data set README: 2-core AMD EPYC)"));
  assert_non_null(strstr(buf, "ours/KF-GINS 0.118 (against the published figure)"));
  assert_null(strstr(buf, "measured in this run"));
  const bench_peer measured = {"KF-GINS", 4.895, 0.02186, true, NULL};
  bench_peer_text(buf, sizeof buf, &measured, 0.389);
  assert_non_null(strstr(buf, "KF-GINS 4.89 s measured in this run"));
  assert_non_null(strstr(buf, "ours/KF-GINS 0.0795 (both measured in this run)"));
  assert_null(strstr(buf, "published"));
  const bench_peer unknown = {"KF-GINS", NAN, NAN, false, NULL};
  bench_peer_text(buf, sizeof buf, &unknown, 0.389);
  assert_non_null(strstr(buf, "time unknown"));
  assert_null(strstr(buf, "ratio"));
  assert_null(strstr(buf, "ours/"));
}

static void test_median(void **state) {
  (void)state;
  double a[3] = {0.41, 0.38, 0.52};
  assert_true(bench_median(a, 3) == 0.41);
  double b[4] = {4.0, 1.0, 3.0, 2.0};
  assert_true(bench_median(b, 4) == 2.5);
  assert_true(isnan(bench_median(b, 0)));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bounds),
      cmocka_unit_test(test_mpi),
      cmocka_unit_test(test_peer_labels),
      cmocka_unit_test(test_median),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
