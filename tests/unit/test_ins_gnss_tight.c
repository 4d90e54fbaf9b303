/*
 * The tightly coupled INS/GNSS (nav_ins_gnss_update_raw, docs/ins-gnss-tight.md):
 * - the receiver-clock states propagate with the exact two-state covariance (Van Loan, 1e-9);
 * - the pseudorange and range-rate rows are the Jacobians of the predicted range and range rate
 *   (finite differences of position, velocity, attitude and gyro bias; seeded, 40 cases);
 * - the predicted range rate agrees with the central difference of the exact range that the
 *   simulation uses (model error below 1 mm/s for a moving antenna with a lever arm);
 * - one satellite updates the filter (P shrinks along the line of sight only), a 1 km outlier is
 *   gated out, a GLONASS pseudorange moves the inter-system bias;
 * - with perfect sensors and measurements the canyon drive stays at the centimetre level.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "filter/filter_internal.h"
#include "integration/ins_gnss_internal.h"
#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_io.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sim.h"

#define CANYON NAV_SOURCE_DIR "/scenes/urban-canyon-tight.yaml"

/* GPS time in seconds since 1980 is a double: at 2026 its spacing is 2.4e-7 s, which moves a
 * satellite by up to 1 mm and a range by about 1e-4 m between neighbouring representable times.
 * The derivative checks run two weeks after the GPS epoch (spacing 2e-10 s) so that this
 * rounding stays far below the quantities compared. */
static double t_epoch(void) {
  return 2.0 * NAV_GNSS_WEEK_S + 8.0 * 3600.0;
}

static nav_gnss_constellation gps_glo(void) {
  nav_gnss_constellation c;
  c.n = 0;
  assert_int_equal(nav_gnss_add_gps_nominal(&c, t_epoch()), NAV_OK);
  assert_int_equal(nav_gnss_add_glonass_nominal(&c, t_epoch(), 0.0), NAV_OK);
  return c;
}

/* Clock states alone (core noise off): P of the clock block after T = 10 s of 0.01 s steps
 * equals Phi P0 Phi^T + Q(T), Q(T) = [[q_f T + q_g T^3/3, q_g T^2/2], [q_g T^2/2, q_g T]]. */
static void test_clock_propagation(void **state) {
  (void)state;
  nav_filter_config c = nav_filter_config_default();
  c.states = NAV_FILTER_STATE_RX_CLOCK;
  c.discretisation = NAV_FILTER_DISC_VAN_LOAN;
  c.clock_bias_q_m2ps = 9e-3;
  c.clock_drift_q_m2ps3 = 3.55e-2;
  c.init.clock_bias_sd_m = 100.0;
  c.init.clock_drift_sd_mps = 10.0;
  nav_filter *f = NULL;
  assert_int_equal(nav_filter_create(&c, &f), NAV_OK);
  const nav_filter_layout lay = nav_filter_get_layout(f);
  assert_true(lay.has_rx_clock);
  assert_int_equal(lay.n_states, 17);
  assert_int_equal(lay.idx_clock, 15);
  assert_int_equal(lay.n_ins, 15);
  nav_filter_nav nv;
  memset(&nv, 0, sizeof nv);
  nv.lat_rad = 0.9;
  nv.C_b_n = nav_mat3_identity();
  nv.f_ib_b_mps2 = nav_vec3_make(0.0, 0.0, -9.81);
  for (int k = 0; k < 1000; ++k)
    assert_int_equal(nav_filter_predict(f, &nv, 0.01), NAV_OK);
  const double *P = nav_filter_get_cov(f);
  const double T = 10.0, qf = c.clock_bias_q_m2ps, qg = c.clock_drift_q_m2ps3;
  const double pbb = 1e4 + T * T * 100.0 + qf * T + qg * T * T * T / 3.0;
  const double pbd = T * 100.0 + qg * T * T / 2.0, pdd = 100.0 + qg * T;
  const size_t n = lay.n_states, i = lay.idx_clock;
  assert_rel_near(P[i * n + i], pbb, 1e-9);
  assert_rel_near(P[i * n + i + 1], pbd, 1e-9);
  assert_rel_near(P[(i + 1) * n + i + 1], pdd, 1e-9);
  /* The clock is independent of the INS errors. */
  for (size_t j = 0; j < lay.n_ins; ++j)
    assert_true(P[j * n + i] == 0.0);
  /* The feedback reset keeps the clock estimate. */
  nav_filter_internal_state(f)[i] = 5.0;
  nav_filter_internal_state(f)[0] = 1.0;
  assert_int_equal(nav_filter_reset_errors(f), NAV_OK);
  assert_true(nav_filter_get_state(f)[i] == 5.0 && nav_filter_get_state(f)[0] == 0.0);
  nav_filter_destroy(f);
  /* The clock excludes the GNSS GM states; the ISB needs the clock. */
  c.states = NAV_FILTER_STATE_RX_CLOCK | NAV_FILTER_STATE_GNSS_POS_GM;
  assert_int_equal(nav_filter_config_validate(&c, NULL, NULL), NAV_ERR_INVALID_ARG);
  c.states = NAV_FILTER_STATE_RX_ISB;
  assert_int_equal(nav_filter_config_validate(&c, NULL, NULL), NAV_ERR_INVALID_ARG);
  c.states = NAV_FILTER_STATE_RX_CLOCK | NAV_FILTER_STATE_RX_ISB | NAV_FILTER_STATE_SCALE_FACTORS;
  assert_int_equal(nav_filter_config_validate(&c, NULL, NULL), NAV_OK);
  assert_int_equal(nav_filter_layout_of(c.states).n_states, NAV_FILTER_MAX_STATES);
}

/* A navigation state (geodetic position, NED velocity, attitude, rate) with its errors applied:
 * computed = true + dr (NED), v + dv, C = (I - [phi x]) C_true (E0.1), w + b_g. */
typedef struct nstate {
  nav_geodetic pos;
  nav_filter_nav nav;
} nstate;

static nstate perturbed(nstate s, nav_vec3 dr, nav_vec3 dv, nav_vec3 phi, nav_vec3 bg) {
  const double rm = nav_earth_radius_meridian_m(s.pos.lat_rad) + s.pos.h_m;
  const double rn = nav_earth_radius_prime_vertical_m(s.pos.lat_rad) + s.pos.h_m;
  s.pos.lat_rad += dr.x / rm;
  s.pos.lon_rad += dr.y / (rn * cos(s.pos.lat_rad));
  s.pos.h_m -= dr.z;
  s.nav.lat_rad = s.pos.lat_rad;
  s.nav.h_m = s.pos.h_m;
  s.nav.v_eb_n_mps = nav_vec3_add(s.nav.v_eb_n_mps, dv);
  /* exp(-[phi x]) C: the exact rotation whose first order is (I - [phi x]) C. */
  s.nav.C_b_n = nav_mat3_mul(nav_quat_to_dcm(nav_quat_from_rotvec(nav_vec3_scale(phi, -1.0))), s.nav.C_b_n);
  s.nav.w_ib_b_rps = nav_vec3_add(s.nav.w_ib_b_rps, bg);
  return s;
}

static void predict(const nstate *s, const nav_filter_layout *lay, nav_vec3 l, const nav_gnss_orbit *o,
                    double t, double *rho, double *rr, double *Hp, double *Hr) {
  nav_tight_geom g;
  nav_ins_gnss_tight_geometry(&g, lay, &s->nav, s->pos, l);
  double hp[NAV_FILTER_MAX_STATES], hr[NAV_FILTER_MAX_STATES];
  nav_ins_gnss_tight_rows(&g, o, t, Hp ? Hp : hp, Hr ? Hr : hr, rho, rr);
}

/* Jacobian check: rho_hat(true + dx) - rho_hat(true) = -H_pr dx (z = P - rho_hat = H x, x =
 * computed - true) to second order, per block; likewise the range rate. */
static void test_rows_are_jacobians(void **state) {
  (void)state;
  const nav_gnss_constellation c = gps_glo();
  const nav_filter_layout lay = nav_filter_layout_of(NAV_FILTER_STATE_RX_CLOCK | NAV_FILTER_STATE_RX_ISB);
  const uint64_t seed = 0x7417u;
  nav_rng r;
  nav_rng_init(&r, seed, 0, NAV_RNG_STREAM_USER << 8);
  int cases = 0;
  for (int k = 0; k < 40; ++k) {
    nstate s;
    s.pos = (nav_geodetic){(30.0 + 30.0 * nav_rng_uniform(&r)) * NAV_DEG2RAD,
                           20.0 * nav_rng_uniform(&r) * NAV_DEG2RAD, 100.0 * nav_rng_uniform(&r)};
    memset(&s.nav, 0, sizeof s.nav);
    s.nav.lat_rad = s.pos.lat_rad;
    s.nav.h_m = s.pos.h_m;
    s.nav.v_eb_n_mps = nav_vec3_make(20.0 * nav_rng_gauss(&r), 20.0 * nav_rng_gauss(&r), nav_rng_gauss(&r));
    const nav_euler e = {0.1 * nav_rng_gauss(&r), 0.1 * nav_rng_gauss(&r), 3.0 * nav_rng_gauss(&r)};
    s.nav.C_b_n = nav_euler_to_dcm(e);
    s.nav.w_ib_b_rps =
        nav_vec3_make(0.3 * nav_rng_gauss(&r), 0.3 * nav_rng_gauss(&r), 0.5 * nav_rng_gauss(&r));
    const nav_vec3 l = nav_vec3_make(0.8, -0.4, -1.3);
    const double t = t_epoch() + 3600.0 * nav_rng_uniform(&r);
    /* a satellite above the horizon */
    const nav_gnss_orbit *o = NULL;
    for (int i = 0; i < c.n && !o; ++i) {
      const nav_gnss_orbit *cand = &c.sats[(i + k * 7) % c.n];
      nav_vec3 rs, vs;
      nav_gnss_orbit_state(cand, t, &rs, &vs);
      double az, el;
      nav_gnss_az_el(s.pos, rs, &az, &el);
      if (el > 0.2) o = cand;
    }
    assert_non_null(o);
    double rho0, rr0, Hp[NAV_FILTER_MAX_STATES], Hr[NAV_FILTER_MAX_STATES];
    predict(&s, &lay, l, o, t, &rho0, &rr0, Hp, Hr);
    const size_t n = lay.n_states;
    assert_true(Hp[lay.idx_clock] == 1.0 && Hr[lay.idx_clock + 1] == 1.0);
    assert_true(Hp[lay.idx_isb] == (o->system == NAV_GNSS_SYS_GLONASS ? 1.0 : 0.0));
    /* Each block in turn: dr 1 m, dv 0.1 m/s, phi 1e-3 rad, b_g 1e-3 rad/s. */
    const nav_vec3 z = nav_vec3_zero();
    for (int blk = 0; blk < 4; ++blk)
      for (int ax = 0; ax < 3; ++ax) {
        const double h[4] = {1.0, 0.1, 1e-3, 1e-3};
        nav_vec3 d = z;
        nav_vec3_set(&d, ax, h[blk]);
        const nstate p = perturbed(s, blk == 0 ? d : z, blk == 1 ? d : z, blk == 2 ? d : z, blk == 3 ? d : z);
        double rho1, rr1;
        predict(&p, &lay, l, o, t, &rho1, &rr1, NULL, NULL);
        const size_t idx[4] = {NAV_FILTER_IDX_DR, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_BG};
        const size_t j = idx[blk] + (size_t)ax;
        /* Second-order terms: |dr|^2 / rho (1e-7 m), phi^2 |l| (2e-6 m); for the range rate the
         * line-of-sight change (|dr| / rho) |v_s| ~ 1e-4 m/s. */
        assert_near(rho1 - rho0, -Hp[j] * h[blk], 1e-5);
        assert_near(rr1 - rr0, -Hr[j] * h[blk], blk == 0 ? 3e-4 : 1e-5);
        ++cases;
      }
    (void)n;
  }
  print_message("%d Jacobian columns checked (seed %llu)\n", cases, (unsigned long long)seed);
}

/* The analytic range rate of the filter against the central difference of the exact range the
 * simulation uses (sim_gnss_raw.c) for an antenna moving at 25 m/s. */
static void test_range_rate_model(void **state) {
  (void)state;
  const nav_gnss_constellation c = gps_glo();
  const nav_filter_layout lay = nav_filter_layout_of(NAV_FILTER_STATE_RX_CLOCK | NAV_FILTER_STATE_RX_ISB);
  nstate s;
  s.pos = (nav_geodetic){52.52 * NAV_DEG2RAD, 13.405 * NAV_DEG2RAD, 35.0};
  memset(&s.nav, 0, sizeof s.nav);
  s.nav.lat_rad = s.pos.lat_rad;
  s.nav.h_m = s.pos.h_m;
  s.nav.v_eb_n_mps = nav_vec3_make(15.0, 20.0, -0.5);
  s.nav.C_b_n = nav_euler_to_dcm((nav_euler){0.02, -0.03, 0.9});
  s.nav.w_ib_b_rps = nav_vec3_make(0.01, -0.02, 0.25);
  const nav_vec3 l = nav_vec3_make(0.5, 0.0, -1.2);
  const double t = t_epoch() + 100.0;
  /* The true antenna in ECEF and its velocity relative to the Earth (w_eb = w_ib - C_n_b w_ie). */
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(s.pos.lat_rad, s.pos.lon_rad);
  const nav_vec3 r_a = nav_vec3_add(nav_earth_geodetic_to_ecef(s.pos),
                                    nav_mat3_mul_vec(C_n_e, nav_mat3_mul_vec(s.nav.C_b_n, l)));
  const nav_vec3 v_a = nav_mat3_mul_vec(C_n_e, nav_filter_gnss_vel_residual(&s.nav, l, nav_vec3_zero()));
  double worst = 0.0;
  int used = 0;
  for (int i = 0; i < c.n; ++i) {
    nav_vec3 rs, vs;
    nav_gnss_orbit_state(&c.sats[i], t, &rs, &vs);
    double az, el;
    nav_gnss_az_el(s.pos, rs, &az, &el);
    if (el < 0.1) continue;
    const double h = 0.01;
    const double rp = nav_gnss_geometric_range_m(&c.sats[i], t + h, nav_vec3_axpy(r_a, h, v_a), NULL);
    const double rm = nav_gnss_geometric_range_m(&c.sats[i], t - h, nav_vec3_axpy(r_a, -h, v_a), NULL);
    double rho, rr;
    predict(&s, &lay, l, &c.sats[i], t, &rho, &rr, NULL, NULL);
    worst = fmax(worst, fabs(rr - (rp - rm) / (2.0 * h)));
    ++used;
  }
  print_message(
      "range-rate model vs central difference of the exact range: %d satellites, largest %.3g m/s\n", used,
      worst);
  assert_true(used >= 8);
  assert_true(worst < 1e-3);
}

/* A tight nav_ins_gnss of the canyon scene at rest, after one IMU step. */
static nav_ins_gnss *tight_at_rest(nav_scene *sc, nav_ins_state *s0, double clock_sd_m) {
  assert_int_equal(nav_scene_read_file(CANYON, sc, NULL, NULL), NAV_OK);
  sc->gnss.constellation.glonass = NAV_GNSS_SOURCE_NOMINAL;
  sc->gnss.constellation.raw.clock_bias_sd_m = clock_sd_m;
  nav_ins_gnss_config xc = nav_ins_gnss_config_from_scene(sc);
  assert_true(nav_filter_layout_of(xc.filter.states).has_isb);
  const nav_geodetic p = {52.52 * NAV_DEG2RAD, 13.405 * NAV_DEG2RAD, 35.0};
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(p.lat_rad, p.lon_rad);
  s0->t_s = 0.0;
  s0->r_fb_f_m = nav_earth_geodetic_to_ecef(p);
  s0->v_fb_f_mps = nav_vec3_zero();
  s0->q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), nav_quat_identity()));
  nav_ins_gnss *x = NULL;
  assert_int_equal(nav_ins_gnss_create(&xc, s0, &x), NAV_OK);
  /* One 10 ms step at rest: the specific force balances gravity; the Earth rate in body axes. */
  const double g = nav_earth_gravity_normal_mps2(p.lat_rad, p.h_m);
  const nav_vec3 w_ie_n = nav_earth_rate_n_rps(p.lat_rad);
  nav_imu_increment inc = {1, 0.01, 0.01, nav_vec3_scale(w_ie_n, 0.01), nav_vec3_make(0.0, 0.0, -g * 0.01)};
  assert_int_equal(nav_ins_gnss_step(x, &inc), NAV_OK);
  return x;
}

static void test_one_satellite_and_gating(void **state) {
  (void)state;
  nav_scene *sc = malloc(sizeof *sc);
  nav_ins_state s0;
  /* First a receiver whose clock is known to 1 cm: the pseudorange then acts on the position. */
  nav_ins_gnss *x = tight_at_rest(sc, &s0, 0.01);
  const nav_filter *kf = nav_ins_gnss_filter(x);
  const nav_filter_layout lay = nav_filter_get_layout(kf);
  const size_t n = lay.n_states;
  const nav_gnss_constellation c = gps_glo();
  const double t = t_epoch() + 0.01;
  const nav_geodetic p = {52.52 * NAV_DEG2RAD, 13.405 * NAV_DEG2RAD, 35.0};
  /* The highest GPS satellite and the highest GLONASS one. */
  int best[2] = {-1, -1};
  double best_el[2] = {0.0, 0.0};
  for (int i = 0; i < c.n; ++i) {
    nav_vec3 rs, vs;
    nav_gnss_orbit_state(&c.sats[i], t, &rs, &vs);
    double az, el;
    nav_gnss_az_el(p, rs, &az, &el);
    const int k = c.sats[i].system == NAV_GNSS_SYS_GLONASS;
    if (el > best_el[k]) {
      best_el[k] = el;
      best[k] = i;
    }
  }
  assert_true(best[0] >= 0 && best[1] >= 0);
  nav_local_view v;
  const nav_filter_nav nv = nav_ins_gnss_epoch_nav(x, &v);
  double rho, rr, Hp[NAV_FILTER_MAX_STATES], Hr[NAV_FILTER_MAX_STATES];
  nav_tight_geom g;
  nav_ins_gnss_tight_geometry(&g, &lay, &nv, v.pos, sc->gnss.model.r_ba_b_m);
  nav_ins_gnss_tight_rows(&g, &c.sats[best[0]], t, Hp, Hr, &rho, &rr);
  /* Variance of the line-of-sight position error u^T dr before: */
  double P0[NAV_FILTER_MAX_STATES * NAV_FILTER_MAX_STATES];
  memcpy(P0, nav_filter_get_cov(kf), n * n * sizeof *P0);
  const nav_vec3 u = nav_vec3_make(Hp[0], Hp[1], Hp[2]);
  /* a direction across the line of sight */
  const nav_vec3 wc = nav_vec3_cross(u, nav_vec3_make(0.0, 0.0, 1.0));
  const nav_vec3 w = nav_vec3_scale(wc, 1.0 / nav_vec3_norm(wc));
  double vu0 = 0.0, vw0 = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      vu0 += nav_vec3_get(u, a) * P0[a * n + b] * nav_vec3_get(u, b);
      vw0 += nav_vec3_get(w, a) * P0[a * n + b] * nav_vec3_get(w, b);
    }
  /* One GPS satellite, its exact range. */
  nav_ins_gnss_sat_meas m = {&c.sats[best[0]], true, rho, true, rr};
  nav_ins_gnss_raw_epoch ep = {0.01, t, 1, &m, 3.0, 0.1};
  nav_ins_gnss_raw_result res;
  assert_int_equal(nav_ins_gnss_update_raw(x, &ep, &res), NAV_OK);
  assert_int_equal(res.pr_used, 1);
  assert_int_equal(res.rr_used, 1);
  assert_int_equal(res.rejected, 0);
  const double *P1 = nav_filter_get_cov(kf);
  double vu1 = 0.0, vw1 = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      vu1 += nav_vec3_get(u, a) * P1[a * n + b] * nav_vec3_get(u, b);
      vw1 += nav_vec3_get(w, a) * P1[a * n + b] * nav_vec3_get(w, b);
    }
  print_message("one satellite: line-of-sight position variance %.3f -> %.3f m^2, across %.3f -> %.3f m^2\n",
                vu0, vu1, vw0, vw1);
  /* Kalman: 1 / (1 / vu0 + 1 / 9) with sigma 3 m, plus the 1 cm clock. */
  assert_rel_near(vu1, 1.0 / (1.0 / vu0 + 1.0 / 9.0), 0.02);
  assert_rel_near(vw1, vw0, 0.02);
  nav_ins_gnss_destroy(x);
  /* Then the scene's receiver (clock unknown, 100 m): one pseudorange 40 m long goes into the
   * clock, and the position hardly moves (one satellite cannot separate them). */
  x = tight_at_rest(sc, &s0, 100.0);
  kf = nav_ins_gnss_filter(x);
  m.pr_m = rho + 40.0;
  assert_int_equal(nav_ins_gnss_update_raw(x, &ep, &res), NAV_OK);
  double b = 0.0, d = 0.0;
  nav_ins_gnss_clock(x, &b, &d);
  const nav_vec3 moved = nav_vec3_sub(nav_ins_gnss_state(x)->r_fb_f_m, s0.r_fb_f_m);
  print_message("clock unknown: clock estimate %.2f m after a pseudorange 40 m long; position moved %.3f m\n",
                b, nav_vec3_norm(moved));
  assert_true(b > 39.0 && b < 40.0);
  assert_true(nav_vec3_norm(moved) < 0.1);
  P1 = nav_filter_get_cov(kf);
  /* A 1 km outlier is gated out and changes nothing. */
  double Pb[NAV_FILTER_MAX_STATES * NAV_FILTER_MAX_STATES];
  memcpy(Pb, P1, n * n * sizeof *Pb);
  m.pr_m += 1000.0;
  m.has_rr = false;
  assert_int_equal(nav_ins_gnss_update_raw(x, &ep, &res), NAV_OK);
  assert_int_equal(res.pr_used, 0);
  assert_int_equal(res.rejected, 1);
  assert_memory_equal(Pb, nav_filter_get_cov(kf), n * n * sizeof *Pb);
  long used = 0, rejected = 0;
  nav_ins_gnss_raw_counts(x, &used, &rejected);
  assert_int_equal(used, 2);
  assert_int_equal(rejected, 1);
  /* A GLONASS pseudorange 25 m long (relative to the GPS clock) moves the ISB, not the clock. */
  nav_ins_gnss_tight_rows(&g, &c.sats[best[1]], t, Hp, Hr, &rho, &rr);
  nav_ins_gnss_sat_meas mg = {&c.sats[best[1]], true, rho + b + 25.0, false, 0.0};
  nav_ins_gnss_raw_epoch eg = {0.01, t, 1, &mg, 3.0, 0.1};
  assert_int_equal(nav_ins_gnss_update_raw(x, &eg, &res), NAV_OK);
  assert_int_equal(res.pr_used, 1);
  const double isb = nav_filter_get_state(kf)[lay.idx_isb];
  print_message("inter-system bias after one GLONASS pseudorange: %.2f m (25 m in the measurement)\n", isb);
  assert_true(isb > 15.0 && isb < 26.0);
  /* Bad input. */
  ep.pr_sd_m = 0.0;
  assert_int_equal(nav_ins_gnss_update_raw(x, &ep, &res), NAV_ERR_INVALID_ARG);
  ep.pr_sd_m = 3.0;
  m.pr_m = NAN;
  assert_int_equal(nav_ins_gnss_update_raw(x, &ep, &res), NAV_ERR_NUMERIC);
  nav_ins_gnss_destroy(x);
  free(sc);
}

/* Perfect sensors, perfect receiver (no clock, no noise): the tight loop through the canyon. */
static void test_ideal_canyon(void **state) {
  (void)state;
  nav_scene *sc = malloc(sizeof *sc);
  assert_int_equal(nav_scene_read_file(CANYON, sc, NULL, NULL), NAV_OK);
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.ideal = true;
  nav_sim_summary s;
  if (nav_sim_run(sim, &o, &s) != NAV_OK) fail_msg("%s", nav_sim_last_error(sim));
  print_message("ideal tight canyon: horizontal RMS %.3e m, max %.3e m; vertical RMS %.3e m\n",
                s.stats.pos_err_h_m.rms, s.stats.pos_err_h_m.max, s.stats.pos_err_v_m.rms);
  assert_true(s.stats.pos_err_h_m.max < 0.1);
  nav_sim_destroy(sim);
  free(sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_clock_propagation), cmocka_unit_test(test_rows_are_jacobians),
      cmocka_unit_test(test_range_rate_model),  cmocka_unit_test(test_one_satellite_and_gating),
      cmocka_unit_test(test_ideal_canyon),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
