/* GPS almanac files (YUMA) into nav_gnss_constellation (nav_gnss_almanac.h). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_gnss_almanac.h"

typedef struct alm_reader {
  const char *file;
  nav_diag_fn report;
  void *user;
  int ndiag;
} alm_reader;

static void diag(alm_reader *r, long line, int col, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
static void diag(alm_reader *r, long line, int col, const char *path, const char *fmt, ...) {
  if (r->ndiag >= NAV_DIAG_MAX_PER_FILE) {
    return;
  }
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", r->file);
  d.line = line > 0 && line < 0x7fffffffL ? (int)line : 0;
  d.col = d.line > 0 ? (col > 0 ? col : 1) : 0;
  snprintf(d.path, sizeof d.path, "%s", path ? path : "");
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d.message, sizeof d.message, fmt, ap);
  va_end(ap);
  r->ndiag++;
  if (r->report) {
    r->report(r->user, &d);
  }
}

/* The keys of a YUMA block, in file order. */
enum { K_ID, K_HEALTH, K_ECC, K_TOA, K_INC, K_OMDOT, K_SQRTA, K_OM0, K_W, K_M0, K_AF0, K_AF1, K_WEEK, K_COUNT };
static const char *const k_keys[K_COUNT] = {"ID",
                                            "Health",
                                            "Eccentricity",
                                            "Time of Applicability(s)",
                                            "Orbital Inclination(rad)",
                                            "Rate of Right Ascen(r/s)",
                                            "SQRT(A)  (m 1/2)",
                                            "Right Ascen at Week(rad)",
                                            "Argument of Perigee(rad)",
                                            "Mean Anom(rad)",
                                            "Af0(s)",
                                            "Af1(s/s)",
                                            "week"};

static bool blank(const char *s) {
  for (; *s; ++s) {
    if (*s != ' ' && *s != '\t' && *s != '\r' && *s != '\n') {
      return false;
    }
  }
  return true;
}

/* Parse one "Key: value" line for key k; on success store the number. */
static bool parse_kv(alm_reader *r, long ln, const char *line, int k, double *val, int *val_col) {
  const char *key = k_keys[k];
  const size_t kl = strlen(key);
  const char *start = line;
  while (*start == ' ') {
    ++start;
  }
  if (strncmp(start, key, kl) != 0) {
    diag(r, ln, (int)(start - line) + 1, key, "expected the YUMA line \"%s: value\"", key);
    return false;
  }
  const char *p = start + kl;
  while (*p == ' ') {
    ++p;
  }
  if (*p != ':') {
    diag(r, ln, (int)(p - line) + 1, key, "expected ':' after \"%s\"", key);
    return false;
  }
  ++p;
  while (*p == ' ' || *p == '\t') {
    ++p;
  }
  const int col = (int)(p - line) + 1;
  errno = 0;
  char *end = NULL;
  const double v = strtod(p, &end);
  if (end == p || errno == ERANGE || !isfinite(v) || !blank(end)) {
    diag(r, ln, col, key, "expected a finite number");
    return false;
  }
  *val = v;
  *val_col = col;
  return true;
}

nav_status nav_gnss_almanac_read_yuma(const char *path, double t_ref_gps_s, nav_gnss_constellation *out,
                                      nav_diag_fn report, void *user) {
  if (!path || !out || !isfinite(t_ref_gps_s) || out->n < 0 || out->n > NAV_GNSS_MAX_SATS) {
    return NAV_ERR_INVALID_ARG;
  }
  alm_reader r = {.file = path, .report = report, .user = user};
  FILE *f = fopen(path, "r");
  if (!f) {
    diag(&r, 0, 0, NULL, "cannot open the almanac file: %s", strerror(errno));
    return NAV_ERR_IO;
  }
  nav_gnss_constellation tmp = *out;
  nav_status st = NAV_OK;
  char line[512];
  long ln = 0;
  int k = -1; /* -1: between blocks; else the next key expected */
  long block_line = 0;
  double v[K_COUNT];
  int vcol[K_COUNT];
  int nblocks = 0;
  while (fgets(line, sizeof line, f)) {
    ++ln;
    if (!strchr(line, '\n') && !feof(f)) {
      diag(&r, ln, 1, NULL, "line longer than %zu characters", sizeof line - 2);
      st = NAV_ERR_PARSE;
      break;
    }
    if (k < 0) {
      if (blank(line)) {
        continue;
      }
      if (strncmp(line, "****", 4) != 0) {
        diag(&r, ln, 1, NULL, "expected a YUMA block header \"******** Week W almanac for PRN-NN ********\"");
        st = NAV_ERR_PARSE;
        break;
      }
      k = 0;
      block_line = ln;
      continue;
    }
    if (!parse_kv(&r, ln, line, k, &v[k], &vcol[k])) {
      st = NAV_ERR_PARSE;
      break;
    }
    if (++k < K_COUNT) {
      continue;
    }
    k = -1;
    /* range checks of the whole block */
    const char *bad = NULL;
    int bk = 0;
    if (!(v[K_ID] >= 1 && v[K_ID] <= 32 && v[K_ID] == floor(v[K_ID]))) {
      bad = "PRN must be an integer 1..32", bk = K_ID;
    } else if (!(v[K_ECC] >= 0.0 && v[K_ECC] < 1.0)) {
      bad = "eccentricity must be in [0, 1)", bk = K_ECC;
    } else if (!(v[K_TOA] >= 0.0 && v[K_TOA] < NAV_GNSS_WEEK_S)) {
      bad = "time of applicability must be in [0, 604800) s", bk = K_TOA;
    } else if (!(v[K_SQRTA] > 2000.0 && v[K_SQRTA] < 10000.0)) {
      bad = "SQRT(A) must be in (2000, 10000) m^0.5 (a GNSS medium Earth orbit)", bk = K_SQRTA;
    } else if (!(v[K_WEEK] >= 0 && v[K_WEEK] == floor(v[K_WEEK]) && v[K_WEEK] < 1e5)) {
      bad = "week must be a non-negative integer", bk = K_WEEK;
    } else if (!(v[K_HEALTH] >= 0 && v[K_HEALTH] == floor(v[K_HEALTH]))) {
      bad = "health must be a non-negative integer", bk = K_HEALTH;
    }
    if (bad) {
      diag(&r, block_line + 1 + bk, vcol[bk], k_keys[bk], "%s", bad);
      st = NAV_ERR_PARSE;
      break;
    }
    if (tmp.n >= NAV_GNSS_MAX_SATS) {
      diag(&r, block_line, 1, NULL, "more than %d satellites", NAV_GNSS_MAX_SATS);
      st = NAV_ERR_OUT_OF_RANGE;
      break;
    }
    /* Week modulo 1024 -> the full week closest to the reference time. */
    const double ref_week = t_ref_gps_s / NAV_GNSS_WEEK_S;
    const double wk10 = fmod(v[K_WEEK], 1024.0);
    const double week = wk10 + 1024.0 * round((ref_week - wk10) / 1024.0);
    nav_gnss_orbit o = {0};
    o.system = NAV_GNSS_SYS_GPS;
    o.prn = (int)v[K_ID];
    o.health = (int)v[K_HEALTH];
    o.toe_s = week * NAV_GNSS_WEEK_S + v[K_TOA];
    o.sqrt_a_sqrtm = v[K_SQRTA];
    o.e = v[K_ECC];
    o.i0_rad = v[K_INC];
    o.omega0_rad = v[K_OM0];
    o.omega_dot_rps = v[K_OMDOT];
    o.w_rad = v[K_W];
    o.m0_rad = v[K_M0];
    o.af0_s = v[K_AF0];
    o.af1_sps = v[K_AF1];
    tmp.sats[tmp.n++] = o;
    ++nblocks;
  }
  if (st == NAV_OK && ferror(f)) {
    diag(&r, 0, 0, NULL, "read error");
    st = NAV_ERR_IO;
  }
  if (st == NAV_OK && k >= 0) {
    diag(&r, ln + 1, 1, k_keys[k], "the file ends inside the block of line %ld (missing \"%s\")", block_line,
         k_keys[k]);
    st = NAV_ERR_PARSE;
  }
  if (st == NAV_OK && nblocks == 0) {
    diag(&r, ln > 0 ? ln : 1, 1, NULL, "no almanac block in the file");
    st = NAV_ERR_PARSE;
  }
  fclose(f);
  if (st == NAV_OK) {
    *out = tmp;
  }
  return st;
}
