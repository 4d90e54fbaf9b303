/*
 * The quaternion-to-DCM formula as an inline function, so that a hot kernel built in several
 * variants (nav_clones.h) gets it inlined into each variant; nav_quat_to_dcm() (math.c) is the
 * same function. [G] section 2.2.3, Hamilton product: C(q) v = q (x) v (x) conj(q).
 */
#ifndef NAV_QUAT_DCM_INLINE_H
#define NAV_QUAT_DCM_INLINE_H

#include "nav_clones.h"
#include "navcore/nav_math.h"

NAV_CLONE_INLINE nav_mat3 nav_quat_to_dcm_inline(nav_quat q) {
  const double ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  nav_mat3 c = {{{ww + xx - yy - zz, 2.0 * (xy - wz), 2.0 * (xz + wy)},
                 {2.0 * (xy + wz), ww - xx + yy - zz, 2.0 * (yz - wx)},
                 {2.0 * (xz - wy), 2.0 * (yz + wx), ww - xx - yy + zz}}};
  return c;
}

#endif /* NAV_QUAT_DCM_INLINE_H */
