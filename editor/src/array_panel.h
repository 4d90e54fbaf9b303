/*
 * navstudio: the Array panel (issue 21): the accelerometer array of the gyro-free schemes. The
 * layout (cube6, nine, twelve or custom sensors), the arm length, the accelerometer part from
 * resources/accel_catalog.csv with its datasheet figures (datasheet units, source and whether they
 * were checked), and the per-sensor error terms typed in datasheet units, which override the part.
 * Self-contained: it loads the accelerometer catalog itself and refreshes on the document's
 * Changed signal; ScenePanels only adds it as a tab.
 */
#ifndef NAVSTUDIO_ARRAY_PANEL_H
#define NAVSTUDIO_ARRAY_PANEL_H

#include <QWidget>

#include <vector>

#include "studio_scene.h"

extern "C" {
#include "navcore/nav_catalog.h"
}

class QComboBox;
class QLabel;
class QTableWidget;

namespace studio {

class NumField;

class ArrayPanel : public QWidget {
  Q_OBJECT
public:
  explicit ArrayPanel(SceneDocument *doc, QWidget *parent = nullptr);
  ~ArrayPanel() override;
  ArrayPanel(const ArrayPanel &) = delete;
  ArrayPanel &operator=(const ArrayPanel &) = delete;
  /** Update every widget from the document (signals blocked). */
  void Refresh();
  /** The accelerometer catalog (NULL when it could not be loaded; the panel says why). */
  const nav_catalog *Parts() const { return parts_; }
  /** The datasheet figures of @p e as the panel shows them (datasheet units, rounded). */
  static QString FiguresText(const nav_catalog_accel_entry &e);

private:
  void ChoosePart(int index);
  void ChooseLayout(int index);
  void OnSensorCellChanged(int row, int col);

  SceneDocument *doc_;
  nav_catalog *parts_ = nullptr;
  QString load_errors_;
  QComboBox *layout_ = nullptr, *part_ = nullptr;
  QLabel *figures_ = nullptr, *note_ = nullptr, *issues_ = nullptr;
  QTableWidget *sensors_ = nullptr;
  std::vector<NumField *> fields_;
  bool refreshing_ = false;
};

} // namespace studio

#endif
