/* Scene section gnss.constellation (issue 22): systems, epoch, almanac file, elevation mask,
 * per-azimuth sky mask and street canyons; read, validated (FILE:LINE:COL) and written.
 * The almanac file is read here (navcore_io), relative to the scene file. */
#define _POSIX_C_SOURCE 200809L /* realpath, locale_t */
#define _DEFAULT_SOURCE

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navcore/nav_gnss_almanac.h"
#include "navcore/nav_gnss_sat.h"
#include "scene_io_internal.h"

#define OFF(member) offsetof(nav_scene, member)
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))
#define C(m) gnss.constellation.m
#define KOFF(m) offsetof(nav_gnss_canyon, m)
#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

static const nav_io_enum_value k_gps_sources[] = {
    {"off", NAV_GNSS_SOURCE_OFF}, {"nominal", NAV_GNSS_SOURCE_NOMINAL}, {"almanac", NAV_GNSS_SOURCE_ALMANAC}, {NULL, 0}};
static const nav_io_enum_value k_glo_sources[] = {
    {"off", NAV_GNSS_SOURCE_OFF}, {"nominal", NAV_GNSS_SOURCE_NOMINAL}, {NULL, 0}};

static const nav_io_enum_value k_fix_sources[] = {
    {"model", NAV_GNSS_FIXES_MODEL}, {"pvt", NAV_GNSS_FIXES_PVT}, {NULL, 0}};

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

/* ---------------------------------------------------------------- epoch: "YYYY-MM-DDTHH:MM:SS[.f]" (GPS time) */

static void read_epoch(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                       void *base) {
  double *t = (double *)((char *)base + f->offset);
  if (nav_io_reject_special(r, key, v)) return;
  size_t len = 0;
  const char *s = nav_io_node_text(v, &len);
  char buf[64];
  int y, mo, d, h, mi, used = 0;
  double sec;
  if (s == NULL || len == 0 || len >= sizeof buf) {
    nav_io_expected(r, key, v, "a GPS-time date \"YYYY-MM-DDTHH:MM:SS\"");
    return;
  }
  memcpy(buf, s, len);
  buf[len] = '\0';
  if (sscanf(buf, "%4d-%2d-%2dT%2d:%2d:%lf%n", &y, &mo, &d, &h, &mi, &sec, &used) != 6 || (size_t)used != len) {
    nav_io_expected(r, key, v, "a GPS-time date \"YYYY-MM-DDTHH:MM:SS\"");
    return;
  }
  static const int mdays[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  if (y < 1900 || y >= 2180 || mo < 1 || mo > 12 || d < 1 || d > mdays[mo - 1] || (mo == 2 && d == 29 && !leap) ||
      h < 0 || h > 23 || mi < 0 || mi > 59 || !(sec >= 0.0 && sec < 60.0)) {
    nav_io_reader_error(r, v, key, "not a valid date and time between 1900 and 2179 (got \"%s\")", buf);
    return;
  }
  *t = nav_gnss_gps_time_s(y, mo, d, h, mi, sec);
}

static nav_status write_epoch(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)indent;
  const double t = *(const double *)((const char *)base + f->offset);
  /* civil date of day number (H. Hinnant's civil_from_days), days from 1970-01-01 */
  const double days_f = floor(t / 86400.0);
  double sod = t - days_f * 86400.0;
  const long z = (long)days_f + 3657 + 719468; /* 1980-01-06 is day 3657 */
  const long era = (z >= 0 ? z : z - 146096) / 146097;
  const long doe = z - era * 146097;
  const long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
  const long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
  const long mp = (5 * doy + 2) / 153;
  const long d = doy - (153 * mp + 2) / 5 + 1;
  const long mo = mp < 10 ? mp + 3 : mp - 9;
  const long y = yoe + era * 400 + (mo <= 2);
  const int h = (int)(sod / 3600.0);
  sod -= h * 3600.0;
  const int mi = (int)(sod / 60.0);
  sod -= mi * 60.0;
  char buf[512];
  if (sod == floor(sod)) {
    snprintf(buf, sizeof buf, "%04ld-%02ld-%02ldT%02d:%02d:%02d", y, mo, d, h, mi, (int)sod);
  } else {
    snprintf(buf, sizeof buf, "%04ld-%02ld-%02ldT%02d:%02d:%012.9f", y, mo, d, h, mi, sod);
  }
  return nav_io_writef(w, " \"%s\"", buf);
}

static bool same_epoch(const nav_io_field *f, const void *a, const void *b) {
  return same_bits(*(const double *)((const char *)a + f->offset), *(const double *)((const char *)b + f->offset));
}

/* ---------------------------------------------------------------- sky_mask_deg: [[az_deg, el_deg], ...] */

static void read_sky_mask(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                          void *base) {
  nav_gnss_sky_mask *m = (nav_gnss_sky_mask *)((char *)base + f->offset);
  if (nav_io_reject_special(r, key, v)) return;
  if (!nav_io_node_is_seq(v)) {
    nav_io_expected(r, key, v, "a list of [azimuth_deg, elevation_deg] points, azimuths increasing");
    return;
  }
  const size_t n = nav_io_node_count(v);
  if (n > NAV_GNSS_MASK_MAX_POINTS) {
    nav_io_reader_error(r, v, key, "at most %d points are supported (got %zu)", NAV_GNSS_MASK_MAX_POINTS, n);
    return;
  }
  const nav_io_field az_f = {.key = "azimuth_deg", .kind = NAV_IO_DOUBLE, .flags = NAV_IO_FINITE | NAV_IO_MIN_GE,
                             .scale = 1.0, .min = 0.0};
  const nav_io_field el_f = {.key = "elevation_deg", .kind = NAV_IO_DOUBLE,
                             .flags = NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE, .scale = 1.0, .min = 0.0,
                             .max = 90.0};
  double az[NAV_GNSS_MASK_MAX_POINTS], el[NAV_GNSS_MASK_MAX_POINTS];
  bool ok = true;
  size_t i = 0;
  for (const nav_io_node *item = nav_io_node_child(v); item != NULL; item = nav_io_node_next(item), ++i) {
    const size_t saved = nav_io_path_push_index(r, i);
    nav_io_mark(r, item, v);
    if (nav_io_reject_special(r, v, item)) {
      ok = false;
    } else if (!nav_io_node_is_seq(item) || nav_io_node_count(item) != 2) {
      nav_io_expected(r, v, item, "[azimuth_deg, elevation_deg]");
      ok = false;
    } else {
      const nav_io_node *a = nav_io_node_child(item), *e = nav_io_node_next(a);
      double x = 0.0, yv = 0.0;
      const bool ga = nav_io_read_number(r, item, a, &x) && nav_io_check_number(r, &az_f, item, a, x);
      const bool ge = nav_io_read_number(r, item, e, &yv) && nav_io_check_number(r, &el_f, item, e, yv);
      if (!ga || !ge) {
        ok = false;
      } else if (!(x < 360.0)) {
        nav_io_reader_error(r, a, item, "the azimuth must be below 360 deg (got %.17g)", x);
        ok = false;
      } else if (i > 0 && !(x * DEG > az[i - 1])) {
        nav_io_reader_error(r, a, item, "azimuths must increase (%.17g deg follows %.17g deg)", x, az[i - 1] / DEG);
        ok = false;
      } else {
        az[i] = x * DEG;
        el[i] = yv * DEG;
      }
    }
    nav_io_path_pop(r, saved);
  }
  if (!ok) return;
  m->n_profile = (int)n;
  for (size_t k = 0; k < n; ++k) {
    m->profile_az_rad[k] = az[k];
    m->profile_el_rad[k] = el[k];
  }
}

static nav_status write_sky_mask(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)indent;
  const nav_gnss_sky_mask *m = (const nav_gnss_sky_mask *)((const char *)base + f->offset);
  nav_status st = nav_io_writef(w, " [");
  for (int i = 0; i < m->n_profile && i < NAV_GNSS_MASK_MAX_POINTS && st == NAV_OK; ++i) {
    st = nav_io_writef(w, "%s[", i ? ", " : "");
    if (st == NAV_OK) st = nav_io_write_double(w, m->profile_az_rad[i] / DEG);
    if (st == NAV_OK) st = nav_io_writef(w, ", ");
    if (st == NAV_OK) st = nav_io_write_double(w, m->profile_el_rad[i] / DEG);
    if (st == NAV_OK) st = nav_io_writef(w, "]");
  }
  return st != NAV_OK ? st : nav_io_writef(w, "]");
}

static bool same_sky_mask(const nav_io_field *f, const void *a, const void *b) {
  const nav_gnss_sky_mask *ma = (const nav_gnss_sky_mask *)((const char *)a + f->offset);
  const nav_gnss_sky_mask *mb = (const nav_gnss_sky_mask *)((const char *)b + f->offset);
  if (ma->n_profile != mb->n_profile) return false;
  for (int i = 0; i < ma->n_profile && i < NAV_GNSS_MASK_MAX_POINTS; ++i)
    if (!same_bits(ma->profile_az_rad[i], mb->profile_az_rad[i]) ||
        !same_bits(ma->profile_el_rad[i], mb->profile_el_rad[i]))
      return false;
  return true;
}

/* ---------------------------------------------------------------- canyons: - {t0_s, t1_s, height_m, left_m, right_m} */

#define POS_LE_1000 (NAV_IO_FINITE | NAV_IO_MIN_GT | NAV_IO_MAX_LE | NAV_IO_REQUIRED)
static const nav_io_field k_canyon[] = {
    {.key = "t0_s",
     .doc = "time the vehicle enters the canyon",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE | NAV_IO_REQUIRED,
     .offset = KOFF(t0_s),
     .scale = 1.0},
    {.key = "t1_s",
     .doc = "time the vehicle leaves the canyon",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE | NAV_IO_REQUIRED,
     .offset = KOFF(t1_s),
     .scale = 1.0},
    {.key = "height_m",
     .doc = "height of the walls above the antenna",
     .kind = NAV_IO_DOUBLE,
     .flags = POS_LE_1000,
     .offset = KOFF(height_m),
     .scale = 1.0,
     .max = 1000.0},
    {.key = "left_m",
     .doc = "distance to the left wall",
     .kind = NAV_IO_DOUBLE,
     .flags = POS_LE_1000,
     .offset = KOFF(left_m),
     .scale = 1.0,
     .max = 1000.0},
    {.key = "right_m",
     .doc = "distance to the right wall",
     .kind = NAV_IO_DOUBLE,
     .flags = POS_LE_1000,
     .offset = KOFF(right_m),
     .scale = 1.0,
     .max = 1000.0},
};
static const nav_io_section k_canyon_section = {k_canyon, COUNT(k_canyon), NULL};

static void read_canyons(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                         void *base) {
  nav_gnss_constellation_config *c = (nav_gnss_constellation_config *)((char *)base + f->offset);
  if (nav_io_reject_special(r, key, v)) return;
  if (!nav_io_node_is_seq(v)) {
    nav_io_expected(r, key, v, "a list of canyons (- {t0_s, t1_s, height_m, left_m, right_m})");
    return;
  }
  const size_t n = nav_io_node_count(v);
  if (n > NAV_GNSS_MAX_CANYONS) {
    nav_io_reader_error(r, v, key, "at most %d canyons are supported (got %zu)", NAV_GNSS_MAX_CANYONS, n);
    return;
  }
  c->n_canyons = (int)n;
  size_t i = 0;
  for (const nav_io_node *item = nav_io_node_child(v); item != NULL; item = nav_io_node_next(item), ++i) {
    const size_t saved = nav_io_path_push_index(r, i);
    nav_io_mark(r, item, v);
    memset(&c->canyons[i], 0, sizeof c->canyons[i]);
    if (nav_io_reject_special(r, v, item)) {
      /* reported */
    } else if (!nav_io_node_is_map(item)) {
      nav_io_expected(r, v, item, "a canyon {t0_s, t1_s, height_m, left_m, right_m}");
    } else {
      nav_io_read_section(r, &k_canyon_section, v, item, &c->canyons[i]);
    }
    nav_io_path_pop(r, saved);
  }
}

static nav_status write_canyons(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  const nav_gnss_constellation_config *c = (const nav_gnss_constellation_config *)((const char *)base + f->offset);
  static const nav_gnss_canyon zero;
  if (c->n_canyons <= 0) return nav_io_writef(w, " []");
  nav_status st = NAV_OK;
  for (int i = 0; i < c->n_canyons && i < NAV_GNSS_MAX_CANYONS && st == NAV_OK; ++i) {
    st = nav_io_writef(w, "\n%*s- ", indent + 2, "");
    if (st == NAV_OK) st = nav_io_write_flow(w, &k_canyon_section, &c->canyons[i], &zero);
  }
  return st;
}

static bool same_canyons(const nav_io_field *f, const void *a, const void *b) {
  const nav_gnss_constellation_config *ca = (const nav_gnss_constellation_config *)((const char *)a + f->offset);
  const nav_gnss_constellation_config *cb = (const nav_gnss_constellation_config *)((const char *)b + f->offset);
  if (ca->n_canyons != cb->n_canyons) return false;
  for (int i = 0; i < ca->n_canyons && i < NAV_GNSS_MAX_CANYONS; ++i) {
    const nav_gnss_canyon *x = &ca->canyons[i], *y = &cb->canyons[i];
    if (!same_bits(x->t0_s, y->t0_s) || !same_bits(x->t1_s, y->t1_s) || !same_bits(x->height_m, y->height_m) ||
        !same_bits(x->left_m, y->left_m) || !same_bits(x->right_m, y->right_m))
      return false;
  }
  return true;
}

/* ---------------------------------------------------------------- JSON Schema of the custom values */

static void schema_epoch(nav_io_json *j, const nav_io_field *f) {
  (void)f;
  nav_io_json_key(j, "type");
  nav_io_json_string(j, "string");
  nav_io_json_key(j, "pattern");
  nav_io_json_string(j, "^[0-9]{4}-[0-9]{1,2}-[0-9]{1,2}T[0-9]{1,2}:[0-9]{1,2}:[0-9]+(\\.[0-9]*)?$");
}

/* [[azimuth_deg, elevation_deg], ...]: the bounds of read_sky_mask's az_f and el_f (azimuths below
   360, increasing: not expressible here). */
static void schema_sky_mask(nav_io_json *j, const nav_io_field *f) {
  (void)f;
  nav_io_json_key(j, "type");
  nav_io_json_string(j, "array");
  nav_io_json_key(j, "items");
  nav_io_json_raw(j, "{\"type\": \"array\", \"prefixItems\": [{\"type\": \"number\", \"minimum\": 0, "
                     "\"exclusiveMaximum\": 360}, {\"type\": \"number\", \"minimum\": 0, \"maximum\": 90}], "
                     "\"minItems\": 2, \"maxItems\": 2}");
  nav_io_json_key(j, "x-unit");
  nav_io_json_string(j, "deg");
}

/* ---------------------------------------------------------------- the section */

static bool almanac_given(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w, (void)f, (void)def;
  return ((const nav_scene *)base)->gnss.constellation.almanac_file[0] != '\0';
}

/* fixes: written only when not the default, so scenes written before the key existed stay the same. */
static bool fixes_given(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w, (void)f, (void)def;
  return ((const nav_scene *)base)->gnss.constellation.fixes != NAV_GNSS_FIXES_MODEL;
}

static void finish_constellation(nav_io_reader *r, const nav_io_node *map, void *base);

static const nav_io_field k_constellation[] = {
    {.key = "epoch",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(C(epoch_gps_s)),
     .read = read_epoch,
     .write = write_epoch,
     .same = same_epoch,
     .comment = "GPS time of scene time 0",
     .schema = schema_epoch},
    {.key = "gps",
     .kind = NAV_IO_ENUM,
     .offset = OFF(C(gps)),
     .enums = k_gps_sources,
     .comment = "nominal: SPS PS 24 slots; almanac: the YUMA file below"},
    {.key = "almanac",
     .kind = NAV_IO_STRING,
     .offset = OFF(C(almanac_file)),
     .size = NAV_GNSS_ALMANAC_PATH_MAX,
     .write_if = almanac_given,
     .comment = "YUMA almanac, relative to this file"},
    {.key = "glonass",
     .doc = "GLONASS satellites: their source",
     .kind = NAV_IO_ENUM,
     .offset = OFF(C(glonass)),
     .enums = k_glo_sources},
    {.key = "glonass_node_lon_deg",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(glonass_node1_lon_rad)),
     .scale = DEG,
     .comment = "plane 1 ascending node at the epoch"},
    {.key = "elevation_mask_deg",
     .doc = "lowest elevation of a visible satellite",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GE,
     .offset = OFF(C(mask.elevation_mask_rad)),
     .scale = DEG,
     .min = 0.0},
    {.key = "sky_mask_deg",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(C(mask)),
     .read = read_sky_mask,
     .write = write_sky_mask,
     .same = same_sky_mask,
     .comment = "[azimuth, elevation] skyline",
     .max_items = NAV_GNSS_MASK_MAX_POINTS,
     .schema = schema_sky_mask},
    {.key = "min_satellites_for_fix",
     .kind = NAV_IO_INT,
     .flags = NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(C(min_satellites_for_fix)),
     .min = 0.0,
     .max = NAV_GNSS_MAX_SATS,
     .comment = "receiver (gnss.enabled): no fix below this many visible satellites; 0: off"},
    {.key = "fixes",
     .doc = "ins_gnss fixes: model (receiver model noise) or pvt (least-squares PVT of the simulated "
            "pseudoranges and range rates, sigma DOP x code_sd_m, no fix below 3 + systems satellites)",
     .kind = NAV_IO_ENUM,
     .offset = OFF(C(fixes)),
     .enums = k_fix_sources,
     .write_if = fixes_given},
    {.key = "code_sd_m",
     .doc = "ins_gnss_tight: white pseudorange noise (1 sigma)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.code_sd_m)),
     .scale = 1.0},
    {.key = "range_rate_sd_mps",
     .doc = "ins_gnss_tight: white Doppler range-rate noise (1 sigma)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.range_rate_sd_mps)),
     .scale = 1.0},
    {.key = "clock_h0_s",
     .doc = "receiver oscillator, Allan h_0 (white frequency)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.clock_h0_s)),
     .scale = 1.0},
    {.key = "clock_hm2_per_s",
     .doc = "receiver oscillator, Allan h_-2 (random-walk frequency)",
     .unit = "1/s",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.clock_hm2_per_s)),
     .scale = 1.0},
    {.key = "clock_bias_sd_m",
     .doc = "receiver clock bias at t = 0 (1 sigma, metres of c dt)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.clock_bias_sd_m)),
     .scale = 1.0},
    {.key = "clock_drift_sd_mps",
     .doc = "receiver clock drift at t = 0 (1 sigma)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.clock_drift_sd_mps)),
     .scale = 1.0},
    {.key = "isb_sd_m",
     .doc = "GLONASS - GPS inter-system bias (1 sigma, constant per run)",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(C(raw.isb_sd_m)),
     .scale = 1.0},
    {.key = "canyons",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(gnss.constellation),
     .read = read_canyons,
     .write = write_canyons,
     .same = same_canyons,
     .comment = "street walls along the direction of travel",
     .items = &k_canyon_section,
     .max_items = NAV_GNSS_MAX_CANYONS},
};
const nav_io_section nav_io_gnss_constellation_section = {k_constellation, COUNT(k_constellation),
                                                          finish_constellation};

/* After the section: it is present, so enabled; load the almanac. */
static void finish_constellation(nav_io_reader *r, const nav_io_node *map, void *base) {
  (void)map;
  nav_scene *s = base;
  nav_gnss_constellation_config *c = &s->gnss.constellation;
  c->enabled = true;
  c->almanac.n = 0;
  if (c->gps != NAV_GNSS_SOURCE_ALMANAC) return; /* an almanac without gps: almanac is a validation error */
  if (c->almanac_file[0] == '\0') {
    nav_io_reader_error_at_path(r, "gnss.constellation.gps",
                                "gps: almanac needs gnss.constellation.almanac: FILE (a YUMA almanac)");
    return;
  }
  const nav_io_read_state *st = nav_io_reader_state(r);
  char path[3 * NAV_IO_PATH_MAX];
  if (!nav_io_resolve_path(path, sizeof path, st->file, st->file_is_path, c->almanac_file) ||
      strlen(path) >= sizeof c->almanac_file) {
    nav_io_reader_error_at_path(r, "gnss.constellation.almanac", "the path of the almanac file is too long");
    return;
  }
  struct stat sb;
  errno = 0;
  if (stat(path, &sb) != 0 || !S_ISREG(sb.st_mode)) {
    nav_io_reader_error_at_path(r, "gnss.constellation.almanac", "cannot read the almanac file \"%s\": %s", path,
                                errno != 0 ? strerror(errno) : "not a regular file");
    return;
  }
  char *canonical = realpath(path, NULL);
  if (canonical != NULL && strlen(canonical) < sizeof path) snprintf(path, sizeof path, "%s", canonical);
  free(canonical);
  nav_gnss_constellation alm;
  alm.n = 0;
  const nav_status rs = nav_gnss_almanac_read_yuma(path, c->epoch_gps_s, &alm, nav_io_forward_diag, r);
  if (rs != NAV_OK) {
    nav_io_reader_error_at_path(r, "gnss.constellation.almanac",
                                "the almanac file \"%s\" was not read (%s; see its messages)", path,
                                nav_status_str(rs));
    return;
  }
  const size_t plen = strlen(path);
  if (plen >= sizeof c->almanac_file) {
    nav_io_reader_error_at_path(r, "gnss.constellation.almanac",
                                "the almanac file's path is %zu bytes long; at most %zu are kept", plen,
                                sizeof c->almanac_file - 1);
    return;
  }
  memcpy(c->almanac_file, path, plen + 1);
  c->almanac = alm;
}

bool nav_io_gnss_constellation_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                       const void *def) {
  (void)w, (void)f, (void)def;
  return ((const nav_scene *)base)->gnss.constellation.enabled;
}
