/*
 * navsim estimate: the preliminary estimate of the design loop (architecture.md section 1):
 * closed-form error growth (numerics.md section 1, corrected formulas of the paper) and a
 * covariance analysis of the scene's scheme along its reference trajectory (numerics.md 6.6),
 * in milliseconds and without random draws.
 *
 * Outputs and their conventions (also in `navsim estimate --help` and estimate.json "conventions"):
 * - The free-INS closed forms are per level axis (one north or east channel, numerics.md 1.2):
 *   every row E1.6-E1.17 separately (nav_analytic_gyro_ins_table_eval(): columns
 *   pos_sd_m_<term>, vel_sd_mps_<term>, att_sd_rad_<term>, e.g. pos_sd_m_E1.10_accel_bias) and
 *   their root-sum-square E1.21 (analytic_pos_sd_m, ...). Bias rows are the one-sigma of a
 *   zero-mean random constant; every input is the worst axis of the scene's IMU model.
 * - Horizontal = sqrt(2) x per axis (north and east independent with equal sigma: the RSS of two
 *   equal per-axis sigmas): analytic_pos_h_sd_m, analytic_vel_h_sd_mps.
 * - Vertical (analytic_pos_v_sd_m): the accelerometer rows E1.10-E1.13 and the vertical initial
 *   errors E1.6-E1.7 (same kernels as a level axis, no tilt or gyro coupling); valid while the
 *   vertical-channel instability is negligible, t << tau_v = sqrt(a / (2 g)) = 570 s on WGS-84
 *   (delta_h = b tau_v^2 (cosh(t/tau_v) - 1) = b t^2/2 (1 + (t/tau_v)^2/12 + ...), numerics.md
 *   1.2 (iv)): analytic_pos_v_valid is 1 while (t/tau_v)^2/12 < 1 %, always on a flat Earth.
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE /* getloadavg */
#include "cli_util.h"
#include "estimate_cmd.h"
#include "navcore/nav_size_limits.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_analytic.h"
#include "navcore/nav_array.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_io.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_version.h"

static const char *k_usage_estimate =
    "usage: navsim estimate SCENE [--out DIR] [--force] [--quiet] [--allow-large] [--threads N]\n"
    "                      [--no-csv]\n"
    "\n"
    "Preliminary estimate of the scene's navigation errors, without simulation:\n"
    "  analytic    one-sigma error growth of a free-inertial INS per level axis from the IMU\n"
    "              error model and initial errors (closed forms E1.6-E1.21; valid for short times,\n"
    "              no Schuler feedback, small angles: flagged per row), term by term and in total\n"
    "  covariance  the error covariance of the scene's scheme (free INS or INS/GNSS with its\n"
    "              outages) propagated along the reference trajectory (wgs84 scenes)\n"
    "Writes into DIR (default out/<scene name>-estimate), atomically:\n"
    "  estimate.csv   one row per output epoch: t_s; the analytic totals per axis\n"
    "                 (analytic_pos_sd_m, analytic_vel_sd_mps, analytic_att_sd_rad, analytic_valid);\n"
    "                 the covariance columns (cov_*, empty unless wgs84); analytic_pos_h_sd_m and\n"
    "                 analytic_vel_h_sd_mps (horizontal = sqrt(2) x per axis: independent north and\n"
    "                 east channels with equal sigma); analytic_pos_v_sd_m and analytic_pos_v_valid\n"
    "                 (vertical: accelerometer rows and vertical initial errors, t << 570 s on\n"
    "                 WGS-84); then each row of E1.6-E1.17 per axis: pos_sd_m_<term>,\n"
    "                 vel_sd_mps_<term>, att_sd_rad_<term> (e.g. pos_sd_m_E1.10_accel_bias)\n"
    "  estimate.json  the final values (totals and every term), the conventions, and the verdict\n"
    "                 for each requirement of the scene (\"requirements\": predicted from the covariance\n"
    "                 analysis: rms, at_time, outage_end, p95/cep of horizontal, vertical and yaw;\n"
    "                 value null where sigmas do not determine the statistic, e.g. max)\n"
    "  summary.json   scene, timing, final analytic and covariance values\n"
    NAVSIM_OUT_HELP
    "\n"
    "options:\n"
    "  --allow-large  go ahead above the limits below\n"
    "  --threads N    threads (default one per idle core: the cores less the load average, at\n"
    "                 least one): the quantile statistics share out their quadrature, and with\n"
    "                 PVT fixes (whose requirements need a covariance analysis of their own; the\n"
    "                 other scenes get theirs from the one of estimate.csv) that analysis runs\n"
    "                 beside the one of estimate.csv; the outputs are bit-identical for any N\n"
    "  --no-csv       write estimate.json and summary.json only, without estimate.csv (what\n"
    "                 navsim serve's POST /api/estimate answers with); the same values\n"
    "\n" NAV_LIMITS_HELP "\n"
    "exit codes: 0 success; 2 invalid scene or options; 1 other failure\n";

static double vmax(nav_vec3 v) { return fmax(fmax(v.x, v.y), v.z); }

/* Worst-axis one-sigma of a per-run random constant: fixed offset and sd combined. */
static double const_sd(unsigned terms, unsigned bit, nav_vec3 fixed, nav_vec3 sd) {
  if (!(terms & bit)) return 0.0;
  double m = 0.0;
  for (int i = 0; i < 3; ++i) m = fmax(m, hypot(nav_vec3_get(fixed, i), nav_vec3_get(sd, i)));
  return m;
}

/* The closed-form inputs from the scene: worst axis of every term (a bound over axes). */
static nav_analytic_estimate_config analytic_config(const nav_scene *sc) {
  nav_analytic_estimate_config c = nav_analytic_estimate_config_default();
  nav_analytic_imu_spec *s = &c.imu;
  const nav_gyro_error_config *g = &sc->imu.model.gyro;
  const nav_accel_error_config *a = &sc->imu.model.accel;
  s->g_mps2 = sc->earth.model == NAV_EARTH_FLAT
                  ? sc->earth.flat_gravity_mps2
                  : nav_earth_gravity_normal_mps2(sc->earth.origin_lat_rad, sc->earth.origin_h_m);
  s->init_pos_sd_m = fmax(sc->initial_errors.pos_sd_m.x, sc->initial_errors.pos_sd_m.y);
  s->init_vel_sd_mps = fmax(sc->initial_errors.vel_sd_mps.x, sc->initial_errors.vel_sd_mps.y);
  s->init_tilt_sd_rad = fmax(sc->initial_errors.att_sd_rad.x, sc->initial_errors.att_sd_rad.y);
  s->init_heading_sd_rad = sc->initial_errors.att_sd_rad.z;
  s->accel_bias_mps2 = const_sd(a->terms, NAV_IMU_TERM_BIAS_TURN_ON, a->bias_turn_on_fixed_mps2, a->bias_turn_on_sd_mps2);
  s->gyro_bias_rps = const_sd(g->terms, NAV_IMU_TERM_BIAS_TURN_ON, g->bias_turn_on_fixed_rps, g->bias_turn_on_sd_rps);
  if (a->terms & NAV_IMU_TERM_NOISE) s->accel_vrw_mps_per_sqrt_s = vmax(a->vrw_mps_per_sqrt_s);
  if (g->terms & NAV_IMU_TERM_NOISE) s->gyro_arw_rad_per_sqrt_s = vmax(g->arw_rad_per_sqrt_s);
  if (a->terms & NAV_IMU_TERM_BIAS_GM) {
    s->accel_gm_sd_mps2 = vmax(a->bias_gm_sd_mps2);
    s->accel_gm_tau_s = vmax(a->bias_gm_tau_s);
  }
  if (g->terms & NAV_IMU_TERM_BIAS_GM) {
    s->gyro_gm_sd_rps = vmax(g->bias_gm_sd_rps);
    s->gyro_gm_tau_s = vmax(g->bias_gm_tau_s);
  }
  if (a->terms & NAV_IMU_TERM_BIAS_RW) s->accel_bias_rw_mps2_per_sqrt_s = vmax(a->bias_rw_mps2_per_sqrt_s);
  if (g->terms & NAV_IMU_TERM_BIAS_RW) s->gyro_rrw_rps_per_sqrt_s = vmax(g->bias_rw_rps_per_sqrt_s);
  /* Gyro-free scheme: the array's geometry (kappa from its H, E1.23-E1.25) and per-sensor errors
   * (biases as zero-mean random constants: turn-on and GM sigma combined). */
  /* gyro_free_gnss: the same closed forms describe its array alone, i.e. how fast an outage grows. */
  if ((sc->navigation.scheme == NAV_SCHEME_GYRO_FREE || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS) &&
      nav_array_layout_from_scene(&sc->array, &c.array) == NAV_OK) {
    const nav_array_error_config *ae = &sc->array.accel;
    c.with_gyrofree = true;
    c.array_accel_bias_mps2 = hypot((ae->terms & NAV_IMU_TERM_BIAS_TURN_ON) ? ae->bias_turn_on_sd_mps2 : 0.0,
                                    (ae->terms & NAV_IMU_TERM_BIAS_GM) ? ae->bias_gm_sd_mps2 : 0.0);
    c.array_accel_noise_mps_per_sqrt_s = (ae->terms & NAV_IMU_TERM_NOISE) ? ae->vrw_mps_per_sqrt_s : 0.0;
    c.array_init_rate_sd_rps = vmax(sc->array.initial_rate_sd_rps);
  }
  return c;
}

/* Column suffix of a table row: its label with blanks as underscores ("E1.10_accel_bias"). */
static void term_label(nav_analytic_term_id id, char *buf, size_t cap) {
  snprintf(buf, cap, "%s", nav_analytic_term_name(id));
  for (char *p = buf; *p; ++p)
    if (*p == ' ') *p = '_';
}

/* Vertical-channel spec: the accelerometer rows with the vertical initial errors; no tilt,
 * heading or gyro coupling into the vertical (numerics.md 1.2 (iv)). */
static nav_analytic_imu_spec vertical_spec(const nav_analytic_imu_spec *h, const nav_scene *sc) {
  nav_analytic_imu_spec v = nav_analytic_imu_spec_default();
  v.g_mps2 = h->g_mps2;
  v.init_pos_sd_m = sc->initial_errors.pos_sd_m.z;
  v.init_vel_sd_mps = sc->initial_errors.vel_sd_mps.z;
  v.accel_bias_mps2 = h->accel_bias_mps2;
  v.accel_vrw_mps_per_sqrt_s = h->accel_vrw_mps_per_sqrt_s;
  v.accel_gm_sd_mps2 = h->accel_gm_sd_mps2;
  v.accel_gm_tau_s = h->accel_gm_tau_s;
  v.accel_bias_rw_mps2_per_sqrt_s = h->accel_bias_rw_mps2_per_sqrt_s;
  return v;
}

/*
 * Schuler-bounded one-sigma of a level channel (north, E1.18/E1.20) for the random constants of
 * the spec: initial position, velocity and tilt errors, accelerometer and gyro biases, each as a
 * zero-mean random constant of the given sigma; the responses to independent sources add in
 * squares. White noise, GM and random-walk terms are not in these closed forms (they are in the
 * short-time table and in the covariance analysis).
 */
static nav_analytic_schuler_error schuler_sd(const nav_analytic_imu_spec *sp, double radius_m, double t) {
  double p2 = 0.0, v2 = 0.0;
  for (int src = 0; src < 5; ++src) {
    nav_analytic_schuler_channel ch;
    memset(&ch, 0, sizeof ch);
    ch.g_mps2 = sp->g_mps2;
    ch.radius_m = radius_m;
    if (src == 0) ch.dr0_m = sp->init_pos_sd_m;
    if (src == 1) ch.dv0_mps = sp->init_vel_sd_mps;
    if (src == 2) ch.accel_bias_mps2 = sp->accel_bias_mps2;
    if (src == 3) ch.tilt0_rad = sp->init_tilt_sd_rad;
    if (src == 4) ch.gyro_bias_rps = sp->gyro_bias_rps;
    const nav_analytic_schuler_error e = nav_analytic_schuler_north(&ch, t);
    p2 += e.pos_m * e.pos_m;
    v2 += e.vel_mps * e.vel_mps;
  }
  nav_analytic_schuler_error r = {sqrt(p2), sqrt(v2)};
  return r;
}

/* Epochs computed and written per batch: the analytic closed forms are evaluated for a batch of
 * output epochs at once and the rows written, so memory does not grow with the run (an estimate
 * of 1e6 output epochs used to hold about 410 MB of rows; issue 25). */
#define EST_BATCH 4096

/* Terminal read-out times [s] (the first output epoch at or after each; 1e30: the last one). */
static const double k_show_s[] = {1, 10, 30, 60, 120, 300, 600, 1800, 3600, 1e30};
#define N_SHOW (sizeof k_show_s / sizeof k_show_s[0])

/* What the rows of estimate.csv are made of, fixed for the scene. */
typedef struct est_ctx {
  const nav_scene *sc;
  nav_analytic_estimate_config acfg;
  nav_analytic_imu_spec vspec;
  double t_v_max_s;
  bool schuler;
  double schuler_r;
  int64_t n_imu, stride;
  size_t nt; /* output epochs */
} est_ctx;

/* Time of output epoch @p i: every stride-th IMU sample, and the last one (as navsim run). */
static double epoch_time(const est_ctx *c, size_t i) {
  const int64_t k = (int64_t)i * c->stride;
  return k <= c->n_imu ? (double)k / c->sc->imu.rate_hz : (double)c->n_imu / c->sc->imu.rate_hz;
}

/* The analytic values of one epoch. */
typedef struct est_epoch {
  double t_s;
  nav_analytic_estimate_point ana;
  nav_analytic_gyro_ins_table tab;
  double pos_v_m;
} est_epoch;

/* Analytic estimate, term table and vertical channel at the times e[0..n).t_s. */
static nav_status eval_epochs(const est_ctx *c, est_epoch *e, size_t n, double *tbuf,
                              nav_analytic_estimate_point *abuf) {
  for (size_t i = 0; i < n; ++i)
    tbuf[i] = e[i].t_s;
  nav_status st = nav_analytic_estimate(&c->acfg, tbuf, n, abuf);
  for (size_t i = 0; i < n && st == NAV_OK; ++i) {
    nav_analytic_gyro_ins_table vt;
    e[i].ana = abuf[i];
    st = nav_analytic_gyro_ins_table_eval(&c->acfg.imu, e[i].t_s, &e[i].tab);
    if (st == NAV_OK) st = nav_analytic_gyro_ins_table_eval(&c->vspec, e[i].t_s, &vt);
    if (st == NAV_OK) e[i].pos_v_m = vt.rss.pos_m;
  }
  return st;
}

/* The header line of estimate.csv. */
static void write_header(FILE *f, const est_ctx *c) {
  fputs("t_s,analytic_pos_sd_m,analytic_vel_sd_mps,analytic_att_sd_rad,analytic_valid,cov_pos_n_sd_m,cov_pos_"
        "e_sd_m,"
        "cov_pos_d_sd_m,cov_pos_h_sd_m,cov_vel_n_sd_mps,cov_vel_e_sd_mps,cov_vel_d_sd_mps,cov_att_n_sd_rad,"
        "cov_att_e_sd_rad,cov_att_d_sd_rad,analytic_pos_h_sd_m,analytic_vel_h_sd_mps,analytic_pos_v_sd_m,"
        "analytic_pos_v_valid",
        f);
  for (int q = 0; q < NAV_ANALYTIC_TERM_COUNT; ++q) {
    char lab[64];
    term_label((nav_analytic_term_id)q, lab, sizeof lab);
    fprintf(f, ",pos_sd_m_%s,vel_sd_mps_%s,att_sd_rad_%s", lab, lab, lab);
  }
  if (c->acfg.with_gyrofree)
    fputs(",gyrofree_pos_sd_m,gyrofree_vel_sd_mps,gyrofree_att_sd_rad,gyrofree_small_angle_ok,gyrofree_paper_"
          "pos_m",
          f);
  if (c->schuler) fputs(",analytic_schuler_pos_sd_m,analytic_schuler_vel_sd_mps", f);
  fputc('\n', f);
}

/* Columns of estimate.csv: the commas of its header, plus one. */
static int header_columns(const est_ctx *c) {
  char *buf = NULL;
  size_t len = 0;
  FILE *m = open_memstream(&buf, &len);
  if (!m) return 0;
  write_header(m, c);
  fclose(m);
  int n = buf ? 1 : 0;
  for (const char *p = buf; p && *p; ++p)
    n += *p == ',';
  free(buf);
  return n;
}

/* A row of estimate.csv built in memory: numbers as printf's "%.17g" (nav_format_g17, the same
 * bytes at a fraction of the cost: formatting was a seventh of ship's estimate), flags as "%d". */
typedef struct row_buf {
  char s[(NAV_FORMAT_G17_SIZE + 1) * (32 + 3 * NAV_ANALYTIC_TERM_COUNT)];
  size_t n;
} row_buf;

static void put_g(row_buf *b, double x) {
  if (b->n) b->s[b->n++] = ',';
  b->n += (size_t)nav_format_g17(b->s + b->n, x);
}
static void put_flag(row_buf *b, bool v) {
  b->s[b->n++] = ',';
  b->s[b->n++] = v ? '1' : '0';
}

/* One row of estimate.csv (cov NULL: empty covariance columns). */
static void write_row(FILE *f, const est_ctx *c, const est_epoch *e, const nav_cov_point *p) {
  const nav_analytic_estimate_point *a = &e->ana;
  row_buf b;
  b.n = 0;
  put_g(&b, e->t_s);
  put_g(&b, a->gyro_ins.pos_sd_m);
  put_g(&b, a->gyro_ins.vel_sd_mps);
  put_g(&b, a->gyro_ins.att_sd_rad);
  put_flag(&b, a->gyro_ins_short_time_ok);
  if (p) {
    const double v[10] = {p->pos_sd_n_m.x,   p->pos_sd_n_m.y,   p->pos_sd_n_m.z,   p->pos_h_sd_m,
                          p->vel_sd_n_mps.x, p->vel_sd_n_mps.y, p->vel_sd_n_mps.z, p->att_sd_rad.x,
                          p->att_sd_rad.y,   p->att_sd_rad.z};
    for (int i = 0; i < 10; ++i) put_g(&b, v[i]);
  } else {
    memcpy(b.s + b.n, ",,,,,,,,,,", 10);
    b.n += 10;
  }
  put_g(&b, sqrt(2.0) * a->gyro_ins.pos_sd_m);
  put_g(&b, sqrt(2.0) * a->gyro_ins.vel_sd_mps);
  put_g(&b, e->pos_v_m);
  put_flag(&b, e->t_s < c->t_v_max_s);
  for (int q = 0; q < NAV_ANALYTIC_TERM_COUNT; ++q) {
    put_g(&b, e->tab.term[q].pos_m);
    put_g(&b, e->tab.term[q].vel_mps);
    put_g(&b, e->tab.term[q].att_rad);
  }
  if (c->acfg.with_gyrofree) {
    put_g(&b, a->gyrofree.pos_sd_m);
    put_g(&b, a->gyrofree.vel_sd_mps);
    put_g(&b, a->gyrofree.att_sd_rad);
    put_flag(&b, a->gyrofree_small_angle_ok);
    put_g(&b, a->gyrofree_paper_pos_m);
  }
  if (c->schuler) {
    const nav_analytic_schuler_error se = schuler_sd(&c->acfg.imu, c->schuler_r, e->t_s);
    put_g(&b, se.pos_m);
    put_g(&b, se.vel_mps);
  }
  b.s[b.n++] = '\n';
  fwrite(b.s, 1, b.n, f);
}

/* The rows of estimate.csv as they are computed: a batch of epochs (with their covariance points
 * when the analysis runs), written when full. Only what the summaries need is kept: the last
 * epoch, the covariance at the read-out times and the largest horizontal sigma. */
typedef struct est_stream {
  const est_ctx *c;
  FILE *f;
  bool with_cov;
  nav_status st; /* first failure of the analytic part */
  size_t n;      /* epochs received */
  size_t nb;     /* epochs in the batch */
  est_epoch *batch;
  nav_cov_point *cov;
  double *tbuf;
  nav_analytic_estimate_point *abuf;
  double analytic_wall_s;         /* time spent in the closed forms */
  double hmax;                    /* largest cov pos_h_sd_m */
  nav_cov_point cov_last;         /* covariance of the last epoch received */
  size_t show_i[N_SHOW];          /* first epoch at or after each read-out time; nt: none yet */
  nav_cov_point show_cov[N_SHOW]; /* its covariance */
  /* Every total-model point (nav_sim_covariance_total), kept when the requirements are predicted
   * from this very analysis: nav_req_predict_scene would run it again. */
  bool keep_points;
  nav_cov_point *pts;
  size_t npts, pts_cap;
} est_stream;

static bool flush_batch(est_stream *s) {
  if (s->nb == 0 || s->st != NAV_OK) return s->st == NAV_OK;
  const double t0 = navsim_now_s();
  s->st = eval_epochs(s->c, s->batch, s->nb, s->tbuf, s->abuf);
  s->analytic_wall_s += navsim_now_s() - t0;
  if (s->st != NAV_OK) return false;
  for (size_t i = 0; i < s->nb && s->f; ++i)
    write_row(s->f, s->c, &s->batch[i], s->with_cov ? &s->cov[i] : NULL);
  s->nb = 0;
  return true;
}

/* Epoch s->n (its covariance point @p p, or NULL; @p keep: the point the requirements are
 * predicted from, kept when s->keep_points). */
static bool stream_epoch(est_stream *s, const nav_cov_point *p, const nav_cov_point *keep) {
  const size_t i = s->n++;
  const double t = epoch_time(s->c, i);
  s->batch[s->nb].t_s = t;
  if (p) {
    s->cov[s->nb] = *p;
    s->hmax = fmax(s->hmax, p->pos_h_sd_m);
    s->cov_last = *p;
    if (s->keep_points && keep) {
      if (s->npts == s->pts_cap) {
        const size_t nc = s->pts_cap ? 2 * s->pts_cap : 1024;
        nav_cov_point *g = realloc(s->pts, nc * sizeof *g);
        if (!g) {
          s->st = NAV_ERR_NO_MEMORY;
          return false;
        }
        s->pts = g;
        s->pts_cap = nc;
      }
      s->pts[s->npts++] = *keep;
    }
  }
  for (size_t q = 0; q < N_SHOW; ++q)
    if (s->show_i[q] == s->c->nt && t >= k_show_s[q]) {
      s->show_i[q] = i;
      if (p) s->show_cov[q] = *p;
    }
  ++s->nb;
  return s->nb < EST_BATCH || flush_batch(s);
}

static nav_callback_result stream_cov(void *user, const nav_cov_point *p) {
  est_stream *s = user;
  if (s->n >= s->c->nt) { /* more epochs than the scene's output epochs */
    s->n = s->c->nt + 1;
    return NAV_STOP;
  }
  return stream_epoch(s, p, p) ? NAV_CONTINUE : NAV_STOP;
}

/* nav_sim_covariance_total: the filter's point into the rows, the total model's kept for the
 * requirements. */
static nav_callback_result stream_cov_total(void *user, const nav_cov_point *p, const nav_cov_point *total) {
  est_stream *s = user;
  if (s->n >= s->c->nt) {
    s->n = s->c->nt + 1;
    return NAV_STOP;
  }
  return stream_epoch(s, p, total) ? NAV_CONTINUE : NAV_STOP;
}

/* The requirements predicted by their own covariance analysis (nav_req_predict_scene_threads),
 * run on a thread of its own beside the analysis that fills estimate.csv: the two share nothing
 * but the scene, which neither changes. */
typedef struct predict_job {
  const nav_scene *sc;
  int threads;
  nav_requirement_verdict *out;
  nav_status st;
} predict_job;

static void *predict_job_run(void *arg) {
  predict_job *j = arg;
  j->st = nav_req_predict_scene_threads(j->sc, j->threads, j->out);
  return NULL;
}

/*
 * estimate.json: the final values of the analytic estimate (totals and every term), the
 * covariance analysis when available, the conventions, and one verdict per requirement of the
 * scene predicted from the covariance analysis (nav_req_predict).
 * @return 0, or -1 when the file cannot be written.
 */
static int write_estimate_json(const char *path, const nav_scene *sc, const char *scene_path,
                               const nav_analytic_gyro_ins_table *tab, const nav_analytic_estimate_point *al,
                               double pos_v_m, bool pos_v_valid, const nav_cov_point *cov,
                               const nav_requirement_verdict *pred, int n_pred) {
  FILE *f = path ? fopen(path, "w") : NULL;
  if (!f) return -1;
  fprintf(f, "{\n  \"navsim_version\": \"%s\",\n  \"scene\": {\"name\": ", nav_version_string());
  nav_json_write_string(f, sc->name);
  fputs(", \"file\": ", f);
  nav_json_write_string(f, scene_path);
  fprintf(f, "},\n  \"scheme\": \"%s\",\n  \"t_s\": %.17g,\n", nav_nav_scheme_name(sc->navigation.scheme), tab->t_s);
  fputs("  \"conventions\": {\"per_axis\": \"one level channel (north or east) of a free-inertial INS, numerics.md "
        "1.2; inputs are the worst axis of the IMU model\", \"horizontal\": \"sqrt(2) x per axis (independent "
        "north and east channels with equal sigma)\", \"vertical\": \"accelerometer rows E1.10-E1.13 and the "
        "vertical initial errors; valid for t << 570 s on WGS-84\", \"total\": \"root-sum-square of the rows "
        "(E1.21); bias rows are the one-sigma of zero-mean random constants\"},\n",
        f);
  fprintf(f,
          "  \"analytic_final\": {\"pos_sd_m\": %.17g, \"vel_sd_mps\": %.17g, \"att_sd_rad\": %.17g, \"pos_h_sd_m\": "
          "%.17g, \"vel_h_sd_mps\": %.17g, \"pos_v_sd_m\": %.17g, \"valid\": %s, \"pos_v_valid\": %s,\n"
          "    \"terms\": [\n",
          al->gyro_ins.pos_sd_m, al->gyro_ins.vel_sd_mps, al->gyro_ins.att_sd_rad, sqrt(2.0) * al->gyro_ins.pos_sd_m,
          sqrt(2.0) * al->gyro_ins.vel_sd_mps, pos_v_m, al->gyro_ins_short_time_ok ? "true" : "false",
          pos_v_valid ? "true" : "false");
  for (int q = 0; q < NAV_ANALYTIC_TERM_COUNT; ++q) {
    const nav_analytic_term_id id = (nav_analytic_term_id)q;
    const char *name = nav_analytic_term_name(id);
    const char *blank = strchr(name, ' ');
    const int eq_len = blank ? (int)(blank - name) : (int)strlen(name);
    fprintf(f,
            "      {\"equation\": \"%.*s\", \"term\": \"%s\", \"kind\": \"%s\", \"pos_sd_m\": %.17g, "
            "\"vel_sd_mps\": %.17g, \"att_sd_rad\": %.17g, \"pos_h_sd_m\": %.17g}%s\n",
            eq_len, name, blank ? blank + 1 : "", nav_analytic_term_is_process(id) ? "process" : "random_constant",
            tab->term[q].pos_m, tab->term[q].vel_mps, tab->term[q].att_rad, sqrt(2.0) * tab->term[q].pos_m,
            q + 1 < NAV_ANALYTIC_TERM_COUNT ? "," : "");
  }
  fputs("    ]},\n", f);
  if (cov)
    fprintf(f,
            "  \"covariance_final\": {\"pos_h_sd_m\": %.17g, \"pos_d_sd_m\": %.17g, \"vel_n_sd_mps\": %.17g, "
            "\"vel_e_sd_mps\": %.17g, \"att_d_sd_rad\": %.17g},\n",
            cov->pos_h_sd_m, cov->pos_sd_n_m.z, cov->vel_sd_n_mps.x, cov->vel_sd_n_mps.y, cov->att_sd_rad.z);
  else
    fputs("  \"covariance_final\": null,\n", f);
  /* Predicted verdicts from the covariance analysis (nav_req_predict; value null where the
     statistic cannot be predicted from sigmas, or without a covariance analysis). */
  fputs("  \"requirements\": ", f);
  if (nav_requirements_write_json(f, pred, pred ? n_pred : 0, 2) != NAV_OK) fputs("[]", f);
  fputs("\n}\n", f);
  const bool bad = ferror(f) != 0;
  return (fclose(f) != 0 || bad) ? -1 : 0;
}

int navsim_estimate(int argc, char **argv) {
  const char *scene_path = NULL, *out_dir = NULL;
  bool quiet = false, force = false, allow_large = false;
  long threads = 0; /* 0: one per core */
  bool no_csv = false;
  for (int i = 0; i < argc; ++i) {
    if (navsim_is_help(argv[i])) {
      fputs(k_usage_estimate, stdout);
      return 0;
    } else if (strcmp(argv[i], "--quiet") == 0) {
      quiet = true;
    } else if (strcmp(argv[i], "--force") == 0) {
      force = true;
    } else if (strcmp(argv[i], "--allow-large") == 0) {
      allow_large = true;
    } else if (strcmp(argv[i], "--no-csv") == 0) {
      no_csv = true;
    } else if (strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      out_dir = argv[++i];
    } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
      char *end = NULL;
      errno = 0;
      threads = strtol(argv[++i], &end, 10);
      if (errno != 0 || end == argv[i] || *end != '\0' || threads < 1 || threads > 256) {
        fprintf(stderr, "navsim estimate: --threads expects an integer from 1 to 256, got \"%s\"\n", argv[i]);
        return 2;
      }
    } else if (argv[i][0] == '-') {
      fprintf(stderr, "navsim estimate: unknown or incomplete option \"%s\" (see navsim estimate --help)\n", argv[i]);
      return 2;
    } else if (!scene_path) {
      scene_path = argv[i];
    } else {
      fprintf(stderr, "navsim estimate: only one SCENE may be given\n");
      return 2;
    }
  }
  if (!scene_path) {
    fprintf(stderr, "navsim estimate: missing SCENE\n%s", k_usage_estimate);
    return 2;
  }
  if (threads == 0) {
    /* One per idle core: the cores less the 1-minute load average (which counts the other
     * programs running), at least one. On a busy machine a second thread would only wait for a
     * core and do speculative work; the outputs are the same either way. */
    const long cores = sysconf(_SC_NPROCESSORS_ONLN);
    double load = 0.0;
    const long busy = getloadavg(&load, 1) == 1 && load > 0.0 ? lround(load) : 0;
    threads = cores - busy;
    if (threads > 16) threads = 16;
    if (threads < 1) threads = 1;
  }
  nav_scene sc;
  const int lrc = navsim_load_scene(scene_path, &sc);
  if (lrc != 0) return lrc;
  navsim_warn_gnss_file_model("estimate", scene_path, &sc);
  char default_dir[600];
  if (!out_dir) {
    char nm[NAV_SCENE_NAME_MAX];
    navsim_safe_name(nm, sizeof nm, sc.name, "scene");
    snprintf(default_dir, sizeof default_dir, "out/%s-estimate", nm);
    out_dir = default_dir;
  }
  const int orc = navsim_out_check("estimate", out_dir, force);
  if (orc != 0) {
    nav_scene_release(&sc);
    return orc;
  }

  int rc = 1;
  nav_sim *sim = NULL;
  nav_resultdir *rd = NULL;
  nav_requirement_verdict *pred = NULL; /* predicted requirement verdicts */
  predict_job job = {&sc, (int)threads, NULL, NAV_OK};
  pthread_t job_thread;
  bool job_running = false, job_started = false;
  est_stream es;
  memset(&es, 0, sizeof es);
  FILE *f = NULL;

  /* Output epochs of the scene (as navsim run: every stride-th IMU sample and the last). */
  est_ctx ctx;
  memset(&ctx, 0, sizeof ctx);
  ctx.sc = &sc;
  ctx.n_imu = (int64_t)floor(sc.trajectory.duration_s * sc.imu.rate_hz + 1e-9);
  ctx.stride = (int64_t)llround(sc.imu.rate_hz / sc.output.rate_hz);
  if (ctx.stride < 1) ctx.stride = 1;
  ctx.nt = (size_t)(ctx.n_imu / ctx.stride + 1 + (ctx.n_imu % ctx.stride != 0 ? 1 : 0));
  const size_t nt = ctx.nt;
  ctx.acfg = analytic_config(&sc);
  /* Term by term (E1.6-E1.17) and the vertical channel. */
  ctx.vspec = vertical_spec(&ctx.acfg.imu, &sc);
  /* Vertical validity: (t / tau_v)^2 / 12 < 1 %, tau_v = sqrt(a / (2 g)) (numerics.md 1.2 (iv)). */
  const double tau_v_s = sqrt(NAV_WGS84_A_M / (2.0 * ctx.acfg.imu.g_mps2));
  ctx.t_v_max_s = sc.earth.model == NAV_EARTH_FLAT ? INFINITY : tau_v_s * sqrt(0.12);
  ctx.schuler = sc.earth.model == NAV_EARTH_WGS84;
  ctx.schuler_r = nav_analytic_schuler_radius_m(sc.earth.origin_lat_rad, sc.earth.origin_h_m);
  const nav_analytic_estimate_config acfg = ctx.acfg;

  es.c = &ctx;
  es.batch = malloc(EST_BATCH * sizeof *es.batch);
  es.cov = malloc(EST_BATCH * sizeof *es.cov);
  es.tbuf = malloc(EST_BATCH * sizeof *es.tbuf);
  es.abuf = malloc(EST_BATCH * sizeof *es.abuf);
  if (!es.batch || !es.cov || !es.tbuf || !es.abuf) {
    fprintf(stderr, "navsim estimate: out of memory\n");
    goto cleanup;
  }
  {
    /* estimate.csv predicted from the scene, refused beyond the limits before any work. */
    nav_size_prediction sp;
    nav_predict_estimate(&sc, header_columns(&ctx), &sp);
    if (nav_size_check("estimate", scene_path, &sp, allow_large, false) != 0) {
      rc = 2;
      goto cleanup;
    }
  }
  for (size_t q = 0; q < N_SHOW; ++q)
    es.show_i[q] = nt;
  /* The first epoch's analytic values: the closed forms' inputs are checked before any output. */
  {
    est_epoch e0;
    e0.t_s = 0.0;
    const nav_status st0 = eval_epochs(&ctx, &e0, 1, es.tbuf, es.abuf);
    if (st0 != NAV_OK) {
      fprintf(stderr, "navsim estimate: analytic estimate failed: %s\n", nav_status_str(st0));
      goto cleanup;
    }
  }

  rc = navsim_out_begin("estimate", out_dir, force, &rd);
  if (rc != 0) goto cleanup;
  rc = 1;
  long header_end = 0;
  if (!no_csv) {
    const char *csv = nav_resultdir_file(rd, "estimate.csv");
    f = csv ? fopen(csv, "w") : NULL;
    if (!f) goto cleanup;
    write_header(f, &ctx);
    header_end = ftell(f);
  }
  es.f = f; /* NULL: no rows written (--no-csv) */

  /* The covariance analysis streams its output epochs into the rows (WGS-84 scenes). */
  bool have_cov = false;
  double t_cov = 0.0;
  nav_status st = NAV_OK;
  if (sc.earth.model == NAV_EARTH_WGS84) {
    st = nav_sim_create(&sc, &sim);
    es.with_cov = true;
    /* The requirements' covariance model (nav_req_predict_scene: the filter, plus the truth's
     * scale factors the filter does not estimate as consider states) comes out of this very
     * analysis (nav_sim_covariance_total), except for PVT fixes, whose budget model is not the
     * filter's: there it runs on its own, beside this one when there is a second thread. */
    es.keep_points = sc.n_requirements > 0 && !nav_scene_gnss_pvt_fixes(&sc);
    if (st == NAV_OK && sc.n_requirements > 0 && !es.keep_points && threads > 1) {
      /* The requirements' own analysis beside this one (used when this one covers the epochs). */
      job.out = calloc((size_t)sc.n_requirements, sizeof *job.out);
      job_running = job_started = job.out && pthread_create(&job_thread, NULL, predict_job_run, &job) == 0;
    }
    if (st == NAV_OK) {
      const double tc = navsim_now_s();
      st = es.keep_points ? nav_sim_covariance_total(sim, stream_cov_total, &es)
                          : nav_sim_covariance(sim, stream_cov, &es);
      if (st == NAV_OK || st == NAV_ERR_CANCELLED) flush_batch(&es);
      t_cov = navsim_now_s() - tc;
    }
    if (es.st != NAV_OK) {
      fprintf(stderr, "navsim estimate: analytic estimate failed: %s\n", nav_status_str(es.st));
      goto cleanup;
    }
    if (st == NAV_ERR_CANCELLED && es.n > nt) st = NAV_OK; /* more epochs than expected: no covariance */
    if (st != NAV_OK) {
      fprintf(stderr, "navsim estimate: covariance analysis failed: %s\n",
              sim ? nav_sim_last_error(sim) : nav_status_str(st));
      goto cleanup;
    }
    have_cov = es.n == nt;
  }
  if (!have_cov) {
    /* No covariance analysis (flat Earth), or one whose epochs are not the output epochs: the
     * analytic rows alone, from the first epoch. */
    if (f && (fflush(f) != 0 || fseek(f, header_end, SEEK_SET) != 0 || ftruncate(fileno(f), header_end) != 0))
      goto cleanup;
    es.with_cov = false;
    es.n = es.nb = 0;
    for (size_t q = 0; q < N_SHOW; ++q)
      es.show_i[q] = nt;
    for (size_t i = 0; i < nt; ++i)
      if (!stream_epoch(&es, NULL, NULL)) break;
    flush_batch(&es);
    if (es.st != NAV_OK) {
      fprintf(stderr, "navsim estimate: analytic estimate failed: %s\n", nav_status_str(es.st));
      goto cleanup;
    }
  }
  t_cov -= have_cov ? es.analytic_wall_s : 0.0;
  const double t_analytic = es.analytic_wall_s;
  const bool bad = f && ferror(f) != 0;
  if (f && (fclose(f) != 0 || bad)) {
    f = NULL;
    goto cleanup;
  }
  f = NULL;

  if (sc.n_requirements > 0) {
    /* Requirements predicted from the covariance analysis; not evaluated without one. */
    pred = calloc((size_t)sc.n_requirements, sizeof *pred);
    if (!pred) goto cleanup;
    /* The covariance analysis plus the truth's scale factors the filter does not estimate
       (nav_req_predict_scene, as navsim select predicts); nothing without a covariance analysis. */
    if (job_running) {
      pthread_join(job_thread, NULL);
      job_running = false;
    }
    if (have_cov && job_started) {
      memcpy(pred, job.out, (size_t)sc.n_requirements * sizeof *pred);
      st = job.st;
    } else {
      st = !have_cov       ? nav_req_predict(sc.requirements, sc.n_requirements, NULL, 0, NULL, 0, pred)
           : es.keep_points ? nav_req_predict_scene_total_points_threads(&sc, es.pts, es.npts, (int)threads, pred)
                            : nav_req_predict_scene_threads(&sc, (int)threads, pred);
    }
    if (st != NAV_OK) {
      fprintf(stderr, "navsim estimate: predicting the requirements failed: %s\n", nav_status_str(st));
      goto cleanup;
    }
  }

  /* The last epoch, for the summaries. */
  est_epoch last;
  last.t_s = epoch_time(&ctx, nt - 1);
  st = eval_epochs(&ctx, &last, 1, es.tbuf, es.abuf);
  if (st != NAV_OK) goto cleanup;
  const nav_analytic_estimate_point *al = &last.ana;
  const char *js = nav_resultdir_file(rd, "summary.json");
  f = js ? fopen(js, "w") : NULL;
  if (!f) goto cleanup;
  fprintf(f, "{\n  \"navsim_version\": \"%s\",\n  \"scene\": {\"name\": \"%s\", \"file\": \"%s\"},\n", nav_version_string(),
          sc.name, scene_path);
  fprintf(
      f,
      "  \"duration_s\": %.17g,\n  \"timing\": {\"analytic_wall_s\": %.6g, \"covariance_wall_s\": %.6g},\n",
      last.t_s, t_analytic, t_cov);
  fprintf(f, "  \"analytic_final\": {\"pos_sd_m\": %.17g, \"vel_sd_mps\": %.17g, \"att_sd_rad\": %.17g, \"valid\": %s}",
          al->gyro_ins.pos_sd_m, al->gyro_ins.vel_sd_mps, al->gyro_ins.att_sd_rad,
          al->gyro_ins_short_time_ok ? "true" : "false");
  if (acfg.with_gyrofree)
    fprintf(f,
            ",\n  \"gyrofree_final\": {\"pos_sd_m\": %.17g, \"vel_sd_mps\": %.17g, \"att_sd_rad\": %.17g, "
            "\"small_angle_ok\": %s, \"paper_formula_pos_m\": %.17g}",
            al->gyrofree.pos_sd_m, al->gyrofree.vel_sd_mps, al->gyrofree.att_sd_rad,
            al->gyrofree_small_angle_ok ? "true" : "false", al->gyrofree_paper_pos_m);
  if (have_cov) {
    const nav_cov_point *p = &es.cov_last;
    fprintf(
        f,
        ",\n  \"covariance_final\": {\"pos_h_sd_m\": %.17g, \"pos_d_sd_m\": %.17g, \"vel_n_sd_mps\": %.17g, "
        "\"att_d_sd_rad\": %.17g},\n  \"covariance_max\": {\"pos_h_sd_m\": %.17g}",
        p->pos_h_sd_m, p->pos_sd_n_m.z, p->vel_sd_n_mps.x, p->att_sd_rad.z, es.hmax);
  }
  fputs("\n}\n", f);
  if (fclose(f) != 0) {
    f = NULL;
    goto cleanup;
  }
  f = NULL;
  if (write_estimate_json(nav_resultdir_file(rd, "estimate.json"), &sc, scene_path, &last.tab, al,
                          last.pos_v_m, last.t_s < ctx.t_v_max_s, have_cov ? &es.cov_last : NULL, pred,
                          sc.n_requirements) != 0) {
    fprintf(stderr, "navsim estimate: writing estimate.json failed\n");
    goto cleanup;
  }
  rc = navsim_out_commit("estimate", rd);
  rd = NULL;
  if (rc != 0) goto cleanup;
  rc = 1;
  if (!quiet) {
    printf("scene      %s (%s)\n", sc.name, scene_path);
    printf("%10s | %-38s | %s\n", "t [s]", "analytic free INS, per axis (1 sigma)",
           have_cov ? "covariance analysis of the scheme (1 sigma)" : "covariance analysis: wgs84 scenes only");
    printf("%10s | %11s %11s %11s  | %11s %11s %11s\n", "", "pos [m]", "vel [m/s]", "att [deg]", "pos h [m]",
           "pos d [m]", "yaw [deg]");
    for (size_t s = 0; s < N_SHOW; ++s) {
      const size_t i = es.show_i[s] < nt ? es.show_i[s] : nt - 1;
      est_epoch e;
      e.t_s = epoch_time(&ctx, i);
      if (s > 0 && e.t_s < k_show_s[s - 1]) continue;
      if (eval_epochs(&ctx, &e, 1, es.tbuf, es.abuf) != NAV_OK) goto cleanup;
      printf("%10.1f | %11.4g %11.4g %11.4g%s |", e.t_s, e.ana.gyro_ins.pos_sd_m, e.ana.gyro_ins.vel_sd_mps,
             e.ana.gyro_ins.att_sd_rad * NAV_RAD2DEG, e.ana.gyro_ins_short_time_ok ? " " : "*");
      if (have_cov) {
        const nav_cov_point *p = es.show_i[s] < nt ? &es.show_cov[s] : &es.cov_last;
        printf(" %11.4g %11.4g %11.4g", p->pos_h_sd_m, p->pos_sd_n_m.z, p->att_sd_rad.z * NAV_RAD2DEG);
      }
      printf("\n");
      if (i == nt - 1) break;
    }
    printf("(* beyond the closed forms' validity: Schuler feedback or large angles)\n");
    if (acfg.with_gyrofree) {
      printf("gyro-free  %s array, per axis (E1.25-E1.28, corrected 1/252):\n", nav_array_layout_kind_name(sc.array.layout));
      for (size_t i = 0; i < nt; i += (nt > 10 ? nt / 10 : 1)) {
        est_epoch e;
        e.t_s = epoch_time(&ctx, i);
        if (eval_epochs(&ctx, &e, 1, es.tbuf, es.abuf) != NAV_OK) goto cleanup;
        printf("%10.1f | pos %11.4g m  vel %11.4g m/s  att %11.4g deg%s  (paper's formula: %.4g m)\n", e.t_s,
               e.ana.gyrofree.pos_sd_m, e.ana.gyrofree.vel_sd_mps, e.ana.gyrofree.att_sd_rad * NAV_RAD2DEG,
               e.ana.gyrofree_small_angle_ok ? " " : "*", e.ana.gyrofree_paper_pos_m);
      }
    }
    const nav_analytic_gyro_ins_table *tf = &last.tab;
    printf("final      t = %g s: horizontal %.4g m (sqrt(2) x per axis), vertical %.4g m%s\n", last.t_s,
           sqrt(2.0) * al->gyro_ins.pos_sd_m, last.pos_v_m,
           last.t_s < ctx.t_v_max_s ? "" : " (beyond its validity)");
    /* The three largest rows of the final per-axis position (they add in squares). */
    int top[3] = {-1, -1, -1};
    for (int q = 0; q < NAV_ANALYTIC_TERM_COUNT; ++q) {
      const double v = tf->term[q].pos_m;
      if (!(v > 0.0)) continue;
      for (int r = 0; r < 3; ++r)
        if (top[r] < 0 || v > tf->term[top[r]].pos_m) {
          for (int u = 2; u > r; --u) top[u] = top[u - 1];
          top[r] = q;
          break;
        }
    }
    if (top[0] >= 0) {
      printf("largest    per axis:");
      for (int r = 0; r < 3 && top[r] >= 0; ++r)
        printf("%s %s %.4g m", r ? "," : "", nav_analytic_term_name((nav_analytic_term_id)top[r]),
               tf->term[top[r]].pos_m);
      printf(" (of %.4g m, root-sum-square)\n", tf->rss.pos_m);
    }
    if (pred) {
      printf("predicted  from the covariance analysis (expected Monte Carlo values; see estimate.json):\n");
      nav_requirements_print(stdout, pred, sc.n_requirements);
    }
    printf("computed   analytic %.3g s, covariance %.3g s\n", t_analytic, t_cov);
    printf("results    %s/\n", out_dir);
  }
  rc = 0;
cleanup:
  if (job_running) pthread_join(job_thread, NULL);
  free(job.out);
  if (f) fclose(f);
  nav_resultdir_abort(rd);
  nav_sim_destroy(sim);
  free(pred);
  free(es.batch);
  free(es.cov);
  free(es.tbuf);
  free(es.abuf);
  nav_scene_release(&sc);
  free(es.pts);
  return rc;
}
