#include "error_chart.h"

#include <QLabel>
#include <QPixmap>
#include <QResizeEvent>
#include <QScrollBar>

#include <algorithm>
#include <string>
#include <vector>

#include "navview/nav_view_chart.h"

namespace studio {

ErrorChart::ErrorChart(QWidget *parent) : QScrollArea(parent) {
  setObjectName("errorChart");
  setMinimumHeight(120);
  setWidgetResizable(false);
  setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  label_ = new QLabel;
  label_->setObjectName("errorChartPicture");
  label_->setAlignment(Qt::AlignCenter);
  label_->setText(tr("Errors against time: run a simulation (F5)"));
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
  if (!NavRenderErrorChartRgb(*nav_, o, &rgb, &err)) {
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
}

} // namespace studio
