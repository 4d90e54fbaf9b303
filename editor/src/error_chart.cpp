#include "error_chart.h"

#include <QEvent>
#include <QLabel>
#include <QMouseEvent>
#include <QPainter>
#include <QPixmap>
#include <QResizeEvent>
#include <QScrollBar>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "navview/nav_view_chart.h"
#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"

namespace studio {

namespace {
constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

/* A value with about three significant digits, without an exponent for ordinary errors. */
QString Num(double v) {
  if (!std::isfinite(v)) return QStringLiteral("n/a");
  const double a = std::fabs(v);
  if (a >= 100.0) return QString::number(v, 'f', 1);
  if (a >= 1.0) return QString::number(v, 'f', 2);
  if (a >= 0.01 || a == 0.0) return QString::number(v, 'f', 3);
  return QString::number(v, 'g', 3);
}

/* The panel's curves at epoch @p i: value and colour of each marker (the chart's colours). */
struct Mark {
  double y;
  QColor colour;
};

std::vector<Mark> PanelMarks(const NavResult &r, const std::string &panel, size_t i) {
  const NavErrorSeries &e = r.errors;
  if (panel == "horizontal") return {{e.pos_err_h_m[i], QColor(214, 39, 40)}};
  if (panel == "vertical") return {{e.pos_err_v_m[i], QColor(214, 39, 40)}};
  if (panel == "velocity" && i < e.vel_err_mps.size()) return {{e.vel_err_mps[i], QColor(214, 39, 40)}};
  if (panel == "attitude")
    return {{e.euler_err_rad[3 * i] * kRadToDeg, QColor(204, 20, 20)},
            {e.euler_err_rad[3 * i + 1] * kRadToDeg, QColor(20, 140, 30)},
            {e.euler_err_rad[3 * i + 2] * kRadToDeg, QColor(20, 60, 210)}};
  return {};
}

/* The read-out of panel @p panel at epoch @p i: the time, run 0's values, the Monte Carlo RMS
 * and the filter's reported 1 sigma where the result has them. */
QString PanelText(const NavResult &r, const std::string &panel, size_t i) {
  const NavErrorSeries &e = r.errors;
  const NavEnvelope &env = r.envelope;
  const double t = e.t_s[i];
  const double dt = e.Size() > 1 ? (e.t_s.back() - e.t_s.front()) / double(e.Size() - 1) : 1.0;
  const int td = dt >= 1.0 ? 0 : dt >= 0.1 ? 1 : 2;
  QStringList parts{QStringLiteral("t = %1 s").arg(t, 0, 'f', td)};
  const bool mc = env.Size() > 0 && r.runs > 1;
  const QString runs = QStringLiteral("RMS of %1 runs").arg(r.runs);
  double s3[3] = {NAN, NAN, NAN};
  const bool filter = NavSigmaNed(r, NavEnvelopeSource::Filter, t, s3);
  if (panel == "horizontal") {
    parts << QStringLiteral("horizontal %1 m").arg(Num(e.pos_err_h_m[i]));
    if (mc)
      parts << QStringLiteral("%1 %2 m").arg(runs, Num(NavInterpolate(env.t_s, env.pos_h_rms_m, 1, 0, t)));
    if (filter) parts << QStringLiteral("filter 1\u03c3 %1 m").arg(Num(std::hypot(s3[0], s3[1])));
  } else if (panel == "vertical") {
    parts << QStringLiteral("vertical %1 m").arg(Num(e.pos_err_v_m[i]));
    if (mc)
      parts << QStringLiteral("%1 %2 m").arg(runs, Num(NavInterpolate(env.t_s, env.pos_rms_ned_m, 3, 2, t)));
    if (filter) parts << QStringLiteral("filter 1\u03c3 %1 m").arg(Num(s3[2]));
  } else if (panel == "velocity") {
    parts << QStringLiteral("velocity %1 m/s").arg(Num(i < e.vel_err_mps.size() ? e.vel_err_mps[i] : NAN));
    if (mc && env.vel_rms_mps.size() == env.Size())
      parts << QStringLiteral("%1 %2 m/s").arg(runs, Num(NavInterpolate(env.t_s, env.vel_rms_mps, 1, 0, t)));
  } else if (panel == "attitude") {
    parts << QStringLiteral("roll %1\u00b0").arg(Num(e.euler_err_rad[3 * i] * kRadToDeg))
          << QStringLiteral("pitch %1\u00b0").arg(Num(e.euler_err_rad[3 * i + 1] * kRadToDeg))
          << QStringLiteral("yaw %1\u00b0").arg(Num(e.euler_err_rad[3 * i + 2] * kRadToDeg));
    if (mc && env.att_rms_rad.size() == env.Size())
      parts << QStringLiteral("%1 %2\u00b0")
                   .arg(runs, Num(NavInterpolate(env.t_s, env.att_rms_rad, 1, 0, t) * kRadToDeg));
  }
  return parts.join(QStringLiteral(" \u00b7 "));
}
} // namespace

/* Drawn over the picture: the hover line through every panel, the markers on the hovered
 * panel's curves and the read-out label. Mouse events pass through to the picture. */
class ChartHoverOverlay : public QWidget {
public:
  ChartHoverOverlay(ErrorChart *chart, QWidget *parent) : QWidget(parent), chart_(chart) {
    setAttribute(Qt::WA_TransparentForMouseEvents);
    setObjectName("errorChartHover");
  }

protected:
  void paintEvent(QPaintEvent *) override {
    const ErrorChart *c = chart_;
    const NavErrorChartLayout &l = c->layout_;
    if (c->hover_panel_ < 0 || !c->nav_ || c->picture_.isNull()) return;
    const size_t k = static_cast<size_t>(c->hover_panel_);
    const double h = c->picture_.height();
    QPainter p(this);
    p.setRenderHint(QPainter::Antialiasing);
    const int x = c->hover_x_;
    QPen line(QColor(40, 40, 50, 200), 1.0, Qt::DashLine);
    p.setPen(line);
    for (const NavChartRect &r : l.plots)
      p.drawLine(QPointF(x + 0.5, h - (r.y + r.h)), QPointF(x + 0.5, h - r.y));
    const NavChartRect &r = l.plots[k];
    for (const Mark &m : PanelMarks(*c->nav_, l.titles[k], c->hover_epoch_)) {
      const double span = l.y_max[k] - l.y_min[k];
      if (!std::isfinite(m.y) || !(span > 0)) continue;
      const double y = h - (r.y + (m.y - l.y_min[k]) / span * r.h);
      if (y < h - (r.y + r.h) - 1 || y > h - r.y + 1) continue;
      p.setPen(QPen(Qt::white, 1.5));
      p.setBrush(m.colour);
      p.drawEllipse(QPointF(x + 0.5, y), 4.0, 4.0);
    }
    // The label, one value a line, at the top of the hovered plot: right of the line, or left of
    // it when the plot's right edge is near (never over the legend right of the plot).
    const QStringList lines = c->readout_.split(QStringLiteral(" \u00b7 "));
    const QFontMetrics fm(font());
    const int pad = 5;
    int tw = 0;
    for (const QString &s : lines)
      tw = std::max(tw, fm.horizontalAdvance(s));
    const int bw = tw + 2 * pad, bh = static_cast<int>(lines.size()) * fm.lineSpacing() + 2 * pad;
    int bx = x + 8;
    if (bx + bw > r.x + r.w) bx = std::max(0, x - 8 - bw);
    const int by = static_cast<int>(h - (r.y + r.h)) + 3;
    p.setPen(QPen(QColor(120, 120, 130), 1.0));
    p.setBrush(QColor(255, 255, 255, 235));
    p.drawRoundedRect(QRectF(bx + 0.5, by + 0.5, bw, bh), 3, 3);
    p.setPen(QColor(15, 15, 20));
    for (int k2 = 0; k2 < lines.size(); ++k2)
      p.drawText(QPoint(bx + pad, by + pad + fm.ascent() + k2 * fm.lineSpacing()), lines[k2]);
  }

private:
  ErrorChart *chart_;
};

ErrorChart::ErrorChart(QWidget *parent) : QScrollArea(parent) {
  setObjectName("errorChart");
  setMinimumHeight(120);
  setWidgetResizable(false);
  setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  label_ = new QLabel;
  label_->setObjectName("errorChartPicture");
  label_->setAlignment(Qt::AlignCenter);
  label_->setText(tr("Errors against time: run a simulation (F5)"));
  label_->setMouseTracking(true); // the hover read-out follows the cursor without a button
  label_->installEventFilter(this);
  overlay_ = new ChartHoverOverlay(this, label_);
  overlay_->hide();
  setWidget(label_);
  setAlignment(Qt::AlignHCenter | Qt::AlignTop);
  // A resize (a dragged splitter) redraws once it pauses.
  redraw_.setSingleShot(true);
  redraw_.setInterval(250);
  connect(&redraw_, &QTimer::timeout, this, [this] {
    if (isVisible()) Draw();
  });
}

void ErrorChart::SetResult(std::shared_ptr<const SimResult> r, std::shared_ptr<const NavResult> result) {
  ClearHover();
  result_ = std::move(r);
  nav_ = std::move(result);
  picture_ = QImage();
  message_.clear();
  due_ = true;
  if (isVisible())
    Draw();
  else if (!nav_)
    Draw(); // the hint, at once
}

void ErrorChart::showEvent(QShowEvent *e) {
  QScrollArea::showEvent(e);
  if (due_) Draw();
}

void ErrorChart::resizeEvent(QResizeEvent *e) {
  QScrollArea::resizeEvent(e);
  if (nav_ && e->size().width() != e->oldSize().width()) {
    due_ = true;
    redraw_.start();
  } else if (!nav_) {
    label_->resize(viewport()->size());
  }
}

QImage ErrorChart::Picture() {
  if (due_) Draw();
  return picture_;
}

void ErrorChart::Draw() {
  due_ = false;
  ClearHover();
  layout_ = NavErrorChartLayout();
  if (!nav_) {
    picture_ = QImage();
    label_->setPixmap(QPixmap());
    label_->setText(message_.isEmpty() ? tr("Errors against time: run a simulation (F5)") : message_);
    label_->resize(viewport()->size());
    return;
  }
  NavChartOptions o;
  o.width_px = std::max(320, viewport()->width());
  o.height_px = std::max(kMinChartHeightPx, viewport()->height());
  std::vector<unsigned char> rgb;
  std::string err;
  if (!NavRenderErrorChartRgb(*nav_, o, &rgb, &layout_, &err)) {
    message_ = QString::fromStdString(err);
    picture_ = QImage();
    label_->setPixmap(QPixmap());
    label_->setText(message_);
    label_->resize(viewport()->size());
    return;
  }
  message_.clear();
  picture_ = QImage(rgb.data(), o.width_px, o.height_px, 3 * o.width_px, QImage::Format_RGB888).copy();
  label_->setPixmap(QPixmap::fromImage(picture_));
  label_->resize(picture_.size());
  overlay_->setGeometry(label_->rect());
}

QString ErrorChart::ReadoutAt(QPoint p, bool show) {
  const NavErrorChartLayout &l = layout_;
  int panel = -1;
  if (nav_ && !picture_.isNull() && nav_->errors.Size() >= 2 && l.t_min_s.size() == l.plots.size()) {
    // The layout counts rows from the bottom of the picture.
    const double xb = p.x() + 0.5, yb = picture_.height() - (p.y() + 0.5);
    for (size_t k = 0; k < l.plots.size(); ++k) {
      const NavChartRect &r = l.plots[k];
      if (xb >= r.x && xb <= r.x + r.w && yb >= r.y && yb <= r.y + r.h) panel = static_cast<int>(k);
    }
  }
  if (panel < 0) {
    if (show) ClearHover();
    return QString();
  }
  const size_t k = static_cast<size_t>(panel);
  const NavChartRect &r = l.plots[k];
  const double t = l.t_min_s[k] + (p.x() + 0.5 - r.x) / r.w * (l.t_max_s[k] - l.t_min_s[k]);
  // The epoch nearest to the cursor's time.
  const std::vector<double> &ts = nav_->errors.t_s;
  size_t i = NavTimeIndex(ts, t);
  if (i + 1 < ts.size() && std::fabs(ts[i + 1] - t) < std::fabs(t - ts[i])) ++i;
  const QString text = PanelText(*nav_, l.titles[k], i);
  if (show) {
    hover_panel_ = panel;
    hover_epoch_ = i;
    hover_x_ = static_cast<int>(
        std::lround(r.x + (ts[i] - l.t_min_s[k]) / (l.t_max_s[k] - l.t_min_s[k]) * r.w - 0.5));
    if (text != readout_) {
      readout_ = text;
      emit ReadoutChanged(readout_);
    }
    overlay_->setGeometry(label_->rect());
    overlay_->show();
    overlay_->raise();
    overlay_->update();
  }
  return text;
}

void ErrorChart::ClearHover() {
  hover_panel_ = -1;
  if (overlay_) {
    overlay_->hide();
  }
  if (!readout_.isEmpty()) {
    readout_.clear();
    emit ReadoutChanged(readout_);
  }
}

bool ErrorChart::eventFilter(QObject *o, QEvent *e) {
  if (o == label_) {
    if (e->type() == QEvent::MouseMove)
      ReadoutAt(static_cast<QMouseEvent *>(e)->pos(), true);
    else if (e->type() == QEvent::Leave)
      ClearHover();
  }
  return QScrollArea::eventFilter(o, e);
}

} // namespace studio
