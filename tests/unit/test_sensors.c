/*
 * Sensor error models (nav_sensors.h) and the catalogs (nav_catalog.h): numerics.md T2.1-T2.7,
 * saturation, the GNSS receiver model, datasheet unit conversions and catalog loading.
 *
 * Statistical checks and their sample sizes. Every tolerance below is the one numerics.md (or the
 * issue) states; the sample sizes were chosen as the smallest that make each tolerance at least
 * three standard deviations of its estimator, and each test asserts that (guard_3sigma) before it
 * asserts the value, so a later change of n cannot silently make a check meaningless. Estimator
 * standard deviations:
 * - Allan deviation: equivalent degrees of freedom of the overlapping estimator from Riley, NIST
 *   SP 1065 (2008) Table 5 (white FM, random-walk FM, white PM), pooled over the three independent
 *   axes (3 x edf); relative sd of the deviation = 1 / sqrt(2 edf). For the Gauss-Markov process
 *   the white-FM formula is used (the GM looks like white FM for tau >> T, where the check is
 *   tightest); a 40-run Monte Carlo at n = 2e6 measured 0.10, 0.29, 0.37, 0.74 and 1.76 % at
 *   tau = 1, 10, 18.9, 100, 1000 s against 0.10, 0.32, 0.32, 0.75 and 1.67 % from the formula.
 * - Sample standard deviation of n normal values: relative sd 1 / sqrt(2 n).
 * - Sample variance and autocorrelation of the AR(1) bias sequence (phi = exp(-dt/T)): Bartlett's
 *   formulas, var(s^2)/sigma^4 = (2/n)(1 + phi^2)/(1 - phi^2) and
 *   var(r_h) = (1/n)[(1 + phi^2)(1 - phi^(2h))/(1 - phi^2) - 2 h phi^(2h)] (Box and Jenkins,
 *   Time Series Analysis, 1976, eq. 2.1.13 and 6.2.x), pooled over three axes.
 * Seeds are fixed, so each check passes or fails deterministically; the seed is printed.
 */
#define _POSIX_C_SOURCE 200809L

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_catalog.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sensors.h"
#include "sensors/imu_model_internal.h"

static const uint64_t k_seed = 20240611;

/* ================================================================ statistics helpers */

/* NIST SP 1065 Table 5, N = number of phase points (samples + 1), m = cluster size. */
static double edf_white_fm(double n_phase, double m) {
  return (3.0 * (n_phase - 1.0) / (2.0 * m) - 2.0 * (n_phase - 2.0) / n_phase) *
         (4.0 * m * m / (4.0 * m * m + 5.0));
}
static double edf_rw_fm(double n_phase, double m) {
  return (n_phase - 2.0) / (m * (n_phase - 3.0) * (n_phase - 3.0)) *
         ((n_phase - 1.0) * (n_phase - 1.0) - 3.0 * m * (n_phase - 1.0) + 4.0 * m * m);
}
static double edf_white_pm(double n_phase, double m) {
  return (n_phase + 1.0) * (n_phase - 2.0 * m) / (2.0 * (n_phase - m));
}
/* Relative sd of an Allan deviation pooled (variance-averaged) over `axes` independent series. */
static double adev_rel_sd(double edf, int axes) {
  return 1.0 / sqrt(2.0 * edf * axes);
}

/* The sample size must make `tol` at least three estimator standard deviations. */
#define guard_3sigma(what, tol, sd)                                                                          \
  do {                                                                                                       \
    const double g_tol_ = (tol), g_sd_ = (sd);                                                               \
    if (!(g_tol_ >= 3.0 * g_sd_))                                                                            \
      fail_msg("%s: tolerance %.3g is only %.2f estimator sd (%.3g); increase the sample size", (what),      \
               g_tol_, g_tol_ / g_sd_, g_sd_);                                                               \
  } while (0)

/* Allan deviation of the first-order GM (numerics.md E2.6). */
static double gm_adev(double sigma, double tau_c, double tau) {
  const double x = tau / tau_c;
  return sigma * sqrt((2.0 / x) * (1.0 - (3.0 - 4.0 * exp(-x) + exp(-2.0 * x)) / (2.0 * x)));
}

/* Three per-axis series of a rate error, with a workspace for the Allan estimator. */
typedef struct series {
  size_t n;
  double dt;
  double *y[3];
  double *work;
} series;

static void series_alloc(series *s, size_t n, double dt) {
  s->n = n;
  s->dt = dt;
  for (int a = 0; a < 3; ++a) {
    s->y[a] = malloc(n * sizeof(double));
    assert_non_null(s->y[a]);
  }
  s->work = malloc((n + 1) * sizeof(double));
  assert_non_null(s->work);
}

static void series_free(series *s) {
  for (int a = 0; a < 3; ++a)
    free(s->y[a]);
  free(s->work);
}

/* Pooled Allan deviation over the three axes (mean of the three variances). */
static void pooled_adev(series *s, const size_t *m, size_t n_m, double *adev) {
  double tmp[64];
  assert_true(n_m <= 64);
  for (size_t i = 0; i < n_m; ++i)
    adev[i] = 0.0;
  for (int a = 0; a < 3; ++a) {
    assert_int_equal(nav_allan_overlapping(s->y[a], s->n, s->dt, m, n_m, s->work, tmp), NAV_OK);
    for (size_t i = 0; i < n_m; ++i)
      adev[i] += tmp[i] * tmp[i] / 3.0;
  }
  for (size_t i = 0; i < n_m; ++i)
    adev[i] = sqrt(adev[i]);
}

static nav_imu_increment increment(int64_t k, double dt) {
  nav_imu_increment inc;
  memset(&inc, 0, sizeof inc);
  inc.k = k;
  inc.t_s = (double)k * dt;
  inc.dt_s = dt;
  return inc;
}

/* Run a gyro-only model with ideal increments = 0 and store the gyro output rate dtheta/dt. */
static void run_gyro_zero_input(const nav_imu_model_config *cfg, uint64_t run, series *s) {
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(cfg, k_seed, run, &m), NAV_OK);
  for (size_t k = 0; k < s->n; ++k) {
    const nav_imu_increment ideal = increment((int64_t)k + 1, s->dt);
    nav_imu_increment meas;
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    s->y[0][k] = meas.dtheta_b_rad.x / s->dt;
    s->y[1][k] = meas.dtheta_b_rad.y / s->dt;
    s->y[2][k] = meas.dtheta_b_rad.z / s->dt;
  }
  nav_imu_model_destroy(m);
}

static double log_slope(double a1, double tau1, double a2, double tau2) {
  return log(a2 / a1) / log(tau2 / tau1);
}

static uint64_t bits_of(double x) {
  uint64_t b = 0;
  memcpy(&b, &x, sizeof b);
  return b;
}

static bool vec3_bit_equal(nav_vec3 a, nav_vec3 b) {
  return bits_of(a.x) == bits_of(b.x) && bits_of(a.y) == bits_of(b.y) && bits_of(a.z) == bits_of(b.z);
}

static nav_vec3 v3(double x) {
  return nav_vec3_make(x, x, x);
}

/* 1 off the diagonal, 0 on it (misalignment sigma pattern). */
static nav_mat3 offdiag_ones(void) {
  const nav_mat3 m = {{{0.0, 1.0, 1.0}, {1.0, 0.0, 1.0}, {1.0, 1.0, 0.0}}};
  return m;
}

/* ================================================================ unit conversions */

/* numerics.md 2.2 / 2.4 examples, each quoted there to the digits compared here (half a unit in
 * the last quoted digit), plus the catalog's own SI columns as a second, independent reference. */
static void test_units_numerics_examples(void **state) {
  (void)state;
  assert_near(nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.15), 4.36332e-5, 0.5e-10);
  assert_near(nav_unit_deg_per_s_per_sqrt_hz_to_rad_per_sqrt_s(0.007), 1.22173e-4, 0.5e-9);
  /* "= 0.42 deg/sqrt(h)": the same number through the other conversion (ARW = 60 x density). */
  assert_rel_near(nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.42),
                  nav_unit_deg_per_s_per_sqrt_hz_to_rad_per_sqrt_s(0.007), 4e-16);
  assert_near(nav_unit_deg_per_h_per_sqrt_hz_to_rad_per_sqrt_s(60.0 * 0.42),
              nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.42), 1e-20);
  assert_near(nav_unit_mps_per_sqrt_h_to_mps_per_sqrt_s(0.07), 1.16667e-3, 0.5e-8);
  assert_near(nav_unit_ug_per_sqrt_hz_to_mps_per_sqrt_s(100.0), 9.80665e-4, 0.5e-9);
  assert_near(nav_unit_ug_per_sqrt_hz_to_mps_per_sqrt_s(100.0) * 60.0, 0.0588, 0.5e-4); /* m/s/sqrt(h) */
  assert_near(nav_unit_ft_per_s_per_sqrt_h_to_mps_per_sqrt_s(0.065), 3.302e-4, 0.5e-7);
  /* Per-sample sigma N / sqrt(dt) at 100 Hz and 1 kHz (numerics.md 2.2 example, T2.1). */
  assert_near(nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.15) / sqrt(0.01), 4.36332e-4, 0.5e-9);
  /* numerics.md quotes 1.37981e-3 here; the value is 1.3798039e-3, which rounds to 1.37980e-3 (the
   * quoted last digit is one unit high). Compared with the correctly rounded figure. */
  assert_near(nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.15) / sqrt(0.001), 1.37980e-3, 0.5e-8);
  /* E2.7 units: K [deg/h/sqrt(h)] x (pi/180)/3600/60. */
  assert_rel_near(nav_unit_deg_per_h_per_sqrt_h_to_rps_per_sqrt_s(1.0), NAV_PI / 180.0 / 216000.0, 1e-15);
  /* Catalog SI columns (resources/imu_catalog.csv, 6 digits): 2 deg/h, 0.84 deg/sqrt(h), 30 ug,
   * 175 ug/sqrt(Hz). */
  assert_near(nav_unit_deg_per_h_to_rps(2.0), 9.69627e-06, 0.5e-11);
  assert_near(nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(0.84), 0.000244346, 0.5e-9);
  assert_near(nav_unit_ug_to_mps2(30.0), 0.000294199, 0.5e-9);
  assert_near(nav_unit_ug_per_sqrt_hz_to_mps_per_sqrt_s(175.0), 0.00171616, 0.5e-8); /* BMI088 175 ug/rtHz */
  /* Exact scalings. */
  assert_near(nav_unit_mg_to_mps2(1.0), 9.80665e-3, 1e-18);
  assert_near(nav_unit_g_to_mps2(1.0), 9.80665, 0.0);
  assert_near(nav_unit_ppm_to_ratio(500.0), 5e-4, 1e-19);
  assert_near(nav_unit_mrad_to_rad(1.0), 1e-3, 0.0);
  assert_rel_near(nav_unit_deg_per_s_to_rps(180.0), NAV_PI, 1e-16);
  assert_rel_near(nav_unit_deg_per_h_per_g_to_rps_per_mps2(1.0), NAV_PI / 180.0 / 3600.0 / 9.80665, 1e-15);
  /* GNSS accuracy figures (numerics.md section 7: CEP 1.1774, 2D95 2.4477, 1D95 1.96 sigma). */
  assert_near(nav_unit_cep_to_sigma_m(1.1774), 1.0, 1e-4);
  assert_near(nav_unit_h95_to_sigma_m(2.4477), 1.0, 1e-4);
  assert_near(nav_unit_v95_to_sigma_m(1.96), 1.0, 1e-4);
}

/* Bias instability -> GM (numerics.md 2.3): the constants are the maximum of E2.6. */
static void test_bias_instability_mapping(void **state) {
  (void)state;
  assert_near(NAV_GM_ALLAN_PEAK_TAU_RATIO, 1.8926, 0.5e-4);
  assert_near(NAV_GM_ALLAN_PEAK_SIGMA_RATIO, 0.61736, 0.5e-5);
  /* The peak really is a maximum of E2.6 (independent evaluation). */
  const double peak = gm_adev(1.0, 1.0, NAV_GM_ALLAN_PEAK_TAU_RATIO);
  assert_near(peak, NAV_GM_ALLAN_PEAK_SIGMA_RATIO, 1e-15);
  assert_true(gm_adev(1.0, 1.0, NAV_GM_ALLAN_PEAK_TAU_RATIO * 1.001) < peak);
  assert_true(gm_adev(1.0, 1.0, NAV_GM_ALLAN_PEAK_TAU_RATIO / 1.001) < peak);
  /* sigma = B / 0.61736 = 1.620 B; T = tau_min / 1.8926; or sigma = B. */
  const double b = nav_unit_deg_per_h_to_rps(2.0);
  const nav_gm_params p = nav_gm_from_bias_instability(b, 300.0, NAV_BI_ALLAN_PEAK);
  assert_near(p.sigma / b, 1.620, 0.5e-3);
  assert_near(p.tau_s, 300.0 / 1.8926, 1e-2);
  /* The mapped GM's Allan peak equals B at tau_min. */
  assert_rel_near(gm_adev(p.sigma, p.tau_s, 300.0), b, 1e-12);
  const nav_gm_params q = nav_gm_from_bias_instability(b, 300.0, NAV_BI_SIGMA_EQUALS_B);
  assert_true(q.sigma == b);
  assert_true(isnan(nav_gm_sigma_from_bias_instability(b, (nav_bi_convention)7)));
  assert_string_equal(nav_bi_convention_name(NAV_BI_ALLAN_PEAK), "allan_peak");
}

/* ================================================================ Allan estimator */

/* Known answers: an alternating series (phase 0,1,0,1,...: every second difference is +/-2) and a
 * linear rate ramp (sigma_A = R tau / sqrt(2), IEEE Std 952-1997 Annex C). */
static void test_allan_known_answers(void **state) {
  (void)state;
  enum { N = 1000 };
  static double y[N], work[N + 1];
  for (size_t i = 0; i < N; ++i)
    y[i] = (i % 2 == 0) ? 1.0 : -1.0;
  const size_t m[3] = {1, 2, 7};
  double adev[3];
  assert_int_equal(nav_allan_overlapping(y, N, 0.01, m, 3, work, adev), NAV_OK);
  assert_near(adev[0], sqrt(2.0), 1e-14);
  assert_near(adev[1], 0.0, 1e-14);
  /* odd m: every second difference is +/-2 again; / (2 m^2) */
  assert_near(adev[2], sqrt(4.0 / (2.0 * 49.0)), 1e-14);

  const double dt = 0.1, ramp = 0.003; /* rate drift [unit/s] */
  for (size_t i = 0; i < N; ++i)
    y[i] = 5.0 + ramp * (double)i * dt;
  const size_t mr[3] = {1, 10, 100};
  assert_int_equal(nav_allan_overlapping(y, N, dt, mr, 3, work, adev), NAV_OK);
  for (int i = 0; i < 3; ++i)
    assert_rel_near(adev[i], ramp * (double)mr[i] * dt / sqrt(2.0), 1e-9);

  /* Argument checks; adev untouched on failure. */
  const size_t bad[1] = {N / 2 + 1};
  adev[0] = -1.0;
  assert_int_equal(nav_allan_overlapping(y, N, dt, bad, 1, work, adev), NAV_ERR_INVALID_ARG);
  assert_true(adev[0] == -1.0);
  const size_t zero[1] = {0};
  assert_int_equal(nav_allan_overlapping(y, N, dt, zero, 1, work, adev), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_allan_overlapping(y, N, 0.0, mr, 1, work, adev), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_allan_overlapping(y, 1, dt, mr, 1, work, adev), NAV_ERR_INVALID_ARG);
  y[3] = NAN;
  assert_int_equal(nav_allan_overlapping(y, N, dt, mr, 1, work, adev), NAV_ERR_NUMERIC);
  assert_int_equal(nav_allan_overlapping(NULL, 0, dt, NULL, 0, NULL, NULL), NAV_OK);

  /* Log-spaced clusters: round(10^(i/3)) = 1, 2, 5, 10, 22, 46, 100. */
  size_t cl[16], count = 0;
  assert_int_equal(nav_allan_log_clusters(100, 3, cl, 16, &count), NAV_OK);
  const size_t want[7] = {1, 2, 5, 10, 22, 46, 100};
  assert_int_equal(count, 7);
  for (int i = 0; i < 7; ++i)
    assert_int_equal(cl[i], want[i]);
  assert_int_equal(nav_allan_log_clusters(100, 3, NULL, 0, &count), NAV_OK);
  assert_int_equal(count, 7);
  cl[0] = 99;
  assert_int_equal(nav_allan_log_clusters(100, 3, cl, 6, &count), NAV_ERR_OUT_OF_RANGE);
  assert_int_equal(count, 7);
  assert_int_equal(cl[0], 99);
  /* 10 per decade never repeats a value after the first few (1, 1, 2, 2, 3, 3, 4, 5, 6, 8 -> distinct). */
  assert_int_equal(nav_allan_log_clusters(10, 10, cl, 16, &count), NAV_OK);
  for (size_t i = 1; i < count; ++i)
    assert_true(cl[i] > cl[i - 1]);
  assert_int_equal(nav_allan_log_clusters(0, 3, cl, 16, &count), NAV_ERR_INVALID_ARG);
  assert_near(nav_allan_rel_uncertainty(1001, 1), 1.0 / sqrt(2000.0), 1e-15);
  assert_true(isinf(nav_allan_rel_uncertainty(10, 10)));
}

/* ================================================================ T2.1 white noise */

static void white_noise_at(double dt, size_t n) {
  const double N = 4.36332e-5; /* rad/sqrt(s): 0.15 deg/sqrt(h) */
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_NOISE;
  cfg.gyro.arw_rad_per_sqrt_s = v3(N);
  series s;
  series_alloc(&s, n, dt);
  run_gyro_zero_input(&cfg, 1, &s);

  /* Per-sample standard deviation N / sqrt(dt) (known mean 0), +/- 0.5 %. */
  double ss = 0.0;
  for (int a = 0; a < 3; ++a)
    for (size_t k = 0; k < n; ++k)
      ss += s.y[a][k] * s.y[a][k];
  const double sd = sqrt(ss / (3.0 * (double)n));
  guard_3sigma("T2.1 per-sample sd", 0.005, 1.0 / sqrt(2.0 * 3.0 * (double)n));
  assert_rel_near(sd, N / sqrt(dt), 0.005);

  /* Allan deviation at 0.1, 1 and 10 s. */
  const size_t m[3] = {(size_t)llround(0.1 / dt), (size_t)llround(1.0 / dt), (size_t)llround(10.0 / dt)};
  double adev[3];
  pooled_adev(&s, m, 3, adev);
  const double np = (double)n + 1.0;
  guard_3sigma("T2.1 Allan(1 s)", 0.03, adev_rel_sd(edf_white_fm(np, (double)m[1]), 3));
  assert_rel_near(adev[1], N, 0.03);
  const double slope = log_slope(adev[0], 0.1, adev[2], 10.0);
  const double sd_slope =
      hypot(adev_rel_sd(edf_white_fm(np, (double)m[0]), 3), adev_rel_sd(edf_white_fm(np, (double)m[2]), 3)) /
      log(100.0);
  guard_3sigma("T2.1 slope", 0.05, sd_slope);
  assert_near(slope, -0.5, 0.05);
  print_message("[ T2.1     ] dt %g s, n %zu x 3 axes: sd %.6e (expected %.6e, %+.3f %%); Allan(1 s) %.6e "
                "(expected %.6e, %+.2f %%); slope 0.1-10 s %.4f (expected -0.5)\n",
                dt, n, sd, N / sqrt(dt), 100.0 * (sd / (N / sqrt(dt)) - 1.0), adev[1], N,
                100.0 * (adev[1] / N - 1.0), slope);
  series_free(&s);
}

/* T2.1: numerics.md asks 1e6 samples per rate; 2e6 at 1 kHz are needed for the Allan(1 s) check to
 * be >= 3 sd (edf = 1.5 n/m per axis), 2e5 suffice at 100 Hz. */
static void test_t2_1_white_noise_rate_independent(void **state) {
  (void)state;
  nav_test_print_seed("T2.1", k_seed);
  white_noise_at(0.001, 2000000);
  white_noise_at(0.01, 200000);
}

/* ================================================================ T2.2 Gauss-Markov */

/* sigma = 1, T = 10 s, dt = 0.1 s, stationary start. n = 5e6 per axis (numerics.md: 2e6 on one
 * axis) so that Allan(1000 s) +/- 5 % and r(3T) +/- 0.01 are >= 3 sd. The bias-state statistics
 * use the known mean 0 and are accumulated on the fly (ring buffer) to keep memory at the rate
 * series only. */
static void test_t2_2_gauss_markov(void **state) {
  (void)state;
  nav_test_print_seed("T2.2", k_seed);
  const double sigma = 1.0, T = 10.0, dt = 0.1;
  const size_t n = 5000000;
  enum { LAG1 = 100, LAG3 = 300 };
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_BIAS_GM;
  cfg.gyro.bias_gm_sd_rps = v3(sigma);
  cfg.gyro.bias_gm_tau_s = v3(T);
  series s;
  series_alloc(&s, n, dt);
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 2, &m), NAV_OK);
  static double ring[3][LAG3 + 1];
  double sum_b2[3] = {0}, sum_l1[3] = {0}, sum_l3[3] = {0};
  for (size_t k = 0; k < n; ++k) {
    const nav_imu_increment ideal = increment((int64_t)k + 1, dt);
    nav_imu_increment meas;
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    s.y[0][k] = meas.dtheta_b_rad.x / dt;
    s.y[1][k] = meas.dtheta_b_rad.y / dt;
    s.y[2][k] = meas.dtheta_b_rad.z / dt;
    const nav_vec3 b = nav_imu_model_bias(m)->gyro_gm_rps;
    const double bb[3] = {b.x, b.y, b.z};
    const size_t slot = k % (LAG3 + 1);
    for (int a = 0; a < 3; ++a) {
      sum_b2[a] += bb[a] * bb[a];
      if (k >= LAG1) sum_l1[a] += bb[a] * ring[a][(k - LAG1) % (LAG3 + 1)];
      if (k >= LAG3) sum_l3[a] += bb[a] * ring[a][(k - LAG3) % (LAG3 + 1)];
      ring[a][slot] = bb[a];
    }
  }
  nav_imu_model_destroy(m);
  double var = 0.0, r1 = 0.0, r3 = 0.0;
  for (int a = 0; a < 3; ++a) {
    var += sum_b2[a] / (double)n / 3.0;
    r1 += sum_l1[a] / sum_b2[a] / 3.0;
    r3 += sum_l3[a] / sum_b2[a] / 3.0;
  }
  const double phi = exp(-dt / T), nn = 3.0 * (double)n;
  const double f1 = (1.0 + phi * phi) / (1.0 - phi * phi);
  guard_3sigma("T2.2 variance", 0.03, sqrt(2.0 * f1 / nn));
  guard_3sigma("T2.2 r(T)", 0.01,
               sqrt(((1.0 + phi * phi) * (1.0 - pow(phi, 2.0 * LAG1)) / (1.0 - phi * phi) -
                     2.0 * LAG1 * pow(phi, 2.0 * LAG1)) /
                    nn));
  guard_3sigma("T2.2 r(3T)", 0.01,
               sqrt(((1.0 + phi * phi) * (1.0 - pow(phi, 2.0 * LAG3)) / (1.0 - phi * phi) -
                     2.0 * LAG3 * pow(phi, 2.0 * LAG3)) /
                    nn));
  assert_rel_near(var, sigma * sigma, 0.03);
  assert_near(r1, exp(-1.0), 0.01);
  assert_near(r3, exp(-3.0), 0.01);

  /* Allan deviation at 1, 10, 18.9, 100, 1000 s against E2.6 (+/- 5 %), and at tau = dt: the
   * exactly integrated increments follow E2.6 there too (0.0813), where a point-sampled bias gives
   * sqrt(1 - phi) = 0.0998 (numerics.md T2.2 note). */
  const size_t mm[6] = {1, 10, 100, 189, 1000, 10000};
  double adev[6];
  pooled_adev(&s, mm, 6, adev);
  for (int i = 0; i < 6; ++i) {
    const double tau = (double)mm[i] * dt, expected = gm_adev(sigma, T, tau);
    char what[64];
    snprintf(what, sizeof what, "T2.2 Allan(%g s)", tau);
    guard_3sigma(what, 0.05, adev_rel_sd(edf_white_fm((double)n + 1.0, (double)mm[i]), 3));
    assert_rel_near(adev[i], expected, 0.05);
    print_message("[ T2.2     ] Allan(%7.1f s) = %.4f, E2.6 %.4f (%+.2f %%)\n", tau, adev[i], expected,
                  100.0 * (adev[i] / expected - 1.0));
  }
  assert_true(fabs(adev[0] - sqrt(1.0 - phi)) > 0.1 * sqrt(1.0 - phi));
  print_message("[ T2.2     ] n %zu x 3: variance %.4f (1), r(T) %.4f (%.4f), r(3T) %.4f (%.4f)\n", n, var,
                r1, exp(-1.0), r3, exp(-3.0));
  series_free(&s);
}

/* ================================================================ T2.3 random walk */

/* K = 1e-3, dt = 0.01 s; n = 3e6 per axis (numerics.md: 1e6 on one axis) so that Allan(100 s)
 * +/- 10 % is >= 3 sd (random-walk FM edf ~ n/m). */
static void test_t2_3_random_walk(void **state) {
  (void)state;
  nav_test_print_seed("T2.3", k_seed);
  const double K = 1e-3, dt = 0.01;
  const size_t n = 3000000;
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_BIAS_RW;
  cfg.gyro.bias_rw_rps_per_sqrt_s = v3(K);
  series s;
  series_alloc(&s, n, dt);
  run_gyro_zero_input(&cfg, 3, &s);
  const size_t m[3] = {100, 1000, 10000};
  double adev[3];
  pooled_adev(&s, m, 3, adev);
  for (int i = 0; i < 3; ++i) {
    const double tau = (double)m[i] * dt, expected = K * sqrt(tau / 3.0);
    guard_3sigma("T2.3 Allan", 0.10, adev_rel_sd(edf_rw_fm((double)n + 1.0, (double)m[i]), 3));
    assert_rel_near(adev[i], expected, 0.10);
    print_message("[ T2.3     ] Allan(%5.0f s) = %.4e, K sqrt(tau/3) %.4e (%+.2f %%)\n", tau, adev[i],
                  expected, 100.0 * (adev[i] / expected - 1.0));
  }
  const double slope = log_slope(adev[0], 1.0, adev[2], 100.0);
  guard_3sigma("T2.3 slope", 0.1,
               hypot(adev_rel_sd(edf_rw_fm((double)n + 1.0, 100.0), 3),
                     adev_rel_sd(edf_rw_fm((double)n + 1.0, 10000.0), 3)) /
                   log(100.0));
  assert_near(slope, 0.5, 0.1);
  print_message("[ T2.3     ] slope 1-100 s %.4f (expected +0.5)\n", slope);
  series_free(&s);
}

/* ================================================================ T2.4 flat region */

/*
 * White noise plus GM with N = 0.01 sigma sqrt(T): the curve is flat (slope ~ 0) around
 * tau = 1.89 T at the GM's 0.617 sigma. numerics.md calls this level the curve's "minimum": the
 * bias-instability floor a real sensor shows, which the single-GM model reproduces as the top of
 * its hump. Checked: the largest Allan value for tau in [1, 1000] s lies within [T, 3.6 T] and
 * within 10 % of 0.617 sigma; the log-log slope across [T, 3.6 T] (symmetric about 1.89 T) is
 * within 0.05 of 0 (E2.6 gives -0.0043 there); at tau = dt the white and GM variances add.
 */
static void test_t2_4_flat_region(void **state) {
  (void)state;
  nav_test_print_seed("T2.4", k_seed);
  const double sigma = 1.0, T = 10.0, dt = 0.1, N = 0.01 * sigma * sqrt(T);
  const size_t n = 1000000;
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_NOISE;
  cfg.gyro.bias_gm_sd_rps = v3(sigma);
  cfg.gyro.bias_gm_tau_s = v3(T);
  cfg.gyro.arw_rad_per_sqrt_s = v3(N);
  assert_true(N / sqrt(1.89 * T) < 0.02 * NAV_GM_ALLAN_PEAK_SIGMA_RATIO * sigma);
  series s;
  series_alloc(&s, n, dt);
  run_gyro_zero_input(&cfg, 4, &s);
  size_t m[64], count = 0;
  assert_int_equal(nav_allan_log_clusters(10000, 10, m, 64, &count), NAV_OK);
  double adev[64];
  pooled_adev(&s, m, count, adev);
  size_t best = 0;
  for (size_t i = 0; i < count; ++i)
    if ((double)m[i] * dt >= 1.0 && adev[i] > adev[best]) best = i;
  const double tau_best = (double)m[best] * dt;
  const double np = (double)n + 1.0;
  guard_3sigma("T2.4 peak value", 0.10, adev_rel_sd(edf_white_fm(np, (double)m[best]), 3));
  assert_true(tau_best >= T && tau_best <= 3.6 * T);
  assert_rel_near(adev[best], NAV_GM_ALLAN_PEAK_SIGMA_RATIO * sigma, 0.10);
  const size_t mf[3] = {1, 100, 360};
  double af[3];
  pooled_adev(&s, mf, 3, af);
  const double slope = log_slope(af[1], T, af[2], 3.6 * T);
  guard_3sigma("T2.4 slope", 0.05 - 0.0043,
               hypot(adev_rel_sd(edf_white_fm(np, 100.0), 3), adev_rel_sd(edf_white_fm(np, 360.0), 3)) /
                   log(3.6));
  assert_near(slope, 0.0, 0.05);
  const double at_dt = hypot(N / sqrt(dt), gm_adev(sigma, T, dt));
  assert_rel_near(af[0], at_dt, 0.02);
  print_message("[ T2.4     ] max Allan %.4f at tau %.1f s (expected %.4f at %.1f s); slope T-3.6T %.4f "
                "(E2.6 -0.0043); "
                "Allan(dt) %.4f (expected %.4f)\n",
                adev[best], tau_best, NAV_GM_ALLAN_PEAK_SIGMA_RATIO * sigma, NAV_GM_ALLAN_PEAK_TAU_RATIO * T,
                slope, af[0], at_dt);
  series_free(&s);
}

/* ================================================================ T2.5 quantisation */

/* Busy signal: true increments uniform on [0, 50 S] per axis. The Allan deviation of the
 * quantisation error (measured - true, as a rate) is S / (2 tau) +/- 2 %, slope -1 +/- 0.05; the
 * output is a whole number of quanta and the accumulated output never drifts from the accumulated
 * input by more than S/2 (residual carried, E2.8). White-PM edf ~ n/2. */
static void test_t2_5_quantisation(void **state) {
  (void)state;
  nav_test_print_seed("T2.5", k_seed);
  const double S = 1e-3, dt = 0.01;
  const size_t n = 50000;
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_QUANTISATION;
  cfg.gyro.quant_step_rad = v3(S);
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 5, &m), NAV_OK);
  nav_rng signal;
  nav_rng_init(&signal, k_seed, 5, NAV_RNG_STREAM_USER);
  series s;
  series_alloc(&s, n, dt);
  double sum_in[3] = {0}, sum_out[3] = {0}, max_drift = 0.0, max_frac = 0.0;
  for (size_t k = 0; k < n; ++k) {
    nav_imu_increment ideal = increment((int64_t)k + 1, dt);
    ideal.dtheta_b_rad =
        nav_vec3_make(50.0 * S * nav_rng_uniform(&signal), 50.0 * S * nav_rng_uniform(&signal),
                      50.0 * S * nav_rng_uniform(&signal));
    nav_imu_increment meas;
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    const double in[3] = {ideal.dtheta_b_rad.x, ideal.dtheta_b_rad.y, ideal.dtheta_b_rad.z};
    const double out[3] = {meas.dtheta_b_rad.x, meas.dtheta_b_rad.y, meas.dtheta_b_rad.z};
    for (int a = 0; a < 3; ++a) {
      s.y[a][k] = (out[a] - in[a]) / dt;
      sum_in[a] += in[a];
      sum_out[a] += out[a];
      max_drift = fmax(max_drift, fabs(sum_out[a] - sum_in[a]));
      max_frac = fmax(max_frac, fabs(out[a] / S - round(out[a] / S)));
    }
  }
  nav_imu_model_destroy(m);
  /* |sum out - sum in| = |residual| <= S/2, up to the rounding of the two running sums (~ n ulp of
   * their size 25 rad: 5e4 * 3.6e-15 = 2e-10). */
  assert_true(max_drift <= 0.5 * S + 1e-9);
  assert_true(max_frac < 1e-9);
  const size_t mm[3] = {1, 10, 100};
  double adev[3];
  pooled_adev(&s, mm, 3, adev);
  for (int i = 0; i < 3; ++i) {
    const double tau = (double)mm[i] * dt, expected = S / (2.0 * tau);
    guard_3sigma("T2.5 Allan", 0.02, adev_rel_sd(edf_white_pm((double)n + 1.0, (double)mm[i]), 3));
    assert_rel_near(adev[i], expected, 0.02);
    print_message("[ T2.5     ] Allan(%4.2f s) = %.5e, S/(2 tau) %.5e (%+.2f %%)\n", tau, adev[i], expected,
                  100.0 * (adev[i] / expected - 1.0));
  }
  const double slope = log_slope(adev[0], 0.01, adev[2], 1.0);
  assert_near(slope, -1.0, 0.05);
  print_message("[ T2.5     ] slope %.4f (expected -1); max |sum out - sum in| %.3g rad (<= S/2 = %.3g)\n",
                slope, max_drift, 0.5 * S);
  series_free(&s);
}

/* ================================================================ T2.6 determinism, streams */

static nav_imu_model_config everything_on(void) {
  nav_imu_model_config c = nav_imu_model_config_default();
  nav_gyro_error_config *g = &c.gyro;
  nav_accel_error_config *a = &c.accel;
  g->terms = NAV_IMU_TERMS_GYRO_ALL;
  a->terms = NAV_IMU_TERMS_ACCEL_ALL;
  g->bias_turn_on_fixed_rps = nav_vec3_make(1e-4, -2e-4, 3e-4);
  g->bias_turn_on_sd_rps = v3(1e-4);
  g->bias_gm_sd_rps = v3(2e-5);
  g->bias_gm_tau_s = nav_vec3_make(100.0, 200.0, 300.0);
  g->bias_rw_rps_per_sqrt_s = v3(1e-6);
  g->arw_rad_per_sqrt_s = v3(4.36332e-5);
  g->scale_factor_sd = v3(500e-6);
  g->misalignment_sd_rad = nav_mat3_scale(offdiag_ones(), 1e-3);
  g->g_sensitivity_sd_rps_per_mps2 = nav_mat3_scale(nav_mat3_identity(), 1e-6);
  g->quant_step_rad = v3(1e-7);
  g->range_rps = v3(8.0);
  a->bias_turn_on_sd_mps2 = v3(7.5e-3);
  a->bias_gm_sd_mps2 = v3(5e-4);
  a->bias_gm_tau_s = v3(300.0);
  a->bias_rw_mps2_per_sqrt_s = v3(1e-5);
  a->vrw_mps_per_sqrt_s = v3(1e-3);
  a->scale_factor_sd = v3(300e-6);
  a->misalignment_sd_rad = nav_mat3_scale(offdiag_ones(), 1e-3);
  a->quant_step_mps = v3(1e-6);
  a->range_mps2 = v3(100.0);
  return c;
}

static nav_imu_increment moving(int64_t k, double dt) {
  nav_imu_increment inc = increment(k, dt);
  const double t = (double)k * dt;
  inc.dtheta_b_rad = nav_vec3_make(0.3 * sin(t) * dt, -0.2 * dt, 0.1 * cos(2.0 * t) * dt);
  inc.dv_b_mps = nav_vec3_make(0.5 * dt, 0.1 * sin(t) * dt, -9.8 * dt);
  return inc;
}

static void test_t2_6_determinism_and_streams(void **state) {
  (void)state;
  nav_test_print_seed("T2.6", k_seed);
  const double dt = 0.005;
  enum { N = 20000 };
  const nav_imu_model_config all = everything_on();
  assert_int_equal(nav_imu_model_config_validate(&all, NULL, NULL), NAV_OK);

  /* Same (seed, run): bit-identical output and bias states; another run differs. */
  nav_imu_model *a = NULL, *b = NULL, *c = NULL;
  assert_int_equal(nav_imu_model_create(&all, k_seed, 9, &a), NAV_OK);
  assert_int_equal(nav_imu_model_create(&all, k_seed, 9, &b), NAV_OK);
  assert_int_equal(nav_imu_model_create(&all, k_seed, 10, &c), NAV_OK);
  bool differs = false;
  for (int64_t k = 1; k <= N; ++k) {
    const nav_imu_increment ideal = moving(k, dt);
    nav_imu_increment ma, mb, mc;
    assert_int_equal(nav_imu_model_apply(a, &ideal, &ma), NAV_OK);
    assert_int_equal(nav_imu_model_apply(b, &ideal, &mb), NAV_OK);
    assert_int_equal(nav_imu_model_apply(c, &ideal, &mc), NAV_OK);
    assert_true(vec3_bit_equal(ma.dtheta_b_rad, mb.dtheta_b_rad) && vec3_bit_equal(ma.dv_b_mps, mb.dv_b_mps));
    if (!vec3_bit_equal(ma.dtheta_b_rad, mc.dtheta_b_rad)) differs = true;
  }
  assert_memory_equal(nav_imu_model_bias(a), nav_imu_model_bias(b), sizeof(nav_imu_bias_state));
  assert_true(differs);
  nav_imu_model_destroy(a);
  nav_imu_model_destroy(b);
  nav_imu_model_destroy(c);

  /* Switching the GM term on (with sigma 0, so it adds exactly 0 while still drawing from its own
   * stream) leaves the white-noise output bit for bit unchanged; with sigma > 0 the output minus
   * the reported bias integral reproduces it to rounding. */
  nav_imu_model_config noise = nav_imu_model_config_default();
  noise.gyro.terms = NAV_IMU_TERM_NOISE;
  noise.gyro.arw_rad_per_sqrt_s = v3(4.36332e-5);
  noise.accel.terms = NAV_IMU_TERM_NOISE;
  noise.accel.vrw_mps_per_sqrt_s = v3(1e-3);
  nav_imu_model_config gm0 = noise, gm1 = noise;
  gm0.gyro.terms |= NAV_IMU_TERM_BIAS_GM;
  gm0.gyro.bias_gm_tau_s = v3(100.0); /* sd 0 */
  gm0.accel.terms |= NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_RW;
  gm0.accel.bias_gm_tau_s = v3(100.0);
  gm1.gyro.terms |= NAV_IMU_TERM_BIAS_GM;
  gm1.gyro.bias_gm_sd_rps = v3(1e-3);
  gm1.gyro.bias_gm_tau_s = v3(100.0);
  nav_imu_model *pn = NULL, *p0 = NULL, *p1 = NULL;
  assert_int_equal(nav_imu_model_create(&noise, k_seed, 11, &pn), NAV_OK);
  assert_int_equal(nav_imu_model_create(&gm0, k_seed, 11, &p0), NAV_OK);
  assert_int_equal(nav_imu_model_create(&gm1, k_seed, 11, &p1), NAV_OK);
  double worst = 0.0;
  for (int64_t k = 1; k <= N; ++k) {
    const nav_imu_increment ideal = increment(k, dt);
    nav_imu_increment mn, m0, m1;
    assert_int_equal(nav_imu_model_apply(pn, &ideal, &mn), NAV_OK);
    assert_int_equal(nav_imu_model_apply(p0, &ideal, &m0), NAV_OK);
    assert_int_equal(nav_imu_model_apply(p1, &ideal, &m1), NAV_OK);
    assert_true(vec3_bit_equal(mn.dtheta_b_rad, m0.dtheta_b_rad));
    assert_true(vec3_bit_equal(mn.dv_b_mps, m0.dv_b_mps));
    const nav_vec3 bias_int = nav_vec3_scale(nav_imu_model_bias(p1)->gyro_mean_rps, dt);
    const nav_vec3 w = nav_vec3_sub(m1.dtheta_b_rad, bias_int);
    worst = fmax(worst, nav_vec3_norm(nav_vec3_sub(w, mn.dtheta_b_rad)));
    assert_true(vec3_bit_equal(m1.dv_b_mps, mn.dv_b_mps));
  }
  /* |bias integral| ~ 1e-3 * 5e-3 = 5e-6 rad: rounding of a + b - b is a few ulp of 5e-6 (1e-21). */
  assert_true(worst < 1e-19);
  nav_imu_model_destroy(pn);
  nav_imu_model_destroy(p0);
  nav_imu_model_destroy(p1);

  /* Per-axis independence: a different x-axis ARW leaves y and z bit-identical; switching the noise
   * off leaves the GM bias states bit-identical. */
  nav_imu_model_config x2 = gm1;
  x2.gyro.arw_rad_per_sqrt_s.x *= 2.0;
  nav_imu_model_config quiet = gm1;
  quiet.gyro.terms &= ~(unsigned)NAV_IMU_TERM_NOISE;
  assert_int_equal(nav_imu_model_create(&gm1, k_seed, 12, &pn), NAV_OK);
  assert_int_equal(nav_imu_model_create(&x2, k_seed, 12, &p0), NAV_OK);
  assert_int_equal(nav_imu_model_create(&quiet, k_seed, 12, &p1), NAV_OK);
  for (int64_t k = 1; k <= 1000; ++k) {
    const nav_imu_increment ideal = moving(k, dt);
    nav_imu_increment mn, m0, m1;
    assert_int_equal(nav_imu_model_apply(pn, &ideal, &mn), NAV_OK);
    assert_int_equal(nav_imu_model_apply(p0, &ideal, &m0), NAV_OK);
    assert_int_equal(nav_imu_model_apply(p1, &ideal, &m1), NAV_OK);
    assert_true(bits_of(mn.dtheta_b_rad.y) == bits_of(m0.dtheta_b_rad.y));
    assert_true(bits_of(mn.dtheta_b_rad.z) == bits_of(m0.dtheta_b_rad.z));
    assert_true(bits_of(mn.dtheta_b_rad.x) != bits_of(m0.dtheta_b_rad.x));
    assert_true(vec3_bit_equal(nav_imu_model_bias(pn)->gyro_gm_rps, nav_imu_model_bias(p1)->gyro_gm_rps));
  }
  nav_imu_model_destroy(pn);
  nav_imu_model_destroy(p0);
  nav_imu_model_destroy(p1);

  /* Per-run constants do not depend on which other terms are on. */
  nav_imu_model_config only_sf = nav_imu_model_config_default();
  only_sf.gyro.terms = NAV_IMU_TERM_SCALE_FACTOR | NAV_IMU_TERM_MISALIGNMENT;
  only_sf.gyro.scale_factor_sd = all.gyro.scale_factor_sd;
  only_sf.gyro.misalignment_sd_rad = all.gyro.misalignment_sd_rad;
  assert_int_equal(nav_imu_model_create(&all, k_seed, 13, &pn), NAV_OK);
  assert_int_equal(nav_imu_model_create(&only_sf, k_seed, 13, &p0), NAV_OK);
  assert_memory_equal(&nav_imu_model_constants(pn)->M_g, &nav_imu_model_constants(p0)->M_g, sizeof(nav_mat3));
  nav_imu_model_destroy(pn);
  nav_imu_model_destroy(p0);
}

/* ================================================================ T2.7 scale factor / misalignment */

/* (I + M) x with the matrix written out (the reference; the model computes x + M x). */
static nav_vec3 i_plus_m(const nav_mat3 *m, nav_vec3 x) {
  const nav_mat3 a = nav_mat3_add(nav_mat3_identity(), *m);
  return nav_mat3_mul_vec(a, x);
}

static void assert_vec_rel(nav_vec3 got, nav_vec3 want, double rel) {
  const double scale = nav_vec3_norm(want);
  if (!(nav_vec3_norm(nav_vec3_sub(got, want)) <= rel * scale))
    fail_msg("(%.17g, %.17g, %.17g) vs (%.17g, %.17g, %.17g): relative difference %.3g > %.3g", got.x, got.y,
             got.z, want.x, want.y, want.z, nav_vec3_norm(nav_vec3_sub(got, want)) / scale, rel);
}

static void test_t2_7_scale_factor_misalignment(void **state) {
  (void)state;
  const double dt = 0.01;
  const nav_vec3 w = nav_vec3_make(0.1, -0.2, 0.3), f = nav_vec3_make(0.4, 0.5, -9.8);
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_SCALE_FACTOR | NAV_IMU_TERM_MISALIGNMENT;
  cfg.gyro.scale_factor_fixed = nav_vec3_make(300e-6, -150e-6, 1e-3);
  const nav_mat3 mis = {{{0.0, 1e-3, -2e-3}, {0.5e-3, 0.0, 3e-4}, {-1e-3, 2e-3, 0.0}}};
  cfg.gyro.misalignment_fixed_rad = mis;
  cfg.accel.terms = NAV_IMU_TERM_SCALE_FACTOR | NAV_IMU_TERM_MISALIGNMENT;
  cfg.accel.scale_factor_sd = v3(500e-6); /* drawn per run: checked against the getter */
  cfg.accel.misalignment_sd_rad = nav_mat3_scale(offdiag_ones(), 1e-3);
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 21, &m), NAV_OK);
  nav_mat3 mg = mis;
  mg.m[0][0] = 300e-6;
  mg.m[1][1] = -150e-6;
  mg.m[2][2] = 1e-3;
  assert_memory_equal(&nav_imu_model_constants(m)->M_g, &mg, sizeof mg);
  const nav_mat3 ma = nav_imu_model_constants(m)->M_a;
  assert_true(ma.m[0][0] != 0.0 && ma.m[0][1] != 0.0);
  for (int64_t k = 1; k <= 100; ++k) {
    nav_imu_increment ideal = increment(k, dt), meas;
    ideal.dtheta_b_rad = nav_vec3_scale(w, dt);
    ideal.dv_b_mps = nav_vec3_scale(f, dt);
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    assert_vec_rel(meas.dtheta_b_rad, i_plus_m(&mg, ideal.dtheta_b_rad), 1e-15);
    assert_vec_rel(meas.dv_b_mps, i_plus_m(&ma, ideal.dv_b_mps), 1e-15);
  }
  nav_imu_model_destroy(m);

  /* G-sensitivity: dtheta += G_g dv (true dv). */
  nav_imu_model_config gs = nav_imu_model_config_default();
  gs.gyro.terms = NAV_IMU_TERM_G_SENSITIVITY;
  const nav_mat3 G = {{{1e-5, 2e-6, 0.0}, {0.0, -1e-5, 3e-6}, {4e-6, 0.0, 2e-5}}};
  gs.gyro.g_sensitivity_fixed_rps_per_mps2 = G;
  assert_int_equal(nav_imu_model_create(&gs, k_seed, 22, &m), NAV_OK);
  nav_imu_increment ideal = increment(1, dt), meas;
  ideal.dtheta_b_rad = nav_vec3_scale(w, dt);
  ideal.dv_b_mps = nav_vec3_scale(f, dt);
  assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
  assert_vec_rel(meas.dtheta_b_rad, nav_vec3_add(ideal.dtheta_b_rad, nav_mat3_mul_vec(G, ideal.dv_b_mps)),
                 1e-15);
  assert_true(vec3_bit_equal(meas.dv_b_mps, ideal.dv_b_mps));
  nav_imu_model_destroy(m);
}

/* ================================================================ biases, saturation, API */

/* Turn-on + GM + RW, noise off: output / dt is the reported interval-mean bias, the total is the
 * sum of the parts, and a long run's turn-on draw has the configured population sigma. */
static void test_bias_reporting(void **state) {
  (void)state;
  const double dt = 0.01;
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.accel.terms = NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_RW;
  cfg.accel.bias_turn_on_fixed_mps2 = nav_vec3_make(0.01, 0.0, -0.01);
  cfg.accel.bias_turn_on_sd_mps2 = v3(1e-3);
  cfg.accel.bias_gm_sd_mps2 = v3(1e-4);
  cfg.accel.bias_gm_tau_s = v3(50.0);
  cfg.accel.bias_rw_mps2_per_sqrt_s = v3(1e-5);
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 31, &m), NAV_OK);
  const nav_imu_bias_state *b = nav_imu_model_bias(m);
  assert_int_equal(b->k, -1);
  assert_true(b->accel_gm_mps2.x != 0.0); /* stationary start */
  for (int64_t k = 1; k <= 500; ++k) {
    const nav_imu_increment ideal = increment(k, dt);
    nav_imu_increment meas;
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    assert_vec3_near(nav_vec3_scale(meas.dv_b_mps, 1.0 / dt), b->accel_mean_mps2, 1e-17);
    const nav_vec3 sum =
        nav_vec3_add(nav_vec3_add(nav_imu_model_constants(m)->accel_bias_turn_on_mps2, b->accel_gm_mps2),
                     b->accel_rw_mps2);
    assert_true(vec3_bit_equal(sum, b->accel_mps2));
    assert_int_equal(b->k, k);
  }
  nav_imu_model_destroy(m);

  /* Population of turn-on draws over runs: mean fixed, sd configured (1000 runs x 3 axes; sd of
   * the sample sd 1/sqrt(6000) = 1.3 %, tolerance 5 % = 3.9 sd; mean tolerance 4 sd of the mean). */
  enum { RUNS = 1000 };
  double s1 = 0.0, s2 = 0.0;
  for (uint64_t r = 0; r < RUNS; ++r) {
    assert_int_equal(nav_imu_model_create(&cfg, k_seed, r, &m), NAV_OK);
    const nav_vec3 b0 = nav_imu_model_constants(m)->accel_bias_turn_on_mps2;
    const double d[3] = {b0.x - 0.01, b0.y, b0.z + 0.01};
    for (int a = 0; a < 3; ++a) {
      s1 += d[a];
      s2 += d[a] * d[a];
    }
    nav_imu_model_destroy(m);
  }
  assert_near(s1 / (3.0 * RUNS), 0.0, 4.0 * 1e-3 / sqrt(3.0 * RUNS));
  assert_rel_near(sqrt(s2 / (3.0 * RUNS)), 1e-3, 0.05);
}

/* nav_imu_model_defer_bias (what a simulation run sets): the same measured increments bit for bit,
 * and nav_imu_model_bias() after a sample gives the bias state of a model that forms it at every
 * sample, bit for bit, whether it is asked after every sample or only now and then; both
 * triads with every bias term, turn-on, GM and random walk, and noise. */
/* Both triads with every bias term (turn-on, GM, random walk) and noise. */
static nav_imu_model_config bias_noise_config(void) {
  nav_imu_model_config cfg = nav_imu_model_config_default();
  const unsigned terms =
      NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_RW | NAV_IMU_TERM_NOISE;
  cfg.gyro.terms = cfg.accel.terms = terms;
  cfg.gyro.bias_turn_on_sd_rps = v3(1e-4);
  cfg.gyro.bias_gm_sd_rps = v3(1e-5);
  cfg.gyro.bias_gm_tau_s = v3(100.0);
  cfg.gyro.bias_rw_rps_per_sqrt_s = v3(1e-6);
  cfg.gyro.arw_rad_per_sqrt_s = v3(1e-4);
  cfg.accel.bias_turn_on_sd_mps2 = v3(1e-3);
  cfg.accel.bias_gm_sd_mps2 = v3(1e-4);
  cfg.accel.bias_gm_tau_s = v3(50.0);
  cfg.accel.bias_rw_mps2_per_sqrt_s = v3(1e-5);
  cfg.accel.vrw_mps_per_sqrt_s = v3(1e-3);
  return cfg;
}

static void test_deferred_bias_state(void **state) {
  (void)state;
  const double dt = 0.01;
  const nav_imu_model_config cfg = bias_noise_config();
  nav_imu_model *eager = NULL, *lazy = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 7, &eager), NAV_OK);
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 7, &lazy), NAV_OK);
  nav_imu_model_defer_bias(lazy);
  assert_memory_equal(nav_imu_model_bias(eager), nav_imu_model_bias(lazy), sizeof(nav_imu_bias_state));
  int asked = 0;
  for (int64_t k = 1; k <= 2000; ++k) {
    const nav_imu_increment ideal = increment(k, dt);
    nav_imu_increment me, ml;
    assert_int_equal(nav_imu_model_apply(eager, &ideal, &me), NAV_OK);
    assert_int_equal(nav_imu_model_apply(lazy, &ideal, &ml), NAV_OK);
    assert_memory_equal(&me, &ml, sizeof me);
    /* Every sample at first, then every 97th. */
    if (k <= 50 || k % 97 == 0) {
      assert_memory_equal(nav_imu_model_bias(eager), nav_imu_model_bias(lazy), sizeof(nav_imu_bias_state));
      ++asked;
    }
  }
  assert_int_equal(asked, 50 + 20);
  /* The values are not all zero (else the comparison would prove nothing). */
  assert_true(nav_imu_model_bias(lazy)->gyro_mean_rps.x != 0.0 &&
              nav_imu_model_bias(lazy)->accel_rw_mps2.z != 0.0);
  nav_imu_model_destroy(eager);
  nav_imu_model_destroy(lazy);
}

/* A model with every term of both triads on (g-sensitivity included), for the lanes test: the
 * bias and noise terms of bias_noise_config() and the rest. */
static nav_imu_model_config every_term_config(void) {
  nav_imu_model_config cfg = bias_noise_config();
  const unsigned more = NAV_IMU_TERM_SCALE_FACTOR | NAV_IMU_TERM_MISALIGNMENT | NAV_IMU_TERM_QUANTISATION |
                        NAV_IMU_TERM_SATURATION;
  cfg.gyro.terms |= more | NAV_IMU_TERM_G_SENSITIVITY;
  cfg.accel.terms |= more;
  cfg.gyro.scale_factor_sd = v3(1e-3);
  cfg.accel.scale_factor_sd = v3(1e-3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      if (i != j) cfg.gyro.misalignment_sd_rad.m[i][j] = cfg.accel.misalignment_sd_rad.m[i][j] = 1e-3;
      cfg.gyro.g_sensitivity_sd_rps_per_mps2.m[i][j] = 1e-5;
    }
  cfg.gyro.quant_step_rad = v3(1e-7);
  cfg.accel.quant_step_mps = v3(1e-5);
  cfg.gyro.range_rps = v3(nav_unit_deg_per_s_to_rps(300.0));
  cfg.accel.range_mps2 = v3(nav_unit_g_to_mps2(8.0));
  return cfg;
}

/* Sample k of a made-up motion: a few rad/s and m/s^2 that change with k, above the sensors'
 * ranges at every 41st sample (saturation), with the interval alternating between two values in
 * runs of 100 samples (the interval cache). */
static nav_imu_increment lanes_sample(int64_t k) {
  const double dt = (k / 100) % 2 ? 0.005 : 0.01;
  nav_imu_increment in = increment(k, dt);
  const double big = k % 41 == 0 ? 30.0 : 1.0;
  in.dtheta_b_rad = nav_vec3_make(big * 0.3 * sin(0.01 * (double)k) * dt, -big * 0.2 * dt, 0.1 * dt);
  in.dv_b_mps = nav_vec3_make(big * 2.0 * cos(0.02 * (double)k) * dt, 0.5 * dt, -9.81 * big * dt);
  return in;
}

/* Four models stepped in lanes (nav_imu_lanes_*) give, sample by sample, the bits of the same four
 * models stepped alone: the measured increments, and after a close the whole bias state and
 * every stream (the models go on alone and still agree); a refused sample changes nothing; the
 * lanes refuse models of different configurations and models that form the bias at every
 * sample. */
static void test_imu_lanes_match_alone(void **state) {
  (void)state;
  const nav_imu_model_config cfg = every_term_config();
  nav_imu_model *lane[4], *alone[4];
  for (int l = 0; l < 4; ++l) {
    assert_int_equal(nav_imu_model_create(&cfg, k_seed, 3 + (uint64_t)l, &lane[l]), NAV_OK);
    assert_int_equal(nav_imu_model_create(&cfg, k_seed, 3 + (uint64_t)l, &alone[l]), NAV_OK);
    nav_imu_model_defer_bias(alone[l]);
  }
  /* Not deferring: refused, models untouched. */
  assert_null(nav_imu_lanes_open(lane));
  for (int l = 0; l < 4; ++l)
    nav_imu_model_defer_bias(lane[l]);
  nav_imu_lanes *g = nav_imu_lanes_open(lane);
  assert_non_null(g);
  nav_imu_increment ml[4], ma;
  nav_imu_increment *mp[4] = {&ml[0], &ml[1], &ml[2], &ml[3]};
  int64_t k = 1;
  for (int part = 0; part < 3; ++part) {
    for (int i = 0; i < 1500; ++i, ++k) {
      const nav_imu_increment in = lanes_sample(k);
      assert_true(nav_imu_lanes_apply(g, &in, mp));
      for (int l = 0; l < 4; ++l) {
        assert_int_equal(nav_imu_model_apply(alone[l], &in, &ma), NAV_OK);
        assert_memory_equal(&ml[l], &ma, sizeof ma);
      }
    }
    /* A sample nav_imu_model_apply refuses: refused by the lanes too, with nothing changed. */
    nav_imu_increment bad = lanes_sample(k);
    bad.dt_s = 0.0;
    assert_false(nav_imu_lanes_apply(g, &bad, mp));
    bad = lanes_sample(k);
    bad.dv_b_mps.y = NAN;
    assert_false(nav_imu_lanes_apply(g, &bad, mp));
    nav_imu_lanes_close(g);
    for (int l = 0; l < 4; ++l)
      assert_memory_equal(nav_imu_model_bias(lane[l]), nav_imu_model_bias(alone[l]),
                          sizeof(nav_imu_bias_state));
    /* Alone for a while (the streams and states written back), then in lanes again. */
    for (int i = 0; i < 300; ++i, ++k) {
      const nav_imu_increment in = lanes_sample(k);
      for (int l = 0; l < 4; ++l) {
        assert_int_equal(nav_imu_model_apply(lane[l], &in, &ml[l]), NAV_OK);
        assert_int_equal(nav_imu_model_apply(alone[l], &in, &ma), NAV_OK);
        assert_memory_equal(&ml[l], &ma, sizeof ma);
      }
    }
    g = nav_imu_lanes_open(lane);
    assert_non_null(g);
  }
  nav_imu_lanes_close(g);
  /* The comparison covered what it should: saturated samples, four different runs. */
  for (int l = 0; l < 4; ++l) {
    const nav_imu_bias_state *b = nav_imu_model_bias(lane[l]);
    assert_true(b->saturated_samples > 50);
    assert_memory_equal(b, nav_imu_model_bias(alone[l]), sizeof *b);
  }
  assert_true(nav_imu_model_bias(lane[0])->gyro_gm_rps.x != nav_imu_model_bias(lane[1])->gyro_gm_rps.x);
  /* Another configuration in one lane: refused. */
  nav_imu_model_config other = cfg;
  other.accel.bias_gm_tau_s.y = 51.0;
  nav_imu_model *odd = NULL;
  assert_int_equal(nav_imu_model_create(&other, k_seed, 9, &odd), NAV_OK);
  nav_imu_model_defer_bias(odd);
  nav_imu_model *mixed[4] = {lane[0], lane[1], odd, lane[3]};
  assert_null(nav_imu_lanes_open(mixed));
  nav_imu_lanes_close(NULL);
  nav_imu_model_destroy(odd);
  for (int l = 0; l < 4; ++l) {
    nav_imu_model_destroy(lane[l]);
    nav_imu_model_destroy(alone[l]);
  }
}

static void test_saturation(void **state) {
  (void)state;
  const double dt = 0.01;
  nav_imu_model_config cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_SATURATION | NAV_IMU_TERM_QUANTISATION;
  cfg.gyro.range_rps = v3(nav_unit_deg_per_s_to_rps(100.0));
  cfg.gyro.quant_step_rad = v3(1e-6);
  cfg.accel.terms = NAV_IMU_TERM_SATURATION;
  cfg.accel.range_mps2 = v3(nav_unit_g_to_mps2(8.0));
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 41, &m), NAV_OK);
  const double lim = nav_unit_deg_per_s_to_rps(100.0) * dt;
  nav_imu_increment ideal = increment(1, dt), meas;
  ideal.dtheta_b_rad = nav_vec3_make(2.0 * dt, -3.0 * dt, 0.5 * dt); /* 115, -172, 29 deg/s */
  ideal.dv_b_mps = nav_vec3_make(0.0, 0.0, -100.0 * dt);             /* -10.2 g on z */
  assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
  const nav_imu_bias_state *b = nav_imu_model_bias(m);
  assert_int_equal(b->saturated, NAV_IMU_SAT_GYRO_X | NAV_IMU_SAT_GYRO_Y | NAV_IMU_SAT_ACCEL_Z);
  /* Clipped to range * dt, then quantised (|error| <= step/2 with the residual carried). */
  assert_near(meas.dtheta_b_rad.x, lim, 0.5e-6);
  assert_near(meas.dtheta_b_rad.y, -lim, 0.5e-6);
  assert_near(meas.dtheta_b_rad.z, 0.5 * dt, 0.5e-6);
  assert_near(meas.dv_b_mps.z, -nav_unit_g_to_mps2(8.0) * dt, 0.0);
  assert_true(meas.dv_b_mps.x == 0.0);
  ideal = increment(2, dt);
  assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
  assert_int_equal(b->saturated, 0);
  assert_int_equal(b->saturated_samples, 1);
  nav_imu_model_destroy(m);
}

/* The default (ideal) configuration returns the ideal record bit for bit, and in place. */
static void test_ideal_model_is_identity(void **state) {
  (void)state;
  const nav_imu_model_config cfg = nav_imu_model_config_default();
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 0, &m), NAV_OK);
  for (int64_t k = 1; k <= 100; ++k) {
    const nav_imu_increment ideal = moving(k, 0.01);
    nav_imu_increment meas, inplace = ideal;
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    assert_memory_equal(&meas, &ideal, sizeof meas);
    assert_int_equal(nav_imu_model_apply(m, &inplace, &inplace), NAV_OK);
    assert_memory_equal(&inplace, &ideal, sizeof meas);
    assert_int_equal(nav_imu_model_bias(m)->k, k);
  }
  nav_imu_model_destroy(m);
}

static void count_issue(void *user, const char *path, const char *message) {
  (void)path;
  (void)message;
  ++*(int *)user;
}

static void test_config_validation_and_errors(void **state) {
  (void)state;
  nav_imu_model_config cfg = nav_imu_model_config_default();
  assert_int_equal(nav_imu_model_config_validate(&cfg, NULL, NULL), NAV_OK);
  /* Fields of disabled terms are ignored... */
  cfg.gyro.bias_gm_tau_s = v3(-1.0);
  assert_int_equal(nav_imu_model_config_validate(&cfg, NULL, NULL), NAV_OK);
  /* ...and checked once enabled: 3 bad tau, 1 negative sd, 1 misalignment diagonal, 1 bad bit. */
  cfg.gyro.terms = NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_MISALIGNMENT;
  cfg.gyro.bias_gm_sd_rps = nav_vec3_make(1e-5, -1e-5, 0.0);
  cfg.gyro.misalignment_sd_rad.m[1][1] = 1e-3;
  cfg.accel.terms = NAV_IMU_TERM_G_SENSITIVITY;
  int issues = 0;
  assert_int_equal(nav_imu_model_config_validate(&cfg, count_issue, &issues), NAV_ERR_INVALID_ARG);
  assert_int_equal(issues, 6);
  nav_imu_model *m = NULL;
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 0, &m), NAV_ERR_INVALID_ARG);
  assert_null(m);

  /* Apply rejects dt <= 0 and non-finite input, leaving the state unchanged. */
  cfg = nav_imu_model_config_default();
  cfg.gyro.terms = NAV_IMU_TERM_NOISE;
  cfg.gyro.arw_rad_per_sqrt_s = v3(1e-4);
  assert_int_equal(nav_imu_model_create(&cfg, k_seed, 0, &m), NAV_OK);
  nav_imu_increment bad = increment(1, 0.0), meas;
  assert_int_equal(nav_imu_model_apply(m, &bad, &meas), NAV_ERR_INVALID_ARG);
  assert_true(strstr(nav_imu_model_last_error(m), "dt_s") != NULL);
  bad = increment(1, 0.01);
  bad.dv_b_mps.y = INFINITY;
  assert_int_equal(nav_imu_model_apply(m, &bad, &meas), NAV_ERR_NUMERIC);
  nav_imu_model_destroy(m);
  nav_imu_model_destroy(NULL);

  nav_gnss_model_config g = nav_gnss_model_config_default();
  assert_int_equal(nav_gnss_model_config_validate(&g, NULL, NULL), NAV_OK);
  g.update_rate_hz = 0.0;
  g.outage_count = 1;
  g.outages[0].t0_s = 5.0;
  g.outages[0].t1_s = 5.0;
  issues = 0;
  assert_int_equal(nav_gnss_model_config_validate(&g, count_issue, &issues), NAV_ERR_INVALID_ARG);
  assert_int_equal(issues, 2);
}

/* ================================================================ GNSS */

static nav_frame flat_frame(void) {
  const nav_scene sc = nav_scene_default();
  return nav_frame_from_scene(&sc);
}

static nav_frame wgs84_frame(double lat_deg, double lon_deg, double h_m) {
  nav_scene sc = nav_scene_default();
  sc.earth.model = NAV_EARTH_WGS84;
  sc.earth.origin_lat_rad = nav_unit_deg_to_rad(lat_deg);
  sc.earth.origin_lon_rad = nav_unit_deg_to_rad(lon_deg);
  sc.earth.origin_h_m = h_m;
  return nav_frame_from_scene(&sc);
}

static nav_traj_state still_at(nav_vec3 r_f, double t) {
  nav_traj_state s;
  memset(&s, 0, sizeof s);
  s.t_s = t;
  s.r_fb_f_m = r_f;
  s.q_b_f = nav_quat_identity();
  return s;
}

/* Per-axis sigma (white, tau = 0) and GM correlation; reported sigmas. */
static void test_gnss_statistics(void **state) {
  (void)state;
  nav_test_print_seed("gnss", k_seed);
  const nav_frame fr = flat_frame();
  nav_gnss_model_config cfg = nav_gnss_model_config_default();
  cfg.terms = NAV_GNSS_TERM_POS_GM | NAV_GNSS_TERM_POS_WHITE | NAV_GNSS_TERM_VEL_WHITE;
  cfg.update_rate_hz = 1.0;
  cfg.pos_gm_sd_m = nav_vec3_make(2.0, 3.0, 4.0);
  cfg.pos_gm_tau_s = nav_vec3_make(0.0, 10.0, 0.0); /* N and D white; E correlated (phi = e^-0.1) */
  cfg.pos_white_sd_m = nav_vec3_make(0.0, 0.0, 3.0);
  cfg.vel_sd_mps = nav_vec3_make(0.05, 0.1, 0.2);
  nav_gnss_model *m = NULL;
  assert_int_equal(nav_gnss_model_create(&cfg, &fr, k_seed, 51, &m), NAV_OK);
  enum { N = 20000 };
  double s2[3] = {0}, v2[3] = {0}, lag[3] = {0}, prev[3] = {0};
  for (int64_t j = 0; j < N; ++j) {
    const nav_traj_state st = still_at(nav_vec3_make(10.0, 20.0, -30.0), (double)j);
    nav_gnss_fix fix;
    bool has = false;
    assert_int_equal(nav_gnss_model_measure(m, j, &st, &fix, &has), NAV_OK);
    assert_true(has);
    if (j == 0) {
      assert_vec3_near(fix.pos_sd_m, nav_vec3_make(2.0, 3.0, 5.0), 1e-15);
      assert_vec3_near(fix.vel_sd_mps, cfg.vel_sd_mps, 0.0);
    }
    const nav_vec3 e = nav_vec3_sub(fix.r_fa_f_m, st.r_fb_f_m);
    assert_vec3_near(e, nav_gnss_model_errors(m)->pos_m, 1e-12);
    const double ee[3] = {e.x, e.y, e.z}, ve[3] = {fix.v_fa_n_mps.x, fix.v_fa_n_mps.y, fix.v_fa_n_mps.z};
    for (int a = 0; a < 3; ++a) {
      s2[a] += ee[a] * ee[a];
      v2[a] += ve[a] * ve[a];
      if (j > 0) lag[a] += ee[a] * prev[a];
      prev[a] = ee[a];
    }
  }
  nav_gnss_model_destroy(m);
  const double want_sd[3] = {2.0, 3.0, 5.0}, want_v[3] = {0.05, 0.1, 0.2};
  const double phi = exp(-0.1);
  /* Sample sd: relative sd 1/sqrt(2N) white (0.5 %), sqrt((1+phi^2)/(2N(1-phi^2))) for the GM
   * axis (2.2 %); tolerances are 4 sd. Lag-1 autocorrelation: sd 1/sqrt(N) (white) and
   * sqrt((1-phi^2)/N) (AR(1)). */
  const double tol_w = 4.0 / sqrt(2.0 * N),
               tol_gm = 4.0 * sqrt((1.0 + phi * phi) / (2.0 * N * (1.0 - phi * phi)));
  for (int a = 0; a < 3; ++a) {
    const double sd = sqrt(s2[a] / N), r1 = lag[a] / s2[a];
    assert_rel_near(sd, want_sd[a], a == 1 ? tol_gm : tol_w);
    assert_rel_near(sqrt(v2[a] / N), want_v[a], tol_w);
    if (a == 1)
      assert_near(r1, phi, 4.0 * sqrt((1.0 - phi * phi) / N));
    else
      assert_near(r1, 0.0, 4.0 / sqrt((double)N));
    print_message("[ GNSS     ] axis %d: position sd %.4f m (expected %.4f), lag-1 autocorrelation %.4f "
                  "(expected %.4f); "
                  "velocity sd %.4f (expected %.4f)\n",
                  a, sd, want_sd[a], r1, a == 1 ? phi : 0.0, sqrt(v2[a] / N), want_v[a]);
  }
}

/* Outages give no fix and do not change the realisation; skipped epochs do not either; latency. */
static void test_gnss_outages_and_epochs(void **state) {
  (void)state;
  const nav_frame fr = flat_frame();
  nav_gnss_model_config cfg = nav_gnss_model_config_default();
  cfg.terms = NAV_GNSS_TERMS_ALL;
  cfg.update_rate_hz = 5.0;
  cfg.latency_s = 0.12;
  cfg.pos_gm_sd_m = v3(1.0);
  cfg.pos_gm_tau_s = v3(30.0);
  cfg.pos_white_sd_m = v3(0.3);
  cfg.vel_sd_mps = v3(0.05);
  nav_gnss_model_config out_cfg = cfg;
  out_cfg.outage_count = 2;
  out_cfg.outages[0] = (nav_gnss_outage){10.0, 20.0};
  out_cfg.outages[1] = (nav_gnss_outage){30.0, 30.5};
  nav_gnss_model *a = NULL, *b = NULL, *c = NULL;
  assert_int_equal(nav_gnss_model_create(&cfg, &fr, k_seed, 61, &a), NAV_OK);
  assert_int_equal(nav_gnss_model_create(&out_cfg, &fr, k_seed, 61, &b), NAV_OK);
  assert_int_equal(nav_gnss_model_create(&cfg, &fr, k_seed, 61, &c), NAV_OK);
  int fixes = 0;
  for (int64_t j = 0; j < 200; ++j) {
    const double t = nav_gnss_model_epoch_time_s(a, j);
    assert_true(t == (double)j / 5.0);
    const nav_traj_state st = still_at(nav_vec3_zero(), t);
    nav_gnss_fix fa, fb;
    bool ha = false, hb = false;
    assert_int_equal(nav_gnss_model_measure(a, j, &st, &fa, &ha), NAV_OK);
    assert_int_equal(nav_gnss_model_measure(b, j, &st, &fb, &hb), NAV_OK);
    const bool out = (t >= 10.0 && t < 20.0) || (t >= 30.0 && t < 30.5);
    assert_true(ha);
    assert_int_equal(hb, !out);
    if (hb) {
      ++fixes;
      assert_memory_equal(&fa, &fb, sizeof fa); /* same realisation before and after the outages */
      assert_near(fb.t_avail_s, t + 0.12, 1e-15);
      assert_int_equal(fb.epoch, j);
    }
    /* Every 7th epoch only: the errors at those epochs are the same as when all are requested. */
    if (j % 7 == 0) {
      nav_gnss_fix fc;
      bool hc = false;
      assert_int_equal(nav_gnss_model_measure(c, j, &st, &fc, &hc), NAV_OK);
      assert_memory_equal(&fa, &fc, sizeof fa);
    }
  }
  assert_int_equal(fixes, 200 - 50 - 3);
  /* Epochs must increase and the truth must be at the epoch time. */
  nav_gnss_fix f;
  bool h = false;
  nav_traj_state st = still_at(nav_vec3_zero(), nav_gnss_model_epoch_time_s(a, 199));
  assert_int_equal(nav_gnss_model_measure(a, 199, &st, &f, &h), NAV_ERR_STATE);
  st.t_s = 41.0;
  assert_int_equal(nav_gnss_model_measure(a, 200, &st, &f, &h), NAV_ERR_INVALID_ARG);
  assert_true(strstr(nav_gnss_model_last_error(a), "truth") != NULL);
  nav_gnss_model_destroy(a);
  nav_gnss_model_destroy(b);
  nav_gnss_model_destroy(c);
}

/* Lever arm: antenna position and velocity, flat Earth (exact numbers) and WGS-84 (height, error
 * mapping through ECEF, also at the pole). */
static void test_gnss_lever_arm_geometry(void **state) {
  (void)state;
  nav_gnss_model_config cfg = nav_gnss_model_config_default();
  cfg.r_ba_b_m = nav_vec3_make(1.0, 0.0, -0.5); /* 1 m forward, 0.5 m up */
  const nav_frame flat = flat_frame();
  nav_gnss_model *m = NULL;
  assert_int_equal(nav_gnss_model_create(&cfg, &flat, k_seed, 71, &m), NAV_OK);
  nav_traj_state st = still_at(nav_vec3_make(100.0, 200.0, -50.0), 0.0);
  st.v_fb_f_mps = nav_vec3_make(10.0, 0.0, 0.0);
  st.q_b_f = nav_euler_to_quat((nav_euler){0.0, 0.0, NAV_PI / 2.0}); /* heading east */
  st.w_fb_b_rps = nav_vec3_make(0.0, 0.0, 0.2);
  nav_gnss_fix fix;
  bool has = false;
  assert_int_equal(nav_gnss_model_measure(m, 0, &st, &fix, &has), NAV_OK);
  assert_true(has);
  /* C_b_n r_ba_b = (0, 1, -0.5); C_b_n (w x r_ba_b) = C_b_n (0, 0.2, 0) = (-0.2, 0, 0). */
  assert_vec3_near(fix.r_fa_f_m, nav_vec3_make(100.0, 201.0, -50.5), 1e-12);
  assert_vec3_near(fix.v_fa_n_mps, nav_vec3_make(9.8, 0.0, 0.0), 1e-15);
  const nav_geodetic g =
      nav_frame_view(&flat, nav_vec3_make(100.0, 201.0, -50.5), nav_vec3_zero(), nav_quat_identity()).pos;
  assert_near(fix.pos.lat_rad, g.lat_rad, 1e-15);
  assert_near(fix.pos.lon_rad, g.lon_rad, 1e-15);
  assert_near(fix.pos.h_m, g.h_m, 1e-9);
  nav_gnss_model_destroy(m);

  /* WGS-84, F = ECEF: level attitude, antenna 0.5 m above the IMU; then white N/E/D errors whose
   * mapping back through ECEF must reproduce the reported true errors. */
  const double lats[3] = {45.0, -89.9, 90.0};
  for (int i = 0; i < 3; ++i) {
    const nav_frame fr = wgs84_frame(lats[i], 10.0, 100.0);
    nav_gnss_model_config c2 = cfg;
    c2.r_ba_b_m = nav_vec3_make(0.0, 0.0, -0.5);
    nav_gnss_model *p = NULL;
    assert_int_equal(nav_gnss_model_create(&c2, &fr, k_seed, 72, &p), NAV_OK);
    const nav_geodetic at = {nav_unit_deg_to_rad(lats[i]), nav_unit_deg_to_rad(10.0), 100.0};
    nav_traj_state s = still_at(nav_earth_geodetic_to_ecef(at), 0.0);
    const nav_mat3 C_n_e = nav_earth_dcm_n_e(at.lat_rad, at.lon_rad);
    s.q_b_f = nav_quat_from_dcm(C_n_e); /* q_b_e with C_b_n = I */
    assert_int_equal(nav_gnss_model_measure(p, 0, &s, &fix, &has), NAV_OK);
    assert_near(fix.pos.h_m, 100.5, 1e-8);
    assert_near(fix.pos.lat_rad, at.lat_rad, 1e-14);
    nav_gnss_model_destroy(p);

    c2.terms = NAV_GNSS_TERM_POS_WHITE;
    c2.pos_white_sd_m = nav_vec3_make(3.0, 4.0, 5.0);
    assert_int_equal(nav_gnss_model_create(&c2, &fr, k_seed, 73, &p), NAV_OK);
    assert_int_equal(nav_gnss_model_measure(p, 0, &s, &fix, &has), NAV_OK);
    const nav_vec3 r_ant = nav_vec3_add(s.r_fb_f_m, nav_mat3_mul_vec(C_n_e, c2.r_ba_b_m));
    const nav_vec3 e_n = nav_mat3_tmul_vec(C_n_e, nav_vec3_sub(fix.r_fa_f_m, r_ant));
    assert_vec3_near(e_n, nav_gnss_model_errors(p)->pos_m, 1e-8);
    const nav_vec3 r_back = nav_earth_geodetic_to_ecef(fix.pos);
    assert_vec3_near(r_back, fix.r_fa_f_m, 2e-8);
    nav_gnss_model_destroy(p);
  }
}

/* ================================================================ catalog */

typedef struct diag_log {
  int n;
  nav_diag d[NAV_DIAG_MAX_PER_FILE];
} diag_log;

static void collect(void *user, const nav_diag *d) {
  diag_log *log = user;
  if (log->n < NAV_DIAG_MAX_PER_FILE) log->d[log->n] = *d;
  log->n++;
}

static void print_log(const diag_log *log) {
  char line[2048];
  for (int i = 0; i < log->n && i < NAV_DIAG_MAX_PER_FILE; ++i) {
    nav_diag_format(&log->d[i], line, sizeof line);
    print_message("  [%d] %s\n", i, line);
  }
}

static void test_catalog_resources(void **state) {
  (void)state;
  static diag_log log;
  memset(&log, 0, sizeof log);
  nav_catalog *cat = NULL;
  const nav_status st =
      nav_catalog_load(NAV_SOURCE_DIR "/resources/imu_catalog.csv", NULL, &cat, collect, &log);
  print_log(&log);
  assert_int_equal(st, NAV_OK);
  assert_int_equal(log.n, 0);
  assert_int_equal(nav_catalog_get_kind(cat), NAV_CATALOG_IMU);
  assert_int_equal(nav_catalog_count(cat), 19);
  size_t unverified = 0;
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_imu_entry *e = nav_catalog_imu_at(cat, i);
    /* Every row converts to a model that creates and runs. */
    nav_imu_model *m = NULL;
    assert_int_equal(nav_imu_model_create(&e->config, k_seed, 0, &m), NAV_OK);
    nav_imu_increment ideal = increment(1, 0.005), meas;
    assert_int_equal(nav_imu_model_apply(m, &ideal, &meas), NAV_OK);
    nav_imu_model_destroy(m);
    if (e->verified == NAV_CATALOG_VERIFIED_NO) {
      ++unverified;
      assert_non_null(strstr(e->verified_text, "unverified"));
    }
  }
  assert_int_equal(unverified, 4); /* BMI088, MTi-630, ADIS16490, HG4930 */
  assert_null(nav_catalog_imu_at(cat, 19));
  assert_null(nav_catalog_gnss_at(cat, 0));

  const nav_catalog_imu_entry *adis = nav_catalog_find_imu(cat, "adis16465-1");
  assert_non_null(adis);
  assert_int_equal(adis->verified, NAV_CATALOG_VERIFIED_YES);
  assert_int_equal(adis->bias_model, NAV_CATALOG_BIAS_ALLAN_MIN);
  assert_int_equal(adis->config.gyro.terms, NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM);
  assert_int_equal(adis->config.accel.terms, NAV_IMU_TERM_BIAS_GM); /* VRW not in the source */
  assert_near(adis->config.gyro.arw_rad_per_sqrt_s.z, 4.36332e-5, 0.5e-10);
  assert_rel_near(adis->config.gyro.bias_gm_sd_rps.x, 9.69627e-06 / 0.61736, 2e-5);
  assert_rel_near(adis->config.gyro.bias_gm_tau_s.y, 300.0 / 1.8926, 1e-4);
  assert_rel_near(adis->config.accel.bias_gm_sd_mps2.x, 3.53039e-05 / 0.61736, 2e-5);

  const nav_catalog_imu_entry *stim = nav_catalog_find_imu(cat, "Safran Sensonor STIM300");
  assert_non_null(stim);
  assert_near(stim->config.gyro.scale_factor_sd.x, 500e-6, 1e-18);
  assert_near(stim->config.accel.scale_factor_sd.y, 300e-6, 1e-18);
  assert_near(stim->config.gyro.misalignment_sd_rad.m[2][1], 1e-3, 0.0);
  assert_true(stim->config.accel.misalignment_sd_rad.m[1][1] == 0.0);
  assert_rel_near(stim->config.accel.bias_turn_on_sd_mps2.x, 0.75e-3 * 9.80665, 1e-15);

  const nav_catalog_imu_entry *a15 = nav_catalog_find_imu(cat, "Leador A15 (KF-GINS example tuning)");
  assert_non_null(a15);
  assert_int_equal(a15->bias_model, NAV_CATALOG_BIAS_GM_SIGMA);
  assert_rel_near(a15->config.gyro.bias_gm_sd_rps.x, 1.309e-07, 1e-4);
  assert_near(a15->config.accel.bias_gm_tau_s.x, 14400.0, 0.0);

  const nav_catalog_imu_entry *groves = nav_catalog_find_imu(cat, "Groves consumer-grade model");
  assert_non_null(groves);
  assert_int_equal(groves->bias_model, NAV_CATALOG_BIAS_TURN_ON);
  assert_true((groves->config.gyro.terms & NAV_IMU_TERM_BIAS_GM) == 0);
  assert_rel_near(groves->config.gyro.bias_turn_on_sd_rps.x, 0.000969627, 1e-5);

  const nav_catalog_imu_entry *bmi = nav_catalog_find_imu(cat, "Bosch BMI088");
  assert_non_null(bmi);
  assert_int_equal(bmi->verified, NAV_CATALOG_VERIFIED_NO);
  assert_null(nav_catalog_find_imu(cat, "no such IMU"));
  nav_catalog_destroy(cat);

  /* The other convention: sigma = B. */
  nav_catalog_options opt = nav_catalog_options_default();
  opt.convention = NAV_BI_SIGMA_EQUALS_B;
  assert_int_equal(nav_catalog_load(NAV_SOURCE_DIR "/resources/imu_catalog.csv", &opt, &cat, NULL, NULL),
                   NAV_OK);
  assert_rel_near(nav_catalog_find_imu(cat, "ADIS16465-1")->config.gyro.bias_gm_sd_rps.x, 9.69627e-06, 1e-5);
  nav_catalog_destroy(cat);

  /* GNSS receivers. */
  memset(&log, 0, sizeof log);
  assert_int_equal(
      nav_catalog_load(NAV_SOURCE_DIR "/resources/gnss_receivers.csv", NULL, &cat, collect, &log), NAV_OK);
  print_log(&log);
  assert_int_equal(nav_catalog_get_kind(cat), NAV_CATALOG_GNSS);
  assert_int_equal(nav_catalog_count(cat), 7);
  const nav_catalog_gnss_entry *rtk = nav_catalog_find_gnss(cat, "RTK fixed");
  assert_non_null(rtk);
  assert_int_equal(rtk->verified, NAV_CATALOG_VERIFIED_PARTLY);
  assert_vec3_near(rtk->config.pos_gm_sd_m, nav_vec3_make(0.01, 0.01, 0.02), 0.0);
  assert_vec3_near(rtk->config.pos_gm_tau_s, v3(5.0), 0.0);
  assert_vec3_near(rtk->config.vel_sd_mps, v3(0.02), 0.0);
  assert_near(rtk->config.update_rate_hz, 10.0, 0.0);
  assert_vec3_near(nav_catalog_find_gnss(cat, "standalone SPS (gnss-ins-sim default)")->config.pos_gm_tau_s,
                   v3(0.0), 0.0);
  assert_int_equal(nav_catalog_find_gnss(cat, "SBAS (WAAS/EGNOS class)")->verified, NAV_CATALOG_VERIFIED_NO);
  const nav_frame fr = flat_frame();
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    nav_gnss_model *g = NULL;
    assert_int_equal(nav_gnss_model_create(&nav_catalog_gnss_at(cat, i)->config, &fr, k_seed, 0, &g), NAV_OK);
    nav_gnss_model_destroy(g);
  }
  nav_catalog_destroy(cat);
}

/* One of each kind of row error, with its exact place; nothing is returned. */
/* Issue 21 item 3: the accelerometer parts for arrays (resources/accel_catalog.csv). Every row
 * loads; a verified row's model is its datasheet figures in SI (Safran Colibrys MS1000 data sheet,
 * MS1010 column: 34 ug/rtHz, in-run bias 15 ug, long-term bias repeatability 1.2 mg, 120 ppm);
 * rows not checked against a data sheet say so. */
static void test_accel_catalog_resources(void **state) {
  (void)state;
  static diag_log log;
  memset(&log, 0, sizeof log);
  nav_catalog *cat = NULL;
  const nav_status st =
      nav_catalog_load(NAV_SOURCE_DIR "/resources/accel_catalog.csv", NULL, &cat, collect, &log);
  print_log(&log);
  assert_int_equal(st, NAV_OK);
  assert_int_equal(nav_catalog_get_kind(cat), NAV_CATALOG_ACCEL);
  assert_true(nav_catalog_count(cat) >= 6);
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const nav_catalog_accel_entry *e = nav_catalog_accel_at(cat, i);
    assert_non_null(e);
    assert_true(strlen(e->source) > 20); /* every row cites its source */
    assert_true(e->given & NAV_CATALOG_ACCEL_HAS_NOISE);
    assert_true(e->config.terms & NAV_IMU_TERM_NOISE);
    assert_true(e->cost_class >= 1);
  }
  assert_null(nav_catalog_accel_at(cat, nav_catalog_count(cat)));
  assert_null(nav_catalog_imu_at(cat, 0));
  assert_null(nav_catalog_find_imu(cat, "Safran Colibrys MS1010"));

  const double g0 = 9.80665, ug = 1e-6 * g0;
  const nav_catalog_accel_entry *ms = nav_catalog_find_accel(cat, "safran colibrys ms1010");
  assert_non_null(ms);
  assert_string_equal(ms->name, "Safran Colibrys MS1010");
  assert_int_equal(ms->verified, NAV_CATALOG_VERIFIED_YES);
  assert_near(ms->noise_density_ug_per_sqrt_hz, 34.0, 1e-12);
  assert_near(ms->bias_instability_ug, 15.0, 1e-12);
  assert_near(ms->bias_repeatability_mg, 1.2, 1e-15);
  assert_near(ms->scale_factor_ppm, 120.0, 0.0);
  assert_near(ms->range_g, 10.0, 0.0);
  const nav_array_error_config *a = &ms->config;
  assert_int_equal(a->terms, NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_TURN_ON |
                                 NAV_IMU_TERM_SCALE_FACTOR);
  assert_rel_near(a->vrw_mps_per_sqrt_s, 34.0 * ug, 1e-12);
  /* Allan floor B -> GM sigma B / 0.61736, T = 300 s / 1.8926 (MEMS default, nav_catalog.h). */
  assert_rel_near(a->bias_gm_sd_mps2, 15.0 * ug / 0.61736, 1e-4);
  assert_rel_near(a->bias_gm_tau_s, 300.0 / 1.8926, 1e-4);
  assert_rel_near(a->bias_turn_on_sd_mps2, 1.2e-3 * g0, 1e-12);
  assert_rel_near(a->scale_factor_sd, 120e-6, 1e-12);

  /* A part with only a noise figure gives only the noise term. */
  const nav_catalog_accel_entry *sca = nav_catalog_find_accel(cat, "Murata SCA3300-D01");
  assert_non_null(sca);
  assert_int_equal(sca->config.terms, NAV_IMU_TERM_NOISE);
  assert_rel_near(sca->config.vrw_mps_per_sqrt_s, 37.0 * ug, 1e-12);
  assert_near(sca->bandwidth_hz, 70.0, 0.0);
  /* Navigation-grade quartz: the long default Allan time; quoted from memory, flagged as such. */
  const nav_catalog_accel_entry *qa = nav_catalog_find_accel(cat, "Honeywell QA-2000 Q-Flex");
  assert_non_null(qa);
  assert_int_equal(qa->verified, NAV_CATALOG_VERIFIED_NO);
  assert_non_null(strstr(qa->verified_text, "unverified"));
  assert_null(nav_catalog_find_accel(cat, "no such part"));
  nav_catalog_destroy(cat);
}

/* Bad accelerometer rows: FILE:LINE:COL of the cell, the column and what was expected. */
static void test_accel_catalog_invalid_rows(void **state) {
  (void)state;
  static const char text[] =
      "part,grade,noise_density_ug_per_sqrt_hz,noise_density_m_per_s2_per_sqrt_hz,bias_instability_ug,"
      "bias_repeatability_mg,bias_model,source,verified_in_corpus\n"
      "P1,MEMS,10,9.80665e-05,,,allan_min,src,yes\n"
      "P2,MEMS,10,1e-4,,,allan_min,src,yes\n"
      "P3,MEMS,99999,,,,allan_min,src,yes\n"
      "P4,MEMS,10,,5,1,turn_on,src,yes\n"
      "p1,MEMS,10,,,,allan_min,src,yes\n"
      "P5,MEMS,10,,3,,gm_sigma,src,yes\n";
  static diag_log log;
  memset(&log, 0, sizeof log);
  nav_catalog *cat = NULL;
  assert_int_equal(nav_catalog_load_string(text, sizeof text - 1, "acc.csv", NULL, &cat, collect, &log),
                   NAV_ERR_PARSE);
  print_log(&log);
  assert_null(cat);
  assert_int_equal(log.n, 5);
  const struct {
    int line, col;
    const char *path, *msg;
  } want[5] = {
      {3, 12, "noise_density_m_per_s2_per_sqrt_hz", "disagrees with noise_density_ug_per_sqrt_hz"},
      {4, 9, "noise_density_ug_per_sqrt_hz", "plausibility bound"},
      {5, 17, "bias_model", "give the same bias twice"},
      {6, 1, "part", "already used on line 2"},
      {7, 16, "bias_model", "needs bias_corr_time_s"},
  };
  for (int i = 0; i < 5; ++i) {
    assert_string_equal(log.d[i].file, "acc.csv");
    assert_int_equal(log.d[i].line, want[i].line);
    assert_int_equal(log.d[i].col, want[i].col);
    assert_string_equal(log.d[i].path, want[i].path);
    assert_non_null(strstr(log.d[i].message, want[i].msg));
  }
  /* Two key columns: not one kind of catalog. */
  static const char two[] = "part,name,source\nA,B,C\n";
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_catalog_load_string(two, sizeof two - 1, "two.csv", NULL, &cat, collect, &log),
                   NAV_ERR_PARSE);
  assert_non_null(strstr(log.d[0].message, "more than one of the key columns"));
}

static void test_catalog_invalid_rows(void **state) {
  (void)state;
  static const char text[] =
      "name,grade,gyro_arw_deg_per_sqrt_h,gyro_arw_rad_per_sqrt_s,bias_model,source,verified_in_corpus\n"
      "A,consumer MEMS,0.15,4.36332e-05,allan_min,src,yes\n"
      "B,consumer MEMS,abc,,allan_min,src,yes\n"
      "C,consumer MEMS,0.15,5e-05,allan_min,src,no\n"
      "D,consumer MEMS,-1,,allan_min,src,maybe\r\n"
      "a,consumer MEMS,0.1,,allan_min,src,yes\n"
      "E,consumer MEMS,0.1,,allan_min,src\n"
      "F,\"consumer MEMS,0.1,,allan_min,src,yes\n";
  static diag_log log;
  memset(&log, 0, sizeof log);
  nav_catalog *cat = NULL;
  assert_int_equal(nav_catalog_load_string(text, sizeof text - 1, "bad.csv", NULL, &cat, collect, &log),
                   NAV_ERR_PARSE);
  print_log(&log);
  assert_null(cat);
  assert_int_equal(log.n, 7);
  const struct {
    int line, col;
    const char *path, *msg;
  } want[7] = {
      {3, 17, "gyro_arw_deg_per_sqrt_h", "'abc' is not a number"},
      {4, 22, "gyro_arw_rad_per_sqrt_s", "disagrees with gyro_arw_deg_per_sqrt_h"},
      {5, 17, "gyro_arw_deg_per_sqrt_h", "must be finite and >= 0"},
      {5, 35, "verified_in_corpus", "must start with yes, partly, derived or no"},
      {6, 1, "name", "already used on line 2"},
      {7, 32, "", "row has 6 cells, the header 7"},
      {8, 3, "", "quoted cell is not closed"},
  };
  for (int i = 0; i < 7; ++i) {
    assert_string_equal(log.d[i].file, "bad.csv");
    assert_int_equal(log.d[i].line, want[i].line);
    assert_int_equal(log.d[i].col, want[i].col);
    assert_string_equal(log.d[i].path, want[i].path);
    assert_non_null(strstr(log.d[i].message, want[i].msg));
  }
  char line[2048];
  nav_diag_format(&log.d[0], line, sizeof line);
  assert_string_equal(line, "bad.csv:3:17: error: gyro_arw_deg_per_sqrt_h: 'abc' is not a number");

  /* Header problems: a misspelt column (with a suggestion) and a missing required one. */
  static const char hdr[] = "name,grade,gyro_arw_deg_per_sqrth,source\nX,MEMS,0.1,s\n";
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_catalog_load_string(hdr, sizeof hdr - 1, "hdr.csv", NULL, &cat, collect, &log),
                   NAV_ERR_PARSE);
  print_log(&log);
  assert_int_equal(log.n, 2);
  assert_int_equal(log.d[0].line, 1);
  assert_int_equal(log.d[0].col, 12);
  assert_non_null(strstr(log.d[0].message, "did you mean 'gyro_arw_deg_per_sqrt_h'"));
  assert_string_equal(log.d[1].path, "verified_in_corpus");
  assert_non_null(strstr(log.d[1].message, "required column is missing"));

  /* gm_sigma without a correlation time; not a catalog at all; unreadable file. */
  static const char gm[] = "name,grade,gyro_bias_instability_deg_per_h,bias_model,source,verified_in_corpus\n"
                           "G,MEMS,1,gm_sigma,s,yes\n";
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_catalog_load_string(gm, sizeof gm - 1, "gm.csv", NULL, &cat, collect, &log),
                   NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  assert_non_null(strstr(log.d[0].message, "bias_corr_time_s"));
  static const char other[] = "a,b\n1,2\n";
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_catalog_load_string(other, sizeof other - 1, "o.csv", NULL, &cat, collect, &log),
                   NAV_ERR_PARSE);
  assert_non_null(strstr(log.d[0].message, "not a sensor catalog"));
  memset(&log, 0, sizeof log);
  assert_int_equal(
      nav_catalog_load(NAV_SOURCE_DIR "/resources/no_such_catalog.csv", NULL, &cat, collect, &log),
      NAV_ERR_IO);
  assert_int_equal(log.n, 1);
  assert_int_equal(log.d[0].line, 0);
  assert_null(cat);
}

/* Issue 25: every numeric column of both catalogs is bounded like the scene key it feeds
 * (navcore/io/scene_bounds.h); a value above is reported at FILE:LINE:COL naming the column (a
 * GNSS row with update_rate_hz 1e9 used to load, and the filter then failed), a value at the
 * bound loads. */
static void test_issue_25_catalog_plausibility(void **state) {
  (void)state;
  static const struct {
    bool gnss;
    const char *column, *at_bound, *above;
  } k[] = {
      {false, "gyro_bias_instability_deg_per_h", "180000", "2e5"},
      {false, "gyro_bias_instability_rad_per_s", "0.87", "0.88"},
      {false, "gyro_arw_deg_per_sqrt_h", "100", "101"},
      {false, "gyro_arw_rad_per_sqrt_s", "0.029", "0.03"},
      {false, "gyro_turn_on_bias_deg_per_s", "100", "1e300"},
      {false, "gyro_scale_factor_ppm", "1e6", "1.1e6"},
      {false, "accel_bias_instability_ug", "5e5", "6e5"},
      {false, "accel_bias_instability_m_per_s2", "4.9", "5"},
      {false, "accel_vrw_m_per_s_per_sqrt_h", "10", "11"},
      {false, "accel_vrw_m_per_s_per_sqrt_s", "0.16", "0.17"},
      {false, "accel_turn_on_bias_mg", "1000", "1001"},
      {false, "accel_scale_factor_ppm", "1e6", "2e6"},
      {false, "misalignment_mrad", "100", "101"},
      {false, "bias_corr_time_s", "1e7", "1e8"},
      {true, "horizontal_sigma_per_axis_m", "1000", "1001"},
      {true, "vertical_sigma_m", "1000", "1e9"},
      {true, "correlation_time_s", "1e7", "1e300"},
      {true, "velocity_sigma_per_axis_m_per_s", "100", "101"},
      {true, "update_rate_hz", "1000", "1e9"},
  };
  static diag_log log;
  char text[1024];
  for (size_t i = 0; i < sizeof k / sizeof k[0]; ++i) {
    for (int above = 0; above < 2; ++above) {
      const char *v = above ? k[i].above : k[i].at_bound;
      if (k[i].gnss) {
        const bool sigma = strstr(k[i].column, "sigma") && strcmp(k[i].column, "velocity_sigma_per_axis_m_per_s");
        const bool rate = strcmp(k[i].column, "update_rate_hz") == 0;
        snprintf(text, sizeof text, "mode,%s%s%s,source,verified_in_corpus\nR,%s%s%s,s,yes\n", k[i].column,
                 sigma ? "" : ",horizontal_sigma_per_axis_m,vertical_sigma_m", rate ? "" : ",update_rate_hz", v,
                 sigma ? "" : ",1,2", rate ? "" : ",1");
        if (sigma) /* the other sigma column too */
          snprintf(text, sizeof text, "mode,%s,%s,update_rate_hz,source,verified_in_corpus\nR,%s,1,1,s,yes\n",
                   k[i].column,
                   strcmp(k[i].column, "vertical_sigma_m") ? "vertical_sigma_m" : "horizontal_sigma_per_axis_m", v);
      } else {
        snprintf(text, sizeof text, "name,grade,%s,source,verified_in_corpus\nI,tactical MEMS,%s,s,yes\n",
                 k[i].column, v);
      }
      memset(&log, 0, sizeof log);
      nav_catalog *cat = NULL;
      const nav_status st = nav_catalog_load_string(text, strlen(text), "c.csv", NULL, &cat, collect, &log);
      if (!above) {
        if (st != NAV_OK) {
          print_log(&log);
          fail_msg("%s = %s (at the bound) refused", k[i].column, v);
        }
        nav_catalog_destroy(cat);
        continue;
      }
      assert_int_equal(st, NAV_ERR_PARSE);
      assert_null(cat);
      assert_int_equal(log.n, 1);
      assert_int_equal(log.d[0].line, 2);
      assert_int_equal(log.d[0].col, k[i].gnss ? 3 : 17); /* the cell after "R," / "I,tactical MEMS," */
      assert_string_equal(log.d[0].path, k[i].column);
      if (!strstr(log.d[0].message, "must be <=")) fail_msg("%s: %s", k[i].column, log.d[0].message);
    }
  }
}

/* Hostile input: 300 seeded mutations of the real catalog (random bytes overwritten, inserted
 * quotes, commas, NULs, truncations) must give NAV_OK or NAV_ERR_PARSE, never a crash (run under
 * ASan in CI), and a catalog only together with zero diagnostics. */
static void test_catalog_hostile_input(void **state) {
  (void)state;
  nav_test_print_seed("catalog fuzz", k_seed);
  FILE *f = fopen(NAV_SOURCE_DIR "/resources/imu_catalog.csv", "rb");
  assert_non_null(f);
  static char orig[1 << 16], buf[1 << 16];
  const size_t len = fread(orig, 1, sizeof orig, f);
  fclose(f);
  assert_true(len > 1000 && len < sizeof orig);
  nav_rng r;
  nav_rng_init(&r, k_seed, 0, NAV_RNG_STREAM_USER + 1);
  static const char specials[] = {'"', ',', '\n', '\r', '\0', '\t', 'x', '-', '.', 'e', (char)0xff};
  static diag_log log;
  for (int iter = 0; iter < 300; ++iter) {
    memcpy(buf, orig, len);
    size_t n = len;
    const int edits = 1 + (int)(nav_rng_next_u64(&r) % 8);
    for (int e = 0; e < edits; ++e) {
      const size_t at = (size_t)(nav_rng_next_u64(&r) % n);
      const char ch = specials[nav_rng_next_u64(&r) % sizeof specials];
      switch (nav_rng_next_u64(&r) % 3) {
      case 0: buf[at] = ch; break;
      case 1:
        if (n + 1 < sizeof buf) {
          memmove(buf + at + 1, buf + at, n - at);
          buf[at] = ch;
          ++n;
        }
        break;
      default: n = at + 1; break;
      }
    }
    memset(&log, 0, sizeof log);
    nav_catalog *cat = NULL;
    const nav_status st = nav_catalog_load_string(buf, n, "fuzz.csv", NULL, &cat, collect, &log);
    assert_true(st == NAV_OK || st == NAV_ERR_PARSE);
    assert_int_equal(st == NAV_OK, log.n == 0);
    assert_int_equal(st == NAV_OK, cat != NULL);
    for (int i = 0; i < log.n && i < NAV_DIAG_MAX_PER_FILE; ++i)
      assert_true(log.d[i].line >= 0 && log.d[i].col >= 0);
    nav_catalog_destroy(cat);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_units_numerics_examples),
      cmocka_unit_test(test_bias_instability_mapping),
      cmocka_unit_test(test_allan_known_answers),
      cmocka_unit_test(test_t2_1_white_noise_rate_independent),
      cmocka_unit_test(test_t2_2_gauss_markov),
      cmocka_unit_test(test_t2_3_random_walk),
      cmocka_unit_test(test_t2_4_flat_region),
      cmocka_unit_test(test_t2_5_quantisation),
      cmocka_unit_test(test_t2_6_determinism_and_streams),
      cmocka_unit_test(test_t2_7_scale_factor_misalignment),
      cmocka_unit_test(test_bias_reporting),
      cmocka_unit_test(test_deferred_bias_state),
      cmocka_unit_test(test_imu_lanes_match_alone),
      cmocka_unit_test(test_saturation),
      cmocka_unit_test(test_ideal_model_is_identity),
      cmocka_unit_test(test_config_validation_and_errors),
      cmocka_unit_test(test_gnss_statistics),
      cmocka_unit_test(test_gnss_outages_and_epochs),
      cmocka_unit_test(test_gnss_lever_arm_geometry),
      cmocka_unit_test(test_catalog_resources),
      cmocka_unit_test(test_catalog_invalid_rows),
      cmocka_unit_test(test_accel_catalog_resources),
      cmocka_unit_test(test_accel_catalog_invalid_rows),
      cmocka_unit_test(test_issue_25_catalog_plausibility),
      cmocka_unit_test(test_catalog_hostile_input),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
