/*
 * Exact ideal IMU increments from the reference trajectory (numerics.md section 3).
 * Flat Earth: omega_ib_b = omega_lb_b, f_b = C_l_b (a_l - g_l).
 * WGS-84 (truth in ECEF, E3.7-E3.8): f_e = a_e + 2 omega_ie_e x v_e - g_e(r_e),
 * f_b = C_e_b f_e, omega_ib_b = C_e_b omega_ie_e + omega_eb_b, with the same gravity model as
 * the mechanization. Both increments are integrated by n-point Gauss-Legendre quadrature over
 * the sample interval; the gyro increment uses the model's closed form where there is one.
 */
#include <stdlib.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_truth.h"

struct nav_truth {
  nav_traj *traj;
  nav_frame frame;
  nav_gravity_model gravity;
  double dt_s;
  int64_t n_samples;
  nav_vec3 g_l_mps2;
  int n_nodes;
  double nodes[NAV_GL_MAX_NODES];
  double weights[NAV_GL_MAX_NODES];
  char msg[256];
};

nav_status nav_gauss_legendre(int n, double *nodes, double *weights) {
  if (n < 1 || n > NAV_GL_MAX_NODES || !nodes || !weights) return NAV_ERR_INVALID_ARG;
  /* Roots of P_n by Newton's method from the initial guess cos(pi (i + 3/4) / (n + 1/2))
   * (Abramowitz & Stegun 22.16.6); the three-term recurrence (m) P_m = (2m - 1) x P_(m-1) -
   * (m - 1) P_(m-2) gives P_n, and P_n' = n (x P_n - P_(n-1)) / (x^2 - 1); weights
   * 2 / ((1 - x^2) P_n'(x)^2) (A&S 25.4.29). */
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = cos(NAV_PI * ((double)i + 0.75) / ((double)n + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;
      for (int m = 2; m <= n; ++m) {
        const double p2 = ((2.0 * m - 1.0) * x * p1 - (m - 1.0) * p0) / (double)m;
        p0 = p1;
        p1 = p2;
      }
      dp = (double)n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (fabs(dx) < 1e-17) break;
    }
    {
      double p0 = 1.0, p1 = x;
      for (int m = 2; m <= n; ++m) {
        const double p2 = ((2.0 * m - 1.0) * x * p1 - (m - 1.0) * p0) / (double)m;
        p0 = p1;
        p1 = p2;
      }
      dp = (double)n * (x * p1 - p0) / (x * x - 1.0);
    }
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    nodes[i] = -x;
    nodes[n - 1 - i] = x;
    weights[i] = w;
    weights[n - 1 - i] = w;
  }
  if (n % 2 == 1) nodes[n / 2] = 0.0;
  return NAV_OK;
}

nav_vec3 nav_gravity_e_mps2(nav_gravity_model model, nav_vec3 r_eb_e_m) {
  if (model == NAV_GRAVITY_J2) return nav_earth_gravity_j2_e_mps2(r_eb_e_m);
  const nav_geodetic p = nav_earth_ecef_to_geodetic(r_eb_e_m);
  /* C_n_e (0, 0, gamma(lat, h)): nav_earth_dcm_n_e() applied to nav_earth_gravity_n_mps2(), the same
   * operations written out so that sin(lat) is evaluated once for both (the ECEF mechanization calls this
   * every step); test_mech checks the agreement with those functions bit for bit. */
  const double s = sin(p.lat_rad), c = cos(p.lat_rad);
  const double so = sin(p.lon_rad), co = cos(p.lon_rad);
  const double s2 = s * s, h = p.h_m;
  const double ea = NAV_WGS84_A_M;
  const double lin = (2.0 / ea) * (1.0 + NAV_WGS84_F + NAV_WGS84_M - 2.0 * NAV_WGS84_F * s2);
  const double quad = 3.0 / (ea * ea);
  const double surface =
      NAV_WGS84_GAMMA_E_MPS2 * (1.0 + NAV_WGS84_SOMIGLIANA_K * s2) / sqrt(1.0 - NAV_WGS84_E2 * s2);
  const nav_vec3 g_n = nav_vec3_make(0.0, 0.0, surface * (1.0 - lin * h + quad * h * h));
  const nav_mat3 C_n_e = {{{-s * co, -so, -c * co}, {-s * so, co, -c * so}, {c, 0.0, -s}}};
  return nav_mat3_mul_vec(C_n_e, g_n);
}

nav_status nav_truth_create_msg(const nav_scene *scene, nav_truth **out, char *msg, size_t msg_size) {
  nav_truth *tr = NULL;
  nav_status st = NAV_OK;
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !out) return NAV_ERR_INVALID_ARG;
  if (!(scene->imu.rate_hz > 0.0) || !(scene->trajectory.duration_s > 0.0)) return NAV_ERR_INVALID_ARG;
  tr = calloc(1, sizeof *tr);
  if (!tr) return NAV_ERR_NO_MEMORY;
  tr->dt_s = 1.0 / scene->imu.rate_hz;
  tr->n_samples = (int64_t)floor(scene->trajectory.duration_s * scene->imu.rate_hz + 1e-9);
  tr->g_l_mps2 = nav_vec3_make(0.0, 0.0, scene->earth.flat_gravity_mps2);
  tr->gravity = scene->earth.gravity_model;
  tr->frame = nav_frame_from_scene(scene);
  tr->n_nodes = scene->imu.quadrature_nodes;
  st = nav_gauss_legendre(tr->n_nodes, tr->nodes, tr->weights);
  if (st != NAV_OK) goto cleanup;
  st = nav_traj_create_msg(scene, tr->dt_s, &tr->traj, msg, msg_size);
  if (st != NAV_OK) goto cleanup;
  *out = tr;
  tr = NULL;
cleanup:
  nav_truth_destroy(tr);
  return st;
}

nav_status nav_truth_create(const nav_scene *scene, nav_truth **out) {
  return nav_truth_create_msg(scene, out, NULL, 0);
}

void nav_truth_destroy(nav_truth *truth) {
  if (!truth) return;
  nav_traj_destroy(truth->traj);
  free(truth);
}

double nav_truth_dt(const nav_truth *truth) { return truth ? truth->dt_s : 0.0; }
int64_t nav_truth_sample_count(const nav_truth *truth) { return truth ? truth->n_samples : 0; }
nav_frame nav_truth_frame(const nav_truth *truth) { return truth->frame; }

/* Numerical guard of a state (one test for all: any NaN or infinity propagates into the sum). */
static bool state_finite(const nav_traj_state *s) {
  return isfinite(s->r_fb_f_m.x + s->r_fb_f_m.y + s->r_fb_f_m.z + s->v_fb_f_mps.x + s->v_fb_f_mps.y +
                  s->v_fb_f_mps.z + s->q_b_f.w + s->q_b_f.x + s->q_b_f.y + s->q_b_f.z);
}

/* The increment over [t0, t1] ending at sample k without its node sums: the time stamps and, where
 * the trajectory integrates the rate in closed form, the rotation vector (*closed). */
static inline nav_status increment_start(nav_truth *truth, int64_t k, double t0, double t1, nav_imu_increment *r,
                                         bool *closed) {
  r->k = k;
  r->t_s = t1;
  r->dt_s = t1 - t0;
  *closed = false;
  /* On WGS-84 nav_traj_rate_integral has no closed form: its answer (the argument check, then no
   * closed form) without the call. */
  if (truth->frame.model != NAV_EARTH_FLAT) return isfinite(t0) && isfinite(t1) ? NAV_OK : NAV_ERR_INVALID_ARG;
  return nav_traj_rate_integral(truth->traj, t0, t1, &r->dtheta_b_rad, closed);
}

/* The increment with the node sums dv and dth (dth only where the rate has no closed form). */
static inline nav_status increment_finish(nav_imu_increment *r, bool closed, nav_vec3 dv, nav_vec3 dth) {
  if (!closed) r->dtheta_b_rad = dth;
  r->dv_b_mps = dv;
  return nav_vec3_isfinite(r->dtheta_b_rad) && nav_vec3_isfinite(r->dv_b_mps) ? NAV_OK : NAV_ERR_NUMERIC;
}

nav_status nav_truth_state(nav_truth *truth, double t_s, nav_traj_state *out) {
  if (!truth) return NAV_ERR_INVALID_ARG;
  const nav_status st = nav_traj_eval(truth->traj, t_s, out);
  if (st != NAV_OK) return st;
  return state_finite(out) ? NAV_OK : NAV_ERR_NUMERIC;
}

nav_status nav_truth_imu(nav_truth *truth, int64_t k, nav_imu_increment *out) {
  if (!truth || !out || k < 1) return NAV_ERR_INVALID_ARG;
  const double t0 = (double)(k - 1) * truth->dt_s, t1 = (double)k * truth->dt_s;
  nav_imu_increment r;
  bool closed;
  nav_status st = increment_start(truth, k, t0, t1, &r, &closed);
  if (st != NAV_OK) return st;
  /* Gauss-Legendre over the interval, all nodes at once (nav_traj_inertial_increment). */
  nav_vec3 dv, dth;
  st = nav_traj_inertial_increment(truth->traj, t0, t1, truth->n_nodes, truth->nodes, truth->weights, &dv,
                                   &dth);
  if (st != NAV_OK) return st;
  st = increment_finish(&r, closed, dv, dth);
  if (st != NAV_OK) return st;
  *out = r;
  return NAV_OK;
}

nav_status nav_truth_sample(nav_truth *truth, int64_t k, nav_traj_state *state, nav_imu_increment *imu) {
  if (!truth || !state || !imu || k < 1) return NAV_ERR_INVALID_ARG;
  const double t0 = (double)(k - 1) * truth->dt_s, t1 = (double)k * truth->dt_s;
  nav_imu_increment r;
  bool closed;
  nav_status st = increment_start(truth, k, t0, t1, &r, &closed);
  if (st != NAV_OK) return st;
  nav_vec3 dv, dth;
  nav_traj_state s;
  st = nav_traj_sample(truth->traj, k, truth->n_nodes, truth->nodes, truth->weights, &s, &dv, &dth);
  if (st != NAV_OK) return st;
  /* The guards of nav_truth_imu and nav_truth_state. */
  st = increment_finish(&r, closed, dv, dth);
  if (st != NAV_OK) return st;
  if (!state_finite(&s)) return NAV_ERR_NUMERIC;
  *state = s;
  *imu = r;
  return NAV_OK;
}
