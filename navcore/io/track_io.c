/*
 * Recorded reference files -> nav_track_sample arrays (nav_track_io.h), for trajectory.type
 * recorded (scene_traj_io.c) and for callers of nav_track_fit().
 *
 * Parsing is strict and reports every malformed line as FILE:LINE:COL (the column of the
 * offending field) with the scene field path of the file. Numbers are read with strtod in the C
 * locale (a GUI process may have set another LC_NUMERIC), which rounds correctly. The file is
 * streamed line by line: memory is the kept samples plus one line.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navcore/nav_track_io.h"
#include "scene_io_internal.h"

/* Position jumps between consecutive samples (nav_track_io.h): |dr - v_avg dt| may reach
 * JUMP_FLOOR_M + JUMP_ACCEL_MPS2 dt^2 / 4. For any motion with |a| <= A between two samples the
 * trapezoid rule's error of the displacement is at most A dt^2 / 4; A = 100 m/s^2 (10 g) is beyond
 * any vehicle the recorded files describe, and 1 m covers the position noise of a reference (the
 * KF-GINS dataset 2 reference stays within 0.023 m, the gnss-ins-sim long drive within 1e-4 m). */
#define JUMP_FLOOR_M 1.0
#define JUMP_ACCEL_MPS2 100.0

/* Longest accepted line [bytes]: a .nav line is about 120 bytes. */
#define MAX_LINE 4096
#define NAV_COLUMNS 11

typedef struct tk_reader {
  const char *file;
  const char *path; /* scene field path of the diagnostics */
  nav_diag_fn report;
  void *user;
  int ndiag;
  unsigned window;
  double start_s, end_s;
  nav_track_sample *out;
  size_t count, cap;
  bool have_prev;
  double t_prev;
  long line_prev;
  long lines_with_data;
  double t_first, t_last; /* of the whole file */
  bool oom;
  /* the previous sample inside the window, for the jump check */
  bool have_prev_sample;
  nav_geodetic prev_pos;
  nav_vec3 prev_v_n_mps;
  double prev_t_s;
  long prev_line;
} tk_reader;

static void diag(tk_reader *r, long line, int col, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static void diag(tk_reader *r, long line, int col, const char *fmt, ...) {
  if (r->ndiag >= NAV_DIAG_MAX_PER_FILE) return;
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", r->file);
  d.line = line > 0 && line < 0x7fffffffL ? (int)line : 0;
  d.col = d.line > 0 ? (col > 0 ? col : 1) : 0;
  r->ndiag++;
  if (r->ndiag == NAV_DIAG_MAX_PER_FILE) {
    d.line = d.col = 0;
    snprintf(d.message, sizeof d.message, "too many problems; stopping after the first %d",
             NAV_DIAG_MAX_PER_FILE - 1);
  } else {
    snprintf(d.path, sizeof d.path, "%s", r->path);
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(d.message, sizeof d.message, fmt, ap);
    va_end(ap);
  }
  if (r->report) r->report(r->user, &d);
}

static const char *const k_nav_columns[NAV_COLUMNS] = {
    "GPS week",   "time [s]",         "latitude [deg]",   "longitude [deg]",
    "height [m]", "velocity N [m/s]", "velocity E [m/s]", "velocity D [m/s]",
    "roll [deg]", "pitch [deg]",      "yaw [deg]"};

/* Printable excerpt of a field: control bytes become '?', long text is cut. */
static void excerpt(char *dst, size_t cap, const char *s, size_t n) {
  size_t j = 0;
  const size_t max = cap > 40 ? 32 : cap - 4;
  for (size_t i = 0; i < n && j < max; ++i) {
    const unsigned char c = (unsigned char)s[i];
    dst[j++] = (c < 0x20 || c == 0x7f) ? '?' : (char)c;
  }
  if (n > max) {
    memcpy(dst + j, "...", 3);
    j += 3;
  }
  dst[j] = '\0';
}

static bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* One line (without its '\n'). */
static void parse_line(tk_reader *r, const char *line, size_t len, long line_no) {
  if (len > 0 && line[len - 1] == '\r') --len;
  size_t i = 0;
  while (i < len && is_blank(line[i]))
    ++i;
  if (i == len || line[i] == '#') return;
  if (len > MAX_LINE) {
    diag(r, line_no, 1, "the line is %zu bytes long; at most %d are accepted", len, MAX_LINE);
    return;
  }
  double v[NAV_COLUMNS];
  int col[NAV_COLUMNS];
  int k = 0;
  while (i < len) {
    const size_t a = i;
    while (i < len && !is_blank(line[i]))
      ++i;
    const size_t n = i - a;
    if (k == NAV_COLUMNS) {
      char ex[48];
      excerpt(ex, sizeof ex, line + a, n);
      diag(r, line_no, (int)a + 1,
           "unexpected field \"%s\": kf_gins_nav lines have %d columns (week, t, lat, lon, "
           "h, vN, vE, vD, roll, pitch, yaw)",
           ex, NAV_COLUMNS);
      return;
    }
    char buf[128];
    char *end = NULL;
    bool ok = n > 0 && n < sizeof buf;
    if (ok) {
      memcpy(buf, line + a, n);
      buf[n] = '\0';
      errno = 0;
      v[k] = strtod(buf, &end);
      ok = end == buf + n;
    }
    if (!ok || !isfinite(v[k])) {
      char ex[48];
      excerpt(ex, sizeof ex, line + a, n);
      diag(r, line_no, (int)a + 1, "%s: \"%s\" is not a finite number", k_nav_columns[k], ex);
      return;
    }
    col[k++] = (int)a + 1;
    while (i < len && is_blank(line[i]))
      ++i;
  }
  if (k < NAV_COLUMNS) {
    diag(r, line_no, (int)len + 1,
         "missing %s: the line has %d columns, kf_gins_nav needs %d (week, t, lat, lon, "
         "h, vN, vE, vD, roll, pitch, yaw)",
         k_nav_columns[k], k, NAV_COLUMNS);
    return;
  }
  /* Ranges (degrees as written). */
  static const struct {
    int c;
    double lo, hi;
  } k_ranges[] = {{0, 0.0, 1.0e6},    {2, -90.0, 90.0}, {3, -360.0, 360.0}, {4, -1.0e5, 1.0e8},
                  {8, -180.0, 180.0}, {9, -90.0, 90.0}, {10, -360.0, 360.0}};
  for (size_t m = 0; m < sizeof k_ranges / sizeof k_ranges[0]; ++m) {
    const int c = k_ranges[m].c;
    if (!(v[c] >= k_ranges[m].lo && v[c] <= k_ranges[m].hi)) {
      diag(r, line_no, col[c], "%s: %.17g is outside [%g, %g]", k_nav_columns[c], v[c], k_ranges[m].lo,
           k_ranges[m].hi);
      return;
    }
  }
  const double t = v[1];
  if (r->have_prev && !(t > r->t_prev)) {
    diag(r, line_no, col[1], "time [s]: %.9g does not increase (line %ld has %.9g)", t, r->line_prev,
         r->t_prev);
    return;
  }
  if (!r->have_prev) r->t_first = t;
  r->have_prev = true;
  r->t_prev = t;
  r->t_last = t;
  r->line_prev = line_no;
  r->lines_with_data++;
  if ((r->window & NAV_RECORDED_HAS_START) && t < r->start_s) return;
  if ((r->window & NAV_RECORDED_HAS_END) && t > r->end_s) return;
  {
    /* A position that jumps further than the recorded velocities carry it would be smoothed over
     * by the fit (a spike of huge acceleration in the ideal IMU): refuse it at its line. */
    const nav_geodetic pos = {v[2] * NAV_DEG2RAD, nav_earth_wrap_lon(v[3] * NAV_DEG2RAD), v[4]};
    const nav_vec3 vel = nav_vec3_make(v[5], v[6], v[7]);
    if (r->have_prev_sample) {
      const double dt = t - r->prev_t_s;
      const nav_vec3 dr = nav_earth_geodetic_to_ned(r->prev_pos, pos);
      const nav_vec3 dv = nav_vec3_make(0.5 * (vel.x + r->prev_v_n_mps.x) * dt, 0.5 * (vel.y + r->prev_v_n_mps.y) * dt,
                                        0.5 * (vel.z + r->prev_v_n_mps.z) * dt);
      const double miss = sqrt((dr.x - dv.x) * (dr.x - dv.x) + (dr.y - dv.y) * (dr.y - dv.y) +
                               (dr.z - dv.z) * (dr.z - dv.z));
      const double bound = JUMP_FLOOR_M + 0.25 * JUMP_ACCEL_MPS2 * dt * dt;
      if (!(miss <= bound)) {
        diag(r, line_no, col[2],
             "the position jumps %.6g m from line %ld (t = %.9g s) to this line (t = %.9g s), while the recorded "
             "velocities carry it %.6g m: |dr - v_avg dt| = %.6g m exceeds %.6g m (1 m + 100 m/s^2 x dt^2 / 4); "
             "fix or remove the sample",
             sqrt(dr.x * dr.x + dr.y * dr.y + dr.z * dr.z), r->prev_line, r->prev_t_s, t,
             sqrt(dv.x * dv.x + dv.y * dv.y + dv.z * dv.z), miss, bound);
        /* Compared from here on with this sample: a step is reported once. */
        r->prev_pos = pos;
        r->prev_v_n_mps = vel;
        r->prev_t_s = t;
        r->prev_line = line_no;
        return;
      }
    }
    r->have_prev_sample = true;
    r->prev_pos = pos;
    r->prev_v_n_mps = vel;
    r->prev_t_s = t;
    r->prev_line = line_no;
  }
  if (r->ndiag > 0 || r->oom) return; /* nothing is returned anyway */
  if (r->count == r->cap) {
    const size_t cap = r->cap ? 2 * r->cap : 1024;
    nav_track_sample *g = realloc(r->out, cap * sizeof *g);
    if (!g) {
      r->oom = true;
      return;
    }
    r->out = g;
    r->cap = cap;
  }
  nav_track_sample *s = &r->out[r->count++];
  s->t_s = t;
  s->pos.lat_rad = v[2] * NAV_DEG2RAD;
  s->pos.lon_rad = nav_earth_wrap_lon(v[3] * NAV_DEG2RAD);
  s->pos.h_m = v[4];
  s->v_n_mps = nav_vec3_make(v[5], v[6], v[7]);
  s->att.roll_rad = v[8] * NAV_DEG2RAD;
  s->att.pitch_rad = v[9] * NAV_DEG2RAD;
  s->att.yaw_rad = nav_wrap_pi(v[10] * NAV_DEG2RAD);
}

static void begin(tk_reader *r, const char *file, const char *field_path, unsigned window, double start_s,
                  double end_s, nav_diag_fn report, void *user) {
  memset(r, 0, sizeof *r);
  r->file = file;
  r->path = field_path ? field_path : "";
  r->report = report;
  r->user = user;
  r->window = window;
  r->start_s = start_s;
  r->end_s = end_s;
}

/* After the last line: the window must hold at least two samples. */
static nav_status finish(tk_reader *r, nav_track_sample **out, size_t *count) {
  if (r->oom) {
    free(r->out);
    return NAV_ERR_NO_MEMORY;
  }
  if (r->ndiag == 0 && r->count < 2) {
    if (r->lines_with_data == 0)
      diag(r, 0, 0, "the file has no samples");
    else if (r->window & (NAV_RECORDED_HAS_START | NAV_RECORDED_HAS_END))
      diag(r, 0, 0,
           "%zu sample(s) in the window [%.9g, %.9g] s; at least 2 are needed (the file covers "
           "%.9g to %.9g s)",
           r->count, (r->window & NAV_RECORDED_HAS_START) ? r->start_s : -INFINITY,
           (r->window & NAV_RECORDED_HAS_END) ? r->end_s : INFINITY, r->t_first, r->t_last);
    else
      diag(r, 0, 0, "the file has %zu sample; at least 2 are needed", r->count);
  }
  if (r->ndiag > 0) {
    free(r->out);
    return NAV_ERR_PARSE;
  }
  *out = r->out;
  *count = r->count;
  return NAV_OK;
}

nav_status nav_track_read_string(const char *text, size_t len, const char *display_name,
                                 nav_recorded_format format, unsigned window, double start_s, double end_s,
                                 const char *field_path, nav_track_sample **out, size_t *count,
                                 nav_diag_fn report, void *user) {
  if ((!text && len > 0) || !out || !count) return NAV_ERR_INVALID_ARG;
  if (format != NAV_RECORDED_KF_GINS_NAV) return NAV_ERR_INVALID_ARG;
  tk_reader r;
  begin(&r, display_name ? display_name : "<string>", field_path, window, start_s, end_s, report, user);
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  long line_no = 0;
  size_t pos = 0;
  while (pos < len && r.ndiag < NAV_DIAG_MAX_PER_FILE && !r.oom) {
    size_t e = pos;
    while (e < len && text[e] != '\n')
      ++e;
    parse_line(&r, text + pos, e - pos, ++line_no);
    pos = e < len ? e + 1 : len;
  }
  nav_io_c_locale_end(&loc);
  return finish(&r, out, count);
}

nav_status nav_track_read_file(const char *path, nav_recorded_format format, unsigned window, double start_s,
                               double end_s, const char *field_path, nav_track_sample **out, size_t *count,
                               nav_diag_fn report, void *user) {
  if (!path || !out || !count) return NAV_ERR_INVALID_ARG;
  if (format != NAV_RECORDED_KF_GINS_NAV) return NAV_ERR_INVALID_ARG;
  tk_reader r;
  begin(&r, path, field_path, window, start_s, end_s, report, user);
  FILE *fp = NULL;
  {
    /* A FIFO, device or directory is refused at once, without a blocking open; why is
     * "cannot open the file: ..." or "cannot read the file: it is ...". */
    char why[320];
    const nav_status open_st = nav_io_fopen_regular(path, &fp, why, sizeof why);
    if (open_st != NAV_OK) {
      diag(&r, 0, 0, "%.11s the recorded file%s", why, strlen(why) >= 20 ? why + 20 : "");
      return open_st;
    }
  }
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  char *line = NULL;
  size_t line_cap = 0;
  long line_no = 0;
  ssize_t got = 0;
  while (r.ndiag < NAV_DIAG_MAX_PER_FILE && !r.oom && (got = getline(&line, &line_cap, fp)) >= 0) {
    size_t n = (size_t)got;
    if (n > 0 && line[n - 1] == '\n') --n;
    parse_line(&r, line, n, ++line_no);
  }
  const bool read_error = ferror(fp) != 0;
  const int err = errno;
  free(line);
  fclose(fp);
  nav_io_c_locale_end(&loc);
  if (read_error) {
    char why[128];
    if (strerror_r(err, why, sizeof why) != 0) snprintf(why, sizeof why, "error %d", err);
    diag(&r, 0, 0, "cannot read the recorded file: %s", why);
    free(r.out);
    return NAV_ERR_IO;
  }
  return finish(&r, out, count);
}
