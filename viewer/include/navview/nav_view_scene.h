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

#include <functional>
#include <memory>
#include <string>

#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"

class NavSceneViewImpl;
class NavInteractive;
// Only for embedding the scene in a host program's VTK window (AttachToWindow); the library's
// headers otherwise carry no VTK types.
class vtkRenderWindow;
class vtkRenderer;

/** A playback movie (RenderMovieFile). */
struct NavMovieOptions {
  double duration_s = 10.0; /**< length of the movie [s]; the run is played back over it */
  double fps = 30.0;        /**< frames per second */
  double t_begin_s = NAN;   /**< part of the run shown (NaN: its start / its end) [s] */
  double t_end_s = NAN;
  /** The encoder program (ffmpeg; its argv is fixed, no shell). */
  std::string ffmpeg = "ffmpeg";
};

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

  /** Playback movie as one video file: H.264 in MP4 (FILE.mp4, libx264, yuv420p) or VP9 in
   *  WebM (FILE.webm, libvpx-vp9), encoded by the ffmpeg program fed raw RGB frames through a
   *  pipe. The options' size (even width and height), the follow camera when options.follow,
   *  the time read-out in every frame. Written to FILE.part and renamed when complete.
   *  @p progress (may be empty) gets the fraction done after each frame and returns false to
   *  cancel (then nothing is left behind and @p error says "cancelled"). */
  bool RenderMovieFile(const std::string &path, const NavMovieOptions &movie,
                       const std::function<bool(double)> &progress, std::string *error);

  /** Embed the scene in a host's window: our renderer draws one layer above @p under, through
   *  its camera (the host keeps the camera), and the legend panel takes the window's right side
   *  (both viewports set by each build). Call before the first Rebuild; the view removes its
   *  renderers from the window when destroyed. */
  void AttachToWindow(vtkRenderWindow *window, vtkRenderer *under);
  /** Build (or rebuild after SetResult/SetOptions) keeping the current camera; the embedded
   *  view's build. @return false with a message on failure. */
  bool Rebuild(std::string *error);
  bool IsBuilt() const;
  /** The follow camera on or off, at @p distance_m (<= 0: automatic); takes effect at once. */
  void SetFollow(bool on, double distance_m);
  /** The follow-camera distance in use [m]. */
  double FollowDistance() const;
  /** Arrow length of the triads as drawn now [m] (tests: they scale with the view). */
  double TriadSizeNow() const;
  /** The estimated triad at the playback time: position (frame r) and body-to-r quaternion. */
  bool NowTriad(double xyz_r[3], double q_b_r[4]) const;
  /** Position of the vehicle glyph (frame r). */
  bool VehiclePosition(double xyz_r[3]) const;
  /** Legend entries' text, top to bottom, one entry per line group (tests); a narrow view draws
   *  each entry's short form (LegendCompact). */
  std::string LegendText() const;
  /** Width of the legend panel / the window's width (0 without text; at most 0.26: a narrow view
   *  draws the short forms in a smaller font instead of a wider panel). */
  double LegendPanelFraction() const;
  /** The legend draws its entries' short forms (a narrow view). */
  bool LegendCompact() const;
  /** The legend's font size [px]. */
  int LegendFontPx() const;
  /** Mark the scene out of date (its result no longer matches the edited scene): every drawn
   *  object faded towards grey and the title says "OUT OF DATE"; false restores it. */
  void SetStale(bool stale);
  bool IsStale() const;
  /** Horizontal 1-sigma floor the envelope is drawn with now (min_envelope_px at the view's
   *  scale) [m] (tests). */
  double EnvelopeFloorM() const;

  /** Build the default view offscreen and render @p frames frames while orbiting the camera. */
  bool Benchmark(int frames, NavBenchResult *out, std::string *error);

private:
  friend class NavInteractive; // the interactive window (src/interactive_internal.h)
  std::unique_ptr<NavSceneViewImpl> Impl;
};

#endif /* NAV_VIEW_SCENE_H */
