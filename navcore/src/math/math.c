/*
 * Small fixed-size maths: rotation-coefficient functions, quaternion / DCM / rotation-vector /
 * Euler conversions, angle wrapping, and the small dense matrix kernels used by the filter.
 *
 * Conventions (nav_math.h, style.md section 4, numerics.md section 0): nav_mat3 is row-major, a
 * DCM C_b_n maps b-coordinates to n, quaternions are Hamilton and scalar first, Euler angles are
 * ZYX intrinsic with C_b_n = R_z(yaw) R_y(pitch) R_x(roll).
 *
 * Matrix elements are named C_rc with 1-based indices in comments (as in the books) and
 * m[r-1][c-1] in code.
 *
 * References:
 * [G]   P. Groves, Principles of GNSS, Inertial, and Multisensor Integrated Navigation Systems,
 *       2nd ed., Artech House 2013, section 2.2 (attitude representations).
 * [S]   P. Savage, Strapdown Analytics, 2nd ed., 2007, and JGCD 21(1), 1998 (rotation vector,
 *       Rodrigues coefficients).
 * [SH]  S. W. Shepperd, "Quaternion from rotation matrix", J. Guidance and Control 1(3):223-224,
 *       1978.
 * [BB]  A. Bjorck, C. Bowie, "An iterative algorithm for computing the best estimate of an
 *       orthogonal matrix", SIAM J. Numer. Anal. 8(2):358-364, 1971.
 * [NUM] docs/numerics.md (project), sections 0.2, 4.1, 4.4.
 */
#include "navcore/nav_math.h"
#include "math/chol_solve_inline.h"
#include "math/quat_dcm_inline.h"

#include <assert.h>
#include <string.h>

/*
 * Above NAV_ROTVEC_SERIES_RAD, (1 - sin a / a)/a^2 still suffers cancellation in 1 - sin(a)/a:
 * the closed form has a relative error of about 1e-16/(a^2/6), i.e. 6e-8 at a = 1e-4 and up to
 * 3.4e-15 for a in [0.5, 1] (measured against 40-digit arithmetic). Up to this bound the coefficient is
 * evaluated by its full Taylor series instead; at a = 2 the closed form is back to ~3e-16
 * relative, and 12 series terms leave a truncation error below 1e-18 there.
 */
#define ONE_MINUS_SINC_SERIES_RAD 2.0
#define ONE_MINUS_SINC_SERIES_TERMS 12

/* ||C C^T - I||_F at which the orthonormalisation stops. Evaluating C C^T - I in double has a
 * floor of a few ulps of the unit entries (up to ~3.5e-15 in the Frobenius norm), so the loop also
 * stops as soon as a step fails to halve the residual: the quadratic convergence has then reached
 * that floor. */
#define ORTHO_TOL 1e-15
/* Each step maps every singular value s to s (3 - s^2)/2, so the departure squares per step:
 * ||E|| = 0.5 converges in 6 steps, 0.1 in 4. Singular values must lie in (0, sqrt 3). */
#define ORTHO_MAX_ITER 8

/* numerics.md 4.4 rule 3: gimbal-lock test on |C_31|. */
#define GIMBAL_LOCK_TOL 1e-12

/* nav_math.h documents the dense kernels for n <= 64; the Cholesky factor is built in a stack
 * buffer of this size so that the output is left untouched on failure (32 KiB). */
#define MATN_MAX_DIM 64

/* ---------------------------------------------------------------- rotation coefficients */

double nav_sinc(double a) {
  /* [NUM] 4.1: sin a / a = 1 - a^2/6 + a^4/120 - ...; the a^6/5040 term is < 2e-28 at 1e-4.
   * The series also removes the 0/0 at a = 0. */
  if (fabs(a) < NAV_ROTVEC_SERIES_RAD) {
    const double a2 = a * a;
    return 1.0 - a2 / 6.0 + a2 * a2 / 120.0;
  }
  return sin(a) / a;
}

double nav_one_minus_cos_over_a2(double a) {
  /* [NUM] 4.1: (1 - cos a)/a^2 = 1/2 - a^2/24 + a^4/720 - ... */
  if (fabs(a) < NAV_ROTVEC_SERIES_RAD) {
    const double a2 = a * a;
    return 0.5 - a2 / 24.0 + a2 * a2 / 720.0;
  }
  /* 1 - cos a = 2 sin^2(a/2) avoids the cancellation of 1 - cos a, so the closed form is
   * accurate to a few ulps for every a above the threshold as well. */
  const double h = 0.5 * a;
  const double sinc_h = sin(h) / h;
  return 0.5 * sinc_h * sinc_h;
}

double nav_one_minus_sinc_over_a2(double a) {
  const double a2 = a * a;
  /* [NUM] 4.1: (1 - sin a / a)/a^2 = 1/6 - a^2/120 + a^4/5040 - ... */
  if (fabs(a) < NAV_ROTVEC_SERIES_RAD) return 1.0 / 6.0 - a2 / 120.0 + a2 * a2 / 5040.0;
  if (fabs(a) < ONE_MINUS_SINC_SERIES_RAD) {
    /* Full series sum_k (-1)^k a^(2k)/(2k+3)!, nested so that every denominator is a small exact
     * integer: t_(k+1)/t_k = -a^2/((2k+4)(2k+5)). */
    double s = 1.0;
    for (int k = ONE_MINUS_SINC_SERIES_TERMS - 2; k >= 0; --k) {
      const double d = (double)((2 * k + 4) * (2 * k + 5));
      s = 1.0 - a2 / d * s;
    }
    return s / 6.0;
  }
  return (1.0 - sin(a) / a) / a2;
}

/* ---------------------------------------------------------------- quaternion <-> rotation vector */

static nav_quat quat_neg(nav_quat q) {
  nav_quat r = {-q.w, -q.x, -q.y, -q.z};
  return r;
}

nav_quat nav_quat_from_rotvec(nav_vec3 phi_rad) {
  const double a = nav_vec3_norm(phi_rad);
  double w, s; /* q = [w, s phi] */
  if (a < NAV_ROTVEC_SERIES_RAD) {
    /* [NUM] 4.1: cos(a/2) = 1 - a^2/8 + a^4/384, sin(a/2)/a = 1/2 - a^2/48 + a^4/3840; no
     * division, so it is also exact for a = 0 and for a phi so small that |phi|^2 underflows. */
    const double a2 = a * a;
    w = 1.0 - a2 / 8.0 + a2 * a2 / 384.0;
    s = 0.5 - a2 / 48.0 + a2 * a2 / 3840.0;
  } else {
    w = cos(0.5 * a);
    s = sin(0.5 * a) / a;
  }
  nav_quat q = {w, s * phi_rad.x, s * phi_rad.y, s * phi_rad.z};
  return q;
}

nav_vec3 nav_quat_to_rotvec(nav_quat q) {
  /* q and -q are the same rotation; w >= 0 selects the angle in [0, pi]. fabs also turns a -0
   * scalar part into +0 so that atan2 stays in [0, pi/2]. */
  if (q.w < 0.0) q = quat_neg(q);
  const double w = fabs(q.w);
  nav_vec3 v = {q.x, q.y, q.z};
  const double n = nav_vec3_norm(v); /* = sin(a/2) for a unit q */
  double f;                          /* phi = f v, f = a / sin(a/2) */
  if (n < NAV_ROTVEC_SERIES_RAD * w) {
    /* a = 2 atan(x), x = n/w: 2 atan(x)/n = (2/w)(1 - x^2/3 + x^4/5), avoiding 0/0 at n = 0;
     * truncation x^6/7 < 2e-29 relative. */
    const double x = n / w;
    const double x2 = x * x;
    f = 2.0 / w * (1.0 - x2 / 3.0 + x2 * x2 / 5.0);
  } else {
    /* atan2 of both sine and cosine is well conditioned over the whole range, unlike acos(w)
     * near 0 and asin(n) near pi ([NUM] 4.4 rule 2). */
    f = 2.0 * atan2(n, w) / n;
  }
  return nav_vec3_scale(v, f);
}

/* ---------------------------------------------------------------- quaternion <-> DCM */

/* The formula is in quat_dcm_inline.h, shared with the hot kernels that inline it. */
nav_mat3 nav_quat_to_dcm(nav_quat q) { return nav_quat_to_dcm_inline(q); }

nav_quat nav_quat_from_dcm(nav_mat3 c) {
  /* [SH] Shepperd 1978: of 4w^2 = 1 + tr, 4x^2 = 1 + C_11 - C_22 - C_33, 4y^2 = ..., 4z^2 = ...
   * take the square root of the largest (comparing tr, C_11, C_22, C_33 is equivalent), which is
   * >= 1/4 of the sum 4, so the divisor is >= 1/2 and the other three components come from the
   * off-diagonal sums and differences without loss:
   *   4wx = C_32 - C_23, 4wy = C_13 - C_31, 4wz = C_21 - C_12,
   *   4xy = C_12 + C_21, 4xz = C_13 + C_31, 4yz = C_23 + C_32. */
  const double c11 = c.m[0][0], c22 = c.m[1][1], c33 = c.m[2][2];
  const double tr = c11 + c22 + c33;
  nav_quat q;
  if (tr >= c11 && tr >= c22 && tr >= c33) {
    const double r = sqrt(1.0 + tr); /* = 2|w| */
    const double f = 0.5 / r;
    q.w = 0.5 * r;
    q.x = (c.m[2][1] - c.m[1][2]) * f;
    q.y = (c.m[0][2] - c.m[2][0]) * f;
    q.z = (c.m[1][0] - c.m[0][1]) * f;
  } else if (c11 >= c22 && c11 >= c33) {
    const double r = sqrt(1.0 + c11 - c22 - c33); /* = 2|x| */
    const double f = 0.5 / r;
    q.x = 0.5 * r;
    q.w = (c.m[2][1] - c.m[1][2]) * f;
    q.y = (c.m[0][1] + c.m[1][0]) * f;
    q.z = (c.m[0][2] + c.m[2][0]) * f;
  } else if (c22 >= c33) {
    const double r = sqrt(1.0 - c11 + c22 - c33); /* = 2|y| */
    const double f = 0.5 / r;
    q.y = 0.5 * r;
    q.w = (c.m[0][2] - c.m[2][0]) * f;
    q.x = (c.m[0][1] + c.m[1][0]) * f;
    q.z = (c.m[1][2] + c.m[2][1]) * f;
  } else {
    const double r = sqrt(1.0 - c11 - c22 + c33); /* = 2|z| */
    const double f = 0.5 / r;
    q.z = 0.5 * r;
    q.w = (c.m[1][0] - c.m[0][1]) * f;
    q.x = (c.m[0][2] + c.m[2][0]) * f;
    q.y = (c.m[1][2] + c.m[2][1]) * f;
  }
  if (q.w < 0.0) q = quat_neg(q);
  /* For an orthonormal C the result is unit to rounding; the normalisation makes that hold
   * for slightly non-orthonormal input too. */
  return nav_quat_normalize(q);
}

/* ---------------------------------------------------------------- DCM exp / log */

/* I + b1 [phi x] + b2 [phi x]^2, with [phi x]^2 = phi phi^T - |phi|^2 I written out so that the
 * diagonal is -(y^2 + z^2) etc. instead of the cancelling x^2 - |phi|^2. */
static nav_mat3 skew_poly(nav_vec3 p, double b1, double b2) {
  const double xx = p.x * p.x, yy = p.y * p.y, zz = p.z * p.z;
  const double xy = p.x * p.y, xz = p.x * p.z, yz = p.y * p.z;
  nav_mat3 r = {{{1.0 - b2 * (yy + zz), -b1 * p.z + b2 * xy, b1 * p.y + b2 * xz},
                 {b1 * p.z + b2 * xy, 1.0 - b2 * (xx + zz), -b1 * p.x + b2 * yz},
                 {-b1 * p.y + b2 * xz, b1 * p.x + b2 * yz, 1.0 - b2 * (xx + yy)}}};
  return r;
}

nav_mat3 nav_dcm_exp(nav_vec3 phi_rad) {
  /* Rodrigues ([NUM] 0.2, [G] section 2.2.4, [S]):
   * exp([phi x]) = I + (sin a / a)[phi x] + ((1 - cos a)/a^2)[phi x]^2, a = |phi|;
   * both coefficients switch to their series below NAV_ROTVEC_SERIES_RAD. */
  const double a = nav_vec3_norm(phi_rad);
  return skew_poly(phi_rad, nav_sinc(a), nav_one_minus_cos_over_a2(a));
}

nav_mat3 nav_rot_comp_matrix(nav_vec3 phi_rad) {
  /* [NUM] E4.4 ([S] JGCD 21(2)): A(phi) = I + ((1 - cos a)/a^2)[phi x] + ((1 - sin a/a)/a^2)
   * [phi x]^2, the integral over s in [0, 1] of exp(s [phi x]). */
  const double a = nav_vec3_norm(phi_rad);
  return skew_poly(phi_rad, nav_one_minus_cos_over_a2(a), nav_one_minus_sinc_over_a2(a));
}

nav_vec3 nav_dcm_log(nav_mat3 c) {
  /* From Rodrigues, C = cos a I + sin a [k x] + (1 - cos a) k k^T, so
   *   s = vee((C - C^T)/2) = sin(a) k,   cos a = (tr C - 1)/2,
   *   (C + C^T)/2 - cos a I = (1 - cos a) k k^T. */
  const nav_vec3 s = {0.5 * (c.m[2][1] - c.m[1][2]), 0.5 * (c.m[0][2] - c.m[2][0]),
                      0.5 * (c.m[1][0] - c.m[0][1])};
  const double cos_a = 0.5 * (c.m[0][0] + c.m[1][1] + c.m[2][2] - 1.0);

  if (cos_a >= 0.0) {
    /* a <= pi/2: the axis comes from s, whose direction is accurate to ~1e-16/sin(a), at most
     * a factor 1.6 worse than at a -> 0 once multiplied by a. */
    const double sin_a = nav_vec3_norm(s);
    double f; /* phi = f s, f = a / sin a */
    if (sin_a < NAV_ROTVEC_SERIES_RAD) {
      /* a = asin(sin_a) here (cos a > 0): asin(x)/x = 1 + x^2/6 + 3x^4/40, truncation
       * 5x^6/112 < 5e-26; avoids 0/0 at the identity. */
      const double x2 = sin_a * sin_a;
      f = 1.0 + x2 / 6.0 + 3.0 * x2 * x2 / 40.0;
    } else {
      f = atan2(sin_a, cos_a) / sin_a;
    }
    return nav_vec3_scale(s, f);
  }

  /* a > pi/2: sin a -> 0 at pi, so s no longer fixes the axis; take it from the symmetric part
   * instead. Its column i is (1 - cos a) k_i k; the column with the largest diagonal
   * (k_i^2 >= 1/3) is normalised to give k to rounding. s only supplies the sign of k (at a = pi
   * exactly both signs are the same rotation). */
  const double d[3] = {c.m[0][0] - cos_a, c.m[1][1] - cos_a, c.m[2][2] - cos_a};
  int i = 0;
  if (d[1] > d[i]) i = 1;
  if (d[2] > d[i]) i = 2;
  nav_vec3 v;
  for (int j = 0; j < 3; ++j)
    nav_vec3_set(&v, j, j == i ? d[i] : 0.5 * (c.m[i][j] + c.m[j][i]));
  nav_vec3 k = nav_vec3_scale(v, 1.0 / nav_vec3_norm(v));
  double sin_a = nav_vec3_dot(k, s);
  if (sin_a < 0.0) k = nav_vec3_scale(k, -1.0);
  /* fabs: a -0 sine would make atan2 return -pi. */
  sin_a = fabs(sin_a);
  return nav_vec3_scale(k, atan2(sin_a, cos_a));
}

/* ---------------------------------------------------------------- orthonormality */

/* E = C C^T - I (symmetric); returns ||E||_F. */
static double ortho_residual(nav_mat3 c, nav_mat3 *e) {
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double v =
          c.m[i][0] * c.m[j][0] + c.m[i][1] * c.m[j][1] + c.m[i][2] * c.m[j][2] - (i == j ? 1.0 : 0.0);
      e->m[i][j] = v;
      sum += v * v;
    }
  return sqrt(sum);
}

nav_mat3 nav_dcm_orthonormalize(nav_mat3 c) {
  /* [NUM] 4.4 rule 1, [BB] (first-order iteration): C <- C - 1/2 (C C^T - I) C. With
   * C = U S V^T every step maps S to S (3I - S^2)/2 and keeps U, V, so the limit is U V^T, the
   * orthonormal matrix nearest to C in the Frobenius norm; the residual E = C C^T - I goes to
   * -3/4 E^2 per step. Stops at ORTHO_TOL, at the rounding floor, after ORTHO_MAX_ITER steps,
   * or on NaN. */
  double prev = INFINITY;
  for (int it = 0; it < ORTHO_MAX_ITER; ++it) {
    nav_mat3 e;
    const double err = ortho_residual(c, &e);
    /* Negated tests so that a NaN residual also stops the loop. */
    if (!(err > ORTHO_TOL) || !(err < 0.5 * prev)) break;
    c = nav_mat3_add(c, nav_mat3_scale(nav_mat3_mul(e, c), -0.5));
    prev = err;
  }
  return c;
}

double nav_dcm_orthonormality_error(nav_mat3 c) {
  double sum = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      /* (C^T C)_ij = column i . column j */
      const double v =
          c.m[0][i] * c.m[0][j] + c.m[1][i] * c.m[1][j] + c.m[2][i] * c.m[2][j] - (i == j ? 1.0 : 0.0);
      sum += v * v;
    }
  return sqrt(sum);
}

/* ---------------------------------------------------------------- attitude differences */

double nav_dcm_angle_between(nav_mat3 c1, nav_mat3 c2) {
  /* |log(C1^T C2)| = atan2(|vee(R - R^T)|/2, (tr R - 1)/2), R = C1^T C2: sine and cosine
   * together keep the angle accurate near 0 and near pi ([NUM] 4.4 rule 2). */
  const nav_mat3 r = nav_mat3_tmul(c1, c2);
  const nav_vec3 s = {0.5 * (r.m[2][1] - r.m[1][2]), 0.5 * (r.m[0][2] - r.m[2][0]),
                      0.5 * (r.m[1][0] - r.m[0][1])};
  const double cos_a = 0.5 * (r.m[0][0] + r.m[1][1] + r.m[2][2] - 1.0);
  return atan2(nav_vec3_norm(s), cos_a);
}

double nav_quat_angle_between(nav_quat q1, nav_quat q2) {
  /* [NUM] 4.4 rule 2: 2 atan2(|v|, |w|) of the relative quaternion; |w| makes it
   * sign-invariant. */
  const nav_quat r = nav_quat_mul(nav_quat_conj(q1), q2);
  return 2.0 * atan2(sqrt(r.x * r.x + r.y * r.y + r.z * r.z), fabs(r.w));
}

/* ---------------------------------------------------------------- Euler angles */

nav_mat3 nav_euler_to_dcm(nav_euler e) {
  /* C_b_n = R_z(yaw) R_y(pitch) R_x(roll): the transpose of C_n_b in [G] eq. (2.22). */
  const double sr = sin(e.roll_rad), cr = cos(e.roll_rad);
  const double sp = sin(e.pitch_rad), cp = cos(e.pitch_rad);
  const double sy = sin(e.yaw_rad), cy = cos(e.yaw_rad);
  nav_mat3 c = {{{cp * cy, -cr * sy + sr * sp * cy, sr * sy + cr * sp * cy},
                 {cp * sy, cr * cy + sr * sp * sy, -sr * cy + cr * sp * sy},
                 {-sp, sr * cp, cr * cp}}};
  return c;
}

nav_euler nav_dcm_to_euler(nav_mat3 c_b_n, bool *gimbal_lock) {
  /* [G] eq. (2.23) for C_b_n, with the gimbal-lock rule of [NUM] 4.4 rule 3. Two deviations
   * from the textbook formulas keep the round trip C -> Euler -> C accurate near pitch +/-90 deg
   * (T4.2 asks for 1e-12 at 89.9999 deg, where 1/cos(pitch) = 5.7e5):
   * - Pitch is atan2(-C_31, hypot(C_11, C_21)) instead of -asin(C_31). asin is ill-conditioned
   *   near |C_31| = 1: the rounding of C_31 alone (5.6e-17) moves it by 3e-11 rad at 89.9999 deg.
   * - Roll and yaw are each ill-conditioned there (errors ~1e-16/cos(pitch) when C carries
   *   absolute rounding errors, as any C from a quaternion or an integration does); only
   *   yaw - roll (pitch > 0) or yaw + roll (pitch < 0) is well determined. Yaw is therefore
   *   formed from that combination plus roll, so the two errors cancel when C is rebuilt:
   *     C_23 - C_12 = (1 + sin p) sin(yaw - roll),   C_22 + C_13 = (1 + sin p) cos(yaw - roll),
   *     -(C_12 + C_23) = (1 - sin p) sin(yaw + roll), C_22 - C_13 = (1 - sin p) cos(yaw + roll),
   *   (expanding C = R_z(yaw) R_y(p) R_x(roll)); the branch keeps the factor 1 +/- sin p >= 1.
   *   Away from the poles this is as accurate as atan2(C_21, C_11). */
  const nav_mat3 *c = &c_b_n;
  const double c31 = c->m[2][0];
  nav_euler e;
  e.pitch_rad = atan2(-c31, hypot(c->m[0][0], c->m[1][0]));
  const bool locked = fabs(c31) > 1.0 - GIMBAL_LOCK_TOL;
  if (locked) {
    /* Pitch +/-90 deg: only yaw - roll (resp. yaw + roll) is observable. With roll = 0,
     * C_12 = -sin(yaw) and C_22 = cos(yaw) for either sign of the pitch. */
    e.roll_rad = 0.0;
    e.yaw_rad = nav_wrap_pi(atan2(-c->m[0][1], c->m[1][1]));
  } else {
    /* nav_wrap_pi also maps an atan2 result of exactly -pi (from a -0 sine) to +pi. */
    e.roll_rad = nav_wrap_pi(atan2(c->m[2][1], c->m[2][2]));
    if (c31 <= 0.0) { /* pitch >= 0 */
      const double yaw_minus_roll = atan2(c->m[1][2] - c->m[0][1], c->m[1][1] + c->m[0][2]);
      e.yaw_rad = nav_wrap_pi(yaw_minus_roll + e.roll_rad);
    } else {
      const double yaw_plus_roll = atan2(-(c->m[0][1] + c->m[1][2]), c->m[1][1] - c->m[0][2]);
      e.yaw_rad = nav_wrap_pi(yaw_plus_roll - e.roll_rad);
    }
  }
  if (gimbal_lock) *gimbal_lock = locked;
  return e;
}

nav_quat nav_euler_to_quat(nav_euler e) {
  /* The quaternion form of R_z(yaw) R_y(pitch) R_x(roll) ([G] section 2.2.3): the Hamilton
   * product of the three elementary rotations in the same order. */
  const double hr = 0.5 * e.roll_rad, hp = 0.5 * e.pitch_rad, hy = 0.5 * e.yaw_rad;
  const nav_quat q_roll = {cos(hr), sin(hr), 0.0, 0.0};
  const nav_quat q_pitch = {cos(hp), 0.0, sin(hp), 0.0};
  const nav_quat q_yaw = {cos(hy), 0.0, 0.0, sin(hy)};
  return nav_quat_mul(nav_quat_mul(q_yaw, q_pitch), q_roll);
}

nav_euler nav_quat_to_euler(nav_quat q, bool *gimbal_lock) {
  /* Through the DCM so that both paths share one extraction and one gimbal-lock rule. */
  return nav_dcm_to_euler(nav_quat_to_dcm(q), gimbal_lock);
}

/* ---------------------------------------------------------------- angle wrapping */

double nav_wrap_pi(double a_rad) {
  /* Inside (-pi, pi] remainder() would return its argument unchanged (|a| < 2pi / 2, and pi itself
   * is a tie rounded to the even quotient 0), so the common case skips the libm call. */
  if (a_rad > -NAV_PI && a_rad <= NAV_PI) return a_rad;
  /* remainder() is exact and returns a value in [-pi, pi] (pi as the double NAV_PI); only the
   * end point -pi has to be moved to +pi. Signed zeros pass through unchanged. */
  double r = remainder(a_rad, NAV_TWO_PI);
  if (r == -NAV_PI) r = NAV_PI;
  return r;
}

double nav_wrap_two_pi(double a_rad) {
  double r = remainder(a_rad, NAV_TWO_PI);
  if (r < 0.0) {
    r += NAV_TWO_PI;
    /* A tiny negative r rounds up to 2 pi, which is outside [0, 2 pi); 0 is the same angle. */
    if (r >= NAV_TWO_PI) r = 0.0;
  }
  /* Turns -0 into +0 (round-to-nearest: -0 + +0 = +0). */
  return r + 0.0;
}

/* ---------------------------------------------------------------- small dense matrices */

nav_status nav_matn_cholesky(double *l, const double *a, size_t n) {
  double buf[MATN_MAX_DIM * MATN_MAX_DIM];
  assert(l != NULL && a != NULL);
  if (l == NULL || a == NULL || n == 0 || n > MATN_MAX_DIM) return NAV_ERR_INVALID_ARG;
  for (size_t i = 0; i < n * n; ++i)
    if (!isfinite(a[i])) return NAV_ERR_NUMERIC;

  /* Row-by-row (Cholesky-Banachiewicz): L_ij = (A_ij - sum_{k<j} L_ik L_jk)/L_jj and
   * L_ii = sqrt(A_ii - sum_{k<i} L_ik^2) (Golub, Van Loan, Matrix Computations, 4th ed.,
   * algorithm 4.2.1). Element (i, j) of A is read just before L_ij is written and never again,
   * so the factor can be built in place when l == a; otherwise it goes to buf and is copied out
   * only on success. Only the lower triangle of A is used. */
  double *out = (l == a) ? l : buf;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j <= i; ++j) {
      double sum = a[i * n + j];
      for (size_t k = 0; k < j; ++k)
        sum -= out[i * n + k] * out[j * n + k];
      if (i == j) {
        /* Not positive definite (or NaN): the pivot must be strictly positive. */
        if (!(sum > 0.0)) return NAV_ERR_NUMERIC;
        out[i * n + i] = sqrt(sum);
      } else {
        const double lij = sum / out[j * n + j];
        if (!isfinite(lij)) return NAV_ERR_NUMERIC;
        out[i * n + j] = lij;
      }
    }
    for (size_t j = i + 1; j < n; ++j)
      out[i * n + j] = 0.0;
  }
  if (out != l) memcpy(l, buf, n * n * sizeof *l);
  return NAV_OK;
}

void nav_matn_chol_solve(double *x, const double *l, const double *b, size_t n, size_t m) {
  assert(x != NULL && l != NULL && b != NULL);
  if (x == NULL || l == NULL || b == NULL) return;
  if (x != b) memmove(x, b, n * m * sizeof *x);
  /* L Y = B by forward substitution, then L^T X = Y by back substitution, in place in x. */
  nav_chol_solve_rows_inline(x, l, n, m);
}

void nav_matn_mul(double *c, const double *a, const double *b, size_t n, size_t k, size_t m) {
  assert(c != NULL && a != NULL && b != NULL);
  if (c == NULL || a == NULL || b == NULL) return;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < m; ++j) {
      double sum = 0.0;
      for (size_t t = 0; t < k; ++t)
        sum += a[i * k + t] * b[t * m + j];
      c[i * m + j] = sum;
    }
}

void nav_matn_mul_bt(double *c, const double *a, const double *b, size_t n, size_t k, size_t m) {
  assert(c != NULL && a != NULL && b != NULL);
  if (c == NULL || a == NULL || b == NULL) return;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < m; ++j) {
      double sum = 0.0;
      for (size_t t = 0; t < k; ++t)
        sum += a[i * k + t] * b[j * k + t];
      c[i * m + j] = sum;
    }
}

void nav_matn_symmetrize(double *p, size_t n) {
  assert(p != NULL);
  if (p == NULL) return;
  /* Addition is commutative in IEEE arithmetic, so both halves get the identical value. */
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const double v = 0.5 * (p[i * n + j] + p[j * n + i]);
      p[i * n + j] = v;
      p[j * n + i] = v;
    }
}

void nav_matn_sandwich(double *c, const double *a, const double *p, size_t n, size_t k, double *work) {
  assert(c != NULL && a != NULL && p != NULL && work != NULL);
  if (c == NULL || a == NULL || p == NULL || work == NULL) return;
  /* W = A P (n x k), then only the upper triangle of W A^T, mirrored: exact symmetry by
   * construction, and half the work of the second product. */
  nav_matn_mul(work, a, p, n, k, k);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      double sum = 0.0;
      for (size_t t = 0; t < k; ++t)
        sum += work[i * k + t] * a[j * k + t];
      c[i * n + j] = sum;
      c[j * n + i] = sum;
    }
}
