// NavSceneView: VTK actors from the scene model (nav_view_model.h), camera, headless PNG and
// the benchmark. Interactive mode lives in interactive.cxx.
#include "navview/nav_view_scene.h"

#include "navview_internal.h"
#include "scene_view_impl.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkAppendPolyData.h>
#include <vtkArrowSource.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkConeSource.h>
#include <vtkCoordinate.h>
#include <vtkCubeSource.h>
#include <vtkDoubleArray.h>
#include <vtkGlyph3DMapper.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkOggTheoraWriter.h>
#include <vtkWindowToImageFilter.h>
#include <sys/stat.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTransform.h>
#include <vtkTransformPolyDataFilter.h>
#include <vtkTubeFilter.h>

#include "navview/nav_view_frame.h"

namespace {

// Colours (RGB 0..1). Reference dark, estimate red. The estimated triad carries the body-axis
// colours (x red, y green, z blue) and the reference triad is grey, so the eye compares the
// coloured estimate against a neutral reference.
const double kRefColor[3] = {0.08, 0.08, 0.10};
const double kEstColor[3] = {0.84, 0.10, 0.11};
const double kRunColor[3] = {0.95, 0.60, 0.60};
const double kTubeColor[3] = {0.35, 0.55, 0.95};
const double kGridColor[3] = {0.80, 0.81, 0.84};
const double kAxisColor[3] = {0.25, 0.25, 0.28};
const double kVehicleColor[3] = {1.00, 0.62, 0.05};
const double kTriadRGB[3][3] = {{0.85, 0.05, 0.05}, {0.05, 0.62, 0.10}, {0.05, 0.25, 0.90}};
const double kTriadRefGrey[3] = {0.42, 0.42, 0.46};
const double kTextColor[3] = {0.05, 0.05, 0.08};
const double kGnssColor[3] = {0.10, 0.62, 0.20};
const double kOutageColor[3] = {0.96, 0.50, 0.80}; // pink: the vehicle is orange
// The outage band's depth offset behind the paths (AddGnss): 50 units = 8e-4 of the depth range,
// more than the depth between the band and a path a few pixels away at any scene scale, far
// less than the scene's depth.
constexpr double kOutageDepthUnits = 50.0;
const double kEllipsoidColor[3] = {0.45, 0.25, 0.80};

// Perceptually ordered colour map for the error magnitude (viridis control points).
const double kViridis[5][3] = {{0.267, 0.005, 0.329},
                               {0.229, 0.322, 0.546},
                               {0.128, 0.567, 0.551},
                               {0.369, 0.789, 0.383},
                               {0.993, 0.906, 0.144}};

vtkSmartPointer<vtkPolyData> MakePolyline(const std::vector<double> &xyz) {
  const vtkIdType n = static_cast<vtkIdType>(xyz.size() / 3);
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(n);
  for (vtkIdType i = 0; i < n; ++i)
    pts->SetPoint(i, &xyz[3 * static_cast<size_t>(i)]);
  vtkNew<vtkCellArray> lines;
  lines->InsertNextCell(n);
  for (vtkIdType i = 0; i < n; ++i)
    lines->InsertCellPoint(i);
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->SetLines(lines);
  return pd;
}

vtkSmartPointer<vtkActor> LineActor(vtkPolyData *pd, const double rgb[3], double width) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(pd);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
  actor->GetProperty()->SetLineWidth(static_cast<float>(width));
  actor->GetProperty()->LightingOff();
  return actor;
}

// An arrow of unit length along body axis `axis` (0 x, 1 y, 2 z).
vtkSmartPointer<vtkPolyData> AxisArrow(int axis, bool thin) {
  vtkNew<vtkArrowSource> arrow;
  arrow->SetTipResolution(12);
  arrow->SetShaftResolution(8);
  arrow->SetTipLength(0.28);
  arrow->SetTipRadius(thin ? 0.075 : 0.09);
  arrow->SetShaftRadius(thin ? 0.022 : 0.03);
  vtkNew<vtkTransform> tf;
  if (axis == 1) tf->RotateZ(90.0);  // x -> y
  if (axis == 2) tf->RotateY(-90.0); // x -> z
  vtkNew<vtkTransformPolyDataFilter> f;
  f->SetTransform(tf);
  f->SetInputConnection(arrow->GetOutputPort());
  f->Update();
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->ShallowCopy(f->GetOutput());
  return pd;
}

// A simple car in body axes (FRD, unit length 1 along x): a body box and a wedge-shaped nose.
vtkSmartPointer<vtkPolyData> VehicleShape() {
  vtkNew<vtkCubeSource> body;
  body->SetXLength(0.75);
  body->SetYLength(0.45);
  body->SetZLength(0.22);
  body->SetCenter(-0.1, 0.0, -0.11); // z is down: the body sits above the path point
  vtkNew<vtkConeSource> nose;
  nose->SetResolution(4);
  nose->SetHeight(0.35);
  nose->SetRadius(0.2);
  nose->SetCenter(0.44, 0.0, -0.11);
  nose->SetDirection(1.0, 0.0, 0.0);
  vtkNew<vtkCubeSource> cabin;
  cabin->SetXLength(0.35);
  cabin->SetYLength(0.38);
  cabin->SetZLength(0.14);
  cabin->SetCenter(-0.15, 0.0, -0.29);
  vtkNew<vtkAppendPolyData> app;
  app->AddInputConnection(body->GetOutputPort());
  app->AddInputConnection(nose->GetOutputPort());
  app->AddInputConnection(cabin->GetOutputPort());
  app->Update();
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->ShallowCopy(app->GetOutput());
  return pd;
}

// An aircraft in body axes (FRD, unit length 1 along x): fuselage, wings, tailplane and fin.
vtkSmartPointer<vtkPolyData> AircraftShape() {
  vtkNew<vtkAppendPolyData> app;
  auto box = [&](double lx, double ly, double lz, double cx, double cy, double cz) {
    vtkNew<vtkCubeSource> c;
    c->SetXLength(lx);
    c->SetYLength(ly);
    c->SetZLength(lz);
    c->SetCenter(cx, cy, cz);
    c->Update();
    app->AddInputData(c->GetOutput());
  };
  box(0.85, 0.11, 0.11, -0.05, 0.0, 0.0);   // fuselage
  box(0.22, 0.95, 0.025, 0.02, 0.0, 0.0);   // wings (span along y)
  box(0.12, 0.36, 0.02, -0.42, 0.0, 0.0);   // tailplane
  box(0.14, 0.02, 0.20, -0.42, 0.0, -0.12); // fin (up is -z)
  vtkNew<vtkConeSource> nose;
  nose->SetResolution(12);
  nose->SetHeight(0.16);
  nose->SetRadius(0.055);
  nose->SetCenter(0.45, 0.0, 0.0);
  nose->SetDirection(1.0, 0.0, 0.0);
  nose->Update();
  app->AddInputData(nose->GetOutput());
  app->Update();
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->ShallowCopy(app->GetOutput());
  return pd;
}

// A generic vehicle: an arrowhead (four-sided cone) along body x, flattened along z.
vtkSmartPointer<vtkPolyData> GenericShape() {
  vtkNew<vtkConeSource> cone;
  cone->SetResolution(4);
  cone->SetHeight(1.0);
  cone->SetRadius(0.3);
  cone->SetCenter(0.0, 0.0, 0.0);
  cone->SetDirection(1.0, 0.0, 0.0);
  vtkNew<vtkTransform> tf;
  tf->Scale(1.0, 1.0, 0.35);
  tf->RotateX(45.0);
  vtkNew<vtkTransformPolyDataFilter> f;
  f->SetTransform(tf);
  f->SetInputConnection(cone->GetOutputPort());
  f->Update();
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->ShallowCopy(f->GetOutput());
  return pd;
}

void StyleText(vtkTextProperty *tp, int size, bool bold = false) {
  NavApplyFont(tp);
  tp->SetFontSize(size);
  tp->SetColor(kTextColor[0], kTextColor[1], kTextColor[2]);
  tp->SetBold(bold);
  tp->SetShadow(false);
}

double Sq(double x) {
  return x * x;
}

vtkSmartPointer<vtkLookupTable> MakeErrorLut(double max_m) {
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->SetNumberOfTableValues(256);
  for (int i = 0; i < 256; ++i) {
    const double u = i / 255.0 * 4.0;
    const int k = std::min(static_cast<int>(u), 3);
    const double f = u - k;
    lut->SetTableValue(i, kViridis[k][0] + f * (kViridis[k + 1][0] - kViridis[k][0]),
                       kViridis[k][1] + f * (kViridis[k + 1][1] - kViridis[k][1]),
                       kViridis[k][2] + f * (kViridis[k + 1][2] - kViridis[k][2]), 1.0);
  }
  lut->SetRange(0.0, max_m > 0.0 ? max_m : 1.0);
  lut->Build();
  return lut;
}

constexpr double kPi = 3.14159265358979323846;

} // namespace

// ----------------------------------------------------------------------------- NavSceneViewImpl

int NavSceneViewImpl::FontSize(double scale) const {
  const int h = std::min(Options.height_px, static_cast<int>(Options.width_px * 0.8));
  return std::max(10, static_cast<int>(std::lround(scale * h / 42.0)));
}

bool NavSceneViewImpl::EnsureWindow(bool offscreen, std::string *error) {
  if (External) {
    if (Window == External) return true;
    Window = External;
    Renderer = vtkSmartPointer<vtkRenderer>::New();
    // One layer above the host's renderer, through its camera: the host's picture (ground,
    // handles) stays underneath, our renderer clears only depth.
    const int layer = Under ? Under->GetLayer() + 1 : 1;
    if (Window->GetNumberOfLayers() < layer + 1) Window->SetNumberOfLayers(layer + 1);
    Renderer->SetLayer(layer);
    Renderer->InteractiveOff();
    if (Under) Renderer->SetActiveCamera(Under->GetActiveCamera());
    Window->AddRenderer(Renderer);
    Panel = vtkSmartPointer<vtkRenderer>::New();
    Panel->InteractiveOff();
    Window->AddRenderer(Panel);
    Offscreen = false;
    Built = false;
    return true;
  }
  if (Window && Offscreen == offscreen) return true;
  if (!NavCheckDisplay(error)) return false;
  if (Window) Window->Finalize();
  Window = vtkSmartPointer<vtkRenderWindow>::New();
  NavAttachDisplay(Window);
  Window->SetOffScreenRendering(offscreen ? 1 : 0);
  Window->SetMultiSamples(Options.multisamples);
  Window->SetSize(Options.width_px, Options.height_px);
  Window->SetWindowName("navview");
  Renderer = vtkSmartPointer<vtkRenderer>::New();
  Window->AddRenderer(Renderer);
  Panel = vtkSmartPointer<vtkRenderer>::New();
  Panel->InteractiveOff();
  Window->AddRenderer(Panel);
  Offscreen = offscreen;
  Built = false;
  return true;
}

void NavSceneViewImpl::FitCamera(const std::vector<double> &pts, const double rect[4]) {
  vtkCamera *cam = Renderer->GetActiveCamera();
  cam->SetWindowCenter(0.0, 0.0);
  double box[6] = {INFINITY, -INFINITY, INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (size_t i = 0; i + 2 < pts.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      box[2 * k] = std::min(box[2 * k], pts[i + static_cast<size_t>(k)]);
      box[2 * k + 1] = std::max(box[2 * k + 1], pts[i + static_cast<size_t>(k)]);
    }
  auto ndc_bounds = [&](double nb[4]) {
    nb[0] = nb[2] = INFINITY;
    nb[1] = nb[3] = -INFINITY;
    for (size_t i = 0; i + 2 < pts.size(); i += 3) {
      Renderer->SetWorldPoint(pts[i], pts[i + 1], pts[i + 2], 1.0);
      Renderer->WorldToView();
      const double *v = Renderer->GetViewPoint();
      nb[0] = std::min(nb[0], v[0]);
      nb[1] = std::max(nb[1], v[0]);
      nb[2] = std::min(nb[2], v[1]);
      nb[3] = std::max(nb[3], v[1]);
    }
  };
  // Scale first (dolly or parallel scale; perspective makes it non-linear, so iterate), then
  // shift the image with the window centre, which changes no perspective.
  for (int it = 0; it < 8; ++it) {
    Renderer->ResetCameraClippingRange(box[0], box[1], box[2], box[3], box[4], box[5]);
    double nb[4];
    ndc_bounds(nb);
    const double s = std::max((nb[1] - nb[0]) / (rect[1] - rect[0]), (nb[3] - nb[2]) / (rect[3] - rect[2]));
    if (!(s > 0.0) || !std::isfinite(s)) break;
    if (cam->GetParallelProjection())
      cam->SetParallelScale(cam->GetParallelScale() * s);
    else
      cam->Dolly(1.0 / s);
    if (std::fabs(s - 1.0) < 1e-3) break;
  }
  for (int it = 0; it < 3; ++it) {
    double nb[4];
    ndc_bounds(nb);
    const double *wc = cam->GetWindowCenter();
    const double dx = 0.5 * (rect[0] + rect[1]) - 0.5 * (nb[0] + nb[1]);
    const double dy = 0.5 * (rect[2] + rect[3]) - 0.5 * (nb[2] + nb[3]);
    cam->SetWindowCenter(wc[0] - dx, wc[1] - dy);
  }
}

void NavSceneViewImpl::SetupCamera() {
  vtkCamera *cam = Renderer->GetActiveCamera();
  if (Options.fixed_camera) {
    cam->SetParallelProjection(false);
    cam->SetWindowCenter(0.0, 0.0);
    cam->SetPosition(Options.camera_position_r);
    cam->SetFocalPoint(Options.camera_focal_r);
    cam->SetViewUp(Options.camera_view_up_r);
    cam->SetViewAngle(Options.camera_view_angle_deg);
    Renderer->ResetCameraClippingRange();
    return;
  }
  // Frame the grid, the paths' bounds with the triads around them, the NED axes (D reaches one
  // cell below the south-west corner) and the scale label under the south edge.
  const double *b = Model.bounds_r, *g = Model.grid_r;
  const double s = Model.grid_spacing_m, z0 = Model.ground_z_r, pad = Model.triad_size_m;
  std::vector<double> pts = {g[0], g[2], z0, g[1], g[2], z0, g[0], g[3], z0, g[1], g[3], z0};
  for (int k = 0; k < 8; ++k) {
    pts.push_back(b[k & 1] + ((k & 1) ? pad : -pad));
    pts.push_back(b[2 + ((k >> 1) & 1)] + (((k >> 1) & 1) ? pad : -pad));
    pts.push_back(b[4 + ((k >> 2) & 1)] + (((k >> 2) & 1) ? pad : -pad));
  }
  if (Options.show_axes) {
    pts.insert(pts.end(), {g[0], g[2], z0 - 1.0 * s});
    if (Options.show_text) pts.insert(pts.end(), {g[1] + 0.3 * s, g[2] - 0.6 * s, z0});
  }
  double box[6] = {INFINITY, -INFINITY, INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (size_t i = 0; i < pts.size(); i += 3)
    for (int k = 0; k < 3; ++k) {
      box[2 * k] = std::min(box[2 * k], pts[i + static_cast<size_t>(k)]);
      box[2 * k + 1] = std::max(box[2 * k + 1], pts[i + static_cast<size_t>(k)]);
    }
  const double c[3] = {0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3]), 0.5 * (box[4] + box[5])};
  const double radius =
      0.5 * std::sqrt(Sq(box[1] - box[0]) + Sq(box[3] - box[2]) + Sq(box[5] - box[4])) + 1e-3;
  if (Options.camera == NavCameraPreset::Top) {
    cam->SetParallelProjection(true);
    cam->SetFocalPoint(c);
    cam->SetPosition(c[0], c[1], c[2] + 4.0 * radius);
    cam->SetViewUp(0.0, 1.0, 0.0);
    cam->SetParallelScale(radius);
  } else {
    // From the south-south-west (azimuth 202.5 deg), 50 deg above the horizon.
    const double az = 22.5 * kPi / 180.0, el = 50.0 * kPi / 180.0;
    const double dir[3] = {-std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el)};
    const double va = 30.0;
    cam->SetParallelProjection(false);
    cam->SetViewAngle(va);
    cam->SetFocalPoint(c);
    const double dist = radius / std::sin(0.5 * va * kPi / 180.0);
    cam->SetPosition(c[0] + dist * dir[0], c[1] + dist * dir[1], c[2] + dist * dir[2]);
    cam->SetViewUp(0.0, 0.0, 1.0);
  }
  // Keep the top free for the title and read-out (two text lines) when there is text.
  const int *size = Renderer->GetSize();
  const double vh = size && size[1] > 0 ? size[1] : Options.height_px;
  const double top = Options.show_text ? 1.0 - 2.0 * (4.6 * FontSize(1.0)) / vh : 0.96;
  // The interactive window keeps the bottom free for the time slider.
  const double bottom = !Offscreen ? -0.76 : -0.96;
  const double rect[4] = {-0.96, 0.96, bottom, top};
  FitCamera(pts, rect);
  Renderer->ResetCameraClippingRange();
}

double NavSceneViewImpl::MetresPerPixel() const {
  vtkCamera *cam = Renderer->GetActiveCamera();
  const double *b = Model.bounds_r;
  const int *size = Renderer->GetSize();
  const double h = size && size[1] > 0 ? size[1] : Options.height_px;
  // Metres per pixel at the nearest bound of the paths (the most demanding depth).
  if (cam->GetParallelProjection()) return 2.0 * cam->GetParallelScale() / h;
  const double *pos = cam->GetPosition();
  double dop[3];
  cam->GetDirectionOfProjection(dop);
  double depth_min = cam->GetDistance();
  for (int k = 0; k < 8; ++k) {
    const double p[3] = {b[k & 1], b[2 + ((k >> 1) & 1)], b[4 + ((k >> 2) & 1)]};
    const double d = (p[0] - pos[0]) * dop[0] + (p[1] - pos[1]) * dop[1] + (p[2] - pos[2]) * dop[2];
    depth_min = std::min(depth_min, d);
  }
  depth_min = std::max(depth_min, 0.1 * cam->GetDistance());
  return 2.0 * depth_min * std::tan(0.5 * cam->GetViewAngle() * kPi / 180.0) / h;
}

bool NavSceneViewImpl::BuildScene(bool offscreen, std::string *error, bool keep_camera) {
  // The outage band's depth offset (AddGnss) needs VTK's coincident-topology resolution, which
  // is off by default. It is a process-wide setting: its global offsets are set to zero, so that
  // only the band's own offset applies and every other actor is drawn as before (an offset makes
  // the fragment shader write its depth, which costs llvmpipe time on every line).
  vtkMapper::SetResolveCoincidentTopologyToPolygonOffset();
  vtkMapper::SetResolveCoincidentTopologyPolygonOffsetParameters(0.0, 0.0);
  vtkMapper::SetResolveCoincidentTopologyLineOffsetParameters(0.0, 0.0);
  vtkMapper::SetResolveCoincidentTopologyPointOffsetParameter(0.0);
  if (!Result) {
    *error = "no result set";
    return false;
  }
  if (Options.width_px < 16 || Options.height_px < 16 || Options.width_px > 8192 ||
      Options.height_px > 8192) {
    *error = "window size out of range (16..8192 pixels)";
    return false;
  }
  if (!EnsureWindow(offscreen, error)) return false;
  if (External) {
    const int *wsz = Window->GetSize();
    if (wsz && wsz[0] >= 16 && wsz[1] >= 16) {
      Options.width_px = wsz[0];
      Options.height_px = wsz[1];
    }
  } else {
    Window->SetSize(Options.width_px, Options.height_px);
  }
  Renderer->RemoveAllViewProps();
  TriadMappers.clear();
  TriadFactors.clear();
  NowRef = NowEst = nullptr;
  EnvelopeActor = nullptr;
  EllipsoidActors.clear();
  StaleColors.clear();
  ScaleMpp = 0.0;
  Panel->RemoveAllViewProps();
  Renderer->SetBackground(1.0, 1.0, 1.0);
  Renderer->SetBackground2(0.90, 0.93, 0.97);
  Renderer->GradientBackgroundOn();
  // No depth peeling: with multisampling it hid the translucent tube entirely (llvmpipe,
  // VTK 9.1). The tube is the only translucent surface, so plain blending is enough.
  Renderer->SetUseDepthPeeling(0);
  Renderer->SetUseFXAA(Options.fxaa);
  Panel->SetBackground(0.985, 0.985, 0.99);
  Vehicle = nullptr;
  EstimateMarker = nullptr;
  EstimateActor = nullptr;
  Title = Readout = PickText = Info = nullptr;
  ScalarBar = nullptr;
  ErrorLut = nullptr;
  VehiclePlaced = false;

  // A model without geometry first: the grid and triad size the camera frames.
  NavSceneModel probe;
  if (!NavBuildSceneModel(*Result, Options, -1.0, &probe, error)) return false;
  Model = probe;

  // The side panel (legend, scalar bar, notes) takes its width from its text.
  PanelFraction = 0.0;
  LegendCompact = false;
  LegendFontPx = 0;
  if (Options.show_text) AddPanel();
  Renderer->SetViewport(0.0, 0.0, 1.0 - PanelFraction, 1.0);
  if (Under) Under->SetViewport(0.0, 0.0, 1.0 - PanelFraction, 1.0);
  Panel->SetViewport(1.0 - PanelFraction, 0.0, 1.0, 1.0);
  Panel->SetDraw(PanelFraction > 0.0);

  if (!keep_camera && !External) SetupCamera();
  const double m_per_px = MetresPerPixel();
  ScaleMpp = Options.follow ? 0.0 : m_per_px;
  const double tol_m = std::max(Options.decimate_px, 0.0) * m_per_px;
  if (!NavBuildSceneModel(*Result, Options, tol_m, &Model, error)) return false;
  PickRadiusM = 12.0 * m_per_px;

  AddGrid();
  AddGnss();
  AddPaths();
  if (Options.show_triads) AddTriads();
  if (Options.show_axes) AddAxesAndScale();
  AddVehicle();
  // Blended surfaces last, in this order (they are drawn in the opaque pass: AddEnvelope).
  AddEllipsoids();
  AddEnvelope();
  if (Options.show_text) AddText();
  Built = true;
  if (!std::isfinite(TimeS)) TimeS = std::isfinite(Options.time_s) ? Options.time_s : Model.t_end_s;
  UpdateTime();
  ApplyStale();
  Renderer->ResetCameraClippingRange();
  return true;
}

double NavSceneViewImpl::FollowDistance() const {
  if (Options.follow_distance_m > 0.0) return Options.follow_distance_m;
  // 60 m shows a car and its surroundings; a small scene gets a third of its extent.
  const double extent = Model.triad_size_m / 0.06;
  return std::max(2.0, std::min(60.0, 0.3 * extent));
}

double NavSceneViewImpl::ViewTriadSize() const {
  // Following, the triads and the vehicle are sized for the camera distance (about a twelfth of
  // it), else for the scene's extent (the model's).
  return Options.follow ? std::min(Model.triad_size_m, 0.08 * FollowDistance()) : Model.triad_size_m;
}

void NavSceneViewImpl::PlaceFollowCamera(const double p_ref[3]) {
  // Behind the vehicle along its direction of travel over the last few seconds (steadier than
  // the instantaneous heading), 25 deg above the horizon, looking at the vehicle.
  const double span = std::max(2.0, 0.01 * (Model.t_end_s - Model.t_begin_s));
  double pa[3], pb[3];
  NavTrackSample(Result->truth, std::max(Model.t_begin_s, TimeS - span), pa, nullptr);
  NavTrackSample(Result->truth, std::min(Model.t_end_s, TimeS + 0.25 * span), pb, nullptr);
  double hx = pb[0] - pa[0], hy = pb[1] - pa[1];
  const double hn = std::hypot(hx, hy);
  if (hn > 1e-6) {
    hx /= hn;
    hy /= hn;
    FollowHeading[0] = hx;
    FollowHeading[1] = hy;
  } else {
    hx = FollowHeading[0];
    hy = FollowHeading[1];
  }
  const double d = FollowDistance(), el = 25.0 * kPi / 180.0;
  vtkCamera *cam = Renderer->GetActiveCamera();
  cam->SetParallelProjection(false);
  cam->SetViewAngle(30.0);
  cam->SetWindowCenter(0.0, 0.0);
  cam->SetFocalPoint(p_ref[0], p_ref[1], p_ref[2]);
  cam->SetPosition(p_ref[0] - d * std::cos(el) * hx, p_ref[1] - d * std::cos(el) * hy, p_ref[2] + d * std::sin(el));
  cam->SetViewUp(0.0, 0.0, 1.0);
  Renderer->ResetCameraClippingRange();
}

void NavSceneViewImpl::UpdateScale(bool force) {
  const int *size = Renderer->GetSize();
  const double h = size && size[1] > 0 ? size[1] : Options.height_px;
  const double mpp = Options.follow ? 2.0 * FollowDistance() * std::tan(15.0 * kPi / 180.0) / h : MetresPerPixel();
  const double ts = ViewTriadSize();
  for (size_t i = 0; i < TriadMappers.size(); ++i)
    TriadMappers[i]->SetScaleFactor(ts * TriadFactors[i]);
  if (EstimateMarker) EstimateMarker->SetScale(0.14 * ts);
  if (!force && ScaleMpp > 0.0 && mpp < 1.5 * ScaleMpp && mpp > ScaleMpp / 1.5) return;
  ScaleMpp = mpp;
  // The envelope floor is in pixels: rebuild the blended surfaces (drawn last, as BuildScene).
  if (EnvelopeActor) Renderer->RemoveActor(EnvelopeActor);
  for (auto &a : EllipsoidActors)
    Renderer->RemoveActor(a);
  EllipsoidActors.clear();
  EnvelopeActor = nullptr;
  AddEllipsoids();
  AddEnvelope();
  ApplyStale();
}

void NavSceneViewImpl::AddPaths() {
  for (size_t r = 0; r < Model.extra_runs.size(); ++r) {
    auto pd = MakePolyline(Model.extra_runs[r].xyz_r);
    auto a = LineActor(pd, kRunColor, 1.0);
    // Opaque (a light colour instead of opacity): any translucent actor makes VTK 9.1 run its
    // order-independent-translucency fallback, about 11 ms per 1000x700 frame on llvmpipe.
    Renderer->AddActor(a);
  }
  auto ref = MakePolyline(Model.reference.xyz_r);
  Renderer->AddActor(LineActor(ref, kRefColor, 2.5));

  auto est = MakePolyline(Model.estimate.xyz_r);
  const bool colour = Options.color_by_error && !Model.estimate.scalar.empty() && Model.error_max_m > 0.0;
  auto actor = LineActor(est, kEstColor, colour ? 3.5 : 2.0);
  if (colour) {
    vtkNew<vtkDoubleArray> s;
    s->SetName("pos_err_h_m");
    s->SetNumberOfValues(static_cast<vtkIdType>(Model.estimate.scalar.size()));
    for (size_t i = 0; i < Model.estimate.scalar.size(); ++i)
      s->SetValue(static_cast<vtkIdType>(i), Model.estimate.scalar[i]);
    est->GetPointData()->SetScalars(s);
    if (!ErrorLut) ErrorLut = MakeErrorLut(Model.error_max_m);
    auto *mapper = vtkPolyDataMapper::SafeDownCast(actor->GetMapper());
    mapper->SetLookupTable(ErrorLut);
    mapper->SetScalarRange(0.0, Model.error_max_m);
    mapper->SetScalarModeToUsePointData();
    mapper->ScalarVisibilityOn();
    if (!Options.show_text) {
      // Without text the colour bar still shows the map, unlabelled, at the right edge.
      ScalarBar = vtkSmartPointer<vtkScalarBarActor>::New();
      ScalarBar->SetLookupTable(ErrorLut);
      ScalarBar->SetOrientationToVertical();
      ScalarBar->DrawTickLabelsOff();
      ScalarBar->SetTitle("");
      ScalarBar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
      ScalarBar->GetPositionCoordinate()->SetValue(0.92, 0.25);
      ScalarBar->SetWidth(0.07);
      ScalarBar->SetHeight(0.5);
      ScalarBar->SetBarRatio(0.6);
      Renderer->AddViewProp(ScalarBar);
    }
  }
  Renderer->AddActor(actor);
  EstimateActor = actor;
}

void NavSceneViewImpl::AddEnvelope() {
  const NavTube &tube = Model.envelope;
  if (tube.Size() < 2) return;
  auto pd = MakePolyline(tube.xyz_r);
  vtkNew<vtkDoubleArray> r;
  r->SetName("radius_m");
  r->SetNumberOfValues(static_cast<vtkIdType>(tube.Size()));
  // vtkTubeFilter needs a positive radius to form its frame; a floor far below a pixel keeps the
  // geometry valid where sigma is zero without showing anything there.
  const double floor_m = std::max(1e-3 * Model.decimation_tol_m + 1e-9, 0.5 * Options.min_envelope_px * ScaleMpp);
  for (size_t i = 0; i < tube.Size(); ++i)
    r->SetValue(static_cast<vtkIdType>(i), std::max(tube.radius_m[i], floor_m));
  pd->GetPointData()->SetScalars(r);
  vtkNew<vtkTubeFilter> tf;
  tf->SetInputData(pd);
  tf->SetVaryRadiusToVaryRadiusByAbsoluteScalar();
  tf->SetNumberOfSides(16);
  tf->CappingOff();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(tf->GetOutputPort());
  mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(kTubeColor[0], kTubeColor[1], kTubeColor[2]);
  actor->GetProperty()->SetOpacity(0.28);
  // Blended in the opaque pass (ForceOpaque) instead of VTK's order-independent-translucency
  // fallback, which cost about 11 ms per 1000x700 frame on llvmpipe (the default view went from
  // 27 to 16 ms CPU per frame without it). Correct because the tube is drawn last (BuildScene
  // adds it after every opaque actor, after the ellipsoids) and only its front faces are drawn,
  // so each pixel is tinted once.
  actor->ForceOpaqueOn();
  actor->GetProperty()->BackfaceCullingOn();
  actor->GetProperty()->SetSpecular(0.0);
  actor->GetProperty()->SetAmbient(0.25);
  Renderer->AddActor(actor);
  EnvelopeActor = actor;
}

void NavSceneViewImpl::AddGnss() {
  // Outages: a wide pink band under the paths. A 9 px line along the reference is nearer to the
  // camera than the estimate beside it wherever the estimate lies behind the reference, and hid
  // it there: its depth is pushed back (kOutageDepthUnits, in VTK's coincident-topology units of
  // 1.6e-5 of the depth range) so that every path, the estimate above all, is drawn over it.
  for (const NavPolyline &seg : Model.outage_segments) {
    if (seg.Size() < 2) continue;
    auto a = LineActor(MakePolyline(seg.xyz_r), kOutageColor, 9.0); // opaque: see AddPaths
    a->GetMapper()->SetRelativeCoincidentTopologyLineOffsetParameters(0.0, kOutageDepthUnits);
    Renderer->AddActor(a);
  }
  // Fixes: small green spheres (points rendered as spheres keep their pixel size at any zoom).
  const size_t n = Model.gnss_r.size() / 3;
  if (n == 0) return;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> verts;
  // Display thinning: fixes closer than three dot diameters on screen to the last one drawn are
  // skipped, so the paths stay visible between them (1 Hz fixes of a car at city scale would
  // otherwise cover the estimate).
  const float dot_px = std::max(4.0f, static_cast<float>(Options.height_px) / 130.0f);
  const double min_gap = 3.0 * dot_px * std::max(MetresPerPixel(), 0.0);
  const double *last = nullptr;
  GnssDrawn = 0;
  for (size_t i = 0; i < n; ++i) {
    const double *p = &Model.gnss_r[3 * i];
    if (last && std::sqrt(Sq(p[0] - last[0]) + Sq(p[1] - last[1]) + Sq(p[2] - last[2])) < min_gap) continue;
    last = p;
    const vtkIdType id = pts->InsertNextPoint(p);
    verts->InsertNextCell(1, &id);
    ++GnssDrawn;
  }
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetVerts(verts);
  vtkNew<vtkPolyDataMapper> m;
  m->SetInputData(pd);
  m->ScalarVisibilityOff();
  vtkNew<vtkActor> a;
  a->SetMapper(m);
  a->GetProperty()->SetColor(kGnssColor[0], kGnssColor[1], kGnssColor[2]);
  a->GetProperty()->SetPointSize(dot_px);
  a->GetProperty()->SetRenderPointsAsSpheres(true);
  // Mostly flat colour: shaded sphere impostors of a few pixels come out nearly black.
  a->GetProperty()->SetAmbient(0.75);
  a->GetProperty()->SetDiffuse(0.35);
  a->GetProperty()->SetSpecular(0.0);
  Renderer->AddActor(a);
}

void NavSceneViewImpl::AddEllipsoids() {
  for (const NavEllipsoid &e : Model.ellipsoids) {
    vtkNew<vtkSphereSource> sphere;
    sphere->SetRadius(1.0);
    sphere->SetThetaResolution(28);
    sphere->SetPhiResolution(16);
    vtkNew<vtkPolyDataMapper> m;
    m->SetInputConnection(sphere->GetOutputPort());
    vtkNew<vtkActor> a;
    a->SetMapper(m);
    // A floor far below a pixel keeps a zero sigma from collapsing the matrix.
    const double fl = std::max(1e-6 * std::max(Model.triad_size_m, 1e-9), 0.5 * Options.min_envelope_px * ScaleMpp);
    a->SetScale(std::max(e.semi_axes_r[0], fl), std::max(e.semi_axes_r[1], fl), std::max(e.semi_axes_r[2], fl));
    a->SetPosition(e.center_r[0], e.center_r[1], e.center_r[2]);
    a->GetProperty()->SetColor(kEllipsoidColor[0], kEllipsoidColor[1], kEllipsoidColor[2]);
    // Following, the camera is close to the ellipsoids: fainter, so the vehicle shows through.
    a->GetProperty()->SetOpacity(Options.follow ? 0.2 : 0.45);
    a->ForceOpaqueOn(); // blended in the opaque pass, before the tube: see AddEnvelope
    a->GetProperty()->BackfaceCullingOn();
    a->GetProperty()->SetSpecular(0.2);
    a->GetProperty()->SetAmbient(0.3);
    Renderer->AddActor(a);
    EllipsoidActors.push_back(a);
  }
}

vtkSmartPointer<vtkPolyData> TriadPolyData(const NavTriadSet &set) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> q;
  q->SetName("q_b_r");
  q->SetNumberOfComponents(4);
  for (size_t i = 0; i < set.Size(); ++i) {
    pts->InsertNextPoint(&set.xyz_r[3 * i]);
    q->InsertNextTuple(&set.q_b_r[4 * i]);
  }
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(pts);
  pd->GetPointData()->AddArray(q);
  return pd;
}

void NavSceneViewImpl::AddTriads() {
  auto add_set = [&](const NavTriadSet &set, const double colors[3][3], bool thin, double factor,
                     vtkSmartPointer<vtkPolyData> *keep) {
    if (set.Size() == 0) return;
    auto pd = TriadPolyData(set);
    if (keep) *keep = pd;
    for (int axis = 0; axis < 3; ++axis) {
      // One mapper per axis: vtkGlyph3DMapper ignores source colours (toolchain.md section 3).
      vtkNew<vtkGlyph3DMapper> gm;
      gm->SetInputData(pd);
      gm->SetSourceData(AxisArrow(axis, thin));
      gm->SetOrientationModeToQuaternion();
      gm->SetOrientationArray("q_b_r");
      gm->SetScaleModeToNoDataScaling();
      gm->SetScaleFactor(Model.triad_size_m * factor);
      gm->ScalarVisibilityOff();
      TriadMappers.push_back(gm.GetPointer());
      TriadFactors.push_back(factor);
      vtkNew<vtkActor> a;
      a->SetMapper(gm);
      a->GetProperty()->SetColor(colors[axis][0], colors[axis][1], colors[axis][2]);
      a->GetProperty()->SetAmbient(0.2);
      Renderer->AddActor(a);
    }
  };
  const double grey[3][3] = {{kTriadRefGrey[0], kTriadRefGrey[1], kTriadRefGrey[2]},
                             {kTriadRefGrey[0], kTriadRefGrey[1], kTriadRefGrey[2]},
                             {kTriadRefGrey[0], kTriadRefGrey[1], kTriadRefGrey[2]}};
  add_set(Model.triads_ref, grey, true, 1.0, nullptr);
  add_set(Model.triads_est, kTriadRGB, false, 0.92, nullptr);
  // The pair at the playback time, a little larger, moved by UpdateTime.
  if (!Options.show_triads_at_time) return;
  NavTriadSet now_ref, now_est;
  NavAppendTriadsAt(*Result, Options.att_exaggeration, Model.t_begin_s, &now_ref, &now_est);
  add_set(now_ref, grey, true, 1.3, &NowRef);
  add_set(now_est, kTriadRGB, false, 1.25, &NowEst);
}

void NavSceneViewImpl::AddGrid() {
  if (!Options.show_grid) return;
  const double *g = Model.grid_r;
  const double s = Model.grid_spacing_m, z = Model.ground_z_r;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkCellArray> lines;
  auto seg = [&](double x0, double y0, double x1, double y1) {
    const vtkIdType a = pts->InsertNextPoint(x0, y0, z);
    const vtkIdType b = pts->InsertNextPoint(x1, y1, z);
    const vtkIdType ids[2] = {a, b};
    lines->InsertNextCell(2, ids);
  };
  const long nx = std::lround((g[1] - g[0]) / s), ny = std::lround((g[3] - g[2]) / s);
  for (long i = 0; i <= nx; ++i)
    seg(g[0] + i * s, g[2], g[0] + i * s, g[3]);
  for (long j = 0; j <= ny; ++j)
    seg(g[0], g[2] + j * s, g[1], g[2] + j * s);
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  Renderer->AddActor(LineActor(pd, kGridColor, 1.0));
}

vtkSmartPointer<vtkTextActor> NavSceneViewImpl::Label3D(const char *text, const double pos[3],
                                                        const double rgb[3], double scale, int dx_px,
                                                        int dy_px) {
  // A 2D text anchored at a world point: crisp, always readable, never hidden by the scene.
  // (vtkBillboardTextActor3D left a ghost copy of the glyphs under the text in plan views.)
  auto t = vtkSmartPointer<vtkTextActor>::New();
  t->SetInput(text);
  StyleText(t->GetTextProperty(), FontSize(scale), true);
  t->GetTextProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
  t->GetTextProperty()->SetJustificationToCentered();
  t->GetTextProperty()->SetVerticalJustificationToCentered();
  vtkNew<vtkCoordinate> anchor;
  anchor->SetCoordinateSystemToWorld();
  anchor->SetValue(pos[0], pos[1], pos[2]);
  t->GetPositionCoordinate()->SetCoordinateSystemToDisplay();
  t->GetPositionCoordinate()->SetReferenceCoordinate(anchor);
  t->GetPositionCoordinate()->SetValue(dx_px, dy_px);
  return t;
}

void NavSceneViewImpl::AddAxesAndScale() {
  // NED axes at the south-west corner of the grid: N = +y, E = +x, D = -z of frame r.
  const double s = Model.grid_spacing_m;
  const double o[3] = {Model.grid_r[0], Model.grid_r[2], Model.ground_z_r};
  const double ned_dirs[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const char *names[3] = {"N", "E", "D"};
  for (int k = 0; k < 3; ++k) {
    double d_r[3];
    NavNedToRender(ned_dirs[k], d_r);
    vtkNew<vtkArrowSource> arrow;
    arrow->SetTipLength(0.22);
    arrow->SetTipRadius(0.06);
    arrow->SetShaftRadius(0.018);
    arrow->SetTipResolution(16);
    arrow->SetShaftResolution(8);
    // Orient the unit +x arrow along d_r, scale it to 0.7 grid cell and move it to o.
    vtkNew<vtkTransform> tf;
    tf->Translate(o);
    if (d_r[1] > 0.5) tf->RotateZ(90.0);
    if (d_r[1] < -0.5) tf->RotateZ(-90.0);
    if (d_r[2] > 0.5) tf->RotateY(-90.0);
    if (d_r[2] < -0.5) tf->RotateY(90.0);
    if (d_r[0] < -0.5) tf->RotateZ(180.0);
    tf->Scale(0.7 * s, 0.7 * s, 0.7 * s);
    vtkNew<vtkTransformPolyDataFilter> f;
    f->SetTransform(tf);
    f->SetInputConnection(arrow->GetOutputPort());
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(f->GetOutputPort());
    vtkNew<vtkActor> a;
    a->SetMapper(mapper);
    a->GetProperty()->SetColor(kAxisColor[0], kAxisColor[1], kAxisColor[2]);
    Renderer->AddActor(a);
    if (Options.show_text) {
      const double lp[3] = {o[0] + 0.9 * s * d_r[0], o[1] + 0.9 * s * d_r[1], o[2] + 0.9 * s * d_r[2]};
      // D points along the view direction in a plan view: nudge it off the axes' origin.
      const int off = k == 2 ? FontSize(0.8) : 0;
      Renderer->AddViewProp(Label3D(names[k], lp, kAxisColor, 1.0, off, -off));
    }
  }

  // Scale bar: one grid cell on the south edge of the grid's south-east cell.
  const double y = Model.grid_r[2], x1 = Model.grid_r[1], x0 = x1 - s, z = Model.ground_z_r;
  const double tick = 0.12 * s;
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->InsertNextPoint(x0, y, z);
  pts->InsertNextPoint(x1, y, z);
  pts->InsertNextPoint(x0, y - tick, z);
  pts->InsertNextPoint(x0, y + tick, z);
  pts->InsertNextPoint(x1, y - tick, z);
  pts->InsertNextPoint(x1, y + tick, z);
  vtkNew<vtkCellArray> lines;
  const vtkIdType a[2] = {0, 1}, b[2] = {2, 3}, c[2] = {4, 5};
  lines->InsertNextCell(2, a);
  lines->InsertNextCell(2, b);
  lines->InsertNextCell(2, c);
  vtkNew<vtkPolyData> pd;
  pd->SetPoints(pts);
  pd->SetLines(lines);
  Renderer->AddActor(LineActor(pd, kTextColor, 4.0));
  if (Options.show_text) {
    char buf[64];
    if (s >= 1000.0)
      std::snprintf(buf, sizeof buf, "%g km", s / 1000.0);
    else
      std::snprintf(buf, sizeof buf, "%g m", s);
    const double lp[3] = {0.5 * (x0 + x1), y - 0.45 * s, z};
    Renderer->AddViewProp(Label3D(buf, lp, kTextColor, 0.95, 0, 0));
  }
}

void NavSceneViewImpl::AddVehicle() {
  if (!Options.show_vehicle) return;
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(Model.vehicle == NavVehicleKind::Aircraft
                           ? AircraftShape()
                           : (Model.vehicle == NavVehicleKind::Car ? VehicleShape() : GenericShape()));
  Vehicle = vtkSmartPointer<vtkActor>::New();
  Vehicle->SetMapper(mapper);
  Vehicle->GetProperty()->SetColor(kVehicleColor[0], kVehicleColor[1], kVehicleColor[2]);
  Vehicle->GetProperty()->SetAmbient(0.25);
  Vehicle->GetProperty()->SetSpecular(0.3);
  Renderer->AddActor(Vehicle);

  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(1.0);
  sphere->SetThetaResolution(20);
  sphere->SetPhiResolution(12);
  vtkNew<vtkPolyDataMapper> smapper;
  smapper->SetInputConnection(sphere->GetOutputPort());
  EstimateMarker = vtkSmartPointer<vtkActor>::New();
  EstimateMarker->SetMapper(smapper);
  EstimateMarker->GetProperty()->SetColor(kEstColor[0], kEstColor[1], kEstColor[2]);
  EstimateMarker->SetScale(0.14 * Model.triad_size_m);
  Renderer->AddActor(EstimateMarker);
}

void NavSceneViewImpl::AddText() {
  Title = vtkSmartPointer<vtkTextActor>::New();
  char buf[512];
  if (Result->runs > 1)
    std::snprintf(buf, sizeof buf, "%s \u00b7 run 0 of %d", Result->scene_name.c_str(), Result->runs);
  else
    std::snprintf(buf, sizeof buf, "%s", Result->scene_name.c_str());
  TitleText = buf;
  Title->SetInput(buf);
  StyleText(Title->GetTextProperty(), FontSize(1.15), true);
  Title->GetTextProperty()->SetVerticalJustificationToTop();
  Title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  Title->GetPositionCoordinate()->SetValue(0.015, 0.985);
  Renderer->AddViewProp(Title);

  Readout = vtkSmartPointer<vtkTextActor>::New();
  StyleText(Readout->GetTextProperty(), FontSize(1.0));
  Readout->GetTextProperty()->SetVerticalJustificationToTop();
  Readout->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  Readout->GetPositionCoordinate()->SetValue(0.015, 0.985 - 1.8 * FontSize(1.15) / Options.height_px);
  Renderer->AddViewProp(Readout);

  if (Info) {
    // Notes at the bottom of the panel, once the decimation is known.
    const double sp = Model.grid_spacing_m;
    std::string grid;
    if (sp >= 1000.0)
      std::snprintf(buf, sizeof buf, "%g km", sp / 1000.0);
    else
      std::snprintf(buf, sizeof buf, "%g m", sp);
    grid = buf;
    char gbuf[160] = "";
    int gn = 0;
    if (GnssDrawn > 0 && GnssDrawn < Model.gnss_r.size() / 3)
      gn = std::snprintf(gbuf, sizeof gbuf, "\nGNSS fixes: %zu of %zu drawn", GnssDrawn, Model.gnss_r.size() / 3);
    if (Model.ellipsoids_too_large > 0 && gn >= 0 && gn < static_cast<int>(sizeof gbuf))
      std::snprintf(gbuf + gn, sizeof gbuf - static_cast<size_t>(gn), "\n%zu ellipsoid%s wider than the scene\nnot drawn",
                    Model.ellipsoids_too_large, Model.ellipsoids_too_large == 1 ? "" : "s");
    size_t drawn = Model.reference.Size() + Model.estimate.Size();
    for (const NavPolyline &p : Model.extra_runs)
      drawn += p.Size();
    std::snprintf(buf, sizeof buf,
                  "grid %s, scale bar one cell\ntriads every %g s\ndrawn %zu of %zu epochs\n(tolerance %.2g "
                  "px = %.3g m)%s",
                  grid.c_str(), Model.triad_interval_s, drawn, Model.full_points, Options.decimate_px,
                  Model.decimation_tol_m, gbuf);
    Info->SetInput(buf);
  }

  PickText = vtkSmartPointer<vtkTextActor>::New();
  StyleText(PickText->GetTextProperty(), FontSize(0.9));
  PickText->GetTextProperty()->SetJustificationToRight();
  PickText->GetTextProperty()->SetVerticalJustificationToTop();
  PickText->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  PickText->GetPositionCoordinate()->SetValue(0.985, 0.985);
  PickText->SetInput("");
  Renderer->AddViewProp(PickText);
}

void NavSceneViewImpl::AddPanel() {
  enum class Sym { Line, Box, Arrow, Triad, Dot };
  struct Entry {
    Sym sym;
    std::string text;
    const double *rgb;
    double width;
    std::string compact; /**< short form for a narrow view (empty: the text itself) */
  };
  const bool colour = Options.color_by_error && Result->errors.Size() > 0;
  std::vector<Entry> e;
  e.push_back({Sym::Line, "reference", kRefColor, 3.0, ""});
  e.push_back({Sym::Line, colour ? "estimate (run 0),\ncolour = horizontal error" : "estimate (run 0)",
               kEstColor, 2.0, colour ? "estimate,\ncolour = error" : "estimate"});
  if (!Result->extra_runs.empty())
    e.push_back({Sym::Line, std::to_string(Result->extra_runs.size()) + " further runs", kRunColor, 1.5, ""});
  // The tube label is known once the model has its envelope; recompute the source here.
  const NavEnvelopeSource src = NavResolveEnvelopeSource(*Result, Options.envelope_source);
  char buf[160];
  if (Options.show_gnss && Result->gnss.Size() > 0)
    e.push_back({Sym::Dot, "GNSS fixes (run 0)", kGnssColor, 0.0, "GNSS fixes"});
  if (Options.show_gnss && !Result->gnss.outage_t0_s.empty()) {
    std::snprintf(buf, sizeof buf, "GNSS outage (%zu)", Result->gnss.outage_t0_s.size());
    e.push_back({Sym::Line, buf, kOutageColor, 7.0, "GNSS outage"});
  }
  if (src != NavEnvelopeSource::None && Options.envelope_k > 0.0) {
    // The largest radius tells why a tube may be invisible (an ideal run has micrometres).
    double rmax = 0.0;
    for (size_t i = 0; i < Result->truth.Size(); i += std::max<size_t>(1, Result->truth.Size() / 4000)) {
      const double sh = NavSigmaH(*Result, src, Result->truth.t_s[i]);
      if (std::isfinite(sh)) rmax = std::max(rmax, Options.envelope_k * sh);
    }
    char rbuf[32];
    if (rmax >= 0.01 || rmax == 0.0)
      std::snprintf(rbuf, sizeof rbuf, "%.3g m", rmax);
    else
      std::snprintf(rbuf, sizeof rbuf, "%.2g mm", 1e3 * rmax);
    if (src == NavEnvelopeSource::MonteCarlo)
      std::snprintf(buf, sizeof buf, "tube: %g\u00d7 RMS horizontal error\nover %d runs (\u2264 %s)",
                    Options.envelope_k, Result->runs, rbuf);
    else if (src == NavEnvelopeSource::Filter)
      std::snprintf(buf, sizeof buf, "tube: %g\u00d7 filter horizontal\n\u03c3, mean of %d runs (\u2264 %s)",
                    Options.envelope_k, Result->runs, rbuf);
    else if (src == NavEnvelopeSource::Covariance)
      std::snprintf(buf, sizeof buf, "tube: %g\u00d7 horizontal \u03c3 of the\ncovariance analysis (\u2264 %s)",
                    Options.envelope_k, rbuf);
    else
      std::snprintf(buf, sizeof buf, "tube: %g\u00d7 horizontal error\nof run 0 (\u2264 %s)",
                    Options.envelope_k, rbuf);
    std::string tube_text = buf;
    if (Options.min_envelope_px > 0.0) {
      std::snprintf(buf, sizeof buf, "\ndrawn at least %g px wide", Options.min_envelope_px);
      tube_text += buf;
    }
    std::snprintf(buf, sizeof buf, "%g%s tube\n\u2264 %s", Options.envelope_k,
                  src == NavEnvelopeSource::MonteCarlo  ? "\u00d7 RMS"
                  : src == NavEnvelopeSource::RunErrors ? "\u00d7 error"
                                                        : "\u03c3",
                  rbuf);
    e.push_back({Sym::Box, tube_text, kTubeColor, 0.0, buf});
    const size_t n_ell = NavEllipsoidTimes(*Result, Options).size();
    if (n_ell > 0) {
      std::snprintf(buf, sizeof buf, "ellipsoids: %g\u03c3 N/E/D\n(%s), at %zu epochs%s", Options.envelope_k,
                    NavEnvelopeSourceName(src), n_ell,
                    Options.ellipsoid_times_s.empty() && !Result->gnss.outage_t0_s.empty() ? "\nincl. outage ends"
                                                                                         : "");
      const std::string full = buf;
      std::snprintf(buf, sizeof buf, "%g\u03c3 ellipsoids", Options.envelope_k);
      e.push_back({Sym::Box, full, kEllipsoidColor, 0.0, buf});
    }
  }
  if (Options.show_triads) {
    e.push_back({Sym::Arrow, "reference attitude", kTriadRefGrey, 2.0, "ref. attitude"});
    std::snprintf(buf, sizeof buf, "estimated attitude,\nerror \u00d7%g (x red, y green,\nz blue)",
                  Options.att_exaggeration);
    const std::string full = buf;
    std::snprintf(buf, sizeof buf, "est. attitude,\nerror \u00d7%g", Options.att_exaggeration);
    e.push_back({Sym::Triad, full, kTriadRGB[0], 2.0, buf});
  }
  if (Options.show_vehicle) {
    const NavVehicleKind vk = Model.vehicle;
    e.push_back({Sym::Box,
                 vk == NavVehicleKind::Aircraft
                     ? "aircraft at t (reference)"
                     : (vk == NavVehicleKind::Car ? "car at t (reference)" : "vehicle at t (reference)"),
                 kVehicleColor, 0.0,
                 vk == NavVehicleKind::Aircraft ? "aircraft at t"
                                                : (vk == NavVehicleKind::Car ? "car at t" : "vehicle at t")});
    e.push_back({Sym::Dot, "estimated position at t", kEstColor, 0.0, "estimate at t"});
  }

  // The panel takes what its text needs, at most kLegendMaxFraction of the window's width. A
  // narrow view (navstudio's 3D view beside the map, about 440 px) would give the full entries
  // about 40 %: there the legend draws each entry's short form in a font scaled with the view's
  // width (at least kLegendMinFontPx) and leaves the notes out.
  Legend.clear();
  for (const Entry &x : e)
    Legend += x.text + "\n";
  std::vector<vtkSmartPointer<vtkTextActor>> texts;
  auto measure = [&](bool short_form, int size) {
    texts.clear();
    double w = 0.0;
    for (const Entry &x : e) {
      auto t = vtkSmartPointer<vtkTextActor>::New();
      t->SetInput((short_form && !x.compact.empty() ? x.compact : x.text).c_str());
      StyleText(t->GetTextProperty(), size);
      t->GetTextProperty()->SetVerticalJustificationToTop();
      t->GetTextProperty()->SetLineSpacing(1.05);
      double sz[2] = {0.0, 0.0};
      t->GetSize(Panel, sz);
      w = std::max(w, sz[0]);
      texts.push_back(t);
    }
    // pad + symbol + gap + text + pad
    return (0.9 + 2.4 + 0.6 + 0.9) * size + w;
  };
  int fs = FontSize(0.82);
  const double max_px = kLegendMaxFraction * Options.width_px;
  double panel_px = measure(false, fs);
  LegendCompact = panel_px > max_px;
  if (LegendCompact) {
    const int fs_full = fs;
    fs =
        std::max(kLegendMinFontPx, std::min(fs_full, static_cast<int>(std::lround(Options.width_px / 46.0))));
    panel_px = measure(true, fs);
    if (panel_px > max_px && fs > kLegendMinFontPx) {
      // Text width grows with the font size: one proportional step down.
      fs = std::max(kLegendMinFontPx, static_cast<int>(std::floor(fs * max_px / panel_px)));
      panel_px = measure(true, fs);
    }
  }
  const double line_h = 1.3 * fs, row_pad = 0.45 * fs, pad = 0.9 * fs, sym_w = 2.4 * fs, gap = 0.6 * fs;
  PanelFraction = std::min(kLegendMaxFraction, panel_px / Options.width_px);
  LegendFontPx = fs;
  const double panel_w = PanelFraction * Options.width_px;

  // Entries from the top; geometry in pixels relative to the panel's top-left corner.
  vtkNew<vtkCoordinate> anchor;
  anchor->SetCoordinateSystemToNormalizedViewport();
  anchor->SetValue(0.0, 1.0);
  auto add_2d = [&](vtkPolyData *pd, const double rgb[3], double width, double opacity) {
    vtkNew<vtkPolyDataMapper2D> m;
    m->SetInputData(pd);
    m->ScalarVisibilityOn();
    auto a = vtkSmartPointer<vtkActor2D>::New();
    a->SetMapper(m);
    a->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    a->GetPositionCoordinate()->SetValue(0.0, 1.0);
    a->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
    a->GetProperty()->SetLineWidth(static_cast<float>(width));
    a->GetProperty()->SetOpacity(opacity);
    Panel->AddViewProp(a);
  };
  double y_cursor = pad + 0.3 * fs;
  for (size_t i = 0; i < e.size(); ++i) {
    // Symbol centred on the entry's first text line.
    const double y_top = y_cursor;
    const double yc = -(y_top + 0.5 * line_h);
    const std::string &drawn = LegendCompact && !e[i].compact.empty() ? e[i].compact : e[i].text;
    y_cursor += line_h * static_cast<double>(1 + std::count(drawn.begin(), drawn.end(), '\n')) + row_pad;
    const double x0 = pad, x1 = pad + sym_w;
    vtkNew<vtkPoints> pts;
    vtkNew<vtkCellArray> cells;
    vtkNew<vtkPolyData> pd;
    pd->SetPoints(pts);
    auto seg = [&](double ax, double ay, double bx, double by) {
      const vtkIdType ids[2] = {pts->InsertNextPoint(ax, ay, 0.0), pts->InsertNextPoint(bx, by, 0.0)};
      cells->InsertNextCell(2, ids);
    };
    const Entry &x = e[i];
    if (x.sym == Sym::Line) {
      seg(x0, yc, x1, yc);
      pd->SetLines(cells);
      add_2d(pd, x.rgb, x.width, 1.0);
    } else if (x.sym == Sym::Box || x.sym == Sym::Dot) {
      const double hw = x.sym == Sym::Dot ? 0.3 * fs : 0.5 * sym_w,
                   hh = x.sym == Sym::Dot ? 0.3 * fs : 0.38 * fs;
      const double xc = 0.5 * (x0 + x1);
      const vtkIdType ids[4] = {
          pts->InsertNextPoint(xc - hw, yc - hh, 0.0), pts->InsertNextPoint(xc + hw, yc - hh, 0.0),
          pts->InsertNextPoint(xc + hw, yc + hh, 0.0), pts->InsertNextPoint(xc - hw, yc + hh, 0.0)};
      cells->InsertNextCell(4, ids);
      pd->SetPolys(cells);
      add_2d(pd, x.rgb, 1.0, x.sym == Sym::Box && (x.rgb == kTubeColor || x.rgb == kEllipsoidColor) ? 0.45 : 1.0);
    } else if (x.sym == Sym::Arrow) {
      seg(x0, yc, x1, yc);
      seg(x1, yc, x1 - 0.35 * fs, yc + 0.3 * fs);
      seg(x1, yc, x1 - 0.35 * fs, yc - 0.3 * fs);
      pd->SetLines(cells);
      add_2d(pd, x.rgb, x.width, 1.0);
    } else if (x.width > 0.0) { // Triad: three coloured axes from one origin
      const double ox = x0 + 0.35 * sym_w, oy = yc - 0.1 * fs;
      const double ends[3][2] = {{x1, oy}, {ox - 0.25 * sym_w, yc + 0.6 * fs}, {ox, yc - 0.7 * fs}};
      for (int k = 0; k < 3; ++k) {
        vtkNew<vtkPoints> p3;
        vtkNew<vtkCellArray> c3;
        const vtkIdType ids[2] = {p3->InsertNextPoint(ox, oy, 0.0),
                                  p3->InsertNextPoint(ends[k][0], ends[k][1], 0.0)};
        c3->InsertNextCell(2, ids);
        vtkNew<vtkPolyData> pk;
        pk->SetPoints(p3);
        pk->SetLines(c3);
        add_2d(pk, kTriadRGB[k], 2.5, 1.0);
      }
    }
    vtkTextActor *t = texts[i];
    t->GetPositionCoordinate()->SetCoordinateSystemToViewport();
    t->GetPositionCoordinate()->SetReferenceCoordinate(anchor);
    t->GetPositionCoordinate()->SetValue(x1 + gap, -(y_top + 0.08 * fs));
    Panel->AddViewProp(t);
  }
  const double legend_bottom_px = y_cursor + 0.5 * fs;

  if (!LegendCompact) {
    Info = vtkSmartPointer<vtkTextActor>::New();
    StyleText(Info->GetTextProperty(), FontSize(0.75));
    Info->GetTextProperty()->SetColor(0.35, 0.35, 0.4);
    Info->GetTextProperty()->SetLineSpacing(1.05);
    Info->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    Info->GetPositionCoordinate()->SetValue(pad / panel_w, 0.015);
    Info->SetInput("");
    Panel->AddViewProp(Info);
  }

  // Scalar bar of the error colouring below the legend.
  if (colour && Result->errors.Size() > 0) {
    ErrorLut =
        MakeErrorLut(*std::max_element(Result->errors.pos_err_h_m.begin(), Result->errors.pos_err_h_m.end()));
    // The bar's own title is centred over the bar and runs out of the panel: a text actor
    // aligned with the legend instead, and the labels to the right of the bar.
    auto title = vtkSmartPointer<vtkTextActor>::New();
    title->SetInput(LegendCompact ? "error [m]" : "horizontal error [m]");
    StyleText(title->GetTextProperty(), fs);
    title->GetTextProperty()->SetVerticalJustificationToTop();
    title->GetPositionCoordinate()->SetCoordinateSystemToViewport();
    title->GetPositionCoordinate()->SetReferenceCoordinate(anchor);
    title->GetPositionCoordinate()->SetValue(pad, -(legend_bottom_px + 0.4 * fs));
    Panel->AddViewProp(title);
    ScalarBar = vtkSmartPointer<vtkScalarBarActor>::New();
    ScalarBar->SetLookupTable(ErrorLut);
    ScalarBar->SetOrientationToVertical();
    ScalarBar->SetTitle("");
    ScalarBar->SetNumberOfLabels(5);
    ScalarBar->SetLabelFormat("%.3g");
    ScalarBar->UnconstrainedFontSizeOn();
    ScalarBar->SetTextPositionToSucceedScalarBar();
    ScalarBar->SetBarRatio(0.3);
    StyleText(ScalarBar->GetLabelTextProperty(), fs, false);
    const double h = Options.height_px;
    const double y_top = 1.0 - (legend_bottom_px + 2.2 * fs) / h;
    // Keep clear of the notes at the bottom of the panel (four or five lines).
    const double notes_h = LegendCompact ? 0.02 : (5.6 * 1.3 * FontSize(0.75)) / h + 0.02;
    const double bar_h = std::max(0.12, std::min(0.45, y_top - notes_h));
    ScalarBar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    ScalarBar->GetPositionCoordinate()->SetValue(pad / panel_w, y_top - bar_h);
    ScalarBar->SetWidth(std::min(0.9, 6.5 * fs / panel_w));
    ScalarBar->SetHeight(bar_h);
    Panel->AddViewProp(ScalarBar);
  }
}

void NavSceneViewImpl::UpdateTime() {
  if (!Built || !Result) return;
  TimeS = std::clamp(TimeS, Model.t_begin_s, Model.t_end_s);
  double p_ref[3], c_ref[9];
  if (!NavTrackSample(Result->truth, TimeS, p_ref, c_ref)) return;
  if (Vehicle) {
    // C_b_r column by column through the render-frame adapter.
    vtkNew<vtkMatrix4x4> mtx;
    const double sc = 1.6 * ViewTriadSize();
    for (int c = 0; c < 3; ++c) {
      const double col_n[3] = {c_ref[c], c_ref[3 + c], c_ref[6 + c]};
      double col_r[3];
      NavNedToRender(col_n, col_r);
      for (int r = 0; r < 3; ++r)
        mtx->SetElement(r, c, sc * col_r[r]);
    }
    for (int r = 0; r < 3; ++r)
      mtx->SetElement(r, 3, p_ref[r]);
    Vehicle->SetUserMatrix(mtx);
  }
  double p_est[3];
  const bool have_est = NavTrackSample(Result->nav, TimeS, p_est, nullptr);
  if (EstimateMarker && have_est) EstimateMarker->SetPosition(p_est);
  if (NowRef || NowEst) {
    NavTriadSet now_ref, now_est;
    NavAppendTriadsAt(*Result, Options.att_exaggeration, TimeS, &now_ref, &now_est);
    auto move = [](vtkPolyData *pd, const NavTriadSet &set) {
      if (!pd || set.Size() == 0) return;
      pd->GetPoints()->SetPoint(0, &set.xyz_r[0]);
      pd->GetPoints()->Modified();
      vtkDataArray *q = pd->GetPointData()->GetArray("q_b_r");
      q->SetTuple(0, &set.q_b_r[0]);
      q->Modified();
      pd->Modified();
    };
    move(NowRef, now_ref);
    move(NowEst, now_est);
  }

  if (Options.follow) {
    PlaceFollowCamera(p_ref);
  } else if (Follow && VehiclePlaced) {
    vtkCamera *cam = Renderer->GetActiveCamera();
    double f[3], p[3];
    cam->GetFocalPoint(f);
    cam->GetPosition(p);
    for (int k = 0; k < 3; ++k) {
      f[k] += p_ref[k] - VehiclePosR[k];
      p[k] += p_ref[k] - VehiclePosR[k];
    }
    cam->SetFocalPoint(f);
    cam->SetPosition(p);
    Renderer->ResetCameraClippingRange();
  }
  for (int k = 0; k < 3; ++k)
    VehiclePosR[k] = p_ref[k];
  VehiclePlaced = true;
  UpdateScale(false);

  if (Readout) {
    char buf[256];
    int n = std::snprintf(buf, sizeof buf, "t = %.1f s of %.0f s%s", TimeS, Model.t_end_s,
                          Result->gnss.InOutage(TimeS) ? "  \u2013 GNSS outage" : "");
    const NavErrorSeries &er = Result->errors;
    if (er.Size() > 0 && n > 0 && n < static_cast<int>(sizeof buf)) {
      const double eh = NavInterpolate(er.t_s, er.pos_err_h_m, 1, 0, TimeS);
      const double ev = NavInterpolate(er.t_s, er.pos_err_v_m, 1, 0, TimeS);
      const double ea = NavInterpolate(er.t_s, er.att_err_rad, 1, 0, TimeS) * 180.0 / kPi;
      std::snprintf(buf + n, sizeof buf - static_cast<size_t>(n),
                    "\nerror: horizontal %.3g m, vertical %.3g m, attitude %.3g\u00b0", eh, ev, ea);
    }
    Readout->SetInput(buf);
  }
}

// ----------------------------------------------------------------------------- NavSceneView

NavSceneView::NavSceneView() : Impl(new NavSceneViewImpl) {}
NavSceneView::~NavSceneView() {
  if (Impl->External) {
    if (Impl->Renderer) Impl->External->RemoveRenderer(Impl->Renderer);
    if (Impl->Panel) Impl->External->RemoveRenderer(Impl->Panel);
    if (Impl->Under) Impl->Under->SetViewport(0.0, 0.0, 1.0, 1.0);
  } else if (Impl->Window) {
    Impl->Window->Finalize();
  }
}

void NavSceneView::SetResult(std::shared_ptr<const NavResult> result) {
  Impl->Result = std::move(result);
  Impl->Built = false;
  Impl->TimeS = Impl->Options.time_s;
}

void NavSceneView::SetOptions(const NavViewOptions &options) {
  Impl->Options = options;
  Impl->Built = false;
  Impl->TimeS = options.time_s;
}

const NavViewOptions &NavSceneView::GetOptions() const {
  return Impl->Options;
}

bool NavSceneView::Build(std::string *error) {
  return Impl->BuildScene(true, error);
}

const NavSceneModel &NavSceneView::Model() const {
  return Impl->Model;
}

void NavSceneView::SetTime(double t_s) {
  Impl->TimeS = t_s;
  Impl->UpdateTime();
}

double NavSceneView::GetTime() const {
  return Impl->TimeS;
}

bool NavSceneView::RenderPng(const std::string &path, std::string *error) {
  if (!Impl->Built || !Impl->Offscreen) {
    if (!Impl->BuildScene(true, error)) return false;
  }
  Impl->Window->Render();
  return NavWriteWindowPng(Impl->Window, path, error);
}

bool NavSceneView::RenderMovie(const std::string &dir, int frames, double fps, bool video, std::string *error) {
  if (frames < 1 || frames > 100000 || !(fps > 0.0)) {
    *error = "movie: frames must be 1..100000 and fps > 0";
    return false;
  }
  mkdir(dir.c_str(), 0755);
  struct stat st;
  if (stat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) {
    *error = dir + ": error: cannot create the movie directory";
    return false;
  }
  if (!Impl->Built || !Impl->Offscreen) {
    if (!Impl->BuildScene(true, error)) return false;
  }
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(Impl->Window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  vtkNew<vtkOggTheoraWriter> ogv;
  const std::string ogv_path = dir + "/playback.ogv";
  if (video) {
    ogv->SetInputConnection(grab->GetOutputPort());
    ogv->SetFileName(ogv_path.c_str());
    ogv->SetRate(std::max(1, static_cast<int>(std::lround(fps))));
    ogv->SetQuality(2);
  }
  const double t0 = Impl->Model.t_begin_s, t1 = Impl->Model.t_end_s;
  for (int i = 0; i < frames; ++i) {
    Impl->TimeS = frames > 1 ? t0 + (t1 - t0) * i / (frames - 1.0) : t1;
    Impl->UpdateTime();
    Impl->Window->Render();
    char name[64];
    std::snprintf(name, sizeof name, "/frame_%04d.png", i);
    if (!NavWriteWindowPng(Impl->Window, dir + name, error)) return false;
    if (video) {
      grab->Modified();
      if (i == 0) ogv->Start();
      ogv->Write();
    }
  }
  if (video) {
    ogv->End();
    if (ogv->GetError()) {
      *error = ogv_path + ": error: the Ogg Theora writer failed";
      return false;
    }
  }
  return true;
}

bool NavSceneView::PickNearest(const double xyz_r[3], NavPickResult *out) const {
  if (!Impl->Result || Impl->Result->nav.Size() == 0) return false;
  const NavTrack &nav = Impl->Result->nav;
  double best = INFINITY;
  size_t bi = 0;
  // Full-rate data, brute force: 720 000 epochs take about a millisecond.
  for (size_t i = 0; i < nav.Size(); ++i) {
    double p[3];
    NavNedToRender(&nav.pos_ned_m[3 * i], p);
    const double d2 = Sq(p[0] - xyz_r[0]) + Sq(p[1] - xyz_r[1]) + Sq(p[2] - xyz_r[2]);
    if (d2 < best) {
      best = d2;
      bi = i;
    }
  }
  out->epoch = bi;
  out->t_s = nav.t_s[bi];
  out->distance_m = std::sqrt(best);
  const NavErrorSeries &er = Impl->Result->errors;
  out->pos_err_h_m = er.Size() ? NavInterpolate(er.t_s, er.pos_err_h_m, 1, 0, out->t_s) : NAN;
  return true;
}

bool NavSceneView::Benchmark(int frames, NavBenchResult *out, std::string *error) {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  if (!Impl->BuildScene(true, error)) return false;
  Impl->Window->Render();
  Impl->Window->WaitForCompletion();
  const auto t1 = clock::now();
  vtkCamera *cam = Impl->Renderer->GetActiveCamera();
  frames = std::max(frames, 1);
  const std::clock_t c1 = std::clock();
  for (int i = 0; i < frames; ++i) {
    cam->Azimuth(360.0 / frames);
    Impl->Renderer->ResetCameraClippingRange();
    Impl->Window->Render();
  }
  Impl->Window->WaitForCompletion();
  const auto t2 = clock::now();
  out->cpu_s_per_frame = static_cast<double>(std::clock() - c1) / CLOCKS_PER_SEC / frames;
  out->build_s = std::chrono::duration<double>(t1 - t0).count();
  out->frames = frames;
  out->fps = frames / std::chrono::duration<double>(t2 - t1).count();
  out->full_points = Impl->Model.full_points;
  out->drawn_points = Impl->Model.reference.Size() + Impl->Model.estimate.Size();
  for (const NavPolyline &p : Impl->Model.extra_runs)
    out->drawn_points += p.Size();
  out->tol_m = Impl->Model.decimation_tol_m;
  return true;
}
