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

/** Add the map of @p result (background, graticule or metric grid, tracks, GNSS, scale bar, text)
 *  to @p ren and set its camera (parallel projection, north up); @p extent receives the view's
 *  size. The caller owns the window; needs an X display (NavCheckDisplay). */
bool NavBuildMap(const NavResult &result, const NavMapOptions &options, vtkRenderer *ren, NavMapExtent *extent,
                 std::string *error);

class NavMapInteractive {
public:
  NavMapInteractive();
  ~NavMapInteractive();
  NavMapInteractive(const NavMapInteractive &) = delete;
  NavMapInteractive &operator=(const NavMapInteractive &) = delete;

  /** Build the map in an on-screen window with its interactor and style, Initialize() and render
   *  once. Start() is left to the caller. */
  bool Open(const NavResult &result, const NavMapOptions &options, std::string *error);
  /** A key by its X keysym: "plus"/"equal"/"KP_Add" zoom in, "minus"/"KP_Subtract" out, "r"
   *  reset, "q"/"Escape" quit. @return whether it is one of the map's keys. */
  bool Key(const std::string &keysym);
  /** Zoom about the view centre by @p factor (> 1 zooms in), within 1/50 .. 20 000 x the fit. */
  void Zoom(double factor);
  /** Move the view by (dx, dy) display pixels (the map follows the pointer). */
  void Pan(double dx_px, double dy_px);
  /** Back to the fitted view. */
  void Reset();
  /** Half the height shown [m] (the camera's parallel scale). */
  double Scale() const;

  vtkSmartPointer<vtkRenderWindow> Window;
  vtkSmartPointer<vtkRenderer> Renderer;
  vtkSmartPointer<vtkRenderWindowInteractor> Iren;
  vtkSmartPointer<vtkNavMapStyle> Style;
  NavMapExtent Extent;
};

#endif /* NAV_MAP_INTERACTIVE_INTERNAL_H */
