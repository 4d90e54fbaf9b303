/*
 * navstudio: the profile chart under the views: speed, longitudinal acceleration and turn rate
 * along the planned path against time (navcore's trajectory evaluation through SamplePath), with
 * the vehicle limits as dashed lines (turn rate: the lesser of the rate limit and the lateral
 * acceleration limit over the speed); samples over a limit are red; GNSS outages shaded pink, and
 * a drag across the time axis adds one. An infeasible plan shows the planner's message instead.
 * QPainter only; GUI thread.
 */
#ifndef NAVSTUDIO_PROFILE_CHART_H
#define NAVSTUDIO_PROFILE_CHART_H

#include <QColor>
#include <QRectF>
#include <QString>
#include <QVector>
#include <QTimer>
#include <QWidget>

#include "studio_scene.h"

namespace studio {

/** GNSS outage spans in the charts: the 3D view's outage pink over the chart's background. */
const QColor kOutageTint(245, 200, 228);

class ProfileChart : public QWidget {
  Q_OBJECT
public:
  explicit ProfileChart(SceneDocument *doc, QWidget *parent = nullptr);
  QSize sizeHint() const override { return QSize(600, 150); }
  /** The profile drawn (brought up to date first; tests). */
  const PathSamples &Profile();
  /** "" or why there is no profile (planner message). */
  QString Message();
  /** Largest |value| / limit over the path for acceleration, turn rate, lateral acceleration. */
  void Utilisation(double *accel, double *turn, double *lateral);
  /** Widget x of time @p t [s] on the time axis, and back (clamped to the drive); NaN without
   *  a profile. */
  double XAtTime(double t);
  double TimeAtX(double x);
  /** The GNSS outage spans drawn at the last paint (widget coordinates; tests). */
  QVector<QRectF> OutageRects() const { return outage_rects_; }

protected:
  void paintEvent(QPaintEvent *e) override;
  /** A drag across the time axis adds a GNSS outage over the dragged span (one undo step). */
  void mousePressEvent(QMouseEvent *e) override;
  void mouseMoveEvent(QMouseEvent *e) override;
  void mouseReleaseEvent(QMouseEvent *e) override;

private:
  void Recompute();
  SceneDocument *doc_;
  PathSamples prof_;
  QString msg_;
  QTimer timer_;
  QVector<QRectF> outage_rects_;
  bool dragging_ = false;
  int drag_x0_ = 0, drag_x1_ = 0;
};

} // namespace studio

#endif
