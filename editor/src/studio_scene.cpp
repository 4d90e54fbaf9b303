#include "studio_scene.h"
#include "scene_text.h"

#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QRegularExpression>
#include <QUndoCommand>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstring>

extern "C" {
#include "navcore/nav_frames.h"
#include "navcore/nav_io.h"
#include "navcore/nav_motiondef.h"
#include "navcore/nav_paths.h"
#include "navcore/nav_traj.h"
}

namespace studio {

// $NAV_RESOURCES_DIR, else <share>/resources; the share directory is found relative to the
// executable, installed or in the build tree (nav_paths.h).
QString ResourcesDir() {
  char dir[4096];
  return nav_paths_resources_dir(dir, sizeof dir) ? QString::fromLocal8Bit(dir) : QString();
}

QString ScenesDir() {
  char dir[4096];
  return nav_paths_scenes_dir(dir, sizeof dir) ? QString::fromLocal8Bit(dir) : QString();
}

namespace {
// Scenes whose heap data the editor keeps (KeepSceneData); released when the program ends.
struct KeptScenes {
  std::vector<nav_scene *> kept;
  ~KeptScenes() {
    for (nav_scene *s : kept) {
      nav_scene_release(s);
      delete s;
    }
  }
};
KeptScenes &Kept() {
  static KeptScenes k;
  return k;
}
} // namespace

void KeepSceneData(const nav_scene &s) {
  if (s.trajectory.recorded.ctrl_ned_m == nullptr) return;
  auto *owner = new nav_scene(s);
  Kept().kept.push_back(owner);
}

void Normalize(nav_scene *s) {
  // navigation.cov_decimation: 0 (nav_scene_default) and 1 both mean "every IMU step"
  // (nav_scene.h), but the reader accepts only >= 1, so a scene written with 0 would not read
  // back. Until navcore agrees with itself, the editor keeps the equivalent 1.
  if (s->navigation.cov_decimation == 0) s->navigation.cov_decimation = 1;
}

std::unique_ptr<nav_scene> NewDriveScene() {
  auto s = std::make_unique<nav_scene>(nav_scene_default());
  Normalize(s.get());
  std::snprintf(s->name, sizeof s->name, "%s", "new-drive");
  s->earth.model = NAV_EARTH_WGS84;
  s->earth.origin_lat_rad = 52.52 * M_PI / 180.0;
  s->earth.origin_lon_rad = 13.405 * M_PI / 180.0;
  s->earth.origin_h_m = 35.0;
  s->trajectory.type = NAV_TRAJ_WAYPOINTS;
  s->trajectory.initial_attitude = nav_euler{0.0, 0.0, 0.0};
  nav_traj_waypoints &w = s->trajectory.waypoints;
  w.count = 0;
  w.timing = NAV_WP_TIMING_SPEED;
  w.attitude_mode = NAV_WP_ATT_GROUND;
  w.hold_start_s = 30.0;
  w.hold_end_s = 5.0;
  w.cruise_mps = kDriveCruiseMps; // two clicks make a drive: the leg between the two stops is driven
  s->trajectory.duration_s = 60.0;
  s->imu.rate_hz = 100.0;
  s->gnss.enabled = true;
  s->navigation.scheme = NAV_SCHEME_INS_GNSS;
  s->navigation.algorithm = NAV_MECH_HIGH_ORDER;
  s->navigation.frame = NAV_MECH_NED;
  s->initial_errors.pos_sd_m = nav_vec3{2.0, 2.0, 4.0};
  s->initial_errors.vel_sd_mps = nav_vec3{0.1, 0.1, 0.1};
  const double d2r = M_PI / 180.0;
  s->initial_errors.att_sd_rad = nav_vec3{0.5 * d2r, 0.5 * d2r, 3.0 * d2r};
  s->output.rate_hz = 10.0;
  s->simulation.seed = 1;
  s->simulation.runs = 10;
  return s;
}

namespace {
struct IssueSink {
  QVector<Issue> *out;
};
void CollectIssue(void *user, const char *path, const char *message) {
  auto *sink = static_cast<IssueSink *>(user);
  sink->out->push_back(Issue{QString::fromUtf8(path ? path : ""), QString::fromUtf8(message ? message : "")});
}
void CollectDiagIssue(void *user, const nav_diag *d) {
  auto *sink = static_cast<IssueSink *>(user);
  sink->out->push_back(Issue{QString::fromUtf8(d->path), QString::fromUtf8(d->message)});
}
bool IsScript(const nav_scene &s) {
  return s.trajectory.type == NAV_TRAJ_WAYPOINTS || s.trajectory.type == NAV_TRAJ_SEGMENTS;
}
} // namespace

QVector<Issue> Validate(const nav_scene &s) {
  // The scene goes through navcore's writer and reader, in memory, so the panels report exactly
  // what `navsim check` would report for the file the editor writes (field checks of the reader,
  // then nav_scene_validate); the trajectory planner's verdict follows. The last answer is
  // cached (one scene is validated by several widgets after each edit).
  static std::vector<unsigned char> cached_scene;
  static QVector<Issue> cached_issues;
  if (cached_scene.size() == sizeof s && std::memcmp(cached_scene.data(), &s, sizeof s) == 0) return cached_issues;
  QVector<Issue> out;
  char *text = nullptr;
  size_t len = 0;
  if (nav_scene_write_string(&s, &text, &len) == NAV_OK) {
    auto back = std::make_unique<nav_scene>();
    IssueSink sink{&out};
    const nav_status st = nav_scene_read_string(text, len, "navstudio", back.get(), CollectDiagIssue, &sink);
    if (st == NAV_OK) nav_scene_release(back.get()); // a temporary read-back
    std::free(text);
  } else {
    IssueSink sink{&out};
    const nav_status st = nav_scene_validate(&s, CollectIssue, &sink);
    (void)st;
  }
  if (out.isEmpty() && IsScript(s)) {
    nav_scene copy = s;
    QString msg;
    if (!UpdateDuration(&copy, &msg))
      out.push_back(Issue{s.trajectory.type == NAV_TRAJ_WAYPOINTS ? QStringLiteral("trajectory.waypoints")
                                                                  : QStringLiteral("trajectory.segments"),
                          msg});
  }
  cached_scene.assign(reinterpret_cast<const unsigned char *>(&s), reinterpret_cast<const unsigned char *>(&s) + sizeof s);
  cached_issues = out;
  return out;
}

bool UpdateDuration(nav_scene *s, QString *msg) {
  if (!IsScript(*s)) return true;
  if (s->trajectory.type == NAV_TRAJ_WAYPOINTS && s->trajectory.waypoints.count < 2) {
    if (msg) *msg = QStringLiteral("at least two waypoints are needed (click on the map to add them)");
    return false;
  }
  nav_script_summary sum;
  std::memset(&sum, 0, sizeof sum);
  char buf[512] = "";
  if (nav_motiondef_script_summary(s, &sum, buf, sizeof buf) != NAV_OK) {
    if (msg) *msg = QString::fromUtf8(buf[0] ? buf : "the trajectory cannot be planned");
    return false;
  }
  s->trajectory.duration_s = sum.duration_s;
  if (msg) msg->clear();
  return true;
}

bool SamplePath(const nav_scene &s, int max_points, PathSamples *out, QString *msg) {
  *out = PathSamples();
  if (s.trajectory.type == NAV_TRAJ_WAYPOINTS) out->limits = s.trajectory.waypoints.limits;
  if (s.trajectory.type == NAV_TRAJ_SEGMENTS) out->limits = s.trajectory.segments.limits;
  if (s.trajectory.type == NAV_TRAJ_WAYPOINTS && s.trajectory.waypoints.count < 2) {
    if (msg) *msg = QStringLiteral("at least two waypoints are needed");
    return false;
  }
  const double dt = 1.0 / (s.imu.rate_hz > 0.0 && std::isfinite(s.imu.rate_hz) ? s.imu.rate_hz : 100.0);
  nav_traj *traj = nullptr;
  char buf[512] = "";
  if (nav_traj_create_msg(&s, dt, &traj, buf, sizeof buf) != NAV_OK) {
    if (msg) *msg = QString::fromUtf8(buf[0] ? buf : "the trajectory cannot be created");
    return false;
  }
  const double dur = nav_traj_duration(traj);
  const nav_frame fr = nav_traj_frame(traj);
  const int n = std::max(2, max_points);
  out->t_s.reserve(static_cast<size_t>(n));
  out->ned_m.reserve(3u * static_cast<size_t>(n));
  bool ok = true;
  for (int i = 0; i < n; ++i) {
    const double t = dur * i / (n - 1);
    nav_traj_state st;
    if (nav_traj_eval(traj, t, &st) != NAV_OK) {
      ok = false;
      if (msg) *msg = QStringLiteral("the trajectory cannot be evaluated at t = %1 s").arg(t);
      break;
    }
    const nav_local_view v = nav_frame_view(&fr, st.r_fb_f_m, st.v_fb_f_mps, st.q_b_f);
    out->t_s.push_back(t);
    out->ned_m.push_back(v.r_ned_m.x);
    out->ned_m.push_back(v.r_ned_m.y);
    out->ned_m.push_back(v.r_ned_m.z);
    // Profile: speed, acceleration along the velocity, course rate (v x a over v^2, horizontal),
    // in local level (the transport-rate term of d(v_n)/dt, v^2/R, is negligible here).
    const nav_vec3 vn = v.v_n_mps, an = nav_mat3_mul_vec(v.C_f_n, st.a_fb_f_mps2);
    const double speed = nav_vec3_norm(vn), vh2 = vn.x * vn.x + vn.y * vn.y;
    const double acc = speed > 1e-3 ? nav_vec3_dot(vn, an) / speed : 0.0;
    const double turn = vh2 > 0.25 ? (vn.x * an.y - vn.y * an.x) / vh2 : 0.0;
    out->speed_mps.push_back(speed);
    out->accel_mps2.push_back(acc);
    out->turn_rps.push_back(turn);
    unsigned char bits = 0;
    const nav_traj_limits &L = out->limits;
    auto over = [](double x, double lim) { return lim > 0.0 && std::fabs(x) > lim * (1.0 + 1e-3) + 1e-9; };
    if (over(acc, L.max_accel_mps2)) bits |= kOverAccel;
    if (over(turn, L.max_rate_rps)) bits |= kOverTurnRate;
    if (over(std::sqrt(vh2) * turn, L.max_lateral_accel_mps2)) bits |= kOverLateral;
    out->over.push_back(bits);
  }
  nav_traj_destroy(traj);
  if (ok && msg) msg->clear();
  return ok;
}

QString OverLimitText(unsigned bits) {
  QStringList l;
  if (bits & kOverAccel) l << QObject::tr("acceleration");
  if (bits & kOverTurnRate) l << QObject::tr("turn rate");
  if (bits & kOverLateral) l << QObject::tr("lateral acceleration");
  return l.join(", ");
}

QByteArray Pack(const nav_scene &s) {
  return qCompress(reinterpret_cast<const uchar *>(&s), static_cast<int>(sizeof s), 1);
}

bool Unpack(const QByteArray &b, nav_scene *s) {
  const QByteArray raw = qUncompress(b);
  if (raw.size() != static_cast<int>(sizeof *s)) return false;
  std::memcpy(s, raw.constData(), sizeof *s);
  return true;
}

void LocalToGeodetic(const nav_scene &s, const double ned[3], double *lat_deg, double *lon_deg, double *h_m) {
  const nav_frame fr = nav_frame_from_scene(&s);
  const nav_geodetic g = nav_frame_local_to_geodetic(&fr, nav_vec3{ned[0], ned[1], ned[2]});
  *lat_deg = g.lat_rad * 180.0 / M_PI;
  *lon_deg = g.lon_rad * 180.0 / M_PI;
  *h_m = g.h_m;
}

void GeodeticToLocal(const nav_scene &s, double lat_deg, double lon_deg, double h_m, double ned[3]) {
  const nav_frame fr = nav_frame_from_scene(&s);
  const nav_vec3 r = nav_frame_geodetic_to_local(&fr, nav_geodetic{lat_deg * M_PI / 180.0, lon_deg * M_PI / 180.0, h_m});
  ned[0] = r.x;
  ned[1] = r.y;
  ned[2] = r.z;
}

/* ---------------------------------------------------------------- catalogs */

namespace {
void CollectDiag(void *user, const nav_diag *d) {
  char buf[1600];
  nav_diag_format(d, buf, sizeof buf);
  auto *s = static_cast<QString *>(user);
  s->append(QString::fromUtf8(buf) + "\n");
}
} // namespace

Catalogs::Catalogs() {
  const QString dir = ResourcesDir();
  const QByteArray imu = QFile::encodeName(dir + "/imu_catalog.csv");
  const QByteArray gnss = QFile::encodeName(dir + "/gnss_receivers.csv");
  if (nav_catalog_load(imu.constData(), nullptr, &imu_, CollectDiag, &errors_) != NAV_OK) imu_ = nullptr;
  if (nav_catalog_load(gnss.constData(), nullptr, &gnss_, CollectDiag, &errors_) != NAV_OK) gnss_ = nullptr;
}

Catalogs::~Catalogs() {
  nav_catalog_destroy(imu_);
  nav_catalog_destroy(gnss_);
}

QStringList Catalogs::ImuNames() const {
  QStringList l;
  for (size_t i = 0; i < nav_catalog_count(imu_); ++i) l << QString::fromUtf8(nav_catalog_imu_at(imu_, i)->name);
  return l;
}

QStringList Catalogs::GnssNames() const {
  QStringList l;
  for (size_t i = 0; i < nav_catalog_count(gnss_); ++i) l << QString::fromUtf8(nav_catalog_gnss_at(gnss_, i)->name);
  return l;
}

/* ---------------------------------------------------------------- document */

namespace {
class SceneCommand : public QUndoCommand {
public:
  SceneCommand(SceneDocument *doc, QByteArray before, QByteArray after, const QString &text)
      : QUndoCommand(text), doc_(doc), before_(std::move(before)), after_(std::move(after)) {}
  void undo() override { Apply(before_); }
  void redo() override { Apply(after_); }

private:
  void Apply(const QByteArray &b) {
    auto s = std::make_unique<nav_scene>();
    if (Unpack(b, s.get())) doc_->SetSceneInternal(*s);
  }
  SceneDocument *doc_;
  QByteArray before_, after_;
};
} // namespace

SceneDocument::SceneDocument(QObject *parent) : QObject(parent), scene_(NewDriveScene()) {
  undo_.setUndoLimit(500);
  connect(&undo_, &QUndoStack::cleanChanged, this, &SceneDocument::FileStateChanged);
  Touch();
}

SceneDocument::~SceneDocument() = default;

qint64 SceneDocument::NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

void SceneDocument::Touch() {
  last_change_ns_ = NowNs();
  QString msg;
  nav_scene copy = *scene_;
  plan_msg_.clear();
  if (!UpdateDuration(&copy, &msg)) plan_msg_ = msg;
}

void SceneDocument::Edit(const QString &text, const std::function<void(nav_scene &)> &fn) {
  auto after = std::make_unique<nav_scene>(*scene_);
  fn(*after);
  QString msg;
  (void)UpdateDuration(after.get(), &msg);
  if (std::memcmp(after.get(), scene_.get(), sizeof(nav_scene)) == 0) return; // nothing changed
  undo_.push(new SceneCommand(this, Pack(*scene_), Pack(*after), text));
}

void SceneDocument::Preview(const nav_scene &s) {
  live_ = true;
  *scene_ = s;
  QString msg;
  (void)UpdateDuration(scene_.get(), &msg);
  Touch();
  emit Changed();
}

void SceneDocument::Commit(const nav_scene &before, const QString &text) {
  live_ = false;
  if (std::memcmp(&before, scene_.get(), sizeof(nav_scene)) == 0) {
    emit Changed(); // no undo step, but the views leave their live-drag drawing
    return;
  }
  // The command's first redo() re-applies the current scene: harmless, and it emits Changed.
  undo_.push(new SceneCommand(this, Pack(before), Pack(*scene_), text));
}

void SceneDocument::SetSceneInternal(const nav_scene &s) {
  live_ = false;
  *scene_ = s;
  Touch();
  emit Changed();
}

namespace {
struct DiagList {
  QStringList *out;
};
void CollectDiagList(void *user, const nav_diag *d) {
  char buf[1600];
  nav_diag_format(d, buf, sizeof buf);
  auto *l = static_cast<DiagList *>(user);
  if (l->out) l->out->push_back(QString::fromUtf8(buf));
}
} // namespace

bool SceneDocument::Load(const QString &path, QStringList *errors) {
  auto s = std::make_unique<nav_scene>();
  DiagList dl{errors};
  const QByteArray p = QFile::encodeName(path);
  if (nav_scene_read_file(p.constData(), s.get(), CollectDiagList, &dl) != NAV_OK) return false;
  KeepSceneData(*s);
  Normalize(s.get());
  RememberUserText(path, *s);
  path_ = QFileInfo(path).absoluteFilePath();
  // A save of this folder's scenes that a killed navstudio left unfinished (the scene itself is
  // whole: saves write a temporary file and rename it).
  RemoveStaleTempFiles(QFileInfo(path_).absolutePath());
  undo_.clear();
  live_ = false;
  *scene_ = *s;
  Touch();
  emit Changed();
  emit FileStateChanged();
  return true;
}

bool SceneDocument::LoadText(const QByteArray &text, const QString &display, const QString &path_for_save,
                             QStringList *errors) {
  auto s = std::make_unique<nav_scene>();
  DiagList dl{errors};
  const QByteArray name = display.toUtf8();
  if (nav_scene_read_string(text.constData(), static_cast<size_t>(text.size()), name.constData(), s.get(),
                            CollectDiagList, &dl) != NAV_OK)
    return false;
  KeepSceneData(*s);
  Normalize(s.get());
  // The file the recovered document belongs to is the base of its comment-preserving save.
  user_text_.clear();
  user_scene_.reset();
  if (!path_for_save.isEmpty() && QFileInfo::exists(path_for_save)) {
    auto f = std::make_unique<nav_scene>();
    const QByteArray fp = QFile::encodeName(path_for_save);
    if (nav_scene_read_file(fp.constData(), f.get(), nullptr, nullptr) == NAV_OK) {
      KeepSceneData(*f);
      Normalize(f.get());
      RememberUserText(path_for_save, *f);
    }
  }
  path_ = path_for_save;
  undo_.clear();
  // A recovered document differs from its file: push the recovery as an edit so it is "modified".
  const nav_scene before = *scene_;
  live_ = false;
  *scene_ = *s;
  undo_.push(new SceneCommand(this, Pack(before), Pack(*s), tr("Recover autosave")));
  Touch();
  emit Changed();
  emit FileStateChanged();
  return true;
}

void SceneDocument::Reset(const nav_scene &s) {
  undo_.clear();
  path_.clear();
  user_text_.clear();
  user_scene_.reset();
  live_ = false;
  *scene_ = s;
  Normalize(scene_.get());
  Touch();
  emit Changed();
  emit FileStateChanged();
}

void SceneDocument::RememberUserText(const QString &path, const nav_scene &read_as) {
  QFile f(path);
  if (f.open(QIODevice::ReadOnly)) {
    user_text_ = f.readAll();
    user_scene_ = std::make_unique<nav_scene>(read_as);
  } else {
    user_text_.clear();
    user_scene_.reset();
  }
}

QString TempPrefix(const QString &file_name) { return "." + file_name + ".navstudio-tmp-"; }

int RemoveStaleTempFiles(const QString &dir) {
  const QDir d(dir);
  if (!d.exists()) return 0;
  int removed = 0;
  const QStringList names = d.entryList({QStringLiteral(".*.navstudio-tmp-*")}, QDir::Files | QDir::Hidden | QDir::System);
  for (const QString &name : names) {
    const int at = name.lastIndexOf(QStringLiteral(".navstudio-tmp-"));
    bool ok = false;
    const qint64 pid = name.mid(at + 15).toLongLong(&ok);
    if (at < 1 || !ok || pid <= 0) continue;
    // Saves run on the GUI thread, which is here: a file of this process id is a leftover of
    // an earlier process that had the same id. Another running process's file is left alone.
    const bool stale = pid == QCoreApplication::applicationPid() ||
                       (kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH);
    if (stale && QFile::remove(d.filePath(name))) ++removed;
  }
  return removed;
}

namespace {
/* navcore's writer's text of @p s (empty on failure). */
QByteArray CanonicalText(const nav_scene &s) {
  char *text = nullptr;
  size_t len = 0;
  QByteArray out;
  if (nav_scene_write_string(&s, &text, &len) == NAV_OK) out = QByteArray(text, static_cast<int>(len));
  std::free(text);
  return out;
}

/* Test hook (NAVSTUDIO_TEST_SLOW_WRITE_US, the kill-during-save test): the text is written in
 * small pieces with this pause between them, as on a slow disk, so that a kill lands inside the
 * write; the start and end of each write are reported on stderr. 0 (unset): one write. */
long SlowWriteUs() {
  bool ok = false;
  const int us = qEnvironmentVariableIntValue("NAVSTUDIO_TEST_SLOW_WRITE_US", &ok);
  return ok && us > 0 ? us : 0;
}

bool WriteAll(int fd, const char *p, size_t n, long pause_us) {
  const size_t piece = pause_us > 0 ? 64 : n;
  while (n > 0) {
    const ssize_t w = write(fd, p, std::min(piece, n));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<size_t>(w);
    if (pause_us > 0 && n > 0) usleep(static_cast<useconds_t>(pause_us));
  }
  return true;
}

/* Write @p text to @p path atomically: a temporary file in the same directory, fsync, rename.
 * The temporary file is hidden (TempPrefix) and carries the process id, so that a later
 * navstudio can tell the temporary files of a killed one from those of a running one
 * (RemoveStaleTempFiles). */
bool WriteAtomically(const QString &path, const QByteArray &text, QString *error) {
  const QFileInfo fi(path);
  const QByteArray final_path = QFile::encodeName(path);
  const QByteArray tmp = QFile::encodeName(fi.absolutePath() + "/" + TempPrefix(fi.fileName()) +
                                           QString::number(QCoreApplication::applicationPid()));
  const long pause_us = SlowWriteUs();
  if (pause_us > 0) std::fprintf(stderr, "navstudio: test: write begin %s\n", final_path.constData());
  const int fd = open(tmp.constData(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  bool ok = fd >= 0;
  int saved_errno = ok ? 0 : errno;
  if (ok && !WriteAll(fd, text.constData(), static_cast<size_t>(text.size()), pause_us)) ok = false;
  // The file keeps its permissions; a new one gets rw-rw-rw- less the umask.
  if (ok) {
    struct stat st {};
    if (stat(final_path.constData(), &st) == 0) {
      ok = fchmod(fd, st.st_mode & 07777) == 0;
    } else {
      const mode_t um = umask(0);
      umask(um);
      ok = fchmod(fd, 0666 & ~um) == 0;
    }
  }
  if (ok) ok = fsync(fd) == 0;
  if (!ok && saved_errno == 0) saved_errno = errno;
  if (fd >= 0 && close(fd) != 0 && ok) {
    ok = false;
    saved_errno = errno;
  }
  if (ok && std::rename(tmp.constData(), final_path.constData()) != 0) {
    ok = false;
    saved_errno = errno;
  }
  if (ok) {
    // The rename is made durable with the directory.
    const QByteArray dir = QFile::encodeName(fi.absolutePath());
    const int dfd = open(dir.constData(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd >= 0) {
      (void)fsync(dfd);
      close(dfd);
    }
  }
  if (!ok) {
    std::remove(tmp.constData());
    if (error)
      *error = QStringLiteral("%1: error: cannot write the scene (%2)").arg(path, QString::fromLocal8Bit(std::strerror(saved_errno)));
    return false;
  }
  if (pause_us > 0) std::fprintf(stderr, "navstudio: test: write end %s\n", final_path.constData());
  return true;
}
} // namespace

QByteArray SceneDocument::SaveText(QString *note) const {
  const QByteArray canon_new = CanonicalText(*scene_);
  if (canon_new.isEmpty()) return QByteArray();
  if (user_text_.isEmpty() || !user_scene_) {
    if (note) *note = tr("written by navcore's writer (a new scene)");
    return canon_new;
  }
  QByteArray canon_old = CanonicalText(*user_scene_);
  // "duration_s: auto" (or none) of a script stays so while the duration is the planned one:
  // both canonical texts say auto there, so the merge sees no change of that key.
  QByteArray user_duration;
  const bool has_duration = SceneScalar(user_text_, {QStringLiteral("trajectory"), QStringLiteral("duration_s")},
                                        &user_duration);
  QByteArray canon_new_auto = canon_new;
  if (!has_duration || user_duration == "auto") {
    auto autoify = [](QByteArray *canon, const nav_scene &sc) {
      if (!IsScript(sc)) return;
      auto planned = std::make_unique<nav_scene>(sc);
      QString m;
      if (!UpdateDuration(planned.get(), &m) || planned->trajectory.duration_s != sc.trajectory.duration_s) return;
      static const QRegularExpression re(QStringLiteral("(^trajectory:\\n(?: .*\\n)*?  duration_s: )[^\\n]*"),
                                         QRegularExpression::MultilineOption);
      *canon = QString::fromUtf8(*canon).replace(re, QStringLiteral("\\1auto")).toUtf8();
    };
    autoify(&canon_old, *user_scene_);
    autoify(&canon_new_auto, *scene_);
  }
  if (canon_old == canon_new_auto) {
    if (note) *note = tr("unchanged: the file's text is kept as it is");
    return user_text_;
  }
  const QByteArray display = QFile::encodeName(path_.isEmpty() ? QStringLiteral("scene.yaml") : path_);
  for (MergeLevel level : {MergeLevel::Fine, MergeLevel::Sections}) {
    QString replaced;
    const QByteArray merged = MergeSceneText(user_text_, canon_old, canon_new_auto, level, &replaced);
    if (merged.isEmpty()) continue;
    // What the user wrote and what the program writes must load identically: the merged text
    // must read back to exactly the scene the writer's text describes.
    auto back = std::make_unique<nav_scene>();
    if (nav_scene_read_string(merged.constData(), static_cast<size_t>(merged.size()), display.constData(), back.get(),
                              nullptr, nullptr) != NAV_OK)
      continue;
    Normalize(back.get());
    const bool same = CanonicalText(*back) == canon_new;
    nav_scene_release(back.get()); // a temporary read-back
    if (!same) continue;
    if (note)
      *note = replaced.isEmpty() ? tr("comments and layout kept")
                                 : tr("comments and layout kept except where rewritten: %1").arg(replaced);
    return merged;
  }
  if (note) *note = tr("written by navcore's writer: the changes could not be placed into the file's text (comments lost)");
  return canon_new;
}

bool SceneDocument::Save(const QString &path, QString *error) {
  QString note;
  const QString abs = QFileInfo(path).absoluteFilePath();
  // A save to another file still starts from the text the document was loaded from.
  const QByteArray text = SaveText(&note);
  if (text.isEmpty()) {
    if (error) *error = QStringLiteral("%1: error: cannot write the scene (the writer failed)").arg(path);
    return false;
  }
  if (!WriteAtomically(abs, text, error)) return false;
  save_note_ = note;
  user_text_ = text;
  user_scene_ = std::make_unique<nav_scene>(*scene_);
  path_ = abs;
  undo_.setClean();
  emit FileStateChanged();
  return true;
}

bool SceneDocument::WriteCopy(const QString &path, QString *error) const {
  // navcore's writer's text, through the same atomic write as Save() (and its test hook).
  const QByteArray text = CanonicalText(*scene_);
  if (text.isEmpty()) {
    if (error) *error = QStringLiteral("%1: error: cannot write the scene (the writer failed)").arg(path);
    return false;
  }
  return WriteAtomically(QFileInfo(path).absoluteFilePath(), text, error);
}

} // namespace studio
