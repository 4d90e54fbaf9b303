/*
 * navstudio: the main window. Panels on the left, the map and 3D views on the right, results
 * (verdicts, statistics, error chart, issues) below, a status bar with progress. Simulations run
 * on SimWorker threads; the live preview re-simulates one run (debounced) after every edit of a
 * scene of at most 10 min at 100 Hz and reports the edit-to-picture latency.
 */
#ifndef NAVSTUDIO_MAIN_WINDOW_H
#define NAVSTUDIO_MAIN_WINDOW_H

#include <QMainWindow>
#include <QMessageBox>
#include <QTimer>

#include <functional>
#include <memory>
#include <vector>

#include "error_chart.h"
#include "panels.h"
#include "profile_chart.h"
#include "path_view.h"
#include "playback.h"
#include "sim_worker.h"
#include "studio_scene.h"
#include "tradeoff_run.h"

class QAction;
class QLabel;
class QListWidget;
class QMenu;
class QProgressBar;
class QTextBrowser;

namespace studio {

/** Live preview simplifications (MainWindow::StartPreview). */
constexpr int kPreviewCovDecimation = 10;
constexpr double kPreviewOutputHz = 10.0;
/** The preview's output rate is lowered (10, 5, 4, 2, 1 Hz) until the drive has at most this
 *  many output epochs: about 2 per 3 m of drawn estimate at 13 m/s over 10 min. */
constexpr double kPreviewMaxEpochs = 2500.0;
/** Live preview runs for scenes of at most this many IMU steps (10 min at 100 Hz). */
constexpr double kPreviewMaxImuSteps = 600.0 * 100.0;
constexpr double kPreviewImuHz = 20.0;
/** The preview's IMU rate when kPreviewImuHz does not fit the scene. */
constexpr double kPreviewImuHzFallback = 50.0;
/** A running live preview that has done less than this fraction is dropped for a newer edit. */
constexpr double kPreviewPreemptFraction = 0.5;
/** During a live drag the path waits at most this long for its preview to be drawn with it. */
constexpr int kLiveRenderDelayMs = 100;
/** The lighter scene the live preview simulates (a copy of @p scene). */
std::unique_ptr<nav_scene> PreviewScene(const nav_scene &scene);

class MainWindow : public QMainWindow {
  Q_OBJECT
public:
  /** Asks the user a question (replaceable by tests); returns the button chosen. */
  using AskFn = std::function<QMessageBox::StandardButton(const QString &title, const QString &text,
                                                          QMessageBox::StandardButtons buttons)>;
  explicit MainWindow(QWidget *parent = nullptr);
  ~MainWindow() override;

  /** Open a scene file (asks to save changes first); false with a message box on errors. */
  bool OpenFile(const QString &path);
  /** Start a new drive (asks to save changes first). */
  bool NewDrive();
  bool Save();
  /** File > Import track...: replace the trajectory by a GPX/KML track or a motion definition
   *  (one undo step). false with the diagnostics (FILE:LINE:COL: error: ...) in a message box and
   *  in @p errors. */
  bool ImportTrack(const QString &path, QStringList *errors = nullptr);
  bool SaveAs(const QString &path);
  /** Size of the 3D and map pictures the report embeds (as File > Export picture writes them). */
  static constexpr int kReportPictureWidth = 1280;
  static constexpr int kReportPictureHeight = 720;
  /** File > Export report: one self-contained HTML file (report_export.h) with the last full
   *  run's verdicts and statistics, the 3D view and the map as single pictures (no forms) and
   *  the error chart. */
  bool ExportReport(const QString &path, QString *error);
  /** Draw the error band of @p r about its estimate in both views (3 sigma or 3 RMS). */
  void SetEnvelopes(const SimResult &r, bool preview);
  /** Simulation > Speed against error...: navsim tradeoff of the saved scene into @p out_dir
   *  (@p runs 0: navsim's default); its dialog opens when it ends. false with @p error when the
   *  scene is unsaved or modified (navsim reads the file) or a tradeoff is running. */
  bool StartTradeoff(const QString &out_dir, int runs, QString *error);
  TradeoffRun *Tradeoff() { return &tradeoff_; }
  /** What File > Export movie writes. */
  struct MovieRequest {
    double duration_s = 10.0;
    int width_px = 1920, height_px = 1080;
    double fps = 30.0;
    bool follow = true;        /**< the follow camera (at the playback bar's distance) */
  };
  /** File > Export movie: the shown result's playback (the 3D view's scene, libnavview) as H.264
   *  MP4 or VP9 WebM (by the file's ending) with a progress dialog whose Cancel stops it and
   *  leaves no file. false with @p error (also "cancelled"). */
  bool ExportMovie(const QString &path, const MovieRequest &req, QString *error);
  /** File > Export picture: one view without the forms, at @p width x @p height (up to
   *  3840x2160), with its legend: @p view "3d" (the 3D view's scene at the playback time, framed
   *  as navview frames it, or from the follow camera when it is on) or "map" (libnavview's geodetic map of the result). */
  bool ExportPicture(const QString &path, const QString &view, int width, int height, QString *error);
  PlaybackBar *Playback() { return playback_; }
  /** The results shown are out of date (the scene was edited after the run). */
  bool ResultsStale() const { return results_stale_; }
  /** Start the Monte Carlo run of the scene. false when the scene has issues. */
  bool Run();
  void Cancel();

  /** Write the autosave copy now (when modified). */
  void Autosave();
  /** The autosave file of the current document. */
  QString AutosavePath() const;
  /** Offer to recover an autosave of the current document; true when recovered. */
  bool CheckRecovery();

  void SetAsk(AskFn fn) { ask_ = std::move(fn); }
  void SetLivePreview(bool on);
  /** How long a live edit's frame may wait for its preview (default kLiveRenderDelayMs; tests). */
  void SetLiveFrameHoldMs(int ms) { frame_hold_ms_ = ms; }
  SceneDocument *Doc() { return &doc_; }
  PathView *MapView() { return map_; }
  /** The map's tile layer (View > Map tiles...): checked (an unusable source is refused with the
   *  reason in @p error and nothing changes), remembered in QSettings (map/tiles,
   *  map/tilesAttribution), used by the map view and the exported map picture. Empty: none. */
  bool SetMapTiles(const QString &source, const QString &attribution, QString *error);
  QString MapTiles() const { return map_tiles_; }
  /** View > Map tiles...: the dialog (source, attribution). */
  void EditMapTiles();
  PathView *View3D() { return view3d_; }
  ProfileChart *Profile() { return profile_; }
  ScenePanels *Panels() { return panels_; }
  SimWorker *Worker() { return &worker_; }
  SimWorker *PreviewWorker() { return &preview_; }
  std::shared_ptr<const SimResult> LastResult() const { return last_result_; }
  std::shared_ptr<const SimResult> LastPreview() const { return last_preview_; }
  /** Edit-to-picture latencies of the live previews so far [ms]: from the edit (the scene's
   *  change) to the last swap, among the visible views, of a frame that shows the preview's
   *  estimate. */
  const std::vector<double> &PreviewLatenciesMs() const { return latencies_ms_; }
  /** The window as it is on screen, views included (QWidget::grab() leaves the views' native
   *  windows out): screenshots, the report. */
  QImage Screenshot();
  QString ResultsText() const;
  /** The status bar's preview read-out (latency, or why there is no preview). */
  QString PreviewStatusText() const;
  /** Shrinks the window to the available area of its screen (the default size, 1500 x 950, is
   *  larger than a 1280 x 1024 screen) and centres it; used when navstudio is opened by a user. */
  void FitToScreen();
  QStringList RecentFiles() const;
  /** Where the save and export dialogs open: the scene's folder, else the user's documents
   *  folder (else home), never the working directory the program was started in. */
  QString DialogDir() const;
  /** Where File > Open starts: the scene's folder, else the shipped scenes. */
  QString OpenDialogDir() const;
  /** @p name in DialogDir(). */
  QString DialogPath(const QString &name) const;

signals:
  /** A Monte Carlo result or a preview has been drawn. */
  void ResultShown(bool preview);

protected:
  void closeEvent(QCloseEvent *e) override;
  /** Holds the window's repaints (QEvent::UpdateRequest) while a live edit waits for its preview. */
  bool event(QEvent *e) override;

private:
  QString map_tiles_, map_tiles_attribution_;
  void BuildUi();
  void BuildActions();
  bool MaybeSave();
  void UpdateTitle();
  void OnSceneChanged();
  void StartPreview();
  void OnFinished(std::shared_ptr<const SimResult> r);
  void OnPreviewFinished(std::shared_ptr<const SimResult> r);
  void ShowIssues();
  /** The Results tab before the first result: how to draw or edit this kind of trajectory. */
  void ShowResultsHint();
  void AddRecent(const QString &path);
  void RebuildRecentMenu();
  void RemoveAutosave();
  bool SceneSmallForPreview() const;
  void UpdateLiveRenderDelay();
  /** The views' picture of the pending preview reached the screen: record its latency. */
  void OnPictureShown();
  /** View @p bit (1: map, 2: 3D) swapped a frame: the pending picture is shown once all have. */
  void OnViewFrame(unsigned bit);
  /** During a live edit the window's widgets (panels, table, profile chart) are repainted with
   *  the preview, when the views show the path and its estimate (at most kLiveRenderDelayMs
   *  after the edit), not before them. */
  void HoldFrames();
  void ReleaseFrames();

  SceneDocument doc_;
  Catalogs catalogs_;
  SimWorker worker_;
  SimWorker preview_;
  ScenePanels *panels_ = nullptr;
  PathView *map_ = nullptr;
  PathView *view3d_ = nullptr;
  ErrorChart *chart_ = nullptr;
  ProfileChart *profile_ = nullptr;
  QTextBrowser *results_ = nullptr;
  QListWidget *issues_ = nullptr;
  QTabWidget *bottom_tabs_ = nullptr;
  QProgressBar *progress_ = nullptr;
  QLabel *status_ = nullptr;
  QLabel *latency_label_ = nullptr;
  TradeoffRun tradeoff_;
  QAction *run_act_ = nullptr, *cancel_act_ = nullptr, *preview_act_ = nullptr;
  QMenu *recent_menu_ = nullptr;
  QTimer preview_timer_;
  QTimer autosave_timer_;
  int autosaved_index_ = -1;
  qint64 preview_started_ns_ = 0;
  // The preview whose picture is drawn but not yet on screen (each view swaps its own frame).
  struct PendingPicture {
    qint64 change_ns = 0, started_ns = 0, arrived_ns = 0, drawn_ns = 0;
    double sim_ms = 0.0, final_err_m = 0.0;
    long long samples = 0;
    unsigned views_owing = 0; // bit 0: the map, bit 1: the 3D view, until each swaps its frame
  };
  PendingPicture pending_picture_;
  bool hold_frames_ = false, held_update_ = false;
  int frame_hold_ms_ = kLiveRenderDelayMs;
  QTimer frame_hold_timer_;
  QTimer latency_label_timer_; // the latency read-out waits for a pause (no extra frame per edit)
  QString latency_text_;
  AskFn ask_;
  std::shared_ptr<const SimResult> last_result_, last_preview_;
  int hint_type_ = -1; /**< trajectory type the Results hint was written for */
  std::vector<double> latencies_ms_;
  PlaybackBar *playback_ = nullptr;
  bool results_stale_ = false;
  QString results_html_; /**< the Results tab of the last complete run (greyed when stale) */
  QTimer scene_preview_timer_; /**< before any run the 3D scene shows the settled preview */
  /** Show @p r (Monte Carlo result or preview) in the 3D view's scene. */
  void ShowScene(const std::shared_ptr<const SimResult> &r);
  void MarkResultsStale(bool stale);
  void ClearResults();
};

} // namespace studio

#endif
