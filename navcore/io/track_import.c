/*
 * GPX and KML tracks -> nav_geotrack -> waypoint trajectories (nav_track_import.h).
 *
 * XML is parsed by expat (Debian libexpat1-dev) as a stream: the handlers keep only the text of
 * the few elements that matter and the position (line:col) where each started, so every
 * diagnostic points at the element, attribute or coordinate tuple at fault. Element names are
 * matched on their local part (after any namespace prefix), so "gx:Track" and a default-namespace
 * "Track" are the same.
 *
 * Thinning is Douglas-Peucker on local curvilinear NED coordinates about the first point
 * (iterative, no recursion), after dropping points within 1 mm of the previous kept one.
 */
#define _POSIX_C_SOURCE 200809L

#include <ctype.h>
#include <expat.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "navcore/nav_frames.h"
#include "navcore/nav_motiondef.h"
#include "navcore/nav_traj.h"
#include "navcore/nav_track_import.h"
#include "scene_io_internal.h"

#define TI_MAX_FILE (256L * 1024 * 1024)

/* ------------------------------------------------------------------------------ diagnostics */

typedef struct ti_reader {
  const char *file;
  nav_diag_fn report;
  void *user;
  int ndiag;
} ti_reader;

/* Heights of track points [m]: the range of a scene's earth.origin.h_m (nav_scene_validate), from
 * below the deepest ocean floor to far beyond any aircraft, so a track gives no height a scene
 * refuses (an <ele> of 1e9 used to be written into the scene). */
#define TRACK_MIN_H_M (-1.0e5)
#define TRACK_MAX_H_M 1.0e8
static bool height_ok(double h) { return h >= TRACK_MIN_H_M && h <= TRACK_MAX_H_M; }

static void ti_diag(ti_reader *r, int line, int col, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
static void ti_diag(ti_reader *r, int line, int col, const char *path, const char *fmt, ...) {
  r->ndiag++;
  if (r->ndiag > NAV_DIAG_MAX_PER_FILE || !r->report) return;
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", r->file);
  d.line = line;
  d.col = line > 0 ? (col > 0 ? col : 1) : 0;
  snprintf(d.path, sizeof d.path, "%s", path ? path : "");
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d.message, sizeof d.message, fmt, ap);
  va_end(ap);
  r->report(r->user, &d);
}

/* ------------------------------------------------------------------------------ numbers, times */

/* Parse a finite double from [s, s+n) in the C locale; the whole range must be the number. */
static bool parse_double_n(const char *s, size_t n, double *out) {
  char buf[64];
  if (n == 0 || n >= sizeof buf) return false;
  memcpy(buf, s, n);
  buf[n] = '\0';
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  char *end = NULL;
  const double v = strtod(buf, &end);
  nav_io_c_locale_end(&loc);
  if (!end || *end != '\0' || !isfinite(v)) return false;
  *out = v;
  return true;
}

/* Days from 1970-01-01 of a proleptic Gregorian date (Howard Hinnant's days_from_civil idea). */
static int64_t days_from_civil(int64_t y, int m, int d) {
  y -= m <= 2;
  const int64_t era = (y >= 0 ? y : y - 399) / 400;
  const int64_t yoe = y - era * 400;
  const int64_t doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const int64_t doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

static bool digits(const char *s, int n, int *out) {
  int v = 0;
  for (int i = 0; i < n; ++i) {
    if (!isdigit((unsigned char)s[i])) return false;
    v = 10 * v + (s[i] - '0');
  }
  *out = v;
  return true;
}

/* ISO 8601 date-time "YYYY-MM-DDThh:mm:ss[.f][Z|+hh:mm|-hh:mm]" -> seconds since the Unix epoch. */
static bool parse_iso8601(const char *s, size_t n, double *out) {
  while (n > 0 && isspace((unsigned char)*s)) ++s, --n;
  while (n > 0 && isspace((unsigned char)s[n - 1])) --n;
  int Y, M, D, h, mi, sec;
  if (n < 19 || !digits(s, 4, &Y) || s[4] != '-' || !digits(s + 5, 2, &M) || s[7] != '-' || !digits(s + 8, 2, &D) ||
      (s[10] != 'T' && s[10] != 't' && s[10] != ' ') || !digits(s + 11, 2, &h) || s[13] != ':' ||
      !digits(s + 14, 2, &mi) || s[16] != ':' || !digits(s + 17, 2, &sec))
    return false;
  if (M < 1 || M > 12 || D < 1 || D > 31 || h > 23 || mi > 59 || sec > 60) return false;
  size_t i = 19;
  double frac = 0.0;
  if (i < n && s[i] == '.') {
    double scale = 0.1;
    ++i;
    if (i >= n || !isdigit((unsigned char)s[i])) return false;
    while (i < n && isdigit((unsigned char)s[i])) {
      frac += scale * (s[i] - '0');
      scale *= 0.1;
      ++i;
    }
  }
  int offset_s = 0;
  if (i < n) {
    if ((s[i] == 'Z' || s[i] == 'z') && i + 1 == n) {
      i = n;
    } else if ((s[i] == '+' || s[i] == '-') && n - i == 6 && s[i + 3] == ':') {
      int oh, om;
      if (!digits(s + i + 1, 2, &oh) || !digits(s + i + 4, 2, &om) || oh > 23 || om > 59) return false;
      offset_s = (s[i] == '+' ? 1 : -1) * (oh * 3600 + om * 60);
      i = n;
    } else {
      return false;
    }
  }
  const int64_t days = days_from_civil(Y, M, D);
  *out = (double)(days * 86400 + h * 3600 + mi * 60 + sec - offset_s) + frac;
  return true;
}

/* ------------------------------------------------------------------------------ XML state */

typedef enum { DOC_UNKNOWN = 0, DOC_GPX, DOC_KML } doc_kind;

/* Elements whose text we keep. */
typedef enum { TX_NONE = 0, TX_ELE, TX_TIME, TX_NAME, TX_COORDS, TX_WHEN, TX_GXCOORD } text_kind;

typedef struct pt_list {
  nav_geopoint *v;
  size_t n, cap;
} pt_list;

/* Geometries of one Placemark kept apart (more are appended to the last one) and tracks of a
 * file listed by name (more are counted). */
#define KML_MAX_GEOM 64
#define KML_MAX_LIST 64

typedef struct geom_range {
  size_t start, end;
  int line, col;
} geom_range;

typedef struct kml_track_info {
  char name[128];
  size_t points;
  int line, col;
} kml_track_info;

typedef struct ti_xml {
  ti_reader *r;
  XML_Parser p;
  doc_kind doc;
  nav_track_format want;
  const char *select;
  bool oom;
  int depth;
  /* text capture */
  text_kind tx;
  int tx_depth;
  char *text;
  size_t text_n, text_cap;
  int text_line, text_col;
  /* GPX */
  bool in_pt;
  int pt_kind; /* 0 trkpt, 1 rtept */
  nav_geopoint cur;
  pt_list trk, rte;
  char trk_name[128];
  bool have_trk_name;
  int in_trk;
  /* KML */
  int in_placemark;
  char pm_name[128];
  pt_list pm_pts;
  int track_line, track_col;
  int in_track;
  int in_linestring;
  double *when;
  size_t n_when, cap_when;
  pt_list gxc;
  bool chosen;
  pt_list kml;
  char kml_name[128];
  bool saw_placemark_name;
  /* Every LineString / gx:Track is one track (issue 18): the geometries of the current
   * Placemark as ranges of pm_pts, and every track of the file for the selection and its list. */
  size_t geom_start;
  int n_geom;
  geom_range geom[KML_MAX_GEOM];
  int n_tracks;
  kml_track_info tracks[KML_MAX_LIST];
} ti_xml;

static const char *local_name(const char *name) {
  const char *c = strrchr(name, ':');
  return c ? c + 1 : name;
}

static int cur_line(ti_xml *x) { return (int)XML_GetCurrentLineNumber(x->p); }
static int cur_col(ti_xml *x) { return (int)XML_GetCurrentColumnNumber(x->p) + 1; }

static bool pt_push(ti_xml *x, pt_list *l, const nav_geopoint *p) {
  if (l->n == l->cap) {
    const size_t cap = l->cap ? 2 * l->cap : 256;
    nav_geopoint *v = realloc(l->v, cap * sizeof *v);
    if (!v) {
      x->oom = true;
      XML_StopParser(x->p, XML_FALSE);
      return false;
    }
    l->v = v;
    l->cap = cap;
  }
  l->v[l->n++] = *p;
  return true;
}

static void text_begin(ti_xml *x, text_kind k) {
  x->tx = k;
  x->tx_depth = x->depth;
  x->text_n = 0;
  x->text_line = 0;
  x->text_col = 0;
}

static void XMLCALL on_text(void *ud, const XML_Char *s, int len) {
  ti_xml *x = ud;
  if (x->tx == TX_NONE || len <= 0) return;
  if (x->text_n == 0 && x->text_line == 0) {
    x->text_line = cur_line(x);
    x->text_col = cur_col(x);
  }
  if (x->text_n + (size_t)len + 1 > x->text_cap) {
    size_t cap = x->text_cap ? x->text_cap : 256;
    while (cap < x->text_n + (size_t)len + 1) cap *= 2;
    char *t = realloc(x->text, cap);
    if (!t) {
      x->oom = true;
      XML_StopParser(x->p, XML_FALSE);
      return;
    }
    x->text = t;
    x->text_cap = cap;
  }
  memcpy(x->text + x->text_n, s, (size_t)len);
  x->text_n += (size_t)len;
  x->text[x->text_n] = '\0';
}

/* Position of byte @p off of the captured text, walking on from byte *from at (*line, *col)
 * (pass *from = 0 with *line = 0 to start at the text's beginning); *from becomes @p off, so a
 * scan over the text costs O(length), not O(length^2). */
static void text_pos_walk(const ti_xml *x, size_t *from, size_t off, int *line, int *col) {
  if (x->text_line == 0) {
    *line = cur_line((ti_xml *)x);
    *col = cur_col((ti_xml *)x);
    return;
  }
  if (*from == 0 && *line == 0) {
    *line = x->text_line;
    *col = x->text_col;
  }
  int l = *line, c = *col;
  for (size_t i = *from; i < off && i < x->text_n; ++i) {
    if (x->text[i] == '\n') {
      ++l;
      c = 1;
    } else {
      ++c;
    }
  }
  *line = l;
  *col = c;
  *from = off;
}

static void text_pos(const ti_xml *x, size_t off, int *line, int *col) {
  size_t from = 0;
  *line = 0;
  *col = 0;
  text_pos_walk(x, &from, off, line, col);
}

static void trim(const char **s, size_t *n) {
  while (*n > 0 && isspace((unsigned char)**s)) ++*s, --*n;
  while (*n > 0 && isspace((unsigned char)(*s)[*n - 1])) --*n;
}

static const char *attr(const XML_Char **atts, const char *name) {
  for (int i = 0; atts && atts[i]; i += 2)
    if (strcmp(local_name(atts[i]), name) == 0) return atts[i + 1];
  return NULL;
}

static void gpx_start_point(ti_xml *x, const XML_Char **atts, int kind) {
  const int line = cur_line(x), col = cur_col(x);
  memset(&x->cur, 0, sizeof x->cur);
  x->cur.line = line;
  x->cur.col = col;
  x->in_pt = true;
  x->pt_kind = kind;
  const char *path = kind == 0 ? "trkpt" : "rtept";
  const char *la = attr(atts, "lat"), *lo = attr(atts, "lon");
  double lat = 0, lon = 0;
  bool ok = true;
  if (!la || !parse_double_n(la, strlen(la), &lat) || fabs(lat) > 90.0) {
    ti_diag(x->r, line, col, path, "attribute lat: expected a latitude in degrees within [-90, 90]%s%s%s",
            la ? ", got \"" : " (missing)", la ? la : "", la ? "\"" : "");
    ok = false;
  }
  if (!lo || !parse_double_n(lo, strlen(lo), &lon) || fabs(lon) > 360.0) {
    ti_diag(x->r, line, col, path, "attribute lon: expected a longitude in degrees within [-180, 180]%s%s%s",
            lo ? ", got \"" : " (missing)", lo ? lo : "", lo ? "\"" : "");
    ok = false;
  }
  if (!ok) x->in_pt = false;
  x->cur.pos.lat_rad = lat * NAV_DEG2RAD;
  x->cur.pos.lon_rad = nav_wrap_pi(lon * NAV_DEG2RAD);
}

static void kml_reset_placemark(ti_xml *x) {
  x->pm_pts.n = 0;
  x->n_geom = 0;
  x->pm_name[0] = '\0';
  x->saw_placemark_name = false;
}

static void kml_geom_begin(ti_xml *x) {
  if (x->n_geom < KML_MAX_GEOM) {
    x->geom[x->n_geom].start = x->pm_pts.n;
    x->geom[x->n_geom].line = cur_line(x);
    x->geom[x->n_geom].col = cur_col(x);
  }
  x->geom_start = x->pm_pts.n;
}

static void kml_geom_end(ti_xml *x) {
  if (x->pm_pts.n == x->geom_start) return; /* no point: not a track */
  if (x->n_geom < KML_MAX_GEOM) x->geom[x->n_geom++].end = x->pm_pts.n;
  else x->geom[KML_MAX_GEOM - 1].end = x->pm_pts.n;
}

/* Does @p sel pick track number @p index (1-based) named @p name? A selection of digits only is
 * an index; else it is the Placemark's name (its first geometry) or the listed name. */
static bool kml_selected(const char *sel, int index, const char *name, const char *pm_name, int k) {
  if (!sel) return index == 1;
  bool digits = sel[0] != '\0';
  for (const char *c = sel; *c; ++c)
    if (*c < '0' || *c > '9') digits = false;
  if (digits) return strtol(sel, NULL, 10) == index;
  return strcmp(sel, name) == 0 || (k == 0 && strcmp(sel, pm_name) == 0);
}

/* A Placemark ends: each of its geometries becomes a track, named after the Placemark (with
 * " (k)" when it holds several); the selected one is kept. false when out of memory. */
static bool kml_placemark_end(ti_xml *x) {
  for (int k = 0; k < x->n_geom; ++k) {
    const geom_range *g = &x->geom[k];
    const int index = ++x->n_tracks;
    char name[128];
    if (x->n_geom > 1) snprintf(name, sizeof name, "%.100s (%d)", x->pm_name, k + 1);
    else snprintf(name, sizeof name, "%s", x->pm_name);
    if (index <= KML_MAX_LIST) {
      kml_track_info *t = &x->tracks[index - 1];
      snprintf(t->name, sizeof t->name, "%s", name);
      t->points = g->end - g->start;
      t->line = g->line;
      t->col = g->col;
    }
    if (!x->chosen && kml_selected(x->select, index, name, x->pm_name, k)) {
      x->chosen = true;
      for (size_t i = g->start; i < g->end; ++i)
        if (!pt_push(x, &x->kml, &x->pm_pts.v[i])) return false;
      snprintf(x->kml_name, sizeof x->kml_name, "%s", name);
    }
  }
  return true;
}

static void XMLCALL on_start(void *ud, const XML_Char *name, const XML_Char **atts) {
  ti_xml *x = ud;
  const char *ln = local_name(name);
  x->depth++;
  if (x->depth == 1) {
    if (strcmp(ln, "gpx") == 0) x->doc = DOC_GPX;
    else if (strcmp(ln, "kml") == 0) x->doc = DOC_KML;
    else {
      ti_diag(x->r, cur_line(x), cur_col(x), "", "root element <%s>: expected <gpx> (GPX) or <kml> (KML)", ln);
      XML_StopParser(x->p, XML_FALSE);
      return;
    }
    if ((x->want == NAV_TRACK_FORMAT_GPX && x->doc != DOC_GPX) || (x->want == NAV_TRACK_FORMAT_KML && x->doc != DOC_KML)) {
      ti_diag(x->r, cur_line(x), cur_col(x), "", "root element <%s>: expected <%s>", ln,
              x->want == NAV_TRACK_FORMAT_GPX ? "gpx" : "kml");
      XML_StopParser(x->p, XML_FALSE);
    }
    return;
  }
  if (x->doc == DOC_GPX) {
    if (strcmp(ln, "trk") == 0) x->in_trk++;
    else if (strcmp(ln, "trkpt") == 0) gpx_start_point(x, atts, 0);
    else if (strcmp(ln, "rtept") == 0) gpx_start_point(x, atts, 1);
    else if (x->in_pt && strcmp(ln, "ele") == 0) text_begin(x, TX_ELE);
    else if (x->in_pt && strcmp(ln, "time") == 0) text_begin(x, TX_TIME);
    else if (x->in_trk && !x->have_trk_name && !x->in_pt && strcmp(ln, "name") == 0) text_begin(x, TX_NAME);
  } else if (x->doc == DOC_KML) {
    if (strcmp(ln, "Placemark") == 0) {
      x->in_placemark++;
      kml_reset_placemark(x);
    } else if (x->in_placemark && strcmp(ln, "name") == 0 && !x->saw_placemark_name && !x->in_track) {
      text_begin(x, TX_NAME);
    } else if (x->in_placemark && strcmp(ln, "LineString") == 0) {
      if (x->in_linestring == 0) kml_geom_begin(x);
      x->in_linestring++;
    } else if (x->in_linestring && strcmp(ln, "coordinates") == 0) {
      text_begin(x, TX_COORDS);
    } else if (x->in_placemark && strcmp(ln, "Track") == 0) {
      if (x->in_track == 0) kml_geom_begin(x);
      x->in_track++;
      x->n_when = 0;
      x->gxc.n = 0;
      x->track_line = cur_line(x);
      x->track_col = cur_col(x);
    } else if (x->in_track && strcmp(ln, "when") == 0) {
      text_begin(x, TX_WHEN);
    } else if (x->in_track && strcmp(ln, "coord") == 0) {
      text_begin(x, TX_GXCOORD);
    }
  }
}

/* "lon,lat[,alt]" tuples separated by white space (KML <coordinates>). */
static void kml_parse_coordinates(ti_xml *x) {
  const char *t = x->text;
  size_t i = 0, n = x->text_n, walked = 0;
  int line = 0, col = 0;
  while (i < n) {
    while (i < n && isspace((unsigned char)t[i])) ++i;
    if (i >= n) break;
    const size_t b = i;
    while (i < n && !isspace((unsigned char)t[i])) ++i;
    /* a tuple [b, i) */
    text_pos_walk(x, &walked, b, &line, &col);
    double v[3] = {0, 0, 0};
    int k = 0;
    size_t s = b;
    bool ok = true;
    for (size_t j = b; j <= i; ++j) {
      if (j == i || t[j] == ',') {
        if (k >= 3 || !parse_double_n(t + s, j - s, &v[k])) {
          ok = false;
          break;
        }
        ++k;
        s = j + 1;
      }
    }
    if (!ok || k < 2 || fabs(v[1]) > 90.0 || fabs(v[0]) > 360.0) {
      ti_diag(x->r, line, col, "coordinates",
              "expected a tuple lon,lat[,alt] (degrees, degrees, metres; |lat| <= 90), got \"%.*s\"", (int)(i - b), t + b);
      continue;
    }
    if (!height_ok(v[2])) {
      ti_diag(x->r, line, col, "coordinates", "altitude %.9g m outside [-1e5, 1e8] m (the heights a scene accepts)",
              v[2]);
      continue;
    }
    nav_geopoint p;
    memset(&p, 0, sizeof p);
    p.pos.lat_rad = v[1] * NAV_DEG2RAD;
    p.pos.lon_rad = nav_wrap_pi(v[0] * NAV_DEG2RAD);
    p.pos.h_m = v[2];
    p.has_h = k == 3;
    p.line = line;
    p.col = col;
    if (!pt_push(x, &x->pm_pts, &p)) return;
  }
}

/* gx:coord "lon lat alt". */
static void kml_parse_gxcoord(ti_xml *x) {
  const char *t = x->text;
  size_t n = x->text_n;
  int line, col;
  size_t off = 0;
  while (off < n && isspace((unsigned char)t[off])) ++off;
  text_pos(x, off, &line, &col);
  double v[3] = {0, 0, 0};
  int k = 0;
  size_t i = off;
  bool ok = true;
  while (i < n) {
    while (i < n && isspace((unsigned char)t[i])) ++i;
    if (i >= n) break;
    const size_t b = i;
    while (i < n && !isspace((unsigned char)t[i])) ++i;
    if (k >= 3 || !parse_double_n(t + b, i - b, &v[k])) {
      ok = false;
      break;
    }
    ++k;
  }
  if (ok && k >= 2 && !height_ok(v[2])) {
    ti_diag(x->r, line, col, "gx:coord", "altitude %.9g m outside [-1e5, 1e8] m (the heights a scene accepts)", v[2]);
    ok = false;
  } else if (!ok || k < 2 || fabs(v[1]) > 90.0 || fabs(v[0]) > 360.0) {
    ti_diag(x->r, line, col, "gx:coord", "expected \"lon lat [alt]\" (degrees, degrees, metres; |lat| <= 90), got \"%.*s\"",
            (int)(n - off > 60 ? 60 : n - off), t + off);
    ok = false;
  }
  if (!ok) {
    nav_geopoint bad;
    memset(&bad, 0, sizeof bad);
    pt_push(x, &x->gxc, &bad); /* keep the pairing with <when> */
    return;
  }
  nav_geopoint p;
  memset(&p, 0, sizeof p);
  p.pos.lat_rad = v[1] * NAV_DEG2RAD;
  p.pos.lon_rad = nav_wrap_pi(v[0] * NAV_DEG2RAD);
  p.pos.h_m = v[2];
  p.has_h = k == 3;
  p.line = line;
  p.col = col;
  pt_push(x, &x->gxc, &p);
}

static void XMLCALL on_end(void *ud, const XML_Char *name) {
  ti_xml *x = ud;
  const char *ln = local_name(name);
  const text_kind tk = (x->tx != TX_NONE && x->tx_depth == x->depth) ? x->tx : TX_NONE;
  if (tk != TX_NONE) x->tx = TX_NONE;
  const char *s = x->text ? x->text : "";
  size_t n = tk != TX_NONE ? x->text_n : 0;
  int line = x->text_line ? x->text_line : cur_line(x), col = x->text_line ? x->text_col : cur_col(x);
  if (x->doc == DOC_GPX) {
    if (tk == TX_ELE) {
      trim(&s, &n);
      double h;
      if (!parse_double_n(s, n, &h)) ti_diag(x->r, line, col, "ele", "expected a height in metres, got \"%.*s\"", (int)n, s);
      else if (!height_ok(h))
        ti_diag(x->r, line, col, "ele", "height %.9g m outside [-1e5, 1e8] m (the heights a scene accepts)", h);
      else {
        x->cur.pos.h_m = h;
        x->cur.has_h = true;
      }
    } else if (tk == TX_TIME) {
      double t;
      if (!parse_iso8601(s, n, &t))
        ti_diag(x->r, line, col, "time", "expected an ISO 8601 time such as 2024-05-01T10:00:00Z, got \"%.*s\"",
                (int)(n > 60 ? 60 : n), s);
      else {
        x->cur.t_s = t;
        x->cur.has_time = true;
      }
    } else if (tk == TX_NAME) {
      trim(&s, &n);
      snprintf(x->trk_name, sizeof x->trk_name, "%.*s", (int)n, s);
      x->have_trk_name = true;
    } else if ((strcmp(ln, "trkpt") == 0 || strcmp(ln, "rtept") == 0) && x->in_pt) {
      pt_push(x, x->pt_kind == 0 ? &x->trk : &x->rte, &x->cur);
      x->in_pt = false;
    } else if (strcmp(ln, "trk") == 0 && x->in_trk > 0) {
      x->in_trk--;
    }
  } else if (x->doc == DOC_KML) {
    if (tk == TX_NAME) {
      trim(&s, &n);
      snprintf(x->pm_name, sizeof x->pm_name, "%.*s", (int)n, s);
      x->saw_placemark_name = true;
    } else if (tk == TX_COORDS) {
      kml_parse_coordinates(x);
    } else if (tk == TX_WHEN) {
      double t = NAN;
      if (!parse_iso8601(s, n, &t))
        ti_diag(x->r, line, col, "when", "expected an ISO 8601 time such as 2024-05-01T10:00:00Z, got \"%.*s\"",
                (int)(n > 60 ? 60 : n), s);
      if (x->n_when == x->cap_when) {
        const size_t cap = x->cap_when ? 2 * x->cap_when : 256;
        double *w = realloc(x->when, cap * sizeof *w);
        if (!w) {
          x->oom = true;
          XML_StopParser(x->p, XML_FALSE);
          return;
        }
        x->when = w;
        x->cap_when = cap;
      }
      x->when[x->n_when++] = t;
    } else if (tk == TX_GXCOORD) {
      kml_parse_gxcoord(x);
    } else if (strcmp(ln, "LineString") == 0 && x->in_linestring > 0) {
      x->in_linestring--;
      if (x->in_linestring == 0) kml_geom_end(x);
    } else if (strcmp(ln, "Track") == 0 && x->in_track > 0) {
      x->in_track--;
      if (x->n_when != 0 && x->n_when != x->gxc.n) {
        ti_diag(x->r, x->track_line, x->track_col, "gx:Track", "%zu <when> but %zu <gx:coord>: expected one time per coordinate",
                x->n_when, x->gxc.n);
      } else {
        for (size_t i = 0; i < x->gxc.n; ++i) {
          nav_geopoint p = x->gxc.v[i];
          if (x->n_when) {
            p.t_s = x->when[i];
            p.has_time = isfinite(p.t_s);
          }
          if (!pt_push(x, &x->pm_pts, &p)) return;
        }
      }
      if (x->in_track == 0) kml_geom_end(x);
    } else if (strcmp(ln, "Placemark") == 0 && x->in_placemark > 0) {
      x->in_placemark--;
      if (!kml_placemark_end(x)) return;
      kml_reset_placemark(x);
    }
  }
  x->depth--;
}

/* ------------------------------------------------------------------------------ reading */

nav_track_format nav_track_format_guess(const char *path, const char *head, size_t head_len) {
  const char *dot = path ? strrchr(path, '.') : NULL;
  if (dot) {
    if (strcasecmp(dot, ".gpx") == 0) return NAV_TRACK_FORMAT_GPX;
    if (strcasecmp(dot, ".kml") == 0) return NAV_TRACK_FORMAT_KML;
    if (strcasecmp(dot, ".csv") == 0) return NAV_TRACK_FORMAT_MOTION_DEF;
  }
  if (head) {
    size_t n = head_len < 4096 ? head_len : 4096;
    char buf[4097];
    memcpy(buf, head, n);
    buf[n] = '\0';
    if (strstr(buf, "<gpx")) return NAV_TRACK_FORMAT_GPX;
    if (strstr(buf, "<kml")) return NAV_TRACK_FORMAT_KML;
  }
  return NAV_TRACK_FORMAT_AUTO;
}

void nav_geotrack_free(nav_geotrack *t) {
  if (!t) return;
  free(t->points);
  t->points = NULL;
  t->count = 0;
}

static nav_status read_string_info(const char *text, size_t len, const char *display_name, nav_track_format format,
                                   const char *select_name, nav_geotrack *out, nav_geotrack_info *info,
                                   nav_diag_fn report, void *user);

nav_status nav_geotrack_read_string(const char *text, size_t len, const char *display_name, nav_track_format format,
                                    const char *select_name, nav_geotrack *out, nav_diag_fn report, void *user) {
  return read_string_info(text, len, display_name, format, select_name, out, NULL, report, user);
}

static nav_status read_string_info(const char *text, size_t len, const char *display_name, nav_track_format format,
                                   const char *select_name, nav_geotrack *out, nav_geotrack_info *info,
                                   nav_diag_fn report, void *user) {
  if (!text || !out || !display_name) return NAV_ERR_INVALID_ARG;
  if (format == NAV_TRACK_FORMAT_MOTION_DEF) return NAV_ERR_INVALID_ARG;
  if (len > (size_t)INT32_MAX) return NAV_ERR_INVALID_ARG;
  ti_reader r = {display_name, report, user, 0};
  ti_xml x;
  memset(&x, 0, sizeof x);
  x.r = &r;
  x.want = format;
  x.select = select_name;
  x.p = XML_ParserCreate(NULL);
  if (!x.p) return NAV_ERR_NO_MEMORY;
  XML_SetUserData(x.p, &x);
  XML_SetElementHandler(x.p, on_start, on_end);
  XML_SetCharacterDataHandler(x.p, on_text);
  const enum XML_Status xs = XML_Parse(x.p, text, (int)len, XML_TRUE);
  nav_status st = NAV_OK;
  if (x.oom) {
    st = NAV_ERR_NO_MEMORY;
  } else if (xs != XML_STATUS_OK && r.ndiag == 0) {
    ti_diag(&r, (int)XML_GetCurrentLineNumber(x.p), (int)XML_GetCurrentColumnNumber(x.p) + 1, "",
            "not well-formed XML: %s", XML_ErrorString(XML_GetErrorCode(x.p)));
  }
  pt_list *src = NULL;
  const char *nm = "";
  if (st == NAV_OK && r.ndiag == 0) {
    if (x.doc == DOC_GPX) {
      src = x.trk.n > 0 ? &x.trk : &x.rte;
      nm = x.trk_name;
      if (src->n == 0) ti_diag(&r, 1, 1, "trk", "no track: expected <trk><trkseg><trkpt lat=\"..\" lon=\"..\"> elements");
    } else if (x.doc == DOC_KML) {
      src = &x.kml;
      nm = x.kml_name;
      if (src->n == 0) {
        if (select_name)
          ti_diag(&r, 1, 1, "Placemark", "no track named or numbered \"%s\" (a Placemark with a <LineString> or "
                                         "<gx:Track>; the file holds %d)", select_name, x.n_tracks);
        else
          ti_diag(&r, 1, 1, "Placemark", "no Placemark with a <LineString> or <gx:Track>");
      }
    } else {
      ti_diag(&r, 1, 1, "", "empty document: expected <gpx> or <kml>");
    }
  }
  if (st == NAV_OK && r.ndiag == 0) {
    /* Times must not go backwards. */
    bool all_timed = true;
    for (size_t i = 0; i < src->n; ++i) {
      if (!src->v[i].has_time) all_timed = false;
      if (i > 0 && src->v[i].has_time && src->v[i - 1].has_time && src->v[i].t_s < src->v[i - 1].t_s)
        ti_diag(&r, src->v[i].line, src->v[i].col, "time", "time goes backwards (%.3f s before the previous point)",
                src->v[i - 1].t_s - src->v[i].t_s);
    }
    if (r.ndiag == 0) {
      out->points = src->v;
      out->count = src->n;
      out->all_timed = all_timed && src->n > 0;
      snprintf(out->name, sizeof out->name, "%s", nm);
      if (info) {
        info->tracks_in_file = x.doc == DOC_KML ? x.n_tracks : 1;
        info->track_list[0] = '\0';
        size_t used = 0;
        for (int i = 0; x.doc == DOC_KML && i < x.n_tracks && i < KML_MAX_LIST && used + 1 < sizeof info->track_list;
             ++i) {
          const int k = snprintf(info->track_list + used, sizeof info->track_list - used,
                                 "%s%d \"%.60s\" (line %d, %zu points)", i ? "; " : "", i + 1, x.tracks[i].name,
                                 x.tracks[i].line, x.tracks[i].points);
          if (k > 0)
            used += (size_t)k < sizeof info->track_list - used ? (size_t)k : sizeof info->track_list - used - 1;
        }
      }
      src->v = NULL;
    }
  }
  if (st == NAV_OK && r.ndiag > 0) st = NAV_ERR_PARSE;
  XML_ParserFree(x.p);
  free(x.text);
  free(x.trk.v);
  free(x.rte.v);
  free(x.pm_pts.v);
  free(x.when);
  free(x.gxc.v);
  free(x.kml.v);
  return st;
}

nav_status nav_geotrack_read_file(const char *path, nav_track_format format, const char *select_name, nav_geotrack *out,
                                  nav_diag_fn report, void *user) {
  return nav_geotrack_read_file_info(path, format, select_name, out, NULL, report, user);
}

nav_status nav_geotrack_read_file_info(const char *path, nav_track_format format, const char *select_name,
                                       nav_geotrack *out, nav_geotrack_info *info, nav_diag_fn report, void *user) {
  if (!path || !out) return NAV_ERR_INVALID_ARG;
  FILE *fp = NULL;
  char why[320];
  const nav_status open_st = nav_io_fopen_regular(path, &fp, why, sizeof why);
  if (open_st != NAV_OK) {
    /* A FIFO, device or directory is refused at once; a missing file stays an I/O error. */
    if (open_st == NAV_ERR_PARSE) {
      ti_reader r = {path, report, user, 0};
      ti_diag(&r, 0, 0, "", "%s", why);
    }
    return open_st;
  }
  char *buf = NULL;
  size_t n = 0, cap = 0;
  nav_status st = NAV_OK;
  for (;;) {
    if (n + 65536 > cap) {
      cap = cap ? 2 * cap : 131072;
      if (cap > (size_t)TI_MAX_FILE + 65536) {
        ti_reader r = {path, report, user, 0};
        ti_diag(&r, 0, 0, "", "file larger than %ld MiB", TI_MAX_FILE / (1024 * 1024));
        st = NAV_ERR_PARSE;
        break;
      }
      char *b = realloc(buf, cap);
      if (!b) {
        st = NAV_ERR_NO_MEMORY;
        break;
      }
      buf = b;
    }
    const size_t got = fread(buf + n, 1, cap - n, fp);
    n += got;
    if (got == 0) {
      if (ferror(fp)) st = NAV_ERR_IO;
      break;
    }
  }
  fclose(fp);
  if (st == NAV_OK) {
    if (format == NAV_TRACK_FORMAT_AUTO) format = nav_track_format_guess(path, buf, n);
    st = read_string_info(buf ? buf : "", n, path, format, select_name, out, info, report, user);
  }
  free(buf);
  return st;
}

/* ------------------------------------------------------------------------------ to a scene */

nav_track_import_options nav_track_import_options_default(void) {
  nav_track_import_options o;
  const nav_scene d = nav_scene_default();
  o.speed_mps = 10.0;
  o.tolerance_m = 5.0;
  o.max_merges = 1000;
  o.use_time = true;
  o.attitude_mode = NAV_WP_ATT_GROUND;
  o.limits = d.trajectory.waypoints.limits;
  /* A car at rest logged by a post-processed reference moves by well under 0.1 m/s; 0.2 m/s
     also takes a receiver's jitter of a few centimetres per second at rest. 3 s separates a
     stop from slowing down through a turn or a queue. */
  o.stop_speed_mps = 0.2;
  o.stop_min_s = 3.0;
  return o;
}

/* Distance of p from the segment [a, b]. */
static double seg_dist(nav_vec3 p, nav_vec3 a, nav_vec3 b) {
  const nav_vec3 ab = nav_vec3_sub(b, a), ap = nav_vec3_sub(p, a);
  const double L2 = nav_vec3_dot(ab, ab);
  double u = L2 > 0 ? nav_vec3_dot(ap, ab) / L2 : 0.0;
  if (u < 0) u = 0;
  if (u > 1) u = 1;
  return nav_vec3_norm(nav_vec3_sub(ap, nav_vec3_scale(ab, u)));
}

/* Douglas-Peucker over idx[0..n) (indices into r), marking keep[]. Iterative with a stack. */
static nav_status douglas_peucker(const nav_vec3 *r, const size_t *idx, size_t n, double tol, bool *keep) {
  if (n == 0) return NAV_OK;
  keep[0] = keep[n - 1] = true;
  if (n < 3) return NAV_OK;
  size_t *stack = malloc(2 * n * sizeof *stack);
  if (!stack) return NAV_ERR_NO_MEMORY;
  size_t sp = 0;
  stack[sp++] = 0;
  stack[sp++] = n - 1;
  while (sp > 0) {
    const size_t j = stack[--sp], i = stack[--sp];
    if (j <= i + 1) continue;
    double dmax = -1;
    size_t kmax = i;
    for (size_t k = i + 1; k < j; ++k) {
      const double d = seg_dist(r[idx[k]], r[idx[i]], r[idx[j]]);
      if (d > dmax) {
        dmax = d;
        kmax = k;
      }
    }
    if (dmax > tol) {
      keep[kmax] = true;
      stack[sp++] = i;
      stack[sp++] = kmax;
      stack[sp++] = kmax;
      stack[sp++] = j;
    }
  }
  free(stack);
  return NAV_OK;
}

/* Speed of the track at distinct point k (index into idx): path length over time across the
 * neighbouring points (two on each side where there are), not across a stop (hold[q] > 0: a
 * stop's entry may end the window, with its departure time). */
static double track_speed(const nav_geotrack *track, const nav_vec3 *r, const size_t *idx, const double *hold,
                          size_t m, size_t k) {
  size_t k0 = k >= 2 ? k - 2 : 0, k1 = k + 2 < m ? k + 2 : m - 1;
  for (size_t q = k; q > k0; --q)
    if (hold[q - 1] > 0.0) {
      k0 = q - 1;
      break;
    }
  for (size_t q = k + 1; q <= k1; ++q)
    if (hold[q] > 0.0) {
      k1 = q;
      break;
    }
  double L = 0;
  for (size_t q = k0; q < k1; ++q) L += nav_vec3_norm(nav_vec3_sub(r[idx[q + 1]], r[idx[q]]));
  const double T = track->points[idx[k1]].t_s - (track->points[idx[k0]].t_s + hold[k0]);
  return T > 0 ? L / T : 0.0;
}

/* Replace waypoints j and j + 1 of W by the corner where the extended legs (j-1 -> j) and
 * (j+2 -> j+1) meet in the horizontal plane: a fly-by turn at that corner follows a dense curve
 * of the track (the points of an arc lie on the curve, the corner outside it). false when the
 * legs do not meet ahead of both points (turn of 180 deg or more, or diverging). */
static bool merge_corner(nav_traj_waypoints *W, int *src_of, int j) {
  if (j < 1 || j + 2 >= W->count) return false;
  const nav_vec3 a0 = W->points[j - 1].r_ned_m, a1 = W->points[j].r_ned_m;
  const nav_vec3 b1 = W->points[j + 1].r_ned_m, b2 = W->points[j + 2].r_ned_m;
  const double dax = a1.x - a0.x, day = a1.y - a0.y, dbx = b1.x - b2.x, dby = b1.y - b2.y;
  const double det = dax * (-dby) - day * (-dbx);
  const double la = hypot(dax, day), lb = hypot(dbx, dby);
  if (!(la > 0) || !(lb > 0) || fabs(det) < 1e-6 * la * lb) return false;
  /* a1 + s da = b1 + u db */
  const double rx = b1.x - a1.x, ry = b1.y - a1.y;
  const double sp = (rx * (-dby) - ry * (-dbx)) / det;
  const double u = (dax * ry - day * rx) / det;
  if (!(sp >= 0) || !(u >= 0)) return false;
  nav_waypoint c = W->points[j];
  c.r_ned_m.x = a1.x + sp * dax;
  c.r_ned_m.y = a1.y + sp * day;
  c.r_ned_m.z = 0.5 * (a1.z + b1.z);
  c.speed_mps = fmin(W->points[j].speed_mps, W->points[j + 1].speed_mps);
  W->points[j] = c;
  memmove(&W->points[j + 1], &W->points[j + 2], (size_t)(W->count - j - 2) * sizeof *W->points);
  memmove(&src_of[j + 1], &src_of[j + 2], (size_t)(W->count - j - 2) * sizeof *src_of);
  W->count--;
  return true;
}

/* Drop interior waypoint j. */
static void drop_waypoint(nav_traj_waypoints *W, int *src_of, int j) {
  memmove(&W->points[j], &W->points[j + 1], (size_t)(W->count - j - 1) * sizeof *W->points);
  memmove(&src_of[j], &src_of[j + 1], (size_t)(W->count - j - 1) * sizeof *src_of);
  W->count--;
}

/* Largest distance of a track point from the flown path, sampled every 0.1 s, or at most 10^5
 * times for long plans (then every T / 10^5 s, measured against the chords between samples), so
 * time and memory stay bounded whatever the track's duration. */
static nav_status flown_deviation(const nav_scene *sc, const nav_vec3 *r, size_t n, double *out, long *where) {
  nav_traj *tr = NULL;
  nav_status st = nav_traj_create(sc, 0.01, &tr);
  if (st != NAV_OK) return st;
  const double T = sc->trajectory.duration_s;
  const double h = fmax(0.1, T / 1e5);
  const size_t m = (size_t)ceil(T / h) + 1;
  nav_vec3 *f = malloc(m * sizeof *f);
  if (!f) {
    nav_traj_destroy(tr);
    return NAV_ERR_NO_MEMORY;
  }
  const nav_frame fr = nav_traj_frame(tr);
  for (size_t i = 0; i < m && st == NAV_OK; ++i) {
    nav_traj_state ts;
    st = nav_traj_eval(tr, fmin(T, h * (double)i), &ts);
    if (st == NAV_OK) f[i] = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f).r_ned_m;
  }
  double worst = 0;
  /* At most 20000 track points are checked (every k-th beyond, and the last); the nearest
     segment is searched over the whole path for moderate sizes, beyond that in a window around
     the previous match (tracks run forward along the path). */
  const size_t stride = n > 20000 ? (n + 19999) / 20000 : 1;
  const bool full = (double)(n / stride) * (double)m < 2e8;
  size_t hint = 0;
  for (size_t i = 0; i < n && st == NAV_OK; i = (i + 1 == n) ? n : (i + stride < n ? i + stride : n - 1)) {
    double best = INFINITY;
    size_t j0 = 0, j1 = m - 1;
    if (!full) {
      j0 = hint > 1000 ? hint - 1000 : 0;
      j1 = hint + 5000 < m - 1 ? hint + 5000 : m - 1;
    }
    for (size_t j = j0; j < j1; ++j) {
      const double d = seg_dist(r[i], f[j], f[j + 1]);
      if (d < best) {
        best = d;
        hint = j;
      }
    }
    if (m == 1) best = nav_vec3_norm(nav_vec3_sub(r[i], f[0]));
    if (best > worst) {
      worst = best;
      *where = (long)i;
    }
  }
  free(f);
  nav_traj_destroy(tr);
  *out = worst;
  return st;
}

/* Time of arrival at waypoint j on the track [s] (its track point's time). */
static double wp_track_time(const nav_geotrack *track, const int *src_of, int j) {
  return track->points[src_of[j]].t_s;
}

/*
 * Each part of a timed track between two stops (and the track's ends) is independent of the
 * others: it starts and ends at rest, or at the track's ends. Its speeds (those > 0) are scaled
 * until its planned duration matches the track's time from the departure at its start to the
 * arrival at its end (the fixed point of D(f) = target, by f <- f D / target, which converges
 * fast because D is nearly proportional to 1/f; a scaling the limits cannot fly is undone and
 * the part keeps its last feasible speeds). A part that is two stops with nothing between them
 * (no interior point on the track) is flown at cruise_mps and not scaled.
 */
static nav_status time_sections(const nav_geotrack *track, const int *src_of, nav_scene *sc) {
  nav_traj_waypoints *W = &sc->trajectory.waypoints;
  nav_scene *part = malloc(sizeof *part);
  nav_waypoint *saved = malloc((size_t)W->count * sizeof *saved);
  if (!part || !saved) {
    free(part);
    free(saved);
    return NAV_ERR_NO_MEMORY;
  }
  *part = *sc;
  nav_traj_waypoints *P = &part->trajectory.waypoints;
  P->hold_start_s = 0.0;
  P->hold_end_s = 0.0;
  const double t0 = track->points[0].t_s;
  for (int a = 0; a + 1 < W->count;) {
    int b = a + 1;
    while (b + 1 < W->count && !(W->points[b].hold_s > 0.0))
      ++b;
    const double dep = a == 0 ? t0 + W->hold_start_s : wp_track_time(track, src_of, a) + W->points[a].hold_s;
    const double target = wp_track_time(track, src_of, b) - dep;
    const int n = b - a + 1;
    bool any_speed = false;
    for (int j = a; j <= b; ++j)
      any_speed = any_speed || W->points[j].speed_mps > 0.0;
    double f = 1.0; /* the last scaling applied */
    int halvings = 0;
    for (int it = 0; it < 40 && target > 0.0 && any_speed; ++it) {
      memcpy(P->points, &W->points[a], (size_t)n * sizeof *P->points);
      P->points[0].hold_s = 0.0;
      P->points[n - 1].hold_s = 0.0;
      P->count = n;
      nav_traj_script_info info;
      if (nav_traj_waypoints_plan_info(part, &info, NULL, NULL, 0) != NAV_OK) {
        /* The last scaling cannot be flown: back to the speeds before it, and try half of it
           (a few times; then the part keeps its last feasible speeds). */
        memcpy(&W->points[a], saved, (size_t)n * sizeof *saved);
        if (it == 0 || ++halvings > 6) break;
        f = 1.0 + 0.5 * (f - 1.0);
        for (int j = a; j <= b; ++j)
          W->points[j].speed_mps *= f;
        continue;
      }
      if (fabs(info.duration_s - target) <= 1e-4 * target) break;
      f = info.duration_s / target;
      memcpy(saved, &W->points[a], (size_t)n * sizeof *saved);
      for (int j = a; j <= b; ++j)
        W->points[j].speed_mps *= f;
    }
    a = b;
  }
  free(part);
  free(saved);
  return NAV_OK;
}

/* Thin with @p tol, build the waypoints into @p sc, and plan them; an interior turn that does not
 * fit its legs is merged with its neighbour into the corner of their extended legs (or dropped
 * when there is no such corner) until the plan is feasible. */
static nav_status build_attempt(const nav_geotrack *track, const nav_track_import_options *opt, bool timed,
                                const nav_vec3 *r, const size_t *idx, const double *hold, size_t m,
                                double tol, bool *keep, int *src_of, nav_scene *sc,
                                nav_track_import_report *rep, char *msg, size_t msg_size) {
  memset(keep, 0, m * sizeof *keep);
  nav_status st = NAV_OK;
  /* Stops are kept: the thinning runs on each part between them, and a part that keeps no
     interior point keeps its middle one, so that no leg between two stops needs cruise_mps. */
  for (size_t a = 0; a + 1 < m && st == NAV_OK;) {
    size_t b = a + 1;
    while (b + 1 < m && !(hold[b] > 0.0))
      ++b;
    st = douglas_peucker(r, idx + a, b - a + 1, tol, keep + a);
    if (hold[a] > 0.0 && hold[b] > 0.0 && b > a + 1) {
      bool any = false;
      for (size_t k = a + 1; k < b; ++k)
        any = any || keep[k];
      if (!any) keep[(a + b) / 2] = true;
    }
    a = b;
  }
  if (st != NAV_OK) return st;
  int count = 0;
  for (size_t k = 0; k < m; ++k)
    if (keep[k]) ++count;
  rep->max_dev_m = 0;
  rep->length_m = 0;
  if (count > NAV_MAX_WAYPOINTS) {
    if (msg)
      snprintf(msg, msg_size,
               "%d waypoints remain after thinning with a tolerance of %g m: at most %d are allowed (use a larger "
               "--tolerance)",
               count, tol, NAV_MAX_WAYPOINTS);
    return NAV_ERR_INVALID_ARG;
  }
  nav_traj_waypoints *W = &sc->trajectory.waypoints;
  sc->trajectory.type = NAV_TRAJ_WAYPOINTS;
  W->count = count;
  W->timing = NAV_WP_TIMING_SPEED;
  W->attitude_mode = opt->attitude_mode;
  W->hold_start_s = 0;
  W->hold_end_s = 0;
  W->limits = opt->limits;
  int w = 0;
  for (size_t k = 0; k < m; ++k) {
    if (!keep[k]) continue;
    nav_waypoint *p = &W->points[w];
    memset(p, 0, sizeof *p);
    p->r_ned_m = r[idx[k]];
    p->speed_mps = timed ? track_speed(track, r, idx, hold, m, k) : opt->speed_mps;
    /* A fly-by turn needs some speed: a slow part inside the track that is not a stop is
       driven through slowly. */
    if (timed && w > 0 && k + 1 < m && p->speed_mps < 0.5) p->speed_mps = 0.5;
    if (hold[k] > 0.0) {
      p->speed_mps = 0.0;
      if (k == 0)
        W->hold_start_s = hold[k];
      else if (k + 1 == m)
        W->hold_end_s = hold[k];
      else
        p->hold_s = hold[k];
    }
    src_of[w++] = (int)idx[k];
  }
  rep->merged = 0;
  char pm[400] = "";
  int first_bad = -1;
  char first_msg[400] = "";
  nav_traj_script_info info;
  for (;;) {
    int bad = -1;
    st = nav_traj_waypoints_plan_info(sc, &info, &bad, pm, sizeof pm);
    if (st == NAV_OK || st == NAV_ERR_NO_MEMORY) break;
    if (first_bad < 0 && first_msg[0] == '\0') {
      first_bad = (bad >= 0 && bad < W->count) ? src_of[bad] : -1;
      snprintf(first_msg, sizeof first_msg, "%s", pm);
    }
    if (bad < 1 || bad >= W->count - 1 || rep->merged >= opt->max_merges) break;
    if (W->points[bad].hold_s > 0.0) {
      /* A stop too short to turn in place there: held longer (the part after it is then timed
         to arrive as the track does); a stop is never merged away. */
      const char *need = strstr(pm, "in place takes ");
      if (need == NULL || W->points[bad].hold_s > 1e6) break;
      /* The planner's message gives the turn's duration (4 digits): a little more than that. */
      const double need_s = strtod(need + strlen("in place takes "), NULL);
      W->points[bad].hold_s = fmax(1.01 * W->points[bad].hold_s, 1.001 * need_s);
      rep->stops_lengthened++;
      continue;
    }
    /* Merge the turn with the neighbour across its shorter leg (never a stop). */
    const double lprev = nav_vec3_norm(nav_vec3_sub(W->points[bad].r_ned_m, W->points[bad - 1].r_ned_m));
    const double lnext = nav_vec3_norm(nav_vec3_sub(W->points[bad + 1].r_ned_m, W->points[bad].r_ned_m));
    int j = (lprev < lnext) ? bad - 1 : bad;
    if (j < 1) j = bad;
    if (j + 2 >= W->count) j = bad - 1;
    const bool stop_in_pair =
        j >= 1 && j + 1 < W->count && (W->points[j].hold_s > 0.0 || W->points[j + 1].hold_s > 0.0);
    if (stop_in_pair || !merge_corner(W, src_of, j)) drop_waypoint(W, src_of, bad);
    rep->merged++;
    if (W->count < 2) break;
  }
  if (st != NAV_OK) {
    rep->bad_point = first_bad;
    if (msg)
      snprintf(msg, msg_size, "the waypoint trajectory is infeasible: %s%s", first_msg[0] ? first_msg : pm,
               rep->merged ? " (still infeasible after merging turns)" : "");
    return st;
  }
  if (timed) {
    st = time_sections(track, src_of, sc);
    if (st == NAV_OK) st = nav_traj_waypoints_plan_info(sc, &info, NULL, pm, sizeof pm);
    if (st != NAV_OK) {
      if (msg) snprintf(msg, msg_size, "the waypoint trajectory is infeasible after timing it: %s", pm);
      return st;
    }
  }
  rep->stops = (W->hold_start_s > 0.0) + (W->hold_end_s > 0.0);
  rep->stop_s = W->hold_start_s + W->hold_end_s;
  for (int k = 0; k < W->count; ++k)
    if (W->points[k].hold_s > 0.0) {
      rep->stops++;
      rep->stop_s += W->points[k].hold_s;
    }
  for (int k = 1; k < W->count; ++k)
    rep->length_m += nav_vec3_norm(nav_vec3_sub(W->points[k].r_ned_m, W->points[k - 1].r_ned_m));
  sc->trajectory.duration_s = info.duration_s;
  rep->duration_s = info.duration_s;
  rep->waypoints = W->count;
  rep->timed = timed;
  rep->bad_point = -1;
  /* The output epoch at t = 0 sees the first leg's heading: set initial_attitude to it. */
  const nav_vec3 d = nav_vec3_sub(W->points[1].r_ned_m, W->points[0].r_ned_m);
  sc->trajectory.initial_attitude.roll_rad = 0;
  sc->trajectory.initial_attitude.pitch_rad = atan2(-d.z, hypot(d.x, d.y));
  sc->trajectory.initial_attitude.yaw_rad = atan2(d.y, d.x);
  return NAV_OK;
}

nav_status nav_geotrack_to_scene(const nav_geotrack *track, const nav_track_import_options *opt, nav_scene *scene,
                                 nav_track_import_report *rep, char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  nav_track_import_report dummy;
  if (!rep) rep = &dummy;
  memset(rep, 0, sizeof *rep);
  rep->bad_point = -1;
  rep->max_dev_point = -1;
  if (!track || !opt || !scene) return NAV_ERR_INVALID_ARG;
  rep->points_in = track->count;
  if (!(opt->speed_mps > 0) || !isfinite(opt->speed_mps) || !(opt->tolerance_m >= 0) ||
      !isfinite(opt->tolerance_m) || opt->max_merges < 0 || !(opt->stop_speed_mps >= 0) ||
      !isfinite(opt->stop_speed_mps) || !(opt->stop_min_s >= 0) || !isfinite(opt->stop_min_s)) {
    if (msg)
      snprintf(msg, msg_size,
               "speed must be > 0, the tolerance >= 0, max_merges >= 0 and the stop threshold "
               "and minimum duration >= 0");
    return NAV_ERR_INVALID_ARG;
  }
  if (track->count < 2) {
    if (msg) snprintf(msg, msg_size, "the track has %zu point(s): at least 2 are needed", track->count);
    return NAV_ERR_INVALID_ARG;
  }
  const bool timed = opt->use_time && track->all_timed;
  nav_scene *sc = malloc(sizeof *sc); /* about 0.5 MB: not on the stack */
  const size_t n = track->count;
  nav_vec3 *r = malloc(n * sizeof *r);
  size_t *idx = malloc(n * sizeof *idx);
  bool *keep = calloc(n, sizeof *keep);
  int *src_of = malloc(n * sizeof *src_of);
  double *hold = calloc(n, sizeof *hold);      /* per distinct point: the stop that starts there [s] */
  long *stop_to = malloc(n * sizeof *stop_to); /* per track point: the last point of its stop, or -1 */
  nav_status st = NAV_OK;
  if (!sc || !r || !idx || !keep || !src_of || !hold || !stop_to) {
    st = NAV_ERR_NO_MEMORY;
    goto done;
  }
  *sc = *scene;
  sc->earth.model = NAV_EARTH_WGS84;
  sc->earth.origin_lat_rad = track->points[0].pos.lat_rad;
  sc->earth.origin_lon_rad = track->points[0].pos.lon_rad;
  sc->earth.origin_h_m = track->points[0].pos.h_m;
  const nav_frame fr = nav_frame_from_scene(sc);
  for (size_t i = 0; i < n; ++i) r[i] = nav_frame_geodetic_to_local(&fr, track->points[i].pos);
  if (timed) rep->track_duration_s = track->points[n - 1].t_s - track->points[0].t_s;
  /* Stops of a timed track: runs of points whose speed is below stop_speed_mps, lasting at least
     stop_min_s. A point's speed is its displacement over +-0.5 s (at least to its neighbours):
     at 10 Hz a receiver's centimetres of jitter at rest are 0.2 m/s from one point to the next,
     but a few cm/s over a second. A run is then widened by the neighbouring intervals whose own
     speed is below the threshold, so that at 1 Hz it starts at the arrival and ends at the
     departure rather than a point inside them. */
  for (size_t i = 0; i < n; ++i)
    stop_to[i] = -1;
  if (timed && opt->stop_min_s > 0.0) {
    const nav_geopoint *P = track->points;
    bool *slow = keep; /* scratch: keep[] is cleared by build_attempt */
    size_t lo = 0, hi = 0;
    for (size_t k = 0; k < n; ++k) {
      /* a: the first point at most 0.5 s before k (k - 1 at the least); b: the last at most
         0.5 s after it (k + 1 at the least). */
      while (lo < k && P[lo].t_s < P[k].t_s - 0.5)
        ++lo;
      const size_t a = k == 0 ? 0 : (lo < k ? lo : k - 1);
      if (hi < k) hi = k;
      while (hi + 1 < n && (hi == k || P[hi + 1].t_s <= P[k].t_s + 0.5))
        ++hi;
      const size_t b = hi;
      const double d = nav_vec3_norm(nav_vec3_sub(r[b], r[a])), dt = P[b].t_s - P[a].t_s;
      slow[k] = a != b && (dt > 0.0 ? d < opt->stop_speed_mps * dt : d < 1e-3);
    }
    size_t floor_idx = 0; /* a run is never widened back into the previous stop */
    for (size_t i = 0; i < n;) {
      if (!slow[i]) {
        ++i;
        continue;
      }
      size_t j = i;
      while (j + 1 < n && slow[j + 1])
        ++j;
      const size_t next = j + 1;
      size_t a = i, b = j;
      while (a > floor_idx &&
             nav_vec3_norm(nav_vec3_sub(r[a], r[a - 1])) < opt->stop_speed_mps * (P[a].t_s - P[a - 1].t_s))
        --a;
      while (b + 1 < n &&
             nav_vec3_norm(nav_vec3_sub(r[b + 1], r[b])) < opt->stop_speed_mps * (P[b + 1].t_s - P[b].t_s))
        ++b;
      if (b > a && P[b].t_s - P[a].t_s >= opt->stop_min_s) {
        stop_to[a] = (long)b;
        floor_idx = b;
        i = b + 1;
      } else {
        i = next;
      }
    }
  }
  /* Drop repeated points (a vehicle at rest repeats its position); the true end is kept. A stop
     is one point, its first, held for the stop's duration; its other points are at rest. */
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    if (stop_to[i] >= 0) {
      const size_t j = (size_t)stop_to[i];
      const bool same = m > 0 && nav_vec3_norm(nav_vec3_sub(r[i], r[idx[m - 1]])) < 1e-3;
      if (!same) idx[m++] = i;
      hold[m - 1] = track->points[j].t_s - track->points[idx[m - 1]].t_s;
      i = j;
      continue;
    }
    if (m > 0 && nav_vec3_norm(nav_vec3_sub(r[i], r[idx[m - 1]])) < 1e-3) {
      if (i == n - 1 && !(hold[m - 1] > 0.0)) idx[m - 1] = i;
      continue;
    }
    idx[m++] = i;
  }
  if (m < 2) {
    if (msg) snprintf(msg, msg_size, "the track's points all coincide: at least 2 distinct points are needed");
    st = NAV_ERR_INVALID_ARG;
    goto done;
  }
  st = build_attempt(track, opt, timed, r, idx, hold, m, opt->tolerance_m, keep, src_of, sc, rep, msg,
                     msg_size);
  if (st != NAV_OK) goto done;
  rep->max_dev_point = -1;
  st = flown_deviation(sc, r, n, &rep->max_dev_m, &rep->max_dev_point);
  if (st != NAV_OK) {
    if (msg) snprintf(msg, msg_size, "the planned trajectory cannot be evaluated: %s", nav_status_str(st));
    goto done;
  }
  *scene = *sc;
done:
  free(sc);
  free(r);
  free(idx);
  free(keep);
  free(src_of);
  free(hold);
  free(stop_to);
  return st;
}
