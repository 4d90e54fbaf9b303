#include "track_import.h"

#include <QFile>
#include <QObject>

#include <cstring>

extern "C" {
#include "navcore/nav_motiondef.h"
#include "navcore/nav_track_import.h"
}

namespace studio {

namespace {
void Collect(void *user, const nav_diag *d) {
  char buf[1600];
  nav_diag_format(d, buf, sizeof buf);
  static_cast<QStringList *>(user)->append(QString::fromUtf8(buf));
}
} // namespace

bool ImportTrackInto(const QString &path, nav_scene *s, QStringList *errors, QString *summary) {
  errors->clear();
  const QByteArray p = QFile::encodeName(path);
  QFile f(path);
  if (!f.open(QIODevice::ReadOnly)) {
    errors->append(QObject::tr("%1: error: cannot open: %2").arg(path, f.errorString()));
    return false;
  }
  const QByteArray head = f.read(4096);
  f.close();
  const nav_track_format fmt = nav_track_format_guess(p.constData(), head.constData(), static_cast<size_t>(head.size()));
  if (fmt == NAV_TRACK_FORMAT_AUTO) {
    errors->append(QObject::tr("%1:1:1: error: unknown track format: expected GPX (.gpx), KML (.kml) or a "
                               "gnss-ins-sim motion definition (.csv)")
                       .arg(path));
    return false;
  }
  if (fmt == NAV_TRACK_FORMAT_MOTION_DEF) {
    const nav_status st = nav_motiondef_read_file(p.constData(), s, Collect, errors);
    if (st != NAV_OK) {
      if (errors->isEmpty()) errors->append(QStringLiteral("%1: error: %2").arg(path, nav_status_str(st)));
      return false;
    }
    *summary = QObject::tr("motion definition, %1 segments, %2 s")
                   .arg(s->trajectory.segments.count)
                   .arg(s->trajectory.duration_s, 0, 'f', 1);
    return true;
  }
  nav_geotrack tr{};
  nav_status st = nav_geotrack_read_file(p.constData(), fmt, nullptr, &tr, Collect, errors);
  if (st != NAV_OK) {
    if (errors->isEmpty()) errors->append(QStringLiteral("%1: error: %2").arg(path, nav_status_str(st)));
    return false;
  }
  nav_track_import_options opt = nav_track_import_options_default();
  // The vehicle limits of the scene being edited, when it has a waypoint trajectory.
  if (s->trajectory.type == NAV_TRAJ_WAYPOINTS && s->trajectory.waypoints.limits.max_accel_mps2 > 0.0)
    opt.limits = s->trajectory.waypoints.limits;
  nav_track_import_report rep{};
  char msg[1024] = "";
  s->earth.model = NAV_EARTH_WGS84;
  st = nav_geotrack_to_scene(&tr, &opt, s, &rep, msg, sizeof msg);
  if (st != NAV_OK) {
    const QString what = QString::fromUtf8(msg[0] ? msg : nav_status_str(st));
    if (rep.bad_point >= 0 && static_cast<size_t>(rep.bad_point) < tr.count)
      errors->append(QStringLiteral("%1:%2:%3: error: trajectory.waypoints: %4")
                         .arg(path)
                         .arg(tr.points[rep.bad_point].line)
                         .arg(tr.points[rep.bad_point].col)
                         .arg(what));
    else
      errors->append(QStringLiteral("%1: error: trajectory.waypoints: %2").arg(path, what));
    nav_geotrack_free(&tr);
    return false;
  }
  if (tr.name[0]) {
    static_assert(sizeof s->name == sizeof tr.name, "scene and track names differ in size");
    std::memcpy(s->name, tr.name, sizeof s->name);
    s->name[sizeof s->name - 1] = '\0';
    for (char *c = s->name; *c; ++c)
      if (static_cast<unsigned char>(*c) < 0x20) *c = ' ';
  }
  *summary = QObject::tr("%1 points -> %2 waypoints, %3 m, %4 s, %5")
                 .arg(rep.points_in)
                 .arg(rep.waypoints)
                 .arg(rep.length_m, 0, 'f', 0)
                 .arg(rep.duration_s, 0, 'f', 1)
                 .arg(rep.timed ? QObject::tr("speeds from the track's times") : QObject::tr("constant speed"));
  nav_geotrack_free(&tr);
  return true;
}

} // namespace studio
