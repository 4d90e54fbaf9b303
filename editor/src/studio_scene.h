/*
 * navstudio: the edited scene (a nav_scene held by value), its undo stack, file I/O through
 * navcore_io, validation through nav_scene_validate (the same messages as `navsim check`), the
 * trajectory path through navcore's trajectory models, and the catalogs of resources/.
 * GUI thread only (style.md section 7); no widget code here.
 */
#ifndef NAVSTUDIO_STUDIO_SCENE_H
#define NAVSTUDIO_STUDIO_SCENE_H

#include <QByteArray>
#include <QElapsedTimer>
#include <QObject>
#include <QString>
#include <QStringList>
#include <QUndoStack>
#include <QVector>

#include <functional>
#include <memory>
#include <vector>

extern "C" {
#include "navcore/nav_catalog.h"
#include "navcore/nav_scene.h"
}

namespace studio {

/** One validation problem: scene-file field path and message (as `navsim check` prints them). */
struct Issue {
  QString path;
  QString message;
  /** "path: message"; a message that already starts with its path or a field under it
   *  (navcore's planner messages do: "trajectory.waypoints[2]: ...") is not prefixed again. */
  QString Text() const {
    const bool own = !path.isEmpty() && message.startsWith(path) && message.size() > path.size() &&
                     QStringLiteral(":[.").contains(message.at(path.size()));
    return path.isEmpty() || own ? message : path + ": " + message;
  }
};

/** The reference path sampled for drawing: local N/E/D about the scene origin [m]. */
struct PathSamples {
  std::vector<double> t_s;
  std::vector<double> ned_m; /**< 3 per sample */
  // The kinematic profile along the path (from navcore's trajectory evaluation), per sample:
  std::vector<double> speed_mps;    /**< |v| */
  std::vector<double> accel_mps2;   /**< longitudinal acceleration (along the velocity) */
  std::vector<double> turn_rps;     /**< horizontal turn rate (course rate; + = right) */
  std::vector<unsigned char> over;  /**< bits of the limits exceeded there (kOver*) */
  nav_traj_limits limits{};         /**< the vehicle limits of the trajectory (0: none) */
  size_t Size() const { return t_s.size(); }
};

/** Limit bits of PathSamples::over. */
enum : unsigned char { kOverAccel = 1, kOverTurnRate = 2, kOverLateral = 4 };
/** Text of the limits in @p bits ("acceleration", "turn rate", "lateral acceleration"). */
QString OverLimitText(unsigned bits);

/** Directory holding imu_catalog.csv and gnss_receivers.csv ($NAV_RESOURCES_DIR, else the share
    directory's resources/ found by nav_paths_resources_dir: installed or build tree); "" if none. */
QString ResourcesDir();
/** Directory of the scene library (the share directory's scenes/, nav_paths_scenes_dir); "" if none. */
QString ScenesDir();

/** Equivalent spellings the editor keeps in one form (see the .cpp). */
void Normalize(nav_scene *s);

/**
 * Take over the heap data of a scene the reader just filled (the control points of a recorded
 * reference, nav_scene_release): the editor copies scenes as plain bytes (undo stack, Pack,
 * workers), so that data is kept until the program ends instead of belonging to one copy.
 * Temporary read-backs release their scene instead.
 */
void KeepSceneData(const nav_scene &s);

/** Speed of a drawn drive between its stops and at its interior waypoints [m/s]. */
constexpr double kDriveCruiseMps = 10.0;

/** A new drive: WGS-84 (Berlin), no waypoints yet, INS/GNSS, 100 Hz IMU, 10 Hz output, 10 runs. */
std::unique_ptr<nav_scene> NewDriveScene();

/** Every problem of @p s: nav_scene_validate, then the trajectory planner (waypoints, segments). */
QVector<Issue> Validate(const nav_scene &s);

/** For waypoint and segment trajectories: set duration_s to the planned length ("auto").
 *  @return false with @p msg when the plan is infeasible (the planner's message). */
bool UpdateDuration(nav_scene *s, QString *msg);

/** Sample the reference trajectory of @p s at up to @p max_points points. */
bool SamplePath(const nav_scene &s, int max_points, PathSamples *out, QString *msg);

/** Compressed snapshot of a scene (undo entries): a 0.5 MB struct, mostly zeros. */
QByteArray Pack(const nav_scene &s);
bool Unpack(const QByteArray &b, nav_scene *s);

/** Local N/E/D [m] <-> geodetic (degrees, metres) through navcore's frame of @p s. */
void LocalToGeodetic(const nav_scene &s, const double ned[3], double *lat_deg, double *lon_deg, double *h_m);
void GeodeticToLocal(const nav_scene &s, double lat_deg, double lon_deg, double h_m, double ned[3]);

/** The IMU and GNSS catalogs (loaded once). */
class Catalogs {
public:
  Catalogs();
  ~Catalogs();
  Catalogs(const Catalogs &) = delete;
  Catalogs &operator=(const Catalogs &) = delete;
  const nav_catalog *Imu() const { return imu_; }
  const nav_catalog *Gnss() const { return gnss_; }
  QStringList ImuNames() const;
  QStringList GnssNames() const;
  QString Errors() const { return errors_; }

private:
  nav_catalog *imu_ = nullptr;
  nav_catalog *gnss_ = nullptr;
  QString errors_;
};

/** The start of the hidden temporary file a save of @p file_name writes next to it before
 *  renaming it over the file: ".<file_name>.navstudio-tmp-", then the writer's process id. */
QString TempPrefix(const QString &file_name);
/** Remove from @p dir the temporary files of saves that did not finish because their navstudio
 *  was killed (their process no longer runs); returns how many were removed. */
int RemoveStaleTempFiles(const QString &dir);

/**
 * The document: the scene being edited, its file, its undo stack. Every edit goes through Edit()
 * (one undo step) or through Preview()/Commit() (a drag: many live updates, one undo step).
 */
class SceneDocument : public QObject {
  Q_OBJECT
public:
  explicit SceneDocument(QObject *parent = nullptr);
  ~SceneDocument() override;

  const nav_scene &Scene() const { return *scene_; }
  QUndoStack *UndoStack() { return &undo_; }
  QString FilePath() const { return path_; }
  bool IsModified() const { return !undo_.isClean(); }

  /** Apply @p fn to a copy of the scene and push it as one undoable edit named @p text. */
  void Edit(const QString &text, const std::function<void(nav_scene &)> &fn);
  /** Show a live state (drag in progress) without an undo entry. */
  void Preview(const nav_scene &s);
  /** End a live edit: one undo step from @p before to the current scene. */
  void Commit(const nav_scene &before, const QString &text);
  /** Replace the scene (used by the undo commands). */
  void SetSceneInternal(const nav_scene &s);

  /** Load a scene file; on failure @p errors holds the diagnostics (FILE:LINE:COL: error: ...). */
  bool Load(const QString &path, QStringList *errors);
  /** Load from memory (autosave recovery): the document keeps @p path_for_save as its file. */
  bool LoadText(const QByteArray &text, const QString &display, const QString &path_for_save,
                QStringList *errors);
  /** Start a new document from @p s (clean, no file). */
  void Reset(const nav_scene &s);
  /** Save atomically (temp + fsync + rename); marks the document clean. When the document was
   *  loaded from a file, the changes are spliced into the text the user wrote (scene_text.h), so
   *  comments, blank lines and layout survive; the spliced text is used only if it reads back to
   *  exactly this scene, else whole sections, else navcore's writer alone (SaveNote() says which). */
  bool Save(const QString &path, QString *error);
  /** What the last Save() kept of the user's text ("" before any save). */
  QString SaveNote() const { return save_note_; }
  /** Write a copy (autosave) without changing the document's file or clean state. */
  bool WriteCopy(const QString &path, QString *error) const;

  /** Monotonic time [ns] of the last change of the scene (edit, drag step, undo). */
  qint64 LastChangeNs() const { return last_change_ns_; }
  static qint64 NowNs();

  /** A live edit (drag) is in progress: Preview() since the last Commit() or other change. */
  bool IsLive() const { return live_; }

  /** Last feasibility message of the trajectory planner ("" when feasible). */
  QString PlanMessage() const { return plan_msg_; }

signals:
  /** The scene changed (any edit, live or undoable). */
  void Changed();
  /** The file path or the clean state changed. */
  void FileStateChanged();

private:
  void Touch();
  void RememberUserText(const QString &path, const nav_scene &read_as);
  QByteArray SaveText(QString *note) const;
  std::unique_ptr<nav_scene> scene_;
  QUndoStack undo_;
  QString path_;
  QString plan_msg_;
  // The text the document was loaded from (or last saved as) and the scene it reads as: the
  // base of the comment-preserving save. Empty for a new document.
  QByteArray user_text_;
  std::unique_ptr<nav_scene> user_scene_;
  QString save_note_;
  qint64 last_change_ns_ = 0;
  bool live_ = false;
};

} // namespace studio

#endif
