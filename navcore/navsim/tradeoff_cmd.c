/*
 * navsim tradeoff: speed against error per scene (issue 23, item 6). Every modelling choice the
 * scene offers is changed one at a time (IMU rate, mechanization algorithm, Earth and gravity
 * model, frame, covariance decimation, filter states, each sensor error term switched off), each
 * variant is run by Monte Carlo with the scene's seed, and its CPU time per run is set against
 * the value of each requirement with a confidence interval. A combined variant applies the
 * cheapest acceptable change of each cost group together. The recommendation is the cheapest
 * variant whose value of every requirement is within the tolerance of the full model's (the
 * scene as written), written as a scene.
 *
 * Each variant is made by editing the nav_scene value, written as scene text
 * (nav_scene_write_string) and read back (nav_scene_read_string + nav_requirements_check_scene):
 * the scene that is run is the one a file would give, and a variant the scene cannot take is
 * skipped with the reader's message rather than run.
 *
 * Confidence interval: percentile bootstrap over the Monte Carlo runs. The statistics of the
 * requirements include quantiles (p95, cep50, cep95) and maxima, for which no closed-form
 * interval over runs holds; resampling whole runs keeps the time correlation inside a run. Each
 * resample re-evaluates the requirement with the same evaluator as navsim run (nav_requirements.h)
 * from the stored epoch errors of the runs drawn. The resampling PRNG (splitmix64) has a fixed
 * seed, so the interval is deterministic. With few runs a percentile bootstrap is too narrow
 * (it cannot see values beyond the runs drawn); the help says so.
 */
#define _POSIX_C_SOURCE 200809L
#include "child_run.h"
#include "cli_util.h"
#include "tradeoff_cmd.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_errors.h"
#include "navcore/nav_io.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };
#define TO_MAX_VARIANTS 48
#define TO_BOOT 200 /* bootstrap resamples */
#define TO_BOOT_SEED 0x7261646f66665eedULL

static const char *k_usage_tradeoff =
    "usage: navsim tradeoff SCENE [--requirement ID] [--runs N] [--tolerance FRAC] [--threads N]\n"
    "                      --out DIR [--force] [--quiet]\n"
    "\n"
    "Speed against error for every modelling choice the scene offers, changed one at a time from\n"
    "the scene as written (the full model): IMU rate x0.5 and x2, the other mechanization\n"
    "algorithm, the other Earth model, the other gravity model and frame (WGS-84), covariance\n"
    "decimation 2, 5 and 10 and the scale-factor states on or off (ins_gnss: 15/18 <-> 21 states;\n"
    "the 3 GNSS position states follow the GNSS error model, so they change with 'gnss pos_gm\n"
    "off'), and each IMU and GNSS error term the scene has switched off in turn. A variant the\n"
    "scene cannot take (the scene reader refuses it, or it does not apply to the scheme) is\n"
    "listed as skipped with the reason.\n"
    "Each variant runs N Monte Carlo runs (--runs, default the scene's simulation.runs but at\n"
    "most 4) with the scene's seed. Per variant: CPU time per run (clock_gettime\n"
    "CLOCK_PROCESS_CPUTIME_ID over the Monte Carlo, all threads, divided by N: noisy, a few per\n"
    "cent between repeats; compare variants, not machines) and per requirement its value (the\n"
    "evaluator of navsim run) with a 95 % confidence interval: percentile bootstrap over the runs\n"
    "(200 resamples of whole runs, fixed seed, so deterministic). Bootstrap because the statistics\n"
    "include quantiles and maxima, for which no closed-form interval exists; with few runs the\n"
    "interval is too narrow (it cannot reach beyond the runs drawn): read it as a lower bound of\n"
    "the Monte Carlo uncertainty.\n"
    "A variant is within tolerance when for every requirement (or only --requirement ID)\n"
    "|value - full| <= FRAC x full (--tolerance, default 0.1). One more variant, 'combined', applies\n"
    "together the cheapest variant within tolerance of each cost group (IMU rate, algorithm,\n"
    "gravity, frame, covariance decimation, filter states; not the sensor terms, which change the\n"
    "simulated hardware) and is run and judged like the others (skipped with the reason when fewer\n"
    "than two groups have one). The recommendation is the variant within tolerance with the least\n"
    "CPU time per run (the full model when none is cheaper).\n"
    "Writes into DIR (atomically):\n"
    "  tradeoff.csv         one row per variant and requirement: variant, group, change, status\n"
    "                       (ok or skipped), note, cpu_s_per_run, wall_s, runs, requirement,\n"
    "                       statistic, unit, value, ci_low, ci_high, full_value, rel_diff,\n"
    "                       tolerance, within_tolerance, pareto (no other variant is both cheaper and\n"
    "                       more accurate), recommended\n"
    "  recommended.yaml     the recommended variant as a scene (simulation.runs as the scene's)\n"
    "  tradeoff.md          the table and the recommendation\n"
    "  summary.json         scene, seed, runs, tolerance, the recommendation and the requirement\n"
    "                       verdicts of the recommended variant (what navsim report DIR shows)\n"
    "  tradeoff_<ID>.png    per requirement: CPU time against value with its interval, each point\n"
    "                       labelled, the Pareto front drawn (navview --tradeoff; when navview is\n"
    "                       built)\n" NAVSIM_OUT_HELP
    "\n"
    "exit codes: 0 success; 2 invalid scene or options; 1 other failure\n";

typedef struct to_variant {
  char name[64];
  char group[32];
  char change[400];
  bool skipped;
  char note[1200];
  nav_scene *scene; /* the scene read back (NULL when skipped) */
  double cpu_s_per_run, wall_s;
  nav_requirement_verdict *v;  /* nreq */
  double *ci_lo, *ci_hi;       /* nreq */
} to_variant;

/* ---------------------------------------------------------------- per-run epoch store */

typedef struct run_store {
  nav_epoch_errors *e;
  size_t n, cap;
  bool complete;
} run_store;

typedef struct to_obs {
  nav_run_observer inner;
  run_store *runs;
  long nruns;
} to_obs;

typedef struct to_ctx {
  to_obs *o;
  void *inner_ctx;
  long run;
  bool oom;
} to_ctx;

static void *obs_begin(void *user, long run) {
  to_obs *o = user;
  to_ctx *c = calloc(1, sizeof *c);
  if (!c) return NULL;
  c->o = o;
  c->run = run;
  c->inner_ctx = o->inner.begin(o->inner.user, run);
  return c;
}

static void obs_epoch(void *ctx, const nav_epoch_errors *e) {
  to_ctx *c = ctx;
  if (c->inner_ctx) c->o->inner.epoch(c->inner_ctx, e);
  if (c->run < 0 || c->run >= c->o->nruns || c->oom) return;
  run_store *s = &c->o->runs[c->run];
  if (s->n == s->cap) {
    const size_t nc = s->cap ? 2 * s->cap : 1024;
    nav_epoch_errors *ne = realloc(s->e, nc * sizeof *ne);
    if (!ne) {
      c->oom = true;
      return;
    }
    s->e = ne;
    s->cap = nc;
  }
  s->e[s->n++] = *e;
}

static void obs_end(void *user, void *ctx, bool complete) {
  to_obs *o = user;
  to_ctx *c = ctx;
  if (!c) return;
  o->inner.end(o->inner.user, c->inner_ctx, complete);
  if (c->run >= 0 && c->run < o->nruns) o->runs[c->run].complete = complete && !c->oom;
  free(c);
}

static uint64_t splitmix64(uint64_t *s) {
  uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Percentile bootstrap of every requirement: TO_BOOT resamples of N whole runs drawn with
 * replacement, each evaluated by a fresh evaluator; the 2.5 and 97.5 % nearest-rank quantiles. */
static nav_status bootstrap(const nav_scene *sc, const run_store *runs, long n, int nreq, double *lo, double *hi) {
  nav_status st = NAV_OK;
  double *vals = calloc((size_t)TO_BOOT * (size_t)nreq, sizeof *vals);
  nav_requirement_verdict *v = calloc((size_t)nreq, sizeof *v);
  int *valid = calloc((size_t)nreq, sizeof *valid);
  if (!vals || !v || !valid) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  uint64_t seed = TO_BOOT_SEED ^ sc->simulation.seed;
  for (int b = 0; b < TO_BOOT && st == NAV_OK; ++b) {
    nav_req_evaluator *ev = NULL;
    st = nav_req_evaluator_create_for_scene(sc, false, &ev);
    for (long k = 0; k < n && st == NAV_OK; ++k) {
      const long pick = (long)(splitmix64(&seed) % (uint64_t)n);
      nav_req_run *r = NULL;
      st = nav_req_run_begin(ev, k, &r);
      for (size_t i = 0; i < runs[pick].n && st == NAV_OK; ++i)
        st = nav_req_run_add(r, &runs[pick].e[i]);
      if (st == NAV_OK) st = nav_req_run_end(ev, r);
      else if (r) nav_req_run_discard(r);
    }
    if (st == NAV_OK) st = nav_req_evaluator_finish(ev, v);
    nav_req_evaluator_destroy(ev);
    if (st != NAV_OK) break;
    for (int q = 0; q < nreq; ++q)
      if (v[q].evaluated && isfinite(v[q].value)) vals[(size_t)q * TO_BOOT + (size_t)valid[q]++] = v[q].value;
  }
  if (st != NAV_OK) goto cleanup;
  for (int q = 0; q < nreq; ++q) {
    const int m = valid[q];
    lo[q] = hi[q] = NAN;
    if (m == 0) continue;
    double *x = &vals[(size_t)q * TO_BOOT];
    qsort(x, (size_t)m, sizeof *x, cmp_double);
    /* nearest rank: the smallest value with at least p of the values at or below it */
    int il = (int)ceil(0.025 * m) - 1, ih = (int)ceil(0.975 * m) - 1;
    if (il < 0) il = 0;
    if (ih < 0) ih = 0;
    lo[q] = x[il];
    hi[q] = x[ih];
  }
cleanup:
  free(vals);
  free(v);
  free(valid);
  return st;
}

/* Monte Carlo of one variant: verdicts, CPU time per run, wall time and bootstrap intervals. */
static nav_status run_variant(to_variant *va, long runs, int threads, int nreq, char *err, size_t err_size) {
  nav_scene *s = malloc(sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  *s = *va->scene;
  s->simulation.runs = runs;
  nav_sim *sim = NULL;
  nav_req_evaluator *ev = NULL;
  run_store *store = calloc((size_t)runs, sizeof *store);
  nav_status st = store ? nav_sim_create(s, &sim) : NAV_ERR_NO_MEMORY;
  if (st == NAV_OK) st = nav_req_evaluator_create_for_scene(s, false, &ev);
  if (st == NAV_OK) {
    to_obs o = {nav_req_evaluator_observer(ev), store, runs};
    const nav_run_observer obs = {obs_begin, obs_epoch, obs_end, &o};
    nav_sim_options opt = nav_sim_options_default();
    opt.threads = threads;
    opt.observer = &obs;
    nav_sim_summary sum;
    struct timespec c0, c1;
    const double w0 = navsim_now_s();
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
    st = nav_sim_run(sim, &opt, &sum);
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
    va->wall_s = navsim_now_s() - w0;
    va->cpu_s_per_run = ((double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec)) / (double)runs;
    if (st == NAV_OK) st = nav_req_evaluator_finish(ev, va->v);
    for (long k = 0; k < runs && st == NAV_OK; ++k)
      if (!store[k].complete) {
        snprintf(err, err_size, "run %ld did not complete (or its epoch errors did not fit in memory)", k);
        st = NAV_ERR_NO_MEMORY;
      }
    if (st == NAV_OK) st = bootstrap(s, store, runs, nreq, va->ci_lo, va->ci_hi);
  }
  if (st != NAV_OK && !err[0]) snprintf(err, err_size, "%s", sim ? nav_sim_last_error(sim) : nav_status_str(st));
  for (long k = 0; store && k < runs; ++k)
    free(store[k].e);
  free(store);
  nav_req_evaluator_destroy(ev);
  nav_sim_destroy(sim);
  free(s);
  return st;
}

/* ---------------------------------------------------------------- variants */

typedef struct first_diag {
  char msg[1024];
  int count;
} first_diag;

static void keep_first_diag(void *user, const nav_diag *d) {
  first_diag *f = user;
  if (f->count++ == 0) snprintf(f->msg, sizeof f->msg, "%s%s%s", d->path, d->path[0] ? ": " : "", d->message);
}

static void keep_first_issue(void *user, const char *path, const char *message) {
  first_diag *f = user;
  if (f->count++ == 0) snprintf(f->msg, sizeof f->msg, "%s%s%s", path, path[0] ? ": " : "", message);
}

/* Write @p edited as scene text and read it back: the variant's scene, or skipped with the
 * reader's first message. */
static void realise(to_variant *va, const nav_scene *edited) {
  char *text = NULL;
  size_t len = 0;
  if (nav_scene_write_string(edited, &text, &len) != NAV_OK) {
    va->skipped = true;
    snprintf(va->note, sizeof va->note, "the scene writer refused the variant");
    return;
  }
  nav_scene *s = malloc(sizeof *s);
  first_diag fd = {"", 0};
  nav_status st = s ? nav_scene_read_string(text, len, va->name, s, keep_first_diag, &fd) : NAV_ERR_NO_MEMORY;
  const bool read_ok = st == NAV_OK;
  if (st == NAV_OK) st = nav_requirements_check_scene(s, keep_first_issue, &fd);
  free(text);
  if (st != NAV_OK) {
    if (read_ok) nav_scene_release(s);
    free(s);
    va->skipped = true;
    snprintf(va->note, sizeof va->note, "not a valid scene: %s", fd.msg[0] ? fd.msg : nav_status_str(st));
    return;
  }
  va->scene = s;
}

static to_variant *add_variant(to_variant *vs, int *n, const char *name, const char *group, const char *change) {
  if (*n >= TO_MAX_VARIANTS) return NULL;
  to_variant *va = &vs[(*n)++];
  memset(va, 0, sizeof *va);
  snprintf(va->name, sizeof va->name, "%s", name);
  snprintf(va->group, sizeof va->group, "%s", group);
  snprintf(va->change, sizeof va->change, "%s", change);
  return va;
}

static void add_skip(to_variant *vs, int *n, const char *name, const char *group, const char *change,
                     const char *why) {
  to_variant *va = add_variant(vs, n, name, group, change);
  if (!va) return;
  va->skipped = true;
  snprintf(va->note, sizeof va->note, "%s", why);
}

static const struct {
  unsigned bit;
  const char *name;
} k_imu_terms[] = {{NAV_IMU_TERM_BIAS_TURN_ON, "bias_turn_on"}, {NAV_IMU_TERM_BIAS_GM, "bias_gm"},
                   {NAV_IMU_TERM_BIAS_RW, "bias_rw"},           {NAV_IMU_TERM_NOISE, "noise"},
                   {NAV_IMU_TERM_SCALE_FACTOR, "scale_factor"}, {NAV_IMU_TERM_MISALIGNMENT, "misalignment"},
                   {NAV_IMU_TERM_G_SENSITIVITY, "g_sensitivity"}, {NAV_IMU_TERM_QUANTISATION, "quantisation"},
                   {NAV_IMU_TERM_SATURATION, "saturation"}};

static const struct {
  unsigned bit;
  const char *name;
} k_gnss_terms[] = {{NAV_GNSS_TERM_POS_GM, "pos_gm"}, {NAV_GNSS_TERM_POS_WHITE, "pos_white"},
                    {NAV_GNSS_TERM_VEL_WHITE, "vel_white"}};

/* Every variant of @p sc (the first is the full model). @p tmp is scratch. */
static int build_variants(const nav_scene *sc, to_variant *vs, nav_scene *tmp) {
  int n = 0;
  char name[64], change[160];
  to_variant *va = add_variant(vs, &n, "full", "full", "the scene as written");
  realise(va, sc);
  const bool wgs = sc->earth.model == NAV_EARTH_WGS84;
  const bool gf = sc->navigation.scheme == NAV_SCHEME_GYRO_FREE;
  const bool kf = sc->navigation.scheme == NAV_SCHEME_INS_GNSS || sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT;

  static const double k_rate_factor[2] = {0.5, 2.0};
  for (int i = 0; i < 2; ++i) {
    *tmp = *sc;
    tmp->imu.rate_hz = sc->imu.rate_hz * k_rate_factor[i];
    snprintf(name, sizeof name, "imu_rate_x%g", k_rate_factor[i]);
    snprintf(change, sizeof change, "imu.rate_hz %g -> %g", sc->imu.rate_hz, tmp->imu.rate_hz);
    va = add_variant(vs, &n, name, "imu_rate", change);
    if (va) realise(va, tmp);
  }

  *tmp = *sc;
  tmp->navigation.algorithm = sc->navigation.algorithm == NAV_MECH_HIGH_ORDER ? NAV_MECH_FIRST_ORDER : NAV_MECH_HIGH_ORDER;
  snprintf(name, sizeof name, "algorithm_%s", nav_mech_algorithm_name(tmp->navigation.algorithm));
  snprintf(change, sizeof change, "navigation.algorithm %s -> %s", nav_mech_algorithm_name(sc->navigation.algorithm),
           nav_mech_algorithm_name(tmp->navigation.algorithm));
  if (gf) {
    add_skip(vs, &n, name, "algorithm", change, "the gyro-free scheme has its own mechanization (no algorithm choice)");
  } else {
    va = add_variant(vs, &n, name, "algorithm", change);
    if (va) realise(va, tmp);
  }

  *tmp = *sc;
  tmp->earth.model = wgs ? NAV_EARTH_FLAT : NAV_EARTH_WGS84;
  snprintf(name, sizeof name, "earth_%s", nav_earth_model_name(tmp->earth.model));
  snprintf(change, sizeof change, "earth.model %s -> %s", nav_earth_model_name(sc->earth.model),
           nav_earth_model_name(tmp->earth.model));
  va = add_variant(vs, &n, name, "earth", change);
  if (va) realise(va, tmp);

  *tmp = *sc;
  tmp->earth.gravity_model = sc->earth.gravity_model == NAV_GRAVITY_J2 ? NAV_GRAVITY_NORMAL : NAV_GRAVITY_J2;
  snprintf(name, sizeof name, "gravity_%s", nav_gravity_model_name(tmp->earth.gravity_model));
  snprintf(change, sizeof change, "earth.gravity %s -> %s", nav_gravity_model_name(sc->earth.gravity_model),
           nav_gravity_model_name(tmp->earth.gravity_model));
  if (!wgs) {
    add_skip(vs, &n, name, "gravity", change, "the flat Earth has uniform gravity (no gravity model)");
  } else {
    va = add_variant(vs, &n, name, "gravity", change);
    if (va) realise(va, tmp);
  }

  *tmp = *sc;
  tmp->navigation.frame = sc->navigation.frame == NAV_MECH_ECEF ? NAV_MECH_NED : NAV_MECH_ECEF;
  snprintf(name, sizeof name, "frame_%s", nav_mech_frame_name(tmp->navigation.frame));
  snprintf(change, sizeof change, "navigation.frame %s -> %s", nav_mech_frame_name(sc->navigation.frame),
           nav_mech_frame_name(tmp->navigation.frame));
  if (!wgs) {
    add_skip(vs, &n, name, "frame", change, "the flat Earth has one frame (the frame applies to WGS-84)");
  } else if (gf) {
    add_skip(vs, &n, name, "frame", change, "the gyro-free scheme has its own mechanization (no frame choice)");
  } else {
    va = add_variant(vs, &n, name, "frame", change);
    if (va) realise(va, tmp);
  }

  static const int k_decim[3] = {2, 5, 10};
  const int d0 = sc->navigation.cov_decimation > 1 ? sc->navigation.cov_decimation : 1;
  for (int i = 0; i < 3; ++i) {
    *tmp = *sc;
    tmp->navigation.cov_decimation = k_decim[i];
    snprintf(name, sizeof name, "cov_decimation_%d", k_decim[i]);
    snprintf(change, sizeof change, "navigation.cov_decimation %d -> %d", d0, k_decim[i]);
    if (!kf) add_skip(vs, &n, name, "cov_decimation", change, "no Kalman filter in this scheme (ins_gnss only)");
    else if (k_decim[i] == d0) add_skip(vs, &n, name, "cov_decimation", change, "the scene's own value (the full model)");
    else if ((va = add_variant(vs, &n, name, "cov_decimation", change))) realise(va, tmp);
  }

  *tmp = *sc;
  tmp->navigation.estimate_scale_factors = !sc->navigation.estimate_scale_factors;
  snprintf(name, sizeof name, "states_%s", tmp->navigation.estimate_scale_factors ? "plus_scale_factors" : "no_scale_factors");
  snprintf(change, sizeof change, "navigation.estimate_scale_factors %s -> %s (filter states %s 6)",
           sc->navigation.estimate_scale_factors ? "true" : "false",
           tmp->navigation.estimate_scale_factors ? "true" : "false",
           tmp->navigation.estimate_scale_factors ? "+" : "-");
  if (!kf) {
    add_skip(vs, &n, name, "filter_states", change, "no Kalman filter in this scheme (ins_gnss only)");
  } else {
    va = add_variant(vs, &n, name, "filter_states", change);
    if (va) realise(va, tmp);
  }

  for (int tri = 0; tri < 2; ++tri) {
    const unsigned terms = tri == 0 ? sc->imu.model.gyro.terms : sc->imu.model.accel.terms;
    for (size_t i = 0; i < sizeof k_imu_terms / sizeof k_imu_terms[0]; ++i) {
      if (!(terms & k_imu_terms[i].bit)) continue;
      *tmp = *sc;
      if (tri == 0) tmp->imu.model.gyro.terms &= ~k_imu_terms[i].bit;
      else tmp->imu.model.accel.terms &= ~k_imu_terms[i].bit;
      snprintf(name, sizeof name, "%s_%s_off", tri == 0 ? "gyro" : "accel", k_imu_terms[i].name);
      snprintf(change, sizeof change, "imu.%s %s switched off (truth and filter model)", tri == 0 ? "gyro" : "accel",
               k_imu_terms[i].name);
      if (gf && tri == 0) add_skip(vs, &n, name, "sensor_term", change, "the gyro-free scheme does not use the gyro triad");
      else if ((va = add_variant(vs, &n, name, "sensor_term", change))) realise(va, tmp);
    }
  }
  if (kf && sc->gnss.enabled)
    for (size_t i = 0; i < sizeof k_gnss_terms / sizeof k_gnss_terms[0]; ++i) {
      if (!(sc->gnss.model.terms & k_gnss_terms[i].bit)) continue;
      *tmp = *sc;
      tmp->gnss.model.terms &= ~k_gnss_terms[i].bit;
      snprintf(name, sizeof name, "gnss_%s_off", k_gnss_terms[i].name);
      snprintf(change, sizeof change, "gnss %s switched off (truth and filter model)", k_gnss_terms[i].name);
      if ((va = add_variant(vs, &n, name, "sensor_term", change))) realise(va, tmp);
    }
  return n;
}


static bool within(double v, double full, double tol) {
  return isfinite(v) && isfinite(full) && fabs(v - full) <= tol * fabs(full);
}

/* Variant i is on the Pareto front of requirement q: no other run variant is at least as cheap
 * and at least as accurate, and strictly better in one of the two. */
static bool pareto(const to_variant *vs, int n, int i, int q) {
  const to_variant *a = &vs[i];
  if (a->skipped || !a->v[q].evaluated || !isfinite(a->v[q].value)) return false;
  for (int j = 0; j < n; ++j) {
    const to_variant *b = &vs[j];
    if (j == i || b->skipped || !b->v[q].evaluated || !isfinite(b->v[q].value)) continue;
    if (b->cpu_s_per_run <= a->cpu_s_per_run && b->v[q].value <= a->v[q].value &&
        (b->cpu_s_per_run < a->cpu_s_per_run || b->v[q].value < a->v[q].value))
      return false;
  }
  return true;
}

/* ---------------------------------------------------------------- command */

/* The groups whose variants are cheaper computations of the same problem, combined into one
   candidate; the sensor-term variants change the simulated hardware and are not combined. */
#define TO_GROUPS 6
static const char *const k_cost_groups[TO_GROUPS] = {"imu_rate", "algorithm", "gravity", "frame", "cov_decimation",
                                                     "filter_states"};

/* Copy the field of cost group @p group from @p from (a variant's scene) into @p to. */
static void apply_group(nav_scene *to, const nav_scene *from, const char *group) {
  if (!strcmp(group, "imu_rate")) to->imu.rate_hz = from->imu.rate_hz;
  else if (!strcmp(group, "algorithm")) to->navigation.algorithm = from->navigation.algorithm;
  else if (!strcmp(group, "gravity")) to->earth.gravity_model = from->earth.gravity_model;
  else if (!strcmp(group, "frame")) to->navigation.frame = from->navigation.frame;
  else if (!strcmp(group, "cov_decimation")) to->navigation.cov_decimation = from->navigation.cov_decimation;
  else if (!strcmp(group, "filter_states"))
    to->navigation.estimate_scale_factors = from->navigation.estimate_scale_factors;
}

/* Run variant @p va unless skipped; a failure marks it skipped with the simulation's message.
   @return false when it failed. */
static bool run_and_print(to_variant *va, long runs, int threads, int nreq, bool quiet) {
  if (va->skipped) {
    if (!quiet) printf("  %-28s skipped: %s\n", va->name, va->note);
    return true;
  }
  char err[512] = "";
  const nav_status st = run_variant(va, runs, threads, nreq, err, sizeof err);
  if (st != NAV_OK) {
    /* A variant the simulation refuses (e.g. a numerical failure) is reported, not faked. */
    va->skipped = true;
    snprintf(va->note, sizeof va->note, "the simulation failed: %s", err);
    if (!quiet) printf("  %-28s failed: %s\n", va->name, err);
    return false;
  }
  if (!quiet) {
    printf("  %-28s %8.3f s CPU/run", va->name, va->cpu_s_per_run);
    for (int q = 0; q < nreq; ++q)
      printf("  %s %.4g [%.4g, %.4g] %s", va->v[q].id, va->v[q].value, va->ci_lo[q], va->ci_hi[q],
             nav_req_unit_name(va->v[q].unit));
    printf("\n");
    fflush(stdout);
  }
  return true;
}

/* ok[i]: variant i was run and each considered requirement is within @p tol of the full model. */
static void mark_within(const to_variant *vs, int nv, int nreq, int qsel, double tol, bool *ok) {
  for (int i = 0; i < nv; ++i) {
    ok[i] = !vs[i].skipped;
    for (int q = 0; q < nreq && ok[i]; ++q)
      if ((qsel < 0 || q == qsel) && !within(vs[i].v[q].value, vs[0].v[q].value, tol)) ok[i] = false;
  }
}

static void csv_text(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; ++s) {
    if (*s == '"') fputc('"', f);
    fputc(*s, f);
  }
  fputc('"', f);
}

static void json_text(FILE *f, const char *s) {
  fputc('"', f);
  for (const unsigned char *p = (const unsigned char *)s; *p; ++p) {
    if (*p == '"' || *p == '\\') fprintf(f, "\\%c", *p);
    else if (*p < 0x20) fprintf(f, "\\u%04x", *p);
    else fputc(*p, f);
  }
  fputc('"', f);
}

/* A figure of tradeoff.csv: the shortest text that reads back to the same double. The pareto,
   within_tolerance and recommended columns are decided on these doubles, so a reader who recomputes
   them from the file gets the same answers; with 9 digits, two variants whose errors differ in the
   10th digit printed equal and a front point looked dominated. */
static void csv_num(FILE *f, double v) {
  if (!isfinite(v)) {
    fputs(",", f);
    return;
  }
  char b[40];
  for (int prec = 9; prec <= 17; ++prec) {
    snprintf(b, sizeof b, "%.*g", prec, v);
    if (strtod(b, NULL) == v) break;
  }
  fprintf(f, ",%s", b);
}

int navsim_tradeoff(int argc, char **argv) {
  const char *scene_path = NULL, *out_dir = NULL, *req_id = NULL;
  long runs = 0, threads = 0;
  double tol = 0.1;
  bool quiet = false, force = false;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (navsim_is_help(a)) {
      fputs(k_usage_tradeoff, stdout);
      return EXIT_OK;
    } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
      quiet = true;
    } else if (!strcmp(a, "--force")) {
      force = true;
    } else if (!strcmp(a, "--out") || !strcmp(a, "--runs") || !strcmp(a, "--threads") ||
               !strcmp(a, "--requirement") || !strcmp(a, "--tolerance")) {
      if (!navsim_need_value("tradeoff", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (!strcmp(a, "--out")) {
        out_dir = v;
      } else if (!strcmp(a, "--requirement")) {
        req_id = v;
      } else if (!strcmp(a, "--tolerance")) {
        if (!navsim_parse_positive(v, &tol, false) || tol >= 10) {
          fprintf(stderr, "navsim tradeoff: --tolerance: expected a fraction > 0 and < 10 (0.1 = 10 %%), got \"%s\"\n",
                  v);
          return EXIT_INVALID;
        }
      } else {
        const long hi = !strcmp(a, "--runs") ? 10000 : 256;
        long x = 0;
        if (!navsim_parse_long(v, 1, hi, &x)) {
          fprintf(stderr, "navsim tradeoff: %s: expected an integer in [1, %ld], got \"%s\"\n", a, hi, v);
          return EXIT_INVALID;
        }
        if (!strcmp(a, "--runs")) runs = x;
        else threads = x;
      }
    } else {
      const int rc = navsim_scene_arg("tradeoff", a, &scene_path);
      if (rc != EXIT_OK) return rc;
    }
  }
  if (!scene_path || !out_dir) {
    fprintf(stderr, "navsim tradeoff: %s\n%s", !scene_path ? "missing SCENE" : "missing --out DIR", k_usage_tradeoff);
    return EXIT_INVALID;
  }
  {
    const int orc = navsim_out_check("tradeoff", out_dir, force);
    if (orc != EXIT_OK) return orc;
  }
  if (threads == 0) {
    const long nc = sysconf(_SC_NPROCESSORS_ONLN);
    threads = nc > 0 ? nc : 1;
  }

  int rc = EXIT_FAIL, nv = 0, nreq = 0, qsel = -1, rec = 0;
  nav_scene *sc = malloc(sizeof *sc), *tmp = malloc(sizeof *tmp);
  to_variant *vs = calloc(TO_MAX_VARIANTS, sizeof *vs);
  nav_resultdir *rd = NULL;
  FILE *f = NULL;
  char paths[8][4400]; /* tradeoff.csv, recommended.yaml, tradeoff.md, a chart, its log, summary.json */
  if (!sc || !tmp || !vs) goto done;
  *sc = nav_scene_default(); /* owns nothing: nav_scene_release below is safe on every path */
  rc = navsim_load_scene(scene_path, sc);
  if (rc != EXIT_OK) goto done;
  rc = EXIT_FAIL;
  nreq = sc->n_requirements;
  if (nreq == 0) {
    fprintf(stderr, "%s: error: requirements: the scene has no requirements to weigh speed against\n", scene_path);
    rc = EXIT_INVALID;
    goto done;
  }
  if (req_id) {
    for (int q = 0; q < nreq; ++q)
      if (!strcmp(sc->requirements[q].id, req_id)) qsel = q;
    if (qsel < 0) {
      fprintf(stderr, "navsim tradeoff: --requirement %s: the scene has no requirement with that id (it has:", req_id);
      for (int q = 0; q < nreq; ++q)
        fprintf(stderr, " %s", sc->requirements[q].id);
      fputs(")\n", stderr);
      rc = EXIT_INVALID;
      goto done;
    }
  }
  if (runs == 0) runs = sc->simulation.runs < 4 ? sc->simulation.runs : 4;
  if (runs < 1) runs = 1;
  nv = build_variants(sc, vs, tmp);
  if (vs[0].skipped) {
    fprintf(stderr, "navsim tradeoff: %s: the scene does not read back as written: %s\n", scene_path, vs[0].note);
    goto done;
  }
  for (int i = 0; i < nv; ++i) {
    vs[i].v = calloc((size_t)nreq, sizeof *vs[i].v);
    vs[i].ci_lo = calloc((size_t)nreq, sizeof *vs[i].ci_lo);
    vs[i].ci_hi = calloc((size_t)nreq, sizeof *vs[i].ci_hi);
    if (!vs[i].v || !vs[i].ci_lo || !vs[i].ci_hi) goto done;
  }
  rc = navsim_out_begin("tradeoff", out_dir, force, &rd);
  if (rc != EXIT_OK) goto done;
  rc = EXIT_FAIL;

  int nrun = 0;
  for (int i = 0; i < nv; ++i)
    nrun += !vs[i].skipped;
  if (!quiet)
    printf("tradeoff   %s: %d variants (%d skipped), %ld run%s each, seed %llu\n", sc->name, nv, nv - nrun, runs,
           runs == 1 ? "" : "s", (unsigned long long)sc->simulation.seed);
  for (int i = 0; i < nv; ++i)
    if (!run_and_print(&vs[i], runs, (int)threads, nreq, quiet) && i == 0) {
      fprintf(stderr, "navsim tradeoff: %s: the full model failed: %s\n", scene_path, vs[0].note);
      goto done;
    }

  /* Within tolerance of the full model (index 0). */
  bool *ok = calloc(TO_MAX_VARIANTS, sizeof *ok);
  if (!ok) goto done;
  mark_within(vs, nv, nreq, qsel, tol, ok);
  /* The combination: per cost group the cheapest variant within tolerance that is cheaper than the
     full model, all applied together, run and judged like the others. */
  {
    int pick[TO_GROUPS];
    char change[400] = "";
    int npick = 0;
    for (int g = 0; g < TO_GROUPS; ++g) {
      pick[g] = -1;
      for (int i = 1; i < nv; ++i)
        if (ok[i] && !strcmp(vs[i].group, k_cost_groups[g]) && vs[i].cpu_s_per_run < vs[0].cpu_s_per_run &&
            (pick[g] < 0 || vs[i].cpu_s_per_run < vs[pick[g]].cpu_s_per_run))
          pick[g] = i;
      if (pick[g] < 0) continue;
      const size_t len = strlen(change);
      snprintf(change + len, sizeof change - len, "%s%s", npick ? " + " : "", vs[pick[g]].name);
      ++npick;
    }
    if (nv < TO_MAX_VARIANTS) {
      if (npick >= 2) {
        *tmp = *sc;
        for (int g = 0; g < TO_GROUPS; ++g)
          if (pick[g] >= 0) apply_group(tmp, vs[pick[g]].scene, k_cost_groups[g]);
        to_variant *va = add_variant(vs, &nv, "combined", "combined", change);
        realise(va, tmp);
      } else {
        add_skip(vs, &nv, "combined", "combined", npick ? change : "(none)",
                 npick ? "only one cost group has a cheaper variant within tolerance (that variant is the combination)"
                       : "no cost group has a variant within tolerance that is cheaper than the full model");
      }
      to_variant *va = &vs[nv - 1];
      va->v = calloc((size_t)nreq, sizeof *va->v);
      va->ci_lo = calloc((size_t)nreq, sizeof *va->ci_lo);
      va->ci_hi = calloc((size_t)nreq, sizeof *va->ci_hi);
      if (!va->v || !va->ci_lo || !va->ci_hi) goto io_fail_ok;
      run_and_print(va, runs, (int)threads, nreq, quiet);
      mark_within(vs, nv, nreq, qsel, tol, ok);
    }
  }
  /* The recommendation: the cheapest within tolerance (the full model unless one is cheaper). */
  for (int i = 1; i < nv; ++i)
    if (ok[i] && vs[i].cpu_s_per_run < vs[rec].cpu_s_per_run) rec = i;

  snprintf(paths[0], sizeof paths[0], "%s", nav_resultdir_file(rd, "tradeoff.csv"));
  f = fopen(paths[0], "w");
  if (!f) goto io_fail_ok;
  fputs("variant,group,change,status,note,cpu_s_per_run,wall_s,runs,requirement,statistic,unit,value,ci_low,ci_high,"
        "full_value,rel_diff,tolerance,within_tolerance,pareto,recommended\n",
        f);
  for (int i = 0; i < nv; ++i) {
    const to_variant *va = &vs[i];
    for (int q = 0; q < nreq; ++q) {
      const nav_requirement *r = &sc->requirements[q];
      csv_text(f, va->name);
      fputc(',', f);
      csv_text(f, va->group);
      fputc(',', f);
      csv_text(f, va->change);
      fprintf(f, ",%s,", va->skipped ? "skipped" : "ok");
      csv_text(f, va->skipped ? va->note : (va->v[q].evaluated ? "" : nav_req_na_reason_text(va->v[q].na_reason)));
      if (va->skipped) {
        fprintf(f, ",,,,%s,%s,%s,,,,,,,,,\n", r->id, nav_req_statistic_name(r->statistic), nav_req_unit_name(r->unit));
        continue;
      }
      csv_num(f, va->cpu_s_per_run);
      csv_num(f, va->wall_s);
      fprintf(f, ",%ld,%s,%s,%s", runs, r->id, nav_req_statistic_name(r->statistic), nav_req_unit_name(r->unit));
      const double val = va->v[q].evaluated ? va->v[q].value : NAN, full = vs[0].v[q].value;
      csv_num(f, val);
      csv_num(f, va->ci_lo[q]);
      csv_num(f, va->ci_hi[q]);
      csv_num(f, full);
      csv_num(f, isfinite(val) && isfinite(full) && full != 0 ? (val - full) / full : NAN);
      csv_num(f, tol);
      fprintf(f, ",%s,%s,%s\n", within(val, full, tol) ? "true" : "false", pareto(vs, nv, i, q) ? "true" : "false",
              i == rec ? "true" : "false");
    }
  }
  {
    const bool bad = ferror(f) != 0;
    const int cl = fclose(f);
    f = NULL;
    if (bad || cl != 0) goto io_fail_ok;
  }

  /* The recommended scene, with the scene's own run count. */
  *tmp = *vs[rec].scene;
  tmp->simulation.runs = sc->simulation.runs;
  snprintf(paths[1], sizeof paths[1], "%s", nav_resultdir_file(rd, "recommended.yaml"));
  if (nav_scene_write_file(paths[1], tmp) != NAV_OK) goto io_fail_ok;

  snprintf(paths[2], sizeof paths[2], "%s", nav_resultdir_file(rd, "tradeoff.md"));
  f = fopen(paths[2], "w");
  if (!f) goto io_fail_ok;
  fprintf(f, "# Speed against error: %s\n\n", sc->name);
  fprintf(f,
          "%ld Monte Carlo run%s per variant (seed %llu); CPU time per run (all threads); values with the 95 %% "
          "percentile-bootstrap interval over the runs. Tolerance: %.3g %% of the full model's value%s%s.\n\n",
          runs, runs == 1 ? "" : "s", (unsigned long long)sc->simulation.seed, 100 * tol,
          qsel >= 0 ? " for requirement " : " for every requirement", qsel >= 0 ? sc->requirements[qsel].id : "");
  fputs("| variant | change | CPU s/run |", f);
  for (int q = 0; q < nreq; ++q)
    fprintf(f, " %s [%s] |", sc->requirements[q].id, nav_req_unit_name(sc->requirements[q].unit));
  fputs(" within |\n|---|---|---|", f);
  for (int q = 0; q < nreq; ++q)
    fputs("---|", f);
  fputs("---|\n", f);
  for (int i = 0; i < nv; ++i) {
    const to_variant *va = &vs[i];
    fprintf(f, "| %s%s | %s |", va->name, i == rec ? " (recommended)" : "", va->change);
    if (va->skipped) {
      fprintf(f, " skipped: %s |", va->note);
      for (int q = 0; q < nreq; ++q)
        fputs(" |", f);
      fputs(" |\n", f);
      continue;
    }
    fprintf(f, " %.3g |", va->cpu_s_per_run);
    for (int q = 0; q < nreq; ++q)
      fprintf(f, " %.4g [%.4g, %.4g]%s |", va->v[q].value, va->ci_lo[q], va->ci_hi[q],
              pareto(vs, nv, i, q) ? " P" : "");
    fprintf(f, " %s |\n", ok[i] ? "yes" : "no");
  }
  fprintf(f,
          "\nP: on the Pareto front of that requirement. Recommended: **%s** (%s), %.3g s CPU per run against %.3g s "
          "for the full model; recommended.yaml.\n",
          vs[rec].name, vs[rec].change, vs[rec].cpu_s_per_run, vs[0].cpu_s_per_run);
  {
    const bool bad = ferror(f) != 0;
    const int cl = fclose(f);
    f = NULL;
    if (bad || cl != 0) goto io_fail_ok;
  }

  /* summary.json: what navsim report reads (scene name, seed, runs, the recommendation and the
     requirement verdicts of the recommended variant over the runs of this command). */
  snprintf(paths[5], sizeof paths[5], "%s", nav_resultdir_file(rd, "summary.json"));
  f = fopen(paths[5], "w");
  if (!f) goto io_fail_ok;
  fputs("{\n  \"command\": \"tradeoff\",\n  \"scene\": {\"name\": ", f);
  json_text(f, sc->name);
  fprintf(f, "},\n  \"seed\": %llu,\n  \"runs\": %ld,\n  \"tolerance\": ", (unsigned long long)sc->simulation.seed,
          runs);
  navsim_json_number(f, tol, 9);
  fputs(",\n  \"recommended\": {\"variant\": ", f);
  json_text(f, vs[rec].name);
  fputs(", \"change\": ", f);
  json_text(f, vs[rec].change);
  fputs(", \"cpu_s_per_run\": ", f);
  navsim_json_number(f, vs[rec].cpu_s_per_run, 6);
  fputs(", \"full_cpu_s_per_run\": ", f);
  navsim_json_number(f, vs[0].cpu_s_per_run, 6);
  fputs("},\n  \"requirements_of\": ", f);
  {
    char what[600];
    snprintf(what, sizeof what, "the recommended variant %s over %ld run%s", vs[rec].name, runs, runs == 1 ? "" : "s");
    json_text(f, what);
  }
  fputs(",\n  \"requirements\": ", f);
  if (nav_requirements_write_json(f, vs[rec].v, nreq, 2) != NAV_OK) goto io_fail_ok;
  fputs("\n}\n", f);
  {
    const bool bad = ferror(f) != 0;
    const int cl = fclose(f);
    f = NULL;
    if (bad || cl != 0) goto io_fail_ok;
  }

  /* Charts through navview, one per requirement. */
  const char *nvx = navsim_navview_exe();
  int charts = 0;
  if (nvx) {
    for (int q = 0; q < nreq; ++q) {
      char safe[80], png_name[128], log_name[128];
      navsim_safe_name(safe, sizeof safe, sc->requirements[q].id, "requirement");
      snprintf(png_name, sizeof png_name, "tradeoff_%s.png", safe);
      snprintf(log_name, sizeof log_name, "tradeoff_%s.log", safe);
      snprintf(paths[3], sizeof paths[3], "%s", nav_resultdir_file(rd, png_name));
      snprintf(paths[4], sizeof paths[4], "%s", nav_resultdir_file(rd, log_name));
      char tol_s[32];
      snprintf(tol_s, sizeof tol_s, "%.9g", tol);
      char *with_x[] = {"xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", (char *)nvx, "--tradeoff", paths[0],
                        "--requirement", sc->requirements[q].id, "--png", paths[3], NULL};
      char *plain[] = {(char *)nvx, "--tradeoff", paths[0], "--requirement", sc->requirements[q].id, "--png", paths[3],
                       NULL};
      int exit_code = 0;
      const bool exited_ok = navsim_run_logged(navsim_have_display() ? plain : with_x, paths[4], 120.0, &exit_code);
      if (exited_ok && access(paths[3], R_OK) == 0) {
        ++charts;
        remove(paths[4]);
      } else {
        fprintf(stderr, "navsim tradeoff: %s: navview failed (exit %d; see %s/%s)\n", png_name, exit_code, out_dir,
                log_name);
      }
    }
  } else if (!quiet) {
    printf("charts     skipped (navview not built: NAV_BUILD_VIEWER=OFF)\n");
  }
  free(ok);
  ok = NULL;
  rc = navsim_out_commit("tradeoff", rd);
  rd = NULL;
  if (rc != EXIT_OK) goto done;
  if (!quiet)
    printf("recommended %s (%s): %.3g s CPU/run against %.3g s for the full model, within %.3g %% -> %s/recommended.yaml, "
           "tradeoff.csv, %d chart%s\n",
           vs[rec].name, vs[rec].change, vs[rec].cpu_s_per_run, vs[0].cpu_s_per_run, 100 * tol, out_dir, charts,
           charts == 1 ? "" : "s");
  rc = EXIT_OK;
  goto done;
io_fail_ok:
  free(ok);
  fprintf(stderr, "navsim tradeoff: writing the results into \"%s\" failed\n", out_dir);
  rc = EXIT_FAIL;
done:
  if (f) fclose(f);
  nav_resultdir_abort(rd);
  for (int i = 0; vs && i < nv; ++i) {
    nav_scene_release(vs[i].scene); /* each variant's scene was read (realise) */
    free(vs[i].scene);
    free(vs[i].v);
    free(vs[i].ci_lo);
    free(vs[i].ci_hi);
  }
  free(vs);
  if (sc) nav_scene_release(sc);
  free(sc);
  free(tmp);
  return rc;
}
