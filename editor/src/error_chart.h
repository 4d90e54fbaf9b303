/*
 * navstudio: the Errors tab. It shows the chart set of `navsim render --view errors`, drawn by
 * libnavview's chart code (NavRenderErrorChartRgb; one chart path for navsim, navview and
 * navstudio): horizontal, vertical and velocity error, roll/pitch/yaw, the Monte Carlo k-RMS
 * bands, the filter's sigma, the requirement limits, the GNSS outages shaded, each legend right of
 * its plot. The picture is drawn at the tab's width and at least kMinChartHeightPx high (a
 * scroll bar when the tab is lower), again after a resize. Hovering a plot shows a read-out: a
 * vertical line at the cursor's time through every panel, markers on the hovered panel's curves
 * and a label with the time and the values there ("t = 123.4 s · horizontal 2.31 m · RMS of 20
 * runs 1.90 m · filter 1σ 1.20 m").
 */
#ifndef NAVSTUDIO_ERROR_CHART_H
#define NAVSTUDIO_ERROR_CHART_H

#include <QImage>
#include <QScrollArea>
#include <QTimer>

#include <memory>

#include "navview/nav_view_chart.h"
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
  /** Where the shown picture's panels are (empty before a picture). */
  const NavErrorChartLayout &Layout() const { return layout_; }
  /** The hover read-out shown ("" when the cursor is off the plots). */
  QString ReadoutText() const { return readout_; }
  /** The read-out for the picture's pixel @p p (x from the left, y from the top; the picture
   *  label's coordinates): "" off the plots. Sets the hover state when @p show. */
  QString ReadoutAt(QPoint p, bool show = false);
  /** The widget showing the picture (hover it for the read-out). */
  QLabel *PictureLabel() const { return label_; }

signals:
  void ReadoutChanged(const QString &text);

protected:
  void resizeEvent(QResizeEvent *e) override;
  void showEvent(QShowEvent *e) override;
  bool eventFilter(QObject *o, QEvent *e) override;

private:
  friend class ChartHoverOverlay;
  void Draw();
  void ClearHover();
  std::shared_ptr<const SimResult> result_;
  std::shared_ptr<const NavResult> nav_;
  QLabel *label_ = nullptr;
  QImage picture_;
  NavErrorChartLayout layout_;
  QString message_;
  // Hover: the panel under the cursor (-1: none), the cursor's x, and the read-out.
  int hover_panel_ = -1;
  int hover_x_ = 0;
  size_t hover_epoch_ = 0;
  QString readout_;
  QWidget *overlay_ = nullptr;
  bool due_ = false;
  QTimer redraw_;
};

} // namespace studio

#endif
