/*
 * The errors of a NED navigation state against a reference row (navcore_io internal, used by the
 * replay in recorded.c; header-only so that the white-box test can include it): the reference
 * item with what depends on its row alone, the scalar ned_errors() and ned_errors4(), which gives
 * the same values for four epochs at once, their arithmetic in the lanes of four-double vectors.
 */
#ifndef NAV_IO_REPLAY_ERRORS_H
#define NAV_IO_REPLAY_ERRORS_H

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_ins.h"
#include "navcore/nav_math.h"
#include "navcore/nav_recorded.h"
#include "err_math.h"

/* A reference row with the parts of its errors that depend on it alone (ned_errors()), which the
 * reading thread computes ahead of the navigation. */
typedef struct ref_item {
  nav_rec_pva row;
  double slt, clt, sot, cot; /* sin and cos of its latitude and longitude */
  nav_quat qt;               /* q_b_n of its Euler angles */
} ref_item;

static inline void ref_item_fill(ref_item *it) {
  const nav_rec_pva *ref = &it->row;
  it->slt = sin(ref->pos.lat_rad);
  it->clt = cos(ref->pos.lat_rad);
  it->sot = sin(ref->pos.lon_rad);
  it->cot = cos(ref->pos.lon_rad);
  it->qt = nav_euler_to_quat(ref->att);
}

/* C_n_e at (lat, lon) from their sines and cosines (rows of e, columns N, E, D). */
static inline nav_mat3 dcm_n_e(double sl, double cl, double so, double co) {
  const nav_mat3 c = {{{-sl * co, -so, -cl * co}, {-sl * so, co, -cl * so}, {cl, 0.0, -sl}}};
  return c;
}

/* WGS-84 ECEF position from sin/cos of latitude and longitude (Groves eq. 2.112). */
static inline nav_vec3 ecef_of(double sl, double cl, double so, double co, double h) {
  const double rn = NAV_WGS84_A_M / sqrt(1.0 - NAV_WGS84_E2 * sl * sl);
  return nav_vec3_make((rn + h) * cl * co, (rn + h) * cl * so, (rn * (1.0 - NAV_WGS84_E2) + h) * sl);
}

/* nav_wrap_pi() with its common case (an angle already in (-pi, pi], returned as is) inline. */
static inline double wrap_pi(double a) { return a > -NAV_PI && a <= NAV_PI ? a : nav_wrap_pi(a); }

/* nav_dcm_to_euler()'s formulas and gimbal-lock rule (navcore's math.c: pitch from atan2 and
 * hypot, yaw from the well-determined yaw -/+ roll, roll 0 within 1e-12 of pitch +/-90 deg) with
 * the kernels of err_math.h in place of libm's atan2 and hypot. */
#define RE_GIMBAL_LOCK_TOL 1e-12

static inline nav_euler em_dcm_to_euler(const nav_mat3 *c) {
  const double c31 = c->m[2][0];
  nav_euler e;
  e.pitch_rad = em_atan2(-c31, em_hypot(c->m[0][0], c->m[1][0]));
  if (fabs(c31) > 1.0 - RE_GIMBAL_LOCK_TOL) {
    e.roll_rad = 0.0;
    e.yaw_rad = wrap_pi(em_atan2(-c->m[0][1], c->m[1][1]));
  } else {
    e.roll_rad = wrap_pi(em_atan2(c->m[2][1], c->m[2][2]));
    const bool up = c31 <= 0.0; /* pitch >= 0: yaw - roll, else yaw + roll */
    const double yy = up ? c->m[1][2] - c->m[0][1] : -(c->m[0][1] + c->m[1][2]);
    const double yx = up ? c->m[1][1] + c->m[0][2] : c->m[1][1] - c->m[0][2];
    const double sg = up ? 1.0 : -1.0;
    e.yaw_rad = wrap_pi(em_atan2(yy, yx) + sg * e.roll_rad);
  }
  return e;
}

/*
 * The errors of nav_errors_compute() for a NED navigation state against a reference row,
 * without the ECEF round trips of the general path (which cost more than the whole navigation
 * step at 200 Hz): e-frame position and velocity differences resolved in the reference's NED,
 * the rotation angle between the two body-to-e attitudes, and differences of the local-level
 * Euler angles (the reference's straight from its row). The values agree with the general path
 * to rounding (a few 1e-10 m, 1e-14 rad: the same formulas without the geodetic inversions).
 * atan2 and hypot are err_math.h's (within 0.75 and 0.53 ulp of the exact values where glibc's are
 * within about 0.52 and 0.56), so that ned_errors4() can compute them in lanes.
 */
static inline nav_epoch_errors ned_errors(const ref_item *ri, const nav_ins_ned *e) {
  const nav_rec_pva *ref = &ri->row;
  nav_epoch_errors r;
  r.t_s = ref->t_s;
  const double slt = ri->slt, clt = ri->clt;
  const double sot = ri->sot, cot = ri->cot;
  const double sle = e->sin_lat, cle = e->cos_lat;
  const double soe = sin(e->pos.lon_rad), coe = cos(e->pos.lon_rad);
  const nav_mat3 Ct = dcm_n_e(slt, clt, sot, cot), Ce = dcm_n_e(sle, cle, soe, coe);
  const nav_mat3 Ct_t = nav_mat3_transpose(Ct);
  const nav_vec3 dr =
      nav_vec3_sub(ecef_of(sle, cle, soe, coe, e->pos.h_m), ecef_of(slt, clt, sot, cot, ref->pos.h_m));
  r.pos_err_n_m = nav_mat3_mul_vec(Ct_t, dr);
  r.pos_err_h_m = em_hypot(r.pos_err_n_m.x, r.pos_err_n_m.y);
  r.pos_err_v_m = fabs(r.pos_err_n_m.z);
  const nav_vec3 dv = nav_vec3_sub(nav_mat3_mul_vec(Ce, e->v_n_mps), nav_mat3_mul_vec(Ct, ref->v_n_mps));
  r.vel_err_n_mps = nav_mat3_mul_vec(Ct_t, dv);
  r.vel_err_mps = nav_vec3_norm(r.vel_err_n_mps);
  /* C_b_e(ref)^T C_b_e(est) = C_n_b(ref) M C_b_n(est) with M = C_e_n(ref) C_n_e(est) ~ I. */
  const nav_quat qt = ri->qt;
  const nav_quat qm = nav_quat_from_dcm(nav_mat3_mul(Ct_t, Ce));
  /* nav_quat_angle_between(qt, q2): 2 atan2(|v|, |w|) of the relative quaternion. */
  const nav_quat rq = nav_quat_mul(nav_quat_conj(qt), nav_quat_mul(qm, e->q_b_n));
  r.att_err_rad = 2.0 * em_atan2(sqrt(rq.x * rq.x + rq.y * rq.y + rq.z * rq.z), fabs(rq.w));
  const nav_mat3 Cb = nav_quat_to_dcm(e->q_b_n);
  const nav_euler ee = em_dcm_to_euler(&Cb);
  r.euler_err.roll_rad = wrap_pi(ee.roll_rad - ref->att.roll_rad);
  r.euler_err.pitch_rad = wrap_pi(ee.pitch_rad - ref->att.pitch_rad);
  r.euler_err.yaw_rad = wrap_pi(ee.yaw_rad - ref->att.yaw_rad);
  return r;
}

/*
 * ned_errors() of four epochs: every lane does the scalar function's operations in its order
 * (IEEE +, -, *, / and sqrt are correctly rounded in a vector lane as in a register, and
 * navcore_io is built with -ffp-contract=off, so no product is fused into a sum), with the same
 * libm calls per lane (sin and cos of the longitude, wrap_pi) and the four-lane forms of
 * err_math.h's atan2 and hypot, which give their scalar forms' bits. The inlined parts of
 * nav_quat_from_dcm, nav_quat_angle_between and nav_quat_to_dcm follow math.c: the quaternion from its trace
 * branch when every lane takes it (M = C_e_n(ref) C_n_e(est) is within a small rotation of I, so the trace is
 * the largest diagonal sum), else nav_quat_from_dcm per lane. So each result is the scalar one bit for bit
 * (test_replay_errors).
 */
typedef double nav_re4 __attribute__((vector_size(32)));
/* Four-double vectors without AVX are passed in memory, not in a register: a note on the ABI that
 * does not concern these functions, which are inlined and never cross a library boundary. GCC
 * reports it where they are inlined, so it stays off for the rest of the including file. */
#pragma GCC diagnostic ignored "-Wpsabi"
#define RE4_INLINE static inline __attribute__((always_inline))

typedef struct re4_mat3 {
  nav_re4 m[3][3];
} re4_mat3;

typedef struct re4_vec3 {
  nav_re4 x, y, z;
} re4_vec3;

RE4_INLINE re4_mat3 re4_dcm_n_e(nav_re4 sl, nav_re4 cl, nav_re4 so, nav_re4 co) {
  const nav_re4 zero = {0.0, 0.0, 0.0, 0.0};
  const re4_mat3 c = {{{-sl * co, -so, -cl * co}, {-sl * so, co, -cl * so}, {cl, zero, -sl}}};
  return c;
}

RE4_INLINE re4_vec3 re4_ecef_of(nav_re4 sl, nav_re4 cl, nav_re4 so, nav_re4 co, nav_re4 h) {
  const nav_re4 rn = NAV_WGS84_A_M / em_sqrt4(1.0 - NAV_WGS84_E2 * sl * sl);
  const re4_vec3 r = {(rn + h) * cl * co, (rn + h) * cl * so, (rn * (1.0 - NAV_WGS84_E2) + h) * sl};
  return r;
}

RE4_INLINE re4_vec3 re4_mul_vec(const re4_mat3 *a, re4_vec3 v) {
  const re4_vec3 r = {a->m[0][0] * v.x + a->m[0][1] * v.y + a->m[0][2] * v.z,
                      a->m[1][0] * v.x + a->m[1][1] * v.y + a->m[1][2] * v.z,
                      a->m[2][0] * v.x + a->m[2][1] * v.y + a->m[2][2] * v.z};
  return r;
}

RE4_INLINE void ned_errors4(const ref_item *const ri[4], const nav_ins_ned *const e[4], nav_epoch_errors r[4]) {
  nav_re4 slt, clt, sot, cot, sle, cle, soe, coe, ht, he;
  re4_vec3 vt, ve;
  nav_re4 qtw, qtx, qty, qtz, qew, qex, qey, qez;
  for (int k = 0; k < 4; ++k) {
    slt[k] = ri[k]->slt;
    clt[k] = ri[k]->clt;
    sot[k] = ri[k]->sot;
    cot[k] = ri[k]->cot;
    ht[k] = ri[k]->row.pos.h_m;
    vt.x[k] = ri[k]->row.v_n_mps.x;
    vt.y[k] = ri[k]->row.v_n_mps.y;
    vt.z[k] = ri[k]->row.v_n_mps.z;
    qtw[k] = ri[k]->qt.w;
    qtx[k] = ri[k]->qt.x;
    qty[k] = ri[k]->qt.y;
    qtz[k] = ri[k]->qt.z;
    sle[k] = e[k]->sin_lat;
    cle[k] = e[k]->cos_lat;
    soe[k] = sin(e[k]->pos.lon_rad);
    coe[k] = cos(e[k]->pos.lon_rad);
    he[k] = e[k]->pos.h_m;
    ve.x[k] = e[k]->v_n_mps.x;
    ve.y[k] = e[k]->v_n_mps.y;
    ve.z[k] = e[k]->v_n_mps.z;
    qew[k] = e[k]->q_b_n.w;
    qex[k] = e[k]->q_b_n.x;
    qey[k] = e[k]->q_b_n.y;
    qez[k] = e[k]->q_b_n.z;
  }
  const re4_mat3 Ct = re4_dcm_n_e(slt, clt, sot, cot), Ce = re4_dcm_n_e(sle, cle, soe, coe);
  re4_mat3 Ct_t;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      Ct_t.m[i][j] = Ct.m[j][i];
  const re4_vec3 pe = re4_ecef_of(sle, cle, soe, coe, he), pt = re4_ecef_of(slt, clt, sot, cot, ht);
  const re4_vec3 dr = {pe.x - pt.x, pe.y - pt.y, pe.z - pt.z};
  const re4_vec3 pn = re4_mul_vec(&Ct_t, dr);
  const re4_vec3 ae = re4_mul_vec(&Ce, ve), at = re4_mul_vec(&Ct, vt);
  const re4_vec3 dv = {ae.x - at.x, ae.y - at.y, ae.z - at.z};
  const re4_vec3 vn = re4_mul_vec(&Ct_t, dv);
  const nav_re4 vnorm = em_sqrt4(vn.x * vn.x + vn.y * vn.y + vn.z * vn.z);
  /* M = Ct_t Ce (nav_mat3_mul), then nav_quat_from_dcm(M). */
  re4_mat3 M;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      M.m[i][j] = Ct_t.m[i][0] * Ce.m[0][j] + Ct_t.m[i][1] * Ce.m[1][j] + Ct_t.m[i][2] * Ce.m[2][j];
  const nav_re4 c11 = M.m[0][0], c22 = M.m[1][1], c33 = M.m[2][2];
  const nav_re4 tr = c11 + c22 + c33;
  bool trace_branch = true;
  for (int k = 0; k < 4; ++k)
    trace_branch = trace_branch && tr[k] >= c11[k] && tr[k] >= c22[k] && tr[k] >= c33[k];
  nav_re4 mw, mx, my, mz;
  if (trace_branch) {
    const nav_re4 rr = em_sqrt4(1.0 + tr); /* = 2|w| >= 0: no sign flip */
    const nav_re4 f = 0.5 / rr;
    const nav_re4 w = 0.5 * rr;
    const nav_re4 x = (M.m[2][1] - M.m[1][2]) * f;
    const nav_re4 y = (M.m[0][2] - M.m[2][0]) * f;
    const nav_re4 z = (M.m[1][0] - M.m[0][1]) * f;
    const nav_re4 s = 1.0 / em_sqrt4(w * w + x * x + y * y + z * z);
    mw = w * s;
    mx = x * s;
    my = y * s;
    mz = z * s;
  } else {
    for (int k = 0; k < 4; ++k) {
      nav_mat3 mk;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          mk.m[i][j] = M.m[i][j][k];
      const nav_quat q = nav_quat_from_dcm(mk);
      mw[k] = q.w;
      mx[k] = q.x;
      my[k] = q.y;
      mz[k] = q.z;
    }
  }
  /* q2 = qm (x) q_b_n(est); rel = conj(qt) (x) q2 (nav_quat_mul, nav_quat_angle_between). */
  const nav_re4 q2w = mw * qew - mx * qex - my * qey - mz * qez;
  const nav_re4 q2x = mw * qex + mx * qew + my * qez - mz * qey;
  const nav_re4 q2y = mw * qey - mx * qez + my * qew + mz * qex;
  const nav_re4 q2z = mw * qez + mx * qey - my * qex + mz * qew;
  const nav_re4 cw = qtw, cx = -qtx, cy = -qty, cz = -qtz;
  const nav_re4 rw = cw * q2w - cx * q2x - cy * q2y - cz * q2z;
  const nav_re4 rx = cw * q2x + cx * q2w + cy * q2z - cz * q2y;
  const nav_re4 ry = cw * q2y - cx * q2z + cy * q2w + cz * q2x;
  const nav_re4 rz = cw * q2z + cx * q2y - cy * q2x + cz * q2w;
  const nav_re4 vpart = em_sqrt4(rx * rx + ry * ry + rz * rz), wabs = em_abs4(rw);
  /* C_b_n of the estimate (nav_quat_to_dcm). */
  const nav_re4 ww = qew * qew, xx = qex * qex, yy = qey * qey, zz = qez * qez;
  const nav_re4 xy = qex * qey, xz = qex * qez, yz = qey * qez;
  const nav_re4 wx = qew * qex, wy = qew * qey, wz = qew * qez;
  const re4_mat3 Cb = {{{ww + xx - yy - zz, 2.0 * (xy - wz), 2.0 * (xz + wy)},
                        {2.0 * (xy + wz), ww - xx + yy - zz, 2.0 * (yz - wx)},
                        {2.0 * (xz - wy), 2.0 * (yz + wx), ww - xx - yy + zz}}};
  /* The Euler angles of the estimate in lanes (em_dcm_to_euler's operations); a lane within the
   * gimbal-lock tolerance takes em_dcm_to_euler itself. */
  const nav_re4 pos_h = em_hypot4(pn.x, pn.y);
  const nav_re4 att = 2.0 * em_atan2_4(vpart, wabs);
  const nav_re4 pitch = em_atan2_4(-Cb.m[2][0], em_hypot4(Cb.m[0][0], Cb.m[1][0]));
  const nav_re4 roll_raw = em_atan2_4(Cb.m[2][1], Cb.m[2][2]);
  nav_re4 yy_arg, yx_arg, sg;
  for (int k = 0; k < 4; ++k) {
    const bool up = Cb.m[2][0][k] <= 0.0;
    yy_arg[k] = up ? Cb.m[1][2][k] - Cb.m[0][1][k] : -(Cb.m[0][1][k] + Cb.m[1][2][k]);
    yx_arg[k] = up ? Cb.m[1][1][k] + Cb.m[0][2][k] : Cb.m[1][1][k] - Cb.m[0][2][k];
    sg[k] = up ? 1.0 : -1.0;
  }
  const nav_re4 yaw_raw = em_atan2_4(yy_arg, yx_arg);
  for (int k = 0; k < 4; ++k) {
    const nav_rec_pva *ref = &ri[k]->row;
    nav_epoch_errors *o = &r[k];
    o->t_s = ref->t_s;
    o->pos_err_n_m = nav_vec3_make(pn.x[k], pn.y[k], pn.z[k]);
    o->pos_err_h_m = pos_h[k];
    o->pos_err_v_m = fabs(pn.z[k]);
    o->vel_err_n_mps = nav_vec3_make(vn.x[k], vn.y[k], vn.z[k]);
    o->vel_err_mps = vnorm[k];
    o->att_err_rad = att[k];
    nav_euler ee;
    if (fabs(Cb.m[2][0][k]) > 1.0 - RE_GIMBAL_LOCK_TOL) {
      nav_mat3 ck;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          ck.m[i][j] = Cb.m[i][j][k];
      ee = em_dcm_to_euler(&ck);
    } else {
      ee.pitch_rad = pitch[k];
      ee.roll_rad = wrap_pi(roll_raw[k]);
      ee.yaw_rad = wrap_pi(yaw_raw[k] + sg[k] * ee.roll_rad);
    }
    o->euler_err.roll_rad = wrap_pi(ee.roll_rad - ref->att.roll_rad);
    o->euler_err.pitch_rad = wrap_pi(ee.pitch_rad - ref->att.pitch_rad);
    o->euler_err.yaw_rad = wrap_pi(ee.yaw_rad - ref->att.yaw_rad);
  }
}

#undef RE4_INLINE

/* ned_errors4() compiled twice, for the x86-64 baseline and for AVX2 (the loader picks one for the
 * CPU through an ifunc), as navcore's hot kernels are: the same IEEE operations in the same order
 * in both (the "avx2" target has no FMA, and the build has -ffp-contract=off), four lanes in one
 * 256-bit register instead of two halves. Off for other compilers and targets, in sanitizer builds
 * (the ifunc resolver runs before the sanitizer runtime is set up) and with -DNAV_NO_CLONES. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) &&                 \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__) && !defined(NAV_NO_CLONES)
__attribute__((target_clones("avx2", "default")))
#endif
static void ned_errors4_clones(const ref_item *const ri[4], const nav_ins_ned *const e[4], nav_epoch_errors r[4]) {
  ned_errors4(ri, e, r);
}

#endif /* NAV_IO_REPLAY_ERRORS_H */
