/**
 * @file ekf.c
 * @brief The error-state Kalman filter object: time update (second-order or Van Loan, optional
 *        covariance decimation), measurement updates (Cholesky of S, Joseph form), checks.
 *
 * Cost notes (n = 15, the hot path at IMU rate): F has 66 non-zeros of 225 and Phi of the
 * second-order form about 120, so every product with Phi runs over its non-zero entries only
 * (row lists rebuilt per step; skipping exact zeros changes no value). The second-order step is
 * fused into one sandwich, P+ = Phi (P + Q/2) Phi^T + Q/2, which is E6.2 rearranged:
 * Phi P Phi^T + (Phi Q Phi^T + Q)/2 with Q = G Q_c G^T T. With Phi = I + FT + (FT)^2/2 (one
 * sparse-times-dense product) a predict costs about 3800 multiply-adds - one dense 15 x 15
 * product is 3375 - plus the Cholesky check (~600). Measured: ~54k instructions, 4-8 us per
 * predict on the development VM. Measurement updates run at GNSS rate and use dense Joseph
 * products (~8 us at n = 15).
 */
#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "navcore/nav_earth.h"

#define NMAX NAV_FILTER_MAX_STATES
#define NN (NMAX * NMAX)
#define MMAX NAV_FILTER_MAX_MEAS
/* nav_van_loan_work_size(NMAX): 2 (2n)^2 for M and E plus 7 (2n)^2 + 2n for the exponential. */
#define VL_WORK (9 * NAV_EXPM_MAX_DIM * NAV_EXPM_MAX_DIM + NAV_EXPM_MAX_DIM)

/* The NED model needs tan(lat) and 1/cos(lat): refuse where nav_ins refuses (numerics.md 4.4
 * rule 4). */
#define MIN_COS_LAT 1e-6

/* Row lists of the non-zero entries of a dense n x n matrix. */
typedef struct sparse_rows {
  size_t start[NMAX + 1];
  size_t col[NN];
  double val[NN];
} sparse_rows;

struct nav_filter {
  nav_filter_config cfg;
  nav_filter_layout lay;
  size_t n;
  double proc_diag[NMAX]; /* -1/T of GM states, 0 otherwise */
  double qc[NMAX];        /* spectral densities (see nav_filter_build_GQG) */

  double x[NMAX];
  double P[NN];

  /* Pending (decimated) covariance step: sums of F dt and G Q_c G^T dt. */
  unsigned pend_count;
  double pend_FT[NN];
  double pend_QT[NN];

  /* Scratch, sized for the largest state; nothing is allocated after create. */
  double F[NN], GQG[NN], FT[NN], QT[NN], Phi[NN], Qd[NN], S[NN], W[NN], Pn[NN], L[NN];
  double H[MMAX * NMAX], K[NMAX * MMAX], Kt[MMAX * NMAX], PHt[NMAX * MMAX];
  double xn[NMAX];
  sparse_rows sp;
  double vl_work[VL_WORK];

  nav_filter_innovation innov;
  char last_error[256];
};

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 2, 3)))
#endif
static void
set_error(nav_filter *f, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(f->last_error, sizeof f->last_error, fmt, ap);
  va_end(ap);
}

/* ---------------------------------------------------------------- create / destroy */

/* Process model of one triad: F diagonal and q per numerics.md 6.2. */
static void triad_process(nav_filter *f, size_t idx, unsigned terms, nav_vec3 gm_sd, nav_vec3 gm_tau,
                          nav_vec3 rw) {
  for (int i = 0; i < 3; ++i) {
    double fd = 0.0, q = 0.0;
    if ((terms & NAV_FILTER_PROC_GM) != 0u) {
      const double sd = nav_vec3_get(gm_sd, i), tau = nav_vec3_get(gm_tau, i);
      fd = -1.0 / tau;
      q += 2.0 * sd * sd / tau;
    }
    if ((terms & NAV_FILTER_PROC_RW) != 0u) {
      const double k = nav_vec3_get(rw, i);
      q += k * k;
    }
    f->proc_diag[idx + (size_t)i] = fd;
    f->qc[idx + (size_t)i] = q;
  }
}

static void set_p0_block(nav_filter *f, size_t idx, nav_vec3 sd) {
  for (int i = 0; i < 3; ++i) {
    const double s = nav_vec3_get(sd, i);
    f->P[(idx + (size_t)i) * f->n + idx + (size_t)i] = s * s;
  }
}

nav_status nav_filter_create(const nav_filter_config *cfg, nav_filter **out) {
  assert(cfg != NULL && out != NULL);
  if (cfg == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  if (nav_filter_config_validate(cfg, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_filter *f = calloc(1, sizeof *f);
  if (f == NULL) return NAV_ERR_NO_MEMORY;
  f->cfg = *cfg;
  f->lay = nav_filter_layout_of(cfg->states);
  f->n = f->lay.n_states;

  for (int i = 0; i < 3; ++i) {
    const double na = nav_vec3_get(cfg->accel_vrw_mps_per_sqrt_s, i);
    const double ng = nav_vec3_get(cfg->gyro_arw_rad_per_sqrt_s, i);
    f->qc[NAV_FILTER_IDX_DV + (size_t)i] = na * na;  /* VRW: q_a = N_a^2 [m^2/s^3] */
    f->qc[NAV_FILTER_IDX_PHI + (size_t)i] = ng * ng; /* ARW: q_g = N_g^2 [rad^2/s] */
  }
  triad_process(f, NAV_FILTER_IDX_BG, cfg->gyro_bias_terms, cfg->gyro_bias_gm_sd_rps, cfg->gyro_bias_gm_tau_s,
                cfg->gyro_bias_rw_rps_per_sqrt_s);
  triad_process(f, NAV_FILTER_IDX_BA, cfg->accel_bias_terms, cfg->accel_bias_gm_sd_mps2,
                cfg->accel_bias_gm_tau_s, cfg->accel_bias_rw_mps2_per_sqrt_s);
  if (f->lay.has_scale_factors) {
    triad_process(f, NAV_FILTER_IDX_SG, cfg->gyro_sf_terms, cfg->gyro_sf_gm_sd, cfg->gyro_sf_gm_tau_s,
                  cfg->gyro_sf_rw_per_sqrt_s);
    triad_process(f, NAV_FILTER_IDX_SA, cfg->accel_sf_terms, cfg->accel_sf_gm_sd, cfg->accel_sf_gm_tau_s,
                  cfg->accel_sf_rw_per_sqrt_s);
  }
  if (f->lay.has_gnss_pos_gm)
    triad_process(f, f->lay.idx_gnss_pos, NAV_FILTER_PROC_GM, cfg->gnss_pos_gm_sd_m, cfg->gnss_pos_gm_tau_s,
                  nav_vec3_zero());

  set_p0_block(f, NAV_FILTER_IDX_DR, cfg->init.pos_sd_m);
  set_p0_block(f, NAV_FILTER_IDX_DV, cfg->init.vel_sd_mps);
  set_p0_block(f, NAV_FILTER_IDX_PHI, cfg->init.att_sd_rad);
  set_p0_block(f, NAV_FILTER_IDX_BG, cfg->init.gyro_bias_sd_rps);
  set_p0_block(f, NAV_FILTER_IDX_BA, cfg->init.accel_bias_sd_mps2);
  if (f->lay.has_scale_factors) {
    set_p0_block(f, NAV_FILTER_IDX_SG, cfg->init.gyro_sf_sd);
    set_p0_block(f, NAV_FILTER_IDX_SA, cfg->init.accel_sf_sd);
  }
  if (f->lay.has_gnss_pos_gm) set_p0_block(f, f->lay.idx_gnss_pos, cfg->init.gnss_pos_sd_m);
  f->innov.m = 0;
  f->last_error[0] = '\0';
  *out = f;
  return NAV_OK;
}

void nav_filter_destroy(nav_filter *f) {
  free(f);
}

nav_filter_layout nav_filter_get_layout(const nav_filter *f) {
  assert(f != NULL);
  if (f == NULL) return nav_filter_layout_of(0u);
  return f->lay;
}

/* ---------------------------------------------------------------- sparse helpers */

/* y += a x over n contiguous elements, unrolled by four so that GCC's -O2 SLP vectoriser packs
 * the body (its -O2 cost model skips loops of unknown trip count). Each element is still
 * computed as y_c + a x_c, so the values are exactly those of the plain loop. */
static void axpy(double *restrict y, double a, const double *restrict x, size_t n) {
  size_t c = 0;
  for (; c + 4 <= n; c += 4) {
    y[c] += a * x[c];
    y[c + 1] += a * x[c + 1];
    y[c + 2] += a * x[c + 2];
    y[c + 3] += a * x[c + 3];
  }
  for (; c < n; ++c)
    y[c] += a * x[c];
}

static void build_rows(sparse_rows *sp, const double *a, size_t n) {
  size_t k = 0;
  for (size_t i = 0; i < n; ++i) {
    sp->start[i] = k;
    for (size_t j = 0; j < n; ++j)
      if (a[i * n + j] != 0.0) {
        sp->col[k] = j;
        sp->val[k] = a[i * n + j];
        ++k;
      }
  }
  sp->start[n] = k;
}

/* out = A S A^T for a symmetric S, with A given by its row lists; W is n x n scratch. The upper
 * triangle is computed and mirrored, so out is exactly symmetric. */
static void sparse_sandwich(double *out, const sparse_rows *sp, const double *s, size_t n, double *w) {
  for (size_t i = 0; i < n; ++i) {
    double *wi = w + i * n;
    for (size_t c = 0; c < n; ++c)
      wi[c] = 0.0;
    for (size_t p = sp->start[i]; p < sp->start[i + 1]; ++p)
      axpy(wi, sp->val[p], s + sp->col[p] * n, n);
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      double sum = 0.0;
      for (size_t p = sp->start[j]; p < sp->start[j + 1]; ++p)
        sum += w[i * n + sp->col[p]] * sp->val[p];
      out[i * n + j] = sum;
      out[j * n + i] = sum;
    }
}

/* y = A x with A given by its row lists. */
static void sparse_mul_vec(double *y, const sparse_rows *sp, const double *x, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    double sum = 0.0;
    for (size_t p = sp->start[i]; p < sp->start[i + 1]; ++p)
      sum += sp->val[p] * x[sp->col[p]];
    y[i] = sum;
  }
}

/* Check a covariance candidate: every entry finite, Cholesky succeeds (which implies a
 * positive diagonal; numerics.md 6.5). On failure the message names the first leading block
 * that is not positive definite (found by factorising growing blocks: failure path only). */
static nav_status check_cov(nav_filter *f, const double *p, const char *what) {
  const size_t n = f->n;
  for (size_t i = 0; i < n * n; ++i)
    if (!isfinite(p[i])) {
      set_error(f, "%s: P(%zu,%zu) = %g is not finite", what, i / n, i % n, p[i]);
      return NAV_ERR_NUMERIC;
    }
  if (nav_matn_cholesky(f->L, p, n) == NAV_OK) return NAV_OK;
  size_t k = 1;
  for (; k <= n; ++k) {
    for (size_t i = 0; i < k; ++i)
      for (size_t j = 0; j < k; ++j)
        f->W[i * k + j] = p[i * n + j];
    if (nav_matn_cholesky(f->L, f->W, k) != NAV_OK) break;
  }
  const size_t bad = k <= n ? k - 1 : n - 1;
  set_error(f,
            "%s: P is not positive definite: the Cholesky factorisation fails at state %zu (P(%zu,%zu) = %g)",
            what, bad, bad, bad, p[bad * n + bad]);
  return NAV_ERR_NUMERIC;
}

/* ---------------------------------------------------------------- time update */

/* One covariance step over the integrated FT = sum F dt and QT = sum G Q_c G^T dt. Commits x and
 * P only on success. */
static nav_status cov_step(nav_filter *f, const double *FT, const double *QT) {
  const size_t n = f->n;
  if (f->cfg.discretisation == NAV_FILTER_DISC_VAN_LOAN) {
    const nav_status st = nav_filter_van_loan(f->Phi, f->Qd, FT, QT, n, f->vl_work, NULL);
    if (st != NAV_OK) {
      set_error(f, "predict: Van Loan matrix exponential failed (%s)", nav_status_str(st));
      return st == NAV_ERR_INVALID_ARG ? NAV_ERR_INVALID_ARG : NAV_ERR_NUMERIC;
    }
    build_rows(&f->sp, f->Phi, n);
    sparse_sandwich(f->Pn, &f->sp, f->P, n, f->W);
    for (size_t i = 0; i < n * n; ++i)
      f->Pn[i] += f->Qd[i];
  } else {
    /* E6.2: Phi = I + FT + (FT)^2/2 with the square over the non-zeros of FT. */
    build_rows(&f->sp, FT, n);
    for (size_t i = 0; i < n; ++i) {
      double *phi_i = f->Phi + i * n;
      for (size_t c = 0; c < n; ++c)
        phi_i[c] = 0.0;
      for (size_t p = f->sp.start[i]; p < f->sp.start[i + 1]; ++p)
        axpy(phi_i, 0.5 * f->sp.val[p], FT + f->sp.col[p] * n, n);
      axpy(phi_i, 1.0, FT + i * n, n);
      phi_i[i] += 1.0;
    }
    build_rows(&f->sp, f->Phi, n);
    /* Fused E6.2: P+ = Phi (P + Q/2) Phi^T + Q/2. */
    for (size_t i = 0; i < n * n; ++i) {
      f->Qd[i] = 0.5 * QT[i];
      f->S[i] = f->P[i] + f->Qd[i];
    }
    sparse_sandwich(f->Pn, &f->sp, f->S, n, f->W);
    for (size_t i = 0; i < n * n; ++i)
      f->Pn[i] += f->Qd[i];
  }
  nav_matn_symmetrize(f->Pn, n);
  const nav_status st = check_cov(f, f->Pn, "predict");
  if (st != NAV_OK) return st;
  sparse_mul_vec(f->xn, &f->sp, f->x, n);
  memcpy(f->P, f->Pn, n * n * sizeof *f->P);
  memcpy(f->x, f->xn, n * sizeof *f->x);
  return NAV_OK;
}

static bool mat3_isfinite(const nav_mat3 *m) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (!isfinite(m->m[i][j])) return false;
  return true;
}

static nav_status check_nav(nav_filter *f, const nav_filter_nav *nav, const char *what) {
  if (!isfinite(nav->lat_rad) || !isfinite(nav->h_m) || !nav_vec3_isfinite(nav->v_eb_n_mps) ||
      !mat3_isfinite(&nav->C_b_n) || !nav_vec3_isfinite(nav->f_ib_b_mps2) ||
      !nav_vec3_isfinite(nav->w_ib_b_rps)) {
    set_error(f, "%s: the navigation state (lat, h, v, C_b_n, f_b or w_ib_b) is not finite", what);
    return NAV_ERR_NUMERIC;
  }
  if (!(fabs(cos(nav->lat_rad)) >= MIN_COS_LAT)) {
    set_error(
        f, "%s: latitude %.17g rad is within cos(lat) < %g of a pole; the NED error model is singular there",
        what, nav->lat_rad, MIN_COS_LAT);
    return NAV_ERR_OUT_OF_RANGE;
  }
  return NAV_OK;
}

nav_status nav_filter_predict(nav_filter *f, const nav_filter_nav *nav, double dt_s) {
  assert(f != NULL && nav != NULL);
  if (f == NULL || nav == NULL) return NAV_ERR_INVALID_ARG;
  if (isnan(dt_s) || isinf(dt_s)) {
    set_error(f, "predict: dt_s = %g is not finite", dt_s);
    return NAV_ERR_NUMERIC;
  }
  if (!(dt_s > 0.0)) {
    set_error(f, "predict: dt_s = %g must be > 0", dt_s);
    return NAV_ERR_INVALID_ARG;
  }
  nav_status st = check_nav(f, nav, "predict");
  if (st != NAV_OK) return st;

  const size_t n = f->n;
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(nav->lat_rad, nav->h_m);
  nav_filter_build_F(f->F, &f->lay, nav, &earth, f->proc_diag);
  nav_filter_build_GQG(f->GQG, &f->lay, nav->C_b_n, f->qc);

  const bool pending = f->pend_count > 0;
  if (f->pend_count + 1u < f->cfg.cov_decimation) {
    /* Accumulate only (n^2 additions); the covariance step comes later. */
    for (size_t i = 0; i < n * n; ++i) {
      f->pend_FT[i] = (pending ? f->pend_FT[i] : 0.0) + f->F[i] * dt_s;
      f->pend_QT[i] = (pending ? f->pend_QT[i] : 0.0) + f->GQG[i] * dt_s;
    }
    f->pend_count++;
    return NAV_OK;
  }
  /* Last step of the covariance interval: totals into FT/QT so that a failure leaves the pending
   * sums untouched. */
  for (size_t i = 0; i < n * n; ++i) {
    f->FT[i] = (pending ? f->pend_FT[i] : 0.0) + f->F[i] * dt_s;
    f->QT[i] = (pending ? f->pend_QT[i] : 0.0) + f->GQG[i] * dt_s;
  }
  st = cov_step(f, f->FT, f->QT);
  if (st == NAV_OK) f->pend_count = 0;
  return st;
}

nav_status nav_filter_flush(nav_filter *f) {
  assert(f != NULL);
  if (f == NULL) return NAV_ERR_INVALID_ARG;
  if (f->pend_count == 0) return NAV_OK;
  const nav_status st = cov_step(f, f->pend_FT, f->pend_QT);
  if (st == NAV_OK) f->pend_count = 0;
  return st;
}

/* ---------------------------------------------------------------- measurement update */

/* Update with an m x n H, m measurements z and the m x m noise R (already checked finite and
 * positive definite). numerics.md 6.5. */
static nav_status do_update(nav_filter *f, size_t m, const double *H, const double *z, const double *R,
                            const char *what) {
  const size_t n = f->n;
  for (size_t i = 0; i < m * n; ++i)
    if (!isfinite(H[i])) {
      set_error(f, "%s: H is not finite", what);
      return NAV_ERR_NUMERIC;
    }
  for (size_t i = 0; i < m; ++i)
    if (!isfinite(z[i])) {
      set_error(f, "%s: measurement z[%zu] = %g is not finite", what, i, z[i]);
      return NAV_ERR_NUMERIC;
    }
  /* Inputs are valid: bring P to the current epoch (decimated propagation), then update. */
  nav_status st = nav_filter_flush(f);
  if (st != NAV_OK) return st;

  /* Innovation y = z - H x_minus (x_minus = 0 in closed loop except the GNSS states). */
  double y[MMAX], S[MMAX * MMAX], Ls[MMAX * MMAX], u[MMAX];
  for (size_t r = 0; r < m; ++r) {
    double hx = 0.0;
    for (size_t j = 0; j < n; ++j)
      hx += H[r * n + j] * f->x[j];
    y[r] = z[r] - hx;
  }
  /* P H^T (n x m), skipping the zeros of H (most of it). */
  for (size_t i = 0; i < n; ++i)
    for (size_t r = 0; r < m; ++r) {
      double sum = 0.0;
      for (size_t j = 0; j < n; ++j) {
        const double h = H[r * n + j];
        if (h != 0.0) sum += f->P[i * n + j] * h;
      }
      f->PHt[i * m + r] = sum;
    }
  /* S = H P H^T + R, symmetrised. */
  for (size_t r = 0; r < m; ++r)
    for (size_t c = 0; c < m; ++c) {
      double sum = 0.0;
      for (size_t j = 0; j < n; ++j)
        sum += H[r * n + j] * f->PHt[j * m + c];
      S[r * m + c] = sum + R[r * m + c];
    }
  nav_matn_symmetrize(S, m);
  if (nav_matn_cholesky(Ls, S, m) != NAV_OK) {
    set_error(f, "%s: innovation covariance S = H P H^T + R is not positive definite", what);
    return NAV_ERR_NUMERIC;
  }
  /* K^T = S^-1 (P H^T)^T by the Cholesky factor (never an explicit inverse). */
  for (size_t r = 0; r < m; ++r)
    for (size_t j = 0; j < n; ++j)
      f->Kt[r * n + j] = f->PHt[j * m + r];
  nav_matn_chol_solve(f->Kt, Ls, f->Kt, m, n);
  for (size_t j = 0; j < n; ++j)
    for (size_t r = 0; r < m; ++r)
      f->K[j * m + r] = f->Kt[r * n + j];

  /* x+ = x- + K y */
  for (size_t j = 0; j < n; ++j) {
    double sum = f->x[j];
    for (size_t r = 0; r < m; ++r)
      sum += f->K[j * m + r] * y[r];
    f->xn[j] = sum;
  }
  /* Joseph form (E6.5): P+ = (I - K H) P (I - K H)^T + K R K^T. A = I - K H goes to Phi. */
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double sum = 0.0;
      for (size_t r = 0; r < m; ++r)
        sum += f->K[i * m + r] * H[r * n + j];
      f->Phi[i * n + j] = (i == j ? 1.0 : 0.0) - sum;
    }
  nav_matn_sandwich(f->Pn, f->Phi, f->P, n, n, f->W);
  /* K R K^T: W = K R (n x m), then the upper triangle of W K^T mirrored. */
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < m; ++c) {
      double sum = 0.0;
      for (size_t r = 0; r < m; ++r)
        sum += f->K[i * m + r] * R[r * m + c];
      f->W[i * m + c] = sum;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      double sum = 0.0;
      for (size_t c = 0; c < m; ++c)
        sum += f->W[i * m + c] * f->K[j * m + c];
      f->Pn[i * n + j] += sum;
      if (j != i) f->Pn[j * n + i] += sum;
    }
  nav_matn_symmetrize(f->Pn, n);
  for (size_t j = 0; j < n; ++j)
    if (!isfinite(f->xn[j])) {
      set_error(f, "%s: updated state x[%zu] is not finite", what, j);
      return NAV_ERR_NUMERIC;
    }
  st = check_cov(f, f->Pn, what);
  if (st != NAV_OK) return st;

  /* Commit, and keep y, S and the NIS y^T S^-1 y for consistency tests (T6.5). */
  memcpy(f->P, f->Pn, n * n * sizeof *f->P);
  memcpy(f->x, f->xn, n * sizeof *f->x);
  nav_matn_chol_solve(u, Ls, y, m, 1);
  double nis = 0.0;
  for (size_t r = 0; r < m; ++r)
    nis += y[r] * u[r];
  f->innov.m = m;
  memcpy(f->innov.y, y, m * sizeof *y);
  memcpy(f->innov.S, S, m * m * sizeof *S);
  f->innov.nis = nis;
  return NAV_OK;
}

/* R = diag(r) from an optional caller vector, else the squared default sigmas. */
static nav_status diag_r(nav_filter *f, double *R, const nav_vec3 *r_diag, nav_vec3 default_sd,
                         const char *what) {
  const nav_vec3 r = r_diag != NULL ? *r_diag
                                    : nav_vec3_make(default_sd.x * default_sd.x, default_sd.y * default_sd.y,
                                                    default_sd.z * default_sd.z);
  memset(R, 0, 9 * sizeof *R);
  for (int i = 0; i < 3; ++i) {
    const double v = nav_vec3_get(r, i);
    if (isnan(v) || isinf(v)) {
      set_error(f, "%s: R[%d] = %g is not finite", what, i, v);
      return NAV_ERR_NUMERIC;
    }
    if (!(v > 0.0)) {
      set_error(f, "%s: R[%d] = %g must be > 0", what, i, v);
      return NAV_ERR_INVALID_ARG;
    }
    R[i * 3 + i] = v;
  }
  return NAV_OK;
}

static nav_status gnss_update(nav_filter *f, const nav_filter_nav *nav, nav_vec3 z, const nav_vec3 *r_diag,
                              nav_vec3 l_ba_b_m, bool velocity) {
  const char *what = velocity ? "update_gnss_vel" : "update_gnss_pos";
  nav_status st = check_nav(f, nav, what);
  if (st != NAV_OK) return st;
  if (!nav_vec3_isfinite(l_ba_b_m)) {
    set_error(f, "%s: lever arm is not finite", what);
    return NAV_ERR_NUMERIC;
  }
  double R[9], zz[3] = {z.x, z.y, z.z};
  st = diag_r(f, R, r_diag, velocity ? f->cfg.gnss_vel_sd_mps : f->cfg.gnss_pos_sd_m, what);
  if (st != NAV_OK) return st;
  if (velocity)
    nav_filter_build_H_vel(f->H, &f->lay, nav, l_ba_b_m);
  else
    nav_filter_build_H_pos(f->H, &f->lay, nav, l_ba_b_m);
  return do_update(f, 3, f->H, zz, R, what);
}

nav_status nav_filter_update_gnss_pos(nav_filter *f, const nav_filter_nav *nav, nav_vec3 z_pos_ned_m,
                                      const nav_vec3 *r_diag_m2, nav_vec3 l_ba_b_m) {
  assert(f != NULL && nav != NULL);
  if (f == NULL || nav == NULL) return NAV_ERR_INVALID_ARG;
  return gnss_update(f, nav, z_pos_ned_m, r_diag_m2, l_ba_b_m, false);
}

nav_status nav_filter_update_gnss_vel(nav_filter *f, const nav_filter_nav *nav, nav_vec3 z_vel_ned_mps,
                                      const nav_vec3 *r_diag_m2s2, nav_vec3 l_ba_b_m) {
  assert(f != NULL && nav != NULL);
  if (f == NULL || nav == NULL) return NAV_ERR_INVALID_ARG;
  return gnss_update(f, nav, z_vel_ned_mps, r_diag_m2s2, l_ba_b_m, true);
}

nav_status nav_filter_update_linear(nav_filter *f, size_t m, const double *H, const double *z,
                                    const double *R) {
  assert(f != NULL && H != NULL && z != NULL && R != NULL);
  if (f == NULL || H == NULL || z == NULL || R == NULL) return NAV_ERR_INVALID_ARG;
  if (m < 1 || m > MMAX) {
    set_error(f, "update_linear: m = %zu outside 1..%d", m, MMAX);
    return NAV_ERR_INVALID_ARG;
  }
  for (size_t i = 0; i < m * m; ++i)
    if (!isfinite(R[i])) {
      set_error(f, "update_linear: R is not finite");
      return NAV_ERR_NUMERIC;
    }
  double Lr[MMAX * MMAX];
  if (nav_matn_cholesky(Lr, R, m) != NAV_OK) {
    set_error(f, "update_linear: R is not positive definite");
    return NAV_ERR_INVALID_ARG;
  }
  return do_update(f, m, H, z, R, "update_linear");
}

/* ---------------------------------------------------------------- state access */

nav_status nav_filter_reset_errors(nav_filter *f) {
  assert(f != NULL);
  if (f == NULL) return NAV_ERR_INVALID_ARG;
  const size_t end = f->lay.has_gnss_pos_gm ? f->lay.idx_gnss_pos : f->n;
  for (size_t i = 0; i < end; ++i)
    f->x[i] = 0.0;
  return NAV_OK;
}

nav_status nav_filter_set_cov(nav_filter *f, const double *P) {
  assert(f != NULL && P != NULL);
  if (f == NULL || P == NULL) return NAV_ERR_INVALID_ARG;
  const size_t n = f->n;
  for (size_t i = 0; i < n * n; ++i)
    if (!isfinite(P[i])) {
      set_error(f, "set_cov: P(%zu,%zu) = %g is not finite", i / n, i % n, P[i]);
      return NAV_ERR_NUMERIC;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const double a = P[i * n + j], b = P[j * n + i];
      if (!(fabs(a - b) <= 1e-12 * fmax(fabs(a), fabs(b)))) {
        set_error(f, "set_cov: P is not symmetric at (%zu,%zu): %.17g vs %.17g", i, j, a, b);
        return NAV_ERR_INVALID_ARG;
      }
    }
  nav_status st = nav_filter_flush(f);
  if (st != NAV_OK) return st;
  memcpy(f->Pn, P, n * n * sizeof *P);
  nav_matn_symmetrize(f->Pn, n);
  st = check_cov(f, f->Pn, "set_cov");
  if (st != NAV_OK) return st;
  memcpy(f->P, f->Pn, n * n * sizeof *P);
  return NAV_OK;
}

const double *nav_filter_get_state(const nav_filter *f) {
  assert(f != NULL);
  return f != NULL ? f->x : NULL;
}

const double *nav_filter_get_cov(const nav_filter *f) {
  assert(f != NULL);
  return f != NULL ? f->P : NULL;
}

double *nav_filter_internal_state(nav_filter *f) {
  return f != NULL ? f->x : NULL;
}

static nav_vec3 block3(const double *x, size_t idx) {
  return nav_vec3_make(x[idx], x[idx + 1], x[idx + 2]);
}

nav_status nav_filter_get_error(const nav_filter *f, nav_filter_error *out) {
  assert(f != NULL && out != NULL);
  if (f == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  nav_filter_error e;
  e.dr_ned_m = block3(f->x, NAV_FILTER_IDX_DR);
  e.dv_n_mps = block3(f->x, NAV_FILTER_IDX_DV);
  e.phi_rad = block3(f->x, NAV_FILTER_IDX_PHI);
  e.b_g_rps = block3(f->x, NAV_FILTER_IDX_BG);
  e.b_a_mps2 = block3(f->x, NAV_FILTER_IDX_BA);
  e.s_g = f->lay.has_scale_factors ? block3(f->x, NAV_FILTER_IDX_SG) : nav_vec3_zero();
  e.s_a = f->lay.has_scale_factors ? block3(f->x, NAV_FILTER_IDX_SA) : nav_vec3_zero();
  e.gnss_pos_m = f->lay.has_gnss_pos_gm ? block3(f->x, f->lay.idx_gnss_pos) : nav_vec3_zero();
  *out = e;
  return NAV_OK;
}

const nav_filter_innovation *nav_filter_last_innovation(const nav_filter *f) {
  assert(f != NULL);
  return f != NULL ? &f->innov : NULL;
}

const char *nav_filter_last_error(const nav_filter *f) {
  return f != NULL ? f->last_error : "";
}
