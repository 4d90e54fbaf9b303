/*
 * Recorded-data readers (KF-GINS text formats) and the replay of our navigation on them
 * (nav_recorded.h).
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <pthread.h>
#include <stdatomic.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_io.h"
#include "navcore/nav_recorded.h"
#include "fast_number.h"
#include "line_layout.h"
#include "replay_errors.h"
#include "scene_bounds.h"

/* Buffer of a streaming reader. Larger than the longest line, so a full buffer always holds a
 * complete line; 256 KiB amortises fread and keeps memory flat for any file size. */
#define BUF_CAP (256u * 1024u)
/* Zero bytes after the buffer's spare byte: a word loaded at any point of a line stays inside
 * the allocation (split_fixed, nav_fast_fixed_scan_padded). */
#define BUF_PAD 32u
#define MAX_COLS 13

struct nav_rec_reader {
  nav_rec_format fmt;
  FILE *f;         /* NULL for a memory source */
  const char *mem; /* memory source */
  size_t mem_len, mem_pos;
  char *buf;       /* BUF_CAP + 1 + BUF_PAD bytes: room for a terminating NUL after the last line */
  size_t len, pos; /* unread data is buf[pos, len) */
  bool src_eof;
  long line;              /* lines consumed */
  long rec_line;          /* line of the last record returned */
  double consumed, total; /* bytes, for the progress fraction */
  nav_status failed;      /* sticky error status */
  nav_diag diag;
  bool have_prev;
  double t_prev;
  long prev_line;
  int64_t k;
  int gnss_cols;      /* column count fixed by the first GNSS record (0 before) */
  long cut_line;      /* a last line without a line end (the file may have been cut), else 0 */
  locale_t c_numeric; /* "C" numbers for strtod, whatever the process locale (a GUI may set one) */
  size_t file_left;   /* bytes of the file still to read (a stretch of it; SIZE_MAX: to its end) */
  /* .nav rows: the layout of the last row read field by field (line_layout.h), and how many rows
   * in a row did not match it (relearning backs off when the layout keeps changing). */
  nav_line_layout pva_layout;
  unsigned pva_layout_misses;
};

/* ---------------------------------------------------------------- diagnostics */

static void diag_set(nav_diag *d, const char *file, int line, int col, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));

static void diag_set(nav_diag *d, const char *file, int line, int col, const char *path, const char *fmt,
                     ...) {
  if (!d) return;
  memset(d, 0, sizeof *d);
  snprintf(d->file, sizeof d->file, "%s", file ? file : "");
  d->line = line;
  d->col = line > 0 ? col : 0;
  snprintf(d->path, sizeof d->path, "%s", path ? path : "");
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d->message, sizeof d->message, fmt, ap);
  va_end(ap);
}

/* Printable excerpt of a field for a message: control bytes become '?', long text is cut. */
/* Length of the well-formed UTF-8 sequence at s[0..n) (RFC 3629: no overlong forms, surrogates
 * or code points above U+10FFFF), or 0 when it is not one. */
static size_t utf8_len(const unsigned char *s, size_t n) {
  const unsigned char c = s[0];
  size_t len;
  unsigned char lo = 0x80, hi = 0xbf; /* range of the second byte */
  if (c >= 0xc2 && c <= 0xdf) len = 2;
  else if (c >= 0xe0 && c <= 0xef) {
    len = 3;
    if (c == 0xe0) lo = 0xa0;
    if (c == 0xed) hi = 0x9f;
  } else if (c >= 0xf0 && c <= 0xf4) {
    len = 4;
    if (c == 0xf0) lo = 0x90;
    if (c == 0xf4) hi = 0x8f;
  } else
    return 0;
  if (len > n || s[1] < lo || s[1] > hi) return 0;
  for (size_t k = 2; k < len; ++k)
    if ((s[k] & 0xc0) != 0x80) return 0;
  return len;
}

/* A field as shown in a message: at most 32 bytes, control characters and bytes that are not
 * well-formed UTF-8 as '?', a multi-byte character never cut, "..." when shortened. */
static void excerpt(char *dst, size_t cap, const char *s, size_t n) {
  size_t j = 0;
  const size_t max = cap > 40 ? 32 : cap - 4;
  size_t i = 0;
  for (; i < n && j < max; ++i) {
    const unsigned char c = (unsigned char)s[i];
    if (c >= 0x80) {
      const size_t len = utf8_len((const unsigned char *)s + i, n - i);
      if (len == 0) {
        dst[j++] = '?';
        continue;
      }
      if (j + len > max) break;
      memcpy(dst + j, s + i, len);
      j += len;
      i += len - 1;
      continue;
    }
    dst[j++] = (c < 0x20 || c == 0x7f) ? '?' : (char)c;
  }
  if (i < n) {
    memcpy(dst + j, "...", 3);
    j += 3;
  }
  dst[j] = '\0';
}

static nav_status fail(nav_rec_reader *r, nav_status st, int line, int col, const char *path,
                       const char *msg) {
  char file[sizeof r->diag.file];
  snprintf(file, sizeof file, "%s", r->diag.file);
  diag_set(&r->diag, file, line, col, path, "%s", msg);
  r->failed = st;
  return st;
}

/* ---------------------------------------------------------------- reader */

static const char *format_name(nav_rec_format f) {
  switch (f) {
  case NAV_REC_IMU: return "IMU";
  case NAV_REC_GNSS: return "GNSS";
  case NAV_REC_PVA: return ".nav";
  default: return "?";
  }
}

static nav_status reader_new(nav_rec_format fmt, const char *name, nav_rec_reader **out) {
  if (fmt != NAV_REC_IMU && fmt != NAV_REC_GNSS && fmt != NAV_REC_PVA) return NAV_ERR_INVALID_ARG;
  nav_rec_reader *r = calloc(1, sizeof *r);
  if (!r) return NAV_ERR_NO_MEMORY;
  r->buf = calloc(BUF_CAP + 1 + BUF_PAD, 1);
  if (!r->buf) {
    free(r);
    return NAV_ERR_NO_MEMORY;
  }
  r->c_numeric = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
  if (r->c_numeric == (locale_t)0) {
    free(r->buf);
    free(r);
    return NAV_ERR_NO_MEMORY;
  }
  r->fmt = fmt;
  r->failed = NAV_OK;
  r->file_left = SIZE_MAX;
  snprintf(r->diag.file, sizeof r->diag.file, "%s", name ? name : "");
  *out = r;
  return NAV_OK;
}

nav_status nav_rec_reader_open(const char *path, nav_rec_format fmt, nav_rec_reader **out, nav_diag *diag) {
  if (!path || !out) return NAV_ERR_INVALID_ARG;
  nav_rec_reader *r = NULL;
  nav_status st = reader_new(fmt, path, &r);
  if (st != NAV_OK) return st;
  char why[320];
  st = nav_io_fopen_regular(path, &r->f, why, sizeof why);
  if (st != NAV_OK) {
    /* why is "cannot open the file: ..." or "cannot read the file: it is a FIFO ...": name the
     * format in it ("cannot read the IMU file: ..."). */
    diag_set(diag, path, 0, 0, "", "%.11s the %s file%s", why, format_name(fmt), strlen(why) >= 20 ? why + 20 : "");
    nav_rec_reader_destroy(r);
    return st;
  }
  struct stat sb;
  if (fstat(fileno(r->f), &sb) == 0 && S_ISREG(sb.st_mode)) r->total = (double)sb.st_size;
  *out = r;
  return NAV_OK;
}

nav_status nav_rec_reader_open_memory(const char *text, size_t len, const char *display_name,
                                      nav_rec_format fmt, nav_rec_reader **out) {
  if ((!text && len > 0) || !out) return NAV_ERR_INVALID_ARG;
  nav_rec_reader *r = NULL;
  const nav_status st = reader_new(fmt, display_name ? display_name : "<memory>", &r);
  if (st != NAV_OK) return st;
  r->mem = text;
  r->mem_len = len;
  r->total = (double)len;
  *out = r;
  return NAV_OK;
}

void nav_rec_reader_destroy(nav_rec_reader *r) {
  if (!r) return;
  if (r->f) fclose(r->f);
  freelocale(r->c_numeric);
  free(r->buf);
  free(r);
}

const nav_diag *nav_rec_reader_diag(const nav_rec_reader *r) {
  return r ? &r->diag : NULL;
}
long nav_rec_reader_line(const nav_rec_reader *r) {
  return r ? r->rec_line : 0;
}
long nav_rec_reader_cut_line(const nav_rec_reader *r) { return r ? r->cut_line : 0; }

double nav_rec_reader_fraction(const nav_rec_reader *r) {
  if (!r || !(r->total > 0.0)) return 0.0;
  return fmin(1.0, r->consumed / r->total);
}

/* Refill the buffer after moving the unread bytes to its start. */
static nav_status refill(nav_rec_reader *r) {
  if (r->pos > 0) {
    memmove(r->buf, r->buf + r->pos, r->len - r->pos);
    r->len -= r->pos;
    r->pos = 0;
  }
  size_t room = BUF_CAP - r->len;
  size_t got = 0;
  if (r->f) {
    if (room > r->file_left) room = r->file_left;
    got = fread(r->buf + r->len, 1, room, r->f);
    if (got < room) {
      if (ferror(r->f)) {
        char msg[256];
        snprintf(msg, sizeof msg, "read error: %s", strerror(errno));
        return fail(r, NAV_ERR_IO, 0, 0, "", msg);
      }
      r->src_eof = true;
    }
    if (r->file_left != SIZE_MAX) {
      r->file_left -= got;
      if (r->file_left == 0) r->src_eof = true;
    }
  } else {
    got = r->mem_len - r->mem_pos < room ? r->mem_len - r->mem_pos : room;
    memcpy(r->buf + r->len, r->mem + r->mem_pos, got);
    r->mem_pos += got;
    if (r->mem_pos >= r->mem_len) r->src_eof = true;
  }
  r->len += got;
  return NAV_OK;
}

/* Next line, NUL-terminated in place (its '\n' is overwritten; a last line without one uses the
 * spare byte of buf). *line = NULL at the end of the input. The line stays valid until the next
 * call. */
static nav_status next_line(nav_rec_reader *r, char **line, size_t *n) {
  *line = NULL;
  *n = 0;
  for (;;) {
    char *start = r->buf + r->pos;
    const size_t avail = r->len - r->pos;
    char *nl = memchr(start, '\n', avail);
    if (nl || (r->src_eof && avail > 0)) {
      const size_t len = nl ? (size_t)(nl - start) : avail;
      if (len > NAV_REC_MAX_LINE) break;
      start[len] = '\0';
      r->pos += nl ? len + 1 : len;
      r->consumed += (double)(nl ? len + 1 : len);
      r->line++;
      if (!nl) r->cut_line = r->line;
      *line = start;
      *n = len;
      return NAV_OK;
    }
    if (r->src_eof) return NAV_OK;
    if (avail > NAV_REC_MAX_LINE) break;
    const nav_status st = refill(r);
    if (st != NAV_OK) return st;
  }
  char msg[128];
  snprintf(msg, sizeof msg, "line longer than %d bytes; expected a text file of records, one per line",
           NAV_REC_MAX_LINE);
  return fail(r, NAV_ERR_PARSE, (int)(r->line + 1), NAV_REC_MAX_LINE + 1, "", msg);
}

/* ---------------------------------------------------------------- records */

static const char *const k_imu_cols[] = {"t_s",        "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad",
                                         "dvel_x_mps", "dvel_y_mps",   "dvel_z_mps"};
static const char *const k_gnss_cols[] = {
    "t_s",       "lat_deg",   "lon_deg",   "h_m",          "sd_n_m",       "sd_e_m",      "sd_d_m",
    "vel_n_mps", "vel_e_mps", "vel_d_mps", "vel_sd_n_mps", "vel_sd_e_mps", "vel_sd_d_mps"};
static const char *const k_pva_cols[] = {"week",     "t_s",       "lat_deg",   "lon_deg",
                                         "h_m",      "vel_n_mps", "vel_e_mps", "vel_d_mps",
                                         "roll_deg", "pitch_deg", "yaw_deg"};

static const char *col_name(nav_rec_format f, int i) {
  switch (f) {
  case NAV_REC_IMU: return i < 7 ? k_imu_cols[i] : "";
  case NAV_REC_GNSS: return i < 13 ? k_gnss_cols[i] : "";
  case NAV_REC_PVA: return i < 11 ? k_pva_cols[i] : "";
  default: return "";
  }
}

static const char *k_expect_imu = "7 columns (t_s, dtheta x/y/z [rad], dvel x/y/z [m/s])";
static const char *k_expect_gnss =
    "7 columns (t_s, lat_deg, lon_deg, h_m, position sigma N/E/D [m]) or 13 (the same, then velocity "
    "N/E/D [m/s] and velocity sigma N/E/D [m/s])";
static const char *k_expect_pva =
    "11 columns (week, t_s, lat_deg, lon_deg, h_m, velocity N/E/D [m/s], roll/pitch/yaw [deg])";

/* The fields of one line. */
typedef struct fields {
  int count; /* number of fields on the line (may exceed MAX_COLS) */
  double v[MAX_COLS];
  int col[MAX_COLS + 1]; /* 1-based column of each field (and of the first extra one) */
  int end_col;           /* column just after the last field */
  /* Read by split_fixed(): col and end_col not filled yet; the line (valid until the next line is
   * read) is split again by with_cols() when a message needs a column. */
  bool fast;
  char *line;
  size_t n;
} fields;

static bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}
static bool is_num_char(char c) {
  return (c >= '0' && c <= '9') || c == '+' || c == '-' || c == '.' || c == 'e' || c == 'E';
}

/* Case-insensitive: is the token a NaN or infinity spelling? (They fail the character check;
 * this only picks the clearer message.) */
static bool is_nonfinite_word(const char *s, size_t n) {
  char w[16];
  size_t j = 0;
  if (n > 0 && (s[0] == '+' || s[0] == '-')) {
    ++s;
    --n;
  }
  if (n >= sizeof w) return false;
  for (size_t i = 0; i < n; ++i)
    w[j++] = (char)((s[i] >= 'A' && s[i] <= 'Z') ? s[i] - 'A' + 'a' : s[i]);
  w[j] = '\0';
  return strcmp(w, "nan") == 0 || strcmp(w, "inf") == 0 || strcmp(w, "infinity") == 0 ||
         strncmp(w, "nan(", 4) == 0;
}

static nav_status field_error(nav_rec_reader *r, int i, int col, const char *what) {
  char path[64];
  const char *name = col_name(r->fmt, i);
  if (name[0])
    snprintf(path, sizeof path, "column %d (%s)", i + 1, name);
  else
    snprintf(path, sizeof path, "column %d", i + 1);
  return fail(r, NAV_ERR_PARSE, (int)r->line, col, path, what);
}

/*
 * Split a line into numbers. A blank or comment line gives count 0. strtod converts each field
 * (correctly rounded; the caller switches to the "C" numeric locale); the character check first
 * keeps hexadecimal floats, NaN and infinities out.
 */
static nav_status split(nav_rec_reader *r, char *line, size_t n, fields *fl) {
  fl->count = 0;
  fl->end_col = 1;
  size_t i = 0;
  while (i < n && is_blank(line[i]))
    ++i;
  if (i == n || line[i] == '#') return NAV_OK;
  while (i < n) {
    const size_t start = i;
    const int k = fl->count++;
    const int col = (int)start + 1;
    if (k <= MAX_COLS) fl->col[k] = col;
    /* The exact fast path (fast_number.h) reads nearly every field of ordinary data in one pass
     * over its characters; a field it declines (or one followed by anything but a blank) is
     * delimited again and goes through the character check and strtod, which word the errors. */
    double v = 0.0;
    const char *q = k < MAX_COLS ? nav_fast_number_scan(line + i, line + n, &v) : NULL;
    if (q && (q == line + n || is_blank(*q))) {
      i = (size_t)(q - line);
      fl->end_col = (int)i + 1;
      fl->v[k] = v;
      while (i < n && is_blank(line[i]))
        ++i;
      continue;
    }
    while (i < n && !is_blank(line[i]))
      ++i;
    const size_t len = i - start;
    fl->end_col = (int)i + 1;
    if (k < MAX_COLS) {
      char shown[48], msg[160];
      {
        bool ok = true;
        for (size_t j = start; j < i && ok; ++j)
          ok = is_num_char(line[j]);
        char *end = NULL;
        if (ok) {
          /* Overflow gives +-HUGE_VAL (caught below); underflow a denormal or zero, accepted.
           * uselocale is per thread and cheap (a pointer swap): "C" numbers whatever the
           * process locale. */
          const locale_t old = uselocale(r->c_numeric);
          v = strtod(line + start, &end);
          uselocale(old);
          ok = end == line + i;
        }
        if (!ok) {
          excerpt(shown, sizeof shown, line + start, len);
          if (is_nonfinite_word(line + start, len))
            snprintf(msg, sizeof msg, "expected a finite number, found \"%s\"", shown);
          else
            snprintf(msg, sizeof msg, "expected a number, found \"%s\"%s", shown,
                     r->line == 1 ? " (a header line must start with '#')" : "");
          return field_error(r, k, col, msg);
        }
      }
      if (!isfinite(v)) {
        excerpt(shown, sizeof shown, line + start, len);
        snprintf(msg, sizeof msg, "\"%s\" is out of the range of a double; expected a finite number", shown);
        return field_error(r, k, col, msg);
      }
      fl->v[k] = v;
    }
    while (i < n && is_blank(line[i]))
      ++i;
  }
  return NAV_OK;
}

/*
 * Line-level fast path of split() for lines of exactly @p want fields in the shapes printf writes
 * them in our data files: fixed-point "%.Nf" (the rows of .nav reference files, the time of IMU
 * records) and, where @p sci is set, "%.12e" first (the increments of KF-GINS IMU files). Each
 * field is converted by nav_fast_sci12_scan_padded() or nav_fast_fixed_scan_padded(), which give
 * the value split() gives, and the blanks between fields are skipped, in one pass without the
 * per-field bookkeeping of split(). The line is NUL-terminated in the padded buffer of the reader.
 * @return false for any other line (leading blank, comment, other shape or count, anything after
 * the last field), which split() then reads as before; nothing is reported here.
 */
static inline __attribute__((always_inline)) bool split_fixed(char *line, size_t n, int want, bool sci,
                                                             fields *fl) {
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
  const char *p = line, *const end = line + n;
  /* (Unrolled: the field count is a constant of each caller, and the loop's exit is then no
   * branch to predict.) */
#pragma GCC unroll 16
  for (int k = 0; k < want; ++k) {
    const char *q = sci && k > 0 ? nav_fast_sci12_scan_padded(p, &fl->v[k]) : NULL;
    if (!q) q = nav_fast_fixed_scan_padded(p, &fl->v[k]);
    if (!q) return false;
    if (k + 1 == want) {
      if (q != end) return false;
    } else {
      if (!is_blank(*q)) return false; /* (the terminating NUL is not a blank) */
      do
        ++q;
      while (is_blank(*q));
    }
    p = q;
  }
  fl->count = want;
  fl->fast = true;
  fl->line = line;
  fl->n = n;
  return true;
#else
  (void)line;
  (void)n;
  (void)want;
  (void)sci;
  (void)fl;
  return false;
#endif
}

/* split_fixed() for the two formats (separate functions: each loop is compiled for its shapes). */
static __attribute__((noinline)) bool split_pva_line(char *line, size_t n, fields *fl) {
  return split_fixed(line, n, 11, false, fl);
}
static __attribute__((noinline)) bool split_imu_line(char *line, size_t n, fields *fl) {
  return split_fixed(line, n, 7, true, fl);
}

/* A .nav row with the layout of the row learned last (line_layout.h): its 11 fields converted
 * from their known places, with the values split_pva_line() gives. */
static __attribute__((noinline)) bool pva_layout_line(const nav_line_layout *lay, char *line, size_t n,
                                                      fields *fl) {
  if (!nav_layout_match(lay, line, n)) return false;
  nav_layout_convert(lay, line, 11, fl->v);
  fl->count = 11;
  fl->fast = true;
  fl->line = line;
  fl->n = n;
  return true;
}

/* A .nav row that did not match the layout and that split_pva_line() read: learn its layout, at
 * once for the first misses in a row (a sign or a digit count changed), then every 64th row only
 * (a file whose layout changes from row to row pays little for the attempts). */
static void pva_layout_missed(nav_rec_reader *r, const char *line, size_t n) {
  const unsigned m = r->pva_layout_misses++;
  if (m < 8u || (m & 63u) == 0u) (void)nav_layout_learn(&r->pva_layout, line, n, 11);
}

/* The columns of a line read by split_fixed(), for a message (split() gives the same values). */
static void with_cols(nav_rec_reader *r, fields *fl) {
  if (!fl->fast) return;
  fl->fast = false;
  (void)split(r, fl->line, fl->n, fl);
}

static nav_status column_count_error(nav_rec_reader *r, const fields *fl, const char *expect) {
  char msg[320];
  snprintf(msg, sizeof msg, "expected %s, found %d", expect, fl->count);
  /* Too many: point at the first extra field; too few: at the end of the line. */
  int col = fl->end_col;
  int expected_max = r->fmt == NAV_REC_IMU ? 7 : (r->fmt == NAV_REC_PVA ? 11 : 13);
  if (r->fmt == NAV_REC_GNSS && r->gnss_cols == 7) expected_max = 7;
  if (fl->count > expected_max && expected_max <= MAX_COLS) col = fl->col[expected_max];
  return fail(r, NAV_ERR_PARSE, (int)r->line, col, "", msg);
}

static nav_status range_error(nav_rec_reader *r, fields *fl, int i, const char *fmt_msg, double v) {
  with_cols(r, fl);
  char msg[200];
  snprintf(msg, sizeof msg, fmt_msg, v);
  return field_error(r, i, fl->col[i], msg);
}

/* Next non-blank line as fields, with the column count and time order checked. */
static nav_status next_record(nav_rec_reader *r, fields *fl, bool *got) {
  *got = false;
  if (r->failed != NAV_OK) return r->failed;
  for (;;) {
    char *line = NULL;
    size_t n = 0;
    nav_status st = next_line(r, &line, &n);
    if (st != NAV_OK) return st;
    if (!line) return NAV_OK;
    fl->fast = false;
    if (r->fmt == NAV_REC_PVA) {
      if (pva_layout_line(&r->pva_layout, line, n, fl)) {
        r->pva_layout_misses = 0;
        break;
      }
      if (split_pva_line(line, n, fl)) {
        pva_layout_missed(r, line, n);
        break;
      }
    } else if (r->fmt == NAV_REC_IMU && split_imu_line(line, n, fl)) {
      break;
    }
    st = split(r, line, n, fl);
    if (st != NAV_OK) return st;
    if (fl->count > 0) break;
  }
  switch (r->fmt) {
  case NAV_REC_IMU:
    if (fl->count != 7) return column_count_error(r, fl, k_expect_imu);
    break;
  case NAV_REC_GNSS:
    if (r->gnss_cols == 0 && (fl->count == 7 || fl->count == 13)) r->gnss_cols = fl->count;
    if (fl->count != r->gnss_cols) {
      if (r->gnss_cols == 0) return column_count_error(r, fl, k_expect_gnss);
      char expect[160];
      snprintf(expect, sizeof expect, "%d columns like the first record of the file", r->gnss_cols);
      return column_count_error(r, fl, expect);
    }
    break;
  case NAV_REC_PVA:
    if (fl->count != 11) return column_count_error(r, fl, k_expect_pva);
    break;
  default: return NAV_ERR_INVALID_ARG;
  }
  const int it = r->fmt == NAV_REC_PVA ? 1 : 0;
  const double t = fl->v[it];
  if (r->have_prev && !(t > r->t_prev)) {
    with_cols(r, fl);
    char msg[200];
    snprintf(msg, sizeof msg,
             "time must increase from record to record: %.6f s is not after %.6f s (line %ld)", t, r->t_prev,
             r->prev_line);
    return field_error(r, it, fl->col[it], msg);
  }
  *got = true;
  return NAV_OK;
}

/* Commit a validated record: time order state and the record line. */
static void accept(nav_rec_reader *r, double t) {
  r->have_prev = true;
  r->t_prev = t;
  r->prev_line = r->line;
  r->rec_line = r->line;
}

static double deg_to_rad_wrapped(double deg) {
  return nav_wrap_pi(deg * NAV_DEG2RAD);
}

/* Largest velocity increment of one IMU record [m/s]: 1000 g over a whole second. Accelerometer
 * ranges end at tens of g (a few hundred for shock-rated parts) and recorded intervals are 1-10 ms,
 * so a larger value is not an increment (wrong units, or another file); 1e300 made the filter's
 * state non-finite. */
#define REC_MAX_DVEL_MPS 1.0e4
/* Recorded heights [m]: the range of a scene's earth.origin.h_m (nav_scene_validate). */
#define REC_MIN_H_M (-1.0e5)
#define REC_MAX_H_M 1.0e8

nav_status nav_rec_read_imu(nav_rec_reader *r, nav_imu_increment *out, bool *got) {
  if (!r || !out || !got || r->fmt != NAV_REC_IMU) return NAV_ERR_INVALID_ARG;
  fields fl;
  const nav_status st = next_record(r, &fl, got);
  if (st != NAV_OK || !*got) return st;
  /* More than half a turn in one interval is not an increment: usually rates (or degrees), or
   * another file given as the IMU file. */
  for (int i = 1; i <= 3; ++i)
    if (!(fabs(fl.v[i]) <= NAV_PI)) {
      *got = false;
      return range_error(
          r, &fl, i,
          "angle increment %.9g rad exceeds pi; expected the increment over one interval in rad "
          "(not a rate, not degrees)",
          fl.v[i]);
    }
  for (int i = 4; i <= 6; ++i)
    if (!(fabs(fl.v[i]) <= REC_MAX_DVEL_MPS)) {
      *got = false;
      return range_error(r, &fl, i,
                         "velocity increment %.9g m/s exceeds 1e4 m/s (1000 g over one second); expected the "
                         "increment over one interval in m/s (not an acceleration in other units)",
                         fl.v[i]);
    }
  nav_imu_increment m;
  m.k = r->k;
  m.t_s = fl.v[0];
  m.dt_s = r->have_prev ? fl.v[0] - r->t_prev : 0.0;
  m.dtheta_b_rad = nav_vec3_make(fl.v[1], fl.v[2], fl.v[3]);
  m.dv_b_mps = nav_vec3_make(fl.v[4], fl.v[5], fl.v[6]);
  accept(r, m.t_s);
  r->k++;
  *out = m;
  return NAV_OK;
}

/* Common geodetic checks of GNSS and .nav rows; i is the latitude column. */
static nav_status check_position(nav_rec_reader *r, fields *fl, int i) {
  if (!(fabs(fl->v[i]) <= 90.0))
    return range_error(r, fl, i, "latitude %.9g deg outside [-90, 90]", fl->v[i]);
  if (!(fl->v[i + 1] >= -180.0 && fl->v[i + 1] <= 360.0))
    return range_error(r, fl, i + 1, "longitude %.9g deg outside [-180, 360]", fl->v[i + 1]);
  return NAV_OK;
}

nav_status nav_rec_read_gnss(nav_rec_reader *r, nav_ins_gnss_fix *out, bool *got) {
  if (!r || !out || !got || r->fmt != NAV_REC_GNSS) return NAV_ERR_INVALID_ARG;
  fields fl;
  nav_status st = next_record(r, &fl, got);
  if (st != NAV_OK || !*got) return st;
  *got = false;
  st = check_position(r, &fl, 1);
  if (st != NAV_OK) return st;
  if (!(fl.v[3] >= REC_MIN_H_M && fl.v[3] <= REC_MAX_H_M))
    return range_error(r, &fl, 3, "height %.9g m outside [-1e5, 1e8] m (the heights a scene accepts)", fl.v[3]);
  for (int i = 4; i < fl.count; ++i) {
    if ((i >= 4 && i <= 6) || i >= 10) {
      if (!(fl.v[i] >= 0.0))
        return range_error(r, &fl, i, "standard deviation %.9g is negative; expected >= 0", fl.v[i]);
      /* The receiver bounds of a scene (scene_bounds.h): a fix known worse than this is an outlier
         to leave out, and 1e300 made the filter's measurement covariance infinite. */
      if (i <= 6 && !(fl.v[i] <= NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M))
        return range_error(r, &fl, i,
                           "standard deviation %.9g m exceeds 1000 m (the bound of a scene's GNSS position "
                           "sigmas); leave such a fix out of the file",
                           fl.v[i]);
      if (i >= 10 && !(fl.v[i] <= NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS))
        return range_error(r, &fl, i,
                           "standard deviation %.9g m/s exceeds 100 m/s (the bound of a scene's GNSS velocity "
                           "sigmas); leave such a fix out of the file",
                           fl.v[i]);
    } else if (!(fabs(fl.v[i]) <= NAV_SCENE_MAX_SPEED_MPS)) {
      return range_error(r, &fl, i, "velocity %.9g m/s exceeds 1e5 m/s (the speed bound of a scene)", fl.v[i]);
    }
  }
  nav_ins_gnss_fix f;
  memset(&f, 0, sizeof f);
  f.t_s = fl.v[0];
  f.pos.lat_rad = fl.v[1] * NAV_DEG2RAD;
  f.pos.lon_rad = deg_to_rad_wrapped(fl.v[2]);
  f.pos.h_m = fl.v[3];
  f.pos_sd_m = nav_vec3_make(fl.v[4], fl.v[5], fl.v[6]);
  f.has_vel = fl.count == 13;
  if (f.has_vel) {
    f.v_n_mps = nav_vec3_make(fl.v[7], fl.v[8], fl.v[9]);
    f.vel_sd_mps = nav_vec3_make(fl.v[10], fl.v[11], fl.v[12]);
  }
  accept(r, f.t_s);
  r->k++;
  *out = f;
  *got = true;
  return NAV_OK;
}

nav_status nav_rec_read_pva(nav_rec_reader *r, nav_rec_pva *out, bool *got) {
  if (!r || !out || !got || r->fmt != NAV_REC_PVA) return NAV_ERR_INVALID_ARG;
  fields fl;
  nav_status st = next_record(r, &fl, got);
  if (st != NAV_OK || !*got) return st;
  *got = false;
  if (!(fl.v[0] >= 0.0 && fl.v[0] == floor(fl.v[0]) && fl.v[0] <= 1e9))
    return range_error(r, &fl, 0, "GPS week %.9g: expected an integer >= 0", fl.v[0]);
  st = check_position(r, &fl, 2);
  if (st != NAV_OK) return st;
  if (!(fabs(fl.v[8]) <= 180.0)) return range_error(r, &fl, 8, "roll %.9g deg outside [-180, 180]", fl.v[8]);
  if (!(fabs(fl.v[9]) <= 90.0)) return range_error(r, &fl, 9, "pitch %.9g deg outside [-90, 90]", fl.v[9]);
  if (!(fl.v[10] >= -180.0 && fl.v[10] <= 360.0))
    return range_error(r, &fl, 10, "yaw %.9g deg outside [-180, 360]", fl.v[10]);
  nav_rec_pva p;
  p.week = (int)fl.v[0];
  p.t_s = fl.v[1];
  p.pos.lat_rad = fl.v[2] * NAV_DEG2RAD;
  p.pos.lon_rad = deg_to_rad_wrapped(fl.v[3]);
  p.pos.h_m = fl.v[4];
  p.v_n_mps = nav_vec3_make(fl.v[5], fl.v[6], fl.v[7]);
  p.att.roll_rad = fl.v[8] * NAV_DEG2RAD;
  p.att.pitch_rad = fl.v[9] * NAV_DEG2RAD;
  p.att.yaw_rad = deg_to_rad_wrapped(fl.v[10]);
  accept(r, p.t_s);
  r->k++;
  *out = p;
  *got = true;
  return NAV_OK;
}

/* ---------------------------------------------------------------- loaders */

static void copy_diag(nav_diag *dst, const nav_rec_reader *r) {
  if (dst && r) *dst = r->diag;
}

/* One loader for the three formats; @p read reads one record of @p size bytes into @p slot. */
typedef nav_status (*read_fn)(nav_rec_reader *r, void *slot, bool *got);
static nav_status read_imu_v(nav_rec_reader *r, void *s, bool *g) {
  return nav_rec_read_imu(r, s, g);
}
static nav_status read_gnss_v(nav_rec_reader *r, void *s, bool *g) {
  return nav_rec_read_gnss(r, s, g);
}
static nav_status read_pva_v(nav_rec_reader *r, void *s, bool *g) {
  return nav_rec_read_pva(r, s, g);
}

static nav_status load(const char *path, nav_rec_format fmt, read_fn read, void *out, size_t size,
                       size_t capacity, size_t *count, nav_diag *diag) {
  if (!path || (!out && capacity > 0) || !count) return NAV_ERR_INVALID_ARG;
  nav_rec_reader *r = NULL;
  nav_status st = nav_rec_reader_open(path, fmt, &r, diag);
  if (st != NAV_OK) return st;
  size_t n = 0;
  for (;;) {
    bool got = false;
    if (n == capacity) {
      /* One more record would not fit: read it to tell "exactly full" from "too many". */
      union {
        nav_imu_increment a;
        nav_ins_gnss_fix b;
        nav_rec_pva c;
      } extra;
      st = read(r, &extra, &got);
      if (st == NAV_OK && got) {
        diag_set(diag, path, (int)r->rec_line, 1, "", "more than %zu records; expected at most %zu", capacity,
                 capacity);
        st = NAV_ERR_OUT_OF_RANGE;
        goto cleanup;
      }
    } else {
      st = read(r, (char *)out + n * size, &got);
    }
    if (st != NAV_OK) {
      copy_diag(diag, r);
      goto cleanup;
    }
    if (!got) break;
    ++n;
  }
  *count = n;
cleanup:
  nav_rec_reader_destroy(r);
  return st;
}

nav_status nav_rec_check_file(const char *path, nav_rec_format fmt, size_t *count, nav_diag *diag) {
  if (!path || (fmt != NAV_REC_IMU && fmt != NAV_REC_GNSS && fmt != NAV_REC_PVA)) return NAV_ERR_INVALID_ARG;
  read_fn read = fmt == NAV_REC_IMU ? read_imu_v : fmt == NAV_REC_GNSS ? read_gnss_v : read_pva_v;
  nav_rec_reader *r = NULL;
  nav_status st = nav_rec_reader_open(path, fmt, &r, diag);
  if (st != NAV_OK) return st;
  size_t n = 0;
  for (;;) {
    union {
      nav_imu_increment a;
      nav_ins_gnss_fix b;
      nav_rec_pva c;
    } rec;
    bool got = false;
    st = read(r, &rec, &got);
    if (st != NAV_OK) {
      copy_diag(diag, r);
      break;
    }
    if (!got) break;
    ++n;
  }
  if (st == NAV_OK && count) *count = n;
  nav_rec_reader_destroy(r);
  return st;
}

nav_status nav_rec_load_imu(const char *path, nav_imu_increment *out, size_t capacity, size_t *count,
                            nav_diag *diag) {
  return load(path, NAV_REC_IMU, read_imu_v, out, sizeof *out, capacity, count, diag);
}
nav_status nav_rec_load_gnss(const char *path, nav_ins_gnss_fix *out, size_t capacity, size_t *count,
                             nav_diag *diag) {
  return load(path, NAV_REC_GNSS, read_gnss_v, out, sizeof *out, capacity, count, diag);
}
nav_status nav_rec_load_pva(const char *path, nav_rec_pva *out, size_t capacity, size_t *count,
                            nav_diag *diag) {
  return load(path, NAV_REC_PVA, read_pva_v, out, sizeof *out, capacity, count, diag);
}

/* ---------------------------------------------------------------- IMU file in memory */

/* Files below this size are read by one thread: a second one would not pay for its start. */
#define SPLIT_MIN_BYTES (4u * 1024u * 1024u)

/* The records of one stretch of an IMU file ([off, off + len), or all of it when whole), its
 * line count and the state a sequential reader would carry into the next stretch. */
typedef struct imu_part {
  const char *path;
  size_t off, len;
  bool whole;
  nav_imu_increment *rec;
  size_t n, cap;
  long lines, cut_line, last_line;
  nav_status st;
  nav_diag diag;
} imu_part;

static void *imu_part_read(void *arg) {
  imu_part *q = arg;
  nav_rec_reader *r = NULL;
  q->st = nav_rec_reader_open(q->path, NAV_REC_IMU, &r, &q->diag);
  if (q->st == NAV_OK && !q->whole) {
    r->file_left = q->len;
    if (fseeko(r->f, (off_t)q->off, SEEK_SET) != 0) {
      diag_set(&q->diag, q->path, 0, 0, "", "cannot read the IMU file: %s", strerror(errno));
      q->st = NAV_ERR_IO;
    }
  }
  for (bool got = true; q->st == NAV_OK && got;) {
    if (q->n == q->cap) {
      const size_t cap = q->cap ? 2 * q->cap : 4096;
      nav_imu_increment *g = realloc(q->rec, cap * sizeof *g);
      if (!g) {
        q->st = NAV_ERR_NO_MEMORY;
        break;
      }
      q->rec = g;
      q->cap = cap;
    }
    q->st = nav_rec_read_imu(r, &q->rec[q->n], &got);
    if (q->st != NAV_OK) q->diag = r->diag;
    if (q->st == NAV_OK && got) q->n++;
  }
  if (r) {
    q->lines = r->line;
    q->cut_line = r->cut_line;
    q->last_line = r->rec_line;
  }
  nav_rec_reader_destroy(r);
  return NULL;
}

void nav_rec_imu_array_free(nav_rec_imu_array *a) {
  if (!a) return;
  free(a->part[0]);
  free(a->part[1]);
  memset(a, 0, sizeof *a);
}

/* Offset just past the first line end at or after @p from (0 when there is none within 64 KiB,
 * longer than any record line). */
static size_t line_start_after(FILE *f, size_t from) {
  char win[64 * 1024];
  if (fseeko(f, (off_t)from, SEEK_SET) != 0) return 0;
  const size_t n = fread(win, 1, sizeof win, f);
  const char *nl = memchr(win, '\n', n);
  return nl ? from + (size_t)(nl - win) + 1 : 0;
}

nav_status nav_rec_imu_array_load(const char *path, size_t max_bytes, nav_rec_imu_array *out,
                                  nav_diag *diag) {
  if (!path || !out) return NAV_ERR_INVALID_ARG;
  imu_part a, b;
  memset(&a, 0, sizeof a);
  memset(&b, 0, sizeof b);
  FILE *f = NULL;
  char why[320];
  nav_status st = nav_io_fopen_regular(path, &f, why, sizeof why);
  if (st != NAV_OK) {
    /* The reader's wording of the same failure ("cannot open the IMU file: ..."). */
    nav_rec_reader *r = NULL;
    st = nav_rec_reader_open(path, NAV_REC_IMU, &r, diag);
    nav_rec_reader_destroy(r);
    return st != NAV_OK ? st : NAV_ERR_IO;
  }
  struct stat sb;
  size_t size = 0, split = 0;
  if (fstat(fileno(f), &sb) == 0 && S_ISREG(sb.st_mode) && sb.st_size > 0) size = (size_t)sb.st_size;
  if (size > max_bytes) {
    fclose(f);
    diag_set(diag, path, 0, 0, "", "the IMU file has %zu bytes, more than the %zu to hold in memory", size,
             max_bytes);
    return NAV_ERR_OUT_OF_RANGE;
  }
  /* Two stretches split at a line start past the middle: the second reader starts where the
   * sequential one would start that line. */
  if (size >= SPLIT_MIN_BYTES) split = line_start_after(f, size / 2);
  fclose(f);
  a.path = path;
  b.path = path;
  a.whole = split == 0;
  a.len = split;
  b.off = split;
  b.len = size - split;
  /* POSIX threads (as the navsim commands): ThreadSanitizer follows them, not C11 thrd_create. */
  pthread_t th;
  bool threaded = false;
  if (split > 0) threaded = pthread_create(&th, NULL, imu_part_read, &b) == 0;
  (void)imu_part_read(&a);
  if (split > 0) {
    if (threaded)
      (void)pthread_join(th, NULL);
    else
      (void)imu_part_read(&b);
  }
  /* The second stretch continues the first: record indices and line numbers go on, the first
   * interval spans the split, and time must increase across it. */
  bool joined = a.st == NAV_OK && b.st == NAV_OK;
  if (joined && b.n > 0 && a.n > 0 && !(b.rec[0].t_s > a.rec[a.n - 1].t_s)) joined = false;
  if (split > 0 && joined) {
    for (size_t i = 0; i < b.n; ++i)
      b.rec[i].k += (int64_t)a.n;
    if (b.n > 0 && a.n > 0) b.rec[0].dt_s = b.rec[0].t_s - a.rec[a.n - 1].t_s;
    if (b.n > 0) a.last_line = a.lines + b.last_line;
    a.cut_line = b.cut_line ? a.lines + b.cut_line : a.cut_line;
  } else if (split > 0) {
    /* An error somewhere, or time not increasing across the split: the sequential reader over the
     * whole file finds the first problem and words it exactly. */
    free(a.rec);
    free(b.rec);
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.path = path;
    a.whole = true;
    (void)imu_part_read(&a);
  }
  st = a.st;
  if (st != NAV_OK) {
    if (diag) *diag = a.diag;
    goto cleanup;
  }
  out->part[0] = a.rec;
  out->part_count[0] = a.n;
  out->part[1] = b.rec;
  out->part_count[1] = b.n;
  out->count = a.n + b.n;
  out->cut_line = a.cut_line;
  out->last_record_line = a.last_line;
  a.rec = NULL;
  b.rec = NULL;
cleanup:
  free(a.rec);
  free(b.rec);
  return st;
}

/* ---------------------------------------------------------------- IMU file as a stream */

/* Records per block of the stream (72 bytes each: about 0.6 MB per block). Blocks are never moved,
 * so a record handed out stays where it is while the parser goes on. */
#define STREAM_BLOCK 8192u
/* Records parsed between two hand-overs to the consumer (a lock and a broadcast each). */
#define STREAM_PUBLISH 1024u
/* The consumer looks at the parser's state at least every this many records, so that a bad
 * record late in the file stops it soon after it is found. */
#define STREAM_LOOK 4096u
/* The shortest IMU record line: seven one-character fields, six separators and a line end. */
#define STREAM_MIN_LINE_BYTES 14u

struct nav_rec_imu_stream {
  nav_rec_reader *r;
  size_t file_bytes;
  nav_imu_increment **blocks; /* block table, sized for the most records the file can hold */
  size_t nblocks;
  bool threaded;
  pthread_t th;
  pthread_mutex_t m;
  pthread_cond_t cv;
  atomic_bool stop; /* destroy: the parser stops at its next block */
  /* Under m: records handed over, their byte fraction of the file, the end and its status. */
  size_t avail;
  double frac;
  bool done;
  nav_status st;
  /* Written by the parser before it sets done (read after seeing done under m). */
  long cut_line, last_line;
  nav_diag diag;
  /* The consumer's copy of the state above (nav_rec_imu_stream_at() and the replay only). */
  size_t c_avail;
  double c_frac;
  bool c_done;
  nav_status c_st;
};

static void stream_publish(nav_rec_imu_stream *s, size_t n, bool done, nav_status st) {
  pthread_mutex_lock(&s->m);
  s->avail = n;
  s->frac = nav_rec_reader_fraction(s->r);
  if (done) {
    s->done = true;
    s->st = st;
  }
  pthread_cond_broadcast(&s->cv);
  pthread_mutex_unlock(&s->m);
}

static void *stream_main(void *arg) {
  nav_rec_imu_stream *s = arg;
  size_t n = 0;
  nav_status st = NAV_OK;
  for (;;) {
    if (n % STREAM_BLOCK == 0) {
      if (atomic_load_explicit(&s->stop, memory_order_relaxed)) {
        st = NAV_ERR_CANCELLED;
        break;
      }
      const size_t b = n / STREAM_BLOCK;
      /* (The table holds the records of the shortest possible lines: never reached.) */
      if (b >= s->nblocks) {
        st = NAV_ERR_NO_MEMORY;
        break;
      }
      if (!s->blocks[b]) s->blocks[b] = malloc(STREAM_BLOCK * sizeof **s->blocks);
      if (!s->blocks[b]) {
        st = NAV_ERR_NO_MEMORY;
        break;
      }
    }
    bool got = false;
    st = nav_rec_read_imu(s->r, &s->blocks[n / STREAM_BLOCK][n % STREAM_BLOCK], &got);
    if (st != NAV_OK) {
      s->diag = s->r->diag;
      break;
    }
    if (!got) break;
    ++n;
    if (n % STREAM_PUBLISH == 0) stream_publish(s, n, false, NAV_OK);
  }
  s->cut_line = s->r->cut_line;
  s->last_line = s->r->rec_line;
  stream_publish(s, n, true, st);
  return NULL;
}

nav_status nav_rec_imu_stream_start(const char *path, size_t max_bytes, nav_rec_imu_stream **out,
                                    nav_diag *diag) {
  if (!path || !out) return NAV_ERR_INVALID_ARG;
  nav_rec_reader *r = NULL;
  nav_status st = nav_rec_reader_open(path, NAV_REC_IMU, &r, diag);
  if (st != NAV_OK) return st;
  const size_t size = r->total > 0.0 ? (size_t)r->total : 0u;
  if (size > max_bytes) {
    nav_rec_reader_destroy(r);
    diag_set(diag, path, 0, 0, "", "the IMU file has %zu bytes, more than the %zu to hold in memory", size,
             max_bytes);
    return NAV_ERR_OUT_OF_RANGE;
  }
  nav_rec_imu_stream *s = calloc(1, sizeof *s);
  const size_t most = (size + 1) / STREAM_MIN_LINE_BYTES + 1;
  const size_t nblocks = most / STREAM_BLOCK + 1;
  nav_imu_increment **blocks = calloc(nblocks, sizeof *blocks);
  if (!s || !blocks) {
    free(s);
    free(blocks);
    nav_rec_reader_destroy(r);
    return NAV_ERR_NO_MEMORY;
  }
  s->r = r;
  s->file_bytes = size;
  s->blocks = blocks;
  s->nblocks = nblocks;
  s->st = NAV_OK;
  atomic_init(&s->stop, false);
  if (pthread_mutex_init(&s->m, NULL) != 0) {
    free(blocks);
    free(s);
    nav_rec_reader_destroy(r);
    return NAV_ERR_NO_MEMORY;
  }
  if (pthread_cond_init(&s->cv, NULL) != 0) {
    pthread_mutex_destroy(&s->m);
    free(blocks);
    free(s);
    nav_rec_reader_destroy(r);
    return NAV_ERR_NO_MEMORY;
  }
  /* POSIX threads (as the other threads here): ThreadSanitizer follows them. Without a thread the
   * whole file is read now. */
  s->threaded = pthread_create(&s->th, NULL, stream_main, s) == 0;
  if (!s->threaded) (void)stream_main(s);
  *out = s;
  return NAV_OK;
}

size_t nav_rec_imu_stream_file_bytes(const nav_rec_imu_stream *s) { return s ? s->file_bytes : 0u; }

size_t nav_rec_imu_stream_max_records(const nav_rec_imu_stream *s) { return s ? s->nblocks * STREAM_BLOCK : 0u; }

/* The consumer's view of the parser's state, waiting until record @p i is parsed or the file
 * ended when @p wait_for is true. */
static void stream_look(nav_rec_imu_stream *s, size_t i, bool wait_for) {
  pthread_mutex_lock(&s->m);
  while (wait_for && s->avail <= i && !s->done)
    pthread_cond_wait(&s->cv, &s->m);
  s->c_avail = s->avail;
  s->c_frac = s->frac;
  s->c_done = s->done;
  s->c_st = s->st;
  pthread_mutex_unlock(&s->m);
}

nav_status nav_rec_imu_stream_at(nav_rec_imu_stream *s, size_t i, const nav_imu_increment **rec) {
  if (!s || !rec) return NAV_ERR_INVALID_ARG;
  if (i >= s->c_avail || i % STREAM_LOOK == 0) stream_look(s, i, true);
  if (s->c_done && s->c_st != NAV_OK) return s->c_st;
  *rec = i < s->c_avail ? &s->blocks[i / STREAM_BLOCK][i % STREAM_BLOCK] : NULL;
  return NAV_OK;
}

bool nav_rec_imu_stream_poll(nav_rec_imu_stream *s, nav_status *st, size_t *count) {
  if (!s) return false;
  pthread_mutex_lock(&s->m);
  const bool done = s->done;
  if (done && st) *st = s->st;
  if (done && count) *count = s->avail;
  pthread_mutex_unlock(&s->m);
  return done;
}

nav_status nav_rec_imu_stream_finish(nav_rec_imu_stream *s, size_t *count, long *cut_line, long *last_line,
                                     nav_diag *diag) {
  if (!s) return NAV_ERR_INVALID_ARG;
  stream_look(s, SIZE_MAX, true);
  if (s->c_st != NAV_OK) {
    if (diag) *diag = s->diag;
    return s->c_st;
  }
  if (count) *count = s->c_avail;
  if (cut_line) *cut_line = s->cut_line;
  if (last_line) *last_line = s->last_line;
  return NAV_OK;
}

void nav_rec_imu_stream_destroy(nav_rec_imu_stream *s) {
  if (!s) return;
  if (s->threaded) {
    atomic_store_explicit(&s->stop, true, memory_order_relaxed);
    (void)pthread_join(s->th, NULL);
  }
  pthread_cond_destroy(&s->cv);
  pthread_mutex_destroy(&s->m);
  for (size_t b = 0; b < s->nblocks; ++b)
    free(s->blocks[b]);
  free(s->blocks);
  nav_rec_reader_destroy(s->r);
  free(s);
}

nav_traj_state nav_rec_pva_to_state(const nav_rec_pva *row) {
  nav_traj_state s;
  memset(&s, 0, sizeof s);
  s.t_s = row->t_s;
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(row->pos.lat_rad, row->pos.lon_rad);
  s.r_fb_f_m = nav_earth_geodetic_to_ecef(row->pos);
  s.v_fb_f_mps = nav_mat3_mul_vec(C_n_e, row->v_n_mps);
  /* q_b_e = q_n_e (x) q_b_n (style.md section 4: inner indices touch). */
  s.q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), nav_euler_to_quat(row->att)));
  return s;
}

/* ================================================================ replay */

nav_replay_config nav_replay_config_default(void) {
  nav_replay_config c;
  memset(&c, 0, sizeof c);
  c.nav.ins = nav_ins_config_default();
  c.nav.ins.earth_model = NAV_EARTH_WGS84;
  c.nav.ins.algorithm = NAV_MECH_HIGH_ORDER;
  c.nav.ins.mech_frame = NAV_MECH_NED;
  c.nav.ins.gravity_model = NAV_GRAVITY_NORMAL;
  c.nav.filter = nav_filter_config_default();
  c.nav.r_ba_b_m = nav_vec3_zero();
  c.nav.pos_sd_floor_m = 1e-3;
  c.nav.vel_sd_floor_mps = 1e-3;
  c.ref_sync_tol_s = 1e-4;
  c.output_interval_s = 0.1;
  c.gap_factor = 1.5;
  c.read_ahead = true;
  return c;
}

/* Running RMS / max of the metrics (streaming: memory does not grow with the epochs). */
enum { N_M = 8 };

/* The metrics of an epoch (computed once when two accumulators take the same epoch). */
static void stats_values(const nav_epoch_errors *e, double v[N_M]) {
  v[0] = e->pos_err_h_m;
  v[1] = e->pos_err_v_m;
  v[2] = hypot(e->vel_err_n_mps.x, e->vel_err_n_mps.y);
  v[3] = fabs(e->vel_err_n_mps.z);
  v[4] = fabs(e->euler_err.roll_rad);
  v[5] = fabs(e->euler_err.pitch_rad);
  v[6] = fabs(e->euler_err.yaw_rad);
  v[7] = e->att_err_rad;
}

static void stats_add_values(nav_replay_stats_acc *a, const double v[N_M], double t_s, const nav_epoch_errors *e) {
  for (int m = 0; m < N_M; ++m) {
    a->sum_sq[m] += v[m] * v[m];
    if (a->n == 0 || v[m] > a->max[m]) {
      a->max[m] = v[m];
      a->t_max[m] = t_s;
    }
  }
  a->sum_pos = nav_vec3_add(a->sum_pos, e->pos_err_n_m);
  a->sum_vel = nav_vec3_add(a->sum_vel, e->vel_err_n_mps);
  a->n++;
}

void nav_replay_stats_add(nav_replay_stats_acc *a, const nav_epoch_errors *e) {
  double v[N_M];
  stats_values(e, v);
  stats_add_values(a, v, e->t_s, e);
}

nav_replay_stats nav_replay_stats_result(const nav_replay_stats_acc *a) {
  nav_replay_stats s;
  memset(&s, 0, sizeof s);
  s.epochs = a->n;
  if (a->n == 0) return s;
  nav_replay_stat *dst[N_M] = {&s.pos_h_m,  &s.pos_v_m,   &s.vel_h_mps, &s.vel_v_mps,
                               &s.roll_rad, &s.pitch_rad, &s.yaw_rad,   &s.att_rad};
  for (int m = 0; m < N_M; ++m) {
    dst[m]->rms = sqrt(a->sum_sq[m] / (double)a->n);
    dst[m]->max = a->max[m];
    dst[m]->t_max_s = a->t_max[m];
  }
  s.pos_mean_n_m = nav_vec3_scale(a->sum_pos, 1.0 / (double)a->n);
  s.vel_mean_n_mps = nav_vec3_scale(a->sum_vel, 1.0 / (double)a->n);
  return s;
}

/* WGS-84 frame with its origin at @p p (the formulas of nav_frame_from_scene()). */
static nav_frame frame_at(nav_geodetic p) {
  nav_frame f;
  f.model = NAV_EARTH_WGS84;
  f.origin = p;
  f.m_per_rad_lat = nav_earth_radius_meridian_m(p.lat_rad) + p.h_m;
  f.m_per_rad_lon = (nav_earth_radius_prime_vertical_m(p.lat_rad) + p.h_m) * cos(p.lat_rad);
  return f;
}

/*
 * A single-producer single-consumer queue of fixed-size items between two threads: a ring of
 * RING_CAP slots handed over in batches under a mutex. Each side sleeps only when the ring is full
 * (producer) or empty (consumer), and is woken once half a ring is free or filled (or at the end),
 * so a run of 193 000 items costs a few hundred wake-ups, not one per item. Items keep their
 * order, so what the consumer sees is what one thread doing both would see.
 */
#define RING_CAP 2048u
#define RING_BATCH 64u

typedef struct ring {
  pthread_mutex_t m;
  pthread_cond_t nonempty, nonfull;
  size_t head, tail;    /* published / released items (under m) */
  bool closed, stopped; /* producer finished / consumer wants no more (under m) */
  size_t size;          /* bytes per item */
  unsigned char *buf;
  size_t p_head, p_pub, p_tail; /* producer's view */
  size_t c_head, c_tail, c_rel; /* consumer's view */
  bool c_closed;
} ring;

static bool ring_init(ring *r, size_t item_size) {
  memset(r, 0, sizeof *r);
  r->size = item_size;
  r->buf = malloc(RING_CAP * item_size);
  if (!r->buf) return false;
  if (pthread_mutex_init(&r->m, NULL) != 0) goto fail_buf;
  if (pthread_cond_init(&r->nonempty, NULL) != 0) goto fail_m;
  if (pthread_cond_init(&r->nonfull, NULL) != 0) goto fail_ne;
  return true;
fail_ne:
  pthread_cond_destroy(&r->nonempty);
fail_m:
  pthread_mutex_destroy(&r->m);
fail_buf:
  free(r->buf);
  r->buf = NULL;
  return false;
}

static void ring_destroy(ring *r) {
  if (!r->buf) return;
  pthread_cond_destroy(&r->nonfull);
  pthread_cond_destroy(&r->nonempty);
  pthread_mutex_destroy(&r->m);
  free(r->buf);
  r->buf = NULL;
}

/* Producer: publish the committed items (under m, with the wake-up rule above). */
static void ring_publish(ring *r, bool closing) {
  pthread_mutex_lock(&r->m);
  r->head = r->p_head;
  if (closing) r->closed = true;
  r->p_tail = r->tail;
  if (closing || r->head - r->tail >= RING_CAP / 2) pthread_cond_signal(&r->nonempty);
  pthread_mutex_unlock(&r->m);
  r->p_pub = r->p_head;
}

/* Producer: the next free slot (write it, then ring_commit()), or NULL when the consumer stopped. */
static void *ring_slot(ring *r) {
  if (r->p_head - r->p_tail == RING_CAP) {
    pthread_mutex_lock(&r->m);
    r->head = r->p_head;
    r->p_pub = r->p_head;
    pthread_cond_signal(&r->nonempty);
    while (RING_CAP - (r->p_head - r->tail) < RING_CAP / 2 && !r->stopped)
      pthread_cond_wait(&r->nonfull, &r->m);
    r->p_tail = r->tail;
    const bool stopped = r->stopped;
    pthread_mutex_unlock(&r->m);
    if (stopped) return NULL;
  }
  return r->buf + (r->p_head % RING_CAP) * r->size;
}

static void ring_commit(ring *r) {
  ++r->p_head;
  if (r->p_head - r->p_pub >= RING_BATCH) ring_publish(r, false);
}

/* Producer: no more items. */
static void ring_close(ring *r) {
  ring_publish(r, true);
}

/* Consumer: the next item (valid until the next call), or NULL after the last one. */
static const void *ring_next(ring *r) {
  if (r->c_tail == r->c_head || r->c_tail - r->c_rel >= RING_BATCH) {
    if (r->c_tail == r->c_head && r->c_closed) return NULL;
    pthread_mutex_lock(&r->m);
    /* The items consumed so far (the previous one included: its caller is done with it). */
    r->tail = r->c_tail;
    r->c_rel = r->c_tail;
    if (RING_CAP - (r->head - r->tail) >= RING_CAP / 2) pthread_cond_signal(&r->nonfull);
    while (r->head == r->c_tail && !r->closed)
      pthread_cond_wait(&r->nonempty, &r->m);
    r->c_head = r->head;
    r->c_closed = r->closed;
    pthread_mutex_unlock(&r->m);
    if (r->c_tail == r->c_head) return NULL;
  }
  return r->buf + (r->c_tail++ % RING_CAP) * r->size;
}

/* Consumer: up to @p n next items at once, in order, valid until the next call (the items of a
 * call are released together at a later one); 0 after the last. The first may wait; the others
 * are those already at hand. */
static int ring_next_n(ring *r, const void **items, int n) {
  const void *first = ring_next(r);
  if (!first) return 0;
  items[0] = first;
  int k = 1;
  while (k < n && r->c_tail != r->c_head)
    items[k++] = r->buf + (r->c_tail++ % RING_CAP) * r->size;
  return k;
}

/* Consumer: want no more items (the producer's next ring_slot() returns NULL). */
static void ring_stop(ring *r) {
  pthread_mutex_lock(&r->m);
  r->stopped = true;
  pthread_cond_signal(&r->nonfull);
  pthread_mutex_unlock(&r->m);
}

/*
 * Read-ahead of one streamed input (IMU or reference) on a thread, through a ring: memory stays
 * flat. Each item carries what the consumer would have asked the reader right after that record
 * (status, progress fraction, cut line), so the replay sees exactly what reading on its own
 * thread gives. After a terminal item (an error or the end) the thread stops; the reader's diag is
 * then stable and read by the consumer.
 */
typedef struct ra_item {
  nav_status st;
  bool got;
  double fraction;
  long cut_line;
  union {
    nav_imu_increment imu;
    ref_item ref;
  } u;
} ra_item;

typedef struct read_ahead {
  nav_rec_reader *r;
  bool threaded;
  pthread_t th;
  ring q;
  bool ended;
  ra_item one; /* without a thread: the record just read */
  ra_item last;
} read_ahead;

static void ra_read_one(nav_rec_reader *r, ra_item *it) {
  if (r->fmt == NAV_REC_IMU) {
    it->st = nav_rec_read_imu(r, &it->u.imu, &it->got);
  } else {
    it->st = nav_rec_read_pva(r, &it->u.ref.row, &it->got);
    if (it->st == NAV_OK && it->got) ref_item_fill(&it->u.ref);
  }
  it->fraction = nav_rec_reader_fraction(r);
  it->cut_line = r->cut_line;
}

static void *ra_main(void *arg) {
  read_ahead *a = arg;
  for (;;) {
    ra_item *it = ring_slot(&a->q);
    if (!it) break;
    ra_read_one(a->r, it);
    ring_commit(&a->q);
    if (it->st != NAV_OK || !it->got) break;
  }
  ring_close(&a->q);
  return NULL;
}

/* Start reading @p r ahead (on a thread when @p threaded and one can be made). */
static void ra_start(read_ahead *a, nav_rec_reader *r, bool threaded) {
  memset(a, 0, sizeof *a);
  a->r = r;
  if (!threaded || !ring_init(&a->q, sizeof(ra_item))) return;
  if (pthread_create(&a->th, NULL, ra_main, a) != 0) {
    ring_destroy(&a->q);
    return; /* read on the calling thread */
  }
  a->threaded = true;
}

/* The next record; valid until the next call. */
static const ra_item *ra_next(read_ahead *a) {
  if (a->ended) return &a->last;
  const ra_item *it = &a->one;
  if (a->threaded) {
    it = ring_next(&a->q);
  } else {
    ra_read_one(a->r, &a->one);
  }
  if (!it || it->st != NAV_OK || !it->got) {
    /* (it is never NULL: the producer's last item is terminal.) */
    if (it) a->last = *it;
    a->ended = true;
    return &a->last;
  }
  return it;
}

/* Stop the thread (it finishes the record in hand) and release the ring; the reader stays. */
static void ra_stop(read_ahead *a) {
  if (!a->threaded) return;
  ring_stop(&a->q);
  (void)pthread_join(a->th, NULL);
  ring_destroy(&a->q);
  a->threaded = false;
}

/* The open inputs of a replay with one record of look-ahead each. */
typedef struct replay {
  const nav_replay_config *cfg;
  nav_rec_reader *imu, *gnss, *ref;
  read_ahead imu_ra, ref_ra;
  bool imu_ra_on, ref_ra_on;
  size_t imu_idx;      /* cfg->imu: records handed out */
  bool imu_end_seen;   /* cfg->imu: a read past the last record */
  double imu_fraction; /* progress */
  long imu_cut_line;   /* as nav_rec_reader_cut_line() at this point of the reading */
  /* The current reference row and its precomputed parts, borrowed from the read-ahead (valid
   * until the next ref_next(); read in place: no copy per epoch). */
  const ref_item *ref_it;
  bool ref_have;
  long ref_cut_line;
  nav_ins_gnss_fix fix;
  bool fix_have;
  nav_ins_gnss_raw_epoch raw; /* cfg->raw: the next raw epoch */
  nav_replay_summary *sum;
  nav_diag *diag;
} replay;

static nav_status reader_failed(replay *p, const nav_rec_reader *r, nav_status st) {
  copy_diag(p->diag, r);
  return st;
}

static nav_status ref_next(replay *p) {
  const ra_item *it = ra_next(&p->ref_ra);
  if (it->st != NAV_OK) {
    p->ref_have = false;
    return reader_failed(p, p->ref, it->st);
  }
  p->ref_have = it->got;
  p->ref_cut_line = it->cut_line;
  if (p->ref_have) {
    p->ref_it = &it->u.ref;
    p->sum->ref_rows++;
  }
  return NAV_OK;
}

/* The next IMU record: from the caller's array or stream, or the (read-ahead) reader. */
static nav_status imu_next(replay *p, nav_imu_increment *inc, bool *got) {
  nav_rec_imu_stream *s = p->cfg->imu_stream;
  if (s) {
    const nav_imu_increment *rec = NULL;
    *got = false;
    const nav_status st = nav_rec_imu_stream_at(s, p->imu_idx, &rec);
    if (st != NAV_OK) return st;
    *got = rec != NULL;
    if (*got) {
      *inc = *rec;
      p->imu_idx++;
    } else {
      p->imu_end_seen = true;
    }
    /* Records handed out against the records the file holds (known once it is read), or the
     * parser's byte fraction scaled to the records handed out (an estimate, for progress only). */
    if (s->c_done)
      p->imu_fraction = s->c_avail ? (double)p->imu_idx / (double)s->c_avail : 1.0;
    else
      p->imu_fraction = s->c_avail ? fmin(1.0, s->c_frac * (double)p->imu_idx / (double)s->c_avail) : 0.0;
    return NAV_OK;
  }
  const nav_rec_imu_array *a = p->cfg->imu;
  if (a) {
    *got = p->imu_idx < a->count;
    if (*got) {
      *inc = *nav_rec_imu_array_at(a, p->imu_idx++);
    } else {
      p->imu_end_seen = true;
    }
    p->imu_fraction = a->count ? (double)p->imu_idx / (double)a->count : 1.0;
    /* The streaming reader has read the last line once it returned the record on it, or tried to
     * read past the last record. */
    if (a->cut_line && (p->imu_end_seen || (p->imu_idx == a->count && a->cut_line == a->last_record_line)))
      p->imu_cut_line = a->cut_line;
    return NAV_OK;
  }
  const ra_item *it = ra_next(&p->imu_ra);
  p->imu_fraction = it->fraction;
  p->imu_cut_line = it->cut_line;
  *got = false;
  if (it->st != NAV_OK) return it->st;
  *got = it->got;
  if (*got) *inc = it->u.imu;
  return NAV_OK;
}

static nav_status fix_next(replay *p) {
  if (p->cfg->raw) {
    /* A raw epoch stands for a fix: only its time is read by the loop (p->fix.t_s). */
    const nav_status st = p->cfg->raw(p->cfg->raw_user, &p->raw, &p->fix_have, p->diag);
    if (st != NAV_OK) return st;
    if (p->fix_have) {
      if (!isfinite(p->raw.t_s)) {
        diag_set(p->diag, "replay", 0, 0, "", "a raw GNSS epoch with a non-finite time");
        return NAV_ERR_PARSE;
      }
      p->fix.t_s = p->raw.t_s;
      p->sum->gnss_records++;
    }
    return NAV_OK;
  }
  const nav_status st = nav_rec_read_gnss(p->gnss, &p->fix, &p->fix_have);
  if (st != NAV_OK) return reader_failed(p, p->gnss, st);
  if (p->fix_have) {
    p->sum->gnss_records++;
    if (p->fix.has_vel) p->sum->gnss_has_vel = true;
  }
  return NAV_OK;
}

static bool in_outage(const nav_replay_config *c, double t) {
  for (size_t i = 0; i < c->outage_count; ++i)
    if (t >= c->outages[i].t0_s && t < c->outages[i].t1_s) return true;
  return false;
}

static nav_status check_config(const nav_replay_config *c, nav_diag *diag) {
  const char *bad = NULL;
  if (!c->imu_path || !c->ref_path)
    bad = "an IMU file and a reference file are both required";
  else if (c->nav.ins.earth_model != NAV_EARTH_WGS84)
    bad = "recorded data needs the WGS-84 Earth model";
  else if (!(c->ref_sync_tol_s > 0.0 && isfinite(c->ref_sync_tol_s)))
    bad = "ref_sync_tol_s must be finite and > 0";
  else if (!(c->output_interval_s > 0.0 && isfinite(c->output_interval_s)))
    bad = "output_interval_s must be finite and > 0";
  else if (!(c->gap_factor > 1.0 && isfinite(c->gap_factor)))
    bad = "gap_factor must be finite and > 1";
  else if (c->has_start && !isfinite(c->t_start_s))
    bad = "the start time must be finite";
  else if (c->has_end && !isfinite(c->t_end_s))
    bad = "the end time must be finite";
  else if (c->has_start && c->has_end && !(c->t_end_s > c->t_start_s))
    bad = "the end time must be after the start time";
  else if (c->outage_count > NAV_GNSS_MAX_OUTAGES)
    bad = "too many outages";
  else if (c->imu && c->imu_stream)
    bad = "IMU records in memory and an IMU stream are exclusive";
  else if (c->raw && c->gnss_path)
    bad = "raw measurements and a GNSS fix file are exclusive";
  else if (c->raw && !(c->nav.filter.states & NAV_FILTER_STATE_RX_CLOCK))
    bad = "raw measurements need the filter's receiver-clock states (the tightly coupled scheme, "
          "navigation.scheme ins_gnss_tight)";
  for (size_t i = 0; !bad && i < c->outage_count; ++i)
    if (!(isfinite(c->outages[i].t0_s) && isfinite(c->outages[i].t1_s) &&
          c->outages[i].t1_s > c->outages[i].t0_s))
      bad = "each outage needs finite t0 < t1";
  if (!bad) return NAV_OK;
  diag_set(diag, "replay", 0, 0, "", "%s", bad);
  return NAV_ERR_INVALID_ARG;
}

/* The navigation: the closed loop with GNSS, or the free strapdown INS. */
typedef struct nav_side {
  nav_ins_gnss *x;
  nav_ins *ins;
} nav_side;

static const nav_ins_state *nav_state(const nav_side *n) {
  return n->x ? nav_ins_gnss_state(n->x) : nav_ins_get_state(n->ins);
}

/* The NED state of a WGS-84 NED mechanization (false for the ECEF one). */
static bool nav_ned(const nav_side *n, nav_ins_ned *out) {
  return nav_ins_get_ned(n->x ? nav_ins_gnss_ins(n->x) : n->ins, out);
}

/* nav_rec_pva_to_state() of a reference item from the sines and cosines of its latitude and
 * longitude and the quaternion of its Euler angles, which the item has already (the same calls on
 * the same angles): the same operations after those, so the same state bit for bit. */
static nav_traj_state ref_item_state(const ref_item *it) {
  const nav_rec_pva *row = &it->row;
  nav_traj_state s;
  memset(&s, 0, sizeof s);
  s.t_s = row->t_s;
  const nav_mat3 C_n_e = dcm_n_e(it->slt, it->clt, it->sot, it->cot);
  s.r_fb_f_m = nav_earth_geodetic_to_ecef_sc(it->slt, it->clt, it->sot, it->cot, row->pos.h_m);
  s.v_fb_f_mps = nav_mat3_mul_vec(C_n_e, row->v_n_mps);
  s.q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), it->qt));
  return s;
}

/* The errors at a reference row: the NED path when the navigation has one, else the general. */
static nav_epoch_errors errors_at(const nav_frame *frame, const ref_item *ref, const nav_side *n) {
  nav_ins_ned ned;
  if (nav_ned(n, &ned)) return ned_errors(ref, &ned);
  const nav_traj_state ts = ref_item_state(ref);
  return nav_errors_compute(frame, &ts, nav_state(n));
}

/*
 * Scoring of the epochs: errors against the reference, statistics, GNSS gap bookkeeping, and the
 * scored and record callbacks, fed in epoch order with what the navigation had at each epoch.
 * On the calling thread (one item at a time, straight after the step) or, with
 * callbacks_on_worker, on a second thread through a ring while the navigation goes on: the same
 * items in the same order, so the same figures, files and callbacks.
 */
typedef enum sc_kind {
  SC_EPOCH, /* an epoch with a reference row or an output */
  SC_GAP,   /* a GNSS gap ended at this epoch (before its fix): gap filled but for pos_h_max_m */
  SC_FIX    /* a fix was applied: the largest error of the next gap starts again */
} sc_kind;

/* The fields an ordinary epoch writes come first and together: each item crosses to the other
 * core, so the fewer cache lines it touches the better. */
typedef struct sc_item {
  sc_kind kind;
  bool has_ref, output, updated, has_ned;
  union {
    struct {
      nav_ins_ned ned;   /* has_ned: the NED state */
      ref_item ref;      /* has_ref */
      nav_ins_state nav; /* !has_ned or output: the e-frame state */
    } e;                 /* SC_EPOCH */
    nav_replay_gap gap;  /* SC_GAP */
  } u;
} sc_item;

typedef struct scorer {
  const nav_replay_config *cfg;
  const nav_frame *frame;
  nav_replay_summary *sum;
  nav_replay_stats_acc acc, acc_out;
  double gap_max_h; /* largest horizontal error since the last fix [m] */
  atomic_bool stop; /* record returned NAV_STOP */
  bool threaded;
  pthread_t th;
  ring q;
  sc_item one; /* on the calling thread: the item being filled */
} scorer;

/* Score one item; @p given: its errors when already computed (ned_errors4), else NULL. */
static void score_epoch(scorer *sc, const sc_item *it, const nav_epoch_errors *given) {
  /* After a NAV_STOP nothing more is scored or called back, as on the calling thread, where the
   * navigation stops at once. */
  if (atomic_load_explicit(&sc->stop, memory_order_relaxed)) return;
  nav_replay_summary *sum = sc->sum;
  if (it->kind == SC_FIX) {
    sc->gap_max_h = 0.0;
    return;
  }
  if (it->kind == SC_GAP) {
    nav_replay_gap g = it->u.gap;
    g.pos_h_max_m = g.has_end_errors ? fmax(sc->gap_max_h, g.pos_h_end_m) : sc->gap_max_h;
    if (sum->gap_count < NAV_REPLAY_MAX_GAPS) sum->gaps[sum->gap_count] = g;
    sum->gap_count++;
    return;
  }
  const nav_replay_config *cfg = sc->cfg;
  nav_epoch_errors err;
  if (it->has_ref) {
    if (given) {
      err = *given;
    } else if (it->has_ned) {
      err = ned_errors(&it->u.e.ref, &it->u.e.ned);
    } else {
      const nav_traj_state ts = ref_item_state(&it->u.e.ref);
      err = nav_errors_compute(sc->frame, &ts, &it->u.e.nav);
    }
    double v[N_M];
    stats_values(&err, v);
    stats_add_values(&sc->acc, v, err.t_s, &err);
    if (cfg->scored) cfg->scored(cfg->user, &err);
    if (it->output) stats_add_values(&sc->acc_out, v, err.t_s, &err);
    sum->final = err;
    sc->gap_max_h = fmax(sc->gap_max_h, err.pos_err_h_m);
  }
  if (it->output && cfg->record) {
    nav_traj_state ts;
    if (it->has_ref) ts = ref_item_state(&it->u.e.ref);
    const nav_replay_record rec = {sc->frame, &it->u.e.nav, it->has_ref ? &ts : NULL,
                                   it->has_ref ? &err : NULL, it->updated};
    if (cfg->record(cfg->user, &rec) == NAV_STOP)
      atomic_store_explicit(&sc->stop, true, memory_order_relaxed);
  }
}

static void score_one(scorer *sc, const sc_item *it) { score_epoch(sc, it, NULL); }

/* An epoch whose errors ned_errors4() can compute. */
static bool ned_epoch(const sc_item *it) { return it->kind == SC_EPOCH && it->has_ref && it->has_ned; }

static void *scorer_main(void *arg) {
  scorer *sc = arg;
  const void *got[4];
  for (int n = ring_next_n(&sc->q, got, 4); n > 0; n = ring_next_n(&sc->q, got, 4)) {
    const sc_item *const *its = (const sc_item *const *)got;
    if (n == 4 && ned_epoch(its[0]) && ned_epoch(its[1]) && ned_epoch(its[2]) && ned_epoch(its[3])) {
      /* Four epochs' errors at once (the same values), then each item as score_one() would. */
      const ref_item *const refs[4] = {&its[0]->u.e.ref, &its[1]->u.e.ref, &its[2]->u.e.ref, &its[3]->u.e.ref};
      const nav_ins_ned *const neds[4] = {&its[0]->u.e.ned, &its[1]->u.e.ned, &its[2]->u.e.ned, &its[3]->u.e.ned};
      nav_epoch_errors err[4];
      ned_errors4_clones(refs, neds, err);
      for (int k = 0; k < 4; ++k)
        score_epoch(sc, its[k], &err[k]);
    } else {
      for (int k = 0; k < n; ++k)
        score_one(sc, its[k]);
    }
  }
  return NULL;
}

static void scorer_start(scorer *sc, bool threaded) {
  sc->threaded = false;
  if (!threaded || !ring_init(&sc->q, sizeof(sc_item))) return;
  if (pthread_create(&sc->th, NULL, scorer_main, sc) != 0) {
    ring_destroy(&sc->q);
    return;
  }
  sc->threaded = true;
}

/* The item to fill for the next epoch or event (then scorer_push()). */
static sc_item *scorer_slot(scorer *sc) {
  /* The consumer never stops early, so a slot always comes. */
  return sc->threaded ? ring_slot(&sc->q) : &sc->one;
}

static void scorer_push(scorer *sc) {
  if (sc->threaded)
    ring_commit(&sc->q);
  else
    score_one(sc, &sc->one);
}

/* Score everything pushed so far and stop the thread; the results are then in sc. */
static void scorer_finish(scorer *sc) {
  if (!sc->threaded) return;
  ring_close(&sc->q);
  (void)pthread_join(sc->th, NULL);
  ring_destroy(&sc->q);
  sc->threaded = false;
}

static nav_status nav_fail(nav_diag *diag, nav_status st, const char *what, const char *detail) {
  diag_set(diag, "replay", 0, 0, "", "%s: %s", what, detail && detail[0] ? detail : nav_status_str(st));
  return st;
}

nav_status nav_replay_run(const nav_replay_config *cfg, nav_replay_summary *out, nav_diag *diag) {
  if (!cfg || !out) return NAV_ERR_INVALID_ARG;
  nav_status st = check_config(cfg, diag);
  if (st != NAV_OK) return st;
  nav_replay_summary *sum = calloc(1, sizeof *sum);
  if (!sum) return NAV_ERR_NO_MEMORY;
  replay p;
  memset(&p, 0, sizeof p);
  scorer sc;
  memset(&sc, 0, sizeof sc);
  sc.cfg = cfg;
  sc.sum = sum;
  p.cfg = cfg;
  p.sum = sum;
  p.diag = diag;
  nav_side nav = {NULL, NULL};
  sum->free_ins = cfg->gnss_path == NULL && cfg->raw == NULL;
  const bool aided = !sum->free_ins;

  if (!cfg->imu && !cfg->imu_stream) st = nav_rec_reader_open(cfg->imu_path, NAV_REC_IMU, &p.imu, diag);
  if (st == NAV_OK) st = nav_rec_reader_open(cfg->ref_path, NAV_REC_PVA, &p.ref, diag);
  if (st == NAV_OK && cfg->gnss_path) st = nav_rec_reader_open(cfg->gnss_path, NAV_REC_GNSS, &p.gnss, diag);
  if (st != NAV_OK) goto cleanup;
  if (p.imu) {
    ra_start(&p.imu_ra, p.imu, cfg->read_ahead);
    p.imu_ra_on = true;
  }
  ra_start(&p.ref_ra, p.ref, cfg->read_ahead);
  p.ref_ra_on = true;
  st = ref_next(&p);
  if (st == NAV_OK && aided) st = fix_next(&p);
  if (st != NAV_OK) goto cleanup;

  /* 1. The initial epoch: the first IMU epoch in the window with a reference row. */
  const double tol = cfg->ref_sync_tol_s;
  nav_imu_increment inc;
  bool got = false;
  for (;;) {
    st = imu_next(&p, &inc, &got);
    if (st != NAV_OK) {
      reader_failed(&p, p.imu, st);
      goto cleanup;
    }
    if (got) sum->imu_records++;
    if (got && !(cfg->has_start && inc.t_s < cfg->t_start_s - tol)) {
      while (p.ref_have && p.ref_it->row.t_s < inc.t_s - tol) {
        st = ref_next(&p);
        if (st != NAV_OK) goto cleanup;
      }
      if (p.ref_have && fabs(p.ref_it->row.t_s - inc.t_s) <= tol &&
          !(cfg->has_end && inc.t_s > cfg->t_end_s + tol))
        break;
    }
    if (!got && sum->imu_records == 0) {
      /* End of the IMU file before its first record: an empty or comment-only file. */
      diag_set(diag, cfg->imu_path, 1, 1, "", "the IMU file holds no records; expected lines of %s", k_expect_imu);
      st = NAV_ERR_PARSE;
      goto cleanup;
    }
    if (!got || !p.ref_have || (cfg->has_end && inc.t_s > cfg->t_end_s + tol)) {
      diag_set(
          diag, cfg->imu_path, 0, 0, "",
          "no IMU epoch%s coincides with a row of the reference %s (within %.3g s); the initial state is "
          "taken from the reference",
          cfg->has_start || cfg->has_end ? " in the time window" : "", cfg->ref_path, tol);
      st = NAV_ERR_INVALID_ARG;
      goto cleanup;
    }
  }
  const nav_rec_pva row0 = p.ref_it->row;
  const nav_traj_state ts0 = nav_rec_pva_to_state(&row0);
  const nav_frame frame = frame_at(row0.pos);
  sc.frame = &frame;
  if (cfg->has_initial && !(fabs(cfg->initial.t_s - inc.t_s) <= tol)) {
    diag_set(diag, cfg->imu_path, 0, 0, "",
             "the given initial state is at t = %.17g s, but the initial epoch (the first IMU epoch with a "
             "reference row) is t = %.17g s; expected the same time within %.3g s",
             cfg->initial.t_s, inc.t_s, tol);
    st = NAV_ERR_INVALID_ARG;
    goto cleanup;
  }
  /* The initial state: the reference row, or the given one (the frame stays the reference's). */
  const nav_traj_state is0 = cfg->has_initial ? nav_rec_pva_to_state(&cfg->initial) : ts0;
  nav_ins_state s0;
  s0.t_s = inc.t_s;
  s0.r_fb_f_m = is0.r_fb_f_m;
  s0.v_fb_f_mps = is0.v_fb_f_mps;
  s0.q_b_f = is0.q_b_f;
  if (aided)
    st = nav_ins_gnss_create(&cfg->nav, &s0, &nav.x);
  else
    st = nav_ins_create(&cfg->nav.ins, &s0, &nav.ins);
  if (st != NAV_OK) {
    nav_fail(diag, st, "cannot set up the navigation", "check the mechanization and filter settings");
    goto cleanup;
  }
  sum->t_first_s = inc.t_s;
  sum->t_last_s = inc.t_s;
  nav_epoch_errors err = nav_errors_compute(&frame, &ts0, nav_state(&nav));
  sum->final = err;
  if (cfg->scored) cfg->scored(cfg->user, &err);
  bool stop = false;
  long long last_out = llround(inc.t_s / cfg->output_interval_s);
  if (cfg->record) {
    const nav_replay_record rec = {&frame, nav_state(&nav), &ts0, &err, false};
    stop = cfg->record(cfg->user, &rec) == NAV_STOP;
  }
  st = ref_next(&p);
  if (st != NAV_OK) goto cleanup;

  /* 2. Every following increment. */
  scorer_start(&sc, cfg->callbacks_on_worker);
  const double t_first = inc.t_s;
  double dt_nominal = 0.0, last_fix_t = 0.0, min_spacing = 0.0;
  bool have_fix = false, have_spacing = false;
  while (!stop) {
    st = imu_next(&p, &inc, &got);
    if (st != NAV_OK) {
      reader_failed(&p, p.imu, st);
      goto cleanup;
    }
    if (!got) break;
    sum->imu_records++;
    if (cfg->has_end && inc.t_s > cfg->t_end_s + tol) break;
    const double t = inc.t_s, dt = inc.dt_s;
    if (sum->imu_steps == 0) dt_nominal = dt;
    if (dt > 1.5 * dt_nominal) sum->imu_gaps++;
    if (dt > sum->imu_dt_max_s) sum->imu_dt_max_s = dt;
    if (nav.x)
      st = nav_ins_gnss_step(nav.x, &inc);
    else
      st = nav_ins_step(nav.ins, &inc);
    if (st != NAV_OK) {
      nav_fail(diag, st, "navigation failed",
               nav.x ? nav_ins_gnss_last_error(nav.x) : nav_ins_last_error(nav.ins));
      goto cleanup;
    }
    sum->imu_steps++;
    sum->t_last_s = t;

    /* The reference row of this epoch, if any (rows in between are counted, not scored). */
    while (p.ref_have && p.ref_it->row.t_s < t - tol) {
      sum->ref_unmatched++;
      st = ref_next(&p);
      if (st != NAV_OK) goto cleanup;
    }
    const bool has_ref = p.ref_have && fabs(p.ref_it->row.t_s - t) <= tol;

    /* GNSS fixes of this epoch: time of validity within dt/2 (numerics.md 6.5). */
    bool updated = false;
    while (aided && p.fix_have && p.fix.t_s <= t + 0.5 * dt) {
      if (p.fix.t_s <= t - 0.5 * dt) {
        if (p.fix.t_s <= t_first + 0.5 * dt)
          sum->gnss_before_start++;
        else
          sum->gnss_unmatched++;
      } else if (in_outage(cfg, p.fix.t_s)) {
        sum->gnss_dropped++;
      } else {
        const double spacing = p.fix.t_s - last_fix_t;
        if (have_fix && have_spacing && spacing > cfg->gap_factor * min_spacing) {
          /* The end of a GNSS gap: errors just before the fix that ends it (the largest error
             inside it is the scorer's). */
          sc_item *gi = scorer_slot(&sc);
          gi->kind = SC_GAP;
          nav_replay_gap *g = &gi->u.gap;
          memset(g, 0, sizeof *g);
          g->t0_s = last_fix_t;
          g->t1_s = p.fix.t_s;
          if (has_ref) {
            const nav_epoch_errors e = errors_at(&frame, p.ref_it, &nav);
            g->has_end_errors = true;
            g->pos_h_end_m = e.pos_err_h_m;
            g->pos_v_end_m = e.pos_err_v_m;
            g->end_errors = e;
          }
          scorer_push(&sc);
        }
        if (cfg->raw)
          st = nav_ins_gnss_update_raw(nav.x, &p.raw, NULL);
        else
          st = nav_ins_gnss_update(nav.x, &p.fix);
        if (st != NAV_OK) {
          nav_fail(diag, st, "GNSS update failed", nav_ins_gnss_last_error(nav.x));
          goto cleanup;
        }
        if (have_fix && (!have_spacing || spacing < min_spacing)) {
          min_spacing = spacing;
          have_spacing = true;
        }
        have_fix = true;
        last_fix_t = p.fix.t_s;
        scorer_slot(&sc)->kind = SC_FIX;
        scorer_push(&sc);
        updated = true;
        sum->gnss_applied++;
      }
      st = fix_next(&p);
      if (st != NAV_OK) goto cleanup;
    }

    const long long j = llround(t / cfg->output_interval_s);
    const bool output = j != last_out && fabs(t - (double)j * cfg->output_interval_s) <= 0.5 * dt;
    if (output) last_out = j;
    if (has_ref || (output && cfg->record)) {
      sc_item *it = scorer_slot(&sc);
      it->kind = SC_EPOCH;
      it->has_ref = has_ref;
      it->output = output;
      it->updated = updated;
      it->has_ned = has_ref && nav_ned(&nav, &it->u.e.ned);
      if (has_ref) it->u.e.ref = *p.ref_it;
      if (!it->has_ned || output) it->u.e.nav = *nav_state(&nav);
      scorer_push(&sc);
      if (atomic_load_explicit(&sc.stop, memory_order_relaxed)) stop = true;
    }
    if (has_ref) {
      st = ref_next(&p);
      if (st != NAV_OK) goto cleanup;
    }
    if (cfg->progress && sum->imu_steps % 8192 == 0) {
      const nav_progress pr = {"replay", 0, p.imu_fraction, t};
      if (cfg->progress(cfg->user, &pr) == NAV_STOP) stop = true;
    }
  }
  scorer_finish(&sc);
  if (atomic_load_explicit(&sc.stop, memory_order_relaxed)) stop = true;
  /* A gap still open at the end of the run. */
  if (aided && have_fix && have_spacing && sum->t_last_s - last_fix_t > cfg->gap_factor * min_spacing) {
    nav_replay_gap g;
    memset(&g, 0, sizeof g);
    g.t0_s = last_fix_t;
    g.t1_s = sum->t_last_s;
    g.open = true;
    g.has_end_errors = fabs(sum->final.t_s - sum->t_last_s) <= tol;
    g.pos_h_end_m = sum->final.pos_err_h_m;
    g.pos_v_end_m = sum->final.pos_err_v_m;
    g.pos_h_max_m = sc.gap_max_h;
    g.end_errors = sum->final;
    if (sum->gap_count < NAV_REPLAY_MAX_GAPS) sum->gaps[sum->gap_count] = g;
    sum->gap_count++;
  }
  if (cfg->progress && !stop) {
    const nav_progress pr = {"replay", 0, 1.0, sum->t_last_s};
    (void)cfg->progress(cfg->user, &pr);
  }
  sum->stats = nav_replay_stats_result(&sc.acc);
  sum->stats_output = nav_replay_stats_result(&sc.acc_out);
  if (nav.x) nav_ins_gnss_biases(nav.x, &sum->b_g_rps, &sum->b_a_mps2);
  sum->partial = stop;
  if (cfg->imu_stream) {
    /* As for records in memory (imu_next()): the streaming reader has read the last line once it
     * returned the record on it or was asked past the last record. The file is read to its end
     * long before the navigation gets there; waiting here only matters for a short window. */
    nav_rec_imu_stream *s = cfg->imu_stream;
    size_t count = 0;
    long cut = 0, last = 0;
    if (nav_rec_imu_stream_finish(s, &count, &cut, &last, NULL) == NAV_OK && cut &&
        (p.imu_end_seen || (p.imu_idx == count && cut == last)))
      p.imu_cut_line = cut;
  }
  sum->imu_cut_line = p.imu_cut_line;
  sum->gnss_cut_line = nav_rec_reader_cut_line(p.gnss);
  sum->ref_cut_line = p.ref_cut_line;
  *out = *sum;
  st = stop ? NAV_ERR_CANCELLED : NAV_OK;

cleanup:
  scorer_finish(&sc);
  if (p.imu_ra_on) ra_stop(&p.imu_ra);
  if (p.ref_ra_on) ra_stop(&p.ref_ra);
  nav_ins_gnss_destroy(nav.x);
  nav_ins_destroy(nav.ins);
  nav_rec_reader_destroy(p.imu);
  nav_rec_reader_destroy(p.gnss);
  nav_rec_reader_destroy(p.ref);
  free(sum);
  return st;
}

nav_status nav_replay_score_pva(const char *ref_path, const char *est_path, bool has_start, double t_start_s,
                                bool has_end, double t_end_s, double sync_tol_s, nav_replay_stats *out,
                                nav_diag *diag) {
  if (!ref_path || !est_path || !out || !(sync_tol_s > 0.0)) return NAV_ERR_INVALID_ARG;
  nav_rec_reader *ref = NULL, *est = NULL;
  nav_replay_stats_acc acc;
  memset(&acc, 0, sizeof acc);
  nav_status st = nav_rec_reader_open(ref_path, NAV_REC_PVA, &ref, diag);
  if (st == NAV_OK) st = nav_rec_reader_open(est_path, NAV_REC_PVA, &est, diag);
  if (st != NAV_OK) goto cleanup;
  nav_rec_pva rr, er;
  bool ref_have = false, est_have = false;
  bool have_frame = false;
  nav_frame frame;
  st = nav_rec_read_pva(ref, &rr, &ref_have);
  if (st != NAV_OK) {
    copy_diag(diag, ref);
    goto cleanup;
  }
  for (;;) {
    st = nav_rec_read_pva(est, &er, &est_have);
    if (st != NAV_OK) {
      copy_diag(diag, est);
      goto cleanup;
    }
    if (!est_have || (has_end && er.t_s > t_end_s + sync_tol_s)) break;
    if (has_start && er.t_s < t_start_s - sync_tol_s) continue;
    while (ref_have && rr.t_s < er.t_s - sync_tol_s) {
      st = nav_rec_read_pva(ref, &rr, &ref_have);
      if (st != NAV_OK) {
        copy_diag(diag, ref);
        goto cleanup;
      }
    }
    if (!ref_have) break;
    if (fabs(rr.t_s - er.t_s) > sync_tol_s) continue;
    if (!have_frame) {
      frame = frame_at(rr.pos);
      have_frame = true;
    }
    const nav_traj_state ts = nav_rec_pva_to_state(&rr), es = nav_rec_pva_to_state(&er);
    const nav_ins_state s = {es.t_s, es.r_fb_f_m, es.v_fb_f_mps, es.q_b_f};
    const nav_epoch_errors e = nav_errors_compute(&frame, &ts, &s);
    nav_replay_stats_add(&acc, &e);
  }
  if (acc.n == 0) {
    diag_set(diag, est_path, 0, 0, "", "no row coincides with a row of the reference %s (within %.3g s)",
             ref_path, sync_tol_s);
    st = NAV_ERR_INVALID_ARG;
    goto cleanup;
  }
  *out = nav_replay_stats_result(&acc);
  st = NAV_OK;
cleanup:
  nav_rec_reader_destroy(ref);
  nav_rec_reader_destroy(est);
  return st;
}
