/*
 * Gyro-free strapdown INS (numerics.md 1.5; design in nav_gyrofree.h).
 *
 * Per interval k (t_(k-1) -> t_k, length dt), with D = H^+ (6 x N) and dA the array increments:
 *   y = D dA = [int f dt ; w_k - w_(k-1)] + D int c(omega) dt        (E1.23 integrated)
 *   w_k  = w_(k-1) + y_w - (D int c dt)_w      (implicit in w_k unless D_w annihilates c)
 *   dv_k = y_f - (D int c dt)_f                 (specific-force increment, body axes)
 *   dtheta_k = int omega dt                     (from the rate interpolant)
 * Order of operations: the rate first (everything else uses the interpolant through w_k), then
 * the centripetal integral and dv, then dtheta; finally the strapdown step, and only if it
 * succeeds is the rate history advanced, so a failed step leaves the object as it was.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_gyrofree.h"

struct nav_gyrofree {
  nav_gyrofree_config cfg;
  nav_array_geometry geom;
  nav_ins *ins;
  nav_vec3 w_prev_rps;  /* w_(k-1) */
  nav_vec3 w_prev2_rps; /* w_(k-2), valid when n_hist >= 2 */
  int n_hist;           /* rate samples known before the current step (1 after create) */
  double prev_dt_s;     /* length of the previous interval (the quadratic needs equal steps) */
  nav_imu_increment last;
  bool comp_on;   /* a compensation was set (nav_gyrofree_set_compensation) */
  double comp[6]; /* subtracted from H^+ dA / dt: [f bias; omega_dot bias] */
  char msg[256];
};

nav_gyrofree_config nav_gyrofree_config_default(void) {
  nav_gyrofree_config c;
  memset(&c, 0, sizeof c);
  /* The cube layout with r = 0.1 m (numerics.md 1.6 worked examples) cannot fail. */
  if (nav_array_cube_layout(0.1, &c.array) != NAV_OK) c.array.n_sensors = 0;
  c.ins = nav_ins_config_default();
  c.ins.algorithm = NAV_MECH_HIGH_ORDER;
  c.rate_interp = NAV_GYROFREE_RATE_QUADRATIC;
  c.max_iterations = 20;
  return c;
}

nav_status nav_gyrofree_create(const nav_gyrofree_config *cfg, const nav_ins_state *initial,
                               nav_vec3 w_ib_b0_rps, nav_gyrofree **out) {
  nav_gyrofree *gf = NULL;
  nav_status st = NAV_OK;
  if (!cfg || !initial || !out) return NAV_ERR_INVALID_ARG;
  if (cfg->rate_interp != NAV_GYROFREE_RATE_LINEAR && cfg->rate_interp != NAV_GYROFREE_RATE_QUADRATIC)
    return NAV_ERR_INVALID_ARG;
  if (cfg->max_iterations < 1 || cfg->max_iterations > 1000 || !nav_vec3_isfinite(w_ib_b0_rps))
    return NAV_ERR_INVALID_ARG;
  gf = calloc(1, sizeof *gf);
  if (!gf) return NAV_ERR_NO_MEMORY;
  gf->cfg = *cfg;
  st = nav_array_geometry_compute(&cfg->array, &gf->geom);
  if (st != NAV_OK) goto cleanup;
  /* Use the renormalised axes (H was built from them) in the centripetal term too. */
  for (int i = 0; i < cfg->array.n_sensors; ++i)
    gf->cfg.array.n_s_b[i] = nav_vec3_scale(cfg->array.n_s_b[i], 1.0 / nav_vec3_norm(cfg->array.n_s_b[i]));
  st = nav_ins_create(&cfg->ins, initial, &gf->ins);
  if (st != NAV_OK) goto cleanup;
  gf->w_prev_rps = w_ib_b0_rps;
  gf->w_prev2_rps = w_ib_b0_rps;
  gf->n_hist = 1;
  gf->last.t_s = initial->t_s;
  *out = gf;
  gf = NULL;
cleanup:
  nav_gyrofree_destroy(gf);
  return st;
}

void nav_gyrofree_destroy(nav_gyrofree *gf) {
  if (!gf) return;
  nav_ins_destroy(gf->ins);
  free(gf);
}

const nav_ins_state *nav_gyrofree_get_state(const nav_gyrofree *gf) {
  return gf ? nav_ins_get_state(gf->ins) : NULL;
}
nav_vec3 nav_gyrofree_rate(const nav_gyrofree *gf) {
  return gf ? gf->w_prev_rps : nav_vec3_zero();
}
const nav_imu_increment *nav_gyrofree_last_increment(const nav_gyrofree *gf) {
  return gf ? &gf->last : NULL;
}
const nav_array_geometry *nav_gyrofree_geometry(const nav_gyrofree *gf) {
  return gf ? &gf->geom : NULL;
}
const char *nav_gyrofree_last_error(const nav_gyrofree *gf) {
  return gf ? gf->msg : "";
}

nav_status nav_gyrofree_set_compensation(nav_gyrofree *gf, const double beta[6]) {
  if (!gf || !beta) return NAV_ERR_INVALID_ARG;
  for (int a = 0; a < 6; ++a)
    if (!isfinite(beta[a])) return NAV_ERR_NUMERIC;
  memcpy(gf->comp, beta, sizeof gf->comp);
  gf->comp_on = true;
  return NAV_OK;
}

nav_status nav_gyrofree_correct(nav_gyrofree *gf, const nav_ins_state *state, nav_vec3 dw_ib_b_rps) {
  if (!gf) return NAV_ERR_INVALID_ARG;
  if (!nav_vec3_isfinite(dw_ib_b_rps)) return NAV_ERR_NUMERIC;
  if (state) {
    const nav_status st = nav_ins_set_state(gf->ins, state);
    if (st != NAV_OK) return st;
  }
  /* The whole rate history moves by the same amount, so the interpolant of the next interval
   * is shifted, not bent. */
  gf->w_prev_rps = nav_vec3_sub(gf->w_prev_rps, dw_ib_b_rps);
  gf->w_prev2_rps = nav_vec3_sub(gf->w_prev2_rps, dw_ib_b_rps);
  return NAV_OK;
}

const nav_ins *nav_gyrofree_ins(const nav_gyrofree *gf) {
  return gf ? gf->ins : NULL;
}

/* Rate interpolant on the interval, s = (t - t_k)/dt in [-1, 0]. Quadratic: Lagrange through
 * s = -2, -1, 0; linear: through s = -1, 0. */
typedef struct rate_interp {
  bool quadratic;
  nav_vec3 w0, w1, w2; /* w_k, w_(k-1), w_(k-2) */
} rate_interp;

static nav_vec3 interp_eval(const rate_interp *ip, double s) {
  if (!ip->quadratic) return nav_vec3_add(nav_vec3_scale(ip->w0, 1.0 + s), nav_vec3_scale(ip->w1, -s));
  const double l0 = 0.5 * (s + 1.0) * (s + 2.0), l1 = -s * (s + 2.0), l2 = 0.5 * s * (s + 1.0);
  return nav_vec3_add(nav_vec3_add(nav_vec3_scale(ip->w0, l0), nav_vec3_scale(ip->w1, l1)),
                      nav_vec3_scale(ip->w2, l2));
}

/* int_interval omega dt: trapezoid, or Adams-Moulton 3 (the exact integral of the quadratic over
 * the last of its three intervals: weights 5/12, 8/12, -1/12). */
static nav_vec3 interp_integral(const rate_interp *ip, double dt) {
  if (!ip->quadratic) return nav_vec3_scale(nav_vec3_add(ip->w0, ip->w1), 0.5 * dt);
  return nav_vec3_scale(nav_vec3_add(nav_vec3_add(nav_vec3_scale(ip->w0, 5.0), nav_vec3_scale(ip->w1, 8.0)),
                                     nav_vec3_scale(ip->w2, -1.0)),
                        dt / 12.0);
}

/* z = D int c(omega(t)) dt: 3-point Gauss-Legendre on [-1, 0] is exact for c(interpolant), a
 * polynomial of degree <= 4 in s. */
static void centripetal_solve(const nav_gyrofree *gf, const rate_interp *ip, double dt, double z[6]) {
  static const double k_gl_x = 0.77459666924148337704; /* sqrt(3/5) */
  const double s_nodes[3] = {-0.5 - 0.5 * k_gl_x, -0.5, -0.5 + 0.5 * k_gl_x};
  const double w_nodes[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0}; /* sum 1: interval of length 1 in s */
  const int n = gf->cfg.array.n_sensors;
  double cint[NAV_ARRAY_MAX_SENSORS] = {0.0};
  for (int j = 0; j < 3; ++j) {
    double c[NAV_ARRAY_MAX_SENSORS];
    nav_array_centripetal(&gf->cfg.array, interp_eval(ip, s_nodes[j]), c);
    for (int i = 0; i < n; ++i)
      cint[i] += w_nodes[j] * dt * c[i];
  }
  for (int a = 0; a < 6; ++a) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i)
      acc += gf->geom.h_pinv[a][i] * cint[i];
    z[a] = acc;
  }
}

nav_status nav_gyrofree_step(nav_gyrofree *gf, const nav_array_increment *inc) {
  if (!gf || !inc) return NAV_ERR_INVALID_ARG;
  const int n = gf->cfg.array.n_sensors;
  if (inc->n_sensors != n) {
    snprintf(gf->msg, sizeof gf->msg, "array increment has %d sensors, the layout %d", inc->n_sensors, n);
    return NAV_ERR_INVALID_ARG;
  }
  if (!(inc->dt_s > 0.0) || !isfinite(inc->dt_s)) {
    snprintf(gf->msg, sizeof gf->msg, "interval dt = %g s is not positive and finite", inc->dt_s);
    return NAV_ERR_INVALID_ARG;
  }
  for (int i = 0; i < n; ++i)
    if (!isfinite(inc->dv_mps[i])) {
      snprintf(gf->msg, sizeof gf->msg, "array increment %d is not finite", i);
      return NAV_ERR_NUMERIC;
    }
  const double dt = inc->dt_s;

  /* y = H^+ dA (E1.24 for the cube, least squares in general). */
  double y[6];
  for (int a = 0; a < 6; ++a) {
    double acc = 0.0;
    for (int i = 0; i < n; ++i)
      acc += gf->geom.h_pinv[a][i] * inc->dv_mps[i];
    y[a] = acc;
  }
  if (gf->comp_on)
    for (int a = 0; a < 6; ++a)
      y[a] -= gf->comp[a] * dt;
  const nav_vec3 dw_meas = nav_vec3_make(y[3], y[4], y[5]);

  /* The quadratic interpolant needs w_(k-2) on an interval of the same length; otherwise (first
   * step, or a changed dt) this interval is linear. */
  rate_interp ip;
  ip.quadratic = gf->cfg.rate_interp == NAV_GYROFREE_RATE_QUADRATIC && gf->n_hist >= 2 &&
                 fabs(gf->prev_dt_s - dt) <= 1e-9 * dt;
  ip.w1 = gf->w_prev_rps;
  ip.w2 = gf->w_prev2_rps;
  ip.w0 = nav_vec3_add(gf->w_prev_rps, dw_meas); /* exact when D_w annihilates c (cube) */

  /* Fixed-point iteration for the implicit rate: w_k = w_(k-1) + y_w - (D int c dt)_w, where
   * int c depends on w_k through the interpolant. For the cube (D_w c = 0, E1.24 property (a))
   * the first pass changes w_k only by round-off. */
  double z[6] = {0.0};
  bool converged = false;
  for (int it = 0; it < gf->cfg.max_iterations; ++it) {
    centripetal_solve(gf, &ip, dt, z);
    const nav_vec3 w_next =
        nav_vec3_sub(nav_vec3_add(gf->w_prev_rps, dw_meas), nav_vec3_make(z[3], z[4], z[5]));
    const double change = nav_vec3_norm(nav_vec3_sub(w_next, ip.w0));
    ip.w0 = w_next;
    if (change <= 1e-13 * nav_vec3_norm(w_next) + 1e-300) {
      converged = true;
      break;
    }
  }
  if (!converged) {
    snprintf(gf->msg, sizeof gf->msg,
             "implicit angular-rate iteration did not converge in %d passes at t = %.9g s (|w| = %.6g rad/s)",
             gf->cfg.max_iterations, inc->t_s, nav_vec3_norm(ip.w0));
    return NAV_ERR_NOT_CONVERGED;
  }
  /* Centripetal integral with the final rate, then dv (the centripetal term uses the integrated
   * omega: numerics.md 1.5 item 5). */
  centripetal_solve(gf, &ip, dt, z);
  nav_imu_increment imu;
  imu.k = inc->k;
  imu.t_s = inc->t_s;
  imu.dt_s = dt;
  imu.dv_b_mps = nav_vec3_make(y[0] - z[0], y[1] - z[1], y[2] - z[2]);
  imu.dtheta_b_rad = interp_integral(&ip, dt);
  if (!nav_vec3_isfinite(imu.dv_b_mps) || !nav_vec3_isfinite(imu.dtheta_b_rad) || !nav_vec3_isfinite(ip.w0)) {
    snprintf(gf->msg, sizeof gf->msg, "non-finite rate or increment at t = %.9g s", inc->t_s);
    return NAV_ERR_NUMERIC;
  }
  const nav_status st = nav_ins_step(gf->ins, &imu);
  if (st != NAV_OK) {
    snprintf(gf->msg, sizeof gf->msg, "strapdown step failed at t = %.9g s: %s (%s)", inc->t_s,
             nav_status_str(st), nav_ins_last_error(gf->ins));
    return st;
  }
  gf->w_prev2_rps = gf->w_prev_rps;
  gf->w_prev_rps = ip.w0;
  if (gf->n_hist < 2) ++gf->n_hist;
  gf->prev_dt_s = dt;
  gf->last = imu;
  gf->msg[0] = '\0';
  return NAV_OK;
}
