/**
 * @file expm.c
 * @brief Matrix exponential (scaling and squaring, Pade) and the Van Loan discretisation.
 *
 * Reference: N. J. Higham, "The scaling and squaring method for the matrix exponential
 * revisited", SIAM J. Matrix Anal. Appl. 26(4), 2005 (algorithm 2.3 and table 2.3); also the
 * basis of MATLAB's expm (before 2009) and SciPy's. Van Loan: IEEE TAC 23(3), 1978.
 */
#include <assert.h>
#include <math.h>
#include <string.h>

#include "filter/filter_internal.h"

/* theta_m of Higham (2005) table 2.3: the largest 1-norm for which the degree-m Pade approximant
 * has backward error <= 2^-53 (unit roundoff) in exact arithmetic. */
static const double theta3 = 1.495585217958292e-2;
static const double theta5 = 2.539398330063230e-1;
static const double theta7 = 9.504178996162932e-1;
static const double theta9 = 2.097847961257068e0;
static const double theta13 = 5.371920351148152e0;

/* Pade coefficients b_0..b_m of the numerator p_m(x) = sum b_j x^j (denominator p_m(-x)),
 * Higham (2005) eq. 2.5, scaled to integers as in that paper. All are exact in binary64. */
static const double pade3[4] = {120.0, 60.0, 12.0, 1.0};
static const double pade5[6] = {30240.0, 15120.0, 3360.0, 420.0, 30.0, 1.0};
static const double pade7[8] = {17297280.0, 8648640.0, 1995840.0, 277200.0, 25200.0, 1512.0, 56.0, 1.0};
static const double pade9[10] = {17643225600.0, 8821612800.0, 2075673600.0, 302702400.0, 30270240.0,
                                 2162160.0,     110880.0,     3960.0,       90.0,        1.0};
static const double pade13[14] = {64764752532480000.0,
                                  32382376266240000.0,
                                  7771770303897600.0,
                                  1187353796428800.0,
                                  129060195264000.0,
                                  10559470521600.0,
                                  670442572800.0,
                                  33522128640.0,
                                  1323241920.0,
                                  40840800.0,
                                  960960.0,
                                  16380.0,
                                  182.0,
                                  1.0};

size_t nav_expm_work_size(size_t n) {
  return 7 * n * n + n;
}

size_t nav_van_loan_work_size(size_t n) {
  return 2 * (2 * n) * (2 * n) + nav_expm_work_size(2 * n);
}

static double norm1(const double *a, size_t n) {
  double best = 0.0;
  for (size_t j = 0; j < n; ++j) {
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
      s += fabs(a[i * n + j]);
    if (s > best || isnan(s)) best = s;
  }
  return best;
}

/* C = A B (n x n) in i-k-j order, skipping exact zeros of A. The Van Loan matrix is block upper
 * triangular with a sparse F, so its powers keep many exact zeros and this halves the work or
 * better; with finite operands skipping 0 * b changes no value (at most the sign of a zero). */
static void mul_skip(double *c, const double *a, const double *b, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    double *ci = c + i * n;
    for (size_t j = 0; j < n; ++j)
      ci[j] = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const double aik = a[i * n + k];
      if (aik == 0.0) continue;
      const double *bk = b + k * n;
      for (size_t j = 0; j < n; ++j)
        ci[j] += aik * bk[j];
    }
  }
}

/* out = sum_k c[k] * mats[k] + c_id * I (all n x n). */
static void lincomb(double *out, size_t n, size_t count, const double *const *mats, const double *c,
                    double c_id) {
  for (size_t i = 0; i < n * n; ++i) {
    double s = 0.0;
    for (size_t k = 0; k < count; ++k)
      s += c[k] * mats[k][i];
    out[i] = s;
  }
  for (size_t i = 0; i < n; ++i)
    out[i * n + i] += c_id;
}

/* In-place LU with partial pivoting of the n x n matrix a (Golub & Van Loan, Matrix Computations,
 * 4th ed., algorithm 3.4.1); piv[k] holds the row swapped with k, stored as a double (exact for
 * n <= 2^53). Returns false if a pivot is zero or not finite. */
static bool lu_factor(double *a, double *piv, size_t n) {
  for (size_t k = 0; k < n; ++k) {
    size_t p = k;
    double best = fabs(a[k * n + k]);
    for (size_t i = k + 1; i < n; ++i)
      if (fabs(a[i * n + k]) > best) {
        best = fabs(a[i * n + k]);
        p = i;
      }
    if (!(best > 0.0) || !isfinite(best)) return false;
    piv[k] = (double)p;
    if (p != k)
      for (size_t j = 0; j < n; ++j) {
        const double t = a[k * n + j];
        a[k * n + j] = a[p * n + j];
        a[p * n + j] = t;
      }
    const double inv = 1.0 / a[k * n + k];
    for (size_t i = k + 1; i < n; ++i) {
      const double l = a[i * n + k] * inv;
      a[i * n + k] = l;
      if (l != 0.0)
        for (size_t j = k + 1; j < n; ++j)
          a[i * n + j] -= l * a[k * n + j];
    }
  }
  return true;
}

/* Solve A X = B in place in b (n x n right-hand sides) with the factor of lu_factor(). */
static void lu_solve(double *b, const double *lu, const double *piv, size_t n) {
  for (size_t k = 0; k < n; ++k) {
    const size_t p = (size_t)piv[k];
    if (p != k)
      for (size_t c = 0; c < n; ++c) {
        const double t = b[k * n + c];
        b[k * n + c] = b[p * n + c];
        b[p * n + c] = t;
      }
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t k = 0; k < i; ++k) {
      const double l = lu[i * n + k];
      if (l != 0.0)
        for (size_t c = 0; c < n; ++c)
          b[i * n + c] -= l * b[k * n + c];
    }
  for (size_t ii = n; ii-- > 0;) {
    for (size_t k = ii + 1; k < n; ++k) {
      const double u = lu[ii * n + k];
      if (u != 0.0)
        for (size_t c = 0; c < n; ++c)
          b[ii * n + c] -= u * b[k * n + c];
    }
    const double inv = 1.0 / lu[ii * n + ii];
    for (size_t c = 0; c < n; ++c)
      b[ii * n + c] *= inv;
  }
}

nav_status nav_expm(double *E, const double *A, size_t n, double *work, nav_expm_info *info) {
  assert(E != NULL && A != NULL && work != NULL);
  if (E == NULL || A == NULL || work == NULL || n == 0 || n > NAV_EXPM_MAX_DIM) return NAV_ERR_INVALID_ARG;
  for (size_t i = 0; i < n * n; ++i)
    if (!isfinite(A[i])) return NAV_ERR_NUMERIC;

  const size_t nn = n * n;
  double *As = work, *A2 = work + nn, *A4 = work + 2 * nn, *A6 = work + 3 * nn;
  double *T1 = work + 4 * nn, *T2 = work + 5 * nn, *V = work + 6 * nn, *piv = work + 7 * nn;

  const double nrm = norm1(A, n);
  unsigned m = 13, s = 0;
  const double *b = pade13;
  if (nrm <= theta3) {
    m = 3;
    b = pade3;
  } else if (nrm <= theta5) {
    m = 5;
    b = pade5;
  } else if (nrm <= theta7) {
    m = 7;
    b = pade7;
  } else if (nrm <= theta9) {
    m = 9;
    b = pade9;
  } else {
    /* s = ceil(log2(nrm / theta13)), exactly: frexp gives nrm/theta13 = fr 2^e, fr in [0.5, 1). */
    int e = 0;
    const double fr = frexp(nrm / theta13, &e);
    const int si = (fr == 0.5) ? e - 1 : e;
    s = si > 0 ? (unsigned)si : 0u;
  }
  /* Scaling by 2^-s is exact. */
  const double scale = ldexp(1.0, -(int)s);
  for (size_t i = 0; i < nn; ++i)
    As[i] = A[i] * scale;

  mul_skip(A2, As, As, n);
  double *U = T1;
  if (m == 13) {
    /* Higham (2005) eq. 2.6 for m = 13: six products and one solve.
     * U = A [A6 (b13 A6 + b11 A4 + b9 A2) + b7 A6 + b5 A4 + b3 A2 + b1 I]
     * V =    A6 (b12 A6 + b10 A4 + b8 A2) + b6 A6 + b4 A4 + b2 A2 + b0 I */
    mul_skip(A4, A2, A2, n);
    mul_skip(A6, A4, A2, n);
    const double *pw[3] = {A6, A4, A2};
    const double cu1[3] = {b[13], b[11], b[9]};
    lincomb(T1, n, 3, pw, cu1, 0.0);
    mul_skip(T2, A6, T1, n);
    const double cu2[3] = {b[7], b[5], b[3]};
    lincomb(T1, n, 3, pw, cu2, b[1]);
    for (size_t i = 0; i < nn; ++i)
      T2[i] += T1[i];
    mul_skip(U, As, T2, n); /* U in T1 */
    const double cv1[3] = {b[12], b[10], b[8]};
    lincomb(T2, n, 3, pw, cv1, 0.0);
    mul_skip(V, A6, T2, n);
    const double cv2[3] = {b[6], b[4], b[2]};
    lincomb(T2, n, 3, pw, cv2, b[0]);
    for (size_t i = 0; i < nn; ++i)
      V[i] += T2[i];
  } else {
    /* Degrees 3..9: powers A2, A4, A6, A8 as needed (A8 in T2). */
    const double *pw[4] = {A2, A4, A6, T2};
    size_t np = (m - 1) / 2; /* number of even powers used: 1, 2, 3, 4 */
    if (np >= 2) mul_skip(A4, A2, A2, n);
    if (np >= 3) mul_skip(A6, A4, A2, n);
    if (np >= 4) mul_skip(T2, A6, A2, n);
    double cu[4] = {0}, cv[4] = {0};
    for (size_t k = 0; k < np; ++k) {
      cu[k] = b[2 * k + 3];
      cv[k] = b[2 * k + 2];
    }
    /* V, then the odd polynomial (in E, free until the solve) and U = A (odd polynomial). */
    lincomb(V, n, np, pw, cv, b[0]);
    lincomb(E, n, np, pw, cu, b[1]);
    mul_skip(U, As, E, n);
  }

  /* (V - U) X = (V + U): the denominator in T2 (factored in place), the right-hand side in E. */
  for (size_t i = 0; i < nn; ++i) {
    T2[i] = V[i] - U[i];
    E[i] = V[i] + U[i];
  }
  if (!lu_factor(T2, piv, n)) return NAV_ERR_NUMERIC;
  lu_solve(E, T2, piv, n);

  /* Undo the scaling: E <- E^(2^s), ping-ponging through As. */
  for (unsigned k = 0; k < s; ++k) {
    mul_skip(As, E, E, n);
    memcpy(E, As, nn * sizeof *E);
  }
  for (size_t i = 0; i < nn; ++i)
    if (!isfinite(E[i])) return NAV_ERR_NUMERIC;
  if (info != NULL) {
    info->pade_degree = m;
    info->squarings = s;
  }
  return NAV_OK;
}

nav_status nav_filter_van_loan(double *Phi, double *Qd, const double *FT, const double *QT, size_t n,
                               double *work, nav_expm_info *info) {
  assert(Phi != NULL && Qd != NULL && FT != NULL && QT != NULL && work != NULL);
  if (Phi == NULL || Qd == NULL || FT == NULL || QT == NULL || work == NULL || n == 0 ||
      2 * n > NAV_EXPM_MAX_DIM)
    return NAV_ERR_INVALID_ARG;
  const size_t n2 = 2 * n;
  double *M = work, *E = work + n2 * n2, *ework = work + 2 * n2 * n2;

  /* E12 is linear in the Q block (M is block upper triangular), so scale QT by a power of two
   * alpha (exact) to the norm of FT: the Pade degree and the number of squarings are then set by
   * the dynamics alone, whatever the units of Q. */
  const double nf = norm1(FT, n), nq = norm1(QT, n);
  double alpha = 1.0;
  if (nq > 0.0 && isfinite(nq)) {
    const double target = nf > 0.0 ? nf : 1.0;
    /* The exponent is bounded only so that alpha itself stays a normal double; any alpha gives
     * the same Q_d in exact arithmetic. */
    const double e2 = fmin(fmax(round(log2(target / nq)), -960.0), 960.0);
    alpha = ldexp(1.0, (int)e2);
  }

  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      M[i * n2 + j] = -FT[i * n + j];
      M[i * n2 + n + j] = alpha * QT[i * n + j];
      M[(n + i) * n2 + j] = 0.0;
      M[(n + i) * n2 + n + j] = FT[j * n + i];
    }
  const nav_status st = nav_expm(E, M, n2, ework, info);
  if (st != NAV_OK) return st;

  /* Phi = E22^T; Q_d = Phi E12 / alpha (E6.1). */
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      Phi[i * n + j] = E[(n + j) * n2 + n + i];
  const double inv_alpha = 1.0 / alpha;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double sum = 0.0;
      for (size_t k = 0; k < n; ++k)
        sum += Phi[i * n + k] * E[k * n2 + n + j];
      Qd[i * n + j] = sum * inv_alpha;
    }
  nav_matn_symmetrize(Qd, n);
  return NAV_OK;
}
