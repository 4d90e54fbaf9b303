/*
 * navstudio: the form of the paper's parametric trajectory (formula (3), numerics.md section 3.1):
 *   R(t) = R0 + V0 t + A t^2 + B sin(2 pi C t + D),   omega(t) = a + b sin(2 pi c t + d)
 * Each coefficient is a row of three fields (N, E, D or body x, y, z); angles and rates have a
 * unit selector (rad or deg, rad/s or deg/s) and are converted to the file's unit. While the user
 * types, the edited scene is checked by navcore_io (segment_editor.h: ApplyFieldSets, so the
 * messages are those of `navsim check`) and, when valid, shown live in the views after a short
 * pause (kParametricDebounceMs); Enter or leaving the field commits one undo step, an invalid
 * value is not committed and the views return to the last committed state. GUI thread only.
 */
#ifndef NAVSTUDIO_PARAMETRIC_EDITOR_H
#define NAVSTUDIO_PARAMETRIC_EDITOR_H

#include <QTimer>
#include <QWidget>

#include <memory>
#include <vector>

#include "segment_editor.h"
#include "studio_scene.h"

class QComboBox;
class QLabel;
class QLineEdit;

namespace studio {

/** Pause after the last keystroke before the path preview is redrawn [ms]. */
constexpr int kParametricDebounceMs = 150;

class ParametricEditor : public QWidget {
  Q_OBJECT
public:
  explicit ParametricEditor(SceneDocument *doc, QWidget *parent = nullptr);
  void Refresh();
  /** The message shown for the current edits ("" when valid). */
  QString Message() const;
  /** Live previews shown so far (tests). */
  int PreviewCount() const { return previews_; }

private:
  struct Field {
    QString path;   /**< scene-file path in SI spelling ("trajectory.parametric.D_rad[1]") */
    QString label;  /**< "D (E)" */
    int row = 0;    /**< coefficient row (unit selector) */
    size_t offset = 0; /**< of the double in nav_scene */
    bool is_int = false;
    QLineEdit *edit = nullptr;
  };
  struct Row {
    QComboBox *unit = nullptr; /**< null: a single unit */
    double scale = 1.0;        /**< the first unit -> SI (the scene table's scale of the key) */
    double alt_scale = 1.0;    /**< the second unit (deg) -> SI */
  };
  double Scale(const Field &f) const;
  QVector<FieldSet> Sets() const;
  bool Check(nav_scene *out, QVector<Issue> *issues) const;
  void ShowIssues(const QVector<Issue> &issues);
  void OnEdited();
  void OnPreview();
  void OnCommit();

  SceneDocument *doc_;
  std::vector<Field> fields_;
  std::vector<Row> rows_;
  QLabel *msg_ = nullptr, *summary_ = nullptr;
  QTimer debounce_;
  std::unique_ptr<nav_scene> before_; /**< the scene when the live edit started */
  int previews_ = 0;
  bool self_ = false; /**< our own Preview/Commit is being applied */
};

} // namespace studio

#endif
