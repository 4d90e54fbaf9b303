/*
 * navsim import FILE --out SCENE.yaml: GPX / KML tracks and gnss-ins-sim motion definitions as
 * scene trajectories.
 * navsim export RESULT_DIR --kml --csv: tracks.kml / tracks.csv of a result directory.
 * navsim run --kml: the same inside the run's (temporary) result directory.
 */
#define _POSIX_C_SOURCE 200809L

#include "cli_util.h"
#include "import_cmd.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navcore/nav_frames.h"
#include "navcore/nav_io.h"
#include "navcore/nav_motiondef.h"
#include "navcore/nav_track_import.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };

static const char *k_usage_import =
    "usage: navsim import FILE --out SCENE.yaml [--speed M/S] [--name NAME] [--tolerance M] [--no-time]\n"
    "                     [--no-merge] [--track NAME|INDEX] [--format gpx|kml|motion_def] [--template SCENE] "
    "[--aircraft]\n"
    "                     [--accept-distance] [--stop-speed M/S] [--stop-min S]\n"
    "\n"
    "Turn a track into a scene trajectory and write a complete scene file:\n"
    "  GPX (.gpx)   <trk>/<trkseg>/<trkpt lat lon> with <ele> and <time> (or <rtept>)\n"
    "  KML (.kml)   a Placemark's <LineString> or <gx:Track> (when/coord); every one is a track\n"
    "  CSV (.csv)   a gnss-ins-sim motion definition (segment script)\n"
    "GPX/KML tracks become waypoint trajectories on WGS-84 with the origin at the first point: the\n"
    "track is thinned (Douglas-Peucker, --tolerance, default 5 m) and flown through its points at\n"
    "the track's speeds (from its times) when every point has a time, else at --speed (default\n"
    "10 m/s).\n"
    "The path flies by the interior waypoints with smooth turns within the limits of the scene\n"
    "defaults (or --template). A turn that does not fit its legs (a dense curve thinned to short\n"
    "chords) is merged with its neighbour into the corner where their outer legs meet, so the turn\n"
    "there follows the curve; the largest distance of a track point from the flown path is printed.\n"
    "Turns that stay infeasible are reported at the track point (FILE:LINE:COL), exit 2.\n"
    "\n"
    "options:\n"
    "  --out FILE       scene file to write (atomically)\n"
    "  --speed M/S      speed at every waypoint for untimed tracks (or with --no-time)\n"
    "  --name NAME      scene name (default: the track's name, else the file name)\n"
    "  --tolerance M    thinning tolerance in metres (0: keep every distinct point), and the largest\n"
    "                   distance of a track point from the flown path (1 m with 0): beyond it the track\n"
    "                   is thinned more finely, and a plan that still strays is refused (exit 2, where\n"
    "                   and what to change)\n"
    "  --accept-distance  write the scene even when the flown path strays beyond --tolerance\n"
    "  --no-merge       report the first infeasible turn instead of merging turns\n"
    "  --no-time        ignore the track's times; fly it at --speed\n"
    "  --stop-speed M/S, --stop-min S  stops of a timed track: where the speed between consecutive\n"
    "                   points stays below --stop-speed (default 0.2 m/s) for at least --stop-min\n"
    "                   (default 3 s; 0: no stops), the vehicle stops at the first of those points for\n"
    "                   that long (hold_start_s, hold_s, hold_end_s); each part between stops is timed\n"
    "                   to take the track's time, so the scene lasts as long as the track\n"
    "  --track NAME|INDEX  KML: the track (LineString / gx:Track) of the Placemark with this name, or\n"
    "                   the INDEX-th of the file (1-based); a file with several needs it (they are listed)\n"
    "  --format F       gpx, kml or motion_def (default: from the extension or content)\n"
    "  --template SCENE take IMU, GNSS, navigation, output and simulation from SCENE\n"
    "  --aircraft       aircraft attitude (coordinated bank in turns) instead of ground\n"
    "\n"
    "exit codes: 0 written; 2 invalid file or options; 1 I/O failure\n";

static void base_name(char *out, size_t cap, const char *path) {
  const char *b = strrchr(path, '/');
  b = b ? b + 1 : path;
  snprintf(out, cap, "%s", b);
  char *dot = strrchr(out, '.');
  if (dot && dot != out) *dot = '\0';
}

/* Diagnostics of the scene an import would write, placed in the input file: a problem of
 * waypoint i at the track point nearest to it (waypoints are track points, or corners between
 * two of them), anything else at the file as a whole. */
typedef struct import_check {
  const char *in;
  const nav_geotrack *track; /* NULL for a motion definition */
  const nav_scene *scene;
  int count;
} import_check;

static void import_diag(void *user, const nav_diag *d) {
  import_check *c = user;
  c->count++;
  int wp = -1;
  if (c->track && c->track->count > 0 && sscanf(d->path, "trajectory.waypoints.points[%d]", &wp) == 1 && wp >= 0 &&
      wp < c->scene->trajectory.waypoints.count) {
    const nav_frame fr = nav_frame_from_scene(c->scene);
    const nav_vec3 w = c->scene->trajectory.waypoints.points[wp].r_ned_m;
    size_t best = 0;
    double best_d = INFINITY;
    for (size_t i = 0; i < c->track->count; ++i) {
      const double dist = nav_vec3_norm(nav_vec3_sub(nav_frame_geodetic_to_local(&fr, c->track->points[i].pos), w));
      if (dist < best_d) {
        best_d = dist;
        best = i;
      }
    }
    fprintf(stderr, "%s:%d:%d: error: %s: %s (in the scene this track gives: waypoint %d, at track point %zu)\n", c->in,
            c->track->points[best].line, c->track->points[best].col, d->path, d->message, wp, best + 1);
    return;
  }
  fprintf(stderr, "%s: error: %s%s%s (in the scene this %s gives)\n", c->in, d->path, d->path[0] ? ": " : "",
          d->message, c->track ? "track" : "motion definition");
}

/* The scene as it would be written, read back from memory with every check of navsim check.
 * @return 0, 2 (problems printed, placed in the input file) or 1. */
static int validate_import(const char *in, const char *out, const nav_geotrack *track, const nav_scene *sc) {
  char *text = NULL;
  size_t len = 0;
  nav_status st = nav_scene_write_string(sc, &text, &len);
  nav_scene *back = st == NAV_OK ? malloc(sizeof *back) : NULL;
  if (st == NAV_OK && back == NULL) st = NAV_ERR_NO_MEMORY;
  import_check c = {in, track, sc, 0};
  if (st == NAV_OK) st = nav_scene_read_string(text, len, out, back, import_diag, &c);
  free(text);
  if (st == NAV_OK) nav_scene_release(back);
  free(back);
  if (st == NAV_OK) return EXIT_OK;
  if (st == NAV_ERR_PARSE) {
    fprintf(stderr, "navsim import: %s gives no valid scene (problems above); \"%s\" was not written\n", in, out);
    return EXIT_INVALID;
  }
  fprintf(stderr, "navsim import: cannot check the scene: %s; \"%s\" was not written\n", nav_status_str(st), out);
  return EXIT_FAIL;
}

/* Names that drawing tools give a path by default (Google Earth, My Maps, GPS loggers). */
static bool is_generic_name(const char *n) {
  static const char *k[] = {"tessellated", "untitled", "untitled path", "path", "line", "track", "route",
                            "linestring", "placemark", "new path", "unnamed", "default"};
  char low[128];
  size_t i = 0;
  while (*n == ' ') ++n;
  for (; n[i] && i + 1 < sizeof low; ++i) low[i] = (char)tolower((unsigned char)n[i]);
  while (i > 0 && low[i - 1] == ' ') --i;
  low[i] = '\0';
  for (size_t j = 0; j < sizeof k / sizeof k[0]; ++j)
    if (strcmp(low, k[j]) == 0) return true;
  return false;
}

int navsim_import(int argc, char **argv) {
  const char *in = NULL, *out = NULL, *name = NULL, *track_name = NULL, *fmt_s = NULL, *templ = NULL;
  nav_track_import_options opt = nav_track_import_options_default();
  bool speed_given = false, accept_distance = false;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (navsim_is_help(a)) {
      fputs(k_usage_import, stdout);
      return EXIT_OK;
    } else if (strcmp(a, "--no-merge") == 0) {
      opt.max_merges = 0;
    } else if (strcmp(a, "--no-time") == 0) {
      opt.use_time = false;
    } else if (strcmp(a, "--aircraft") == 0) {
      opt.attitude_mode = NAV_WP_ATT_AIRCRAFT;
    } else if (strcmp(a, "--accept-distance") == 0) {
      accept_distance = true;
    } else if (strcmp(a, "--out") == 0 || strcmp(a, "--speed") == 0 || strcmp(a, "--name") == 0 ||
               strcmp(a, "--tolerance") == 0 || strcmp(a, "--track") == 0 || strcmp(a, "--format") == 0 ||
               strcmp(a, "--template") == 0 || strcmp(a, "--stop-speed") == 0 ||
               strcmp(a, "--stop-min") == 0) {
      if (!navsim_need_value("import", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (strcmp(a, "--out") == 0) out = v;
      else if (strcmp(a, "--name") == 0) name = v;
      else if (strcmp(a, "--track") == 0) track_name = v;
      else if (strcmp(a, "--format") == 0) fmt_s = v;
      else if (strcmp(a, "--template") == 0) templ = v;
      else if (strcmp(a, "--speed") == 0) {
        if (!navsim_parse_positive(v, &opt.speed_mps, false) || opt.speed_mps > 1000.0) {
          fprintf(stderr, "navsim import: --speed: expected a speed in (0, 1000] m/s, got \"%s\"\n", v);
          return EXIT_INVALID;
        }
        speed_given = true;
      } else if (strcmp(a, "--stop-speed") == 0) {
        if (!navsim_parse_positive(v, &opt.stop_speed_mps, true) || opt.stop_speed_mps > 10.0) {
          fprintf(stderr, "navsim import: --stop-speed: expected a speed in [0, 10] m/s, got \"%s\"\n", v);
          return EXIT_INVALID;
        }
      } else if (strcmp(a, "--stop-min") == 0) {
        if (!navsim_parse_positive(v, &opt.stop_min_s, true) || opt.stop_min_s > 1e6) {
          fprintf(stderr, "navsim import: --stop-min: expected a duration in [0, 1e6] s, got \"%s\"\n", v);
          return EXIT_INVALID;
        }
      } else if (!navsim_parse_positive(v, &opt.tolerance_m, true) || opt.tolerance_m > 1e5) {
        fprintf(stderr, "navsim import: --tolerance: expected a distance in [0, 1e5] m, got \"%s\"\n", v);
        return EXIT_INVALID;
      }
    } else if (a[0] == '-' && a[1] != '\0') {
      return navsim_unknown_option("import", a);
    } else if (!in) {
      in = a;
    } else {
      fprintf(stderr, "navsim import: only one FILE may be given (got \"%s\" and \"%s\")\n", in, a);
      return EXIT_INVALID;
    }
  }
  if (!in || !out) {
    fprintf(stderr, "navsim import: %s\n%s", !in ? "missing FILE" : "missing --out SCENE.yaml", k_usage_import);
    return EXIT_INVALID;
  }
  nav_track_format fmt = NAV_TRACK_FORMAT_AUTO;
  if (fmt_s) {
    if (strcmp(fmt_s, "gpx") == 0) fmt = NAV_TRACK_FORMAT_GPX;
    else if (strcmp(fmt_s, "kml") == 0) fmt = NAV_TRACK_FORMAT_KML;
    else if (strcmp(fmt_s, "motion_def") == 0) fmt = NAV_TRACK_FORMAT_MOTION_DEF;
    else {
      fprintf(stderr, "navsim import: --format: expected gpx, kml or motion_def, got \"%s\"\n", fmt_s);
      return EXIT_INVALID;
    }
  }
  if (name && (strlen(name) == 0 || strlen(name) >= NAV_SCENE_NAME_MAX)) {
    fprintf(stderr, "navsim import: --name: expected 1 to %d characters\n", NAV_SCENE_NAME_MAX - 1);
    return EXIT_INVALID;
  }
  if (fmt == NAV_TRACK_FORMAT_AUTO) {
    char head[4096];
    size_t n = 0;
    FILE *f = NULL;
    char why[320];
    const nav_status open_st = nav_io_fopen_regular(in, &f, why, sizeof why);
    if (open_st != NAV_OK) { /* a FIFO, device or directory is refused at once (exit 2) */
      if (open_st == NAV_ERR_PARSE)
        fprintf(stderr, "%s: error: %s\n", in, why);
      else
        fprintf(stderr, "%s: error: cannot open: %s\n", in, strerror(errno));
      return open_st == NAV_ERR_PARSE ? EXIT_INVALID : EXIT_FAIL;
    }
    n = fread(head, 1, sizeof head, f);
    fclose(f);
    fmt = nav_track_format_guess(in, head, n);
    if (fmt == NAV_TRACK_FORMAT_AUTO) {
      fprintf(stderr, "%s:1:1: error: unknown track format: expected GPX (.gpx), KML (.kml) or a gnss-ins-sim motion "
                      "definition (.csv); use --format\n", in);
      return EXIT_INVALID;
    }
  }

  nav_scene *sc = malloc(sizeof *sc);
  if (!sc) return EXIT_FAIL;
  int rc = EXIT_OK;
  nav_geotrack tr = {0};
  navsim_diag_sink sink = {0};
  static char stray[2400]; /* the flown path strays beyond --tolerance: the message, else "" */
  stray[0] = '\0';
  if (templ) {
    const int lrc = navsim_load_scene(templ, sc);
    if (lrc != EXIT_OK) {
      free(sc);
      return lrc;
    }
    /* The import replaces the trajectory: a recorded template's fitted model is not needed (and
     * the scene copies below are plain struct copies). */
    nav_scene_release(sc);
  } else {
    *sc = nav_scene_default();
    sc->imu.rate_hz = 100.0;
    sc->output.rate_hz = 10.0;
    sc->navigation.algorithm = NAV_MECH_HIGH_ORDER;
  }
  sc->earth.model = NAV_EARTH_WGS84;
  char default_name[NAV_SCENE_NAME_MAX];
  base_name(default_name, sizeof default_name, in);

  if (fmt == NAV_TRACK_FORMAT_MOTION_DEF) {
    const nav_status st = nav_motiondef_read_file(in, sc, navsim_print_diag, &sink);
    if (st != NAV_OK) {
      if (sink.count == 0) fprintf(stderr, "%s: error: %s\n", in, nav_status_str(st));
      rc = st == NAV_ERR_IO ? EXIT_FAIL : EXIT_INVALID;
      goto done;
    }
    snprintf(sc->name, sizeof sc->name, "%s", name ? name : default_name);
    printf("imported   %s: motion definition, %d segments, %.3f s\n", in, sc->trajectory.segments.count,
           sc->trajectory.duration_s);
  } else {
    nav_geotrack_info info;
    memset(&info, 0, sizeof info);
    nav_status st = nav_geotrack_read_file_info(in, fmt, track_name, &tr, &info, navsim_print_diag, &sink);
    if (st != NAV_OK) {
      if (sink.count == 0) fprintf(stderr, "%s: error: %s\n", in, nav_status_str(st));
      rc = (st == NAV_ERR_PARSE || st == NAV_ERR_INVALID_ARG) ? EXIT_INVALID : EXIT_FAIL;
      goto done;
    }
    if (!track_name && info.tracks_in_file > 1) {
      /* Several tracks and none picked: list them instead of taking the first silently. */
      fprintf(stderr, "%s:1:1: error: the file holds %d tracks (LineString / gx:Track): %s%s; pick one with --track "
                      "NAME or --track INDEX\n", in, info.tracks_in_file, info.track_list,
              info.tracks_in_file > 64 ? "; ..." : "");
      rc = EXIT_INVALID;
      goto done;
    }
    if (!tr.all_timed && opt.use_time && !speed_given && tr.count > 0)
      fprintf(stderr, "navsim import: %s: the track has no times on every point: flown at %g m/s (--speed)\n", in,
              opt.speed_mps);
    nav_track_import_report rep;
    char msg[1024];
    /* The flown path must stay within the distance limit of every track point (issue 18): the
     * thinning tolerance, 1 m with --tolerance 0. Thinning uses part of it, the fly-by turns the
     * rest; when the plan strays beyond it, the track is thinned more finely (tolerance / 2, / 4,
     * / 8) before the import gives up, so an import that already fits is unchanged. */
    const double limit_m = opt.tolerance_m > 0.0 ? opt.tolerance_m : 1.0;
    nav_scene *base = malloc(sizeof *base);
    if (!base) {
      rc = EXIT_FAIL;
      goto done;
    }
    *base = *sc;
    nav_track_import_options o2 = opt;
    st = nav_geotrack_to_scene(&tr, &o2, sc, &rep, msg, sizeof msg);
    for (int refine = 0; refine < 3 && st == NAV_OK && rep.max_dev_m > limit_m && o2.tolerance_m > 0.0; ++refine) {
      nav_track_import_report r2;
      nav_scene *try_sc = malloc(sizeof *try_sc);
      if (!try_sc) break;
      *try_sc = *base;
      o2.tolerance_m *= 0.5;
      if (nav_geotrack_to_scene(&tr, &o2, try_sc, &r2, msg, sizeof msg) == NAV_OK && r2.max_dev_m < rep.max_dev_m) {
        *sc = *try_sc;
        rep = r2;
      }
      free(try_sc);
    }
    free(base);
    if (st != NAV_OK) {
      const char *hint = tr.all_timed && opt.use_time
                             ? "; use a larger --tolerance, or --no-time with a lower --speed"
                             : "; use a larger --tolerance or a lower --speed";
      if (rep.bad_point >= 0 && (size_t)rep.bad_point < tr.count)
        fprintf(stderr, "%s:%d:%d: error: trajectory.waypoints: %s%s\n", in, tr.points[rep.bad_point].line,
                tr.points[rep.bad_point].col, msg, hint);
      else
        fprintf(stderr, "%s: error: trajectory.waypoints: %s%s\n", in, msg[0] ? msg : nav_status_str(st), hint);
      rc = st == NAV_ERR_NO_MEMORY ? EXIT_FAIL : EXIT_INVALID;
      goto done;
    }
    if (rep.max_dev_m > limit_m && !accept_distance) {
      /* Where the plan strays, and what to change; reported after the scene's own checks (a scene
       * that is not valid is refused for that first), and nothing is written. */
      const long w = rep.max_dev_point;
      const bool where = w >= 0 && (size_t)w < tr.count;
      char at[160] = "", loc[600];
      if (where && tr.points[w].has_time && tr.points[0].has_time)
        snprintf(at, sizeof at, ", %.1f s into the track", tr.points[w].t_s - tr.points[0].t_s);
      if (where) snprintf(loc, sizeof loc, "%s:%d:%d", in, tr.points[w].line, tr.points[w].col);
      else snprintf(loc, sizeof loc, "%s", in);
      snprintf(stray, sizeof stray,
               "%s: error: the planned path passes %.2f m from this track point%s, beyond --tolerance %g m: the "
               "vehicle cannot follow the track there within the planner's limits at its speed. Lower the speed "
               "(--speed, or --no-time with a lower --speed), keep the track's stops and times (a timed GPX/KML, "
               "without --no-time), raise the limits (--template with larger trajectory.waypoints.limits), or "
               "accept the distance with --accept-distance; \"%s\" was not written\n",
               loc, rep.max_dev_m, at, limit_m, out);
    }
    if (o2.tolerance_m != opt.tolerance_m)
      printf("refined    thinned with %g m instead of %g m to keep the flown path within %g m of the track\n",
             o2.tolerance_m, opt.tolerance_m, limit_m);
    /* A generic placemark name ("Tessellated", "Untitled", "Path", ...) names nothing: the file's
     * name does (issue 18). */
    const bool generic = tr.name[0] == '\0' || is_generic_name(tr.name);
    snprintf(sc->name, sizeof sc->name, "%s", name ? name : (!generic ? tr.name : default_name));
    for (char *p = sc->name; *p; ++p)
      if ((unsigned char)*p < 0x20) *p = ' ';
    printf("imported   %s: %zu points -> %d waypoints (tolerance %g m, %d turn%s merged), %.1f m, %s, %.3f s; "
           "largest distance of a track point from the flown path %.2f m\n",
           in, rep.points_in, rep.waypoints, opt.tolerance_m, rep.merged, rep.merged == 1 ? "" : "s", rep.length_m,
           rep.timed ? "speeds from the track's times" : "constant speed", rep.duration_s, rep.max_dev_m);
    if (rep.timed) {
      printf("stops      %d (%.1f s at rest: speed below %g m/s for at least %g s); duration %.3f s, the "
             "track's "
             "%.3f s\n",
             rep.stops, rep.stop_s, opt.stop_speed_mps, opt.stop_min_s, rep.duration_s, rep.track_duration_s);
      if (rep.stops_lengthened > 0)
        printf("note       %d stop%s held longer than on the track, to turn in place at a corner within the "
               "limits\n",
               rep.stops_lengthened, rep.stops_lengthened == 1 ? "" : "s");
    }
  }
  /* Nothing is written, and no existing scene replaced, unless the scene is valid. */
  rc = validate_import(in, out, fmt == NAV_TRACK_FORMAT_MOTION_DEF ? NULL : &tr, sc);
  if (rc != EXIT_OK) goto done;
  if (stray[0] != '\0') {
    fputs(stray, stderr);
    rc = EXIT_INVALID;
    goto done;
  }
  {
    const nav_status st = nav_scene_write_file(out, sc);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim import: cannot write \"%s\": %s\n", out, nav_status_str(st));
      rc = EXIT_FAIL;
      goto done;
    }
    /* The written file must read back as a valid scene. */
    navsim_diag_sink s2 = {0};
    const nav_status st2 = nav_scene_read_file(out, sc, navsim_print_diag, &s2);
    if (st2 != NAV_OK) {
      fprintf(stderr, "navsim import: the written scene \"%s\" does not read back: %s\n", out, nav_status_str(st2));
      rc = EXIT_FAIL;
      goto done;
    }
    printf("scene      %s (%s)\n", out, sc->name);
  }
done:
  nav_geotrack_free(&tr);
  nav_scene_release(sc); /* what the read-back check read */
  free(sc);
  return rc;
}

/* ------------------------------------------------------------------------------ export */

typedef struct geo_series {
  double *t;
  nav_geodetic *p;
  size_t n, cap;
  int last_line; /* line of the last data row */
} geo_series;

static void series_free(geo_series *s) {
  free(s->t);
  free(s->p);
  memset(s, 0, sizeof *s);
}

static bool series_push(geo_series *s, double t, nav_geodetic p) {
  if (s->n == s->cap) {
    const size_t cap = s->cap ? 2 * s->cap : 1024;
    double *t2 = realloc(s->t, cap * sizeof *t2);
    if (!t2) return false;
    s->t = t2;
    nav_geodetic *p2 = realloc(s->p, cap * sizeof *p2);
    if (!p2) return false;
    s->p = p2;
    s->cap = cap;
  }
  s->t[s->n] = t;
  s->p[s->n] = p;
  s->n++;
  return true;
}

/* Read t_s, lat_deg, lon_deg, h_m from a CSV with a header (truth.csv, nav.csv, gnss.csv).
 * Returns 0, 1 (cannot read), 2 (malformed: FILE:LINE:COL printed). */
static int read_geo_csv(const char *path, geo_series *s, bool need_rows) {
  FILE *f = NULL;
  char why[320];
  const nav_status open_st = nav_io_fopen_regular(path, &f, why, sizeof why);
  if (open_st == NAV_ERR_PARSE) { /* a FIFO, device or directory: refused at once */
    fprintf(stderr, "%s: error: %s\n", path, why);
    return 2;
  }
  if (!f) return 1;
  struct stat sb;
  if (fstat(fileno(f), &sb) == 0 && !S_ISREG(sb.st_mode)) {
    fprintf(stderr, "%s: error: not a regular file (%s); expected the CSV file navsim writes there\n", path,
            S_ISDIR(sb.st_mode) ? "a directory" : "a device, FIFO or socket");
    fclose(f);
    return 2;
  }
  char *line = NULL;
  size_t cap = 0;
  ssize_t len;
  int col_idx[4] = {-1, -1, -1, -1};
  static const char *names[4] = {"t_s", "lat_deg", "lon_deg", "h_m"};
  int ln = 0, rc = 0;
  bool line_end = true; /* the last line read ended with '\n' */
  int last_len = 0;      /* its length without the line end */
  while ((len = getline(&line, &cap, f)) >= 0) {
    ++ln;
    line_end = len > 0 && line[len - 1] == '\n';
    while (len > 0 && (line[len - 1] == '\n' || line[len - 1] == '\r')) line[--len] = '\0';
    last_len = (int)len;
    if (ln == 1) {
      int c = 0;
      for (char *tok = line, *next; tok; tok = next, ++c) {
        next = strchr(tok, ',');
        if (next) *next++ = '\0';
        for (int k = 0; k < 4; ++k)
          if (strcmp(tok, names[k]) == 0) col_idx[k] = c;
      }
      for (int k = 0; k < 4; ++k)
        if (col_idx[k] < 0) {
          fprintf(stderr, "%s:1:1: error: header: expected a column %s\n", path, names[k]);
          rc = 2;
        }
      if (rc) break;
      continue;
    }
    if (len == 0) continue;
    double v[4] = {NAN, NAN, NAN, NAN};
    int c = 0;
    char *p = line;
    for (;;) {
      char *comma = strchr(p, ',');
      for (int k = 0; k < 4; ++k)
        if (col_idx[k] == c) {
          char *end = NULL;
          v[k] = strtod(p, &end);
          if (end == p || (end && *end != ',' && *end != '\0') || !isfinite(v[k])) {
            fprintf(stderr, "%s:%d:%d: error: %s: expected a finite number\n", path, ln, (int)(p - line) + 1, names[k]);
            rc = 2;
          }
        }
      if (!comma || rc) break;
      p = comma + 1;
      ++c;
    }
    if (rc) break;
    for (int k = 0; k < 4; ++k)
      if (isnan(v[k])) {
        fprintf(stderr, "%s:%d:%d: error: %s: missing column\n", path, ln, (int)len + 1, names[k]);
        rc = 2;
      }
    if (rc) break;
    if (!series_push(s, v[0], (nav_geodetic){v[1] * NAV_DEG2RAD, v[2] * NAV_DEG2RAD, v[3]})) {
      rc = 1;
      break;
    }
    s->last_line = ln;
  }
  const int read_err = ferror(f) ? errno : 0;
  free(line);
  fclose(f);
  /* navsim writes whole lines: a last line without its end, or no row at all, is a cut file
   * whose track would be drawn shortened (or not at all) without a word. */
  if (rc == 0 && read_err) {
    fprintf(stderr, "%s: error: cannot read: %s\n", path, strerror(read_err));
    rc = 1;
  } else if (rc == 0 && ln == 0) {
    fprintf(stderr, "%s: error: the file is empty; expected a header line (t_s,lat_deg,lon_deg,h_m,...) and rows\n",
            path);
    rc = 2;
  } else if (rc == 0 && !line_end) {
    fprintf(stderr, "%s:%d:%d: error: the last line has no line end: the file was cut short (navsim writes whole lines)\n",
            path, ln, last_len + 1);
    rc = 2;
  } else if (rc == 0 && need_rows && s->n == 0) {
    fprintf(stderr, "%s:%d:1: error: no data row after the header: the file was cut short\n", path, ln);
    rc = 2;
  }
  return rc;
}

/* final.t_s of the directory's summary.json (the last epoch of the run), NaN when unknown. */
static double summary_final_t(const char *path) {
  if (!path) return NAN;
  FILE *f = fopen(path, "r");
  if (!f) return NAN;
  char buf[8192];
  const size_t n = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[n] = '\0';
  const char *p = strstr(buf, "\"final\": {\"t_s\": ");
  if (!p) return NAN;
  char *end = NULL;
  const double t = strtod(p + strlen("\"final\": {\"t_s\": "), &end);
  return end && end != p && isfinite(t) ? t : NAN;
}

/* A track that ends before the run's last epoch by more than 1.5 of its own row spacing. */
static int check_track_end(const char *path, const geo_series *s, double t_final) {
  if (!path || s->n == 0 || !isfinite(t_final)) return 0;
  const double t_last = s->t[s->n - 1];
  const double dt = s->n > 1 ? s->t[s->n - 1] - s->t[s->n - 2] : 0.0;
  if (t_last >= t_final - 1.5 * dt - 1e-9 * fmax(1.0, fabs(t_final))) return 0;
  fprintf(stderr,
          "%s:%d: error: the track ends at t = %.9g s but the run ends at %.9g s (summary.json final.t_s): the file "
          "was cut short\n",
          path, s->last_line, t_last, t_final);
  return 2;
}

/* Write tracks.kml / tracks.csv of a directory (files named by @p file_of). */
typedef const char *(*file_fn)(void *ctx, const char *name);

static int write_tracks(file_fn file_of, void *ctx, const char *label, bool kml, bool csv) {
  geo_series ref = {0}, est = {0}, gnss = {0};
  int rc = 0;
  const double t_final = summary_final_t(file_of(ctx, "summary.json"));
  const char *path = file_of(ctx, "truth.csv");
  int r = path ? read_geo_csv(path, &ref, true) : 1;
  if (r == 1) fprintf(stderr, "navsim: cannot read %s\n", path ? path : "truth.csv");
  if (r == 0) r = check_track_end(path, &ref, t_final);
  if (r) rc = r;
  path = file_of(ctx, "nav.csv");
  r = (rc == 0 && path) ? read_geo_csv(path, &est, true) : rc ? rc : 1;
  if (r == 1 && rc == 0) fprintf(stderr, "navsim: cannot read %s\n", path ? path : "nav.csv");
  if (r == 0) r = check_track_end(path, &est, t_final);
  if (r && !rc) rc = r;
  if (!rc) {
    path = file_of(ctx, "gnss.csv");
    struct stat probe;
    if (path && stat(path, &probe) == 0) {
      rc = read_geo_csv(path, &gnss, false); /* 2 for a FIFO, device or directory, as for truth.csv */
      if (rc == 1) rc = 0;            /* present but unreadable: no GNSS track, as before */
    }
  }
  if (!rc) {
    nav_kml_track t[3];
    size_t nt = 0;
    t[nt++] = (nav_kml_track){"reference", "ff00ff00", 3.0, false, ref.t, ref.p, ref.n};
    t[nt++] = (nav_kml_track){"estimate (run 0)", "ff0000ff", 2.0, false, est.t, est.p, est.n};
    if (gnss.n > 0) t[nt++] = (nav_kml_track){"GNSS fixes (run 0)", "ff00ffff", 1.0, true, gnss.t, gnss.p, gnss.n};
    if (kml) {
      const char *kp = file_of(ctx, "tracks.kml");
      const nav_status st = kp ? nav_kml_write_file(kp, label, t, nt, 20000) : NAV_ERR_INVALID_ARG;
      if (st != NAV_OK) {
        fprintf(stderr, "navsim: writing tracks.kml failed: %s\n", nav_status_str(st));
        rc = 1;
      }
    }
    if (csv && !rc) {
      const char *cp = file_of(ctx, "tracks.csv");
      const nav_status st = cp ? nav_tracks_csv_write_file(cp, t, nt) : NAV_ERR_INVALID_ARG;
      if (st != NAV_OK) {
        fprintf(stderr, "navsim: writing tracks.csv failed: %s\n", nav_status_str(st));
        rc = 1;
      }
    }
  }
  series_free(&ref);
  series_free(&est);
  series_free(&gnss);
  return rc;
}

static const char *rd_file(void *ctx, const char *name) { return nav_resultdir_file((nav_resultdir *)ctx, name); }

/* The document name of a result directory's tracks: its last path component. */
static const char *dir_label(const char *dir) {
  static char buf[512];
  snprintf(buf, sizeof buf, "%s", dir);
  size_t n = strlen(buf);
  while (n > 1 && buf[n - 1] == '/') buf[--n] = '\0';
  const char *slash = strrchr(buf, '/');
  return (slash && slash[1]) ? slash + 1 : buf;
}

int navsim_run_tracks(nav_resultdir *rd, const char *out_dir) {
  /* gnss.csv (the receiver's fixes of run 0, INS/GNSS scenes) is already in the directory. */
  return write_tracks(rd_file, rd, dir_label(out_dir), true, true) ? 1 : 0;
}

static const char *k_usage_export =
    "usage: navsim export RESULT_DIR [--kml] [--csv]\n"
    "\n"
    "Write the tracks of a result directory of navsim run: the reference (truth.csv), the\n"
    "estimate of run 0 (nav.csv) and, when present, the GNSS fixes of run 0 (gnss.csv, written by\n"
    "navsim run --kml) as\n"
    "  tracks.kml  KML 2.2 for Google Earth: reference (green line), estimate (red line), GNSS\n"
    "              fixes (yellow points); lines thinned to at most 20000 vertices\n"
    "  tracks.csv  track,t_s,lat_deg,lon_deg,h_m (every point)\n"
    "Without --kml or --csv both are written. Files are replaced atomically.\n"
    "\n"
    "exit codes: 0 written; 2 invalid options or malformed files; 1 unreadable directory or I/O failure\n";

typedef struct dir_ctx {
  const char *dir;
  char buf[4200];
} dir_ctx;

static const char *dir_file(void *ctx, const char *name) {
  dir_ctx *d = ctx;
  const int n = snprintf(d->buf, sizeof d->buf, "%s/%s", d->dir, name);
  return (n < 0 || n >= (int)sizeof d->buf) ? NULL : d->buf;
}

int navsim_export(int argc, char **argv) {
  const char *dir = NULL;
  bool kml = false, csv = false;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (navsim_is_help(a)) {
      fputs(k_usage_export, stdout);
      return EXIT_OK;
    } else if (strcmp(a, "--kml") == 0) {
      kml = true;
    } else if (strcmp(a, "--csv") == 0) {
      csv = true;
    } else if (a[0] == '-' && a[1] != '\0') {
      return navsim_unknown_option("export", a);
    } else if (!dir) {
      dir = a;
    } else {
      fprintf(stderr, "navsim export: only one RESULT_DIR may be given\n");
      return EXIT_INVALID;
    }
  }
  if (!dir) {
    fprintf(stderr, "navsim export: missing RESULT_DIR\n%s", k_usage_export);
    return EXIT_INVALID;
  }
  if (!kml && !csv) kml = csv = true;
  dir_ctx ctx = {dir, ""};
  const int rc = write_tracks(dir_file, &ctx, dir_label(dir), kml, csv);
  if (rc == 0) {
    /* Listed in the result directory's manifest, so that a later run may still replace it. */
    if (kml) (void)nav_resultdir_record(dir, "tracks.kml");
    if (csv) (void)nav_resultdir_record(dir, "tracks.csv");
    if (kml) printf("written    %s/tracks.kml\n", dir);
    if (csv) printf("written    %s/tracks.csv\n", dir);
  }
  return rc;
}
