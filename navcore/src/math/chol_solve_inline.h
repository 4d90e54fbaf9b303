/*
 * Solving (L L^T) X = B in place, X and B with @p cols columns stored row by row and L the
 * n_l x n_l lower Cholesky factor: forward substitution L Y = B, then back substitution
 * L^T X = Y, row by row, each row operation over all the columns. One copy of the operations for
 * nav_matn_chol_solve (math.c, sizes known at run time) and the filter's measurement update
 * (filter/ekf.c), which inlines it with compile-time sizes so that the compiler unrolls the row
 * loops; both give the same bits, since every entry gets the same operations in the same order.
 */
#ifndef NAV_CHOL_SOLVE_INLINE_H
#define NAV_CHOL_SOLVE_INLINE_H

#include <stddef.h>

#if defined(__GNUC__) || defined(__clang__)
#define NAV_CHOL_INLINE static __attribute__((always_inline)) inline
#else
#define NAV_CHOL_INLINE static inline
#endif
#if defined(__GNUC__) && !defined(__clang__)
#define NAV_CHOL_UNROLL _Pragma("GCC unroll 8")
#else
#define NAV_CHOL_UNROLL
#endif

NAV_CHOL_INLINE void nav_chol_solve_rows_inline(double *x, const double *l, const size_t n_l, const size_t cols) {
  NAV_CHOL_UNROLL
  for (size_t i = 0; i < n_l; ++i) {
    NAV_CHOL_UNROLL
    for (size_t k = 0; k < i; ++k) {
      const double lik = l[i * n_l + k];
      for (size_t c = 0; c < cols; ++c)
        x[i * cols + c] -= lik * x[k * cols + c];
    }
    const double lii = l[i * n_l + i];
    for (size_t c = 0; c < cols; ++c)
      x[i * cols + c] /= lii;
  }
  NAV_CHOL_UNROLL
  for (size_t ii = n_l; ii-- > 0;) {
    NAV_CHOL_UNROLL
    for (size_t k = ii + 1; k < n_l; ++k) {
      const double lki = l[k * n_l + ii]; /* (L^T)_ik */
      for (size_t c = 0; c < cols; ++c)
        x[ii * cols + c] -= lki * x[k * cols + c];
    }
    const double lii = l[ii * n_l + ii];
    for (size_t c = 0; c < cols; ++c)
      x[ii * cols + c] /= lii;
  }
}

#endif /* NAV_CHOL_SOLVE_INLINE_H */
