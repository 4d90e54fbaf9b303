// Douglas-Peucker display decimation (nav_view_decimate.h). The distance is taken to the segment,
// not to the infinite line through its end points: paths that double back (figure eights, a drive
// that returns to its start, a vehicle at rest) would otherwise lose points that lie far from the
// drawn segment but close to its extension.
#include "navview/nav_view_decimate.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace {

// Squared distance of point p from the segment a-b, all of dimension dim.
double SegmentDistance2(const double *p, const double *a, const double *b, int dim) {
  double ab2 = 0.0, ap_ab = 0.0;
  for (int k = 0; k < dim; ++k) {
    const double d = b[k] - a[k];
    ab2 += d * d;
    ap_ab += (p[k] - a[k]) * d;
  }
  double t = 0.0;
  if (ab2 > 0.0) t = std::clamp(ap_ab / ab2, 0.0, 1.0);
  double d2 = 0.0;
  for (int k = 0; k < dim; ++k) {
    const double e = p[k] - (a[k] + t * (b[k] - a[k]));
    d2 += e * e;
  }
  return d2;
}

} // namespace

std::vector<size_t> NavDecimatePolyline(const double *pts, size_t n, int dim, double tol) {
  std::vector<size_t> kept;
  if (n == 0 || dim < 2 || dim > 4) return kept;
  if (n <= 2) {
    for (size_t i = 0; i < n; ++i)
      kept.push_back(i);
    return kept;
  }
  const size_t d = static_cast<size_t>(dim);
  const double tol2 = tol > 0.0 ? tol * tol : 0.0;
  std::vector<char> keep(n, 0);
  keep[0] = keep[n - 1] = 1;
  std::vector<std::pair<size_t, size_t>> stack;
  stack.emplace_back(0, n - 1);
  while (!stack.empty()) {
    const auto [a, b] = stack.back();
    stack.pop_back();
    if (b <= a + 1) continue;
    double dmax2 = -1.0;
    size_t imax = a;
    for (size_t i = a + 1; i < b; ++i) {
      const double d2 = SegmentDistance2(pts + i * d, pts + a * d, pts + b * d, dim);
      if (d2 > dmax2) {
        dmax2 = d2;
        imax = i;
      }
    }
    if (dmax2 > tol2) {
      keep[imax] = 1;
      stack.emplace_back(a, imax);
      stack.emplace_back(imax, b);
    }
  }
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) kept.push_back(i);
  return kept;
}

double NavDecimationError(const double *pts, size_t n, int dim, const std::vector<size_t> &kept) {
  if (n == 0 || kept.empty()) return 0.0;
  const size_t d = static_cast<size_t>(dim);
  double emax2 = 0.0;
  for (size_t k = 0; k + 1 < kept.size(); ++k) {
    const size_t a = kept[k], b = kept[k + 1];
    for (size_t i = a + 1; i < b; ++i)
      emax2 = std::max(emax2, SegmentDistance2(pts + i * d, pts + a * d, pts + b * d, dim));
  }
  // Points before the first or after the last kept point are not covered by any segment.
  for (size_t i = 0; i < kept.front(); ++i)
    emax2 =
        std::max(emax2, SegmentDistance2(pts + i * d, pts + kept.front() * d, pts + kept.front() * d, dim));
  for (size_t i = kept.back() + 1; i < n; ++i)
    emax2 = std::max(emax2, SegmentDistance2(pts + i * d, pts + kept.back() * d, pts + kept.back() * d, dim));
  return std::sqrt(emax2);
}
