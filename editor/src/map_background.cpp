#include "map_background.h"

#include <QObject>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sys/stat.h>

#include "navview/nav_map_data.h"
#include "navview/nav_map_tiles.h"
#include "navview/nav_view_map.h"

extern "C" {
#include "navcore/nav_frames.h"
#include "navcore/nav_paths.h"
}

namespace studio {

namespace {

constexpr double kD2R = M_PI / 180.0;

double WrapDeg(double d) {
  d = std::fmod(d + 180.0, 360.0);
  if (d < 0) d += 360.0;
  return d - 180.0;
}

/** One shapefile part with its lon/lat bounding box [deg]. */
struct Part {
  std::vector<double> lonlat;
  double lon0, lat0, lon1, lat1;
};

struct Shapes {
  std::vector<Part> parts;
  QString note;
};

/** The coastlines and lakes, read once (GUI thread) from the cartopy data. */
const Shapes &CoastShapes() {
  static const Shapes shapes = [] {
    Shapes sh;
    const std::string dir = MapDataDir();
    for (const char *rel : {"/shapefiles/gshhs/c/GSHHS_c_L1.shp", "/shapefiles/gshhs/l/GSHHS_l_L2.shp"}) {
      const std::string f = dir + rel;
      struct stat st;
      std::vector<std::vector<double>> parts;
      std::string err;
      if (stat(f.c_str(), &st) != 0 || !NavReadShapefile(f, &parts, &err)) {
        sh.note = QObject::tr("no coastline data (%1)").arg(QString::fromStdString(f));
        continue;
      }
      for (auto &pl : parts) {
        if (pl.size() < 4) continue;
        Part p;
        p.lon0 = p.lat0 = INFINITY;
        p.lon1 = p.lat1 = -INFINITY;
        for (size_t i = 0; i + 1 < pl.size(); i += 2) {
          p.lon0 = std::min(p.lon0, pl[i]);
          p.lon1 = std::max(p.lon1, pl[i]);
          p.lat0 = std::min(p.lat0, pl[i + 1]);
          p.lat1 = std::max(p.lat1, pl[i + 1]);
        }
        p.lonlat = std::move(pl);
        sh.parts.push_back(std::move(p));
      }
    }
    return sh;
  }();
  return shapes;
}

std::string FormatDeg(double v, bool lat, double step) {
  int dec = 0;
  while (dec < 6 && std::fabs(step * std::pow(10.0, dec) - std::round(step * std::pow(10.0, dec))) > 1e-6) ++dec;
  char buf[64];
  const char hemi = lat ? (v >= 0 ? 'N' : 'S') : (v >= 0 ? 'E' : 'W');
  std::snprintf(buf, sizeof buf, "%.*f\u00b0%c", dec, std::fabs(v) < 0.5 * std::pow(10.0, -dec) ? 0.0 : std::fabs(v),
                hemi);
  return buf;
}

/** Projects lon/lat [deg] polylines into the local frame; a polyline is broken where it leaves the
 *  rectangle (grown by @p margin) or jumps across the longitude seam of the local frame. */
class Projector {
public:
  Projector(const nav_scene &s, double x0, double y0, double x1, double y1)
      : fr_(nav_frame_from_scene(&s)), x0_(x0), y0_(y0), x1_(x1), y1_(y1) {
    margin_ = 0.05 * std::max(x1 - x0, y1 - y0);
    jump_ = 0.25 * M_PI * 6371e3; // the longitude seam of the local frame, not a coastline step
  }
  void Add(const double *lonlat, size_t n, std::vector<std::vector<double>> *out) const {
    std::vector<double> cur;
    double px = 0, py = 0;
    bool prev_in = false;
    for (size_t i = 0; i < n; ++i) {
      const nav_vec3 r = nav_frame_geodetic_to_local(&fr_, nav_geodetic{lonlat[2 * i + 1] * kD2R, lonlat[2 * i] * kD2R, 0.0});
      const double x = r.y, y = r.x;
      const bool in = x >= x0_ - margin_ && x <= x1_ + margin_ && y >= y0_ - margin_ && y <= y1_ + margin_;
      const bool jump = i > 0 && (std::fabs(x - px) > jump_ || std::fabs(y - py) > jump_);
      // A segment is kept when one of its ends is inside (it is clipped by the viewport).
      if (i > 0 && !jump && (in || prev_in)) {
        if (cur.empty()) cur.insert(cur.end(), {px, py});
        cur.insert(cur.end(), {x, y});
      } else {
        Flush(&cur, out);
      }
      px = x;
      py = y;
      prev_in = in;
    }
    Flush(&cur, out);
  }

private:
  static void Flush(std::vector<double> *cur, std::vector<std::vector<double>> *out) {
    if (cur->size() >= 4) out->push_back(*cur);
    cur->clear();
  }
  nav_frame fr_;
  double x0_, y0_, x1_, y1_, margin_, jump_;
};

} // namespace

std::string MapDataDir() {
  char dir[4096];
  return nav_paths_map_data_dir(dir, sizeof dir) ? std::string(dir) : std::string();
}

void BuildMapBackground(const nav_scene &s, double x0, double y0, double x1, double y1, MapBackground *out,
                        int w_px, int h_px, const MapTiles *tiles, const NavMapTextSize &text_size) {
  *out = MapBackground();
  const nav_frame fr = nav_frame_from_scene(&s);
  // The lat/lon box of the rectangle (its boundary and inside, sampled), longitudes relative to the
  // centre's so that a box across the date line stays one interval.
  const nav_geodetic c = nav_frame_local_to_geodetic(&fr, nav_vec3{0.5 * (y0 + y1), 0.5 * (x0 + x1), 0.0});
  const double lonc = c.lon_rad / kD2R;
  double la0 = INFINITY, la1 = -INFINITY, dlo0 = INFINITY, dlo1 = -INFINITY;
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j) {
      const double x = x0 + (x1 - x0) * i / 8.0, y = y0 + (y1 - y0) * j / 8.0;
      const nav_geodetic g = nav_frame_local_to_geodetic(&fr, nav_vec3{y, x, 0.0});
      la0 = std::min(la0, g.lat_rad / kD2R);
      la1 = std::max(la1, g.lat_rad / kD2R);
      const double d = WrapDeg(g.lon_rad / kD2R - lonc);
      dlo0 = std::min(dlo0, d);
      dlo1 = std::max(dlo1, d);
    }
  la0 = std::max(-90.0, la0);
  la1 = std::min(90.0, la1);
  const Projector proj(s, x0, y0, x1, y1);
  const double span = std::max(x1 - x0, y1 - y0);

  // Land and water from GSHHG, painted into an image of the rectangle (one pixel per screen pixel).
  NavMapLayers layers;
  bool gshhg = false;
  if (w_px > 0 && h_px > 0) {
    std::string err;
    const bool all_lon = dlo1 - dlo0 > 300.0;
    gshhg = NavMapLoadLayers(NavMapGshhgDir(), NavShoreResForScale((x1 - x0) / w_px), la0, la1,
                             all_lon ? lonc - 180.0 : lonc + dlo0, all_lon ? lonc + 180.0 : lonc + dlo1, &layers, &err);
    if (!gshhg) {
      out->note = QString::fromStdString(err);
    } else {
      // Rings far beyond the rectangle are skipped: the local frame folds the far side of the
      // Earth back onto the view (its "down" grows as 1 - cos of the arc from the origin).
      const double arc_max = std::min(M_PI, 0.75 * std::hypot(std::max(std::fabs(x0), std::fabs(x1)),
                                                               std::max(std::fabs(y0), std::fabs(y1))) / 6371e3 +
                                                    10.0 * kD2R);
      const double down_max = 6371e3 * (1.0 - std::cos(arc_max)) + 1.0;
      NavMapPaintAreas(layers,
                       [&](double lat, double lon, double *px, double *py) {
                         const nav_vec3 r = nav_frame_geodetic_to_local(&fr, nav_geodetic{lat * kD2R, lon * kD2R, 0.0});
                         if (r.z > down_max) return false;
                         *px = (r.y - x0) / (x1 - x0) * w_px;
                         *py = (r.x - y0) / (y1 - y0) * h_px;
                         return true;
                       },
                       w_px, h_px, &out->land_rgb);
      out->land_w = w_px;
      out->land_h = h_px;
      out->shore_res = NavShoreResLetter(layers.res);
    }
  }
  // The user's tiles over the fill: each pixel centre taken back to lat/lon through the scene's
  // frame and resampled from the Web-Mercator tiles.
  if (tiles && !tiles->source.empty() && w_px > 0 && h_px > 0) {
    std::shared_ptr<NavTileSource> src;
    std::string err;
    if (!NavTileSourceOpen(tiles->source, &src, &err)) {
      out->note = QString::fromStdString(err);
    } else {
      if (out->land_rgb.size() != 3 * static_cast<size_t>(w_px) * static_cast<size_t>(h_px)) {
        // No GSHHG fill: the tiles go over the plain land colour.
        out->land_rgb.assign(3 * static_cast<size_t>(w_px) * static_cast<size_t>(h_px), 0);
        for (size_t i = 0; i < out->land_rgb.size(); i += 3)
          std::copy(kNavMapLandRgb, kNavMapLandRgb + 3, out->land_rgb.begin() + static_cast<std::ptrdiff_t>(i));
        out->land_w = w_px;
        out->land_h = h_px;
      }
      NavTilePaint tp;
      NavMapPaintTiles(*src,
                       [&](double px, double py, double *lat_deg, double *lon_deg) {
                         const double x = x0 + px / w_px * (x1 - x0), y = y0 + py / h_px * (y1 - y0);
                         const nav_geodetic g = nav_frame_local_to_geodetic(&fr, nav_vec3{y, x, 0.0});
                         *lat_deg = g.lat_rad / kD2R;
                         *lon_deg = g.lon_rad / kD2R;
                         return true;
                       },
                       (x1 - x0) / w_px, c.lat_rad / kD2R, w_px, h_px, &out->land_rgb, &tp);
      out->tile_zoom = tp.zoom;
      out->tile_coverage = tp.coverage;
      if (tp.tiles > 0) out->tile_credit = QString::fromStdString(NavTileCredit(*src, tiles->attribution));
      for (const std::string &n : tp.notes)
        out->note += (out->note.isEmpty() ? "" : "; ") + QString::fromStdString(n);
    }
  }
  if (gshhg && span > kCoastSpanM) {
    const double m_px = (x1 - x0) / w_px;
    const int river_max = m_px < 60.0 ? 5 : m_px < 600.0 ? 3 : m_px < 3000.0 ? 2 : 1;
    for (const NavMapLine &l : layers.shores)
      proj.Add(l.lonlat.data(), l.lonlat.size() / 2, &out->coast);
    for (const NavMapLine &l : layers.rivers)
      if (l.level <= river_max) proj.Add(l.lonlat.data(), l.lonlat.size() / 2, &out->rivers);
    for (const NavMapLine &l : layers.borders)
      if (l.level <= 2) proj.Add(l.lonlat.data(), l.lonlat.size() / 2, &out->borders);
  } else if (span > kCoastSpanM) {
    const Shapes &sh = CoastShapes();
    out->note = sh.note;
    for (const Part &p : sh.parts) {
      if (p.lat1 < la0 || p.lat0 > la1) continue;
      // Longitude overlap, relative to the centre (parts across the date line are kept).
      const double a = WrapDeg(p.lon0 - lonc), b = a + (p.lon1 - p.lon0);
      const bool overlap = (b >= dlo0 && a <= dlo1) || (b - 360.0 >= dlo0 && a - 360.0 <= dlo1) ||
                           (b + 360.0 >= dlo0 && a + 360.0 <= dlo1) || p.lon1 - p.lon0 > 300.0;
      if (!overlap) continue;
      proj.Add(p.lonlat.data(), p.lonlat.size() / 2, &out->coast);
    }
  }

  if (span >= kStreetScaleSpanM) {
    const double lat_step = NavGraticuleStepDeg(std::max((la1 - la0) * 0.8, 1e-4));
    const double lon_step = NavGraticuleStepDeg(std::max((dlo1 - dlo0) * 0.8, 1e-4));
    out->lat_step_deg = lat_step;
    out->lon_step_deg = lon_step;
    const int n = 256;
    std::vector<double> ll(2 * (n + 1));
    // Label anchor: the point of the line inside the rectangle nearest its right (parallels) or
    // top (meridians) edge.
    auto anchor = [&](const std::vector<std::vector<double>> &lines, bool lat, MapLabel *l) {
      double best = -INFINITY;
      for (const auto &pl : lines)
        for (size_t i = 0; i + 1 < pl.size(); i += 2) {
          const double x = pl[i], y = pl[i + 1];
          if (x < x0 || x > x1 || y < y0 || y > y1) continue;
          const double key = lat ? x : y;
          if (key > best) {
            best = key;
            l->x = x;
            l->y = y;
          }
        }
      // Labels at the right edge stay below the top ones; those at the top stay left of the right ones.
      const bool clear = lat ? l->y < y0 + 0.93 * (y1 - y0) : l->x < x0 + 0.93 * (x1 - x0);
      return std::isfinite(best) && clear && best > (lat ? x0 + 0.7 * (x1 - x0) : y0 + 0.7 * (y1 - y0));
    };
    for (double la = std::ceil(la0 / lat_step) * lat_step; la <= la1 + 1e-9; la += lat_step) {
      if (std::fabs(la) > 89.999) continue;
      for (int i = 0; i <= n; ++i) {
        ll[2 * i] = lonc + dlo0 + (dlo1 - dlo0) * i / n;
        ll[2 * i + 1] = la;
      }
      std::vector<std::vector<double>> lines;
      proj.Add(ll.data(), n + 1, &lines);
      MapLabel l;
      l.latitude = true;
      l.text = FormatDeg(la, true, lat_step);
      if (anchor(lines, true, &l)) out->labels.push_back(l);
      out->graticule.insert(out->graticule.end(), lines.begin(), lines.end());
    }
    for (double lo = std::ceil((lonc + dlo0) / lon_step) * lon_step; lo <= lonc + dlo1 + 1e-9; lo += lon_step) {
      for (int i = 0; i <= n; ++i) {
        ll[2 * i] = lo;
        ll[2 * i + 1] = la0 + (la1 - la0) * i / n;
      }
      std::vector<std::vector<double>> lines;
      proj.Add(ll.data(), n + 1, &lines);
      MapLabel l;
      l.text = FormatDeg(WrapDeg(lo), false, lon_step);
      if (anchor(lines, false, &l)) out->labels.push_back(l);
      out->graticule.insert(out->graticule.end(), lines.begin(), lines.end());
    }
  }

  // Place names, placed as on navview's map, clear of the caption (bottom), the legend (top right)
  // and, above street scale, the graticule labels (top and right edges).
  if (text_size && w_px > 0 && h_px > 0) {
    const std::string path = NavMapPlacesFile();
    const std::vector<NavPlace> *places = nullptr;
    std::string err;
    if (!path.empty() && NavMapLoadPlaces(path, &places, &err)) {
      out->have_gazetteer = true;
      const double W = w_px, H = h_px;
      std::vector<std::array<double, 4>> taken = {{0, 0, W, 70}, {W - 300, H - 90, W, H}};
      if (span >= kStreetScaleSpanM) {
        taken.push_back({0, H - 26, W, H});
        taken.push_back({W - 90, 0, W, H});
      }
      const double arc_max = std::min(M_PI, 0.75 * std::hypot(std::max(std::fabs(x0), std::fabs(x1)),
                                                              std::max(std::fabs(y0), std::fabs(y1))) / 6371e3 +
                                                  10.0 * kD2R);
      const double down_max = 6371e3 * (1.0 - std::cos(arc_max)) + 1.0;
      const std::vector<NavMapPlaceLabel> chosen = NavMapChoosePlaces(
          *places,
          [&](double lat, double lon) {
            return lat >= la0 && lat <= la1 && (dlo1 - dlo0 > 300.0 || (WrapDeg(lon - lonc) >= dlo0 && WrapDeg(lon - lonc) <= dlo1));
          },
          [&](double lat, double lon, double *px, double *py) {
            const nav_vec3 r = nav_frame_geodetic_to_local(&fr, nav_geodetic{lat * kD2R, lon * kD2R, 0.0});
            if (r.z > down_max) return false;
            *px = (r.y - x0) / (x1 - x0) * W;
            *py = (r.x - y0) / (y1 - y0) * H;
            return true;
          },
          w_px, h_px, 13, text_size, taken);
      for (const NavMapPlaceLabel &l : chosen) {
        MapPlace p;
        p.name = l.place->name;
        p.dot_x = x0 + l.dot_x / W * (x1 - x0);
        p.dot_y = y0 + l.dot_y / H * (y1 - y0);
        p.text_x = x0 + l.x0 / W * (x1 - x0);
        p.text_y = y0 + l.y0 / H * (y1 - y0);
        p.size_pt = l.size_pt;
        p.bold = l.bold;
        out->places.push_back(p);
      }
    }
  }
}

} // namespace studio
