/*
 * Consider states of a covariance analysis, propagated as a sensitivity beside the navigation
 * filter (consider_internal.h; docs/estimate-speed.md derives it). The budget's total model
 * (nav_budget.h) is the navigation filter plus the truth's scale factors as random constants the
 * gains never touch; its covariance of the navigation states is P + S Pss S^T, where P is the
 * navigation filter's own covariance and S the sensitivity below. Computing it this way costs a
 * few n x 6 products per step instead of a second filter of n + 6 states and a third one for
 * the gains.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "sim/consider_internal.h"

#define NMAX NAV_FILTER_MAX_STATES
#define NS 6  /* consider states: gyro scale factors x, y, z, then accelerometer ones */
#define LDS 8 /* row stride of S and its products: two zero columns, so the rows vectorise */
#if defined(__GNUC__) && !defined(__clang__)
#define UNROLL_LDS _Pragma("GCC unroll 8")
#else
#define UNROLL_LDS
#endif
/* As the filter's kernels (ekf.c): also an AVX2 clone picked at load time on x86-64, the same
 * elementwise multiplies and adds (no FMA), so the same values on every machine. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__SANITIZE_THREAD__)
#define CONSIDER_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define CONSIDER_CLONES
#endif

static nav_vec3 sq3(nav_vec3 v) { return nav_vec3_make(v.x * v.x, v.y * v.y, v.z * v.z); }
static double vmax3(nav_vec3 v) { return fmax(fmax(v.x, v.y), v.z); }

nav_vec3 nav_consider_sf_var(const nav_scene *sc, bool accel) {
  const unsigned terms = accel ? sc->imu.model.accel.terms : sc->imu.model.gyro.terms;
  if (!(terms & NAV_IMU_TERM_SCALE_FACTOR)) return nav_vec3_zero();
  return accel ? nav_vec3_add(sq3(sc->imu.model.accel.scale_factor_sd), sq3(sc->imu.model.accel.scale_factor_fixed))
               : nav_vec3_add(sq3(sc->imu.model.gyro.scale_factor_sd), sq3(sc->imu.model.gyro.scale_factor_fixed));
}

bool nav_consider_config(const nav_scene *sc, const nav_filter_config *cr, nav_filter_config *c) {
  *c = *cr;
  const nav_vec3 vg = nav_consider_sf_var(sc, false), va = nav_consider_sf_var(sc, true);
  const bool consider = (vmax3(vg) > 0.0 || vmax3(va) > 0.0) && !(cr->states & NAV_FILTER_STATE_SCALE_FACTORS);
  if (!consider) return false;
  c->states |= NAV_FILTER_STATE_SCALE_FACTORS;
  c->gyro_sf_terms = 0u; /* random constants */
  c->accel_sf_terms = 0u;
  for (int i = 0; i < 3; ++i) {
    nav_vec3_set(&c->init.gyro_sf_sd, i, fmax(sqrt(nav_vec3_get(vg, i)), 1e-9));
    nav_vec3_set(&c->init.accel_sf_sd, i, fmax(sqrt(nav_vec3_get(va, i)), 1e-9));
  }
  return true;
}

/* The sums of a (decimated) covariance interval, as the filter keeps them (ekf.c struct
 * pending): the blocks of F linear in C_b_n exactly, the others at the interval means. */
typedef struct interval {
  unsigned count;
  double T, lat_T, h_T;
  double last_lat, last_h;
  nav_vec3 last_v, v_T, fn_T;
  nav_mat3 C_T, Cf_T, Cw_T;
} interval;

struct nav_consider {
  nav_filter_layout lay_r, lay_c; /* the navigation filter's layout and the consider one */
  size_t nr;                      /* navigation states */
  size_t col[NMAX];               /* column of navigation state i in the consider layout */
  unsigned decimation;
  double proc_diag[NMAX]; /* F diagonal of the navigation filter's sensor blocks */
  double pss[NS];         /* variances of the consider states (constant: never updated) */
  double S[NMAX * LDS];   /* sensitivity of the navigation states to the consider states */
  interval iv;
  double F[NMAX * NMAX]; /* the navigation filter's F (nr x nr) */
  double A[NMAX * NMAX]; /* A_xx = F T (nr x nr); zero outside its pattern */
  /* The structural non-zeros of F (fixed by the layout), row by row: entries nz[row[i] ..
   * row[i + 1]) are the indices i nr + j of row i. */
  size_t nz[NMAX * NMAX], row[NMAX + 1], n_nz;
  double Hc[3 * NMAX];
};

/* The structural non-zeros of the navigation filter's F: F at a generic point (every term
 * non-zero) with every GM diagonal set, and the blocks step() writes from the interval sums. */
static void structure(nav_consider *k) {
  const size_t nr = k->nr;
  nav_filter_nav g;
  g.lat_rad = 0.61;
  g.h_m = 123.0;
  g.v_eb_n_mps = nav_vec3_make(3.1, -4.2, 0.53);
  const nav_euler e = {0.11, -0.23, 0.37};
  g.C_b_n = nav_euler_to_dcm(e);
  g.f_ib_b_mps2 = nav_vec3_make(0.31, -0.22, -9.7);
  g.w_ib_b_rps = nav_vec3_make(0.011, -0.027, 0.033);
  double pd[NMAX];
  for (size_t i = 0; i < NMAX; ++i) pd[i] = -1.0;
  const nav_filter_earth_terms et = nav_filter_earth_terms_wgs84(g.lat_rad, g.h_m);
  nav_filter_build_F(k->F, &k->lay_r, &g, &et, pd);
  k->n_nz = 0;
  for (size_t i = 0; i < nr; ++i) {
    k->row[i] = k->n_nz;
    for (size_t j = 0; j < nr; ++j) {
      const bool blk = (i >= NAV_FILTER_IDX_DV && i < NAV_FILTER_IDX_DV + 3 &&
                        ((j >= NAV_FILTER_IDX_PHI && j < NAV_FILTER_IDX_PHI + 3) ||
                         (j >= NAV_FILTER_IDX_BA && j < NAV_FILTER_IDX_BA + 3))) ||
                       (i >= NAV_FILTER_IDX_PHI && i < NAV_FILTER_IDX_PHI + 3 && j >= NAV_FILTER_IDX_BG &&
                        j < NAV_FILTER_IDX_BG + 3);
      if (blk || k->F[i * nr + j] != 0.0) k->nz[k->n_nz++] = i * nr + j;
    }
  }
  k->row[nr] = k->n_nz;
}

nav_status nav_consider_create(const nav_scene *sc, const nav_filter_config *cr, nav_consider **out) {
  *out = NULL;
  nav_filter_config c;
  if (!nav_consider_config(sc, cr, &c)) return NAV_OK;
  if (cr->discretisation != NAV_FILTER_DISC_SECOND_ORDER) return NAV_ERR_INVALID_ARG;
  nav_consider *k = calloc(1, sizeof *k);
  if (!k) return NAV_ERR_NO_MEMORY;
  k->lay_r = nav_filter_layout_of(cr->states);
  k->lay_c = nav_filter_layout_of(c.states);
  if (k->lay_r.has_rx_clock || k->lay_r.has_isb || !k->lay_c.has_scale_factors) {
    free(k);
    return NAV_ERR_INVALID_ARG;
  }
  k->nr = k->lay_r.n_states;
  for (size_t i = 0; i < k->nr; ++i)
    k->col[i] = (k->lay_r.has_gnss_pos_gm && i >= k->lay_r.idx_gnss_pos)
                    ? k->lay_c.idx_gnss_pos + (i - k->lay_r.idx_gnss_pos)
                    : i;
  double qc[NMAX];
  memset(qc, 0, sizeof qc);
  nav_filter_process_model(cr, &k->lay_r, k->proc_diag, qc);
  structure(k);
  for (int i = 0; i < 3; ++i) {
    k->pss[i] = nav_vec3_get(c.init.gyro_sf_sd, i) * nav_vec3_get(c.init.gyro_sf_sd, i);
    k->pss[3 + i] = nav_vec3_get(c.init.accel_sf_sd, i) * nav_vec3_get(c.init.accel_sf_sd, i);
  }
  k->decimation = cr->cov_decimation > 1 ? cr->cov_decimation : 1u;
  *out = k;
  return NAV_OK;
}

void nav_consider_destroy(nav_consider *c) { free(c); }

static nav_mat3 mat3_axpy(nav_mat3 y, double a, nav_mat3 x) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      y.m[i][j] += a * x.m[i][j];
  return y;
}

static void interval_add(interval *iv, const nav_filter_nav *nav, double dt) {
  const nav_mat3 C = nav->C_b_n;
  iv->count++;
  iv->T += dt;
  iv->lat_T += nav->lat_rad * dt;
  iv->h_T += nav->h_m * dt;
  iv->v_T = nav_vec3_axpy(iv->v_T, dt, nav->v_eb_n_mps);
  iv->last_lat = nav->lat_rad;
  iv->last_h = nav->h_m;
  iv->last_v = nav->v_eb_n_mps;
  iv->fn_T = nav_vec3_axpy(iv->fn_T, dt, nav_mat3_mul_vec(C, nav->f_ib_b_mps2));
  iv->C_T = mat3_axpy(iv->C_T, dt, C);
  for (int i = 0; i < 3; ++i) {
    iv->Cf_T.m[i][0] += C.m[i][0] * nav->f_ib_b_mps2.x * dt;
    iv->Cf_T.m[i][1] += C.m[i][1] * nav->f_ib_b_mps2.y * dt;
    iv->Cf_T.m[i][2] += C.m[i][2] * nav->f_ib_b_mps2.z * dt;
    iv->Cw_T.m[i][0] += C.m[i][0] * nav->w_ib_b_rps.x * dt;
    iv->Cw_T.m[i][1] += C.m[i][1] * nav->w_ib_b_rps.y * dt;
    iv->Cw_T.m[i][2] += C.m[i][2] * nav->w_ib_b_rps.z * dt;
  }
}

/* A 3 x 3 block b (times s) into the nr x w matrix a at (r, c). */
static void put_block(double *a, size_t w, size_t r, size_t c, nav_mat3 b, double s) {
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      a[(r + i) * w + c + j] = s * b.m[i][j];
}

/* One covariance step over the pending interval: S <- S + U + A_xx U / 2, U = A_xx S + A_xs.
 * A_xx is the navigation filter's F T (its layout's F at the interval means, with the blocks
 * linear in C_b_n from the interval sums, as ekf.c pending_integrals); A_xs has only the blocks
 * C diag(f) T (dv by s_a) and -C diag(w) T (phi by s_g), the interval sums Cf_T and Cw_T. */
CONSIDER_CLONES static void step(nav_consider *k) {
  const interval *iv = &k->iv;
  const size_t nr = k->nr;
  const double T = iv->T;
  nav_filter_nav m;
  memset(&m, 0, sizeof m);
  if (iv->count == 1) {
    m.lat_rad = iv->last_lat;
    m.h_m = iv->last_h;
    m.v_eb_n_mps = iv->last_v;
  } else {
    m.lat_rad = iv->lat_T / T;
    m.h_m = iv->h_T / T;
    m.v_eb_n_mps = nav_vec3_scale(iv->v_T, 1.0 / T);
  }
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(m.lat_rad, m.h_m);
  nav_filter_build_F(k->F, &k->lay_r, &m, &earth, k->proc_diag);
  for (size_t e = 0; e < k->n_nz; ++e)
    k->A[k->nz[e]] = k->F[k->nz[e]] * T;
  /* The blocks linear in C_b_n: the interval's exact integrals (as the filter). */
  put_block(k->A, nr, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_PHI, nav_mat3_skew(iv->fn_T), 1.0);
  put_block(k->A, nr, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_BA, iv->C_T, 1.0);
  put_block(k->A, nr, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_BG, iv->C_T, -1.0);
  /* U = A_xx S + A_xs over the non-zeros of A_xx (about a third of it). */
  double U[NMAX * LDS];
  for (size_t i = 0; i < nr; ++i) {
    double u[LDS] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (size_t e = k->row[i]; e < k->row[i + 1]; ++e) {
      const size_t j = k->nz[e] - i * nr;
      const double aij = k->A[k->nz[e]];
      UNROLL_LDS
      for (size_t a = 0; a < LDS; ++a) u[a] += aij * k->S[j * LDS + a];
    }
    for (size_t a = 0; a < LDS; ++a) U[i * LDS + a] = u[a];
  }
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j) {
      U[(NAV_FILTER_IDX_DV + i) * LDS + 3 + j] += iv->Cf_T.m[i][j];
      U[(NAV_FILTER_IDX_PHI + i) * LDS + j] -= iv->Cw_T.m[i][j];
    }
  for (size_t i = 0; i < nr; ++i) {
    double au[LDS] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (size_t e = k->row[i]; e < k->row[i + 1]; ++e) {
      const size_t j = k->nz[e] - i * nr;
      const double aij = k->A[k->nz[e]];
      UNROLL_LDS
      for (size_t a = 0; a < LDS; ++a) au[a] += aij * U[j * LDS + a];
    }
    for (size_t a = 0; a < LDS; ++a) k->S[i * LDS + a] += U[i * LDS + a] + 0.5 * au[a];
  }
  memset(&k->iv, 0, sizeof k->iv);
}

void nav_consider_predict(nav_consider *c, const nav_filter_nav *nav, double dt_s) {
  /* The filter's rule (nav_filter_predict): a step when the interval reaches the decimation. */
  const bool full = c->iv.count + 1 >= c->decimation;
  interval_add(&c->iv, nav, dt_s);
  if (full) step(c);
}

void nav_consider_flush(nav_consider *c) {
  if (c->iv.count > 0) step(c);
}

nav_status nav_consider_update(nav_consider *c, const double *P, const nav_filter_nav *nav, nav_vec3 l_ba_b_m,
                               nav_vec3 r, bool vel) {
  const size_t nr = c->nr, nc = c->lay_c.n_states;
  if (vel)
    nav_filter_build_H_vel(c->Hc, &c->lay_c, nav, l_ba_b_m);
  else
    nav_filter_build_H_pos(c->Hc, &c->lay_c, nav, l_ba_b_m);
  /* The filter's gain K = P H^T (H P H^T + R)^-1 (nr x 3), H its own rows (the navigation
   * columns of the consider layout's H). */
  double Hx[3 * NMAX], PHt[NMAX * 3], Sm[9], L[9], K[NMAX * 3], M[3 * LDS];
  for (size_t q = 0; q < 3; ++q)
    for (size_t i = 0; i < nr; ++i) Hx[q * nr + i] = c->Hc[q * nc + c->col[i]];
  for (size_t i = 0; i < nr; ++i)
    for (size_t q = 0; q < 3; ++q) {
      double s = 0.0;
      for (size_t j = 0; j < nr; ++j) s += P[i * nr + j] * Hx[q * nr + j];
      PHt[i * 3 + q] = s;
    }
  for (size_t q = 0; q < 3; ++q)
    for (size_t p = 0; p < 3; ++p) {
      double s = 0.0;
      for (size_t j = 0; j < nr; ++j) s += Hx[q * nr + j] * PHt[j * 3 + p];
      Sm[q * 3 + p] = s + (q == p ? nav_vec3_get(r, (int)q) : 0.0);
    }
  for (size_t q = 0; q < 3; ++q) /* symmetric, as the filter's */
    for (size_t p = q + 1; p < 3; ++p) Sm[q * 3 + p] = Sm[p * 3 + q] = 0.5 * (Sm[q * 3 + p] + Sm[p * 3 + q]);
  if (nav_matn_cholesky(L, Sm, 3) != NAV_OK) return NAV_ERR_NUMERIC;
  for (size_t i = 0; i < nr; ++i) { /* K_i = S^-1 (P H^T)_i: L y = b, L^T x = y */
    double y[3];
    for (size_t a = 0; a < 3; ++a) {
      double s = PHt[i * 3 + a];
      for (size_t b = 0; b < a; ++b) s -= L[a * 3 + b] * y[b];
      y[a] = s / L[a * 3 + a];
    }
    for (size_t a = 3; a-- > 0;) {
      double s = y[a];
      for (size_t b = a + 1; b < 3; ++b) s -= L[b * 3 + a] * K[i * 3 + b];
      K[i * 3 + a] = s / L[a * 3 + a];
    }
  }
  /* M = H_x S + H_s (3 x 6), then S -= K M. */
  for (size_t q = 0; q < 3; ++q)
    for (size_t a = 0; a < NS; ++a) {
      double s = c->Hc[q * nc + NAV_FILTER_IDX_SG + a];
      for (size_t j = 0; j < nr; ++j) s += Hx[q * nr + j] * c->S[j * LDS + a];
      M[q * LDS + a] = s;
    }
  for (size_t i = 0; i < nr; ++i)
    for (size_t a = 0; a < NS; ++a)
      c->S[i * LDS + a] -= K[i * 3] * M[a] + K[i * 3 + 1] * M[LDS + a] + K[i * 3 + 2] * M[2 * LDS + a];
  return NAV_OK;
}

void nav_consider_total_diag(const nav_consider *c, const double *P, size_t m, double *diag) {
  const size_t nr = c->nr;
  for (size_t i = 0; i < m && i < nr; ++i) {
    double s = 0.0;
    for (size_t a = 0; a < NS; ++a) s += c->S[i * LDS + a] * c->S[i * LDS + a] * c->pss[a];
    diag[i] = P[i * nr + i] + s;
  }
}
