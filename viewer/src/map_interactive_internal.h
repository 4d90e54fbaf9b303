/**
 * @file map_interactive_internal.h
 * @brief The interactive geodetic map window (private): the map of NavBuildMap in an on-screen
 *        window, north up, with pan (left or middle drag), zoom (wheel, +/-) and reset (r). Tests
 *        drive it without an event loop through Key(), Zoom() and Pan() (toolchain.md section 4).
 */
#ifndef NAV_MAP_INTERACTIVE_INTERNAL_H
#define NAV_MAP_INTERACTIVE_INTERNAL_H

#include <string>

#include <vtkSmartPointer.h>

#include "navview/nav_view_map.h"
#include "navview/nav_view_result.h"

class vtkRenderer;
class vtkRenderWindow;
class vtkRenderWindowInteractor;
class vtkNavMapStyle;

/** Extent of a built map view: the projected width and height shown [m]. */
struct NavMapExtent {
  double span_x_m = 0.0, span_y_m = 0.0;
};

/** The fitted map of a result: the projection centre (azimuthal equidistant) and the width that
 *  frames the tracks (or the options' span); the tracks' box in the projection [m]. */
struct NavMapFrame {
  double lat0_rad = 0.0, lon0_rad = 0.0;
  double fit_span_x_m = 0.0;
  double track_box_m[4] = {0, 0, 0, 0}; /**< x0, y0, x1, y1 */
};

/** The widest view drawn [m] (200 deg of arc). */
double NavMapMaxSpanM();

/** Fit the map of @p result (centre and width, from the options or the tracks). */
bool NavMapFit(const NavResult &result, const NavMapOptions &options, NavMapFrame *frame, std::string *error);

/** Replace the props of @p ren by the map of @p result for the view centred at (@p cx_m, @p cy_m)
 *  in the frame's projection, @p span_x_m wide (height from the options' aspect): land and water,
 *  rivers, borders, graticule or grid, tracks, scale bar, title, legend and place names. The
 *  camera is left as it is. @p info (may be null) receives what was drawn. */
bool NavBuildMapView(const NavResult &result, const NavMapOptions &options, const NavMapFrame &frame, double cx_m,
                     double cy_m, double span_x_m, vtkRenderer *ren, NavMapInfo *info, std::string *error);

/** Add the fitted map of @p result to @p ren (NavMapFit, then NavBuildMapView at the centre) and
 *  set its camera (parallel projection, north up); @p extent receives the view's size. The
 *  caller owns the window; needs an X display (NavCheckDisplay). */
bool NavBuildMap(const NavResult &result, const NavMapOptions &options, vtkRenderer *ren, NavMapExtent *extent,
                 std::string *error, NavMapFrame *frame = nullptr, NavMapInfo *info = nullptr);

class NavMapInteractive {
public:
  NavMapInteractive();
  ~NavMapInteractive();
  NavMapInteractive(const NavMapInteractive &) = delete;
  NavMapInteractive &operator=(const NavMapInteractive &) = delete;

  /** Build the map in an on-screen window (@p result must outlive this object) with its interactor and style, Initialize() and render
   *  once. Start() is left to the caller. */
  bool Open(const NavResult &result, const NavMapOptions &options, std::string *error);
  /** A key by its X keysym: "plus"/"equal"/"KP_Add" zoom in, "minus"/"KP_Subtract" out, "r"
   *  reset, "q"/"Escape" quit. @return whether it is one of the map's keys. */
  bool Key(const std::string &keysym);
  /** Zoom about the view centre by @p factor (> 1 zooms in), within 1/50 .. 20 000 x the fit
   *  (and at most the widest map drawn), then rebuild. */
  void Zoom(double factor);
  /** Zoom about the display pixel (@p px, @p py) (origin bottom left): the map point under it
   *  stays there; then rebuild. */
  void ZoomAt(double factor, double px, double py);
  /** Move the view by (dx, dy) display pixels (the map follows the pointer); rebuild the map for
   *  the new view unless @p rebuild is false (during a drag, rebuilt on release). */
  void Pan(double dx_px, double dy_px, bool rebuild = true);
  /** Rebuild the map for the camera's view (land, labels, scale bar, title's "km across"). */
  bool Rebuild();
  /** Back to the fitted view. */
  void Reset();
  /** Half the height shown [m] (the camera's parallel scale). */
  double Scale() const;

  vtkSmartPointer<vtkRenderWindow> Window;
  vtkSmartPointer<vtkRenderer> Renderer;
  vtkSmartPointer<vtkRenderWindowInteractor> Iren;
  vtkSmartPointer<vtkNavMapStyle> Style;
  NavMapExtent Extent;
  const NavResult *Result = nullptr; /**< borrowed from Open()'s caller, who keeps it alive */
  NavMapOptions Options;
  NavMapFrame Frame;
  NavMapInfo Info;          /**< what the last build drew */
  double LastRebuildMs = 0; /**< the last Rebuild(), layers and render [ms] */
};

#endif /* NAV_MAP_INTERACTIVE_INTERNAL_H */
