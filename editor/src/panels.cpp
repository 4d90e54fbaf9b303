#include "panels.h"
#include "array_panel.h"
#include "path_view.h"
#include "schema_fields.h"
#include "segment_editor.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QTableWidget>
#include <QVBoxLayout>

#include <cmath>
#include <cstring>

extern "C" {
#include "navcore/nav_sensors.h"
}

namespace studio {

namespace {
const char *kErrorStyle = "QLineEdit { border: 2px solid #d03030; background: #fff0f0; }";

// @p digits significant digits, but every digit before the decimal point (no exponent for a
// whole number of up to 15 digits: "3000", not "3e+03").
QString Num(double v, int digits = 10) {
  if (!std::isfinite(v)) return QString::number(v);
  const double a = std::fabs(v);
  const int whole = a >= 1.0 ? static_cast<int>(std::floor(std::log10(a))) + 1 : 0;
  return QString::number(v, 'g', std::min(15, std::max(digits, whole)));
}

bool SameNumber(const QString &text, double v, int digits = 10) {
  bool ok = false;
  const double t = text.trimmed().toDouble(&ok);
  return ok && (t == v || Num(t, digits) == Num(v, digits));
}

QComboBox *Combo(const QString &name, const QStringList &items) {
  auto *c = new QComboBox;
  // Long catalog names must not widen the panel: the popup still shows them whole.
  c->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  c->setMinimumContentsLength(14);
  c->setObjectName(name);
  c->addItems(items);
  return c;
}

void SetVec(nav_vec3 &v, double x) { v = nav_vec3{x, x, x}; }
} // namespace

/* ---------------------------------------------------------------- NumField */

NumField::NumField(SceneDocument *doc, const QString &label, const QString &unit, const QString &path, Getter get,
                   Setter set, QWidget *parent)
    : QWidget(parent), doc_(doc), label_(label), unit_(unit), path_(path), get_(std::move(get)),
      set_(std::move(set)) {
  auto *v = new QVBoxLayout(this);
  v->setContentsMargins(0, 0, 0, 0);
  v->setSpacing(1);
  auto *h = new QHBoxLayout;
  h->setContentsMargins(0, 0, 0, 0);
  edit_ = new QLineEdit;
  edit_->setObjectName(path);
  edit_->setToolTip(tr("%1 [%2] (scene file: %3)").arg(label, unit, path));
  h->addWidget(edit_, 1);
  if (!unit.isEmpty()) {
    auto *u = new QLabel(unit);
    u->setMinimumWidth(54);
    h->addWidget(u);
  }
  v->addLayout(h);
  msg_ = new QLabel;
  msg_->setObjectName(path + ".message");
  msg_->setWordWrap(true);
  msg_->setStyleSheet("color: #c02020; font-size: 9pt;");
  msg_->hide();
  v->addWidget(msg_);
  connect(edit_, &QLineEdit::textEdited, this, &NumField::OnEdited);
  connect(edit_, &QLineEdit::editingFinished, this, &NumField::OnCommit);
}

void NumField::SetHelp(const QString &key, const QString &help) {
  edit_->setToolTip(
      tr("%1 [%2] (scene file: %3)%4").arg(label_, unit_, key, help.isEmpty() ? QString() : ": " + help));
}

void NumField::SetOptional(std::function<bool(const nav_scene &)> is_set, std::function<void(nav_scene &)> clear) {
  is_set_ = std::move(is_set);
  clear_ = std::move(clear);
  edit_->setPlaceholderText(tr("off"));
}

QString NumField::Message() const { return msg_->isVisible() ? msg_->text() : QString(); }

bool NumField::Parse(double *v, bool *empty, QString *err) const {
  const QString t = edit_->text().trimmed();
  *empty = t.isEmpty();
  if (*empty) {
    if (clear_) return true;
    *err = tr("%1: expected a number, got an empty value").arg(path_);
    return false;
  }
  bool ok = false;
  *v = t.toDouble(&ok);
  if (!ok) {
    *err = tr("%1: expected a number, got '%2'").arg(path_, t);
    return false;
  }
  return true;
}

void NumField::ShowIssues(const QVector<Issue> &issues) {
  QStringList lines;
  for (const Issue &i : issues)
    if (i.path.startsWith(path_)) lines << i.Text();
  msg_->setText(lines.join("\n"));
  msg_->setVisible(!lines.isEmpty());
  edit_->setStyleSheet(lines.isEmpty() ? QString() : QString(kErrorStyle));
}

void NumField::OnEdited() {
  double v = 0.0;
  bool empty = false;
  QString err;
  if (!Parse(&v, &empty, &err)) {
    ShowIssues({Issue{path_, err.mid(path_.size() + 2)}});
    return;
  }
  nav_scene cand = doc_->Scene();
  if (empty)
    clear_(cand);
  else
    set_(cand, v);
  ShowIssues(Validate(cand));
}

void NumField::SetSignificantDigits(int digits) {
  digits_ = digits;
  Refresh();
}

void NumField::OnCommit() {
  double v = 0.0;
  bool empty = false;
  QString err;
  if (!Parse(&v, &empty, &err)) return; // the message stays; nothing is committed
  // Leaving a field unchanged is no edit: a value shown rounded (a datasheet term at three
  // significant digits) keeps its full precision in the scene.
  if (!empty && (!is_set_ || is_set_(doc_->Scene())) &&
      SameNumber(edit_->text(), get_(doc_->Scene()), digits_))
    return;
  if (empty) {
    doc_->Edit(tr("Switch off %1").arg(label_), [this](nav_scene &s) { clear_(s); });
  } else {
    doc_->Edit(tr("Set %1").arg(label_), [this, v](nav_scene &s) { set_(s, v); });
  }
}

void NumField::Refresh() {
  const nav_scene &s = doc_->Scene();
  if (is_set_ && !is_set_(s)) {
    if (!edit_->text().trimmed().isEmpty() && !edit_->hasFocus()) edit_->clear();
    return;
  }
  const double v = get_(s);
  if (!SameNumber(edit_->text(), v, digits_)) edit_->setText(Num(v, digits_));
}

/* ---------------------------------------------------------------- panels */

ScenePanels::ScenePanels(SceneDocument *doc, Catalogs *catalogs, QWidget *parent)
    : QTabWidget(parent), doc_(doc), cat_(catalogs) {
  setObjectName("panels");
  addTab(ScrolledPanel(BuildModel()), tr("Model"));
  addTab(ScrolledPanel(BuildImu()), tr("IMU"));
  addTab(ScrolledPanel(BuildGnss()), tr("GNSS"));
  addTab(new TrajectoryEditors(doc_, BuildTrajectory()), tr("Trajectory")); // waypoints, segments, parametric
  addTab(ScrolledPanel(BuildSimulation()), tr("Simulation"));
  addTab(BuildRequirements(), tr("Requirements"));
  addTab(ScrolledPanel(new ArrayPanel(doc_)), tr("Array")); // issue 21: layout, arm, accelerometer part
  connect(doc_, &SceneDocument::Changed, this, &ScenePanels::Refresh);
  Refresh();
}

NumField *ScenePanels::AddField(QFormLayout *form, const QString &label, const QString &unit, const QString &path,
                                NumField::Getter get, NumField::Setter set) {
  auto *f = new NumField(doc_, label, unit, path, std::move(get), std::move(set));
  form->addRow(label, f);
  fields_.push_back(f);
  return f;
}

NumField *ScenePanels::AddKey(QFormLayout *form, const QString &label, const char *key, const QString &path,
                              NumField::Getter get_si, NumField::Setter set_si) {
  const nav_schema_key &k = SchemaKey(key);
  const double scale = k.scale;
  NumField *f = AddField(
      form, label, DisplayUnit(k.unit), path,
      [get_si, scale](const nav_scene &s) { return get_si(s) / scale; },
      [set_si, scale](nav_scene &s, double v) { set_si(s, v * scale); });
  f->SetHelp(QString::fromUtf8(key), KeyHelp(k));
  return f;
}

QWidget *ScenePanels::BuildModel() {
  auto *w = new QWidget;
  auto *form = new QFormLayout(w);
  QStringList schemes, algs, earths, frames;
  for (int i = 0; i <= 4; ++i) schemes << nav_nav_scheme_name(static_cast<nav_nav_scheme>(i));
  for (int i = 0; i <= 1; ++i) algs << nav_mech_algorithm_name(static_cast<nav_mech_algorithm>(i));
  for (int i = 0; i <= 1; ++i) earths << nav_earth_model_name(static_cast<nav_earth_model>(i));
  for (int i = 0; i <= 1; ++i) frames << nav_mech_frame_name(static_cast<nav_mech_frame>(i));
  scheme_ = Combo("scheme", schemes);
  scheme_->setItemData(0, tr("free-inertial strapdown INS"), Qt::ToolTipRole);
  scheme_->setItemData(1, tr("loosely coupled INS/GNSS Kalman filter"), Qt::ToolTipRole);
  scheme_->setItemData(2, tr("gyro-free INS from an accelerometer array"), Qt::ToolTipRole);
  scheme_->setItemData(3, tr("gyro-free INS (accelerometer array) aided by GNSS: loosely coupled Kalman filter"),
                       Qt::ToolTipRole);
  scheme_->setItemData(4, tr("tightly coupled INS/GNSS: pseudoranges and range rates of the satellites in view "
                             "(gnss.constellation), receiver clock states; works with fewer than four satellites"),
                       Qt::ToolTipRole);
  algorithm_ = Combo("algorithm", algs);
  earth_ = Combo("earthModel", earths);
  frame_ = Combo("mechFrame", frames);
  form->addRow(tr("Navigation scheme"), scheme_);
  form->addRow(tr("Mechanization"), algorithm_);
  form->addRow(tr("Earth model"), earth_);
  form->addRow(tr("Frame (WGS-84)"), frame_);
  connect(scheme_, QOverload<int>::of(&QComboBox::activated), this, [this](int i) {
    doc_->Edit(tr("Set scheme"), [i](nav_scene &s) {
      s.navigation.scheme = static_cast<nav_nav_scheme>(i);
      if (i == NAV_SCHEME_INS_GNSS || i == NAV_SCHEME_GYRO_FREE_GNSS || i == NAV_SCHEME_INS_GNSS_TIGHT)
        s.gnss.enabled = true;
      // The tightly coupled scheme needs satellites: the section's settings (the defaults, GPS
      // nominal, when it was never set) switched on.
      if (i == NAV_SCHEME_INS_GNSS_TIGHT) s.gnss.constellation.enabled = true;
    });
  });
  connect(algorithm_, QOverload<int>::of(&QComboBox::activated), this, [this](int i) {
    doc_->Edit(tr("Set algorithm"), [i](nav_scene &s) { s.navigation.algorithm = static_cast<nav_mech_algorithm>(i); });
  });
  connect(earth_, QOverload<int>::of(&QComboBox::activated), this, [this](int i) {
    doc_->Edit(tr("Set Earth model"), [i](nav_scene &s) { s.earth.model = static_cast<nav_earth_model>(i); });
  });
  connect(frame_, QOverload<int>::of(&QComboBox::activated), this, [this](int i) {
    doc_->Edit(tr("Set frame"), [i](nav_scene &s) { s.navigation.frame = static_cast<nav_mech_frame>(i); });
  });
  AddKey(
      form, tr("Origin latitude"), "earth.origin.lat_deg", "earth.origin.lat",
      [](const nav_scene &s) { return s.earth.origin_lat_rad; },
      [](nav_scene &s, double v) { s.earth.origin_lat_rad = v; });
  AddKey(
      form, tr("Origin longitude"), "earth.origin.lon_deg", "earth.origin.lon",
      [](const nav_scene &s) { return s.earth.origin_lon_rad; },
      [](nav_scene &s, double v) { s.earth.origin_lon_rad = v; });
  AddKey(
      form, tr("Origin height"), "earth.origin.h_m", "earth.origin.h",
      [](const nav_scene &s) { return s.earth.origin_h_m; },
      [](nav_scene &s, double v) { s.earth.origin_h_m = v; });
  return w;
}

QWidget *ScenePanels::BuildImu() {
  auto *w = new QWidget;
  auto *form = new QFormLayout(w);
  QStringList names;
  names << tr("(perfect IMU)") << cat_->ImuNames();
  imu_catalog_ = Combo("imuCatalog", names);
  form->addRow(tr("Catalog part"), imu_catalog_);
  imu_note_ = new QLabel;
  imu_note_->setWordWrap(true);
  imu_note_->setStyleSheet("color: #555; font-size: 9pt;");
  form->addRow(QString(), imu_note_);
  connect(imu_catalog_, QOverload<int>::of(&QComboBox::activated), this, [this](int i) {
    if (i == 0) {
      doc_->Edit(tr("Perfect IMU"), [](nav_scene &s) {
        s.imu.catalog[0] = '\0';
        s.imu.model.gyro.terms = 0;
        s.imu.model.accel.terms = 0;
      });
      return;
    }
    const nav_catalog_imu_entry *e = nav_catalog_imu_at(cat_->Imu(), static_cast<size_t>(i - 1));
    if (!e) return;
    const nav_catalog_imu_entry entry = *e;
    doc_->Edit(tr("IMU %1").arg(QString::fromUtf8(entry.name)), [entry](nav_scene &s) {
      std::snprintf(s.imu.catalog, sizeof s.imu.catalog, "%s", entry.name);
      s.imu.model = entry.config;
    });
  });
  AddKey(
      form, tr("IMU rate"), "imu.rate_hz", "imu.rate_hz", [](const nav_scene &s) { return s.imu.rate_hz; },
      [](nav_scene &s, double v) { s.imu.rate_hz = v; });

  // Error terms in datasheet units (the unit and scale of each scene key, from navcore_io's table);
  // one value for the three axes; empty = term off.
  struct Term {
    QString label;
    const char *key; // the scene key whose unit, scale and bounds the field has
    QString path;    // the field's name (its issues are those under this path)
    bool gyro;
    unsigned bit;
    nav_vec3 nav_gyro_error_config::*g;
    nav_vec3 nav_accel_error_config::*a;
  };
  const std::vector<Term> terms = {
      {tr("Gyro ARW"), "imu.gyro.arw_deg_per_sqrt_h", "imu.gyro.arw", true, NAV_IMU_TERM_NOISE,
       &nav_gyro_error_config::arw_rad_per_sqrt_s, nullptr},
      {tr("Gyro bias GM σ"), "imu.gyro.bias_gm_sigma_deg_per_h", "imu.gyro.bias_gm_sigma", true,
       NAV_IMU_TERM_BIAS_GM, &nav_gyro_error_config::bias_gm_sd_rps, nullptr},
      {tr("Gyro bias GM τ"), "imu.gyro.bias_gm_tau_s", "imu.gyro.bias_gm_tau", true, NAV_IMU_TERM_BIAS_GM,
       &nav_gyro_error_config::bias_gm_tau_s, nullptr},
      {tr("Gyro turn-on bias σ"), "imu.gyro.bias_turn_on_deg_per_h", "imu.gyro.bias_turn_on", true,
       NAV_IMU_TERM_BIAS_TURN_ON, &nav_gyro_error_config::bias_turn_on_sd_rps, nullptr},
      {tr("Gyro rate random walk"), "imu.gyro.rrw_deg_per_h_per_sqrt_h", "imu.gyro.bias_rw", true,
       NAV_IMU_TERM_BIAS_RW, &nav_gyro_error_config::bias_rw_rps_per_sqrt_s, nullptr},
      {tr("Gyro scale factor σ"), "imu.gyro.scale_factor_ppm", "imu.gyro.scale_factor", true,
       NAV_IMU_TERM_SCALE_FACTOR, &nav_gyro_error_config::scale_factor_sd, nullptr},
      {tr("Accel VRW"), "imu.accel.vrw_m_per_s_per_sqrt_h", "imu.accel.vrw", false, NAV_IMU_TERM_NOISE,
       nullptr, &nav_accel_error_config::vrw_mps_per_sqrt_s},
      {tr("Accel bias GM σ"), "imu.accel.bias_gm_sigma_ug", "imu.accel.bias_gm_sigma", false,
       NAV_IMU_TERM_BIAS_GM, nullptr, &nav_accel_error_config::bias_gm_sd_mps2},
      {tr("Accel bias GM τ"), "imu.accel.bias_gm_tau_s", "imu.accel.bias_gm_tau", false, NAV_IMU_TERM_BIAS_GM,
       nullptr, &nav_accel_error_config::bias_gm_tau_s},
      {tr("Accel turn-on bias σ"), "imu.accel.bias_turn_on_mg", "imu.accel.bias_turn_on", false,
       NAV_IMU_TERM_BIAS_TURN_ON, nullptr, &nav_accel_error_config::bias_turn_on_sd_mps2},
      {tr("Accel scale factor σ"), "imu.accel.scale_factor_ppm", "imu.accel.scale_factor", false,
       NAV_IMU_TERM_SCALE_FACTOR, nullptr, &nav_accel_error_config::scale_factor_sd},
  };
  for (const Term &t : terms) {
    auto vec = [t](nav_scene &s) -> nav_vec3 & { return t.gyro ? s.imu.model.gyro.*(t.g) : s.imu.model.accel.*(t.a); };
    auto cvec = [t](const nav_scene &s) -> const nav_vec3 & {
      return t.gyro ? s.imu.model.gyro.*(t.g) : s.imu.model.accel.*(t.a);
    };
    auto bits = [t](nav_scene &s) -> unsigned & { return t.gyro ? s.imu.model.gyro.terms : s.imu.model.accel.terms; };
    const bool is_tau = t.path.endsWith("_tau");
    NumField *f = AddKey(
        form, t.label, t.key, t.path, [cvec](const nav_scene &s) { return cvec(s).x; },
        [vec, bits, t, is_tau](nav_scene &s, double v) {
          SetVec(vec(s), v);
          bits(s) |= t.bit;
          if (!is_tau && t.bit == NAV_IMU_TERM_BIAS_GM) {
            nav_vec3 &tau = t.gyro ? s.imu.model.gyro.bias_gm_tau_s : s.imu.model.accel.bias_gm_tau_s;
            if (!(tau.x > 0.0)) SetVec(tau, 300.0);
          }
        });
    f->SetOptional([t](const nav_scene &s) { return ((t.gyro ? s.imu.model.gyro.terms : s.imu.model.accel.terms) & t.bit) != 0; },
                   [bits, t](nav_scene &s) { bits(s) &= ~t.bit; });
    // A datasheet figure converted to the field's unit ("16.19789203 deg/h") at datasheet precision.
    f->SetSignificantDigits(3);
  }
  return w;
}

QWidget *ScenePanels::BuildGnss() {
  auto *w = new QWidget;
  auto *form = new QFormLayout(w);
  gnss_enabled_ = new QCheckBox(tr("GNSS receiver fitted"));
  gnss_enabled_->setObjectName("gnssEnabled");
  form->addRow(gnss_enabled_);
  connect(gnss_enabled_, &QCheckBox::clicked, this, [this](bool on) {
    doc_->Edit(on ? tr("Enable GNSS") : tr("Disable GNSS"), [on](nav_scene &s) { s.gnss.enabled = on; });
  });
  QStringList names;
  names << tr("(scene values)") << cat_->GnssNames();
  gnss_receiver_ = Combo("gnssReceiver", names);
  // Receiver classes have long names ("standalone SPS typical (single-frequency code, open
  // sky)"): the combo takes the panel's whole width under its label, each name also its tooltip.
  for (int i = 0; i < gnss_receiver_->count(); ++i)
    gnss_receiver_->setItemData(i, gnss_receiver_->itemText(i), Qt::ToolTipRole);
  form->addRow(new QLabel(tr("Receiver class")));
  form->addRow(gnss_receiver_);
  connect(gnss_receiver_, QOverload<int>::of(&QComboBox::activated), this, [this](int i) {
    if (i == 0) {
      // "(scene values)": the receiver's values stay, as the scene's own (no catalog class).
      doc_->Edit(tr("Receiver: scene values"), [](nav_scene &s) { s.gnss.catalog[0] = '\0'; });
      return;
    }
    const nav_catalog_gnss_entry *e = nav_catalog_gnss_at(cat_->Gnss(), static_cast<size_t>(i - 1));
    if (!e) return;
    const nav_catalog_gnss_entry entry = *e;
    doc_->Edit(tr("Receiver %1").arg(QString::fromUtf8(entry.name)), [entry](nav_scene &s) {
      nav_gnss_model_config c = entry.config;
      // Mounting, latency and outages belong to the scene, not to the receiver class.
      c.r_ba_b_m = s.gnss.model.r_ba_b_m;
      c.latency_s = s.gnss.model.latency_s;
      c.outage_count = s.gnss.model.outage_count;
      std::memcpy(c.outages, s.gnss.model.outages, sizeof c.outages);
      s.gnss.model = c;
      s.gnss.enabled = true;
      std::snprintf(s.gnss.catalog, sizeof s.gnss.catalog, "%s", entry.name);
    });
  });
  AddKey(
      form, tr("Fix rate"), "gnss.update_rate_hz", "gnss.update_rate",
      [](const nav_scene &s) { return s.gnss.model.update_rate_hz; },
      [](nav_scene &s, double v) { s.gnss.model.update_rate_hz = v; });
  AddKey(
      form, tr("Latency"), "gnss.latency_s", "gnss.latency",
      [](const nav_scene &s) { return s.gnss.model.latency_s; },
      [](nav_scene &s, double v) { s.gnss.model.latency_s = v; });
  // The receiver's noise (the catalog class's values, or the scene's own for "(scene values)"):
  // horizontal components (N and E) and vertical (D) of each term; empty = term off.
  struct Noise {
    QString label;
    const char *key;
    QString path;
    unsigned bit;
    nav_vec3 nav_gnss_model_config::*v;
    int axes; // 0: N and E, 1: D, 2: all three
  };
  const std::vector<Noise> noise = {
      {tr("Position σ horizontal"), "gnss.position_sigma_m", "gnss.position_sigma", NAV_GNSS_TERM_POS_GM,
       &nav_gnss_model_config::pos_gm_sd_m, 0},
      {tr("Position σ vertical"), "gnss.position_sigma_m", "gnss.position_sigma", NAV_GNSS_TERM_POS_GM,
       &nav_gnss_model_config::pos_gm_sd_m, 1},
      {tr("Position correlation time"), "gnss.position_corr_time_s", "gnss.position_corr_time",
       NAV_GNSS_TERM_POS_GM, &nav_gnss_model_config::pos_gm_tau_s, 2},
      {tr("White position σ horizontal"), "gnss.position_white_sigma_m", "gnss.position_white_sigma",
       NAV_GNSS_TERM_POS_WHITE, &nav_gnss_model_config::pos_white_sd_m, 0},
      {tr("White position σ vertical"), "gnss.position_white_sigma_m", "gnss.position_white_sigma",
       NAV_GNSS_TERM_POS_WHITE, &nav_gnss_model_config::pos_white_sd_m, 1},
      {tr("Velocity σ"), "gnss.velocity_sigma_mps", "gnss.velocity_sigma", NAV_GNSS_TERM_VEL_WHITE,
       &nav_gnss_model_config::vel_sd_mps, 2},
  };
  for (const Noise &n : noise) {
    NumField *f = AddKey(
        form, n.label, n.key, n.path,
        [n](const nav_scene &s) {
          const nav_vec3 &v = s.gnss.model.*(n.v);
          return n.axes == 1 ? v.z : v.x;
        },
        [n](nav_scene &s, double x) {
          nav_vec3 &v = s.gnss.model.*(n.v);
          if (n.axes != 1) v.x = v.y = x;
          if (n.axes != 0) v.z = x;
          if (!(s.gnss.model.terms & n.bit)) {
            // A term switched on from one field: the other axes get the same value (a
            // correlation time of 0 is white noise, valid).
            if (n.axes == 0) v.z = x;
            if (n.axes == 1) v.x = v.y = x;
            s.gnss.model.terms |= n.bit;
          }
        });
    // Two fields per key (horizontal, vertical): each its own name.
    if (n.axes != 2) f->Edit()->setObjectName(n.path + (n.axes == 0 ? ".horizontal" : ".vertical"));
    f->SetOptional([n](const nav_scene &s) { return (s.gnss.model.terms & n.bit) != 0; },
                   [n](nav_scene &s) { s.gnss.model.terms &= ~n.bit; });
    f->SetSignificantDigits(3);
  }
  const char *axes[3] = {"x (forward)", "y (right)", "z (down)"};
  for (int k = 0; k < 3; ++k) {
    AddKey(
        form, tr("Lever arm %1").arg(axes[k]), "gnss.lever_arm_b_m", "gnss.lever_arm",
        [k](const nav_scene &s) {
          const nav_vec3 &r = s.gnss.model.r_ba_b_m;
          return k == 0 ? r.x : k == 1 ? r.y : r.z;
        },
        [k](nav_scene &s, double v) {
          nav_vec3 &r = s.gnss.model.r_ba_b_m;
          (k == 0 ? r.x : k == 1 ? r.y : r.z) = v;
        });
  }
  outages_ = new QTableWidget(0, 2);
  outages_->setObjectName("outageTable");
  outages_->setHorizontalHeaderLabels({tr("start [s]"), tr("end [s]")});
  outages_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  outages_->setMinimumHeight(110);
  form->addRow(tr("Outages"), outages_);
  auto *row = new QHBoxLayout;
  auto *add = new QPushButton(tr("Add 60 s outage"));
  add->setObjectName("addOutage");
  auto *del = new QPushButton(tr("Remove"));
  del->setObjectName("removeOutage");
  row->addWidget(add);
  row->addWidget(del);
  form->addRow(QString(), row);
  connect(add, &QPushButton::clicked, this, [this] {
    doc_->Edit(tr("Add outage"), [](nav_scene &s) {
      nav_gnss_model_config &g = s.gnss.model;
      if (g.outage_count >= NAV_GNSS_MAX_OUTAGES) return;
      double start = 0.0;
      for (size_t i = 0; i < g.outage_count; ++i) start = std::max(start, g.outages[i].t1_s + 30.0);
      if (g.outage_count == 0) {
        // The middle of the motion (after the initial hold), rounded to 10 s.
        const double hold = s.trajectory.type == NAV_TRAJ_WAYPOINTS ? s.trajectory.waypoints.hold_start_s : 0.0;
        const double d = s.trajectory.duration_s;
        start = std::max(hold + 10.0, std::floor((hold + 0.5 * (d - hold) - 30.0) / 10.0) * 10.0);
      }
      g.outages[g.outage_count++] = nav_gnss_outage{start, start + 60.0};
      s.gnss.enabled = true;
    });
  });
  connect(del, &QPushButton::clicked, this, [this] {
    const int r = outages_->currentRow() >= 0 ? outages_->currentRow() : outages_->rowCount() - 1;
    if (r < 0) return;
    doc_->Edit(tr("Remove outage"), [r](nav_scene &s) {
      nav_gnss_model_config &g = s.gnss.model;
      if (static_cast<size_t>(r) >= g.outage_count) return;
      for (size_t i = static_cast<size_t>(r); i + 1 < g.outage_count; ++i) g.outages[i] = g.outages[i + 1];
      g.outage_count--;
    });
  });
  connect(outages_, &QTableWidget::cellChanged, this, &ScenePanels::OnOutageCellChanged);
  return w;
}

QWidget *ScenePanels::BuildTrajectory() {
  auto *w = new QWidget;
  auto *vl = new QVBoxLayout(w);
  geodetic_ = new QCheckBox(tr("latitude / longitude / height"));
  geodetic_->setObjectName("geodeticColumns");
  vl->addWidget(geodetic_);
  connect(geodetic_, &QCheckBox::toggled, this, [this] { RefreshWaypoints(); });
  wp_table_ = new QTableWidget(0, 4);
  wp_table_->setObjectName("waypointTable");
  wp_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  wp_table_->setSelectionBehavior(QAbstractItemView::SelectRows);
  wp_table_->setSelectionMode(QAbstractItemView::SingleSelection);
  vl->addWidget(wp_table_, 1);
  connect(wp_table_, &QTableWidget::cellChanged, this, &ScenePanels::OnWaypointCellChanged);
  connect(wp_table_, &QTableWidget::currentCellChanged, this, [this](int row, int, int prev, int) {
    if (!refreshing_ && row != prev) emit WaypointSelected(row);
  });
  auto *row = new QHBoxLayout;
  auto *add = new QPushButton(tr("Add"));
  auto *del = new QPushButton(tr("Delete"));
  auto *up = new QPushButton(tr("Up"));
  auto *down = new QPushButton(tr("Down"));
  add->setObjectName("addWaypoint");
  del->setObjectName("deleteWaypoint");
  for (auto *b : {add, del, up, down}) row->addWidget(b);
  vl->addLayout(row);
  connect(add, &QPushButton::clicked, this, [this] {
    const nav_scene &s = doc_->Scene();
    double n = 0, e = 0;
    if (s.trajectory.type == NAV_TRAJ_WAYPOINTS && s.trajectory.waypoints.count > 0) {
      const nav_vec3 r = s.trajectory.waypoints.points[s.trajectory.waypoints.count - 1].r_ned_m;
      n = r.x + 100.0;
      e = r.y;
    }
    AddWaypoint(doc_, n, e, 0.0);
  });
  connect(del, &QPushButton::clicked, this, [this] { DeleteWaypoint(doc_, wp_table_->currentRow()); });
  auto move = [this](int dir) {
    const int r = wp_table_->currentRow();
    const nav_scene &s = doc_->Scene();
    const int to = r + dir;
    if (s.trajectory.type != NAV_TRAJ_WAYPOINTS || r < 0 || to < 0 || to >= s.trajectory.waypoints.count) return;
    doc_->Edit(tr("Reorder waypoints"), [r, to](nav_scene &sc) {
      std::swap(sc.trajectory.waypoints.points[r].r_ned_m, sc.trajectory.waypoints.points[to].r_ned_m);
    });
    wp_table_->setCurrentCell(to, 0);
  };
  connect(up, &QPushButton::clicked, this, [move] { move(-1); });
  connect(down, &QPushButton::clicked, this, [move] { move(+1); });
  auto *formw = new QWidget;
  auto *form = new QFormLayout(formw);
  form->setContentsMargins(0, 0, 0, 0);
  AddKey(
      form, tr("Hold at start"), "trajectory.waypoints.hold_start_s", "trajectory.waypoints.hold_start",
      [](const nav_scene &s) { return s.trajectory.waypoints.hold_start_s; },
      [](nav_scene &s, double v) { s.trajectory.waypoints.hold_start_s = v; });
  AddKey(
      form, tr("Hold at end"), "trajectory.waypoints.hold_end_s", "trajectory.waypoints.hold_end",
      [](const nav_scene &s) { return s.trajectory.waypoints.hold_end_s; },
      [](nav_scene &s, double v) { s.trajectory.waypoints.hold_end_s = v; });
  AddKey(
      form, tr("Speed between stops"), "trajectory.waypoints.cruise_mps", "trajectory.waypoints.cruise",
      [](const nav_scene &s) { return s.trajectory.waypoints.cruise_mps; },
      [](nav_scene &s, double v) { s.trajectory.waypoints.cruise_mps = v; });
  AddKey(
      form, tr("Max acceleration"), "trajectory.waypoints.limits.max_accel_mps2",
      "trajectory.waypoints.limits.max_accel",
      [](const nav_scene &s) { return s.trajectory.waypoints.limits.max_accel_mps2; },
      [](nav_scene &s, double v) { s.trajectory.waypoints.limits.max_accel_mps2 = v; });
  AddKey(
      form, tr("Max lateral accel."), "trajectory.waypoints.limits.max_lateral_accel_mps2",
      "trajectory.waypoints.limits.max_lateral",
      [](const nav_scene &s) { return s.trajectory.waypoints.limits.max_lateral_accel_mps2; },
      [](nav_scene &s, double v) { s.trajectory.waypoints.limits.max_lateral_accel_mps2 = v; });
  vl->addWidget(formw);
  plan_label_ = new QLabel;
  plan_label_->setObjectName("planLabel");
  plan_label_->setWordWrap(true);
  vl->addWidget(plan_label_);
  return w;
}

QWidget *ScenePanels::BuildSimulation() {
  auto *w = new QWidget;
  auto *form = new QFormLayout(w);
  NumField *runs = AddField(
      form, tr("Monte Carlo runs"), "", "simulation.runs",
      [](const nav_scene &s) { return static_cast<double>(s.simulation.runs); },
      [](nav_scene &s, double v) {
        s.simulation.runs = std::isfinite(v) && std::fabs(v) < 1e12 ? static_cast<long>(v) : -1;
      });
  NumField *seed = AddField(
      form, tr("Seed"), "", "simulation.seed",
      [](const nav_scene &s) { return static_cast<double>(s.simulation.seed); },
      [](nav_scene &s, double v) { s.simulation.seed = v >= 0 && v < 9e15 ? static_cast<uint64_t>(v) : 0; });
  runs->SetHelp("simulation.runs", KeyHelp(SchemaKey("simulation.runs")));
  seed->SetHelp("simulation.seed", KeyHelp(SchemaKey("simulation.seed")));
  AddKey(
      form, tr("Output rate"), "output.rate_hz", "output.rate_hz",
      [](const nav_scene &s) { return s.output.rate_hz; },
      [](nav_scene &s, double v) { s.output.rate_hz = v; });
  auto *row = new QHBoxLayout;
  auto *run = new QPushButton(tr("Run"));
  run->setObjectName("panelRun");
  auto *cancel = new QPushButton(tr("Cancel"));
  cancel->setObjectName("panelCancel");
  row->addWidget(run);
  row->addWidget(cancel);
  form->addRow(QString(), row);
  connect(run, &QPushButton::clicked, this, &ScenePanels::RunRequested);
  connect(cancel, &QPushButton::clicked, this, &ScenePanels::CancelRequested);
  return w;
}

QWidget *ScenePanels::BuildRequirements() {
  auto *w = new QWidget;
  auto *vl = new QVBoxLayout(w);
  req_table_ = new QTableWidget(0, 7);
  req_table_->setObjectName("requirementsTable");
  req_table_->setHorizontalHeaderLabels({tr("id"), tr("verdict"), tr("metric"), tr("statistic"), tr("limit"),
                                         tr("unit"), tr("time [s]")});
  req_table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  req_table_->horizontalHeader()->setStretchLastSection(true);
  vl->addWidget(req_table_, 1);
  auto *buttons = new QHBoxLayout;
  auto *add = new QPushButton(tr("Add requirement"));
  add->setObjectName("addRequirement");
  auto *del = new QPushButton(tr("Remove"));
  buttons->addWidget(add);
  buttons->addWidget(del);
  vl->addLayout(buttons);
  req_summary_ = new QLabel(tr("no result yet"));
  req_summary_->setObjectName("verdictSummary");
  req_summary_->setWordWrap(true);
  vl->addWidget(req_summary_);
  connect(add, &QPushButton::clicked, this, [this] {
    doc_->Edit(tr("Add requirement"), [](nav_scene &s) {
      if (s.n_requirements >= NAV_SCENE_MAX_REQUIREMENTS) return;
      nav_requirement r;
      std::memset(&r, 0, sizeof r);
      const bool outage = s.gnss.enabled && s.gnss.model.outage_count > 0 &&
                          (s.navigation.scheme == NAV_SCHEME_INS_GNSS || s.navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
                           s.navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT);
      r.metric = NAV_REQ_HORIZONTAL_POSITION;
      r.statistic = outage ? NAV_REQ_OUTAGE_END : NAV_REQ_RMS;
      r.limit = outage ? 5.0 : 10.0;
      r.unit = NAV_REQ_UNIT_M;
      // A unique id.
      for (int k = 1;; ++k) {
        std::snprintf(r.id, sizeof r.id, "%s%s", outage ? "h-outage-end" : "h-rms", k == 1 ? "" : std::to_string(k).c_str());
        bool used = false;
        for (int i = 0; i < s.n_requirements; ++i) used = used || std::strcmp(s.requirements[i].id, r.id) == 0;
        if (!used) break;
      }
      s.requirements[s.n_requirements++] = r;
    });
  });
  connect(del, &QPushButton::clicked, this, [this] {
    const int r = req_table_->currentRow() >= 0 ? req_table_->currentRow() : req_table_->rowCount() - 1;
    if (r < 0) return;
    doc_->Edit(tr("Remove requirement"), [r](nav_scene &s) {
      if (r >= s.n_requirements) return;
      for (int i = r; i + 1 < s.n_requirements; ++i) s.requirements[i] = s.requirements[i + 1];
      s.n_requirements--;
    });
  });
  connect(req_table_, &QTableWidget::cellChanged, this, [this](int row, int col) {
    if (refreshing_) return;
    const QString text = req_table_->item(row, col) ? req_table_->item(row, col)->text().trimmed() : QString();
    doc_->Edit(tr("Edit requirement"), [row, col, text](nav_scene &s) {
      if (row >= s.n_requirements) return;
      nav_requirement &r = s.requirements[row];
      bool ok = false;
      const double v = text.toDouble(&ok);
      if (col == 0) std::snprintf(r.id, sizeof r.id, "%s", text.toUtf8().constData());
      if (col == 4 && ok) r.limit = v;
      if (col == 6 && ok) r.time_s = v;
    });
  });
  return w;
}

/* ---------------------------------------------------------------- refresh */

void ScenePanels::Refresh() {
  refreshing_ = true;
  const nav_scene &s = doc_->Scene();
  const QVector<Issue> issues = Validate(s);
  for (NumField *f : fields_) {
    f->Refresh();
    // Issues of the committed scene (fields being typed keep their own as-you-type message).
    if (!f->Edit()->hasFocus()) {
      QStringList lines;
      for (const Issue &i : issues)
        if (i.path.startsWith(f->Path())) lines << i.Text();
      auto *msg = f->findChild<QLabel *>(f->Path() + ".message");
      if (msg) {
        msg->setText(lines.join("\n"));
        msg->setVisible(!lines.isEmpty());
      }
      f->Edit()->setStyleSheet(lines.isEmpty() ? QString() : QString(kErrorStyle));
    }
  }
  for (QComboBox *c : {scheme_, algorithm_, earth_, frame_, imu_catalog_, gnss_receiver_}) c->blockSignals(true);
  scheme_->setCurrentIndex(static_cast<int>(s.navigation.scheme));
  algorithm_->setCurrentIndex(static_cast<int>(s.navigation.algorithm));
  earth_->setCurrentIndex(static_cast<int>(s.earth.model));
  frame_->setCurrentIndex(static_cast<int>(s.navigation.frame));
  const int imu_i = imu_catalog_->findText(QString::fromUtf8(s.imu.catalog), Qt::MatchFixedString);
  imu_catalog_->setCurrentIndex(s.imu.catalog[0] && imu_i > 0 ? imu_i : 0);
  const int gi = gnss_receiver_->findText(QString::fromUtf8(s.gnss.catalog), Qt::MatchFixedString);
  gnss_receiver_->setCurrentIndex(s.gnss.catalog[0] && gi > 0 ? gi : 0);
  for (QComboBox *c : {scheme_, algorithm_, earth_, frame_, imu_catalog_, gnss_receiver_}) c->blockSignals(false);
  gnss_enabled_->blockSignals(true);
  gnss_enabled_->setChecked(s.gnss.enabled);
  gnss_enabled_->blockSignals(false);
  if (s.imu.catalog[0])
    imu_note_->setText(tr("From the catalog: %1. Edited terms override it.").arg(QString::fromUtf8(s.imu.catalog)));
  else
    imu_note_->setText(s.imu.model.gyro.terms || s.imu.model.accel.terms ? tr("Error terms of the scene.")
                                                                         : tr("Perfect IMU: no error terms."));
  RefreshWaypoints();
  RefreshOutages();
  RefreshRequirements();
  const QString plan = doc_->PlanMessage();
  if (s.trajectory.type != NAV_TRAJ_WAYPOINTS) {
    plan_label_->setText(tr("Trajectory type: %1 (click on the map to start a waypoint drive)")
                             .arg(nav_traj_type_name(s.trajectory.type)));
    plan_label_->setStyleSheet("color: #555;");
  } else if (plan.isEmpty()) {
    plan_label_->setText(tr("Feasible: %1 s of motion within the vehicle limits.").arg(s.trajectory.duration_s, 0, 'f', 1));
    plan_label_->setStyleSheet("color: #207020;");
  } else {
    plan_label_->setText(tr("Not feasible: %1").arg(plan));
    plan_label_->setStyleSheet("color: #c02020;");
  }
  refreshing_ = false;
}

void ScenePanels::RefreshWaypoints() {
  const bool prev = refreshing_;
  refreshing_ = true;
  wp_table_->blockSignals(true);
  const nav_scene &s = doc_->Scene();
  const bool geo = geodetic_->isChecked();
  wp_table_->setHorizontalHeaderLabels(geo ? QStringList{tr("lat [deg]"), tr("lon [deg]"), tr("h [m]"), tr("speed [m/s]")}
                                           : QStringList{tr("N [m]"), tr("E [m]"), tr("D [m]"), tr("speed [m/s]")});
  const int n = s.trajectory.type == NAV_TRAJ_WAYPOINTS ? s.trajectory.waypoints.count : 0;
  wp_table_->setRowCount(n);
  QStringList rows;
  for (int i = 0; i < n; ++i) rows << QString::number(i); // 0-based, as navcore's messages count them
  wp_table_->setVerticalHeaderLabels(rows);
  for (int i = 0; i < n; ++i) {
    const nav_waypoint &p = s.trajectory.waypoints.points[i];
    double v[4] = {p.r_ned_m.x, p.r_ned_m.y, p.r_ned_m.z, p.speed_mps};
    int prec[4] = {2, 2, 2, 3};
    if (geo) {
      const double ned[3] = {p.r_ned_m.x, p.r_ned_m.y, p.r_ned_m.z};
      LocalToGeodetic(s, ned, &v[0], &v[1], &v[2]);
      prec[0] = prec[1] = 7;
    }
    for (int c = 0; c < 4; ++c) {
      auto *it = wp_table_->item(i, c);
      if (!it) {
        it = new QTableWidgetItem;
        wp_table_->setItem(i, c, it);
      }
      it->setText(QString::number(v[c], 'f', prec[c]));
    }
  }
  wp_table_->blockSignals(false);
  refreshing_ = prev;
}

void ScenePanels::SelectWaypoint(int i) {
  refreshing_ = true;
  if (i >= 0 && i < wp_table_->rowCount())
    wp_table_->setCurrentCell(i, 0);
  else
    wp_table_->clearSelection();
  refreshing_ = false;
}

void ScenePanels::OnWaypointCellChanged(int row, int col) {
  if (refreshing_) return;
  bool ok = false;
  const double v = wp_table_->item(row, col)->text().trimmed().toDouble(&ok);
  if (!ok) {
    RefreshWaypoints();
    return;
  }
  const bool geo = geodetic_->isChecked();
  doc_->Edit(tr("Edit waypoint %1").arg(row), [row, col, v, geo](nav_scene &s) {
    if (row >= s.trajectory.waypoints.count) return;
    nav_waypoint &p = s.trajectory.waypoints.points[row];
    if (col == 3) {
      p.speed_mps = v;
    } else if (!geo) {
      (col == 0 ? p.r_ned_m.x : col == 1 ? p.r_ned_m.y : p.r_ned_m.z) = v;
    } else {
      double ned[3] = {p.r_ned_m.x, p.r_ned_m.y, p.r_ned_m.z}, lat, lon, h;
      LocalToGeodetic(s, ned, &lat, &lon, &h);
      (col == 0 ? lat : col == 1 ? lon : h) = v;
      GeodeticToLocal(s, lat, lon, h, ned);
      p.r_ned_m = nav_vec3{ned[0], ned[1], ned[2]};
    }
  });
}

void ScenePanels::RefreshOutages() {
  outages_->blockSignals(true);
  const nav_gnss_model_config &g = doc_->Scene().gnss.model;
  outages_->setRowCount(static_cast<int>(g.outage_count));
  for (int i = 0; i < static_cast<int>(g.outage_count); ++i) {
    const double v[2] = {g.outages[i].t0_s, g.outages[i].t1_s};
    for (int c = 0; c < 2; ++c) {
      auto *it = outages_->item(i, c);
      if (!it) {
        it = new QTableWidgetItem;
        outages_->setItem(i, c, it);
      }
      it->setText(Num(v[c]));
    }
  }
  outages_->blockSignals(false);
}

void ScenePanels::OnOutageCellChanged(int row, int col) {
  if (refreshing_) return;
  bool ok = false;
  const double v = outages_->item(row, col)->text().trimmed().toDouble(&ok);
  if (!ok) {
    RefreshOutages();
    return;
  }
  doc_->Edit(tr("Edit outage"), [row, col, v](nav_scene &s) {
    if (static_cast<size_t>(row) >= s.gnss.model.outage_count) return;
    (col == 0 ? s.gnss.model.outages[row].t0_s : s.gnss.model.outages[row].t1_s) = v;
  });
}

void ScenePanels::RefreshRequirements() {
  const nav_scene &s = doc_->Scene();
  req_table_->blockSignals(true);
  req_table_->setRowCount(s.n_requirements);
  for (int i = 0; i < s.n_requirements; ++i) {
    const nav_requirement &r = s.requirements[i];
    auto set = [&](int c, const QString &t, bool editable) {
      auto *it = req_table_->item(i, c);
      if (!it) {
        it = new QTableWidgetItem;
        req_table_->setItem(i, c, it);
      }
      it->setText(t);
      it->setFlags(editable ? it->flags() | Qt::ItemIsEditable : it->flags() & ~Qt::ItemIsEditable);
    };
    set(0, QString::fromUtf8(r.id), true);
    set(4, Num(r.limit), true);
    set(6, r.statistic == NAV_REQ_AT_TIME ? Num(r.time_s) : QString(), r.statistic == NAV_REQ_AT_TIME);
    // Enumerations: combo boxes.
    auto combo = [&](int c, int count, const char *(*name)(int), int cur, std::function<void(nav_requirement &, int)> apply) {
      auto *cb = qobject_cast<QComboBox *>(req_table_->cellWidget(i, c));
      if (!cb) {
        cb = new QComboBox;
        for (int k = 0; k < count; ++k) cb->addItem(QString::fromUtf8(name(k)));
        const int row = i;
        connect(cb, QOverload<int>::of(&QComboBox::activated), this, [this, row, apply](int k) {
          doc_->Edit(tr("Edit requirement"), [row, k, apply](nav_scene &sc) {
            if (row < sc.n_requirements) apply(sc.requirements[row], k);
          });
        });
        req_table_->setCellWidget(i, c, cb);
      }
      cb->blockSignals(true);
      cb->setCurrentIndex(cur);
      cb->blockSignals(false);
    };
    combo(2, NAV_REQ_METRIC_COUNT, [](int k) { return nav_req_metric_name(static_cast<nav_req_metric>(k)); },
          static_cast<int>(r.metric), [](nav_requirement &q, int k) {
            q.metric = static_cast<nav_req_metric>(k);
            // Keep the unit consistent with the metric's quantity.
            if (nav_req_unit_quantity(q.unit) != nav_req_metric_quantity(q.metric)) {
              const nav_req_quantity qq = nav_req_metric_quantity(q.metric);
              q.unit = qq == NAV_REQ_LENGTH ? NAV_REQ_UNIT_M : qq == NAV_REQ_SPEED ? NAV_REQ_UNIT_MPS : NAV_REQ_UNIT_DEG;
            }
          });
    combo(3, NAV_REQ_STATISTIC_COUNT, [](int k) { return nav_req_statistic_name(static_cast<nav_req_statistic>(k)); },
          static_cast<int>(r.statistic), [](nav_requirement &q, int k) { q.statistic = static_cast<nav_req_statistic>(k); });
    combo(5, NAV_REQ_UNIT_COUNT, [](int k) { return nav_req_unit_name(static_cast<nav_req_unit>(k)); },
          static_cast<int>(r.unit), [](nav_requirement &q, int k) { q.unit = static_cast<nav_req_unit>(k); });
    // Verdict of the last result for this id.
    QString verdict;
    QColor colour(Qt::black);
    for (const nav_requirement_verdict &v : verdicts_) {
      if (std::strcmp(v.id, r.id) != 0) continue;
      if (!v.evaluated)
        verdict = tr("not evaluated");
      else
        verdict = QStringLiteral("%1 %2 %3 (≤ %4)")
                      .arg(v.pass ? tr("PASS") : tr("FAIL"))
                      .arg(v.value, 0, 'g', 4)
                      .arg(QString::fromUtf8(nav_req_unit_name(v.unit)))
                      .arg(v.limit, 0, 'g', 4);
      colour = !v.evaluated ? QColor(120, 120, 120) : v.pass ? QColor(20, 130, 40) : QColor(200, 30, 30);
    }
    set(1, verdict, false);
    req_table_->item(i, 1)->setForeground(colour);
  }
  req_table_->blockSignals(false);
}

void ScenePanels::SetVerdicts(const std::vector<nav_requirement_verdict> &v) {
  verdicts_ = v;
  RefreshRequirements();
  if (v.empty()) {
    req_summary_->setText(tr("No requirement verdicts (add a requirement and run)."));
    req_summary_->setStyleSheet("color: #555;");
    return;
  }
  int pass = 0;
  for (const auto &x : v) pass += x.pass ? 1 : 0;
  const bool all = pass == static_cast<int>(v.size());
  req_summary_->setText(all ? tr("PASS: all %1 requirements met").arg(v.size())
                            : tr("FAIL: %1 of %2 requirements met").arg(pass).arg(v.size()));
  req_summary_->setStyleSheet(all ? "color: #148228; font-weight: bold;" : "color: #c81e1e; font-weight: bold;");
}

} // namespace studio
