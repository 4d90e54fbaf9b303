#define _POSIX_C_SOURCE 200809L
/*
 * The exact fast path of the CSV writers (navcore/io/fast_format.h): nav_fmt_g17 must write
 * byte for byte what glibc's printf("%.17g") writes, for every double, on and off its fast path
 * (1e-39 <= |x| < 1e17; below 1e-11 with the three-limb products). Random bit patterns (every exponent),
 * random values inside the fast path with full and short significands (decimal-looking numbers such as
 * 100000.005, small binary fractions, which give exact ties at the 17th digit), the boundaries of every
 * decade and of the fast path, and the special values. The tie case is also checked against its digits.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fast_format.h"
#include "nav_test.h"
#include "navcore/nav_rng.h"

static long g_checked;

static void check(double x) {
  char ref[64], got[NAV_FMT_G17_SIZE + 8];
  const int nr = snprintf(ref, sizeof ref, "%.17g", x);
  memset(got, 'Z', sizeof got);
  const int ng = nav_fmt_g17(got, x);
  if (ng != nr || strcmp(ref, got) != 0)
    fail_msg("%a: printf \"%s\" (%d), nav_fmt_g17 \"%s\" (%d)", x, ref, nr, got, ng);
  if (got[ng] != '\0') fail_msg("%a: no terminator", x);
  if (ng >= NAV_FMT_G17_SIZE) fail_msg("%a: %d characters do not fit the buffer", x, ng);
  g_checked++;
}

static double from_bits(uint64_t b) {
  double x;
  memcpy(&x, &b, sizeof x);
  return x;
}

static void test_random_bits(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261122u, 1u, 0u);
  for (int i = 0; i < 300000; ++i)
    check(from_bits(nav_rng_next_u64(&r)));
}

/* Values inside and around the fast path: uniform significand, binary exponent -50..60. */
static void test_random_fast_path(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261122u, 2u, 0u);
  long in_range = 0;
  for (int i = 0; i < 1000000; ++i) {
    const uint64_t u = nav_rng_next_u64(&r);
    const int e2 = (int)(u % 111u) - 50;
    const uint64_t mant = nav_rng_next_u64(&r) & ((1ull << 52) - 1u);
    double x = ldexp(1.0 + ldexp((double)mant, -52), e2);
    if (u & (1ull << 40)) x = -x;
    if (fabs(x) >= 1e-11 && fabs(x) < 1e17) in_range++;
    check(x);
  }
  print_message("[ fastfmt  ] %ld of 1000000 random values inside the fast path\n", in_range);
  /* Binary exponents -36..56 of -50..60 lie inside: about 93 / 111 of the values. */
  assert_true(in_range > 800000);
}

/* The small magnitudes (1e-39 .. 1e-11, products of up to 181 bits) and around their lower
 * bound: uniform significands at binary exponents -140..-30, short binary fractions (exact ties
 * at the 17th digit, whose remainder is exactly half in the middle limbs) and decimal-looking
 * values k / 10^j. */
static void test_small_magnitudes(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261127u, 4u, 0u);
  long in_range = 0;
  for (int i = 0; i < 1000000; ++i) {
    const uint64_t u = nav_rng_next_u64(&r);
    const int e2 = (int)(u % 111u) - 140;
    const uint64_t mant = nav_rng_next_u64(&r) & ((1ull << 52) - 1u);
    double x = ldexp(1.0 + ldexp((double)mant, -52), e2);
    if (u & (1ull << 40)) x = -x;
    if (fabs(x) >= 1e-39 && fabs(x) < 1e-11) in_range++;
    check(x);
  }
  for (int i = 0; i < 200000; ++i) {
    const uint64_t k = nav_rng_next_u64(&r) % 100000000000000ull;
    check(ldexp((double)(k | 1u), -(int)(64u + nav_rng_next_u64(&r) % 120u)));
    check((double)k / pow(10.0, 20 + (int)(nav_rng_next_u64(&r) % 30u)));
  }
  print_message("[ fastfmt  ] %ld of 1000000 random values between 1e-39 and 1e-11\n", in_range);
  assert_true(in_range > 800000);
}

/* Short significands: decimal-looking values (k / 10^j, as the data files hold) and small
 * binary fractions (k / 2^j), whose exact expansions end within a few digits past the 17th and
 * so produce exact ties. */
static void test_short_significands(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261122u, 3u, 0u);
  for (int i = 0; i < 400000; ++i) {
    const uint64_t k = nav_rng_next_u64(&r) % 100000000000000ull;
    const int j = (int)(nav_rng_next_u64(&r) % 23u);
    check((double)k / pow(10.0, j));
    check(ldexp((double)(k | 1u), -(int)(nav_rng_next_u64(&r) % 64u)));
  }
}

static void test_edges(void **state) {
  (void)state;
  static const double fixed[] = {0.0,           1.0,
                                 -1.0,          0.1,
                                 0.5,           100000.005,
                                 1e-11,         1e17,
                                 9.99999999e16, 1.0000001e-11,
                                 1e-5,          1e-4,
                                 1e16,          1e15,
                                 123456.789,    31.508183,
                                 -177.0,        120.401989,
                                 2.5,           0.0001234,
                                 6.02214076e23, 1.7976931348623157e308,
                                 4.9e-324,      2.2250738585072014e-308,
                                 1e-39,         1.0000001e-39,
                                 9.9999999e-40, 3.14e-16,
                                 1e-12,         9.999999999e-12};
  for (size_t i = 0; i < sizeof fixed / sizeof fixed[0]; ++i) {
    check(fixed[i]);
    check(-fixed[i]);
    check(nextafter(fixed[i], INFINITY));
    check(nextafter(fixed[i], -INFINITY));
  }
  check(-0.0);
  check(INFINITY);
  check(-INFINITY);
  check(NAN);
  /* Every power of ten and its neighbours across and beyond the fast path. */
  for (int p = -42; p <= 25; ++p) {
    const double t = pow(10.0, p);
    check(t);
    check(nextafter(t, 0.0));
    check(nextafter(t, INFINITY));
    /* Values that round up to the next decade at 17 digits. */
    check(t * (1.0 - 1e-17));
    check(t * 0.99999999999999999);
  }
  /* An exact tie at the 17th digit: 123456789012345.625 has 18 significant digits; ties to even
   * gives ...62, as glibc's printf in the default rounding mode. */
  char got[NAV_FMT_G17_SIZE];
  nav_fmt_g17(got, 123456789012345.625);
  assert_string_equal(got, "123456789012345.62");
  check(123456789012345.625);
  check(123456789012345.875);
  print_message("[ fastfmt  ] %ld values byte-identical to printf(\"%%.17g\")\n", g_checked);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_bits),
      cmocka_unit_test(test_random_fast_path),
      cmocka_unit_test(test_small_magnitudes),
      cmocka_unit_test(test_short_significands),
      cmocka_unit_test(test_edges),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
