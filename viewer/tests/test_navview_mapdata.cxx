// The map's offline data (nav_map_data.h), without a display: GSHHG's binned files as
// docs/map-data.md reads them (corner levels agree with the way the bins are closed, known
// places get their true level), and the gazetteer file (known places, bad input).
// White-box: map_data.cxx is included to reach its static helpers (style.md section 10).
#include "../src/map_data.cxx"

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

const std::string kDir = "/usr/share/gmt-gshhg";

// Every corner of a bin that the boundary walk passes between two segments of level L lies
// inside the area it closes, so its recorded level is >= L. This is what fixes the direction of
// the walk (counter-clockwise for land, clockwise for lakes); the other direction fails.
void test_closure_agrees_with_corner_levels(void **) {
  for (const char r : {'c', 'l', 'i', 'h'}) {
    std::string err;
    long passed = 0, wrong = 0, wrong_other_way = 0;
    // The lock is released before any assertion (a failing one jumps out of the test).
    [&] {
    std::lock_guard<std::mutex> lock(g_mutex);
    BinnedFile *f = OpenBinned(kDir + "/binned_GSHHS_" + r + ".nc", true, &err);
    if (!f) return;
    for (int b = 0; b < f->nbins; ++b) {
      auto segs = BinSegs(f, b, &err);
      if (!segs) break;
      const short c = f->node_levels[static_cast<size_t>(b)];
      for (int level = 1; level <= 4; ++level) {
        std::vector<double> in, out;
        for (const Seg &s : *segs) {
          if (s.level == 6 || MapLevel(s.level) != level || s.entry == kClosed) continue;
          in.push_back(PerimeterParam(s.entry, s.uv[0], s.uv[1]));
          out.push_back(PerimeterParam(s.exit, s.uv[s.uv.size() - 2], s.uv.back()));
        }
        for (int way = 0; way < 2; ++way) {
          const bool ccw = (level % 2 == 1) == (way == 0);
          for (double pe : out) {
            double gap = 4.0;
            for (double pi : in)
              gap = std::min(gap, ccw ? std::fmod(pi - pe + 8.0, 4.0) : std::fmod(pe - pi + 8.0, 4.0));
            for (int k = 0; k < 4; ++k) {
              const double d = ccw ? std::fmod(k - pe + 8.0, 4.0) : std::fmod(pe - k + 8.0, 4.0);
              if (d <= 0.0 || d >= gap) continue;
              const bool ok = MapLevel(CornerLevel(c, k)) >= level;
              if (way == 0) {
                ++passed;
                wrong += ok ? 0 : 1;
              } else {
                wrong_other_way += ok ? 0 : 1;
              }
            }
          }
        }
      }
    }
    }();
    if (!err.empty()) fail_msg("%s", err.c_str());
    std::printf("%c: %ld corners passed, %ld with a lower level; the other way round %ld\n", r, passed, wrong,
                wrong_other_way);
    assert_true(passed > 100);
    assert_int_equal(wrong, 0);
    assert_true(wrong_other_way > passed / 2);
  }
}

// The closed rings themselves: a bin corner on a ring of level L has a recorded level >= L, in
// every bin of every resolution (full included). This caught a segment of three equal points
// (entering and leaving at one point) that was walked once round the bin: a wedge of land in
// Melville Bay at the intermediate resolution.
void test_rings_agree_with_corner_levels(void **) {
  for (const char r : {'c', 'l', 'i', 'h', 'f'}) {
    std::string err;
    long corners = 0, wrong = 0, rings = 0;
    [&] {
    std::lock_guard<std::mutex> lock(g_mutex);
    BinnedFile *f = OpenBinned(kDir + "/binned_GSHHS_" + r + ".nc", true, &err);
    if (!f) return;
    for (int b = 0; b < f->nbins; ++b) {
      auto segs = BinSegs(f, b, &err);
      if (!segs) break;
      const short c = f->node_levels[static_cast<size_t>(b)];
      for (const NavMapRing &g : CloseBin(*segs, c)) {
        ++rings;
        for (size_t i = 0; i + 1 < g.lonlat.size(); i += 2) {
          const double u = g.lonlat[i], v = g.lonlat[i + 1];
          const int k = u == 0.0 && v == 0.0 ? 0 : u == 1.0 && v == 0.0 ? 1 : u == 1.0 && v == 1.0 ? 2 : u == 0.0 && v == 1.0 ? 3 : -1;
          if (k < 0) continue;
          ++corners;
          if (MapLevel(CornerLevel(c, k)) < g.level) {
            if (wrong < 5)
              std::printf("%c: bin %d: ring of level %d passes corner %d of level %d\n", r, b, g.level, k,
                          CornerLevel(c, k));
            ++wrong;
          }
        }
      }
      f->segs.erase(b); // the full file would hold about 200 MB of decoded segments
    }
    }();
    if (!err.empty()) fail_msg("%s", err.c_str());
    std::printf("%c: %ld rings, %ld corners on them, %ld of a lower level\n", r, rings, corners, wrong);
    assert_true(corners > 100);
    assert_int_equal(wrong, 0);
  }
}

/** The level at a point as the map paints it: the last ring (in painting order) holding it. */
int LevelAt(const NavMapLayers &m, double lat, double lon) {
  int level = 0;
  for (const NavMapRing &r : m.rings) {
    bool in = false;
    const size_t n = r.lonlat.size() / 2;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
      double xi = r.lonlat[2 * i], yi = r.lonlat[2 * i + 1], xj = r.lonlat[2 * j], yj = r.lonlat[2 * j + 1];
      double x = lon;
      while (x < std::min(xi, xj) - 180.0) x += 360.0;
      if ((yi > lat) != (yj > lat) && x < xi + (lat - yi) * (xj - xi) / (yj - yi)) in = !in;
    }
    if (in) level = r.level;
  }
  return level;
}

struct Probe {
  const char *what;
  double lat, lon;
  int level;
};

// Known places at full resolution: sea, land, islands, lakes, an island in a lake.
void test_levels_at_known_places(void **) {
  const Probe probes[] = {
      {"San Francisco Bay", 37.79, -122.36, 0}, {"Oakland", 37.80, -122.27, 1},
      {"San Francisco", 37.76, -122.44, 1},     {"Angel Island", 37.862, -122.432, 1},
      {"Pacific off Ocean Beach", 37.75, -122.55, 0}, {"Turin", 45.07, 7.68, 1},
      {"Mueggelsee", 52.437, 13.645, 2},        {"Berlin", 52.50, 13.45, 1},
      {"Lago Maggiore", 45.95, 8.62, 2},        {"Lake Huron", 45.30, -82.00, 2},
      {"Manitoulin Island (in Lake Huron)", 45.85, -82.60, 3}, {"Lake Mindemoya (on Manitoulin)", 45.77, -82.19, 4},
      {"Baltic, Pomeranian Bay", 54.2, 14.2, 0}, {"Svalbard", 78.7, 16.0, 1},
      {"Arctic Ocean at the pole", 89.9, 0.0, 0}, {"Antarctic ice", -80.0, 10.0, 1},
  };
  for (const Probe &p : probes) {
    NavMapLayers m;
    std::string err;
    // lon in [0, 360) as the bins store it
    const double lon = p.lon < 0 ? p.lon + 360.0 : p.lon;
    if (!NavMapLoadLayers(kDir, NavShoreRes::Full, p.lat - 0.01, p.lat + 0.01, lon - 0.01, lon + 0.01, &m, &err))
      fail_msg("%s", err.c_str());
    const int got = LevelAt(m, p.lat, lon);
    std::printf("%-28s %9.4f %9.4f level %d (expected %d), %zu rings, %zu river and %zu border lines\n", p.what,
                p.lat, p.lon, got, p.level, m.rings.size(), m.rivers.size(), m.borders.size());
    assert_int_equal(got, p.level);
  }
}

void test_bad_input(void **) {
  NavMapLayers m;
  std::string err;
  assert_false(NavMapLoadLayers("/nonexistent", NavShoreRes::Crude, 0, 1, 0, 1, &m, &err));
  assert_non_null(std::strstr(err.c_str(), "/nonexistent/binned_GSHHS_c.nc: error: no such file"));
  std::string dir = NAVVIEW_TEST_OUT_DIR;
  for (size_t p = 1; p != std::string::npos; p = dir.find('/', p + 1))
    mkdir(dir.substr(0, p).c_str(), 0755);
  mkdir(dir.c_str(), 0755);
  const std::string bad = dir + "/geomap_bad_places.tsv";
  std::FILE *f = std::fopen(bad.c_str(), "w");
  assert_non_null(f);
  std::fputs("# comment\nBerlin\t52.5\t13.4\t3426354\tPPLC\tDE\nNowhere\t95.0\t1.0\t10\tPPL\tXX\n", f);
  std::fclose(f);
  const std::vector<NavPlace> *places = nullptr;
  assert_false(NavMapLoadPlaces(bad, &places, &err));
  std::printf("%s\n", err.c_str());
  assert_non_null(std::strstr(err.c_str(), "geomap_bad_places.tsv:3: error: field 'lat_deg': not a latitude: '95.0'"));
}

// The gazetteer built from GeoNames: the places the map tests label, largest first.
void test_gazetteer(void **) {
#ifdef NAVVIEW_NO_GAZETTEER
  skip(); // built without node and npm: no places.tsv
#endif
  const std::string path = NavMapPlacesFile();
  if (path.empty()) fail_msg("no places.tsv (built by navview_places with node and npm)");
  const std::vector<NavPlace> *places = nullptr;
  std::string err;
  if (!NavMapLoadPlaces(path, &places, &err)) fail_msg("%s", err.c_str());
  std::printf("%s: %zu places\n", path.c_str(), places->size());
  assert_true(places->size() > 100000);
  for (size_t i = 1; i < places->size(); ++i)
    assert_true((*places)[i - 1].population >= (*places)[i].population);
  bool berlin = false, turin = false, sf = false;
  for (const NavPlace &p : *places) {
    berlin = berlin || (p.name == "Berlin" && p.capital && std::fabs(p.lat_deg - 52.52) < 0.05);
    turin = turin || (p.name == "Turin" && std::fabs(p.lon_deg - 7.69) < 0.05);
    sf = sf || (p.name == "San Francisco" && std::fabs(p.lon_deg + 122.42) < 0.05);
  }
  assert_true(berlin && turin && sf);
}

} // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_closure_agrees_with_corner_levels),
      cmocka_unit_test(test_rings_agree_with_corner_levels),
      cmocka_unit_test(test_levels_at_known_places),
      cmocka_unit_test(test_bad_input),
      cmocka_unit_test(test_gazetteer),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
