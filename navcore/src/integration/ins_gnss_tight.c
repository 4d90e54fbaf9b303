/*
 * Tightly coupled INS/GNSS (nav_ins_gnss_update_raw, docs/ins-gnss-tight.md): the loosely coupled
 * object's INS, error-state filter and feedback, updated by pseudoranges and range rates instead
 * of position and velocity fixes. The filter carries the receiver clock (bias, drift) and, with
 * GPS and GLONASS, the inter-system bias as extra states (nav_filter.h).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "integration/ins_gnss_internal.h"
#include "navcore/nav_earth.h"

void nav_ins_gnss_tight_filter(const nav_scene *sc, nav_filter_config *c) {
  const nav_gnss_constellation_config *cc = &sc->gnss.constellation;
  const nav_gnss_raw_config *raw = &cc->raw;
  /* Pseudoranges replace the fixes: the receiver's position error states have no meaning here
   * (its code noise is white in this model, docs/ins-gnss-tight.md 2.2). */
  c->states &= ~(unsigned)NAV_FILTER_STATE_GNSS_POS_GM;
  c->states |= NAV_FILTER_STATE_RX_CLOCK;
  if (cc->gps != NAV_GNSS_SOURCE_OFF && cc->glonass != NAV_GNSS_SOURCE_OFF)
    c->states |= NAV_FILTER_STATE_RX_ISB;
  /* Brown and Hwang, 4th ed., section 9.3: S_f = h_0 / 2, S_g = 2 pi^2 h_-2 (fractional
   * frequency), times c^2 for metres. */
  const double c2 = NAV_GNSS_C_MPS * NAV_GNSS_C_MPS;
  c->clock_bias_q_m2ps = 0.5 * raw->clock_h0_s * c2;
  c->clock_drift_q_m2ps3 = 2.0 * NAV_PI * NAV_PI * raw->clock_hm2_per_s * c2;
  c->init.clock_bias_sd_m = raw->clock_bias_sd_m;
  c->init.clock_drift_sd_mps = raw->clock_drift_sd_mps;
  c->init.isb_sd_m = raw->isb_sd_m;
}

void nav_ins_gnss_clock(const nav_ins_gnss *x, double *bias_m, double *drift_mps) {
  double b = 0.0, d = 0.0;
  if (x) {
    const nav_filter_layout lay = nav_filter_get_layout(x->kf);
    if (lay.has_rx_clock) {
      const double *xs = nav_filter_get_state(x->kf);
      b = xs[lay.idx_clock];
      d = xs[lay.idx_clock + 1];
    }
  }
  if (bias_m) *bias_m = b;
  if (drift_mps) *drift_mps = d;
}

void nav_ins_gnss_raw_counts(const nav_ins_gnss *x, long *used, long *rejected) {
  if (used) *used = x ? x->raw_used : 0;
  if (rejected) *rejected = x ? x->raw_rejected : 0;
}

/* u^T M for a 3 x n block M (rows N, E, D) into one H row. */
static void project_rows(double *row, const double *M, nav_vec3 u, size_t n) {
  for (size_t j = 0; j < n; ++j)
    row[j] = u.x * M[j] + u.y * M[n + j] + u.z * M[2 * n + j];
}

void nav_ins_gnss_tight_geometry(nav_tight_geom *g, const nav_filter_layout *lay, const nav_filter_nav *nav,
                                 nav_geodetic pos, nav_vec3 l_ba_b_m) {
  g->lay = *lay;
  /* The antenna as the INS sees it: position and velocity in ECEF (docs/ins-gnss-tight.md 3). */
  g->C_n_e = nav_earth_dcm_n_e(pos.lat_rad, pos.lon_rad);
  const nav_vec3 r_eb_e = nav_earth_geodetic_to_ecef(pos);
  g->r_ea_e = nav_vec3_add(r_eb_e, nav_mat3_mul_vec(g->C_n_e, nav_mat3_mul_vec(nav->C_b_n, l_ba_b_m)));
  /* v_a = v + C_b_n (w_ib_b x l) - w_ie_n x (C_b_n l): the loose filter's velocity residual
   * against a zero measurement (E6.4). */
  const nav_vec3 v_ea_n = nav_filter_gnss_vel_residual(nav, l_ba_b_m, nav_vec3_zero());
  g->v_ea_e = nav_mat3_mul_vec(g->C_n_e, v_ea_n);
  nav_filter_build_H_pos(g->Hpos, lay, nav, l_ba_b_m);
  nav_filter_build_H_vel(g->Hvel, lay, nav, l_ba_b_m);
}

void nav_ins_gnss_tight_rows(const nav_tight_geom *g, const nav_gnss_orbit *sat, double t_gps_s, double *H_pr,
                             double *H_rr, double *rho_m, double *rr_mps) {
  const nav_filter_layout *lay = &g->lay;
  const size_t n = lay->n_states;
  /* Predicted range from the INS antenna (light time and Sagnac rotation, nav_gnss_sat.h). */
  nav_vec3 r_es_e;
  const double rho = nav_gnss_geometric_range_m(sat, t_gps_s, g->r_ea_e, &r_es_e);
  const nav_vec3 u_e = nav_vec3_scale(nav_vec3_sub(r_es_e, g->r_ea_e), 1.0 / rho);
  const nav_vec3 u_n = nav_mat3_tmul_vec(g->C_n_e, u_e);
  /* Pseudorange: z = P - rho_hat = u_n^T dr_a + b (+ isb) + e with dr_a = H_pos x
   * (docs/ins-gnss-tight.md 3.1). With one system only, its clock is the receiver clock. */
  project_rows(H_pr, g->Hpos, u_n, n);
  H_pr[lay->idx_clock] = 1.0;
  if (lay->has_isb && sat->system == NAV_GNSS_SYS_GLONASS) H_pr[lay->idx_isb] = 1.0;
  /* Range rate: the satellite velocity at the transmit time, rotated like its position (Sagnac),
   * and the rate of the moving geometry (u.(v_s - v_a)) / (1 + u.v_s / c); z = rr - rr_hat =
   * u_n^T dv_a + d + e with dv_a = H_vel x (docs/ins-gnss-tight.md 3.2). */
  const double tau = rho / NAV_GNSS_C_MPS;
  nav_vec3 r_tx, v_tx;
  nav_gnss_orbit_state(sat, t_gps_s - tau, &r_tx, &v_tx);
  const double a = NAV_GPS_OMEGA_E_RPS * tau, ca = cos(a), sa = sin(a);
  const nav_vec3 v_s = nav_vec3_make(ca * v_tx.x + sa * v_tx.y, -sa * v_tx.x + ca * v_tx.y, v_tx.z);
  const double us = nav_vec3_dot(u_e, v_s);
  project_rows(H_rr, g->Hvel, u_n, n);
  H_rr[lay->idx_clock + 1] = 1.0;
  *rho_m = rho;
  *rr_mps = (us - nav_vec3_dot(u_e, g->v_ea_e)) / (1.0 + us / NAV_GNSS_C_MPS);
}

/* Test one scalar measurement against the gate and apply it. */
static nav_status scalar_update(nav_ins_gnss *x, const double *H, double z, double r, bool *applied) {
  *applied = false;
  if (x->cfg.gate) {
    double nis = 0.0;
    const nav_status st = nav_filter_nis(x->kf, 1, H, &z, &r, &nis);
    if (st != NAV_OK) return st;
    if (!(nis <= x->cfg.gate_chi2)) return NAV_OK;
  }
  const nav_status st = nav_filter_update_linear(x->kf, 1, H, &z, &r);
  if (st == NAV_OK) *applied = true;
  return st;
}

nav_status nav_ins_gnss_update_raw(nav_ins_gnss *x, const nav_ins_gnss_raw_epoch *ep,
                                   nav_ins_gnss_raw_result *res) {
  if (!x || !ep || (ep->n > 0 && !ep->sats) || ep->n < 0 || ep->n > NAV_GNSS_MAX_SATS)
    return NAV_ERR_INVALID_ARG;
  if (!(ep->pr_sd_m > 0.0) || !(ep->rr_sd_mps > 0.0) || !isfinite(ep->pr_sd_m) || !isfinite(ep->rr_sd_mps) ||
      !isfinite(ep->t_gps_s)) {
    snprintf(x->err, sizeof x->err, "raw GNSS epoch at t = %.6f s: sigmas must be finite and > 0", ep->t_s);
    return NAV_ERR_INVALID_ARG;
  }
  const nav_filter_layout lay = nav_filter_get_layout(x->kf);
  if (!lay.has_rx_clock) {
    snprintf(x->err, sizeof x->err, "raw GNSS update needs the receiver-clock states (ins_gnss_tight)");
    return NAV_ERR_INVALID_ARG;
  }
  if (!x->have_step) {
    snprintf(x->err, sizeof x->err, "a GNSS epoch before the first IMU step (t = %.6f s)", ep->t_s);
    return NAV_ERR_STATE;
  }
  nav_ins_gnss_raw_result r0 = {0, 0, 0};
  nav_local_view v;
  const nav_filter_nav nav = nav_ins_gnss_epoch_nav(x, &v);
  nav_tight_geom geom;
  nav_ins_gnss_tight_geometry(&geom, &lay, &nav, v.pos, x->cfg.r_ba_b_m);
  double Hp[NAV_FILTER_MAX_STATES], Hr[NAV_FILTER_MAX_STATES];
  const double rp = ep->pr_sd_m * ep->pr_sd_m, rr = ep->rr_sd_mps * ep->rr_sd_mps;
  nav_status st = NAV_OK;
  for (int i = 0; i < ep->n && st == NAV_OK; ++i) {
    const nav_ins_gnss_sat_meas *m = &ep->sats[i];
    if (!m->sat) {
      snprintf(x->err, sizeof x->err, "raw GNSS epoch at t = %.6f s: measurement %d has no satellite",
               ep->t_s, i);
      st = NAV_ERR_INVALID_ARG;
      break;
    }
    if ((m->has_pr && !isfinite(m->pr_m)) || (m->has_rr && !isfinite(m->rr_mps))) {
      snprintf(x->err, sizeof x->err, "non-finite raw measurement of satellite %d at t = %.6f s", m->sat->prn,
               ep->t_s);
      st = NAV_ERR_NUMERIC;
      break;
    }
    double rho, rr_hat;
    nav_ins_gnss_tight_rows(&geom, m->sat, ep->t_gps_s, Hp, Hr, &rho, &rr_hat);
    bool applied = false;
    if (m->has_pr) {
      st = scalar_update(x, Hp, m->pr_m - rho, rp, &applied);
      if (st != NAV_OK) {
        snprintf(x->err, sizeof x->err, "pseudorange update (satellite %d) failed at t = %.6f s: %s",
                 m->sat->prn, ep->t_s, nav_filter_last_error(x->kf));
        break;
      }
      if (applied)
        r0.pr_used++;
      else
        r0.rejected++;
    }
    if (m->has_rr) {
      st = scalar_update(x, Hr, m->rr_mps - rr_hat, rr, &applied);
      if (st != NAV_OK) {
        snprintf(x->err, sizeof x->err, "range-rate update (satellite %d) failed at t = %.6f s: %s",
                 m->sat->prn, ep->t_s, nav_filter_last_error(x->kf));
        break;
      }
      if (applied)
        r0.rr_used++;
      else
        r0.rejected++;
    }
  }
  if (st != NAV_OK) return st;
  x->raw_used += r0.pr_used + r0.rr_used;
  x->raw_rejected += r0.rejected;
  if (res) *res = r0;
  if (r0.pr_used + r0.rr_used == 0) return NAV_OK;
  return nav_ins_gnss_feedback(x, &v, ep->t_s);
}
