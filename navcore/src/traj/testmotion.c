/*
 * Test motions with known answers (numerics.md section 5): stationary, coning (5.1), sculling
 * (5.2), constant-axis spin (5.3), great-circle flight over the pole (5.5, defined in ECEF) and a
 * vertical loop (pitch through +/-90 deg). Everything is in closed form, with analytic first and
 * second derivatives of position and the analytic angular acceleration; the gyro increments have
 * closed forms too (rate_integral), used by nav_truth on the flat Earth.
 *
 * Local motions give q_b_n(t) = R (x) q_m(t) with a constant R = q_ref (x) conj(q_m(0)), so
 * q_b_n(0) = q_ref = trajectory.initial_attitude and the body rate is that of q_m alone:
 * omega = 2 conj(q) (x) q_dot = 2 conj(q_m) conj(R) R q_m_dot = 2 conj(q_m) (x) q_m_dot.
 * Positions are given in the motion frame m (the frame of R) and mapped by C(R): r_n = C_R r_m.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "traj/traj_internal.h"

/* Harmonics kept in the Fourier-Bessel series of the sculling motion. |J_m(theta0)| <=
 * (|theta0|/2)^m / m! (A&S 9.1.62), which for |theta0| <= pi/2 is < 3e-21 at m = 20, so 24
 * harmonics reach rounding; the series is cut earlier once the bound is below 1e-22. */
#define SCULL_MAX_HARMONICS 24
#define SCULL_CUT 1e-22

typedef struct tm_model {
  nav_test_motion_kind kind;
  nav_traj_test_motion p;
  nav_quat R;   /* constant left factor of q_b_n (local motions) or right factor (great circle) */
  nav_mat3 C_R; /* its DCM */
  /* coning */
  double cb2, sb2; /* cos, sin of beta/2 */
  /* sculling: a_m = (0, A sum_{m odd} c_m sin(m x), A J1 + A sum_{m even} d_m cos(m x)) + gravity */
  int n_harm;
  double J1;
  double coef[SCULL_MAX_HARMONICS + 1]; /* c_m (m odd) or d_m (m even), index m */
  nav_vec3 g_add_n;                     /* flat Earth: the uniform gravity added to the acceleration */
  /* spin */
  nav_vec3 axis; /* unit axis */
  /* great circle */
  double gc_R, gc_w; /* radius [m], angular rate V/R [rad/s] */
  double gc_slon, gc_clon;
} tm_model;

const char *nav_test_motion_kind_name(nav_test_motion_kind k) {
  switch (k) {
  case NAV_TEST_MOTION_STATIONARY: return "stationary";
  case NAV_TEST_MOTION_CONING: return "coning";
  case NAV_TEST_MOTION_SCULLING: return "sculling";
  case NAV_TEST_MOTION_SPIN: return "spin";
  case NAV_TEST_MOTION_POLAR_GREAT_CIRCLE: return "polar_great_circle";
  case NAV_TEST_MOTION_VERTICAL_LOOP: return "vertical_loop";
  }
  return "unknown";
}

/*
 * Bessel function of the first kind J_n(x) by its power series (Abramowitz & Stegun 9.1.10):
 * J_n(x) = sum_k (-1)^k (x/2)^(2k+n) / (k! (k+n)!). For |x| <= pi/2 the terms decrease from the
 * first and alternate, so the sum is accurate to a few ulp; at most ~15 terms are needed.
 */
static double bessel_j(int n, double x) {
  const double hx = 0.5 * x;
  double term = 1.0;
  for (int k = 1; k <= n; ++k)
    term *= hx / (double)k;
  double sum = term;
  const double q = -hx * hx;
  for (int k = 1; k < 60 && term != 0.0; ++k) {
    term *= q / ((double)k * (double)(k + n));
    sum += term;
    if (fabs(term) <= 1e-18 * fabs(sum)) break;
  }
  return sum;
}

/* Rotation about one axis: [cos(a/2), sin(a/2) e_i]. */
static nav_quat quat_axis(int axis, double angle_rad) {
  const double c = cos(0.5 * angle_rad), s = sin(0.5 * angle_rad);
  nav_quat q = {c, 0.0, 0.0, 0.0};
  if (axis == 0)
    q.x = s;
  else if (axis == 1)
    q.y = s;
  else
    q.z = s;
  return q;
}

/* Own rotation of the local motions at time t. */
static nav_quat motion_quat(const tm_model *m, double t) {
  switch (m->kind) {
  case NAV_TEST_MOTION_CONING: {
    /* numerics.md 5.1: q(t) = [cos(beta/2), 0, sin(beta/2) cos(Omega t), sin(beta/2) sin(Omega t)]. */
    const double x = m->p.cone_rate_rps * t;
    nav_quat q = {m->cb2, 0.0, m->sb2 * cos(x), m->sb2 * sin(x)};
    return q;
  }
  case NAV_TEST_MOTION_SCULLING:
    /* numerics.md 5.2: C(t) = R_x(theta0 sin(Omega t)). */
    return quat_axis(0, m->p.scull_angle_rad * sin(m->p.scull_rate_rps * t));
  case NAV_TEST_MOTION_SPIN: {
    /* numerics.md 5.3: C(t) = exp(t |omega| [u x]). */
    const double half = 0.5 * m->p.spin_rate_rps * t;
    const double s = sin(half);
    nav_quat q = {cos(half), s * m->axis.x, s * m->axis.y, s * m->axis.z};
    return q;
  }
  case NAV_TEST_MOTION_VERTICAL_LOOP:
    /* Pitch theta(t) = rate t about body y (ZYX pitch, nose up for a positive rate). */
    return quat_axis(1, m->p.loop_pitch_rate_rps * t);
  default: return nav_quat_identity();
  }
}

/* Sculling motion-frame kinematics (derivation in numerics.md 5.2 and the Jacobi-Anger
 * expansions cos(z sin x) = J0 + 2 sum J_2k cos(2k x), sin(z sin x) = 2 sum J_(2k+1) sin((2k+1) x)):
 *   a_m = C_x(theta) (0, A sin x, 0) = (0, A sin x cos(theta0 sin x), A sin x sin(theta0 sin x))
 *       = (0, A sum_{m odd} c_m sin(m x), A J1 + A sum_{m even >= 2} d_m cos(m x)),
 *   c_m = J_(m-1) - J_(m+1), d_m = J_(m+1) - J_(m-1), x = Omega t,
 * integrated with v_y, r_y zero-mean and v_z(0) = r(0) = 0:
 *   v_y = -A sum c_m cos(m x)/(m Omega),  r_y = -A sum c_m sin(m x)/(m Omega)^2,
 *   v_z = A J1 t + A sum d_m sin(m x)/(m Omega),  r_z = A J1 t^2/2 + A sum d_m (1 - cos(m x))/(m Omega)^2. */
static void scull_kin(const tm_model *m, double t, nav_vec3 *r, nav_vec3 *v, nav_vec3 *a) {
  const double A = m->p.scull_accel_mps2, W = m->p.scull_rate_rps;
  const double x = W * t;
  const double s1 = sin(x), c1 = cos(x);
  double ay = 0.0, vy = 0.0, ry = 0.0, az = 0.0, vz = 0.0, rz = 0.0;
  /* sin(m x), cos(m x) by the Chebyshev recurrence f_(m+1) = 2 cos x f_m - f_(m-1). */
  double sm_1 = 0.0, cm_1 = 1.0, sm = s1, cm = c1;
  for (int k = 1; k <= m->n_harm; ++k) {
    const double mw = (double)k * W;
    const double c = m->coef[k];
    if (k % 2) {
      ay += c * sm;
      vy -= c * cm / mw;
      ry -= c * sm / (mw * mw);
    } else {
      az += c * cm;
      vz += c * sm / mw;
      rz += c * (1.0 - cm) / (mw * mw);
    }
    const double sn = 2.0 * c1 * sm - sm_1, cn = 2.0 * c1 * cm - cm_1;
    sm_1 = sm;
    cm_1 = cm;
    sm = sn;
    cm = cn;
  }
  *a = nav_vec3_make(0.0, A * ay, A * (m->J1 + az));
  *v = nav_vec3_make(0.0, A * vy, A * (m->J1 * t + vz));
  *r = nav_vec3_make(0.0, A * ry, A * (0.5 * m->J1 * t * t + rz));
}

static nav_status tm_eval_local(void *self, double t, nav_local_kin *out) {
  const tm_model *m = self;
  nav_local_kin k;
  memset(&k, 0, sizeof k);
  nav_vec3 r_m = nav_vec3_zero(), v_m = nav_vec3_zero(), a_m = nav_vec3_zero();
  switch (m->kind) {
  case NAV_TEST_MOTION_STATIONARY: break;
  case NAV_TEST_MOTION_CONING: {
    /* E5.1 and its derivative. */
    const double W = m->p.cone_rate_rps, sb = sin(m->p.cone_half_angle_rad);
    const double x = W * t, s = sin(x), c = cos(x);
    k.w_nb_b_rps = nav_vec3_make(-2.0 * W * m->sb2 * m->sb2, -W * sb * s, W * sb * c);
    k.dw_nb_b_rps2 = nav_vec3_make(0.0, -W * W * sb * c, -W * W * sb * s);
    break;
  }
  case NAV_TEST_MOTION_SCULLING: {
    const double th0 = m->p.scull_angle_rad, W = m->p.scull_rate_rps;
    const double x = W * t;
    k.w_nb_b_rps = nav_vec3_make(th0 * W * cos(x), 0.0, 0.0);
    k.dw_nb_b_rps2 = nav_vec3_make(-th0 * W * W * sin(x), 0.0, 0.0);
    scull_kin(m, t, &r_m, &v_m, &a_m);
    break;
  }
  case NAV_TEST_MOTION_SPIN: k.w_nb_b_rps = nav_vec3_scale(m->axis, m->p.spin_rate_rps); break;
  case NAV_TEST_MOTION_VERTICAL_LOOP: {
    /* Velocity along body x: v_m = V (cos theta, 0, -sin theta), theta = rate t, radius V/rate. */
    const double V = m->p.loop_speed_mps, W = m->p.loop_pitch_rate_rps;
    const double th = W * t, s = sin(th), c = cos(th), rad = V / W;
    r_m = nav_vec3_make(rad * s, 0.0, rad * (c - 1.0));
    v_m = nav_vec3_make(V * c, 0.0, -V * s);
    a_m = nav_vec3_make(-V * W * s, 0.0, -V * W * c);
    k.w_nb_b_rps = nav_vec3_make(0.0, W, 0.0);
    break;
  }
  default: return NAV_ERR_INVALID_ARG;
  }
  k.q_b_n = nav_quat_mul(m->R, motion_quat(m, t));
  k.r_ned_m = nav_vec3_add(nav_mat3_mul_vec(m->C_R, r_m), nav_vec3_scale(m->g_add_n, 0.5 * t * t));
  k.v_ned_mps = nav_vec3_add(nav_mat3_mul_vec(m->C_R, v_m), nav_vec3_scale(m->g_add_n, t));
  k.a_ned_mps2 = nav_vec3_add(nav_mat3_mul_vec(m->C_R, a_m), m->g_add_n);
  *out = k;
  return NAV_OK;
}

/* Exact integral of omega_nb_b over [t0, t1] (differences of sines and cosines in product form,
 * which keeps full relative accuracy for short intervals). */
static bool tm_rate_integral(void *self, double t0, double t1, nav_vec3 *out) {
  const tm_model *m = self;
  const double dt = t1 - t0;
  switch (m->kind) {
  case NAV_TEST_MOTION_STATIONARY: *out = nav_vec3_zero(); return true;
  case NAV_TEST_MOTION_CONING: {
    /* E5.2: (-2 Omega sin^2(beta/2) dt, sin beta (cos x1 - cos x0), sin beta (sin x1 - sin x0)). */
    const double W = m->p.cone_rate_rps, sb = sin(m->p.cone_half_angle_rad);
    const double mid = 0.5 * W * (t1 + t0), hs = sin(0.5 * W * dt);
    *out =
        nav_vec3_make(-2.0 * W * m->sb2 * m->sb2 * dt, -2.0 * sb * sin(mid) * hs, 2.0 * sb * cos(mid) * hs);
    return true;
  }
  case NAV_TEST_MOTION_SCULLING: {
    /* theta0 (sin x1 - sin x0). */
    const double W = m->p.scull_rate_rps;
    *out = nav_vec3_make(2.0 * m->p.scull_angle_rad * cos(0.5 * W * (t1 + t0)) * sin(0.5 * W * dt), 0.0, 0.0);
    return true;
  }
  case NAV_TEST_MOTION_SPIN: *out = nav_vec3_scale(m->axis, m->p.spin_rate_rps * dt); return true;
  case NAV_TEST_MOTION_VERTICAL_LOOP:
    *out = nav_vec3_make(0.0, m->p.loop_pitch_rate_rps * dt, 0.0);
    return true;
  default: return false;
  }
}

/*
 * Great circle over the pole (numerics.md 5.5), in ECEF: u = u0 + (V/R) t,
 *   p = R (cos u cos lon, cos u sin lon, sin u),  v = V (-sin u cos lon, -sin u sin lon, cos u),
 *   a = -(V^2/R) (cos u cos lon, cos u sin lon, sin u).
 * Path frame: x along v, y = (-sin lon, cos lon, 0), z = -p/R, i.e. C_path_e = R_z(lon)
 * R_y(-(u + pi/2)) (columns checked against the three axes), omega_e,path = (0, -V/R, 0) in
 * path axes; the body is the path frame rotated by q_ref: q_b_e = q_path (x) q_ref,
 * omega_eb_b = C_ref^T (0, -V/R, 0), constant.
 */
static nav_status tm_eval_ecef(void *self, double t, nav_traj_state *out) {
  const tm_model *m = self;
  const double u = m->p.gc_start_angle_rad + m->gc_w * t;
  const double su = sin(u), cu = cos(u);
  const double V = m->p.gc_speed_mps, cl = m->gc_clon, sl = m->gc_slon;
  const nav_vec3 radial = nav_vec3_make(cu * cl, cu * sl, su);
  out->r_fb_f_m = nav_vec3_scale(radial, m->gc_R);
  out->v_fb_f_mps = nav_vec3_make(-V * su * cl, -V * su * sl, V * cu);
  out->a_fb_f_mps2 = nav_vec3_scale(radial, -V * m->gc_w);
  const nav_quat q_path = nav_quat_mul(quat_axis(2, m->p.gc_lon_rad), quat_axis(1, -(u + 0.5 * NAV_PI)));
  out->q_b_f = nav_quat_mul(q_path, m->R);
  out->w_fb_b_rps = nav_mat3_tmul_vec(m->C_R, nav_vec3_make(0.0, -m->gc_w, 0.0));
  out->dw_fb_b_rps2 = nav_vec3_zero();
  return NAV_OK;
}

static void tm_destroy(void *self) {
  free(self);
}

/* Check the parameters the selected kind uses; message with the scene-file field path. */
static nav_status tm_check(const nav_scene *scene, char *msg, size_t msg_size) {
  const nav_traj_test_motion *p = &scene->trajectory.test_motion;
  const char *bad = NULL;
  switch (p->kind) {
  case NAV_TEST_MOTION_STATIONARY: break;
  case NAV_TEST_MOTION_CONING:
    if (!(p->cone_half_angle_rad > 0.0 && p->cone_half_angle_rad <= 0.5 * NAV_PI))
      bad = "cone_half_angle_rad";
    else if (!isfinite(p->cone_rate_rps))
      bad = "cone_rate_rps";
    break;
  case NAV_TEST_MOTION_SCULLING:
    if (!(fabs(p->scull_angle_rad) <= 0.5 * NAV_PI))
      bad = "scull_angle_rad";
    else if (!isfinite(p->scull_accel_mps2))
      bad = "scull_accel_mps2";
    else if (!(p->scull_rate_rps > 0.0 && isfinite(p->scull_rate_rps)))
      bad = "scull_rate_rps";
    break;
  case NAV_TEST_MOTION_SPIN:
    if (!isfinite(p->spin_rate_rps))
      bad = "spin_rate_rps";
    else if (!nav_vec3_isfinite(p->spin_axis_b) || !(nav_vec3_norm(p->spin_axis_b) > 0.0))
      bad = "spin_axis_b";
    break;
  case NAV_TEST_MOTION_POLAR_GREAT_CIRCLE:
    if (!(p->gc_height_m > -0.5 * NAV_WGS84_B_M && p->gc_height_m < 1.0e8))
      bad = "gc_height_m";
    else if (!isfinite(p->gc_speed_mps))
      bad = "gc_speed_mps";
    else if (!isfinite(p->gc_start_angle_rad))
      bad = "gc_start_angle_rad";
    else if (!isfinite(p->gc_lon_rad))
      bad = "gc_lon_rad";
    break;
  case NAV_TEST_MOTION_VERTICAL_LOOP:
    if (!isfinite(p->loop_speed_mps))
      bad = "loop_speed_mps";
    else if (!(isfinite(p->loop_pitch_rate_rps) && p->loop_pitch_rate_rps != 0.0))
      bad = "loop_pitch_rate_rps";
    break;
  default:
    if (msg) snprintf(msg, msg_size, "trajectory.test_motion.kind: unknown test motion %d", (int)p->kind);
    return NAV_ERR_INVALID_ARG;
  }
  if (bad) {
    if (msg)
      snprintf(msg, msg_size, "trajectory.test_motion.%s is out of range for the %s motion", bad,
               nav_test_motion_kind_name(p->kind));
    return NAV_ERR_INVALID_ARG;
  }
  return NAV_OK;
}

nav_status nav_traj_test_motion_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                       size_t msg_size) {
  (void)dt_s; /* closed forms everywhere: no sub-grid */
  const nav_status st = tm_check(scene, msg, msg_size);
  if (st != NAV_OK) return st;
  tm_model *m = calloc(1, sizeof *m);
  if (!m) return NAV_ERR_NO_MEMORY;
  m->p = scene->trajectory.test_motion;
  m->kind = m->p.kind;
  const nav_quat q_ref = nav_euler_to_quat(scene->trajectory.initial_attitude);
  m->cb2 = cos(0.5 * m->p.cone_half_angle_rad);
  m->sb2 = sin(0.5 * m->p.cone_half_angle_rad);
  if (m->kind == NAV_TEST_MOTION_SPIN)
    m->axis = nav_vec3_scale(m->p.spin_axis_b, 1.0 / nav_vec3_norm(m->p.spin_axis_b));
  if (m->kind == NAV_TEST_MOTION_SCULLING) {
    double J[SCULL_MAX_HARMONICS + 2];
    for (int n = 0; n <= SCULL_MAX_HARMONICS + 1; ++n)
      J[n] = bessel_j(n, m->p.scull_angle_rad);
    m->J1 = J[1];
    m->n_harm = SCULL_MAX_HARMONICS;
    double bound = 1.0; /* (|theta0|/2)^(m-1) / (m-1)!, a bound of |J_(m-1)| */
    for (int k = 1; k <= SCULL_MAX_HARMONICS; ++k) {
      m->coef[k] = (k % 2) ? J[k - 1] - J[k + 1] : J[k + 1] - J[k - 1];
      if (k > 1) bound *= 0.5 * fabs(m->p.scull_angle_rad) / (double)(k - 1);
      if (bound < SCULL_CUT) {
        m->n_harm = k;
        break;
      }
    }
    if (scene->earth.model == NAV_EARTH_FLAT)
      m->g_add_n = nav_vec3_make(0.0, 0.0, scene->earth.flat_gravity_mps2);
  }
  memset(out, 0, sizeof *out);
  out->name = "test_motion";
  out->duration_s = scene->trajectory.duration_s;
  out->self = m;
  out->destroy = tm_destroy;
  if (m->kind == NAV_TEST_MOTION_POLAR_GREAT_CIRCLE) {
    m->R = q_ref;
    m->gc_R = NAV_WGS84_A_M + m->p.gc_height_m;
    m->gc_w = m->p.gc_speed_mps / m->gc_R;
    m->gc_slon = sin(m->p.gc_lon_rad);
    m->gc_clon = cos(m->p.gc_lon_rad);
    out->eval_ecef = tm_eval_ecef;
  } else {
    m->R = nav_quat_normalize(nav_quat_mul(q_ref, nav_quat_conj(motion_quat(m, 0.0))));
    out->eval_local = tm_eval_local;
    out->rate_integral = tm_rate_integral;
  }
  m->C_R = nav_quat_to_dcm(m->R);
  return NAV_OK;
}
