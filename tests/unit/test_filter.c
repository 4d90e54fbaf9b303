/*
 * Tests of the loosely coupled INS/GNSS error-state filter (nav_filter.h, src/filter/):
 * numerics.md section 6, recipes T6.1-T6.4, plus the matrix exponential, the numerical
 * safeguards of 6.5 and the covariance decimation.
 *
 * White-box parts use src/filter/filter_internal.h (expm, Van Loan, F and H builders).
 *
 * The F checks need a reference for the continuous NED navigation equations; it is written here
 * independently of the filter (ref_* below): lat/lon/h rates, v_dot = C_b_n f_b -
 * (2 w_ie + w_en) x v + g_n, C_b_n_dot = C_b_n [w_ib_b x] - [w_in_n x] C_b_n, and the error
 * definitions of numerics.md 6.1 (dr in N/E/D metres, phi by E0.1, residual sensor errors).
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
#include "navcore/nav_earth.h"
#include "navcore/nav_filter.h"
#include "navcore/nav_math.h"
#include "navcore/nav_rng.h"
#include "nav_test.h"

#define NMAX NAV_FILTER_MAX_STATES

/* ================================================================ helpers */

static nav_vec3 v3(double a) {
  return nav_vec3_make(a, a, a);
}

static double max_abs(const double *a, size_t count) {
  double m = 0.0;
  for (size_t i = 0; i < count; ++i)
    m = fmax(m, fabs(a[i]));
  return m;
}

/* exp(-[phi x]) - I without cancellation: -sinc(a) [phi x] + ((1 - cos a)/a^2) [phi x]^2. */
static nav_mat3 expm1_neg_skew(nav_vec3 phi) {
  const double a = nav_vec3_norm(phi);
  const nav_mat3 k = nav_mat3_skew(phi);
  return nav_mat3_add(nav_mat3_scale(k, -nav_sinc(a)),
                      nav_mat3_scale(nav_mat3_mul(k, k), nav_one_minus_cos_over_a2(a)));
}

/* ================================================================ matrix exponential */

static void check_expm(const double *A, const double *expected, size_t n, double rel_tol,
                       unsigned *squarings) {
  double E[64], work[7 * 64 + 8];
  for (size_t i = 0; i < n * n; ++i)
    E[i] = NAN;
  nav_expm_info info = {0, 0};
  assert_int_equal(nav_expm(E, A, n, work, &info), NAV_OK);
  const double scale = max_abs(expected, n * n);
  for (size_t i = 0; i < n * n; ++i)
    assert_near(E[i], expected[i], rel_tol * scale);
  if (squarings != NULL) *squarings = info.squarings;
}

/* Rotation generators: exp([[0, -t], [t, 0]]) = [[cos t, -sin t], [sin t, cos t]] for angles
 * that select each Pade degree and, from |t| > theta_13 = 5.37, the scaling path; and the 3x3
 * skew matrix against Rodrigues (nav_dcm_exp). Tolerance: a few ulps of 1 per squaring. */
static void test_expm_rotation(void **state) {
  (void)state;
  const double angles[] = {1e-3, 0.2, 0.9, 2.0, 5.0, 10.0, 100.0};
  for (size_t k = 0; k < sizeof angles / sizeof angles[0]; ++k) {
    const double t = angles[k];
    const double A[4] = {0.0, -t, t, 0.0};
    const double X[4] = {cos(t), -sin(t), sin(t), cos(t)};
    unsigned s = 0;
    check_expm(A, X, 2, 1e-14, &s);
    if (t > 5.371920351148152) assert_true(s > 0);
  }
  const nav_vec3 axes[] = {{0.3, -0.2, 0.1}, {1.0, 2.0, -2.0}, {-20.0, 5.0, 7.0}};
  for (size_t k = 0; k < 3; ++k) {
    const nav_mat3 K = nav_mat3_skew(axes[k]), R = nav_dcm_exp(axes[k]);
    double A[9], X[9];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        A[3 * i + j] = K.m[i][j];
        X[3 * i + j] = R.m[i][j];
      }
    check_expm(A, X, 3, 2e-14, NULL);
  }
}

/* Nilpotent N (strictly upper triangular): exp(N) = I + N + N^2/2 + N^3/6 exactly; the Pade
 * approximant is exact on it, so only rounding remains, also after scaling (large entries). */
static void test_expm_nilpotent(void **state) {
  (void)state;
  const double mags[] = {0.01, 1.0, 40.0};
  for (size_t k = 0; k < 3; ++k) {
    const double c = mags[k];
    double N[16] = {0}, N2[16], N3[16], X[16];
    N[0 * 4 + 1] = c;
    N[0 * 4 + 2] = -0.5 * c;
    N[0 * 4 + 3] = 0.25 * c;
    N[1 * 4 + 2] = 2.0 * c;
    N[1 * 4 + 3] = -c;
    N[2 * 4 + 3] = 3.0 * c;
    nav_matn_mul(N2, N, N, 4, 4, 4);
    nav_matn_mul(N3, N2, N, 4, 4, 4);
    for (size_t i = 0; i < 16; ++i)
      X[i] = N[i] + N2[i] / 2.0 + N3[i] / 6.0 + ((i % 5) == 0 ? 1.0 : 0.0);
    unsigned s = 0;
    check_expm(N, X, 4, 1e-14, &s);
    if (c >= 40.0) assert_true(s > 0);
  }
}

/* Diagonal: exp(diag(d)) = diag(exp(d)), relative per entry; and a non-normal 2x2 upper
 * triangular [[a, b], [0, c]] -> [[e^a, b (e^a - e^c)/(a - c)], [0, e^c]]. */
static void test_expm_diagonal_and_triangular(void **state) {
  (void)state;
  const double d[6] = {-30.0, -1.0, 0.0, 1e-8, 2.5, 20.0};
  double A[36] = {0}, E[36], work[7 * 36 + 6];
  for (int i = 0; i < 6; ++i)
    A[i * 6 + i] = d[i];
  nav_expm_info info;
  assert_int_equal(nav_expm(E, A, 6, work, &info), NAV_OK);
  assert_true(info.squarings > 0);
  for (int i = 0; i < 6; ++i) {
    /* Each squaring doubles the relative error of exp(d/2^s): s = 2 here, so ~2^2 ulps plus the
     * Pade backward error (<= u |d|): 3e-15 relative covers |d| <= 30. Off-diagonals stay 0. */
    assert_rel_near(E[i * 6 + i], exp(d[i]), 3e-15 * fmax(1.0, fabs(d[i])));
    for (int j = 0; j < 6; ++j)
      if (j != i) assert_near(E[i * 6 + j], 0.0, 0.0);
  }
  const double a = 1.5, b = 3.0, c = -0.7;
  const double T[4] = {a, b, 0.0, c};
  const double X[4] = {exp(a), b * (exp(a) - exp(c)) / (a - c), 0.0, exp(c)};
  check_expm(T, X, 2, 1e-15, NULL);
  const double T2[4] = {8.0 * a, 8.0 * b, 0.0, 8.0 * c}; /* scaling path */
  const double X2[4] = {exp(8 * a), 8 * b * (exp(8 * a) - exp(8 * c)) / (8 * a - 8 * c), 0.0, exp(8 * c)};
  unsigned s = 0;
  check_expm(T2, X2, 2, 1e-14, &s);
  assert_true(s > 0);
  /* Argument checks. */
  assert_int_equal(nav_expm(E, A, 0, work, NULL), NAV_ERR_INVALID_ARG);
  A[3] = NAN;
  assert_int_equal(nav_expm(E, A, 6, work, NULL), NAV_ERR_NUMERIC);
}

/* ================================================================ T6.2 Van Loan */

/* numerics.md T6.2: F = [[0, 1], [0, 0]], G = [0; 1], Q_c = q -> Phi = [[1, dt], [0, 1]],
 * Q_d = q [[dt^3/3, dt^2/2], [dt^2/2, dt]] to 1e-14 relative, for several dt and q (the Q
 * block is rescaled internally by a power of two, so q's magnitude must not matter). */
static void test_van_loan_T62(void **state) {
  (void)state;
  const double dts[] = {0.005, 0.01, 1.0, 30.0};
  const double qs[] = {1e-12, 2.5, 1e9};
  double work[2 * 16 + 7 * 16 + 4];
  double worst_phi = 0.0, worst_q = 0.0;
  for (size_t a = 0; a < 4; ++a)
    for (size_t b = 0; b < 3; ++b) {
      const double dt = dts[a], q = qs[b];
      const double FT[4] = {0.0, dt, 0.0, 0.0};
      const double QT[4] = {0.0, 0.0, 0.0, q * dt};
      double Phi[4] = {NAN, NAN, NAN, NAN}, Qd[4] = {NAN, NAN, NAN, NAN};
      assert_int_equal(nav_filter_van_loan(Phi, Qd, FT, QT, 2, work, NULL), NAV_OK);
      const double Pe[4] = {1.0, dt, 0.0, 1.0};
      const double Qe[4] = {q * dt * dt * dt / 3.0, q * dt * dt / 2.0, q * dt * dt / 2.0, q * dt};
      for (int i = 0; i < 4; ++i) {
        if (Pe[i] == 0.0)
          assert_near(Phi[i], 0.0, 0.0);
        else
          assert_rel_near(Phi[i], Pe[i], 1e-14);
        assert_rel_near(Qd[i], Qe[i], 1e-14);
        if (Pe[i] != 0.0) worst_phi = fmax(worst_phi, fabs(Phi[i] / Pe[i] - 1.0));
        worst_q = fmax(worst_q, fabs(Qd[i] / Qe[i] - 1.0));
      }
    }
  print_message("[ T6.2     ] Van Loan worst relative error: Phi %.2e, Q_d %.2e\n", worst_phi, worst_q);
}

/* ================================================================ T6.3 covariance analysis */

/* numerics.md T6.3: 120 s free-inertial outage at lat 45 deg, h = 0, v = (20, 0, 0), level,
 * heading north, f_n = (0, 0, -g), 15 states, dt = 0.01 s; N_a = 0.07/60 m/s/sqrt(s),
 * N_g = 0.15 deg/sqrt(h), random-constant biases 0.05 mg and 0.5 deg/h; P0 from the recipe.
 * The reference is held at 45 deg (F constant): the recipe gives one set of values for the whole
 * outage, and advancing the reference latitude at 20 m/s changes sigma_N(120 s) by 8e-7 relative. */
static nav_filter_config t63_config(nav_filter_discretisation disc, unsigned decimation) {
  nav_filter_config c = nav_filter_config_default();
  c.discretisation = disc;
  c.cov_decimation = decimation;
  c.gyro_arw_rad_per_sqrt_s = v3(0.15 * NAV_DEG2RAD / 60.0);
  c.accel_vrw_mps_per_sqrt_s = v3(0.07 / 60.0);
  c.gyro_bias_terms = 0u; /* random constants */
  c.accel_bias_terms = 0u;
  const double sbg = 0.5 * NAV_DEG2RAD / 3600.0, sba = 0.05e-3 * NAV_G0_MPS2;
  c.init.pos_sd_m = v3(0.02);
  c.init.vel_sd_mps = v3(0.01);
  c.init.att_sd_rad = nav_vec3_make(0.005 * NAV_DEG2RAD, 0.005 * NAV_DEG2RAD, 0.05 * NAV_DEG2RAD);
  c.init.gyro_bias_sd_rps = v3(sbg);
  c.init.accel_bias_sd_mps2 = v3(sba);
  return c;
}

static nav_filter_nav t63_nav(void) {
  nav_filter_nav nav;
  nav.lat_rad = 45.0 * NAV_DEG2RAD;
  nav.h_m = 0.0;
  nav.v_eb_n_mps = nav_vec3_make(20.0, 0.0, 0.0);
  nav.C_b_n = nav_mat3_identity();
  const double g = nav_earth_gravity_normal_mps2(nav.lat_rad, 0.0);
  nav.f_ib_b_mps2 = nav_vec3_make(0.0, 0.0, -g);
  nav.w_ib_b_rps = nav_vec3_add(nav_earth_rate_n_rps(nav.lat_rad),
                                nav_earth_transport_rate_n_rps(nav.lat_rad, 0.0, nav.v_eb_n_mps));
  return nav;
}

/* North position sigma at 10, 30, 60, 120 s. */
static void t63_run(nav_filter_discretisation disc, unsigned decimation, double sd[4]) {
  const nav_filter_config cfg = t63_config(disc, decimation);
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  const nav_filter_nav nav = t63_nav();
  const int marks[4] = {1000, 3000, 6000, 12000};
  int next = 0;
  for (int k = 1; k <= 12000; ++k) {
    assert_int_equal(nav_filter_predict(kf, &nav, 0.01), NAV_OK);
    if (k == marks[next]) {
      assert_int_equal(nav_filter_flush(kf), NAV_OK);
      sd[next++] = sqrt(nav_filter_get_cov(kf)[0]);
    }
  }
  nav_filter_destroy(kf);
}

static const double t63_expected[4] = {0.11923, 0.73033, 3.38406, 18.0667};

/* The Van Loan, undecimated run is the reference of three tests; it costs 12000 exponentials of
 * a 30 x 30 matrix, so it is computed once. */
static void t63_van_loan_reference(double sd[4]) {
  static double cache[4];
  static bool have = false;
  if (!have) {
    t63_run(NAV_FILTER_DISC_VAN_LOAN, 1, cache);
    have = true;
  }
  memcpy(sd, cache, sizeof cache);
}

static void test_T63_van_loan(void **state) {
  (void)state;
  double sd[4];
  t63_van_loan_reference(sd);
  for (int i = 0; i < 4; ++i)
    assert_rel_near(sd[i], t63_expected[i], 1e-3);
  print_message(
      "[ T6.3     ] Van Loan:     %.6f %.6f %.6f %.5f m (expected 0.11923 0.73033 3.38406 18.0667)\n", sd[0],
      sd[1], sd[2], sd[3]);
}

static void test_T63_second_order(void **state) {
  (void)state;
  double vl[4], so[4];
  t63_van_loan_reference(vl);
  t63_run(NAV_FILTER_DISC_SECOND_ORDER, 1, so);
  double worst = 0.0;
  for (int i = 0; i < 4; ++i) {
    assert_rel_near(so[i], t63_expected[i], 1e-3);
    worst = fmax(worst, fabs(so[i] / vl[i] - 1.0));
  }
  /* numerics.md 6.3: "predicted position sigmas agree to 5 significant digits". */
  assert_true(worst < 1e-5);
  print_message("[ T6.3     ] second order: %.6f %.6f %.6f %.5f m; max rel. difference to Van Loan %.2e\n",
                so[0], so[1], so[2], so[3], worst);
}

/* Covariance decimation (cov_decimation 10 and 20 IMU steps per covariance step): F is constant
 * here, so Van Loan over the summed interval is exact and must agree with the per-step result
 * to rounding; the second-order form over 0.1-0.2 s loses its third-order terms (g T^3/6 of the
 * gyro-bias-to-position coupling) and is only required to stay within the T6.3 tolerance. */
static void test_T63_decimation(void **state) {
  (void)state;
  double ref[4], d10[4], d20[4], s10[4], s20[4];
  t63_van_loan_reference(ref);
  t63_run(NAV_FILTER_DISC_VAN_LOAN, 10, d10);
  t63_run(NAV_FILTER_DISC_VAN_LOAN, 20, d20);
  t63_run(NAV_FILTER_DISC_SECOND_ORDER, 10, s10);
  t63_run(NAV_FILTER_DISC_SECOND_ORDER, 20, s20);
  double w10 = 0, w20 = 0, ws10 = 0, ws20 = 0;
  for (int i = 0; i < 4; ++i) {
    assert_rel_near(d10[i], ref[i], 1e-9);
    assert_rel_near(d20[i], ref[i], 1e-9);
    assert_rel_near(s10[i], t63_expected[i], 1e-3);
    assert_rel_near(s20[i], t63_expected[i], 1e-3);
    w10 = fmax(w10, fabs(d10[i] / ref[i] - 1));
    w20 = fmax(w20, fabs(d20[i] / ref[i] - 1));
    ws10 = fmax(ws10, fabs(s10[i] / ref[i] - 1));
    ws20 = fmax(ws20, fabs(s20[i] / ref[i] - 1));
  }
  print_message("[ T6.3 dec ] VL x10 %.2e, VL x20 %.2e, 2nd-order x10 %.2e, x20 %.2e (max rel. vs VL x1)\n",
                w10, w20, ws10, ws20);
  print_message("[ T6.3 dec ] 2nd-order x20: %.6f %.6f %.6f %.5f m\n", s20[0], s20[1], s20[2], s20[3]);
}

/* An update in the middle of a decimated interval first completes the partial covariance
 * step, so the result equals the undecimated filter's (F constant: to rounding). */
static void test_decimation_flush_on_update(void **state) {
  (void)state;
  double P[2][NMAX * NMAX];
  for (int run = 0; run < 2; ++run) {
    nav_filter_config cfg = t63_config(NAV_FILTER_DISC_VAN_LOAN, run == 0 ? 1u : 10u);
    nav_filter *kf = NULL;
    assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
    const nav_filter_nav nav = t63_nav();
    for (int k = 0; k < 27; ++k)
      assert_int_equal(nav_filter_predict(kf, &nav, 0.01), NAV_OK);
    const nav_vec3 r = v3(0.25);
    assert_int_equal(
        nav_filter_update_gnss_pos(kf, &nav, nav_vec3_make(0.1, -0.2, 0.3), &r, nav_vec3_make(1, 0, -1)),
        NAV_OK);
    memcpy(P[run], nav_filter_get_cov(kf), 15 * 15 * sizeof(double));
    nav_filter_destroy(kf);
  }
  for (int i = 0; i < 15 * 15; ++i)
    assert_near(P[1][i], P[0][i], 1e-9 * sqrt(fabs(P[0][(i / 15) * 16]) * fabs(P[0][(i % 15) * 16])));
}

/* ================================================================ reference NED model */

typedef struct ref_model {
  bool sphere; /* R_M = R_N = R0 constant and g(h) = g_ref ((R0 + h_ref)/(R0 + h))^2 */
  double R0, g_ref, h_ref;
} ref_model;

typedef struct ref_state {
  double lat, lon, h;
  nav_vec3 v;
  nav_quat q; /* q_b_n */
} ref_state;

static void ref_radii(const ref_model *m, double lat, double *RM, double *RN, double *dRM, double *dRN) {
  if (m->sphere) {
    *RM = *RN = m->R0;
    *dRM = *dRN = 0.0;
    return;
  }
  /* Groves eqs. 2.105-2.106 and their latitude derivatives. */
  const double a = NAV_WGS84_A_M, e2 = NAV_WGS84_E2, s = sin(lat), c = cos(lat);
  const double w = 1.0 - e2 * s * s, sw = sqrt(w);
  *RN = a / sw;
  *RM = a * (1.0 - e2) / (w * sw);
  *dRN = a * e2 * s * c / (w * sw);
  *dRM = 3.0 * a * (1.0 - e2) * e2 * s * c / (w * w * sw);
}

static double ref_gravity(const ref_model *m, double lat, double h) {
  if (m->sphere) {
    const double r = (m->R0 + m->h_ref) / (m->R0 + h);
    return m->g_ref * r * r;
  }
  return nav_earth_gravity_normal_mps2(lat, h);
}

static nav_vec3 ref_w_ie(double lat) {
  return nav_vec3_make(NAV_WGS84_OMEGA_IE_RPS * cos(lat), 0.0, -NAV_WGS84_OMEGA_IE_RPS * sin(lat));
}

static nav_vec3 ref_w_en(const ref_model *m, double lat, double h, nav_vec3 v) {
  double RM, RN, dRM, dRN;
  ref_radii(m, lat, &RM, &RN, &dRM, &dRN);
  return nav_vec3_make(v.y / (RN + h), -v.x / (RM + h), -v.y * tan(lat) / (RN + h));
}

/* Continuous NED state derivative (the navigation equations; Groves ch. 5, numerics.md 3.2):
 * d/dt [lat, lon, h, v, q]. */
static void ref_deriv(double *d, const ref_model *m, const double *s, nav_vec3 f_b, nav_vec3 w_b) {
  const double lat = s[0], h = s[2];
  const nav_vec3 v = {s[3], s[4], s[5]};
  const nav_quat q = {s[6], s[7], s[8], s[9]};
  double RM, RN, dRM, dRN;
  ref_radii(m, lat, &RM, &RN, &dRM, &dRN);
  d[0] = v.x / (RM + h);
  d[1] = v.y / ((RN + h) * cos(lat));
  d[2] = -v.z;
  const nav_vec3 w_ie = ref_w_ie(lat), w_en = ref_w_en(m, lat, h, v);
  const nav_vec3 f_n = nav_quat_rotate(q, f_b);
  const nav_vec3 cor = nav_vec3_cross(nav_vec3_add(nav_vec3_scale(w_ie, 2.0), w_en), v);
  d[3] = f_n.x - cor.x;
  d[4] = f_n.y - cor.y;
  d[5] = f_n.z - cor.z + ref_gravity(m, lat, h);
  /* q_dot = 1/2 q (x) (0, w_ib_b) - 1/2 (0, w_in_n) (x) q */
  const nav_vec3 w_in = nav_vec3_add(w_ie, w_en);
  const nav_quat qb = nav_quat_mul(q, (nav_quat){0.0, w_b.x, w_b.y, w_b.z});
  const nav_quat qn = nav_quat_mul((nav_quat){0.0, w_in.x, w_in.y, w_in.z}, q);
  d[6] = 0.5 * (qb.w - qn.w);
  d[7] = 0.5 * (qb.x - qn.x);
  d[8] = 0.5 * (qb.y - qn.y);
  d[9] = 0.5 * (qb.z - qn.z);
}

/* One classical RK4 step with constant inputs; the quaternion is renormalised. */
static void ref_rk4(const ref_model *m, ref_state *st, nav_vec3 f_b, nav_vec3 w_b, double dt) {
  double s[10] = {st->lat, st->lon, st->h, st->v.x, st->v.y, st->v.z, st->q.w, st->q.x, st->q.y, st->q.z};
  double k1[10], k2[10], k3[10], k4[10], t[10];
  ref_deriv(k1, m, s, f_b, w_b);
  for (int i = 0; i < 10; ++i)
    t[i] = s[i] + 0.5 * dt * k1[i];
  ref_deriv(k2, m, t, f_b, w_b);
  for (int i = 0; i < 10; ++i)
    t[i] = s[i] + 0.5 * dt * k2[i];
  ref_deriv(k3, m, t, f_b, w_b);
  for (int i = 0; i < 10; ++i)
    t[i] = s[i] + dt * k3[i];
  ref_deriv(k4, m, t, f_b, w_b);
  for (int i = 0; i < 10; ++i)
    s[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  st->lat = s[0];
  st->lon = s[1];
  st->h = s[2];
  st->v = nav_vec3_make(s[3], s[4], s[5]);
  st->q = nav_quat_normalize((nav_quat){s[6], s[7], s[8], s[9]});
}

/* Error state of a computed state c against the truth t (numerics.md 6.1 definitions, D at the
 * truth; phi = -log(C_c C_t^T) from E0.1). Only dr, dv, phi are written. */
static void ref_error(double *e, const ref_model *m, const ref_state *c, const ref_state *t) {
  double RM, RN, dRM, dRN;
  ref_radii(m, t->lat, &RM, &RN, &dRM, &dRN);
  e[0] = (c->lat - t->lat) * (RM + t->h);
  e[1] = (c->lon - t->lon) * (RN + t->h) * cos(t->lat);
  e[2] = -(c->h - t->h);
  e[3] = c->v.x - t->v.x;
  e[4] = c->v.y - t->v.y;
  e[5] = c->v.z - t->v.z;
  const nav_vec3 r = nav_quat_to_rotvec(nav_quat_mul(c->q, nav_quat_conj(t->q)));
  e[6] = -r.x;
  e[7] = -r.y;
  e[8] = -r.z;
}

static nav_filter_nav ref_nav(const ref_state *t, nav_vec3 f_b, nav_vec3 w_b) {
  nav_filter_nav nav;
  nav.lat_rad = t->lat;
  nav.h_m = t->h;
  nav.v_eb_n_mps = t->v;
  nav.C_b_n = nav_quat_to_dcm(t->q);
  nav.f_ib_b_mps2 = f_b;
  nav.w_ib_b_rps = w_b;
  return nav;
}

/*
 * The exact time derivative of the error state for a computed state = truth (+) dx, both obeying
 * the navigation equations, the computed one with the residual sensor errors of dx:
 * f_c = f + b_a + diag(f) s_a, w_c = w + b_g + diag(w) s_g. Written as differences of like terms so
 * that nothing cancels catastrophically. dx_eff receives the error state actually applied (the
 * position perturbation goes through lat/lon/h and is re-measured exactly).
 */
static void ref_error_rate(double *edot, double *dx_eff, const ref_model *m, const nav_filter_layout *lay,
                           const ref_state *t, nav_vec3 f, nav_vec3 w, const double *proc_diag,
                           const double *dx) {
  const size_t n = lay->n_states;
  double RM, RN, dRM, dRN;
  ref_radii(m, t->lat, &RM, &RN, &dRM, &dRN);
  const double rm = RM + t->h, rn = RN + t->h, cl = cos(t->lat), sl = sin(t->lat);
  const double lat_c = t->lat + dx[0] / rm, lon_c = t->lon + dx[1] / (rn * cl), h_c = t->h - dx[2];
  const double dlat = lat_c - t->lat, dlon = lon_c - t->lon, dh = h_c - t->h; /* exact */
  for (size_t i = 0; i < n; ++i)
    dx_eff[i] = dx[i];
  dx_eff[0] = dlat * rm;
  dx_eff[1] = dlon * rn * cl;
  dx_eff[2] = -dh;
  const nav_vec3 dv = {dx[3], dx[4], dx[5]}, phi = {dx[6], dx[7], dx[8]};
  const nav_vec3 v_t = t->v, v_c = nav_vec3_add(v_t, dv);
  const nav_mat3 C_t = nav_quat_to_dcm(t->q);
  const nav_mat3 AmI = expm1_neg_skew(phi); /* A - I, A = exp(-[phi x]) = C_c C_t^T */
  const nav_mat3 C_c = nav_mat3_add(C_t, nav_mat3_mul(AmI, C_t));
  nav_vec3 b_g = {dx[9], dx[10], dx[11]}, b_a = {dx[12], dx[13], dx[14]};
  nav_vec3 df = b_a, dw = b_g;
  if (lay->has_scale_factors) {
    df = nav_vec3_add(df, nav_vec3_make(f.x * dx[18], f.y * dx[19], f.z * dx[20]));
    dw = nav_vec3_add(dw, nav_vec3_make(w.x * dx[15], w.y * dx[16], w.z * dx[17]));
  }
  const nav_vec3 f_c = nav_vec3_add(f, df);

  /* Position: d/dt of ((lat_c - lat_t)(R_M(lat_t) + h_t), ...). */
  double RMc, RNc, dRMc, dRNc;
  ref_radii(m, lat_c, &RMc, &RNc, &dRMc, &dRNc);
  const double latd_t = v_t.x / rm, lond_t = v_t.y / (rn * cl), hd_t = -v_t.z;
  const double latd_c = v_c.x / (RMc + h_c), lond_c = v_c.y / ((RNc + h_c) * cos(lat_c)), hd_c = -v_c.z;
  edot[0] = (latd_c - latd_t) * rm + dlat * (dRM * latd_t + hd_t);
  edot[1] = (lond_c - lond_t) * rn * cl + dlon * ((dRN * latd_t + hd_t) * cl - rn * sl * latd_t);
  edot[2] = -(hd_c - hd_t);

  /* Velocity: (C_c f_c - C_t f) - ((Om_c - Om_t) x v_c + Om_t x dv) + (g_c - g_t) e_D. */
  const nav_vec3 Om_t = nav_vec3_add(nav_vec3_scale(ref_w_ie(t->lat), 2.0), ref_w_en(m, t->lat, t->h, v_t));
  const nav_vec3 Om_c = nav_vec3_add(nav_vec3_scale(ref_w_ie(lat_c), 2.0), ref_w_en(m, lat_c, h_c, v_c));
  const nav_vec3 sf =
      nav_vec3_add(nav_mat3_mul_vec(AmI, nav_mat3_mul_vec(C_t, f_c)), nav_mat3_mul_vec(C_t, df));
  const nav_vec3 cor = nav_vec3_add(nav_vec3_cross(nav_vec3_sub(Om_c, Om_t), v_c), nav_vec3_cross(Om_t, dv));
  const double dg = ref_gravity(m, lat_c, h_c) - ref_gravity(m, t->lat, t->h);
  edot[3] = sf.x - cor.x;
  edot[4] = sf.y - cor.y;
  edot[5] = sf.z - cor.z + dg;

  /* Attitude: with A = C_c C_t^T, A_dot A^T = [w_A x], w_A = C_c dw + A w_in_t - w_in_c (from
   * C_dot = C [w_ib x] - [w_in x] C); A = exp([theta x]) with theta = -phi gives
   * theta_dot = J_l(theta)^-1 w_A, J_l^-1 = I - [theta x]/2 + [theta x]^2/12 + O(theta^4). */
  const nav_vec3 w_in_t = nav_vec3_add(ref_w_ie(t->lat), ref_w_en(m, t->lat, t->h, v_t));
  const nav_vec3 w_in_c = nav_vec3_add(ref_w_ie(lat_c), ref_w_en(m, lat_c, h_c, v_c));
  const nav_vec3 wA = nav_vec3_add(nav_vec3_sub(nav_mat3_mul_vec(C_c, dw), nav_vec3_sub(w_in_c, w_in_t)),
                                   nav_mat3_mul_vec(AmI, w_in_t));
  const nav_vec3 th = nav_vec3_scale(phi, -1.0);
  const nav_vec3 thd = nav_vec3_add(nav_vec3_sub(wA, nav_vec3_scale(nav_vec3_cross(th, wA), 0.5)),
                                    nav_vec3_scale(nav_vec3_cross(th, nav_vec3_cross(th, wA)), 1.0 / 12.0));
  edot[6] = -thd.x;
  edot[7] = -thd.y;
  edot[8] = -thd.z;
  /* Sensor and GNSS states: first-order Gauss-Markov (or constant) residuals. */
  for (size_t i = 9; i < n; ++i)
    edot[i] = proc_diag[i] * dx[i];
}

/* A moving, turning, climbing reference point with every F entry non-zero. */
static ref_state f_test_state(void) {
  ref_state t;
  t.lat = 37.0 * NAV_DEG2RAD;
  t.lon = -122.0 * NAV_DEG2RAD;
  t.h = 1500.0;
  t.v = nav_vec3_make(60.0, -35.0, 4.0);
  t.q = nav_euler_to_quat((nav_euler){8.0 * NAV_DEG2RAD, -4.0 * NAV_DEG2RAD, 125.0 * NAV_DEG2RAD});
  return t;
}

/* State scales (the size of a typical error of each block) for steps and for the comparison. */
static double state_scale(size_t i, const nav_filter_layout *lay) {
  if (i < 3) return 1.0;   /* m */
  if (i < 6) return 0.1;   /* m/s */
  if (i < 9) return 1e-3;  /* rad */
  if (i < 12) return 1e-4; /* rad/s */
  if (i < 15) return 1e-2; /* m/s^2 */
  if (lay->has_scale_factors && i < 21) return 1e-3;
  return 1.0; /* GNSS position error, m */
}

/* Finite-difference F by central differences of ref_error_rate(). Steps: 100 m for position
 * (curvature makes the truncation error (100/R)^2 ~ 2e-10, and large steps keep the rounding of
 * latitude irrelevant), 1e-3 of the state scale elsewhere (attitude 1e-6 rad: truncation 1e-12). */
static void fd_F(double *Ffd, const ref_model *m, const nav_filter_layout *lay, const ref_state *t,
                 nav_vec3 f, nav_vec3 w, const double *proc_diag) {
  const size_t n = lay->n_states;
  for (size_t i = 0; i < n * n; ++i)
    Ffd[i] = NAN;
  for (size_t j = 0; j < n; ++j) {
    double dxp[NMAX] = {0}, dxm[NMAX] = {0}, ep[NMAX], em[NMAX], xp[NMAX], xm[NMAX];
    const double step = j < 3 ? 100.0 : 1e-3 * state_scale(j, lay);
    dxp[j] = step;
    dxm[j] = -step;
    ref_error_rate(ep, xp, m, lay, t, f, w, proc_diag, dxp);
    ref_error_rate(em, xm, m, lay, t, f, w, proc_diag, dxm);
    for (size_t i = 0; i < n; ++i)
      Ffd[i * n + j] = (ep[i] - em[i]) / (xp[j] - xm[j]);
  }
}

static nav_filter_layout f_test_layout_and_proc(double *proc_diag) {
  const nav_filter_layout lay =
      nav_filter_layout_of(NAV_FILTER_STATE_SCALE_FACTORS | NAV_FILTER_STATE_GNSS_POS_GM);
  for (size_t i = 0; i < NMAX; ++i)
    proc_diag[i] = 0.0;
  for (size_t i = 9; i < lay.n_states; ++i)
    proc_diag[i] = -1.0 / (100.0 * (double)(i + 1)); /* distinct GM time constants */
  return lay;
}

/*
 * T6.1, continuous part, model-consistent reference: on a sphere (R_M = R_N = R0, no latitude
 * variation of the radii) with inverse-square gravity g(h) = g_ref ((R0 + h_ref)/(R0 + h))^2,
 * numerics.md 6.1's F is the exact Jacobian of the error dynamics (the [SHIN] derivation
 * neglects exactly dR/dlat and the latitude gradient of gravity). F(R0, R0, g_ref) must match the
 * finite-difference Jacobian of the nonlinear reference entry by entry, at a state where every
 * velocity, rate and specific-force component is non-zero, with all 24 states (scale factors
 * and GNSS GM included).
 * Tolerance: 1e-7 relative to the entry plus a noise floor of 1e-7 x (the largest entry of the
 * same 3x3 block): the central differences are accurate to ~1e-9 relative (truncation
 * (step/R)^2 and (1e-6 rad)^2; rounding of differences of O(1) terms), so any wrong sign or
 * missing term - down to the smallest, e.g. F_vr(1,3) = v_N v_D/R_m^2 - v_E^2 tan/R_n^2 ~ 1e-10 -
 * fails by orders of magnitude.
 */
static void test_F_exact_on_sphere(void **state) {
  (void)state;
  double proc[NMAX];
  const nav_filter_layout lay = f_test_layout_and_proc(proc);
  const size_t n = lay.n_states;
  const ref_state t = f_test_state();
  const nav_vec3 f = {0.8, -1.3, -9.5}, w = {0.02, -0.05, 0.11};
  ref_model m = {true, 0.0, 0.0, t.h};
  m.R0 = sqrt(nav_earth_radius_meridian_m(t.lat) * nav_earth_radius_prime_vertical_m(t.lat));
  m.g_ref = nav_earth_gravity_normal_mps2(t.lat, t.h);
  const nav_filter_earth_terms earth = {m.R0, m.R0, m.g_ref, NAV_WGS84_OMEGA_IE_RPS};
  const nav_filter_nav nav = ref_nav(&t, f, w);
  double F[NMAX * NMAX], Ffd[NMAX * NMAX];
  for (size_t i = 0; i < n * n; ++i)
    F[i] = NAN;
  nav_filter_build_F(F, &lay, &nav, &earth, proc);
  fd_F(Ffd, &m, &lay, &t, f, w, proc);
  double worst = 0.0;
  for (size_t bi = 0; bi < n; bi += 3)
    for (size_t bj = 0; bj < n; bj += 3) {
      double bmax = 0.0;
      for (size_t i = bi; i < bi + 3; ++i)
        for (size_t j = bj; j < bj + 3; ++j)
          bmax = fmax(bmax, fabs(F[i * n + j]));
      for (size_t i = bi; i < bi + 3; ++i)
        for (size_t j = bj; j < bj + 3; ++j) {
          const double a = F[i * n + j], b = Ffd[i * n + j];
          assert_true(isfinite(a));
          const double tol = 1e-7 * fabs(a) + 1e-7 * bmax;
          if (!(fabs(a - b) <= tol))
            fail_msg("F(%zu,%zu) = %.10e, finite difference %.10e (block max %.3e)", i, j, a, b, bmax);
          if (bmax > 0.0) worst = fmax(worst, fabs(a - b) / bmax);
        }
    }
  print_message("[ T6.1 F   ] sphere: max |F - F_fd| / block max = %.2e\n", worst);
}

/*
 * Same check against the real WGS-84 reference (ellipsoidal radii varying with latitude, normal
 * gravity with its latitude and height gradients). F of 6.1 neglects dR_M/dlat, dR_N/dlat
 * (relative size ~3 e^2 sin cos ~ 1 % of the transport-rate terms), the latitude gradient of
 * gravity (~8e-9 s^-2, 0.3 % of the vertical gravity gradient 2g/R) and approximates
 * d gamma/dh by 2g/(sqrt(R_M R_N) + h) (0.35 %): every entry must agree within 1.5 % of the
 * largest entry of its 3x3 block.
 */
static void test_F_wgs84_within_neglected_terms(void **state) {
  (void)state;
  double proc[NMAX];
  const nav_filter_layout lay = f_test_layout_and_proc(proc);
  const size_t n = lay.n_states;
  const ref_state t = f_test_state();
  const nav_vec3 f = {0.8, -1.3, -9.5}, w = {0.02, -0.05, 0.11};
  const ref_model m = {false, 0.0, 0.0, 0.0};
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(t.lat, t.h);
  const nav_filter_nav nav = ref_nav(&t, f, w);
  double F[NMAX * NMAX], Ffd[NMAX * NMAX];
  nav_filter_build_F(F, &lay, &nav, &earth, proc);
  fd_F(Ffd, &m, &lay, &t, f, w, proc);
  double worst = 0.0;
  for (size_t bi = 0; bi < n; bi += 3)
    for (size_t bj = 0; bj < n; bj += 3) {
      double bmax = 0.0;
      for (size_t i = bi; i < bi + 3; ++i)
        for (size_t j = bj; j < bj + 3; ++j)
          bmax = fmax(bmax, fmax(fabs(F[i * n + j]), fabs(Ffd[i * n + j])));
      for (size_t i = bi; i < bi + 3; ++i)
        for (size_t j = bj; j < bj + 3; ++j) {
          const double a = F[i * n + j], b = Ffd[i * n + j];
          if (!(fabs(a - b) <= 0.015 * bmax))
            fail_msg("F(%zu,%zu) = %.10e, WGS-84 finite difference %.10e (block max %.3e)", i, j, a, b, bmax);
          if (bmax > 0.0) worst = fmax(worst, fabs(a - b) / bmax);
        }
    }
  print_message("[ T6.1 F   ] WGS-84: max |F - F_fd| / block max = %.2e\n", worst);
}

/*
 * T6.1 integrated (numerics.md 6.1), with this file's nonlinear reference in place of the
 * WGS-84 mechanization: integrate the true and a perturbed initial state (dx0 = [1 m x3,
 * 0.01 m/s x3, 1e-4 rad x3]) with identical perfect inputs, and propagate dx0 through the
 * filter's Phi along the true trajectory; after 10 s and 60 s the difference must equal Phi dx0
 * within 2 % of |Phi dx0| per block. Second order at every step, and Van Loan with
 * cov_decimation 10 (one exponential per 0.1 s over the mean F of a turning trajectory).
 */
static void t61_mismatch(nav_filter_discretisation disc, unsigned decimation, double scale,
                         double out_rel[2][3]) {
  const ref_model m = {false, 0.0, 0.0, 0.0};
  const nav_vec3 f = {0.3, 0.9, -9.79}, w = {0.001, -0.002, 0.03}; /* turning, slightly accelerating */
  ref_state t = f_test_state(), c;
  t.v = nav_vec3_make(30.0, -10.0, 0.5);
  const double dx0[9] = {1, 1, 1, 0.01, 0.01, 0.01, 1e-4, 1e-4, 1e-4};
  double RM, RN, dRM, dRN;
  ref_radii(&m, t.lat, &RM, &RN, &dRM, &dRN);
  c = t;
  c.lat += scale * dx0[0] / (RM + t.h);
  c.lon += scale * dx0[1] / ((RN + t.h) * cos(t.lat));
  c.h -= scale * dx0[2];
  c.v = nav_vec3_add(c.v, nav_vec3_make(scale * dx0[3], scale * dx0[4], scale * dx0[5]));
  /* C_c = exp(-[phi x]) C_t, i.e. q_c = q(-phi) (x) q_t */
  c.q = nav_quat_mul(nav_quat_from_rotvec(nav_vec3_make(-scale * dx0[6], -scale * dx0[7], -scale * dx0[8])),
                     t.q);

  nav_filter_config cfg = nav_filter_config_default();
  cfg.discretisation = disc;
  cfg.cov_decimation = decimation;
  cfg.gyro_bias_terms = 0u;
  cfg.accel_bias_terms = 0u;
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  double *x = nav_filter_internal_state(kf);
  double e0[9];
  ref_error(e0, &m, &c, &t); /* the applied dx0, re-measured */
  for (int i = 0; i < 9; ++i)
    x[i] = e0[i];
  const double dt = 0.01;
  const int marks[2] = {1000, 6000};
  int next = 0;
  for (int k = 1; k <= 6000; ++k) {
    /* Linearise at the middle of the interval: F from the truth half a step ahead. */
    ref_state mid = t;
    ref_rk4(&m, &mid, f, w, 0.5 * dt);
    const nav_filter_nav nav = ref_nav(&mid, f, w);
    assert_int_equal(nav_filter_predict(kf, &nav, dt), NAV_OK);
    ref_rk4(&m, &t, f, w, dt);
    ref_rk4(&m, &c, f, w, dt);
    if (k == marks[next]) {
      double e[9];
      assert_int_equal(nav_filter_flush(kf), NAV_OK);
      ref_error(e, &m, &c, &t);
      const double *xs = nav_filter_get_state(kf);
      for (int g = 0; g < 3; ++g) {
        double d2 = 0.0, p2 = 0.0;
        for (int i = 3 * g; i < 3 * g + 3; ++i) {
          d2 += (e[i] - xs[i]) * (e[i] - xs[i]);
          p2 += xs[i] * xs[i];
        }
        out_rel[next][g] = sqrt(d2 / p2);
      }
      ++next;
    }
  }
  nav_filter_destroy(kf);
}

static void test_T61_propagation(void **state) {
  (void)state;
  const nav_filter_discretisation discs[2] = {NAV_FILTER_DISC_SECOND_ORDER, NAV_FILTER_DISC_VAN_LOAN};
  const unsigned decs[2] = {1u, 10u};
  for (int d = 0; d < 2; ++d) {
    double full[2][3], half[2][3];
    t61_mismatch(discs[d], decs[d], 1.0, full);
    t61_mismatch(discs[d], decs[d], 0.5, half);
    for (int k = 0; k < 2; ++k)
      for (int g = 0; g < 3; ++g)
        assert_true(full[k][g] < 0.02);
    print_message("[ T6.1 int ] %s: rel. mismatch (r, v, phi) at 10 s %.1e %.1e %.1e, 60 s %.1e %.1e %.1e; "
                  "halved dx0 at 60 s %.1e %.1e %.1e\n",
                  d == 0 ? "2nd order" : "VL x10   ", full[0][0], full[0][1], full[0][2], full[1][0],
                  full[1][1], full[1][2], half[1][0], half[1][1], half[1][2]);
  }
}

/* ================================================================ T6.4 H matrices */

typedef struct h_case {
  ref_state t;
  nav_vec3 w; /* w_ib_b */
  nav_vec3 l; /* lever arm */
} h_case;

/* Nonlinear E6.3: z_pos = D_c (r_IMU,c - r_GNSS) + C_c l, with r_GNSS = true antenna + GNSS
 * error (D_t^-1 e), all as offsets from the true IMU position (no absolute-latitude rounding). */
static void z_pos_nl(double *z, const h_case *hc, const nav_filter_layout *lay, const double *dx) {
  const ref_model m = {false, 0.0, 0.0, 0.0};
  double RM, RN, dRM, dRN, RMc, RNc;
  ref_radii(&m, hc->t.lat, &RM, &RN, &dRM, &dRN);
  const double rm = RM + hc->t.h, rn = RN + hc->t.h, cl = cos(hc->t.lat);
  const nav_mat3 C_t = nav_quat_to_dcm(hc->t.q);
  const nav_vec3 phi = {dx[6], dx[7], dx[8]};
  const nav_mat3 AmI = expm1_neg_skew(phi);
  const nav_vec3 Cl_t = nav_mat3_mul_vec(C_t, hc->l);
  const nav_vec3 dCl = nav_mat3_mul_vec(AmI, Cl_t); /* (C_c - C_t) l */
  nav_vec3 e = nav_vec3_zero();
  if (lay->has_gnss_pos_gm)
    e = nav_vec3_make(dx[lay->idx_gnss_pos], dx[lay->idx_gnss_pos + 1], dx[lay->idx_gnss_pos + 2]);
  /* offsets in (lat, lon, h) */
  const double c_lat = dx[0] / rm, c_lon = dx[1] / (rn * cl), c_h = -dx[2];
  const nav_vec3 g_ned = nav_vec3_add(Cl_t, e);
  const double g_lat = g_ned.x / rm, g_lon = g_ned.y / (rn * cl), g_h = -g_ned.z;
  const double lat_c = hc->t.lat + c_lat, h_c = hc->t.h + c_h;
  ref_radii(&m, lat_c, &RMc, &RNc, &dRM, &dRN);
  z[0] = (c_lat - g_lat) * (RMc + h_c) + Cl_t.x + dCl.x;
  z[1] = (c_lon - g_lon) * (RNc + h_c) * cos(lat_c) + Cl_t.y + dCl.y;
  z[2] = -(c_h - g_h) + Cl_t.z + dCl.z;
}

/* Nonlinear E6.4: z_vel = v_ant,INS - v_ant,true with v_ant = v + C (w x l) - w_ie(lat) x (C l). */
static void z_vel_nl(double *z, const h_case *hc, const nav_filter_layout *lay, const double *dx) {
  const ref_model m = {false, 0.0, 0.0, 0.0};
  double RM, RN, dRM, dRN;
  ref_radii(&m, hc->t.lat, &RM, &RN, &dRM, &dRN);
  const double lat_c = hc->t.lat + dx[0] / (RM + hc->t.h);
  const nav_mat3 C_t = nav_quat_to_dcm(hc->t.q);
  const nav_mat3 AmI = expm1_neg_skew(nav_vec3_make(dx[6], dx[7], dx[8]));
  nav_vec3 dw = {dx[9], dx[10], dx[11]};
  if (lay->has_scale_factors)
    dw = nav_vec3_add(dw, nav_vec3_make(hc->w.x * dx[15], hc->w.y * dx[16], hc->w.z * dx[17]));
  const nav_vec3 w_c = nav_vec3_add(hc->w, dw);
  /* C_c (w_c x l) - C_t (w x l) = AmI C_t (w_c x l) + C_t (dw x l) */
  const nav_vec3 lev = nav_vec3_add(nav_mat3_mul_vec(AmI, nav_mat3_mul_vec(C_t, nav_vec3_cross(w_c, hc->l))),
                                    nav_mat3_mul_vec(C_t, nav_vec3_cross(dw, hc->l)));
  /* w_ie(lat_c) x (C_c l) - w_ie(lat_t) x (C_t l) */
  const nav_vec3 Cl_t = nav_mat3_mul_vec(C_t, hc->l), dCl = nav_mat3_mul_vec(AmI, Cl_t);
  const nav_vec3 ear = nav_vec3_add(
      nav_vec3_cross(nav_vec3_sub(ref_w_ie(lat_c), ref_w_ie(hc->t.lat)), nav_vec3_add(Cl_t, dCl)),
      nav_vec3_cross(ref_w_ie(hc->t.lat), dCl));
  z[0] = dx[3] + lev.x - ear.x;
  z[1] = dx[4] + lev.y - ear.y;
  z[2] = dx[5] + lev.z - ear.z;
}

/* T6.4: H_pos and H_vel against central differences of the nonlinear measurement functions,
 * step 1e-6 of the state scale, agreement 1e-5 relative. "Relative" per row: the mismatch of an
 * entry times its state scale, over the largest |H_ik| x scale_k of the row (the sensitivity of
 * that measurement to a typical error). Outputs are pre-filled with NaN. All 24 states. */
static void test_H_T64(void **state) {
  (void)state;
  const nav_filter_layout lay =
      nav_filter_layout_of(NAV_FILTER_STATE_SCALE_FACTORS | NAV_FILTER_STATE_GNSS_POS_GM);
  const size_t n = lay.n_states;
  h_case cases[3];
  cases[0].t = f_test_state();
  cases[0].w = nav_vec3_make(0.3, -0.2, 0.5);
  cases[0].l = nav_vec3_make(1.2, -0.4, -0.8);
  cases[1].t = f_test_state();
  cases[1].t.lat = -62.0 * NAV_DEG2RAD;
  cases[1].t.q =
      nav_euler_to_quat((nav_euler){-170.0 * NAV_DEG2RAD, 80.0 * NAV_DEG2RAD, -30.0 * NAV_DEG2RAD});
  cases[1].w = nav_vec3_make(-1.5, 0.02, 2.0);
  cases[1].l = nav_vec3_make(-0.3, 2.5, 0.1);
  cases[2].t = f_test_state();
  cases[2].w = nav_vec3_make(1e-4, 0.0, 5e-5); /* nearly static: the Earth-rate term matters */
  cases[2].l = nav_vec3_make(0.5, 0.5, -1.5);
  double worst[2] = {0.0, 0.0};
  for (int c = 0; c < 3; ++c) {
    const h_case *hc = &cases[c];
    const nav_filter_nav nav = ref_nav(&hc->t, nav_vec3_make(0, 0, -9.8), hc->w);
    for (int which = 0; which < 2; ++which) {
      double H[3 * NMAX], Hfd[3 * NMAX];
      for (size_t i = 0; i < 3 * n; ++i)
        H[i] = Hfd[i] = NAN;
      if (which == 0)
        nav_filter_build_H_pos(H, &lay, &nav, hc->l);
      else
        nav_filter_build_H_vel(H, &lay, &nav, hc->l);
      for (size_t j = 0; j < n; ++j) {
        double dxp[NMAX] = {0}, dxm[NMAX] = {0}, zp[3], zm[3];
        const double hstep = 1e-6 * state_scale(j, &lay);
        dxp[j] = hstep;
        dxm[j] = -hstep;
        if (which == 0) {
          z_pos_nl(zp, hc, &lay, dxp);
          z_pos_nl(zm, hc, &lay, dxm);
        } else {
          z_vel_nl(zp, hc, &lay, dxp);
          z_vel_nl(zm, hc, &lay, dxm);
        }
        for (int i = 0; i < 3; ++i)
          Hfd[(size_t)i * n + j] = (zp[i] - zm[i]) / (2.0 * hstep);
      }
      for (int i = 0; i < 3; ++i) {
        double rowmax = 0.0;
        for (size_t j = 0; j < n; ++j)
          rowmax = fmax(rowmax, fabs(H[(size_t)i * n + j]) * state_scale(j, &lay));
        for (size_t j = 0; j < n; ++j) {
          const double a = H[(size_t)i * n + j], b = Hfd[(size_t)i * n + j];
          assert_true(isfinite(a) && isfinite(b));
          const double rel = fabs(a - b) * state_scale(j, &lay) / rowmax;
          if (!(rel <= 1e-5))
            fail_msg("case %d %s H(%d,%zu) = %.12e, finite difference %.12e (rel %.2e)", c,
                     which ? "vel" : "pos", i, j, a, b, rel);
          worst[which] = fmax(worst[which], rel);
        }
      }
    }
  }
  print_message("[ T6.4     ] max relative mismatch: H_pos %.2e, H_vel %.2e\n", worst[0], worst[1]);
}

/* The residual helpers agree with the offset form used above and wrap longitude. */
static void test_gnss_residual_helpers(void **state) {
  (void)state;
  const ref_state t = f_test_state();
  const nav_mat3 C = nav_quat_to_dcm(t.q);
  const nav_vec3 l = {1.2, -0.4, -0.8};
  /* INS = truth and GNSS = true antenna (D^-1 C l away): z = 0 to the curvature of D (|l|^2/R). */
  const double rm = nav_earth_radius_meridian_m(t.lat) + t.h,
               rn = nav_earth_radius_prime_vertical_m(t.lat) + t.h;
  const nav_vec3 Cl = nav_mat3_mul_vec(C, l);
  const nav_geodetic ins = {t.lat, t.lon, t.h};
  const nav_geodetic ant = {t.lat + Cl.x / rm, t.lon + Cl.y / (rn * cos(t.lat)), t.h - Cl.z};
  const nav_vec3 z = nav_filter_gnss_pos_residual(ins, C, l, ant);
  assert_vec3_near(z, nav_vec3_zero(), 1e-8);
  /* Across the antimeridian: INS at lon = pi - 1e-7, GNSS at -pi + 1e-7, same lat/h, l = 0. */
  const nav_geodetic a = {0.3, NAV_PI - 1e-7, 10.0}, b = {0.3, -NAV_PI + 1e-7, 10.0};
  const nav_vec3 z2 = nav_filter_gnss_pos_residual(a, nav_mat3_identity(), nav_vec3_zero(), b);
  const double rn2 = nav_earth_radius_prime_vertical_m(0.3) + 10.0;
  assert_near(z2.y, -2e-7 * rn2 * cos(0.3), 1e-6);
  assert_near(z2.x, 0.0, 0.0);
  /* Velocity: v_ant = v + C (w x l) - w_ie x (C l); against v_GNSS = that, z = 0. */
  const nav_filter_nav nav = ref_nav(&t, nav_vec3_zero(), nav_vec3_make(0.3, -0.2, 0.5));
  const nav_vec3 v_ant =
      nav_vec3_sub(nav_vec3_add(t.v, nav_mat3_mul_vec(C, nav_vec3_cross(nav.w_ib_b_rps, l))),
                   nav_vec3_cross(nav_earth_rate_n_rps(t.lat), Cl));
  assert_vec3_near(nav_filter_gnss_vel_residual(&nav, l, v_ant), nav_vec3_zero(), 1e-13);
}

/* ================================================================ update safeguards */

/* Joseph form over 10^5 random updates (position and velocity, random attitude, lever arm,
 * latitude; R per axis from (1e-6 m)^2 to (1e4 m)^2, i.e. far below and far above the prior),
 * interleaved with predicts: every update succeeds, P stays exactly symmetric and positive
 * definite (Cholesky) with a positive diagonal. */
static void test_joseph_random_updates(void **state) {
  (void)state;
  const uint64_t seed = 0x5EED0005u;
  nav_test_print_seed("test_joseph_random_updates", seed);
  nav_rng rng;
  nav_rng_init(&rng, seed, 0, NAV_RNG_STREAM_USER);
  nav_filter_config cfg = nav_filter_config_default();
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  const size_t n = 15;
  double min_ratio = INFINITY;
  for (int k = 0; k < 100000; ++k) {
    nav_filter_nav nav;
    nav.lat_rad = (nav_rng_uniform(&rng) * 2.0 - 1.0) * 1.3;
    nav.h_m = nav_rng_uniform(&rng) * 3000.0;
    nav.v_eb_n_mps = nav_vec3_scale(nav_rng_gauss_vec3(&rng), 30.0);
    nav.C_b_n = nav_dcm_exp(nav_vec3_scale(nav_rng_gauss_vec3(&rng), 2.0));
    nav.f_ib_b_mps2 = nav_vec3_add(nav_vec3_make(0, 0, -9.8), nav_rng_gauss_vec3(&rng));
    nav.w_ib_b_rps = nav_vec3_scale(nav_rng_gauss_vec3(&rng), 0.3);
    if (k % 10 == 0) {
      const nav_status st = nav_filter_predict(kf, &nav, 0.1);
      if (st != NAV_OK) fail_msg("predict %d: %s", k, nav_filter_last_error(kf));
    }
    const nav_vec3 l = nav_vec3_scale(nav_rng_gauss_vec3(&rng), 1.5);
    nav_vec3 r;
    for (int i = 0; i < 3; ++i) {
      const double sd = pow(10.0, -6.0 + 10.0 * nav_rng_uniform(&rng));
      nav_vec3_set(&r, i, sd * sd);
    }
    const nav_vec3 z = nav_vec3_scale(nav_rng_gauss_vec3(&rng), 0.1);
    const nav_status st = (k & 1) ? nav_filter_update_gnss_vel(kf, &nav, z, &r, l)
                                  : nav_filter_update_gnss_pos(kf, &nav, z, &r, l);
    if (st != NAV_OK)
      fail_msg("update %d: %s (seed %llu)", k, nav_filter_last_error(kf), (unsigned long long)seed);
    assert_int_equal(nav_filter_reset_errors(kf), NAV_OK);
    const double *P = nav_filter_get_cov(kf);
    if (k % 1000 == 999) {
      for (size_t i = 0; i < n; ++i) {
        assert_true(P[i * n + i] > 0.0);
        for (size_t j = 0; j < i; ++j)
          assert_true(P[i * n + j] == P[j * n + i]);
      }
      double L[15 * 15];
      assert_int_equal(nav_matn_cholesky(L, P, n), NAV_OK);
      for (size_t i = 0; i < n; ++i)
        min_ratio = fmin(min_ratio, L[i * n + i] * L[i * n + i] / P[i * n + i]);
    }
  }
  print_message("[ Joseph   ] 1e5 updates OK; smallest pivot/diagonal ratio of chol(P) %.2e\n", min_ratio);
  nav_filter_destroy(kf);
}

/* Non-finite inputs and non-positive-definite covariances give NAV_ERR_NUMERIC with a message
 * and leave x and P exactly as they were; nothing is clamped. */
static void test_numeric_errors(void **state) {
  (void)state;
  nav_filter_config cfg = nav_filter_config_default();
  cfg.states = NAV_FILTER_STATE_GNSS_POS_GM;
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  const size_t n = nav_filter_get_layout(kf).n_states;
  assert_int_equal(n, 18);
  nav_filter_nav nav = t63_nav();
  assert_int_equal(nav_filter_predict(kf, &nav, 0.01), NAV_OK);
  double P0[NMAX * NMAX], x0[NMAX];
  memcpy(P0, nav_filter_get_cov(kf), n * n * sizeof(double));
  memcpy(x0, nav_filter_get_state(kf), n * sizeof(double));
#define UNCHANGED()                                                                                          \
  do {                                                                                                       \
    assert_memory_equal(nav_filter_get_cov(kf), P0, n *n * sizeof(double));                                  \
    assert_memory_equal(nav_filter_get_state(kf), x0, n * sizeof(double));                                   \
    assert_true(strlen(nav_filter_last_error(kf)) > 0);                                                      \
  } while (0)

  nav_filter_nav bad = nav;
  bad.f_ib_b_mps2.y = NAN;
  assert_int_equal(nav_filter_predict(kf, &bad, 0.01), NAV_ERR_NUMERIC);
  UNCHANGED();
  bad = nav;
  bad.C_b_n.m[2][1] = INFINITY;
  assert_int_equal(nav_filter_predict(kf, &bad, 0.01), NAV_ERR_NUMERIC);
  UNCHANGED();
  assert_int_equal(nav_filter_predict(kf, &nav, NAN), NAV_ERR_NUMERIC);
  assert_int_equal(nav_filter_predict(kf, &nav, 0.0), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_filter_predict(kf, &nav, -0.01), NAV_ERR_INVALID_ARG);
  bad = nav;
  bad.lat_rad = NAV_PI / 2.0;
  assert_int_equal(nav_filter_predict(kf, &bad, 0.01), NAV_ERR_OUT_OF_RANGE);
  UNCHANGED();

  const nav_vec3 l = {0.5, 0.0, -1.0};
  assert_int_equal(nav_filter_update_gnss_pos(kf, &nav, nav_vec3_make(1, NAN, 0), NULL, l), NAV_ERR_NUMERIC);
  UNCHANGED();
  nav_vec3 r = {1, 1, 0};
  assert_int_equal(nav_filter_update_gnss_pos(kf, &nav, nav_vec3_make(1, 2, 3), &r, l), NAV_ERR_INVALID_ARG);
  r.z = -1;
  assert_int_equal(nav_filter_update_gnss_vel(kf, &nav, nav_vec3_make(1, 2, 3), &r, l), NAV_ERR_INVALID_ARG);
  r.z = INFINITY;
  assert_int_equal(nav_filter_update_gnss_vel(kf, &nav, nav_vec3_make(1, 2, 3), &r, l), NAV_ERR_NUMERIC);
  assert_int_equal(
      nav_filter_update_gnss_vel(kf, &nav, nav_vec3_make(1, 2, 3), NULL, nav_vec3_make(0, NAN, 0)),
      NAV_ERR_NUMERIC);
  UNCHANGED();
  double H[NMAX] = {0}, z = 1.0, R = -1.0;
  H[0] = 1.0;
  assert_int_equal(nav_filter_update_linear(kf, 1, H, &z, &R), NAV_ERR_INVALID_ARG);
  R = 1.0;
  H[4] = NAN;
  assert_int_equal(nav_filter_update_linear(kf, 1, H, &z, &R), NAV_ERR_NUMERIC);
  UNCHANGED();

  /* Negative definite, indefinite, non-finite and asymmetric covariances are refused. */
  double Pbad[NMAX * NMAX];
  for (size_t i = 0; i < n * n; ++i)
    Pbad[i] = -P0[i];
  assert_int_equal(nav_filter_set_cov(kf, Pbad), NAV_ERR_NUMERIC);
  UNCHANGED();
  memcpy(Pbad, P0, sizeof Pbad);
  Pbad[7 * n + 7] = -1e-12; /* one negative variance */
  assert_int_equal(nav_filter_set_cov(kf, Pbad), NAV_ERR_NUMERIC);
  UNCHANGED();
  memcpy(Pbad, P0, sizeof Pbad);
  Pbad[0 * n + 1] = Pbad[1 * n + 0] = 2.0 * sqrt(P0[0] * P0[n + 1]); /* |correlation| = 2: indefinite */
  assert_int_equal(nav_filter_set_cov(kf, Pbad), NAV_ERR_NUMERIC);
  UNCHANGED();
  memcpy(Pbad, P0, sizeof Pbad);
  Pbad[3 * n + 3] = NAN;
  assert_int_equal(nav_filter_set_cov(kf, Pbad), NAV_ERR_NUMERIC);
  UNCHANGED();
  memcpy(Pbad, P0, sizeof Pbad);
  Pbad[2 * n + 5] = 1e-3;
  assert_int_equal(nav_filter_set_cov(kf, Pbad), NAV_ERR_INVALID_ARG);
  UNCHANGED();

  /* A P that is positive definite but so ill-conditioned that the update cannot keep it so:
   * perfectly correlated position states (rank-deficient up to rounding) and a huge-weight
   * update. The failure is reported, never repaired. */
  memset(Pbad, 0, sizeof Pbad);
  for (size_t i = 0; i < n; ++i)
    Pbad[i * n + i] = P0[i * n + i];
  Pbad[0] = 1.0;
  Pbad[n + 1] = 1.0;
  Pbad[1] = Pbad[n] = 1.0 - 1e-15;
  assert_int_equal(nav_filter_set_cov(kf, Pbad), NAV_OK);
  memcpy(P0, nav_filter_get_cov(kf), n * n * sizeof(double));
  const nav_vec3 rr = v3(1e-300);
  const nav_status st = nav_filter_update_gnss_pos(kf, &nav, nav_vec3_make(1, 2, 3), &rr, nav_vec3_zero());
  assert_int_equal(st, NAV_ERR_NUMERIC);
  UNCHANGED();
#undef UNCHANGED
  nav_filter_destroy(kf);
}

/* A scalar sanity check against the discrete algebraic Riccati equation: a GNSS GM state
 * (sigma, tau) observed directly with noise R every dt, Van Loan (exact: a = exp(-dt/tau),
 * Q = sigma^2 (1 - a^2)). The prior steady state solves p^2 + p (R (1 - a^2) - Q) - Q R = 0 and
 * the posterior is p R/(p + R); the GM block stays decoupled from the INS states. */
static void test_scalar_steady_state(void **state) {
  (void)state;
  nav_filter_config cfg = nav_filter_config_default();
  cfg.states = NAV_FILTER_STATE_GNSS_POS_GM;
  cfg.discretisation = NAV_FILTER_DISC_VAN_LOAN;
  cfg.gnss_pos_gm_sd_m = v3(2.0);
  cfg.gnss_pos_gm_tau_s = v3(100.0);
  cfg.init.gnss_pos_sd_m = v3(10.0);
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  const nav_filter_layout lay = nav_filter_get_layout(kf);
  const size_t n = lay.n_states, j = lay.idx_gnss_pos;
  const double dt = 0.5, R = 1.0, sigma = 2.0, tau = 100.0;
  const double a = exp(-dt / tau), Q = sigma * sigma * (1.0 - a * a);
  const double bq = R * (1.0 - a * a) - Q;
  const double p_prior = 0.5 * (-bq + sqrt(bq * bq + 4.0 * Q * R)), p_post = p_prior * R / (p_prior + R);
  double H[NMAX] = {0};
  H[j] = 1.0;
  const nav_filter_nav nav = t63_nav();
  double prior = 0.0;
  for (int k = 0; k < 2000; ++k) {
    assert_int_equal(nav_filter_predict(kf, &nav, dt), NAV_OK);
    prior = nav_filter_get_cov(kf)[j * n + j];
    const double zz = 0.0;
    assert_int_equal(nav_filter_update_linear(kf, 1, H, &zz, &R), NAV_OK);
  }
  assert_rel_near(prior, p_prior, 1e-10);
  assert_rel_near(nav_filter_get_cov(kf)[j * n + j], p_post, 1e-10);
  /* The innovation record: S = prior + R, y = 0, NIS = 0. */
  const nav_filter_innovation *in = nav_filter_last_innovation(kf);
  assert_int_equal(in->m, 1);
  assert_rel_near(in->S[0], p_prior + R, 1e-10);
  assert_near(in->nis, 0.0, 0.0);
  print_message("[ scalar   ] steady-state prior %.12f (DARE %.12f), posterior %.12f (%.12f)\n", prior,
                p_prior, nav_filter_get_cov(kf)[j * n + j], p_post);
  nav_filter_destroy(kf);
}

/* NIS and innovation of a first position update: no lever arm, x = 0, P diagonal:
 * S = diag(P_rr + R), NIS = sum z_i^2 / S_ii; the update moves x to K z. */
static void test_innovation_record(void **state) {
  (void)state;
  nav_filter_config cfg = nav_filter_config_default();
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  assert_int_equal(nav_filter_last_innovation(kf)->m, 0);
  const nav_filter_nav nav = t63_nav();
  const nav_vec3 z = {1.0, -2.0, 3.0}, r = {4.0, 1.0, 9.0};
  assert_int_equal(nav_filter_update_gnss_pos(kf, &nav, z, &r, nav_vec3_zero()), NAV_OK);
  const nav_filter_innovation *in = nav_filter_last_innovation(kf);
  assert_int_equal(in->m, 3);
  const double s[3] = {1.0 + 4.0, 1.0 + 1.0, 1.0 + 9.0}; /* P0 position 1 m^2 */
  assert_rel_near(in->nis, 1.0 / s[0] + 4.0 / s[1] + 9.0 / s[2], 1e-14);
  assert_near(in->y[1], -2.0, 0.0);
  assert_rel_near(in->S[4], s[1], 1e-15);
  nav_filter_error e;
  assert_int_equal(nav_filter_get_error(kf, &e), NAV_OK);
  assert_rel_near(e.dr_ned_m.x, 1.0 / s[0], 1e-14);
  assert_rel_near(e.dr_ned_m.z, 3.0 / s[2], 1e-14);
  /* Posterior position variance P R/(P + R). */
  assert_rel_near(nav_filter_get_cov(kf)[0], 4.0 / 5.0, 1e-14);
  nav_filter_destroy(kf);
}

/* ================================================================ feedback */

/* apply_correction undoes an error applied by the definitions of 6.1: position to second order
 * in dr/R, velocity and sensor estimates exactly, attitude exactly (exp(phi) exp(-phi) = I). */
static void test_apply_correction(void **state) {
  (void)state;
  const ref_state t = f_test_state();
  const double rm = nav_earth_radius_meridian_m(t.lat) + t.h,
               rn = nav_earth_radius_prime_vertical_m(t.lat) + t.h;
  nav_filter_error dx;
  memset(&dx, 0, sizeof dx);
  dx.dr_ned_m = nav_vec3_make(3.0, -4.0, 2.5);
  dx.dv_n_mps = nav_vec3_make(0.1, -0.2, 0.05);
  dx.phi_rad = nav_vec3_make(2e-3, -1e-3, 5e-3);
  dx.b_g_rps = nav_vec3_make(1e-5, 2e-5, -3e-5);
  dx.b_a_mps2 = nav_vec3_make(1e-3, 0.0, -2e-3);
  dx.s_g = nav_vec3_make(1e-4, 0, 0);
  dx.s_a = nav_vec3_make(0, 0, -2e-4);
  nav_filter_ins_state ins;
  ins.lat_rad = t.lat + dx.dr_ned_m.x / rm;
  ins.lon_rad = t.lon + dx.dr_ned_m.y / (rn * cos(t.lat));
  ins.h_m = t.h - dx.dr_ned_m.z;
  ins.v_eb_n_mps = nav_vec3_add(t.v, dx.dv_n_mps);
  ins.q_b_n = nav_quat_mul(nav_quat_from_rotvec(nav_vec3_scale(dx.phi_rad, -1.0)), t.q);
  ins.b_g_rps = nav_vec3_make(1e-4, 1e-4, 1e-4);
  ins.b_a_mps2 = v3(0.01);
  ins.s_g = v3(0.0);
  ins.s_a = v3(1e-3);
  nav_filter_ins_state out;
  nav_filter_apply_correction(&out, &ins, &dx);
  /* D^-1 at the INS instead of the truth: relative error dr/R ~ 1e-6 of 5 m -> 5e-6 m. */
  assert_near((out.lat_rad - t.lat) * rm, 0.0, 1e-5);
  assert_near((out.lon_rad - t.lon) * rn * cos(t.lat), 0.0, 1e-5);
  assert_near(out.h_m, t.h, 1e-12);
  assert_vec3_near(out.v_eb_n_mps, t.v, 1e-14);
  assert_quat_near(out.q_b_n, t.q, 2e-16 * 4);
  assert_vec3_near(out.b_g_rps, nav_vec3_make(1.1e-4, 1.2e-4, 0.7e-4), 1e-19);
  assert_vec3_near(out.s_a, nav_vec3_make(1e-3, 1e-3, 0.8e-3), 1e-18);
  /* In place, and across the antimeridian: the INS 1 m west of the truth at lon = pi - 1e-8
   * (dr_E = -1 m); the correction moves it 1 m east, past +pi, to a wrapped negative longitude. */
  memset(&dx, 0, sizeof dx);
  dx.dr_ned_m = nav_vec3_make(0.0, -1.0, 0.0);
  ins.lon_rad = NAV_PI - 1e-8;
  const nav_filter_ins_state before = ins;
  nav_filter_apply_correction(&ins, &ins, &dx);
  const double m_per_rad =
      (nav_earth_radius_prime_vertical_m(before.lat_rad) + before.h_m) * cos(before.lat_rad);
  assert_true(ins.lon_rad < 0.0 && ins.lon_rad > -NAV_PI);
  assert_near(nav_wrap_pi(ins.lon_rad - before.lon_rad) * m_per_rad, 1.0, 1e-9);
  assert_near(ins.lat_rad, before.lat_rad, 0.0);
}

/* reset_errors zeroes the INS blocks and keeps the GNSS position-error estimate and P. */
static void test_reset_keeps_gnss_states(void **state) {
  (void)state;
  nav_filter_config cfg = nav_filter_config_default();
  cfg.states = NAV_FILTER_STATE_SCALE_FACTORS | NAV_FILTER_STATE_GNSS_POS_GM;
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&cfg, &kf), NAV_OK);
  const nav_filter_layout lay = nav_filter_get_layout(kf);
  assert_int_equal(lay.n_states, 24);
  assert_int_equal(lay.idx_gnss_pos, 21);
  const nav_filter_nav nav = t63_nav();
  assert_int_equal(nav_filter_predict(kf, &nav, 0.01), NAV_OK);
  assert_int_equal(
      nav_filter_update_gnss_pos(kf, &nav, nav_vec3_make(2, -1, 3), NULL, nav_vec3_make(1, 0, 0)), NAV_OK);
  double P[NMAX * NMAX], x[NMAX];
  memcpy(P, nav_filter_get_cov(kf), sizeof P);
  memcpy(x, nav_filter_get_state(kf), sizeof x);
  assert_true(x[21] != 0.0 && x[0] != 0.0);
  assert_int_equal(nav_filter_reset_errors(kf), NAV_OK);
  const double *xr = nav_filter_get_state(kf);
  for (size_t i = 0; i < 21; ++i)
    assert_near(xr[i], 0.0, 0.0);
  for (size_t i = 21; i < 24; ++i)
    assert_near(xr[i], x[i], 0.0);
  assert_memory_equal(nav_filter_get_cov(kf), P, 24 * 24 * sizeof(double));
  nav_filter_error e;
  assert_int_equal(nav_filter_get_error(kf, &e), NAV_OK);
  assert_near(e.gnss_pos_m.x, x[21], 0.0);
  nav_filter_destroy(kf);
}

/* ================================================================ configuration */

static int issue_count;
static void count_issue(void *user, const char *path, const char *message) {
  (void)user;
  (void)path;
  (void)message;
  ++issue_count;
}

static void test_config_validate(void **state) {
  (void)state;
  nav_filter_config c = nav_filter_config_default();
  assert_int_equal(nav_filter_config_validate(&c, NULL, NULL), NAV_OK);
  c.cov_decimation = 0;
  c.init.att_sd_rad.z = 0.0; /* P0 must be positive definite */
  c.gyro_bias_gm_tau_s.y = -1.0;
  c.accel_vrw_mps_per_sqrt_s.x = NAN;
  c.states = 0x80u;
  c.discretisation = (nav_filter_discretisation)7;
  issue_count = 0;
  assert_int_equal(nav_filter_config_validate(&c, count_issue, NULL), NAV_ERR_INVALID_ARG);
  assert_int_equal(issue_count, 6);
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&c, &kf), NAV_ERR_INVALID_ARG);
  assert_null(kf);
  /* Scale-factor and GNSS fields are checked only when their blocks exist. */
  c = nav_filter_config_default();
  c.gnss_pos_gm_tau_s.x = 0.0;
  c.init.gyro_sf_sd.x = 0.0;
  assert_int_equal(nav_filter_config_validate(&c, NULL, NULL), NAV_OK);
  c.states = NAV_FILTER_STATE_GNSS_POS_GM;
  assert_int_equal(nav_filter_config_validate(&c, NULL, NULL), NAV_ERR_INVALID_ARG);
  nav_filter_destroy(NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_expm_rotation),
      cmocka_unit_test(test_expm_nilpotent),
      cmocka_unit_test(test_expm_diagonal_and_triangular),
      cmocka_unit_test(test_van_loan_T62),
      cmocka_unit_test(test_T63_van_loan),
      cmocka_unit_test(test_T63_second_order),
      cmocka_unit_test(test_T63_decimation),
      cmocka_unit_test(test_decimation_flush_on_update),
      cmocka_unit_test(test_F_exact_on_sphere),
      cmocka_unit_test(test_F_wgs84_within_neglected_terms),
      cmocka_unit_test(test_T61_propagation),
      cmocka_unit_test(test_H_T64),
      cmocka_unit_test(test_gnss_residual_helpers),
      cmocka_unit_test(test_joseph_random_updates),
      cmocka_unit_test(test_numeric_errors),
      cmocka_unit_test(test_scalar_steady_state),
      cmocka_unit_test(test_innovation_record),
      cmocka_unit_test(test_apply_correction),
      cmocka_unit_test(test_reset_keeps_gnss_states),
      cmocka_unit_test(test_config_validate),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
