#include "playback.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QHBoxLayout>
#include <QLabel>
#include <QSlider>
#include <QSpinBox>
#include <QStyle>
#include <QVBoxLayout>
#include <QToolButton>

#include <algorithm>
#include <cmath>

#include "navview/nav_view_scene.h"
#include "path_view.h"

extern "C" {
#include "navcore/nav_frames.h"
}

namespace studio {

namespace {
constexpr int kSliderSteps = 2000;
constexpr int kTickMs = 40; // 25 playback frames per second at most
const double kSpeeds[] = {0.5, 1, 2, 5, 10, 20, 50, 100};
constexpr int kDefaultSpeedIndex = 4; // 10x: urban-drive's 513 s in under a minute

void FillTrack(const std::vector<double> &t, const std::vector<double> &ned, const std::vector<double> &euler,
               const nav_frame &fr, NavTrack *out) {
  const size_t n = std::min({t.size(), ned.size() / 3, euler.size() / 3});
  out->t_s.assign(t.begin(), t.begin() + static_cast<long>(n));
  out->pos_ned_m.assign(ned.begin(), ned.begin() + static_cast<long>(3 * n));
  out->euler_rad.assign(euler.begin(), euler.begin() + static_cast<long>(3 * n));
  out->geo.resize(3 * n);
  for (size_t i = 0; i < n; ++i) {
    const nav_geodetic g = nav_frame_local_to_geodetic(&fr, nav_vec3{ned[3 * i], ned[3 * i + 1], ned[3 * i + 2]});
    out->geo[3 * i] = g.lat_rad;
    out->geo[3 * i + 1] = g.lon_rad;
    out->geo[3 * i + 2] = g.h_m;
  }
}
} // namespace

std::shared_ptr<NavResult> ToNavResult(const SimResult &r, const nav_scene &scene) {
  auto out = std::make_shared<NavResult>();
  out->scene_name = scene.name[0] ? scene.name : "navstudio";
  out->runs = static_cast<int>(std::max(1L, r.summary.runs > 0 ? static_cast<long>(r.summary.runs) : r.runs));
  const nav_frame fr = nav_frame_from_scene(&scene);
  FillTrack(r.t_s, r.truth_ned, r.truth_euler, fr, &out->truth);
  FillTrack(r.t_s, r.nav_ned, r.nav_euler, fr, &out->nav);
  NavErrorSeries &e = out->errors;
  const size_t n = out->truth.Size();
  if (r.err_h_m.size() >= n && r.err_ned_m.size() >= 3 * n && r.err_v_m.size() >= n && r.att_err_rad.size() >= n &&
      r.euler_err_rad.size() >= 3 * n) {
    e.t_s = out->truth.t_s;
    e.pos_err_ned_m.assign(r.err_ned_m.begin(), r.err_ned_m.begin() + static_cast<long>(3 * n));
    e.pos_err_h_m.assign(r.err_h_m.begin(), r.err_h_m.begin() + static_cast<long>(n));
    e.pos_err_v_m.assign(r.err_v_m.begin(), r.err_v_m.begin() + static_cast<long>(n));
    e.att_err_rad.assign(r.att_err_rad.begin(), r.att_err_rad.begin() + static_cast<long>(n));
    e.euler_err_rad.assign(r.euler_err_rad.begin(), r.euler_err_rad.begin() + static_cast<long>(3 * n));
    if (r.err_vel_mps.size() >= n)
      e.vel_err_mps.assign(r.err_vel_mps.begin(), r.err_vel_mps.begin() + static_cast<long>(n));
  }
  // The Monte Carlo envelope (a preview's single run has the filter's sigma only).
  const size_t m = r.env_t_s.size();
  if (!r.preview && m > 0 && r.env_h_rms_m.size() == m && r.env_rms_ned_m.size() == 3 * m) {
    NavEnvelope &v = out->envelope;
    v.t_s = r.env_t_s;
    v.pos_rms_ned_m = r.env_rms_ned_m;
    v.pos_h_rms_m = r.env_h_rms_m;
    if (r.env_att_rms_rad.size() == m) v.att_rms_rad = r.env_att_rms_rad;
    if (r.env_vel_rms_mps.size() == m) v.vel_rms_mps = r.env_vel_rms_mps;
    if (r.env_sd_ned_m.size() == 3 * m) v.pos_sd_reported_ned_m = r.env_sd_ned_m;
  } else if (r.preview && m > 0 && r.env_sd_ned_m.size() == 3 * m && r.env_h_rms_m.size() == m &&
             r.env_rms_ned_m.size() == 3 * m) {
    NavEnvelope &v = out->envelope;
    v.t_s = r.env_t_s;
    v.pos_rms_ned_m = r.env_rms_ned_m;
    v.pos_h_rms_m = r.env_h_rms_m;
    v.pos_sd_reported_ned_m = r.env_sd_ned_m;
  }
  for (const nav_gnss_outage &o : r.outages) {
    out->gnss.outage_t0_s.push_back(o.t0_s);
    out->gnss.outage_t1_s.push_back(o.t1_s);
  }
  // The requirement verdicts (limits on the error charts), as summary.json carries them.
  for (const nav_requirement_verdict &v : r.verdicts) {
    NavRequirementVerdict x;
    x.id = v.id;
    x.metric = nav_req_metric_name(v.metric);
    x.statistic = nav_req_statistic_name(v.statistic);
    x.unit = nav_req_unit_name(v.unit);
    x.limit = v.limit;
    x.value = v.value;
    x.limit_si = v.limit * nav_req_unit_to_si(v.unit);
    x.pass = v.pass;
    out->requirements.push_back(x);
  }
  return out;
}

NavViewOptions StudioViewOptions(const SimResult &r) {
  NavViewOptions o;
  o.show_grid = false; // the editor's ground grid is underneath
  o.show_axes = false;
  o.multisamples = 0; // the host window's
  o.ellipsoid_count = 6;
  if (r.preview)
    o.envelope_source = r.env_sd_ned_m.empty() ? NavEnvelopeSource::RunErrors : NavEnvelopeSource::Filter;
  else
    o.envelope_source = NavEnvelopeSource::MonteCarlo;
  return o;
}

PlaybackBar::PlaybackBar(PathView *view, QWidget *parent) : QWidget(parent), view_(view) {
  setObjectName("playbackBar");
  // Two rows: the time slider across the view, the buttons and settings under it.
  auto *rows = new QVBoxLayout(this);
  rows->setContentsMargins(4, 2, 4, 2);
  rows->setSpacing(2);
  auto *top = new QHBoxLayout;
  auto *lay = new QHBoxLayout;
  lay->setSpacing(4);
  rows->addLayout(top);
  rows->addLayout(lay);
  auto button = [&](QStyle::StandardPixmap icon, const QString &tip, const char *name) {
    auto *b = new QToolButton;
    b->setIcon(style()->standardIcon(icon));
    b->setToolTip(tip);
    b->setObjectName(name);
    b->setAutoRaise(true);
    lay->addWidget(b);
    return b;
  };
  slider_ = new QSlider(Qt::Horizontal);
  slider_->setObjectName("timeSlider");
  slider_->setRange(0, kSliderSteps);
  slider_->setToolTip(tr("Playback time: the vehicle, the attitude triads at t and the read-out"));
  top->addWidget(slider_, 1);
  time_label_ = new QLabel(tr("no result"));
  time_label_->setObjectName("playbackTime");
  time_label_->setMinimumWidth(time_label_->fontMetrics().horizontalAdvance(QStringLiteral("t = 0000.0 / 0000 s")));
  top->addWidget(time_label_);
  back_ = button(QStyle::SP_MediaSkipBackward, tr("Step back (1 s of the run)"), "stepBack");
  play_ = button(QStyle::SP_MediaPlay, tr("Play / pause the run"), "playButton");
  play_->setCheckable(true);
  fwd_ = button(QStyle::SP_MediaSkipForward, tr("Step forward (1 s of the run)"), "stepForward");
  speed_ = new QComboBox;
  speed_->setObjectName("playbackSpeed");
  for (double x : kSpeeds)
    speed_->addItem(QStringLiteral("%1\u00d7").arg(x), x);
  speed_->setCurrentIndex(kDefaultSpeedIndex);
  speed_->setToolTip(tr("Playback speed (run seconds per second)"));
  lay->addWidget(speed_);
  follow_ = new QCheckBox(tr("Follow"));
  follow_->setObjectName("followBox");
  follow_->setToolTip(tr("Camera follows the vehicle from behind at the distance on the right"));
  lay->addWidget(follow_);
  distance_ = new QSpinBox;
  distance_->setObjectName("followDistance");
  distance_->setRange(5, 50000);
  distance_->setValue(60);
  distance_->setSuffix(QStringLiteral(" m"));
  distance_->setToolTip(tr("Follow-camera distance"));
  lay->addWidget(distance_);
  lay->addStretch(1);
  auto *xl = new QLabel(tr("attitude error \u00d7"));
  lay->addWidget(xl);
  exag_ = new QDoubleSpinBox;
  exag_->setObjectName("exaggeration");
  exag_->setRange(1.0, 1000.0);
  exag_->setDecimals(0);
  exag_->setValue(kNavDefaultAttExaggeration);
  exag_->setToolTip(tr("Attitude-error exaggeration of the estimated triads (shown in the legend)"));
  lay->addWidget(exag_);

  timer_.setInterval(kTickMs);
  connect(&timer_, &QTimer::timeout, this, &PlaybackBar::Tick);
  connect(play_, &QToolButton::toggled, this, [this](bool on) { SetPlaying(on); });
  connect(back_, &QToolButton::clicked, this, [this] { Step(-1); });
  connect(fwd_, &QToolButton::clicked, this, [this] { Step(1); });
  connect(slider_, &QSlider::valueChanged, this, [this](int v) {
    if (updating_) return;
    SetTime(t0_ + (t1_ - t0_) * v / kSliderSteps);
  });
  connect(follow_, &QCheckBox::toggled, this, [this](bool on) { SetFollow(on); });
  connect(distance_, QOverload<int>::of(&QSpinBox::valueChanged), this, [this](int m) { SetFollowDistance(m); });
  connect(exag_, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this,
          [this](double k) { emit ExaggerationChanged(k); });
  SceneChanged();
}

void PlaybackBar::SceneChanged() {
  NavSceneView *sc = view_->Scene();
  const bool have = sc && sc->IsBuilt();
  for (QWidget *w : std::initializer_list<QWidget *>{play_, back_, fwd_, slider_, speed_, follow_, distance_})
    w->setEnabled(have);
  if (!have) {
    SetPlaying(false);
    view_->SetEditOverlayHidden(false);
    time_label_->setText(tr("no result"));
    return;
  }
  t0_ = sc->Model().t_begin_s;
  t1_ = sc->Model().t_end_s;
  t_s_ = std::clamp(sc->GetTime(), t0_, t1_);
  sc->SetFollow(follow_->isChecked(), distance_->value());
  view_->SetEditOverlayHidden(follow_->isChecked());
  ShowTime();
}

void PlaybackBar::ShowTime() {
  updating_ = true;
  slider_->setValue(t1_ > t0_ ? static_cast<int>(std::lround((t_s_ - t0_) / (t1_ - t0_) * kSliderSteps)) : 0);
  updating_ = false;
  time_label_->setText(QStringLiteral("t = %1 / %2 s").arg(t_s_, 0, 'f', 1).arg(t1_, 0, 'f', 0));
}

void PlaybackBar::SetTime(double t_s) {
  NavSceneView *sc = view_->Scene();
  if (!sc || !sc->IsBuilt()) return;
  t_s_ = std::clamp(t_s, t0_, t1_);
  sc->SetTime(t_s_);
  ShowTime();
  view_->Render();
}

void PlaybackBar::SetPlaying(bool on) {
  if (on && !(view_->Scene() && view_->Scene()->IsBuilt())) on = false;
  if (on) {
    if (t_s_ >= t1_) SetTime(t0_);
    QElapsedTimer now;
    now.start();
    last_tick_ns_ = now.msecsSinceReference() * 1000000;
    timer_.start();
  } else {
    timer_.stop();
  }
  if (play_->isChecked() != on) play_->setChecked(on);
  play_->setIcon(style()->standardIcon(on ? QStyle::SP_MediaPause : QStyle::SP_MediaPlay));
}

void PlaybackBar::Tick() {
  QElapsedTimer now;
  now.start();
  const qint64 ns = now.msecsSinceReference() * 1000000;
  // Advance by the wall time since the last tick (a slow frame does not slow the run down),
  // at most half a second of wall time per tick.
  const double dt = std::min(0.5, (ns - last_tick_ns_) * 1e-9);
  last_tick_ns_ = ns;
  SetTime(t_s_ + Speed() * dt);
  if (t_s_ >= t1_) SetPlaying(false);
}

void PlaybackBar::SetSpeed(double x) {
  int best = 0;
  for (int i = 0; i < speed_->count(); ++i)
    if (std::fabs(speed_->itemData(i).toDouble() - x) < std::fabs(speed_->itemData(best).toDouble() - x)) best = i;
  speed_->setCurrentIndex(best);
}

double PlaybackBar::Speed() const { return speed_->currentData().toDouble(); }

void PlaybackBar::Step(int direction) { SetTime(t_s_ + (direction < 0 ? -1.0 : 1.0)); }

void PlaybackBar::SetFollow(bool on) {
  if (follow_->isChecked() != on) {
    follow_->setChecked(on); // comes back here through toggled
    return;
  }
  NavSceneView *sc = view_->Scene();
  if (sc && sc->IsBuilt()) {
    sc->SetFollow(on, distance_->value());
    view_->SetEditOverlayHidden(on);
    if (!on) view_->ResetCamera();
    view_->Render();
  }
}

bool PlaybackBar::Follow() const { return follow_->isChecked(); }

void PlaybackBar::SetFollowDistance(double m) {
  if (distance_->value() != static_cast<int>(std::lround(m))) {
    distance_->setValue(static_cast<int>(std::lround(m)));
    return;
  }
  NavSceneView *sc = view_->Scene();
  if (sc && sc->IsBuilt() && follow_->isChecked()) {
    sc->SetFollow(true, m);
    view_->Render();
  }
}

double PlaybackBar::FollowDistance() const { return distance_->value(); }

void PlaybackBar::SetExaggeration(double k) { exag_->setValue(k); }

double PlaybackBar::Exaggeration() const { return exag_->value(); }

} // namespace studio
