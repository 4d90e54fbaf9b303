// Helpers shared by the navstudio GUI tests (QTest under Xvfb): screenshots, waiting, typing,
// choosing, the main window with its questions answered, and the small four-waypoint drive.
#pragma once

#include <QApplication>
#include <QComboBox>
#include <QDir>
#include <QElapsedTimer>
#include <QLineEdit>
#include <QMessageBox>
#include <QTest>

#include <functional>
#include <memory>

#include "main_window.h"

namespace studio_test {

/** Screenshot of the main window as NAVSTUDIO_TEST_OUT_DIR/<name>.png. */
inline void Shot(studio::MainWindow *w, const QString &name) {
  QDir().mkpath(NAVSTUDIO_TEST_OUT_DIR);
  QApplication::processEvents();
  const QString p = QStringLiteral(NAVSTUDIO_TEST_OUT_DIR) + "/" + name + ".png";
  QVERIFY2(w->Screenshot().save(p), qPrintable("cannot write " + p));
}

/** Process events until @p done or @p timeout_ms; false on timeout. */
inline bool WaitUntil(const std::function<bool()> &done, int timeout_ms) {
  QElapsedTimer t;
  t.start();
  while (!done()) {
    if (t.elapsed() > timeout_ms) return false;
    QTest::qWait(20);
  }
  return true;
}

/** Select the entry matching @p text (@p match: Qt's matching flags) as a user does. */
inline void Choose(QComboBox *c, const QString &text, Qt::MatchFlags match = Qt::MatchContains) {
  const int i = c->findText(text, match);
  QVERIFY2(i >= 0, qPrintable("no entry " + text));
  c->setCurrentIndex(i);
  emit c->activated(i);
}

/** Type @p text into a field, replacing its content, and press Enter. */
inline void TypeInto(QLineEdit *e, const QString &text) {
  e->setFocus();
  e->selectAll();
  QTest::keyClicks(e, text);
  QTest::keyClick(e, Qt::Key_Return);
}

/** The main window, shown and exposed; questions answered Yes (else Discard). */
inline std::unique_ptr<studio::MainWindow> MakeWindow() {
  auto w = std::make_unique<studio::MainWindow>();
  w->SetAsk([](const QString &, const QString &, QMessageBox::StandardButtons b) {
    return (b & QMessageBox::Yes) ? QMessageBox::Yes : QMessageBox::Discard;
  });
  w->show();
  if (!QTest::qWaitForWindowExposed(w.get())) return nullptr;
  QTest::qWait(50);
  return w;
}

/** Four waypoints of a small drive (north, east in metres). */
inline const double kDrive[4][2] = {{-200.0, -300.0}, {-200.0, 150.0}, {150.0, 150.0}, {150.0, 400.0}};

} // namespace studio_test
