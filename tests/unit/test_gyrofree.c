/*
 * Gyro-free INS (numerics.md 1.5): exact ideal array increments (E1.22) cross-checked against
 * the ideal IMU, closure of the gyro-free mechanization with perfect sensors and its
 * convergence order, the common-bias rate and position errors against E1.25 and E1.28, a noise
 * Monte Carlo against E1.25, general (non-cube) layouts and error handling.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_analytic.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_gyrofree.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_truth.h"

#define K_R 0.1

/* ------------------------------------------------------------------ helpers */

/* The T3.1 trajectory (numerics.md 3.3: rotating at up to 0.36 rad/s, accelerating) at a rate. */
static nav_scene rotating_scene(double rate_hz, double duration_s) {
  nav_scene sc = nav_scene_default();
  sc.imu.rate_hz = rate_hz;
  sc.trajectory.duration_s = duration_s;
  return sc;
}

/* A level body at rest in the flat frame. */
static nav_scene stationary_scene(double rate_hz, double duration_s) {
  nav_scene sc = rotating_scene(rate_hz, duration_s);
  nav_traj_parametric *p = &sc.trajectory.parametric;
  p->v0_mps = nav_vec3_zero();
  p->a_mps2 = nav_vec3_zero();
  p->b_m = nav_vec3_zero();
  p->wa_rps = nav_vec3_zero();
  p->wb_rps = nav_vec3_zero();
  return sc;
}

static nav_accel_array cube_array(void) {
  nav_accel_array a;
  assert_int_equal(nav_array_cube_layout(K_R, &a), NAV_OK);
  return a;
}

/* A six-sensor layout that is not of the [CLD] type: axes not perpendicular to the lever arms,
 * so H^-1 does not annihilate c(omega) and the rate is implicit. */
static nav_accel_array skew_array(void) {
  nav_accel_array a = cube_array();
  static const double tilt[6][3] = {{0.3, 0.1, 0.0},  {-0.2, 0.0, 0.1}, {0.0, 0.25, -0.1},
                                    {0.1, -0.3, 0.0}, {0.0, 0.1, 0.2},  {-0.1, 0.0, -0.3}};
  for (int i = 0; i < 6; ++i) {
    const nav_vec3 u = nav_vec3_add(a.n_s_b[i], nav_vec3_make(tilt[i][0], tilt[i][1], tilt[i][2]));
    a.n_s_b[i] = nav_vec3_scale(u, 1.0 / nav_vec3_norm(u));
  }
  return a;
}

/* All ideal increments of a scene (test-side allocation; navcore never allocates per sample). */
static nav_array_increment *make_increments(nav_array_truth *tr, int64_t n) {
  nav_array_increment *inc = calloc((size_t)n + 1, sizeof *inc);
  assert_non_null(inc);
  for (int64_t k = 1; k <= n; ++k)
    assert_int_equal(nav_array_truth_sample(tr, k, &inc[k]), NAV_OK);
  return inc;
}

typedef struct gf_result {
  nav_epoch_errors err;  /* at the end */
  nav_vec3 rate_err_rps; /* estimated minus true omega_ib_b at the end */
  nav_vec3 pos_err_m;    /* estimated minus true position (flat l = NED) */
} gf_result;

/* Runs the gyro-free INS over inc[1..n] from the perfect initial state (rate included). */
static gf_result run_gyrofree_ins(nav_array_truth *tr, const nav_accel_array *array,
                                  nav_gyrofree_rate_interp interp, const nav_array_increment *inc, int64_t n,
                                  const nav_ins_config *ins_cfg) {
  nav_traj_state ts;
  nav_vec3 w0;
  assert_int_equal(nav_array_truth_state(tr, 0.0, &ts), NAV_OK);
  assert_int_equal(nav_array_truth_rate(tr, 0.0, &w0), NAV_OK);
  nav_gyrofree_config cfg = nav_gyrofree_config_default();
  cfg.array = *array;
  cfg.rate_interp = interp;
  if (ins_cfg) cfg.ins = *ins_cfg;
  nav_ins_state s0 = {0.0, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f};
  nav_gyrofree *gf = NULL;
  assert_int_equal(nav_gyrofree_create(&cfg, &s0, w0, &gf), NAV_OK);
  for (int64_t k = 1; k <= n; ++k) {
    const nav_status st = nav_gyrofree_step(gf, &inc[k]);
    if (st != NAV_OK) fail_msg("step %lld: %s", (long long)k, nav_gyrofree_last_error(gf));
  }
  const double t_end = (double)n * nav_array_truth_dt(tr);
  assert_int_equal(nav_array_truth_state(tr, t_end, &ts), NAV_OK);
  nav_vec3 w_true;
  assert_int_equal(nav_array_truth_rate(tr, t_end, &w_true), NAV_OK);
  const nav_frame fr = nav_array_truth_frame(tr);
  gf_result r;
  r.err = nav_errors_compute(&fr, &ts, nav_gyrofree_get_state(gf));
  r.rate_err_rps = nav_vec3_sub(nav_gyrofree_rate(gf), w_true);
  r.pos_err_m = nav_vec3_sub(nav_gyrofree_get_state(gf)->r_fb_f_m, ts.r_fb_f_m);
  assert_near(nav_gyrofree_get_state(gf)->t_s, t_end, 1e-9);
  nav_gyrofree_destroy(gf);
  return r;
}

static gf_result run_gyrofree(nav_array_truth *tr, const nav_accel_array *array,
                              nav_gyrofree_rate_interp interp, const nav_array_increment *inc, int64_t n) {
  return run_gyrofree_ins(tr, array, interp, inc, n, NULL);
}

/* ------------------------------------------------------------------ E1.22 truth */

/*
 * The array increments against the independent ideal IMU (imu_ideal.c): with the cube inverse,
 * the omega_dot part of H^-1 dA must equal omega(t_k) - omega(t_(k-1)) and the f part minus the
 * centripetal integral (8-point Gauss-Legendre over the true rate) must equal the IMU's dv.
 */
static void check_truth_consistency(nav_scene sc) {
  const nav_accel_array cube = cube_array();
  nav_array_geometry geo;
  assert_int_equal(nav_array_geometry_compute(&cube, &geo), NAV_OK);
  nav_array_truth *atr = NULL;
  nav_truth *itr = NULL;
  assert_int_equal(nav_array_truth_create(&sc, &cube, &atr), NAV_OK);
  assert_int_equal(nav_truth_create(&sc, &itr), NAV_OK);
  double xg[8], wg[8];
  assert_int_equal(nav_gauss_legendre(8, xg, wg), NAV_OK);
  const double dt = nav_array_truth_dt(atr);
  double worst_w = 0.0, worst_v = 0.0;
  for (int64_t k = 1; k <= nav_array_truth_sample_count(atr); k += 97) {
    nav_array_increment inc;
    nav_imu_increment imu;
    assert_int_equal(nav_array_truth_sample(atr, k, &inc), NAV_OK);
    assert_int_equal(nav_truth_imu(itr, k, &imu), NAV_OK);
    assert_int_equal(inc.n_sensors, 6);
    assert_near(inc.t_s, imu.t_s, 0.0);
    double y[6] = {0};
    for (int a = 0; a < 6; ++a)
      for (int i = 0; i < 6; ++i)
        y[a] += geo.h_pinv[a][i] * inc.dv_mps[i];
    nav_vec3 w0, w1;
    assert_int_equal(nav_array_truth_rate(atr, inc.t_s - dt, &w0), NAV_OK);
    assert_int_equal(nav_array_truth_rate(atr, inc.t_s, &w1), NAV_OK);
    const nav_vec3 dw = nav_vec3_sub(w1, w0);
    const nav_vec3 dw_arr = nav_vec3_make(y[3], y[4], y[5]);
    worst_w = fmax(worst_w, nav_vec3_norm(nav_vec3_sub(dw_arr, dw)));
    double cint[6] = {0};
    for (int j = 0; j < 8; ++j) {
      nav_vec3 w;
      assert_int_equal(nav_array_truth_rate(atr, inc.t_s - 0.5 * dt + 0.5 * dt * xg[j], &w), NAV_OK);
      double c[6];
      nav_array_centripetal(&cube, w, c);
      for (int i = 0; i < 6; ++i)
        cint[i] += 0.5 * dt * wg[j] * c[i];
    }
    nav_vec3 dv = nav_vec3_make(y[0], y[1], y[2]);
    for (int i = 0; i < 6; ++i)
      dv = nav_vec3_sub(dv, nav_vec3_make(geo.h_pinv[0][i] * cint[i], geo.h_pinv[1][i] * cint[i],
                                          geo.h_pinv[2][i] * cint[i]));
    worst_v = fmax(worst_v, nav_vec3_norm(nav_vec3_sub(dv, imu.dv_b_mps)));
  }
  print_message("%s: max |d omega error| %.3g rad/s, max |dv error| %.3g m/s\n",
                sc.earth.model == NAV_EARTH_FLAT ? "flat" : "WGS-84", worst_w, worst_v);
  /* Round-off of 6-node quadratures of O(0.1 m/s) and O(1e-3 rad/s) increments. */
  assert_true(worst_w < 1e-14);
  assert_true(worst_v < 1e-13);
  nav_truth_destroy(itr);
  nav_array_truth_destroy(atr);
}

static void test_array_truth_vs_imu_truth(void **state) {
  (void)state;
  check_truth_consistency(rotating_scene(100.0, 20.0));
  /* WGS-84: omega_ib includes the Earth rate, omega_dot_ib the -omega_eb x omega_ie term, f the
   * Coriolis term. */
  nav_scene sc = rotating_scene(100.0, 20.0);
  sc.earth.model = NAV_EARTH_WGS84;
  check_truth_consistency(sc);
}

/* ------------------------------------------------------------------ closure and order */

/*
 * Perfect array, perfect initial state (rate included), T3.1 trajectory for T = 20 s at
 * dt = 0.04 .. 0.005 s. The rate is exact at the samples (the array measures omega_dot, whose
 * integral is the rate change), so the remaining error is that of the rate interpolant inside
 * the interval (dtheta, centripetal integral) plus the strapdown algorithm (b) it feeds:
 * LINEAR -> O(dt^2) (ratio 4 per halving), QUADRATIC -> O(dt^3) (ratio 8).
 */
static void test_closure_order(void **state) {
  (void)state;
  static const double rates[4] = {25.0, 50.0, 100.0, 200.0};
  gf_result lin[4], quad[4];
  const nav_accel_array cube = cube_array();
  for (int i = 0; i < 4; ++i) {
    nav_scene sc = rotating_scene(rates[i], 20.0);
    nav_array_truth *tr = NULL;
    assert_int_equal(nav_array_truth_create(&sc, &cube, &tr), NAV_OK);
    const int64_t n = nav_array_truth_sample_count(tr);
    nav_array_increment *inc = make_increments(tr, n);
    lin[i] = run_gyrofree(tr, &cube, NAV_GYROFREE_RATE_LINEAR, inc, n);
    quad[i] = run_gyrofree(tr, &cube, NAV_GYROFREE_RATE_QUADRATIC, inc, n);
    print_message(
        "dt=%.3f linear: att %.3e vel %.3e pos %.3e rate %.1e | quadratic: att %.3e vel %.3e pos %.3e "
        "rate %.1e\n",
        1.0 / rates[i], lin[i].err.att_err_rad, lin[i].err.vel_err_mps, nav_vec3_norm(lin[i].err.pos_err_n_m),
        nav_vec3_norm(lin[i].rate_err_rps), quad[i].err.att_err_rad, quad[i].err.vel_err_mps,
        nav_vec3_norm(quad[i].err.pos_err_n_m), nav_vec3_norm(quad[i].rate_err_rps));
    /* The rate at the samples is exact up to round-off accumulated over n steps. */
    assert_true(nav_vec3_norm(quad[i].rate_err_rps) < 1e-12);
    free(inc);
    nav_array_truth_destroy(tr);
  }
  for (int i = 0; i < 3; ++i) {
    const double ra = lin[i].err.att_err_rad / lin[i + 1].err.att_err_rad;
    const double rv = lin[i].err.vel_err_mps / lin[i + 1].err.vel_err_mps;
    const double qa = quad[i].err.att_err_rad / quad[i + 1].err.att_err_rad;
    const double qv = quad[i].err.vel_err_mps / quad[i + 1].err.vel_err_mps;
    const double qp = nav_vec3_norm(quad[i].err.pos_err_n_m) / nav_vec3_norm(quad[i + 1].err.pos_err_n_m);
    print_message("halving %d: linear att x%.2f vel x%.2f | quadratic att x%.2f vel x%.2f pos x%.2f\n", i, ra,
                  rv, qa, qv, qp);
    assert_near(ra, 4.0, 0.4);
    assert_near(rv, 4.0, 0.4);
    assert_near(qa, 8.0, 1.0);
    assert_near(qv, 8.0, 1.0);
    assert_near(qp, 8.0, 1.0);
  }
  /* Achieved errors at dt = 0.01 s (index 2), with margin over the measured values. */
  assert_true(quad[2].err.att_err_rad < 1e-6);
  assert_true(quad[2].err.vel_err_mps < 1e-4);
}

/*
 * WGS-84 (the T3.1 motion about 45 deg N, 100 Hz): the array truth senses omega_ib (Earth rate
 * included) and f with the Coriolis term; the gyro-free INS feeds the WGS-84 strapdown in NED and
 * in ECEF. The closure is that of the flat case (the interpolation error dominates).
 */
static void test_closure_wgs84(void **state) {
  (void)state;
  const nav_accel_array cube = cube_array();
  nav_scene sc = rotating_scene(100.0, 20.0);
  sc.earth.model = NAV_EARTH_WGS84;
  nav_array_truth *tr = NULL;
  assert_int_equal(nav_array_truth_create(&sc, &cube, &tr), NAV_OK);
  const int64_t n = nav_array_truth_sample_count(tr);
  nav_array_increment *inc = make_increments(tr, n);
  static const nav_mech_frame frames[2] = {NAV_MECH_NED, NAV_MECH_ECEF};
  for (int i = 0; i < 2; ++i) {
    nav_ins_config ic = nav_gyrofree_config_default().ins;
    ic.earth_model = NAV_EARTH_WGS84;
    ic.mech_frame = frames[i];
    const gf_result r = run_gyrofree_ins(tr, &cube, NAV_GYROFREE_RATE_QUADRATIC, inc, n, &ic);
    print_message("WGS-84 %s: att %.3e vel %.3e pos %.3e rate %.1e\n", nav_mech_frame_name(frames[i]),
                  r.err.att_err_rad, r.err.vel_err_mps, nav_vec3_norm(r.err.pos_err_n_m),
                  nav_vec3_norm(r.rate_err_rps));
    /* Flat-Earth values at 100 Hz: 2.42e-7 rad, 2.58e-5 m/s, 2.71e-4 m. */
    assert_true(r.err.att_err_rad < 3e-7);
    assert_true(r.err.vel_err_mps < 3e-5);
    assert_true(nav_vec3_norm(r.err.pos_err_n_m) < 3e-4);
    assert_true(nav_vec3_norm(r.rate_err_rps) < 1e-12);
  }
  free(inc);
  nav_array_truth_destroy(tr);
}

/* ------------------------------------------------------------------ E1.25, E1.28 with a bias */

/* Adds a constant b [m/s^2] to every sensor: b dt to each increment. */
static void add_common_bias(nav_array_increment *inc, int64_t n, double b) {
  for (int64_t k = 1; k <= n; ++k)
    for (int i = 0; i < inc[k].n_sensors; ++i)
      inc[k].dv_mps[i] += b * inc[k].dt_s;
}

/* On the rotating trajectory a common bias b drives each rate axis by -(1/sqrt 2) b t / r
 * (E1.25 with the cube's sign pattern), independent of the motion. */
static void test_common_bias_rate(void **state) {
  (void)state;
  const nav_accel_array cube = cube_array();
  nav_scene sc = rotating_scene(100.0, 2.0);
  nav_array_truth *tr = NULL;
  assert_int_equal(nav_array_truth_create(&sc, &cube, &tr), NAV_OK);
  const int64_t n = nav_array_truth_sample_count(tr);
  nav_array_increment *inc = make_increments(tr, n);
  const double b = 1e-3 * NAV_G0_MPS2;
  add_common_bias(inc, n, b);
  const gf_result r = run_gyrofree(tr, &cube, NAV_GYROFREE_RATE_QUADRATIC, inc, n);
  const double t = 2.0;
  nav_analytic_gyrofree_spec sp = {NAV_G0_MPS2, K_R, sqrt(0.5), sqrt(0.5), b, 0.0};
  nav_analytic_gyrofree_errors e;
  assert_int_equal(nav_analytic_gyrofree_eval(&sp, t, &e), NAV_OK);
  print_message("rate error (%.6g, %.6g, %.6g) rad/s, E1.25 -kappa b t / r = %.6g\n", r.rate_err_rps.x,
                r.rate_err_rps.y, r.rate_err_rps.z, -e.rate_bias_rps);
  assert_rel_near(r.rate_err_rps.x, -e.rate_bias_rps, 0.01);
  assert_rel_near(r.rate_err_rps.y, -e.rate_bias_rps, 0.01);
  assert_rel_near(r.rate_err_rps.z, -e.rate_bias_rps, 0.01);
  /* It is in fact exact (linear, and the omega_dot rows annihilate c): */
  assert_rel_near(r.rate_err_rps.y, -e.rate_bias_rps, 1e-9);
  free(inc);
  nav_array_truth_destroy(tr);
}

/*
 * The whole chain E1.25-E1.28 with signs, on a level body at rest (t = 5 s, b = 1e-5 m/s^2,
 * small angles): omega_dot error -(1/sqrt 2) b/r on every axis gives attitude errors
 * dtheta = -(1/sqrt 2) b t^2 / (2r) about each body axis; with f = (0, 0, -g) the tilt about y
 * pushes north by +g kappa b t^4/(24 r), the tilt about x pushes east by -g kappa b t^4/(24 r), and
 * the specific-force bias +(1/sqrt 2) b adds kappa_f b t^2/2 on every axis. So north is exactly
 * E1.28's bias column, east has the opposite gravity term, and down is the f part plus the
 * second-order tilt term: |f| (1 - cos alpha) ~ g (alpha_x^2 + alpha_y^2)/2 = g (kappa b/(2r))^2 t^4
 * integrated twice, g (kappa b / (2r))^2 t^6 / 30 (7 % of the down error here; first-order
 * formulas such as E1.28 have no vertical gravity term).
 */
static void test_stationary_bias_chain(void **state) {
  (void)state;
  const nav_accel_array cube = cube_array();
  nav_scene sc = stationary_scene(100.0, 5.0);
  nav_array_truth *tr = NULL;
  assert_int_equal(nav_array_truth_create(&sc, &cube, &tr), NAV_OK);
  const int64_t n = nav_array_truth_sample_count(tr);
  nav_array_increment *inc = make_increments(tr, n);
  const double b = 1e-5, t = 5.0, g = NAV_G0_MPS2, k = sqrt(0.5);
  add_common_bias(inc, n, b);
  const gf_result r = run_gyrofree(tr, &cube, NAV_GYROFREE_RATE_QUADRATIC, inc, n);
  nav_analytic_gyrofree_spec sp = {g, K_R, k, k, b, 0.0};
  nav_analytic_gyrofree_errors e;
  assert_int_equal(nav_analytic_gyrofree_eval(&sp, t, &e), NAV_OK);
  const double f_part = k * b * t * t / 2, w_part = g * k * b * pow(t, 4) / (24 * K_R);
  print_message(
      "pos error (%.6g, %.6g, %.6g) m; E1.28 bias %.6g (= %.6g + %.6g); att %.6g rad vs sqrt3 %.6g\n",
      r.pos_err_m.x, r.pos_err_m.y, r.pos_err_m.z, e.pos_bias_m, f_part, w_part, r.err.att_err_rad,
      sqrt(3.0) * e.att_bias_rad);
  assert_rel_near(r.pos_err_m.x, e.pos_bias_m, 0.01);
  assert_rel_near(r.pos_err_m.y, f_part - w_part, 0.01);
  const double tilt2_part = g * pow(k * b / (2 * K_R), 2) * pow(t, 6) / 30;
  assert_rel_near(r.pos_err_m.z, f_part + tilt2_part, 0.01);
  assert_rel_near(r.err.att_err_rad, sqrt(3.0) * e.att_bias_rad, 0.01);
  assert_rel_near(r.rate_err_rps.x, -e.rate_bias_rps, 1e-9);
  free(inc);
  nav_array_truth_destroy(tr);
}

/* ------------------------------------------------------------------ E1.25 Monte Carlo */

/*
 * 200 runs of the gyro-free INS on the rotating trajectory with independent white noise of
 * per-sample sd sigma on each of the six sensors (increment noise sigma dt w, E1.2). At t = 1 s
 * the rate error of each axis has sd kappa sigma sqrt(t dt)/r (E1.25). The three axes are
 * independent for the cube (E1.24 property (c)), so the 600 errors are pooled: N s^2 / sigma^2 ~
 * chi2(600), 95 % interval of s/sigma [0.9434, 1.0565] (Wilson-Hilferty).
 */
static void test_noise_monte_carlo(void **state) {
  (void)state;
  const nav_accel_array cube = cube_array();
  nav_scene sc = rotating_scene(100.0, 1.0);
  nav_array_truth *tr = NULL;
  assert_int_equal(nav_array_truth_create(&sc, &cube, &tr), NAV_OK);
  const int64_t n = nav_array_truth_sample_count(tr);
  nav_array_increment *ideal = make_increments(tr, n);
  nav_array_increment *noisy = calloc((size_t)n + 1, sizeof *noisy);
  assert_non_null(noisy);
  const double sigma = 1e-3 * NAV_G0_MPS2, dt = nav_array_truth_dt(tr), t = (double)n * dt;
  const int runs = 200;
  const uint64_t seed = 20240611;
  nav_test_print_seed("gyro-free rate Monte Carlo", seed);
  double acc = 0.0, acc_att = 0.0;
  for (int run = 0; run < runs; ++run) {
    nav_rng rng[6];
    for (unsigned i = 0; i < 6; ++i)
      nav_rng_init(&rng[i], seed, (uint64_t)run, nav_rng_stream_id(NAV_RNG_STREAM_ACCEL_NOISE, i));
    memcpy(noisy, ideal, ((size_t)n + 1) * sizeof *noisy);
    for (int64_t k = 1; k <= n; ++k)
      for (int i = 0; i < 6; ++i)
        noisy[k].dv_mps[i] += sigma * dt * nav_rng_gauss(&rng[i]);
    const gf_result r = run_gyrofree(tr, &cube, NAV_GYROFREE_RATE_QUADRATIC, noisy, n);
    acc += nav_vec3_dot(r.rate_err_rps, r.rate_err_rps);
    acc_att += r.err.att_err_rad * r.err.att_err_rad;
  }
  nav_analytic_gyrofree_spec sp = {NAV_G0_MPS2, K_R, sqrt(0.5),
                                   sqrt(0.5),   0.0, nav_analytic_density_from_sample_sd(sigma, dt)};
  nav_analytic_gyrofree_errors e;
  assert_int_equal(nav_analytic_gyrofree_eval(&sp, t, &e), NAV_OK);
  const double rms = sqrt(acc / (3.0 * runs));
  const double rms_att = sqrt(acc_att / runs);
  print_message(
      "rate error RMS per axis %.6g rad/s vs E1.25 %.6g (ratio %.4f); attitude angle RMS %.4g rad vs "
      "sqrt3 E1.26 %.4g (rotating body: indicative only)\n",
      rms, e.rate_sd_rps, rms / e.rate_sd_rps, rms_att, sqrt(3.0) * e.att_sd_rad);
  assert_near(rms / e.rate_sd_rps, 0.99995, 0.05655); /* [0.9434, 1.0565] */
  free(noisy);
  free(ideal);
  nav_array_truth_destroy(tr);
}

/* ------------------------------------------------------------------ general layouts */

/*
 * A non-[CLD] six-sensor layout (implicit rate, fixed-point iteration) and a redundant
 * eight-sensor one (least squares). Unlike the cube, their omega_dot rows see the centripetal
 * term, so the interpolant's error in int c(omega) dt now also enters the rate at the samples:
 * the errors are larger (same magnitude) but of the same order, O(dt^3) with QUADRATIC. For the
 * skew layout the dt^4 part is still visible at these steps: the attitude ratio per halving
 * measured 11.9 (25->50 Hz), 10.6 (50->100), 9.5 (100->200), 8.8 (200->400), tending to 8; the
 * test accepts [7, 12] at 50->100 Hz.
 */
static void test_general_layout_closure(void **state) {
  (void)state;
  nav_accel_array layouts[3] = {cube_array(), skew_array(), cube_array()};
  /* Eight sensors: the cube plus two on the z axis measuring x and y. */
  layouts[2].n_sensors = 8;
  layouts[2].r_bs_b_m[6] = nav_vec3_make(0.0, 0.0, 0.15);
  layouts[2].n_s_b[6] = nav_vec3_make(1.0, 0.0, 0.0);
  layouts[2].r_bs_b_m[7] = nav_vec3_make(0.0, 0.0, -0.15);
  layouts[2].n_s_b[7] = nav_vec3_make(0.0, 1.0, 0.0);
  gf_result res[3], res50[3];
  for (int l = 0; l < 3; ++l) {
    nav_array_geometry geo;
    assert_int_equal(nav_array_geometry_compute(&layouts[l], &geo), NAV_OK);
    nav_scene sc = rotating_scene(100.0, 20.0);
    nav_array_truth *tr = NULL;
    assert_int_equal(nav_array_truth_create(&sc, &layouts[l], &tr), NAV_OK);
    const int64_t n = nav_array_truth_sample_count(tr);
    nav_array_increment *inc = make_increments(tr, n);
    res[l] = run_gyrofree(tr, &layouts[l], NAV_GYROFREE_RATE_QUADRATIC, inc, n);
    free(inc);
    nav_array_truth_destroy(tr);
    sc = rotating_scene(50.0, 20.0);
    assert_int_equal(nav_array_truth_create(&sc, &layouts[l], &tr), NAV_OK);
    const int64_t n50 = nav_array_truth_sample_count(tr);
    inc = make_increments(tr, n50);
    res50[l] = run_gyrofree(tr, &layouts[l], NAV_GYROFREE_RATE_QUADRATIC, inc, n50);
    free(inc);
    nav_array_truth_destroy(tr);
    print_message(
        "layout %d (N=%d, cond %.3g, kappa %.3f %.3f %.3f) dt=0.01: att %.3e vel %.3e pos %.3e rate %.1e; "
        "ratio to dt=0.02: att x%.2f vel x%.2f rate x%.2f\n",
        l, layouts[l].n_sensors, geo.cond, geo.kappa_w[0], geo.kappa_w[1], geo.kappa_w[2],
        res[l].err.att_err_rad, res[l].err.vel_err_mps, nav_vec3_norm(res[l].err.pos_err_n_m),
        nav_vec3_norm(res[l].rate_err_rps), res50[l].err.att_err_rad / res[l].err.att_err_rad,
        res50[l].err.vel_err_mps / res[l].err.vel_err_mps,
        nav_vec3_norm(res50[l].rate_err_rps) / nav_vec3_norm(res[l].rate_err_rps));
    assert_near(res50[l].err.att_err_rad / res[l].err.att_err_rad, 9.5, 2.5); /* [7, 12] */
    assert_near(res50[l].err.vel_err_mps / res[l].err.vel_err_mps, 9.5, 2.5);
  }
  for (int l = 1; l < 3; ++l) {
    assert_true(res[l].err.att_err_rad < 4.0 * res[0].err.att_err_rad);
    assert_true(res[l].err.vel_err_mps < 4.0 * res[0].err.vel_err_mps);
    assert_true(nav_vec3_norm(res[l].rate_err_rps) < 1e-7);
  }
}

/* ------------------------------------------------------------------ errors */

static void test_errors(void **state) {
  (void)state;
  nav_gyrofree_config cfg = nav_gyrofree_config_default();
  nav_ins_state s0 = {0.0, nav_vec3_zero(), nav_vec3_zero(), nav_quat_identity()};
  nav_gyrofree *gf = NULL;
  assert_int_equal(nav_gyrofree_create(NULL, &s0, nav_vec3_zero(), &gf), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_gyrofree_create(&cfg, NULL, nav_vec3_zero(), &gf), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_gyrofree_create(&cfg, &s0, nav_vec3_make(NAN, 0, 0), &gf), NAV_ERR_INVALID_ARG);
  nav_gyrofree_config bad = cfg;
  bad.rate_interp = (nav_gyrofree_rate_interp)7;
  assert_int_equal(nav_gyrofree_create(&bad, &s0, nav_vec3_zero(), &gf), NAV_ERR_INVALID_ARG);
  bad = cfg;
  bad.max_iterations = 0;
  assert_int_equal(nav_gyrofree_create(&bad, &s0, nav_vec3_zero(), &gf), NAV_ERR_INVALID_ARG);
  bad = cfg;
  for (int i = 0; i < 6; ++i)
    bad.array.n_s_b[i] = nav_vec3_scale(bad.array.r_bs_b_m[i], 1.0 / K_R);
  assert_int_equal(nav_gyrofree_create(&bad, &s0, nav_vec3_zero(), &gf), NAV_ERR_NUMERIC);
  assert_null(gf);
  nav_gyrofree_destroy(NULL);

  /* Mismatched and non-finite increments leave the state untouched. */
  assert_int_equal(nav_gyrofree_create(&cfg, &s0, nav_vec3_make(0.1, 0.2, 0.3), &gf), NAV_OK);
  assert_int_equal(nav_gyrofree_last_increment(gf)->k, 0);
  nav_array_increment inc;
  memset(&inc, 0, sizeof inc);
  inc.k = 1;
  inc.t_s = 0.01;
  inc.dt_s = 0.01;
  inc.n_sensors = 5;
  assert_int_equal(nav_gyrofree_step(gf, &inc), NAV_ERR_INVALID_ARG);
  assert_true(strlen(nav_gyrofree_last_error(gf)) > 0);
  inc.n_sensors = 6;
  inc.dv_mps[2] = NAN;
  assert_int_equal(nav_gyrofree_step(gf, &inc), NAV_ERR_NUMERIC);
  inc.dv_mps[2] = 0.0;
  inc.dt_s = 0.0;
  assert_int_equal(nav_gyrofree_step(gf, &inc), NAV_ERR_INVALID_ARG);
  assert_vec3_near(nav_gyrofree_rate(gf), nav_vec3_make(0.1, 0.2, 0.3), 0.0);
  assert_near(nav_gyrofree_get_state(gf)->t_s, 0.0, 0.0);
  inc.dt_s = 0.01;
  assert_int_equal(nav_gyrofree_step(gf, &inc), NAV_OK);
  assert_string_equal(nav_gyrofree_last_error(gf), "");
  assert_int_equal(nav_gyrofree_last_increment(gf)->k, 1);
  nav_gyrofree_destroy(gf);
  gf = NULL;

  /* The implicit rate of a general layout needs several passes: one is refused, state kept. */
  cfg.array = skew_array();
  cfg.max_iterations = 1;
  assert_int_equal(nav_gyrofree_create(&cfg, &s0, nav_vec3_make(1.0, -2.0, 0.5), &gf), NAV_OK);
  assert_int_equal(nav_gyrofree_step(gf, &inc), NAV_ERR_NOT_CONVERGED);
  print_message("refusal message: %s\n", nav_gyrofree_last_error(gf));
  assert_vec3_near(nav_gyrofree_rate(gf), nav_vec3_make(1.0, -2.0, 0.5), 0.0);
  assert_near(nav_gyrofree_get_state(gf)->t_s, 0.0, 0.0);
  nav_gyrofree_destroy(gf);

  /* Array truth argument checks. */
  nav_scene sc = rotating_scene(100.0, 1.0);
  nav_array_truth *tr = NULL;
  char msg[256];
  nav_accel_array one = cube_array();
  one.n_sensors = 2;
  assert_int_equal(nav_array_truth_create_msg(&sc, &one, &tr, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_null(tr);
  assert_true(strlen(msg) > 0);
  one = cube_array();
  assert_int_equal(nav_array_truth_create(&sc, &one, &tr), NAV_OK);
  nav_array_increment a;
  assert_int_equal(nav_array_truth_sample(tr, 0, &a), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_array_truth_sample_count(tr), 100);
  assert_int_equal(nav_array_truth_layout(tr)->n_sensors, 6);
  nav_array_truth_destroy(tr);
  nav_array_truth_destroy(NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_array_truth_vs_imu_truth),
      cmocka_unit_test(test_closure_order),
      cmocka_unit_test(test_closure_wgs84),
      cmocka_unit_test(test_common_bias_rate),
      cmocka_unit_test(test_stationary_bias_chain),
      cmocka_unit_test(test_noise_monte_carlo),
      cmocka_unit_test(test_general_layout_closure),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
