/*
 * nav_format_g17 (nav_results.h, navsim estimate's estimate.csv): the same bytes as
 * snprintf("%.17g") for random bit patterns (every exponent: the fast path and the fallback),
 * random values in the range the estimate writes (1e-12 .. 1e7), and the edge cases: zeros of
 * both signs, subnormals, infinities, NaN, powers of ten and their neighbours, integers.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "navcore/nav_results.h"

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static uint64_t next_u64(void) { /* splitmix64 */
  uint64_t z = (rng_state += 0x9e3779b97f4a7c15ull);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

static long checked = 0;

static void check(double x) {
  char want[64], got[NAV_FORMAT_G17_SIZE + 8];
  memset(got, 'x', sizeof got);
  const int nw = snprintf(want, sizeof want, "%.17g", x);
  const int ng = nav_format_g17(got, x);
  if (ng != nw || strcmp(want, got) != 0 || ng >= NAV_FORMAT_G17_SIZE)
    fail_msg("%a: printf \"%s\" (%d), nav_format_g17 \"%s\" (%d)", x, want, nw, got, ng);
  ++checked;
}

static void test_edges(void **state) {
  (void)state;
  const double v[] = {0.0, -0.0, 1.0, -1.0, 0.1, 0.5, 2.0 / 3.0, 1e-12, 1e-11, 9.999999999999999e-12, 1e-5,
                      1e-4, 9.9999999999999991e-5, 123456789.0, 1e16, 1e17, 9.9999999999999984e16, 1e22, 1e300,
                      DBL_MIN, DBL_MIN / 3.0, DBL_TRUE_MIN, DBL_MAX, -DBL_MAX, INFINITY, -INFINITY, NAN,
                      3.141592653589793, -2.718281828459045, 0.30000000000000004, 5e-324, 4503599627370496.5, 9007199254740993.0};
  for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i) check(v[i]);
  for (int e = -30; e <= 30; ++e) {
    const double p = pow(10.0, e);
    check(p);
    check(nextafter(p, 0.0));
    check(nextafter(p, INFINITY));
    check(-p);
  }
  for (int i = -1000; i <= 1000; ++i) check((double)i);
}

static void test_random(void **state) {
  (void)state;
  for (int i = 0; i < 200000; ++i) {
    const uint64_t bits = next_u64();
    double x;
    memcpy(&x, &bits, sizeof x);
    check(x);
  }
  for (int i = 0; i < 200000; ++i) { /* the estimate's sigmas and times: 1e-12 .. 1e7 */
    const double u = (double)(next_u64() >> 11) / 9007199254740992.0;
    check(pow(10.0, -12.0 + 19.0 * u) * ((next_u64() & 1u) ? 1.0 : -1.0));
  }
  print_message("%ld values byte-identical to printf\n", checked);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_edges),
      cmocka_unit_test(test_random),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
