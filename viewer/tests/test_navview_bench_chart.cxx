/*
 * The speed-against-error chart of navsim bench (NavRenderSpeedVsErrorPng) on a bench.csv of four
 * cases: one panel per case in the file's order, each panel's markers labelled with their variants
 * (the failed row left out), and on the pixels (text off, no baseline): the PNG has the asked size
 * and each of the four panels of the 2 x 2 grid holds coloured markers. A single-case file gives one
 * panel; a file without the needed columns is an error naming the file. Runs under an X display
 * (with_display.sh).
 */
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include "navview/nav_view_chart.h"

namespace {

int g_failures = 0;

void Check(bool ok, const std::string &what) {
  if (!ok) {
    std::fprintf(stderr, "test_navview_bench_chart: FAILED: %s\n", what.c_str());
    ++g_failures;
  }
}

std::string Join(const std::vector<std::string> &v) {
  std::string s;
  for (const std::string &x : v) s += (s.empty() ? "" : " | ") + x;
  return s;
}

// Saturated pixels (marker colours; axes, grid and background are grey or white) in each quadrant
// of the image: q[0] top left, q[1] top right, q[2] bottom left, q[3] bottom right.
struct Pixels {
  int w = 0, h = 0;
  long q[4] = {0, 0, 0, 0};
};

Pixels Count(const std::string &png) {
  Pixels c;
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
  for (int y = 0; y < c.h; ++y)
    for (int x = 0; x < c.w; ++x) {
      const unsigned char *px = p + (static_cast<long>(y) * c.w + x) * nc;
      const int mx = std::max(px[0], std::max(px[1], px[2])), mn = std::min(px[0], std::min(px[1], px[2]));
      if (mx - mn < 60) continue; // grey, black or white
      // VTK images start at the bottom row.
      const int top = y >= c.h / 2 ? 0 : 2, right = x >= c.w / 2 ? 1 : 0;
      ++c.q[top + right];
    }
  return c;
}

} // namespace

int main() {
  const std::string csv = NAVVIEW_TEST_DATA_DIR "/bench_cases.csv";
  const std::string out = NAVVIEW_TEST_OUT_DIR "/bench_chart";
  NavChartOptions o;
  o.width_px = 300;
  o.height_px = 240;
  o.show_text = false;
  std::string err;
  NavBenchChartLayout lay;
  bool ok = NavRenderSpeedVsErrorPng(csv, o, out + "_pixels.png", &err, &lay);
  Check(ok, "four cases: " + err);
  Check(lay.cases.size() == 4, "panels: " + std::to_string(lay.cases.size()) + ", expected 4 (" + Join(lay.cases) + ")");
  const Pixels c = Count(out + "_pixels.png");
  Check(c.w == 300 && c.h == 240, "size " + std::to_string(c.w) + "x" + std::to_string(c.h) + ", expected 300x240");
  const char *where[4] = {"top left", "top right", "bottom left", "bottom right"};
  for (int q = 0; q < 4; ++q)
    Check(c.q[q] > 15, std::string("no markers in the ") + where[q] + " panel (" + std::to_string(c.q[q]) +
                           " coloured pixels)");
  // With text: titles and one label per marker, the variant of its row.
  o.width_px = 900;
  o.height_px = 700;
  o.show_text = true;
  ok = NavRenderSpeedVsErrorPng(csv, o, out + "_labelled.png", &err, &lay);
  Check(ok, "labelled: " + err);
  const std::vector<std::string> cases = {"parametric-closure", "throughput", "long-drive-truth", "long-drive-replay"};
  Check(lay.cases == cases, "cases in file order: " + Join(lay.cases));
  if (lay.labels.size() == 4) {
    Check(lay.labels[0].size() == 6, "parametric-closure labels: " + Join(lay.labels[0]));
    Check(!lay.labels[0].empty() && lay.labels[0][0] == "first_order/flat/flat/50Hz",
          "first label: " + Join(lay.labels[0]));
    Check(lay.labels[1] == std::vector<std::string>({"high_order/flat/flat/200Hz", "high_order/wgs84/ned/200Hz",
                                                     "high_order/wgs84/ecef/200Hz"}),
          "throughput labels: " + Join(lay.labels[1]));
    Check(lay.labels[2] == std::vector<std::string>({"high_order/wgs84/ned/200Hz"}),
          "long-drive-truth labels: " + Join(lay.labels[2]));
    // The failed row ("data not found") is not drawn.
    Check(lay.labels[3] == std::vector<std::string>({"GNSS.txt", "GNSS_outage.txt"}),
          "long-drive-replay labels: " + Join(lay.labels[3]));
  } else {
    Check(false, "label lists: " + std::to_string(lay.labels.size()) + ", expected 4");
  }
  // A case of more than eight variants spans two whole rows; rows of one case with the same
  // variant (a replay against two peers) are labelled with their peers.
  {
    const std::string big = out + "_big.csv";
    FILE *f = std::fopen(big.c_str(), "w");
    Check(f != nullptr, "cannot write " + big);
    if (f) {
      std::fputs("case,variant,algorithm,frame,mech_samples_per_s,pos_err_m,peer,status\n", f);
      std::fputs("small,a,first_order,ned,1e6,1e-3,,ok\n", f);
      for (int i = 0; i < 10; ++i)
        std::fprintf(f, "many,v%d,high_order,ned,%g,%g,,ok\n", i, 1e6 * (1 + i), 1e-4 * (1 + i));
      std::fputs("replay,GNSS.txt,high_order,ned,5e5,0.02,KF-GINS,ok\n", f);
      std::fputs("replay,GNSS.txt,high_order,ned,5e5,0.02,pyins,ok\n", f);
      std::fputs("other,b,high_order,ecef,2e6,2e-4,,ok\n", f);
      std::fclose(f);
    }
    ok = NavRenderSpeedVsErrorPng(big, o, out + "_big.png", &err, &lay);
    Check(ok, "big case: " + err);
    Check(lay.cases == std::vector<std::string>({"small", "many", "replay", "other"}), "big: cases " + Join(lay.cases));
    if (lay.cells.size() == 4) {
      // Two columns (four cases): small at (0, 0); many from the next row, both columns x two rows;
      // replay and other after it.
      const auto &c1 = lay.cells[1], &c2 = lay.cells[2], &c3 = lay.cells[3];
      Check(lay.cells[0].col == 0 && lay.cells[0].row == 0, "small not top left");
      Check(c1.col == 0 && c1.row == 1 && c1.cols == 2 && c1.rows == 2,
            "many: cell " + std::to_string(c1.col) + "," + std::to_string(c1.row) + " span " + std::to_string(c1.cols) +
                "x" + std::to_string(c1.rows) + ", expected 0,1 span 2x2");
      Check(c2.col == 0 && c2.row == 3 && c2.cols == 1 && c3.col == 1 && c3.row == 3, "replay/other after the wide panel");
    } else {
      Check(false, "big: cells " + std::to_string(lay.cells.size()));
    }
    Check(lay.labels.size() == 4 && lay.labels[2] == std::vector<std::string>({"GNSS.txt vs KF-GINS", "GNSS.txt vs pyins"}),
          "replay labels: " + (lay.labels.size() == 4 ? Join(lay.labels[2]) : std::string("?")));
    Check(lay.labels.size() == 4 && lay.labels[1].size() == 10, "many: labels");
  }
  // The old single-case file: one panel.
  o.width_px = 300;
  o.height_px = 240;
  o.show_text = false;
  ok = NavRenderSpeedVsErrorPng(NAVVIEW_TEST_DATA_DIR "/bench.csv", o, out + "_one.png", &err, &lay);
  Check(ok && lay.cases == std::vector<std::string>({"closure"}), "bench.csv: " + err + " " + Join(lay.cases));
  // Not a bench.csv: an error that names the file.
  err.clear();
  Check(!NavRenderSpeedVsErrorPng(NAVVIEW_TEST_DATA_DIR "/allan.csv", o, out + "_x.png", &err, &lay),
        "allan.csv accepted");
  Check(err.find("allan.csv:1: error: expected columns") != std::string::npos, "allan.csv: message \"" + err + "\"");
  if (g_failures == 0)
    std::printf("test_navview_bench_chart: passed (%s_pixels.png, %s_labelled.png)\n", out.c_str(), out.c_str());
  return g_failures == 0 ? 0 : 1;
}
