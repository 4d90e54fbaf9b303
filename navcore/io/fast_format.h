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
 * This covers 1e-11 <= |x| < 1e17, where all navigation outputs live. Below, down to 1e-39
 * (k <= 55, 5^55 < 2^128), the product m 5^k takes up to 181 bits and is formed in three 64-bit
 * limbs, with the same exact shift and round-half-even: the e-16 velocities of a state at rest and
 * other rounding residues are that small. Zero is printed directly and everything else (tinier or
 * huge magnitudes, subnormals, infinities, NaN) goes to snprintf.
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

/* 5^28 .. 5^55 as {high, low} 64-bit halves (5^55 < 2^128): the scale factors of the small
 * magnitudes, 1e-39 <= |x| < 1e-11, whose products m 5^k need up to 181 bits. */
static const uint64_t nav_fmt_pow5_wide[28][2] = {{0x0000000000000002ull, 0x04fce5e3e2502611ull}, /* 5^28 */
                                                  {0x000000000000000aull, 0x18f07d736b90be55ull}, /* 5^29 */
                                                  {0x0000000000000032ull, 0x7cb2734119d3b7a9ull}, /* 5^30 */
                                                  {0x00000000000000fcull, 0x6f7c40458122964dull}, /* 5^31 */
                                                  {0x00000000000004eeull, 0x2d6d415b85acef81ull}, /* 5^32 */
                                                  {0x00000000000018a6ull, 0xe32246c99c60ad85ull}, /* 5^33 */
                                                  {0x0000000000007b42ull, 0x6fab61f00de36399ull}, /* 5^34 */
                                                  {0x000000000002684cull, 0x2e58e9b04570f1fdull}, /* 5^35 */
                                                  {0x00000000000c097cull, 0xe7bc90715b34b9f1ull}, /* 5^36 */
                                                  {0x00000000003c2f70ull, 0x86aed236c807a1b5ull}, /* 5^37 */
                                                  {0x00000000012ced32ull, 0xa16a1b11e8262889ull}, /* 5^38 */
                                                  {0x0000000005e0a1fdull, 0x2712875988becaadull}, /* 5^39 */
                                                  {0x000000001d6329f1ull, 0xc35ca4bfabb9f561ull}, /* 5^40 */
                                                  {0x0000000092efd1b8ull, 0xd0cf37be5aa1cae5ull}, /* 5^41 */
                                                  {0x00000002deaf189cull, 0x140c16b7c528f679ull}, /* 5^42 */
                                                  {0x0000000e596b7b0cull, 0x643c7196d9ccd05dull}, /* 5^43 */
                                                  {0x00000047bf19673dull, 0xf52e37f2410011d1ull}, /* 5^44 */
                                                  {0x00000166bb7f0435ull, 0xc9e717bb45005915ull}, /* 5^45 */
                                                  {0x00000701a97b150cull, 0xf18376a85901bd69ull}, /* 5^46 */
                                                  {0x000023084f676940ull, 0xb7915149bd08b30dull}, /* 5^47 */
                                                  {0x0000af298d050e43ull, 0x95d69670b12b7f41ull}, /* 5^48 */
                                                  {0x00036bcfc1194751ull, 0xed30f03375d97c45ull}, /* 5^49 */
                                                  {0x00111b0ec57e6499ull, 0xa1f4b1014d3f6d59ull}, /* 5^50 */
                                                  {0x00558749db77f700ull, 0x29c77506823d22bdull}, /* 5^51 */
                                                  {0x01aba4714957d300ull, 0xd0e549208b31adb1ull}, /* 5^52 */
                                                  {0x085a36366eb71f04ull, 0x147a6da2b7f86475ull}, /* 5^53 */
                                                  {0x29c30f1029939b14ull, 0x6664242d97d9f649ull}, /* 5^54 */
                                                  {0xd0cf4b50cfe20765ull, 0xfff4b4e3f741cf6dull},
                                                  /* 5^55 */};

/* The eight decimal digits of n < 10^8 as ASCII in one word, the first digit in the lowest byte
 * (the order of a little-endian store): n is split into two groups of four digits, each group
 * into two of two, each of those into two digits, every split done in all lanes at once by a
 * multiplication by a scaled reciprocal (floor(v 10486 / 2^20) = floor(v / 100) for v < 10^4,
 * floor(v 103 / 2^10) = floor(v / 10) for v < 100; no lane's product reaches the next lane). */
static inline uint64_t nav_fmt_digits8(uint32_t n) {
  uint64_t x = (uint64_t)(n / 10000u) | ((uint64_t)(n % 10000u) << 32);
  const uint64_t y = ((x * 10486u) >> 20) & 0x0000007F0000007Full;
  x = y | ((x - y * 100u) << 16);
  const uint64_t z = ((x * 103u) >> 10) & 0x000F000F000F000Full;
  x = z | ((x - z * 10u) << 8);
  return x | 0x3030303030303030ull;
}
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "fast_format.h stores the digits of nav_fmt_digits8 little-endian"
#endif

/* round(P / 2^sh) to nearest, ties to even, for P = p2 2^128 + p1 2^64 + p0 and 64 <= sh < 192;
 * UINT64_MAX when it does not fit below 2^63. */
static inline uint64_t nav_fmt_shift192(uint64_t p2, uint64_t p1, uint64_t p0, int sh) {
  const nav_fmt_u128 hi = ((nav_fmt_u128)p2 << 64) | p1; /* P = hi 2^64 + p0 */
  const int sh2 = sh - 64;                               /* 0 <= sh2 < 128 */
  nav_fmt_u128 q = sh2 ? hi >> sh2 : hi;
  /* The bits shifted out: rem_hi 2^64 + p0, compared with half = 2^(sh - 1). */
  const nav_fmt_u128 rem_hi = sh2 ? hi & ((((nav_fmt_u128)1) << sh2) - 1u) : 0;
  int cmp; /* sign of (rem - half) */
  if (sh2 == 0) {
    cmp = p0 > (1ull << 63) ? 1 : (p0 == (1ull << 63) ? 0 : -1);
  } else {
    const nav_fmt_u128 half_hi = ((nav_fmt_u128)1) << (sh2 - 1);
    cmp = rem_hi > half_hi ? 1 : (rem_hi < half_hi ? -1 : (p0 > 0 ? 1 : 0));
  }
  if (cmp > 0 || (cmp == 0 && (q & 1u))) ++q;
  return q >> 63 ? UINT64_MAX : (uint64_t)q;
}

/* round(m 5^k 2^s) to nearest, ties to even; UINT64_MAX when it does not fit below 2^63.
 * 0 <= k <= 55; for k > 27, s < 0 (the small magnitudes). */
static inline uint64_t nav_fmt_scaled(uint64_t m, int k, int s) {
  if (k > 27) {
    if (s >= 0) return UINT64_MAX;
    const uint64_t h = nav_fmt_pow5_wide[k - 28][0], l = nav_fmt_pow5_wide[k - 28][1];
    const nav_fmt_u128 a = (nav_fmt_u128)m * l, b = (nav_fmt_u128)m * h;
    const nav_fmt_u128 t = (a >> 64) + (uint64_t)b;
    const uint64_t p0 = (uint64_t)a, p1 = (uint64_t)t, p2 = (uint64_t)(b >> 64) + (uint64_t)(t >> 64);
    const int sh = -s;
    if (sh >= 192) return 0; /* P < 2^181: far below one half */
    if (sh >= 64) return nav_fmt_shift192(p2, p1, p0, sh);
    /* sh < 64: the quotient would need P < 2^127 to fit below 2^63. */
    if (p2 != 0 || (p1 >> 62) != 0) return UINT64_MAX;
    const nav_fmt_u128 p = ((nav_fmt_u128)p1 << 64) | p0;
    nav_fmt_u128 q = p >> sh;
    const nav_fmt_u128 rem = p - (q << sh);
    const nav_fmt_u128 half = (nav_fmt_u128)1 << (sh - 1);
    q += (unsigned)((rem > half) | ((rem == half) & (unsigned)(q & 1u))); /* (no branch: the bits are random) */
    return q >> 63 ? UINT64_MAX : (uint64_t)q;
  }
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
  /* Round half to even, without a branch on the discarded bits (they are random). */
  q += (unsigned)((rem > half) | ((rem == half) & (unsigned)(q & 1u)));
  return q >> 63 ? UINT64_MAX : (uint64_t)q;
}

/**
 * Writes x as printf("%.17g", x) would into buf (at least NAV_FMT_G17_SIZE bytes), with a
 * terminating NUL (the bytes after it, up to NAV_FMT_G17_SIZE, are overwritten with zeros or
 * digits). @return the length.
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
    if (k < 0 || k > 55 || ++tries > 4) return snprintf(buf, NAV_FMT_G17_SIZE, "%.17g", x);
    d = nav_fmt_scaled(m, k, k + e);
    if (d >= 100000000000000000ull)
      ++x10;
    else if (d < 10000000000000000ull)
      --x10;
    else
      break;
  }
  /* The 17 digits: the first (c0), then digits 1 .. 16 in the bytes of D (digit 1 lowest), two
   * groups of eight converted by nav_fmt_digits8. The significant digits end at the last one that
   * is not '0'. */
  const uint64_t rest = d % 10000000000000000ull;
  const char c0 = (char)('0' + (int)(d / 10000000000000000ull));
  const uint64_t wh = nav_fmt_digits8((uint32_t)(rest / 100000000u));
  const uint64_t wl = nav_fmt_digits8((uint32_t)(rest % 100000000u));
  const nav_fmt_u128 D = (nav_fmt_u128)wh | ((nav_fmt_u128)wl << 64);
  const uint64_t zh = wh ^ 0x3030303030303030ull, zl = wl ^ 0x3030303030303030ull; /* '0' -> 0 */
  int nd; /* significant digits after removing trailing zeros */
  if (zl)
    nd = 17 - (__builtin_clzll(zl) >> 3);
  else if (zh)
    nd = 9 - (__builtin_clzll(zh) >> 3);
  else
    nd = 1;
  /* The text is laid out in t from the digits in registers with 1-, 8- and 16-byte stores that may
   * run past its end (copies of fixed size: short variable-length ones cost more than the
   * digits), then t's first NAV_FMT_G17_SIZE bytes go to buf. */
  char t[64];
  memset(t, 0, NAV_FMT_G17_SIZE);
  char *p = t;
  *p = '-';
  p += neg; /* (the sign without a branch: it changes from value to value) */
  if (x10 < -4 || x10 >= 17) {
    p[0] = c0;
    p[1] = '.';
    memcpy(p + 2, &D, 16);
    p += nd > 1 ? nd + 1 : 1;
    *p++ = 'e';
    int ex = x10;
    *p++ = ex < 0 ? '-' : '+';
    if (ex < 0) ex = -ex;
    if (ex >= 100) *p++ = (char)('0' + ex / 100);
    *p++ = (char)('0' + ex / 10 % 10);
    *p++ = (char)('0' + ex % 10);
  } else if (x10 >= 0) {
    const int ni = x10 + 1; /* integer digits, 1..17 */
    p[0] = c0;
    memcpy(p + 1, &D, 16);
    if (nd > ni) {
      /* ni <= 16: the point, then digits ni .. 16 (bytes ni - 1 .. 15 of D) after it. */
      const nav_fmt_u128 tail = D >> (8 * (ni - 1));
      p[ni] = '.';
      memcpy(p + ni + 1, &tail, 16);
      p += nd + 1;
    } else {
      p += ni;
    }
  } else {
    /* -4 <= x10 <= -1: "0." and -x10 - 1 zeros before the digits. */
    memcpy(p, "0.000000", 8);
    p += 2 + (-x10 - 1);
    p[0] = c0;
    memcpy(p + 1, &D, 16);
    p += nd;
  }
  *p = '\0';
  memcpy(buf, t, NAV_FMT_G17_SIZE);
  return (int)(p - t);
}

#endif /* NAV_IO_FAST_FORMAT_H */
