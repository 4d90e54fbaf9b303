/*
 * navstudio: File > Import track... through navcore_io's importers (nav_track_import.h,
 * nav_motiondef.h), as `navsim import` uses them: GPX and KML tracks become a waypoint trajectory
 * (WGS-84, origin at the first point), a gnss-ins-sim motion definition a segment script.
 * Diagnostics are FILE:LINE:COL: error: ... lines.
 */
#ifndef NAVSTUDIO_TRACK_IMPORT_H
#define NAVSTUDIO_TRACK_IMPORT_H

#include <QString>
#include <QStringList>

extern "C" {
#include "navcore/nav_scene.h"
}

namespace studio {

/** Replace the trajectory of @p s (a copy the caller owns) by the track in @p path (format from
 *  the extension or the content). @return false with @p errors; @p summary says what was read. */
bool ImportTrackInto(const QString &path, nav_scene *s, QStringList *errors, QString *summary);

} // namespace studio

#endif
