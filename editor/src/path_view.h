/*
 * navstudio: the map view (top-down, parallel projection, local grid with geodetic read-out) and
 * the 3D view (perspective, ground plane) of the scene, both plain VTK in a native OpenGL window
 * of their own (QVTKOpenGLStereoWidget: a QVTKOpenGLWindow in a window container). A view
 * swaps its own frames: Qt does not compose it into the main window's frame, which with Mesa's
 * software renderer cost about 20 ms per frame (live preview, urban-drive: edit-to-picture
 * median 116-125 ms with QVTKOpenGLNativeWidget, 98-102 ms with native windows, all else equal).
 * The price: QWidget::grab() of a parent shows no view (Grab() reads a view's frame from VTK's
 * framebuffer for screenshots), and a resize needs care: a view renders at once at its new size
 * and once more after that frame's swap (resize_redraws_views). Click on the ground adds a waypoint (Ctrl+click inserts it into the
 * nearest leg), dragging a waypoint's handle moves it (Shift+drag in 3D changes its height),
 * Delete removes the selected one. The smooth path comes from navcore's waypoint model.
 * World axes: x = East, y = North, z = Up, metres from the scene origin.
 */
#ifndef NAVSTUDIO_PATH_VIEW_H
#define NAVSTUDIO_PATH_VIEW_H

#include <QStringList>
#include <QTimer>
#include <QWidget>

#include <memory>
#include <vector>

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include "studio_scene.h"

class NavSceneView;
struct NavResult;
struct NavViewOptions;
class QImage;
class QWindow;
class QVTKOpenGLStereoWidget;
class vtkActor;
class vtkImageData;
class vtkPlaneSource;
class vtkBillboardTextActor3D;
class vtkGenericOpenGLRenderWindow;
class vtkPolyData;
class vtkRenderer;
class vtkRenderWindowInteractor;
class vtkTextActor;

namespace studio {

class PathViewStyle;

class PathView : public QWidget {
  Q_OBJECT
public:
  enum class Mode { Map, ThreeD };
  PathView(SceneDocument *doc, Mode mode, QWidget *parent = nullptr);
  ~PathView() override;

  Mode GetMode() const { return mode_; }
  /** Rebuild waypoints and path from the document and render. */
  void Rebuild();
  /** Estimated path to draw over the reference (local NED, 3 per epoch); @p preview: live preview
   *  colour, else the Monte Carlo result's (the one it replaces stays drawn in grey for A/B
   *  comparison). Empty clears it. */
  void SetEstimate(const std::vector<double> &ned, bool preview);
  /** Error envelope around the estimate: the region within @p half_width_m[i] of the points
   *  @p ned (3 per point, local NED), drawn as one light blue region under the paths (k x the
   *  filter's reported sigma for a preview, k x the RMS over runs for a Monte Carlo result; the
   *  legend says which). Empty clears it. */
  void SetEnvelope(const std::vector<double> &ned, const std::vector<double> &half_width_m, bool preview);
  /** Two per epoch of the drawn envelope band (its two edges; tests). */
  size_t EnvelopePointCount();
  /** The legend's entries, top to bottom (the map always; the 3D view until a result scene with
   *  its own legend is shown). */
  QStringList LegendEntries() const { return legend_entries_; }
  /** GNSS outages drawn as pink bands along the plan (tests). */
  int OutageSpanCount() const { return outage_spans_; }
  /** 3D view: show @p result through libnavview's scene (NavSceneView, the scene of navview and
   *  `navsim render`): reference and estimate, attitude triads, vehicle, outages, error tube and
   *  ellipsoids, legend, read-out; the editor's own estimate and band are hidden meanwhile.
   *  nullptr clears it. The playback time is kept when @p keep_time. false with @p error. */
  bool SetSceneResult(std::shared_ptr<const NavResult> result, const NavViewOptions &options, bool keep_time,
                      QString *error);
  /** The result's scene (nullptr when none is shown). */
  NavSceneView *Scene() { return scene_.get(); }
  std::shared_ptr<const NavResult> SceneResult() const { return scene_result_; }
  /** Mark the shown result as out of date (greyed caption "out of date: edited after the run"). */
  void SetSceneStale(bool stale);
  bool SceneStale() const { return scene_stale_; }
  /** Hide the editing overlay (waypoint handles, labels, drop lines) while the follow camera is
   *  close to the vehicle: a handle sphere near the camera would fill the view. */
  void SetEditOverlayHidden(bool hidden);
  /** Fit the camera to the scene and rebuild the grid. */
  void ResetCamera();
  /** Render now (a hidden view, or one collapsed to no area, renders when it is shown again). */
  void Render();

  /** The caption at the view's bottom-left (tests). */
  QString CaptionText() const;
  /** Width of the drawn caption [px] (tests: it fits the view). */
  int CaptionWidth();
  /** VTK display coordinates (origin bottom-left) of a local N/E/D point; false if off-screen. */
  bool DisplayOf(double n, double e, double d, int *x, int *y);
  /** Ground point (local N, E at height -d_plane) under a VTK display point. */
  bool GroundAt(int x, int y, double d_plane, double *n, double *e);
  vtkRenderWindowInteractor *Interactor();
  /** The view's native window (receives the mouse and keys; tests send Qt events to it). */
  QWindow *NativeWindow();
  /** This view's last frame, read from VTK's framebuffer (a pending render first; screenshots). */
  QImage Grab();
  /** Frames this view has swapped to the screen so far (benchmarks, tests). */
  long FrameCount() const { return frame_count_; }
  /** A render of this view is due or has not reached the screen yet (tests wait for quiet views). */
  bool FramePending() const { return render_count_ != swapped_render_count_ || render_timer_.isActive(); }
  int SelectedWaypoint() const { return selected_; }
  void SetSelectedWaypoint(int i);
  /** 3D view: drop lines drawn from waypoints off the ground plane (tests). */
  size_t StemCount();
  /** Number of points of the drawn reference path (tests). */
  size_t PathPointCount();
  /** Samples of the drawn path over a vehicle limit (coloured red; tests). */
  size_t OverLimitPointCount();
  /** The drawn reference path (brought up to date first). */
  const PathSamples &Path();

  /** Map view: centre the camera on local N/E [m] showing @p half_height_m above and below. */
  void SetMapExtent(double n, double e, double half_height_m);
  /** Map background (tests): coastline and graticule polylines drawn, graticule labels, and
   *  whether the local metric grid is shown (street scale). */
  size_t CoastlineCount() const { return coast_count_; }
  /** GSHHG resolution letter of the land/water fill now shown (c l i h f), 0 when none. */
  char LandResolution() const { return land_res_; }
  /** The land/water fill's colour at local East/North (@p e, @p n) [m] as 0xRRGGBB; -1 when no
   *  fill is shown or the point is outside the view. */
  long LandColourAt(double e, double n) const;
  /** Map view: zoom by @p factor (> 1: in) about VTK display point @p x, @p y (origin bottom
   *  left), which keeps showing the same ground point (the mouse wheel, 1.25 a step). false in
   *  the 3D view or off the ground. */
  bool ZoomMapAt(int x, int y, double factor);
  /** Map view: the tile layer drawn over the land/water fill (View > Map tiles...; an MBTiles
   *  file, an XYZ directory or template, or a URL template; empty source: none). Rebuilds the
   *  background. */
  void SetMapTiles(const QString &source, const QString &attribution);
  /** The tile layer's credit shown in the caption ("" when no tile is drawn) and its zoom (-1). */
  QString MapTilesCredit() const { return tile_credit_; }
  int MapTileZoom() const { return tile_zoom_; }
  size_t GraticuleCount() const { return graticule_count_; }
  /** Map view: the place names shown (GeoNames gazetteer; none without it). */
  QStringList PlaceNames() const { return place_names_; }
  QStringList GraticuleLabels() const;
  bool MetricGridShown() const;
  /** During a live drag, draw a changed path with the next estimate (SetEstimate), at most
   *  @p ms later; 0: at once (live preview off). */
  void SetLiveRenderDelay(int ms) { live_render_delay_ms_ = ms; }
  /** Number of renders of this view so far (benchmarks, tests). */
  long RenderCount() const { return render_count_; }
  /** Bring the map background up to date with the camera now (normally deferred). */
  void UpdateBackground();
  /** Give VTK's window the native window's current size (it learns it only when Qt paints). */
  void SyncSize();

signals:
  void SelectionChanged(int waypoint);
  /** Cursor read-out text (status bar). */
  void CursorText(const QString &text);
  /** A frame of this view reached the screen (swapped). */
  void FrameSwapped();

private:
  friend class PathViewStyle;
  // Interaction (called by the interactor style).
  bool OnPress(int x, int y, bool ctrl, bool shift);
  void OnDrag(int x, int y, bool shift);
  void OnRelease();
  void OnClick(int x, int y, bool ctrl);
  void OnHover(int x, int y);
  void OnDeleteKey();
  int PickWaypoint(int x, int y);
  /** World points (x = E, y = N, z = Up) at the near and far planes under display point x, y. */
  bool RayAt(int x, int y, double a[3], double b[3]);
  /** Height (Up) of the point of the vertical line through local N/E @p n, @p e nearest to the
   *  ray under display point x, y; false when the line of sight is (nearly) vertical. */
  bool HeightUnder(int x, int y, double n, double e, double *up);
  void UpdateGrid(double cx, double cy, double extent);
  void UpdateCaption();
  void UpdateLegend();
  void resizeEvent(QResizeEvent *e) override;
  void showEvent(QShowEvent *e) override;

  SceneDocument *doc_;
  Mode mode_;
  std::unique_ptr<NavSceneView> scene_;
  std::shared_ptr<const NavResult> scene_result_;
  bool scene_stale_ = false;
  bool overlay_hidden_ = false;
  vtkSmartPointer<vtkTextActor> stale_text_;
  QVTKOpenGLStereoWidget *widget_ = nullptr;
  vtkSmartPointer<vtkGenericOpenGLRenderWindow> window_;
  vtkSmartPointer<vtkRenderer> renderer_;
  vtkSmartPointer<PathViewStyle> style_;
  vtkSmartPointer<vtkActor> grid_, ground_, path_actor_, over_actor_, handles_, selected_actor_, estimate_, result_, previous_, bad_actor_;
  vtkSmartPointer<vtkActor> envelope_; // band around the estimate (SetEnvelope)
  vtkSmartPointer<vtkActor> outages_;  // GNSS outages along the plan
  int outage_spans_ = 0;
  size_t envelope_epochs_ = 0;
  bool envelope_preview_ = true;
  std::vector<vtkSmartPointer<vtkTextActor>> legend_;
  QStringList legend_entries_;
  vtkSmartPointer<vtkActor> stems_;    // 3D view: drop lines of waypoints off the ground plane
  vtkSmartPointer<vtkTextActor> caption_, problem_;
  std::vector<vtkSmartPointer<vtkBillboardTextActor3D>> labels_;
  PathSamples path_;
  int selected_ = -1;
  // Drag state.
  int drag_index_ = -1;
  bool dragging_ = false;
  int press_x_ = 0, press_y_ = 0;
  double drag_d_ = 0.0;
  std::unique_ptr<nav_scene> drag_before_;
  QTimer rebuild_timer_;
  // Map background (coastlines, graticule and its labels), rebuilt when the view moves.
  vtkSmartPointer<vtkActor> coast_, graticule_, rivers_, borders_;
  /** Land and water (GSHHG through libnavview), a textured quad covering the view. */
  vtkSmartPointer<vtkActor> land_;
  vtkSmartPointer<vtkPlaneSource> land_plane_;
  vtkSmartPointer<vtkImageData> land_image_;
  char land_res_ = 0;
  std::vector<vtkSmartPointer<vtkTextActor>> geo_labels_;
  std::vector<vtkSmartPointer<vtkTextActor>> place_labels_;
  vtkSmartPointer<vtkActor> place_dots_;
  QStringList place_names_;
  QTimer bg_timer_;
  double bg_key_[5] = {0, 0, 0, 0, 0};
  bool street_ = true;
  size_t coast_count_ = 0, graticule_count_ = 0;
  QString bg_note_;
  std::string tiles_source_, tiles_attribution_;
  QString tile_credit_;
  int tile_zoom_ = -1;
  double graticule_step_deg_ = 0.0;
  long render_count_ = 0, frame_count_ = 0, swapped_render_count_ = 0;
  int resized_ = 0; // frames to swap after a resize before the one more render (constructor)
  unsigned long camera_observer_ = 0, render_observer_ = 0;
  int live_render_delay_ms_ = 0;
  QTimer render_timer_;
  bool render_pending_ = false; // a render skipped while the view was hidden or had no area
  double grid_cx_ = 0.0, grid_cy_ = 0.0, grid_extent_ = 0.0, grid_step_ = 100.0;
};

/** "waypoint", "segment-script", "parametric", ... (captions and messages). */
QString TrajectoryKindName(nav_traj_type t);
/** Waypoint edits shared by the views and the table (each is one undo step). */
void AddWaypoint(SceneDocument *doc, double n, double e, double d, int insert_at = -1);
void DeleteWaypoint(SceneDocument *doc, int index);

} // namespace studio

#endif
