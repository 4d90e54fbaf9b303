/*
 * navsim select: the cheapest catalog configuration (IMU, GNSS receiver, scheme) that meets the
 * scene's requirements.
 *
 * 1. Every combination is predicted by the covariance analysis of its scheme along the scene's
 *    reference trajectory (nav_req_predict_scene, at a reduced IMU rate: --predict-rate), on
 *    worker threads.
 * 2. Requirements are classified with the band factor B (--band, default 1.5): predicted value
 *    <= limit / B clearly passes, >= limit x B clearly fails, between is near the limit; a
 *    statistic the sigmas do not determine (max, p95 of 3-D position) is near the limit too. A
 *    configuration with a clear failure fails; one whose requirements all pass clearly passes;
 *    the others survive.
 * 3. Survivors are simulated by Monte Carlo (--runs, the scene's seed, the evaluator of
 *    nav_requirements.h) in order of cost, but only while they can still be the recommendation:
 *    not when they cost more than a configuration that already passed (clearly by prediction or
 *    by simulation).
 * 4. ranking.csv lists every configuration, passing ones first from the cheapest; the
 *    recommendation is the first row. The cost of a configuration is the middle of the cost
 *    bands (nav_catalog_cost_band) of its IMU and, for schemes with GNSS, of its receiver:
 *    class k -> 3 x 10^k USD (order of magnitude only).
 */
#define _POSIX_C_SOURCE 200809L
#include "cli_util.h"
#include "select_cmd.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

#include "catalog_cmd.h"
#include "navcore/nav_array.h"
#include "navcore/nav_catalog.h"
#include "navcore/nav_io.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };

static const char *k_usage_select =
    "usage: navsim select SCENE [--imus NAMES|all] [--receivers NAMES|all] [--schemes LIST]\n"
    "                    [--array-parts NAMES|all] [--runs N]\n"
    "                    [--threads N] [--band F] [--predict-rate HZ] --out DIR [--force] [--quiet]\n"
    "\n"
    "Find the least expensive catalog configuration that meets the scene's requirements. Each\n"
    "combination of IMU (resources/imu_catalog.csv), GNSS receiver (gnss_receivers.csv) and scheme\n"
    "replaces the scene's sensors by the catalog models (as imu: {catalog: NAME} would; the scene's\n"
    "rate, lever arm, latency and outages are kept), then:\n"
    "  predict   covariance analysis of the scheme along the trajectory (nav_req_predict; the\n"
    "            quantiles p95/cep from at most 150 evenly spaced output epochs)\n"
    "  prune     predicted <= limit / F passes clearly, >= limit x F fails clearly (F = --band,\n"
    "            default 1.5); statistics the sigmas cannot predict (max) count as near the limit\n"
    "  confirm   Monte Carlo of the configurations near the limit, cheapest first, while they can\n"
    "            still be the recommendation (not when a cheaper-or-equal one already passed)\n"
    "Writes into DIR (atomically):\n"
    "  ranking.csv  rank, imu, receiver, scheme, cost classes and cost index, then per requirement\n"
    "               the predicted value, the simulated value (empty when not simulated) and pass,\n"
    "               then pass (true, false, or not_confirmed: near the limit but costlier than a\n"
    "               passing configuration, so not simulated), decided_by (prediction or\n"
    "               monte_carlo) and the margin (smallest (limit - value) / limit); passing\n"
    "               configurations first, cheapest first, then not_confirmed, then failing ones\n"
    "  recommended.yaml  the scene with the recommended configuration\n"
    "The terminal shows the recommendation and why each cheaper configuration fails.\n" NAVSIM_OUT_HELP "\n"
    "options:\n"
    "  --imus NAMES       IMU names separated by commas, or all (default)\n"
    "  --receivers NAMES  receiver modes separated by commas, or all (default)\n"
    "  --schemes LIST     free_ins, ins_gnss and/or gyro_free_gnss, comma-separated (default: the\n"
    "                     scene's scheme); gyro_free_gnss puts the catalog IMU's accelerometers\n"
    "                     (noise, turn-on and Gauss-Markov bias; not its scale factors or bias random\n"
    "                     walk) into every sensor of the scene's array (layout and arm kept)\n"
    "  --array-parts NAMES  gyro_free_gnss ranges over these accelerometer parts\n"
    "                     (resources/accel_catalog.csv, comma-separated, or all) instead of the\n"
    "                     IMUs' accelerometers: each fills every sensor of the scene's array (the\n"
    "                     scale factor left out: the filter has no states for it); the imu column\n"
    "                     of ranking.csv then names the part, its cost index is N sensors x part\n"
    "  --runs N           Monte Carlo runs per confirmed configuration (default 20)\n"
    "  --threads N        worker threads (default one per core); results do not depend on it\n"
    "  --band F           pruning band factor > 1 (default 1.5)\n"
    "  --predict-rate HZ  IMU rate of the covariance prediction (default 10, at most the scene's;\n"
    "                     the scene's rate when the reduced one is not a multiple of the output rate)\n"
    "\n"
    "exit codes: 0 a configuration passes; 3 none passes; 2 invalid scene or options; 1 other failure\n";

enum { DEC_PREDICTION = 0, DEC_MONTE_CARLO = 1 };

typedef struct combo {
  int imu, gnss; /* catalog indices; gnss -1: no receiver (free_ins) */
  int part;      /* accelerometer-part index of a gyro_free_gnss array (--array-parts); -1: none */
  nav_nav_scheme scheme;
  int imu_cls, gnss_cls;
  double cost_usd;
  nav_requirement_verdict *pred, *sim; /* n_req each; sim NULL when not simulated */
  nav_status pred_st;
  int cls;        /* 1 clear pass, -1 clear fail, 0 near */
  bool pass;
  bool unconfirmed; /* near the limit and not simulated (costlier than a passing configuration) */
  int decided;
  double margin;
  char why[512];  /* first failing requirement, for the terminal */
} combo;

typedef struct ctx {
  const nav_scene *base;
  const nav_catalog *imus, *gnss, *parts;
  combo *c;
  size_t n;
  int n_req;
  double band;
  double predict_rate;
  pthread_mutex_t mu;
  size_t next;
} ctx;

static double class_usd(int k) { return k >= 1 ? 3.0 * pow(10.0, k) : 0.0; }

static double vmax3(nav_vec3 v) { return fmax(fmax(v.x, v.y), v.z); }

/*
 * gyro_free_gnss: every sensor of the scene's array (its layout and arm) gets the error model of
 * the catalog IMU's accelerometers: white noise, turn-on bias (random and fixed parts as one
 * sigma) and Gauss-Markov bias, the largest axis of each. The terms the array model does not
 * have (scale factor: not estimated by the gyro-free filter, refused by the scheme; bias random
 * walk, misalignment, quantisation, range) are left out, so the array is somewhat optimistic.
 */
static nav_array_error_config array_accel_of(const nav_accel_error_config *a) {
  nav_array_error_config o = nav_array_error_config_default();
  if (a->terms & NAV_IMU_TERM_NOISE) {
    o.terms |= NAV_IMU_TERM_NOISE;
    o.vrw_mps_per_sqrt_s = vmax3(a->vrw_mps_per_sqrt_s);
  }
  if (a->terms & NAV_IMU_TERM_BIAS_TURN_ON) {
    o.terms |= NAV_IMU_TERM_BIAS_TURN_ON;
    o.bias_turn_on_sd_mps2 = hypot(vmax3(a->bias_turn_on_sd_mps2),
                                   fmax(fmax(fabs(a->bias_turn_on_fixed_mps2.x), fabs(a->bias_turn_on_fixed_mps2.y)),
                                        fabs(a->bias_turn_on_fixed_mps2.z)));
  }
  if (a->terms & NAV_IMU_TERM_BIAS_GM) {
    o.terms |= NAV_IMU_TERM_BIAS_GM;
    o.bias_gm_sd_mps2 = vmax3(a->bias_gm_sd_mps2);
    o.bias_gm_tau_s = vmax3(a->bias_gm_tau_s);
  }
  return o;
}

/* The scene of a combination (heap). */
static nav_status make_scene(const ctx *x, const combo *c, nav_scene *sc) {
  *sc = *x->base;
  sc->navigation.scheme = c->scheme;
  if (c->part >= 0) {
    /* An array part: every sensor gets its datasheet model; the IMU section is not used. */
    const nav_catalog_accel_entry *pe = nav_catalog_accel_at(x->parts, (size_t)c->part);
    sc->array.accel = pe->config;
    sc->array.accel.terms &= ~(unsigned)NAV_IMU_TERM_SCALE_FACTOR;
    snprintf(sc->array.catalog, sizeof sc->array.catalog, "%s", pe->name);
  } else {
    const nav_catalog_imu_entry *ie = nav_catalog_imu_at(x->imus, (size_t)c->imu);
    sc->imu.model = ie->config;
    snprintf(sc->imu.catalog, sizeof sc->imu.catalog, "%s", ie->name);
    if (c->scheme == NAV_SCHEME_GYRO_FREE_GNSS) sc->array.accel = array_accel_of(&ie->config.accel);
  }
  if (c->gnss >= 0) {
    const nav_catalog_gnss_entry *ge = nav_catalog_gnss_at(x->gnss, (size_t)c->gnss);
    const nav_gnss_model_config old = x->base->gnss.model;
    nav_gnss_model_config g = ge->config;
    g.latency_s = old.latency_s;
    g.r_ba_b_m = old.r_ba_b_m;
    g.report_model_sigmas = old.report_model_sigmas;
    g.reported_pos_sd_m = old.reported_pos_sd_m;
    g.reported_vel_sd_mps = old.reported_vel_sd_mps;
    g.outage_count = old.outage_count;
    memcpy(g.outages, old.outages, sizeof g.outages);
    sc->gnss.model = g;
    sc->gnss.enabled = true;
    snprintf(sc->gnss.catalog, sizeof sc->gnss.catalog, "%s", ge->name);
  }
  return nav_scene_validate(sc, NULL, NULL);
}

typedef struct cov_keep {
  nav_cov_point *p;
  size_t n, cap;
  bool oom;
} cov_keep;

static nav_callback_result keep_point(void *user, const nav_cov_point *p) {
  cov_keep *k = user;
  if (k->n == k->cap) {
    const size_t cap = k->cap ? 2 * k->cap : 4096;
    nav_cov_point *q = realloc(k->p, cap * sizeof *q);
    if (!q) {
      k->oom = true;
      return NAV_STOP;
    }
    k->p = q;
    k->cap = cap;
  }
  k->p[k->n++] = *p;
  return NAV_CONTINUE;
}

/* Most output epochs entering the predicted quantiles (p95, cep50, cep95). */
#define QUANTILE_EPOCHS 150

/*
 * nav_req_predict_scene, with the quantile statistics predicted from at most QUANTILE_EPOCHS
 * evenly spaced output epochs (their mixture CDF costs a quadrature per epoch and bisection
 * step; the quantile of the mixture barely moves when the epochs are thinned), the others from
 * every epoch.
 */
nav_status navsim_predict_requirements(const nav_scene *sc, nav_requirement_verdict *out) {
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  nav_status st = NAV_OK;
  if (sc->navigation.scheme == NAV_SCHEME_INS_GNSS || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
      sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT)
    st = nav_req_scene_outages(sc, iv, NAV_REQ_MAX_OUTAGES, &ni);
  if (st != NAV_OK) return st;
  nav_sim *sim = NULL;
  st = nav_sim_create(sc, &sim);
  if (st != NAV_OK) return st;
  cov_keep k = {NULL, 0, 0, false};
  st = nav_sim_covariance(sim, keep_point, &k);
  nav_sim_destroy(sim);
  if (k.oom) st = NAV_ERR_NO_MEMORY;
  const int nr = sc->n_requirements;
  nav_requirement q[NAV_SCENE_MAX_REQUIREMENTS], o[NAV_SCENE_MAX_REQUIREMENTS];
  int iq[NAV_SCENE_MAX_REQUIREMENTS], io[NAV_SCENE_MAX_REQUIREMENTS], nq = 0, no = 0;
  for (int r = 0; r < nr; ++r) {
    if (nav_req_statistic_is_quantile(sc->requirements[r].statistic)) {
      iq[nq] = r;
      q[nq++] = sc->requirements[r];
    } else {
      io[no] = r;
      o[no++] = sc->requirements[r];
    }
  }
  nav_requirement_verdict vq[NAV_SCENE_MAX_REQUIREMENTS], vo[NAV_SCENE_MAX_REQUIREMENTS];
  if (st == NAV_OK && no > 0) st = nav_req_predict(o, no, k.p, k.n, iv, ni, vo);
  if (st == NAV_OK && nq > 0) {
    const size_t stride = k.n > QUANTILE_EPOCHS ? (k.n + QUANTILE_EPOCHS - 1) / QUANTILE_EPOCHS : 1;
    size_t m = 0;
    for (size_t i = 0; i < k.n; i += stride) k.p[m++] = k.p[i];
    st = nav_req_predict(q, nq, k.p, m, iv, ni, vq);
  }
  if (st == NAV_OK) {
    for (int j = 0; j < no; ++j) out[io[j]] = vo[j];
    for (int j = 0; j < nq; ++j) out[iq[j]] = vq[j];
  }
  free(k.p);
  return st;
}

static void *predict_worker(void *arg) {
  ctx *x = arg;
  nav_scene *sc = malloc(sizeof *sc);
  if (!sc) return NULL;
  for (;;) {
    pthread_mutex_lock(&x->mu);
    const size_t i = x->next++;
    pthread_mutex_unlock(&x->mu);
    if (i >= x->n) break;
    combo *c = &x->c[i];
    c->pred_st = make_scene(x, c, sc);
    if (c->pred_st != NAV_OK) continue;
    /* A reduced IMU rate for the covariance propagation when it stays a multiple of the output
       rate and the scene stays valid. */
    if (x->predict_rate > 0 && x->predict_rate < sc->imu.rate_hz) {
      const double old = sc->imu.rate_hz;
      sc->imu.rate_hz = x->predict_rate;
      if (nav_scene_validate(sc, NULL, NULL) != NAV_OK) sc->imu.rate_hz = old;
    }
    c->pred_st = navsim_predict_requirements(sc, c->pred);
  }
  free(sc);
  return NULL;
}

/* Classify a combination from its predictions. */
static void classify(const ctx *x, combo *c) {
  if (c->pred_st != NAV_OK) {
    c->cls = 0;
    return;
  }
  bool all_clear_pass = true;
  c->cls = 0;
  for (int r = 0; r < x->n_req; ++r) {
    const nav_requirement_verdict *v = &c->pred[r];
    if (!v->evaluated || !isfinite(v->value)) {
      all_clear_pass = false;
      continue;
    }
    if (v->value >= v->limit * x->band) {
      c->cls = -1;
      return;
    }
    if (!(v->value <= v->limit / x->band)) all_clear_pass = false;
  }
  c->cls = all_clear_pass ? 1 : 0;
}

static const nav_requirement_verdict *verdicts(const combo *c) { return c->sim ? c->sim : c->pred; }

/* Pass, margin and the reason of the first failure, from the simulation if any. */
static void judge(const ctx *x, combo *c) {
  const nav_requirement_verdict *v = verdicts(c);
  c->pass = c->sim ? true : c->cls == 1;
  c->margin = INFINITY;
  c->why[0] = '\0';
  if (!c->sim && c->pred_st != NAV_OK) {
    c->pass = false;
    c->margin = -INFINITY;
    snprintf(c->why, sizeof c->why, "cannot be predicted (%s) and was not simulated", nav_status_str(c->pred_st));
    return;
  }
  for (int r = 0; r < x->n_req; ++r) {
    const bool ok = v[r].evaluated && isfinite(v[r].value);
    const double m = ok ? (v[r].limit - v[r].value) / v[r].limit : -INFINITY;
    if (m < c->margin) c->margin = m;
    const bool fail = c->sim ? !v[r].pass : (c->cls == -1 && ok && v[r].value >= v[r].limit * x->band);
    if (c->sim && !v[r].pass) c->pass = false;
    if (fail && c->why[0] == '\0') {
      if (ok)
        snprintf(c->why, sizeof c->why, "%s %.4g %s > %.4g %s (%s)", v[r].id, v[r].value, nav_req_unit_name(v[r].unit),
                 v[r].limit, nav_req_unit_name(v[r].unit), c->sim ? "simulated" : "predicted");
      else
        snprintf(c->why, sizeof c->why, "%s not evaluated", v[r].id);
    }
  }
  c->unconfirmed = !c->sim && c->cls == 0 && c->pred_st == NAV_OK;
  if (!c->pass && c->why[0] == '\0') {
    if (c->unconfirmed)
      snprintf(c->why, sizeof c->why, "near the limit, not simulated (costlier than a passing configuration)");
    else
      snprintf(c->why, sizeof c->why, "fails");
  }
}

static int by_cost(const void *a, const void *b) {
  const combo *x = a, *y = b;
  if (x->cost_usd != y->cost_usd) return x->cost_usd < y->cost_usd ? -1 : 1;
  if (x->scheme != y->scheme) return x->scheme < y->scheme ? -1 : 1;
  if (x->imu != y->imu) return x->imu < y->imu ? -1 : 1;
  if (x->part != y->part) return x->part < y->part ? -1 : 1;
  return x->gnss < y->gnss ? -1 : x->gnss > y->gnss;
}

static int by_rank(const void *a, const void *b) {
  const combo *x = a, *y = b;
  if (x->pass != y->pass) return x->pass ? -1 : 1;
  if (x->unconfirmed != y->unconfirmed) return x->unconfirmed ? -1 : 1;
  if (x->cost_usd != y->cost_usd) return x->cost_usd < y->cost_usd ? -1 : 1;
  if (x->margin != y->margin) return x->margin > y->margin ? -1 : 1;
  return by_cost(a, b);
}

/* Split a comma-separated list of catalog names (names may themselves hold commas: parts are
 * joined until they name an entry). */
static const char *catalog_name(const nav_catalog *cat, size_t i) {
  switch (nav_catalog_get_kind(cat)) {
  case NAV_CATALOG_IMU: return nav_catalog_imu_at(cat, i)->name;
  case NAV_CATALOG_GNSS: return nav_catalog_gnss_at(cat, i)->name;
  case NAV_CATALOG_ACCEL: return nav_catalog_accel_at(cat, i)->name;
  }
  return "";
}

static int parse_names(const char *list, const nav_catalog *cat, int **out, int *n_out) {
  const nav_catalog_kind kind = nav_catalog_get_kind(cat);
  const size_t total = nav_catalog_count(cat);
  int *v = calloc(total > 0 ? total : 1, sizeof *v);
  if (!v) return EXIT_FAIL;
  int n = 0;
  if (strcmp(list, "all") == 0) {
    for (size_t i = 0; i < total; ++i) v[n++] = (int)i;
    *out = v;
    *n_out = n;
    return EXIT_OK;
  }
  char cur[512] = "";
  const char *p = list;
  while (*p) {
    const char *comma = strchr(p, ',');
    const size_t len = comma ? (size_t)(comma - p) : strlen(p);
    if (strlen(cur) + len + 2 >= sizeof cur) break;
    if (cur[0]) strcat(cur, ",");
    strncat(cur, p, len);
    const char *s = cur;
    while (*s == ' ') ++s;
    for (size_t i = 0; i < total; ++i) {
      const char *nm = catalog_name(cat, i);
      if (strcasecmp(nm, s) == 0) {
        bool dup = false;
        for (int k = 0; k < n; ++k) dup |= v[k] == (int)i;
        if (!dup) v[n++] = (int)i;
        cur[0] = '\0';
        break;
      }
    }
    p += len;
    if (*p == ',') ++p;
  }
  if (cur[0] || n == 0) {
    fprintf(stderr, "navsim select: --%s: unknown %s \"%s\" (navsim catalog --%s lists them)\n",
            kind == NAV_CATALOG_IMU    ? "imus"
            : kind == NAV_CATALOG_GNSS ? "receivers"
                                       : "array-parts",
            kind == NAV_CATALOG_IMU    ? "IMU"
            : kind == NAV_CATALOG_GNSS ? "receiver"
                                       : "accelerometer part",
            cur[0] ? cur : list,
            kind == NAV_CATALOG_IMU    ? "imu"
            : kind == NAV_CATALOG_GNSS ? "gnss"
                                       : "accel");
    free(v);
    return EXIT_INVALID;
  }
  *out = v;
  *n_out = n;
  return EXIT_OK;
}

static void csv_text(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"') fputc('"', f);
    fputc(*s, f);
  }
  fputc('"', f);
}

static void csv_value(FILE *f, const nav_requirement_verdict *v) {
  if (v && v->evaluated && isfinite(v->value)) fprintf(f, ",%.6g", v->value);
  else fputs(",", f);
}

/* The IMU of a combination, or its array part. */
static const char *sensor_name(const ctx *x, const combo *k) {
  return k->part >= 0 ? nav_catalog_accel_at(x->parts, (size_t)k->part)->name
                      : nav_catalog_imu_at(x->imus, (size_t)k->imu)->name;
}

static int write_ranking(const char *path, const ctx *x, const combo *c, size_t n) {
  FILE *f = fopen(path, "w");
  if (!f) return EXIT_FAIL;
  fputs("rank,imu,receiver,scheme,imu_cost_class,receiver_cost_class,cost_class,cost_index_usd", f);
  for (int r = 0; r < x->n_req; ++r) {
    const char *id = x->base->requirements[r].id;
    fprintf(f, ",%s_limit_%s,%s_predicted,%s_simulated,%s_pass", id, nav_req_unit_name(x->base->requirements[r].unit),
            id, id, id);
  }
  fputs(",pass,decided_by,margin\n", f);
  for (size_t i = 0; i < n; ++i) {
    const combo *k = &c[i];
    fprintf(f, "%zu,", i + 1);
    csv_text(f, sensor_name(x, k));
    fputc(',', f);
    csv_text(f, k->gnss >= 0 ? nav_catalog_gnss_at(x->gnss, (size_t)k->gnss)->name : "");
    fprintf(f, ",%s,%d,", nav_nav_scheme_name(k->scheme), k->imu_cls);
    if (k->gnss >= 0) fprintf(f, "%d", k->gnss_cls);
    fprintf(f, ",%d,%.0f", k->gnss_cls > k->imu_cls ? k->gnss_cls : k->imu_cls, k->cost_usd);
    for (int r = 0; r < x->n_req; ++r) {
      fprintf(f, ",%.6g", x->base->requirements[r].limit);
      csv_value(f, k->pred_st == NAV_OK ? &k->pred[r] : NULL);
      csv_value(f, k->sim ? &k->sim[r] : NULL);
      const nav_requirement_verdict *v = verdicts(k);
      bool p;
      if (k->sim) p = v[r].pass;
      else p = k->pred_st == NAV_OK && v[r].evaluated && v[r].value <= v[r].limit;
      fprintf(f, ",%s", p ? "true" : "false");
    }
    fprintf(f, ",%s,%s,", k->pass ? "true" : k->unconfirmed ? "not_confirmed" : "false",
            k->decided == DEC_MONTE_CARLO ? "monte_carlo" : "prediction");
    if (isfinite(k->margin)) fprintf(f, "%.4f", k->margin);
    fputc('\n', f);
  }
  const bool bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad) return EXIT_FAIL;
  return EXIT_OK;
}

static void label(char *buf, size_t size, const ctx *x, const combo *k) {
  if (k->gnss >= 0)
    snprintf(buf, size, "%s%s + %s (%s)", k->part >= 0 ? "array of " : "", sensor_name(x, k),
             nav_catalog_gnss_at(x->gnss, (size_t)k->gnss)->name, nav_nav_scheme_name(k->scheme));
  else
    snprintf(buf, size, "%s (%s)", sensor_name(x, k), nav_nav_scheme_name(k->scheme));
}

int navsim_select(int argc, char **argv) {
  const char *scene_path = NULL, *out_dir = NULL, *imus_s = "all", *rcv_s = "all", *schemes_s = NULL,
             *parts_s = NULL;
  long runs = 20, threads = 0;
  double band = 1.5, predict_rate = 10.0;
  bool quiet = false, force = false;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (navsim_is_help(a)) {
      fputs(k_usage_select, stdout);
      return EXIT_OK;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = true;
    } else if (strcmp(a, "--force") == 0) {
      force = true;
    } else if (!strcmp(a, "--out") || !strcmp(a, "--imus") || !strcmp(a, "--receivers") ||
               !strcmp(a, "--schemes") || !strcmp(a, "--array-parts") || !strcmp(a, "--runs") ||
               !strcmp(a, "--threads") || !strcmp(a, "--band") || !strcmp(a, "--predict-rate")) {
      if (!navsim_need_value("select", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (!strcmp(a, "--out")) out_dir = v;
      else if (!strcmp(a, "--imus")) imus_s = v;
      else if (!strcmp(a, "--array-parts"))
        parts_s = v;
      else if (!strcmp(a, "--receivers")) rcv_s = v;
      else if (!strcmp(a, "--schemes")) schemes_s = v;
      else if (!strcmp(a, "--runs")) {
        if (!navsim_parse_long(v, 1, 100000, &runs)) {
          fprintf(stderr, "navsim select: --runs: expected an integer in [1, 100000], got \"%s\"\n", v);
          return EXIT_INVALID;
        }
      } else if (!strcmp(a, "--threads")) {
        if (!navsim_parse_long(v, 1, 256, &threads)) {
          fprintf(stderr, "navsim select: --threads: expected an integer in [1, 256], got \"%s\"\n", v);
          return EXIT_INVALID;
        }
      } else {
        char *end = NULL;
        const double d = strtod(v, &end);
        const bool is_band = !strcmp(a, "--band");
        if (!end || *end || !isfinite(d) || (is_band ? !(d > 1.0) : !(d > 0.0))) {
          fprintf(stderr, "navsim select: %s: expected a number %s, got \"%s\"\n", a, is_band ? "> 1" : "> 0", v);
          return EXIT_INVALID;
        }
        if (is_band) band = d;
        else predict_rate = d;
      }
    } else {
      const int rc = navsim_scene_arg("select", a, &scene_path);
      if (rc != EXIT_OK) return rc;
    }
  }
  if (!scene_path || !out_dir) {
    fprintf(stderr, "navsim select: %s\n%s", !scene_path ? "missing SCENE" : "missing --out DIR", k_usage_select);
    return EXIT_INVALID;
  }
  {
    const int orc = navsim_out_check("select", out_dir, force);
    if (orc != EXIT_OK) return orc;
  }
  if (threads == 0) {
    const long nc = sysconf(_SC_NPROCESSORS_ONLN);
    threads = nc > 0 ? nc : 1;
  }

  int rc = EXIT_FAIL;
  nav_scene *base = malloc(sizeof *base), *sc = malloc(sizeof *sc);
  nav_catalog *imus = NULL, *gnss = NULL, *parts = NULL;
  int *imu_idx = NULL, *rcv_idx = NULL, *part_idx = NULL, n_imu = 0, n_rcv = 0, n_part = 0,
      n_array_sensors = 0;
  combo *c = NULL;
  size_t n = 0;
  nav_resultdir *rd = NULL;
  bool base_loaded = false;
  ctx x;
  memset(&x, 0, sizeof x);
  if (!base || !sc) goto done;
  rc = navsim_load_scene(scene_path, base);
  if (rc != EXIT_OK) goto done;
  base_loaded = true; /* the combinations' scenes are plain copies of base (make_scene) */
  rc = EXIT_FAIL;
  if (base->n_requirements == 0) {
    fprintf(stderr, "%s: error: requirements: the scene has no requirements to select against (add a requirements "
                    "list: id, metric, statistic, limit, unit)\n", scene_path);
    rc = EXIT_INVALID;
    goto done;
  }
  if (base->earth.model != NAV_EARTH_WGS84) {
    fprintf(stderr, "%s: error: earth.model: navsim select needs a wgs84 scene (the covariance prediction)\n", scene_path);
    rc = EXIT_INVALID;
    goto done;
  }
  if (!schemes_s && base->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
    fprintf(stderr, "%s: error: navigation.scheme: navsim select does not support ins_gnss_tight yet (the receiver "
                    "catalog gives fix errors, not the raw-measurement errors of gnss.constellation); use "
                    "--schemes ins_gnss, or navsim sweep\n", scene_path);
    rc = EXIT_INVALID;
    goto done;
  }
  nav_nav_scheme schemes[3];
  int n_sch = 0;
  if (!schemes_s) {
    schemes[n_sch++] = base->navigation.scheme;
  } else {
    char buf[128];
    snprintf(buf, sizeof buf, "%s", schemes_s);
    for (char *tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
      nav_nav_scheme s;
      if (!strcmp(tok, "free_ins")) s = NAV_SCHEME_FREE_INS;
      else if (!strcmp(tok, "ins_gnss")) s = NAV_SCHEME_INS_GNSS;
      else if (!strcmp(tok, "gyro_free_gnss")) s = NAV_SCHEME_GYRO_FREE_GNSS;
      else if (!strcmp(tok, "ins_gnss_tight")) {
        fprintf(stderr, "navsim select: --schemes: ins_gnss_tight is not supported by select yet (the receiver "
                        "catalog gives fix errors, not the raw-measurement errors of gnss.constellation)\n");
        rc = EXIT_INVALID;
        goto done;
      } else {
        fprintf(stderr, "navsim select: --schemes: expected free_ins, ins_gnss and/or gyro_free_gnss, got \"%s\"\n",
                tok);
        rc = EXIT_INVALID;
        goto done;
      }
      bool dup = false;
      for (int q = 0; q < n_sch; ++q) dup = dup || schemes[q] == s;
      if (n_sch < 3 && !dup) schemes[n_sch++] = s;
    }
  }
  for (int k = 0; k < n_sch; ++k)
    if (schemes[k] == NAV_SCHEME_GYRO_FREE) {
      fprintf(stderr, "navsim select: the gyro_free scheme has no catalog sensors to select\n");
      rc = EXIT_INVALID;
      goto done;
    }
  {
    char res[4096], path[4200];
    if (!navsim_find_resources_dir(res, sizeof res)) {
      fprintf(stderr, "navsim select: cannot find the resources directory with the catalogs; set NAV_RESOURCES_DIR\n");
      goto done;
    }
    navsim_diag_sink sink = {0};
    snprintf(path, sizeof path, "%s/imu_catalog.csv", res);
    nav_status st = nav_catalog_load(path, NULL, &imus, navsim_print_diag, &sink);
    if (st == NAV_OK) {
      snprintf(path, sizeof path, "%s/gnss_receivers.csv", res);
      st = nav_catalog_load(path, NULL, &gnss, navsim_print_diag, &sink);
    }
    if (st == NAV_OK && parts_s) {
      snprintf(path, sizeof path, "%s/accel_catalog.csv", res);
      st = nav_catalog_load(path, NULL, &parts, navsim_print_diag, &sink);
    }
    if (st != NAV_OK) {
      if (sink.count == 0) fprintf(stderr, "%s: error: %s\n", path, nav_status_str(st));
      goto done;
    }
  }
  rc = parse_names(imus_s, imus, &imu_idx, &n_imu);
  if (rc == EXIT_OK) rc = parse_names(rcv_s, gnss, &rcv_idx, &n_rcv);
  if (rc == EXIT_OK && parts_s) {
    bool gf = false;
    for (int k = 0; k < n_sch; ++k)
      gf = gf || schemes[k] == NAV_SCHEME_GYRO_FREE_GNSS;
    if (!gf) {
      fprintf(stderr,
              "navsim select: --array-parts applies to the gyro_free_gnss scheme (add it to --schemes)\n");
      rc = EXIT_INVALID;
    } else {
      rc = parse_names(parts_s, parts, &part_idx, &n_part);
    }
    nav_accel_array layout;
    if (rc == EXIT_OK && nav_array_layout_from_scene(&base->array, &layout) == NAV_OK)
      n_array_sensors = layout.n_sensors;
  }
  if (rc != EXIT_OK) goto done;
  rc = EXIT_FAIL;

  /* The combinations. */
  {
    const int n_sens = n_imu > n_part ? n_imu : n_part;
    size_t cap = (size_t)n_sens * (size_t)(n_rcv + 1) * (size_t)n_sch;
    c = calloc(cap, sizeof *c);
    if (!c) goto done;
    for (int s = 0; s < n_sch; ++s) {
      /* gyro_free_gnss over the array parts when --array-parts is given, else over the IMUs. */
      const bool by_part = parts_s != NULL && schemes[s] == NAV_SCHEME_GYRO_FREE_GNSS;
      for (int i = 0; i < (by_part ? n_part : n_imu); ++i) {
        const bool aided = schemes[s] == NAV_SCHEME_INS_GNSS || schemes[s] == NAV_SCHEME_GYRO_FREE_GNSS;
        const int nr = aided ? n_rcv : 1;
        for (int g = 0; g < nr; ++g) {
          combo *k = &c[n++];
          k->imu = by_part ? -1 : imu_idx[i];
          k->part = by_part ? part_idx[i] : -1;
          k->gnss = aided ? rcv_idx[g] : -1;
          k->scheme = schemes[s];
          k->imu_cls = by_part ? nav_catalog_accel_at(parts, (size_t)k->part)->cost_class
                               : nav_catalog_imu_at(imus, (size_t)k->imu)->cost_class;
          k->gnss_cls = k->gnss >= 0 ? nav_catalog_gnss_at(gnss, (size_t)k->gnss)->cost_class : 0;
          /* An array costs its N sensors. */
          k->cost_usd = (by_part ? n_array_sensors : 1) * class_usd(k->imu_cls) +
                        (k->gnss >= 0 ? class_usd(k->gnss_cls) : 0.0);
          k->pred = calloc((size_t)base->n_requirements, sizeof *k->pred);
          if (!k->pred) goto done;
        }
      }
    }
  }
  qsort(c, n, sizeof *c, by_cost);
  x.base = base;
  x.imus = imus;
  x.gnss = gnss;
  x.parts = parts;
  x.c = c;
  x.n = n;
  x.n_req = base->n_requirements;
  x.band = band;
  x.predict_rate = predict_rate;
  pthread_mutex_init(&x.mu, NULL);

  if (!quiet && !parts_s)
    printf("select     %s: %d IMU%s x %d receiver%s x %d scheme%s = %zu configurations, %d requirement%s\n",
           base->name, n_imu, n_imu == 1 ? "" : "s", n_rcv, n_rcv == 1 ? "" : "s", n_sch, n_sch == 1 ? "" : "s", n,
           x.n_req, x.n_req == 1 ? "" : "s");
  else if (!quiet)
    printf("select     %s: %d IMU%s or %d array part%s (gyro_free_gnss, %d sensors each) x %d receiver%s x "
           "%d scheme%s = "
           "%zu configurations, %d requirement%s\n",
           base->name, n_imu, n_imu == 1 ? "" : "s", n_part, n_part == 1 ? "" : "s", n_array_sensors, n_rcv,
           n_rcv == 1 ? "" : "s", n_sch, n_sch == 1 ? "" : "s", n, x.n_req, x.n_req == 1 ? "" : "s");
  const double t0 = navsim_now_s();
  {
    pthread_t th[256];
    int nt = 0;
    for (long t = 0; t < threads && (size_t)t < n; ++t)
      if (pthread_create(&th[nt], NULL, predict_worker, &x) == 0) ++nt;
    if (nt == 0) predict_worker(&x);
    for (int t = 0; t < nt; ++t) pthread_join(th[t], NULL);
  }
  const double t_pred = navsim_now_s() - t0;
  int n_fail = 0, n_pass = 0, n_near = 0;
  for (size_t i = 0; i < n; ++i) {
    classify(&x, &c[i]);
    if (c[i].cls < 0) ++n_fail;
    else if (c[i].cls > 0) ++n_pass;
    else ++n_near;
  }
  if (!quiet)
    printf("predicted  %zu by covariance analysis (IMU rate %g Hz) in %.1f s: %d fail clearly, %d pass clearly, %d near "
           "the limit (band x%g)\n",
           n, predict_rate < base->imu.rate_hz ? predict_rate : base->imu.rate_hz, t_pred, n_fail, n_pass, n_near,
           band);

  /* Monte Carlo of the survivors, cheapest first, while they can still be the recommendation. */
  const double t1 = navsim_now_s();
  int n_sim = 0;
  double best_pass_cost = INFINITY;
  for (size_t i = 0; i < n; ++i)
    if (c[i].cls > 0 && c[i].cost_usd < best_pass_cost) best_pass_cost = c[i].cost_usd;
  for (size_t i = 0; i < n; ++i) {
    combo *k = &c[i];
    /* A survivor is near its limits, so its margin is below that of any clear pass: at equal cost
       it cannot become the recommendation either. */
    if (k->cls != 0 || k->cost_usd >= best_pass_cost) continue;
    if (make_scene(&x, k, sc) != NAV_OK) continue;
    sc->simulation.runs = runs;
    nav_sim *sim = NULL;
    nav_req_evaluator *ev = NULL;
    nav_status st = nav_sim_create(sc, &sim);
    if (st == NAV_OK) st = nav_req_evaluator_create_for_scene(sc, false, &ev);
    if (st == NAV_OK) {
      const nav_run_observer obs = nav_req_evaluator_observer(ev);
      nav_sim_options o = nav_sim_options_default();
      o.threads = (int)threads;
      o.observer = &obs;
      nav_sim_summary sum;
      st = nav_sim_run(sim, &o, &sum);
      if (st == NAV_OK) {
        k->sim = calloc((size_t)x.n_req, sizeof *k->sim);
        st = k->sim ? nav_req_evaluator_finish(ev, k->sim) : NAV_ERR_NO_MEMORY;
        if (st != NAV_OK) {
          free(k->sim);
          k->sim = NULL;
        }
      }
    }
    if (st != NAV_OK) {
      char lb[400];
      label(lb, sizeof lb, &x, k);
      fprintf(stderr, "navsim select: %s: Monte Carlo failed: %s\n", lb, sim ? nav_sim_last_error(sim) : nav_status_str(st));
    } else {
      k->decided = DEC_MONTE_CARLO;
      ++n_sim;
      if (nav_req_all_pass(k->sim, x.n_req) && k->cost_usd < best_pass_cost) best_pass_cost = k->cost_usd;
    }
    nav_req_evaluator_destroy(ev);
    nav_sim_destroy(sim);
  }
  const double t_sim = navsim_now_s() - t1;
  if (!quiet)
    printf("simulated  %d near the limit and not costlier than a passing one, %ld runs each, in %.1f s\n", n_sim, runs,
           t_sim);
  for (size_t i = 0; i < n; ++i) judge(&x, &c[i]);
  qsort(c, n, sizeof *c, by_rank);

  {
    const int orc = navsim_out_begin("select", out_dir, force, &rd);
    if (orc != EXIT_OK) {
      rc = orc;
      goto done;
    }
  }
  {
    const char *p = nav_resultdir_file(rd, "ranking.csv");
    if (!p || write_ranking(p, &x, c, n) != EXIT_OK) {
      fprintf(stderr, "navsim select: writing ranking.csv failed\n");
      goto done;
    }
    if (c[0].pass && make_scene(&x, &c[0], sc) == NAV_OK) {
      p = nav_resultdir_file(rd, "recommended.yaml");
      if (!p || nav_scene_write_file(p, sc) != NAV_OK) {
        fprintf(stderr, "navsim select: writing recommended.yaml failed\n");
        goto done;
      }
    }
    const int orc = navsim_out_commit("select", rd);
    if (orc != EXIT_OK) {
      rd = NULL;
      rc = orc;
      goto done;
    }
    rd = NULL;
  }
  if (!quiet) {
    char lb[400];
    if (c[0].pass) {
      label(lb, sizeof lb, &x, &c[0]);
      char cls[32];
      if (c[0].gnss >= 0) snprintf(cls, sizeof cls, "%d + %d", c[0].imu_cls, c[0].gnss_cls);
      else snprintf(cls, sizeof cls, "%d", c[0].imu_cls);
      char usd[32];
      if (c[0].cost_usd >= 1e3) snprintf(usd, sizeof usd, "%.3g kUSD", c[0].cost_usd / 1e3);
      else snprintf(usd, sizeof usd, "%.3g USD", c[0].cost_usd);
      printf("recommend  %s: cost class %s (order of %s), margin %.0f %%, %s\n", lb, cls, usd, 100.0 * c[0].margin, c[0].decided == DEC_MONTE_CARLO ? "confirmed by Monte Carlo" : "predicted");
      const nav_requirement_verdict *v = verdicts(&c[0]);
      for (int r = 0; r < x.n_req; ++r)
        printf("             %-20s %.4g %s <= %.4g %s (%s)\n", v[r].id, v[r].value, nav_req_unit_name(v[r].unit),
               v[r].limit, nav_req_unit_name(v[r].unit), c[0].sim ? "simulated" : "predicted");
      int shown = 0, cheaper = 0;
      for (size_t i = 1; i < n; ++i)
        if (!c[i].pass && c[i].cost_usd < c[0].cost_usd) ++cheaper;
      if (cheaper) printf("cheaper configurations fail (%d):\n", cheaper);
      for (size_t i = 1; i < n && shown < 12; ++i) {
        if (c[i].pass || !(c[i].cost_usd < c[0].cost_usd)) continue;
        label(lb, sizeof lb, &x, &c[i]);
        printf("  %-70.70s %s\n", lb, c[i].why);
        ++shown;
      }
      if (cheaper > shown) printf("  ... %d more in ranking.csv\n", cheaper - shown);
    } else {
      printf("recommend  none: no configuration meets every requirement\n");
      for (size_t i = 0; i < n && i < 5; ++i) {
        label(lb, sizeof lb, &x, &c[i]);
        printf("  %-70.70s %s\n", lb, c[i].why);
      }
    }
    printf("ranking    %s/ranking.csv\n", out_dir);
  }
  rc = c[0].pass ? EXIT_OK : 3;

done:
  if (x.c) pthread_mutex_destroy(&x.mu);
  nav_resultdir_abort(rd);
  for (size_t i = 0; i < n; ++i) {
    free(c[i].pred);
    free(c[i].sim);
  }
  free(c);
  free(imu_idx);
  free(rcv_idx);
  nav_catalog_destroy(imus);
  nav_catalog_destroy(parts);
  free(part_idx);
  nav_catalog_destroy(gnss);
  if (base_loaded) nav_scene_release(base);
  free(base);
  free(sc);
  return rc;
}
