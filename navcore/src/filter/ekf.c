/**
 * @file ekf.c
 * @brief The error-state Kalman filter object: time update (second-order or Van Loan, optional
 *        covariance decimation), measurement updates (Cholesky of S, Joseph form), checks.
 *
 * Cost notes (the hot path at IMU rate). The non-zero patterns of F T and of the second-order
 * Phi are structural (fixed by the layout: computed once at create), so products with Phi run
 * over them only: at 15 states F has 66 non-zeros of 225, Phi about 140 (its bias rows are a
 * single diagonal entry). The second-order step is fused into one sandwich,
 * P+ = Phi (P + Q/2) Phi^T + Q/2, which is E6.2 rearranged: Phi P Phi^T + (Phi Q Phi^T + Q)/2
 * with Q = G Q_c G^T T. The sandwich runs row-wise on zero-padded rows of 16, 20 or 24 doubles
 * (n rounded up to a multiple of 4), W = Phi S, a 4 x 4-block transpose, then the upper
 * triangle of Phi W^T, each row an unrolled multiply-add that the compiler vectorises (an AVX2
 * clone is picked at load time on x86-64; same values). Every propagated P is checked for
 * non-finite entries and a non-positive diagonal; positive definiteness is proved by a
 * right-looking Cholesky on padded rows, whose success also proves P finite (chol_ok), on every
 * update and on every COV_FULL_CHECK_EVERY-th covariance step in between (check_cov_predict).
 * Measured with callgrind on the Monte Carlo bench scene (18 states: the core plus three GNSS
 * error states; cov_decimation 10): 19k instructions per covariance step (sandwich 8.3k,
 * Cholesky check 6.2k, Phi 2.1k, the rest 2.5k) plus 4.8k for F and the interval sums
 * (pending_integrals); the calls in between only accumulate the sums of struct pending (~350
 * instructions with the input checks). Since then the sandwich computes only the columns it
 * keeps (7.4k) and the full Cholesky check runs on the updates and on a schedule; the per-step
 * guard (all_finite and the diagonal) costs 0.5k (issue 23). Measurement updates (GNSS rate) use the Joseph form as
 * (A P) A^T with A = I - K H never formed, O(n^2 m), instantiated with compile-time sizes for
 * the GNSS cases: 32k instructions per 3-component update.
 * Then (issue 23, same scene, and the 21-state long-drive replay in brackets): the row kernels
 * keep their sums in registers (nav_v4), the rows of the states whose Phi row is its diagonal
 * alone (biases, scale factors, GNSS errors) take the short path d_i (d_j S_ij), the other rows
 * are computed in the columns their pattern reaches only, the upper triangle is mirrored by
 * 4 x 4 block transposes: covariance step 14.3k -> 10.8k (22.1k -> 15.9k; sandwich 8.1k -> 6.3k
 * (12.0k -> 9.5k), Phi 2.1k -> 1.4k (2.9k -> 2.1k)); F without clearing the n x n matrix
 * (nav_filter_build_F_nonzero): pending_integrals 4.7k -> 2.1k (6.1k -> 2.6k); the input check
 * per IMU step 90 -> 64; the update with its n x m products stored transposed (sums over whole
 * rows, vectorised) and a Cholesky check that updates each row from column k + 1 on: 27.6k ->
 * 21.9k per 3-component update (72.7k -> 28.3k, now instantiated for 21 states). Every one of
 * these transformations keeps the values bit for bit (test_filter_kernels checks each kernel
 * against its plain loops; scripts/compare-outputs over every scene and replay).
 * Then (issue 23, bench scene): the INS/GNSS step's prediction without the input check of the
 * numbers the NED INS vouches for (nav_filter_predict_ins: 64 -> 0 per IMU step), and the update
 * with P+ symmetrised in its K R K^T pass and S^-1 solved inline: 22.8k -> 20.0k per position
 * update, 22.4k -> 19.6k per velocity update (docs/campaign-speed.md has the whole budget).
 */
#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "math/chol_solve_inline.h"
#include "navcore/nav_earth.h"

#define NMAX NAV_FILTER_MAX_STATES
#define NN (NMAX * NMAX)
#define MMAX NAV_FILTER_MAX_MEAS
/* nav_van_loan_work_size(NMAX): 2 (2n)^2 for M and E plus 7 (2n)^2 + 2n for the exponential. */
#define VL_WORK (9 * NAV_EXPM_MAX_DIM * NAV_EXPM_MAX_DIM + NAV_EXPM_MAX_DIM)

/* The NED model needs tan(lat) and 1/cos(lat): refuse where nav_ins refuses (numerics.md 4.4
 * rule 4). */
#define MIN_COS_LAT 1e-6

/* Column indices of the (structurally) non-zero entries of each row. */
typedef struct row_pattern {
  unsigned char cnt[NMAX];
  unsigned char col[NMAX][NMAX];
  uint32_t mask[NMAX];     /* the same columns as bits */
  unsigned char diag_from; /* rows diag_from .. n-1 hold their diagonal entry alone */
  unsigned char width;     /* the columns of rows 0 .. diag_from-1 lie below this multiple of 4 */
} row_pattern;

/* The derived fields of a pattern whose cnt and col are set. */
static void pattern_finish(row_pattern *pt, size_t n, size_t ld) {
  size_t s0 = n;
  while (s0 > 0 && pt->cnt[s0 - 1] == 1 && pt->col[s0 - 1][0] == s0 - 1)
    --s0;
  size_t w = 0;
  for (size_t i = 0; i < n; ++i) {
    pt->mask[i] = 0;
    for (unsigned p = 0; p < pt->cnt[i]; ++p) {
      pt->mask[i] |= UINT32_C(1) << pt->col[i][p];
      if (i < s0 && pt->col[i][p] + 1u > w) w = pt->col[i][p] + 1u;
    }
  }
  w = (w + 3) & ~(size_t)3;
  pt->diag_from = (unsigned char)s0;
  pt->width = (unsigned char)(w < 4 ? 4 : (w > ld ? ld : w));
}

/* Index of the lowest set bit of m != 0. */
static inline unsigned nav_ctz32(uint32_t m) {
#if defined(__GNUC__)
  return (unsigned)__builtin_ctz(m);
#else
  unsigned k = 0;
  while ((m & 1u) == 0) {
    m >>= 1;
    ++k;
  }
  return k;
#endif
}

/*
 * Sums over a decimated covariance interval (numerics.md 6.3 with cov_decimation > 1). The
 * blocks of F that vary at IMU rate are linear in C_b_n, C_b_n f and C_b_n diag(f or w), so
 * their interval means are exact from these sums; the other blocks (Earth curvature, transport
 * and Coriolis terms) depend on lat, h and v only, which change by parts in 1e6 over a
 * covariance interval, and are evaluated once at the interval means of lat, h and v (the mean
 * F to second order in the interval). G Q_c G^T is C diag(q) C^T: q I when q is isotropic,
 * else summed.
 */
typedef struct pending {
  unsigned count;
  double T, lat_T, h_T;
  double last_lat, last_h; /* the last interval's values: a single-step interval uses them as */
  nav_vec3 last_v;         /* they are (no rounding through the sums) */
  nav_vec3 v_T, fn_T;
  nav_mat3 C_T, Cf_T, Cw_T, Qa_T, Qg_T;
} pending;

struct nav_filter {
  nav_filter_config cfg;
  nav_filter_layout lay;
  size_t n;
  double proc_diag[NMAX]; /* -1/T of GM states, 0 otherwise */
  double qc[NMAX];        /* spectral densities (see nav_filter_build_GQG) */

  double x[NMAX];
  /* The committed covariance P and the candidate Pn of a time or measurement update are the two
   * halves of cov; a candidate that passes its checks becomes P by swapping the pointers (a copy
   * of n^2 doubles less per covariance step and per update). nav_filter_get_cov()'s pointer is
   * valid until the next non-const call, which allows the swap. */
  double *P, *Pn;
  double cov[2][NN];

  /* Pending (decimated) covariance step: the sums over the interval of everything F and
   * G Q_c G^T need (see pending_add). */
  pending pend;
  bool q_isotropic; /* q of ARW and VRW equal on the three axes: G Q_c G^T blocks are q I */

  /* Structural non-zero pattern of F T and of the second-order Phi (fixed by the layout). */
  row_pattern a_pat, phi_pat;
  size_t ld; /* row stride of the padded work matrices: n rounded up to a multiple of 4 */

  /* Scratch, sized for the largest state; nothing is allocated after create. */
  double F[NN], GQG[NN], FT[NN], QT[NN], Phi[NN], Qd[NN], S[NN], W[NN], L[NN], A[NN], Wt[NN];
  double H[MMAX * NMAX], Kt[MMAX * NMAX], PHt[NMAX * MMAX];
  double xn[NMAX];
  double vl_work[VL_WORK];

  /* Covariance steps since P was last proved positive definite by a full Cholesky
   * (check_cov_predict). */
  unsigned cov_unproved;

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

static void init_patterns(nav_filter *f);

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
  f->P = f->cov[0];
  f->Pn = f->cov[1];
  f->lay = nav_filter_layout_of(cfg->states);
  f->n = f->lay.n_states;

  nav_filter_process_model(cfg, &f->lay, f->proc_diag, f->qc);

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
  if (f->lay.has_rx_clock) {
    const size_t c = f->lay.idx_clock;
    f->P[c * f->n + c] = cfg->init.clock_bias_sd_m * cfg->init.clock_bias_sd_m;
    f->P[(c + 1) * f->n + c + 1] = cfg->init.clock_drift_sd_mps * cfg->init.clock_drift_sd_mps;
  }
  if (f->lay.has_isb) f->P[f->lay.idx_isb * f->n + f->lay.idx_isb] = cfg->init.isb_sd_m * cfg->init.isb_sd_m;
  f->q_isotropic = true;
  for (size_t i = 1; i < 3; ++i)
    if (f->qc[NAV_FILTER_IDX_DV + i] != f->qc[NAV_FILTER_IDX_DV] ||
        f->qc[NAV_FILTER_IDX_PHI + i] != f->qc[NAV_FILTER_IDX_PHI])
      f->q_isotropic = false;
  init_patterns(f);
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

/* On x86-64 with GCC the hot kernels are also compiled for AVX2 and picked at load time
 * (ifunc): the same elementwise multiplies and adds, four doubles at a time instead of two, so
 * the values are bit-identical on every machine (no FMA: -ffp-contract=off, and the avx2 target
 * has none). */
/* Not under ThreadSanitizer: its instrumented ifunc resolver runs before the TSan runtime is
 * initialised and crashes every program at load time. */
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) && \
    !defined(__SANITIZE_THREAD__)
#define NAV_KERNEL_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define NAV_KERNEL_CLONES
#endif

/* ---------------------------------------------------------------- time update */

/* Row pattern of the non-zeros of an n x n matrix given as flags. */
static void pattern_of(row_pattern *pt, const unsigned char *nz, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    unsigned char c = 0;
    for (size_t j = 0; j < n; ++j)
      if (nz[i * n + j]) pt->col[i][c++] = (unsigned char)j;
    pt->cnt[i] = c;
  }
}

/*
 * The structural non-zeros of F T and of the second-order Phi = I + F T + (F T)^2/2: F built at
 * a generic point (every term non-zero), every state diagonal flagged. The patterns depend on
 * the layout only; entries outside them are exactly zero for every navigation state (build_F
 * writes fixed positions), so products over them skip only exact zeros.
 */
static void init_patterns(nav_filter *f) {
  const size_t n = f->n;
  nav_filter_nav g;
  g.lat_rad = 0.61;
  g.h_m = 123.0;
  g.v_eb_n_mps = nav_vec3_make(3.1, -4.2, 0.53);
  const nav_euler e = {0.11, -0.23, 0.37};
  g.C_b_n = nav_euler_to_dcm(e);
  g.f_ib_b_mps2 = nav_vec3_make(0.31, -0.22, -9.7);
  g.w_ib_b_rps = nav_vec3_make(0.011, -0.027, 0.033);
  double pd[NMAX];
  for (size_t i = 0; i < n; ++i)
    pd[i] = -1.0;
  const nav_filter_earth_terms et = nav_filter_earth_terms_wgs84(g.lat_rad, g.h_m);
  nav_filter_build_F(f->F, &f->lay, &g, &et, pd);
  unsigned char a[NN], p[NN];
  for (size_t i = 0; i < n * n; ++i)
    a[i] = f->F[i] != 0.0 || i % (n + 1) == 0;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      unsigned char v = a[i * n + j];
      for (size_t k = 0; k < n && !v; ++k)
        v = a[i * n + k] && a[k * n + j];
      p[i * n + j] = v;
    }
  pattern_of(&f->a_pat, a, n);
  pattern_of(&f->phi_pat, p, n);
  /* The three instantiations of the padded kernels: 16 (the 15-state core), 20 (18 states: the
   * core with GNSS error states) and 24 (the rest). */
  f->ld = n <= 16 ? 16 : (n <= 20 ? 20 : 24);
  pattern_finish(&f->a_pat, n, f->ld);
  pattern_finish(&f->phi_pat, n, f->ld);
}

/* Copy an n x n matrix into a zero-padded one of row stride ld. */
static void pad_copy(double *dst, const double *src, size_t n, size_t ld) {
  for (size_t i = 0; i < n; ++i) {
    memcpy(dst + i * ld, src + i * n, n * sizeof *dst);
    for (size_t c = n; c < ld; ++c)
      dst[i * ld + c] = 0.0;
  }
}

#if defined(__GNUC__) || defined(__clang__)
#define NAV_ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define NAV_ALWAYS_INLINE inline
#endif
#if defined(__GNUC__) && !defined(__clang__)
#define NAV_UNROLL _Pragma("GCC unroll 8")
#else
#define NAV_UNROLL
#endif

/* Four doubles as one value: GCC/Clang vector extensions (elementwise IEEE operations, no FMA
 * under -ffp-contract=off, two SSE2 operations each in the baseline clone), else a plain struct.
 * The row kernels below keep their running sums in such values, i.e. in registers, for the
 * whole of a row instead of loading and storing the row once per term. */
#if defined(__GNUC__)
/* These helpers are always inlined, so the note that a 32-byte vector return changes the ABI
 * where AVX is off (the baseline clone) does not apply (GCC and clang both raise it). */
#pragma GCC diagnostic ignored "-Wpsabi"
typedef double nav_v4 __attribute__((vector_size(32)));
static NAV_ALWAYS_INLINE nav_v4 v4_splat(double a) {
  return (nav_v4){a, a, a, a};
}
static NAV_ALWAYS_INLINE nav_v4 v4_add(nav_v4 a, nav_v4 b) {
  return a + b;
}
static NAV_ALWAYS_INLINE nav_v4 v4_sub(nav_v4 a, nav_v4 b) {
  return a - b;
}
static NAV_ALWAYS_INLINE nav_v4 v4_mul(nav_v4 a, nav_v4 b) {
  return a * b;
}
#else
typedef struct nav_v4 {
  double e[4];
} nav_v4;
static NAV_ALWAYS_INLINE nav_v4 v4_splat(double a) {
  const nav_v4 v = {{a, a, a, a}};
  return v;
}
static NAV_ALWAYS_INLINE nav_v4 v4_add(nav_v4 a, nav_v4 b) {
  for (int c = 0; c < 4; ++c)
    a.e[c] += b.e[c];
  return a;
}
static NAV_ALWAYS_INLINE nav_v4 v4_sub(nav_v4 a, nav_v4 b) {
  for (int c = 0; c < 4; ++c)
    a.e[c] -= b.e[c];
  return a;
}
static NAV_ALWAYS_INLINE nav_v4 v4_mul(nav_v4 a, nav_v4 b) {
  for (int c = 0; c < 4; ++c)
    a.e[c] *= b.e[c];
  return a;
}
#endif
/* Loads and stores through memcpy: any alignment, either representation. */
static NAV_ALWAYS_INLINE nav_v4 v4_load(const double *p) {
  nav_v4 v;
  memcpy(&v, p, sizeof v);
  return v;
}
static NAV_ALWAYS_INLINE void v4_store(double *p, nav_v4 v) {
  memcpy(p, &v, sizeof v);
}

/* The widest row any kernel handles: NMAX rounded up to four doubles. */
#define NV_MAX ((NMAX + 3) / 4)

/* Call body(NV) with NV a compile-time constant 1..6 (the row widths 4..24 in doubles). */
#define NV_DISPATCH(nv, body)                                                                                    \
  switch (nv) {                                                                                                  \
  case 6: body(6); break;                                                                                        \
  case 5: body(5); break;                                                                                        \
  case 4: body(4); break;                                                                                        \
  case 3: body(3); break;                                                                                        \
  case 2: body(2); break;                                                                                        \
  default: body(1); break;                                                                                       \
  }

/* Row i of the elimination from column c0 = LD - 4 NV on: a_i -= (a_ki / a_kk) a_k. */
static NAV_ALWAYS_INLINE void chol_rows(double *a, size_t k, size_t n, double inv, const size_t LD, const size_t NV) {
  const double *ak = a + k * LD;
  const size_t c0 = LD - 4 * NV;
  nav_v4 x[NV_MAX];
  for (size_t q = 0; q < NV; ++q)
    x[q] = v4_load(ak + c0 + 4 * q);
  for (size_t i = k + 1; i < n; ++i) {
    const nav_v4 f = v4_splat(ak[i] * inv);
    double *ai = a + i * LD + c0;
    for (size_t q = 0; q < NV; ++q)
      v4_store(ai + 4 * q, v4_sub(v4_load(ai + 4 * q), v4_mul(f, x[q])));
  }
}

/* Is the symmetric n x n matrix p positive definite? Right-looking Cholesky (as Gaussian
 * elimination, pivots a_kk = L_kk^2) on a zero-padded copy (row stride LD): the outer-product
 * updates of the trailing rows are independent of each other, and each runs from column k + 1
 * rounded down to a multiple of 4 to the end of the padded row, at one of the compile-time widths
 * (unrolled, vectorised; the multiplied row of step k held in registers) instead of the variable
 * tail j >= i. The entries j >= i get exactly the operations a_ij -= (a_ki / a_kk) a_kj of the
 * textbook loop; the others (j < i and the padding) are computed or left stale, never read. A strictly positive, finite pivot
 * at every step is the criterion (numerics.md 6.5); the factor itself is not kept. NaN fails (the
 * comparisons are false).
 *
 * Success also proves that every entry of the upper triangle is finite, which is why check_cov
 * scans for non-finite entries only on failure: an entry changes only by subtraction, so a
 * non-finite one stays non-finite until its row k is the pivot row; there a non-finite diagonal
 * fails at once, and a non-finite a_kj (j > k) makes the multiplier f_j = a_kj / a_kk non-finite
 * and the later pivot a_jj - f_j a_kj infinite or NaN, which fails at step j. */
static NAV_ALWAYS_INLINE bool chol_ok_ld(const double *p, size_t n, double *a, const size_t LD) {
  if (LD - n < 4) {
    /* The padded copy four entries at a time (p read past each row end, into the next row or
     * the rest of its NMAX^2 buffer), the padding then set to zero. */
    for (size_t i = 0; i < n; ++i) {
      for (size_t q = 0; q < LD; q += 4)
        v4_store(a + i * LD + q, v4_load(p + i * n + q));
      for (size_t c = n; c < LD; ++c)
        a[i * LD + c] = 0.0;
    }
  } else {
    pad_copy(a, p, n, LD);
  }
  for (size_t k = 0; k < n; ++k) {
    const double d = a[k * LD + k];
    if (!(d > 0.0) || !(d < INFINITY)) return false;
    const double inv = 1.0 / d;
    /* Only the columns from k + 1 rounded down to a multiple of 4: every entry j >= i > k still
     * gets each of its operations; the entries left of them are never read again. */
    const size_t nv = (LD - ((k + 1) & ~(size_t)3)) / 4;
#define CHOL_ROWS(NV) chol_rows(a, k, n, inv, LD, NV)
    NV_DISPATCH(nv, CHOL_ROWS)
#undef CHOL_ROWS
  }
  return true;
}

/* The instantiations (as pattern_sandwich): LD 16, 20 or 24. */
NAV_KERNEL_CLONES static bool chol_ok(const double *p, size_t n, size_t ld, double *a) {
  if (ld == 16) return chol_ok_ld(p, n, a, 16);
  if (ld == 20) return chol_ok_ld(p, n, a, 20);
  return chol_ok_ld(p, n, a, 24);
}

/* The checked candidate Pn becomes P; the old P's buffer is the next candidate's. */
static inline void commit_cov(nav_filter *f) {
  double *const p = f->P;
  f->P = f->Pn;
  f->Pn = p;
}

/* Covariance steps between two full positive-definiteness proofs of a propagated P (see
 * check_cov_predict). */
#define COV_FULL_CHECK_EVERY 16u

/* Check a covariance candidate: every entry finite, Cholesky succeeds (which implies a
 * positive diagonal; numerics.md 6.5), on every call. p must be exactly symmetric (every caller
 * mirrors or symmetrises it): the Cholesky reads the upper triangle only, and its success proves
 * that triangle finite (chol_ok), so the entry-by-entry finiteness scan runs on the failure path
 * only, where it picks the message. On failure the message names the first non-finite entry, or
 * else the first leading block that is not positive definite (found by factorising growing
 * blocks). */
NAV_KERNEL_CLONES static nav_status check_cov(nav_filter *f, const double *p, const char *what) {
  const size_t n = f->n;
#ifndef NDEBUG
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < i; ++j)
      assert(memcmp(&p[i * n + j], &p[j * n + i], sizeof *p) == 0);
#endif
  if (chol_ok(p, n, f->ld, f->L)) return NAV_OK;
  for (size_t i = 0; i < n * n; ++i)
    if (!isfinite(p[i])) {
      set_error(f, "%s: P(%zu,%zu) = %g is not finite", what, i / n, i % n, p[i]);
      return NAV_ERR_NUMERIC;
    }
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

/* Every entry of the n x n matrix p finite: x - x is +0.0 (all bits clear) for a finite x and
 * NaN otherwise, so the OR of the bits of p_i - p_i over the matrix is zero exactly when every
 * entry is finite; four lanes of independent ORs (no chain of floating-point adds), vectorised.
 * count = n * n is a compile-time constant in the instantiations. */
static NAV_ALWAYS_INLINE bool all_finite_nn(const double *p, const size_t count) {
  uint64_t acc[4] = {0, 0, 0, 0};
  const size_t blocks = count / 4;
  for (size_t q = 0; q < blocks; ++q)
    for (size_t c = 0; c < 4; ++c) {
      const double d = p[4 * q + c] - p[4 * q + c];
      uint64_t b;
      memcpy(&b, &d, sizeof b);
      acc[c] |= b;
    }
  for (size_t i = 4 * blocks; i < count; ++i) {
    const double d = p[i] - p[i];
    uint64_t b;
    memcpy(&b, &d, sizeof b);
    acc[0] |= b;
  }
  return (acc[0] | acc[1] | acc[2] | acc[3]) == 0;
}

NAV_KERNEL_CLONES static bool all_finite(const double *p, size_t n) {
  if (n == 15) return all_finite_nn(p, 225);
  if (n == 18) return all_finite_nn(p, 324);
  if (n == 21) return all_finite_nn(p, 441);
  return all_finite_nn(p, n * n);
}

/*
 * The guard of a propagated covariance. P+ = Phi (P + Q/2) Phi^T + Q/2 is a
 * congruence of a positive definite matrix plus a positive semi-definite one, so in exact
 * arithmetic it is positive definite whenever P was; in floating point it can lose that only when
 * P is already near singular (an eigenvalue within rounding of zero relative to its norm), which
 * the measurement updates, not the propagation, produce. So every step checks what is cheap and
 * catches a blow-up at once (every entry finite, the diagonal positive: a necessary condition),
 * and the full Cholesky proof runs on every COV_FULL_CHECK_EVERY-th step after the last full
 * proof (the updates prove every P they make: do_update) and whenever the cheap test fails, where
 * it decides and picks the message (check_cov). The checks never change a value, so a P that
 * stays positive definite gives the same numbers as a full proof at every step; a P that lost
 * definiteness is reported at the latest COV_FULL_CHECK_EVERY - 1 steps later, by the next
 * scheduled proof or by the next update's. The full proof on every step cost a quarter of the
 * covariance step.
 */
static nav_status check_cov_predict(nav_filter *f, const double *p) {
  const size_t n = f->n;
  f->cov_unproved++;
  if (f->cov_unproved < COV_FULL_CHECK_EVERY) {
    bool diag_ok = true;
    for (size_t i = 0; i < n; ++i)
      diag_ok &= p[i * (n + 1)] > 0.0;
    if (diag_ok && all_finite(p, n)) return NAV_OK;
  }
  const nav_status st = check_cov(f, p, "predict");
  if (st == NAV_OK) f->cov_unproved = 0;
  return st;
}

/*
 * acc[0..NV) = sum over p < cnt of a_p x_p, x_p = rows + col[p] * stride + c0 (4 NV doubles),
 * a_p = coef[col[p]] (times 0.5 when half): the first term a product, each further one a
 * multiply and an add, in pattern order. Entry by entry these are the operations of the
 * former full-row loops y = a x, y += a x (the values do not depend on how many columns are
 * computed).
 */
static NAV_ALWAYS_INLINE void combo(nav_v4 *acc, const double *coef, bool half, const unsigned char *col,
                                    unsigned cnt, const double *rows, size_t stride, size_t c0, const size_t NV) {
  {
    const size_t k = col[0];
    const nav_v4 a = v4_splat(half ? 0.5 * coef[k] : coef[k]);
    const double *x = rows + k * stride + c0;
    for (size_t q = 0; q < NV; ++q)
      acc[q] = v4_mul(a, v4_load(x + 4 * q));
  }
  for (unsigned p = 1; p < cnt; ++p) {
    const size_t k = col[p];
    const nav_v4 a = v4_splat(half ? 0.5 * coef[k] : coef[k]);
    const double *x = rows + k * stride + c0;
    for (size_t q = 0; q < NV; ++q)
      acc[q] = v4_add(acc[q], v4_mul(a, v4_load(x + 4 * q)));
  }
}

/* W row j, columns 0 .. 4 NV - 1: sum over the pattern of Phi_jk (row k of S). */
static NAV_ALWAYS_INLINE void w_row(double *wj, const double *phi_j, const unsigned char *col, unsigned cnt,
                                    const double *S, size_t LD, const size_t NV) {
  nav_v4 acc[NV_MAX];
  combo(acc, phi_j, false, col, cnt, S, LD, 0, NV);
  for (size_t q = 0; q < NV; ++q)
    v4_store(wj + 4 * q, acc[q]);
}

/* Row i of Phi W^T + Qh from column c0 = LD - 4 NV on: sum over the pattern of Phi_ik (row k of
 * W^T), then + Qh_ij (Qh unpadded, stride n: the columns past n read the next row or the rest
 * of the buffer, and land in columns that are never read). */
static NAV_ALWAYS_INLINE void upper_row(double *ui, const double *phi_i, const unsigned char *col, unsigned cnt,
                                        const double *Wt, const double *qh_i, size_t LD, const size_t NV) {
  const size_t c0 = LD - 4 * NV;
  nav_v4 acc[NV_MAX];
  combo(acc, phi_i, false, col, cnt, Wt, LD, c0, NV);
  for (size_t q = 0; q < NV; ++q)
    v4_store(ui + c0 + 4 * q, v4_add(acc[q], v4_load(qh_i + c0 + 4 * q)));
}

/* Row i of the second-order Phi, columns 0 .. 4 NV - 1: sum over the pattern of A of
 * (0.5 a_ik) (row k of A), then + 1.0 a_i (the axpy with 1.0 of before), then + 1 on the
 * diagonal. */
static NAV_ALWAYS_INLINE void phi2_row(double *phi_i, const double *ai, const unsigned char *col, unsigned cnt,
                                       const double *A, size_t LD, size_t i, const size_t NV) {
  nav_v4 acc[NV_MAX];
  combo(acc, ai, true, col, cnt, A, LD, 0, NV);
  const nav_v4 one = v4_splat(1.0);
  for (size_t q = 0; q < NV; ++q)
    v4_store(phi_i + 4 * q, v4_add(acc[q], v4_mul(one, v4_load(ai + 4 * q))));
  phi_i[i] += 1.0;
}

/* 4 x 4 block transpose: Wt[(j0 + c) LD + i0 + r] = W[(i0 + r) LD + j0 + c]. With GCC vector
 * extensions as four row loads, register shuffles and four column stores (the scalar transpose
 * took a quarter of the sandwich); only values move, so the result is the plain loop's. The
 * block is read before it is written: the two may be blocks of the same matrix (not the same
 * block). */
#if defined(__GNUC__) && !defined(__clang__)
typedef long long nav_v4i __attribute__((vector_size(32)));
static NAV_ALWAYS_INLINE void transpose4(double *Wt, const double *W, size_t i0, size_t j0, const size_t LD) {
  const nav_v4 r0 = v4_load(W + (i0 + 0) * LD + j0);
  const nav_v4 r1 = v4_load(W + (i0 + 1) * LD + j0);
  const nav_v4 r2 = v4_load(W + (i0 + 2) * LD + j0);
  const nav_v4 r3 = v4_load(W + (i0 + 3) * LD + j0);
  const nav_v4 t0 = __builtin_shuffle(r0, r1, (nav_v4i){0, 4, 2, 6});
  const nav_v4 t1 = __builtin_shuffle(r0, r1, (nav_v4i){1, 5, 3, 7});
  const nav_v4 t2 = __builtin_shuffle(r2, r3, (nav_v4i){0, 4, 2, 6});
  const nav_v4 t3 = __builtin_shuffle(r2, r3, (nav_v4i){1, 5, 3, 7});
  v4_store(Wt + (j0 + 0) * LD + i0, __builtin_shuffle(t0, t2, (nav_v4i){0, 1, 4, 5}));
  v4_store(Wt + (j0 + 1) * LD + i0, __builtin_shuffle(t1, t3, (nav_v4i){0, 1, 4, 5}));
  v4_store(Wt + (j0 + 2) * LD + i0, __builtin_shuffle(t0, t2, (nav_v4i){2, 3, 6, 7}));
  v4_store(Wt + (j0 + 3) * LD + i0, __builtin_shuffle(t1, t3, (nav_v4i){2, 3, 6, 7}));
}
#else
static NAV_ALWAYS_INLINE void transpose4(double *Wt, const double *W, size_t i0, size_t j0, const size_t LD) {
  for (size_t r = 0; r < 4; ++r)
    for (size_t c = 0; c < 4; ++c)
      Wt[(j0 + c) * LD + i0 + r] = W[(i0 + r) * LD + j0 + c];
}
#endif

/* Wt = W^T for rows 0 .. n - 1 and columns 0 .. cols - 1 of a padded W (stride LD), cols a
 * (rounded up to a multiple of 4). Blocks reach up to row round_up(n, 4) <= LD: the extra rows of W are scratch
 * (stale values), which land in padding columns of Wt that are never read. */
static NAV_ALWAYS_INLINE void transpose_ld(double *Wt, const double *W, size_t n, size_t cols, const size_t LD) {
  for (size_t i0 = 0; i0 < n; i0 += 4)
    for (size_t j0 = 0; j0 < cols; j0 += 4)
      transpose4(Wt, W, i0, j0, LD);
}

/*
 * Pn = Phi S Phi^T + Qh for a symmetric S (numerics.md 6.3), Phi given padded (stride LD) with
 * the row pattern pt. Every entry of the upper triangle gets the operations of the plain loops
 * W_jk = sum_p Phi_jp S_pk and (Phi W^T)_ij = sum_k Phi_ik W_jk over the pattern, in pattern
 * order, then + Qh_ij; the lower triangle is its mirror. What is not computed any more is only
 * what was computed and never read:
 *  - rows i >= pt->diag_from have the single entry Phi_ii = d_i (the sensor and GNSS states:
 *    Phi = [[Phi_nn, Phi_ns], [0, D]]). There W_jk = d_j S_jk, and for j >= i >= diag_from the
 *    entry is d_i W_ji = d_i (d_j S_ji) = d_i (d_j S_ij) (S is exactly symmetric: P is mirrored
 *    and Qh symmetric): a row of S times the diagonal of Phi, times d_i.
 *  - the other rows have their pattern in columns 0 .. pt->width - 1, so W is needed in those
 *    columns only (and its transpose in those rows);
 *  - a row of the upper triangle from column i rounded down to a multiple of 4 (one of the
 *    compile-time widths LD - c0).
 * The upper triangle is written straight into Pn (n x n, stride n), four entries at a time, then
 * mirrored there block by block (4 x 4 transposes at stride n). A row's stores end at column LD - 1,
 * so its last LD - n entries land in the first columns of the next row, or past the n x n matrix
 * (the buffer holds NMAX^2); those of the next row are either in its upper triangle, which that
 * row's own stores rewrite afterwards (they start at column i + 1 rounded down to a multiple of
 * 4), or in its lower triangle, which the mirror rewrites. A mirrored block whose columns reach
 * past n reads such entries, and writes them to rows >= n, past the matrix. (Before, the upper
 * triangle went into a padded scratch and was copied to Pn at the end: 90 loads and stores of 4
 * doubles per step at 18 states, an eighth of the sandwich's time.) S, W and Wt are padded
 * scratch. n is a compile-time constant in the instantiations for 15, 18 and 21 states.
 */
static NAV_ALWAYS_INLINE void sandwich_ld(double *Pn, const double *Phi, const row_pattern *pt,
                                          const double *S, const double *Qh, const size_t n, double *W,
                                          double *Wt, const size_t LD) {
  const size_t s0 = pt->diag_from, nvw = pt->width / 4;
  double d[NMAX + 4];
  for (size_t j = 0; j < n; ++j)
    d[j] = Phi[j * LD + j];
  for (size_t j = n; j < LD; ++j)
    d[j] = 0.0;
  if (s0 > 0) {
    for (size_t j = 0; j < s0; ++j) {
#define W_ROW(NV) w_row(W + j * LD, Phi + j * LD, pt->col[j], pt->cnt[j], S, LD, NV)
      NV_DISPATCH(nvw, W_ROW)
#undef W_ROW
    }
    for (size_t j = s0; j < n; ++j) {
      const nav_v4 dj = v4_splat(d[j]);
      for (size_t q = 0; q < nvw; ++q)
        v4_store(W + j * LD + 4 * q, v4_mul(dj, v4_load(S + j * LD + 4 * q)));
    }
    transpose_ld(Wt, W, n, pt->width, LD);
  }
  for (size_t i = 0; i < n; ++i) {
    const size_t c0 = i & ~(size_t)3, nv = (LD - c0) / 4;
    if (i < s0) {
#define U_ROW(NV) upper_row(Pn + i * n, Phi + i * LD, pt->col[i], pt->cnt[i], Wt, Qh + i * n, LD, NV)
      NV_DISPATCH(nv, U_ROW)
#undef U_ROW
    } else {
      const nav_v4 di = v4_splat(d[i]);
      for (size_t q = c0 / 4; q < LD / 4; ++q) {
        const nav_v4 dsd = v4_mul(di, v4_mul(v4_load(d + 4 * q), v4_load(S + i * LD + 4 * q)));
        v4_store(Pn + i * n + 4 * q, v4_add(dsd, v4_load(Qh + i * n + 4 * q)));
      }
    }
  }
  /* The lower triangle: the blocks left of the diagonal by 4 x 4 transposes of the blocks above
   * it, the diagonal blocks entry by entry (their rows and columns past n are past the matrix, or
   * entries rewritten as above). */
  for (size_t i0 = 0; i0 < n; i0 += 4) {
    for (size_t j0 = i0 + 4; j0 < n; j0 += 4)
      transpose4(Pn, Pn, i0, j0, n);
    double *u = Pn + i0 * n + i0;
    u[1 * n + 0] = u[0 * n + 1];
    u[2 * n + 0] = u[0 * n + 2];
    u[3 * n + 0] = u[0 * n + 3];
    u[2 * n + 1] = u[1 * n + 2];
    u[3 * n + 1] = u[1 * n + 3];
    u[3 * n + 2] = u[2 * n + 3];
  }
}

/* Phi = I + A + A^2/2 over the pattern of A (padded, stride LD), in the entries the sandwich and
 * pattern_mul_vec read (the pattern of Phi, pt): rows below pt->diag_from in columns 0 ..
 * pt->width - 1, the others (whose A row is the diagonal entry alone) on the diagonal only,
 * ((0.5 a_ii) a_ii + 1.0 a_ii) + 1 as the full-row code computed it. The other entries of Phi
 * are not written (the update uses Phi as scratch). */
static NAV_ALWAYS_INLINE void phi2_ld(double *Phi, const double *A, const row_pattern *ap, const row_pattern *pt,
                                      size_t n, const size_t LD) {
  const size_t s0 = pt->diag_from, nvw = pt->width / 4;
  for (size_t i = 0; i < s0; ++i) {
#define PHI_ROW(NV) phi2_row(Phi + i * LD, A + i * LD, ap->col[i], ap->cnt[i], A, LD, i, NV)
    NV_DISPATCH(nvw, PHI_ROW)
#undef PHI_ROW
  }
  for (size_t i = s0; i < n; ++i) {
    const double a = A[i * LD + i];
    Phi[i * LD + i] = ((0.5 * a) * a + 1.0 * a) + 1.0;
  }
}

/* The instantiations: LD 16 (up to 16 states: the 15-state core), 20 (17 to 20: the core with
 * the GNSS error states) and 24 (the rest), each also as an AVX2 clone (NAV_KERNEL_CLONES). The
 * padding only adds products of zeros to entries that are never read, so the values do not
 * depend on LD. */
NAV_KERNEL_CLONES static void pattern_sandwich(double *Pn, const double *Phi, const row_pattern *pt,
                                               const double *S, const double *Qh, size_t n, size_t ld,
                                               double *W, double *Wt) {
  if (n == 15 && ld == 16)
    sandwich_ld(Pn, Phi, pt, S, Qh, 15, W, Wt, 16);
  else if (n == 18 && ld == 20)
    sandwich_ld(Pn, Phi, pt, S, Qh, 18, W, Wt, 20);
  else if (n == 21 && ld == 24)
    sandwich_ld(Pn, Phi, pt, S, Qh, 21, W, Wt, 24);
  else if (ld == 16)
    sandwich_ld(Pn, Phi, pt, S, Qh, n, W, Wt, 16);
  else if (ld == 20)
    sandwich_ld(Pn, Phi, pt, S, Qh, n, W, Wt, 20);
  else
    sandwich_ld(Pn, Phi, pt, S, Qh, n, W, Wt, 24);
}

NAV_KERNEL_CLONES static void phi_second_order(double *Phi, const double *A, const row_pattern *ap,
                                               const row_pattern *pt, size_t n, size_t ld) {
  if (ld == 16)
    phi2_ld(Phi, A, ap, pt, n, 16);
  else if (ld == 20)
    phi2_ld(Phi, A, ap, pt, n, 20);
  else
    phi2_ld(Phi, A, ap, pt, n, 24);
}

/* y = Phi x over the pattern, skipping the terms whose x_k is zero: each sum starts at +0.0 and
 * so is never -0.0 (a round-to-nearest sum is -0.0 only from two negative zeros), and adding a
 * signed zero to a sum that is not -0.0 leaves it unchanged; so the result is bit for bit the
 * sum over the whole pattern (x is finite: every committed x is checked). In closed loop the INS
 * error states are reset to zero after each update, so only the GNSS states are left. */
static void pattern_mul_vec(double *y, const double *Phi, const row_pattern *pt, const double *x, size_t ld,
                            size_t n) {
  uint32_t xnz = 0;
  for (size_t k = 0; k < n; ++k)
    if (x[k] != 0.0) xnz |= UINT32_C(1) << k;
  for (size_t i = 0; i < n; ++i) {
    double sum = 0.0;
    uint32_t m = pt->mask[i] & xnz;
    while (m != 0) {
      const size_t k = (size_t)nav_ctz32(m);
      m &= m - 1;
      sum += Phi[i * ld + k] * x[k];
    }
    y[i] = sum;
  }
}

/* Row pattern of the non-zero values of a padded matrix (the Van Loan Phi is dense in general). */
static void pattern_of_values(row_pattern *pt, const double *a, size_t n, size_t ld) {
  for (size_t i = 0; i < n; ++i) {
    unsigned char c = 0;
    for (size_t j = 0; j < n; ++j)
      if (a[i * ld + j] != 0.0) pt->col[i][c++] = (unsigned char)j;
    pt->cnt[i] = c;
  }
  pattern_finish(pt, n, ld);
}

/* The inputs of the second-order step besides A = F T (pending_integrals writes it in place, over
 * the pattern of A, zeros elsewhere): for the fused E6.2, P+ = Phi (P + Q/2) Phi^T + Q/2,
 * Qd = Q/2 and S = P + Q/2 padded. Always
 * inlined: cov_step instantiates it for 15 and 18 states with compile-time bounds (unrolled
 * rows, no memset calls for the padding), and once generically; the same values either way. */
static NAV_ALWAYS_INLINE void second_order_inputs(nav_filter *f, const double *QT, const size_t n,
                                                  const size_t ld) {
  /* A = F T is already in place (pending_integrals): written only there and only over its
   * pattern, which is fixed at create, so every other entry (padding included) is still the zero
   * of calloc and the rows need no clearing (a rep stos per row cost a quarter of the step). */
  /* Qd = Q/2 only where QT can be non-zero (pending_integrals writes the diagonal, and the
   * velocity and attitude blocks when the noise is not isotropic): elsewhere both keep the zeros
   * of calloc (a filter with the second-order discretisation never writes Qd otherwise), so this
   * is 0.5 QT everywhere without a pass over all n^2 entries. Then the padded rows of S
   * (unrolled); S = P + Qd, as before, so that a -0.0 in P still becomes +0.0: where Qd is the
   * +0.0 of calloc this is P + 0.0 (the same bits without reading Qd), and the entries Qd can
   * hold are then added again from P. */
  for (size_t i = 0; i < n; ++i)
    f->Qd[i * (n + 1)] = 0.5 * QT[i * (n + 1)];
  if (!f->q_isotropic)
    for (size_t b = NAV_FILTER_IDX_DV; b <= NAV_FILTER_IDX_PHI; b += NAV_FILTER_IDX_PHI - NAV_FILTER_IDX_DV)
      for (size_t i = 0; i < 3; ++i)
        for (size_t j = 0; j < 3; ++j)
          f->Qd[(b + i) * n + b + j] = 0.5 * QT[(b + i) * n + b + j];
#ifndef NDEBUG
  for (size_t k = 0; k < n * n; ++k)
    assert(memcmp(&f->Qd[k], &(double){0.5 * QT[k]}, sizeof(double)) == 0);
#endif
  for (size_t i = 0; i < n; ++i) {
    NAV_UNROLL
    for (size_t j = 0; j < n; ++j)
      f->S[i * ld + j] = f->P[i * n + j] + 0.0;
    for (size_t c = n; c < ld; ++c)
      f->S[i * ld + c] = 0.0;
    f->S[i * ld + i] = f->P[i * (n + 1)] + f->Qd[i * (n + 1)];
  }
  if (!f->q_isotropic)
    for (size_t b = NAV_FILTER_IDX_DV; b <= NAV_FILTER_IDX_PHI; b += NAV_FILTER_IDX_PHI - NAV_FILTER_IDX_DV)
      for (size_t i = 0; i < 3; ++i)
        for (size_t j = 0; j < 3; ++j)
          f->S[(b + i) * ld + b + j] = f->P[(b + i) * n + b + j] + f->Qd[(b + i) * n + b + j];
}

/* One covariance step over the integrated FT = int F dt and QT = int G Q_c G^T dt. Commits x and
 * P only on success. */
NAV_KERNEL_CLONES static nav_status cov_step(nav_filter *f, const double *FT, const double *QT) {
  const size_t n = f->n, ld = f->ld;
  const row_pattern *pt = &f->phi_pat;
  row_pattern dyn;
  if (f->cfg.discretisation == NAV_FILTER_DISC_VAN_LOAN) {
    const nav_status st = nav_filter_van_loan(f->Qd, f->Pn, FT, QT, n, f->vl_work, NULL);
    if (st != NAV_OK) {
      set_error(f, "predict: Van Loan matrix exponential failed (%s)", nav_status_str(st));
      return st == NAV_ERR_INVALID_ARG ? NAV_ERR_INVALID_ARG : NAV_ERR_NUMERIC;
    }
    /* Phi (in Qd for the moment) to the padded Phi; Q_d (in Pn) to Qd. */
    pad_copy(f->Phi, f->Qd, n, ld);
    memcpy(f->Qd, f->Pn, n * n * sizeof *f->Qd);
    pattern_of_values(&dyn, f->Phi, n, ld);
    pt = &dyn;
    pad_copy(f->S, f->P, n, ld);
  } else {
    /* E6.2: Phi = I + A + A^2/2, A = F T, the square over the structural non-zeros of A. */
    if (n == 15)
      second_order_inputs(f, QT, 15, 16);
    else if (n == 18)
      second_order_inputs(f, QT, 18, 20);
    else if (n == 21)
      second_order_inputs(f, QT, 21, 24);
    else
      second_order_inputs(f, QT, n, ld);
    phi_second_order(f->Phi, f->A, &f->a_pat, &f->phi_pat, n, ld);
  }
  pattern_sandwich(f->Pn, f->Phi, pt, f->S, f->Qd, n, ld, f->W, f->Wt);
  const nav_status st = check_cov_predict(f, f->Pn);
  if (st != NAV_OK) return st;
  pattern_mul_vec(f->xn, f->Phi, pt, f->x, ld, n);
  commit_cov(f);
  memcpy(f->x, f->xn, n * sizeof *f->x);
  return NAV_OK;
}

/* |lat| below this has cos(lat) > 0.07, far from the MIN_COS_LAT limit: no cos needed. */
#define LAT_SAFE_RAD 1.5

/* Every number of a nav_filter_nav finite, by the test of all_finite_nn (x - x is +0.0 exactly
 * for finite x): the per-IMU-step check without a branch per number. */
_Static_assert(sizeof(nav_filter_nav) == 20 * sizeof(double), "nav_filter_nav is 20 doubles");
static bool nav_all_finite(const nav_filter_nav *nav) {
  double v[20];
  memcpy(v, nav, sizeof v);
  return all_finite_nn(v, 20);
}

static nav_status check_nav(nav_filter *f, const nav_filter_nav *nav, const char *what) {
  if (!nav_all_finite(nav)) {
    set_error(f, "%s: the navigation state (lat, h, v, C_b_n, f_b or w_ib_b) is not finite", what);
    return NAV_ERR_NUMERIC;
  }
  if (!(fabs(nav->lat_rad) <= LAT_SAFE_RAD) && !(fabs(cos(nav->lat_rad)) >= MIN_COS_LAT)) {
    set_error(
        f, "%s: latitude %.17g rad is within cos(lat) < %g of a pole; the NED error model is singular there",
        what, nav->lat_rad, MIN_COS_LAT);
    return NAV_ERR_OUT_OF_RANGE;
  }
  return NAV_OK;
}

static nav_mat3 mat3_axpy(nav_mat3 y, double a, nav_mat3 x) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      y.m[i][j] += a * x.m[i][j];
  return y;
}

/* C diag(q) C^T with exactly symmetric off-diagonal entries (as nav_filter_build_GQG). */
static nav_mat3 cqct(nav_mat3 C, const double *q) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      double s = 0.0;
      for (int k = 0; k < 3; ++k)
        s += C.m[i][k] * q[k] * C.m[j][k];
      r.m[i][j] = s;
      r.m[j][i] = s;
    }
  return r;
}

/* Add one IMU interval to the pending sums (struct pending). */
static void pending_add(const nav_filter *f, pending *pd, const nav_filter_nav *nav, double dt) {
  const nav_mat3 C = nav->C_b_n;
  pd->count++;
  pd->T += dt;
  pd->lat_T += nav->lat_rad * dt;
  pd->h_T += nav->h_m * dt;
  pd->v_T = nav_vec3_axpy(pd->v_T, dt, nav->v_eb_n_mps);
  pd->last_lat = nav->lat_rad;
  pd->last_h = nav->h_m;
  pd->last_v = nav->v_eb_n_mps;
  pd->fn_T = nav_vec3_axpy(pd->fn_T, dt, nav_mat3_mul_vec(C, nav->f_ib_b_mps2));
  pd->C_T = mat3_axpy(pd->C_T, dt, C);
  if (f->lay.has_scale_factors)
    for (int i = 0; i < 3; ++i) {
      pd->Cf_T.m[i][0] += C.m[i][0] * nav->f_ib_b_mps2.x * dt;
      pd->Cf_T.m[i][1] += C.m[i][1] * nav->f_ib_b_mps2.y * dt;
      pd->Cf_T.m[i][2] += C.m[i][2] * nav->f_ib_b_mps2.z * dt;
      pd->Cw_T.m[i][0] += C.m[i][0] * nav->w_ib_b_rps.x * dt;
      pd->Cw_T.m[i][1] += C.m[i][1] * nav->w_ib_b_rps.y * dt;
      pd->Cw_T.m[i][2] += C.m[i][2] * nav->w_ib_b_rps.z * dt;
    }
  if (!f->q_isotropic) {
    pd->Qa_T = mat3_axpy(pd->Qa_T, dt, cqct(C, f->qc + NAV_FILTER_IDX_DV));
    pd->Qg_T = mat3_axpy(pd->Qg_T, dt, cqct(C, f->qc + NAV_FILTER_IDX_PHI));
  }
}

/* Write the 3x3 block b (times s) into a (n columns) at (r, c). */
static void put_block(double *a, size_t n, size_t r, size_t c, nav_mat3 b, double s) {
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      a[(r + i) * n + c + j] = s * b.m[i][j];
}

/* F T and G Q_c G^T T of the pending interval into f->QT and, for the Van Loan discretisation,
 * f->FT; for the second-order one F T goes straight into the padded A = F T that cov_step's
 * Phi = I + A + A^2/2 reads (stride ld), at the same positions and with the same values (it was
 * written into FT and copied over the pattern, a scalar loop of a fifth of cov_step's own time). */
static void pending_integrals(nav_filter *f, const pending *pd) {
  const size_t n = f->n;
  const bool van_loan = f->cfg.discretisation == NAV_FILTER_DISC_VAN_LOAN;
  double *const FT = van_loan ? f->FT : f->A;
  const size_t ft_ld = van_loan ? n : f->ld;
  const double T = pd->T;
  nav_filter_nav m;
  memset(&m, 0, sizeof m);
  if (pd->count == 1) {
    m.lat_rad = pd->last_lat;
    m.h_m = pd->last_h;
    m.v_eb_n_mps = pd->last_v;
  } else {
    m.lat_rad = pd->lat_T / T;
    m.h_m = pd->h_T / T;
    m.v_eb_n_mps = nav_vec3_scale(pd->v_T, 1.0 / T);
  }
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(m.lat_rad, m.h_m);
  /* f->F holds the build of init_patterns or of the last step: the same entries are rewritten. */
  nav_filter_build_F_nonzero(f->F, &f->lay, &m, &earth, f->proc_diag);
  /* F T over the structural pattern of F only (fixed at create, init_patterns). Outside it F is
   * exactly zero, and FT and QT keep the zeros of calloc: both are written only here, always at
   * the same positions (the pattern, the blocks below, the diagonal), so the values are those of
   * a full pass after a clearing. The full passes cost more than the rest: their loads came right
   * behind the rep stos of the clearing, which cannot forward to them. */
  for (size_t i = 0; i < n; ++i)
    for (unsigned p = 0; p < f->a_pat.cnt[i]; ++p) {
      const size_t k = f->a_pat.col[i][p];
      FT[i * ft_ld + k] = f->F[i * n + k] * T;
    }
#ifndef NDEBUG
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < n; ++k) {
      bool in = false;
      for (unsigned p = 0; p < f->a_pat.cnt[i]; ++p)
        in = in || f->a_pat.col[i][p] == k;
      assert(in || (f->F[i * n + k] == 0.0 && !signbit(f->F[i * n + k])));
    }
#endif
  /* The blocks linear in C_b_n: their exact integrals. */
  put_block(FT, ft_ld, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_PHI, nav_mat3_skew(pd->fn_T), 1.0);
  put_block(FT, ft_ld, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_BA, pd->C_T, 1.0);
  put_block(FT, ft_ld, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_BG, pd->C_T, -1.0);
  if (f->lay.has_scale_factors) {
    put_block(FT, ft_ld, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_SA, pd->Cf_T, 1.0);
    put_block(FT, ft_ld, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_SG, pd->Cw_T, -1.0);
  }
  if (f->q_isotropic) {
    for (size_t i = 0; i < 3; ++i) {
      f->QT[(NAV_FILTER_IDX_DV + i) * (n + 1)] = f->qc[NAV_FILTER_IDX_DV] * T;
      f->QT[(NAV_FILTER_IDX_PHI + i) * (n + 1)] = f->qc[NAV_FILTER_IDX_PHI] * T;
    }
  } else {
    put_block(f->QT, n, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_DV, pd->Qa_T, 1.0);
    put_block(f->QT, n, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_PHI, pd->Qg_T, 1.0);
  }
  for (size_t i = NAV_FILTER_IDX_BG; i < n; ++i)
    f->QT[i * (n + 1)] = f->qc[i] * T;
}

/* nav_filter_predict after its checks of nav and dt_s. */
static nav_status predict_checked(nav_filter *f, const nav_filter_nav *nav, double dt_s) {
  /* Between covariance steps, accumulate in place. */
  if (f->pend.count + 1 < f->cfg.cov_decimation) {
    pending_add(f, &f->pend, nav, dt_s);
    return NAV_OK;
  }
  /* A covariance step: accumulate into a copy, so that a failing step leaves the pending sums
   * untouched. */
  pending pd = f->pend;
  pending_add(f, &pd, nav, dt_s);
  pending_integrals(f, &pd);
  const nav_status st = cov_step(f, f->FT, f->QT);
  if (st == NAV_OK) memset(&f->pend, 0, sizeof f->pend);
  return st;
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
  const nav_status st = check_nav(f, nav, "predict");
  if (st != NAV_OK) return st;
  return predict_checked(f, nav, dt_s);
}

nav_status nav_filter_predict_ins(nav_filter *f, const nav_filter_nav *nav, double dt_s) {
  assert(f != NULL && nav != NULL);
  /* x - x is +0.0 for a finite x and NaN otherwise, so the sum is +0.0 exactly when the six
   * numbers are finite. */
  const nav_vec3 a = nav->f_ib_b_mps2, w = nav->w_ib_b_rps;
  const double z = (a.x - a.x) + (a.y - a.y) + (a.z - a.z) + (w.x - w.x) + (w.y - w.y) + (w.z - w.z);
  if (!(z == 0.0) || !(dt_s > 0.0) || isinf(dt_s) || !(fabs(nav->lat_rad) <= LAT_SAFE_RAD))
    return nav_filter_predict(f, nav, dt_s); /* its checks decide and word the failure */
  return predict_checked(f, nav, dt_s);
}

nav_status nav_filter_flush(nav_filter *f) {
  assert(f != NULL);
  if (f == NULL) return NAV_ERR_INVALID_ARG;
  if (f->pend.count == 0) return NAV_OK;
  pending_integrals(f, &f->pend);
  const nav_status st = cov_step(f, f->FT, f->QT);
  if (st == NAV_OK) memset(&f->pend, 0, sizeof f->pend);
  return st;
}

/* ---------------------------------------------------------------- measurement update */

/* The arithmetic of an update (do_update): y, S and its Cholesky factor Ls, K, x+ into xn and the
 * Joseph-form P+ into Pn. Always inlined, so that do_update instantiates it for the GNSS cases
 * (n = 15, 18 or 21, m = 3) with compile-time bounds (loops unrolled, no loop control per product) and once
 * generically; the same operations in the same order either way, so the values are identical.
 * Returns false when S is not positive definite. */
/* out = base - X^T Y for n x n out and base and m x n X and Y (rows of n): row i of X^T Y is
 * sum_r X_ri Y_r, accumulated from +0.0 over r ascending, a whole row of n at a time. out must not
 * be X or Y (base may not be out either: it is read row by row after the sums). */
static NAV_ALWAYS_INLINE void sub_xty(double *restrict out, const double *base, const double *X, const double *Y,
                                      const size_t n, const size_t m) {
  double tmp[NMAX];
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j)
      tmp[j] = 0.0;
    NAV_UNROLL
    for (size_t r = 0; r < m; ++r) {
      const double x = X[r * n + i];
      for (size_t j = 0; j < n; ++j)
        tmp[j] += x * Y[r * n + j];
    }
    for (size_t j = 0; j < n; ++j)
      out[i * n + j] = base[i * n + j] - tmp[j];
  }
}

static NAV_ALWAYS_INLINE bool update_core(nav_filter *f, const size_t n, const size_t m, const double *H,
                                          const double *z, const double *R, double *y, double *S, double *Ls) {
  const double *P = f->P;
  /* Innovation y = z - H x_minus (x_minus = 0 in closed loop except the GNSS states). */
  NAV_UNROLL
  for (size_t r = 0; r < m; ++r) {
    double hx = 0.0;
    for (size_t j = 0; j < n; ++j)
      hx += H[r * n + j] * f->x[j];
    y[r] = z[r] - hx;
  }
  /* The columns of H with a non-zero entry (a position or velocity update touches 3 to 9 of
   * the n): the products with H run over them only, without a test per entry (adding the exact
   * zeros of the other rows changes no sum: every P entry is finite). */
  size_t hc[NMAX], nhc = 0;
  for (size_t j = 0; j < n; ++j) {
    bool nz = false;
    NAV_UNROLL
    for (size_t r = 0; r < m; ++r)
      nz = nz || H[r * n + j] != 0.0;
    if (nz) hc[nhc++] = j;
  }
  /* Every n x m product below is kept transposed (m x n, as PHtT, Kt, BHtT, WT), so that each
   * sum runs over the rows r or the columns hc of H for a whole row of n entries at a time
   * (vectorised), with, entry by entry, the operations and the order of the textbook loops: each
   * sum from +0.0 over r or q ascending, the products with their operands as before (a b = b a
   * exactly). */
  /* (P H^T)^T: PHtT_ri = sum_q P_i,hc_q H_r,hc_q; P is exactly symmetric (mirrored or
   * symmetrised wherever it is written), so P_i,c is P_c,i and the sum runs over rows of P. */
#ifndef NDEBUG
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < i; ++j)
      assert(memcmp(&P[i * n + j], &P[j * n + i], sizeof *P) == 0);
#endif
  double *PHtT = f->PHt;
  for (size_t r = 0; r < m; ++r) {
    double *o = PHtT + r * n;
    for (size_t i = 0; i < n; ++i)
      o[i] = 0.0;
    for (size_t q = 0; q < nhc; ++q) {
      const double h = H[r * n + hc[q]];
      const double *pc = P + hc[q] * n;
      for (size_t i = 0; i < n; ++i)
        o[i] += pc[i] * h;
    }
  }
  /* S = H P H^T + R, symmetrised. */
  NAV_UNROLL
  for (size_t r = 0; r < m; ++r)
    NAV_UNROLL
    for (size_t c = 0; c < m; ++c) {
      double sum = 0.0;
      for (size_t j = 0; j < n; ++j)
        sum += H[r * n + j] * PHtT[c * n + j];
      S[r * m + c] = sum + R[r * m + c];
    }
  /* Symmetrised as nav_matn_symmetrize, with the compile-time m. */
  NAV_UNROLL
  for (size_t r = 0; r < m; ++r)
    NAV_UNROLL
    for (size_t c = r + 1; c < m; ++c) {
      const double v = 0.5 * (S[r * m + c] + S[c * m + r]);
      S[r * m + c] = v;
      S[c * m + r] = v;
    }
  if (nav_matn_cholesky(Ls, S, m) != NAV_OK) return false;
  /* K^T = S^-1 (P H^T)^T by the Cholesky factor (never an explicit inverse). */
  double *Kt = f->Kt;
  memcpy(Kt, PHtT, m * n * sizeof *Kt);
  /* Kt := S^-1 Kt by the Cholesky factor of S: the operations and order of
     nav_matn_chol_solve(Kt, Ls, Kt, m, n), inlined with the compile-time m and n of update_core. */
  nav_chol_solve_rows_inline(Kt, Ls, m, n);

  /* x+ = x- + K y */
  for (size_t j = 0; j < n; ++j)
    f->xn[j] = f->x[j];
  NAV_UNROLL
  for (size_t r = 0; r < m; ++r)
    for (size_t j = 0; j < n; ++j)
      f->xn[j] += Kt[r * n + j] * y[r];
  /* Joseph form (E6.5): P+ = (I - K H) P (I - K H)^T + K R K^T, evaluated as (A P) A^T with
   * A = I - K H without forming A: A P = P - K (H P) with H P = (P H^T)^T, then
   * (A P) A^T = A P - ((A P) H^T) K^T over the non-zero columns of H. The same product in
   * O(n^2 m) instead of the 2 n^3 of a dense sandwich. A P goes to Phi, ((A P) H^T)^T to S
   * (both scratch here). */
  double *B = f->Phi, *BHtT = f->S;
  sub_xty(B, P, Kt, PHtT, n, m);
  for (size_t r = 0; r < m; ++r) {
    double *o = BHtT + r * n;
    for (size_t i = 0; i < n; ++i)
      o[i] = 0.0;
    for (size_t q = 0; q < nhc; ++q) {
      const double h = H[r * n + hc[q]];
      for (size_t i = 0; i < n; ++i)
        o[i] += B[i * n + hc[q]] * h;
    }
  }
  sub_xty(f->Pn, B, BHtT, Kt, n, m);
  /* K R K^T: (K R)^T = WT (m x n), then the upper triangle of W K^T, added to both triangles. */
  double *WT = f->W;
  NAV_UNROLL
  for (size_t c = 0; c < m; ++c) {
    double *o = WT + c * n;
    for (size_t i = 0; i < n; ++i)
      o[i] = 0.0;
    NAV_UNROLL
    for (size_t r = 0; r < m; ++r) {
      const double rr = R[r * m + c];
      for (size_t i = 0; i < n; ++i)
        o[i] += Kt[r * n + i] * rr;
    }
  }
  double tmp[NMAX];
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i; j < n; ++j)
      tmp[j] = 0.0;
    NAV_UNROLL
    for (size_t c = 0; c < m; ++c) {
      const double w = WT[c * n + i];
      for (size_t j = i; j < n; ++j)
        tmp[j] += w * Kt[c * n + j];
    }
    /* Added to both triangles and symmetrised as nav_matn_symmetrize would (v = (P_ij + P_ji) / 2
     * on both), in the same pass: the pair (i, j > i) is final once row i has added its term. */
    f->Pn[i * n + i] += tmp[i];
    for (size_t j = i + 1; j < n; ++j) {
      const double a = f->Pn[i * n + j] + tmp[j], b = f->Pn[j * n + i] + tmp[j];
      const double v = 0.5 * (a + b);
      f->Pn[i * n + j] = v;
      f->Pn[j * n + i] = v;
    }
  }
  return true;
}

/* Update with an m x n H, m measurements z and the m x m noise R (already checked finite and
 * positive definite). numerics.md 6.5. */
NAV_KERNEL_CLONES static nav_status do_update(nav_filter *f, size_t m, const double *H, const double *z,
                                              const double *R, const char *what) {
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

  double y[MMAX], S[MMAX * MMAX], Ls[MMAX * MMAX], u[MMAX];
  bool s_ok = false;
  if (n == 15 && m == 3)
    s_ok = update_core(f, 15, 3, H, z, R, y, S, Ls);
  else if (n == 18 && m == 3)
    s_ok = update_core(f, 18, 3, H, z, R, y, S, Ls);
  else if (n == 21 && m == 3)
    s_ok = update_core(f, 21, 3, H, z, R, y, S, Ls);
  else
    s_ok = update_core(f, n, m, H, z, R, y, S, Ls);
  if (!s_ok) {
    set_error(f, "%s: innovation covariance S = H P H^T + R is not positive definite", what);
    return NAV_ERR_NUMERIC;
  }
  /* Pn is symmetric already (update_core symmetrises it as it adds K R K^T). */
  for (size_t j = 0; j < n; ++j)
    if (!isfinite(f->xn[j])) {
      set_error(f, "%s: updated state x[%zu] is not finite", what, j);
      return NAV_ERR_NUMERIC;
    }
  st = check_cov(f, f->Pn, what);
  if (st != NAV_OK) return st;
  f->cov_unproved = 0;

  /* Commit, and keep y, S and the NIS y^T S^-1 y for consistency tests (T6.5). */
  commit_cov(f);
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

nav_status nav_filter_nis(nav_filter *f, size_t m, const double *H, const double *z, const double *R,
                          double *nis_out) {
  assert(f != NULL && H != NULL && z != NULL && R != NULL && nis_out != NULL);
  if (f == NULL || H == NULL || z == NULL || R == NULL || nis_out == NULL) return NAV_ERR_INVALID_ARG;
  if (m < 1 || m > MMAX) {
    set_error(f, "nis: m = %zu outside 1..%d", m, MMAX);
    return NAV_ERR_INVALID_ARG;
  }
  const size_t n = f->n;
  for (size_t i = 0; i < m * n; ++i)
    if (!isfinite(H[i])) {
      set_error(f, "nis: H is not finite");
      return NAV_ERR_NUMERIC;
    }
  for (size_t i = 0; i < m; ++i)
    if (!isfinite(z[i])) {
      set_error(f, "nis: measurement z[%zu] = %g is not finite", i, z[i]);
      return NAV_ERR_NUMERIC;
    }
  for (size_t i = 0; i < m * m; ++i)
    if (!isfinite(R[i])) {
      set_error(f, "nis: R is not finite");
      return NAV_ERR_NUMERIC;
    }
  nav_status st = nav_filter_flush(f);
  if (st != NAV_OK) return st;
  double y[MMAX], S[MMAX * MMAX], Ls[MMAX * MMAX], u[MMAX];
  for (size_t r = 0; r < m; ++r) {
    double hx = 0.0;
    for (size_t j = 0; j < n; ++j)
      hx += H[r * n + j] * f->x[j];
    y[r] = z[r] - hx;
  }
  for (size_t r = 0; r < m; ++r)
    for (size_t c = 0; c < m; ++c) {
      double sum = 0.0;
      for (size_t i = 0; i < n; ++i) {
        double ph = 0.0;
        for (size_t j = 0; j < n; ++j)
          ph += f->P[i * n + j] * H[c * n + j];
        sum += H[r * n + i] * ph;
      }
      S[r * m + c] = sum + R[r * m + c];
    }
  nav_matn_symmetrize(S, m);
  if (nav_matn_cholesky(Ls, S, m) != NAV_OK) {
    set_error(f, "nis: innovation covariance S = H P H^T + R is not positive definite");
    return NAV_ERR_NUMERIC;
  }
  nav_matn_chol_solve(u, Ls, y, m, 1);
  double nis = 0.0;
  for (size_t r = 0; r < m; ++r)
    nis += y[r] * u[r];
  *nis_out = nis;
  return NAV_OK;
}

/* ---------------------------------------------------------------- state access */

nav_status nav_filter_reset_errors(nav_filter *f) {
  assert(f != NULL);
  if (f == NULL) return NAV_ERR_INVALID_ARG;
  /* Only the INS blocks: the GNSS GM, receiver-clock and inter-system-bias states keep theirs. */
  const size_t end = f->lay.n_ins;
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
  f->cov_unproved = 0;
  commit_cov(f);
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
