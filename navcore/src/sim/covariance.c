/*
 * Covariance analysis (numerics.md 6.6): propagate the error covariance of the scene's
 * navigation scheme along the reference trajectory, with GNSS updates at the receiver's epochs
 * (outages respected) for the integrated scheme; no random draws. It predicts the one-sigma
 * errors of the real filter (and of the free INS) in milliseconds, before any Monte Carlo.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "navcore/nav_gyrofree_gnss.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"
#include "filter/filter_internal.h"
#include "integration/ins_gnss_internal.h"
#include "sim/consider_internal.h"
#include "sim/sim_internal.h"

static bool in_outage(const nav_gnss_model_config *g, double t) {
  for (size_t i = 0; i < g->outage_count; ++i)
    if (t >= g->outages[i].t0_s && t < g->outages[i].t1_s) return true;
  return false;
}

/* The filter of the scene's scheme: the gyro INS's (nav_filter) or the gyro-free INS's
 * (nav_gfg_filter, gyro_free_gnss). Both lead with dr, dv, phi at the same indices. */
typedef struct cov_filter {
  nav_filter *kf;
  nav_gfg_filter *gf;
} cov_filter;

static nav_status cf_predict(cov_filter *c, const nav_filter_nav *nv, double dt) {
  return c->gf ? nav_gfg_filter_predict(c->gf, nv, dt) : nav_filter_predict(c->kf, nv, dt);
}
static nav_status cf_update(cov_filter *c, const nav_filter_nav *nv, nav_vec3 rp, nav_vec3 rv, nav_vec3 l) {
  nav_status st;
  if (c->gf) {
    st = nav_gfg_filter_update_pos(c->gf, nv, nav_vec3_zero(), rp, l);
    if (st == NAV_OK) st = nav_gfg_filter_update_vel(c->gf, nv, nav_vec3_zero(), rv, l);
    return st;
  }
  st = nav_filter_update_gnss_pos(c->kf, nv, nav_vec3_zero(), &rp, l);
  if (st == NAV_OK) st = nav_filter_update_gnss_vel(c->kf, nv, nav_vec3_zero(), &rv, l);
  return st;
}
static const char *cf_error(const cov_filter *c) {
  return c->gf ? nav_gfg_filter_last_error(c->gf) : nav_filter_last_error(c->kf);
}

static nav_cov_point make_point(double t, const cov_filter *c) {
  const double *P = c->gf ? nav_gfg_filter_cov(c->gf) : nav_filter_get_cov(c->kf);
  const size_t n = c->gf ? nav_gfg_filter_n_states(c->gf) : nav_filter_get_layout(c->kf).n_states;
  nav_cov_point p;
  memset(&p, 0, sizeof p);
  p.t_s = t;
  for (int i = 0; i < 3; ++i) {
    nav_vec3_set(&p.pos_sd_n_m, i, sqrt(P[(size_t)(NAV_FILTER_IDX_DR + i) * n + (size_t)(NAV_FILTER_IDX_DR + i)]));
    nav_vec3_set(&p.vel_sd_n_mps, i, sqrt(P[(size_t)(NAV_FILTER_IDX_DV + i) * n + (size_t)(NAV_FILTER_IDX_DV + i)]));
    nav_vec3_set(&p.att_sd_rad, i, sqrt(P[(size_t)(NAV_FILTER_IDX_PHI + i) * n + (size_t)(NAV_FILTER_IDX_PHI + i)]));
  }
  p.pos_h_sd_m = hypot(p.pos_sd_n_m.x, p.pos_sd_n_m.y);
  return p;
}

/* ins_gnss_tight: one scalar update per pseudorange and range rate of every satellite visible from
 * the reference (the simulation's visibility, nav_sim_gnss_raw_measure), with the rows of the
 * real filter (nav_ins_gnss_tight_rows) at the reference; no gating (z = 0). The GNSS epochs are
 * processed at the IMU step they fall in, as the simulation does, with that step's reference. */
static nav_status tight_update(nav_filter *kf, const nav_scene *sc, const nav_gnss_constellation *sats,
                               const nav_frame *fr, const nav_traj_state *ts, const nav_filter_nav *nv,
                               nav_geodetic pos) {
  const nav_gnss_constellation_config *cc = &sc->gnss.constellation;
  const double t_gps = cc->epoch_gps_s + ts->t_s;
  const double heading = atan2(nv->C_b_n.m[1][0], nv->C_b_n.m[0][0]);
  const nav_gnss_sky_mask mask = nav_gnss_constellation_mask_at(cc, ts->t_s);
  nav_gnss_sat_view views[NAV_GNSS_MAX_SATS];
  nav_gnss_dop dop;
  nav_status st = nav_gnss_visibility(sats, &mask, t_gps, pos, heading, views, &dop);
  if (st != NAV_OK) return st;
  (void)fr;
  nav_tight_geom geom;
  const nav_filter_layout lay = nav_filter_get_layout(kf);
  nav_ins_gnss_tight_geometry(&geom, &lay, nv, pos, sc->gnss.model.r_ba_b_m);
  const double rp = cc->raw.code_sd_m * cc->raw.code_sd_m, rr = cc->raw.range_rate_sd_mps * cc->raw.range_rate_sd_mps;
  double Hp[NAV_FILTER_MAX_STATES], Hr[NAV_FILTER_MAX_STATES];
  for (int i = 0; i < sats->n && st == NAV_OK; ++i) {
    if (!views[i].visible) continue;
    double rho, rdot;
    nav_ins_gnss_tight_rows(&geom, &sats->sats[i], t_gps, Hp, Hr, &rho, &rdot);
    const double z = 0.0;
    st = nav_filter_update_linear(kf, 1, Hp, &z, &rp);
    if (st == NAV_OK) st = nav_filter_update_linear(kf, 1, Hr, &z, &rr);
  }
  return st;
}

/* ins_gnss with gnss.constellation.fixes: pvt: the PVT fix of the satellites visible from the
 * reference with R = sigma^2 Q (the NED block of the least-squares cofactor, position with a clock
 * per system, velocity with one drift), as the simulation's fixes (sim.c pvt_fix); no fix where
 * the geometry has no solution (fewer than 3 + systems satellites). */
static nav_status pvt_update(nav_filter *kf, const nav_scene *sc, const nav_gnss_constellation *sats,
                             const nav_traj_state *ts, const nav_filter_nav *nv, nav_geodetic pos) {
  const nav_gnss_constellation_config *cc = &sc->gnss.constellation;
  const double t_gps = cc->epoch_gps_s + ts->t_s;
  const double heading = atan2(nv->C_b_n.m[1][0], nv->C_b_n.m[0][0]);
  const nav_gnss_sky_mask mask = nav_gnss_constellation_mask_at(cc, ts->t_s);
  nav_gnss_sat_view views[NAV_GNSS_MAX_SATS];
  nav_gnss_dop dop;
  nav_status st = nav_gnss_visibility(sats, &mask, t_gps, pos, heading, views, &dop);
  if (st != NAV_OK) return st;
  double az[NAV_GNSS_MAX_SATS], el[NAV_GNSS_MAX_SATS];
  nav_gnss_system sy[NAV_GNSS_MAX_SATS];
  int m = 0;
  for (int i = 0; i < sats->n; ++i) {
    if (!views[i].visible) continue;
    az[m] = views[i].az_rad;
    el[m] = views[i].el_rad;
    sy[m] = views[i].system;
    ++m;
  }
  double qp[3][3], qv[3][3];
  if (!nav_gnss_cofactor_ned(m, az, el, sy, false, qp)) return NAV_OK;
  const bool vel = nav_gnss_cofactor_ned(m, az, el, sy, true, qv);
  const double sp2 = cc->raw.code_sd_m * cc->raw.code_sd_m, sv2 = cc->raw.range_rate_sd_mps * cc->raw.range_rate_sd_mps;
  double Rp[9], Rv[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      Rp[r * 3 + c] = sp2 * qp[r][c];
      Rv[r * 3 + c] = vel ? sv2 * qv[r][c] : 0.0;
    }
  const nav_filter_layout lay = nav_filter_get_layout(kf);
  double H[3 * NAV_FILTER_MAX_STATES];
  const double z[3] = {0.0, 0.0, 0.0};
  nav_filter_build_H_pos(H, &lay, nv, sc->gnss.model.r_ba_b_m);
  st = nav_filter_update_linear(kf, 3, H, z, Rp);
  if (st == NAV_OK && vel) {
    nav_filter_build_H_vel(H, &lay, nv, sc->gnss.model.r_ba_b_m);
    st = nav_filter_update_linear(kf, 3, H, z, Rv);
  }
  return st;
}

/* Where the output epochs go: the filter's points (fn), or those and the budget's total model
 * (tfn, nav_sim_covariance_total). */
typedef struct cov_sink {
  nav_cov_fn fn;
  nav_cov_total_fn tfn;
  void *user;
} cov_sink;

/* The point of the total model: the filter's, plus the consider part when there is one. */
static nav_callback_result emit(const cov_sink *s, const nav_cov_point *p, const cov_filter *cf,
                                const nav_consider *k) {
  if (s->fn) return s->fn(s->user, p);
  if (!k) return s->tfn(s->user, p, p);
  double v[9];
  nav_consider_total_diag(k, nav_filter_get_cov(cf->kf), 9, v);
  nav_cov_point q;
  memset(&q, 0, sizeof q);
  q.t_s = p->t_s;
  q.pos_sd_n_m = nav_vec3_make(sqrt(v[0]), sqrt(v[1]), sqrt(v[2]));
  q.pos_h_sd_m = hypot(q.pos_sd_n_m.x, q.pos_sd_n_m.y);
  q.vel_sd_n_mps = nav_vec3_make(sqrt(v[3]), sqrt(v[4]), sqrt(v[5]));
  q.att_sd_rad = nav_vec3_make(sqrt(v[6]), sqrt(v[7]), sqrt(v[8]));
  return s->tfn(s->user, p, &q);
}

/* The GNSS position and velocity updates of the gyro INS filter with the consider part
 * following each (its gain from the filter's covariance before that update). */
static nav_status consider_update(nav_sim *sim, cov_filter *c, nav_consider *k, const nav_filter_nav *nv,
                                  nav_vec3 rp, nav_vec3 rv, nav_vec3 l) {
  nav_status st = nav_filter_flush(c->kf);
  nav_consider_flush(k);
  const size_t n = nav_filter_get_layout(c->kf).n_states;
  double P[NAV_FILTER_MAX_STATES * NAV_FILTER_MAX_STATES];
  for (int u = 0; u < 2 && st == NAV_OK; ++u) {
    const nav_vec3 r = u ? rv : rp;
    /* The filter first, so that its failure is reported as without the consider part; the
     * consider part's gain from the filter's covariance before this update. */
    memcpy(P, nav_filter_get_cov(c->kf), n * n * sizeof *P);
    st = u ? nav_filter_update_gnss_vel(c->kf, nv, nav_vec3_zero(), &r, l)
           : nav_filter_update_gnss_pos(c->kf, nv, nav_vec3_zero(), &r, l);
    if (st != NAV_OK) break;
    st = nav_consider_update(k, P, nv, l, r, u == 1);
    if (st != NAV_OK) {
      nav_sim_set_error(sim, "consider states: the innovation covariance is not positive definite");
      return st;
    }
  }
  if (st != NAV_OK) nav_sim_set_error(sim, cf_error(c));
  return st;
}

static nav_status cov_run(nav_sim *sim, const cov_sink *sink) {
  const nav_scene *sc = nav_sim_scene(sim);
  if (sc->earth.model != NAV_EARTH_WGS84) {
    nav_sim_set_error(sim, "covariance analysis needs the wgs84 Earth model (the error model is the NED one)");
    return NAV_ERR_INVALID_ARG;
  }
  if (sc->navigation.scheme == NAV_SCHEME_GYRO_FREE) {
    nav_sim_set_error(sim, "covariance analysis models gyro INS schemes; for gyro_free use the closed forms "
                           "(navsim estimate) or Monte Carlo");
    return NAV_ERR_INVALID_ARG;
  }
  const bool gfg = sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
  nav_truth *truth = NULL;
  cov_filter cf = {NULL, NULL};
  nav_consider *cons = NULL; /* the total model's consider part (nav_sim_covariance_total) */
  char msg[200];
  nav_status st = nav_truth_create_msg(sc, &truth, msg, sizeof msg);
  if (st != NAV_OK) {
    nav_sim_set_error(sim, msg[0] ? msg : nav_status_str(st));
    return st;
  }
  const nav_ins_gnss_config xc = nav_ins_gnss_config_from_scene(sc);
  /* gyro_free_gnss: its filter along the reference (the IMU truth gives the mean specific force
   * and rate of each interval, which F needs; docs/gyro-free-gnss.md). */
  const nav_gyrofree_gnss_config xg = gfg ? nav_gyrofree_gnss_config_from_scene(sc) : (nav_gyrofree_gnss_config){0};
  st = gfg ? nav_gfg_filter_create(&xg.filter, &cf.gf) : nav_filter_create(&xc.filter, &cf.kf);
  if (st != NAV_OK) {
    nav_sim_set_error(sim, "filter set-up failed");
    goto cleanup;
  }
  const nav_frame fr = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  const double dt = nav_truth_dt(truth);
  int64_t out_stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  if (out_stride < 1) out_stride = 1;
  const bool tight = sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT;
  const bool gnss = sc->navigation.scheme == NAV_SCHEME_INS_GNSS || gfg || tight;
  nav_gnss_model_config gcfg;
  st = nav_sim_gnss_config(sc, 1.0 / sc->imu.rate_hz, &gcfg, msg, sizeof msg);
  if (st != NAV_OK) {
    nav_sim_set_error(sim, msg);
    goto cleanup;
  }
  const nav_gnss_model_config *g = &gcfg;
  const bool gm_states = gfg ? xg.filter.gnss_gm : (xc.filter.states & NAV_FILTER_STATE_GNSS_POS_GM) != 0;
  const double pos_floor_m = gfg ? xg.pos_sd_floor_m : xc.pos_sd_floor_m;
  const double vel_floor_mps = gfg ? xg.vel_sd_floor_mps : xc.vel_sd_floor_mps;
  int64_t next_epoch = 0;
  /* ins_gnss_tight: the satellites the reference trajectory sees (as the simulation's receiver). */
  nav_gnss_constellation sats;
  sats.n = 0;
  const bool pvt = nav_scene_gnss_pvt_fixes(sc);
  if (tight || pvt) {
    st = nav_gnss_constellation_build(&sc->gnss.constellation, &sats);
    if (st != NAV_OK) {
      nav_sim_set_error(sim, "gnss.constellation: cannot build the constellation");
      goto cleanup;
    }
  }
  /* The total model's consider part (nav_sim_covariance_total): the truth's scale factors the
   * gyro INS filter does not estimate, as the budget has them (ins_gnss with the receiver's
   * fixes, free_ins); the other schemes' total is their filter. */
  if (sink->tfn && !gfg && !tight) {
    if (pvt) {
      nav_sim_set_error(sim, "the total covariance model is the budget's, which has no PVT fixes "
                             "(gnss.constellation.fixes: pvt)");
      st = NAV_ERR_INVALID_ARG;
      goto cleanup;
    }
    st = nav_consider_create(sc, &xc.filter, &cons);
    if (st != NAV_OK) {
      nav_sim_set_error(sim, st == NAV_ERR_NO_MEMORY ? "out of memory"
                                                     : "consider states need the second-order discretisation");
      goto cleanup;
    }
  }
  nav_cov_point p0 = make_point(0.0, &cf);
  if (emit(sink, &p0, &cf, cons) == NAV_STOP) goto cleanup;
  for (int64_t k = 1; k <= n; ++k) {
    nav_imu_increment imu;
    nav_traj_state ts;
    st = nav_truth_imu(truth, k, &imu);
    if (st == NAV_OK) st = nav_truth_state(truth, imu.t_s, &ts);
    if (st != NAV_OK) goto cleanup;
    const nav_local_view v = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
    const nav_filter_nav nv = {v.pos.lat_rad,
                               v.pos.h_m,
                               v.v_n_mps,
                               nav_quat_to_dcm(v.q_b_n),
                               nav_vec3_scale(imu.dv_b_mps, 1.0 / imu.dt_s),
                               nav_vec3_scale(imu.dtheta_b_rad, 1.0 / imu.dt_s)};
    st = cf_predict(&cf, &nv, imu.dt_s);
    if (st != NAV_OK) {
      nav_sim_set_error(sim, cf_error(&cf));
      goto cleanup;
    }
    if (cons) nav_consider_predict(cons, &nv, imu.dt_s);
    while (gnss) {
      const double t_fix = (double)next_epoch / g->update_rate_hz;
      if (!(t_fix <= imu.t_s + 0.5 * dt)) break;
      ++next_epoch;
      if (t_fix < imu.t_s - 0.5 * dt || in_outage(g, t_fix)) continue;
      if (tight) {
        st = tight_update(cf.kf, sc, &sats, &fr, &ts, &nv, v.pos);
        if (st != NAV_OK) {
          nav_sim_set_error(sim, cf_error(&cf));
          goto cleanup;
        }
        continue;
      }
      if (pvt) {
        st = pvt_update(cf.kf, sc, &sats, &ts, &nv, v.pos);
        if (st != NAV_OK) {
          nav_sim_set_error(sim, cf_error(&cf));
          goto cleanup;
        }
        continue;
      }
      /* R as the simulation uses it: the receiver's reported sigmas (white part only when the
       * filter carries GNSS GM states), floored as in nav_ins_gnss. */
      nav_vec3 rp, rv;
      for (int i = 0; i < 3; ++i) {
        const double gm = (g->terms & NAV_GNSS_TERM_POS_GM) ? nav_vec3_get(g->pos_gm_sd_m, i) : 0.0;
        const double wh = (g->terms & NAV_GNSS_TERM_POS_WHITE) ? nav_vec3_get(g->pos_white_sd_m, i) : 0.0;
        const double vv = (g->terms & NAV_GNSS_TERM_VEL_WHITE) ? nav_vec3_get(g->vel_sd_mps, i) : 0.0;
        double sp = g->report_model_sigmas ? (gm_states ? wh : hypot(gm, wh)) : nav_vec3_get(g->reported_pos_sd_m, i);
        double sv = g->report_model_sigmas ? vv : nav_vec3_get(g->reported_vel_sd_mps, i);
        sp = fmax(sp, pos_floor_m);
        sv = fmax(sv, vel_floor_mps);
        nav_vec3_set(&rp, i, sp * sp);
        nav_vec3_set(&rv, i, sv * sv);
      }
      if (cons) {
        st = consider_update(sim, &cf, cons, &nv, rp, rv, g->r_ba_b_m);
        if (st != NAV_OK) goto cleanup;
        continue;
      }
      st = cf_update(&cf, &nv, rp, rv, g->r_ba_b_m);
      if (st != NAV_OK) {
        nav_sim_set_error(sim, cf_error(&cf));
        goto cleanup;
      }
    }
    if (k % out_stride == 0 || k == n) {
      st = cf.kf ? nav_filter_flush(cf.kf) : NAV_OK;
      if (st != NAV_OK) goto cleanup;
      if (cons) nav_consider_flush(cons);
      nav_cov_point p = make_point(imu.t_s, &cf);
      if (emit(sink, &p, &cf, cons) == NAV_STOP) {
        st = NAV_ERR_CANCELLED;
        goto cleanup;
      }
    }
  }
cleanup:
  nav_consider_destroy(cons);
  nav_filter_destroy(cf.kf);
  nav_gfg_filter_destroy(cf.gf);
  nav_truth_destroy(truth);
  return st;
}

nav_status nav_sim_covariance(nav_sim *sim, nav_cov_fn fn, void *user) {
  if (!sim || !fn) return NAV_ERR_INVALID_ARG;
  const cov_sink sink = {fn, NULL, user};
  return cov_run(sim, &sink);
}

nav_status nav_sim_covariance_total(nav_sim *sim, nav_cov_total_fn fn, void *user) {
  if (!sim || !fn) return NAV_ERR_INVALID_ARG;
  const cov_sink sink = {NULL, fn, user};
  return cov_run(sim, &sink);
}
