/*
 * atan2 and hypot for the replay's errors (navcore_io internal, used by replay_errors.h; header-only
 * so that the white-box tests can include it): a scalar form and a four-lane form with the same
 * IEEE operations in the same order, so both give the same bits. The replay scores every IMU epoch
 * (193 034 on the shared long drive), four atan2 and two hypot each (the attitude angle, the
 * three Euler angles of the estimate, the horizontal position error); glibc's atan2 and hypot took
 * about 9 % of the whole replay's CPU time, and a vector library would not return their bits, so
 * the four-epoch path had to call them lane by lane.
 *
 * atan2(y, x) for non-zero x and y with max(|x|, |y|) in [2^-900, 2^960] (zeros, infinities, NaN and
 * the extremes go to libm's atan2, in both forms, which then agree as well):
 *   num / den = min(|x|, |y|) / max(|x|, |y|) in (0, 1]; c = 0 when the ratio r is below 1/8, else
 *   c = floor(64 r) / 64; atan(num / den) = atan c + atan t with t = (num - c den) / (den + c num) in
 *   [0, 1/8]. With den split into a 26-bit head and its tail, c den is formed exactly and
 *   num - c den has one rounding (num and c den are within a factor of two of each other, so the
 *   first subtraction is exact); the division's own rounding error is recovered from its exact
 *   remainder (Dekker's product in halves), so t + tc carries t to about 2^-100. atan c comes from a
 *   table of head and tail doubles (atan(k/64) to 113 bits, from libquadmath's atanq) and
 *   atan t = t + t z (A1 + z (A2 + ... + z A9)), z = t^2, A_n = (-1)^n / (2n + 1): the Taylor series,
 *   whose first omitted term t^21 / 21 is below 2^-64 t at t = 1/8. Both parts have the sign of r,
 *   so they add without cancellation, and above r = 1/8 the reduced part is at most a seventh of
 *   the result, so its rounding errors weigh little (an eighth at most). The octant then gives base + sg atan
 * r with base 0, pi/2 or pi and sg = +/-1 (pi and pi/2 as head and tail), and the sign of y. hypot(x, y) when
 * max(|x|, |y|) lies in [2^-500, 2^500] (libm's hypot otherwise): x^2 + y^2 exactly as a sum of four doubles
 * (Dekker's squares, Knuth's two-sum), h = sqrt of its leading double, then one Newton step h + (x^2 + y^2 -
 * h^2) / 2h with h^2 also exact, which leaves the rounding of the last addition.
 *
 * test_err_math measures both against long double over millions of arguments (the bounds it
 * asserts and the maxima it prints are in ulps of the result) and checks the lanes bit for bit.
 */
#ifndef NAV_IO_ERR_MATH_H
#define NAV_IO_ERR_MATH_H

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <string.h>

/* atan(k / 64), k = 0..64, as head + tail (the head is the double nearest to the value; rows 1 to 7
 * are not used: below 1/8 the series takes the whole ratio). */
static const double em_atan_tab[65][2] = {
    {0x0p+0, 0x0p+0},
    {0x1.fff555bbb729bp-7, -0x1.220c39d4dff5p-61},
    {0x1.ffd55bba97625p-6, -0x1.5ec431444912cp-60},
    {0x1.7fb818430da2ap-5, -0x1.86ef8f794f105p-63},
    {0x1.ff55bb72cfdeap-5, -0x1.c934d86d23f1dp-60},
    {0x1.3f59f0e7c559dp-4, 0x1.ac4ce285df847p-58},
    {0x1.7ee182602f10fp-4, -0x1.cfb654c0c3d98p-58},
    {0x1.be39ebe6f07c3p-4, 0x1.f7b8f29a05987p-58},
    {0x1.fd5ba9aac2f6ep-4, -0x1.cd37686760c17p-59},
    {0x1.1e1fafb043727p-3, -0x1.b485914dacf8cp-59},
    {0x1.3d6eee8c6626cp-3, 0x1.61a3b0ce9281bp-57},
    {0x1.5c9811e3ec26ap-3, -0x1.054ab2c010f3dp-58},
    {0x1.7b97b4bce5b02p-3, 0x1.347b0b4f881cap-58},
    {0x1.9a6a8e96c8626p-3, 0x1.cf601e7b4348ep-59},
    {0x1.b90d7529260a2p-3, 0x1.17b10d2e0e5aap-61},
    {0x1.d77d5df205736p-3, 0x1.c648d1534597ep-57},
    {0x1.f5b75f92c80ddp-3, 0x1.8ab6e3cf7afbdp-57},
    {0x1.09dc597d86362p-2, 0x1.62e47390cb865p-56},
    {0x1.18bf5a30bf178p-2, 0x1.30ca4748b1bf8p-57},
    {0x1.278372057ef46p-2, -0x1.077cdd36dfc81p-56},
    {0x1.362773707ebccp-2, -0x1.963a544b672d8p-57},
    {0x1.44aa436c2af0ap-2, -0x1.5d5e43c55b3bap-56},
    {0x1.530ad9951cd4ap-2, -0x1.2566480884082p-57},
    {0x1.614840309cfe2p-2, -0x1.a725715711fp-56},
    {0x1.6f61941e4def1p-2, -0x1.c63aae6f6e918p-56},
    {0x1.7d5604b63b3f7p-2, 0x1.69c885c2b249ap-56},
    {0x1.8b24d394a1b25p-2, 0x1.b6d0ba3748fa8p-56},
    {0x1.98cd5454d6b18p-2, 0x1.9e6c988fd0a77p-56},
    {0x1.a64eec3cc23fdp-2, -0x1.24dec1b50b7ffp-56},
    {0x1.b3a911da65c6cp-2, 0x1.ae187b1ca504p-56},
    {0x1.c0db4c94ec9fp-2, -0x1.cc1ce70934c34p-56},
    {0x1.cde53432c1351p-2, -0x1.a2cfa4418f1adp-56},
    {0x1.dac670561bb4fp-2, 0x1.a2b7f222f65e2p-56},
    {0x1.e77eb7f175a34p-2, 0x1.0e53dc1bf3435p-56},
    {0x1.f40dd0b541418p-2, -0x1.a3992dc382a23p-57},
    {0x1.0039c73c1a40cp-1, -0x1.b32c949c9d593p-55},
    {0x1.0657e94db30dp-1, -0x1.d5b495f6349e6p-56},
    {0x1.0c6145b5b43dap-1, 0x1.974fa13b5404fp-58},
    {0x1.1255d9bfbd2a9p-1, -0x1.2bdaee1c0ee35p-58},
    {0x1.1835a88be7c13p-1, 0x1.c621cec00c301p-55},
    {0x1.1e00babdefeb4p-1, -0x1.928df287a668fp-58},
    {0x1.23b71e2cc9e6ap-1, 0x1.c421c9f38224ep-57},
    {0x1.2958e59308e31p-1, -0x1.09e73b0c6c087p-56},
    {0x1.2ee628406cbcap-1, 0x1.c5d5e9ff0cf8dp-55},
    {0x1.345f01cce37bbp-1, 0x1.1021137c71102p-55},
    {0x1.39c391cd4171ap-1, -0x1.2304331d8bf46p-55},
    {0x1.3f13fb89e96f4p-1, 0x1.ecf8b492644fp-56},
    {0x1.445065b795b56p-1, -0x1.f76d0163f79c8p-56},
    {0x1.4978fa3269ee1p-1, 0x1.2419a87f2a458p-56},
    {0x1.4e8de5bb6ec04p-1, 0x1.4a33dbeb3796cp-55},
    {0x1.538f57b89061fp-1, -0x1.1bb74abda520cp-55},
    {0x1.587d81f732fbbp-1, -0x1.5e5c9d8c5a95p-56},
    {0x1.5d58987169b18p-1, 0x1.0028e4bc5e7cap-57},
    {0x1.6220d115d7b8ep-1, -0x1.2b785350ee8c1p-57},
    {0x1.66d663923e087p-1, -0x1.6ea6febe8bbbap-56},
    {0x1.6b798920b3d99p-1, -0x1.a80386188c50ep-55},
    {0x1.700a7c5784634p-1, -0x1.8c34d25aadef6p-56},
    {0x1.748978fba8e0fp-1, 0x1.7b2a6165884a2p-59},
    {0x1.78f6bbd5d315ep-1, 0x1.406a08980374p-55},
    {0x1.7d528289fa093p-1, 0x1.560821e2f3aa9p-55},
    {0x1.819d0b7158a4dp-1, -0x1.bf76229d3b917p-56},
    {0x1.85d69576cc2c5p-1, 0x1.6b66e7fc8b8c4p-57},
    {0x1.89ff5ff57f1f8p-1, -0x1.55b9a5e177a1bp-55},
    {0x1.8e17aa99cc05ep-1, -0x1.ec182ab042f61p-56},
    {0x1.921fb54442d18p-1, 0x1.1a62633145c07p-55},
};
#define EM_PI_HI 0x1.921fb54442d18p+1
#define EM_PI_LO 0x1.1a62633145c07p-53
#define EM_PIO2_HI 0x1.921fb54442d18p+0
#define EM_PIO2_LO 0x1.1a62633145c07p-54
#define EM_A1 (-1.0 / 3.0)
#define EM_A2 (1.0 / 5.0)
#define EM_A3 (-1.0 / 7.0)
#define EM_A4 (1.0 / 9.0)
#define EM_A5 (-1.0 / 11.0)
#define EM_A6 (1.0 / 13.0)
#define EM_A7 (-1.0 / 15.0)
#define EM_A8 (1.0 / 17.0)
#define EM_A9 (-1.0 / 19.0)

#define EM_INLINE static inline __attribute__((always_inline))

/* Whether atan2 takes the kernel (else libm): both arguments non-zero, the larger within
 * [2^-900, 2^960] (so that the splits and c den neither overflow nor lose bits below the normals). */
EM_INLINE bool em_atan2_kernel(double ay, double ax) {
  return ax > 0.0 && ay > 0.0 && ax <= 0x1p960 && ay <= 0x1p960 && (ax >= 0x1p-900 || ay >= 0x1p-900);
}

/* v with the low 27 bits of its significand cleared: for the table's c = k / 64 (at most seven
 * significant bits) the products c head and c (v - head) are exact. */
EM_INLINE double em_head(double v) {
  uint64_t b;
  memcpy(&b, &v, sizeof b);
  b &= ~UINT64_C(0x7ffffff);
  memcpy(&v, &b, sizeof v);
  return v;
}

/* Veltkamp's split v = h + l, h with 26 significant bits and l with at most 26: the products of
 * two such halves are exact (|v| < 2^995). */
EM_INLINE void em_split(double v, double *h, double *l) {
  const double pv = v * 134217729.0; /* 2^27 + 1 */
  *h = pv - (pv - v);
  *l = v - *h;
}

/* v^2 - vv exactly, for vv = v * v rounded (Dekker's square in the halves of em_split). */
EM_INLINE double em_sq_err(double v, double vv) {
  double h, l;
  em_split(v, &h, &l);
  return (((h * h - vv) + h * l) + h * l) + l * l;
}

EM_INLINE double em_atan2(double y, double x) {
  const double ax = fabs(x), ay = fabs(y);
  if (!em_atan2_kernel(ay, ax)) return atan2(y, x);
  const bool swap = ay > ax, neg = x < 0.0;
  const double num = swap ? ax : ay, den = swap ? ay : ax;
  const double r = num / den;
  const int k = r < 0.125 ? 0 : (int)(r * 64.0);
  const double c = (double)k * 0.015625;
  const double dh = em_head(den), dl = den - dh;
  const double nn = (num - c * dh) - c * dl, dd = den + c * num;
  const double t = nn / dd;
  /* The division's remainder nn - t dd, exact (Dekker's product t dd in halves of 26 bits), gives
   * its rounding error: t + tc is nn / dd to about 2^-100. */
  double th, tl, qh, ql;
  em_split(t, &th, &tl);
  em_split(dd, &qh, &ql);
  const double tc = ((((nn - th * qh) - th * ql) - tl * qh) - tl * ql) / dd;
  const double z = t * t;
  const double p =
      t *
      (z *
       (EM_A1 +
        z * (EM_A2 +
             z * (EM_A3 + z * (EM_A4 + z * (EM_A5 + z * (EM_A6 + z * (EM_A7 + z * (EM_A8 + z * EM_A9)))))))));
  const double s = t + ((p + em_atan_tab[k][1]) + tc);
  /* The octant: 0 + a, pi/2 - a, pi/2 + a or pi - a for a = atan(num / den) = head + s. */
  const double bh = swap ? EM_PIO2_HI : (neg ? EM_PI_HI : 0.0);
  const double bl = swap ? EM_PIO2_LO : (neg ? EM_PI_LO : 0.0);
  const double sg = swap != neg ? -1.0 : 1.0;
  const double res = bh + sg * (em_atan_tab[k][0] + (s + sg * bl));
  return copysign(res, y);
}

EM_INLINE bool em_hypot_kernel(double ax, double ay) {
  return ax <= 0x1p500 && ay <= 0x1p500 && (ax >= 0x1p-500 || ay >= 0x1p-500);
}

EM_INLINE double em_hypot(double x, double y) {
  const double ax = fabs(x), ay = fabs(y);
  if (!em_hypot_kernel(ax, ay)) return hypot(x, y);
  /* s + se + xe + ye = x^2 + y^2 exactly (Dekker's squares, Knuth's sum), h = sqrt(s), then one
   * Newton step h + (x^2 + y^2 - h^2) / 2h with h^2 = h2 + he exact as well. */
  const double xx = ax * ax, yy = ay * ay;
  const double xe = em_sq_err(ax, xx), ye = em_sq_err(ay, yy);
  const double s = xx + yy;
  const double bv = s - xx;
  const double se = (xx - (s - bv)) + (yy - bv);
  const double h = sqrt(s);
  const double h2 = h * h;
  const double he = em_sq_err(h, h2);
  const double res = (((s - h2) - he) + se) + (xe + ye);
  return h + res / (h + h);
}
/* The four-lane forms. Four-double vectors without AVX are passed in memory, not in a register:
 * a note on the ABI that does not concern these functions, which are inlined and never cross a
 * library boundary. */
typedef double em_v4 __attribute__((vector_size(32)));
typedef long long em_m4 __attribute__((vector_size(32)));
typedef int em_i4 __attribute__((vector_size(16)));
#pragma GCC diagnostic ignored "-Wpsabi"

EM_INLINE em_m4 em_bits(em_v4 a) {
  em_m4 b;
  __builtin_memcpy(&b, &a, sizeof b);
  return b;
}

EM_INLINE em_v4 em_dbl(em_m4 b) {
  em_v4 a;
  __builtin_memcpy(&a, &b, sizeof a);
  return a;
}

/* Lane by lane m ? a : b (m: all ones or zero per lane). */
EM_INLINE em_v4 em_sel(em_m4 m, em_v4 a, em_v4 b) {
  return em_dbl((em_bits(a) & m) | (em_bits(b) & ~m));
}

EM_INLINE em_v4 em_abs4(em_v4 a) {
  return em_dbl(em_bits(a) & 0x7fffffffffffffffLL);
}

EM_INLINE bool em_all(em_m4 m) {
  return (m[0] & m[1] & m[2] & m[3]) != 0;
}

/* sqrt in lanes: SSE2's packed square root (IEEE, as the scalar one) in two halves, which the
 * AVX2 build joins; lane by lane elsewhere. */
EM_INLINE em_v4 em_sqrt4(em_v4 a) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  typedef double em_v2 __attribute__((vector_size(16)));
  const em_v2 lo = {a[0], a[1]}, hi = {a[2], a[3]};
  const em_v2 sl = __builtin_ia32_sqrtpd(lo), sh = __builtin_ia32_sqrtpd(hi);
  const em_v4 r = {sl[0], sl[1], sh[0], sh[1]};
  return r;
#else
  em_v4 r;
  for (int l = 0; l < 4; ++l)
    r[l] = sqrt(a[l]);
  return r;
#endif
}

EM_INLINE void em_split4(em_v4 v, em_v4 *h, em_v4 *l) {
  const em_v4 pv = v * 134217729.0;
  *h = pv - (pv - v);
  *l = v - *h;
}

EM_INLINE em_v4 em_sq_err4(em_v4 v, em_v4 vv) {
  em_v4 h, l;
  em_split4(v, &h, &l);
  return (((h * h - vv) + h * l) + h * l) + l * l;
}

EM_INLINE em_v4 em_atan2_4(em_v4 y, em_v4 x) {
  const em_v4 ax = em_abs4(x), ay = em_abs4(y);
  const em_v4 zero = {0.0, 0.0, 0.0, 0.0};
  const em_v4 big = {0x1p960, 0x1p960, 0x1p960, 0x1p960}, small = {0x1p-900, 0x1p-900, 0x1p-900, 0x1p-900};
  /* em_atan2_kernel() in lanes (a NaN fails every comparison). */
  const em_m4 in = (ax > zero) & (ay > zero) & (ax <= big) & (ay <= big) & ((ax >= small) | (ay >= small));
  const em_m4 swap = ay > ax;
  const em_m4 neg = x < zero;
  const em_v4 num = em_sel(swap, ax, ay), den = em_sel(swap, ay, ax);
  const em_v4 r = num / den;
  /* k = floor(64 r) for r >= 1/8, else 0 (and 0 in a lane outside the domain, whose result is
   * replaced below): truncated in lanes as (int) truncates. */
  const em_v4 kf = em_sel(in & (r >= 0.125), r * 64.0, zero);
  const em_i4 ki = __builtin_convertvector(kf, em_i4);
  const em_v4 c = __builtin_convertvector(ki, em_v4) * 0.015625;
  const em_v4 th_tab = {em_atan_tab[ki[0]][0], em_atan_tab[ki[1]][0], em_atan_tab[ki[2]][0],
                        em_atan_tab[ki[3]][0]};
  const em_v4 tl_tab = {em_atan_tab[ki[0]][1], em_atan_tab[ki[1]][1], em_atan_tab[ki[2]][1],
                        em_atan_tab[ki[3]][1]};
  const em_v4 dh = em_dbl(em_bits(den) & ~0x7ffffffLL);
  const em_v4 dl = den - dh;
  const em_v4 nn = (num - c * dh) - c * dl, dd = den + c * num;
  const em_v4 t = nn / dd;
  em_v4 th, tl, qh, ql;
  em_split4(t, &th, &tl);
  em_split4(dd, &qh, &ql);
  const em_v4 tc = ((((nn - th * qh) - th * ql) - tl * qh) - tl * ql) / dd;
  const em_v4 z = t * t;
  const em_v4 p =
      t *
      (z *
       (EM_A1 +
        z * (EM_A2 +
             z * (EM_A3 + z * (EM_A4 + z * (EM_A5 + z * (EM_A6 + z * (EM_A7 + z * (EM_A8 + z * EM_A9)))))))));
  const em_v4 s = t + ((p + tl_tab) + tc);
  const em_v4 pio2h = {EM_PIO2_HI, EM_PIO2_HI, EM_PIO2_HI, EM_PIO2_HI};
  const em_v4 pio2l = {EM_PIO2_LO, EM_PIO2_LO, EM_PIO2_LO, EM_PIO2_LO};
  const em_v4 pih = {EM_PI_HI, EM_PI_HI, EM_PI_HI, EM_PI_HI}, pil = {EM_PI_LO, EM_PI_LO, EM_PI_LO, EM_PI_LO};
  const em_v4 one = {1.0, 1.0, 1.0, 1.0}, mone = {-1.0, -1.0, -1.0, -1.0};
  const em_v4 bh = em_sel(swap, pio2h, em_sel(neg, pih, zero));
  const em_v4 bl = em_sel(swap, pio2l, em_sel(neg, pil, zero));
  const em_v4 sg = em_sel(swap ^ neg, mone, one);
  const em_v4 res = bh + sg * (th_tab + (s + sg * bl));
  const long long sign = (long long)0x8000000000000000ULL;
  em_v4 out = em_dbl((em_bits(res) & ~sign) | (em_bits(y) & sign)); /* copysign(res, y) */
  if (!em_all(in))
    for (int l = 0; l < 4; ++l)
      if (!in[l]) out[l] = atan2(y[l], x[l]);
  return out;
}

EM_INLINE em_v4 em_hypot4(em_v4 x, em_v4 y) {
  const em_v4 ax = em_abs4(x), ay = em_abs4(y);
  const em_v4 big = {0x1p500, 0x1p500, 0x1p500, 0x1p500}, small = {0x1p-500, 0x1p-500, 0x1p-500, 0x1p-500};
  /* em_hypot_kernel() in lanes. */
  const em_m4 in = (ax <= big) & (ay <= big) & ((ax >= small) | (ay >= small));
  const em_v4 xx = ax * ax, yy = ay * ay;
  const em_v4 xe = em_sq_err4(ax, xx), ye = em_sq_err4(ay, yy);
  const em_v4 s = xx + yy;
  const em_v4 bv = s - xx;
  const em_v4 se = (xx - (s - bv)) + (yy - bv);
  const em_v4 h = em_sqrt4(s);
  const em_v4 h2 = h * h;
  const em_v4 he = em_sq_err4(h, h2);
  const em_v4 res = (((s - h2) - he) + se) + (xe + ye);
  em_v4 out = h + res / (h + h);
  if (!em_all(in))
    for (int l = 0; l < 4; ++l)
      if (!in[l]) out[l] = hypot(x[l], y[l]);
  return out;
}

#undef EM_INLINE

#endif /* NAV_IO_ERR_MATH_H */
