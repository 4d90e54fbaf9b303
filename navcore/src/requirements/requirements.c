/*
 * Accuracy requirements (nav_requirements.h): names, validation and the streaming evaluator.
 *
 * Evaluator layout. Each run accumulates into its own nav_req_run: per requirement a few doubles
 * (sum of squares, count, maximum; the at_time candidate; the last value inside each outage) and,
 * for the quantile statistics, the run's metric values. nav_req_run_end copies the small part into
 * the run's row of a runs x width table and appends the quantile values to a shared store under a
 * mutex. nav_req_evaluator_finish reduces the table in run order, and a quantile does not depend
 * on the order of its values, so the verdicts are bit-identical for any thread schedule.
 *
 * Quantile store: exact values while the evaluator's total stays within NAV_REQ_EXACT_BUDGET
 * (split evenly between its quantile requirements); past that share, a requirement moves all its
 * values into a logarithmic histogram (bins of relative width NAV_REQ_HIST_REL_WIDTH over
 * [HIST_LO, HIST_HI] SI, one under- and one overflow bin) and keeps the exact minimum and maximum.
 * The set of values is the same whatever the order, so the final state is too.
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_errors.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"
#include "requirements/budget_internal.h"
#include "sim/nav_thread_internal.h"
#include "sim/sim_internal.h"

#define HIST_LO 1e-12
#define HIST_HI 1e12

/* ================================================================ names and units */

static const char *const k_metric_names[NAV_REQ_METRIC_COUNT] = {
    "horizontal_position", "vertical_position", "position_3d", "velocity", "roll_pitch", "yaw"};
static const char *const k_statistic_names[NAV_REQ_STATISTIC_COUNT] = {"rms",        "max",   "p95",  "at_time",
                                                                       "outage_end", "cep50", "cep95"};
static const char *const k_unit_names[NAV_REQ_UNIT_COUNT] = {"m",   "cm",     "km",     "m/s",  "cm/s",
                                                             "deg", "arcmin", "arcsec", "mrad", "rad"};

const char *nav_req_metric_name(nav_req_metric m) {
  return (int)m >= 0 && (int)m < NAV_REQ_METRIC_COUNT ? k_metric_names[m] : "unknown";
}
const char *nav_req_statistic_name(nav_req_statistic s) {
  return (int)s >= 0 && (int)s < NAV_REQ_STATISTIC_COUNT ? k_statistic_names[s] : "unknown";
}
const char *nav_req_unit_name(nav_req_unit u) {
  return (int)u >= 0 && (int)u < NAV_REQ_UNIT_COUNT ? k_unit_names[u] : "unknown";
}

static int find_name(const char *const *names, int n, const char *name) {
  if (name == NULL) return -1;
  for (int i = 0; i < n; ++i)
    if (strcmp(names[i], name) == 0) return i;
  return -1;
}
bool nav_req_metric_from_name(const char *name, nav_req_metric *out) {
  const int i = find_name(k_metric_names, NAV_REQ_METRIC_COUNT, name);
  if (i < 0) return false;
  if (out) *out = (nav_req_metric)i;
  return true;
}
bool nav_req_statistic_from_name(const char *name, nav_req_statistic *out) {
  const int i = find_name(k_statistic_names, NAV_REQ_STATISTIC_COUNT, name);
  if (i < 0) return false;
  if (out) *out = (nav_req_statistic)i;
  return true;
}
bool nav_req_unit_from_name(const char *name, nav_req_unit *out) {
  const int i = find_name(k_unit_names, NAV_REQ_UNIT_COUNT, name);
  if (i < 0) return false;
  if (out) *out = (nav_req_unit)i;
  return true;
}

double nav_req_unit_to_si(nav_req_unit u) {
  switch (u) {
  case NAV_REQ_UNIT_M: return 1.0;
  case NAV_REQ_UNIT_CM: return 0.01;
  case NAV_REQ_UNIT_KM: return 1000.0;
  case NAV_REQ_UNIT_MPS: return 1.0;
  case NAV_REQ_UNIT_CMPS: return 0.01;
  case NAV_REQ_UNIT_DEG: return NAV_PI / 180.0;
  case NAV_REQ_UNIT_ARCMIN: return NAV_PI / 10800.0;
  case NAV_REQ_UNIT_ARCSEC: return NAV_PI / 648000.0;
  case NAV_REQ_UNIT_MRAD: return 1e-3;
  case NAV_REQ_UNIT_RAD: return 1.0;
  }
  return NAN;
}

nav_req_quantity nav_req_unit_quantity(nav_req_unit u) {
  switch (u) {
  case NAV_REQ_UNIT_M:
  case NAV_REQ_UNIT_CM:
  case NAV_REQ_UNIT_KM: return NAV_REQ_LENGTH;
  case NAV_REQ_UNIT_MPS:
  case NAV_REQ_UNIT_CMPS: return NAV_REQ_SPEED;
  default: return NAV_REQ_ANGLE;
  }
}

nav_req_quantity nav_req_metric_quantity(nav_req_metric m) {
  switch (m) {
  case NAV_REQ_HORIZONTAL_POSITION:
  case NAV_REQ_VERTICAL_POSITION:
  case NAV_REQ_POSITION_3D: return NAV_REQ_LENGTH;
  case NAV_REQ_VELOCITY: return NAV_REQ_SPEED;
  default: return NAV_REQ_ANGLE;
  }
}

double nav_req_metric_value(nav_req_metric m, const nav_epoch_errors *e) {
  const nav_vec3 p = e->pos_err_n_m, v = e->vel_err_n_mps;
  switch (m) {
  case NAV_REQ_HORIZONTAL_POSITION: return hypot(p.x, p.y);
  case NAV_REQ_VERTICAL_POSITION: return fabs(p.z);
  case NAV_REQ_POSITION_3D: return sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
  case NAV_REQ_VELOCITY: return sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  case NAV_REQ_ROLL_PITCH: return fmax(fabs(e->euler_err.roll_rad), fabs(e->euler_err.pitch_rad));
  case NAV_REQ_YAW: return fabs(e->euler_err.yaw_rad);
  }
  return NAN;
}

bool nav_req_statistic_is_quantile(nav_req_statistic s) {
  return s == NAV_REQ_P95 || s == NAV_REQ_CEP50 || s == NAV_REQ_CEP95;
}

/* Percent of a quantile statistic. */
static int quantile_percent(nav_req_statistic s) { return s == NAV_REQ_CEP50 ? 50 : 95; }

/* ================================================================ validation */

static void req_issue(nav_req_issue_fn report, void *user, int *count, int i, const char *field, const char *fmt,
                      ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 6, 7)))
#endif
    ;

static void req_issue(nav_req_issue_fn report, void *user, int *count, int i, const char *field, const char *fmt,
                      ...) {
  char path[96], msg[256];
  if (i < 0) snprintf(path, sizeof path, "requirements");
  else if (field == NULL) snprintf(path, sizeof path, "requirements[%d]", i);
  else snprintf(path, sizeof path, "requirements[%d].%s", i, field);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  ++*count;
  if (report) report(user, path, msg);
}

static const char *units_of(nav_req_quantity q) {
  switch (q) {
  case NAV_REQ_LENGTH: return "m, cm, km";
  case NAV_REQ_SPEED: return "m/s, cm/s";
  case NAV_REQ_ANGLE: return "deg, arcmin, arcsec, mrad, rad";
  }
  return "?";
}

nav_status nav_requirements_validate(const nav_requirement *reqs, int count, nav_req_issue_fn report, void *user) {
  int n = 0;
  if (count < 0 || count > NAV_SCENE_MAX_REQUIREMENTS) {
    req_issue(report, user, &n, -1, NULL, "at most %d requirements are supported (got %d)",
              NAV_SCENE_MAX_REQUIREMENTS, count);
    return NAV_ERR_INVALID_ARG;
  }
  if (count > 0 && reqs == NULL) return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < count; ++i) {
    const nav_requirement *q = &reqs[i];
    size_t len = 0;
    while (len < NAV_REQ_ID_MAX && q->id[len] != '\0') ++len;
    if (len == 0 || len >= NAV_REQ_ID_MAX) {
      req_issue(report, user, &n, i, "id", "must be 1 to %d characters of A-Z a-z 0-9 _ . -", NAV_REQ_ID_MAX - 1);
    } else {
      bool ok = true;
      for (size_t k = 0; k < len; ++k) {
        const char c = q->id[k];
        if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '.' ||
              c == '-'))
          ok = false;
      }
      if (!ok)
        req_issue(report, user, &n, i, "id", "\"%s\": only the characters A-Z a-z 0-9 _ . - are allowed", q->id);
      for (int j = 0; j < i && ok; ++j)
        if (strncmp(reqs[j].id, q->id, NAV_REQ_ID_MAX) == 0) {
          req_issue(report, user, &n, i, "id", "\"%s\" is already the id of requirements[%d]; ids must be unique",
                    q->id, j);
          break;
        }
    }
    const bool metric_ok = (int)q->metric >= 0 && (int)q->metric < NAV_REQ_METRIC_COUNT;
    const bool stat_ok = (int)q->statistic >= 0 && (int)q->statistic < NAV_REQ_STATISTIC_COUNT;
    const bool unit_ok = (int)q->unit >= 0 && (int)q->unit < NAV_REQ_UNIT_COUNT;
    if (!metric_ok) req_issue(report, user, &n, i, "metric", "unknown metric %d", (int)q->metric);
    if (!stat_ok) req_issue(report, user, &n, i, "statistic", "unknown statistic %d", (int)q->statistic);
    if (!unit_ok) req_issue(report, user, &n, i, "unit", "unknown unit %d", (int)q->unit);
    if (!(isfinite(q->limit) && q->limit > 0.0))
      req_issue(report, user, &n, i, "limit", "must be a finite number > 0 (got %g)", q->limit);
    if (metric_ok && unit_ok && nav_req_unit_quantity(q->unit) != nav_req_metric_quantity(q->metric))
      req_issue(report, user, &n, i, "unit", "%s is not a unit of %s: expected one of %s", nav_req_unit_name(q->unit),
                nav_req_metric_name(q->metric), units_of(nav_req_metric_quantity(q->metric)));
    if (metric_ok && stat_ok && (q->statistic == NAV_REQ_CEP50 || q->statistic == NAV_REQ_CEP95) &&
        q->metric != NAV_REQ_HORIZONTAL_POSITION)
      req_issue(report, user, &n, i, "statistic", "%s applies to metric horizontal_position only (got %s)",
                nav_req_statistic_name(q->statistic), nav_req_metric_name(q->metric));
    if (stat_ok && q->statistic == NAV_REQ_AT_TIME && !(isfinite(q->time_s) && q->time_s >= 0.0))
      req_issue(report, user, &n, i, "time_s", "statistic at_time needs time_s, a finite time >= 0 [s] (got %g)",
                q->time_s);
  }
  return n ? NAV_ERR_INVALID_ARG : NAV_OK;
}

const char *nav_req_na_reason_text(nav_req_na_reason r) {
  switch (r) {
  case NAV_REQ_NA_NONE: return "";
  case NAV_REQ_NA_NO_DATA: return "no epoch entered the statistic";
  case NAV_REQ_NA_NO_OUTAGE: return "the run has no GNSS outage";
  case NAV_REQ_NA_TIME_OUTSIDE: return "time_s lies outside the run's epochs";
  case NAV_REQ_NA_NOT_PREDICTED: return "not predicted (no covariance analysis, or not predictable from sigmas)";
  case NAV_REQ_NA_NO_GNSS_FIX: return "no GNSS fix was applied";
  }
  return "not evaluated";
}

nav_status nav_requirements_check_scene(const nav_scene *scene, nav_req_issue_fn report, void *user) {
  if (!scene) return NAV_ERR_INVALID_ARG;
  int n = 0;
  const double dur = scene->trajectory.duration_s;
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  bool outages_known = true;
  const bool has_gnss = scene->navigation.scheme == NAV_SCHEME_INS_GNSS ||
                        scene->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
                        scene->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT;
  if (has_gnss) outages_known = nav_req_scene_outages(scene, iv, NAV_REQ_MAX_OUTAGES, &ni) == NAV_OK;
  int n_in_run = 0;
  for (int j = 0; j < ni; ++j)
    if (!(iv[j].t0_s >= dur)) ++n_in_run;
  for (int i = 0; i < scene->n_requirements && i < NAV_SCENE_MAX_REQUIREMENTS; ++i) {
    const nav_requirement *q = &scene->requirements[i];
    /* The last output epoch is at the end of the run (duration_s); 1e-9 relative covers its
     * rounding to the output grid. */
    if (q->statistic == NAV_REQ_AT_TIME && isfinite(dur) && q->time_s > dur * (1.0 + 1e-9) + 1e-9)
      req_issue(report, user, &n, i, "time_s",
                "%g s is after the end of the run (trajectory duration %g s): an at_time requirement needs a "
                "time within [0, %g] s",
                q->time_s, dur, dur);
    if (q->statistic == NAV_REQ_OUTAGE_END && outages_known && n_in_run == 0) {
      if (!has_gnss)
        req_issue(report, user, &n, i, "statistic",
                  "outage_end needs a GNSS outage, and navigation.scheme %s has no GNSS: use scheme ins_gnss "
                  "(or gyro_free_gnss, ins_gnss_tight) with gnss.outages, or another statistic",
                  nav_nav_scheme_name(scene->navigation.scheme));
      else if (ni > 0)
        req_issue(report, user, &n, i, "statistic",
                  "outage_end needs a GNSS outage within the run, and every outage starts after its end (%g s)",
                  dur);
      else
        req_issue(report, user, &n, i, "statistic",
                  "outage_end needs a GNSS outage, and the scene has none: add gnss.outages (or a segment with "
                  "gnss_visible: false), or use another statistic");
    }
  }
  return n ? NAV_ERR_INVALID_ARG : NAV_OK;
}

bool nav_req_all_pass(const nav_requirement_verdict *v, int count) {
  for (int i = 0; i < count; ++i)
    if (!v[i].pass) return false;
  return true;
}

/* ================================================================ quantile store */

typedef struct qstore {
  double *exact;
  size_t n, cap, budget;
  uint64_t *hist; /* NULL while exact */
  size_t nbins;
  uint64_t total;
  double min, max;
} qstore;

static double hist_ratio(void) { return 1.0 + NAV_REQ_HIST_REL_WIDTH; }

static size_t hist_bins(void) {
  /* bin 0: below HIST_LO; 1..m: [LO r^(i-1), LO r^i); m + 1: at or above HIST_HI */
  return (size_t)ceil(log(HIST_HI / HIST_LO) / log1p(NAV_REQ_HIST_REL_WIDTH)) + 2;
}

static size_t hist_index(const qstore *q, double x) {
  if (!(x >= HIST_LO)) return 0;
  if (x >= HIST_HI) return q->nbins - 1;
  size_t i = (size_t)floor(log(x / HIST_LO) / log1p(NAV_REQ_HIST_REL_WIDTH)) + 1;
  if (i > q->nbins - 2) i = q->nbins - 2;
  return i;
}

static nav_status qstore_to_hist(qstore *q) {
  q->nbins = hist_bins();
  q->hist = calloc(q->nbins, sizeof *q->hist);
  if (!q->hist) return NAV_ERR_NO_MEMORY;
  for (size_t i = 0; i < q->n; ++i) q->hist[hist_index(q, q->exact[i])]++;
  free(q->exact);
  q->exact = NULL;
  q->n = q->cap = 0;
  return NAV_OK;
}

static nav_status qstore_add(qstore *q, const double *v, size_t count) {
  for (size_t i = 0; i < count; ++i) {
    if (q->total == 0 || v[i] < q->min) q->min = v[i];
    if (q->total == 0 || v[i] > q->max) q->max = v[i];
    q->total++;
    if (q->hist) {
      q->hist[hist_index(q, v[i])]++;
      continue;
    }
    if (q->n == q->cap) {
      if (q->n >= q->budget) {
        const nav_status st = qstore_to_hist(q);
        if (st != NAV_OK) return st;
        q->hist[hist_index(q, v[i])]++;
        continue;
      }
      size_t nc = q->cap ? 2 * q->cap : 4096;
      if (nc > q->budget) nc = q->budget;
      double *g = realloc(q->exact, nc * sizeof *g);
      if (!g) return NAV_ERR_NO_MEMORY;
      q->exact = g;
      q->cap = nc;
    }
    q->exact[q->n++] = v[i];
  }
  return NAV_OK;
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Nearest-rank quantile: the k-th smallest value, k = ceil(pct N / 100). NaN when empty. */
static double qstore_quantile(qstore *q, int pct) {
  if (q->total == 0) return NAN;
  uint64_t k = (q->total * (uint64_t)pct + 99) / 100;
  if (k < 1) k = 1;
  if (!q->hist) {
    qsort(q->exact, q->n, sizeof *q->exact, cmp_double);
    return q->exact[k - 1];
  }
  uint64_t c = 0;
  for (size_t i = 0; i < q->nbins; ++i) {
    c += q->hist[i];
    if (c >= k) {
      double x;
      if (i == 0) x = q->min;
      else if (i == q->nbins - 1) x = q->max;
      else x = HIST_LO * pow(hist_ratio(), (double)(i - 1) + 0.5);
      return fmin(fmax(x, q->min), q->max);
    }
  }
  return q->max;
}

/* ================================================================ evaluator */

/* Row layout per requirement (offsets into a run's row of doubles):
 *   rms, max, quantiles: [sum of squares, count, max]
 *   at_time:             [value, epoch time, |epoch time - time_s|, first epoch, last epoch, spacing
 *                        of the last two epochs]  (value NaN: no epoch)
 *   outage_end:          [value, time] at the last epoch inside outage j, j = 0..n_outages-1 (NaN: none) */
typedef struct req_layout {
  size_t off, width;
  int qindex; /* quantile store index, -1 */
} req_layout;

struct nav_req_evaluator {
  nav_requirement reqs[NAV_SCENE_MAX_REQUIREMENTS];
  req_layout lay[NAV_SCENE_MAX_REQUIREMENTS];
  int count;
  long runs;
  nav_req_interval outages[NAV_REQ_MAX_OUTAGES];
  int n_outages;
  size_t width; /* doubles per run row */
  double *table; /* runs x width */
  unsigned char *done; /* per run: merged */
  qstore q[NAV_SCENE_MAX_REQUIREMENTS];
  int nq;
  nav_mutex lock;
  bool lock_ok;
  nav_status failed; /* first merge failure */
};

struct nav_req_run {
  long run;
  const nav_req_evaluator *ev;
  double *row;
  double *qv[NAV_SCENE_MAX_REQUIREMENTS]; /* quantile values of this run */
  size_t qn[NAV_SCENE_MAX_REQUIREMENTS], qcap[NAV_SCENE_MAX_REQUIREMENTS];
  nav_status st;
};

nav_status nav_req_evaluator_create(const nav_requirement *reqs, int count, long runs,
                                    const nav_req_interval *outages, int n_outages, nav_req_evaluator **out) {
  if (!out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  if (runs < 1 || n_outages < 0 || (n_outages > 0 && !outages)) return NAV_ERR_INVALID_ARG;
  if (nav_requirements_validate(reqs, count, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  if (n_outages > NAV_REQ_MAX_OUTAGES) n_outages = NAV_REQ_MAX_OUTAGES;
  nav_req_evaluator *ev = calloc(1, sizeof *ev);
  if (!ev) return NAV_ERR_NO_MEMORY;
  ev->count = count;
  ev->runs = runs;
  ev->n_outages = n_outages;
  for (int j = 0; j < n_outages; ++j) ev->outages[j] = outages[j];
  int nq = 0;
  for (int i = 0; i < count; ++i)
    if (nav_req_statistic_is_quantile(reqs[i].statistic)) ++nq;
  size_t w = 0;
  for (int i = 0; i < count; ++i) {
    ev->reqs[i] = reqs[i];
    ev->lay[i].off = w;
    ev->lay[i].qindex = -1;
    ev->lay[i].width = reqs[i].statistic == NAV_REQ_OUTAGE_END ? 2 * (size_t)n_outages
                       : reqs[i].statistic == NAV_REQ_AT_TIME  ? 6
                                                               : 3;
    if (nav_req_statistic_is_quantile(reqs[i].statistic)) {
      ev->lay[i].qindex = ev->nq;
      ev->q[ev->nq].budget = (size_t)(NAV_REQ_EXACT_BUDGET / nq);
      ev->nq++;
    }
    w += ev->lay[i].width;
  }
  ev->width = w;
  if (w > 0 && (size_t)runs > SIZE_MAX / sizeof(double) / w) {
    free(ev);
    return NAV_ERR_NO_MEMORY;
  }
  ev->table = calloc((size_t)runs * (w ? w : 1), sizeof *ev->table);
  ev->done = calloc((size_t)runs, 1);
  ev->lock_ok = nav_mutex_init(&ev->lock);
  if (!ev->table || !ev->done || !ev->lock_ok) {
    nav_req_evaluator_destroy(ev);
    return NAV_ERR_NO_MEMORY;
  }
  *out = ev;
  return NAV_OK;
}

nav_status nav_req_scene_outages(const nav_scene *scene, nav_req_interval *out, int cap, int *n) {
  if (!scene || !n || (cap > 0 && !out)) return NAV_ERR_INVALID_ARG;
  *n = 0;
  if (!scene->gnss.enabled) return NAV_OK;
  nav_gnss_model_config g;
  char msg[200];
  const nav_status st = nav_sim_gnss_config(scene, 1.0 / scene->imu.rate_hz, &g, msg, sizeof msg);
  if (st != NAV_OK) return st;
  for (size_t i = 0; i < g.outage_count && (int)i < cap; ++i) {
    out[i].t0_s = g.outages[i].t0_s;
    out[i].t1_s = g.outages[i].t1_s;
    ++*n;
  }
  return NAV_OK;
}

nav_status nav_req_evaluator_create_for_scene(const nav_scene *scene, bool ideal, nav_req_evaluator **out) {
  if (!scene || !out) return NAV_ERR_INVALID_ARG;
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int n = 0;
  if (scene->navigation.scheme == NAV_SCHEME_INS_GNSS || scene->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
      scene->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
    const nav_status st = nav_req_scene_outages(scene, iv, NAV_REQ_MAX_OUTAGES, &n);
    if (st != NAV_OK) return st;
  }
  return nav_req_evaluator_create(scene->requirements, scene->n_requirements, ideal ? 1 : scene->simulation.runs, iv,
                                  n, out);
}

void nav_req_evaluator_destroy(nav_req_evaluator *ev) {
  if (!ev) return;
  for (int i = 0; i < ev->nq; ++i) {
    free(ev->q[i].exact);
    free(ev->q[i].hist);
  }
  if (ev->lock_ok) nav_mutex_destroy(&ev->lock);
  free(ev->table);
  free(ev->done);
  free(ev);
}

int nav_req_evaluator_count(const nav_req_evaluator *ev) { return ev ? ev->count : 0; }

nav_status nav_req_run_begin(nav_req_evaluator *ev, long run, nav_req_run **out) {
  if (!ev || !out || run < 0 || run >= ev->runs) return NAV_ERR_INVALID_ARG;
  nav_req_run *r = calloc(1, sizeof *r);
  if (!r) return NAV_ERR_NO_MEMORY;
  r->row = calloc(ev->width ? ev->width : 1, sizeof *r->row);
  if (!r->row) {
    free(r);
    return NAV_ERR_NO_MEMORY;
  }
  r->run = run;
  r->ev = ev;
  for (int i = 0; i < ev->count; ++i) {
    double *row = r->row + ev->lay[i].off;
    if (ev->reqs[i].statistic == NAV_REQ_AT_TIME) {
      row[0] = NAN;
      row[1] = NAN;
      row[2] = INFINITY;
      row[3] = NAN;
      row[4] = NAN;
      row[5] = 0.0;
    } else if (ev->reqs[i].statistic == NAV_REQ_OUTAGE_END) {
      for (size_t j = 0; j < ev->lay[i].width; ++j) row[j] = NAN;
    }
  }
  *out = r;
  return NAV_OK;
}

nav_status nav_req_run_add(nav_req_run *r, const nav_epoch_errors *e) {
  if (!r || !e) return NAV_ERR_INVALID_ARG;
  if (r->st != NAV_OK) return r->st;
  const nav_req_evaluator *ev = r->ev;
  for (int i = 0; i < ev->count; ++i) {
    const nav_requirement *q = &ev->reqs[i];
    const double x = nav_req_metric_value(q->metric, e);
    double *row = r->row + ev->lay[i].off;
    switch (q->statistic) {
    case NAV_REQ_AT_TIME: {
      const double d = fabs(e->t_s - q->time_s);
      if (d < row[2]) {
        row[0] = x;
        row[1] = e->t_s;
        row[2] = d;
      }
      if (isnan(row[3])) row[3] = e->t_s;
      else row[5] = e->t_s - row[4];
      row[4] = e->t_s;
      break;
    }
    case NAV_REQ_OUTAGE_END:
      for (int j = 0; j < ev->n_outages; ++j)
        if (e->t_s >= ev->outages[j].t0_s && e->t_s < ev->outages[j].t1_s) {
          row[2 * j] = x;
          row[2 * j + 1] = e->t_s;
        }
      break;
    default: {
      row[0] += x * x;
      row[1] += 1.0;
      if (row[1] == 1.0 || x > row[2] || isnan(x)) row[2] = x;
      const int k = ev->lay[i].qindex;
      if (k >= 0) {
        if (r->qn[k] == r->qcap[k]) {
          const size_t nc = r->qcap[k] ? 2 * r->qcap[k] : 1024;
          double *g = realloc(r->qv[k], nc * sizeof *g);
          if (!g) return r->st = NAV_ERR_NO_MEMORY;
          r->qv[k] = g;
          r->qcap[k] = nc;
        }
        r->qv[k][r->qn[k]++] = x;
      }
      break;
    }
    }
  }
  return NAV_OK;
}

void nav_req_run_discard(nav_req_run *r) {
  if (!r) return;
  for (int k = 0; k < NAV_SCENE_MAX_REQUIREMENTS; ++k) free(r->qv[k]);
  free(r->row);
  free(r);
}

nav_status nav_req_run_end(nav_req_evaluator *ev, nav_req_run *r) {
  if (!ev || !r || r->ev != ev) {
    nav_req_run_discard(r);
    return NAV_ERR_INVALID_ARG;
  }
  nav_status st = r->st;
  nav_mutex_lock(&ev->lock);
  if (st == NAV_OK && ev->done[r->run]) st = NAV_ERR_INVALID_ARG; /* ended twice */
  if (st == NAV_OK) {
    for (int k = 0; k < ev->nq && st == NAV_OK; ++k) st = qstore_add(&ev->q[k], r->qv[k], r->qn[k]);
  }
  if (st == NAV_OK) {
    memcpy(ev->table + (size_t)r->run * ev->width, r->row, ev->width * sizeof *r->row);
    ev->done[r->run] = 1;
  } else if (ev->failed == NAV_OK) {
    ev->failed = st;
  }
  nav_mutex_unlock(&ev->lock);
  nav_req_run_discard(r);
  return st;
}

nav_status nav_req_evaluator_finish(nav_req_evaluator *ev, nav_requirement_verdict *out) {
  if (!ev || (!out && ev->count > 0)) return NAV_ERR_INVALID_ARG;
  if (ev->failed != NAV_OK) return ev->failed;
  for (int i = 0; i < ev->count; ++i) {
    const nav_requirement *q = &ev->reqs[i];
    nav_requirement_verdict *v = &out[i];
    memset(v, 0, sizeof *v);
    snprintf(v->id, sizeof v->id, "%s", q->id);
    v->metric = q->metric;
    v->statistic = q->statistic;
    v->limit = q->limit;
    v->unit = q->unit;
    v->at_time_s = NAN;
    v->span_t0_s = v->span_t1_s = NAN;
    const double k = nav_req_unit_to_si(q->unit);
    const size_t off = ev->lay[i].off;
    double value = NAN;
    long samples = 0;
    switch (q->statistic) {
    case NAV_REQ_RMS:
    case NAV_REQ_MAX:
    case NAV_REQ_P95:
    case NAV_REQ_CEP50:
    case NAV_REQ_CEP95: {
      double s2 = 0.0, n = 0.0, mx = NAN;
      for (long r = 0; r < ev->runs; ++r) {
        if (!ev->done[r]) continue;
        const double *row = ev->table + (size_t)r * ev->width + off;
        if (row[1] == 0.0) continue;
        s2 += row[0];
        n += row[1];
        if (isnan(mx) || row[2] > mx || isnan(row[2])) mx = row[2];
      }
      samples = (long)n;
      if (n > 0.0) {
        if (q->statistic == NAV_REQ_RMS) value = sqrt(s2 / n);
        else if (q->statistic == NAV_REQ_MAX) value = mx;
        else value = qstore_quantile(&ev->q[ev->lay[i].qindex], quantile_percent(q->statistic));
      }
      break;
    }
    case NAV_REQ_AT_TIME: {
      double s2 = 0.0;
      long n = 0;
      bool outside = false;
      v->span_t0_s = v->span_t1_s = NAN;
      for (long r = 0; r < ev->runs; ++r) {
        if (!ev->done[r]) continue;
        const double *row = ev->table + (size_t)r * ev->width + off;
        if (isnan(row[1])) continue;
        if (n == 0) {
          v->at_time_s = row[1];
          v->span_t0_s = row[3];
          v->span_t1_s = row[4];
        }
        /* Beyond half an epoch spacing past the first or last epoch, the nearest epoch is not at
         * time_s: the run does not reach that time. 1e-9 relative covers rounding of the grid. */
        const double tol = 0.5 * row[5] + 1e-9 * fmax(1.0, fabs(q->time_s));
        if (q->time_s < row[3] - tol || q->time_s > row[4] + tol) outside = true;
        s2 += row[0] * row[0];
        ++n;
      }
      samples = n;
      if (n > 0 && !outside) value = sqrt(s2 / (double)n);
      if (outside) {
        v->na_reason = NAV_REQ_NA_TIME_OUTSIDE;
        v->at_time_s = q->time_s;
        samples = 0;
      }
      break;
    }
    case NAV_REQ_OUTAGE_END: {
      v->outage_count = ev->n_outages;
      for (int j = 0; j < ev->n_outages; ++j) {
        double s2 = 0.0;
        long n = 0;
        v->outage_t0_s[j] = ev->outages[j].t0_s;
        v->outage_t1_s[j] = ev->outages[j].t1_s;
        v->outage_end_t_s[j] = NAN;
        for (long r = 0; r < ev->runs; ++r) {
          if (!ev->done[r]) continue;
          const double *cell = ev->table + (size_t)r * ev->width + off + 2 * (size_t)j;
          const double x = cell[0];
          if (isnan(cell[1])) continue;
          if (n == 0) v->outage_end_t_s[j] = cell[1];
          s2 += x * x;
          ++n;
        }
        v->outage_value[j] = n > 0 ? sqrt(s2 / (double)n) / k : NAN;
        samples += n;
        if (n > 0 && (isnan(value) || v->outage_value[j] * k > value)) value = v->outage_value[j] * k;
      }
      break;
    }
    }
    v->samples = samples;
    v->evaluated = !isnan(value);
    v->value = v->evaluated ? value / k : NAN;
    /* Not evaluated is never a pass, not even outage_end without an outage. */
    v->pass = v->evaluated && v->value <= v->limit;
    if (v->evaluated) v->na_reason = NAV_REQ_NA_NONE;
    else if (v->na_reason == NAV_REQ_NA_NONE)
      v->na_reason = q->statistic == NAV_REQ_OUTAGE_END && ev->n_outages == 0 ? NAV_REQ_NA_NO_OUTAGE
                                                                            : NAV_REQ_NA_NO_DATA;
  }
  return NAV_OK;
}

/* ---------------------------------------------------------------- observer */

static void *obs_begin(void *user, long run) {
  nav_req_run *r = NULL;
  return nav_req_run_begin(user, run, &r) == NAV_OK ? r : NULL;
}
static void obs_epoch(void *ctx, const nav_epoch_errors *e) {
  if (ctx && nav_req_run_add(ctx, e) != NAV_OK) {
    /* recorded in the run; nav_req_run_end reports it to the evaluator */
  }
}
static void obs_end(void *user, void *ctx, bool complete) {
  if (!ctx) return;
  if (complete) {
    if (nav_req_run_end(user, ctx) != NAV_OK) {
      /* kept in the evaluator: nav_req_evaluator_finish returns it */
    }
  }
  else nav_req_run_discard(ctx);
}

nav_run_observer nav_req_evaluator_observer(nav_req_evaluator *ev) {
  nav_run_observer o = {obs_begin, obs_epoch, obs_end, ev};
  return o;
}

/* ================================================================ prediction from covariance */

/* P(|x| <= r), x ~ N(0, s^2), and its derivative in r (*dens). */
static double cdf_abs_normal(double r, double s, double *dens) {
  if (!(s > 0.0)) {
    *dens = 0.0;
    return r >= 0.0 ? 1.0 : 0.0;
  }
  *dens = sqrt(2.0 / NAV_PI) / s * exp(-0.5 * (r / s) * (r / s));
  return erf(r / (sqrt(2.0) * s));
}

/* Nodes of the first look at the stop rule of cdf_radius, and the most it doubles to. */
#define CDF_RADIUS_MIN_NODES 8
#define CDF_RADIUS_MAX_NODES (1 << 21)

/*
 * P(hypot(x, y) <= r), x ~ N(0, a^2), y ~ N(0, b^2) independent, and its derivative in r (*dens).
 * docs/estimate-cep.md derives it: with e = b / a (a >= b) and tan(phi) = tan(theta) / sqrt(e),
 *   P = (2/pi) int_0^{pi/2} J(theta) (1 - exp(-X(theta))) dtheta,
 *   dP/dr = (2/pi) r / (a b) int_0^{pi/2} J(theta) exp(-X(theta)) D(theta) / N(theta) dtheta,
 * N = cos^2 + e sin^2, D = e cos^2 + sin^2, J = sqrt(e) / D, X = r^2 D / (2 a b N).
 * The integrands are smooth and even about 0 and pi/2 (one quarter of a periodic function), so the
 * trapezoid rule with halved end nodes converges geometrically: the node count doubles (every new
 * node midway between old ones) until P changes by at most 1e-15 (plus the sum's rounding,
 * sqrt(nodes) ulps of P) and dP/dr by at most 1e-9 of itself (the root finder needs only the
 * slope's direction and scale), looked at first with a node spacing at most sqrt(e), the width
 * of the integrand's features. 1 - exp is taken as -expm1 so a
 * small P keeps its relative accuracy. b below 1e-9 a: the 1-D |x| <= r (the y part adds < 1e-9 a).
 */
static double cdf_radius(double r, double a, double b, double *dens) {
  *dens = 0.0;
  if (!(r > 0.0)) return 0.0;
  if (a < b) {
    const double t = a;
    a = b;
    b = t;
  }
  if (!(a > 0.0)) return 1.0;
  if (!(b > 0.0) || b < 1e-9 * a) return cdf_abs_normal(r, a, dens);
  const double e = b / a, se = sqrt(e);
  const double w = (r / a) * (r / b) * 0.5; /* r^2 / (2 a b) */
  const double quarter = 0.5 * NAV_PI;
  int first = CDF_RADIUS_MIN_NODES;
  while (first < CDF_RADIUS_MAX_NODES && quarter / first > se) first *= 2;
  double sp = 0.0, sd = 0.0; /* sums over the nodes so far, end nodes halved */
  for (int k = 0; k <= 1; ++k) {
    const double th = quarter * k, c = cos(th), s = sin(th);
    const double den = e * c * c + s * s, num = c * c + e * s * s;
    const double x = w * den / num, jac = se / den;
    sp += 0.5 * jac * -expm1(-x);
    sd += 0.5 * jac * exp(-x) * den / num;
  }
  double p = 0.0, d = 0.0;
  for (int n = 1; n < CDF_RADIUS_MAX_NODES; n *= 2) {
    const double h = quarter / n;
    for (int k = 0; k < n; ++k) { /* the new nodes, midway between the n + 1 old ones */
      const double th = (k + 0.5) * h, c = cos(th), s = sin(th);
      const double den = e * c * c + s * s, num = c * c + e * s * s;
      const double x = w * den / num, jac = se / den;
      sp += jac * -expm1(-x);
      sd += jac * exp(-x) * den / num;
    }
    const double pn = sp * (0.5 * h) / quarter, dn = sd * (0.5 * h) / quarter;
    /* The sum's own rounding grows like sqrt(nodes) ulps of P: a change below it is converged. */
    const double ptol = 1e-15 + DBL_EPSILON * sqrt(2.0 * n) * pn;
    const bool settled = 2 * n >= first && fabs(pn - p) <= ptol && fabs(dn - d) <= 1e-9 * dn;
    p = pn;
    d = dn;
    if (settled) break;
  }
  *dens = d * (r / a) / b;
  return fmin(1.0, fmax(0.0, p));
}

typedef struct pred_point {
  double a, b; /* sigmas of the 1-D (a) or 2-D (a, b) Gaussian of the metric */
  bool radial; /* 2-D radius, else |1-D| */
} pred_point;

/* One point's CDF at @p r and its derivative (*dens). */
static double point_cdf(const pred_point *p, double r, double *dens) {
  return p->radial ? cdf_radius(r, p->a, p->b, dens) : cdf_abs_normal(r, p->a, dens);
}

/*
 * The points' CDFs and densities at one radius computed by helper threads: helper k fills
 * cdf/dens[lo_k, hi_k) (a contiguous share of the points after the caller's own), which the
 * caller reads after joining it and adds in point order: each value is the same pure function of
 * (r, point), whoever computes it, so the sums are those of the one-thread loop.
 */
typedef struct mix_share {
  const pred_point *p;
  double r;
  double *cdf, *dens;
  size_t lo, hi;
} mix_share;

static int mix_share_run(void *arg) {
  mix_share *s = arg;
  for (size_t i = s->lo; i < s->hi; ++i) s->cdf[i] = point_cdf(&s->p[i], s->r, &s->dens[i]);
  return 0;
}

/* Helper threads of mixture_quantile (at most NAV_REQ_MAX_THREADS - 1) and their value buffers. */
#define NAV_REQ_MAX_THREADS 16
typedef struct mix_pool {
  int helpers;        /* 0: the one-thread loop */
  double *cdf, *dens; /* n values each */
  size_t own;         /* the caller computes points [0, own) itself */
} mix_pool;

/* The mixture CDF at @p r (the mean of the points' CDFs, summed in point order) and its
 * derivative (*dens), with the helpers of @p pool (NULL: none). */
static double mixture_cdf(const pred_point *p, size_t n, double r, const mix_pool *pool, double *dens) {
  mix_share sh[NAV_REQ_MAX_THREADS];
  nav_thread th[NAV_REQ_MAX_THREADS];
  nav_thread_call calls[NAV_REQ_MAX_THREADS];
  bool started[NAV_REQ_MAX_THREADS] = {false};
  const int nh = pool ? pool->helpers : 0;
  const size_t own = nh > 0 ? pool->own : n;
  for (int k = 0; k < nh; ++k) {
    const size_t rest = n - own;
    sh[k] = (mix_share){p, r, pool->cdf, pool->dens, own + rest * (size_t)k / (size_t)nh,
                        own + rest * (size_t)(k + 1) / (size_t)nh};
    started[k] = nav_thread_start(&th[k], &calls[k], mix_share_run, &sh[k]);
    if (!started[k]) mix_share_run(&sh[k]); /* a helper that could not start: its share here */
  }
  double s = 0.0, sd = 0.0;
  for (size_t i = 0; i < own; ++i) {
    double di;
    s += point_cdf(&p[i], r, &di);
    sd += di;
  }
  for (int k = 0; k < nh; ++k) {
    if (started[k]) nav_thread_join(th[k]);
    for (size_t i = sh[k].lo; i < sh[k].hi; ++i) {
      s += pool->cdf[i];
      sd += pool->dens[i];
    }
  }
  *dens = sd / (double)n;
  return s / (double)n;
}

/* Relative width of the quantile's last step or bracket. */
#define MIX_QUANTILE_RTOL 1e-13

/*
 * r with mixture CDF F(r) = q: Newton's method on F(r) - q with the exact derivative, kept inside
 * a bracket [lo, hi] with F(lo) < q <= F(hi) (from [0, 10 sigma_max]); a step that leaves the
 * bracket, or a zero slope, bisects instead. Stops when the step or the bracket is within 1e-13
 * of r (docs/estimate-cep.md). @p threads computing it (the same value for any count).
 */
static double mixture_quantile(const pred_point *p, size_t n, double q, int threads) {
  double hi = 0.0, ms = 0.0;
  for (size_t i = 0; i < n; ++i) {
    hi = fmax(hi, p[i].radial ? hypot(p[i].a, p[i].b) : p[i].a);
    ms += p[i].a * p[i].a + (p[i].radial ? p[i].b * p[i].b : 0.0);
  }
  if (!(hi > 0.0)) return 0.0;
  mix_pool pool = {0, NULL, NULL, n};
  if (threads > NAV_REQ_MAX_THREADS) threads = NAV_REQ_MAX_THREADS;
  /* Helpers only where there is enough work to share (a few hundred points and more). */
  if (threads > 1 && n >= 256u) {
    pool.cdf = malloc(2 * n * sizeof *pool.cdf);
    if (pool.cdf) {
      pool.dens = pool.cdf + n;
      pool.helpers = threads - 1;
      pool.own = n / (size_t)threads;
    }
  }
  const mix_pool *pp = pool.helpers > 0 ? &pool : NULL;
  hi *= 10.0; /* P(|x| > 10 sigma_max) < 1e-20 */
  const double hi0 = hi;
  double lo = 0.0;
  /* Start at the points' RMS radius (inside the bracket unless the input is NaN). */
  double r = sqrt(ms / (double)n);
  if (!(r > lo && r < hi)) r = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    double dens;
    const double f = mixture_cdf(p, n, r, pp, &dens) - q;
    if (f != f) { /* a NaN point: F is never >= q, as the bisection had it: the bracket's top */
      r = hi0;
      break;
    }
    if (f >= 0.0) hi = r;
    else lo = r;
    if (f == 0.0 || hi - lo <= MIX_QUANTILE_RTOL * hi) break;
    double next = dens > 0.0 ? r - f / dens : NAN;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool small = fabs(next - r) <= MIX_QUANTILE_RTOL * r;
    r = next;
    if (small) break;
  }
  free(pool.cdf);
  return r;
}

/* E[metric^2] at one covariance epoch (NaN: not predicted). */
static double mean_square(nav_req_metric m, const nav_cov_point *c) {
  const nav_vec3 p = c->pos_sd_n_m, v = c->vel_sd_n_mps, a = c->att_sd_rad;
  switch (m) {
  case NAV_REQ_HORIZONTAL_POSITION: return p.x * p.x + p.y * p.y;
  case NAV_REQ_VERTICAL_POSITION: return p.z * p.z;
  case NAV_REQ_POSITION_3D: return p.x * p.x + p.y * p.y + p.z * p.z;
  case NAV_REQ_VELOCITY: return v.x * v.x + v.y * v.y + v.z * v.z;
  case NAV_REQ_ROLL_PITCH: return a.x * a.x + a.y * a.y;
  case NAV_REQ_YAW: return a.z * a.z;
  }
  return NAN;
}

nav_status nav_req_predict(const nav_requirement *reqs, int count, const nav_cov_point *pts, size_t npts,
                           const nav_req_interval *outages, int n_outages, nav_requirement_verdict *out) {
  return nav_req_predict_threads(reqs, count, pts, npts, outages, n_outages, 1, out);
}

nav_status nav_req_predict_threads(const nav_requirement *reqs, int count, const nav_cov_point *pts, size_t npts,
                                   const nav_req_interval *outages, int n_outages, int threads,
                                   nav_requirement_verdict *out) {
  if ((count > 0 && (!reqs || !out)) || (npts > 0 && !pts) || n_outages < 0 || (n_outages > 0 && !outages))
    return NAV_ERR_INVALID_ARG;
  if (nav_requirements_validate(reqs, count, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  if (n_outages > NAV_REQ_MAX_OUTAGES) n_outages = NAV_REQ_MAX_OUTAGES;
  pred_point *pp = NULL;
  for (int i = 0; i < count; ++i) {
    const nav_requirement *q = &reqs[i];
    nav_requirement_verdict *v = &out[i];
    memset(v, 0, sizeof *v);
    snprintf(v->id, sizeof v->id, "%s", q->id);
    v->metric = q->metric;
    v->statistic = q->statistic;
    v->limit = q->limit;
    v->unit = q->unit;
    v->at_time_s = NAN;
    v->span_t0_s = v->span_t1_s = NAN;
    const double k = nav_req_unit_to_si(q->unit);
    double value = NAN;
    long samples = 0;
    if (npts == 0) {
      /* nothing to predict from */
    } else if (q->statistic == NAV_REQ_RMS) {
      double s = 0.0;
      for (size_t j = 0; j < npts; ++j) s += mean_square(q->metric, &pts[j]);
      value = sqrt(s / (double)npts);
      samples = (long)npts;
    } else if (q->statistic == NAV_REQ_AT_TIME) {
      size_t best = 0;
      for (size_t j = 1; j < npts; ++j)
        if (fabs(pts[j].t_s - q->time_s) < fabs(pts[best].t_s - q->time_s)) best = j;
      v->at_time_s = pts[best].t_s;
      v->span_t0_s = pts[0].t_s;
      v->span_t1_s = pts[npts - 1].t_s;
      /* As the evaluator: half the spacing of the last two points beyond the span. */
      const double tol = 0.5 * (npts > 1 ? pts[npts - 1].t_s - pts[npts - 2].t_s : 0.0) +
                         1e-9 * fmax(1.0, fabs(q->time_s));
      if (q->time_s < pts[0].t_s - tol || q->time_s > pts[npts - 1].t_s + tol) {
        v->na_reason = NAV_REQ_NA_TIME_OUTSIDE;
        v->at_time_s = q->time_s;
      } else {
        value = sqrt(mean_square(q->metric, &pts[best]));
        samples = 1;
      }
    } else if (q->statistic == NAV_REQ_OUTAGE_END) {
      v->outage_count = n_outages;
      for (int o = 0; o < n_outages; ++o) {
        v->outage_t0_s[o] = outages[o].t0_s;
        v->outage_t1_s[o] = outages[o].t1_s;
        v->outage_end_t_s[o] = NAN;
        v->outage_value[o] = NAN;
        for (size_t j = 0; j < npts; ++j)
          if (pts[j].t_s >= outages[o].t0_s && pts[j].t_s < outages[o].t1_s) {
            v->outage_end_t_s[o] = pts[j].t_s;
            v->outage_value[o] = sqrt(mean_square(q->metric, &pts[j])) / k;
          }
        if (!isnan(v->outage_value[o])) {
          ++samples;
          if (isnan(value) || v->outage_value[o] * k > value) value = v->outage_value[o] * k;
        }
      }
    } else if (nav_req_statistic_is_quantile(q->statistic) &&
               (q->metric == NAV_REQ_HORIZONTAL_POSITION || q->metric == NAV_REQ_VERTICAL_POSITION ||
                q->metric == NAV_REQ_YAW)) {
      if (!pp) {
        pp = malloc(npts * sizeof *pp);
        if (!pp) return NAV_ERR_NO_MEMORY;
      }
      for (size_t j = 0; j < npts; ++j) {
        pp[j].radial = q->metric == NAV_REQ_HORIZONTAL_POSITION;
        pp[j].a = q->metric == NAV_REQ_HORIZONTAL_POSITION ? pts[j].pos_sd_n_m.x
                  : q->metric == NAV_REQ_VERTICAL_POSITION  ? pts[j].pos_sd_n_m.z
                                                            : pts[j].att_sd_rad.z;
        pp[j].b = pts[j].pos_sd_n_m.y;
      }
      value = mixture_quantile(pp, npts, quantile_percent(q->statistic) / 100.0, threads);
      samples = (long)npts;
    }
    v->samples = samples;
    v->evaluated = isfinite(value);
    v->value = v->evaluated ? value / k : NAN;
    v->pass = v->evaluated && v->value <= v->limit;
    if (v->evaluated) v->na_reason = NAV_REQ_NA_NONE;
    else if (v->na_reason == NAV_REQ_NA_NONE)
      v->na_reason = npts == 0                                               ? NAV_REQ_NA_NOT_PREDICTED
                     : q->statistic == NAV_REQ_OUTAGE_END && n_outages == 0 ? NAV_REQ_NA_NO_OUTAGE
                     : q->statistic == NAV_REQ_OUTAGE_END                   ? NAV_REQ_NA_NO_DATA
                                                                            : NAV_REQ_NA_NOT_PREDICTED;
  }
  free(pp);
  return NAV_OK;
}

typedef struct cov_buf {
  nav_cov_point *p;
  size_t n, cap;
  bool failed;
} cov_buf;

/* A covariance-analysis epoch (nav_sim_covariance) into the buffer. */
static nav_callback_result keep_cov_point(void *user, const nav_cov_point *p) {
  cov_buf *b = user;
  if (b->n == b->cap) {
    const size_t nc = b->cap ? 2 * b->cap : 1024;
    nav_cov_point *g = realloc(b->p, nc * sizeof *g);
    if (!g) {
      b->failed = true;
      return NAV_STOP;
    }
    b->p = g;
    b->cap = nc;
  }
  b->p[b->n++] = *p;
  return NAV_CONTINUE;
}

/* A budget epoch's total covariance as a covariance-analysis epoch, into the buffer. */
static nav_callback_result keep_point(void *user, const nav_budget_epoch *e) {
  nav_cov_point q;
  memset(&q, 0, sizeof q);
  q.t_s = e->t_s;
  q.pos_sd_n_m = nav_vec3_make(sqrt(e->total.v[0]), sqrt(e->total.v[1]), sqrt(e->total.v[2]));
  q.pos_h_sd_m = hypot(q.pos_sd_n_m.x, q.pos_sd_n_m.y);
  q.vel_sd_n_mps = nav_vec3_make(sqrt(e->total.v[3]), sqrt(e->total.v[4]), sqrt(e->total.v[5]));
  q.att_sd_rad = nav_vec3_make(sqrt(e->total.v[6]), sqrt(e->total.v[7]), sqrt(e->total.v[8]));
  return keep_cov_point(user, &q);
}

bool nav_req_predict_scene_uses_sim_covariance(const nav_scene *scene) {
  return scene && (scene->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
                   scene->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT);
}

/* The checks of nav_req_predict_scene and the scene's outages (@p iv, @p ni). */
static nav_status predict_scene_begin(const nav_scene *scene, nav_requirement_verdict *out, nav_req_interval *iv,
                                      int *ni) {
  if (!scene || (scene->n_requirements > 0 && !out)) return NAV_ERR_INVALID_ARG;
  if (scene->earth.model != NAV_EARTH_WGS84 || scene->navigation.scheme == NAV_SCHEME_GYRO_FREE)
    return NAV_ERR_INVALID_ARG;
  *ni = 0;
  nav_status st = NAV_OK;
  if (scene->navigation.scheme == NAV_SCHEME_INS_GNSS || nav_req_predict_scene_uses_sim_covariance(scene))
    st = nav_req_scene_outages(scene, iv, NAV_REQ_MAX_OUTAGES, ni);
  if (st != NAV_OK) return st;
  if (nav_scene_validate(scene, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  return NAV_OK;
}

nav_status nav_req_predict_scene_points(const nav_scene *scene, const nav_cov_point *pts, size_t npts,
                                        nav_requirement_verdict *out) {
  return nav_req_predict_scene_points_threads(scene, pts, npts, 1, out);
}

nav_status nav_req_predict_scene_points_threads(const nav_scene *scene, const nav_cov_point *pts, size_t npts,
                                                int threads, nav_requirement_verdict *out) {
  if (!nav_req_predict_scene_uses_sim_covariance(scene)) return NAV_ERR_INVALID_ARG;
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  const nav_status st = predict_scene_begin(scene, out, iv, &ni);
  if (st != NAV_OK) return st;
  return nav_req_predict_threads(scene->requirements, scene->n_requirements, pts, npts, iv, ni, threads, out);
}

nav_status nav_req_predict_scene_total_points_threads(const nav_scene *scene, const nav_cov_point *pts, size_t npts,
                                                      int threads, nav_requirement_verdict *out) {
  if (npts > 0 && !pts) return NAV_ERR_INVALID_ARG;
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  const nav_status st = predict_scene_begin(scene, out, iv, &ni);
  if (st != NAV_OK) return st;
  return nav_req_predict_threads(scene->requirements, scene->n_requirements, pts, npts, iv, ni, threads, out);
}

nav_status nav_req_predict_scene(const nav_scene *scene, nav_requirement_verdict *out) {
  return nav_req_predict_scene_threads(scene, 1, out);
}

nav_status nav_req_predict_scene_threads(const nav_scene *scene, int threads, nav_requirement_verdict *out) {
  /* gyro_free_gnss and ins_gnss_tight: their filters' covariance analysis (nav_sim_covariance). */
  const bool gfg = nav_req_predict_scene_uses_sim_covariance(scene);
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  nav_status st = predict_scene_begin(scene, out, iv, &ni);
  if (st != NAV_OK) return st;
  cov_buf b = {NULL, 0, 0, false};
  if (gfg) {
    /* gyro_free_gnss: its filter's covariance analysis (no consider states: the scheme refuses
     * the scale-factor terms the filter does not estimate). ins_gnss_tight: its filter's
     * covariance analysis too, without consider states (docs/ins-gnss-tight.md 6). */
    nav_sim *sim = NULL;
    st = nav_sim_create(scene, &sim);
    if (st == NAV_OK) st = nav_sim_covariance(sim, keep_cov_point, &b);
    nav_sim_destroy(sim);
  } else {
    st = nav_budget_run(scene, false, keep_point, &b, NULL, NULL, 0);
  }
  if (b.failed) st = NAV_ERR_NO_MEMORY;
  if (st == NAV_OK)
    st = nav_req_predict_threads(scene->requirements, scene->n_requirements, b.p, b.n, iv, ni, threads, out);
  free(b.p);
  return st;
}
