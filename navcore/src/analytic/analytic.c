/*
 * Analytical error growth (numerics.md section 1): integrated-noise kernels, Gauss-Markov
 * variances, the free-inertial gyro INS table, Schuler-bounded channels, the gyro-free array
 * geometry (H, pseudo-inverse, kappa) and error chain, the paper's original formulas for
 * comparison, and the preliminary-estimate entry point. Every formula cites its equation number
 * in numerics.md; the paper is Soloviev, Sablin, Lyalinsky (IPPM RAS), formulas (1) and (2).
 */
#include <float.h>
#include <string.h>

#include "navcore/nav_analytic.h"
#include "navcore/nav_earth.h"

/* ------------------------------------------------------------------ helpers */

static double factorial(int n) {
  double f = 1.0;
  for (int i = 2; i <= n; ++i)
    f *= (double)i;
  return f;
}

static bool nonneg_finite(double v) {
  return isfinite(v) && v >= 0.0;
}

/* ------------------------------------------------------------------ E1.1-E1.2 */

double nav_analytic_white_sd(double density, double t_s, int m) {
  if (m < 1 || m > 8) return NAN;
  /* E1.1 with h(u) = u^(m-1)/(m-1)!: int_0^t h^2 = t^(2m-1) / ((2m-1) ((m-1)!)^2). */
  const double fm = factorial(m - 1);
  return density * sqrt(pow(t_s, 2.0 * m - 1.0) / ((2.0 * m - 1.0) * fm * fm));
}

double nav_analytic_bias_response(double b, double t_s, int m) {
  if (m < 1 || m > 8) return NAN;
  /* E1.1, deterministic column: m integrations of a constant. */
  return b * pow(t_s, (double)m) / factorial(m);
}

double nav_analytic_density_from_sample_sd(double sigma, double dt_s) {
  /* E1.2: a per-sample average of white noise of density N has variance N^2 / dt. */
  return sigma * sqrt(dt_s);
}

/* ------------------------------------------------------------------ E1.3-E1.5 */

/*
 * Series of the GM variances, written relative to t^(2m) so that T = +inf (a random constant)
 * and huge T neither overflow nor divide by zero:
 *   I1 = 2 sigma^2 t^2 sum_{k>=2} (-1)^k x^(k-2) / k!
 *   I2 = 2 sigma^2 t^4 sum_{k>=4} (-1)^k (k-1) x^(k-4) / k!
 *   I3 =   sigma^2 t^6 sum_{k>=6} (-1)^k (k-1)(k-2) x^(k-6) / k!
 * (expand e^-x in E1.3-E1.5; the terms below k0 = 2m cancel identically). For x <= 1 the terms
 * decrease monotonically after the first, so the alternating sum is accurate to a few ulps and
 * the truncation error is below the first omitted term.
 */
static double gm_series(int m, double sigma, double x, double t) {
  const int k0 = 2 * m;
  double p = 1.0 / factorial(k0); /* x^(k - k0) / k! */
  double sum = 0.0;
  for (int k = k0; k < k0 + 400; ++k) {
    double a = (k % 2 == 0) ? 1.0 : -1.0;
    if (m == 2) a *= (double)(k - 1);
    if (m == 3) a *= (double)(k - 1) * (double)(k - 2);
    const double term = a * p;
    sum += term;
    if (k > k0 + 2 && fabs(term) <= 1e-17 * fabs(sum)) break;
    p *= x / (double)(k + 1);
  }
  const double s2 = sigma * sigma;
  if (m == 1) return 2.0 * s2 * t * t * sum;
  if (m == 2) return 2.0 * s2 * pow(t, 4.0) * sum;
  return s2 * pow(t, 6.0) * sum;
}

/* E1.3-E1.5 exactly as printed (catastrophic cancellation for small t/T, see the header). */
static double gm_closed(int m, double sigma, double tau, double t) {
  const double s2 = sigma * sigma, x = t / tau, e = exp(-x);
  const double T = tau;
  if (m == 1) return 2.0 * s2 * T * T * (x - 1.0 + e);
  if (m == 2)
    return (s2 * T / 3.0) *
           (2.0 * t * t * t - 3.0 * T * t * t + 6.0 * T * T * T - 6.0 * T * T * T * e - 6.0 * T * T * t * e);
  const double T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  return (s2 * T / 60.0) * (6.0 * pow(t, 5.0) - 15.0 * T * pow(t, 4.0) + 20.0 * T2 * t * t * t - 120.0 * T5 +
                            e * (120.0 * T5 + 120.0 * T4 * t + 60.0 * T3 * t * t));
}

double nav_analytic_gm_var(int m, double sigma, double tau_s, double t_s, nav_analytic_gm_method method) {
  if (m < 1 || m > 3 || !(tau_s > 0.0) || !(t_s >= 0.0) || !isfinite(t_s) || !isfinite(sigma)) return NAN;
  const double x = t_s / tau_s;
  switch (method) {
  case NAV_ANALYTIC_GM_AUTO:
    return x < NAV_ANALYTIC_GM_SERIES_X ? gm_series(m, sigma, x, t_s) : gm_closed(m, sigma, tau_s, t_s);
  case NAV_ANALYTIC_GM_CLOSED_FORM: return gm_closed(m, sigma, tau_s, t_s);
  case NAV_ANALYTIC_GM_SERIES: return gm_series(m, sigma, x, t_s);
  }
  return NAN;
}

double nav_analytic_gm_var_i1(double sigma, double tau_s, double t_s) {
  return nav_analytic_gm_var(1, sigma, tau_s, t_s, NAV_ANALYTIC_GM_AUTO);
}
double nav_analytic_gm_var_i2(double sigma, double tau_s, double t_s) {
  return nav_analytic_gm_var(2, sigma, tau_s, t_s, NAV_ANALYTIC_GM_AUTO);
}
double nav_analytic_gm_var_i3(double sigma, double tau_s, double t_s) {
  return nav_analytic_gm_var(3, sigma, tau_s, t_s, NAV_ANALYTIC_GM_AUTO);
}

/* ------------------------------------------------------------------ E1.6-E1.17, E1.21 */

nav_analytic_imu_spec nav_analytic_imu_spec_default(void) {
  nav_analytic_imu_spec s;
  memset(&s, 0, sizeof s);
  s.g_mps2 = NAV_G0_MPS2;
  return s;
}

static const char *const k_term_names[NAV_ANALYTIC_TERM_COUNT] = {
    "E1.6 initial position", "E1.7 initial velocity", "E1.8 initial tilt", "E1.9 initial heading",
    "E1.10 accel bias",      "E1.11 accel noise",     "E1.12 accel GM",    "E1.13 accel bias RW",
    "E1.14 gyro bias",       "E1.15 gyro noise",      "E1.16 gyro GM",     "E1.17 gyro rate RW"};

const char *nav_analytic_term_name(nav_analytic_term_id id) {
  return ((int)id >= 0 && id < NAV_ANALYTIC_TERM_COUNT) ? k_term_names[id] : "?";
}

bool nav_analytic_term_is_process(nav_analytic_term_id id) {
  switch (id) {
  case NAV_ANALYTIC_TERM_ACCEL_NOISE:
  case NAV_ANALYTIC_TERM_ACCEL_GM:
  case NAV_ANALYTIC_TERM_ACCEL_BIAS_RW:
  case NAV_ANALYTIC_TERM_GYRO_NOISE:
  case NAV_ANALYTIC_TERM_GYRO_GM:
  case NAV_ANALYTIC_TERM_GYRO_RRW: return true;
  default: return false;
  }
}

static bool imu_spec_ok(const nav_analytic_imu_spec *s) {
  const double v[] = {s->g_mps2,
                      s->init_pos_sd_m,
                      s->init_vel_sd_mps,
                      s->init_tilt_sd_rad,
                      s->init_heading_sd_rad,
                      s->horiz_accel_mps2,
                      s->accel_bias_mps2,
                      s->accel_vrw_mps_per_sqrt_s,
                      s->accel_gm_sd_mps2,
                      s->accel_bias_rw_mps2_per_sqrt_s,
                      s->gyro_bias_rps,
                      s->gyro_arw_rad_per_sqrt_s,
                      s->gyro_gm_sd_rps,
                      s->gyro_rrw_rps_per_sqrt_s};
  for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i)
    if (!nonneg_finite(v[i])) return false;
  /* Correlation times: T = +inf is allowed (random-constant limit); T must be > 0 when used. */
  if (s->accel_gm_sd_mps2 > 0.0 && !(s->accel_gm_tau_s > 0.0)) return false;
  if (s->gyro_gm_sd_rps > 0.0 && !(s->gyro_gm_tau_s > 0.0)) return false;
  return true;
}

static nav_analytic_axis_error axis_err(double att, double vel, double pos) {
  nav_analytic_axis_error e = {att, vel, pos};
  return e;
}

nav_status nav_analytic_gyro_ins_table_eval(const nav_analytic_imu_spec *spec, double t_s,
                                            nav_analytic_gyro_ins_table *out) {
  if (!spec || !out || !nonneg_finite(t_s) || !imu_spec_ok(spec)) return NAV_ERR_INVALID_ARG;
  const double t = t_s, g = spec->g_mps2;
  nav_analytic_gyro_ins_table r;
  r.t_s = t;
  /* E1.6 */
  r.term[NAV_ANALYTIC_TERM_INIT_POS] = axis_err(0.0, 0.0, spec->init_pos_sd_m);
  /* E1.7 */
  r.term[NAV_ANALYTIC_TERM_INIT_VEL] = axis_err(0.0, spec->init_vel_sd_mps, spec->init_vel_sd_mps * t);
  /* E1.8: the tilt misplaces gravity: g psi0 integrated once and twice. */
  {
    const double gp = g * spec->init_tilt_sd_rad;
    r.term[NAV_ANALYTIC_TERM_INIT_TILT] = axis_err(
        spec->init_tilt_sd_rad, nav_analytic_bias_response(gp, t, 1), nav_analytic_bias_response(gp, t, 2));
  }
  /* E1.9: a heading error rotates the horizontal specific force a_h. */
  {
    const double ap = spec->horiz_accel_mps2 * spec->init_heading_sd_rad;
    r.term[NAV_ANALYTIC_TERM_INIT_HEADING] =
        axis_err(spec->init_heading_sd_rad, nav_analytic_bias_response(ap, t, 1),
                 nav_analytic_bias_response(ap, t, 2));
  }
  /* E1.10 */
  r.term[NAV_ANALYTIC_TERM_ACCEL_BIAS] =
      axis_err(0.0, nav_analytic_bias_response(spec->accel_bias_mps2, t, 1),
               nav_analytic_bias_response(spec->accel_bias_mps2, t, 2));
  /* E1.11 */
  r.term[NAV_ANALYTIC_TERM_ACCEL_NOISE] =
      axis_err(0.0, nav_analytic_white_sd(spec->accel_vrw_mps_per_sqrt_s, t, 1),
               nav_analytic_white_sd(spec->accel_vrw_mps_per_sqrt_s, t, 2));
  /* E1.12 */
  if (spec->accel_gm_sd_mps2 > 0.0)
    r.term[NAV_ANALYTIC_TERM_ACCEL_GM] =
        axis_err(0.0, sqrt(nav_analytic_gm_var_i1(spec->accel_gm_sd_mps2, spec->accel_gm_tau_s, t)),
                 sqrt(nav_analytic_gm_var_i2(spec->accel_gm_sd_mps2, spec->accel_gm_tau_s, t)));
  else
    r.term[NAV_ANALYTIC_TERM_ACCEL_GM] = axis_err(0.0, 0.0, 0.0);
  /* E1.13: a random-walk bias is the integral of white noise of density K_a. */
  r.term[NAV_ANALYTIC_TERM_ACCEL_BIAS_RW] =
      axis_err(0.0, nav_analytic_white_sd(spec->accel_bias_rw_mps2_per_sqrt_s, t, 2),
               nav_analytic_white_sd(spec->accel_bias_rw_mps2_per_sqrt_s, t, 3));
  /* E1.14: tilt b_g t, then g tilt integrated once and twice. */
  r.term[NAV_ANALYTIC_TERM_GYRO_BIAS] = axis_err(nav_analytic_bias_response(spec->gyro_bias_rps, t, 1),
                                                 g * nav_analytic_bias_response(spec->gyro_bias_rps, t, 2),
                                                 g * nav_analytic_bias_response(spec->gyro_bias_rps, t, 3));
  /* E1.15: the t^5/20 coefficient (the paper's /30 is wrong, numerics.md 1.4). */
  r.term[NAV_ANALYTIC_TERM_GYRO_NOISE] =
      axis_err(nav_analytic_white_sd(spec->gyro_arw_rad_per_sqrt_s, t, 1),
               g * nav_analytic_white_sd(spec->gyro_arw_rad_per_sqrt_s, t, 2),
               g * nav_analytic_white_sd(spec->gyro_arw_rad_per_sqrt_s, t, 3));
  /* E1.16 */
  if (spec->gyro_gm_sd_rps > 0.0)
    r.term[NAV_ANALYTIC_TERM_GYRO_GM] =
        axis_err(sqrt(nav_analytic_gm_var_i1(spec->gyro_gm_sd_rps, spec->gyro_gm_tau_s, t)),
                 g * sqrt(nav_analytic_gm_var_i2(spec->gyro_gm_sd_rps, spec->gyro_gm_tau_s, t)),
                 g * sqrt(nav_analytic_gm_var_i3(spec->gyro_gm_sd_rps, spec->gyro_gm_tau_s, t)));
  else
    r.term[NAV_ANALYTIC_TERM_GYRO_GM] = axis_err(0.0, 0.0, 0.0);
  /* E1.17 */
  r.term[NAV_ANALYTIC_TERM_GYRO_RRW] =
      axis_err(nav_analytic_white_sd(spec->gyro_rrw_rps_per_sqrt_s, t, 2),
               g * nav_analytic_white_sd(spec->gyro_rrw_rps_per_sqrt_s, t, 3),
               g * nav_analytic_white_sd(spec->gyro_rrw_rps_per_sqrt_s, t, 4));
  /* E1.21: independent contributions add in variance (biases as random constants). */
  double va = 0.0, vv = 0.0, vp = 0.0;
  for (int i = 0; i < NAV_ANALYTIC_TERM_COUNT; ++i) {
    va += r.term[i].att_rad * r.term[i].att_rad;
    vv += r.term[i].vel_mps * r.term[i].vel_mps;
    vp += r.term[i].pos_m * r.term[i].pos_m;
  }
  r.rss = axis_err(sqrt(va), sqrt(vv), sqrt(vp));
  *out = r;
  return NAV_OK;
}

/* ------------------------------------------------------------------ E1.18-E1.20 */

double nav_analytic_schuler_radius_m(double lat_rad, double h_m) {
  return sqrt(nav_earth_radius_meridian_m(lat_rad) * nav_earth_radius_prime_vertical_m(lat_rad)) + h_m;
}

double nav_analytic_schuler_rate_rps(double g_mps2, double radius_m) {
  return sqrt(g_mps2 / radius_m);
}

/*
 * Shared evaluation of E1.18-E1.20. With x = ws t and R ws^2 = g:
 *   sin(ws t)/ws = t sinc(x),  (R/g)(1 - cos ws t) = t^2 (1 - cos x)/x^2,
 *   R (t - sin(ws t)/ws) = g t^3 (1 - sinc x)/x^2,  R (1 - cos ws t) = g t^2 (1 - cos x)/x^2,
 * so the short-time limits (E1.7, E1.8/E1.10, E1.14) come out without cancellation.
 * drive = b_a +- g phi0; gyro_sign = -1 (north, -b_gE) or +1 (east, +b_gN).
 */
static nav_analytic_schuler_error schuler(const nav_analytic_schuler_channel *ch, double t, double drive,
                                          double gyro_sign) {
  const double ws = nav_analytic_schuler_rate_rps(ch->g_mps2, ch->radius_m);
  const double x = ws * t;
  const double omc = nav_one_minus_cos_over_a2(x), oms = nav_one_minus_sinc_over_a2(x), sc = nav_sinc(x);
  const double g = ch->g_mps2, bg = gyro_sign * ch->gyro_bias_rps;
  nav_analytic_schuler_error e;
  e.pos_m = ch->dr0_m + ch->dv0_mps * t * sc + drive * t * t * omc + bg * g * t * t * t * oms;
  e.vel_mps = ch->dv0_mps * cos(x) + drive * t * sc + bg * g * t * t * omc;
  return e;
}

nav_analytic_schuler_error nav_analytic_schuler_north(const nav_analytic_schuler_channel *ch, double t_s) {
  /* E1.18, E1.20: delta_v_N_dot = b_aN + g phi_E, phi_E_dot = -delta_v_N / R - b_gE. */
  return schuler(ch, t_s, ch->accel_bias_mps2 + ch->g_mps2 * ch->tilt0_rad, -1.0);
}

nav_analytic_schuler_error nav_analytic_schuler_east(const nav_analytic_schuler_channel *ch, double t_s) {
  /* E1.19 (and its derivative): delta_v_E_dot = b_aE - g phi_N, phi_N_dot = +delta_v_E / R - b_gN. */
  return schuler(ch, t_s, ch->accel_bias_mps2 - ch->g_mps2 * ch->tilt0_rad, +1.0);
}

/* ------------------------------------------------------------------ E1.22-E1.24 array geometry */

nav_status nav_array_cube_layout(double r_m, nav_accel_array *out) {
  if (!out || !isfinite(r_m) || !(r_m > 0.0)) return NAV_ERR_INVALID_ARG;
  /* numerics.md 1.5 table; s = 1/sqrt(2). */
  static const double k_r[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const double k_n[6][3] = {{0, 1, 1}, {0, 1, -1}, {1, 0, 1}, {-1, 0, 1}, {1, 1, 0}, {1, -1, 0}};
  const double s = sqrt(0.5);
  nav_accel_array a;
  memset(&a, 0, sizeof a);
  a.n_sensors = 6;
  for (int i = 0; i < 6; ++i) {
    a.r_bs_b_m[i] = nav_vec3_make(r_m * k_r[i][0], r_m * k_r[i][1], r_m * k_r[i][2]);
    a.n_s_b[i] = nav_vec3_make(s * k_n[i][0], s * k_n[i][1], s * k_n[i][2]);
  }
  *out = a;
  return NAV_OK;
}

/* Checks a layout and returns its unit axes (renormalised within the tolerance). */
static nav_status check_layout(const nav_accel_array *a, nav_vec3 *n_unit) {
  if (!a || a->n_sensors < NAV_ARRAY_MIN_SENSORS || a->n_sensors > NAV_ARRAY_MAX_SENSORS)
    return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < a->n_sensors; ++i) {
    if (!nav_vec3_isfinite(a->r_bs_b_m[i]) || !nav_vec3_isfinite(a->n_s_b[i])) return NAV_ERR_INVALID_ARG;
    const double nn = nav_vec3_norm(a->n_s_b[i]);
    if (!(fabs(nn - 1.0) <= NAV_ARRAY_AXIS_UNIT_TOL)) return NAV_ERR_INVALID_ARG;
    n_unit[i] = nav_vec3_scale(a->n_s_b[i], 1.0 / nn);
  }
  return NAV_OK;
}

/* Row i of H (E1.23): [n_i^T, (r_i x n_i)^T]. */
static void h_row(nav_vec3 r, nav_vec3 n, double *row) {
  const nav_vec3 rxn = nav_vec3_cross(r, n);
  row[0] = n.x;
  row[1] = n.y;
  row[2] = n.z;
  row[3] = rxn.x;
  row[4] = rxn.y;
  row[5] = rxn.z;
}

nav_status nav_array_geometry_compute(const nav_accel_array *array, nav_array_geometry *out) {
  nav_vec3 n_unit[NAV_ARRAY_MAX_SENSORS];
  if (!out) return NAV_ERR_INVALID_ARG;
  nav_status st = check_layout(array, n_unit);
  if (st != NAV_OK) return st;
  const int n = array->n_sensors;
  nav_array_geometry g;
  memset(&g, 0, sizeof g);
  g.n_sensors = n;
  double r2 = 0.0;
  for (int i = 0; i < n; ++i)
    r2 += nav_vec3_dot(array->r_bs_b_m[i], array->r_bs_b_m[i]);
  g.r_ref_m = sqrt(r2 / (double)n);
  if (!(g.r_ref_m > 0.0) || !isfinite(g.r_ref_m)) return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < n; ++i)
    h_row(array->r_bs_b_m[i], n_unit[i], g.h[i]);

  /* Column scaling D = diag(1,1,1,1/r,1/r,1/r): Hs = H D has columns of order 1 in any unit of
   * length, so its condition number measures the geometry, not the choice of metres. */
  double u[NAV_ARRAY_MAX_SENSORS][6], v[6][6];
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < 6; ++j)
      u[i][j] = j < 3 ? g.h[i][j] : g.h[i][j] / g.r_ref_m;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
      v[i][j] = i == j ? 1.0 : 0.0;

  /* One-sided Jacobi SVD (Hestenes): rotate column pairs of U = Hs V until they are mutually
   * orthogonal; then Hs = (U Sigma^-1) Sigma V^T with sigma_j = |U_:j|. Rotations are exact
   * orthogonal transformations, so the singular values are accurate even near rank deficiency. */
  bool converged = false;
  for (int sweep = 0; sweep < 60 && !converged; ++sweep) {
    converged = true;
    for (int p = 0; p < 5; ++p)
      for (int q = p + 1; q < 6; ++q) {
        double alpha = 0.0, beta = 0.0, gamma = 0.0;
        for (int i = 0; i < n; ++i) {
          alpha += u[i][p] * u[i][p];
          beta += u[i][q] * u[i][q];
          gamma += u[i][p] * u[i][q];
        }
        if (gamma == 0.0 || fabs(gamma) <= 1e-15 * sqrt(alpha * beta)) continue;
        converged = false;
        const double zeta = (beta - alpha) / (2.0 * gamma);
        const double tr = (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
        const double c = 1.0 / sqrt(1.0 + tr * tr), s = c * tr;
        for (int i = 0; i < n; ++i) {
          const double up = u[i][p], uq = u[i][q];
          u[i][p] = c * up - s * uq;
          u[i][q] = s * up + c * uq;
        }
        for (int i = 0; i < 6; ++i) {
          const double vp = v[i][p], vq = v[i][q];
          v[i][p] = c * vp - s * vq;
          v[i][q] = s * vp + c * vq;
        }
      }
  }
  if (!converged) return NAV_ERR_NOT_CONVERGED;
  double sv[6], sv_max = 0.0, sv_min = INFINITY;
  for (int j = 0; j < 6; ++j) {
    double s2 = 0.0;
    for (int i = 0; i < n; ++i)
      s2 += u[i][j] * u[i][j];
    sv[j] = sqrt(s2);
    sv_max = fmax(sv_max, sv[j]);
    sv_min = fmin(sv_min, sv[j]);
  }
  if (!(sv_min > 0.0) || !(sv_max / sv_min <= NAV_ARRAY_MAX_COND)) return NAV_ERR_NUMERIC;
  g.cond = sv_max / sv_min;

  /* Hs^+ = V Sigma^-2 U^T (U holds u_j sigma_j) and (Hs^T Hs)^-1 = V Sigma^-2 V^T; then undo the
   * scaling: H^+ = D Hs^+, cov = D covs D (rows/columns 3..5 divided by r). */
  for (int a = 0; a < 6; ++a) {
    const double da = a < 3 ? 1.0 : 1.0 / g.r_ref_m;
    for (int i = 0; i < n; ++i) {
      double acc = 0.0;
      for (int k = 0; k < 6; ++k)
        acc += v[a][k] * u[i][k] / (sv[k] * sv[k]);
      g.h_pinv[a][i] = da * acc;
    }
    for (int b = 0; b < 6; ++b) {
      const double db = b < 3 ? 1.0 : 1.0 / g.r_ref_m;
      double acc = 0.0;
      for (int k = 0; k < 6; ++k)
        acc += v[a][k] * v[b][k] / (sv[k] * sv[k]);
      g.cov[a][b] = da * db * acc;
    }
  }
  for (int j = 0; j < 3; ++j) {
    /* numerics.md 1.5: kappa_j = r sqrt((H^-1 H^-T)_{3+j,3+j}), kappa_f likewise for f. */
    g.kappa_w[j] = g.r_ref_m * sqrt(g.cov[3 + j][3 + j]);
    g.kappa_f[j] = sqrt(g.cov[j][j]);
  }
  *out = g;
  return NAV_OK;
}

nav_status nav_array_h_det(const nav_accel_array *array, double *det_m3) {
  nav_vec3 n_unit[NAV_ARRAY_MAX_SENSORS];
  if (!det_m3 || !array || array->n_sensors != 6) return NAV_ERR_INVALID_ARG;
  nav_status st = check_layout(array, n_unit);
  if (st != NAV_OK) return st;
  double m[6][6];
  for (int i = 0; i < 6; ++i)
    h_row(array->r_bs_b_m[i], n_unit[i], m[i]);
  /* LU with partial pivoting: det = sign(P) prod U_ii. */
  double det = 1.0;
  for (int c = 0; c < 6; ++c) {
    int p = c;
    for (int i = c + 1; i < 6; ++i)
      if (fabs(m[i][c]) > fabs(m[p][c])) p = i;
    if (m[p][c] == 0.0) {
      *det_m3 = 0.0;
      return NAV_OK;
    }
    if (p != c) {
      for (int j = 0; j < 6; ++j) {
        const double tmp = m[c][j];
        m[c][j] = m[p][j];
        m[p][j] = tmp;
      }
      det = -det;
    }
    det *= m[c][c];
    for (int i = c + 1; i < 6; ++i) {
      const double f = m[i][c] / m[c][c];
      for (int j = c; j < 6; ++j)
        m[i][j] -= f * m[c][j];
    }
  }
  *det_m3 = det;
  return NAV_OK;
}

void nav_array_centripetal(const nav_accel_array *array, nav_vec3 w_ib_b_rps, double *c_mps2) {
  /* E1.22: n . (w x (w x r)) = (n . w)(r . w) - (n . r)|w|^2. */
  const double w2 = nav_vec3_dot(w_ib_b_rps, w_ib_b_rps);
  for (int i = 0; i < array->n_sensors; ++i) {
    const nav_vec3 n = array->n_s_b[i], r = array->r_bs_b_m[i];
    c_mps2[i] = nav_vec3_dot(n, w_ib_b_rps) * nav_vec3_dot(r, w_ib_b_rps) - nav_vec3_dot(n, r) * w2;
  }
}

void nav_array_readings(const nav_accel_array *array, nav_vec3 f_ib_b_mps2, nav_vec3 w_ib_b_rps,
                        nav_vec3 dw_ib_b_rps2, double *a_mps2) {
  /* E1.22 without bias and noise; the rigid-body acceleration of the sensor point is computed
   * as a vector first (f + w_dot x r + w x (w x r)) and then projected, which is the same
   * quantity as the stacked form H [f; w_dot] + c(w) of E1.23. */
  for (int i = 0; i < array->n_sensors; ++i) {
    const nav_vec3 r = array->r_bs_b_m[i];
    const nav_vec3 acc = nav_vec3_add(nav_vec3_add(f_ib_b_mps2, nav_vec3_cross(dw_ib_b_rps2, r)),
                                      nav_vec3_cross(w_ib_b_rps, nav_vec3_cross(w_ib_b_rps, r)));
    a_mps2[i] = nav_vec3_dot(array->n_s_b[i], acc);
  }
}

/* ------------------------------------------------------------------ E1.25-E1.28 */

nav_status nav_analytic_gyrofree_eval(const nav_analytic_gyrofree_spec *spec, double t_s,
                                      nav_analytic_gyrofree_errors *out) {
  if (!spec || !out || !nonneg_finite(t_s)) return NAV_ERR_INVALID_ARG;
  if (!nonneg_finite(spec->g_mps2) || !isfinite(spec->r_m) || !(spec->r_m > 0.0) ||
      !nonneg_finite(spec->kappa_w) || !nonneg_finite(spec->kappa_f) ||
      !nonneg_finite(spec->accel_bias_mps2) || !nonneg_finite(spec->accel_noise_mps_per_sqrt_s))
    return NAV_ERR_INVALID_ARG;
  const double t = t_s, g = spec->g_mps2, b = spec->accel_bias_mps2, n = spec->accel_noise_mps_per_sqrt_s;
  const double kw_r = spec->kappa_w / spec->r_m, kf = spec->kappa_f;
  nav_analytic_gyrofree_errors e;
  /* E1.25: one integration of the omega_dot error (kappa b / r, or density kappa N / r). */
  e.rate_bias_rps = kw_r * nav_analytic_bias_response(b, t, 1);
  e.rate_sd_rps = kw_r * nav_analytic_white_sd(n, t, 1);
  /* E1.26: two integrations. */
  e.att_bias_rad = kw_r * nav_analytic_bias_response(b, t, 2);
  e.att_sd_rad = kw_r * nav_analytic_white_sd(n, t, 2);
  /* E1.27: the tilt misplaces gravity (small angles only). */
  e.grav_bias_mps2 = g * e.att_bias_rad;
  e.grav_sd_mps2 = g * e.att_sd_rad;
  /* Velocity: the f error integrated once plus the gravity error integrated once (three
   * integrations of omega_dot): E1.1 kernels u^0 and u^2/2. */
  e.vel_bias_mps = kf * nav_analytic_bias_response(b, t, 1) + g * kw_r * nav_analytic_bias_response(b, t, 3);
  e.vel_sd_mps = hypot(kf * nav_analytic_white_sd(n, t, 1), g * kw_r * nav_analytic_white_sd(n, t, 3));
  /* E1.28 with the corrected t^7/252 (kernel u^3/6, four integrations). */
  e.pos_bias_m = kf * nav_analytic_bias_response(b, t, 2) + g * kw_r * nav_analytic_bias_response(b, t, 4);
  e.pos_sd_m = hypot(kf * nav_analytic_white_sd(n, t, 2), g * kw_r * nav_analytic_white_sd(n, t, 4));
  *out = e;
  return NAV_OK;
}

nav_status nav_analytic_gyrofree_spec_from_geometry(const nav_array_geometry *geom, double g_mps2,
                                                    double accel_bias_mps2, double accel_noise_mps_per_sqrt_s,
                                                    nav_analytic_gyrofree_spec *out) {
  if (!geom || !out) return NAV_ERR_INVALID_ARG;
  nav_analytic_gyrofree_spec s;
  s.g_mps2 = g_mps2;
  s.r_m = geom->r_ref_m;
  s.kappa_w = fmax(fmax(geom->kappa_w[0], geom->kappa_w[1]), geom->kappa_w[2]);
  s.kappa_f = fmax(fmax(geom->kappa_f[0], geom->kappa_f[1]), geom->kappa_f[2]);
  s.accel_bias_mps2 = accel_bias_mps2;
  s.accel_noise_mps_per_sqrt_s = accel_noise_mps_per_sqrt_s;
  *out = s;
  return NAV_OK;
}

/* ------------------------------------------------------------------ the paper's formulas */

double nav_analytic_paper_gyrofree_position_noise_630(double sigma_mps2, double r_m, double dt_s,
                                                      double g_mps2, double t_s) {
  /* Paper, formula (1), noise part, as printed: the 630 is wrong (252, E1.28), kappa = 1. */
  const double t = t_s;
  return sigma_mps2 *
         sqrt(t * t * t * dt_s / 3.0 + (g_mps2 / r_m) * (g_mps2 / r_m) * pow(t, 7.0) * dt_s / 630.0);
}

double nav_analytic_paper_gyrofree_position_sigma_630(double b_mps2, double sigma_mps2, double r_m,
                                                      double dt_s, double g_mps2, double t_s) {
  /* Paper, formula (1), as printed: bias part + noise part added linearly. */
  const double t = t_s;
  return b_mps2 * (g_mps2 * pow(t, 4.0) / (r_m * 24.0) + t * t / 2.0) +
         nav_analytic_paper_gyrofree_position_noise_630(sigma_mps2, r_m, dt_s, g_mps2, t_s);
}

double nav_analytic_coriolis_scale_mps(double drive_rate_rps, double drive_amplitude_m) {
  /* numerics.md 1.4: Coriolis acceleration 2 Omega (w r) for drive velocity amplitude w r. */
  return 2.0 * drive_rate_rps * drive_amplitude_m;
}

double nav_analytic_paper_gyro_ins_position_bias(double b_a_mps2, double drive_rate_rps,
                                                 double drive_amplitude_m, double g_mps2, double t_s) {
  /* Paper, formula (2), bias part: b_a (g t^3/(12 w r) + t^2/2) = E1.10 + E1.14 with
   * b_g = b_a / (2 w r). */
  const double t = t_s;
  return b_a_mps2 * (g_mps2 * t * t * t / (12.0 * drive_rate_rps * drive_amplitude_m) + t * t / 2.0);
}

static double coriolis_noise(double sigma_a, double w, double r, double dt, double g, double t,
                             double coeff) {
  const double k = g / nav_analytic_coriolis_scale_mps(w, r);
  return sigma_a * sqrt(t * t * t * dt / 3.0 + k * k * pow(t, 5.0) * dt / coeff);
}

double nav_analytic_paper_gyro_ins_position_noise_30(double sigma_a_mps2, double drive_rate_rps,
                                                     double drive_amplitude_m, double dt_s, double g_mps2,
                                                     double t_s) {
  /* Paper, formula (2), noise part as printed: the 30 is wrong (20, E1.15). */
  return coriolis_noise(sigma_a_mps2, drive_rate_rps, drive_amplitude_m, dt_s, g_mps2, t_s, 30.0);
}

double nav_analytic_paper_gyro_ins_position_sigma_30(double b_a_mps2, double sigma_a_mps2,
                                                     double drive_rate_rps, double drive_amplitude_m,
                                                     double dt_s, double g_mps2, double t_s) {
  /* Paper, formula (2), as printed: bias part + noise part added linearly. */
  return nav_analytic_paper_gyro_ins_position_bias(b_a_mps2, drive_rate_rps, drive_amplitude_m, g_mps2, t_s) +
         nav_analytic_paper_gyro_ins_position_noise_30(sigma_a_mps2, drive_rate_rps, drive_amplitude_m, dt_s,
                                                       g_mps2, t_s);
}

double nav_analytic_coriolis_gyro_ins_position_noise(double sigma_a_mps2, double drive_rate_rps,
                                                     double drive_amplitude_m, double dt_s, double g_mps2,
                                                     double t_s) {
  /* E1.11 + E1.15 with sigma_g = sigma_a / (2 w r) (numerics.md 1.4, corrected /20). */
  return coriolis_noise(sigma_a_mps2, drive_rate_rps, drive_amplitude_m, dt_s, g_mps2, t_s, 20.0);
}

/* ------------------------------------------------------------------ preliminary estimate */

nav_analytic_estimate_config nav_analytic_estimate_config_default(void) {
  nav_analytic_estimate_config c;
  memset(&c, 0, sizeof c);
  c.imu = nav_analytic_imu_spec_default();
  c.with_gyrofree = false;
  /* The cube layout of numerics.md 1.5 with r = 0.1 m cannot fail. */
  if (nav_array_cube_layout(0.1, &c.array) != NAV_OK) c.array.n_sensors = 0;
  return c;
}

nav_status nav_analytic_estimate(const nav_analytic_estimate_config *cfg, const double *t_s, size_t count,
                                 nav_analytic_estimate_point *out) {
  if (!cfg || (count > 0 && (!t_s || !out))) return NAV_ERR_INVALID_ARG;
  if (!imu_spec_ok(&cfg->imu)) return NAV_ERR_INVALID_ARG;
  for (size_t i = 0; i < count; ++i)
    if (!nonneg_finite(t_s[i])) return NAV_ERR_INVALID_ARG;
  nav_analytic_gyrofree_spec gf;
  memset(&gf, 0, sizeof gf);
  if (cfg->with_gyrofree) {
    if (!nonneg_finite(cfg->array_accel_bias_mps2) || !nonneg_finite(cfg->array_accel_noise_mps_per_sqrt_s) ||
        !nonneg_finite(cfg->array_init_rate_sd_rps))
      return NAV_ERR_INVALID_ARG;
    nav_array_geometry geom;
    nav_status st = nav_array_geometry_compute(&cfg->array, &geom);
    if (st != NAV_OK) return st;
    st = nav_analytic_gyrofree_spec_from_geometry(&geom, cfg->imu.g_mps2, cfg->array_accel_bias_mps2,
                                                  cfg->array_accel_noise_mps_per_sqrt_s, &gf);
    if (st != NAV_OK) return st;
  }
  /* Schuler rate for the validity flag (numerics.md 1.2 (ii)): the table's bias terms are
   * within 1 % of E1.18 while (omega_s t)^2 / 12 < 0.01. */
  const double ws = nav_analytic_schuler_rate_rps(cfg->imu.g_mps2, NAV_WGS84_A_M);
  for (size_t i = 0; i < count; ++i) {
    const double t = t_s[i];
    nav_analytic_gyro_ins_table tab;
    nav_status st = nav_analytic_gyro_ins_table_eval(&cfg->imu, t, &tab);
    if (st != NAV_OK) return st; /* unreachable: inputs checked above */
    nav_analytic_estimate_point p;
    memset(&p, 0, sizeof p);
    p.t_s = t;
    p.gyro_ins.att_sd_rad = tab.rss.att_rad;
    p.gyro_ins.vel_sd_mps = tab.rss.vel_mps;
    p.gyro_ins.pos_sd_m = tab.rss.pos_m;
    p.gyro_ins_short_time_ok = (ws * t) * (ws * t) / 12.0 < 0.01;
    if (cfg->with_gyrofree) {
      nav_analytic_gyrofree_errors e;
      st = nav_analytic_gyrofree_eval(&gf, t, &e);
      if (st != NAV_OK) return st;
      const double g = cfg->imu.g_mps2, w0 = cfg->array_init_rate_sd_rps, b = gf.accel_bias_mps2;
      const double kw_r = gf.kappa_w / gf.r_m;
      /* Initial-condition rows shared with the gyro INS (E1.6-E1.9). */
      double va = 0.0, vv = 0.0, vp = 0.0;
      for (int k = NAV_ANALYTIC_TERM_INIT_POS; k <= NAV_ANALYTIC_TERM_INIT_HEADING; ++k) {
        va += tab.term[k].att_rad * tab.term[k].att_rad;
        vv += tab.term[k].vel_mps * tab.term[k].vel_mps;
        vp += tab.term[k].pos_m * tab.term[k].pos_m;
      }
      /* Initial rate error: integrated once into attitude, then as the gyro-bias chain of E1.14
       * shifted by one integration (att w0 t, vel g w0 t^2/2, pos g w0 t^3/6). */
      const double a_w0 = nav_analytic_bias_response(w0, t, 1);
      const double v_w0 = g * nav_analytic_bias_response(w0, t, 2);
      const double p_w0 = g * nav_analytic_bias_response(w0, t, 3);
      /* Bias chain E1.25-E1.28 with the f and omega_dot parts as independent random constants. */
      const double a_b = e.att_bias_rad;
      const double v_bf = gf.kappa_f * nav_analytic_bias_response(b, t, 1);
      const double v_bw = g * kw_r * nav_analytic_bias_response(b, t, 3);
      const double p_bf = gf.kappa_f * nav_analytic_bias_response(b, t, 2);
      const double p_bw = g * kw_r * nav_analytic_bias_response(b, t, 4);
      va += a_w0 * a_w0 + a_b * a_b + e.att_sd_rad * e.att_sd_rad;
      vv += v_w0 * v_w0 + v_bf * v_bf + v_bw * v_bw + e.vel_sd_mps * e.vel_sd_mps;
      vp += p_w0 * p_w0 + p_bf * p_bf + p_bw * p_bw + e.pos_sd_m * e.pos_sd_m;
      p.gyrofree.att_sd_rad = sqrt(va);
      p.gyrofree.vel_sd_mps = sqrt(vv);
      p.gyrofree.pos_sd_m = sqrt(vp);
      p.gyrofree_small_angle_ok = p.gyrofree.att_sd_rad < 0.05;
      /* Paper's (1) with sigma^2 dt = N^2: evaluate with dt = 1 s and sigma = N. */
      p.gyrofree_paper_pos_m =
          nav_analytic_paper_gyrofree_position_sigma_630(b, gf.accel_noise_mps_per_sqrt_s, gf.r_m, 1.0, g, t);
    }
    out[i] = p;
  }
  return NAV_OK;
}
