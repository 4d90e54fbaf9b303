// Error-versus-time charts (nav_view_chart.h): three vtkChartXY panels in a vtkChartMatrix,
// rendered offscreen in a vtkContextView and written as PNG.
#include "navview/nav_view_chart.h"

#include "navview_internal.h"
#include "navview/nav_view_model.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <cmath>
#include <cstdio>
#include <set>

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartMatrix.h>
#include <vtkChartXY.h>
#include <vtkContext2D.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotArea.h>
#include <vtkRenderWindow.h>
#include <vtkRect.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkVector.h>

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
// GNSS outage spans: the pink of the 3D view's outage band.
constexpr double kOutageRgb[3] = {0.96, 0.50, 0.80};

struct Series {
  std::string name;
  std::vector<double> y;
  unsigned char rgb[3];
  int pen = vtkPen::SOLID_LINE;
  float width = 1.5f;
};

// Rows to draw: per bucket of consecutive epochs, the first, last, minimum and maximum of every
// series, so peaks survive the thinning.
std::vector<size_t> ThinRows(size_t n, const std::vector<Series> &series, int max_points) {
  std::vector<size_t> rows;
  const size_t buckets = static_cast<size_t>(std::max(max_points / 4, 16));
  if (n <= static_cast<size_t>(std::max(max_points, 16))) {
    rows.resize(n);
    for (size_t i = 0; i < n; ++i)
      rows[i] = i;
    return rows;
  }
  std::set<size_t> keep;
  for (size_t b = 0; b < buckets; ++b) {
    const size_t i0 = b * n / buckets, i1 = std::max(i0 + 1, (b + 1) * n / buckets);
    keep.insert(i0);
    keep.insert(i1 - 1);
    for (const Series &s : series) {
      auto mm = std::minmax_element(s.y.begin() + static_cast<long>(i0), s.y.begin() + static_cast<long>(i1));
      keep.insert(static_cast<size_t>(mm.first - s.y.begin()));
      keep.insert(static_cast<size_t>(mm.second - s.y.begin()));
    }
  }
  rows.assign(keep.begin(), keep.end());
  return rows;
}

void StyleAxis(vtkAxis *axis, const std::string &title, bool text, int font) {
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

// One panel: the outage spans shaded (under everything), a band [lo, hi] when given, lines for
// the series; the y axis fixed to [y_lo, y_hi] so that the spans fill the plot's height.
void FillChart(vtkChartXY *chart, const std::string &title, const std::string &ytitle, bool xtitle,
               const std::vector<double> &t, const std::vector<Series> &series, const std::vector<double> *lo,
               const std::vector<double> *hi, const std::string &band_name,
               const std::vector<std::pair<double, double>> &outages, double y_lo, double y_hi,
               const NavChartOptions &opt, int font) {
  std::vector<Series> all = series;
  if (lo && hi) {
    all.push_back({"lo", *lo, {0, 0, 0}});
    all.push_back({"hi", *hi, {0, 0, 0}});
  }
  const std::vector<size_t> rows = ThinRows(t.size(), all, opt.max_points);
  vtkNew<vtkTable> table;
  vtkNew<vtkDoubleArray> tc;
  tc->SetName("t_s");
  table->AddColumn(tc);
  for (const Series &s : all) {
    vtkNew<vtkDoubleArray> c;
    c->SetName(s.name.c_str());
    table->AddColumn(c);
  }
  table->SetNumberOfRows(static_cast<vtkIdType>(rows.size()));
  for (size_t r = 0; r < rows.size(); ++r) {
    table->SetValue(static_cast<vtkIdType>(r), 0, t[rows[r]]);
    for (size_t k = 0; k < all.size(); ++k)
      table->SetValue(static_cast<vtkIdType>(r), static_cast<vtkIdType>(k + 1), all[k].y[rows[r]]);
  }
  if (!outages.empty() && t.size() >= 2) {
    // Each span as four points (t0 empty, t0 full, t1 full, t1 empty): vertical edges.
    vtkNew<vtkTable> spans;
    const char *names[3] = {"t_s", "lo", "hi"};
    for (const char *n : names) {
      vtkNew<vtkDoubleArray> c;
      c->SetName(n);
      spans->AddColumn(c);
    }
    std::vector<std::array<double, 3>> pts;
    for (const auto &o : outages) {
      const double a = std::max(o.first, t.front()), b = std::min(o.second, t.back());
      if (!(b > a)) continue;
      pts.push_back({a, y_lo, y_lo});
      pts.push_back({a, y_lo, y_hi});
      pts.push_back({b, y_lo, y_hi});
      pts.push_back({b, y_lo, y_lo});
    }
    if (!pts.empty()) {
      spans->SetNumberOfRows(static_cast<vtkIdType>(pts.size()));
      for (size_t r = 0; r < pts.size(); ++r)
        for (int k = 0; k < 3; ++k)
          spans->SetValue(static_cast<vtkIdType>(r), k, pts[r][static_cast<size_t>(k)]);
      vtkNew<vtkPlotArea> area;
      area->SetInputData(spans);
      area->SetInputArray(0, "t_s");
      area->SetInputArray(1, "lo");
      area->SetInputArray(2, "hi");
      area->GetBrush()->SetColorF(kOutageRgb[0], kOutageRgb[1], kOutageRgb[2], 0.22);
      area->GetPen()->SetLineType(vtkPen::NO_PEN);
      area->SetLabel("GNSS outage");
      chart->AddPlot(area);
    }
  }
  if (lo && hi) {
    vtkNew<vtkPlotArea> area;
    area->SetInputData(table);
    area->SetInputArray(0, "t_s");
    area->SetInputArray(1, "lo");
    area->SetInputArray(2, "hi");
    area->GetBrush()->SetColorF(0.35, 0.55, 0.95, 0.25);
    area->GetPen()->SetLineType(vtkPen::NO_PEN);
    area->SetLabel(band_name);
    chart->AddPlot(area);
  }
  for (size_t k = 0; k < series.size(); ++k) {
    vtkPlot *line = chart->AddPlot(vtkChart::LINE);
    line->SetInputData(table, 0, static_cast<vtkIdType>(k + 1));
    line->SetColor(series[k].rgb[0], series[k].rgb[1], series[k].rgb[2], 255);
    line->SetWidth(series[k].width);
    line->GetPen()->SetLineType(series[k].pen);
    line->SetLabel(series[k].name);
  }
  chart->SetTitle(opt.show_text ? title : std::string());
  NavApplyFont(chart->GetTitleProperties());
  chart->GetTitleProperties()->SetFontSize(font + 1);
  chart->GetTitleProperties()->SetColor(0.05, 0.05, 0.08);
  chart->GetTitleProperties()->BoldOn();
  StyleAxis(chart->GetAxis(vtkAxis::LEFT), ytitle, opt.show_text, font);
  StyleAxis(chart->GetAxis(vtkAxis::BOTTOM), xtitle ? "time [s]" : "", opt.show_text, font);
  if (t.size() >= 2 && t.back() > t.front()) {
    chart->GetAxis(vtkAxis::BOTTOM)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::BOTTOM)->SetRange(t.front(), t.back());
  }
  if (std::isfinite(y_lo) && std::isfinite(y_hi) && y_hi > y_lo) {
    chart->GetAxis(vtkAxis::LEFT)->SetBehavior(vtkAxis::FIXED);
    chart->GetAxis(vtkAxis::LEFT)->SetRange(y_lo, y_hi);
  }
  chart->SetShowLegend(opt.show_text);
  if (opt.show_text) {
    NavApplyFont(chart->GetLegend()->GetLabelProperties());
    chart->GetLegend()->GetLabelProperties()->SetFontSize(font - 2);
    chart->GetLegend()->GetLabelProperties()->SetColor(0.05, 0.05, 0.08);
    chart->GetLegend()->GetBrush()->SetColorF(1.0, 1.0, 1.0, 0.8);
  }
}

// The y range of a panel: every finite value of the series and the band, with a margin above
// (and below when negative values occur).
void PanelRange(const std::vector<Series> &series, const std::vector<double> *lo,
                const std::vector<double> *hi, double *y_lo, double *y_hi) {
  double mn = 0.0, mx = 0.0;
  auto take = [&](const std::vector<double> &v) {
    for (double x : v)
      if (std::isfinite(x)) {
        mn = std::min(mn, x);
        mx = std::max(mx, x);
      }
  };
  for (const Series &s : series)
    take(s.y);
  if (lo) take(*lo);
  if (hi) take(*hi);
  if (!(mx > mn)) mx = mn + 1.0;
  const double m = 0.08 * (mx - mn);
  *y_lo = mn < 0.0 ? mn - m : 0.0;
  *y_hi = mx + m;
}

// A requirement limit's line: PASS dark grey, FAIL red; the limits of one panel in different
// dash patterns (two FAIL limits in one panel are told apart by their pattern).
Series LimitSeries(const NavRequirementVerdict &r, size_t n, double scale, int index_in_panel) {
  static const int kPens[4] = {vtkPen::DASH_DOT_LINE, vtkPen::DASH_LINE, vtkPen::DOT_LINE,
                               vtkPen::DASH_DOT_DOT_LINE};
  char buf[160];
  std::snprintf(buf, sizeof buf, "limit %s: %s %g %s (%s)", r.id.c_str(), r.statistic.c_str(), r.limit,
                r.unit.c_str(), r.pass ? "pass" : "FAIL");
  Series s{buf, std::vector<double>(n, r.limit_si * scale), {0, 0, 0}, kPens[index_in_panel % 4], 2.0f};
  const unsigned char pass_rgb[2][3] = {{40, 40, 40}, {0, 110, 60}};
  const unsigned char fail_rgb[2][3] = {{200, 0, 0}, {150, 40, 150}};
  const unsigned char *c = r.pass ? pass_rgb[(index_in_panel / 4) % 2] : fail_rgb[(index_in_panel / 4) % 2];
  for (int k = 0; k < 3; ++k)
    s.rgb[k] = c[k];
  return s;
}

// The error panels in a context view of the options' size (NavRenderErrorChartPng/Rgb).
bool BuildErrorChart(const NavResult &result, const NavChartOptions &opt, vtkContextView *view,
                     std::string *error, NavErrorChartLayout *layout = nullptr) {
  const NavErrorSeries &e = result.errors;
  if (e.Size() < 2) {
    *error = (result.dir.empty() ? std::string("result") : result.dir) +
             ": error: no errors.csv (or fewer than two epochs): nothing to chart";
    return false;
  }
  if (opt.width_px < 64 || opt.height_px < 64 || opt.width_px > 8192 || opt.height_px > 8192) {
    *error = "chart size out of range (64..8192 pixels)";
    return false;
  }
  if (!NavCheckDisplay(error)) return false;
  const size_t n = e.Size();
  const NavEnvelope &env = result.envelope;
  const bool mc = env.Size() > 0;
  const bool vel = e.vel_err_mps.size() == n;
  const double k = opt.band_k;
  char buf[160];

  std::vector<double> zero(n, 0.0), h_hi(n), v_hi(n), s_hi(n), a_lo(n), a_hi(n);
  const bool vel_band = mc && env.vel_rms_mps.size() == env.Size();
  if (mc) {
    for (size_t i = 0; i < n; ++i) {
      h_hi[i] = k * NavInterpolate(env.t_s, env.pos_h_rms_m, 1, 0, e.t_s[i]);
      v_hi[i] = k * NavInterpolate(env.t_s, env.pos_rms_ned_m, 3, 2, e.t_s[i]);
      s_hi[i] = vel_band ? k * NavInterpolate(env.t_s, env.vel_rms_mps, 1, 0, e.t_s[i]) : NAN;
      const double a =
          env.att_rms_rad.empty() ? NAN : k * NavInterpolate(env.t_s, env.att_rms_rad, 1, 0, e.t_s[i]);
      a_lo[i] = -a * kRadToDeg;
      a_hi[i] = a * kRadToDeg;
    }
  }
  std::vector<double> roll(n), pitch(n), yaw(n);
  for (size_t i = 0; i < n; ++i) {
    roll[i] = e.euler_err_rad[3 * i] * kRadToDeg;
    pitch[i] = e.euler_err_rad[3 * i + 1] * kRadToDeg;
    yaw[i] = e.euler_err_rad[3 * i + 2] * kRadToDeg;
  }
  std::vector<std::pair<double, double>> outages;
  for (size_t i = 0; i < result.gnss.outage_t0_s.size() && i < result.gnss.outage_t1_s.size(); ++i)
    outages.emplace_back(result.gnss.outage_t0_s[i], result.gnss.outage_t1_s[i]);

  NavAttachDisplay(view->GetRenderWindow());
  view->GetRenderWindow()->SetOffScreenRendering(1);
  // A headless chart needs no interactor. vtkContextView creates one, and the first Render()
  // initialises it (vtkXRenderWindowInteractor::Initialize -> XSync), which crashed
  // intermittently under Xvfb (7th of 40 runs under load; backtrace in XSync). Detach it.
  view->GetRenderWindow()->SetInteractor(nullptr);
  view->GetRenderWindow()->SetSize(opt.width_px, opt.height_px);
  view->GetRenderWindow()->SetMultiSamples(8);
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);

  std::snprintf(buf, sizeof buf, "0 .. %g\u00d7 RMS over %d runs", k, result.runs);
  const std::string band = buf;
  std::snprintf(buf, sizeof buf, "\u00b1%g\u00d7 RMS attitude error", k);
  const std::string aband = buf;
  const std::string who = result.scene_name.empty() ? std::string() : result.scene_name + ": ";
  std::vector<Series> hs = {{"run 0", e.pos_err_h_m, {214, 39, 40}}};
  std::vector<Series> vs = {{"run 0", e.pos_err_v_m, {214, 39, 40}}};
  std::vector<Series> ss;
  if (vel) ss.push_back({"run 0", e.vel_err_mps, {214, 39, 40}});
  std::vector<Series> as = {{"roll", roll, {204, 20, 20}}, {"pitch", pitch, {20, 140, 30}}, {"yaw", yaw, {20, 60, 210}}};
  // Further k-sigma curves: the filter's reported sigma (mean over runs) and the covariance
  // analysis, when the result carries them.
  const NavEnvelopeSource more[2] = {NavEnvelopeSource::Filter, NavEnvelopeSource::Covariance};
  const unsigned char more_rgb[2][3] = {{20, 120, 200}, {120, 60, 170}};
  for (int m = 0; m < 2; ++m) {
    std::vector<double> sh(n), sv(n);
    bool ok = true;
    for (size_t i = 0; i < n && ok; ++i) {
      double s3[3];
      ok = NavSigmaNed(result, more[m], e.t_s[i], s3);
      if (!ok) break;
      sh[i] = k * std::hypot(s3[0], s3[1]);
      sv[i] = k * s3[2];
    }
    if (!ok) continue;
    std::snprintf(buf, sizeof buf, "%g\u00d7 %s", k, NavEnvelopeSourceName(more[m]));
    Series a{buf, sh, {more_rgb[m][0], more_rgb[m][1], more_rgb[m][2]}, vtkPen::DASH_LINE, 1.5f};
    hs.push_back(a);
    a.y = sv;
    vs.push_back(a);
  }
  // Requirement limits as lines (summary.json "requirements"), each in its panel's next style.
  int limits_in[4] = {0, 0, 0, 0};
  for (const NavRequirementVerdict &r : result.requirements) {
    std::vector<Series> *dst = nullptr;
    double scale = 1.0;
    int panel = 0;
    if (r.metric == "horizontal_position") {
      dst = &hs;
    } else if (r.metric == "vertical_position") {
      dst = &vs;
      panel = 1;
    } else if (r.metric == "velocity" && vel) {
      dst = &ss;
      panel = 2;
    } else if (r.metric == "roll_pitch" || r.metric == "yaw") {
      dst = &as;
      scale = kRadToDeg;
      panel = 3;
    }
    if (!dst || !(r.limit_si > 0.0)) continue;
    dst->push_back(LimitSeries(r, n, scale, limits_in[panel]++));
  }

  // Panels top to bottom: horizontal, vertical, velocity (when errors.csv has it), attitude.
  const int rows = vel ? 4 : 3;
  vtkNew<vtkChartMatrix> matrix;
  matrix->SetSize(vtkVector2i(1, rows));
  const int font = std::max(10, static_cast<int>(std::lround(opt.height_px / (vel ? 66.0 : 58.0))));
  const bool text = opt.show_text;
  // The legends stand right of the plots, off the data: the right border is as wide as the
  // longest legend entry (DejaVu Sans averages about 0.58 em a character).
  size_t longest = std::max(band.size(), aband.size());
  for (const auto *v : {&hs, &vs, &ss, &as})
    for (const Series &x : *v)
      longest = std::max(longest, x.name.size());
  const int legend_px =
      text ? std::min(static_cast<int>(0.45 * opt.width_px),
                      static_cast<int>(0.58 * (font - 2) * static_cast<double>(longest)) + 3 * font)
           : 0;
  // Left: tick labels and axis title; bottom: time axis; top and gutters: the panel titles.
  matrix->SetBorders(static_cast<int>((text ? 4.8 : 1.0) * font), static_cast<int>((text ? 3.4 : 1.0) * font),
                     static_cast<int>(1.5 * font) + legend_px, static_cast<int>((text ? 2.2 : 1.0) * font));
  matrix->SetGutter(vtkVector2f(0.0f, static_cast<float>((text ? 4.0 : 1.0) * font)));
  view->GetScene()->AddItem(matrix);

  std::vector<vtkChartXY *> charts;
  for (int r = rows - 1; r >= 0; --r)
    charts.push_back(vtkChartXY::SafeDownCast(matrix->GetChart(vtkVector2i(0, r))));
  for (vtkChartXY *c : charts)
    if (!c) {
      *error = "vtkChartMatrix did not create XY charts";
      return false;
    }
  double lo = 0.0, hi = 0.0;
  size_t next = 0;
  PanelRange(hs, mc ? &zero : nullptr, mc ? &h_hi : nullptr, &lo, &hi);
  FillChart(charts[next++], who + "horizontal position error", "horizontal [m]", false, e.t_s, hs,
            mc ? &zero : nullptr, mc ? &h_hi : nullptr, band, outages, lo, hi, opt, font);
  PanelRange(vs, mc ? &zero : nullptr, mc ? &v_hi : nullptr, &lo, &hi);
  FillChart(charts[next++], "vertical position error", "vertical [m]", false, e.t_s, vs, mc ? &zero : nullptr,
            mc ? &v_hi : nullptr, band, outages, lo, hi, opt, font);
  if (vel) {
    PanelRange(ss, vel_band ? &zero : nullptr, vel_band ? &s_hi : nullptr, &lo, &hi);
    FillChart(charts[next++], "velocity error", "velocity [m/s]", false, e.t_s, ss,
              vel_band ? &zero : nullptr, vel_band ? &s_hi : nullptr, band, outages, lo, hi, opt, font);
  }
  const bool att_band = mc && !env.att_rms_rad.empty();
  PanelRange(as, att_band ? &a_lo : nullptr, att_band ? &a_hi : nullptr, &lo, &hi);
  FillChart(charts[next++], "attitude error (run 0)", "attitude [\u00b0]", true, e.t_s, as,
            att_band ? &a_lo : nullptr, att_band ? &a_hi : nullptr, aband, outages, lo, hi, opt, font);
  view->Render(); // lays the panels out: their plot corners are known from here on
  if (text) {
    for (vtkChartXY *c : charts) {
      // Top-left corner of the legend just right of the plot's top-right corner.
      int p2[2];
      c->GetPoint2(p2);
      const double entries = static_cast<double>(c->GetNumberOfPlots());
      const double legend_h = entries * (1.25 * (font - 2) + 5.0) + 5.0;
      vtkChartLegend *l = c->GetLegend();
      l->SetHorizontalAlignment(vtkChartLegend::CUSTOM);
      l->SetVerticalAlignment(vtkChartLegend::CUSTOM);
      l->SetPoint(vtkVector2f(static_cast<float>(p2[0] + 0.6 * font), static_cast<float>(p2[1] - legend_h)));
    }
    view->Render();
  }
  if (layout) {
    *layout = NavErrorChartLayout();
    const char *titles[4] = {"horizontal", "vertical", vel ? "velocity" : "attitude", "attitude"};
    for (size_t i = 0; i < charts.size(); ++i) {
      vtkChartXY *c = charts[i];
      int p1[2], p2[2];
      c->GetPoint1(p1);
      c->GetPoint2(p2);
      layout->titles.push_back(titles[i]);
      layout->plots.push_back({double(p1[0]), double(p1[1]), double(p2[0] - p1[0]), double(p2[1] - p1[1])});
      NavChartRect lr;
      if (c->GetShowLegend()) {
        // The box of the last paint (vtkChartLegend caches it while nothing changed).
        const vtkRectf r = c->GetLegend()->GetBoundingRect(view->GetContext());
        lr = {r.GetX(), r.GetY(), r.GetWidth(), r.GetHeight()};
      }
      layout->legends.push_back(lr);
      std::vector<int> pens;
      for (vtkIdType pi = 0; pi < c->GetNumberOfPlots(); ++pi) {
        vtkPlot *p = c->GetPlot(pi);
        const std::string label = p->GetLabel();
        if (label.compare(0, 6, "limit ") == 0) pens.push_back(p->GetPen()->GetLineType());
      }
      layout->limit_pens.push_back(pens);
      layout->t_min_s.push_back(c->GetAxis(vtkAxis::BOTTOM)->GetMinimum());
      layout->t_max_s.push_back(c->GetAxis(vtkAxis::BOTTOM)->GetMaximum());
      layout->y_min.push_back(c->GetAxis(vtkAxis::LEFT)->GetMinimum());
      layout->y_max.push_back(c->GetAxis(vtkAxis::LEFT)->GetMaximum());
    }
  }
  return true;
}

} // namespace

bool NavRenderErrorChartPng(const NavResult &result, const NavChartOptions &opt, const std::string &path,
                            std::string *error) {
  vtkNew<vtkContextView> view;
  if (!BuildErrorChart(result, opt, view, error)) return false;
  return NavWriteWindowPng(view->GetRenderWindow(), path, error);
}

bool NavRenderErrorChartRgb(const NavResult &result, const NavChartOptions &opt,
                            std::vector<unsigned char> *rgb, std::string *error) {
  return NavRenderErrorChartRgb(result, opt, rgb, nullptr, error);
}

bool NavRenderErrorChartRgb(const NavResult &result, const NavChartOptions &opt,
                            std::vector<unsigned char> *rgb, NavErrorChartLayout *layout, std::string *error) {
  vtkNew<vtkContextView> view;
  if (!BuildErrorChart(result, opt, view, error, layout)) return false;
  const int w = opt.width_px, h = opt.height_px;
  unsigned char *px = view->GetRenderWindow()->GetPixelData(0, 0, w - 1, h - 1, 0, 0);
  if (!px) {
    *error = "chart: cannot read the picture back";
    return false;
  }
  // OpenGL's rows run bottom to top.
  const size_t row = static_cast<size_t>(w) * 3;
  rgb->resize(row * static_cast<size_t>(h));
  for (int y = 0; y < h; ++y)
    std::memcpy(rgb->data() + static_cast<size_t>(y) * row, px + static_cast<size_t>(h - 1 - y) * row, row);
  delete[] px;
  return true;
}
