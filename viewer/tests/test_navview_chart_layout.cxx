/*
 * test_navview_chart_layout: the error charts (navsim render --view errors, navstudio's Errors
 * tab) as laid out, on urban-drive-like data: data/tiny-gnss with a second GNSS outage and a
 * second error peak at its end (as the urban drive's two 60 s outages), and two horizontal
 * requirements that both FAIL.
 *   - issue 19 "chart legends cover the second outage peak": in every panel the legend's box
 *     lies outside every plot area (and inside the picture), and the box is where the legend's
 *     text is drawn (dark text pixels inside it);
 *   - issue 19 "both FAIL limit lines share one style": the two limits of the horizontal panel
 *     get different dash patterns, and their rows of pixels differ in their on/off pattern.
 * Writes Testing/Temporary/navview_chart_layout.png. Runs under Xvfb (label render).
 */
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <vtkPNGWriter.h>
#include <vtkImageData.h>
#include <vtkNew.h>

#include "navview/navview.h"

namespace {

int g_failures = 0;

void Check(bool ok, const char *what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what);
  if (!ok) ++g_failures;
}

void WritePng(const std::vector<unsigned char> &rgb, int w, int h, const std::string &path) {
  vtkNew<vtkImageData> img;
  img->SetDimensions(w, h, 1);
  img->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto *dst = static_cast<unsigned char *>(img->GetScalarPointer());
  for (int y = 0; y < h; ++y) // vtkImageData rows run bottom to top
    std::memcpy(dst + static_cast<size_t>(y) * w * 3, rgb.data() + static_cast<size_t>(h - 1 - y) * w * 3,
                static_cast<size_t>(w) * 3);
  vtkNew<vtkPNGWriter> wr;
  wr->SetFileName(path.c_str());
  wr->SetInputData(img);
  wr->Write();
}

// Pixel (x, y) with y from the bottom (the layout's convention) of a top-down RGB picture.
const unsigned char *Px(const std::vector<unsigned char> &rgb, int w, int h, int x, int y_up) {
  return rgb.data() + (static_cast<size_t>(h - 1 - y_up) * w + x) * 3;
}

} // namespace

int main() {
  std::string out_dir = NAVVIEW_TEST_OUT_DIR;
  for (size_t p = 1; p != std::string::npos; p = out_dir.find('/', p + 1))
    mkdir(out_dir.substr(0, p).c_str(), 0755);
  NavResult r;
  std::string err;
  if (!NavLoadResultDir(NAVVIEW_TEST_DATA_DIR "/tiny-gnss", &r, &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  // The second outage [85, 110) s and its error peak: the horizontal error grows as after the
  // first outage and is largest at the outage's end, near the right edge where a legend in the
  // plot's top-right corner sat.
  r.gnss.outage_t0_s.push_back(85.0);
  r.gnss.outage_t1_s.push_back(110.0);
  NavErrorSeries &e = r.errors;
  double peak1 = 0.0;
  for (size_t i = 0; i < e.Size(); ++i)
    peak1 = std::max(peak1, e.pos_err_h_m[i]);
  for (size_t i = 0; i < e.Size(); ++i) {
    const double t = e.t_s[i];
    if (t >= 85.0 && t <= 115.0) {
      const double f = t <= 110.0 ? (t - 85.0) / 25.0 : (115.0 - t) / 5.0;
      e.pos_err_h_m[i] = std::max(e.pos_err_h_m[i], 1.1 * peak1 * f * f);
    }
  }
  // Two horizontal limits, both FAIL (the urban drive's h-outage-end and CEP95).
  r.requirements.clear();
  NavRequirementVerdict a;
  a.id = "h-outage-end";
  a.metric = "horizontal_position";
  a.statistic = "outage_end";
  a.unit = "m";
  a.limit = a.limit_si = 0.35 * peak1;
  a.value = peak1;
  a.pass = false;
  NavRequirementVerdict b = a;
  b.id = "h-cep95";
  b.statistic = "cep95";
  b.limit = b.limit_si = 0.7 * peak1;
  r.requirements = {a, b};

  NavChartOptions opt;
  opt.width_px = 1000;
  opt.height_px = 900;
  std::vector<unsigned char> rgb;
  NavErrorChartLayout lay;
  if (!NavRenderErrorChartRgb(r, opt, &rgb, &lay, &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }
  const int w = opt.width_px, h = opt.height_px;
  WritePng(rgb, w, h, out_dir + "/navview_chart_layout.png");

  Check(lay.plots.size() >= 3 && lay.legends.size() == lay.plots.size(), "a plot and a legend per panel");
  for (size_t i = 0; i < lay.plots.size(); ++i) {
    const NavChartRect &p = lay.plots[i], &l = lay.legends[i];
    std::printf("%s: plot x %.0f..%.0f y %.0f..%.0f, legend x %.0f..%.0f y %.0f..%.0f\n", lay.titles[i].c_str(), p.x,
                p.x + p.w, p.y, p.y + p.h, l.x, l.x + l.w, l.y, l.y + l.h);
    Check(p.w > 100 && p.h > 50, "plot area of a sensible size");
    Check(l.w > 20 && l.h > 10, "legend box drawn");
    bool clear = true;
    for (const NavChartRect &q : lay.plots)
      clear = clear && !l.Intersects(q);
    Check(clear, "legend box outside every plot area");
    Check(l.x >= 0 && l.y >= 0 && l.x + l.w <= w && l.y + l.h <= h, "legend box inside the picture");
    // The legend's text (RGB about 13, 13, 20) is drawn inside the box: the box is the real one.
    long dark = 0;
    for (int y = std::max(0, int(l.y)); y < std::min(h, int(l.y + l.h)); ++y)
      for (int x = std::max(0, int(l.x)); x < std::min(w, int(l.x + l.w)); ++x) {
        const unsigned char *c = Px(rgb, w, h, x, y);
        dark += c[0] < 90 && c[1] < 90 && c[2] < 90;
      }
    std::printf("  dark text pixels in the legend box: %ld\n", dark);
    Check(dark > 40, "legend text inside the legend box");
  }

  // Two FAIL limits in the horizontal panel: different dash patterns.
  Check(!lay.limit_pens.empty() && lay.limit_pens[0].size() == 2, "two limit lines in the horizontal panel");
  if (!lay.limit_pens.empty() && lay.limit_pens[0].size() == 2) {
    std::printf("limit pens: %d %d\n", lay.limit_pens[0][0], lay.limit_pens[0][1]);
    Check(lay.limit_pens[0][0] != lay.limit_pens[0][1], "the two limits have different pen types");
    // Their rows in the picture: the y of each limit from the panel's axis range is not exposed,
    // so find the two rows inside the plot with the most pure-red limit pixels (FAIL red 200, 0,
    // 0) and compare their on/off runs.
    const NavChartRect &p = lay.plots[0];
    std::vector<std::pair<long, int>> rows;
    for (int y = int(p.y) + 2; y < int(p.y + p.h) - 2; ++y) {
      long n = 0;
      for (int x = int(p.x) + 2; x < int(p.x + p.w) - 2; ++x) {
        const unsigned char *c = Px(rgb, w, h, x, y);
        n += c[0] > 150 && c[1] < 25 && c[2] < 25;
      }
      rows.push_back({n, y});
    }
    std::sort(rows.rbegin(), rows.rend());
    // The two lines are far apart (0.35 and 0.7 of the peak): take the best row, then the best
    // row at least 10 px away from it.
    int y1 = rows.empty() ? -1 : rows[0].second, y2 = -1;
    long n1 = rows.empty() ? 0 : rows[0].first, n2 = 0;
    for (const auto &rw : rows)
      if (std::abs(rw.second - y1) >= 10) {
        y2 = rw.second;
        n2 = rw.first;
        break;
      }
    std::printf("limit rows y %d (%ld red px) and y %d (%ld red px)\n", y1, n1, y2, n2);
    Check(y2 >= 0 && n1 > 0.2 * p.w && n2 > 0.2 * p.w, "both limit lines found in the picture");
    if (y2 >= 0) {
      // Dash lengths: the runs of red pixels along each row (the error curve crosses a row at a
      // few places only and adds a short run at most).
      auto runs = [&](int y) {
        std::vector<int> v;
        int len = 0;
        for (int x = int(p.x) + 2; x < int(p.x + p.w) - 2; ++x) {
          const unsigned char *c = Px(rgb, w, h, x, y);
          if (c[0] > 150 && c[1] < 25 && c[2] < 25) {
            ++len;
          } else if (len) {
            v.push_back(len);
            len = 0;
          }
        }
        std::sort(v.begin(), v.end());
        return v;
      };
      const std::vector<int> r1 = runs(y1), r2 = runs(y2);
      const int med1 = r1.empty() ? 0 : r1[r1.size() / 2], med2 = r2.empty() ? 0 : r2[r2.size() / 2];
      const int max1 = r1.empty() ? 0 : r1.back(), max2 = r2.empty() ? 0 : r2.back();
      std::printf("dash runs: %zu runs median %d max %d; %zu runs median %d max %d\n", r1.size(), med1, max1,
                  r2.size(), med2, max2);
      Check(r1.size() != r2.size() || med1 != med2 || max1 != max2, "the two limit rows differ in their dash pattern");
    }
  }
  std::printf("%s\n", g_failures ? "test_navview_chart_layout: FAILED" : "test_navview_chart_layout: passed");
  return g_failures ? 1 : 0;
}
