/**
 * @file nav_view_chart.h
 * @brief Error-versus-time charts (vtkChartXY in a vtkContextView) written as PNG.
 *
 * Stacked panels: horizontal position error, vertical position error, velocity error (when
 * errors.csv has vel_err_mps) and attitude error (roll, pitch, yaw), each of run 0, with the
 * Monte Carlo k-RMS band when mc_stats.csv is present, the filter's and the covariance analysis's
 * k-sigma curves when present, the requirement limits (PASS grey, FAIL red, the limits of one
 * panel in different dash patterns) and the GNSS outages shaded; each panel's legend stands right
 * of its plot, off the data. Axis titles carry units in brackets; labels use DejaVu Sans. Needs an
 * X server.
 */
#ifndef NAV_VIEW_CHART_H
#define NAV_VIEW_CHART_H

#include <string>
#include <vector>

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

/**
 * The picture NavRenderErrorChartPng writes, as pixels: @p rgb gets options.width_px x
 * options.height_px pixels of 3 bytes (R, G, B), rows from the top (a program's own window,
 * navstudio's Errors tab, shows it without a file).
 * @return false with a message as NavRenderErrorChartPng.
 */
bool NavRenderErrorChartRgb(const NavResult &result, const NavChartOptions &options,
                            std::vector<unsigned char> *rgb, std::string *error);

/** A rectangle of a chart picture in pixels; x from the left, y from the BOTTOM row up. */
struct NavChartRect {
  double x = 0, y = 0, w = 0, h = 0;
  /** True when the two rectangles share an area (touching edges do not count). */
  bool Intersects(const NavChartRect &o) const {
    return x < o.x + o.w && o.x < x + w && y < o.y + o.h && o.y < y + h;
  }
};

/** Where the error chart put things, one entry per panel from the top (horizontal first). */
struct NavErrorChartLayout {
  std::vector<std::string> titles;
  std::vector<NavChartRect> plots;   ///< the plot area inside the axes
  std::vector<NavChartRect> legends; ///< the legend box (w = h = 0 when text is off)
  /** Per panel: the vtkPen line type of each requirement-limit line, in the panel's order. */
  std::vector<std::vector<int>> limit_pens;
  /** Per panel: the axis ranges as drawn, time [s] across the plot and the panel's unit up it
   *  (hover read-outs map a pixel of a plot to these). */
  std::vector<double> t_min_s, t_max_s, y_min, y_max;
};

/**
 * NavRenderErrorChartRgb and the chart's layout as drawn (for tests and for programs that place
 * read-outs over the picture).
 */
bool NavRenderErrorChartRgb(const NavResult &result, const NavChartOptions &options,
                            std::vector<unsigned char> *rgb, NavErrorChartLayout *layout, std::string *error);

/**
 * Simulated sensor errors of run 0 (imu_errors.csv; the paper's Fig. 2): gyro errors [deg/h] and
 * accelerometer errors [mg] per axis against time, two panels.
 */
bool NavRenderSensorErrorChartPng(const NavResult &result, const NavChartOptions &options, const std::string &path,
                                  std::string *error);

/**
 * Allan deviation (allan.csv of `navsim allan`): log-log, gyros [deg/h] and accelerometers [mg] in
 * two panels, measured per axis, the model curve dashed, and slope guides -1/2 (white noise),
 * 0 (flicker floor) and +1/2 (random walk) through the curve's middle.
 */
bool NavRenderAllanChartPng(const std::string &allan_csv, const NavChartOptions &options, const std::string &path,
                            std::string *error);

/**
 * Speed against error from bench.csv (`navsim bench`): one log-log panel per case (column case, in
 * the file's order; a grid of up to three columns, first case top left), x = mechanization samples
 * per second (mech_samples_per_s, else samples_per_s), y = position error [m] (pos_err_m, else
 * error); each row one marker labelled with its variant (variant, else algorithm column; labels
 * only with options.show_text), coloured by algorithm and frame alike in every panel. Rows with a
 * status other than ok, or a non-positive value, are skipped. @p layout (may be NULL) gets what
 * was drawn: the case of each panel and the labels written next to its markers.
 */
struct NavBenchChartLayout {
  /** Grid cell of a panel: column and row from the top left, and how many it spans. */
  struct Cell {
    int col = 0, row = 0, cols = 1, rows = 1;
  };
  std::vector<std::string> cases;               /**< panel titles' cases, first panel top left */
  std::vector<std::vector<std::string>> labels; /**< per panel, the marker labels drawn (show_text) */
  std::vector<Cell> cells;                      /**< per panel, its place (a case of more than eight
                                                     variants spans two whole rows) */
};
bool NavRenderSpeedVsErrorPng(const std::string &bench_csv, const NavChartOptions &options, const std::string &path,
                              std::string *error, NavBenchChartLayout *layout = nullptr);

/**
 * Speed against error from tradeoff.csv (`navsim tradeoff`): per requirement (one panel each, or
 * only @p requirement when not empty) CPU time per run against the requirement's value, each
 * variant a labelled marker with its confidence interval as a vertical bar, coloured by whether
 * it is within the tolerance of the full model (dashed band), the recommended one as a diamond,
 * and the Pareto front (column pareto) as a staircase. Rows with status other than ok are skipped.
 */
bool NavRenderTradeoffPng(const std::string &tradeoff_csv, const std::string &requirement,
                          const NavChartOptions &options, const std::string &path, std::string *error);

/**
 * Sky plot of a result directory of navsim run with gnss.constellation (issue 22): azimuth /
 * elevation tracks of run 0's satellites from gnss_sats.csv (GPS blue, GLONASS red; epochs in view
 * as markers, masked ones grey), PRN labels at each track's end, elevation rings at 0, 30 and
 * 60 deg, and the sky masks of gnss_mask.csv (the open-sky mask dashed, each canyon's walls at
 * the heading of its middle solid brown). North up, east right, zenith at the centre.
 */
bool NavRenderSkyPlotPng(const std::string &result_dir, const NavChartOptions &options, const std::string &path,
                         std::string *error);

/**
 * DOP and visible count over time from gnss_dop.csv: GDOP, PDOP, HDOP and VDOP (gaps where the
 * geometry has no solution) above the number of satellites in view, with the street-canyon
 * spans (in_canyon) and, when gnss_outages.csv is present, the receiver's outages.
 */
bool NavRenderDopChartPng(const std::string &result_dir, const NavChartOptions &options, const std::string &path,
                          std::string *error);

#endif /* NAV_VIEW_CHART_H */
