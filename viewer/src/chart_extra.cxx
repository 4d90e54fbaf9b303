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
#include <vtkContext2D.h>
#include <vtkContextView.h>
#include <vtkObjectFactory.h>
#include <vtkTransform2D.h>
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

// ------------------------------------------------------------------ tradeoff (navsim tradeoff)

namespace {

// Markers of a tradeoff chart with their interval bars and a text label next to each point.
// vtkPlotPoints draws the markers; the bars and labels are painted in data coordinates under the
// chart's transform (the axes are linear here, so data and plot coordinates agree).
class vtkNavLabelledPoints : public vtkPlotPoints {
public:
  static vtkNavLabelledPoints *New();
  vtkTypeMacro(vtkNavLabelledPoints, vtkPlotPoints)
  std::vector<double> x, lo, hi, y;
  std::vector<std::string> labels; // non-empty: this plot is the label layer (no markers, no bars)
  double y_lo = 0.0, y_hi = 1.0;   // the axis range, to keep labels inside the plot area
  int font = 10;
  bool Paint(vtkContext2D *painter) override {
    if (!this->Visible) return false;
    if (labels.empty()) {
      painter->GetPen()->SetColor(this->Pen->GetColor());
      painter->GetPen()->SetWidth(1.5f);
      for (size_t i = 0; i < x.size(); ++i)
        if (std::isfinite(lo[i]) && std::isfinite(hi[i])) painter->DrawLine(x[i], lo[i], x[i], hi[i]);
      return this->Superclass::Paint(painter);
    }
    vtkTransform2D *t = painter->GetTransform();
    if (!t) return true;
    vtkTextProperty *tp = painter->GetTextProp();
    NavApplyFont(tp);
    tp->SetFontSize(font);
    tp->SetColor(0.1, 0.1, 0.15);
    tp->SetJustificationToLeft();
    tp->SetVerticalJustificationToCentered();
    tp->BoldOff();
    // Label placement in pixels: to the right of each point, moved up or down in steps of one
    // line to the nearest place that overlaps no label placed before (points by decreasing
    // value), with a leader line when moved.
    struct Box {
      double x0, x1, y0, y1;
    };
    std::vector<Box> placed;
    std::vector<size_t> order(x.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return y[a] > y[b]; });
    double lim[4] = {0.0, y_lo, 0.0, y_hi};
    t->TransformPoints(lim, lim, 2);
    const double py_min = std::min(lim[1], lim[3]), py_max = std::max(lim[1], lim[3]);
    std::vector<double> px(x.size()), py(x.size()), ly(x.size());
    for (size_t i = 0; i < x.size(); ++i) {
      double p[2] = {x[i], y[i]};
      t->TransformPoints(p, p, 1);
      px[i] = p[0];
      py[i] = p[1];
    }
    // Measure and draw in pixels (scene coordinates): the chart's data transform set aside.
    vtkNew<vtkTransform2D> identity;
    painter->PushMatrix();
    painter->SetTransform(identity);
    for (size_t i : order) {
      float b[4] = {0, 0, 0, 0};
      painter->ComputeStringBounds(labels[i], b);
      const double w = b[2], h = std::max<double>(b[3], font) + 2.0;
      const double x0 = px[i] + 7.0;
      double best = py[i];
      for (int k = 0; k < 400; ++k) {
        const double cand = py[i] + ((k % 2) ? 1.0 : -1.0) * h * ((k + 1) / 2);
        if (cand - h / 2 < py_min || cand + h / 2 > py_max) continue;
        bool clash = false;
        for (const Box &o : placed)
          if (x0 < o.x1 && x0 + w > o.x0 && cand - h / 2 < o.y1 && cand + h / 2 > o.y0) clash = true;
        if (!clash) {
          best = cand;
          break;
        }
      }
      placed.push_back({x0, x0 + w, best - h / 2, best + h / 2});
      ly[i] = best;
    }
    painter->GetPen()->SetColor(150, 150, 150, 255);
    painter->GetPen()->SetWidth(0.8f);
    for (size_t i = 0; i < x.size(); ++i)
      if (std::fabs(ly[i] - py[i]) > 1.0) painter->DrawLine(px[i] + 3.0, py[i], px[i] + 6.0, ly[i]);
    for (size_t i = 0; i < x.size(); ++i)
      painter->DrawString(static_cast<float>(px[i] + 7.0), static_cast<float>(ly[i]), labels[i]);
    painter->PopMatrix();
    return true;
  }
};
vtkStandardNewMacro(vtkNavLabelledPoints);

struct TradeoffRow {
  std::string variant, requirement, unit, statistic;
  double cpu = NAN, value = NAN, lo = NAN, hi = NAN, full = NAN, tol = NAN;
  bool pareto = false, recommended = false, within = false;
};

} // namespace

bool NavRenderTradeoffPng(const std::string &csv, const std::string &requirement, const NavChartOptions &opt,
                          const std::string &path, std::string *error) {
  std::vector<std::string> h;
  std::vector<std::vector<std::string>> rows;
  if (!ReadTextCsv(csv, &h, &rows, error)) return false;
  auto col = [&](const char *n) {
    for (size_t i = 0; i < h.size(); ++i)
      if (h[i] == n) return static_cast<int>(i);
    return -1;
  };
  const char *need[] = {"variant", "status", "cpu_s_per_run", "requirement", "unit", "statistic", "value",
                        "ci_low", "ci_high", "full_value", "tolerance", "within_tolerance", "pareto", "recommended"};
  int c[14];
  for (int k = 0; k < 14; ++k) {
    c[k] = col(need[k]);
    if (c[k] < 0) {
      *error = csv + ":1: error: missing column '" + need[k] + "' (expected navsim tradeoff's tradeoff.csv)";
      return false;
    }
  }
  std::vector<std::string> reqs;
  std::map<std::string, std::vector<TradeoffRow>> by_req;
  for (const auto &r : rows) {
    if (r.size() < h.size() || r[static_cast<size_t>(c[1])] != "ok") continue;
    TradeoffRow t;
    t.variant = r[static_cast<size_t>(c[0])];
    t.requirement = r[static_cast<size_t>(c[3])];
    t.unit = r[static_cast<size_t>(c[4])];
    t.statistic = r[static_cast<size_t>(c[5])];
    if (!requirement.empty() && t.requirement != requirement) continue;
    if (!ParseNum(r[static_cast<size_t>(c[2])], &t.cpu) || !ParseNum(r[static_cast<size_t>(c[6])], &t.value))
      continue;
    ParseNum(r[static_cast<size_t>(c[7])], &t.lo);
    ParseNum(r[static_cast<size_t>(c[8])], &t.hi);
    ParseNum(r[static_cast<size_t>(c[9])], &t.full);
    ParseNum(r[static_cast<size_t>(c[10])], &t.tol);
    t.within = r[static_cast<size_t>(c[11])] == "true";
    t.pareto = r[static_cast<size_t>(c[12])] == "true";
    t.recommended = r[static_cast<size_t>(c[13])] == "true";
    if (!by_req.count(t.requirement)) reqs.push_back(t.requirement);
    by_req[t.requirement].push_back(t);
  }
  if (reqs.empty()) {
    *error = csv + ": error: no evaluated variant" +
             (requirement.empty() ? std::string() : " for requirement '" + requirement + "'");
    return false;
  }
  ChartCanvas cv;
  if (!MakeCanvas(&cv, opt, static_cast<int>(reqs.size()), error)) return false;
  for (size_t k = 0; k < reqs.size(); ++k) {
    vtkChartXY *chart = Panel(&cv, static_cast<int>(reqs.size() - 1 - k));
    if (!chart) {
      *error = "vtkChartMatrix did not create an XY chart";
      return false;
    }
    const std::vector<TradeoffRow> &pts = by_req[reqs[k]];
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY, full = NAN, tol = NAN;
    for (const TradeoffRow &t : pts) {
      xmin = std::min(xmin, t.cpu);
      xmax = std::max(xmax, t.cpu);
      ymin = std::min(ymin, std::isfinite(t.lo) ? std::min(t.lo, t.value) : t.value);
      ymax = std::max(ymax, std::isfinite(t.hi) ? std::max(t.hi, t.value) : t.value);
      if (t.variant == "full") full = t.value;
      tol = t.tol;
    }
    // Tolerance band around the full model's value.
    std::vector<Line> lines;
    if (std::isfinite(full) && std::isfinite(tol)) {
      for (int s : {-1, 1}) {
        Line b;
        b.name = s < 0 ? "full model \u00b1 tolerance" : "";
        b.x = {xmin, xmax};
        b.y = {full * (1.0 + s * tol), full * (1.0 + s * tol)};
        b.rgb[0] = b.rgb[1] = b.rgb[2] = 120;
        b.pen = vtkPen::DASH_LINE;
        b.width = 1.0f;
        lines.push_back(b);
        ymin = std::min(ymin, b.y[0]);
        ymax = std::max(ymax, b.y[0]);
      }
    }
    // Pareto front: its points by increasing CPU time, joined as a staircase.
    std::vector<const TradeoffRow *> front;
    for (const TradeoffRow &t : pts)
      if (t.pareto) front.push_back(&t);
    std::sort(front.begin(), front.end(), [](const TradeoffRow *a, const TradeoffRow *b) { return a->cpu < b->cpu; });
    Line pf;
    pf.name = "Pareto front";
    pf.rgb[0] = 214;
    pf.rgb[1] = 39;
    pf.rgb[2] = 40;
    pf.width = 2.0f;
    for (size_t i = 0; i < front.size(); ++i) {
      if (i > 0) {
        pf.x.push_back(front[i]->cpu);
        pf.y.push_back(front[i - 1]->value);
      }
      pf.x.push_back(front[i]->cpu);
      pf.y.push_back(front[i]->value);
    }
    lines.push_back(pf);
    AddLines(chart, lines);
    // Markers in three groups: within tolerance, outside, and the recommended one.
    const struct {
      const char *name;
      unsigned char rgb[3];
      int marker;
      float size;
    } groups[4] = {{"within tolerance", {44, 160, 44}, vtkPlotPoints::CIRCLE, 9.f},
                   {"outside tolerance", {127, 127, 127}, vtkPlotPoints::SQUARE, 8.f},
                   {"full model", {20, 20, 20}, vtkPlotPoints::CROSS, 14.f},
                   {"recommended", {31, 119, 180}, vtkPlotPoints::DIAMOND, 15.f}};
    const int font = std::max(8, cv.font - 3);
    for (int g = 0; g < 4; ++g) {
      vtkNew<vtkNavLabelledPoints> p;
      vtkNew<vtkTable> table;
      vtkNew<vtkDoubleArray> xc, yc;
      xc->SetName("cpu");
      yc->SetName(groups[g].name);
      table->AddColumn(xc);
      table->AddColumn(yc);
      for (const TradeoffRow &t : pts) {
        const int tg = t.recommended ? 3 : t.variant == "full" ? 2 : (t.within ? 0 : 1);
        if (tg != g) continue;
        p->x.push_back(t.cpu);
        p->y.push_back(t.value);
        p->lo.push_back(t.lo);
        p->hi.push_back(t.hi);
      }
      if (p->x.empty()) continue;
      table->SetNumberOfRows(static_cast<vtkIdType>(p->x.size()));
      for (size_t i = 0; i < p->x.size(); ++i) {
        table->SetValue(static_cast<vtkIdType>(i), 0, p->x[i]);
        table->SetValue(static_cast<vtkIdType>(i), 1, p->y[i]);
      }
      p->font = font;
      p->SetInputData(table, 0, 1);
      p->SetColor(groups[g].rgb[0], groups[g].rgb[1], groups[g].rgb[2], 255);
      p->SetMarkerStyle(groups[g].marker);
      p->SetMarkerSize(groups[g].size);
      p->SetWidth(2.0f);
      p->SetLabel(groups[g].name);
      chart->AddPlot(p);
    }
    const double ys = ymax > ymin ? ymax - ymin : std::max(1e-9, 0.1 * std::fabs(ymax));
    const double y_lo = std::max(0.0, ymin - 0.1 * ys), y_hi = ymax + 0.1 * ys;
    if (opt.show_text) {
      vtkNew<vtkNavLabelledPoints> lab;
      vtkNew<vtkTable> table;
      vtkNew<vtkDoubleArray> xc, yc;
      xc->SetName("cpu");
      yc->SetName("labels");
      table->AddColumn(xc);
      table->AddColumn(yc);
      table->SetNumberOfRows(static_cast<vtkIdType>(pts.size()));
      for (size_t i = 0; i < pts.size(); ++i) {
        lab->x.push_back(pts[i].cpu);
        lab->y.push_back(pts[i].value);
        lab->labels.push_back(pts[i].variant);
        table->SetValue(static_cast<vtkIdType>(i), 0, pts[i].cpu);
        table->SetValue(static_cast<vtkIdType>(i), 1, pts[i].value);
      }
      lab->font = font;
      lab->y_lo = y_lo;
      lab->y_hi = y_hi;
      lab->SetInputData(table, 0, 1);
      lab->SetLegendVisibility(false);
      chart->AddPlot(lab);
    }
    const TradeoffRow &t0 = pts.front();
    StyleChart(chart,
               reqs[k] + " (" + t0.statistic + ") against CPU time: 95 % intervals, Pareto front",
               "CPU time per Monte Carlo run [s]", reqs[k] + " [" + t0.unit + "]", opt, cv.font);
    chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
    chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    const double xs = xmax > xmin ? xmax - xmin : std::max(1e-3, 0.1 * xmax);
    chart->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
    // Room on the right for the labels of the slowest points.
    chart->GetAxis(vtkAxis::BOTTOM)->SetRange(std::max(0.0, xmin - 0.08 * xs), xmax + 0.45 * xs);
    chart->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::LEFT)->SetRange(y_lo, y_hi);
  }
  cv.view->Render();
  return NavWriteWindowPng(cv.view->GetRenderWindow(), path, error);
}
