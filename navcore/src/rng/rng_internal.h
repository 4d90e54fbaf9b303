/**
 * @file rng_internal.h
 * @brief Private inline forms of the generator for the per-sample sensor models (rng.c): the
 *        xoshiro256** step, the ziggurat's fast path and the batch of normal draws, so that a
 *        caller draws its deviates without a call per deviate. Never installed.
 */
#ifndef NAV_RNG_INTERNAL_H
#define NAV_RNG_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "navcore/nav_rng.h"

/** Layers of the ziggurat (rng.c explains the tables). */
#define NAV_RNG_ZIG_LAYERS 256

/** Right edges of the ziggurat's layers (rng.c). */
extern const double nav_rng_zig_x[NAV_RNG_ZIG_LAYERS + 1];

/** The ziggurat after a first word @p bits that was not accepted at once (rng.c): the wedge, the
 *  tail and the retries; returns the deviate nav_rng_gauss() returns for that word. */
double nav_rng_gauss_slow(nav_rng *r, uint64_t bits);

/** One step of xoshiro256** (Blackman and Vigna's reference xoshiro256starstar.c, public
 *  domain). The ** scrambler makes every output bit usable, including the low byte the ziggurat
 *  takes as its layer index (the + variant's low bits would not do). */
static inline uint64_t nav_rng_next_inline(nav_rng *r) {
  uint64_t *s = r->s;
  const uint64_t m = s[1] * 5u;
  const uint64_t result = ((m << 7) | (m >> 57)) * 9u;
  const uint64_t t = s[1] << 17;
  s[2] ^= s[0];
  s[3] ^= s[1];
  s[1] ^= s[2];
  s[0] ^= s[3];
  s[2] ^= t;
  s[3] = (s[3] << 45) | (s[3] >> 19);
  return result;
}

/**
 * One standard normal deviate, the value and the words of nav_rng_gauss(): the accept-at-once
 * test of the first word inline, everything else in nav_rng_gauss_slow (which repeats that test on
 * the same word: the sequence of words consumed and the value returned are those of a single
 * loop). Disjoint bits for layer (0-7), sign (8) and abscissa (11-63): Doornik ("An improved
 * ziggurat method to generate normal random samples", Nuffield College, 2005) showed that sharing
 * bits between the layer index and the abscissa correlates them.
 */
static inline double nav_rng_gauss_inline(nav_rng *r) {
  const uint64_t bits = nav_rng_next_inline(r);
  const unsigned layer = (unsigned)(bits & 0xffu);
  /* bits >> 11 < 2^53 is exact as a signed integer too, whose conversion to double is one
   * instruction (the unsigned one is a branchy sequence without AVX-512): the same value. */
  const double x = (double)(int64_t)(bits >> 11) * 0x1.0p-53 * nav_rng_zig_x[layer];
  /* Inside the part of the layer that lies wholly under the curve: accept at once, with the sign
   * bit 8 copied into the IEEE sign bit: without a branch (the sign is a coin flip, which a
   * branch predictor cannot learn) and exactly the value (1 - 2 bit8) * x of the slow path, -0.0
   * included (x >= 0 here). */
  if (x < nav_rng_zig_x[layer + 1]) {
    uint64_t xb;
    memcpy(&xb, &x, sizeof xb);
    xb |= (bits & UINT64_C(0x100)) << 55;
    double v;
    memcpy(&v, &xb, sizeof v);
    return v;
  }
  return nav_rng_gauss_slow(r, bits);
}

/**
 * Standard normal deviates from several streams in one call: out[s * per_stream + d] is the d-th
 * draw of stream r[s], exactly the value nav_rng_gauss(&r[s]) would return at that point (same
 * words consumed, same result). Streams are independent, so taking them one after the other
 * changes nothing but the call count: the sensor models draw a triad's 3 or 6 deviates per sample
 * inline, and with constant counts the three streams' generator steps interleave.
 * @param[in,out] r           n_streams initialised streams
 * @param[in]     n_streams   number of streams
 * @param[in]     per_stream  draws per stream, in order
 * @param[out]    out         n_streams * per_stream deviates, N(0, 1)
 */
static inline void nav_rng_gauss_streams(nav_rng *r, size_t n_streams, size_t per_stream, double *out) {
  for (size_t s = 0; s < n_streams; ++s)
    for (size_t d = 0; d < per_stream; ++d)
      out[s * per_stream + d] = nav_rng_gauss_inline(&r[s]);
}

/**
 * Up to four streams side by side for the per-sample sensor models: word w of lane i's
 * xoshiro256** state is s[w][i] (structure of arrays, so one vector operation steps every lane).
 * A lane that holds no stream is all zero, which xoshiro maps to itself: it yields the word 0,
 * the deviate +0.0, and is never read.
 */
typedef struct nav_rng_lanes {
  uint64_t s[4][4];
} nav_rng_lanes;

/** Load @p n <= 4 streams into lanes 0..n-1 (the others zero). */
static inline void nav_rng_lanes_pack(nav_rng_lanes *p, const nav_rng *r, size_t n) {
  memset(p, 0, sizeof *p);
  for (size_t i = 0; i < n; ++i)
    for (size_t w = 0; w < 4; ++w)
      p->s[w][i] = r[i].s[w];
}

/** Lane @p i as a stream (the inverse of nav_rng_lanes_pack for that lane). */
static inline nav_rng nav_rng_lanes_get(const nav_rng_lanes *p, size_t i) {
  nav_rng r;
  for (size_t w = 0; w < 4; ++w)
    r.s[w] = p->s[w][i];
  return r;
}

#if defined(__GNUC__) && defined(__x86_64__)
typedef uint64_t nav_rng_u64x4 __attribute__((vector_size(32)));
typedef int64_t nav_rng_i64x4 __attribute__((vector_size(32)));
typedef double nav_rng_f64x4 __attribute__((vector_size(32)));
typedef double nav_rng_f64x2 __attribute__((vector_size(16)));

/**
 * One standard normal deviate from each of the first @p n lanes: out[i] is exactly the value
 * nav_rng_gauss() returns for lane i's stream at that point (same words consumed), so drawing
 * from the lanes changes nothing but the speed. Lanes >= n are stepped too (all zero: no change).
 *
 * The generator step (nav_rng_next_inline) is done on all lanes at once in integer vector
 * operations: the multiplications by 5 and 9 as shifts and adds (the same results modulo 2^64).
 * The ziggurat's accept-at-once test is the same IEEE arithmetic: the 53-bit integer bits >> 11 is
 * converted to double exactly in two halves (hi 2^32 + lo, each exact from an exponent-bias
 * trick, and the sum exact because it is an integer below 2^53), then scaled by 2^-53 (exact) and
 * multiplied by the layer's edge (one rounding, as in the scalar form). A lane whose first word is
 * not accepted at once continues in nav_rng_gauss_slow on that lane's stream, as the scalar path
 * does (1.2 % of the draws).
 */
static inline void nav_rng_lanes_gauss(nav_rng_lanes *p, size_t n, double out[4]) {
  nav_rng_u64x4 s0, s1, s2, s3;
  memcpy(&s0, p->s[0], sizeof s0);
  memcpy(&s1, p->s[1], sizeof s1);
  memcpy(&s2, p->s[2], sizeof s2);
  memcpy(&s3, p->s[3], sizeof s3);
  const nav_rng_u64x4 m = s1 + (s1 << 2);
  const nav_rng_u64x4 rm = (m << 7) | (m >> 57);
  const nav_rng_u64x4 bits = rm + (rm << 3);
  const nav_rng_u64x4 t = s1 << 17;
  s2 ^= s0;
  s3 ^= s1;
  s1 ^= s2;
  s0 ^= s3;
  s2 ^= t;
  s3 = (s3 << 45) | (s3 >> 19);
  memcpy(p->s[0], &s0, sizeof s0);
  memcpy(p->s[1], &s1, sizeof s1);
  memcpy(p->s[2], &s2, sizeof s2);
  memcpy(p->s[3], &s3, sizeof s3);

  const nav_rng_u64x4 v = bits >> 11;
  const nav_rng_u64x4 lo = (v & 0xffffffffu) | 0x4330000000000000u; /* 2^52 + lo */
  const nav_rng_u64x4 hi = (v >> 32) | 0x4530000000000000u;         /* 2^84 + hi 2^32 */
  nav_rng_f64x4 dlo, dhi;
  memcpy(&dlo, &lo, sizeof dlo);
  memcpy(&dhi, &hi, sizeof dhi);
  const nav_rng_f64x4 dv = (dhi - 0x1.0p84) + (dlo - 0x1.0p52);
  const nav_rng_f64x4 edge = {nav_rng_zig_x[bits[0] & 0xffu], nav_rng_zig_x[bits[1] & 0xffu],
                              nav_rng_zig_x[bits[2] & 0xffu], nav_rng_zig_x[bits[3] & 0xffu]};
  const nav_rng_f64x4 next = {nav_rng_zig_x[(bits[0] & 0xffu) + 1], nav_rng_zig_x[(bits[1] & 0xffu) + 1],
                              nav_rng_zig_x[(bits[2] & 0xffu) + 1], nav_rng_zig_x[(bits[3] & 0xffu) + 1]};
  const nav_rng_f64x4 x = dv * 0x1.0p-53 * edge;
  const nav_rng_i64x4 ok = x < next;
  nav_rng_u64x4 xb;
  memcpy(&xb, &x, sizeof xb);
  xb |= (bits & 0x100u) << 55;
  memcpy(out, &xb, sizeof xb);
  /* One test for the usual case, every lane accepted at once (95 % of the vectors). */
  if (__builtin_expect((ok[0] & ok[1] & ok[2] & ok[3]) != 0, 1)) return;
  for (size_t i = 0; i < n; ++i)
    if (!ok[i]) {
      nav_rng r = nav_rng_lanes_get(p, i);
      out[i] = nav_rng_gauss_slow(&r, bits[i]);
      for (size_t w = 0; w < 4; ++w)
        p->s[w][i] = r.s[w];
    }
}
#else
static inline void nav_rng_lanes_gauss(nav_rng_lanes *p, size_t n, double out[4]) {
  for (size_t i = 0; i < 4; ++i) {
    nav_rng r = nav_rng_lanes_get(p, i);
    out[i] = i < n ? nav_rng_gauss_inline(&r) : 0.0;
    for (size_t w = 0; w < 4; ++w)
      p->s[w][i] = r.s[w];
  }
}
#endif

#endif
