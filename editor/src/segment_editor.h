/*
 * navstudio: the editor of segment scripts (trajectory type "segments": hold, accelerate, turn,
 * climb, circle, helix, lawnmower, motion commands) and the Trajectory panel's stack of editors
 * (waypoints, segments, parametric) chosen by the trajectory type.
 *
 * A field edit is validated by navcore_io itself: the scene is written, the field is set in the
 * parsed document exactly as it would be typed in the file (nav_scene_doc_set, the mechanism of
 * `navsim sweep`), and the document is read by the one scene reader. The messages are therefore
 * those of `navsim check` for that file, at the item and field ("trajectory.segments.items[2].
 * radius_m: must be > 0 (got -5)"). Each valid edit is one undo step; the views redraw the path
 * from the document's Changed signal. GUI thread only.
 */
#ifndef NAVSTUDIO_SEGMENT_EDITOR_H
#define NAVSTUDIO_SEGMENT_EDITOR_H

#include <QPair>
#include <QString>
#include <QVector>
#include <QWidget>

#include <functional>
#include <vector>

#include "studio_scene.h"

class QCheckBox;
class QComboBox;
class QFormLayout;
class QLabel;
class QLineEdit;
class QPushButton;
class QStackedWidget;
class QTableWidget;

namespace studio {

/** One "PATH=VALUE" edit of the scene file (PATH as in nav_scene_override.h). */
using FieldSet = QPair<QString, QString>;

/**
 * Apply @p sets to the scene file of @p base (written by navcore's writer) and read it back with
 * navcore's reader into @p out (normalized). On failure @p issues holds the reader's diagnostics
 * (field path and message, as `navsim check` prints them) and @p out is untouched.
 */
bool ApplyFieldSets(const nav_scene &base, const QVector<FieldSet> &sets, nav_scene *out, QVector<Issue> *issues);

/** Text of a number as the editor shows it (10 significant digits, no trailing zeros). */
QString FieldNumber(double v);
/** Whether a field's @p text already holds @p v (equal, or the same as FieldNumber shows it). */
bool SameFieldNumber(const QString &text, double v);
/** @p inner in a frameless, vertically scrolling area (the panels' tabs and editor pages). */
QWidget *ScrolledPanel(QWidget *inner);

/** Editor of trajectory.segments. */
class SegmentEditor : public QWidget {
  Q_OBJECT
public:
  explicit SegmentEditor(SceneDocument *doc, QWidget *parent = nullptr);
  /** Update from the document (keeps the selected item). */
  void Refresh();
  QTableWidget *Table() { return table_; }
  int CurrentItem() const { return current_; }
  void SelectItem(int i);
  /** The message shown for the current field edits ("" when valid). */
  QString Message() const;

private:
  /** One editable number: a key of the selected item (item) or of the script (start, limits). */
  struct Field {
    QString key;   /**< file key, with [i] for a vector component ("yaw_deg", "v_b_mps[1]") */
    QString label; /**< what the user reads */
    QString unit;
    size_t offset = 0;  /**< of the double (int for legs) in nav_segment or nav_traj_segments */
    double scale = 1.0; /**< file unit -> SI (deg -> rad) */
    bool is_int = false;
    bool item = true;      /**< in nav_segment (else in nav_traj_segments) */
    bool optional = false; /**< a limit: empty = none */
    QLineEdit *edit = nullptr;
  };
  Field &FieldAt(int f) { return f < 0 ? start_[static_cast<size_t>(-f - 1)] : fields_[static_cast<size_t>(f)]; }
  const Field &FieldAt(int f) const {
    return f < 0 ? start_[static_cast<size_t>(-f - 1)] : fields_[static_cast<size_t>(f)];
  }
  double ValueOf(const Field &f, const nav_scene &s) const;
  QString PathOf(const Field &f) const;
  void RebuildForm();
  void OnEdited(int field);
  void OnCommit(int field);
  QVector<FieldSet> SetsOf(int field) const;
  void ShowIssues(const QVector<Issue> &issues, int field);
  void EditItems(const QString &text, const std::function<void(nav_traj_segments &)> &fn, int select);

  SceneDocument *doc_;
  QTableWidget *table_ = nullptr;
  QComboBox *kind_ = nullptr;
  QCheckBox *coordinated_ = nullptr, *gnss_visible_ = nullptr;
  QWidget *form_host_ = nullptr;
  QFormLayout *form_ = nullptr;
  QLabel *msg_ = nullptr, *summary_ = nullptr;
  QPushButton *add_ = nullptr, *insert_ = nullptr, *del_ = nullptr, *up_ = nullptr, *down_ = nullptr;
  std::vector<Field> fields_;     // item fields of the current kind
  std::vector<Field> start_;      // r0, v0 and limits of the script (index -1 - i in the slots)
  int current_ = 0;
  int form_kind_ = -1;
  bool refreshing_ = false;
};

/**
 * The Trajectory panel: a type selector (waypoints, segments, parametric; other types are shown
 * as such) over the editor of that type. Switching the type is one undo step; a script or a
 * parametric trajectory that is empty gets a small valid default.
 */
class TrajectoryEditors : public QWidget {
  Q_OBJECT
public:
  TrajectoryEditors(SceneDocument *doc, QWidget *waypoints, QWidget *parent = nullptr);
  void Refresh();
  SegmentEditor *Segments() { return segments_; }
  QWidget *Parametric() { return parametric_; }

private:
  SceneDocument *doc_;
  QComboBox *type_ = nullptr;
  QStackedWidget *stack_ = nullptr;
  QLabel *other_ = nullptr;
  SegmentEditor *segments_ = nullptr;
  QWidget *parametric_ = nullptr;
  QWidget *waypoints_ = nullptr;
};

} // namespace studio

#endif
