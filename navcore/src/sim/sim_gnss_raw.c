/* Raw GNSS measurements of the tightly coupled scheme (docs/ins-gnss-tight.md section 2): the
 * pseudorange and range rate of every satellite of gnss.constellation visible from the true
 * trajectory, with the receiver's two-state clock, a GLONASS inter-system bias and white noise.
 * One object per Monte Carlo run; its random streams depend on (seed, run) only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_rng.h"
#include "sim/sim_internal.h"

struct nav_sim_gnss_raw {
  nav_gnss_constellation_config cc;
  nav_gnss_constellation c;
  nav_vec3 r_ba_b_m;        /* antenna lever arm */
  bool noise;               /* false with --ideal: no clock, no noise */
  double q_f, q_g;          /* clock spectral densities [m^2/s], [m^2/s^3] */
  double bias_m, drift_mps; /* receiver clock now */
  double t_clock_s;         /* time of the clock state */
  double isb_m;             /* GLONASS - GPS inter-system bias (both systems on) */
  nav_rng clock_rng;
  nav_rng code_rng[NAV_GNSS_MAX_SATS];
  nav_rng dopp_rng[NAV_GNSS_MAX_SATS];
  nav_gnss_sat_view views[NAV_GNSS_MAX_SATS];
  nav_ins_gnss_sat_meas meas[NAV_GNSS_MAX_SATS];
};

nav_status nav_sim_gnss_raw_create(const nav_scene *sc, uint64_t run, bool ideal, nav_sim_gnss_raw **out) {
  if (!sc || !out) return NAV_ERR_INVALID_ARG;
  nav_sim_gnss_raw *g = calloc(1, sizeof *g);
  if (!g) return NAV_ERR_NO_MEMORY;
  g->cc = sc->gnss.constellation;
  nav_status st = nav_gnss_constellation_build(&g->cc, &g->c);
  if (st != NAV_OK) {
    free(g);
    return st;
  }
  g->r_ba_b_m = sc->gnss.model.r_ba_b_m;
  g->noise = !ideal;
  const nav_gnss_raw_config *raw = &g->cc.raw;
  const double c2 = NAV_GNSS_C_MPS * NAV_GNSS_C_MPS;
  /* The filter's clock model (ins_gnss_tight.c): S_f = c^2 h_0 / 2, S_g = 2 pi^2 c^2 h_-2. */
  g->q_f = 0.5 * raw->clock_h0_s * c2;
  g->q_g = 2.0 * NAV_PI * NAV_PI * raw->clock_hm2_per_s * c2;
  const uint64_t seed = sc->simulation.seed;
  nav_rng_init(&g->clock_rng, seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_CLOCK, 1));
  for (int i = 0; i < g->c.n; ++i) {
    nav_rng_init(&g->code_rng[i], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_CODE, (unsigned)i));
    nav_rng_init(&g->dopp_rng[i], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_DOPPLER, (unsigned)i));
  }
  if (g->noise) {
    nav_rng r0;
    nav_rng_init(&r0, seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_CLOCK, 0));
    g->bias_m = raw->clock_bias_sd_m * nav_rng_gauss(&r0);
    g->drift_mps = raw->clock_drift_sd_mps * nav_rng_gauss(&r0);
    if (g->cc.gps != NAV_GNSS_SOURCE_OFF && g->cc.glonass != NAV_GNSS_SOURCE_OFF) {
      nav_rng ri;
      nav_rng_init(&ri, seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GNSS_ISB, 0));
      g->isb_m = raw->isb_sd_m * nav_rng_gauss(&ri);
    }
  }
  *out = g;
  return NAV_OK;
}

void nav_sim_gnss_raw_destroy(nav_sim_gnss_raw *g) {
  free(g);
}

/* Advance the receiver clock to t_s: the exact discrete form of b' = d + w_f, d' = w_g over T
 * (Brown and Hwang, 4th ed., eq. 9.3.11): Q = [[S_f T + S_g T^3/3, S_g T^2/2], [S_g T^2/2, S_g T]],
 * drawn through its Cholesky factor. */
static void clock_to(nav_sim_gnss_raw *g, double t_s) {
  const double T = t_s - g->t_clock_s;
  g->t_clock_s = t_s;
  if (!(T > 0.0) || !g->noise) return;
  const double q11 = g->q_f * T + g->q_g * T * T * T / 3.0, q12 = g->q_g * T * T / 2.0, q22 = g->q_g * T;
  const double l11 = sqrt(q11);
  const double l21 = l11 > 0.0 ? q12 / l11 : 0.0;
  const double l22 = sqrt(fmax(q22 - l21 * l21, 0.0));
  const double n1 = nav_rng_gauss(&g->clock_rng), n2 = nav_rng_gauss(&g->clock_rng);
  g->bias_m += g->drift_mps * T + l11 * n1;
  g->drift_mps += l21 * n1 + l22 * n2;
}

nav_status nav_sim_gnss_raw_measure(nav_sim_gnss_raw *g, const nav_frame *fr, const nav_traj_state *ts,
                                    nav_ins_gnss_raw_epoch *ep) {
  if (!g || !fr || !ts || !ep) return NAV_ERR_INVALID_ARG;
  const double t = ts->t_s, t_gps = g->cc.epoch_gps_s + t;
  const nav_local_view v = nav_frame_view(fr, ts->r_fb_f_m, ts->v_fb_f_mps, ts->q_b_f);
  const nav_mat3 C_b_n = nav_quat_to_dcm(v.q_b_n);
  /* Heading and visibility as the visibility outputs (gnss_dop.csv / gnss_sats.csv) compute them. */
  const double heading = atan2(C_b_n.m[1][0], C_b_n.m[0][0]);
  const nav_gnss_sky_mask mask = nav_gnss_constellation_mask_at(&g->cc, t);
  nav_gnss_dop dop;
  nav_status st = nav_gnss_visibility(&g->c, &mask, t_gps, v.pos, heading, g->views, &dop);
  if (st != NAV_OK) return st;
  clock_to(g, t);
  /* The true antenna in ECEF: r_a = r_b + C_b_e l, v_a = v_b + C_b_e (w_eb_b x l). */
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(v.pos.lat_rad, v.pos.lon_rad);
  const nav_mat3 C_b_e = nav_mat3_mul(C_n_e, C_b_n);
  const nav_vec3 r_eb_e = nav_earth_geodetic_to_ecef(v.pos);
  const nav_vec3 r_ea_e = nav_vec3_add(r_eb_e, nav_mat3_mul_vec(C_b_e, g->r_ba_b_m));
  const nav_vec3 v_eb_e = nav_mat3_mul_vec(C_n_e, v.v_n_mps);
  const nav_vec3 v_ea_e =
      nav_vec3_add(v_eb_e, nav_mat3_mul_vec(C_b_e, nav_vec3_cross(ts->w_fb_b_rps, g->r_ba_b_m)));
  const bool both = g->cc.gps != NAV_GNSS_SOURCE_OFF && g->cc.glonass != NAV_GNSS_SOURCE_OFF;
  int m = 0;
  for (int i = 0; i < g->c.n; ++i) {
    if (!g->views[i].visible) continue;
    const nav_gnss_orbit *o = &g->c.sats[i];
    const double rho = nav_gnss_geometric_range_m(o, t_gps, r_ea_e, NULL);
    /* The range rate of the true geometry: a central difference of the exact range (light time
     * and Sagnac included) with the antenna moved along its velocity. h = 0.5 s: GPS time as a
     * double has a spacing of 2.4e-7 s in 2026, which makes the range jitter by about 1e-4 m
     * (the satellite moves up to 1 mm in that time), 2e-4 m/s after dividing by 2 h; the
     * truncation rho''' h^2 / 6 of the satellite's motion stays near 1e-5 m/s (the antenna moves
     * on a straight line here, so its acceleration does not enter). */
    const double h = 0.5;
    const double rp = nav_gnss_geometric_range_m(o, t_gps + h, nav_vec3_axpy(r_ea_e, h, v_ea_e), NULL);
    const double rm = nav_gnss_geometric_range_m(o, t_gps - h, nav_vec3_axpy(r_ea_e, -h, v_ea_e), NULL);
    const double rdot = (rp - rm) / (2.0 * h);
    const bool glo = o->system == NAV_GNSS_SYS_GLONASS;
    double e_pr = 0.0, e_rr = 0.0;
    if (g->noise) {
      e_pr = g->cc.raw.code_sd_m * nav_rng_gauss(&g->code_rng[i]);
      e_rr = g->cc.raw.range_rate_sd_mps * nav_rng_gauss(&g->dopp_rng[i]);
    }
    nav_ins_gnss_sat_meas *s = &g->meas[m++];
    s->sat = o;
    s->has_pr = true;
    s->pr_m = rho + g->bias_m + (glo && both ? g->isb_m : 0.0) + e_pr;
    s->has_rr = true;
    s->rr_mps = rdot + g->drift_mps + e_rr;
  }
  ep->t_s = t;
  ep->t_gps_s = t_gps;
  ep->n = m;
  ep->sats = g->meas;
  ep->pr_sd_m = g->cc.raw.code_sd_m;
  ep->rr_sd_mps = g->cc.raw.range_rate_sd_mps;
  return NAV_OK;
}

void nav_sim_gnss_raw_clock(const nav_sim_gnss_raw *g, double *bias_m, double *drift_mps) {
  if (bias_m) *bias_m = g ? g->bias_m : 0.0;
  if (drift_mps) *drift_mps = g ? g->drift_mps : 0.0;
}
