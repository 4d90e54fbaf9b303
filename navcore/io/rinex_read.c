/*
 * RINEX 3 observation and navigation readers, and the raw-measurement source of a tightly
 * coupled replay (nav_rinex_read.h). Column numbers in comments are the 1-based columns of the
 * RINEX 3.04 format tables (A1-A11).
 */
#define _POSIX_C_SOURCE 200809L
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_rinex_read.h"

/* ---------------------------------------------------------------- lines */

/* A line source over a FILE or memory; one line at a time into buf (no line end, NUL-terminated). */
typedef struct lines {
  FILE *f;
  const char *mem;
  size_t mem_len, mem_pos;
  long file_size, consumed;
  char buf[NAV_RINEX_MAX_LINE + 2];
  size_t n;
  long line; /* 1-based number of the line in buf */
  bool eof;
  nav_diag diag;
  nav_status failed;
  locale_t c_numeric;
} lines;

static void diag_set(nav_diag *d, const char *file, int line, int col, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static void diag_set(nav_diag *d, const char *file, int line, int col, const char *fmt, ...) {
  if (!d) return;
  char name[sizeof d->file];
  snprintf(name, sizeof name, "%s", file ? file : "");
  memset(d, 0, sizeof *d);
  memcpy(d->file, name, sizeof d->file);
  d->line = line;
  d->col = line > 0 ? (col > 0 ? col : 1) : 0;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d->message, sizeof d->message, fmt, ap);
  va_end(ap);
}

static nav_status lfail(lines *L, nav_status st, int col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static nav_status lfail(lines *L, nav_status st, int col, const char *fmt, ...) {
  char msg[sizeof L->diag.message];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  diag_set(&L->diag, L->diag.file, (int)L->line, col, "%s", msg);
  L->failed = st;
  return st;
}

static nav_status lines_init(lines *L, const char *path, const char *text, size_t len, const char *name,
                             nav_diag *diag) {
  memset(L, 0, sizeof *L);
  snprintf(L->diag.file, sizeof L->diag.file, "%s", name ? name : "");
  L->c_numeric = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
  if (L->c_numeric == (locale_t)0) return NAV_ERR_NO_MEMORY;
  if (path) {
    /* The readers' one way to open an input (nav_io.h): a FIFO, device or directory is refused at
     * once instead of blocking or reading forever. */
    char why[320];
    const nav_status st = nav_io_fopen_regular(path, &L->f, why, sizeof why);
    if (st != NAV_OK) {
      diag_set(diag, path, 0, 0, "%s", why);
      return st;
    }
    if (fseek(L->f, 0, SEEK_END) == 0) L->file_size = ftell(L->f);
    if (fseek(L->f, 0, SEEK_SET) != 0) L->file_size = 0;
  } else {
    L->mem = text;
    L->mem_len = len;
    L->file_size = (long)len;
  }
  return NAV_OK;
}

static void lines_close(lines *L) {
  if (L->f) fclose(L->f);
  L->f = NULL;
  if (L->c_numeric != (locale_t)0) freelocale(L->c_numeric);
  L->c_numeric = (locale_t)0;
}

static int lgetc(lines *L) {
  if (L->f) return getc(L->f);
  if (L->mem_pos >= L->mem_len) return EOF;
  return (unsigned char)L->mem[L->mem_pos++];
}

/* Next line into L->buf; *got false at the end of the input. CR-LF and a last line without a
 * line end are accepted; a NUL byte or a line longer than NAV_RINEX_MAX_LINE is an error. */
static nav_status next_line(lines *L, bool *got) {
  *got = false;
  if (L->failed != NAV_OK) return L->failed;
  if (L->eof) return NAV_OK;
  size_t n = 0;
  int c = lgetc(L);
  if (c == EOF) {
    L->eof = true;
    if (L->f && ferror(L->f)) {
      ++L->line;
      return lfail(L, NAV_ERR_IO, 1, "read error");
    }
    return NAV_OK;
  }
  ++L->line;
  for (; c != EOF && c != '\n'; c = lgetc(L)) {
    L->consumed++;
    if (c == '\0') return lfail(L, NAV_ERR_PARSE, (int)n + 1, "a NUL byte; expected a text file");
    if (n >= NAV_RINEX_MAX_LINE)
      return lfail(L, NAV_ERR_PARSE, NAV_RINEX_MAX_LINE + 1,
                   "line longer than %d bytes; expected RINEX records (80 columns, longer only for "
                   "observation records)",
                   NAV_RINEX_MAX_LINE);
    L->buf[n++] = (char)c;
  }
  if (c == '\n') L->consumed++;
  if (c == EOF) {
    L->eof = true;
    if (L->f && ferror(L->f)) return lfail(L, NAV_ERR_IO, 1, "read error");
  }
  if (n > 0 && L->buf[n - 1] == '\r') --n;
  L->buf[n] = '\0';
  L->n = n;
  *got = true;
  return NAV_OK;
}

/* Columns [col, col + w) (1-based) of the line, blank-padded beyond its end, into dst. */
static void field(const lines *L, int col, int w, char *dst) {
  for (int i = 0; i < w; ++i) {
    const size_t k = (size_t)(col - 1 + i);
    dst[i] = k < L->n ? L->buf[k] : ' ';
  }
  dst[w] = '\0';
}

static bool all_blank(const char *s) {
  for (; *s; ++s)
    if (*s != ' ') return false;
  return true;
}

/* Printable copy of a field for messages. */
static void shown(const char *s, char *dst, size_t cap) {
  size_t j = 0;
  for (; *s && j + 1 < cap; ++s)
    dst[j++] = ((unsigned char)*s < 0x20 || (unsigned char)*s >= 0x7f) ? '?' : *s;
  dst[j] = '\0';
}

/* A number in columns [col, col + w): Fortran F, E or D form, blanks around it. *blank set when
 * the field is empty (then *v = 0). */
static nav_status num(lines *L, int col, int w, const char *what, double *v, bool *blank) {
  char f[64], s[64];
  if (w > 60) w = 60;
  field(L, col, w, f);
  *v = 0.0;
  if (blank) *blank = false;
  if (all_blank(f)) {
    if (blank) {
      *blank = true;
      return NAV_OK;
    }
    return lfail(L, NAV_ERR_PARSE, col, "%s: blank; expected a number in columns %d-%d", what, col,
                 col + w - 1);
  }
  int a = 0, b = w;
  while (f[a] == ' ')
    ++a;
  while (b > a && f[b - 1] == ' ')
    --b;
  int k = 0;
  bool ok = true;
  for (int i = a; i < b; ++i) {
    char c = f[i];
    if (c == 'D' || c == 'd') c = 'E';
    if (!((c >= '0' && c <= '9') || c == '.' || c == '+' || c == '-' || c == 'E' || c == 'e')) ok = false;
    s[k++] = c;
  }
  s[k] = '\0';
  char *end = NULL;
  double x = NAN;
  if (ok) {
    /* uselocale is per thread: "C" numbers whatever the process locale. */
    const locale_t old = uselocale(L->c_numeric);
    x = strtod(s, &end);
    uselocale(old);
  }
  if (!ok || end != s + k || !isfinite(x)) {
    char sh[64];
    shown(f + a, sh, sizeof sh);
    sh[b - a < (int)sizeof sh ? b - a : (int)sizeof sh - 1] = '\0';
    return lfail(L, NAV_ERR_PARSE, col + a,
                 "%s: \"%s\" is not a number; expected a finite number in columns %d-%d", what, sh, col,
                 col + w - 1);
  }
  *v = x;
  return NAV_OK;
}

/* An integer field in [lo, hi]. */
static nav_status inum(lines *L, int col, int w, const char *what, int lo, int hi, int *v) {
  double x = 0.0;
  nav_status st = num(L, col, w, what, &x, NULL);
  if (st != NAV_OK) return st;
  if (x != floor(x) || x < lo || x > hi)
    return lfail(L, NAV_ERR_PARSE, col, "%s: %.12g; expected an integer in [%d, %d] in columns %d-%d", what,
                 x, lo, hi, col, col + w - 1);
  *v = (int)x;
  return NAV_OK;
}

/* The header label of the line (columns 61-80, trailing blanks dropped). */
static void label_of(const lines *L, char *dst) {
  field(L, 61, 20, dst);
  for (int i = 19; i >= 0 && dst[i] == ' '; --i)
    dst[i] = '\0';
}

/* Civil epoch "yyyy mm dd hh mm ss.s" fields to GPS time, checked. cols: year, month, day, hour,
 * minute (integer fields) and second (real). */
static nav_status epoch_fields(lines *L, const int col[6], const int w[6], double *t_gps) {
  static const char *const names[6] = {"year", "month", "day", "hour", "minute", "second"};
  static const int lo[5] = {1980, 1, 1, 0, 0}, hi[5] = {2200, 12, 31, 23, 59};
  int v[5];
  for (int i = 0; i < 5; ++i) {
    nav_status st = inum(L, col[i], w[i], names[i], lo[i], hi[i], &v[i]);
    if (st != NAV_OK) return st;
  }
  double sec = 0.0;
  nav_status st = num(L, col[5], w[5], "second", &sec, NULL);
  if (st != NAV_OK) return st;
  if (!(sec >= 0.0 && sec < 61.0))
    return lfail(L, NAV_ERR_PARSE, col[5], "second: %.12g; expected 0 <= second < 61", sec);
  static const int mdays[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (v[2] > mdays[v[1] - 1])
    return lfail(L, NAV_ERR_PARSE, col[2], "day: %d; month %d has at most %d days", v[2], v[1],
                 mdays[v[1] - 1]);
  *t_gps = nav_gnss_gps_time_s(v[0], v[1], v[2], v[3], v[4], sec);
  return NAV_OK;
}

/* The version line (first line of both file kinds): F9.2 version, file type at column 21,
 * system at column 41. */
static nav_status version_line(lines *L, char want_type, double *version, char *system) {
  bool got = false;
  nav_status st = next_line(L, &got);
  if (st != NAV_OK) return st;
  if (!got) {
    L->line = 1;
    return lfail(L, NAV_ERR_PARSE, 1,
                 "empty file; expected a RINEX 3 header starting with RINEX VERSION / TYPE");
  }
  char lab[21];
  label_of(L, lab);
  if (strcmp(lab, "RINEX VERSION / TYPE") != 0)
    return lfail(L, NAV_ERR_PARSE, 61,
                 "first line: label \"%s\"; expected RINEX VERSION / TYPE in columns 61-80", lab);
  st = num(L, 1, 9, "RINEX version", version, NULL);
  if (st != NAV_OK) return st;
  if (!(*version >= 3.0 && *version < 4.0))
    return lfail(L, NAV_ERR_PARSE, 1, "RINEX version %.2f; expected 3.00 to 3.05 (RINEX 3)", *version);
  char t[2];
  field(L, 21, 1, t);
  if (t[0] != want_type)
    return lfail(L, NAV_ERR_PARSE, 21, "file type '%c'; expected '%c' (%s file) in column 21",
                 t[0] == ' ' ? '?' : t[0], want_type, want_type == 'O' ? "observation" : "navigation");
  field(L, 41, 1, t);
  *system = t[0] == ' ' ? 'G' : t[0];
  return NAV_OK;
}

static int sys_index(char c) {
  return c == 'G' ? NAV_GNSS_SYS_GPS : c == 'R' ? NAV_GNSS_SYS_GLONASS : -1;
}

static bool known_sys(char c) {
  return c == 'G' || c == 'R' || c == 'E' || c == 'C' || c == 'J' || c == 'I' || c == 'S';
}

/* ---------------------------------------------------------------- observation files */

struct nav_rinex_obs_reader {
  lines L;
  nav_rinex_obs_header h;
  nav_rinex_obs_info info;
  /* Per system: the file's type count and, per file type, its kept index or -1. */
  int n_file[NAV_GNSS_SYS_COUNT];
  int keep[NAV_GNSS_SYS_COUNT][NAV_RINEX_MAX_FILE_TYPES];
  double t_prev;
  bool have_prev;
  long events;
};

/* The types the replay and its users need; the others are skipped. */
static bool kept_type(const char *t) {
  return strcmp(t, "C1C") == 0 || strcmp(t, "L1C") == 0 || strcmp(t, "D1C") == 0 || strcmp(t, "S1C") == 0;
}

static nav_status obs_header(nav_rinex_obs_reader *r) {
  lines *L = &r->L;
  nav_rinex_obs_header *h = &r->h;
  nav_rinex_obs_info *in = &r->info;
  memset(h, 0, sizeof *h);
  memset(in, 0, sizeof *in);
  nav_status st = version_line(L, 'O', &in->version, &in->system);
  if (st != NAV_OK) return st;
  int pending_sys = -2, pending_left = 0; /* SYS / # / OBS TYPES continuation */
  int glo_left = -1;                      /* GLONASS SLOT / FRQ # entries still expected */
  bool any_types = false;
  char time_sys[4] = "";
  for (;;) {
    bool got = false;
    st = next_line(L, &got);
    if (st != NAV_OK) return st;
    if (!got) {
      ++L->line;
      return lfail(L, NAV_ERR_PARSE, 1, "end of file inside the header; expected END OF HEADER");
    }
    char lab[21];
    label_of(L, lab);
    if (strcmp(lab, "END OF HEADER") == 0) break;
    if (strcmp(lab, "SYS / # / OBS TYPES") == 0) {
      char c[2];
      field(L, 1, 1, c);
      int idx = 0, count = 0;
      if (c[0] == ' ') {
        if (pending_left <= 0)
          return lfail(L, NAV_ERR_PARSE, 1,
                       "SYS / # / OBS TYPES continuation line without a preceding record; expected a "
                       "system letter (G, R, E, C, J, I, S) in column 1");
        idx = pending_sys;
        count = pending_left;
      } else {
        if (pending_left > 0)
          return lfail(L, NAV_ERR_PARSE, 1,
                       "%d observation type(s) of the previous system still missing; expected a continuation "
                       "line (blank column 1)",
                       pending_left);
        if (!known_sys(c[0]))
          return lfail(L, NAV_ERR_PARSE, 1, "satellite system '%c'; expected G, R, E, C, J, I or S",
                       (unsigned char)c[0] < 0x20 || (unsigned char)c[0] >= 0x7f ? '?' : c[0]);
        st = inum(L, 4, 3, "number of observation types", 1, 999, &count);
        if (st != NAV_OK) return st;
        any_types = true;
        idx = sys_index(c[0]);
        if (idx < 0) {
          in->skipped_systems++;
        } else {
          if (r->n_file[idx] > 0)
            return lfail(L, NAV_ERR_PARSE, 1, "second SYS / # / OBS TYPES record of system %c; expected one",
                         c[0]);
          if (count > NAV_RINEX_MAX_FILE_TYPES)
            return lfail(L, NAV_ERR_PARSE, 4, "%d observation types; at most %d are supported", count,
                         NAV_RINEX_MAX_FILE_TYPES);
        }
      }
      const int on_line = count < 13 ? count : 13;
      for (int k = 0; k < on_line; ++k) {
        char t[4];
        field(L, 8 + 4 * k, 3, t);
        if (t[0] < 'A' || t[0] > 'Z' || t[1] < '0' || t[1] > '9' || t[2] == ' ' ||
            (unsigned char)t[2] < 0x20 || (unsigned char)t[2] >= 0x7f) {
          char sh[8];
          shown(t, sh, sizeof sh);
          return lfail(L, NAV_ERR_PARSE, 8 + 4 * k,
                       "observation type \"%s\"; expected a RINEX 3 type such as C1C (type, band, attribute)",
                       sh);
        }
        if (idx >= 0) {
          const int j = r->n_file[idx]++;
          r->keep[idx][j] = -1;
          if (kept_type(t) && h->n_types[idx] < NAV_RINEX_MAX_OBS_TYPES) {
            r->keep[idx][j] = h->n_types[idx];
            memcpy(h->types[idx][h->n_types[idx]++], t, 4);
          }
        }
      }
      pending_sys = idx;
      pending_left = count - on_line;
      continue;
    }
    if (pending_left > 0)
      return lfail(
          L, NAV_ERR_PARSE, 61,
          "label \"%s\" while %d observation type(s) are still missing; expected a SYS / # / OBS TYPES "
          "continuation line",
          lab, pending_left);
    if (strcmp(lab, "MARKER NAME") == 0) {
      field(L, 1, 60, h->marker_name);
      for (int i = 59; i >= 0 && h->marker_name[i] == ' '; --i)
        h->marker_name[i] = '\0';
    } else if (strcmp(lab, "APPROX POSITION XYZ") == 0) {
      double x[3];
      for (int i = 0; i < 3; ++i) {
        st = num(L, 1 + 14 * i, 14, "approximate position", &x[i], NULL);
        if (st != NAV_OK) return st;
      }
      h->approx_pos_e_m = nav_vec3_make(x[0], x[1], x[2]);
    } else if (strcmp(lab, "ANTENNA: DELTA H/E/N") == 0) {
      double x[3];
      for (int i = 0; i < 3; ++i) {
        st = num(L, 1 + 14 * i, 14, "antenna delta", &x[i], NULL);
        if (st != NAV_OK) return st;
      }
      h->antenna_delta_hen_m = nav_vec3_make(x[0], x[1], x[2]);
    } else if (strcmp(lab, "INTERVAL") == 0) {
      st = num(L, 1, 10, "interval", &h->interval_s, NULL);
      if (st != NAV_OK) return st;
      if (!(h->interval_s > 0.0))
        return lfail(L, NAV_ERR_PARSE, 1, "interval %.12g s; expected > 0", h->interval_s);
    } else if (strcmp(lab, "LEAP SECONDS") == 0) {
      st = inum(L, 1, 6, "leap seconds", 0, 99, &h->leap_seconds);
      if (st != NAV_OK) return st;
      in->has_leap = true;
    } else if (strcmp(lab, "TIME OF FIRST OBS") == 0) {
      static const int col[6] = {1, 7, 13, 19, 25, 31}, w[6] = {6, 6, 6, 6, 6, 13};
      st = epoch_fields(L, col, w, &h->t_first_gps_s);
      if (st != NAV_OK) return st;
      field(L, 49, 3, time_sys);
      in->has_first = true;
      if (!(all_blank(time_sys) || strcmp(time_sys, "GPS") == 0)) {
        char sh[8];
        shown(time_sys, sh, sizeof sh);
        return lfail(L, NAV_ERR_PARSE, 49,
                     "time system \"%s\"; only GPS time is supported (expected GPS, or blank in a GPS file)",
                     sh);
      }
      if (all_blank(time_sys) && in->system != 'G')
        return lfail(
            L, NAV_ERR_PARSE, 49,
            "blank time system in a file of system %c; expected GPS in columns 49-51 (only GPS time is "
            "supported)",
            in->system);
    } else if (strcmp(lab, "GLONASS SLOT / FRQ #") == 0) {
      int n = 0;
      if (glo_left < 0) {
        st = inum(L, 1, 3, "number of GLONASS satellites", 0, NAV_RINEX_MAX_GLO_SLOTS, &n);
        if (st != NAV_OK) return st;
        glo_left = n;
      } else {
        char c[4];
        field(L, 1, 3, c);
        if (!all_blank(c))
          return lfail(L, NAV_ERR_PARSE, 1,
                       "second GLONASS SLOT / FRQ # record; expected a continuation line "
                       "(blank columns 1-3)");
      }
      for (int k = 0; k < 8 && glo_left > 0; ++k, --glo_left) {
        char c[4];
        field(L, 5 + 7 * k, 3, c);
        int slot = 0, fk = 0;
        if (c[0] != 'R')
          return lfail(L, NAV_ERR_PARSE, 5 + 7 * k,
                       "GLONASS SLOT / FRQ #: '%c'; expected R and the slot (Rnn)",
                       (unsigned char)c[0] < 0x20 || (unsigned char)c[0] >= 0x7f ? '?' : c[0]);
        st = inum(L, 6 + 7 * k, 2, "GLONASS slot", 1, 24, &slot);
        if (st == NAV_OK) st = inum(L, 9 + 7 * k, 2, "GLONASS frequency number", -7, 13, &fk);
        if (st != NAV_OK) return st;
        h->glo_slot[h->n_glo] = slot;
        h->glo_channel[h->n_glo] = fk;
        h->n_glo++;
      }
    }
    /* Other labels are not needed for the replay. */
  }
  if (pending_left > 0)
    return lfail(L, NAV_ERR_PARSE, 1, "END OF HEADER while %d observation type(s) are missing", pending_left);
  if (glo_left > 0)
    return lfail(L, NAV_ERR_PARSE, 1, "END OF HEADER while %d GLONASS SLOT / FRQ # entries are missing",
                 glo_left);
  if (!any_types)
    return lfail(L, NAV_ERR_PARSE, 1,
                 "the header has no SYS / # / OBS TYPES record; expected one per system");
  if (!in->has_first && in->system != 'G')
    return lfail(L, NAV_ERR_PARSE, 1,
                 "no TIME OF FIRST OBS in a file of system %c; expected it with time system GPS", in->system);
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s)
    in->file_types[s] = r->n_file[s];
  return NAV_OK;
}

static nav_status obs_open(const char *path, const char *text, size_t len, const char *name,
                           nav_rinex_obs_reader **out, nav_diag *diag) {
  if (!out || (!path && !text && len > 0)) return NAV_ERR_INVALID_ARG;
  nav_rinex_obs_reader *r = calloc(1, sizeof *r);
  if (!r) return NAV_ERR_NO_MEMORY;
  nav_status st = lines_init(&r->L, path, text, len, name, diag);
  if (st == NAV_OK) {
    st = obs_header(r);
    if (st != NAV_OK && diag) *diag = r->L.diag;
  }
  if (st != NAV_OK) {
    lines_close(&r->L);
    free(r);
    return st;
  }
  r->L.failed = NAV_OK;
  *out = r;
  return NAV_OK;
}

nav_status nav_rinex_obs_open(const char *path, nav_rinex_obs_reader **out, nav_diag *diag) {
  if (!path) return NAV_ERR_INVALID_ARG;
  return obs_open(path, NULL, 0, path, out, diag);
}

nav_status nav_rinex_obs_open_memory(const char *text, size_t len, const char *display_name,
                                     nav_rinex_obs_reader **out, nav_diag *diag) {
  return obs_open(NULL, text ? text : "", text ? len : 0, display_name ? display_name : "memory", out, diag);
}

void nav_rinex_obs_destroy(nav_rinex_obs_reader *r) {
  if (!r) return;
  lines_close(&r->L);
  free(r);
}

const nav_rinex_obs_header *nav_rinex_obs_get_header(const nav_rinex_obs_reader *r) {
  return r ? &r->h : NULL;
}
const nav_rinex_obs_info *nav_rinex_obs_get_info(const nav_rinex_obs_reader *r) {
  return r ? &r->info : NULL;
}

int nav_rinex_obs_type_index(const nav_rinex_obs_header *h, nav_gnss_system sys, const char *type) {
  if (!h || !type || (int)sys < 0 || (int)sys >= NAV_GNSS_SYS_COUNT) return -1;
  for (int k = 0; k < h->n_types[sys] && k < NAV_RINEX_MAX_OBS_TYPES; ++k)
    if (strcmp(h->types[sys][k], type) == 0) return k;
  return -1;
}
const nav_diag *nav_rinex_obs_diag(const nav_rinex_obs_reader *r) {
  return r ? &r->L.diag : NULL;
}
long nav_rinex_obs_events(const nav_rinex_obs_reader *r) {
  return r ? r->events : 0;
}
double nav_rinex_obs_fraction(const nav_rinex_obs_reader *r) {
  if (!r || r->L.file_size <= 0) return 1.0;
  const double f = (double)r->L.consumed / (double)r->L.file_size;
  return f > 1.0 ? 1.0 : f;
}

/* One observation record line of an epoch: satellite in columns 1-3, then 16 columns per type
 * (F14.3, LLI, signal strength). */
static nav_status obs_sat_line(nav_rinex_obs_reader *r, nav_rinex_obs_epoch *ep, int *skipped) {
  lines *L = &r->L;
  char c[4];
  field(L, 1, 3, c);
  if (c[0] == '>')
    return lfail(L, NAV_ERR_PARSE, 1,
                 "an epoch record where a satellite's observations were expected (the "
                 "previous epoch announced more satellites)");
  if (!known_sys(c[0]))
    return lfail(L, NAV_ERR_PARSE, 1,
                 "satellite system '%c'; expected G, R, E, C, J, I or S and a number (e.g. G05)",
                 (unsigned char)c[0] < 0x20 || (unsigned char)c[0] >= 0x7f ? '?' : c[0]);
  int prn = 0;
  nav_status st = inum(L, 2, 2, "satellite number", 1, 99, &prn);
  if (st != NAV_OK) return st;
  const int s = sys_index(c[0]);
  if (s < 0) {
    ++*skipped;
    return NAV_OK;
  }
  if (r->n_file[s] == 0)
    return lfail(L, NAV_ERR_PARSE, 1,
                 "satellite %c%02d of a system without SYS / # / OBS TYPES in the header", c[0], prn);
  if (s == NAV_GNSS_SYS_GLONASS && prn > 24)
    return lfail(L, NAV_ERR_PARSE, 2, "GLONASS slot %d; expected 1..24", prn);
  if (s == NAV_GNSS_SYS_GPS && prn > 32) return lfail(L, NAV_ERR_PARSE, 2, "GPS PRN %d; expected 1..32", prn);
  for (int k = 0; k < ep->n; ++k)
    if ((int)ep->sats[k].system == s && ep->sats[k].prn == prn)
      return lfail(L, NAV_ERR_PARSE, 1, "satellite %c%02d twice in one epoch; expected each once", c[0], prn);
  if (ep->n >= NAV_RINEX_MAX_EPOCH_SATS)
    return lfail(L, NAV_ERR_PARSE, 1, "more than %d GPS and GLONASS satellites in one epoch",
                 NAV_RINEX_MAX_EPOCH_SATS);
  nav_rinex_obs_sat *o = &ep->sats[ep->n];
  memset(o, 0, sizeof *o);
  o->system = (nav_gnss_system)s;
  o->prn = prn;
  for (int j = 0; j < r->n_file[s]; ++j) {
    const int k = r->keep[s][j];
    if (k < 0) continue;
    const char *t = r->h.types[s][k];
    char what[32];
    snprintf(what, sizeof what, "%s of %c%02d", t, c[0], prn);
    const int col = 4 + 16 * j;
    bool blank = false;
    st = num(L, col, 14, what, &o->value[k], &blank);
    if (st != NAV_OK) return st;
    o->has[k] = !blank;
    if (blank) continue;
    const double v = o->value[k];
    if (t[0] == 'C' && !(v > 1.0e6 && v < 1.0e8))
      return lfail(
          L, NAV_ERR_PARSE, col,
          "%s: pseudorange %.3f m; expected 1e6 to 1e8 m (a satellite range plus a receiver clock bias)",
          what, v);
    if (t[0] == 'D' && !(fabs(v) < 1.0e6))
      return lfail(L, NAV_ERR_PARSE, col, "%s: Doppler %.3f Hz; expected |D| < 1e6 Hz", what, v);
  }
  ep->n++;
  return NAV_OK;
}

nav_status nav_rinex_obs_next(nav_rinex_obs_reader *r, nav_rinex_obs_epoch *out, nav_rinex_epoch_info *info,
                              bool *got) {
  if (!r || !out || !got) return NAV_ERR_INVALID_ARG;
  *got = false;
  lines *L = &r->L;
  if (L->failed != NAV_OK) return L->failed;
  for (;;) {
    bool have = false;
    nav_status st = next_line(L, &have);
    if (st != NAV_OK) return st;
    if (!have) return NAV_OK;
    if (L->n == 0) continue; /* a blank line between records */
    if (L->buf[0] != '>')
      return lfail(L, NAV_ERR_PARSE, 1,
                   "expected an epoch record starting with '>' (RINEX 3 observation data)");
    /* '>' yyyy mm dd hh mm ss.sssssss  flag numsat  (reserved)  rx clock offset:
     * A1,1X,I4,4(1X,I2),F11.7,2X,I1,I3,6X,F15.12 */
    int flag = 0, nsat = 0;
    st = inum(L, 32, 1, "epoch flag", 0, 6, &flag);
    if (st == NAV_OK) st = inum(L, 33, 3, "number of satellites", 0, 999, &nsat);
    if (st != NAV_OK) return st;
    if (flag >= 2 && flag <= 5) {
      /* Events: nsat special records follow (header lines or nothing). */
      r->events++;
      for (int k = 0; k < nsat; ++k) {
        st = next_line(L, &have);
        if (st != NAV_OK) return st;
        if (!have) {
          ++L->line;
          return lfail(L, NAV_ERR_PARSE, 1, "end of file inside an event record (flag %d announced %d lines)",
                       flag, nsat);
        }
      }
      continue;
    }
    static const int col[6] = {3, 8, 11, 14, 17, 19}, w[6] = {4, 2, 2, 2, 2, 11};
    double t = 0.0;
    st = epoch_fields(L, col, w, &t);
    if (st != NAV_OK) return st;
    const long epoch_line = L->line;
    double clk = 0.0;
    bool clk_blank = true;
    st = num(L, 42, 15, "receiver clock offset", &clk, &clk_blank);
    if (st != NAV_OK) return st;
    if (flag == 6) r->events++;
    if (flag <= 1 && r->have_prev && t < r->t_prev)
      return lfail(L, NAV_ERR_PARSE, 3,
                   "epoch %.7f s GPS is before the previous epoch (%.7f s); expected epochs in "
                   "time order",
                   t, r->t_prev);
    /* A cycle-slip record's satellites are read (and checked) into a scratch epoch. */
    nav_rinex_obs_epoch *dst = out;
    nav_rinex_obs_epoch *scratch = NULL;
    if (flag == 6) {
      scratch = malloc(sizeof *scratch);
      if (!scratch) return lfail(L, NAV_ERR_NO_MEMORY, 1, "out of memory");
      dst = scratch;
    }
    dst->n = 0;
    int skipped = 0;
    for (int k = 0; k < nsat && st == NAV_OK; ++k) {
      st = next_line(L, &have);
      if (st == NAV_OK && !have) {
        ++L->line;
        st = lfail(L, NAV_ERR_PARSE, 1,
                   "end of file inside the epoch record of line %ld, which announced %d satellites; got %d",
                   epoch_line, nsat, k);
      }
      if (st == NAV_OK) st = obs_sat_line(r, dst, &skipped);
    }
    free(scratch);
    if (st != NAV_OK) return st;
    if (flag == 6) continue;
    out->t_gps_s = t;
    if (info) {
      info->flag = flag;
      info->has_rx_clock = !clk_blank;
      info->rx_clock_s = clk;
      info->skipped = skipped;
      info->line = epoch_line;
    }
    r->t_prev = t;
    r->have_prev = true;
    *got = true;
    return NAV_OK;
  }
}

/* ---------------------------------------------------------------- navigation files */

/* The broadcast-orbit fields of a record line: 4 x D19.12 starting at column 5. */
static nav_status orbit_line(lines *L, int which, double v[4], int n_required) {
  bool got = false;
  nav_status st = next_line(L, &got);
  if (st != NAV_OK) return st;
  if (!got) {
    ++L->line;
    return lfail(L, NAV_ERR_PARSE, 1, "end of file inside a navigation record; expected BROADCAST ORBIT - %d",
                 which);
  }
  char buf[48];
  for (int i = 0; i < 4; ++i) {
    snprintf(buf, sizeof buf, "BROADCAST ORBIT - %d, field %d", which, i + 1);
    bool blank = false;
    st = num(L, 5 + 19 * i, 19, buf, &v[i], &blank);
    if (st != NAV_OK) return st;
    if (blank && i < n_required)
      return lfail(L, NAV_ERR_PARSE, 5 + 19 * i, "%s: blank; expected a number in columns %d-%d", buf,
                   5 + 19 * i, 23 + 19 * i);
  }
  return NAV_OK;
}

/* Room for record n in an array of records and its parallel array of lines. */
static nav_status nav_grow(lines *L, void **arr, long **line_arr, size_t *cap, size_t n, size_t size) {
  if (n < *cap) return NAV_OK;
  size_t nc = *cap ? 2 * *cap : 64;
  if (nc > NAV_RINEX_MAX_EPHEMERIDES) nc = NAV_RINEX_MAX_EPHEMERIDES;
  void *p = realloc(*arr, nc * size);
  if (!p) return lfail(L, NAV_ERR_NO_MEMORY, 1, "out of memory");
  *arr = p;
  long *q = realloc(*line_arr, nc * sizeof *q);
  if (!q) return lfail(L, NAV_ERR_NO_MEMORY, 1, "out of memory");
  *line_arr = q;
  *cap = nc;
  return NAV_OK;
}

static nav_status nav_parse(lines *L, nav_rinex_nav *nv) {
  char system = 'G';
  nav_status st = version_line(L, 'N', &nv->version, &system);
  if (st != NAV_OK) return st;
  for (;;) {
    bool got = false;
    st = next_line(L, &got);
    if (st != NAV_OK) return st;
    if (!got) {
      ++L->line;
      return lfail(L, NAV_ERR_PARSE, 1, "end of file inside the header; expected END OF HEADER");
    }
    char lab[21];
    label_of(L, lab);
    if (strcmp(lab, "END OF HEADER") == 0) break;
    if (strcmp(lab, "LEAP SECONDS") == 0) {
      st = inum(L, 1, 6, "leap seconds", 0, 99, &nv->leap_s);
      if (st != NAV_OK) return st;
      nv->has_leap = true;
    }
  }
  size_t cap_g = 0, cap_r = 0;
  for (;;) {
    bool got = false;
    st = next_line(L, &got);
    if (st != NAV_OK) return st;
    if (!got) break;
    if (L->n == 0) continue;
    char c[4];
    field(L, 1, 3, c);
    const long line0 = L->line;
    int prn = 0;
    if (!known_sys(c[0]))
      return lfail(
          L, NAV_ERR_PARSE, 1,
          "satellite system '%c'; expected the first line of a navigation record (G, R, E, C, J, I or S "
          "and the satellite number)",
          (unsigned char)c[0] < 0x20 || (unsigned char)c[0] >= 0x7f ? '?' : c[0]);
    st = inum(L, 2, 2, "satellite number", 1, 99, &prn);
    if (st != NAV_OK) return st;
    if (c[0] != 'G' && c[0] != 'R') {
      /* Other systems: 8 lines (Galileo, BeiDou, QZSS, IRNSS), 4 (SBAS). */
      const int more = c[0] == 'S' ? 3 : 7;
      for (int k = 0; k < more; ++k) {
        st = next_line(L, &got);
        if (st != NAV_OK) return st;
        if (!got) {
          ++L->line;
          return lfail(L, NAV_ERR_PARSE, 1, "end of file inside the %c%02d navigation record of line %ld",
                       c[0], prn, line0);
        }
      }
      nv->skipped++;
      continue;
    }
    if (nv->n_gps + nv->n_glo >= NAV_RINEX_MAX_EPHEMERIDES)
      return lfail(L, NAV_ERR_OUT_OF_RANGE, 1,
                   "more than %d GPS and GLONASS navigation records; the limit is %d",
                   NAV_RINEX_MAX_EPHEMERIDES, NAV_RINEX_MAX_EPHEMERIDES);
    static const int col[6] = {5, 10, 13, 16, 19, 22}, w[6] = {4, 2, 2, 2, 2, 2};
    double t_rec = 0.0, clk[3];
    st = epoch_fields(L, col, w, &t_rec);
    for (int i = 0; i < 3 && st == NAV_OK; ++i) {
      static const char *const nm[2][3] = {
          {"SV clock bias af0", "SV clock drift af1", "SV clock drift rate af2"},
          {"SV clock bias -TauN", "relative frequency bias +GammaN", "message frame time"}};
      st = num(L, 24 + 19 * i, 19, nm[c[0] == 'R'][i], &clk[i], NULL);
    }
    if (st != NAV_OK) return st;
    if (c[0] == 'G') {
      if (prn > 32) return lfail(L, NAV_ERR_PARSE, 2, "GPS PRN %d; expected 1..32", prn);
      double o[7][4];
      for (int k = 0; k < 7 && st == NAV_OK; ++k)
        st = orbit_line(L, k + 1, o[k], k < 6 ? 4 : 1);
      if (st != NAV_OK) return st;
      /* Field checks; the line of each is the record's first line + the orbit line number. */
      const long last = L->line;
      const double week = o[4][2];
      if (!(o[1][1] >= 0.0 && o[1][1] < 1.0)) {
        L->line = line0 + 2;
        st = lfail(L, NAV_ERR_PARSE, 24, "eccentricity %.12g; expected 0 <= e < 1", o[1][1]);
      } else if (!(o[1][3] > 1000.0 && o[1][3] < 10000.0)) {
        L->line = line0 + 2;
        st = lfail(L, NAV_ERR_PARSE, 62, "sqrt(A) %.12g m^0.5; expected 1000 to 10000 (a GPS orbit: 5153.7)",
                   o[1][3]);
      } else if (!(o[2][0] >= 0.0 && o[2][0] < NAV_GNSS_WEEK_S)) {
        L->line = line0 + 3;
        st = lfail(L, NAV_ERR_PARSE, 5, "toe %.12g s; expected seconds of the GPS week, 0 <= toe < 604800",
                   o[2][0]);
      } else if (!(week == floor(week) && week >= 0.0 && week < 1.0e5)) {
        L->line = line0 + 5;
        st = lfail(L, NAV_ERR_PARSE, 43,
                   "GPS week %.12g; expected a non-negative integer (continuous week number)", week);
      } else if (!(o[5][1] == floor(o[5][1]) && o[5][1] >= 0.0 && o[5][1] < 64.0)) {
        L->line = line0 + 6;
        st = lfail(L, NAV_ERR_PARSE, 24, "SV health %.12g; expected an integer 0..63", o[5][1]);
      }
      if (st != NAV_OK) return st;
      L->line = last;
      st = nav_grow(L, (void **)&nv->gps, &nv->gps_line, &cap_g, nv->n_gps, sizeof *nv->gps);
      if (st != NAV_OK) return st;
      nav_rinex_gps_eph *e = &nv->gps[nv->n_gps];
      memset(e, 0, sizeof *e);
      nv->gps_line[nv->n_gps] = line0;
      e->prn = prn;
      e->toc_gps_s = t_rec;
      e->af0_s = clk[0];
      e->af1_sps = clk[1];
      e->af2_sps2 = clk[2];
      e->iode = (int)fmax(-1.0, fmin(1023.0, o[0][0]));
      e->crs_m = o[0][1];
      e->delta_n_rps = o[0][2];
      e->m0_rad = o[0][3];
      e->cuc_rad = o[1][0];
      e->e = o[1][1];
      e->cus_rad = o[1][2];
      e->sqrt_a_sqrtm = o[1][3];
      e->cic_rad = o[2][1];
      e->omega0_rad = o[2][2];
      e->cis_rad = o[2][3];
      e->i0_rad = o[3][0];
      e->crc_m = o[3][1];
      e->w_rad = o[3][2];
      e->omega_dot_rps = o[3][3];
      e->idot_rps = o[4][0];
      e->l2_codes = (int)fmax(0.0, fmin(3.0, o[4][1]));
      e->l2p_flag = (int)fmax(0.0, fmin(1.0, o[4][3]));
      e->sv_accuracy_m = o[5][0];
      e->health = (int)o[5][1];
      e->tgd_s = o[5][2];
      e->iodc = (int)fmax(-1.0, fmin(1023.0, o[5][3]));
      /* The week of toe; a toe near the week's start may belong to the week after toc's
       * (IS-GPS-200N 20.3.4.3): take the week that puts toe closest to toc. */
      double toe = week * NAV_GNSS_WEEK_S + o[2][0];
      if (toe - e->toc_gps_s > 0.5 * NAV_GNSS_WEEK_S) toe -= NAV_GNSS_WEEK_S;
      if (e->toc_gps_s - toe > 0.5 * NAV_GNSS_WEEK_S) toe += NAV_GNSS_WEEK_S;
      e->toe_gps_s = toe;
      e->t_tx_gps_s = week * NAV_GNSS_WEEK_S + o[6][0];
      e->fit_interval_h = o[6][1];
      nv->n_gps++;
    } else {
      if (prn > 24) return lfail(L, NAV_ERR_PARSE, 2, "GLONASS slot %d; expected 1..24", prn);
      double o[4][4];
      for (int k = 0; k < 3 && st == NAV_OK; ++k)
        st = orbit_line(L, k + 1, o[k], 4);
      if (st == NAV_OK && nv->version >= 3.045) st = orbit_line(L, 4, o[3], 0);
      if (st != NAV_OK) return st;
      const long last = L->line;
      const nav_vec3 r_m = nav_vec3_make(1e3 * o[0][0], 1e3 * o[1][0], 1e3 * o[2][0]);
      if (!(o[1][3] == floor(o[1][3]) && o[1][3] >= -7.0 && o[1][3] <= 13.0)) {
        L->line = line0 + 2;
        st = lfail(L, NAV_ERR_PARSE, 62, "frequency number %.12g; expected an integer -7..13", o[1][3]);
      } else if (!(nav_vec3_norm(r_m) > 1.0e7 && nav_vec3_norm(r_m) < 1.0e8)) {
        L->line = line0 + 1;
        st = lfail(
            L, NAV_ERR_PARSE, 5,
            "satellite position %.6g km from the Earth's centre; expected 10 000 to 100 000 km (a GLONASS "
            "orbit: 25 500 km; the file's unit is km)",
            1e-3 * nav_vec3_norm(r_m));
      } else if (!(o[0][3] == floor(o[0][3]) && o[0][3] >= 0.0 && o[0][3] < 16.0)) {
        L->line = line0 + 1;
        st = lfail(L, NAV_ERR_PARSE, 62, "health %.12g; expected an integer (0 = healthy)", o[0][3]);
      }
      if (st != NAV_OK) return st;
      L->line = last;
      st = nav_grow(L, (void **)&nv->glo, &nv->glo_line, &cap_r, nv->n_glo, sizeof *nv->glo);
      if (st != NAV_OK) return st;
      nav_rinex_glo_eph *e = &nv->glo[nv->n_glo];
      memset(e, 0, sizeof *e);
      nv->glo_line[nv->n_glo] = line0;
      e->slot = prn;
      /* The record's epoch is UTC (RINEX 3.04 Table A11): GPS = UTC + leap seconds. */
      const int leap = nv->has_leap ? nv->leap_s : nav_rinex_leap_seconds(t_rec);
      e->tb_gps_s = t_rec + (double)leap;
      e->clock_bias_s = clk[0];
      e->gamma_n = clk[1];
      /* tk: seconds of the UTC week of the record. */
      e->tk_gps_s = floor(t_rec / NAV_GNSS_WEEK_S) * NAV_GNSS_WEEK_S + clk[2] + (double)leap;
      /* km, km/s, km/s^2 in the file. */
      e->r_e_m = r_m;
      e->v_e_mps = nav_vec3_make(1e3 * o[0][1], 1e3 * o[1][1], 1e3 * o[2][1]);
      e->a_e_mps2 = nav_vec3_make(1e3 * o[0][2], 1e3 * o[1][2], 1e3 * o[2][2]);
      e->health = (int)o[0][3];
      e->channel = (int)o[1][3];
      e->age_d = (int)fmax(0.0, fmin(99.0, o[2][3]));
      nv->n_glo++;
    }
  }
  return NAV_OK;
}

static nav_status nav_read(const char *path, const char *text, size_t len, const char *name,
                           nav_rinex_nav **out, nav_diag *diag) {
  if (!out) return NAV_ERR_INVALID_ARG;
  lines *L = malloc(sizeof *L);
  nav_rinex_nav *nv = calloc(1, sizeof *nv);
  nav_status st = (L && nv) ? NAV_OK : NAV_ERR_NO_MEMORY;
  if (st == NAV_OK) st = lines_init(L, path, text, len, name, diag);
  if (st == NAV_OK) {
    st = nav_parse(L, nv);
    if (st != NAV_OK && diag) *diag = L->diag;
  }
  if (L) lines_close(L);
  free(L);
  if (st != NAV_OK) {
    nav_rinex_nav_destroy(nv);
    return st;
  }
  *out = nv;
  return NAV_OK;
}

nav_status nav_rinex_nav_read(const char *path, nav_rinex_nav **out, nav_diag *diag) {
  if (!path) return NAV_ERR_INVALID_ARG;
  return nav_read(path, NULL, 0, path, out, diag);
}

nav_status nav_rinex_nav_read_memory(const char *text, size_t len, const char *display_name,
                                     nav_rinex_nav **out, nav_diag *diag) {
  return nav_read(NULL, text ? text : "", text ? len : 0, display_name ? display_name : "memory", out, diag);
}

void nav_rinex_nav_destroy(nav_rinex_nav *n) {
  if (!n) return;
  free(n->gps);
  free(n->gps_line);
  free(n->glo);
  free(n->glo_line);
  free(n);
}

nav_gnss_orbit nav_rinex_gps_orbit(const nav_rinex_gps_eph *e, bool *has_harmonics) {
  nav_gnss_orbit o;
  memset(&o, 0, sizeof o);
  o.system = NAV_GNSS_SYS_GPS;
  o.prn = e->prn;
  o.health = e->health;
  o.toe_s = e->toe_gps_s;
  o.sqrt_a_sqrtm = e->sqrt_a_sqrtm;
  o.e = e->e;
  o.i0_rad = e->i0_rad;
  o.idot_rps = e->idot_rps;
  o.omega0_rad = e->omega0_rad;
  o.omega_dot_rps = e->omega_dot_rps;
  o.w_rad = e->w_rad;
  o.m0_rad = e->m0_rad;
  o.delta_n_rps = e->delta_n_rps;
  o.af0_s = e->af0_s;
  o.af1_sps = e->af1_sps;
  o.cuc_rad = e->cuc_rad;
  o.cus_rad = e->cus_rad;
  o.crc_m = e->crc_m;
  o.crs_m = e->crs_m;
  o.cic_rad = e->cic_rad;
  o.cis_rad = e->cis_rad;
  if (has_harmonics)
    *has_harmonics = e->crs_m != 0.0 || e->crc_m != 0.0 || e->cus_rad != 0.0 || e->cuc_rad != 0.0 ||
                     e->cis_rad != 0.0 || e->cic_rad != 0.0;
  return o;
}

/* ---------------------------------------------------------------- replay source */

struct nav_rinex_source {
  nav_rinex_source_config cfg;
  char obs_name[512];
  nav_rinex_obs_reader *obs;
  nav_rinex_nav *nav;
  nav_rinex_obs_epoch ep;
  int i_c1c[NAV_GNSS_SYS_COUNT], i_d1c[NAV_GNSS_SYS_COUNT]; /* kept-type indices, or -1 */
  nav_gnss_orbit orbits[NAV_RINEX_MAX_EPOCH_SATS];
  nav_ins_gnss_sat_meas meas[NAV_RINEX_MAX_EPOCH_SATS];
  nav_rinex_source_counts counts;
  char nav_name[512];
};

nav_rinex_source_config nav_rinex_source_config_default(void) {
  nav_rinex_source_config c;
  memset(&c, 0, sizeof c);
  c.pr_sd_m = 3.0;
  c.rr_sd_mps = 0.1;
  c.max_eph_age_s = 7200.0;
  c.max_glo_age_s = 1800.0;
  c.use_doppler = true;
  return c;
}

nav_status nav_rinex_source_create(const nav_rinex_source_config *cfg, nav_rinex_source **out,
                                   nav_diag *diag) {
  if (!cfg || !out) return NAV_ERR_INVALID_ARG;
  const char *bad = NULL;
  if (!cfg->obs_path || !cfg->nav_path)
    bad = "an observation file and a navigation file are both required";
  else if (!(cfg->pr_sd_m > 0.0 && isfinite(cfg->pr_sd_m)))
    bad = "the pseudorange sigma must be finite and > 0";
  else if (!(cfg->rr_sd_mps > 0.0 && isfinite(cfg->rr_sd_mps)))
    bad = "the range-rate sigma must be finite and > 0";
  else if (!(cfg->max_eph_age_s > 0.0 && isfinite(cfg->max_eph_age_s)) ||
           !(cfg->max_glo_age_s > 0.0 && cfg->max_glo_age_s <= 86400.0))
    bad = "the ephemeris ages must be > 0 (GLONASS: at most one day)";
  else if (!isfinite(cfg->t0_gps_s))
    bad = "the GPS time of t = 0 must be finite";
  if (bad) {
    diag_set(diag, "replay", 0, 0, "%s", bad);
    return NAV_ERR_INVALID_ARG;
  }
  nav_rinex_source *s = calloc(1, sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  s->cfg = *cfg;
  snprintf(s->nav_name, sizeof s->nav_name, "%s", cfg->nav_path);
  snprintf(s->obs_name, sizeof s->obs_name, "%s", cfg->obs_path);
  s->cfg.nav_path = s->nav_name;
  s->cfg.obs_path = s->obs_name;
  nav_status st = nav_rinex_nav_read(cfg->nav_path, &s->nav, diag);
  if (st == NAV_OK) st = nav_rinex_obs_open(cfg->obs_path, &s->obs, diag);
  if (st == NAV_OK) {
    const nav_rinex_obs_header *h = nav_rinex_obs_get_header(s->obs);
    for (int k = 0; k < NAV_GNSS_SYS_COUNT; ++k) {
      s->i_c1c[k] = nav_rinex_obs_type_index(h, (nav_gnss_system)k, "C1C");
      s->i_d1c[k] = nav_rinex_obs_type_index(h, (nav_gnss_system)k, "D1C");
    }
    if (s->i_c1c[NAV_GNSS_SYS_GPS] < 0 && s->i_c1c[NAV_GNSS_SYS_GLONASS] < 0) {
      diag_set(diag, cfg->obs_path, 1, 1,
               "no C1C observation type for GPS or GLONASS in the header; the replay needs L1 C/A "
               "pseudoranges (SYS / # / OBS TYPES with C1C)");
      st = NAV_ERR_PARSE;
    }
  }
  if (st == NAV_OK && s->nav->n_gps == 0 && s->nav->n_glo == 0) {
    diag_set(diag, cfg->nav_path, 0, 0,
             "no GPS or GLONASS navigation record; the replay needs the satellites' ephemerides");
    st = NAV_ERR_PARSE;
  }
  if (st != NAV_OK) {
    nav_rinex_source_destroy(s);
    return st;
  }
  *out = s;
  return NAV_OK;
}

void nav_rinex_source_destroy(nav_rinex_source *s) {
  if (!s) return;
  nav_rinex_obs_destroy(s->obs);
  nav_rinex_nav_destroy(s->nav);
  free(s);
}

nav_rinex_source_counts nav_rinex_source_get_counts(const nav_rinex_source *s) {
  nav_rinex_source_counts c;
  memset(&c, 0, sizeof c);
  if (!s) return c;
  c = s->counts;
  c.events = nav_rinex_obs_events(s->obs);
  return c;
}

double nav_rinex_source_fraction(const nav_rinex_source *s) {
  return s ? nav_rinex_obs_fraction(s->obs) : 1.0;
}

/* The GPS ephemeris of @p prn with toe nearest to @p t (ties: the later record), or NULL. */
static const nav_rinex_gps_eph *gps_eph_for(const nav_rinex_nav *nv, int prn, double t) {
  const nav_rinex_gps_eph *best = NULL;
  for (size_t i = 0; i < nv->n_gps; ++i) {
    const nav_rinex_gps_eph *e = &nv->gps[i];
    if (e->prn != prn) continue;
    if (!best || fabs(e->toe_gps_s - t) <= fabs(best->toe_gps_s - t)) best = e;
  }
  return best;
}

/* The GLONASS record of @p slot with tb nearest to @p t, or NULL. */
static const nav_rinex_glo_eph *glo_eph_for(const nav_rinex_nav *nv, int slot, double t) {
  const nav_rinex_glo_eph *best = NULL;
  for (size_t i = 0; i < nv->n_glo; ++i) {
    const nav_rinex_glo_eph *e = &nv->glo[i];
    if (e->slot != slot) continue;
    if (!best || fabs(e->tb_gps_s - t) <= fabs(best->tb_gps_s - t)) best = e;
  }
  return best;
}

/* Derivative of the GLONASS state [r, v] (PZ-90, rotating): the ICD force model
 * (nav_rinex_glo_force, the one the writer fits its records to) plus the record's constant
 * luni-solar acceleration. */
static void glo_deriv(const double x[6], nav_vec3 acc, double dx[6]) {
  const nav_vec3 a = nav_vec3_add(nav_rinex_glo_force(nav_vec3_make(x[0], x[1], x[2]), nav_vec3_make(x[3], x[4], x[5])), acc);
  dx[0] = x[3];
  dx[1] = x[4];
  dx[2] = x[5];
  dx[3] = a.x;
  dx[4] = a.y;
  dx[5] = a.z;
}

/* The satellite's ECEF state at @p t from its record: fourth-order Runge-Kutta from tb in steps
 * of at most 60 s (ICD GLONASS A.3.1.2 recommends RK4; RTKLIB uses 60 s). */
static void glo_state(const nav_rinex_glo_eph *e, double t, nav_vec3 *r, nav_vec3 *v) {
  double x[6] = {e->r_e_m.x, e->r_e_m.y, e->r_e_m.z, e->v_e_mps.x, e->v_e_mps.y, e->v_e_mps.z};
  const double span = t - e->tb_gps_s;
  const int n = (int)ceil(fabs(span) / 60.0);
  const double h = n > 0 ? span / n : 0.0;
  for (int s = 0; s < n; ++s) {
    double k1[6], k2[6], k3[6], k4[6], y[6];
    glo_deriv(x, e->a_e_mps2, k1);
    for (int i = 0; i < 6; ++i)
      y[i] = x[i] + 0.5 * h * k1[i];
    glo_deriv(y, e->a_e_mps2, k2);
    for (int i = 0; i < 6; ++i)
      y[i] = x[i] + 0.5 * h * k2[i];
    glo_deriv(y, e->a_e_mps2, k3);
    for (int i = 0; i < 6; ++i)
      y[i] = x[i] + h * k3[i];
    glo_deriv(y, e->a_e_mps2, k4);
    for (int i = 0; i < 6; ++i)
      x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  *r = nav_vec3_make(x[0], x[1], x[2]);
  *v = nav_vec3_make(x[3], x[4], x[5]);
}

/*
 * The osculating orbit at @p t of an ECEF state, in the form nav_gnss_orbit_state() propagates
 * (toe = t, no rates): the filter evaluates a satellite within a few tenths of a second of the
 * epoch (light time, range rate), where the two-body motion and the ICD integration differ by
 * far less than a millimetre. Classical elements from position and inertial velocity (Vallado,
 * Fundamentals of Astrodynamics and Applications, 4th ed., algorithm 9 "RV2COE"), with the
 * constants the propagator uses (IS-GPS-200N mu and omega_e) so that it returns the state at t.
 */
static bool osculating_orbit(nav_vec3 r, nav_vec3 v_e, double t, int slot, nav_gnss_orbit *o) {
  const double mu = NAV_GPS_MU_M3PS2, we = NAV_GPS_OMEGA_E_RPS;
  /* Inertial velocity in the frame aligned with ECEF at t: v_i = v_e + omega_e x r. */
  const nav_vec3 v = nav_vec3_add(v_e, nav_vec3_make(-we * r.y, we * r.x, 0.0));
  const nav_vec3 h = nav_vec3_cross(r, v);
  const double rn = nav_vec3_norm(r), hn = nav_vec3_norm(h), v2 = nav_vec3_dot(v, v);
  const double a = 1.0 / (2.0 / rn - v2 / mu);
  if (!(a > 0.0) || !(hn > 0.0)) return false;
  const double inc = acos(h.z / hn);
  const double node = atan2(h.x, -h.y); /* longitude of the ascending node at t */
  /* Eccentric anomaly from r and r.v (e cos E = 1 - r/a, e sin E = r.v / sqrt(mu a)). */
  const double ecE = 1.0 - rn / a, esE = nav_vec3_dot(r, v) / sqrt(mu * a);
  const double e = hypot(ecE, esE);
  if (!(e < 1.0)) return false;
  const double E = atan2(esE, ecE);
  const double M = E - esE;
  const double nu = atan2(sqrt(1.0 - e * e) * sin(E), cos(E) - e);
  /* Argument of latitude: the angle from the node line to r in the orbit plane. */
  const double cO = cos(node), sO = sin(node);
  const double u = atan2(r.z / sin(inc), r.x * cO + r.y * sO);
  memset(o, 0, sizeof *o);
  o->system = NAV_GNSS_SYS_GLONASS;
  o->prn = slot;
  o->toe_s = t;
  o->sqrt_a_sqrtm = sqrt(a);
  o->e = e;
  o->i0_rad = inc;
  o->m0_rad = M;
  o->w_rad = u - nu;
  /* Omega_k = Omega_0 - omega_e toe_sow at t_k = 0 (nav_gnss_orbit_state). */
  const double toe_sow = t - floor(t / NAV_GNSS_WEEK_S) * NAV_GNSS_WEEK_S;
  o->omega0_rad = node + we * toe_sow;
  return true;
}

/* GLONASS frequency channel of @p slot: the observation header's SLOT / FRQ #, else the record's. */
static int glo_channel(const nav_rinex_obs_header *h, const nav_rinex_glo_eph *e) {
  for (int i = 0; i < h->n_glo && i < NAV_RINEX_MAX_GLO_SLOTS; ++i)
    if (h->glo_slot[i] == e->slot) return h->glo_channel[i];
  return e->channel;
}

nav_status nav_rinex_source_next(nav_rinex_source *s, nav_ins_gnss_raw_epoch *ep, bool *got, nav_diag *diag) {
  if (!s || !ep || !got) return NAV_ERR_INVALID_ARG;
  *got = false;
  bool have = false;
  nav_rinex_epoch_info info;
  nav_status st = nav_rinex_obs_next(s->obs, &s->ep, &info, &have);
  if (st != NAV_OK) {
    if (diag) *diag = *nav_rinex_obs_diag(s->obs);
    return st;
  }
  if (!have) return NAV_OK;
  const double t = s->ep.t_gps_s;
  const nav_rinex_obs_header *hdr = nav_rinex_obs_get_header(s->obs);
  int m = 0;
  s->counts.other_systems += info.skipped;
  for (int i = 0; i < s->ep.n; ++i) {
    const nav_rinex_obs_sat *o = &s->ep.sats[i];
    const int sys = (int)o->system;
    const int ic = s->i_c1c[sys], id = s->i_d1c[sys];
    if (ic < 0 || !o->has[ic]) {
      s->counts.no_code++;
      continue;
    }
    const double c1c = o->value[ic];
    const double t_tx = t - c1c / NAV_GNSS_C_MPS;
    if (o->system == NAV_GNSS_SYS_GLONASS) {
      const nav_rinex_glo_eph *g = glo_eph_for(s->nav, o->prn, t);
      if (!g || fabs(g->tb_gps_s - t) > s->cfg.max_glo_age_s) {
        s->counts.no_ephemeris++;
        continue;
      }
      if (g->health != 0) {
        s->counts.unhealthy++;
        continue;
      }
      nav_vec3 r, v;
      glo_state(g, t, &r, &v);
      if (!osculating_orbit(r, v, t, o->prn, &s->orbits[m])) {
        diag_set(diag, s->cfg.nav_path, (int)s->nav->glo_line[g - s->nav->glo], 1,
                 "R%02d: the record's state does not give a closed orbit at t = %.3f s GPS; expected a "
                 "satellite state vector in km, km/s",
                 g->slot, t);
        return NAV_ERR_PARSE;
      }
      /* Satellite clock -TauN + GammaN (t - tb) (nav_rinex_glo_clock_s), its rate GammaN. */
      const double dt_sv = nav_rinex_glo_clock_s(g, t_tx);
      const double lambda = NAV_GNSS_C_MPS / nav_rinex_l1_hz(NAV_GNSS_SYS_GLONASS, glo_channel(hdr, g));
      nav_ins_gnss_sat_meas *x = &s->meas[m];
      x->sat = &s->orbits[m];
      x->has_pr = true;
      x->pr_m = c1c + NAV_GNSS_C_MPS * dt_sv;
      x->has_rr = s->cfg.use_doppler && id >= 0 && o->has[id];
      x->rr_mps = x->has_rr ? -lambda * o->value[id] + NAV_GNSS_C_MPS * g->gamma_n : 0.0;
      ++m;
      s->counts.glonass_used++;
      continue;
    }
    const nav_rinex_gps_eph *e = gps_eph_for(s->nav, o->prn, t);
    if (!e || fabs(e->toe_gps_s - t) > s->cfg.max_eph_age_s) {
      s->counts.no_ephemeris++;
      continue;
    }
    if (e->health != 0) {
      s->counts.unhealthy++;
      continue;
    }
    s->orbits[m] = nav_rinex_gps_orbit(e, NULL);
    /* The satellite clock at the transmit time t - P/c, applied to the code; its rate (central
     * difference over +-1 s: af1, af2 and the relativistic term) to the range rate. */
    const double dt_sv = nav_rinex_gps_clock_s(e, t_tx, true);
    const double dt_sv_rate =
        0.5 * (nav_rinex_gps_clock_s(e, t_tx + 1.0, true) - nav_rinex_gps_clock_s(e, t_tx - 1.0, true));
    nav_ins_gnss_sat_meas *x = &s->meas[m];
    x->sat = &s->orbits[m];
    x->has_pr = true;
    x->pr_m = c1c + NAV_GNSS_C_MPS * dt_sv;
    /* Range rate = -lambda D (D positive for an approaching satellite). */
    x->has_rr = s->cfg.use_doppler && id >= 0 && o->has[id];
    x->rr_mps = x->has_rr
                    ? -(NAV_GNSS_C_MPS / NAV_RINEX_GPS_L1_HZ) * o->value[id] + NAV_GNSS_C_MPS * dt_sv_rate
                    : 0.0;
    ++m;
  }
  s->counts.epochs++;
  s->counts.sats_used += m;
  ep->t_gps_s = t;
  ep->t_s = t - s->cfg.t0_gps_s;
  ep->n = m;
  ep->sats = s->meas;
  ep->pr_sd_m = s->cfg.pr_sd_m;
  ep->rr_sd_mps = s->cfg.rr_sd_mps;
  *got = true;
  return NAV_OK;
}
