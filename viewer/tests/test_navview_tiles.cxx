// The map's tile layer (issue 19, item 2: streets at street scale). The test makes its own tiles
// around Turin (tile_fixture.h: a colour per tile, two dark streets through each tile's centre),
// renders the map at 1280x800 under Xvfb and checks that the streets fall where their latitude
// and longitude project (to 1.5 px), that the tiles' colours are where they belong, that the
// attribution is drawn, that the XYZ directory gives the same picture as the MBTiles file, that
// the zoom follows the scale and that beyond the tiles' levels the GSHHG fill shows; bad files
// and tiles give clear errors. The PNGs stay in Testing/Temporary/tiles_*.png to be looked at.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkCommand.h>
#include <vtkPNGReader.h>
#include <vtkRenderWindowInteractor.h>

#include "map_interactive_internal.h"
#include "navview/nav_map_data.h"
#include "navview/nav_map_tiles.h"
#include "navview/nav_view_map.h"

#include "tile_fixture.h"

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
constexpr double kLat = 45.0703, kLon = 7.6869; // Turin, Piazza Castello
constexpr int kZ0 = 14, kZ1 = 16;

std::string OutDir() {
  std::string d = NAVVIEW_TEST_OUT_DIR;
  tilefix::MkDirs(d);
  return d;
}
std::string Fixture() {
  return OutDir() + "/tiles_fixture";
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

/** A result whose reference runs just north of the view (the tracks are not under test). */
NavResult Track() {
  NavResult r;
  r.scene_name = "turin-tiles";
  const double ll[2][2] = {{kLat + 0.0075, kLon - 0.004}, {kLat + 0.0075, kLon + 0.004}};
  for (int i = 0; i < 2; ++i) {
    r.truth.t_s.push_back(i);
    r.truth.pos_ned_m.insert(r.truth.pos_ned_m.end(), {0.0, 0.0, 0.0});
    r.truth.geo.insert(r.truth.geo.end(), {ll[i][0] * kD2R, ll[i][1] * kD2R, 0.0});
  }
  return r;
}

/** The map centred on Turin. Place names are off unless @p places: the probes of CheckTiles
 *  must not lie under a text, and the name "Turin" sits at the centre (they are tested in
 *  test_navview_geomap). */
NavMapInfo Render(const std::string &tiles, const std::string &attribution, const char *name, double span_km,
                  Image *im, bool places = false) {
  NavMapOptions o;
  o.width_px = kW;
  o.height_px = kH;
  o.center_lat_deg = kLat;
  o.center_lon_deg = kLon;
  o.span_km = span_km;
  o.multisamples = 0;
  o.tiles = tiles;
  o.tiles_attribution = attribution;
  o.show_places = places;
  const std::string png = OutDir() + "/tiles_" + name + ".png";
  NavMapInfo info;
  std::string err;
  if (!NavRenderMapPng(Track(), o, png, &err, &info)) fail_msg("%s: %s", name, err.c_str());
  *im = ReadPng(png);
  std::printf("%s: %s: %.3g km across, zoom %d, %d tiles, %.1f %% of the view from tiles, built in %.0f ms\n",
              name, png.c_str(), span_km, info.tile_zoom, info.tiles, 100.0 * info.tile_coverage,
              info.build_ms);
  for (const std::string &n : info.notes)
    std::printf("  note: %s\n", n.c_str());
  assert_int_equal(im->w, kW);
  assert_int_equal(im->h, kH);
  return info;
}

bool UnderText(const NavMapInfo &info, double px, double py, double pad) {
  for (const NavMapLabel &l : info.labels)
    if (px > l.x0 - pad && px < l.x1 + pad && py > l.y0 - pad && py < l.y1 + pad) return true;
  return false;
}

bool Dark(const unsigned char *c) {
  return c[0] < 70 && c[1] < 70 && c[2] < 70;
}

/** Centre of the dark run along a row (@p horizontal) or column through (@p x, @p y), searched
 *  within +-@p reach pixels; NaN when there is none. */
double DarkCentre(const Image &im, int x, int y, bool horizontal, int reach) {
  double sum = 0.0;
  int n = 0;
  for (int d = -reach; d <= reach; ++d) {
    const int xx = horizontal ? x + d : x, yy = horizontal ? y : y + d;
    if (xx < 0 || yy < 0 || xx >= im.w || yy >= im.h) continue;
    if (Dark(im.At(xx, yy))) {
      sum += (horizontal ? xx : yy) + 0.5; // a pixel's centre
      ++n;
    }
  }
  return n > 0 ? sum / n : NAN;
}

/** The tiles of zoom @p z around the centre: their streets cross where the tile centre projects
 *  (checked along each street at four places, 1.5 px), and a point a quarter into the tile shows
 *  the tile's colour. @return the tiles checked (those whose probes lie in the view and off the
 *  texts). */
int CheckTiles(const Image &im, const NavMapInfo &info, int z) {
  double fx, fy;
  tilefix::TileXY(kLat, kLon, z, &fx, &fy);
  // Tile size on screen [px] (its centre's scale).
  const double m_px = info.span_x_m / info.width_px;
  const double tile_px = 2.0 * tilefix::kPi * 6378137.0 * std::cos(kLat * kD2R) / std::ldexp(1.0, z) / m_px;
  int checked = 0;
  for (int dx = -1; dx <= 1; ++dx)
    for (int dy = -1; dy <= 1; ++dy) {
      const int tx = static_cast<int>(std::floor(fx)) + dx, ty = static_cast<int>(std::floor(fy)) + dy;
      double clat, clon, px, py;
      tilefix::TileLatLon(tx + 0.5, ty + 0.5, z, &clat, &clon);
      info.PixelOf(clat, clon, &px, &py);
      const double off[4] = {-0.35 * tile_px, -0.2 * tile_px, 0.2 * tile_px, 0.35 * tile_px};
      const int reach = static_cast<int>(0.12 * tile_px);
      bool inside = px - 0.45 * tile_px > 2 && px + 0.45 * tile_px < kW - 2 && py - 0.45 * tile_px > 2 &&
                    py + 0.45 * tile_px < kH - 2;
      for (double o : off)
        inside = inside && !UnderText(info, px + o, py, reach + 4) && !UnderText(info, px, py + o, reach + 4);
      double qlat, qlon, qx, qy;
      tilefix::TileLatLon(tx + 0.25, ty + 0.25, z, &qlat, &qlon);
      info.PixelOf(qlat, qlon, &qx, &qy);
      inside = inside && !UnderText(info, qx, qy, 4);
      if (!inside) continue;
      // The meridian street: along rows above and below the crossing, its centre is at px.
      for (double o : off) {
        const double c = DarkCentre(im, static_cast<int>(px), static_cast<int>(py + o), true, reach);
        const double r = DarkCentre(im, static_cast<int>(px + o), static_cast<int>(py), false, reach);
        std::printf(
            "  z%d tile %d/%d: street crossing at (%.1f, %.1f) px; meridian street at x %.2f (row %+.0f), "
            "parallel street at y %.2f (column %+.0f)\n",
            z, tx, ty, px, py, c, o, r, o);
        assert_near(c, px, 1.5);
        assert_near(r, py, 1.5);
      }
      // The tile's colour a quarter in from its north-west corner (3 x 3 pixels, a grid line
      // of the local metric grid may cross: 6 of 9 must match to 4 levels).
      unsigned char want[3];
      tilefix::TileRgb(z, tx, ty, want);
      int match = 0;
      for (int a = -1; a <= 1; ++a)
        for (int b = -1; b <= 1; ++b) {
          const unsigned char *p = im.At(static_cast<int>(qx) + a, static_cast<int>(qy) + b);
          match +=
              std::abs(p[0] - want[0]) <= 4 && std::abs(p[1] - want[1]) <= 4 && std::abs(p[2] - want[2]) <= 4;
        }
      const unsigned char *p = im.At(static_cast<int>(qx), static_cast<int>(qy));
      std::printf("  z%d tile %d/%d colour at (%.0f, %.0f): %d %d %d, expected %d %d %d (%d of 9)\n", z, tx,
                  ty, qx, qy, p[0], p[1], p[2], want[0], want[1], want[2], match);
      assert_true(match >= 6);
      ++checked;
    }
  return checked;
}

/** Land (GSHHG fill) at the pixel of @p lat, @p lon: blue minus red below -8 in 18 of 25. */
bool GshhgLandAt(const Image &im, const NavMapInfo &info, double lat, double lon) {
  double px, py;
  info.PixelOf(lat, lon, &px, &py);
  if (px < 3 || py < 3 || px > kW - 3 || py > kH - 3) fail_msg("(%g, %g) is outside the view", lat, lon);
  if (UnderText(info, px, py, 3)) fail_msg("(%g, %g) lies under a text: choose another point", lat, lon);
  int land = 0;
  for (int a = -2; a <= 2; ++a)
    for (int b = -2; b <= 2; ++b) {
      const unsigned char *c = im.At(static_cast<int>(px) + a, static_cast<int>(py) + b);
      land += std::abs(c[0] - kNavMapLandRgb[0]) <= 6 && std::abs(c[1] - kNavMapLandRgb[1]) <= 6 &&
              std::abs(c[2] - kNavMapLandRgb[2]) <= 6;
    }
  std::printf("  GSHHG land colour at (%.4f, %.4f) pixel (%.0f, %.0f): %d of 25\n", lat, lon, px, py, land);
  return land >= 18;
}

int Setup(void **) {
  std::string err;
  const int n = tilefix::MakeTiles(Fixture(), kLat, kLon, kZ0, kZ1, 2500.0, &err);
  if (n < 0) {
    std::fprintf(stderr, "tile fixture: %s\n", err.c_str());
    return -1;
  }
  return 0;
}

void test_street_scale_mbtiles(void **) {
  Image im;
  const NavMapInfo info = Render(Fixture() + "/tiles.mbtiles", "", "mbtiles_1500m", 1.5, &im);
  assert_int_equal(info.tile_zoom, 16); // the scale asks for 17; the file stops at 16
  assert_true(info.tile_coverage > 0.999);
  assert_true(CheckTiles(im, info, 16) >= 2);
  // The attribution: the metadata's HTML as text, in the legend, drawn (dark text pixels).
  assert_string_equal(info.tile_credit.c_str(),
                      (std::string("map tiles: ") + tilefix::kAttributionText).c_str());
  bool found = false;
  for (const NavMapLabel &l : info.labels) {
    if (l.kind != NavMapLabel::Legend || l.text.find(info.tile_credit) == std::string::npos) continue;
    int dark = 0;
    for (int y = static_cast<int>(l.y0); y < static_cast<int>(l.y1); ++y)
      for (int x = static_cast<int>(l.x0); x < static_cast<int>(l.x1); ++x)
        dark += Dark(im.At(std::clamp(x, 0, kW - 1), std::clamp(y, 0, kH - 1)));
    std::printf("  legend with the credit at (%.0f, %.0f)-(%.0f, %.0f): %d dark text pixels\n", l.x0, l.y0,
                l.x1, l.y1, dark);
    assert_true(dark >= 200);
    found = true;
  }
  assert_true(found);
}

void test_xyz_directory_same_picture(void **) {
  Image a, b, c;
  Render(Fixture() + "/tiles.mbtiles", "", "mbtiles_places_1500m", 1.5, &a, true);
  const NavMapInfo ib = Render(Fixture() + "/xyz", tilefix::kAttributionText, "xyz_1500m", 1.5, &b, true);
  const NavMapInfo ic = Render(Fixture() + "/xyz/{z}/{x}/{y}.png", tilefix::kAttributionText,
                               "xyz_template_1500m", 1.5, &c, true);
  assert_int_equal(ib.tile_zoom, 16);
  assert_int_equal(ic.tile_zoom, 16);
  size_t diff_b = 0, diff_c = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) {
    diff_b += a.rgb[i] != b.rgb[i];
    diff_c += a.rgb[i] != c.rgb[i];
  }
  std::printf("  bytes differing from the MBTiles picture: directory %zu, template %zu\n", diff_b, diff_c);
  assert_int_equal(diff_b, 0);
  assert_int_equal(diff_c, 0);
}

void test_zoom_follows_scale(void **) {
  Image im;
  const NavMapInfo info = Render(Fixture() + "/tiles.mbtiles", "", "mbtiles_4km", 4.0, &im);
  // 4 km over 1280 px at 45.07 N: log2(2 pi 6378137 cos(lat) / (256 x 3.125 m)) = 15.1.
  assert_near(NavTileZoomForScale(4000.0 / kW, kLat), 15.11, 0.01);
  assert_int_equal(info.tile_zoom, 15);
  assert_true(CheckTiles(im, info, 15) >= 3);
}

void test_fallback_beyond_tiles(void **) {
  Image im;
  // 8 km: zoom 14, the tiles cover only the middle; east of them the GSHHG land shows.
  NavMapInfo info = Render(Fixture() + "/tiles.mbtiles", "", "mbtiles_8km", 8.0, &im);
  assert_int_equal(info.tile_zoom, 14);
  assert_true(info.tile_coverage > 0.2 && info.tile_coverage < 0.95);
  assert_true(CheckTiles(im, info, 14) >= 1);
  assert_true(GshhgLandAt(im, info, kLat + 0.005, kLon - 0.046)); // 3.6 km west: beyond the tiles
  // 100 km: zoom 10 would be needed, the file starts at 14: no tiles, the GSHHG map, a note.
  info = Render(Fixture() + "/tiles.mbtiles", "", "mbtiles_100km", 100.0, &im);
  assert_int_equal(info.tile_zoom, -1);
  assert_int_equal(info.tiles, 0);
  assert_true(info.tile_credit.empty());
  bool note = false;
  for (const std::string &n : info.notes)
    note = note || n.find("not drawn at this scale") != std::string::npos;
  assert_true(note);
  assert_true(GshhgLandAt(im, info, kLat - 0.1, kLon - 0.15));
}

void test_open_errors(void **) {
  const std::string d = OutDir() + "/tiles_bad";
  tilefix::MkDirs(d + "/empty");
  struct Case {
    std::string spec, expect;
  };
  { std::ofstream(d + "/garbage.mbtiles") << "this is not a database\n"; }
  { // the first 3 kB of a good file: a SQLite header over missing pages
    std::ifstream in(Fixture() + "/tiles.mbtiles", std::ios::binary);
    std::vector<char> buf(3072);
    in.read(buf.data(), 3072);
    std::ofstream(d + "/truncated.mbtiles", std::ios::binary).write(buf.data(), 3072);
  }
  const Case cases[] = {
      {d + "/garbage.mbtiles", "not an MBTiles file"},
      {d + "/truncated.mbtiles", "error: "},
      {d + "/no-such.mbtiles", "no such file or directory"},
      {d + "/empty", "holds no zoom-level directories"},
      {d + "/nowhere/{z}/{x}/{y}.png", "does not exist"},
      {Fixture() + "/xyz/{z}/{x}.png", "needs {z}, {x} and {y}"},
      {"http://127.0.0.1:9/tiles/{z}/{x}.png", "needs {z}, {x} and {y}"},
  };
  for (const Case &c : cases) {
    std::shared_ptr<NavTileSource> src;
    std::string err;
    const bool ok = NavTileSourceOpen(c.spec, &src, &err);
    std::printf("  %s -> %s\n", c.spec.c_str(), ok ? "opened" : err.c_str());
    assert_false(ok);
    assert_true(err.rfind(c.spec + ": error: ", 0) == 0);
    assert_true(err.find(c.expect) != std::string::npos);
  }
  // The map build fails with the same message.
  NavMapOptions o;
  o.tiles = d + "/garbage.mbtiles";
  o.center_lat_deg = kLat;
  o.center_lon_deg = kLon;
  o.span_km = 1.5;
  std::string err;
  assert_false(NavRenderMapPng(Track(), o, OutDir() + "/tiles_never.png", &err));
  assert_true(err.find("not an MBTiles file") != std::string::npos);
}

void test_damaged_tile(void **) {
  // A good file with one tile's data replaced by bytes that are no image: the map is drawn, the
  // tile is left out (GSHHG shows there) and a note names it.
  const std::string src = Fixture() + "/tiles.mbtiles", dst = OutDir() + "/tiles_bad/damaged.mbtiles";
  tilefix::MkDirs(OutDir() + "/tiles_bad");
  {
    std::ifstream in(src, std::ios::binary);
    std::ofstream out(dst, std::ios::binary);
    out << in.rdbuf();
  }
  double fx, fy;
  tilefix::TileXY(kLat, kLon, 16, &fx, &fy);
  const int tx = static_cast<int>(fx), ty = static_cast<int>(fy);
  sqlite3 *db = nullptr;
  assert_int_equal(sqlite3_open(dst.c_str(), &db), SQLITE_OK);
  const std::string sql =
      "UPDATE tiles SET tile_data = X'3c68746d6c3e' WHERE zoom_level = 16 AND tile_column = " +
      std::to_string(tx) + " AND tile_row = " + std::to_string((1 << 16) - 1 - ty);
  assert_int_equal(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK);
  assert_int_equal(sqlite3_changes(db), 1);
  sqlite3_close(db);
  Image im;
  const NavMapInfo info = Render(dst, "", "damaged_1500m", 1.5, &im);
  bool note = false;
  for (const std::string &n : info.notes)
    note = note || (n.find("tile 16/" + std::to_string(tx) + "/" + std::to_string(ty) +
                           ": not a PNG or JPEG image") != std::string::npos);
  assert_true(note);
  assert_true(info.tile_coverage < 0.98);
  double qlat, qlon;
  tilefix::TileLatLon(tx + 0.25, ty + 0.25, 16, &qlat, &qlon);
  assert_true(GshhgLandAt(im, info, qlat, qlon));
}

// navview's interactive map with tiles: each wheel step rebuilds the map, and the tile zoom
// follows the scale (8 km across: 14; after six steps in, 2.1 km: 16), the credit stays.
void test_interactive_zoom(void **) {
  NavMapOptions o;
  o.width_px = kW;
  o.height_px = kH;
  o.center_lat_deg = kLat;
  o.center_lon_deg = kLon;
  o.span_km = 8.0;
  o.multisamples = 0;
  o.show_places = false;
  o.tiles = Fixture() + "/tiles.mbtiles";
  NavMapInteractive m;
  std::string err;
  const NavResult r = Track();
  if (!m.Open(r, o, &err)) fail_msg("%s", err.c_str());
  assert_int_equal(m.Info.tile_zoom, 14);
  int zooms[7] = {m.Info.tile_zoom};
  for (int k = 1; k <= 6; ++k) {
    m.Iren->SetEventPosition(kW / 2, kH / 2);
    m.Iren->InvokeEvent(vtkCommand::MouseWheelForwardEvent);
    zooms[k] = m.Info.tile_zoom;
    std::printf("  wheel step %d: %.3g km across, tile zoom %d, %d tiles, %.1f %% covered, rebuild %.0f ms\n",
                k, m.Info.span_x_m / 1e3, m.Info.tile_zoom, m.Info.tiles, 100.0 * m.Info.tile_coverage,
                m.LastRebuildMs);
    assert_true(zooms[k] >= zooms[k - 1]);
    assert_false(m.Info.tile_credit.empty());
  }
  assert_near(m.Info.span_x_m, 8e3 / std::pow(1.25, 6), 1e-6);
  assert_int_equal(m.Info.tile_zoom, 16);
}

void test_antimeridian_and_poles(void **) {
  // The four tiles of zoom 1 (x 0: west, 1: east; y 0: north, 1: south) and a made-up view
  // 200 x 100 px in plate carree from 170 E across the date line to 170 W and from 89 N to
  // 79 N: west of 180 the pixels show the eastern tiles, east of it the western ones; beyond
  // Web-Mercator's 85.05 N nothing is painted (the background stays).
  const std::string d = OutDir() + "/tiles_world";
  for (int x = 0; x < 2; ++x)
    for (int y = 0; y < 2; ++y) {
      const std::string dir = d + "/1/" + std::to_string(x);
      tilefix::MkDirs(dir);
      const std::vector<unsigned char> png = tilefix::TilePng(1, x, y);
      std::ofstream(dir + "/" + std::to_string(y) + ".png", std::ios::binary)
          .write(reinterpret_cast<const char *>(png.data()), static_cast<std::streamsize>(png.size()));
    }
  std::shared_ptr<NavTileSource> src;
  std::string err;
  if (!NavTileSourceOpen(d, &src, &err)) fail_msg("%s", err.c_str());
  assert_int_equal(src->MinZoom(), 1);
  assert_int_equal(src->MaxZoom(), 1);
  const int w = 200, h = 100;
  std::vector<unsigned char> rgb(3 * w * h, 7);
  NavTilePaint tp;
  // m_per_px chosen so that the zoom is 1: 2 pi a cos(80 deg) / (256 x 2^1) = 13.7 km.
  NavMapPaintTiles(
      *src,
      [&](double px, double py, double *lat, double *lon) {
        *lon = 170.0 + 20.0 * px / w; // 170 .. 190 (= 170 W)
        *lat = 79.0 + 10.0 * py / h;  // 79 .. 89 N
        return true;
      },
      13.7e3, 80.0, w, h, &rgb, &tp);
  assert_int_equal(tp.zoom, 1);
  auto at = [&](int i, int j) { return &rgb[3 * (static_cast<size_t>(j) * w + i)]; };
  unsigned char east[3], west[3];
  tilefix::TileRgb(1, 1, 0, east);
  tilefix::TileRgb(1, 0, 0, west);
  for (int j : {5, 30, 55}) { // 79.5, 82, 84.5 N
    for (int i : {10, 90})    // 171, 179 E
      assert_memory_equal(at(i, j), east, 3);
    for (int i : {110, 190}) // 179 W, 171 W
      assert_memory_equal(at(i, j), west, 3);
  }
  for (int j : {65, 95}) // 85.5, 88.5 N: beyond Web-Mercator
    for (int i : {10, 110, 190}) {
      const unsigned char bg[3] = {7, 7, 7};
      assert_memory_equal(at(i, j), bg, 3);
    }
  std::printf("  date line and pole: %d tiles, %.1f %% painted\n", tp.tiles, 100.0 * tp.coverage);
  assert_int_equal(tp.tiles, 2);
}

} // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_street_scale_mbtiles),
      cmocka_unit_test(test_xyz_directory_same_picture),
      cmocka_unit_test(test_zoom_follows_scale),
      cmocka_unit_test(test_fallback_beyond_tiles),
      cmocka_unit_test(test_open_errors),
      cmocka_unit_test(test_damaged_tile),
      cmocka_unit_test(test_antimeridian_and_poles),
      cmocka_unit_test(test_interactive_zoom),
  };
  return cmocka_run_group_tests(tests, Setup, nullptr);
}
