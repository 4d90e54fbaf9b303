/*
 * Four doubles in lockstep: the lane type of the Monte Carlo runs that step together (sim.c,
 * docs/campaign-speed.md). One lane holds one run's value; every operation below is the scalar
 * operation lane by lane (IEEE addition, subtraction, multiplication and division are correctly
 * rounded in a vector lane exactly as in a scalar register, and navcore is compiled with
 * -ffp-contract=off, so no fused multiply-add appears on either path). Code written with these
 * types and the same expression trees as the scalar code gives the scalar bits in every lane.
 *
 * GCC and clang vector extensions: 256-bit vectors compile to AVX2 in the avx2 clones and to
 * pairs of SSE2 operations otherwise, with the same values. Comparisons give lane masks (all ones
 * or all zeros); sel() blends by mask, all4() asks whether a test holds in every lane.
 */
#ifndef NAV_LANES4_H
#define NAV_LANES4_H

#include <stdint.h>

#include "navcore/nav_math.h"

#define NAV_LANES 4

#if defined(__GNUC__)
/* Every helper here is always inlined, so GCC's and clang's note that a 32-byte vector argument or
 * return changes the ABI where AVX is off (the baseline clone) does not apply. */
#pragma GCC diagnostic ignored "-Wpsabi"
#define NAV_L4_INLINE static inline __attribute__((always_inline))
#else
#define NAV_L4_INLINE static inline
#endif

typedef double nav_l4 __attribute__((vector_size(32)));
typedef long long nav_m4 __attribute__((vector_size(32)));

typedef struct {
  nav_l4 x, y, z;
} nav_l4v3;
typedef struct {
  nav_l4 w, x, y, z;
} nav_l4q;
typedef struct {
  nav_l4 m[3][3];
} nav_l4m3;

NAV_L4_INLINE nav_l4 l4_splat(double a) { return (nav_l4){a, a, a, a}; }
/* Every lane's mask set. */
NAV_L4_INLINE int l4_all(nav_m4 m) { return (m[0] & m[1] & m[2] & m[3]) != 0; }
/* a where the mask is set, b elsewhere (bit blend: the values are moved, not computed). */
NAV_L4_INLINE nav_l4 l4_sel(nav_m4 m, nav_l4 a, nav_l4 b) { return (nav_l4)(((nav_m4)a & m) | ((nav_m4)b & ~m)); }
/* |a| lane by lane (the sign bit cleared, as fabs). */
NAV_L4_INLINE nav_l4 l4_abs(nav_l4 a) {
  const nav_m4 k = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};
  return (nav_l4)((nav_m4)a & k);
}

NAV_L4_INLINE nav_l4v3 l4v3(nav_l4 x, nav_l4 y, nav_l4 z) {
  nav_l4v3 r = {x, y, z};
  return r;
}
/* The nav_vec3_* operations of nav_math.h, same expression trees. */
NAV_L4_INLINE nav_l4v3 l4v3_add(nav_l4v3 a, nav_l4v3 b) { return l4v3(a.x + b.x, a.y + b.y, a.z + b.z); }
NAV_L4_INLINE nav_l4v3 l4v3_sub(nav_l4v3 a, nav_l4v3 b) { return l4v3(a.x - b.x, a.y - b.y, a.z - b.z); }
NAV_L4_INLINE nav_l4v3 l4v3_scale(nav_l4v3 a, nav_l4 s) { return l4v3(a.x * s, a.y * s, a.z * s); }
NAV_L4_INLINE nav_l4v3 l4v3_axpy(nav_l4v3 a, nav_l4 s, nav_l4v3 b) {
  return l4v3(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
NAV_L4_INLINE nav_l4 l4v3_dot(nav_l4v3 a, nav_l4v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
NAV_L4_INLINE nav_l4v3 l4v3_cross(nav_l4v3 a, nav_l4v3 b) {
  return l4v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
NAV_L4_INLINE nav_l4v3 l4m3_mul_vec(const nav_l4m3 *a, nav_l4v3 v) {
  return l4v3(a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
              a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
              a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z);
}
/* nav_quat_mul. */
NAV_L4_INLINE nav_l4q l4q_mul(nav_l4q a, nav_l4q b) {
  nav_l4q r = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
               a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
  return r;
}
/* nav_quat_to_dcm_inline (math/quat_dcm_inline.h). */
NAV_L4_INLINE nav_l4m3 l4q_to_dcm(nav_l4q q) {
  const nav_l4 ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const nav_l4 xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const nav_l4 wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  const nav_l4 two = l4_splat(2.0);
  nav_l4m3 c = {{{ww + xx - yy - zz, two * (xy - wz), two * (xz + wy)},
                 {two * (xy + wz), ww - xx + yy - zz, two * (yz - wx)},
                 {two * (xz - wy), two * (yz + wx), ww - xx - yy + zz}}};
  return c;
}

/* Lane l of a vector, of a lane vector, of a lane quaternion. */
NAV_L4_INLINE nav_vec3 l4v3_lane(nav_l4v3 a, int l) { return nav_vec3_make(a.x[l], a.y[l], a.z[l]); }
NAV_L4_INLINE void l4v3_set_lane(nav_l4v3 *a, int l, nav_vec3 v) {
  a->x[l] = v.x;
  a->y[l] = v.y;
  a->z[l] = v.z;
}
NAV_L4_INLINE nav_quat l4q_lane(nav_l4q a, int l) {
  nav_quat q = {a.w[l], a.x[l], a.y[l], a.z[l]};
  return q;
}
NAV_L4_INLINE void l4q_set_lane(nav_l4q *a, int l, nav_quat q) {
  a->w[l] = q.w;
  a->x[l] = q.x;
  a->y[l] = q.y;
  a->z[l] = q.z;
}

#endif /* NAV_LANES4_H */
