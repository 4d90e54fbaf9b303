/*
 * The paper's parametric trajectory (Soloviev, Sablin, Lyalinsky, formula (3)), with the
 * corrections of numerics.md section 3.1:
 *   R(t) = R0 + V0 t + A t^2 + B sin(2 pi C t + D)            (E3.1, element-wise, l frame)
 *   omega_lb_b(t) = a + b sin(2 pi c t + d)                     (E3.2, body axes)
 * Attitude (Option B): C_dot = C [omega x] integrated by the 4th-order Magnus step (E3.5) on a
 * sub-grid h_s = dt / substeps aligned with the IMU samples. The paper's own first-order
 * recursion C_i = C_{i-1} exp(Omega(t_i) dt) is O(dt) and is NOT used as truth.
 */
#include <stdlib.h>
#include <string.h>

#include <stdio.h>

#include "traj/traj_internal.h"

/* One checkpoint of the integrated attitude every CHECKPOINT_STRIDE grid steps, so evaluation
 * at an earlier time re-integrates at most that many steps. */
#define CHECKPOINT_STRIDE 4096

typedef struct param_model {
  double duration_s;
  nav_traj_parametric p;
  nav_quat q0_b_l;
  double h_s;          /* Magnus sub-grid step */
  nav_quat *checkpoints; /* q_b_l at grid index i * CHECKPOINT_STRIDE, i < n_valid */
  int64_t n_checkpoints;
  int64_t n_valid;
  int64_t cache_j;     /* grid index of the cached attitude */
  nav_quat cache_q;
} param_model;

/* omega(t) = a + b sin(2 pi c t + d), element-wise (E3.2). */
static nav_vec3 param_rate(const nav_traj_parametric *p, double t) {
  return nav_vec3_make(p->wa_rps.x + p->wb_rps.x * sin(NAV_TWO_PI * p->wc_hz.x * t + p->wd_rad.x),
                       p->wa_rps.y + p->wb_rps.y * sin(NAV_TWO_PI * p->wc_hz.y * t + p->wd_rad.y),
                       p->wa_rps.z + p->wb_rps.z * sin(NAV_TWO_PI * p->wc_hz.z * t + p->wd_rad.z));
}

static double rate_dot_1(double b, double c, double d, double t) {
  const double w = NAV_TWO_PI * c;
  return b * w * cos(w * t + d);
}

/*
 * One 4th-order Magnus step of C_dot = C [omega x] from t0 over h (h may be negative or zero),
 * numerics.md E3.5: two-point Gauss-Legendre nodes, sigma = h/2 (w_a + w_b) +
 * (sqrt(3)/12) h^2 (w_a x w_b), then C <- C exp([sigma x]).
 */
static nav_quat magnus_step(const nav_traj_parametric *p, nav_quat q, double t0, double h) {
  static const double k_off = 0.28867513459481288225; /* sqrt(3)/6 */
  static const double k_cross = 0.14433756729740644113; /* sqrt(3)/12 */
  const nav_vec3 w_a = param_rate(p, t0 + (0.5 - k_off) * h);
  const nav_vec3 w_b = param_rate(p, t0 + (0.5 + k_off) * h);
  const nav_vec3 sigma =
      nav_vec3_add(nav_vec3_scale(nav_vec3_add(w_a, w_b), 0.5 * h), nav_vec3_scale(nav_vec3_cross(w_a, w_b), k_cross * h * h));
  return nav_quat_normalize(nav_quat_mul(q, nav_quat_from_rotvec(sigma)));
}

static double grid_time(const param_model *tr, int64_t j) { return (double)j * tr->h_s; }

/* Advance the cached attitude to grid index j (j >= 0). Checkpoints are recorded as the cache
 * walks forward, so going back costs at most CHECKPOINT_STRIDE steps. */
static void advance_cache(param_model *tr, int64_t j) {
  if (j < tr->cache_j) {
    int64_t c = j / CHECKPOINT_STRIDE;
    if (c >= tr->n_valid) c = tr->n_valid - 1;
    tr->cache_j = c * CHECKPOINT_STRIDE;
    tr->cache_q = tr->checkpoints[c];
  }
  while (tr->cache_j < j) {
    tr->cache_q = magnus_step(&tr->p, tr->cache_q, grid_time(tr, tr->cache_j), tr->h_s);
    tr->cache_j++;
    if (tr->cache_j % CHECKPOINT_STRIDE == 0) {
      const int64_t c = tr->cache_j / CHECKPOINT_STRIDE;
      if (c < tr->n_checkpoints) {
        tr->checkpoints[c] = tr->cache_q;
        if (c >= tr->n_valid) tr->n_valid = c + 1;
      }
    }
  }
}

/* Attitude at any t >= 0: grid point below t, then one partial Magnus step. */
static nav_quat attitude_at(param_model *tr, double t) {
  const double x = t / tr->h_s;
  int64_t j = (int64_t)floor(x);
  /* Sample times k*dt land on the grid up to rounding: snap to the grid point instead of taking
   * a full step minus a tiny remainder. */
  if (x - (double)j > 1.0 - 1e-9) j += 1;
  if (j < 0) j = 0;
  advance_cache(tr, j);
  const double rem = t - grid_time(tr, j);
  if (rem == 0.0) return tr->cache_q;
  return magnus_step(&tr->p, tr->cache_q, grid_time(tr, j), rem);
}

static nav_status parametric_prepare(param_model *tr) {
  const double n = ceil(tr->duration_s / tr->h_s) + 2.0 * (double)CHECKPOINT_STRIDE;
  if (!(n < 4.0e12)) return NAV_ERR_OUT_OF_RANGE;
  tr->n_checkpoints = (int64_t)n / CHECKPOINT_STRIDE + 1;
  tr->checkpoints = calloc((size_t)tr->n_checkpoints, sizeof *tr->checkpoints);
  if (!tr->checkpoints) return NAV_ERR_NO_MEMORY;
  tr->checkpoints[0] = tr->q0_b_l;
  tr->n_valid = 1;
  tr->cache_j = 0;
  tr->cache_q = tr->q0_b_l;
  return NAV_OK;
}

static void param_destroy(void *self) {
  param_model *tr = self;
  if (!tr) return;
  free(tr->checkpoints);
  free(tr);
}

static nav_status param_eval(void *self, double t_s, nav_local_kin *out);
static bool param_rate_integral(void *self, double t0_s, double t1_s, nav_vec3 *out);

nav_status nav_traj_parametric_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                      size_t msg_size) {
  if (scene->trajectory.parametric.magnus_substeps < 1) {
    if (msg) snprintf(msg, msg_size, "trajectory.parametric.magnus_substeps must be >= 1");
    return NAV_ERR_INVALID_ARG;
  }
  param_model *tr = calloc(1, sizeof *tr);
  if (!tr) return NAV_ERR_NO_MEMORY;
  tr->duration_s = scene->trajectory.duration_s;
  tr->p = scene->trajectory.parametric;
  tr->q0_b_l = nav_euler_to_quat(scene->trajectory.initial_attitude);
  tr->h_s = dt_s / (double)tr->p.magnus_substeps;
  const nav_status st = parametric_prepare(tr);
  if (st != NAV_OK) {
    param_destroy(tr);
    if (msg) snprintf(msg, msg_size, "the trajectory is too long for the Magnus sub-grid");
    return st;
  }
  memset(out, 0, sizeof *out);
  out->name = "parametric";
  out->duration_s = tr->duration_s;
  out->self = tr;
  out->eval_local = param_eval;
  out->rate_integral = param_rate_integral;
  out->destroy = param_destroy;
  return NAV_OK;
}

/* Local kinematics: on flat Earth l = n, so omega_lb_b of E3.2 is omega_nb_b. Defined for
 * t >= -h_s (the attitude is integrated forward from t = 0). */
static nav_status param_eval(void *self, double t_s, nav_local_kin *out) {
  param_model *traj = self;
  if (!(t_s >= -traj->h_s)) return NAV_ERR_OUT_OF_RANGE;
  const nav_traj_parametric *p = &traj->p;
  nav_local_kin s;
  for (int i = 0; i < 3; ++i) {
    /* E3.1 and its analytic derivatives. */
    const double B = nav_vec3_get(p->b_m, i), w = NAV_TWO_PI * nav_vec3_get(p->c_hz, i);
    const double ph = w * t_s + nav_vec3_get(p->d_rad, i);
    const double A = nav_vec3_get(p->a_mps2, i);
    nav_vec3_set(&s.r_ned_m, i,
                 nav_vec3_get(p->r0_m, i) + nav_vec3_get(p->v0_mps, i) * t_s + A * t_s * t_s + B * sin(ph));
    nav_vec3_set(&s.v_ned_mps, i, nav_vec3_get(p->v0_mps, i) + 2.0 * A * t_s + w * B * cos(ph));
    nav_vec3_set(&s.a_ned_mps2, i, 2.0 * A - w * w * B * sin(ph));
  }
  s.w_nb_b_rps = param_rate(p, t_s);
  s.dw_nb_b_rps2 = nav_vec3_make(rate_dot_1(p->wb_rps.x, p->wc_hz.x, p->wd_rad.x, t_s),
                                 rate_dot_1(p->wb_rps.y, p->wc_hz.y, p->wd_rad.y, t_s),
                                 rate_dot_1(p->wb_rps.z, p->wc_hz.z, p->wd_rad.z, t_s));
  s.q_b_n = attitude_at(traj, t_s);
  *out = s;
  return NAV_OK;
}

static bool param_rate_integral(void *self, double t0_s, double t1_s, nav_vec3 *out) {
  const nav_traj_parametric *p = &((const param_model *)self)->p;
  nav_vec3 r;
  for (int i = 0; i < 3; ++i) {
    /* E3.6: integral of a + b sin(2 pi c t + d); c = 0 degenerates to (a + b sin d) dt. */
    const double a = nav_vec3_get(p->wa_rps, i), b = nav_vec3_get(p->wb_rps, i);
    const double c = nav_vec3_get(p->wc_hz, i), d = nav_vec3_get(p->wd_rad, i);
    double v;
    if (c == 0.0) {
      v = (a + b * sin(d)) * (t1_s - t0_s);
    } else {
      /* cos(x1) - cos(x0) = -2 sin((x1 + x0)/2) sin((x1 - x0)/2): no cancellation for short
       * intervals, where the plain difference loses log10(1/(w dt)) digits. */
      const double w = NAV_TWO_PI * c;
      const double half = 0.5 * w * (t1_s - t0_s);
      v = a * (t1_s - t0_s) + (2.0 * b / w) * sin(0.5 * w * (t1_s + t0_s) + d) * sin(half);
    }
    nav_vec3_set(&r, i, v);
  }
  *out = r;
  return true;
}
