/**
 * @file scene_view_impl.h
 * @brief NavSceneViewImpl: the VTK side of NavSceneView (private; F3D-style *_impl split).
 */
#ifndef NAV_SCENE_VIEW_IMPL_H
#define NAV_SCENE_VIEW_IMPL_H

#include <memory>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"
#include "navview/nav_view_scene.h"

class vtkActor;
class vtkLookupTable;
class vtkPolyData;
class vtkRenderWindow;
class vtkRenderer;
class vtkScalarBarActor;
class vtkTextActor;

class NavSceneViewImpl {
public:
  std::shared_ptr<const NavResult> Result;
  NavViewOptions Options;
  NavSceneModel Model;
  bool Built = false;
  bool Offscreen = true;
  double TimeS = NAN;
  bool Follow = false;

  vtkSmartPointer<vtkRenderWindow> Window;
  vtkSmartPointer<vtkRenderer> Renderer; /**< the 3D scene */
  vtkSmartPointer<vtkRenderer> Panel;    /**< legend, scalar bar and notes on the right (with text) */
  double PanelFraction = 0.0;            /**< width of the panel / window width */
  vtkSmartPointer<vtkActor> Vehicle;
  vtkSmartPointer<vtkActor> EstimateMarker;
  vtkSmartPointer<vtkActor> EstimateActor; /**< the estimated path (pick target) */
  vtkSmartPointer<vtkTextActor> Title;
  vtkSmartPointer<vtkTextActor> Readout;
  vtkSmartPointer<vtkTextActor> PickText;
  vtkSmartPointer<vtkTextActor> Info; /**< notes at the bottom of the panel */
  vtkSmartPointer<vtkScalarBarActor> ScalarBar;
  vtkSmartPointer<vtkLookupTable> ErrorLut;
  double VehiclePosR[3] = {0, 0, 0};
  bool VehiclePlaced = false;
  double PickRadiusM = 0.0;
  size_t GnssDrawn = 0; /**< GNSS fixes drawn after display thinning */

  /** Create (or re-create, when the on/offscreen mode changes) the window and renderer. */
  bool EnsureWindow(bool offscreen, std::string *error);
  /** Camera preset (framing Model.bounds_r) or the options' fixed camera. */
  void SetupCamera();
  /** Metres per pixel of the current camera at the nearest corner of the paths' bounds. */
  double MetresPerPixel() const;
  /** Model, actors, camera (unless kept), time. */
  bool BuildScene(bool offscreen, std::string *error, bool keep_camera = false);
  void UpdateTime();
  int FontSize(double scale) const;

  void AddPaths();
  void AddEnvelope();
  void AddGnss();
  void AddEllipsoids();
  void AddTriads();
  void AddGrid();
  void AddAxesAndScale();
  void AddVehicle();
  void AddText();
  /** Legend, scalar bar and notes in the side panel; sets PanelFraction. */
  void AddPanel();
  /** Fit the camera so that the points (x, y, z triples, frame r) appear inside the NDC
   *  rectangle (x0, x1, y0, y1) of the 3D viewport. */
  void FitCamera(const std::vector<double> &pts, const double rect[4]);
  /** Text centred at a world point (frame r), shifted by (dx, dy) pixels. */
  vtkSmartPointer<vtkTextActor> Label3D(const char *text, const double pos[3], const double rgb[3],
                                        double scale, int dx_px, int dy_px);
};

#endif /* NAV_SCENE_VIEW_IMPL_H */
