/**
 * @file scene_view_impl.h
 * @brief NavSceneViewImpl: the VTK side of NavSceneView (private; F3D-style *_impl split).
 */
#ifndef NAV_SCENE_VIEW_IMPL_H
#define NAV_SCENE_VIEW_IMPL_H

#include <array>
#include <memory>
#include <utility>
#include <string>
#include <vector>

#include <vtkSmartPointer.h>

#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"
#include "navview/nav_view_scene.h"

class vtkActor;
class vtkGlyph3DMapper;
class vtkLookupTable;
class vtkPolyData;
class vtkRenderWindow;
class vtkRenderer;
class vtkScalarBarActor;
class vtkTextActor;

/** The legend panel takes at most this fraction of the window's width. */
constexpr double kLegendMaxFraction = 0.26;
/** The smallest legend font of a narrow view [px]. */
constexpr int kLegendMinFontPx = 8;

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
  bool LegendCompact = false;            /**< the legend draws its entries' short forms (AddPanel) */
  int LegendFontPx = 0;                  /**< the legend's font size [px] */
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

  /** Embedded in another program's window (navstudio): our renderer draws over @c Under (its
   *  camera, one layer up), the legend panel takes the window's right side. */
  vtkRenderWindow *External = nullptr;
  vtkRenderer *Under = nullptr;
  /** Triad glyph mappers (their scale follows the view) and their nominal size factors. */
  std::vector<vtkSmartPointer<vtkGlyph3DMapper>> TriadMappers;
  std::vector<double> TriadFactors;
  /** The triads at the playback time (reference and estimate), moved by UpdateTime. */
  vtkSmartPointer<vtkPolyData> NowRef, NowEst;
  vtkSmartPointer<vtkActor> EnvelopeActor;
  std::vector<vtkSmartPointer<vtkActor>> EllipsoidActors;
  double ScaleMpp = 0.0;
  std::string Legend; /**< the legend entries' text (AddPanel) */
  /** Out-of-date marking: every actor's colour faded towards grey (originals kept), title says so. */
  bool Stale = false;
  std::vector<std::pair<vtkSmartPointer<vtkActor>, std::array<double, 3>>> StaleColors;
  std::string TitleText;
  void ApplyStale();
  double FollowHeading[2] = {0.0, 1.0}; /**< last horizontal direction of travel (frame r) */ /**< metres per pixel the scale-dependent sizes were set for */

  /** Triad arrow length for the current view [m]: the model's, or sized for the follow camera. */
  double ViewTriadSize() const;
  /** Follow-camera distance [m] (the options' or automatic). */
  double FollowDistance() const;
  /** Place the follow camera at the vehicle (reference position and heading at TimeS). */
  void PlaceFollowCamera(const double p_ref[3]);
  /** Re-size the triads, the vehicle and the envelope floor for the current view scale. */
  void UpdateScale(bool force);

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
