/*
 * Scene files: the writer. It walks the schema tables of scene_read.c, so every field the reader
 * knows is written, explicitly, under its preferred key (the spelling of the canonical example:
 * degrees for lat/lon and Euler angles, radians and rad/s for the parametric phases and rates).
 *
 * Round trips are bit-exact: numbers are printed with the fewest digits (15..17) that read back
 * to the same double, and a quantity whose preferred key is in degrees is written in degrees only
 * when some decimal degree value converts back (deg * pi/180, exactly as the reader does it) to
 * the same radians; otherwise it is written under its _rad spelling, which the reader accepts too.
 *
 * The file is replaced atomically: PATH.tmp.XXXXXX (mkstemp, same directory), fflush + fsync,
 * rename over PATH, then fsync of the directory (best effort).
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <math.h>
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

static const double *double_at(const nav_scene *s, const nav_io_field *f) {
  return (const double *)((const char *)s + f->offset);
}

/* The spelling of field @p i of @p sec to write: the preferred one if it is exact, else the SI
   spelling of the same quantity (scale 1). */
static const nav_io_field *choose_spelling(const nav_io_section *sec, size_t i, const nav_scene *s) {
  const nav_io_field *f = &sec->fields[i];
  if ((f->kind != NAV_IO_DOUBLE && f->kind != NAV_IO_VEC3) || f->scale == 1.0) return f;
  double si[3] = {0.0, 0.0, 0.0};
  size_t n = 1;
  if (f->kind == NAV_IO_VEC3) {
    const nav_vec3 *p = (const nav_vec3 *)((const char *)s + f->offset);
    si[0] = p->x;
    si[1] = p->y;
    si[2] = p->z;
    n = 3;
  } else {
    si[0] = *double_at(s, f);
  }
  double v = 0.0;
  bool exact = true;
  for (size_t k = 0; k < n; ++k)
    if (!exact_file_value(si[k], f->scale, &v)) exact = false;
  if (exact) return f;
  for (size_t j = 0; j < sec->count; ++j) {
    const nav_io_field *g = &sec->fields[j];
    if (g->kind == f->kind && g->offset == f->offset && g->scale == 1.0) return g;
  }
  return f; /* no SI spelling in the table: closest decimal value */
}

static int write_number(FILE *fp, double si, double scale) {
  char buf[40];
  double v = si;
  if (!exact_file_value(si, scale, &v)) v = si / scale;
  return fputs(nav_io_format_double(buf, sizeof buf, v), fp) < 0 ? -1 : 0;
}

/* A YAML double-quoted string; control characters are escaped. */
static int write_quoted(FILE *fp, const char *s) {
  if (fputc('"', fp) == EOF) return -1;
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
    if (rc < 0) return -1;
  }
  return fputc('"', fp) == EOF ? -1 : 0;
}

/* The value of a non-section field (the text after "key: "). */
static nav_status write_value(FILE *fp, const nav_io_field *f, const nav_scene *s) {
  const char *base = (const char *)s;
  int rc = 0;
  switch (f->kind) {
  case NAV_IO_SECTION: return NAV_ERR_INVALID_ARG;
  case NAV_IO_DOUBLE: rc = write_number(fp, *double_at(s, f), f->scale); break;
  case NAV_IO_VEC3: {
    const nav_vec3 *v = (const nav_vec3 *)(base + f->offset);
    rc = fputc('[', fp) == EOF ? -1 : 0;
    if (rc == 0) rc = write_number(fp, v->x, f->scale);
    if (rc == 0) rc = fputs(", ", fp) < 0 ? -1 : 0;
    if (rc == 0) rc = write_number(fp, v->y, f->scale);
    if (rc == 0) rc = fputs(", ", fp) < 0 ? -1 : 0;
    if (rc == 0) rc = write_number(fp, v->z, f->scale);
    if (rc == 0) rc = fputc(']', fp) == EOF ? -1 : 0;
    break;
  }
  case NAV_IO_INT: rc = fprintf(fp, "%d", *(const int *)(base + f->offset)); break;
  case NAV_IO_LONG: rc = fprintf(fp, "%ld", *(const long *)(base + f->offset)); break;
  case NAV_IO_U64: rc = fprintf(fp, "%" PRIu64, *(const uint64_t *)(base + f->offset)); break;
  case NAV_IO_ENUM: {
    const int value = *(const int *)(base + f->offset);
    const char *name = NULL;
    for (size_t i = 0; f->enums[i].name != NULL; ++i)
      if (f->enums[i].value == value) name = f->enums[i].name;
    if (name == NULL) return NAV_ERR_INVALID_ARG; /* not a value of the enum: nothing to write */
    rc = fputs(name, fp);
    break;
  }
  case NAV_IO_STRING: {
    const char *str = base + f->offset;
    if (memchr(str, '\0', f->size) == NULL) return NAV_ERR_INVALID_ARG;
    rc = write_quoted(fp, str);
    break;
  }
  case NAV_IO_CUSTOM: rc = f->write(fp, f, s); break;
  }
  return rc < 0 ? NAV_ERR_IO : NAV_OK;
}

/* "  # a | b" after an enum, or the descriptor's comment. */
static nav_status write_comment(FILE *fp, const nav_io_field *f) {
  int rc = 0;
  if (f->comment != NULL) {
    rc = fprintf(fp, "  # %s", f->comment);
  } else if (f->kind == NAV_IO_ENUM && f->enums[0].name != NULL && f->enums[1].name != NULL) {
    rc = fputs("  #", fp);
    for (size_t i = 0; rc >= 0 && f->enums[i].name != NULL; ++i)
      rc = fprintf(fp, "%s %s", i ? " |" : "", f->enums[i].name);
  }
  return rc < 0 ? NAV_ERR_IO : NAV_OK;
}

static nav_status write_section(FILE *fp, const nav_io_section *sec, const nav_scene *s, int indent) {
  nav_status st = NAV_OK;
  for (size_t i = 0; i < sec->count && st == NAV_OK; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (f->flags & NAV_IO_ALT) continue;
    if (f->kind == NAV_IO_SECTION && indent == 0 && fputc('\n', fp) == EOF) return NAV_ERR_IO;
    if (f->kind == NAV_IO_SECTION && (f->flags & NAV_IO_FLOW)) {
      /* {a: 1, b: 2} on one line, as in the canonical example. */
      if (fprintf(fp, "%*s%s: {", indent, "", f->key) < 0) return NAV_ERR_IO;
      bool first = true;
      for (size_t j = 0; j < f->section->count && st == NAV_OK; ++j) {
        if (f->section->fields[j].flags & NAV_IO_ALT) continue;
        const nav_io_field *g = choose_spelling(f->section, j, s);
        if (fprintf(fp, "%s%s: ", first ? "" : ", ", g->key) < 0) return NAV_ERR_IO;
        st = write_value(fp, g, s);
        first = false;
      }
      if (st == NAV_OK && fputs("}\n", fp) < 0) return NAV_ERR_IO;
    } else if (f->kind == NAV_IO_SECTION) {
      if (fprintf(fp, "%*s%s:\n", indent, "", f->key) < 0) return NAV_ERR_IO;
      st = write_section(fp, f->section, s, indent + 2);
    } else {
      const nav_io_field *g = choose_spelling(sec, i, s);
      if (fprintf(fp, "%*s%s: ", indent, "", g->key) < 0) return NAV_ERR_IO;
      st = write_value(fp, g, s);
      if (st == NAV_OK) st = write_comment(fp, f);
      if (st == NAV_OK && fputc('\n', fp) == EOF) st = NAV_ERR_IO;
    }
  }
  return st;
}

static nav_status write_scene(FILE *fp, const nav_scene *scene) {
  if (fprintf(fp,
              "# navcore scene file, format_version %d, written by navcore_io.\n"
              "# Units are part of the key names (_deg, _rad, _rps, _hz, _m, _mps, _s ...).\n",
              NAV_SCENE_FORMAT_VERSION) < 0)
    return NAV_ERR_IO;
  return write_section(fp, &nav_io_scene_schema, scene, 0);
}

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

  if (path == NULL || scene == NULL || path[0] == '\0') return NAV_ERR_INVALID_ARG;
  const size_t len = strlen(path);
  tmp = malloc(len + sizeof ".tmp.XXXXXX");
  if (tmp == NULL) return NAV_ERR_NO_MEMORY;
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
  st = write_scene(fp, scene);
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
  return st;
}
