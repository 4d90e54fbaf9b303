#include "array_panel.h"
#include "panels.h"

#include <QComboBox>
#include <QFile>
#include <QFormLayout>
#include <QHeaderView>
#include <QLabel>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>
#include <cstdio>

extern "C" {
#include "navcore/nav_array.h"
#include "navcore/nav_sensors.h"
}

namespace studio {

namespace {
// Three significant digits: datasheet figures are rarely given to more.
QString Fig(double v) {
  return QString::number(v, 'g', 3);
}

void CollectDiag(void *user, const nav_diag *d) {
  char buf[1600];
  nav_diag_format(d, buf, sizeof buf);
  static_cast<QString *>(user)->append(QString::fromUtf8(buf) + "\n");
}

const char *const kLayoutTips[4] = {
    "six sensors at the face centres of a cube, axes along face diagonals",
    "a triad at the centre and two sensors on each axis at the arm length",
    "both face diagonals at each face centre (twelve sensors)",
    "sensors at positions and axes of your own (the table below)",
};
} // namespace

ArrayPanel::ArrayPanel(SceneDocument *doc, QWidget *parent) : QWidget(parent), doc_(doc) {
  setObjectName("arrayPanel");
  const QByteArray path = QFile::encodeName(ResourcesDir() + "/accel_catalog.csv");
  if (nav_catalog_load(path.constData(), nullptr, &parts_, CollectDiag, &load_errors_) != NAV_OK)
    parts_ = nullptr;

  auto *form = new QFormLayout(this);
  auto *intro = new QLabel(tr("Accelerometer array of the gyro-free schemes (gyro_free, gyro_free_gnss)."));
  intro->setWordWrap(true);
  intro->setStyleSheet("color: #555; font-size: 9pt;");
  form->addRow(intro);

  layout_ = new QComboBox;
  layout_->setObjectName("arrayLayout");
  for (int k = 0; k <= NAV_ARRAY_LAYOUT_CUSTOM; ++k) {
    layout_->addItem(QString::fromUtf8(nav_array_layout_kind_name(static_cast<nav_array_layout_kind>(k))));
    layout_->setItemData(k, tr(kLayoutTips[k]), Qt::ToolTipRole);
  }
  form->addRow(tr("Layout"), layout_);
  connect(layout_, QOverload<int>::of(&QComboBox::activated), this, &ArrayPanel::ChooseLayout);

  auto add = [this, form](const QString &label, const QString &unit, const QString &p, NumField::Getter get,
                          NumField::Setter set) {
    auto *f = new NumField(doc_, label, unit, p, std::move(get), std::move(set));
    form->addRow(label, f);
    fields_.push_back(f);
    return f;
  };
  add(
      tr("Arm length"), "m", "array.radius_m", [](const nav_scene &s) { return s.array.radius_m; },
      [](nav_scene &s, double v) { s.array.radius_m = v; });

  part_ = new QComboBox;
  part_->setObjectName("arrayPart");
  part_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  part_->setMinimumContentsLength(14);
  part_->addItem(tr("(typed terms)"));
  for (size_t i = 0; i < nav_catalog_count(parts_); ++i) {
    const nav_catalog_accel_entry *e = nav_catalog_accel_at(parts_, i);
    part_->addItem(QString::fromUtf8(e->name));
    part_->setItemData(static_cast<int>(i) + 1, FiguresText(*e), Qt::ToolTipRole);
  }
  form->addRow(tr("Accelerometer part"), part_);
  connect(part_, QOverload<int>::of(&QComboBox::activated), this, &ArrayPanel::ChoosePart);
  figures_ = new QLabel;
  figures_->setObjectName("arrayPartFigures");
  figures_->setWordWrap(true);
  figures_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  figures_->setStyleSheet("font-size: 9pt;");
  form->addRow(QString(), figures_);
  note_ = new QLabel;
  note_->setObjectName("arrayNote");
  note_->setWordWrap(true);
  note_->setStyleSheet("color: #555; font-size: 9pt;");
  form->addRow(QString(), note_);

  // Per-sensor terms in datasheet units (the same for every sensor); empty = term off.
  struct Term {
    QString label, unit, path;
    unsigned bit;
    double scale; // datasheet unit -> SI
    double nav_array_error_config::*field;
  };
  const std::vector<Term> terms = {
      {tr("Noise density"), "µg/√Hz", "array.accel.noise_density", NAV_IMU_TERM_NOISE,
       nav_unit_ug_to_mps2(1.0), &nav_array_error_config::vrw_mps_per_sqrt_s},
      {tr("Turn-on bias σ"), "mg", "array.accel.bias_turn_on", NAV_IMU_TERM_BIAS_TURN_ON,
       nav_unit_mg_to_mps2(1.0), &nav_array_error_config::bias_turn_on_sd_mps2},
      {tr("Bias GM σ"), "µg", "array.accel.bias_gm_sigma", NAV_IMU_TERM_BIAS_GM, nav_unit_ug_to_mps2(1.0),
       &nav_array_error_config::bias_gm_sd_mps2},
      {tr("Bias GM τ"), "s", "array.accel.bias_gm_tau", NAV_IMU_TERM_BIAS_GM, 1.0,
       &nav_array_error_config::bias_gm_tau_s},
      {tr("Scale factor σ"), "ppm", "array.accel.scale_factor", NAV_IMU_TERM_SCALE_FACTOR, 1e-6,
       &nav_array_error_config::scale_factor_sd},
  };
  for (const Term &t : terms) {
    const bool is_tau = t.path.endsWith("_tau");
    NumField *f = add(
        t.label, t.unit, t.path, [t](const nav_scene &s) { return s.array.accel.*(t.field) / t.scale; },
        [t, is_tau](nav_scene &s, double v) {
          s.array.accel.*(t.field) = v * t.scale;
          s.array.accel.terms |= t.bit;
          if (!is_tau && t.bit == NAV_IMU_TERM_BIAS_GM && !(s.array.accel.bias_gm_tau_s > 0.0))
            s.array.accel.bias_gm_tau_s = 300.0;
        });
    f->SetOptional([t](const nav_scene &s) { return (s.array.accel.terms & t.bit) != 0; },
                   [t](nav_scene &s) { s.array.accel.terms &= ~t.bit; });
  }
  const double r2d = 180.0 / M_PI;
  add(
      tr("Initial rate σ"), "deg/s", "array.initial_rate_sd",
      [r2d](const nav_scene &s) { return s.array.initial_rate_sd_rps.x * r2d; },
      [r2d](nav_scene &s, double v) {
        s.array.initial_rate_sd_rps = nav_vec3{v / r2d, v / r2d, v / r2d};
      });

  sensors_ = new QTableWidget(0, 6);
  sensors_->setObjectName("arraySensors");
  sensors_->setHorizontalHeaderLabels({"x [m]", "y [m]", "z [m]", tr("axis x"), tr("axis y"), tr("axis z")});
  sensors_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  sensors_->setMinimumHeight(150);
  form->addRow(tr("Sensors"), sensors_);
  connect(sensors_, &QTableWidget::cellChanged, this, &ArrayPanel::OnSensorCellChanged);
  issues_ = new QLabel;
  issues_->setObjectName("arrayIssues");
  issues_->setWordWrap(true);
  issues_->setStyleSheet("color: #c02020; font-size: 9pt;");
  form->addRow(issues_);

  connect(doc_, &SceneDocument::Changed, this, &ArrayPanel::Refresh);
  Refresh();
}

ArrayPanel::~ArrayPanel() {
  nav_catalog_destroy(parts_);
}

QString ArrayPanel::FiguresText(const nav_catalog_accel_entry &e) {
  QStringList f;
  if (e.given & NAV_CATALOG_ACCEL_HAS_RANGE) f << tr("range ±%1 g").arg(Fig(e.range_g));
  if (e.given & NAV_CATALOG_ACCEL_HAS_BANDWIDTH) f << tr("bandwidth %1 Hz").arg(Fig(e.bandwidth_hz));
  if (e.given & NAV_CATALOG_ACCEL_HAS_NOISE)
    f << tr("noise %1 µg/√Hz").arg(Fig(e.noise_density_ug_per_sqrt_hz));
  if (e.given & NAV_CATALOG_ACCEL_HAS_BIAS_INSTABILITY)
    f << tr("bias instability %1 µg").arg(Fig(e.bias_instability_ug));
  if (e.given & NAV_CATALOG_ACCEL_HAS_BIAS_REPEAT)
    f << tr("bias repeatability %1 mg").arg(Fig(e.bias_repeatability_mg));
  if (e.given & NAV_CATALOG_ACCEL_HAS_SCALE_FACTOR)
    f << tr("scale factor %1 ppm").arg(Fig(e.scale_factor_ppm));
  const QString verified = e.verified == NAV_CATALOG_VERIFIED_NO
                               ? tr("NOT verified against a datasheet")
                               : tr("verified: %1").arg(QString::fromUtf8(e.verified_text));
  return tr("%1 (%2): %3.\nSource: %4\n%5")
      .arg(QString::fromUtf8(e.name), QString::fromUtf8(e.grade), f.join(", "), QString::fromUtf8(e.source),
           verified);
}

void ArrayPanel::ChooseLayout(int index) {
  doc_->Edit(tr("Array layout %1").arg(layout_->itemText(index)), [index](nav_scene &s) {
    const auto kind = static_cast<nav_array_layout_kind>(index);
    if (kind == NAV_ARRAY_LAYOUT_CUSTOM && s.array.layout != NAV_ARRAY_LAYOUT_CUSTOM) {
      // Start the custom sensors from the geometry in use, so the user edits a working array.
      nav_accel_array a;
      if (nav_array_layout_from_scene(&s.array, &a) == NAV_OK) {
        s.array.custom_count = a.n_sensors;
        for (int i = 0; i < a.n_sensors; ++i)
          s.array.custom[i] = nav_scene_array_sensor{a.r_bs_b_m[i], a.n_s_b[i]};
      }
    }
    s.array.layout = kind;
  });
}

void ArrayPanel::ChoosePart(int index) {
  if (index <= 0) {
    doc_->Edit(tr("Array part: typed terms"), [](nav_scene &s) { s.array.catalog[0] = '\0'; });
    return;
  }
  const nav_catalog_accel_entry *e = nav_catalog_accel_at(parts_, static_cast<size_t>(index - 1));
  if (!e) return;
  const nav_catalog_accel_entry entry = *e;
  doc_->Edit(tr("Array part %1").arg(QString::fromUtf8(entry.name)), [entry](nav_scene &s) {
    std::snprintf(s.array.catalog, sizeof s.array.catalog, "%s", entry.name);
    s.array.accel = entry.config;
    // The gyro-free/GNSS filter has no scale-factor states and refuses the term (the note says so).
    if (s.navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS) s.array.accel.terms &= ~NAV_IMU_TERM_SCALE_FACTOR;
  });
}

void ArrayPanel::OnSensorCellChanged(int row, int col) {
  if (refreshing_) return;
  const nav_scene &cur = doc_->Scene();
  if (cur.array.layout != NAV_ARRAY_LAYOUT_CUSTOM || row < 0 || row >= cur.array.custom_count) return;
  bool ok = false;
  const double v = sensors_->item(row, col)->text().trimmed().toDouble(&ok);
  if (!ok || !std::isfinite(v)) {
    issues_->setText(
        tr("array.sensors[%1]: expected a number, got '%2'").arg(row).arg(sensors_->item(row, col)->text()));
    return;
  }
  doc_->Edit(tr("Array sensor %1").arg(row), [row, col, v](nav_scene &s) {
    nav_scene_array_sensor &p = s.array.custom[row];
    nav_vec3 &x = col < 3 ? p.r_bs_b_m : p.n_s_b;
    const int k = col % 3;
    (k == 0 ? x.x : k == 1 ? x.y : x.z) = v;
  });
}

void ArrayPanel::Refresh() {
  refreshing_ = true;
  const nav_scene &s = doc_->Scene();
  const QVector<Issue> issues = Validate(s);
  for (NumField *f : fields_)
    f->Refresh();
  // fields_[0] is the arm length: the custom layout has its own positions.
  fields_[0]->setEnabled(s.array.layout != NAV_ARRAY_LAYOUT_CUSTOM);
  layout_->blockSignals(true);
  layout_->setCurrentIndex(static_cast<int>(s.array.layout));
  layout_->blockSignals(false);
  part_->blockSignals(true);
  const int pi = part_->findText(QString::fromUtf8(s.array.catalog), Qt::MatchFixedString);
  part_->setCurrentIndex(s.array.catalog[0] && pi > 0 ? pi : 0);
  part_->blockSignals(false);

  const nav_catalog_accel_entry *e =
      s.array.catalog[0] ? nav_catalog_find_accel(parts_, s.array.catalog) : nullptr;
  if (!parts_)
    figures_->setText(tr("The accelerometer catalog could not be loaded:\n%1").arg(load_errors_.trimmed()));
  else if (e)
    figures_->setText(FiguresText(*e));
  else
    figures_->setText(tr("No catalog part: the terms below are the scene's (%1 parts in %2).")
                          .arg(nav_catalog_count(parts_))
                          .arg("resources/accel_catalog.csv"));
  QString note;
  if (e) {
    note = tr("From the catalog: %1. Edited terms override it.").arg(QString::fromUtf8(e->name));
    if ((e->config.terms & NAV_IMU_TERM_SCALE_FACTOR) && !(s.array.accel.terms & NAV_IMU_TERM_SCALE_FACTOR))
      note += tr(" Its scale factor (%1 ppm) is off: the gyro-free/GNSS filter has no scale-factor states.")
                  .arg(Fig(e->scale_factor_ppm));
  }
  nav_accel_array a;
  nav_array_geometry geo;
  if (nav_array_layout_from_scene(&s.array, &a) == NAV_OK && nav_array_geometry_compute(&a, &geo) == NAV_OK)
    note += (note.isEmpty() ? QString() : QString(" ")) +
            tr("%1 sensors; angular-acceleration noise gain κ/r = %2 /m (largest axis).")
                .arg(a.n_sensors)
                .arg(Fig(std::fmax(std::fmax(geo.kappa_w[0], geo.kappa_w[1]), geo.kappa_w[2]) / geo.r_ref_m));
  note_->setText(note);

  sensors_->blockSignals(true);
  const bool custom = s.array.layout == NAV_ARRAY_LAYOUT_CUSTOM;
  const int n =
      custom ? s.array.custom_count : (nav_array_layout_from_scene(&s.array, &a) == NAV_OK ? a.n_sensors : 0);
  sensors_->setRowCount(n);
  for (int i = 0; i < n; ++i) {
    const nav_vec3 r = custom ? s.array.custom[i].r_bs_b_m : a.r_bs_b_m[i];
    const nav_vec3 ax = custom ? s.array.custom[i].n_s_b : a.n_s_b[i];
    const double v[6] = {r.x, r.y, r.z, ax.x, ax.y, ax.z};
    for (int c = 0; c < 6; ++c) {
      // Positions to the millimetre of a metre-size array; axes to three digits (0.707).
      auto *it =
          new QTableWidgetItem(QString::number(std::fabs(v[c]) < 1e-12 ? 0.0 : v[c], 'g', c < 3 ? 4 : 3));
      if (!custom) it->setFlags(it->flags() & ~Qt::ItemIsEditable);
      sensors_->setItem(i, c, it);
    }
  }
  sensors_->blockSignals(false);

  QStringList lines;
  for (const Issue &i : issues)
    if (i.path.startsWith("array")) lines << i.Text();
  issues_->setText(lines.join("\n"));
  refreshing_ = false;
}

} // namespace studio
