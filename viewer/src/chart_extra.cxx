// Further charts (nav_view_chart.h): simulated sensor errors, Allan deviation with slope guides,
// and speed against error from bench.csv. vtkChartXY panels in a vtkContextView, offscreen.
#include "navview/nav_view_chart.h"

#include "navview_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartMatrix.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkVector.h>

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
constexpr double kG = 9.80665;

struct Line {
  std::string name;
  std::vector<double> x, y;
  unsigned char rgb[3];
  int pen = vtkPen::SOLID_LINE;
  float width = 1.5f;
  bool points = false; // markers instead of a line
  int marker = vtkPlotPoints::CIRCLE;
};

void StyleAxis2(vtkAxis *axis, const std::string &title, bool text, int font) {
  axis->SetTitle(text ? title : std::string());
  NavApplyFont(axis->GetTitleProperties());
  NavApplyFont(axis->GetLabelProperties());
  axis->GetTitleProperties()->SetFontSize(font);
  axis->GetLabelProperties()->SetFontSize(font - 2);
  axis->GetTitleProperties()->SetColor(0.05, 0.05, 0.08);
  axis->GetLabelProperties()->SetColor(0.15, 0.15, 0.2);
  axis->GetTitleProperties()->BoldOff();
  axis->SetLabelsVisible(text);
  axis->GetGridPen()->SetColorF(0.86, 0.86, 0.88);
}

// Every line gets its own table (lines may have different x).
void AddLines(vtkChartXY *chart, const std::vector<Line> &lines) {
  for (const Line &l : lines) {
    if (l.x.empty()) continue;
    vtkNew<vtkTable> table;
    vtkNew<vtkDoubleArray> xc, yc;
    xc->SetName("x");
    yc->SetName(l.name.c_str());
    table->AddColumn(xc);
    table->AddColumn(yc);
    table->SetNumberOfRows(static_cast<vtkIdType>(l.x.size()));
    for (size_t i = 0; i < l.x.size(); ++i) {
      table->SetValue(static_cast<vtkIdType>(i), 0, l.x[i]);
      table->SetValue(static_cast<vtkIdType>(i), 1, l.y[i]);
    }
    vtkPlot *p = chart->AddPlot(l.points ? vtkChart::POINTS : vtkChart::LINE);
    p->SetInputData(table, 0, 1);
    p->SetColor(l.rgb[0], l.rgb[1], l.rgb[2], 255);
    p->SetWidth(l.width);
    p->GetPen()->SetLineType(l.pen);
    p->SetLabel(l.name);
    if (l.points) {
      auto *pp = vtkPlotPoints::SafeDownCast(p);
      if (pp) {
        pp->SetMarkerStyle(l.marker);
        pp->SetMarkerSize(std::max(8.0f, 2.5f * l.width));
      }
    }
  }
}

void StyleChart(vtkChartXY *chart, const std::string &title, const std::string &xt, const std::string &yt,
                const NavChartOptions &opt, int font) {
  chart->SetTitle(opt.show_text ? title : std::string());
  NavApplyFont(chart->GetTitleProperties());
  chart->GetTitleProperties()->SetFontSize(font + 1);
  chart->GetTitleProperties()->SetColor(0.05, 0.05, 0.08);
  chart->GetTitleProperties()->BoldOn();
  StyleAxis2(chart->GetAxis(vtkAxis::LEFT), yt, opt.show_text, font);
  StyleAxis2(chart->GetAxis(vtkAxis::BOTTOM), xt, opt.show_text, font);
  chart->SetShowLegend(opt.show_text);
  if (opt.show_text) {
    NavApplyFont(chart->GetLegend()->GetLabelProperties());
    chart->GetLegend()->GetLabelProperties()->SetFontSize(font - 2);
    chart->GetLegend()->GetLabelProperties()->SetColor(0.05, 0.05, 0.08);
    chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
    chart->GetLegend()->GetBrush()->SetColorF(1.0, 1.0, 1.0, 0.85);
  }
}

struct ChartCanvas {
  vtkNew<vtkContextView> view;
  vtkNew<vtkChartMatrix> matrix;
  int font = 12;
};

bool MakeCanvas(ChartCanvas *c, const NavChartOptions &opt, int rows, std::string *error) {
  if (opt.width_px < 64 || opt.height_px < 64 || opt.width_px > 8192 || opt.height_px > 8192) {
    *error = "chart size out of range (64..8192 pixels)";
    return false;
  }
  if (!NavCheckDisplay(error)) return false;
  NavAttachDisplay(c->view->GetRenderWindow());
  c->view->GetRenderWindow()->SetOffScreenRendering(1);
  c->view->GetRenderWindow()->SetInteractor(nullptr); // see chart.cxx: no interactor headless
  c->view->GetRenderWindow()->SetSize(opt.width_px, opt.height_px);
  c->view->GetRenderWindow()->SetMultiSamples(8);
  c->view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  c->matrix->SetSize(vtkVector2i(1, rows));
  c->font = std::max(10, static_cast<int>(std::lround(std::min(opt.height_px / (rows == 1 ? 40.0 : 52.0),
                                                                opt.width_px / 60.0))));
  const bool text = opt.show_text;
  const int f = c->font;
  c->matrix->SetBorders(static_cast<int>((text ? 5.2 : 1.0) * f), static_cast<int>((text ? 3.4 : 1.0) * f),
                        static_cast<int>(1.5 * f), static_cast<int>((text ? 2.2 : 1.0) * f));
  c->matrix->SetGutter(vtkVector2f(0.0f, static_cast<float>((text ? 4.0 : 1.0) * f)));
  c->view->GetScene()->AddItem(c->matrix);
  return true;
}

vtkChartXY *Panel(ChartCanvas *c, int row) {
  return vtkChartXY::SafeDownCast(c->matrix->GetChart(vtkVector2i(0, row)));
}

// Min/max bucketing of a series to at most about max_points points (peaks survive).
void Thin(const std::vector<double> &x, const std::vector<double> &y, int max_points, std::vector<double> *ox,
          std::vector<double> *oy) {
  const size_t n = x.size();
  const size_t buckets = static_cast<size_t>(std::max(max_points / 2, 8));
  if (n <= static_cast<size_t>(max_points)) {
    *ox = x;
    *oy = y;
    return;
  }
  for (size_t b = 0; b < buckets; ++b) {
    const size_t i0 = b * n / buckets, i1 = std::max(i0 + 1, (b + 1) * n / buckets);
    auto mm = std::minmax_element(y.begin() + static_cast<long>(i0), y.begin() + static_cast<long>(i1));
    size_t a = static_cast<size_t>(mm.first - y.begin()), c = static_cast<size_t>(mm.second - y.begin());
    if (a > c) std::swap(a, c);
    ox->push_back(x[a]);
    oy->push_back(y[a]);
    if (c != a) {
      ox->push_back(x[c]);
      oy->push_back(y[c]);
    }
  }
}

const unsigned char kAxisRGB[3][3] = {{214, 39, 40}, {44, 160, 44}, {31, 119, 180}};

// Minimal CSV with text fields (bench.csv): header names, rows of strings; "..." quoting.
bool ReadTextCsv(const std::string &path, std::vector<std::string> *header,
                 std::vector<std::vector<std::string>> *rows, std::string *error) {
  std::string text; // a FIFO, device or directory is refused at once (no blocking open)
  if (!NavReadRegularFile(path, kNavCsvMaxFileBytes, &text, error)) return false;
  std::istringstream in(text);
  auto split = [](const std::string &line) {
    std::vector<std::string> f;
    std::string cur;
    bool q = false;
    for (char ch : line) {
      if (ch == '"') q = !q;
      else if (ch == ',' && !q) {
        f.push_back(cur);
        cur.clear();
      } else if (ch != '\r')
        cur += ch;
    }
    f.push_back(cur);
    return f;
  };
  std::string line;
  if (!std::getline(in, line)) {
    *error = path + ":1: error: empty file (a header line was expected)";
    return false;
  }
  *header = split(line);
  while (std::getline(in, line))
    if (!line.empty() && line != "\r") rows->push_back(split(line));
  return true;
}

bool ParseNum(const std::string &s, double *v) {
  if (s.empty()) return false;
  char *end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return end && *end == '\0' && std::isfinite(*v);
}

} // namespace

bool NavRenderSensorErrorChartPng(const NavResult &result, const NavChartOptions &opt, const std::string &path,
                                  std::string *error) {
  const NavImuErrors &e = result.imu_errors;
  if (e.Size() < 2) {
    *error = (result.dir.empty() ? std::string("result") : result.dir) +
             ": error: no imu_errors.csv (ideal sensors or a scene without IMU error terms): nothing to chart";
    return false;
  }
  ChartCanvas c;
  if (!MakeCanvas(&c, opt, 2, error)) return false;
  std::vector<Line> gl, al;
  const char *ax[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    std::vector<double> g(e.Size()), a(e.Size());
    for (size_t i = 0; i < e.Size(); ++i) {
      g[i] = e.gyro_rps[3 * i + static_cast<size_t>(k)] * kRadToDeg * 3600.0;
      a[i] = e.accel_mps2[3 * i + static_cast<size_t>(k)] / kG * 1e3;
    }
    Line lg, la;
    lg.name = std::string("gyro ") + ax[k];
    la.name = std::string("accel ") + ax[k];
    Thin(e.t_s, g, opt.max_points, &lg.x, &lg.y);
    Thin(e.t_s, a, opt.max_points, &la.x, &la.y);
    std::copy(kAxisRGB[k], kAxisRGB[k] + 3, lg.rgb);
    std::copy(kAxisRGB[k], kAxisRGB[k] + 3, la.rgb);
    lg.width = la.width = 1.0f;
    gl.push_back(lg);
    al.push_back(la);
  }
  vtkChartXY *top = Panel(&c, 1), *bottom = Panel(&c, 0);
  if (!top || !bottom) {
    *error = "vtkChartMatrix did not create XY charts";
    return false;
  }
  const std::string who = result.scene_name.empty() ? std::string() : result.scene_name + ": ";
  AddLines(top, gl);
  AddLines(bottom, al);
  StyleChart(top, who + "simulated gyro errors (run 0)", "", "gyro error [\u00b0/h]", opt, c.font);
  StyleChart(bottom, "simulated accelerometer errors (run 0)", "time [s]", "accel error [mg]", opt, c.font);
  for (vtkChartXY *ch : {top, bottom}) {
    ch->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
    ch->GetAxis(vtkAxis::BOTTOM)->SetRange(e.t_s.front(), e.t_s.back());
  }
  c.view->Render();
  return NavWriteWindowPng(c.view->GetRenderWindow(), path, error);
}

bool NavRenderAllanChartPng(const std::string &allan_csv, const NavChartOptions &opt, const std::string &path,
                            std::string *error) {
  NavCsvTable t;
  if (!NavCsvReadFile(allan_csv, &t, error)) return false;
  const char *meas[6] = {"adev_gx_rad_per_s", "adev_gy_rad_per_s", "adev_gz_rad_per_s",
                         "adev_ax_mps2",      "adev_ay_mps2",      "adev_az_mps2"};
  const char *model[6] = {"model_adev_gx_rad_per_s", "model_adev_gy_rad_per_s", "model_adev_gz_rad_per_s",
                          "model_adev_ax_mps2",      "model_adev_ay_mps2",      "model_adev_az_mps2"};
  const int ct = t.Column("tau_s");
  if (ct < 0) {
    *error = allan_csv + ":1: error: missing column 'tau_s'";
    return false;
  }
  for (const char *m : meas)
    if (t.Column(m) < 0) {
      *error = allan_csv + ":1: error: missing column '" + m + "'";
      return false;
    }
  if (t.rows < 2) {
    *error = allan_csv + ": error: fewer than two tau values";
    return false;
  }
  ChartCanvas c;
  if (!MakeCanvas(&c, opt, 2, error)) return false;
  vtkChartXY *top = Panel(&c, 1), *bottom = Panel(&c, 0);
  if (!top || !bottom) {
    *error = "vtkChartMatrix did not create XY charts";
    return false;
  }
  const char *ax[3] = {"x", "y", "z"};
  for (int group = 0; group < 2; ++group) {
    const double scale = group == 0 ? kRadToDeg * 3600.0 : 1e3 / kG; // deg/h or mg
    std::vector<Line> lines;
    double ymin = INFINITY, ymax = 0.0, tmin = INFINITY, tmax = 0.0;
    for (int k = 0; k < 3; ++k) {
      const int ch = group * 3 + k;
      Line l;
      l.name = std::string(group == 0 ? "gyro " : "accel ") + ax[k];
      Line m;
      m.name = std::string("model ") + ax[k];
      const int cm = t.Column(meas[ch]), cmod = t.Column(model[ch]);
      for (size_t r = 0; r < t.rows; ++r) {
        const double tau = t.At(r, ct), a = t.At(r, cm) * scale;
        if (!(tau > 0.0) || !(a > 0.0)) continue;
        l.x.push_back(tau);
        l.y.push_back(a);
        ymin = std::min(ymin, a);
        ymax = std::max(ymax, a);
        tmin = std::min(tmin, tau);
        tmax = std::max(tmax, tau);
        if (cmod >= 0 && t.At(r, cmod) > 0.0) {
          m.x.push_back(tau);
          m.y.push_back(t.At(r, cmod) * scale);
        }
      }
      std::copy(kAxisRGB[k], kAxisRGB[k] + 3, l.rgb);
      std::copy(kAxisRGB[k], kAxisRGB[k] + 3, m.rgb);
      l.width = 2.0f;
      m.pen = vtkPen::DASH_LINE;
      m.width = 1.0f;
      lines.push_back(l);
      if (k == 0 && !m.x.empty()) lines.push_back(m);
    }
    if (!(tmax > tmin) || !(ymax > 0.0)) {
      *error = allan_csv + ": error: no positive Allan deviation values";
      return false;
    }
    // Slope guides of the x channel: -1/2 through its first point (white noise), 0 through its
    // minimum (bias-instability floor), +1/2 through its last point (rate random walk).
    const Line x0 = lines.front(); // a copy: lines grows below
    const size_t imin = static_cast<size_t>(std::min_element(x0.y.begin(), x0.y.end()) - x0.y.begin());
    const struct {
      double slope;
      size_t at;
      const char *name;
    } guides[3] = {{-0.5, 0, "slope \u22121/2 (white noise)"},
                   {0.0, imin, "slope 0 (bias-instability floor)"},
                   {0.5, x0.x.size() - 1, "slope +1/2 (random walk)"}};
    for (const auto &g : guides) {
      Line l;
      l.name = g.name;
      const double tau_c = x0.x[g.at], a_c = x0.y[g.at];
      l.x = {tmin, tmax};
      l.y = {a_c * std::pow(tmin / tau_c, g.slope), a_c * std::pow(tmax / tau_c, g.slope)};
      const unsigned char grey = g.slope < 0 ? 40 : (g.slope == 0 ? 90 : 140);
      l.rgb[0] = l.rgb[1] = l.rgb[2] = grey;
      l.pen = g.slope < 0 ? vtkPen::DASH_DOT_LINE : (g.slope == 0 ? vtkPen::DOT_LINE : vtkPen::DASH_DOT_DOT_LINE);
      l.width = 1.5f;
      lines.push_back(l);
    }
    vtkChartXY *chart = group == 0 ? top : bottom;
    AddLines(chart, lines);
    StyleChart(chart, group == 0 ? "Allan deviation: gyros" : "Allan deviation: accelerometers",
               group == 0 ? "" : "averaging time \u03c4 [s]",
               group == 0 ? "\u03c3(\u03c4) [\u00b0/h]" : "\u03c3(\u03c4) [mg]", opt, c.font);
    for (int a : {vtkAxis::LEFT, vtkAxis::BOTTOM}) {
      chart->GetAxis(a)->SetLogScale(true);
    }
    chart->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::BOTTOM)->SetRange(tmin, tmax);
    chart->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::LEFT)->SetRange(ymin / 3.0, ymax * 3.0);
  }
  c.view->Render();
  return NavWriteWindowPng(c.view->GetRenderWindow(), path, error);
}

bool NavRenderSpeedVsErrorPng(const std::string &bench_csv, const NavChartOptions &opt, const std::string &path,
                              std::string *error) {
  std::vector<std::string> h;
  std::vector<std::vector<std::string>> rows;
  if (!ReadTextCsv(bench_csv, &h, &rows, error)) return false;
  auto col = [&](std::initializer_list<const char *> names) {
    for (const char *n : names)
      for (size_t i = 0; i < h.size(); ++i)
        if (h[i] == n) return static_cast<int>(i);
    return -1;
  };
  const int cx = col({"mech_samples_per_s", "samples_per_s"});
  const int cy = col({"pos_err_m", "error", "error_m"});
  const int cv = col({"variant", "algorithm"});
  const int cs = col({"status"});
  const int cc = col({"case"});
  const int ca = col({"algorithm"}), cf = col({"frame"});
  if (cx < 0 || cy < 0 || cv < 0) {
    *error = bench_csv + ":1: error: expected columns mech_samples_per_s (or samples_per_s), pos_err_m (or "
                         "error) and variant (or algorithm)";
    return false;
  }
  std::map<std::string, Line> by_variant;
  std::vector<std::string> order;
  double xmin = INFINITY, xmax = 0.0, ymin = INFINITY, ymax = 0.0;
  for (const auto &r : rows) {
    if (static_cast<int>(r.size()) <= std::max(cx, std::max(cy, cv))) continue;
    if (cs >= 0 && cs < static_cast<int>(r.size()) && r[static_cast<size_t>(cs)] != "ok") continue;
    double x, y;
    if (!ParseNum(r[static_cast<size_t>(cx)], &x) || !ParseNum(r[static_cast<size_t>(cy)], &y)) continue;
    if (!(x > 0.0) || !(y > 0.0)) continue;
    // Series: algorithm + frame when bench.csv has them (each row, i.e. each variant, is one
    // marker; the rates of a series line up along it), else the variant name.
    std::string v = r[static_cast<size_t>(cv)];
    if (ca >= 0 && cf >= 0 && std::max(ca, cf) < static_cast<int>(r.size()))
      v = r[static_cast<size_t>(ca)] + ", " + r[static_cast<size_t>(cf)];
    if (v.empty() && cc >= 0) v = r[static_cast<size_t>(cc)];
    if (!by_variant.count(v)) order.push_back(v);
    Line &l = by_variant[v];
    l.x.push_back(x);
    l.y.push_back(y);
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
  }
  if (order.empty()) {
    *error = bench_csv + ": error: no row with a positive speed and error (status ok)";
    return false;
  }
  static const unsigned char pal[10][3] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                           {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127},
                                           {188, 189, 34},  {23, 190, 207}};
  static const int markers[4] = {vtkPlotPoints::CIRCLE, vtkPlotPoints::SQUARE, vtkPlotPoints::DIAMOND,
                                 vtkPlotPoints::CROSS};
  std::vector<Line> lines;
  for (size_t i = 0; i < order.size(); ++i) {
    Line l = by_variant[order[i]];
    l.name = order[i];
    std::copy(pal[i % 10], pal[i % 10] + 3, l.rgb);
    l.points = true;
    l.marker = markers[(i / 10) % 4];
    l.width = 4.0f;
    lines.push_back(l);
  }
  ChartCanvas c;
  if (!MakeCanvas(&c, opt, 1, error)) return false;
  vtkChartXY *chart = Panel(&c, 0);
  if (!chart) {
    *error = "vtkChartMatrix did not create an XY chart";
    return false;
  }
  AddLines(chart, lines);
  StyleChart(chart, "speed against error (navsim bench): one marker per variant",
             "speed [mechanization samples/s]", "position error [m]", opt, c.font);
  chart->GetAxis(vtkAxis::LEFT)->SetLogScale(true);
  chart->GetAxis(vtkAxis::BOTTOM)->SetLogScale(true);
  chart->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
  chart->GetAxis(vtkAxis::BOTTOM)->SetRange(xmin / 2.0, xmax * 2.0);
  chart->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
  chart->GetAxis(vtkAxis::LEFT)->SetRange(ymin / 3.0, ymax * 3.0);
  c.view->Render();
  return NavWriteWindowPng(c.view->GetRenderWindow(), path, error);
}
