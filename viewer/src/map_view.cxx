// Geodetic map view (nav_view_map.h): tracks in latitude/longitude over an offline background,
// graticule or local metric grid, scale bar; rendered offscreen to PNG.
#include "navview/nav_view_map.h"

#include "map_interactive_internal.h"

#include "navview_internal.h"
#include "navview/nav_map_data.h"
#include "navview/nav_map_tiles.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sys/stat.h>
#include <chrono>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkTextRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkPointData.h>
#include <vtkNew.h>
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
  /** Angular distance of a point from the centre [rad]. */
  double Dist(double lat, double lon) const {
    return std::acos(std::clamp(sin0 * std::sin(lat) + cos0 * std::cos(lat) * std::cos(lon - lon0), -1.0, 1.0));
  }
  /** The inverse: lat/lon [rad] of (x, y) [m]; false beyond the antipode. */
  bool Inv(double x, double y, double *lat, double *lon) const {
    const double rho = std::hypot(x, y), c = rho / kR;
    if (rho < 1e-9) {
      *lat = lat0;
      *lon = lon0;
      return true;
    }
    if (c > kPi) return false;
    const double sc = std::sin(c), cc = std::cos(c);
    *lat = std::asin(std::clamp(cc * sin0 + y * sc * cos0 / rho, -1.0, 1.0));
    *lon = lon0 + std::atan2(x * sc, rho * cos0 * cc - y * sin0 * sc);
    return true;
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
  if (a == 0.0 || (!lat && std::fabs(a - 180.0) < 1e-9)) // the equator, prime and 180th meridians
    std::snprintf(buf, sizeof buf, "%.*f\u00b0", dec, a);
  else
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

namespace {

// Map colours (RGB 0..1): the sea and lakes one blue, land a light sand, so the two differ in
// every channel that a pixel test reads (blue minus red: about +60 on water, -20 on land).
const double kSea[3] = {kNavMapWaterRgb[0] / 255.0, kNavMapWaterRgb[1] / 255.0, kNavMapWaterRgb[2] / 255.0};
const double kLand[3] = {kNavMapLandRgb[0] / 255.0, kNavMapLandRgb[1] / 255.0, kNavMapLandRgb[2] / 255.0};
const double kNoData[3] = {0.900, 0.900, 0.900};

struct Box {
  double x0, y0, x1, y1;
  bool Hits(const Box &o) const { return x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};

/** Text extent [px] with the label's property (left/bottom justified). */
void TextSize(vtkTextProperty *tp, const std::string &s, double *w, double *h) {
  int bb[4] = {0, 0, 0, 0};
  vtkTextRenderer *tr = vtkTextRenderer::GetInstance();
  if (tr && tr->GetBoundingBox(tp, s, bb, 72)) {
    *w = bb[1] - bb[0] + 1;
    *h = bb[3] - bb[2] + 1;
  } else { // no renderer: a generous estimate
    *w = 0.62 * tp->GetFontSize() * static_cast<double>(s.size());
    *h = 1.25 * tp->GetFontSize();
  }
}

} // namespace

void NavMapInfo::PixelOf(double lat_deg, double lon_deg, double *px, double *py) const {
  Projection pr;
  pr.Init(proj_lat_deg * kD2R, proj_lon_deg * kD2R);
  double x, y;
  pr.Fwd(lat_deg * kD2R, lon_deg * kD2R, &x, &y);
  *px = (x - (view_x_m - 0.5 * span_x_m)) / span_x_m * width_px;
  *py = (y - (view_y_m - 0.5 * span_y_m)) / span_y_m * height_px;
}

bool NavMapFit(const NavResult &result, const NavMapOptions &opt, NavMapFrame *frame, std::string *error) {
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
  const double half_w = std::max(std::fabs(x0), std::fabs(x1)), half_h = std::max(std::fabs(y0), std::fabs(y1));
  double span_x = opt.span_km > 0.0 ? opt.span_km * 1e3 : std::max(200.0, 2.3 * std::max(half_w, half_h * aspect));
  frame->lat0_rad = pr.lat0;
  frame->lon0_rad = pr.lon0;
  frame->fit_span_x_m = std::min(span_x, NavMapMaxSpanM());
  frame->track_box_m[0] = x0;
  frame->track_box_m[1] = y0;
  frame->track_box_m[2] = x1;
  frame->track_box_m[3] = y1;
  return true;
}

double NavMapMaxSpanM() { return 2.0 * kMaxC * kR; }

bool NavBuildMapView(const NavResult &result, const NavMapOptions &opt, const NavMapFrame &frame, double cx, double cy,
                     double span_x, vtkRenderer *ren, NavMapInfo *info_out, std::string *error) {
  const auto t_start = std::chrono::steady_clock::now();
  const NavTrack &ref = result.truth;
  if (!std::isfinite(cx) || !std::isfinite(cy) || !(span_x > 0.0) || !std::isfinite(span_x)) {
    *error = "map view: centre and width must be finite, width > 0";
    return false;
  }
  NavMapInfo info;
  const int W = opt.width_px, H = opt.height_px;
  span_x = std::clamp(span_x, 1.0, NavMapMaxSpanM());
  const double span_y = span_x * H / W;
  const double left = cx - 0.5 * span_x, bottom = cy - 0.5 * span_y;
  const double m_px = span_x / W;
  info.width_px = W;
  info.height_px = H;
  info.span_x_m = span_x;
  info.span_y_m = span_y;
  info.proj_lat_deg = frame.lat0_rad / kD2R;
  info.proj_lon_deg = frame.lon0_rad / kD2R;
  info.view_x_m = cx;
  info.view_y_m = cy;
  Projection pr;
  pr.Init(frame.lat0_rad, frame.lon0_rad);
  auto to_px = [&](double x, double y, double *px, double *py) {
    *px = (x - left) / m_px;
    *py = (y - bottom) / m_px;
  };
  auto to_world = [&](double px, double py, double *x, double *y) {
    *x = left + px * m_px;
    *y = bottom + py * m_px;
  };
  ren->RemoveAllViewProps();

  // The view's latitude/longitude box: the inverse projection of its border, widened to every
  // longitude when a pole is inside or the view reaches far from the centre.
  double lat_lo = INFINITY, lat_hi = -INFINITY, dlon_lo = INFINITY, dlon_hi = -INFINITY, c_max = 0.0;
  for (int k = 0; k < 4 * 32; ++k) {
    const double f = (k % 32) / 32.0;
    const int side = k / 32;
    const double x = side == 0 ? left + f * span_x : side == 1 ? left + span_x : side == 2 ? left + span_x - f * span_x : left;
    const double y = side == 0 ? bottom : side == 1 ? bottom + f * span_y : side == 2 ? bottom + span_y : bottom + span_y - f * span_y;
    double la, lo;
    if (!pr.Inv(x, y, &la, &lo)) continue;
    c_max = std::max(c_max, std::hypot(x, y) / kR);
    lat_lo = std::min(lat_lo, la);
    lat_hi = std::max(lat_hi, la);
    const double d = std::remainder(lo - pr.lon0, 2 * kPi);
    dlon_lo = std::min(dlon_lo, d);
    dlon_hi = std::max(dlon_hi, d);
  }
  bool all_lon = c_max > 80.0 * kD2R;
  for (double pole : {0.5 * kPi, -0.5 * kPi}) {
    double x, y;
    pr.Fwd(pole, 0.0, &x, &y);
    if (x >= left && x <= left + span_x && y >= bottom && y <= bottom + span_y) {
      all_lon = true;
      (pole > 0 ? lat_hi : lat_lo) = pole;
    }
  }
  if (all_lon) {
    lat_lo = std::max(-0.5 * kPi, std::min(lat_lo, pr.lat0 - c_max));
    lat_hi = std::min(0.5 * kPi, std::max(lat_hi, pr.lat0 + c_max));
    dlon_lo = -kPi;
    dlon_hi = kPi;
  }
  const double lon_lo = pr.lon0 + dlon_lo, lon_hi = pr.lon0 + dlon_hi;
  const double span_deg_y = (lat_hi - lat_lo) / kD2R, span_deg_x = (lon_hi - lon_lo) / kD2R;
  const bool pole = all_lon;

  // Land and water: GSHHG areas painted level by level into an image of the view.
  const bool street = span_x < 20e3;
  std::vector<unsigned char> img(3 * static_cast<size_t>(W) * static_cast<size_t>(H));
  const std::string gshhg = opt.data_dir.empty() ? NavMapGshhgDir() : opt.data_dir;
  NavMapLayers layers;
  std::string derr;
  const NavShoreRes res = NavShoreResForScale(m_px);
  const bool have_shore = NavMapLoadLayers(gshhg, res, lat_lo / kD2R, lat_hi / kD2R, lon_lo / kD2R,
                                           all_lon ? lon_lo / kD2R + 360.0 : lon_hi / kD2R, &layers, &derr);
  {
    const double *bg = have_shore ? kSea : kNoData;
    const unsigned char c0[3] = {static_cast<unsigned char>(std::lround(255 * bg[0])),
                                 static_cast<unsigned char>(std::lround(255 * bg[1])),
                                 static_cast<unsigned char>(std::lround(255 * bg[2]))};
    for (size_t i = 0; i < img.size(); i += 3)
      std::memcpy(&img[i], c0, 3);
  }
  // Beyond this angular distance from the centre a ring is not drawn: the projection stretches
  // rings near the antipode around the whole disc (the view's corners reach at most ~141 deg).
  const double c_draw = std::min(kPi - 0.05, c_max + 10.0 * kD2R);
  if (have_shore) {
    info.shore_res = NavShoreResLetter(layers.res);
    info.bins = layers.bins;
    NavMapPaintAreas(layers,
                     [&](double lat_deg, double lon_deg, double *px, double *py) {
                       const double la = lat_deg * kD2R, lo = lon_deg * kD2R;
                       if (pr.Dist(la, lo) > c_draw) return false;
                       double x, y;
                       pr.Fwd(la, lo, &x, &y);
                       to_px(x, y, px, py);
                       return true;
                     },
                     W, H, &img);
  } else {
    info.notes.push_back(derr);
  }
  // The user's tiles over the fill: every pixel centre taken back to lat/lon and resampled from
  // the Web-Mercator tiles, so the streets sit where the azimuthal projection puts them.
  if (!opt.tiles.empty()) {
    std::shared_ptr<NavTileSource> tiles;
    if (!NavTileSourceOpen(opt.tiles, &tiles, error)) return false;
    double clat = pr.lat0, clon = pr.lon0;
    pr.Inv(cx, cy, &clat, &clon);
    NavTilePaint tp;
    NavMapPaintTiles(*tiles,
                     [&](double px, double py, double *lat_deg, double *lon_deg) {
                       double x, y, la, lo;
                       to_world(px, py, &x, &y);
                       if (!pr.Inv(x, y, &la, &lo)) return false;
                       *lat_deg = la / kD2R;
                       *lon_deg = lo / kD2R;
                       return true;
                     },
                     m_px, clat / kD2R, W, H, &img, &tp);
    info.tile_zoom = tp.zoom;
    info.tiles = tp.tiles;
    info.tile_coverage = tp.coverage;
    if (tp.tiles > 0) info.tile_credit = NavTileCredit(*tiles, opt.tiles_attribution);
    info.notes.insert(info.notes.end(), tp.notes.begin(), tp.notes.end());
  }
  {
    vtkNew<vtkImageData> im;
    im->SetDimensions(W, H, 1);
    vtkNew<vtkUnsignedCharArray> px;
    px->SetNumberOfComponents(3);
    px->SetNumberOfTuples(static_cast<vtkIdType>(W) * H);
    std::memcpy(px->GetPointer(0), img.data(), img.size());
    im->GetPointData()->SetScalars(px);
    vtkNew<vtkTexture> tex;
    tex->SetInputData(im);
    tex->InterpolateOff();
    tex->SetColorModeToDirectScalars();
    vtkNew<vtkPlaneSource> plane;
    plane->SetOrigin(left, bottom, -2.0);
    plane->SetPoint1(left + span_x, bottom, -2.0);
    plane->SetPoint2(left, bottom + span_y, -2.0);
    vtkNew<vtkPolyDataMapper> m;
    m->SetInputConnection(plane->GetOutputPort());
    vtkNew<vtkActor> a;
    a->SetMapper(m);
    a->SetTexture(tex);
    a->GetProperty()->LightingOff();
    ren->AddActor(a);
  }
  ren->SetBackground(have_shore ? kSea[0] : kNoData[0], have_shore ? kSea[1] : kNoData[1],
                     have_shore ? kSea[2] : kNoData[2]);

  // Shorelines, rivers and borders as lines over the fill.
  auto world_lines = [&](const std::vector<NavMapLine> &ls, int max_level, int min_level) {
    std::vector<std::vector<double>> out;
    for (const NavMapLine &l : ls) {
      if (l.level > max_level || l.level < min_level) continue;
      AddProjected(pr, l.lonlat, 0.25 * kPi * kR, &out, 0.8 * m_px);
    }
    return out;
  };
  // Tiles covering the whole view carry their own coasts and rivers: GSHHG's lines would only
  // disagree with them by the difference of the two surveys.
  if (have_shore && info.tile_coverage < 0.999) {
    // River classes: 0 double-lined, 1-4 permanent (major to minor), 5-10 intermittent, canals.
    const int river_max = m_px < 60.0 ? 5 : m_px < 600.0 ? 3 : m_px < 3000.0 ? 2 : 1;
    const double c_river[3] = {0.36, 0.58, 0.84}, c_border[3] = {0.52, 0.30, 0.50}, c_state[3] = {0.66, 0.55, 0.64};
    // Shores: a thin line a shade darker than the water hides the fill's pixel steps.
    const double c_shore[3] = {0.45, 0.60, 0.75};
    ren->AddActor(Lines(world_lines(layers.shores, 4, 1), c_shore, 1.0f, -1.7));
    ren->AddActor(Lines(world_lines(layers.rivers, river_max, 0), c_river, m_px < 60.0 ? 1.6f : 1.1f, -1.6));
    if (m_px < 3000.0) ren->AddActor(Lines(world_lines(layers.borders, 2, 2), c_state, 0.9f, -1.5));
    ren->AddActor(Lines(world_lines(layers.borders, 1, 1), c_border, 1.6f, -1.4));
  }

  const int font = std::max(10, static_cast<int>(std::lround(H / 48.0)));
  const double tc[3] = {0.05, 0.05, 0.08}, gc[3] = {0.38, 0.40, 0.46};
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
          const double x = pl[i] - cx, y = pl[i + 1] - cy;
          if (std::fabs(x) > 0.5 * span_x || std::fabs(y) > 0.5 * span_y) continue;
          const double key = right ? x : y;
          if (key > best) {
            best = key;
            *pos = right ? pl[i + 1] : pl[i];
          }
        }
      return std::isfinite(best) && best > (right ? 0.3 * span_x : 0.3 * span_y);
    };
    for (double la = std::ceil(lat_a / lat_step) * lat_step; la <= lat_b + 1e-9; la += lat_step) {
      if (std::fabs(la) > 89.999) continue;
      std::vector<double> ll;
      for (int i = 0; i <= 720; ++i)
        ll.insert(ll.end(), {lon_a + (lon_b - lon_a) * i / 720.0, la});
      std::vector<std::vector<double>> lines;
      AddProjected(pr, ll, 0.25 * kPi * kR, &lines, 1.5 * m_px);
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
      AddProjected(pr, ll, 0.25 * kPi * kR, &lines, 1.5 * m_px);
      double wl = std::remainder(lo, 360.0);
      if (wl <= -180.0) wl += 360.0;
      double pos = 0.0;
      if (label_at(lines, false, &pos)) xlabels.push_back({FormatDeg(wl, false, lon_step), pos});
      grid.insert(grid.end(), lines.begin(), lines.end());
    }
  } else {
    const double s = NiceLength(span_x / 6.0);
    for (double x = std::floor(left / s) * s; x <= left + span_x; x += s)
      grid.push_back({x, bottom, x, bottom + span_y});
    for (double y = std::floor(bottom / s) * s; y <= bottom + span_y; y += s)
      grid.push_back({left, y, left + span_x, y});
    char buf[64];
    for (double x = std::ceil(left / s) * s; x <= left + span_x; x += s) {
      std::snprintf(buf, sizeof buf, "%+g m E", x);
      xlabels.push_back({buf, x});
    }
    for (double y = std::ceil(bottom / s) * s; y <= bottom + span_y; y += s) {
      std::snprintf(buf, sizeof buf, "%+g m N", y);
      ylabels.push_back({buf, y});
    }
  }
  ren->AddActor(Lines(grid, gc, 1.0f, -0.5, 0.5));

  // Tracks, thinned to about half a pixel between vertices: with multisampling, llvmpipe drew
  // almost nothing of 18 000 sub-pixel segments (the ship scene at 20 km across).
  const double track_step = 0.5 * m_px;
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
    const double dot_px = std::max(4.0, H / 150.0);
    const double gap = 3.0 * dot_px * m_px;
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
  {
    const double *tb = frame.track_box_m;
    if (std::max(tb[2] - tb[0], tb[3] - tb[1]) < 8.0 * m_px) {
      std::vector<double> ring;
      const double rx = 0.5 * (tb[0] + tb[2]), ry = 0.5 * (tb[1] + tb[3]);
      for (int i = 0; i <= 48; ++i) {
        ring.push_back(rx + 9.0 * m_px * std::cos(2 * kPi * i / 48.0));
        ring.push_back(ry + 9.0 * m_px * std::sin(2 * kPi * i / 48.0));
      }
      ren->AddActor(Lines({ring}, c_est, 2.5f, 0.8));
    }
  }

  // Scale bar: a nice length about a fifth of the width, bottom left.
  std::vector<Box> taken; // display boxes of every text and the scale bar: nothing overlaps them
  auto add_text = [&](vtkTextActor *t, double px, double py, NavMapLabel::Kind kind, const std::string &s, double w,
                      double h) {
    double x, y;
    to_world(px, py, &x, &y);
    t->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    t->GetPositionCoordinate()->SetValue(x, y, 1.0);
    ren->AddViewProp(t);
    NavMapLabel l;
    l.kind = kind;
    l.text = s;
    l.x0 = px;
    l.y0 = py;
    l.x1 = px + w;
    l.y1 = py + h;
    info.labels.push_back(l);
    taken.push_back({px, py, px + w, py + h});
  };
  size_t placed = 0;
  const std::string places_path = opt.places_file.empty() ? NavMapPlacesFile() : opt.places_file;
  const std::vector<NavPlace> *places = nullptr;
  if (opt.show_places && opt.show_text) {
    std::string perr;
    if (places_path.empty())
      info.notes.push_back("no gazetteer (places.tsv not built: node and npm needed)");
    else if (!NavMapLoadPlaces(places_path, &places, &perr))
      info.notes.push_back(perr);
  }
  const double sb = NiceLength(span_x / 5.0);
  {
    const double bpx = 0.04 * W, bpy = 0.06 * H, tick = 0.012 * H;
    double bx, by;
    to_world(bpx, bpy, &bx, &by);
    ren->AddActor(Lines({{bx, by, bx + sb, by}, {bx, by - tick * m_px, bx, by + tick * m_px},
                         {bx + sb, by - tick * m_px, bx + sb, by + tick * m_px}},
                        tc, 3.0f, 1.0));
    taken.push_back({bpx - 4, bpy - tick - 4, bpx + sb / m_px + 4, bpy + tick + 2});
    if (opt.show_text) {
      char buf[64];
      if (sb >= 1000.0)
        std::snprintf(buf, sizeof buf, "%g km", sb / 1000.0);
      else
        std::snprintf(buf, sizeof buf, "%g m", sb);
      auto t = Text(buf, font, tc);
      double w, h;
      TextSize(t->GetTextProperty(), buf, &w, &h);
      add_text(t, bpx + 0.5 * sb / m_px - 0.5 * w, bpy + tick + 2, NavMapLabel::ScaleBar, buf, w, h);
    }
  }
  if (opt.show_text) {
    char buf[512];
    {
      double clat = pr.lat0, clon = pr.lon0;
      pr.Inv(cx, cy, &clat, &clon);
      clon = std::remainder(clon, 2 * kPi);
      char km[32];
      std::snprintf(km, sizeof km, span_x >= 1e7 ? "%.0f" : "%.4g", span_x / 1e3);
      std::snprintf(buf, sizeof buf, "%s \u2013 map, %s km across, centre %.5f\u00b0%c %.5f\u00b0%c\n%s",
                    result.scene_name.c_str(), km, std::fabs(clat / kD2R), clat >= 0 ? 'N' : 'S',
                    std::fabs(clon / kD2R), clon >= 0 ? 'E' : 'W',
                    street ? "local metric grid (m from the projection centre)" : "azimuthal equidistant, graticule");
    }
    auto title = Text(buf, font, tc);
    title->GetTextProperty()->SetBold(true);
    title->GetTextProperty()->SetBackgroundColor(1, 1, 1);
    title->GetTextProperty()->SetBackgroundOpacity(0.75);
    double w, h;
    TextSize(title->GetTextProperty(), buf, &w, &h);
    add_text(title, 0.012 * W, H - 0.012 * H - h, NavMapLabel::Title, buf, w, h);
    const double title_y0 = H - 0.012 * H - h;

    std::string lt = "black: reference   red: estimate (run 0)";
    if (result.gnss.Size() > 0) lt += "   green dots: GNSS fixes";
    if (!result.gnss.outage_t0_s.empty()) lt += "   pink: GNSS outage";
    if (have_shore && info.tile_coverage < 0.999) {
      lt += std::string("\nGSHHG 2.3.7 (") + NavShoreResLetter(layers.res) +
            ") land, lakes, WDBII rivers and borders";
    }
    if (!info.tile_credit.empty()) lt += "\n" + info.tile_credit;
    // GeoNames asks for credit (CC BY 4.0).
    if (places) lt += "\nplace names: GeoNames (CC BY 4.0)";
    for (const std::string &n : info.notes)
      lt += "\n" + n;
    auto leg = Text(lt, font - 2, tc);
    leg->GetTextProperty()->SetBackgroundColor(1, 1, 1);
    leg->GetTextProperty()->SetBackgroundOpacity(0.75);
    leg->GetTextProperty()->SetJustificationToRight();
    TextSize(leg->GetTextProperty(), lt, &w, &h);
    leg->GetTextProperty()->SetJustificationToLeft();
    // Bottom right; raised above the scale bar when a narrow map puts the two side by side.
    double leg_y = 0.015 * H;
    for (const Box &o : taken)
      if (o.Hits({0.985 * W - w, leg_y, 0.985 * W, leg_y + h})) leg_y = o.y1 + 4;
    add_text(leg, 0.985 * W - w, leg_y, NavMapLabel::Legend, lt, w, h);

    // Graticule (or grid) labels: longitudes below the title, latitudes at the right edge; one
    // that would touch an earlier text is left out.
    for (const auto &l : xlabels) {
      auto t = Text(l.first, font - 3, gc);
      t->GetTextProperty()->SetBackgroundColor(kLand[0], kLand[1], kLand[2]);
      t->GetTextProperty()->SetBackgroundOpacity(0.6);
      TextSize(t->GetTextProperty(), l.first, &w, &h);
      double px, py;
      to_px(l.second, 0.0, &px, &py);
      const Box b{px - 0.5 * w, title_y0 - 4 - h, px + 0.5 * w, title_y0 - 4};
      if (b.x0 < 2 || b.x1 > W - 2) continue;
      bool clash = false;
      for (const Box &o : taken)
        clash = clash || o.Hits({b.x0 - 6, b.y0, b.x1 + 6, b.y1});
      if (clash) continue;
      add_text(t, b.x0, b.y0, NavMapLabel::Graticule, l.first, w, h);
    }
    for (const auto &l : ylabels) {
      auto t = Text(l.first, font - 3, gc);
      t->GetTextProperty()->SetBackgroundColor(kLand[0], kLand[1], kLand[2]);
      t->GetTextProperty()->SetBackgroundOpacity(0.6);
      TextSize(t->GetTextProperty(), l.first, &w, &h);
      double px, py;
      to_px(0.0, l.second, &px, &py);
      const Box b{0.992 * W - w, py - 0.5 * h, 0.992 * W, py + 0.5 * h};
      if (b.y0 < 2 || b.y1 > H - 2) continue;
      bool clash = false;
      for (const Box &o : taken)
        clash = clash || o.Hits({b.x0, b.y0 - 3, b.x1, b.y1 + 3});
      if (clash) continue;
      add_text(t, b.x0, b.y0, NavMapLabel::Graticule, l.first, w, h);
    }
  }

  // Place names: the most populous places in view first, each with a dot, its name right of the
  // dot (else left, above, below), never over another text; at most one label per ~30 000 px^2.
  if (places) {
    const double c_place[3] = {0.10, 0.10, 0.14};
    std::vector<std::array<double, 4>> boxes;
    for (const Box &o : taken)
      boxes.push_back({o.x0, o.y0, o.x1, o.y1});
    const std::vector<NavMapPlaceLabel> chosen = NavMapChoosePlaces(
        *places,
        [&](double lat_deg, double lon_deg) {
          const double la = lat_deg * kD2R, lo = lon_deg * kD2R;
          if (la < lat_lo || la > lat_hi) return false;
          if (all_lon) return true;
          const double d = std::remainder(lo - pr.lon0, 2 * kPi);
          return d >= dlon_lo && d <= dlon_hi;
        },
        [&](double lat_deg, double lon_deg, double *px, double *py) {
          double x, y;
          if (!pr.Fwd(lat_deg * kD2R, lon_deg * kD2R, &x, &y)) return false;
          to_px(x, y, px, py);
          return true;
        },
        W, H, font,
        [&](const std::string &text, int size, bool bold, double *w, double *h) {
          // Measured as drawn: the background widens the text's box.
          auto t = Text(text, size, c_place);
          t->GetTextProperty()->SetBold(bold);
          t->GetTextProperty()->SetBackgroundColor(kLand[0], kLand[1], kLand[2]);
          t->GetTextProperty()->SetBackgroundOpacity(0.55);
          TextSize(t->GetTextProperty(), text, w, h);
        },
        boxes);
    std::vector<double> dots;
    for (const NavMapPlaceLabel &l : chosen) {
      auto t = Text(l.place->name, l.size_pt, c_place);
      t->GetTextProperty()->SetBold(l.bold);
      t->GetTextProperty()->SetBackgroundColor(kLand[0], kLand[1], kLand[2]);
      t->GetTextProperty()->SetBackgroundOpacity(0.55);
      add_text(t, l.x0, l.y0, NavMapLabel::Place, l.place->name, l.x1 - l.x0, l.y1 - l.y0);
      // Place labels first in the list (the documented order): move this one forward.
      std::rotate(info.labels.begin() + static_cast<std::ptrdiff_t>(placed), info.labels.end() - 1, info.labels.end());
      double x, y;
      to_world(l.dot_x, l.dot_y, &x, &y);
      dots.insert(dots.end(), {x, y});
      ++placed;
    }
    if (!dots.empty()) {
      vtkNew<vtkPoints> pts;
      vtkNew<vtkCellArray> verts;
      for (size_t i = 0; i + 1 < dots.size(); i += 2) {
        const vtkIdType id = pts->InsertNextPoint(dots[i], dots[i + 1], 0.9);
        verts->InsertNextCell(1, &id);
      }
      vtkNew<vtkPolyData> pd;
      pd->SetPoints(pts);
      pd->SetVerts(verts);
      vtkNew<vtkPolyDataMapper> m;
      m->SetInputData(pd);
      vtkNew<vtkActor> a;
      a->SetMapper(m);
      a->GetProperty()->SetColor(c_place[0], c_place[1], c_place[2]);
      a->GetProperty()->SetPointSize(5.0f);
      a->GetProperty()->LightingOff();
      ren->AddActor(a);
    }
  }
  info.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_start).count();
  if (info_out) *info_out = std::move(info);
  return true;
}

bool NavBuildMap(const NavResult &result, const NavMapOptions &opt, vtkRenderer *ren, NavMapExtent *extent,
                 std::string *error, NavMapFrame *frame_out, NavMapInfo *info) {
  NavMapFrame frame;
  if (!NavMapFit(result, opt, &frame, error)) return false;
  const double span_x = frame.fit_span_x_m, span_y = span_x * opt.height_px / opt.width_px;
  if (!NavBuildMapView(result, opt, frame, 0.0, 0.0, span_x, ren, info, error)) return false;
  // Camera: plan view, parallel projection, north up.
  vtkCamera *cam = ren->GetActiveCamera();
  cam->ParallelProjectionOn();
  cam->SetFocalPoint(0, 0, 0);
  cam->SetPosition(0, 0, 10.0 * span_x + 100.0);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(0.5 * span_y);
  cam->SetClippingRange(1.0, 40.0 * span_x + 1000.0);
  if (extent) {
    extent->span_x_m = span_x;
    extent->span_y_m = span_y;
  }
  if (frame_out) *frame_out = frame;
  return true;
}

bool NavRenderMapPng(const NavResult &result, const NavMapOptions &opt, const std::string &path, std::string *error,
                     NavMapInfo *info) {
  if (!NavCheckDisplay(error)) return false;
  vtkNew<vtkRenderWindow> win;
  NavAttachDisplay(win);
  win->SetOffScreenRendering(1);
  win->SetSize(opt.width_px, opt.height_px);
  win->SetMultiSamples(opt.multisamples);
  vtkNew<vtkRenderer> ren;
  win->AddRenderer(ren);
  if (!NavBuildMap(result, opt, ren, nullptr, error, nullptr, info)) {
    win->Finalize();
    return false;
  }
  win->Render();
  const bool ok = NavWriteWindowPng(win, path, error);
  win->Finalize();
  return ok;
}
