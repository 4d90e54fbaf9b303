#include "parametric_editor.h"
#include "schema_fields.h"

#include <QComboBox>
#include <QGridLayout>
#include <QLabel>
#include <QLineEdit>
#include <QVBoxLayout>

#include <cmath>
#include <cstddef>
#include <cstring>

namespace studio {

namespace {
const char *kErrorStyle = "QLineEdit { border: 2px solid #d03030; background: #fff0f0; }";

struct RowSpec {
  const char *key;   /* file key in SI spelling, relative to trajectory.parametric */
  const char *label; /* symbol of formula (3) */
  const char *alt;   /* the key in a second unit (deg), or null; units and scales: the scene table */
  size_t offset;     /* of the nav_vec3 in nav_scene */
  const char *tip;
};

#define POFF(m) offsetof(nav_scene, trajectory.parametric.m)

const RowSpec kRows[] = {
    {"R0_m", "R0", nullptr, POFF(r0_m), "start position (N, E, D)"},
    {"V0_mps", "V0", nullptr, POFF(v0_mps), "start velocity"},
    {"A_mps2", "A", nullptr, POFF(a_mps2), "R contains A t², so the acceleration is 2A"},
    {"B_m", "B", nullptr, POFF(b_m), "amplitude of the sine term of R"},
    {"C_hz", "C", nullptr, POFF(c_hz), "frequency of the sine term of R"},
    {"D_rad", "D", "D_deg", POFF(d_rad), "phase of the sine term of R"},
    {"rate.a_rps", "a", "rate.a_dps", POFF(wa_rps), "constant body rate (x, y, z)"},
    {"rate.b_rps", "b", "rate.b_dps", POFF(wb_rps), "amplitude of the body-rate sine"},
    {"rate.c_hz", "c", nullptr, POFF(wc_hz), "frequency of the body-rate sine"},
    {"rate.d_rad", "d", "rate.d_deg", POFF(wd_rad), "phase of the body-rate sine"},
};
/* The scene table's key trajectory.parametric.@p key. */
const nav_schema_key &ParKey(const char *key) {
  return SchemaKey((QByteArray("trajectory.parametric.") + key).constData());
}
} // namespace

ParametricEditor::ParametricEditor(SceneDocument *doc, QWidget *parent) : QWidget(parent), doc_(doc) {
  setObjectName("parametricEditor");
  auto *vl = new QVBoxLayout(this);
  auto *formula = new QLabel(tr("<b>R(t) = R0 + V0 t + A t² + B sin(2π C t + D)</b><br>"
                                "<b>ω(t) = a + b sin(2π c t + d)</b> &nbsp;(body rate)<br>"
                                "<span style='color:#555'>per axis: N, E, D for R; body x, y, z for ω</span>"));
  formula->setWordWrap(true);
  vl->addWidget(formula);
  auto *grid = new QGridLayout;
  grid->addWidget(new QLabel(tr("x / N")), 0, 1);
  grid->addWidget(new QLabel(tr("y / E")), 0, 2);
  grid->addWidget(new QLabel(tr("z / D")), 0, 3);
  int r = 1;
  for (const RowSpec &rs : kRows) {
    auto *name = new QLabel(QString::fromUtf8(rs.label));
    name->setToolTip(tr(rs.tip));
    grid->addWidget(name, r, 0);
    Row row;
    if (rs.alt) {
      row.unit = new QComboBox;
      row.unit->setObjectName(QStringLiteral("par.unit.%1").arg(QString::fromLatin1(rs.key)));
      row.unit->addItem(DisplayUnit(ParKey(rs.key).unit));
      row.unit->addItem(DisplayUnit(ParKey(rs.alt).unit));
      row.scale = ParKey(rs.key).scale;
      row.alt_scale = ParKey(rs.alt).scale;
      grid->addWidget(row.unit, r, 4);
      connect(row.unit, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this] {
        // Show the committed values in the chosen unit (a pending edit is dropped).
        for (Field &f : fields_) f.edit->setModified(false);
        Refresh();
      });
    } else {
      grid->addWidget(new QLabel(DisplayUnit(ParKey(rs.key).unit)), r, 4);
      row.scale = ParKey(rs.key).scale;
    }
    const int row_index = static_cast<int>(rows_.size());
    rows_.push_back(row);
    for (int k = 0; k < 3; ++k) {
      Field f;
      f.path = QStringLiteral("trajectory.parametric.%1[%2]").arg(QString::fromLatin1(rs.key)).arg(k);
      f.label = QStringLiteral("%1[%2]").arg(QString::fromUtf8(rs.label)).arg(k);
      f.row = row_index;
      f.offset = rs.offset + static_cast<size_t>(k) * sizeof(double);
      f.edit = new QLineEdit;
      f.edit->setObjectName(QStringLiteral("par.%1[%2]").arg(QString::fromLatin1(rs.key)).arg(k));
      f.edit->setToolTip(tr("%1 (scene file: %2)").arg(tr(rs.tip), f.path));
      f.edit->setMinimumWidth(60);
      grid->addWidget(f.edit, r, 1 + k);
      fields_.push_back(f);
    }
    ++r;
  }
  // Duration and the Magnus sub-steps (one field each).
  Row single;
  const int single_row = static_cast<int>(rows_.size());
  rows_.push_back(single);
  auto add_single = [&](const QString &path, const QString &label, const QString &unit, size_t off, bool is_int) {
    grid->addWidget(new QLabel(label), r, 0, 1, 1);
    Field f;
    f.path = path;
    f.label = label;
    f.row = single_row;
    f.offset = off;
    f.is_int = is_int;
    f.edit = new QLineEdit;
    f.edit->setObjectName("par." + path.section('.', -1));
    f.edit->setToolTip(tr("scene file: %1").arg(path));
    grid->addWidget(f.edit, r, 1);
    grid->addWidget(new QLabel(unit), r, 2);
    fields_.push_back(f);
    ++r;
  };
  add_single(QStringLiteral("trajectory.duration_s"), tr("Duration"), QStringLiteral("s"),
             offsetof(nav_scene, trajectory.duration_s), false);
  add_single(QStringLiteral("trajectory.parametric.magnus_substeps"), tr("Magnus sub-steps"), QString(),
             offsetof(nav_scene, trajectory.parametric.magnus_substeps), true);
  vl->addLayout(grid);
  for (size_t i = 0; i < fields_.size(); ++i) {
    connect(fields_[i].edit, &QLineEdit::textEdited, this, &ParametricEditor::OnEdited);
    connect(fields_[i].edit, &QLineEdit::editingFinished, this, &ParametricEditor::OnCommit);
  }
  msg_ = new QLabel;
  msg_->setObjectName("parMessage");
  msg_->setWordWrap(true);
  msg_->setStyleSheet("color: #c02020; font-size: 9pt;");
  msg_->hide();
  vl->addWidget(msg_);
  summary_ = new QLabel;
  summary_->setObjectName("parSummary");
  summary_->setWordWrap(true);
  summary_->setStyleSheet("color: #555;");
  vl->addWidget(summary_);
  vl->addStretch(1);
  debounce_.setSingleShot(true);
  debounce_.setInterval(kParametricDebounceMs);
  connect(&debounce_, &QTimer::timeout, this, &ParametricEditor::OnPreview);
  connect(doc_, &SceneDocument::Changed, this, [this] {
    if (!self_) Refresh();
  });
  Refresh();
}

double ParametricEditor::Scale(const Field &f) const {
  const Row &row = rows_[static_cast<size_t>(f.row)];
  return row.unit && row.unit->currentIndex() == 1 ? row.alt_scale : row.scale;
}

QVector<FieldSet> ParametricEditor::Sets() const {
  // Every field the user changed since the last commit, in the file's SI spelling: a number in
  // the second unit is converted (all digits kept); anything else goes to the reader as typed.
  QVector<FieldSet> sets;
  for (const Field &f : fields_) {
    if (!f.edit->isModified()) continue;
    const QString t = f.edit->text().trimmed();
    const double sc = Scale(f);
    bool ok = false;
    const double v = t.toDouble(&ok);
    sets.push_back(FieldSet{f.path, ok && sc != 1.0 ? QString::number(v * sc, 'g', 17) : t});
  }
  return sets;
}

bool ParametricEditor::Check(nav_scene *out, QVector<Issue> *issues) const {
  const nav_scene &base = before_ ? *before_ : doc_->Scene();
  if (!ApplyFieldSets(base, Sets(), out, issues)) return false;
  QString msg;
  // The reader accepted it; navcore must also be able to build the trajectory (the preview).
  PathSamples probe;
  if (!SamplePath(*out, 2, &probe, &msg)) {
    issues->push_back(Issue{QStringLiteral("trajectory.parametric"), msg});
    return false;
  }
  return true;
}

QString ParametricEditor::Message() const { return msg_->isVisible() ? msg_->text() : QString(); }

void ParametricEditor::ShowIssues(const QVector<Issue> &issues) {
  QStringList lines;
  for (const Issue &i : issues) lines << i.Text();
  msg_->setText(lines.join("\n"));
  msg_->setVisible(!lines.isEmpty());
  for (Field &f : fields_) {
    bool bad = false;
    for (const Issue &i : issues) bad = bad || (f.edit->isModified() && i.path.startsWith(f.path.section('[', 0, 0)));
    f.edit->setStyleSheet(bad ? QString(kErrorStyle) : QString());
  }
}

void ParametricEditor::OnEdited() {
  if (doc_->Scene().trajectory.type != NAV_TRAJ_PARAMETRIC) return;
  if (!before_) before_ = std::make_unique<nav_scene>(doc_->Scene());
  debounce_.start();
}

void ParametricEditor::OnPreview() {
  if (!before_) return;
  auto out = std::make_unique<nav_scene>();
  QVector<Issue> issues;
  if (!Check(out.get(), &issues)) {
    ShowIssues(issues);
    return; // the views keep the last valid state
  }
  ShowIssues({});
  self_ = true;
  doc_->Preview(*out);
  self_ = false;
  ++previews_;
  summary_->setText(tr("Preview (not committed): press Enter to keep it."));
}

void ParametricEditor::OnCommit() {
  debounce_.stop();
  bool any = false;
  for (const Field &f : fields_) any = any || f.edit->isModified();
  if (!any) return;
  if (!before_) before_ = std::make_unique<nav_scene>(doc_->Scene());
  // Values that show what is already there are no edit.
  bool changed = false;
  for (Field &f : fields_) {
    if (!f.edit->isModified()) continue;
    double v = 0.0;
    if (f.is_int) {
      int iv = 0;
      std::memcpy(&iv, reinterpret_cast<const char *>(before_.get()) + f.offset, sizeof iv);
      v = iv;
    } else {
      std::memcpy(&v, reinterpret_cast<const char *>(before_.get()) + f.offset, sizeof v);
      v /= Scale(f);
    }
    if (SameFieldNumber(f.edit->text(), v))
      f.edit->setModified(false);
    else
      changed = true;
  }
  std::unique_ptr<nav_scene> before = std::move(before_);
  if (!changed) {
    if (doc_->IsLive()) { // back to the committed state, no undo step
      self_ = true;
      doc_->Preview(*before);
      doc_->Commit(*before, QString());
      self_ = false;
    }
    Refresh();
    return;
  }
  auto out = std::make_unique<nav_scene>();
  QVector<Issue> issues;
  before_ = std::move(before);
  const bool ok = Check(out.get(), &issues);
  before = std::move(before_);
  if (!ok) {
    ShowIssues(issues); // the message stays; nothing is committed
    if (doc_->IsLive()) {
      self_ = true;
      doc_->Preview(*before);
      doc_->Commit(*before, QString());
      self_ = false;
    }
    return;
  }
  QStringList names;
  for (const Field &f : fields_)
    if (f.edit->isModified()) names << f.label;
  for (Field &f : fields_) f.edit->setModified(false);
  ShowIssues({});
  self_ = true;
  doc_->Preview(*out);
  doc_->Commit(*before, tr("Parametric: %1").arg(names.join(", ")));
  self_ = false;
  Refresh();
}

void ParametricEditor::Refresh() {
  const nav_scene &s = doc_->Scene();
  for (Field &f : fields_) {
    if (f.edit->isModified()) continue; // a pending edit of the user
    double v = 0.0;
    if (f.is_int) {
      int iv = 0;
      std::memcpy(&iv, reinterpret_cast<const char *>(&s) + f.offset, sizeof iv);
      v = iv;
    } else {
      std::memcpy(&v, reinterpret_cast<const char *>(&s) + f.offset, sizeof v);
      v /= Scale(f);
    }
    const QString t = FieldNumber(v);
    if (f.edit->text() != t) f.edit->setText(t);
    f.edit->setStyleSheet(QString());
  }
  if (!before_) {
    msg_->hide();
    summary_->setText(s.trajectory.type == NAV_TRAJ_PARAMETRIC
                          ? tr("%1 s; the views show the path of these coefficients.").arg(s.trajectory.duration_s)
                          : tr("Not a parametric trajectory."));
  }
}

} // namespace studio
