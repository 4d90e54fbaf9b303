/**
 * @file fast_format.h
 * @brief Exact fast path for double to decimal text, byte-identical to printf's "%.17g"
 *        (navcore_io internal; header-only so that the white-box test can include it). Used by
 *        the CSV writers, where glibc's multi-precision printf was the largest cost of writing
 *        results (about 0.6 us per number).
 *
 * "%.17g" prints the 17-significant-digit decimal nearest to the double (ties to even, as
 * glibc's printf does in the default rounding mode), which reads back as the same double. For a
 * normal double x = m 2^e (m < 2^53) and a decimal exponent k with 0 <= k <= 27, the scaled value
 * x 10^k = m 5^k 2^(k+e) is an integer m 5^k (< 2^116, exact in 128 bits: 5^27 < 2^63) times a
 * power of two, so D = round(x 10^k) is computed exactly by a shift with a round-half-even on
 * the bits shifted out. k is chosen so that 10^16 <= D < 10^17, i.e. D holds the 17 digits.
 * This covers 1e-11 <= |x| < 1e17, where all navigation outputs live; zero is printed directly
 * and everything else (tiny or huge magnitudes, subnormals, infinities, NaN) goes to snprintf.
 * The layout then follows C11 7.21.6.1 for %g with precision 17: exponent X of D; style e when
 * X < -4 or X >= 17, else style f with 16 - X fraction digits; trailing zeros (and a trailing
 * point) removed; at least two exponent digits.
 */
#ifndef NAV_IO_FAST_FORMAT_H
#define NAV_IO_FAST_FORMAT_H

#include <stdint.h>
#include <stdio.h>
#include <string.h>

/** Buffer size that holds any "%.17g" output and its terminator. */
#define NAV_FMT_G17_SIZE 32

__extension__ typedef unsigned __int128 nav_fmt_u128;

/* 5^0 .. 5^27 (5^27 = 7 450 580 596 923 828 125 < 2^63). */
static const uint64_t nav_fmt_pow5[28] = {1ull,
                                          5ull,
                                          25ull,
                                          125ull,
                                          625ull,
                                          3125ull,
                                          15625ull,
                                          78125ull,
                                          390625ull,
                                          1953125ull,
                                          9765625ull,
                                          48828125ull,
                                          244140625ull,
                                          1220703125ull,
                                          6103515625ull,
                                          30517578125ull,
                                          152587890625ull,
                                          762939453125ull,
                                          3814697265625ull,
                                          19073486328125ull,
                                          95367431640625ull,
                                          476837158203125ull,
                                          2384185791015625ull,
                                          11920928955078125ull,
                                          59604644775390625ull,
                                          298023223876953125ull,
                                          1490116119384765625ull,
                                          7450580596923828125ull};

/* round(m 5^k 2^s) to nearest, ties to even; UINT64_MAX when it does not fit below 2^63. */
static inline uint64_t nav_fmt_scaled(uint64_t m, int k, int s) {
  const nav_fmt_u128 p = (nav_fmt_u128)m * nav_fmt_pow5[k];
  if (s >= 0) {
    if (s > 62 || (p >> (63 - s)) != 0) return UINT64_MAX;
    return (uint64_t)(p << s);
  }
  const int sh = -s;
  if (sh >= 127) return 0; /* p < 2^116: far below one half */
  nav_fmt_u128 q = p >> sh;
  const nav_fmt_u128 rem = p - (q << sh);
  const nav_fmt_u128 half = (nav_fmt_u128)1 << (sh - 1);
  if (rem > half || (rem == half && (q & 1u))) ++q;
  return q >> 63 ? UINT64_MAX : (uint64_t)q;
}

/**
 * Writes x as printf("%.17g", x) would into buf (at least NAV_FMT_G17_SIZE bytes), with a
 * terminating NUL. @return the length.
 */
static inline int nav_fmt_g17(char *buf, double x) {
  uint64_t bits;
  memcpy(&bits, &x, sizeof bits);
  const int neg = (int)(bits >> 63);
  const int be = (int)((bits >> 52) & 0x7ffu);
  const uint64_t frac = bits & ((1ull << 52) - 1u);
  if (be == 0 && frac == 0) {
    if (neg) {
      memcpy(buf, "-0", 3);
      return 2;
    }
    memcpy(buf, "0", 2);
    return 1;
  }
  if (be == 0 || be == 0x7ff) return snprintf(buf, NAV_FMT_G17_SIZE, "%.17g", x);
  const uint64_t m = frac | (1ull << 52);
  const int e = be - 1075; /* x = m 2^e */
  /* Decimal exponent of the leading bit, floor((e + 52) log10 2), within one of floor(log10 |x|). */
  const int lead = e + 52;
  int x10 = lead >= 0 ? (lead * 78913) >> 18 : -((-lead * 78913 + (1 << 18) - 1) >> 18);
  uint64_t d = 0;
  int tries = 0;
  for (;;) {
    const int k = 16 - x10;
    if (k < 0 || k > 27 || ++tries > 4) return snprintf(buf, NAV_FMT_G17_SIZE, "%.17g", x);
    d = nav_fmt_scaled(m, k, k + e);
    if (d >= 100000000000000000ull)
      ++x10;
    else if (d < 10000000000000000ull)
      --x10;
    else
      break;
  }
  char dig[17];
  for (int i = 16; i >= 0; --i) {
    dig[i] = (char)('0' + (int)(d % 10u));
    d /= 10u;
  }
  int nd = 17; /* significant digits after removing trailing zeros */
  while (nd > 1 && dig[nd - 1] == '0')
    --nd;
  char *p = buf;
  if (neg) *p++ = '-';
  if (x10 < -4 || x10 >= 17) {
    *p++ = dig[0];
    if (nd > 1) {
      *p++ = '.';
      memcpy(p, dig + 1, (size_t)(nd - 1));
      p += nd - 1;
    }
    *p++ = 'e';
    int ex = x10;
    *p++ = ex < 0 ? '-' : '+';
    if (ex < 0) ex = -ex;
    if (ex >= 100) *p++ = (char)('0' + ex / 100);
    *p++ = (char)('0' + ex / 10 % 10);
    *p++ = (char)('0' + ex % 10);
  } else if (x10 >= 0) {
    const int ni = x10 + 1; /* integer digits */
    memcpy(p, dig, (size_t)ni);
    p += ni;
    if (nd > ni) {
      *p++ = '.';
      memcpy(p, dig + ni, (size_t)(nd - ni));
      p += nd - ni;
    }
  } else {
    *p++ = '0';
    *p++ = '.';
    for (int i = 0; i < -x10 - 1; ++i)
      *p++ = '0';
    memcpy(p, dig, (size_t)nd);
    p += nd;
  }
  *p = '\0';
  return (int)(p - buf);
}

#endif /* NAV_IO_FAST_FORMAT_H */
