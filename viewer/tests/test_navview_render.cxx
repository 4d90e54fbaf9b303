/*
 * test_navview_render CASE: render one fixed view of the vendored tiny result (data/tiny) at
 * 240x240 with a fixed camera and no text, and compare it with baselines/CASE.png using
 * vtkImageDifference. On a mismatch or a missing baseline the rendered image (and the
 * difference image) stay in the build's Testing/Temporary and the test fails; a human looks at
 * a new image before it is copied to baselines/ (style.md section 10). Runs under xvfb-run.
 */
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <sys/stat.h>

#include "navview/navview.h"

namespace {

// vtkImageDifference's thresholded error (pixels count above a summed RGB difference of 40, with
// two-pixel shifts allowed): 0 for repeated llvmpipe renders; in scene_exaggerated, k = 9.7
// instead of 10 (a 1 deg turn of the estimated triad) scores 0.01 and k = 9 (3 deg) scores 18.5.
// The threshold leaves room for antialiasing differences of a Mesa update.
constexpr double kThreshold = 5.0;
constexpr int kSize = 240;

NavViewOptions BaseOptions() {
  NavViewOptions o;
  o.width_px = kSize;
  o.height_px = kSize;
  o.show_text = false;
  o.time_s = 60.0;
  o.triad_interval_s = 15.0;
  o.triad_size_m = 9.0;
  // The first baselines predate these: keep them off (scene_gnss shows them).
  o.ellipsoid_count = 0;
  o.show_gnss = false;
  o.vehicle = NavVehicleKind::Car;
  // Also predating the baselines: exaggeration 1 (now 20 by default), no triad pair at the
  // playback time, no pixel floor of the envelope.
  o.att_exaggeration = 1.0;
  o.show_triads_at_time = false;
  o.min_envelope_px = 0.0;
  return o;
}

void SetCamera(NavViewOptions *o, double px, double py, double pz, double fx, double fy, double fz) {
  o->fixed_camera = true;
  o->camera_position_r[0] = px;
  o->camera_position_r[1] = py;
  o->camera_position_r[2] = pz;
  o->camera_focal_r[0] = fx;
  o->camera_focal_r[1] = fy;
  o->camera_focal_r[2] = fz;
  o->camera_view_up_r[0] = 0.0;
  o->camera_view_up_r[1] = 0.0;
  o->camera_view_up_r[2] = 1.0;
  o->camera_view_angle_deg = 30.0;
}

} // namespace

int main(int argc, char **argv) {
  if (argc != 2) {
    std::fprintf(stderr,
                 "usage: test_navview_render scene_oblique|scene_top_error|scene_exaggerated|scene_gnss|chart_errors|\n"
                 "       chart_errors_req|chart_noise|chart_allan|chart_bench|chart_sky|chart_dop|map_local|\n"
                 "       map_region\n");
    return 2;
  }
  const std::string name = argv[1];
  // mkdir -p of the output directory (a fresh build tree has no Testing/ yet).
  std::string out_dir = NAVVIEW_TEST_OUT_DIR;
  for (size_t p = 1; p != std::string::npos; p = out_dir.find('/', p + 1))
    mkdir(out_dir.substr(0, p).c_str(), 0755);
  mkdir(out_dir.c_str(), 0755);
  const std::string actual = std::string(NAVVIEW_TEST_OUT_DIR) + "/navview_" + name + ".png";
  const std::string diff = std::string(NAVVIEW_TEST_OUT_DIR) + "/navview_" + name + "_diff.png";
  const std::string baseline = std::string(NAVVIEW_BASELINE_DIR) + "/" + name + ".png";
  std::remove(actual.c_str());
  std::remove(diff.c_str());

  auto result = std::make_shared<NavResult>();
  std::string err;
  // tiny-gnss: tiny plus GNSS fixes, an outage [40, 70) s, sensor errors and requirements.
  const bool gnss = name == "scene_gnss" || name == "map_local" || name == "map_region" || name == "chart_noise" ||
                    name == "chart_errors_req";
  if (!NavLoadResultDir(gnss ? NAVVIEW_TEST_DATA_DIR "/tiny-gnss" : NAVVIEW_TEST_DATA_DIR "/tiny", result.get(),
                        &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    return 1;
  }

  bool ok = false;
  NavChartOptions c;
  c.width_px = kSize;
  c.height_px = kSize;
  c.show_text = false;
  NavMapOptions mo;
  mo.width_px = kSize;
  mo.height_px = kSize;
  mo.show_text = false;
  if (name == "chart_errors" || name == "chart_errors_req") {
    // chart_errors_req: requirement limits as lines (h-rms 2.5 m pass, v-max 0.6 m FAIL, yaw 3 deg).
    ok = NavRenderErrorChartPng(*result, c, actual, &err);
  } else if (name == "chart_noise") {
    ok = NavRenderSensorErrorChartPng(*result, c, actual, &err);
  } else if (name == "chart_allan") {
    ok = NavRenderAllanChartPng(NAVVIEW_TEST_DATA_DIR "/allan.csv", c, actual, &err);
  } else if (name == "chart_sky") {
    // data/gnss-canyon: GPS (blue) and GLONASS (red) tracks, masked epochs (grey crosses), the
    // 10 deg elevation mask (dashed) and the canyon walls at mid-canyon (brown).
    ok = NavRenderSkyPlotPng(NAVVIEW_TEST_DATA_DIR "/gnss-canyon", c, actual, &err);
  } else if (name == "chart_dop") {
    // data/gnss-canyon: DOP lines with their gap where fewer than five satellites (two systems)
    // are in view, the visible count, the canyon [40, 100) s and the receiver outage [40, 72) s.
    ok = NavRenderDopChartPng(NAVVIEW_TEST_DATA_DIR "/gnss-canyon", c, actual, &err);
  } else if (name == "chart_bench") {
    ok = NavRenderSpeedVsErrorPng(NAVVIEW_TEST_DATA_DIR "/bench.csv", c, actual, &err);
  } else if (name == "map_local") {
    // Street scale: fitted to the 120 m figure eight, local metric grid, outage band, fixes.
    ok = NavRenderMapPng(*result, mo, actual, &err);
  } else if (name == "map_region") {
    // 600 km around Munich: GSHHG land and lakes (high resolution), rivers and borders, graticule.
    mo.span_km = 600.0;
    ok = NavRenderMapPng(*result, mo, actual, &err);
  } else {
    NavViewOptions o = BaseOptions();
    if (name == "scene_oblique") {
      // Whole figure eight from the south-west: paths, 1x MC tube, triads (k = 5), grid, NED
      // axes, scale bar, vehicle at t = 60 s.
      o.att_exaggeration = 5.0;
      o.envelope_k = 1.0;
      SetCamera(&o, -95.0, -205.0, 165.0, 0.0, -10.0, -8.0);
    } else if (name == "scene_top_error") {
      // Plan view, estimate coloured by horizontal error with an unlabelled scalar bar, run-0
      // error tube at k = 1, no triads.
      o.camera = NavCameraPreset::Top;
      o.color_by_error = true;
      o.envelope_source = NavEnvelopeSource::RunErrors;
      o.envelope_k = 1.0;
      o.show_triads = false;
      o.time_s = 100.0;
    } else if (name == "scene_exaggerated") {
      // Close-up of the triads near the end (largest attitude error) with k = 10.
      o.att_exaggeration = 10.0;
      o.envelope_source = NavEnvelopeSource::None;
      o.show_grid = false;
      o.show_vehicle = false;
      o.show_axes = false;
      o.triad_interval_s = 90.0; // triads at 0 s (no error yet) and 90 s (n = -60 m, e = 0)
      o.triad_size_m = 12.0;
      SetCamera(&o, -16.0, -88.0, 36.0, -1.0, -60.0, -5.0);
    } else if (name == "scene_gnss") {
      // GNSS fixes (green), the outage [40, 70) s highlighted, four MC ellipsoids (k = 2),
      // aircraft glyph at t = 60 s.
      o.show_gnss = true;
      o.ellipsoid_times_s = {20.0, 50.0, 80.0, 110.0};
      o.envelope_k = 2.0;
      o.vehicle = NavVehicleKind::Aircraft;
      o.show_triads = false;
      SetCamera(&o, -95.0, -205.0, 165.0, 0.0, -10.0, -8.0);
    } else {
      std::fprintf(stderr, "unknown case '%s'\n", name.c_str());
      return 2;
    }
    NavSceneView view;
    view.SetResult(result);
    view.SetOptions(o);
    ok = view.RenderPng(actual, &err);
  }
  if (!ok) {
    std::fprintf(stderr, "%s: render failed: %s\n", name.c_str(), err.c_str());
    return 1;
  }

  NavImageComparison cmp;
  if (NavCompareImages(actual, baseline, kThreshold, diff, &cmp, &err)) {
    std::printf("%s: matches %s (thresholded error %.3g <= %.3g)\n", name.c_str(), baseline.c_str(),
                cmp.thresholded_error, kThreshold);
    std::remove(actual.c_str());
    return 0;
  }
  std::fprintf(stderr, "%s: FAILED: %s\n  rendered image: %s\n", name.c_str(), err.c_str(), actual.c_str());
  if (cmp.baseline_found && cmp.size_matches) std::fprintf(stderr, "  difference image: %s\n", diff.c_str());
  if (!cmp.baseline_found)
    std::fprintf(stderr, "  look at the rendered image; if it is right: cp %s %s\n", actual.c_str(),
                 baseline.c_str());
  return 1;
}
