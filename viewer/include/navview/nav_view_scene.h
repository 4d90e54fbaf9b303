/**
 * @file nav_view_scene.h
 * @brief NavSceneView: the VTK 3D view of a result (headless PNG, interactive window, benchmark).
 *        The VTK objects live in NavSceneViewImpl (src/scene_view_impl.h), F3D-style.
 *
 * Example (headless; needs an X server, e.g. under xvfb-run):
 * @code
 *   auto result = std::make_shared<NavResult>();
 *   std::string err;
 *   if (!NavLoadResultDir("/tmp/r-car", result.get(), &err)) { fprintf(stderr, "%s\n", err.c_str()); }
 *   NavSceneView view;
 *   NavViewOptions opt;
 *   opt.att_exaggeration = 20;
 *   view.SetResult(result);
 *   view.SetOptions(opt);
 *   if (!view.RenderPng("/tmp/view.png", &err)) { ... }
 * @endcode
 * Not thread-safe; use from the GUI thread only (style.md section 7).
 */
#ifndef NAV_VIEW_SCENE_H
#define NAV_VIEW_SCENE_H

#include <memory>
#include <string>

#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"

class NavSceneViewImpl;
class NavInteractive;

/** Result of picking the nearest full-rate epoch of the estimated path. */
struct NavPickResult {
  size_t epoch = 0; /**< index into NavResult::nav */
  double t_s = 0.0;
  double distance_m = 0.0;  /**< from the query point to the epoch's position [m] */
  double pos_err_h_m = NAN; /**< run-0 horizontal error at that epoch (NaN without errors.csv) */
};

/** Frames-per-second measurement of the default view. */
struct NavBenchResult {
  double build_s = 0.0;         /**< scene model + actors + first frame [s] */
  double fps = 0.0;             /**< frames per second (wall clock) while orbiting the camera */
  double cpu_s_per_frame = 0.0; /**< process CPU time per frame, all threads (llvmpipe's too) [s] */
  int frames = 0;
  size_t full_points = 0;  /**< epochs of all paths before decimation */
  size_t drawn_points = 0; /**< vertices drawn for the paths after decimation */
  double tol_m = 0.0;      /**< decimation tolerance [m] */
};

class NavSceneView {
public:
  NavSceneView();
  ~NavSceneView();
  NavSceneView(const NavSceneView &) = delete;
  NavSceneView &operator=(const NavSceneView &) = delete;

  /** Set the result to show (shared, never modified). */
  void SetResult(std::shared_ptr<const NavResult> result);
  /** Set the options; takes effect at the next Build/Render. */
  void SetOptions(const NavViewOptions &options);
  const NavViewOptions &GetOptions() const;

  /** Build the scene (model, actors, camera) in an offscreen window of the options' size.
   *  Needs an X server (DISPLAY). @return false with a message on failure. */
  bool Build(std::string *error);
  /** The scene model of the last Build (valid until the next Build). */
  const NavSceneModel &Model() const;

  /** Move the playback time (vehicle glyph, read-out, camera follow) [s]; clamped to the run. */
  void SetTime(double t_s);
  double GetTime() const;

  /** Build if needed, render one frame offscreen and write it as PNG. */
  bool RenderPng(const std::string &path, std::string *error);

  /** Nearest full-rate epoch of the estimated path to a point of frame r. */
  bool PickNearest(const double xyz_r[3], NavPickResult *out) const;

  /** Open an interactive window (trackball camera, time slider, space = play/pause,
   *  f = camera follow, c = colour by error, +/- = attitude exaggeration, p = pick, r = reset
   *  camera, q = quit) and run its event loop until closed. Needs a display. */
  bool RunInteractive(std::string *error);

  /** Playback movie for demos: @p frames frames from the start to the end of the run (fixed
   *  camera, the vehicle, estimate marker and read-out moving), written as DIR/frame_NNNN.png and,
   *  when @p video is set, as DIR/playback.ogv (Ogg Theora, vtkOggTheoraWriter) at @p fps. */
  bool RenderMovie(const std::string &dir, int frames, double fps, bool video, std::string *error);

  /** Build the default view offscreen and render @p frames frames while orbiting the camera. */
  bool Benchmark(int frames, NavBenchResult *out, std::string *error);

private:
  friend class NavInteractive; // the interactive window (src/interactive_internal.h)
  std::unique_ptr<NavSceneViewImpl> Impl;
};

#endif /* NAV_VIEW_SCENE_H */
