// navstudio's map tile layer (issue 19 item 2): View > Map tiles... takes an MBTiles file the test
// makes (viewer/tests/tile_fixture.h, around the new drive's origin in Berlin), refuses a corrupt
// one with the reason, remembers the choice in QSettings for the next window, draws the tiles'
// colours and streets where their lat/lon fall in the map view, credits them in the caption, and
// shows the GSHHG fill again when zoomed out beyond the tiles. Also the map view's place names
// (navview's placement) and its zoom about the pointer (issue 19 item 2). Screenshots:
// Testing/navstudio/tiles-*.png, map-places-*.png.
#include <QApplication>
#include <QDialog>
#include <QDialogButtonBox>
#include <QLineEdit>
#include <QPushButton>
#include <QSettings>
#include <QSurfaceFormat>
#include <QTemporaryDir>
#include <QTest>
#include <QTimer>

#include <QVTKOpenGLStereoWidget.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include <vtkCommand.h>
#include <vtkRenderWindowInteractor.h>

#include "main_window.h"
#include "navview/nav_map_tiles.h"
#include "path_view.h"
#include "studio_scene.h"
#include "studio_test_support.h"
#include "tile_fixture.h"

using namespace studio_test;
using studio::PathView;

namespace {

long Rgb(const unsigned char c[3]) {
  return (long(c[0]) << 16) | (long(c[1]) << 8) | long(c[2]);
}

/** Local East, North [m] of @p lat, @p lon in the window's scene. */
void EastNorth(studio::MainWindow *w, double lat, double lon, double *e, double *n) {
  double ned[3];
  studio::GeodeticToLocal(w->Doc()->Scene(), lat, lon, 0.0, ned);
  *n = ned[0];
  *e = ned[1];
}

} // namespace

class TestNavstudioTiles : public QObject {
  Q_OBJECT
private slots:
  void map_tiles() {
    QSettings().remove("map");
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    PathView *map = w->MapView();
    double lat = 0, lon = 0, h = 0;
    const double zero[3] = {0, 0, 0};
    studio::LocalToGeodetic(w->Doc()->Scene(), zero, &lat, &lon, &h);
    const std::string dir = tmp_.path().toStdString() + "/tiles";
    std::string err;
    QVERIFY2(tilefix::MakeTiles(dir, lat, lon, 14, 16, 1500.0, &err) > 0, err.c_str());

    // A corrupt file is refused with its reason; nothing changes.
    const QString bad = tmp_.path() + "/bad.mbtiles";
    std::ofstream(bad.toStdString()) << "not a database\n";
    QString why;
    QVERIFY(!w->SetMapTiles(bad, QString(), &why));
    QVERIFY2(why.contains("not an MBTiles file"), qPrintable(why));
    QVERIFY(w->MapTiles().isEmpty());

    const QString mb = QString::fromStdString(dir + "/tiles.mbtiles");
    QVERIFY2(w->SetMapTiles(mb, QString(), &why), qPrintable(why));
    QCOMPARE(QSettings().value("map/tiles").toString(), mb);
    map->SetMapExtent(0.0, 0.0, 400.0); // street scale
    const int zoom = map->MapTileZoom();
    QVERIFY2(zoom >= 14 && zoom <= 16, qPrintable(QString::number(zoom)));
    QCOMPARE(map->MapTilesCredit(), QString("map tiles: ") + QString::fromUtf8(tilefix::kAttributionText));
    QVERIFY2(map->CaptionText().contains(map->MapTilesCredit()), qPrintable(map->CaptionText()));
    // The tile under the origin: its colour a quarter in, its streets' crossing dark.
    double fx, fy;
    tilefix::TileXY(lat, lon, zoom, &fx, &fy);
    const int tx = static_cast<int>(fx), ty = static_cast<int>(fy);
    double qlat, qlon, clat, clon, e, n;
    tilefix::TileLatLon(tx + 0.25, ty + 0.25, zoom, &qlat, &qlon);
    tilefix::TileLatLon(tx + 0.5, ty + 0.5, zoom, &clat, &clon);
    unsigned char want[3];
    tilefix::TileRgb(zoom, tx, ty, want);
    EastNorth(w.get(), qlat, qlon, &e, &n);
    QCOMPARE(map->LandColourAt(e, n), Rgb(want));
    EastNorth(w.get(), clat, clon, &e, &n);
    const long street = map->LandColourAt(e, n);
    QVERIFY2(((street >> 16) & 255) < 70 && ((street >> 8) & 255) < 70 && (street & 255) < 70,
             qPrintable(QString::number(street, 16)));
    Shot(w.get(), "tiles-01-street");

    // Zoomed out beyond the tiles' levels: the GSHHG fill (Berlin is land), no credit.
    map->SetMapExtent(0.0, 0.0, 30e3);
    QCOMPARE(map->MapTileZoom(), -1);
    QCOMPARE(map->LandColourAt(0.0, 0.0), 0xf2eedeL);
    QVERIFY(map->MapTilesCredit().isEmpty());
    Shot(w.get(), "tiles-02-zoomed-out");

    // A new window remembers the choice.
    map->SetMapExtent(0.0, 0.0, 400.0);
    w.reset();
    auto w2 = MakeWindow();
    QVERIFY(w2);
    QCOMPARE(w2->MapTiles(), mb);

    // View > Map tiles...: the dialog with the source; emptied and accepted, the tiles go.
    bool seen = false;
    QTimer::singleShot(200, this, [&] {
      for (QWidget *tw : QApplication::topLevelWidgets()) {
        auto *d = qobject_cast<QDialog *>(tw);
        if (!d || d->objectName() != "mapTilesDialog") continue;
        auto *src = d->findChild<QLineEdit *>("mapTilesSource");
        seen = src && src->text() == mb;
        if (src) src->clear();
        d->findChild<QDialogButtonBox *>()->button(QDialogButtonBox::Ok)->click();
      }
    });
    w2->EditMapTiles();
    QVERIFY(seen);
    QVERIFY(w2->MapTiles().isEmpty());
    QVERIFY(QSettings().value("map/tiles").toString().isEmpty());
  }

  // Place names as on navview's map (GeoNames: Berlin and its neighbours at 60 km), none over
  // another; the wheel zooms about the pointer: the ground point under it stays under it.
  void map_places_zoom() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    PathView *map = w->MapView();
    map->SetMapExtent(0.0, 0.0, 30e3);
    const QStringList names = map->PlaceNames();
    QVERIFY2(names.contains("Berlin"), qPrintable(names.join(", ")));
    QVERIFY2(names.contains("Potsdam"), qPrintable(names.join(", ")));
    QVERIFY2(map->CaptionText().contains("GeoNames (CC BY 4.0)"), qPrintable(map->CaptionText()));
    Shot(w.get(), "map-places-01-60km");
    // Street scale in the middle of Berlin: fewer, local names or none, never a crash.
    map->SetMapExtent(0.0, 0.0, 400.0);
    Shot(w.get(), "map-places-02-street");
    map->SetMapExtent(0.0, 0.0, 30e3);

    // A point off the centre: what lies under it before and after a wheel step.
    int x = 0, y = 0;
    QVERIFY(map->DisplayOf(9000.0, -12000.0, 0.0, &x, &y));
    double n0 = 0, e0 = 0, n1 = 0, e1 = 0;
    QVERIFY(map->GroundAt(x, y, 0.0, &n0, &e0));
    vtkRenderWindowInteractor *i = map->Interactor();
    i->SetEventPosition(x, y);
    i->InvokeEvent(vtkCommand::MouseWheelForwardEvent);
    QApplication::processEvents();
    QVERIFY(map->GroundAt(x, y, 0.0, &n1, &e1));
    const double m_px = 60e3 / 1.25 / std::max(1, map->height());
    std::printf("wheel at (%d, %d): ground point (%.1f, %.1f) m -> (%.1f, %.1f) m\n", x, y, n0, e0, n1, e1);
    QVERIFY2(std::hypot(n1 - n0, e1 - e0) < 2.0 * m_px, "the point under the pointer moved");
    // And in: 1.25 x closer each step, so 10 steps bring 60 km down to 6.4 km, about the pointer.
    for (int k = 0; k < 10; ++k)
      i->InvokeEvent(vtkCommand::MouseWheelForwardEvent);
    QApplication::processEvents();
    QVERIFY(map->GroundAt(x, y, 0.0, &n1, &e1));
    QVERIFY2(std::hypot(n1 - n0, e1 - e0) < 20.0, "the point under the pointer moved");
    QVERIFY(map->MetricGridShown()); // street scale: the map was rebuilt for the new view
    Shot(w.get(), "map-places-03-zoomed-about-pointer");
  }

private:
  QTemporaryDir tmp_;
};

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navstudio-test");
  QApplication::setApplicationName("navstudio-test");
  TestNavstudioTiles t;
  return QTest::qExec(&t, argc, argv);
}

#include "test_navstudio_tiles.moc"
