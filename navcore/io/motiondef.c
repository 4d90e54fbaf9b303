/*
 * gnss-ins-sim motion-definition files (motion_def*.csv) -> segment scripts (nav_motiondef.h).
 *
 * Parsing is strict and reports every malformed line as FILE:LINE:COL with the scene field path
 * it would have filled. Numbers are read in the C locale (a GUI process may have set another
 * LC_NUMERIC). After parsing, the script is planned once (segments.c) to reject commands the
 * limits cannot execute and to measure the script's length, which becomes
 * trajectory.duration_s.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_motiondef.h"
#include "scene_io_internal.h"
#include "navcore/nav_traj.h"

#define MD_MAX_FIELDS 16
#define MD_COLUMNS 9

/* gnss-ins-sim's "high_mobility" (ins_sim.py: max acceleration 1.0 m/s^2, max angular
 * acceleration 0.5 rad/s^2, max angular rate 2.0 rad/s), with the jerk limits of the segment
 * defaults of nav_scene_default() (gnss-ins-sim has none; its accelerations step). */
static nav_traj_limits high_mobility(void) {
  nav_traj_limits L;
  L.max_accel_mps2 = 1.0;
  L.max_jerk_mps3 = 2.0;
  L.max_lateral_accel_mps2 = 10.0;
  L.max_rate_rps = 2.0;
  L.max_ang_accel_rps2 = 0.5;
  L.max_ang_jerk_rps3 = 2.0;
  return L;
}

typedef struct md_reader {
  const char *file;
  nav_diag_fn report;
  void *user;
  int ndiag;
} md_reader;

static void diag(md_reader *r, int line, int col, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
static void diag(md_reader *r, int line, int col, const char *path, const char *fmt, ...) {
  if (r->ndiag >= NAV_DIAG_MAX_PER_FILE) return;
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", r->file);
  d.line = line > 0 ? line : 0;
  d.col = line > 0 ? (col > 0 ? col : 1) : 0;
  r->ndiag++;
  if (r->ndiag == NAV_DIAG_MAX_PER_FILE) {
    d.line = d.col = 0;
    snprintf(d.message, sizeof d.message, "too many problems; stopping after the first %d",
             NAV_DIAG_MAX_PER_FILE - 1);
  } else {
    snprintf(d.path, sizeof d.path, "%s", path ? path : "");
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d.message, sizeof d.message, fmt, ap);
    va_end(ap);
  }
  if (r->report) r->report(r->user, &d);
}

typedef struct md_field {
  const char *s;
  size_t len;
  int col;
} md_field;

/* Split one line (without its end-of-line) at commas; fields are trimmed of blanks. */
static int split(const char *line, size_t len, md_field *f, int max) {
  int n = 0;
  size_t i = 0;
  for (;;) {
    size_t a = i;
    while (a < len && line[a] != ',' && (line[a] == ' ' || line[a] == '\t'))
      ++a;
    size_t b = a;
    while (b < len && line[b] != ',')
      ++b;
    size_t e = b;
    while (e > a && (line[e - 1] == ' ' || line[e - 1] == '\t'))
      --e;
    if (n < max) {
      f[n].s = line + a;
      f[n].len = e - a;
      f[n].col = (int)a + 1;
    }
    ++n;
    if (b >= len) break;
    i = b + 1;
  }
  return n;
}

/* A whole field as a finite number. */
static bool parse_number(const md_field *f, double *out) {
  char buf[128];
  if (f->len == 0 || f->len >= sizeof buf) return false;
  memcpy(buf, f->s, f->len);
  buf[f->len] = '\0';
  char *end = NULL;
  errno = 0;
  const double v = strtod(buf, &end);
  if (end != buf + f->len || !isfinite(v)) return false;
  *out = v;
  return true;
}

static bool blank(const char *s, size_t len) {
  for (size_t i = 0; i < len; ++i)
    if (s[i] != ' ' && s[i] != '\t' && s[i] != '\r') return false;
  return true;
}

static bool contains_ci(const char *s, size_t len, const char *needle) {
  const size_t n = strlen(needle);
  for (size_t i = 0; i + n <= len; ++i)
    if (strncasecmp(s + i, needle, n) == 0) return true;
  return false;
}

static const char *const k_init_paths[MD_COLUMNS] = {"earth.origin.lat_deg",
                                                     "earth.origin.lon_deg",
                                                     "earth.origin.h_m",
                                                     "trajectory.segments.v0_b_mps[0]",
                                                     "trajectory.segments.v0_b_mps[1]",
                                                     "trajectory.segments.v0_b_mps[2]",
                                                     "trajectory.initial_attitude.yaw_deg",
                                                     "trajectory.initial_attitude.pitch_deg",
                                                     "trajectory.initial_attitude.roll_deg"};

static void command_path(char *buf, size_t size, int k, int col, bool rates) {
  static const char *const att[3] = {"yaw_rad", "pitch_rad", "roll_rad"};
  static const char *const rate[3] = {"yaw_rate_rps", "pitch_rate_rps", "roll_rate_rps"};
  const char *name = "kind";
  char tmp[32];
  if (col >= 1 && col <= 3)
    name = rates ? rate[col - 1] : att[col - 1];
  else if (col >= 4 && col <= 6) {
    snprintf(tmp, sizeof tmp, "%s[%d]", rates ? "accel_b_mps2" : "v_b_mps", col - 4);
    name = tmp;
  } else if (col == 7)
    name = "duration_s";
  else if (col == 8)
    name = "gnss_visible";
  snprintf(buf, size, "trajectory.segments.items[%d].%s", k, name);
}

static nav_status parse(md_reader *r, const char *text, size_t len, nav_scene *scene) {
  nav_scene *work = NULL;
  int *seg_line = NULL;
  nav_status st = NAV_OK;
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  work = malloc(sizeof *work);
  seg_line = calloc(NAV_MAX_SEGMENTS, sizeof *seg_line);
  if (!work || !seg_line) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  *work = *scene;
  nav_traj_segments *S = &work->trajectory.segments;
  S->count = 0;
  S->allow_unconverged = true;
  S->fit_rate_ramps = true;
  S->r0_ned_m = nav_vec3_zero();
  S->limits = high_mobility();
  work->trajectory.type = NAV_TRAJ_SEGMENTS;

  int stage = 0; /* 0: header 1, 1: initial state, 2: header 2, 3: commands */
  bool radians = false, too_many = false;
  double yaw_shift = 0.0, roll_shift = 0.0;
  int line_no = 0;
  size_t pos = 0;
  while (pos < len) {
    size_t e = pos;
    while (e < len && text[e] != '\n')
      ++e;
    const char *line = text + pos;
    size_t ll = e - pos;
    if (ll > 0 && line[ll - 1] == '\r') --ll;
    ++line_no;
    pos = e < len ? e + 1 : len;
    if (blank(line, ll)) continue;
    md_field f[MD_MAX_FIELDS];
    const int nf = split(line, ll, f, MD_MAX_FIELDS);
    double first = 0.0;
    const bool numeric = parse_number(&f[0], &first);
    if (stage == 0 || stage == 2) {
      if (numeric) {
        diag(r, line_no, 1, "",
             stage == 0
                 ? "expected the header of the initial state (\"ini lat (deg),ini lon (deg),...\"), got "
                   "numbers"
                 : "expected the header of the commands (\"command type,yaw (deg),...\"), got numbers");
        st = NAV_ERR_PARSE;
        goto cleanup;
      }
      if (stage == 2) radians = contains_ci(line, ll, "(rad)");
      ++stage;
      continue;
    }
    if (nf != MD_COLUMNS) {
      diag(r, line_no, nf > MD_COLUMNS && nf <= MD_MAX_FIELDS ? f[MD_COLUMNS].col : (int)ll + 1, "",
           "expected %d comma-separated values, found %d", MD_COLUMNS, nf);
      st = NAV_ERR_PARSE;
      if (stage == 1)
        stage = 2;
      else
        S->count++; /* keep the indices of later commands aligned with their positions */
      continue;
    }
    double v[MD_COLUMNS];
    bool ok = true;
    if (stage == 1) {
      for (int c = 0; c < MD_COLUMNS; ++c)
        if (!parse_number(&f[c], &v[c])) {
          diag(r, line_no, f[c].col, k_init_paths[c], "expected a finite number, got \"%.*s\"",
               (int)(f[c].len > 40 ? 40 : f[c].len), f[c].s);
          ok = false;
        }
      if (ok && !(fabs(v[0]) <= 90.0)) {
        diag(r, line_no, f[0].col, k_init_paths[0], "latitude must be within [-90, 90] deg (got %g)", v[0]);
        ok = false;
      }
      if (ok && !(fabs(v[7]) <= 90.0)) {
        diag(r, line_no, f[7].col, k_init_paths[7], "pitch must be within [-90, 90] deg (got %g)", v[7]);
        ok = false;
      }
      if (!ok) {
        st = NAV_ERR_PARSE;
        stage = 2;
        continue;
      }
      work->earth.origin_lat_rad = v[0] * NAV_DEG2RAD;
      work->earth.origin_lon_rad = nav_earth_wrap_lon(v[1] * NAV_DEG2RAD);
      work->earth.origin_h_m = v[2];
      S->v0_b_mps = nav_vec3_make(v[3], v[4], v[5]);
      /* Wrap yaw and roll to (-pi, pi]; absolute commands are shifted by the same amount. */
      const double yaw = v[6] * NAV_DEG2RAD, roll = v[8] * NAV_DEG2RAD;
      work->trajectory.initial_attitude.yaw_rad = nav_wrap_pi(yaw);
      work->trajectory.initial_attitude.pitch_rad = v[7] * NAV_DEG2RAD;
      work->trajectory.initial_attitude.roll_rad = nav_wrap_pi(roll);
      yaw_shift = work->trajectory.initial_attitude.yaw_rad - yaw;
      roll_shift = work->trajectory.initial_attitude.roll_rad - roll;
      stage = 2;
      continue;
    }
    /* A command. */
    const int k = S->count;
    char path[128];
    for (int c = 0; c < MD_COLUMNS; ++c)
      if (!parse_number(&f[c], &v[c])) {
        command_path(path, sizeof path, k, c, true);
        diag(r, line_no, f[c].col, path, "expected a finite number, got \"%.*s\"",
             (int)(f[c].len > 40 ? 40 : f[c].len), f[c].s);
        ok = false;
      }
    if (ok && !(v[0] == 1.0 || v[0] == 2.0 || v[0] == 3.0 || v[0] == 4.0 || v[0] == 5.0)) {
      command_path(path, sizeof path, k, 0, true);
      diag(r, line_no, f[0].col, path, "command type must be 1, 2, 3, 4 or 5 (got %g)", v[0]);
      ok = false;
    }
    if (ok && !(v[7] >= 0.0)) {
      command_path(path, sizeof path, k, 7, true);
      diag(r, line_no, f[7].col, path, "command duration must be >= 0 s (got %g)", v[7]);
      ok = false;
    }
    if (k >= NAV_MAX_SEGMENTS) {
      if (!too_many)
        diag(r, line_no, 1, "trajectory.segments.items",
             "too many commands: a segment script holds at most %d (NAV_MAX_SEGMENTS)", NAV_MAX_SEGMENTS);
      too_many = true;
      st = NAV_ERR_PARSE;
      continue;
    }
    if (!ok) {
      st = NAV_ERR_PARSE;
      S->count++; /* keep the indices of later commands aligned with their positions */
      continue;
    }
    nav_segment *g = &S->items[k];
    memset(g, 0, sizeof *g);
    const double ak = radians ? 1.0 : NAV_DEG2RAD;
    const int type = (int)v[0];
    static const nav_segment_kind kinds[6] = {NAV_SEG_HOLD,           NAV_SEG_MOTION_RATES,
                                              NAV_SEG_MOTION_ABS_ABS, NAV_SEG_MOTION_REL_REL,
                                              NAV_SEG_MOTION_ABS_REL, NAV_SEG_MOTION_REL_ABS};
    g->kind = kinds[type];
    g->gnss_visible = v[8] != 0.0;
    g->duration_s = v[7];
    if (type == 1) {
      g->yaw_rate_rps = v[1] * ak;
      g->pitch_rate_rps = v[2] * ak;
      g->roll_rate_rps = v[3] * ak;
      g->accel_b_mps2 = nav_vec3_make(v[4], v[5], v[6]);
    } else {
      const bool att_abs = type == 2 || type == 4;
      g->yaw_rad = v[1] * ak + (att_abs ? yaw_shift : 0.0);
      g->pitch_rad = v[2] * ak;
      g->roll_rad = v[3] * ak + (att_abs ? roll_shift : 0.0);
      g->v_b_mps = nav_vec3_make(v[4], v[5], v[6]);
    }
    seg_line[k] = line_no;
    S->count++;
  }
  if (st != NAV_OK) goto cleanup;
  if (stage < 3 || S->count == 0) {
    diag(r, stage < 3 ? 0 : line_no, 1, "", "the file ends before %s",
         stage < 2 ? "the initial state" : (stage < 3 ? "the command header" : "any command"));
    st = NAV_ERR_PARSE;
    goto cleanup;
  }
  /* Plan once: feasibility and length. */
  {
    nav_traj_script_info info;
    int bad = -1;
    char msg[sizeof(((nav_diag *)0)->message)];
    const nav_status ps = nav_traj_segments_plan_info(work, &info, &bad, msg, sizeof msg);
    if (ps == NAV_ERR_NO_MEMORY) {
      st = ps;
      goto cleanup;
    }
    if (ps != NAV_OK) {
      char path[64];
      if (bad >= 0)
        snprintf(path, sizeof path, "trajectory.segments.items[%d]", bad);
      else
        snprintf(path, sizeof path, "trajectory.segments");
      diag(r, bad >= 0 ? seg_line[bad] : 0, 1, path, "%s", msg);
      st = NAV_ERR_PARSE;
      goto cleanup;
    }
    work->trajectory.duration_s = info.duration_s;
  }
  *scene = *work;
cleanup:
  nav_io_c_locale_end(&loc);
  free(seg_line);
  free(work);
  return st;
}

nav_status nav_motiondef_read_string(const char *text, size_t len, const char *display_name, nav_scene *scene,
                                     nav_diag_fn report, void *user) {
  if (!scene || (!text && len > 0)) return NAV_ERR_INVALID_ARG;
  md_reader r = {display_name ? display_name : "<string>", report, user, 0};
  if (len > NAV_IO_MAX_INPUT_BYTES) {
    diag(&r, 0, 0, "", "the input is too large (%zu bytes); at most %zu bytes", len, NAV_IO_MAX_INPUT_BYTES);
    return NAV_ERR_PARSE;
  }
  return parse(&r, text ? text : "", len, scene);
}

nav_status nav_motiondef_read_file(const char *path, nav_scene *scene, nav_diag_fn report, void *user) {
  nav_status st = NAV_OK;
  FILE *fp = NULL;
  char *buf = NULL;
  size_t len = 0;
  if (!path || !scene) return NAV_ERR_INVALID_ARG;
  md_reader r = {path, report, user, 0};
  {
    /* A FIFO, device or directory is refused at once, without a blocking open. */
    char why[320];
    st = nav_io_fopen_regular(path, &fp, why, sizeof why);
    if (st != NAV_OK) {
      diag(&r, 0, 0, "", "%s", why);
      return st;
    }
  }
  struct stat sb;
  if (fstat(fileno(fp), &sb) != 0) {
    diag(&r, 0, 0, "", "cannot read the file: %s", strerror(errno));
    st = NAV_ERR_IO;
    goto cleanup;
  }
  if ((uintmax_t)sb.st_size > NAV_IO_MAX_INPUT_BYTES) {
    diag(&r, 0, 0, "", "the file is too large (%jd bytes); at most %zu bytes", (intmax_t)sb.st_size,
         NAV_IO_MAX_INPUT_BYTES);
    st = NAV_ERR_PARSE;
    goto cleanup;
  }
  buf = malloc((size_t)sb.st_size + 1);
  if (!buf) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  len = fread(buf, 1, (size_t)sb.st_size, fp);
  if (ferror(fp)) {
    diag(&r, 0, 0, "", "cannot read the file");
    st = NAV_ERR_IO;
    goto cleanup;
  }
  st = parse(&r, buf, len, scene);
cleanup:
  free(buf);
  if (fp) fclose(fp);
  return st;
}

nav_status nav_motiondef_script_summary(const nav_scene *scene, nav_script_summary *out, char *msg,
                                        size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !out) return NAV_ERR_INVALID_ARG;
  nav_traj_script_info info;
  int bad = -1;
  nav_status st;
  int items;
  if (scene->trajectory.type == NAV_TRAJ_SEGMENTS) {
    st = nav_traj_segments_plan_info(scene, &info, &bad, msg, msg_size);
    items = scene->trajectory.segments.count;
  } else if (scene->trajectory.type == NAV_TRAJ_WAYPOINTS) {
    st = nav_traj_waypoints_plan_info(scene, &info, &bad, msg, msg_size);
    items = scene->trajectory.waypoints.count;
  } else {
    if (msg)
      snprintf(msg, msg_size, "trajectory.type %s is not a waypoint or segment script",
               nav_traj_type_name(scene->trajectory.type));
    return NAV_ERR_INVALID_ARG;
  }
  if (st != NAV_OK) return st;
  out->duration_s = info.duration_s;
  out->items = items;
  out->unconverged = info.unconverged;
  out->first_unconverged = info.first_unconverged;
  out->shortened_ramps = info.shortened_ramps;
  out->max_ramp_ang_accel_rps2 = info.max_ramp_ang_accel_rps2;
  return NAV_OK;
}
