/*
 * The tradeoff chart (NavRenderTradeoffPng) of the vendored tradeoff.csv, checked without a
 * baseline: the PNG has the size asked for, is not blank (a share of its pixels are not the white
 * background), shows the Pareto front (pixels of its red) and the recommended point (its blue);
 * one panel per requirement without --requirement; an unknown requirement and a file that is not
 * tradeoff.csv are errors naming the file. Runs under xvfb-run (with_display.sh).
 */
#include <cstdio>
#include <string>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include "navview/nav_view_chart.h"

namespace {

int g_failures = 0;

void Check(bool ok, const std::string &what) {
  if (!ok) {
    std::fprintf(stderr, "test_navview_tradeoff: FAILED: %s\n", what.c_str());
    ++g_failures;
  }
}

struct Counts {
  int w = 0, h = 0;
  long not_white = 0, red = 0, blue = 0;
};

// Pixels near the colours the chart uses: the Pareto front (214, 39, 40) and the recommended
// marker (31, 119, 180), within 40 per channel (antialiasing blends the edges).
Counts Count(const std::string &png) {
  Counts c;
  vtkNew<vtkPNGReader> r;
  if (!r->CanReadFile(png.c_str())) return c;
  r->SetFileName(png.c_str());
  r->Update();
  vtkImageData *im = r->GetOutput();
  int dims[3];
  im->GetDimensions(dims);
  c.w = dims[0];
  c.h = dims[1];
  const int nc = im->GetNumberOfScalarComponents();
  auto *p = static_cast<unsigned char *>(im->GetScalarPointer());
  auto near = [](const unsigned char *q, int r0, int g0, int b0) {
    return std::abs(q[0] - r0) < 40 && std::abs(q[1] - g0) < 40 && std::abs(q[2] - b0) < 40;
  };
  for (long i = 0; i < static_cast<long>(c.w) * c.h; ++i) {
    const unsigned char *q = p + i * nc;
    if (q[0] < 245 || q[1] < 245 || q[2] < 245) ++c.not_white;
    if (near(q, 214, 39, 40)) ++c.red;
    if (near(q, 31, 119, 180)) ++c.blue;
  }
  return c;
}

} // namespace

int main() {
  const std::string csv = NAVVIEW_TEST_DATA_DIR "/tradeoff.csv";
  const std::string out = NAVVIEW_TEST_OUT_DIR "/tradeoff_chart";
  NavChartOptions o;
  o.width_px = 300;
  o.height_px = 240;
  o.show_text = false;
  std::string err;
  // One requirement.
  bool ok = NavRenderTradeoffPng(csv, "h-outage-end", o, out + "_one.png", &err);
  Check(ok, "h-outage-end: " + err);
  Counts c = Count(out + "_one.png");
  Check(c.w == 300 && c.h == 240, "size " + std::to_string(c.w) + "x" + std::to_string(c.h) + ", expected 300x240");
  Check(c.not_white > 300 * 240 / 50, "blank: " + std::to_string(c.not_white) + " non-white pixels");
  Check(c.red > 20, "no Pareto front (" + std::to_string(c.red) + " red pixels)");
  Check(c.blue > 10, "no recommended marker (" + std::to_string(c.blue) + " blue pixels)");
  // Every requirement, one panel each: taller image, still not blank.
  o.height_px = 300;
  ok = NavRenderTradeoffPng(csv, "", o, out + "_all.png", &err);
  Check(ok, "all requirements: " + err);
  c = Count(out + "_all.png");
  Check(c.w == 300 && c.h == 300, "all: size " + std::to_string(c.w) + "x" + std::to_string(c.h));
  Check(c.red > 40, "all: Pareto fronts of two panels (" + std::to_string(c.red) + " red pixels)");
  // Bad input: a requirement the file does not have, a file that is not tradeoff.csv.
  err.clear();
  Check(!NavRenderTradeoffPng(csv, "nope", o, out + "_x.png", &err), "unknown requirement accepted");
  Check(err.find("tradeoff.csv: error: no evaluated variant for requirement 'nope'") != std::string::npos,
        "unknown requirement: message \"" + err + "\"");
  err.clear();
  Check(!NavRenderTradeoffPng(NAVVIEW_TEST_DATA_DIR "/bench.csv", "", o, out + "_x.png", &err), "bench.csv accepted");
  Check(err.find("bench.csv:1: error: missing column") != std::string::npos, "bench.csv: message \"" + err + "\"");
  if (g_failures == 0) std::printf("test_navview_tradeoff: passed (%s_one.png, %s_all.png)\n", out.c_str(), out.c_str());
  return g_failures == 0 ? 0 : 1;
}
