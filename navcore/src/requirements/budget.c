/*
 * Error budget by covariance analysis, one source at a time with the gains of the full model
 * (nav_budget.h). The loop follows nav_sim_covariance (covariance.c): reference trajectory,
 * nav_filter_predict at every IMU step, GNSS position and velocity updates at the receiver's
 * epochs outside the outages, R as the simulation uses it. The updates are done here with the
 * documented H (nav_filter.h) and one K for every filter, then written back with
 * nav_filter_set_cov.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_budget.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_filter.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_truth.h"
#include "requirements/budget_internal.h"
#include "sim/consider_internal.h"
#include "sim/sim_internal.h"

#define NMAX NAV_FILTER_MAX_STATES

static const char *const k_names[NAV_BUDGET_SOURCE_COUNT] = {
    "gyro_arw",         "gyro_bias_instability", "gyro_rate_random_walk", "gyro_turn_on_bias",
    "accel_vrw",        "accel_bias_instability", "accel_random_walk",    "accel_turn_on_bias",
    "initial_position", "initial_velocity",       "initial_attitude",     "gnss_position_noise",
    "gnss_position_correlated", "gnss_velocity_noise", "filter_floors", "gyro_scale_factor",
    "accel_scale_factor"};

const char *nav_budget_source_name(nav_budget_source s) {
  return (int)s >= 0 && (int)s < NAV_BUDGET_SOURCE_COUNT ? k_names[s] : "unknown";
}

double nav_budget_mean_square(nav_req_metric m, const nav_budget_diag *d) {
  const double *v = d->v;
  switch (m) {
  case NAV_REQ_HORIZONTAL_POSITION: return v[0] + v[1];
  case NAV_REQ_VERTICAL_POSITION: return v[2];
  case NAV_REQ_POSITION_3D: return v[0] + v[1] + v[2];
  case NAV_REQ_VELOCITY: return v[3] + v[4] + v[5];
  case NAV_REQ_ROLL_PITCH: return v[6] + v[7];
  case NAV_REQ_YAW: return v[8];
  }
  return NAN;
}

unsigned nav_budget_unmodelled_terms(const nav_scene *scene) {
  const unsigned modelled = NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_RW |
                            NAV_IMU_TERM_NOISE | NAV_IMU_TERM_SCALE_FACTOR | NAV_IMU_TERM_SATURATION;
  return (scene->imu.model.gyro.terms & ~modelled) | ((scene->imu.model.accel.terms & ~modelled) << 16);
}

/* ---------------------------------------------------------------- per-source inputs */

typedef struct src_input {
  double p0[NMAX]; /* diagonal of P0 */
  nav_filter_config cfg;
  nav_vec3 r_pos, r_vel; /* R diagonal shares (computed per update from the fractions below) */
} src_input;

static double vmax3(nav_vec3 v) { return fmax(fmax(v.x, v.y), v.z); }

static void set3(double *p0, size_t at, nav_vec3 v2) {
  p0[at] = v2.x;
  p0[at + 1] = v2.y;
  p0[at + 2] = v2.z;
}

static nav_vec3 sq3(nav_vec3 v) { return nav_vec3_make(v.x * v.x, v.y * v.y, v.z * v.z); }

/* A noise parameter whose variance (and so its q) is doubled: the full model plus this source. */
static nav_vec3 twice(nav_vec3 v) { return nav_vec3_scale(v, sqrt(2.0)); }

/* R diagonal of the position and velocity updates, split by source (as covariance.c). */
typedef struct r_split {
  nav_vec3 pos[NAV_BUDGET_SOURCE_COUNT], vel[NAV_BUDGET_SOURCE_COUNT];
  nav_vec3 pos_total, vel_total;
} r_split;

static r_split split_r(const nav_gnss_model_config *g, const nav_ins_gnss_config *xc, bool gm_states) {
  r_split r;
  memset(&r, 0, sizeof r);
  for (int i = 0; i < 3; ++i) {
    const double gm = (g->terms & NAV_GNSS_TERM_POS_GM) ? nav_vec3_get(g->pos_gm_sd_m, i) : 0.0;
    const double wh = (g->terms & NAV_GNSS_TERM_POS_WHITE) ? nav_vec3_get(g->pos_white_sd_m, i) : 0.0;
    const double vv = (g->terms & NAV_GNSS_TERM_VEL_WHITE) ? nav_vec3_get(g->vel_sd_mps, i) : 0.0;
    double sp = g->report_model_sigmas ? (gm_states ? wh : hypot(gm, wh)) : nav_vec3_get(g->reported_pos_sd_m, i);
    double sv = g->report_model_sigmas ? vv : nav_vec3_get(g->reported_vel_sd_mps, i);
    sp = fmax(sp, xc->pos_sd_floor_m);
    sv = fmax(sv, xc->vel_sd_floor_mps);
    const double rp = sp * sp, rv = sv * sv;
    /* Shares of the model's parts (reported sigmas are split in the model's proportions). */
    const double mw = wh * wh, mg = gm_states ? 0.0 : gm * gm;
    double pw, pg;
    if (g->report_model_sigmas) {
      pw = mw;
      pg = mg;
    } else if (mw + mg > 0.0) {
      pw = rp * mw / (mw + mg);
      pg = rp * mg / (mw + mg);
    } else {
      pw = rp;
      pg = 0.0;
    }
    nav_vec3_set(&r.pos[NAV_BUDGET_GNSS_POS_NOISE], i, pw);
    nav_vec3_set(&r.pos[NAV_BUDGET_GNSS_POS_CORRELATED], i, pg);
    nav_vec3_set(&r.pos[NAV_BUDGET_FLOORS], i, rp - pw - pg);
    const double vw = g->report_model_sigmas ? vv * vv : rv;
    nav_vec3_set(&r.vel[NAV_BUDGET_GNSS_VEL_NOISE], i, vw);
    nav_vec3_set(&r.vel[NAV_BUDGET_FLOORS], i, rv - vw);
    nav_vec3_set(&r.pos_total, i, rp);
    nav_vec3_set(&r.vel_total, i, rv);
  }
  return r;
}

/* Scale-factor variance of the truth per axis (sd^2 + fixed^2), gyro (a = false) or accel. */
static nav_vec3 sf_var(const nav_scene *sc, bool accel) { return nav_consider_sf_var(sc, accel); }

/* P0 diagonal and process noise of source s; false when the source is absent. */
static bool source_input(const nav_scene *sc, const nav_filter_config *c, const nav_filter_layout *lay, int s,
                         const r_split *rs, src_input *in) {
  memset(in->p0, 0, sizeof in->p0);
  in->cfg = *c;
  const nav_gyro_error_config *g = &sc->imu.model.gyro;
  const nav_accel_error_config *a = &sc->imu.model.accel;
  const bool g_to = (g->terms & NAV_IMU_TERM_BIAS_TURN_ON) != 0, a_to = (a->terms & NAV_IMU_TERM_BIAS_TURN_ON) != 0;
  const bool g_gm = (g->terms & NAV_IMU_TERM_BIAS_GM) != 0, a_gm = (a->terms & NAV_IMU_TERM_BIAS_GM) != 0;
  const nav_vec3 g_to2 = g_to ? nav_vec3_add(sq3(g->bias_turn_on_sd_rps), sq3(g->bias_turn_on_fixed_rps)) : nav_vec3_zero();
  const nav_vec3 a_to2 =
      a_to ? nav_vec3_add(sq3(a->bias_turn_on_sd_mps2), sq3(a->bias_turn_on_fixed_mps2)) : nav_vec3_zero();
  const nav_vec3 g_gm2 = g_gm ? sq3(g->bias_gm_sd_rps) : nav_vec3_zero();
  const nav_vec3 a_gm2 = a_gm ? sq3(a->bias_gm_sd_mps2) : nav_vec3_zero();
  bool any = false;
  switch ((nav_budget_source)s) {
  case NAV_BUDGET_GYRO_ARW:
    in->cfg.gyro_arw_rad_per_sqrt_s = twice(c->gyro_arw_rad_per_sqrt_s);
    any = vmax3(c->gyro_arw_rad_per_sqrt_s) > 0.0;
    break;
  case NAV_BUDGET_GYRO_BIAS_INSTABILITY:
    in->cfg.gyro_bias_gm_sd_rps = twice(c->gyro_bias_gm_sd_rps);
    set3(in->p0, NAV_FILTER_IDX_BG, g_gm2);
    any = (c->gyro_bias_terms & NAV_FILTER_PROC_GM) && vmax3(c->gyro_bias_gm_sd_rps) > 0.0;
    break;
  case NAV_BUDGET_GYRO_RATE_RW:
    in->cfg.gyro_bias_rw_rps_per_sqrt_s = twice(c->gyro_bias_rw_rps_per_sqrt_s);
    any = (c->gyro_bias_terms & NAV_FILTER_PROC_RW) && vmax3(c->gyro_bias_rw_rps_per_sqrt_s) > 0.0;
    break;
  case NAV_BUDGET_GYRO_TURN_ON_BIAS:
    set3(in->p0, NAV_FILTER_IDX_BG, g_to2);
    any = vmax3(g_to2) > 0.0;
    break;
  case NAV_BUDGET_ACCEL_VRW:
    in->cfg.accel_vrw_mps_per_sqrt_s = twice(c->accel_vrw_mps_per_sqrt_s);
    any = vmax3(c->accel_vrw_mps_per_sqrt_s) > 0.0;
    break;
  case NAV_BUDGET_ACCEL_BIAS_INSTABILITY:
    in->cfg.accel_bias_gm_sd_mps2 = twice(c->accel_bias_gm_sd_mps2);
    set3(in->p0, NAV_FILTER_IDX_BA, a_gm2);
    any = (c->accel_bias_terms & NAV_FILTER_PROC_GM) && vmax3(c->accel_bias_gm_sd_mps2) > 0.0;
    break;
  case NAV_BUDGET_ACCEL_RW:
    in->cfg.accel_bias_rw_mps2_per_sqrt_s = twice(c->accel_bias_rw_mps2_per_sqrt_s);
    any = (c->accel_bias_terms & NAV_FILTER_PROC_RW) && vmax3(c->accel_bias_rw_mps2_per_sqrt_s) > 0.0;
    break;
  case NAV_BUDGET_ACCEL_TURN_ON_BIAS:
    set3(in->p0, NAV_FILTER_IDX_BA, a_to2);
    any = vmax3(a_to2) > 0.0;
    break;
  case NAV_BUDGET_INITIAL_POSITION:
    set3(in->p0, NAV_FILTER_IDX_DR, sq3(c->init.pos_sd_m));
    any = true;
    break;
  case NAV_BUDGET_INITIAL_VELOCITY:
    set3(in->p0, NAV_FILTER_IDX_DV, sq3(c->init.vel_sd_mps));
    any = true;
    break;
  case NAV_BUDGET_INITIAL_ATTITUDE:
    set3(in->p0, NAV_FILTER_IDX_PHI, sq3(c->init.att_sd_rad));
    any = true;
    break;
  case NAV_BUDGET_GNSS_POS_NOISE:
  case NAV_BUDGET_GNSS_VEL_NOISE:
    any = vmax3(rs->pos[s]) > 0.0 || vmax3(rs->vel[s]) > 0.0;
    break;
  case NAV_BUDGET_GNSS_POS_CORRELATED:
    if (lay->has_gnss_pos_gm) {
      in->cfg.gnss_pos_gm_sd_m = twice(c->gnss_pos_gm_sd_m);
      set3(in->p0, lay->idx_gnss_pos, sq3(c->init.gnss_pos_sd_m));
      any = true;
    }
    any = any || vmax3(rs->pos[s]) > 0.0;
    break;
  case NAV_BUDGET_FLOORS: {
    /* What the floors add to the bias and scale-factor P0 and to R (not scene inputs). */
    const nav_vec3 bg = nav_vec3_sub(nav_vec3_sub(sq3(c->init.gyro_bias_sd_rps), g_to2), g_gm2);
    const nav_vec3 ba = nav_vec3_sub(nav_vec3_sub(sq3(c->init.accel_bias_sd_mps2), a_to2), a_gm2);
    set3(in->p0, NAV_FILTER_IDX_BG, bg);
    set3(in->p0, NAV_FILTER_IDX_BA, ba);
    if (lay->has_scale_factors) {
      set3(in->p0, NAV_FILTER_IDX_SG, nav_vec3_sub(sq3(c->init.gyro_sf_sd), sf_var(sc, false)));
      set3(in->p0, NAV_FILTER_IDX_SA, nav_vec3_sub(sq3(c->init.accel_sf_sd), sf_var(sc, true)));
    }
    any = true;
    break;
  }
  case NAV_BUDGET_GYRO_SCALE_FACTOR:
  case NAV_BUDGET_ACCEL_SCALE_FACTOR: {
    const bool acc = s == NAV_BUDGET_ACCEL_SCALE_FACTOR;
    if (lay->has_scale_factors) {
      set3(in->p0, acc ? NAV_FILTER_IDX_SA : NAV_FILTER_IDX_SG, sf_var(sc, acc));
      if (acc) {
        in->cfg.accel_sf_gm_sd = twice(c->accel_sf_gm_sd);
        in->cfg.accel_sf_rw_per_sqrt_s = twice(c->accel_sf_rw_per_sqrt_s);
      } else {
        in->cfg.gyro_sf_gm_sd = twice(c->gyro_sf_gm_sd);
        in->cfg.gyro_sf_rw_per_sqrt_s = twice(c->gyro_sf_rw_per_sqrt_s);
      }
      any = vmax3(sf_var(sc, acc)) > 0.0 || (acc ? vmax3(c->accel_sf_gm_sd) + vmax3(c->accel_sf_rw_per_sqrt_s)
                                                 : vmax3(c->gyro_sf_gm_sd) + vmax3(c->gyro_sf_rw_per_sqrt_s)) > 0.0;
    }
    break;
  }
  }
  return any;
}

/* ---------------------------------------------------------------- fixed-gain updates */

/* H (3 x n, row-major) of the GNSS position (vel = false) or velocity update (nav_filter.h). */
static void build_h(bool vel, const nav_filter_layout *lay, const nav_filter_nav *nv, nav_vec3 l, double *H) {
  const size_t n = lay->n_states;
  memset(H, 0, 3 * n * sizeof *H);
  const nav_mat3 C = nv->C_b_n;
  const nav_vec3 cl = nav_mat3_mul_vec(C, l);
  if (!vel) {
    const nav_mat3 S = nav_mat3_skew(cl);
    for (int i = 0; i < 3; ++i) {
      H[(size_t)i * n + NAV_FILTER_IDX_DR + (size_t)i] = 1.0;
      for (int j = 0; j < 3; ++j) H[(size_t)i * n + NAV_FILTER_IDX_PHI + (size_t)j] = S.m[i][j];
      if (lay->has_gnss_pos_gm) H[(size_t)i * n + lay->idx_gnss_pos + (size_t)i] = -1.0;
    }
    return;
  }
  const nav_vec3 w = nv->w_ib_b_rps;
  const nav_vec3 wie = nav_vec3_make(NAV_WGS84_OMEGA_IE_RPS * cos(nv->lat_rad), 0.0,
                                     -NAV_WGS84_OMEGA_IE_RPS * sin(nv->lat_rad));
  const nav_mat3 Sa = nav_mat3_skew(nav_mat3_mul_vec(C, nav_vec3_cross(w, l)));
  const nav_mat3 Sb = nav_mat3_mul(nav_mat3_skew(wie), nav_mat3_skew(cl));
  const nav_mat3 Cl = nav_mat3_mul(C, nav_mat3_skew(l));
  for (int i = 0; i < 3; ++i) {
    H[(size_t)i * n + NAV_FILTER_IDX_DV + (size_t)i] = 1.0;
    for (int j = 0; j < 3; ++j) {
      H[(size_t)i * n + NAV_FILTER_IDX_PHI + (size_t)j] = Sa.m[i][j] - Sb.m[i][j];
      H[(size_t)i * n + NAV_FILTER_IDX_BG + (size_t)j] = -Cl.m[i][j];
      if (lay->has_scale_factors) H[(size_t)i * n + NAV_FILTER_IDX_SG + (size_t)j] = -Cl.m[i][j] * nav_vec3_get(w, j);
    }
  }
}

/* K = P H^T S^-1 with S = H P H^T + R (3 x 3, Cholesky); false when S is not positive definite. */
static bool gain(size_t n, const double *P, const double *H, nav_vec3 r, double *K) {
  double PHt[NMAX * 3], S[9];
  for (size_t i = 0; i < n; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += P[i * n + k] * H[(size_t)j * n + k];
      PHt[i * 3 + (size_t)j] = s;
    }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += H[(size_t)i * n + k] * PHt[k * 3 + (size_t)j];
      S[i * 3 + j] = s + (i == j ? nav_vec3_get(r, i) : 0.0);
    }
  /* Cholesky S = L L^T */
  double L[9] = {0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) {
      double s = S[i * 3 + j];
      for (int k = 0; k < j; ++k) s -= L[i * 3 + k] * L[j * 3 + k];
      if (i == j) {
        if (!(s > 0.0)) return false;
        L[i * 3 + i] = sqrt(s);
      } else {
        L[i * 3 + j] = s / L[j * 3 + j];
      }
    }
  /* K rows: solve S k^T = (P H^T)_row^T, i.e. L L^T x = b for each row b of PHt */
  for (size_t i = 0; i < n; ++i) {
    double y[3], x[3];
    for (int a = 0; a < 3; ++a) {
      double s = PHt[i * 3 + (size_t)a];
      for (int k = 0; k < a; ++k) s -= L[a * 3 + k] * y[k];
      y[a] = s / L[a * 3 + a];
    }
    for (int a = 2; a >= 0; --a) {
      double s = y[a];
      for (int k = a + 1; k < 3; ++k) s -= L[k * 3 + a] * x[k];
      x[a] = s / L[a * 3 + a];
    }
    for (int a = 0; a < 3; ++a) K[i * 3 + (size_t)a] = x[a];
  }
  return true;
}

/* P <- A P A^T + K R K^T with A = I - K H; symmetrised. */
static void joseph(size_t n, double *P, const double *K, const double *H, nav_vec3 r, double *A, double *T) {
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double s = (i == j) ? 1.0 : 0.0;
      for (int k = 0; k < 3; ++k) s -= K[i * 3 + (size_t)k] * H[(size_t)k * n + j];
      A[i * n + j] = s;
    }
  for (size_t i = 0; i < n; ++i) /* T = A P */
    for (size_t j = 0; j < n; ++j) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += A[i * n + k] * P[k * n + j];
      T[i * n + j] = s;
    }
  for (size_t i = 0; i < n; ++i) /* P = T A^T + K R K^T */
    for (size_t j = 0; j < n; ++j) {
      double s = 0.0;
      for (size_t k = 0; k < n; ++k) s += T[i * n + k] * A[j * n + k];
      for (int k = 0; k < 3; ++k) s += K[i * 3 + (size_t)k] * nav_vec3_get(r, k) * K[j * 3 + (size_t)k];
      P[i * n + j] = s;
    }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const double m = 0.5 * (P[i * n + j] + P[j * n + i]);
      P[i * n + j] = m;
      P[j * n + i] = m;
    }
}

/* ---------------------------------------------------------------- the analysis */

typedef struct budget_run {
  int nf;                                /* filters: 0 the full model, 1.. full model + one source */
  nav_filter *kf[NAV_BUDGET_SOURCE_COUNT + 1];
  int src[NAV_BUDGET_SOURCE_COUNT + 1];  /* source of filter f (-1: the full model) */
} budget_run;

static bool in_outage(const nav_gnss_model_config *g, double t) {
  for (size_t i = 0; i < g->outage_count; ++i)
    if (t >= g->outages[i].t0_s && t < g->outages[i].t1_s) return true;
  return false;
}

static void diag_of(const nav_filter *kf, size_t n, nav_budget_diag *d) {
  const double *P = nav_filter_get_cov(kf);
  for (size_t i = 0; i < 9; ++i) d->v[i] = P[i * n + i];
}

static nav_status emit(budget_run *b, size_t n, double t, nav_budget_fn fn, void *user) {
  nav_budget_epoch e;
  memset(&e, 0, sizeof e);
  e.t_s = t;
  for (int f = 0; f < b->nf; ++f) {
    const nav_status st = nav_filter_flush(b->kf[f]);
    if (st != NAV_OK) return st;
  }
  diag_of(b->kf[0], n, &e.total);
  for (int f = 1; f < b->nf; ++f) {
    nav_budget_diag d;
    diag_of(b->kf[f], n, &d);
    for (int i = 0; i < 9; ++i) e.source[b->src[f]].v[i] = d.v[i] - e.total.v[i];
  }
  return fn(user, &e) == NAV_STOP ? NAV_ERR_CANCELLED : NAV_OK;
}

/* P0 of the full model plus the source's diagonal. */
static nav_status set_p0(nav_filter *kf, size_t n, const double *p0_total, const double *p0_s, double *tmp) {
  memcpy(tmp, p0_total, n * n * sizeof *tmp);
  for (size_t i = 0; i < n; ++i) tmp[i * n + i] += p0_s[i];
  return nav_filter_set_cov(kf, tmp);
}

nav_status nav_budget_run(const nav_scene *sc, bool sources, nav_budget_fn fn, void *user, unsigned *active,
                          char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (active) *active = 0;
  if (!sc || !fn) return NAV_ERR_INVALID_ARG;
  if (sc->earth.model != NAV_EARTH_WGS84 || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE ||
      sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS || sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
    if (msg) snprintf(msg, msg_size, "the covariance budget needs the wgs84 Earth and the free_ins or ins_gnss scheme");
    return NAV_ERR_INVALID_ARG;
  }
  nav_truth *truth = NULL;
  budget_run b;
  memset(&b, 0, sizeof b);
  double *A = NULL, *T = NULL, *P = NULL, *P0 = NULL;
  char m2[200];
  nav_status st = nav_truth_create_msg(sc, &truth, m2, sizeof m2);
  if (st != NAV_OK) {
    if (msg) snprintf(msg, msg_size, "reference trajectory: %s", m2[0] ? m2 : nav_status_str(st));
    return st;
  }
  const bool gnss = sc->navigation.scheme == NAV_SCHEME_INS_GNSS;
  const nav_ins_gnss_config xc = nav_ins_gnss_config_from_scene(sc);
  const nav_filter_config cr = xc.filter; /* the navigation filter: its gains */
  /* Scale factors of the truth that the filter does not estimate: consider states. */
  nav_filter_config c;
  const bool consider = nav_consider_config(sc, &cr, &c);
  nav_filter *kref = NULL; /* consider mode: the navigation filter itself, for the gains */
  nav_gnss_model_config gcfg;
  st = nav_sim_gnss_config(sc, 1.0 / sc->imu.rate_hz, &gcfg, m2, sizeof m2);
  if (st != NAV_OK) {
    if (msg) snprintf(msg, msg_size, "GNSS outages: %s", m2);
    goto cleanup;
  }
  /* Total filter: the full model, as nav_sim_covariance (plus the consider states). */
  st = nav_filter_create(&c, &b.kf[0]);
  if (st == NAV_OK && consider) st = nav_filter_create(&cr, &kref);
  if (st != NAV_OK) {
    if (msg) snprintf(msg, msg_size, "filter set-up failed");
    goto cleanup;
  }
  const nav_filter_layout lay = nav_filter_get_layout(b.kf[0]);
  const nav_filter_layout lay_r = consider ? nav_filter_get_layout(kref) : lay;
  const size_t n = lay.n_states, n_r = lay_r.n_states;
  /* Row of the budget state vector for each state of the navigation filter. */
  size_t row_of[NMAX];
  for (size_t i = 0; i < n_r; ++i)
    row_of[i] = (lay_r.has_gnss_pos_gm && i >= lay_r.idx_gnss_pos) ? lay.idx_gnss_pos + (i - lay_r.idx_gnss_pos) : i;
  A = malloc(n * n * sizeof *A);
  T = malloc(n * n * sizeof *T);
  P = malloc(n * n * sizeof *P);
  if (!A || !T || !P) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  const bool gm_states = lay.has_gnss_pos_gm;
  const r_split rs = split_r(&gcfg, &xc, gm_states);
  P0 = malloc(n * n * sizeof *P0);
  if (!P0) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  memcpy(P0, nav_filter_get_cov(b.kf[0]), n * n * sizeof *P0);
  b.src[0] = -1;
  b.nf = 1;
  for (int s = 0; s < NAV_BUDGET_SOURCE_COUNT && st == NAV_OK && sources; ++s) {
    src_input in;
    if (!source_input(sc, &c, &lay, s, &rs, &in)) continue;
    if (!gnss && (s == NAV_BUDGET_GNSS_POS_NOISE || s == NAV_BUDGET_GNSS_POS_CORRELATED ||
                  s == NAV_BUDGET_GNSS_VEL_NOISE))
      continue;
    if (active) *active |= 1u << s;
    st = nav_filter_create(&in.cfg, &b.kf[b.nf]);
    if (st == NAV_OK) st = set_p0(b.kf[b.nf], n, P0, in.p0, P);
    b.src[b.nf] = s;
    if (st == NAV_OK) ++b.nf;
  }
  if (st != NAV_OK) {
    if (msg) snprintf(msg, msg_size, "per-source filter set-up failed: %s", nav_status_str(st));
    goto cleanup;
  }

  const nav_frame fr = nav_truth_frame(truth);
  const int64_t nsamp = nav_truth_sample_count(truth);
  const double dt = nav_truth_dt(truth);
  int64_t out_stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  if (out_stride < 1) out_stride = 1;
  int64_t next_epoch = 0;
  st = emit(&b, n, 0.0, fn, user);
  double H[3 * NMAX], Hr[3 * NMAX], K[NMAX * 3], Kr[NMAX * 3];
  for (int64_t k = 1; k <= nsamp && st == NAV_OK; ++k) {
    nav_imu_increment imu;
    nav_traj_state ts;
    st = nav_truth_imu(truth, k, &imu);
    if (st == NAV_OK) st = nav_truth_state(truth, imu.t_s, &ts);
    if (st != NAV_OK) break;
    const nav_local_view v = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
    const nav_filter_nav nv = {v.pos.lat_rad,
                               v.pos.h_m,
                               v.v_n_mps,
                               nav_quat_to_dcm(v.q_b_n),
                               nav_vec3_scale(imu.dv_b_mps, 1.0 / imu.dt_s),
                               nav_vec3_scale(imu.dtheta_b_rad, 1.0 / imu.dt_s)};
    if (kref) {
      st = nav_filter_predict(kref, &nv, imu.dt_s);
      if (st != NAV_OK && msg) snprintf(msg, msg_size, "navigation filter: %s", nav_filter_last_error(kref));
    }
    for (int f = 0; f < b.nf && st == NAV_OK; ++f) {
      st = nav_filter_predict(b.kf[f], &nv, imu.dt_s);
      if (st != NAV_OK && msg)
        snprintf(msg, msg_size, "%s filter: %s", f == 0 ? "full-model" : k_names[b.src[f]],
                 nav_filter_last_error(b.kf[f]));
    }
    while (gnss && st == NAV_OK) {
      const double t_fix = (double)next_epoch / gcfg.update_rate_hz;
      if (!(t_fix <= imu.t_s + 0.5 * dt)) break;
      ++next_epoch;
      if (t_fix < imu.t_s - 0.5 * dt || in_outage(&gcfg, t_fix)) continue;
      for (int u = 0; u < 2 && st == NAV_OK; ++u) {
        const bool vel = u == 1;
        build_h(vel, &lay, &nv, gcfg.r_ba_b_m, H);
        build_h(vel, &lay_r, &nv, gcfg.r_ba_b_m, Hr);
        for (int f = 0; f < b.nf && st == NAV_OK; ++f) st = nav_filter_flush(b.kf[f]);
        if (st == NAV_OK && kref) st = nav_filter_flush(kref);
        if (st != NAV_OK) break;
        /* The gains of the navigation filter (its own P), mapped into the budget state. */
        const nav_vec3 rtot = vel ? rs.vel_total : rs.pos_total;
        memcpy(P, nav_filter_get_cov(kref ? kref : b.kf[0]), n_r * n_r * sizeof *P);
        if (!gain(n_r, P, Hr, rtot, Kr)) {
          st = NAV_ERR_NUMERIC;
          if (msg) snprintf(msg, msg_size, "innovation covariance not positive definite at t = %.6f s", t_fix);
          break;
        }
        if (kref) {
          joseph(n_r, P, Kr, Hr, rtot, A, T);
          st = nav_filter_set_cov(kref, P);
          if (st != NAV_OK) {
            if (msg) snprintf(msg, msg_size, "navigation filter after the update at t = %.6f s: %s", t_fix,
                              nav_filter_last_error(kref));
            break;
          }
        }
        memset(K, 0, n * 3 * sizeof *K);
        for (size_t i = 0; i < n_r; ++i)
          for (int j = 0; j < 3; ++j) K[row_of[i] * 3 + (size_t)j] = Kr[i * 3 + (size_t)j];
        for (int f = 0; f < b.nf && st == NAV_OK; ++f) {
          nav_vec3 r;
          r = vel ? rs.vel_total : rs.pos_total;
          if (f > 0) r = nav_vec3_add(r, vel ? rs.vel[b.src[f]] : rs.pos[b.src[f]]);
          memcpy(P, nav_filter_get_cov(b.kf[f]), n * n * sizeof *P);
          joseph(n, P, K, H, r, A, T);
          st = nav_filter_set_cov(b.kf[f], P);
          if (st != NAV_OK && msg)
            snprintf(msg, msg_size, "%s covariance after the update at t = %.6f s: %s",
                     f == 0 ? "full-model" : k_names[b.src[f]], t_fix,
                     nav_filter_last_error(b.kf[f]));
        }
      }
    }
    if (st == NAV_OK && (k % out_stride == 0 || k == nsamp)) st = emit(&b, n, imu.t_s, fn, user);
  }
cleanup:
  for (int f = 0; f < NAV_BUDGET_SOURCE_COUNT + 1; ++f) nav_filter_destroy(b.kf[f]);
  nav_filter_destroy(kref);
  free(P0);
  free(A);
  free(T);
  free(P);
  nav_truth_destroy(truth);
  return st;
}

nav_status nav_budget_covariance(const nav_scene *sc, nav_budget_fn fn, void *user, unsigned *active, char *msg,
                                 size_t msg_size) {
  return nav_budget_run(sc, true, fn, user, active, msg, msg_size);
}

/* ---------------------------------------------------------------- per requirement */

typedef struct req_acc {
  const nav_requirement *reqs;
  int count;
  const nav_req_interval *outages;
  int n_out;
  nav_budget_result *out;
  long epochs;
  /* at_time: best distance per requirement; outage_end: per requirement and outage, the last
     epoch inside it */
  double best_d[NAV_SCENE_MAX_REQUIREMENTS];
  double o_total[NAV_SCENE_MAX_REQUIREMENTS][NAV_REQ_MAX_OUTAGES];
  double o_t[NAV_SCENE_MAX_REQUIREMENTS][NAV_REQ_MAX_OUTAGES];
  double o_src[NAV_SCENE_MAX_REQUIREMENTS][NAV_REQ_MAX_OUTAGES][NAV_BUDGET_SOURCE_COUNT];
} req_acc;

static nav_callback_result on_epoch(void *user, const nav_budget_epoch *e) {
  req_acc *a = user;
  a->epochs++;
  for (int i = 0; i < a->count; ++i) {
    const nav_requirement *q = &a->reqs[i];
    nav_budget_result *r = &a->out[i];
    if (q->statistic == NAV_REQ_AT_TIME) {
      const double d = fabs(e->t_s - q->time_s);
      if (d < a->best_d[i]) {
        a->best_d[i] = d;
        r->t_s = e->t_s;
        r->total_ms = nav_budget_mean_square(q->metric, &e->total);
        for (int s = 0; s < NAV_BUDGET_SOURCE_COUNT; ++s)
          r->source_ms[s] = nav_budget_mean_square(q->metric, &e->source[s]);
      }
    } else if (q->statistic == NAV_REQ_OUTAGE_END) {
      for (int o = 0; o < a->n_out; ++o)
        if (e->t_s >= a->outages[o].t0_s && e->t_s < a->outages[o].t1_s) {
          a->o_t[i][o] = e->t_s;
          a->o_total[i][o] = nav_budget_mean_square(q->metric, &e->total);
          for (int s = 0; s < NAV_BUDGET_SOURCE_COUNT; ++s)
            a->o_src[i][o][s] = nav_budget_mean_square(q->metric, &e->source[s]);
        }
    } else {
      r->total_ms += nav_budget_mean_square(q->metric, &e->total);
      for (int s = 0; s < NAV_BUDGET_SOURCE_COUNT; ++s)
        r->source_ms[s] += nav_budget_mean_square(q->metric, &e->source[s]);
    }
  }
  return NAV_CONTINUE;
}

nav_status nav_budget_requirements(const nav_scene *scene, const nav_requirement *reqs, int count,
                                   nav_budget_result *out, char *msg, size_t msg_size) {
  if (!scene || count < 0 || count > NAV_SCENE_MAX_REQUIREMENTS || (count > 0 && (!reqs || !out)))
    return NAV_ERR_INVALID_ARG;
  if (nav_requirements_validate(reqs, count, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  req_acc *a = calloc(1, sizeof *a);
  if (!a) return NAV_ERR_NO_MEMORY;
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  nav_status st = NAV_OK;
  if (scene->navigation.scheme == NAV_SCHEME_INS_GNSS || scene->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
      scene->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT)
    st = nav_req_scene_outages(scene, iv, NAV_REQ_MAX_OUTAGES, &ni);
  if (st != NAV_OK) {
    free(a);
    return st;
  }
  a->reqs = reqs;
  a->count = count;
  a->outages = iv;
  a->n_out = ni;
  a->out = out;
  for (int i = 0; i < count; ++i) {
    memset(&out[i], 0, sizeof out[i]);
    out[i].req = reqs[i];
    out[i].t_s = NAN;
    a->best_d[i] = INFINITY;
    for (int o = 0; o < NAV_REQ_MAX_OUTAGES; ++o) a->o_t[i][o] = NAN;
  }
  unsigned active = 0;
  st = nav_budget_covariance(scene, on_epoch, a, &active, msg, msg_size);
  if (st == NAV_OK) {
    for (int i = 0; i < count; ++i) {
      nav_budget_result *r = &out[i];
      r->active = active;
      if (reqs[i].statistic == NAV_REQ_OUTAGE_END) {
        int worst = -1;
        for (int o = 0; o < ni; ++o)
          if (!isnan(a->o_t[i][o]) && (worst < 0 || a->o_total[i][o] > a->o_total[i][worst])) worst = o;
        if (worst >= 0) {
          r->t_s = a->o_t[i][worst];
          r->total_ms = a->o_total[i][worst];
          for (int s = 0; s < NAV_BUDGET_SOURCE_COUNT; ++s) r->source_ms[s] = a->o_src[i][worst][s];
        } else {
          r->total_ms = NAN;
        }
      } else if (reqs[i].statistic != NAV_REQ_AT_TIME && a->epochs > 0) {
        r->total_ms /= (double)a->epochs;
        for (int s = 0; s < NAV_BUDGET_SOURCE_COUNT; ++s) r->source_ms[s] /= (double)a->epochs;
      }
    }
  }
  free(a);
  return st;
}
