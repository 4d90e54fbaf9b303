// Geodetic map view (nav_view_map.h): tracks in latitude/longitude over an offline background,
// graticule or local metric grid, scale bar; rendered offscreen to PNG.
#include "navview/nav_view_map.h"

#include "map_interactive_internal.h"

#include "navview_internal.h"
#include "navcore/nav_paths.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sys/stat.h>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkPointData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>
#include <vtkPlaneSource.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTexture.h>

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kD2R = kPi / 180.0;
constexpr double kR = 6371008.8; // mean Earth radius [m]: map scale only

bool Exists(const std::string &p) {
  struct stat st;
  return stat(p.c_str(), &st) == 0;
}

uint32_t Be32(const unsigned char *p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) | uint32_t(p[3]);
}
int32_t Le32(const unsigned char *p) {
  return static_cast<int32_t>(uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24));
}
double LeF64(const unsigned char *p) {
  uint64_t u = 0;
  for (int i = 7; i >= 0; --i)
    u = (u << 8) | p[i];
  double d;
  std::memcpy(&d, &u, sizeof d);
  return d;
}

// Azimuthal equidistant about the view centre: distances and directions from the centre are
// true, so a small area is the local tangent plane (metres east/north), and a view over a pole
// or across the date line has no seam. Points more than kMaxC from the centre are "off".
constexpr double kMaxC = 100.0 * kD2R;

struct Projection {
  double lat0, lon0, sin0, cos0;
  void Init(double lat, double lon) {
    lat0 = lat;
    lon0 = lon;
    sin0 = std::sin(lat);
    cos0 = std::cos(lat);
  }
  /** @return false when the point is more than kMaxC from the centre. */
  bool Fwd(double lat, double lon, double *x, double *y) const {
    const double sl = std::sin(lat), cl = std::cos(lat), dl = lon - lon0;
    const double cdl = std::cos(dl), sdl = std::sin(dl);
    const double cc = std::clamp(sin0 * sl + cos0 * cl * cdl, -1.0, 1.0);
    const double c = std::acos(cc);
    const double k = c < 1e-9 ? 1.0 : c / std::sin(c);
    *x = kR * k * cl * sdl;
    *y = kR * k * (cos0 * sl - sin0 * cl * cdl);
    return c <= kMaxC;
  }
};

// Mean direction of the points (lat, lon pairs, stride 3) as lat/lon: a centre without seams.
void MeanDirection(const std::vector<const std::vector<double> *> &sets, double *lat, double *lon) {
  double sx = 0, sy = 0, sz = 0;
  for (const auto *g : sets)
    for (size_t i = 0; i + 2 < g->size(); i += 3) {
      const double la = (*g)[i], lo = (*g)[i + 1];
      sx += std::cos(la) * std::cos(lo);
      sy += std::cos(la) * std::sin(lo);
      sz += std::sin(la);
    }
  *lat = std::atan2(sz, std::hypot(sx, sy));
  *lon = std::atan2(sy, sx);
}

// Split a projected polyline where points are off or where it jumps by more than @p jump.
// Points closer than @p min_step to the last kept one are dropped: llvmpipe draws nothing for
// many sub-pixel segments in a row (a gap in a straight graticule line at 20 km across).
void AddProjected(const Projection &pr, const std::vector<double> &lonlat_deg, double jump,
                  std::vector<std::vector<double>> *out, double min_step = 0.0) {
  std::vector<double> cur;
  double px = 0, py = 0;
  bool have_pending = false;
  for (size_t i = 0; i + 1 < lonlat_deg.size(); i += 2) {
    double x, y;
    const bool on = pr.Fwd(lonlat_deg[i + 1] * kD2R, lonlat_deg[i] * kD2R, &x, &y);
    if (!on || (!cur.empty() && std::hypot(x - cur[cur.size() - 2], y - cur.back()) > jump)) {
      if (have_pending) cur.insert(cur.end(), {px, py});
      have_pending = false;
      if (cur.size() >= 4) out->push_back(cur);
      cur.clear();
      if (!on) continue;
    }
    if (!cur.empty() && std::hypot(x - cur[cur.size() - 2], y - cur.back()) < min_step) {
      px = x; // keep the last point of a run of short steps for the end of the line
      py = y;
      have_pending = true;
      continue;
    }
    have_pending = false;
    cur.push_back(x);
    cur.push_back(y);
  }
  if (have_pending) cur.insert(cur.end(), {px, py});
  if (cur.size() >= 4) out->push_back(cur);
}

vtkSmartPointer<vtkActor> Lines(const std::vector<std::vector<double>> &polylines, const double rgb[3], float width,
                                double z, double opacity = 1.0) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> cells;
  for (const auto &pl : polylines) {
    const vtkIdType n = static_cast<vtkIdType>(pl.size() / 2);
    if (n < 2) continue;
    cells->InsertNextCell(n);
    for (vtkIdType i = 0; i < n; ++i)
      cells->InsertCellPoint(pts->InsertNextPoint(pl[2 * i], pl[2 * i + 1], z));
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(cells);
  vtkNew<vtkPolyDataMapper> m;
  m->SetInputData(pd);
  m->ScalarVisibilityOff();
  auto a = vtkSmartPointer<vtkActor>::New();
  a->SetMapper(m);
  a->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
  a->GetProperty()->SetLineWidth(width);
  a->GetProperty()->SetOpacity(opacity);
  a->GetProperty()->LightingOff();
  return a;
}

vtkSmartPointer<vtkTextActor> Text(const std::string &s, int size, const double rgb[3]) {
  auto t = vtkSmartPointer<vtkTextActor>::New();
  t->SetInput(s.c_str());
  vtkTextProperty *tp = t->GetTextProperty();
  NavApplyFont(tp);
  tp->SetFontSize(size);
  tp->SetColor(rgb[0], rgb[1], rgb[2]);
  tp->SetShadow(false);
  return t;
}

double NiceLength(double raw) {
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / p;
  return (m < 1.5 ? 1.0 : (m < 3.5 ? 2.0 : (m < 7.5 ? 5.0 : 10.0))) * p;
}

std::string FormatDeg(double v, bool lat, double step) {
  char buf[64];
  const char hemi = lat ? (v >= 0 ? 'N' : 'S') : (v >= 0 ? 'E' : 'W');
  const double a = std::fabs(v);
  int dec = 0;
  while (dec < 6 && std::fabs(step * std::pow(10.0, dec) - std::round(step * std::pow(10.0, dec))) > 1e-6)
    ++dec;
  std::snprintf(buf, sizeof buf, "%.*f\u00b0%c", dec, a, hemi);
  return buf;
}

} // namespace

double NavGraticuleStepDeg(double span_deg) {
  static const double steps[] = {30, 15, 10, 5, 2, 1, 0.5, 0.2, 0.1, 0.05, 0.02, 0.01, 0.005, 0.002, 0.001,
                                 0.0005, 0.0002, 0.0001};
  for (double s : steps)
    if (span_deg / s >= 3.0) return s;
  return 0.0001;
}

bool NavReadShapefile(const std::string &path, std::vector<std::vector<double>> *parts, std::string *error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = path + ": error: cannot open";
    return false;
  }
  std::vector<unsigned char> buf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (buf.size() < 100 || Be32(buf.data()) != 9994u) {
    *error = path + ": error: not an ESRI shapefile (file code 9994 expected)";
    return false;
  }
  size_t off = 100;
  while (off + 8 <= buf.size()) {
    const size_t len = static_cast<size_t>(Be32(&buf[off + 4])) * 2; // 16-bit words
    const size_t c = off + 8;
    if (c + len > buf.size() || len < 4) {
      *error = path + ": error: truncated record at byte " + std::to_string(off);
      return false;
    }
    const int type = Le32(&buf[c]);
    if ((type == 3 || type == 5) && len >= 44) { // PolyLine, Polygon
      const int np = Le32(&buf[c + 36]), npt = Le32(&buf[c + 40]);
      const size_t need = 44 + 4 * static_cast<size_t>(std::max(np, 0)) + 16 * static_cast<size_t>(std::max(npt, 0));
      if (np < 0 || npt < 0 || need > len) {
        *error = path + ": error: bad polygon record at byte " + std::to_string(off);
        return false;
      }
      const size_t pts = c + 44 + 4 * static_cast<size_t>(np);
      for (int p = 0; p < np; ++p) {
        const int i0 = Le32(&buf[c + 44 + 4 * static_cast<size_t>(p)]);
        const int i1 = p + 1 < np ? Le32(&buf[c + 44 + 4 * static_cast<size_t>(p + 1)]) : npt;
        if (i0 < 0 || i1 > npt || i1 < i0) continue;
        std::vector<double> pl;
        pl.reserve(2 * static_cast<size_t>(i1 - i0));
        for (int i = i0; i < i1; ++i) {
          pl.push_back(LeF64(&buf[pts + 16 * static_cast<size_t>(i)]));
          pl.push_back(LeF64(&buf[pts + 16 * static_cast<size_t>(i) + 8]));
        }
        parts->push_back(std::move(pl));
      }
    }
    off = c + len;
  }
  return true;
}

bool NavBuildMap(const NavResult &result, const NavMapOptions &opt, vtkRenderer *ren, NavMapExtent *extent,
                 std::string *error) {
  const NavTrack &ref = result.truth;
  if (!ref.HasGeodetic() || ref.Size() == 0) {
    *error = (result.dir.empty() ? std::string("result") : result.dir) +
             ": error: truth.csv has no lat_deg/lon_deg/h_m columns: no map view";
    return false;
  }
  if (opt.width_px < 64 || opt.height_px < 64 || opt.width_px > 8192 || opt.height_px > 8192) {
    *error = "map size out of range (64..8192 pixels)";
    return false;
  }

  // Centre: the mean direction of the tracks (no seam at the date line or the poles); extent:
  // the tracks projected about it.
  Projection pr;
  {
    double la, lo;
    MeanDirection({&ref.geo, &result.nav.geo, &result.gnss.geo}, &la, &lo);
    pr.Init(std::isfinite(opt.center_lat_deg) ? opt.center_lat_deg * kD2R : la,
            std::isfinite(opt.center_lon_deg) ? opt.center_lon_deg * kD2R : lo);
  }
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (const auto *g : {&ref.geo, &result.nav.geo, &result.gnss.geo})
    for (size_t i = 0; i + 2 < g->size(); i += 3) {
      double x, y;
      pr.Fwd((*g)[i], (*g)[i + 1], &x, &y);
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  const double aspect = static_cast<double>(opt.width_px) / opt.height_px;
  // Fit about the centre (the view is centred on it), symmetric extents.
  const double half_w = std::max(std::fabs(x0), std::fabs(x1)), half_h = std::max(std::fabs(y0), std::fabs(y1));
  double span_x = opt.span_km > 0.0 ? opt.span_km * 1e3 : std::max(200.0, 2.3 * std::max(half_w, half_h * aspect));
  span_x = std::min(span_x, 2.0 * kMaxC * kR);
  const double span_y = span_x / aspect;
  // Angular radius of the view (half diagonal) and the lat/lon range it covers.
  const double view_c = std::min(0.5 * std::hypot(span_x, span_y) / kR, kMaxC);
  const double lat_lo = std::max(-0.5 * kPi, pr.lat0 - view_c), lat_hi = std::min(0.5 * kPi, pr.lat0 + view_c);
  const bool pole = lat_hi >= 0.5 * kPi - 1e-9 || lat_lo <= -0.5 * kPi + 1e-9;
  const double dlon = pole ? kPi : std::min(kPi, std::asin(std::min(1.0, std::sin(view_c) / std::max(std::cos(pr.lat0 + (pr.lat0 > 0 ? view_c : -view_c)), 1e-6))));
  const double lon_lo = pr.lon0 - dlon, lon_hi = pr.lon0 + dlon;
  const double span_deg_y = (lat_hi - lat_lo) / kD2R, span_deg_x = 2.0 * dlon / kD2R;

  const bool street = span_x < 20e3;
  ren->SetBackground(street ? 0.97 : 0.86, street ? 0.97 : 0.91, street ? 0.95 : 0.96); // sea tint when zoomed out
  std::vector<std::string> notes;

  char data_dir[4096];
  const std::string data = !opt.data_dir.empty() ? opt.data_dir
                           : nav_paths_map_data_dir(data_dir, sizeof data_dir) ? std::string(data_dir)
                                                                              : std::string();
  // Shaded relief (0.5 deg per pixel): useful from a few hundred km across.
  const std::string relief = data + "/raster/natural_earth/50-natural-earth-1-downsampled.png";
  if (span_x > 250e3) {
    if (Exists(relief)) {
      vtkNew<vtkPNGReader> rd;
      rd->SetFileName(relief.c_str());
      vtkNew<vtkTexture> tex;
      tex->SetInputConnection(rd->GetOutputPort());
      tex->InterpolateOn();
      // The raster is plate carree (-180..180, -90..90): a lon/lat mesh carries its texture
      // coordinates through the projection. Cells of about a degree over the visible range.
      const double cell = std::max(0.25, std::min(2.0, span_deg_y / 60.0)) * kD2R;
      const int nlat = std::max(2, static_cast<int>(std::ceil((lat_hi - lat_lo) / cell)));
      const int nlon = std::max(2, static_cast<int>(std::ceil((lon_hi - lon_lo) / cell)));
      vtkNew<vtkPoints> mp;
      vtkNew<vtkFloatArray> tc;
      tc->SetNumberOfComponents(2);
      tc->SetName("tcoords");
      std::vector<char> on(static_cast<size_t>((nlat + 1) * (nlon + 1)));
      for (int i = 0; i <= nlat; ++i)
        for (int j = 0; j <= nlon; ++j) {
          const double la = lat_lo + (lat_hi - lat_lo) * i / nlat, lo = lon_lo + (lon_hi - lon_lo) * j / nlon;
          double x, y;
          on[static_cast<size_t>(i * (nlon + 1) + j)] = pr.Fwd(la, lo, &x, &y) ? 1 : 0;
          mp->InsertNextPoint(x, y, -2.0);
          double u = (lo / kD2R + 180.0) / 360.0;
          u -= std::floor(u);
          if (j > 0 && u < 1e-9) u = 1.0; // the cell ending at the date line
          tc->InsertNextTuple2(u, (la / kD2R + 90.0) / 180.0);
        }
      vtkNew<vtkCellArray> quads;
      for (int i = 0; i < nlat; ++i)
        for (int j = 0; j < nlon; ++j) {
          const vtkIdType a0 = i * (nlon + 1) + j, a1 = a0 + 1, a2 = a0 + nlon + 2, a3 = a0 + nlon + 1;
          if (!on[static_cast<size_t>(a0)] || !on[static_cast<size_t>(a1)] || !on[static_cast<size_t>(a2)] ||
              !on[static_cast<size_t>(a3)])
            continue;
          // A cell whose texture wraps (crosses the date line between its corners) is skipped.
          double ua[2], ub[2];
          tc->GetTuple(a0, ua);
          tc->GetTuple(a1, ub);
          if (ub[0] < ua[0]) continue;
          const vtkIdType ids[4] = {a0, a1, a2, a3};
          quads->InsertNextCell(4, ids);
        }
      vtkNew<vtkPolyData> mesh;
      mesh->SetPoints(mp);
      mesh->SetPolys(quads);
      mesh->GetPointData()->SetTCoords(tc);
      vtkNew<vtkPolyDataMapper> m;
      m->SetInputData(mesh);
      vtkNew<vtkActor> a;
      a->SetMapper(m);
      a->SetTexture(tex);
      a->GetProperty()->LightingOff();
      a->GetProperty()->SetOpacity(0.9);
      ren->AddActor(a);
    } else {
      notes.push_back("no relief raster (" + relief + ")");
    }
  }
  // Coastlines (GSHHS crude, about 25 km): down to regional scale; they thin out below.
  const std::string coast = data + "/shapefiles/gshhs/c/GSHHS_c_L1.shp";
  const std::string lakes = data + "/shapefiles/gshhs/l/GSHHS_l_L2.shp";
  if (span_x > 15e3) {
    for (const std::string &f : {coast, lakes}) {
      std::vector<std::vector<double>> parts;
      std::string e2;
      if (!Exists(f) || !NavReadShapefile(f, &parts, &e2)) {
        notes.push_back("no coastline data (" + f + ")");
        continue;
      }
      std::vector<std::vector<double>> split;
      for (const auto &pl : parts)
        AddProjected(pr, pl, 0.25 * kPi * kR, &split, 1.5 * span_x / opt.width_px);
      const double c[3] = {0.30, 0.36, 0.45};
      ren->AddActor(Lines(split, c, f == coast ? 1.3f : 0.8f, -1.0));
    }
  }

  const int font = std::max(10, static_cast<int>(std::lround(opt.height_px / 48.0)));
  const double tc[3] = {0.05, 0.05, 0.08}, gc[3] = {0.45, 0.47, 0.52};
  // Graticule, or a local metric grid at street scale.
  std::vector<std::vector<double>> grid;
  std::vector<std::pair<std::string, double>> xlabels, ylabels; // text, position in m
  if (!street) {
    const double lat_step = NavGraticuleStepDeg(std::max(span_deg_y * 0.8, 1e-4));
    const double lon_step = pole ? 30.0 : NavGraticuleStepDeg(std::max(span_deg_x * 0.8, 1e-4));
    const double lat_a = lat_lo / kD2R, lat_b = lat_hi / kD2R, lon_a = lon_lo / kD2R, lon_b = lon_hi / kD2R;
    // Label position: the point of each line nearest the right (latitudes) or top (longitudes)
    // edge inside the view.
    auto label_at = [&](const std::vector<std::vector<double>> &lines, bool right, double *pos) {
      double best = -INFINITY;
      for (const auto &pl : lines)
        for (size_t i = 0; i + 1 < pl.size(); i += 2) {
          const double x = pl[i], y = pl[i + 1];
          if (std::fabs(x) > 0.5 * span_x || std::fabs(y) > 0.5 * span_y) continue;
          const double key = right ? x : y;
          if (key > best) {
            best = key;
            *pos = right ? y : x;
          }
        }
      // Only lines that reach the edge get a label there (not those ending at a pole inside).
      return std::isfinite(best) && best > (right ? 0.3 * span_x : 0.3 * span_y);
    };
    for (double la = std::ceil(lat_a / lat_step) * lat_step; la <= lat_b + 1e-9; la += lat_step) {
      if (std::fabs(la) > 89.999) continue;
      std::vector<double> ll;
      for (int i = 0; i <= 720; ++i)
        ll.insert(ll.end(), {lon_a + (lon_b - lon_a) * i / 720.0, la});
      std::vector<std::vector<double>> lines;
      AddProjected(pr, ll, 0.25 * kPi * kR, &lines, 1.5 * span_x / opt.width_px);
      double pos = 0.0;
      if (label_at(lines, true, &pos)) ylabels.push_back({FormatDeg(la, true, lat_step), pos});
      grid.insert(grid.end(), lines.begin(), lines.end());
    }
    for (double lo = std::ceil(lon_a / lon_step) * lon_step; lo < lon_b - 1e-9 || (!pole && lo <= lon_b + 1e-9);
         lo += lon_step) {
      std::vector<double> ll;
      for (int i = 0; i <= 720; ++i)
        ll.insert(ll.end(), {lo, std::clamp(lat_a + (lat_b - lat_a) * i / 720.0, -90.0, 90.0)});
      std::vector<std::vector<double>> lines;
      AddProjected(pr, ll, 0.25 * kPi * kR, &lines, 1.5 * span_x / opt.width_px);
      double wl = lo;
      while (wl > 180)
        wl -= 360;
      while (wl <= -180)
        wl += 360;
      double pos = 0.0;
      if (label_at(lines, false, &pos)) xlabels.push_back({FormatDeg(wl, false, lon_step), pos});
      grid.insert(grid.end(), lines.begin(), lines.end());
    }
  } else {
    const double s = NiceLength(span_x / 6.0);
    for (double x = std::ceil(-span_x / s) * s; x <= span_x; x += s)
      grid.push_back({x, -span_y, x, span_y});
    for (double y = std::ceil(-span_y / s) * s; y <= span_y; y += s)
      grid.push_back({-span_x, y, span_x, y});
    char buf[64];
    for (double x = std::ceil(-0.5 * span_x / s) * s; x <= 0.5 * span_x; x += s) {
      std::snprintf(buf, sizeof buf, "%+g m E", x);
      xlabels.push_back({buf, x});
    }
    for (double y = std::ceil(-0.5 * span_y / s) * s; y <= 0.5 * span_y; y += s) {
      std::snprintf(buf, sizeof buf, "%+g m N", y);
      ylabels.push_back({buf, y});
    }
  }
  ren->AddActor(Lines(grid, gc, 1.0f, -0.5, 0.55));

  // Tracks.
  // Tracks thinned to about half a pixel between vertices: with multisampling, llvmpipe drew
  // almost nothing of 18 000 sub-pixel segments (the ship scene at 20 km across).
  const double track_step = 0.5 * span_x / opt.width_px;
  auto track_lines = [&](const NavTrack &t) {
    std::vector<double> ll;
    ll.reserve(2 * t.Size());
    for (size_t i = 0; i < t.Size(); ++i)
      ll.insert(ll.end(), {t.geo[3 * i + 1] / kD2R, t.geo[3 * i] / kD2R});
    std::vector<std::vector<double>> out;
    AddProjected(pr, ll, 0.25 * kPi * kR, &out, track_step);
    return out;
  };
  const double c_ref[3] = {0.08, 0.08, 0.10}, c_est[3] = {0.84, 0.10, 0.11}, c_gnss[3] = {0.10, 0.62, 0.20},
               c_out[3] = {0.96, 0.50, 0.80};
  // Outages: the reference inside each outage interval, wide and pink, under the tracks.
  std::vector<std::vector<double>> outs;
  for (size_t o = 0; o < result.gnss.outage_t0_s.size(); ++o) {
    std::vector<double> pl;
    for (size_t i = 0; i < ref.Size(); ++i)
      if (ref.t_s[i] >= result.gnss.outage_t0_s[o] && ref.t_s[i] <= result.gnss.outage_t1_s[o]) {
        double x, y;
        pr.Fwd(ref.geo[3 * i], ref.geo[3 * i + 1], &x, &y);
        pl.push_back(x);
        pl.push_back(y);
      }
    outs.push_back(pl);
  }
  if (!outs.empty() && opt.show_gnss) ren->AddActor(Lines(outs, c_out, 8.0f, 0.2, 0.75));
  ren->AddActor(Lines(track_lines(ref), c_ref, 2.5f, 0.5));
  if (result.nav.HasGeodetic()) ren->AddActor(Lines(track_lines(result.nav), c_est, 1.8f, 0.6));
  if (result.gnss.Size() > 0 && opt.show_gnss) {
    vtkNew<vtkPoints> pts;
    vtkNew<vtkCellArray> verts;
    // Display thinning as in the 3D view: at least three dot diameters between drawn fixes.
    const double dot_px = std::max(4.0, opt.height_px / 150.0);
    const double gap = 3.0 * dot_px * span_x / opt.width_px;
    double lx = INFINITY, ly = INFINITY;
    for (size_t i = 0; i < result.gnss.Size(); ++i) {
      double x, y;
      pr.Fwd(result.gnss.geo[3 * i], result.gnss.geo[3 * i + 1], &x, &y);
      if (std::hypot(x - lx, y - ly) < gap) continue;
      lx = x;
      ly = y;
      const vtkIdType id = pts->InsertNextPoint(x, y, 0.7);
      verts->InsertNextCell(1, &id);
    }
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    pd->SetVerts(verts);
    vtkNew<vtkPolyDataMapper> m;
    m->SetInputData(pd);
    vtkNew<vtkActor> a;
    a->SetMapper(m);
    a->GetProperty()->SetColor(c_gnss[0], c_gnss[1], c_gnss[2]);
    a->GetProperty()->SetPointSize(static_cast<float>(dot_px));
    a->GetProperty()->SetRenderPointsAsSpheres(true);
    a->GetProperty()->SetAmbient(0.75);
    a->GetProperty()->SetDiffuse(0.35);
    a->GetProperty()->SetSpecular(0.0);
    ren->AddActor(a);
  }
  // When the whole drive is smaller than a few pixels, a ring marks where it is.
  const double px_m = span_x / opt.width_px;
  if (std::max(x1 - x0, y1 - y0) < 8.0 * px_m) {
    std::vector<double> ring;
    double cx, cy;
    cx = 0.5 * (x0 + x1);
    cy = 0.5 * (y0 + y1);
    for (int i = 0; i <= 48; ++i) {
      ring.push_back(cx + 9.0 * px_m * std::cos(2 * kPi * i / 48.0));
      ring.push_back(cy + 9.0 * px_m * std::sin(2 * kPi * i / 48.0));
    }
    ren->AddActor(Lines({ring}, c_est, 2.5f, 0.8));
  }

  // Camera: plan view, parallel projection, north up.
  vtkCamera *cam = ren->GetActiveCamera();
  cam->ParallelProjectionOn();
  cam->SetFocalPoint(0, 0, 0);
  cam->SetPosition(0, 0, 10.0 * span_x + 100.0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(0.5 * span_y);
  cam->SetClippingRange(1.0, 40.0 * span_x + 1000.0);

  // Scale bar: a nice length about a fifth of the width, bottom left.
  const double sb = NiceLength(span_x / 5.0);
  {
    const double bx = -0.5 * span_x + 0.04 * span_x, by = -0.5 * span_y + 0.06 * span_y;
    const double tick = 0.012 * span_y;
    ren->AddActor(Lines({{bx, by, bx + sb, by}, {bx, by - tick, bx, by + tick}, {bx + sb, by - tick, bx + sb, by + tick}},
                        tc, 3.0f, 1.0));
    if (opt.show_text) {
      char buf[64];
      if (sb >= 1000.0)
        std::snprintf(buf, sizeof buf, "%g km", sb / 1000.0);
      else
        std::snprintf(buf, sizeof buf, "%g m", sb);
      auto t = Text(buf, font, tc);
      t->GetTextProperty()->SetJustificationToCentered();
      t->GetPositionCoordinate()->SetCoordinateSystemToWorld();
      t->GetPositionCoordinate()->SetValue(bx + 0.5 * sb, by + 1.5 * tick, 1.0);
      ren->AddViewProp(t);
    }
  }
  if (opt.show_text) {
    // Drop labels that would overlap an earlier one (meridians meet at a pole, parallels around
    // it have their rightmost points side by side).
    auto dedupe = [&](std::vector<std::pair<std::string, double>> *v, double min_gap) {
      std::vector<std::pair<std::string, double>> keep;
      for (const auto &l : *v) {
        bool clash = false;
        for (const auto &k : keep)
          clash = clash || std::fabs(k.second - l.second) < min_gap;
        if (!clash) keep.push_back(l);
      }
      *v = keep;
    };
    dedupe(&xlabels, 5.0 * font * span_x / opt.width_px);
    dedupe(&ylabels, 1.3 * font * span_y / opt.height_px);
    for (const auto &l : xlabels) {
      if (std::fabs(l.second) > 0.47 * span_x) continue;
      auto t = Text(l.first, font - 3, gc);
      t->GetTextProperty()->SetJustificationToCentered();
      t->GetTextProperty()->SetVerticalJustificationToTop();
      t->GetPositionCoordinate()->SetCoordinateSystemToWorld();
      // Below the title band (two lines at the top left).
      t->GetPositionCoordinate()->SetValue(l.second, 0.5 * span_y - (3.0 * font + 4.0) * span_y / opt.height_px, 1.0);
      ren->AddViewProp(t);
    }
    for (const auto &l : ylabels) {
      if (std::fabs(l.second) > 0.45 * span_y) continue;
      auto t = Text(l.first, font - 3, gc);
      t->GetTextProperty()->SetJustificationToRight();
      t->GetTextProperty()->SetVerticalJustificationToCentered();
      t->GetPositionCoordinate()->SetCoordinateSystemToWorld();
      t->GetPositionCoordinate()->SetValue(0.5 * span_x - 0.008 * span_x, l.second, 1.0);
      ren->AddViewProp(t);
    }
    char buf[512];
    std::snprintf(buf, sizeof buf, "%s \u2013 map, %.4g km across, centre %.5f\u00b0%c %.5f\u00b0%c%s%s",
                  result.scene_name.c_str(), span_x / 1e3, std::fabs(pr.lat0 / kD2R), pr.lat0 >= 0 ? 'N' : 'S',
                  std::fabs(pr.lon0 / kD2R), pr.lon0 >= 0 ? 'E' : 'W',
                  street ? "\nlocal metric grid about the centre" : "",
                  street ? "" : "\nazimuthal equidistant about the centre");
    auto title = Text(buf, font, tc);
    title->GetTextProperty()->SetBold(true);
    title->GetTextProperty()->SetVerticalJustificationToTop();
    title->GetTextProperty()->SetBackgroundColor(1, 1, 1);
    title->GetTextProperty()->SetBackgroundOpacity(0.75);
    title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    title->GetPositionCoordinate()->SetValue(0.012, 0.985);
    ren->AddViewProp(title);
    auto leg = Text("", font - 2, tc);
    std::string lt = "black: reference   red: estimate (run 0)";
    if (result.gnss.Size() > 0) lt += "   green dots: GNSS fixes";
    if (!result.gnss.outage_t0_s.empty()) lt += "   pink: GNSS outage";
    lt += span_x > 250e3 ? "\nbackground: Natural Earth relief, GSHHS coastlines" : "";
    for (const std::string &n : notes)
      lt += "\n" + n;
    leg->SetInput(lt.c_str());
    leg->GetTextProperty()->SetBackgroundColor(1, 1, 1);
    leg->GetTextProperty()->SetBackgroundOpacity(0.75);
    leg->GetTextProperty()->SetJustificationToRight();
    leg->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    leg->GetPositionCoordinate()->SetValue(0.985, 0.015);
    ren->AddViewProp(leg);
  }
  if (extent) {
    extent->span_x_m = span_x;
    extent->span_y_m = span_y;
  }
  return true;
}

bool NavRenderMapPng(const NavResult &result, const NavMapOptions &opt, const std::string &path, std::string *error) {
  if (!NavCheckDisplay(error)) return false;
  vtkNew<vtkRenderWindow> win;
  NavAttachDisplay(win);
  win->SetOffScreenRendering(1);
  win->SetSize(opt.width_px, opt.height_px);
  win->SetMultiSamples(opt.multisamples);
  vtkNew<vtkRenderer> ren;
  win->AddRenderer(ren);
  if (!NavBuildMap(result, opt, ren, nullptr, error)) {
    win->Finalize();
    return false;
  }
  win->Render();
  const bool ok = NavWriteWindowPng(win, path, error);
  win->Finalize();
  return ok;
}
