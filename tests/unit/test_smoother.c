/*
 * RTS smoother (nav_smoother.h):
 * - linear-Gaussian check: a closed-loop run of the real filter (nav_filter, with feedback and
 *   resets) on a constant linearisation point, smoothed, against the batch solution computed
 *   independently as the conditional Gaussian E[x_k | all z] of the joint distribution of the
 *   record-epoch states and the measurements (dense transitions, no RTS recursion);
 * - simulated INS/GNSS drive with two 60 s outages (urban-drive.yaml, sensor errors the
 *   15-state filter models): smoothed sigma <= forward sigma at every record and every state,
 *   smoothed errors consistent with the smoothed sigmas, much smaller errors inside the outages;
 * - replay of the vendored 50 s slice of the long drive with a 15 s GNSS gap, and (when the
 *   shared data is present) the whole long drive with GNSS_outage.txt;
 * - error paths: call order, non-finite inputs, an indefinite covariance.
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
#include <unistd.h>

#include "filter/filter_internal.h"
#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_errors.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_io.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_smoother.h"
#include "navcore/nav_truth.h"

#define NM NAV_FILTER_MAX_STATES
#define NNM (NM * NM)
#define N 15 /* the 15-state layout of the error-path test */
#define NN (N * N)

/* ---------------------------------------------------------------- helpers (n x n, row-major) */

static void mat_mul(double *c, const double *a, const double *b, int n) {
  double t[NNM];
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double s = 0.0;
      for (int k = 0; k < n; ++k)
        s += a[i * n + k] * b[k * n + j];
      t[i * n + j] = s;
    }
  memcpy(c, t, (size_t)(n * n) * sizeof *t);
}

/* c = a b^T */
static void mat_mul_bt(double *c, const double *a, const double *b, int n) {
  double t[NNM];
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double s = 0.0;
      for (int k = 0; k < n; ++k)
        s += a[i * n + k] * b[j * n + k];
      t[i * n + j] = s;
    }
  memcpy(c, t, (size_t)(n * n) * sizeof *t);
}

static void eye(double *a, int n) {
  memset(a, 0, (size_t)(n * n) * sizeof *a);
  for (int i = 0; i < n; ++i)
    a[i * n + i] = 1.0;
}

static double rng_u(uint64_t *s) {
  *s ^= *s << 13;
  *s ^= *s >> 7;
  *s ^= *s << 17;
  return ((double)(*s >> 11) + 0.5) / 9007199254740992.0;
}

static double rng_gauss(uint64_t *s) {
  const double u1 = rng_u(s), u2 = rng_u(s);
  return sqrt(-2.0 * log(u1)) * cos(2.0 * NAV_PI * u2);
}

/* The error blocks in state order for a layout (n values). */
static void pack_error(double *x, const nav_filter_error *e, const nav_filter_layout *lay) {
  const nav_vec3 b[5] = {e->dr_ned_m, e->dv_n_mps, e->phi_rad, e->b_g_rps, e->b_a_mps2};
  for (int i = 0; i < 5; ++i) {
    x[3 * i] = b[i].x;
    x[3 * i + 1] = b[i].y;
    x[3 * i + 2] = b[i].z;
  }
  if (lay->has_scale_factors) {
    const nav_vec3 s2[2] = {e->s_g, e->s_a};
    for (int i = 0; i < 2; ++i) {
      x[15 + 3 * i] = s2[i].x;
      x[15 + 3 * i + 1] = s2[i].y;
      x[15 + 3 * i + 2] = s2[i].z;
    }
  }
  if (lay->has_gnss_pos_gm) {
    x[lay->idx_gnss_pos] = e->gnss_pos_m.x;
    x[lay->idx_gnss_pos + 1] = e->gnss_pos_m.y;
    x[lay->idx_gnss_pos + 2] = e->gnss_pos_m.z;
  }
}

static nav_filter_ins_state some_nominal(void) {
  nav_filter_ins_state s;
  memset(&s, 0, sizeof s);
  s.lat_rad = 0.7;
  s.lon_rad = 0.2;
  s.h_m = 100.0;
  s.v_eb_n_mps = nav_vec3_make(10.0, 5.0, 0.0);
  s.q_b_n = nav_euler_to_quat((nav_euler){0.1, -0.05, 1.0});
  return s;
}

/* ---------------------------------------------------------------- (a) linear-Gaussian toy */

#define TOY_STEPS_PER_REC 10
#define TOY_RECS 30 /* records 1..TOY_RECS after record 0 */
#define TOY_MAXMEAS 10
#define TOY_MAXZ (3 * TOY_MAXMEAS)

typedef struct toy_meas {
  int rec; /* record index */
  double H[3 * NM];
  double R[9];
  double z[3]; /* measurement of the TRUE error state (open-loop form) */
} toy_meas;

/* Process model of one triad as numerics.md 6.2 (independent of the library's code). */
static void toy_triad(double *proc, double *qc, int idx, unsigned terms, nav_vec3 sd, nav_vec3 tau,
                      nav_vec3 rw) {
  for (int i = 0; i < 3; ++i) {
    proc[idx + i] = 0.0;
    qc[idx + i] = 0.0;
    if (terms & NAV_FILTER_PROC_GM) {
      proc[idx + i] = -1.0 / nav_vec3_get(tau, i);
      qc[idx + i] += 2.0 * pow(nav_vec3_get(sd, i), 2) / nav_vec3_get(tau, i);
    }
    if (terms & NAV_FILTER_PROC_RW) qc[idx + i] += pow(nav_vec3_get(rw, i), 2);
  }
}

/*
 * The closed-loop filter on a constant linearisation point, smoothed, against the batch
 * conditional mean and covariance. @p states: nav_filter_config.states (with the GNSS GM block
 * the reset keeps those states, so the smoother's x_after path is exercised).
 */
static void linear_gaussian_case(unsigned states) {
  nav_filter_config fc = nav_filter_config_default();
  fc.states = states;
  fc.gyro_bias_terms = NAV_FILTER_PROC_GM | NAV_FILTER_PROC_RW;
  fc.gyro_bias_rw_rps_per_sqrt_s = nav_vec3_make(1e-7, 2e-7, 3e-7);
  nav_filter *kf = NULL;
  assert_int_equal(nav_filter_create(&fc, &kf), NAV_OK);
  const nav_filter_layout lay = nav_filter_get_layout(kf);
  const int n = (int)lay.n_states;
  nav_smoother_config scfg = nav_smoother_config_default();
  scfg.filter = fc;
  nav_smoother *sm = NULL;
  assert_int_equal(nav_smoother_create(&scfg, &sm), NAV_OK);

  /* Constant linearisation point: moving, attitude not level, with rotation and force. */
  const nav_filter_ins_state nom = some_nominal();
  nav_filter_nav nav;
  nav.lat_rad = nom.lat_rad;
  nav.h_m = nom.h_m;
  nav.v_eb_n_mps = nom.v_eb_n_mps;
  nav.C_b_n = nav_quat_to_dcm(nom.q_b_n);
  nav.f_ib_b_mps2 = nav_vec3_make(0.3, -0.2, -9.8);
  nav.w_ib_b_rps = nav_vec3_make(0.01, -0.02, 0.03);
  const double dt = 0.01;

  /* Independent transition and noise per record interval: dense product of the per-step E6.2
   * transitions and the transported per-step noise (Phi_s Q_c Phi_s^T + Q_c) dt / 2. */
  double F[NNM] = {0}, GQG[NNM] = {0}, proc[NM] = {0}, qc[NM] = {0};
  for (int i = 0; i < 3; ++i) {
    qc[3 + i] = pow(nav_vec3_get(fc.accel_vrw_mps_per_sqrt_s, i), 2);
    qc[6 + i] = pow(nav_vec3_get(fc.gyro_arw_rad_per_sqrt_s, i), 2);
  }
  toy_triad(proc, qc, 9, fc.gyro_bias_terms, fc.gyro_bias_gm_sd_rps, fc.gyro_bias_gm_tau_s,
            fc.gyro_bias_rw_rps_per_sqrt_s);
  toy_triad(proc, qc, 12, fc.accel_bias_terms, fc.accel_bias_gm_sd_mps2, fc.accel_bias_gm_tau_s,
            fc.accel_bias_rw_mps2_per_sqrt_s);
  if (lay.has_gnss_pos_gm)
    toy_triad(proc, qc, (int)lay.idx_gnss_pos, NAV_FILTER_PROC_GM, fc.gnss_pos_gm_sd_m, fc.gnss_pos_gm_tau_s,
              nav_vec3_zero());
  const nav_filter_earth_terms earth = nav_filter_earth_terms_wgs84(nav.lat_rad, nav.h_m);
  nav_filter_build_F(F, &lay, &nav, &earth, proc);
  nav_filter_build_GQG(GQG, &lay, nav.C_b_n, qc);
  double Phis[NNM] = {0}, Qs[NNM] = {0}, A[NNM] = {0}, T[NNM] = {0};
  for (int i = 0; i < n * n; ++i)
    A[i] = F[i] * dt;
  mat_mul(T, A, A, n);
  eye(Phis, n);
  for (int i = 0; i < n * n; ++i)
    Phis[i] += A[i] + 0.5 * T[i];
  for (int i = 0; i < n * n; ++i)
    T[i] = GQG[i] * dt;
  mat_mul(Qs, Phis, T, n);
  mat_mul_bt(Qs, Qs, Phis, n);
  for (int i = 0; i < n * n; ++i)
    Qs[i] = 0.5 * (Qs[i] + T[i]);
  double PhiR[NNM] = {0}, QR[NNM] = {0};
  eye(PhiR, n);
  memset(QR, 0, sizeof QR);
  for (int s = 0; s < TOY_STEPS_PER_REC; ++s) {
    mat_mul(PhiR, Phis, PhiR, n);
    mat_mul(QR, Phis, QR, n);
    mat_mul_bt(QR, QR, Phis, n);
    for (int i = 0; i < n * n; ++i)
      QR[i] += Qs[i];
  }

  /* Measurements: position at records 5, 10, ..., 30 (with the GNSS error states when present);
   * velocity too at 10 and 20 (a second update at the same epoch); an attitude-and-bias mixing
   * H at 15. Truth drawn from P0 and propagated without process noise (z is just data here: the
   * equivalence holds for any z). */
  toy_meas meas[TOY_MAXMEAS];
  int nm = 0;
  uint64_t rs = 0x9E3779B97F4A7C15ull;
  double P0[NNM];
  memcpy(P0, nav_filter_get_cov(kf), (size_t)(n * n) * sizeof *P0);
  static double etr[TOY_RECS + 1][NM];
  for (int i = 0; i < n; ++i)
    etr[0][i] = sqrt(P0[i * n + i]) * rng_gauss(&rs);
  for (int k = 1; k <= TOY_RECS; ++k)
    for (int i = 0; i < n; ++i) {
      double s = 0.0;
      for (int j = 0; j < n; ++j)
        s += PhiR[i * n + j] * etr[k - 1][j];
      etr[k][i] = s;
    }
  for (int k = 5; k <= TOY_RECS; k += 5) {
    for (int kind = 0; kind < 3; ++kind) {
      if (kind == 1 && k % 10 != 0) continue;
      if (kind == 2 && k != 15) continue;
      toy_meas *m = &meas[nm++];
      memset(m, 0, sizeof *m);
      m->rec = k;
      for (int r = 0; r < 3; ++r) {
        if (kind == 0) {
          m->H[r * n + r] = 1.0;
          if (lay.has_gnss_pos_gm) m->H[r * n + (int)lay.idx_gnss_pos + r] = -1.0;
        }
        if (kind == 1) m->H[r * n + 3 + r] = 1.0;
        if (kind == 2) {
          m->H[r * n + 6 + r] = 100.0;            /* 1 mrad -> 0.1 */
          m->H[r * n + 9 + (r + 1) % 3] = 1000.0; /* bias coupling */
          m->H[r * n + r] = 0.5;
        }
        const double sd = kind == 0 ? 0.05 : kind == 1 ? 0.01 : 0.02;
        m->R[r * 3 + r] = sd * sd;
      }
      for (int r = 0; r < 3; ++r) {
        double s = 0.0;
        for (int j = 0; j < n; ++j)
          s += m->H[r * n + j] * etr[k][j];
        m->z[r] = s + sqrt(m->R[r * 3 + r]) * rng_gauss(&rs);
      }
    }
  }

  /* Forward: closed loop. The INS offset c (the corrections fed back so far) propagates with the
   * transition; the filter sees z - H c, its estimate is fed back and the error state reset
   * (GNSS error states are kept by the reset: they are never fed back). */
  assert_int_equal(nav_smoother_begin(sm, 0.0, &nom, nav_filter_get_cov(kf), nav_filter_get_state(kf)),
                   NAV_OK);
  double c[NM] = {0};
  static double cr[TOY_RECS + 1][NM];
  memset(cr, 0, sizeof cr);
  int mi = 0;
  for (int k = 1; k <= TOY_RECS; ++k) {
    for (int s = 0; s < TOY_STEPS_PER_REC; ++s) {
      assert_int_equal(nav_filter_predict(kf, &nav, dt), NAV_OK);
      assert_int_equal(
          nav_smoother_step(sm, dt * (double)((k - 1) * TOY_STEPS_PER_REC + s + 1), &nav, dt, &nom), NAV_OK);
    }
    double cn[NM];
    for (int i = 0; i < n; ++i) {
      double sum = 0.0;
      for (int j = 0; j < n; ++j)
        sum += PhiR[i * n + j] * c[j];
      cn[i] = sum;
    }
    memcpy(c, cn, sizeof c);
    /* Odd records: mark before the updates (the update completes the record); even: after. */
    if (k % 2 == 1) assert_int_equal(nav_smoother_mark(sm), NAV_OK);
    for (; mi < nm && meas[mi].rec == k; ++mi) {
      const toy_meas *m = &meas[mi];
      double z[3];
      for (int r = 0; r < 3; ++r) {
        double s = 0.0;
        for (int j = 0; j < n; ++j)
          s += m->H[r * n + j] * c[j];
        z[r] = m->z[r] - s;
      }
      assert_int_equal(nav_filter_update_linear(kf, 3, m->H, z, m->R), NAV_OK);
      double d[NM];
      memcpy(d, nav_filter_get_state(kf), (size_t)n * sizeof *d);
      assert_int_equal(nav_filter_reset_errors(kf), NAV_OK);
      const double *xa = nav_filter_get_state(kf);
      for (int i = 0; i < n; ++i) {
        d[i] -= xa[i];
        c[i] += d[i];
      }
      assert_int_equal(nav_smoother_update(sm, &nom, nav_filter_get_cov(kf), xa, d), NAV_OK);
    }
    if (k % 2 == 0) assert_int_equal(nav_smoother_mark(sm), NAV_OK);
    memcpy(cr[k], c, sizeof c);
    /* The recorded covariance is the filter's: its own P after updates, and between them the
     * smoother's propagation, which must agree with the filter's (same E6.2 step). */
    nav_smoother_epoch ek;
    assert_int_equal(nav_smoother_get(sm, (size_t)k, &ek), NAV_OK);
    const double *Pf = nav_filter_get_cov(kf);
    for (int i = 0; i < n; ++i)
      assert_rel_near(ek.sd_forward[i], sqrt(Pf[i * n + i]), 1e-12);
  }
  assert_int_equal(nav_smoother_count(sm), TOY_RECS + 1);
  assert_int_equal(nav_smoother_run(sm), NAV_OK);

  /* Batch: prior marginals S_k, cross covariances Cov(e_i, e_j) = Phi^(i-j) S_j (i >= j). */
  static double S[TOY_RECS + 1][NNM], Tp[TOY_RECS + 1][NNM];
  memcpy(S[0], P0, sizeof P0);
  eye(Tp[0], n);
  for (int k = 1; k <= TOY_RECS; ++k) {
    mat_mul(S[k], PhiR, S[k - 1], n);
    mat_mul_bt(S[k], S[k], PhiR, n);
    for (int i = 0; i < n * n; ++i)
      S[k][i] += QR[i];
    mat_mul(Tp[k], PhiR, Tp[k - 1], n); /* PhiR^k */
  }
  const int nz = 3 * nm;
  /* Cov(e_i, z) for every record i (n x nz) and Szz. */
  static double Cez[TOY_RECS + 1][NM * TOY_MAXZ];
  double Szz[TOY_MAXZ * TOY_MAXZ], Lz[TOY_MAXZ * TOY_MAXZ], Z[TOY_MAXZ];
  for (int i = 0; i <= TOY_RECS; ++i)
    for (int q = 0; q < nm; ++q) {
      const int j = meas[q].rec;
      double Cij[NNM]; /* Cov(e_i, e_j) */
      if (i >= j)
        mat_mul(Cij, Tp[i - j], S[j], n);
      else
        mat_mul_bt(Cij, S[i], Tp[j - i], n);
      for (int a = 0; a < n; ++a)
        for (int r = 0; r < 3; ++r) {
          double s = 0.0;
          for (int b = 0; b < n; ++b)
            s += Cij[a * n + b] * meas[q].H[r * n + b];
          Cez[i][a * nz + 3 * q + r] = s;
        }
    }
  for (int q = 0; q < nm; ++q) {
    for (int r = 0; r < 3; ++r)
      Z[3 * q + r] = meas[q].z[r];
    const int j = meas[q].rec;
    for (int p = 0; p < nm; ++p)
      for (int r = 0; r < 3; ++r)
        for (int u = 0; u < 3; ++u) {
          /* Cov(z_q, z_p) = H_q Cov(e_jq, z_p) (+ R) */
          double s = 0.0;
          for (int a = 0; a < n; ++a)
            s += meas[q].H[r * n + a] * Cez[j][a * nz + 3 * p + u];
          if (p == q) s += meas[q].R[r * 3 + u];
          Szz[(3 * q + r) * nz + 3 * p + u] = s;
        }
  }
  nav_matn_symmetrize(Szz, (size_t)nz);
  assert_int_equal(nav_matn_cholesky(Lz, Szz, (size_t)nz), NAV_OK);
  double w[TOY_MAXZ];
  nav_matn_chol_solve(w, Lz, Z, (size_t)nz, 1);

  double worst_x = 0.0, worst_sd = 0.0, gain = 0.0;
  for (int i = 0; i <= TOY_RECS; ++i) {
    nav_smoother_epoch e;
    assert_int_equal(nav_smoother_get(sm, (size_t)i, &e), NAV_OK);
    double xs[NM];
    pack_error(xs, &e.dx_smoothed, &lay);
    /* Batch covariance: S_i - Cez Szz^-1 Cez^T (diagonal only). */
    static double Ct[TOY_MAXZ * NM], X[TOY_MAXZ * NM];
    for (int a = 0; a < n; ++a)
      for (int q = 0; q < nz; ++q)
        Ct[q * n + a] = Cez[i][a * nz + q];
    nav_matn_chol_solve(X, Lz, Ct, (size_t)nz, (size_t)n);
    for (int a = 0; a < n; ++a) {
      double mean = 0.0, red = 0.0;
      for (int q = 0; q < nz; ++q) {
        mean += Cez[i][a * nz + q] * w[q];
        red += Ct[q * n + a] * X[q * n + a];
      }
      const double var = S[i][a * n + a] - red;
      assert_true(var > 0.0);
      const double sd = sqrt(var);
      /* Smoothed estimate of the true error = offset fed back so far + smoothed residual error. */
      const double est = cr[i][a] + xs[a];
      worst_x = fmax(worst_x, fabs(est - mean) / sd);
      worst_sd = fmax(worst_sd, fabs(e.sd_smoothed[a] - sd) / sd);
      gain = fmax(gain, e.sd_forward[a] / e.sd_smoothed[a]);
      /* Smoothing never loses information. */
      assert_true(e.sd_smoothed[a] <= e.sd_forward[a] * (1.0 + 1e-12));
    }
  }
  print_message("linear toy, %d states (%d records, %d updates): max |RTS - batch| %.2e sigma (mean), %.2e "
                "(sigma, relative); largest sigma reduction by smoothing x%.1f\n",
                n, TOY_RECS + 1, nm, worst_x, worst_sd, gain);
  /* Rounding level: the two computations share no code beyond F, G Q G^T and the Cholesky. */
  assert_true(worst_x < 1e-9);
  assert_true(worst_sd < 1e-9);
  assert_true(gain > 2.0); /* the case is informative: smoothing changes something */
  nav_smoother_destroy(sm);
  nav_filter_destroy(kf);
}

static void test_linear_gaussian_equals_batch(void **state) {
  (void)state;
  linear_gaussian_case(0u);
}

static void test_linear_gaussian_gnss_states(void **state) {
  (void)state;
  linear_gaussian_case(NAV_FILTER_STATE_GNSS_POS_GM);
}

/* ---------------------------------------------------------------- (b) simulated drive */

static void test_simulated_outage(void **state) {
  (void)state;
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(NAV_SOURCE_DIR "/scenes/urban-drive.yaml", sc, NULL, NULL), NAV_OK);
  /* Only the sensor errors the 15-state filter models (noise, turn-on and GM biases): the check
   * is of the smoother, not of the filter's model mismatch. */
  const unsigned keep =
      NAV_IMU_TERM_NOISE | NAV_IMU_TERM_BIAS_TURN_ON | NAV_IMU_TERM_BIAS_GM | NAV_IMU_TERM_BIAS_RW;
  sc->imu.model.gyro.terms &= keep;
  sc->imu.model.accel.terms &= keep;
  nav_truth *truth = NULL;
  char msg[256] = "";
  assert_int_equal(nav_truth_create_msg(sc, &truth, msg, sizeof msg), NAV_OK);
  const nav_frame frame = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  nav_imu_model *imu = NULL;
  nav_gnss_model *gnss = NULL;
  assert_int_equal(nav_imu_model_create(&sc->imu.model, sc->simulation.seed, 0, &imu), NAV_OK);
  assert_int_equal(nav_gnss_model_create(&sc->gnss.model, &frame, sc->simulation.seed, 0, &gnss), NAV_OK);
  nav_ins_gnss_config cfg = nav_ins_gnss_config_from_scene(sc);
  const bool gm = (cfg.filter.states & NAV_FILTER_STATE_GNSS_POS_GM) != 0u;
  nav_smoother_config scfg = nav_smoother_config_default();
  scfg.filter = cfg.filter;
  nav_smoother *sm = NULL;
  assert_int_equal(nav_smoother_create(&scfg, &sm), NAV_OK);
  cfg.smoother = sm;

  /* Initial state: the truth displaced by one sigma of the scene's initial errors (within P0). */
  nav_traj_state ts;
  assert_int_equal(nav_truth_state(truth, 0.0, &ts), NAV_OK);
  const nav_local_view v0 = nav_frame_view(&frame, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
  const nav_scene_initial_errors *ie = &sc->initial_errors;
  nav_ins_state s0 = {0.0, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f};
  s0.r_fb_f_m = nav_vec3_add(s0.r_fb_f_m, nav_mat3_tmul_vec(v0.C_f_n, ie->pos_sd_m));
  s0.v_fb_f_mps =
      nav_vec3_add(s0.v_fb_f_mps, nav_mat3_tmul_vec(v0.C_f_n, nav_vec3_scale(ie->vel_sd_mps, -1.0)));
  const nav_vec3 phi_f = nav_mat3_tmul_vec(v0.C_f_n, ie->att_sd_rad);
  s0.q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_rotvec(nav_vec3_scale(phi_f, -1.0)), ts.q_b_f));
  nav_ins_gnss *x = NULL;
  assert_int_equal(nav_ins_gnss_create(&cfg, &s0, &x), NAV_OK);

  size_t cap = (size_t)(n / 10 + 1000), stored = 0;
  nav_traj_state *tr = malloc(cap * sizeof *tr);
  assert_non_null(tr);
  tr[stored++] = ts;
  int64_t next_epoch = 0;
  for (int64_t k = 1; k <= n; ++k) {
    nav_imu_increment ideal, meas;
    assert_int_equal(nav_truth_imu(truth, k, &ideal), NAV_OK);
    assert_int_equal(nav_imu_model_apply(imu, &ideal, &meas), NAV_OK);
    if (nav_ins_gnss_step(x, &meas) != NAV_OK) fail_msg("%s", nav_ins_gnss_last_error(x));
    for (;;) {
      const double tf = nav_gnss_model_epoch_time_s(gnss, next_epoch);
      if (!(tf <= meas.t_s + 0.5 * meas.dt_s)) break;
      const int64_t ep = next_epoch++;
      if (tf < meas.t_s - 0.5 * meas.dt_s) continue;
      nav_traj_state tf_state;
      assert_int_equal(nav_truth_state(truth, tf, &tf_state), NAV_OK);
      nav_gnss_fix fix;
      bool has = false;
      assert_int_equal(nav_gnss_model_measure(gnss, ep, &tf_state, &fix, &has), NAV_OK);
      if (!has) continue;
      nav_ins_gnss_fix f = {fix.t_s, fix.pos, fix.pos_sd_m, true, fix.v_fa_n_mps, fix.vel_sd_mps};
      if (gm) f.pos_sd_m = sc->gnss.model.pos_white_sd_m;
      if (nav_ins_gnss_update(x, &f) != NAV_OK) fail_msg("%s", nav_ins_gnss_last_error(x));
    }
    if (k % 10 == 0) assert_int_equal(nav_smoother_mark(sm), NAV_OK);
    if (nav_smoother_count(sm) > stored) {
      assert_int_equal(nav_truth_state(truth, meas.t_s, &ts), NAV_OK);
      while (stored < nav_smoother_count(sm)) {
        assert_true(stored < cap);
        tr[stored++] = ts;
      }
    }
  }
  const nav_status st = nav_smoother_run(sm);
  if (st != NAV_OK) fail_msg("%s", nav_smoother_last_error(sm));

  /* Per record: sigma ordering everywhere; errors against the smoothed sigmas; outage RMS. */
  const size_t nrec = nav_smoother_count(sm);
  const size_t ns = nav_smoother_layout(sm).n_states;
  long inside3 = 0, total = 0;
  double sum_f[2] = {0, 0}, sum_s[2] = {0, 0}, sig_f[2] = {0, 0}, sig_s[2] = {0, 0};
  long cnt[2] = {0, 0};
  double worst_ratio = 0.0;
  for (size_t k = 0; k < nrec; ++k) {
    nav_smoother_epoch e;
    assert_int_equal(nav_smoother_get(sm, k, &e), NAV_OK);
    for (size_t i = 0; i < ns; ++i) {
      worst_ratio = fmax(worst_ratio, e.sd_smoothed[i] / e.sd_forward[i]);
      assert_true(e.sd_smoothed[i] <= e.sd_forward[i] * (1.0 + 1e-9));
    }
    const nav_ins_state ss = nav_ins_gnss_state_ecef(&e.smoothed, e.t_s);
    const nav_ins_state sf = nav_ins_gnss_state_ecef(&e.forward, e.t_s);
    const nav_epoch_errors es = nav_errors_compute(&frame, &tr[k], &ss);
    const nav_epoch_errors ef = nav_errors_compute(&frame, &tr[k], &sf);
    total++;
    if (fabs(es.pos_err_n_m.x) <= 3.0 * e.sd_smoothed[0] && fabs(es.pos_err_n_m.y) <= 3.0 * e.sd_smoothed[1])
      inside3++;
    for (int g = 0; g < (int)sc->gnss.model.outage_count && g < 2; ++g) {
      const nav_gnss_outage *o = &sc->gnss.model.outages[g];
      if (e.t_s > o->t0_s && e.t_s < o->t1_s) {
        sum_f[g] += ef.pos_err_h_m * ef.pos_err_h_m;
        sum_s[g] += es.pos_err_h_m * es.pos_err_h_m;
        sig_f[g] += e.sd_forward[0] * e.sd_forward[0] + e.sd_forward[1] * e.sd_forward[1];
        sig_s[g] += e.sd_smoothed[0] * e.sd_smoothed[0] + e.sd_smoothed[1] * e.sd_smoothed[1];
        cnt[g]++;
      }
    }
  }
  const double frac = (double)inside3 / (double)total;
  print_message(
      "simulated drive (%zu states): %zu records, %zu bytes; N and E within 3 smoothed sigma at %.1f %% of "
      "them; largest sd_s/sd_f %.6f\n",
      ns, nrec, nav_smoother_memory_bytes(sm), 100.0 * frac, worst_ratio);
  for (int g = 0; g < 2; ++g) {
    assert_true(cnt[g] > 100);
    const double rf = sqrt(sum_f[g] / (double)cnt[g]), rs = sqrt(sum_s[g] / (double)cnt[g]);
    const double pf = sqrt(sig_f[g] / (double)cnt[g]), ps = sqrt(sig_s[g] / (double)cnt[g]);
    print_message("outage %d: horizontal RMS error forward %.3f m, smoothed %.3f m (ratio %.3f); predicted "
                  "sigma forward %.3f m, smoothed %.3f m (ratio %.3f)\n",
                  g + 1, rf, rs, rs / rf, pf, ps, ps / pf);
    /* The filter's own prediction says how much smoothing must help inside a bracketed outage;
     * the realised errors must agree with each side's sigma (a single run: 3 sigma). */
    assert_true(ps / pf < 0.5);
    assert_true(rs <= 3.0 * ps);
    assert_true(rs < rf);
  }
  /* A 2-D 3-sigma box holds 99.5 % of a Gaussian; 90 % leaves room for the correlated epochs of
   * one run (numerics.md T6.5 uses the same 90 % rule). */
  assert_true(frac >= 0.90);
  free(tr);
  nav_ins_gnss_destroy(x);
  nav_smoother_destroy(sm);
  nav_gnss_model_destroy(gnss);
  nav_imu_model_destroy(imu);
  nav_truth_destroy(truth);
  free(sc);
}

/* ---------------------------------------------------------------- (c) replay */

typedef struct replay_ctx {
  nav_smoother *sm;
  nav_frame frame;
  size_t n, cap;
  double *t;
  nav_traj_state *ref;
  nav_epoch_errors *fwd;
} replay_ctx;

static nav_callback_result on_rec(void *user, const nav_replay_record *r) {
  replay_ctx *c = user;
  c->frame = *r->frame;
  if (nav_smoother_mark(c->sm) != NAV_OK) return NAV_STOP;
  if (!r->ref) return NAV_CONTINUE;
  if (c->n == c->cap) {
    c->cap = c->cap ? 2 * c->cap : 1024;
    c->t = realloc(c->t, c->cap * sizeof *c->t);
    c->ref = realloc(c->ref, c->cap * sizeof *c->ref);
    c->fwd = realloc(c->fwd, c->cap * sizeof *c->fwd);
    if (!c->t || !c->ref || !c->fwd) return NAV_STOP;
  }
  c->t[c->n] = r->nav->t_s;
  c->ref[c->n] = *r->ref;
  c->fwd[c->n] = *r->err;
  c->n++;
  return NAV_CONTINUE;
}

/* Replay with the smoother; returns, per closed GNSS gap, the smoothed horizontal error and
 * sigma at its end and the largest smoothed error inside it. */
static void replay_smoothed(nav_replay_config *c, nav_replay_summary *sum, double *sm_end_h,
                            double *sm_end_sd, double *sm_max_in, double *fw_max_in, double *rms_f,
                            double *rms_s) {
  nav_smoother_config scfg = nav_smoother_config_default();
  scfg.filter = c->nav.filter;
  replay_ctx ctx;
  memset(&ctx, 0, sizeof ctx);
  assert_int_equal(nav_smoother_create(&scfg, &ctx.sm), NAV_OK);
  c->nav.smoother = ctx.sm;
  c->record = on_rec;
  c->user = &ctx;
  nav_diag d;
  memset(&d, 0, sizeof d);
  assert_int_equal(nav_replay_run(c, sum, &d), NAV_OK);
  if (nav_smoother_run(ctx.sm) != NAV_OK) fail_msg("%s", nav_smoother_last_error(ctx.sm));
  size_t j = 0;
  double ss = 0.0, sf = 0.0;
  long m = 0;
  for (long g = 0; g < sum->gap_count; ++g) {
    sm_end_h[g] = NAN;
    sm_end_sd[g] = NAN;
    sm_max_in[g] = 0.0;
    fw_max_in[g] = 0.0;
  }
  for (size_t k = 0; k < nav_smoother_count(ctx.sm); ++k) {
    nav_smoother_epoch e;
    assert_int_equal(nav_smoother_get(ctx.sm, k, &e), NAV_OK);
    for (size_t i = 0; i < nav_smoother_layout(ctx.sm).n_states; ++i)
      assert_true(e.sd_smoothed[i] <= e.sd_forward[i] * (1.0 + 1e-9));
    while (j < ctx.n && ctx.t[j] < e.t_s - 1e-6)
      ++j;
    if (j >= ctx.n || fabs(ctx.t[j] - e.t_s) > 1e-6) continue;
    const nav_ins_state s = nav_ins_gnss_state_ecef(&e.smoothed, e.t_s);
    const nav_epoch_errors es = nav_errors_compute(&ctx.frame, &ctx.ref[j], &s);
    ss += es.pos_err_h_m * es.pos_err_h_m;
    sf += ctx.fwd[j].pos_err_h_m * ctx.fwd[j].pos_err_h_m;
    m++;
    for (long g = 0; g < sum->gap_count; ++g) {
      const nav_replay_gap *gp = &sum->gaps[g];
      if (fabs(e.t_s - gp->t1_s) <= 1e-6) {
        sm_end_h[g] = es.pos_err_h_m;
        sm_end_sd[g] = hypot(e.sd_smoothed[0], e.sd_smoothed[1]);
      }
      if (e.t_s > gp->t0_s && e.t_s < gp->t1_s) {
        sm_max_in[g] = fmax(sm_max_in[g], es.pos_err_h_m);
        fw_max_in[g] = fmax(fw_max_in[g], ctx.fwd[j].pos_err_h_m);
      }
    }
  }
  assert_true(m > 0);
  *rms_f = sqrt(sf / (double)m);
  *rms_s = sqrt(ss / (double)m);
  print_message(
      "  %zu records, %.1f MiB; horizontal RMS at the %ld output epochs: forward %.4f m, smoothed %.4f m\n",
      nav_smoother_count(ctx.sm), (double)nav_smoother_memory_bytes(ctx.sm) / 1048576.0, m, *rms_f, *rms_s);
  nav_smoother_destroy(ctx.sm);
  free(ctx.t);
  free(ctx.ref);
  free(ctx.fwd);
}

static nav_replay_config scene_config(const char *scene) {
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(scene, sc, NULL, NULL), NAV_OK);
  nav_replay_config c = nav_replay_config_default();
  c.nav = nav_ins_gnss_config_from_scene(sc);
  c.nav.ins.earth_model = NAV_EARTH_WGS84;
  free(sc);
  return c;
}

static void check_gaps(const nav_replay_summary *sum, const double *end_h, const double *end_sd,
                       const double *max_in, const double *fw_max) {
  assert_true(sum->gap_count > 0);
  for (long g = 0; g < sum->gap_count; ++g) {
    const nav_replay_gap *gp = &sum->gaps[g];
    if (gp->open || !gp->has_end_errors) continue;
    print_message(
        "  gap %.0f..%.0f s: end horizontal error forward %.3f m -> smoothed %.4f m (sigma %.4f m); "
        "largest inside: %.3f -> %.4f m\n",
        gp->t0_s, gp->t1_s, gp->pos_h_end_m, end_h[g], end_sd[g], fw_max[g], max_in[g]);
    assert_true(isfinite(end_h[g]));
    /* The smoothed end error is bounded by its own sigma (3 sigma, one run) ... */
    assert_true(end_h[g] <= 3.0 * end_sd[g]);
    /* ... and the smoothed estimate inside the gap is better than the forward one. */
    assert_true(max_in[g] < fw_max[g]);
  }
}

static void test_replay_slice_gap(void **state) {
  (void)state;
  nav_replay_config c = scene_config(NAV_TEST_DATA_DIR "/replay/long-drive.yaml");
  c.imu_path = NAV_TEST_DATA_DIR "/replay/IMU-100195-100245.txt";
  c.gnss_path = NAV_TEST_DATA_DIR "/replay/GNSS-100195-100245.txt";
  c.ref_path = NAV_TEST_DATA_DIR "/replay/truth-100195-100245-20Hz.nav";
  c.outage_count = 1;
  c.outages[0].t0_s = 100215.5;
  c.outages[0].t1_s = 100230.5;
  nav_replay_summary sum;
  double eh[NAV_REPLAY_MAX_GAPS], esd[NAV_REPLAY_MAX_GAPS], mi[NAV_REPLAY_MAX_GAPS], fm[NAV_REPLAY_MAX_GAPS],
      rf, rs;
  print_message("replay slice with a 15 s GNSS gap:\n");
  replay_smoothed(&c, &sum, eh, esd, mi, fm, &rf, &rs);
  check_gaps(&sum, eh, esd, mi, fm);
  assert_true(rs < rf);
}

static void test_replay_long_drive_outages(void **state) {
  (void)state;
  const char *imu = NAV_SHARED_DIR "/data/gnss-ins-sim-long-drive/IMU.txt";
  if (access(imu, R_OK) != 0) {
    print_message("skipped: %s not present\n", imu);
    skip();
  }
  nav_replay_config c = scene_config(NAV_SOURCE_DIR "/scenes/long-drive-replay.yaml");
  c.imu_path = imu;
  c.gnss_path = NAV_SHARED_DIR "/data/gnss-ins-sim-long-drive/GNSS_outage.txt";
  c.ref_path = NAV_SHARED_DIR "/data/gnss-ins-sim-long-drive/truth.nav";
  nav_replay_summary sum;
  double eh[NAV_REPLAY_MAX_GAPS], esd[NAV_REPLAY_MAX_GAPS], mi[NAV_REPLAY_MAX_GAPS], fm[NAV_REPLAY_MAX_GAPS],
      rf, rs;
  print_message("long drive, GNSS_outage.txt:\n");
  replay_smoothed(&c, &sum, eh, esd, mi, fm, &rf, &rs);
  assert_int_equal(sum.gap_count, 2);
  check_gaps(&sum, eh, esd, mi, fm);
  assert_true(rs < rf);
}

/* ---------------------------------------------------------------- error paths */

static void test_errors(void **state) {
  (void)state;
  nav_smoother_config cfg = nav_smoother_config_default();
  nav_smoother *sm = NULL;
  cfg.group_steps = 0;
  assert_int_equal(nav_smoother_create(&cfg, &sm), NAV_ERR_INVALID_ARG);
  cfg.group_steps = 1;
  cfg.filter.init.pos_sd_m.x = -1.0;
  assert_int_equal(nav_smoother_create(&cfg, &sm), NAV_ERR_INVALID_ARG);
  cfg = nav_smoother_config_default();
  assert_int_equal(nav_smoother_create(&cfg, &sm), NAV_OK);
  const nav_filter_ins_state nom = some_nominal();
  nav_filter_nav nav;
  nav.lat_rad = nom.lat_rad;
  nav.h_m = nom.h_m;
  nav.v_eb_n_mps = nom.v_eb_n_mps;
  nav.C_b_n = nav_quat_to_dcm(nom.q_b_n);
  nav.f_ib_b_mps2 = nav_vec3_make(0.0, 0.0, -9.8);
  nav.w_ib_b_rps = nav_vec3_zero();
  /* Call order. */
  assert_int_equal(nav_smoother_step(sm, 0.01, &nav, 0.01, &nom), NAV_ERR_STATE);
  assert_int_equal(nav_smoother_mark(sm), NAV_ERR_STATE);
  assert_int_equal(nav_smoother_run(sm), NAV_ERR_STATE);
  assert_true(strlen(nav_smoother_last_error(sm)) > 0);
  double P[NN];
  memset(P, 0, sizeof P);
  for (int i = 0; i < N; ++i)
    P[i * N + i] = 1e-4;
  /* Non-finite inputs. */
  P[0] = NAN;
  assert_int_equal(nav_smoother_begin(sm, 0.0, &nom, P, NULL), NAV_ERR_NUMERIC);
  P[0] = 1e-4;
  assert_int_equal(nav_smoother_begin(sm, 0.0, &nom, P, NULL), NAV_OK);
  assert_int_equal(nav_smoother_step(sm, 0.01, &nav, 0.0, &nom), NAV_ERR_INVALID_ARG);
  nav_filter_nav bad = nav;
  bad.v_eb_n_mps.y = INFINITY;
  assert_int_equal(nav_smoother_step(sm, 0.01, &bad, 0.01, &nom), NAV_ERR_NUMERIC);
  assert_non_null(strstr(nav_smoother_last_error(sm), "non-finite"));
  bad = nav;
  bad.lat_rad = NAV_PI / 2;
  assert_int_equal(nav_smoother_step(sm, 0.01, &bad, 0.01, &nom), NAV_ERR_OUT_OF_RANGE);
  double xd[N] = {0};
  xd[3] = NAN;
  assert_int_equal(nav_smoother_update(sm, &nom, P, NULL, xd), NAV_ERR_NUMERIC);
  assert_int_equal(nav_smoother_get(sm, 5, &(nav_smoother_epoch){0}), NAV_ERR_OUT_OF_RANGE);
  /* Before a run the smoothed values are NAN. */
  nav_smoother_epoch e;
  assert_int_equal(nav_smoother_get(sm, 0, &e), NAV_OK);
  assert_true(isnan(e.sd_smoothed[0]) && isnan(e.smoothed.lat_rad));
  nav_smoother_destroy(sm);

  /* An indefinite covariance is refused by the backward pass with the epoch in the message. */
  assert_int_equal(nav_smoother_create(&cfg, &sm), NAV_OK);
  for (int i = 0; i < N; ++i)
    P[i * N + i] = 1e-4;
  P[0 * N + 1] = P[1 * N + 0] = 2e-4; /* |rho| = 2: not a covariance */
  assert_int_equal(nav_smoother_begin(sm, 0.0, &nom, P, NULL), NAV_OK);
  for (int k = 1; k <= 5; ++k)
    assert_int_equal(nav_smoother_step(sm, 0.01 * k, &nav, 0.01, &nom), NAV_OK);
  assert_int_equal(nav_smoother_mark(sm), NAV_OK);
  assert_int_equal(nav_smoother_run(sm), NAV_ERR_NUMERIC);
  print_message("indefinite P: %s\n", nav_smoother_last_error(sm));
  assert_non_null(strstr(nav_smoother_last_error(sm), "positive definite"));
  nav_smoother_destroy(sm);
  nav_smoother_destroy(NULL);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_linear_gaussian_equals_batch),
      cmocka_unit_test(test_linear_gaussian_gnss_states),
      cmocka_unit_test(test_errors),
      cmocka_unit_test(test_simulated_outage),
      cmocka_unit_test(test_replay_slice_gap),
      cmocka_unit_test(test_replay_long_drive_outages),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
