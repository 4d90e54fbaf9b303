/*
 * Scene files: the writer. It walks the schema tables of scene_read.c and scene_traj_io.c, so
 * every field the reader knows is written, explicitly, under one of its keys: the shortest exact
 * spelling among the preferred one (the spelling of the canonical example: degrees for lat/lon
 * and Euler angles, datasheet units for sensor figures), the SI one, and the alternatives marked
 * NAV_IO_WRITE_ALT (rpm for a spin rate, Hz for a coning rate).
 *
 * Round trips are bit-exact: numbers are printed with the fewest digits (15..17) that read back
 * to the same double, and a quantity is written in a unit other than SI only when some decimal
 * value converts back (value * scale, exactly as the reader does it) to the same bits; otherwise
 * its SI spelling is used, which the reader accepts too. Inputs that have no place in the scene
 * (bias instability and Allan-minimum time, waypoints in latitude/longitude, the motion-definition
 * file) are written as what they became: the Gauss-Markov bias, local NED waypoints, the segment
 * script. What is written is what is read back:
 * - error-model terms: a term's keys when the term is on or its values differ from the defaults,
 *   and an "off" list for terms that are off but have values (or may be switched on by a catalog
 *   part, which the reader loads first);
 * - sections of unused trajectory types, and the gnss section, only when they differ from the
 *   defaults (a scene keeps the parameters of a type it does not use);
 * - in kind-dependent mappings (segments, test motions) the keys of the selected kind only.
 *
 * The file is replaced atomically: PATH.tmp.XXXXXX (mkstemp, same directory), fflush + fsync,
 * rename over PATH, then fsync of the directory (best effort).
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "navcore/nav_io.h"
#include "scene_io_internal.h"

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

/* A file value v with v * scale == si bit for bit (the reader's conversion), choosing the one
   with the shortest text among the doubles next to si / scale. */
static bool exact_file_value(double si, double scale, double *out) {
  if (!isfinite(si) || scale == 1.0) {
    *out = si;
    return true;
  }
  const double v0 = si / scale;
  double cand[5] = {v0, nextafter(v0, INFINITY), nextafter(v0, -INFINITY), 0.0, 0.0};
  cand[3] = nextafter(cand[1], INFINITY);
  cand[4] = nextafter(cand[2], -INFINITY);
  bool found = false;
  size_t best_len = 0;
  char buf[40];
  for (size_t i = 0; i < 5; ++i) {
    if (!same_bits(cand[i] * scale, si)) continue;
    const size_t len = strlen(nav_io_format_double(buf, sizeof buf, cand[i]));
    if (!found || len < best_len) {
      found = true;
      best_len = len;
      *out = cand[i];
    }
  }
  return found;
}

/* ================================================================ output primitives */

nav_status nav_io_writef(nav_io_writer *w, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  const int rc = vfprintf(w->fp, fmt, ap);
  va_end(ap);
  return rc < 0 ? NAV_ERR_IO : NAV_OK;
}

nav_status nav_io_write_double(nav_io_writer *w, double v) {
  char buf[40];
  return fputs(nav_io_format_double(buf, sizeof buf, v), w->fp) < 0 ? NAV_ERR_IO : NAV_OK;
}

/* A YAML double-quoted string; control characters are escaped. */
nav_status nav_io_write_quoted(nav_io_writer *w, const char *s) {
  FILE *fp = w->fp;
  if (fputc('"', fp) == EOF) return NAV_ERR_IO;
  for (const unsigned char *c = (const unsigned char *)s; *c != '\0'; ++c) {
    int rc = 0;
    if (*c == '"' || *c == '\\')
      rc = fprintf(fp, "\\%c", *c);
    else if (*c == '\n')
      rc = fputs("\\n", fp);
    else if (*c == '\t')
      rc = fputs("\\t", fp);
    else if (*c < 0x20 || *c == 0x7f)
      rc = fprintf(fp, "\\x%02x", *c);
    else
      rc = fputc(*c, fp);
    if (rc < 0) return NAV_ERR_IO;
  }
  return fputc('"', fp) == EOF ? NAV_ERR_IO : NAV_OK;
}

/* ================================================================ numbers in some unit */

/* A small text buffer for one value, so spellings can be compared by length before writing. */
typedef struct text_buf {
  char s[1024];
  size_t n;
  bool exact; /* every number read back gives the stored bits */
} text_buf;

static void put(text_buf *t, const char *s) {
  const size_t l = strlen(s);
  if (t->n + l < sizeof t->s) {
    memcpy(t->s + t->n, s, l + 1);
    t->n += l;
  }
}

static void put_number(text_buf *t, double si, double scale) {
  char buf[40];
  double v = si;
  if (!exact_file_value(si, scale, &v)) {
    v = si / scale;
    t->exact = false;
  }
  put(t, nav_io_format_double(buf, sizeof buf, v));
}

static void put_numbers(text_buf *t, const double *si, size_t n, double scale) {
  put(t, "[");
  for (size_t i = 0; i < n; ++i) {
    if (i) put(t, ", ");
    put_number(t, si[i], scale);
  }
  put(t, "]");
}

static bool all_same(const double *x, const size_t *idx, size_t n) {
  for (size_t i = 1; i < n; ++i)
    if (!same_bits(x[idx[i]], x[idx[0]])) return false;
  return true;
}

static bool all_zero(const double *x, const size_t *idx, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!same_bits(x[idx[i]], 0.0)) return false;
  return true;
}

/* The value of numeric field @p f of @p base in the unit of @p f, in its shortest form: a vector
   with three equal elements as one number, a matrix as one number, its diagonal or 3 rows. */
static void format_numeric(text_buf *t, const nav_io_field *f, const void *base) {
  const char *p = (const char *)base + f->offset;
  static const size_t k_diag[3] = {0, 4, 8}, k_off[6] = {1, 2, 3, 5, 6, 7}, k_vec[3] = {0, 1, 2};
  double x[9];
  t->n = 0;
  t->s[0] = '\0';
  t->exact = true;
  switch (f->kind) {
  case NAV_IO_DOUBLE: put_number(t, *(const double *)p, f->scale); return;
  case NAV_IO_VEC3:
  case NAV_IO_VEC3S: {
    const nav_vec3 *v = (const nav_vec3 *)p;
    x[0] = v->x;
    x[1] = v->y;
    x[2] = v->z;
    if (f->kind == NAV_IO_VEC3S && all_same(x, k_vec, 3))
      put_number(t, x[0], f->scale);
    else
      put_numbers(t, x, 3, f->scale);
    return;
  }
  case NAV_IO_MAT3_OFFDIAG:
  case NAV_IO_MAT3_DIAG: {
    const nav_mat3 *m = (const nav_mat3 *)p;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        x[3 * i + j] = m->m[i][j];
    if (f->kind == NAV_IO_MAT3_OFFDIAG && all_zero(x, k_diag, 3) && all_same(x, k_off, 6)) {
      put_number(t, x[1], f->scale);
    } else if (f->kind == NAV_IO_MAT3_DIAG && all_zero(x, k_off, 6)) {
      if (all_same(x, k_diag, 3)) {
        put_number(t, x[0], f->scale);
      } else {
        const double d[3] = {x[0], x[4], x[8]};
        put_numbers(t, d, 3, f->scale);
      }
    } else {
      put(t, "[");
      for (int i = 0; i < 3; ++i) {
        if (i) put(t, ", ");
        put_numbers(t, x + 3 * i, 3, f->scale);
      }
      put(t, "]");
    }
    return;
  }
  default: return;
  }
}

static bool is_numeric(nav_io_kind k) {
  return k == NAV_IO_DOUBLE || k == NAV_IO_VEC3 || k == NAV_IO_VEC3S || k == NAV_IO_MAT3_OFFDIAG ||
         k == NAV_IO_MAT3_DIAG;
}

/* The spelling of field @p i of @p sec to write and its text: the shortest exact one among the
   preferred spelling, the SI one and the NAV_IO_WRITE_ALT ones (ties: the earlier in the table). */
static const nav_io_field *choose_spelling(const nav_io_section *sec, size_t i, const void *base,
                                           text_buf *out) {
  const nav_io_field *f = &sec->fields[i];
  format_numeric(out, f, base);
  if (f->scale == 1.0 && out->exact) return f;
  const nav_io_field *best = out->exact ? f : NULL;
  text_buf cand;
  for (size_t j = i + 1; j < sec->count; ++j) {
    const nav_io_field *g = &sec->fields[j];
    if (!(g->flags & NAV_IO_ALT) || g->kind != f->kind || g->offset != f->offset ||
        (g->flags & NAV_IO_STATE) != (f->flags & NAV_IO_STATE))
      continue;
    if (g->scale != 1.0 && !(g->flags & NAV_IO_WRITE_ALT)) continue;
    format_numeric(&cand, g, base);
    if (!cand.exact) continue;
    if (best == NULL || cand.n < out->n) {
      best = g;
      *out = cand;
    }
  }
  if (best != NULL) return best;
  format_numeric(out, f, base); /* no SI spelling in the table: the closest decimal value */
  return f;
}

/* ================================================================ comparing with the defaults */

bool nav_io_field_same(const nav_io_field *f, const void *a, const void *b) {
  if (f->flags & (NAV_IO_ALT | NAV_IO_STATE)) return true;
  const char *pa = (const char *)a + f->offset, *pb = (const char *)b + f->offset;
  size_t n = 0;
  switch (f->kind) {
  case NAV_IO_SECTION: return nav_io_section_same(f->section, a, b);
  case NAV_IO_DOUBLE: n = 1; break;
  case NAV_IO_VEC3:
  case NAV_IO_VEC3S: n = 3; break;
  case NAV_IO_MAT3_OFFDIAG:
  case NAV_IO_MAT3_DIAG: n = 9; break;
  case NAV_IO_INT:
  case NAV_IO_ENUM: return *(const int *)pa == *(const int *)pb;
  case NAV_IO_LONG: return *(const long *)pa == *(const long *)pb;
  case NAV_IO_U64: return *(const uint64_t *)pa == *(const uint64_t *)pb;
  case NAV_IO_BOOL: return *(const bool *)pa == *(const bool *)pb;
  case NAV_IO_STRING: return strncmp(pa, pb, f->size) == 0;
  case NAV_IO_CUSTOM: return f->same != NULL && f->same(f, a, b);
  }
  /* Doubles of nav_vec3 / nav_mat3 are contiguous (both are plain arrays of double). */
  for (size_t i = 0; i < n; ++i) {
    double x, y;
    memcpy(&x, pa + i * sizeof(double), sizeof x);
    memcpy(&y, pb + i * sizeof(double), sizeof y);
    if (!same_bits(x, y)) return false;
  }
  return true;
}

bool nav_io_section_same(const nav_io_section *sec, const void *a, const void *b) {
  for (size_t i = 0; i < sec->count; ++i)
    if (!nav_io_field_same(&sec->fields[i], a, b)) return false;
  return true;
}

/*
 * Whether field @p i of @p sec is written. A field of an error-model term (bit != 0) is written
 * when its value differs from the default; a term that is on with every value at its default
 * is written through its first field, so that reading switches it on again.
 */
static bool written(const nav_io_writer *w, const nav_io_section *sec, size_t i, const void *base,
                    const void *def) {
  const nav_io_field *f = &sec->fields[i];
  if (f->flags & (NAV_IO_ALT | NAV_IO_STATE)) return false;
  if (f->kind == NAV_IO_CUSTOM && f->write == NULL) return false;
  if (f->write_if != NULL) return f->write_if(w, f, base, def);
  if (f->bit == 0) return true;
  if (!nav_io_field_same(f, base, def)) return true;
  const unsigned terms = *(const unsigned *)((const char *)base + f->bits_offset);
  if (!(terms & f->bit)) return false;
  size_t first = sec->count;
  for (size_t j = 0; j < sec->count; ++j) {
    const nav_io_field *g = &sec->fields[j];
    if (g->bit != f->bit || g->bits_offset != f->bits_offset || (g->flags & (NAV_IO_ALT | NAV_IO_STATE)))
      continue;
    if (!nav_io_field_same(g, base, def)) return false; /* the term is written through that one */
    if (first == sec->count) first = j;
  }
  return first == i;
}

/* Whether writing @p sec would write anything. */
static bool section_has_output(const nav_io_writer *w, const nav_io_section *sec, const void *base,
                               const void *def) {
  for (size_t i = 0; i < sec->count; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (!written(w, sec, i, base, def)) continue;
    if (f->kind != NAV_IO_SECTION || (f->flags & NAV_IO_FLOW) || section_has_output(w, f->section, base, def))
      return true;
  }
  return false;
}

/* ================================================================ values and sections */

/* The value of a non-section, non-custom field chosen by choose_spelling (the text after "key: "). */
static nav_status write_scalar(nav_io_writer *w, const nav_io_field *f, const void *base) {
  const char *p = (const char *)base + f->offset;
  switch (f->kind) {
  case NAV_IO_INT: return nav_io_writef(w, "%d", *(const int *)p);
  case NAV_IO_LONG: return nav_io_writef(w, "%ld", *(const long *)p);
  case NAV_IO_U64: return nav_io_writef(w, "%" PRIu64, *(const uint64_t *)p);
  case NAV_IO_BOOL: return nav_io_writef(w, "%s", *(const bool *)p ? "true" : "false");
  case NAV_IO_ENUM: {
    const int value = *(const int *)p;
    const char *name = NULL;
    for (size_t i = 0; f->enums[i].name != NULL; ++i)
      if (f->enums[i].value == value) name = f->enums[i].name;
    if (name == NULL) return NAV_ERR_INVALID_ARG; /* not a value of the enum: nothing to write */
    return nav_io_writef(w, "%s", name);
  }
  case NAV_IO_STRING:
    if (memchr(p, '\0', f->size) == NULL) return NAV_ERR_INVALID_ARG;
    return nav_io_write_quoted(w, p);
  default: return NAV_ERR_INVALID_ARG;
  }
}

/* "key: value" of a non-section field (no newline). */
static nav_status write_entry(nav_io_writer *w, const nav_io_section *sec, size_t i, const void *base,
                              int indent) {
  const nav_io_field *f = &sec->fields[i];
  if (f->kind == NAV_IO_CUSTOM) {
    const nav_status st = nav_io_writef(w, "%s:", f->key);
    return st != NAV_OK ? st : f->write(w, f, base, indent);
  }
  if (is_numeric(f->kind)) {
    text_buf t;
    const nav_io_field *g = choose_spelling(sec, i, base, &t);
    return nav_io_writef(w, "%s: %s", g->key, t.s);
  }
  const nav_status st = nav_io_writef(w, "%s: ", f->key);
  return st != NAV_OK ? st : write_scalar(w, f, base);
}

/* "  # a | b" after an enum, or the descriptor's comment. */
static nav_status write_comment(nav_io_writer *w, const nav_io_field *f) {
  nav_status st = NAV_OK;
  if (f->comment != NULL) {
    st = nav_io_writef(w, "  # %s", f->comment);
  } else if (f->kind == NAV_IO_ENUM && f->enums[0].name != NULL && f->enums[1].name != NULL) {
    st = nav_io_writef(w, "  #");
    for (size_t i = 0; st == NAV_OK && f->enums[i].name != NULL; ++i)
      st = nav_io_writef(w, "%s %s", i ? " |" : "", f->enums[i].name);
  }
  return st;
}

nav_status nav_io_write_flow(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def) {
  nav_status st = nav_io_writef(w, "{");
  bool first = true;
  for (size_t i = 0; i < sec->count && st == NAV_OK; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (!written(w, sec, i, base, def)) continue;
    st = nav_io_writef(w, "%s", first ? "" : ", ");
    first = false;
    if (st != NAV_OK) break;
    if (f->kind == NAV_IO_SECTION) {
      st = nav_io_writef(w, "%s: ", f->key);
      if (st == NAV_OK) st = nav_io_write_flow(w, f->section, base, def);
    } else {
      st = write_entry(w, sec, i, base, 0);
    }
  }
  return st != NAV_OK ? st : nav_io_writef(w, "}");
}

/* Each field on its own line: "key: value\n" (lead = false), or "\nkey: value" (lead = true, for
   custom values, which end without a newline). */
static nav_status write_lines(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def,
                              int indent, bool lead) {
  nav_status st = NAV_OK;
  for (size_t i = 0; i < sec->count && st == NAV_OK; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (!written(w, sec, i, base, def)) continue;
    if (f->kind == NAV_IO_SECTION && !(f->flags & NAV_IO_FLOW) &&
        !section_has_output(w, f->section, base, def))
      continue; /* e.g. imu.gyro of a perfect IMU */
    if (f->kind == NAV_IO_SECTION && indent == 0 && !lead) st = nav_io_writef(w, "\n");
    if (st == NAV_OK) st = nav_io_writef(w, "%s%*s", lead ? "\n" : "", indent, "");
    if (st != NAV_OK) break;
    if (f->kind == NAV_IO_SECTION && (f->flags & NAV_IO_FLOW)) {
      /* {a: 1, b: 2} on one line, as in the canonical example. */
      st = nav_io_writef(w, "%s: ", f->key);
      if (st == NAV_OK) st = nav_io_write_flow(w, f->section, base, def);
      if (st == NAV_OK && !lead) st = nav_io_writef(w, "\n");
    } else if (f->kind == NAV_IO_SECTION) {
      st = nav_io_writef(w, "%s:%s", f->key, lead ? "" : "\n");
      if (st == NAV_OK) st = write_lines(w, f->section, base, def, indent + 2, lead);
    } else {
      st = write_entry(w, sec, i, base, indent);
      if (st == NAV_OK) st = write_comment(w, f);
      if (st == NAV_OK && !lead) st = nav_io_writef(w, "\n");
    }
  }
  return st;
}

nav_status nav_io_write_block(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def,
                              int indent) {
  return write_lines(w, sec, base, def, indent, false);
}

nav_status nav_io_write_lines(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def,
                              int indent) {
  return write_lines(w, sec, base, def, indent, true);
}

static nav_status write_scene(FILE *fp, const nav_scene *scene, const nav_scene *def) {
  nav_io_writer w = {fp, scene, def};
  const nav_status st =
      nav_io_writef(&w,
                    "# navcore scene file, format_version %d, written by navcore_io.\n"
                    "# Units are part of the key names (_deg, _rad, _rps, _hz, _m, _mps, _s ...).\n",
                    NAV_SCENE_FORMAT_VERSION);
  return st != NAV_OK ? st : nav_io_write_block(&w, &nav_io_scene_schema, scene, def, 0);
}

nav_status nav_scene_write_string(const nav_scene *scene, char **text, size_t *len) {
  if (scene == NULL || text == NULL) return NAV_ERR_INVALID_ARG;
  *text = NULL;
  if (len != NULL) *len = 0;
  char *buf = NULL;
  size_t n = 0;
  nav_scene *def = malloc(sizeof *def); /* a scene is a few hundred kB: not on the stack */
  FILE *fp = def != NULL ? open_memstream(&buf, &n) : NULL;
  if (fp == NULL) {
    free(def);
    return NAV_ERR_NO_MEMORY;
  }
  *def = nav_scene_default();
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  nav_status st = write_scene(fp, scene, def);
  nav_io_c_locale_end(&loc);
  if (fclose(fp) != 0 && st == NAV_OK) st = NAV_ERR_NO_MEMORY;
  free(def);
  if (st != NAV_OK) {
    free(buf);
    return st;
  }
  *text = buf;
  if (len != NULL) *len = n;
  return NAV_OK;
}

/* ================================================================ the file */

/* fsync the directory holding @p path, so the rename itself survives a crash (best effort:
   some file systems refuse fsync on directories). */
static void sync_parent_dir(const char *path) {
  const char *slash = strrchr(path, '/');
  char *dir = NULL;
  if (slash == NULL)
    dir = strdup(".");
  else if (slash == path)
    dir = strdup("/");
  else {
    dir = malloc((size_t)(slash - path) + 1);
    if (dir != NULL) {
      memcpy(dir, path, (size_t)(slash - path));
      dir[slash - path] = '\0';
    }
  }
  if (dir == NULL) return;
  const int fd = open(dir, O_RDONLY | O_DIRECTORY);
  if (fd >= 0) {
    (void)fsync(fd);
    close(fd);
  }
  free(dir);
}

nav_status nav_scene_write_file(const char *path, const nav_scene *scene) {
  nav_status st = NAV_OK;
  char *tmp = NULL;
  int fd = -1;
  FILE *fp = NULL;
  bool tmp_exists = false;
  nav_io_c_locale loc;
  bool locale_set = false;
  nav_scene *def = NULL;

  if (path == NULL || scene == NULL || path[0] == '\0') return NAV_ERR_INVALID_ARG;
  const size_t len = strlen(path);
  tmp = malloc(len + sizeof ".tmp.XXXXXX");
  def = malloc(sizeof *def); /* a scene is a few hundred kB: not on the stack */
  if (tmp == NULL || def == NULL) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  *def = nav_scene_default();
  memcpy(tmp, path, len);
  memcpy(tmp + len, ".tmp.XXXXXX", sizeof ".tmp.XXXXXX");

  fd = mkstemp(tmp);
  if (fd < 0) {
    st = NAV_ERR_IO;
    goto cleanup;
  }
  tmp_exists = true;
  /* mkstemp creates 0600; keep the mode of the file being replaced, else use rw-r--r--. */
  struct stat sb;
  const mode_t mode = stat(path, &sb) == 0 ? (sb.st_mode & 07777) : 0644;
  if (fchmod(fd, mode) != 0) {
    st = NAV_ERR_IO;
    goto cleanup;
  }
  fp = fdopen(fd, "w");
  if (fp == NULL) {
    st = NAV_ERR_IO;
    goto cleanup;
  }
  fd = -1; /* owned by fp now */

  nav_io_c_locale_begin(&loc);
  locale_set = true;
  st = write_scene(fp, scene, def);
  nav_io_c_locale_end(&loc);
  locale_set = false;
  if (st != NAV_OK) goto cleanup;

  if (fflush(fp) != 0 || ferror(fp) || fsync(fileno(fp)) != 0) {
    st = NAV_ERR_IO;
    goto cleanup;
  }
  const int rc = fclose(fp);
  fp = NULL;
  if (rc != 0 || rename(tmp, path) != 0) {
    st = NAV_ERR_IO;
    goto cleanup;
  }
  tmp_exists = false;
  sync_parent_dir(path);

cleanup:
  if (locale_set) nav_io_c_locale_end(&loc);
  if (fp != NULL) fclose(fp);
  if (fd >= 0) close(fd);
  if (tmp_exists) unlink(tmp);
  free(tmp);
  free(def);
  return st;
}
