/*
 * navsim budget SCENE --out DIR: the contribution of each error source to each requirement of
 * the scene (nav_budget.h: covariance analysis with one source on at a time and the gains of the
 * full model; variances add). Writes budget.csv (one row per requirement and source, sorted by
 * share within each requirement) and budget.json, and prints the largest contributors.
 */
#include "budget_cmd.h"
#include "cli_util.h"

#include <errno.h>
#include <math.h>
#include <unistd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_budget.h"
#include "navcore/nav_io.h"
#include "navcore/nav_results.h"
#include "navcore/nav_version.h"

static const char *k_usage_budget =
    "usage: navsim budget SCENE [--out DIR] [--force] [--runs N] [--threads N] [--quiet]\n"
    "\n"
    "Error budget: how much each error source contributes to each requirement of the scene, so\n"
    "that the spec worth buying better shows at once. Covariance analysis with one source on at a\n"
    "time and the Kalman gains of the full model (variances add: the shares sum to 1) for wgs84\n"
    "scenes with the free_ins or ins_gnss scheme. Sources: gyro_arw, gyro_bias_instability,\n"
    "gyro_rate_random_walk, gyro_turn_on_bias, accel_vrw, accel_bias_instability,\n"
    "accel_random_walk, accel_turn_on_bias, initial_position, initial_velocity, initial_attitude,\n"
    "gnss_position_noise, gnss_position_correlated, gnss_velocity_noise, filter_floors,\n"
    "gyro_scale_factor, accel_scale_factor (scale factors the filter does not estimate are carried\n"
    "as consider states: never corrected, their effect is in the budget and in the total).\n"
    "A scene without requirements is budgeted for the RMS of the horizontal, vertical, velocity\n"
    "and yaw errors. Quantile requirements (p95, cep) and max are budgeted through the mean square\n"
    "of their metric over the same epochs; outage_end at the worst outage. IMU terms outside the\n"
    "linear model (misalignment, g-sensitivity, quantisation) are listed as not budgeted.\n"
    "Schemes that are not linearisable (gyro_free) and flat-Earth scenes are budgeted by Monte\n"
    "Carlo instead: one campaign per error source with that source alone (--runs N each, default\n"
    "simulation.runs), each requirement's metric reduced to its mean square as above; the shares\n"
    "are of the sum over the sources, and the campaign with every source on is reported next to\n"
    "that sum (they agree when the sources act independently and linearly).\n"
    "\n"
    "Writes into DIR (default out/<scene name>-budget):\n"
    "  budget.csv   requirement,metric,statistic,source,contribution,unit,variance,share,method\n"
    "               contribution: sqrt(variance) in the requirement's unit (the RSS part);\n"
    "               variance in unit^2; share = variance / total variance\n"
    "               method: covariance or monte_carlo\n"
    "  budget.json  per requirement: the total, its epoch, the limit and the sources\n"
    NAVSIM_OUT_HELP
    "\n"
    "exit codes: 0 success; 2 invalid scene or options; 1 other failure\n";

/* One line of the budget of a requirement. */
typedef struct row {
  char source[48];
  double var, share; /* SI^2; of the requirement's total */
} row;

static int by_share(const void *a, const void *b) {
  const row *x = a, *y = b;
  if (x->share != y->share) return x->share < y->share ? 1 : -1;
  return strcmp(x->source, y->source);
}

/* The budget of one requirement, whatever the method. */
typedef struct req_budget {
  int n;
  row rows[32];
  double total_ms;    /* covariance: the full model; Monte Carlo: the sum over the sources */
  double all_ms;      /* Monte Carlo: every source on together (NaN for covariance) */
  double t_s;         /* epoch used, NaN: all */
} req_budget;

static nav_requirement default_req(const char *id, nav_req_metric m, nav_req_statistic s, nav_req_unit u) {
  nav_requirement q;
  memset(&q, 0, sizeof q);
  snprintf(q.id, sizeof q.id, "%s", id);
  q.metric = m;
  q.statistic = s;
  q.limit = INFINITY;
  q.unit = u;
  q.time_s = NAN;
  return q;
}

/* ---------------------------------------------------------------- Monte Carlo budget */

/* One error source of the Monte Carlo budget. */
typedef enum mc_kind { MC_GYRO, MC_ACCEL, MC_ARRAY, MC_INIT_POS, MC_INIT_VEL, MC_INIT_ATT, MC_INIT_RATE, MC_GNSS } mc_kind;
typedef struct mc_source {
  char name[48];
  mc_kind kind;
  unsigned bit;
} mc_source;

static const char *const k_term_names[9] = {"turn_on_bias", "bias_instability", "bias_random_walk",
                                            "noise",        "scale_factor",     "misalignment",
                                            "g_sensitivity", "quantisation",    "saturation"};

static double vmax3(nav_vec3 v) { return fmax(fmax(v.x, v.y), v.z); }

/* The sources present in @p sc; returns their count. */
static int mc_sources(const nav_scene *sc, mc_source *out, int cap) {
  int n = 0;
  const bool gf = sc->navigation.scheme == NAV_SCHEME_GYRO_FREE || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
  const unsigned skip = NAV_IMU_TERM_SATURATION; /* a limit, not an error source */
  for (int t = 0; t < 9 && n < cap; ++t) {
    const unsigned bit = 1u << t;
    if (bit & skip) continue;
    /* The names of the covariance budget where the term is the same. */
    static const char *const gname[9] = {"turn_on_bias", "bias_instability", "rate_random_walk", "arw",
                                         "scale_factor", "misalignment",     "g_sensitivity",    "quantisation", ""};
    static const char *const aname[9] = {"turn_on_bias", "bias_instability", "random_walk",  "vrw",
                                         "scale_factor", "misalignment",     "g_sensitivity", "quantisation", ""};
    if (!gf && (sc->imu.model.gyro.terms & bit)) {
      snprintf(out[n].name, sizeof out[n].name, "gyro_%s", gname[t]);
      out[n].kind = MC_GYRO;
      out[n++].bit = bit;
    }
    if (!gf && (sc->imu.model.accel.terms & bit) && n < cap) {
      snprintf(out[n].name, sizeof out[n].name, "accel_%s", aname[t]);
      out[n].kind = MC_ACCEL;
      out[n++].bit = bit;
    }
    if (gf && (sc->array.accel.terms & bit) && n < cap) {
      snprintf(out[n].name, sizeof out[n].name, "array_accel_%s", aname[t]);
      out[n].kind = MC_ARRAY;
      out[n++].bit = bit;
    }
  }
  const struct {
    const char *name;
    mc_kind kind;
    double sd;
  } init[4] = {{"initial_position", MC_INIT_POS, vmax3(sc->initial_errors.pos_sd_m)},
               {"initial_velocity", MC_INIT_VEL, vmax3(sc->initial_errors.vel_sd_mps)},
               {"initial_attitude", MC_INIT_ATT, vmax3(sc->initial_errors.att_sd_rad)},
               {"initial_rate", MC_INIT_RATE, gf ? vmax3(sc->array.initial_rate_sd_rps) : 0.0}};
  for (int i = 0; i < 4 && n < cap; ++i)
    if (init[i].sd > 0.0) {
      snprintf(out[n].name, sizeof out[n].name, "%s", init[i].name);
      out[n].kind = init[i].kind;
      out[n++].bit = 0;
    }
  if (sc->gnss.enabled &&
      (sc->navigation.scheme == NAV_SCHEME_INS_GNSS || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS)) {
    static const char *const gn[3] = {"gnss_position_correlated", "gnss_position_noise", "gnss_velocity_noise"};
    for (int t = 0; t < 3 && n < cap; ++t)
      if (sc->gnss.model.terms & (1u << t)) {
        snprintf(out[n].name, sizeof out[n].name, "%s", gn[t]);
        out[n].kind = MC_GNSS;
        out[n++].bit = 1u << t;
      }
  }
  return n;
}

/* @p sc with source @p src alone (saturation limits kept). */
static void only_source(nav_scene *sc, const mc_source *src) {
  const unsigned keep = NAV_IMU_TERM_SATURATION;
  sc->imu.model.gyro.terms = (sc->imu.model.gyro.terms & keep) | (src->kind == MC_GYRO ? src->bit : 0u);
  sc->imu.model.accel.terms = (sc->imu.model.accel.terms & keep) | (src->kind == MC_ACCEL ? src->bit : 0u);
  sc->array.accel.terms = src->kind == MC_ARRAY ? src->bit : 0u;
  if (src->kind != MC_INIT_POS) sc->initial_errors.pos_sd_m = nav_vec3_zero();
  if (src->kind != MC_INIT_VEL) sc->initial_errors.vel_sd_mps = nav_vec3_zero();
  if (src->kind != MC_INIT_ATT) sc->initial_errors.att_sd_rad = nav_vec3_zero();
  if (src->kind != MC_INIT_RATE) sc->array.initial_rate_sd_rps = nav_vec3_zero();
  sc->gnss.model.terms = src->kind == MC_GNSS ? src->bit : 0u;
}

/* Mean square (SI^2) of each requirement's metric over a Monte Carlo campaign of @p sc: rms,
 * at_time and outage_end as they are (their value is an RMS), the others through their RMS. */
static nav_status mc_mean_squares(const nav_scene *sc, const nav_requirement *reqs, int nreq, int threads,
                                  double *ms, double *t_s) {
  nav_requirement q[NAV_SCENE_MAX_REQUIREMENTS];
  for (int i = 0; i < nreq; ++i) {
    q[i] = reqs[i];
    if (q[i].statistic != NAV_REQ_RMS && q[i].statistic != NAV_REQ_AT_TIME && q[i].statistic != NAV_REQ_OUTAGE_END)
      q[i].statistic = NAV_REQ_RMS;
    if (q[i].limit > 1e299) q[i].limit = 1e299; /* a finite limit for validation */
  }
  nav_scene *s = malloc(sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  *s = *sc;
  for (int i = 0; i < nreq; ++i) s->requirements[i] = q[i];
  s->n_requirements = nreq;
  nav_req_evaluator *ev = NULL;
  nav_sim *sim = NULL;
  nav_requirement_verdict v[NAV_SCENE_MAX_REQUIREMENTS];
  nav_status st = nav_req_evaluator_create_for_scene(s, false, &ev);
  if (st == NAV_OK) st = nav_sim_create(s, &sim);
  if (st == NAV_OK) {
    nav_sim_options o = nav_sim_options_default();
    o.threads = threads;
    const nav_run_observer obs = nav_req_evaluator_observer(ev);
    o.observer = &obs;
    nav_sim_summary sum;
    st = nav_sim_run(sim, &o, &sum);
  }
  if (st == NAV_OK) st = nav_req_evaluator_finish(ev, v);
  if (st == NAV_OK)
    for (int i = 0; i < nreq; ++i) {
      const double k = nav_req_unit_to_si(q[i].unit);
      ms[i] = v[i].evaluated ? (v[i].value * k) * (v[i].value * k) : NAN;
      if (t_s) {
        t_s[i] = NAN;
        if (q[i].statistic == NAV_REQ_AT_TIME) t_s[i] = v[i].at_time_s;
        if (q[i].statistic == NAV_REQ_OUTAGE_END)
          for (int o = 0; o < v[i].outage_count; ++o)
            if (v[i].outage_value[o] == v[i].value) t_s[i] = v[i].outage_end_t_s[o];
      }
    }
  nav_sim_destroy(sim);
  nav_req_evaluator_destroy(ev);
  free(s);
  return st;
}

typedef struct mc_budget {
  int nsrc;
  mc_source src[32];
  double ms[32][NAV_SCENE_MAX_REQUIREMENTS]; /* per source and requirement */
  double all[NAV_SCENE_MAX_REQUIREMENTS];    /* every source on */
  double t_s[NAV_SCENE_MAX_REQUIREMENTS];
} mc_budget;

static nav_status mc_budget_run(const nav_scene *sc, const nav_requirement *reqs, int nreq, int threads, bool quiet,
                                mc_budget *b) {
  b->nsrc = mc_sources(sc, b->src, 32);
  nav_scene *s = malloc(sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  nav_status st = NAV_OK;
  for (int k = 0; k < b->nsrc && st == NAV_OK; ++k) {
    if (!quiet) fprintf(stderr, "\r  budget: Monte Carlo %d/%d (%s)          ", k + 1, b->nsrc + 1, b->src[k].name);
    *s = *sc;
    only_source(s, &b->src[k]);
    st = mc_mean_squares(s, reqs, nreq, threads, b->ms[k], NULL);
  }
  if (st == NAV_OK) {
    if (!quiet) fprintf(stderr, "\r  budget: Monte Carlo %d/%d (all sources)          ", b->nsrc + 1, b->nsrc + 1);
    st = mc_mean_squares(sc, reqs, nreq, threads, b->all, b->t_s);
  }
  if (!quiet) fputc('\n', stderr);
  free(s);
  return st;
}

int navsim_budget(int argc, char **argv) {
  const char *scene_path = NULL, *out_dir = NULL;
  bool quiet = false, force = false;
  long runs = 0, threads = 0;
  for (int i = 0; i < argc; ++i) {
    if (navsim_is_help(argv[i])) {
      fputs(k_usage_budget, stdout);
      return 0;
    } else if (strcmp(argv[i], "--quiet") == 0 || strcmp(argv[i], "-q") == 0) {
      quiet = true;
    } else if (strcmp(argv[i], "--force") == 0) {
      force = true;
    } else if (strcmp(argv[i], "--out") == 0 || strcmp(argv[i], "--runs") == 0 || strcmp(argv[i], "--threads") == 0) {
      if (!navsim_need_value("budget", argc, i, argv[i])) return 2;
      const char *opt = argv[i], *v = argv[++i];
      if (opt[2] == 'o') {
        out_dir = v;
        continue;
      }
      const long max = opt[2] == 'r' ? NAV_SCENE_MAX_RUNS : 256;
      long x = 0;
      if (!navsim_parse_long(v, 1, max, &x)) {
        fprintf(stderr, "navsim budget: %s: expected an integer in [1, %ld], got \"%s\"\n", opt, max, v);
        return 2;
      }
      if (opt[2] == 'r') runs = x;
      else threads = x;
    } else {
      const int rc = navsim_scene_arg("budget", argv[i], &scene_path);
      if (rc != 0) return rc;
    }
  }
  if (!scene_path) {
    fprintf(stderr, "navsim budget: missing SCENE\n%s", k_usage_budget);
    return 2;
  }
  nav_scene *sc = malloc(sizeof *sc);
  if (!sc) return 1;
  const int lrc = navsim_load_scene(scene_path, sc);
  if (lrc != 0) {
    free(sc);
    return lrc;
  }
  if (sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
    /* Its error sources (code and range-rate noise, receiver clock) are not yet sources of either
     * budget; a budget without them would misattribute the error. */
    fprintf(stderr, "navsim budget: %s: navigation.scheme ins_gnss_tight is not supported by the error budget yet "
                    "(its raw-measurement error sources are not budget sources); use navsim sweep over "
                    "gnss.constellation.code_sd_m or navsim estimate\n",
            scene_path);
    nav_scene_release(sc);
    free(sc);
    return 2;
  }
  navsim_warn_gnss_file_model("budget", scene_path, sc);
  if (runs > 0) sc->simulation.runs = runs;
  if (threads == 0) {
    const long nc = sysconf(_SC_NPROCESSORS_ONLN);
    threads = sc->simulation.threads > 0 ? sc->simulation.threads : (nc > 0 ? nc : 1);
  }
  const bool covariance = sc->earth.model == NAV_EARTH_WGS84 && sc->navigation.scheme != NAV_SCHEME_GYRO_FREE &&
                          sc->navigation.scheme != NAV_SCHEME_GYRO_FREE_GNSS;
  nav_requirement reqs[NAV_SCENE_MAX_REQUIREMENTS];
  int nreq = sc->n_requirements;
  for (int i = 0; i < nreq; ++i) reqs[i] = sc->requirements[i];
  if (nreq == 0) {
    reqs[nreq++] = default_req("h-rms", NAV_REQ_HORIZONTAL_POSITION, NAV_REQ_RMS, NAV_REQ_UNIT_M);
    reqs[nreq++] = default_req("v-rms", NAV_REQ_VERTICAL_POSITION, NAV_REQ_RMS, NAV_REQ_UNIT_M);
    reqs[nreq++] = default_req("vel-rms", NAV_REQ_VELOCITY, NAV_REQ_RMS, NAV_REQ_UNIT_MPS);
    reqs[nreq++] = default_req("yaw-rms", NAV_REQ_YAW, NAV_REQ_RMS, NAV_REQ_UNIT_DEG);
    for (int i = 0; i < nreq; ++i) reqs[i].limit = 1e300; /* no limit: a budget only */
  }
  char default_dir[600];
  if (!out_dir) {
    char nm[NAV_SCENE_NAME_MAX];
    navsim_safe_name(nm, sizeof nm, sc->name, "scene");
    snprintf(default_dir, sizeof default_dir, "out/%s-budget", nm);
    out_dir = default_dir;
  }
  {
    const int orc = navsim_out_check("budget", out_dir, force);
    if (orc != 0) {
      nav_scene_release(sc);
      free(sc);
      return orc;
    }
  }
  req_budget *rb = calloc((size_t)nreq, sizeof *rb);
  nav_budget_result *res = covariance ? calloc((size_t)nreq, sizeof *res) : NULL;
  mc_budget *mb = covariance ? NULL : calloc(1, sizeof *mb);
  int rc = 1;
  nav_resultdir *rd = NULL;
  FILE *f = NULL;
  char msg[256] = "";
  if (!rb || (covariance ? !res : !mb)) goto cleanup;
  nav_status st;
  if (covariance) {
    st = nav_budget_requirements(sc, reqs, nreq, res, msg, sizeof msg);
  } else {
    st = mc_budget_run(sc, reqs, nreq, (int)threads, quiet || !isatty(STDERR_FILENO), mb);
    if (st != NAV_OK) snprintf(msg, sizeof msg, "Monte Carlo campaign failed: %s", nav_status_str(st));
  }
  if (st != NAV_OK) {
    fprintf(stderr, "navsim budget: %s: %s\n", scene_path, msg[0] ? msg : nav_status_str(st));
    rc = st == NAV_ERR_INVALID_ARG ? 2 : 1;
    goto cleanup;
  }
  for (int i = 0; i < nreq; ++i) {
    req_budget *b = &rb[i];
    if (covariance) {
      b->total_ms = res[i].total_ms;
      b->all_ms = NAN;
      b->t_s = res[i].t_s;
      for (int q = 0; q < NAV_BUDGET_SOURCE_COUNT; ++q)
        if (res[i].active & (1u << q)) {
          snprintf(b->rows[b->n].source, sizeof b->rows[b->n].source, "%s", nav_budget_source_name((nav_budget_source)q));
          b->rows[b->n++].var = res[i].source_ms[q];
        }
    } else {
      b->total_ms = 0.0;
      for (int q = 0; q < mb->nsrc; ++q) {
        snprintf(b->rows[b->n].source, sizeof b->rows[b->n].source, "%s", mb->src[q].name);
        b->rows[b->n++].var = mb->ms[q][i];
        b->total_ms += mb->ms[q][i];
      }
      b->all_ms = mb->all[i];
      b->t_s = mb->t_s[i];
    }
    for (int q = 0; q < b->n; ++q) b->rows[q].share = b->total_ms > 0.0 ? b->rows[q].var / b->total_ms : 0.0;
    qsort(b->rows, (size_t)b->n, sizeof *b->rows, by_share);
  }
  const char *method = covariance ? "covariance" : "monte_carlo";

  {
    const int orc = navsim_out_begin("budget", out_dir, force, &rd);
    if (orc != 0) {
      rc = orc;
      goto cleanup;
    }
  }
  const char *csv = nav_resultdir_file(rd, "budget.csv");
  f = csv ? fopen(csv, "w") : NULL;
  if (!f) goto cleanup;
  fputs("requirement,metric,statistic,source,contribution,unit,variance,share,method\n", f);
  for (int i = 0; i < nreq; ++i) {
    const nav_requirement *q = &reqs[i];
    const double k = nav_req_unit_to_si(q->unit);
    for (int j = 0; j < rb[i].n; ++j) {
      const row *w = &rb[i].rows[j];
      fprintf(f, "%s,%s,%s,%s,%.17g,%s,%.17g,%.17g,%s\n", q->id, nav_req_metric_name(q->metric),
              nav_req_statistic_name(q->statistic), w->source, sqrt(fmax(w->var, 0.0)) / k, nav_req_unit_name(q->unit),
              w->var / (k * k), w->share, method);
    }
  }
  bool bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad) {
    f = NULL;
    goto cleanup;
  }
  f = NULL;
  const char *js = nav_resultdir_file(rd, "budget.json");
  f = js ? fopen(js, "w") : NULL;
  if (!f) goto cleanup;
  const unsigned unmod = covariance ? nav_budget_unmodelled_terms(sc) : 0u;
  fprintf(f, "{\n  \"navsim_version\": \"%s\",\n  \"scene\": \"%s\",\n  \"method\": \"%s\",\n", nav_version_string(),
          sc->name, method);
  if (covariance)
    fputs("  \"method_note\": \"covariance analysis, one source at a time, gains of the full model (variances add)\",\n", f);
  else
    fprintf(f, "  \"method_note\": \"Monte Carlo, %ld runs per source alone; shares of the sum over the sources\",\n",
            sc->simulation.runs);
  fputs("  \"not_budgeted\": [", f);
  int nn = 0;
  for (int t = 0; t < 9; ++t) {
    if (unmod & (1u << t)) fprintf(f, "%s\"gyro_%s\"", nn++ ? ", " : "", k_term_names[t]);
    if (unmod & (1u << (t + 16))) fprintf(f, "%s\"accel_%s\"", nn++ ? ", " : "", k_term_names[t]);
  }
  fputs("],\n  \"requirements\": [\n", f);
  for (int i = 0; i < nreq; ++i) {
    const nav_requirement *q = &reqs[i];
    const double k = nav_req_unit_to_si(q->unit);
    fprintf(f, "    {\"id\": \"%s\", \"metric\": \"%s\", \"statistic\": \"%s\", \"unit\": \"%s\", \"limit\": ", q->id,
            nav_req_metric_name(q->metric), nav_req_statistic_name(q->statistic), nav_req_unit_name(q->unit));
    if (q->limit < 1e299) fprintf(f, "%.17g", q->limit);
    else fputs("null", f);
    fputs(", \"t_s\": ", f);
    if (isfinite(rb[i].t_s)) fprintf(f, "%.17g", rb[i].t_s);
    else fputs("null", f);
    fputs(", \"total\": ", f);
    if (isfinite(rb[i].total_ms)) fprintf(f, "%.17g", sqrt(rb[i].total_ms) / k);
    else fputs("null", f);
    if (!covariance) {
      fputs(", \"all_sources_together\": ", f);
      if (isfinite(rb[i].all_ms)) fprintf(f, "%.17g", sqrt(rb[i].all_ms) / k);
      else fputs("null", f);
    }
    fputs(", \"sources\": [", f);
    for (int j = 0; j < rb[i].n; ++j)
      fprintf(f, "%s{\"source\": \"%s\", \"contribution\": %.17g, \"share\": %.17g}", j ? ", " : "", rb[i].rows[j].source,
              sqrt(fmax(rb[i].rows[j].var, 0.0)) / k, rb[i].rows[j].share);
    fprintf(f, "]}%s\n", i + 1 < nreq ? "," : "");
  }
  fputs("  ]\n}\n", f);
  bad = ferror(f) != 0;
  if (fclose(f) != 0 || bad) {
    f = NULL;
    goto cleanup;
  }
  f = NULL;
  {
    const int orc = navsim_out_commit("budget", rd);
    if (orc != 0) {
      rd = NULL;
      rc = orc;
      goto cleanup;
    }
  }
  rd = NULL;
  if (!quiet) {
    printf("scene      %s (%s, %s; %s)\n", sc->name, scene_path, nav_nav_scheme_name(sc->navigation.scheme),
           covariance ? "covariance budget" : "Monte Carlo budget");
    for (int i = 0; i < nreq; ++i) {
      const nav_requirement *q = &reqs[i];
      const double k = nav_req_unit_to_si(q->unit);
      const char *u = nav_req_unit_name(q->unit);
      const bool ms_budget = q->statistic != NAV_REQ_RMS && q->statistic != NAV_REQ_AT_TIME &&
                             q->statistic != NAV_REQ_OUTAGE_END; /* budgeted through the mean square */
      printf("%s  %s %s: %s %.4g %s", q->id, nav_req_metric_name(q->metric), nav_req_statistic_name(q->statistic),
             ms_budget ? "budgeted as its RMS," : covariance ? "predicted" : "sum of the sources", sqrt(rb[i].total_ms) / k,
             u);
      if (q->limit < 1e299) printf(" (limit %.4g %s)", q->limit, u);
      if (isfinite(rb[i].t_s)) printf(" at t = %g s", rb[i].t_s);
      if (!covariance) printf("; all sources together %.4g %s", sqrt(rb[i].all_ms) / k, u);
      printf("\n");
      for (int j = 0; j < rb[i].n && j < 5; ++j)
        printf("  %6.2f %%  %-26s %.4g %s\n", 100.0 * rb[i].rows[j].share, rb[i].rows[j].source,
               sqrt(fmax(rb[i].rows[j].var, 0.0)) / k, u);
    }
    if (unmod) {
      printf("not budgeted (outside the filter's linear model; Monte Carlo with that term alone):");
      for (int t = 0; t < 9; ++t) {
        if (unmod & (1u << t)) printf(" gyro_%s", k_term_names[t]);
        if (unmod & (1u << (t + 16))) printf(" accel_%s", k_term_names[t]);
      }
      printf("\n");
    }
    printf("results    %s/\n", out_dir);
  }
  rc = 0;
cleanup:
  if (f) fclose(f);
  nav_resultdir_abort(rd);
  free(rb);
  free(res);
  free(mb);
  nav_scene_release(sc);
  free(sc);
  return rc;
}
