// Offline map data (nav_map_data.h): GSHHG binned netCDF shorelines, rivers and borders through
// Debian's libnetcdf, and the gazetteer file made at build time. The format and the closing of
// bin-clipped segments into areas are written up in docs/map-data.md.
#include "navview/nav_map_data.h"
#include "navcore/nav_paths.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>
#include <sys/stat.h>

#include <netcdf.h>

namespace {

bool Exists(const std::string &p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

/** Sides of a bin as the format numbers them (checked against the points: a segment entering by
 *  side 0 starts at dy = 0, by 1 at dx = 65535, by 2 at dy = 65535, by 3 at dx = 0), and 4 for a
 *  segment that is a closed ring inside the bin. */
constexpr int kClosed = 4;
/** Perimeter densification: points per bin side, so the edges bend with the projection. */
constexpr int kEdgeSteps = 16;

/** A decoded segment: its level and sides, points as fractions of the bin (0..1). */
struct Seg {
  int level = 0;
  int entry = kClosed, exit = kClosed;
  std::vector<double> uv;
};

/** One file of the binned format with the per-bin tables read once and decoded bins cached. */
struct BinnedFile {
  std::string path;
  int ncid = -1;
  bool shore = false; // GSHHS (areas) rather than river/border (lines)
  int bin_min = 0, nx = 0, ny = 0, nbins = 0;
  std::vector<int> first_seg;
  std::vector<short> nseg, node_levels;
  int v_info = -1, v_start = -1, v_npts = -1, v_level = -1, v_dx = -1, v_dy = -1;
  int total_points = 0, total_segs = 0;
  std::map<int, std::shared_ptr<const std::vector<Seg>>> segs;
  std::map<int, std::shared_ptr<const std::vector<NavMapRing>>> rings;
  ~BinnedFile() {
    if (ncid >= 0) nc_close(ncid);
  }
};

std::mutex g_mutex;
std::map<std::string, std::unique_ptr<BinnedFile>> g_files;

bool Fail(std::string *error, const std::string &path, const std::string &what) {
  if (error) *error = path + ": error: " + what;
  return false;
}

bool ScalarInt(int ncid, const char *name, int *v) {
  int id;
  return nc_inq_varid(ncid, name, &id) == NC_NOERR && nc_get_var_int(ncid, id, v) == NC_NOERR;
}

/** Open @p path (cached); nullptr with a message when it is absent or not the binned format. */
BinnedFile *OpenBinned(const std::string &path, bool shore, std::string *error) {
  auto it = g_files.find(path);
  if (it != g_files.end()) return it->second.get();
  if (!Exists(path)) {
    Fail(error, path, "no such file (Debian packages gmt-gshhg-low, gmt-gshhg-high, gmt-gshhg-full)");
    return nullptr;
  }
  auto f = std::make_unique<BinnedFile>();
  f->path = path;
  f->shore = shore;
  if (nc_open(path.c_str(), NC_NOWRITE, &f->ncid) != NC_NOERR) {
    f->ncid = -1;
    Fail(error, path, "not a netCDF file");
    return nullptr;
  }
  int id;
  const bool ok =
      ScalarInt(f->ncid, "Bin_size_in_minutes", &f->bin_min) &&
      ScalarInt(f->ncid, "N_bins_in_360_longitude_range", &f->nx) &&
      ScalarInt(f->ncid, "N_bins_in_180_degree_latitude_range", &f->ny) &&
      ScalarInt(f->ncid, "N_bins_in_file", &f->nbins) && ScalarInt(f->ncid, "N_points_in_file", &f->total_points) &&
      ScalarInt(f->ncid, "N_segments_in_file", &f->total_segs) && f->bin_min > 0 &&
      f->nx * f->bin_min == 360 * 60 && f->ny * f->bin_min == 180 * 60 && f->nbins == f->nx * f->ny &&
      nc_inq_varid(f->ncid, "Id_of_first_point_in_a_segment", &f->v_start) == NC_NOERR &&
      nc_inq_varid(f->ncid, "Relative_longitude_from_SW_corner_of_bin", &f->v_dx) == NC_NOERR &&
      nc_inq_varid(f->ncid, "Relative_latitude_from_SW_corner_of_bin", &f->v_dy) == NC_NOERR &&
      (shore ? nc_inq_varid(f->ncid, "Embedded_npts_levels_exit_entry_for_a_segment", &f->v_info) == NC_NOERR
             : nc_inq_varid(f->ncid, "N_points_for_a_segment", &f->v_npts) == NC_NOERR &&
                   nc_inq_varid(f->ncid, "Hierarchial_level_of_a_segment", &f->v_level) == NC_NOERR);
  if (!ok) {
    Fail(error, path, "not a GSHHG binned file (bin size, bin counts or segment variables missing)");
    return nullptr;
  }
  f->first_seg.resize(static_cast<size_t>(f->nbins));
  f->nseg.resize(static_cast<size_t>(f->nbins));
  bool tables = nc_inq_varid(f->ncid, "Id_of_first_segment_in_a_bin", &id) == NC_NOERR &&
                nc_get_var_int(f->ncid, id, f->first_seg.data()) == NC_NOERR &&
                nc_inq_varid(f->ncid, "N_segments_in_a_bin", &id) == NC_NOERR &&
                nc_get_var_short(f->ncid, id, f->nseg.data()) == NC_NOERR;
  if (tables && shore) {
    f->node_levels.resize(static_cast<size_t>(f->nbins));
    tables = nc_inq_varid(f->ncid, "Embedded_node_levels_in_a_bin", &id) == NC_NOERR &&
             nc_get_var_short(f->ncid, id, f->node_levels.data()) == NC_NOERR;
  }
  if (!tables) {
    Fail(error, path, "cannot read the per-bin tables");
    return nullptr;
  }
  BinnedFile *raw = f.get();
  g_files[path] = std::move(f);
  return raw;
}

/** The segments of bin @p b, decoded (cached). */
std::shared_ptr<const std::vector<Seg>> BinSegs(BinnedFile *f, int b, std::string *error) {
  auto it = f->segs.find(b);
  if (it != f->segs.end()) return it->second;
  auto out = std::make_shared<std::vector<Seg>>();
  const int ns = f->nseg[static_cast<size_t>(b)], s0 = f->first_seg[static_cast<size_t>(b)];
  if (ns > 0) {
    if (s0 < 0 || s0 + ns > f->total_segs) {
      Fail(error, f->path, "bin " + std::to_string(b) + ": segment range out of the file");
      return nullptr;
    }
    const size_t start[1] = {static_cast<size_t>(s0)}, count[1] = {static_cast<size_t>(ns)};
    std::vector<int> first(static_cast<size_t>(ns)), info(static_cast<size_t>(ns));
    std::vector<short> npts(static_cast<size_t>(ns)), level(static_cast<size_t>(ns));
    bool ok = nc_get_vara_int(f->ncid, f->v_start, start, count, first.data()) == NC_NOERR;
    if (f->shore)
      ok = ok && nc_get_vara_int(f->ncid, f->v_info, start, count, info.data()) == NC_NOERR;
    else
      ok = ok && nc_get_vara_short(f->ncid, f->v_npts, start, count, npts.data()) == NC_NOERR &&
           nc_get_vara_short(f->ncid, f->v_level, start, count, level.data()) == NC_NOERR;
    if (!ok) {
      Fail(error, f->path, "bin " + std::to_string(b) + ": cannot read its segments");
      return nullptr;
    }
    // The points of a bin's segments are contiguous: one read for the bin.
    int p0 = first[0], p1 = first[0];
    std::vector<int> n(static_cast<size_t>(ns));
    for (int s = 0; s < ns; ++s) {
      const size_t k = static_cast<size_t>(s);
      // Shoreline segments pack points, level, exit and entry side in one integer: bits 9 and up
      // the point count, bits 6-8 the level, 3-5 the entry side, 0-2 the exit side.
      n[k] = f->shore ? (info[k] >> 9) : npts[k];
      p0 = std::min(p0, first[k]);
      p1 = std::max(p1, first[k] + n[k]);
    }
    if (p0 < 0 || p1 > f->total_points || p1 < p0) {
      Fail(error, f->path, "bin " + std::to_string(b) + ": point range out of the file");
      return nullptr;
    }
    std::vector<short> dx(static_cast<size_t>(p1 - p0)), dy(static_cast<size_t>(p1 - p0));
    const size_t ps[1] = {static_cast<size_t>(p0)}, pc[1] = {static_cast<size_t>(p1 - p0)};
    if (p1 > p0 && (nc_get_vara_short(f->ncid, f->v_dx, ps, pc, dx.data()) != NC_NOERR ||
                    nc_get_vara_short(f->ncid, f->v_dy, ps, pc, dy.data()) != NC_NOERR)) {
      Fail(error, f->path, "bin " + std::to_string(b) + ": cannot read its points");
      return nullptr;
    }
    for (int s = 0; s < ns; ++s) {
      const size_t k = static_cast<size_t>(s);
      Seg g;
      if (f->shore) {
        g.level = (info[k] >> 6) & 7;
        g.entry = (info[k] >> 3) & 7;
        g.exit = info[k] & 7;
      } else {
        g.level = level[k];
      }
      if (n[k] < 1) continue;
      g.uv.reserve(2 * static_cast<size_t>(n[k]));
      // Offsets from the bin's south-west corner, unsigned 16 bit: 65535 is the whole bin.
      for (int i = 0; i < n[k]; ++i) {
        const size_t j = static_cast<size_t>(first[k] + i - p0);
        g.uv.push_back(static_cast<unsigned short>(dx[j]) / 65535.0);
        g.uv.push_back(static_cast<unsigned short>(dy[j]) / 65535.0);
      }
      out->push_back(std::move(g));
    }
  }
  f->segs[b] = out;
  return out;
}

/** Position on the bin's perimeter, counter-clockwise from the south-west corner: side s covers
 *  [s, s + 1) (0 south eastwards, 1 east northwards, 2 north westwards, 3 west southwards). */
double PerimeterParam(int side, double u, double v) {
  switch (side) {
  case 0: return std::clamp(u, 0.0, 1.0);
  case 1: return 1.0 + std::clamp(v, 0.0, 1.0);
  case 2: return 2.0 + 1.0 - std::clamp(u, 0.0, 1.0);
  default: return std::fmod(3.0 + 1.0 - std::clamp(v, 0.0, 1.0), 4.0);
  }
}

void PerimeterPoint(double p, double *u, double *v) {
  p = std::fmod(p + 4.0, 4.0);
  const int side = std::min(3, static_cast<int>(p));
  const double f = p - side;
  switch (side) {
  case 0: *u = f, *v = 0.0; break;
  case 1: *u = 1.0, *v = f; break;
  case 2: *u = 1.0 - f, *v = 1.0; break;
  default: *u = 0.0, *v = 1.0 - f; break;
  }
}

/** Corner levels: the format packs the four corners' levels in 3 bits each, south-west in bits
 *  9-11, then south-east, north-east and north-west (counter-clockwise). */
int CornerLevel(short packed, int corner) { return (packed >> (9 - 3 * corner)) & 7; }

/** GSHHG 2.3 puts Antarctica's ice front at level 1 with a flag and its grounding line at level
 *  6 (5 is unused here): the map shows the ice shelves as land, so level 6 segments are dropped
 *  and anything above 4 counts as land. */
int MapLevel(int level) { return level > 4 ? 1 : level; }

/** Close the bin's segments into rings, level by level (docs/map-data.md, "Closing the bins"). */
std::vector<NavMapRing> CloseBin(const std::vector<Seg> &segs, short corners) {
  std::vector<NavMapRing> rings;
  int corner_lv[4];
  for (int k = 0; k < 4; ++k)
    corner_lv[k] = MapLevel(CornerLevel(corners, k));
  for (int level = 1; level <= 4; ++level) {
    std::vector<const Seg *> open;
    for (const Seg &s : segs) {
      if (s.level == 6 || MapLevel(s.level) != level || s.uv.size() < 2) continue;
      if (s.entry == kClosed || s.exit == kClosed) {
        if (s.uv.size() >= 6) rings.push_back({level, s.uv});
      } else {
        open.push_back(&s);
      }
    }
    if (open.empty()) {
      // No boundary of this level crosses the bin: the whole bin is inside an area of this
      // level when its corners are (then all four agree).
      if (*std::max_element(corner_lv, corner_lv + 4) >= level) {
        NavMapRing r;
        r.level = level;
        for (int i = 0; i < 4 * kEdgeSteps; ++i) {
          double u, v;
          PerimeterPoint(static_cast<double>(i) / kEdgeSteps, &u, &v);
          r.lonlat.insert(r.lonlat.end(), {u, v});
        }
        rings.push_back(std::move(r));
      }
      continue;
    }
    // From a segment's exit the boundary follows the bin's edge to the nearest entry of a segment
    // of the same level, and so on until it is back at the first segment. Which way round: the
    // format keeps land on one side of every segment, so areas of land (odd levels) close
    // counter-clockwise and areas of water (lakes, ponds: even levels) clockwise. With that rule
    // every corner passed has a level >= the area's in all four coarser files (tested in
    // test_navview_geomap); the other way round fails at most of them.
    const bool ccw = level % 2 == 1;
    std::vector<double> entry_p(open.size()), exit_p(open.size());
    for (size_t i = 0; i < open.size(); ++i) {
      const auto &uv = open[i]->uv;
      entry_p[i] = PerimeterParam(open[i]->entry, uv[0], uv[1]);
      exit_p[i] = PerimeterParam(open[i]->exit, uv[uv.size() - 2], uv[uv.size() - 1]);
    }
    std::vector<char> used(open.size(), 0);
    for (size_t s0 = 0; s0 < open.size(); ++s0) {
      if (used[s0]) continue;
      NavMapRing r;
      r.level = level;
      size_t cur = s0;
      for (size_t guard = 0; guard <= open.size(); ++guard) {
        used[cur] = 1;
        r.lonlat.insert(r.lonlat.end(), open[cur]->uv.begin(), open[cur]->uv.end());
        const double pe = exit_p[cur];
        size_t best = cur;
        double best_d = INFINITY;
        for (size_t j = 0; j < open.size(); ++j) {
          double d = ccw ? std::fmod(entry_p[j] - pe + 8.0, 4.0) : std::fmod(pe - entry_p[j] + 8.0, 4.0);
          if (j == cur && d < 1e-12) {
            // A segment leaving where it entered (an island touching the edge at one point) is a
            // loop of its own when it turns the closing way round; else its area is the rest of
            // the bin and the walk goes once round.
            double area2 = 0.0;
            const auto &uv = open[cur]->uv;
            for (size_t a = 0, b = uv.size() / 2 - 1; a < uv.size() / 2; b = a++)
              area2 += uv[2 * b] * uv[2 * a + 1] - uv[2 * a] * uv[2 * b + 1];
            d = (area2 == 0.0 || (area2 > 0.0) == ccw) ? 0.0 : 4.0;
          }
          if (d < best_d) {
            best_d = d;
            best = j;
          }
        }
        // The perimeter between: every densification step passed (corners among them).
        if (ccw) {
          for (double q = std::floor(pe * kEdgeSteps + 1e-9) + 1.0; q / kEdgeSteps < pe + best_d - 1e-9; q += 1.0) {
            double u, v;
            PerimeterPoint(q / kEdgeSteps, &u, &v);
            r.lonlat.insert(r.lonlat.end(), {u, v});
          }
        } else {
          for (double q = std::ceil(pe * kEdgeSteps - 1e-9) - 1.0; q / kEdgeSteps > pe - best_d + 1e-9; q -= 1.0) {
            double u, v;
            PerimeterPoint(q / kEdgeSteps, &u, &v);
            r.lonlat.insert(r.lonlat.end(), {u, v});
          }
        }
        if (best == s0 || used[best]) break;
        cur = best;
      }
      if (r.lonlat.size() >= 6) rings.push_back(std::move(r));
    }
  }
  return rings;
}

/** Even-odd scanline fill of one ring (display pixels, origin bottom left) into an RGB image:
 *  a pixel is painted when its centre is inside. Rings sharing an edge (neighbouring bins) paint
 *  each pixel once. */
void FillRing(std::vector<unsigned char> *img, int w, int h, const std::vector<double> &xy, const unsigned char rgb[3],
              std::vector<std::pair<int, float>> *scratch) {
  const size_t n = xy.size() / 2;
  if (n < 3) return;
  double ymin = INFINITY, ymax = -INFINITY, xmin = INFINITY, xmax = -INFINITY;
  for (size_t i = 0; i < n; ++i) {
    xmin = std::min(xmin, xy[2 * i]);
    xmax = std::max(xmax, xy[2 * i]);
    ymin = std::min(ymin, xy[2 * i + 1]);
    ymax = std::max(ymax, xy[2 * i + 1]);
  }
  if (xmax < 0 || ymax < 0 || xmin > w || ymin > h) return;
  auto &cross = *scratch;
  cross.clear();
  for (size_t i = 0; i < n; ++i) {
    const double x0 = xy[2 * i], y0 = xy[2 * i + 1];
    const double x1 = xy[2 * ((i + 1) % n)], y1 = xy[2 * ((i + 1) % n) + 1];
    if (y0 == y1) continue;
    const double ylo = std::min(y0, y1), yhi = std::max(y0, y1);
    // Rows whose centre j + 0.5 lies in [ylo, yhi).
    const int j0 = std::max(0, static_cast<int>(std::ceil(ylo - 0.5))), j1 = std::min(h - 1, static_cast<int>(std::ceil(yhi - 0.5)) - 1);
    for (int j = j0; j <= j1; ++j) {
      const double yc = j + 0.5;
      cross.push_back({j, static_cast<float>(x0 + (yc - y0) * (x1 - x0) / (y1 - y0))});
    }
  }
  std::sort(cross.begin(), cross.end());
  for (size_t k = 0; k + 1 < cross.size(); k += 2) {
    if (cross[k].first != cross[k + 1].first) { // an odd count on a row (degenerate): resync
      --k;
      continue;
    }
    const int j = cross[k].first;
    const int i0 = std::max(0, static_cast<int>(std::ceil(cross[k].second - 0.5)));
    const int i1 = std::min(w - 1, static_cast<int>(std::ceil(cross[k + 1].second - 0.5)) - 1);
    unsigned char *row = img->data() + 3 * static_cast<size_t>(j) * static_cast<size_t>(w);
    for (int i = i0; i <= i1; ++i) {
      row[3 * i] = rgb[0];
      row[3 * i + 1] = rgb[1];
      row[3 * i + 2] = rgb[2];
    }
  }
}

} // namespace

void NavMapPaintAreas(const NavMapLayers &layers, const NavMapToPixel &to_pixel, int w, int h,
                      std::vector<unsigned char> *rgb) {
  rgb->resize(3 * static_cast<size_t>(w) * static_cast<size_t>(h));
  for (size_t i = 0; i < rgb->size(); i += 3)
    std::memcpy(&(*rgb)[i], kNavMapWaterRgb, 3);
  std::vector<double> xy;
  std::vector<std::pair<int, float>> scratch;
  for (const NavMapRing &r : layers.rings) {
    xy.resize(r.lonlat.size());
    bool ok = true;
    for (size_t i = 0; ok && i + 1 < r.lonlat.size(); i += 2)
      ok = to_pixel(r.lonlat[i + 1], r.lonlat[i], &xy[i], &xy[i + 1]);
    if (ok) FillRing(rgb, w, h, xy, r.level % 2 ? kNavMapLandRgb : kNavMapWaterRgb, &scratch);
  }
}

char NavShoreResLetter(NavShoreRes r) {
  static const char letters[] = {'c', 'l', 'i', 'h', 'f'};
  return letters[static_cast<int>(r)];
}

NavShoreRes NavShoreResForScale(double m_per_px) {
  // GSHHG's nominal point spacings: full ~ 40 m, high 200 m, intermediate 1 km, low 5 km,
  // crude 25 km; each is drawn while its spacing is at most about two pixels... with the next
  // finer level taking over below that.
  if (m_per_px < 100.0) return NavShoreRes::Full;
  if (m_per_px < 500.0) return NavShoreRes::High;
  if (m_per_px < 2500.0) return NavShoreRes::Intermediate;
  if (m_per_px < 12500.0) return NavShoreRes::Low;
  return NavShoreRes::Crude;
}

std::string NavMapGshhgDir() {
  const char *e = std::getenv("NAVVIEW_GSHHG_DIR");
  return e && *e ? std::string(e) : std::string("/usr/share/gmt-gshhg");
}

bool NavMapLoadLayers(const std::string &dir, NavShoreRes res, double lat0, double lat1, double lon0, double lon1,
                      NavMapLayers *out, std::string *error) {
  std::lock_guard<std::mutex> lock(g_mutex);
  const char L = NavShoreResLetter(res);
  out->res = res;
  out->bins = 0;
  BinnedFile *shore = OpenBinned(dir + "/binned_GSHHS_" + L + ".nc", true, error);
  if (!shore) return false;
  std::string ignored;
  BinnedFile *river = OpenBinned(dir + "/binned_river_" + L + ".nc", false, &ignored);
  BinnedFile *border = OpenBinned(dir + "/binned_border_" + L + ".nc", false, &ignored);
  const double bs = shore->bin_min / 60.0;
  lat0 = std::max(-90.0, lat0);
  lat1 = std::min(90.0, lat1);
  // Rows count from the north: row 0 is [90 - bs, 90].
  const int row0 = std::clamp(static_cast<int>(std::floor((90.0 - lat1) / bs)), 0, shore->ny - 1);
  const int row1 = std::clamp(static_cast<int>(std::floor((90.0 - lat0) / bs)), 0, shore->ny - 1);
  const bool all_lon = lon1 - lon0 >= 360.0 - 1e-9;
  const int c0 = all_lon ? 0 : static_cast<int>(std::floor(lon0 / bs));
  const int c1 = all_lon ? shore->nx - 1 : static_cast<int>(std::floor(lon1 / bs));
  for (int row = row0; row <= row1; ++row)
    for (int cc = c0; cc <= c1 && cc - c0 < shore->nx; ++cc) {
      const int col = ((cc % shore->nx) + shore->nx) % shore->nx;
      const int b = row * shore->nx + col;
      const double lat_sw = 90.0 - (row + 1) * bs, lon_sw = cc * bs; // cc keeps the caller's side
      ++out->bins;
      auto it = shore->rings.find(b);
      std::shared_ptr<const std::vector<NavMapRing>> rings;
      if (it != shore->rings.end()) {
        rings = it->second;
      } else {
        auto segs = BinSegs(shore, b, error);
        if (!segs) return false;
        rings = std::make_shared<const std::vector<NavMapRing>>(CloseBin(*segs, shore->node_levels[static_cast<size_t>(b)]));
        shore->rings[b] = rings;
      }
      {
        auto segs = BinSegs(shore, b, error);
        if (!segs) return false;
        for (const Seg &sg : *segs) {
          if (sg.level == 6 || sg.uv.size() < 4) continue;
          NavMapLine l;
          l.level = MapLevel(sg.level);
          l.lonlat.resize(sg.uv.size() + (sg.entry == kClosed ? 2 : 0));
          for (size_t i = 0; i + 1 < sg.uv.size(); i += 2) {
            l.lonlat[i] = lon_sw + bs * sg.uv[i];
            l.lonlat[i + 1] = lat_sw + bs * sg.uv[i + 1];
          }
          if (sg.entry == kClosed) { // close the ring's outline
            l.lonlat[sg.uv.size()] = l.lonlat[0];
            l.lonlat[sg.uv.size() + 1] = l.lonlat[1];
          }
          out->shores.push_back(std::move(l));
        }
      }
      for (const NavMapRing &r : *rings) {
        NavMapRing g;
        g.level = r.level;
        g.lonlat.resize(r.lonlat.size());
        for (size_t i = 0; i + 1 < r.lonlat.size(); i += 2) {
          g.lonlat[i] = lon_sw + bs * r.lonlat[i];
          g.lonlat[i + 1] = lat_sw + bs * r.lonlat[i + 1];
        }
        out->rings.push_back(std::move(g));
      }
      for (BinnedFile *lf : {river, border}) {
        if (!lf || lf->bin_min != shore->bin_min) continue;
        auto segs = BinSegs(lf, b, error);
        if (!segs) return false;
        for (const Seg &s : *segs) {
          NavMapLine l;
          l.level = s.level;
          l.lonlat.resize(s.uv.size());
          for (size_t i = 0; i + 1 < s.uv.size(); i += 2) {
            l.lonlat[i] = lon_sw + bs * s.uv[i];
            l.lonlat[i + 1] = lat_sw + bs * s.uv[i + 1];
          }
          (lf == river ? out->rivers : out->borders).push_back(std::move(l));
        }
      }
    }
  return true;
}

std::string NavMapPlacesFile() {
  const char *e = std::getenv("NAVVIEW_PLACES");
  if (e && *e) return e;
  char share[4096];
  if (!nav_paths_share_dir(share, sizeof share)) return std::string();
  const std::string path = std::string(share) + "/places.tsv";
  return Exists(path) ? path : std::string();
}

bool NavMapLoadPlaces(const std::string &path, const std::vector<NavPlace> **places, std::string *error) {
  static std::map<std::string, std::unique_ptr<std::vector<NavPlace>>> cache;
  std::lock_guard<std::mutex> lock(g_mutex);
  auto it = cache.find(path);
  if (it != cache.end()) {
    *places = it->second.get();
    return true;
  }
  std::ifstream in(path);
  if (!in) return Fail(error, path, "cannot open the gazetteer");
  auto v = std::make_unique<std::vector<NavPlace>>();
  std::string line;
  for (long ln = 1; std::getline(in, line); ++ln) {
    if (line.empty() || line[0] == '#') continue;
    std::vector<std::string> f;
    size_t p = 0;
    for (;;) {
      const size_t q = line.find('\t', p);
      f.push_back(line.substr(p, q == std::string::npos ? std::string::npos : q - p));
      if (q == std::string::npos) break;
      p = q + 1;
    }
    const std::string where = path + ":" + std::to_string(ln);
    if (f.size() < 5) return Fail(error, where, "expected 6 tab-separated fields (name, lat, lon, population, code, country)");
    NavPlace pl;
    pl.name = f[0];
    char *end = nullptr;
    pl.lat_deg = std::strtod(f[1].c_str(), &end);
    if (f[1].empty() || *end || !(std::fabs(pl.lat_deg) <= 90.0))
      return Fail(error, where, "field 'lat_deg': not a latitude: '" + f[1] + "'");
    pl.lon_deg = std::strtod(f[2].c_str(), &end);
    if (f[2].empty() || *end || !(std::fabs(pl.lon_deg) <= 360.0))
      return Fail(error, where, "field 'lon_deg': not a longitude: '" + f[2] + "'");
    pl.population = std::strtol(f[3].c_str(), &end, 10);
    if (f[3].empty() || *end || pl.population < 0)
      return Fail(error, where, "field 'population': not a count: '" + f[3] + "'");
    pl.capital = f[4] == "PPLC";
    // Sections of a city (PPLX: "Chinatown", "Mission District") and historical, abandoned or
    // destroyed places are not labelled: the map names towns.
    if (f[4] == "PPLX" || f[4] == "PPLH" || f[4] == "PPLQ" || f[4] == "PPLW") continue;
    v->push_back(std::move(pl));
  }
  std::stable_sort(v->begin(), v->end(), [](const NavPlace &a, const NavPlace &b) { return a.population > b.population; });
  *places = v.get();
  cache[path] = std::move(v);
  return true;
}

std::vector<NavMapPlaceLabel> NavMapChoosePlaces(const std::vector<NavPlace> &places,
                                                 const std::function<bool(double lat_deg, double lon_deg)> &may_show,
                                                 const NavMapToPixel &to_pixel, int w, int h, int font_pt,
                                                 const NavMapTextSize &text_size,
                                                 std::vector<std::array<double, 4>> taken) {
  std::vector<NavMapPlaceLabel> out;
  const size_t max_labels = std::clamp<size_t>(static_cast<size_t>(w) * static_cast<size_t>(h) / 30000, 3, 40);
  auto hits = [](const std::array<double, 4> &a, const std::array<double, 4> &b) {
    return a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3];
  };
  std::vector<std::array<double, 4>> dot_boxes;
  size_t looked = 0;
  for (const NavPlace &p : places) {
    if (out.size() >= max_labels || looked > 20000) break;
    if (may_show && !may_show(p.lat_deg, p.lon_deg)) continue;
    double px, py;
    if (!to_pixel(p.lat_deg, p.lon_deg, &px, &py)) continue;
    if (px < 4 || py < 4 || px > w - 4 || py > h - 4) continue;
    ++looked;
    const int size = p.population >= 1000000 ? font_pt : p.population >= 100000 ? font_pt - 1 : font_pt - 2;
    const bool bold = p.capital || p.population >= 1000000;
    const std::array<double, 4> dot{px - 3, py - 3, px + 3, py + 3};
    bool dot_free = true;
    for (const auto &o : taken)
      dot_free = dot_free && !hits(o, dot);
    if (!dot_free) continue;
    double tw, th;
    text_size(p.name, size, bold, &tw, &th);
    const std::array<double, 4> cand[4] = {{px + 5, py - 0.5 * th, px + 5 + tw, py + 0.5 * th},
                                           {px - 5 - tw, py - 0.5 * th, px - 5, py + 0.5 * th},
                                           {px - 0.5 * tw, py + 4, px + 0.5 * tw, py + 4 + th},
                                           {px - 0.5 * tw, py - 4 - th, px + 0.5 * tw, py - 4}};
    for (const auto &b : cand) {
      if (b[0] < 2 || b[1] < 2 || b[2] > w - 2 || b[3] > h - 2) continue;
      const std::array<double, 4> pad{b[0] - 3, b[1] - 2, b[2] + 3, b[3] + 2};
      bool clash = false;
      for (const auto &o : taken)
        clash = clash || hits(o, pad);
      for (const auto &o : dot_boxes)
        clash = clash || hits(o, pad);
      if (clash) continue;
      NavMapPlaceLabel l;
      l.place = &p;
      l.dot_x = px;
      l.dot_y = py;
      l.x0 = b[0];
      l.y0 = b[1];
      l.x1 = b[2];
      l.y1 = b[3];
      l.size_pt = size;
      l.bold = bold;
      out.push_back(l);
      taken.push_back(b);
      dot_boxes.push_back(dot);
      break;
    }
  }
  return out;
}
