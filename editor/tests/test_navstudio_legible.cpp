// navstudio GUI tests (QTest under Xvfb) of issue 19's "legible pictures" and "smaller defects":
// the 3D view's legend in a narrow view, the estimate drawn over the outage band, the Errors tab
// with libnavview's chart set, outages on the profile, F5 with fewer than two waypoints, Issues
// messages without a repeated prefix, the receiver's whole name, datasheet values at three
// significant digits, the file dialogs' folder, exports confirmed in the status bar, the
// "(scene values)" receiver's noise fields and undo marking results out of date. Screenshots go
// to NAVSTUDIO_TEST_OUT_DIR/legible-*.png.
#include <QAction>
#include <QComboBox>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QMouseEvent>
#include <QListWidget>
#include <QPushButton>
#include <QStandardPaths>
#include <QStatusBar>
#include <QSurfaceFormat>
#include <QTabWidget>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>
#include <QVTKOpenGLStereoWidget.h>

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "main_window.h"
#include "playback.h"
#include "navview/nav_view_chart.h"
#include "navview/nav_view_result.h"
#include "navview/nav_view_scene.h"
#include "studio_test_support.h"

using studio::MainWindow;
using namespace studio_test;

namespace {

void ClickMap(studio::PathView *v, double n, double e) {
  int x = 0, y = 0;
  QVERIFY2(v->DisplayOf(n, e, 0.0, &x, &y), "target outside the map view");
  vtkRenderWindowInteractor *i = v->Interactor();
  i->SetEventInformation(x, y, 0, 0);
  i->InvokeEvent(vtkCommand::MouseMoveEvent);
  i->InvokeEvent(vtkCommand::LeftButtonPressEvent);
  i->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
  QApplication::processEvents();
}

bool RunAndWait(MainWindow *w, int timeout_ms) {
  w->findChild<QAction *>("actionRun")->trigger(); // F5
  if (!w->Worker()->IsBusy()) return false;
  return WaitUntil([&] { return !w->Worker()->IsBusy(); }, timeout_ms);
}

/** Pixels of @p img within @p tol (per channel) of @p rgb. */
long CountColour(const QImage &img, int r, int g, int b, int tol) {
  long n = 0;
  const QImage im = img.convertToFormat(QImage::Format_RGB32);
  for (int y = 0; y < im.height(); ++y) {
    const QRgb *row = reinterpret_cast<const QRgb *>(im.constScanLine(y));
    for (int x = 0; x < im.width(); ++x)
      if (std::abs(qRed(row[x]) - r) <= tol && std::abs(qGreen(row[x]) - g) <= tol &&
          std::abs(qBlue(row[x]) - b) <= tol)
        ++n;
  }
  return n;
}

/** Answer the next file dialog: note its folder, then accept @p file (empty: cancel). */
void AnswerFileDialog(QString *dir_seen, const QString &file) {
  QTimer::singleShot(300, [dir_seen, file] {
    auto *d = qobject_cast<QFileDialog *>(QApplication::activeModalWidget());
    if (!d) {
      AnswerFileDialog(dir_seen, file); // not open yet
      return;
    }
    *dir_seen = d->directory().absolutePath();
    if (file.isEmpty()) {
      d->reject();
    } else {
      d->selectFile(file);
      QMetaObject::invokeMethod(d, "accept", Qt::QueuedConnection); // as the Save button does
    }
  });
}

/** The urban drive (two outages, two horizontal requirements) at @p runs runs. */
bool OpenUrbanDrive(MainWindow *w, int runs) {
  if (!w->OpenFile(QStringLiteral(NAVSTUDIO_SOURCE_DIR "/scenes/urban-drive.yaml"))) return false;
  w->Doc()->Edit("runs", [runs](nav_scene &s) { s.simulation.runs = runs; });
  return true;
}

} // namespace

class TestLegible : public QObject {
  Q_OBJECT
private slots:
  // The 3D view beside the map is narrow (about 440 px): its legend took about 40 % of it. It is
  // at most 26 % now, in a font scaled with the view, entries in their short forms.
  void legend_narrow_view() {
    auto w = MakeWindow();
    QVERIFY(w);
    QVERIFY(w->NewDrive());
    w->SetLivePreview(true);
    for (auto &p : kDrive)
      ClickMap(w->MapView(), p[0], p[1]);
    QVERIFY(
        WaitUntil([&] { return w->View3D()->Scene() != nullptr && w->View3D()->Scene()->IsBuilt(); }, 60000));
    QTest::qWait(200);
    NavSceneView *sc = w->View3D()->Scene();
    const int vw = w->View3D()->width();
    qInfo("3D view %d x %d px: legend %.1f %% of the width, font %d px, compact %d", vw,
          w->View3D()->height(), 100.0 * sc->LegendPanelFraction(), sc->LegendFontPx(), sc->LegendCompact());
    QVERIFY2(vw < 700, "the 3D view is expected narrow in the default layout");
    QVERIFY(sc->LegendPanelFraction() > 0.0);
    QVERIFY2(sc->LegendPanelFraction() <= 0.26 + 1e-9,
             qPrintable(QString::number(sc->LegendPanelFraction())));
    QVERIFY(sc->LegendCompact());
    QVERIFY(sc->LegendFontPx() >= 8);
    QVERIFY(sc->LegendText().find("estimate (run 0)") != std::string::npos);
    // The map's legend names what it draws, in the colours of the 3D scene: plan black under the
    // estimate red (the live preview's orange and the plan's blue are gone).
    const QStringList map_legend = w->MapView()->LegendEntries();
    qInfo("map legend: %s", qPrintable(map_legend.join(" | ")));
    QVERIFY(map_legend.contains("plan (reference path)"));
    QVERIFY(map_legend.contains("estimate (live preview)"));
    const QImage map_img = w->MapView()->Grab();
    const long red = CountColour(map_img, 214, 26, 28, 40), orange = CountColour(map_img, 242, 140, 13, 30),
               blue = CountColour(map_img, 26, 89, 217, 30);
    qInfo("map pixels: estimate red %ld, old preview orange %ld, old plan blue %ld", red, orange, blue);
    QVERIFY(red > 100);
    QVERIFY(orange == 0 && blue == 0);
    Shot(w.get(), "legible-01-legend-narrow");
    QVERIFY(w->View3D()->Grab().save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/legible-01-view3d.png")));

    // A wide picture keeps the full legend (File > Export picture at 1920 x 1080).
    NavSceneView wide;
    NavViewOptions o = sc->GetOptions();
    o.width_px = 1920;
    o.height_px = 1080;
    o.time_s = NAN;
    wide.SetResult(w->View3D()->SceneResult());
    wide.SetOptions(o);
    std::string err;
    QVERIFY2(wide.RenderPng(NAVSTUDIO_TEST_OUT_DIR "/legible-02-wide.png", &err), err.c_str());
    qInfo("1920 x 1080: legend %.1f %%, font %d px, compact %d", 100.0 * wide.LegendPanelFraction(),
          wide.LegendFontPx(), wide.LegendCompact());
    QVERIFY(!wide.LegendCompact());
    QVERIFY(wide.LegendPanelFraction() <= 0.26 + 1e-9);
  }

  // The estimate is drawn over the outage band (the band hid the estimate where it lay behind
  // the reference): as many estimate pixels with the band as without it.
  void estimate_over_outage() {
    auto with = std::make_shared<NavResult>();
    std::string err;
    QVERIFY2(NavLoadResultDir(NAVSTUDIO_SOURCE_DIR "/viewer/tests/data/tiny-gnss", with.get(), &err),
             err.c_str());
    QVERIFY(!with->gnss.outage_t0_s.empty());
    auto without = std::make_shared<NavResult>(*with);
    without->gnss.outage_t0_s.clear();
    without->gnss.outage_t1_s.clear();
    long count[2] = {0, 0};
    for (int k = 0; k < 2; ++k) {
      NavViewOptions o;
      o.width_px = 480;
      o.height_px = 360;
      o.show_text = false;
      o.show_triads = false;
      o.show_vehicle = false;
      o.show_gnss = true;
      o.ellipsoid_count = 0;
      o.envelope_source = NavEnvelopeSource::None;
      o.att_exaggeration = 1.0;
      // Low over the figure eight from the south-west: the band lies in front of parts of the estimate.
      o.fixed_camera = true;
      const double pos[3] = {-60.0, -150.0, 40.0}, foc[3] = {0.0, -10.0, -8.0}, up[3] = {0.0, 0.0, 1.0};
      for (int i = 0; i < 3; ++i) {
        o.camera_position_r[i] = pos[i];
        o.camera_focal_r[i] = foc[i];
        o.camera_view_up_r[i] = up[i];
      }
      o.camera_view_angle_deg = 30.0;
      NavSceneView v;
      v.SetResult(k == 0 ? with : without);
      v.SetOptions(o);
      const QString png =
          QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/legible-03-outage-%1.png").arg(k == 0 ? "band" : "none");
      QVERIFY2(v.RenderPng(png.toStdString(), &err), err.c_str());
      QImage img(png);
      QVERIFY(!img.isNull());
      // The estimate's red (libnavview kEstColor 0.84, 0.10, 0.11).
      count[k] = CountColour(img, 214, 26, 28, 40);
    }
    qInfo("estimate pixels: %ld with the outage band, %ld without", count[0], count[1]);
    QVERIFY(count[1] > 200);
    QVERIFY2(count[0] >= 0.97 * count[1], "the outage band hides part of the estimate");
  }

  // The Errors tab carries libnavview's chart set: drawn at the tab's width, four panels high
  // at least, the outages shaded, two FAIL limits of one panel in different patterns.
  void errors_tab_charts() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->FitToScreen();
    w->SetLivePreview(false);
    QVERIFY(OpenUrbanDrive(w.get(), 4));
    QVERIFY(RunAndWait(w.get(), 600000));
    auto r = w->LastResult();
    QVERIFY(r && r->status == NAV_OK);
    QCOMPARE(r->err_vel_mps.size(), r->t_s.size());
    auto *tabs = w->findChild<QTabWidget *>("bottomTabs");
    auto *chart = w->findChild<studio::ErrorChart *>("errorChart");
    QVERIFY(tabs && chart);
    tabs->setCurrentWidget(chart);
    QTest::qWait(300);
    const QImage pic = chart->Picture();
    QVERIFY2(!pic.isNull(), qPrintable(chart->Message()));
    qInfo("Errors tab picture %d x %d (viewport %d px wide)", pic.width(), pic.height(),
          chart->viewport()->width());
    QVERIFY(pic.height() >= studio::kMinChartHeightPx);
    QVERIFY(std::abs(pic.width() - chart->viewport()->width()) <= 2 || pic.width() == 320);
    QVERIFY(pic.save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/legible-04-errors-tab.png")));
    // The outage spans: the pink at 22 % over white.
    const long tint = CountColour(pic, 250, 227, 243, 6);
    qInfo("outage tint pixels: %ld", tint);
    QVERIFY(tint > 1000);
    // The same chart as laid out (issue 19): with the urban drive's two outages each legend lies
    // outside every plot area (it covered the second outage's peak), and its two horizontal
    // requirements get different dash patterns (both FAIL limits shared one style).
    const std::shared_ptr<NavResult> nr = studio::ToNavResult(*r, w->Doc()->Scene());
    QCOMPARE(static_cast<int>(nr->gnss.outage_t0_s.size()), 2);
    NavChartOptions co;
    co.width_px = pic.width();
    co.height_px = pic.height();
    std::vector<unsigned char> rgb;
    NavErrorChartLayout lay;
    std::string chart_err;
    QVERIFY2(NavRenderErrorChartRgb(*nr, co, &rgb, &lay, &chart_err), chart_err.c_str());
    QVERIFY(lay.plots.size() >= 4 && lay.legends.size() == lay.plots.size());
    for (size_t i = 0; i < lay.legends.size(); ++i) {
      const NavChartRect &l = lay.legends[i];
      qInfo("%s: legend x %.0f..%.0f y %.0f..%.0f, plot x %.0f..%.0f", lay.titles[i].c_str(), l.x, l.x + l.w, l.y,
            l.y + l.h, lay.plots[i].x, lay.plots[i].x + lay.plots[i].w);
      QVERIFY(l.w > 0 && l.h > 0);
      for (const NavChartRect &p : lay.plots)
        QVERIFY(!l.Intersects(p));
    }
    QCOMPARE(static_cast<int>(lay.limit_pens[0].size()), 2);
    QVERIFY(lay.limit_pens[0][0] != lay.limit_pens[0][1]);
    Shot(w.get(), "legible-04-errors-window");
  }

  // The profile chart shades the GNSS outages over the time axis.
  void profile_outages() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(OpenUrbanDrive(w.get(), 1));
    studio::ProfileChart *pc = w->Profile();
    QVERIFY(pc->Profile().Size() > 2);
    pc->repaint();
    QApplication::processEvents();
    const QVector<QRectF> spans = pc->OutageRects();
    QCOMPARE(spans.size(), 2);
    // On the map too: a pink band along the plan for each, named in its legend.
    QCOMPARE(w->MapView()->OutageSpanCount(), 2);
    QVERIFY(w->MapView()->LegendEntries().contains("GNSS outage"));
    const QImage img = pc->grab().toImage();
    QVERIFY(img.save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/legible-05-profile.png")));
    for (const QRectF &s : spans) {
      // Most of the span is tinted (the curves and limit lines cross it).
      long tinted = 0, all = 0;
      for (int y = static_cast<int>(s.top()) + 2; y < static_cast<int>(s.bottom()) - 2; y += 3)
        for (int x = static_cast<int>(s.left()) + 2; x < static_cast<int>(s.right()) - 2; x += 3) {
          const QColor c = img.pixelColor(x, y);
          ++all;
          if (std::abs(c.red() - studio::kOutageTint.red()) <= 4 &&
              std::abs(c.green() - studio::kOutageTint.green()) <= 4 &&
              std::abs(c.blue() - studio::kOutageTint.blue()) <= 4)
            ++tinted;
        }
      qInfo("span %.0f..%.0f px: %ld of %ld samples tinted", s.left(), s.right(), tinted, all);
      QVERIFY(all > 50 && tinted > 0.6 * all);
    }
    // Wider apart in the picture as in time: 150-210 s and 330-390 s of a 513 s drive.
    const double t1 = pc->Profile().t_s.back();
    const double px_per_s = spans[0].width() / 60.0;
    QVERIFY(std::fabs((spans[1].left() - spans[0].left()) / px_per_s - 180.0) < 3.0);
    QVERIFY(t1 > 390.0);

    // A drag across the time axis adds an outage over the dragged span (one undo step).
    const int undo = w->Doc()->UndoStack()->count();
    const int xa = static_cast<int>(std::lround(pc->XAtTime(240.0))),
              xb = static_cast<int>(std::lround(pc->XAtTime(300.0)));
    const int y = pc->height() / 2;
    QTest::mousePress(pc, Qt::LeftButton, Qt::NoModifier, QPoint(xa, y));
    for (int k = 1; k <= 6; ++k) {
      QMouseEvent move(QEvent::MouseMove, QPointF(xa + (xb - xa) * k / 6.0, y), Qt::LeftButton,
                       Qt::LeftButton, Qt::NoModifier);
      QApplication::sendEvent(pc, &move);
    }
    QTest::mouseRelease(pc, Qt::LeftButton, Qt::NoModifier, QPoint(xb, y));
    QCOMPARE(w->Doc()->UndoStack()->count(), undo + 1);
    const nav_gnss_model_config &g = w->Doc()->Scene().gnss.model;
    QCOMPARE(static_cast<int>(g.outage_count), 3);
    const double s_per_px = 60.0 / (xb - xa);
    qInfo("dragged outage %.1f-%.1f s (%.2f s per pixel)", g.outages[2].t0_s, g.outages[2].t1_s, s_per_px);
    QVERIFY(std::fabs(g.outages[2].t0_s - 240.0) <= s_per_px + 0.05);
    QVERIFY(std::fabs(g.outages[2].t1_s - 300.0) <= s_per_px + 0.05);
    pc->repaint();
    QCOMPARE(pc->OutageRects().size(), 3);
    QVERIFY(pc->grab().save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/legible-05-profile-dragged.png")));
    // A click is no outage.
    QTest::mouseClick(pc, Qt::LeftButton, Qt::NoModifier, QPoint(xa, y));
    QCOMPARE(static_cast<int>(w->Doc()->Scene().gnss.model.outage_count), 3);
  }

  // F5 with fewer than two waypoints says why (status bar and the Issues tab), and no Issues
  // message repeats its prefix.
  void f5_few_waypoints() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    ClickMap(w->MapView(), kDrive[0][0], kDrive[0][1]);
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.count, 1);
    w->findChild<QAction *>("actionRun")->trigger();
    QVERIFY(!w->Worker()->IsBusy());
    const QString status = w->findChild<QLabel *>("statusText")->text();
    qInfo("status: %s", qPrintable(status));
    QVERIFY(status.contains("Cannot run"));
    QVERIFY(status.contains("waypoints (got 1)"));
    auto *tabs = w->findChild<QTabWidget *>("bottomTabs");
    auto *issues = w->findChild<QListWidget *>("issuesList");
    QCOMPARE(tabs->currentWidget(), static_cast<QWidget *>(issues));
    QVERIFY(issues->count() >= 1);
    for (int i = 0; i < issues->count(); ++i) {
      const QString t = issues->item(i)->text();
      qInfo("issue: %s", qPrintable(t));
      const int colon = t.indexOf(": ");
      QVERIFY(colon > 0);
      const QString prefix = t.left(colon);
      QVERIFY2(!t.mid(colon + 2).startsWith(prefix), qPrintable("repeated prefix: " + t));
    }
    Shot(w.get(), "legible-06-f5-one-waypoint");
    // navcore's planner messages carry their own path: not prefixed again.
    const studio::Issue own{"trajectory.waypoints", "trajectory.waypoints[2]: turn too tight"};
    QCOMPARE(own.Text(), QString("trajectory.waypoints[2]: turn too tight"));
    const studio::Issue plain{"imu.rate_hz", "must be positive"};
    QCOMPARE(plain.Text(), QString("imu.rate_hz: must be positive"));
  }

  // Datasheet terms at three significant digits ("16.2 deg/h", not "16.19789203"); leaving such
  // a field unchanged is no edit (the scene keeps the full value).
  void datasheet_digits() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    Choose(w->findChild<QComboBox *>("imuCatalog"), "ADIS16465");
    w->Panels()->setCurrentIndex(1);
    QApplication::processEvents();
    int checked = 0;
    for (const char *name : {"imu.gyro.arw", "imu.gyro.bias_gm_sigma", "imu.gyro.bias_turn_on",
                             "imu.accel.vrw", "imu.accel.bias_gm_sigma"}) {
      auto *e = w->findChild<QLineEdit *>(name);
      QVERIFY2(e, name);
      const QString t = e->text();
      if (t.isEmpty()) continue;
      QString digits = t;
      digits.remove('-').remove('.');
      while (digits.startsWith('0'))
        digits.remove(0, 1);
      qInfo("%s = %s", name, qPrintable(t));
      QVERIFY2(!t.contains('e') && digits.size() <= 3, qPrintable(QString("%1 = %2").arg(name, t)));
      ++checked;
      const int undo = w->Doc()->UndoStack()->count();
      const nav_scene before = w->Doc()->Scene();
      e->setFocus();
      QTest::keyClick(e, Qt::Key_Return); // editingFinished with the rounded text
      QCOMPARE(w->Doc()->UndoStack()->count(), undo);
      QVERIFY(std::memcmp(&before, &w->Doc()->Scene(), sizeof before) == 0);
    }
    QVERIFY(checked >= 3);
    Shot(w.get(), "legible-07-datasheet");
  }

  // The "(scene values)" receiver shows its noise fields, which edit the scene's receiver; the
  // receiver combo shows the chosen name whole.
  void receiver_fields() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    w->Panels()->setCurrentIndex(2);
    auto *rx = w->findChild<QComboBox *>("gnssReceiver");
    QVERIFY(rx);
    // The longest catalog name, chosen: drawn whole in the combo.
    int longest = 1;
    for (int i = 1; i < rx->count(); ++i)
      if (rx->itemText(i).size() > rx->itemText(longest).size()) longest = i;
    Choose(rx, rx->itemText(longest), Qt::MatchExactly);
    QApplication::processEvents();
    const int need = rx->fontMetrics().horizontalAdvance(rx->itemText(longest));
    qInfo("receiver '%s': text %d px, combo %d px", qPrintable(rx->itemText(longest)), need, rx->width());
    QVERIFY2(rx->width() >= need + 24, "the receiver's name is cut off");
    auto *h = w->findChild<QLineEdit *>("gnss.position_sigma.horizontal");
    auto *v = w->findChild<QLineEdit *>("gnss.position_sigma.vertical");
    auto *vel = w->findChild<QLineEdit *>("gnss.velocity_sigma");
    QVERIFY(h && v && vel);
    QVERIFY(h->isVisibleTo(w.get()) && v->isVisibleTo(w.get()));
    Shot(w.get(), "legible-08-receiver-catalog");
    // "(scene values)": the fields stay, and edit the scene's noise.
    const nav_vec3 catalog_sd = w->Doc()->Scene().gnss.model.pos_gm_sd_m;
    Choose(rx, "(scene values)", Qt::MatchExactly);
    QCOMPARE(rx->currentText(), QString("(scene values)"));
    QCOMPARE(w->Doc()->Scene().gnss.catalog[0], '\0');
    QCOMPARE(w->Doc()->Scene().gnss.model.pos_gm_sd_m.x, catalog_sd.x); // the values stay
    QVERIFY(!h->text().isEmpty());
    TypeInto(h, "2.5");
    TypeInto(v, "4");
    const nav_gnss_model_config &g = w->Doc()->Scene().gnss.model;
    QCOMPARE(g.pos_gm_sd_m.x, 2.5);
    QCOMPARE(g.pos_gm_sd_m.y, 2.5);
    QCOMPARE(g.pos_gm_sd_m.z, 4.0);
    QVERIFY(g.terms & NAV_GNSS_TERM_POS_GM);
    QCOMPARE(h->text(), QString("2.5"));
    Shot(w.get(), "legible-09-receiver-scene-values");
  }

  // Save and export dialogs open in the user's documents folder (no scene file) or the scene's
  // folder, not in the directory navstudio was started from; an export is confirmed in the
  // status bar.
  void dialogs_and_exports() {
    QVERIFY(QDir::setCurrent(NAVSTUDIO_SOURCE_DIR)); // as when started from the repository
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    const QString docs = w->DialogDir();
    qInfo("dialog folder without a scene file: %s", qPrintable(docs));
    QVERIFY(QFileInfo(docs).canonicalFilePath() != QFileInfo(NAVSTUDIO_SOURCE_DIR).canonicalFilePath());
    const QString want = QStandardPaths::writableLocation(QStandardPaths::DocumentsLocation);
    QVERIFY(docs == want || docs == QDir::homePath());

    QTemporaryDir tmp;
    QVERIFY(tmp.isValid());
    const QString shot = tmp.filePath("navstudio.png");
    QString seen;
    AnswerFileDialog(&seen, shot);
    w->findChild<QAction *>("actionScreenshot")->trigger();
    qInfo("dialog opened in %s; status bar: %s", qPrintable(seen),
          qPrintable(w->statusBar()->currentMessage()));
    QVERIFY(QFileInfo(shot).size() > 1000);
    QCOMPARE(QFileInfo(seen).canonicalFilePath(), QFileInfo(docs).canonicalFilePath());
    const QString msg = w->statusBar()->currentMessage();
    qInfo("status bar: %s", qPrintable(msg));
    QVERIFY(msg.contains("Screenshot written to") && msg.contains(shot));

    // With a scene file: its folder.
    const QString scene = tmp.filePath("drive.yaml");
    QVERIFY(QFile::copy(NAVSTUDIO_SOURCE_DIR "/scenes/urban-drive.yaml", scene));
    QVERIFY(w->OpenFile(scene));
    QCOMPARE(w->DialogDir(), QFileInfo(scene).absolutePath());
    AnswerFileDialog(&seen, QString()); // cancel
    w->findChild<QAction *>("actionScreenshot")->trigger();
    QCOMPARE(QFileInfo(seen).canonicalFilePath(), QFileInfo(tmp.path()).canonicalFilePath());
  }

  // The error band at a corner sharper than its half-width is one clean region: one colour, no
  // darker folds (a strip of offset points folded over itself there, translucent).
  void band_clean_region() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    studio::PathView *map = w->MapView();
    map->SetMapExtent(0.0, 0.0, 320.0);
    // An L: east along n = 0, then a right-angle turn north; 80 m half-width, points every 5 m.
    std::vector<double> ned, half;
    for (double e = -220.0; e <= 0.0; e += 5.0)
      ned.insert(ned.end(), {0.0, e, 0.0});
    for (double n = 5.0; n <= 220.0; n += 5.0)
      ned.insert(ned.end(), {n, 0.0, 0.0});
    half.assign(ned.size() / 3, 80.0);
    map->SetEnvelope(ned, half, false);
    QCOMPARE(map->EnvelopePointCount(), 2 * half.size());
    map->Render();
    QTest::qWait(300);
    const QImage img = map->Grab();
    QVERIFY(img.save(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR "/legible-11-band-corner.png")));
    // The band's pixels: bluish. One shade (the fill) but for antialiased edges.
    long fill = 0, other = 0;
    const QImage im = img.convertToFormat(QImage::Format_RGB32);
    for (int y = 0; y < im.height(); ++y)
      for (int x = 0; x < im.width(); ++x) {
        const QRgb c = im.pixel(x, y);
        const int r = qRed(c), g = qGreen(c), b = qBlue(c);
        if (!(b > r + 15 && b >= g)) continue;
        if (std::abs(r - 204) <= 4 && std::abs(g - 219) <= 4 && std::abs(b - 247) <= 4)
          ++fill;
        else if (r + g + b < 204 + 219 + 247 - 24)
          ++other;
      }
    qInfo("band pixels: %ld of the fill colour, %ld darker (folds, lines through the band)", fill, other);
    QVERIFY(fill > 5000);
    QVERIFY2(other < fill / 100, "the band is not one clean region");
  }

  // Undo after a run marks the results out of date (they stay, greyed) until the next run.
  void undo_marks_stale() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(true);
    QVERIFY(w->NewDrive());
    for (auto &p : kDrive)
      ClickMap(w->MapView(), p[0], p[1]);
    TypeInto(w->findChild<QLineEdit *>("simulation.runs"), "2");
    QVERIFY(WaitUntil([&] { return w->LastPreview() && !w->PreviewWorker()->IsBusy(); }, 60000));
    QVERIFY(w->MapView()->LegendEntries().contains("estimate (live preview)"));
    QVERIFY(RunAndWait(w.get(), 300000));
    QVERIFY(!w->ResultsStale());
    // One estimate in the map: the run's, the preview's gone.
    const QStringList legend = w->MapView()->LegendEntries();
    QVERIFY(legend.contains("estimate (Monte Carlo run 0)"));
    QVERIFY(!legend.contains("estimate (live preview)"));
    w->findChild<QAction *>("actionUndo")->trigger(); // the runs edit
    QVERIFY(w->ResultsStale());
    auto *tabs = w->findChild<QTabWidget *>("bottomTabs");
    QVERIFY(tabs->tabText(0).contains("out of date"));
    QVERIFY(tabs->tabText(1).contains("out of date"));
    QVERIFY(w->ResultsText().contains("Out of date"));
    Shot(w.get(), "legible-10-undo-stale");
    // New drive: no estimate or band of the old drive is left in either view.
    QVERIFY(w->MapView()->EnvelopePointCount() > 0);
    QVERIFY(w->NewDrive());
    for (studio::PathView *v : {w->MapView(), w->View3D()}) {
      QCOMPARE(v->EnvelopePointCount(), size_t{0});
      QVERIFY(!v->LegendEntries().join(" ").contains("estimate"));
    }
  }
};

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navstudio-test");
  QApplication::setApplicationName("navstudio-test");
  TestLegible t;
  return QTest::qExec(&t, argc, argv);
}

#include "test_navstudio_legible.moc"
