/**
 * @file nav_map_tiles.h
 * @brief The map's optional raster tile layer: streets and buildings at street scale from tiles
 *        the user supplies in the Web-Mercator ("slippy map") tiling: a local MBTiles file, an XYZ
 *        directory, or an XYZ URL template fetched over the network with a disk cache.
 *        No VTK types here (docs/map-data.md, "Tile layer").
 *
 * A tile source is named by one string, the "spec":
 *  - `FILE.mbtiles` (any regular file): MBTiles 1.3, a SQLite database with the table
 *    `tiles(zoom_level, tile_column, tile_row, tile_data)` (rows counted from the south, TMS) and
 *    `metadata(name, value)` (format png|jpg, attribution, minzoom, maxzoom are read);
 *  - `DIR/{z}/{x}/{y}.png` (or .jpg): a directory template, rows counted from the north; a plain
 *    directory DIR means `DIR/{z}/{x}/{y}.png`; the zoom levels present are DIR's numeric
 *    subdirectories when the template starts with `DIR/{z}/`;
 *  - `http://HOST/.../{z}/{x}/{y}.png` or `https://...`: fetched with libcurl, kept in a disk cache
 *    ($NAVVIEW_TILE_CACHE, else $XDG_CACHE_HOME/navsim/tiles, else ~/.cache/navsim/tiles; a cached
 *    tile younger than 7 days is used without asking the server), zoom 0 to 19. When the server
 *    cannot be reached the layer keeps to the cached tiles for a minute and says so in a note.
 *
 * Thread-safety: a source serialises its own calls with a mutex; the process keeps one source
 * per spec (NavTileSourceOpen), with its most recently used decoded tiles.
 */
#ifndef NAV_MAP_TILES_H
#define NAV_MAP_TILES_H

#include <functional>
#include <memory>
#include <string>
#include <vector>

/** One decoded tile: RGBA, @c w x @c h pixels, row 0 at the top (north). */
struct NavTileImage {
  int w = 0, h = 0;
  std::vector<unsigned char> rgba;
};

class NavTileSource {
public:
  enum class Kind { MBTiles, Directory, Url };
  enum class Fetch { Ok, Missing, Failed };

  ~NavTileSource();
  NavTileSource(const NavTileSource &) = delete;
  NavTileSource &operator=(const NavTileSource &) = delete;

  Kind GetKind() const;
  /** The spec it was opened with. */
  const std::string &Spec() const;
  /** MBTiles metadata `name`, else the spec. */
  const std::string &Name() const;
  /** Metadata `attribution` with HTML tags removed, "" when there is none. */
  const std::string &Attribution() const;
  /** Zoom levels the source holds (MBTiles metadata or table, the directory's levels, 0..19 for
   *  a URL). */
  int MinZoom() const;
  int MaxZoom() const;

  /** The tile @p z / @p x / @p y (XYZ numbering: x east from 180 deg W, y south from 85.05 deg N).
   *  @return Ok with the decoded tile in @p out; Missing when the source has no such tile (or is
   *  offline and has no cached copy); Failed with a message (source, tile, what is wrong) when
   *  the tile's data cannot be read or decoded. */
  Fetch Get(int z, int x, int y, NavTileImage *out, std::string *error);

  /** "" or why tiles were not fetched (a URL source that found the server unreachable). */
  std::string OfflineNote() const;

  struct Impl;

private:
  explicit NavTileSource(std::unique_ptr<Impl> impl);
  friend bool NavTileSourceOpen(const std::string &spec, std::shared_ptr<NavTileSource> *out,
                                std::string *error);
  std::unique_ptr<Impl> impl_;
};

/** Open the tile source @p spec (kept for the life of the process: the same spec gives the same
 *  source). Checks what can be checked without drawing: the file is an MBTiles database with
 *  raster tiles, the directory exists and holds zoom levels, the template has {z}, {x} and {y}.
 *  @return false with "SPEC: error: what is wrong; what is expected". */
bool NavTileSourceOpen(const std::string &spec, std::shared_ptr<NavTileSource> *out, std::string *error);

/** The Web-Mercator zoom whose 256-pixel tiles have @p m_per_px metres per pixel at latitude
 *  @p lat_deg (not rounded, not clamped). */
double NavTileZoomForScale(double m_per_px, double lat_deg);

/** Maps a display pixel position (x right, y up, origin at the image's bottom-left corner) to
 *  latitude, longitude [deg]; false: the pixel shows no point of the Earth. */
using NavMapFromPixel = std::function<bool(double px, double py, double *lat_deg, double *lon_deg)>;

/** What NavMapPaintTiles drew. */
struct NavTilePaint {
  int zoom = -1;         /**< the zoom level used; -1: none (the scale is beyond the source's levels) */
  int tiles = 0;         /**< tiles drawn */
  int missing = 0;       /**< tiles the view needed that the source does not have */
  int failed = 0;        /**< tiles that could not be read or decoded */
  double coverage = 0.0; /**< fraction of the image's pixels painted from tiles */
  std::vector<std::string>
      notes; /**< for the map's credits (offline, first failure, no tiles at this scale) */
};

/** Paint the tiles of @p src over @p rgb (@p w x @p h x 3 bytes, row 0 at the bottom; tile
 *  transparency blends with what is there). The zoom is the nearest to NavTileZoomForScale(
 *  @p m_per_px, @p lat_deg), lowered to the source's MaxZoom (the tiles are then magnified); below
 *  its MinZoom nothing is painted. Each pixel centre is mapped through @p from_pixel to lat/lon
 *  and into the Web-Mercator tile (bilinear), so any map projection is resampled exactly. */
void NavMapPaintTiles(NavTileSource &src, const NavMapFromPixel &from_pixel, double m_per_px, double lat_deg,
                      int w, int h, std::vector<unsigned char> *rgb, NavTilePaint *result);

/** The credit line of a tile layer: "map tiles: ATTRIBUTION" from @p attribution_override, else
 *  the source's attribution, else its name with "(no attribution given)". */
std::string NavTileCredit(const NavTileSource &src, const std::string &attribution_override);

#endif /* NAV_MAP_TILES_H */
