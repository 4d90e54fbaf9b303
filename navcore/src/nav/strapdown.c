/*
 * Strapdown mechanization (numerics.md section 4).
 *
 * Flat Earth, the non-rotating scene frame l (flat-l rows): C(k) = C(k-1) exp([phi_k x]);
 * v_k = v_(k-1) + C(k-1) dv_l_body + g dt; p_k = p_(k-1) + dt/2 (v_(k-1) + v_k).
 *
 * WGS-84, local-level NED (NED rows of 4.1-4.3; Groves 2nd ed. section 5.4, Savage JGCD 21(2)):
 *   C_b_n(k) = exp(-[zeta x]) C_b_n(k-1) exp([phi x]),  zeta = (omega_ie_n + omega_en_n)_(k-1/2) dt
 *   v_k = v_(k-1) + C_b_n(k-1) dv_body + frame term (-1/2 [zeta x] C_b_n(k-1) dv + ...)
 *         + [g_n - (2 omega_ie_n + omega_en_n) x v_n]_(k-1/2) dt
 *   h, lat, lon by the curvilinear trapezoidal rule (4.3), lon wrapped to (-pi, pi].
 * WGS-84, ECEF (ECEF rows):
 *   C_b_e(k) = R_z(-omega_ie dt) C_b_e(k-1) exp([phi x])
 *   v_k = v_(k-1) + C_b_e(k-1) dv_body + frame term (-1/2 [omega_ie_e x] C_b_e(k-1) dv dt + ...)
 *         + [g_e(r) - 2 omega_ie_e x v]_(k-1/2) dt,   r_k = r_(k-1) + dt/2 (v_(k-1) + v_k).
 * dv_body is dv + 1/2 dtheta x dv for algorithm (a), A(phi) dv + dv_scul (E4.4, E4.5) for (b);
 * the frame term (frame_rotation_term) is first order for (a) and second order for (b), so that
 * body and frame rotations cancel consistently (exactly at rest).
 *
 * Mid-interval terms: the gravity/Coriolis/transport bracket evaluated at k-1 only leaves a
 * global O(dt) velocity error (numerics.md 4.2: 1.28e-3 m/s in T5.5). A predictor gives the
 * k values to O(dt^2) locally and the corrector uses the mean of the k-1 and predicted-k values
 * (trapezoid, second order); NAV_INS_GRAVITY_START_OF_INTERVAL keeps the k-1 values (for
 * comparisons only).
 *
 * Order of updates inside a step: velocity (needs the attitude at k-1), then position (needs
 * both velocities), then attitude. Everything is computed into locals and committed at the end,
 * so a refused or non-finite step leaves the state untouched. The NED step is the hot path of
 * the WGS-84 runs: it uses one sin/cos pair of lat/2 and one of lon/2 per step (the output in
 * e needs both anyway), series instead of trig for small rotations, and reciprocals shared or
 * refined from a nearby point instead of fresh divisions. The step helpers are inlined into one
 * function per configuration (algorithm x gravity step), and nav_ins_step is compiled for the
 * baseline and for AVX2 (nav_clones.h, bit-identical): about 1010 instructions per NED step,
 * 860 per ECEF step (its normal gravity without trigonometry, nav/ecef_gravity.h), 890 flat
 * (high order, 200 Hz; 1360, 2290 and 970 before).
 */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_ins.h"
#include "nav/ecef_gravity.h"
#include "nav_clones.h"
#include "math/quat_dcm_inline.h"
#include "math/sincos_quarter.h"
#include "nav/strapdown_lanes.h"

/* 1 - e^2 = (b/a)^2. */
#define E2M (1.0 - NAV_WGS84_E2)

/* Latitude steps below this use the addition theorem with Taylor series of sin/cos(d) for the
 * predicted point: the first neglected terms, d^6/720 and d^7/5040, are < 1.4e-21 at 1e-3 rad,
 * far below double rounding of sin(lat). (A step of 1e-3 rad is 6.4 km: 8 km/s at 1.25 Hz.) */
#define LAT_STEP_SERIES_RAD 1e-3

/* Below this rotation angle the coefficients of q(phi), A(phi) are evaluated by their Taylor
 * series through a^6 instead of sin/cos: the first neglected terms (a^8/10321920 for cos(a/2),
 * a^8/3628800 for (1 - cos a)/a^2, ...) are < 3e-23 at a = 1e-2, far below the rounding of the
 * coefficients (~1e-17), so the series is as exact as the closed form, also above the 1e-4
 * threshold numerics.md 4.1 gives for cancellation; it needs no sqrt and no trig. Typical
 * increments (|omega| dt < 0.01 rad, e.g. 2 rad/s at 200 Hz) and every navigation-frame
 * rotation zeta take this branch. */
#define ROT_SERIES_RAD 1e-2

/* Newton refinements of a reciprocal or reciprocal square root from a nearby point's value are
 * used when the relative residual e is below this: the result's relative error, O(e^2) < 1e-18,
 * is below the rounding of the direct evaluation. */
#define NEWTON_REL 1e-9

/* The per-step helpers are inlined into each step function so that the whole step is one block of
 * straight-line code with its values in registers (constant configuration tests fold away). */
#if defined(__GNUC__)
#define HOT_INLINE static inline __attribute__((always_inline))
#else
#define HOT_INLINE static inline
#endif

/* Entries of the cache of Earth-rotation steps per dt (ECEF). */
#define ROT_CACHE 4

/* Earth terms at one point of the NED mechanization. */
typedef struct ned_terms {
  double sl, cl, icl; /* sin(lat), cos(lat), 1/cos(lat) */
  double RM, RN;      /* meridian and prime-vertical radii [m] */
  double iRMh, iRNh;  /* 1/(R_M + h), 1/(R_N + h) [1/m] */
  double isq, inv;    /* 1/sqrt(1 - e^2 sin^2 lat), 1/((R_M + h)(R_N + h) cos lat) (Newton seeds) */
  nav_vec3 g_n;       /* gravity (gravitation + centrifugal) in n [m/s^2] */
} ned_terms;

struct nav_ins {
  nav_ins_config cfg;
  nav_ins_state s; /* the state in F (output) */
  bool have_prev;
  nav_vec3 prev_dtheta_b_rad;
  nav_vec3 prev_dv_b_mps;
  /* Vertical hold (clamp_vertical): the last aided height and down velocity. */
  double hold_h_m, hold_vd_mps;
  /* WGS-84 NED state. */
  double lat_rad, lon_rad, h_m;
  nav_vec3 v_n_mps;
  nav_quat q_b_n;
  ned_terms et; /* Earth terms at the current point */
  /* The e-frame view s of the NED state is computed on demand (nav_ins_get_state): a step
   * leaves it stale together with sin, cos(lat/2) of the new point. */
  bool view_stale;
  double view_sh, view_ch;
  /* WGS-84 ECEF state: s holds r, v, q; the gravity at s.r_fb_f_m is cached. */
  nav_vec3 g_e_mps2;
  /* cos, sin of omega_ie dt / 2 for the last ROT_CACHE distinct dt (R_z(-omega_ie dt)): the
   * interval t_k - t_(k-1) of the time stamps k dt takes a few values differing in the last bits,
   * which alternate early in a run (a single cached dt was recomputed every other step). */
  double rot_dt_s[ROT_CACHE], rot_c[ROT_CACHE], rot_s[ROT_CACHE];
  int rot_next;
  char msg[256];
};

nav_ins_config nav_ins_config_default(void) {
  nav_ins_config c;
  c.earth_model = NAV_EARTH_FLAT;
  c.algorithm = NAV_MECH_FIRST_ORDER;
  c.mech_frame = NAV_MECH_NED;
  c.gravity_model = NAV_GRAVITY_NORMAL;
  c.g_l_mps2 = nav_vec3_make(0.0, 0.0, 9.80665);
  c.clamp_vertical = false;
  c.gravity_step = NAV_INS_GRAVITY_PREDICTOR_CORRECTOR;
  return c;
}

/* ------------------------------------------------------------------ small helpers */

/* Renormalise a quaternion whose norm is 1 to rounding (a product of unit quaternions): one
 * Newton step for 1/sqrt(n2), s = (3 - n2)/2, leaves an error of O((n2 - 1)^2) ~ 1e-32, i.e. the
 * same result as q/|q| to rounding, without sqrt and division (numerics.md 4.4 rule 1). Any
 * larger departure takes the exact path. */
static inline nav_quat renormalize(nav_quat q) {
  const double n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
  if (!(fabs(n2 - 1.0) < 1e-8)) return nav_quat_normalize(q);
  const double s = 0.5 * (3.0 - n2);
  nav_quat r = {q.w * s, q.x * s, q.y * s, q.z * s};
  return r;
}

/* q(v) = [cos(|v|/2), sin(|v|/2) v/|v|] (numerics.md 4.1); series below ROT_SERIES_RAD. */
static inline nav_quat quat_of_rotvec(nav_vec3 v) {
  const double a2 = nav_vec3_dot(v, v);
  if (!(a2 < ROT_SERIES_RAD * ROT_SERIES_RAD)) return nav_quat_from_rotvec(v);
  const double w = 1.0 - a2 * (1.0 / 8.0 - a2 * (1.0 / 384.0 - a2 * (1.0 / 46080.0)));
  const double s = 0.5 - a2 * (1.0 / 48.0 - a2 * (1.0 / 3840.0 - a2 * (1.0 / 645120.0)));
  nav_quat q = {w, s * v.x, s * v.y, s * v.z};
  return q;
}

/* ------------------------------------------------------------------ Earth terms (NED) */

/*
 * Radii (Groves 2nd ed. eqs. 2.105-2.106) and gravity at (lat, h) from sin/cos of latitude.
 * Normal gravity (TR8350.2 eqs. 4-1, 4-3; numerics.md E3.10-E3.11) is the formula of
 * nav_earth_gravity_normal_mps2() evaluated with the trig already at hand (test_mech checks that
 * both, and nav_gravity_e_mps2(), agree to rounding). J2: the shared nav_gravity_e_mps2()
 * rotated into n; the J2 field and the centrifugal term are axially symmetric, so the point is
 * placed on the meridian lon = 0 and no trig of longitude is needed.
 */
HOT_INLINE void ned_terms_fill(bool j2, double sl, double cl, double h, const ned_terms *near, ned_terms *t) {
  const double s2 = sl * sl;
  const double den2 = 1.0 - NAV_WGS84_E2 * s2;
  /* 1/sqrt(den2): one Newton step y (3 - den2 y^2)/2 from a nearby point's value leaves a
   * relative error 1.5 e^2, e = 1 - den2 y^2; below NEWTON_REL (e^2 < 1e-18) that is the
   * correctly rounded result to within an ulp, without the sqrt and division latency. */
  double isq;
  const double e_sq = near ? 1.0 - den2 * near->isq * near->isq : 1.0;
  if (fabs(e_sq) < NEWTON_REL)
    isq = near->isq * (1.0 + 0.5 * e_sq);
  else
    isq = 1.0 / sqrt(den2);
  t->sl = sl;
  t->cl = cl;
  t->isq = isq;
  t->RN = NAV_WGS84_A_M * isq;
  t->RM = NAV_WGS84_A_M * E2M * isq * isq * isq;
  /* Three reciprocals from one (a few ulp): 1/(R_M + h), 1/(R_N + h), 1/cos lat. The division
   * is again a Newton step y (1 + e), e = 1 - x y, from a nearby point when |e| < NEWTON_REL. */
  const double A = t->RM + h, B = t->RN + h, P = A * B, x = P * cl;
  const double e_inv = near ? 1.0 - x * near->inv : 1.0;
  t->inv = fabs(e_inv) < NEWTON_REL ? near->inv * (1.0 + e_inv) : 1.0 / x;
  t->iRMh = t->inv * B * cl;
  t->iRNh = t->inv * A * cl;
  t->icl = t->inv * P;
  if (j2) {
    /* Geodetic -> ECEF (Groves eq. 2.112) on lon = 0, then C_e_n g_e (rows of C_e_n: north,
     * east, down). */
    const nav_vec3 r_e = nav_vec3_make(B * cl, 0.0, (t->RN * E2M + h) * sl);
    const nav_vec3 g_e = nav_gravity_e_mps2(NAV_GRAVITY_J2, r_e);
    t->g_n = nav_vec3_make(-sl * g_e.x + cl * g_e.z, g_e.y, -cl * g_e.x - sl * g_e.z);
  } else {
    const double a = NAV_WGS84_A_M;
    const double gamma0 = NAV_WGS84_GAMMA_E_MPS2 * (1.0 + NAV_WGS84_SOMIGLIANA_K * s2) * isq;
    const double lin = (2.0 / a) * (1.0 + NAV_WGS84_F + NAV_WGS84_M - 2.0 * NAV_WGS84_F * s2);
    const double quad = 3.0 / (a * a);
    t->g_n = nav_vec3_make(0.0, 0.0, gamma0 * (1.0 - lin * h + quad * h * h));
  }
}

/* omega_in_n = omega_ie_n + omega_en_n and the Coriolis-plus-transport rate
 * 2 omega_ie_n + omega_en_n (numerics.md E3.9; Groves eqs. 5.41, 5.44). Needs cos(lat) > 0. */
static inline void ned_rates(const ned_terms *t, nav_vec3 v_n, nav_vec3 *w_in_n, nav_vec3 *w_cor_n) {
  const double w = NAV_WGS84_OMEGA_IE_RPS;
  const double east = v_n.y * t->iRNh;
  const nav_vec3 w_ie = nav_vec3_make(w * t->cl, 0.0, -w * t->sl);
  const nav_vec3 w_en = nav_vec3_make(east, -v_n.x * t->iRMh, -east * t->sl * t->icl);
  *w_in_n = nav_vec3_add(w_ie, w_en);
  *w_cor_n = nav_vec3_add(*w_in_n, w_ie);
}

/* The specific-force-free part of the NED velocity rate: g_n - (2 omega_ie_n + omega_en_n) x v_n. */
static inline nav_vec3 ned_force(const ned_terms *t, nav_vec3 w_cor_n, nav_vec3 v_n) {
  return nav_vec3_sub(t->g_n, nav_vec3_cross(w_cor_n, v_n));
}

/* sin and cos of lat + d from those of lat (addition theorem; series for small d). */
static inline void sincos_shift(double sl, double cl, double lat_new, double d, double *s_out,
                                double *c_out) {
  if (fabs(d) < LAT_STEP_SERIES_RAD) {
    const double d2 = d * d;
    const double cd = 1.0 - d2 * (0.5 - d2 / 24.0);
    const double sd = d * (1.0 - d2 * (1.0 / 6.0 - d2 / 120.0));
    *s_out = sl * cd + cl * sd;
    *c_out = cl * cd - sl * sd;
  } else {
    *s_out = sin(lat_new);
    *c_out = cos(lat_new);
  }
}

/* ------------------------------------------------------------------ body increments */

/*
 * Body-frame terms of one interval for the WGS-84 mechanizations: the attitude increment
 * quaternion q(phi) and the body-frame velocity increment dv_body.
 * (a): phi = dtheta (E4.1), dv_body = dv + 1/2 dtheta x dv.
 * (b): phi = dtheta + 1/12 dtheta_(k-1) x dtheta (E4.2), dv_body = A(phi) dv + dv_scul (E4.4,
 *      E4.5), A(phi) v = v + b1 phi x v + b2 phi x (phi x v), b1 = (1 - cos a)/a^2,
 *      b2 = (1 - sin a/a)/a^2. Below ROT_SERIES_RAD every coefficient is a series in a^2; above,
 *      one sin/cos pair of a/2 gives q(phi) = [cos(a/2), sin(a/2)/a phi] and
 *      b1 = 1/2 (sin(a/2)/(a/2))^2, and b2 comes from the shared nav_one_minus_sinc_over_a2().
 *      At the first step there is no previous increment and the coning and sculling terms are
 *      dropped (one-off O(dt^3) error, numerics.md T5.1 note).
 */
HOT_INLINE void body_terms(bool high, const nav_ins *ins, nav_vec3 dth, nav_vec3 dv, nav_vec3 *phi_out,
                           nav_quat *q_phi, nav_vec3 *dv_body) {
  if (!high) {
    *phi_out = dth;
    *q_phi = quat_of_rotvec(dth);
    *dv_body = nav_vec3_add(dv, nav_vec3_scale(nav_vec3_cross(dth, dv), 0.5));
    return;
  }
  const nav_vec3 pdth = ins->have_prev ? ins->prev_dtheta_b_rad : nav_vec3_zero();
  const nav_vec3 pdv = ins->have_prev ? ins->prev_dv_b_mps : nav_vec3_zero();
  const nav_vec3 phi = nav_vec3_add(dth, nav_vec3_scale(nav_vec3_cross(pdth, dth), 1.0 / 12.0));
  *phi_out = phi;
  const double a2 = nav_vec3_dot(phi, phi);
  double qw, qs, b1, b2;
  if (a2 < ROT_SERIES_RAD * ROT_SERIES_RAD) {
    qw = 1.0 - a2 * (1.0 / 8.0 - a2 * (1.0 / 384.0 - a2 * (1.0 / 46080.0)));
    qs = 0.5 - a2 * (1.0 / 48.0 - a2 * (1.0 / 3840.0 - a2 * (1.0 / 645120.0)));
    b1 = 0.5 - a2 * (1.0 / 24.0 - a2 * (1.0 / 720.0 - a2 * (1.0 / 40320.0)));
    b2 = 1.0 / 6.0 - a2 * (1.0 / 120.0 - a2 * (1.0 / 5040.0 - a2 * (1.0 / 362880.0)));
  } else {
    const double a = sqrt(a2), hh = 0.5 * a;
    const double sh = sin(hh);
    qw = cos(hh);
    qs = sh / a;
    const double sinc_h = sh / hh;
    b1 = 0.5 * sinc_h * sinc_h;
    b2 = nav_one_minus_sinc_over_a2(a);
  }
  q_phi->w = qw;
  q_phi->x = qs * phi.x;
  q_phi->y = qs * phi.y;
  q_phi->z = qs * phi.z;
  const nav_vec3 pxdv = nav_vec3_cross(phi, dv);
  const nav_vec3 dv_rot =
      nav_vec3_add(nav_vec3_axpy(dv, b1, pxdv), nav_vec3_scale(nav_vec3_cross(phi, pxdv), b2));
  const nav_vec3 dv_scul =
      nav_vec3_scale(nav_vec3_add(nav_vec3_cross(pdth, dv), nav_vec3_cross(pdv, dth)), 1.0 / 12.0);
  *dv_body = nav_vec3_add(dv_rot, dv_scul);
}

/*
 * Velocity term of the rotation of the navigation frame (n or e) by zeta during the interval
 * (numerics.md 4.2; Savage JGCD 21(2); Groves eq. 5.84): the specific-force integral is
 * int_0^1 exp(-s [zeta x]) C exp(s [phi x]) dv ds for constant rates, whose expansion is
 *   C dv + (C [phi x] - [zeta x] C) dv / 2 + (C [phi x]^2 / 6 - [zeta x] C [phi x] / 3 + [zeta x]^2 C / 6)
 * dv. The body part is C A(phi) dv for (b), exact in phi; the frame part is returned here: (a): -1/2 zeta x C
 * dv   (first order, matching dv + 1/2 dtheta x dv), (b): zeta x (-1/2 C dv + (zeta/6 - C phi/3) x C dv) (all
 * second-order terms). Mixing orders would leave a residual: at rest (C phi = zeta) (b) with the first-order
 * frame term alone leaves zeta x (zeta x C dv)/6 per step, a velocity drift of up to omega_ie^2 g dt / 6
 * (9e-10 m/s^2 at dt = 0.1 s, mostly vertical), which the closure test at rest detects.
 */
HOT_INLINE nav_vec3 frame_rotation_term(bool high, nav_vec3 zeta, nav_vec3 cdv, nav_vec3 cphi) {
  if (!high) return nav_vec3_scale(nav_vec3_cross(zeta, cdv), -0.5);
  const nav_vec3 k = nav_vec3_sub(nav_vec3_scale(zeta, 1.0 / 6.0), nav_vec3_scale(cphi, 1.0 / 3.0));
  return nav_vec3_cross(zeta, nav_vec3_add(nav_vec3_scale(cdv, -0.5), nav_vec3_cross(k, cdv)));
}

/* ------------------------------------------------------------------ NED point and output */

/*
 * The ECEF output state of the NED mechanization from its current point, with the Earth terms
 * ins->et already filled and sh, ch = sin, cos(lat/2). Trig comes from half angles: with
 * so, co = sin, cos(lon/2),
 *   sin lon = 2 so co,  cos lon = (co - so)(co + so)  (and likewise for lat, see ned_half_lat),
 *   q_n_e = q_z(lon) (x) q_y(-(lat + pi/2)) = [co ca, -so sa, co sa, so ca],
 *   ca = cos(-(lat/2 + pi/4)) = (ch - sh)/sqrt(2),  sa = -(sh + ch)/sqrt(2),
 * which is C_n_e of nav_earth_dcm_n_e() (Groves eq. 2.150 transposed) without a DCM ->
 * quaternion conversion; r_e is nav_earth_geodetic_to_ecef() (Groves eq. 2.112).
 */
static void ned_output(nav_ins *ins, double sh, double ch) {
  const ned_terms *t = &ins->et;
  const double sl = t->sl, cl = t->cl;
  const double ho = 0.5 * ins->lon_rad;
  const double so = sin(ho), co = cos(ho);
  const double slo = 2.0 * so * co, clo = (co - so) * (co + so);
  const double rho = (t->RN + ins->h_m) * cl;
  ins->s.r_fb_f_m = nav_vec3_make(rho * clo, rho * slo, (t->RN * E2M + ins->h_m) * sl);
  const nav_mat3 C_n_e = {{{-sl * clo, -slo, -cl * clo}, {-sl * slo, clo, -cl * slo}, {cl, 0.0, -sl}}};
  ins->s.v_fb_f_mps = nav_mat3_mul_vec(C_n_e, ins->v_n_mps);
  const double r2 = 0.70710678118654752440; /* 1/sqrt(2) */
  const double ca = (ch - sh) * r2, sa = -(sh + ch) * r2;
  const nav_quat q_n_e = {co * ca, -so * sa, co * sa, so * ca};
  /* A product of two unit quaternions: unit to rounding, no renormalisation needed. */
  ins->s.q_b_f = nav_quat_mul(q_n_e, ins->q_b_n);
}

/* sin, cos of lat/2 and, from them, sin lat = 2 sh ch and cos lat = (ch - sh)(ch + sh). lat/2 is
 * exact, so cos lat keeps an absolute accuracy of ~1e-16 near the poles, the same as the rounding
 * of lat itself there; one sin/cos pair serves the Earth terms and q_n_e. */
static void ned_half_lat(double lat, double *sh, double *ch, double *sl, double *cl) {
  const double hl = 0.5 * lat;
  /* navcore's kernel (math/sincos_quarter.h), which the lockstep step computes in lanes; libm's
   * sin and cos only beyond a quarter turn (never for a latitude). */
  if (fabs(hl) <= NAV_SINCOS_QUARTER_MAX) {
    nav_sincos_quarter(hl, sh, ch);
  } else {
    *sh = sin(hl);
    *ch = cos(hl);
  }
  *sl = 2.0 * *sh * *ch;
  *cl = (*ch - *sh) * (*ch + *sh);
}

/* Recompute the Earth terms and the output after the position was set from outside. */
static void ned_refresh(nav_ins *ins) {
  double sl, cl;
  ned_half_lat(ins->lat_rad, &ins->view_sh, &ins->view_ch, &sl, &cl);
  ned_terms_fill(ins->cfg.gravity_model == NAV_GRAVITY_J2, sl, cl, ins->h_m, NULL, &ins->et);
  ned_output(ins, ins->view_sh, ins->view_ch);
  ins->view_stale = false;
}

/* Set the NED state from geodetic position, v_n, q_b_n; refuses near the poles. */
static nav_status ned_set(nav_ins *ins, nav_geodetic p, nav_vec3 v_n, nav_quat q_b_n) {
  const double cl = cos(p.lat_rad);
  if (!(cl >= NAV_INS_NED_MIN_COS_LAT)) {
    snprintf(
        ins->msg, sizeof ins->msg,
        "NED mechanization: latitude %.9f deg has cos(lat) = %.3g < %.0e (the transport rate is singular at "
        "the pole); use the ECEF mechanization",
        p.lat_rad * NAV_RAD2DEG, cl, NAV_INS_NED_MIN_COS_LAT);
    return NAV_ERR_OUT_OF_RANGE;
  }
  ins->lat_rad = p.lat_rad;
  ins->lon_rad = nav_earth_wrap_lon(p.lon_rad);
  ins->h_m = p.h_m;
  ins->v_n_mps = v_n;
  ins->q_b_n = nav_quat_normalize(q_b_n);
  ned_refresh(ins);
  return NAV_OK;
}

/* Geodetic position, v_n and q_b_n of an ECEF state. */
static void ecef_to_ned(nav_vec3 r_e, nav_vec3 v_e, nav_quat q_b_e, nav_geodetic *p, nav_vec3 *v_n,
                        nav_quat *q_b_n) {
  *p = nav_earth_ecef_to_geodetic(r_e);
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(p->lat_rad, p->lon_rad);
  *v_n = nav_mat3_tmul_vec(C_n_e, v_e);
  *q_b_n = nav_quat_normalize(nav_quat_mul(nav_quat_conj(nav_quat_from_dcm(C_n_e)), q_b_e));
}

/* ------------------------------------------------------------------ create / destroy / access */

/* Validate and (re)initialise @p ins in place from @p cfg and @p initial; allocates nothing. */
static nav_status ins_init(nav_ins *ins, const nav_ins_config *cfg, const nav_ins_state *initial) {
  if (cfg->earth_model != NAV_EARTH_FLAT && cfg->earth_model != NAV_EARTH_WGS84) return NAV_ERR_INVALID_ARG;
  if (cfg->algorithm != NAV_MECH_FIRST_ORDER && cfg->algorithm != NAV_MECH_HIGH_ORDER)
    return NAV_ERR_INVALID_ARG;
  if (cfg->earth_model == NAV_EARTH_WGS84) {
    if (cfg->mech_frame != NAV_MECH_NED && cfg->mech_frame != NAV_MECH_ECEF) return NAV_ERR_INVALID_ARG;
    if (cfg->gravity_model != NAV_GRAVITY_NORMAL && cfg->gravity_model != NAV_GRAVITY_J2)
      return NAV_ERR_INVALID_ARG;
    if (cfg->gravity_step != NAV_INS_GRAVITY_PREDICTOR_CORRECTOR &&
        cfg->gravity_step != NAV_INS_GRAVITY_START_OF_INTERVAL)
      return NAV_ERR_INVALID_ARG;
    const nav_quat q = initial->q_b_f;
    if (!nav_vec3_isfinite(initial->r_fb_f_m) || !nav_vec3_isfinite(initial->v_fb_f_mps) ||
        !(isfinite(q.w) && isfinite(q.x) && isfinite(q.y) && isfinite(q.z)) || !(nav_quat_norm(q) > 0.0))
      return NAV_ERR_INVALID_ARG;
  }
  memset(ins, 0, sizeof *ins);
  ins->cfg = *cfg;
  ins->s = *initial;
  ins->s.q_b_f = nav_quat_normalize(initial->q_b_f);
  if (cfg->earth_model == NAV_EARTH_WGS84) {
    nav_geodetic p;
    nav_vec3 v_n;
    nav_quat q_b_n;
    ecef_to_ned(ins->s.r_fb_f_m, ins->s.v_fb_f_mps, ins->s.q_b_f, &p, &v_n, &q_b_n);
    ins->hold_h_m = p.h_m;
    ins->hold_vd_mps = v_n.z;
    if (cfg->mech_frame == NAV_MECH_NED) {
      const nav_status st = ned_set(ins, p, v_n, q_b_n);
      if (st != NAV_OK) return st;
      ins->s.t_s = initial->t_s;
    } else {
      ins->g_e_mps2 = nav_gravity_e_mps2(cfg->gravity_model, ins->s.r_fb_f_m);
    }
  }
  return NAV_OK;
}

nav_ins_config nav_ins_config_from_scene(const nav_scene *scene) {
  nav_ins_config c = nav_ins_config_default();
  c.earth_model = scene->earth.model;
  c.algorithm = scene->navigation.algorithm;
  c.mech_frame = scene->navigation.frame;
  c.gravity_model = scene->earth.gravity_model;
  c.g_l_mps2 = nav_vec3_make(0.0, 0.0, scene->earth.flat_gravity_mps2);
  return c;
}

nav_status nav_ins_create(const nav_ins_config *cfg, const nav_ins_state *initial, nav_ins **out) {
  if (!cfg || !initial || !out) return NAV_ERR_INVALID_ARG;
  nav_ins *ins = calloc(1, sizeof *ins);
  if (!ins) return NAV_ERR_NO_MEMORY;
  const nav_status st = ins_init(ins, cfg, initial);
  if (st != NAV_OK) {
    free(ins);
    return st;
  }
  *out = ins;
  return NAV_OK;
}

nav_status nav_ins_set_state(nav_ins *ins, const nav_ins_state *state) {
  if (!ins || !state) return NAV_ERR_INVALID_ARG;
  const nav_quat q = state->q_b_f;
  if (!nav_vec3_isfinite(state->r_fb_f_m) || !nav_vec3_isfinite(state->v_fb_f_mps) ||
      !(isfinite(q.w) && isfinite(q.x) && isfinite(q.y) && isfinite(q.z)) || !(nav_quat_norm(q) > 0.0))
    return NAV_ERR_NUMERIC;
  /* Re-initialise through the create path into a copy (the state stays as it was on failure),
   * keeping the previous increments: a correction changes the state, not the sensor history
   * that the coning and sculling terms use, nor the vertical hold. */
  nav_ins fresh;
  const nav_status st = ins_init(&fresh, &ins->cfg, state);
  if (st != NAV_OK) return st;
  fresh.have_prev = ins->have_prev;
  fresh.prev_dtheta_b_rad = ins->prev_dtheta_b_rad;
  fresh.prev_dv_b_mps = ins->prev_dv_b_mps;
  if (ins->cfg.clamp_vertical) {
    fresh.hold_h_m = ins->hold_h_m;
    fresh.hold_vd_mps = ins->hold_vd_mps;
  }
  *ins = fresh;
  return NAV_OK;
}

void nav_ins_destroy(nav_ins *ins) {
  free(ins);
}

const nav_ins_state *nav_ins_get_state(const nav_ins *ins) {
  if (!ins) return NULL;
  if (ins->view_stale) {
    /* Logically const: the e-frame view of the NED state is a cache filled on first use after a
     * step, so a caller that only steps (or reads the state at an output rate) does not pay for
     * the conversion every step. The object was allocated non-const by nav_ins_create, so
     * writing through it is defined; objects are used from one thread at a time (style.md 7). */
    nav_ins *m = (nav_ins *)ins;
    ned_output(m, m->view_sh, m->view_ch);
    m->view_stale = false;
  }
  return &ins->s;
}

bool nav_ins_get_ned(const nav_ins *ins, nav_ins_ned *out) {
  if (!ins || !out || ins->cfg.earth_model != NAV_EARTH_WGS84 || ins->cfg.mech_frame != NAV_MECH_NED)
    return false;
  out->t_s = ins->s.t_s;
  out->pos.lat_rad = ins->lat_rad;
  out->pos.lon_rad = ins->lon_rad;
  out->pos.h_m = ins->h_m;
  out->v_n_mps = ins->v_n_mps;
  out->q_b_n = ins->q_b_n;
  out->sin_lat = ins->et.sl;
  out->cos_lat = ins->et.cl;
  return true;
}

const char *nav_ins_last_error(const nav_ins *ins) {
  return ins ? ins->msg : "";
}

/* ECEF: replace height and down velocity, keep latitude, longitude, v_N, v_E. */
static void ecef_set_vertical(nav_ins *ins, double h_m, double v_d_mps) {
  nav_geodetic p = nav_earth_ecef_to_geodetic(ins->s.r_fb_f_m);
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(p.lat_rad, p.lon_rad);
  nav_vec3 v_n = nav_mat3_tmul_vec(C_n_e, ins->s.v_fb_f_mps);
  p.h_m = h_m;
  v_n.z = v_d_mps;
  ins->s.r_fb_f_m = nav_earth_geodetic_to_ecef(p);
  ins->s.v_fb_f_mps = nav_mat3_mul_vec(C_n_e, v_n);
  ins->g_e_mps2 = nav_gravity_e_mps2(ins->cfg.gravity_model, ins->s.r_fb_f_m);
}

nav_status nav_ins_aid_vertical(nav_ins *ins, double h_m, double v_d_mps) {
  if (!ins || !isfinite(h_m) || !isfinite(v_d_mps)) return NAV_ERR_INVALID_ARG;
  if (ins->cfg.earth_model == NAV_EARTH_FLAT) {
    /* Flat Earth: D is -height relative to the origin plane; the scene origin height is 0 in l. */
    ins->s.r_fb_f_m.z = -h_m;
    ins->s.v_fb_f_mps.z = v_d_mps;
    return NAV_OK;
  }
  ins->hold_h_m = h_m;
  ins->hold_vd_mps = v_d_mps;
  if (ins->cfg.mech_frame == NAV_MECH_NED) {
    ins->h_m = h_m;
    ins->v_n_mps.z = v_d_mps;
    ned_refresh(ins);
  } else {
    ecef_set_vertical(ins, h_m, v_d_mps);
  }
  return NAV_OK;
}

/* ------------------------------------------------------------------ flat step */

HOT_INLINE nav_status step_flat(nav_ins *ins, const nav_imu_increment *imu) {
  const double dt = imu->dt_s;
  const nav_vec3 dth = imu->dtheta_b_rad, dv = imu->dv_b_mps;
  const nav_mat3 C_b_l = nav_quat_to_dcm_inline(ins->s.q_b_f);
  nav_vec3 phi, dv_body;

  if (ins->cfg.algorithm == NAV_MECH_FIRST_ORDER) {
    /* (a) E4.1 and the classic rotation compensation dv + 1/2 dtheta x dv. */
    phi = dth;
    dv_body = nav_vec3_add(dv, nav_vec3_scale(nav_vec3_cross(dth, dv), 0.5));
  } else {
    /* (b) E4.2 two-sample coning, E4.4 exact rotation compensation, E4.5 two-sample sculling.
     * At the first step there is no previous increment: the terms are dropped (a one-off
     * O(dt^3) error, numerics.md T5.1 note). */
    const nav_vec3 pdth = ins->have_prev ? ins->prev_dtheta_b_rad : nav_vec3_zero();
    const nav_vec3 pdv = ins->have_prev ? ins->prev_dv_b_mps : nav_vec3_zero();
    phi = nav_vec3_add(dth, nav_vec3_scale(nav_vec3_cross(pdth, dth), 1.0 / 12.0));
    const nav_vec3 dv_rot = nav_mat3_mul_vec(nav_rot_comp_matrix(phi), dv);
    const nav_vec3 dv_scul =
        nav_vec3_scale(nav_vec3_add(nav_vec3_cross(pdth, dv), nav_vec3_cross(pdv, dth)), 1.0 / 12.0);
    dv_body = nav_vec3_add(dv_rot, dv_scul);
  }

  nav_ins_state n = ins->s;
  n.t_s = imu->t_s;
  n.v_fb_f_mps = nav_vec3_add(nav_vec3_add(ins->s.v_fb_f_mps, nav_mat3_mul_vec(C_b_l, dv_body)),
                              nav_vec3_scale(ins->cfg.g_l_mps2, dt));
  n.r_fb_f_m =
      nav_vec3_add(ins->s.r_fb_f_m, nav_vec3_scale(nav_vec3_add(ins->s.v_fb_f_mps, n.v_fb_f_mps), 0.5 * dt));
  /* Renormalise every step (numerics.md 4.4 rule 1). */
  n.q_b_f = nav_quat_normalize(nav_quat_mul(ins->s.q_b_f, nav_quat_from_rotvec(phi)));
  if (!nav_vec3_isfinite(n.v_fb_f_mps) || !nav_vec3_isfinite(n.r_fb_f_m) || !isfinite(n.q_b_f.w)) {
    snprintf(ins->msg, sizeof ins->msg, "flat mechanization: non-finite state at t = %.6f s", imu->t_s);
    return NAV_ERR_NUMERIC;
  }
  ins->s = n;
  return NAV_OK;
}

/* ------------------------------------------------------------------ NED step */

static nav_status refuse_pole(nav_ins *ins, const char *where, double lat_rad, double cl, double t_s) {
  snprintf(ins->msg, sizeof ins->msg,
           "NED mechanization: the %s latitude %.9f deg at t = %.6f s has cos(lat) = %.3g < %.0e (the "
           "transport rate "
           "is singular at the pole); use the ECEF mechanization",
           where, lat_rad * NAV_RAD2DEG, t_s, cl, NAV_INS_NED_MIN_COS_LAT);
  return NAV_ERR_OUT_OF_RANGE;
}

HOT_INLINE nav_status step_ned_impl(nav_ins *ins, const nav_imu_increment *imu, bool high, bool pc) {
  const bool j2 = ins->cfg.gravity_model == NAV_GRAVITY_J2;
  const double dt = imu->dt_s, hdt = 0.5 * dt;
  const ned_terms *t0 = &ins->et;
  const double lat0 = ins->lat_rad, h0 = ins->h_m;
  const nav_vec3 v0 = ins->v_n_mps;
  nav_quat q_phi;
  nav_vec3 phi, dv_body;
  body_terms(high, ins, imu->dtheta_b_rad, imu->dv_b_mps, &phi, &q_phi, &dv_body);

  /* Specific-force part: C_b_n(k-1) dv_body, and C_b_n(k-1) dv, C_b_n(k-1) phi for the term of
   * the rotation of n during the interval (frame_rotation_term). */
  const nav_mat3 C_b_n = nav_quat_to_dcm_inline(ins->q_b_n);
  const nav_vec3 dv_f = nav_mat3_mul_vec(C_b_n, dv_body);
  const nav_vec3 cdv = nav_mat3_mul_vec(C_b_n, imu->dv_b_mps);
  const nav_vec3 cphi = nav_mat3_mul_vec(C_b_n, phi);
  const nav_vec3 base = nav_vec3_add(v0, dv_f);

  /* Terms at k-1. */
  nav_vec3 w_in0, w_cor0;
  ned_rates(t0, v0, &w_in0, &w_cor0);
  const nav_vec3 F0 = ned_force(t0, w_cor0, v0);
  const double lat_rate0 = v0.x * t0->iRMh;
  const double lon_rate0 = v0.y * t0->iRNh * t0->icl;

  /* Predictor with the k-1 values (numerics.md 4.2-4.3). */
  nav_vec3 zeta = nav_vec3_scale(w_in0, dt);
  /* (The predicted v_k feeds only the Coriolis and transport terms, so the first-order frame term
   * is enough for it; the start-of-interval variant has no corrector and takes the full term.) */
  nav_vec3 v1 = nav_vec3_add(nav_vec3_add(base, pc ? nav_vec3_scale(nav_vec3_cross(zeta, cdv), -0.5)
                                                   : frame_rotation_term(high, zeta, cdv, cphi)),
                             nav_vec3_scale(F0, dt));
  ned_terms tp;
  const ned_terms *pk = NULL; /* the predicted point, when there is one */
  if (pc) {
    /* The position-dependent terms at k (gravity, radii, Earth rate, 1/cos lat) are needed to
     * O(dt^2) only, so the predicted point is the Euler step of the position with v_(k-1): its
     * O(dt^2) position error changes them by O(dt^2) relative. It does not depend on this
     * interval's increments, so it is computed off the critical path of the step. */
    const double lat_p = lat0 + dt * lat_rate0, h_p = h0 - dt * v0.z;
    double sp, cp;
    sincos_shift(t0->sl, t0->cl, lat_p, lat_p - lat0, &sp, &cp);
    if (!(cp >= NAV_INS_NED_MIN_COS_LAT)) return refuse_pole(ins, "predicted", lat_p, cp, imu->t_s);
    ned_terms_fill(j2, sp, cp, h_p, t0, &tp);
    pk = &tp;
    /* The velocity-dependent terms (Coriolis, transport rate) use the predicted v_k. */
    nav_vec3 w_inp, w_corp;
    ned_rates(&tp, v1, &w_inp, &w_corp);
    const nav_vec3 Fp = ned_force(&tp, w_corp, v1);
    /* Corrector: trapezoidal means of the k-1 and predicted-k terms. */
    zeta = nav_vec3_scale(nav_vec3_add(w_in0, w_inp), hdt);
    v1 = nav_vec3_add(nav_vec3_add(base, frame_rotation_term(high, zeta, cdv, cphi)),
                      nav_vec3_scale(nav_vec3_add(F0, Fp), hdt));
  }
  const double h1 = h0 - hdt * (v0.z + v1.z);
  /* Curvilinear trapezoidal position (numerics.md 4.3; Groves eq. 5.56). With the predictor, the
   * k terms use R_M, R_N and cos lat of the predicted point (O(dt^2) relative): one order better
   * than R_M(lat_(k-1)) of 4.3, and the longitude need not wait for the trig of the new
   * latitude. Without it, R_M(lat_(k-1)) as in 4.3 and R_N, cos lat at the new latitude. */
  const double lat1 = lat0 + hdt * (lat_rate0 + v1.x * (pk ? pk->iRMh : t0->iRMh));
  double sh1, ch1, sl1, cl1;
  ned_half_lat(lat1, &sh1, &ch1, &sl1, &cl1);
  if (!(cl1 >= NAV_INS_NED_MIN_COS_LAT)) return refuse_pole(ins, "new", lat1, cl1, imu->t_s);
  /* The Earth terms of the new point, seeded by the nearest point (the Newton steps): with the
   * predictor they are not needed before the commit and are filled in place (ins->et) then. */
  ned_terms t1;
  if (!pk) ned_terms_fill(j2, sl1, cl1, h1, t0, &t1);
  const double lon_fac1 = pk ? pk->iRNh * pk->icl : t1.iRNh * t1.icl;
  double lon1 = ins->lon_rad + hdt * (lon_rate0 + v1.y * lon_fac1);
  /* Wrap to (-pi, pi]; values already inside are returned unchanged by nav_earth_wrap_lon. */
  if (lon1 > NAV_PI || lon1 <= -NAV_PI) lon1 = nav_earth_wrap_lon(lon1);

  /* Attitude: q_k = q(-zeta) (x) q_(k-1) (x) q(phi), renormalised (numerics.md 4.1, 4.4 rule 1). */
  const nav_quat q1 =
      renormalize(nav_quat_mul(quat_of_rotvec(nav_vec3_scale(zeta, -1.0)), nav_quat_mul(ins->q_b_n, q_phi)));

  /* One test for all: a sum of finite state values (each far below DBL_MAX) is finite, and any
   * NaN or infinity propagates into it. */
  if (!isfinite(v1.x + v1.y + v1.z + h1 + lat1 + lon1 + q1.w + q1.x + q1.y + q1.z)) {
    snprintf(ins->msg, sizeof ins->msg, "NED mechanization: non-finite state at t = %.6f s", imu->t_s);
    return NAV_ERR_NUMERIC;
  }
  ins->lat_rad = lat1;
  ins->lon_rad = lon1;
  ins->h_m = h1;
  ins->v_n_mps = v1;
  ins->q_b_n = q1;
  if (pk)
    ned_terms_fill(j2, sl1, cl1, h1, pk, &ins->et);
  else
    ins->et = t1;
  if (ins->cfg.clamp_vertical) {
    ins->h_m = ins->hold_h_m;
    ins->v_n_mps.z = ins->hold_vd_mps;
    const ned_terms seed = ins->et;
    ned_terms_fill(j2, sl1, cl1, ins->h_m, &seed, &ins->et);
  }
  ins->view_sh = sh1;
  ins->view_ch = ch1;
  ins->view_stale = true;
  ins->s.t_s = imu->t_s;
  return NAV_OK;
}

/* The NED step specialised for the algorithm and the gravity step (the hot path of WGS-84 runs). */
HOT_INLINE nav_status step_ned(nav_ins *ins, const nav_imu_increment *imu) {
  const bool high = ins->cfg.algorithm == NAV_MECH_HIGH_ORDER;
  if (ins->cfg.gravity_step == NAV_INS_GRAVITY_PREDICTOR_CORRECTOR)
    return high ? step_ned_impl(ins, imu, true, true) : step_ned_impl(ins, imu, false, true);
  return high ? step_ned_impl(ins, imu, true, false) : step_ned_impl(ins, imu, false, false);
}

/* ------------------------------------------------------------------ ECEF step */

HOT_INLINE nav_status step_ecef(nav_ins *ins, const nav_imu_increment *imu) {
  const bool high = ins->cfg.algorithm == NAV_MECH_HIGH_ORDER;
  const double dt = imu->dt_s, hdt = 0.5 * dt;
  const nav_vec3 w_ie_e = nav_earth_rate_e_rps();
  const nav_vec3 r0 = ins->s.r_fb_f_m, v0 = ins->s.v_fb_f_mps;
  nav_quat q_phi;
  nav_vec3 phi, dv_body;
  body_terms(high, ins, imu->dtheta_b_rad, imu->dv_b_mps, &phi, &q_phi, &dv_body);

  /* Exact Earth-rotation step R_z(-omega_ie dt) (numerics.md 4.1 ECEF row); cached per dt. */
  int ir = 0;
  while (ir < ROT_CACHE && ins->rot_dt_s[ir] != dt)
    ++ir;
  if (ir == ROT_CACHE) {
    ir = ins->rot_next;
    ins->rot_next = (ir + 1) % ROT_CACHE;
    const double half = 0.5 * NAV_WGS84_OMEGA_IE_RPS * dt;
    ins->rot_c[ir] = cos(half);
    ins->rot_s[ir] = sin(half);
    ins->rot_dt_s[ir] = dt;
  }
  const nav_quat q_rot = {ins->rot_c[ir], 0.0, 0.0, -ins->rot_s[ir]};

  const nav_mat3 C_b_e = nav_quat_to_dcm_inline(ins->s.q_b_f);
  const nav_vec3 dv_f = nav_mat3_mul_vec(C_b_e, dv_body);
  /* The e frame turns by omega_ie dt while the increment accrues (-1/2 [omega_ie_e x] C_b_e dv dt
   * and, for (b), the second-order terms; frame_rotation_term). */
  const nav_vec3 rot = frame_rotation_term(
      high, nav_vec3_scale(w_ie_e, dt), nav_mat3_mul_vec(C_b_e, imu->dv_b_mps), nav_mat3_mul_vec(C_b_e, phi));
  const nav_vec3 base = nav_vec3_add(nav_vec3_add(v0, dv_f), rot);

  /* Gravity (with centrifugal) minus Coriolis, at k-1 (cached gravity at r0). */
  const nav_vec3 F0 = nav_vec3_sub(ins->g_e_mps2, nav_vec3_scale(nav_vec3_cross(w_ie_e, v0), 2.0));
  nav_vec3 v1 = nav_vec3_axpy(base, dt, F0);
  nav_vec3 r1 = nav_vec3_axpy(r0, hdt, nav_vec3_add(v0, v1));
  nav_vec3 g1;
  if (ins->cfg.gravity_step == NAV_INS_GRAVITY_PREDICTOR_CORRECTOR) {
    /* Predicted point, then the trapezoidal mean. The gravity at the predicted position is kept
     * as the gravity at r_k: the two points differ by dt/2 |v_k - v_pred| ~ 1e-8 m at dt = 0.04 s,
     * i.e. ~3e-14 m/s^2 of gravity gradient, and the cache halves the gravity evaluations (a
     * foot-point solution each for the normal model, nav/ecef_gravity.h). */
    g1 = nav_ecef_gravity_fast(ins->cfg.gravity_model, r1);
    const nav_vec3 Fp = nav_vec3_sub(g1, nav_vec3_scale(nav_vec3_cross(w_ie_e, v1), 2.0));
    v1 = nav_vec3_axpy(base, hdt, nav_vec3_add(F0, Fp));
    r1 = nav_vec3_axpy(r0, hdt, nav_vec3_add(v0, v1));
  } else {
    g1 = nav_ecef_gravity_fast(ins->cfg.gravity_model, r1);
  }

  /* Attitude: q_k = q_z(-omega_ie dt) (x) q_(k-1) (x) q(phi), renormalised. */
  const nav_quat q1 = renormalize(nav_quat_mul(q_rot, nav_quat_mul(ins->s.q_b_f, q_phi)));

  if (!nav_vec3_isfinite(v1) || !nav_vec3_isfinite(r1) || !nav_vec3_isfinite(g1) || !isfinite(q1.w) ||
      !isfinite(q1.x) || !isfinite(q1.y) || !isfinite(q1.z)) {
    snprintf(ins->msg, sizeof ins->msg, "ECEF mechanization: non-finite state at t = %.6f s", imu->t_s);
    return NAV_ERR_NUMERIC;
  }
  ins->s.t_s = imu->t_s;
  ins->s.r_fb_f_m = r1;
  ins->s.v_fb_f_mps = v1;
  ins->s.q_b_f = q1;
  ins->g_e_mps2 = g1;
  if (ins->cfg.clamp_vertical) ecef_set_vertical(ins, ins->hold_h_m, ins->hold_vd_mps);
  return NAV_OK;
}

/* ------------------------------------------------------------------ step */

/* The whole step, with the frame steps inlined, is compiled for the baseline and for AVX2
 * (nav_clones.h; bit-identical results). */
NAV_HOT_CLONES nav_status nav_ins_step(nav_ins *ins, const nav_imu_increment *imu) {
  if (!ins || !imu || !(imu->dt_s > 0.0)) return NAV_ERR_INVALID_ARG;
  if (!nav_vec3_isfinite(imu->dtheta_b_rad) || !nav_vec3_isfinite(imu->dv_b_mps) || !isfinite(imu->dt_s)) {
    snprintf(ins->msg, sizeof ins->msg, "non-finite IMU increment at t = %.6f s", imu->t_s);
    return NAV_ERR_NUMERIC;
  }
  nav_status st;
  if (ins->cfg.earth_model == NAV_EARTH_FLAT)
    st = step_flat(ins, imu);
  else if (ins->cfg.mech_frame == NAV_MECH_NED)
    st = step_ned(ins, imu);
  else
    st = step_ecef(ins, imu);
  if (st != NAV_OK) return st;
  ins->prev_dtheta_b_rad = imu->dtheta_b_rad;
  ins->prev_dv_b_mps = imu->dv_b_mps;
  ins->have_prev = true;
  return NAV_OK;
}

/* ------------------------------------------------------------------ four INS in lockstep */

/* The Earth terms of ned_terms_fill() (normal gravity) in four lanes, from a nearby point's terms.
 * The two Newton steps are taken lane by lane where the scalar code takes them, the exact 1/sqrt
 * and division elsewhere: both are computed and the lane's own choice kept. */
typedef struct ned_terms4 {
  nav_l4 sl, cl, icl, RM, RN, iRMh, iRNh, isq, inv, gz;
} ned_terms4;

NAV_CLONE_INLINE void ned_terms_fill4(nav_l4 sl, nav_l4 cl, nav_l4 h, const ned_terms4 *near, ned_terms4 *t) {
  const nav_l4 one = l4_splat(1.0);
  const nav_l4 s2 = sl * sl;
  const nav_l4 den2 = one - l4_splat(NAV_WGS84_E2) * s2;
  const nav_l4 e_sq = one - den2 * near->isq * near->isq;
  const nav_m4 newton_sq = l4_abs(e_sq) < l4_splat(NEWTON_REL);
  nav_l4 isq = near->isq * (one + l4_splat(0.5) * e_sq);
  if (!l4_all(newton_sq))
    for (int l = 0; l < NAV_LANES; ++l)
      if (!newton_sq[l]) isq[l] = 1.0 / sqrt(den2[l]);
  t->sl = sl;
  t->cl = cl;
  t->isq = isq;
  t->RN = l4_splat(NAV_WGS84_A_M) * isq;
  t->RM = l4_splat(NAV_WGS84_A_M * E2M) * isq * isq * isq;
  const nav_l4 A = t->RM + h, B = t->RN + h, P = A * B, x = P * cl;
  const nav_l4 e_inv = one - x * near->inv;
  /* The division only when a lane needs it (a point that moved far), as the 1/sqrt above. */
  const nav_m4 newton_inv = l4_abs(e_inv) < l4_splat(NEWTON_REL);
  t->inv = near->inv * (one + e_inv);
  if (!l4_all(newton_inv)) t->inv = l4_sel(newton_inv, t->inv, one / x);
  t->iRMh = t->inv * B * cl;
  t->iRNh = t->inv * A * cl;
  t->icl = t->inv * P;
  const double a = NAV_WGS84_A_M;
  const nav_l4 gamma0 =
      l4_splat(NAV_WGS84_GAMMA_E_MPS2) * (one + l4_splat(NAV_WGS84_SOMIGLIANA_K) * s2) * isq;
  const nav_l4 lin = l4_splat(2.0 / a) * (l4_splat(1.0 + NAV_WGS84_F + NAV_WGS84_M) - l4_splat(2.0 * NAV_WGS84_F) * s2);
  const nav_l4 quad = l4_splat(3.0 / (a * a));
  t->gz = gamma0 * (one - lin * h + quad * h * h);
}

/* ned_rates() and ned_force() in lanes (g_n = (0, 0, gz) with normal gravity). */
NAV_CLONE_INLINE void ned_rates4(const ned_terms4 *t, nav_l4v3 v, nav_l4v3 *w_in, nav_l4v3 *w_cor) {
  const nav_l4 w = l4_splat(NAV_WGS84_OMEGA_IE_RPS);
  const nav_l4 east = v.y * t->iRNh;
  const nav_l4v3 w_ie = l4v3(w * t->cl, l4_splat(0.0), -w * t->sl);
  const nav_l4v3 w_en = l4v3(east, -v.x * t->iRMh, -east * t->sl * t->icl);
  *w_in = l4v3_add(w_ie, w_en);
  *w_cor = l4v3_add(*w_in, w_ie);
}
NAV_CLONE_INLINE nav_l4v3 ned_force4(const ned_terms4 *t, nav_l4v3 w_cor, nav_l4v3 v) {
  return l4v3_sub(l4v3(l4_splat(0.0), l4_splat(0.0), t->gz), l4v3_cross(w_cor, v));
}

/* The series of quat_of_rotvec() / body_terms() below ROT_SERIES_RAD (the caller checks a2). */
NAV_CLONE_INLINE nav_l4q quat_series4(nav_l4v3 v, nav_l4 a2) {
  const nav_l4 w = l4_splat(1.0) - a2 * (l4_splat(1.0 / 8.0) - a2 * (l4_splat(1.0 / 384.0) - a2 * l4_splat(1.0 / 46080.0)));
  const nav_l4 s = l4_splat(0.5) - a2 * (l4_splat(1.0 / 48.0) - a2 * (l4_splat(1.0 / 3840.0) - a2 * l4_splat(1.0 / 645120.0)));
  nav_l4q q = {w, s * v.x, s * v.y, s * v.z};
  return q;
}

/* Does this INS step on the lockstep path: WGS-84 in NED, the high-order algorithm with the
 * predictor-corrector gravity step and normal gravity, no vertical hold. */
static bool lanes_config(const nav_ins *ins) {
  const nav_ins_config *c = &ins->cfg;
  return c->earth_model == NAV_EARTH_WGS84 && c->mech_frame == NAV_MECH_NED && c->algorithm == NAV_MECH_HIGH_ORDER &&
         c->gravity_step == NAV_INS_GRAVITY_PREDICTOR_CORRECTOR && c->gravity_model == NAV_GRAVITY_NORMAL &&
         !c->clamp_vertical;
}

/*
 * step_ned_impl(high, predictor-corrector) of four INS at once, lane l being ins[l] with imu[l]:
 * the same operations in the same order in every lane. Where the scalar step branches on the
 * data, the lanes go on only when every lane takes the branch taken here (the rotation series,
 * the series of the latitude step, no pole, no longitude wrap, renormalisation by the Newton
 * step, a finite state); otherwise nothing is written and false is returned, and the caller
 * steps each INS with nav_ins_step(), which also words any error.
 */
NAV_HOT_CLONES bool nav_ins_step_lanes(nav_ins *const ins[NAV_LANES],
                                       const nav_imu_increment *const imu[NAV_LANES],
                                       nav_ins_lanes_nav *out) {
  nav_l4 dt, lat0, lon0, h0;
  nav_l4v3 dth, dv, pdth, pdv, v0;
  nav_l4q q0;
  ned_terms4 t0;
  for (int l = 0; l < NAV_LANES; ++l) {
    const nav_ins *s = ins[l];
    const nav_imu_increment *u = imu[l];
    if (!lanes_config(s) || !(u->dt_s > 0.0) || !nav_vec3_isfinite(u->dtheta_b_rad) ||
        !nav_vec3_isfinite(u->dv_b_mps) || !isfinite(u->dt_s))
      return false;
    dt[l] = u->dt_s;
    l4v3_set_lane(&dth, l, u->dtheta_b_rad);
    l4v3_set_lane(&dv, l, u->dv_b_mps);
    l4v3_set_lane(&pdth, l, s->have_prev ? s->prev_dtheta_b_rad : nav_vec3_zero());
    l4v3_set_lane(&pdv, l, s->have_prev ? s->prev_dv_b_mps : nav_vec3_zero());
    lat0[l] = s->lat_rad;
    lon0[l] = s->lon_rad;
    h0[l] = s->h_m;
    l4v3_set_lane(&v0, l, s->v_n_mps);
    l4q_set_lane(&q0, l, s->q_b_n);
    const ned_terms *e = &s->et;
    t0.sl[l] = e->sl;
    t0.cl[l] = e->cl;
    t0.icl[l] = e->icl;
    t0.RM[l] = e->RM;
    t0.RN[l] = e->RN;
    t0.iRMh[l] = e->iRMh;
    t0.iRNh[l] = e->iRNh;
    t0.isq[l] = e->isq;
    t0.inv[l] = e->inv;
    t0.gz[l] = e->g_n.z;
  }
  const nav_l4 hdt = l4_splat(0.5) * dt;
  const nav_l4 one = l4_splat(1.0);

  /* body_terms(high) */
  const nav_l4v3 phi = l4v3_add(dth, l4v3_scale(l4v3_cross(pdth, dth), l4_splat(1.0 / 12.0)));
  const nav_l4 a2 = l4v3_dot(phi, phi);
  if (!l4_all(a2 < l4_splat(ROT_SERIES_RAD * ROT_SERIES_RAD))) return false;
  const nav_l4q q_phi = quat_series4(phi, a2);
  const nav_l4 b1 =
      l4_splat(0.5) - a2 * (l4_splat(1.0 / 24.0) - a2 * (l4_splat(1.0 / 720.0) - a2 * l4_splat(1.0 / 40320.0)));
  const nav_l4 b2 = l4_splat(1.0 / 6.0) -
                    a2 * (l4_splat(1.0 / 120.0) - a2 * (l4_splat(1.0 / 5040.0) - a2 * l4_splat(1.0 / 362880.0)));
  const nav_l4v3 pxdv = l4v3_cross(phi, dv);
  const nav_l4v3 dv_rot = l4v3_add(l4v3_axpy(dv, b1, pxdv), l4v3_scale(l4v3_cross(phi, pxdv), b2));
  const nav_l4v3 dv_scul =
      l4v3_scale(l4v3_add(l4v3_cross(pdth, dv), l4v3_cross(pdv, dth)), l4_splat(1.0 / 12.0));
  const nav_l4v3 dv_body = l4v3_add(dv_rot, dv_scul);

  const nav_l4m3 C_b_n = l4q_to_dcm(q0);
  const nav_l4v3 dv_f = l4m3_mul_vec(&C_b_n, dv_body);
  const nav_l4v3 cdv = l4m3_mul_vec(&C_b_n, dv);
  const nav_l4v3 cphi = l4m3_mul_vec(&C_b_n, phi);
  const nav_l4v3 base = l4v3_add(v0, dv_f);

  nav_l4v3 w_in0, w_cor0;
  ned_rates4(&t0, v0, &w_in0, &w_cor0);
  const nav_l4v3 F0 = ned_force4(&t0, w_cor0, v0);
  const nav_l4 lat_rate0 = v0.x * t0.iRMh;
  const nav_l4 lon_rate0 = v0.y * t0.iRNh * t0.icl;

  /* Predictor */
  nav_l4v3 zeta = l4v3_scale(w_in0, dt);
  nav_l4v3 v1 =
      l4v3_add(l4v3_add(base, l4v3_scale(l4v3_cross(zeta, cdv), l4_splat(-0.5))), l4v3_scale(F0, dt));
  const nav_l4 lat_p = lat0 + dt * lat_rate0, h_p = h0 - dt * v0.z;
  /* sincos_shift(), series branch */
  const nav_l4 d = lat_p - lat0;
  if (!l4_all(l4_abs(d) < l4_splat(LAT_STEP_SERIES_RAD))) return false;
  const nav_l4 d2 = d * d;
  const nav_l4 cd = one - d2 * (l4_splat(0.5) - d2 / l4_splat(24.0));
  const nav_l4 sd = d * (one - d2 * (l4_splat(1.0 / 6.0) - d2 / l4_splat(120.0)));
  const nav_l4 sp = t0.sl * cd + t0.cl * sd, cp = t0.cl * cd - t0.sl * sd;
  if (!l4_all(cp >= l4_splat(NAV_INS_NED_MIN_COS_LAT))) return false;
  ned_terms4 tp;
  ned_terms_fill4(sp, cp, h_p, &t0, &tp);
  nav_l4v3 w_inp, w_corp;
  ned_rates4(&tp, v1, &w_inp, &w_corp);
  const nav_l4v3 Fp = ned_force4(&tp, w_corp, v1);
  /* Corrector, with frame_rotation_term(high) */
  zeta = l4v3_scale(l4v3_add(w_in0, w_inp), hdt);
  const nav_l4v3 k = l4v3_sub(l4v3_scale(zeta, l4_splat(1.0 / 6.0)), l4v3_scale(cphi, l4_splat(1.0 / 3.0)));
  const nav_l4v3 rot = l4v3_cross(zeta, l4v3_add(l4v3_scale(cdv, l4_splat(-0.5)), l4v3_cross(k, cdv)));
  v1 = l4v3_add(l4v3_add(base, rot), l4v3_scale(l4v3_add(F0, Fp), hdt));
  const nav_l4 h1 = h0 - hdt * (v0.z + v1.z);
  const nav_l4 lat1 = lat0 + hdt * (lat_rate0 + v1.x * tp.iRMh);
  /* ned_half_lat(): navcore's sin and cos kernel in lanes */
  const nav_l4 hl = l4_splat(0.5) * lat1;
  if (!l4_all(l4_abs(hl) <= l4_splat(NAV_SINCOS_QUARTER_MAX))) return false;
  nav_l4 sh1, ch1;
  nav_sincos_quarter4(hl, &sh1, &ch1);
  const nav_l4 sl1 = l4_splat(2.0) * sh1 * ch1, cl1 = (ch1 - sh1) * (ch1 + sh1);
  if (!l4_all(cl1 >= l4_splat(NAV_INS_NED_MIN_COS_LAT))) return false;
  const nav_l4 lon_fac1 = tp.iRNh * tp.icl;
  const nav_l4 lon1 = lon0 + hdt * (lon_rate0 + v1.y * lon_fac1);
  if (!l4_all((lon1 <= l4_splat(NAV_PI)) & (lon1 > l4_splat(-NAV_PI)))) return false;
  /* Attitude: q(-zeta) (x) q (x) q(phi), renormalised by the Newton step */
  const nav_l4v3 mz = l4v3_scale(zeta, l4_splat(-1.0));
  const nav_l4 z2 = l4v3_dot(mz, mz);
  if (!l4_all(z2 < l4_splat(ROT_SERIES_RAD * ROT_SERIES_RAD))) return false;
  const nav_l4q qq = l4q_mul(quat_series4(mz, z2), l4q_mul(q0, q_phi));
  const nav_l4 n2 = qq.w * qq.w + qq.x * qq.x + qq.y * qq.y + qq.z * qq.z;
  if (!l4_all(l4_abs(n2 - one) < l4_splat(1e-8))) return false;
  const nav_l4 sc = l4_splat(0.5) * (l4_splat(3.0) - n2);
  const nav_l4q q1 = {qq.w * sc, qq.x * sc, qq.y * sc, qq.z * sc};
  /* The finiteness test of step_ned_impl, lane by lane. */
  const nav_l4 sum = v1.x + v1.y + v1.z + h1 + lat1 + lon1 + q1.w + q1.x + q1.y + q1.z;
  if (!l4_all(l4_abs(sum) <= l4_splat(DBL_MAX))) return false;
  ned_terms4 t1;
  ned_terms_fill4(sl1, cl1, h1, &tp, &t1);
  for (int l = 0; l < NAV_LANES; ++l) {
    nav_ins *s = ins[l];
    s->lat_rad = lat1[l];
    s->lon_rad = lon1[l];
    s->h_m = h1[l];
    s->v_n_mps = l4v3_lane(v1, l);
    s->q_b_n = l4q_lane(q1, l);
    ned_terms *e = &s->et;
    e->sl = t1.sl[l];
    e->cl = t1.cl[l];
    e->icl = t1.icl[l];
    e->RM = t1.RM[l];
    e->RN = t1.RN[l];
    e->iRMh = t1.iRMh[l];
    e->iRNh = t1.iRNh[l];
    e->isq = t1.isq[l];
    e->inv = t1.inv[l];
    e->g_n = nav_vec3_make(0.0, 0.0, t1.gz[l]);
    s->view_sh = sh1[l];
    s->view_ch = ch1[l];
    s->view_stale = true;
    s->s.t_s = imu[l]->t_s;
    s->prev_dtheta_b_rad = imu[l]->dtheta_b_rad;
    s->prev_dv_b_mps = imu[l]->dv_b_mps;
    s->have_prev = true;
  }
  if (out) {
    out->lat = lat1;
    out->h = h1;
    out->v = v1;
    out->C_b_n = l4q_to_dcm(q1);
  }
  return true;
}
