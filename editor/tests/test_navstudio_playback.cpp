// navstudio GUI tests (QTest under Xvfb) of the 3D playback (issue 19): the "Done when" journey
// (open scenes/urban-drive.yaml, 20 Monte Carlo runs, play back with attitude triads, follow the
// car, export a 10 s 1920x1080 MP4 checked with ffprobe), the exaggeration control and its
// legend, and the honest result state (out of date after an edit, Cancel keeps the last complete
// results, New drive clears them). Screenshots of each state go to
// NAVSTUDIO_TEST_OUT_DIR/playback-*.png.
#include <QAction>
#include <QCheckBox>
#include <QDoubleSpinBox>
#include <QFile>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QProcess>
#include <QProgressDialog>
#include <QTimer>
#include <QSlider>
#include <QSurfaceFormat>
#include <QTabWidget>
#include <QTest>
#include <QToolButton>
#include <QVTKOpenGLStereoWidget.h>

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>

#include <chrono>
#include <cmath>

#include "main_window.h"
#include "navview/nav_view_scene.h"
#include "studio_test_support.h"

using studio::MainWindow;
using namespace studio_test;

namespace {

double Dist(const double a[3], const double b[3]) {
  return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/** Rotation angle between two unit quaternions {w, x, y, z} [rad]. */
double QuatAngle(const double a[4], const double b[4]) {
  const double d = std::fabs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
  return 2.0 * std::acos(std::min(1.0, d));
}

/** ffprobe's value of @p entry (e.g. "stream=codec_name") of @p file; empty on failure. */
QString Probe(const QString &file, const QString &entry) {
  QProcess p;
  p.start("ffprobe", {"-v", "error", "-select_streams", "v:0", "-show_entries", entry, "-of",
                      "default=noprint_wrappers=1:nokey=1", file});
  if (!p.waitForFinished(60000) || p.exitCode() != 0) return QString();
  return QString::fromUtf8(p.readAllStandardOutput()).trimmed();
}

bool RunAndWait(MainWindow *w, int timeout_ms) {
  w->findChild<QAction *>("actionRun")->trigger(); // F5
  if (!w->Worker()->IsBusy()) return false;
  return WaitUntil([&] { return !w->Worker()->IsBusy(); }, timeout_ms);
}

} // namespace

class TestPlayback : public QObject {
  Q_OBJECT
private slots:
  // The first "Done when" of issue 19, step by step as a user does it.
  void playback_journey() {
    auto w = MakeWindow();
    QVERIFY(w);
    QVERIFY(w->OpenFile(QStringLiteral(NAVSTUDIO_SOURCE_DIR "/scenes/urban-drive.yaml")));
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "20");
    QCOMPARE(w->Doc()->Scene().simulation.runs, 20L);
    Shot(w.get(), "playback-01-opened");
    QVERIFY(RunAndWait(w.get(), 600000));
    QVERIFY(w->LastResult());
    QCOMPARE(static_cast<long>(w->LastResult()->summary.runs), 20L);
    QVERIFY(!w->ResultsStale());

    // The 3D view shows libnavview's scene of the result, with its legend.
    NavSceneView *sc = w->View3D()->Scene();
    QVERIFY(sc && sc->IsBuilt());
    QCOMPARE(sc->GetOptions().att_exaggeration, kNavDefaultAttExaggeration);
    const std::string legend = sc->LegendText();
    qInfo("legend:\n%s", legend.c_str());
    QVERIFY(legend.find("reference") != std::string::npos);
    QVERIFY(legend.find("estimate (run 0)") != std::string::npos);
    QVERIFY(legend.find("tube: 3\u00d7 RMS horizontal error\nover 20 runs") != std::string::npos);
    QVERIFY(legend.find("GNSS outage") != std::string::npos);
    QVERIFY(legend.find("error \u00d720") != std::string::npos);
    QVERIFY(legend.find("car at t") != std::string::npos);
    QVERIFY(sc->Model().triads_est.Size() > 5);
    QVERIFY(sc->Model().ellipsoids.size() > 0);
    // At city scale (5 km) the envelope is drawn at least 3 px wide at the view's scale.
    QVERIFY(sc->EnvelopeFloorM() > 0.0);
    studio::PlaybackBar *bar = w->Playback();
    QVERIFY(bar->Slider()->isEnabled());
    Shot(w.get(), "playback-02-result");

    // The slider moves the vehicle and the triads at t.
    bar->Slider()->setValue(bar->Slider()->maximum() / 4);
    double v1[3], p1[3], q1[4];
    QVERIFY(sc->VehiclePosition(v1));
    QVERIFY(sc->NowTriad(p1, q1));
    const double t1 = sc->GetTime();
    bar->Slider()->setValue(bar->Slider()->maximum() / 2);
    double v2[3], p2[3], q2[4];
    QVERIFY(sc->VehiclePosition(v2));
    QVERIFY(sc->NowTriad(p2, q2));
    const double t2 = sc->GetTime();
    qInfo("slider: t %.1f -> %.1f s, vehicle moved %.1f m, estimated triad %.1f m, turned %.2f deg", t1, t2,
          Dist(v1, v2), Dist(p1, p2), QuatAngle(q1, q2) * 180.0 / M_PI);
    QVERIFY(t2 > t1 + 50.0);
    QVERIFY(Dist(v1, v2) > 50.0);
    QVERIFY(Dist(p1, p2) > 50.0);
    QVERIFY(bar->TimeLabel()->text().contains(QString::number(t2, 'f', 1)));
    Shot(w.get(), "playback-03-slider-half");

    // Play advances time; pause stops it.
    QTest::mouseClick(bar->PlayButton(), Qt::LeftButton);
    QVERIFY(bar->Playing());
    QTest::qWait(1500);
    QTest::mouseClick(bar->PlayButton(), Qt::LeftButton);
    QVERIFY(!bar->Playing());
    const double t3 = sc->GetTime();
    qInfo("play: %.1f s of the run in 1.5 s at %gx", t3 - t2, bar->Speed());
    QVERIFY(t3 > t2 + 2.0);
    QTest::qWait(300);
    QCOMPARE(sc->GetTime(), t3);
    // Step forward: one second of the run.
    w->findChild<QToolButton *>("stepForward")->click();
    QCOMPARE(sc->GetTime(), t3 + 1.0);

    // Follow the car: the camera frames the vehicle at the chosen distance, the triads are sized
    // for that view (a twelfth of the distance, not the 5 km scene's size).
    const double triad_overview = sc->TriadSizeNow();
    QTest::mouseClick(bar->FollowBox(), Qt::LeftButton, {}, QPoint(8, bar->FollowBox()->height() / 2));
    QVERIFY(bar->Follow());
    QVERIFY(sc->GetOptions().follow);
    QCOMPARE(sc->FollowDistance(), 60.0);
    const double triad_follow = sc->TriadSizeNow();
    qInfo("triad size: overview %.1f m, following at 60 m %.1f m", triad_overview, triad_follow);
    QVERIFY(triad_follow < 0.5 * triad_overview);
    QVERIFY(std::fabs(triad_follow - 0.08 * 60.0) < 1e-9);
    Shot(w.get(), "playback-04-follow");

    // File > Export movie: 10 s, 1920x1080, H.264 MP4, the follow camera.
    const QString movie = QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/playback-urban-drive.mp4");
    QFile::remove(movie);
    MainWindow::MovieRequest req;
    req.duration_s = 10.0;
    req.width_px = 1920;
    req.height_px = 1080;
    req.follow = bar->Follow();
    QString err;
    const auto c0 = std::chrono::steady_clock::now();
    QVERIFY2(w->ExportMovie(movie, req, &err), qPrintable(err));
    const double enc_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - c0).count();
    QVERIFY(!QFileInfo::exists(movie + ".part"));
    qInfo("movie: %s, %.1f MB, written in %.1f s", qPrintable(movie), QFileInfo(movie).size() / 1e6, enc_s);
    QCOMPARE(Probe(movie, "stream=codec_name"), QStringLiteral("h264"));
    QCOMPARE(Probe(movie, "stream=width"), QStringLiteral("1920"));
    QCOMPARE(Probe(movie, "stream=height"), QStringLiteral("1080"));
    const double dur = Probe(movie, "format=duration").toDouble();
    qInfo("movie duration %.3f s", dur);
    QVERIFY(std::fabs(dur - 10.0) < 0.05);
    // Frames of the movie for the eye (start, middle).
    for (const char *at : {"1", "5"})
      QProcess::execute("ffmpeg", {"-v", "error", "-y", "-ss", at, "-i", movie, "-frames:v", "1",
                                   QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/playback-movie-%1s.png").arg(at)});
    Shot(w.get(), "playback-05-after-movie");

    // Single-view pictures without the forms.
    const QString pic3d = QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/playback-picture-3d.png");
    QVERIFY2(w->ExportPicture(pic3d, "3d", 1600, 900, &err), qPrintable(err));
    QCOMPARE(QImage(pic3d).size(), QSize(1600, 900));
    QVERIFY(!w->ExportPicture(pic3d + "-big.png", "3d", 4000, 3000, &err));
    QVERIFY(err.contains("3840x2160"));
    const QString picmap = QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/playback-picture-map.png");
    QVERIFY2(w->ExportPicture(picmap, "map", 1280, 720, &err), qPrintable(err));
    QCOMPARE(QImage(picmap).size(), QSize(1280, 720));
  }

  // The exaggeration control: the triad at t turns k times the attitude error away from the
  // reference, and the legend states k.
  void exaggeration() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(QStringLiteral(NAVSTUDIO_SOURCE_DIR "/scenes/urban-drive.yaml")));
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "2");
    QVERIFY(RunAndWait(w.get(), 600000));
    studio::PlaybackBar *bar = w->Playback();
    bar->Slider()->setValue(bar->Slider()->maximum() * 3 / 4);
    auto triad_at = [&](double k, double q[4]) {
      bar->ExaggerationBox()->setValue(k);
      NavSceneView *sc = w->View3D()->Scene();
      QVERIFY(sc);
      double p[3];
      QVERIFY(sc->NowTriad(p, q));
      QVERIFY(sc->LegendText().find("error \u00d7" + QString::number(k).toStdString()) != std::string::npos);
    };
    double q1[4], q2[4], q50[4];
    triad_at(1.0, q1);
    Shot(w.get(), "playback-06-exaggeration-1");
    triad_at(2.0, q2);
    triad_at(50.0, q50);
    Shot(w.get(), "playback-07-exaggeration-50");
    // exp(k phi) C_truth: the angle between k = 50 and k = 1 is 49 |phi|, between 2 and 1 |phi|.
    const double a49 = QuatAngle(q50, q1), a1 = QuatAngle(q2, q1);
    qInfo("attitude error %.4f deg; k=50 triad %.3f deg from k=1", a1 * 180 / M_PI, a49 * 180 / M_PI);
    QVERIFY(a1 > 1e-5);
    QVERIFY(std::fabs(a49 / a1 - 49.0) < 0.5);

    // File > Export movie's Cancel (in its progress dialog) stops it and leaves no file.
    const QString movie = QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/playback-cancelled.webm");
    QFile::remove(movie);
    QTimer::singleShot(1500, [&] {
      auto *dlg = w->findChild<QProgressDialog *>("movieProgress");
      if (dlg) dlg->cancel();
    });
    MainWindow::MovieRequest req;
    req.duration_s = 60.0;
    req.width_px = 640;
    req.height_px = 360;
    QString err;
    QVERIFY(!w->ExportMovie(movie, req, &err));
    qInfo("cancelled movie: %s", qPrintable(err));
    QVERIFY(err.contains("cancelled"));
    QVERIFY(!QFileInfo::exists(movie));
    QVERIFY(!QFileInfo::exists(movie + ".part"));
  }

  // Honest result state: an edit after a run marks the results out of date (greyed scene, tabs
  // say so) while the preview follows; Cancel keeps the last complete results; New drive clears.
  void result_state() {
    auto w = MakeWindow();
    QVERIFY(w);
    QVERIFY(w->NewDrive());
    w->SetLivePreview(true);
    // A small drive drawn on the map (its preview is shown in the 3D scene before any run).
    for (auto &p : kDrive) {
      int x = 0, y = 0;
      QVERIFY(w->MapView()->DisplayOf(p[0], p[1], 0.0, &x, &y));
      vtkRenderWindowInteractor *i = w->MapView()->Interactor();
      i->SetEventInformation(x, y, 0, 0);
      i->InvokeEvent(vtkCommand::MouseMoveEvent);
      i->InvokeEvent(vtkCommand::LeftButtonPressEvent);
      i->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
      QApplication::processEvents();
    }
    QVERIFY(WaitUntil([&] { return w->View3D()->Scene() != nullptr; }, 60000));
    Shot(w.get(), "playback-08-preview-scene");
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "4");
    QVERIFY(RunAndWait(w.get(), 300000));
    const auto good = w->LastResult();
    QVERIFY(good && good->summary.runs == 4);
    QVERIFY(!w->ResultsStale());
    QVERIFY(!w->View3D()->Scene()->IsStale());
    const QString results = w->ResultsText();
    QVERIFY(results.contains("4 Monte Carlo runs"));

    // An edit: out of date everywhere, the preview still follows.
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "3000");
    QVERIFY(w->ResultsStale());
    QVERIFY(w->View3D()->Scene()->IsStale());
    QVERIFY(w->ResultsText().contains("Out of date"));
    QVERIFY(w->ResultsText().contains("4 Monte Carlo runs")); // greyed, still there
    auto *tabs = w->findChild<QTabWidget *>("bottomTabs");
    QVERIFY(tabs->tabText(0).contains("out of date"));
    QVERIFY(w->LastResult() == good);
    Shot(w.get(), "playback-09-out-of-date");

    // Cancel a long run: the last complete results stay (still marked out of date).
    w->findChild<QAction *>("actionRun")->trigger();
    QVERIFY(w->Worker()->IsBusy());
    QVERIFY(WaitUntil([&] { return w->Worker()->Fraction() > 0.0; }, 120000));
    w->findChild<QAction *>("actionCancel")->trigger();
    QVERIFY(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 30000));
    QVERIFY(w->LastResult() == good);
    QVERIFY(w->View3D()->Scene() != nullptr);
    QVERIFY(w->ResultsText().contains("4 Monte Carlo runs"));
    QVERIFY(w->findChild<QLabel *>("statusText")->text().contains("last complete results are kept"));
    Shot(w.get(), "playback-10-cancel-keeps");

    // A new run: current again.
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "3");
    QVERIFY(RunAndWait(w.get(), 300000));
    QVERIFY(!w->ResultsStale());
    QVERIFY(!w->View3D()->Scene()->IsStale());
    QVERIFY(!tabs->tabText(0).contains("out of date"));

    // New drive: no results of the old drive anywhere.
    QVERIFY(w->NewDrive());
    QVERIFY(!w->LastResult());
    QVERIFY(!w->LastPreview());
    QVERIFY(w->View3D()->Scene() == nullptr);
    QVERIFY(!w->ResultsText().contains("Monte Carlo runs"));
    QVERIFY(!w->Playback()->Slider()->isEnabled());
    Shot(w.get(), "playback-11-new-drive");
  }
};

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navstudio-test");
  QApplication::setApplicationName("navstudio-test");
  TestPlayback t;
  return QTest::qExec(&t, argc, argv);
}

#include "test_navstudio_playback.moc"
