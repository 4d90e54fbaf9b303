// Interactive geodetic map window (map_interactive_internal.h): the static map of map_view.cxx
// on screen, with a 2D navigation style (no rotation: the map stays north up).
#include "map_interactive_internal.h"

#include "navview_internal.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include <vtkCamera.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkObjectFactory.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>

/** Left or middle drag pans (the map is rebuilt for the new view on release), the wheel zooms
 *  about the pointer, the map's keys; VTK's default character keys and rotation are swallowed so
 *  the map cannot be tilted or put in wireframe. */
class vtkNavMapStyle : public vtkInteractorStyleTrackballCamera {
public:
  static vtkNavMapStyle *New();
  vtkTypeMacro(vtkNavMapStyle, vtkInteractorStyleTrackballCamera) NavMapInteractive *State = nullptr;

  void OnChar() override {}
  void OnKeyPress() override {
    const char *k = this->Interactor->GetKeySym();
    if (State && k) State->Key(k);
  }
  void OnLeftButtonDown() override { StartDrag(); }
  void OnLeftButtonUp() override { EndDrag(); }
  void OnMiddleButtonDown() override { StartDrag(); }
  void OnMiddleButtonUp() override { EndDrag(); }
  void OnRightButtonDown() override {}
  void OnRightButtonUp() override {}
  void OnMouseMove() override {
    if (!dragging_ || !State) return;
    const int *p = this->Interactor->GetEventPosition();
    State->Pan(p[0] - last_[0], p[1] - last_[1], false);
    last_[0] = p[0];
    last_[1] = p[1];
  }
  void OnMouseWheelForward() override {
    const int *p = this->Interactor->GetEventPosition();
    if (State) State->ZoomAt(1.25, p[0], p[1]);
  }
  void OnMouseWheelBackward() override {
    const int *p = this->Interactor->GetEventPosition();
    if (State) State->ZoomAt(1.0 / 1.25, p[0], p[1]);
  }

private:
  void EndDrag() {
    if (dragging_ && State) State->Rebuild();
    dragging_ = false;
  }
  void StartDrag() {
    const int *p = this->Interactor->GetEventPosition();
    last_[0] = p[0];
    last_[1] = p[1];
    dragging_ = true;
  }
  bool dragging_ = false;
  int last_[2] = {0, 0};
};
vtkStandardNewMacro(vtkNavMapStyle);

NavMapInteractive::NavMapInteractive() = default;
NavMapInteractive::~NavMapInteractive() {
  if (Window) Window->Finalize();
}

bool NavMapInteractive::Open(const NavResult &result, const NavMapOptions &options, std::string *error) {
  if (!NavCheckDisplay(error)) return false;
  Window = vtkSmartPointer<vtkRenderWindow>::New();
  NavAttachDisplay(Window);
  Window->SetSize(options.width_px, options.height_px);
  Window->SetMultiSamples(options.multisamples);
  Window->SetWindowName("navview - map");
  Renderer = vtkSmartPointer<vtkRenderer>::New();
  Window->AddRenderer(Renderer);
  Result = &result;
  Options = options;
  if (!NavBuildMap(result, options, Renderer, &Extent, error, &Frame, &Info)) return false;
  Iren = vtkSmartPointer<vtkRenderWindowInteractor>::New();
  Iren->SetRenderWindow(Window);
  Style = vtkSmartPointer<vtkNavMapStyle>::New();
  Style->State = this;
  Style->SetDefaultRenderer(Renderer);
  Iren->SetInteractorStyle(Style);
  Iren->Initialize();
  Window->Render();
  return true;
}

double NavMapInteractive::Scale() const {
  return Renderer ? Renderer->GetActiveCamera()->GetParallelScale() : NAN;
}

void NavMapInteractive::Zoom(double factor) {
  if (!Window) return;
  const int *size = Window->GetSize();
  ZoomAt(factor, 0.5 * size[0], 0.5 * size[1]);
}

void NavMapInteractive::ZoomAt(double factor, double px, double py) {
  if (!Renderer || !(factor > 0.0)) return;
  vtkCamera *cam = Renderer->GetActiveCamera();
  const int *size = Window->GetSize();
  if (size[0] <= 0 || size[1] <= 0) return;
  const double fit = 0.5 * Extent.span_y_m;
  const double s0 = cam->GetParallelScale();
  // At most the widest map the projection draws, at least a hundredth of a metre per pixel.
  const double s_max = std::min(50.0 * fit, 0.5 * NavMapMaxSpanM() * size[1] / size[0]);
  const double s = std::clamp(s0 / factor, fit / 20000.0, std::max(s_max, fit));
  // The point under the pointer stays under it: the focal point moves towards it by 1 - s/s0.
  const double m_per_px = 2.0 * s0 / size[1];
  double f[3], p[3];
  cam->GetFocalPoint(f);
  cam->GetPosition(p);
  const double wx = f[0] + (px - 0.5 * size[0]) * m_per_px, wy = f[1] + (py - 0.5 * size[1]) * m_per_px;
  const double k = s / s0;
  const double nx = wx + (f[0] - wx) * k, ny = wy + (f[1] - wy) * k;
  cam->SetFocalPoint(nx, ny, f[2]);
  cam->SetPosition(nx, ny, p[2]);
  cam->SetParallelScale(s);
  Rebuild();
}

void NavMapInteractive::Pan(double dx_px, double dy_px, bool rebuild) {
  if (!Renderer) return;
  vtkCamera *cam = Renderer->GetActiveCamera();
  const int *size = Window->GetSize();
  if (size[1] <= 0) return;
  const double m_per_px = 2.0 * cam->GetParallelScale() / size[1];
  double f[3], p[3];
  cam->GetFocalPoint(f);
  cam->GetPosition(p);
  // The map follows the pointer: the camera moves the other way (north up, x east).
  const double ex = -dx_px * m_per_px, ny = -dy_px * m_per_px;
  cam->SetFocalPoint(f[0] + ex, f[1] + ny, f[2]);
  cam->SetPosition(p[0] + ex, p[1] + ny, p[2]);
  if (rebuild)
    Rebuild();
  else
    Window->Render();
}

bool NavMapInteractive::Rebuild() {
  if (!Renderer || !Result) return false;
  vtkCamera *cam = Renderer->GetActiveCamera();
  const int *size = Window->GetSize();
  if (size[0] <= 0 || size[1] <= 0) return false;
  double f[3];
  cam->GetFocalPoint(f);
  NavMapOptions o = Options;
  o.width_px = size[0];
  o.height_px = size[1];
  const double span_x = 2.0 * cam->GetParallelScale() * size[0] / size[1];
  std::string err;
  const auto t0 = std::chrono::steady_clock::now();
  const bool ok = NavBuildMapView(*Result, o, Frame, f[0], f[1], span_x, Renderer, &Info, &err);
  double p[3];
  cam->GetPosition(p);
  cam->SetClippingRange(1.0, std::max(40.0 * span_x + 1000.0, 2.0 * std::fabs(p[2])));
  Window->Render();
  LastRebuildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return ok;
}

void NavMapInteractive::Reset() {
  if (!Renderer) return;
  vtkCamera *cam = Renderer->GetActiveCamera();
  double p[3];
  cam->GetPosition(p);
  cam->SetFocalPoint(0, 0, 0);
  cam->SetPosition(0, 0, p[2]);
  cam->SetViewUp(0, 1, 0);
  cam->SetParallelScale(0.5 * Extent.span_y_m);
  Rebuild();
}

bool NavMapInteractive::Key(const std::string &key) {
  if (key == "plus" || key == "equal" || key == "KP_Add") {
    Zoom(2.0);
  } else if (key == "minus" || key == "KP_Subtract") {
    Zoom(0.5);
  } else if (key == "r") {
    Reset();
  } else if (key == "q" || key == "Escape") {
    if (Iren) Iren->TerminateApp();
  } else {
    return false;
  }
  return true;
}

bool NavRunMapInteractive(const NavResult &result, const NavMapOptions &options, std::string *error) {
  NavMapInteractive st;
  if (!st.Open(result, options, error)) return false;
  std::printf("navview map: drag = pan, wheel or +/- = zoom, r = reset, q = quit\n");
  std::fflush(stdout);
  st.Iren->Start();
  return true;
}
