/*
 * The replay's own atan2 and hypot (navcore/io/err_math.h): their error against long double over
 * random arguments of every octant and of ratios from 1e-300 to 1 (the maxima are printed, the
 * bounds asserted), libm's results where the kernel hands over (zeros, infinities, NaN, extreme
 * magnitudes), and the four-lane forms giving the scalar bits, lanes of every kind mixed.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "err_math.h"
#include "navcore/nav_rng.h"

/* |got - ref| in ulps of the double nearest to ref. */
static double ulps(double got, long double ref) {
  const double rd = (double)ref;
  const double a = fabs(rd);
  const double ulp = a > 0.0 ? nextafter(a, INFINITY) - a : 0x1p-1074;
  return (double)(fabsl((long double)got - ref) / (long double)ulp);
}

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

static double uni(nav_rng *r, double lo, double hi) {
  return lo + (hi - lo) * nav_rng_uniform(r);
}

/* A random finite non-zero argument pair: ratios |y/x| over 2^-60 .. 2^60 (and some down to
 * 1e-300), magnitudes 1e-6 .. 1e6, every sign. */
static void pair(nav_rng *r, double *y, double *x) {
  const double m = exp(uni(r, log(1e-6), log(1e6)));
  const double e = nav_rng_uniform(r) < 0.02 ? uni(r, -996.0, -60.0) : uni(r, -60.0, 60.0);
  *x = (nav_rng_uniform(r) < 0.5 ? -1.0 : 1.0) * m;
  *y = (nav_rng_uniform(r) < 0.5 ? -1.0 : 1.0) * ldexp(m * uni(r, 1.0, 2.0), (int)e);
  if (nav_rng_uniform(r) < 0.5) {
    const double t = *x;
    *x = *y;
    *y = t;
  }
}

static void test_atan2_accuracy(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261128u, 11u, 0u);
  double worst = 0.0, worst_libm = 0.0;
  double wy = 0.0, wx = 0.0;
  for (long i = 0; i < 2000000; ++i) {
    double y, x;
    if (i % 4 == 0) {
      /* The ratios the replay meets most: near the table's nodes and near 1. */
      x = uni(&r, 0.1, 10.0);
      y = x * ((double)(i / 4 % 17) / 16.0 + uni(&r, -1e-3, 1e-3));
      if (y == 0.0) y = 1e-3 * x;
      if (i % 8 == 0) x = -x;
    } else {
      pair(&r, &y, &x);
    }
    const long double ref = atan2l((long double)y, (long double)x);
    const double e = ulps(em_atan2(y, x), ref);
    if (e > worst) {
      worst = e;
      wy = y;
      wx = x;
    }
    worst_libm = fmax(worst_libm, ulps(atan2(y, x), ref));
  }
  printf("em_atan2: at most %.3f ulp over 2e6 pairs (at y %a, x %a); glibc's atan2 %.3f ulp\n", worst, wy, wx,
         worst_libm);
  assert_true(worst <= 1.0);
}

static void test_hypot_accuracy(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261128u, 12u, 0u);
  double worst = 0.0, worst_libm = 0.0;
  for (long i = 0; i < 2000000; ++i) {
    double y, x;
    pair(&r, &y, &x);
    if (i % 3 == 0) y = x * uni(&r, -1.0, 1.0);
    const long double ref = hypotl((long double)y, (long double)x);
    worst = fmax(worst, ulps(em_hypot(x, y), ref));
    worst_libm = fmax(worst_libm, ulps(hypot(x, y), ref));
  }
  printf("em_hypot: at most %.3f ulp over 2e6 pairs; glibc's hypot %.3f ulp\n", worst, worst_libm);
  assert_true(worst <= 0.6);
}

/* Where the kernels hand over, the result is libm's, bit for bit. */
static void test_handover_is_libm(void **state) {
  (void)state;
  const double v[] = {0.0, -0.0,      1.0,      -1.0,    3.5,     -2.25,    INFINITY, -INFINITY,
                      NAN, 0x1p-1074, 0x1p-600, 0x1p600, DBL_MAX, -DBL_MAX, 0x1p-1022};
  const size_t n = sizeof v / sizeof v[0];
  long handed = 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      const double y = v[i], x = v[j];
      if (!em_atan2_kernel(fabs(y), fabs(x))) {
        ++handed;
        const double a = em_atan2(y, x), b = atan2(y, x);
        assert_true(same_bits(a, b) || (isnan(a) && isnan(b)));
      } else {
        /* Tiny, huge and subnormal arguments inside the domain: still close to long double. */
        assert_true(ulps(em_atan2(y, x), atan2l((long double)y, (long double)x)) <= 1.5);
      }
      const double h = em_hypot(x, y);
      if (!em_hypot_kernel(fabs(x), fabs(y))) {
        const double b = hypot(x, y);
        assert_true(same_bits(h, b) || (isnan(h) && isnan(b)));
      } else if (isfinite(h)) {
        assert_true(ulps(h, hypotl((long double)x, (long double)y)) <= 1.0);
      }
    }
  assert_true(handed > 0);
  /* The quadrant conventions of the handed-over cases are libm's: a sample. */
  assert_true(same_bits(em_atan2(0.0, -1.0), atan2(0.0, -1.0)));
  assert_true(same_bits(em_atan2(-0.0, -1.0), atan2(-0.0, -1.0)));
  assert_true(em_atan2(1.0, 0.0) == atan2(1.0, 0.0));
}

/* Signs and octants: each quadrant's value against long double, and exact axes of the diagonal. */
static void test_octants(void **state) {
  (void)state;
  const double sx[2] = {1.0, -1.0}, sy[2] = {1.0, -1.0};
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int q = 1; q <= 40; ++q) {
        const double y = sy[a] * (double)q / 7.0, x = sx[b] * 3.0;
        const double got = em_atan2(y, x);
        assert_true(ulps(got, atan2l((long double)y, (long double)x)) <= 1.5);
        assert_true(signbit(got) == signbit(y));
      }
  assert_true(ulps(em_atan2(1.0, 1.0), atan2l(1.0L, 1.0L)) <= 0.5);
  assert_true(ulps(em_atan2(1.0, -1.0), atan2l(1.0L, -1.0L)) <= 0.5);
}

static void test_lanes_bit_for_bit(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261128u, 13u, 0u);
  const double special[] = {0.0, -0.0, INFINITY, -INFINITY, NAN, 0x1p-1074, 0x1p700};
  long mixed = 0;
  for (long i = 0; i < 200000; ++i) {
    em_v4 y, x;
    bool any = false;
    for (int l = 0; l < 4; ++l) {
      pair(&r, &y[l], &x[l]);
      if (i % 5 == 0 && nav_rng_uniform(&r) < 0.3) {
        const size_t s = (size_t)(nav_rng_uniform(&r) * 7.0) % 7;
        if (nav_rng_uniform(&r) < 0.5)
          y[l] = special[s];
        else
          x[l] = special[s];
        any = true;
      }
    }
    mixed += any;
    const em_v4 a = em_atan2_4(y, x), h = em_hypot4(x, y);
    for (int l = 0; l < 4; ++l) {
      const double a1 = em_atan2(y[l], x[l]), h1 = em_hypot(x[l], y[l]);
      if (!(same_bits(a[l], a1) || (isnan(a[l]) && isnan(a1))))
        fail_msg("atan2 lane %d: y %a x %a: %a against %a", l, y[l], x[l], a[l], a1);
      if (!(same_bits(h[l], h1) || (isnan(h[l]) && isnan(h1))))
        fail_msg("hypot lane %d: x %a y %a: %a against %a", l, x[l], y[l], h[l], h1);
    }
  }
  assert_true(mixed > 1000);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_atan2_accuracy),    cmocka_unit_test(test_hypot_accuracy),
      cmocka_unit_test(test_handover_is_libm),  cmocka_unit_test(test_octants),
      cmocka_unit_test(test_lanes_bit_for_bit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
