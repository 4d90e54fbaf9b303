/*
 * navstudio: a small chart of the horizontal position error against time (QPainter): run 0 of
 * the last result, the RMS over the Monte Carlo runs, and the GNSS outages shaded.
 */
#ifndef NAVSTUDIO_ERROR_CHART_H
#define NAVSTUDIO_ERROR_CHART_H

#include <QWidget>

#include <memory>

#include "sim_worker.h"

namespace studio {

class ErrorChart : public QWidget {
  Q_OBJECT
public:
  explicit ErrorChart(QWidget *parent = nullptr);
  void SetResult(std::shared_ptr<const SimResult> r);
  QSize sizeHint() const override { return QSize(400, 160); }

protected:
  void paintEvent(QPaintEvent *e) override;

private:
  std::shared_ptr<const SimResult> result_;
};

} // namespace studio

#endif
