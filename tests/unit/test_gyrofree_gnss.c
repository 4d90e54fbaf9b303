/*
 * Gyro-free INS aided by GNSS (nav_gyrofree_gnss.h, docs/gyro-free-gnss.md):
 * - closure: ideal array and a perfect receiver, the closed loop follows the reference;
 * - Monte Carlo (N = 200, fixed seeds) against the covariance analysis of the same filter along
 *   the reference: RMS over the runs / predicted sigma of every component of position, velocity,
 *   attitude and angular-rate error inside the 99 % chi-square band at ten epochs (including the
 *   end of an outage), and the 9-state and 12-state NEES inside the 95 % band on >= 90 % of the
 *   epochs; the filter model equals the truth's (white array noise, random-constant biases,
 *   white GNSS noise, initial errors drawn from P0);
 * - the same NEES through the simulation (nav_sim, mc_stats), bit-identical for 1 and 2 threads;
 * - fast rotation (centripetal terms dominant) stays stable with aiding;
 * - P symmetric positive definite through tiny and huge noise.
 *
 * Bands (numerics.md T6.5, T6.6): N s^2 / sigma^2 ~ chi2(N) for the RMS s over N runs; the mean
 * NEES of n states over M runs times M ~ chi2(n M). Quantiles from Wilson-Hilferty (accurate to
 * < 0.1 % at these sizes).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_array.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_gyrofree_gnss.h"
#include "navcore/nav_io.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"

/* chi2(k)/k quantile by Wilson-Hilferty. */
static double chi2_over_k(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + z * sqrt(a);
  return c * c * c;
}

/* A short car drive with two corners, a stop and a 5 s GNSS outage; cube6 array, r = 0.5 m. */
static const char k_scene[] =
    "format_version: 1\n"
    "name: gfg-test\n"
    "earth: {model: wgs84, origin: {lat_deg: 52.52, lon_deg: 13.405, h_m: 35}}\n"
    "trajectory:\n"
    "  type: waypoints\n"
    "  initial_attitude: {roll_deg: 0, pitch_deg: 0, yaw_deg: 90}\n"
    "  waypoints:\n"
    "    timing: speed\n"
    "    attitude_mode: ground\n"
    "    hold_start_s: 5\n"
    "    hold_end_s: 2\n"
    "    limits: {max_accel_mps2: 2, max_jerk_mps3: 2, max_lateral_accel_mps2: 3,\n"
    "             max_rate_dps: 30, max_ang_accel_dps2: 30, max_ang_jerk_dps3: 120}\n"
    "    points:\n"
    "      - {ned_m: [0, 0, 0], speed_mps: 0}\n"
    "      - {ned_m: [0, 150, 0], speed_mps: 10}\n"
    "      - {ned_m: [150, 150, 0], speed_mps: 8}\n"
    "      - {ned_m: [150, 300, 0], speed_mps: 0}\n"
    "imu: {rate_hz: 100}\n"
    "array:\n"
    "  layout: cube6\n"
    "  radius_m: 0.5\n"
    "  accel: {bias_turn_on_mg: 0.05, bias_gm_sigma_ug: 20, bias_gm_tau_s: 60, noise_density_ug_per_sqrt_hz: 20}\n"
    "  initial_rate_sd_dps: 0.01\n"
    "gnss:\n"
    "  enabled: true\n"
    "  update_rate_hz: 1\n"
    "  position_white_sigma_m: [1, 1, 2]\n"
    "  velocity_sigma_mps: [0.05, 0.05, 0.1]\n"
    "  lever_arm_b_m: [0.5, 0, -1.2]\n"
    "  outages: [[30, 35]]\n"
    "initial_errors: {position_m: [1, 1, 2], velocity_mps: 0.1, attitude_deg: [0.1, 0.1, 0.5]}\n"
    "navigation: {scheme: gyro_free_gnss, algorithm: high_order, frame: ned}\n"
    "output: {rate_hz: 1}\n"
    "simulation: {seed: 2121, runs: 200}\n";

static nav_scene read_scene(void) {
  nav_scene sc;
  const nav_status st = nav_scene_read_string(k_scene, strlen(k_scene), "gfg-test", &sc, NULL, NULL);
  if (st != NAV_OK) fail_msg("test scene: %s", nav_status_str(st));
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_OK);
  return sc;
}

/* ------------------------------------------------------------------ the Monte Carlo harness */

#define N_EPOCH_MAX 128
#define N_COMP 12 /* dr N/E/D, dv N/E/D, phi N/E/D, dw x/y/z */

typedef struct mc_acc {
  int n_ep;
  double t_s[N_EPOCH_MAX];
  double sum2[N_EPOCH_MAX][N_COMP];
  double nees9[N_EPOCH_MAX], nees12[N_EPOCH_MAX];
  double sigma_cov[N_EPOCH_MAX][N_COMP]; /* covariance analysis */
} mc_acc;

/* Quadratic form e^T P_sub^-1 e of the leading n x n block (the first 12 states are dr, dv, phi,
 * dw in the same order as the error vector). */
static double nees_of(const double *P, size_t nP, const double *e, size_t n) {
  double B[144], L[144], x[12];
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) B[i * n + j] = P[i * nP + j];
  assert_int_equal(nav_matn_cholesky(L, B, n), NAV_OK);
  nav_matn_chol_solve(x, L, e, n, 1);
  double q = 0.0;
  for (size_t i = 0; i < n; ++i) q += e[i] * x[i];
  return q;
}

/* Filter linearisation point from the reference at sample k (covariance analysis). */
static nav_filter_nav ref_nav(const nav_frame *fr, const nav_traj_state *ts, const nav_imu_increment *imu) {
  const nav_local_view v = nav_frame_view(fr, ts->r_fb_f_m, ts->v_fb_f_mps, ts->q_b_f);
  nav_filter_nav n = {v.pos.lat_rad, v.pos.h_m, v.v_n_mps, nav_quat_to_dcm(v.q_b_n),
                      nav_vec3_scale(imu->dv_b_mps, 1.0 / imu->dt_s),
                      nav_vec3_scale(imu->dtheta_b_rad, 1.0 / imu->dt_s)};
  return n;
}

/* R of a fix as the closed loop uses it (sd floored at 1 mm, 1 mm/s). */
static void fix_r(const nav_gnss_fix *fx, nav_vec3 *rp, nav_vec3 *rv) {
  for (int i = 0; i < 3; ++i) {
    const double sp = fmax(nav_vec3_get(fx->pos_sd_m, i), 1e-3), sv = fmax(nav_vec3_get(fx->vel_sd_mps, i), 1e-3);
    nav_vec3_set(rp, i, sp * sp);
    nav_vec3_set(rv, i, sv * sv);
  }
}

/* Covariance analysis: the filter driven by the reference (P does not depend on z), updates at
 * the receiver's epochs outside the outages, sigma at every output epoch (1 Hz). */
static void covariance_analysis(const nav_scene *sc, mc_acc *acc) {
  nav_truth *truth = NULL;
  assert_int_equal(nav_truth_create(sc, &truth), NAV_OK);
  const nav_frame fr = nav_truth_frame(truth);
  const nav_gyrofree_gnss_config xc = nav_gyrofree_gnss_config_from_scene(sc);
  nav_gfg_filter *kf = NULL;
  assert_int_equal(nav_gfg_filter_create(&xc.filter, &kf), NAV_OK);
  nav_gnss_model *gm = NULL;
  assert_int_equal(nav_gnss_model_create(&sc->gnss.model, &fr, 1, 0, &gm), NAV_OK);
  const int64_t n = nav_truth_sample_count(truth), stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  const size_t ns = nav_gfg_filter_n_states(kf);
  int64_t epoch = 1;
  int e = 0;
  for (int64_t k = 0; k <= n; ++k) {
    nav_traj_state ts;
    assert_int_equal(nav_truth_state(truth, (double)k / sc->imu.rate_hz, &ts), NAV_OK);
    if (k > 0) {
      nav_imu_increment imu;
      assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
      nav_filter_nav nv = ref_nav(&fr, &ts, &imu);
      assert_int_equal(nav_gfg_filter_predict(kf, &nv, imu.dt_s), NAV_OK);
      if (fabs(nav_gnss_model_epoch_time_s(gm, epoch) - imu.t_s) < 0.5 * imu.dt_s) {
        nav_gnss_fix fx;
        bool has = false;
        assert_int_equal(nav_gnss_model_measure(gm, epoch++, &ts, &fx, &has), NAV_OK);
        if (has) {
          nav_vec3 rp, rv;
          fix_r(&fx, &rp, &rv);
          const nav_vec3 z = nav_vec3_zero();
          assert_int_equal(nav_gfg_filter_update_pos(kf, &nv, z, rp, xc.r_ba_b_m), NAV_OK);
          assert_int_equal(nav_gfg_filter_update_vel(kf, &nv, z, rv, xc.r_ba_b_m), NAV_OK);
          nav_gfg_filter_reset_errors(kf);
        }
      }
    }
    if (k % stride == 0 && e < N_EPOCH_MAX) {
      const double *P = nav_gfg_filter_cov(kf);
      for (int c = 0; c < N_COMP; ++c) acc->sigma_cov[e][c] = sqrt(P[(size_t)c * ns + (size_t)c]);
      acc->t_s[e] = ts.t_s;
      ++e;
    }
  }
  acc->n_ep = e;
  nav_gnss_model_destroy(gm);
  nav_gfg_filter_destroy(kf);
  nav_truth_destroy(truth);
}

/* One Monte Carlo run of the closed loop, from the public pieces (array truth and error model,
 * receiver model, nav_gyrofree_gnss), with the full error vector at every output epoch. */
static void one_run(const nav_scene *sc, long run, mc_acc *acc) {
  nav_accel_array layout;
  assert_int_equal(nav_array_layout_from_scene(&sc->array, &layout), NAV_OK);
  nav_array_truth *at = NULL;
  assert_int_equal(nav_array_truth_create(sc, &layout, &at), NAV_OK);
  const nav_frame fr = nav_array_truth_frame(at);
  nav_array_model *am = NULL;
  assert_int_equal(nav_array_model_create(&sc->array.accel, layout.n_sensors, sc->simulation.seed, (uint64_t)run, &am),
                   NAV_OK);
  nav_gnss_model *gm = NULL;
  assert_int_equal(nav_gnss_model_create(&sc->gnss.model, &fr, sc->simulation.seed, (uint64_t)run, &gm), NAV_OK);
  /* Initial errors drawn from P0 (the scene's sigmas), NED at the true position. */
  nav_traj_state ts;
  assert_int_equal(nav_array_truth_state(at, 0.0, &ts), NAV_OK);
  nav_rng r;
  nav_rng_init(&r, sc->simulation.seed, (uint64_t)run, 0xfeedu);
  const nav_local_view v0 = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
  nav_vec3 dr = {0.0, 0.0, 0.0}, dv = dr, phi = dr, dw = dr;
  for (int i = 0; i < 3; ++i) {
    nav_vec3_set(&dr, i, nav_vec3_get(sc->initial_errors.pos_sd_m, i) * nav_rng_gauss(&r));
    nav_vec3_set(&dv, i, nav_vec3_get(sc->initial_errors.vel_sd_mps, i) * nav_rng_gauss(&r));
    nav_vec3_set(&phi, i, nav_vec3_get(sc->initial_errors.att_sd_rad, i) * nav_rng_gauss(&r));
    nav_vec3_set(&dw, i, nav_vec3_get(sc->array.initial_rate_sd_rps, i) * nav_rng_gauss(&r));
  }
  nav_ins_state s0 = {0.0, nav_vec3_add(ts.r_fb_f_m, nav_mat3_tmul_vec(v0.C_f_n, dr)),
                      nav_vec3_add(ts.v_fb_f_mps, nav_mat3_tmul_vec(v0.C_f_n, dv)), ts.q_b_f};
  s0.q_b_f = nav_quat_normalize(
      nav_quat_mul(nav_quat_from_rotvec(nav_vec3_scale(nav_mat3_tmul_vec(v0.C_f_n, phi), -1.0)), ts.q_b_f));
  nav_vec3 w0;
  assert_int_equal(nav_array_truth_rate(at, 0.0, &w0), NAV_OK);
  nav_gyrofree_gnss *x = NULL;
  const nav_gyrofree_gnss_config xc = nav_gyrofree_gnss_config_from_scene(sc);
  assert_int_equal(nav_gyrofree_gnss_create(&xc, &s0, nav_vec3_add(w0, dw), &x), NAV_OK);
  const int64_t n = nav_array_truth_sample_count(at), stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  int64_t epoch = 1;
  int e = 0;
  for (int64_t k = 0; k <= n; ++k) {
    if (k > 0) {
      nav_array_increment inc;
      assert_int_equal(nav_array_truth_sample(at, k, &inc), NAV_OK);
      assert_int_equal(nav_array_model_apply(am, &inc, &inc), NAV_OK);
      if (nav_gyrofree_gnss_step(x, &inc) != NAV_OK) fail_msg("run %ld: %s", run, nav_gyrofree_gnss_last_error(x));
      if (fabs(nav_gnss_model_epoch_time_s(gm, epoch) - inc.t_s) < 0.5 * inc.dt_s) {
        assert_int_equal(nav_array_truth_state(at, inc.t_s, &ts), NAV_OK);
        nav_gnss_fix fx;
        bool has = false;
        assert_int_equal(nav_gnss_model_measure(gm, epoch++, &ts, &fx, &has), NAV_OK);
        if (has) {
          nav_ins_gnss_fix f = {fx.t_s, fx.pos, fx.pos_sd_m, true, fx.v_fa_n_mps, fx.vel_sd_mps};
          if (nav_gyrofree_gnss_update(x, &f) != NAV_OK) fail_msg("run %ld: %s", run, nav_gyrofree_gnss_last_error(x));
        }
      }
    }
    if (k % stride != 0 || e >= acc->n_ep) continue;
    const double t = (double)k / sc->imu.rate_hz;
    assert_int_equal(nav_array_truth_state(at, t, &ts), NAV_OK);
    const nav_ins_state *s = nav_gyrofree_gnss_state(x);
    const nav_epoch_errors err = nav_errors_compute(&fr, &ts, s);
    const nav_local_view vt = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
    const nav_vec3 phi_n =
        nav_mat3_mul_vec(vt.C_f_n, nav_quat_to_rotvec(nav_quat_mul(ts.q_b_f, nav_quat_conj(s->q_b_f))));
    nav_vec3 w_true;
    assert_int_equal(nav_array_truth_rate(at, t, &w_true), NAV_OK);
    const nav_vec3 dw_k = nav_vec3_sub(nav_gyrofree_gnss_rate(x), w_true);
    const double ev[N_COMP] = {err.pos_err_n_m.x, err.pos_err_n_m.y, err.pos_err_n_m.z, err.vel_err_n_mps.x,
                               err.vel_err_n_mps.y, err.vel_err_n_mps.z, phi_n.x, phi_n.y, phi_n.z,
                               dw_k.x, dw_k.y, dw_k.z};
    for (int c = 0; c < N_COMP; ++c) acc->sum2[e][c] += ev[c] * ev[c];
    const double *P = nav_gfg_filter_cov(nav_gyrofree_gnss_filter(x));
    const size_t ns = nav_gfg_filter_n_states(nav_gyrofree_gnss_filter(x));
    acc->nees9[e] += nees_of(P, ns, ev, 9);
    acc->nees12[e] += nees_of(P, ns, ev, 12);
    ++e;
  }
  nav_gyrofree_gnss_destroy(x);
  nav_gnss_model_destroy(gm);
  nav_array_model_destroy(am);
  nav_array_truth_destroy(at);
}

/* ------------------------------------------------------------------ tests */

typedef struct track {
  double h_max_m, v_max_m, att_max_rad, vel_max_mps, h_final_m;
  long n;
} track;

static nav_callback_result keep_max(void *user, const nav_sim_record *r) {
  track *t = user;
  if (r->err->pos_err_h_m > t->h_max_m) t->h_max_m = r->err->pos_err_h_m;
  if (r->err->pos_err_v_m > t->v_max_m) t->v_max_m = r->err->pos_err_v_m;
  if (r->err->att_err_rad > t->att_max_rad) t->att_max_rad = r->err->att_err_rad;
  if (r->err->vel_err_mps > t->vel_max_mps) t->vel_max_mps = r->err->vel_err_mps;
  t->h_final_m = r->err->pos_err_h_m;
  t->n++;
  return NAV_CONTINUE;
}

static track run_ideal(const nav_scene *sc) {
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.ideal = true;
  track t;
  memset(&t, 0, sizeof t);
  o.record = keep_max;
  o.user = &t;
  nav_sim_summary sum;
  if (nav_sim_run(sim, &o, &sum) != NAV_OK) fail_msg("%s", nav_sim_last_error(sim));
  nav_sim_destroy(sim);
  return t;
}

/*
 * Closure: an ideal array and a perfect receiver (the receiver's R floored at 1 mm, 1 mm/s).
 * The closed loop must follow the reference well inside that floor: position and velocity
 * below 1 mm and 1 mm/s, attitude below 1e-4 rad, an order below the 7.7e-4 rad that a 1 mm
 * position floor resolves over the 1.3 m lever arm (the filter turns the INS's truncation
 * residuals into attitude corrections of that size; the free gyro-free INS on the same drive is
 * printed beside it). The residual comes from the algorithm's truncation, so halving dt must
 * shrink it at least twofold (measured: 2.9 x in position, 3.9 x in attitude).
 */
static void test_ideal_closure(void **state) {
  (void)state;
  nav_scene sc = read_scene();
  const track a = run_ideal(&sc);
  sc.imu.rate_hz = 200.0;
  const track b = run_ideal(&sc);
  sc.imu.rate_hz = 100.0;
  sc.navigation.scheme = NAV_SCHEME_GYRO_FREE;
  sc.gnss.enabled = false;
  const track f = run_ideal(&sc);
  print_message("closure (ideal array, perfect receiver): max horizontal %.3g m, vertical %.3g m, velocity %.3g m/s, "
                "attitude %.3g rad at 100 Hz; %.3g m, %.3g rad at 200 Hz; free gyro-free INS %.3g m, %.3g rad\n",
                a.h_max_m, a.v_max_m, a.vel_max_mps, a.att_max_rad, b.h_max_m, b.att_max_rad, f.h_max_m, f.att_max_rad);
  assert_true(a.n > 10);
  assert_true(a.h_max_m < 1e-3 && a.v_max_m < 1e-3 && a.vel_max_mps < 1e-3);
  assert_true(a.att_max_rad < 1e-4);
  assert_true(2.0 * b.h_max_m < a.h_max_m && 2.0 * b.att_max_rad < a.att_max_rad);
}

/*
 * Monte Carlo (200 runs) against the covariance analysis: RMS / sigma of each of the 12
 * components in the 99 % band of chi2(200) at ten epochs spread over the drive, the end of the
 * outage included; the 9- and 12-state mean NEES in the 95 % band of chi2(n M)/M on >= 90 % of
 * the epochs.
 */
static void test_mc_vs_covariance(void **state) {
  (void)state;
  const nav_scene sc = read_scene();
  mc_acc *acc = calloc(1, sizeof *acc);
  assert_non_null(acc);
  covariance_analysis(&sc, acc);
  const long M = sc.simulation.runs;
  assert_true(M >= 200);
  for (long run = 0; run < M; ++run) one_run(&sc, run, acc);
  const double kN = (double)M;
  const double lo99 = sqrt(chi2_over_k(kN, -2.5758)), hi99 = sqrt(chi2_over_k(kN, 2.5758));
  const double lo9 = 9.0 * chi2_over_k(9.0 * kN, -1.96), hi9 = 9.0 * chi2_over_k(9.0 * kN, 1.96);
  const double lo12 = 12.0 * chi2_over_k(12.0 * kN, -1.96), hi12 = 12.0 * chi2_over_k(12.0 * kN, 1.96);
  /* Ten epochs: every 1/10 of the run, with the end of the outage (35 s) in place of the nearest. */
  const int n_ep = acc->n_ep;
  int ep[10];
  for (int i = 0; i < 10; ++i) ep[i] = (int)llround((double)(i + 1) * (double)(n_ep - 1) / 10.0);
  int e_out = 0;
  for (int e = 0; e < n_ep; ++e)
    if (fabs(acc->t_s[e] - 35.0) < 1e-9) e_out = e;
  assert_true(e_out > 0);
  int near = 0;
  for (int i = 1; i < 10; ++i)
    if (abs(ep[i] - e_out) < abs(ep[near] - e_out)) near = i;
  ep[near] = e_out;
  static const char *names[N_COMP] = {"dr_N", "dr_E", "dr_D", "dv_N", "dv_E", "dv_D",
                                      "phi_N", "phi_E", "phi_D", "dw_x", "dw_y", "dw_z"};
  int outside = 0;
  for (int i = 0; i < 10; ++i) {
    const int e = ep[i];
    char line[512];
    int len = snprintf(line, sizeof line, "t = %5.1f s RMS/sigma:", acc->t_s[e]);
    for (int c = 0; c < N_COMP; ++c) {
      const double ratio = sqrt(acc->sum2[e][c] / kN) / acc->sigma_cov[e][c];
      len += snprintf(line + len, sizeof line - (size_t)len, " %s %.3f", names[c], ratio);
      if (!(ratio > lo99 && ratio < hi99)) {
        ++outside;
        len += snprintf(line + len, sizeof line - (size_t)len, "(!)");
      }
    }
    print_message("%s\n", line);
  }
  int in9 = 0, in12 = 0;
  double m9 = 0.0, m12 = 0.0;
  for (int e = 0; e < n_ep; ++e) {
    const double a9 = acc->nees9[e] / kN, a12 = acc->nees12[e] / kN;
    in9 += a9 > lo9 && a9 < hi9;
    in12 += a12 > lo12 && a12 < hi12;
    m9 += a9;
    m12 += a12;
  }
  print_message("99 %% band [%.3f, %.3f]: %d of %d ratios outside; NEES 9: mean %.3f, %d of %d epochs in [%.3f, %.3f]; "
                "NEES 12: mean %.3f, %d of %d in [%.3f, %.3f]\n",
                lo99, hi99, outside, 10 * N_COMP, m9 / n_ep, in9, n_ep, lo9, hi9, m12 / n_ep, in12, n_ep, lo12, hi12);
  free(acc);
  /* 120 ratios at 1 % each: about one outside by chance; epochs of one run are correlated, so
   * allow two (P(>2) ~ 0.12 for independent tests, a fixed seed makes it reproducible). */
  assert_true(outside <= 2);
  assert_true((double)in9 >= 0.9 * (double)n_ep);
  assert_true((double)in12 >= 0.9 * (double)n_ep);
}

/*
 * The simulation (navsim run): the same scene through nav_sim, 200 runs on 2 threads: mc_stats'
 * 9-state NEES in the 95 % band on >= 90 % of the output epochs and the RMS of north, east and
 * down position in the 99 % band of the covariance analysis at the ten epochs of the test above
 * (>= 28 of 30); 30 runs on 1 and 3 threads give bit-identical envelopes and final errors.
 */
static void run_sim(const nav_scene *sc, int threads, nav_sim **out, nav_sim_summary *sum) {
  assert_int_equal(nav_sim_create(sc, out), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = threads;
  if (nav_sim_run(*out, &o, sum) != NAV_OK) fail_msg("%s", nav_sim_last_error(*out));
}

static void test_sim_nees_and_threads(void **state) {
  (void)state;
  nav_scene sc = read_scene();
  mc_acc *acc = calloc(1, sizeof *acc);
  assert_non_null(acc);
  covariance_analysis(&sc, acc);
  nav_sim *sim = NULL;
  nav_sim_summary sum;
  run_sim(&sc, 2, &sim, &sum);
  size_t ne = 0;
  const nav_sim_envelope_point *env = nav_sim_envelope(sim, &ne);
  assert_non_null(env);
  /* The simulation adds the last sample (t = duration) when it is not on the output grid. */
  assert_true((int)ne >= acc->n_ep);
  for (int e = 0; e < acc->n_ep; ++e) assert_near(env[e].t_s, acc->t_s[e], 1e-9);
  ne = (size_t)acc->n_ep;
  const double M = (double)sc.simulation.runs;
  const double lo9 = 9.0 * chi2_over_k(9.0 * M, -1.96), hi9 = 9.0 * chi2_over_k(9.0 * M, 1.96);
  const double lo99 = sqrt(chi2_over_k(M, -2.5758)), hi99 = sqrt(chi2_over_k(M, 2.5758));
  size_t in9 = 0;
  for (size_t e = 0; e < ne; ++e) in9 += env[e].nees9_mean > lo9 && env[e].nees9_mean < hi9;
  int in_rms = 0;
  for (int i = 1; i <= 10; ++i) {
    const size_t e = (size_t)llround((double)i * (double)(ne - 1) / 10.0);
    const double r[3] = {env[e].pos_rms_n_m.x / acc->sigma_cov[e][0], env[e].pos_rms_n_m.y / acc->sigma_cov[e][1],
                         env[e].pos_rms_n_m.z / acc->sigma_cov[e][2]};
    for (int c = 0; c < 3; ++c) in_rms += r[c] > lo99 && r[c] < hi99;
    print_message("nav_sim t = %5.1f s: position RMS/sigma N %.3f E %.3f D %.3f, NEES %.3f\n", env[e].t_s, r[0], r[1],
                  r[2], env[e].nees9_mean);
  }
  print_message("nav_sim NEES (9 states, %.0f runs): %zu of %zu epochs in [%.3f, %.3f]; %d of 30 ratios in [%.3f, %.3f]\n",
                M, in9, ne, lo9, hi9, in_rms, lo99, hi99);
  assert_true((double)in9 >= 0.9 * (double)ne);
  assert_true(in_rms >= 28);
  nav_sim_destroy(sim);
  free(acc);

  sc.simulation.runs = 30;
  nav_sim *s1 = NULL, *s3 = NULL;
  nav_sim_summary a, b;
  run_sim(&sc, 1, &s1, &a);
  run_sim(&sc, 3, &s3, &b);
  size_t n1 = 0, n3 = 0, f1 = 0, f3 = 0;
  const nav_sim_envelope_point *e1 = nav_sim_envelope(s1, &n1), *e3 = nav_sim_envelope(s3, &n3);
  const nav_sim_run_final *r1 = nav_sim_finals(s1, &f1), *r3 = nav_sim_finals(s3, &f3);
  assert_int_equal(n1, n3);
  assert_int_equal(f1, f3);
  assert_int_equal(f1, 30);
  assert_memory_equal(e1, e3, n1 * sizeof *e1);
  assert_memory_equal(r1, r3, f1 * sizeof *r1);
  nav_sim_destroy(s1);
  nav_sim_destroy(s3);
}

/*
 * Fast rotation, where the centripetal terms dominate (numerics.md 1.5 item 5): a body spinning
 * at 300 rpm about x (centripetal acceleration 99 m/s^2 at the 0.1 m arm), 1 kHz array, GNSS at
 * 10 Hz. Alone the gyro-free INS is lost within seconds; aided, every one of 20 runs completes
 * (P positive definite at every step), the final horizontal error stays at the receiver's
 * level (RMS < 3 m for 1 m per axis) and the filter's 9-state NEES at the end is not far off
 * (the mean over 20 runs below the 99.9 % point of chi2(180)/20).
 */
static const char k_spin[] =
    "format_version: 1\n"
    "name: gfg-spin\n"
    "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 300}}\n"
    "trajectory:\n"
    "  type: test_motion\n"
    "  duration_s: 10\n"
    "  test_motion: {kind: spin, spin_rate_rpm: 300, spin_axis_b: [1, 0, 0]}\n"
    "imu: {rate_hz: 1000}\n"
    "array:\n"
    "  layout: cube6\n"
    "  radius_m: 0.1\n"
    "  accel: {bias_turn_on_mg: 0.05, bias_gm_sigma_ug: 20, bias_gm_tau_s: 60, noise_density_ug_per_sqrt_hz: 20}\n"
    "  initial_rate_sd_dps: 0.01\n"
    "gnss:\n"
    "  enabled: true\n"
    "  update_rate_hz: 10\n"
    "  position_white_sigma_m: [1, 1, 2]\n"
    "  velocity_sigma_mps: [0.05, 0.05, 0.1]\n"
    "  lever_arm_b_m: [0.3, 0, 0]\n"
    "initial_errors: {position_m: [1, 1, 2], velocity_mps: 0.1, attitude_deg: [0.1, 0.1, 0.5]}\n"
    "navigation: {scheme: gyro_free_gnss, algorithm: high_order, frame: ned}\n"
    "output: {rate_hz: 10}\n"
    "simulation: {seed: 2122, runs: 20}\n";

static void test_fast_rotation_stable(void **state) {
  (void)state;
  nav_scene sc;
  if (nav_scene_read_string(k_spin, strlen(k_spin), "gfg-spin", &sc, NULL, NULL) != NAV_OK) fail_msg("spin scene");
  nav_sim *sim = NULL;
  nav_sim_summary sum;
  run_sim(&sc, 2, &sim, &sum);
  size_t ne = 0, nf = 0;
  const nav_sim_envelope_point *env = nav_sim_envelope(sim, &ne);
  nav_sim_finals(sim, &nf);
  assert_int_equal(nf, 20);
  const double hi = 9.0 * chi2_over_k(9.0 * 20.0, 3.09);
  print_message("spin 300 rpm aided: final horizontal RMS %.3f m, attitude RMS %.3g rad, NEES %.3f (limit %.3f)\n",
                sum.final_rms.pos_err_h_m, sum.final_rms.att_err_rad, env[ne - 1].nees9_mean, hi);
  assert_true(sum.final_rms.pos_err_h_m < 3.0);
  assert_true(env[ne - 1].nees9_mean < hi);
  nav_sim_destroy(sim);
  /* The same array without aiding. */
  sc.navigation.scheme = NAV_SCHEME_GYRO_FREE;
  sc.gnss.enabled = false;
  sc.simulation.runs = 4;
  run_sim(&sc, 2, &sim, &sum);
  print_message("spin 300 rpm free gyro-free INS: final horizontal RMS %.3g m\n", sum.final_rms.pos_err_h_m);
  nav_sim_destroy(sim);
}

/*
 * P stays symmetric and positive definite through tiny and huge noise (the cases of
 * test_filter_hard for the gyro INS filter): the filter along the test drive's reference, fixes
 * at 10 Hz, with
 *  - tiny: sensor noise and biases 1e-9 of nominal, P0 1e-4 m, 1e-6 m/s, 1e-9 rad, 1e-9 rad/s,
 *    R sigma 1e-4 m and 1e-6 m/s;
 *  - huge: noise 20 mg/sqrt(Hz), biases 50 mg, P0 10 km, 100 m/s, 1 rad, 0.1 rad/s, R sigma
 *    100 m and 10 m/s;
 *  - RTK: nominal sensors and P0, R sigma 1 cm and 5 mm/s;
 * every predict and update NAV_OK, P exactly symmetric after each, and our own Cholesky of P
 * succeeding after each.
 */
typedef struct spd_case {
  const char *name;
  double noise_scale, p0_pos_m, p0_vel_mps, p0_att_rad, p0_rate_rps, r_pos_m, r_vel_mps;
} spd_case;

static void test_p_spd_tiny_huge(void **state) {
  (void)state;
  const nav_scene sc = read_scene();
  const spd_case cases[3] = {{"tiny", 1e-9, 1e-4, 1e-6, 1e-9, 1e-9, 1e-4, 1e-6},
                             {"huge", 1e3, 1e4, 100.0, 1.0, 0.1, 100.0, 10.0},
                             {"RTK", 1.0, 1.0, 0.1, 0.01, 1e-3, 0.01, 0.005}};
  for (int c = 0; c < 3; ++c) {
    const spd_case *cs = &cases[c];
    nav_truth *truth = NULL;
    assert_int_equal(nav_truth_create(&sc, &truth), NAV_OK);
    const nav_frame fr = nav_truth_frame(truth);
    nav_gyrofree_gnss_config xc = nav_gyrofree_gnss_config_from_scene(&sc);
    xc.filter.vrw_mps_per_sqrt_s *= cs->noise_scale;
    xc.filter.bias_const_sd_mps2 *= cs->noise_scale;
    xc.filter.bias_sd_floor_mps2 = xc.filter.bias_const_sd_mps2;
    xc.filter.pos_sd_m = nav_vec3_make(cs->p0_pos_m, cs->p0_pos_m, cs->p0_pos_m);
    xc.filter.vel_sd_mps = nav_vec3_make(cs->p0_vel_mps, cs->p0_vel_mps, cs->p0_vel_mps);
    xc.filter.att_sd_rad = nav_vec3_make(cs->p0_att_rad, cs->p0_att_rad, cs->p0_att_rad);
    xc.filter.rate_sd_rps = nav_vec3_make(cs->p0_rate_rps, cs->p0_rate_rps, cs->p0_rate_rps);
    nav_gfg_filter *kf = NULL;
    assert_int_equal(nav_gfg_filter_create(&xc.filter, &kf), NAV_OK);
    const size_t ns = nav_gfg_filter_n_states(kf);
    const double rp1 = cs->r_pos_m * cs->r_pos_m, rv1 = cs->r_vel_mps * cs->r_vel_mps;
    const nav_vec3 rp = nav_vec3_make(rp1, rp1, 4.0 * rp1), rv = nav_vec3_make(rv1, rv1, 4.0 * rv1);
    const int64_t n = nav_truth_sample_count(truth);
    for (int64_t k = 1; k <= n; ++k) {
      nav_traj_state ts;
      nav_imu_increment imu;
      assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
      assert_int_equal(nav_truth_state(truth, imu.t_s, &ts), NAV_OK);
      nav_filter_nav nv = ref_nav(&fr, &ts, &imu);
      for (int step = 0; step < (k % 10 == 0 ? 3 : 1); ++step) {
        nav_status st = step == 0   ? nav_gfg_filter_predict(kf, &nv, imu.dt_s)
                        : step == 1 ? nav_gfg_filter_update_pos(kf, &nv, nav_vec3_zero(), rp, xc.r_ba_b_m)
                                    : nav_gfg_filter_update_vel(kf, &nv, nav_vec3_zero(), rv, xc.r_ba_b_m);
        if (st != NAV_OK) fail_msg("%s, k = %lld, step %d: %s", cs->name, (long long)k, step, nav_gfg_filter_last_error(kf));
        const double *P = nav_gfg_filter_cov(kf);
        double L[NAV_GFG_MAX_STATES * NAV_GFG_MAX_STATES];
        for (size_t i = 0; i < ns; ++i)
          for (size_t j = 0; j < i; ++j)
            if (P[i * ns + j] != P[j * ns + i]) fail_msg("%s: P not symmetric at (%zu, %zu), k = %lld", cs->name, i, j, (long long)k);
        if (nav_matn_cholesky(L, P, ns) != NAV_OK) fail_msg("%s: P not positive definite, k = %lld", cs->name, (long long)k);
      }
      if (k % 10 == 0) nav_gfg_filter_reset_errors(kf);
    }
    const double *P = nav_gfg_filter_cov(kf);
    print_message("%-5s: final sigma north %.3g m, yaw %.3g rad, dw_z %.3g rad/s, beta_w_z %.3g rad/s^2\n", cs->name,
                  sqrt(P[0]), sqrt(P[8 * ns + 8]), sqrt(P[11 * ns + 11]), sqrt(P[17 * ns + 17]));
    nav_gfg_filter_destroy(kf);
    nav_truth_destroy(truth);
  }
}

/*
 * Observability (docs/gyro-free-gnss.md section 5), by covariance analysis: at rest, GNSS makes
 * the level components of the rate error and of the angular-acceleration bias observable (their
 * sigma falls well below P0) but not the vertical one (beta_w,z stays at its prior, dw_z grows);
 * the drive with its turns and speed changes calibrates the vertical component too.
 */
static void final_sigmas(const nav_scene *sc, double *sd0, double *sd1) {
  nav_truth *truth = NULL;
  assert_int_equal(nav_truth_create(sc, &truth), NAV_OK);
  const nav_frame fr = nav_truth_frame(truth);
  const nav_gyrofree_gnss_config xc = nav_gyrofree_gnss_config_from_scene(sc);
  nav_gfg_filter *kf = NULL;
  assert_int_equal(nav_gfg_filter_create(&xc.filter, &kf), NAV_OK);
  const size_t ns = nav_gfg_filter_n_states(kf);
  for (size_t i = 0; i < ns; ++i) sd0[i] = sqrt(nav_gfg_filter_cov(kf)[i * ns + i]);
  const int64_t n = nav_truth_sample_count(truth);
  const nav_vec3 rp = nav_vec3_make(1.0, 1.0, 4.0), rv = nav_vec3_make(0.0025, 0.0025, 0.01);
  for (int64_t k = 1; k <= n; ++k) {
    nav_traj_state ts;
    nav_imu_increment imu;
    assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
    assert_int_equal(nav_truth_state(truth, imu.t_s, &ts), NAV_OK);
    nav_filter_nav nv = ref_nav(&fr, &ts, &imu);
    assert_int_equal(nav_gfg_filter_predict(kf, &nv, imu.dt_s), NAV_OK);
    if (k % 100 == 0) {
      assert_int_equal(nav_gfg_filter_update_pos(kf, &nv, nav_vec3_zero(), rp, xc.r_ba_b_m), NAV_OK);
      assert_int_equal(nav_gfg_filter_update_vel(kf, &nv, nav_vec3_zero(), rv, xc.r_ba_b_m), NAV_OK);
    }
  }
  for (size_t i = 0; i < ns; ++i) sd1[i] = sqrt(nav_gfg_filter_cov(kf)[i * ns + i]);
  nav_gfg_filter_destroy(kf);
  nav_truth_destroy(truth);
}

static void test_observability(void **state) {
  (void)state;
  nav_scene drive = read_scene();
  /* Turn-on biases only: with a Gauss-Markov part too, beta holds only that part (the
   * constant part has its own states) and the sums are what is observable. */
  drive.array.accel.terms &= ~(unsigned)NAV_IMU_TERM_BIAS_GM;
  nav_scene rest = drive;
  rest.trajectory.type = NAV_TRAJ_TEST_MOTION;
  rest.trajectory.test_motion.kind = NAV_TEST_MOTION_STATIONARY;
  rest.trajectory.duration_s = 62.0;
  rest.trajectory.initial_attitude = (nav_euler){0.0, 0.0, 0.5 * NAV_PI};
  assert_int_equal(nav_scene_validate(&rest, NULL, NULL), NAV_OK);
  double r0[NAV_GFG_MAX_STATES], r1[NAV_GFG_MAX_STATES], d0[NAV_GFG_MAX_STATES], d1[NAV_GFG_MAX_STATES];
  final_sigmas(&rest, r0, r1);
  final_sigmas(&drive, d0, d1);
  static const char *nm[9] = {"dw_x", "dw_y", "dw_z", "beta_f_x", "beta_f_y", "beta_f_z", "beta_w_x", "beta_w_y", "beta_w_z"};
  for (int i = 0; i < 9; ++i)
    print_message("%-9s P0 %.3g, after 62 s at rest %.3g (x%.3f), after the drive %.3g (x%.3f)\n", nm[i], r0[9 + i],
                  r1[9 + i], r1[9 + i] / r0[9 + i], d1[9 + i], d1[9 + i] / d0[9 + i]);
  const int bwx = NAV_GFG_IDX_BW, bwz = NAV_GFG_IDX_BW + 2, dwz = NAV_GFG_IDX_DW + 2;
  /* At rest: level beta_w well determined, vertical beta_w at its prior, dw_z not held. */
  assert_true(r1[bwx] < 0.5 * r0[bwx] && r1[bwx + 1] < 0.5 * r0[bwx + 1]);
  assert_true(r1[bwz] > 0.99 * r0[bwz]);
  assert_true(r1[dwz] > r0[dwz]);
  /* The drive calibrates the vertical component. */
  assert_true(d1[bwz] < 0.5 * d0[bwz]);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_ideal_closure),
      cmocka_unit_test(test_mc_vs_covariance),
      cmocka_unit_test(test_sim_nees_and_threads),
      cmocka_unit_test(test_fast_rotation_stable),
      cmocka_unit_test(test_p_spd_tiny_huge),
      cmocka_unit_test(test_observability),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
