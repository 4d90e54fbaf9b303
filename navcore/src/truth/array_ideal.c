/*
 * Accelerometer-array layouts (the nine- and twelve-sensor ones and the scene's; the cube is in
 * analytic.c) and exact ideal array increments from the reference trajectory (numerics.md 1.5,
 * E1.22, with the integration rules of section 3.1).
 *
 * Each sensor i reads A_i = n_i . (f + omega_dot x r_i + omega x (omega x r_i)) (body axes,
 * omega = omega_ib_b); its increment over a sample interval is the integral of A_i, taken by
 * n-point Gauss-Legendre quadrature with f, omega and omega_dot from the trajectory at the
 * nodes. n_i and r_i are fixed in the body, so projecting before integrating is exact. For the
 * smooth trajectories of section 3 the quadrature is at round-off with 6 nodes (section 3.1).
 *
 * Flat Earth: f_b = C_l_b (a_l - g_l), omega = omega_lb_b.
 * WGS-84 (E3.7-E3.8, as imu_ideal.c): f_b = C_e_b (a_e + 2 omega_ie_e x v_e - g_e(r_e)),
 * omega_ib_b = C_e_b omega_ie_e + omega_eb_b, and its body-frame derivative
 * omega_dot_ib_b = omega_dot_eb_b - omega_eb_b x (C_e_b omega_ie_e), because
 * d/dt C_e_b = -[omega_eb_b x] C_e_b and omega_ie_e is constant.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_array.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_truth.h"

/* ------------------------------------------------------------------ layouts */

/* A layout from tables of r_i / r and n_i / n_scale (n_scale makes the axes unit vectors: 1 for
 * coordinate axes, sqrt(1/2) for face diagonals, as nav_array_cube_layout() computes them, so the
 * twelve-sensor layout's first six sensors equal the cube's bit for bit). The geometry and the
 * kappa of each layout are derived in nav_array.h. */
static nav_status layout_from_table(double r_m, int n, const double (*k_r)[3], const double (*k_n)[3],
                                    double n_scale, nav_accel_array *out) {
  if (!out || !isfinite(r_m) || !(r_m > 0.0)) return NAV_ERR_INVALID_ARG;
  nav_accel_array a;
  memset(&a, 0, sizeof a);
  a.n_sensors = n;
  for (int i = 0; i < n; ++i) {
    a.r_bs_b_m[i] = nav_vec3_make(r_m * k_r[i][0], r_m * k_r[i][1], r_m * k_r[i][2]);
    a.n_s_b[i] = nav_vec3_make(n_scale * k_n[i][0], n_scale * k_n[i][1], n_scale * k_n[i][2]);
  }
  *out = a;
  return NAV_OK;
}

nav_status nav_array_nine_layout(double r_m, nav_accel_array *out) {
  /* Padgaonkar 3-2-2-2: a triad at O, then two sensors across each positive axis. */
  static const double k_r[9][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {1, 0, 0}, {1, 0, 0},
                                   {0, 1, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, 1}};
  static const double k_n[9][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 1, 0}, {0, 0, 1},
                                   {1, 0, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
  return layout_from_table(r_m, 9, k_r, k_n, 1.0, out);
}

nav_status nav_array_twelve_layout(double r_m, nav_accel_array *out) {
  /* The cube (numerics.md 1.5 table), then the other diagonal of each face. */
  static const double k_r[12][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1},
                                    {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  static const double k_n[12][3] = {{0, 1, 1},  {0, 1, -1}, {1, 0, 1},  {-1, 0, 1}, {1, 1, 0},  {1, -1, 0},
                                    {0, 1, -1}, {0, 1, 1},  {1, 0, -1}, {1, 0, 1},  {1, -1, 0}, {1, 1, 0}};
  return layout_from_table(r_m, 12, k_r, k_n, sqrt(0.5), out);
}

nav_status nav_array_layout_from_scene(const nav_scene_array *sa, nav_accel_array *out) {
  if (!sa || !out) return NAV_ERR_INVALID_ARG;
  switch (sa->layout) {
  case NAV_ARRAY_LAYOUT_CUBE6: return nav_array_cube_layout(sa->radius_m, out);
  case NAV_ARRAY_LAYOUT_NINE: return nav_array_nine_layout(sa->radius_m, out);
  case NAV_ARRAY_LAYOUT_TWELVE: return nav_array_twelve_layout(sa->radius_m, out);
  case NAV_ARRAY_LAYOUT_CUSTOM: break;
  default: return NAV_ERR_INVALID_ARG;
  }
  if (sa->custom_count < NAV_ARRAY_MIN_SENSORS || sa->custom_count > NAV_ARRAY_MAX_SENSORS)
    return NAV_ERR_INVALID_ARG;
  nav_accel_array a;
  memset(&a, 0, sizeof a);
  a.n_sensors = sa->custom_count;
  for (int i = 0; i < a.n_sensors; ++i) {
    const nav_scene_array_sensor *c = &sa->custom[i];
    const double nn = nav_vec3_norm(c->n_s_b);
    if (!nav_vec3_isfinite(c->r_bs_b_m) || !nav_vec3_isfinite(c->n_s_b) || !(nn > 0.0) || !isfinite(nn))
      return NAV_ERR_INVALID_ARG;
    a.r_bs_b_m[i] = c->r_bs_b_m;
    a.n_s_b[i] = nav_vec3_scale(c->n_s_b, 1.0 / nn);
  }
  *out = a;
  return NAV_OK;
}

/* ------------------------------------------------------------------ ideal increments */

struct nav_array_truth {
  nav_traj *traj;
  nav_frame frame;
  nav_gravity_model gravity;
  nav_accel_array array;
  double dt_s;
  int64_t n_samples;
  nav_vec3 g_l_mps2;
  int n_nodes;
  double nodes[NAV_GL_MAX_NODES];
  double weights[NAV_GL_MAX_NODES];
};

static void set_msg(char *msg, size_t msg_size, const char *text) {
  if (msg && msg_size) snprintf(msg, msg_size, "%s", text);
}

nav_status nav_array_truth_create_msg(const nav_scene *scene, const nav_accel_array *array,
                                      nav_array_truth **out, char *msg, size_t msg_size) {
  nav_array_truth *tr = NULL;
  nav_status st = NAV_OK;
  nav_array_geometry geom;
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !array || !out) return NAV_ERR_INVALID_ARG;
  if (!(scene->imu.rate_hz > 0.0) || !(scene->trajectory.duration_s > 0.0)) {
    set_msg(msg, msg_size, "imu.rate_hz and trajectory.duration_s must be positive");
    return NAV_ERR_INVALID_ARG;
  }
  /* Reject layouts the navigation could not invert, with the same checks. */
  st = nav_array_geometry_compute(array, &geom);
  if (st != NAV_OK) {
    set_msg(msg, msg_size,
            "accelerometer array: invalid or singular layout (see nav_array_geometry_compute)");
    return st;
  }
  tr = calloc(1, sizeof *tr);
  if (!tr) return NAV_ERR_NO_MEMORY;
  tr->array = *array;
  for (int i = 0; i < array->n_sensors; ++i)
    tr->array.n_s_b[i] = nav_vec3_scale(array->n_s_b[i], 1.0 / nav_vec3_norm(array->n_s_b[i]));
  tr->dt_s = 1.0 / scene->imu.rate_hz;
  tr->n_samples = (int64_t)floor(scene->trajectory.duration_s * scene->imu.rate_hz + 1e-9);
  tr->g_l_mps2 = nav_vec3_make(0.0, 0.0, scene->earth.flat_gravity_mps2);
  tr->gravity = scene->earth.gravity_model;
  tr->frame = nav_frame_from_scene(scene);
  tr->n_nodes = scene->imu.quadrature_nodes;
  st = nav_gauss_legendre(tr->n_nodes, tr->nodes, tr->weights);
  if (st != NAV_OK) {
    set_msg(msg, msg_size, "imu.quadrature_nodes out of range");
    goto cleanup;
  }
  st = nav_traj_create_msg(scene, tr->dt_s, &tr->traj, msg, msg_size);
  if (st != NAV_OK) goto cleanup;
  *out = tr;
  tr = NULL;
cleanup:
  nav_array_truth_destroy(tr);
  return st;
}

nav_status nav_array_truth_create(const nav_scene *scene, const nav_accel_array *array,
                                  nav_array_truth **out) {
  return nav_array_truth_create_msg(scene, array, out, NULL, 0);
}

void nav_array_truth_destroy(nav_array_truth *truth) {
  if (!truth) return;
  nav_traj_destroy(truth->traj);
  free(truth);
}

double nav_array_truth_dt(const nav_array_truth *truth) {
  return truth ? truth->dt_s : 0.0;
}
int64_t nav_array_truth_sample_count(const nav_array_truth *truth) {
  return truth ? truth->n_samples : 0;
}
nav_frame nav_array_truth_frame(const nav_array_truth *truth) {
  return truth->frame;
}
const nav_accel_array *nav_array_truth_layout(const nav_array_truth *truth) {
  return truth ? &truth->array : NULL;
}

nav_status nav_array_truth_state(nav_array_truth *truth, double t_s, nav_traj_state *out) {
  if (!truth || !out) return NAV_ERR_INVALID_ARG;
  return nav_traj_eval(truth->traj, t_s, out);
}

/* Specific force, inertial angular rate and its derivative in body axes at one trajectory state. */
static void body_kinematics(const nav_array_truth *tr, const nav_traj_state *s, nav_vec3 *f_b,
                            nav_vec3 *w_ib_b, nav_vec3 *dw_ib_b) {
  const nav_quat q_f_b = nav_quat_conj(s->q_b_f);
  if (tr->frame.model == NAV_EARTH_FLAT) {
    *f_b = nav_quat_rotate(q_f_b, nav_vec3_sub(s->a_fb_f_mps2, tr->g_l_mps2));
    *w_ib_b = s->w_fb_b_rps;
    *dw_ib_b = s->dw_fb_b_rps2;
    return;
  }
  const nav_vec3 w_ie_e = nav_earth_rate_e_rps();
  const nav_vec3 f_e =
      nav_vec3_sub(nav_vec3_add(s->a_fb_f_mps2, nav_vec3_scale(nav_vec3_cross(w_ie_e, s->v_fb_f_mps), 2.0)),
                   nav_gravity_e_mps2(tr->gravity, s->r_fb_f_m));
  const nav_vec3 w_ie_b = nav_quat_rotate(q_f_b, w_ie_e);
  *f_b = nav_quat_rotate(q_f_b, f_e);
  *w_ib_b = nav_vec3_add(w_ie_b, s->w_fb_b_rps);
  *dw_ib_b = nav_vec3_sub(s->dw_fb_b_rps2, nav_vec3_cross(s->w_fb_b_rps, w_ie_b));
}

nav_status nav_array_truth_rate(nav_array_truth *truth, double t_s, nav_vec3 *w_ib_b_rps) {
  if (!truth || !w_ib_b_rps) return NAV_ERR_INVALID_ARG;
  nav_traj_state s;
  nav_status st = nav_traj_eval(truth->traj, t_s, &s);
  if (st != NAV_OK) return st;
  nav_vec3 f, w, dw;
  body_kinematics(truth, &s, &f, &w, &dw);
  *w_ib_b_rps = w;
  return NAV_OK;
}

nav_status nav_array_truth_sample(nav_array_truth *truth, int64_t k, nav_array_increment *out) {
  if (!truth || !out || k < 1) return NAV_ERR_INVALID_ARG;
  /* Sample times from the integer index (style.md section 4), never accumulated. */
  const double t0 = (double)(k - 1) * truth->dt_s, t1 = (double)k * truth->dt_s;
  const double half = 0.5 * (t1 - t0), mid = 0.5 * (t1 + t0);
  const int n = truth->array.n_sensors;
  nav_array_increment r;
  memset(&r, 0, sizeof r);
  r.k = k;
  r.t_s = t1;
  r.dt_s = t1 - t0;
  r.n_sensors = n;
  for (int j = 0; j < truth->n_nodes; ++j) {
    nav_traj_state s;
    const nav_status st = nav_traj_eval(truth->traj, mid + half * truth->nodes[j], &s);
    if (st != NAV_OK) return st;
    nav_vec3 f_b, w_ib_b, dw_ib_b;
    body_kinematics(truth, &s, &f_b, &w_ib_b, &dw_ib_b);
    double a[NAV_ARRAY_MAX_SENSORS];
    nav_array_readings(&truth->array, f_b, w_ib_b, dw_ib_b, a);
    const double wgt = truth->weights[j] * half;
    for (int i = 0; i < n; ++i)
      r.dv_mps[i] += wgt * a[i];
  }
  *out = r;
  return NAV_OK;
}
