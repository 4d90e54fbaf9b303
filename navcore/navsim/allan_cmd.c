/*
 * navsim allan: verify an IMU error model against its datasheet through the Allan deviation
 * (issue 4 item 4; numerics.md 2.2-2.5, IEEE Std 952-1997 and 1293-1998 Annex C).
 *
 * A static IMU (level, heading north, at 45 deg latitude: w_ib_b = earth rate, f_ib_b = -g0 on z)
 * is simulated through the real error model (nav_imu_model_apply(), every configured term on),
 * the six rate outputs (increment / dt) are kept, and their overlapping Allan deviations are
 * computed at log-spaced cluster times (nav_allan_overlapping()). The constant input only sets
 * the operating point: the estimator removes the mean, and constant terms (turn-on bias, scale
 * factor and misalignment on a constant input) have no Allan deviation.
 *
 * Read-outs per channel:
 * - white noise N (ARW for gyros, VRW for accelerometers): the line of slope -1/2 read at
 *   tau = 1 s (IEEE 952 Annex C), drawn through the curve point (tau <= 10 s) whose local slope
 *   is closest to -1/2, i.e. where the white noise dominates most: N = sigma_A(tau*) sqrt(tau*).
 *   Reading the curve itself at 1 s is not enough: a bias term may already lift it there (a GM
 *   bias acts as a random walk sqrt(2/(3T)) sigma at tau << T; the HG1700 row's accelerometer
 *   curve is 18 % above its VRW at 1 s); that value is kept in summary.json as well.
 *   Check: |N / N_spec - 1| <= max(5 %, 3 u), u = 1 / sqrt(2 (L/m - 1)) the relative 1-sigma of
 *   the estimate at tau* (numerics.md 2.5); with the default 2 h, u <= 0.83 % for tau* <= 1 s.
 * - the local slope between tau = 0.1 s and 10 s (-1/2 for white noise);
 * - the bias instability in the datasheet floor convention (ADI, Safran Sensonor, Honeywell: the
 *   minimum of the Allan curve; IEEE's flicker coefficient is B / 0.6643): the minimum of the
 *   measured curve and its tau, and the curve read at tau_B, where the datasheet B belongs: the
 *   GM peak 1.8926 T (the allan_peak mapping puts the model's peak 0.61736 sigma = B there), else
 *   the minimum of the model's theoretical curve (white + E2.6 GM + K sqrt(tau/3) random walk +
 *   S/(2 tau) busy-signal quantisation). Both are shown next to the model's value there and the
 *   datasheet B (catalog rows given as an Allan floor). A single GM plus white noise has no flat
 *   floor, and where the white noise is still large at tau_B (BMI088, STIM300 gyros) the curve
 *   there exceeds B: the comparison is reported, not checked.
 */
#define _POSIX_C_SOURCE 200809L
#include "allan_cmd.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "catalog_cmd.h"
#include "cli_util.h"
#include "navcore/nav_catalog.h"
#include "navcore/nav_io.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_version.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2, EXIT_CHECK_FAILED = 3 };
enum { N_CH = 6 };

#define DEFAULT_RATE_HZ 100.0
#define DEFAULT_DURATION_S 7200.0
/* Samples per channel: six series of doubles plus the work array stay under ~600 MB. */
#define MAX_SAMPLES 10000000.0
/* ARW / VRW tolerance of the Done-when of issue 4. */
#define TOL_REL 0.05
/* Longest tau at which the -1/2 line may be anchored [s]. */
#define LINE_TAU_MAX_S 10.0
/* Latitude of the static input (earth-rate components only; any value would do). */
#define STATIC_LAT_RAD (NAV_PI / 4.0)

static const char *k_usage_allan =
    "usage: navsim allan (--imu NAME | SCENE) [--rate HZ] [--duration S] [--seed N] [--out DIR]\n"
    "                    [--force] [--convention allan_peak|sigma_equals_b] [--strict] [--quiet]\n"
    "\n"
    "Simulate a static IMU with the error model of a catalog part (--imu NAME, see `navsim catalog`)\n"
    "or of a scene's imu section, compute the overlapping Allan deviation of the three gyro and\n"
    "three accelerometer rate outputs, and compare with the specification:\n"
    "  ARW / VRW    the line of slope -1/2 read at tau = 1 s (IEEE 952), through the curve point\n"
    "               (tau <= 10 s) whose local slope is closest to -1/2; checked: within max(5 %, 3 x\n"
    "               the estimator's 1-sigma 1/sqrt(2 (T/tau - 1)) there) of the spec\n"
    "  slope        log-log slope of the curve between tau = 0.1 s and 10 s (-0.5 for white noise)\n"
    "  bias inst.   datasheet floor convention (IEEE's flicker coefficient is B / 0.6643): the\n"
    "               minimum of the curve and its tau, and the curve at tau_B = 1.89 T of the\n"
    "               Gauss-Markov bias (where a datasheet B is placed; else the model's minimum),\n"
    "               next to the model's value there and the datasheet B; reported, not checked\n"
    "Writes DIR/allan.csv (tau_s, adev per channel, the estimator's relative 1-sigma, the model's\n"
    "theoretical curve per channel) and DIR/summary.json, and prints a table.\n"
    "\n"
    "options:\n"
    "  --imu NAME        catalog part (resources/imu_catalog.csv; case-insensitive)\n"
    "  SCENE             a scene file: its imu model, rate and seed\n"
    "  --rate HZ         IMU rate (default: 100 Hz, or the scene's imu.rate_hz); alias --rate-hz\n"
    "  --duration S      simulated time (default 7200 s = 2 h: 0.83 % uncertainty at tau = 1 s,\n"
    "                    Allan curve up to 720 s); at most 1e7 samples; alias --duration-s\n"
    "  --seed N          random seed (default 1, or the scene's simulation.seed)\n"
    "  --out DIR         result directory (default out/allan-<part or scene name>)\n"
    "  --convention C    catalog parts: bias instability B -> Gauss-Markov sigma (allan_peak,\n"
    "                    the default: sigma = B / 0.61736; or sigma_equals_b)\n"
    "  --strict          exit 3 when an ARW/VRW check fails\n"
    "  --quiet           print nothing but errors\n"
    "  -h, --help        print this help\n"
    NAVSIM_OUT_HELP
    "\n"
    "exit codes: 0 success (failed checks are reported; with --strict they exit 3); 1 I/O or\n"
    "numerical failure, catalog not found; 2 invalid scene, part name or options; 3 see --strict\n";

/* Back to datasheet units, display only (inverse factors of nav_sensors.h). */
#define RPS_TO_DPH (1.0 / nav_unit_deg_per_h_to_rps(1.0))
#define ARW_TO_DEG_PER_SQRT_H (1.0 / nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(1.0))
#define VRW_TO_MPS_PER_SQRT_H 60.0
#define MPS2_TO_UG (1.0 / nav_unit_ug_to_mps2(1.0))

static const char *const k_ch_name[N_CH] = {"gx", "gy", "gz", "ax", "ay", "az"};

/* The error terms of one channel that have an Allan signature (SI). */
typedef struct chan_model {
  bool noise_on;
  double n; /* N: ARW [rad/sqrt(s)] or VRW [m/s/sqrt(s)] */
  bool gm_on;
  double gm_sd, gm_tau_s; /* GM sigma [rad/s | m/s^2], T [s] */
  bool rw_on;
  double k; /* random walk K [rad/s/sqrt(s) | m/s^2/sqrt(s)] */
  bool q_on;
  double q_step; /* increment quantum [rad | m/s] */
  bool b_known;  /* a datasheet Allan floor B is known (catalog allan_min row) */
  double b;      /* that B [rad/s | m/s^2] */
} chan_model;

/* Results of one channel. */
typedef struct chan_result {
  double n_meas;     /* white-noise coefficient: the -1/2 line read at tau = 1 s */
  double line_tau_s; /* the curve point the -1/2 line goes through */
  double line_rel;   /* relative 1-sigma of the estimate there */
  double line_slope; /* local slope of the curve there */
  double n_1s;       /* the curve itself at tau ~ 1 s, x sqrt(tau) */
  double ratio;      /* n_meas / n_spec (NaN without spec) */
  double tol;        /* relative tolerance used */
  bool checked, pass;
  double slope;               /* log-log slope between ~0.1 s and ~10 s (NaN if not available) */
  double min_adev, min_tau_s; /* minimum of the measured curve (taus up to L/10) */
  const char
      *min_where;     /* "inside", "longest_tau" (still falling) or "shortest_tau" (rising from the start) */
  double b_tau_s;     /* where the bias instability is read (NaN: nowhere), see b_rule */
  const char *b_rule; /* "gm_peak" (1.8926 T), "model_minimum", or "none" */
  double b_model;     /* the model's Allan deviation at b_tau_s */
  double b_meas;      /* the measured one at the cluster nearest b_tau_s (NaN beyond L/10) */
  double b_meas_tau_s, b_meas_rel;
  double gm_peak; /* 0.61736 sigma of the GM term (NaN when off) */
} chan_result;

/* A JSON number, or null for NaN / inf. */
static void json_num(FILE *f, double v) { navsim_json_number(f, v, 10); }

/*
 * Allan variance of a first-order GM rate process (numerics.md E2.6, IEEE 952 Annex C):
 *   sigma_A^2 = (q T^2 / tau) [1 - (T / (2 tau)) (3 - 4 e^{-x} + e^{-2x})],  x = tau / T, q = 2 sigma^2 / T.
 * The bracket cancels for x -> 0; below x = 1e-3 its series x^2/3 - x^3/4 + 7 x^4/60 (truncation
 * ~x^5, relative 1e-9) is used instead.
 */
static double gm_avar(double sd, double tau_gm_s, double tau_s) {
  const double q = 2.0 * sd * sd / tau_gm_s, x = tau_s / tau_gm_s;
  const double br = x < 1e-3 ? x * x * (1.0 / 3.0 - x * (0.25 - x * 7.0 / 60.0))
                             : 1.0 - (3.0 - 4.0 * exp(-x) + exp(-2.0 * x)) / (2.0 * x);
  return q * tau_gm_s * tau_gm_s / tau_s * br;
}

/* The model's theoretical Allan deviation: white N^2/tau (E2.2), GM (E2.6), random walk
 * K^2 tau/3 (E2.7), quantisation (S/(2 tau))^2 (E2.8, busy signal). Independent terms add. */
static double model_adev(const chan_model *c, double tau_s) {
  double v = 0.0;
  if (c->noise_on) v += c->n * c->n / tau_s;
  if (c->gm_on && c->gm_sd > 0.0) v += gm_avar(c->gm_sd, c->gm_tau_s, tau_s);
  if (c->rw_on) v += c->k * c->k * tau_s / 3.0;
  if (c->q_on) v += c->q_step * c->q_step / (4.0 * tau_s * tau_s);
  return sqrt(v);
}

static void channel_models(const nav_imu_model_config *cfg, chan_model ch[N_CH]) {
  const nav_gyro_error_config *g = &cfg->gyro;
  const nav_accel_error_config *a = &cfg->accel;
  for (int i = 0; i < 3; ++i) {
    chan_model *c = &ch[i];
    memset(c, 0, sizeof *c);
    c->noise_on = (g->terms & NAV_IMU_TERM_NOISE) != 0;
    c->n = nav_vec3_get(g->arw_rad_per_sqrt_s, i);
    c->gm_on = (g->terms & NAV_IMU_TERM_BIAS_GM) != 0;
    c->gm_sd = nav_vec3_get(g->bias_gm_sd_rps, i);
    c->gm_tau_s = nav_vec3_get(g->bias_gm_tau_s, i);
    c->rw_on = (g->terms & NAV_IMU_TERM_BIAS_RW) != 0;
    c->k = nav_vec3_get(g->bias_rw_rps_per_sqrt_s, i);
    c->q_on = (g->terms & NAV_IMU_TERM_QUANTISATION) != 0;
    c->q_step = nav_vec3_get(g->quant_step_rad, i);
    c = &ch[3 + i];
    memset(c, 0, sizeof *c);
    c->noise_on = (a->terms & NAV_IMU_TERM_NOISE) != 0;
    c->n = nav_vec3_get(a->vrw_mps_per_sqrt_s, i);
    c->gm_on = (a->terms & NAV_IMU_TERM_BIAS_GM) != 0;
    c->gm_sd = nav_vec3_get(a->bias_gm_sd_mps2, i);
    c->gm_tau_s = nav_vec3_get(a->bias_gm_tau_s, i);
    c->rw_on = (a->terms & NAV_IMU_TERM_BIAS_RW) != 0;
    c->k = nav_vec3_get(a->bias_rw_mps2_per_sqrt_s, i);
    c->q_on = (a->terms & NAV_IMU_TERM_QUANTISATION) != 0;
    c->q_step = nav_vec3_get(a->quant_step_mps, i);
  }
}

/* Display factors: white-noise coefficient and bias to datasheet units. */
static double n_disp(int ch) {
  return ch < 3 ? ARW_TO_DEG_PER_SQRT_H : VRW_TO_MPS_PER_SQRT_H;
}
static double b_disp(int ch) {
  return ch < 3 ? RPS_TO_DPH : MPS2_TO_UG;
}

/* Where the options put us. */
typedef struct allan_args {
  const char *imu_name, *scene_path, *out_dir;
  double rate_hz, duration_s;
  bool have_rate, have_duration, have_seed, strict, quiet, force;
  uint64_t seed;
  nav_bi_convention convention;
} allan_args;

/* Parse the command line. @return -1 to go on, else the exit code. */
static int parse_args(int argc, char **argv, allan_args *a) {
  for (int i = 0; i < argc; ++i) {
    const char *s = argv[i];
    if (navsim_is_help(s)) {
      fputs(k_usage_allan, stdout);
      return EXIT_OK;
    } else if (strcmp(s, "--strict") == 0) {
      a->strict = true;
    } else if (strcmp(s, "--force") == 0) {
      a->force = true;
    } else if (strcmp(s, "--quiet") == 0 || strcmp(s, "-q") == 0) {
      a->quiet = true;
    } else if (strcmp(s, "--imu") == 0 || strcmp(s, "--out") == 0 || strcmp(s, "--rate") == 0 ||
               strcmp(s, "--rate-hz") == 0 || strcmp(s, "--duration") == 0 ||
               strcmp(s, "--duration-s") == 0 || strcmp(s, "--seed") == 0 || strcmp(s, "--convention") == 0) {
      if (!navsim_need_value("allan", argc, i, s)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (strcmp(s, "--imu") == 0) {
        a->imu_name = v;
      } else if (strcmp(s, "--out") == 0) {
        a->out_dir = v;
      } else if (strncmp(s, "--rate", 6) == 0) {
        if (!navsim_parse_positive(v, &a->rate_hz, false) || a->rate_hz < 1.0 || a->rate_hz > 1e5) {
          fprintf(stderr, "navsim allan: %s: expected a rate in [1, 100000] Hz, got \"%s\"\n", s, v);
          return EXIT_INVALID;
        }
        a->have_rate = true;
      } else if (strncmp(s, "--duration", 10) == 0) {
        if (!navsim_parse_positive(v, &a->duration_s, false)) {
          fprintf(stderr, "navsim allan: %s: expected a duration > 0 s, got \"%s\"\n", s, v);
          return EXIT_INVALID;
        }
        a->have_duration = true;
      } else if (strcmp(s, "--seed") == 0) {
        if (!navsim_parse_u64(v, &a->seed)) {
          fprintf(stderr, "navsim allan: --seed: expected an integer in [0, 2^64-1], got \"%s\"\n", v);
          return EXIT_INVALID;
        }
        a->have_seed = true;
      } else if (strcmp(v, "allan_peak") == 0) {
        a->convention = NAV_BI_ALLAN_PEAK;
      } else if (strcmp(v, "sigma_equals_b") == 0) {
        a->convention = NAV_BI_SIGMA_EQUALS_B;
      } else {
        fprintf(stderr, "navsim allan: --convention: '%s' is neither allan_peak nor sigma_equals_b\n", v);
        return EXIT_INVALID;
      }
    } else {
      const int rc = navsim_scene_arg("allan", s, &a->scene_path);
      if (rc != EXIT_OK) return rc;
    }
  }
  if ((a->imu_name != NULL) == (a->scene_path != NULL)) {
    fprintf(stderr, "navsim allan: give either --imu NAME or a SCENE\n%s", k_usage_allan);
    return EXIT_INVALID;
  }
  return -1;
}

/* What is being verified. */
typedef struct allan_source {
  char name[NAV_SCENE_NAME_MAX + NAV_SCENE_CATALOG_NAME_MAX]; /* a part or scene name */
  const char *kind;                                           /* "catalog" or "scene" */
  char verified[NAV_CATALOG_VERIFIED_MAX];
  const char *bias_model; /* catalog bias_model, or NULL */
  nav_imu_model_config cfg;
} allan_source;

static int load_catalog_part(const allan_args *a, allan_source *src, chan_model ch[N_CH]) {
  char dir[4096];
  if (!navsim_find_resources_dir(dir, sizeof dir)) {
    fprintf(stderr,
            "navsim allan: cannot find the resources directory; set NAV_RESOURCES_DIR to the directory "
            "holding imu_catalog.csv\n");
    return EXIT_FAIL;
  }
  char path[4200];
  snprintf(path, sizeof path, "%s/imu_catalog.csv", dir);
  nav_catalog_options opt = nav_catalog_options_default();
  opt.convention = a->convention;
  nav_catalog *cat = NULL;
  navsim_diag_sink nd = {0};
  const nav_status st = nav_catalog_load(path, &opt, &cat, navsim_print_diag, &nd);
  if (st != NAV_OK) {
    if (nd.count == 0) fprintf(stderr, "%s: error: %s\n", path, nav_status_str(st));
    return st == NAV_ERR_PARSE ? EXIT_INVALID : EXIT_FAIL;
  }
  const nav_catalog_imu_entry *e = nav_catalog_find_imu(cat, a->imu_name);
  if (!e) {
    fprintf(stderr, "navsim allan: unknown IMU \"%s\"; `navsim catalog --imu` lists the %zu parts of %s\n",
            a->imu_name, nav_catalog_count(cat), path);
    nav_catalog_destroy(cat);
    return EXIT_INVALID;
  }
  snprintf(src->name, sizeof src->name, "%s", e->name);
  src->kind = "catalog";
  snprintf(src->verified, sizeof src->verified, "%s", nav_catalog_verification_name(e->verified));
  src->bias_model = nav_catalog_bias_model_name(e->bias_model);
  src->cfg = e->config;
  channel_models(&src->cfg, ch);
  /* An allan_min row states the Allan floor B; the catalog turned it into the GM sigma under
   * the convention, which is inverted here (exact up to one rounding). */
  if (e->bias_model == NAV_CATALOG_BIAS_ALLAN_MIN)
    for (int c = 0; c < N_CH; ++c)
      if (ch[c].gm_on) {
        ch[c].b_known = true;
        ch[c].b = ch[c].gm_sd * (a->convention == NAV_BI_ALLAN_PEAK ? NAV_GM_ALLAN_PEAK_SIGMA_RATIO : 1.0);
      }
  nav_catalog_destroy(cat);
  return EXIT_OK;
}

static int write_csv(const char *path, const double *tau, size_t n_m, const double *adev, const double *rel,
                     const chan_model ch[N_CH]) {
  FILE *f = path ? fopen(path, "w") : NULL;
  if (!f) return EXIT_FAIL;
  fputs("tau_s,adev_gx_rad_per_s,adev_gy_rad_per_s,adev_gz_rad_per_s,adev_ax_mps2,adev_ay_mps2,adev_az_mps2,"
        "adev_rel_sd,model_adev_gx_rad_per_s,model_adev_gy_rad_per_s,model_adev_gz_rad_per_s,model_adev_ax_"
        "mps2,"
        "model_adev_ay_mps2,model_adev_az_mps2\n",
        f);
  for (size_t k = 0; k < n_m; ++k) {
    fprintf(f, "%.10g", tau[k]);
    for (int c = 0; c < N_CH; ++c)
      fprintf(f, ",%.10g", adev[(size_t)c * n_m + k]);
    fprintf(f, ",%.6g", rel[k]);
    for (int c = 0; c < N_CH; ++c)
      fprintf(f, ",%.10g", model_adev(&ch[c], tau[k]));
    fputc('\n', f);
  }
  const bool bad = ferror(f) != 0;
  return (fclose(f) != 0 || bad) ? EXIT_FAIL : EXIT_OK;
}

static int write_json(const char *path, const allan_args *a, const allan_source *src, int64_t n,
                      double tau1_s, const chan_model ch[N_CH], const chan_result res[N_CH], int n_checked,
                      int n_pass, double wall_s) {
  FILE *f = path ? fopen(path, "w") : NULL;
  if (!f) return EXIT_FAIL;
  fprintf(f, "{\n  \"navsim_version\": \"%s\",\n  \"source\": {\"kind\": \"%s\", \"name\": ",
          nav_version_string(), src->kind);
  nav_json_write_string(f, src->name);
  if (a->scene_path) {
    fputs(", \"file\": ", f);
    nav_json_write_string(f, a->scene_path);
  }
  if (src->bias_model)
    fprintf(f, ", \"bias_model\": \"%s\", \"verified\": \"%s\"", src->bias_model, src->verified);
  fputs("},\n", f);
  fprintf(f, "  \"rate_hz\": %.10g,\n  \"duration_s\": %.10g,\n  \"samples\": %lld,\n  \"seed\": %llu,\n",
          a->rate_hz, (double)n / a->rate_hz, (long long)n, (unsigned long long)a->seed);
  fprintf(f, "  \"wall_s\": %.4g,\n", wall_s);
  fputs("  \"input\": \"static: level, heading north, latitude 45 deg; w_ib_b = earth rate, f_ib_b = (0, 0, "
        "-g0)\",\n",
        f);
  fprintf(
      f,
      "  \"method\": {\"estimator\": \"overlapping Allan deviation (numerics.md 2.5)\",\n"
      "             \"white_noise\": \"line of slope -1/2 through the curve point (tau <= %g s) whose local "
      "slope is closest to -1/2, read at tau = 1 s (IEEE 952 Annex C)\",\n"
      "             \"tolerance\": \"max(%g, 3 x the relative 1-sigma of the estimate at that point)\",\n"
      "             \"bias_instability\": \"minimum of the Allan deviation (datasheet floor convention; IEEE "
      "flicker B_IEEE = B / 0.6643)\"",
      LINE_TAU_MAX_S, TOL_REL);
  if (src->bias_model) fprintf(f, ", \"catalog_convention\": \"%s\"", nav_bi_convention_name(a->convention));
  fputs("},\n  \"channels\": [\n", f);
  for (int c = 0; c < N_CH; ++c) {
    const chan_model *m = &ch[c];
    const chan_result *r = &res[c];
    const bool gyro = c < 3;
    fprintf(f,
            "    {\"channel\": \"%s\", \"quantity\": \"%s\", \"unit\": \"%s\", \"measured\": ", k_ch_name[c],
            gyro ? "ARW" : "VRW", gyro ? "rad/sqrt(s)" : "m/s/sqrt(s)");
    json_num(f, r->n_meas);
    fputs(", \"datasheet\": ", f);
    json_num(f, m->noise_on ? m->n : NAN);
    fputs(", \"ratio\": ", f);
    json_num(f, r->ratio);
    fputs(", \"read_at_tau_s\": ", f);
    json_num(f, r->line_tau_s);
    fputs(", \"local_slope\": ", f);
    json_num(f, r->line_slope);
    fprintf(f, ", \"rel_uncertainty\": %.6g, \"tolerance_rel\": %.6g, \"checked\": %s, \"pass\": %s,\n",
            r->line_rel, r->tol, r->checked ? "true" : "false",
            r->checked ? (r->pass ? "true" : "false") : "null");
    fprintf(f, "     \"curve_at_%g_s_x_sqrt_tau\": ", tau1_s);
    json_num(f, r->n_1s);
    fputs(", ", f);
    fprintf(f, "\"%s\": {\"measured\": ", gyro ? "arw_deg_per_sqrt_h" : "vrw_m_per_s_per_sqrt_h");
    json_num(f, r->n_meas * n_disp(c));
    fputs(", \"datasheet\": ", f);
    json_num(f, m->noise_on ? m->n * n_disp(c) : NAN);
    fputs("}, \"slope_0p1_to_10_s\": ", f);
    json_num(f, r->slope);
    fprintf(f,
            ",\n     \"bias_instability\": {\"unit\": \"%s\", \"measured_min\": ", gyro ? "rad/s" : "m/s^2");
    json_num(f, r->min_adev);
    fputs(", \"min_tau_s\": ", f);
    json_num(f, r->min_tau_s);
    fprintf(f, ", \"minimum_at\": \"%s\",\n       \"tau_b_rule\": \"%s\", \"tau_b_s\": ", r->min_where,
            r->b_rule);
    json_num(f, r->b_tau_s);
    fputs(", \"model_at_tau_b\": ", f);
    json_num(f, r->b_model);
    fputs(", \"measured_at_tau_b\": ", f);
    json_num(f, r->b_meas);
    fputs(", \"measured_at_tau_b_tau_s\": ", f);
    json_num(f, r->b_meas_tau_s);
    fputs(", \"measured_at_tau_b_rel_sd\": ", f);
    json_num(f, r->b_meas_rel);
    fputs(",\n       \"gm_allan_peak\": ", f);
    json_num(f, r->gm_peak);
    fputs(", \"datasheet\": ", f);
    json_num(f, m->b_known ? m->b : NAN);
    fputs(", \"ratio_measured_at_tau_b_to_datasheet\": ", f);
    json_num(f, m->b_known ? r->b_meas / m->b : NAN);
    fprintf(f, ", \"measured_min_%s\": ", gyro ? "deg_per_h" : "ug");
    json_num(f, r->min_adev * b_disp(c));
    fprintf(f, ", \"measured_at_tau_b_%s\": ", gyro ? "deg_per_h" : "ug");
    json_num(f, r->b_meas * b_disp(c));
    fprintf(f, ", \"datasheet_%s\": ", gyro ? "deg_per_h" : "ug");
    json_num(f, m->b_known ? m->b * b_disp(c) : NAN);
    fprintf(f, "}}%s\n", c + 1 < N_CH ? "," : "");
  }
  fprintf(f, "  ],\n  \"checks\": %d,\n  \"passed\": %d,\n  \"pass\": %s\n}\n", n_checked, n_pass,
          n_pass == n_checked ? "true" : "false");
  const bool bad = ferror(f) != 0;
  return (fclose(f) != 0 || bad) ? EXIT_FAIL : EXIT_OK;
}

/* A table cell, "-" for NaN. */
static void cell(double v, int width) {
  if (isfinite(v))
    printf(" %*.4g", width, v);
  else
    printf(" %*s", width, "-");
}

static void print_table(const allan_args *a, const allan_source *src, int64_t n, double tau_longest,
                        const chan_model ch[N_CH], const chan_result res[N_CH], int n_checked, int n_pass,
                        const char *out_dir) {
  printf("part       %s (%s%s%s%s%s)\n", src->name, src->kind, src->bias_model ? ", bias model " : "",
         src->bias_model ? src->bias_model : "", src->bias_model ? ", verified: " : "",
         src->bias_model ? src->verified : "");
  printf("simulated  static IMU, %g Hz x %g s = %lld samples per channel, seed %llu\n", a->rate_hz,
         (double)n / a->rate_hz, (long long)n, (unsigned long long)a->seed);
  printf(
      "white      N = the line of slope -1/2 read at tau = 1 s (IEEE 952), through the curve point\n"
      "           (\"at tau\", <= %g s) whose local slope is closest to -1/2; tolerance max(%g %%, 3 x the\n"
      "           estimator's 1-sigma there)\n",
      LINE_TAU_MAX_S, 100.0 * TOL_REL);
  printf(
      "bias inst. datasheet floor convention (minimum of the Allan curve)%s%s;\n"
      "           a single Gauss-Markov bias is flat only at its peak (0.617 sigma at tau_B = 1.89 T): read\n"
      "           there too\n\n",
      src->bias_model ? "; catalog B -> GM sigma: " : "",
      src->bias_model ? nav_bi_convention_name(a->convention) : "");
  printf("%-4s %-3s %-8s %10s %10s %7s %6s %6s  %-5s | %-5s %9s %8s %9s %9s %9s %9s\n", "chan", "", "unit",
         "measured", "spec", "ratio", "at tau", "slope", "check", "unit", "Allan min", "at tau s", "tau_B s",
         "measured", "model", "datasheet");
  for (int c = 0; c < N_CH; ++c) {
    const chan_model *m = &ch[c];
    const chan_result *r = &res[c];
    const bool gyro = c < 3;
    printf("%-4s %-3s %-8s %10.4g", k_ch_name[c], gyro ? "ARW" : "VRW", gyro ? "deg/rt-h" : "m/s/rt-h",
           r->n_meas * n_disp(c));
    cell(m->noise_on ? m->n * n_disp(c) : NAN, 10);
    if (isfinite(r->ratio))
      printf(" %7.4f", r->ratio);
    else
      printf(" %7s", "-");
    printf(" %6.3g", r->line_tau_s);
    if (isfinite(r->slope))
      printf(" %6.3f", r->slope);
    else
      printf(" %6s", "-");
    const char *flag = strcmp(r->min_where, "longest_tau") == 0    ? "+"
                       : strcmp(r->min_where, "shortest_tau") == 0 ? "<"
                                                                   : " ";
    printf("  %-5s | %-5s %9.4g %7.4g%s", r->checked ? (r->pass ? "pass" : "FAIL") : "-",
           gyro ? "deg/h" : "ug", r->min_adev * b_disp(c), r->min_tau_s, flag);
    cell(r->b_tau_s, 8);
    cell(r->b_meas * b_disp(c), 9);
    cell(r->b_model * b_disp(c), 9);
    cell(m->b_known ? m->b * b_disp(c) : NAN, 9);
    printf("\n");
  }
  printf(
      "(Allan min: + still falling at the longest tau, < rising from the shortest tau. tau_B: 1.89 T of the\n"
      " GM bias, else the model curve's minimum; model above datasheet there: white noise hides the bias "
      "term)\n");
  double tau_max = 0.0;
  int c_max = -1;
  for (int c = 0; c < N_CH; ++c)
    if (isfinite(res[c].b_tau_s) && res[c].b_tau_s > tau_longest && res[c].b_tau_s > tau_max) {
      tau_max = res[c].b_tau_s;
      c_max = c;
    }
  if (c_max >= 0)
    printf("note       tau_B of %s is %.3g s, beyond the curve (%.3g s): --duration %.3g reads it\n",
           k_ch_name[c_max], tau_max, tau_longest, 10.0 * tau_max);
  printf("checks     %d of %d ARW/VRW checks pass\n", n_pass, n_checked);
  printf("results    %s/\n", out_dir);
}

int navsim_allan(int argc, char **argv) {
  allan_args a;
  memset(&a, 0, sizeof a);
  a.rate_hz = DEFAULT_RATE_HZ;
  a.duration_s = DEFAULT_DURATION_S;
  a.seed = 1;
  a.convention = NAV_BI_ALLAN_PEAK;
  const int prc = parse_args(argc, argv, &a);
  if (prc >= 0) return prc;

  allan_source src;
  memset(&src, 0, sizeof src);
  chan_model ch[N_CH];
  if (a.imu_name) {
    const int rc = load_catalog_part(&a, &src, ch);
    if (rc != EXIT_OK) return rc;
  } else {
    nav_scene sc;
    const int lrc = navsim_load_scene(a.scene_path, &sc);
    if (lrc != EXIT_OK) return lrc;
    snprintf(src.name, sizeof src.name, "%s", sc.imu.catalog[0] ? sc.imu.catalog : sc.name);
    src.kind = "scene";
    src.cfg = sc.imu.model;
    channel_models(&src.cfg, ch);
    if (!a.have_rate) a.rate_hz = sc.imu.rate_hz;
    if (!a.have_seed) a.seed = sc.simulation.seed;
    nav_scene_release(&sc);
  }

  const double n_real = floor(a.duration_s * a.rate_hz + 1e-9);
  const size_t m1 = (size_t)fmax(1.0, round(a.rate_hz)); /* tau ~ 1 s */
  if (n_real > MAX_SAMPLES) {
    fprintf(
        stderr,
        "navsim allan: %g s at %g Hz is %.3g samples; at most %.0e are kept (lower --duration or --rate)\n",
        a.duration_s, a.rate_hz, n_real, MAX_SAMPLES);
    return EXIT_INVALID;
  }
  if (n_real < 20.0 * (double)m1) {
    fprintf(stderr,
            "navsim allan: --duration must cover at least 20 s (the white noise is read at tau = 1 s)\n");
    return EXIT_INVALID;
  }
  const size_t n = (size_t)n_real;
  const double dt = 1.0 / a.rate_hz;

  char default_dir[600];
  if (!a.out_dir) {
    char nm[sizeof src.name];
    navsim_safe_name(nm, sizeof nm, src.name, "imu");
    snprintf(default_dir, sizeof default_dir, "out/allan-%s", nm);
    a.out_dir = default_dir;
  }
  {
    const int orc = navsim_out_check("allan", a.out_dir, a.force);
    if (orc != EXIT_OK) return orc;
  }

  int rc = EXIT_FAIL;
  nav_imu_model *model = NULL;
  nav_resultdir *rd = NULL;
  double *y = NULL, *work = NULL, *adev = NULL, *tau = NULL, *rel = NULL;
  size_t *m = NULL;
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);

  nav_status st = nav_imu_model_create(&src.cfg, a.seed, 0, &model);
  if (st != NAV_OK) {
    fprintf(stderr, "navsim allan: %s: invalid IMU model (%s)\n", src.name, nav_status_str(st));
    rc = EXIT_INVALID;
    goto cleanup;
  }
  y = malloc(sizeof *y * n * N_CH);
  work = malloc(sizeof *work * (n + 1));
  if (!y || !work) {
    fprintf(stderr, "navsim allan: out of memory (%zu samples)\n", n);
    goto cleanup;
  }

  /* Static input, constant over the run (FRD body = NED: level, heading north). */
  const double w_ie = NAV_WGS84_OMEGA_IE_RPS;
  const nav_vec3 w_ib_b = nav_vec3_make(w_ie * cos(STATIC_LAT_RAD), 0.0, -w_ie * sin(STATIC_LAT_RAD));
  const nav_vec3 f_ib_b = nav_vec3_make(0.0, 0.0, -NAV_G0_MPS2);
  for (size_t k = 1; k <= n; ++k) {
    nav_imu_increment ideal, meas;
    ideal.k = (int64_t)k;
    ideal.t_s = (double)k / a.rate_hz; /* t_k = k / rate from the integer k, never accumulated */
    ideal.dt_s = dt;
    ideal.dtheta_b_rad = nav_vec3_scale(w_ib_b, dt);
    ideal.dv_b_mps = nav_vec3_scale(f_ib_b, dt);
    st = nav_imu_model_apply(model, &ideal, &meas);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim allan: sample %zu: %s\n", k, nav_imu_model_last_error(model));
      goto cleanup;
    }
    for (int c = 0; c < 3; ++c) {
      y[(size_t)c * n + k - 1] = nav_vec3_get(meas.dtheta_b_rad, c) / dt;
      y[(size_t)(3 + c) * n + k - 1] = nav_vec3_get(meas.dv_b_mps, c) / dt;
    }
  }

  /* Log-spaced cluster sizes up to n/10 (relative uncertainty <= 0.24), 10 per decade. */
  size_t n_m = 0;
  if (nav_allan_log_clusters(n / 10, 10, NULL, 0, &n_m) != NAV_OK || n_m == 0) goto cleanup;
  m = malloc(sizeof *m * n_m);
  tau = malloc(sizeof *tau * n_m);
  rel = malloc(sizeof *rel * n_m);
  adev = malloc(sizeof *adev * n_m * N_CH);
  if (!m || !tau || !rel || !adev || nav_allan_log_clusters(n / 10, 10, m, n_m, &n_m) != NAV_OK) {
    fprintf(stderr, "navsim allan: out of memory\n");
    goto cleanup;
  }
  for (size_t k = 0; k < n_m; ++k) {
    tau[k] = (double)m[k] * dt;
    rel[k] = nav_allan_rel_uncertainty(n, m[k]);
  }
  /* The read-out points: ~0.1 s, ~1 s, ~10 s (whatever the rate; the slope uses the actual taus). */
  size_t mr[3] = {(size_t)fmax(1.0, round(0.1 * a.rate_hz)), m1, (size_t)round(10.0 * a.rate_hz)};
  const bool have_slope = mr[0] < m1 && mr[2] <= n / 2;
  const size_t n_r = have_slope ? 3 : 2;
  if (!have_slope) mr[2] = 0;
  const double tau1_s = (double)m1 * dt;
  chan_result res[N_CH];
  int n_checked = 0, n_pass = 0;
  for (int c = 0; c < N_CH; ++c) {
    const double *yc = y + (size_t)c * n;
    double ar[3] = {NAN, NAN, NAN};
    const size_t mq[3] = {m1, mr[0], mr[2]};
    st = nav_allan_overlapping(yc, n, dt, m, n_m, work, adev + (size_t)c * n_m);
    if (st == NAV_OK) st = nav_allan_overlapping(yc, n, dt, mq, n_r, work, ar);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim allan: Allan deviation of %s failed: %s\n", k_ch_name[c], nav_status_str(st));
      goto cleanup;
    }
    chan_result *r = &res[c];
    const chan_model *cm = &ch[c];
    r->n_1s = ar[0] * sqrt(tau1_s);
    /* The -1/2 line (IEEE 952 Annex C): through the curve point up to LINE_TAU_MAX_S whose local
     * slope (over its two neighbours, 0.2 decade) is closest to -1/2, i.e. where white noise
     * dominates most; read at tau = 1 s: N = adev(tau*) sqrt(tau*). At 1 s itself a bias term can
     * already lift the curve (a GM acts as a random walk at tau << T), as in the HG1700 row,
     * whose accelerometer curve is 18 % above the VRW at 1 s. */
    const double *ac = adev + (size_t)c * n_m;
    size_t kl = 0;
    double sl_best = INFINITY;
    for (size_t k = 1; k + 1 < n_m && tau[k] <= LINE_TAU_MAX_S; ++k) {
      if (!(ac[k - 1] > 0.0 && ac[k + 1] > 0.0)) continue;
      const double sl = log(ac[k + 1] / ac[k - 1]) / log(tau[k + 1] / tau[k - 1]);
      if (fabs(sl + 0.5) < fabs(sl_best + 0.5)) {
        sl_best = sl;
        kl = k;
      }
    }
    if (isfinite(sl_best)) {
      r->n_meas = ac[kl] * sqrt(tau[kl]);
      r->line_tau_s = tau[kl];
      r->line_rel = rel[kl];
      r->line_slope = sl_best;
    } else { /* too few points for a slope: the curve at 1 s */
      r->n_meas = r->n_1s;
      r->line_tau_s = tau1_s;
      r->line_rel = nav_allan_rel_uncertainty(n, m1);
      r->line_slope = NAN;
    }
    r->tol = fmax(TOL_REL, 3.0 * r->line_rel);
    r->checked = cm->noise_on && cm->n > 0.0;
    r->ratio = cm->noise_on && cm->n > 0.0 ? r->n_meas / cm->n : NAN;
    r->pass = r->checked && fabs(r->ratio - 1.0) <= r->tol;
    r->slope = have_slope && ar[1] > 0.0 && ar[2] > 0.0
                   ? log(ar[2] / ar[1]) / log((double)mr[2] / (double)mr[0])
                   : NAN;
    size_t imin = 0;
    for (size_t k = 0; k < n_m; ++k)
      if (ac[k] < ac[imin]) imin = k;
    r->min_adev = ac[imin];
    r->min_tau_s = tau[imin];
    r->min_where = imin + 1 == n_m ? "longest_tau" : (imin == 0 ? "shortest_tau" : "inside");
    /* Where to read the bias instability: the GM peak 1.8926 T (where the allan_peak mapping puts
     * the datasheet B), else the interior minimum of the model curve (white noise with a random
     * walk or quantisation), searched over 1 ms .. 1e6 s at 50 points per decade. */
    r->b_rule = "none";
    r->b_tau_s = NAN;
    if (cm->gm_on && cm->gm_sd > 0.0) {
      r->b_rule = "gm_peak";
      r->b_tau_s = NAV_GM_ALLAN_PEAK_TAU_RATIO * cm->gm_tau_s;
    } else {
      double best = INFINITY;
      int q_best = 0;
      for (int q = -150; q <= 300; ++q) {
        const double mv = model_adev(cm, pow(10.0, q / 50.0));
        if (mv < best) {
          best = mv;
          q_best = q;
        }
      }
      if (q_best > -150 && q_best < 300 && best > 0.0) {
        r->b_rule = "model_minimum";
        r->b_tau_s = pow(10.0, q_best / 50.0);
      }
    }
    r->b_model = isfinite(r->b_tau_s) ? model_adev(cm, r->b_tau_s) : NAN;
    r->b_meas = r->b_meas_tau_s = r->b_meas_rel = NAN;
    if (isfinite(r->b_tau_s)) {
      const size_t mb = (size_t)fmax(1.0, round(r->b_tau_s / dt));
      double ab = NAN;
      if (mb <= n / 10 && nav_allan_overlapping(yc, n, dt, &mb, 1, work, &ab) == NAV_OK) {
        r->b_meas = ab;
        r->b_meas_tau_s = (double)mb * dt;
        r->b_meas_rel = nav_allan_rel_uncertainty(n, mb);
      }
    }
    r->gm_peak = cm->gm_on ? NAV_GM_ALLAN_PEAK_SIGMA_RATIO * cm->gm_sd : NAN;
    if (r->checked) {
      ++n_checked;
      if (r->pass) ++n_pass;
    }
  }
  clock_gettime(CLOCK_MONOTONIC, &t1);
  const double wall = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);

  {
    const int orc = navsim_out_begin("allan", a.out_dir, a.force, &rd);
    if (orc != EXIT_OK) {
      rc = orc;
      goto cleanup;
    }
  }
  if (write_csv(nav_resultdir_file(rd, "allan.csv"), tau, n_m, adev, rel, ch) != EXIT_OK ||
      write_json(nav_resultdir_file(rd, "summary.json"), &a, &src, (int64_t)n, tau1_s, ch, res, n_checked,
                 n_pass, wall) != EXIT_OK) {
    fprintf(stderr, "navsim allan: writing the results in \"%s\" failed\n", a.out_dir);
    goto cleanup;
  }
  {
    const int orc = navsim_out_commit("allan", rd);
    rd = NULL;
    if (orc != EXIT_OK) {
      rc = orc;
      goto cleanup;
    }
  }
  if (!a.quiet) print_table(&a, &src, (int64_t)n, tau[n_m - 1], ch, res, n_checked, n_pass, a.out_dir);
  if (n_pass < n_checked)
    fprintf(stderr, "navsim allan: %d of %d ARW/VRW checks failed\n", n_checked - n_pass, n_checked);
  rc = (a.strict && n_pass < n_checked) ? EXIT_CHECK_FAILED : EXIT_OK;

cleanup:
  nav_resultdir_abort(rd);
  nav_imu_model_destroy(model);
  free(y);
  free(work);
  free(adev);
  free(tau);
  free(rel);
  free(m);
  return rc;
}
