/**
 * @file rng_internal.h
 * @brief Private batch form of the normal generator for the per-sample sensor models (rng.c).
 *        Never installed.
 */
#ifndef NAV_RNG_INTERNAL_H
#define NAV_RNG_INTERNAL_H

#include <stddef.h>

#include "navcore/nav_rng.h"

/**
 * Standard normal deviates from several streams in one call: out[s * per_stream + d] is the d-th
 * draw of stream r[s], exactly the value nav_rng_gauss(&r[s]) would return at that point (same
 * words consumed, same result). Streams are independent, so taking them one after the other
 * changes nothing but the call count: the sensor models draw a triad's 3 or 6 deviates per sample
 * with one call instead of one call per deviate (the call and its frame cost as much as the
 * accepted fast path of the ziggurat).
 * @param[in,out] r           n_streams initialised streams
 * @param[in]     n_streams   number of streams
 * @param[in]     per_stream  draws per stream, in order
 * @param[out]    out         n_streams * per_stream deviates, N(0, 1)
 */
void nav_rng_gauss_streams(nav_rng *r, size_t n_streams, size_t per_stream, double *out);

#endif
