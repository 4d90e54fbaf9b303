#include "error_chart.h"

#include <QPainter>
#include <QPainterPath>

#include <algorithm>
#include <cmath>

namespace studio {

ErrorChart::ErrorChart(QWidget *parent) : QWidget(parent) {
  setObjectName("errorChart");
  setMinimumHeight(120);
}

void ErrorChart::SetResult(std::shared_ptr<const SimResult> r) {
  result_ = std::move(r);
  update();
}

void ErrorChart::paintEvent(QPaintEvent *) {
  QPainter p(this);
  p.setRenderHint(QPainter::Antialiasing);
  p.fillRect(rect(), QColor(252, 252, 250));
  const QRectF plot(52, 10, width() - 64, height() - 36);
  p.setPen(QColor(120, 120, 120));
  p.drawRect(plot);
  if (!result_ || result_->t_s.empty()) {
    p.drawText(plot, Qt::AlignCenter, tr("horizontal error: run a simulation"));
    return;
  }
  const SimResult &r = *result_;
  const double t0 = r.t_s.front(), t1 = std::max(r.t_s.back(), t0 + 1e-9);
  double ymax = 0.0;
  for (double v : r.err_h_m) ymax = std::max(ymax, v);
  for (double v : r.env_h_rms_m) ymax = std::max(ymax, v);
  if (!(ymax > 0.0) || !std::isfinite(ymax)) ymax = 1.0;
  ymax *= 1.1;
  auto X = [&](double t) { return plot.left() + (t - t0) / (t1 - t0) * plot.width(); };
  auto Y = [&](double v) { return plot.bottom() - v / ymax * plot.height(); };
  for (const nav_gnss_outage &o : r.outages) {
    const double a = std::max(o.t0_s, t0), b = std::min(o.t1_s, t1);
    if (b > a) p.fillRect(QRectF(X(a), plot.top(), X(b) - X(a), plot.height()), QColor(255, 225, 200));
  }
  auto draw = [&](const std::vector<double> &t, const std::vector<double> &v, QColor c, double w) {
    if (t.size() < 2 || v.size() != t.size()) return;
    QPainterPath path;
    path.moveTo(X(t[0]), Y(v[0]));
    for (size_t i = 1; i < t.size(); ++i) path.lineTo(X(t[i]), Y(v[i]));
    p.setPen(QPen(c, w));
    p.drawPath(path);
  };
  draw(r.t_s, r.err_h_m, QColor(240, 140, 10), 1.2);
  draw(r.env_t_s, r.env_h_rms_m, QColor(200, 20, 110), 2.0);
  p.setPen(Qt::black);
  QFont f = p.font();
  f.setPointSizeF(8.5);
  p.setFont(f);
  p.drawText(QPointF(4, plot.top() + 10), QString::number(ymax, 'g', 3) + " m");
  p.drawText(QPointF(4, plot.bottom()), "0");
  p.drawText(QPointF(plot.left(), height() - 8), QString::number(t0, 'f', 0) + " s");
  p.drawText(QPointF(plot.right() - 40, height() - 8), QString::number(t1, 'f', 0) + " s");
  QString legend = tr("horizontal error: run 0 (orange)");
  if (!r.env_t_s.empty()) legend += tr(", RMS over %1 runs (magenta)").arg(r.summary.runs);
  if (!r.outages.empty()) legend += tr(", GNSS outages shaded");
  p.drawText(QPointF(plot.left() + 60, height() - 8), legend);
}

} // namespace studio
