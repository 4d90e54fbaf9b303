/*
 * Loosely coupled INS/GNSS in closed loop (nav_ins_gnss.h): strapdown + error-state EKF +
 * feedback (numerics.md section 6). Consumes measured increments and fixes only.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_sensors.h"
#include "filter/filter_internal.h"
#include "integration/ins_gnss_internal.h"
#include "nav/strapdown_lanes.h"
#include "math/quat_dcm_inline.h"

static nav_filter_ins_state nominal_of(const nav_ins_gnss *x);

/* Largest element of a vector. */
static double vmax(nav_vec3 v) { return fmax(fmax(v.x, v.y), v.z); }

static double rss3(double a, double b, double c) { return sqrt(a * a + b * b + c * c); }

/*
 * The filter's model of the sensors, taken from the scene's error models (the filter is tuned
 * to the truth's statistics, numerics.md 6.2): white noise densities as they are; GM and random
 * walk biases as bias processes; turn-on biases and fixed offsets as the initial bias sigma.
 * Floors keep P0 positive definite where the scene has no error at all (a perfect sensor).
 */
static nav_filter_config filter_config(const nav_scene *sc) {
  nav_filter_config c = nav_filter_config_default();
  if (sc->navigation.cov_decimation > 1) c.cov_decimation = (unsigned)sc->navigation.cov_decimation;
  const nav_gyro_error_config *g = &sc->imu.model.gyro;
  const nav_accel_error_config *a = &sc->imu.model.accel;
  if (g->terms & NAV_IMU_TERM_NOISE) c.gyro_arw_rad_per_sqrt_s = g->arw_rad_per_sqrt_s;
  if (a->terms & NAV_IMU_TERM_NOISE) c.accel_vrw_mps_per_sqrt_s = a->vrw_mps_per_sqrt_s;
  c.gyro_bias_terms = 0;
  c.accel_bias_terms = 0;
  if (g->terms & NAV_IMU_TERM_BIAS_GM) {
    c.gyro_bias_terms |= NAV_FILTER_PROC_GM;
    c.gyro_bias_gm_sd_rps = g->bias_gm_sd_rps;
    c.gyro_bias_gm_tau_s = g->bias_gm_tau_s;
  }
  if (g->terms & NAV_IMU_TERM_BIAS_RW) {
    c.gyro_bias_terms |= NAV_FILTER_PROC_RW;
    c.gyro_bias_rw_rps_per_sqrt_s = g->bias_rw_rps_per_sqrt_s;
  }
  if (a->terms & NAV_IMU_TERM_BIAS_GM) {
    c.accel_bias_terms |= NAV_FILTER_PROC_GM;
    c.accel_bias_gm_sd_mps2 = a->bias_gm_sd_mps2;
    c.accel_bias_gm_tau_s = a->bias_gm_tau_s;
  }
  if (a->terms & NAV_IMU_TERM_BIAS_RW) {
    c.accel_bias_terms |= NAV_FILTER_PROC_RW;
    c.accel_bias_rw_mps2_per_sqrt_s = a->bias_rw_mps2_per_sqrt_s;
  }
  for (int i = 0; i < 3; ++i) {
    const bool gt = (g->terms & NAV_IMU_TERM_BIAS_TURN_ON) != 0, at = (a->terms & NAV_IMU_TERM_BIAS_TURN_ON) != 0;
    const bool gg = (g->terms & NAV_IMU_TERM_BIAS_GM) != 0, ag = (a->terms & NAV_IMU_TERM_BIAS_GM) != 0;
    const double sg = rss3(gt ? nav_vec3_get(g->bias_turn_on_sd_rps, i) : 0.0,
                           gt ? nav_vec3_get(g->bias_turn_on_fixed_rps, i) : 0.0,
                           gg ? nav_vec3_get(g->bias_gm_sd_rps, i) : 0.0);
    const double sa = rss3(at ? nav_vec3_get(a->bias_turn_on_sd_mps2, i) : 0.0,
                           at ? nav_vec3_get(a->bias_turn_on_fixed_mps2, i) : 0.0,
                           ag ? nav_vec3_get(a->bias_gm_sd_mps2, i) : 0.0);
    /* Floors: 0.01 deg/h and 1 ug, far below any real part, so P0 stays positive definite. */
    nav_vec3_set(&c.init.gyro_bias_sd_rps, i, fmax(sg, 4.85e-8));
    nav_vec3_set(&c.init.accel_bias_sd_mps2, i, fmax(sa, 9.8e-6));
    nav_vec3_set(&c.init.pos_sd_m, i, fmax(nav_vec3_get(sc->initial_errors.pos_sd_m, i), 1e-3));
    nav_vec3_set(&c.init.vel_sd_mps, i, fmax(nav_vec3_get(sc->initial_errors.vel_sd_mps, i), 1e-4));
    nav_vec3_set(&c.init.att_sd_rad, i, fmax(nav_vec3_get(sc->initial_errors.att_sd_rad, i), 1e-6));
  }
  if (sc->navigation.estimate_scale_factors) {
    /* Scale factors with the scene's sigma (fixed part included), floored at 1 ppm so P0 stays
     * positive definite for a perfect sensor: random constants, or Gauss-Markov processes of
     * that stationary sigma when navigation.scale_factor_gm_tau_s > 0. */
    c.states |= NAV_FILTER_STATE_SCALE_FACTORS;
    const double sf_tau = sc->navigation.scale_factor_gm_tau_s;
    c.gyro_sf_terms = sf_tau > 0.0 ? NAV_FILTER_PROC_GM : 0u;
    c.accel_sf_terms = sf_tau > 0.0 ? NAV_FILTER_PROC_GM : 0u;
    const bool gs = (g->terms & NAV_IMU_TERM_SCALE_FACTOR) != 0, as = (a->terms & NAV_IMU_TERM_SCALE_FACTOR) != 0;
    for (int i = 0; i < 3; ++i) {
      const double sgs = gs ? hypot(nav_vec3_get(g->scale_factor_sd, i), nav_vec3_get(g->scale_factor_fixed, i)) : 0.0;
      const double sas = as ? hypot(nav_vec3_get(a->scale_factor_sd, i), nav_vec3_get(a->scale_factor_fixed, i)) : 0.0;
      nav_vec3_set(&c.init.gyro_sf_sd, i, fmax(sgs, 1e-6));
      nav_vec3_set(&c.init.accel_sf_sd, i, fmax(sas, 1e-6));
      if (sf_tau > 0.0) {
        nav_vec3_set(&c.gyro_sf_gm_sd, i, fmax(sgs, 1e-6));
        nav_vec3_set(&c.accel_sf_gm_sd, i, fmax(sas, 1e-6));
        nav_vec3_set(&c.gyro_sf_gm_tau_s, i, sf_tau);
        nav_vec3_set(&c.accel_sf_gm_tau_s, i, sf_tau);
      }
    }
  }
  /* A time-correlated GNSS error gets its own GM states when tau >> update interval
   * (numerics.md 6.4 (a)); white R on correlated errors would make the filter overconfident. */
  const nav_gnss_model_config *gm = &sc->gnss.model;
  /* PVT fixes (gnss.constellation.fixes: pvt) have white errors: no GM states. */
  if (!nav_scene_gnss_pvt_fixes(sc) && (gm->terms & NAV_GNSS_TERM_POS_GM) && vmax(gm->pos_gm_sd_m) > 0.0 &&
      vmax(gm->pos_gm_tau_s) * gm->update_rate_hz > 10.0) {
    c.states |= NAV_FILTER_STATE_GNSS_POS_GM;
    c.gnss_pos_gm_sd_m = gm->pos_gm_sd_m;
    c.gnss_pos_gm_tau_s = gm->pos_gm_tau_s;
    c.init.gnss_pos_sd_m = gm->pos_gm_sd_m;
  }
  return c;
}

nav_ins_gnss_config nav_ins_gnss_config_from_scene(const nav_scene *sc) {
  nav_ins_gnss_config c;
  memset(&c, 0, sizeof c);
  c.ins = nav_ins_config_from_scene(sc);
  c.filter = filter_config(sc);
  c.r_ba_b_m = sc->gnss.model.r_ba_b_m;
  c.pos_sd_floor_m = 1e-3;
  c.vel_sd_floor_mps = 1e-3;
  c.gate = true;
  c.gate_chi2 = 10.83; /* chi-square, 1 degree of freedom, P = 0.999 */
  if (sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) nav_ins_gnss_tight_filter(sc, &c.filter);
  return c;
}

nav_status nav_ins_gnss_create(const nav_ins_gnss_config *cfg, const nav_ins_state *initial, nav_ins_gnss **out) {
  if (!cfg || !initial || !out) return NAV_ERR_INVALID_ARG;
  if (cfg->ins.earth_model != NAV_EARTH_WGS84) return NAV_ERR_INVALID_ARG;
  if (!(cfg->pos_sd_floor_m > 0.0) || !(cfg->vel_sd_floor_mps > 0.0)) return NAV_ERR_INVALID_ARG;
  if (cfg->gate && !(cfg->gate_chi2 > 0.0)) return NAV_ERR_INVALID_ARG;
  nav_ins_gnss *x = calloc(1, sizeof *x);
  if (!x) return NAV_ERR_NO_MEMORY;
  x->cfg = *cfg;
  memset(&x->frame, 0, sizeof x->frame);
  x->frame.model = NAV_EARTH_WGS84;
  nav_status st = nav_ins_create(&cfg->ins, initial, &x->ins);
  if (st == NAV_OK) st = nav_filter_create(&cfg->filter, &x->kf);
  if (st == NAV_OK) x->sf_on = nav_filter_get_layout(x->kf).has_scale_factors;
  if (st == NAV_OK && cfg->smoother) {
    const nav_filter_ins_state nom = nominal_of(x);
    st = nav_smoother_begin(cfg->smoother, initial->t_s, &nom, nav_filter_get_cov(x->kf), nav_filter_get_state(x->kf));
  }
  if (st != NAV_OK) {
    nav_ins_gnss_destroy(x);
    return st;
  }
  *out = x;
  return NAV_OK;
}

void nav_ins_gnss_destroy(nav_ins_gnss *x) {
  if (!x) return;
  nav_filter_destroy(x->kf);
  nav_ins_destroy(x->ins);
  free(x);
}

const nav_ins_state *nav_ins_gnss_state(const nav_ins_gnss *x) { return x ? nav_ins_get_state(x->ins) : NULL; }
const nav_filter *nav_ins_gnss_filter(const nav_ins_gnss *x) { return x ? x->kf : NULL; }
const nav_ins *nav_ins_gnss_ins(const nav_ins_gnss *x) { return x ? x->ins : NULL; }
long nav_ins_gnss_updates(const nav_ins_gnss *x) { return x ? x->updates : 0; }
const char *nav_ins_gnss_last_error(const nav_ins_gnss *x) { return x ? x->err : ""; }

void nav_ins_gnss_biases(const nav_ins_gnss *x, nav_vec3 *b_g_rps, nav_vec3 *b_a_mps2) {
  if (!x) return;
  if (b_g_rps) *b_g_rps = x->b_g_rps;
  if (b_a_mps2) *b_a_mps2 = x->b_a_mps2;
}

void nav_ins_gnss_scale_factors(const nav_ins_gnss *x, nav_vec3 *s_g, nav_vec3 *s_a) {
  if (!x) return;
  if (s_g) *s_g = x->s_g;
  if (s_a) *s_a = x->s_a;
}

/* The current navigation state in NED terms with the bias estimates (smoother records). */
static nav_filter_ins_state nominal_of(const nav_ins_gnss *x) {
  const nav_ins_state *s = nav_ins_get_state(x->ins);
  const nav_local_view v = nav_frame_view(&x->frame, s->r_fb_f_m, s->v_fb_f_mps, s->q_b_f);
  nav_filter_ins_state o;
  memset(&o, 0, sizeof o);
  o.lat_rad = v.pos.lat_rad;
  o.lon_rad = v.pos.lon_rad;
  o.h_m = v.pos.h_m;
  o.v_eb_n_mps = v.v_n_mps;
  o.q_b_n = v.q_b_n;
  o.b_g_rps = x->b_g_rps;
  o.b_a_mps2 = x->b_a_mps2;
  o.s_g = x->s_g;
  o.s_a = x->s_a;
  return o;
}

/* The filter's specific force and angular rate: the increment's means over its interval. */
static inline void filter_nav_rates(nav_filter_nav *n, const nav_imu_increment *imu) {
  const double idt = 1.0 / imu->dt_s;
  n->f_ib_b_mps2 = nav_vec3_make(imu->dv_b_mps.x * idt, imu->dv_b_mps.y * idt, imu->dv_b_mps.z * idt);
  n->w_ib_b_rps =
      nav_vec3_make(imu->dtheta_b_rad.x * idt, imu->dtheta_b_rad.y * idt, imu->dtheta_b_rad.z * idt);
}

/* Filter inputs from the INS and the compensated increment of the step just taken. A NED
 * mechanization hands over its geodetic state directly (no ECEF round trip at IMU rate); the
 * ECEF one through the frame view. The record is read field by field, never copied whole: a
 * whole-struct copy moves 16-byte pairs at the struct's alignment, and reading a vector member
 * (at offset 24) back from such a copy as a pair straddles two stores, which the CPU cannot
 * forward (a stall of some 10 cycles per read at every IMU step). */
static inline bool filter_nav_fill(nav_filter_nav *n, const nav_frame *fr, const nav_ins *ins,
                                   const nav_imu_increment *imu) {
  nav_ins_ned ned;
  const bool from_ned = nav_ins_get_ned(ins, &ned);
  if (from_ned) {
    n->lat_rad = ned.pos.lat_rad;
    n->h_m = ned.pos.h_m;
    n->v_eb_n_mps = ned.v_n_mps;
    n->C_b_n = nav_quat_to_dcm_inline(ned.q_b_n);
  } else {
    const nav_ins_state *s = nav_ins_get_state(ins);
    const nav_local_view v = nav_frame_view(fr, s->r_fb_f_m, s->v_fb_f_mps, s->q_b_f);
    n->lat_rad = v.pos.lat_rad;
    n->h_m = v.pos.h_m;
    n->v_eb_n_mps = v.v_n_mps;
    n->C_b_n = nav_quat_to_dcm_inline(v.q_b_n);
  }
  filter_nav_rates(n, imu);
  return from_ned;
}

nav_filter_nav nav_ins_gnss_filter_nav(const nav_frame *fr, const nav_ins *ins, const nav_imu_increment *imu) {
  nav_filter_nav n;
  filter_nav_fill(&n, fr, ins, imu);
  return n;
}

/* Compensation of a raw increment: (raw - b dt) / (1 + s), written member by member (see
 * nav_ins_gnss_filter_nav). */
static inline void compensate(const nav_ins_gnss *x, const nav_imu_increment *raw, nav_imu_increment *m) {
  const double dt = raw->dt_s;
  double gx = raw->dtheta_b_rad.x + -dt * x->b_g_rps.x, gy = raw->dtheta_b_rad.y + -dt * x->b_g_rps.y,
         gz = raw->dtheta_b_rad.z + -dt * x->b_g_rps.z;
  double ax = raw->dv_b_mps.x + -dt * x->b_a_mps2.x, ay = raw->dv_b_mps.y + -dt * x->b_a_mps2.y,
         az = raw->dv_b_mps.z + -dt * x->b_a_mps2.z;
  if (x->sf_on) {
    gx /= 1.0 + x->s_g.x;
    gy /= 1.0 + x->s_g.y;
    gz /= 1.0 + x->s_g.z;
    ax /= 1.0 + x->s_a.x;
    ay /= 1.0 + x->s_a.y;
    az /= 1.0 + x->s_a.z;
  }
  m->k = raw->k;
  m->t_s = raw->t_s;
  m->dt_s = dt;
  m->dtheta_b_rad.x = gx;
  m->dtheta_b_rad.y = gy;
  m->dtheta_b_rad.z = gz;
  m->dv_b_mps.x = ax;
  m->dv_b_mps.y = ay;
  m->dv_b_mps.z = az;
}

static nav_status strapdown_failed(nav_ins_gnss *x, const nav_imu_increment *m, nav_status st) {
  snprintf(x->err, sizeof x->err, "strapdown navigation stopped at t = %.6f s: %s", m->t_s, nav_ins_last_error(x->ins));
  return st;
}

/* The step after the strapdown: the filter prediction (and the smoother's record) with the
 * compensated increment m the INS was just stepped with. */
static inline nav_status after_strapdown_nav(nav_ins_gnss *x, const nav_imu_increment *m,
                                             const nav_filter_nav *np, bool from_ned) {
  const double dt = m->dt_s;
  /* From the NED state the INS vouches for lat, h, v and C_b_n (nav_filter_predict_ins). */
  nav_status st = from_ned ? nav_filter_predict_ins(x->kf, np, dt) : nav_filter_predict(x->kf, np, dt);
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "filter prediction failed at t = %.6f s: %s", m->t_s, nav_filter_last_error(x->kf));
    return st;
  }
  if (x->cfg.smoother) {
    const nav_filter_ins_state nom = nominal_of(x);
    st = nav_smoother_step(x->cfg.smoother, m->t_s, np, dt, &nom);
    if (st != NAV_OK) {
      snprintf(x->err, sizeof x->err, "%s", nav_smoother_last_error(x->cfg.smoother));
      return st;
    }
  }
  /* The previous step's increment (for the rate extrapolation at the next fix epoch), then this
   * one, member by member from the values at hand. */
  if (x->have_step) {
    x->prev_dtheta_b_rad = x->last.dtheta_b_rad;
    x->prev_dt_s = x->last.dt_s;
    x->have_prev = true;
  }
  x->last.k = m->k;
  x->last.t_s = m->t_s;
  x->last.dt_s = dt;
  x->last.dtheta_b_rad = nav_vec3_make(m->dtheta_b_rad.x, m->dtheta_b_rad.y, m->dtheta_b_rad.z);
  x->last.dv_b_mps = nav_vec3_make(m->dv_b_mps.x, m->dv_b_mps.y, m->dv_b_mps.z);
  x->have_step = true;
  return NAV_OK;
}

static inline nav_status after_strapdown(nav_ins_gnss *x, const nav_imu_increment *m) {
  nav_filter_nav n; /* filled in place: no copy of the returned struct per step */
  const bool from_ned = filter_nav_fill(&n, &x->frame, x->ins, m);
  return after_strapdown_nav(x, m, &n, from_ned);
}

nav_status nav_ins_gnss_step(nav_ins_gnss *x, const nav_imu_increment *raw) {
  if (!x || !raw || !(raw->dt_s > 0.0)) return NAV_ERR_INVALID_ARG;
  nav_imu_increment m;
  compensate(x, raw, &m);
  const nav_status st = nav_ins_step(x->ins, &m);
  if (st != NAV_OK) return strapdown_failed(x, &m, st);
  return after_strapdown(x, &m);
}

void nav_ins_gnss_step_lanes(nav_ins_gnss *const x[NAV_LANES], const nav_imu_increment *const raw[NAV_LANES],
                             nav_status st[NAV_LANES]) {
  for (int l = 0; l < NAV_LANES; ++l)
    if (!x[l] || !raw[l] || !(raw[l]->dt_s > 0.0)) {
      for (int i = 0; i < NAV_LANES; ++i)
        st[i] = nav_ins_gnss_step(x[i], raw[i]);
      return;
    }
  nav_imu_increment m[NAV_LANES];
  nav_ins *ins[NAV_LANES];
  const nav_imu_increment *mp[NAV_LANES];
  for (int l = 0; l < NAV_LANES; ++l) {
    compensate(x[l], raw[l], &m[l]);
    ins[l] = x[l]->ins;
    mp[l] = &m[l];
  }
  nav_ins_lanes_nav out;
  if (nav_ins_step_lanes(ins, mp, &out)) {
    /* The filter's inputs from the lanes: filter_nav_fill() of each INS (its NED state, the DCM
     * of its attitude, the increment's mean rates), the same values. */
    for (int l = 0; l < NAV_LANES; ++l) {
      nav_filter_nav n;
      n.lat_rad = out.lat[l];
      n.h_m = out.h[l];
      n.v_eb_n_mps = l4v3_lane(out.v, l);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          n.C_b_n.m[i][j] = out.C_b_n.m[i][j][l];
      filter_nav_rates(&n, &m[l]);
      st[l] = after_strapdown_nav(x[l], &m[l], &n, true);
    }
    return;
  }
  for (int l = 0; l < NAV_LANES; ++l) {
    st[l] = nav_ins_step(ins[l], &m[l]);
    st[l] = st[l] != NAV_OK ? strapdown_failed(x[l], &m[l], st[l]) : after_strapdown(x[l], &m[l]);
  }
}

/* The filter's linearisation point at the current epoch: the INS state (view), the filter inputs of
 * the last step, with the angular rate extrapolated to the epoch for the lever-arm velocity. */
nav_filter_nav nav_ins_gnss_epoch_nav(const nav_ins_gnss *x, nav_local_view *view) {
  const nav_ins_state *s = nav_ins_get_state(x->ins);
  *view = nav_frame_view(&x->frame, s->r_fb_f_m, s->v_fb_f_mps, s->q_b_f);
  nav_filter_nav n = nav_ins_gnss_filter_nav(&x->frame, x->ins, &x->last);
  /* The lever-arm velocity needs the angular rate AT the fix epoch; the increments give interval
   * means at mid-intervals, so extrapolate linearly from the last two: w(t_k) = 1.5 w_(k-1/2) -
   * 0.5 w_(k-3/2), an O(dt^2) error instead of the O(dt) of the plain mean (which, while
   * turning, is w_dot dt / 2 x l, ~1 mm/s for a 1.3 m arm at 100 Hz). */
  if (x->have_prev) {
    const nav_vec3 w_prev_rps = nav_vec3_scale(x->prev_dtheta_b_rad, 1.0 / x->prev_dt_s);
    n.w_ib_b_rps = nav_vec3_sub(nav_vec3_scale(n.w_ib_b_rps, 1.5), nav_vec3_scale(w_prev_rps, 0.5));
  }
  return n;
}

nav_status nav_ins_gnss_update(nav_ins_gnss *x, const nav_ins_gnss_fix *fix) {
  if (!x || !fix) return NAV_ERR_INVALID_ARG;
  if (!x->have_step) {
    snprintf(x->err, sizeof x->err, "a GNSS fix before the first IMU step (t = %.6f s)", fix->t_s);
    return NAV_ERR_STATE;
  }
  nav_local_view v;
  const nav_filter_nav n = nav_ins_gnss_epoch_nav(x, &v);
  const nav_vec3 l = x->cfg.r_ba_b_m;
  nav_vec3 r_pos, r_vel;
  for (int i = 0; i < 3; ++i) {
    const double sp = fmax(nav_vec3_get(fix->pos_sd_m, i), x->cfg.pos_sd_floor_m);
    const double sv = fmax(nav_vec3_get(fix->vel_sd_mps, i), x->cfg.vel_sd_floor_mps);
    nav_vec3_set(&r_pos, i, sp * sp);
    nav_vec3_set(&r_vel, i, sv * sv);
  }
  const nav_vec3 z_pos = nav_filter_gnss_pos_residual(v.pos, n.C_b_n, l, fix->pos);
  nav_status st = nav_filter_update_gnss_pos(x->kf, &n, z_pos, &r_pos, l);
  if (st == NAV_OK && fix->has_vel) {
    const nav_vec3 z_vel = nav_filter_gnss_vel_residual(&n, l, fix->v_n_mps);
    st = nav_filter_update_gnss_vel(x->kf, &n, z_vel, &r_vel, l);
  }
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "GNSS update failed at t = %.6f s: %s", fix->t_s, nav_filter_last_error(x->kf));
    return st;
  }
  return nav_ins_gnss_feedback(x, &v, fix->t_s);
}

nav_status nav_ins_gnss_update_cov(nav_ins_gnss *x, const nav_ins_gnss_fix *fix, const double pos_cov_ned_m2[9],
                                   const double vel_cov_ned_m2s2[9]) {
  if (!x || !fix || !pos_cov_ned_m2 || (fix->has_vel && !vel_cov_ned_m2s2)) return NAV_ERR_INVALID_ARG;
  if (!x->have_step) {
    snprintf(x->err, sizeof x->err, "a GNSS fix before the first IMU step (t = %.6f s)", fix->t_s);
    return NAV_ERR_STATE;
  }
  nav_local_view v;
  const nav_filter_nav n = nav_ins_gnss_epoch_nav(x, &v);
  const nav_vec3 l = x->cfg.r_ba_b_m;
  const nav_filter_layout lay = nav_filter_get_layout(x->kf);
  double H[3 * NAV_FILTER_MAX_STATES];
  /* The same measurement and Jacobian as nav_filter_update_gnss_pos/_vel (E6.3, E6.4); only R
   * is full. */
  const nav_vec3 zp = nav_filter_gnss_pos_residual(v.pos, n.C_b_n, l, fix->pos);
  const double z_pos[3] = {zp.x, zp.y, zp.z};
  nav_filter_build_H_pos(H, &lay, &n, l);
  nav_status st = nav_filter_update_linear(x->kf, 3, H, z_pos, pos_cov_ned_m2);
  if (st == NAV_OK && fix->has_vel) {
    const nav_vec3 zv = nav_filter_gnss_vel_residual(&n, l, fix->v_n_mps);
    const double z_vel[3] = {zv.x, zv.y, zv.z};
    nav_filter_build_H_vel(H, &lay, &n, l);
    st = nav_filter_update_linear(x->kf, 3, H, z_vel, vel_cov_ned_m2s2);
  }
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "GNSS update failed at t = %.6f s: %s", fix->t_s, nav_filter_last_error(x->kf));
    return st;
  }
  return nav_ins_gnss_feedback(x, &v, fix->t_s);
}

/* Closed-loop feedback (numerics.md 6.5) of the filter's INS error estimates into the INS and the
 * sensor estimates, then the reset of those states; the smoother records the update. */
nav_status nav_ins_gnss_feedback(nav_ins_gnss *x, const nav_local_view *view, double t_s) {
  const nav_ins_state *s = nav_ins_get_state(x->ins);
  const nav_local_view v = *view;
  nav_filter_error dx;
  nav_status st = nav_filter_get_error(x->kf, &dx);
  if (st != NAV_OK) return st;
  double x_before[NAV_FILTER_MAX_STATES];
  const size_t nx = nav_filter_get_layout(x->kf).n_states;
  if (x->cfg.smoother) memcpy(x_before, nav_filter_get_state(x->kf), nx * sizeof *x_before);
  nav_filter_ins_state fs;
  fs.lat_rad = v.pos.lat_rad;
  fs.lon_rad = v.pos.lon_rad;
  fs.h_m = v.pos.h_m;
  fs.v_eb_n_mps = v.v_n_mps;
  fs.q_b_n = v.q_b_n;
  fs.b_g_rps = x->b_g_rps;
  fs.b_a_mps2 = x->b_a_mps2;
  fs.s_g = x->s_g;
  fs.s_a = x->s_a;
  nav_filter_apply_correction(&fs, &fs, &dx);
  const nav_ins_state corrected = nav_ins_gnss_state_ecef(&fs, s->t_s);
  st = nav_ins_set_state(x->ins, &corrected);
  if (st == NAV_OK) st = nav_filter_reset_errors(x->kf);
  if (st != NAV_OK) {
    snprintf(x->err, sizeof x->err, "feedback failed at t = %.6f s: %s", t_s, nav_status_str(st));
    return st;
  }
  x->b_g_rps = fs.b_g_rps;
  x->b_a_mps2 = fs.b_a_mps2;
  if (x->sf_on) {
    x->s_g = fs.s_g;
    x->s_a = fs.s_a;
  }
  x->updates++;
  if (x->cfg.smoother) {
    /* The correction fed back is what the reset removed from the error state. */
    const double *x_after = nav_filter_get_state(x->kf);
    for (size_t i = 0; i < nx; ++i) x_before[i] -= x_after[i];
    const nav_filter_ins_state nom = nominal_of(x);
    st = nav_smoother_update(x->cfg.smoother, &nom, nav_filter_get_cov(x->kf), x_after, x_before);
    if (st != NAV_OK) {
      snprintf(x->err, sizeof x->err, "smoother record at t = %.6f s: %s", t_s,
               nav_smoother_last_error(x->cfg.smoother));
      return st;
    }
  }
  return NAV_OK;
}

nav_ins_state nav_ins_gnss_state_ecef(const nav_filter_ins_state *s, double t_s) {
  const nav_geodetic p = {s->lat_rad, s->lon_rad, s->h_m};
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(p.lat_rad, p.lon_rad);
  nav_ins_state o;
  o.t_s = t_s;
  o.r_fb_f_m = nav_earth_geodetic_to_ecef(p);
  o.v_fb_f_mps = nav_mat3_mul_vec(C_n_e, s->v_eb_n_mps);
  o.q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), s->q_b_n));
  return o;
}
