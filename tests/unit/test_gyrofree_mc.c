/*
 * The gyro-free INS as a simulated navigation scheme (issue 4 item 5, "Done when"): Monte Carlo
 * runs of nav_sim with the scheme gyro_free against the corrected closed forms of numerics.md 1.5
 * (E1.25-E1.28 with the array's geometry factors), closure with ideal sensors for every layout,
 * the array error model, and determinism.
 *
 * Monte Carlo set-up: a level body at rest on the flat Earth (yaw 0: body x = north, y = east),
 * 100 Hz, 10 s, N = 200 seeded runs, one error source at a time, small enough that the attitude
 * error stays below 0.03 rad per axis (E1.27 is a small-angle result). The statistic is the RMS over runs
 * of each N/E/D position-error component at t = 10 s (nav_sim_envelope); for zero-mean Gaussian
 * errors N s^2 / sigma^2 ~ chi2(N), so RMS / sigma lies in [0.873, 1.130] with 99 % probability
 * (numerics.md T6.6, N = 200).
 *
 * Which components E1.28 describes: a tilt about body y (from the omega_dot_y error) misplaces
 * gravity into the north channel, a tilt about x into the east channel; those are the per-axis
 * sigma_r of E1.28 (its f part kappa_f ... is included but 1000 times smaller here). The down
 * channel has no first-order gravity coupling: its error is the f part plus the second-order
 * tilt term g (1 - cos alpha) ~ g (alpha_x^2 + alpha_y^2) / 2, which is positive in every run
 * (not zero mean), so it is tested through its mean: E[dr_D] = g/2 int int E[alpha_x^2 + alpha_y^2].
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
#include "navcore/nav_array.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_sim.h"

#define MC_RUNS 200
#define T_END_S 10.0
#define ARM_M 0.1
/* T6.6, N = 200, 99 %: RMS / sigma in [0.873, 1.130]. */
#define BAND_LO 0.873
#define BAND_HI 1.130

/* ------------------------------------------------------------------ helpers */

/* Level body at rest, flat Earth, the gyro-free scheme with an ideal cube array. */
static nav_scene rest_scene(nav_array_layout_kind layout) {
  nav_scene sc = nav_scene_default();
  sc.trajectory.type = NAV_TRAJ_TEST_MOTION;
  sc.trajectory.test_motion.kind = NAV_TEST_MOTION_STATIONARY;
  sc.trajectory.duration_s = T_END_S;
  sc.imu.rate_hz = 100.0;
  sc.output.rate_hz = 10.0;
  sc.navigation.scheme = NAV_SCHEME_GYRO_FREE;
  sc.navigation.algorithm = NAV_MECH_HIGH_ORDER;
  sc.array.layout = layout;
  sc.array.radius_m = ARM_M;
  sc.simulation.seed = 20261122;
  sc.simulation.runs = MC_RUNS;
  return sc;
}

/* The T3.1 trajectory (rotating at up to 0.36 rad/s, accelerating), 20 s, high-order strapdown. */
static nav_scene rotating_scene(nav_array_layout_kind layout) {
  nav_scene sc = nav_scene_default();
  sc.trajectory.duration_s = 20.0;
  sc.imu.rate_hz = 100.0;
  sc.navigation.scheme = NAV_SCHEME_GYRO_FREE;
  sc.navigation.algorithm = NAV_MECH_HIGH_ORDER;
  sc.array.layout = layout;
  sc.array.radius_m = ARM_M;
  return sc;
}

/* A six-sensor custom layout that is not of the [CLD] type (axes tilted off the face
 * diagonals): H^+ does not annihilate c(omega) and the rate is implicit. */
static void skew_custom(nav_scene_array *a) {
  nav_accel_array cube;
  assert_int_equal(nav_array_cube_layout(ARM_M, &cube), NAV_OK);
  static const double tilt[6][3] = {{0.3, 0.1, 0.0},  {-0.2, 0.0, 0.1}, {0.0, 0.25, -0.1},
                                    {0.1, -0.3, 0.0}, {0.0, 0.1, 0.2},  {-0.1, 0.0, -0.3}};
  a->layout = NAV_ARRAY_LAYOUT_CUSTOM;
  a->custom_count = 6;
  for (int i = 0; i < 6; ++i) {
    a->custom[i].r_bs_b_m = cube.r_bs_b_m[i];
    /* Not normalised: the scene accepts any non-zero axis. */
    a->custom[i].n_s_b = nav_vec3_add(cube.n_s_b[i], nav_vec3_make(tilt[i][0], tilt[i][1], tilt[i][2]));
  }
}

typedef struct mc_result {
  nav_sim_envelope_point last; /* the envelope at t = T_END_S */
  nav_sim_summary sum;
} mc_result;

static mc_result run_mc(const nav_scene *sc, bool ideal) {
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.ideal = ideal;
  o.threads = 4;
  mc_result r;
  memset(&r, 0, sizeof r);
  const nav_status st = nav_sim_run(sim, &o, &r.sum);
  if (st != NAV_OK) fail_msg("nav_sim_run: %s: %s", nav_status_str(st), nav_sim_last_error(sim));
  size_t ne = 0;
  const nav_sim_envelope_point *env = nav_sim_envelope(sim, &ne);
  assert_non_null(env);
  assert_true(ne > 0);
  r.last = env[ne - 1];
  assert_near(r.last.t_s, sc->trajectory.duration_s, 1e-9);
  nav_sim_destroy(sim);
  return r;
}

static nav_array_geometry scene_geometry(const nav_scene *sc) {
  nav_accel_array a;
  nav_array_geometry g;
  assert_int_equal(nav_array_layout_from_scene(&sc->array, &a), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&a, &g), NAV_OK);
  return g;
}

/* Down channel: the sample mean must match the second-order prediction within 3.29 standard
 * errors (99.9 %) of the mean, the standard error estimated from the runs themselves. */
static void check_down_mean(const mc_result *r, double predicted_m, const char *what) {
  const double rms = r->last.pos_rms_n_m.z, mean = r->last.pos_mean_n_m.z;
  const double var = fmax(rms * rms - mean * mean, 0.0) * MC_RUNS / (MC_RUNS - 1.0);
  const double se = sqrt(var / MC_RUNS);
  print_message(
      "%s: down mean %.5g m vs second-order prediction %.5g m (ratio %.4f, standard error %.3g m)\n", what,
      mean, predicted_m, mean / predicted_m, se);
  assert_near(mean, predicted_m, 3.29 * se);
}

static void check_band(double ratio, const char *what) {
  if (!(ratio >= BAND_LO && ratio <= BAND_HI))
    fail_msg("%s: MC RMS / analytic sigma = %.4f outside the T6.6 99 %% band [%.3f, %.3f]", what, ratio,
             BAND_LO, BAND_HI);
}

/* ------------------------------------------------------------------ E1.28, noise */

/*
 * White noise only, density N = 1e-4 m/s/sqrt(s) (10.2 ug/sqrt(Hz)) on every sensor, for each
 * built-in layout. E1.28: sigma_r^2 = kappa_f^2 N^2 t^3/3 + (g kappa N / r)^2 t^7 / 252 with
 * kappa, r = r_ref from the layout's H (nav_analytic_gyrofree_spec_from_geometry). Down: the
 * attitude variance per axis is (kappa N / r)^2 t^3 / 3 (E1.26), so
 * E[dr_D] = g (kappa N / r)^2 t^5 / 60.
 */
static void test_noise_vs_e128(void **state) {
  (void)state;
  static const nav_array_layout_kind layouts[3] = {NAV_ARRAY_LAYOUT_CUBE6, NAV_ARRAY_LAYOUT_NINE,
                                                   NAV_ARRAY_LAYOUT_TWELVE};
  const double n_density = 1e-4, g = NAV_G0_MPS2, t = T_END_S;
  for (int l = 0; l < 3; ++l) {
    nav_scene sc = rest_scene(layouts[l]);
    sc.array.accel.terms = NAV_IMU_TERM_NOISE;
    sc.array.accel.vrw_mps_per_sqrt_s = n_density;
    nav_test_print_seed(nav_array_layout_kind_name(layouts[l]), sc.simulation.seed);
    const mc_result r = run_mc(&sc, false);
    const nav_array_geometry geo = scene_geometry(&sc);
    nav_analytic_gyrofree_spec sp;
    assert_int_equal(nav_analytic_gyrofree_spec_from_geometry(&geo, g, 0.0, n_density, &sp), NAV_OK);
    nav_analytic_gyrofree_errors e;
    assert_int_equal(nav_analytic_gyrofree_eval(&sp, t, &e), NAV_OK);
    const double rn = r.last.pos_rms_n_m.x / e.pos_sd_m, re = r.last.pos_rms_n_m.y / e.pos_sd_m;
    print_message("%-6s (N=%d, kappa %.4f, kappa_f %.4f, r_ref %.4f m): RMS N %.4f E %.4f m vs E1.28 %.4f m: "
                  "ratios %.4f %.4f; attitude RMS %.4g rad\n",
                  nav_array_layout_kind_name(layouts[l]), geo.n_sensors, sp.kappa_w, sp.kappa_f, sp.r_m,
                  r.last.pos_rms_n_m.x, r.last.pos_rms_n_m.y, e.pos_sd_m, rn, re, r.last.att_rms_rad);
    check_band(rn, "north");
    check_band(re, "east");
    const double kw = sp.kappa_w * n_density / sp.r_m;
    check_down_mean(&r, g * kw * kw * pow(t, 5) / 60.0, nav_array_layout_kind_name(layouts[l]));
    /* Small angles held (E1.27's domain): the three-axis angle is sqrt 3 times the per-axis tilt. */
    assert_true(r.last.att_rms_rad < 0.05);
  }
}

/* ------------------------------------------------------------------ E1.28, bias */

/*
 * Turn-on bias only, sd s = 5 ug, independent per sensor: the f and omega_dot biases H^+ b are
 * zero-mean Gaussian with sd kappa_f s and kappa s / r per axis and, for the cube (H^+ H^+T
 * block diagonal, numerics.md 1.5 (c)), independent, so the per-axis position sigma is the RSS of
 * E1.28's two bias terms, kappa_f s t^2 / 2 and g kappa s t^4 / (24 r). Down:
 * E[alpha_x^2 + alpha_y^2] = 2 (kappa s / (2 r))^2 t^4, E[dr_D] = g (kappa s / (2r))^2 t^6 / 30.
 */
static void test_bias_vs_e128(void **state) {
  (void)state;
  const double s = nav_unit_ug_to_mps2(5.0), g = NAV_G0_MPS2, t = T_END_S;
  nav_scene sc = rest_scene(NAV_ARRAY_LAYOUT_CUBE6);
  sc.array.accel.terms = NAV_IMU_TERM_BIAS_TURN_ON;
  sc.array.accel.bias_turn_on_sd_mps2 = s;
  nav_test_print_seed("bias", sc.simulation.seed);
  const mc_result r = run_mc(&sc, false);
  const nav_array_geometry geo = scene_geometry(&sc);
  nav_analytic_gyrofree_spec sp;
  assert_int_equal(nav_analytic_gyrofree_spec_from_geometry(&geo, g, s, 0.0, &sp), NAV_OK);
  /* The two terms of E1.28's bias column separately (kappa 0 removes one). */
  nav_analytic_gyrofree_spec sp_f = sp, sp_w = sp;
  sp_f.kappa_w = 0.0;
  sp_w.kappa_f = 0.0;
  nav_analytic_gyrofree_errors ef, ew;
  assert_int_equal(nav_analytic_gyrofree_eval(&sp_f, t, &ef), NAV_OK);
  assert_int_equal(nav_analytic_gyrofree_eval(&sp_w, t, &ew), NAV_OK);
  const double sigma = hypot(ef.pos_bias_m, ew.pos_bias_m);
  const double rn = r.last.pos_rms_n_m.x / sigma, re = r.last.pos_rms_n_m.y / sigma;
  print_message("bias: RMS N %.4f E %.4f m vs E1.28 (RSS of %.4g and %.4g) %.4f m: ratios %.4f %.4f; "
                "attitude RMS %.4g rad\n",
                r.last.pos_rms_n_m.x, r.last.pos_rms_n_m.y, ef.pos_bias_m, ew.pos_bias_m, sigma, rn, re,
                r.last.att_rms_rad);
  check_band(rn, "north");
  check_band(re, "east");
  const double a = sp.kappa_w * s / (2.0 * sp.r_m);
  check_down_mean(&r, g * a * a * pow(t, 6) / 30.0, "bias");
  assert_true(r.last.att_rms_rad < 0.05);
}

/* ------------------------------------------------------------------ initial rate error */

/*
 * Initial angular-rate error only, sd w0 = 1e-4 rad/s per body axis: the array cannot observe
 * omega, so the error persists like a gyro bias: tilt w0 t, horizontal position g w0 t^3 / 6
 * per axis (E1.14 with b_g = w0), not a term of E1.28. The scene's figure reaches the same value
 * through nav_analytic_estimate (the gyro-free preliminary estimate).
 */
static void test_initial_rate_error(void **state) {
  (void)state;
  const double w0 = 1e-4, g = NAV_G0_MPS2, t = T_END_S;
  nav_scene sc = rest_scene(NAV_ARRAY_LAYOUT_CUBE6);
  sc.array.initial_rate_sd_rps = nav_vec3_make(w0, w0, w0);
  nav_test_print_seed("initial rate", sc.simulation.seed);
  const mc_result r = run_mc(&sc, false);
  nav_analytic_estimate_config cfg = nav_analytic_estimate_config_default();
  cfg.imu.g_mps2 = g;
  cfg.with_gyrofree = true;
  assert_int_equal(nav_array_cube_layout(ARM_M, &cfg.array), NAV_OK);
  cfg.array_init_rate_sd_rps = w0;
  nav_analytic_estimate_point p;
  assert_int_equal(nav_analytic_estimate(&cfg, &t, 1, &p), NAV_OK);
  assert_rel_near(p.gyrofree.pos_sd_m, g * w0 * t * t * t / 6.0, 1e-12);
  const double rn = r.last.pos_rms_n_m.x / p.gyrofree.pos_sd_m,
               re = r.last.pos_rms_n_m.y / p.gyrofree.pos_sd_m;
  print_message("initial rate: RMS N %.5f E %.5f m vs g w0 t^3/6 = %.5f m: ratios %.4f %.4f\n",
                r.last.pos_rms_n_m.x, r.last.pos_rms_n_m.y, p.gyrofree.pos_sd_m, rn, re);
  check_band(rn, "north");
  check_band(re, "east");
  /* Down: second order only, E[dr_D] = g/2 int int 2 w0^2 u^2 = g w0^2 t^4 / 12. */
  check_down_mean(&r, g * w0 * w0 * pow(t, 4) / 12.0, "initial rate");
}

/* ------------------------------------------------------------------ closure */

/*
 * Ideal array (nav_sim_options.ideal) on the rotating T3.1 trajectory, 20 s at 100 Hz, through
 * nav_sim: every layout closes to the level of the gyro-free mechanization alone (test_gyrofree:
 * cube 2.4e-7 rad, 2.6e-5 m/s, 2.7e-4 m; general layouts up to 4 times that). Also WGS-84.
 */
static void test_closure_every_layout(void **state) {
  (void)state;
  static const nav_array_layout_kind layouts[4] = {NAV_ARRAY_LAYOUT_CUBE6, NAV_ARRAY_LAYOUT_NINE,
                                                   NAV_ARRAY_LAYOUT_TWELVE, NAV_ARRAY_LAYOUT_CUSTOM};
  for (int l = 0; l < 5; ++l) {
    nav_scene sc = rotating_scene(l < 4 ? layouts[l] : NAV_ARRAY_LAYOUT_CUBE6);
    if (l == 3) skew_custom(&sc.array);
    if (l == 4) sc.earth.model = NAV_EARTH_WGS84;
    /* The errors of ideal runs are ignored: a noisy configuration must not leak in. */
    sc.array.accel.terms = NAV_IMU_TERM_NOISE;
    sc.array.accel.vrw_mps_per_sqrt_s = 1.0;
    sc.array.initial_rate_sd_rps = nav_vec3_make(1.0, 1.0, 1.0);
    const mc_result r = run_mc(&sc, true);
    const nav_epoch_errors *e = &r.sum.final;
    print_message("closure %-6s%s: att %.3e rad, vel %.3e m/s, pos %.3e m\n",
                  nav_array_layout_kind_name(sc.array.layout), l == 4 ? " (WGS-84)" : "", e->att_err_rad,
                  e->vel_err_mps, nav_vec3_norm(e->pos_err_n_m));
    assert_int_equal(r.sum.runs, 1);
    assert_true(e->att_err_rad < 1e-6);
    assert_true(e->vel_err_mps < 1e-4);
    assert_true(nav_vec3_norm(e->pos_err_n_m) < 2e-3);
  }
}

/* ------------------------------------------------------------------ determinism */

/* The same scene and seed give bit-identical results whatever the thread count, and a run whose
 * ideal increments come from the job's shared table equals the same run sampling its own. */
static void test_determinism(void **state) {
  (void)state;
  nav_scene sc = rest_scene(NAV_ARRAY_LAYOUT_NINE);
  sc.trajectory.duration_s = 2.0;
  sc.array.accel.terms = NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_SCALE_FACTOR;
  sc.array.accel.vrw_mps_per_sqrt_s = 1e-3;
  sc.array.accel.bias_gm_sd_mps2 = 1e-3;
  sc.array.accel.bias_gm_tau_s = 50.0;
  sc.array.accel.scale_factor_sd = 1e-3;
  sc.array.initial_rate_sd_rps = nav_vec3_make(1e-3, 1e-3, 1e-3);
  sc.simulation.runs = 5;
  nav_epoch_errors fin[2][5];
  for (int pass = 0; pass < 2; ++pass) {
    nav_sim *sim = NULL;
    assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
    nav_sim_options o = nav_sim_options_default();
    o.threads = pass == 0 ? 1 : 5;
    nav_sim_summary sum;
    assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_OK);
    size_t nf = 0;
    const nav_sim_run_final *f = nav_sim_finals(sim, &nf);
    assert_int_equal(nf, 5);
    for (int i = 0; i < 5; ++i)
      fin[pass][i] = f[i].err;
    nav_sim_destroy(sim);
  }
  assert_memory_equal(fin[0], fin[1], sizeof fin[0]);
  /* runs = 1: no shared table; run 0 must be the same bits. */
  sc.simulation.runs = 1;
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  nav_sim_summary sum;
  assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_OK);
  assert_memory_equal(&sum.final, &fin[0][0], sizeof sum.final);
  nav_sim_destroy(sim);
}

/* ------------------------------------------------------------------ array error model */

/*
 * Streams and statistics of nav_array_model: per-run constants are the first draws of the
 * documented streams (ACCEL kinds, channel = sensor index) and do not change when another term
 * is switched on; white noise has sd N sqrt(dt) per sample at any rate (chi-square check, 16
 * sensors x 2000 samples, 99.9 % band of the sample sd: [0.9870, 1.0130]).
 */
static void test_array_model(void **state) {
  (void)state;
  const uint64_t seed = 77, run = 3;
  nav_array_error_config cfg = nav_array_error_config_default();
  cfg.terms = NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_SCALE_FACTOR;
  cfg.bias_turn_on_sd_mps2 = 2e-3;
  cfg.scale_factor_sd = 1e-4;
  nav_array_model *m = NULL, *m2 = NULL;
  assert_int_equal(nav_array_model_create(&cfg, 16, seed, run, &m), NAV_OK);
  nav_array_error_config cfg2 = cfg;
  cfg2.terms |= NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_GM;
  cfg2.vrw_mps_per_sqrt_s = 0.01;
  cfg2.bias_gm_sd_mps2 = 1e-3;
  cfg2.bias_gm_tau_s = 10.0;
  assert_int_equal(nav_array_model_create(&cfg2, 16, seed, run, &m2), NAV_OK);
  for (int i = 0; i < 16; ++i) {
    nav_rng rb, rs;
    nav_rng_init(&rb, seed, run, nav_rng_stream_id(NAV_RNG_STREAM_ACCEL_BIAS_TURN_ON, (unsigned)i));
    nav_rng_init(&rs, seed, run, nav_rng_stream_id(NAV_RNG_STREAM_ACCEL_SCALE_FACTOR, (unsigned)i));
    assert_near(nav_array_model_bias_turn_on(m, i), 2e-3 * nav_rng_gauss(&rb), 0.0);
    assert_near(nav_array_model_scale_factor(m, i), 1e-4 * nav_rng_gauss(&rs), 0.0);
    assert_near(nav_array_model_bias_turn_on(m2, i), nav_array_model_bias_turn_on(m, i), 0.0);
    assert_near(nav_array_model_scale_factor(m2, i), nav_array_model_scale_factor(m, i), 0.0);
  }
  /* Deterministic part: (1 + s) dA + b0 dt. */
  nav_array_increment in, out;
  memset(&in, 0, sizeof in);
  in.k = 1;
  in.t_s = 0.01;
  in.dt_s = 0.01;
  in.n_sensors = 16;
  for (int i = 0; i < 16; ++i)
    in.dv_mps[i] = 0.1 * (i + 1);
  assert_int_equal(nav_array_model_apply(m, &in, &out), NAV_OK);
  for (int i = 0; i < 16; ++i)
    assert_near(out.dv_mps[i],
                in.dv_mps[i] + nav_array_model_scale_factor(m, i) * in.dv_mps[i] +
                    nav_array_model_bias_turn_on(m, i) * 0.01,
                1e-15);
  /* Errors: sensor-count mismatch, bad dt, non-finite input; output untouched. */
  nav_array_increment keep = out;
  in.n_sensors = 6;
  assert_int_equal(nav_array_model_apply(m, &in, &out), NAV_ERR_INVALID_ARG);
  in.n_sensors = 16;
  in.dt_s = 0.0;
  assert_int_equal(nav_array_model_apply(m, &in, &out), NAV_ERR_INVALID_ARG);
  in.dt_s = 0.01;
  in.dv_mps[3] = NAN;
  assert_int_equal(nav_array_model_apply(m, &in, &out), NAV_ERR_NUMERIC);
  assert_memory_equal(&keep, &out, sizeof out);
  nav_array_model_destroy(m);
  nav_array_model_destroy(m2);
  nav_array_model_destroy(NULL);

  /* White noise: sample sd N sqrt(dt) at 100 Hz and at 1 kHz. */
  for (int rate = 0; rate < 2; ++rate) {
    const double dt = rate == 0 ? 0.01 : 0.001, n_density = 3e-3;
    nav_array_error_config cn = nav_array_error_config_default();
    cn.terms = NAV_IMU_TERM_NOISE;
    cn.vrw_mps_per_sqrt_s = n_density;
    assert_int_equal(nav_array_model_create(&cn, 16, seed, run, &m), NAV_OK);
    memset(&in, 0, sizeof in);
    in.n_sensors = 16;
    in.dt_s = dt;
    double s2 = 0.0;
    const int samples = 2000;
    for (int k = 1; k <= samples; ++k) {
      in.k = k;
      in.t_s = k * dt;
      assert_int_equal(nav_array_model_apply(m, &in, &out), NAV_OK);
      for (int i = 0; i < 16; ++i)
        s2 += out.dv_mps[i] * out.dv_mps[i];
    }
    const double ratio = sqrt(s2 / (16.0 * samples)) / (n_density * sqrt(dt));
    print_message("array noise at dt = %g s: sample sd / (N sqrt(dt)) = %.4f\n", dt, ratio);
    assert_near(ratio, 1.0, 0.013);
    nav_array_model_destroy(m);
  }

  /* Validation. */
  nav_array_error_config bad = nav_array_error_config_default();
  bad.terms = NAV_IMU_TERM_BIAS_GM;
  bad.bias_gm_tau_s = 0.0;
  assert_int_equal(nav_array_error_config_validate(&bad, NULL, NULL), NAV_ERR_INVALID_ARG);
  bad.terms = NAV_IMU_TERM_MISALIGNMENT;
  assert_int_equal(nav_array_error_config_validate(&bad, NULL, NULL), NAV_ERR_INVALID_ARG);
  bad.terms = NAV_IMU_TERM_NOISE;
  bad.vrw_mps_per_sqrt_s = -1.0;
  assert_int_equal(nav_array_error_config_validate(&bad, NULL, NULL), NAV_ERR_INVALID_ARG);
  bad.terms = 0; /* a disabled term's fields are ignored */
  assert_int_equal(nav_array_error_config_validate(&bad, NULL, NULL), NAV_OK);
}

/* ------------------------------------------------------------------ layouts and scene checks */

/* The geometry factors documented in nav_array.h, and nav_scene_validate on the array section. */
static void test_layouts_and_validation(void **state) {
  (void)state;
  nav_accel_array a;
  nav_array_geometry g;
  assert_int_equal(nav_array_nine_layout(ARM_M, &a), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&a, &g), NAV_OK);
  for (int j = 0; j < 3; ++j) {
    /* (H^T H)^-1: 5/9 for f, 5/(6 r^2) for omega_dot; r_ref = r sqrt(2/3). */
    assert_near(g.cov[j][j], 5.0 / 9.0, 1e-12);
    assert_rel_near(g.cov[3 + j][3 + j], 5.0 / (6.0 * ARM_M * ARM_M), 1e-12);
    assert_near(g.kappa_f[j], sqrt(5.0) / 3.0, 1e-12);
    assert_near(g.kappa_w[j], sqrt(5.0) / 3.0, 1e-12);
  }
  assert_rel_near(g.r_ref_m, ARM_M * sqrt(2.0 / 3.0), 1e-14);
  print_message("nine: cond %.4g, kappa %.6f (r_ref), sqrt(5/6) = %.6f (r)\n", g.cond, g.kappa_w[0],
                sqrt(5.0 / 6.0));
  assert_int_equal(nav_array_twelve_layout(ARM_M, &a), NAV_OK);
  assert_int_equal(nav_array_geometry_compute(&a, &g), NAV_OK);
  nav_accel_array cube;
  assert_int_equal(nav_array_cube_layout(ARM_M, &cube), NAV_OK);
  assert_memory_equal(a.n_s_b, cube.n_s_b, 6 * sizeof(nav_vec3));
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      assert_near(g.cov[i][j], i != j ? 0.0 : (i < 3 ? 0.25 : 0.25 / (ARM_M * ARM_M)), 1e-12);
  assert_near(g.kappa_w[1], 0.5, 1e-12);
  assert_near(g.kappa_f[2], 0.5, 1e-12);
  /* Twelve: the omega_dot rows of H^+ annihilate c(omega) for any omega. */
  double c[NAV_ARRAY_MAX_SENSORS];
  nav_array_centripetal(&a, nav_vec3_make(0.7, -1.3, 2.1), c);
  for (int row = 3; row < 6; ++row) {
    double acc = 0.0;
    for (int i = 0; i < 12; ++i)
      acc += g.h_pinv[row][i] * c[i];
    assert_near(acc, 0.0, 1e-12);
  }
  assert_int_equal(nav_array_nine_layout(-1.0, &a), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_array_twelve_layout(NAN, &a), NAV_ERR_INVALID_ARG);

  nav_scene sc = rotating_scene(NAV_ARRAY_LAYOUT_CUSTOM);
  sc.array.custom_count = 5;
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  skew_custom(&sc.array);
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_OK);
  /* Every axis along its lever arm: H singular. */
  for (int i = 0; i < 6; ++i)
    sc.array.custom[i].n_s_b = sc.array.custom[i].r_bs_b_m;
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  sc.array.custom[0].n_s_b = nav_vec3_zero();
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  sc = rotating_scene(NAV_ARRAY_LAYOUT_CUBE6);
  sc.navigation.aid_vertical = true;
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  sc = rotating_scene(NAV_ARRAY_LAYOUT_CUBE6);
  sc.array.radius_m = 0.0;
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  sc = rotating_scene(NAV_ARRAY_LAYOUT_CUBE6);
  sc.array.initial_rate_sd_rps.y = -1.0;
  assert_int_equal(nav_scene_validate(&sc, NULL, NULL), NAV_ERR_INVALID_ARG);
  assert_string_equal(nav_nav_scheme_name(NAV_SCHEME_GYRO_FREE), "gyro_free");
  assert_string_equal(nav_array_layout_kind_name(NAV_ARRAY_LAYOUT_TWELVE), "twelve");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_layouts_and_validation), cmocka_unit_test(test_array_model),
      cmocka_unit_test(test_closure_every_layout),   cmocka_unit_test(test_determinism),
      cmocka_unit_test(test_noise_vs_e128),          cmocka_unit_test(test_bias_vs_e128),
      cmocka_unit_test(test_initial_rate_error),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
