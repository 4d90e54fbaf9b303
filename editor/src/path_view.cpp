#include "path_view.h"

#include "navview/nav_view_scene.h"

#include <QResizeEvent>
#include <QShowEvent>
#include <QVBoxLayout>
#include <QImage>
#include <QVTKOpenGLStereoWidget.h>
#include <QVTKOpenGLWindow.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vtkUnsignedCharArray.h>

#include <vtkActor.h>
#include <vtkBillboardTextActor3D.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCameraPass.h>
#include <vtkLightsPass.h>
#include <vtkOpaquePass.h>
#include <vtkOverlayPass.h>
#include <vtkRenderPassCollection.h>
#include <vtkSequencePass.h>
#include <vtkTranslucentPass.h>
#include <vtkCellArray.h>
#include <vtkCoordinate.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGlyph3D.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkObjectFactory.h>
#include <vtkImageData.h>
#include <vtkPlaneSource.h>
#include <vtkPointData.h>
#include <vtkTexture.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>

#include "map_background.h"

namespace studio {

/* ---------------------------------------------------------------- waypoint edits */

QString TrajectoryKindName(nav_traj_type t) {
  switch (t) {
  case NAV_TRAJ_WAYPOINTS: return QObject::tr("waypoint");
  case NAV_TRAJ_SEGMENTS: return QObject::tr("segment-script");
  case NAV_TRAJ_PARAMETRIC: return QObject::tr("parametric");
  case NAV_TRAJ_RECORDED: return QObject::tr("recorded");
  case NAV_TRAJ_TEST_MOTION: return QObject::tr("test-motion");
  }
  return QString::fromUtf8(nav_traj_type_name(t));
}

void AddWaypoint(SceneDocument *doc, double n, double e, double d, int insert_at) {
  const nav_scene &cur = doc->Scene();
  if (cur.trajectory.type == NAV_TRAJ_WAYPOINTS && cur.trajectory.waypoints.count >= NAV_MAX_WAYPOINTS) return;
  doc->Edit(QObject::tr("Add waypoint"), [&](nav_scene &s) {
    nav_traj_waypoints &w = s.trajectory.waypoints;
    if (s.trajectory.type != NAV_TRAJ_WAYPOINTS) {
      s.trajectory.type = NAV_TRAJ_WAYPOINTS;
      w.count = 0;
      w.timing = NAV_WP_TIMING_SPEED;
      if (w.hold_start_s <= 0.0) w.hold_start_s = 30.0;
      if (w.cruise_mps <= 0.0) w.cruise_mps = kDriveCruiseMps;
    }
    const double cruise = w.cruise_mps > 0.0 ? w.cruise_mps : kDriveCruiseMps;
    nav_waypoint p;
    std::memset(&p, 0, sizeof p);
    p.r_ned_m = nav_vec3{n, e, d};
    int at = insert_at < 0 || insert_at > w.count ? w.count : insert_at;
    if (at == w.count) {
      // A new end point: the drive stops there; the former end point becomes a cruise point.
      p.speed_mps = 0.0;
      if (w.count >= 2 && w.points[w.count - 1].speed_mps == 0.0) w.points[w.count - 1].speed_mps = cruise;
      if (w.count == 1) p.speed_mps = 0.0;
    } else {
      p.speed_mps = at == 0 ? 0.0 : cruise;
      if (at == 0 && w.count > 0 && w.points[0].speed_mps == 0.0) w.points[0].speed_mps = cruise;
    }
    for (int i = w.count; i > at; --i) w.points[i] = w.points[i - 1];
    w.points[at] = p;
    w.count += 1;
    if (w.timing == NAV_WP_TIMING_TIME) {
      // Timing by time: keep the list increasing (new point 30 s after its predecessor).
      for (int i = 1; i < w.count; ++i)
        if (w.points[i].time_s <= w.points[i - 1].time_s) w.points[i].time_s = w.points[i - 1].time_s + 30.0;
    }
  });
}

void DeleteWaypoint(SceneDocument *doc, int index) {
  const nav_scene &cur = doc->Scene();
  if (cur.trajectory.type != NAV_TRAJ_WAYPOINTS || index < 0 || index >= cur.trajectory.waypoints.count) return;
  doc->Edit(QObject::tr("Delete waypoint %1").arg(index), [&](nav_scene &s) {
    nav_traj_waypoints &w = s.trajectory.waypoints;
    for (int i = index; i + 1 < w.count; ++i) w.points[i] = w.points[i + 1];
    w.count -= 1;
    if (w.count >= 1) {
      w.points[0].speed_mps = 0.0;
      w.points[w.count - 1].speed_mps = 0.0;
      w.points[0].time_s = 0.0;
      // A stop (hold_s) is for interior waypoints; the ends hold with hold_start_s / hold_end_s.
      w.points[0].hold_s = 0.0;
      w.points[w.count - 1].hold_s = 0.0;
    }
  });
}

/* ---------------------------------------------------------------- interactor style */

class PathViewStyle : public vtkInteractorStyleTrackballCamera {
public:
  static PathViewStyle *New();
  vtkTypeMacro(PathViewStyle, vtkInteractorStyleTrackballCamera)
  PathView *view = nullptr;
  bool map = false;

  void OnLeftButtonDown() override {
    vtkRenderWindowInteractor *i = GetInteractor();
    const int *p = i->GetEventPosition();
    px_ = p[0];
    py_ = p[1];
    down_ = true;
    moved_ = false;
    ctrl_ = i->GetControlKey() != 0;
    if (view->OnPress(p[0], p[1], ctrl_, i->GetShiftKey() != 0)) {
      consumed_ = true;
      return;
    }
    consumed_ = false;
    FindPokedRenderer(p[0], p[1]);
    if (map)
      StartPan();
    else
      vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
  }
  void OnMouseMove() override {
    vtkRenderWindowInteractor *i = GetInteractor();
    const int *p = i->GetEventPosition();
    if (consumed_) {
      view->OnDrag(p[0], p[1], i->GetShiftKey() != 0);
      return;
    }
    if (down_ && std::abs(p[0] - px_) + std::abs(p[1] - py_) > 3) moved_ = true;
    view->OnHover(p[0], p[1]);
    vtkInteractorStyleTrackballCamera::OnMouseMove();
  }
  void OnLeftButtonUp() override {
    const bool was_down = down_;
    down_ = false;
    if (consumed_) {
      consumed_ = false;
      view->OnRelease();
      return;
    }
    if (map)
      EndPan();
    else
      vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
    if (was_down && !moved_) view->OnClick(px_, py_, ctrl_);
  }
  // The map zooms about the pointer (the point under it stays under it), 1.25x a wheel step;
  // the 3D view keeps the trackball's dolly.
  void OnMouseWheelForward() override {
    const int *p = GetInteractor()->GetEventPosition();
    if (!map || !view->ZoomMapAt(p[0], p[1], 1.25)) vtkInteractorStyleTrackballCamera::OnMouseWheelForward();
  }
  void OnMouseWheelBackward() override {
    const int *p = GetInteractor()->GetEventPosition();
    if (!map || !view->ZoomMapAt(p[0], p[1], 1.0 / 1.25)) vtkInteractorStyleTrackballCamera::OnMouseWheelBackward();
  }
  void OnKeyPress() override {
    const char *sym = GetInteractor()->GetKeySym();
    if (sym && (std::strcmp(sym, "Delete") == 0 || std::strcmp(sym, "BackSpace") == 0)) view->OnDeleteKey();
  }
  void OnChar() override {
    // No VTK default keys ('q'/'e' would end the program, 'w'/'s' switch representations).
    const char c = GetInteractor()->GetKeyCode();
    if (c == 'r') view->ResetCamera();
  }

private:
  bool consumed_ = false, down_ = false, moved_ = false, ctrl_ = false;
  int px_ = 0, py_ = 0;
};
vtkStandardNewMacro(PathViewStyle)

/* ---------------------------------------------------------------- helpers */

namespace {
constexpr int kMultiSamples = 8;

// One colour per kind of object in both views (the 3D view's result scene, libnavview, uses the
// same: reference black, estimate red, envelope blue, outages pink). Bottom to top: the
// envelope (an opaque light blue region), outages, plan, the previous result (grey, A/B), the
// estimate (preview thin, Monte Carlo result wider).
constexpr double kPlanRgb[3] = {0.08, 0.08, 0.10};
constexpr double kEstimateRgb[3] = {0.84, 0.10, 0.11};
constexpr double kOutageRgb[3] = {0.96, 0.50, 0.80};
// The envelope's fill: libnavview's tube blue (0.35, 0.55, 0.95) at 28 % over the views' light
// background, drawn opaque
// (SetEnvelope: overlapping pieces of the band show as one region).
constexpr double kEnvelopeFillRgb[3] = {0.80, 0.86, 0.97};
constexpr double kPreviousRgb[3] = {0.55, 0.55, 0.58};
constexpr double kOverRgb[3] = {1.00, 0.55, 0.00}; // over a vehicle limit: orange, not the estimate's red
// The outage band's depth pushed behind the paths (VTK coincident-topology units): a wide line
// is nearer to the camera than a path a pixel beside it and would hide it.
constexpr double kOutageDepthUnits = 50.0;

vtkSmartPointer<vtkActor> MakeActor(vtkPolyData *pd, double r, double g, double b, double width) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(pd);
  mapper->ScalarVisibilityOff();
  auto a = vtkSmartPointer<vtkActor>::New();
  a->SetMapper(mapper);
  a->GetProperty()->SetColor(r, g, b);
  a->GetProperty()->SetLineWidth(static_cast<float>(width));
  a->GetProperty()->SetPointSize(static_cast<float>(width));
  a->GetProperty()->LightingOff();
  return a;
}

vtkPolyData *InputOf(vtkActor *a) {
  return vtkPolyData::SafeDownCast(vtkPolyDataMapper::SafeDownCast(a->GetMapper())->GetInput());
}

void SetPolyline(vtkPolyData *pd, const std::vector<double> &ned, double lift) {
  auto pts = vtkSmartPointer<vtkPoints>::New();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  const vtkIdType n = static_cast<vtkIdType>(ned.size() / 3);
  pts->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
    pts->SetPoint(i, ned[3 * i + 1], ned[3 * i], -ned[3 * i + 2] + lift);
  if (n >= 2) {
    lines->InsertNextCell(n);
    for (vtkIdType i = 0; i < n; ++i) lines->InsertCellPoint(i);
  }
  pd->SetPoints(pts);
  pd->SetLines(lines);
  pd->Modified();
}

/** Polylines of x/y pairs [m] at height @p z into @p pd; returns the number of polylines. */
size_t SetXyPolylines(vtkPolyData *pd, const std::vector<std::vector<double>> &lines, double z) {
  auto pts = vtkSmartPointer<vtkPoints>::New();
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  for (const auto &pl : lines) {
    const vtkIdType n = static_cast<vtkIdType>(pl.size() / 2);
    if (n < 2) continue;
    cells->InsertNextCell(n);
    for (vtkIdType i = 0; i < n; ++i) cells->InsertCellPoint(pts->InsertNextPoint(pl[2 * i], pl[2 * i + 1], z));
  }
  pd->SetPoints(pts);
  pd->SetLines(cells);
  pd->Modified();
  return static_cast<size_t>(cells->GetNumberOfCells());
}

/** SamplePath for the views: both draw the same path, the second one of an edit reuses the
 *  first one's samples (GUI thread only, as the views). */
bool SharedSamplePath(const nav_scene &s, int max_points, PathSamples *out, QString *msg) {
  static std::vector<unsigned char> key;
  static int key_points = 0;
  static PathSamples samples;
  static QString message;
  static bool ok = false;
  if (key_points != max_points || key.size() != sizeof s || std::memcmp(key.data(), &s, sizeof s) != 0) {
    message.clear();
    ok = SamplePath(s, max_points, &samples, &message);
    const auto *bytes = reinterpret_cast<const unsigned char *>(&s);
    key.assign(bytes, bytes + sizeof s);
    key_points = max_points;
  }
  *out = samples;
  if (msg) *msg = message;
  return ok;
}

double NiceStep(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(std::max(x, 1e-6))));
  const double m = x / p;
  return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * p;
}

QString FormatLatLon(double lat, double lon) {
  return QStringLiteral("%1°%2 %3°%4")
      .arg(std::fabs(lat), 0, 'f', 5)
      .arg(lat >= 0 ? "N" : "S")
      .arg(std::fabs(lon), 0, 'f', 5)
      .arg(lon >= 0 ? "E" : "W");
}
} // namespace

/* ---------------------------------------------------------------- PathView */

PathView::PathView(SceneDocument *doc, Mode mode, QWidget *parent) : QWidget(parent), doc_(doc), mode_(mode) {
  setObjectName(mode == Mode::Map ? "mapView" : "view3d");
  auto *lay = new QVBoxLayout(this);
  lay->setContentsMargins(0, 0, 0, 0);
  widget_ = new QVTKOpenGLStereoWidget(this);
  lay->addWidget(widget_);
  connect(widget_->embeddedOpenGLWindow(), &QOpenGLWindow::frameSwapped, this, [this] {
    ++frame_count_;
    swapped_render_count_ = render_count_;
    // The first frame after a resize can go to a drawable of the old size (Mesa learns a
    // window's new size at a buffer swap): one more frame draws it at the new size.
    if (resized_ && --resized_ == 0) render_timer_.start(0);
    emit FrameSwapped();
  });
  window_ = vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New();
  window_->SetMultiSamples(kMultiSamples);
  widget_->setRenderWindow(window_);
  renderer_ = vtkSmartPointer<vtkRenderer>::New();
  {
    // Lights, opaque props, translucent props with plain alpha blending, 2D overlay. The only
    // translucent props (the 3D view's ground under everything, the label backgrounds over
    // everything, in that actor order) blend alike in one pass; VTK's default for translucent
    // props, order-independent transparency, adds full-window passes to every frame (about a
    // quarter of a frame's main-thread time with Mesa's software renderer).
    vtkNew<vtkRenderPassCollection> passes;
    passes->AddItem(vtkNew<vtkLightsPass>());
    passes->AddItem(vtkNew<vtkOpaquePass>());
    passes->AddItem(vtkNew<vtkTranslucentPass>());
    passes->AddItem(vtkNew<vtkOverlayPass>());
    vtkNew<vtkSequencePass> sequence;
    sequence->SetPasses(passes);
    vtkNew<vtkCameraPass> camera;
    camera->SetDelegatePass(sequence);
    renderer_->SetPass(camera);
  }
  window_->AddRenderer(renderer_);
  {
    vtkNew<vtkCallbackCommand> cb;
    cb->SetClientData(&render_count_);
    cb->SetCallback([](vtkObject *, unsigned long, void *client, void *) { ++*static_cast<long *>(client); });
    render_observer_ = renderer_->AddObserver(vtkCommand::StartEvent, cb);
  }
  if (mode == Mode::Map) {
    renderer_->SetBackground(0.93, 0.95, 0.92);
  } else {
    // navview's light sky: the scene of a result (libnavview, drawn over this view) is coloured
    // for it (black reference, grey reference triads, translucent blue tube).
    renderer_->SetBackground(1.0, 1.0, 1.0);
    renderer_->SetBackground2(0.90, 0.93, 0.97);
    renderer_->GradientBackgroundOn();
  }

  if (mode == Mode::Map) {
    // Offline background: coastlines and lakes, the graticule (above street scale).
    coast_ = MakeActor(vtkNew<vtkPolyData>(), 0.45, 0.60, 0.75, 1.2);
    graticule_ = MakeActor(vtkNew<vtkPolyData>(), 0.62, 0.66, 0.72, 1.0);
    rivers_ = MakeActor(vtkNew<vtkPolyData>(), 0.36, 0.58, 0.84, 1.1);
    borders_ = MakeActor(vtkNew<vtkPolyData>(), 0.52, 0.30, 0.50, 1.4);
    // Land and water under everything: an image of the view on a quad (UpdateBackground).
    land_plane_ = vtkSmartPointer<vtkPlaneSource>::New();
    land_image_ = vtkSmartPointer<vtkImageData>::New();
    auto tex = vtkSmartPointer<vtkTexture>::New();
    tex->SetInputData(land_image_);
    tex->InterpolateOff();
    tex->SetColorModeToDirectScalars();
    auto lm = vtkSmartPointer<vtkPolyDataMapper>::New();
    lm->SetInputConnection(land_plane_->GetOutputPort());
    land_ = vtkSmartPointer<vtkActor>::New();
    land_->SetMapper(lm);
    land_->SetTexture(tex);
    land_->GetProperty()->LightingOff();
    land_->SetVisibility(0);
    renderer_->AddActor(land_);
    renderer_->AddActor(graticule_);
    renderer_->AddActor(rivers_);
    renderer_->AddActor(borders_);
    renderer_->AddActor(coast_);
    place_dots_ = MakeActor(vtkNew<vtkPolyData>(), 0.10, 0.10, 0.14, 5.0); // place names' dots
    renderer_->AddActor(place_dots_);
  }
  grid_ = MakeActor(vtkNew<vtkPolyData>(), 0.70, 0.74, 0.70, 1.0);
  if (mode == Mode::ThreeD) grid_->GetProperty()->SetColor(0.74, 0.77, 0.74);
  renderer_->AddActor(grid_);
  if (mode == Mode::ThreeD) {
    vtkNew<vtkPlaneSource> plane;
    plane->SetOrigin(-1, -1, -0.05);
    plane->SetPoint1(1, -1, -0.05);
    plane->SetPoint2(-1, 1, -0.05);
    plane->Update();
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    pd->DeepCopy(plane->GetOutput());
    ground_ = MakeActor(pd, 0.90, 0.93, 0.88, 1.0);
    ground_->GetProperty()->SetOpacity(0.55);
    renderer_->AddActor(ground_);
  }
  // The plan wider than the estimate drawn on it: where they coincide the plan edges it in black.
  path_actor_ = MakeActor(vtkNew<vtkPolyData>(), kPlanRgb[0], kPlanRgb[1], kPlanRgb[2], 4.0);
  over_actor_ =
      MakeActor(vtkNew<vtkPolyData>(), kOverRgb[0], kOverRgb[1], kOverRgb[2], 5.0); // over a vehicle limit
  estimate_ = MakeActor(vtkNew<vtkPolyData>(), kEstimateRgb[0], kEstimateRgb[1], kEstimateRgb[2], 1.6);
  result_ = MakeActor(vtkNew<vtkPolyData>(), kEstimateRgb[0], kEstimateRgb[1], kEstimateRgb[2], 2.4);
  previous_ = MakeActor(vtkNew<vtkPolyData>(), kPreviousRgb[0], kPreviousRgb[1], kPreviousRgb[2], 1.5); // A/B
  outages_ = MakeActor(vtkNew<vtkPolyData>(), kOutageRgb[0], kOutageRgb[1], kOutageRgb[2], 9.0);
  outages_->GetMapper()->SetRelativeCoincidentTopologyLineOffsetParameters(0.0, kOutageDepthUnits);
  // The offset above needs VTK's coincident-topology resolution (off by default; process-wide):
  // on, with zero global offsets, so that only the band's applies (as libnavview sets it).
  vtkMapper::SetResolveCoincidentTopologyToPolygonOffset();
  vtkMapper::SetResolveCoincidentTopologyPolygonOffsetParameters(0.0, 0.0);
  vtkMapper::SetResolveCoincidentTopologyLineOffsetParameters(0.0, 0.0);
  vtkMapper::SetResolveCoincidentTopologyPointOffsetParameter(0.0);
  handles_ = MakeActor(vtkNew<vtkPolyData>(), 0.98, 0.98, 0.98, 1.0);
  handles_->GetProperty()->LightingOn();
  handles_->GetProperty()->SetColor(0.15, 0.15, 0.15);
  selected_actor_ = MakeActor(vtkNew<vtkPolyData>(), 1.0, 0.80, 0.0, 1.0);
  selected_actor_->GetProperty()->LightingOn();
  bad_actor_ = MakeActor(vtkNew<vtkPolyData>(), 0.90, 0.10, 0.10, 1.0); // infeasible waypoints
  bad_actor_->GetProperty()->LightingOn();
  envelope_ =
      MakeActor(vtkNew<vtkPolyData>(), kEnvelopeFillRgb[0], kEnvelopeFillRgb[1], kEnvelopeFillRgb[2], 1.0);
  renderer_->AddActor(outages_);
  renderer_->AddActor(envelope_); // under the paths
  for (auto &a : {previous_, path_actor_, over_actor_, estimate_, result_, handles_, selected_actor_, bad_actor_})
    renderer_->AddActor(a);
  if (mode == Mode::ThreeD) {
    // Drop lines from waypoints off the ground plane (Shift+drag) to it: their height is read.
    stems_ = MakeActor(vtkNew<vtkPolyData>(), 0.35, 0.35, 0.40, 1.5);
    renderer_->AddActor(stems_);
  }

  caption_ = vtkSmartPointer<vtkTextActor>::New();
  caption_->GetTextProperty()->SetFontSize(14);
  caption_->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
  caption_->SetPosition(8, 8);
  renderer_->AddViewProp(caption_);
  problem_ = vtkSmartPointer<vtkTextActor>::New();
  problem_->GetTextProperty()->SetFontSize(14);
  problem_->GetTextProperty()->SetColor(0.85, 0.05, 0.05);
  problem_->GetTextProperty()->SetBackgroundColor(1.0, 1.0, 1.0);
  problem_->GetTextProperty()->SetBackgroundOpacity(0.8);
  problem_->GetTextProperty()->SetVerticalJustificationToTop();
  problem_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  problem_->SetPosition(0.01, 0.98);
  renderer_->AddViewProp(problem_);

  style_ = vtkSmartPointer<PathViewStyle>::New();
  style_->view = this;
  style_->map = mode == Mode::Map;
  widget_->interactor()->SetInteractorStyle(style_);

  if (mode == Mode::Map) renderer_->GetActiveCamera()->ParallelProjectionOn();
  // Redraws are coalesced: a burst of changes (a drag, undo of several steps) draws once.
  rebuild_timer_.setSingleShot(true);
  rebuild_timer_.setInterval(0);
  connect(&rebuild_timer_, &QTimer::timeout, this, &PathView::Rebuild);
  render_timer_.setSingleShot(true);
  connect(&render_timer_, &QTimer::timeout, this, &PathView::Render);
  connect(doc_, &SceneDocument::Changed, &rebuild_timer_, QOverload<>::of(&QTimer::start));
  if (mode == Mode::Map) {
    // The background follows the camera (pan, zoom), deferred and coalesced.
    bg_timer_.setSingleShot(true);
    bg_timer_.setInterval(0);
    connect(&bg_timer_, &QTimer::timeout, this, &PathView::UpdateBackground);
    vtkNew<vtkCallbackCommand> cb;
    cb->SetClientData(&bg_timer_);
    cb->SetCallback([](vtkObject *, unsigned long, void *client, void *) { static_cast<QTimer *>(client)->start(); });
    camera_observer_ = renderer_->GetActiveCamera()->AddObserver(vtkCommand::ModifiedEvent, cb);
  }
  Rebuild();
  ResetCamera();
}

bool PathView::SetSceneResult(std::shared_ptr<const NavResult> result, const NavViewOptions &options, bool keep_time,
                              QString *error) {
  if (mode_ != Mode::ThreeD) return false;
  scene_result_ = result;
  const bool show = result != nullptr;
  // The scene draws the estimate, its band and the envelope: the editor's own stay hidden.
  for (auto &a : {estimate_, result_, envelope_})
    a->SetVisibility(!show);
  if (!show) {
    scene_.reset();
    scene_stale_ = false;
    UpdateLegend();
    UpdateCaption();
    Render();
    return true;
  }
  const double t = scene_ && keep_time ? scene_->GetTime() : NAN;
  const bool follow = scene_ && scene_->GetOptions().follow;
  const double follow_m = scene_ ? scene_->GetOptions().follow_distance_m : 0.0;
  if (!scene_) {
    scene_ = std::make_unique<NavSceneView>();
    scene_->AttachToWindow(window_, renderer_);
  }
  NavViewOptions o = options;
  o.follow = follow;
  o.follow_distance_m = follow_m;
  o.time_s = t;
  scene_->SetResult(result);
  scene_->SetOptions(o);
  SyncSize();
  std::string err;
  if (!scene_->Rebuild(&err)) {
    if (error) *error = QString::fromStdString(err);
    scene_.reset();
    scene_result_.reset();
    for (auto &a : {estimate_, result_, envelope_})
      a->SetVisibility(true);
    Render();
    return false;
  }
  scene_->SetStale(scene_stale_);
  UpdateLegend();
  UpdateCaption(); // left of the scene's legend panel
  Render();
  return true;
}

void PathView::SetSceneStale(bool stale) {
  scene_stale_ = stale;
  if (scene_) scene_->SetStale(stale);
  // The live preview keeps following in the editor's own estimate and band, over the greyed run.
  for (auto &a : {estimate_, envelope_})
    a->SetVisibility(!scene_ || stale);
  UpdateLegend();
  Render();
}

void PathView::SetEditOverlayHidden(bool hidden) {
  overlay_hidden_ = hidden;
  Render();
}

PathView::~PathView() {
  scene_.reset(); // takes its renderers out of our window
  // The observers point into this object; the renderer and its camera may outlive it.
  if (camera_observer_) renderer_->GetActiveCamera()->RemoveObserver(camera_observer_);
  if (render_observer_) renderer_->RemoveObserver(render_observer_);
}

vtkRenderWindowInteractor *PathView::Interactor() { return widget_->interactor(); }

size_t PathView::StemCount() {
  Path(); // a pending redraw first
  return stems_ ? static_cast<size_t>(InputOf(stems_)->GetNumberOfLines()) : 0u;
}

QWindow *PathView::NativeWindow() { return widget_->embeddedOpenGLWindow(); }

void PathView::SyncSize() {
  // The native window takes its new size at once, VTK's window only when Qt next paints it: a
  // render or a map background in between would use the old size (after a resize of the main
  // window: a stale picture cropped or padded on screen).
  QWindow *native = NativeWindow();
  const qreal dpr = native->devicePixelRatio();
  const int w = qRound(native->width() * dpr), h = qRound(native->height() * dpr);
  const int *size = window_->GetSize();
  if (w > 0 && h > 0 && (size[0] != w || size[1] != h)) Interactor()->UpdateSize(w, h);
}

QImage PathView::Grab() {
  if (render_pending_ || render_timer_.isActive()) Render();
  // VTK's own framebuffer holds the last frame; Qt's window buffer need not (after a resize it
  // is blank until Qt paints it again).
  const int *sz = window_->GetSize();
  const int w = sz[0], h = sz[1];
  if (w <= 0 || h <= 0) return QImage();
  window_->MakeCurrent();
  vtkNew<vtkUnsignedCharArray> px;
  if (!window_->GetPixelData(0, 0, w - 1, h - 1, 1, px, 0)) return QImage();
  QImage img(w, h, QImage::Format_RGB888);
  const unsigned char *src = px->GetPointer(0);
  for (int y = 0; y < h; ++y) std::memcpy(img.scanLine(h - 1 - y), src + 3 * static_cast<size_t>(w) * y, 3 * static_cast<size_t>(w));
  img.setDevicePixelRatio(NativeWindow()->devicePixelRatio());
  return img;
}

void PathView::Render() {
  render_timer_.stop();
  if (!window_) return;
  if (!isVisible() || width() <= 0 || height() <= 0) {
    render_pending_ = true;
    return;
  }
  render_pending_ = false;
  for (auto &a : {handles_, selected_actor_, bad_actor_, stems_})
    if (a) a->SetVisibility(!overlay_hidden_);
  for (auto &l : labels_)
    l->SetVisibility(!overlay_hidden_);
  // While a drag is live the views render without multisampling: with Mesa's software renderer
  // 8x MSAA about doubles the cost of a frame (measured: 20-30 ms -> 11-15 ms per view); the
  // committed edit is drawn smooth again.
  const int samples = doc_->IsLive() ? 0 : kMultiSamples;
  if (window_->GetMultiSamples() != samples) window_->SetMultiSamples(samples);
  SyncSize();
  window_->Render(); // VTK's adapter asks the view's window for the frame that shows it
}

void PathView::UpdateGrid(double cx, double cy, double extent) {
  const double step = NiceStep(extent / 12.0);
  // The oblique 3D view sees farther than the map: its ground reaches twice as far.
  const double half = std::ceil((mode_ == Mode::ThreeD ? 2.0 : 1.0) * extent / step) * step;
  const double x0 = std::floor((cx - half) / step) * step, x1 = std::ceil((cx + half) / step) * step;
  const double y0 = std::floor((cy - half) / step) * step, y1 = std::ceil((cy + half) / step) * step;
  auto pts = vtkSmartPointer<vtkPoints>::New();
  auto lines = vtkSmartPointer<vtkCellArray>::New();
  const double z = -0.02;
  for (double x = x0; x <= x1 + 0.5 * step; x += step) {
    const vtkIdType a = pts->InsertNextPoint(x, y0, z), b = pts->InsertNextPoint(x, y1, z);
    lines->InsertNextCell(2);
    lines->InsertCellPoint(a);
    lines->InsertCellPoint(b);
  }
  for (double y = y0; y <= y1 + 0.5 * step; y += step) {
    const vtkIdType a = pts->InsertNextPoint(x0, y, z), b = pts->InsertNextPoint(x1, y, z);
    lines->InsertNextCell(2);
    lines->InsertCellPoint(a);
    lines->InsertCellPoint(b);
  }
  vtkPolyData *pd = InputOf(grid_);
  pd->SetPoints(pts);
  pd->SetLines(lines);
  pd->Modified();
  if (ground_) {
    vtkPolyData *g = InputOf(ground_);
    vtkPoints *gp = g->GetPoints();
    const double zz = -0.1;
    gp->SetPoint(0, x0, y0, zz);
    gp->SetPoint(1, x1, y0, zz);
    gp->SetPoint(2, x0, y1, zz);
    gp->SetPoint(3, x1, y1, zz);
    gp->Modified();
    g->Modified();
  }
  grid_cx_ = cx;
  grid_cy_ = cy;
  grid_extent_ = extent;
  grid_step_ = step;
}

void PathView::ResetCamera() {
  Path(); // a pending redraw first: the camera fits the current path
  const nav_scene &s = doc_->Scene();
  // The points framed: every path sample and every waypoint, in world axes (east, north, up).
  auto each_point = [&](const auto &visit) {
    for (size_t i = 0; i < path_.Size(); ++i) visit(path_.ned_m[3 * i + 1], path_.ned_m[3 * i], -path_.ned_m[3 * i + 2]);
    if (s.trajectory.type == NAV_TRAJ_WAYPOINTS)
      for (int i = 0; i < s.trajectory.waypoints.count; ++i) {
        const nav_vec3 r = s.trajectory.waypoints.points[i].r_ned_m;
        visit(r.y, r.x, -r.z);
      }
  };
  // Their horizontal box; around the origin when there are none.
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  each_point([&](double x, double y, double) {
    xmin = std::min(xmin, x);
    xmax = std::max(xmax, x);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
  });
  if (!(xmin <= xmax)) xmin = xmax = ymin = ymax = 0.0;
  const double cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
  // An empty drive shows about a kilometre, a drawn one its extent.
  const bool empty = s.trajectory.type == NAV_TRAJ_WAYPOINTS && s.trajectory.waypoints.count < 2;
  const double minimum = empty ? 1000.0 : 200.0;
  const double extent = std::max({xmax - xmin, ymax - ymin, minimum}) * 0.5 * 1.25;
  const int *sz = window_->GetSize();
  const double aspect = sz[0] > 0 && sz[1] > 0 ? static_cast<double>(sz[0]) / sz[1] : 1.0;
  UpdateGrid(cx, cy, extent * 2.0);
  vtkCamera *cam = renderer_->GetActiveCamera();
  if (mode_ == Mode::Map) {
    cam->SetFocalPoint(cx, cy, 0.0);
    cam->SetPosition(cx, cy, 10.0 * extent + 1000.0);
    cam->SetViewUp(0, 1, 0);
    // The larger of the box's half-height and half-width over the aspect, so that a tall path in
    // a wide view and a wide path in a narrow view both fit, 25 % margin.
    cam->SetParallelScale(0.5 * 1.25 * std::max({ymax - ymin, (xmax - xmin) / aspect, minimum}));
    renderer_->ResetCameraClippingRange();
  } else {
    // Seen from the south-south-west, 33 deg above the horizon, at the smallest distance at which
    // every path sample, every waypoint and, for a small path, the minimum square (the kilometre
    // of an empty drive) project inside the middle 84 % of the view. A point p (relative to the focal point) is at
    // depth D - p.b in front of a camera at distance D along the unit vector b, so it is inside
    // when D >= p.b + max(|p.r| / (tan(a/2) aspect m), |p.u| / (tan(a/2) m)) (r, u: the camera's
    // right and up, a: the vertical view angle, m: the used fraction of the half-size).
    const double view_angle_deg = 30.0, m = 0.84;
    const double zc = 0.0;
    const double bx = -0.8, by = -2.0, bz = 1.4, bn = std::sqrt(bx * bx + by * by + bz * bz);
    const double b[3] = {bx / bn, by / bn, bz / bn};
    // r = b x z (horizontal, to the right of a camera looking along -b); u = r x b.
    double r[3] = {b[1], -b[0], 0.0};
    const double rn = std::hypot(r[0], r[1]);
    r[0] /= rn;
    r[1] /= rn;
    const double u[3] = {r[1] * b[2] - r[2] * b[1], r[2] * b[0] - r[0] * b[2], r[0] * b[1] - r[1] * b[0]};
    const double t = std::tan(0.5 * view_angle_deg * M_PI / 180.0);
    double dist = 1.0;
    auto fit = [&](double x, double y, double z) {
      const double p[3] = {x - cx, y - cy, z - zc};
      const double pb = p[0] * b[0] + p[1] * b[1] + p[2] * b[2];
      const double pr = p[0] * r[0] + p[1] * r[1] + p[2] * r[2];
      const double pu = p[0] * u[0] + p[1] * u[1] + p[2] * u[2];
      dist = std::max(dist, pb + std::max(std::fabs(pr) / (t * aspect * m), std::fabs(pu) / (t * m)));
    };
    each_point(fit);
    // The minimum square only for a path smaller than it (a longer path seen end-on fills the
    // view's height rather than a square's width).
    const double h = 0.5 * minimum;
    if (std::max(xmax - xmin, ymax - ymin) < minimum)
      for (int k = 0; k < 4; ++k) fit(cx + (k & 1 ? h : -h), cy + (k & 2 ? h : -h), 0.0);
    cam->SetFocalPoint(cx, cy, zc);
    cam->SetPosition(cx + dist * b[0], cy + dist * b[1], zc + dist * b[2]);
    cam->SetViewUp(0, 0, 1);
    cam->SetViewAngle(view_angle_deg);
    renderer_->ResetCameraClippingRange();
  }
  Rebuild();
}

const PathSamples &PathView::Path() {
  if (rebuild_timer_.isActive()) Rebuild();
  return path_;
}

size_t PathView::PathPointCount() { return Path().Size(); }

size_t PathView::OverLimitPointCount() {
  const PathSamples &p = Path();
  return static_cast<size_t>(std::count_if(p.over.begin(), p.over.end(), [](unsigned char b) { return b != 0; }));
}

void PathView::Rebuild() {
  rebuild_timer_.stop();
  const nav_scene &s = doc_->Scene();
  QString msg;
  if (!SharedSamplePath(s, 1200, &path_, &msg)) path_ = PathSamples();
  SetPolyline(InputOf(path_actor_), path_.ned_m, 0.3);
  // GNSS outages: the plan's samples inside each outage, a wide pink band under the paths.
  outage_spans_ = 0;
  {
    auto pts = vtkSmartPointer<vtkPoints>::New();
    auto lines = vtkSmartPointer<vtkCellArray>::New();
    const nav_gnss_model_config &g = s.gnss.model;
    for (size_t o = 0; s.gnss.enabled && o < g.outage_count; ++o) {
      std::vector<vtkIdType> ids;
      for (size_t i = 0; i < path_.Size(); ++i)
        if (path_.t_s[i] >= g.outages[o].t0_s && path_.t_s[i] <= g.outages[o].t1_s)
          ids.push_back(pts->InsertNextPoint(path_.ned_m[3 * i + 1], path_.ned_m[3 * i],
                                             -path_.ned_m[3 * i + 2] + 0.1));
      if (ids.size() < 2) continue;
      lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
      ++outage_spans_;
    }
    vtkPolyData *pd = InputOf(outages_);
    pd->SetPoints(pts);
    pd->SetLines(lines);
    pd->Modified();
  }
  // Parts of the path over a vehicle limit (a motion-definition script may exceed them): red.
  unsigned over_bits = 0;
  double over_t0 = 0.0, over_t1 = 0.0;
  {
    auto pts = vtkSmartPointer<vtkPoints>::New();
    auto lines = vtkSmartPointer<vtkCellArray>::New();
    const size_t n = path_.Size();
    for (size_t i = 0; i < n;) {
      if (!path_.over[i]) {
        ++i;
        continue;
      }
      const size_t a = i > 0 ? i - 1 : i;
      while (i < n && path_.over[i]) {
        if (!over_bits) over_t0 = path_.t_s[i];
        over_bits |= path_.over[i];
        over_t1 = path_.t_s[i];
        ++i;
      }
      const size_t b = i < n ? i : n - 1;
      lines->InsertNextCell(static_cast<vtkIdType>(b - a + 1));
      for (size_t k = a; k <= b; ++k)
        lines->InsertCellPoint(pts->InsertNextPoint(path_.ned_m[3 * k + 1], path_.ned_m[3 * k], -path_.ned_m[3 * k + 2] + 0.6));
    }
    vtkPolyData *pd = InputOf(over_actor_);
    pd->SetPoints(pts);
    pd->SetLines(lines);
    pd->Modified();
  }

  // Handle size: constant on screen in the map, a fraction of the grid in 3D.
  const double radius = mode_ == Mode::Map ? renderer_->GetActiveCamera()->GetParallelScale() * 0.022
                                           : std::max(grid_extent_, 100.0) * 0.010;
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(radius);
  sphere->SetThetaResolution(16);
  sphere->SetPhiResolution(12);
  auto pts = vtkSmartPointer<vtkPoints>::New();
  const bool wp = s.trajectory.type == NAV_TRAJ_WAYPOINTS;
  const int count = wp ? s.trajectory.waypoints.count : 0;
  for (int i = 0; i < count; ++i) {
    const nav_vec3 r = s.trajectory.waypoints.points[i].r_ned_m;
    pts->InsertNextPoint(r.y, r.x, -r.z + 0.5);
  }
  {
    vtkNew<vtkPolyData> in;
    in->SetPoints(pts);
    vtkNew<vtkGlyph3D> g;
    g->SetInputData(in);
    g->SetSourceConnection(sphere->GetOutputPort());
    g->ScalingOff();
    g->Update();
    InputOf(handles_)->DeepCopy(g->GetOutput());
  }
  if (stems_) {
    auto sp = vtkSmartPointer<vtkPoints>::New();
    auto lines = vtkSmartPointer<vtkCellArray>::New();
    for (int i = 0; i < count; ++i) {
      const nav_vec3 r = s.trajectory.waypoints.points[i].r_ned_m;
      if (std::fabs(r.z) < 0.5) continue;
      const vtkIdType a = sp->InsertNextPoint(r.y, r.x, -r.z), b = sp->InsertNextPoint(r.y, r.x, 0.0);
      lines->InsertNextCell(2);
      lines->InsertCellPoint(a);
      lines->InsertCellPoint(b);
    }
    vtkPolyData *pd = InputOf(stems_);
    pd->SetPoints(sp);
    pd->SetLines(lines);
    pd->Modified();
  }
  {
    vtkNew<vtkPolyData> in;
    vtkNew<vtkPoints> sp;
    if (selected_ >= count) selected_ = -1;
    if (selected_ >= 0) {
      double p[3];
      pts->GetPoint(selected_, p);
      sp->InsertNextPoint(p[0], p[1], p[2] + 0.1);
    }
    in->SetPoints(sp);
    vtkNew<vtkSphereSource> big;
    big->SetRadius(radius * 1.35);
    big->SetThetaResolution(16);
    big->SetPhiResolution(12);
    vtkNew<vtkGlyph3D> g;
    g->SetInputData(in);
    g->SetSourceConnection(big->GetOutputPort());
    g->ScalingOff();
    g->Update();
    InputOf(selected_actor_)->DeepCopy(g->GetOutput());
  }
  // Waypoints the planner rejects (infeasible turns, legs too short): red, with the message.
  {
    vtkNew<vtkPolyData> in;
    vtkNew<vtkPoints> bp;
    QString problem;
    for (const Issue &is : Validate(s)) {
      const QString pre = QStringLiteral("trajectory.waypoints.points[");
      if (!is.path.startsWith(pre)) continue;
      const int k = is.path.mid(pre.size()).section(']', 0, 0).toInt();
      if (k >= 0 && k < count) {
        double p[3];
        pts->GetPoint(k, p);
        bp->InsertNextPoint(p[0], p[1], p[2] + 0.2);
      }
      if (problem.isEmpty()) problem = is.message;
    }
    in->SetPoints(bp);
    vtkNew<vtkSphereSource> bs;
    bs->SetRadius(radius * 1.2);
    vtkNew<vtkGlyph3D> g;
    g->SetInputData(in);
    g->SetSourceConnection(bs->GetOutputPort());
    g->ScalingOff();
    g->Update();
    InputOf(bad_actor_)->DeepCopy(g->GetOutput());
    const bool planner_problem = !problem.isEmpty();
    if (problem.isEmpty() && over_bits)
      problem = tr("the path exceeds the vehicle's %1 limit between t = %2 s and %3 s (red)")
                    .arg(OverLimitText(over_bits))
                    .arg(over_t0, 0, 'f', 1)
                    .arg(over_t1, 0, 'f', 1);
    // Wrapped to the view's width (about 8 px per character).
    QString wrapped;
    const int per_line = std::max(30, window_->GetSize()[0] / 9);
    for (const QString &word : problem.split(' ')) {
      const int line_len = static_cast<int>(wrapped.size() - wrapped.lastIndexOf('\n') - 1);
      if (!wrapped.isEmpty()) wrapped += line_len + word.size() + 1 > per_line ? "\n" : " ";
      wrapped += word;
    }
    problem_->SetInput(wrapped.isEmpty() ? "" : ((planner_problem ? tr("Not feasible: ") : tr("Over the limits: ")) + wrapped).toUtf8().constData());
    problem_->SetVisibility(!wrapped.isEmpty());
  }
  // Waypoint numbers.
  while (static_cast<int>(labels_.size()) > count) {
    renderer_->RemoveActor(labels_.back());
    labels_.pop_back();
  }
  while (static_cast<int>(labels_.size()) < count && labels_.size() < 200) {
    auto t = vtkSmartPointer<vtkBillboardTextActor3D>::New();
    t->GetTextProperty()->SetFontSize(15);
    t->GetTextProperty()->BoldOn();
    t->GetTextProperty()->SetColor(0.05, 0.05, 0.05);
    t->GetTextProperty()->SetBackgroundColor(1.0, 1.0, 0.85);
    t->GetTextProperty()->SetBackgroundOpacity(0.85);
    t->SetDisplayOffset(10, 8);
    renderer_->AddActor(t);
    labels_.push_back(t);
  }
  for (size_t i = 0; i < labels_.size(); ++i) {
    double p[3];
    pts->GetPoint(static_cast<vtkIdType>(i), p);
    labels_[i]->SetPosition(p[0], p[1], p[2]);
    labels_[i]->SetInput(std::to_string(i).c_str()); // 0-based, as navcore's messages count them
  }

  // Grows the grid when the path leaves it.
  if (grid_extent_ > 0.0) {
    double need = 0.0;
    for (size_t i = 0; i < path_.Size(); ++i)
      need = std::max({need, std::fabs(path_.ned_m[3 * i + 1] - grid_cx_), std::fabs(path_.ned_m[3 * i] - grid_cy_)});
    if (need > 0.9 * grid_extent_) UpdateGrid(grid_cx_, grid_cy_, 2.0 * need);
  }

  UpdateLegend();
  UpdateCaption();
  renderer_->ResetCameraClippingRange();
  if (doc_->IsLive() && live_render_delay_ms_ > 0) {
    // A live drag with the live preview on: the new path is drawn together with the estimate
    // that follows it (one frame instead of two), or after live_render_delay_ms_ at the latest.
    if (!render_timer_.isActive()) render_timer_.start(live_render_delay_ms_);
  } else {
    Render();
  }
}

void PathView::UpdateLegend() {
  // Rebuilt only when what it lists changes (each text actor is rasterized when first drawn).
  // Top right, one line per kind of object drawn: a coloured bar and what it is. In 3D the result
  // scene (libnavview) draws its own legend; this one stands in before a result is shown.
  struct Entry {
    const double *rgb;
    QString text;
  };
  std::vector<Entry> e;
  const bool own = mode_ == Mode::Map || !scene_;
  auto drawn = [](vtkActor *a) { return a->GetVisibility() && InputOf(a)->GetNumberOfPoints() > 1; };
  if (own) {
    if (path_.Size() > 1) e.push_back({kPlanRgb, tr("plan (reference path)")});
    if (InputOf(over_actor_)->GetNumberOfPoints() > 1) e.push_back({kOverRgb, tr("over a vehicle limit")});
    if (outage_spans_ > 0) e.push_back({kOutageRgb, tr("GNSS outage")});
    if (drawn(envelope_))
      e.push_back({kEnvelopeFillRgb, envelope_preview_ ? tr("band: 3 sigma of the preview")
                                                       : tr("band: 3 x RMS over the runs")});
    if (drawn(previous_)) e.push_back({kPreviousRgb, tr("previous result")});
    if (drawn(estimate_)) e.push_back({kEstimateRgb, tr("estimate (live preview)")});
    if (drawn(result_)) e.push_back({kEstimateRgb, tr("estimate (Monte Carlo run 0)")});
  }
  QStringList texts;
  for (const Entry &x : e)
    texts << x.text;
  if (texts == legend_entries_ && legend_.size() == 2 * e.size()) return;
  legend_entries_.clear();
  for (auto &a : legend_)
    renderer_->RemoveViewProp(a);
  legend_.clear();
  const int fs = 12, line_h = 18, right = 8, top = 8, sym_w = 30;
  for (size_t i = 0; i < e.size(); ++i) {
    legend_entries_ << e[i].text;
    const double y = -(top + static_cast<double>(i) * line_h);
    for (int k = 0; k < 2; ++k) {
      auto t = vtkSmartPointer<vtkTextActor>::New();
      vtkTextProperty *tp = t->GetTextProperty();
      tp->SetFontSize(fs);
      tp->SetJustificationToRight();
      tp->SetVerticalJustificationToTop();
      if (k == 0) {
        // The swatch: blanks on the object's colour, a bar 22 px wide and 6 px high.
        t->SetInput("      ");
        tp->SetFontSize(5);
        tp->SetBackgroundColor(e[i].rgb[0], e[i].rgb[1], e[i].rgb[2]);
        tp->SetBackgroundOpacity(1.0);
      } else {
        t->SetInput(e[i].text.toUtf8().constData());
        tp->SetColor(0.08, 0.08, 0.10);
        tp->SetBackgroundColor(1.0, 1.0, 1.0);
        tp->SetBackgroundOpacity(0.75);
      }
      // Pixels from the view's top-right corner.
      vtkNew<vtkCoordinate> corner;
      corner->SetCoordinateSystemToNormalizedViewport();
      corner->SetValue(1.0, 1.0);
      t->GetPositionCoordinate()->SetCoordinateSystemToViewport();
      t->GetPositionCoordinate()->SetReferenceCoordinate(corner);
      t->GetPositionCoordinate()->SetValue(k == 0 ? -right : -(right + sym_w), k == 0 ? y - 5.0 : y);
      renderer_->AddViewProp(t);
      legend_.push_back(t);
    }
  }
}

void PathView::UpdateCaption() {
  if (!caption_) return;
  const nav_scene &s = doc_->Scene();
  const bool wp = s.trajectory.type == NAV_TRAJ_WAYPOINTS;
  const int count = wp ? s.trajectory.waypoints.count : 0;
  double lat = 0, lon = 0, h = 0;
  const double zero[3] = {0, 0, 0};
  LocalToGeodetic(s, zero, &lat, &lon, &h);
  // The facts, in groups kept whole; the hint above them, in words. Both wrap to the view's width.
  QStringList facts;
  facts << (mode_ == Mode::Map ? tr("Map") : tr("3D")) << tr("origin %1").arg(FormatLatLon(lat, lon));
  if (mode_ == Mode::ThreeD || street_)
    facts << tr("grid %1 m").arg(grid_step_, 0, 'g', 6);
  else
    facts << tr("graticule %1°").arg(bg_key_[2] > 0 ? QString::number(graticule_step_deg_, 'g', 6) : "-");
  if (wp) facts << tr("%1 waypoints").arg(count);
  if (path_.Size() > 0) facts << tr("%1 s").arg(s.trajectory.duration_s, 0, 'f', 0);
  if (mode_ == Mode::Map && !bg_note_.isEmpty()) facts << bg_note_;
  if (mode_ == Mode::Map && !tile_credit_.isEmpty()) facts << tile_credit_;
  // GeoNames asks for credit (CC BY 4.0).
  if (mode_ == Mode::Map && !place_names_.isEmpty()) facts << tr("place names: GeoNames (CC BY 4.0)");
  QString hint;
  if (mode_ == Mode::Map && !wp)
    hint = tr("A %1 trajectory: edit it in the Trajectory panel").arg(TrajectoryKindName(s.trajectory.type));
  else if (mode_ == Mode::Map && count < 4)
    hint = tr("Click to add a waypoint, drag one to move it (Ctrl+click inserts, Delete removes)");
  // The caption sits 8 px from the left edge, left of the result scene's legend panel.
  const double panel = scene_ ? scene_->LegendPanelFraction() : 0.0;
  const int avail = std::max(120, static_cast<int>(width() * (1.0 - panel)) - 16);
  vtkTextRenderer *text_renderer = vtkTextRenderer::GetInstance();
  const int dpi = window_ ? window_->GetDPI() : 72;
  auto fits = [&](const QString &line) {
    int bb[4] = {0, 0, 0, 0};
    if (!text_renderer || !text_renderer->GetBoundingBox(caption_->GetTextProperty(), line.toUtf8().constData(), bb, dpi)) return true;
    return bb[1] - bb[0] <= avail;
  };
  // Greedy packing of pieces joined by sep into lines that fit (a piece wider than the view gets
  // a line of its own).
  auto pack = [&](const QStringList &pieces, const QString &sep) {
    QStringList lines;
    for (const QString &p : pieces) {
      if (!lines.isEmpty() && fits(lines.back() + sep + p))
        lines.back() += sep + p;
      else
        lines << p;
    }
    return lines;
  };
  QStringList lines;
  if (!hint.isEmpty()) lines << pack(hint.split(' ', Qt::SkipEmptyParts), " ");
  lines << pack(facts, QStringLiteral("  ·  "));
  caption_->SetInput(lines.join('\n').toUtf8().constData());
}

void PathView::resizeEvent(QResizeEvent *e) {
  QWidget::resizeEvent(e);
  if (mode_ == Mode::Map) bg_timer_.start();
  UpdateCaption(); // wrapped to the new width
  render_timer_.start(0); // at the new size (SyncSize), not waiting for Qt to paint the native window
  resized_ = 1;
}

void PathView::showEvent(QShowEvent *e) {
  QWidget::showEvent(e);
  if (render_pending_) render_timer_.start(0);
}

void PathView::SetMapExtent(double n, double e, double half_height_m) {
  vtkCamera *cam = renderer_->GetActiveCamera();
  const double *p = cam->GetPosition(), *f = cam->GetFocalPoint();
  const double dz = p[2] - f[2];
  cam->SetFocalPoint(e, n, 0.0);
  cam->SetPosition(e, n, std::max(dz, 10.0 * half_height_m + 1000.0));
  cam->SetParallelScale(half_height_m);
  renderer_->ResetCameraClippingRange();
  UpdateBackground();
}

QStringList PathView::GraticuleLabels() const {
  QStringList l;
  for (const auto &a : geo_labels_)
    if (a->GetVisibility()) l << QString::fromUtf8(a->GetInput());
  return l;
}

long PathView::LandColourAt(double e, double n) const {
  if (!land_ || !land_->GetVisibility()) return -1;
  int d[3];
  land_image_->GetDimensions(d);
  const double *o = land_plane_->GetOrigin(), *p1 = land_plane_->GetPoint1(), *p2 = land_plane_->GetPoint2();
  const int x = static_cast<int>(std::floor((e - o[0]) / (p1[0] - o[0]) * d[0]));
  const int y = static_cast<int>(std::floor((n - o[1]) / (p2[1] - o[1]) * d[1]));
  if (x < 0 || y < 0 || x >= d[0] || y >= d[1]) return -1;
  const auto *p = static_cast<const unsigned char *>(land_image_->GetScalarPointer(x, y, 0));
  return (long(p[0]) << 16) | (long(p[1]) << 8) | long(p[2]);
}

bool PathView::ZoomMapAt(int x, int y, double factor) {
  if (mode_ != Mode::Map || !(factor > 0.0)) return false;
  double n = 0.0, e = 0.0;
  if (!GroundAt(x, y, 0.0, &n, &e)) return false;
  vtkCamera *cam = renderer_->GetActiveCamera();
  const double s0 = cam->GetParallelScale();
  // Between 5 m and 20 000 km from the centre to the top edge.
  const double s = std::clamp(s0 / factor, 5.0, 2.0e7);
  const double k = s / s0; // the focal point moves towards the pointed point by 1 - k
  const double *f = cam->GetFocalPoint(), *p = cam->GetPosition();
  const double fx = e + (f[0] - e) * k, fy = n + (f[1] - n) * k;
  cam->SetFocalPoint(fx, fy, f[2]);
  cam->SetPosition(fx, fy, std::max(p[2] - f[2], 10.0 * s + 1000.0) + f[2]);
  cam->SetParallelScale(s);
  renderer_->ResetCameraClippingRange();
  Render();
  return true;
}

void PathView::SetMapTiles(const QString &source, const QString &attribution) {
  tiles_source_ = source.toStdString();
  tiles_attribution_ = attribution.toStdString();
  if (mode_ != Mode::Map) return;
  bg_key_[3] = -1.0; // force the rebuild
  UpdateBackground();
  UpdateCaption();
  Render();
}

bool PathView::MetricGridShown() const { return grid_->GetVisibility() != 0; }

void PathView::UpdateBackground() {
  bg_timer_.stop();
  if (mode_ != Mode::Map) return;
  SyncSize();
  vtkCamera *cam = renderer_->GetActiveCamera();
  const double *f = cam->GetFocalPoint();
  const int *sz = window_->GetSize();
  const double w = std::max(sz[0], 1), h = std::max(sz[1], 1);
  const double key[5] = {f[0], f[1], cam->GetParallelScale(), w, h};
  if (std::equal(key, key + 5, bg_key_)) return; // clipping-range updates change nothing here
  std::copy(key, key + 5, bg_key_);
  const double half_h = key[2], half_w = half_h * w / h, cx = f[0], cy = f[1];
  const double span = 2.0 * std::max(half_w, half_h);
  MapBackground bg;
  const MapTiles tiles{tiles_source_, tiles_attribution_};
  // Place names are measured in the font they are drawn with (the text renderer's box).
  const NavMapTextSize measure = [this](const std::string &text, int size, bool bold, double *tw, double *th) {
    vtkNew<vtkTextProperty> tp;
    tp->SetFontSize(size);
    tp->SetBold(bold);
    tp->SetBackgroundOpacity(0.55);
    int bb[4] = {0, 0, 0, 0};
    vtkTextRenderer *tr = vtkTextRenderer::GetInstance();
    if (tr && tr->GetBoundingBox(tp, text, bb, window_->GetDPI())) {
      *tw = bb[1] - bb[0] + 1;
      *th = bb[3] - bb[2] + 1;
    } else {
      *tw = 0.62 * size * static_cast<double>(text.size());
      *th = 1.25 * size;
    }
  };
  BuildMapBackground(doc_->Scene(), cx - half_w, cy - half_h, cx + half_w, cy + half_h, &bg, static_cast<int>(w),
                     static_cast<int>(h), tiles_source_.empty() ? nullptr : &tiles, measure);
  tile_credit_ = bg.tile_credit;
  tile_zoom_ = bg.tile_zoom;
  coast_count_ = SetXyPolylines(InputOf(coast_), bg.coast, -0.06);
  SetXyPolylines(InputOf(rivers_), bg.rivers, -0.065);
  SetXyPolylines(InputOf(borders_), bg.borders, -0.062);
  land_res_ = bg.shore_res;
  if (!bg.land_rgb.empty()) {
    land_image_->SetDimensions(bg.land_w, bg.land_h, 1);
    auto px = vtkSmartPointer<vtkUnsignedCharArray>::New();
    px->SetNumberOfComponents(3);
    px->SetNumberOfTuples(static_cast<vtkIdType>(bg.land_w) * bg.land_h);
    std::memcpy(px->GetPointer(0), bg.land_rgb.data(), bg.land_rgb.size());
    land_image_->GetPointData()->SetScalars(px);
    land_image_->Modified();
    land_plane_->SetOrigin(cx - half_w, cy - half_h, -0.08);
    land_plane_->SetPoint1(cx + half_w, cy - half_h, -0.08);
    land_plane_->SetPoint2(cx - half_w, cy + half_h, -0.08);
    land_->SetVisibility(1);
  } else {
    land_->SetVisibility(0);
  }
  graticule_count_ = SetXyPolylines(InputOf(graticule_), bg.graticule, -0.04);
  graticule_step_deg_ = std::min(bg.lat_step_deg, bg.lon_step_deg);
  bg_note_ = bg.note;
  street_ = span < kStreetScaleSpanM;
  grid_->SetVisibility(street_);
  if (street_) {
    // The metric grid follows the view: rebuilt when it no longer covers it or its step is off.
    const bool covered = std::fabs(cx - grid_cx_) + half_w <= grid_extent_ && std::fabs(cy - grid_cy_) + half_h <= grid_extent_;
    if (!covered || grid_step_ > span / 4.0 || grid_step_ < span / 40.0) UpdateGrid(cx, cy, 2.0 * std::max(half_w, half_h));
  }
  while (geo_labels_.size() < bg.labels.size()) {
    auto t = vtkSmartPointer<vtkTextActor>::New();
    t->GetTextProperty()->SetFontSize(13);
    t->GetTextProperty()->SetColor(0.15, 0.18, 0.25);
    t->GetTextProperty()->SetBackgroundColor(0.97, 0.97, 0.95);
    t->GetTextProperty()->SetBackgroundOpacity(0.75);
    t->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    renderer_->AddViewProp(t);
    geo_labels_.push_back(t);
  }
  for (size_t i = 0; i < geo_labels_.size(); ++i) {
    vtkTextActor *t = geo_labels_[i];
    if (i >= bg.labels.size()) {
      t->SetVisibility(0);
      continue;
    }
    const MapLabel &l = bg.labels[i];
    t->SetVisibility(1);
    t->SetInput(l.text.c_str());
    // Parallels: right-aligned above the line at the right edge; meridians: right of the line at the top.
    t->GetTextProperty()->SetJustification(l.latitude ? VTK_TEXT_RIGHT : VTK_TEXT_LEFT);
    t->GetTextProperty()->SetVerticalJustification(l.latitude ? VTK_TEXT_BOTTOM : VTK_TEXT_TOP);
    t->GetPositionCoordinate()->SetValue(l.x + (l.latitude ? -0.01 : 0.01) * half_w, l.y + (l.latitude ? 0.01 : -0.01) * half_h, 0.0);
  }
  // Place names: a dot and the name beside it (navview's placement, NavMapChoosePlaces).
  while (place_labels_.size() < bg.places.size()) {
    auto t = vtkSmartPointer<vtkTextActor>::New();
    vtkTextProperty *tp = t->GetTextProperty();
    tp->SetColor(0.10, 0.10, 0.14);
    tp->SetBackgroundColor(kNavMapLandRgb[0] / 255.0, kNavMapLandRgb[1] / 255.0, kNavMapLandRgb[2] / 255.0);
    tp->SetBackgroundOpacity(0.55);
    tp->SetJustificationToLeft();
    tp->SetVerticalJustificationToBottom();
    t->GetPositionCoordinate()->SetCoordinateSystemToWorld();
    renderer_->AddViewProp(t);
    place_labels_.push_back(t);
  }
  place_names_.clear();
  auto dot_pts = vtkSmartPointer<vtkPoints>::New();
  auto dot_cells = vtkSmartPointer<vtkCellArray>::New();
  for (size_t i = 0; i < place_labels_.size(); ++i) {
    vtkTextActor *t = place_labels_[i];
    if (i >= bg.places.size()) {
      t->SetVisibility(0);
      continue;
    }
    const MapPlace &p = bg.places[i];
    place_names_ << QString::fromStdString(p.name);
    t->SetVisibility(1);
    t->SetInput(p.name.c_str());
    t->GetTextProperty()->SetFontSize(p.size_pt);
    t->GetTextProperty()->SetBold(p.bold);
    t->GetPositionCoordinate()->SetValue(p.text_x, p.text_y, 0.0);
    const vtkIdType id = dot_pts->InsertNextPoint(p.dot_x, p.dot_y, 0.2);
    dot_cells->InsertNextCell(1, &id);
  }
  InputOf(place_dots_)->SetPoints(dot_pts);
  InputOf(place_dots_)->SetVerts(dot_cells);
  InputOf(place_dots_)->Modified();
  UpdateCaption();
  Render();
}

void PathView::SetEstimate(const std::vector<double> &ned, bool preview) {
  if (!preview && InputOf(result_)->GetNumberOfPoints() > 1) {
    // The Monte Carlo result being replaced stays as a grey overlay for comparison.
    InputOf(previous_)->DeepCopy(InputOf(result_));
  }
  // Drawn above the reference (in the top-down map the lift is invisible; in 3D it is small).
  SetPolyline(InputOf(preview ? estimate_ : result_), ned, mode_ == Mode::Map ? 5.0 : 0.004 * std::max(grid_extent_, 100.0));
  if (preview) {
    // A new preview supersedes the drawn Monte Carlo estimate of an older scene.
    SetPolyline(InputOf(result_), std::vector<double>(), 0.0);
  } else if (!ned.empty()) {
    // The Monte Carlo result's run 0 is the scene's estimate now: one red estimate line, not the
    // preview's beside it (the next edit's preview replaces it again).
    SetPolyline(InputOf(estimate_), std::vector<double>(), 0.0);
  }
  UpdateLegend();
  Render();
}

void PathView::SetEnvelope(const std::vector<double> &ned, const std::vector<double> &half_width_m, bool preview) {
  // The band is the region within half_width_m[i] of the estimate: the union of a disc at every
  // epoch and a trapezoid along every leg between two epochs (each piece convex). A strip of
  // offset points (the band before) folds over itself at a corner tighter than its half-width
  // and, translucent, drew each fold darker. The union is drawn opaque in the band's colour as
  // seen through (kEnvelopeFillRgb), under the outages and the paths, so overlapping pieces
  // show as one clean region.
  vtkPolyData *pd = InputOf(envelope_);
  auto pts = vtkSmartPointer<vtkPoints>::New();
  auto polys = vtkSmartPointer<vtkCellArray>::New();
  const size_t n = std::min(ned.size() / 3, half_width_m.size());
  // Under the plan (0.3 m up) and the outage band (0.1 m).
  const double lift = mode_ == Mode::Map ? 0.05 : 0.02;
  envelope_epochs_ = n >= 2 ? n : 0;
  constexpr int kSides = 20;
  auto width = [&](size_t i) {
    return std::isfinite(half_width_m[i]) ? std::max(half_width_m[i], 0.0) : 0.0;
  };
  // Straight stretches of nearly constant width become one trapezoid (a live preview's band has
  // about 2000 epochs: a piece per epoch cost about 10 ms of CPU per edit). A disc is needed only
  // where the band turns (it fills the wedge between two trapezoids) and at the ends.
  auto heading = [&](size_t a, size_t b) {
    return std::atan2(ned[3 * b + 1] - ned[3 * a + 1], ned[3 * b] - ned[3 * a]);
  };
  constexpr double kTurnRad = 1.0 * M_PI / 180.0, kWidthChange = 0.02;
  auto disc = [&](size_t i) {
    const double x = ned[3 * i + 1], y = ned[3 * i], z = -ned[3 * i + 2] + lift, w = width(i);
    if (!(w > 0.0)) return;
    vtkIdType ids[kSides];
    for (int k = 0; k < kSides; ++k) {
      const double a = 2.0 * M_PI * k / kSides;
      ids[k] = pts->InsertNextPoint(x + w * std::cos(a), y + w * std::sin(a), z);
    }
    polys->InsertNextCell(kSides, ids);
  };
  auto trapezoid = [&](size_t i, size_t j) {
    const double x = ned[3 * i + 1], y = ned[3 * i], z = -ned[3 * i + 2] + lift, w = width(i);
    const double x1 = ned[3 * j + 1], y1 = ned[3 * j], z1 = -ned[3 * j + 2] + lift, w1 = width(j);
    const double len = std::hypot(x1 - x, y1 - y);
    if (!(len > 1e-9) || (w <= 0.0 && w1 <= 0.0)) return;
    // Unit normal (east, north) of the stretch.
    const double nx = -(y1 - y) / len, ny = (x1 - x) / len;
    const vtkIdType q[4] = {pts->InsertNextPoint(x + w * nx, y + w * ny, z),
                            pts->InsertNextPoint(x1 + w1 * nx, y1 + w1 * ny, z1),
                            pts->InsertNextPoint(x1 - w1 * nx, y1 - w1 * ny, z1),
                            pts->InsertNextPoint(x - w * nx, y - w * ny, z)};
    polys->InsertNextCell(4, q);
  };
  if (n >= 2) {
    disc(0);
    size_t a = 0;
    double prev_dir = NAN;
    while (a + 1 < n) {
      // Skip repeated points (a vehicle at rest): no direction.
      size_t b = a + 1;
      while (b + 1 < n && std::hypot(ned[3 * b] - ned[3 * a], ned[3 * b + 1] - ned[3 * a + 1]) < 1e-9)
        ++b;
      const double dir = heading(a, b);
      const double wa = width(a);
      while (b + 1 < n) {
        const size_t c = b + 1;
        if (std::hypot(ned[3 * c] - ned[3 * b], ned[3 * c + 1] - ned[3 * b + 1]) < 1e-9) {
          b = c;
          continue;
        }
        if (std::fabs(std::remainder(heading(b, c) - dir, 2.0 * M_PI)) > kTurnRad ||
            std::fabs(width(c) - wa) > kWidthChange * std::max(wa, 1e-9))
          break;
        b = c;
      }
      if (std::isfinite(prev_dir) && std::fabs(std::remainder(dir - prev_dir, 2.0 * M_PI)) > kTurnRad)
        disc(a);
      trapezoid(a, b);
      prev_dir = dir;
      a = b;
    }
    disc(n - 1);
  }
  pd->SetPoints(pts);
  pd->SetPolys(polys);
  pd->SetStrips(vtkSmartPointer<vtkCellArray>::New());
  pd->Modified();
  envelope_preview_ = preview;
  UpdateLegend();
}

size_t PathView::EnvelopePointCount() {
  return 2 * envelope_epochs_;
}

QString PathView::CaptionText() const { return QString::fromUtf8(caption_->GetInput()); }

int PathView::CaptionWidth() {
  double bb[4] = {0, 0, 0, 0};
  caption_->GetBoundingBox(renderer_, bb);
  return static_cast<int>(std::ceil(bb[1] - bb[0]));
}

bool PathView::DisplayOf(double n, double e, double d, int *x, int *y) {
  renderer_->SetWorldPoint(e, n, -d, 1.0);
  renderer_->WorldToDisplay();
  const double *p = renderer_->GetDisplayPoint();
  *x = static_cast<int>(std::lround(p[0]));
  *y = static_cast<int>(std::lround(p[1]));
  const int *sz = window_->GetSize();
  return p[2] >= 0.0 && p[2] <= 1.0 && *x >= 0 && *y >= 0 && *x < sz[0] && *y < sz[1];
}

bool PathView::GroundAt(int x, int y, double d_plane, double *n, double *e) {
  double a[3], b[3];
  if (!RayAt(x, y, a, b)) return false;
  const double z = -d_plane;
  const double dz = b[2] - a[2];
  if (std::fabs(dz) < 1e-12) return false;
  const double t = (z - a[2]) / dz;
  if (t < 0.0 || t > 1.0) return false;
  *e = a[0] + t * (b[0] - a[0]);
  *n = a[1] + t * (b[1] - a[1]);
  return std::isfinite(*n) && std::isfinite(*e);
}

bool PathView::RayAt(int x, int y, double a[3], double b[3]) {
  double pa[4], pb[4];
  renderer_->SetDisplayPoint(x, y, 0.0);
  renderer_->DisplayToWorld();
  renderer_->GetWorldPoint(pa);
  renderer_->SetDisplayPoint(x, y, 1.0);
  renderer_->DisplayToWorld();
  renderer_->GetWorldPoint(pb);
  if (pa[3] == 0.0 || pb[3] == 0.0) return false;
  for (int k = 0; k < 3; ++k) {
    a[k] = pa[k] / pa[3];
    b[k] = pb[k] / pb[3];
  }
  return true;
}

bool PathView::HeightUnder(int x, int y, double n, double e, double *up) {
  // Nearest points of the ray a + t (b - a) and the vertical line (e, n, 0) + s (0, 0, 1):
  // with w = a - (e, n, 0) and d = b - a, s = w_z + d_z t and t minimises the horizontal
  // distance |w_xy + d_xy t|, i.e. t = -(w_xy . d_xy) / |d_xy|^2.
  double a[3], b[3];
  if (!RayAt(x, y, a, b)) return false;
  const double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double w[3] = {a[0] - e, a[1] - n, a[2]};
  const double dh2 = d[0] * d[0] + d[1] * d[1];
  const double len2 = dh2 + d[2] * d[2];
  if (!(len2 > 0.0) || dh2 < 1e-6 * len2) return false; // nearly vertical line of sight
  const double t = -(w[0] * d[0] + w[1] * d[1]) / dh2;
  *up = w[2] + d[2] * t;
  return std::isfinite(*up);
}

int PathView::PickWaypoint(int x, int y) {
  const nav_scene &s = doc_->Scene();
  if (s.trajectory.type != NAV_TRAJ_WAYPOINTS) return -1;
  int best = -1;
  double best_d2 = 12.0 * 12.0;
  for (int i = 0; i < s.trajectory.waypoints.count; ++i) {
    const nav_vec3 r = s.trajectory.waypoints.points[i].r_ned_m;
    int px = 0, py = 0;
    if (!DisplayOf(r.x, r.y, r.z, &px, &py)) continue;
    const double d2 = double(px - x) * (px - x) + double(py - y) * (py - y);
    if (d2 <= best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  return best;
}

void PathView::SetSelectedWaypoint(int i) {
  if (i == selected_) return;
  selected_ = i;
  Rebuild();
  emit SelectionChanged(i);
}

bool PathView::OnPress(int x, int y, bool ctrl, bool shift) {
  (void)ctrl;
  (void)shift;
  const int i = PickWaypoint(x, y);
  if (i < 0) return false;
  SetSelectedWaypoint(i);
  drag_index_ = i;
  dragging_ = false;
  press_x_ = x;
  press_y_ = y;
  drag_before_ = std::make_unique<nav_scene>(doc_->Scene());
  drag_d_ = doc_->Scene().trajectory.waypoints.points[i].r_ned_m.z;
  return true;
}

void PathView::OnDrag(int x, int y, bool shift) {
  if (drag_index_ < 0 || !drag_before_) return;
  if (!dragging_ && std::abs(x - press_x_) + std::abs(y - press_y_) < 2) return;
  dragging_ = true;
  nav_scene s = doc_->Scene();
  nav_waypoint &p = s.trajectory.waypoints.points[drag_index_];
  if (shift && mode_ == Mode::ThreeD) {
    // Height: the point of the waypoint's vertical line nearest to the ray under the cursor, so
    // that the handle stays under the cursor whatever the camera's tilt; measured from where
    // the drag started (a press a few pixels off the handle's centre does not make it jump).
    const nav_vec3 r = drag_before_->trajectory.waypoints.points[drag_index_].r_ned_m;
    double up_now = 0.0, up_press = 0.0;
    if (HeightUnder(x, y, r.x, r.y, &up_now) && HeightUnder(press_x_, press_y_, r.x, r.y, &up_press)) {
      p.r_ned_m.z = drag_d_ - (up_now - up_press);
    } else {
      // The line of sight is vertical (looking straight down): vertical mouse motion, scaled by
      // the distance to the point.
      vtkCamera *cam = renderer_->GetActiveCamera();
      const double *cp = cam->GetPosition();
      const double dist = std::sqrt((cp[0] - r.y) * (cp[0] - r.y) + (cp[1] - r.x) * (cp[1] - r.x) +
                                    (cp[2] + r.z) * (cp[2] + r.z));
      const int h = window_->GetSize()[1] > 0 ? window_->GetSize()[1] : 1;
      const double m_per_px = 2.0 * dist * std::tan(cam->GetViewAngle() * M_PI / 360.0) / h;
      p.r_ned_m.z = drag_d_ - (y - press_y_) * m_per_px;
    }
  } else {
    double n = 0, e = 0;
    if (!GroundAt(x, y, drag_d_, &n, &e)) return;
    p.r_ned_m.x = n;
    p.r_ned_m.y = e;
  }
  doc_->Preview(s);
}

void PathView::OnRelease() {
  if (drag_before_ && dragging_) doc_->Commit(*drag_before_, tr("Move waypoint %1").arg(drag_index_));
  drag_before_.reset();
  drag_index_ = -1;
  dragging_ = false;
}

void PathView::OnClick(int x, int y, bool ctrl) {
  double n = 0, e = 0;
  if (!GroundAt(x, y, 0.0, &n, &e)) return;
  const nav_scene &s = doc_->Scene();
  if (s.trajectory.type != NAV_TRAJ_WAYPOINTS) {
    // A click would replace a segment script, a parametric or a recorded trajectory by one
    // waypoint: no edit, the status bar says where such a trajectory is edited.
    emit CursorText(tr("A %1 trajectory has no waypoints to add: edit it in the Trajectory panel, or "
                       "File > New drive to draw one")
                        .arg(TrajectoryKindName(s.trajectory.type)));
    return;
  }
  int insert_at = -1;
  if (ctrl && s.trajectory.type == NAV_TRAJ_WAYPOINTS && s.trajectory.waypoints.count >= 2) {
    // Insert into the nearest leg (distance to the straight segment between waypoints).
    double best = 1e300;
    for (int i = 0; i + 1 < s.trajectory.waypoints.count; ++i) {
      const nav_vec3 a = s.trajectory.waypoints.points[i].r_ned_m, b = s.trajectory.waypoints.points[i + 1].r_ned_m;
      const double vx = b.x - a.x, vy = b.y - a.y, l2 = vx * vx + vy * vy;
      double t = l2 > 0 ? ((n - a.x) * vx + (e - a.y) * vy) / l2 : 0.0;
      t = std::clamp(t, 0.0, 1.0);
      const double dx = a.x + t * vx - n, dy = a.y + t * vy - e, d2 = dx * dx + dy * dy;
      if (d2 < best) {
        best = d2;
        insert_at = i + 1;
      }
    }
  }
  AddWaypoint(doc_, n, e, 0.0, insert_at);
  const int idx = insert_at < 0 ? doc_->Scene().trajectory.waypoints.count - 1 : insert_at;
  SetSelectedWaypoint(idx);
}

void PathView::OnHover(int x, int y) {
  double n = 0, e = 0;
  if (!GroundAt(x, y, 0.0, &n, &e)) return;
  const double ned[3] = {n, e, 0.0};
  double lat = 0, lon = 0, h = 0;
  LocalToGeodetic(doc_->Scene(), ned, &lat, &lon, &h);
  emit CursorText(tr("N %1 m  E %2 m  ·  %3").arg(n, 0, 'f', 1).arg(e, 0, 'f', 1).arg(FormatLatLon(lat, lon)));
}

void PathView::OnDeleteKey() {
  if (selected_ < 0) return;
  const int i = selected_;
  selected_ = -1;
  DeleteWaypoint(doc_, i);
  emit SelectionChanged(-1);
}

} // namespace studio
