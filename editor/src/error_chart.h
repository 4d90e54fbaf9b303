/*
 * navstudio: the Errors tab. It shows the chart set of `navsim render --view errors`, drawn by
 * libnavview's chart code (NavRenderErrorChartRgb; one chart path for navsim, navview and
 * navstudio): horizontal, vertical and velocity error, roll/pitch/yaw, the Monte Carlo k-RMS
 * bands, the filter's sigma, the requirement limits, the GNSS outages shaded, each legend right of
 * its plot. The picture is drawn at the tab's width and at least kMinChartHeightPx high (a
 * scroll bar when the tab is lower), again after a resize.
 */
#ifndef NAVSTUDIO_ERROR_CHART_H
#define NAVSTUDIO_ERROR_CHART_H

#include <QImage>
#include <QScrollArea>
#include <QTimer>

#include <memory>

#include "sim_worker.h"

class QLabel;
struct NavResult;

namespace studio {

/** The chart is drawn at least this high (four panels) [px]. */
constexpr int kMinChartHeightPx = 560;

class ErrorChart : public QScrollArea {
  Q_OBJECT
public:
  explicit ErrorChart(QWidget *parent = nullptr);
  /** Show the errors of @p r (with @p result, the same run as libnavview's result); nullptr
   *  clears. The picture is drawn when the tab is next shown. */
  void SetResult(std::shared_ptr<const SimResult> r, std::shared_ptr<const NavResult> result);
  QSize sizeHint() const override { return QSize(400, 160); }
  /** The picture shown (drawn first when due; tests, the report). */
  QImage Picture();
  /** Why there is no picture ("" when there is one). */
  QString Message() const { return message_; }

protected:
  void resizeEvent(QResizeEvent *e) override;
  void showEvent(QShowEvent *e) override;

private:
  void Draw();
  std::shared_ptr<const SimResult> result_;
  std::shared_ptr<const NavResult> nav_;
  QLabel *label_ = nullptr;
  QImage picture_;
  QString message_;
  bool due_ = false;
  QTimer redraw_;
};

} // namespace studio

#endif
