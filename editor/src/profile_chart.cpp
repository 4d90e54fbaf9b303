#include "profile_chart.h"

#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cmath>

namespace studio {

namespace {
constexpr int kProfilePoints = 500;
// The plot's horizontal extent in the widget [px]: left of it the lane labels.
constexpr double kPlotLeftPx = 150.0, kPlotRightMarginPx = 12.0;
// A drag shorter than this adds no outage (a click) [px].
constexpr int kMinOutageDragPx = 4;
} // namespace

double ProfileChart::XAtTime(double t) {
  const PathSamples &pr = Profile();
  if (pr.Size() < 2) return NAN;
  const double t0 = pr.t_s.front(), t1 = std::max(pr.t_s.back(), t0 + 1e-9);
  return kPlotLeftPx + (t - t0) / (t1 - t0) * (width() - kPlotRightMarginPx - kPlotLeftPx);
}

double ProfileChart::TimeAtX(double x) {
  const PathSamples &pr = Profile();
  if (pr.Size() < 2) return NAN;
  const double t0 = pr.t_s.front(), t1 = std::max(pr.t_s.back(), t0 + 1e-9);
  const double f = (x - kPlotLeftPx) / (width() - kPlotRightMarginPx - kPlotLeftPx);
  return t0 + std::clamp(f, 0.0, 1.0) * (t1 - t0);
}

void ProfileChart::mousePressEvent(QMouseEvent *e) {
  if (e->button() != Qt::LeftButton || Profile().Size() < 2 || e->pos().x() < kPlotLeftPx) {
    QWidget::mousePressEvent(e);
    return;
  }
  drag_x0_ = drag_x1_ = e->pos().x();
  dragging_ = true;
  update();
}

void ProfileChart::mouseMoveEvent(QMouseEvent *e) {
  if (!dragging_) return;
  drag_x1_ = e->pos().x();
  update();
}

void ProfileChart::mouseReleaseEvent(QMouseEvent *e) {
  if (!dragging_) return;
  dragging_ = false;
  drag_x1_ = e->pos().x();
  update();
  if (std::abs(drag_x1_ - drag_x0_) < kMinOutageDragPx) return;
  // The span dragged over the time axis becomes a GNSS outage (one undo step), at 0.1 s.
  double a = TimeAtX(std::min(drag_x0_, drag_x1_)), b = TimeAtX(std::max(drag_x0_, drag_x1_));
  a = std::round(a * 10.0) / 10.0;
  b = std::round(b * 10.0) / 10.0;
  if (!(b > a)) return;
  doc_->Edit(tr("Add GNSS outage %1-%2 s").arg(a).arg(b), [a, b](nav_scene &s) {
    nav_gnss_model_config &g = s.gnss.model;
    if (g.outage_count >= NAV_GNSS_MAX_OUTAGES) return;
    g.outages[g.outage_count].t0_s = a;
    g.outages[g.outage_count].t1_s = b;
    ++g.outage_count;
  });
}

ProfileChart::ProfileChart(SceneDocument *doc, QWidget *parent) : QWidget(parent), doc_(doc) {
  setObjectName("profileChart");
  setMinimumHeight(120);
  // Coalesced like the views: a drag redraws the chart once per event-loop pass.
  timer_.setSingleShot(true);
  connect(&timer_, &QTimer::timeout, this, &ProfileChart::Recompute);
  // During a live drag too: the window holds its repaints until the live preview's estimate is
  // drawn (MainWindow), so the chart changes with the views' path and estimate, not before them.
  connect(doc_, &SceneDocument::Changed, this, [this] { timer_.start(0); });
  Recompute();
}

void ProfileChart::Recompute() {
  timer_.stop();
  if (!SamplePath(doc_->Scene(), kProfilePoints, &prof_, &msg_)) prof_ = PathSamples();
  if (msg_.isEmpty() && !doc_->PlanMessage().isEmpty()) msg_ = doc_->PlanMessage();
  update();
}

const PathSamples &ProfileChart::Profile() {
  if (timer_.isActive()) Recompute();
  return prof_;
}

QString ProfileChart::Message() {
  Profile();
  return msg_;
}

void ProfileChart::Utilisation(double *accel, double *turn, double *lateral) {
  const PathSamples &p = Profile();
  *accel = *turn = *lateral = 0.0;
  const nav_traj_limits &L = p.limits;
  for (size_t i = 0; i < p.Size(); ++i) {
    if (L.max_accel_mps2 > 0) *accel = std::max(*accel, std::fabs(p.accel_mps2[i]) / L.max_accel_mps2);
    if (L.max_rate_rps > 0) *turn = std::max(*turn, std::fabs(p.turn_rps[i]) / L.max_rate_rps);
    if (L.max_lateral_accel_mps2 > 0)
      *lateral = std::max(*lateral, std::fabs(p.turn_rps[i]) * p.speed_mps[i] / L.max_lateral_accel_mps2);
  }
}

void ProfileChart::paintEvent(QPaintEvent *) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  p.fillRect(rect(), QColor(252, 252, 250));
  QFont f = p.font();
  f.setPointSizeF(8.5);
  p.setFont(f);
  const double left = kPlotLeftPx, right = width() - kPlotRightMarginPx, top = 6, bottom = height() - 18.0;
  const PathSamples &pr = prof_;
  if (pr.Size() < 2) {
    // A drive still being drawn (fewer than two waypoints) is not an error: grey, and what to do.
    const nav_scene &s = doc_->Scene();
    const bool drawing = msg_.isEmpty() || (s.trajectory.type == NAV_TRAJ_WAYPOINTS && s.trajectory.waypoints.count < 2);
    p.setPen(drawing ? QColor(90, 90, 90) : QColor(200, 20, 20));
    p.drawText(rect().adjusted(8, 4, -8, -4), Qt::AlignCenter | Qt::TextWordWrap,
               drawing ? tr("Profile: speed, acceleration and turn rate along the drive appear here once it has two "
                            "waypoints (click on the map)")
                       : tr("Profile: the plan is not feasible: %1").arg(msg_));
    return;
  }
  const double t0 = pr.t_s.front(), t1 = std::max(pr.t_s.back(), t0 + 1e-9);
  auto X = [&](double t) { return left + (t - t0) / (t1 - t0) * (right - left); };
  const nav_traj_limits &L = pr.limits;
  const double lane_h = (bottom - top) / 3.0;
  const double r2d = 180.0 / M_PI;
  // GNSS outages: pink spans (the 3D view's outage colour) under the curves, across the lanes.
  outage_rects_.clear();
  const nav_scene &sc = doc_->Scene();
  if (sc.gnss.enabled) {
    for (size_t i = 0; i < sc.gnss.model.outage_count; ++i) {
      const double a = std::max(sc.gnss.model.outages[i].t0_s, t0),
                   b = std::min(sc.gnss.model.outages[i].t1_s, t1);
      if (!(b > a)) continue;
      const QRectF span(X(a), top, X(b) - X(a), bottom - top);
      p.fillRect(span, kOutageTint);
      outage_rects_.push_back(span);
      // Named inside the span's top edge.
      p.setPen(QColor(170, 40, 120));
      p.drawText(
          QRectF(span.left() + 2, top + 1, std::max(span.width() - 2, 30.0), 14),
          Qt::AlignLeft | Qt::AlignTop,
          p.fontMetrics().elidedText(tr("GNSS outage"), Qt::ElideRight, static_cast<int>(span.width()) - 2));
    }
  }
  struct Lane {
    QString name, unit;
    const std::vector<double> *v;
    double scale;     // display units per SI unit
    double limit;     // display units (0: none)
    bool symmetric;   // -max..max, else 0..max
    unsigned char bit;
    QColor colour;
  };
  const Lane lanes[3] = {
      {tr("speed"), "m/s", &pr.speed_mps, 1.0, 0.0, false, 0, QColor(20, 90, 200)},
      {tr("accel."), "m/s²", &pr.accel_mps2, 1.0, L.max_accel_mps2, true, kOverAccel, QColor(20, 140, 60)},
      {tr("turn rate"), "°/s", &pr.turn_rps, r2d, L.max_rate_rps * r2d, true, kOverTurnRate | kOverLateral,
       QColor(150, 60, 170)},
  };
  for (int k = 0; k < 3; ++k) {
    const Lane &ln = lanes[k];
    const QRectF box(left, top + k * lane_h + 2, right - left, lane_h - 4);
    p.setPen(QColor(170, 170, 170));
    p.drawRect(box);
    double vmax = 0.0, peak = 0.0;
    for (double v : *ln.v) peak = std::max(peak, std::fabs(v) * ln.scale);
    vmax = std::max(peak, ln.limit) * 1.1;
    if (!(vmax > 0.0) || !std::isfinite(vmax)) vmax = 1.0;
    auto Y = [&](double v) {
      return ln.symmetric ? box.center().y() - v / vmax * 0.5 * box.height() : box.bottom() - v / vmax * box.height();
    };
    if (ln.symmetric) {
      p.setPen(QPen(QColor(200, 200, 200), 1.0));
      p.drawLine(QPointF(box.left(), Y(0)), QPointF(box.right(), Y(0)));
    }
    // Limits: dashed red lines; the turn rate's also from the lateral acceleration at the speed.
    QPen lim(QColor(215, 40, 40), 1.0, Qt::DashLine);
    p.setPen(lim);
    if (ln.limit > 0.0)
      for (double sgn : {1.0, -1.0}) p.drawLine(QPointF(box.left(), Y(sgn * ln.limit)), QPointF(box.right(), Y(sgn * ln.limit)));
    if (k == 2 && L.max_lateral_accel_mps2 > 0.0) {
      for (double sgn : {1.0, -1.0}) {
        QPainterPath path;
        bool started = false;
        for (size_t i = 0; i < pr.Size(); ++i) {
          const double v = pr.speed_mps[i];
          if (v < 0.5) {
            started = false;
            continue;
          }
          const double lim_t = std::min(L.max_lateral_accel_mps2 / v * r2d, vmax);
          if (ln.limit > 0 && lim_t >= ln.limit) {
            started = false;
            continue;
          }
          const QPointF pt(X(pr.t_s[i]), Y(sgn * lim_t));
          if (started)
            path.lineTo(pt);
          else
            path.moveTo(pt);
          started = true;
        }
        p.setPen(QPen(QColor(230, 120, 40), 1.0, Qt::DashLine));
        p.drawPath(path);
      }
    }
    // The curve, red where a limit is exceeded.
    QPainterPath ok, bad;
    for (size_t i = 0; i + 1 < pr.Size(); ++i) {
      const QPointF a(X(pr.t_s[i]), Y((*ln.v)[i] * ln.scale)), b(X(pr.t_s[i + 1]), Y((*ln.v)[i + 1] * ln.scale));
      QPainterPath &pp = (ln.bit && (pr.over[i] & ln.bit)) ? bad : ok;
      pp.moveTo(a);
      pp.lineTo(b);
    }
    p.setPen(QPen(ln.colour, 1.6));
    p.drawPath(ok);
    p.setPen(QPen(QColor(220, 0, 0), 2.6));
    p.drawPath(bad);
    p.setPen(Qt::black);
    QString label = QStringLiteral("%1 [%2]\nmax %3").arg(ln.name, ln.unit).arg(peak, 0, 'f', peak < 10 ? 2 : 1);
    if (ln.limit > 0.0) label += QStringLiteral(" / %1").arg(ln.limit, 0, 'f', ln.limit < 10 ? 2 : 1);
    p.drawText(QRectF(4, box.top(), left - 8, box.height()), Qt::AlignVCenter | Qt::AlignLeft, label);
  }
  p.setPen(Qt::black);
  p.drawText(QPointF(left, height() - 4), QString::number(t0, 'f', 0) + " s");
  p.drawText(QPointF(right - 50, height() - 4), QString::number(t1, 'f', 0) + " s");
  unsigned all = 0;
  for (unsigned char b : pr.over) all |= b;
  if (dragging_) {
    // The outage being dragged out.
    const double a = std::clamp(static_cast<double>(std::min(drag_x0_, drag_x1_)), left, right);
    const double b = std::clamp(static_cast<double>(std::max(drag_x0_, drag_x1_)), left, right);
    p.fillRect(QRectF(a, top, b - a, bottom - top), QColor(230, 90, 170, 70));
  }
  QString legend =
      tr("limits dashed (turn rate: also lateral acceleration / speed); drag across to add a GNSS outage");
  if (all) legend = tr("over the vehicle limits (red): %1").arg(OverLimitText(all));
  p.setPen(all ? QColor(200, 0, 0) : QColor(60, 60, 60));
  // Between the time labels, elided when the chart is narrow.
  p.drawText(QPointF(left + 60, height() - 4),
             p.fontMetrics().elidedText(legend, Qt::ElideRight,
                                        static_cast<int>(std::max(40.0, right - 60 - (left + 60)))));
}

} // namespace studio
