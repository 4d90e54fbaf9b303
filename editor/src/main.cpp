// navstudio: the scenario editor.
//   navstudio [SCENE]                 open SCENE (default: a new drive)
//   navstudio --screenshot PNG [SCENE] render the window once, save it as PNG and exit
//   navstudio --bench-preview [N] [SCENE]  move a waypoint N times (default 20) and report the
//                                     live-preview edit-to-picture latency (median, p90, max) [ms]:
//                                     from the edit to the swap of the window frame showing the
//                                     re-simulated estimate; renders and frames per view per edit
// Test hooks (the kill-during-save test, editor/tests/navstudio_kill_save.py), by environment:
//   NAVSTUDIO_TEST_SAVE_LOOP=save|autosave  after opening SCENE, change its seed and undo it in
//                                     turn, saving (File > Save) or autosaving after each change,
//                                     until killed or NAVSTUDIO_TEST_SAVE_LOOP_CYCLES changes
//   NAVSTUDIO_TEST_SLOW_WRITE_US=US   write files in small pieces US microseconds apart (a slow
//                                     disk) and report each write's begin and end on stderr
#include <QApplication>
#include <QElapsedTimer>
#include <QSurfaceFormat>
#include <QTimer>
#include <QVTKOpenGLStereoWidget.h>

#include <sys/resource.h>

#include <algorithm>
#include <functional>
#include <cstdio>
#include <cstring>
#include <vector>

#include "main_window.h"

namespace {
// Waits the way the application's event loop does (sleeping until an event arrives; a 10 ms
// tick re-checks @p done): a busy loop here would take a core from the preview's simulation
// and from the software renderer's threads, which a user's navstudio does not.
// NAVSTUDIO_BENCH_BUSY_WAIT=1 polls as the first version of this benchmark did (comparisons).
void WaitFor(const std::function<bool()> &done, int timeout_ms) {
  QElapsedTimer t;
  t.start();
  QTimer tick;
  tick.start(10);
  const bool busy = qEnvironmentVariableIntValue("NAVSTUDIO_BENCH_BUSY_WAIT") == 1;
  while (!done() && t.elapsed() < timeout_ms) {
    if (busy)
      QApplication::processEvents(QEventLoop::AllEvents, 20); // returns at once when nothing is pending
    else
      QApplication::processEvents(QEventLoop::AllEvents | QEventLoop::WaitForMoreEvents);
  }
}

int BenchPreview(studio::MainWindow *w, int n) {
  studio::SceneDocument *doc = w->Doc();
  if (doc->Scene().trajectory.type != NAV_TRAJ_WAYPOINTS || doc->Scene().trajectory.waypoints.count < 2) {
    std::fprintf(stderr, "navstudio: --bench-preview needs a waypoint scene\n");
    return 2;
  }
  WaitFor([&] { return !w->PreviewWorker()->IsBusy() && !w->PreviewLatenciesMs().empty(); }, 60000);
  // The edits are measured with the 3D view's scene of the first preview drawn (libnavview's
  // triads, tube, vehicle and legend; greyed and overdrawn by each new preview during the drag).
  WaitFor([&] { return w->View3D()->Scene() != nullptr; }, 10000);
  const size_t before = w->PreviewLatenciesMs().size();
  // This process and the helper processes that run the simulations (sim_worker.h).
  auto cpu_s = [w] {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) +
           w->PreviewWorker()->HelperCpuS() + w->Worker()->HelperCpuS();
  };
  {
    // Cost of the GUI thread's per-edit work (validation, path sampling, one render per view).
    QElapsedTimer t;
    t.start();
    for (int i = 0; i < 5; ++i) {
      nav_scene v = doc->Scene(); // a different scene each time: the validation cache misses
      v.trajectory.waypoints.points[0].r_ned_m.x += 1e-3 * (i + 1);
      (void)studio::Validate(v);
    }
    const double v_ms = t.nsecsElapsed() * 1e-6 / 5;
    t.restart();
    studio::PathSamples ps;
    for (int i = 0; i < 5; ++i) studio::SamplePath(doc->Scene(), 1200, &ps, nullptr);
    const double s_ms = t.nsecsElapsed() * 1e-6 / 5;
    t.restart();
    for (int i = 0; i < 5; ++i) w->MapView()->Render();
    const double rm_ms = t.nsecsElapsed() * 1e-6 / 5;
    t.restart();
    for (int i = 0; i < 5; ++i) w->View3D()->Render();
    const double r3_ms = t.nsecsElapsed() * 1e-6 / 5;
    std::printf("preview_parts_ms: validate=%.1f sample_path_1200=%.1f render_map=%.1f render_3d=%.1f\n", v_ms, s_ms,
                rm_ms, r3_ms);
  }
  const double cpu0 = cpu_s();
  const long renders0 = w->MapView()->RenderCount() + w->View3D()->RenderCount();
  const long frames0 = w->MapView()->FrameCount() + w->View3D()->FrameCount();
  const int k = doc->Scene().trajectory.waypoints.count / 2;
  for (int i = 0; i < n; ++i) {
    nav_scene s = doc->Scene();
    s.trajectory.waypoints.points[k].r_ned_m.y += (i % 2 ? -5.0 : 5.0);
    doc->Preview(s);
    const size_t want = before + static_cast<size_t>(i) + 1;
    WaitFor([&] { return w->PreviewLatenciesMs().size() >= want; }, 30000);
  }
  std::vector<double> l(w->PreviewLatenciesMs().begin() + static_cast<long>(before), w->PreviewLatenciesMs().end());
  if (l.empty()) {
    std::fprintf(stderr, "navstudio: no preview completed\n");
    return 1;
  }
  const double cpu_ms = (cpu_s() - cpu0) * 1e3 / n;
  std::sort(l.begin(), l.end());
  // CPU per edit (simulation + redraw, all threads) is what the latency would be on an idle
  // machine with the simulation and the redraw not overlapping; the wall figures include load.
  double load = 0.0;
  if (FILE *f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1) load = 0.0;
    std::fclose(f);
  }
  const double renders = double(w->MapView()->RenderCount() + w->View3D()->RenderCount() - renders0) / n;
  const double frames = double(w->MapView()->FrameCount() + w->View3D()->FrameCount() - frames0) / n;
  {
    // The frames of a drag (the document is still live: no multisampling).
    QElapsedTimer t;
    t.start();
    for (int i = 0; i < 5; ++i) w->MapView()->Render();
    const double rm_ms = t.nsecsElapsed() * 1e-6 / 5;
    t.restart();
    for (int i = 0; i < 5; ++i) w->View3D()->Render();
    const double r3_ms = t.nsecsElapsed() * 1e-6 / 5;
    std::printf("preview_parts_ms: live render_map=%.1f render_3d=%.1f\n", rm_ms, r3_ms);
  }
  std::printf("preview_latency_ms: samples=%zu median=%.1f p90=%.1f max=%.1f cpu_per_edit_ms=%.1f "
              "renders_per_edit=%.1f renders_per_view_per_edit=%.2f frames_per_view_per_edit=%.2f duration_s=%.1f imu_rate_hz=%g "
              "loadavg=%.2f\n",
              l.size(), l[l.size() / 2], l[std::min(l.size() - 1, l.size() * 9 / 10)], l.back(), cpu_ms, renders,
              renders / 2.0, frames / 2.0,
              doc->Scene().trajectory.duration_s, doc->Scene().imu.rate_hz, load);
  return 0;
}
// NAVSTUDIO_TEST_SAVE_LOOP: save (or autosave) after each of a series of changes that alternate
// between two scenes, so that the file on disk is always one of two known texts. "save loop
// ready" on stderr marks the start; the loop ends after @p cycles changes (negative: never).
int SaveLoop(studio::MainWindow *w, bool autosave, int cycles) {
  studio::SceneDocument *doc = w->Doc();
  auto change = [doc] { doc->Edit(QStringLiteral("test: seed"), [](nav_scene &s) { s.simulation.seed += 1; }); };
  // An autosave is written only for a modified document: both of its scenes differ from the file.
  if (autosave) change();
  std::fprintf(stderr, "navstudio: test: save loop ready (%s)\n", autosave ? "autosave" : "save");
  int done = 0;
  QTimer tick;
  tick.setInterval(0);
  QObject::connect(&tick, &QTimer::timeout, [&] {
    if (cycles >= 0 && done >= cycles) {
      tick.stop();
      QApplication::exit(0);
      return;
    }
    if (done % 2 == 0)
      change();
    else
      doc->UndoStack()->undo();
    if (autosave)
      w->Autosave();
    else
      w->Save();
    ++done;
  });
  tick.start();
  return QApplication::exec();
}
} // namespace

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navsim");
  QApplication::setApplicationName("navstudio");
  QString scene, shot;
  int bench = 0;
  const QStringList args = QApplication::arguments();
  for (int i = 1; i < args.size(); ++i) {
    if (args[i] == "--screenshot" && i + 1 < args.size()) {
      shot = args[++i];
    } else if (args[i] == "--bench-preview") {
      bench = 20;
      if (i + 1 < args.size() && args[i + 1].toInt() > 0) bench = args[++i].toInt();
    } else if (args[i] == "--check" && i + 1 < args.size()) {
      // The panels' validation of a scene, without a window.
      studio::SceneDocument doc;
      QStringList errors;
      if (!doc.Load(args[i + 1], &errors)) {
        for (const QString &e : errors) std::fprintf(stderr, "%s\n", e.toLocal8Bit().constData());
        return 2;
      }
      const QVector<studio::Issue> issues = studio::Validate(doc.Scene());
      for (const studio::Issue &is : issues) std::fprintf(stderr, "%s\n", is.Text().toLocal8Bit().constData());
      return issues.isEmpty() ? 0 : 2;
    } else if (args[i] == "--help" || args[i] == "-h") {
      std::printf("usage: navstudio [SCENE] [--screenshot PNG] [--bench-preview [N]] | --check SCENE\n");
      return 0;
    } else if (args[i].startsWith("--")) {
      std::fprintf(stderr, "navstudio: error: unknown option '%s' (see --help)\n", args[i].toLocal8Bit().constData());
      return 2;
    } else {
      scene = args[i];
    }
  }
  studio::MainWindow w;
  const QString loop = scene.isEmpty() ? QString() : qEnvironmentVariable("NAVSTUDIO_TEST_SAVE_LOOP");
  if (!shot.isEmpty() || bench > 0 || !loop.isEmpty()) qputenv("NAVSTUDIO_NO_DIALOGS", "1");
  // The save loop answers "Recover the autosave?" (an earlier loop's) with No, as a user who
  // keeps the file's version would: the loop starts from the scene file.
  if (!loop.isEmpty())
    w.SetAsk([](const QString &, const QString &, QMessageBox::StandardButtons) { return QMessageBox::No; });
  if (shot.isEmpty() && bench == 0) w.FitToScreen(); // screenshots and the bench keep the default size
  w.show();
  if (!scene.isEmpty() && !w.OpenFile(scene)) {
    if (!shot.isEmpty() || bench > 0 || !loop.isEmpty()) return 2;
  }
  if (scene.isEmpty() && shot.isEmpty() && bench == 0) w.CheckRecovery();
  if (!loop.isEmpty()) {
    bool ok = false;
    const int cycles = qEnvironmentVariableIntValue("NAVSTUDIO_TEST_SAVE_LOOP_CYCLES", &ok);
    return SaveLoop(&w, loop == "autosave", ok ? cycles : -1);
  }
  if (bench > 0) return BenchPreview(&w, bench);
  if (!shot.isEmpty()) {
    WaitFor([&] { return !w.PreviewWorker()->IsBusy() && w.LastPreview() != nullptr && !w.PreviewLatenciesMs().empty(); },
            20000);
    QApplication::processEvents();
    return w.Screenshot().save(shot) ? 0 : 1;
  }
  return app.exec();
}
