/*
 * navstudio: the scene panels (Model, IMU, GNSS, Trajectory, Simulation, Requirements). Every
 * field shows its value in the units of the scene file (datasheet units for sensors), validates
 * as the user types with the messages `navsim check` prints for the same value, and commits one
 * undoable edit when the user presses Enter or leaves the field.
 */
#ifndef NAVSTUDIO_PANELS_H
#define NAVSTUDIO_PANELS_H

#include <QTabWidget>

#include <functional>
#include <memory>
#include <vector>

#include "sim_worker.h"
#include "studio_scene.h"

class QCheckBox;
class QComboBox;
class QFormLayout;
class QLabel;
class QLineEdit;
class QPushButton;
class QTableWidget;

namespace studio {

/** A numeric field bound to one scene value. */
class NumField : public QWidget {
  Q_OBJECT
public:
  using Getter = std::function<double(const nav_scene &)>;
  using Setter = std::function<void(nav_scene &, double)>;
  /** @p path: scene-file path prefix whose issues belong to this field ("imu.rate_hz");
   *  @p optional: an empty field is allowed and calls @p clear (a term switched off);
   *  @p is_set: whether the value is present (optional fields). */
  NumField(SceneDocument *doc, const QString &label, const QString &unit, const QString &path, Getter get,
           Setter set, QWidget *parent = nullptr);
  void SetOptional(std::function<bool(const nav_scene &)> is_set, std::function<void(nav_scene &)> clear);
  /** Add the scene table's description, range and default of @p key to the tooltip. */
  void SetHelp(const QString &key, const QString &help);
  void Refresh();
  /** Show the value with @p digits significant digits (whole numbers keep every digit); the scene
   *  keeps the full value until the user types another (default 10). */
  void SetSignificantDigits(int digits);
  QLineEdit *Edit() { return edit_; }
  QString Label() const { return label_; }
  QString Path() const { return path_; }
  /** The message shown under the field ("" when valid). */
  QString Message() const;

private:
  void OnEdited();
  void OnCommit();
  bool Parse(double *v, bool *empty, QString *err) const;
  void ShowIssues(const QVector<Issue> &issues);
  SceneDocument *doc_;
  QString label_, unit_, path_;
  Getter get_;
  Setter set_;
  std::function<bool(const nav_scene &)> is_set_;
  std::function<void(nav_scene &)> clear_;
  QLineEdit *edit_;
  QLabel *msg_;
  int digits_ = 10;
};

class ScenePanels : public QTabWidget {
  Q_OBJECT
public:
  ScenePanels(SceneDocument *doc, Catalogs *catalogs, QWidget *parent = nullptr);
  /** Update every widget from the document (signals blocked). */
  void Refresh();
  /** Show the verdicts of the last result in the Requirements table. */
  void SetVerdicts(const std::vector<nav_requirement_verdict> &v);
  QTableWidget *WaypointTable() { return wp_table_; }
  void SelectWaypoint(int i);

signals:
  void RunRequested();
  void CancelRequested();
  void WaypointSelected(int i);

private:
  QWidget *BuildModel();
  QWidget *BuildImu();
  QWidget *BuildGnss();
  QWidget *BuildTrajectory();
  QWidget *BuildSimulation();
  QWidget *BuildRequirements();
  NumField *AddField(QFormLayout *form, const QString &label, const QString &unit, const QString &path,
                     NumField::Getter get, NumField::Setter set);
  /** A field for the scene key @p key of navcore_io's table (nav_schema.h): its unit, scale to SI
   *  and help come from the table; @p get / @p set work in SI, the field in the key's unit. */
  NumField *AddKey(QFormLayout *form, const QString &label, const char *key, const QString &path,
                   NumField::Getter get_si, NumField::Setter set_si);
  void RefreshWaypoints();
  void RefreshOutages();
  void RefreshRequirements();
  void OnWaypointCellChanged(int row, int col);
  void OnOutageCellChanged(int row, int col);

  SceneDocument *doc_;
  Catalogs *cat_;
  std::vector<NumField *> fields_;
  QComboBox *scheme_ = nullptr, *algorithm_ = nullptr, *earth_ = nullptr, *frame_ = nullptr;
  QComboBox *imu_catalog_ = nullptr, *gnss_receiver_ = nullptr;
  QCheckBox *gnss_enabled_ = nullptr, *geodetic_ = nullptr;
  QTableWidget *wp_table_ = nullptr, *outages_ = nullptr, *req_table_ = nullptr;
  QLabel *plan_label_ = nullptr, *imu_note_ = nullptr, *req_summary_ = nullptr;
  std::vector<nav_requirement_verdict> verdicts_;
  bool refreshing_ = false;
};

} // namespace studio

#endif
