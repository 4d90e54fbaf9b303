/*
 * Covariance analysis (numerics.md 6.6): propagate the error covariance of the scene's
 * navigation scheme along the reference trajectory, with GNSS updates at the receiver's epochs
 * (outages respected) for the integrated scheme; no random draws. It predicts the one-sigma
 * errors of the real filter (and of the free INS) in milliseconds, before any Monte Carlo.
 */
#include <stdio.h>
#include <string.h>

#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"
#include "sim/sim_internal.h"

static bool in_outage(const nav_gnss_model_config *g, double t) {
  for (size_t i = 0; i < g->outage_count; ++i)
    if (t >= g->outages[i].t0_s && t < g->outages[i].t1_s) return true;
  return false;
}

static nav_cov_point make_point(double t, const nav_filter *kf) {
  const double *P = nav_filter_get_cov(kf);
  const size_t n = nav_filter_get_layout(kf).n_states;
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

nav_status nav_sim_covariance(nav_sim *sim, nav_cov_fn fn, void *user) {
  if (!sim || !fn) return NAV_ERR_INVALID_ARG;
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
  if (sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS) {
    nav_sim_set_error(sim, "covariance analysis of gyro_free_gnss is not implemented yet; use Monte Carlo "
                           "(navsim run --runs N: mc_stats.csv has the filter's sigma and NEES)");
    return NAV_ERR_INVALID_ARG;
  }
  nav_truth *truth = NULL;
  nav_filter *kf = NULL;
  char msg[200];
  nav_status st = nav_truth_create_msg(sc, &truth, msg, sizeof msg);
  if (st != NAV_OK) {
    nav_sim_set_error(sim, msg[0] ? msg : nav_status_str(st));
    return st;
  }
  const nav_ins_gnss_config xc = nav_ins_gnss_config_from_scene(sc);
  st = nav_filter_create(&xc.filter, &kf);
  if (st != NAV_OK) {
    nav_sim_set_error(sim, "filter set-up failed");
    goto cleanup;
  }
  const nav_frame fr = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  const double dt = nav_truth_dt(truth);
  int64_t out_stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  if (out_stride < 1) out_stride = 1;
  const bool gnss = sc->navigation.scheme == NAV_SCHEME_INS_GNSS;
  nav_gnss_model_config gcfg;
  st = nav_sim_gnss_config(sc, 1.0 / sc->imu.rate_hz, &gcfg, msg, sizeof msg);
  if (st != NAV_OK) {
    nav_sim_set_error(sim, msg);
    goto cleanup;
  }
  const nav_gnss_model_config *g = &gcfg;
  const bool gm_states = (xc.filter.states & NAV_FILTER_STATE_GNSS_POS_GM) != 0;
  int64_t next_epoch = 0;
  nav_cov_point p0 = make_point(0.0, kf);
  if (fn(user, &p0) == NAV_STOP) goto cleanup;
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
    st = nav_filter_predict(kf, &nv, imu.dt_s);
    if (st != NAV_OK) {
      nav_sim_set_error(sim, nav_filter_last_error(kf));
      goto cleanup;
    }
    while (gnss) {
      const double t_fix = (double)next_epoch / g->update_rate_hz;
      if (!(t_fix <= imu.t_s + 0.5 * dt)) break;
      ++next_epoch;
      if (t_fix < imu.t_s - 0.5 * dt || in_outage(g, t_fix)) continue;
      /* R as the simulation uses it: the receiver's reported sigmas (white part only when the
       * filter carries GNSS GM states), floored as in nav_ins_gnss. */
      nav_vec3 rp, rv;
      for (int i = 0; i < 3; ++i) {
        const double gm = (g->terms & NAV_GNSS_TERM_POS_GM) ? nav_vec3_get(g->pos_gm_sd_m, i) : 0.0;
        const double wh = (g->terms & NAV_GNSS_TERM_POS_WHITE) ? nav_vec3_get(g->pos_white_sd_m, i) : 0.0;
        const double vv = (g->terms & NAV_GNSS_TERM_VEL_WHITE) ? nav_vec3_get(g->vel_sd_mps, i) : 0.0;
        double sp = g->report_model_sigmas ? (gm_states ? wh : hypot(gm, wh)) : nav_vec3_get(g->reported_pos_sd_m, i);
        double sv = g->report_model_sigmas ? vv : nav_vec3_get(g->reported_vel_sd_mps, i);
        sp = fmax(sp, xc.pos_sd_floor_m);
        sv = fmax(sv, xc.vel_sd_floor_mps);
        nav_vec3_set(&rp, i, sp * sp);
        nav_vec3_set(&rv, i, sv * sv);
      }
      st = nav_filter_update_gnss_pos(kf, &nv, nav_vec3_zero(), &rp, g->r_ba_b_m);
      if (st == NAV_OK) st = nav_filter_update_gnss_vel(kf, &nv, nav_vec3_zero(), &rv, g->r_ba_b_m);
      if (st != NAV_OK) {
        nav_sim_set_error(sim, nav_filter_last_error(kf));
        goto cleanup;
      }
    }
    if (k % out_stride == 0 || k == n) {
      st = nav_filter_flush(kf);
      if (st != NAV_OK) goto cleanup;
      nav_cov_point p = make_point(imu.t_s, kf);
      if (fn(user, &p) == NAV_STOP) {
        st = NAV_ERR_CANCELLED;
        goto cleanup;
      }
    }
  }
cleanup:
  nav_filter_destroy(kf);
  nav_truth_destroy(truth);
  return st;
}
