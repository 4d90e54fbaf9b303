// navstudio GUI tests of trajectory editing (QTest under Xvfb): the segment-script editor (edit,
// add/insert/delete/reorder, validation messages of `navsim check`, undo), the parametric form
// (live debounced preview, unit selector, undo), comments kept by a save of an opened file, and
// Shift+drag of a waypoint's height in the 3D view. Screenshots of the main window go to
// NAVSTUDIO_TEST_OUT_DIR/<test>-<step>.png.
#include <QAction>
#include <QComboBox>
#include <QDir>
#include <QFileInfo>
#include <QElapsedTimer>
#include <QFile>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QRegularExpression>
#include <QSurfaceFormat>
#include <QTabBar>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QScreen>
#include <QSignalSpy>
#include <QTest>
#include <QVTKOpenGLStereoWidget.h>

#include <cmath>
#include <cstring>
#include <memory>

#include <vtkCommand.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>

#include "main_window.h"
#include "studio_test_support.h"
#include "parametric_editor.h"
#include "segment_editor.h"

extern "C" {
#include "navcore/nav_io.h"
}

using studio::MainWindow;
using studio::PathView;
using namespace studio_test;

namespace {

// Length of a drawn path [m] (3D polyline of the samples).
double PathLength(const studio::PathSamples &p) {
  double l = 0.0;
  for (size_t i = 1; i < p.Size(); ++i) {
    const double *a = &p.ned_m[3 * (i - 1)], *b = &p.ned_m[3 * i];
    l += std::sqrt((b[0] - a[0]) * (b[0] - a[0]) + (b[1] - a[1]) * (b[1] - a[1]) + (b[2] - a[2]) * (b[2] - a[2]));
  }
  return l;
}

QByteArray ReadAll(const QString &path) {
  QFile f(path);
  return f.open(QIODevice::ReadOnly) ? f.readAll() : QByteArray();
}

} // namespace

class TestNavstudioTraj : public QObject {
  Q_OBJECT
private slots:
  void initTestCase() {
    QVERIFY(tmp_.isValid());
    qputenv("NAVSTUDIO_AUTOSAVE_DIR", QFile::encodeName(tmp_.path() + "/autosave"));
    qputenv("NAVSTUDIO_NO_DIALOGS", "1");
  }

  // A segment script: switch the new drive to segments, edit items in the form (the path and
  // its length follow), add / insert / delete / reorder items, each one undo step; undo restores
  // the path exactly.
  void segment_edit() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    w->Panels()->setCurrentIndex(3);
    auto *type = w->findChild<QComboBox *>("trajectoryType");
    QVERIFY(type);
    Choose(type, "segments", Qt::MatchFixedString);
    const nav_scene &s = w->Doc()->Scene();
    QCOMPARE(static_cast<int>(s.trajectory.type), static_cast<int>(NAV_TRAJ_SEGMENTS));
    QVERIFY2(w->Doc()->PlanMessage().isEmpty(), qPrintable(w->Doc()->PlanMessage()));
    auto *table = w->findChild<QTableWidget *>("segmentTable");
    QVERIFY(table && table->isVisible());
    QCOMPARE(table->rowCount(), s.trajectory.segments.count);
    PathView *map = w->MapView();
    QVERIFY(map->PathPointCount() > 100);
    const std::vector<double> path0 = map->Path().ned_m;
    const double len0 = PathLength(map->Path());
    const double dur0 = s.trajectory.duration_s;
    Shot(w.get(), "segments-01-default-script");

    // Lengthen the final hold (the vehicle cruises on): +30 s at the cruise speed.
    const int last = s.trajectory.segments.count - 1;
    QCOMPARE(static_cast<int>(s.trajectory.segments.items[last].kind), static_cast<int>(NAV_SEG_HOLD));
    table->setCurrentCell(last, 0);
    QTest::qWait(10); // the rebuilt form's fields are shown by the event loop
    auto *dur = w->findChild<QLineEdit *>("seg.duration_s");
    QVERIFY(dur && dur->isVisible());
    const int undo0 = w->Doc()->UndoStack()->index();
    const double hold0 = s.trajectory.segments.items[last].duration_s;
    QElapsedTimer edit_timer;
    edit_timer.start();
    TypeInto(dur, QString::number(hold0 + 30.0));
    qInfo("segments: typing, validating (per keystroke) and committing the edit took %lld ms",
          static_cast<long long>(edit_timer.elapsed()));
    QCOMPARE(s.trajectory.segments.items[last].duration_s, hold0 + 30.0);
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0 + 1);
    QCOMPARE(s.trajectory.duration_s, dur0 + 30.0);
    const double speed = s.trajectory.segments.items[1].speed_mps;
    const double len1 = PathLength(map->Path());
    qInfo("segments: path %.1f m -> %.1f m after +30 s hold at %.1f m/s", len0, len1, speed);
    QVERIFY2(std::fabs(len1 - len0 - 30.0 * speed) < 0.02 * 30.0 * speed,
             qPrintable(QString("length %1 -> %2").arg(len0).arg(len1)));

    // Turn the other way: the shape changes, the length does not.
    int turn = -1;
    for (int i = 0; i < s.trajectory.segments.count; ++i)
      if (s.trajectory.segments.items[i].kind == NAV_SEG_TURN) turn = i;
    QVERIFY(turn >= 0);
    table->setCurrentCell(turn, 0);
    QTest::qWait(10); // the rebuilt form's fields are shown by the event loop
    auto *yaw = w->findChild<QLineEdit *>("seg.yaw_deg");
    QVERIFY(yaw && yaw->isVisible());
    QCOMPARE(yaw->text(), QString("90"));
    const std::vector<double> path1 = map->Path().ned_m;
    TypeInto(yaw, "-90");
    QCOMPARE(s.trajectory.segments.items[turn].yaw_rad, -M_PI / 2.0);
    const std::vector<double> &path2 = map->Path().ned_m;
    QCOMPARE(path2.size(), path1.size());
    QVERIFY(std::fabs(path2[path2.size() - 2] + path1[path1.size() - 2]) < 1.0); // east mirrored
    QVERIFY(std::fabs(path2[path2.size() - 2]) > 100.0);
    QVERIFY(w->View3D()->Path().ned_m == map->Path().ned_m);
    Shot(w.get(), "segments-02-edited");

    // Kind change from the combo: the turn becomes a circle (radius 100 m, one turn).
    Choose(w->findChild<QComboBox *>("segKind"), "circle", Qt::MatchFixedString);
    QTest::qWait(10);
    QCOMPARE(static_cast<int>(s.trajectory.segments.items[turn].kind), static_cast<int>(NAV_SEG_CIRCLE));
    QVERIFY(w->findChild<QLineEdit *>("seg.radius_m")->isVisible());
    QVERIFY2(w->Doc()->PlanMessage().isEmpty(), qPrintable(w->Doc()->PlanMessage()));
    const double len_circle = PathLength(map->Path());
    double max_e = -1e300;
    for (size_t k = 0; k < map->Path().Size(); ++k) max_e = std::max(max_e, map->Path().ned_m[3 * k + 1]);
    qInfo("segments: circle of radius 100 m: east extent %.2f m, path %.1f m -> %.1f m", max_e, len1, len_circle);
    QVERIFY2(len_circle > len1 + 2.0 * M_PI * 100.0 * 0.9, qPrintable(QString::number(len_circle)));

    // Add after, insert before, move up, delete: one undo step each.
    const int n = s.trajectory.segments.count;
    int u = w->Doc()->UndoStack()->index();
    QTest::mouseClick(w->findChild<QPushButton *>("segAdd"), Qt::LeftButton);
    QCOMPARE(s.trajectory.segments.count, n + 1);
    QCOMPARE(static_cast<int>(s.trajectory.segments.items[turn + 1].kind), static_cast<int>(NAV_SEG_HOLD));
    QCOMPARE(w->findChild<studio::SegmentEditor *>("segmentEditor")->CurrentItem(), turn + 1);
    QTest::mouseClick(w->findChild<QPushButton *>("segInsert"), Qt::LeftButton);
    QCOMPARE(s.trajectory.segments.count, n + 2);
    QTest::mouseClick(w->findChild<QPushButton *>("segUp"), Qt::LeftButton);
    QCOMPARE(static_cast<int>(s.trajectory.segments.items[turn].kind), static_cast<int>(NAV_SEG_HOLD));
    QCOMPARE(static_cast<int>(s.trajectory.segments.items[turn + 1].kind), static_cast<int>(NAV_SEG_CIRCLE));
    QTest::mouseClick(w->findChild<QPushButton *>("segDelete"), Qt::LeftButton);
    QCOMPARE(s.trajectory.segments.count, n + 1);
    QCOMPARE(w->Doc()->UndoStack()->index(), u + 4);
    QCOMPARE(table->rowCount(), n + 1);
    Shot(w.get(), "segments-03-reordered");

    // Undo everything back to the default script: the path is the first one again.
    QAction *undo = w->findChild<QAction *>("actionUndo");
    while (w->Doc()->UndoStack()->index() > undo0) undo->trigger();
    QCOMPARE(s.trajectory.segments.count, n);
    QCOMPARE(s.trajectory.duration_s, dur0);
    QVERIFY(map->Path().ned_m == path0);
    QCOMPARE(table->rowCount(), n);
    w->findChild<QAction *>("actionRedo")->trigger();
    QCOMPARE(s.trajectory.segments.items[last].duration_s, hold0 + 30.0);
    QVERIFY(std::fabs(PathLength(map->Path()) - len1) < 1e-6);
  }

  // An invalid field of a segment shows the message `navsim check` prints for that value in the
  // file, at the item and field; nothing is committed.
  void segment_invalid() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    w->Panels()->setCurrentIndex(3);
    Choose(w->findChild<QComboBox *>("trajectoryType"), "segments", Qt::MatchFixedString);
    auto *table = w->findChild<QTableWidget *>("segmentTable");
    table->setCurrentCell(2, 0);
    QTest::qWait(10); // the rebuilt form's fields are shown by the event loop
    Choose(w->findChild<QComboBox *>("segKind"), "circle", Qt::MatchFixedString);
    QTest::qWait(10);
    const nav_scene &s = w->Doc()->Scene();
    const int undo0 = w->Doc()->UndoStack()->index();
    auto *radius = w->findChild<QLineEdit *>("seg.radius_m");
    auto *msg = w->findChild<QLabel *>("segMessage");
    QVERIFY(radius && msg);
    radius->setFocus();
    radius->selectAll();
    QTest::keyClicks(radius, "-5");
    const QString expected = "trajectory.segments.items[2].radius_m: must be > 0 (got -5)";
    QVERIFY2(msg->isVisible() && msg->text() == expected, qPrintable(msg->text()));
    // The same text as the reader's diagnostic of that file (navsim check's FIELD: MESSAGE).
    QTemporaryDir dir;
    const QString file = dir.filePath("bad.yaml");
    QVERIFY(w->Doc()->WriteCopy(file, nullptr));
    QByteArray text = ReadAll(file);
    QVERIFY(text.contains("radius_m: 100"));
    text.replace("radius_m: 100", "radius_m: -5");
    QFile f(file);
    QVERIFY(f.open(QIODevice::WriteOnly));
    f.write(text);
    f.close();
    auto back = std::make_unique<nav_scene>();
    struct Sink {
      static void Fn(void *user, const nav_diag *d) {
        static_cast<QStringList *>(user)->push_back(QString::fromUtf8(d->path) + ": " + QString::fromUtf8(d->message));
      }
    };
    QStringList check;
    const QByteArray fp = QFile::encodeName(file);
    QCOMPARE(nav_scene_read_file(fp.constData(), back.get(), &Sink::Fn, &check), NAV_ERR_PARSE);
    QCOMPARE(check, QStringList{expected});
    Shot(w.get(), "segments-04-invalid-radius");
    QTest::keyClick(radius, Qt::Key_Return);
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0); // nothing committed
    QCOMPARE(s.trajectory.segments.items[2].radius_m, 100.0);
    QVERIFY(msg->isVisible());
    radius->selectAll();
    QTest::keyClicks(radius, "abc");
    QVERIFY2(msg->text() == "trajectory.segments.items[2].radius_m: expected a number, got \"abc\"", qPrintable(msg->text()));
    radius->selectAll();
    QTest::keyClicks(radius, "150");
    QVERIFY(!msg->isVisible());
    QTest::keyClick(radius, Qt::Key_Return);
    QCOMPARE(s.trajectory.segments.items[2].radius_m, 150.0);
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0 + 1);
    // A limit of the script: the reader's message for a negative maximum.
    auto *lim = w->findChild<QLineEdit *>("seg.limits.max_accel_mps2");
    QVERIFY(lim);
    lim->setFocus();
    lim->selectAll();
    QTest::keyClicks(lim, "-1");
    QVERIFY2(msg->text().startsWith("trajectory.segments.limits.max_accel_mps2: must be > 0"), qPrintable(msg->text()));
  }

  // The parametric form: typing a coefficient redraws the path after a pause (live, no undo
  // step); Enter commits one step; undo restores the path; the unit selector converts degrees.
  void parametric_preview() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/paper-parametric.yaml"));
    w->Panels()->setCurrentIndex(3);
    const nav_scene &s = w->Doc()->Scene();
    QCOMPARE(static_cast<int>(s.trajectory.type), static_cast<int>(NAV_TRAJ_PARAMETRIC));
    auto *ed = w->findChild<studio::ParametricEditor *>("parametricEditor");
    QVERIFY(ed && ed->isVisible());
    // Before any result, the Results tab says where this kind of trajectory is edited (not
    // "draw a drive on the map").
    QVERIFY2(w->ResultsText().contains("has a parametric trajectory") && w->ResultsText().contains("Trajectory panel") &&
                 !w->ResultsText().contains("Draw a drive"),
             qPrintable(w->ResultsText()));
    auto *b0 = w->findChild<QLineEdit *>("par.B_m[0]");
    QVERIFY(b0);
    QCOMPARE(b0->text(), QString("1"));
    PathView *map = w->MapView();
    const std::vector<double> path0 = map->Path().ned_m;
    QVERIFY(path0.size() > 300);
    const int undo0 = w->Doc()->UndoStack()->index();
    {
      // A click on the map does not replace the parametric trajectory by a waypoint; the status
      // bar says where it is edited.
      QSignalSpy said(map, &PathView::CursorText);
      int x = 0, y = 0;
      QVERIFY(map->DisplayOf(path0[0] + 30.0, path0[1] + 30.0, 0.0, &x, &y));
      vtkRenderWindowInteractor *i = map->Interactor();
      i->SetEventInformation(x, y, 0, 0);
      i->InvokeEvent(vtkCommand::MouseMoveEvent);
      i->InvokeEvent(vtkCommand::LeftButtonPressEvent);
      i->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
      QCOMPARE(static_cast<int>(s.trajectory.type), static_cast<int>(NAV_TRAJ_PARAMETRIC));
      QCOMPARE(w->Doc()->UndoStack()->index(), undo0);
      QVERIFY(!said.isEmpty());
      QVERIFY2(said.last().at(0).toString().contains("parametric trajectory has no waypoints"),
               qPrintable(said.last().at(0).toString()));
    }
    b0->setFocus();
    b0->selectAll();
    QTest::keyClicks(b0, "50");
    // Debounced: nothing yet right after the keystrokes, then the preview.
    QCOMPARE(ed->PreviewCount(), 0);
    QElapsedTimer typed;
    typed.start();
    QVERIFY(WaitUntil([&] { return ed->PreviewCount() > 0; }, 5000));
    qInfo("parametric: preview %lld ms after the last keystroke (debounce %d ms)",
          static_cast<long long>(typed.elapsed()), studio::kParametricDebounceMs);
    QCOMPARE(ed->PreviewCount(), 1); // one preview for the burst of keystrokes
    QVERIFY(w->Doc()->IsLive());
    QCOMPARE(s.trajectory.parametric.b_m.x, 50.0);
    QVERIFY(WaitUntil([&] { return map->Path().ned_m != path0; }, 5000));
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0); // a preview is no edit
    // Sample 1 of 1200 over 20 s: N moves by B sin(2 pi C t) with C = 0.1 Hz.
    const studio::PathSamples &p = map->Path();
    double max_dn = 0.0;
    for (size_t i = 0; i < p.Size(); ++i) {
      const double t = p.t_s[i];
      const double n_expected = 10.0 * t + 0.1 * t * t + 50.0 * std::sin(2.0 * M_PI * 0.1 * t);
      max_dn = std::max(max_dn, std::fabs(p.ned_m[3 * i] - n_expected));
    }
    QVERIFY2(max_dn < 1e-6, qPrintable(QString::number(max_dn)));
    Shot(w.get(), "parametric-01-preview");
    QTest::keyClick(b0, Qt::Key_Return);
    QVERIFY(!w->Doc()->IsLive());
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0 + 1);
    QCOMPARE(s.trajectory.parametric.b_m.x, 50.0);
    const std::vector<double> path1 = map->Path().ned_m;
    w->findChild<QAction *>("actionUndo")->trigger();
    QCOMPARE(s.trajectory.parametric.b_m.x, 1.0);
    QCOMPARE(b0->text(), QString("1"));
    QVERIFY(map->Path().ned_m == path0);
    w->findChild<QAction *>("actionRedo")->trigger();
    QVERIFY(map->Path().ned_m == path1);

    // Unit-aware: D in degrees.
    auto *unit = w->findChild<QComboBox *>("par.unit.D_rad");
    QVERIFY(unit);
    unit->setCurrentIndex(1);
    auto *d1 = w->findChild<QLineEdit *>("par.D_rad[1]");
    QCOMPARE(d1->text(), studio::FieldNumber(0.5 * 180.0 / M_PI));
    TypeInto(d1, "90");
    QVERIFY(std::fabs(s.trajectory.parametric.d_rad.y - M_PI / 2.0) < 1e-15);
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0 + 2);

    // Invalid: the reader's message, nothing committed, the views back to the committed state.
    const std::vector<double> path2 = map->Path().ned_m;
    auto *c0 = w->findChild<QLineEdit *>("par.C_hz[0]");
    auto *msg = w->findChild<QLabel *>("parMessage");
    c0->setFocus();
    c0->selectAll();
    QTest::keyClicks(c0, "x");
    QVERIFY(WaitUntil([&] { return msg->isVisible(); }, 5000));
    QVERIFY2(msg->text().startsWith("trajectory.parametric.C_hz[0]: expected a number"), qPrintable(msg->text()));
    Shot(w.get(), "parametric-02-invalid");
    QTest::keyClick(c0, Qt::Key_Return);
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0 + 2);
    QCOMPARE(s.trajectory.parametric.c_hz.x, 0.1);
    QVERIFY(map->Path().ned_m == path2);
  }

  // Save after open keeps the user's comments and layout; what was saved loads as the scene.
  void save_keeps_comments() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    const QString src = studio::ScenesDir() + "/bench-mc-1h.yaml";
    const QString file = tmp_.filePath("bench-copy.yaml");
    QFile::remove(file);
    QVERIFY(QFile::copy(src, file));
    QFile::setPermissions(file, QFile::ReadOwner | QFile::WriteOwner);
    // The user's comments: own-line ones between list items, one after an item that changes.
    QByteArray original = ReadAll(file);
    QVERIFY(original.contains("      - {kind: hold, duration_s: 20}\n      - {kind: accelerate, speed_mps: 15}\n"));
    original.replace("      - {kind: hold, duration_s: 20}\n      - {kind: accelerate, speed_mps: 15}\n",
                     "      # wait for the alignment\n      - {kind: hold, duration_s: 20}   # seconds\n"
                     "      - {kind: accelerate, speed_mps: 15}\n      # the survey\n");
    QVERIFY(original.contains("seed: 2026"));
    // A limit in the other unit spelling of the reader (rad/s where the writer writes deg/s).
    QVERIFY(original.contains("max_rate_dps: 30,"));
    original.replace("max_rate_dps: 30,", "max_rate_rps: 0.5235987755982988,");
    {
      QFile f(file);
      QVERIFY(f.open(QIODevice::WriteOnly | QIODevice::Truncate));
      f.write(original);
    }
    QVERIFY(w->OpenFile(file));
    w->Panels()->setCurrentIndex(3);
    // Edits: a segment value, a new segment, the seed.
    auto *table = w->findChild<QTableWidget *>("segmentTable");
    table->setCurrentCell(0, 0);
    QTest::qWait(10); // the rebuilt form's fields are shown by the event loop
    TypeInto(w->findChild<QLineEdit *>("seg.duration_s"), "25");
    QTest::mouseClick(w->findChild<QPushButton *>("segAdd"), Qt::LeftButton);
    TypeInto(w->findChild<QLineEdit *>("simulation.seed"), "42");
    QCOMPARE(w->findChild<QLineEdit *>("seg.limits.max_rate_dps")->text(), QString("30"));
    TypeInto(w->findChild<QLineEdit *>("seg.limits.max_rate_dps"), "20");
    QVERIFY(w->Save());
    QFile::remove(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR) + "/save-keeps-comments.yaml");
    QFile::copy(file, QStringLiteral(NAVSTUDIO_TEST_OUT_DIR) + "/save-keeps-comments.yaml"); // to look at
    const QString note = w->Doc()->SaveNote();
    qInfo("save: %s", qPrintable(note));
    const QByteArray saved = ReadAll(file);
    // Every comment line of the original survives.
    QStringList lost;
    for (const QByteArray &line : original.split('\n')) {
      const int h = line.indexOf('#');
      if (h < 0) continue;
      if (!saved.contains(line.mid(h))) lost << QString::fromUtf8(line.mid(h));
    }
    QVERIFY2(lost.isEmpty(), qPrintable("lost: " + lost.join(" | ") + "\nnote: " + note));
    // Exactly the edits, nothing else: the value in place, the new item on a line of its own.
    QByteArray expected = original;
    expected.replace("      - {kind: hold, duration_s: 20}   # seconds\n",
                     "      - {kind: hold, duration_s: 25}   # seconds\n      - {kind: hold, duration_s: 10}\n");
    expected.replace("seed: 2026", "seed: 42");
    expected.replace("max_rate_rps: 0.5235987755982988,", "max_rate_dps: 20,");
    QCOMPARE(QString::fromUtf8(saved), QString::fromUtf8(expected));
    QVERIFY2(note.startsWith("comments and layout kept except where rewritten: "
                             "trajectory.segments.limits.max_rate_dps (unit of max_rate_rps)"),
             qPrintable(note));
    // What the program wrote loads as the scene that was saved.
    auto back = std::make_unique<MainWindow>();
    QVERIFY(back->OpenFile(file));
    const nav_scene &a = w->Doc()->Scene(), &b = back->Doc()->Scene();
    QCOMPARE(b.trajectory.segments.count, a.trajectory.segments.count);
    QCOMPARE(b.trajectory.segments.items[0].duration_s, 25.0);
    QCOMPARE(b.simulation.seed, uint64_t(42));
    QTemporaryDir dir;
    QVERIFY(w->Doc()->WriteCopy(dir.filePath("a.yaml"), nullptr));
    QVERIFY(back->Doc()->WriteCopy(dir.filePath("b.yaml"), nullptr));
    QCOMPARE(ReadAll(dir.filePath("a.yaml")), ReadAll(dir.filePath("b.yaml")));
    // A second save after more edits (delete the new item, another seed) keeps them too.
    w->findChild<studio::SegmentEditor *>("segmentEditor")->SelectItem(1);
    QTest::mouseClick(w->findChild<QPushButton *>("segDelete"), Qt::LeftButton);
    QCOMPARE(w->Doc()->Scene().trajectory.segments.count, 5);
    TypeInto(w->findChild<QLineEdit *>("simulation.seed"), "43");
    QVERIFY(w->Save());
    const QByteArray saved2 = ReadAll(file);
    expected = original;
    expected.replace("duration_s: 20}   # seconds", "duration_s: 25}   # seconds");
    expected.replace("seed: 2026", "seed: 43");
    expected.replace("max_rate_rps: 0.5235987755982988,", "max_rate_dps: 20,");
    QCOMPARE(QString::fromUtf8(saved2), QString::fromUtf8(expected));
    // The duration of the script stays "auto" (the file has it so): the plan changed with the edit.
    QVERIFY(saved2.contains("  duration_s: auto\n"));
  }

  // Every scene of the library: open, change the seed, save as: the saved text is the original
  // with that one value changed (or the key added), and it reads (in the scene's directory, for
  // its relative file references) as the scene that was saved.
  void save_all_scenes() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    const QStringList scenes = QDir(studio::ScenesDir()).entryList({"*.yaml"}, QDir::Files, QDir::Name);
    QVERIFY(scenes.size() >= 10);
    QTemporaryDir dir;
    int kept = 0;
    for (const QString &name : scenes) {
      const QString src = studio::ScenesDir() + "/" + name;
      QVERIFY2(w->OpenFile(src), qPrintable(name));
      const QByteArray original = ReadAll(src);
      const uint64_t seed = w->Doc()->Scene().simulation.seed;
      TypeInto(w->findChild<QLineEdit *>("simulation.seed"), QString::number(seed + 1));
      QCOMPARE(w->Doc()->Scene().simulation.seed, seed + 1);
      const QString out = dir.filePath(name);
      QVERIFY2(w->SaveAs(out), qPrintable(name));
      const QByteArray saved = ReadAll(out);
      QDir().mkpath(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR) + "/saved-scenes");
      QFile::remove(QStringLiteral(NAVSTUDIO_TEST_OUT_DIR) + "/saved-scenes/" + name);
      QFile::copy(out, QStringLiteral(NAVSTUDIO_TEST_OUT_DIR) + "/saved-scenes/" + name); // to look at
      const QString note = w->Doc()->SaveNote();
      const QRegularExpression seed_line(QStringLiteral("(\\n  seed: *)%1\\b").arg(seed));
      if (QString::fromUtf8(original).contains(seed_line)) {
        const QString expected = QString::fromUtf8(original).replace(seed_line, QStringLiteral("\\1%1").arg(seed + 1));
        QVERIFY2(QString::fromUtf8(saved) == expected, qPrintable(name + ": " + note));
        ++kept;
      } else {
        for (const QByteArray &line : original.split('\n')) {
          const int h = line.indexOf('#');
          if (h >= 0) QVERIFY2(saved.contains(line.mid(h)), qPrintable(name + ": lost " + QString::fromUtf8(line)));
        }
        // The section the file left to the defaults comes back with the changed key only.
        QVERIFY2(saved.contains(QByteArray("\nsimulation:\n  seed: ") + QByteArray::number(qulonglong(seed + 1)) + "\n"),
                 qPrintable(name));
        QCOMPARE(saved.count('\n'), original.count('\n') + 2);
      }
      // Loads identically: the saved text read in the scene's own directory, written canonically.
      auto back = std::make_unique<nav_scene>();
      const QByteArray display = QFile::encodeName(src);
      QCOMPARE(nav_scene_read_string(saved.constData(), size_t(saved.size()), display.constData(), back.get(), nullptr,
                                     nullptr),
               NAV_OK);
      studio::Normalize(back.get());
      auto doc2 = std::make_unique<studio::SceneDocument>();
      doc2->Reset(*back);
      QVERIFY(doc2->WriteCopy(dir.filePath("a.yaml"), nullptr));
      QVERIFY(w->Doc()->WriteCopy(dir.filePath("b.yaml"), nullptr));
      QVERIFY2(ReadAll(dir.filePath("a.yaml")) == ReadAll(dir.filePath("b.yaml")), qPrintable(name));
      qInfo("%s: %s", qPrintable(name), qPrintable(note));
    }
    qInfo("%d of %d scenes saved with exactly the one line changed", kept, int(scenes.size()));
  }

  // Shift+drag of a waypoint's handle in the 3D view changes its height only (one undo step).
  void shift_drag_height() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QVERIFY(w->NewDrive());
    for (const auto &p : kDrive) studio::AddWaypoint(w->Doc(), p[0], p[1], 0.0);
    PathView *v3 = w->View3D();
    v3->ResetCamera();
    v3->Render();
    QTest::qWait(50);
    const nav_vec3 r0 = w->Doc()->Scene().trajectory.waypoints.points[2].r_ned_m;
    int x0 = 0, y0 = 0;
    QVERIFY(v3->DisplayOf(r0.x, r0.y, r0.z, &x0, &y0));
    const int undo0 = w->Doc()->UndoStack()->index();
    vtkRenderWindowInteractor *i = v3->Interactor();
    const int dy = 60; // VTK display y grows upwards: drag up
    i->SetEventInformation(x0, y0, 0, 1);
    i->InvokeEvent(vtkCommand::MouseMoveEvent);
    i->InvokeEvent(vtkCommand::LeftButtonPressEvent);
    for (int k = 1; k <= 6; ++k) {
      i->SetEventInformation(x0, y0 + dy * k / 6, 0, 1);
      i->InvokeEvent(vtkCommand::MouseMoveEvent);
      QApplication::processEvents();
    }
    i->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
    const nav_vec3 r1 = w->Doc()->Scene().trajectory.waypoints.points[2].r_ned_m;
    qInfo("shift-drag: waypoint 2 D %.2f m -> %.2f m for %d px", r0.z, r1.z, dy);
    QCOMPARE(r1.x, r0.x);
    QCOMPARE(r1.y, r0.y);
    QVERIFY2(r1.z < r0.z - 1.0, qPrintable(QString::number(r1.z))); // up = negative down
    QCOMPARE(w->Doc()->UndoStack()->index(), undo0 + 1);
    QCOMPARE(v3->StemCount(), size_t(1)); // the raised waypoint's drop line to the ground
    // The handle followed the height: it is drawn where the mouse was released.
    int x1 = 0, y1 = 0;
    QVERIFY(v3->DisplayOf(r1.x, r1.y, r1.z, &x1, &y1));
    // The handle stays under the cursor: the height is the point of the waypoint's vertical line
    // nearest to the ray under the mouse (the camera is tilted, so the vertical is foreshortened).
    qInfo("shift-drag: handle moved %d px up for a %d px drag", y1 - y0, dy);
    QVERIFY2(std::abs(x1 - x0) <= 2 && std::abs(y1 - (y0 + dy)) <= 2,
             qPrintable(QString("handle at %1,%2, released at %3,%4").arg(x1).arg(y1).arg(x0).arg(y0 + dy)));
    Shot(w.get(), "shift-drag-01-raised");
    w->findChild<QAction *>("actionUndo")->trigger();
    QCOMPARE(w->Doc()->Scene().trajectory.waypoints.points[2].r_ned_m.z, r0.z);
    QCOMPARE(v3->StemCount(), size_t(0));
  }

  // Opened by a user, the window fits the screen's available area (the default 1500 x 950 is wider
  // than a 1280 x 1024 screen) unless the layout's minimum is larger; the views stay usable.
  void fit_to_screen() {
    auto w = MakeWindow();
    QVERIFY(w);
    const QRect avail = w->screen()->availableGeometry();
    QCOMPARE(w->size(), QSize(1500, 950)); // the default the screenshots and the bench use
    w->FitToScreen();
    QTRY_VERIFY_WITH_TIMEOUT(w->MapView()->isVisible(), 5000);
    const QSize minimum = w->minimumSizeHint();
    qInfo("screen %dx%d available, window %dx%d (layout minimum %dx%d)", avail.width(), avail.height(), w->width(),
          w->height(), minimum.width(), minimum.height());
    QVERIFY(w->width() <= std::max(avail.width(), minimum.width()));
    QVERIFY(w->height() <= std::max(avail.height(), minimum.height()));
    if (minimum.width() <= avail.width()) QVERIFY(avail.contains(w->geometry()));
    QVERIFY(w->MapView()->width() >= 200 && w->MapView()->height() >= 150);
    QVERIFY(w->Panels()->width() >= 400);
    // Every panel tab is in sight, and each view's caption (hint and facts) wraps to its width.
    QTabBar *tabs = w->Panels()->tabBar();
    for (int i = 0; i < tabs->count(); ++i)
      QVERIFY2(tabs->rect().contains(tabs->tabRect(i)), qPrintable(tabs->tabText(i)));
    for (PathView *v : {w->MapView(), w->View3D()}) {
      v->Render();
      qInfo("%s view %d px wide, caption %d px:\n%s", v == w->MapView() ? "map" : "3D", v->width(), v->CaptionWidth(),
            qPrintable(v->CaptionText()));
      QVERIFY2(v->CaptionWidth() <= v->width() - 8, qPrintable(v->CaptionText()));
    }
    QVERIFY(w->MapView()->CaptionText().simplified().contains("drag one to move it (Ctrl+click inserts, Delete removes)"));
    QVERIFY(w->MapView()->CaptionText().simplified().contains("0 waypoints"));
    Shot(w.get(), "fit-to-screen");
  }

  // Opening a scene frames it in both views: every waypoint and every drawn path sample projects
  // inside the view with a margin, and the path is not a speck (it spans at least 40 % of the
  // view's width or height). Before the fit was computed, the first waypoint of an opened
  // elongated drive fell outside the 3D view. Every library scene, the journey's drive and a long
  // thin climbing drive.
  void views_frame_the_path() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(false);
    QStringList files;
    for (const QString &f : QDir(studio::ScenesDir()).entryList({"*.yaml"}, QDir::Files, QDir::Name))
      files << studio::ScenesDir() + "/" + f;
    files << QString(NAVSTUDIO_TEST_DATA_DIR) + "/four-waypoint-drive.yaml";
    {
      QByteArray text = ReadAll(QString(NAVSTUDIO_TEST_DATA_DIR) + "/four-waypoint-drive.yaml");
      const int a = text.indexOf("    points:\n"), b = text.indexOf("imu:");
      QVERIFY(a > 0 && b > a);
      text.replace(a, b - a,
                   "    cruise_mps: 10\n    points:\n      - {ned_m: [0, 0, 0], speed_mps: 0}\n"
                   "      - {ned_m: [60, 900, -30], speed_mps: 0}\n");
      QFile f(tmp_.filePath("thin-drive.yaml"));
      QVERIFY(f.open(QIODevice::WriteOnly) && f.write(text) == text.size());
      files << f.fileName();
    }
    for (const QString &file : files) {
      QVERIFY2(w->OpenFile(file), qPrintable(file));
      const nav_scene &s = w->Doc()->Scene();
      for (PathView *v : {w->MapView(), w->View3D()}) {
        v->Render();
        const int *wsz = v->Interactor()->GetRenderWindow()->GetSize();
        const struct {
          int w, h;
        } sz = {wsz[0], wsz[1]};
        const studio::PathSamples &path = v->Path();
        QVERIFY2(path.Size() >= 2, qPrintable(file));
        const int margin = std::max(2, sz.w / 50);
        int xmin = sz.w, xmax = -1, ymin = sz.h, ymax = -1, misses = 0;
        auto inside = [&](double n, double e, double d, const char *what, int k) {
          int x = 0, y = 0;
          const bool on = v->DisplayOf(n, e, d, &x, &y) && x >= margin && y >= margin && x < sz.w - margin &&
                          y < sz.h - margin;
          xmin = std::min(xmin, x), xmax = std::max(xmax, x), ymin = std::min(ymin, y), ymax = std::max(ymax, y);
          if (!on && ++misses <= 3)
            qWarning("%s, %s view: %s %d at %d,%d in %dx%d", qPrintable(QFileInfo(file).fileName()),
                     v == w->MapView() ? "map" : "3D", what, k, x, y, sz.w, sz.h);
          return on;
        };
        bool all = true;
        for (size_t i = 0; i < path.Size(); ++i)
          all = inside(path.ned_m[3 * i], path.ned_m[3 * i + 1], path.ned_m[3 * i + 2], "path sample", int(i)) && all;
        if (s.trajectory.type == NAV_TRAJ_WAYPOINTS)
          for (int i = 0; i < s.trajectory.waypoints.count; ++i) {
            const nav_vec3 r = s.trajectory.waypoints.points[i].r_ned_m;
            all = inside(r.x, r.y, r.z, "waypoint", i) && all;
          }
        QVERIFY2(all, qPrintable(file));
        const double span = std::max(double(xmax - xmin) / sz.w, double(ymax - ymin) / sz.h);
        qInfo("%-28s %s view: path spans %.0f %% of the view", qPrintable(QFileInfo(file).fileName()),
              v == w->MapView() ? "map" : "3D ", 100.0 * span);
        // Paths shorter than the 200 m minimum square are allowed to be small.
        double ext = 0.0;
        for (size_t i = 0; i < path.Size(); ++i)
          ext = std::max({ext, std::fabs(path.ned_m[3 * i] - path.ned_m[0]), std::fabs(path.ned_m[3 * i + 1] - path.ned_m[1])});
        if (ext > 200.0) QVERIFY2(span >= 0.4, qPrintable(file));
      }
      if (file.endsWith("thin-drive.yaml")) Shot(w.get(), "frame-thin-drive");
    }
  }

  // Live preview runs for scenes of up to 10 min at 100 Hz worth of IMU steps: a 20 s scene at
  // 200 Hz (long-drive-replay's parametric path) is previewed, the long drive (811 s at 200 Hz) is
  // not and the status bar says why.
  void preview_size_limit() {
    auto w = MakeWindow();
    QVERIFY(w);
    w->SetLivePreview(true);
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/long-drive-replay.yaml"));
    const nav_scene &s = w->Doc()->Scene();
    QCOMPARE(s.imu.rate_hz, 200.0);
    QVERIFY(s.trajectory.duration_s * s.imu.rate_hz <= studio::kPreviewMaxImuSteps);
    QVERIFY(WaitUntil([&] { return w->LastPreview() != nullptr && !w->PreviewWorker()->IsBusy(); }, 60000));
    QVERIFY2(w->PreviewStatusText().startsWith("preview "), qPrintable(w->PreviewStatusText()));
    QVERIFY2(!w->PreviewStatusText().contains("off"), qPrintable(w->PreviewStatusText()));
    QVERIFY(w->OpenFile(studio::ScenesDir() + "/long-drive.yaml"));
    QVERIFY(s.trajectory.duration_s * s.imu.rate_hz > studio::kPreviewMaxImuSteps);
    const QString off = QString("preview off: %1 s at 200 Hz").arg(s.trajectory.duration_s, 0, 'f', 0);
    QTRY_VERIFY2_WITH_TIMEOUT(w->PreviewStatusText().startsWith(off), qPrintable(w->PreviewStatusText()), 5000);
    qInfo("%s", qPrintable(w->PreviewStatusText()));
    Shot(w.get(), "preview-off-long-drive");
  }

private:
  QTemporaryDir tmp_;
};

int main(int argc, char **argv) {
  QSurfaceFormat::setDefaultFormat(QVTKOpenGLStereoWidget::defaultFormat());
  QApplication app(argc, argv);
  QApplication::setOrganizationName("navstudio-test");
  QApplication::setApplicationName("navstudio-test");
  TestNavstudioTraj t;
  return QTest::qExec(&t, argc, argv);
}

#include "test_navstudio_traj.moc"
