// Error-versus-time charts (nav_view_chart.h): three vtkChartXY panels in a vtkChartMatrix,
// rendered offscreen in a vtkContextView and written as PNG.
#include "navview/nav_view_chart.h"

#include "navview_internal.h"
#include "navview/nav_view_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

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
#include <vtkPlotArea.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkVector.h>

namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

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

// One panel: lines for the series, and a band [lo, hi] when given.
void FillChart(vtkChartXY *chart, const std::string &title, const std::string &ytitle, bool xtitle,
               const std::vector<double> &t, const std::vector<Series> &series, const std::vector<double> *lo,
               const std::vector<double> *hi, const std::string &band_name, const NavChartOptions &opt,
               int font) {
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
  chart->SetShowLegend(opt.show_text);
  if (opt.show_text) {
    NavApplyFont(chart->GetLegend()->GetLabelProperties());
    chart->GetLegend()->GetLabelProperties()->SetFontSize(font - 2);
    chart->GetLegend()->GetLabelProperties()->SetColor(0.05, 0.05, 0.08);
    chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
    chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
    chart->GetLegend()->GetBrush()->SetColorF(1.0, 1.0, 1.0, 0.8);
  }
}

} // namespace

bool NavRenderErrorChartPng(const NavResult &result, const NavChartOptions &opt, const std::string &path,
                            std::string *error) {
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
  const double k = opt.band_k;
  char buf[128];

  std::vector<double> zero(n, 0.0), h_hi(n), v_hi(n), a_lo(n), a_hi(n);
  if (mc) {
    for (size_t i = 0; i < n; ++i) {
      h_hi[i] = k * NavInterpolate(env.t_s, env.pos_h_rms_m, 1, 0, e.t_s[i]);
      v_hi[i] = k * NavInterpolate(env.t_s, env.pos_rms_ned_m, 3, 2, e.t_s[i]);
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

  vtkNew<vtkContextView> view;
  NavAttachDisplay(view->GetRenderWindow());
  view->GetRenderWindow()->SetOffScreenRendering(1);
  // A headless chart needs no interactor. vtkContextView creates one, and the first Render()
  // initialises it (vtkXRenderWindowInteractor::Initialize -> XSync), which crashed
  // intermittently under Xvfb (7th of 40 runs under load; backtrace in XSync). Detach it.
  view->GetRenderWindow()->SetInteractor(nullptr);
  view->GetRenderWindow()->SetSize(opt.width_px, opt.height_px);
  view->GetRenderWindow()->SetMultiSamples(8);
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  vtkNew<vtkChartMatrix> matrix;
  matrix->SetSize(vtkVector2i(1, 3));
  const int font = std::max(10, static_cast<int>(std::lround(opt.height_px / 58.0)));
  // Left: tick labels and axis title; bottom: time axis; top and gutters: the panel titles.
  const bool text = opt.show_text;
  matrix->SetBorders(static_cast<int>((text ? 4.8 : 1.0) * font), static_cast<int>((text ? 3.4 : 1.0) * font),
                     static_cast<int>(1.5 * font), static_cast<int>((text ? 2.2 : 1.0) * font));
  matrix->SetGutter(vtkVector2f(0.0f, static_cast<float>((text ? 4.0 : 1.0) * font)));
  view->GetScene()->AddItem(matrix);

  // Row 2 (top): horizontal, row 1: vertical, row 0 (bottom): attitude.
  auto *ch = vtkChartXY::SafeDownCast(matrix->GetChart(vtkVector2i(0, 2)));
  auto *cv = vtkChartXY::SafeDownCast(matrix->GetChart(vtkVector2i(0, 1)));
  auto *ca = vtkChartXY::SafeDownCast(matrix->GetChart(vtkVector2i(0, 0)));
  if (!ch || !cv || !ca) {
    *error = "vtkChartMatrix did not create XY charts";
    return false;
  }
  std::snprintf(buf, sizeof buf, "0 .. %g\u00d7 RMS over %d runs", k, result.runs);
  const std::string band = buf;
  std::snprintf(buf, sizeof buf, "\u00b1%g\u00d7 RMS attitude error", k);
  const std::string aband = buf;
  const std::string who = result.scene_name.empty() ? std::string() : result.scene_name + ": ";
  std::vector<Series> hs = {{"run 0", e.pos_err_h_m, {214, 39, 40}}};
  std::vector<Series> vs = {{"run 0", e.pos_err_v_m, {214, 39, 40}}};
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
  // Requirement limits as lines (summary.json "requirements").
  for (const NavRequirementVerdict &r : result.requirements) {
    std::vector<Series> *dst = nullptr;
    double scale = 1.0;
    if (r.metric == "horizontal_position") dst = &hs;
    else if (r.metric == "vertical_position") dst = &vs;
    else if (r.metric == "roll_pitch" || r.metric == "yaw") {
      dst = &as;
      scale = kRadToDeg;
    }
    if (!dst || !(r.limit_si > 0.0)) continue;
    std::snprintf(buf, sizeof buf, "limit %s: %s %g %s (%s)", r.id.c_str(), r.statistic.c_str(), r.limit,
                  r.unit.c_str(), r.pass ? "pass" : "FAIL");
    dst->push_back(Series{buf, std::vector<double>(n, r.limit_si * scale),
                          {static_cast<unsigned char>(r.pass ? 30 : 200), static_cast<unsigned char>(r.pass ? 30 : 0),
                           static_cast<unsigned char>(r.pass ? 30 : 0)},
                          vtkPen::DASH_DOT_LINE, 2.0f});
  }
  FillChart(ch, who + "horizontal position error", "horizontal [m]", false, e.t_s, hs, mc ? &zero : nullptr,
            mc ? &h_hi : nullptr, band, opt, font);
  FillChart(cv, "vertical position error", "vertical [m]", false, e.t_s, vs, mc ? &zero : nullptr,
            mc ? &v_hi : nullptr, band, opt, font);
  const bool att_band = mc && !env.att_rms_rad.empty();
  FillChart(ca, "attitude error (run 0)", "attitude [\u00b0]", true, e.t_s, as, att_band ? &a_lo : nullptr,
            att_band ? &a_hi : nullptr, aband, opt, font);
  view->Render();
  return NavWriteWindowPng(view->GetRenderWindow(), path, error);
}
