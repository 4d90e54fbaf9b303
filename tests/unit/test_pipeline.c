/*
 * Pipeline closure tests: parametric trajectory -> exact ideal increments -> strapdown in the
 * flat frame, against numerics.md T3.1 (table of section 3.3), plus unit checks of the
 * trajectory derivatives, the Gauss-Legendre rule and the statistics accumulator.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_ins.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"

typedef struct closure {
  double att_rad, vel_mps, pos_m;
} closure;

/* Run the T3.1 scene (the scene default) at @p rate_hz with @p alg; errors at T = 20 s. */
static closure run_t31(double rate_hz, nav_mech_algorithm alg) {
  nav_scene sc = nav_scene_default();
  sc.imu.rate_hz = rate_hz;
  sc.navigation.algorithm = alg;
  nav_truth *truth = NULL;
  nav_ins *ins = NULL;
  assert_int_equal(nav_truth_create(&sc, &truth), NAV_OK);
  nav_traj_state ts;
  assert_int_equal(nav_truth_state(truth, 0.0, &ts), NAV_OK);
  nav_ins_config cfg = nav_ins_config_default();
  cfg.algorithm = alg;
  nav_ins_state s0 = {0.0, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f};
  assert_int_equal(nav_ins_create(&cfg, &s0, &ins), NAV_OK);
  const int64_t n = nav_truth_sample_count(truth);
  assert_int_equal(n, (int64_t)llround(20.0 * rate_hz));
  for (int64_t k = 1; k <= n; ++k) {
    nav_imu_increment imu;
    assert_int_equal(nav_truth_imu(truth, k, &imu), NAV_OK);
    assert_int_equal(nav_ins_step(ins, &imu), NAV_OK);
  }
  assert_int_equal(nav_truth_state(truth, 20.0, &ts), NAV_OK);
  const nav_frame fr = nav_truth_frame(truth);
  const nav_epoch_errors e = nav_errors_compute(&fr, &ts, nav_ins_get_state(ins));
  nav_ins_destroy(ins);
  nav_truth_destroy(truth);
  closure c = {e.att_err_rad, e.vel_err_mps, nav_vec3_norm(e.pos_err_n_m)};
  return c;
}

/* numerics.md T3.1, column (a): dt = 0.04, 0.02, 0.01, 0.005 s. */
static const double k_a_att[4] = {1.370e-05, 3.428e-06, 8.573e-07, 2.143e-07};
static const double k_a_vel[4] = {2.078e-03, 5.200e-04, 1.300e-04, 3.251e-05};
static const double k_a_pos[4] = {2.350e-02, 5.879e-03, 1.470e-03, 3.675e-04};
static const double k_b_att[4] = {1.127e-06, 1.407e-07, 1.757e-08, 2.194e-09};
static const double k_b_vel[4] = {6.768e-05, 8.494e-06, 1.068e-06, 1.340e-07};
static const double k_b_pos[4] = {1.017e-03, 1.258e-04, 1.567e-05, 1.957e-06};
static const double k_rates[4] = {25.0, 50.0, 100.0, 200.0};

/* First-order algorithm (a) reproduces the T3.1 table to 2 significant digits (5 %) and shows
 * second-order convergence (ratio 4 +/- 0.4 per halving of dt). */
static void test_t31_first_order(void **state) {
  (void)state;
  closure c[4];
  for (int i = 0; i < 4; ++i) {
    c[i] = run_t31(k_rates[i], NAV_MECH_FIRST_ORDER);
    print_message("(a) dt=%.3f att=%.4e vel=%.4e pos=%.4e\n", 1.0 / k_rates[i], c[i].att_rad, c[i].vel_mps,
                  c[i].pos_m);
    assert_rel_near(c[i].att_rad, k_a_att[i], 0.05);
    assert_rel_near(c[i].vel_mps, k_a_vel[i], 0.05);
    assert_rel_near(c[i].pos_m, k_a_pos[i], 0.05);
  }
  for (int i = 0; i < 3; ++i) {
    assert_near(c[i].att_rad / c[i + 1].att_rad, 4.0, 0.4);
    assert_near(c[i].vel_mps / c[i + 1].vel_mps, 4.0, 0.4);
  }
}

/* Algorithm (b): table to 2 significant digits and third-order convergence (8 +/- 1). */
static void test_t31_high_order(void **state) {
  (void)state;
  closure c[4];
  for (int i = 0; i < 4; ++i) {
    c[i] = run_t31(k_rates[i], NAV_MECH_HIGH_ORDER);
    print_message("(b) dt=%.3f att=%.4e vel=%.4e pos=%.4e\n", 1.0 / k_rates[i], c[i].att_rad, c[i].vel_mps,
                  c[i].pos_m);
    assert_rel_near(c[i].att_rad, k_b_att[i], 0.05);
    assert_rel_near(c[i].vel_mps, k_b_vel[i], 0.05);
    assert_rel_near(c[i].pos_m, k_b_pos[i], 0.05);
  }
  for (int i = 0; i < 3; ++i) {
    assert_near(c[i].att_rad / c[i + 1].att_rad, 8.0, 1.0);
    assert_near(c[i].vel_mps / c[i + 1].vel_mps, 8.0, 1.0);
    assert_near(c[i].pos_m / c[i + 1].pos_m, 8.0, 1.0);
  }
}

/* Trajectory derivatives are analytic: compare with central differences of the position and
 * rate (a check of the formulas, with a tolerance set by the difference step h^2 error). */
static void test_parametric_derivatives(void **state) {
  (void)state;
  nav_scene sc = nav_scene_default();
  nav_traj *tr = NULL;
  assert_int_equal(nav_traj_create(&sc, 0.01, &tr), NAV_OK);
  const double h = 1e-5;
  /* Flat Earth: F = l. */
  for (double t = 0.5; t < 20.0; t += 3.7) {
    nav_traj_state s, sp, sm;
    assert_int_equal(nav_traj_eval(tr, t, &s), NAV_OK);
    assert_int_equal(nav_traj_eval(tr, t + h, &sp), NAV_OK);
    assert_int_equal(nav_traj_eval(tr, t - h, &sm), NAV_OK);
    const nav_vec3 v_fd = nav_vec3_scale(nav_vec3_sub(sp.r_fb_f_m, sm.r_fb_f_m), 0.5 / h);
    const nav_vec3 a_fd = nav_vec3_scale(nav_vec3_sub(sp.v_fb_f_mps, sm.v_fb_f_mps), 0.5 / h);
    const nav_vec3 dw_fd = nav_vec3_scale(nav_vec3_sub(sp.w_fb_b_rps, sm.w_fb_b_rps), 0.5 / h);
    assert_vec3_near(s.v_fb_f_mps, v_fd, 1e-6);
    assert_vec3_near(s.a_fb_f_mps2, a_fd, 1e-6);
    assert_vec3_near(s.dw_fb_b_rps2, dw_fd, 1e-6);
    /* Attitude: C^T C_dot = [omega x], with C_dot by central differences of the quaternion. */
    const nav_mat3 C = nav_quat_to_dcm(s.q_b_f);
    const nav_mat3 Cd = nav_mat3_scale(nav_mat3_add(nav_quat_to_dcm(sp.q_b_f),
                                                    nav_mat3_scale(nav_quat_to_dcm(sm.q_b_f), -1.0)),
                                       0.5 / h);
    const nav_mat3 W = nav_mat3_tmul(C, Cd);
    assert_vec3_near(nav_vec3_make(W.m[2][1], W.m[0][2], W.m[1][0]), s.w_fb_b_rps, 1e-6);
  }
  /* Going back in time re-integrates from a checkpoint and gives the same attitude. */
  nav_traj_state late, early, again;
  assert_int_equal(nav_traj_eval(tr, 7.3, &early), NAV_OK);
  assert_int_equal(nav_traj_eval(tr, 19.9, &late), NAV_OK);
  assert_int_equal(nav_traj_eval(tr, 7.3, &again), NAV_OK);
  assert_quat_near(again.q_b_f, early.q_b_f, 1e-14);
  nav_traj_destroy(tr);
}

/* Exact gyro increments (closed form) equal the quadrature of the rate. */
static void test_rate_integral(void **state) {
  (void)state;
  nav_scene sc = nav_scene_default();
  nav_traj *tr = NULL;
  assert_int_equal(nav_traj_create(&sc, 0.01, &tr), NAV_OK);
  double x[8], w[8];
  assert_int_equal(nav_gauss_legendre(8, x, w), NAV_OK);
  for (double t0 = 0.0; t0 < 19.0; t0 += 1.3) {
    const double t1 = t0 + 0.01;
    nav_vec3 exact, quad = nav_vec3_zero();
    bool closed = false;
    assert_int_equal(nav_traj_rate_integral(tr, t0, t1, &exact, &closed), NAV_OK);
    assert_true(closed);
    for (int i = 0; i < 8; ++i) {
      nav_traj_state s;
      assert_int_equal(nav_traj_eval(tr, 0.5 * (t0 + t1) + 0.5 * (t1 - t0) * x[i], &s), NAV_OK);
      quad = nav_vec3_axpy(quad, 0.5 * (t1 - t0) * w[i], s.w_fb_b_rps);
    }
    /* Increments are ~1e-3 rad; the sine arguments reach 2 pi c t ~ 60 rad, whose rounding
     * (ulp 7e-15 rad) times b dt ~ 3e-3 bounds the difference of the two evaluations at ~2e-17. */
    assert_vec3_near(exact, quad, 1e-16);
  }
  nav_traj_destroy(tr);
}

/* Gauss-Legendre: weights sum to 2, symmetric nodes, exact for x^(2n-1) and x^(2n-2). */
static void test_gauss_legendre(void **state) {
  (void)state;
  for (int n = 1; n <= NAV_GL_MAX_NODES; ++n) {
    double x[NAV_GL_MAX_NODES], w[NAV_GL_MAX_NODES];
    assert_int_equal(nav_gauss_legendre(n, x, w), NAV_OK);
    double sw = 0.0, m = 0.0;
    for (int i = 0; i < n; ++i) {
      sw += w[i];
      m += w[i] * pow(x[i], 2 * n - 2);
      assert_near(x[i], -x[n - 1 - i], 1e-15);
      if (i > 0) assert_true(x[i] > x[i - 1]);
    }
    assert_near(sw, 2.0, 1e-14);
    assert_near(m, 2.0 / (2.0 * n - 1.0), 1e-14);
  }
  /* Known 2-point rule: +/- 1/sqrt(3), weights 1. */
  double x2[2], w2[2];
  assert_int_equal(nav_gauss_legendre(2, x2, w2), NAV_OK);
  assert_near(x2[1], 0.57735026918962576451, 1e-16);
  assert_near(w2[0], 1.0, 1e-15);
  double xx[1], ww[1];
  assert_int_equal(nav_gauss_legendre(0, xx, ww), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_gauss_legendre(NAV_GL_MAX_NODES + 1, xx, ww), NAV_ERR_INVALID_ARG);
}

/* T3.2: dv from 5-point and 8-point Gauss-Legendre differ by < 1e-13 relative (dt = 0.01 s). */
static void test_t32_quadrature_convergence(void **state) {
  (void)state;
  nav_scene s5 = nav_scene_default(), s8 = nav_scene_default();
  s5.imu.quadrature_nodes = 5;
  s8.imu.quadrature_nodes = 8;
  nav_truth *t5 = NULL, *t8 = NULL;
  assert_int_equal(nav_truth_create(&s5, &t5), NAV_OK);
  assert_int_equal(nav_truth_create(&s8, &t8), NAV_OK);
  double worst = 0.0;
  for (int64_t k = 1; k <= nav_truth_sample_count(t5); k += 7) {
    nav_imu_increment a, b;
    assert_int_equal(nav_truth_imu(t5, k, &a), NAV_OK);
    assert_int_equal(nav_truth_imu(t8, k, &b), NAV_OK);
    const double rel = nav_vec3_norm(nav_vec3_sub(a.dv_b_mps, b.dv_b_mps)) / nav_vec3_norm(b.dv_b_mps);
    if (rel > worst) worst = rel;
  }
  print_message("T3.2 worst relative dv difference 5 vs 8 nodes: %.3e\n", worst);
  assert_true(worst < 1e-13);
  nav_truth_destroy(t5);
  nav_truth_destroy(t8);
}

/* Statistics: RMS, max and type-7 95th percentile of 1..100. */
static void test_stats(void **state) {
  (void)state;
  nav_stat_acc *acc = NULL;
  assert_int_equal(nav_stat_acc_create(100, &acc), NAV_OK);
  /* Insert in a scrambled order so the selection is exercised. */
  for (int i = 0; i < 100; ++i) assert_int_equal(nav_stat_acc_add(acc, (double)((i * 37) % 100 + 1)), NAV_OK);
  assert_int_equal(nav_stat_acc_add(acc, 1.0), NAV_ERR_OUT_OF_RANGE);
  const nav_stat s = nav_stat_acc_result(acc);
  assert_near(s.max, 100.0, 0.0);
  assert_near(s.rms, sqrt(338350.0 / 100.0), 1e-12); /* sum of squares 1..100 = 338350 */
  assert_near(s.p95, 95.05, 1e-12);                  /* h = 99 * 0.95 = 94.05 -> 95 + 0.05 */
  nav_stat_acc_destroy(acc);
  assert_int_equal(nav_stat_acc_create(4, &acc), NAV_OK);
  assert_int_equal(nav_stat_acc_add(acc, NAN), NAV_ERR_NUMERIC);
  assert_int_equal(nav_stat_acc_add(acc, 3.0), NAV_OK);
  const nav_stat one = nav_stat_acc_result(acc);
  assert_near(one.p95, 3.0, 0.0);
  nav_stat_acc_destroy(acc);
}

/* nav_stat_acc_add_each: the same accumulators, bit for bit, as nav_stat_acc_add one metric after
 * the other; it stops at the first error and returns it. */
static void test_stats_add_each(void **state) {
  (void)state;
  enum { M = 5, N = 1000 };
  nav_stat_acc *a[M], *b[M];
  for (int m = 0; m < M; ++m) {
    assert_int_equal(nav_stat_acc_create(N, &a[m]), NAV_OK);
    assert_int_equal(nav_stat_acc_create(N, &b[m]), NAV_OK);
  }
  unsigned long long x = 88172645463325252ull;
  for (int i = 0; i < N; ++i) {
    double v[M];
    for (int m = 0; m < M; ++m) {
      x ^= x << 13;
      x ^= x >> 7;
      x ^= x << 17;
      v[m] = ((double)(x >> 11) * 0x1p-53 - 0.3) * (m + 1);
      assert_int_equal(nav_stat_acc_add(a[m], v[m]), NAV_OK);
    }
    assert_int_equal(nav_stat_acc_add_each(b, v, M), NAV_OK);
  }
  for (int m = 0; m < M; ++m) {
    const nav_stat sa = nav_stat_acc_result(a[m]), sb = nav_stat_acc_result(b[m]);
    assert_memory_equal(&sa, &sb, sizeof sa);
    assert_int_equal(nav_stat_acc_count(b[m]), N);
  }
  /* Full accumulators: the first one's error, nothing added to the others. */
  const double one[M] = {1, 2, 3, 4, 5};
  assert_int_equal(nav_stat_acc_add_each(b, one, M), NAV_ERR_OUT_OF_RANGE);
  for (int m = 0; m < M; ++m) nav_stat_acc_reset(b[m]);
  const double bad[M] = {1, 2, NAN, 4, 5};
  assert_int_equal(nav_stat_acc_add_each(b, bad, M), NAV_ERR_NUMERIC);
  assert_int_equal(nav_stat_acc_count(b[1]), 1);
  assert_int_equal(nav_stat_acc_count(b[2]), 0);
  assert_int_equal(nav_stat_acc_count(b[3]), 0);
  assert_int_equal(nav_stat_acc_add_each(NULL, one, M), NAV_ERR_INVALID_ARG);
  for (int m = 0; m < M; ++m) {
    nav_stat_acc_destroy(a[m]);
    nav_stat_acc_destroy(b[m]);
  }
}

/* The p95 of nav_stat_acc_result (a radix selection) against the order statistics of a sort, bit
 * for bit, on many random sets: spread and clustered values (one binade, one value repeated),
 * negatives, zeros of both signs, sizes from 1 to 200 000. */
static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : (x > y ? 1 : 0);
}

static void test_stats_p95_exact(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261127u, 95u, 0u);
  static const size_t sizes[] = {1, 2, 3, 20, 21, 49, 50, 100, 1001, 4097, 65536, 200000};
  double *v = malloc(200000 * sizeof *v), *sorted = malloc(200000 * sizeof *sorted);
  assert_non_null(v);
  assert_non_null(sorted);
  int cases = 0;
  for (size_t si = 0; si < sizeof sizes / sizeof sizes[0]; ++si)
    for (int kind = 0; kind < 7; ++kind) {
      const size_t n = sizes[si];
      nav_stat_acc *acc = NULL;
      assert_int_equal(nav_stat_acc_create(n, &acc), NAV_OK);
      for (size_t i = 0; i < n; ++i) {
        const double u = nav_rng_uniform(&r);
        double x;
        switch (kind) {
        case 0: x = u * 10.0; break;                                   /* spread */
        case 1: x = 0.015 + 0.001 * u; break;                          /* one binade, 16 buckets of it */
        case 2: x = 0.25; break;                                       /* all equal */
        case 3: x = (u < 0.5 ? -1.0 : 1.0) * exp(40.0 * (nav_rng_uniform(&r) - 0.5)); break; /* signs, scales */
        case 4: x = u < 0.3 ? 0.0 : (u < 0.6 ? -0.0 : u - 0.8); break; /* zeros of both signs */
        case 5: x = (double)(nav_rng_next_u64(&r) % 7u) * 1e-3; break; /* few distinct values */
        default: x = 1.0 + ldexp(u, -45); break;                       /* differ in the last bits only */
        }
        v[i] = x;
        assert_int_equal(nav_stat_acc_add(acc, x), NAV_OK);
      }
      memcpy(sorted, v, n * sizeof *v);
      qsort(sorted, n, sizeof *sorted, cmp_double);
      const double h = (double)(n - 1) * 0.95;
      const size_t lo = (size_t)floor(h);
      const double x_lo = sorted[lo], x_hi = lo + 1 < n ? sorted[lo + 1] : sorted[lo];
      const double want = x_lo + (h - (double)lo) * (x_hi - x_lo);
      const nav_stat s = nav_stat_acc_result(acc);
      if (memcmp(&s.p95, &want, sizeof want) != 0)
        fail_msg("n %zu kind %d: p95 %.17g (%a), from the sort %.17g (%a)", n, kind, s.p95, s.p95, want, want);
      /* A second call gives the same (the values are left as they were). */
      const nav_stat s2 = nav_stat_acc_result(acc);
      assert_memory_equal(&s.p95, &s2.p95, sizeof s.p95);
      nav_stat_acc_destroy(acc);
      ++cases;
    }
  free(v);
  free(sorted);
  assert_int_equal(cases, 12 * 7);
}

/* nav_sim end to end on the default scene: summary consistent with the direct closure. */
typedef struct rec_count {
  int n;
  double last_t;
} rec_count;

static nav_callback_result count_records(void *user, const nav_sim_record *r) {
  rec_count *c = user;
  c->n++;
  c->last_t = r->truth->t_s;
  return NAV_CONTINUE;
}

static void test_sim_run(void **state) {
  (void)state;
  nav_scene sc = nav_scene_default();
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  rec_count rc = {0, 0.0};
  o.ideal = true;
  o.record = count_records;
  o.user = &rc;
  nav_sim_summary sum;
  assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_OK);
  assert_int_equal(sum.imu_samples, 2000);
  assert_int_equal(rc.n, 201); /* 10 Hz over 20 s, both ends */
  assert_near(rc.last_t, 20.0, 1e-12);
  assert_int_equal(sum.stats_epochs, 2001);
  const closure c = run_t31(100.0, NAV_MECH_FIRST_ORDER);
  assert_near(sum.final.att_err_rad, c.att_rad, 1e-18);
  assert_true(sum.stats.pos_err_h_m.max >= sum.stats.pos_err_h_m.p95);
  assert_true(sum.stats.pos_err_h_m.p95 >= 0.0);
  assert_false(sum.partial);
  nav_sim_destroy(sim);
}

static nav_callback_result stop_early(void *user, const nav_sim_record *r) {
  (void)user;
  return r->truth->t_s >= 5.0 ? NAV_STOP : NAV_CONTINUE;
}

static void test_sim_stop(void **state) {
  (void)state;
  nav_scene sc = nav_scene_default();
  nav_sim *sim = NULL;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_OK);
  nav_sim_options o = nav_sim_options_default();
  o.record = stop_early;
  nav_sim_summary sum;
  assert_int_equal(nav_sim_run(sim, &o, &sum), NAV_ERR_CANCELLED);
  assert_true(sum.partial);
  assert_near(sum.duration_s, 5.0, 1e-9);
  nav_sim_destroy(sim);
  sc.imu.rate_hz = -1.0;
  assert_int_equal(nav_sim_create(&sc, &sim), NAV_ERR_INVALID_ARG);
}

/* nav_errors_compute_ref with the reference part of nav_errors_ref_compute (shared by the runs of
 * a Monte Carlo job) gives the errors of nav_errors_compute bit for bit, on the flat and the
 * WGS-84 frame, for estimates off the reference in position, velocity and attitude. */
static void test_errors_ref_same_bits(void **state) {
  (void)state;
  for (int model = 0; model < 2; ++model) {
    nav_scene sc = nav_scene_default();
    if (model == 1) {
      sc.earth.model = NAV_EARTH_WGS84;
      sc.earth.origin_lat_rad = 0.84;
      sc.earth.origin_lon_rad = 0.2;
      sc.earth.origin_h_m = 520.0;
    }
    nav_truth *truth = NULL;
    assert_int_equal(nav_truth_create(&sc, &truth), NAV_OK);
    const nav_frame fr = nav_truth_frame(truth);
    for (int i = 0; i < 8; ++i) {
      nav_traj_state ts;
      assert_int_equal(nav_truth_state(truth, 2.5 * i, &ts), NAV_OK);
      const double d = 0.3 + 0.7 * i;
      const nav_ins_state est = {ts.t_s, nav_vec3_add(ts.r_fb_f_m, nav_vec3_make(d, -2.0 * d, 0.5 * d)),
                                 nav_vec3_add(ts.v_fb_f_mps, nav_vec3_make(0.01 * d, 0.02, -0.03 * d)),
                                 nav_quat_mul(ts.q_b_f, nav_quat_from_rotvec(nav_vec3_make(1e-3 * d, -2e-3, 0.05 * d)))};
      const nav_epoch_errors a = nav_errors_compute(&fr, &ts, &est);
      const nav_errors_ref ref = nav_errors_ref_compute(&fr, &ts);
      const nav_epoch_errors b = nav_errors_compute_ref(&fr, &ts, &ref, &est);
      assert_true(a.pos_err_h_m > 0.0 && a.att_err_rad > 0.0);
      assert_memory_equal(&a, &b, sizeof a);
    }
    nav_truth_destroy(truth);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gauss_legendre),
      cmocka_unit_test(test_stats),
      cmocka_unit_test(test_stats_add_each),
      cmocka_unit_test(test_stats_p95_exact),
      cmocka_unit_test(test_parametric_derivatives),
      cmocka_unit_test(test_rate_integral),
      cmocka_unit_test(test_t32_quadrature_convergence),
      cmocka_unit_test(test_t31_first_order),
      cmocka_unit_test(test_t31_high_order),
      cmocka_unit_test(test_sim_run),
      cmocka_unit_test(test_sim_stop),
      cmocka_unit_test(test_errors_ref_same_bits),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
