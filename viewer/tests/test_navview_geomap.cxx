// The geodetic map at known places (issue 19, item 2), rendered at 1280x800 under Xvfb: land
// where there is land and water where there is water at chosen points, place names at city and
// country scale (in the label list and as dark text pixels inside their boxes), no text over
// another text or the scale bar, and the interactive map rebuilding as it zooms about the
// pointer. The PNGs stay in Testing/Temporary (geomap_*.png) to be looked at.
#include <algorithm>
#include <cstring>
#include <cmath>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <vtkCamera.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

#include "map_interactive_internal.h"
#include "navview/nav_map_data.h"
#include "navview/nav_view_map.h"
#include "navview_internal.h"

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>

#include <cstdarg>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <setjmp.h>
extern "C" {
#include <cmocka.h>
}

#include "nav_test.h"

namespace {

constexpr double kD2R = 3.14159265358979323846 / 180.0;
constexpr int kW = 1280, kH = 800;

std::string OutDir() {
  std::string d = NAVVIEW_TEST_OUT_DIR;
  for (size_t p = 1; p != std::string::npos; p = d.find('/', p + 1))
    mkdir(d.substr(0, p).c_str(), 0755);
  mkdir(d.c_str(), 0755);
  return d;
}

/** A result whose reference is the polyline @p latlon_deg (pairs), one point a second. */
NavResult Track(const std::string &name, const std::vector<double> &latlon_deg) {
  NavResult r;
  r.scene_name = name;
  for (size_t i = 0; i + 1 < latlon_deg.size(); i += 2) {
    r.truth.t_s.push_back(static_cast<double>(i / 2));
    r.truth.pos_ned_m.insert(r.truth.pos_ned_m.end(), {0.0, 0.0, 0.0});
    r.truth.geo.insert(r.truth.geo.end(), {latlon_deg[i] * kD2R, latlon_deg[i + 1] * kD2R, 0.0});
  }
  return r;
}

struct Image {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  const unsigned char *At(int x, int y) const { return &rgb[3 * (static_cast<size_t>(y) * w + x)]; }
};

Image ReadPng(const std::string &path) {
  vtkNew<vtkPNGReader> rd;
  rd->SetFileName(path.c_str());
  rd->Update();
  Image im;
  int *d = rd->GetOutput()->GetDimensions();
  im.w = d[0];
  im.h = d[1];
  const int nc = rd->GetOutput()->GetNumberOfScalarComponents();
  for (int y = 0; y < im.h; ++y)
    for (int x = 0; x < im.w; ++x) {
      auto *p = static_cast<unsigned char *>(rd->GetOutput()->GetScalarPointer(x, y, 0));
      im.rgb.insert(im.rgb.end(), {p[0], p[nc > 1 ? 1 : 0], p[nc > 2 ? 2 : 0]});
    }
  return im;
}

enum class Surface { Water, Land };

struct Point {
  const char *what;
  double lat, lon;
  Surface is;
};

/** Land or water at a point: the fill colours differ in blue minus red (water about +60, land
 *  about -20); a 5x5 block is read and at least 18 of its 25 pixels must agree (a graticule line
 *  or a river may cross it). */
void CheckSurface(const Image &im, const NavMapInfo &info, const Point &p) {
  double px, py;
  info.PixelOf(p.lat, p.lon, &px, &py);
  const int x = static_cast<int>(px), y = static_cast<int>(py);
  if (x < 2 || y < 2 || x >= im.w - 2 || y >= im.h - 2) fail_msg("%s: outside the view (%g, %g)", p.what, px, py);
  for (const NavMapLabel &l : info.labels)
    if (px > l.x0 - 3 && px < l.x1 + 3 && py > l.y0 - 3 && py < l.y1 + 3)
      fail_msg("%s: the test point lies under the text '%s': choose another", p.what, l.text.c_str());
  int water = 0, land = 0;
  for (int dy = -2; dy <= 2; ++dy)
    for (int dx = -2; dx <= 2; ++dx) {
      const unsigned char *c = im.At(x + dx, y + dy);
      const int b_minus_r = static_cast<int>(c[2]) - static_cast<int>(c[0]);
      if (b_minus_r > 35) ++water;
      if (b_minus_r < -8) ++land;
    }
  std::printf("  %-30s (%8.4f, %9.4f) at pixel (%4d, %4d): %2d water, %2d land of 25 -> expected %s\n", p.what, p.lat,
              p.lon, x, y, water, land, p.is == Surface::Water ? "water" : "land");
  assert_true((p.is == Surface::Water ? water : land) >= 18);
}

/** The place @p name was labelled, and its box holds dark text pixels. */
void CheckPlace(const Image &im, const NavMapInfo &info, const std::string &name) {
  for (const NavMapLabel &l : info.labels) {
    if (l.kind != NavMapLabel::Place || l.text != name) continue;
    int dark = 0;
    for (int y = static_cast<int>(l.y0); y < static_cast<int>(l.y1); ++y)
      for (int x = static_cast<int>(l.x0); x < static_cast<int>(l.x1); ++x) {
        const unsigned char *c = im.At(std::clamp(x, 0, im.w - 1), std::clamp(y, 0, im.h - 1));
        dark += c[0] < 90 && c[1] < 90 && c[2] < 100;
      }
    std::printf("  label '%s' at (%.0f, %.0f)-(%.0f, %.0f): %d dark text pixels\n", name.c_str(), l.x0, l.y0, l.x1,
                l.y1, dark);
    assert_true(dark >= 15);
    return;
  }
  std::string all;
  for (const NavMapLabel &l : info.labels)
    if (l.kind == NavMapLabel::Place) all += " '" + l.text + "'";
  fail_msg("no label '%s'; placed:%s", name.c_str(), all.c_str());
}

/** No two texts overlap (the scale bar is a text box too). */
void CheckNoOverlap(const NavMapInfo &info) {
  for (size_t i = 0; i < info.labels.size(); ++i)
    for (size_t j = i + 1; j < info.labels.size(); ++j) {
      const NavMapLabel &a = info.labels[i], &b = info.labels[j];
      if (a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1)
        fail_msg("'%s' overlaps '%s'", a.text.c_str(), b.text.c_str());
    }
}

NavMapInfo Render(const NavResult &r, const char *name, double lat, double lon, double span_km, Image *im,
                  int h = kH) {
  NavMapOptions o;
  o.width_px = kW;
  o.height_px = h;
  o.center_lat_deg = lat;
  o.center_lon_deg = lon;
  o.span_km = span_km;
  o.multisamples = 0;
  const std::string png = OutDir() + "/geomap_" + name + ".png";
  NavMapInfo info;
  std::string err;
  if (!NavRenderMapPng(r, o, png, &err, &info)) fail_msg("%s: %s", name, err.c_str());
  *im = ReadPng(png);
  size_t places = 0;
  for (const NavMapLabel &l : info.labels)
    places += l.kind == NavMapLabel::Place;
  std::printf("%s: %s, GSHHG %c, %d bins, %zu place names, %zu texts, layers built in %.1f ms\n", name, png.c_str(),
              info.shore_res, info.bins, places, info.labels.size(), info.build_ms);
  for (const std::string &n : info.notes)
    std::printf("  note: %s\n", n.c_str());
  assert_int_equal(im->w, kW);
  assert_int_equal(im->h, h);
  CheckNoOverlap(info);
  return info;
}

void test_san_francisco_50km(void **) {
  const NavResult r = Track("sf", {37.7955, -122.3937, 37.7749, -122.4194});
  Image im;
  const NavMapInfo info = Render(r, "sf_50km", 37.77, -122.35, 50.0, &im);
  assert_int_equal(info.shore_res, 'f');
  for (const Point &p : {Point{"San Francisco Bay", 37.79, -122.36, Surface::Water},
                         Point{"Bay south of Alameda", 37.70, -122.30, Surface::Water},
                         Point{"Pacific off Ocean Beach", 37.75, -122.56, Surface::Water},
                         Point{"Oakland", 37.79, -122.25, Surface::Land},
                         Point{"San Francisco, Sunset", 37.75, -122.48, Surface::Land},
                         Point{"Angel Island", 37.862, -122.432, Surface::Land},
                         Point{"Berkeley hills", 37.88, -122.24, Surface::Land}})
    CheckSurface(im, info, p);
  CheckPlace(im, info, "San Francisco");
  CheckPlace(im, info, "Oakland");
}

void test_san_francisco_5km(void **) {
  const NavResult r = Track("sf-embarcadero", {37.7955, -122.3937, 37.7935, -122.3990});
  Image im;
  const NavMapInfo info = Render(r, "sf_5km", 37.7955, -122.3937, 5.0, &im);
  assert_int_equal(info.shore_res, 'f');
  for (const Point &p : {Point{"Bay off the Ferry Building", 37.800, -122.383, Surface::Water},
                         Point{"Bay by the Bay Bridge", 37.790, -122.375, Surface::Water},
                         Point{"Financial District", 37.792, -122.403, Surface::Land},
                         Point{"Telegraph Hill", 37.8020, -122.4060, Surface::Land}})
    CheckSurface(im, info, p);
}

void test_turin_30km(void **) {
  const NavResult r = Track("turin", {45.0703, 7.6869, 45.0625, 7.6781});
  Image im;
  const NavMapInfo info = Render(r, "turin_30km", 45.07, 7.68, 30.0, &im);
  for (const Point &p : {Point{"Turin centre", 45.073, 7.665, Surface::Land},
                         Point{"Collina (east of the Po)", 45.05, 7.74, Surface::Land},
                         Point{"Rivoli side", 45.09, 7.56, Surface::Land}})
    CheckSurface(im, info, p);
  // Inland: nothing of the view is sea (the old map tinted it all sea blue at this scale).
  long water = 0;
  for (size_t i = 0; i + 2 < im.rgb.size(); i += 3)
    water += static_cast<int>(im.rgb[i + 2]) - static_cast<int>(im.rgb[i]) > 35;
  std::printf("  water-coloured pixels: %ld of %d\n", water, kW * kH);
  assert_true(water < kW * kH / 200);
  CheckPlace(im, info, "Turin");
}

void test_berlin_500km(void **) {
  const NavResult r = Track("berlin", {52.5163, 13.3777, 52.5200, 13.4050});
  Image im;
  // 1280x1024: the view reaches 54.3 N, the Baltic coast.
  const NavMapInfo info = Render(r, "berlin_500km", 52.52, 13.40, 500.0, &im, 1024);
  assert_int_equal(info.shore_res, 'h');
  for (const Point &p : {Point{"Baltic, Pomeranian Bay", 54.20, 14.25, Surface::Water},
                         Point{"Szczecin Lagoon", 53.78, 14.15, Surface::Water},
                         Point{"Mueritz (lake)", 53.43, 12.69, Surface::Water},
                         Point{"Brandenburg", 52.30, 13.00, Surface::Land},
                         Point{"Saxony-Anhalt", 51.90, 11.50, Surface::Land},
                         Point{"Greater Poland", 52.30, 16.20, Surface::Land}})
    CheckSurface(im, info, p);
  CheckPlace(im, info, "Berlin");
  CheckPlace(im, info, "Hamburg");
  CheckPlace(im, info, "Leipzig");
}

void test_berlin_50km_lakes(void **) {
  const NavResult r = Track("berlin-lakes", {52.45, 13.40, 52.46, 13.41});
  Image im;
  const NavMapInfo info = Render(r, "berlin_50km", 52.45, 13.40, 50.0, &im);
  for (const Point &p : {Point{"Mueggelsee", 52.437, 13.645, Surface::Water},
                         Point{"Havel by the Grosser Wannsee", 52.440, 13.150, Surface::Water},
                         Point{"Zehlendorf", 52.43, 13.25, Surface::Land},
                         Point{"Neukoelln", 52.46, 13.44, Surface::Land}})
    CheckSurface(im, info, p);
  CheckPlace(im, info, "Berlin");
}

void test_polar_route(void **) {
  // Longyearbyen over the pole to Alert (Ellesmere Island): the fitted view holds the pole.
  std::vector<double> route;
  for (int i = 0; i <= 40; ++i) {
    const double f = i / 40.0;
    route.insert(route.end(), {f < 0.5 ? 78.22 + (90.0 - 78.22) * 2 * f : 90.0 - (90.0 - 82.50) * (2 * f - 1),
                               f < 0.5 ? 15.65 : -62.35});
  }
  const NavResult r = Track("polar", route);
  Image im;
  const NavMapInfo info = Render(r, "polar_route", NAN, NAN, 0.0, &im);
  for (const Point &p : {Point{"Arctic Ocean near the pole", 88.0, 100.0, Surface::Water},
                         Point{"Greenland ice", 81.0, -40.0, Surface::Land},
                         Point{"Svalbard, Andree Land", 79.30, 16.50, Surface::Land},
                         Point{"Ellesmere Island", 81.0, -75.0, Surface::Land},
                         Point{"Fram Strait", 79.0, 0.0, Surface::Water}})
    CheckSurface(im, info, p);
}

// Without the GSHHG files the map says so (the file it looked for) and paints neither land nor
// sea: a neutral grey, so that nothing looks like sea that may be land.
void test_missing_data(void **) {
  const NavResult r = Track("no-data", {45.0703, 7.6869, 45.0625, 7.6781});
  NavMapOptions o;
  o.width_px = 320;
  o.height_px = 200;
  o.span_km = 30.0;
  o.multisamples = 0;
  o.data_dir = "/nonexistent-gshhg";
  o.places_file = "/nonexistent-places.tsv";
  NavMapInfo info;
  std::string err;
  const std::string png = OutDir() + "/geomap_missing_data.png";
  if (!NavRenderMapPng(r, o, png, &err, &info)) fail_msg("%s", err.c_str());
  assert_int_equal(info.shore_res, 0);
  std::string notes;
  for (const std::string &n : info.notes)
    notes += n + "\n";
  std::printf("notes:\n%s", notes.c_str());
  assert_non_null(std::strstr(notes.c_str(), "/nonexistent-gshhg/binned_GSHHS_f.nc: error: no such file"));
  assert_non_null(std::strstr(notes.c_str(), "/nonexistent-places.tsv: error: cannot open the gazetteer"));
  const Image im = ReadPng(png);
  const unsigned char *c = im.At(160, 100);
  assert_true(std::abs(c[0] - c[2]) < 8);
}

// navview's interactive map: the wheel zooms about the pointer (the point under it stays), and
// the map is rebuilt for each view: its "km across", scale bar and labels follow. Also times a
// rebuild at each scale from the globe to a street (layers, render) at 1280x800.
void test_interactive_rebuilds(void **) {
  const NavResult r = Track("sf-zoom", {37.7955, -122.3937, 37.7749, -122.4194});
  NavMapOptions o;
  o.width_px = kW;
  o.height_px = kH;
  o.span_km = 50.0;
  o.multisamples = 0;
  NavMapInteractive m;
  std::string err;
  if (!m.Open(r, o, &err)) fail_msg("%s", err.c_str());
  assert_near(m.Info.span_x_m, 50e3, 1e-6);
  // The world point under the pointer at (900, 300) before and after a wheel step.
  const double mpp0 = 2.0 * m.Scale() / kH;
  double f[3];
  m.Renderer->GetActiveCamera()->GetFocalPoint(f);
  const double wx = f[0] + (900 - 0.5 * kW) * mpp0, wy = f[1] + (300 - 0.5 * kH) * mpp0;
  m.Iren->SetEventPosition(900, 300);
  m.Iren->InvokeEvent(vtkCommand::MouseWheelForwardEvent);
  const double mpp1 = 2.0 * m.Scale() / kH;
  m.Renderer->GetActiveCamera()->GetFocalPoint(f);
  assert_near(f[0] + (900 - 0.5 * kW) * mpp1, wx, 1e-6 * mpp0);
  assert_near(f[1] + (300 - 0.5 * kH) * mpp1, wy, 1e-6 * mpp0);
  assert_near(m.Info.span_x_m, 50e3 / 1.25, 1e-6);
  bool title = false;
  for (const NavMapLabel &l : m.Info.labels)
    title = title || (l.kind == NavMapLabel::Title && l.text.find(" 40 km across") != std::string::npos);
  assert_true(title);
  std::printf("rebuild after a wheel step: %.1f ms (layers %.1f ms)\n", m.LastRebuildMs, m.Info.build_ms);
  // From a street to the globe: each rebuild's time, and the labels never overlap.
  const double spans_km[] = {0.5, 5, 30, 50, 500, 5000, 20000};
  for (double s : spans_km) {
    m.Renderer->GetActiveCamera()->SetParallelScale(0.5 * s * 1e3 * kH / kW);
    m.Pan(0.0, 0.0); // rebuild at the new scale
    const double first = m.LastRebuildMs;
    m.Pan(40.0, -25.0); // a pan at the same scale (bins cached)
    size_t places = 0;
    for (const NavMapLabel &l : m.Info.labels)
      places += l.kind == NavMapLabel::Place;
    std::printf("%7g km across: GSHHG %c, %3d bins, %2zu place names: first rebuild %6.1f ms, after a pan %6.1f ms "
                "(layers %5.1f ms)\n",
                s, m.Info.shore_res, m.Info.bins, places, first, m.LastRebuildMs, m.Info.build_ms);
    assert_near(m.Info.span_x_m, std::min(s * 1e3, NavMapMaxSpanM()), 1e-6 * s * 1e3);
    CheckNoOverlap(m.Info);
  }
  const std::string shot = OutDir() + "/geomap_interactive_globe.png";
  assert_true(NavWriteWindowPng(m.Window, shot, &err));
  std::printf("screenshot: %s\n", shot.c_str());
}

} // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_san_francisco_50km), cmocka_unit_test(test_san_francisco_5km),
      cmocka_unit_test(test_turin_30km),         cmocka_unit_test(test_berlin_500km),
      cmocka_unit_test(test_berlin_50km_lakes),  cmocka_unit_test(test_polar_route),
      cmocka_unit_test(test_missing_data),       cmocka_unit_test(test_interactive_rebuilds),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
