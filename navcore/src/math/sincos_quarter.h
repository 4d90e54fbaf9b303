/*
 * sin and cos of an angle within a quarter turn of zero (|x| <= pi/4): navcore's own kernel, in
 * a scalar form and a four-lane form with the same operations in the same order, so that both
 * give the same bits (lanes4.h). The strapdown's half latitude (|lat / 2| < pi/4) takes it at
 * every step, one run at a time or four runs in lockstep; with glibc's sin and cos the lockstep
 * had to call them lane by lane (a vector math library does not return glibc's bits).
 *
 * Taylor series in z = x^2, evaluated by Horner's rule:
 *   sin x = x + x z (S1 + z (S2 + ... + z S8)),       S_k = (-1)^k / (2k + 1)!
 *   cos x = 1 - (z / 2 - z^2 (C2 + z (C3 + ... + z C8))),  C_k = (-1)^k / (2k)!
 * At |x| = pi/4 the first omitted terms are x^19 / 19! = 8e-20 and x^18 / 18! = 2e-18, far below
 * half an ulp of the results (>= 0.707, ulp 1.1e-16). The rounding errors stay below one ulp:
 * in sin the correction x z (...) is at most a tenth of x; in cos the bracket is formed first,
 * with z / 2 exact (x split into a 26-bit head and a tail, whose square goes into the small
 * term), and subtracted from 1 once. test_math measures the error against the
 * long-double sinl and cosl (at most 1 ulp required; the figure it prints is the measured
 * maximum).
 */
#ifndef NAV_SINCOS_QUARTER_H
#define NAV_SINCOS_QUARTER_H

#include <stdint.h>
#include <string.h>

#include "math/lanes4.h"
#include "nav_clones.h"

/* The kernel's domain, |x| <= pi/4 with a margin of rounding (the series holds far beyond). */
#define NAV_SINCOS_QUARTER_MAX 0.7853981633974484

#define NAV_SQ_S1 (-1.66666666666666666667e-01) /* -1/3! */
#define NAV_SQ_S2 8.33333333333333333333e-03    /* 1/5! */
#define NAV_SQ_S3 (-1.98412698412698412698e-04) /* -1/7! */
#define NAV_SQ_S4 2.75573192239858906526e-06    /* 1/9! */
#define NAV_SQ_S5 (-2.50521083854417187751e-08) /* -1/11! */
#define NAV_SQ_S6 1.60590438368216145994e-10    /* 1/13! */
#define NAV_SQ_S7 (-7.64716373181981647590e-13) /* -1/15! */
#define NAV_SQ_S8 2.81145725434552076320e-15    /* 1/17! */
#define NAV_SQ_C2 4.16666666666666666667e-02    /* 1/4! */
#define NAV_SQ_C3 (-1.38888888888888888889e-03) /* -1/6! */
#define NAV_SQ_C4 2.48015873015873015873e-05    /* 1/8! */
#define NAV_SQ_C5 (-2.75573192239858906526e-07) /* -1/10! */
#define NAV_SQ_C6 2.08767569878680989792e-09    /* 1/12! */
#define NAV_SQ_C7 (-1.14707455977297247139e-11) /* -1/14! */
#define NAV_SQ_C8 4.77947733238738529744e-14    /* 1/16! */

/* sin x and cos x for |x| <= NAV_SINCOS_QUARTER_MAX (outside it the series loses accuracy:
 * callers take libm's sin and cos there). */
NAV_CLONE_INLINE void nav_sincos_quarter(double x, double *s, double *c) {
  /* x = xh + xl exactly, xh with the low 27 bits of its significand cleared, so xh^2 is exact
   * and z / 2 enters cos's bracket without a rounding (z = xh^2 + (2 xh xl + xl^2)). */
  uint64_t b;
  memcpy(&b, &x, sizeof b);
  b &= ~UINT64_C(0x7ffffff);
  double xh;
  memcpy(&xh, &b, sizeof xh);
  const double xl = x - xh;
  const double zh = xh * xh, zl = (xh + xh) * xl + xl * xl;
  const double z = zh + zl;
  const double ps =
      NAV_SQ_S1 +
      z * (NAV_SQ_S2 +
           z * (NAV_SQ_S3 +
                z * (NAV_SQ_S4 + z * (NAV_SQ_S5 + z * (NAV_SQ_S6 + z * (NAV_SQ_S7 + z * NAV_SQ_S8))))));
  const double pc =
      NAV_SQ_C2 +
      z * (NAV_SQ_C3 + z * (NAV_SQ_C4 + z * (NAV_SQ_C5 + z * (NAV_SQ_C6 + z * (NAV_SQ_C7 + z * NAV_SQ_C8)))));
  *s = x + (x * z) * ps;
  *c = 1.0 - (0.5 * zh - ((z * z) * pc - 0.5 * zl));
}

/* nav_sincos_quarter() lane by lane: the same operations, the same bits in every lane. */
NAV_L4_INLINE void nav_sincos_quarter4(nav_l4 x, nav_l4 *s, nav_l4 *c) {
  const nav_m4 keep = {~INT64_C(0x7ffffff), ~INT64_C(0x7ffffff), ~INT64_C(0x7ffffff), ~INT64_C(0x7ffffff)};
  const nav_l4 xh = (nav_l4)((nav_m4)x & keep);
  const nav_l4 xl = x - xh;
  const nav_l4 zh = xh * xh, zl = (xh + xh) * xl + xl * xl;
  const nav_l4 z = zh + zl;
  const nav_l4 ps =
      l4_splat(NAV_SQ_S1) +
      z * (l4_splat(NAV_SQ_S2) +
           z * (l4_splat(NAV_SQ_S3) +
                z * (l4_splat(NAV_SQ_S4) +
                     z * (l4_splat(NAV_SQ_S5) +
                          z * (l4_splat(NAV_SQ_S6) + z * (l4_splat(NAV_SQ_S7) + z * l4_splat(NAV_SQ_S8)))))));
  const nav_l4 pc =
      l4_splat(NAV_SQ_C2) +
      z * (l4_splat(NAV_SQ_C3) +
           z * (l4_splat(NAV_SQ_C4) +
                z * (l4_splat(NAV_SQ_C5) +
                     z * (l4_splat(NAV_SQ_C6) + z * (l4_splat(NAV_SQ_C7) + z * l4_splat(NAV_SQ_C8))))));
  *s = x + (x * z) * ps;
  *c = l4_splat(1.0) - (l4_splat(0.5) * zh - ((z * z) * pc - l4_splat(0.5) * zl));
}

#endif /* NAV_SINCOS_QUARTER_H */
