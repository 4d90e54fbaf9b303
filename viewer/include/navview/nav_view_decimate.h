/**
 * @file nav_view_decimate.h
 * @brief Display decimation of long polylines (Douglas-Peucker with a hard error bound).
 *
 * The viewer keeps the full-rate data for picking and read-outs and draws a decimated copy. The
 * tolerance is a distance in the polyline's own units; the scene view derives it from a
 * screen-space tolerance in pixels times the metres per pixel of the view, so straight stretches
 * collapse to their end points while bends keep as many vertices as their curvature needs.
 */
#ifndef NAV_VIEW_DECIMATE_H
#define NAV_VIEW_DECIMATE_H

#include <cstddef>
#include <vector>

/**
 * Douglas-Peucker decimation of a polyline of @p n points of dimension @p dim (2..4; the 4th
 * component may carry a scaled scalar such as a tube radius, so that the bound covers it too).
 *
 * Guarantee: every dropped point lies within @p tol (Euclidean, in @p dim dimensions) of the
 * segment joining the kept points around it. The first and last points are always kept.
 * Iterative (explicit stack): no recursion depth limit for 10^6 points.
 *
 * @param[in] pts  n*dim values, point-major
 * @param[in] n    number of points
 * @param[in] dim  components per point, 2..4
 * @param[in] tol  tolerance (>= 0; 0 keeps every point that is not exactly on a segment)
 * @return indices of the kept points, increasing. Empty when n == 0.
 */
std::vector<size_t> NavDecimatePolyline(const double *pts, size_t n, int dim, double tol);

/**
 * Largest distance of any point of the full polyline from the decimated one (the segment
 * joining the kept points around it): the quantity NavDecimatePolyline bounds. For tests.
 */
double NavDecimationError(const double *pts, size_t n, int dim, const std::vector<size_t> &kept);

#endif /* NAV_VIEW_DECIMATE_H */
