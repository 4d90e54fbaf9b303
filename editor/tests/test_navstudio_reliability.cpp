// navstudio GUI tests (QTest under Xvfb) of issue 19 items 7 and 4: a crash of the simulation
// (SIGSEGV in the run's process, through the test hook NAVSTUDIO_TEST_CRASH_RUN) is reported in
// the window, which stays up with the previous results; the Errors tab's hover read-out shows
// the time and the values under the cursor. Screenshots go to NAVSTUDIO_TEST_OUT_DIR/reliab-*.png.
#include <QAction>
#include <QLabel>
#include <QRegularExpression>
#include <QSurfaceFormat>
#include <QTabWidget>
#include <QTest>
#include <QVTKOpenGLStereoWidget.h>

#include <cmath>
#include <vector>

#include "error_chart.h"
#include "main_window.h"
#include "navview/nav_view_chart.h"

extern "C" {
#include "navcore/nav_frames.h"
#include "navcore/nav_traj.h"
}
#include "studio_test_support.h"

using studio::MainWindow;
using namespace studio_test;

namespace {

bool OpenUrbanDrive(MainWindow *w, int runs) {
  if (!w->OpenFile(QStringLiteral(NAVSTUDIO_SOURCE_DIR "/scenes/urban-drive.yaml"))) return false;
  w->Doc()->Edit("runs", [runs](nav_scene &s) { s.simulation.runs = runs; });
  return true;
}

bool RunAndWait(MainWindow *w, int timeout_ms) {
  w->findChild<QAction *>("actionRun")->trigger(); // F5
  if (!w->Worker()->IsBusy()) return false;
  return WaitUntil([&] { return !w->Worker()->IsBusy(); }, timeout_ms);
}

QString StatusText(MainWindow *w) {
  return w->findChild<QLabel *>("statusText")->text();
}

/** The first number after @p key in @p text (NaN when absent). */
double NumberAfter(const QString &text, const QString &key) {
  const QRegularExpression re(QRegularExpression::escape(key) + QStringLiteral(" (-?[0-9]+(?:\\.[0-9]+)?)"));
  const QRegularExpressionMatch m = re.match(text);
  return m.hasMatch() ? m.captured(1).toDouble() : NAN;
}

} // namespace

class TestReliability : public QObject {
  Q_OBJECT
private slots:
  void cleanup() { qunsetenv("NAVSTUDIO_TEST_CRASH_RUN"); }

  // The Monte Carlo run crashes (SIGSEGV in navcore's run, by the test hook): the window stays
  // up and usable, the status bar says what happened, and the previous results stay shown.
  void run_crash_reported() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(OpenUrbanDrive(w.get(), 4));
    QVERIFY(RunAndWait(w.get(), 600000));
    const auto before = w->LastResult();
    QVERIFY(before && before->status == NAV_OK);
    const QString results_before = w->ResultsText();
    QVERIFY(results_before.contains("4 Monte Carlo runs"));
    Shot(w.get(), "reliab-01-before-crash");

    qputenv("NAVSTUDIO_TEST_CRASH_RUN", "run");
    QVERIFY(RunAndWait(w.get(), 600000));
    QVERIFY(w->isVisible());
    const QString status = StatusText(w.get());
    qInfo("status after the crash: %s", qPrintable(status));
    QVERIFY2(status.contains("crashed") && status.contains("SIGSEGV"), qPrintable(status));
    QVERIFY2(status.contains("last complete results are kept"), qPrintable(status));
    QVERIFY(w->LastResult() == before);         // the previous results remain...
    QCOMPARE(w->ResultsText(), results_before); // ...and are still shown
    QVERIFY(w->findChild<QAction *>("actionRun")->isEnabled());
    QVERIFY(!w->findChild<QAction *>("actionCancel")->isEnabled());
    Shot(w.get(), "reliab-02-after-crash");

    // The window still runs simulations.
    qunsetenv("NAVSTUDIO_TEST_CRASH_RUN");
    QVERIFY(RunAndWait(w.get(), 600000));
    QVERIFY(w->LastResult() && w->LastResult() != before && w->LastResult()->status == NAV_OK);
    QVERIFY2(StatusText(w.get()).startsWith("Done"), qPrintable(StatusText(w.get())));
    // Same scene, same seed: the run in its own process gives the same numbers again.
    QCOMPARE(w->LastResult()->summary.final.pos_err_h_m, before->summary.final.pos_err_h_m);
    QVERIFY(w->LastResult()->err_h_m == before->err_h_m);
  }

  // The live preview's run crashes: reported in the status bar, the window stays up, and the
  // next edit's preview (hook off) draws again.
  void preview_crash_reported() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(true);
    QVERIFY(OpenUrbanDrive(w.get(), 1));
    QVERIFY(WaitUntil([&] { return !w->PreviewWorker()->IsBusy() && w->LastPreview() != nullptr; }, 120000));
    const auto before = w->LastPreview();
    qputenv("NAVSTUDIO_TEST_CRASH_RUN", "preview");
    w->Doc()->Edit("seed", [](nav_scene &s) { s.simulation.seed += 1; });
    QVERIFY2(WaitUntil([&] { return StatusText(w.get()).contains("crashed"); }, 120000),
             qPrintable(QStringLiteral("status '%1', preview worker %2")
                            .arg(StatusText(w.get()), w->PreviewWorker()->IsBusy() ? "busy" : "idle")));
    QVERIFY(WaitUntil([&] { return !w->PreviewWorker()->IsBusy(); }, 120000));
    qInfo("status after the preview crash: %s", qPrintable(StatusText(w.get())));
    QVERIFY(StatusText(w.get()).contains("SIGSEGV"));
    QVERIFY(w->isVisible());
    QVERIFY(w->LastPreview() == before); // the last preview stays drawn
    Shot(w.get(), "reliab-03-preview-crash");
    qunsetenv("NAVSTUDIO_TEST_CRASH_RUN");
    w->Doc()->Edit("seed", [](nav_scene &s) { s.simulation.seed += 1; });
    QVERIFY(WaitUntil([&] { return w->LastPreview() != before && !w->PreviewWorker()->IsBusy(); }, 120000));
    QCOMPARE(w->LastPreview()->status, static_cast<int>(NAV_OK));
  }

  // A recorded reference crosses to the helper process with its control points (the scene's
  // bytes carry only pointers to them): the run follows the recorded path.
  void recorded_scene_runs() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(QStringLiteral(NAVSTUDIO_SOURCE_DIR "/scenes/recorded-adis16465.yaml")));
    QCOMPARE(w->Doc()->Scene().trajectory.type, NAV_TRAJ_RECORDED);
    QVERIFY(w->Doc()->Scene().trajectory.recorded.count > 0);
    w->Doc()->Edit("runs", [](nav_scene &s) { s.simulation.runs = 2; });
    QVERIFY(RunAndWait(w.get(), 600000));
    const auto r = w->LastResult();
    QVERIFY2(r && r->status == NAV_OK, r ? qPrintable(r->message) : "no result");
    QVERIFY(r->t_s.size() > 10 && r->truth_ned.size() == 3 * r->t_s.size());
    // The reference is the recorded drive: at the last epoch it is where navcore's trajectory
    // of the same scene, evaluated in this process, puts it.
    const size_t n = r->t_s.size();
    const nav_scene &sc = w->Doc()->Scene();
    nav_traj *traj = nullptr;
    QCOMPARE(nav_traj_create(&sc, 1.0 / sc.imu.rate_hz, &traj), NAV_OK);
    nav_traj_state st{};
    const nav_status es = nav_traj_eval(traj, r->t_s[n - 1], &st);
    const nav_frame fr = nav_traj_frame(traj);
    nav_traj_destroy(traj);
    QCOMPARE(es, NAV_OK);
    const nav_local_view v = nav_frame_view(&fr, st.r_fb_f_m, st.v_fb_f_mps, st.q_b_f);
    const double dn = r->truth_ned[3 * (n - 1)] - v.r_ned_m.x,
                 de = r->truth_ned[3 * (n - 1) + 1] - v.r_ned_m.y;
    const double moved = std::hypot(r->truth_ned[3 * (n - 1)] - r->truth_ned[0],
                                    r->truth_ned[3 * (n - 1) + 1] - r->truth_ned[1]);
    qInfo(
        "recorded reference: %zu epochs, %.2f m from the start at %.2f s; against this process's trajectory "
        "dN %.2e m, dE %.2e m",
        n, moved, r->t_s[n - 1], dn, de);
    QVERIFY(moved > 1.0);
    QVERIFY(std::fabs(dn) < 1e-6 && std::fabs(de) < 1e-6);
    QVERIFY(std::isfinite(r->summary.final.pos_err_h_m));
  }

  // Hovering a plot of the Errors tab shows a vertical line and a label with the time and the
  // values of the epoch under the cursor; off the plots the read-out goes away.
  void errors_hover_readout() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->FitToScreen();
    w->SetLivePreview(false);
    QVERIFY(OpenUrbanDrive(w.get(), 4));
    QVERIFY(RunAndWait(w.get(), 600000));
    const auto r = w->LastResult();
    QVERIFY(r && r->status == NAV_OK && r->t_s.size() > 100);
    auto *tabs = w->findChild<QTabWidget *>("bottomTabs");
    auto *chart = w->findChild<studio::ErrorChart *>("errorChart");
    QVERIFY(tabs && chart);
    tabs->setCurrentWidget(chart);
    QTest::qWait(300);
    const QImage pic = chart->Picture();
    QVERIFY2(!pic.isNull(), qPrintable(chart->Message()));
    const NavErrorChartLayout &lay = chart->Layout();
    QVERIFY(lay.plots.size() >= 4 && lay.t_min_s.size() == lay.plots.size());
    QCOMPARE(QString::fromStdString(lay.titles[0]), QStringLiteral("horizontal"));
    QLabel *label = chart->PictureLabel();
    // Points inside the plots, from the layout (x from the left, y from the bottom row up).
    auto at = [&](size_t panel, double fx, double fy) {
      const NavChartRect &p = lay.plots[panel];
      return QPoint(static_cast<int>(p.x + fx * p.w), static_cast<int>(pic.height() - (p.y + fy * p.h)));
    };
    auto time_at = [&](size_t panel, QPoint pt) {
      const NavChartRect &p = lay.plots[panel];
      return lay.t_min_s[panel] + (pt.x() + 0.5 - p.x) / p.w * (lay.t_max_s[panel] - lay.t_min_s[panel]);
    };
    const double dt = r->t_s[1] - r->t_s[0];

    // The horizontal panel, 60 % along (between the urban drive's two outages).
    chart->ensureVisible(0, 0);
    const QPoint ph = at(0, 0.6, 0.5);
    QTest::mouseMove(label, ph);
    QTRY_VERIFY_WITH_TIMEOUT(chart->ReadoutText().contains("horizontal"), 5000);
    const QString th = chart->ReadoutText();
    qInfo("read-out (horizontal): %s", qPrintable(th));
    const double t = NumberAfter(th, "t =");
    QVERIFY2(std::isfinite(t), qPrintable(th));
    // The nearest epoch to the cursor's time (one pixel spans (t1 - t0) / width seconds).
    const double px_s = (lay.t_max_s[0] - lay.t_min_s[0]) / lay.plots[0].w;
    QVERIFY2(std::fabs(t - time_at(0, ph)) <= 0.5 * dt + px_s + 0.05, qPrintable(th));
    size_t i = 0;
    while (i + 1 < r->t_s.size() && std::fabs(r->t_s[i + 1] - t) < std::fabs(r->t_s[i] - t))
      ++i;
    const double h = NumberAfter(th, "horizontal");
    qInfo("epoch %zu: t %.3f s, run 0 horizontal %.4f m; read-out %.4f m", i, r->t_s[i], r->err_h_m[i], h);
    QVERIFY(std::fabs(h - r->err_h_m[i]) <= 0.006 * std::max(1.0, std::fabs(r->err_h_m[i])));
    QVERIFY2(th.contains("RMS of 4 runs"), qPrintable(th));
    QVERIFY2(th.contains(QString::fromUtf8("filter 1\u03c3")), qPrintable(th));
    // The line and the label are drawn over the picture (the picture itself stays clean).
    const QImage shown = label->grab().toImage().convertToFormat(QImage::Format_RGB888);
    const QImage clean = pic.convertToFormat(QImage::Format_RGB888);
    long differ = 0;
    for (int y = 0; y < std::min(shown.height(), clean.height()); ++y)
      for (int x = 0; x < std::min(shown.width(), clean.width()); ++x)
        differ += shown.pixel(x, y) != clean.pixel(x, y) ? 1 : 0;
    qInfo("pixels changed by the hover overlay: %ld", differ);
    QVERIFY(differ > 2000);
    QVERIFY(chart->Picture() == pic);
    shown.save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/reliab-04-hover-horizontal.png"));
    Shot(w.get(), "reliab-05-hover-window");

    // The attitude panel: roll, pitch and yaw of the epoch.
    const size_t att = lay.plots.size() - 1;
    const QPoint pa = at(att, 0.25, 0.5);
    chart->ensureVisible(pa.x(), pa.y(), 10, 60);
    QTest::qWait(100);
    QTest::mouseMove(label, pa);
    QTRY_VERIFY_WITH_TIMEOUT(chart->ReadoutText().contains("roll"), 5000);
    const QString ta = chart->ReadoutText();
    qInfo("read-out (attitude): %s", qPrintable(ta));
    QVERIFY(ta.contains("pitch") && ta.contains("yaw"));
    const double ta_t = NumberAfter(ta, "t =");
    QVERIFY2(std::fabs(ta_t - time_at(att, pa)) <= 0.5 * dt + px_s + 0.05, qPrintable(ta));
    label->grab().save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/reliab-06-hover-attitude.png"));

    // Off the plots (in the legend column): no read-out.
    const NavChartRect &lg = lay.legends[0];
    QVERIFY(lg.w > 0);
    chart->ensureVisible(0, 0);
    QTest::qWait(100);
    const QPoint off(static_cast<int>(lg.x + lg.w / 2), static_cast<int>(pic.height() - (lg.y + lg.h / 2)));
    QTest::mouseMove(label, off);
    QTRY_VERIFY_WITH_TIMEOUT(chart->ReadoutText().isEmpty(), 5000);
  }
};

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navstudio-test");
  QApplication::setApplicationName("navstudio-test");
  TestReliability t;
  return QTest::qExec(&t, argc, argv);
}

#include "test_navstudio_reliability.moc"
