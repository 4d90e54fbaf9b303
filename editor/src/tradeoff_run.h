// navstudio: Simulation > Speed against error... runs `navsim tradeoff` on the saved scene as a
// child process (the command of issue 23 item 6; its result directory, charts and recommended
// scene are navsim's) and shows its charts and recommendation in a dialog.
#pragma once

#include <QDialog>
#include <QObject>
#include <QProcess>
#include <QString>
#include <functional>

namespace studio {

class TradeoffRun : public QObject {
  Q_OBJECT
public:
  explicit TradeoffRun(QObject *parent = nullptr);
  ~TradeoffRun() override;
  /** navsim of this build or installation (nav_paths_program), else "navsim" on PATH; tests set it. */
  void SetProgram(const QString &navsim) { program_ = navsim; }
  /** Start `navsim tradeoff SCENE --out DIR --quiet [--runs N]` (N 0: navsim's default).
   *  false with @p error when one is already running or the process cannot start. */
  bool Start(const QString &scene, const QString &out_dir, int runs, QString *error);
  bool IsBusy() const { return proc_.state() != QProcess::NotRunning; }
  QString OutDir() const { return out_dir_; }
signals:
  /** The command ended: @p ok exit 0; @p message its stderr (or why it did not run). */
  void Finished(bool ok, const QString &message);

private:
  QProcess proc_;
  QString program_, out_dir_;
};

/** The dialog of a tradeoff result directory: the recommendation (summary.json), the charts
 *  (tradeoff_*.png) and a button that opens recommended.yaml through @p open_scene.
 *  objectName "tradeoffDialog"; the charts are QLabels named "tradeoffChart". */
QDialog *MakeTradeoffDialog(QWidget *parent, const QString &dir, const std::function<void(const QString &)> &open_scene);

} // namespace studio
