// navstudio GUI tests (QTest under Xvfb): the "Done when" journey by injected clicks on the map
// view, dragging a waypoint with the live preview, cancel mid-run, undo/redo, save/load round
// trip and autosave recovery. Screenshots of the main window after each step go to
// NAVSTUDIO_TEST_OUT_DIR/<test>-<step>.png.
#include <QAction>
#include <QComboBox>
#include <QDialog>
#include <QDir>
#include <QElapsedTimer>
#include <QFile>
#include <QGuiApplication>
#include <QLabel>
#include <QLineEdit>
#include <QMouseEvent>
#include <QPushButton>
#include <QRegularExpression>
#include <QScreen>
#include <QSignalSpy>
#include <QSurfaceFormat>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QWindow>
#include <QVTKOpenGLStereoWidget.h>

#include <cmath>
#include <cstring>
#include <memory>

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>

#include "main_window.h"
#include "schema_fields.h"
#include "studio_test_support.h"

using studio::MainWindow;
using studio::PathView;
using namespace studio_test;

namespace {

// Injected VTK events (toolchain.md section 4a): hover, press, optional drag steps, release.
void ClickAt(PathView *v, int x, int y, bool ctrl = false) {
  vtkRenderWindowInteractor *i = v->Interactor();
  i->SetEventInformation(x, y, ctrl ? 1 : 0, 0);
  i->InvokeEvent(vtkCommand::MouseMoveEvent);
  i->InvokeEvent(vtkCommand::LeftButtonPressEvent);
  i->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
}

void DragFromTo(PathView *v, int x0, int y0, int x1, int y1, int steps = 8) {
  vtkRenderWindowInteractor *i = v->Interactor();
  i->SetEventInformation(x0, y0, 0, 0);
  i->InvokeEvent(vtkCommand::MouseMoveEvent);
  i->InvokeEvent(vtkCommand::LeftButtonPressEvent);
  for (int k = 1; k <= steps; ++k) {
    i->SetEventInformation(x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps, 0, 0);
    i->InvokeEvent(vtkCommand::MouseMoveEvent);
    QApplication::processEvents();
  }
  i->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
}

// Click on the map at local north/east [m]; returns the pixel used.
void ClickMap(PathView *v, double n, double e, bool ctrl = false) {
  int x = 0, y = 0;
  QVERIFY2(v->DisplayOf(n, e, 0.0, &x, &y), "target outside the map view");
  ClickAt(v, x, y, ctrl);
}

// Metres per pixel of the map view at the centre (tolerance of a click).
double MapMetresPerPixel(PathView *v) {
  double n0 = 0, e0 = 0, n1 = 0, e1 = 0;
  int x = 0, y = 0;
  v->DisplayOf(0, 0, 0, &x, &y);
  v->GroundAt(x, y, 0.0, &n0, &e0);
  v->GroundAt(x + 1, y, 0.0, &n1, &e1);
  return std::hypot(n1 - n0, e1 - e0);
}





/** The PNG pictures a report embeds, in order. */
QList<QImage> ReportImages(const QString &html) {
  QList<QImage> out;
  const QRegularExpression re("data:image/png;base64,([A-Za-z0-9+/=]+)\"");
  for (auto it = re.globalMatch(html); it.hasNext();)
    out.push_back(QImage::fromData(QByteArray::fromBase64(it.next().captured(1).toLatin1()), "PNG"));
  return out;
}

} // namespace

class TestNavstudio : public QObject {
  Q_OBJECT
private slots:
  void initTestCase() {
    QVERIFY(tmp_.isValid());
    qputenv("NAVSTUDIO_AUTOSAVE_DIR", QFile::encodeName(tmp_.path() + "/autosave"));
    qputenv("NAVSTUDIO_NO_DIALOGS", "1");
  }

  // The "Done when" journey: draw four waypoints on the map, choose an IMU and a GNSS receiver
  // with a 60 s outage, run 100 Monte Carlo runs and read the requirement verdict.
  void journey() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    QVERIFY2(w->ResultsText().startsWith("Draw a drive on the map"), qPrintable(w->ResultsText()));
    Shot(w.get(), "journey-01-new");
    PathView *map = w->MapView();
    const double mpp = MapMetresPerPixel(map);
    QVERIFY(mpp > 0.0 && mpp < 5.0);
    for (int k = 0; k < 4; ++k) {
      ClickMap(map, kDrive[k][0], kDrive[k][1]);
      const nav_scene &s = w->Doc()->Scene();
      QCOMPARE(s.trajectory.waypoints.count, k + 1);
      const nav_vec3 r = s.trajectory.waypoints.points[k].r_ned_m;
      QVERIFY2(std::fabs(r.x - kDrive[k][0]) <= 1.5 * mpp && std::fabs(r.y - kDrive[k][1]) <= 1.5 * mpp,
               qPrintable(QString("waypoint %1 at %2, %3").arg(k).arg(r.x).arg(r.y)));
      // Two clicks already make a drive: stop, up to the cruise speed, stop.
      if (k == 1) QVERIFY2(w->Doc()->PlanMessage().isEmpty(), qPrintable(w->Doc()->PlanMessage()));
    }
    QVERIFY2(w->Doc()->PlanMessage().isEmpty(), qPrintable(w->Doc()->PlanMessage()));
    QVERIFY(map->PathPointCount() > 100);
    QVERIFY(w->View3D()->PathPointCount() == map->PathPointCount()); // both views in sync
    Shot(w.get(), "journey-02-four-waypoints");

    auto *imu = w->findChild<QComboBox *>("imuCatalog");
    QVERIFY(imu);
    Choose(imu, "ADIS16465");
    QCOMPARE(QString::fromUtf8(w->Doc()->Scene().imu.catalog), QString("ADIS16465-1"));
    QVERIFY(w->Doc()->Scene().imu.model.gyro.terms != 0);
    auto *rx = w->findChild<QComboBox *>("gnssReceiver");
    QVERIFY(rx);
    Choose(rx, "SBAS");
    QVERIFY(QString::fromUtf8(w->Doc()->Scene().gnss.catalog).contains("SBAS"));
    auto *add_outage = w->findChild<QPushButton *>("addOutage");
    QVERIFY(add_outage);
    w->Panels()->setCurrentIndex(2);
    QTest::mouseClick(add_outage, Qt::LeftButton);
    const nav_gnss_model_config &g = w->Doc()->Scene().gnss.model;
    QCOMPARE(static_cast<int>(g.outage_count), 1);
    QCOMPARE(g.outages[0].t1_s - g.outages[0].t0_s, 60.0);
    QVERIFY(g.outages[0].t1_s < w->Doc()->Scene().trajectory.duration_s);
    auto *add_req = w->findChild<QPushButton *>("addRequirement");
    QVERIFY(add_req);
    QTest::mouseClick(add_req, Qt::LeftButton);
    QCOMPARE(w->Doc()->Scene().n_requirements, 1);
    QCOMPARE(static_cast<int>(w->Doc()->Scene().requirements[0].statistic), static_cast<int>(NAV_REQ_OUTAGE_END));
    auto *runs = w->findChild<QLineEdit *>("simulation.runs");
    QVERIFY(runs);
    TypeInto(runs, "100");
    QCOMPARE(w->Doc()->Scene().simulation.runs, 100L);
    Shot(w.get(), "journey-03-configured");

    w->findChild<QAction *>("actionRun")->trigger();
    QVERIFY(w->Worker()->IsBusy());
    QVERIFY2(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 600000), "the Monte Carlo run did not finish");
    auto r = w->LastResult();
    QVERIFY(r);
    QCOMPARE(r->status, static_cast<int>(NAV_OK));
    QCOMPARE(r->summary.runs, 100L);
    QCOMPARE(static_cast<int>(r->verdicts.size()), 1);
    const nav_requirement_verdict &v = r->verdicts[0];
    QVERIFY(v.evaluated);
    QCOMPARE(v.outage_count, 1);
    QVERIFY(std::isfinite(v.value) && v.value > 0.0);
    QCOMPARE(v.pass, v.value <= v.limit);
    // The verdict as the user reads it: the Requirements panel's summary and the results text.
    auto *summary = w->findChild<QLabel *>("verdictSummary");
    QVERIFY(summary);
    QVERIFY2(summary->text().startsWith(v.pass ? "PASS" : "FAIL"), qPrintable(summary->text()));
    QVERIFY(w->ResultsText().contains(v.pass ? "verdict: PASS" : "verdict: FAIL"));
    qInfo("journey: 100 runs in %.1f s, %s = %.3f m (limit %.1f m): %s", r->wall_s, v.id, v.value, v.limit,
          v.pass ? "PASS" : "FAIL");
    // The Monte Carlo band (3 x RMS over the 100 runs) about run 0's estimate in both views.
    QVERIFY(r->env_t_s.size() > 10);
    QCOMPARE(w->MapView()->EnvelopePointCount(), 2 * r->env_t_s.size());
    QCOMPARE(w->View3D()->EnvelopePointCount(), 2 * r->env_t_s.size());
    w->Panels()->setCurrentIndex(5); // the Requirements panel: the verdict per requirement
    Shot(w.get(), "journey-04-verdict");
    w->findChild<QTabWidget *>("bottomTabs")->setCurrentIndex(1);
    Shot(w.get(), "journey-05-error-chart");
  }

  // Issue 21: the gyro-free INS aided by GNSS from the Model panel. A scene of that scheme shows
  // it in the scheme list; choosing it from another scheme turns the receiver on; a Monte Carlo
  // run reports the filter's sigma band beside the Monte Carlo band, and the requirement verdicts.
  void gyro_free_gnss_scheme() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/gyro-free-gnss-car.yaml"));
    auto *scheme = w->findChild<QComboBox *>("scheme");
    QVERIFY(scheme);
    QCOMPARE(scheme->currentText(), QString("gyro_free_gnss"));
    QVERIFY(!scheme->itemData(scheme->currentIndex(), Qt::ToolTipRole).toString().isEmpty());
    w->Panels()->setCurrentIndex(0);
    Choose(scheme, "free_ins", Qt::MatchExactly);
    QCOMPARE(static_cast<int>(w->Doc()->Scene().navigation.scheme), static_cast<int>(NAV_SCHEME_FREE_INS));
    w->Doc()->Edit("receiver off", [](nav_scene &s) { s.gnss.enabled = false; });
    Choose(scheme, "gyro_free_gnss", Qt::MatchExactly);
    QCOMPARE(static_cast<int>(w->Doc()->Scene().navigation.scheme), static_cast<int>(NAV_SCHEME_GYRO_FREE_GNSS));
    QVERIFY(w->Doc()->Scene().gnss.enabled);
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "4");
    QCOMPARE(w->Doc()->Scene().simulation.runs, 4L);
    QVERIFY(w->Run());
    QVERIFY2(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 600000), "the Monte Carlo run did not finish");
    auto r = w->LastResult();
    QVERIFY(r);
    QCOMPARE(r->status, static_cast<int>(NAV_OK));
    QCOMPARE(r->summary.runs, 4L);
    QVERIFY(r->env_t_s.size() > 10);
    QCOMPARE(r->env_sd_h_m.size(), r->env_t_s.size());
    for (double sd : r->env_sd_h_m) QVERIFY(std::isfinite(sd) && sd > 0.0);
    QCOMPARE(static_cast<int>(r->verdicts.size()), 2);
    QVERIFY(r->verdicts[0].evaluated && r->verdicts[0].outage_count == 1);
    qInfo("gyro_free_gnss: 4 runs in %.1f s, %s = %.3f m (limit %.1f m)", r->wall_s, r->verdicts[0].id,
          r->verdicts[0].value, r->verdicts[0].limit);
    Shot(w.get(), "gyro-free-gnss-01-run");
  }

  // Issue 22: the tightly coupled INS/GNSS from the Model panel. A scene of that scheme shows it in
  // the scheme list; choosing it from another scheme turns the receiver and the constellation on;
  // a Monte Carlo run reports the filter's sigma band and the requirement verdicts.
  void tight_scheme() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/urban-canyon-tight.yaml"));
    auto *scheme = w->findChild<QComboBox *>("scheme");
    QVERIFY(scheme);
    QCOMPARE(scheme->currentText(), QString("ins_gnss_tight"));
    QVERIFY(!scheme->itemData(scheme->currentIndex(), Qt::ToolTipRole).toString().isEmpty());
    w->Panels()->setCurrentIndex(0);
    Choose(scheme, "free_ins", Qt::MatchExactly);
    QCOMPARE(static_cast<int>(w->Doc()->Scene().navigation.scheme), static_cast<int>(NAV_SCHEME_FREE_INS));
    w->Doc()->Edit("receiver and satellites off", [](nav_scene &s) {
      s.gnss.enabled = false;
      s.gnss.constellation.enabled = false;
    });
    Choose(scheme, "ins_gnss_tight", Qt::MatchExactly);
    QCOMPARE(static_cast<int>(w->Doc()->Scene().navigation.scheme), static_cast<int>(NAV_SCHEME_INS_GNSS_TIGHT));
    QVERIFY(w->Doc()->Scene().gnss.enabled);
    QVERIFY(w->Doc()->Scene().gnss.constellation.enabled);
    QVERIFY(nav_scene_validate(&w->Doc()->Scene(), nullptr, nullptr) == NAV_OK);
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "4");
    QCOMPARE(w->Doc()->Scene().simulation.runs, 4L);
    QVERIFY(w->Run());
    QVERIFY2(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 600000), "the Monte Carlo run did not finish");
    auto r = w->LastResult();
    QVERIFY(r);
    QCOMPARE(r->status, static_cast<int>(NAV_OK));
    QCOMPARE(r->summary.runs, 4L);
    QVERIFY(r->env_t_s.size() > 10);
    QCOMPARE(r->env_sd_h_m.size(), r->env_t_s.size());
    for (double sd : r->env_sd_h_m) QVERIFY(std::isfinite(sd) && sd > 0.0);
    QCOMPARE(static_cast<int>(r->verdicts.size()), 2);
    QVERIFY(r->verdicts[0].evaluated);
    // The canyon came back with the constellation section: metres at its end, not centimetres.
    QVERIFY(r->verdicts[0].value > 1.0);
    qInfo("ins_gnss_tight: 4 runs in %.1f s, %s = %.3f m (limit %.1f m)", r->wall_s, r->verdicts[0].id,
          r->verdicts[0].value, r->verdicts[0].limit);
    Shot(w.get(), "tight-01-run");
  }

  // Issue 21 item 3: arrays and parts from the Array panel. The car scene shows its cube6 array
  // with typed terms; picking a catalog part fills the per-sensor terms with its datasheet figures
  // (shown in datasheet units with the source), the scale factor the gyro-free/GNSS filter cannot
  // take is switched off with a note, and a longer arm is typed; the run's filter sigma at the end
  // of the outage falls as the noise per arm length does (20 ug/rtHz / 0.5 m -> 7 ug/rtHz / 1 m).
  void array_parts() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/gyro-free-gnss-car.yaml"));
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "4");
    QCOMPARE(w->Doc()->Scene().simulation.runs, 4L);
    // The outage end: largest filter sigma inside [100, 108] s.
    auto outage_sd = [](const studio::SimResult &r) {
      double m = 0.0;
      for (size_t i = 0; i < r.env_t_s.size(); ++i)
        if (r.env_t_s[i] >= 100.0 && r.env_t_s[i] <= 108.0) m = std::max(m, r.env_sd_h_m[i]);
      return m;
    };
    QVERIFY(w->Run());
    QVERIFY2(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 600000), "the first run did not finish");
    auto r0 = w->LastResult();
    QVERIFY(r0 && r0->status == NAV_OK);
    const double sd0 = outage_sd(*r0);
    QVERIFY(sd0 > 0.0);

    int tab = -1;
    for (int i = 0; i < w->Panels()->count(); ++i)
      if (w->Panels()->tabText(i) == "Array") tab = i;
    QVERIFY(tab >= 0);
    w->Panels()->setCurrentIndex(tab);
    auto *layout = w->findChild<QComboBox *>("arrayLayout");
    auto *part = w->findChild<QComboBox *>("arrayPart");
    auto *figures = w->findChild<QLabel *>("arrayPartFigures");
    auto *note = w->findChild<QLabel *>("arrayNote");
    auto *sensors = w->findChild<QTableWidget *>("arraySensors");
    QVERIFY(layout && part && figures && note && sensors);
    QCOMPARE(layout->currentText(), QString("cube6"));
    QCOMPARE(part->currentIndex(), 0); // typed terms
    QCOMPARE(sensors->rowCount(), 6);
    QCOMPARE(w->findChild<QLineEdit *>("array.accel.noise_density")->text(), QString("20"));
    QVERIFY(part->count() >= 7);
    Shot(w.get(), "array-01-typed-terms");

    Choose(part, "Safran Colibrys MS1002", Qt::MatchExactly);
    const nav_scene &s = w->Doc()->Scene();
    QCOMPARE(QString::fromUtf8(s.array.catalog), QString("Safran Colibrys MS1002"));
    const double ug = 1e-6 * 9.80665;
    QVERIFY(std::fabs(s.array.accel.vrw_mps_per_sqrt_s - 7.0 * ug) <= 1e-12 * 7.0 * ug);
    QVERIFY(std::fabs(s.array.accel.bias_turn_on_sd_mps2 - 0.24e3 * ug) <= 1e-12);
    QVERIFY(std::fabs(s.array.accel.bias_gm_sd_mps2 - 3.0 * ug / 0.61736) <= 1e-4 * 3.0 * ug);
    QVERIFY(s.array.accel.terms & NAV_IMU_TERM_BIAS_GM);
    QVERIFY(!(s.array.accel.terms & NAV_IMU_TERM_SCALE_FACTOR)); // gyro_free_gnss: no SF states
    QVERIFY2(note->text().contains("scale factor (120 ppm) is off"), qPrintable(note->text()));
    // The datasheet figures as the datasheet gives them, with the source and its check.
    for (const char *want :
         {"range ±2 g", "noise 7 µg/√Hz", "bias instability 3 µg", "bias repeatability 0.24 mg",
          "scale factor 120 ppm", "MS1000 data sheet", "verified: yes"})
      QVERIFY2(figures->text().contains(QString::fromUtf8(want)), qPrintable(figures->text()));
    // The typed-term fields now show the part's figures in datasheet units.
    QCOMPARE(w->findChild<QLineEdit *>("array.accel.noise_density")->text(), QString("7"));
    QCOMPARE(w->findChild<QLineEdit *>("array.accel.bias_turn_on")->text(), QString("0.24"));
    QVERIFY(w->findChild<QLineEdit *>("array.accel.scale_factor")->text().isEmpty());

    TypeInto(w->findChild<QLineEdit *>("array.radius_m"), "1");
    QCOMPARE(w->Doc()->Scene().array.radius_m, 1.0);
    QVERIFY2(note->text().contains(QString::fromUtf8("κ/r = 0.707 /m")),
             qPrintable(note->text())); // 1/sqrt(2) / 1 m
    QCOMPARE(sensors->item(0, 0)->text(), QString("1"));
    // An unverified part says so.
    const int qa = part->findText("Honeywell QA-2000 Q-Flex");
    QVERIFY(qa > 0);
    QVERIFY(part->itemData(qa, Qt::ToolTipRole).toString().contains("NOT verified"));
    Shot(w.get(), "array-02-ms1002-arm-1m");

    QVERIFY(w->Run());
    QVERIFY2(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 600000), "the second run did not finish");
    auto r1 = w->LastResult();
    QVERIFY(r1 && r1->status == NAV_OK);
    const double sd1 = outage_sd(*r1);
    qInfo("array_parts: filter horizontal sigma at the outage end %.3f m (20 ug/rtHz, 0.5 m) -> %.3f m "
          "(MS1002, 1 m); "
          "h-outage-end over 4 runs %.3f -> %.3f m",
          sd0, sd1, r0->verdicts[0].value, r1->verdicts[0].value);
    // navsim estimate predicts 3.18 m -> 2.40 m for the two scenes (ratio 0.75).
    QVERIFY2(sd1 < 0.85 * sd0 && sd1 > 0.5 * sd0, qPrintable(QString("%1 vs %2").arg(sd1).arg(sd0)));
    QVERIFY(r1->verdicts[0].evaluated && r1->verdicts[0].pass);

    // The part survives save and reload as array.catalog with the overrides.
    const QString path = tmp_.path() + "/array-part.yaml";
    QVERIFY(w->SaveAs(path));
    auto w2 = MakeWindow();
    QVERIFY(w2 && w2->OpenFile(path));
    QCOMPARE(QString::fromUtf8(w2->Doc()->Scene().array.catalog), QString("Safran Colibrys MS1002"));
    QCOMPARE(w2->Doc()->Scene().array.radius_m, 1.0);
    QCOMPARE(w2->Doc()->Scene().array.accel.terms, s.array.accel.terms);
    w->Panels()->setCurrentIndex(tab);
    w->findChild<QTabWidget *>("bottomTabs")->setCurrentIndex(1);
    Shot(w.get(), "array-03-run");

    // Layouts: nine shows its nine sensors; custom starts from the geometry in use and its table
    // is editable, one undoable edit per cell.
    Choose(layout, "nine", Qt::MatchExactly);
    QCOMPARE(static_cast<int>(w->Doc()->Scene().array.layout), static_cast<int>(NAV_ARRAY_LAYOUT_NINE));
    QCOMPARE(sensors->rowCount(), 9);
    QVERIFY(!(sensors->item(0, 0)->flags() & Qt::ItemIsEditable));
    Choose(layout, "custom", Qt::MatchExactly);
    const nav_scene_array &arr = w->Doc()->Scene().array;
    QCOMPARE(static_cast<int>(arr.layout), static_cast<int>(NAV_ARRAY_LAYOUT_CUSTOM));
    QCOMPARE(arr.custom_count, 9);
    QCOMPARE(sensors->rowCount(), 9);
    QVERIFY(sensors->item(0, 0)->flags() & Qt::ItemIsEditable);
    const double x_before = arr.custom[3].r_bs_b_m.x;
    sensors->item(3, 0)->setText("0.9");
    QCOMPARE(w->Doc()->Scene().array.custom[3].r_bs_b_m.x, 0.9);
    w->Doc()->UndoStack()->undo();
    QCOMPARE(w->Doc()->Scene().array.custom[3].r_bs_b_m.x, x_before);
    Shot(w.get(), "array-04-custom");
  }

  // Fields validate as the user types, with the messages of `navsim check`; nothing is
  // committed until Enter, and a valid value then clears the message.
  void validation() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    auto *arw = w->findChild<QLineEdit *>("imu.gyro.arw");
    QVERIFY(arw);
    auto *msg = w->findChild<QLabel *>("imu.gyro.arw.message");
    QVERIFY(msg);
    // The field's unit, bounds and description come from navcore_io's scene table.
    const nav_schema_key &k = studio::SchemaKey("imu.gyro.arw_deg_per_sqrt_h");
    QVERIFY2(arw->toolTip().contains(QString::fromUtf8(k.doc)), qPrintable(arw->toolTip()));
    QVERIFY2(arw->toolTip().contains(QStringLiteral("≤ %1 deg/√h").arg(k.max)), qPrintable(arw->toolTip()));
    w->Panels()->setCurrentIndex(1);
    arw->setFocus();
    QTest::keyClicks(arw, "-1");
    QVERIFY2(msg->text().contains("imu.gyro.arw_deg_per_sqrt_h: must be >= 0 (got -1)"), qPrintable(msg->text()));
    QCOMPARE(w->Doc()->Scene().imu.model.gyro.terms & NAV_IMU_TERM_NOISE, 0u); // not committed yet
    Shot(w.get(), "validation-01-negative-arw");
    arw->selectAll();
    QTest::keyClicks(arw, "x");
    QVERIFY2(msg->text().contains("expected a number, got 'x'"), qPrintable(msg->text()));
    arw->selectAll();
    QTest::keyClicks(arw, "0.15");
    QVERIFY(msg->text().isEmpty() || !msg->isVisible());
    QTest::keyClick(arw, Qt::Key_Return);
    QVERIFY(w->Doc()->Scene().imu.model.gyro.terms & NAV_IMU_TERM_NOISE);
    QCOMPARE(w->Doc()->Scene().imu.model.gyro.arw_rad_per_sqrt_s.x, 0.15 * (M_PI / 180.0) / 60.0);
    auto *rate = w->findChild<QLineEdit *>("gnss.update_rate");
    QVERIFY(rate);
    rate->setFocus();
    rate->selectAll();
    QTest::keyClicks(rate, "0");
    QVERIFY2(w->findChild<QLabel *>("gnss.update_rate.message")->text().contains("gnss.update_rate_hz: must be > 0"),
             qPrintable(w->findChild<QLabel *>("gnss.update_rate.message")->text()));
  }

  // An infeasible edit in the waypoint table: the planner's message (as navsim check prints it)
  // names the waypoint, the run is refused, undo restores a feasible drive.
  void infeasible_edit() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    for (auto &p : kDrive) ClickMap(w->MapView(), p[0], p[1]);
    QVERIFY(w->Doc()->PlanMessage().isEmpty());
    w->Panels()->setCurrentIndex(3);
    QTableWidget *t = w->Panels()->WaypointTable();
    QCOMPARE(t->rowCount(), 4);
    t->item(1, 3)->setText("40"); // 40 m/s into a 90 deg corner 450 m after the start
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.points[1].speed_mps, 40.0);
    QVERIFY(!w->Doc()->PlanMessage().isEmpty());
    bool named = false;
    for (const studio::Issue &i : studio::Validate(w->Doc()->Scene()))
      named = named || (i.path == "trajectory.waypoints.points[1]" && i.message.contains("max_lateral_accel"));
    QVERIFY(named);
    QVERIFY(!w->Run());
    Shot(w.get(), "infeasible-01-turn-too-fast");
    w->findChild<QAction *>("actionUndo")->trigger();
    QVERIFY(w->Doc()->PlanMessage().isEmpty());
    QVERIFY(w->MapView()->PathPointCount() > 100);
  }

  // Dragging a waypoint moves it, redraws the path and updates the live preview.
  void drag_waypoint() {
    auto w = MakeWindow();
    QVERIFY(w);
    QVERIFY(w->NewDrive());
    PathView *map = w->MapView();
    for (auto &p : kDrive) ClickMap(map, p[0], p[1]);
    QVERIFY(WaitUntil([&] { return w->LastPreview() && !w->PreviewWorker()->IsBusy(); }, 60000));
    const std::vector<double> path_before = map->Path().ned_m;
    const std::vector<double> est_before = w->LastPreview()->nav_ned;
    const int undo_before = w->Doc()->UndoStack()->index();
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    QVERIFY(map->DisplayOf(kDrive[2][0], kDrive[2][1], 0, &x0, &y0));
    QVERIFY(map->DisplayOf(kDrive[2][0] + 100.0, kDrive[2][1] + 50.0, 0, &x1, &y1));
    DragFromTo(map, x0, y0, x1, y1);
    const double mpp = MapMetresPerPixel(map);
    const nav_vec3 r = w->Doc()->Scene().trajectory.waypoints.points[2].r_ned_m;
    QVERIFY2(std::fabs(r.x - (kDrive[2][0] + 100.0)) <= 1.5 * mpp && std::fabs(r.y - (kDrive[2][1] + 50.0)) <= 1.5 * mpp,
             qPrintable(QString("dragged to %1, %2").arg(r.x).arg(r.y)));
    QCOMPARE(w->Doc()->UndoStack()->index(), undo_before + 1); // one undo step for the drag
    QVERIFY(map->Path().ned_m != path_before);
    QVERIFY(w->View3D()->Path().ned_m == map->Path().ned_m);
    // The preview follows: a preview of the current scene arrives.
    QVERIFY(WaitUntil([&] { return w->LastPreview() && w->LastPreview()->scene_change_ns == w->Doc()->LastChangeNs(); },
                      60000));
    QVERIFY(w->LastPreview()->nav_ned != est_before);
    // The latency is taken when the frame showing the estimate has been swapped.
    QVERIFY(WaitUntil([&] { return !w->PreviewLatenciesMs().empty(); }, 10000));
    qInfo("drag: preview latency %.1f ms (edit to picture)", w->PreviewLatenciesMs().back());
    Shot(w.get(), "drag-01-after-drag");
  }

  // Cancel mid-run: the worker stops promptly and the window reports it.
  void cancel_run() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    for (auto &p : kDrive) ClickMap(w->MapView(), p[0], p[1]);
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "5000");
    QVERIFY(w->Run());
    QVERIFY(WaitUntil([&] { return w->Worker()->Fraction() > 0.0; }, 120000));
    Shot(w.get(), "cancel-01-running");
    QElapsedTimer t;
    t.start();
    w->findChild<QAction *>("actionCancel")->trigger();
    QVERIFY(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 30000));
    qInfo("cancel: stopped %lld ms after the request", static_cast<long long>(t.elapsed()));
    QVERIFY(t.elapsed() < 10000);
    QVERIFY(!w->LastResult()); // no result from a cancelled run
    QVERIFY(w->findChild<QLabel *>("statusText")->text().startsWith("Cancelled"));
    QVERIFY(w->findChild<QAction *>("actionRun")->isEnabled());
    Shot(w.get(), "cancel-02-cancelled");
  }

  // File > Export report: one self-contained HTML file with the verdict of each requirement, the
  // statistics and the pictures embedded; before any run it says so; a path that cannot be
  // written gives an error and leaves nothing.
  void export_report() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    for (auto &p : kDrive) ClickMap(w->MapView(), p[0], p[1]);
    const QString dir = QString(NAVSTUDIO_TEST_OUT_DIR);
    QDir().mkpath(dir);
    const QString before = dir + "/report-before-run.html";
    QFile::remove(before);
    QString err;
    QVERIFY2(w->ExportReport(before, &err), qPrintable(err));
    QFile fb(before);
    QVERIFY(fb.open(QIODevice::ReadOnly));
    const QString hb = QString::fromUtf8(fb.readAll());
    QVERIFY(hb.contains("No simulation has been run for this scene yet."));
    QVERIFY(hb.contains("data:image/png;base64,"));
    // Before a run the report embeds the map and the 3D view as they stand, each at its view's
    // size, never a grab of the window with its forms (issue 19).
    const QList<QImage> before_imgs = ReportImages(hb);
    QVERIFY(!before_imgs.isEmpty());
    for (const QImage &im : before_imgs) {
      qInfo("report before a run: picture %d x %d (window %d x %d, map %d x %d, 3D %d x %d)", im.width(), im.height(),
            w->width(), w->height(), w->MapView()->width(), w->MapView()->height(), w->View3D()->width(),
            w->View3D()->height());
      QVERIFY(im.size() == w->MapView()->size() || im.size() == w->View3D()->size());
      QVERIFY(im.size() != w->size());
    }

    QTest::mouseClick(w->findChild<QPushButton *>("addRequirement"), Qt::LeftButton);
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "8");
    QVERIFY(w->Run());
    QVERIFY(WaitUntil([&] { return !w->Worker()->IsBusy(); }, 300000));
    auto r = w->LastResult();
    QVERIFY(r && r->status == NAV_OK && r->verdicts.size() == 1);
    const QString path = dir + "/report.html";
    QFile::remove(path);
    QVERIFY2(w->ExportReport(path, &err), qPrintable(err));
    QFile f(path);
    QVERIFY(f.open(QIODevice::ReadOnly));
    const QString h = QString::fromUtf8(f.readAll());
    const nav_requirement_verdict &v = r->verdicts[0];
    QVERIFY(h.startsWith("<!DOCTYPE html>"));
    QVERIFY(h.contains("8 Monte Carlo runs"));
    QVERIFY(h.contains(QString("Requirements: %1 of 1 pass").arg(v.pass ? 1 : 0)));
    QVERIFY(h.contains(QString::fromUtf8(v.id)));
    QVERIFY(h.contains(v.pass ? ">PASS<" : ">FAIL<"));
    QVERIFY(h.contains(QString::number(v.value, 'g', 4)));
    QVERIFY(h.contains("horizontal position"));
    // Three pictures: the 3D view and the map as File > Export picture writes them (the view
    // alone at kReportPictureWidth x kReportPictureHeight, no forms; issue 19: the report
    // embedded a grab of the whole window), and the error chart.
    QCOMPARE(h.count("data:image/png;base64,"), 3);
    const QList<QImage> imgs = ReportImages(h);
    QCOMPARE(imgs.size(), 3);
    const QSize pic(MainWindow::kReportPictureWidth, MainWindow::kReportPictureHeight);
    QVERIFY(w->size() != pic); // else the sizes could not tell a view from the window
    const char *names[2] = {"3d", "map"};
    for (int k = 0; k < 2; ++k) {
      qInfo("report picture %s: %d x %d (window %d x %d)", names[k], imgs[k].width(), imgs[k].height(), w->width(),
            w->height());
      QCOMPARE(imgs[k].size(), pic);
      QVERIFY(imgs[k].save(dir + QString("/report-%1.png").arg(names[k])));
      // The same picture as File > Export picture of that view at that size.
      const QString exported = dir + QString("/report-export-%1.png").arg(names[k]);
      QString e2;
      QVERIFY2(w->ExportPicture(exported, names[k], pic.width(), pic.height(), &e2), qPrintable(e2));
      QCOMPARE(imgs[k].convertToFormat(QImage::Format_RGB32), QImage(exported).convertToFormat(QImage::Format_RGB32));
    }
    QVERIFY(h.trimmed().endsWith("</html>"));
    qInfo("report: %lld bytes, verdict %s = %.4g", static_cast<long long>(f.size()), v.id, v.value);
    // An unwritable path: an error naming it, and no file.
    const QString bad = dir + "/no-such-dir/report.html";
    QVERIFY(!w->ExportReport(bad, &err));
    QVERIFY(err.contains(bad));
    QVERIFY(!QFile::exists(bad));
  }

  // Simulation > Speed against error: navsim tradeoff of the saved scene (1 run per variant), its
  // dialog with one chart per requirement and the recommendation, which opens as the scene.
  void tradeoff() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/urban-drive.yaml"));
    w->Tradeoff()->SetProgram(NAVSIM_EXE);
    const QString out = QString(NAVSTUDIO_TEST_OUT_DIR) + "/tradeoff-urban-drive";
    QDir(out).removeRecursively();
    QSignalSpy done(w->Tradeoff(), &studio::TradeoffRun::Finished);
    QString err;
    QVERIFY2(w->StartTradeoff(out, 1, &err), qPrintable(err));
    QVERIFY(!w->StartTradeoff(out, 1, &err)); // one at a time
    QVERIFY(done.wait(600000));
    QVERIFY2(done.at(0).at(0).toBool(), qPrintable(done.at(0).at(1).toString()));
    QDialog *d = w->findChild<QDialog *>("tradeoffDialog");
    QVERIFY(d);
    QVERIFY(QTest::qWaitForWindowExposed(d));
    const auto charts = d->findChildren<QLabel *>("tradeoffChart");
    QCOMPARE(charts.size(), 2); // h-outage-end, h-cep95
    for (const QLabel *c : charts) QCOMPARE(c->pixmap(Qt::ReturnByValue).width(), 1000);
    QFile sf(out + "/summary.json");
    QVERIFY(sf.open(QIODevice::ReadOnly));
    const QString summary = QString::fromUtf8(sf.readAll());
    const QRegularExpression re("\"recommended\": \\{\"variant\": \"([^\"]+)\"");
    const QRegularExpressionMatch m = re.match(summary);
    QVERIFY(m.hasMatch());
    QVERIFY(d->findChild<QLabel *>("tradeoffRecommendation")->text().contains("<b>" + m.captured(1) + "</b>"));
    d->grab().save(QString(NAVSTUDIO_TEST_OUT_DIR) + "/tradeoff-dialog.png");
    QTest::mouseClick(d->findChild<QPushButton *>("openRecommended"), Qt::LeftButton);
    QTRY_COMPARE(w->Doc()->FilePath(), out + "/recommended.yaml");
    // A modified scene is not what navsim would read: refused with the reason.
    QTest::mouseClick(w->findChild<QPushButton *>("addRequirement"), Qt::LeftButton);
    QVERIFY(!w->StartTradeoff(out + "-2", 1, &err));
    QVERIFY(err.contains("Save the scene first"));
  }

  // Undo/redo of clicks, a catalog choice and a typed field; the modified marker follows.
  void undo_redo() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    QVERIFY(!w->isWindowModified());
    for (auto &p : kDrive) ClickMap(w->MapView(), p[0], p[1]);
    QVERIFY(w->isWindowModified());
    Choose(w->findChild<QComboBox *>("imuCatalog"), "STIM300");
    TypeInto(w->findChild<QLineEdit *>("simulation.seed"), "42");
    QCOMPARE(w->Doc()->Scene().simulation.seed, uint64_t(42));
    QAction *undo = w->findChild<QAction *>("actionUndo");
    QAction *redo = w->findChild<QAction *>("actionRedo");
    undo->trigger();
    QCOMPARE(w->Doc()->Scene().simulation.seed, uint64_t(1));
    undo->trigger();
    QCOMPARE(QString::fromUtf8(w->Doc()->Scene().imu.catalog), QString());
    QCOMPARE(w->findChild<QComboBox *>("imuCatalog")->currentIndex(), 0);
    undo->trigger();
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 3);
    Shot(w.get(), "undo-01-three-waypoints");
    for (int k = 0; k < 3; ++k) undo->trigger();
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 0);
    QVERIFY(!w->isWindowModified()); // back to the clean state
    for (int k = 0; k < 6; ++k) redo->trigger();
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 4);
    QCOMPARE(QString::fromUtf8(w->Doc()->Scene().imu.catalog), QString("Safran Sensonor STIM300"));
    QCOMPARE(w->Doc()->Scene().simulation.seed, uint64_t(42));
    QVERIFY(w->isWindowModified());
    Shot(w.get(), "undo-02-redone");
  }

  // Save, load in a fresh window, save again: identical files and scenes.
  void save_load() {
    const QString a = tmp_.path() + "/drive-a.yaml", b = tmp_.path() + "/drive-b.yaml";
    nav_scene saved;
    {
      auto w = MakeWindow();
      QVERIFY(w);
      w->SetLivePreview(false);
      QVERIFY(w->NewDrive());
      for (auto &p : kDrive) ClickMap(w->MapView(), p[0], p[1]);
      Choose(w->findChild<QComboBox *>("imuCatalog"), "ADIS16465");
      Choose(w->findChild<QComboBox *>("gnssReceiver"), "SBAS");
      QTest::mouseClick(w->findChild<QPushButton *>("addOutage"), Qt::LeftButton);
      QTest::mouseClick(w->findChild<QPushButton *>("addRequirement"), Qt::LeftButton);
      QVERIFY(w->SaveAs(a));
      QVERIFY(!w->isWindowModified());
      QVERIFY(w->windowTitle().startsWith("drive-a.yaml"));
      QVERIFY(w->RecentFiles().contains(QFileInfo(a).absoluteFilePath()));
      saved = w->Doc()->Scene();
    }
    auto w2 = MakeWindow();
    QVERIFY(w2);
    w2->SetLivePreview(false);
    QVERIFY(w2->OpenFile(a));
    const nav_scene &s = w2->Doc()->Scene();
    QCOMPARE(s.trajectory.waypoints.count, 4);
    QVERIFY(std::memcmp(s.trajectory.waypoints.points, saved.trajectory.waypoints.points, 4 * sizeof(nav_waypoint)) == 0);
    QVERIFY(std::memcmp(&s.imu.model, &saved.imu.model, sizeof s.imu.model) == 0);
    QVERIFY(std::memcmp(&s.gnss.model, &saved.gnss.model, sizeof s.gnss.model) == 0);
    QCOMPARE(s.n_requirements, 1);
    QCOMPARE(s.trajectory.duration_s, saved.trajectory.duration_s);
    QVERIFY(w2->SaveAs(b));
    QFile fa(a), fb(b);
    QVERIFY(fa.open(QIODevice::ReadOnly) && fb.open(QIODevice::ReadOnly));
    QCOMPARE(fa.readAll(), fb.readAll());
    // No temporary file is left next to the scene (atomic save: temp + rename).
    const QStringList left = QDir(tmp_.path()).entryList(QStringList() << "*.tmp*", QDir::Files | QDir::Hidden);
    QVERIFY2(left.isEmpty(), qPrintable(left.join(",")));
    Shot(w2.get(), "save-01-reopened");
  }

  // An autosave left by a window that ended without saving is offered and recovered.
  void autosave_recovery() {
    int count = 0;
    nav_vec3 last{};
    QString autosave;
    {
      auto w = MakeWindow();
      QVERIFY(w);
      w->SetLivePreview(false);
      QVERIFY(w->NewDrive());
      for (auto &p : kDrive) ClickMap(w->MapView(), p[0], p[1]);
      Choose(w->findChild<QComboBox *>("imuCatalog"), "HG4930");
      w->Autosave();
      autosave = w->AutosavePath();
      QVERIFY(QFile::exists(autosave));
      count = w->Doc()->Scene().trajectory.waypoints.count;
      last = w->Doc()->Scene().trajectory.waypoints.points[count - 1].r_ned_m;
      // "Crash": the window goes away without asking to save; the autosave stays.
      w->SetAsk([](const QString &, const QString &, QMessageBox::StandardButtons) { return QMessageBox::Cancel; });
    }
    QVERIFY(QFile::exists(autosave));
    auto w2 = MakeWindow();
    QVERIFY(w2);
    w2->SetLivePreview(false);
    QVERIFY(w2->CheckRecovery());
    const nav_scene &s = w2->Doc()->Scene();
    QCOMPARE(s.trajectory.waypoints.count, count);
    QCOMPARE(s.trajectory.waypoints.points[count - 1].r_ned_m.x, last.x);
    QCOMPARE(s.trajectory.waypoints.points[count - 1].r_ned_m.y, last.y);
    QCOMPARE(QString::fromUtf8(s.imu.catalog), QString("Honeywell HG4930"));
    QVERIFY(w2->isWindowModified()); // recovered, not yet saved
    Shot(w2.get(), "autosave-01-recovered");
    // Discarding the recovered changes removes the autosave.
    QVERIFY(w2->NewDrive());
    QVERIFY(!QFile::exists(autosave));
  }

  // File > Import track: a GPX drive becomes waypoints (one undo step), a motion definition a
  // segment script, a broken file an error at FILE:LINE:COL.
  void import_track() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    const QString dir = tmp_.path();
    auto write = [&](const QString &name, const QByteArray &text) {
      QFile f(dir + "/" + name);
      if (!f.open(QIODevice::WriteOnly)) return QString();
      f.write(text);
      return f.fileName();
    };
    // An L-shaped drive in Munich: 400 m north, then 400 m east (no times: constant speed).
    const QString gpx = write("drive.gpx", "<?xml version=\"1.0\"?>\n"
                                           "<gpx version=\"1.1\" creator=\"t\" xmlns=\"http://www.topografix.com/GPX/1/1\">\n"
                                           "<trk><name>l drive</name><trkseg>\n"
                                           "<trkpt lat=\"48.137\" lon=\"11.575\"/>\n"
                                           "<trkpt lat=\"48.1406\" lon=\"11.575\"/>\n"
                                           "<trkpt lat=\"48.1406\" lon=\"11.5804\"/>\n"
                                           "</trkseg></trk></gpx>\n");
    QVERIFY(!gpx.isEmpty());
    const int before = w->Doc()->UndoStack()->count();
    QStringList errors;
    QVERIFY2(w->ImportTrack(gpx, &errors), qPrintable(errors.join("\n")));
    const nav_scene &s = w->Doc()->Scene();
    QCOMPARE(int(s.trajectory.type), int(NAV_TRAJ_WAYPOINTS));
    QVERIFY(s.trajectory.waypoints.count >= 3);
    QCOMPARE(int(s.earth.model), int(NAV_EARTH_WGS84));
    QVERIFY(std::fabs(s.earth.origin_lat_rad * 180.0 / M_PI - 48.137) < 1e-9);
    // The last waypoint is about 400 m north and 400 m east of the first.
    const nav_vec3 last = s.trajectory.waypoints.points[s.trajectory.waypoints.count - 1].r_ned_m;
    QVERIFY2(std::fabs(last.x - 400.4) < 5.0 && std::fabs(last.y - 401.5) < 5.0,
             qPrintable(QString("%1 %2").arg(last.x).arg(last.y)));
    QCOMPARE(w->Doc()->UndoStack()->count(), before + 1);
    QVERIFY(w->MapView()->PathPointCount() > 10);
    Shot(w.get(), "import-01-gpx");
    // Undoable: back to the empty drive, and redo.
    w->Doc()->UndoStack()->undo();
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 0);
    w->Doc()->UndoStack()->redo();
    QVERIFY(w->Doc()->Scene().trajectory.waypoints.count >= 3);

    // A broken GPX: the error names the file, line and column; the scene is unchanged.
    const QString bad = write("bad.gpx", "<?xml version=\"1.0\"?>\n"
                                         "<gpx version=\"1.1\" creator=\"t\" xmlns=\"http://www.topografix.com/GPX/1/1\">\n"
                                         "<trk><trkseg>\n"
                                         "<trkpt lat=\"48.137\" lon=\"11.575\"/>\n"
                                         "<trkpt lat=\"148.2\" lon=\"11.575\"/>\n"
                                         "</trkseg></trk></gpx>\n");
    const int count = w->Doc()->UndoStack()->count();
    QVERIFY(!w->ImportTrack(bad, &errors));
    QVERIFY(!errors.isEmpty());
    QVERIFY2(errors.first().contains(QRegularExpression("bad\\.gpx:5:\\d+: error: ")), qPrintable(errors.join("\n")));
    QCOMPARE(w->Doc()->UndoStack()->count(), count);
    QVERIFY(w->Doc()->Scene().trajectory.waypoints.count >= 3);
    Shot(w.get(), "import-02-error");

    // A gnss-ins-sim motion definition: a segment script.
    const QString md = write("motion.csv",
                             "ini lat (deg),ini lon (deg),ini alt (m),ini vx_body (m/s),ini vy_body (m/s),ini vz_body (m/s),"
                             "ini yaw (deg),ini pitch (deg),ini roll (deg)\n"
                             "32,120,0,0,0,0,0,0,0\n"
                             "command type,yaw (deg),pitch (deg),roll (deg),vx_body (m/s),vy_body (m/s),vz_body (m/s),"
                             "command duration (s),GPS visibility\n"
                             "1,0,0,0,0,0,0,20,1\n"
                             "2,0,0,0,1,0,0,10,1\n"
                             "1,0,0,0,0,0,0,30,1\n");
    QVERIFY2(w->ImportTrack(md, &errors), qPrintable(errors.join("\n")));
    QCOMPARE(int(w->Doc()->Scene().trajectory.type), int(NAV_TRAJ_SEGMENTS));
    QVERIFY(w->Doc()->Scene().trajectory.segments.count >= 3);
    QVERIFY(w->MapView()->PathPointCount() > 10);
    Shot(w.get(), "import-03-motiondef");
    w->Doc()->UndoStack()->undo();
    QCOMPARE(int(w->Doc()->Scene().trajectory.type), int(NAV_TRAJ_WAYPOINTS));
  }

  // The profile chart: speed, acceleration and turn rate along the planned drive, within the
  // vehicle limits; a motion definition whose type-1 turn exceeds them is coloured and explained.
  void profile_chart() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    QVERIFY(!w->Profile()->Message().isEmpty() || w->Profile()->Profile().Size() == 0);
    for (const auto &p : kDrive) studio::AddWaypoint(w->Doc(), p[0], p[1], 0.0);
    const studio::PathSamples &pr = w->Profile()->Profile();
    QVERIFY(pr.Size() >= 100);
    QVERIFY2(w->Profile()->Message().isEmpty(), qPrintable(w->Profile()->Message()));
    double vmax = 0.0, turn_abs = 0.0, tmin = 0.0, tmax = 0.0;
    for (size_t i = 0; i < pr.Size(); ++i) {
      vmax = std::max(vmax, pr.speed_mps[i]);
      tmin = std::min(tmin, pr.turn_rps[i]);
      tmax = std::max(tmax, pr.turn_rps[i]);
      if (i > 0) turn_abs += 0.5 * (std::fabs(pr.turn_rps[i]) + std::fabs(pr.turn_rps[i - 1])) * (pr.t_s[i] - pr.t_s[i - 1]);
    }
    // The drive: east, a left turn to north, a right turn back to east, at the 10 m/s cruise speed.
    const double cruise = w->Doc()->Scene().trajectory.waypoints.points[1].speed_mps;
    QVERIFY(std::fabs(vmax - cruise) < 0.01 * cruise);
    QVERIFY(tmin < 0.0 && tmax > 0.0);
    QVERIFY2(std::fabs(turn_abs - M_PI) < 0.03 * M_PI, qPrintable(QString::number(turn_abs * 180 / M_PI)));
    double ua = 0, ut = 0, ul = 0;
    w->Profile()->Utilisation(&ua, &ut, &ul);
    QVERIFY(ua > 0.0 && ua <= 1.001);
    QVERIFY(ut > 0.0 && ut <= 1.001);
    QVERIFY(ul > 0.0 && ul <= 1.001);
    QCOMPARE(w->MapView()->OverLimitPointCount(), size_t(0));
    Shot(w.get(), "profile-01-drive");

    // A motion definition: accelerate to 10 m/s, then a 90 deg/s yaw rate for 1 s (type 1 is
    // not limited by gnss-ins-sim): 15.7 m/s² sideways, over the lateral-acceleration limit.
    QFile f(tmp_.path() + "/sharp.csv");
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write("ini lat (deg),ini lon (deg),ini alt (m),ini vx_body (m/s),ini vy_body (m/s),ini vz_body (m/s),"
            "ini yaw (deg),ini pitch (deg),ini roll (deg)\n"
            "52.5,13.4,0,0,0,0,0,0,0\n"
            "command type,yaw (deg),pitch (deg),roll (deg),vx_body (m/s),vy_body (m/s),vz_body (m/s),"
            "command duration (s),GPS visibility\n"
            "1,0,0,0,0,0,0,5,1\n"
            "1,0,0,0,1,0,0,10,1\n"
            "1,90,0,0,0,0,0,1,1\n"
            "1,0,0,0,0,0,0,10,1\n");
    f.close();
    QStringList errors;
    QVERIFY2(w->ImportTrack(f.fileName(), &errors), qPrintable(errors.join("\n")));
    const studio::PathSamples &p2 = w->Profile()->Profile();
    QVERIFY(p2.Size() >= 100);
    unsigned bits = 0;
    for (unsigned char b : p2.over) bits |= b;
    QVERIFY2(bits & studio::kOverLateral, qPrintable(studio::OverLimitText(bits)));
    QVERIFY(w->MapView()->OverLimitPointCount() > 0);
    QVERIFY(w->View3D()->OverLimitPointCount() > 0);
    Shot(w.get(), "profile-02-over-limit");
  }

  // Live-preview cost cuts: the preview simulates a lighter scene (covariance every 10th IMU
  // step, IMU at 50 Hz, output at 10 Hz), and during a live drag each view draws one frame per
  // preview (the path waits for its estimate); the committed edit is drawn at once.
  void live_preview_cost() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(true);
    QVERIFY(w->NewDrive());
    for (const auto &p : kDrive) studio::AddWaypoint(w->Doc(), p[0], p[1], 0.0);
    studio::SceneDocument *doc = w->Doc();
    auto settled = [&] {
      return !w->PreviewWorker()->IsBusy() && w->LastPreview() && w->LastPreview()->scene_change_ns == doc->LastChangeNs();
    };
    QVERIFY(WaitUntil(settled, 60000));
    QVERIFY(WaitUntil([&] { return !w->PreviewLatenciesMs().empty(); }, 10000)); // its picture is shown
    const nav_scene &s = doc->Scene();
    QCOMPARE(s.imu.rate_hz, 100.0);
    auto light = studio::PreviewScene(s);
    QCOMPARE(light->imu.rate_hz, studio::kPreviewImuHz);
    QVERIFY(light->navigation.cov_decimation >= studio::kPreviewCovDecimation);
    QVERIFY(light->output.rate_hz <= studio::kPreviewOutputHz);
    QCOMPARE(light->trajectory.waypoints.count, s.trajectory.waypoints.count);
    // A scene whose IMU rate 50 Hz does not divide keeps it.
    nav_scene odd = s;
    odd.imu.rate_hz = 64.0;
    odd.output.rate_hz = 8.0;
    QCOMPARE(studio::PreviewScene(odd)->imu.rate_hz, 64.0);
    // The preview of the lighter scene: estimates over the whole drive at its output rate, at
    // most kPreviewMaxEpochs of them (10 Hz for a short drive).
    const auto pv = w->LastPreview();
    QVERIFY(std::fabs(double(pv->t_s.size()) - (s.trajectory.duration_s * light->output.rate_hz + 1.0)) <= 2.0);
    QVERIFY(pv->t_s.size() <= studio::kPreviewMaxEpochs + 2);
    nav_scene long_drive = s;
    long_drive.trajectory.duration_s = 513.0;
    QCOMPARE(studio::PreviewScene(long_drive)->output.rate_hz, 4.0);
    long_drive.output.rate_hz = 2.0; // a scene's lower rate stays
    QCOMPARE(studio::PreviewScene(long_drive)->output.rate_hz, 2.0);
    // The preview's error band (3 x the filter's horizontal sigma) follows the estimate in both
    // views: two band points per envelope epoch, a width that is the filter's, not zero.
    QVERIFY(pv->env_sd_h_m.size() > 100 && pv->env_sd_h_m.size() == pv->env_t_s.size());
    QCOMPARE(w->MapView()->EnvelopePointCount(), 2 * pv->env_t_s.size());
    QCOMPARE(w->View3D()->EnvelopePointCount(), 2 * pv->env_t_s.size());
    for (double sd : pv->env_sd_h_m) QVERIFY(std::isfinite(sd) && sd > 0.0 && sd < 1e3);

    PathView *views[2] = {w->MapView(), w->View3D()};
    for (PathView *v : views) v->SetLiveRenderDelay(60000); // the mechanism, not the machine's speed
    w->SetLiveFrameHoldMs(60000);
    long r0[2] = {views[0]->RenderCount(), views[1]->RenderCount()};
    const size_t n0 = w->PreviewLatenciesMs().size();
    const nav_scene before = s;
    const int edits = 4;
    auto quiet = [&] { return !views[0]->FramePending() && !views[1]->FramePending(); };
    for (int i = 0; i < edits; ++i) {
      // No earlier render's frame still to come (on failure: which view waits, and for what).
      QVERIFY2(WaitUntil(quiet, 10000),
               qPrintable(QString("edit %1: map renders %2 frames %3 pending %4 exposed %5; 3D renders %6 frames %7 "
                                  "pending %8 exposed %9")
                              .arg(i)
                              .arg(views[0]->RenderCount())
                              .arg(views[0]->FrameCount())
                              .arg(views[0]->FramePending())
                              .arg(views[0]->NativeWindow()->isExposed())
                              .arg(views[1]->RenderCount())
                              .arg(views[1]->FrameCount())
                              .arg(views[1]->FramePending())
                              .arg(views[1]->NativeWindow()->isExposed())));
      nav_scene e = doc->Scene();
      e.trajectory.waypoints.points[1].r_ned_m.y += 5.0;
      const long f0[2] = {views[0]->FrameCount(), views[1]->FrameCount()};
      doc->Preview(e);
      QVERIFY(doc->IsLive());
      QVERIFY(WaitUntil([&] { return w->PreviewLatenciesMs().size() >= n0 + size_t(i) + 1; }, 30000));
      // One frame per view and edit: the path and its estimate together.
      for (int k = 0; k < 2; ++k) QCOMPARE(views[k]->FrameCount() - f0[k], 1L);
      QVERIFY(WaitUntil(settled, 30000));
    }
    for (int k = 0; k < 2; ++k) QCOMPARE(views[k]->RenderCount() - r0[k], long(edits));
    // The path drawn is the edited one.
    QCOMPARE(views[0]->Path().Size(), views[0]->PathPointCount());
    Shot(w.get(), "live-01-dragging");
    // Release: one undo step, drawn at once (not waiting for a preview).
    const long r1 = views[0]->RenderCount();
    doc->Commit(before, "Move waypoint 1");
    QVERIFY(!doc->IsLive());
    QTest::qWait(30);
    QVERIFY(views[0]->RenderCount() > r1);
    QVERIFY(WaitUntil(settled, 60000));
    Shot(w.get(), "live-02-released");
  }

  // The views are native windows: real Qt mouse events (not injected VTK ones) reach the
  // waypoint editor through VTK's Qt adapter. A click adds a waypoint under the cursor, a drag
  // of its handle moves it, the Delete key removes the selected one.
  void qt_events_on_views() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    PathView *map = w->MapView();
    QWindow *win = map->NativeWindow();
    QVERIFY(win && win->isExposed());
    const double mpp = MapMetresPerPixel(map);
    // VTK display coordinates have their origin at the bottom left, Qt's at the top left.
    auto qt_point = [&](double n, double e) {
      int x = 0, y = 0;
      if (!map->DisplayOf(n, e, 0.0, &x, &y)) return QPoint(-1, -1);
      return QPoint(x, win->height() - 1 - y);
    };
    for (int k = 0; k < 2; ++k) {
      const QPoint p = qt_point(kDrive[k][0], kDrive[k][1]);
      QVERIFY(p.x() >= 0);
      QTest::mouseMove(win, p);
      QTest::mouseClick(win, Qt::LeftButton, Qt::NoModifier, p);
      QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, k + 1);
      const nav_vec3 r = w->Doc()->Scene().trajectory.waypoints.points[k].r_ned_m;
      QVERIFY2(std::fabs(r.x - kDrive[k][0]) <= 1.5 * mpp && std::fabs(r.y - kDrive[k][1]) <= 1.5 * mpp,
               qPrintable(QString("waypoint %1 at %2, %3").arg(k).arg(r.x).arg(r.y)));
    }
    // Drag waypoint 1 by 40 px to the right (east) in steps.
    const QPoint a = qt_point(kDrive[1][0], kDrive[1][1]);
    QTest::mouseMove(win, a);
    QTest::mousePress(win, Qt::LeftButton, Qt::NoModifier, a);
    for (int s = 1; s <= 8; ++s) {
      // QTest::mouseMove on a QWindow sends no button state: a QMouseEvent with the left button
      // held, as the window system sends during a drag.
      QMouseEvent mv(QEvent::MouseMove, a + QPoint(5 * s, 0), Qt::NoButton, Qt::LeftButton, Qt::NoModifier);
      QGuiApplication::sendEvent(win, &mv);
      QApplication::processEvents();
    }
    QTest::mouseRelease(win, Qt::LeftButton, Qt::NoModifier, a + QPoint(40, 0));
    const nav_vec3 moved = w->Doc()->Scene().trajectory.waypoints.points[1].r_ned_m;
    QVERIFY2(std::fabs(moved.y - (kDrive[1][1] + 40.0 * mpp)) <= 2.0 * mpp && std::fabs(moved.x - kDrive[1][0]) <= 2.0 * mpp,
             qPrintable(QString("moved to %1, %2 (mpp %3)").arg(moved.x).arg(moved.y).arg(mpp)));
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 2);
    QCOMPARE(map->SelectedWaypoint(), 1);
    Shot(w.get(), "qt-events-01-dragged");
    QTest::keyClick(win, Qt::Key_Delete);
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 1);
  }

  // A resize of the main window: each view draws at its new size at once, on screen and in its
  // own framebuffer (a native window learns its size before VTK does; the first render after a
  // resize used to draw at the old size: a stale, cropped map on screen and a blank Grab()).
  void resize_redraws_views() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    PathView *map = w->MapView();
    for (int k = 0; k < 4; ++k) ClickMap(map, kDrive[k][0], kDrive[k][1]);
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 4);
    // The drawn plan's black (0.08, 0.08, 0.10; the views' one palette), in the middle fifth to
    // four fifths of the view's height: the legend (top right) and the caption (bottom) are text
    // of about the same colour.
    auto blue_pixels = [](const QImage &img) {
      int k = 0;
      for (int y = img.height() / 5; y < img.height() * 4 / 5; ++y)
        for (int x = 0; x < img.width(); ++x) {
          const QColor c = img.pixelColor(x, y);
          if (c.red() < 50 && c.green() < 50 && c.blue() < 55) ++k;
        }
      return k;
    };
    // Share of pixels where the screen and the view's own frame differ (any channel by > 40),
    // over the part of the view that is on the screen.
    auto screen_mismatch = [](PathView *v, const QImage &frame) {
      const QRect on_screen = QRect(v->mapToGlobal(QPoint(0, 0)), v->size()) & QGuiApplication::primaryScreen()->geometry();
      if (on_screen.width() * on_screen.height() < v->width() * v->height() / 4) return -1.0; // not enough to judge
      const QImage screen = QGuiApplication::primaryScreen()
                                ->grabWindow(0, on_screen.x(), on_screen.y(), on_screen.width(), on_screen.height())
                                .toImage();
      const QPoint off = v->mapFromGlobal(on_screen.topLeft());
      long bad = 0;
      for (int y = 0; y < screen.height(); ++y)
        for (int x = 0; x < screen.width(); ++x) {
          const QColor a = screen.pixelColor(x, y), b = frame.pixelColor(x + off.x(), y + off.y());
          if (std::abs(a.red() - b.red()) > 40 || std::abs(a.green() - b.green()) > 40 || std::abs(a.blue() - b.blue()) > 40) ++bad;
        }
      return static_cast<double>(bad) / (static_cast<double>(screen.width()) * screen.height());
    };
    PathView *views[2] = {map, w->View3D()};
    auto quiet = [&] { return !views[0]->FramePending() && !views[1]->FramePending(); };
    QVERIFY(WaitUntil(quiet, 5000));
    QTest::qWait(50);
    const int blue_before = blue_pixels(map->Grab());
    QVERIFY2(blue_before > 200, qPrintable(QString::number(blue_before)));
    w->move(0, 0);
    const QSize start = w->size();
    for (const QSize size : {start - QSize(300, 150), start - QSize(100, 50)}) {
      const QSize before = map->size();
      w->resize(size);
      QVERIFY(WaitUntil([&] { return map->size() != before; }, 5000));
      QVERIFY(WaitUntil(quiet, 5000));
      QTest::qWait(50);
      int compared = 0; // a small screen (the 800x600 fallback) may show only the map
      for (PathView *v : views) {
        const QImage frame = v->Grab();
        QCOMPARE(frame.size(), v->size()); // device pixel ratio 1 under Xvfb
        const double mismatch = screen_mismatch(v, frame);
        if (mismatch < 0.0) continue;
        ++compared;
        QVERIFY2(mismatch < 0.01, qPrintable(QString("%1: %2 of the pixels on screen differ from the view's frame")
                                                 .arg(v->objectName()).arg(mismatch)));
      }
      QVERIFY(compared >= 1);
      const int blue = blue_pixels(map->Grab());
      QVERIFY2(blue > 100, qPrintable(QString("the path on the resized map: %1 blue pixels").arg(blue)));
    }
    Shot(w.get(), "resize-01");
  }

  // Two drag steps in a row: the preview of the first, barely started, is dropped for the second
  // (its estimate would be out of date); the second's estimate is drawn, in one frame.
  void preview_preempt() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(true);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/urban-drive.yaml")); // 513 s: a preview of some length
    studio::SceneDocument *doc = w->Doc();
    auto settled = [&] {
      return !w->PreviewWorker()->IsBusy() && w->LastPreview() && w->LastPreview()->scene_change_ns == doc->LastChangeNs();
    };
    QVERIFY(WaitUntil(settled, 60000));
    QVERIFY(WaitUntil([&] { return !w->PreviewLatenciesMs().empty(); }, 10000));
    // No earlier render's frame still to come.
    QVERIFY(WaitUntil([&] { return !w->MapView()->FramePending() && !w->View3D()->FramePending(); }, 10000));
    w->SetLiveFrameHoldMs(60000);
    for (PathView *v : {w->MapView(), w->View3D()}) v->SetLiveRenderDelay(60000);
    QSignalSpy finished(w->PreviewWorker(), &studio::SimWorker::Finished);
    const size_t n0 = w->PreviewLatenciesMs().size();
    const long f0[2] = {w->MapView()->FrameCount(), w->View3D()->FrameCount()};
    const long r0[2] = {w->MapView()->RenderCount(), w->View3D()->RenderCount()};
    nav_scene e = doc->Scene();
    e.trajectory.waypoints.points[6].r_ned_m.y += 5.0;
    // The first edit's job waits for its cancel: without the hold, a loaded machine could let it
    // finish (40-70 ms) before the second edit arrives.
    w->PreviewWorker()->HoldNextJobForTest();
    doc->Preview(e);
    QVERIFY(w->PreviewWorker()->IsBusy());
    e.trajectory.waypoints.points[6].r_ned_m.y += 5.0;
    doc->Preview(e);
    QVERIFY(WaitUntil(settled, 60000));
    QVERIFY(WaitUntil([&] { return w->PreviewLatenciesMs().size() > n0; }, 10000));
    QCOMPARE(finished.count(), 2);
    const auto first = finished.at(0).at(0).value<std::shared_ptr<const studio::SimResult>>();
    const auto second = finished.at(1).at(0).value<std::shared_ptr<const studio::SimResult>>();
    QCOMPARE(first->status, int(NAV_ERR_CANCELLED));
    QCOMPARE(second->status, int(NAV_OK));
    QCOMPARE(second->scene_change_ns, doc->LastChangeNs());
    QCOMPARE(w->PreviewLatenciesMs().size(), n0 + 1);
    // Each view rendered the second edit's path and estimate once and showed it in one frame.
    QCOMPARE(w->MapView()->RenderCount() - r0[0], 1L);
    QCOMPARE(w->View3D()->RenderCount() - r0[1], 1L);
    QCOMPARE(w->MapView()->FrameCount() - f0[0], 1L);
    QCOMPARE(w->View3D()->FrameCount() - f0[1], 1L);
    QCOMPARE(w->LastPreview()->t_s.size(), second->t_s.size());
    Shot(w.get(), "preempt-01");
  }

  // Map background: at street scale the metric grid; zoomed out, GSHHS coastlines (the Baltic
  // coast north of the Berlin origin) and a labelled lat/lon graticule.
  void map_background() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    PathView *map = w->MapView();
    map->UpdateBackground();
    QVERIFY(map->MetricGridShown());
    QCOMPARE(map->GraticuleCount(), size_t(0));
    QVERIFY(map->GraticuleLabels().isEmpty());
    Shot(w.get(), "map-01-street");
    map->SetMapExtent(0.0, 0.0, 250e3);
    QVERIFY(!map->MetricGridShown());
    QVERIFY2(map->CoastlineCount() > 0, "no coastline in a 500 km view of Berlin");
    QVERIFY(map->GraticuleCount() >= 4);
    const QStringList labels = map->GraticuleLabels();
    QVERIFY2(labels.filter(QRegularExpression("^5[0-5]°N$")).size() >= 2, qPrintable(labels.join(", ")));
    QVERIFY2(labels.filter(QRegularExpression("^1[0-6]°E$")).size() >= 2, qPrintable(labels.join(", ")));
    // The labelled parallels are where the frame puts those latitudes: the label's point maps back.
    const nav_scene &s = w->Doc()->Scene();
    double ned[3];
    studio::GeodeticToLocal(s, 54.0, 13.4, 0.0, ned); // on the Baltic coast (Greifswald)
    QVERIFY(ned[0] > 100e3 && ned[0] < 250e3);
    // Land and water filled from GSHHG (issue 19): Berlin is land, the Baltic north of Usedom and
    // the Mueritz lake are water.
    QVERIFY(map->LandResolution() != 0);
    const long land = 0xf2eede, water = 0xaaccE8;
    QCOMPARE(map->LandColourAt(0.0, 0.0), land);
    studio::GeodeticToLocal(s, 54.2, 14.25, 0.0, ned);
    QCOMPARE(map->LandColourAt(ned[1], ned[0]), water);
    studio::GeodeticToLocal(s, 53.43, 12.69, 0.0, ned);
    QCOMPARE(map->LandColourAt(ned[1], ned[0]), water);
    Shot(w.get(), "map-02-regional");
    // Continental scale, then back to street scale: the grid returns, the graticule goes.
    map->SetMapExtent(0.0, 0.0, 2000e3);
    QVERIFY(map->CoastlineCount() > 10);
    Shot(w.get(), "map-03-continental");
    map->SetMapExtent(0.0, 0.0, 400.0);
    QCOMPARE(map->LandColourAt(0.0, 0.0), land); // the fill at street scale too
    QVERIFY(map->MetricGridShown());
    QCOMPARE(map->GraticuleCount(), size_t(0));
    QCOMPARE(map->CoastlineCount(), size_t(0));
  }

private:
  QTemporaryDir tmp_;
};

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navstudio-test");
  QApplication::setApplicationName("navstudio-test");
  TestNavstudio t;
  return QTest::qExec(&t, argc, argv);
}

#include "test_navstudio.moc"
