/**
 * @file nav_view_chart.h
 * @brief Error-versus-time charts (vtkChartXY in a vtkContextView) written as PNG.
 *
 * Three stacked panels: horizontal position error, vertical position error and attitude error
 * (roll, pitch, yaw), each of run 0, with the Monte Carlo k-RMS band when mc_stats.csv is
 * present. Axis titles carry units in brackets; labels use DejaVu Sans. Needs an X server.
 */
#ifndef NAV_VIEW_CHART_H
#define NAV_VIEW_CHART_H

#include <string>

#include "navview/nav_view_result.h"

struct NavChartOptions {
  int width_px = 900;
  int height_px = 800;
  /** Band half-width factor: +/- k * RMS over runs. */
  double band_k = 3.0;
  /** Draw text (titles, tick labels, legend). Render tests switch it off. */
  bool show_text = true;
  /** Maximum points per drawn series (min/max bucketing keeps the peaks). */
  int max_points = 4000;
};

/**
 * Render the error charts of @p result to the PNG file @p path.
 * @return false with a message when errors.csv was not loaded or rendering fails.
 */
bool NavRenderErrorChartPng(const NavResult &result, const NavChartOptions &options, const std::string &path,
                            std::string *error);

#endif /* NAV_VIEW_CHART_H */
