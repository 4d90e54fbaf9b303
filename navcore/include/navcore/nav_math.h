/**
 * @file nav_math.h
 * @brief Small fixed-size maths: 3-vectors, 3x3 matrices, Hamilton quaternions, rotation
 *        vectors, DCM exp/log, ZYX Euler angles, and small dense matrices for the filter.
 *
 * Conventions (style.md section 4, numerics.md section 0):
 * - nav_mat3 is row-major: m[row][col]. A DCM C_b_n maps b-coordinates to n: v_n = C_b_n v_b.
 * - Quaternions are Hamilton, scalar first {w, x, y, z}; q_b_n means the same rotation as C_b_n,
 *   and q_b_e = q_n_e (x) q_b_n. q and -q represent the same rotation.
 * - Euler angles are ZYX intrinsic: C_b_n = R_z(yaw) R_y(pitch) R_x(roll), roll in (-pi, pi],
 *   pitch in [-pi/2, pi/2], yaw in (-pi, pi]. They are for I/O only.
 * - Rotation vector phi: the rotation by |phi| about phi/|phi|; exp([phi x]) is its DCM.
 *
 * Small value types are passed and returned by value; the tiny operations are static inline so
 * the hot paths (mechanization, truth generation) inline them. Leaf maths cannot fail and lets
 * NaN propagate; callers that take external input check finiteness themselves.
 */
#ifndef NAV_MATH_H
#define NAV_MATH_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "nav_export.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** pi to double precision (M_PI is not declared under strict C11). */
#define NAV_PI 3.14159265358979323846
#define NAV_TWO_PI 6.28318530717958647692
#define NAV_DEG2RAD (NAV_PI / 180.0)
#define NAV_RAD2DEG (180.0 / NAV_PI)

/** A 3-vector; the frame and unit are carried by the variable's name. */
typedef struct nav_vec3 {
  double x, y, z;
} nav_vec3;

/** A 3x3 matrix, row-major: m[row][col]. */
typedef struct nav_mat3 {
  double m[3][3];
} nav_mat3;

/** A Hamilton quaternion, scalar first. */
typedef struct nav_quat {
  double w, x, y, z;
} nav_quat;

/** ZYX Euler angles [rad] (I/O and display only). */
typedef struct nav_euler {
  double roll_rad, pitch_rad, yaw_rad;
} nav_euler;

/* ---------------------------------------------------------------- vec3 (inline) */

static inline nav_vec3 nav_vec3_make(double x, double y, double z) {
  nav_vec3 r = {x, y, z};
  return r;
}
static inline nav_vec3 nav_vec3_zero(void) { return nav_vec3_make(0.0, 0.0, 0.0); }
static inline nav_vec3 nav_vec3_add(nav_vec3 a, nav_vec3 b) {
  return nav_vec3_make(a.x + b.x, a.y + b.y, a.z + b.z);
}
static inline nav_vec3 nav_vec3_sub(nav_vec3 a, nav_vec3 b) {
  return nav_vec3_make(a.x - b.x, a.y - b.y, a.z - b.z);
}
static inline nav_vec3 nav_vec3_scale(nav_vec3 a, double s) {
  return nav_vec3_make(a.x * s, a.y * s, a.z * s);
}
/** a + s b */
static inline nav_vec3 nav_vec3_axpy(nav_vec3 a, double s, nav_vec3 b) {
  return nav_vec3_make(a.x + s * b.x, a.y + s * b.y, a.z + s * b.z);
}
static inline double nav_vec3_dot(nav_vec3 a, nav_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline nav_vec3 nav_vec3_cross(nav_vec3 a, nav_vec3 b) {
  return nav_vec3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/** Euclidean norm, overflow-safe for the magnitudes navcore handles (uses sqrt of the dot). */
static inline double nav_vec3_norm(nav_vec3 a) { return sqrt(nav_vec3_dot(a, a)); }
static inline bool nav_vec3_isfinite(nav_vec3 a) {
  return isfinite(a.x) && isfinite(a.y) && isfinite(a.z);
}
/** Element-wise access by index 0..2 (for loops over axes). */
static inline double nav_vec3_get(nav_vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }
static inline void nav_vec3_set(nav_vec3 *a, int i, double v) {
  if (i == 0) a->x = v;
  else if (i == 1) a->y = v;
  else a->z = v;
}

/* ---------------------------------------------------------------- mat3 (inline) */

static inline nav_mat3 nav_mat3_identity(void) {
  nav_mat3 r = {{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};
  return r;
}
static inline nav_mat3 nav_mat3_zero(void) {
  nav_mat3 r = {{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}}};
  return r;
}
/** Skew-symmetric matrix [v x], so that [v x] u = v x u. */
static inline nav_mat3 nav_mat3_skew(nav_vec3 v) {
  nav_mat3 r = {{{0.0, -v.z, v.y}, {v.z, 0.0, -v.x}, {-v.y, v.x, 0.0}}};
  return r;
}
static inline nav_mat3 nav_mat3_transpose(nav_mat3 a) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[j][i];
  return r;
}
static inline nav_mat3 nav_mat3_mul(nav_mat3 a, nav_mat3 b) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}
/** a^T b without forming the transpose. */
static inline nav_mat3 nav_mat3_tmul(nav_mat3 a, nav_mat3 b) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[0][i] * b.m[0][j] + a.m[1][i] * b.m[1][j] + a.m[2][i] * b.m[2][j];
  return r;
}
static inline nav_mat3 nav_mat3_add(nav_mat3 a, nav_mat3 b) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] + b.m[i][j];
  return r;
}
static inline nav_mat3 nav_mat3_scale(nav_mat3 a, double s) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.m[i][j] = a.m[i][j] * s;
  return r;
}
/** A v (free vector: rotation only). */
static inline nav_vec3 nav_mat3_mul_vec(nav_mat3 a, nav_vec3 v) {
  return nav_vec3_make(a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
                       a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
                       a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z);
}
/** A^T v. */
static inline nav_vec3 nav_mat3_tmul_vec(nav_mat3 a, nav_vec3 v) {
  return nav_vec3_make(a.m[0][0] * v.x + a.m[1][0] * v.y + a.m[2][0] * v.z,
                       a.m[0][1] * v.x + a.m[1][1] * v.y + a.m[2][1] * v.z,
                       a.m[0][2] * v.x + a.m[1][2] * v.y + a.m[2][2] * v.z);
}

/* ---------------------------------------------------------------- quaternion (inline) */

static inline nav_quat nav_quat_identity(void) {
  nav_quat q = {1.0, 0.0, 0.0, 0.0};
  return q;
}
/** Hamilton product a (x) b. */
static inline nav_quat nav_quat_mul(nav_quat a, nav_quat b) {
  nav_quat r = {a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
                a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
                a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
  return r;
}
static inline nav_quat nav_quat_conj(nav_quat q) {
  nav_quat r = {q.w, -q.x, -q.y, -q.z};
  return r;
}
static inline double nav_quat_norm(nav_quat q) {
  return sqrt(q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z);
}
static inline nav_quat nav_quat_normalize(nav_quat q) {
  double s = 1.0 / nav_quat_norm(q);
  nav_quat r = {q.w * s, q.x * s, q.y * s, q.z * s};
  return r;
}
/** Rotate a free vector: q (x) v (x) conj(q), i.e. C(q) v. */
static inline nav_vec3 nav_quat_rotate(nav_quat q, nav_vec3 v) {
  /* v' = v + 2w (u x v) + 2 u x (u x v), u = vector part; exact for unit q. */
  nav_vec3 u = {q.x, q.y, q.z};
  nav_vec3 t = nav_vec3_scale(nav_vec3_cross(u, v), 2.0);
  return nav_vec3_add(nav_vec3_add(v, nav_vec3_scale(t, q.w)), nav_vec3_cross(u, t));
}

/* ---------------------------------------------------------------- rotations (math.c) */

/**
 * Thresholds of the series branches. Below NAV_ROTVEC_SERIES_RAD the Rodrigues coefficients
 * sin(a)/a, (1-cos a)/a^2 and (1 - sin(a)/a)/a^2 are evaluated by their Taylor series: at
 * a = 1e-4 the truncation error of the series (a^6 terms) is below 1e-25 while the closed forms
 * lose about 8 digits to cancellation in 1 - cos a (numerics.md section 4.1).
 */
#define NAV_ROTVEC_SERIES_RAD 1e-4

/** sin(a)/a, accurate for all a >= 0. */
NAV_API double nav_sinc(double a);
/** (1 - cos a)/a^2, accurate for all a >= 0. */
NAV_API double nav_one_minus_cos_over_a2(double a);
/** (1 - sin(a)/a)/a^2, accurate for all a >= 0. */
NAV_API double nav_one_minus_sinc_over_a2(double a);

/** Quaternion of rotation vector phi [rad]: [cos(|phi|/2), sin(|phi|/2) phi/|phi|] (series below threshold). */
NAV_API nav_quat nav_quat_from_rotvec(nav_vec3 phi_rad);
/** Rotation vector [rad] of a unit quaternion, angle in [0, pi] (the shorter of q and -q). */
NAV_API nav_vec3 nav_quat_to_rotvec(nav_quat q);
/** DCM of a unit quaternion (C(q) v = q (x) v (x) conj(q)). */
NAV_API nav_mat3 nav_quat_to_dcm(nav_quat q);
/** Unit quaternion of a rotation matrix (Shepperd's method; w >= 0). */
NAV_API nav_quat nav_quat_from_dcm(nav_mat3 c);
/** exp([phi x]) by Rodrigues' formula, with series coefficients for small |phi|. */
NAV_API nav_mat3 nav_dcm_exp(nav_vec3 phi_rad);
/** Rotation vector phi with exp([phi x]) = c, angle in [0, pi]; robust near 0 and near pi. */
NAV_API nav_vec3 nav_dcm_log(nav_mat3 c);
/** Nearest orthonormal matrix, by the iteration C <- C - 1/2 (C C^T - I) C repeated to convergence. */
NAV_API nav_mat3 nav_dcm_orthonormalize(nav_mat3 c);
/** ||C^T C - I||_F: departure from orthonormality. */
NAV_API double nav_dcm_orthonormality_error(nav_mat3 c);
/** Rotation angle [rad] between two attitudes: |log(C1^T C2)| in [0, pi]. */
NAV_API double nav_dcm_angle_between(nav_mat3 c1, nav_mat3 c2);
/** Rotation angle [rad] between two unit quaternions, sign-invariant: 2 atan2(|v|, |w|) of conj(q1) q2. */
NAV_API double nav_quat_angle_between(nav_quat q1, nav_quat q2);
/** A(phi) = I + ((1-cos a)/a^2)[phi x] + ((1 - sin a/a)/a^2)[phi x]^2 (numerics.md E4.4). */
NAV_API nav_mat3 nav_rot_comp_matrix(nav_vec3 phi_rad);

/** C_b_n = R_z(yaw) R_y(pitch) R_x(roll). */
NAV_API nav_mat3 nav_euler_to_dcm(nav_euler e);
/**
 * ZYX Euler angles of C_b_n (numerics.md section 4.4 rule 3).
 * @param[out] gimbal_lock set true when |C_31| > 1 - 1e-12 (pitch at +/-90 deg); then roll = 0
 *             and yaw carries the observable combination. May be NULL.
 */
NAV_API nav_euler nav_dcm_to_euler(nav_mat3 c_b_n, bool *gimbal_lock);
NAV_API nav_quat nav_euler_to_quat(nav_euler e);
NAV_API nav_euler nav_quat_to_euler(nav_quat q, bool *gimbal_lock);

/** Wrap an angle to (-pi, pi]. */
NAV_API double nav_wrap_pi(double a_rad);
/** Wrap an angle to [0, 2 pi). */
NAV_API double nav_wrap_two_pi(double a_rad);

/* ---------------------------------------------------------------- small dense matrices (math.c) */

/**
 * Dense row-major n x n (or n x m) matrices used by the filter. Sizes are small (<= 64); the
 * caller owns all storage, nothing allocates. `a[i*n + j]` is row i, column j.
 */

/**
 * Cholesky factorisation A = L L^T of a symmetric positive-definite n x n matrix.
 * @param[out] l  n*n lower-triangular factor (upper part set to zero). May alias @p a.
 * @return NAV_OK, NAV_ERR_NUMERIC if A is not positive definite or not finite (l untouched then
 *         unless it aliases a), NAV_ERR_INVALID_ARG for NULL or n == 0.
 */
NAV_API NAV_NODISCARD nav_status nav_matn_cholesky(double *l, const double *a, size_t n);
/**
 * Solve A X = B for X given the Cholesky factor L of A (n x n) and B (n x m); X may alias B.
 */
NAV_API void nav_matn_chol_solve(double *x, const double *l, const double *b, size_t n, size_t m);
/** C = A B with A (n x k), B (k x m). C must not alias A or B. */
NAV_API void nav_matn_mul(double *c, const double *a, const double *b, size_t n, size_t k, size_t m);
/** C = A B^T with A (n x k), B (m x k). C must not alias A or B. */
NAV_API void nav_matn_mul_bt(double *c, const double *a, const double *b, size_t n, size_t k, size_t m);
/** P <- (P + P^T)/2 in place (n x n). */
NAV_API void nav_matn_symmetrize(double *p, size_t n);
/**
 * Symmetric product C = A P A^T with A (n x k), P (k x k) symmetric; work has room for n*k
 * doubles. The result is exactly symmetric (upper triangle mirrored).
 */
NAV_API void nav_matn_sandwich(double *c, const double *a, const double *p, size_t n, size_t k, double *work);

NAV_END_DECLS

#endif /* NAV_MATH_H */
