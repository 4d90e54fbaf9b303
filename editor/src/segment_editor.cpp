#include "segment_editor.h"
#include "schema_fields.h"
#include "parametric_editor.h"

#include <QCheckBox>
#include <QComboBox>
#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFormLayout>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QScrollArea>
#include <QStackedWidget>
#include <QStandardItemModel>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>
#include <climits>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <memory>

extern "C" {
#include "navcore/nav_io.h"
#include "navcore/nav_scene_override.h"
}

namespace studio {

namespace {
const char *kErrorStyle = "QLineEdit { border: 2px solid #d03030; background: #fff0f0; }";
constexpr double kDeg = M_PI / 180.0;

void CollectDiag(void *user, const nav_diag *d) {
  static_cast<QVector<Issue> *>(user)->push_back(Issue{QString::fromUtf8(d->path), QString::fromUtf8(d->message)});
}

/* The segment kinds as the scene file names them (index = nav_segment_kind). */
const char *const kKindNames[] = {"hold",           "accelerate",     "turn",          "coordinated_turn",
                                  "climb",          "circle",         "figure_eight",  "helix",
                                  "lawnmower",      "motion_rates",   "motion_abs_abs", "motion_rel_rel",
                                  "motion_abs_rel", "motion_rel_abs"};
constexpr int kKindCount = static_cast<int>(sizeof kKindNames / sizeof kKindNames[0]);

struct Spec {
  const char *key; // the scene key (its unit and scale come from navcore_io's table: KeyOf)
  const char *label;
  size_t offset;
  bool is_int;
};

#define SEG(m) offsetof(nav_segment, m)
#define SEGV(m, k) (offsetof(nav_segment, m) + (k) * sizeof(double))

/* The keys of each kind as navcore_io reads and writes them (scene_traj_io.c), in its units. */
std::vector<Spec> SpecsOf(int kind) {
  const Spec duration{"duration_s", "Duration", SEG(duration_s), false};
  const Spec yaw{"yaw_deg", "Yaw", SEG(yaw_rad), false};
  const Spec pitch{"pitch_deg", "Pitch", SEG(pitch_rad), false};
  const Spec roll{"roll_deg", "Roll", SEG(roll_rad), false};
  const Spec yaw_rate{"yaw_rate_dps", "Yaw rate", SEG(yaw_rate_rps), false};
  const Spec radius{"radius_m", "Radius", SEG(radius_m), false};
  const Spec turns{"turns", "Turns", SEG(turns), false};
  switch (kind) {
  case NAV_SEG_HOLD: return {duration};
  case NAV_SEG_ACCELERATE: return {{"speed_mps", "Speed", SEG(speed_mps), false}};
  case NAV_SEG_TURN:
  case NAV_SEG_COORD_TURN: return {yaw, yaw_rate};
  case NAV_SEG_CLIMB: return {{"height_m", "Height change", SEG(height_m), false}, pitch};
  case NAV_SEG_CIRCLE:
  case NAV_SEG_FIGURE_EIGHT: return {radius, turns};
  case NAV_SEG_HELIX: return {radius, turns, pitch};
  case NAV_SEG_LAWNMOWER:
    return {{"legs", "Legs", SEG(legs), true},
            {"length_m", "Leg length", SEG(length_m), false},
            {"spacing_m", "Spacing", SEG(spacing_m), false}};
  case NAV_SEG_MOTION_RATES:
    return {yaw_rate,
            {"pitch_rate_dps", "Pitch rate", SEG(pitch_rate_rps), false},
            {"roll_rate_dps", "Roll rate", SEG(roll_rate_rps), false},
            {"accel_b_mps2[0]", "Accel. x", SEGV(accel_b_mps2, 0), false},
            {"accel_b_mps2[1]", "Accel. y", SEGV(accel_b_mps2, 1), false},
            {"accel_b_mps2[2]", "Accel. z", SEGV(accel_b_mps2, 2), false},
            duration};
  default: // MOTION_ABS_ABS .. REL_ABS
    return {yaw,
            pitch,
            roll,
            {"v_b_mps[0]", "Velocity x", SEGV(v_b_mps, 0), false},
            {"v_b_mps[1]", "Velocity y", SEGV(v_b_mps, 1), false},
            {"v_b_mps[2]", "Velocity z", SEGV(v_b_mps, 2), false},
            duration};
  }
}

/* The table's path of scene key @p key (its "[i]" component index dropped) under @p prefix. */
QByteArray KeyOf(const char *prefix, const char *key) {
  QByteArray k(key);
  const int br = k.indexOf('[');
  if (br >= 0) k.truncate(br);
  return QByteArray(prefix) + k;
}

/* The same for a key of a segment of kind @p kind ("trajectory.segments.items[circle].radius_m"). */
QByteArray ItemKeyOf(int kind, const char *key) {
  const char *name = kind >= 0 && kind < kKindCount ? kKindNames[kind] : "hold";
  return KeyOf((QByteArray("trajectory.segments.items[") + name + "].").constData(), key);
}

bool HasCoordinated(int kind) { return kind != NAV_SEG_HOLD && kind != NAV_SEG_ACCELERATE && kind != NAV_SEG_COORD_TURN && kind != NAV_SEG_CLIMB; }

/* A new item of @p kind keeps what it shares with the old one and gets a small valid default
   where its main values are zero. */
void SetKind(nav_segment &g, int kind) {
  g.kind = static_cast<nav_segment_kind>(kind);
  auto dflt = [](double &v, double d) {
    if (v == 0.0) v = d;
  };
  switch (kind) {
  case NAV_SEG_HOLD: dflt(g.duration_s, 10.0); break;
  case NAV_SEG_ACCELERATE: dflt(g.speed_mps, 10.0); break;
  case NAV_SEG_TURN:
  case NAV_SEG_COORD_TURN: dflt(g.yaw_rad, 90.0 * kDeg); break;
  case NAV_SEG_CLIMB:
    dflt(g.height_m, 20.0);
    dflt(g.pitch_rad, 5.0 * kDeg);
    break;
  case NAV_SEG_CIRCLE:
  case NAV_SEG_FIGURE_EIGHT:
    dflt(g.radius_m, 100.0);
    dflt(g.turns, 1.0);
    break;
  case NAV_SEG_HELIX:
    dflt(g.radius_m, 100.0);
    dflt(g.turns, 1.0);
    dflt(g.pitch_rad, 5.0 * kDeg);
    break;
  case NAV_SEG_LAWNMOWER:
    if (g.legs < 1) g.legs = 4;
    dflt(g.length_m, 500.0);
    dflt(g.spacing_m, 100.0);
    break;
  default: dflt(g.duration_s, 10.0); break;
  }
}

nav_segment HoldItem(double s) {
  nav_segment g;
  std::memset(&g, 0, sizeof g);
  g.kind = NAV_SEG_HOLD;
  g.gnss_visible = true;
  g.duration_s = s;
  return g;
}

} // namespace

QString FieldNumber(double v) {
  if (!std::isfinite(v)) return QString::number(v);
  if (v == 0.0) return QStringLiteral("0"); // also -0
  return QString::number(v, 'g', 10);
}

bool SameFieldNumber(const QString &text, double v) {
  bool ok = false;
  const double t = text.trimmed().toDouble(&ok);
  return ok && (t == v || FieldNumber(t) == FieldNumber(v));
}

QWidget *ScrolledPanel(QWidget *inner) {
  auto *sa = new QScrollArea;
  sa->setWidget(inner);
  sa->setWidgetResizable(true);
  sa->setFrameShape(QFrame::NoFrame);
  sa->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  return sa;
}

bool ApplyFieldSets(const nav_scene &base, const QVector<FieldSet> &sets, nav_scene *out, QVector<Issue> *issues) {
  // The edit goes through navcore's writer, the override document and the reader, in memory.
  QVector<Issue> found;
  char *text = nullptr;
  size_t len = 0;
  if (nav_scene_write_string(&base, &text, &len) != NAV_OK) {
    if (issues) issues->push_back(Issue{QString(), QStringLiteral("cannot write the scene to check the edit")});
    return false;
  }
  nav_scene_doc *doc = nullptr;
  char msg[512] = "";
  const nav_status load = nav_scene_doc_load_string(text, len, "navstudio", &doc, msg, sizeof msg);
  std::free(text);
  if (load != NAV_OK) {
    if (issues) issues->push_back(Issue{QString(), QString::fromUtf8(msg)});
    return false;
  }
  bool ok = true;
  for (const FieldSet &fs : sets) {
    const QByteArray p = fs.first.toUtf8(), v = fs.second.toUtf8();
    if (nav_scene_doc_set(doc, p.constData(), v.constData(), msg, sizeof msg) != NAV_OK) {
      found.push_back(Issue{fs.first, QString::fromUtf8(msg)});
      ok = false;
    }
  }
  auto s = std::make_unique<nav_scene>();
  if (ok && nav_scene_doc_read(doc, s.get(), CollectDiag, &found) != NAV_OK) ok = false;
  nav_scene_doc_destroy(doc);
  if (!ok) {
    if (found.isEmpty()) found.push_back(Issue{QString(), QStringLiteral("the edited scene cannot be read")});
    if (issues) *issues = found;
    return false;
  }
  KeepSceneData(*s); // *out is copied as plain bytes (undo, workers)
  Normalize(s.get());
  *out = *s;
  if (issues) issues->clear();
  return true;
}

/* ---------------------------------------------------------------- SegmentEditor */

SegmentEditor::SegmentEditor(SceneDocument *doc, QWidget *parent) : QWidget(parent), doc_(doc) {
  setObjectName("segmentEditor");
  auto *vl = new QVBoxLayout(this);
  summary_ = new QLabel;
  summary_->setObjectName("segSummary");
  summary_->setWordWrap(true);
  vl->addWidget(summary_);

  table_ = new QTableWidget(0, 2);
  table_->setObjectName("segmentTable");
  table_->setHorizontalHeaderLabels({tr("kind"), tr("parameters")});
  table_->horizontalHeader()->setSectionResizeMode(0, QHeaderView::ResizeToContents);
  table_->horizontalHeader()->setSectionResizeMode(1, QHeaderView::Stretch);
  table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  table_->setSelectionMode(QAbstractItemView::SingleSelection);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  table_->setMinimumHeight(150);
  vl->addWidget(table_, 1);
  connect(table_, &QTableWidget::currentCellChanged, this, [this](int row, int, int, int) {
    if (refreshing_ || row < 0) return;
    current_ = row;
    Refresh();
  });

  auto *row = new QHBoxLayout;
  add_ = new QPushButton(tr("Add"));
  insert_ = new QPushButton(tr("Insert"));
  del_ = new QPushButton(tr("Delete"));
  up_ = new QPushButton(tr("Up"));
  down_ = new QPushButton(tr("Down"));
  add_->setObjectName("segAdd");
  insert_->setObjectName("segInsert");
  del_->setObjectName("segDelete");
  up_->setObjectName("segUp");
  down_->setObjectName("segDown");
  add_->setToolTip(tr("Add a 10 s hold after the selected segment"));
  insert_->setToolTip(tr("Insert a 10 s hold before the selected segment"));
  for (auto *b : {add_, insert_, del_, up_, down_}) row->addWidget(b);
  vl->addLayout(row);
  // Add (after the selection) and Insert (before it) put a 10 s hold at index `at`.
  auto insert_hold = [this](const QString &label, int at) {
    EditItems(label.arg(at), [at](nav_traj_segments &S) {
      if (S.count >= NAV_MAX_SEGMENTS) return;
      std::memmove(&S.items[at + 1], &S.items[at], sizeof(nav_segment) * static_cast<size_t>(S.count - at));
      S.items[at] = HoldItem(10.0);
      ++S.count;
    }, at);
  };
  connect(add_, &QPushButton::clicked, this, [this, insert_hold] {
    const int n = doc_->Scene().trajectory.segments.count;
    insert_hold(tr("Add segment %1"), n == 0 ? 0 : std::min(current_ + 1, n));
  });
  connect(insert_, &QPushButton::clicked, this, [this, insert_hold] {
    insert_hold(tr("Insert segment %1"), std::clamp(current_, 0, doc_->Scene().trajectory.segments.count));
  });
  connect(del_, &QPushButton::clicked, this, [this] {
    const int n = doc_->Scene().trajectory.segments.count;
    const int at = current_;
    if (n <= 1 || at < 0 || at >= n) return; // a script has at least one segment
    EditItems(tr("Delete segment %1").arg(at), [at](nav_traj_segments &S) {
      std::memmove(&S.items[at], &S.items[at + 1], sizeof(nav_segment) * static_cast<size_t>(S.count - at - 1));
      --S.count;
      S.items[S.count] = HoldItem(0.0); // what an unused slot holds (nav_scene_default)
    }, std::min(at, n - 2));
  });
  auto move = [this](int dir) {
    const int n = doc_->Scene().trajectory.segments.count;
    const int at = current_, to = current_ + dir;
    if (at < 0 || to < 0 || at >= n || to >= n) return;
    EditItems(tr("Move segment %1").arg(at),
              [at, to](nav_traj_segments &S) { std::swap(S.items[at], S.items[to]); }, to);
  };
  connect(up_, &QPushButton::clicked, this, [move] { move(-1); });
  connect(down_, &QPushButton::clicked, this, [move] { move(+1); });

  // The selected item: kind, flags, and the keys of its kind.
  auto *item_box = new QGroupBox(tr("Selected segment"));
  auto *ib = new QVBoxLayout(item_box);
  auto *kr = new QHBoxLayout;
  kind_ = new QComboBox;
  kind_->setObjectName("segKind");
  for (int k = 0; k < kKindCount; ++k) kind_->addItem(QString::fromLatin1(kKindNames[k]));
  coordinated_ = new QCheckBox(tr("coordinated"));
  coordinated_->setObjectName("segCoordinated");
  coordinated_->setToolTip(tr("bank into turns (roll = atan(V yaw rate / g))"));
  gnss_visible_ = new QCheckBox(tr("GNSS visible"));
  gnss_visible_->setObjectName("segGnssVisible");
  kr->addWidget(kind_, 1);
  kr->addWidget(coordinated_);
  kr->addWidget(gnss_visible_);
  ib->addLayout(kr);
  form_host_ = new QWidget;
  form_ = new QFormLayout(form_host_);
  form_->setContentsMargins(0, 0, 0, 0);
  ib->addWidget(form_host_);
  msg_ = new QLabel;
  msg_->setObjectName("segMessage");
  msg_->setWordWrap(true);
  msg_->setStyleSheet("color: #c02020; font-size: 9pt;");
  msg_->hide();
  ib->addWidget(msg_);
  vl->addWidget(item_box);
  connect(kind_, QOverload<int>::of(&QComboBox::activated), this, [this](int k) {
    const int i = current_;
    if (i < 0 || i >= doc_->Scene().trajectory.segments.count) return;
    if (static_cast<int>(doc_->Scene().trajectory.segments.items[i].kind) == k) return;
    EditItems(tr("Segment %1: %2").arg(i).arg(QString::fromLatin1(kKindNames[k])),
              [i, k](nav_traj_segments &S) { SetKind(S.items[i], k); }, i);
  });
  auto flag = [this](QCheckBox *c, bool nav_segment::*m, const QString &what) {
    connect(c, &QCheckBox::toggled, this, [this, m, what](bool on) {
      if (refreshing_) return;
      const int i = current_;
      if (i < 0 || i >= doc_->Scene().trajectory.segments.count) return;
      EditItems(tr("Segment %1: %2").arg(i).arg(what), [i, m, on](nav_traj_segments &S) { S.items[i].*m = on; }, i);
    });
  };
  flag(coordinated_, &nav_segment::coordinated, tr("coordinated"));
  flag(gnss_visible_, &nav_segment::gnss_visible, tr("GNSS visible"));

  // The script: start state and vehicle limits.
  auto *start_box = new QGroupBox(tr("Start and vehicle limits"));
  auto *grid = new QGridLayout(start_box);
  struct StartSpec {
    const char *key;
    const char *label;
    size_t offset;
    bool optional;
  };
  const StartSpec starts[] = {
      {"r0_ned_m[0]", "Start N", offsetof(nav_traj_segments, r0_ned_m) + 0 * sizeof(double), false},
      {"r0_ned_m[1]", "Start E", offsetof(nav_traj_segments, r0_ned_m) + 1 * sizeof(double), false},
      {"r0_ned_m[2]", "Start D", offsetof(nav_traj_segments, r0_ned_m) + 2 * sizeof(double), false},
      {"v0_b_mps[0]", "Start vx", offsetof(nav_traj_segments, v0_b_mps) + 0 * sizeof(double), false},
      {"v0_b_mps[1]", "Start vy", offsetof(nav_traj_segments, v0_b_mps) + 1 * sizeof(double), false},
      {"v0_b_mps[2]", "Start vz", offsetof(nav_traj_segments, v0_b_mps) + 2 * sizeof(double), false},
      {"limits.max_accel_mps2", "Max accel.",
       offsetof(nav_traj_segments, limits) + offsetof(nav_traj_limits, max_accel_mps2), true},
      {"limits.max_jerk_mps3", "Max jerk",
       offsetof(nav_traj_segments, limits) + offsetof(nav_traj_limits, max_jerk_mps3), true},
      {"limits.max_lateral_accel_mps2", "Max lateral",
       offsetof(nav_traj_segments, limits) + offsetof(nav_traj_limits, max_lateral_accel_mps2), true},
      {"limits.max_rate_dps", "Max rate",
       offsetof(nav_traj_segments, limits) + offsetof(nav_traj_limits, max_rate_rps), true},
      {"limits.max_ang_accel_dps2", "Max ang. acc.",
       offsetof(nav_traj_segments, limits) + offsetof(nav_traj_limits, max_ang_accel_rps2), true},
      {"limits.max_ang_jerk_dps3", "Max ang. jerk",
       offsetof(nav_traj_segments, limits) + offsetof(nav_traj_limits, max_ang_jerk_rps3), true},
  };
  int k = 0;
  for (const StartSpec &ss : starts) {
    Field f;
    f.key = QString::fromLatin1(ss.key);
    f.label = tr(ss.label);
    const nav_schema_key &sk = SchemaKey(KeyOf("trajectory.segments.", ss.key).constData());
    f.unit = DisplayUnit(sk.unit);
    f.offset = ss.offset;
    f.scale = sk.scale;
    f.item = false;
    f.optional = ss.optional;
    f.edit = new QLineEdit;
    f.edit->setObjectName("seg." + f.key);
    f.edit->setToolTip(tr("%1 [%2] (scene file: trajectory.segments.%3)").arg(f.label, f.unit, f.key));
    if (f.optional) f.edit->setPlaceholderText(tr("none"));
    const int r = k / 3, c = k % 3;
    grid->addWidget(new QLabel(f.label + (f.unit.isEmpty() ? QString() : " [" + f.unit + "]")), 2 * r, c);
    grid->addWidget(f.edit, 2 * r + 1, c);
    const int idx = -1 - static_cast<int>(start_.size());
    connect(f.edit, &QLineEdit::textEdited, this, [this, idx] { OnEdited(idx); });
    connect(f.edit, &QLineEdit::editingFinished, this, [this, idx] { OnCommit(idx); });
    start_.push_back(f);
    ++k;
  }
  vl->addWidget(start_box);
  connect(doc_, &SceneDocument::Changed, this, &SegmentEditor::Refresh);
  Refresh();
}

double SegmentEditor::ValueOf(const Field &f, const nav_scene &s) const {
  const nav_traj_segments &S = s.trajectory.segments;
  const char *base = f.item ? reinterpret_cast<const char *>(&S.items[std::clamp(current_, 0, NAV_MAX_SEGMENTS - 1)])
                            : reinterpret_cast<const char *>(&S);
  if (f.is_int) {
    int v = 0;
    std::memcpy(&v, base + f.offset, sizeof v);
    return v;
  }
  double v = 0.0;
  std::memcpy(&v, base + f.offset, sizeof v);
  return v / f.scale;
}

QString SegmentEditor::PathOf(const Field &f) const {
  return f.item ? QStringLiteral("trajectory.segments.items[%1].%2").arg(current_).arg(f.key)
                : QStringLiteral("trajectory.segments.%1").arg(f.key);
}

QVector<FieldSet> SegmentEditor::SetsOf(int field) const {
  const Field &f = FieldAt(field);
  return {FieldSet{PathOf(f), f.edit->text().trimmed()}};
}

QString SegmentEditor::Message() const { return msg_->isVisible() ? msg_->text() : QString(); }

void SegmentEditor::ShowIssues(const QVector<Issue> &issues, int field) {
  QStringList lines;
  for (const Issue &i : issues) lines << i.Text();
  msg_->setText(lines.join("\n"));
  msg_->setVisible(!lines.isEmpty());
  if (field != INT32_MIN) FieldAt(field).edit->setStyleSheet(lines.isEmpty() ? QString() : QString(kErrorStyle));
}

void SegmentEditor::OnEdited(int field) {
  const Field &f = FieldAt(field);
  if (f.optional && f.edit->text().trimmed().isEmpty()) {
    ShowIssues({}, field);
    return;
  }
  auto out = std::make_unique<nav_scene>();
  QVector<Issue> issues;
  if (!ApplyFieldSets(doc_->Scene(), SetsOf(field), out.get(), &issues)) {
    ShowIssues(issues, field);
    return;
  }
  // Valid for the reader; the planner may still refuse the script (shown, not blocking).
  QString plan;
  if (!UpdateDuration(out.get(), &plan))
    ShowIssues({Issue{QStringLiteral("trajectory.segments"), plan}}, INT32_MIN);
  else
    ShowIssues({}, field);
}

void SegmentEditor::OnCommit(int field) {
  if (refreshing_) return;
  Field &f = FieldAt(field);
  if (!f.edit->isModified()) return;
  const nav_scene &cur = doc_->Scene();
  const QString text = f.edit->text().trimmed();
  if (f.item && (current_ < 0 || current_ >= cur.trajectory.segments.count)) return;
  const QString what = f.item ? tr("Segment %1: %2").arg(current_).arg(f.key) : tr("Segments: %1").arg(f.key);
  if (f.optional && text.isEmpty()) {
    const size_t off = f.offset;
    doc_->Edit(tr("%1 off").arg(what), [off](nav_scene &s) {
      const double zero = 0.0;
      std::memcpy(reinterpret_cast<char *>(&s.trajectory.segments) + off, &zero, sizeof zero);
    });
    f.edit->setModified(false);
    ShowIssues({}, field);
    return;
  }
  if (SameFieldNumber(text, ValueOf(f, cur))) {
    f.edit->setModified(false);
    return;
  }
  auto out = std::make_unique<nav_scene>();
  QVector<Issue> issues;
  if (!ApplyFieldSets(cur, SetsOf(field), out.get(), &issues)) {
    ShowIssues(issues, field); // the message stays; nothing is committed
    return;
  }
  f.edit->setModified(false);
  ShowIssues({}, field);
  const nav_scene *o = out.get();
  doc_->Edit(what, [o](nav_scene &s) { s.trajectory.segments = o->trajectory.segments; });
}

void SegmentEditor::EditItems(const QString &text, const std::function<void(nav_traj_segments &)> &fn, int select) {
  current_ = select;
  doc_->Edit(text, [&fn](nav_scene &s) { fn(s.trajectory.segments); });
  Refresh();
}

void SegmentEditor::SelectItem(int i) {
  current_ = i;
  Refresh();
}

void SegmentEditor::RebuildForm() {
  while (form_->rowCount() > 0) form_->removeRow(0);
  fields_.clear();
  if (form_kind_ < 0) return;
  for (const Spec &sp : SpecsOf(form_kind_)) {
    Field f;
    f.key = QString::fromLatin1(sp.key);
    f.label = tr(sp.label);
    const nav_schema_key &sk = SchemaKey(ItemKeyOf(form_kind_, sp.key).constData());
    f.unit = DisplayUnit(sk.unit);
    f.offset = sp.offset;
    f.scale = sk.scale;
    f.is_int = sp.is_int;
    f.item = true;
    auto *w = new QWidget;
    auto *h = new QHBoxLayout(w);
    h->setContentsMargins(0, 0, 0, 0);
    f.edit = new QLineEdit;
    f.edit->setObjectName("seg." + f.key);
    f.edit->setToolTip(tr("%1 [%2] (scene file: trajectory.segments.items[i].%3)").arg(f.label, f.unit, f.key));
    h->addWidget(f.edit, 1);
    auto *u = new QLabel(f.unit);
    u->setMinimumWidth(48);
    h->addWidget(u);
    form_->addRow(f.label, w);
    const int idx = static_cast<int>(fields_.size());
    connect(f.edit, &QLineEdit::textEdited, this, [this, idx] { OnEdited(idx); });
    connect(f.edit, &QLineEdit::editingFinished, this, [this, idx] { OnCommit(idx); });
    fields_.push_back(f);
  }
}

void SegmentEditor::Refresh() {
  const bool prev = refreshing_;
  refreshing_ = true;
  const nav_scene &s = doc_->Scene();
  const nav_traj_segments &S = s.trajectory.segments;
  const int n = s.trajectory.type == NAV_TRAJ_SEGMENTS ? std::max(0, S.count) : 0;
  if (current_ >= n) current_ = n - 1;
  if (current_ < 0 && n > 0) current_ = 0;

  table_->blockSignals(true);
  table_->setRowCount(n);
  QStringList rows;
  for (int i = 0; i < n; ++i) rows << QString::number(i); // 0-based, as navcore's messages count them
  table_->setVerticalHeaderLabels(rows);
  for (int i = 0; i < n; ++i) {
    const nav_segment &g = S.items[i];
    const int kind = static_cast<int>(g.kind);
    QStringList parts;
    if (kind >= 0 && kind < kKindCount) {
      for (const Spec &sp : SpecsOf(kind)) {
        double v = 0.0;
        if (sp.is_int) {
          int iv = 0;
          std::memcpy(&iv, reinterpret_cast<const char *>(&g) + sp.offset, sizeof iv);
          v = iv;
        } else {
          std::memcpy(&v, reinterpret_cast<const char *>(&g) + sp.offset, sizeof v);
          v /= SchemaKey(ItemKeyOf(kind, sp.key).constData()).scale;
        }
        parts << QStringLiteral("%1: %2").arg(QString::fromLatin1(sp.key), FieldNumber(v));
      }
      if (g.coordinated && HasCoordinated(kind)) parts << QStringLiteral("coordinated");
      if (!g.gnss_visible) parts << QStringLiteral("no GNSS");
    }
    const QString kn = kind >= 0 && kind < kKindCount ? QString::fromLatin1(kKindNames[kind]) : QStringLiteral("?");
    for (int c = 0; c < 2; ++c) {
      const QString t = c == 0 ? kn : parts.join(", ");
      QTableWidgetItem *it = table_->item(i, c);
      if (!it) table_->setItem(i, c, it = new QTableWidgetItem);
      if (it->text() != t) it->setText(t);
    }
  }
  if (n > 0) table_->setCurrentCell(current_, 0);
  table_->blockSignals(false);

  const int kind = n > 0 ? static_cast<int>(S.items[current_].kind) : -1;
  if (kind != form_kind_ || fields_.empty() != (kind < 0)) {
    form_kind_ = kind;
    RebuildForm();
    ShowIssues({}, INT32_MIN);
  }
  auto show = [&](Field &f) {
    if (f.edit->hasFocus() && f.edit->isModified()) return; // the user is typing there
    if (f.edit->isModified()) msg_->hide(); // an abandoned invalid value: the document's is shown
    const double v = ValueOf(f, s);
    const QString t = f.optional && v == 0.0 ? QString() : FieldNumber(v);
    if (f.edit->text() != t) f.edit->setText(t);
    f.edit->setModified(false);
    f.edit->setStyleSheet(QString());
  };
  for (Field &f : fields_) show(f);
  for (Field &f : start_) show(f);
  kind_->setEnabled(n > 0);
  if (kind >= 0) kind_->setCurrentIndex(kind);
  coordinated_->setEnabled(kind >= 0 && HasCoordinated(kind));
  coordinated_->setChecked(kind >= 0 && S.items[current_].coordinated);
  gnss_visible_->setEnabled(kind >= 0);
  gnss_visible_->setChecked(kind >= 0 && S.items[current_].gnss_visible);
  del_->setEnabled(n > 1);
  up_->setEnabled(current_ > 0);
  down_->setEnabled(current_ >= 0 && current_ + 1 < n);

  const QString plan = doc_->PlanMessage();
  if (s.trajectory.type != NAV_TRAJ_SEGMENTS) {
    summary_->setText(tr("Not a segment script."));
    summary_->setStyleSheet("color: #555;");
  } else if (plan.isEmpty()) {
    summary_->setText(tr("%n segment(s), %1 s of motion within the vehicle limits.", nullptr, n)
                          .arg(s.trajectory.duration_s, 0, 'f', 1));
    summary_->setStyleSheet("color: #207020;");
  } else {
    summary_->setText(tr("Not feasible: %1").arg(plan));
    summary_->setStyleSheet("color: #c02020;");
  }
  refreshing_ = prev;
}

/* ---------------------------------------------------------------- TrajectoryEditors */

TrajectoryEditors::TrajectoryEditors(SceneDocument *doc, QWidget *waypoints, QWidget *parent)
    : QWidget(parent), doc_(doc), waypoints_(waypoints) {
  setObjectName("trajectoryEditors");
  auto *vl = new QVBoxLayout(this);
  vl->setContentsMargins(0, 0, 0, 0);
  auto *row = new QHBoxLayout;
  row->setContentsMargins(6, 6, 6, 0);
  row->addWidget(new QLabel(tr("Type")));
  type_ = new QComboBox;
  type_->setObjectName("trajectoryType");
  for (int t = 0; t <= static_cast<int>(NAV_TRAJ_RECORDED); ++t) {
    type_->addItem(QString::fromUtf8(nav_traj_type_name(static_cast<nav_traj_type>(t))), t);
    // Test motions and recorded references come from scene files and imports: shown, not chosen.
    if (t != NAV_TRAJ_WAYPOINTS && t != NAV_TRAJ_SEGMENTS && t != NAV_TRAJ_PARAMETRIC)
      if (auto *m = qobject_cast<QStandardItemModel *>(type_->model())) m->item(type_->count() - 1)->setEnabled(false);
  }
  row->addWidget(type_, 1);
  vl->addLayout(row);
  stack_ = new QStackedWidget;
  segments_ = new SegmentEditor(doc_);
  parametric_ = new ParametricEditor(doc_);
  other_ = new QLabel;
  other_->setObjectName("trajectoryOther");
  other_->setWordWrap(true);
  other_->setAlignment(Qt::AlignTop | Qt::AlignLeft);
  other_->setMargin(8);
  stack_->addWidget(waypoints_);            // 0
  stack_->addWidget(ScrolledPanel(segments_));   // 1
  stack_->addWidget(ScrolledPanel(parametric_)); // 2
  stack_->addWidget(other_);                // 3
  vl->addWidget(stack_, 1);
  connect(type_, QOverload<int>::of(&QComboBox::activated), this, [this](int idx) {
    const int t = type_->itemData(idx).toInt();
    if (t == static_cast<int>(doc_->Scene().trajectory.type)) return;
    if (t != NAV_TRAJ_WAYPOINTS && t != NAV_TRAJ_SEGMENTS && t != NAV_TRAJ_PARAMETRIC) {
      Refresh(); // test motions and recorded references come from scene files or imports
      return;
    }
    doc_->Edit(tr("Trajectory type: %1").arg(type_->itemText(idx)), [t](nav_scene &s) {
      s.trajectory.type = static_cast<nav_traj_type>(t);
      if (t == NAV_TRAJ_SEGMENTS && s.trajectory.segments.count < 1) {
        nav_traj_segments &S = s.trajectory.segments;
        S.count = 4;
        S.items[0] = HoldItem(10.0);
        S.items[1] = HoldItem(0.0);
        SetKind(S.items[1], NAV_SEG_ACCELERATE);
        S.items[2] = HoldItem(0.0);
        SetKind(S.items[2], NAV_SEG_TURN);
        S.items[3] = HoldItem(30.0);
      }
      if (t == NAV_TRAJ_PARAMETRIC && !(s.trajectory.duration_s > 0.0)) s.trajectory.duration_s = 60.0;
    });
  });
  connect(doc_, &SceneDocument::Changed, this, &TrajectoryEditors::Refresh);
  Refresh();
}

void TrajectoryEditors::Refresh() {
  const int t = static_cast<int>(doc_->Scene().trajectory.type);
  type_->blockSignals(true);
  type_->setCurrentIndex(type_->findData(t));
  type_->blockSignals(false);
  switch (t) {
  case NAV_TRAJ_WAYPOINTS: stack_->setCurrentIndex(0); break;
  case NAV_TRAJ_SEGMENTS: stack_->setCurrentIndex(1); break;
  case NAV_TRAJ_PARAMETRIC: stack_->setCurrentIndex(2); break;
  default:
    other_->setText(tr("Trajectory type %1: edited in the scene file (the path is drawn in the views).")
                        .arg(QString::fromUtf8(nav_traj_type_name(static_cast<nav_traj_type>(t)))));
    stack_->setCurrentIndex(3);
    break;
  }
}

} // namespace studio
