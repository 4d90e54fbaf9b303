/**
 * @file line_layout.h
 * @brief Speculative field layout of fixed-point text lines (navcore_io internal; header-only so
 *        that the white-box test can include it). Used by the .nav reference reader (recorded.c).
 *
 * Files written by printf with fixed "%.Nf" formats have, line after line, the same bytes at the
 * same places except for the digits: the same field starts, signs, points and blanks. A layout
 * remembers one such line: which bytes are digits, every other byte exactly, and for each field
 * where its integer and fraction digits are. A new line is checked against it with whole-register
 * compares (SSE2, 16 bytes at a time, no branch per byte or per field): same length, a digit
 * wherever the layout has one, and the layout's byte everywhere else. When it holds, every field
 * is converted from its known place, and the fields do not wait on each other (the field-by-field
 * scan of fast_number.h has to find each field's end before it can start the next one).
 *
 * The value of each field is the one nav_fast_fixed_scan_padded() gives: the digits as an
 * integer M (at most 15 of them, so M < 10^15 < 2^53 is exact as a double), one correctly
 * rounded division by 10^nf (nf fraction digits; Clinger's exact case, i.e. strtod's value) and
 * the sign applied by flipping the sign bit. A line that passes the check has the same digit and
 * non-digit positions as the learned one, and therefore the same sign, digit counts and end of
 * every field for that scan too, so the two give the same bits.
 *
 * Requires a little-endian machine with SSE2 (x86-64); elsewhere nav_layout_learn() declines and
 * the caller keeps its field-by-field path.
 */
#ifndef NAV_IO_LINE_LAYOUT_H
#define NAV_IO_LINE_LAYOUT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "fast_number.h"

#if defined(__SSE2__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#include <emmintrin.h>
#define NAV_LAYOUT_ENABLED 1
#else
#define NAV_LAYOUT_ENABLED 0
#endif

/* Longest line a layout describes (bytes before the terminating NUL); the reference rows of the
 * shared data are 107-114 bytes. */
#define NAV_LAYOUT_MAX_LINE 127
#define NAV_LAYOUT_MAX_FIELDS 16
/* Digits of a field's significand a layout takes (M < 10^15 < 2^53: exact, no check needed). */
#define NAV_LAYOUT_MAX_DIGITS 15

/* One field of d = li + nf digits (li integer, nf fraction digits) starting at offset off. Its
 * first min(d, 8) digits form word A: the 8 bytes at off, with the bytes from the point on taken
 * from the 8 bytes at off + 1 (merge: the bytes kept from the first load), so that the point drops
 * out. The other d - 8 digits, if any, are fraction digits (li <= 7), the first of them at
 * off + 9 (digit 8, one byte after its place without the point): word B. Each word's digits are
 * moved to its top by a shift, and M = A, or A * mul + B (mul = 10^(d - 8)); value = M / div
 * (div = 10^nf). */
typedef struct nav_layout_field {
  uint64_t merge, mul;
  double div;
  uint16_t off, off_b;
  uint8_t shift_a, shift_b;
  bool has_b, neg;
} nav_layout_field;

typedef struct nav_line_layout {
  /* Per byte of the line (and of the words loaded past its end): 0xFF where the learned line had
   * a digit (digit), the learned byte elsewhere (byte), 0xFF at and after the line's end (any). */
  unsigned char digit[NAV_LAYOUT_MAX_LINE + 1];
  unsigned char byte[NAV_LAYOUT_MAX_LINE + 1];
  unsigned char any[NAV_LAYOUT_MAX_LINE + 1];
  size_t n;   /* length of the learned line */
  int chunks; /* 16-byte chunks that cover [0, n] */
  int count;  /* fields; 0: no layout */
  nav_layout_field f[NAV_LAYOUT_MAX_FIELDS];
} nav_line_layout;

static inline bool nav_layout_is_digit(char c) {
  return (unsigned)(c - '0') < 10u;
}

/**
 * Learn the layout of @p line (@p n bytes, NUL-terminated; reads line[0..n] only):
 * exactly @p want fields of printf's "%.Nf" shape ([+-], 1-7 integer digits, optionally a point
 * and 1-15 fraction digits, at most 15 digits in all), separated by blanks, none before the first
 * or after the last.
 * @return true when the line has that shape (the layout then describes it); false otherwise
 *         (L->count = 0: no line matches it).
 */
static inline bool nav_layout_learn(nav_line_layout *L, const char *line, size_t n, int want) {
  L->count = 0;
#if NAV_LAYOUT_ENABLED
  if (n > NAV_LAYOUT_MAX_LINE || want < 1 || want > NAV_LAYOUT_MAX_FIELDS) return false;
  size_t p = 0;
  for (int k = 0; k < want; ++k) {
    nav_layout_field *fd = &L->f[k];
    fd->neg = line[p] == '-';
    if (line[p] == '-' || line[p] == '+') ++p;
    const size_t si = p;
    while (nav_layout_is_digit(line[p]))
      ++p;
    const unsigned li = (unsigned)(p - si);
    if (li < 1u || li > 7u) return false;
    unsigned nf = 0;
    if (line[p] == '.') {
      const size_t sf = ++p;
      while (nav_layout_is_digit(line[p]))
        ++p;
      nf = (unsigned)(p - sf);
      if (nf < 1u || li + nf > NAV_LAYOUT_MAX_DIGITS) return false;
    }
    const unsigned d = li + nf, na = d < 8u ? d : 8u, nb = d - na;
    fd->off = (uint16_t)si;
    fd->off_b = (uint16_t)(si + 9u);
    fd->merge = nf && li < 8u ? ((uint64_t)1 << (8u * li)) - 1u : ~(uint64_t)0;
    fd->shift_a = (uint8_t)(8u * (8u - na));
    fd->shift_b = (uint8_t)(nb ? 8u * (8u - nb) : 0u);
    fd->has_b = nb > 0u;
    fd->mul = nav_fast_pow10_u[nb];
    fd->div = nav_fast_pow10[nf];
    if (k + 1 < want) {
      const char c = line[p];
      if (!(c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f')) return false;
      do
        ++p;
      while (line[p] == ' ' || line[p] == '\t' || line[p] == '\r' || line[p] == '\v' || line[p] == '\f');
    } else if (p != n) {
      return false;
    }
  }
  for (size_t i = 0; i <= NAV_LAYOUT_MAX_LINE; ++i) {
    const bool in = i < n, dig = in && nav_layout_is_digit(line[i]);
    L->digit[i] = dig ? 0xFFu : 0u;
    L->byte[i] = in && !dig ? (unsigned char)line[i] : 0u;
    L->any[i] = in ? 0u : 0xFFu;
  }
  L->n = n;
  L->chunks = (int)(n / 16u) + 1;
  L->count = want;
  return true;
#else
  (void)line;
  (void)n;
  (void)want;
  return false;
#endif
}

/**
 * Does @p line (@p n bytes, NUL-terminated, readable to n + 16) have the learned layout: the same
 * length, a digit wherever the learned line had one and the learned byte everywhere else?
 * Branch-free over the bytes: one compare per 16 bytes, the chunk count being the layout's.
 */
static inline bool nav_layout_match(const nav_line_layout *L, const char *line, size_t n) {
#if NAV_LAYOUT_ENABLED
  if (L->count == 0 || n != L->n) return false;
  const __m128i lo = _mm_set1_epi8('0' - 1), hi = _mm_set1_epi8('9' + 1);
  __m128i ok = _mm_set1_epi8(-1);
  for (int c = 0; c < L->chunks; ++c) {
    const __m128i x = _mm_loadu_si128((const __m128i *)(const void *)(line + 16 * c));
    const __m128i d = _mm_loadu_si128((const __m128i *)(const void *)(L->digit + 16 * c));
    const __m128i b = _mm_loadu_si128((const __m128i *)(const void *)(L->byte + 16 * c));
    const __m128i a = _mm_loadu_si128((const __m128i *)(const void *)(L->any + 16 * c));
    /* (signed compares: bytes >= 0x80 are negative, so not digits) */
    const __m128i isdig = _mm_and_si128(_mm_cmpgt_epi8(x, lo), _mm_cmplt_epi8(x, hi));
    const __m128i same = _mm_cmpeq_epi8(x, b);
    ok = _mm_and_si128(ok, _mm_or_si128(_mm_or_si128(_mm_and_si128(d, isdig), _mm_andnot_si128(d, same)), a));
  }
  return _mm_movemask_epi8(ok) == 0xFFFF;
#else
  (void)L;
  (void)line;
  (void)n;
  return false;
#endif
}

#if NAV_LAYOUT_ENABLED
/* The value of the digits of word w, moved to its top by @p shift (the bytes below become leading
 * zeros, those after the digits are shifted out), combined by the
 * multiply-shift steps of fast_number.h. */
NAV_FAST_INLINE uint64_t nav_layout_digits(uint64_t w, unsigned shift) {
  uint64_t d = (w - 0x3030303030303030ull) << shift;
  d = (d * 10u) + (d >> 8);
  d = (((d & 0x000000FF000000FFull) * (100u + (1000000ull << 32))) +
       (((d >> 16) & 0x000000FF000000FFull) * (1u + (10000ull << 32)))) >>
      32;
  return d & 0xFFFFFFFFu;
}
#endif

/**
 * Convert the @p count fields (the layout's count; a constant at the call site lets the compiler
 * unroll) of a line that nav_layout_match() accepted into v[0..count-1]. The words are loaded up
 * to 16 bytes past a field's start, inside the line's readable padding.
 */
NAV_FAST_INLINE void nav_layout_convert(const nav_line_layout *L, const char *line, int count, double *v) {
#if NAV_LAYOUT_ENABLED
  for (int k = 0; k < count; ++k) {
    const nav_layout_field *fd = &L->f[k];
    uint64_t w0, w1;
    memcpy(&w0, line + fd->off, 8);
    memcpy(&w1, line + fd->off + 1, 8);
    uint64_t m = nav_layout_digits((w0 & fd->merge) | (w1 & ~fd->merge), fd->shift_a);
    /* (a branch on the layout, not on the text: the same for every row that matches, so predicted) */
    if (fd->has_b) {
      uint64_t wb;
      memcpy(&wb, line + fd->off_b, 8);
      m = m * fd->mul + nav_layout_digits(wb, fd->shift_b);
    }
    /* m < 10^15 < 2^53: exact (converted as a signed integer, one instruction) */
    v[k] = nav_fast_negate_if((double)(int64_t)m / fd->div, fd->neg);
  }
#else
  (void)L;
  (void)line;
  (void)count;
  (void)v;
#endif
}

#endif /* NAV_IO_LINE_LAYOUT_H */
