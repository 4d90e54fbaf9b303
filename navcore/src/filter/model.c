/**
 * @file model.c
 * @brief The error-state model of the INS/GNSS filter: configuration, F (numerics.md 6.1),
 *        G Q_c G^T (6.2), the GNSS measurement matrices and residuals (6.4) and the feedback
 *        correction (6.5).
 *
 * Conventions: NED; phi-angle attitude error C_b_n(comp) = (I - [phi x]) C_b_n(true) (E0.1);
 * position error in N/E/D metres; the sensor states are the residual errors in the compensated
 * IMU outputs, so the INS adds them to its estimates on feedback.
 */
#include <assert.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "earth/earth_internal.h"
#include "filter/filter_internal.h"
#include "navcore/nav_earth.h"

/* ---------------------------------------------------------------- configuration */

static nav_vec3 v3(double a) {
  return nav_vec3_make(a, a, a);
}

nav_filter_config nav_filter_config_default(void) {
  nav_filter_config c;
  memset(&c, 0, sizeof c);
  c.states = 0u;
  c.discretisation = NAV_FILTER_DISC_SECOND_ORDER;
  c.cov_decimation = 1u;
  /* numerics.md 2.2 conversions: 0.15 deg/sqrt(h) x (pi/180)/60; 0.07 m/s/sqrt(h) / 60. */
  c.gyro_arw_rad_per_sqrt_s = v3(0.15 * NAV_DEG2RAD / 60.0);
  c.accel_vrw_mps_per_sqrt_s = v3(0.07 / 60.0);
  /* 0.5 deg/h and 0.05 mg (g0 = 9.80665 m/s^2 for unit conversions, numerics.md 0.4). */
  const double bg = 0.5 * NAV_DEG2RAD / 3600.0, ba = 0.05e-3 * NAV_G0_MPS2;
  c.gyro_bias_terms = NAV_FILTER_PROC_GM;
  c.gyro_bias_gm_sd_rps = v3(bg);
  c.gyro_bias_gm_tau_s = v3(3600.0);
  c.gyro_bias_rw_rps_per_sqrt_s = v3(0.0);
  c.accel_bias_terms = NAV_FILTER_PROC_GM;
  c.accel_bias_gm_sd_mps2 = v3(ba);
  c.accel_bias_gm_tau_s = v3(3600.0);
  c.accel_bias_rw_mps2_per_sqrt_s = v3(0.0);
  c.gyro_sf_terms = 0u;
  c.gyro_sf_gm_sd = v3(0.0);
  c.gyro_sf_gm_tau_s = v3(3600.0);
  c.gyro_sf_rw_per_sqrt_s = v3(0.0);
  c.accel_sf_terms = 0u;
  c.accel_sf_gm_sd = v3(0.0);
  c.accel_sf_gm_tau_s = v3(3600.0);
  c.accel_sf_rw_per_sqrt_s = v3(0.0);
  c.gnss_pos_gm_sd_m = v3(1.0);
  c.gnss_pos_gm_tau_s = v3(300.0);
  c.init.pos_sd_m = v3(1.0);
  c.init.vel_sd_mps = v3(0.1);
  c.init.att_sd_rad = nav_vec3_make(0.1 * NAV_DEG2RAD, 0.1 * NAV_DEG2RAD, 1.0 * NAV_DEG2RAD);
  c.init.gyro_bias_sd_rps = v3(bg);
  c.init.accel_bias_sd_mps2 = v3(ba);
  c.init.gyro_sf_sd = v3(1e-4);
  c.init.accel_sf_sd = v3(1e-4);
  c.init.gnss_pos_sd_m = v3(1.0);
  c.gnss_pos_sd_m = nav_vec3_make(1.5, 1.5, 3.0);
  c.gnss_vel_sd_mps = v3(0.05);
  /* Receiver clock (only with NAV_FILTER_STATE_RX_CLOCK / RX_ISB): a low-quality TCXO (Brown and
   * Hwang, 4th ed., Table 9.2: h_0 = 2e-19 s, h_-2 = 2e-20 /s), q_f = c^2 h_0 / 2,
   * q_g = 2 pi^2 c^2 h_-2; 100 m, 10 m/s and 10 m initial sigmas (docs/ins-gnss-tight.md). */
  const double c2 = 299792458.0 * 299792458.0;
  c.clock_bias_q_m2ps = 0.5 * 2e-19 * c2;
  c.clock_drift_q_m2ps3 = 2.0 * NAV_PI * NAV_PI * 2e-20 * c2;
  c.init.clock_bias_sd_m = 100.0;
  c.init.clock_drift_sd_mps = 10.0;
  c.init.isb_sd_m = 10.0;
  return c;
}

typedef struct checker {
  nav_scene_issue_fn report;
  void *user;
  int problems;
} checker;

static void complain(checker *ck, const char *path, const char *msg) {
  ++ck->problems;
  if (ck->report != NULL) ck->report(ck->user, path, msg);
}

/* Each component finite and >= 0 (strict: > 0). */
static void check_vec(checker *ck, const char *name, nav_vec3 v, bool strict) {
  for (int i = 0; i < 3; ++i) {
    const double x = nav_vec3_get(v, i);
    const bool ok = isfinite(x) && (strict ? x > 0.0 : x >= 0.0);
    if (!ok) {
      char path[96];
      snprintf(path, sizeof path, "%s[%d]", name, i);
      complain(ck, path, strict ? "must be finite and > 0" : "must be finite and >= 0");
    }
  }
}

static void check_process(checker *ck, const char *prefix, unsigned terms, nav_vec3 gm_sd, nav_vec3 gm_tau,
                          nav_vec3 rw) {
  char path[96];
  if ((terms & ~(unsigned)(NAV_FILTER_PROC_GM | NAV_FILTER_PROC_RW)) != 0u) {
    snprintf(path, sizeof path, "%s_terms", prefix);
    complain(ck, path, "unknown process bits (allowed: NAV_FILTER_PROC_GM, NAV_FILTER_PROC_RW)");
  }
  if ((terms & NAV_FILTER_PROC_GM) != 0u) {
    snprintf(path, sizeof path, "%s_gm_sd", prefix);
    check_vec(ck, path, gm_sd, false);
    snprintf(path, sizeof path, "%s_gm_tau_s", prefix);
    check_vec(ck, path, gm_tau, true);
  }
  if ((terms & NAV_FILTER_PROC_RW) != 0u) {
    snprintf(path, sizeof path, "%s_rw", prefix);
    check_vec(ck, path, rw, false);
  }
}

nav_status nav_filter_config_validate(const nav_filter_config *cfg, nav_scene_issue_fn report, void *user) {
  if (cfg == NULL) return NAV_ERR_INVALID_ARG;
  checker ck = {report, user, 0};
  const unsigned known = (unsigned)(NAV_FILTER_STATE_SCALE_FACTORS | NAV_FILTER_STATE_GNSS_POS_GM |
                                    NAV_FILTER_STATE_RX_CLOCK | NAV_FILTER_STATE_RX_ISB);
  if ((cfg->states & ~known) != 0u) complain(&ck, "states", "unknown state-option bits");
  const bool clk = (cfg->states & NAV_FILTER_STATE_RX_CLOCK) != 0u;
  if (clk && (cfg->states & NAV_FILTER_STATE_GNSS_POS_GM) != 0u)
    complain(&ck, "states", "the receiver-clock states (tight coupling) exclude the GNSS position GM states");
  if (!clk && (cfg->states & NAV_FILTER_STATE_RX_ISB) != 0u)
    complain(&ck, "states", "the inter-system bias state needs the receiver-clock states");
  if (clk) {
    if (!(isfinite(cfg->clock_bias_q_m2ps) && cfg->clock_bias_q_m2ps >= 0.0))
      complain(&ck, "clock_bias_q_m2ps", "must be finite and >= 0");
    if (!(isfinite(cfg->clock_drift_q_m2ps3) && cfg->clock_drift_q_m2ps3 >= 0.0))
      complain(&ck, "clock_drift_q_m2ps3", "must be finite and >= 0");
    if (!(isfinite(cfg->init.clock_bias_sd_m) && cfg->init.clock_bias_sd_m > 0.0))
      complain(&ck, "init.clock_bias_sd_m", "must be finite and > 0");
    if (!(isfinite(cfg->init.clock_drift_sd_mps) && cfg->init.clock_drift_sd_mps > 0.0))
      complain(&ck, "init.clock_drift_sd_mps", "must be finite and > 0");
  }
  if ((cfg->states & NAV_FILTER_STATE_RX_ISB) != 0u && !(isfinite(cfg->init.isb_sd_m) && cfg->init.isb_sd_m > 0.0))
    complain(&ck, "init.isb_sd_m", "must be finite and > 0");
  if (cfg->discretisation != NAV_FILTER_DISC_SECOND_ORDER && cfg->discretisation != NAV_FILTER_DISC_VAN_LOAN)
    complain(&ck, "discretisation", "must be NAV_FILTER_DISC_SECOND_ORDER or NAV_FILTER_DISC_VAN_LOAN");
  if (cfg->cov_decimation < 1u) complain(&ck, "cov_decimation", "must be >= 1");
  check_vec(&ck, "gyro_arw_rad_per_sqrt_s", cfg->gyro_arw_rad_per_sqrt_s, false);
  check_vec(&ck, "accel_vrw_mps_per_sqrt_s", cfg->accel_vrw_mps_per_sqrt_s, false);
  check_process(&ck, "gyro_bias", cfg->gyro_bias_terms, cfg->gyro_bias_gm_sd_rps, cfg->gyro_bias_gm_tau_s,
                cfg->gyro_bias_rw_rps_per_sqrt_s);
  check_process(&ck, "accel_bias", cfg->accel_bias_terms, cfg->accel_bias_gm_sd_mps2,
                cfg->accel_bias_gm_tau_s, cfg->accel_bias_rw_mps2_per_sqrt_s);
  check_vec(&ck, "init.pos_sd_m", cfg->init.pos_sd_m, true);
  check_vec(&ck, "init.vel_sd_mps", cfg->init.vel_sd_mps, true);
  check_vec(&ck, "init.att_sd_rad", cfg->init.att_sd_rad, true);
  check_vec(&ck, "init.gyro_bias_sd_rps", cfg->init.gyro_bias_sd_rps, true);
  check_vec(&ck, "init.accel_bias_sd_mps2", cfg->init.accel_bias_sd_mps2, true);
  if ((cfg->states & NAV_FILTER_STATE_SCALE_FACTORS) != 0u) {
    check_process(&ck, "gyro_sf", cfg->gyro_sf_terms, cfg->gyro_sf_gm_sd, cfg->gyro_sf_gm_tau_s,
                  cfg->gyro_sf_rw_per_sqrt_s);
    check_process(&ck, "accel_sf", cfg->accel_sf_terms, cfg->accel_sf_gm_sd, cfg->accel_sf_gm_tau_s,
                  cfg->accel_sf_rw_per_sqrt_s);
    check_vec(&ck, "init.gyro_sf_sd", cfg->init.gyro_sf_sd, true);
    check_vec(&ck, "init.accel_sf_sd", cfg->init.accel_sf_sd, true);
  }
  if ((cfg->states & NAV_FILTER_STATE_GNSS_POS_GM) != 0u) {
    check_vec(&ck, "gnss_pos_gm_sd_m", cfg->gnss_pos_gm_sd_m, false);
    check_vec(&ck, "gnss_pos_gm_tau_s", cfg->gnss_pos_gm_tau_s, true);
    check_vec(&ck, "init.gnss_pos_sd_m", cfg->init.gnss_pos_sd_m, true);
  }
  check_vec(&ck, "gnss_pos_sd_m", cfg->gnss_pos_sd_m, true);
  check_vec(&ck, "gnss_vel_sd_mps", cfg->gnss_vel_sd_mps, true);
  return ck.problems == 0 ? NAV_OK : NAV_ERR_INVALID_ARG;
}

/* F diagonal and q of one triad (numerics.md 6.2). */
static void triad_process(double *proc_diag, double *qc, size_t idx, unsigned terms, nav_vec3 gm_sd,
                          nav_vec3 gm_tau, nav_vec3 rw) {
  for (int i = 0; i < 3; ++i) {
    double fd = 0.0, q = 0.0;
    if ((terms & NAV_FILTER_PROC_GM) != 0u) {
      const double sd = nav_vec3_get(gm_sd, i), tau = nav_vec3_get(gm_tau, i);
      fd = -1.0 / tau;
      q += 2.0 * sd * sd / tau;
    }
    if ((terms & NAV_FILTER_PROC_RW) != 0u) {
      const double k = nav_vec3_get(rw, i);
      q += k * k;
    }
    proc_diag[idx + (size_t)i] = fd;
    qc[idx + (size_t)i] = q;
  }
}

void nav_filter_process_model(const nav_filter_config *cfg, const nav_filter_layout *lay, double *proc_diag,
                              double *qc) {
  for (int i = 0; i < 3; ++i) {
    const double na = nav_vec3_get(cfg->accel_vrw_mps_per_sqrt_s, i);
    const double ng = nav_vec3_get(cfg->gyro_arw_rad_per_sqrt_s, i);
    qc[NAV_FILTER_IDX_DV + (size_t)i] = na * na;  /* VRW: q_a = N_a^2 [m^2/s^3] */
    qc[NAV_FILTER_IDX_PHI + (size_t)i] = ng * ng; /* ARW: q_g = N_g^2 [rad^2/s] */
  }
  triad_process(proc_diag, qc, NAV_FILTER_IDX_BG, cfg->gyro_bias_terms, cfg->gyro_bias_gm_sd_rps,
                cfg->gyro_bias_gm_tau_s, cfg->gyro_bias_rw_rps_per_sqrt_s);
  triad_process(proc_diag, qc, NAV_FILTER_IDX_BA, cfg->accel_bias_terms, cfg->accel_bias_gm_sd_mps2,
                cfg->accel_bias_gm_tau_s, cfg->accel_bias_rw_mps2_per_sqrt_s);
  if (lay->has_scale_factors) {
    triad_process(proc_diag, qc, NAV_FILTER_IDX_SG, cfg->gyro_sf_terms, cfg->gyro_sf_gm_sd, cfg->gyro_sf_gm_tau_s,
                  cfg->gyro_sf_rw_per_sqrt_s);
    triad_process(proc_diag, qc, NAV_FILTER_IDX_SA, cfg->accel_sf_terms, cfg->accel_sf_gm_sd,
                  cfg->accel_sf_gm_tau_s, cfg->accel_sf_rw_per_sqrt_s);
  }
  if (lay->has_gnss_pos_gm)
    triad_process(proc_diag, qc, lay->idx_gnss_pos, NAV_FILTER_PROC_GM, cfg->gnss_pos_gm_sd_m,
                  cfg->gnss_pos_gm_tau_s, nav_vec3_zero());
  if (lay->has_rx_clock) {
    /* Two-state clock (docs/ins-gnss-tight.md 2.3): no damping; white noise on both states. */
    proc_diag[lay->idx_clock] = 0.0;
    proc_diag[lay->idx_clock + 1] = 0.0;
    qc[lay->idx_clock] = cfg->clock_bias_q_m2ps;
    qc[lay->idx_clock + 1] = cfg->clock_drift_q_m2ps3;
  }
  if (lay->has_isb) {
    proc_diag[lay->idx_isb] = 0.0; /* random constant */
    qc[lay->idx_isb] = 0.0;
  }
}

nav_filter_layout nav_filter_layout_of(unsigned states) {
  nav_filter_layout l;
  l.has_scale_factors = (states & NAV_FILTER_STATE_SCALE_FACTORS) != 0u;
  l.has_gnss_pos_gm = (states & NAV_FILTER_STATE_GNSS_POS_GM) != 0u;
  l.has_rx_clock = (states & NAV_FILTER_STATE_RX_CLOCK) != 0u;
  l.has_isb = l.has_rx_clock && (states & NAV_FILTER_STATE_RX_ISB) != 0u;
  size_t n = NAV_FILTER_N_CORE;
  if (l.has_scale_factors) n += 6;
  l.n_ins = n;
  l.idx_gnss_pos = n;
  if (l.has_gnss_pos_gm) n += 3;
  l.idx_clock = n;
  if (l.has_rx_clock) n += 2;
  l.idx_isb = n;
  if (l.has_isb) n += 1;
  l.n_states = n;
  return l;
}

/* ---------------------------------------------------------------- F, G Q G^T */

nav_filter_earth_terms nav_filter_earth_terms_wgs84(double lat_rad, double h_m) {
  nav_filter_earth_terms e;
  nav_earth_radii_gravity(lat_rad, h_m, &e.R_M_m, &e.R_N_m, &e.g_mps2);
  e.w_ie_rps = NAV_WGS84_OMEGA_IE_RPS;
  return e;
}

/* Write the 3x3 matrix b into the block of a (n columns) at (r, c). */
static void put3(double *a, size_t n, size_t r, size_t c, nav_mat3 b) {
  for (size_t i = 0; i < 3; ++i)
    for (size_t j = 0; j < 3; ++j)
      a[(r + i) * n + c + j] = b.m[i][j];
}

/* C diag(d) */
static nav_mat3 mul_diag(nav_mat3 C, nav_vec3 d) {
  nav_mat3 r;
  for (int i = 0; i < 3; ++i) {
    r.m[i][0] = C.m[i][0] * d.x;
    r.m[i][1] = C.m[i][1] * d.y;
    r.m[i][2] = C.m[i][2] * d.z;
  }
  return r;
}

void nav_filter_build_F(double *F, const nav_filter_layout *lay, const nav_filter_nav *nav,
                        const nav_filter_earth_terms *earth, const double *proc_diag) {
  const size_t n = lay->n_states;
  memset(F, 0, n * n * sizeof *F);
  nav_filter_build_F_nonzero(F, lay, nav, earth, proc_diag);
}

void nav_filter_build_F_nonzero(double *F, const nav_filter_layout *lay, const nav_filter_nav *nav,
                                const nav_filter_earth_terms *earth, const double *proc_diag) {
  const size_t n = lay->n_states;

  /* numerics.md 6.1, identical to [SHIN] ch. 3 and KF-GINS gi_engine.cpp (StateID order
   * P, V, PHI, BG, BA, SG, SA). R_m = R_M + h, R_n = R_N + h. */
  const double lat = nav->lat_rad, h = nav->h_m;
  const double vn = nav->v_eb_n_mps.x, ve = nav->v_eb_n_mps.y, vd = nav->v_eb_n_mps.z;
  const double sl = sin(lat), cl = cos(lat), tl = sl / cl;
  const double rm = earth->R_M_m + h, rn = earth->R_N_m + h;
  const double wie = earth->w_ie_rps, g = earth->g_mps2;
  const double rm2 = rm * rm, rn2 = rn * rn, c2 = cl * cl;
#define F_(i, j) F[(size_t)(i)*n + (size_t)(j)]
  const size_t R = NAV_FILTER_IDX_DR, V = NAV_FILTER_IDX_DV, P = NAV_FILTER_IDX_PHI;

  /* F_rr, F_rv */
  F_(R + 0, R + 0) = -vd / rm;
  F_(R + 0, R + 2) = vn / rm;
  F_(R + 1, R + 0) = ve * tl / rn;
  F_(R + 1, R + 1) = -(vd + vn * tl) / rn;
  F_(R + 1, R + 2) = ve / rn;
  for (size_t i = 0; i < 3; ++i)
    F_(R + i, V + i) = 1.0;

  /* F_vr; the (3,3) term is the vertical-channel gravity gradient 2 g / (sqrt(R_M R_N) + h). */
  F_(V + 0, R + 0) = -2.0 * ve * wie * cl / rm - ve * ve / (rm * rn * c2);
  F_(V + 0, R + 2) = vn * vd / rm2 - ve * ve * tl / rn2;
  F_(V + 1, R + 0) = 2.0 * wie * (vn * cl - vd * sl) / rm + vn * ve / (rm * rn * c2);
  F_(V + 1, R + 2) = (ve * vd + vn * ve * tl) / rn2;
  F_(V + 2, R + 0) = 2.0 * wie * ve * sl / rm;
  F_(V + 2, R + 2) = -ve * ve / rn2 - vn * vn / rm2 + 2.0 * g / (sqrt(earth->R_M_m * earth->R_N_m) + h);

  /* F_vv */
  F_(V + 0, V + 0) = vd / rm;
  F_(V + 0, V + 1) = -2.0 * (wie * sl + ve * tl / rn);
  F_(V + 0, V + 2) = vn / rm;
  F_(V + 1, V + 0) = 2.0 * wie * sl + ve * tl / rn;
  F_(V + 1, V + 1) = (vd + vn * tl) / rn;
  F_(V + 1, V + 2) = 2.0 * wie * cl + ve / rn;
  F_(V + 2, V + 0) = -2.0 * vn / rm;
  F_(V + 2, V + 1) = -2.0 * (wie * cl + ve / rn);

  /* F_vphi = [f_n x], F_vba = C_b_n (E0.3: dv_dot = C b_a + f_n x phi). */
  const nav_vec3 f_n = nav_mat3_mul_vec(nav->C_b_n, nav->f_ib_b_mps2);
  put3(F, n, V, P, nav_mat3_skew(f_n));
  put3(F, n, V, NAV_FILTER_IDX_BA, nav->C_b_n);

  /* F_phir */
  F_(P + 0, R + 0) = -wie * sl / rm;
  F_(P + 0, R + 2) = ve / rn2;
  F_(P + 1, R + 2) = -vn / rm2;
  F_(P + 2, R + 0) = -wie * cl / rm - ve / (rm * rn * c2);
  F_(P + 2, R + 2) = -ve * tl / rn2;
  /* F_phiv */
  F_(P + 0, V + 1) = 1.0 / rn;
  F_(P + 1, V + 0) = -1.0 / rm;
  F_(P + 2, V + 1) = -tl / rn;
  /* F_phiphi = -[w_in_n x], w_in = w_ie + w_en = (wie cl + ve/rn, -vn/rm, -wie sl - ve tl/rn) */
  const nav_vec3 w_in = nav_vec3_make(wie * cl + ve / rn, -vn / rm, -wie * sl - ve * tl / rn);
  put3(F, n, P, P, nav_mat3_scale(nav_mat3_skew(w_in), -1.0));
  /* F_phibg = -C_b_n (E0.3: phi_dot = -C b_g) */
  put3(F, n, P, NAV_FILTER_IDX_BG, nav_mat3_scale(nav->C_b_n, -1.0));

  if (lay->has_scale_factors) {
    put3(F, n, V, NAV_FILTER_IDX_SA, mul_diag(nav->C_b_n, nav->f_ib_b_mps2));
    put3(F, n, P, NAV_FILTER_IDX_SG, mul_diag(nav_mat3_scale(nav->C_b_n, -1.0), nav->w_ib_b_rps));
  }
  /* Sensor and GNSS states: -1/T (Gauss-Markov) or 0. */
  for (size_t i = NAV_FILTER_IDX_BG; i < n; ++i)
    F_(i, i) = proc_diag[i];
  /* Receiver clock: the bias integrates the drift (docs/ins-gnss-tight.md 2.3). */
  if (lay->has_rx_clock) F_(lay->idx_clock, lay->idx_clock + 1) = 1.0;
#undef F_
}

void nav_filter_build_GQG(double *GQG, const nav_filter_layout *lay, nav_mat3 C_b_n, const double *qc) {
  const size_t n = lay->n_states;
  memset(GQG, 0, n * n * sizeof *GQG);
  /* numerics.md 6.2: dv gets C_b_n w_a and phi gets -C_b_n w_g; with independent per-axis white
   * noise the blocks are C diag(q) C^T (the sign of G drops out). */
  const nav_vec3 qa =
      nav_vec3_make(qc[NAV_FILTER_IDX_DV], qc[NAV_FILTER_IDX_DV + 1], qc[NAV_FILTER_IDX_DV + 2]);
  const nav_vec3 qg =
      nav_vec3_make(qc[NAV_FILTER_IDX_PHI], qc[NAV_FILTER_IDX_PHI + 1], qc[NAV_FILTER_IDX_PHI + 2]);
  nav_mat3 bv = nav_mat3_mul(mul_diag(C_b_n, qa), nav_mat3_transpose(C_b_n));
  nav_mat3 bp = nav_mat3_mul(mul_diag(C_b_n, qg), nav_mat3_transpose(C_b_n));
  /* Exact symmetry of the blocks (the two triangles round differently). */
  for (int i = 0; i < 3; ++i)
    for (int j = i + 1; j < 3; ++j) {
      bv.m[j][i] = bv.m[i][j];
      bp.m[j][i] = bp.m[i][j];
    }
  put3(GQG, n, NAV_FILTER_IDX_DV, NAV_FILTER_IDX_DV, bv);
  put3(GQG, n, NAV_FILTER_IDX_PHI, NAV_FILTER_IDX_PHI, bp);
  for (size_t i = NAV_FILTER_IDX_BG; i < n; ++i)
    GQG[i * n + i] = qc[i];
}

/* ---------------------------------------------------------------- measurements */

void nav_filter_build_H_pos(double *H, const nav_filter_layout *lay, const nav_filter_nav *nav,
                            nav_vec3 l_ba_b_m) {
  const size_t n = lay->n_states;
  memset(H, 0, 3 * n * sizeof *H);
  /* E6.3: z = dr + (C_comp - C_true) l = dr + [(C l) x] phi to first order
   * (d(C a) = -phi x (C a) = (C a) x phi under E0.1); the GNSS error enters as -e. */
  for (size_t i = 0; i < 3; ++i)
    H[i * n + NAV_FILTER_IDX_DR + i] = 1.0;
  const nav_vec3 Cl = nav_mat3_mul_vec(nav->C_b_n, l_ba_b_m);
  put3(H, n, 0, NAV_FILTER_IDX_PHI, nav_mat3_skew(Cl));
  if (lay->has_gnss_pos_gm)
    for (size_t i = 0; i < 3; ++i)
      H[i * n + lay->idx_gnss_pos + i] = -1.0;
}

void nav_filter_build_H_vel(double *H, const nav_filter_layout *lay, const nav_filter_nav *nav,
                            nav_vec3 l_ba_b_m) {
  const size_t n = lay->n_states;
  memset(H, 0, 3 * n * sizeof *H);
  /* E6.4: z = dv + C (w x l) - w_ie x (C l) - v_GNSS with w = w_true + b_g + diag(w) s_g:
   *   d/dphi: [(C (w x l)) x] - [w_ie x][(C l) x]  (Earth-rate part kept: exact Jacobian)
   *   d/db_g: C (b_g x l) = -C [l x] b_g;   d/ds_g: -C [l x] diag(w). */
  for (size_t i = 0; i < 3; ++i)
    H[i * n + NAV_FILTER_IDX_DV + i] = 1.0;
  const nav_mat3 C = nav->C_b_n;
  const nav_vec3 w = nav->w_ib_b_rps;
  const nav_vec3 Cwl = nav_mat3_mul_vec(C, nav_vec3_cross(w, l_ba_b_m));
  const nav_vec3 Cl = nav_mat3_mul_vec(C, l_ba_b_m);
  const nav_vec3 w_ie_n = nav_earth_rate_n_rps(nav->lat_rad);
  const nav_mat3 hphi = nav_mat3_add(
      nav_mat3_skew(Cwl), nav_mat3_scale(nav_mat3_mul(nav_mat3_skew(w_ie_n), nav_mat3_skew(Cl)), -1.0));
  put3(H, n, 0, NAV_FILTER_IDX_PHI, hphi);
  const nav_mat3 mCl = nav_mat3_scale(nav_mat3_mul(C, nav_mat3_skew(l_ba_b_m)), -1.0);
  put3(H, n, 0, NAV_FILTER_IDX_BG, mCl);
  if (lay->has_scale_factors) put3(H, n, 0, NAV_FILTER_IDX_SG, mul_diag(mCl, w));
}

nav_vec3 nav_filter_gnss_pos_residual(nav_geodetic ins_pos, nav_mat3 C_b_n, nav_vec3 l_ba_b_m,
                                      nav_geodetic gnss_pos) {
  /* E6.3 with D = diag(R_M + h, (R_N + h) cos lat, -1) at the INS position. */
  const double rm = nav_earth_radius_meridian_m(ins_pos.lat_rad) + ins_pos.h_m;
  const double rn = nav_earth_radius_prime_vertical_m(ins_pos.lat_rad) + ins_pos.h_m;
  const nav_vec3 Cl = nav_mat3_mul_vec(C_b_n, l_ba_b_m);
  const double dlon = nav_earth_wrap_lon(ins_pos.lon_rad - gnss_pos.lon_rad);
  return nav_vec3_make((ins_pos.lat_rad - gnss_pos.lat_rad) * rm + Cl.x,
                       dlon * rn * cos(ins_pos.lat_rad) + Cl.y, -(ins_pos.h_m - gnss_pos.h_m) + Cl.z);
}

nav_vec3 nav_filter_gnss_vel_residual(const nav_filter_nav *nav, nav_vec3 l_ba_b_m, nav_vec3 v_gnss_n_mps) {
  const nav_vec3 Cwl = nav_mat3_mul_vec(nav->C_b_n, nav_vec3_cross(nav->w_ib_b_rps, l_ba_b_m));
  const nav_vec3 Cl = nav_mat3_mul_vec(nav->C_b_n, l_ba_b_m);
  const nav_vec3 wCl = nav_vec3_cross(nav_earth_rate_n_rps(nav->lat_rad), Cl);
  return nav_vec3_sub(nav_vec3_sub(nav_vec3_add(nav->v_eb_n_mps, Cwl), wCl), v_gnss_n_mps);
}

/* ---------------------------------------------------------------- feedback */

void nav_filter_apply_correction(nav_filter_ins_state *out, const nav_filter_ins_state *in,
                                 const nav_filter_error *dx) {
  assert(out != NULL && in != NULL && dx != NULL);
  if (out == NULL || in == NULL || dx == NULL) return;
  const nav_filter_ins_state s = *in; /* out may alias in */
  /* numerics.md 6.5: r <- r - D^-1 dr with D at the INS position. */
  const double rm = nav_earth_radius_meridian_m(s.lat_rad) + s.h_m;
  const double rn = nav_earth_radius_prime_vertical_m(s.lat_rad) + s.h_m;
  out->lat_rad = s.lat_rad - dx->dr_ned_m.x / rm;
  out->lon_rad = nav_earth_wrap_lon(s.lon_rad - dx->dr_ned_m.y / (rn * cos(s.lat_rad)));
  out->h_m = s.h_m + dx->dr_ned_m.z;
  out->v_eb_n_mps = nav_vec3_sub(s.v_eb_n_mps, dx->dv_n_mps);
  /* C_true = (I - [phi x])^-1 C_comp ~ exp([phi x]) C_comp; as quaternions q(phi) (x) q_b_n
   * (C(q1 (x) q2) = C(q1) C(q2)), renormalised. */
  out->q_b_n = nav_quat_normalize(nav_quat_mul(nav_quat_from_rotvec(dx->phi_rad), s.q_b_n));
  out->b_g_rps = nav_vec3_add(s.b_g_rps, dx->b_g_rps);
  out->b_a_mps2 = nav_vec3_add(s.b_a_mps2, dx->b_a_mps2);
  out->s_g = nav_vec3_add(s.s_g, dx->s_g);
  out->s_a = nav_vec3_add(s.s_a, dx->s_a);
}
