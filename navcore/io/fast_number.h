/**
 * @file fast_number.h
 * @brief Exact fast path for decimal text to double (navcore_io internal; header-only so that the
 *        white-box test can include it). Used by the recorded-data readers (recorded.c), where
 *        strtod was the largest single cost of `navsim replay`.
 *
 * The fast path is Clinger's (W. D. Clinger, "How to read floating point numbers accurately",
 * PLDI 1990): a decimal d_1..d_k x 10^e whose significand M (the digits as an integer, leading
 * zeros dropped) is at most 2^53 and whose scaled exponent q = e - (fraction digits) has
 * |q| <= 22 is M * 10^q or M / 10^-q, where M and 10^|q| are exact doubles, so the result is a
 * single correctly rounded IEEE operation, i.e. the double nearest to the decimal value: exactly
 * what a correctly rounding strtod (glibc's is) returns, not merely within an ulp. Everything
 * else (more than 19 significant digits, M > 2^53, |q| > 22, hexadecimal, nan/inf, any other
 * character) is reported as "not handled" and the caller falls back to strtod, which also
 * produces its error messages. Requires IEEE double arithmetic in round-to-nearest without
 * extended precision (x86-64 SSE2, AArch64; not x87) and no FMA contraction (irrelevant here:
 * there is a single operation).
 */
#ifndef NAV_IO_FAST_NUMBER_H
#define NAV_IO_FAST_NUMBER_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

/* The padded scans are called once per field of every line: inlined into the line loop. */
#if defined(__GNUC__)
#define NAV_FAST_INLINE static inline __attribute__((always_inline))
#else
#define NAV_FAST_INLINE static inline
#endif

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* -v when @p neg, else v (IEEE negation: the sign bit flipped), without a branch on the data. */
NAV_FAST_INLINE double nav_fast_negate_if(double v, bool neg) {
  uint64_t b;
  memcpy(&b, &v, sizeof b);
  b ^= (uint64_t)neg << 63;
  memcpy(&v, &b, sizeof v);
  return v;
}
#endif

/* 10^0 .. 10^22: all exactly representable as doubles (5^22 < 2^53). */
static const double nav_fast_pow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                          1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                          1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* Up to eight bytes of [s, end) in a word, the first in the lowest byte; missing bytes are 0,
 * which is not a digit. */
static inline uint64_t nav_fast_load8(const char *s, const char *end) {
  uint64_t w = 0;
  if (end - s >= 8)
    memcpy(&w, s, 8);
  else
    memcpy(&w, s, (size_t)(end - s));
  return w;
}

/* The number of leading ASCII digits of the word (8 when all are). */
static inline unsigned nav_fast_digit_run(uint64_t w) {
  /* A byte b is a digit iff its high nibble and that of b + 6 are both 3; a carry of b + 6 only
   * reaches bytes above the first non-digit, so the bytes up to it are judged right. */
  const uint64_t z = ((w & 0xF0F0F0F0F0F0F0F0ull) | (((w + 0x0606060606060606ull) & 0xF0F0F0F0F0F0F0F0ull) >> 4)) ^
                     0x3333333333333333ull;
  /* Without a branch on the data: the top bit set aside, z = 0 gives 63 + 1 = 64, i.e. 8. */
  return (unsigned)(__builtin_ctzll(z | 0x8000000000000000ull) + (z == 0)) >> 3;
}

/* The value of the first n (1..8) ASCII digits of the word: they are moved to the top bytes (the
 * bytes below become leading zeros) and combined by the usual multiply-shift steps. */
static inline uint64_t nav_fast_digits_value(uint64_t w, unsigned n) {
  uint64_t d = (w - 0x3030303030303030ull) << (8u * (8u - n));
  d = (d * 10u) + (d >> 8);
  d = (((d & 0x000000FF000000FFull) * (100u + (1000000ull << 32))) +
       (((d >> 16) & 0x000000FF000000FFull) * (1u + (10000ull << 32)))) >>
      32;
  return d & 0xFFFFFFFFu;
}

/* 10^0 .. 10^19 as integers. */
static const uint64_t nav_fast_pow10_u[20] = {1ull,
                                              10ull,
                                              100ull,
                                              1000ull,
                                              10000ull,
                                              100000ull,
                                              1000000ull,
                                              10000000ull,
                                              100000000ull,
                                              1000000000ull,
                                              10000000000ull,
                                              100000000000ull,
                                              1000000000000ull,
                                              10000000000000ull,
                                              100000000000000ull,
                                              1000000000000000ull,
                                              10000000000000000ull,
                                              100000000000000000ull,
                                              1000000000000000000ull,
                                              10000000000000000000ull};
#endif

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/* The value of the 18 characters at @p p when they are printf's "%.12e" shape,
 * d.dddddddddddde[+-]dd, with a scale 10^q, |q| <= 22 (Clinger's exact case): *out = the
 * correctly rounded value (negated when @p neg) and true; false for any other text. Reads
 * p[0..17] only; the caller checks what follows. */
NAV_FAST_INLINE bool nav_fast_sci12_words(const char *p, bool neg, double *out) {
  uint64_t a, b;
  memcpy(&a, p, 8);     /* d . d d d d d d */
  memcpy(&b, p + 8, 8); /* d d d d d d e +- */
  const uint64_t ad = (a & ~0xFF00ull) | 0x3000ull;                     /* the point as a '0' */
  const uint64_t bd = (b & 0x0000FFFFFFFFFFFFull) | 0x3030000000000000ull; /* e and sign as '0's */
  const unsigned c6 = (unsigned)(b >> 48) & 0xFFu, c7 = (unsigned)(b >> 56);
  if (!(((ad & 0xF0F0F0F0F0F0F0F0ull) | (((ad + 0x0606060606060606ull) & 0xF0F0F0F0F0F0F0F0ull) >> 4)) ==
            0x3333333333333333ull &&
        ((bd & 0xF0F0F0F0F0F0F0F0ull) | (((bd + 0x0606060606060606ull) & 0xF0F0F0F0F0F0F0F0ull) >> 4)) ==
            0x3333333333333333ull &&
        ((a >> 8) & 0xFFu) == '.' && (c6 | 0x20u) == 'e' && (c7 == '+' || c7 == '-') &&
        (unsigned)(p[16] - '0') < 10u && (unsigned)(p[17] - '0') < 10u))
    return false;
  const int e = (c7 == '-' ? -1 : 1) * ((p[16] - '0') * 10 + (p[17] - '0'));
  const int q = e - 12;
  if (q < -22 || q > 22) return false;
  /* Fraction digits 1-8 (bytes 2-7 of a, 0-1 of b) and 9-12 (bytes 2-5 of b), combined as in the
   * eight- and four-digit steps of the general scan. */
  uint64_t w = ((a >> 16) | (b << 48)) - 0x3030303030303030ull;
  w = (w * 10u) + (w >> 8);
  w = (((w & 0x000000FF000000FFull) * (100u + (1000000ull << 32))) +
       (((w >> 16) & 0x000000FF000000FFull) * (1u + (10000ull << 32)))) >>
      32;
  uint32_t w4 = (uint32_t)(b >> 16) - 0x30303030u;
  w4 = (w4 * 10u) + (w4 >> 8);
  w4 = ((w4 & 0x000000FFu) * 100u) + ((w4 >> 16) & 0x000000FFu);
  const uint64_t m = ((a & 0xFFu) - '0') * 1000000000000ull + (w & 0xFFFFFFFFu) * 10000u + w4;
  /* m < 10^13 < 2^53 is exact; 0 gives +0 either way, as the general scan's 0 */
  const double v = q < 0 ? (double)m / nav_fast_pow10[-q] : (double)m * nav_fast_pow10[q];
  *out = nav_fast_negate_if(v, neg);
  return true;
}
#endif

/**
 * Parse a number [+-]digits[.digits][(e|E)[+-]digits] (at least one significand digit) at the
 * start of [s, end) when the exact fast path applies, stopping at the first character that
 * cannot continue it.
 * @return the end of the number and *out = the correctly rounded value; NULL when there is no
 *         such number or it is outside the fast path (*out untouched). The caller checks what
 *         follows (a field separator) and otherwise uses strtod.
 */
static inline const char *nav_fast_number_scan(const char *s, const char *end, double *out) {
  const char *p = s;
  if (p == end) return NULL;
  bool neg = false;
  if (*p == '+' || *p == '-') {
    neg = *p == '-';
    if (++p == end) return NULL;
  }
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  /* The shape printf's "%.12e" writes, d.dddddddddddde[+-]dd (the increments of KF-GINS IMU
   * files, six of their seven columns), checked and converted in whole-word steps without a loop
   * per character; any other text goes on to the general scan below, which gives the same value
   * for this shape too. */
  if (end - p >= 18 && p[1] == '.' && (end - p == 18 || (unsigned)(p[18] - '0') >= 10u) &&
      nav_fast_sci12_words(p, neg, out))
    return p + 18;
  /* Fixed-point text, printf's "%.Nf" (the columns of reference and GNSS files): 1-7 integer
   * digits, optionally a point and up to 15 fraction digits, at most 19 digits in all, no
   * exponent. The digit runs are found and converted a word at a time; the significand and the
   * scale are those of the general scan below (leading zeros only add nothing to M), so the value
   * is the same single division. Anything else goes on to the general scan. */
  {
    const uint64_t wi = nav_fast_load8(p, end);
    const unsigned li = nav_fast_digit_run(wi);
    if (li >= 1u && li <= 7u) {
      const uint64_t vi = nav_fast_digits_value(wi, li);
      const char *f = p + li;
      if (f == end || (*f != '.' && *f != 'e' && *f != 'E')) {
        *out = neg ? -(double)vi : (double)vi; /* exact: vi < 10^7 */
        return f;
      }
      if (*f == '.') {
        ++f;
        const uint64_t w1 = nav_fast_load8(f, end);
        unsigned nf = nav_fast_digit_run(w1);
        uint64_t m = 0;
        bool ok = nf >= 1u;
        if (nf >= 1u && nf <= 7u) {
          m = vi * nav_fast_pow10_u[nf] + nav_fast_digits_value(w1, nf);
        } else if (nf == 8u) {
          const uint64_t w2 = nav_fast_load8(f + 8, end);
          const unsigned n2 = nav_fast_digit_run(w2);
          ok = n2 <= 7u && li + 8u + n2 <= 19u;
          if (ok) {
            m = vi * nav_fast_pow10_u[8] + nav_fast_digits_value(w1, 8u);
            if (n2 > 0u) m = m * nav_fast_pow10_u[n2] + nav_fast_digits_value(w2, n2);
            nf = 8u + n2;
          }
        }
        if (ok && m <= ((uint64_t)1 << 53)) {
          const char *q = f + nf;
          if (q == end || (*q != 'e' && *q != 'E')) {
            double v = (double)m; /* exact */
            if (m != 0) v = v / nav_fast_pow10[nf];
            *out = neg ? -v : v;
            return q;
          }
        }
      }
    }
  }
#endif
  uint64_t m = 0;
  int sig = 0;     /* significant digits in m (leading zeros excluded) */
  int frac = 0;    /* digits after the point */
  int digits = 0;  /* all significand digits */
  while (p != end && (unsigned)(*p - '0') < 10u) {
    const unsigned d = (unsigned)(*p - '0');
    if (m != 0 || d != 0) {
      if (++sig > 19) return NULL;
      m = m * 10u + d;
    }
    ++digits;
    ++p;
  }
  if (p != end && *p == '.') {
    ++p;
    /* Eight, then four fraction digits at a time (SWAR: the usual digit test and the
     * multiply-shift steps that combine ASCII digits into their value); the byte loop below
     * finishes. Leading zeros of the significand (0.000123) are skipped without counting them as
     * significant. Reads only inside [p, end). */
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    while (sig <= 11 && end - p >= 8) {
      uint64_t w;
      memcpy(&w, p, 8);
      if (((w & 0xF0F0F0F0F0F0F0F0ull) | (((w + 0x0606060606060606ull) & 0xF0F0F0F0F0F0F0F0ull) >> 4)) !=
          0x3333333333333333ull)
        break;
      w -= 0x3030303030303030ull; /* digit bytes, first digit in the lowest byte (little endian) */
      if (m == 0) {
        if (w == 0) { /* eight leading zeros */
          digits += 8;
          frac += 8;
          p += 8;
          continue;
        }
        sig -= __builtin_ctzll(w) >> 3; /* zeros before the first significant digit */
      }
      w = (w * 10u) + (w >> 8);
      w = (((w & 0x000000FF000000FFull) * (100u + (1000000ull << 32))) +
           (((w >> 16) & 0x000000FF000000FFull) * (1u + (10000ull << 32)))) >>
          32;
      m = m * 100000000u + (w & 0xFFFFFFFFu);
      sig += 8;
      digits += 8;
      frac += 8;
      p += 8;
    }
    if (sig <= 15 && end - p >= 4) {
      uint32_t w;
      memcpy(&w, p, 4);
      if (((w & 0xF0F0F0F0u) | (((w + 0x06060606u) & 0xF0F0F0F0u) >> 4)) == 0x33333333u) {
        w -= 0x30303030u;
        if (m == 0 && w != 0) sig -= __builtin_ctz(w) >> 3;
        if (m != 0 || w != 0) sig += 4;
        w = (w * 10u) + (w >> 8);                                   /* two-digit values in bytes 0, 2 */
        w = ((w & 0x000000FFu) * 100u) + ((w >> 16) & 0x000000FFu); /* the four-digit value */
        m = m * 10000u + w;
        digits += 4;
        frac += 4;
        p += 4;
      }
    }
#endif
    while (p != end && (unsigned)(*p - '0') < 10u) {
      const unsigned d = (unsigned)(*p - '0');
      if (m != 0 || d != 0) {
        if (++sig > 19) return NULL;
        m = m * 10u + d;
      }
      ++digits;
      ++frac;
      ++p;
    }
  }
  if (digits == 0) return NULL;
  int e = 0;
  if (p != end && (*p == 'e' || *p == 'E')) {
    ++p;
    bool eneg = false;
    if (p != end && (*p == '+' || *p == '-')) {
      eneg = *p == '-';
      ++p;
    }
    int ed = 0;
    while (p != end && (unsigned)(*p - '0') < 10u) {
      if (++ed > 4) return NULL;
      e = e * 10 + (*p - '0');
      ++p;
    }
    if (ed == 0) return NULL;
    if (eneg) e = -e;
  }
  if (m > ((uint64_t)1 << 53)) return NULL;
  const int q = e - frac;
  double v = (double)m; /* exact */
  if (m != 0) {
    if (q < -22 || q > 22) return NULL;
    if (q < 0)
      v = v / nav_fast_pow10[-q];
    else
      v = v * nav_fast_pow10[q];
  }
  *out = neg ? -v : v;
  return p;
}

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/**
 * The fixed-point shape of nav_fast_number_scan() alone (printf's "%.Nf": [+-], 1-7 integer
 * digits, optionally a point and 1-15 fraction digits, at most 19 digits, no exponent), for text
 * in a padded buffer: the text ends at a byte that is not a digit (a line's terminating NUL),
 * after which at least 8 more bytes are readable, so every word is loaded without a length check.
 * The significand and the scale are those of nav_fast_number_scan(), so the value is the same
 * single correctly rounded division (strtod's value).
 * @return the end of the number and *out; NULL when the text at @p p has another shape (an
 *         exponent, more digits, no digit, ...), *out untouched.
 */
NAV_FAST_INLINE const char *nav_fast_fixed_scan_padded(const char *p, double *out) {
  const bool neg = *p == '-';
  p += neg | (*p == '+'); /* (no branch on the sign: it changes from field to field) */
  uint64_t wi;
  memcpy(&wi, p, 8);
  const unsigned li = nav_fast_digit_run(wi);
  if (li < 1u || li > 7u) return NULL;
  const uint64_t vi = nav_fast_digits_value(wi, li);
  const char *f = p + li;
  if (*f != '.') {
    if (*f == 'e' || *f == 'E') return NULL;
    *out = nav_fast_negate_if((double)vi, neg); /* exact: vi < 10^7 */
    return f;
  }
  ++f;
  uint64_t w1;
  memcpy(&w1, f, 8);
  unsigned nf = nav_fast_digit_run(w1);
  uint64_t m;
  if (nf >= 1u && nf <= 7u) {
    m = vi * nav_fast_pow10_u[nf] + nav_fast_digits_value(w1, nf);
  } else if (nf == 8u) {
    uint64_t w2;
    memcpy(&w2, f + 8, 8); /* f + 8 is at most the terminating byte */
    const unsigned n2 = nav_fast_digit_run(w2);
    if (n2 > 7u || li + 8u + n2 > 19u) return NULL;
    m = vi * nav_fast_pow10_u[8] + nav_fast_digits_value(w1, 8u);
    if (n2 > 0u) m = m * nav_fast_pow10_u[n2] + nav_fast_digits_value(w2, n2);
    nf = 8u + n2;
  } else {
    return NULL; /* "5." without fraction digits: the general scan */
  }
  if (m > ((uint64_t)1 << 53)) return NULL;
  const char *q = f + nf;
  if (*q == 'e' || *q == 'E') return NULL;
  /* m exact as a double; 0 / 10^nf is +0 as the general scan's 0 (no branch on the data) */
  *out = nav_fast_negate_if((double)m / nav_fast_pow10[nf], neg);
  return q;
}
#endif

#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
/**
 * The "%.12e" shape of nav_fast_number_scan() alone ([+-]d.dddddddddddde[+-]dd, |q| <= 22) for
 * text in a padded buffer: the text ends at a byte that is not a digit, after which at least 19
 * more bytes are readable (every byte of the shape is checked, so a shorter text fails at its
 * terminating byte). @return the end of the number and *out (nav_fast_number_scan()'s value);
 * NULL for any other text, *out untouched.
 */
NAV_FAST_INLINE const char *nav_fast_sci12_scan_padded(const char *p, double *out) {
  const bool neg = *p == '-';
  p += neg | (*p == '+');
  if (p[1] != '.' || (unsigned)(p[18] - '0') < 10u || !nav_fast_sci12_words(p, neg, out)) return NULL;
  return p + 18;
}
#endif

/**
 * Parse the whole of [s, end) as one number when the exact fast path applies.
 * @return true and *out = the correctly rounded value; false when the text is not exactly one
 *         such number or outside the fast path (the caller then uses strtod); *out is untouched.
 */
static inline bool nav_fast_number(const char *s, const char *end, double *out) {
  double v = 0.0;
  const char *p = nav_fast_number_scan(s, end, &v);
  if (p != end) return false;
  *out = v;
  return true;
}

#endif /* NAV_IO_FAST_NUMBER_H */
