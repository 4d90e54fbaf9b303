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

#endif
