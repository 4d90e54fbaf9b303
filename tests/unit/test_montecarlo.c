/*
 * Monte Carlo engine: determinism across thread counts, and Monte Carlo RMS against the
 * closed-form error growth of numerics.md section 1 (E1.11, E1.15, E1.7, E1.8) on a stationary
 * body on the flat Earth, where those formulas are exact for the linear error chains (no
 * Schuler loop, no Earth rate).
 *
 * Chi-square bands: with M runs and two independent horizontal axes, M * (h_rms / sigma_1axis)^2
 * / 2 ... is chi2(2M) / (2M) distributed for h^2 = e_N^2 + e_E^2, i.e. (RMS_h / (sqrt(2) sigma))^2
 * ~ chi2(2M) / (2M). The 99.9 % band for 2M = 800 degrees of freedom is computed below from the
 * Wilson-Hilferty approximation (accurate to < 0.1 % at this size).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "nav_test.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_sim.h"

/* chi2(k)/k quantile by Wilson-Hilferty: (1 - 2/(9k) + z sqrt(2/(9k)))^3. */
static double chi2_over_k(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + z * sqrt(a);
  return c * c * c;
}

static nav_scene stationary_flat(double duration_s, long runs) {
  nav_scene sc = nav_scene_default();
  sc.name[0] = 'm';
  sc.name[1] = '\0';
  sc.trajectory.type = NAV_TRAJ_TEST_MOTION;
  sc.trajectory.test_motion.kind = NAV_TEST_MOTION_STATIONARY;
  sc.trajectory.duration_s = duration_s;
  sc.imu.rate_hz = 100.0;
  sc.output.rate_hz = 1.0;
  sc.simulation.runs = runs;
  sc.simulation.seed = 20261122;
  return sc;
}

static nav_sim_summary run_scene(const nav_scene *sc, int threads) {
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = threads;
  nav_sim_summary sum;
  const nav_status st = nav_sim_run(sim, &o, &sum);
  if (st != NAV_OK) fail_msg("nav_sim_run: %s: %s", nav_status_str(st), nav_sim_last_error(sim));
  nav_sim_destroy(sim);
  return sum;
}

/* Same scene and seed, 1, 2 and 3 threads: bit-identical summaries. */
static void test_deterministic_across_threads(void **state) {
  (void)state;
  nav_scene sc = nav_scene_default();
  sc.simulation.runs = 7;
  nav_imu_model_config *m = &sc.imu.model;
  m->gyro.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_TURN_ON;
  m->gyro.arw_rad_per_sqrt_s = nav_vec3_make(1e-4, 1e-4, 1e-4);
  m->gyro.bias_gm_sd_rps = nav_vec3_make(1e-5, 1e-5, 1e-5);
  m->gyro.bias_gm_tau_s = nav_vec3_make(100.0, 100.0, 100.0);
  m->gyro.bias_turn_on_sd_rps = nav_vec3_make(1e-5, 2e-5, 3e-5);
  m->accel.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_SCALE_FACTOR;
  m->accel.vrw_mps_per_sqrt_s = nav_vec3_make(1e-3, 1e-3, 1e-3);
  m->accel.scale_factor_sd = nav_vec3_make(1e-4, 1e-4, 1e-4);
  sc.initial_errors.pos_sd_m = nav_vec3_make(0.1, 0.1, 0.2);
  sc.initial_errors.att_sd_rad = nav_vec3_make(1e-4, 1e-4, 1e-3);
  const nav_sim_summary a = run_scene(&sc, 1), b = run_scene(&sc, 2), c = run_scene(&sc, 3);
  assert_int_equal(a.runs, 7);
  assert_memory_equal(&a.stats, &b.stats, sizeof a.stats);
  assert_memory_equal(&a.stats, &c.stats, sizeof a.stats);
  assert_memory_equal(&a.final, &c.final, sizeof a.final);
  assert_memory_equal(&a.final_rms, &b.final_rms, sizeof a.final_rms);
  /* The errors are real: a different seed changes them. */
  sc.simulation.seed += 1;
  const nav_sim_summary d = run_scene(&sc, 2);
  assert_true(d.final_rms.pos_err_h_m != a.final_rms.pos_err_h_m);
  assert_true(a.final_rms.pos_err_h_m > 1e-3);
}

static void check_band(const char *what, double rms_h, double sigma_axis, long runs) {
  const double k = 2.0 * (double)runs;
  const double lo = sqrt(chi2_over_k(k, -3.29)), hi = sqrt(chi2_over_k(k, 3.29)); /* 99.9 % */
  const double ratio = rms_h / (sqrt(2.0) * sigma_axis);
  print_message("%s: MC RMS %.5g m, formula %.5g m per axis, ratio %.4f, band [%.4f, %.4f]\n", what, rms_h,
                sigma_axis, ratio, lo, hi);
  if (!(ratio > lo && ratio < hi)) fail_msg("%s: ratio %.4f outside [%.4f, %.4f]", what, ratio, lo, hi);
}

/* E1.11: accelerometer white noise N_a -> position sigma N_a sqrt(t^3/3) per axis. */
static void test_mc_accel_noise(void **state) {
  (void)state;
  const double t = 10.0, Na = 2e-3;
  const long runs = 400;
  nav_scene sc = stationary_flat(t, runs);
  sc.imu.model.accel.terms = NAV_IMU_TERM_NOISE;
  sc.imu.model.accel.vrw_mps_per_sqrt_s = nav_vec3_make(Na, Na, Na);
  const nav_sim_summary s = run_scene(&sc, 2);
  check_band("E1.11 accel noise", s.final_rms.pos_err_h_m, Na * sqrt(t * t * t / 3.0), runs);
}

/* E1.15: gyro white noise N_g -> position sigma g N_g sqrt(t^5/20) per axis (level, small angles). */
static void test_mc_gyro_noise(void **state) {
  (void)state;
  const double t = 10.0, Ng = 3e-4, g = 9.80665;
  const long runs = 400;
  nav_scene sc = stationary_flat(t, runs);
  sc.imu.model.gyro.terms = NAV_IMU_TERM_NOISE;
  sc.imu.model.gyro.arw_rad_per_sqrt_s = nav_vec3_make(Ng, Ng, Ng);
  const nav_sim_summary s = run_scene(&sc, 2);
  check_band("E1.15 gyro noise", s.final_rms.pos_err_h_m, g * Ng * sqrt(pow(t, 5.0) / 20.0), runs);
}

/* E1.7 and E1.8: initial velocity and tilt errors -> dv0 t and g psi0 t^2 / 2 per axis. */
static void test_mc_initial_errors(void **state) {
  (void)state;
  const double t = 10.0, g = 9.80665;
  const long runs = 400;
  nav_scene sc = stationary_flat(t, runs);
  sc.initial_errors.vel_sd_mps = nav_vec3_make(0.01, 0.01, 0.0);
  nav_sim_summary s = run_scene(&sc, 2);
  check_band("E1.7 initial velocity", s.final_rms.pos_err_h_m, 0.01 * t, runs);
  sc.initial_errors.vel_sd_mps = nav_vec3_zero();
  sc.initial_errors.att_sd_rad = nav_vec3_make(1e-4, 1e-4, 0.0);
  s = run_scene(&sc, 2);
  check_band("E1.8 initial tilt", s.final_rms.pos_err_h_m, g * 1e-4 * t * t / 2.0, runs);
}

/* --ideal ignores the error models and runs once. */
static void test_ideal_ignores_errors(void **state) {
  (void)state;
  nav_scene sc = stationary_flat(5.0, 10);
  sc.imu.model.accel.terms = NAV_IMU_TERM_NOISE;
  sc.imu.model.accel.vrw_mps_per_sqrt_s = nav_vec3_make(1.0, 1.0, 1.0);
  sc.initial_errors.pos_sd_m = nav_vec3_make(10.0, 10.0, 10.0);
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.ideal = true;
  nav_sim_summary sum;
  assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_OK);
  assert_int_equal(sum.runs, 1);
  assert_true(sum.final.pos_err_h_m < 1e-9);
  nav_sim_destroy(sim);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_deterministic_across_threads),
      cmocka_unit_test(test_mc_accel_noise),
      cmocka_unit_test(test_mc_gyro_noise),
      cmocka_unit_test(test_mc_initial_errors),
      cmocka_unit_test(test_ideal_ignores_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
