/*
 * navsim sweep: evaluate the scene's requirements over a grid of scene parameters, and for a
 * single parameter the largest value that still meets each requirement (inverse design).
 *
 * Parameters are scene fields addressed by their YAML path (nav_scene_override.h): the override
 * is applied to the scene file's YAML and read by the one scene reader, so units, catalog
 * look-ups and validation are those of the file.
 *
 * Threshold of one parameter (per requirement): the grid is ordered by the parameter; from the
 * smallest value upwards the first failing point after a passing one brackets the limit, and
 * the value where the requirement's value equals its limit is interpolated linearly between the
 * two points (in log(parameter) for :log grids). When every point passes, the threshold is at
 * least the largest grid value ("all_pass"); when none passes, below the smallest ("none_pass").
 * A requirement that passes again above a failure is marked "non_monotonic" (the first crossing
 * is reported).
 */
#define _POSIX_C_SOURCE 200809L
#include "cli_util.h"
#include "select_cmd.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_io.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_results.h"
#include "navcore/nav_scene_override.h"
#include "navcore/nav_sim.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };
#define SWEEP_MAX_PARAMS 4
#define SWEEP_MAX_POINTS 10000

static const char *k_usage_sweep =
    "usage: navsim sweep SCENE --param PATH=START:STOP:COUNT[:log] [--param ...] [--runs N] [--threads N]\n"
    "                   [--predict] --out DIR [--force] [--quiet]\n"
    "\n"
    "Evaluate the scene's requirements over a grid of parameter values. PATH is the field's YAML\n"
    "path in the scene file (keys joined by dots, list items by [i]), e.g.\n"
    "  imu.gyro.bias_instability_deg_per_h=0.5:50:9:log   gnss.outages[0].t1_s=170:230:7\n"
    "the value replaces (or adds) that field before the scene is read, exactly like an edit of the\n"
    "file. COUNT values from START to STOP, evenly spaced (or geometrically with :log, START and\n"
    "STOP > 0); several --param make the full grid (first parameter slowest).\n"
    "Each point is evaluated by Monte Carlo (--runs, default the scene's simulation.runs; the\n"
    "scene's seed) or, with --predict, by the covariance prediction (nav_req_predict_scene, the\n"
    "quantiles p95/cep from at most 150 evenly spaced output epochs; statistics such as max are\n"
    "then not evaluated).\n"
    "Writes into DIR (atomically):\n"
    "  sweep.csv       one row per grid point: the parameter values, then per requirement its value\n"
    "                  (the requirement's unit) and pass, then all_pass\n"
    "  thresholds.csv  when one parameter varies (others may be fixed: COUNT 1): per requirement the\n"
    "                  largest value of the varying parameter that still\n"
    "                  meets it, interpolated between the last passing and the first failing grid\n"
    "                  point (linear; in log(value) for :log), with status interpolated, all_pass\n"
    "                  (>= the largest value), none_pass (< the smallest) or non_monotonic\n"
    NAVSIM_OUT_HELP
    "\n"
    "exit codes: 0 success; 2 invalid scene, parameter or options; 1 other failure\n";

typedef struct sweep_param {
  char path[256];
  double start, stop;
  int count;
  bool log;
} sweep_param;

static bool parse_param(const char *text, sweep_param *p) {
  char path[256], rest[256];
  if (nav_scene_override_split(text, path, sizeof path, rest, sizeof rest) != NAV_OK) return false;
  snprintf(p->path, sizeof p->path, "%s", path);
  char *fields[5];
  int nf = 0;
  for (char *tok = strtok(rest, ":"); tok && nf < 5; tok = strtok(NULL, ":")) fields[nf++] = tok;
  if (nf < 3 || nf > 4) return false;
  char *end = NULL;
  p->start = strtod(fields[0], &end);
  if (!end || *end || !isfinite(p->start)) return false;
  p->stop = strtod(fields[1], &end);
  if (!end || *end || !isfinite(p->stop)) return false;
  errno = 0;
  const long c = strtol(fields[2], &end, 10);
  if (errno || !end || *end || c < 1 || c > 1000) return false;
  p->count = (int)c;
  p->log = false;
  if (nf == 4) {
    if (strcmp(fields[3], "log") != 0) return false;
    if (!(p->start > 0) || !(p->stop > 0)) return false;
    p->log = true;
  }
  if (p->count == 1 && p->start != p->stop) return false;
  return true;
}

static double param_value(const sweep_param *p, int i) {
  if (p->count == 1) return p->start;
  const double u = (double)i / (double)(p->count - 1);
  if (p->log) return exp(log(p->start) + u * (log(p->stop) - log(p->start)));
  return p->start + u * (p->stop - p->start);
}

/* The values of grid point @p g (first parameter slowest). */
static void grid_values(const sweep_param *prm, int np, long g, double *vals) {
  long rem = g;
  for (int k = np - 1; k >= 0; --k) {
    vals[k] = param_value(&prm[k], (int)(rem % prm[k].count));
    rem /= prm[k].count;
  }
}

/* Field paths @p a and @p b are the same, or one holds the other ("x.y" and "x.y[1]", "x" and
   "x.y"). */
static bool paths_overlap(const char *a, const char *b) {
  const size_t la = strlen(a), lb = strlen(b), n = la < lb ? la : lb;
  if (strncmp(a, b, n) != 0) return false;
  if (la == lb) return true;
  const char next = la < lb ? b[n] : a[n];
  return next == '.' || next == '[';
}

/* Diagnostics of one grid point before anything is computed. One about a value a --param set
   has no place in the file (nav_scene_doc_read: line 0): it names the --param, the grid value
   and the point; one about the file keeps its place, with the point's values as context. */
typedef struct grid_sink {
  const sweep_param *prm;
  int np;
  const double *vals;
  long point;
  bool print;
  int count;
} grid_sink;

static void grid_diag(void *user, const nav_diag *d) {
  grid_sink *s = user;
  s->count++;
  if (!s->print) return;
  if (d->line == 0)
    for (int k = 0; k < s->np; ++k)
      if (paths_overlap(d->path, s->prm[k].path)) {
        const bool same = strcmp(d->path, s->prm[k].path) == 0;
        fprintf(stderr, "navsim sweep: --param %s: grid value %.17g at point %ld: %s%s%s\n", s->prm[k].path,
                s->vals[k], s->point + 1, same ? "" : d->path, same ? "" : ": ", d->message);
        return;
      }
  char line[2048];
  nav_diag_format(d, line, sizeof line);
  fprintf(stderr, "%s (grid point %ld:", line, s->point + 1);
  for (int k = 0; k < s->np; ++k) fprintf(stderr, " --param %s=%.17g", s->prm[k].path, s->vals[k]);
  fputs(")\n", stderr);
}

/* Every grid point read as a scene before any is computed, so a bad value is found before the
   work, not after the points before it. @return 0, or the exit code (diagnostics printed). */
static int validate_grid(nav_scene_doc *doc, const sweep_param *prm, int np, long total, nav_scene *sc) {
  enum { SHOWN = 5 };
  long bad = 0;
  for (long g = 0; g < total; ++g) {
    double vals[SWEEP_MAX_PARAMS];
    grid_values(prm, np, g, vals);
    for (int k = 0; k < np; ++k) {
      char val[64], msg[512];
      snprintf(val, sizeof val, "%.17g", vals[k]);
      if (nav_scene_doc_set(doc, prm[k].path, val, msg, sizeof msg) != NAV_OK) {
        fprintf(stderr, "navsim sweep: --param %s: %s\n", prm[k].path, msg);
        return EXIT_INVALID;
      }
    }
    grid_sink gs = {prm, np, vals, g, bad < SHOWN, 0};
    nav_scene_release(sc); /* the previous point's recorded model, if any */
    const nav_status st = nav_scene_doc_read(doc, sc, grid_diag, &gs);
    if (st == NAV_OK) continue;
    if (st != NAV_ERR_PARSE) {
      fprintf(stderr, "navsim sweep: grid point %ld: %s\n", g + 1, nav_status_str(st));
      return EXIT_FAIL;
    }
    if (gs.count == 0 && bad < SHOWN) fprintf(stderr, "navsim sweep: grid point %ld is not a valid scene\n", g + 1);
    ++bad;
  }
  if (bad == 0) return EXIT_OK;
  fprintf(stderr, "navsim sweep: %ld of %ld grid point%s %s not a valid scene%s; nothing was computed\n", bad, total,
          total == 1 ? "" : "s", bad == 1 ? "is" : "are", bad > SHOWN ? " (the first 5 are shown)" : "");
  return EXIT_INVALID;
}

/* Evaluate one scene: verdicts of its requirements. */
static nav_status evaluate(const nav_scene *sc, bool predict, long runs, int threads, nav_requirement_verdict *out,
                           char *err, size_t err_size) {
  if (predict) {
    const nav_status st = navsim_predict_requirements(sc, out);
    if (st != NAV_OK) snprintf(err, err_size, "covariance prediction: %s", nav_status_str(st));
    return st;
  }
  nav_scene *s = malloc(sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  *s = *sc;
  if (runs > 0) s->simulation.runs = runs;
  nav_sim *sim = NULL;
  nav_req_evaluator *ev = NULL;
  nav_status st = nav_sim_create(s, &sim);
  if (st == NAV_OK) st = nav_req_evaluator_create_for_scene(s, false, &ev);
  if (st == NAV_OK) {
    const nav_run_observer obs = nav_req_evaluator_observer(ev);
    nav_sim_options o = nav_sim_options_default();
    o.threads = threads;
    o.observer = &obs;
    nav_sim_summary sum;
    st = nav_sim_run(sim, &o, &sum);
    if (st == NAV_OK) st = nav_req_evaluator_finish(ev, out);
  }
  if (st != NAV_OK) snprintf(err, err_size, "%s", sim ? nav_sim_last_error(sim) : nav_status_str(st));
  nav_req_evaluator_destroy(ev);
  nav_sim_destroy(sim);
  free(s);
  return st;
}

int navsim_sweep(int argc, char **argv) {
  const char *scene_path = NULL, *out_dir = NULL;
  sweep_param prm[SWEEP_MAX_PARAMS];
  int np = 0;
  long runs = 0, threads = 0;
  bool predict = false, quiet = false, force = false;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (navsim_is_help(a)) {
      fputs(k_usage_sweep, stdout);
      return EXIT_OK;
    } else if (!strcmp(a, "--predict")) {
      predict = true;
    } else if (!strcmp(a, "--quiet") || !strcmp(a, "-q")) {
      quiet = true;
    } else if (!strcmp(a, "--force")) {
      force = true;
    } else if (!strcmp(a, "--param") || !strcmp(a, "--out") || !strcmp(a, "--runs") || !strcmp(a, "--threads")) {
      if (!navsim_need_value("sweep", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (!strcmp(a, "--out")) {
        out_dir = v;
      } else if (!strcmp(a, "--param")) {
        if (np >= SWEEP_MAX_PARAMS) {
          fprintf(stderr, "navsim sweep: at most %d --param\n", SWEEP_MAX_PARAMS);
          return EXIT_INVALID;
        }
        if (!parse_param(v, &prm[np])) {
          fprintf(stderr,
                  "navsim sweep: --param \"%s\": expected PATH=START:STOP:COUNT[:log] (COUNT 1..1000; log needs START "
                  "and STOP > 0; COUNT 1 needs START = STOP)\n",
                  v);
          return EXIT_INVALID;
        }
        ++np;
      } else {
        const long hi = !strcmp(a, "--runs") ? 1000000 : 256;
        long x = 0;
        if (!navsim_parse_long(v, 1, hi, &x)) {
          fprintf(stderr, "navsim sweep: %s: expected an integer in [1, %ld], got \"%s\"\n", a, hi, v);
          return EXIT_INVALID;
        }
        if (!strcmp(a, "--runs")) runs = x;
        else threads = x;
      }
    } else {
      const int rc = navsim_scene_arg("sweep", a, &scene_path);
      if (rc != EXIT_OK) return rc;
    }
  }
  if (!scene_path || !out_dir || np == 0) {
    fprintf(stderr, "navsim sweep: %s\n%s",
            !scene_path ? "missing SCENE" : !out_dir ? "missing --out DIR" : "missing --param", k_usage_sweep);
    return EXIT_INVALID;
  }
  for (int k = 0; k < np; ++k)
    for (int j = 0; j < k; ++j)
      if (paths_overlap(prm[j].path, prm[k].path)) {
        fprintf(stderr,
                "navsim sweep: --param %s and --param %s set the same field: give each field once (several "
                "--param make a grid of different fields)\n",
                prm[j].path, prm[k].path);
        return EXIT_INVALID;
      }
  {
    const int orc = navsim_out_check("sweep", out_dir, force);
    if (orc != EXIT_OK) return orc;
  }
  long total = 1;
  for (int k = 0; k < np; ++k) total *= prm[k].count;
  if (total > SWEEP_MAX_POINTS) {
    fprintf(stderr, "navsim sweep: %ld grid points: at most %d\n", total, SWEEP_MAX_POINTS);
    return EXIT_INVALID;
  }
  if (threads == 0) {
    const long nc = sysconf(_SC_NPROCESSORS_ONLN);
    threads = nc > 0 ? nc : 1;
  }

  int rc = EXIT_FAIL;
  nav_scene_doc *doc = NULL;
  nav_scene *sc = malloc(sizeof *sc);
  nav_requirement_verdict *v = NULL;
  double *x = NULL;
  nav_resultdir *rd = NULL;
  FILE *f = NULL;
  int nreq = 0;
  if (!sc) goto done;
  *sc = nav_scene_default(); /* owns nothing: nav_scene_release below is safe on every path */
  {
    char msg[512];
    const nav_status st = nav_scene_doc_load(scene_path, &doc, msg, sizeof msg);
    if (st != NAV_OK) {
      fprintf(stderr, "%s: error: %s\n", scene_path, msg[0] ? msg : nav_status_str(st));
      rc = st == NAV_ERR_PARSE ? EXIT_INVALID : EXIT_FAIL;
      goto done;
    }
    /* The scene as it is must be valid (its own diagnostics point into the file). */
    rc = navsim_load_scene(scene_path, sc);
    if (rc != EXIT_OK) goto done;
    rc = EXIT_FAIL;
    nreq = sc->n_requirements;
    if (nreq == 0) {
      fprintf(stderr, "%s: error: requirements: the scene has no requirements to sweep against\n", scene_path);
      rc = EXIT_INVALID;
      goto done;
    }
    rc = validate_grid(doc, prm, np, total, sc);
    if (rc != EXIT_OK) goto done;
    rc = EXIT_FAIL;
    /* A --param may change the requirements (their count is the file's above). */
    if (sc->n_requirements != nreq) {
      fprintf(stderr, "navsim sweep: the --param values change the number of requirements\n");
      rc = EXIT_INVALID;
      goto done;
    }
  }
  v = calloc((size_t)total * (size_t)nreq, sizeof *v);
  x = calloc((size_t)total * (size_t)np, sizeof *x);
  if (!v || !x) goto done;
  /* The result directory is started before any grid point is computed, so that an --out that
     cannot be written is reported before the work, not after it. */
  rc = navsim_out_begin("sweep", out_dir, force, &rd);
  if (rc != EXIT_OK) goto done;
  rc = EXIT_FAIL;
  const double t0 = navsim_now_s();
  for (long g = 0; g < total; ++g) {
    long rem = g;
    char context[1024] = "(with";
    for (int k = np - 1; k >= 0; --k) {
      const int i = (int)(rem % prm[k].count);
      rem /= prm[k].count;
      x[g * np + k] = param_value(&prm[k], i);
    }
    for (int k = 0; k < np; ++k) {
      char val[64], msg[512];
      snprintf(val, sizeof val, "%.17g", x[g * np + k]);
      const size_t len = strlen(context);
      if (len + strlen(prm[k].path) + strlen(val) + 12 < sizeof context) {
        context[len] = '\0';
        strcat(context, " --param ");
        strcat(context, prm[k].path);
        strcat(context, "=");
        strcat(context, val);
      }
      if (nav_scene_doc_set(doc, prm[k].path, val, msg, sizeof msg) != NAV_OK) {
        fprintf(stderr, "navsim sweep: --param %s: %s\n", prm[k].path, msg);
        rc = EXIT_INVALID;
        goto done;
      }
    }
    strncat(context, ")", sizeof context - strlen(context) - 1);
    navsim_diag_sink sink = {0, context};
    nav_scene_release(sc); /* the previous point's recorded model, if any */
    const nav_status st = nav_scene_doc_read(doc, sc, navsim_print_diag, &sink);
    if (st != NAV_OK) {
      if (sink.count == 0) fprintf(stderr, "%s: error: %s %s\n", scene_path, nav_status_str(st), context);
      rc = st == NAV_ERR_PARSE ? EXIT_INVALID : EXIT_FAIL;
      goto done;
    }
    char err[512] = "";
    const nav_status se = evaluate(sc, predict, runs, (int)threads, &v[g * nreq], err, sizeof err);
    if (se != NAV_OK) {
      fprintf(stderr, "navsim sweep: %s %s: %s\n", scene_path, context, err);
      goto done;
    }
    if (!quiet) {
      printf("point %4ld/%ld ", g + 1, total);
      for (int k = 0; k < np; ++k) printf(" %s=%.6g", prm[k].path, x[g * np + k]);
      for (int r = 0; r < nreq; ++r) {
        const nav_requirement_verdict *w = &v[g * nreq + r];
        printf("  %s %.4g %s %s", w->id, w->value, nav_req_unit_name(w->unit), w->pass ? "pass" : "FAIL");
      }
      printf("\n");
      fflush(stdout);
    }
  }
  const double wall = navsim_now_s() - t0;

  {
    const char *p = nav_resultdir_file(rd, "sweep.csv");
    f = p ? fopen(p, "w") : NULL;
    if (!f) goto io_fail;
    for (int k = 0; k < np; ++k) fprintf(f, "%s%s", k ? "," : "", prm[k].path);
    for (int r = 0; r < nreq; ++r)
      fprintf(f, ",%s_value_%s,%s_pass", sc->requirements[r].id, nav_req_unit_name(sc->requirements[r].unit),
              sc->requirements[r].id);
    fputs(",all_pass\n", f);
    for (long g = 0; g < total; ++g) {
      for (int k = 0; k < np; ++k) fprintf(f, "%s%.17g", k ? "," : "", x[g * np + k]);
      for (int r = 0; r < nreq; ++r) {
        const nav_requirement_verdict *w = &v[g * nreq + r];
        if (w->evaluated && isfinite(w->value)) fprintf(f, ",%.9g", w->value);
        else fputs(",", f);
        fprintf(f, ",%s", w->pass ? "true" : "false");
      }
      fprintf(f, ",%s\n", nav_req_all_pass(&v[g * nreq], nreq) ? "true" : "false");
    }
    const bool bad = ferror(f) != 0;
    const int cl = fclose(f);
    f = NULL;
    if (bad || cl != 0) goto io_fail;
  }
  /* Thresholds when exactly one parameter varies (the others may be fixed with COUNT 1). */
  int sw = -1, nvary = 0;
  for (int k = 0; k < np; ++k)
    if (prm[k].count > 1) {
      sw = k;
      ++nvary;
    }
  if (np == 1) sw = 0;
  if (nvary <= 1 && sw >= 0) {
    const char *p = nav_resultdir_file(rd, "thresholds.csv");
    f = p ? fopen(p, "w") : NULL;
    if (!f) goto io_fail;
    fprintf(f, "requirement,limit,unit,parameter,largest_passing_value,status,bracket_low,bracket_high\n");
    /* Grid indices by increasing parameter value. */
    const int n = prm[sw].count;
    const bool rev = prm[sw].stop < prm[sw].start;
    if (!quiet) printf("largest %s that still meets each requirement:\n", prm[sw].path);
    for (int r = 0; r < nreq; ++r) {
      /* j runs over the grid by increasing parameter value; g(j) is the grid index. */
#define G(j) (rev ? n - 1 - (j) : (j))
      int first_fail = -1;
      bool any_pass = false, pass_after_fail = false;
      for (int j = 0; j < n; ++j) {
        const bool ok = v[G(j) * nreq + r].pass;
        any_pass |= ok;
        if (!ok && first_fail < 0) first_fail = j;
        if (ok && first_fail >= 0) pass_after_fail = true;
      }
      const nav_requirement *q = &sc->requirements[r];
      const char *status;
      double thr = NAN, lo = NAN, hi = NAN;
      if (first_fail < 0) {
        status = "all_pass";
        thr = lo = x[G(n - 1) * np + sw];
      } else if (first_fail == 0) {
        status = any_pass ? "non_monotonic" : "none_pass";
        hi = x[G(0) * np + sw];
      } else {
        const int ga = G(first_fail - 1), gb = G(first_fail);
#undef G
        const double xa = x[ga * np + sw], xb = x[gb * np + sw];
        const double va = v[ga * nreq + r].value, vb = v[gb * nreq + r].value, L = v[ga * nreq + r].limit;
        lo = xa;
        hi = xb;
        double u = (isfinite(va) && isfinite(vb) && vb != va) ? (L - va) / (vb - va) : 0.5;
        if (u < 0) u = 0;
        if (u > 1) u = 1;
        thr = prm[sw].log ? exp(log(xa) + u * (log(xb) - log(xa))) : xa + u * (xb - xa);
        status = pass_after_fail ? "non_monotonic" : "interpolated";
      }
      fprintf(f, "%s,%.9g,%s,%s,", q->id, q->limit, nav_req_unit_name(q->unit), prm[sw].path);
      if (isfinite(thr)) fprintf(f, "%.9g", thr);
      fprintf(f, ",%s,", status);
      if (isfinite(lo)) fprintf(f, "%.9g", lo);
      fputc(',', f);
      if (isfinite(hi)) fprintf(f, "%.9g", hi);
      fputc('\n', f);
      if (!quiet) {
        if (!strcmp(status, "all_pass"))
          printf("  %-20s >= %.6g (every grid value passes)\n", q->id, thr);
        else if (!isfinite(thr))
          printf("  %-20s none: the smallest grid value already fails (%s)\n", q->id, status);
        else
          printf("  %-20s %.6g (%s between %.6g and %.6g)\n", q->id, thr, status, lo, hi);
      }
    }
    const bool bad = ferror(f) != 0;
    const int cl = fclose(f);
    f = NULL;
    if (bad || cl != 0) goto io_fail;
  }
  rc = navsim_out_commit("sweep", rd);
  if (rc != EXIT_OK) {
    rd = NULL;
    goto done;
  }
  rd = NULL;
  if (!quiet)
    printf("sweep      %ld point%s by %s in %.1f s -> %s/sweep.csv%s\n", total, total == 1 ? "" : "s",
           predict ? "covariance prediction" : "Monte Carlo", wall, out_dir,
           (nvary <= 1 && sw >= 0) ? ", thresholds.csv" : "");
  rc = EXIT_OK;
  goto done;
io_fail:
  fprintf(stderr, "navsim sweep: writing the results into \"%s\" failed\n", out_dir);
  rc = EXIT_FAIL;
done:
  if (f) fclose(f);
  nav_resultdir_abort(rd);
  nav_scene_doc_destroy(doc);
  if (sc) nav_scene_release(sc);
  free(sc);
  free(v);
  free(x);
  return rc;
}
