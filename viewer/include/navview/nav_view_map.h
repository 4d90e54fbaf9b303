/**
 * @file nav_view_map.h
 * @brief Geodetic map view: reference, estimated and GNSS tracks in latitude/longitude over an
 *        offline background (Natural Earth shaded relief and GSHHS coastlines from Debian's
 *        python-cartopy-data), with a graticule and a scale bar; below about 20 km across, a
 *        local metric grid replaces the graticule (the background thins out at street scale).
 *
 * Projection: equirectangular about the view centre (x = R cos(lat0) dlon, y = R dlat, metres),
 * which is what a lat/lon plot with a 1:cos(lat0) aspect shows. No VTK types here.
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
  /** Directory of the cartopy data (shapefiles/, raster/); empty: $NAVVIEW_MAP_DATA, else
   *  /usr/share/cartopy/data. Missing files leave the background blank with a note. */
  std::string data_dir;
  int multisamples = 8;
};

/** Graticule step [deg] (1-2-5 x 10^k, or 10/15/30) for a view @p span_deg across: 3 to 8 lines. */
double NavGraticuleStepDeg(double span_deg);

/** Render the map of @p result to the PNG @p path. Needs an X server. */
bool NavRenderMapPng(const NavResult &result, const NavMapOptions &options, const std::string &path,
                     std::string *error);

/** Open the map of @p result in an interactive window (drag = pan, wheel or +/- = zoom, r = reset,
 *  q = quit) and run its event loop until it is closed. Needs an X server. */
bool NavRunMapInteractive(const NavResult &result, const NavMapOptions &options, std::string *error);

/** Read the polylines (parts of polygon or arc shapes) of an ESRI shapefile (.shp), lon/lat in
 *  degrees, 2 per point. For the map background; public for its unit test. */
bool NavReadShapefile(const std::string &shp_path, std::vector<std::vector<double>> *parts, std::string *error);

#endif /* NAV_VIEW_MAP_H */
