/*
 * Gyro-free (accelerometer-array) INS aided by GNSS (nav_gyrofree_gnss.h; derivation in
 * docs/gyro-free-gnss.md). A dense error-state filter of 18 or 21 states: small enough that
 * plain loops (skipping the zeros of the sparse F and Phi) cost about as much as the strapdown
 * step, so it does not share the pattern machinery of the gyro INS filter (ekf.c); it shares
 * that filter's F of the navigation blocks (model.c, numerics.md 6.1) and its H (E6.3-E6.4).
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_gyrofree_gnss.h"

#define NMAX NAV_GFG_MAX_STATES

struct nav_gfg_filter {
  nav_gfg_filter_config cfg;
  nav_array_geometry geom;
  nav_accel_array array; /* axes renormalised */
  size_t n;
  bool split;      /* turn-on and Gauss-Markov bias parts as separate states (idx_bc) */
  size_t idx_bc;   /* first of the six constant-bias states (valid when split) */
  size_t idx_gnss; /* first GNSS state (valid with cfg.gnss_gm) */
  size_t n_fb;     /* states fed back and reset: 18, or 24 when split */
  double x[NMAX];
  double P[NMAX * NMAX];
  double q_bias; /* per-sensor GM bias spectral density 2 sigma^2 / T [m^2/s^5] (0: none) */
  double nis;
  char msg[256];
};

static void set_err(char *buf, size_t size, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, size, fmt, ap);
  va_end(ap);
}

static bool vec3_pos(nav_vec3 v) {
  return v.x > 0.0 && v.y > 0.0 && v.z > 0.0 && nav_vec3_isfinite(v);
}

nav_gfg_filter_config nav_gfg_filter_config_default(void) {
  nav_gfg_filter_config c;
  memset(&c, 0, sizeof c);
  if (nav_array_cube_layout(0.1, &c.array) != NAV_OK) c.array.n_sensors = 0;
  c.bias_gm_tau_s = 3600.0;
  c.bias_sd_floor_mps2 = 1e-5;
  c.pos_sd_m = nav_vec3_make(1.0, 1.0, 1.0);
  c.vel_sd_mps = nav_vec3_make(0.1, 0.1, 0.1);
  c.att_sd_rad = nav_vec3_make(1e-3, 1e-3, 1e-3);
  c.rate_sd_rps = nav_vec3_make(1e-3, 1e-3, 1e-3);
  c.gnss_gm_sd_m = nav_vec3_make(1.0, 1.0, 1.0);
  c.gnss_gm_tau_s = nav_vec3_make(300.0, 300.0, 300.0);
  return c;
}

/* Cholesky check of a symmetric n x n matrix (the PD test after every step and update). */
static bool is_pd(const double *P, size_t n) {
  double L[NMAX * NMAX];
  for (size_t i = 0; i < n; ++i)
    if (!(P[i * n + i] > 0.0) || !isfinite(P[i * n + i])) return false;
  return nav_matn_cholesky(L, P, n) == NAV_OK;
}

nav_status nav_gfg_filter_create(const nav_gfg_filter_config *cfg, nav_gfg_filter **out) {
  if (!cfg || !out) return NAV_ERR_INVALID_ARG;
  const bool gm_ok = !cfg->bias_gm || (cfg->bias_gm_sd_mps2 >= 0.0 && isfinite(cfg->bias_gm_sd_mps2) &&
                                       cfg->bias_gm_tau_s > 0.0 && isfinite(cfg->bias_gm_tau_s));
  const bool gnss_ok = !cfg->gnss_gm || (vec3_pos(cfg->gnss_gm_sd_m) && vec3_pos(cfg->gnss_gm_tau_s));
  if (!(cfg->vrw_mps_per_sqrt_s >= 0.0) || !isfinite(cfg->vrw_mps_per_sqrt_s) || !(cfg->bias_const_sd_mps2 >= 0.0) ||
      !isfinite(cfg->bias_const_sd_mps2) || !(cfg->bias_sd_floor_mps2 > 0.0) || !isfinite(cfg->bias_sd_floor_mps2) ||
      !gm_ok || !gnss_ok || !vec3_pos(cfg->pos_sd_m) || !vec3_pos(cfg->vel_sd_mps) || !vec3_pos(cfg->att_sd_rad) ||
      !vec3_pos(cfg->rate_sd_rps))
    return NAV_ERR_INVALID_ARG;
  nav_gfg_filter *f = calloc(1, sizeof *f);
  if (!f) return NAV_ERR_NO_MEMORY;
  f->cfg = *cfg;
  nav_status st = nav_array_geometry_compute(&cfg->array, &f->geom);
  if (st != NAV_OK) {
    free(f);
    return st;
  }
  f->array = cfg->array;
  for (int i = 0; i < f->array.n_sensors; ++i)
    f->array.n_s_b[i] = nav_vec3_scale(f->array.n_s_b[i], 1.0 / nav_vec3_norm(f->array.n_s_b[i]));
  /* A bias with both a turn-on (constant) and a Gauss-Markov part needs two sets of states: one
   * Gauss-Markov state of the combined sigma would let the constant part decay and make the
   * filter overconfident (docs/gyro-free-gnss.md section 2). */
  f->split = cfg->bias_gm && cfg->bias_const_sd_mps2 > 0.0;
  f->idx_bc = NAV_GFG_N_CORE;
  f->n_fb = f->split ? NAV_GFG_N_CORE + 6 : NAV_GFG_N_CORE;
  f->idx_gnss = f->n_fb;
  f->n = f->n_fb + (cfg->gnss_gm ? 3 : 0);
  f->q_bias = cfg->bias_gm ? 2.0 * cfg->bias_gm_sd_mps2 * cfg->bias_gm_sd_mps2 / cfg->bias_gm_tau_s : 0.0;
  const size_t n = f->n;
  const nav_vec3 *sd[4] = {&cfg->pos_sd_m, &cfg->vel_sd_mps, &cfg->att_sd_rad, &cfg->rate_sd_rps};
  for (int b = 0; b < 4; ++b)
    for (int i = 0; i < 3; ++i) {
      const double s = nav_vec3_get(*sd[b], i);
      f->P[(size_t)(3 * b + i) * (n + 1)] = s * s;
    }
  /* Bias block: beta = H^+ b with independent per-sensor biases of variance sigma^2 has the
   * covariance sigma^2 H^+ H^+T = sigma^2 (H^T H)^-1 (geom.cov). */
  const double gm2 = cfg->bias_gm ? cfg->bias_gm_sd_mps2 * cfg->bias_gm_sd_mps2 : 0.0;
  const double c2 = cfg->bias_const_sd_mps2 * cfg->bias_const_sd_mps2, fl2 = cfg->bias_sd_floor_mps2 * cfg->bias_sd_floor_mps2;
  /* Split: the GM part on beta, the constant part on its own block; else both on beta. */
  const double s2 = f->split ? fmax(gm2, fl2) : fmax(c2 + gm2, fl2);
  for (size_t a = 0; a < 6; ++a)
    for (size_t b = 0; b < 6; ++b) {
      f->P[(NAV_GFG_IDX_BF + a) * n + NAV_GFG_IDX_BF + b] = s2 * f->geom.cov[a][b];
      if (f->split) f->P[(f->idx_bc + a) * n + f->idx_bc + b] = fmax(c2, fl2) * f->geom.cov[a][b];
    }
  if (cfg->gnss_gm)
    for (int i = 0; i < 3; ++i) {
      const double s = nav_vec3_get(cfg->gnss_gm_sd_m, i);
      f->P[(f->idx_gnss + (size_t)i) * (n + 1)] = s * s;
    }
  if (!is_pd(f->P, n)) {
    free(f);
    return NAV_ERR_NUMERIC;
  }
  *out = f;
  return NAV_OK;
}

void nav_gfg_filter_destroy(nav_gfg_filter *f) { free(f); }
size_t nav_gfg_filter_n_states(const nav_gfg_filter *f) { return f ? f->n : 0; }
const double *nav_gfg_filter_state(const nav_gfg_filter *f) { return f ? f->x : NULL; }
const double *nav_gfg_filter_cov(const nav_gfg_filter *f) { return f ? f->P : NULL; }
double nav_gfg_filter_last_nis(const nav_gfg_filter *f) { return f ? f->nis : 0.0; }
const nav_array_geometry *nav_gfg_filter_geometry(const nav_gfg_filter *f) { return f ? &f->geom : NULL; }
const char *nav_gfg_filter_last_error(const nav_gfg_filter *f) { return f ? f->msg : ""; }

void nav_gfg_filter_reset_errors(nav_gfg_filter *f) {
  if (f) memset(f->x, 0, f->n_fb * sizeof f->x[0]);
}

size_t nav_gfg_filter_idx_gnss(const nav_gfg_filter *f) { return f && f->cfg.gnss_gm ? f->idx_gnss : 0; }
size_t nav_gfg_filter_idx_const_bias(const nav_gfg_filter *f) { return f && f->split ? f->idx_bc : 0; }

void nav_gfg_filter_bias_estimate(const nav_gfg_filter *f, double beta[6]) {
  if (!f || !beta) return;
  for (size_t a = 0; a < 6; ++a) beta[a] = f->x[NAV_GFG_IDX_BF + a] + (f->split ? f->x[f->idx_bc + a] : 0.0);
}

/*
 * M = D J_c(w) (6 x 3): how a rate error moves y = H^+ (dA - int c dt) / dt through the
 * centripetal compensation, with J_c the Jacobian of E1.22's centripetal readings,
 * d c_i / d w = (r_i . w) n_i^T + (n_i . w) r_i^T - 2 (n_i . r_i) w^T.
 */
static void centripetal_gain(const nav_gfg_filter *f, nav_vec3 w, double M[6][3]) {
  const int N = f->array.n_sensors;
  double J[NAV_ARRAY_MAX_SENSORS][3];
  for (int i = 0; i < N; ++i) {
    const nav_vec3 r = f->array.r_bs_b_m[i], nn = f->array.n_s_b[i];
    const double rw = nav_vec3_dot(r, w), nw = nav_vec3_dot(nn, w), nr = nav_vec3_dot(nn, r);
    for (int c = 0; c < 3; ++c)
      J[i][c] = rw * nav_vec3_get(nn, c) + nw * nav_vec3_get(r, c) - 2.0 * nr * nav_vec3_get(w, c);
  }
  for (int a = 0; a < 6; ++a)
    for (int c = 0; c < 3; ++c) {
      double s = 0.0;
      for (int i = 0; i < N; ++i) s += f->geom.h_pinv[a][i] * J[i][c];
      M[a][c] = s;
    }
}

static bool nav_ok(const nav_filter_nav *nav) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!isfinite(nav->C_b_n.m[i][j])) return false;
  return isfinite(nav->lat_rad) && isfinite(nav->h_m) && nav_vec3_isfinite(nav->v_eb_n_mps) &&
         nav_vec3_isfinite(nav->f_ib_b_mps2) && nav_vec3_isfinite(nav->w_ib_b_rps);
}

/* Continuous F and G Q_c G^T (docs/gyro-free-gnss.md E21.1-E21.4). */
static void build_model(const nav_gfg_filter *f, const nav_filter_nav *nav, double *F, double *Q) {
  const size_t n = f->n;
  double F15[NAV_FILTER_N_CORE * NAV_FILTER_N_CORE], proc[NAV_FILTER_N_CORE];
  memset(proc, 0, sizeof proc);
  const nav_filter_layout lay = nav_filter_layout_of(0);
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(nav->lat_rad, nav->h_m);
  /* The navigation blocks of the gyro INS (numerics.md 6.1) with dw in the place of the gyro
   * bias and beta_f in that of the accelerometer bias. */
  nav_filter_build_F(F15, &lay, nav, &earth, proc);
  memset(F, 0, n * n * sizeof *F);
  memset(Q, 0, n * n * sizeof *Q);
  for (size_t i = 0; i < NAV_FILTER_N_CORE; ++i)
    for (size_t j = 0; j < NAV_FILTER_N_CORE; ++j) F[i * n + j] = F15[i * NAV_FILTER_N_CORE + j];
  double M[6][3];
  centripetal_gain(f, nav->w_ib_b_rps, M);
  const nav_mat3 C = nav->C_b_n;
  for (int i = 0; i < 3; ++i)
    for (int c = 0; c < 3; ++c) {
      /* dv_dot += C_b_n (-D_f J_c) dw;  dw_dot = -D_w J_c dw + beta_w */
      double s = 0.0;
      for (int k = 0; k < 3; ++k) s += C.m[i][k] * M[k][c];
      F[(NAV_GFG_IDX_DV + (size_t)i) * n + NAV_GFG_IDX_DW + (size_t)c] = -s;
      F[(NAV_GFG_IDX_DW + (size_t)i) * n + NAV_GFG_IDX_DW + (size_t)c] = -M[3 + i][c];
    }
  for (size_t i = 0; i < 3; ++i) F[(NAV_GFG_IDX_DW + i) * n + NAV_GFG_IDX_BW + i] = 1.0;
  if (f->split) /* the constant part enters as the Gauss-Markov part does: C_b_n on dv, I on dw */
    for (size_t i = 0; i < 3; ++i) {
      for (size_t c = 0; c < 3; ++c) F[(NAV_GFG_IDX_DV + i) * n + f->idx_bc + c] = C.m[i][c];
      F[(NAV_GFG_IDX_DW + i) * n + f->idx_bc + 3 + i] = 1.0;
    }
  if (f->cfg.bias_gm)
    for (size_t i = 0; i < 6; ++i) F[(NAV_GFG_IDX_BF + i) * (n + 1)] = -1.0 / f->cfg.bias_gm_tau_s;
  if (f->cfg.gnss_gm)
    for (int i = 0; i < 3; ++i)
      F[(f->idx_gnss + (size_t)i) * (n + 1)] = -1.0 / nav_vec3_get(f->cfg.gnss_gm_tau_s, i);
  /* Sensor white noise: [w_f; w_w] = D w with cov N^2 (H^T H)^-1; w_f enters dv through C_b_n. */
  const double q = f->cfg.vrw_mps_per_sqrt_s * f->cfg.vrw_mps_per_sqrt_s;
  double Cc[3][3], Cfw[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double a = 0.0, b = 0.0;
      for (int k = 0; k < 3; ++k) {
        a += C.m[i][k] * f->geom.cov[k][j];
        b += C.m[i][k] * f->geom.cov[k][3 + j];
      }
      Cc[i][j] = a;
      Cfw[i][j] = b;
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double a = 0.0;
      for (int k = 0; k < 3; ++k) a += Cc[i][k] * C.m[j][k];
      Q[(NAV_GFG_IDX_DV + (size_t)i) * n + NAV_GFG_IDX_DV + (size_t)j] = q * a;
      Q[(NAV_GFG_IDX_DV + (size_t)i) * n + NAV_GFG_IDX_DW + (size_t)j] = q * Cfw[i][j];
      Q[(NAV_GFG_IDX_DW + (size_t)j) * n + NAV_GFG_IDX_DV + (size_t)i] = q * Cfw[i][j];
      Q[(NAV_GFG_IDX_DW + (size_t)i) * n + NAV_GFG_IDX_DW + (size_t)j] = q * f->geom.cov[3 + i][3 + j];
    }
  for (size_t a = 0; a < 6; ++a)
    for (size_t b = 0; b < 6; ++b) Q[(NAV_GFG_IDX_BF + a) * n + NAV_GFG_IDX_BF + b] = f->q_bias * f->geom.cov[a][b];
  if (f->cfg.gnss_gm)
    for (int i = 0; i < 3; ++i) {
      const double s = nav_vec3_get(f->cfg.gnss_gm_sd_m, i);
      Q[(f->idx_gnss + (size_t)i) * (n + 1)] = 2.0 * s * s / nav_vec3_get(f->cfg.gnss_gm_tau_s, i);
    }
}

nav_status nav_gfg_filter_predict(nav_gfg_filter *f, const nav_filter_nav *nav, double dt_s) {
  if (!f || !nav || !(dt_s > 0.0) || !isfinite(dt_s)) return NAV_ERR_INVALID_ARG;
  if (!nav_ok(nav)) {
    set_err(f->msg, sizeof f->msg, "non-finite navigation state in the prediction");
    return NAV_ERR_NUMERIC;
  }
  if (cos(nav->lat_rad) < 1e-6) {
    set_err(f->msg, sizeof f->msg, "latitude %.9f rad: the NED error model is singular at the poles", nav->lat_rad);
    return NAV_ERR_OUT_OF_RANGE;
  }
  const size_t n = f->n;
  double F[NMAX * NMAX], Q[NMAX * NMAX], Phi[NMAX * NMAX], W[NMAX * NMAX], Pn[NMAX * NMAX], xn[NMAX];
  build_model(f, nav, F, Q);
  /* Phi = I + F T + (F T)^2 / 2 (numerics.md E6.2); F is sparse, so skip its zeros. */
  for (size_t i = 0; i < n * n; ++i) F[i] *= dt_s;
  memcpy(Phi, F, n * n * sizeof *F);
  for (size_t i = 0; i < n; ++i) {
    Phi[i * n + i] += 1.0;
    for (size_t k = 0; k < n; ++k) {
      const double a = 0.5 * F[i * n + k];
      if (a == 0.0) continue;
      for (size_t j = 0; j < n; ++j) Phi[i * n + j] += a * F[k * n + j];
    }
  }
  /* E6.2 fused: P <- Phi (P + Q_c T/2) Phi^T + Q_c T/2. */
  const double h = 0.5 * dt_s;
  for (size_t i = 0; i < n * n; ++i) Pn[i] = f->P[i] + h * Q[i];
  memset(W, 0, n * n * sizeof *W);
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < n; ++k) {
      const double a = Phi[i * n + k];
      if (a == 0.0) continue;
      for (size_t j = 0; j < n; ++j) W[i * n + j] += a * Pn[k * n + j];
    }
  for (size_t i = 0; i < n; ++i) {
    double s = 0.0;
    for (size_t k = 0; k < n; ++k) s += Phi[i * n + k] * f->x[k];
    xn[i] = s;
    for (size_t j = 0; j <= i; ++j) {
      double v = 0.0;
      for (size_t k = 0; k < n; ++k) v += W[i * n + k] * Phi[j * n + k];
      v += h * 0.5 * (Q[i * n + j] + Q[j * n + i]);
      Pn[i * n + j] = v;
      Pn[j * n + i] = v;
    }
  }
  if (!is_pd(Pn, n)) {
    set_err(f->msg, sizeof f->msg, "propagated covariance is not positive definite (dt = %g s)", dt_s);
    return NAV_ERR_NUMERIC;
  }
  memcpy(f->P, Pn, n * n * sizeof *Pn);
  memcpy(f->x, xn, n * sizeof *xn);
  f->msg[0] = '\0';
  return NAV_OK;
}

/* z = H x + v (m = 3): Cholesky of S, K = P H^T S^-1, Joseph form (numerics.md E6.5). */
static nav_status update3(nav_gfg_filter *f, const double *H, nav_vec3 zv, nav_vec3 r, const char *what) {
  const size_t n = f->n;
  const double z[3] = {zv.x, zv.y, zv.z}, R[3] = {r.x, r.y, r.z};
  if (!nav_vec3_isfinite(zv) || !vec3_pos(r)) {
    set_err(f->msg, sizeof f->msg, "%s update: non-finite measurement or R not positive", what);
    return !nav_vec3_isfinite(zv) ? NAV_ERR_NUMERIC : NAV_ERR_INVALID_ARG;
  }
  double PHt[NMAX * 3], S[9], L[9], K[NMAX * 3], y[3], A[NMAX * NMAX], AP[NMAX * NMAX], Pn[NMAX * NMAX];
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += f->P[i * n + k] * H[c * n + k];
      PHt[i * 3 + c] = s;
    }
  for (size_t a = 0; a < 3; ++a) {
    double hx = 0.0;
    for (size_t k = 0; k < n; ++k) hx += H[a * n + k] * f->x[k];
    y[a] = z[a] - hx;
    for (size_t b = 0; b < 3; ++b) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += H[a * n + k] * PHt[k * 3 + b];
      S[a * 3 + b] = s + (a == b ? R[a] : 0.0);
    }
  }
  nav_matn_symmetrize(S, 3);
  if (nav_matn_cholesky(L, S, 3) != NAV_OK) {
    set_err(f->msg, sizeof f->msg, "%s update: innovation covariance S is not positive definite", what);
    return NAV_ERR_NUMERIC;
  }
  /* K^T = S^-1 (P H^T)^T: solve with the Cholesky factor, never an explicit inverse. */
  double Kt[3 * NMAX], PHtT[3 * NMAX], Sy[3];
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) PHtT[c * n + i] = PHt[i * 3 + c];
  nav_matn_chol_solve(Kt, L, PHtT, 3, n);
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < 3; ++c) K[i * 3 + c] = Kt[c * n + i];
  nav_matn_chol_solve(Sy, L, y, 3, 1);
  const double nis = y[0] * Sy[0] + y[1] * Sy[1] + y[2] * Sy[2];
  /* A = I - K H; P+ = A P A^T + K R K^T. */
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double s = 0.0;
      for (size_t c = 0; c < 3; ++c) s += K[i * 3 + c] * H[c * n + j];
      A[i * n + j] = (i == j ? 1.0 : 0.0) - s;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += A[i * n + k] * f->P[k * n + j];
      AP[i * n + j] = s;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j <= i; ++j) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += AP[i * n + k] * A[j * n + k];
      for (size_t c = 0; c < 3; ++c) s += K[i * 3 + c] * R[c] * K[j * 3 + c];
      Pn[i * n + j] = s;
      Pn[j * n + i] = s;
    }
  if (!is_pd(Pn, n)) {
    set_err(f->msg, sizeof f->msg, "%s update: updated covariance is not positive definite", what);
    return NAV_ERR_NUMERIC;
  }
  for (size_t i = 0; i < n; ++i) {
    double dx = 0.0;
    for (size_t c = 0; c < 3; ++c) dx += K[i * 3 + c] * y[c];
    f->x[i] += dx;
  }
  memcpy(f->P, Pn, n * n * sizeof *Pn);
  f->nis = nis;
  f->msg[0] = '\0';
  return NAV_OK;
}

/* H of the gyro INS (E6.3/E6.4, 15 states) in the first 15 columns: the rate error dw takes
 * the gyro bias's column, as both are errors of the body rate the INS integrates. */
static void embed_h(const nav_gfg_filter *f, const double *H15, double *H) {
  const size_t n = f->n;
  memset(H, 0, 3 * n * sizeof *H);
  for (size_t c = 0; c < 3; ++c)
    for (size_t j = 0; j < NAV_FILTER_N_CORE; ++j) H[c * n + j] = H15[c * NAV_FILTER_N_CORE + j];
}

nav_status nav_gfg_filter_update_pos(nav_gfg_filter *f, const nav_filter_nav *nav, nav_vec3 z, nav_vec3 r,
                                     nav_vec3 l) {
  if (!f || !nav) return NAV_ERR_INVALID_ARG;
  if (!nav_ok(nav) || !nav_vec3_isfinite(l)) return NAV_ERR_NUMERIC;
  double H15[3 * NAV_FILTER_N_CORE], H[3 * NMAX];
  const nav_filter_layout lay = nav_filter_layout_of(0);
  nav_filter_build_H_pos(H15, &lay, nav, l);
  embed_h(f, H15, H);
  if (f->cfg.gnss_gm) /* z = dr - e_gnss */
    for (size_t c = 0; c < 3; ++c) H[c * f->n + f->idx_gnss + c] = -1.0;
  return update3(f, H, z, r, "GNSS position");
}

nav_status nav_gfg_filter_update_vel(nav_gfg_filter *f, const nav_filter_nav *nav, nav_vec3 z, nav_vec3 r,
                                     nav_vec3 l) {
  if (!f || !nav) return NAV_ERR_INVALID_ARG;
  if (!nav_ok(nav) || !nav_vec3_isfinite(l)) return NAV_ERR_NUMERIC;
  double H15[3 * NAV_FILTER_N_CORE], H[3 * NMAX];
  const nav_filter_layout lay = nav_filter_layout_of(0);
  nav_filter_build_H_vel(H15, &lay, nav, l);
  embed_h(f, H15, H);
  return update3(f, H, z, r, "GNSS velocity");
}

/* ------------------------------------------------------------------ closed loop */

struct nav_gyrofree_gnss {
  nav_gyrofree_gnss_config cfg;
  nav_frame frame;
  nav_gyrofree *gf;
  nav_gfg_filter *kf;
  double beta[6]; /* compensation fed to the array INS */
  bool have_step;
  long updates;
  char err[256];
};

nav_gyrofree_gnss_config nav_gyrofree_gnss_config_from_scene(const nav_scene *sc) {
  nav_gyrofree_gnss_config c;
  memset(&c, 0, sizeof c);
  c.gf = nav_gyrofree_config_default();
  c.gf.ins = nav_ins_config_from_scene(sc);
  if (nav_array_layout_from_scene(&sc->array, &c.gf.array) != NAV_OK) c.gf.array.n_sensors = 0;
  c.filter = nav_gfg_filter_config_default();
  c.filter.array = c.gf.array;
  const nav_array_error_config *a = &sc->array.accel;
  if (a->terms & NAV_IMU_TERM_NOISE) c.filter.vrw_mps_per_sqrt_s = a->vrw_mps_per_sqrt_s;
  if (a->terms & NAV_IMU_TERM_BIAS_TURN_ON) c.filter.bias_const_sd_mps2 = a->bias_turn_on_sd_mps2;
  if (a->terms & NAV_IMU_TERM_BIAS_GM) {
    c.filter.bias_gm = true;
    c.filter.bias_gm_sd_mps2 = a->bias_gm_sd_mps2;
    c.filter.bias_gm_tau_s = a->bias_gm_tau_s;
  }
  /* Floors as the gyro INS filter's (1 mm, 0.1 mm/s, 1 urad) and 1e-6 rad/s for the rate, far
   * below any real error, so P0 stays positive definite for a perfect start. */
  for (int i = 0; i < 3; ++i) {
    nav_vec3_set(&c.filter.pos_sd_m, i, fmax(nav_vec3_get(sc->initial_errors.pos_sd_m, i), 1e-3));
    nav_vec3_set(&c.filter.vel_sd_mps, i, fmax(nav_vec3_get(sc->initial_errors.vel_sd_mps, i), 1e-4));
    nav_vec3_set(&c.filter.att_sd_rad, i, fmax(nav_vec3_get(sc->initial_errors.att_sd_rad, i), 1e-6));
    nav_vec3_set(&c.filter.rate_sd_rps, i, fmax(nav_vec3_get(sc->array.initial_rate_sd_rps, i), 1e-6));
  }
  const nav_gnss_model_config *gm = &sc->gnss.model;
  const double tau_max = fmax(fmax(gm->pos_gm_tau_s.x, gm->pos_gm_tau_s.y), gm->pos_gm_tau_s.z);
  const double sd_max = fmax(fmax(gm->pos_gm_sd_m.x, gm->pos_gm_sd_m.y), gm->pos_gm_sd_m.z);
  if ((gm->terms & NAV_GNSS_TERM_POS_GM) && sd_max > 0.0 && tau_max * gm->update_rate_hz > 10.0) {
    c.filter.gnss_gm = true;
    c.filter.gnss_gm_sd_m = gm->pos_gm_sd_m;
    c.filter.gnss_gm_tau_s = gm->pos_gm_tau_s;
  }
  c.r_ba_b_m = gm->r_ba_b_m;
  c.pos_sd_floor_m = 1e-3;
  c.vel_sd_floor_mps = 1e-3;
  return c;
}

nav_status nav_gyrofree_gnss_create(const nav_gyrofree_gnss_config *cfg, const nav_ins_state *initial,
                                    nav_vec3 w0, nav_gyrofree_gnss **out) {
  if (!cfg || !initial || !out) return NAV_ERR_INVALID_ARG;
  if (cfg->gf.ins.earth_model != NAV_EARTH_WGS84 || !(cfg->pos_sd_floor_m > 0.0) || !(cfg->vel_sd_floor_mps > 0.0) ||
      !nav_vec3_isfinite(cfg->r_ba_b_m))
    return NAV_ERR_INVALID_ARG;
  nav_gyrofree_gnss *x = calloc(1, sizeof *x);
  if (!x) return NAV_ERR_NO_MEMORY;
  x->cfg = *cfg;
  x->cfg.filter.array = cfg->gf.array;
  x->frame.model = NAV_EARTH_WGS84;
  nav_status st = nav_gyrofree_create(&cfg->gf, initial, w0, &x->gf);
  if (st == NAV_OK) st = nav_gfg_filter_create(&x->cfg.filter, &x->kf);
  if (st != NAV_OK) {
    nav_gyrofree_gnss_destroy(x);
    return st;
  }
  *out = x;
  return NAV_OK;
}

void nav_gyrofree_gnss_destroy(nav_gyrofree_gnss *x) {
  if (!x) return;
  nav_gfg_filter_destroy(x->kf);
  nav_gyrofree_destroy(x->gf);
  free(x);
}

const nav_ins_state *nav_gyrofree_gnss_state(const nav_gyrofree_gnss *x) {
  return x ? nav_gyrofree_get_state(x->gf) : NULL;
}
nav_vec3 nav_gyrofree_gnss_rate(const nav_gyrofree_gnss *x) { return x ? nav_gyrofree_rate(x->gf) : nav_vec3_zero(); }
void nav_gyrofree_gnss_compensation(const nav_gyrofree_gnss *x, double beta[6]) {
  if (x && beta) memcpy(beta, x->beta, sizeof x->beta);
}
const nav_imu_increment *nav_gyrofree_gnss_last_increment(const nav_gyrofree_gnss *x) {
  return x ? nav_gyrofree_last_increment(x->gf) : NULL;
}
const nav_gfg_filter *nav_gyrofree_gnss_filter(const nav_gyrofree_gnss *x) { return x ? x->kf : NULL; }
long nav_gyrofree_gnss_updates(const nav_gyrofree_gnss *x) { return x ? x->updates : 0; }
const char *nav_gyrofree_gnss_last_error(const nav_gyrofree_gnss *x) { return x ? x->err : ""; }

/* Linearisation point from the array INS: its NED state, the mean specific force of the last
 * interval and the given rate. */
static nav_filter_nav filter_nav(const nav_gyrofree_gnss *x, nav_vec3 w, nav_local_view *view) {
  const nav_ins_state *s = nav_gyrofree_get_state(x->gf);
  const nav_imu_increment *imu = nav_gyrofree_last_increment(x->gf);
  const nav_local_view v = nav_frame_view(&x->frame, s->r_fb_f_m, s->v_fb_f_mps, s->q_b_f);
  nav_filter_nav n;
  n.lat_rad = v.pos.lat_rad;
  n.h_m = v.pos.h_m;
  n.v_eb_n_mps = v.v_n_mps;
  n.C_b_n = nav_quat_to_dcm(v.q_b_n);
  n.f_ib_b_mps2 = imu->dt_s > 0.0 ? nav_vec3_scale(imu->dv_b_mps, 1.0 / imu->dt_s) : nav_vec3_zero();
  n.w_ib_b_rps = w;
  if (view) *view = v;
  return n;
}

nav_status nav_gyrofree_gnss_step(nav_gyrofree_gnss *x, const nav_array_increment *inc) {
  if (!x || !inc) return NAV_ERR_INVALID_ARG;
  nav_status st = nav_gyrofree_step(x->gf, inc);
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "array INS stopped: %s", nav_gyrofree_last_error(x->gf));
    return st;
  }
  const nav_imu_increment *imu = nav_gyrofree_last_increment(x->gf);
  /* The rate over the interval: its mean, dtheta / dt, as the gyro INS filter uses. */
  const nav_filter_nav n = filter_nav(x, nav_vec3_scale(imu->dtheta_b_rad, 1.0 / imu->dt_s), NULL);
  st = nav_gfg_filter_predict(x->kf, &n, imu->dt_s);
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "filter prediction failed at t = %.6f s: %s", imu->t_s,
             nav_gfg_filter_last_error(x->kf));
    return st;
  }
  x->have_step = true;
  return NAV_OK;
}

nav_status nav_gyrofree_gnss_update(nav_gyrofree_gnss *x, const nav_ins_gnss_fix *fix) {
  if (!x || !fix) return NAV_ERR_INVALID_ARG;
  if (!x->have_step) {
    snprintf(x->err, sizeof x->err, "a GNSS fix before the first array step (t = %.6f s)", fix->t_s);
    return NAV_ERR_STATE;
  }
  /* The array INS knows the rate at the sample instant itself (w_k), which is what the
   * lever-arm velocity needs at the fix epoch. */
  nav_local_view v;
  const nav_filter_nav n = filter_nav(x, nav_gyrofree_rate(x->gf), &v);
  const nav_vec3 l = x->cfg.r_ba_b_m;
  nav_vec3 r_pos, r_vel;
  for (int i = 0; i < 3; ++i) {
    const double sp = fmax(nav_vec3_get(fix->pos_sd_m, i), x->cfg.pos_sd_floor_m);
    const double sv = fmax(nav_vec3_get(fix->vel_sd_mps, i), x->cfg.vel_sd_floor_mps);
    nav_vec3_set(&r_pos, i, sp * sp);
    nav_vec3_set(&r_vel, i, sv * sv);
  }
  nav_status st = nav_gfg_filter_update_pos(x->kf, &n, nav_filter_gnss_pos_residual(v.pos, n.C_b_n, l, fix->pos),
                                            r_pos, l);
  if (st == NAV_OK && fix->has_vel)
    st = nav_gfg_filter_update_vel(x->kf, &n, nav_filter_gnss_vel_residual(&n, l, fix->v_n_mps), r_vel, l);
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "GNSS update failed at t = %.6f s: %s", fix->t_s,
             nav_gfg_filter_last_error(x->kf));
    return st;
  }
  /* Closed-loop feedback (numerics.md 6.5): position, velocity and attitude as for the gyro INS,
   * the rate error into the array INS's rate history, the bias combinations into its
   * compensation; then the first-order reset. */
  const double *xs = nav_gfg_filter_state(x->kf);
  nav_filter_error dx;
  memset(&dx, 0, sizeof dx);
  dx.dr_ned_m = nav_vec3_make(xs[0], xs[1], xs[2]);
  dx.dv_n_mps = nav_vec3_make(xs[3], xs[4], xs[5]);
  dx.phi_rad = nav_vec3_make(xs[6], xs[7], xs[8]);
  nav_filter_ins_state fs;
  memset(&fs, 0, sizeof fs);
  fs.lat_rad = v.pos.lat_rad;
  fs.lon_rad = v.pos.lon_rad;
  fs.h_m = v.pos.h_m;
  fs.v_eb_n_mps = v.v_n_mps;
  fs.q_b_n = v.q_b_n;
  nav_filter_apply_correction(&fs, &fs, &dx);
  const nav_ins_state corrected = nav_ins_gnss_state_ecef(&fs, nav_gyrofree_get_state(x->gf)->t_s);
  double beta[6], dbeta[6];
  nav_gfg_filter_bias_estimate(x->kf, dbeta);
  for (int a = 0; a < 6; ++a) beta[a] = x->beta[a] + dbeta[a];
  /* The compensation first: it is the call that can refuse (non-finite), before anything moved. */
  st = nav_gyrofree_set_compensation(x->gf, beta);
  if (st == NAV_OK) st = nav_gyrofree_correct(x->gf, &corrected, nav_vec3_make(xs[9], xs[10], xs[11]));
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "feedback failed at t = %.6f s: %s", fix->t_s, nav_status_str(st));
    return st;
  }
  memcpy(x->beta, beta, sizeof beta);
  nav_gfg_filter_reset_errors(x->kf);
  x->updates++;
  return NAV_OK;
}
