/*
 * The scene schema as data (nav_schema.h): the flat key list and the JSON Schema, both generated
 * from the nav_io_field tables that the reader (scene_read.c, scene_traj_io.c,
 * scene_gnss_sat_io.c) and the writer walk. Nothing here restates a key, a bound or a default:
 * bounds are the descriptors' min/max under their flags, defaults are nav_scene_default()'s values
 * at the descriptors' offsets divided by their scale, units come from the key's unit suffix (or a
 * descriptor's .unit), and the values of CUSTOM keys are described by their own .schema function
 * or by their .items / .kinded tables. docs/scene-schema.md explains the mapping.
 */
#define _POSIX_C_SOURCE 200809L

#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_schema.h"
#include "scene_io_internal.h"

/* ================================================================ JSON text */

#define JSON_MAX_DEPTH 64

struct nav_io_json {
  char *buf;
  size_t len, cap;
  bool oom;
  int depth;
  int count[JSON_MAX_DEPTH];   /* members / items written in each open container */
  bool is_array[JSON_MAX_DEPTH];
  bool inline_array[JSON_MAX_DEPTH];
  bool after_key; /* a key was written; its value comes next on the same line */
};

static void put(nav_io_json *j, const char *s, size_t n) {
  if (j->oom) return;
  if (j->len + n + 1 > j->cap) {
    size_t cap = j->cap ? j->cap : 4096;
    while (j->len + n + 1 > cap) cap *= 2;
    char *b = realloc(j->buf, cap);
    if (b == NULL) {
      j->oom = true;
      return;
    }
    j->buf = b;
    j->cap = cap;
  }
  memcpy(j->buf + j->len, s, n);
  j->len += n;
  j->buf[j->len] = '\0';
}

static void puts_(nav_io_json *j, const char *s) {
  put(j, s, strlen(s));
}

static void newline(nav_io_json *j) {
  puts_(j, "\n");
  for (int i = 0; i < j->depth; ++i) puts_(j, "  ");
}

/* Before a value: a separator and a new line inside arrays; nothing after a key. */
static void value_prefix(nav_io_json *j) {
  if (j->after_key) {
    j->after_key = false;
    return;
  }
  if (j->depth == 0) return;
  const int d = j->depth - 1;
  if (j->count[d] > 0) puts_(j, j->inline_array[d] ? ", " : ",");
  if (!j->inline_array[d]) newline(j);
  j->count[d]++;
}

static void open_(nav_io_json *j, const char *c, bool array, bool inl) {
  value_prefix(j);
  puts_(j, c);
  if (j->depth < JSON_MAX_DEPTH) {
    j->count[j->depth] = 0;
    j->is_array[j->depth] = array;
    j->inline_array[j->depth] = inl;
  }
  j->depth++;
}

static void close_(nav_io_json *j, const char *c) {
  j->depth--;
  const int d = j->depth;
  if (d < JSON_MAX_DEPTH && j->count[d] > 0 && !j->inline_array[d]) newline(j);
  puts_(j, c);
}

void nav_io_json_begin(nav_io_json *j) {
  open_(j, "{", false, false);
}
void nav_io_json_end(nav_io_json *j) {
  close_(j, "}");
}
static void array_begin(nav_io_json *j, bool inl) {
  open_(j, "[", true, inl);
}
static void array_end(nav_io_json *j) {
  close_(j, "]");
}

static void quoted(nav_io_json *j, const char *s) {
  puts_(j, "\"");
  for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
    char esc[8];
    if (*p == '"' || *p == '\\') {
      esc[0] = '\\';
      esc[1] = (char)*p;
      put(j, esc, 2);
    } else if (*p < 0x20) {
      snprintf(esc, sizeof esc, "\\u%04x", *p);
      puts_(j, esc);
    } else {
      put(j, (const char *)p, 1);
    }
  }
  puts_(j, "\"");
}

void nav_io_json_key(nav_io_json *j, const char *key) {
  const int d = j->depth - 1;
  if (d >= 0 && d < JSON_MAX_DEPTH) {
    if (j->count[d] > 0) puts_(j, ",");
    j->count[d]++;
  }
  newline(j);
  quoted(j, key);
  puts_(j, ": ");
  j->after_key = true;
}

void nav_io_json_raw(nav_io_json *j, const char *json) {
  value_prefix(j);
  puts_(j, json);
}

void nav_io_json_string(nav_io_json *j, const char *s) {
  value_prefix(j);
  quoted(j, s);
}

/* Numbers with at most 15 significant digits: a default converted to the file's unit (x / scale)
   shows as the value a person would type (45, not 45.000000000000007). */
void nav_io_json_number(nav_io_json *j, double v) {
  char b[40];
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  if (!isfinite(v))
    snprintf(b, sizeof b, "null");
  else if (v == 0.0)
    snprintf(b, sizeof b, "0");
  else
    snprintf(b, sizeof b, "%.15g", v);
  nav_io_c_locale_end(&loc);
  nav_io_json_raw(j, b);
}

/* Bounds and scales: the shortest text that reads back to the same double, so that a consumer
   compares against exactly the reader's bound. */
static void member_exact(nav_io_json *j, const char *key, double v) {
  char b[40];
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  nav_io_format_double(b, sizeof b, v);
  nav_io_c_locale_end(&loc);
  nav_io_json_key(j, key);
  nav_io_json_raw(j, isfinite(v) ? b : "null");
}

static void member_string(nav_io_json *j, const char *key, const char *s) {
  nav_io_json_key(j, key);
  nav_io_json_string(j, s);
}
static void member_number(nav_io_json *j, const char *key, double v) {
  nav_io_json_key(j, key);
  nav_io_json_number(j, v);
}
static void member_raw(nav_io_json *j, const char *key, const char *json) {
  nav_io_json_key(j, key);
  nav_io_json_raw(j, json);
}

/* ================================================================ what the table says */

/* Units as written, from the key's unit suffix (style.md: units are part of the names). Longest
   suffixes first; the first match wins. */
static const struct {
  const char *suffix;
  const char *unit;
} k_units[] = {
    {"_deg_per_h_per_sqrt_h", "deg/h/sqrt(h)"},
    {"_deg_per_s_per_sqrt_hz", "deg/s/sqrt(Hz)"},
    {"_deg_per_h_per_g", "deg/h/g"},
    {"_deg_per_sqrt_h", "deg/sqrt(h)"},
    {"_deg_per_h", "deg/h"},
    {"_rad_per_sqrt_s", "rad/sqrt(s)"},
    {"_rps_per_sqrt_s", "rad/s/sqrt(s)"},
    {"_rps_per_mps2", "rad/s/(m/s^2)"},
    {"_m_per_s2_per_sqrt_h", "m/s^2/sqrt(h)"},
    {"_mps2_per_sqrt_s", "m/s^2/sqrt(s)"},
    {"_m_per_s_per_sqrt_h", "m/s/sqrt(h)"},
    {"_mps_per_sqrt_s", "m/s/sqrt(s)"},
    {"_ug_per_sqrt_hz", "ug/sqrt(Hz)"},
    {"_dps3", "deg/s^3"},
    {"_dps2", "deg/s^2"},
    {"_rps3", "rad/s^3"},
    {"_rps2", "rad/s^2"},
    {"_mps3", "m/s^3"},
    {"_mps2", "m/s^2"},
    {"_dps", "deg/s"},
    {"_rps", "rad/s"},
    {"_rpm", "rev/min"},
    {"_mps", "m/s"},
    {"_hz", "Hz"},
    {"_mrad", "mrad"},
    {"_rad", "rad"},
    {"_deg", "deg"},
    {"_ppm", "ppm"},
    {"_mg", "mg"},
    {"_ug", "ug"},
    {"_g", "g"},
    {"_m", "m"},
    {"_s", "s"},
};

static bool ends_with(const char *s, const char *suffix) {
  const size_t n = strlen(s), m = strlen(suffix);
  return n > m && strcmp(s + n - m, suffix) == 0;
}

static bool is_numeric(nav_io_kind k) {
  return k == NAV_IO_DOUBLE || k == NAV_IO_VEC3 || k == NAV_IO_VEC3S || k == NAV_IO_MAT3_OFFDIAG ||
         k == NAV_IO_MAT3_DIAG;
}

/* The unit of a numeric key as written in the file, or NULL (counts, enums, text). */
static const char *unit_of(const nav_io_field *f) {
  if (f->unit != NULL) return f->unit[0] != '\0' ? f->unit : NULL;
  if (!is_numeric(f->kind) && f->kind != NAV_IO_CUSTOM) return NULL;
  for (size_t i = 0; i < sizeof k_units / sizeof k_units[0]; ++i)
    if (ends_with(f->key, k_units[i].suffix)) return k_units[i].unit;
  return NULL;
}

static const char *doc_of(const nav_io_field *f) {
  if (f->doc != NULL) return f->doc;
  if (f->comment != NULL) return f->comment;
  return "";
}

/* The preferred spelling of an ALT descriptor: the nearest earlier non-ALT one of the same
   quantity (same storage). */
static const nav_io_field *preferred_of(const nav_io_section *sec, size_t i) {
  const nav_io_field *f = &sec->fields[i];
  if (!(f->flags & NAV_IO_ALT)) return NULL;
  for (size_t k = i; k-- > 0;) {
    const nav_io_field *g = &sec->fields[k];
    if (!(g->flags & NAV_IO_ALT) && g->offset == f->offset && (g->flags & NAV_IO_STATE) == (f->flags & NAV_IO_STATE))
      return g;
  }
  return NULL;
}

/* The description of field i of sec: its own, else its comment, else (another spelling of a
   quantity) that of the preferred spelling. */
static const char *doc_in(const nav_io_section *sec, size_t i) {
  const char *d = doc_of(&sec->fields[i]);
  const nav_io_field *pref = d[0] == '\0' ? preferred_of(sec, i) : NULL;
  return pref != NULL ? doc_of(pref) : d;
}

/* The default of a plain field in the file's unit, from the default object @p def (NULL: none). */
typedef struct field_default {
  bool has;
  int n;          /* numbers in v (1 or 3); 0 for text */
  double v[3];
  const char *text; /* enum name (static) */
  bool string;      /* the default is the text in buf */
  char buf[NAV_SCHEMA_TEXT_MAX];
  bool boolean;
} field_default;

static const char *enum_name(const nav_io_enum_value *e, int v) {
  for (; e != NULL && e->name != NULL; ++e)
    if (e->value == v) return e->name;
  return NULL;
}

static field_default default_of(const nav_io_field *f, const void *def) {
  field_default d;
  memset(&d, 0, sizeof d);
  if (def == NULL || (f->flags & NAV_IO_STATE)) return d;
  const char *p = (const char *)def + f->offset;
  const double sc = f->scale != 0.0 ? f->scale : 1.0;
  switch (f->kind) {
  case NAV_IO_DOUBLE: {
    double x;
    memcpy(&x, p, sizeof x);
    d.v[0] = x / sc;
    d.n = 1;
    d.has = isfinite(d.v[0]);
    break;
  }
  case NAV_IO_VEC3:
  case NAV_IO_VEC3S: {
    nav_vec3 x;
    memcpy(&x, p, sizeof x);
    d.v[0] = x.x / sc;
    d.v[1] = x.y / sc;
    d.v[2] = x.z / sc;
    d.n = f->kind == NAV_IO_VEC3S && d.v[0] == d.v[1] && d.v[1] == d.v[2] ? 1 : 3;
    d.has = isfinite(d.v[0]) && isfinite(d.v[1]) && isfinite(d.v[2]);
    break;
  }
  case NAV_IO_MAT3_OFFDIAG:
  case NAV_IO_MAT3_DIAG: {
    nav_mat3 m;
    memcpy(&m, p, sizeof m);
    const bool diag = f->kind == NAV_IO_MAT3_DIAG;
    const double x = diag ? m.m[0][0] : m.m[0][1];
    bool uniform = true;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        const bool on = (r == c) == diag;
        if (on && m.m[r][c] != x) uniform = false;
        if (!on && !diag && m.m[r][c] != 0.0) uniform = false; /* diagonal of an off-diagonal matrix */
        if (!on && diag && m.m[r][c] != 0.0) uniform = false;
      }
    d.v[0] = x / sc;
    d.n = 1;
    d.has = uniform && isfinite(d.v[0]);
    break;
  }
  case NAV_IO_INT: {
    int x;
    memcpy(&x, p, sizeof x);
    d.v[0] = x;
    d.n = 1;
    d.has = true;
    break;
  }
  case NAV_IO_LONG: {
    long x;
    memcpy(&x, p, sizeof x);
    d.v[0] = (double)x;
    d.n = 1;
    d.has = true;
    break;
  }
  case NAV_IO_U64: {
    uint64_t x;
    memcpy(&x, p, sizeof x);
    snprintf(d.buf, sizeof d.buf, "%" PRIu64, x);
    d.v[0] = (double)x;
    d.n = 1;
    d.has = true;
    break;
  }
  case NAV_IO_BOOL: {
    bool x;
    memcpy(&x, p, sizeof x);
    d.boolean = true;
    d.v[0] = x ? 1.0 : 0.0;
    d.n = 1;
    d.has = true;
    break;
  }
  case NAV_IO_ENUM: {
    int x;
    memcpy(&x, p, sizeof x);
    d.text = enum_name(f->enums, x);
    d.has = d.text != NULL;
    break;
  }
  case NAV_IO_STRING:
    snprintf(d.buf, sizeof d.buf, "%.*s", (int)(f->size < sizeof d.buf ? f->size : sizeof d.buf - 1), p);
    d.string = true;
    d.has = strnlen(p, f->size) < sizeof d.buf;
    break;
  default:
    break;
  }
  return d;
}

/* ================================================================ JSON Schema */

static void json_field(nav_io_json *j, const nav_io_field *f, const void *def, const char *doc);

static void number_bounds(nav_io_json *j, const nav_io_field *f) {
  if (f->flags & NAV_IO_MIN_GT) member_exact(j, "exclusiveMinimum", f->min);
  if (f->flags & NAV_IO_MIN_GE) member_exact(j, "minimum", f->min);
  if (f->flags & NAV_IO_MAX_LE) member_exact(j, "maximum", f->max);
}

/* {"type": "number", bounds} as the value of the current key */
static void number_schema(nav_io_json *j, const nav_io_field *f) {
  nav_io_json_begin(j);
  member_string(j, "type", "number");
  number_bounds(j, f);
  nav_io_json_end(j);
}

static void three(nav_io_json *j) {
  member_number(j, "minItems", 3);
  member_number(j, "maxItems", 3);
}

static void json_default(nav_io_json *j, const nav_io_field *f, const void *def) {
  const field_default d = default_of(f, def);
  if (!d.has) return;
  nav_io_json_key(j, "default");
  if (d.boolean) {
    nav_io_json_raw(j, d.v[0] != 0.0 ? "true" : "false");
  } else if (d.text != NULL) {
    nav_io_json_string(j, d.text);
  } else if (d.string) {
    nav_io_json_string(j, d.buf);
  } else if (f->kind == NAV_IO_U64) {
    nav_io_json_raw(j, d.buf);
  } else if (d.n == 3) {
    array_begin(j, true);
    for (int i = 0; i < 3; ++i) nav_io_json_number(j, d.v[i]);
    array_end(j);
  } else {
    nav_io_json_number(j, d.v[0]);
  }
}

static void enum_list(nav_io_json *j, const nav_io_enum_value *e) {
  array_begin(j, true);
  for (; e != NULL && e->name != NULL; ++e) nav_io_json_string(j, e->name);
  array_end(j);
}

/* The keywords of a mapping read against @p sec, into the open object. */
void nav_io_json_section_members(nav_io_json *j, const nav_io_section *sec, const void *def) {
  nav_io_json_key(j, "properties");
  nav_io_json_begin(j);
  for (size_t i = 0; i < sec->count; ++i) {
    nav_io_json_key(j, sec->fields[i].key);
    json_field(j, &sec->fields[i], def, doc_in(sec, i));
  }
  nav_io_json_end(j);
  member_raw(j, "additionalProperties", "false");
  size_t nreq = 0, nalt = 0;
  for (size_t i = 0; i < sec->count; ++i) {
    if (sec->fields[i].flags & NAV_IO_REQUIRED) ++nreq;
    if (preferred_of(sec, i) != NULL) ++nalt;
  }
  if (nreq > 0) {
    nav_io_json_key(j, "required");
    array_begin(j, true);
    for (size_t i = 0; i < sec->count; ++i)
      if (sec->fields[i].flags & NAV_IO_REQUIRED) nav_io_json_string(j, sec->fields[i].key);
    array_end(j);
  }
  /* Two spellings of one quantity (lat_deg and lat_rad) may not both be given. */
  if (nalt > 0) {
    nav_io_json_key(j, "allOf");
    array_begin(j, false);
    for (size_t i = 0; i < sec->count; ++i) {
      if (preferred_of(sec, i) == NULL) continue;
      for (size_t k = 0; k < i; ++k) {
        const nav_io_field *f = &sec->fields[i], *g = &sec->fields[k];
        if (g->offset != f->offset || (g->flags & NAV_IO_STATE) != (f->flags & NAV_IO_STATE)) continue;
        if (preferred_of(sec, i) != g && preferred_of(sec, k) != preferred_of(sec, i)) continue;
        nav_io_json_begin(j);
        nav_io_json_key(j, "not");
        nav_io_json_begin(j);
        nav_io_json_key(j, "required");
        array_begin(j, true);
        nav_io_json_string(j, g->key);
        nav_io_json_string(j, f->key);
        array_end(j);
        nav_io_json_end(j);
        nav_io_json_end(j);
      }
    }
    array_end(j);
  }
}

void nav_io_json_section(nav_io_json *j, const nav_io_section *sec, const void *def) {
  nav_io_json_begin(j);
  member_string(j, "type", "object");
  nav_io_json_section_members(j, sec, def);
  nav_io_json_end(j);
}

/* A kind-dependent mapping: the kind names, then for each kind the keys of its section. */
static void kinded_schema(nav_io_json *j, const nav_io_kinded *kd, const void *def) {
  member_string(j, "type", "object");
  member_raw(j, "required", "[\"kind\"]");
  nav_io_json_key(j, "properties");
  nav_io_json_begin(j);
  nav_io_json_key(j, "kind");
  nav_io_json_begin(j);
  member_string(j, "type", "string");
  nav_io_json_key(j, "enum");
  enum_list(j, kd->kinds);
  /* each kind's section starts with the kind descriptor itself (scene_io_internal.h) */
  const nav_io_section *first = kd->nsections > 0 ? kd->sections[0] : NULL;
  if (first != NULL && first->count > 0 && doc_of(&first->fields[0])[0] != '\0')
    member_string(j, "description", doc_of(&first->fields[0]));
  nav_io_json_end(j);
  nav_io_json_end(j);
  nav_io_json_key(j, "allOf");
  array_begin(j, false);
  for (const nav_io_enum_value *e = kd->kinds; e->name != NULL; ++e) {
    if (e->value < 0 || (size_t)e->value >= kd->nsections || kd->sections[e->value] == NULL) continue;
    nav_io_json_begin(j);
    nav_io_json_key(j, "if");
    nav_io_json_begin(j);
    nav_io_json_key(j, "properties");
    nav_io_json_begin(j);
    nav_io_json_key(j, "kind");
    nav_io_json_begin(j);
    member_string(j, "const", e->name);
    nav_io_json_end(j);
    nav_io_json_end(j);
    nav_io_json_end(j);
    nav_io_json_key(j, "then");
    nav_io_json_section(j, kd->sections[e->value], def);
    nav_io_json_end(j);
  }
  array_end(j);
}

static void json_field(nav_io_json *j, const nav_io_field *f, const void *def, const char *doc) {
  nav_io_json_begin(j);
  const char *unit = unit_of(f);
  switch (f->kind) {
  case NAV_IO_SECTION:
    member_raw(j, "type", "[\"object\", \"null\"]");
    if (doc[0] != '\0') member_string(j, "description", doc);
    nav_io_json_section_members(j, f->section, def);
    nav_io_json_end(j);
    return;
  case NAV_IO_DOUBLE:
    member_string(j, "type", "number");
    number_bounds(j, f);
    break;
  case NAV_IO_VEC3:
    member_string(j, "type", "array");
    nav_io_json_key(j, "items");
    number_schema(j, f);
    three(j);
    break;
  case NAV_IO_VEC3S:
    member_raw(j, "type", "[\"number\", \"array\"]");
    if (f->max_axis != NULL) {
      /* one number sets all three axes: the smallest axis maximum; a list: each axis its own */
      nav_io_field one = *f;
      for (int a = 0; a < 3; ++a)
        if (f->max_axis[a] < one.max) one.max = f->max_axis[a];
      number_bounds(j, &one);
      nav_io_json_key(j, "prefixItems");
      array_begin(j, false);
      for (int a = 0; a < 3; ++a) {
        one.max = f->max_axis[a];
        number_schema(j, &one);
      }
      array_end(j);
    } else {
      number_bounds(j, f);
    }
    nav_io_json_key(j, "items");
    number_schema(j, f);
    three(j);
    break;
  case NAV_IO_MAT3_OFFDIAG:
  case NAV_IO_MAT3_DIAG:
    member_raw(j, "type", "[\"number\", \"array\"]");
    number_bounds(j, f);
    nav_io_json_key(j, "items");
    nav_io_json_begin(j);
    if (f->kind == NAV_IO_MAT3_DIAG) {
      member_raw(j, "type", "[\"number\", \"array\"]");
      number_bounds(j, f);
    } else {
      member_string(j, "type", "array");
    }
    nav_io_json_key(j, "items");
    number_schema(j, f);
    three(j);
    nav_io_json_end(j);
    three(j);
    break;
  case NAV_IO_INT:
  case NAV_IO_LONG:
    member_string(j, "type", "integer");
    number_bounds(j, f);
    break;
  case NAV_IO_U64:
    member_string(j, "type", "integer");
    member_number(j, "minimum", 0);
    member_raw(j, "maximum", "18446744073709551615");
    break;
  case NAV_IO_BOOL:
    member_string(j, "type", "boolean");
    break;
  case NAV_IO_ENUM:
    member_string(j, "type", "string");
    nav_io_json_key(j, "enum");
    enum_list(j, f->enums);
    break;
  case NAV_IO_STRING:
    member_string(j, "type", "string");
    if (f->size > 0) member_number(j, "maxLength", (double)(f->size - 1));
    break;
  case NAV_IO_CUSTOM:
    if (f->schema != NULL) {
      f->schema(j, f);
    } else if (f->items != NULL) {
      member_string(j, "type", "array");
      nav_io_json_key(j, "items");
      nav_io_json_section(j, f->items, NULL);
    } else if (f->kinded != NULL && f->items_kinded) {
      member_string(j, "type", "array");
      nav_io_json_key(j, "items");
      nav_io_json_begin(j);
      kinded_schema(j, f->kinded, NULL);
      nav_io_json_end(j);
    } else if (f->kinded != NULL) {
      kinded_schema(j, f->kinded, def);
    }
    if (f->max_items > 0) member_number(j, "maxItems", (double)f->max_items);
    break;
  }
  if (doc[0] != '\0') member_string(j, "description", doc);
  json_default(j, f, def);
  if (unit != NULL) {
    member_string(j, "x-unit", unit);
    if (is_numeric(f->kind)) member_exact(j, "x-si-scale", f->scale != 0.0 ? f->scale : 1.0);
  }
  nav_io_json_end(j);
}

char *nav_schema_json(void) {
  nav_io_json j;
  memset(&j, 0, sizeof j);
  nav_scene *def = malloc(sizeof *def);
  if (def == NULL) return NULL;
  *def = nav_scene_default();
  nav_io_json_begin(&j);
  member_string(&j, "$schema", "https://json-schema.org/draft/2020-12/schema");
  member_string(&j, "$id", "https://navsim.invalid/schema/scene-v1.json");
  member_string(&j, "title", "navsim scene file");
  {
    char d[160];
    snprintf(d, sizeof d,
             "A scene for navsim and navstudio (format_version %d); YAML 1.2, shown here as the JSON "
             "it maps to",
             NAV_SCENE_FORMAT_VERSION);
    member_string(&j, "description", d);
  }
  member_string(&j, "type", "object");
  nav_io_json_section_members(&j, &nav_io_scene_schema, def);
  nav_io_json_end(&j);
  put(&j, "\n", 1);
  free(def);
  if (j.oom) {
    free(j.buf);
    return NULL;
  }
  return j.buf;
}

/* ================================================================ the flat key list */

typedef struct key_list {
  nav_schema_key *keys;
  size_t n, cap;
  bool oom;
} key_list;

static nav_schema_key *add_key(key_list *L) {
  if (L->oom) return NULL;
  if (L->n == L->cap) {
    const size_t cap = L->cap ? 2 * L->cap : 256;
    nav_schema_key *k = realloc(L->keys, cap * sizeof *k);
    if (k == NULL) {
      L->oom = true;
      return NULL;
    }
    L->keys = k;
    L->cap = cap;
  }
  nav_schema_key *k = &L->keys[L->n++];
  memset(k, 0, sizeof *k);
  k->alt_of = -1;
  k->scale = 1.0;
  return k;
}

static nav_schema_type type_of(const nav_io_field *f) {
  switch (f->kind) {
  case NAV_IO_SECTION: return NAV_SCHEMA_SECTION;
  case NAV_IO_DOUBLE: return NAV_SCHEMA_NUMBER;
  case NAV_IO_VEC3: return NAV_SCHEMA_VEC3;
  case NAV_IO_VEC3S: return NAV_SCHEMA_VEC3_SCALAR;
  case NAV_IO_MAT3_OFFDIAG: return NAV_SCHEMA_MAT3_OFFDIAG;
  case NAV_IO_MAT3_DIAG: return NAV_SCHEMA_MAT3_DIAG;
  case NAV_IO_INT:
  case NAV_IO_LONG:
  case NAV_IO_U64: return NAV_SCHEMA_INTEGER;
  case NAV_IO_BOOL: return NAV_SCHEMA_BOOLEAN;
  case NAV_IO_ENUM: return NAV_SCHEMA_ENUM;
  case NAV_IO_STRING: return NAV_SCHEMA_STRING;
  case NAV_IO_CUSTOM:
    return f->items != NULL || (f->kinded != NULL && f->items_kinded) ? NAV_SCHEMA_LIST : NAV_SCHEMA_OTHER;
  }
  return NAV_SCHEMA_OTHER;
}

static void walk(key_list *L, const nav_io_section *sec, const void *def, const char *prefix);

static void walk_kinded(key_list *L, const nav_io_kinded *kd, const void *def, const char *path) {
  for (const nav_io_enum_value *e = kd->kinds; e->name != NULL; ++e) {
    if (e->value < 0 || (size_t)e->value >= kd->nsections || kd->sections[e->value] == NULL) continue;
    char p[NAV_SCHEMA_PATH_MAX];
    if (snprintf(p, sizeof p, "%s[%s]", path, e->name) >= (int)sizeof p) continue; /* no path that long */
    walk(L, kd->sections[e->value], def, p);
  }
}

static void walk(key_list *L, const nav_io_section *sec, const void *def, const char *prefix) {
  size_t index[64]; /* list index of each field of sec, for alt_of (sections hold at most 64) */
  for (size_t i = 0; i < sec->count; ++i) {
    const nav_io_field *f = &sec->fields[i];
    nav_schema_key *k = add_key(L);
    if (k == NULL) return;
    if (i < 64) index[i] = L->n - 1;
    snprintf(k->path, sizeof k->path, "%s%s%s", prefix, prefix[0] ? "." : "", f->key);
    k->key = f->key;
    k->type = type_of(f);
    k->unit = unit_of(f);
    k->scale = is_numeric(f->kind) && f->scale != 0.0 ? f->scale : 1.0;
    if (f->flags & NAV_IO_MIN_GT) k->bounds |= NAV_SCHEMA_MIN | NAV_SCHEMA_MIN_EXCLUSIVE;
    if (f->flags & NAV_IO_MIN_GE) k->bounds |= NAV_SCHEMA_MIN;
    if (f->flags & NAV_IO_MAX_LE) k->bounds |= NAV_SCHEMA_MAX;
    if (f->flags & NAV_IO_FINITE) k->bounds |= NAV_SCHEMA_FINITE;
    if (f->flags & NAV_IO_RANGE_LATER) k->bounds |= NAV_SCHEMA_CHECKED_IN_SI;
    k->min = f->min;
    k->max = f->max;
    for (int a = 0; a < 3; ++a) {
      k->max_axis[a] = f->max_axis != NULL ? f->max_axis[a] : f->max;
      if (k->max_axis[a] < k->max) k->max = k->max_axis[a];
    }
    k->required = (f->flags & NAV_IO_REQUIRED) != 0;
    k->doc = doc_in(sec, i);
    const nav_io_field *pref = preferred_of(sec, i);
    if (pref != NULL && (size_t)(pref - sec->fields) < 64) k->alt_of = (int)index[pref - sec->fields];
    const field_default d = default_of(f, def);
    if (d.has) {
      k->has_default = true;
      for (int c = 0; c < 3; ++c) k->default_value[c] = d.n == 1 ? d.v[0] : d.v[c];
      if (d.text != NULL || d.string)
        snprintf(k->default_text, sizeof k->default_text, "%s", d.text != NULL ? d.text : d.buf);
    }
    if (f->kind == NAV_IO_ENUM)
      for (const nav_io_enum_value *e = f->enums; e != NULL && e->name != NULL && k->n_choices < NAV_SCHEMA_MAX_CHOICES;
           ++e)
        k->choices[k->n_choices++] = e->name;
    char path[NAV_SCHEMA_PATH_MAX];
    snprintf(path, sizeof path, "%s", k->path); /* k moves when the list grows */
    if (f->kind == NAV_IO_SECTION) {
      walk(L, f->section, def, path);
    } else if (f->kind == NAV_IO_CUSTOM) {
      char p[NAV_SCHEMA_PATH_MAX];
      if (f->items != NULL && snprintf(p, sizeof p, "%s[]", path) < (int)sizeof p) walk(L, f->items, NULL, p);
      if (f->kinded != NULL) walk_kinded(L, f->kinded, f->items_kinded ? NULL : def, path);
    }
  }
}

nav_status nav_schema_keys(nav_schema_key **keys, size_t *count) {
  if (keys == NULL || count == NULL) return NAV_ERR_INVALID_ARG;
  nav_scene *def = malloc(sizeof *def);
  if (def == NULL) return NAV_ERR_NO_MEMORY;
  *def = nav_scene_default();
  key_list L = {NULL, 0, 0, false};
  walk(&L, &nav_io_scene_schema, def, "");
  free(def);
  if (L.oom) {
    free(L.keys);
    return NAV_ERR_NO_MEMORY;
  }
  *keys = L.keys;
  *count = L.n;
  return NAV_OK;
}

const nav_schema_key *nav_schema_find(const nav_schema_key *keys, size_t count, const char *path) {
  if (keys == NULL || path == NULL) return NULL;
  for (size_t i = 0; i < count; ++i)
    if (strcmp(keys[i].path, path) == 0) return &keys[i];
  return NULL;
}
