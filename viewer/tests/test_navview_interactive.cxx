/*
 * test_navview_interactive: the interactive window of NavSceneView driven without an event loop
 * (toolchain.md section 4): keys injected through the style, playback advanced by explicit
 * wall-clock steps, the slider moved through its representation, picking at a projected path
 * point. White-box (src/interactive_internal.h). Needs an X server: runs under xvfb-run. It
 * also leaves a screenshot with the slider in Testing/Temporary (not compared: it has text).
 */

#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <sys/stat.h>

#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkNew.h>
#include <vtkUnsignedCharArray.h>

#include "interactive_internal.h"
#include "map_interactive_internal.h"
#include "navview/navview.h"
#include "navview_internal.h"
#include "scene_view_impl.h"

// cmocka after the C++ and VTK headers: it defines fail(), which clashes with std::ios::fail.
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
extern "C" {
#include <cmocka.h>
}
#include "nav_test.h"

namespace {

struct Fixture {
  std::shared_ptr<NavResult> result = std::make_shared<NavResult>();
  NavSceneView view;
  NavInteractive st;
};

int setup(void **state) {
  std::string out_dir = NAVVIEW_TEST_OUT_DIR; // mkdir -p
  for (size_t p = 1; p != std::string::npos; p = out_dir.find('/', p + 1))
    mkdir(out_dir.substr(0, p).c_str(), 0755);
  mkdir(out_dir.c_str(), 0755);
  auto *f = new Fixture;
  std::string err;
  if (!NavLoadResultDir(NAVVIEW_TEST_DATA_DIR "/tiny", f->result.get(), &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    delete f;
    return -1;
  }
  NavViewOptions o;
  o.width_px = 640;
  o.height_px = 420;
  o.multisamples = 0;
  o.time_s = 10.0;
  o.att_exaggeration = 1.0; // +/- below: 1 -> 2 -> 4 -> 2
  f->view.SetResult(f->result);
  f->view.SetOptions(o);
  if (!f->st.Open(&f->view, &err)) {
    std::fprintf(stderr, "%s\n", err.c_str());
    delete f;
    return -1;
  }
  *state = f;
  return 0;
}

int teardown(void **state) {
  delete static_cast<Fixture *>(*state);
  return 0;
}

// Send a key the way the X interactor does: KeySym on the interactor, then KeyPressEvent.
void press(NavInteractive &st, const char *keysym) {
  st.Iren->SetKeySym(keysym);
  st.Iren->InvokeEvent(vtkCommand::KeyPressEvent);
}

void test_playback(void **state) {
  NavInteractive &st = static_cast<Fixture *>(*state)->st;
  assert_near(st.Impl->TimeS, 10.0, 0.0);
  assert_near(st.Speed, 2.0, 0.0); // 120 s played in 60 s
  press(st, "space");
  assert_true(st.Playing);
  st.Advance(0.5);
  assert_near(st.Impl->TimeS, 11.0, 1e-12);
  assert_near(st.Rep->GetValue(), 11.0, 1e-12);
  press(st, "space");
  assert_false(st.Playing);
  st.Advance(0.5);
  assert_near(st.Impl->TimeS, 11.0, 1e-12);
  press(st, "space");
  st.Advance(1000.0); // clamps at the end and stops
  assert_near(st.Impl->TimeS, 120.0, 0.0);
  assert_false(st.Playing);
  press(st, "space"); // from the end, play restarts at the beginning
  assert_true(st.Playing);
  assert_near(st.Impl->TimeS, 0.0, 0.0);
  press(st, "space");
}

void test_slider(void **state) {
  NavInteractive &st = static_cast<Fixture *>(*state)->st;
  st.Rep->SetValue(30.0);
  st.Slider->InvokeEvent(vtkCommand::InteractionEvent);
  assert_near(st.Impl->TimeS, 30.0, 1e-12);
  assert_near(st.Rep->GetMinimumValue(), 0.0, 0.0);
  assert_near(st.Rep->GetMaximumValue(), 120.0, 0.0);
}

void test_follow(void **state) {
  Fixture *f = static_cast<Fixture *>(*state);
  NavInteractive &st = f->st;
  st.SetTime(20.0, true);
  double f0[3], p0[3];
  st.Impl->Renderer->GetActiveCamera()->GetFocalPoint(f0);
  press(st, "f");
  assert_true(st.Impl->Follow);
  st.SetTime(40.0, true);
  double f1[3];
  st.Impl->Renderer->GetActiveCamera()->GetFocalPoint(f1);
  double a[3], b[3];
  NavTrackSample(f->result->truth, 20.0, a, nullptr);
  NavTrackSample(f->result->truth, 40.0, b, nullptr);
  for (int k = 0; k < 3; ++k)
    assert_near(f1[k] - f0[k], b[k] - a[k], 1e-9);
  press(st, "f");
  assert_false(st.Impl->Follow);
  st.Impl->Renderer->GetActiveCamera()->GetPosition(p0);
  st.SetTime(60.0, true);
  double p1[3];
  st.Impl->Renderer->GetActiveCamera()->GetPosition(p1);
  for (int k = 0; k < 3; ++k)
    assert_near(p1[k], p0[k], 0.0);
  press(st, "r"); // back to the preset camera
}

void test_option_keys(void **state) {
  NavInteractive &st = static_cast<Fixture *>(*state)->st;
  const double t = st.Impl->TimeS;
  assert_false(st.Impl->Options.color_by_error);
  press(st, "c");
  assert_true(st.Impl->Options.color_by_error);
  assert_true(st.Impl->Built);
  assert_true(st.Impl->ScalarBar != nullptr);
  press(st, "c");
  assert_false(st.Impl->Options.color_by_error);
  press(st, "plus");
  assert_near(st.Impl->Options.att_exaggeration, 2.0, 0.0);
  press(st, "plus");
  assert_near(st.Impl->Options.att_exaggeration, 4.0, 0.0);
  press(st, "minus");
  assert_near(st.Impl->Options.att_exaggeration, 2.0, 0.0);
  assert_near(st.Impl->TimeS, t, 0.0); // a rebuild keeps the playback time
  assert_false(st.Key("w"));           // VTK's wireframe key is not ours and does nothing
}

void test_pick(void **state) {
  Fixture *f = static_cast<Fixture *>(*state);
  NavInteractive &st = f->st;
  st.Impl->Window->Render();
  // Project the estimated position at t = 97 s (on the path, away from the crossing).
  double p[3];
  NavTrackSample(f->result->nav, 97.0, p, nullptr);
  vtkRenderer *ren = st.Impl->Renderer;
  ren->SetWorldPoint(p[0], p[1], p[2], 1.0);
  ren->WorldToDisplay();
  const double *d = ren->GetDisplayPoint();
  st.Pick(static_cast<int>(std::lround(d[0])), static_cast<int>(std::lround(d[1])));
  std::printf("picked t = %.2f s at %.3g m from the pick point\n", st.LastPick.t_s, st.LastPick.distance_m);
  assert_near(st.LastPick.t_s, 97.0, 2.0);
  assert_near(st.Impl->TimeS, st.LastPick.t_s, 0.0);
  assert_true(std::isfinite(st.LastPick.pos_err_h_m));

  std::string err;
  const std::string shot = std::string(NAVVIEW_TEST_OUT_DIR) + "/navview_interactive.png";
  st.Impl->Window->Render();
  assert_true(NavWriteWindowPng(st.Impl->Window, shot, &err));
  std::printf("screenshot: %s\n", shot.c_str());
}

// The interactive map (navview DIR --view map without --png): pan by a drag, zoom by the wheel
// and keys, reset; the window shows the tracks (dark reference pixels on the light map).
void test_map_window(void **state) {
  Fixture *f = static_cast<Fixture *>(*state);
  NavMapOptions o;
  o.width_px = 640;
  o.height_px = 420;
  o.multisamples = 0;
  NavMapInteractive m;
  std::string err;
  if (!m.Open(*f->result, o, &err)) fail_msg("map window: %s", err.c_str());
  const double s0 = m.Scale();
  assert_true(s0 > 0.0);
  assert_near(s0, 0.5 * m.Extent.span_y_m, 1e-9 * s0);
  // Wheel forward zooms in by 1.25 about the pointer, here at the window centre (so the view
  // centre stays; zooming about another point is test_navview_geomap's); "minus" zooms out by 2
  // about the centre; "r" resets.
  m.Iren->SetEventPosition(o.width_px / 2, o.height_px / 2);
  m.Iren->InvokeEvent(vtkCommand::MouseWheelForwardEvent);
  assert_near(m.Scale(), s0 / 1.25, 1e-9 * s0);
  m.Iren->SetKeySym("minus");
  m.Iren->InvokeEvent(vtkCommand::KeyPressEvent);
  assert_near(m.Scale(), 2.0 * s0 / 1.25, 1e-9 * s0);
  // A drag of (+50, +20) pixels moves the map with the pointer: the camera by (-50, -20) pixels.
  const double mpp = 2.0 * m.Scale() / o.height_px;
  m.Iren->SetEventPosition(100, 100);
  m.Iren->InvokeEvent(vtkCommand::LeftButtonPressEvent);
  m.Iren->SetEventPosition(150, 120);
  m.Iren->InvokeEvent(vtkCommand::MouseMoveEvent);
  m.Iren->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
  double fp[3], dir[3];
  m.Renderer->GetActiveCamera()->GetFocalPoint(fp);
  assert_near(fp[0], -50.0 * mpp, 1e-9 * s0);
  assert_near(fp[1], -20.0 * mpp, 1e-9 * s0);
  // No rotation: still looking straight down, north up.
  m.Renderer->GetActiveCamera()->GetDirectionOfProjection(dir);
  assert_near(dir[2], -1.0, 1e-12);
  m.Iren->SetEventPosition(300, 200);
  m.Iren->InvokeEvent(vtkCommand::MouseMoveEvent); // no button: no pan
  double fp2[3];
  m.Renderer->GetActiveCamera()->GetFocalPoint(fp2);
  assert_near(fp2[0], fp[0], 0.0);
  assert_true(m.Key("r"));
  m.Renderer->GetActiveCamera()->GetFocalPoint(fp);
  assert_near(fp[0], 0.0, 0.0);
  assert_near(fp[1], 0.0, 0.0);
  assert_near(m.Scale(), s0, 1e-9 * s0);
  assert_false(m.Key("w"));
  // Zoom is bounded: 100 wheel steps out stop at 50 x the fitted half-height.
  for (int i = 0; i < 100; ++i)
    m.Zoom(1.0 / 1.25);
  assert_near(m.Scale(), 50.0 * s0, 1e-9 * s0);
  m.Key("r");

  // The picture: the reference track is drawn in near-black over the light map background.
  m.Window->Render();
  vtkNew<vtkUnsignedCharArray> px;
  m.Window->GetPixelData(0, 0, o.width_px - 1, o.height_px - 1, 0, px);
  long dark = 0;
  for (vtkIdType i = 0; i < px->GetNumberOfTuples(); ++i) {
    const unsigned char *c = px->GetPointer(3 * i);
    if (c[0] < 60 && c[1] < 60 && c[2] < 70) dark++;
  }
  std::printf("map window: %ld dark pixels of %d\n", dark, o.width_px * o.height_px);
  assert_true(dark > 300);
  const std::string shot = std::string(NAVVIEW_TEST_OUT_DIR) + "/navview_map_interactive.png";
  assert_true(NavWriteWindowPng(m.Window, shot, &err));
  std::printf("screenshot: %s\n", shot.c_str());
}

} // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_playback),    cmocka_unit_test(test_slider), cmocka_unit_test(test_follow),
      cmocka_unit_test(test_option_keys), cmocka_unit_test(test_pick),   cmocka_unit_test(test_map_window),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
