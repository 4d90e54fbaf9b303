/*
 * navstudio: playback of a result in the 3D view. The 3D scene itself (paths, attitude triads,
 * vehicle, outages, error tube and ellipsoids, legend) is libnavview's NavSceneView, the same
 * code navview and `navsim render` draw with; this file turns a SimResult into libnavview's
 * NavResult and holds the playback controls (time slider, play/pause, speed, step, follow
 * camera and its distance, attitude-error exaggeration).
 */
#ifndef NAVSTUDIO_PLAYBACK_H
#define NAVSTUDIO_PLAYBACK_H

#include <QTimer>
#include <QWidget>

#include <memory>

#include "navview/nav_view_model.h"
#include "navview/nav_view_result.h"
#include "sim_worker.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QSlider;
class QSpinBox;
class QToolButton;

namespace studio {

class PathView;

/** libnavview's view of @p r (run 0's reference, estimate and errors with attitude, the Monte
 *  Carlo envelope, the scene's GNSS outages); positions in the scene's local NED, geodetic
 *  positions through the scene's frame. GNSS fixes are not recorded by navstudio (none drawn). */
std::shared_ptr<NavResult> ToNavResult(const SimResult &r, const nav_scene &scene);

/** The view options navstudio's 3D view uses for @p r (envelope source: Monte Carlo RMS for a
 *  Monte Carlo result, the filter's sigma for a preview when it has one). */
NavViewOptions StudioViewOptions(const SimResult &r);

/** Time slider, play/pause, speed, step, follow and exaggeration for the 3D view's scene. */
class PlaybackBar : public QWidget {
  Q_OBJECT
public:
  explicit PlaybackBar(PathView *view, QWidget *parent = nullptr);

  /** The scene was (re)built: range of the slider, controls enabled. */
  void SceneChanged();
  /** Playback time [s] (moves the vehicle, the triads at t, the read-out; renders). */
  void SetTime(double t_s);
  double Time() const { return t_s_; }
  void SetPlaying(bool on);
  bool Playing() const { return timer_.isActive(); }
  /** Playback speed: simulated seconds per second of wall time. */
  void SetSpeed(double x);
  double Speed() const;
  void Step(int direction);
  void SetFollow(bool on);
  bool Follow() const;
  void SetFollowDistance(double m);
  double FollowDistance() const;
  void SetExaggeration(double k);
  double Exaggeration() const;

  QSlider *Slider() { return slider_; }
  QToolButton *PlayButton() { return play_; }
  QCheckBox *FollowBox() { return follow_; }
  QDoubleSpinBox *ExaggerationBox() { return exag_; }
  QLabel *TimeLabel() { return time_label_; }

signals:
  /** The exaggeration changed: the owner rebuilds the scene with it. */
  void ExaggerationChanged(double k);

private:
  void Tick();
  void ShowTime();
  PathView *view_;
  QToolButton *play_ = nullptr, *back_ = nullptr, *fwd_ = nullptr;
  QSlider *slider_ = nullptr;
  QLabel *time_label_ = nullptr;
  QComboBox *speed_ = nullptr;
  QCheckBox *follow_ = nullptr;
  QSpinBox *distance_ = nullptr;
  QDoubleSpinBox *exag_ = nullptr;
  QTimer timer_;
  qint64 last_tick_ns_ = 0;
  double t_s_ = 0.0, t0_ = 0.0, t1_ = 0.0;
  bool updating_ = false;
};

} // namespace studio

#endif
