/*
 * navstudio: the offline background of the map view: land and water filled from GSHHG (libnavview's
 * map data), or else GSHHS coastlines and lakes (read through
 * libnavview's shapefile reader from Debian's python-cartopy-data) and a lat/lon graticule with
 * labels, both in the view's local frame (x = East, y = North, metres from the scene origin).
 * Plain data; PathView turns it into VTK actors. GUI thread only.
 */
#ifndef NAVSTUDIO_MAP_BACKGROUND_H
#define NAVSTUDIO_MAP_BACKGROUND_H

#include <QString>

#include <string>
#include <vector>

#include "navview/nav_map_data.h"

extern "C" {
#include "navcore/nav_scene.h"
}

namespace studio {

struct MapLabel {
  std::string text;
  double x = 0.0, y = 0.0; /**< local East/North of the label's anchor [m] */
  bool latitude = false;   /**< a parallel (anchored on the right edge), else a meridian (top edge) */
};

/** A place name on the map: its dot and the bottom-left corner of its text (local East/North [m]). */
struct MapPlace {
  std::string name;
  double dot_x = 0.0, dot_y = 0.0, text_x = 0.0, text_y = 0.0;
  int size_pt = 0;
  bool bold = false;
};

struct MapBackground {
  std::vector<std::vector<double>> coast;     /**< polylines, x/y pairs [m] */
  std::vector<std::vector<double>> rivers, borders; /**< GSHHG WDBII polylines, x/y pairs [m] */
  /** Land and water of the rectangle painted by libnavview (NavMapPaintAreas): land_w x land_h
   *  RGB pixels, row 0 at the bottom; empty when no pixel size was given or GSHHG is missing. */
  std::vector<unsigned char> land_rgb;
  int land_w = 0, land_h = 0;
  char shore_res = 0; /**< GSHHG resolution letter of the fill, 0: none */
  std::vector<std::vector<double>> graticule; /**< polylines, x/y pairs [m] */
  std::vector<MapLabel> labels;
  double lat_step_deg = 0.0, lon_step_deg = 0.0;
  QString note; /**< "" or why there is no coastline (data missing) */
  /** The user's tile layer, painted into land_rgb over the GSHHG fill: its credit line ("" when
   *  no tile was drawn), the zoom used (-1: none) and the share of the view it covers. */
  QString tile_credit;
  int tile_zoom = -1;
  double tile_coverage = 0.0;
  /** Place names (GeoNames gazetteer, chosen like navview's map: NavMapChoosePlaces), when a
   *  text measure was given. */
  std::vector<MapPlace> places;
  bool have_gazetteer = false; /**< a gazetteer was found and read */
};

/** The map's optional tile layer (nav_map_tiles.h): an MBTiles file, an XYZ directory or
 *  template, or an XYZ URL template; @c attribution overrides the source's own credit. */
struct MapTiles {
  std::string source, attribution;
};

/** Views narrower than this [m] are "street scale": the local metric grid, no graticule. */
constexpr double kStreetScaleSpanM = 20e3;
/** Views wider than this [m] show the coastlines (GSHHS crude, ~25 km). */
constexpr double kCoastSpanM = 15e3;

/** The cartopy data directory: $NAVVIEW_MAP_DATA, else /usr/share/cartopy/data. */
std::string MapDataDir();

/** Coastlines (when the rectangle is wider than kCoastSpanM) and the graticule with labels for
 *  the local rectangle [x0, x1] x [y0, y1] (East, North [m]) of the scene @p s. With a pixel size
 *  (@p w_px, @p h_px > 0) also land and water at every scale, from GSHHG at the resolution of the
 *  scale (navview's map data, nav_map_data.h), and rivers and borders above kCoastSpanM; the
 *  coastlines then come from GSHHG too (python-cartopy-data only when GSHHG is missing). With
 *  @p tiles (and a pixel size) the tiles are resampled into the same image, over the fill; a
 *  source that cannot be opened leaves the fill and says why in the note. With @p text_size (the
 *  view's font measure) also the place names, clear of the caption (bottom), the legend (top
 *  right) and the graticule labels. */
void BuildMapBackground(const nav_scene &s, double x0, double y0, double x1, double y1, MapBackground *out,
                        int w_px = 0, int h_px = 0, const MapTiles *tiles = nullptr,
                        const NavMapTextSize &text_size = NavMapTextSize());

} // namespace studio

#endif
