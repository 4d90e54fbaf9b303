/**
 * @file interactive_internal.h
 * @brief State of the interactive window (private). Tests drive it directly: Key() injects a
 *        key, Advance() a wall-clock step of the playback, SetTime() a slider move, so no
 *        event loop is needed (toolchain.md section 4).
 */
#ifndef NAV_INTERACTIVE_INTERNAL_H
#define NAV_INTERACTIVE_INTERNAL_H

#include <chrono>
#include <string>

#include <vtkSmartPointer.h>

#include "navview/nav_view_scene.h"

class NavSceneViewImpl;
class vtkCallbackCommand;
class vtkNavInteractorStyle;
class vtkRenderWindowInteractor;
class vtkSliderRepresentation2D;
class vtkSliderWidget;

class NavInteractive {
public:
  NavInteractive();
  ~NavInteractive();
  NavInteractive(const NavInteractive &) = delete;
  NavInteractive &operator=(const NavInteractive &) = delete;

  /** Build the scene in an on-screen window, add the interactor, style, slider and observers,
   *  Initialize() and render once. Start() is left to the caller. */
  bool Open(NavSceneView *view, std::string *error);
  /** Handle a key by its X keysym ("space", "f", "c", "plus", "minus", "p", "r", "q").
   *  @return whether the key is one of the viewer's. */
  bool Key(const std::string &keysym);
  /** Advance the playback by a wall-clock step [s] (no-op when paused). */
  void Advance(double wall_dt_s);
  /** Move the playback time [s], as the slider does. */
  void SetTime(double t_s, bool sync_slider);
  /** Pick the estimated path at display pixel (x, y) and jump to the nearest epoch. */
  void Pick(int x, int y);
  /** Rebuild the scene keeping the camera (options changed or the screen scale did). */
  void Rebuild();
  void SyncSlider();

  NavSceneView *View = nullptr;
  NavSceneViewImpl *Impl = nullptr;
  vtkSmartPointer<vtkRenderWindowInteractor> Iren;
  vtkSmartPointer<vtkNavInteractorStyle> Style;
  vtkSmartPointer<vtkSliderRepresentation2D> Rep;
  vtkSmartPointer<vtkSliderWidget> Slider;
  vtkSmartPointer<vtkCallbackCommand> SliderCb, TimerCb, EndCb;
  bool Playing = false;
  double Speed = 1.0; /**< simulated seconds per wall-clock second */
  double BuiltMetresPerPixel = 0.0;
  NavPickResult LastPick;
  std::chrono::steady_clock::time_point Last;
};

#endif /* NAV_INTERACTIVE_INTERNAL_H */
