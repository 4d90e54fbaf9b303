/*
 * KML 2.2 and CSV export of geodetic tracks (nav_track_import.h).
 *
 * The KML is a plain OGC KML 2.2 document (namespace http://www.opengis.net/kml/2.2, no gx
 * extensions): one <Style> per track, lines as <LineString> with absolute heights, points as a
 * <Folder> of point <Placemark>s. Files are written to a temporary name in the same directory and
 * renamed into place.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "navcore/nav_track_import.h"
#include "scene_io_internal.h"

typedef struct atomic_file {
  char tmp[4200];
  const char *path;
  FILE *f;
} atomic_file;

static nav_status af_open(atomic_file *a, const char *path) {
  a->path = path;
  a->f = NULL;
  if (strlen(path) + 16 > sizeof a->tmp) return NAV_ERR_INVALID_ARG;
  snprintf(a->tmp, sizeof a->tmp, "%s.tmp.XXXXXX", path);
  const int fd = mkstemp(a->tmp);
  if (fd < 0) return NAV_ERR_IO;
  (void)fchmod(fd, 0644);
  a->f = fdopen(fd, "w");
  if (!a->f) {
    close(fd);
    unlink(a->tmp);
    return NAV_ERR_IO;
  }
  return NAV_OK;
}

static nav_status af_close(atomic_file *a, bool ok) {
  bool bad = !ok || ferror(a->f) != 0;
  if (fflush(a->f) != 0) bad = true;
  if (!bad && fsync(fileno(a->f)) != 0) bad = true;
  if (fclose(a->f) != 0) bad = true;
  a->f = NULL;
  if (bad || rename(a->tmp, a->path) != 0) {
    unlink(a->tmp);
    return NAV_ERR_IO;
  }
  return NAV_OK;
}

static void xml_text(FILE *f, const char *s) {
  for (; s && *s; ++s) {
    switch (*s) {
    case '&': fputs("&amp;", f); break;
    case '<': fputs("&lt;", f); break;
    case '>': fputs("&gt;", f); break;
    case '"': fputs("&quot;", f); break;
    default: fputc(*s, f);
    }
  }
}

static bool valid_color(const char *c) {
  if (!c || strlen(c) != 8) return false;
  for (int i = 0; i < 8; ++i) {
    const char x = c[i];
    if (!((x >= '0' && x <= '9') || (x >= 'a' && x <= 'f') || (x >= 'A' && x <= 'F'))) return false;
  }
  return true;
}

static void coord(FILE *f, const nav_geodetic *p) {
  fprintf(f, "%.9f,%.9f,%.4f", p->lon_rad * NAV_RAD2DEG, p->lat_rad * NAV_RAD2DEG, p->h_m);
}

nav_status nav_kml_write_file(const char *path, const char *doc_name, const nav_kml_track *tracks, size_t n_tracks,
                              size_t max_points) {
  if (!path || (!tracks && n_tracks > 0)) return NAV_ERR_INVALID_ARG;
  for (size_t k = 0; k < n_tracks; ++k) {
    if (!tracks[k].pos && tracks[k].count > 0) return NAV_ERR_INVALID_ARG;
    for (size_t i = 0; i < tracks[k].count; ++i) {
      const nav_geodetic *p = &tracks[k].pos[i];
      if (!isfinite(p->lat_rad) || !isfinite(p->lon_rad) || !isfinite(p->h_m)) return NAV_ERR_INVALID_ARG;
    }
  }
  if (max_points < 2) max_points = 2;
  atomic_file a;
  nav_status st = af_open(&a, path);
  if (st != NAV_OK) return st;
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  FILE *f = a.f;
  fputs("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\">\n<Document>\n", f);
  fputs("  <name>", f);
  xml_text(f, doc_name ? doc_name : "navsim tracks");
  fputs("</name>\n", f);
  for (size_t k = 0; k < n_tracks; ++k) {
    const nav_kml_track *t = &tracks[k];
    const char *col = valid_color(t->color_abgr) ? t->color_abgr : "ff0000ff";
    fprintf(f, "  <Style id=\"track%zu\">\n", k);
    if (t->as_points)
      fprintf(f,
              "    <IconStyle><color>%s</color><scale>0.4</scale><Icon><href>"
              "http://maps.google.com/mapfiles/kml/shapes/shaded_dot.png</href></Icon></IconStyle>\n"
              "    <LabelStyle><scale>0</scale></LabelStyle>\n",
              col);
    fprintf(f, "    <LineStyle><color>%s</color><width>%g</width></LineStyle>\n  </Style>\n", col,
            t->width > 0 && isfinite(t->width) ? t->width : 2.0);
  }
  for (size_t k = 0; k < n_tracks; ++k) {
    const nav_kml_track *t = &tracks[k];
    const size_t stride = t->count > max_points ? (t->count + max_points - 1) / max_points : 1;
    if (t->as_points) {
      fputs("  <Folder>\n    <name>", f);
      xml_text(f, t->name ? t->name : "points");
      fputs("</name>\n", f);
      for (size_t i = 0; i < t->count; i += stride) {
        fprintf(f, "    <Placemark>");
        if (t->t_s) fprintf(f, "<name>%.3f s</name>", t->t_s[i]);
        fprintf(f, "<styleUrl>#track%zu</styleUrl><Point><altitudeMode>absolute</altitudeMode><coordinates>", k);
        coord(f, &t->pos[i]);
        fputs("</coordinates></Point></Placemark>\n", f);
      }
      fputs("  </Folder>\n", f);
    } else {
      fputs("  <Placemark>\n    <name>", f);
      xml_text(f, t->name ? t->name : "track");
      fprintf(f, "</name>\n    <styleUrl>#track%zu</styleUrl>\n", k);
      fputs("    <LineString>\n      <tessellate>0</tessellate>\n      <altitudeMode>absolute</altitudeMode>\n"
            "      <coordinates>\n",
            f);
      for (size_t i = 0; i < t->count; ++i) {
        if (i % stride != 0 && i + 1 != t->count) continue;
        fputs("        ", f);
        coord(f, &t->pos[i]);
        fputc('\n', f);
      }
      fputs("      </coordinates>\n    </LineString>\n  </Placemark>\n", f);
    }
  }
  fputs("</Document>\n</kml>\n", f);
  nav_io_c_locale_end(&loc);
  return af_close(&a, true);
}

nav_status nav_tracks_csv_write_file(const char *path, const nav_kml_track *tracks, size_t n_tracks) {
  if (!path || (!tracks && n_tracks > 0)) return NAV_ERR_INVALID_ARG;
  atomic_file a;
  nav_status st = af_open(&a, path);
  if (st != NAV_OK) return st;
  nav_io_c_locale loc;
  nav_io_c_locale_begin(&loc);
  FILE *f = a.f;
  fputs("track,t_s,lat_deg,lon_deg,h_m\n", f);
  for (size_t k = 0; k < n_tracks; ++k) {
    const nav_kml_track *t = &tracks[k];
    for (size_t i = 0; i < t->count; ++i) {
      fputc('"', f);
      for (const char *s = t->name ? t->name : ""; *s; ++s) {
        if (*s == '"') fputc('"', f);
        fputc(*s, f);
      }
      fprintf(f, "\",%.17g,%.12f,%.12f,%.6f\n", t->t_s ? t->t_s[i] : (double)i, t->pos[i].lat_rad * NAV_RAD2DEG,
              t->pos[i].lon_rad * NAV_RAD2DEG, t->pos[i].h_m);
    }
  }
  nav_io_c_locale_end(&loc);
  return af_close(&a, true);
}
