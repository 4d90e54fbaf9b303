/*
 * Scene files, format_version 1: the YAML reader (libfyaml) and the schema tables it shares with
 * the writer. See scene_io_internal.h for how the tables are laid out and extended.
 *
 * Reading goes in five steps, and each step reports what it finds through nav_diag:
 *   1. size cap and a UTF-8 / binary check of the raw bytes (libfyaml silently drops some invalid
 *      bytes, so it must not see them);
 *   2. libfyaml's event parser builds a small tree of our own (nav_io_node) that keeps the
 *      1-based line/column of every node. Aliases are kept as alias nodes and never expanded, so
 *      alias bombs cost nothing; nesting depth and node count are capped;
 *   3. the tree is walked against the schema tables: unknown keys (with did-you-mean), duplicate
 *      keys, two spellings of one quantity, wrong node kinds, numbers, enums, ranges; every field
 *      read leaves (path -> line:col) in a small map;
 *   4. nav_scene_validate() runs on the result; each (path, message) it reports is placed at the
 *      node of that path (or its nearest parent present in the file, else line 0);
 *   5. the scene is copied out only if nothing was reported.
 *
 * Format rules (v1):
 * - format_version is required: a file without it is not taken for a scene. Versions 1 ..
 *   NAV_SCENE_FORMAT_VERSION are read; a newer version is reported once and nothing else is read.
 *   Every other key is optional and keeps its nav_scene_default() value.
 * - One YAML document per file, UTF-8 (a BOM is allowed), no aliases, no tags; at most
 *   NAV_IO_MAX_INPUT_BYTES (16 MiB), NAV_IO_MAX_DEPTH levels and NAV_IO_MAX_NODES nodes.
 * - Numbers are YAML 1.2 decimal ints/floats (1, -2.5, 1e-3, .5); .inf/.nan are rejected where a
 *   finite value is required (all v1 doubles). Quoted strings and booleans are not numbers.
 *   Integers also accept 0x.. and 0o..; floats are not integers.
 * - Angles may be given as _deg or _rad (rates as _rps or _dps); giving both is an error.
 * - An empty section ("imu:") means all defaults.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdalign.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <libfyaml.h>

#include "navcore/nav_io.h"
#include "scene_io_internal.h"

/* Enums are stored through int pointers by the table-driven reader and writer. */
_Static_assert(sizeof(nav_earth_model) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_traj_type) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_attitude_mode) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_mech_algorithm) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_gravity_model) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_mech_frame) == sizeof(int), "enum storage");

#define PATH_MAX_LEN ((size_t)sizeof(((nav_diag *)0)->path))
#define MAX_SECTION_FIELDS 64 /* descriptors per section; checked when a section is read */
#define SHOW_MAX 40           /* bytes of a user value quoted back in a message */

/* ================================================================ schema, format_version 1 */

#define OFF(member) offsetof(nav_scene, member)
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))
/* A section table; the reader tracks seen keys in arrays of MAX_SECTION_FIELDS. */
#define DEFINE_SECTION(name, fields)                                                                         \
  _Static_assert(COUNT(fields) <= MAX_SECTION_FIELDS, #fields ": too many fields");                          \
  static const nav_io_section name = {fields, COUNT(fields)}

static void read_format_version(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                                const nav_io_node *value, nav_scene *scene);
static int write_format_version(FILE *fp, const nav_io_field *f, const nav_scene *scene) {
  (void)f;
  (void)scene;
  /* The writer always emits the current version (style.md section 11). */
  return fprintf(fp, "%d", NAV_SCENE_FORMAT_VERSION);
}

static const nav_io_enum_value k_earth_models[] = {
    {"flat", NAV_EARTH_FLAT}, {"wgs84", NAV_EARTH_WGS84}, {NULL, 0}};
static const nav_io_enum_value k_traj_types[] = {{"parametric", NAV_TRAJ_PARAMETRIC}, {NULL, 0}};
static const nav_io_enum_value k_attitude_modes[] = {{"magnus", NAV_ATT_RATE_MAGNUS}, {NULL, 0}};
static const nav_io_enum_value k_gravity_models[] = {
    {"normal", NAV_GRAVITY_NORMAL}, {"j2", NAV_GRAVITY_J2}, {NULL, 0}};
static const nav_io_enum_value k_mech_frames[] = {{"ned", NAV_MECH_NED}, {"ecef", NAV_MECH_ECEF}, {NULL, 0}};
static const nav_io_enum_value k_mech_algorithms[] = {
    {"first_order", NAV_MECH_FIRST_ORDER}, {"high_order", NAV_MECH_HIGH_ORDER}, {NULL, 0}};

/* Plain descriptors; each field's range and flags are spelled out where it is listed. */
#define F_DOUBLE(k, member, sc, fl)                                                                          \
  { .key = (k), .kind = NAV_IO_DOUBLE, .flags = (fl), .offset = OFF(member), .scale = (sc) }
#define F_VEC3(k, member, sc, fl)                                                                            \
  { .key = (k), .kind = NAV_IO_VEC3, .flags = NAV_IO_FINITE | (fl), .offset = OFF(member), .scale = (sc) }
/* One angle in degrees (preferred, as in the canonical example) or radians. */
#define ANGLE_DEG_RAD(name, member)                                                                          \
  F_DOUBLE(name "_deg", member, NAV_DEG2RAD, NAV_IO_FINITE),                                                 \
      F_DOUBLE(name "_rad", member, 1.0, NAV_IO_FINITE | NAV_IO_ALT)

static const nav_io_field k_origin[] = {
    ANGLE_DEG_RAD("lat", earth.origin_lat_rad),
    ANGLE_DEG_RAD("lon", earth.origin_lon_rad),
    F_DOUBLE("h_m", earth.origin_h_m, 1.0, NAV_IO_FINITE),
};
DEFINE_SECTION(k_origin_section, k_origin);

static const nav_io_field k_earth[] = {
    {.key = "model", .kind = NAV_IO_ENUM, .offset = OFF(earth.model), .enums = k_earth_models},
    {.key = "origin", .kind = NAV_IO_SECTION, .flags = NAV_IO_FLOW, .section = &k_origin_section},
    {.key = "gravity_mps2",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(earth.flat_gravity_mps2),
     .scale = 1.0,
     .comment = "flat model only: uniform gravity, pointing down"},
    {.key = "gravity_model",
     .kind = NAV_IO_ENUM,
     .offset = OFF(earth.gravity_model),
     .enums = k_gravity_models,
     .comment = "wgs84 only: normal (Somigliana) or j2"},
};
DEFINE_SECTION(k_earth_section, k_earth);

static const nav_io_field k_attitude[] = {
    ANGLE_DEG_RAD("roll", trajectory.initial_attitude.roll_rad),
    ANGLE_DEG_RAD("pitch", trajectory.initial_attitude.pitch_rad),
    ANGLE_DEG_RAD("yaw", trajectory.initial_attitude.yaw_rad),
};
DEFINE_SECTION(k_attitude_section, k_attitude);

static const nav_io_field k_rate[] = {
    F_VEC3("a_rps", trajectory.parametric.wa_rps, 1.0, 0),
    F_VEC3("a_dps", trajectory.parametric.wa_rps, NAV_DEG2RAD, NAV_IO_ALT),
    F_VEC3("b_rps", trajectory.parametric.wb_rps, 1.0, 0),
    F_VEC3("b_dps", trajectory.parametric.wb_rps, NAV_DEG2RAD, NAV_IO_ALT),
    F_VEC3("c_hz", trajectory.parametric.wc_hz, 1.0, 0),
    F_VEC3("d_rad", trajectory.parametric.wd_rad, 1.0, 0),
    F_VEC3("d_deg", trajectory.parametric.wd_rad, NAV_DEG2RAD, NAV_IO_ALT),
};
DEFINE_SECTION(k_rate_section, k_rate);

static const nav_io_field k_parametric[] = {
    F_VEC3("R0_m", trajectory.parametric.r0_m, 1.0, 0),
    F_VEC3("V0_mps", trajectory.parametric.v0_mps, 1.0, 0),
    F_VEC3("A_mps2", trajectory.parametric.a_mps2, 1.0, 0),
    F_VEC3("B_m", trajectory.parametric.b_m, 1.0, 0),
    F_VEC3("C_hz", trajectory.parametric.c_hz, 1.0, 0),
    F_VEC3("D_rad", trajectory.parametric.d_rad, 1.0, 0),
    F_VEC3("D_deg", trajectory.parametric.d_rad, NAV_DEG2RAD, NAV_IO_ALT),
    {.key = "rate", .kind = NAV_IO_SECTION, .section = &k_rate_section},
    {.key = "attitude",
     .kind = NAV_IO_ENUM,
     .offset = OFF(trajectory.parametric.attitude_mode),
     .enums = k_attitude_modes},
    /* Ranges of integers that only the simulation constrains are left to nav_scene_validate. */
    {.key = "magnus_substeps", .kind = NAV_IO_INT, .offset = OFF(trajectory.parametric.magnus_substeps)},
};
DEFINE_SECTION(k_parametric_section, k_parametric);

static const nav_io_field k_trajectory[] = {
    {.key = "type", .kind = NAV_IO_ENUM, .offset = OFF(trajectory.type), .enums = k_traj_types},
    {.key = "duration_s",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GT | NAV_IO_MAX_LE,
     .offset = OFF(trajectory.duration_s),
     .scale = 1.0,
     .min = 0.0,
     .max = NAV_SCENE_MAX_DURATION_S},
    {.key = "initial_attitude", .kind = NAV_IO_SECTION, .flags = NAV_IO_FLOW, .section = &k_attitude_section},
    {.key = "parametric", .kind = NAV_IO_SECTION, .section = &k_parametric_section},
};
DEFINE_SECTION(k_trajectory_section, k_trajectory);

#define RATE_HZ(member)                                                                                      \
  {                                                                                                          \
    .key = "rate_hz", .kind = NAV_IO_DOUBLE, .flags = NAV_IO_FINITE | NAV_IO_MIN_GT | NAV_IO_MAX_LE,         \
    .offset = OFF(member), .scale = 1.0, .min = 0.0, .max = NAV_SCENE_MAX_RATE_HZ                            \
  }

static const nav_io_field k_imu[] = {
    RATE_HZ(imu.rate_hz),
    {.key = "quadrature_nodes", .kind = NAV_IO_INT, .offset = OFF(imu.quadrature_nodes)},
};
DEFINE_SECTION(k_imu_section, k_imu);

static const nav_io_field k_navigation[] = {
    {.key = "algorithm",
     .kind = NAV_IO_ENUM,
     .offset = OFF(navigation.algorithm),
     .enums = k_mech_algorithms},
    {.key = "frame",
     .kind = NAV_IO_ENUM,
     .offset = OFF(navigation.frame),
     .enums = k_mech_frames,
     .comment = "wgs84 only: ned (local level) or ecef (works over the poles)"},
};
DEFINE_SECTION(k_navigation_section, k_navigation);

static const nav_io_field k_output[] = {RATE_HZ(output.rate_hz)};
DEFINE_SECTION(k_output_section, k_output);

static const nav_io_field k_simulation[] = {
    {.key = "seed", .kind = NAV_IO_U64, .offset = OFF(simulation.seed)},
    {.key = "runs",
     .kind = NAV_IO_LONG,
     .flags = NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(simulation.runs),
     .min = 1.0,
     .max = (double)NAV_SCENE_MAX_RUNS},
};
DEFINE_SECTION(k_simulation_section, k_simulation);

static const nav_io_field k_root[] = {
    {.key = "format_version",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_REQUIRED,
     .read = read_format_version,
     .write = write_format_version},
    {.key = "name", .kind = NAV_IO_STRING, .offset = OFF(name), .size = NAV_SCENE_NAME_MAX},
    {.key = "earth", .kind = NAV_IO_SECTION, .section = &k_earth_section},
    {.key = "trajectory", .kind = NAV_IO_SECTION, .section = &k_trajectory_section},
    {.key = "imu", .kind = NAV_IO_SECTION, .section = &k_imu_section},
    {.key = "navigation", .kind = NAV_IO_SECTION, .section = &k_navigation_section},
    {.key = "output", .kind = NAV_IO_SECTION, .section = &k_output_section},
    {.key = "simulation", .kind = NAV_IO_SECTION, .section = &k_simulation_section},
};
_Static_assert(COUNT(k_root) <= MAX_SECTION_FIELDS, "k_root: too many fields");
const nav_io_section nav_io_scene_schema = {k_root, COUNT(k_root)};

/* ================================================================ shared helpers */

void nav_io_c_locale_begin(nav_io_c_locale *s) {
  s->c_loc = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
  s->old_loc = (locale_t)0;
  if (s->c_loc != (locale_t)0) s->old_loc = uselocale(s->c_loc);
}

void nav_io_c_locale_end(nav_io_c_locale *s) {
  if (s->c_loc == (locale_t)0) return;
  uselocale(s->old_loc);
  freelocale(s->c_loc);
  s->c_loc = (locale_t)0;
}

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

char *nav_io_format_double(char *buf, size_t size, double v) {
  if (isnan(v)) {
    snprintf(buf, size, ".nan");
  } else if (isinf(v)) {
    snprintf(buf, size, "%s", v > 0 ? ".inf" : "-.inf");
  } else {
    /* 17 significant digits always round-trip; fewer are tried first so that values typed by a
       person (0.1, 9.80665) are written back as typed. */
    for (int prec = 15; prec <= 17; ++prec) {
      snprintf(buf, size, "%.*g", prec, v);
      if (same_bits(strtod(buf, NULL), v)) break;
    }
  }
  return buf;
}

/* ================================================================ the YAML tree */

typedef enum ykind { Y_SCALAR, Y_SEQ, Y_MAP, Y_ALIAS } ykind;

struct nav_io_node {
  nav_io_node *next;  /* next sibling; in a mapping, children alternate key, value */
  nav_io_node *child; /* first child */
  nav_io_node *last;  /* last child (used while building) */
  const char *text;   /* scalar value or alias name, NUL-terminated (may contain NULs) */
  size_t len;
  size_t count;  /* children */
  int line, col; /* 1-based; 0 when libfyaml gives no position (an empty value) */
  ykind kind;
  bool quoted; /* any scalar style but plain: always a string */
  bool tagged; /* has an explicit tag (!!str, !foo) */
};

typedef struct arena_block {
  struct arena_block *next;
  size_t used, cap;
  max_align_t data[];
} arena_block;

typedef struct mark_entry {
  char path[PATH_MAX_LEN];
  int line, col;
} mark_entry;

struct nav_io_reader {
  const char *file;
  nav_diag_fn report;
  void *user;
  int ndiag;
  bool stop;         /* too many diagnostics, or nothing more can be read */
  bool oom;          /* an allocation failed */
  bool newer_format; /* format_version is newer than this reader: the rest is not read */
  char path[PATH_MAX_LEN];
  size_t path_len;
  arena_block *blocks;
  size_t nnodes;
  mark_entry *marks;
  size_t nmarks, cap_marks;
  char err_paths[NAV_DIAG_MAX_PER_FILE][PATH_MAX_LEN]; /* paths with a reader error */
  int nerr_paths;
};

#define ARENA_BLOCK_BYTES ((size_t)64 * 1024)

static void *arena_alloc(nav_io_reader *r, size_t n) {
  const size_t a = alignof(max_align_t);
  n = (n + a - 1) / a * a; /* n <= NAV_IO_MAX_INPUT_BYTES + 1: no overflow */
  arena_block *b = r->blocks;
  if (b == NULL || b->cap - b->used < n) {
    const size_t cap = n > ARENA_BLOCK_BYTES ? n : ARENA_BLOCK_BYTES;
    b = malloc(sizeof *b + cap);
    if (b == NULL) {
      r->oom = true;
      r->stop = true;
      return NULL;
    }
    b->next = r->blocks;
    b->used = 0;
    b->cap = cap;
    r->blocks = b;
  }
  void *p = (char *)b->data + b->used;
  b->used += n;
  return p;
}

static void arena_free(nav_io_reader *r) {
  arena_block *b = r->blocks;
  while (b != NULL) {
    arena_block *next = b->next;
    free(b);
    b = next;
  }
  r->blocks = NULL;
}

/* ================================================================ diagnostics */

static void emit(nav_io_reader *r, int line, int col, const char *path, const char *message) {
  if (r->ndiag >= NAV_DIAG_MAX_PER_FILE) {
    r->stop = true;
    return;
  }
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", r->file);
  d.line = line > 0 ? line : 0;
  d.col = line > 0 && col > 0 ? col : 0;
  if (r->ndiag == NAV_DIAG_MAX_PER_FILE - 1) {
    /* The last slot says that the list is cut, so the count never looks complete when it is not. */
    d.line = 0;
    d.col = 0;
    snprintf(d.message, sizeof d.message, "too many problems; stopping after the first %d",
             NAV_DIAG_MAX_PER_FILE - 1);
    r->stop = true;
  } else {
    snprintf(d.path, sizeof d.path, "%s", path);
    snprintf(d.message, sizeof d.message, "%s", message);
  }
  r->ndiag++;
  if (r->report != NULL) r->report(r->user, &d);
}

static void emitf(nav_io_reader *r, int line, int col, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
static void emitf(nav_io_reader *r, int line, int col, const char *path, const char *fmt, ...) {
  char msg[sizeof(((nav_diag *)0)->message)];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  emit(r, line, col, path, msg);
}

void nav_io_reader_error(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback,
                         const char *fmt, ...) {
  char msg[sizeof(((nav_diag *)0)->message)];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  const nav_io_node *at = node != NULL && node->line > 0 ? node : fallback;
  if (r->nerr_paths < NAV_DIAG_MAX_PER_FILE)
    snprintf(r->err_paths[r->nerr_paths++], PATH_MAX_LEN, "%s", r->path);
  emit(r, at != NULL ? at->line : 0, at != NULL ? at->col : 0, r->path, msg);
}

void nav_diag_format(const nav_diag *d, char *buf, size_t size) {
  if (buf == NULL || size == 0) return;
  if (d == NULL) {
    buf[0] = '\0';
    return;
  }
  /* "FILE:LINE:COL: error: PATH: MESSAGE"; the location is dropped when line is 0 and the path
     when it is empty, so no field is ever printed as a placeholder. */
  if (d->line > 0 && d->path[0] != '\0')
    snprintf(buf, size, "%s:%d:%d: error: %s: %s", d->file, d->line, d->col, d->path, d->message);
  else if (d->line > 0)
    snprintf(buf, size, "%s:%d:%d: error: %s", d->file, d->line, d->col, d->message);
  else if (d->path[0] != '\0')
    snprintf(buf, size, "%s: error: %s: %s", d->file, d->path, d->message);
  else
    snprintf(buf, size, "%s: error: %s", d->file, d->message);
}

/* Copy user text for a message: control bytes become '?', long text is cut (at a UTF-8
   boundary) and ends with "...". */
static void show(char *dst, size_t size, const char *src, size_t len) {
  size_t n = len;
  bool cut = false;
  if (n > SHOW_MAX) {
    n = SHOW_MAX;
    while (n > 0 && ((unsigned char)src[n] & 0xC0) == 0x80)
      --n;
    cut = true;
  }
  if (n + 4 > size) n = size > 4 ? size - 4 : 0;
  size_t j = 0;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = (unsigned char)src[i];
    dst[j++] = (c < 0x20 || c == 0x7f) ? '?' : (char)c;
  }
  if (cut) {
    memcpy(dst + j, "...", 3);
    j += 3;
  }
  dst[j] = '\0';
}

/* ================================================================ field paths and marks */

static size_t path_push_key(nav_io_reader *r, const char *key, size_t len) {
  const size_t saved = r->path_len;
  char shown[SHOW_MAX + 4];
  show(shown, sizeof shown, key, len);
  const int n =
      snprintf(r->path + r->path_len, PATH_MAX_LEN - r->path_len, "%s%s", r->path_len ? "." : "", shown);
  if (n > 0) r->path_len += (size_t)n;
  if (r->path_len >= PATH_MAX_LEN) r->path_len = PATH_MAX_LEN - 1;
  return saved;
}

static size_t path_push_index(nav_io_reader *r, size_t i) {
  const size_t saved = r->path_len;
  const int n = snprintf(r->path + r->path_len, PATH_MAX_LEN - r->path_len, "[%zu]", i);
  if (n > 0) r->path_len += (size_t)n;
  if (r->path_len >= PATH_MAX_LEN) r->path_len = PATH_MAX_LEN - 1;
  return saved;
}

static void path_pop(nav_io_reader *r, size_t saved) {
  r->path_len = saved;
  r->path[saved] = '\0';
}

/* Remember where the current path is in the file, for nav_scene_validate's messages. */
static void mark_path(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback) {
  const nav_io_node *at = node != NULL && node->line > 0 ? node : fallback;
  if (at == NULL || at->line <= 0) return;
  if (r->nmarks == r->cap_marks) {
    const size_t cap = r->cap_marks ? 2 * r->cap_marks : 64;
    if (cap > 65536) return; /* only schema fields are marked: a few hundred at most */
    mark_entry *m = realloc(r->marks, cap * sizeof *m);
    if (m == NULL) return; /* marks only refine locations; reading goes on without them */
    r->marks = m;
    r->cap_marks = cap;
  }
  mark_entry *e = &r->marks[r->nmarks++];
  snprintf(e->path, sizeof e->path, "%s", r->path);
  e->line = at->line;
  e->col = at->col;
}

/* The mark of @p path, else of its nearest parent ("a.b[2]" -> "a.b" -> "a"); false if none. */
static bool find_mark(const nav_io_reader *r, const char *path, int *line, int *col) {
  char buf[PATH_MAX_LEN];
  snprintf(buf, sizeof buf, "%s", path);
  while (buf[0] != '\0') {
    for (size_t i = 0; i < r->nmarks; ++i)
      if (strcmp(r->marks[i].path, buf) == 0) {
        *line = r->marks[i].line;
        *col = r->marks[i].col;
        return true;
      }
    char *dot = strrchr(buf, '.');
    char *bracket = strrchr(buf, '[');
    char *cut = dot > bracket ? dot : bracket;
    if (cut == NULL) break;
    *cut = '\0';
  }
  return false;
}

/* True if @p a and @p b are the same path or one contains the other ("x.y" and "x.y[1]"). */
static bool path_related(const char *a, const char *b) {
  const size_t la = strlen(a), lb = strlen(b);
  const size_t n = la < lb ? la : lb;
  if (strncmp(a, b, n) != 0) return false;
  if (la == lb) return true;
  const char next = la < lb ? b[n] : a[n];
  return next == '.' || next == '[';
}

/* ================================================================ raw text checks */

/* Reject what is not UTF-8 text before libfyaml sees it; report the first offending byte. */
static bool check_text(nav_io_reader *r, const unsigned char *s, size_t n) {
  size_t i = 0;
  int line = 1, col = 1;
  if (n >= 3 && s[0] == 0xEF && s[1] == 0xBB && s[2] == 0xBF) i = 3; /* UTF-8 byte order mark */
  while (i < n) {
    const unsigned c = s[i];
    if (c == '\n') {
      ++line;
      col = 1;
      ++i;
      continue;
    }
    if (c < 0x80) {
      if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
        emitf(r, line, col, "",
              "the file contains binary data (control byte 0x%02x); a scene file must be UTF-8 text", c);
        return false;
      }
      ++i;
      ++col;
      continue;
    }
    /* Multi-byte sequence: length from the lead byte, then continuation bytes; overlong forms,
       UTF-16 surrogates and code points above U+10FFFF are invalid (RFC 3629). */
    size_t len = 0;
    uint32_t cp = 0, min = 0;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
      cp = c & 0x1F;
      min = 0x80;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      cp = c & 0x0F;
      min = 0x800;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      cp = c & 0x07;
      min = 0x10000;
    }
    bool ok = len != 0 && i + len <= n;
    for (size_t k = 1; ok && k < len; ++k) {
      if ((s[i + k] & 0xC0) != 0x80)
        ok = false;
      else
        cp = (cp << 6) | (s[i + k] & 0x3F);
    }
    if (ok && (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))) ok = false;
    if (!ok) {
      emitf(r, line, col, "", "the file is not valid UTF-8 (byte 0x%02x); a scene file must be UTF-8 text",
            c);
      return false;
    }
    i += len;
    ++col;
  }
  return true;
}

/* ================================================================ building the tree */

/* libfyaml's diagnostics are collected (fy_diag_set_collect_errors) and reported by us; anything
   it would still print goes here and is dropped, so the library never writes to stderr. */
static void fy_output_sink(struct fy_diag *diag, void *user, const char *buf, size_t len) {
  (void)diag;
  (void)user;
  (void)buf;
  (void)len;
}

static nav_io_node *new_node(nav_io_reader *r, ykind kind, const struct fy_mark *m) {
  if (r->nnodes >= NAV_IO_MAX_NODES) {
    emitf(r, m != NULL && m->line >= 0 ? m->line + 1 : 0, m != NULL ? m->column + 1 : 0, "",
          "the file has more than %d YAML nodes; this is not a scene file", NAV_IO_MAX_NODES);
    r->stop = true;
    return NULL;
  }
  nav_io_node *n = arena_alloc(r, sizeof *n);
  if (n == NULL) return NULL;
  memset(n, 0, sizeof *n);
  n->kind = kind;
  if (m != NULL && m->line >= 0 && m->column >= 0) {
    n->line = m->line + 1;
    n->col = m->column + 1;
  }
  r->nnodes++;
  return n;
}

static bool set_text(nav_io_reader *r, nav_io_node *n, struct fy_token *tok) {
  size_t len = 0;
  const char *t = tok != NULL ? fy_token_get_text(tok, &len) : NULL;
  if (t == NULL) len = 0;
  char *copy = arena_alloc(r, len + 1);
  if (copy == NULL) return false;
  if (len > 0) memcpy(copy, t, len);
  copy[len] = '\0';
  n->text = copy;
  n->len = len;
  return true;
}

static void attach(nav_io_node *parent, nav_io_node *n) {
  if (parent->child == NULL)
    parent->child = n;
  else
    parent->last->next = n;
  parent->last = n;
  parent->count++;
}

/* Parse @p text into our tree (*root stays NULL for an empty stream). Returns false after a
   reported problem (syntax error, limits) or on allocation failure (r->oom). */
static bool build_tree(nav_io_reader *r, const char *text, size_t len, nav_io_node **root) {
  bool ok = false;
  struct fy_diag *diag = NULL;
  struct fy_parser *fyp = NULL;
  struct fy_event *ev = NULL;
  nav_io_node *stack[NAV_IO_MAX_DEPTH];
  int depth = 0, ndocs = 0;
  int last_line = 0, last_col = 0;

  *root = NULL;
  struct fy_diag_cfg dcfg;
  fy_diag_cfg_default(&dcfg);
  dcfg.fp = NULL;
  dcfg.output_fn = fy_output_sink;
  dcfg.user = NULL;
  dcfg.level = FYET_ERROR;
  dcfg.colorize = false;
  diag = fy_diag_create(&dcfg);
  if (diag == NULL) {
    r->oom = true;
    goto cleanup;
  }
  fy_diag_set_collect_errors(diag, true);

  struct fy_parse_cfg pcfg;
  memset(&pcfg, 0, sizeof pcfg);
  /* YAML 1.2; no JSON mode guessing; duplicate keys are detected by the schema walk, which can
     say where the first one was. Aliases are never resolved here (events only). */
  pcfg.flags = (enum fy_parse_cfg_flags)(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2 | FYPCF_JSON_NONE);
  pcfg.diag = diag;
  fyp = fy_parser_create(&pcfg);
  if (fyp == NULL || fy_parser_set_string(fyp, text, len) != 0) {
    r->oom = true;
    goto cleanup;
  }

  for (;;) {
    ev = fy_parser_parse(fyp);
    if (ev == NULL) break;
    const struct fy_mark *m = fy_event_start_mark(ev);
    if (m != NULL && m->line >= 0) {
      last_line = m->line + 1;
      last_col = m->column + 1;
    }
    nav_io_node *n = NULL;
    switch (ev->type) {
    case FYET_DOCUMENT_START:
      if (++ndocs > 1) {
        emitf(r, last_line, last_col, "",
              "a scene file holds a single YAML document; found a second one (remove the \"---\")");
        goto cleanup;
      }
      break;
    case FYET_MAPPING_START:
    case FYET_SEQUENCE_START:
      if (depth >= NAV_IO_MAX_DEPTH) {
        emitf(r, last_line, last_col, "", "nesting is deeper than %d levels; this is not a scene file",
              NAV_IO_MAX_DEPTH);
        goto cleanup;
      }
      n = new_node(r, ev->type == FYET_MAPPING_START ? Y_MAP : Y_SEQ, m);
      if (n == NULL) goto cleanup;
      n->tagged = (ev->type == FYET_MAPPING_START ? ev->mapping_start.tag : ev->sequence_start.tag) != NULL;
      if (depth > 0)
        attach(stack[depth - 1], n);
      else
        *root = n;
      stack[depth++] = n;
      break;
    case FYET_MAPPING_END:
    case FYET_SEQUENCE_END:
      if (depth > 0) --depth;
      break;
    case FYET_SCALAR:
    case FYET_ALIAS:
      n = new_node(r, ev->type == FYET_SCALAR ? Y_SCALAR : Y_ALIAS, m);
      if (n == NULL) goto cleanup;
      if (ev->type == FYET_SCALAR) {
        if (!set_text(r, n, ev->scalar.value)) goto cleanup;
        const enum fy_scalar_style style = fy_token_scalar_style(ev->scalar.value);
        n->quoted = style != FYSS_PLAIN;
        n->tagged = ev->scalar.tag != NULL;
        /* libfyaml marks the first character after an opening quote; point at the quote. */
        if ((style == FYSS_SINGLE_QUOTED || style == FYSS_DOUBLE_QUOTED) && n->col > 1) n->col--;
      } else {
        if (!set_text(r, n, ev->alias.anchor)) goto cleanup;
        if (n->col > 1) n->col--; /* the mark follows the '*' */
      }
      if (depth > 0)
        attach(stack[depth - 1], n);
      else
        *root = n;
      break;
    default: break;
    }
    fy_parser_event_free(fyp, ev);
    ev = NULL;
  }

  if (fy_parser_get_stream_error(fyp)) {
    int reported = 0;
    void *iter = NULL;
    for (struct fy_diag_error *e = fy_diag_errors_iterate(diag, &iter); e != NULL;
         e = fy_diag_errors_iterate(diag, &iter)) {
      if (e->type < FYET_ERROR) continue;
      emitf(r, e->line, e->column, "", "YAML syntax error: %s", e->msg != NULL ? e->msg : "invalid YAML");
      ++reported;
    }
    if (reported == 0) emitf(r, last_line, last_col, "", "YAML syntax error");
    goto cleanup;
  }
  ok = true;

cleanup:
  if (ev != NULL) fy_parser_event_free(fyp, ev);
  /* Collected errors hold parser tokens and fy_diag_unref does not free them: drop them first,
     while the parser is alive (libfyaml 0.7). */
  if (diag != NULL) fy_diag_reset_error(diag);
  if (fyp != NULL) fy_parser_destroy(fyp);
  if (diag != NULL) fy_diag_unref(diag);
  return ok;
}

/* ================================================================ scalars */

static bool text_is(const nav_io_node *n, const char *s) {
  return n->len == strlen(s) && memcmp(n->text, s, n->len) == 0;
}

static bool is_null(const nav_io_node *n) {
  return n->kind == Y_SCALAR && !n->quoted &&
         (n->len == 0 || text_is(n, "~") || text_is(n, "null") || text_is(n, "Null") || text_is(n, "NULL"));
}

static bool is_bool(const nav_io_node *n) {
  /* YAML 1.2 core booleans plus the YAML 1.1 words people still write. */
  static const char *const words[] = {"true", "True", "TRUE", "false", "False", "FALSE", "yes", "Yes",
                                      "YES",  "no",   "No",   "NO",    "on",    "On",    "ON",  "off",
                                      "Off",  "OFF",  "y",    "Y",     "n",     "N"};
  if (n->kind != Y_SCALAR || n->quoted) return false;
  for (size_t i = 0; i < COUNT(words); ++i)
    if (text_is(n, words[i])) return true;
  return false;
}

/* A short description of what a node is, for "expected X, got <this>". */
static void describe(char *buf, size_t size, const nav_io_node *n) {
  char shown[SHOW_MAX + 4];
  switch (n->kind) {
  case Y_MAP: snprintf(buf, size, "a mapping"); return;
  case Y_SEQ: snprintf(buf, size, "a sequence"); return;
  case Y_ALIAS: snprintf(buf, size, "an alias"); return;
  case Y_SCALAR: break;
  }
  show(shown, sizeof shown, n->text, n->len);
  if (is_null(n))
    snprintf(buf, size, "null (no value)");
  else if (is_bool(n))
    snprintf(buf, size, "the boolean \"%s\"", shown);
  else if (n->quoted)
    snprintf(buf, size, "the quoted string \"%s\"", shown);
  else
    snprintf(buf, size, "\"%s\"", shown);
}

/* Aliases and tags are not part of the scene format: report them once, where they are used. */
static bool reject_special(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v) {
  char shown[SHOW_MAX + 4];
  if (v->kind == Y_ALIAS) {
    show(shown, sizeof shown, v->text, v->len);
    nav_io_reader_error(r, v, key, "aliases (*%s) are not supported in scene files; write the value out",
                        shown);
    return true;
  }
  if (v->tagged) {
    nav_io_reader_error(r, v, key, "YAML tags (!...) are not supported in scene files; remove the tag");
    return true;
  }
  return false;
}

static bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

/* YAML 1.2 core schema float or decimal integer: [-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)? */
static bool is_decimal_number(const char *s, size_t n) {
  size_t i = 0, digits = 0;
  if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
  while (i < n && is_digit(s[i]))
    ++i, ++digits;
  if (i < n && s[i] == '.') {
    ++i;
    while (i < n && is_digit(s[i]))
      ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < n && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
    size_t exp_digits = 0;
    while (i < n && is_digit(s[i]))
      ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  return i == n;
}

static bool is_special_float(const nav_io_node *v, double *out) {
  const char *s = v->text;
  size_t n = v->len;
  double sign = 1.0;
  if (n > 0 && (s[0] == '+' || s[0] == '-')) {
    sign = s[0] == '-' ? -1.0 : 1.0;
    ++s;
    --n;
    if (n == 4 && (memcmp(s, ".inf", 4) == 0 || memcmp(s, ".Inf", 4) == 0 || memcmp(s, ".INF", 4) == 0)) {
      *out = sign * INFINITY;
      return true;
    }
    return false;
  }
  if (n == 4 && (memcmp(s, ".inf", 4) == 0 || memcmp(s, ".Inf", 4) == 0 || memcmp(s, ".INF", 4) == 0)) {
    *out = INFINITY;
    return true;
  }
  if (n == 4 && (memcmp(s, ".nan", 4) == 0 || memcmp(s, ".NaN", 4) == 0 || memcmp(s, ".NAN", 4) == 0)) {
    *out = NAN;
    return true;
  }
  return false;
}

/* A number, as the schema's expectation @p what ("a number", "a sequence of 3 numbers" item). */
static bool parse_double(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, double *out) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return false;
  if (v->kind == Y_SCALAR && !v->quoted && is_special_float(v, out)) return true;
  if (v->kind != Y_SCALAR || v->quoted || !is_decimal_number(v->text, v->len)) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a number, got %s", got);
    return false;
  }
  errno = 0;
  const double d = strtod(v->text, NULL);
  if (errno == ERANGE && isinf(d)) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "number is too large for a double (got %s)", got);
    return false;
  }
  *out = d; /* underflow to a subnormal or zero is accepted: it is the nearest double */
  return true;
}

/* Range and finiteness of a double in file units; the message quotes the text as written. */
static bool check_double(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, double d) {
  char shown[SHOW_MAX + 4], lo[40], hi[40];
  show(shown, sizeof shown, v->text, v->len);
  if ((f->flags & NAV_IO_FINITE) && !isfinite(d)) {
    nav_io_reader_error(r, v, key, "must be finite (got %s)", shown);
    return false;
  }
  const bool has_lo = (f->flags & (NAV_IO_MIN_GT | NAV_IO_MIN_GE)) != 0,
             has_hi = (f->flags & NAV_IO_MAX_LE) != 0;
  const bool lo_ok = !has_lo || ((f->flags & NAV_IO_MIN_GT) ? d > f->min : d >= f->min);
  const bool hi_ok = !has_hi || d <= f->max;
  if (lo_ok && hi_ok) return true;
  /* Name the bound that is violated: "must be > 0 (got -5)". */
  if (!lo_ok) {
    nav_io_format_double(lo, sizeof lo, f->min);
    nav_io_reader_error(r, v, key, "must be %s %s (got %s)", (f->flags & NAV_IO_MIN_GT) ? ">" : ">=", lo,
                        shown);
  } else {
    nav_io_format_double(hi, sizeof hi, f->max);
    nav_io_reader_error(r, v, key, "must be <= %s (got %s)", hi, shown);
  }
  return false;
}

/* A YAML 1.2 integer: [-+]?[0-9]+ | 0x[0-9a-fA-F]+ | 0o[0-7]+, as sign and magnitude;
 *overflow is set when the magnitude does not fit 64 bits. */
static bool parse_integer(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, bool *neg,
                          uint64_t *mag, bool *overflow) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return false;
  const char *s = v->text;
  size_t n = v->len, i = 0;
  unsigned base = 10;
  bool ok = v->kind == Y_SCALAR && !v->quoted && n > 0;
  *neg = false;
  *mag = 0;
  *overflow = false;
  if (ok && (s[0] == '+' || s[0] == '-')) {
    *neg = s[0] == '-';
    i = 1;
  } else if (ok && n > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'o')) {
    base = s[1] == 'x' ? 16 : 8;
    i = 2;
  }
  if (ok && i == n) ok = false;
  for (; ok && i < n; ++i) {
    const char c = s[i];
    unsigned dgt = 16;
    if (is_digit(c))
      dgt = (unsigned)(c - '0');
    else if (c >= 'a' && c <= 'f')
      dgt = (unsigned)(c - 'a' + 10);
    else if (c >= 'A' && c <= 'F')
      dgt = (unsigned)(c - 'A' + 10);
    if (dgt >= base) {
      ok = false;
      break;
    }
    if (*mag > (UINT64_MAX - dgt) / base)
      *overflow = true;
    else
      *mag = *mag * base + dgt;
  }
  if (!ok) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected an integer, got %s", got);
  }
  return ok;
}

/* An integer field of any width: range from the descriptor, else from the C type. */
static bool read_integer(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, long long type_min, long long type_max, long long *out) {
  bool neg = false, overflow = false;
  uint64_t mag = 0;
  char shown[SHOW_MAX + 4];
  if (!parse_integer(r, key, v, &neg, &mag, &overflow)) return false;
  show(shown, sizeof shown, v->text, v->len);
  long long lo = type_min, hi = type_max;
  const bool lo_given = (f->flags & NAV_IO_MIN_GE) != 0, hi_given = (f->flags & NAV_IO_MAX_LE) != 0;
  if (lo_given && f->min > (double)lo) lo = (long long)f->min;
  if (hi_given && f->max < (double)hi) hi = (long long)f->max;
  /* Below or above the range; magnitudes beyond long long are beyond every range. */
  bool below = false, above = false;
  long long val = 0;
  if (overflow || mag > (uint64_t)LLONG_MAX + (neg ? 1u : 0u)) {
    below = neg;
    above = !neg;
  } else {
    val = !neg ? (long long)mag : mag == (uint64_t)LLONG_MAX + 1u ? LLONG_MIN : -(long long)mag;
    below = val < lo;
    above = val > hi;
  }
  /* Name the bound that is violated; the C type's limits only when no range is given. */
  if (below && lo_given) {
    nav_io_reader_error(r, v, key, "must be >= %lld (got %s)", lo, shown);
    return false;
  }
  if (above && hi_given) {
    nav_io_reader_error(r, v, key, "must be <= %lld (got %s)", hi, shown);
    return false;
  }
  if (below || above) {
    nav_io_reader_error(r, v, key, "must be in [%lld, %lld] (got %s)", lo, hi, shown);
    return false;
  }
  *out = val;
  return true;
}

static bool read_u64(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, uint64_t *out) {
  bool neg = false, overflow = false;
  uint64_t mag = 0;
  char shown[SHOW_MAX + 4];
  if (!parse_integer(r, key, v, &neg, &mag, &overflow)) return false;
  show(shown, sizeof shown, v->text, v->len);
  if (neg && (mag > 0 || overflow)) {
    nav_io_reader_error(r, v, key, "must be >= 0 (got %s)", shown);
    return false;
  }
  if (overflow) {
    nav_io_reader_error(r, v, key, "must be <= %" PRIu64 " (got %s)", UINT64_MAX, shown);
    return false;
  }
  *out = mag;
  return true;
}

/* ================================================================ fields and sections */

static void list_keys(char *buf, size_t size, const nav_io_section *sec) {
  size_t len = 0;
  buf[0] = '\0';
  for (size_t i = 0; i < sec->count && len < size; ++i) {
    const int n = snprintf(buf + len, size - len, "%s%s", i ? ", " : "", sec->fields[i].key);
    if (n < 0) break;
    len += (size_t)n;
  }
}

static void list_enum(char *buf, size_t size, const nav_io_enum_value *e) {
  size_t len = 0;
  buf[0] = '\0';
  for (size_t i = 0; e[i].name != NULL && len < size; ++i) {
    const int n = snprintf(buf + len, size - len, "%s%s", i ? ", " : "", e[i].name);
    if (n < 0) break;
    len += (size_t)n;
  }
}

static void read_section(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key,
                         const nav_io_node *v, nav_scene *scene, const nav_io_node *skip_key);

static void read_vec3(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                      nav_scene *scene) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return;
  if (v->kind != Y_SEQ) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a sequence of 3 numbers, got %s", got);
    return;
  }
  if (v->count != 3) {
    nav_io_reader_error(r, v, key, "expected a sequence of 3 numbers, got %zu", v->count);
    return;
  }
  double x[3];
  bool ok = true;
  size_t i = 0;
  for (const nav_io_node *item = v->child; item != NULL && i < 3; item = item->next, ++i) {
    const size_t saved = path_push_index(r, i);
    mark_path(r, item, v);
    if (!parse_double(r, v, item, &x[i]) || !check_double(r, f, v, item, x[i])) ok = false;
    path_pop(r, saved);
  }
  if (!ok) return;
  nav_vec3 *dst = (nav_vec3 *)((char *)scene + f->offset);
  *dst = nav_vec3_make(x[0] * f->scale, x[1] * f->scale, x[2] * f->scale);
}

static void read_enum(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                      nav_scene *scene) {
  char list[256], got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return;
  if (v->kind == Y_SCALAR && !is_null(v))
    for (size_t i = 0; f->enums[i].name != NULL; ++i)
      if (text_is(v, f->enums[i].name)) {
        *(int *)((char *)scene + f->offset) = f->enums[i].value;
        return;
      }
  list_enum(list, sizeof list, f->enums);
  describe(got, sizeof got, v);
  nav_io_reader_error(r, v, key, "expected one of: %s; got %s", list, got);
}

static void read_string(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                        nav_scene *scene) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return;
  if (v->kind != Y_SCALAR || is_null(v)) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a string, got %s", got);
    return;
  }
  if (v->len >= f->size) {
    nav_io_reader_error(r, v, key, "is too long (%zu bytes); at most %zu bytes are allowed", v->len,
                        f->size - 1);
    return;
  }
  for (size_t i = 0; i < v->len; ++i) {
    const unsigned char c = (unsigned char)v->text[i];
    if (c < 0x20 || c == 0x7f) {
      nav_io_reader_error(r, v, key, "must not contain control characters (byte 0x%02x)", c);
      return;
    }
  }
  char *dst = (char *)scene + f->offset;
  memcpy(dst, v->text, v->len);
  dst[v->len] = '\0';
}

static void read_field(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                       nav_scene *scene) {
  char *base = (char *)scene;
  double d = 0.0;
  long long ll = 0;
  switch (f->kind) {
  case NAV_IO_SECTION: read_section(r, f->section, key, v, scene, NULL); break;
  case NAV_IO_DOUBLE:
    if (parse_double(r, key, v, &d) && check_double(r, f, key, v, d))
      *(double *)(base + f->offset) = d * f->scale;
    break;
  case NAV_IO_VEC3: read_vec3(r, f, key, v, scene); break;
  case NAV_IO_INT:
    if (read_integer(r, f, key, v, INT_MIN, INT_MAX, &ll)) *(int *)(base + f->offset) = (int)ll;
    break;
  case NAV_IO_LONG:
    if (read_integer(r, f, key, v, LONG_MIN, LONG_MAX, &ll)) *(long *)(base + f->offset) = (long)ll;
    break;
  case NAV_IO_U64: read_u64(r, key, v, (uint64_t *)(base + f->offset)); break;
  case NAV_IO_ENUM: read_enum(r, f, key, v, scene); break;
  case NAV_IO_STRING: read_string(r, f, key, v, scene); break;
  case NAV_IO_CUSTOM: f->read(r, f, key, v, scene); break;
  }
}

/* Fields with the same storage are spellings of one quantity (lat_deg / lat_rad). */
static size_t group_of(const nav_io_section *sec, size_t i) {
  const nav_io_field *f = &sec->fields[i];
  if (f->kind == NAV_IO_SECTION || f->kind == NAV_IO_CUSTOM) return i;
  for (size_t j = 0; j < i; ++j)
    if (sec->fields[j].kind == f->kind && sec->fields[j].offset == f->offset) return j;
  return i;
}

static long find_field(const nav_io_section *sec, const nav_io_node *key) {
  for (size_t i = 0; i < sec->count; ++i)
    if (text_is(key, sec->fields[i].key)) return (long)i;
  return -1;
}

static char lower(char c) {
  return c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c;
}

/* Optimal string alignment distance (Levenshtein plus adjacent transpositions), case-blind. */
static size_t edit_distance(const char *a, size_t la, const char *b, size_t lb) {
  enum { N = 64 };
  size_t d[N + 1][N + 1];
  if (la > N || lb > N) return (size_t)-1;
  for (size_t i = 0; i <= la; ++i)
    d[i][0] = i;
  for (size_t j = 0; j <= lb; ++j)
    d[0][j] = j;
  for (size_t i = 1; i <= la; ++i)
    for (size_t j = 1; j <= lb; ++j) {
      const size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      size_t best = d[i - 1][j] + 1;
      if (d[i][j - 1] + 1 < best) best = d[i][j - 1] + 1;
      if (d[i - 1][j - 1] + cost < best) best = d[i - 1][j - 1] + cost;
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]) &&
          d[i - 2][j - 2] + 1 < best)
        best = d[i - 2][j - 2] + 1;
      d[i][j] = best;
    }
  return d[la][lb];
}

static void unknown_key(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key) {
  char shown[SHOW_MAX + 4], list[512];
  show(shown, sizeof shown, key->text, key->len);

  /* "rate" for "rate_hz", "lat" for "lat_deg" / "lat_rad": the unit suffix is missing. */
  const char *prefixed[3];
  size_t nprefixed = 0;
  for (size_t i = 0; i < sec->count && nprefixed < 3; ++i) {
    const char *k = sec->fields[i].key;
    if (key->len > 0 && strlen(k) > key->len + 1 && memcmp(k, key->text, key->len) == 0 && k[key->len] == '_')
      prefixed[nprefixed++] = k;
  }
  if (nprefixed == 1) {
    nav_io_reader_error(r, key, NULL, "unknown key \"%s\"; did you mean \"%s\"? (keys carry their unit)",
                        shown, prefixed[0]);
    return;
  }
  if (nprefixed > 1) {
    nav_io_reader_error(r, key, NULL,
                        "unknown key \"%s\"; did you mean \"%s\" or \"%s\"? (keys carry their unit)", shown,
                        prefixed[0], prefixed[1]);
    return;
  }

  /* Closest key by edit distance, within a budget that grows with the length of the key. */
  const size_t budget = key->len <= 3 ? 1 : key->len <= 8 ? 2 : 3;
  size_t best = (size_t)-1;
  const char *best_key = NULL;
  for (size_t i = 0; i < sec->count; ++i) {
    const char *k = sec->fields[i].key;
    const size_t dist = edit_distance(key->text, key->len, k, strlen(k));
    if (dist < best) {
      best = dist;
      best_key = k;
    }
  }
  if (best_key != NULL && best <= budget && best < key->len) {
    nav_io_reader_error(r, key, NULL, "unknown key \"%s\"; did you mean \"%s\"?", shown, best_key);
    return;
  }
  list_keys(list, sizeof list, sec);
  nav_io_reader_error(r, key, NULL, "unknown key \"%s\"; expected one of: %s", shown, list);
}

/* Read the mapping @p map against @p sec. @p skip_key was already read (format_version). */
static void read_mapping(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *map,
                         nav_scene *scene, const nav_io_node *skip_key) {
  const nav_io_node *seen_key[MAX_SECTION_FIELDS] = {NULL};
  size_t seen_field[MAX_SECTION_FIELDS] = {0};
  char got[SHOW_MAX + 32];

  for (const nav_io_node *key = map->child; key != NULL && !r->stop;
       key = key->next ? key->next->next : NULL) {
    const nav_io_node *value = key->next;
    if (value == NULL) break; /* cannot happen: libfyaml gives mappings an even number of events */
    if (key->kind != Y_SCALAR || is_null(key)) {
      describe(got, sizeof got, key);
      nav_io_reader_error(r, key, value, "expected a key name, got %s", got);
      continue;
    }
    const long idx = find_field(sec, key);
    const size_t saved = path_push_key(r, key->text, key->len);
    if (idx < 0) {
      unknown_key(r, sec, key);
      path_pop(r, saved);
      continue;
    }
    const size_t g = group_of(sec, (size_t)idx);
    if (seen_key[g] != NULL) {
      const nav_io_node *first = seen_key[g];
      if (seen_field[g] == (size_t)idx)
        nav_io_reader_error(r, key, NULL, "duplicate key \"%s\" (first given at line %d, column %d)",
                            sec->fields[idx].key, first->line, first->col);
      else
        nav_io_reader_error(r, key, NULL, "both \"%s\" and \"%s\" are given; give only one of them",
                            sec->fields[seen_field[g]].key, sec->fields[idx].key);
      path_pop(r, saved);
      continue;
    }
    seen_key[g] = key;
    seen_field[g] = (size_t)idx;
    if (key != skip_key) {
      /* Mark the value under every spelling, so validation messages about "lat_deg" find a
         file that wrote "lat_rad". */
      for (size_t j = 0; j < sec->count; ++j) {
        if (group_of(sec, j) != g) continue;
        path_pop(r, saved);
        path_push_key(r, sec->fields[j].key, strlen(sec->fields[j].key));
        mark_path(r, value, key);
      }
      path_pop(r, saved);
      path_push_key(r, key->text, key->len);
      read_field(r, &sec->fields[idx], key, value, scene);
    }
    path_pop(r, saved);
  }

  for (size_t i = 0; i < sec->count && !r->stop; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (!(f->flags & NAV_IO_REQUIRED) || group_of(sec, i) != i || seen_key[i] != NULL) continue;
    const size_t saved = path_push_key(r, f->key, strlen(f->key));
    nav_io_reader_error(r, map, NULL, "missing required key \"%s\"", f->key);
    path_pop(r, saved);
  }
}

static void read_section(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key,
                         const nav_io_node *v, nav_scene *scene, const nav_io_node *skip_key) {
  char list[512], got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return;
  if (is_null(v)) return; /* "imu:" with every key commented out: all defaults */
  if (v->kind != Y_MAP) {
    list_keys(list, sizeof list, sec);
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a mapping with keys %s; got %s", list, got);
    return;
  }
  read_mapping(r, sec, v, scene, skip_key);
}

static void read_format_version(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                                const nav_io_node *value, nav_scene *scene) {
  long long v = 0;
  const nav_io_field as_int = {.key = f->key, .kind = NAV_IO_INT};
  if (!read_integer(r, &as_int, key, value, INT_MIN, INT_MAX, &v)) return;
  char supported[32];
  if (NAV_SCENE_FORMAT_VERSION == 1)
    snprintf(supported, sizeof supported, "1");
  else
    snprintf(supported, sizeof supported, "1 to %d", NAV_SCENE_FORMAT_VERSION);
  if (v < 1) {
    nav_io_reader_error(r, value, key, "must be >= 1 (got %lld); supported versions: %s", v, supported);
    return;
  }
  if (v > NAV_SCENE_FORMAT_VERSION) {
    nav_io_reader_error(r, value, key,
                        "format_version %lld is newer than this program supports (supported versions: %s); "
                        "update navcore to read this file",
                        v, supported);
    r->newer_format = true;
    return;
  }
  scene->format_version = (int)v;
}

static void read_root(nav_io_reader *r, const nav_io_node *root, nav_scene *scene) {
  char got[SHOW_MAX + 32];
  if (root->kind != Y_MAP) {
    describe(got, sizeof got, root);
    nav_io_reader_error(
        r, root, NULL,
        "expected a mapping of scene keys (format_version, name, earth, trajectory, ...) at the "
        "top level, got %s",
        got);
    return;
  }
  /* format_version first, wherever it is: a newer file is not read against this schema. */
  const nav_io_section *sec = &nav_io_scene_schema;
  const nav_io_node *fv_key = NULL;
  for (const nav_io_node *k = root->child; k != NULL && k->next != NULL; k = k->next->next)
    if (k->kind == Y_SCALAR && text_is(k, "format_version")) {
      fv_key = k;
      break;
    }
  if (fv_key != NULL) {
    const long idx = find_field(sec, fv_key);
    const size_t saved = path_push_key(r, fv_key->text, fv_key->len);
    mark_path(r, fv_key->next, fv_key);
    read_field(r, &sec->fields[idx], fv_key, fv_key->next, scene);
    path_pop(r, saved);
    if (r->newer_format) return;
  }
  read_mapping(r, sec, root, scene, fv_key);
}

/* ================================================================ validation and entry points */

static void on_validate_issue(void *user, const char *path, const char *message) {
  nav_io_reader *r = user;
  if (path == NULL) path = "";
  /* A field the reader rejected keeps its default, so validation would only repeat the problem. */
  for (int i = 0; i < r->nerr_paths; ++i)
    if (path_related(r->err_paths[i], path)) return;
  int line = 0, col = 0;
  find_mark(r, path, &line, &col);
  emit(r, line, col, path, message != NULL ? message : "invalid value");
}

static nav_status read_buffer(const char *text, size_t len, const char *name, nav_scene *out,
                              nav_diag_fn report, void *user) {
  nav_status st = NAV_OK;
  nav_io_reader *r = NULL;
  nav_io_node *root = NULL;
  nav_io_c_locale loc;
  nav_scene scene = nav_scene_default();

  r = calloc(1, sizeof *r);
  if (r == NULL) return NAV_ERR_NO_MEMORY;
  r->file = name;
  r->report = report;
  r->user = user;
  nav_io_c_locale_begin(&loc);

  if (len > NAV_IO_MAX_INPUT_BYTES) {
    emitf(r, 0, 0, "", "the input is too large (%zu bytes); scene files are limited to %zu bytes (16 MiB)",
          len, NAV_IO_MAX_INPUT_BYTES);
    goto cleanup;
  }
  if (!check_text(r, (const unsigned char *)text, len)) goto cleanup;
  if (len > 0 && !build_tree(r, text, len, &root)) goto cleanup;
  if (root == NULL || is_null(root)) { /* nothing, or only "---" / "~" */
    emitf(r, 1, 1, "", "the file is empty; a scene needs at least \"format_version: %d\"",
          NAV_SCENE_FORMAT_VERSION);
    goto cleanup;
  }
  read_root(r, root, &scene);
  if (r->newer_format || r->oom || root->kind != Y_MAP) goto cleanup;

  /* Cross-field and domain checks shared with the editor; their paths are placed in the file. */
  const int before = r->ndiag;
  const nav_status vs = nav_scene_validate(&scene, on_validate_issue, r);
  if (vs != NAV_OK && r->ndiag == before && r->nerr_paths == 0)
    emitf(r, 0, 0, "", "the scene is not valid (%s)", nav_status_str(vs));

cleanup:
  nav_io_c_locale_end(&loc);
  arena_free(r);
  free(r->marks);
  if (r->oom)
    st = NAV_ERR_NO_MEMORY;
  else if (r->ndiag > 0)
    st = NAV_ERR_PARSE;
  else
    *out = scene;
  free(r);
  return st;
}

nav_status nav_scene_read_string(const char *text, size_t len, const char *display_name, nav_scene *out,
                                 nav_diag_fn report, void *user) {
  if (out == NULL || (text == NULL && len > 0)) return NAV_ERR_INVALID_ARG;
  return read_buffer(text != NULL ? text : "", len, display_name != NULL ? display_name : "<string>", out,
                     report, user);
}

static void report_file_problem(const char *path, nav_diag_fn report, void *user, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static void report_file_problem(const char *path, nav_diag_fn report, void *user, const char *fmt, ...) {
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", path);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d.message, sizeof d.message, fmt, ap);
  va_end(ap);
  if (report != NULL) report(user, &d);
}

nav_status nav_scene_read_file(const char *path, nav_scene *out, nav_diag_fn report, void *user) {
  nav_status st = NAV_OK;
  FILE *fp = NULL;
  char *buf = NULL;
  char why[256];
  size_t len = 0, cap = 0;

  if (path == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  fp = fopen(path, "rb");
  if (fp == NULL) {
    const int err = errno;
    if (strerror_r(err, why, sizeof why) != 0) snprintf(why, sizeof why, "error %d", err);
    report_file_problem(path, report, user, "cannot open the file: %s", why);
    st = NAV_ERR_IO;
    goto cleanup;
  }
  struct stat sb;
  if (fstat(fileno(fp), &sb) == 0) {
    if (S_ISDIR(sb.st_mode)) {
      report_file_problem(path, report, user, "cannot read the file: it is a directory");
      st = NAV_ERR_IO;
      goto cleanup;
    }
    if (S_ISREG(sb.st_mode) && (uintmax_t)sb.st_size > NAV_IO_MAX_INPUT_BYTES) {
      report_file_problem(path, report, user,
                          "the file is too large (%jd bytes); scene files are limited to %zu bytes (16 MiB)",
                          (intmax_t)sb.st_size, NAV_IO_MAX_INPUT_BYTES);
      st = NAV_ERR_PARSE;
      goto cleanup;
    }
    if (S_ISREG(sb.st_mode)) cap = (size_t)sb.st_size + 1;
  }
  if (cap < 4096) cap = 4096;
  buf = malloc(cap);
  if (buf == NULL) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  /* Read to the end even for pipes and files that grow, but never beyond the cap. */
  for (;;) {
    if (len == cap) {
      if (cap > NAV_IO_MAX_INPUT_BYTES) {
        report_file_problem(path, report, user,
                            "the file is too large; scene files are limited to %zu bytes (16 MiB)",
                            NAV_IO_MAX_INPUT_BYTES);
        st = NAV_ERR_PARSE;
        goto cleanup;
      }
      size_t next = cap * 2;
      if (next > NAV_IO_MAX_INPUT_BYTES + 1) next = NAV_IO_MAX_INPUT_BYTES + 1;
      char *grown = realloc(buf, next);
      if (grown == NULL) {
        st = NAV_ERR_NO_MEMORY;
        goto cleanup;
      }
      buf = grown;
      cap = next;
    }
    const size_t got = fread(buf + len, 1, cap - len, fp);
    len += got;
    if (got == 0) break;
  }
  if (ferror(fp)) {
    const int err = errno;
    if (strerror_r(err, why, sizeof why) != 0) snprintf(why, sizeof why, "error %d", err);
    report_file_problem(path, report, user, "cannot read the file: %s", why);
    st = NAV_ERR_IO;
    goto cleanup;
  }
  st = read_buffer(buf, len, path, out, report, user);

cleanup:
  free(buf);
  if (fp != NULL) fclose(fp);
  return st;
}
