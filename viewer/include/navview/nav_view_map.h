/**
 * @file nav_view_map.h
 * @brief Geodetic map view: reference, estimated and GNSS tracks in latitude/longitude over an
 *        offline map: land and water filled from GSHHG shorelines (lakes, islands in lakes) at a
 *        resolution chosen by the scale, WDBII rivers and borders, place names from a GeoNames
 *        gazetteer chosen by population, a graticule (below about 20 km across a local metric
 *        grid) and a scale bar; no label overlaps another (nav_map_data.h, docs/map-data.md).
 *
 * Projection: azimuthal equidistant about the projection centre (x east, y north, metres):
 * distances and directions from the centre are true, and a view over a pole or across the date
 * line has no seam. No VTK types here.
 */
#ifndef NAV_VIEW_MAP_H
#define NAV_VIEW_MAP_H

#include <cmath>
#include <string>
#include <vector>

#include "navview/nav_view_result.h"

struct NavMapOptions {
  int width_px = 1000;
  int height_px = 700;
  /** Width of the view [km]; <= 0: fit the tracks (15 % margin, at least 200 m). */
  double span_km = 0.0;
  /** View centre [deg]; NaN: the centre of the tracks. */
  double center_lat_deg = NAN, center_lon_deg = NAN;
  bool show_text = true;
  /** GNSS fixes and outage highlighting (gnss.csv, gnss_outages.csv). */
  bool show_gnss = true;
  /** Directory of the GSHHG binned files (binned_GSHHS_f.nc ...); empty: NavMapGshhgDir()
   *  ($NAVVIEW_GSHHG_DIR, else /usr/share/gmt-gshhg). Missing files leave the sea tint with a note. */
  std::string data_dir;
  /** Gazetteer (places.tsv); empty: NavMapPlacesFile(). None: no place names, with a note. */
  std::string places_file;
  bool show_places = true;
  int multisamples = 8;
  /** Optional raster tile layer (streets at street scale) drawn over the GSHHG fill and under
   *  the lines, tracks and texts: an MBTiles file, an XYZ directory or template, or an XYZ URL
   *  template (nav_map_tiles.h); empty: none. A source that cannot be opened fails the build. */
  std::string tiles;
  /** Credit for the tiles shown on the map; empty: the MBTiles metadata's attribution. */
  std::string tiles_attribution;
};

/** A text placed on the map, as a box in display pixels (origin bottom left). */
struct NavMapLabel {
  enum Kind { Place, Graticule, ScaleBar, Title, Legend } kind = Place;
  std::string text;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/** What a map build drew: for tests, the interactive title and the speed report. */
struct NavMapInfo {
  int width_px = 0, height_px = 0;
  double span_x_m = 0.0, span_y_m = 0.0; /**< width and height shown [m] */
  double proj_lat_deg = 0.0, proj_lon_deg = 0.0; /**< projection centre */
  double view_x_m = 0.0, view_y_m = 0.0;         /**< view centre in the projection [m] */
  char shore_res = 0;                            /**< GSHHG resolution letter (c l i h f), 0: none */
  int bins = 0;                                  /**< GSHHG bins read */
  int tile_zoom = -1;                            /**< zoom of the tile layer drawn, -1: none */
  int tiles = 0;                                 /**< tiles drawn */
  double tile_coverage = 0.0;                    /**< fraction of the view painted from tiles */
  std::string tile_credit;                       /**< the tiles' credit line ("" without tiles) */
  std::vector<NavMapLabel> labels;               /**< every text placed, place names first */
  std::vector<std::string> notes;                /**< missing data */
  double build_ms = 0.0;                         /**< time to build the layers (no render) */
  /** Display pixel (origin bottom left, may lie outside the view) of @p lat_deg, @p lon_deg. */
  void PixelOf(double lat_deg, double lon_deg, double *px, double *py) const;
};

/** Graticule step [deg] (1-2-5 x 10^k, or 10/15/30) for a view @p span_deg across: 3 to 8 lines. */
double NavGraticuleStepDeg(double span_deg);

/** Render the map of @p result to the PNG @p path. Needs an X server. */
bool NavRenderMapPng(const NavResult &result, const NavMapOptions &options, const std::string &path,
                     std::string *error, NavMapInfo *info = nullptr);

/** Open the map of @p result in an interactive window (drag = pan, wheel or +/- = zoom, r = reset,
 *  q = quit) and run its event loop until it is closed. Needs an X server. */
bool NavRunMapInteractive(const NavResult &result, const NavMapOptions &options, std::string *error);

/** Read the polylines (parts of polygon or arc shapes) of an ESRI shapefile (.shp), lon/lat in
 *  degrees, 2 per point. For the map background; public for its unit test. */
bool NavReadShapefile(const std::string &shp_path, std::vector<std::vector<double>> *parts, std::string *error);

#endif /* NAV_VIEW_MAP_H */
