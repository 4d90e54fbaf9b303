/*
 * Overlapping Allan deviation (numerics.md 2.5; IEEE Std 952-1997 Annex C; W. J. Riley, Handbook
 * of Frequency Stability Analysis, NIST SP 1065, 2008, eq. 14 with phase data).
 */
#include "navcore/nav_sensors.h"

#include <math.h>

nav_status nav_allan_overlapping(const double *rate, size_t n, double dt_s, const size_t *m, size_t n_m,
                                 double *work, double *adev_out) {
  if (n_m == 0) return NAV_OK;
  if (rate == NULL || m == NULL || work == NULL || adev_out == NULL || n < 2) return NAV_ERR_INVALID_ARG;
  if (!(isfinite(dt_s) && dt_s > 0.0)) return NAV_ERR_INVALID_ARG;
  for (size_t i = 0; i < n_m; ++i)
    if (m[i] < 1 || m[i] > n / 2) return NAV_ERR_INVALID_ARG;

  double sum = 0.0;
  for (size_t i = 0; i < n; ++i)
    sum += rate[i];
  if (!isfinite(sum)) return NAV_ERR_NUMERIC;
  const double mean = sum / (double)n;

  /* Phase in units of rate x samples (the factor dt cancels against tau = m dt below). Removing
   * the mean keeps theta a zero-mean walk: with a large constant rate (a biased gyro, an
   * accelerometer sensing g) theta would grow linearly and its second differences would lose
   * digits to cancellation. */
  work[0] = 0.0;
  for (size_t i = 0; i < n; ++i)
    work[i + 1] = work[i] + (rate[i] - mean);

  for (size_t k = 0; k < n_m; ++k) {
    const size_t mk = m[k];
    const size_t terms = n + 1 - 2 * mk;
    double acc = 0.0;
    for (size_t j = 0; j < terms; ++j) {
      const double d = work[j + 2 * mk] - 2.0 * work[j + mk] + work[j];
      acc += d * d;
    }
    const double md = (double)mk;
    adev_out[k] = sqrt(acc / (2.0 * md * md * (double)terms));
  }
  return NAV_OK;
}

nav_status nav_allan_log_clusters(size_t m_max, unsigned per_decade, size_t *m_out, size_t capacity,
                                  size_t *count) {
  if (count == NULL || m_max < 1 || per_decade < 1 || per_decade > 100) return NAV_ERR_INVALID_ARG;
  /* Two passes: count, then write, so a too-small buffer is never partly written. */
  size_t needed = 0;
  for (int pass = 0; pass < 2; ++pass) {
    size_t c = 0, last = 0;
    for (unsigned i = 0;; ++i) {
      const double v = round(pow(10.0, (double)i / (double)per_decade));
      if (v > (double)m_max) break;
      const size_t mv = (size_t)v;
      if (mv == last) continue;
      if (pass == 1) m_out[c] = mv;
      ++c;
      last = mv;
    }
    needed = c;
    if (pass == 0 && (m_out == NULL || capacity < needed)) {
      *count = needed;
      return m_out == NULL ? NAV_OK : NAV_ERR_OUT_OF_RANGE;
    }
  }
  *count = needed;
  return NAV_OK;
}

double nav_allan_rel_uncertainty(size_t n, size_t m) {
  if (m == 0 || n <= m) return INFINITY;
  return 1.0 / sqrt(2.0 * ((double)n / (double)m - 1.0));
}
