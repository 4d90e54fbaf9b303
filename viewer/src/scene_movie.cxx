/*
 * NavSceneView: the playback movie as a video file (H.264 MP4 or VP9 WebM through the ffmpeg
 * program), and the embedding of the scene in a host's window (navstudio's 3D view).
 *
 * The movie: the scene is built offscreen at the options' size; each frame moves the playback
 * time (vehicle, triads at t, read-out, follow camera), renders and is read back as RGB rows,
 * which go to ffmpeg's standard input as raw video (-f rawvideo -pix_fmt rgb24; VTK's rows run
 * bottom-up, so ffmpeg flips them with -vf vflip). ffmpeg is started with a fixed argv through
 * fork/execvp, never a shell; it writes FILE.part, renamed to FILE once ffmpeg has succeeded.
 */
#include "navview/nav_view_scene.h"

#include "navview_internal.h"
#include "scene_view_impl.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkCamera.h>
#include <vtkProperty.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkDataArray.h>
#include <vtkGlyph3DMapper.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>

namespace {

bool EndsWith(const std::string &s, const char *suffix) {
  const size_t n = std::strlen(suffix);
  return s.size() >= n && s.compare(s.size() - n, n, suffix) == 0;
}

/** Write all of @p n bytes (EINTR-safe); false on a broken pipe or another error. */
bool WriteAll(int fd, const unsigned char *p, size_t n) {
  while (n > 0) {
    const ssize_t w = write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += w;
    n -= static_cast<size_t>(w);
  }
  return true;
}

/** Wait for @p pid; its exit code, or -1 when it did not exit normally. */
int WaitChild(pid_t pid) {
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

} // namespace

bool NavSceneView::RenderMovieFile(const std::string &path, const NavMovieOptions &movie,
                                   const std::function<bool(double)> &progress, std::string *error) {
  const bool mp4 = EndsWith(path, ".mp4"), webm = EndsWith(path, ".webm");
  if (!mp4 && !webm) {
    *error = path + ": error: the movie file must end in .mp4 (H.264) or .webm (VP9)";
    return false;
  }
  if (!(movie.duration_s > 0.0) || movie.duration_s > 3600.0 || !(movie.fps >= 1.0) || movie.fps > 120.0) {
    *error = "movie: expected a duration of 0..3600 s and 1..120 frames per second";
    return false;
  }
  const NavViewOptions &o = Impl->Options;
  if (o.width_px % 2 != 0 || o.height_px % 2 != 0) {
    *error = "movie: the frame size must have an even width and height (H.264/VP9 in 4:2:0)";
    return false;
  }
  if (!Impl->Built || !Impl->Offscreen || Impl->External) {
    if (Impl->External) {
      *error = "movie: render it from an offscreen view (not one embedded in a window)";
      return false;
    }
    if (!Impl->BuildScene(true, error)) return false;
  }
  const int frames = std::max(1, static_cast<int>(std::lround(movie.duration_s * movie.fps)));
  const double t0 = std::isfinite(movie.t_begin_s) ? movie.t_begin_s : Impl->Model.t_begin_s;
  const double t1 = std::isfinite(movie.t_end_s) ? movie.t_end_s : Impl->Model.t_end_s;
  const std::string part = path + ".part";

  char size_arg[32], fps_arg[32];
  std::snprintf(size_arg, sizeof size_arg, "%dx%d", o.width_px, o.height_px);
  std::snprintf(fps_arg, sizeof fps_arg, "%g", movie.fps);
  std::vector<std::string> args = {movie.ffmpeg, "-hide_banner", "-loglevel", "error", "-nostdin", "-y",
                                   "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", size_arg, "-r", fps_arg,
                                   "-i", "pipe:0", "-vf", "vflip", "-pix_fmt", "yuv420p"};
  if (mp4)
    args.insert(args.end(), {"-c:v", "libx264", "-preset", "veryfast", "-crf", "20", "-movflags", "+faststart",
                             "-f", "mp4"});
  else
    args.insert(args.end(), {"-c:v", "libvpx-vp9", "-b:v", "0", "-crf", "33", "-deadline", "realtime",
                             "-cpu-used", "8", "-row-mt", "1", "-f", "webm"});
  args.push_back(part);
  std::vector<char *> argv;
  for (std::string &a : args)
    argv.push_back(&a[0]);
  argv.push_back(nullptr);

  int fds[2];
  if (pipe(fds) != 0) {
    *error = std::string("movie: cannot create a pipe: ") + std::strerror(errno);
    return false;
  }
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    *error = std::string("movie: cannot start ffmpeg: ") + std::strerror(errno);
    return false;
  }
  if (pid == 0) {
    dup2(fds[0], STDIN_FILENO);
    close(fds[0]);
    close(fds[1]);
    execvp(argv[0], argv.data());
    std::fprintf(stderr, "navview: cannot start %s: %s (Debian package ffmpeg)\n", argv[0], std::strerror(errno));
    _exit(127);
  }
  close(fds[0]);
  const int out = fds[1];
  // A dead encoder must give EPIPE here, not kill the host program.
  struct sigaction ign {}, old {};
  ign.sa_handler = SIG_IGN;
  sigemptyset(&ign.sa_mask);
  sigaction(SIGPIPE, &ign, &old);

  bool ok = true, cancelled = false;
  std::vector<unsigned char> rgb(static_cast<size_t>(o.width_px) * static_cast<size_t>(o.height_px) * 3);
  for (int i = 0; i < frames && ok; ++i) {
    Impl->TimeS = frames > 1 ? t0 + (t1 - t0) * i / (frames - 1.0) : t1;
    Impl->UpdateTime();
    Impl->Window->Render();
    unsigned char *px = Impl->Window->GetPixelData(0, 0, o.width_px - 1, o.height_px - 1, 0, 0);
    if (!px) {
      *error = "movie: cannot read the frame back";
      ok = false;
      break;
    }
    std::memcpy(rgb.data(), px, rgb.size());
    delete[] px;
    if (!WriteAll(out, rgb.data(), rgb.size())) {
      *error = "movie: ffmpeg stopped reading frames";
      ok = false;
      break;
    }
    if (progress && !progress((i + 1.0) / frames)) {
      cancelled = true;
      ok = false;
    }
  }
  close(out);
  if (!ok) kill(pid, SIGTERM); // our own child: nothing else is signalled
  const int rc = WaitChild(pid);
  sigaction(SIGPIPE, &old, nullptr);
  if (ok && rc != 0) {
    *error = rc == 127 ? "movie: cannot start ffmpeg (install the Debian package ffmpeg)"
                       : "movie: ffmpeg failed (exit " + std::to_string(rc) + ")";
    ok = false;
  }
  if (!ok) {
    unlink(part.c_str());
    if (cancelled) *error = "movie: cancelled";
    return false;
  }
  if (std::rename(part.c_str(), path.c_str()) != 0) {
    *error = path + ": error: cannot rename the finished movie: " + std::strerror(errno);
    unlink(part.c_str());
    return false;
  }
  return true;
}

void NavSceneView::AttachToWindow(vtkRenderWindow *window, vtkRenderer *under) {
  Impl->External = window;
  Impl->Under = under;
  Impl->Window = nullptr;
  Impl->Built = false;
}

bool NavSceneView::Rebuild(std::string *error) {
  const double t = Impl->TimeS;
  if (!Impl->BuildScene(true, error, true)) return false;
  if (std::isfinite(t)) {
    Impl->TimeS = t;
    Impl->UpdateTime();
  }
  return true;
}

bool NavSceneView::IsBuilt() const { return Impl->Built; }

void NavSceneView::SetFollow(bool on, double distance_m) {
  Impl->Options.follow = on;
  Impl->Options.follow_distance_m = distance_m;
  if (!Impl->Built) return;
  Impl->UpdateTime();
  Impl->UpdateScale(true);
}

double NavSceneView::FollowDistance() const { return Impl->FollowDistance(); }

double NavSceneView::TriadSizeNow() const { return Impl->ViewTriadSize(); }

bool NavSceneView::NowTriad(double xyz_r[3], double q_b_r[4]) const {
  vtkPolyData *pd = Impl->NowEst;
  if (!pd || pd->GetNumberOfPoints() < 1) return false;
  pd->GetPoints()->GetPoint(0, xyz_r);
  pd->GetPointData()->GetArray("q_b_r")->GetTuple(0, q_b_r);
  return true;
}

bool NavSceneView::VehiclePosition(double xyz_r[3]) const {
  if (!Impl->VehiclePlaced) return false;
  for (int k = 0; k < 3; ++k)
    xyz_r[k] = Impl->VehiclePosR[k];
  return true;
}

std::string NavSceneView::LegendText() const { return Impl->Legend; }
double NavSceneView::LegendPanelFraction() const {
  return Impl->PanelFraction;
}
bool NavSceneView::LegendCompact() const {
  return Impl->LegendCompact;
}
int NavSceneView::LegendFontPx() const {
  return Impl->LegendFontPx;
}

double NavSceneView::EnvelopeFloorM() const { return 0.5 * Impl->Options.min_envelope_px * Impl->ScaleMpp; }

void NavSceneViewImpl::ApplyStale() {
  if (!Renderer) return;
  if (!Stale) {
    for (auto &sc : StaleColors)
      sc.first->GetProperty()->SetColor(sc.second.data());
    StaleColors.clear();
    if (Title) {
      Title->SetInput(TitleText.c_str());
      Title->GetTextProperty()->SetColor(0.05, 0.05, 0.08);
    }
    return;
  }
  vtkActorCollection *actors = Renderer->GetActors();
  actors->InitTraversal();
  while (vtkActor *a = actors->GetNextActor()) {
    bool done = false;
    for (auto &sc : StaleColors)
      if (sc.first == a) done = true;
    if (done) continue;
    std::array<double, 3> c;
    a->GetProperty()->GetColor(c.data());
    StaleColors.push_back({a, c});
    // Two thirds of the way to a light grey: still readable, plainly not current.
    a->GetProperty()->SetColor(c[0] / 3.0 + 0.5, c[1] / 3.0 + 0.5, c[2] / 3.0 + 0.5);
  }
  if (Title) {
    Title->SetInput((TitleText + "  \u2013  OUT OF DATE").c_str());
    Title->GetTextProperty()->SetColor(0.55, 0.30, 0.0);
  }
}

void NavSceneView::SetStale(bool stale) {
  Impl->Stale = stale;
  Impl->ApplyStale();
}

bool NavSceneView::IsStale() const { return Impl->Stale; }
