#include "main_window.h"

#include "report_export.h"
#include "track_import.h"

#include <QAction>
#include <QMessageBox>
#include <QDialog>
#include <QPushButton>
#include <QLineEdit>
#include <QHBoxLayout>
#include <QDialogButtonBox>
#include <QApplication>
#include <QCloseEvent>
#include <QCryptographicHash>
#include <QDir>
#include <QFile>
#include <QFileDialog>
#include <QFileInfo>
#include <QKeySequence>
#include <QLabel>
#include <QListWidget>
#include <QMenuBar>
#include <QProgressBar>
#include <QScreen>
#include <QSettings>
#include <QSplitter>
#include <QTabBar>
#include <QTemporaryDir>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTextBrowser>
#include <QToolBar>
#include <QUndoStack>
#include <QImage>
#include <QInputDialog>
#include <QPainter>
#include <QProgressDialog>
#include <QVBoxLayout>

#include "navview/nav_map_tiles.h"
#include "navview/nav_view_map.h"
#include "navview/nav_view_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace studio {

namespace {
QString AutosaveDir() {
  const QByteArray env = qgetenv("NAVSTUDIO_AUTOSAVE_DIR");
  if (!env.isEmpty()) return QString::fromLocal8Bit(env);
  return QStandardPaths::writableLocation(QStandardPaths::AppLocalDataLocation) + "/autosave";
}

QString Fmt(double v, int prec = 3) { return std::isfinite(v) ? QString::number(v, 'g', prec) : QStringLiteral("—"); }
} // namespace

MainWindow::MainWindow(QWidget *parent) : QMainWindow(parent) {
  setObjectName("navstudio");
  ask_ = [this](const QString &title, const QString &text, QMessageBox::StandardButtons buttons) {
    return QMessageBox::question(this, title, text, buttons);
  };
  // The live preview is started first after an edit (the worker thread then simulates while
  // this thread redraws the views and panels).
  connect(&doc_, &SceneDocument::Changed, this, [this] {
    if (preview_act_ && preview_act_->isChecked()) StartPreview();
    if (!doc_.IsLive()) ReleaseFrames();
  });
  BuildUi();
  BuildActions();
  connect(&doc_, &SceneDocument::Changed, this, &MainWindow::OnSceneChanged);
  connect(&doc_, &SceneDocument::FileStateChanged, this, &MainWindow::UpdateTitle);
  connect(&worker_, &SimWorker::Progress, this, [this](double f) {
    progress_->setValue(static_cast<int>(std::lround(1000.0 * f)));
  });
  connect(&worker_, &SimWorker::Finished, this, &MainWindow::OnFinished);
  connect(&preview_, &SimWorker::Finished, this, &MainWindow::OnPreviewFinished);
  preview_timer_.setSingleShot(true);
  // A burst of edits (a drag) does not pile up previews: while one runs, only the newest edit
  // waits (SimWorker queues one job); this timer only retries after a Monte Carlo run.
  preview_timer_.setInterval(30);
  connect(&preview_timer_, &QTimer::timeout, this, &MainWindow::StartPreview);
  frame_hold_timer_.setSingleShot(true);
  connect(&frame_hold_timer_, &QTimer::timeout, this, &MainWindow::ReleaseFrames);
  latency_label_timer_.setSingleShot(true);
  latency_label_timer_.setInterval(250);
  connect(&latency_label_timer_, &QTimer::timeout, this, [this] { latency_label_->setText(latency_text_); });
  bool ok = false;
  const int ms = qEnvironmentVariableIntValue("NAVSTUDIO_AUTOSAVE_MS", &ok);
  autosave_timer_.setInterval(ok && ms > 0 ? ms : 30000);
  connect(&autosave_timer_, &QTimer::timeout, this, &MainWindow::Autosave);
  autosave_timer_.start();
  RemoveStaleTempFiles(AutosaveDir()); // an autosave a killed navstudio did not finish
  UpdateTitle();
  ShowIssues();
  ShowResultsHint();
}

MainWindow::~MainWindow() {
  // Stop the workers before the views they report to go away.
  worker_.Cancel();
  preview_.Cancel();
  worker_.Join();
  preview_.Join();
}

void MainWindow::BuildUi() {
  resize(1500, 950);
  panels_ = new ScenePanels(&doc_, &catalogs_);
  // Every panel's tab stays in sight (no scroll arrows): the panels are at least as wide as
  // their tab bar.
  panels_->setUsesScrollButtons(false);
  panels_->setMinimumWidth(std::max(470, panels_->tabBar()->sizeHint().width() + 8));
  map_ = new PathView(&doc_, PathView::Mode::Map);
  view3d_ = new PathView(&doc_, PathView::Mode::ThreeD);
  auto *views = new QSplitter(Qt::Horizontal);
  views->addWidget(map_);
  {
    // The 3D view with its playback bar under it.
    auto *box = new QWidget;
    box->setObjectName("view3dBox");
    auto *vl = new QVBoxLayout(box);
    vl->setContentsMargins(0, 0, 0, 0);
    vl->setSpacing(0);
    vl->addWidget(view3d_, 1);
    playback_ = new PlaybackBar(view3d_);
    vl->addWidget(playback_);
    views->addWidget(box);
    connect(playback_, &PlaybackBar::ExaggerationChanged, this, [this](double) {
      const std::shared_ptr<const SimResult> r = last_result_ ? last_result_ : last_preview_;
      if (view3d_->Scene() && r) ShowScene(r);
    });
    scene_preview_timer_.setSingleShot(true);
    scene_preview_timer_.setInterval(400);
    connect(&scene_preview_timer_, &QTimer::timeout, this, [this] {
      if (!last_result_ && last_preview_ && !doc_.IsLive()) ShowScene(last_preview_);
    });
  }
  views->setSizes({560, 440});

  bottom_tabs_ = new QTabWidget;
  bottom_tabs_->setObjectName("bottomTabs");
  results_ = new QTextBrowser;
  results_->setObjectName("resultsText");
  chart_ = new ErrorChart;
  issues_ = new QListWidget;
  issues_->setObjectName("issuesList");
  bottom_tabs_->addTab(results_, tr("Results"));
  bottom_tabs_->addTab(chart_, tr("Errors"));
  bottom_tabs_->addTab(issues_, tr("Issues"));

  profile_ = new ProfileChart(&doc_);
  auto *right = new QSplitter(Qt::Vertical);
  right->addWidget(views);
  right->addWidget(profile_);
  right->addWidget(bottom_tabs_);
  right->setSizes({520, 150, 210});
  auto *main = new QSplitter(Qt::Horizontal);
  main->addWidget(panels_);
  main->addWidget(right);
  main->setSizes({480, 1020});
  setCentralWidget(main);

  status_ = new QLabel(tr("Ready"));
  status_->setObjectName("statusText");
  latency_label_ = new QLabel;
  latency_label_->setObjectName("latencyLabel");
  progress_ = new QProgressBar;
  progress_->setObjectName("progress");
  progress_->setRange(0, 1000);
  progress_->setMaximumWidth(220);
  progress_->setTextVisible(true);
  progress_->setFormat("%p%");
  progress_->setValue(0);
  statusBar()->addWidget(status_, 1);
  statusBar()->addPermanentWidget(latency_label_);
  statusBar()->addPermanentWidget(progress_);

  connect(map_, &PathView::CursorText, status_, &QLabel::setText);
  connect(view3d_, &PathView::CursorText, status_, &QLabel::setText);
  // Each view swaps its own frames (native windows): a preview's picture is on screen when
  // every visible view has swapped the frame with its estimate.
  connect(map_, &PathView::FrameSwapped, this, [this] { OnViewFrame(1u); });
  connect(view3d_, &PathView::FrameSwapped, this, [this] { OnViewFrame(2u); });
  // Selection in sync: views and the table.
  connect(map_, &PathView::SelectionChanged, this, [this](int i) {
    view3d_->SetSelectedWaypoint(i);
    panels_->SelectWaypoint(i);
  });
  connect(view3d_, &PathView::SelectionChanged, this, [this](int i) {
    map_->SetSelectedWaypoint(i);
    panels_->SelectWaypoint(i);
  });
  connect(panels_, &ScenePanels::WaypointSelected, this, [this](int i) {
    map_->SetSelectedWaypoint(i);
    view3d_->SetSelectedWaypoint(i);
  });
  connect(panels_, &ScenePanels::RunRequested, this, [this] { Run(); });
  connect(panels_, &ScenePanels::CancelRequested, this, &MainWindow::Cancel);
}

void MainWindow::BuildActions() {
  QMenu *file = menuBar()->addMenu(tr("&File"));
  QMenu *edit = menuBar()->addMenu(tr("&Edit"));
  QMenu *sim = menuBar()->addMenu(tr("&Simulation"));
  QMenu *view = menuBar()->addMenu(tr("&View"));
  QToolBar *tb = addToolBar(tr("Main"));
  tb->setObjectName("mainToolBar");
  tb->setToolButtonStyle(Qt::ToolButtonTextOnly);

  auto act = [this](const QString &text, const QString &name, const QKeySequence &key) {
    auto *a = new QAction(text, this);
    a->setObjectName(name);
    if (!key.isEmpty()) a->setShortcut(key);
    return a;
  };
  QAction *nw = act(tr("&New drive"), "actionNew", QKeySequence::New);
  QAction *open = act(tr("&Open..."), "actionOpen", QKeySequence::Open);
  QAction *save = act(tr("&Save"), "actionSave", QKeySequence::Save);
  QAction *saveas = act(tr("Save &as..."), "actionSaveAs", QKeySequence::SaveAs);
  QAction *import = act(tr("&Import track..."), "actionImportTrack", QKeySequence(tr("Ctrl+I")));
  connect(import, &QAction::triggered, this, [this] {
    const QString p = QFileDialog::getOpenFileName(this, tr("Import track"), DialogDir(),
                                                   tr("Tracks (*.gpx *.kml *.csv);;All files (*)"));
    if (!p.isEmpty()) ImportTrack(p);
  });
  QAction *shot = act(tr("Export &screenshot..."), "actionScreenshot", QKeySequence(tr("Ctrl+Shift+P")));
  QAction *report = act(tr("Export &report..."), "actionReport", QKeySequence(tr("Ctrl+Shift+R")));
  QAction *movie = act(tr("Export &movie..."), "actionMovie", QKeySequence(tr("Ctrl+Shift+M")));
  QAction *picture = act(tr("Export &picture..."), "actionPicture", QKeySequence(tr("Ctrl+Shift+I")));
  connect(movie, &QAction::triggered, this, [this] {
    const QString p =
        QFileDialog::getSaveFileName(this, tr("Export movie"), DialogPath("navstudio-playback.mp4"),
                                     tr("H.264 MP4 (*.mp4);;VP9 WebM (*.webm)"));
    if (p.isEmpty()) return;
    MovieRequest req;
    bool ok = false;
    req.duration_s = QInputDialog::getDouble(this, tr("Export movie"), tr("Length of the movie [s]:"), 10.0, 1.0, 600.0,
                                             0, &ok);
    if (!ok) return;
    const QString size = QInputDialog::getItem(this, tr("Export movie"), tr("Size:"),
                                               {"1920x1080", "1280x720", "3840x2160"}, 0, false, &ok);
    if (!ok) return;
    req.width_px = size.section('x', 0, 0).toInt();
    req.height_px = size.section('x', 1, 1).toInt();
    req.follow = playback_->Follow();
    QString err;
    if (ExportMovie(p, req, &err))
      statusBar()->showMessage(tr("Movie written to %1").arg(p), 8000);
    else if (!err.contains("cancelled"))
      QMessageBox::warning(this, tr("Export movie"), err);
  });
  connect(picture, &QAction::triggered, this, [this] {
    bool ok = false;
    const QString which = QInputDialog::getItem(this, tr("Export picture"), tr("View:"), {"3d", "map"}, 0, false, &ok);
    if (!ok) return;
    const QString size = QInputDialog::getItem(this, tr("Export picture"), tr("Size:"),
                                               {"1920x1080", "1280x720", "2560x1440", "3840x2160"}, 0, true, &ok);
    if (!ok) return;
    const QString p = QFileDialog::getSaveFileName(
        this, tr("Export picture"), DialogPath("navstudio-" + which + ".png"), tr("PNG (*.png)"));
    if (p.isEmpty()) return;
    QString err;
    if (ExportPicture(p, which, size.section('x', 0, 0).toInt(), size.section('x', 1, 1).toInt(), &err))
      statusBar()->showMessage(tr("Picture written to %1").arg(p), 8000);
    else
      QMessageBox::warning(this, tr("Export picture"), err);
  });
  QAction *quit = act(tr("&Quit"), "actionQuit", QKeySequence::Quit);
  connect(nw, &QAction::triggered, this, [this] { NewDrive(); });
  connect(open, &QAction::triggered, this, [this] {
    const QString p =
        QFileDialog::getOpenFileName(this, tr("Open scene"), OpenDialogDir(), tr("Scenes (*.yaml *.yml)"));
    if (!p.isEmpty()) OpenFile(p);
  });
  connect(save, &QAction::triggered, this, [this] { Save(); });
  connect(saveas, &QAction::triggered, this, [this] {
    const QString p = QFileDialog::getSaveFileName(
        this, tr("Save scene as"), doc_.FilePath().isEmpty() ? DialogPath("drive.yaml") : doc_.FilePath(),
        tr("Scenes (*.yaml)"));
    if (!p.isEmpty()) SaveAs(p);
  });
  connect(shot, &QAction::triggered, this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, tr("Export screenshot"), DialogPath("navstudio.png"),
                                                   tr("PNG (*.png)"));
    if (p.isEmpty()) return;
    if (Screenshot().save(p))
      statusBar()->showMessage(tr("Screenshot written to %1").arg(p), 8000);
    else
      QMessageBox::warning(this, tr("Export screenshot"), tr("%1: cannot write the picture").arg(p));
  });
  connect(report, &QAction::triggered, this, [this] {
    const QString p = QFileDialog::getSaveFileName(this, tr("Export report"),
                                                   DialogPath("navstudio-report.html"), tr("HTML (*.html)"));
    if (p.isEmpty()) return;
    QString err;
    if (ExportReport(p, &err))
      statusBar()->showMessage(tr("Report written to %1").arg(p), 5000);
    else
      QMessageBox::warning(this, tr("Export report"), err);
  });
  connect(quit, &QAction::triggered, this, &QWidget::close);
  file->addActions({nw, open});
  recent_menu_ = file->addMenu(tr("Open &recent"));
  file->addActions({save, saveas});
  file->addSeparator();
  file->addAction(import);
  file->addAction(shot);
  file->addAction(picture);
  file->addAction(movie);
  file->addAction(report);
  file->addSeparator();
  file->addAction(quit);
  RebuildRecentMenu();

  QAction *undo = doc_.UndoStack()->createUndoAction(this, tr("&Undo"));
  undo->setObjectName("actionUndo");
  undo->setShortcut(QKeySequence::Undo);
  undo->setIconText(tr("Undo")); // the menu says "Undo <edit>", the toolbar stays short
  QAction *redo = doc_.UndoStack()->createRedoAction(this, tr("&Redo"));
  redo->setObjectName("actionRedo");
  redo->setShortcut(QKeySequence::Redo);
  redo->setIconText(tr("Redo"));
  QAction *del = act(tr("&Delete waypoint"), "actionDeleteWaypoint", QKeySequence(Qt::CTRL | Qt::Key_Delete));
  connect(del, &QAction::triggered, this, [this] { DeleteWaypoint(&doc_, map_->SelectedWaypoint()); });
  edit->addActions({undo, redo, del});

  run_act_ = act(tr("&Run"), "actionRun", QKeySequence(Qt::Key_F5));
  cancel_act_ = act(tr("&Cancel"), "actionCancel", QKeySequence(Qt::Key_Escape));
  cancel_act_->setEnabled(false);
  preview_act_ = act(tr("&Live preview"), "actionLivePreview", QKeySequence(tr("Ctrl+L")));
  preview_act_->setCheckable(true);
  preview_act_->setChecked(true);
  connect(run_act_, &QAction::triggered, this, [this] { Run(); });
  connect(cancel_act_, &QAction::triggered, this, &MainWindow::Cancel);
  connect(preview_act_, &QAction::toggled, this, [this](bool on) {
    UpdateLiveRenderDelay();
    if (on) preview_timer_.start();
  });
  UpdateLiveRenderDelay();
  sim->addActions({run_act_, cancel_act_, preview_act_});
  QAction *trade = act(tr("Speed against &error..."), "actionTradeoff", QKeySequence());
  connect(trade, &QAction::triggered, this, [this] {
    const QString base =
        doc_.FilePath().isEmpty() ? DialogPath("tradeoff") : doc_.FilePath().section('.', 0, -2);
    const QString p = QFileDialog::getSaveFileName(this, tr("navsim tradeoff into the new directory"),
                                                   base + "-tradeoff");
    if (p.isEmpty()) return;
    QString err;
    if (!StartTradeoff(p, 0, &err)) QMessageBox::warning(this, tr("Speed against error"), err);
  });
  connect(&tradeoff_, &TradeoffRun::Finished, this, [this](bool ok, const QString &msg) {
    if (!ok) {
      statusBar()->showMessage(tr("navsim tradeoff failed"), 5000);
      QMessageBox::warning(this, tr("Speed against error"), msg);
      return;
    }
    statusBar()->showMessage(tr("navsim tradeoff written to %1").arg(tradeoff_.OutDir()), 5000);
    QDialog *d = MakeTradeoffDialog(this, tradeoff_.OutDir(), [this](const QString &scene) { OpenFile(scene); });
    d->setAttribute(Qt::WA_DeleteOnClose);
    d->show();
  });
  sim->addSeparator();
  sim->addAction(trade);

  QAction *reset = act(tr("&Fit views"), "actionFit", QKeySequence(tr("Ctrl+0")));
  connect(reset, &QAction::triggered, this, [this] {
    map_->ResetCamera();
    view3d_->ResetCamera();
  });
  view->addAction(reset);

  // The map's tile layer (streets at street scale): a source and its credit, kept in QSettings.
  QAction *tiles = act(tr("Map &tiles..."), "actionMapTiles", QKeySequence());
  connect(tiles, &QAction::triggered, this, [this] { EditMapTiles(); });
  view->addAction(tiles);
  {
    QSettings st;
    const QString src = st.value("map/tiles").toString(), attr = st.value("map/tilesAttribution").toString();
    QString err;
    if (!src.isEmpty() && !SetMapTiles(src, attr, &err)) statusBar()->showMessage(err, 10000);
  }

  tb->addActions({nw, open, save});
  tb->addSeparator();
  tb->addActions({undo, redo});
  tb->addSeparator();
  tb->addActions({run_act_, cancel_act_, preview_act_});
}

bool MainWindow::SetMapTiles(const QString &source, const QString &attribution, QString *error) {
  if (!source.isEmpty()) {
    std::shared_ptr<NavTileSource> src;
    std::string err;
    if (!NavTileSourceOpen(source.toStdString(), &src, &err)) {
      if (error) *error = QString::fromStdString(err);
      return false;
    }
  }
  map_tiles_ = source;
  map_tiles_attribution_ = source.isEmpty() ? QString() : attribution;
  QSettings st;
  st.setValue("map/tiles", map_tiles_);
  st.setValue("map/tilesAttribution", map_tiles_attribution_);
  map_->SetMapTiles(map_tiles_, map_tiles_attribution_);
  return true;
}

void MainWindow::EditMapTiles() {
  QDialog d(this);
  d.setObjectName("mapTilesDialog");
  d.setWindowTitle(tr("Map tiles"));
  auto *lay = new QVBoxLayout(&d);
  auto *help = new QLabel(tr("Streets at street scale from raster tiles in the Web-Mercator tiling: an MBTiles "
                             "file, a directory of {z}/{x}/{y}.png tiles (or a template DIR/{z}/{x}/{y}.png), or "
                             "a URL template https://HOST/{z}/{x}/{y}.png where you have a network and the "
                             "server's permission. Empty: no tiles."),
                          &d);
  help->setWordWrap(true);
  lay->addWidget(help);
  auto *row = new QHBoxLayout;
  auto *src = new QLineEdit(map_tiles_, &d);
  src->setObjectName("mapTilesSource");
  auto *browse = new QPushButton(tr("&File..."), &d);
  row->addWidget(src, 1);
  row->addWidget(browse);
  lay->addLayout(row);
  connect(browse, &QPushButton::clicked, &d, [&] {
    const QString f = QFileDialog::getOpenFileName(&d, tr("MBTiles file"), DialogPath("tiles"),
                                                   tr("MBTiles (*.mbtiles);;All files (*)"));
    if (!f.isEmpty()) src->setText(f);
  });
  lay->addWidget(new QLabel(tr("Attribution shown on the map (default: the MBTiles file's own):"), &d));
  auto *attr = new QLineEdit(map_tiles_attribution_, &d);
  attr->setObjectName("mapTilesAttribution");
  lay->addWidget(attr);
  auto *buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, &d);
  lay->addWidget(buttons);
  connect(buttons, &QDialogButtonBox::rejected, &d, &QDialog::reject);
  connect(buttons, &QDialogButtonBox::accepted, &d, [&] {
    QString err;
    if (SetMapTiles(src->text().trimmed(), attr->text().trimmed(), &err)) {
      d.accept();
      return;
    }
    QMessageBox::warning(&d, tr("Map tiles"), err); // the dialog stays open with what was typed
  });
  d.exec();
}

bool MainWindow::StartTradeoff(const QString &out_dir, int runs, QString *error) {
  if (doc_.FilePath().isEmpty() || doc_.IsModified()) {
    if (error) *error = tr("Save the scene first: navsim tradeoff reads the scene file.");
    return false;
  }
  if (!tradeoff_.Start(doc_.FilePath(), out_dir, runs, error)) return false;
  statusBar()->showMessage(tr("navsim tradeoff running (every modelling choice, Monte Carlo each)..."));
  return true;
}

/* ---------------------------------------------------------------- files */

void MainWindow::UpdateTitle() {
  const QString name = doc_.FilePath().isEmpty() ? tr("untitled") : QFileInfo(doc_.FilePath()).fileName();
  setWindowTitle(QStringLiteral("%1[*] — navstudio").arg(name));
  setWindowModified(doc_.IsModified());
}

bool MainWindow::MaybeSave() {
  if (!doc_.IsModified()) return true;
  const auto b = ask_(tr("Unsaved changes"), tr("The scene has unsaved changes. Save them?"),
                      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
  if (b == QMessageBox::Cancel) return false;
  if (b == QMessageBox::Save) return Save();
  RemoveAutosave();
  return true;
}

bool MainWindow::OpenFile(const QString &path) {
  if (!MaybeSave()) return false;
  QStringList errors;
  if (!doc_.Load(path, &errors)) {
    const QString text = errors.isEmpty() ? tr("%1: cannot read the scene").arg(path) : errors.join("\n");
    status_->setText(tr("Cannot open %1").arg(path));
    issues_->clear();
    issues_->addItems(errors);
    bottom_tabs_->setCurrentWidget(issues_);
    if (!qEnvironmentVariableIsSet("NAVSTUDIO_NO_DIALOGS"))
      QMessageBox::warning(this, tr("Cannot open scene"), text);
    else
      std::fprintf(stderr, "%s\n", text.toLocal8Bit().constData());
    return false;
  }
  AddRecent(doc_.FilePath());
  map_->ResetCamera();
  view3d_->ResetCamera();
  status_->setText(tr("Opened %1").arg(doc_.FilePath()));
  CheckRecovery();
  return true;
}

bool MainWindow::ImportTrack(const QString &path, QStringList *errors_out) {
  auto s = std::make_unique<nav_scene>(doc_.Scene());
  QStringList errors;
  QString summary;
  if (!ImportTrackInto(path, s.get(), &errors, &summary)) {
    status_->setText(tr("Cannot import %1").arg(path));
    issues_->clear();
    issues_->addItems(errors);
    bottom_tabs_->setCurrentWidget(issues_);
    if (!qEnvironmentVariableIsSet("NAVSTUDIO_NO_DIALOGS"))
      QMessageBox::warning(this, tr("Cannot import track"), errors.join("\n"));
    else
      std::fprintf(stderr, "%s\n", errors.join("\n").toLocal8Bit().constData());
    if (errors_out) *errors_out = errors;
    return false;
  }
  doc_.Edit(tr("Import track %1").arg(QFileInfo(path).fileName()), [&](nav_scene &x) { x = *s; });
  map_->ResetCamera();
  view3d_->ResetCamera();
  status_->setText(tr("Imported %1: %2").arg(QFileInfo(path).fileName(), summary));
  if (errors_out) errors_out->clear();
  return true;
}

bool MainWindow::NewDrive() {
  if (!MaybeSave()) return false;
  doc_.Reset(*NewDriveScene());
  ClearResults();
  map_->ResetCamera();
  view3d_->ResetCamera();
  status_->setText(tr("New drive: click on the map to add waypoints"));
  return true;
}

bool MainWindow::Save() {
  if (doc_.FilePath().isEmpty()) {
    const QString p =
        QFileDialog::getSaveFileName(this, tr("Save scene"), DialogPath("drive.yaml"), tr("Scenes (*.yaml)"));
    if (p.isEmpty()) return false;
    return SaveAs(p);
  }
  return SaveAs(doc_.FilePath());
}

bool MainWindow::SaveAs(const QString &path) {
  const QString old_autosave = AutosavePath();
  QString err;
  if (!doc_.Save(path, &err)) {
    status_->setText(err);
    if (!qEnvironmentVariableIsSet("NAVSTUDIO_NO_DIALOGS")) QMessageBox::warning(this, tr("Cannot save"), err);
    return false;
  }
  QFile::remove(old_autosave);
  RemoveAutosave();
  AddRecent(doc_.FilePath());
  status_->setText(tr("Saved %1 (%2)").arg(doc_.FilePath(), doc_.SaveNote()));
  return true;
}

void MainWindow::closeEvent(QCloseEvent *e) {
  if (MaybeSave()) {
    worker_.Cancel();
    preview_.Cancel();
    e->accept();
  } else {
    e->ignore();
  }
}

QString MainWindow::AutosavePath() const {
  const QString key = doc_.FilePath().isEmpty() ? QStringLiteral("untitled") : doc_.FilePath();
  const QByteArray h = QCryptographicHash::hash(key.toUtf8(), QCryptographicHash::Sha1).toHex().left(16);
  return AutosaveDir() + "/autosave-" + QString::fromLatin1(h) + ".yaml";
}

void MainWindow::Autosave() {
  if (!doc_.IsModified() || doc_.UndoStack()->index() == autosaved_index_) return;
  QDir().mkpath(AutosaveDir());
  QString err;
  if (doc_.WriteCopy(AutosavePath(), &err)) {
    autosaved_index_ = doc_.UndoStack()->index();
    status_->setText(tr("Autosaved"));
  }
}

void MainWindow::RemoveAutosave() {
  QFile::remove(AutosavePath());
  autosaved_index_ = -1;
}

bool MainWindow::CheckRecovery() {
  const QString p = AutosavePath();
  QFile f(p);
  if (!f.exists() || !f.open(QIODevice::ReadOnly)) return false;
  const QByteArray text = f.readAll();
  f.close();
  const auto b = ask_(tr("Recover autosave"),
                      tr("navstudio found an autosaved version of this scene that was not saved (the program "
                         "ended without saving). Recover it?"),
                      QMessageBox::Yes | QMessageBox::No);
  if (b != QMessageBox::Yes) {
    QFile::remove(p);
    return false;
  }
  QStringList errors;
  if (!doc_.LoadText(text, p, doc_.FilePath(), &errors)) {
    status_->setText(tr("The autosave cannot be read: %1").arg(errors.join("; ")));
    return false;
  }
  map_->ResetCamera();
  view3d_->ResetCamera();
  status_->setText(tr("Recovered the autosave"));
  return true;
}

QString MainWindow::DialogDir() const {
  if (!doc_.FilePath().isEmpty()) return QFileInfo(doc_.FilePath()).absolutePath();
  const QString docs = QStandardPaths::writableLocation(QStandardPaths::DocumentsLocation);
  if (!docs.isEmpty() && QFileInfo(docs).isDir()) return docs;
  return QDir::homePath();
}

QString MainWindow::OpenDialogDir() const {
  if (!doc_.FilePath().isEmpty()) return DialogDir();
  const QString scenes = ScenesDir();
  return scenes.isEmpty() ? DialogDir() : scenes;
}

QString MainWindow::DialogPath(const QString &name) const {
  return QDir(DialogDir()).filePath(name);
}

QStringList MainWindow::RecentFiles() const { return QSettings().value("recentFiles").toStringList(); }

void MainWindow::AddRecent(const QString &path) {
  QStringList l = RecentFiles();
  l.removeAll(path);
  l.prepend(path);
  while (l.size() > 10) l.removeLast();
  QSettings().setValue("recentFiles", l);
  RebuildRecentMenu();
}

void MainWindow::RebuildRecentMenu() {
  recent_menu_->clear();
  const QStringList l = RecentFiles();
  for (int i = 0; i < l.size(); ++i) {
    QAction *a = recent_menu_->addAction(QStringLiteral("&%1 %2").arg(i + 1).arg(l[i]));
    const QString p = l[i];
    connect(a, &QAction::triggered, this, [this, p] { OpenFile(p); });
  }
  recent_menu_->setEnabled(!l.isEmpty());
}

/* ---------------------------------------------------------------- simulation */

void MainWindow::ShowIssues() {
  const QVector<Issue> issues = Validate(doc_.Scene());
  issues_->clear();
  for (const Issue &i : issues) issues_->addItem(i.Text());
  bottom_tabs_->setTabText(bottom_tabs_->indexOf(issues_),
                           issues.isEmpty() ? tr("Issues") : tr("Issues (%1)").arg(issues.size()));
}

void MainWindow::OnSceneChanged() {
  setWindowModified(doc_.IsModified());
  // A result of another scene than the one edited is out of date until the next run.
  if (last_result_ && !results_stale_ && last_result_->scene_change_ns != doc_.LastChangeNs()) MarkResultsStale(true);
  ShowIssues();
  ShowResultsHint();
}

bool MainWindow::SceneSmallForPreview() const {
  const nav_scene &s = doc_.Scene();
  // At most the IMU steps of 10 min at 100 Hz (a 20 s scene at 200 Hz is previewed too).
  return s.trajectory.duration_s * s.imu.rate_hz <= kPreviewMaxImuSteps + 0.5;
}

void MainWindow::SetLivePreview(bool on) { preview_act_->setChecked(on); }

void MainWindow::UpdateLiveRenderDelay() {
  const int ms = preview_act_ && preview_act_->isChecked() ? kLiveRenderDelayMs : 0;
  map_->SetLiveRenderDelay(ms);
  view3d_->SetLiveRenderDelay(ms);
}

namespace {
// The highest of the scene's output rate (at most kPreviewOutputHz) and 5, 4, 2, 1 Hz that
// divides the IMU rate and gives at most kPreviewMaxEpochs epochs (else the lowest that divides).
double PreviewOutputHz(const nav_scene &s) {
  const double own = std::min(s.output.rate_hz, kPreviewOutputHz);
  double best = s.output.rate_hz;
  for (const double hz : {own, 10.0, 5.0, 4.0, 2.0, 1.0}) {
    if (hz > own || std::fmod(s.imu.rate_hz, hz) != 0.0) continue;
    best = hz;
    if (hz * s.trajectory.duration_s <= kPreviewMaxEpochs) break;
  }
  return best;
}
} // namespace

std::unique_ptr<nav_scene> PreviewScene(const nav_scene &scene) {
  // The preview is one run of a lighter scene: the filter covariance propagated every 10th IMU
  // step, the IMU at 20 Hz (else 50 Hz) instead of 100 Hz, output at 10 Hz at most and at most
  // kPreviewMaxEpochs epochs (urban-drive's 513 s: 4 Hz; its estimate is still drawn with a
  // point every 3 m). The error statistics are taken at the output epochs only (SimWorker). The sensor
  // noise densities are per root hertz and the increments are exact integrals of the reference
  // motion, so the error growth stays alike (over 24 seeds of urban-drive: horizontal RMS 7.97 m
  // at 20 Hz, 7.78 m at 50 Hz, 7.22 m for the full 100 Hz run; final error 2.18 / 2.20 / 2.17 m).
  // A lighter scene that navcore rejects (rates that no longer divide, a GNSS latency that is
  // not a whole number of IMU steps) falls back to the next rate, then to the scene itself.
  for (const double imu_hz : {kPreviewImuHz, kPreviewImuHzFallback}) {
    auto s = std::make_unique<nav_scene>(scene);
    if (s->navigation.cov_decimation < kPreviewCovDecimation) s->navigation.cov_decimation = kPreviewCovDecimation;
    if (s->imu.rate_hz > imu_hz && std::fmod(s->imu.rate_hz, imu_hz) == 0.0) s->imu.rate_hz = imu_hz;
    s->output.rate_hz = PreviewOutputHz(*s);
    if (nav_scene_validate(s.get(), nullptr, nullptr) == NAV_OK) return s;
  }
  return std::make_unique<nav_scene>(scene);
}

void MainWindow::StartPreview() {
  if (!preview_act_->isChecked() || worker_.IsBusy()) return;
  if (!SceneSmallForPreview()) {
    const nav_scene &s = doc_.Scene();
    latency_label_->setText(tr("preview off: %1 s at %2 Hz, more than 10 min at 100 Hz (Run simulates it)")
                                .arg(s.trajectory.duration_s, 0, 'f', 0)
                                .arg(s.imu.rate_hz, 0, 'g', 6));
    return;
  }
  if (!Validate(doc_.Scene()).isEmpty()) return;
  preview_started_ns_ = SceneDocument::NowNs();
  // During a drag a preview that has done less than half of its run is dropped for the newer
  // edit (its estimate would be out of date when drawn); one further along is finished and
  // drawn first, so that the estimate keeps following a continuous drag.
  const bool preempt = doc_.IsLive() && preview_.IsBusy() && preview_.Fraction() < kPreviewPreemptFraction;
  preview_.Start(*PreviewScene(doc_.Scene()), 1, true, doc_.LastChangeNs(), preempt);
  if (doc_.IsLive()) HoldFrames();
}

void MainWindow::HoldFrames() {
  hold_frames_ = true;
  if (!frame_hold_timer_.isActive()) frame_hold_timer_.start(frame_hold_ms_);
}

void MainWindow::ReleaseFrames() {
  frame_hold_timer_.stop();
  hold_frames_ = false;
  if (held_update_) {
    held_update_ = false;
    QCoreApplication::postEvent(this, new QEvent(QEvent::UpdateRequest), Qt::LowEventPriority);
  }
}

bool MainWindow::event(QEvent *e) {
  if (e->type() == QEvent::UpdateRequest && hold_frames_) {
    held_update_ = true; // the dirty regions stay marked; ReleaseFrames() asks for the frame
    return true;
  }
  return QMainWindow::event(e);
}

void MainWindow::OnPreviewFinished(std::shared_ptr<const SimResult> r) {
  if (r->status == kStatusCrashed) {
    // The preview's process crashed: the window stays, the last preview stays drawn.
    status_->setText(tr("Live preview: %1").arg(r->message));
    return;
  }
  if (r->status != NAV_OK) return; // cancelled by a newer edit, or failed (the issues list says why)
  const qint64 arrived_ns = SceneDocument::NowNs();
  last_preview_ = r;
  SetEnvelopes(*r, true);
  map_->SetEstimate(r->nav_ned, true);
  view3d_->SetEstimate(r->nav_ned, true);
  // Before any Monte Carlo run the 3D scene shows the preview once the edits settle (rebuilding
  // it for every preview of a drag would cost the live preview its frame time).
  if (!last_result_) {
    // The scene shows an older preview meanwhile: greyed, the new estimate drawn over it.
    if (view3d_->Scene() && !view3d_->SceneStale()) view3d_->SetSceneStale(true);
    scene_preview_timer_.start();
  }
  if (r->scene_change_ns == doc_.LastChangeNs()) {
    // The views have drawn the current scene's estimate; the latency ends when every visible
    // view has swapped the frame that shows it (OnViewFrame), or now for a hidden window.
    pending_picture_.change_ns = r->scene_change_ns;
    pending_picture_.started_ns = preview_started_ns_;
    pending_picture_.arrived_ns = arrived_ns;
    pending_picture_.drawn_ns = SceneDocument::NowNs();
    pending_picture_.sim_ms = r->wall_s * 1e3;
    pending_picture_.samples = static_cast<long long>(r->summary.imu_samples);
    pending_picture_.final_err_m = r->summary.final.pos_err_h_m;
    pending_picture_.views_owing = (map_->isVisible() ? 1u : 0u) | (view3d_->isVisible() ? 2u : 0u);
    ReleaseFrames();
    if (!isVisible() || isMinimized() || pending_picture_.views_owing == 0) OnPictureShown();
  }
  emit ResultShown(true);
}

void MainWindow::OnViewFrame(unsigned bit) {
  if (pending_picture_.change_ns == 0 || !(pending_picture_.views_owing & bit)) return;
  pending_picture_.views_owing &= ~bit;
  if (pending_picture_.views_owing == 0) OnPictureShown();
}

QImage MainWindow::Screenshot() {
  QImage img = grab().toImage();
  QPainter p(&img);
  for (PathView *v : {map_, view3d_})
    if (v->isVisible() && v->width() > 0 && v->height() > 0)
      p.drawImage(QRect(v->mapTo(this, QPoint(0, 0)), v->size()), v->Grab());
  return img;
}

void MainWindow::OnPictureShown() {
  const PendingPicture p = pending_picture_;
  if (p.change_ns == 0) return;
  pending_picture_ = PendingPicture();
  const qint64 now = SceneDocument::NowNs();
  const double ms = (now - p.change_ns) * 1e-6;
  latencies_ms_.push_back(ms);
  latency_text_ = tr("preview %1 ms (final error %2 m)").arg(ms, 0, 'f', 0).arg(Fmt(p.final_err_m));
  if (doc_.IsLive())
    latency_label_timer_.start(); // shown when the drag pauses, not as an extra frame per edit
  else
    latency_label_->setText(latency_text_);
  std::fprintf(stderr,
               "navstudio: preview latency %.1f ms (edit to picture: %.1f ms to the start of the preview, simulation "
               "%.1f ms for %lld samples, %.1f ms to draw, %.1f ms to the views' swaps)\n",
               ms, (p.started_ns - p.change_ns) * 1e-6, p.sim_ms, p.samples, (p.drawn_ns - p.arrived_ns) * 1e-6,
               (now - p.drawn_ns) * 1e-6);
}

void MainWindow::FitToScreen() {
  QScreen *sc = screen();
  if (!sc) return;
  // Room for a window manager's frame and title bar; the layout's minimum size wins on a tiny screen.
  const QRect avail = sc->availableGeometry().adjusted(0, 0, -16, -48);
  const QSize fit = size().boundedTo(avail.size()).expandedTo(minimumSizeHint());
  if (fit != size()) resize(fit);
  move(avail.topLeft() + QPoint(std::max(0, (avail.width() - fit.width()) / 2), std::max(0, (avail.height() - fit.height()) / 2)));
}

void MainWindow::ShowResultsHint() {
  if (last_result_ || worker_.IsBusy()) return; // a result stays until the next run replaces it
  const nav_scene &s = doc_.Scene();
  if (hint_type_ == static_cast<int>(s.trajectory.type)) return;
  hint_type_ = static_cast<int>(s.trajectory.type);
  const QString draw = s.trajectory.type == NAV_TRAJ_WAYPOINTS
                           ? tr("Draw a drive on the map (click to add waypoints, drag to move them)")
                           : tr("This scene has a %1 trajectory: edit it in the Trajectory panel (File &gt; New drive "
                                "to draw one on the map instead)")
                                 .arg(TrajectoryKindName(s.trajectory.type).toHtmlEscaped());
  results_->setHtml(tr("<p>%1; choose the IMU and the GNSS receiver in the panels, then <b>Run</b> (F5).</p>").arg(draw));
}

bool MainWindow::Run() {
  const QVector<Issue> issues = Validate(doc_.Scene());
  if (!issues.isEmpty()) {
    ShowIssues();
    bottom_tabs_->setCurrentWidget(issues_);
    status_->setText(tr("Cannot run: %1").arg(issues.front().Text()));
    return false;
  }
  if (worker_.IsBusy()) return false;
  preview_.Cancel();
  const long runs = doc_.Scene().simulation.runs;
  worker_.Start(doc_.Scene(), runs, false, doc_.LastChangeNs(), false);
  run_act_->setEnabled(false);
  cancel_act_->setEnabled(true);
  progress_->setValue(0);
  status_->setText(tr("Running %1 Monte Carlo runs...").arg(runs));
  return true;
}

void MainWindow::Cancel() {
  if (!worker_.IsBusy()) return;
  worker_.Cancel();
  status_->setText(tr("Cancelling..."));
}

QString MainWindow::ResultsText() const { return results_->toPlainText(); }

QString MainWindow::PreviewStatusText() const { return latency_label_->text(); }

void MainWindow::OnFinished(std::shared_ptr<const SimResult> r) {
  run_act_->setEnabled(true);
  cancel_act_->setEnabled(false);
  if (preview_act_->isChecked() && (!last_preview_ || last_preview_->scene_change_ns != doc_.LastChangeNs()))
    preview_timer_.start(); // edits made during the run
  if (r->status != NAV_OK) {
    progress_->setValue(0);
    const QString what = r->status == NAV_ERR_CANCELLED ? tr("Cancelled after %1 s").arg(r->wall_s, 0, 'f', 1)
                         : r->status == kStatusCrashed ? tr("Run failed: %1").arg(r->message)
                                                       : r->message;
    // The last complete results stay (the cancelled or failed run has none to show).
    status_->setText(last_result_ ? tr("%1 — the last complete results are kept").arg(what) : what);
    if (!last_result_) results_->setHtml(QStringLiteral("<p><b>%1</b></p>").arg(what.toHtmlEscaped()));
    emit ResultShown(false);
    return;
  }
  last_result_ = r;
  scene_preview_timer_.stop();
  progress_->setValue(1000);
  const nav_sim_summary &s = r->summary;
  QString h;
  h += tr("<h3>%1 — %2 Monte Carlo runs in %3 s</h3>")
           .arg(QString::fromUtf8(doc_.Scene().name).toHtmlEscaped())
           .arg(s.runs)
           .arg(r->wall_s, 0, 'f', 1);
  {
    const nav_scene &sc = doc_.Scene();
    // The gyro-free schemes have no IMU: their sensors are the array's (layout, arm, part).
    const bool gyro_free =
        sc.navigation.scheme == NAV_SCHEME_GYRO_FREE || sc.navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
    const QString part =
        sc.array.catalog[0] ? QString::fromUtf8(sc.array.catalog).toHtmlEscaped() : tr("(scene terms)");
    const QString sensors =
        gyro_free ? tr("array %1 %2 m, %3")
                        .arg(QString::fromUtf8(nav_array_layout_kind_name(sc.array.layout)))
                        .arg(sc.array.radius_m)
                        .arg(part)
                  : tr("IMU %1").arg(sc.imu.catalog[0] ? QString::fromUtf8(sc.imu.catalog).toHtmlEscaped()
                                                       : tr("(scene terms)"));
    h += tr("<p>%1 · %2 · GNSS %3 · %4 GNSS outage(s) · %5 s at %6 Hz</p>")
             .arg(QString::fromUtf8(nav_nav_scheme_name(sc.navigation.scheme)), sensors,
                  !sc.gnss.enabled     ? tr("off")
                  : sc.gnss.catalog[0] ? QString::fromUtf8(sc.gnss.catalog).toHtmlEscaped()
                                       : tr("(scene values)"))
             .arg(r->outages.size())
             .arg(s.duration_s, 0, 'f', 0)
             .arg(sc.imu.rate_hz);
  }
  if (!r->verdicts.empty()) {
    int pass = 0;
    for (const auto &v : r->verdicts) pass += v.pass ? 1 : 0;
    const bool all = pass == static_cast<int>(r->verdicts.size());
    h += QStringLiteral("<p style='font-size:13pt; color:%1'><b>%2</b></p>")
             .arg(all ? "#148228" : "#c81e1e")
             .arg(all ? tr("Requirement verdict: PASS (%1 of %1 met)").arg(r->verdicts.size())
                      : tr("Requirement verdict: FAIL (%1 of %2 met)").arg(pass).arg(r->verdicts.size()));
    h += "<table border=1 cellspacing=0 cellpadding=3><tr><th>requirement</th><th>metric</th><th>statistic</th>"
         "<th>value</th><th>limit</th><th>verdict</th></tr>";
    for (const auto &v : r->verdicts) {
      const QString unit = QString::fromUtf8(nav_req_unit_name(v.unit));
      h += QStringLiteral("<tr><td>%1</td><td>%2</td><td>%3</td><td>%4 %5</td><td>%6 %5</td><td style='color:%7'><b>%8</b></td></tr>")
               .arg(QString::fromUtf8(v.id).toHtmlEscaped(), QString::fromUtf8(nav_req_metric_name(v.metric)),
                    QString::fromUtf8(nav_req_statistic_name(v.statistic)), Fmt(v.value, 4), unit, Fmt(v.limit, 4),
                    v.pass ? "#148228" : "#c81e1e", !v.evaluated ? tr("not evaluated") : v.pass ? tr("PASS") : tr("FAIL"));
      for (int k = 0; k < v.outage_count && v.statistic == NAV_REQ_OUTAGE_END; ++k)
        h += QStringLiteral("<tr><td></td><td colspan=2>outage %1–%2 s, end at %3 s</td><td>%4 %5</td><td></td><td></td></tr>")
                 .arg(v.outage_t0_s[k]).arg(v.outage_t1_s[k]).arg(v.outage_end_t_s[k]).arg(Fmt(v.outage_value[k], 4)).arg(unit);
    }
    h += "</table>";
  } else {
    h += tr("<p>No requirements in the scene (add them in the Requirements panel).</p>");
  }
  const double r2d = 180.0 / M_PI;
  h += tr("<p>Over all runs and epochs (RMS / 95th percentile / max):</p>");
  h += "<table border=1 cellspacing=0 cellpadding=3><tr><th></th><th>RMS</th><th>p95</th><th>max</th></tr>";
  auto row = [&](const QString &name, const nav_stat &st, double k, const QString &unit) {
    h += QStringLiteral("<tr><td>%1 [%2]</td><td>%3</td><td>%4</td><td>%5</td></tr>")
             .arg(name, unit, Fmt(st.rms * k), Fmt(st.p95 * k), Fmt(st.max * k));
  };
  row(tr("horizontal position"), s.stats.pos_err_h_m, 1.0, "m");
  row(tr("vertical position"), s.stats.pos_err_v_m, 1.0, "m");
  row(tr("velocity"), s.stats.vel_err_mps, 1.0, "m/s");
  row(tr("attitude"), s.stats.att_err_rad, r2d, "deg");
  row(tr("yaw"), s.stats.yaw_err_rad, r2d, "deg");
  h += "</table>";
  h += tr("<p>Final horizontal error: run 0 %1 m, RMS over runs %2 m (duration %3 s, %4 IMU samples per run).</p>")
           .arg(Fmt(s.final.pos_err_h_m))
           .arg(Fmt(s.final_rms.pos_err_h_m))
           .arg(s.duration_s, 0, 'f', 1)
           .arg(static_cast<long long>(s.imu_samples));
  results_html_ = h;
  results_stale_ = false;
  results_->setHtml(h);
  bottom_tabs_->setCurrentWidget(results_);
  chart_->SetResult(r, ToNavResult(*r, doc_.Scene()));
  panels_->SetVerdicts(r->verdicts);
  SetEnvelopes(*r, false);
  map_->SetEstimate(r->nav_ned, false);
  view3d_->SetEstimate(r->nav_ned, false);
  ShowScene(r);
  MarkResultsStale(r->scene_change_ns != doc_.LastChangeNs()); // edited while it ran
  QString verdict;
  if (!r->verdicts.empty())
    verdict = nav_req_all_pass(r->verdicts.data(), static_cast<int>(r->verdicts.size())) ? tr(" — verdict PASS")
                                                                                          : tr(" — verdict FAIL");
  status_->setText(tr("Done: %1 runs in %2 s%3").arg(s.runs).arg(r->wall_s, 0, 'f', 1).arg(verdict));
  emit ResultShown(false);
}


bool MainWindow::ExportReport(const QString &path, QString *error) {
  StudioReport r;
  const nav_scene &sc = doc_.Scene();
  r.scene_name = QString::fromUtf8(sc.name);
  r.scene_path = doc_.FilePath();
  r.imu = QString::fromUtf8(sc.imu.catalog);
  r.receiver = QString::fromUtf8(sc.gnss.catalog);
  const std::shared_ptr<const SimResult> res = last_result_;
  r.result = res && !res->preview ? res.get() : nullptr;
  // The single views, without the forms: as File > Export picture writes them once there is a
  // result to draw (issue 19: the report embedded a grab of the whole window), else the map and
  // 3D view as they stand on the screen.
  bool drawn = false;
  QTemporaryDir tmp;
  if (view3d_->SceneResult() && view3d_->Scene() && tmp.isValid()) {
    const QString p3 = tmp.filePath("3d.png"), pm = tmp.filePath("map.png");
    QString e3, em;
    if (ExportPicture(p3, "3d", kReportPictureWidth, kReportPictureHeight, &e3) &&
        ExportPicture(pm, "map", kReportPictureWidth, kReportPictureHeight, &em)) {
      r.images.push_back({tr("3D view: reference and estimate, attitude triads, error envelope"), QImage(p3)});
      r.images.push_back({tr("map: reference and estimate on the geodetic map"), QImage(pm)});
      drawn = true;
    }
  }
  if (!drawn)
    for (PathView *v : {map_, view3d_})
      if (v->isVisible() && v->width() > 0 && v->height() > 0)
        r.images.push_back({v == map_ ? tr("map view") : tr("3D view"), v->Grab()});
  if (chart_ && !chart_->Picture().isNull())
    r.images.push_back(
        {tr("errors against time (horizontal, vertical, velocity, attitude)"), chart_->Picture()});
  return WriteStudioReport(path, r, error);
}


void MainWindow::SetEnvelopes(const SimResult &r, bool preview) {
  // The band about run 0's estimate at the envelope epochs: 3 x the filter's reported horizontal
  // sigma for a preview (one run), 3 x the RMS over runs for a Monte Carlo result.
  const std::vector<double> &w = preview ? r.env_sd_h_m : r.env_h_rms_m;
  std::vector<double> ned, half;
  size_t j = 0;
  for (size_t i = 0; i < r.env_t_s.size() && i < w.size(); ++i) {
    while (j < r.t_s.size() && r.t_s[j] < r.env_t_s[i] - 1e-6) ++j;
    if (j >= r.t_s.size() || std::fabs(r.t_s[j] - r.env_t_s[i]) > 1e-6 || 3 * j + 2 >= r.nav_ned.size()) continue;
    ned.insert(ned.end(), {r.nav_ned[3 * j], r.nav_ned[3 * j + 1], r.nav_ned[3 * j + 2]});
    half.push_back(3.0 * w[i]);
  }
  map_->SetEnvelope(ned, half, preview);
  view3d_->SetEnvelope(ned, half, preview);
}

} // namespace studio

namespace studio {

void MainWindow::ShowScene(const std::shared_ptr<const SimResult> &r) {
  NavViewOptions o = StudioViewOptions(*r);
  o.att_exaggeration = playback_->Exaggeration();
  QString err;
  const bool same = view3d_->Scene() && view3d_->SceneResult() && last_result_ == r;
  if (!view3d_->SetSceneResult(ToNavResult(*r, doc_.Scene()), o, same, &err))
    status_->setText(tr("3D view: %1").arg(err));
  if (view3d_->Scene() && !same) view3d_->Scene()->SetTime(view3d_->Scene()->Model().t_begin_s);
  view3d_->SetSceneStale(results_stale_ && !r->preview);
  playback_->SceneChanged();
}

void MainWindow::MarkResultsStale(bool stale) {
  results_stale_ = stale;
  view3d_->SetSceneStale(stale && view3d_->Scene() && last_result_);
  bottom_tabs_->setTabText(bottom_tabs_->indexOf(results_), stale ? tr("Results (out of date)") : tr("Results"));
  bottom_tabs_->setTabText(bottom_tabs_->indexOf(chart_), stale ? tr("Errors (out of date)") : tr("Errors"));
  chart_->setEnabled(!stale); // greyed
  if (!last_result_) return;
  if (stale)
    results_->setHtml(tr("<p style='color:#a05000'><b>Out of date:</b> the scene was edited after this run; "
                         "Run (F5) again for current results. The live preview follows the edits.</p>") +
                      QStringLiteral("<div style='color:#8a8a8a'>%1</div>").arg(results_html_));
  else
    results_->setHtml(results_html_);
}

void MainWindow::ClearResults() {
  last_result_.reset();
  last_preview_.reset();
  scene_preview_timer_.stop();
  results_stale_ = false;
  results_html_.clear();
  view3d_->SetSceneResult(nullptr, NavViewOptions(), false, nullptr);
  playback_->SceneChanged();
  for (PathView *v : {map_, view3d_}) {
    v->SetEstimate({}, false);
    v->SetEstimate({}, true);
    v->SetEnvelope({}, {}, true);
  }
  chart_->SetResult(nullptr, nullptr);
  chart_->setEnabled(true);
  panels_->SetVerdicts({});
  bottom_tabs_->setTabText(bottom_tabs_->indexOf(results_), tr("Results"));
  bottom_tabs_->setTabText(bottom_tabs_->indexOf(chart_), tr("Errors"));
  hint_type_ = -1;
  ShowResultsHint();
}

bool MainWindow::ExportMovie(const QString &path, const MovieRequest &req, QString *error) {
  const std::shared_ptr<const NavResult> res = view3d_->SceneResult();
  if (!res || !view3d_->Scene()) {
    *error = tr("no result to play back: Run (F5) first");
    return false;
  }
  if (req.width_px < 16 || req.height_px < 16 || req.width_px > 3840 || req.height_px > 2160) {
    *error = tr("movie size %1x%2: expected 16x16 to 3840x2160").arg(req.width_px).arg(req.height_px);
    return false;
  }
  // Its own offscreen view of the same result and options: the window stays as it is.
  NavSceneView movie;
  NavViewOptions o = view3d_->Scene()->GetOptions();
  o.width_px = req.width_px;
  o.height_px = req.height_px;
  o.show_grid = true;
  o.show_axes = true;
  o.multisamples = 0;
  o.follow = req.follow;
  o.follow_distance_m = playback_->FollowDistance();
  o.time_s = NAN;
  movie.SetResult(res);
  movie.SetOptions(o);
  NavMovieOptions mo;
  mo.duration_s = req.duration_s;
  mo.fps = req.fps;
  QProgressDialog dlg(tr("Writing %1...").arg(QFileInfo(path).fileName()), tr("Cancel"), 0, 1000, this);
  dlg.setObjectName("movieProgress");
  dlg.setWindowTitle(tr("Export movie"));
  dlg.setWindowModality(Qt::WindowModal);
  dlg.setMinimumDuration(0);
  dlg.setValue(0);
  std::string err;
  const bool ok = movie.RenderMovieFile(path.toStdString(), mo, [&](double f) {
    dlg.setValue(static_cast<int>(std::lround(1000.0 * f)));
    QCoreApplication::processEvents();
    return !dlg.wasCanceled();
  }, &err);
  dlg.reset();
  if (!ok) *error = QString::fromStdString(err);
  return ok;
}

bool MainWindow::ExportPicture(const QString &path, const QString &view, int width, int height, QString *error) {
  const std::shared_ptr<const NavResult> res = view3d_->SceneResult();
  if (!res || !view3d_->Scene()) {
    *error = tr("no result to draw: Run (F5) first");
    return false;
  }
  if (width < 16 || height < 16 || width > 3840 || height > 2160) {
    *error = tr("picture size %1x%2: expected 16x16 to 3840x2160").arg(width).arg(height);
    return false;
  }
  std::string err;
  bool ok = false;
  if (view == "map") {
    NavMapOptions mo;
    mo.width_px = width;
    mo.height_px = height;
    mo.tiles = map_tiles_.toStdString();
    mo.tiles_attribution = map_tiles_attribution_.toStdString();
    ok = NavRenderMapPng(*res, mo, path.toStdString(), &err);
  } else {
    NavSceneView pic;
    NavViewOptions o = view3d_->Scene()->GetOptions();
    o.width_px = width;
    o.height_px = height;
    o.show_grid = true;
    o.show_axes = true;
    o.multisamples = 8;
    o.time_s = view3d_->Scene()->GetTime();
    pic.SetResult(res);
    pic.SetOptions(o);
    ok = pic.RenderPng(path.toStdString(), &err);
  }
  if (!ok) *error = QString::fromStdString(err);
  return ok;
}

} // namespace studio
