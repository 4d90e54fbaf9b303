// Test tiles for the map's tile layer (issue 19, item 2): small Web-Mercator tiles around a point,
// each filled with a colour of its own and crossed by two dark "streets" through its centre (one
// along the tile's middle column: a meridian; one along its middle row: a parallel), written as
// PNGs (VTK) into an XYZ directory DIR/xyz/{z}/{x}/{y}.png and packed into DIR/tiles.mbtiles
// (MBTiles 1.3, SQLite API). The tests know from these rules what each pixel must show.
#ifndef NAVVIEW_TILE_FIXTURE_H
#define NAVVIEW_TILE_FIXTURE_H

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <sqlite3.h>

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkUnsignedCharArray.h>

namespace tilefix {

constexpr double kPi = 3.14159265358979323846;
constexpr int kSize = 256;
constexpr int kStreetLo = 126, kStreetHi = 129; // street pixels: columns / rows 126..129
constexpr unsigned char kStreet = 30;           // street grey level (R = G = B)
constexpr const char *kAttributionHtml = "<a href=\"https://example.invalid/\">&copy; navview test tiles</a>";
constexpr const char *kAttributionText = "\u00a9 navview test tiles";

/** Fill colour of tile z/x/y (no channel below 90, so it never looks like a street). */
inline void TileRgb(int z, int x, int y, unsigned char rgb[3]) {
  rgb[0] = static_cast<unsigned char>(90 + 40 * (x % 4));
  rgb[1] = static_cast<unsigned char>(90 + 40 * (y % 4));
  rgb[2] = static_cast<unsigned char>(110 + 45 * ((z - 14 + 3) % 3));
}

/** Fractional XYZ tile coordinates of a point at zoom @p z. */
inline void TileXY(double lat_deg, double lon_deg, int z, double *fx, double *fy) {
  const double n = std::ldexp(1.0, z);
  *fx = (lon_deg + 180.0) / 360.0 * n;
  *fy = (1.0 - std::asinh(std::tan(lat_deg * kPi / 180.0)) / kPi) * 0.5 * n;
}
/** Latitude, longitude [deg] of fractional tile coordinates. */
inline void TileLatLon(double fx, double fy, int z, double *lat_deg, double *lon_deg) {
  const double n = std::ldexp(1.0, z);
  *lon_deg = fx / n * 360.0 - 180.0;
  *lat_deg = std::atan(std::sinh(kPi * (1.0 - 2.0 * fy / n))) * 180.0 / kPi;
}

inline std::vector<unsigned char> TilePng(int z, int x, int y) {
  vtkNew<vtkImageData> im;
  im->SetDimensions(kSize, kSize, 1);
  vtkNew<vtkUnsignedCharArray> px;
  px->SetNumberOfComponents(3);
  px->SetNumberOfTuples(kSize * kSize);
  unsigned char c[3];
  TileRgb(z, x, y, c);
  for (int vy = 0; vy < kSize; ++vy) {
    const int row = kSize - 1 - vy; // VTK rows start at the bottom; tile rows at the top
    for (int col = 0; col < kSize; ++col) {
      const bool street = (col >= kStreetLo && col <= kStreetHi) || (row >= kStreetLo && row <= kStreetHi);
      unsigned char *p = px->GetPointer(3 * (vy * kSize + col));
      for (int k = 0; k < 3; ++k)
        p[k] = street ? kStreet : c[k];
    }
  }
  im->GetPointData()->SetScalars(px);
  vtkNew<vtkPNGWriter> w;
  w->SetInputData(im);
  w->WriteToMemoryOn();
  w->Write();
  vtkUnsignedCharArray *r = w->GetResult();
  return std::vector<unsigned char>(r->GetPointer(0), r->GetPointer(0) + r->GetNumberOfTuples());
}

inline void MkDirs(const std::string &d) {
  for (size_t p = 1; p != std::string::npos; p = d.find('/', p + 1))
    mkdir(d.substr(0, p).c_str(), 0755);
  mkdir(d.c_str(), 0755);
}

/** Tiles of zooms @p z0..@p z1 covering @p radius_m around (@p lat, @p lon): DIR/xyz/{z}/{x}/{y}.png
 *  and DIR/tiles.mbtiles (metadata: name, format png, minzoom, maxzoom, attribution in HTML).
 *  @return the number of tiles per zoom level written, or -1 with @p error. */
inline int MakeTiles(const std::string &dir, double lat, double lon, int z0, int z1, double radius_m,
                     std::string *error) {
  MkDirs(dir + "/xyz");
  const std::string mb = dir + "/tiles.mbtiles";
  std::remove(mb.c_str());
  sqlite3 *db = nullptr;
  if (sqlite3_open(mb.c_str(), &db) != SQLITE_OK) {
    *error = "cannot create " + mb;
    sqlite3_close(db);
    return -1;
  }
  const char *ddl =
      "CREATE TABLE metadata (name TEXT, value TEXT);"
      "CREATE TABLE tiles (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, tile_data BLOB);"
      "CREATE UNIQUE INDEX tile_index ON tiles (zoom_level, tile_column, tile_row);"
      "BEGIN;";
  char *msg = nullptr;
  if (sqlite3_exec(db, ddl, nullptr, nullptr, &msg) != SQLITE_OK) {
    *error = std::string("sqlite: ") + (msg ? msg : "?");
    sqlite3_free(msg);
    sqlite3_close(db);
    return -1;
  }
  sqlite3_stmt *meta = nullptr, *ins = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO metadata VALUES (?, ?)", -1, &meta, nullptr);
  sqlite3_prepare_v2(db, "INSERT INTO tiles VALUES (?, ?, ?, ?)", -1, &ins, nullptr);
  const std::string kv[][2] = {{"name", "navview test tiles"},
                               {"format", "png"},
                               {"minzoom", std::to_string(z0)},
                               {"maxzoom", std::to_string(z1)},
                               {"attribution", kAttributionHtml}};
  for (const auto &p : kv) {
    sqlite3_bind_text(meta, 1, p[0].c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(meta, 2, p[1].c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_step(meta);
    sqlite3_reset(meta);
  }
  int per_zoom = 0;
  const double dlat = radius_m / 111320.0, dlon = radius_m / (111320.0 * std::cos(lat * kPi / 180.0));
  for (int z = z0; z <= z1; ++z) {
    double ax, ay, bx, by;
    TileXY(lat + dlat, lon - dlon, z, &ax, &ay);
    TileXY(lat - dlat, lon + dlon, z, &bx, &by);
    int count = 0;
    for (int x = static_cast<int>(std::floor(ax)); x <= static_cast<int>(std::floor(bx)); ++x)
      for (int y = static_cast<int>(std::floor(ay)); y <= static_cast<int>(std::floor(by)); ++y) {
        const std::vector<unsigned char> png = TilePng(z, x, y);
        const std::string d = dir + "/xyz/" + std::to_string(z) + "/" + std::to_string(x);
        MkDirs(d);
        FILE *f = std::fopen((d + "/" + std::to_string(y) + ".png").c_str(), "wb");
        if (!f || std::fwrite(png.data(), 1, png.size(), f) != png.size()) {
          *error = "cannot write " + d;
          if (f) std::fclose(f);
          sqlite3_close(db);
          return -1;
        }
        std::fclose(f);
        sqlite3_bind_int(ins, 1, z);
        sqlite3_bind_int(ins, 2, x);
        sqlite3_bind_int(ins, 3, (1 << z) - 1 - y); // MBTiles rows count from the south (TMS)
        sqlite3_bind_blob(ins, 4, png.data(), static_cast<int>(png.size()), SQLITE_TRANSIENT);
        if (sqlite3_step(ins) != SQLITE_DONE) {
          *error = std::string("sqlite insert: ") + sqlite3_errmsg(db);
          sqlite3_close(db);
          return -1;
        }
        sqlite3_reset(ins);
        ++count;
      }
    per_zoom = std::max(per_zoom, count);
  }
  sqlite3_finalize(meta);
  sqlite3_finalize(ins);
  sqlite3_exec(db, "COMMIT;", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  return per_zoom;
}

} // namespace tilefix

#endif
