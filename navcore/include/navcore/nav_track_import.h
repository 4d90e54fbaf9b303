/**
 * @file nav_track_import.h
 * @brief navcore_io: geodetic tracks in and out. GPX and KML tracks are read into a plain list of
 *        points (nav_geotrack) and turned into waypoint scene trajectories; reference, estimated
 *        and GNSS tracks are written as KML 2.2 (Google Earth) and CSV.
 *
 * Read formats (XML through expat; every problem is FILE:LINE:COL of the offending element,
 * attribute or coordinate tuple):
 *   - GPX 1.0/1.1: every <trkpt lat=".." lon=".."> of every <trk>/<trkseg> in document order,
 *     with optional <ele> [m] and <time> (ISO 8601, UTC or with an offset); <rtept> when the file
 *     has no track points.
 *   - KML 2.2: the first <Placemark> holding a <LineString> (<coordinates> "lon,lat[,alt]"
 *     tuples) or a <gx:Track> (<when> ISO 8601 times and <gx:coord> "lon lat alt"); with a
 *     name, the Placemark whose <name> equals it.
 * Heights are used as given (ellipsoidal; GPX/KML heights are nominally above the geoid, and a
 * geoid model is not part of navsim: the difference, tens of metres, is constant over a track).
 */
#ifndef NAV_TRACK_IMPORT_H
#define NAV_TRACK_IMPORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "nav_earth.h"
#include "nav_export.h"
#include "nav_io.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** One point of a geodetic track. */
typedef struct nav_geopoint {
  nav_geodetic pos; /**< latitude, longitude [rad], height [m] (0 without one) */
  double t_s;       /**< time [s] since 1970-01-01 UTC (has_time) */
  bool has_h;       /**< the file gave a height */
  bool has_time;    /**< the file gave a time */
  int line, col;    /**< where the point is in its file (1-based) */
} nav_geopoint;

/** A track read from a file. */
typedef struct nav_geotrack {
  nav_geopoint *points; /**< heap array (nav_geotrack_free) */
  size_t count;
  bool all_timed;       /**< every point has a time */
  char name[128];       /**< track / Placemark name ("" if none) */
} nav_geotrack;

/** What a track file holds besides the track read (nav_geotrack_read_file_info()). */
typedef struct nav_geotrack_info {
  /** KML: LineStrings / gx:Tracks in the file (the one read is the selected or the first); GPX 1. */
  int tracks_in_file;
  /** KML: "1 \"NAME\" (line L, N points); 2 ..." for a message listing them (cut when long). */
  char track_list[1600];
} nav_geotrack_info;

/** Input formats. */
typedef enum nav_track_format {
  NAV_TRACK_FORMAT_AUTO = 0, /**< by extension (.gpx, .kml, .csv), else by content */
  NAV_TRACK_FORMAT_GPX = 1,
  NAV_TRACK_FORMAT_KML = 2,
  NAV_TRACK_FORMAT_MOTION_DEF = 3 /**< gnss-ins-sim motion definition (nav_motiondef.h) */
} nav_track_format;

/** Format of @p path from its extension or its first bytes; NAV_TRACK_FORMAT_AUTO if unknown. */
NAV_API nav_track_format nav_track_format_guess(const char *path, const char *head, size_t head_len);

/**
 * Read a GPX or KML track.
 * @param[in]  path        file to read
 * @param[in]  format      NAV_TRACK_FORMAT_GPX / _KML / _AUTO
 * @param[in]  select_name KML: the track to read: its Placemark's name, its listed name ("NAME (k)" for
 *                         the k-th geometry of a Placemark with several) or its 1-based number
 *                         among every LineString / gx:Track of the file. NULL: the first
 *                         (out->tracks_in_file says how many there are)
 * @param[out] out         the track (written on NAV_OK; free with nav_geotrack_free)
 * @return NAV_OK; NAV_ERR_IO; NAV_ERR_PARSE (each problem reported as FILE:LINE:COL); NAV_ERR_NO_MEMORY;
 *         NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_geotrack_read_file(const char *path, nav_track_format format,
                                                        const char *select_name, nav_geotrack *out,
                                                        nav_diag_fn report, void *user);

/** As nav_geotrack_read_file(), from memory (@p display_name is FILE in the diagnostics). */
NAV_API NAV_NODISCARD nav_status nav_geotrack_read_string(const char *text, size_t len, const char *display_name,
                                                          nav_track_format format, const char *select_name,
                                                          nav_geotrack *out, nav_diag_fn report, void *user);

/** As nav_geotrack_read_file(), and @p info (may be NULL) says how many tracks the file holds. */
NAV_API NAV_NODISCARD nav_status nav_geotrack_read_file_info(const char *path, nav_track_format format,
                                                             const char *select_name, nav_geotrack *out,
                                                             nav_geotrack_info *info, nav_diag_fn report, void *user);

NAV_API void nav_geotrack_free(nav_geotrack *t);

/** How a track becomes a waypoint trajectory. */
typedef struct nav_track_import_options {
  /** Speed [m/s] at every waypoint when the track has no times (or use_time is false); > 0. */
  double speed_mps;
  /** Thinning: Douglas-Peucker tolerance [m] (3-D, local NED); points closer than this to the
   *  simplified polyline are dropped. 0 keeps every point except duplicates. */
  double tolerance_m;
  /** Most turns merged to make the plan feasible (default 1000; 0: report the first infeasible
   *  turn). A turn that does not fit its legs (a dense curve thinned to short chords) is merged with
   *  its neighbour into the corner where their outer legs meet, so the fly-by turn there follows
   *  the curve; without such a corner (a turn of 180 deg or more) the waypoint is dropped. */
  int max_merges;
  /** Use the track's times: each kept waypoint gets the track's speed there (path length over
   *  time across its two neighbours on each side; at least 0.5 m/s inside the track). The
   *  waypoint model's speed timing is used, so a track whose fly-by turns shorten the path stays
   *  feasible; the planned duration is close to, not equal to, the track's. */
  bool use_time;
  nav_wp_attitude_mode attitude_mode; /**< ground (default) or aircraft */
  nav_traj_limits limits;             /**< planner limits (default: those of nav_scene_default) */
  /** Stops of a timed track (use_time): a run of consecutive points whose point-to-point speeds
   *  are all below stop_speed_mps [m/s] (default 0.2) and that lasts at least stop_min_s [s]
   *  (default 3) becomes a stop: a waypoint with speed 0 at the run's first point, held for the
   *  run's duration (hold_start_s / hold_end_s at the ends of the track, hold_s inside). Each
   *  part between stops is then timed to take the track's time (its speeds scaled), so the
   *  planned duration follows the track's. stop_min_s 0: no stops are detected. */
  double stop_speed_mps;
  double stop_min_s;
} nav_track_import_options;

NAV_API nav_track_import_options nav_track_import_options_default(void);

/** What nav_geotrack_to_scene() did. */
typedef struct nav_track_import_report {
  size_t points_in;    /**< points of the track */
  int waypoints;       /**< waypoints kept */
  int merged;          /**< turns merged (or dropped) to make the plan feasible */
  double max_dev_m;    /**< largest distance of a track point from the flown path (sampled every 0.1 s;
                            at most 20000 track points, evenly spaced, the last included) [m] */
  double length_m;     /**< length of the kept polyline [m] */
  double duration_s;   /**< length of the planned trajectory [s] */
  long max_dev_point;  /**< index of the track point at max_dev_m (-1: none checked) */
  bool timed;          /**< the speeds came from the track's times */
  int bad_point;       /**< on an infeasible plan: index into the track's points, else -1 */
  int stops;           /**< stops kept (timed tracks), the start and the end included */
  double stop_s;       /**< their total duration [s] (holds of the trajectory) */
  double track_duration_s; /**< timed tracks: last time minus first time [s], else 0 */
  int stops_lengthened;    /**< stops held longer than on the track: too short to turn in place
                                at a corner within the angular limits (the part after such a
                                stop is timed to arrive when the track does) */
} nav_track_import_report;

/**
 * Replace the trajectory of @p scene by a waypoint trajectory through the (thinned) track: Earth
 * model WGS-84 with its origin at the first point, waypoints in local curvilinear NED, the first
 * waypoint's speed from the track's times or speed_mps, duration from the planned script.
 * Thinning never drops the first or the last point. The result is planned; while it is
 * infeasible, turns are merged (max_merges). A plan that stays infeasible is an error whose
 * message names the waypoint and the limit, and rep->bad_point the track point.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (fewer than 2 distinct points, bad options, infeasible plan:
 *         @p msg says why, rep->bad_point where); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_geotrack_to_scene(const nav_geotrack *track, const nav_track_import_options *opt,
                                                       nav_scene *scene, nav_track_import_report *rep, char *msg,
                                                       size_t msg_size);

/* ---------------------------------------------------------------------------- KML / CSV export */

/** One track to export. */
typedef struct nav_kml_track {
  const char *name;        /**< Placemark name ("reference", "estimate (run 0)", "GNSS fixes") */
  const char *color_abgr;  /**< KML colour aabbggrr, e.g. "ff0000ff" (red) */
  double width;            /**< line width [px] */
  bool as_points;          /**< points (a folder of point Placemarks, thinned to max_points) instead of a line */
  const double *t_s;       /**< times [s] from the scene epoch (count values; may be NULL) */
  const nav_geodetic *pos; /**< positions */
  size_t count;
} nav_kml_track;

/**
 * Write a KML 2.2 document with one Placemark per track (LineString with absolute heights, or
 * points), atomically (temporary file + rename). Lines are thinned to at most @p max_points
 * vertices (every k-th, the last always kept); coordinates have 9 decimals of a degree (0.1 mm)
 * and heights 4 decimals; points are named by their time.
 * @return NAV_OK, NAV_ERR_IO, NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_kml_write_file(const char *path, const char *doc_name, const nav_kml_track *tracks,
                                                    size_t n_tracks, size_t max_points);

/** Write the tracks as one CSV (track,t_s,lat_deg,lon_deg,h_m; all points), atomically. */
NAV_API NAV_NODISCARD nav_status nav_tracks_csv_write_file(const char *path, const nav_kml_track *tracks,
                                                           size_t n_tracks);

NAV_END_DECLS

#endif /* NAV_TRACK_IMPORT_H */
