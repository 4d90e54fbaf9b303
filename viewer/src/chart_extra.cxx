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
  bool legend = true; // false: a continuation of a series already in the legend
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
    p->SetLegendVisibility(l.legend);
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

bool MakeCanvas(ChartCanvas *c, const NavChartOptions &opt, int rows, std::string *error, int cols = 1) {
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
  c->matrix->SetSize(vtkVector2i(cols, rows));
  c->font = std::max(10, static_cast<int>(std::lround(std::min(opt.height_px / (rows == 1 ? 40.0 : 52.0),
                                                                opt.width_px / 60.0))));
  // A grid of panels: the font of one panel's size (about 24 lines high, 40 characters wide).
  if (cols > 1 || rows > 2)
    c->font = std::max(9, static_cast<int>(std::lround(std::min(opt.height_px / (rows * 24.0),
                                                                 opt.width_px / (cols * 40.0)))));
  const bool text = opt.show_text;
  const int f = c->font;
  c->matrix->SetBorders(static_cast<int>((text ? 5.2 : 1.0) * f), static_cast<int>((text ? 3.4 : 1.0) * f),
                        static_cast<int>(1.5 * f), static_cast<int>((text ? 2.2 : 1.0) * f));
  c->matrix->SetGutter(vtkVector2f(cols > 1 ? static_cast<float>((text ? 6.0 : 1.0) * f) : 0.0f,
                                    static_cast<float>((text ? 4.0 : 1.0) * f)));
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

bool NavRenderSpeedVsErrorPng(const std::string &bench_csv, const NavChartOptions &opt, const std::string &path,
                              std::string *error, NavBenchChartLayout *layout) {
  if (layout) *layout = NavBenchChartLayout();
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
  const int cp = col({"peer"});
  if (cx < 0 || cy < 0 || cv < 0) {
    *error = bench_csv + ":1: error: expected columns mech_samples_per_s (or samples_per_s), pos_err_m (or "
                         "error) and variant (or algorithm)";
    return false;
  }
  // One panel per case (in the order of bench.csv), one labelled marker per variant (row); the
  // marker's colour is its algorithm and frame, the same in every panel.
  struct Point {
    double x, y;
    std::string label, series, peer;
  };
  std::map<std::string, std::vector<Point>> by_case;
  std::vector<std::string> cases, series;
  for (const auto &r : rows) {
    if (static_cast<int>(r.size()) <= std::max(cx, std::max(cy, cv))) continue;
    if (cs >= 0 && cs < static_cast<int>(r.size()) && r[static_cast<size_t>(cs)] != "ok") continue;
    Point p;
    if (!ParseNum(r[static_cast<size_t>(cx)], &p.x) || !ParseNum(r[static_cast<size_t>(cy)], &p.y)) continue;
    if (!(p.x > 0.0) || !(p.y > 0.0)) continue;
    p.label = r[static_cast<size_t>(cv)];
    p.series = p.label;
    if (cp >= 0 && cp < static_cast<int>(r.size())) p.peer = r[static_cast<size_t>(cp)];
    if (ca >= 0 && cf >= 0 && std::max(ca, cf) < static_cast<int>(r.size()))
      p.series = r[static_cast<size_t>(ca)] + ", " + r[static_cast<size_t>(cf)];
    const std::string k = cc >= 0 && cc < static_cast<int>(r.size()) ? r[static_cast<size_t>(cc)] : std::string("bench");
    if (!by_case.count(k)) cases.push_back(k);
    if (std::find(series.begin(), series.end(), p.series) == series.end()) series.push_back(p.series);
    by_case[k].push_back(p);
  }
  if (cases.empty()) {
    *error = bench_csv + ": error: no row with a positive speed and error (status ok)";
    return false;
  }
  // Rows of one case with the same variant (a replay scored against two peers) are told apart by
  // their peer column.
  for (auto &kv : by_case) {
    std::vector<int> same(kv.second.size(), 0);
    for (size_t i = 0; i < kv.second.size(); ++i)
      for (const Point &q : kv.second) same[i] += q.label == kv.second[i].label;
    for (size_t i = 0; i < kv.second.size(); ++i)
      if (same[i] > 1 && !kv.second[i].peer.empty()) kv.second[i].label += " vs " + kv.second[i].peer;
  }
  static const unsigned char pal[10][3] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                           {148, 103, 189}, {140, 86, 75},  {227, 119, 194}, {127, 127, 127},
                                           {188, 189, 34},  {23, 190, 207}};
  static const int markers[4] = {vtkPlotPoints::CIRCLE, vtkPlotPoints::SQUARE, vtkPlotPoints::DIAMOND,
                                 vtkPlotPoints::CROSS};
  const int n = static_cast<int>(cases.size());
  const int ncols = n == 1 ? 1 : (n <= 4 ? 2 : 3);
  // Grid cells, filled left to right from the top; a case with many variants (more than fit one
  // above the other in a cell) takes two whole rows, so that its labels find room.
  constexpr size_t kBigCase = 8;
  std::vector<int> cell_col(static_cast<size_t>(n)), cell_top(static_cast<size_t>(n));
  std::vector<bool> big(static_cast<size_t>(n));
  int top = 0, colk = 0;
  for (int k = 0; k < n; ++k) {
    big[static_cast<size_t>(k)] = ncols > 1 && by_case[cases[static_cast<size_t>(k)]].size() > kBigCase;
    if (big[static_cast<size_t>(k)]) {
      if (colk != 0) {
        ++top;
        colk = 0;
      }
      cell_col[static_cast<size_t>(k)] = 0;
      cell_top[static_cast<size_t>(k)] = top;
      top += 2;
      continue;
    }
    cell_col[static_cast<size_t>(k)] = colk;
    cell_top[static_cast<size_t>(k)] = top;
    if (++colk == ncols) {
      colk = 0;
      ++top;
    }
  }
  const int nrows = top + (colk != 0 ? 1 : 0);
  ChartCanvas c;
  if (!MakeCanvas(&c, opt, nrows, error, ncols)) return false;
  for (int k = 0; k < n; ++k) {
    // Row 0 of vtkChartMatrix is at the bottom and a span grows upwards: the first case goes top left.
    const bool wide = big[static_cast<size_t>(k)];
    const int cidx = cell_col[static_cast<size_t>(k)];
    const int ridx = nrows - 1 - cell_top[static_cast<size_t>(k)] - (wide ? 1 : 0);
    if (wide) c.matrix->SetChartSpan(vtkVector2i(cidx, ridx), vtkVector2i(ncols, 2));
    vtkChartXY *chart = vtkChartXY::SafeDownCast(c.matrix->GetChart(vtkVector2i(cidx, ridx)));
    if (!chart) {
      *error = "vtkChartMatrix did not create an XY chart";
      return false;
    }
    const std::vector<Point> &pts = by_case[cases[static_cast<size_t>(k)]];
    if (layout) {
      layout->cases.push_back(cases[static_cast<size_t>(k)]);
      layout->labels.emplace_back();
      NavBenchChartLayout::Cell cell;
      cell.col = cidx;
      cell.row = cell_top[static_cast<size_t>(k)];
      cell.cols = wide ? ncols : 1;
      cell.rows = wide ? 2 : 1;
      layout->cells.push_back(cell);
    }
    double xmin = INFINITY, xmax = 0.0, ymin = INFINITY, ymax = 0.0;
    std::vector<Line> lines;
    for (size_t si = 0; si < series.size(); ++si) {
      Line l;
      l.name = series[si];
      for (const Point &p : pts)
        if (p.series == series[si]) {
          l.x.push_back(p.x);
          l.y.push_back(p.y);
        }
      if (l.x.empty()) continue;
      std::copy(pal[si % 10], pal[si % 10] + 3, l.rgb);
      l.points = true;
      l.marker = markers[(si / 10) % 4];
      l.width = 3.0f;
      lines.push_back(l);
    }
    for (const Point &p : pts) {
      xmin = std::min(xmin, p.x);
      xmax = std::max(xmax, p.x);
      ymin = std::min(ymin, p.y);
      ymax = std::max(ymax, p.y);
    }
    AddLines(chart, lines);
    // Axes: log-log; room on the right of the fastest point for its label.
    const double x_lo = xmin / 2.0, x_hi = xmax * 12.0, y_lo = ymin / 3.0, y_hi = ymax * 3.0;
    if (opt.show_text) {
      // The label layer paints in the chart's (log10) data coordinates.
      vtkNew<vtkNavLabelledPoints> lab;
      vtkNew<vtkTable> table;
      vtkNew<vtkDoubleArray> xc, yc;
      xc->SetName("speed");
      yc->SetName("labels");
      table->AddColumn(xc);
      table->AddColumn(yc);
      table->SetNumberOfRows(static_cast<vtkIdType>(pts.size()));
      for (size_t i = 0; i < pts.size(); ++i) {
        lab->x.push_back(std::log10(pts[i].x));
        lab->y.push_back(std::log10(pts[i].y));
        lab->labels.push_back(pts[i].label);
        table->SetValue(static_cast<vtkIdType>(i), 0, pts[i].x);
        table->SetValue(static_cast<vtkIdType>(i), 1, pts[i].y);
      }
      lab->font = std::max(8, c.font - 2);
      lab->y_lo = std::log10(y_lo);
      lab->y_hi = std::log10(y_hi);
      lab->SetInputData(table, 0, 1);
      lab->SetLegendVisibility(false);
      chart->AddPlot(lab);
      if (layout) layout->labels.back() = lab->labels;
    }
    const bool bottom_row = ridx == 0;
    StyleChart(chart, cases[static_cast<size_t>(k)] + " (" + std::to_string(pts.size()) + " variant" +
                          (pts.size() == 1 ? ")" : "s)"),
               bottom_row ? "speed [samples/s]" : "", cidx == 0 ? "position error [m]" : "", opt, c.font);
    chart->SetShowLegend(false); // every marker carries its variant's label
    chart->GetAxis(vtkAxis::LEFT)->SetLogScale(true);
    chart->GetAxis(vtkAxis::BOTTOM)->SetLogScale(true);
    chart->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::BOTTOM)->SetRange(x_lo, x_hi);
    chart->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::LEFT)->SetRange(y_lo, y_hi);
  }
  c.view->Render();
  return NavWriteWindowPng(c.view->GetRenderWindow(), path, error);
}

// ------------------------------------------------------------------ GNSS sky plot and DOP chart

namespace {

// Numeric columns of a CSV by name (empty fields are NaN): the files navsim run writes.
struct NumCsv {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int Col(const char *name) const {
    for (size_t i = 0; i < header.size(); ++i)
      if (header[i] == name) return static_cast<int>(i);
    return -1;
  }
  double Num(size_t r, int c) const {
    double v = NAN;
    if (c >= 0 && static_cast<size_t>(c) < rows[r].size() && ParseNum(rows[r][static_cast<size_t>(c)], &v)) return v;
    return NAN;
  }
  std::string Str(size_t r, int c) const {
    return c >= 0 && static_cast<size_t>(c) < rows[r].size() ? rows[r][static_cast<size_t>(c)] : std::string();
  }
};

bool ReadNumCsv(const std::string &path, const std::vector<const char *> &need, NumCsv *t, std::string *error) {
  if (!ReadTextCsv(path, &t->header, &t->rows, error)) return false;
  for (const char *n : need)
    if (t->Col(n) < 0) {
      *error = path + ":1: error: no column " + n + " (a file of navsim run was expected)";
      return false;
    }
  return true;
}

// Polar (azimuth from north clockwise, elevation) to the plot plane: zenith at the origin, north
// up, east right, radius 90 - elevation [deg].
void SkyXY(double az_deg, double el_deg, double *x, double *y) {
  const double r = 90.0 - el_deg, a = az_deg / kRadToDeg;
  *x = r * std::sin(a);
  *y = r * std::cos(a);
}

// Time spans [t0, t1) where a 0/1 column is 1 (rows sorted by time; a span ends at the next row).
std::vector<std::pair<double, double>> Spans(const NumCsv &t, int ct, int cflag) {
  std::vector<std::pair<double, double>> out;
  bool on = false;
  double t0 = 0.0, last = 0.0;
  for (size_t r = 0; r < t.rows.size(); ++r) {
    const double tt = t.Num(r, ct), f = t.Num(r, cflag);
    if (!std::isfinite(tt)) continue;
    const bool now = f > 0.5;
    if (now && !on) t0 = tt;
    if (!now && on) out.push_back({t0, tt});
    on = now;
    last = tt;
  }
  if (on) out.push_back({t0, last});
  return out;
}

} // namespace

bool NavRenderSkyPlotPng(const std::string &dir, const NavChartOptions &opt, const std::string &path,
                         std::string *error) {
  NumCsv sats, mask;
  if (!ReadNumCsv(dir + "/gnss_sats.csv", {"t_s", "system", "prn", "az_deg", "el_deg", "visible"}, &sats, error))
    return false;
  const bool have_mask = ReadNumCsv(dir + "/gnss_mask.csv", {"t_s", "in_canyon", "az_deg", "mask_el_deg"}, &mask,
                                    error);
  if (!have_mask) error->clear(); // an older result directory: no mask file, the tracks only
  const int ct = sats.Col("t_s"), cs = sats.Col("system"), cp = sats.Col("prn"), ca = sats.Col("az_deg"),
            ce = sats.Col("el_deg"), cv = sats.Col("visible");
  std::vector<Line> lines;
  // Grid: elevation rings 0, 30, 60 deg and spokes every 30 deg of azimuth.
  for (int ring = 0; ring < 3; ++ring) {
    Line l;
    l.name = "rings: elevation 0, 30, 60 deg";
    l.legend = ring == 0;
    for (int a = 0; a <= 360; a += 3) {
      double x, y;
      SkyXY(a, 30.0 * ring, &x, &y);
      l.x.push_back(x);
      l.y.push_back(y);
    }
    l.rgb[0] = l.rgb[1] = l.rgb[2] = 175;
    l.width = 1.0f;
    lines.push_back(l);
  }
  for (int a = 0; a < 360; a += 30) {
    Line l;
    l.name = "grid";
    l.legend = false;
    double x, y;
    SkyXY(a, 90.0, &x, &y);
    l.x.push_back(x);
    l.y.push_back(y);
    SkyXY(a, 0.0, &x, &y);
    l.x.push_back(x);
    l.y.push_back(y);
    l.rgb[0] = l.rgb[1] = l.rgb[2] = 205;
    l.width = 0.8f;
    lines.push_back(l);
  }
  // Masks: one closed curve per block of gnss_mask.csv (the open-sky mask, each canyon).
  if (have_mask) {
    const int mt = mask.Col("t_s"), mc = mask.Col("in_canyon"), ma = mask.Col("az_deg"), me = mask.Col("mask_el_deg");
    Line cur;
    double cur_t = NAN;
    auto flush = [&]() {
      if (cur.x.empty()) return;
      lines.push_back(cur);
      cur = Line();
    };
    bool open_named = false, canyon_named = false;
    for (size_t r = 0; r < mask.rows.size(); ++r) {
      const double t = mask.Num(r, mt);
      if (!(t == cur_t)) {
        flush();
        cur_t = t;
        const bool canyon = mask.Num(r, mc) > 0.5;
        cur.name = canyon ? "canyon walls (mid-canyon)" : "elevation mask";
        cur.legend = canyon ? !canyon_named : !open_named;
        (canyon ? canyon_named : open_named) = true;
        const unsigned char brown[3] = {140, 86, 75}, black[3] = {40, 40, 40};
        std::copy(canyon ? brown : black, (canyon ? brown : black) + 3, cur.rgb);
        cur.width = canyon ? 2.5f : 2.0f;
        cur.pen = canyon ? vtkPen::SOLID_LINE : vtkPen::DASH_LINE;
      }
      double x, y;
      SkyXY(mask.Num(r, ma), mask.Num(r, me), &x, &y);
      cur.x.push_back(x);
      cur.y.push_back(y);
    }
    flush();
  }
  // Tracks: GPS blue, GLONASS red; visible epochs as markers, masked ones as small grey dots.
  Line vis[2], hid;
  const unsigned char col[2][3] = {{31, 119, 180}, {214, 39, 40}};
  const char *sys_name[2] = {"GPS in view", "GLONASS in view"};
  for (int k = 0; k < 2; ++k) {
    vis[k].name = sys_name[k];
    std::copy(col[k], col[k] + 3, vis[k].rgb);
    vis[k].points = true;
    vis[k].width = 2.4f;
  }
  hid.name = "masked (above the horizon)";
  hid.rgb[0] = hid.rgb[1] = hid.rgb[2] = 120;
  hid.points = true;
  hid.width = 1.0f;
  hid.marker = vtkPlotPoints::CROSS;
  struct Last {
    double x, y, t;
    int seen, in_view;
  };
  std::map<std::string, Last> last; // label position of each satellite: its last point
  double t_min = INFINITY, t_max = -INFINITY;
  for (size_t r = 0; r < sats.rows.size(); ++r) {
    const double az = sats.Num(r, ca), el = sats.Num(r, ce), t = sats.Num(r, ct);
    if (!std::isfinite(az) || !std::isfinite(el) || !std::isfinite(t)) continue;
    double x, y;
    SkyXY(az, el, &x, &y);
    const std::string sys = sats.Str(r, cs);
    const int k = sys == "R" ? 1 : 0;
    if (sats.Num(r, cv) > 0.5) {
      vis[k].x.push_back(x);
      vis[k].y.push_back(y);
    } else {
      hid.x.push_back(x);
      hid.y.push_back(y);
    }
    const std::string id = sys + sats.Str(r, cp);
    Last &L = last[id];
    L.x = x;
    L.y = y;
    L.t = t;
    L.seen++;
    L.in_view += sats.Num(r, cv) > 0.5;
    t_min = std::min(t_min, t);
    t_max = std::max(t_max, t);
  }
  if (last.empty()) {
    *error = dir + "/gnss_sats.csv: error: no satellite above the horizon";
    return false;
  }
  for (int k = 0; k < 2; ++k) lines.push_back(vis[k]);
  lines.push_back(hid);

  ChartCanvas c;
  if (!MakeCanvas(&c, opt, 1, error)) return false;
  vtkChartXY *chart = Panel(&c, 0);
  if (!chart) {
    *error = "vtkChartMatrix did not create an XY chart";
    return false;
  }
  AddLines(chart, lines);
  // PRN labels at the end of each track.
  vtkNew<vtkNavLabelledPoints> lab;
  for (const auto &kv : last) {
    lab->x.push_back(kv.second.x);
    lab->y.push_back(kv.second.y);
    // PRN and the share of its epochs above the horizon in which it was in view.
    char text[48];
    std::snprintf(text, sizeof text, "%s %d%%", kv.first.c_str(),
                  static_cast<int>(std::lround(100.0 * kv.second.in_view / std::max(kv.second.seen, 1))));
    lab->labels.push_back(text);
  }
  lab->y_lo = -95.0;
  lab->y_hi = 95.0;
  lab->font = std::max(9, c.font - 2);
  if (opt.show_text) {
    chart->AddPlot(lab);
    lab->SetLegendVisibility(false);
  }
  char title[160];
  std::snprintf(title, sizeof title, "sky plot of run 0, t = %.0f..%.0f s (north up, east right, zenith at the centre; label: PRN, share of time in view)",
                t_min, t_max);
  StyleChart(chart, title, "east  [deg from zenith]", "north  [deg from zenith]", opt, c.font);
  // The legend in the empty left part of the wide plot area, clear of the sky circle.
  if (opt.show_text) chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::LEFT);
  // Equal scales on both axes: the x range follows the plot area's aspect (borders of MakeCanvas).
  const double f = c.font;
  const double pw = opt.width_px - (opt.show_text ? 6.7 : 2.5) * f, ph = opt.height_px - (opt.show_text ? 5.6 : 2.0) * f;
  const double half_y = 95.0, half_x = half_y * std::max(1.0, pw / std::max(ph, 1.0));
  chart->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
  chart->GetAxis(vtkAxis::LEFT)->SetRange(-half_y, half_y);
  chart->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
  chart->GetAxis(vtkAxis::BOTTOM)->SetRange(-half_x, half_x);
  chart->GetAxis(vtkAxis::LEFT)->SetGridVisible(false);
  chart->GetAxis(vtkAxis::BOTTOM)->SetGridVisible(false);
  c.view->Render();
  return NavWriteWindowPng(c.view->GetRenderWindow(), path, error);
}

bool NavRenderDopChartPng(const std::string &dir, const NavChartOptions &opt, const std::string &path,
                          std::string *error) {
  NumCsv dop;
  if (!ReadNumCsv(dir + "/gnss_dop.csv", {"t_s", "n_visible", "gdop", "pdop", "hdop", "vdop", "in_canyon"}, &dop,
                  error))
    return false;
  if (dop.rows.empty()) {
    *error = dir + "/gnss_dop.csv: error: no epoch";
    return false;
  }
  const int ct = dop.Col("t_s");
  const char *names[4] = {"gdop", "pdop", "hdop", "vdop"};
  const char *labels[4] = {"GDOP", "PDOP", "HDOP", "VDOP"};
  static const unsigned char pal[4][3] = {{148, 103, 189}, {31, 119, 180}, {44, 160, 44}, {255, 127, 14}};
  std::vector<Line> top, bottom;
  double dmax = 1.0, nmax = 1.0;
  const double t_end = dop.Num(dop.rows.size() - 1, ct);
  // DOP lines break where the geometry has no solution (empty fields): one segment per run of rows.
  for (int k = 0; k < 4; ++k) {
    const int cd = dop.Col(names[k]);
    Line seg;
    bool named = false;
    auto flush = [&]() {
      if (seg.x.empty()) return;
      seg.name = labels[k];
      seg.legend = !named;
      named = true;
      std::copy(pal[k], pal[k] + 3, seg.rgb);
      seg.width = 2.0f;
      top.push_back(seg);
      seg = Line();
    };
    for (size_t r = 0; r < dop.rows.size(); ++r) {
      const double v = dop.Num(r, cd), t = dop.Num(r, ct);
      if (!std::isfinite(v) || !std::isfinite(t)) {
        flush();
        continue;
      }
      seg.x.push_back(t);
      seg.y.push_back(v);
      dmax = std::max(dmax, v);
    }
    flush();
  }
  Line count;
  count.name = "satellites in view";
  count.rgb[0] = 31;
  count.rgb[1] = 119;
  count.rgb[2] = 180;
  count.width = 2.0f;
  const int cn = dop.Col("n_visible");
  for (size_t r = 0; r < dop.rows.size(); ++r) {
    const double t = dop.Num(r, ct), n = dop.Num(r, cn);
    if (!std::isfinite(t) || !std::isfinite(n)) continue;
    // A step line: hold the count until the next epoch.
    if (!count.x.empty()) {
      count.x.push_back(t);
      count.y.push_back(count.y.back());
    }
    count.x.push_back(t);
    count.y.push_back(n);
    nmax = std::max(nmax, n);
  }
  bottom.push_back(count);
  Line four;
  four.name = "4: fewest for a position fix (one system)";
  four.x = {0.0, t_end};
  four.y = {4.0, 4.0};
  four.rgb[0] = four.rgb[1] = four.rgb[2] = 110;
  four.pen = vtkPen::DASH_LINE;
  four.width = 1.2f;
  bottom.push_back(four);
  // Canyon spans (gnss_dop.csv in_canyon) and receiver outages (gnss_outages.csv, loosely coupled
  // runs) as vertical bars spanning each panel.
  const double ytop[2] = {std::ceil(dmax * 1.15), std::ceil(nmax + 2.0)};
  std::vector<std::pair<double, double>> canyons = Spans(dop, ct, dop.Col("in_canyon"));
  std::vector<std::pair<double, double>> outages;
  {
    NumCsv o;
    std::string e2;
    if (ReadNumCsv(dir + "/gnss_outages.csv", {"t0_s", "t1_s"}, &o, &e2))
      for (size_t r = 0; r < o.rows.size(); ++r)
        outages.push_back({o.Num(r, o.Col("t0_s")), o.Num(r, o.Col("t1_s"))});
  }
  for (int panel = 0; panel < 2; ++panel) {
    std::vector<Line> &ls = panel == 0 ? top : bottom;
    for (int kind = 0; kind < 2; ++kind) {
      const auto &spans = kind == 0 ? canyons : outages;
      bool named = false;
      for (const auto &sp : spans) {
        Line b;
        b.name = kind == 0 ? "street canyon" : "receiver outage (no fix)";
        b.legend = !named;
        named = true;
        const double y0 = kind == 0 ? 0.0 : 0.03 * ytop[panel], y1 = kind == 0 ? ytop[panel] : 0.97 * ytop[panel];
        b.x = {sp.first, sp.first, sp.second, sp.second};
        b.y = {y0, y1, y1, y0};
        if (kind == 0) {
          b.rgb[0] = 140;
          b.rgb[1] = 86;
          b.rgb[2] = 75;
          b.width = 2.5f;
        } else {
          b.rgb[0] = 214;
          b.rgb[1] = 39;
          b.rgb[2] = 40;
          b.pen = vtkPen::DASH_LINE;
          b.width = 1.5f;
        }
        ls.push_back(b);
      }
    }
  }
  ChartCanvas c;
  if (!MakeCanvas(&c, opt, 2, error)) return false;
  vtkChartXY *ch[2] = {Panel(&c, 1), Panel(&c, 0)}; // matrix row 1 is the top panel
  if (!ch[0] || !ch[1]) {
    *error = "vtkChartMatrix did not create an XY chart";
    return false;
  }
  AddLines(ch[0], top);
  AddLines(ch[1], bottom);
  StyleChart(ch[0], "dilution of precision of run 0 (empty: fewer satellites than a position needs)", "time [s]",
             "DOP [-]", opt, c.font);
  StyleChart(ch[1], "satellites in view", "time [s]", "count [-]", opt, c.font);
  for (int p = 0; p < 2; ++p) {
    ch[p]->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
    ch[p]->GetAxis(vtkAxis::LEFT)->SetRange(0.0, ytop[p]);
    ch[p]->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
    ch[p]->GetAxis(vtkAxis::BOTTOM)->SetRange(0.0, t_end);
  }
  c.view->Render();
  return NavWriteWindowPng(c.view->GetRenderWindow(), path, error);
}
