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
#include "navcore/nav_filter.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"

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

/*
 * numerics.md T6.6: the T6.3 outage (lat 45 deg, h = 0, 20 m/s north, level, tactical IMU with
 * random-constant biases, no GNSS) simulated with the full nonlinear simulator (sensor models of
 * section 2, random initial errors drawn from P0), N = 200 runs; at 10, 30, 60 and 120 s the RMS
 * north error over runs divided by the covariance-analysis sigma must lie in the 99 % interval
 * [0.873, 1.130] at >= 3 of the 4 epochs. The covariance sigma is computed here by the filter in
 * covariance mode along the same truth, and itself checked against T6.3 (0.1 %).
 */
static void test_t66_monte_carlo_vs_covariance(void **state) {
  (void)state;
  const double d2r = NAV_PI / 180.0, g0 = 9.80665;
  const double Na = 0.07 / 60.0, Ng = 0.15 * d2r / 60.0, sba = 0.05e-3 * g0, sbg = 0.5 * d2r / 3600.0;
  nav_scene sc = nav_scene_default();
  sc.earth.model = NAV_EARTH_WGS84;
  sc.earth.origin_lat_rad = 45.0 * d2r;
  sc.earth.origin_lon_rad = 0.0;
  sc.earth.origin_h_m = 0.0;
  sc.trajectory.type = NAV_TRAJ_SEGMENTS;
  sc.trajectory.duration_s = 120.0;
  sc.trajectory.initial_attitude = (nav_euler){0.0, 0.0, 0.0};
  sc.trajectory.segments.count = 1;
  sc.trajectory.segments.v0_b_mps = nav_vec3_make(20.0, 0.0, 0.0);
  sc.trajectory.segments.items[0].kind = NAV_SEG_HOLD;
  sc.trajectory.segments.items[0].duration_s = 120.0;
  sc.imu.rate_hz = 100.0;
  sc.output.rate_hz = 10.0;
  sc.navigation.algorithm = NAV_MECH_HIGH_ORDER;
  sc.imu.model.gyro.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON;
  sc.imu.model.gyro.arw_rad_per_sqrt_s = nav_vec3_make(Ng, Ng, Ng);
  sc.imu.model.gyro.bias_turn_on_sd_rps = nav_vec3_make(sbg, sbg, sbg);
  sc.imu.model.accel.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON;
  sc.imu.model.accel.vrw_mps_per_sqrt_s = nav_vec3_make(Na, Na, Na);
  sc.imu.model.accel.bias_turn_on_sd_mps2 = nav_vec3_make(sba, sba, sba);
  sc.initial_errors.pos_sd_m = nav_vec3_make(0.02, 0.02, 0.02);
  sc.initial_errors.vel_sd_mps = nav_vec3_make(0.01, 0.01, 0.01);
  sc.initial_errors.att_sd_rad = nav_vec3_make(0.005 * d2r, 0.005 * d2r, 0.05 * d2r);
  sc.simulation.runs = 200;
  sc.simulation.seed = 66;

  /* Covariance analysis along the same truth (15 states, Van Loan, dt = 0.01 s). */
  nav_filter_config fc = nav_filter_config_default();
  fc.discretisation = NAV_FILTER_DISC_VAN_LOAN;
  fc.gyro_arw_rad_per_sqrt_s = nav_vec3_make(Ng, Ng, Ng);
  fc.accel_vrw_mps_per_sqrt_s = nav_vec3_make(Na, Na, Na);
  fc.gyro_bias_terms = 0;
  fc.accel_bias_terms = 0;
  fc.init.pos_sd_m = sc.initial_errors.pos_sd_m;
  fc.init.vel_sd_mps = sc.initial_errors.vel_sd_mps;
  fc.init.att_sd_rad = sc.initial_errors.att_sd_rad;
  fc.init.gyro_bias_sd_rps = nav_vec3_make(sbg, sbg, sbg);
  fc.init.accel_bias_sd_mps2 = nav_vec3_make(sba, sba, sba);
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&fc, &kf), NAV_OK);
  nav_truth *truth = NULL;
  assert_int_equal(nav_truth_create(&sc, &truth), NAV_OK);
  const nav_frame fr = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  const double t_check[4] = {10.0, 30.0, 60.0, 120.0};
  const double t63[4] = {0.11923, 0.73033, 3.38406, 18.0667};
  double sigma_n[4];
  int c = 0;
  for (int64_t k = 1; k <= n; ++k) {
    nav_imu_increment imu;
    nav_traj_state ts;
    assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
    assert_int_equal(nav_truth_state(truth, imu.t_s, &ts), NAV_OK);
    const nav_local_view v = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
    nav_filter_nav nv = {v.pos.lat_rad, v.pos.h_m, v.v_n_mps, nav_quat_to_dcm(v.q_b_n),
                         nav_vec3_scale(imu.dv_b_mps, 1.0 / imu.dt_s), nav_vec3_scale(imu.dtheta_b_rad, 1.0 / imu.dt_s)};
    assert_int_equal(nav_filter_predict(kf, &nv, imu.dt_s), NAV_OK);
    if (c < 4 && fabs(imu.t_s - t_check[c]) < 1e-9) {
      const double *P = nav_filter_get_cov(kf);
      sigma_n[c] = sqrt(P[0]);
      ++c;
    }
  }
  assert_int_equal(c, 4);
  nav_truth_destroy(truth);
  nav_filter_destroy(kf);
  for (int i = 0; i < 4; ++i) assert_rel_near(sigma_n[i], t63[i], 1e-3);

  /* Monte Carlo with the nonlinear simulator. */
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = 2;
  nav_sim_summary sum;
  const nav_status st = nav_sim_run(sim, &o, &sum);
  if (st != NAV_OK) fail_msg("%s", nav_sim_last_error(sim));
  size_t ne = 0;
  const nav_sim_envelope_point *env = nav_sim_envelope(sim, &ne);
  assert_non_null(env);
  int inside = 0;
  for (int i = 0; i < 4; ++i) {
    const size_t e = (size_t)llround(t_check[i] * sc.output.rate_hz);
    assert_true(e < ne);
    assert_near(env[e].t_s, t_check[i], 1e-9);
    const double ratio = env[e].pos_rms_n_m.x / sigma_n[i];
    print_message("T6.6 t = %5.0f s: MC RMS north %.5g m, covariance sigma %.5g m, ratio %.4f\n", t_check[i],
                  env[e].pos_rms_n_m.x, sigma_n[i], ratio);
    if (ratio > 0.873 && ratio < 1.130) ++inside;
  }
  nav_sim_destroy(sim);
  assert_true(inside >= 3);
}

/*
 * numerics.md T6.5: NEES of a consistent INS/GNSS filter. The filter's model equals the truth's
 * (white IMU noise, random-constant biases drawn from the filter's P0, initial errors drawn from
 * P0, white GNSS noise equal to R), so the 9-state NEES averaged over M runs satisfies
 * M nees ~ chi2(9 M); with M = 100 the 95 % region is computed below. Pass: >= 90 % of the
 * epochs inside (epochs are correlated).
 */
static void test_t65_nees_consistency(void **state) {
  (void)state;
  const double d2r = NAV_PI / 180.0, g0 = 9.80665;
  const double Na = 0.07 / 60.0, Ng = 0.15 * d2r / 60.0, sba = 0.05e-3 * g0, sbg = 0.5 * d2r / 3600.0;
  nav_scene sc = nav_scene_default();
  sc.earth.model = NAV_EARTH_WGS84;
  sc.earth.origin_lat_rad = 45.0 * d2r;
  sc.trajectory.type = NAV_TRAJ_SEGMENTS;
  sc.trajectory.duration_s = 60.0;
  sc.trajectory.initial_attitude = (nav_euler){0.0, 0.0, 0.0};
  sc.trajectory.segments.count = 2;
  sc.trajectory.segments.v0_b_mps = nav_vec3_make(20.0, 0.0, 0.0);
  sc.trajectory.segments.items[0].kind = NAV_SEG_HOLD;
  sc.trajectory.segments.items[0].duration_s = 20.0;
  sc.trajectory.segments.items[1].kind = NAV_SEG_HOLD;
  sc.trajectory.segments.items[1].duration_s = 40.0;
  sc.imu.rate_hz = 100.0;
  sc.output.rate_hz = 1.0;
  sc.navigation.algorithm = NAV_MECH_HIGH_ORDER;
  sc.navigation.scheme = NAV_SCHEME_INS_GNSS;
  sc.imu.model.gyro.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON;
  sc.imu.model.gyro.arw_rad_per_sqrt_s = nav_vec3_make(Ng, Ng, Ng);
  sc.imu.model.gyro.bias_turn_on_sd_rps = nav_vec3_make(sbg, sbg, sbg);
  sc.imu.model.accel.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON;
  sc.imu.model.accel.vrw_mps_per_sqrt_s = nav_vec3_make(Na, Na, Na);
  sc.imu.model.accel.bias_turn_on_sd_mps2 = nav_vec3_make(sba, sba, sba);
  sc.initial_errors.pos_sd_m = nav_vec3_make(1.0, 1.0, 2.0);
  sc.initial_errors.vel_sd_mps = nav_vec3_make(0.1, 0.1, 0.1);
  sc.initial_errors.att_sd_rad = nav_vec3_make(0.05 * d2r, 0.05 * d2r, 0.5 * d2r);
  sc.gnss.enabled = true;
  sc.gnss.model.terms = NAV_GNSS_TERM_POS_WHITE | NAV_GNSS_TERM_VEL_WHITE;
  sc.gnss.model.update_rate_hz = 1.0;
  sc.gnss.model.pos_white_sd_m = nav_vec3_make(1.0, 1.0, 2.0);
  sc.gnss.model.vel_sd_mps = nav_vec3_make(0.05, 0.05, 0.1);
  sc.simulation.runs = 100;
  sc.simulation.seed = 65;
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.threads = 2;
  nav_sim_summary sum;
  if (nav_sim_run(sim, &o, &sum) != NAV_OK) fail_msg("%s", nav_sim_last_error(sim));
  size_t ne = 0;
  const nav_sim_envelope_point *env = nav_sim_envelope(sim, &ne);
  assert_non_null(env);
  const double k = 9.0 * 100.0;
  const double lo = 9.0 * chi2_over_k(k, -1.96), hi = 9.0 * chi2_over_k(k, 1.96);
  size_t inside = 0;
  double mean_all = 0.0;
  for (size_t e = 0; e < ne; ++e) {
    if (env[e].nees9_mean > lo && env[e].nees9_mean < hi) ++inside;
    mean_all += env[e].nees9_mean;
  }
  print_message("T6.5 NEES (9 states, 100 runs): time-average %.3f, %zu of %zu epochs in [%.3f, %.3f]\n",
                mean_all / (double)ne, inside, ne, lo, hi);
  nav_sim_destroy(sim);
  assert_true((double)inside >= 0.9 * (double)ne);
}

/* Errors of run 0 at its output epochs (record callback). */
typedef struct {
  double h[256];
  int n;
} out_errors;

static nav_callback_result keep_h(void *user, const nav_sim_record *r) {
  out_errors *o = user;
  if (r->run == 0 && o->n < 256) o->h[o->n++] = r->err->pos_err_h_m;
  return NAV_CONTINUE;
}

/*
 * nav_sim_options.stats_stride_min (navstudio's live preview passes its output stride): the
 * statistics are taken at every N-th IMU epoch only, and are then exactly the statistics of the
 * errors the record callback sees at the output epochs; the final errors and the envelope do
 * not change. The run with statistics at every IMU epoch differs (it sees the epochs between).
 */
static void test_stats_stride_min(void **state) {
  (void)state;
  nav_scene sc = nav_scene_default();
  sc.trajectory.duration_s = 30.0;
  sc.imu.rate_hz = 100.0;
  sc.output.rate_hz = 2.0;
  sc.simulation.runs = 1;
  sc.imu.model.accel.terms = NAV_IMU_TERM_NOISE;
  sc.imu.model.accel.vrw_mps_per_sqrt_s = nav_vec3_make(2e-3, 2e-3, 2e-3);
  sc.initial_errors.vel_sd_mps = nav_vec3_make(0.05, 0.05, 0.05);
  nav_sim_summary sum[2];
  out_errors rec[2];
  const nav_sim_envelope_point *env[2];
  size_t ne[2];
  nav_sim *sim[2];
  for (int i = 0; i < 2; ++i) {
    memset(&rec[i], 0, sizeof rec[i]);
    assert_int_equal(nav_sim_create(&sc, &sim[i]), NAV_OK);
    nav_sim_options o = nav_sim_options_default();
    o.record = keep_h;
    o.user = &rec[i];
    o.stats_stride_min = i == 0 ? 0 : 50;
    if (nav_sim_run(sim[i], &o, &sum[i]) != NAV_OK) fail_msg("%s", nav_sim_last_error(sim[i]));
    env[i] = nav_sim_envelope(sim[i], &ne[i]);
  }
  assert_int_equal(sum[0].stats_stride, 1);
  assert_int_equal(sum[0].stats_epochs, 3001);
  assert_int_equal(sum[1].stats_stride, 50);
  assert_int_equal(sum[1].stats_epochs, 61);
  assert_int_equal(rec[1].n, 61);
  assert_memory_equal(rec[0].h, rec[1].h, sizeof rec[0].h);
  assert_memory_equal(&sum[0].final, &sum[1].final, sizeof sum[0].final);
  assert_int_equal(ne[0], ne[1]);
  assert_memory_equal(env[0], env[1], ne[0] * sizeof *env[0]);
  double ss = 0.0, mx = 0.0;
  for (int e = 0; e < rec[1].n; ++e) {
    ss += rec[1].h[e] * rec[1].h[e];
    if (rec[1].h[e] > mx) mx = rec[1].h[e];
  }
  assert_true(mx > 1e-3);
  assert_true(sum[1].stats.pos_err_h_m.max == mx);
  assert_true(fabs(sum[1].stats.pos_err_h_m.rms - sqrt(ss / rec[1].n)) <= 1e-12 * mx);
  assert_true(sum[0].stats.pos_err_h_m.rms != sum[1].stats.pos_err_h_m.rms);
  for (int i = 0; i < 2; ++i) nav_sim_destroy(sim[i]);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_deterministic_across_threads),
      cmocka_unit_test(test_mc_accel_noise),
      cmocka_unit_test(test_mc_gyro_noise),
      cmocka_unit_test(test_mc_initial_errors),
      cmocka_unit_test(test_ideal_ignores_errors),
      cmocka_unit_test(test_t66_monte_carlo_vs_covariance),
      cmocka_unit_test(test_t65_nees_consistency),
      cmocka_unit_test(test_stats_stride_min),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
