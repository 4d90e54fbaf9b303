/**
 * @file rts.c
 * @brief Rauch-Tung-Striebel smoother for the closed-loop error-state filter (nav_smoother.h,
 *        where the formulation is documented).
 *
 * Forward-time cost per IMU step (n = 15): F and G Q_c G^T (model.c) summed into the group
 * accumulators (2 n^2 additions); per group, Phi_g = I + A + A^2/2 over the non-zeros of A and
 * the two sparse products Phi_g Phi and Phi_g (Q + Q_g) Phi_g^T, as in the filter's own
 * covariance step. Backward pass: dense n^3 products per record (a few per record, at the
 * record rate only).
 */
#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "navcore/nav_smoother.h"

#define NMAX NAV_FILTER_MAX_STATES
#define NN (NMAX * NMAX)
/* The NED model needs 1/cos(lat) (as ekf.c). */
#define MIN_COS_LAT 1e-6

typedef struct rows {
  size_t start[NMAX + 1];
  size_t col[NN];
  double val[NN];
} rows;

/* Per-record scalars; the matrices live in parallel arrays of the smoother. */
typedef struct rec {
  double t_s;
  long step;     /* forward step index of the epoch */
  bool measured; /* a measurement update happened */
  nav_filter_ins_state nominal;
} rec;

struct nav_smoother {
  nav_smoother_config cfg;
  nav_filter_layout lay;
  size_t n, ntri;
  double proc_diag[NMAX], qc[NMAX];

  /* Recording (amortised growth). */
  size_t count, cap;
  rec *r;
  double *phi;           /* n^2 per record: transition from the previous record (identity for record 0) */
  double *q;             /* ntri per record: process noise from the previous record */
  double *p;             /* ntri per record: a-posteriori covariance */
  double *x;             /* n per record: error state after the reset */
  double *d;             /* n per record: correction fed back at the record */
  double *xs;            /* n per record: smoothed error (after run) */
  double *sds;           /* n per record: smoothed sigmas (after run) */
  size_t smoothed_count; /* records covered by the last run */

  bool begun;
  long step;                /* IMU steps so far */
  nav_filter_ins_state cur; /* nominal of the last step */
  double cur_t_s;

  /* Since the last record: accumulated transition and noise, x and P propagated. */
  double Phi[NN], Q[NN];
  /* Pending group. */
  unsigned grp_count;
  double A[NN], QT[NN];
  /* Last record's P (full) and x, to propagate at mark. */
  double Plast[NN], xlast[NMAX];

  /* Scratch. */
  double F[NN], GQG[NN], Pg[NN], W[NN], T1[NN], T2[NN], L[NN];
  /* Backward-pass work (separate, so that a run between recordings keeps the group sums). */
  double Bs[NN], Bk[NN], Bm[NN], Bc[NN], Ba[NN], Bq[NN], Bw[NN];
  rows sp;
  char err[256];
};

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 2, 3)))
#endif
static void
set_error(nav_smoother *s, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(s->err, sizeof s->err, fmt, ap);
  va_end(ap);
}

/* ---------------------------------------------------------------- config */

nav_smoother_config nav_smoother_config_default(void) {
  nav_smoother_config c;
  memset(&c, 0, sizeof c);
  c.filter = nav_filter_config_default();
  c.group_steps = 1u;
  return c;
}

nav_status nav_smoother_create(const nav_smoother_config *cfg, nav_smoother **out) {
  assert(cfg != NULL && out != NULL);
  if (cfg == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  if (cfg->group_steps < 1u) return NAV_ERR_INVALID_ARG;
  if (nav_filter_config_validate(&cfg->filter, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_smoother *s = calloc(1, sizeof *s);
  if (s == NULL) return NAV_ERR_NO_MEMORY;
  s->cfg = *cfg;
  s->lay = nav_filter_layout_of(cfg->filter.states);
  s->n = s->lay.n_states;
  s->ntri = s->n * (s->n + 1) / 2;
  nav_filter_process_model(&cfg->filter, &s->lay, s->proc_diag, s->qc);
  *out = s;
  return NAV_OK;
}

static void free_arrays(nav_smoother *s) {
  free(s->r);
  free(s->phi);
  free(s->q);
  free(s->p);
  free(s->x);
  free(s->d);
  free(s->xs);
  free(s->sds);
  s->r = NULL;
  s->phi = s->q = s->p = s->x = s->d = s->xs = s->sds = NULL;
  s->cap = s->count = s->smoothed_count = 0;
}

void nav_smoother_destroy(nav_smoother *s) {
  if (s == NULL) return;
  free_arrays(s);
  free(s);
}

size_t nav_smoother_count(const nav_smoother *s) {
  return s != NULL ? s->count : 0;
}

nav_filter_layout nav_smoother_layout(const nav_smoother *s) {
  return s != NULL ? s->lay : nav_filter_layout_of(0u);
}

const char *nav_smoother_last_error(const nav_smoother *s) {
  return s != NULL ? s->err : "";
}

size_t nav_smoother_memory_bytes(const nav_smoother *s) {
  if (s == NULL) return 0;
  const size_t n = s->n;
  const size_t per = sizeof(rec) + sizeof(double) * (n * n + 2 * s->ntri + 4 * n);
  return sizeof *s + s->cap * per;
}

/* ---------------------------------------------------------------- small helpers */

static void pack(double *dst, const double *P, size_t n) {
  size_t k = 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j)
      dst[k++] = P[i * n + j];
}

static void unpack(double *P, const double *src, size_t n) {
  size_t k = 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      P[i * n + j] = src[k];
      P[j * n + i] = src[k];
      ++k;
    }
}

static void identity(double *a, size_t n) {
  memset(a, 0, n * n * sizeof *a);
  for (size_t i = 0; i < n; ++i)
    a[i * n + i] = 1.0;
}

static bool all_finite(const double *a, size_t m) {
  for (size_t i = 0; i < m; ++i)
    if (!isfinite(a[i])) return false;
  return true;
}

static bool nominal_finite(const nav_filter_ins_state *v) {
  const double a[] = {v->lat_rad, v->lon_rad, v->h_m, v->q_b_n.w, v->q_b_n.x, v->q_b_n.y, v->q_b_n.z};
  return all_finite(a, sizeof a / sizeof a[0]) && nav_vec3_isfinite(v->v_eb_n_mps) &&
         nav_vec3_isfinite(v->b_g_rps) && nav_vec3_isfinite(v->b_a_mps2) && nav_vec3_isfinite(v->s_g) &&
         nav_vec3_isfinite(v->s_a);
}

static void build_rows(rows *sp, const double *a, size_t n) {
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

/* y += a x over m elements, unrolled by four so that GCC's -O2 vectoriser packs the body (its
 * -O2 cost model skips loops of unknown trip count); values are those of the plain loop. */
static inline void axpy(double *restrict y, double a, const double *restrict x, size_t m) {
  size_t c = 0;
  for (; c + 4 <= m; c += 4) {
    y[c] += a * x[c];
    y[c + 1] += a * x[c + 1];
    y[c + 2] += a * x[c + 2];
    y[c + 3] += a * x[c + 3];
  }
  for (; c < m; ++c)
    y[c] += a * x[c];
}

static inline double dot(const double *a, const double *b, size_t m) {
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
  size_t c = 0;
  for (; c + 4 <= m; c += 4) {
    s0 += a[c] * b[c];
    s1 += a[c + 1] * b[c + 1];
    s2 += a[c + 2] * b[c + 2];
    s3 += a[c + 3] * b[c + 3];
  }
  for (; c < m; ++c)
    s0 += a[c] * b[c];
  return (s0 + s1) + (s2 + s3);
}

/* out = S b (S sparse rows, b dense n x n); out must not alias b. */
static void sparse_mul(double *out, const rows *sp, const double *b, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    double *o = out + i * n;
    for (size_t c = 0; c < n; ++c)
      o[c] = 0.0;
    for (size_t p = sp->start[i]; p < sp->start[i + 1]; ++p)
      axpy(o, sp->val[p], b + sp->col[p] * n, n);
  }
}

/* Dense n x n products for the backward pass (row-major). c = a b. */
static void mm(double *restrict c, const double *restrict a, const double *restrict b, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    double *ci = c + i * n;
    for (size_t j = 0; j < n; ++j)
      ci[j] = 0.0;
    for (size_t t = 0; t < n; ++t)
      axpy(ci, a[i * n + t], b + t * n, n);
  }
}

/* c = a b^T, known to be symmetric: upper triangle by row dot products, mirrored. */
static void mm_bt_sym(double *restrict c, const double *restrict a, const double *restrict b, size_t n) {
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      const double v = dot(a + i * n, b + j * n, n);
      c[i * n + j] = v;
      c[j * n + i] = v;
    }
}

/* out = S m S^T for symmetric m; w scratch; out exactly symmetric. */
static void sparse_sandwich(double *out, const rows *sp, const double *m, size_t n, double *w) {
  sparse_mul(w, sp, m, n);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      double sum = 0.0;
      for (size_t p = sp->start[j]; p < sp->start[j + 1]; ++p)
        sum += w[i * n + sp->col[p]] * sp->val[p];
      out[i * n + j] = sum;
      out[j * n + i] = sum;
    }
}

/* ---------------------------------------------------------------- recording */

static nav_status grow(nav_smoother *s) {
  if (s->count < s->cap) return NAV_OK;
  const size_t n = s->n, cap = s->cap ? s->cap + s->cap / 2 : 256;
  rec *r = realloc(s->r, cap * sizeof *r);
  if (r == NULL) return NAV_ERR_NO_MEMORY;
  s->r = r;
  double **arrs[7] = {&s->phi, &s->q, &s->p, &s->x, &s->d, &s->xs, &s->sds};
  const size_t per[7] = {n * n, s->ntri, s->ntri, n, n, n, n};
  for (int i = 0; i < 7; ++i) {
    double *a = realloc(*arrs[i], cap * per[i] * sizeof(double));
    if (a == NULL) return NAV_ERR_NO_MEMORY;
    *arrs[i] = a;
  }
  s->cap = cap;
  return NAV_OK;
}

/* Discretise the pending group (E6.2) and chain it into Phi and Q. */
static void flush_group(nav_smoother *s) {
  if (s->grp_count == 0) return;
  const size_t n = s->n;
  /* Phi_g = I + A + A^2/2, the square over the non-zeros of A. */
  build_rows(&s->sp, s->A, n);
  sparse_mul(s->Pg, &s->sp, s->A, n);
  for (size_t i = 0; i < n * n; ++i)
    s->Pg[i] = s->A[i] + 0.5 * s->Pg[i];
  for (size_t i = 0; i < n; ++i)
    s->Pg[i * n + i] += 1.0;
  build_rows(&s->sp, s->Pg, n);
  /* Phi <- Phi_g Phi. */
  sparse_mul(s->T1, &s->sp, s->Phi, n);
  memcpy(s->Phi, s->T1, n * n * sizeof *s->Phi);
  /* Fused E6.2 (as ekf.c): Q <- Phi_g (Q + QT/2) Phi_g^T + QT/2. */
  for (size_t i = 0; i < n * n; ++i)
    s->T1[i] = s->Q[i] + 0.5 * s->QT[i];
  sparse_sandwich(s->Q, &s->sp, s->T1, n, s->W);
  for (size_t i = 0; i < n * n; ++i)
    s->Q[i] += 0.5 * s->QT[i];
  s->grp_count = 0;
}

/* Append a record for the current step from Phi, Q, P (full) and x; resets the accumulators. */
static nav_status append(nav_smoother *s, double t_s, const nav_filter_ins_state *nominal, bool measured,
                         const double *P, const double *x, const double *d) {
  const nav_status st = grow(s);
  if (st != NAV_OK) {
    set_error(s, "smoother: out of memory after %zu records", s->count);
    return st;
  }
  const size_t n = s->n, k = s->count;
  rec *r = &s->r[k];
  r->t_s = t_s;
  r->step = s->step;
  r->measured = measured;
  r->nominal = *nominal;
  memcpy(s->phi + k * n * n, s->Phi, n * n * sizeof(double));
  nav_matn_symmetrize(s->Q, n);
  pack(s->q + k * s->ntri, s->Q, n);
  pack(s->p + k * s->ntri, P, n);
  memcpy(s->x + k * n, x, n * sizeof(double));
  memcpy(s->d + k * n, d, n * sizeof(double));
  for (size_t i = 0; i < n; ++i) {
    s->xs[k * n + i] = NAN;
    s->sds[k * n + i] = NAN;
  }
  if (P != s->Plast) memcpy(s->Plast, P, n * n * sizeof(double));
  if (x != s->xlast) memcpy(s->xlast, x, n * sizeof(double));
  identity(s->Phi, n);
  memset(s->Q, 0, n * n * sizeof *s->Q);
  s->count++;
  return NAV_OK;
}

nav_status nav_smoother_begin(nav_smoother *s, double t_s, const nav_filter_ins_state *nominal,
                              const double *P, const double *x) {
  assert(s != NULL && nominal != NULL && P != NULL);
  if (s == NULL || nominal == NULL || P == NULL) return NAV_ERR_INVALID_ARG;
  const size_t n = s->n;
  if (!isfinite(t_s) || !nominal_finite(nominal) || !all_finite(P, n * n) || (x && !all_finite(x, n))) {
    set_error(s, "smoother begin: non-finite time, state or covariance");
    return NAV_ERR_NUMERIC;
  }
  s->count = 0;
  s->smoothed_count = 0;
  s->step = 0;
  s->grp_count = 0;
  s->cur = *nominal;
  s->cur_t_s = t_s;
  identity(s->Phi, n);
  memset(s->Q, 0, n * n * sizeof *s->Q);
  double zero[NMAX] = {0};
  memcpy(s->T2, P, n * n * sizeof(double));
  nav_matn_symmetrize(s->T2, n);
  const nav_status st = append(s, t_s, nominal, false, s->T2, x ? x : zero, zero);
  s->begun = st == NAV_OK;
  return st;
}

nav_status nav_smoother_step(nav_smoother *s, double t_s, const nav_filter_nav *nav, double dt_s,
                             const nav_filter_ins_state *nominal) {
  assert(s != NULL && nav != NULL && nominal != NULL);
  if (s == NULL || nav == NULL || nominal == NULL || !(dt_s > 0.0)) return NAV_ERR_INVALID_ARG;
  if (!s->begun) {
    set_error(s, "smoother step before nav_smoother_begin()");
    return NAV_ERR_STATE;
  }
  if (!isfinite(dt_s) || !isfinite(t_s) || !isfinite(nav->lat_rad) || !isfinite(nav->h_m) ||
      !nav_vec3_isfinite(nav->v_eb_n_mps) || !nav_vec3_isfinite(nav->f_ib_b_mps2) ||
      !nav_vec3_isfinite(nav->w_ib_b_rps) || !all_finite(&nav->C_b_n.m[0][0], 9) ||
      !nominal_finite(nominal)) {
    set_error(s, "smoother step at t = %.6f s: non-finite input", t_s);
    return NAV_ERR_NUMERIC;
  }
  if (!(fabs(cos(nav->lat_rad)) >= MIN_COS_LAT)) {
    set_error(s, "smoother step at t = %.6f s: latitude too close to a pole for the NED model", t_s);
    return NAV_ERR_OUT_OF_RANGE;
  }
  const size_t n = s->n;
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(nav->lat_rad, nav->h_m);
  nav_filter_build_F(s->F, &s->lay, nav, &earth, s->proc_diag);
  nav_filter_build_GQG(s->GQG, &s->lay, nav->C_b_n, s->qc);
  /* Two plain loops (no select in the body) so that they vectorise. */
  if (s->grp_count == 0) {
    memset(s->A, 0, n * n * sizeof *s->A);
    memset(s->QT, 0, n * n * sizeof *s->QT);
  }
  axpy(s->A, dt_s, s->F, n * n);
  axpy(s->QT, dt_s, s->GQG, n * n);
  s->grp_count++;
  if (s->grp_count >= s->cfg.group_steps) flush_group(s);
  s->step++;
  s->cur = *nominal;
  s->cur_t_s = t_s;
  return NAV_OK;
}

/* P = Phi Plast Phi^T + Q and x = Phi xlast (the filter's propagation from the last record). */
static nav_status propagate_to_now(nav_smoother *s, double *P, double *x) {
  const size_t n = s->n;
  flush_group(s);
  nav_matn_symmetrize(s->Q, n);
  mm(s->W, s->Phi, s->Plast, n);
  mm_bt_sym(P, s->W, s->Phi, n);
  for (size_t i = 0; i < n * n; ++i)
    P[i] += s->Q[i];
  for (size_t i = 0; i < n; ++i) {
    double sum = 0.0;
    for (size_t j = 0; j < n; ++j)
      sum += s->Phi[i * n + j] * s->xlast[j];
    x[i] = sum;
  }
  if (!all_finite(P, n * n) || !all_finite(x, n)) {
    set_error(s, "smoother: propagated covariance at t = %.6f s is not finite", s->cur_t_s);
    return NAV_ERR_NUMERIC;
  }
  return NAV_OK;
}

nav_status nav_smoother_mark(nav_smoother *s) {
  assert(s != NULL);
  if (s == NULL) return NAV_ERR_INVALID_ARG;
  if (!s->begun) {
    set_error(s, "smoother mark before nav_smoother_begin()");
    return NAV_ERR_STATE;
  }
  if (s->count > 0 && s->r[s->count - 1].step == s->step) return NAV_OK;
  double x[NMAX], zero[NMAX] = {0};
  nav_status st = propagate_to_now(s, s->T2, x);
  if (st != NAV_OK) return st;
  return append(s, s->cur_t_s, &s->cur, false, s->T2, x, zero);
}

nav_status nav_smoother_update(nav_smoother *s, const nav_filter_ins_state *nominal, const double *P,
                               const double *x_after, const double *correction) {
  assert(s != NULL && nominal != NULL && P != NULL);
  if (s == NULL || nominal == NULL || P == NULL) return NAV_ERR_INVALID_ARG;
  if (!s->begun) {
    set_error(s, "smoother update before nav_smoother_begin()");
    return NAV_ERR_STATE;
  }
  const size_t n = s->n;
  double zero[NMAX] = {0};
  const double *xa = x_after ? x_after : zero, *dc = correction ? correction : zero;
  if (!nominal_finite(nominal) || !all_finite(P, n * n) || !all_finite(xa, n) || !all_finite(dc, n)) {
    set_error(s, "smoother update at t = %.6f s: non-finite state, covariance or correction", s->cur_t_s);
    return NAV_ERR_NUMERIC;
  }
  memcpy(s->T2, P, n * n * sizeof(double));
  nav_matn_symmetrize(s->T2, n);
  s->cur = *nominal;
  if (s->count > 0 && s->r[s->count - 1].step == s->step) {
    /* This step is already recorded (a mark, or an earlier update of the same epoch): replace
     * its a-posteriori values and accumulate the correction. */
    const size_t k = s->count - 1;
    rec *r = &s->r[k];
    r->measured = true;
    r->nominal = *nominal;
    pack(s->p + k * s->ntri, s->T2, n);
    memcpy(s->x + k * n, xa, n * sizeof(double));
    for (size_t i = 0; i < n; ++i)
      s->d[k * n + i] += dc[i];
    memcpy(s->Plast, s->T2, n * n * sizeof(double));
    memcpy(s->xlast, xa, n * sizeof(double));
    s->smoothed_count = s->smoothed_count > k ? k : s->smoothed_count;
    return NAV_OK;
  }
  flush_group(s);
  return append(s, s->cur_t_s, nominal, true, s->T2, xa, dc);
}

/* ---------------------------------------------------------------- backward pass */

nav_status nav_smoother_run(nav_smoother *s) {
  assert(s != NULL);
  if (s == NULL) return NAV_ERR_INVALID_ARG;
  if (s->count == 0) {
    set_error(s, "smoother run: nothing recorded");
    return NAV_ERR_STATE;
  }
  const size_t n = s->n, N = s->count;
  /* Work matrices: Ps (smoothed P of k+1), Pk, Phi, Q, P-, C, A = I - C Phi. */
  double *Ps = s->Bs, *Pk = s->Bk, *Pm = s->Bm, *C = s->Bc, *A = s->Ba, *Qm = s->Bq, *M = s->Bw;
  double xs_next[NMAX], r[NMAX];
  /* Last record: smoothed = filtered. */
  unpack(Ps, s->p + (N - 1) * s->ntri, n);
  for (size_t i = 0; i < n; ++i) {
    s->xs[(N - 1) * n + i] = s->x[(N - 1) * n + i];
    if (!(Ps[i * n + i] > 0.0) || !isfinite(Ps[i * n + i])) {
      set_error(s, "smoother run: variance %zu of the last record (t = %.6f s) is %g", i, s->r[N - 1].t_s,
                Ps[i * n + i]);
      return NAV_ERR_NUMERIC;
    }
    s->sds[(N - 1) * n + i] = sqrt(Ps[i * n + i]);
    xs_next[i] = s->x[(N - 1) * n + i];
  }
  for (size_t k = N - 1; k-- > 0;) {
    const double *Phi = s->phi + (k + 1) * n * n;
    const double *xk = s->x + k * n, *dk1 = s->d + (k + 1) * n;
    unpack(Pk, s->p + k * s->ntri, n);
    unpack(Qm, s->q + (k + 1) * s->ntri, n);
    /* M = Phi P_k;  P- = M Phi^T + Q. */
    mm(M, Phi, Pk, n);
    mm_bt_sym(Pm, M, Phi, n);
    for (size_t i = 0; i < n * n; ++i)
      Pm[i] += Qm[i];
    if (!all_finite(Pm, n * n) || nav_matn_cholesky(s->L, Pm, n) != NAV_OK) {
      set_error(s,
                "smoother run: a-priori covariance between t = %.6f s and %.6f s is not finite or not "
                "positive definite",
                s->r[k].t_s, s->r[k + 1].t_s);
      return NAV_ERR_NUMERIC;
    }
    /* C^T = (P-)^-1 Phi P_k = (P-)^-1 M (P- and P_k symmetric). */
    nav_matn_chol_solve(M, s->L, M, n, n);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        C[i * n + j] = M[j * n + i];
    /* x_s(k) = x_k + C (x_s(k+1) + d_(k+1) - Phi x_k). */
    for (size_t i = 0; i < n; ++i)
      r[i] = xs_next[i] + dk1[i] - dot(Phi + i * n, xk, n);
    for (size_t i = 0; i < n; ++i)
      xs_next[i] = xk[i] + dot(C + i * n, r, n);
    /* P_s(k) = (I - C Phi) P_k (I - C Phi)^T + C (Q + P_s(k+1)) C^T. */
    mm(A, C, Phi, n);
    for (size_t i = 0; i < n * n; ++i)
      A[i] = -A[i];
    for (size_t i = 0; i < n; ++i)
      A[i * n + i] += 1.0;
    for (size_t i = 0; i < n * n; ++i)
      Qm[i] += Ps[i];
    mm(M, A, Pk, n);
    mm_bt_sym(Ps, M, A, n);
    mm(M, C, Qm, n);
    mm_bt_sym(Pm, M, C, n);
    for (size_t i = 0; i < n * n; ++i)
      Ps[i] += Pm[i];
    for (size_t i = 0; i < n; ++i) {
      const double v = Ps[i * n + i];
      if (!isfinite(v) || !(v > 0.0) || !isfinite(xs_next[i])) {
        set_error(s, "smoother run: smoothed variance %zu at t = %.6f s is %g (state %g)", i, s->r[k].t_s, v,
                  xs_next[i]);
        return NAV_ERR_NUMERIC;
      }
      s->sds[k * n + i] = sqrt(v);
      s->xs[k * n + i] = xs_next[i];
    }
  }
  s->smoothed_count = N;
  return NAV_OK;
}

/* ---------------------------------------------------------------- results */

static nav_vec3 blk(const double *x, size_t i) {
  return nav_vec3_make(x[i], x[i + 1], x[i + 2]);
}

nav_status nav_smoother_get(const nav_smoother *s, size_t k, nav_smoother_epoch *out) {
  assert(s != NULL && out != NULL);
  if (s == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  if (k >= s->count) return NAV_ERR_OUT_OF_RANGE;
  const size_t n = s->n;
  const rec *r = &s->r[k];
  nav_smoother_epoch e;
  memset(&e, 0, sizeof e);
  e.t_s = r->t_s;
  e.measured = r->measured;
  e.forward = r->nominal;
  for (size_t i = 0; i < NMAX; ++i) {
    e.sd_forward[i] = NAN;
    e.sd_smoothed[i] = NAN;
  }
  /* Diagonal of the packed upper triangle: row i starts at i n - i (i - 1)/2. */
  const double *pp = s->p + k * s->ntri;
  for (size_t i = 0; i < n; ++i)
    e.sd_forward[i] = sqrt(pp[i * n - i * (i - 1) / 2]);
  if (k < s->smoothed_count) {
    const double *xs = s->xs + k * n;
    for (size_t i = 0; i < n; ++i)
      e.sd_smoothed[i] = s->sds[k * n + i];
    e.dx_smoothed.dr_ned_m = blk(xs, NAV_FILTER_IDX_DR);
    e.dx_smoothed.dv_n_mps = blk(xs, NAV_FILTER_IDX_DV);
    e.dx_smoothed.phi_rad = blk(xs, NAV_FILTER_IDX_PHI);
    e.dx_smoothed.b_g_rps = blk(xs, NAV_FILTER_IDX_BG);
    e.dx_smoothed.b_a_mps2 = blk(xs, NAV_FILTER_IDX_BA);
    e.dx_smoothed.s_g = s->lay.has_scale_factors ? blk(xs, NAV_FILTER_IDX_SG) : nav_vec3_zero();
    e.dx_smoothed.s_a = s->lay.has_scale_factors ? blk(xs, NAV_FILTER_IDX_SA) : nav_vec3_zero();
    e.dx_smoothed.gnss_pos_m = s->lay.has_gnss_pos_gm ? blk(xs, s->lay.idx_gnss_pos) : nav_vec3_zero();
    nav_filter_apply_correction(&e.smoothed, &r->nominal, &e.dx_smoothed);
  } else {
    const double nan = NAN;
    e.smoothed.lat_rad = e.smoothed.lon_rad = e.smoothed.h_m = nan;
    e.smoothed.v_eb_n_mps = nav_vec3_make(nan, nan, nan);
    e.smoothed.q_b_n = (nav_quat){nan, nan, nan, nan};
    e.smoothed.b_g_rps = e.smoothed.b_a_mps2 = e.smoothed.s_g = e.smoothed.s_a = e.smoothed.v_eb_n_mps;
    e.dx_smoothed.dr_ned_m = e.dx_smoothed.dv_n_mps = e.dx_smoothed.phi_rad = e.smoothed.v_eb_n_mps;
    e.dx_smoothed.b_g_rps = e.dx_smoothed.b_a_mps2 = e.dx_smoothed.s_g = e.dx_smoothed.s_a =
        e.smoothed.v_eb_n_mps;
    e.dx_smoothed.gnss_pos_m = e.smoothed.v_eb_n_mps;
  }
  *out = e;
  return NAV_OK;
}
