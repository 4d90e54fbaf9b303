/*
 * GNSS receiver model (numerics.md section 7 "GNSS receiver models", 6.4). The model and its
 * stream layout are described in nav_sensors.h.
 */
#include "navcore/nav_sensors.h"

#include <assert.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_rng.h"

/* Channel offset of the white position noise inside NAV_RNG_STREAM_GNSS_POS (0-2 are the GM). */
#define GNSS_POS_WHITE_CHANNEL 3u

/* Largest accepted |truth->t_s - epoch time|: generous against rounding of t = j / rate computed
 * elsewhere (1e-15 relative at 1e7 s is 1e-8 s), small against any GNSS epoch spacing. */
#define GNSS_TIME_MATCH_S 1e-6

struct nav_gnss_model {
  nav_gnss_model_config cfg;
  nav_frame frame;
  double phi[3];   /* GM: exp(-dt_e / tau); 0 for tau = 0 */
  double drive[3]; /* GM: sigma sqrt(1 - phi^2) */
  double gm[3];    /* GM state at epoch `epoch` */
  int64_t epoch;   /* last epoch whose errors were drawn; -1 before the first */
  nav_rng rng_gm[3], rng_pw[3], rng_vel[3];
  nav_gnss_error_state err;
  char last_error[256];
};

nav_gnss_model_config nav_gnss_model_config_default(void) {
  nav_gnss_model_config c;
  memset(&c, 0, sizeof c);
  c.update_rate_hz = 1.0;
  c.report_model_sigmas = true;
  return c;
}

typedef struct checker {
  nav_scene_issue_fn report;
  void *user;
  int problems;
} checker;

static void issue(checker *ck, const char *path, const char *fmt, ...) {
  ck->problems++;
  if (!ck->report) return;
  char msg[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  ck->report(ck->user, path, msg);
}

static void get3(double a[3], nav_vec3 v) {
  a[0] = v.x;
  a[1] = v.y;
  a[2] = v.z;
}

static void check_nonneg(checker *ck, const char *name, nav_vec3 v) {
  double a[3];
  get3(a, v);
  for (int i = 0; i < 3; ++i) {
    char path[96];
    snprintf(path, sizeof path, "%s[%d]", name, i);
    if (!(isfinite(a[i]) && a[i] >= 0.0)) issue(ck, path, "must be finite and >= 0, got %g", a[i]);
  }
}

nav_status nav_gnss_model_config_validate(const nav_gnss_model_config *cfg, nav_scene_issue_fn report,
                                          void *user) {
  if (cfg == NULL) return NAV_ERR_INVALID_ARG;
  checker ck = {report, user, 0};
  if (cfg->terms & ~NAV_GNSS_TERMS_ALL)
    issue(&ck, "terms", "unknown term bits 0x%x", cfg->terms & ~NAV_GNSS_TERMS_ALL);
  if (!(isfinite(cfg->update_rate_hz) && cfg->update_rate_hz > 0.0))
    issue(&ck, "update_rate_hz", "must be finite and > 0 Hz, got %g", cfg->update_rate_hz);
  if (!(isfinite(cfg->latency_s) && cfg->latency_s >= 0.0))
    issue(&ck, "latency_s", "must be finite and >= 0 s, got %g", cfg->latency_s);
  if (cfg->terms & NAV_GNSS_TERM_POS_GM) {
    check_nonneg(&ck, "pos_gm_sd_m", cfg->pos_gm_sd_m);
    check_nonneg(&ck, "pos_gm_tau_s", cfg->pos_gm_tau_s);
  }
  if (cfg->terms & NAV_GNSS_TERM_POS_WHITE) check_nonneg(&ck, "pos_white_sd_m", cfg->pos_white_sd_m);
  if (cfg->terms & NAV_GNSS_TERM_VEL_WHITE) check_nonneg(&ck, "vel_sd_mps", cfg->vel_sd_mps);
  if (!nav_vec3_isfinite(cfg->r_ba_b_m)) issue(&ck, "r_ba_b_m", "lever arm must be finite");
  if (!cfg->report_model_sigmas) {
    check_nonneg(&ck, "reported_pos_sd_m", cfg->reported_pos_sd_m);
    check_nonneg(&ck, "reported_vel_sd_mps", cfg->reported_vel_sd_mps);
  }
  if (cfg->outage_count > NAV_GNSS_MAX_OUTAGES) {
    issue(&ck, "outages", "at most %d outages, got %zu", NAV_GNSS_MAX_OUTAGES, cfg->outage_count);
  } else {
    for (size_t i = 0; i < cfg->outage_count; ++i) {
      const nav_gnss_outage *o = &cfg->outages[i];
      char path[64];
      snprintf(path, sizeof path, "outages[%zu]", i);
      if (!(isfinite(o->t0_s) && isfinite(o->t1_s) && o->t1_s > o->t0_s))
        issue(&ck, path, "needs finite t0_s < t1_s, got [%g, %g)", o->t0_s, o->t1_s);
    }
  }
  return ck.problems == 0 ? NAV_OK : NAV_ERR_INVALID_ARG;
}

/* Advance every error process by one epoch (GM recursion E2.4; white draws). The white draws are
 * made for every epoch, requested or not, so a realisation depends on the epoch index only. */
static void draw_epoch(nav_gnss_model *m, double pos_white[3], double vel[3]) {
  const unsigned terms = m->cfg.terms;
  if (terms & NAV_GNSS_TERM_POS_GM) {
    if (m->epoch < 0) {
      /* Stationary start (E2.5). */
      double sd[3];
      get3(sd, m->cfg.pos_gm_sd_m);
      for (int i = 0; i < 3; ++i)
        m->gm[i] = sd[i] * nav_rng_gauss(&m->rng_gm[i]);
    } else {
      for (int i = 0; i < 3; ++i)
        m->gm[i] = m->phi[i] * m->gm[i] + m->drive[i] * nav_rng_gauss(&m->rng_gm[i]);
    }
  }
  if (terms & NAV_GNSS_TERM_POS_WHITE) {
    double sd[3];
    get3(sd, m->cfg.pos_white_sd_m);
    for (int i = 0; i < 3; ++i)
      pos_white[i] = sd[i] * nav_rng_gauss(&m->rng_pw[i]);
  } else {
    pos_white[0] = pos_white[1] = pos_white[2] = 0.0;
  }
  if (terms & NAV_GNSS_TERM_VEL_WHITE) {
    double sd[3];
    get3(sd, m->cfg.vel_sd_mps);
    for (int i = 0; i < 3; ++i)
      vel[i] = sd[i] * nav_rng_gauss(&m->rng_vel[i]);
  } else {
    vel[0] = vel[1] = vel[2] = 0.0;
  }
  m->epoch++;
}

nav_status nav_gnss_model_create(const nav_gnss_model_config *cfg, const nav_frame *frame, uint64_t seed,
                                 uint64_t run, nav_gnss_model **out) {
  assert(cfg != NULL && frame != NULL && out != NULL);
  if (cfg == NULL || frame == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  if (nav_gnss_model_config_validate(cfg, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_gnss_model *m = calloc(1, sizeof *m);
  if (m == NULL) return NAV_ERR_NO_MEMORY;
  m->cfg = *cfg;
  m->frame = *frame;
  const double dt_e = 1.0 / cfg->update_rate_hz;
  double sd[3], tau[3];
  get3(sd, cfg->pos_gm_sd_m);
  get3(tau, cfg->pos_gm_tau_s);
  for (unsigned i = 0; i < 3; ++i) {
    /* tau = 0 is the white limit of E2.4 (phi -> 0), written out to avoid dividing by zero. */
    m->phi[i] = tau[i] > 0.0 ? exp(-dt_e / tau[i]) : 0.0;
    m->drive[i] = tau[i] > 0.0 ? sd[i] * sqrt(-expm1(-2.0 * dt_e / tau[i])) : sd[i];
    nav_rng_init(&m->rng_gm[i], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_POS, i));
    nav_rng_init(&m->rng_pw[i], seed, run,
                 nav_rng_stream_id(NAV_RNG_STREAM_GNSS_POS, GNSS_POS_WHITE_CHANNEL + i));
    nav_rng_init(&m->rng_vel[i], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_VEL, i));
  }
  m->epoch = -1;
  m->err.epoch = -1;
  *out = m;
  return NAV_OK;
}

void nav_gnss_model_destroy(nav_gnss_model *model) {
  free(model);
}

double nav_gnss_model_epoch_time_s(const nav_gnss_model *model, int64_t epoch) {
  assert(model != NULL);
  return model ? (double)epoch / model->cfg.update_rate_hz : NAN;
}

static nav_status fail(nav_gnss_model *m, nav_status st, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(m->last_error, sizeof m->last_error, fmt, ap);
  va_end(ap);
  return st;
}

static bool in_outage(const nav_gnss_model_config *cfg, double t) {
  for (size_t i = 0; i < cfg->outage_count; ++i)
    if (t >= cfg->outages[i].t0_s && t < cfg->outages[i].t1_s) return true;
  return false;
}

nav_status nav_gnss_model_measure(nav_gnss_model *model, int64_t epoch, const nav_traj_state *truth,
                                  nav_gnss_fix *fix, bool *has_fix) {
  assert(model != NULL && truth != NULL && fix != NULL && has_fix != NULL);
  if (model == NULL || truth == NULL || fix == NULL || has_fix == NULL) return NAV_ERR_INVALID_ARG;
  if (epoch < 0) return fail(model, NAV_ERR_INVALID_ARG, "epoch must be >= 0, got %lld", (long long)epoch);
  if (epoch <= model->epoch)
    return fail(model, NAV_ERR_STATE, "epochs must increase: got %lld after %lld", (long long)epoch,
                (long long)model->epoch);
  const double t = nav_gnss_model_epoch_time_s(model, epoch);
  if (!(fabs(truth->t_s - t) <= GNSS_TIME_MATCH_S))
    return fail(model, NAV_ERR_INVALID_ARG, "epoch %lld is at t = %.9f s but the truth state is at %.9f s",
                (long long)epoch, t, truth->t_s);
  if (!nav_vec3_isfinite(truth->r_fb_f_m) || !nav_vec3_isfinite(truth->v_fb_f_mps) ||
      !nav_vec3_isfinite(truth->w_fb_b_rps) || !isfinite(truth->q_b_f.w) || !isfinite(truth->q_b_f.x) ||
      !isfinite(truth->q_b_f.y) || !isfinite(truth->q_b_f.z))
    return fail(model, NAV_ERR_NUMERIC, "epoch %lld: non-finite truth state", (long long)epoch);
  model->last_error[0] = '\0';

  /* Draw every epoch up to this one (skipped ones included, see the header). */
  double pw[3] = {0.0, 0.0, 0.0}, ve[3] = {0.0, 0.0, 0.0};
  while (model->epoch < epoch)
    draw_epoch(model, pw, ve);

  const nav_gnss_model_config *cfg = &model->cfg;
  const double e_pos[3] = {model->gm[0] + pw[0], model->gm[1] + pw[1], model->gm[2] + pw[2]};
  model->err.epoch = epoch;
  model->err.pos_gm_m = nav_vec3_make(model->gm[0], model->gm[1], model->gm[2]);
  model->err.pos_m = nav_vec3_make(e_pos[0], e_pos[1], e_pos[2]);
  model->err.vel_mps = nav_vec3_make(ve[0], ve[1], ve[2]);

  if (in_outage(cfg, t)) {
    *has_fix = false;
    return NAV_OK;
  }

  /* Antenna kinematics in F (rigid body; numerics.md E6.3-E6.4 written in F, where the Earth-rate
   * term of E6.4 is already inside w_fb_b because F = e rotates with the Earth):
   *   r_fa_f = r_fb_f + C_b_f r_ba_b,   v_fa_f = v_fb_f + C_b_f (w_fb_b x r_ba_b). */
  const nav_mat3 C_b_f = nav_quat_to_dcm(nav_quat_normalize(truth->q_b_f));
  const nav_vec3 r_fa_f = nav_vec3_add(truth->r_fb_f_m, nav_mat3_mul_vec(C_b_f, cfg->r_ba_b_m));
  const nav_vec3 v_fa_f = nav_vec3_add(
      truth->v_fb_f_mps, nav_mat3_mul_vec(C_b_f, nav_vec3_cross(truth->w_fb_b_rps, cfg->r_ba_b_m)));
  const nav_local_view at = nav_frame_view(&model->frame, r_fa_f, v_fa_f, truth->q_b_f);

  /* Errors are N/E/D at the antenna: r_meas_f = r_fa_f + C_n_f e_n, C_n_f = C_f_n^T. Mapping the
   * displaced point back to geodetic coordinates through F is exact (no radii-of-curvature
   * linearisation) and works at the poles when F is ECEF. */
  const nav_vec3 e_n = model->err.pos_m;
  const nav_vec3 r_meas_f = nav_vec3_add(r_fa_f, nav_mat3_tmul_vec(at.C_f_n, e_n));
  const nav_local_view meas = nav_frame_view(&model->frame, r_meas_f, v_fa_f, truth->q_b_f);

  nav_gnss_fix f;
  f.epoch = epoch;
  f.t_s = t;
  f.t_avail_s = t + cfg->latency_s;
  f.pos = meas.pos;
  f.r_fa_f_m = r_meas_f;
  f.v_fa_n_mps = nav_vec3_add(at.v_n_mps, model->err.vel_mps);
  if (cfg->report_model_sigmas) {
    double gm_sd[3] = {0.0, 0.0, 0.0}, w_sd[3] = {0.0, 0.0, 0.0}, v_sd[3] = {0.0, 0.0, 0.0};
    if (cfg->terms & NAV_GNSS_TERM_POS_GM) get3(gm_sd, cfg->pos_gm_sd_m);
    if (cfg->terms & NAV_GNSS_TERM_POS_WHITE) get3(w_sd, cfg->pos_white_sd_m);
    if (cfg->terms & NAV_GNSS_TERM_VEL_WHITE) get3(v_sd, cfg->vel_sd_mps);
    f.pos_sd_m = nav_vec3_make(hypot(gm_sd[0], w_sd[0]), hypot(gm_sd[1], w_sd[1]), hypot(gm_sd[2], w_sd[2]));
    f.vel_sd_mps = nav_vec3_make(v_sd[0], v_sd[1], v_sd[2]);
  } else {
    f.pos_sd_m = cfg->reported_pos_sd_m;
    f.vel_sd_mps = cfg->reported_vel_sd_mps;
  }
  *fix = f;
  *has_fix = true;
  return NAV_OK;
}

const nav_gnss_error_state *nav_gnss_model_errors(const nav_gnss_model *model) {
  return model ? &model->err : NULL;
}

const char *nav_gnss_model_last_error(const nav_gnss_model *model) {
  return model ? model->last_error : "";
}
