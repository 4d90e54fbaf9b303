/*
 * White-box tests of the fast paths of the filter's hot kernels (ekf.c) and of the batch normal
 * draws (rng.c): each one against its plain reference, bit for bit where the claim is "the same
 * values" (the Monte Carlo outputs must not move when a kernel gets faster), and the claim behind
 * the cheaper covariance check (a successful Cholesky proves P finite) over every position of the
 * upper triangle. Seeded; the seed is printed on failure.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "filter/ekf.c"
#include "navcore/nav_rng.h"
#include "rng/rng_internal.h"

#include "nav_test.h"

#define SEED UINT64_C(20261122)

/* The padded stride the filter uses for n states (init_patterns). */
static size_t ld_of(size_t n) {
  return n <= 16 ? 16 : (n <= 20 ? 20 : 24);
}

/* A random symmetric n x n matrix: B B^T + shift I (positive definite for shift > 0), exactly
 * symmetric (each entry computed once and mirrored). */
static void random_sym(double *a, size_t n, nav_rng *r, double shift) {
  double b[NN];
  for (size_t i = 0; i < n * n; ++i)
    b[i] = nav_rng_gauss(r);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      double s = i == j ? shift : 0.0;
      for (size_t k = 0; k < n; ++k)
        s += b[i * n + k] * b[j * n + k];
      a[i * n + j] = s;
      a[j * n + i] = s;
    }
}

/* The padded Cholesky check decides as the library's textbook Cholesky, on positive definite
 * and on indefinite matrices, for every padded width. */
static void test_chol_ok_matches_reference(void **state) {
  (void)state;
  static const size_t sizes[] = {15, 18, 21, 24};
  nav_rng r;
  nav_rng_init(&r, SEED, 0, 1);
  double a[NN], l[NN], work[NN];
  int pd = 0, indefinite = 0;
  for (size_t s = 0; s < sizeof sizes / sizeof *sizes; ++s) {
    const size_t n = sizes[s];
    for (int rep = 0; rep < 40; ++rep) {
      /* Shifts from clearly positive definite to clearly indefinite. */
      const double shift = (rep % 2 == 0) ? 1e-3 * (double)(rep + 1) : -(double)n * 0.4 * (double)rep;
      random_sym(a, n, &r, shift);
      const bool ref = nav_matn_cholesky(l, a, n) == NAV_OK;
      const bool got = chol_ok(a, n, ld_of(n), work);
      if (ref != got) fail_msg("seed %llu, n = %zu, rep %d: chol_ok %d, reference %d", (unsigned long long)SEED, n, rep, got, ref);
      pd += ref;
      indefinite += !ref;
    }
  }
  /* Both outcomes were exercised. */
  assert_true(pd > 10);
  assert_true(indefinite > 10);
}

/* check_cov skips the entry-by-entry finiteness scan when the Cholesky succeeds: that is sound
 * only if any non-finite entry of the upper triangle makes it fail. Every position, three values. */
static void test_chol_ok_rejects_any_non_finite_entry(void **state) {
  (void)state;
  static const size_t sizes[] = {15, 18, 24};
  const double bad[] = {NAN, INFINITY, -INFINITY};
  nav_rng r;
  nav_rng_init(&r, SEED, 0, 2);
  double a[NN], b[NN], work[NN];
  for (size_t s = 0; s < sizeof sizes / sizeof *sizes; ++s) {
    const size_t n = sizes[s];
    random_sym(a, n, &r, 1.0);
    assert_true(chol_ok(a, n, ld_of(n), work));
    for (size_t i = 0; i < n; ++i)
      for (size_t j = i; j < n; ++j)
        for (size_t v = 0; v < 3; ++v) {
          memcpy(b, a, n * n * sizeof *b);
          b[i * n + j] = bad[v];
          b[j * n + i] = bad[v];
          if (chol_ok(b, n, ld_of(n), work))
            fail_msg("n = %zu: P(%zu,%zu) = %g accepted by the Cholesky check", n, i, j, bad[v]);
        }
  }
}

/* The block transpose moves exactly the values of the plain loop. */
static void test_transpose_matches_plain(void **state) {
  (void)state;
  static const size_t sizes[] = {15, 16, 17, 18, 20, 21, 24};
  nav_rng r;
  nav_rng_init(&r, SEED, 0, 3);
  double w[NN], wt[NN];
  for (size_t s = 0; s < sizeof sizes / sizeof *sizes; ++s) {
    const size_t n = sizes[s], ld = ld_of(n);
    for (size_t i = 0; i < NN; ++i) {
      w[i] = nav_rng_gauss(&r);
      wt[i] = NAN;
    }
    if (ld == 16)
      transpose_ld(wt, w, n, n, 16);
    else if (ld == 20)
      transpose_ld(wt, w, n, n, 20);
    else
      transpose_ld(wt, w, n, n, 24);
    for (size_t i = 0; i < n; ++i)
      for (size_t j = 0; j < n; ++j)
        if (memcmp(&wt[j * ld + i], &w[i * ld + j], sizeof *w) != 0)
          fail_msg("n = %zu: Wt(%zu,%zu) = %.17g, W(%zu,%zu) = %.17g", n, j, i, wt[j * ld + i], i, j, w[i * ld + j]);
  }
}

/* The update's arithmetic written as the textbook loops (row-major n x m products, every sum
 * from +0.0 in index order over the non-zero columns of H where update_core uses them): P+ (Joseph
 * form, then symmetrised by nav_matn_symmetrize: the P+ of do_update), x+ and S. */
static void reference_update(const double *P, const double *x, const double *H, const double *z, const double *R,
                             size_t n, size_t m, double *Pn, double *xn, double *S) {
  static double PHt[NMAX * MMAX], K[NMAX * MMAX], Kt[MMAX * NMAX], B[NN], BHt[NMAX * MMAX], W[NMAX * MMAX];
  double y[MMAX], Ls[MMAX * MMAX];
  size_t hc[NMAX], nhc = 0;
  for (size_t r = 0; r < m; ++r) {
    double hx = 0.0;
    for (size_t j = 0; j < n; ++j)
      hx += H[r * n + j] * x[j];
    y[r] = z[r] - hx;
  }
  for (size_t j = 0; j < n; ++j) {
    bool nz = false;
    for (size_t r = 0; r < m; ++r)
      nz = nz || H[r * n + j] != 0.0;
    if (nz) hc[nhc++] = j;
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t r = 0; r < m; ++r) {
      double sum = 0.0;
      for (size_t q = 0; q < nhc; ++q)
        sum += P[i * n + hc[q]] * H[r * n + hc[q]];
      PHt[i * m + r] = sum;
    }
  for (size_t r = 0; r < m; ++r)
    for (size_t c = 0; c < m; ++c) {
      double sum = 0.0;
      for (size_t j = 0; j < n; ++j)
        sum += H[r * n + j] * PHt[j * m + c];
      S[r * m + c] = sum + R[r * m + c];
    }
  nav_matn_symmetrize(S, m);
  assert_int_equal(nav_matn_cholesky(Ls, S, m), NAV_OK);
  for (size_t r = 0; r < m; ++r)
    for (size_t j = 0; j < n; ++j)
      Kt[r * n + j] = PHt[j * m + r];
  nav_matn_chol_solve(Kt, Ls, Kt, m, n);
  for (size_t j = 0; j < n; ++j)
    for (size_t r = 0; r < m; ++r)
      K[j * m + r] = Kt[r * n + j];
  for (size_t j = 0; j < n; ++j) {
    double sum = x[j];
    for (size_t r = 0; r < m; ++r)
      sum += K[j * m + r] * y[r];
    xn[j] = sum;
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double sum = 0.0;
      for (size_t r = 0; r < m; ++r)
        sum += K[i * m + r] * PHt[j * m + r];
      B[i * n + j] = P[i * n + j] - sum;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t r = 0; r < m; ++r) {
      double sum = 0.0;
      for (size_t q = 0; q < nhc; ++q)
        sum += B[i * n + hc[q]] * H[r * n + hc[q]];
      BHt[i * m + r] = sum;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double sum = 0.0;
      for (size_t r = 0; r < m; ++r)
        sum += BHt[i * m + r] * K[j * m + r];
      Pn[i * n + j] = B[i * n + j] - sum;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t c = 0; c < m; ++c) {
      double sum = 0.0;
      for (size_t r = 0; r < m; ++r)
        sum += K[i * m + r] * R[r * m + c];
      W[i * m + c] = sum;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i; j < n; ++j) {
      double sum = 0.0;
      for (size_t c = 0; c < m; ++c)
        sum += W[i * m + c] * K[j * m + c];
      Pn[i * n + j] += sum;
      if (j != i) Pn[j * n + i] += sum;
    }
  /* do_update's symmetrisation of P+ (update_core does it as it adds K R K^T). */
  nav_matn_symmetrize(Pn, n);
}

/* The measurement update instantiated with compile-time sizes (n = 15, 18 or 21, m = 3) gives the
 * values of the generic code bit for bit: x+, P+, S and the innovation. */
static void check_update_instantiation(size_t n, uint64_t stream) {
  nav_filter *f = calloc(1, sizeof *f);
  nav_filter *g = calloc(1, sizeof *g);
  assert_non_null(f);
  assert_non_null(g);
  /* P and Pn point into the filter's own cov buffers (as nav_filter_create sets them). */
  f->P = f->cov[0];
  f->Pn = f->cov[1];
  nav_rng r;
  nav_rng_init(&r, SEED, 1, stream);
  f->n = n;
  random_sym(f->P, n, &r, 0.5);
  for (size_t i = 0; i < n; ++i)
    f->x[i] = 0.1 * nav_rng_gauss(&r);
  /* H: selection of states 0..2 plus lever-arm-like terms on 6..8 and, for 18 states, the
   * GNSS error states (the structure of a position update). */
  double H[MMAX * NMAX], z[3], R[9];
  memset(H, 0, sizeof H);
  memset(R, 0, sizeof R);
  for (size_t q = 0; q < 3; ++q) {
    H[q * n + q] = 1.0;
    for (size_t c = 6; c < 9; ++c)
      H[q * n + c] = nav_rng_gauss(&r);
    if (n == 18) H[q * n + 15 + q] = 1.0;
    z[q] = nav_rng_gauss(&r);
    R[q * 3 + q] = 0.5 + fabs(nav_rng_gauss(&r));
  }
  *g = *f;
  g->P = g->cov[0];
  g->Pn = g->cov[1];
  double yf[MMAX], Sf[MMAX * MMAX], Lf[MMAX * MMAX], yg[MMAX], Sg[MMAX * MMAX], Lg[MMAX * MMAX];
  /* The specialised instance, then the generic one (sizes the compiler cannot see). */
  const bool ok_f = n == 15   ? update_core(f, 15, 3, H, z, R, yf, Sf, Lf)
                    : n == 18 ? update_core(f, 18, 3, H, z, R, yf, Sf, Lf)
                              : update_core(f, 21, 3, H, z, R, yf, Sf, Lf);
  volatile size_t n_rt = n, m_rt = 3;
  const bool ok_g = update_core(g, n_rt, m_rt, H, z, R, yg, Sg, Lg);
  assert_true(ok_f);
  assert_true(ok_g);
  assert_memory_equal(f->Pn, g->Pn, n * n * sizeof *f->Pn);
  assert_memory_equal(f->xn, g->xn, n * sizeof *f->xn);
  assert_memory_equal(Sf, Sg, 9 * sizeof *Sf);
  assert_memory_equal(yf, yg, 3 * sizeof *yf);
  /* And both are the textbook loops' values (the transposed layouts change no operation). */
  static double Pr[NN];
  double xr[NMAX], Sr[MMAX * MMAX];
  reference_update(g->P, g->x, H, z, R, n, 3, Pr, xr, Sr);
  assert_memory_equal(f->Pn, Pr, n * n * sizeof *Pr);
  assert_memory_equal(f->xn, xr, n * sizeof *xr);
  assert_memory_equal(Sf, Sr, 9 * sizeof *Sr);
  free(f);
  free(g);
}

static void test_update_instantiations_bit_identical(void **state) {
  (void)state;
  for (uint64_t s = 0; s < 20; ++s) {
    check_update_instantiation(15, 10 + s);
    check_update_instantiation(18, 100 + s);
    check_update_instantiation(21, 200 + s);
  }
}

/* nav_rng_gauss_streams returns exactly the values of one nav_rng_gauss() call per deviate, in
 * stream order, and leaves each stream where those calls would (the wedge and tail paths
 * included: 2e5 draws per stream pass through both). */
static void test_gauss_streams_equal_single_draws(void **state) {
  (void)state;
  nav_rng a[3], b[3];
  for (unsigned s = 0; s < 3; ++s) {
    nav_rng_init(&a[s], SEED, 7, s);
    b[s] = a[s];
  }
  double u[6];
  long tails = 0;
  for (long it = 0; it < 100000; ++it) {
    nav_rng_gauss_streams(a, 3, 2, u);
    for (unsigned s = 0; s < 3; ++s)
      for (unsigned d = 0; d < 2; ++d) {
        const double v = nav_rng_gauss(&b[s]);
        if (memcmp(&v, &u[2 * s + d], sizeof v) != 0)
          fail_msg("seed %llu, draw %ld, stream %u: %.17g vs %.17g", (unsigned long long)SEED, it, s, u[2 * s + d], v);
        tails += fabs(v) > 3.6541528853610088;
      }
  }
  for (unsigned s = 0; s < 3; ++s)
    assert_memory_equal(a[s].s, b[s].s, sizeof a[s].s);
  assert_true(tails > 10);
}

/* The time update writes F T (into the padded A of the second-order step), QT and Qd only at
 * fixed positions and relies on the zeros of calloc elsewhere (pending_integrals,
 * second_order_inputs). After covariance steps the stored matrices must equal the full passes
 * they replace, bit for bit: A = F T outside the
 * blocks integrated from the sums, QT zero outside its diagonal and noise blocks, Qd = QT / 2
 * everywhere. Every layout, isotropic and per-axis noise. */
static void check_time_update_buffers(unsigned states, bool isotropic) {
  nav_filter_config c = nav_filter_config_default();
  c.states = states;
  c.cov_decimation = 3;
  c.gyro_bias_terms = NAV_FILTER_PROC_GM;
  c.gyro_bias_gm_sd_rps = nav_vec3_make(1e-4, 1e-4, 1e-4);
  c.gyro_bias_gm_tau_s = nav_vec3_make(300.0, 300.0, 300.0);
  if (!isotropic) {
    c.gyro_arw_rad_per_sqrt_s = nav_vec3_make(1e-4, 2e-4, 3e-4);
    c.accel_vrw_mps_per_sqrt_s = nav_vec3_make(1e-3, 2e-3, 1.5e-3);
  }
  if (states & NAV_FILTER_STATE_GNSS_POS_GM) {
    c.gnss_pos_gm_sd_m = nav_vec3_make(2.0, 2.0, 4.0);
    c.gnss_pos_gm_tau_s = nav_vec3_make(300.0, 300.0, 300.0);
    c.init.gnss_pos_sd_m = c.gnss_pos_gm_sd_m;
  }
  nav_filter *f = NULL;
  assert_int_equal(nav_filter_create(&c, &f), NAV_OK);
  const size_t n = f->n;
  nav_filter_nav g;
  g.lat_rad = 0.84;
  g.h_m = 520.0;
  g.v_eb_n_mps = nav_vec3_make(12.0, -7.5, 0.2);
  const nav_euler e = {0.05, -0.02, 2.1};
  g.C_b_n = nav_euler_to_dcm(e);
  g.f_ib_b_mps2 = nav_vec3_make(0.4, -0.3, -9.79);
  g.w_ib_b_rps = nav_vec3_make(0.01, -0.02, 0.15);
  for (int step = 0; step < 6; ++step) {
    double T = 0.0;
    for (int q = 0; q < 3; ++q) {
      T += 0.01; /* as pending_add sums it */
      assert_int_equal(nav_filter_predict(f, &g, 0.01), NAV_OK);
    }
    /* Positions that pending_integrals overwrites from the interval sums. */
    bool blk[NN];
    memset(blk, 0, sizeof blk);
    const size_t rows[] = {NAV_FILTER_IDX_DV, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_PHI};
    const size_t cols[] = {NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_BA, NAV_FILTER_IDX_BG, NAV_FILTER_IDX_SA, NAV_FILTER_IDX_SG};
    const size_t nblk = f->lay.has_scale_factors ? 5 : 3;
    for (size_t b = 0; b < nblk; ++b)
      for (size_t i = 0; i < 3; ++i)
        for (size_t j = 0; j < 3; ++j)
          blk[(rows[b] + i) * n + cols[b] + j] = true;
    for (size_t k = 0; k < n * n; ++k) {
      const double ft = f->F[k] * T, qd = 0.5 * f->QT[k];
      /* The second-order step's F T is the padded A (stride ld), written in place. */
      const double a_k = f->A[(k / n) * f->ld + k % n];
      if (!blk[k] && memcmp(&a_k, &ft, sizeof ft) != 0)
        fail_msg("n = %zu: A(%zu,%zu) = %g, F T = %g", n, k / n, k % n, a_k, ft);
      if (memcmp(&f->Qd[k], &qd, sizeof qd) != 0)
        fail_msg("n = %zu: Qd(%zu,%zu) = %g, QT / 2 = %g", n, k / n, k % n, f->Qd[k], qd);
      const size_t i = k / n, j = k % n;
      const bool noise_blk = i / 3 == j / 3 && (i / 3 == NAV_FILTER_IDX_DV / 3 || i / 3 == NAV_FILTER_IDX_PHI / 3);
      if (i != j && !noise_blk && memcmp(&f->QT[k], &(double){0.0}, sizeof(double)) != 0)
        fail_msg("n = %zu: QT(%zu,%zu) = %g outside the noise blocks", n, i, j, f->QT[k]);
    }
    /* A's padding columns: the +0.0 of calloc (phi_second_order reads whole padded rows). */
    for (size_t i = 0; i < n; ++i)
      for (size_t j = n; j < f->ld; ++j)
        if (memcmp(&f->A[i * f->ld + j], &(double){0.0}, sizeof(double)) != 0)
          fail_msg("n = %zu: A(%zu,%zu) padding = %g", n, i, j, f->A[i * f->ld + j]);
    /* Move along so that the next step sees other values. */
    g.v_eb_n_mps.x += 0.3;
    g.w_ib_b_rps.z = -g.w_ib_b_rps.z;
  }
  nav_filter_destroy(f);
}

static void test_time_update_buffers_match_full_passes(void **state) {
  (void)state;
  const unsigned layouts[] = {0u, NAV_FILTER_STATE_GNSS_POS_GM, NAV_FILTER_STATE_SCALE_FACTORS,
                              NAV_FILTER_STATE_SCALE_FACTORS | NAV_FILTER_STATE_GNSS_POS_GM};
  for (size_t l = 0; l < 4; ++l) {
    check_time_update_buffers(layouts[l], true);
    check_time_update_buffers(layouts[l], false);
  }
}

/* all_finite (the per-step part of the propagation guard) is false exactly when some entry is
 * NaN or infinite, at every position, for the instantiated and the generic sizes; extreme finite
 * values (DBL_MAX, subnormals, -0.0) are finite. */
static void test_all_finite_every_position(void **state) {
  (void)state;
  static const size_t sizes[] = {3, 15, 17, 18, 21, 24};
  const double bad[] = {NAN, INFINITY, -INFINITY};
  const double odd[] = {DBL_MAX, -DBL_MAX, 4.9e-324, -0.0, 0.0, 2.2250738585072014e-308};
  nav_rng r;
  nav_rng_init(&r, SEED, 0, 7);
  double a[NN];
  for (size_t s = 0; s < sizeof sizes / sizeof *sizes; ++s) {
    const size_t n = sizes[s];
    for (size_t i = 0; i < n * n; ++i)
      a[i] = nav_rng_gauss(&r) * 1e3;
    for (size_t i = 0; i < n * n; ++i) a[i] = odd[i % (sizeof odd / sizeof *odd)] + (i % 7 == 0 ? a[i] : 0.0);
    if (!all_finite(a, n)) fail_msg("n = %zu: a finite matrix reported non-finite", n);
    for (size_t pos = 0; pos < n * n; ++pos)
      for (size_t b = 0; b < 3; ++b) {
        const double keep = a[pos];
        a[pos] = bad[b];
        if (all_finite(a, n)) fail_msg("n = %zu: %g at entry %zu not seen", n, bad[b], pos);
        a[pos] = keep;
      }
  }
}

/* The sandwich computes only the columns j >= i rounded down to a multiple of 4 of Phi W^T:
 * every entry of Pn is, bit for bit, the plain loops' value with the same order of operations
 * (W = Phi S over the pattern, then Phi W^T + Qh), for all three padded widths. */
static void test_sandwich_matches_plain(void **state) {
  (void)state;
  static const size_t sizes[] = {15, 16, 17, 18, 20, 21, 24};
  nav_rng r;
  nav_rng_init(&r, SEED, 0, 8);
  static double phi[NN], sp[NN], qh[NN], pn[NN], w[NN], wt[NN], wref[NN];
  row_pattern pt;
  for (size_t s = 0; s < sizeof sizes / sizeof *sizes; ++s) {
    const size_t n = sizes[s], ld = ld_of(n);
    for (size_t rep = 0; rep < 20; ++rep) {
      memset(phi, 0, sizeof phi);
      memset(sp, 0, sizeof sp);
      /* A sparse Phi with its diagonal, about a third of the entries non-zero; in every other
       * repetition the rows from a random diag_tail on hold their diagonal alone (the sensor and
       * GNSS states of the filter), which the sandwich computes by its shorter path. */
      const size_t diag_tail = rep % 2 == 0 ? n : (size_t)(nav_rng_uniform(&r) * (double)n);
      for (size_t i = 0; i < n; ++i) {
        unsigned char c = 0;
        for (size_t j = 0; j < n; ++j)
          if (i == j || (i < diag_tail && nav_rng_uniform(&r) < 0.33)) {
            phi[i * ld + j] = nav_rng_gauss(&r);
            pt.col[i][c++] = (unsigned char)j;
          }
        pt.cnt[i] = c;
      }
      random_sym(qh, n, &r, 0.5);
      double tmp[NN];
      random_sym(tmp, n, &r, 1.0);
      for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j)
          sp[i * ld + j] = tmp[i * n + j];
      for (size_t i = 0; i < NN; ++i)
        pn[i] = NAN;
      pattern_finish(&pt, n, ld);
      pattern_sandwich(pn, phi, &pt, sp, qh, n, ld, w, wt);
      for (size_t i = 0; i < n; ++i)
        for (size_t c = 0; c < n; ++c) {
          double v = phi[i * ld + pt.col[i][0]] * sp[pt.col[i][0] * ld + c];
          for (unsigned p = 1; p < pt.cnt[i]; ++p)
            v += phi[i * ld + pt.col[i][p]] * sp[pt.col[i][p] * ld + c];
          wref[i * n + c] = v;
        }
      for (size_t i = 0; i < n; ++i)
        for (size_t j = i; j < n; ++j) {
          double v = phi[i * ld + pt.col[i][0]] * wref[j * n + pt.col[i][0]];
          for (unsigned p = 1; p < pt.cnt[i]; ++p)
            v += phi[i * ld + pt.col[i][p]] * wref[j * n + pt.col[i][p]];
          v += qh[i * n + j];
          if (memcmp(&pn[i * n + j], &v, sizeof v) != 0 || memcmp(&pn[j * n + i], &v, sizeof v) != 0)
            fail_msg("n = %zu, rep %zu: Pn(%zu,%zu) = %.17g / %.17g, plain %.17g", n, rep, i, j, pn[i * n + j],
                     pn[j * n + i], v);
        }
    }
  }
}

/* A filter at rest at 45 deg latitude with covariance step every predict. */
static nav_filter_nav guard_nav(void) {
  nav_filter_nav g;
  memset(&g, 0, sizeof g);
  g.lat_rad = 0.785;
  g.h_m = 100.0;
  g.C_b_n = nav_euler_to_dcm((nav_euler){0.0, 0.0, 0.3});
  g.f_ib_b_mps2 = nav_vec3_make(0.0, 0.0, -9.8);
  return g;
}

/* The propagation guard: a P that is not positive definite although its diagonal is positive and
 * every entry finite (a 3 x 3 correlation block with eigenvalue -0.8) is reported as
 * NAV_ERR_NUMERIC by at most COV_FULL_CHECK_EVERY covariance steps, with the message of the full
 * check, and P is left as it was; a non-finite entry or a non-positive diagonal is reported by
 * the very next step; an update on such a P always reports it (the updated P is fully checked). */
static void test_predict_guard_reports_lost_definiteness(void **state) {
  (void)state;
  const nav_filter_nav g = guard_nav();
  for (int variant = 0; variant < 4; ++variant) {
    nav_filter_config c = nav_filter_config_default();
    nav_filter *f = NULL;
    assert_int_equal(nav_filter_create(&c, &f), NAV_OK);
    const size_t n = f->n;
    /* Some steps with a valid P first: the counter is part of the state. */
    for (int k = 0; k < 5; ++k)
      assert_int_equal(nav_filter_predict(f, &g, 0.01), NAV_OK);
    const double rho = 0.9;
    const double blk[3][3] = {{1.0, rho, rho}, {rho, 1.0, -rho}, {rho, -rho, 1.0}};
    for (size_t i = 0; i < 3; ++i)
      for (size_t j = 0; j < 3; ++j)
        f->P[i * n + j] = blk[i][j];
    if (variant == 1) f->P[1 * n + 7] = f->P[7 * n + 1] = NAN;
    if (variant == 2) f->P[4 * n + 4] = -1e-3;
    double before[NN];
    if (variant == 3) {
      /* A position update (H = [I 0]) on the indefinite P. */
      double Hm[3 * NMAX];
      memset(Hm, 0, sizeof Hm);
      for (size_t i = 0; i < 3; ++i)
        Hm[i * n + i] = 1.0;
      const double z[3] = {0.1, -0.2, 0.3}, R[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      memcpy(before, f->P, n * n * sizeof *before);
      const nav_status st = nav_filter_update_linear(f, 3, Hm, z, R);
      assert_int_equal(st, NAV_ERR_NUMERIC);
      assert_memory_equal(before, f->P, n * n * sizeof *before);
      nav_filter_destroy(f);
      continue;
    }
    int failed_at = -1;
    for (int k = 1; k <= (int)COV_FULL_CHECK_EVERY && failed_at < 0; ++k) {
      memcpy(before, f->P, n * n * sizeof *before);
      const nav_status st = nav_filter_predict(f, &g, 0.01);
      if (st != NAV_OK) {
        assert_int_equal(st, NAV_ERR_NUMERIC);
        assert_memory_equal(before, f->P, n * n * sizeof *before);
        failed_at = k;
      }
    }
    print_message("[ guard    ] variant %d: reported at covariance step %d: %s\n", variant, failed_at,
                  nav_filter_last_error(f));
    if (failed_at < 0) fail_msg("variant %d: not reported within %u steps", variant, COV_FULL_CHECK_EVERY);
    if (variant == 0) assert_non_null(strstr(nav_filter_last_error(f), "not positive definite"));
    if (variant == 1) {
      assert_int_equal(failed_at, 1);
      assert_non_null(strstr(nav_filter_last_error(f), "not finite"));
    }
    if (variant == 2) assert_int_equal(failed_at, 1);
    nav_filter_destroy(f);
  }
}

/* check_nav tests the 20 numbers of a nav_filter_nav at once: NaN or an infinity at any one of
 * them is refused (NAV_ERR_NUMERIC, the predict leaves the filter as it was), finite extremes
 * are accepted. */
static void test_check_nav_every_position(void **state) {
  (void)state;
  nav_filter_config c = nav_filter_config_default();
  nav_filter *f = NULL;
  assert_int_equal(nav_filter_create(&c, &f), NAV_OK);
  nav_filter_nav g;
  g.lat_rad = 0.7;
  g.h_m = -12.0;
  g.v_eb_n_mps = nav_vec3_make(DBL_MAX, -0.0, 4.9e-324);
  g.C_b_n = nav_euler_to_dcm((nav_euler){0.1, 0.2, 0.3});
  g.f_ib_b_mps2 = nav_vec3_make(0.1, -0.2, -9.8);
  g.w_ib_b_rps = nav_vec3_make(-DBL_MAX, 0.0, 1e-300);
  assert_int_equal(check_nav(f, &g, "test"), NAV_OK);
  const double bad[] = {NAN, INFINITY, -INFINITY};
  for (size_t pos = 0; pos < 20; ++pos)
    for (size_t b = 0; b < 3; ++b) {
      double v[20];
      memcpy(v, &g, sizeof v);
      v[pos] = bad[b];
      nav_filter_nav h;
      memcpy(&h, v, sizeof h);
      if (check_nav(f, &h, "test") != NAV_ERR_NUMERIC) fail_msg("number %zu = %g of the navigation state accepted", pos, bad[b]);
      assert_non_null(strstr(nav_filter_last_error(f), "not finite"));
    }
  nav_filter_destroy(f);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_chol_ok_matches_reference),
      cmocka_unit_test(test_chol_ok_rejects_any_non_finite_entry),
      cmocka_unit_test(test_transpose_matches_plain),
      cmocka_unit_test(test_update_instantiations_bit_identical),
      cmocka_unit_test(test_gauss_streams_equal_single_draws),
      cmocka_unit_test(test_time_update_buffers_match_full_passes),
      cmocka_unit_test(test_all_finite_every_position),
      cmocka_unit_test(test_sandwich_matches_plain),
      cmocka_unit_test(test_predict_guard_reports_lost_definiteness),
      cmocka_unit_test(test_check_nav_every_position),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
