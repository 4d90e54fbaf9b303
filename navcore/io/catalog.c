/*
 * navcore_io: IMU and GNSS receiver catalogs (CSV) -> nav_imu_model_config / nav_gnss_model_config.
 * The format and the conversions are documented in nav_catalog.h and resources/README.md; this
 * file explains only parsing choices.
 */
#include "navcore/nav_catalog.h"
#include "navcore/nav_io.h"

#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene_bounds.h"

#define MAX_COLS 64

/* Relative disagreement allowed between a datasheet-unit column and its SI twin: the files carry
 * 6 significant digits, so a correct pair differs by at most 5e-6 relative (measured: 3.9e-6). */
#define PAIR_REL_TOL 2e-5

/* ------------------------------------------------------------------ diagnostics */

#define ROW_DIAG_MAX 16

typedef struct ctx {
  const char *file;
  nav_diag_fn report;
  void *user;
  int count; /* problems found (reported or not, past the cap) */
  /* While a row is converted its diagnostics are held here and emitted sorted by column, so they
   * come out in reading order whatever order the conversion checks the cells in. */
  bool hold;
  int held;
  nav_diag row[ROW_DIAG_MAX];
} ctx;

static void emit(ctx *c, const nav_diag *d) {
  if (c->report && c->count <= NAV_DIAG_MAX_PER_FILE) c->report(c->user, d);
}

static void diag(ctx *c, int line, int col, const char *path, const char *fmt, ...) {
  c->count++;
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", c->file);
  d.line = line;
  d.col = line > 0 ? col : 0;
  snprintf(d.path, sizeof d.path, "%s", path ? path : "");
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d.message, sizeof d.message, fmt, ap);
  va_end(ap);
  if (c->hold && c->held < ROW_DIAG_MAX)
    c->row[c->held++] = d;
  else
    emit(c, &d);
}

/* Emit the held diagnostics of a row in (line, column) order (insertion sort: a handful). */
static void flush_row(ctx *c) {
  for (int i = 1; i < c->held; ++i) {
    const nav_diag d = c->row[i];
    int j = i - 1;
    while (j >= 0 && (c->row[j].line > d.line || (c->row[j].line == d.line && c->row[j].col > d.col))) {
      c->row[j + 1] = c->row[j];
      --j;
    }
    c->row[j + 1] = d;
  }
  const int first = c->count - c->held; /* count before this row's problems */
  for (int i = 0; i < c->held; ++i)
    if (c->report && first + i < NAV_DIAG_MAX_PER_FILE) c->report(c->user, &c->row[i]);
  c->held = 0;
  c->hold = false;
}

/* ------------------------------------------------------------------ CSV records */

typedef struct field {
  char *s;  /* unquoted, NUL-terminated, inside the record buffer */
  int line; /* position of the first byte of the cell (the quote, if quoted) */
  int col;
} field;

typedef struct record {
  field f[MAX_COLS];
  size_t n;
  int line;
} record;

typedef struct parser {
  const char *p, *end;
  int line, col;
  char *buf; /* unquoted cells; capacity >= input length + MAX_COLS + 1 */
} parser;

static bool at_eol(const parser *ps) {
  return ps->p >= ps->end || *ps->p == '\n' || *ps->p == '\r';
}

/* Consume one end of line (LF or CRLF; a lone CR counts as one). */
static void eat_eol(parser *ps) {
  if (ps->p < ps->end && *ps->p == '\r') ps->p++;
  if (ps->p < ps->end && *ps->p == '\n') ps->p++;
  ps->line++;
  ps->col = 1;
}

static void skip_to_eol(parser *ps) {
  while (!at_eol(ps)) {
    ps->p++;
    ps->col++;
  }
}

static bool bad_byte(unsigned char ch) {
  return ch < 0x20 && ch != '\t';
}

/*
 * Read the next non-blank record. Returns false at the end of input. Problems are reported and
 * the record is still returned (with what could be read) so later rows get checked too; *ok says
 * whether it is usable.
 */
static bool read_record(parser *ps, ctx *c, record *r, bool *ok) {
  while (ps->p < ps->end && (*ps->p == '\n' || *ps->p == '\r'))
    eat_eol(ps);
  if (ps->p >= ps->end) return false;
  *ok = true;
  r->n = 0;
  r->line = ps->line;
  char *out = ps->buf;
  for (;;) {
    if (r->n == MAX_COLS) {
      diag(c, ps->line, ps->col, "", "more than %d cells in one row", MAX_COLS);
      *ok = false;
      skip_to_eol(ps);
      break;
    }
    field *f = &r->f[r->n++];
    f->line = ps->line;
    f->col = ps->col;
    f->s = out;
    if (ps->p < ps->end && *ps->p == '"') {
      ps->p++;
      ps->col++;
      bool closed = false;
      while (ps->p < ps->end) {
        const unsigned char ch = (unsigned char)*ps->p;
        if (ch == '"') {
          if (ps->p + 1 < ps->end && ps->p[1] == '"') {
            *out++ = '"';
            ps->p += 2;
            ps->col += 2;
            continue;
          }
          ps->p++;
          ps->col++;
          closed = true;
          break;
        }
        if (ch == '\n' || ch == '\r') break;
        if (bad_byte(ch)) {
          diag(c, ps->line, ps->col, "", "control character 0x%02x in a cell", ch);
          *ok = false;
        }
        *out++ = (char)ch;
        ps->p++;
        ps->col++;
      }
      if (!closed) {
        diag(c, f->line, f->col, "",
             "quoted cell is not closed on its line (cells cannot contain line breaks)");
        *ok = false;
        *out++ = '\0';
        skip_to_eol(ps);
        break;
      }
      if (!at_eol(ps) && *ps->p != ',') {
        diag(c, ps->line, ps->col, "",
             "unexpected text after the closing quote; expected ',' or the end of the line");
        *ok = false;
        while (!at_eol(ps) && *ps->p != ',') {
          ps->p++;
          ps->col++;
        }
      }
    } else {
      while (!at_eol(ps) && *ps->p != ',') {
        const unsigned char ch = (unsigned char)*ps->p;
        if (ch == '"') {
          diag(c, ps->line, ps->col, "",
               "quote inside an unquoted cell; quote the whole cell and double the quote");
          *ok = false;
        } else if (bad_byte(ch)) {
          diag(c, ps->line, ps->col, "", "control character 0x%02x in a cell", ch);
          *ok = false;
        }
        *out++ = (char)ch;
        ps->p++;
        ps->col++;
      }
    }
    *out++ = '\0';
    if (at_eol(ps)) break;
    ps->p++; /* the comma */
    ps->col++;
  }
  if (ps->p < ps->end) eat_eol(ps);
  return true;
}

/* ------------------------------------------------------------------ small helpers */

static int lower(int ch) {
  return (ch >= 'A' && ch <= 'Z') ? ch - 'A' + 'a' : ch;
}

static bool equal_nocase(const char *a, const char *b) {
  while (*a && *b) {
    if (lower((unsigned char)*a) != lower((unsigned char)*b)) return false;
    ++a;
    ++b;
  }
  return *a == *b;
}

/* Trim ASCII blanks in place; returns the trimmed start. */
static char *trim(char *s) {
  while (*s == ' ' || *s == '\t')
    ++s;
  size_t n = strlen(s);
  while (n > 0 && (s[n - 1] == ' ' || s[n - 1] == '\t'))
    s[--n] = '\0';
  return s;
}

/* Levenshtein distance, capped: only used to suggest a column name. */
static size_t edit_distance(const char *a, const char *b) {
  size_t la = strlen(a), lb = strlen(b);
  if (la > 63 || lb > 63) return 99;
  size_t prev[64], cur[64];
  for (size_t j = 0; j <= lb; ++j)
    prev[j] = j;
  for (size_t i = 1; i <= la; ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= lb; ++j) {
      const size_t sub = prev[j - 1] + (a[i - 1] != b[j - 1]);
      const size_t del = prev[j] + 1, ins = cur[j - 1] + 1;
      cur[j] = sub < del ? (sub < ins ? sub : ins) : (del < ins ? del : ins);
    }
    memcpy(prev, cur, (lb + 1) * sizeof prev[0]);
  }
  return prev[lb];
}

/* ------------------------------------------------------------------ column tables */

enum imu_col {
  I_NAME,
  I_GRADE,
  I_G_BI_DPH,
  I_G_BI_RPS,
  I_G_ARW_DPSH,
  I_G_ARW_SI,
  I_G_TURN_ON_DPS,
  I_G_SF_PPM,
  I_A_BI_UG,
  I_A_BI_SI,
  I_A_VRW_MPSH,
  I_A_VRW_SI,
  I_A_TURN_ON_MG,
  I_A_SF_PPM,
  I_MISALIGN_MRAD,
  I_CORR_TIME_S,
  I_BIAS_MODEL,
  I_SOURCE,
  I_VERIFIED,
  I_COST_CLASS,
  I_COUNT
};

static const char *const imu_cols[I_COUNT] = {"name",
                                              "grade",
                                              "gyro_bias_instability_deg_per_h",
                                              "gyro_bias_instability_rad_per_s",
                                              "gyro_arw_deg_per_sqrt_h",
                                              "gyro_arw_rad_per_sqrt_s",
                                              "gyro_turn_on_bias_deg_per_s",
                                              "gyro_scale_factor_ppm",
                                              "accel_bias_instability_ug",
                                              "accel_bias_instability_m_per_s2",
                                              "accel_vrw_m_per_s_per_sqrt_h",
                                              "accel_vrw_m_per_s_per_sqrt_s",
                                              "accel_turn_on_bias_mg",
                                              "accel_scale_factor_ppm",
                                              "misalignment_mrad",
                                              "bias_corr_time_s",
                                              "bias_model",
                                              "source",
                                              "verified_in_corpus",
                                              "cost_class"};
static const bool imu_required[I_COUNT] = {
    [I_NAME] = true, [I_GRADE] = true, [I_SOURCE] = true, [I_VERIFIED] = true};

enum gnss_col { G_MODE, G_H_SD, G_V_SD, G_CORR, G_VEL_SD, G_RATE, G_SOURCE, G_VERIFIED, G_COST_CLASS, G_COUNT };

static const char *const gnss_cols[G_COUNT] = {"mode",
                                               "horizontal_sigma_per_axis_m",
                                               "vertical_sigma_m",
                                               "correlation_time_s",
                                               "velocity_sigma_per_axis_m_per_s",
                                               "update_rate_hz",
                                               "source",
                                               "verified_in_corpus",
                                               "cost_class"};
static const bool gnss_required[G_COUNT] = {[G_MODE] = true, [G_H_SD] = true,   [G_V_SD] = true,
                                            [G_RATE] = true, [G_SOURCE] = true, [G_VERIFIED] = true};

enum accel_col {
  A_PART,
  A_GRADE,
  A_RANGE_G,
  A_BANDWIDTH_HZ,
  A_NOISE_UG,
  A_NOISE_SI,
  A_BI_UG,
  A_BI_SI,
  A_REPEAT_MG,
  A_SF_PPM,
  A_CORR_TIME_S,
  A_BIAS_MODEL,
  A_SOURCE,
  A_VERIFIED,
  A_COST_CLASS,
  A_COUNT
};

static const char *const accel_cols[A_COUNT] = {"part",
                                                "grade",
                                                "range_g",
                                                "bandwidth_hz",
                                                "noise_density_ug_per_sqrt_hz",
                                                "noise_density_m_per_s2_per_sqrt_hz",
                                                "bias_instability_ug",
                                                "bias_instability_m_per_s2",
                                                "bias_repeatability_mg",
                                                "scale_factor_ppm",
                                                "bias_corr_time_s",
                                                "bias_model",
                                                "source",
                                                "verified_in_corpus",
                                                "cost_class"};
static const bool accel_required[A_COUNT] = {
    [A_PART] = true, [A_GRADE] = true, [A_SOURCE] = true, [A_VERIFIED] = true};

/* Largest accepted range and bandwidth (plausibility only: no scene key takes them). */
#define ACCEL_MAX_RANGE_G 1.0e5
#define ACCEL_MAX_BANDWIDTH_HZ 1.0e6

/* Header: map file column -> table column (-1 unknown). */
typedef struct header {
  nav_catalog_kind kind;
  size_t n_file;
  int table_of_file[MAX_COLS];
  int file_of_table[MAX_COLS]; /* table column -> file column (-1 absent) */
} header;

static bool parse_header(ctx *c, record *r, header *h) {
  bool has_name = false, has_mode = false, has_part = false;
  for (size_t i = 0; i < r->n; ++i) {
    r->f[i].s = trim(r->f[i].s);
    const char *s = r->f[i].s;
    if (strcmp(s, "name") == 0) has_name = true;
    if (strcmp(s, "mode") == 0) has_mode = true;
    if (strcmp(s, "part") == 0) has_part = true;
  }
  const int n_keys = (int)has_name + (int)has_mode + (int)has_part;
  if (n_keys != 1) {
    diag(c, r->line, 1, "",
         n_keys > 1
             ? "the header has more than one of the key columns 'name' (IMU), 'mode' (GNSS) and 'part' "
               "(accelerometer)"
             : "not a sensor catalog: the header needs a 'name' column (IMU catalog), a 'mode' column "
               "(GNSS catalog) or a 'part' column (accelerometer catalog)");
    return false;
  }
  h->kind = has_name ? NAV_CATALOG_IMU : has_mode ? NAV_CATALOG_GNSS : NAV_CATALOG_ACCEL;
  const char *const *cols = has_name ? imu_cols : has_mode ? gnss_cols : accel_cols;
  const bool *required = has_name ? imu_required : has_mode ? gnss_required : accel_required;
  const int ncols = has_name ? I_COUNT : has_mode ? G_COUNT : A_COUNT;
  for (int k = 0; k < ncols; ++k)
    h->file_of_table[k] = -1;
  h->n_file = r->n;
  bool ok = true;
  for (size_t i = 0; i < r->n; ++i) {
    const char *s = r->f[i].s; /* trimmed above */
    h->table_of_file[i] = -1;
    int best = -1;
    size_t best_d = 99;
    for (int k = 0; k < ncols; ++k) {
      if (strcmp(s, cols[k]) == 0) {
        h->table_of_file[i] = k;
        break;
      }
      const size_t d = edit_distance(s, cols[k]);
      if (d < best_d) {
        best_d = d;
        best = k;
      }
    }
    const int k = h->table_of_file[i];
    if (k < 0) {
      if (best >= 0 && best_d <= 3)
        diag(c, r->f[i].line, r->f[i].col, s, "unknown column (did you mean '%s'?)", cols[best]);
      else
        diag(c, r->f[i].line, r->f[i].col, s, "unknown column of a %s catalog",
             has_name   ? "IMU"
             : has_mode ? "GNSS"
                        : "accelerometer");
      ok = false;
    } else if (h->file_of_table[k] >= 0) {
      diag(c, r->f[i].line, r->f[i].col, s, "duplicate column (first in column %d)", h->file_of_table[k] + 1);
      ok = false;
    } else {
      h->file_of_table[k] = (int)i;
    }
  }
  for (int k = 0; k < ncols; ++k)
    if (required[k] && h->file_of_table[k] < 0) {
      diag(c, r->line, 1, cols[k], "required column is missing");
      ok = false;
    }
  return ok;
}

/* ------------------------------------------------------------------ cells */

typedef struct row {
  ctx *c;
  record *r;
  const header *h;
  const char *const *cols;
  bool ok;
} row;

/* The cell of table column k, trimmed; NULL when the file has no such column. */
static field *cell(row *w, int k) {
  const int i = w->h->file_of_table[k];
  if (i < 0 || (size_t)i >= w->r->n) return NULL;
  field *f = &w->r->f[i];
  f->s = trim(f->s);
  return f;
}

/* Optional number: *has = false for an absent column or an empty cell. Range: >= 0, or > 0 when
 * positive, and <= max: the plausibility bound of the quantity (scene_bounds.h, in the column's
 * unit), so that a catalog row gives nothing a scene file could not. */
static double number(row *w, int k, bool positive, double max, bool *has) {
  *has = false;
  field *f = cell(w, k);
  if (!f || f->s[0] == '\0') return 0.0;
  char *end = NULL;
  const double v = strtod(f->s, &end);
  if (end == f->s || *end != '\0') {
    diag(w->c, f->line, f->col, w->cols[k], "'%s' is not a number", f->s);
    w->ok = false;
    return 0.0;
  }
  if (!isfinite(v) || v < 0.0 || (positive && v == 0.0)) {
    diag(w->c, f->line, f->col, w->cols[k], "%s must be finite and %s", f->s, positive ? "> 0" : ">= 0");
    w->ok = false;
    return 0.0;
  }
  if (v > max) {
    diag(w->c, f->line, f->col, w->cols[k], "%s must be <= %.9g (the plausibility bound of the quantity)", f->s, max);
    w->ok = false;
    return 0.0;
  }
  *has = true;
  return v;
}

/* One quantity stated in a datasheet unit (column k_ds, converted by factor) and/or in SI
 * (column k_si): the datasheet value wins, the SI twin must agree. */
static double pair(row *w, int k_ds, int k_si, double factor, const char *si_unit, double max_ds, bool *has) {
  bool has_ds = false, has_si = false;
  const double ds = number(w, k_ds, false, max_ds, &has_ds);
  const double si = number(w, k_si, false, max_ds * factor, &has_si);
  *has = has_ds || has_si;
  if (has_ds && has_si) {
    const double conv = ds * factor;
    if (fabs(conv - si) > PAIR_REL_TOL * fmax(fabs(conv), fabs(si))) {
      const field *f = cell(w, k_si);
      diag(w->c, f->line, f->col, w->cols[k_si], "%g %s disagrees with %s = %g (= %.6g %s)", si, si_unit,
           w->cols[k_ds], ds, conv, si_unit);
      w->ok = false;
    }
    return conv;
  }
  return has_ds ? ds * factor : si;
}

/* Copy a text cell; reports empty (when required) and too-long text. */
static void text(row *w, int k, char *dst, size_t size, bool required) {
  dst[0] = '\0';
  const field *f = cell(w, k);
  if (!f) return;
  if (required && f->s[0] == '\0') {
    diag(w->c, f->line, f->col, w->cols[k], "must not be empty");
    w->ok = false;
    return;
  }
  if (strlen(f->s) >= size) {
    diag(w->c, f->line, f->col, w->cols[k], "longer than %zu bytes", size - 1);
    w->ok = false;
    return;
  }
  memcpy(dst, f->s, strlen(f->s) + 1);
}

/* Optional cost class (column cost_class): an integer 1..NAV_CATALOG_COST_CLASS_MAX; 0 when the
 * column is absent or the cell empty. */
static int cost_class(row *w, int k) {
  field *f = cell(w, k);
  if (!f || f->s[0] == '\0') return 0;
  const char *s = f->s;
  if (s[0] >= '1' && s[0] <= '0' + NAV_CATALOG_COST_CLASS_MAX && s[1] == '\0') return s[0] - '0';
  diag(w->c, f->line, f->col, w->cols[k], "'%s': expected an integer cost class from 1 to %d", s,
       NAV_CATALOG_COST_CLASS_MAX);
  w->ok = false;
  return 0;
}

static nav_catalog_verification verification(row *w, int k, const char *s) {
  char word[16];
  size_t n = 0;
  while (s[n] && s[n] != ' ' && s[n] != '(' && n + 1 < sizeof word) {
    word[n] = (char)lower((unsigned char)s[n]);
    ++n;
  }
  word[n] = '\0';
  if (strcmp(word, "yes") == 0) return NAV_CATALOG_VERIFIED_YES;
  if (strcmp(word, "partly") == 0) return NAV_CATALOG_VERIFIED_PARTLY;
  if (strcmp(word, "derived") == 0) return NAV_CATALOG_VERIFIED_DERIVED;
  if (strcmp(word, "no") == 0) return NAV_CATALOG_VERIFIED_NO;
  const field *f = cell(w, k);
  if (f && s[0] != '\0') {
    diag(w->c, f->line, f->col, w->cols[k],
         "'%s' must start with yes, partly, derived or no (optionally followed by a note in parentheses)", s);
    w->ok = false;
  }
  return NAV_CATALOG_VERIFIED_NO;
}

static nav_vec3 v3(double x) {
  return nav_vec3_make(x, x, x);
}

static nav_mat3 offdiag(double x) {
  nav_mat3 m = {{{0.0, x, x}, {x, 0.0, x}, {x, x, 0.0}}};
  return m;
}

/* FOG / RLG / navigation grades get the long default Allan-minimum time. */
static bool is_nav_grade(const char *grade) {
  char g[NAV_CATALOG_GRADE_MAX];
  size_t n = 0;
  for (; grade[n] && n + 1 < sizeof g; ++n)
    g[n] = (char)lower((unsigned char)grade[n]);
  g[n] = '\0';
  return strstr(g, "fog") || strstr(g, "rlg") || strncmp(g, "navigation", 10) == 0;
}

/* The bias_model column of table column k (IMU and accelerometer rows); allan_min when empty. */
static nav_catalog_bias_model bias_model(row *w, int k) {
  const field *bm = cell(w, k);
  if (!bm || bm->s[0] == '\0') return NAV_CATALOG_BIAS_ALLAN_MIN;
  if (strcmp(bm->s, "allan_min") == 0) return NAV_CATALOG_BIAS_ALLAN_MIN;
  if (strcmp(bm->s, "gm_sigma") == 0) return NAV_CATALOG_BIAS_GM_SIGMA;
  if (strcmp(bm->s, "turn_on") == 0) return NAV_CATALOG_BIAS_TURN_ON;
  diag(w->c, bm->line, bm->col, w->cols[k], "'%s' must be allan_min, gm_sigma or turn_on", bm->s);
  w->ok = false;
  return NAV_CATALOG_BIAS_ALLAN_MIN;
}

/* ------------------------------------------------------------------ rows -> entries */

static void convert_imu(row *w, const nav_catalog_options *opt, nav_catalog_imu_entry *e) {
  memset(e, 0, sizeof *e);
  e->line = w->r->line;
  text(w, I_NAME, e->name, sizeof e->name, true);
  text(w, I_GRADE, e->grade, sizeof e->grade, true);
  text(w, I_SOURCE, e->source, sizeof e->source, true);
  text(w, I_VERIFIED, e->verified_text, sizeof e->verified_text, true);
  e->verified = verification(w, I_VERIFIED, e->verified_text);
  e->cost_class = cost_class(w, I_COST_CLASS);

  e->bias_model = bias_model(w, I_BIAS_MODEL);

  nav_imu_model_config cfg = nav_imu_model_config_default();
  nav_gyro_error_config *g = &cfg.gyro;
  nav_accel_error_config *a = &cfg.accel;
  bool has = false;

  const double arw =
      pair(w, I_G_ARW_DPSH, I_G_ARW_SI, nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(1.0), "rad/sqrt(s)",
           NAV_SCENE_MAX_GYRO_ARW_DEG_PER_SQRT_H, &has);
  if (has) {
    g->terms |= NAV_IMU_TERM_NOISE;
    g->arw_rad_per_sqrt_s = v3(arw);
  }
  const double vrw =
      pair(w, I_A_VRW_MPSH, I_A_VRW_SI, nav_unit_mps_per_sqrt_h_to_mps_per_sqrt_s(1.0), "m/s/sqrt(s)",
           NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H, &has);
  if (has) {
    a->terms |= NAV_IMU_TERM_NOISE;
    a->vrw_mps_per_sqrt_s = v3(vrw);
  }

  bool has_gb = false, has_ab = false, has_t = false;
  const double gb = pair(w, I_G_BI_DPH, I_G_BI_RPS, nav_unit_deg_per_h_to_rps(1.0), "rad/s",
                         NAV_SCENE_MAX_GYRO_BI_DEG_PER_H, &has_gb);
  const double ab = pair(w, I_A_BI_UG, I_A_BI_SI, nav_unit_ug_to_mps2(1.0), "m/s^2", NAV_SCENE_MAX_ACCEL_BI_UG, &has_ab);
  const double corr = number(w, I_CORR_TIME_S, true, NAV_SCENE_MAX_CORRELATION_TIME_S, &has_t);
  bool has_gt = false, has_at = false;
  const double gturn = nav_unit_deg_per_s_to_rps(number(w, I_G_TURN_ON_DPS, false, NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H / 3600.0, &has_gt));
  const double aturn = nav_unit_mg_to_mps2(number(w, I_A_TURN_ON_MG, false, NAV_SCENE_MAX_ACCEL_BIAS_MG, &has_at));

  double tau = 0.0, sigma_g = 0.0, sigma_a = 0.0;
  switch (e->bias_model) {
  case NAV_CATALOG_BIAS_ALLAN_MIN:
    tau = has_t ? corr
                : (is_nav_grade(e->grade) ? opt->default_tau_min_nav_s : opt->default_tau_min_mems_s) /
                      NAV_GM_ALLAN_PEAK_TAU_RATIO;
    sigma_g = nav_gm_sigma_from_bias_instability(gb, opt->convention);
    sigma_a = nav_gm_sigma_from_bias_instability(ab, opt->convention);
    break;
  case NAV_CATALOG_BIAS_GM_SIGMA:
    tau = corr;
    sigma_g = gb;
    sigma_a = ab;
    if ((has_gb || has_ab) && !has_t) {
      const field *f = cell(w, I_BIAS_MODEL);
      diag(w->c, f->line, f->col, imu_cols[I_BIAS_MODEL],
           "gm_sigma needs bias_corr_time_s (the GM correlation time)");
      w->ok = false;
    }
    break;
  case NAV_CATALOG_BIAS_TURN_ON:
    if ((has_gb && has_gt) || (has_ab && has_at)) {
      const field *f = cell(w, I_BIAS_MODEL);
      diag(w->c, f->line, f->col, imu_cols[I_BIAS_MODEL],
           "turn_on bias model and a turn-on bias column give the same bias twice");
      w->ok = false;
    }
    break;
  }
  if (e->bias_model == NAV_CATALOG_BIAS_TURN_ON) {
    if (has_gb) {
      g->terms |= NAV_IMU_TERM_BIAS_TURN_ON;
      g->bias_turn_on_sd_rps = v3(gb);
    }
    if (has_ab) {
      a->terms |= NAV_IMU_TERM_BIAS_TURN_ON;
      a->bias_turn_on_sd_mps2 = v3(ab);
    }
  } else {
    if (has_gb) {
      g->terms |= NAV_IMU_TERM_BIAS_GM;
      g->bias_gm_sd_rps = v3(sigma_g);
      g->bias_gm_tau_s = v3(tau);
    }
    if (has_ab) {
      a->terms |= NAV_IMU_TERM_BIAS_GM;
      a->bias_gm_sd_mps2 = v3(sigma_a);
      a->bias_gm_tau_s = v3(tau);
    }
  }
  if (has_gt) {
    g->terms |= NAV_IMU_TERM_BIAS_TURN_ON;
    g->bias_turn_on_sd_rps = v3(gturn);
  }
  if (has_at) {
    a->terms |= NAV_IMU_TERM_BIAS_TURN_ON;
    a->bias_turn_on_sd_mps2 = v3(aturn);
  }
  const double gsf = number(w, I_G_SF_PPM, false, NAV_SCENE_MAX_SCALE_FACTOR_PPM, &has);
  if (has) {
    g->terms |= NAV_IMU_TERM_SCALE_FACTOR;
    g->scale_factor_sd = v3(nav_unit_ppm_to_ratio(gsf));
  }
  const double asf = number(w, I_A_SF_PPM, false, NAV_SCENE_MAX_SCALE_FACTOR_PPM, &has);
  if (has) {
    a->terms |= NAV_IMU_TERM_SCALE_FACTOR;
    a->scale_factor_sd = v3(nav_unit_ppm_to_ratio(asf));
  }
  const double mis = number(w, I_MISALIGN_MRAD, false, NAV_SCENE_MAX_MISALIGNMENT_MRAD, &has);
  if (has) {
    g->terms |= NAV_IMU_TERM_MISALIGNMENT;
    a->terms |= NAV_IMU_TERM_MISALIGNMENT;
    g->misalignment_sd_rad = offdiag(nav_unit_mrad_to_rad(mis));
    a->misalignment_sd_rad = offdiag(nav_unit_mrad_to_rad(mis));
  }
  e->config = cfg;
  if (w->ok && nav_imu_model_config_validate(&cfg, NULL, NULL) != NAV_OK) {
    /* Every value was range-checked above, so this means the options are bad (e.g. a default tau). */
    diag(w->c, w->r->line, 1, e->name, "the converted model is invalid (check the catalog options)");
    w->ok = false;
  }
}

/* One single-axis accelerometer part -> the per-sensor error model of an array. The bias
 * instability follows the row's bias_model as for IMU rows; the run-to-run bias repeatability is
 * a turn-on constant (drawn per sensor and run). */
static void convert_accel(row *w, const nav_catalog_options *opt, nav_catalog_accel_entry *e) {
  memset(e, 0, sizeof *e);
  e->line = w->r->line;
  text(w, A_PART, e->name, sizeof e->name, true);
  text(w, A_GRADE, e->grade, sizeof e->grade, true);
  text(w, A_SOURCE, e->source, sizeof e->source, true);
  text(w, A_VERIFIED, e->verified_text, sizeof e->verified_text, true);
  e->verified = verification(w, A_VERIFIED, e->verified_text);
  e->cost_class = cost_class(w, A_COST_CLASS);
  e->bias_model = bias_model(w, A_BIAS_MODEL);
  nav_array_error_config *a = &e->config;
  memset(a, 0, sizeof *a);
  bool has = false;
  e->range_g = number(w, A_RANGE_G, true, ACCEL_MAX_RANGE_G, &has);
  if (has) e->given |= NAV_CATALOG_ACCEL_HAS_RANGE;
  e->bandwidth_hz = number(w, A_BANDWIDTH_HZ, true, ACCEL_MAX_BANDWIDTH_HZ, &has);
  if (has) e->given |= NAV_CATALOG_ACCEL_HAS_BANDWIDTH;
  /* The noise density of one axis in ug/sqrt(Hz) is its VRW: 1 ug/sqrt(Hz) = 1e-6 g0 m/s/sqrt(s). */
  const double ug = nav_unit_ug_to_mps2(1.0);
  const double max_noise_ug = NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H / 60.0 / ug;
  const double vrw = pair(w, A_NOISE_UG, A_NOISE_SI, ug, "m/s^2/sqrt(Hz)", max_noise_ug, &has);
  if (has) {
    e->given |= NAV_CATALOG_ACCEL_HAS_NOISE;
    e->noise_density_ug_per_sqrt_hz = vrw / ug;
    a->terms |= NAV_IMU_TERM_NOISE;
    a->vrw_mps_per_sqrt_s = vrw;
  }
  bool has_bi = false, has_t = false, has_rep = false;
  const double bi = pair(w, A_BI_UG, A_BI_SI, ug, "m/s^2", NAV_SCENE_MAX_ACCEL_BI_UG, &has_bi);
  const double corr = number(w, A_CORR_TIME_S, true, NAV_SCENE_MAX_CORRELATION_TIME_S, &has_t);
  const double rep_mg = number(w, A_REPEAT_MG, false, NAV_SCENE_MAX_ACCEL_BIAS_MG, &has_rep);
  if (has_bi) {
    e->given |= NAV_CATALOG_ACCEL_HAS_BIAS_INSTABILITY;
    e->bias_instability_ug = bi / ug;
  }
  if (has_t) {
    e->given |= NAV_CATALOG_ACCEL_HAS_CORR_TIME;
    e->bias_corr_time_s = corr;
  }
  if (has_rep) {
    e->given |= NAV_CATALOG_ACCEL_HAS_BIAS_REPEAT;
    e->bias_repeatability_mg = rep_mg;
  }
  if (has_bi) {
    switch (e->bias_model) {
    case NAV_CATALOG_BIAS_ALLAN_MIN:
      a->terms |= NAV_IMU_TERM_BIAS_GM;
      a->bias_gm_sd_mps2 = nav_gm_sigma_from_bias_instability(bi, opt->convention);
      a->bias_gm_tau_s =
          has_t ? corr
                : (is_nav_grade(e->grade) ? opt->default_tau_min_nav_s : opt->default_tau_min_mems_s) /
                      NAV_GM_ALLAN_PEAK_TAU_RATIO;
      break;
    case NAV_CATALOG_BIAS_GM_SIGMA:
      if (!has_t) {
        const field *f = cell(w, A_BIAS_MODEL);
        diag(w->c, f->line, f->col, accel_cols[A_BIAS_MODEL],
             "gm_sigma needs bias_corr_time_s (the GM correlation time)");
        w->ok = false;
      }
      a->terms |= NAV_IMU_TERM_BIAS_GM;
      a->bias_gm_sd_mps2 = bi;
      a->bias_gm_tau_s = corr;
      break;
    case NAV_CATALOG_BIAS_TURN_ON:
      if (has_rep) {
        const field *f = cell(w, A_BIAS_MODEL);
        diag(w->c, f->line, f->col, accel_cols[A_BIAS_MODEL],
             "turn_on bias model and bias_repeatability_mg give the same bias twice");
        w->ok = false;
      }
      a->terms |= NAV_IMU_TERM_BIAS_TURN_ON;
      a->bias_turn_on_sd_mps2 = bi;
      break;
    }
  }
  if (has_rep) {
    a->terms |= NAV_IMU_TERM_BIAS_TURN_ON;
    a->bias_turn_on_sd_mps2 = nav_unit_mg_to_mps2(rep_mg);
  }
  const double sf = number(w, A_SF_PPM, false, NAV_SCENE_MAX_SCALE_FACTOR_PPM, &has);
  if (has) {
    e->given |= NAV_CATALOG_ACCEL_HAS_SCALE_FACTOR;
    e->scale_factor_ppm = sf;
    a->terms |= NAV_IMU_TERM_SCALE_FACTOR;
    a->scale_factor_sd = nav_unit_ppm_to_ratio(sf);
  }
  if (w->ok && a->terms & NAV_IMU_TERM_BIAS_GM && !(isfinite(a->bias_gm_tau_s) && a->bias_gm_tau_s > 0.0)) {
    diag(w->c, w->r->line, 1, e->name, "the converted model is invalid (check the catalog options)");
    w->ok = false;
  }
}

static void convert_gnss(row *w, nav_catalog_gnss_entry *e) {
  memset(e, 0, sizeof *e);
  e->line = w->r->line;
  text(w, G_MODE, e->name, sizeof e->name, true);
  text(w, G_SOURCE, e->source, sizeof e->source, true);
  text(w, G_VERIFIED, e->verified_text, sizeof e->verified_text, true);
  e->verified = verification(w, G_VERIFIED, e->verified_text);
  e->cost_class = cost_class(w, G_COST_CLASS);
  nav_gnss_model_config cfg = nav_gnss_model_config_default();
  bool has_h = false, has_v = false, has_t = false, has_vel = false, has_rate = false;
  const double h = number(w, G_H_SD, false, NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, &has_h);
  const double v = number(w, G_V_SD, false, NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, &has_v);
  const double tau = number(w, G_CORR, false, NAV_SCENE_MAX_CORRELATION_TIME_S, &has_t);
  const double vel = number(w, G_VEL_SD, false, NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS, &has_vel);
  const double rate = number(w, G_RATE, true, NAV_SCENE_MAX_GNSS_RATE_HZ, &has_rate);
  if (!has_h || !has_v || !has_rate) {
    const int k = !has_h ? G_H_SD : (!has_v ? G_V_SD : G_RATE);
    const field *f = cell(w, k);
    if (f && f->s[0] == '\0') {
      diag(w->c, f->line, f->col, gnss_cols[k], "must not be empty");
      w->ok = false;
    }
  }
  cfg.terms = NAV_GNSS_TERM_POS_GM;
  cfg.pos_gm_sd_m = nav_vec3_make(h, h, v);
  cfg.pos_gm_tau_s = v3(has_t ? tau : 0.0); /* empty: white, the catalog convention */
  if (has_vel) {
    cfg.terms |= NAV_GNSS_TERM_VEL_WHITE;
    cfg.vel_sd_mps = v3(vel);
  }
  if (has_rate) cfg.update_rate_hz = rate;
  e->config = cfg;
}

/* ------------------------------------------------------------------ catalog object */

struct nav_catalog {
  nav_catalog_kind kind;
  size_t count;
  nav_catalog_imu_entry *imu;
  nav_catalog_gnss_entry *gnss;
  nav_catalog_accel_entry *accel;
};

nav_catalog_options nav_catalog_options_default(void) {
  nav_catalog_options o;
  o.convention = NAV_BI_ALLAN_PEAK;
  o.default_tau_min_mems_s = 300.0;
  o.default_tau_min_nav_s = 7200.0;
  return o;
}

void nav_catalog_destroy(nav_catalog *cat) {
  if (!cat) return;
  free(cat->imu);
  free(cat->gnss);
  free(cat->accel);
  free(cat);
}

static const char *entry_name(const nav_catalog *cat, size_t i) {
  return cat->kind == NAV_CATALOG_IMU    ? cat->imu[i].name
         : cat->kind == NAV_CATALOG_GNSS ? cat->gnss[i].name
                                         : cat->accel[i].name;
}

static int entry_line(const nav_catalog *cat, size_t i) {
  return cat->kind == NAV_CATALOG_IMU    ? cat->imu[i].line
         : cat->kind == NAV_CATALOG_GNSS ? cat->gnss[i].line
                                         : cat->accel[i].line;
}

nav_status nav_catalog_load_string(const char *text_in, size_t len, const char *display_name,
                                   const nav_catalog_options *opt_in, nav_catalog **out, nav_diag_fn report,
                                   void *user) {
  if (text_in == NULL || display_name == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  const nav_catalog_options opt = opt_in ? *opt_in : nav_catalog_options_default();
  ctx c = {.file = display_name, .report = report, .user = user};
  nav_status st = NAV_OK;
  nav_catalog *cat = NULL;
  parser ps = {text_in, text_in + len, 1, 1, NULL};
  /* A UTF-8 byte-order mark is tolerated (spreadsheet exports write one). */
  if (len >= 3 && memcmp(text_in, "\xEF\xBB\xBF", 3) == 0) ps.p += 3;
  ps.buf = malloc(len + MAX_COLS + 1);
  record *rec = malloc(sizeof *rec);
  cat = calloc(1, sizeof *cat);
  if (!ps.buf || !rec || !cat) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  bool ok = true;
  if (!read_record(&ps, &c, rec, &ok)) {
    diag(&c, 0, 0, "", "empty file: expected a header row");
    st = NAV_ERR_PARSE;
    goto cleanup;
  }
  header h;
  if (!ok || !parse_header(&c, rec, &h)) {
    st = NAV_ERR_PARSE;
    goto cleanup;
  }
  cat->kind = h.kind;
  size_t cap = 0;
  const size_t entry_size = h.kind == NAV_CATALOG_IMU    ? sizeof(nav_catalog_imu_entry)
                            : h.kind == NAV_CATALOG_GNSS ? sizeof(nav_catalog_gnss_entry)
                                                         : sizeof(nav_catalog_accel_entry);
  while (read_record(&ps, &c, rec, &ok)) {
    if (cat->count == NAV_CATALOG_MAX_ENTRIES) {
      diag(&c, rec->line, 1, "", "more than %d rows", NAV_CATALOG_MAX_ENTRIES);
      break;
    }
    if (!ok) continue; /* already reported; its cells are not trustworthy */
    if (rec->n != h.n_file) {
      diag(&c, rec->line, rec->f[rec->n - 1].col, "", "row has %zu cells, the header %zu", rec->n, h.n_file);
      continue;
    }
    if (cat->count == cap) {
      const size_t ncap = cap ? 2 * cap : 32;
      void *old_p = h.kind == NAV_CATALOG_IMU    ? (void *)cat->imu
                    : h.kind == NAV_CATALOG_GNSS ? (void *)cat->gnss
                                                 : (void *)cat->accel;
      void *p = realloc(old_p, ncap * entry_size);
      if (!p) {
        st = NAV_ERR_NO_MEMORY;
        goto cleanup;
      }
      if (h.kind == NAV_CATALOG_IMU)
        cat->imu = p;
      else if (h.kind == NAV_CATALOG_GNSS)
        cat->gnss = p;
      else
        cat->accel = p;
      cap = ncap;
    }
    row w = {&c, rec, &h,
             h.kind == NAV_CATALOG_IMU    ? imu_cols
             : h.kind == NAV_CATALOG_GNSS ? gnss_cols
                                          : accel_cols,
             true};
    c.hold = true;
    if (h.kind == NAV_CATALOG_IMU)
      convert_imu(&w, &opt, &cat->imu[cat->count]);
    else if (h.kind == NAV_CATALOG_GNSS)
      convert_gnss(&w, &cat->gnss[cat->count]);
    else
      convert_accel(&w, &opt, &cat->accel[cat->count]);
    flush_row(&c);
    if (!w.ok) continue;
    /* Names identify rows in scenes: they must be unique. */
    const char *name = entry_name(cat, cat->count);
    for (size_t i = 0; i < cat->count; ++i)
      if (equal_nocase(entry_name(cat, i), name)) {
        const field *f = &rec->f[h.file_of_table[0]];
        diag(&c, f->line, f->col,
             h.kind == NAV_CATALOG_IMU    ? "name"
             : h.kind == NAV_CATALOG_GNSS ? "mode"
                                          : "part",
             "'%s' is already used on line %d (names are compared ignoring case)", name, entry_line(cat, i));
        w.ok = false;
        break;
      }
    if (w.ok) cat->count++;
  }
  if (c.count > 0) {
    st = NAV_ERR_PARSE;
    goto cleanup;
  }
  *out = cat;
  cat = NULL;
cleanup:
  nav_catalog_destroy(cat);
  free(rec);
  free(ps.buf);
  return st;
}

nav_status nav_catalog_load(const char *path, const nav_catalog_options *opt, nav_catalog **out,
                            nav_diag_fn report, void *user) {
  if (path == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  ctx c = {.file = path, .report = report, .user = user};
  nav_status st = NAV_OK;
  char *buf = NULL;
  FILE *f = NULL;
  char why[320];
  st = nav_io_fopen_regular(path, &f, why, sizeof why);
  if (st != NAV_OK) {
    /* A FIFO, device or directory is refused at once (NAV_ERR_PARSE), not read until EOF. */
    diag(&c, 0, 0, "", "%s", st == NAV_ERR_IO ? "cannot open the file for reading" : why);
    return st;
  }
  buf = malloc((size_t)NAV_CATALOG_MAX_BYTES + 1);
  if (!buf) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  const size_t n = fread(buf, 1, (size_t)NAV_CATALOG_MAX_BYTES + 1, f);
  if (ferror(f)) {
    diag(&c, 0, 0, "", "read error");
    st = NAV_ERR_IO;
    goto cleanup;
  }
  if (n > NAV_CATALOG_MAX_BYTES) {
    diag(&c, 0, 0, "", "file is larger than %u bytes", (unsigned)NAV_CATALOG_MAX_BYTES);
    st = NAV_ERR_IO;
    goto cleanup;
  }
  st = nav_catalog_load_string(buf, n, path, opt, out, report, user);
cleanup:
  free(buf);
  fclose(f);
  return st;
}

nav_catalog_kind nav_catalog_get_kind(const nav_catalog *cat) {
  return cat ? cat->kind : NAV_CATALOG_IMU;
}

size_t nav_catalog_count(const nav_catalog *cat) {
  return cat ? cat->count : 0;
}

const nav_catalog_imu_entry *nav_catalog_imu_at(const nav_catalog *cat, size_t i) {
  return (cat && cat->kind == NAV_CATALOG_IMU && i < cat->count) ? &cat->imu[i] : NULL;
}

const nav_catalog_gnss_entry *nav_catalog_gnss_at(const nav_catalog *cat, size_t i) {
  return (cat && cat->kind == NAV_CATALOG_GNSS && i < cat->count) ? &cat->gnss[i] : NULL;
}

const nav_catalog_accel_entry *nav_catalog_accel_at(const nav_catalog *cat, size_t i) {
  return (cat && cat->kind == NAV_CATALOG_ACCEL && i < cat->count) ? &cat->accel[i] : NULL;
}

const nav_catalog_accel_entry *nav_catalog_find_accel(const nav_catalog *cat, const char *name) {
  if (!cat || !name || cat->kind != NAV_CATALOG_ACCEL) return NULL;
  for (size_t i = 0; i < cat->count; ++i)
    if (equal_nocase(cat->accel[i].name, name)) return &cat->accel[i];
  return NULL;
}

const nav_catalog_imu_entry *nav_catalog_find_imu(const nav_catalog *cat, const char *name) {
  if (!cat || !name || cat->kind != NAV_CATALOG_IMU) return NULL;
  for (size_t i = 0; i < cat->count; ++i)
    if (equal_nocase(cat->imu[i].name, name)) return &cat->imu[i];
  return NULL;
}

const nav_catalog_gnss_entry *nav_catalog_find_gnss(const nav_catalog *cat, const char *name) {
  if (!cat || !name || cat->kind != NAV_CATALOG_GNSS) return NULL;
  for (size_t i = 0; i < cat->count; ++i)
    if (equal_nocase(cat->gnss[i].name, name)) return &cat->gnss[i];
  return NULL;
}

const char *nav_catalog_cost_band(int cost_class) {
  switch (cost_class) {
  case 1: return "< 100 USD";
  case 2: return "100 USD - 1 kUSD";
  case 3: return "1 - 10 kUSD";
  case 4: return "10 - 100 kUSD";
  case 5: return "> 100 kUSD";
  default: return "not given";
  }
}

const char *nav_catalog_verification_name(nav_catalog_verification v) {
  switch (v) {
  case NAV_CATALOG_VERIFIED_YES: return "yes";
  case NAV_CATALOG_VERIFIED_PARTLY: return "partly";
  case NAV_CATALOG_VERIFIED_DERIVED: return "derived";
  case NAV_CATALOG_VERIFIED_NO: return "no";
  }
  return "unknown";
}

const char *nav_catalog_bias_model_name(nav_catalog_bias_model m) {
  switch (m) {
  case NAV_CATALOG_BIAS_ALLAN_MIN: return "allan_min";
  case NAV_CATALOG_BIAS_GM_SIGMA: return "gm_sigma";
  case NAV_CATALOG_BIAS_TURN_ON: return "turn_on";
  }
  return "unknown";
}
