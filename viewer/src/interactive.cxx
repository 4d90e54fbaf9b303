// Interactive mode of NavSceneView: trackball camera, time slider, play/pause, camera follow,
// picking on the full-rate data, and re-decimation when a zoom changes the screen scale.
// NavInteractive (interactive_internal.h) holds the state so that tests can drive it with
// injected events and explicit time steps instead of the event loop.
#include "navview/nav_view_scene.h"

#include "interactive_internal.h"
#include "navview_internal.h"
#include "scene_view_impl.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellPicker.h>
#include <vtkCommand.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

/** Trackball camera plus the viewer's keys; VTK's default character keys (wireframe, stereo,
 *  fly-to...) are swallowed so they cannot put the scene in a confusing state. */
class vtkNavInteractorStyle : public vtkInteractorStyleTrackballCamera {
public:
  static vtkNavInteractorStyle *New();
  vtkTypeMacro(vtkNavInteractorStyle, vtkInteractorStyleTrackballCamera) NavInteractive *State = nullptr;

  void OnChar() override {}
  void OnKeyPress() override {
    const char *k = this->Interactor->GetKeySym();
    if (State && k) State->Key(k);
  }
};
vtkStandardNewMacro(vtkNavInteractorStyle);

namespace {

void OnSlider(vtkObject *, unsigned long, void *client, void *) {
  auto *st = static_cast<NavInteractive *>(client);
  st->SetTime(st->Rep->GetValue(), false);
}

void OnTimer(vtkObject *, unsigned long, void *client, void *) {
  auto *st = static_cast<NavInteractive *>(client);
  const auto now = std::chrono::steady_clock::now();
  const double dt = std::chrono::duration<double>(now - st->Last).count();
  st->Last = now;
  if (st->Playing) {
    st->Advance(dt);
    st->Impl->Window->Render();
  }
}

void OnEndInteraction(vtkObject *, unsigned long, void *client, void *) {
  auto *st = static_cast<NavInteractive *>(client);
  const double m = st->Impl->MetresPerPixel();
  // Re-decimate when the screen scale changed by more than 2x since the last build.
  if (st->BuiltMetresPerPixel > 0.0 &&
      (m < 0.5 * st->BuiltMetresPerPixel || m > 2.0 * st->BuiltMetresPerPixel)) {
    st->Rebuild();
    st->Impl->Window->Render();
  }
}

} // namespace

NavInteractive::NavInteractive() = default;
NavInteractive::~NavInteractive() {
  if (Slider) Slider->Off();
}

void NavInteractive::SyncSlider() {
  Rep->SetMinimumValue(Impl->Model.t_begin_s);
  Rep->SetMaximumValue(std::max(Impl->Model.t_end_s, Impl->Model.t_begin_s + 1e-6));
  Rep->SetValue(Impl->TimeS);
}

void NavInteractive::SetTime(double t_s, bool sync_slider) {
  Impl->TimeS = t_s;
  Impl->UpdateTime();
  if (sync_slider) SyncSlider();
}

void NavInteractive::Advance(double wall_dt_s) {
  if (!Playing) return;
  const double t = std::min(Impl->TimeS + wall_dt_s * Speed, Impl->Model.t_end_s);
  if (t >= Impl->Model.t_end_s) Playing = false;
  SetTime(t, true);
}

void NavInteractive::Rebuild() {
  const int *size = Impl->Window->GetSize();
  Impl->Options.width_px = size[0];
  Impl->Options.height_px = size[1];
  std::string err;
  const double t = Impl->TimeS;
  if (!Impl->BuildScene(false, &err, true)) {
    std::fprintf(stderr, "navview: %s\n", err.c_str());
    return;
  }
  SetTime(t, false);
  BuiltMetresPerPixel = Impl->MetresPerPixel();
  Slider->Off(); // its representation went with the other props
  Slider->On();
  SyncSlider();
}

void NavInteractive::Pick(int x, int y) {
  vtkNew<vtkCellPicker> picker;
  picker->SetTolerance(0.005);
  // Only the estimated path: the tube, triads or grid in front of it must not catch the click.
  if (Impl->EstimateActor) {
    picker->AddPickList(Impl->EstimateActor);
    picker->PickFromListOn();
  }
  if (!picker->Pick(x, y, 0.0, Impl->Renderer)) return;
  double p[3];
  picker->GetPickPosition(p);
  NavPickResult r;
  if (!View->PickNearest(p, &r)) return;
  LastPick = r;
  if (Impl->PickText) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "picked epoch %zu: t = %.2f s\nhorizontal error %.3g m (run 0)", r.epoch,
                  r.t_s, r.pos_err_h_m);
    Impl->PickText->SetInput(buf);
  }
  SetTime(r.t_s, true);
}

bool NavInteractive::Key(const std::string &key) {
  if (key == "space") {
    Playing = !Playing;
    if (Playing && Impl->TimeS >= Impl->Model.t_end_s) SetTime(Impl->Model.t_begin_s, true);
    Last = std::chrono::steady_clock::now();
  } else if (key == "f") {
    Impl->Follow = !Impl->Follow;
  } else if (key == "c") {
    Impl->Options.color_by_error = !Impl->Options.color_by_error;
    Rebuild();
  } else if (key == "plus" || key == "KP_Add" || key == "equal") {
    Impl->Options.att_exaggeration =
        Impl->Options.att_exaggeration > 0.0 ? 2.0 * Impl->Options.att_exaggeration : 1.0;
    Rebuild();
  } else if (key == "minus" || key == "KP_Subtract") {
    Impl->Options.att_exaggeration = std::max(Impl->Options.att_exaggeration / 2.0, 1.0);
    Rebuild();
  } else if (key == "r") {
    Impl->SetupCamera();
    Rebuild();
  } else if (key == "p") {
    const int *pos = Iren->GetEventPosition();
    Pick(pos[0], pos[1]);
  } else if (key == "q" || key == "Escape") {
    Iren->TerminateApp();
    return true;
  } else {
    return false;
  }
  Impl->Window->Render();
  return true;
}

bool NavInteractive::Open(NavSceneView *view, std::string *error) {
  View = view;
  Impl = view->Impl.get();
  if (!Impl->BuildScene(false, error)) return false;
  Iren = vtkSmartPointer<vtkRenderWindowInteractor>::New();
  Iren->SetRenderWindow(Impl->Window);
  // Play a run in about a minute, never slower than real time.
  Speed = std::max(1.0, (Impl->Model.t_end_s - Impl->Model.t_begin_s) / 60.0);
  BuiltMetresPerPixel = Impl->MetresPerPixel();

  Style = vtkSmartPointer<vtkNavInteractorStyle>::New();
  Style->State = this;
  Style->SetDefaultRenderer(Impl->Renderer);
  Iren->SetInteractorStyle(Style);

  // Time slider along the bottom of the 3D view. The 2D slider's defaults are white on white
  // (toolchain.md section 4): every colour is set.
  const double right = 0.97 * (1.0 - Impl->PanelFraction);
  Rep = vtkSmartPointer<vtkSliderRepresentation2D>::New();
  Rep->GetPoint1Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  Rep->GetPoint1Coordinate()->SetValue(0.03, 0.065);
  Rep->GetPoint2Coordinate()->SetCoordinateSystemToNormalizedDisplay();
  Rep->GetPoint2Coordinate()->SetValue(right, 0.065);
  Rep->SetSliderLength(0.02);
  Rep->SetSliderWidth(0.025);
  Rep->SetTubeWidth(0.006);
  Rep->SetEndCapLength(0.006);
  Rep->SetEndCapWidth(0.025);
  Rep->SetTitleText("time [s]");
  Rep->SetTitleHeight(0.022);
  Rep->SetLabelHeight(0.022);
  Rep->SetLabelFormat("%.1f");
  Rep->GetTubeProperty()->SetColor(0.55, 0.55, 0.6);
  Rep->GetCapProperty()->SetColor(0.35, 0.35, 0.4);
  Rep->GetSliderProperty()->SetColor(0.15, 0.3, 0.75);
  Rep->GetSelectedProperty()->SetColor(0.85, 0.2, 0.1);
  for (vtkTextProperty *tp : {Rep->GetTitleProperty(), Rep->GetLabelProperty()}) {
    NavApplyFont(tp);
    tp->SetColor(0.05, 0.05, 0.08);
    tp->ShadowOff();
    tp->BoldOff();
  }
  Slider = vtkSmartPointer<vtkSliderWidget>::New();
  Slider->SetInteractor(Iren);
  Slider->SetCurrentRenderer(Impl->Renderer);
  Slider->SetRepresentation(Rep);
  Slider->SetAnimationModeToJump();
  SyncSlider();
  Slider->On();

  SliderCb = vtkSmartPointer<vtkCallbackCommand>::New();
  SliderCb->SetCallback(OnSlider);
  SliderCb->SetClientData(this);
  Slider->AddObserver(vtkCommand::InteractionEvent, SliderCb);
  TimerCb = vtkSmartPointer<vtkCallbackCommand>::New();
  TimerCb->SetCallback(OnTimer);
  TimerCb->SetClientData(this);
  Iren->AddObserver(vtkCommand::TimerEvent, TimerCb);
  EndCb = vtkSmartPointer<vtkCallbackCommand>::New();
  EndCb->SetCallback(OnEndInteraction);
  EndCb->SetClientData(this);
  Style->AddObserver(vtkCommand::EndInteractionEvent, EndCb);

  Iren->Initialize();
  Last = std::chrono::steady_clock::now();
  Impl->Window->Render();
  return true;
}

bool NavSceneView::RunInteractive(std::string *error) {
  NavInteractive st;
  if (!st.Open(this, error)) return false;
  std::printf("navview: mouse = trackball camera, space = play/pause, f = camera follow, c = colour by "
              "error,\n         +/- = attitude exaggeration, p = pick the path under the mouse, r = reset "
              "camera, q = quit\n");
  std::fflush(stdout);
  st.Iren->CreateRepeatingTimer(33);
  st.Iren->Start();
  return true;
}
