/*
 * Analytical error growth (numerics.md section 1): T1.1 (formula unit tests: Tables 1.6a-d,
 * E1.21 vs the T6.3 numbers, GM series/closed-form continuity, Schuler solutions, cube-layout
 * properties, general layouts), T1.2 (Monte Carlo of the linear error chains), and the
 * preliminary-estimate entry point.
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
#include "navcore/nav_earth.h"
#include "navcore/nav_rng.h"

/* ------------------------------------------------------------------ helpers */

/*
 * "Reproduces a 6-significant-digit table value": |actual - expected| <= half a unit in the
 * sixth significant digit of expected (plus 1e-12 relative for the decimal representation). A
 * flat relative 1e-6 is stricter than the printed tables themselves: rounding a value to six
 * digits moves it by up to 5e-6 relative (e.g. 4.903325 printed as 4.90332, 1.7e-6 below).
 */
#define assert_sig6(actual, expected)                                                                        \
  do {                                                                                                       \
    const double sa_ = (actual), se_ = (expected);                                                           \
    const double ulp6_ = pow(10.0, floor(log10(fabs(se_))) - 5.0);                                           \
    assert_near(sa_, se_, 0.5 * ulp6_ * (1.0 + 1e-9) + 1e-12 * fabs(se_));                                   \
  } while (0)

/* Worked-example inputs of numerics.md 1.6. */
#define K_G0 9.80665
#define K_B (1e-3 * K_G0)     /* 1 mg bias */
#define K_SIGMA (1e-3 * K_G0) /* 1 mg per-sample noise */
#define K_R 0.1
#define K_DT 0.01

static const double k_times[3] = {1.0, 10.0, 60.0};

/* ------------------------------------------------------------------ E1.1-E1.2 */

static void test_kernels(void **state) {
  (void)state;
  /* E1.1: t, t^3/3, t^5/20, t^7/252 for N = 1, t = 2. */
  assert_rel_near(nav_analytic_white_sd(1.0, 2.0, 1), sqrt(2.0), 1e-15);
  assert_rel_near(nav_analytic_white_sd(1.0, 2.0, 2), sqrt(8.0 / 3.0), 1e-15);
  assert_rel_near(nav_analytic_white_sd(1.0, 2.0, 3), sqrt(32.0 / 20.0), 1e-15);
  assert_rel_near(nav_analytic_white_sd(1.0, 2.0, 4), sqrt(128.0 / 252.0), 1e-15);
  assert_rel_near(nav_analytic_white_sd(3.0, 2.0, 4), 3.0 * sqrt(128.0 / 252.0), 1e-15);
  assert_true(isnan(nav_analytic_white_sd(1.0, 2.0, 0)));
  assert_true(isnan(nav_analytic_white_sd(1.0, 2.0, 9)));
  /* Deterministic column: b t, b t^2/2, b t^3/6, b t^4/24. */
  assert_rel_near(nav_analytic_bias_response(0.5, 3.0, 1), 1.5, 1e-15);
  assert_rel_near(nav_analytic_bias_response(0.5, 3.0, 2), 2.25, 1e-15);
  assert_rel_near(nav_analytic_bias_response(0.5, 3.0, 3), 2.25, 1e-15);
  assert_rel_near(nav_analytic_bias_response(0.5, 3.0, 4), 0.5 * 81.0 / 24.0, 1e-15);
  assert_near(nav_analytic_white_sd(1.0, 0.0, 3), 0.0, 0.0);
  /* E1.2: per-sample 0.1 deg/s at 100 Hz is ARW 0.6 deg/sqrt(h) (numerics.md 1.2). */
  const double n_g = nav_analytic_density_from_sample_sd(0.1 * NAV_DEG2RAD, 0.01);
  assert_rel_near(n_g, 0.6 * NAV_DEG2RAD / 60.0, 1e-14);
}

/* ------------------------------------------------------------------ T1.1: Tables 1.6a-d */

typedef struct gf_row {
  double w_b, w_n, a_b, a_n, g_b, g_n, r_b, r_n, r_n630;
} gf_row;

static void check_gf_rows(double kappa_w, double kappa_f, double r_m, const gf_row *rows, bool with_630) {
  nav_analytic_gyrofree_spec sp;
  sp.g_mps2 = K_G0;
  sp.r_m = r_m;
  sp.kappa_w = kappa_w;
  sp.kappa_f = kappa_f;
  sp.accel_bias_mps2 = K_B;
  sp.accel_noise_mps_per_sqrt_s = nav_analytic_density_from_sample_sd(K_SIGMA, K_DT);
  for (int i = 0; i < 3; ++i) {
    const double t = k_times[i];
    nav_analytic_gyrofree_errors e;
    assert_int_equal(nav_analytic_gyrofree_eval(&sp, t, &e), NAV_OK);
    const gf_row *x = &rows[i];
    print_message("t=%4.0f w %.6g %.6g  a %.6g %.6g  G %.6g %.6g  r %.6g %.6g\n", t, e.rate_bias_rps,
                  e.rate_sd_rps, e.att_bias_rad, e.att_sd_rad, e.grav_bias_mps2, e.grav_sd_mps2, e.pos_bias_m,
                  e.pos_sd_m);
    assert_sig6(e.rate_bias_rps, x->w_b);
    assert_sig6(e.rate_sd_rps, x->w_n);
    assert_sig6(e.att_bias_rad, x->a_b);
    assert_sig6(e.att_sd_rad, x->a_n);
    assert_sig6(e.grav_bias_mps2, x->g_b);
    assert_sig6(e.grav_sd_mps2, x->g_n);
    assert_sig6(e.pos_bias_m, x->r_b);
    assert_sig6(e.pos_sd_m, x->r_n);
    if (with_630) {
      const double p630 = nav_analytic_paper_gyrofree_position_noise_630(K_SIGMA, K_R, K_DT, K_G0, t);
      print_message("        paper /630 noise %.6g\n", p630);
      assert_sig6(p630, x->r_n630);
      /* The paper's total (1) is the linear sum of the bias part (kappa = 1) and /630 noise. */
      assert_rel_near(nav_analytic_paper_gyrofree_position_sigma_630(K_B, K_SIGMA, K_R, K_DT, K_G0, t),
                      e.pos_bias_m + p630, 1e-14);
    }
  }
}

/* Table 1.6a: paper convention kappa = kappa_f = 1, corrected /252, plus the paper's /630. */
static void test_table_1_6a(void **state) {
  (void)state;
  static const gf_row rows[3] = {
      {0.0980665, 0.00980665, 0.0490333, 0.00566187, 0.480852, 0.0555240, 0.0449743, 0.00608456, 0.00387313},
      {0.980665, 0.0310114, 4.90332, 0.179044, 48.0852, 1.75582, 401.200, 19.1576, 12.1163},
      {5.88399, 0.0759620, 176.520, 2.63140, 1731.07, 25.8052, 519338, 10136.1, 6410.63}};
  check_gf_rows(1.0, 1.0, K_R, rows, true);
  /* The paper's coefficient underestimates the t^7 term's sigma by sqrt(630/252) = 1.58. */
  const double t = 60.0;
  const double n252 = K_G0 * K_SIGMA / K_R * sqrt(K_DT * pow(t, 7.0) / 252.0);
  const double n630 = K_G0 * K_SIGMA / K_R * sqrt(K_DT * pow(t, 7.0) / 630.0);
  assert_rel_near(n252 / n630, sqrt(2.5), 1e-14);
}

/* Table 1.6b: cube layout, kappa from H (not typed in). */
static void test_table_1_6b(void **state) {
  (void)state;
  static const gf_row rows[3] = {
      {0.0693435, 0.00693435, 0.0346717, 0.00400355, 0.340014, 0.0392614, 0.0318016, 0.00430244, 0.0},
      {0.693435, 0.0219283, 3.46717, 0.126603, 34.0014, 1.24155, 283.691, 13.5465, 0.0},
      {4.16061, 0.0537132, 124.818, 1.86068, 1224.05, 18.2470, 367227, 7167.30, 0.0}};
  nav_accel_array cube;
  nav_array_geometry geom;
  assert_int_equal(nav_array_cube_layout(K_R, &cube), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&cube, &geom), NAV_OK);
  nav_analytic_gyrofree_spec sp;
  assert_int_equal(nav_analytic_gyrofree_spec_from_geometry(&geom, K_G0, K_B, 0.0, &sp), NAV_OK);
  assert_rel_near(sp.r_m, K_R, 1e-15);
  check_gf_rows(sp.kappa_w, sp.kappa_f, sp.r_m, rows, false);
}

/* Table 1.6c: gyro INS, same accelerometers, b_g = 10 deg/h, ARW 0.1 deg/sqrt(h). */
static void test_table_1_6c(void **state) {
  (void)state;
  nav_analytic_imu_spec s = nav_analytic_imu_spec_default();
  s.g_mps2 = K_G0;
  s.accel_bias_mps2 = K_B;
  s.accel_vrw_mps_per_sqrt_s = nav_analytic_density_from_sample_sd(K_SIGMA, K_DT);
  s.gyro_bias_rps = 10.0 * NAV_DEG2RAD / 3600.0;
  s.gyro_arw_rad_per_sqrt_s = 0.1 * NAV_DEG2RAD / 60.0;
  assert_sig6(s.gyro_arw_rad_per_sqrt_s, 2.90888e-5);
  assert_sig6(s.gyro_arw_rad_per_sqrt_s / sqrt(K_DT), 2.90888e-4);
  static const double t_c[2] = {10.0, 60.0};
  static const double want[2][5] = {{0.490333, 0.0179044, 0.0792400, 0.0201712, 0.497426},
                                    {17.6520, 0.263140, 17.1158, 1.77873, 24.6531}};
  for (int i = 0; i < 2; ++i) {
    nav_analytic_gyro_ins_table tab;
    assert_int_equal(nav_analytic_gyro_ins_table_eval(&s, t_c[i], &tab), NAV_OK);
    const double got[5] = {tab.term[NAV_ANALYTIC_TERM_ACCEL_BIAS].pos_m,
                           tab.term[NAV_ANALYTIC_TERM_ACCEL_NOISE].pos_m,
                           tab.term[NAV_ANALYTIC_TERM_GYRO_BIAS].pos_m,
                           tab.term[NAV_ANALYTIC_TERM_GYRO_NOISE].pos_m, tab.rss.pos_m};
    print_message("t=%3.0f %.6g %.6g %.6g %.6g RSS %.6g\n", t_c[i], got[0], got[1], got[2], got[3], got[4]);
    for (int j = 0; j < 5; ++j)
      assert_sig6(got[j], want[i][j]);
  }
}

/* Table 1.6d: the paper's Coriolis-gyro reading, 2 w r with w = 2 pi 10 kHz, r = 10 um. */
static void test_table_1_6d(void **state) {
  (void)state;
  const double w = NAV_TWO_PI * 1e4, r = 10e-6;
  assert_sig6(nav_analytic_coriolis_scale_mps(w, r), 1.256637);
  assert_sig6(K_B / nav_analytic_coriolis_scale_mps(w, r), 7.80388e-3);
  static const double t_d[2] = {10.0, 60.0};
  static const double want[2][3] = {{13.2453, 0.541445, 0.442209}, {2772.73, 47.7201, 38.9636}};
  for (int i = 0; i < 2; ++i) {
    const double t = t_d[i];
    const double bias = nav_analytic_paper_gyro_ins_position_bias(K_B, w, r, K_G0, t);
    const double n20 = nav_analytic_coriolis_gyro_ins_position_noise(K_SIGMA, w, r, K_DT, K_G0, t);
    const double n30 = nav_analytic_paper_gyro_ins_position_noise_30(K_SIGMA, w, r, K_DT, K_G0, t);
    print_message("t=%3.0f bias %.6g noise/20 %.6g paper/30 %.6g\n", t, bias, n20, n30);
    assert_sig6(bias, want[i][0]);
    assert_sig6(n20, want[i][1]);
    assert_sig6(n30, want[i][2]);
    assert_rel_near(nav_analytic_paper_gyro_ins_position_sigma_30(K_B, K_SIGMA, w, r, K_DT, K_G0, t),
                    bias + n30, 1e-14);
    /* Under the Coriolis reading the bias part is E1.10 + E1.14 with b_g = b_a / (2 w r). */
    nav_analytic_imu_spec s = nav_analytic_imu_spec_default();
    s.accel_bias_mps2 = K_B;
    s.gyro_bias_rps = K_B / nav_analytic_coriolis_scale_mps(w, r);
    nav_analytic_gyro_ins_table tab;
    assert_int_equal(nav_analytic_gyro_ins_table_eval(&s, t, &tab), NAV_OK);
    assert_rel_near(tab.term[NAV_ANALYTIC_TERM_ACCEL_BIAS].pos_m +
                        tab.term[NAV_ANALYTIC_TERM_GYRO_BIAS].pos_m,
                    bias, 1e-14);
  }
}

/* ------------------------------------------------------------------ E1.21 vs T6.3 */

/* numerics.md 1.4 / 6.6: the tactical IMU of T6.3 at lat 45 deg (g = normal gravity 9.80620). */
static void test_e121_vs_t63(void **state) {
  (void)state;
  nav_analytic_imu_spec s = nav_analytic_imu_spec_default();
  s.g_mps2 = nav_earth_gravity_normal_mps2(45.0 * NAV_DEG2RAD, 0.0);
  s.init_pos_sd_m = 0.02;
  s.init_vel_sd_mps = 0.01;
  s.init_tilt_sd_rad = 0.005 * NAV_DEG2RAD;
  s.init_heading_sd_rad = 0.05 * NAV_DEG2RAD; /* multiplies a_h = 0: no contribution */
  s.accel_vrw_mps_per_sqrt_s = 0.07 / 60.0;
  s.gyro_arw_rad_per_sqrt_s = 0.15 * NAV_DEG2RAD / 60.0;
  s.accel_bias_mps2 = 0.05e-3 * NAV_G0_MPS2;
  s.gyro_bias_rps = 0.5 * NAV_DEG2RAD / 3600.0;
  static const double t_e[4] = {10.0, 30.0, 60.0, 120.0};
  /* Closed form (numerics.md 6.6, printed to 5-6 digits) and the covariance propagation. */
  static const double closed[4] = {0.11923, 0.73042, 3.38533, 18.0914};
  static const double cov[4] = {0.11923, 0.73033, 3.38406, 18.0667};
  static const double t63_quoted[4] = {0.1192, 0.7304, 3.385, 18.09};
  for (int i = 0; i < 4; ++i) {
    nav_analytic_gyro_ins_table tab;
    assert_int_equal(nav_analytic_gyro_ins_table_eval(&s, t_e[i], &tab), NAV_OK);
    print_message("t=%4.0f E1.21 %.6g m (closed %.6g, covariance %.6g)\n", t_e[i], tab.rss.pos_m, closed[i],
                  cov[i]);
    /* Half a unit of the last printed digit. */
    const double last = i == 0 ? 1e-5 : (i == 1 ? 1e-5 : (i == 2 ? 1e-5 : 1e-4));
    assert_near(tab.rss.pos_m, closed[i], 0.5 * last);
    assert_near(tab.rss.pos_m, t63_quoted[i], 0.5 * (i < 2 ? 1e-4 : (i == 2 ? 1e-3 : 1e-2)));
    /* Within 0.2 % of the full covariance propagation up to 120 s (numerics.md 6.6). */
    assert_rel_near(tab.rss.pos_m, cov[i], 2e-3);
  }
}

/* Every table row against its formula, the RSS, and argument checks. */
static void test_gyro_ins_table_terms(void **state) {
  (void)state;
  nav_analytic_imu_spec s = nav_analytic_imu_spec_default();
  s.g_mps2 = 9.8;
  s.init_pos_sd_m = 1.0;
  s.init_vel_sd_mps = 0.1;
  s.init_tilt_sd_rad = 1e-3;
  s.init_heading_sd_rad = 2e-3;
  s.horiz_accel_mps2 = 0.5;
  s.accel_bias_mps2 = 1e-3;
  s.accel_vrw_mps_per_sqrt_s = 1e-3;
  s.accel_gm_sd_mps2 = 2e-3;
  s.accel_gm_tau_s = 100.0;
  s.accel_bias_rw_mps2_per_sqrt_s = 1e-5;
  s.gyro_bias_rps = 1e-5;
  s.gyro_arw_rad_per_sqrt_s = 1e-4;
  s.gyro_gm_sd_rps = 2e-5;
  s.gyro_gm_tau_s = 300.0;
  s.gyro_rrw_rps_per_sqrt_s = 1e-7;
  const double t = 37.0, g = 9.8;
  nav_analytic_gyro_ins_table tab;
  assert_int_equal(nav_analytic_gyro_ins_table_eval(&s, t, &tab), NAV_OK);
  const nav_analytic_axis_error *e = tab.term;
  const double tol = 1e-13;
  assert_rel_near(e[NAV_ANALYTIC_TERM_INIT_POS].pos_m, 1.0, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_INIT_VEL].pos_m, 0.1 * t, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_INIT_TILT].vel_mps, g * 1e-3 * t, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_INIT_TILT].pos_m, g * 1e-3 * t * t / 2, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_INIT_HEADING].pos_m, 0.5 * 2e-3 * t * t / 2, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_BIAS].pos_m, 1e-3 * t * t / 2, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_NOISE].vel_mps, 1e-3 * sqrt(t), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_NOISE].pos_m, 1e-3 * sqrt(t * t * t / 3), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_GM].vel_mps, sqrt(nav_analytic_gm_var_i1(2e-3, 100.0, t)), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_GM].pos_m, sqrt(nav_analytic_gm_var_i2(2e-3, 100.0, t)), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_BIAS_RW].vel_mps, 1e-5 * sqrt(t * t * t / 3), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_ACCEL_BIAS_RW].pos_m, 1e-5 * sqrt(pow(t, 5) / 20), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_BIAS].att_rad, 1e-5 * t, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_BIAS].vel_mps, g * 1e-5 * t * t / 2, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_BIAS].pos_m, g * 1e-5 * t * t * t / 6, tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_NOISE].att_rad, 1e-4 * sqrt(t), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_NOISE].vel_mps, g * 1e-4 * sqrt(t * t * t / 3), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_NOISE].pos_m, g * 1e-4 * sqrt(pow(t, 5) / 20), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_GM].att_rad, sqrt(nav_analytic_gm_var_i1(2e-5, 300.0, t)), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_GM].vel_mps, g * sqrt(nav_analytic_gm_var_i2(2e-5, 300.0, t)),
                  tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_GM].pos_m, g * sqrt(nav_analytic_gm_var_i3(2e-5, 300.0, t)), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_RRW].att_rad, 1e-7 * sqrt(t * t * t / 3), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_RRW].vel_mps, g * 1e-7 * sqrt(pow(t, 5) / 20), tol);
  assert_rel_near(e[NAV_ANALYTIC_TERM_GYRO_RRW].pos_m, g * 1e-7 * sqrt(pow(t, 7) / 252), tol);
  double vp = 0.0;
  for (int i = 0; i < NAV_ANALYTIC_TERM_COUNT; ++i) {
    vp += e[i].pos_m * e[i].pos_m;
    assert_string_not_equal(nav_analytic_term_name((nav_analytic_term_id)i), "?");
  }
  assert_rel_near(tab.rss.pos_m, sqrt(vp), 1e-14);
  assert_true(nav_analytic_term_is_process(NAV_ANALYTIC_TERM_GYRO_GM));
  assert_false(nav_analytic_term_is_process(NAV_ANALYTIC_TERM_GYRO_BIAS));
  assert_string_equal(nav_analytic_term_name(NAV_ANALYTIC_TERM_COUNT), "?");
  /* A random-constant GM bias (T = +inf) is the plain bias row. */
  nav_analytic_imu_spec c = nav_analytic_imu_spec_default();
  c.gyro_gm_sd_rps = 1e-5;
  c.gyro_gm_tau_s = INFINITY;
  assert_int_equal(nav_analytic_gyro_ins_table_eval(&c, t, &tab), NAV_OK);
  assert_rel_near(tab.term[NAV_ANALYTIC_TERM_GYRO_GM].pos_m, NAV_G0_MPS2 * 1e-5 * t * t * t / 6, 1e-14);
  /* Argument checks; the output is untouched on error. */
  nav_analytic_gyro_ins_table keep;
  memset(&keep, 0x5a, sizeof keep);
  nav_analytic_gyro_ins_table probe = keep;
  assert_int_equal(nav_analytic_gyro_ins_table_eval(NULL, t, &probe), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_analytic_gyro_ins_table_eval(&s, -1.0, &probe), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_analytic_gyro_ins_table_eval(&s, NAN, &probe), NAV_ERR_INVALID_ARG);
  nav_analytic_imu_spec bad = s;
  bad.accel_bias_mps2 = -1.0;
  assert_int_equal(nav_analytic_gyro_ins_table_eval(&bad, t, &probe), NAV_ERR_INVALID_ARG);
  bad = s;
  bad.gyro_gm_tau_s = 0.0;
  assert_int_equal(nav_analytic_gyro_ins_table_eval(&bad, t, &probe), NAV_ERR_INVALID_ARG);
  assert_memory_equal(&probe, &keep, sizeof keep);
}

/* ------------------------------------------------------------------ E1.3-E1.5 */

static void test_gm_series_vs_closed_form(void **state) {
  (void)state;
  const double sigma = 0.3, tau = 50.0;
  for (int m = 1; m <= 3; ++m) {
    /* Continuity at the switch: AUTO takes the series just below NAV_ANALYTIC_GM_SERIES_X and the
     * closed form from it on, and the two branches agree there. */
    const double t_sw = NAV_ANALYTIC_GM_SERIES_X * tau, t_below = t_sw * (1.0 - 1e-12);
    const double ser_sw = nav_analytic_gm_var(m, sigma, tau, t_sw, NAV_ANALYTIC_GM_SERIES);
    const double cf_sw = nav_analytic_gm_var(m, sigma, tau, t_sw, NAV_ANALYTIC_GM_CLOSED_FORM);
    print_message("I%d at the switch: series %.17g closed %.17g (rel diff %.2e)\n", m, ser_sw, cf_sw,
                  (cf_sw - ser_sw) / ser_sw);
    assert_rel_near(cf_sw, ser_sw, 1e-13);
    assert_near(nav_analytic_gm_var(m, sigma, tau, t_sw, NAV_ANALYTIC_GM_AUTO), cf_sw, 0.0);
    assert_near(nav_analytic_gm_var(m, sigma, tau, t_below, NAV_ANALYTIC_GM_AUTO),
                nav_analytic_gm_var(m, sigma, tau, t_below, NAV_ANALYTIC_GM_SERIES), 0.0);
    /* Where both are accurate the branches agree (closed form loses ~72 eps / x^6 for I3). */
    for (double x = 0.5; x <= 4.0; x += 0.25) {
      const double s = nav_analytic_gm_var(m, sigma, tau, x * tau, NAV_ANALYTIC_GM_SERIES);
      const double c = nav_analytic_gm_var(m, sigma, tau, x * tau, NAV_ANALYTIC_GM_CLOSED_FORM);
      assert_rel_near(s, c, 1e-11);
    }
    /* Short-time limit (random constant): sigma^2 t^2, t^4/4, t^6/36, next term relative x. */
    const double t_small = 1e-9 * tau;
    const double lim_small =
        m == 1 ? sigma * sigma * t_small * t_small
               : (m == 2 ? sigma * sigma * pow(t_small, 4) / 4 : sigma * sigma * pow(t_small, 6) / 36);
    assert_rel_near(nav_analytic_gm_var(m, sigma, tau, t_small, NAV_ANALYTIC_GM_AUTO), lim_small, 1e-8);
    /* T = +inf is exactly the random constant. */
    assert_rel_near(
        nav_analytic_gm_var(m, sigma, INFINITY, 2.0, NAV_ANALYTIC_GM_AUTO),
        m == 1 ? sigma * sigma * 4.0 : (m == 2 ? sigma * sigma * 4.0 : sigma * sigma * 64.0 / 36.0), 1e-15);
    /* Long-time limit: white noise of q = 2 sigma^2 T; leading corrections are O(1/x). */
    const double t_big = 1e6 * tau;
    const double q = 2.0 * sigma * sigma * tau;
    const double lim_big = m == 1 ? q * t_big : (m == 2 ? q * pow(t_big, 3) / 3 : q * pow(t_big, 5) / 20);
    assert_rel_near(nav_analytic_gm_var(m, sigma, tau, t_big, NAV_ANALYTIC_GM_AUTO), lim_big, 5e-6);
    /* Why the switch sits at x = 1, not at numerics.md's 1e-3: at x = 1e-3 the closed forms of I2
     * and I3 have lost most or all digits. */
    const double s3 = nav_analytic_gm_var(m, sigma, tau, 1e-3 * tau, NAV_ANALYTIC_GM_SERIES);
    const double c3 = nav_analytic_gm_var(m, sigma, tau, 1e-3 * tau, NAV_ANALYTIC_GM_CLOSED_FORM);
    print_message("I%d at t/T = 1e-3: closed form relative error %.2e\n", m, fabs(c3 - s3) / s3);
  }
  /* Domain. */
  assert_true(isnan(nav_analytic_gm_var(4, 1.0, 1.0, 1.0, NAV_ANALYTIC_GM_AUTO)));
  assert_true(isnan(nav_analytic_gm_var(1, 1.0, 0.0, 1.0, NAV_ANALYTIC_GM_AUTO)));
  assert_true(isnan(nav_analytic_gm_var(1, 1.0, 1.0, -1.0, NAV_ANALYTIC_GM_AUTO)));
  assert_near(nav_analytic_gm_var_i3(1.0, 1.0, 0.0), 0.0, 0.0);
}

/* ------------------------------------------------------------------ E1.18-E1.20 */

static void test_schuler(void **state) {
  (void)state;
  const double lat = 45.0 * NAV_DEG2RAD;
  const double R = nav_analytic_schuler_radius_m(lat, 0.0);
  const double g = nav_earth_gravity_normal_mps2(lat, 0.0);
  assert_near(R, 6378101.0, 1.0);
  assert_near(g, 9.80620, 5e-6);
  const double ws = nav_analytic_schuler_rate_rps(g, R);
  const double ts = NAV_TWO_PI / ws;
  print_message("Schuler period %.4f min\n", ts / 60.0);
  assert_near(ts / 60.0, 84.45, 0.005);
  nav_analytic_schuler_channel ch;
  memset(&ch, 0, sizeof ch);
  ch.g_mps2 = g;
  ch.radius_m = R;
  /* Tilt 0.1 mrad: peak 2 R psi0 = 1.276 km at T_s/2 (north: phi_E drives +). */
  ch.tilt0_rad = 1e-4;
  nav_analytic_schuler_error n = nav_analytic_schuler_north(&ch, 0.5 * ts);
  assert_rel_near(n.pos_m, 2.0 * R * 1e-4, 1e-12);
  assert_near(n.pos_m, 1276.0, 0.5);
  assert_near(n.vel_mps, 0.0, 1e-9);
  nav_analytic_schuler_error e = nav_analytic_schuler_east(&ch, 0.5 * ts);
  assert_rel_near(e.pos_m, -2.0 * R * 1e-4, 1e-12); /* east: -g phi_N */
  /* Accelerometer bias 10 ug: 2 R b / g = 127.6 m. */
  memset(&ch, 0, sizeof ch);
  ch.g_mps2 = g;
  ch.radius_m = R;
  ch.accel_bias_mps2 = 10e-6 * NAV_G0_MPS2;
  n = nav_analytic_schuler_north(&ch, 0.5 * ts);
  assert_near(n.pos_m, 127.6, 0.05);
  /* Gyro bias 0.01 deg/h: the velocity averages -R b_g over a period (0.309 m/s). */
  memset(&ch, 0, sizeof ch);
  ch.g_mps2 = g;
  ch.radius_m = R;
  ch.gyro_bias_rps = 0.01 * NAV_DEG2RAD / 3600.0;
  n = nav_analytic_schuler_north(&ch, ts);
  assert_near(n.pos_m / ts, -0.309, 0.0005); /* over a full period dr = -b_g R T_s */
  assert_near(n.vel_mps, 0.0, 1e-12);
  /* Short times: the table terms with the Schuler factors of numerics.md 1.2 (ii). */
  ch.dr0_m = 0.3;
  ch.dv0_mps = 0.02;
  ch.accel_bias_mps2 = 1e-4;
  ch.tilt0_rad = 2e-5;
  ch.gyro_bias_rps = 1e-6;
  for (double t = 1e-3; t < 400.0; t *= 3.7) {
    const double x = ws * t;
    const double drive = ch.accel_bias_mps2 + g * ch.tilt0_rad;
    const double want = ch.dr0_m + ch.dv0_mps * sin(x) / ws +
                        drive * t * t / 2 * (2 * (1 - cos(x)) / (x * x)) -
                        g * ch.gyro_bias_rps * t * t * t / 6 * (6 * (x - sin(x)) / (x * x * x));
    const double table = ch.dr0_m + ch.dv0_mps * t + drive * t * t / 2 - g * ch.gyro_bias_rps * t * t * t / 6;
    n = nav_analytic_schuler_north(&ch, t);
    /* The direct formula above cancels for small x (its own error is ~ eps b / ws^2 ~ 1e-14 m). */
    assert_near(n.pos_m, want, 1e-12 * fabs(want) + 1e-13);
    if (t < 280.0) assert_rel_near(n.pos_m, table, 0.01);
  }
  /* t -> 0: exactly the initial error, no cancellation. */
  n = nav_analytic_schuler_north(&ch, 0.0);
  assert_near(n.pos_m, 0.3, 0.0);
  assert_near(n.vel_mps, 0.02, 0.0);
}

/* ------------------------------------------------------------------ array geometry */

static void test_cube_layout_properties(void **state) {
  (void)state;
  const double r = 0.1;
  nav_accel_array cube;
  nav_array_geometry g;
  assert_int_equal(nav_array_cube_layout(r, &cube), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&cube, &g), NAV_OK);
  double det = 0.0;
  assert_int_equal(nav_array_h_det(&cube, &det), NAV_OK);
  print_message("det H = %.17g (8 r^3 = %.17g), cond = %.17g\n", det, 8 * r * r * r, g.cond);
  assert_rel_near(det, 8.0 * r * r * r, 1e-14);
  assert_near(g.cond, 1.0, 1e-13);
  /* E1.24 coefficients: H^-1 is exactly k times the sign patterns (k = 1/(2 sqrt 2)). */
  const double k = 1.0 / (2.0 * sqrt(2.0));
  static const double pat[6][6] = {{0, 0, 1, -1, 1, 1},   {1, 1, 0, 0, 1, -1},   {1, -1, 1, 1, 0, 0},
                                   {0, 0, 1, -1, -1, -1}, {-1, -1, 0, 0, 1, -1}, {1, -1, -1, -1, 0, 0}};
  for (int a = 0; a < 6; ++a)
    for (int i = 0; i < 6; ++i)
      assert_near(g.h_pinv[a][i], k * pat[a][i] / (a < 3 ? 1.0 : r), 1e-14 / r);
  /* (b) row norms sqrt(1/2) and sqrt(1/2)/r; kappa = kappa_f = 1/sqrt 2. */
  for (int j = 0; j < 3; ++j) {
    double nf = 0.0, nw = 0.0;
    for (int i = 0; i < 6; ++i) {
      nf += g.h_pinv[j][i] * g.h_pinv[j][i];
      nw += g.h_pinv[3 + j][i] * g.h_pinv[3 + j][i];
    }
    assert_rel_near(sqrt(nf), sqrt(0.5), 1e-14);
    assert_rel_near(sqrt(nw), sqrt(0.5) / r, 1e-14);
    assert_rel_near(g.kappa_w[j], sqrt(0.5), 1e-14);
    assert_rel_near(g.kappa_f[j], sqrt(0.5), 1e-14);
  }
  /* (c) H^-1 H^-T = diag(1/2, 1/2, 1/2, 1/(2r^2), 1/(2r^2), 1/(2r^2)). */
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) {
      const double want = a != b ? 0.0 : (a < 3 ? 0.5 : 0.5 / (r * r));
      assert_near(g.cov[a][b], want, 1e-13 / (r * r));
    }
  /* (a) the omega_dot rows annihilate c(omega); the f rows give -r (w_y w_z, w_x w_z, w_x w_y). */
  nav_rng rng;
  nav_rng_init(&rng, 4, 0, nav_rng_stream_id(NAV_RNG_STREAM_USER, 1));
  for (int trial = 0; trial < 100; ++trial) {
    const nav_vec3 w = nav_vec3_scale(nav_rng_gauss_vec3(&rng), 5.0);
    double c[6];
    nav_array_centripetal(&cube, w, c);
    double y[6] = {0};
    for (int a = 0; a < 6; ++a)
      for (int i = 0; i < 6; ++i)
        y[a] += g.h_pinv[a][i] * c[i];
    const double scale = r * nav_vec3_dot(w, w);
    for (int a = 3; a < 6; ++a)
      assert_near(y[a] * r, 0.0, 1e-15 * scale);
    assert_near(y[0], r * w.y * w.z, 1e-15 * scale);
    assert_near(y[1], r * w.x * w.z, 1e-15 * scale);
    assert_near(y[2], r * w.x * w.y, 1e-15 * scale);
    /* Readings built as vectors equal H [f; w_dot] + c(w) (E1.22 = E1.23). */
    const nav_vec3 f = nav_rng_gauss_vec3(&rng), dw = nav_rng_gauss_vec3(&rng);
    double a6[6];
    nav_array_readings(&cube, f, w, dw, a6);
    for (int i = 0; i < 6; ++i) {
      const double hx = g.h[i][0] * f.x + g.h[i][1] * f.y + g.h[i][2] * f.z + g.h[i][3] * dw.x +
                        g.h[i][4] * dw.y + g.h[i][5] * dw.z;
      assert_near(a6[i], hx + c[i], 1e-13 * (1.0 + fabs(c[i])));
    }
  }
  /* Common bias b on all six: omega_dot = -(1/sqrt 2) b / r per axis, f = +(1/sqrt 2) b. */
  const double b = 1e-3;
  for (int a = 0; a < 6; ++a) {
    double y = 0.0;
    for (int i = 0; i < 6; ++i)
      y += g.h_pinv[a][i] * b;
    assert_near(y, a < 3 ? b / sqrt(2.0) : -b / (sqrt(2.0) * r), 1e-15 / r);
  }
  /* Scale invariance: the same cube at 1 km has the same cond and kappa. */
  nav_accel_array big;
  nav_array_geometry gb;
  assert_int_equal(nav_array_cube_layout(1000.0, &big), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&big, &gb), NAV_OK);
  assert_near(gb.cond, 1.0, 1e-13);
  assert_rel_near(gb.kappa_w[1], sqrt(0.5), 1e-13);
}

static void test_general_layouts(void **state) {
  (void)state;
  nav_rng rng;
  nav_rng_init(&rng, 7, 0, nav_rng_stream_id(NAV_RNG_STREAM_USER, 2));
  /* Random layouts with N = 6..16: H^+ H = I (left inverse) and (H^+ H^+T) = (H^T H)^-1. */
  for (int n = 6; n <= NAV_ARRAY_MAX_SENSORS; ++n) {
    nav_accel_array a;
    memset(&a, 0, sizeof a);
    a.n_sensors = n;
    for (int i = 0; i < n; ++i) {
      a.r_bs_b_m[i] = nav_vec3_scale(nav_rng_gauss_vec3(&rng), 0.2);
      const nav_vec3 u = nav_rng_gauss_vec3(&rng);
      a.n_s_b[i] = nav_vec3_scale(u, 1.0 / nav_vec3_norm(u));
    }
    nav_array_geometry g;
    assert_int_equal(nav_array_geometry_compute(&a, &g), NAV_OK);
    for (int p = 0; p < 6; ++p)
      for (int q = 0; q < 6; ++q) {
        double acc = 0.0, cc = 0.0;
        for (int i = 0; i < n; ++i) {
          acc += g.h_pinv[p][i] * g.h[i][q];
          cc += g.h_pinv[p][i] * g.h_pinv[q][i];
        }
        assert_near(acc, p == q ? 1.0 : 0.0, 1e-12 * g.cond);
        assert_near(cc, g.cov[p][q], 1e-12 * (fabs(g.cov[p][q]) + fabs(g.cov[p][p])));
      }
    if (n == 6) {
      double det;
      assert_int_equal(nav_array_h_det(&a, &det), NAV_OK);
      assert_true(fabs(det) > 0.0);
    } else {
      double det;
      assert_int_equal(nav_array_h_det(&a, &det), NAV_ERR_INVALID_ARG);
    }
  }
  /* Redundancy pays: two cubes (N = 12, the second rotated 90 deg about z) give kappa = 1/2. */
  nav_accel_array two;
  nav_accel_array cube;
  assert_int_equal(nav_array_cube_layout(0.1, &cube), NAV_OK);
  two = cube;
  two.n_sensors = 12;
  for (int i = 0; i < 6; ++i) {
    const nav_vec3 rr = cube.r_bs_b_m[i], nn = cube.n_s_b[i];
    two.r_bs_b_m[6 + i] = nav_vec3_make(-rr.y, rr.x, rr.z);
    two.n_s_b[6 + i] = nav_vec3_make(-nn.y, nn.x, nn.z);
  }
  nav_array_geometry g2;
  assert_int_equal(nav_array_geometry_compute(&two, &g2), NAV_OK);
  for (int j = 0; j < 3; ++j) {
    assert_rel_near(g2.kappa_w[j], 0.5, 1e-13);
    assert_rel_near(g2.kappa_f[j], 0.5, 1e-13);
  }
  /* Singular: every axis along its lever arm (r x n = 0), so omega_dot is unobservable. */
  nav_accel_array radial;
  memset(&radial, 0, sizeof radial);
  radial.n_sensors = 6;
  for (int i = 0; i < 6; ++i) {
    radial.r_bs_b_m[i] = cube.r_bs_b_m[i];
    radial.n_s_b[i] = nav_vec3_scale(cube.r_bs_b_m[i], 10.0);
  }
  nav_array_geometry gs;
  memset(&gs, 0x5a, sizeof gs);
  nav_array_geometry keep = gs;
  assert_int_equal(nav_array_geometry_compute(&radial, &gs), NAV_ERR_NUMERIC);
  assert_memory_equal(&gs, &keep, sizeof gs);
  double det = 1.0;
  assert_int_equal(nav_array_h_det(&radial, &det), NAV_OK);
  assert_near(det, 0.0, 0.0);
  /* A cube with one axis tilted by 1 mrad stays invertible. */
  nav_accel_array pert = cube;
  pert.n_s_b[0] = nav_vec3_make(0.0, cos(0.25 * NAV_PI + 1e-3), sin(0.25 * NAV_PI + 1e-3));
  assert_int_equal(nav_array_geometry_compute(&pert, &gs), NAV_OK);
  /* Argument checks. */
  nav_accel_array bad = cube;
  bad.n_sensors = 5;
  assert_int_equal(nav_array_geometry_compute(&bad, &gs), NAV_ERR_INVALID_ARG);
  bad = cube;
  bad.n_sensors = NAV_ARRAY_MAX_SENSORS + 1;
  assert_int_equal(nav_array_geometry_compute(&bad, &gs), NAV_ERR_INVALID_ARG);
  bad = cube;
  bad.n_s_b[2] = nav_vec3_make(1.0, 1.0, 0.0);
  assert_int_equal(nav_array_geometry_compute(&bad, &gs), NAV_ERR_INVALID_ARG);
  bad = cube;
  bad.r_bs_b_m[3].x = NAN;
  assert_int_equal(nav_array_geometry_compute(&bad, &gs), NAV_ERR_INVALID_ARG);
  bad = cube;
  for (int i = 0; i < 6; ++i)
    bad.r_bs_b_m[i] = nav_vec3_zero();
  assert_int_equal(nav_array_geometry_compute(&bad, &gs), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_array_geometry_compute(NULL, &gs), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_array_cube_layout(0.0, &bad), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_array_cube_layout(NAN, &bad), NAV_ERR_INVALID_ARG);
}

/* ------------------------------------------------------------------ T1.2 Monte Carlo */

/*
 * A linear chain driven by per-sample Gaussian noise and integrated by the rectangle rule
 * (each stage adds dt times the already-updated previous stage): state x[0] = the driving value
 * (white: redrawn each step; GM: e_k = phi e_(k-1) + sqrt(1 - phi^2) sigma w_k), x[1..m] the
 * integrals. Besides the Monte Carlo, the exact variance of the same discrete chain is
 * propagated (P <- A P A^T + Q), so the test separates the sampling scatter (chi-square band
 * [0.969, 1.031] for N = 2000, numerics.md T6.6) from the discretisation bias relative to the
 * continuous formula (order dt/t, numerics.md T1.2).
 */
#define MC_RUNS 2000
#define MC_DT 0.01
#define MC_STEPS 1000 /* t = 10 s */

typedef struct chain {
  int m;          /* number of integrations, <= 4 */
  bool gm;        /* GM driving process instead of white */
  double sigma;   /* per-sample sd (white) or process sd (GM) */
  double phi;     /* GM: exp(-dt/T) */
  double gain[5]; /* gain applied when stage j integrates stage j-1 (e.g. g for tilt -> v) */
} chain;

/* Exact discrete variance of stage j after n steps (per-run initial state zero except GM). */
static void chain_exact_var(const chain *c, int n, double *var_out) {
  const int s = c->m + 1;
  double p[5][5] = {{0}};
  if (c->gm) p[0][0] = c->sigma * c->sigma;
  /* x' = A x + B w: x0' = phi x0 + q w (white: phi = 0, q = sigma); xj' = xj + gain_j dt xj-1'. */
  double a[5][5] = {{0}}, bq[5] = {0};
  const double phi = c->gm ? c->phi : 0.0;
  const double q = c->gm ? c->sigma * sqrt(1.0 - c->phi * c->phi) : c->sigma;
  a[0][0] = phi;
  bq[0] = q;
  for (int j = 1; j < s; ++j) {
    for (int k = 0; k < s; ++k)
      a[j][k] = c->gain[j] * MC_DT * a[j - 1][k];
    a[j][j] += 1.0;
    bq[j] = c->gain[j] * MC_DT * bq[j - 1];
  }
  for (int step = 0; step < n; ++step) {
    double ap[5][5] = {{0}}, np[5][5] = {{0}};
    for (int i = 0; i < s; ++i)
      for (int j = 0; j < s; ++j)
        for (int k = 0; k < s; ++k)
          ap[i][j] += a[i][k] * p[k][j];
    for (int i = 0; i < s; ++i)
      for (int j = 0; j < s; ++j) {
        for (int k = 0; k < s; ++k)
          np[i][j] += ap[i][k] * a[j][k];
        np[i][j] += bq[i] * bq[j];
      }
    memcpy(p, np, sizeof p);
  }
  for (int j = 0; j < s; ++j)
    var_out[j] = p[j][j];
}

/* Monte Carlo: RMS over runs of each stage at step n. */
static void chain_mc(const chain *c, uint64_t seed, double *rms_out) {
  const int s = c->m + 1;
  double acc[5] = {0};
  for (int run = 0; run < MC_RUNS; ++run) {
    nav_rng rng;
    nav_rng_init(&rng, seed, (uint64_t)run, nav_rng_stream_id(NAV_RNG_STREAM_USER, 3));
    double x[5] = {0};
    const double q = c->gm ? c->sigma * sqrt(1.0 - c->phi * c->phi) : c->sigma;
    if (c->gm) x[0] = c->sigma * nav_rng_gauss(&rng); /* stationary start (E2.4-E2.5) */
    for (int k = 0; k < MC_STEPS; ++k) {
      x[0] = (c->gm ? c->phi * x[0] : 0.0) + q * nav_rng_gauss(&rng);
      for (int j = 1; j < s; ++j)
        x[j] += c->gain[j] * MC_DT * x[j - 1];
    }
    for (int j = 0; j < s; ++j)
      acc[j] += x[j] * x[j];
  }
  for (int j = 0; j < s; ++j)
    rms_out[j] = sqrt(acc[j] / MC_RUNS);
}

/* Checks one stage: MC vs exact discrete in the chi-square band, exact discrete vs formula
 * within the dt/t allowance (2 m dt / t relative, covering the rectangle rule's leading term). */
static void check_stage(const char *name, double mc, double exact_var, double formula, int m, double t) {
  const double exact = sqrt(exact_var);
  print_message("%-28s MC %.6g  discrete %.6g  formula %.6g  MC/formula %.4f\n", name, mc, exact, formula,
                mc / formula);
  assert_near(mc / exact, 1.0, 0.031);
  assert_rel_near(exact, formula, 2.0 * m * MC_DT / t);
}

static void test_t12_monte_carlo(void **state) {
  (void)state;
  const double t = MC_STEPS * MC_DT, g = K_G0;
  double mc[5], var[5];
  /* E1.11: accelerometer white noise 1 mg per sample -> v, r. */
  chain ca = {2, false, K_SIGMA, 0.0, {0, 1, 1, 0, 0}};
  chain_mc(&ca, 101, mc);
  chain_exact_var(&ca, MC_STEPS, var);
  const double na = nav_analytic_density_from_sample_sd(K_SIGMA, MC_DT);
  check_stage("E1.11 accel noise: v", mc[1], var[1], nav_analytic_white_sd(na, t, 1), 1, t);
  check_stage("E1.11 accel noise: r", mc[2], var[2], nav_analytic_white_sd(na, t, 2), 2, t);
  /* E1.15: gyro white noise 0.1 deg/s per sample -> tilt, v = g tilt, r. */
  chain cg = {3, false, 0.1 * NAV_DEG2RAD, 0.0, {0, 1, g, 1, 0}};
  chain_mc(&cg, 102, mc);
  chain_exact_var(&cg, MC_STEPS, var);
  const double ng = nav_analytic_density_from_sample_sd(0.1 * NAV_DEG2RAD, MC_DT);
  check_stage("E1.15 gyro noise: att", mc[1], var[1], nav_analytic_white_sd(ng, t, 1), 1, t);
  check_stage("E1.15 gyro noise: v", mc[2], var[2], g * nav_analytic_white_sd(ng, t, 2), 2, t);
  check_stage("E1.15 gyro noise: r (t^5/20)", mc[3], var[3], g * nav_analytic_white_sd(ng, t, 3), 3, t);
  /* E1.16: gyro GM bias, T = 5 s (t/T = 2: neither limit). */
  const double tau = 5.0, sg = 1e-3;
  chain cm = {3, true, sg, exp(-MC_DT / tau), {0, 1, 1, 1, 0}};
  chain_mc(&cm, 103, mc);
  chain_exact_var(&cm, MC_STEPS, var);
  check_stage("E1.3 GM: I1", mc[1], var[1], sqrt(nav_analytic_gm_var_i1(sg, tau, t)), 1, t);
  check_stage("E1.4 GM: I2", mc[2], var[2], sqrt(nav_analytic_gm_var_i2(sg, tau, t)), 2, t);
  check_stage("E1.5 GM: I3", mc[3], var[3], sqrt(nav_analytic_gm_var_i3(sg, tau, t)), 3, t);

  /* E1.25-E1.28: the gyro-free chain with six sensors (cube, r = 0.1 m, 1 mg per sample), the
   * array solved by H^-1 per sample: omega_dot_y -> omega_y -> alpha_y -> v_x (+ f_x) -> r_x. */
  nav_accel_array cube;
  nav_array_geometry geo;
  assert_int_equal(nav_array_cube_layout(K_R, &cube), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&cube, &geo), NAV_OK);
  double acc_w = 0.0, acc_a = 0.0, acc_r = 0.0;
  for (int run = 0; run < MC_RUNS; ++run) {
    nav_rng rs[6];
    for (unsigned i = 0; i < 6; ++i)
      nav_rng_init(&rs[i], 104, (uint64_t)run, nav_rng_stream_id(NAV_RNG_STREAM_ACCEL_NOISE, i));
    double w = 0.0, al = 0.0, v = 0.0, r = 0.0;
    for (int k = 0; k < MC_STEPS; ++k) {
      double e[6], fx = 0.0, dwy = 0.0;
      for (int i = 0; i < 6; ++i)
        e[i] = K_SIGMA * nav_rng_gauss(&rs[i]);
      for (int i = 0; i < 6; ++i) {
        fx += geo.h_pinv[0][i] * e[i];
        dwy += geo.h_pinv[4][i] * e[i];
      }
      w += dwy * MC_DT;
      al += w * MC_DT;
      v += (fx + g * al) * MC_DT;
      r += v * MC_DT;
    }
    acc_w += w * w;
    acc_a += al * al;
    acc_r += r * r;
  }
  /* Exact discrete variance: the f path (2 integrations) and the omega_dot path (4) are
   * independent for the cube (E1.24 property (c)). */
  const double kw = geo.kappa_w[1], kf = geo.kappa_f[0];
  chain cw = {4, false, kw * K_SIGMA / K_R, 0.0, {0, 1, 1, g, 1}};
  chain cf = {2, false, kf * K_SIGMA, 0.0, {0, 1, 1, 0, 0}};
  double vw[5], vf[5];
  chain_exact_var(&cw, MC_STEPS, vw);
  chain_exact_var(&cf, MC_STEPS, vf);
  nav_analytic_gyrofree_spec sp;
  assert_int_equal(nav_analytic_gyrofree_spec_from_geometry(
                       &geo, g, 0.0, nav_analytic_density_from_sample_sd(K_SIGMA, MC_DT), &sp),
                   NAV_OK);
  nav_analytic_gyrofree_errors ge;
  assert_int_equal(nav_analytic_gyrofree_eval(&sp, t, &ge), NAV_OK);
  check_stage("E1.25 gyro-free: omega", sqrt(acc_w / MC_RUNS), vw[1], ge.rate_sd_rps, 1, t);
  check_stage("E1.26 gyro-free: alpha", sqrt(acc_a / MC_RUNS), vw[2], ge.att_sd_rad, 2, t);
  check_stage("E1.28 gyro-free: r (t^7/252)", sqrt(acc_r / MC_RUNS), vw[4] + vf[2], ge.pos_sd_m, 4, t);
  /* numerics.md 1.5: 13.72 m (its MC) vs 13.55 m (/252) vs 8.57 m (/630) at 10 s. */
  assert_near(ge.pos_sd_m, 13.55, 0.005);
  const double paper = sqrt(kf * kf * K_SIGMA * K_SIGMA * MC_DT * t * t * t / 3 +
                            (g * kw * K_SIGMA / K_R) * (g * kw * K_SIGMA / K_R) * MC_DT * pow(t, 7) / 630);
  assert_near(paper, 8.57, 0.005);
  assert_true(sqrt(acc_r / MC_RUNS) / paper > 1.031 * 1.5); /* the /630 is rejected outright */
}

/* ------------------------------------------------------------------ preliminary estimate */

static void test_estimate_curves(void **state) {
  (void)state;
  nav_analytic_estimate_config cfg = nav_analytic_estimate_config_default();
  cfg.imu.accel_bias_mps2 = K_B;
  cfg.imu.accel_vrw_mps_per_sqrt_s = nav_analytic_density_from_sample_sd(K_SIGMA, K_DT);
  cfg.imu.gyro_bias_rps = 10.0 * NAV_DEG2RAD / 3600.0;
  cfg.imu.gyro_arw_rad_per_sqrt_s = 0.1 * NAV_DEG2RAD / 60.0;
  cfg.with_gyrofree = true;
  cfg.array_accel_noise_mps_per_sqrt_s = nav_analytic_density_from_sample_sd(K_SIGMA, K_DT);
  const double t[5] = {0.0, 1.0, 10.0, 60.0, 600.0};
  nav_analytic_estimate_point p[5];
  assert_int_equal(nav_analytic_estimate(&cfg, t, 5, p), NAV_OK);
  for (int i = 0; i < 5; ++i) {
    print_message(
        "t=%5.0f gyro INS r %.6g v %.6g a %.6g %s | gyro-free r %.6g v %.6g a %.6g %s | paper(1) %.6g\n",
        t[i], p[i].gyro_ins.pos_sd_m, p[i].gyro_ins.vel_sd_mps, p[i].gyro_ins.att_sd_rad,
        p[i].gyro_ins_short_time_ok ? "ok" : "beyond 1 %", p[i].gyrofree.pos_sd_m, p[i].gyrofree.vel_sd_mps,
        p[i].gyrofree.att_sd_rad, p[i].gyrofree_small_angle_ok ? "ok" : "large angle",
        p[i].gyrofree_paper_pos_m);
    assert_near(p[i].t_s, t[i], 0.0);
    nav_analytic_gyro_ins_table tab;
    assert_int_equal(nav_analytic_gyro_ins_table_eval(&cfg.imu, t[i], &tab), NAV_OK);
    assert_rel_near(p[i].gyro_ins.pos_sd_m, tab.rss.pos_m, 1e-15);
  }
  /* Gyro INS with noise only in the array (cube): its curve is E1.28's noise column. */
  assert_rel_near(p[2].gyro_ins.pos_sd_m, 0.497426, 5e-6); /* Table 1.6c RSS */
  assert_rel_near(p[2].gyrofree.pos_sd_m, 13.5465, 5e-6);  /* Table 1.6b noise, no bias */
  assert_rel_near(p[3].gyrofree.pos_sd_m, 7167.30, 5e-6);
  assert_true(p[3].gyro_ins_short_time_ok);
  assert_false(p[4].gyro_ins_short_time_ok);
  assert_true(p[1].gyrofree_small_angle_ok);
  assert_false(p[3].gyrofree_small_angle_ok);
  assert_near(p[0].gyro_ins.pos_sd_m, 0.0, 0.0);
  /* The paper column: formula (1) with kappa = 1, /630 (no bias here): Table 1.6a last column. */
  assert_rel_near(p[2].gyrofree_paper_pos_m, 12.1163, 5e-6);
  /* Biases as independent random constants: RSS of the f part and the omega_dot part. */
  cfg.array_accel_noise_mps_per_sqrt_s = 0.0;
  cfg.array_accel_bias_mps2 = K_B;
  cfg.array_init_rate_sd_rps = 1e-4;
  cfg.imu = nav_analytic_imu_spec_default();
  cfg.imu.init_pos_sd_m = 0.5;
  assert_int_equal(nav_analytic_estimate(&cfg, t + 1, 1, p), NAV_OK);
  const double kk = sqrt(0.5), tt = 1.0;
  const double pos_f = kk * K_B * tt * tt / 2, pos_w = K_G0 * kk * K_B * pow(tt, 4) / (24 * K_R);
  const double pos_w0 = K_G0 * 1e-4 * tt * tt * tt / 6;
  assert_rel_near(p[0].gyrofree.pos_sd_m, sqrt(0.25 + pos_f * pos_f + pos_w * pos_w + pos_w0 * pos_w0),
                  1e-14);
  const double att = sqrt(pow(kk * K_B * tt * tt / (2 * K_R), 2) + pow(1e-4 * tt, 2));
  assert_rel_near(p[0].gyrofree.att_sd_rad, att, 1e-14);
  /* Arguments: count 0 is fine; bad times and layouts are rejected, output untouched. */
  assert_int_equal(nav_analytic_estimate(&cfg, NULL, 0, NULL), NAV_OK);
  nav_analytic_estimate_point keep;
  memset(&keep, 0x5a, sizeof keep);
  nav_analytic_estimate_point probe = keep;
  const double tbad = -1.0;
  assert_int_equal(nav_analytic_estimate(&cfg, &tbad, 1, &probe), NAV_ERR_INVALID_ARG);
  cfg.array.n_sensors = 3;
  assert_int_equal(nav_analytic_estimate(&cfg, t, 1, &probe), NAV_ERR_INVALID_ARG);
  assert_memory_equal(&probe, &keep, sizeof keep);
  cfg.with_gyrofree = false; /* the array is ignored then */
  assert_int_equal(nav_analytic_estimate(&cfg, t, 1, &probe), NAV_OK);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_kernels),
      cmocka_unit_test(test_table_1_6a),
      cmocka_unit_test(test_table_1_6b),
      cmocka_unit_test(test_table_1_6c),
      cmocka_unit_test(test_table_1_6d),
      cmocka_unit_test(test_e121_vs_t63),
      cmocka_unit_test(test_gyro_ins_table_terms),
      cmocka_unit_test(test_gm_series_vs_closed_form),
      cmocka_unit_test(test_schuler),
      cmocka_unit_test(test_cube_layout_properties),
      cmocka_unit_test(test_general_layouts),
      cmocka_unit_test(test_t12_monte_carlo),
      cmocka_unit_test(test_estimate_curves),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
