/*
 * The paper's parametric trajectory (Soloviev, Sablin, Lyalinsky, formula (3)), with the
 * corrections of numerics.md section 3.1:
 *   R(t) = R0 + V0 t + A t^2 + B sin(2 pi C t + D)            (E3.1, element-wise, l frame)
 *   omega_lb_b(t) = a + b sin(2 pi c t + d)                     (E3.2, body axes)
 * Attitude (Option B): C_dot = C [omega x] integrated by the 4th-order Magnus step (E3.5) on a
 * sub-grid h_s = dt / substeps aligned with the IMU samples. The paper's own first-order
 * recursion C_i = C_{i-1} exp(Omega(t_i) dt) is O(dt) and is NOT used as truth.
 *
 * Evaluation cost (the ideal IMU evaluates 6 quadrature nodes per sample, each needing its own
 * partial Magnus step): every sinusoid is written as sin(phase(t_K) + w o) = S cos(w o) +
 * C sin(w o), with S, C the phase at the sample time t_K = K dt (phase_at: a rotation per sample,
 * re-anchored by a direct sin/cos every PHASE_BLOCK samples) and cos(w o), sin(w o) constants of
 * the sub-grid and of the quadrature rule; exp of the Magnus vector is a Taylor series (no
 * trigonometry, no sqrt) and the chained grid steps are renormalized by a Newton step when
 * needed (renormalize). All of these change only the rounding. The grid attitudes stay a pure
 * function of the grid index: the IMU and nav_traj_eval share the same grid steps (grid_exp,
 * cache_apply).
 */
#include <stdlib.h>
#include <string.h>

#include <stdio.h>

#include "traj/traj_kin_internal.h"
#include "nav_clones.h"

/* One checkpoint of the integrated attitude every CHECKPOINT_STRIDE grid steps, so evaluation
 * at an earlier time re-integrates at most that many steps. */
#define CHECKPOINT_STRIDE 4096

/* The Magnus step is the inner loop of the ideal IMU: GCC and Clang are told to inline it (the
 * vectors stay in registers instead of going through the stack). */
#if defined(__GNUC__)
#define NAV_PARAM_INLINE static inline __attribute__((always_inline))
#else
#define NAV_PARAM_INLINE static inline
#endif

/* Sub-steps per sample whose exps the node evaluation batches (more are stepped one by one). */
#define BATCH_SUBSTEPS 64

/* Per-node constants of a quadrature rule on the sample interval [t0, t0 + dt] (node_table). */
typedef struct node_const {
  int m;                /* sub-grid step below the node: grid index (k - 1) S + m */
  double rem;           /* node offset from that grid point [s]; 0 on the grid */
  double rate[3][2];    /* cos, sin of w_i o (rate phase advance from t0 to the node, o = offset) */
  double pos[3][2];     /* cos, sin of W_i o (position phase advance) */
  double part[2][3][2]; /* cos, sin of w_i o at the two Magnus nodes of the partial step */
} node_const;

/* sin and cos of three phases at the sample time t_k = k dt; k = -1: empty. */
typedef struct phase_slot {
  int64_t k;
  double s[3], c[3];
} phase_slot;

typedef struct param_model {
  double duration_s;
  nav_traj_parametric p;
  nav_quat q0_b_l;
  double dt_s;           /* IMU interval (sample grid K dt) */
  int substeps;          /* S: sub-grid steps per sample */
  double h_s;            /* Magnus sub-grid step dt / S */
  nav_quat *checkpoints; /* q_b_l at grid index i * CHECKPOINT_STRIDE, i < n_valid */
  int64_t n_checkpoints;
  int64_t n_valid;
  int64_t cache_j;     /* grid index of the cached attitude */
  int64_t cache_k, cache_m; /* cache_j = cache_k S + cache_m, 0 <= cache_m < S */
  nav_quat cache_q;
  /* Grid steps: step j = K S + m has its two Magnus nodes at t_K + (m + 1/2 -/+ sqrt(3)/6) h_s,
   * t_K = K dt; step_cs[((m * 2 + node) * 3 + axis) * 2 + {0, 1}] = cos, sin of w_axis times that
   * offset. With the rate phases at t_K (anchor) this gives the rates without trigonometry. */
  double *step_cs;
  double wa[3], wb[3]; /* a and b of E3.2 */
  /* E3.1 per axis: R0, V0, 2A, A, B, W = 2 pi C, W B and W^2 B. */
  double pr0[3], pv0[3], pa2[3], pa[3], pb[3], pwb[3], pwwb[3];
  /* Phases at the sample times t_K = K dt (phase_at): of the rates, sin and cos of
   * 2 pi c_i t_K + d_i (the last two K used), and of the position, 2 pi C_i t_K + D_i. */
  phase_slot rate_ph[2], pos_ph;
  double rate_step[3][2], pos_step[3][2]; /* cos, sin of the phase advance over dt */
  double half_cs[3][2];                   /* cos, sin of the rate phase advance over dt / 2 */
  /* Node constants of the last quadrature rule (nav_traj_parametric_nodes). */
  int nc_n;
  double nc_x[NAV_KIN_MAX_NODES];
  node_const nc[NAV_KIN_MAX_NODES];
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

/*
 * exp of a rotation vector as a quaternion, [cos(a/2), sin(a/2)/a sigma], a = |sigma|. Below
 * a = 0.2 rad (every Magnus step of a sub-grid, except for spin rates above 0.2 / h_s) by the
 * Taylor series of cos x and sin(x)/x in x^2 = a^2/4, so that no sqrt and no trigonometry are
 * needed: through x^4 while x^2 < 1e-5 (first omitted terms x^6/720, x^6/5040 < 1.4e-18),
 * through x^8 while x^2 < 1e-3 (x^10/10! < 2.8e-22), else through x^10 (x^12/12! < 2.1e-21 at
 * the bound). All far below rounding. Above 0.2 rad, the closed form.
 */
NAV_PARAM_INLINE void quat_exp_coef(double a2, double *w_out, double *s_out) {
  double w, s;
  const double x2 = 0.25 * a2;
  if (x2 < 1e-5) {
    w = 1.0 - x2 * (1.0 / 2.0) * (1.0 - x2 * (1.0 / 12.0));
    s = 0.5 * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0)));
  } else if (x2 < 1e-3) {
    w = 1.0 -
        x2 * (1.0 / 2.0) * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0))));
    s = 0.5 * (1.0 - x2 * (1.0 / 6.0) *
                         (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0) * (1.0 - x2 * (1.0 / 72.0)))));
  } else if (a2 < 0.04) {
    w = 1.0 -
        x2 * (1.0 / 2.0) *
            (1.0 - x2 * (1.0 / 12.0) *
                       (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0) * (1.0 - x2 * (1.0 / 90.0)))));
    s = 0.5 * (1.0 - x2 * (1.0 / 6.0) *
                         (1.0 - x2 * (1.0 / 20.0) *
                                    (1.0 - x2 * (1.0 / 42.0) *
                                               (1.0 - x2 * (1.0 / 72.0) * (1.0 - x2 * (1.0 / 110.0))))));
  } else {
    const double a = sqrt(a2);
    w = cos(0.5 * a);
    s = sin(0.5 * a) / a;
  }
  *w_out = w;
  *s_out = s;
}

/*
 * Renormalization of the chained grid attitude, whose |q|^2 = n stays within a few roundings of
 * 1 (a product of unit quaternions): left alone while |n - 1| <= 1e-15, else scaled by one Newton
 * step for 1/sqrt(n) from 1, (3 - n)/2 (exact to O((n - 1)^2); no sqrt, no division). The dead
 * band matters: rescaling at every step by a factor within an ulp or two of 1 rounds the
 * components with a bias that depends on their magnitudes, i.e. turns the attitude; on the
 * paper's trajectory that drift reached 3e-13 rad after 200 s, against 2e-14 rad of unbiased
 * rounding with the band (the rounding of the original exact normalization; checked against a
 * long-double integration of the same Magnus grid). A |q|^2 off by 1e-15 scales f_b by as little.
 */
NAV_PARAM_INLINE nav_quat renormalize(nav_quat q) {
  const double n = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
  if (fabs(n - 1.0) <= 1e-15) return q;
  const double s = 1.5 - 0.5 * n;
  const nav_quat r = {q.w * s, q.x * s, q.y * s, q.z * s};
  return r;
}

/* exp([sigma x]) of the E3.5 step from the two-node rates a, b over h (C <- C exp([sigma x])),
 * sigma = h/2 (a + b) + (sqrt(3)/12) h^2 (a x b); written out in scalars (the inner loop). */
NAV_PARAM_INLINE nav_quat magnus_e(const double a[3], const double b[3], double h) {
  static const double k_cross = 0.14433756729740644113; /* sqrt(3)/12 */
  const double h1 = 0.5 * h, h2 = k_cross * h * h;
  const double sx = (a[0] + b[0]) * h1 + (a[1] * b[2] - a[2] * b[1]) * h2;
  const double sy = (a[1] + b[1]) * h1 + (a[2] * b[0] - a[0] * b[2]) * h2;
  const double sz = (a[2] + b[2]) * h1 + (a[0] * b[1] - a[1] * b[0]) * h2;
  double ew, es;
  quat_exp_coef(sx * sx + sy * sy + sz * sz, &ew, &es);
  const nav_quat e = {ew, es * sx, es * sy, es * sz};
  return e;
}

/* C_b_n of a unit quaternion (nav_quat_to_dcm, inline). */
static inline void quat_dcm(nav_quat q, nav_mat3 *c) {
  const double ww = q.w * q.w, xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
  const double xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
  const double wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
  c->m[0][0] = ww + xx - yy - zz;
  c->m[0][1] = 2.0 * (xy - wz);
  c->m[0][2] = 2.0 * (xz + wy);
  c->m[1][0] = 2.0 * (xy + wz);
  c->m[1][1] = ww - xx + yy - zz;
  c->m[1][2] = 2.0 * (yz - wx);
  c->m[2][0] = 2.0 * (xz - wy);
  c->m[2][1] = 2.0 * (yz + wx);
  c->m[2][2] = ww - xx - yy + zz;
}

/* Phases are re-evaluated directly every PHASE_BLOCK samples. */
#define PHASE_BLOCK 64

/*
 * sin and cos of the phases f_i t_K + g_i (f = 2 pi x frequency) at t_K = K dt into out. A pure
 * function of K: sin/cos directly when K is a multiple of PHASE_BLOCK, else the phases of K - 1
 * advanced by f_i dt (angle addition with step = {cos, sin} of f_i dt). Starting from @p from
 * (an earlier K of the same block) a forward walk costs one rotation per sample; otherwise the
 * walk starts at the block. The rotations add at most PHASE_BLOCK roundings (~1e-14), less than
 * the rounding of the argument f t_K + g itself once t_K is more than a few seconds.
 */
NAV_CLONE_INLINE void phase_at(int64_t K, double dt, nav_vec3 f, nav_vec3 g, const double (*step)[2],
                               const phase_slot *from, phase_slot *out) {
  phase_slot r;
  if (from && from->k >= 0 && from->k <= K && K / PHASE_BLOCK == from->k / PHASE_BLOCK) {
    r = *from;
  } else {
    r.k = K - K % PHASE_BLOCK;
    const double t = (double)r.k * dt;
    for (int i = 0; i < 3; ++i) {
      const double ph = nav_vec3_get(f, i) * t + nav_vec3_get(g, i);
      r.s[i] = sin(ph);
      r.c[i] = cos(ph);
    }
  }
  for (; r.k < K; ++r.k)
    for (int i = 0; i < 3; ++i) {
      const double sn = r.s[i] * step[i][0] + r.c[i] * step[i][1];
      r.c[i] = r.c[i] * step[i][0] - r.s[i] * step[i][1];
      r.s[i] = sn;
    }
  *out = r;
}

static nav_vec3 two_pi_times(nav_vec3 hz) {
  return nav_vec3_make(NAV_TWO_PI * hz.x, NAV_TWO_PI * hz.y, NAV_TWO_PI * hz.z);
}

/* Rate phases at the sample time t_K (the anchor of the grid steps of sample K). The last two
 * are kept: the grid steps of sample K - 1 and the nodes of sample K alternate. */
static const phase_slot *rate_phase(param_model *tr, int64_t K) {
  phase_slot *a = &tr->rate_ph[0], *b = &tr->rate_ph[1];
  if (a->k == K) return a;
  if (b->k == K) return b;
  /* Start from the later slot at or before K; overwrite the other one. */
  const bool a_ok = a->k >= 0 && a->k < K, b_ok = b->k >= 0 && b->k < K;
  phase_slot *from = a_ok && (!b_ok || a->k > b->k) ? a : (b_ok ? b : NULL);
  phase_slot *out = from == a ? b : a;
  phase_at(K, tr->dt_s, two_pi_times(tr->p.wc_hz), tr->p.wd_rad, (const double(*)[2])tr->rate_step, from,
           out);
  return out;
}

/* omega = a + b sin(phase(t_K) + w o) from the phases ph of t_K and cs = {cos w o, sin w o}. */
NAV_PARAM_INLINE void rate_at(const param_model *tr, const phase_slot *ph, const double cs[3][2],
                              double r[3]) {
  r[0] = tr->wa[0] + tr->wb[0] * (ph->s[0] * cs[0][0] + ph->c[0] * cs[0][1]);
  r[1] = tr->wa[1] + tr->wb[1] * (ph->s[1] * cs[1][0] + ph->c[1] * cs[1][1]);
  r[2] = tr->wa[2] + tr->wb[2] * (ph->s[2] * cs[2][0] + ph->c[2] * cs[2][1]);
}

/* exp([sigma x]) of grid step j -> j + 1 (numerics.md E3.5), j = K S + m, ph: the rate phases
 * of sample K. Every grid step, whoever asks for it, is computed here and applied by
 * cache_apply, so the cached attitudes are a pure function of j. */
NAV_PARAM_INLINE nav_quat grid_exp(const param_model *tr, const phase_slot *ph, int64_t m) {
  const double(*cs)[3][2] = (const double(*)[3][2])(tr->step_cs + m * 12);
  double wa[3], wb[3];
  rate_at(tr, ph, cs[0], wa);
  rate_at(tr, ph, cs[1], wb);
  return magnus_e(wa, wb, tr->h_s);
}

/* One grid step of the cache with e = grid_exp of its step (the renormalized product),
 * recording checkpoints. */
NAV_PARAM_INLINE void cache_apply(param_model *tr, nav_quat e) {
  tr->cache_q = renormalize(nav_quat_mul(tr->cache_q, e));
  tr->cache_j++;
  if (++tr->cache_m == tr->substeps) {
    tr->cache_m = 0;
    tr->cache_k++;
  }
  if (tr->cache_j % CHECKPOINT_STRIDE == 0) {
    const int64_t c = tr->cache_j / CHECKPOINT_STRIDE;
    if (c < tr->n_checkpoints) {
      tr->checkpoints[c] = tr->cache_q;
      if (c >= tr->n_valid) tr->n_valid = c + 1;
    }
  }
}

NAV_CLONE_INLINE void cache_step(param_model *tr, const phase_slot *ph) {
  cache_apply(tr, grid_exp(tr, ph, tr->cache_m));
}

/* Advance the cached attitude to grid index j (j >= 0). Checkpoints are recorded as the cache
 * walks forward, so going back costs at most CHECKPOINT_STRIDE steps. */
static void advance_cache(param_model *tr, int64_t j) {
  if (j == tr->cache_j) return;
  if (j < tr->cache_j) {
    int64_t c = j / CHECKPOINT_STRIDE;
    if (c >= tr->n_valid) c = tr->n_valid - 1;
    tr->cache_j = c * CHECKPOINT_STRIDE;
    tr->cache_q = tr->checkpoints[c];
    tr->cache_k = tr->cache_j / tr->substeps;
    tr->cache_m = tr->cache_j - tr->cache_k * tr->substeps;
  }
  while (tr->cache_j < j) {
    const phase_slot *ph = rate_phase(tr, tr->cache_k);
    const int64_t k = tr->cache_k;
    while (tr->cache_j < j && tr->cache_k == k)
      cache_step(tr, ph);
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
  tr->cache_k = tr->cache_m = 0;
  tr->cache_q = tr->q0_b_l;
  tr->step_cs = malloc((size_t)tr->substeps * 12 * sizeof *tr->step_cs);
  if (!tr->step_cs) return NAV_ERR_NO_MEMORY;
  static const double k_off = 0.28867513459481288225; /* sqrt(3)/6 */
  for (int m = 0; m < tr->substeps; ++m)
    for (int node = 0; node < 2; ++node) {
      const double o = ((double)m + (node == 0 ? 0.5 - k_off : 0.5 + k_off)) * tr->h_s;
      for (int i = 0; i < 3; ++i) {
        const double ph = NAV_TWO_PI * nav_vec3_get(tr->p.wc_hz, i) * o;
        tr->step_cs[((m * 2 + node) * 3 + i) * 2] = cos(ph);
        tr->step_cs[((m * 2 + node) * 3 + i) * 2 + 1] = sin(ph);
      }
    }
  for (int i = 0; i < 3; ++i) {
    const double W = NAV_TWO_PI * nav_vec3_get(tr->p.c_hz, i), A = nav_vec3_get(tr->p.a_mps2, i);
    tr->pr0[i] = nav_vec3_get(tr->p.r0_m, i);
    tr->pv0[i] = nav_vec3_get(tr->p.v0_mps, i);
    tr->pa[i] = A;
    tr->pa2[i] = 2.0 * A;
    tr->pb[i] = nav_vec3_get(tr->p.b_m, i);
    tr->pwb[i] = W * tr->pb[i];
    tr->pwwb[i] = W * W * tr->pb[i];
    tr->wa[i] = nav_vec3_get(tr->p.wa_rps, i);
    tr->wb[i] = nav_vec3_get(tr->p.wb_rps, i);
    const double fr = NAV_TWO_PI * nav_vec3_get(tr->p.wc_hz, i) * tr->dt_s;
    const double fp = NAV_TWO_PI * nav_vec3_get(tr->p.c_hz, i) * tr->dt_s;
    tr->rate_step[i][0] = cos(fr);
    tr->rate_step[i][1] = sin(fr);
    tr->pos_step[i][0] = cos(fp);
    tr->pos_step[i][1] = sin(fp);
    tr->half_cs[i][0] = cos(0.5 * fr);
    tr->half_cs[i][1] = sin(0.5 * fr);
  }
  tr->rate_ph[0].k = tr->rate_ph[1].k = tr->pos_ph.k = -1;
  tr->nc_n = 0;
  return NAV_OK;
}

static void param_destroy(void *self) {
  param_model *tr = self;
  if (!tr) return;
  free(tr->checkpoints);
  free(tr->step_cs);
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
  tr->dt_s = dt_s;
  tr->substeps = tr->p.magnus_substeps;
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
  param_model *tr = self;
  const nav_traj_parametric *p = &tr->p;
  nav_vec3 r;
  const double kf = nearbyint(t0_s / tr->dt_s);
  if (kf >= 0.0 && kf < 9.0e15 && kf * tr->dt_s == t0_s && (kf + 1.0) * tr->dt_s == t1_s) {
    /* A sample interval: as below, with sin(w (t0 + t1)/2 + d) = sin(phase(t0) + w dt/2) from
     * the anchor phases (constants half_cs) and sin(w dt/2) = half_cs[i][1]. */
    const phase_slot *ph = rate_phase(tr, (int64_t)kf);
    for (int i = 0; i < 3; ++i) {
      const double a = tr->wa[i], b = tr->wb[i], c = nav_vec3_get(p->wc_hz, i),
                   d = nav_vec3_get(p->wd_rad, i);
      double v;
      if (c == 0.0) {
        v = (a + b * sin(d)) * (t1_s - t0_s);
      } else {
        const double w = NAV_TWO_PI * c;
        const double smid = ph->s[i] * tr->half_cs[i][0] + ph->c[i] * tr->half_cs[i][1];
        v = a * (t1_s - t0_s) + (2.0 * b / w) * smid * tr->half_cs[i][1];
      }
      nav_vec3_set(&r, i, v);
    }
    *out = r;
    return true;
  }
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

/* Node constants for the rule x on [t0, t0 + dt]: node offset o = dt (1 + x) / 2. */
static void node_table(param_model *tr, int n, const double *x) {
  static const double k_off = 0.28867513459481288225; /* sqrt(3)/6 */
  if (tr->nc_n == n && memcmp(tr->nc_x, x, (size_t)n * sizeof *x) == 0) return;
  const nav_traj_parametric *p = &tr->p;
  for (int i = 0; i < n; ++i) {
    node_const *c = &tr->nc[i];
    const double o = 0.5 * tr->dt_s * (1.0 + x[i]);
    /* The grid point below, snapped as in attitude_at. */
    const double g = o / tr->h_s;
    double m = floor(g);
    if (g - m > 1.0 - 1e-9) m += 1.0;
    if (m < 0.0) m = 0.0;
    if (m > (double)(tr->substeps - 1)) m = (double)(tr->substeps - 1);
    c->m = (int)m;
    c->rem = o - m * tr->h_s;
    if (fabs(c->rem) < 1e-9 * tr->h_s) c->rem = 0.0;
    const double oa = m * tr->h_s + (0.5 - k_off) * c->rem, ob = m * tr->h_s + (0.5 + k_off) * c->rem;
    for (int a = 0; a < 3; ++a) {
      const double w = NAV_TWO_PI * nav_vec3_get(p->wc_hz, a), W = NAV_TWO_PI * nav_vec3_get(p->c_hz, a);
      c->rate[a][0] = cos(w * o);
      c->rate[a][1] = sin(w * o);
      c->pos[a][0] = cos(W * o);
      c->pos[a][1] = sin(W * o);
      c->part[0][a][0] = cos(w * oa);
      c->part[0][a][1] = sin(w * oa);
      c->part[1][a][0] = cos(w * ob);
      c->part[1][a][1] = sin(w * ob);
    }
  }
  memcpy(tr->nc_x, x, (size_t)n * sizeof *x);
  tr->nc_n = n;
}

/*
 * Ideal-IMU nodes on the sample interval [t_(k-1), t_k]: param_eval at each node, with every
 * sinusoid written as sin(phase(t_(k-1)) + w o) = S cos(w o) + C sin(w o) from six sincos per
 * interval (the rate and position phases at t_(k-1)) and per-rule constants, and the attitude as
 * in attitude_at: the cached grid attitude (grid steps are shared with nav_traj_eval) and one
 * partial Magnus step from the grid point below each node. Off the sample grid, param_eval.
 */
NAV_HOT_CLONES nav_status nav_traj_parametric_nodes(void *self, nav_kin_nodes *io) {
  param_model *tr = self;
  const nav_traj_parametric *p = &tr->p;
  if (io->k < 1) {
    for (int i = 0; i < io->n; ++i) {
      nav_local_kin k;
      const nav_status st = param_eval(self, io->t_s[i], &k);
      if (st != NAV_OK) return st;
      io->C_b_n[i] = nav_quat_to_dcm(k.q_b_n);
      io->w_nb_b_rps[i] = k.w_nb_b_rps;
      io->v_ned_mps[i] = k.v_ned_mps;
      io->a_ned_mps2[i] = k.a_ned_mps2;
      io->r_ned_m[i] = k.r_ned_m;
    }
    io->has_pos = true;
    return NAV_OK;
  }
  node_table(tr, io->n, io->x);
  const int64_t K = io->k - 1;
  if (K != tr->pos_ph.k)
    phase_at(K, tr->dt_s, two_pi_times(p->c_hz), p->d_rad, (const double(*)[2])tr->pos_step, &tr->pos_ph,
             &tr->pos_ph);
  const double *ps = tr->pos_ph.s, *pc = tr->pos_ph.c;
  /* The grid walk up to the first node may cross from sample K - 1 (or restart); between the
   * nodes it stays in sample K, whose rate phases ph are fixed. */
  const int64_t j0 = K * tr->substeps;
  advance_cache(tr, j0 + tr->nc[0].m);
  const phase_slot *ph = rate_phase(tr, K);
  /* Everything but the grid chain is independent of it and is computed first: the node kinematics,
   * the exps of the grid steps up to the last node and of the nodes' partial steps, so that only
   * the quaternion products remain in the sequential part. */
  nav_quat e_node[NAV_KIN_MAX_NODES];
  for (int i = 0; i < io->n; ++i) {
    const node_const *c = &tr->nc[i];
    const double t = io->t_s[i];
    /* E3.1 and its derivatives. */
    double r[3], v[3], acc[3];
    for (int a = 0; a < 3; ++a) {
      const double sn = ps[a] * c->pos[a][0] + pc[a] * c->pos[a][1];
      const double cs = pc[a] * c->pos[a][0] - ps[a] * c->pos[a][1];
      r[a] = io->need_pos ? tr->pr0[a] + tr->pv0[a] * t + tr->pa[a] * t * t + tr->pb[a] * sn : 0.0;
      v[a] = tr->pv0[a] + tr->pa2[a] * t + tr->pwb[a] * cs;
      acc[a] = tr->pa2[a] - tr->pwwb[a] * sn;
    }
    io->r_ned_m[i] = nav_vec3_make(r[0], r[1], r[2]);
    io->v_ned_mps[i] = nav_vec3_make(v[0], v[1], v[2]);
    io->a_ned_mps2[i] = nav_vec3_make(acc[0], acc[1], acc[2]);
    double w[3];
    rate_at(tr, ph, c->rate, w);
    io->w_nb_b_rps[i] = nav_vec3_make(w[0], w[1], w[2]);
    if (c->rem != 0.0) {
      double wa[3], wb[3];
      rate_at(tr, ph, c->part[0], wa);
      rate_at(tr, ph, c->part[1], wb);
      e_node[i] = magnus_e(wa, wb, c->rem);
    }
  }
  nav_quat e_step[BATCH_SUBSTEPS];
  const int64_t m_end = tr->nc[io->n - 1].m;
  const bool batch = m_end <= BATCH_SUBSTEPS;
  if (batch)
    for (int64_t m = tr->cache_m; m < m_end; ++m)
      e_step[m] = grid_exp(tr, ph, m);
  for (int i = 0; i < io->n; ++i) {
    const node_const *c = &tr->nc[i];
    /* Attitude: grid point, then the partial step (E3.5) over rem. */
    while (tr->cache_j < j0 + c->m) {
      if (batch)
        cache_apply(tr, e_step[tr->cache_m]);
      else
        cache_step(tr, ph);
    }
    /* Not renormalized (unlike the chained grid steps): |q| differs from 1 by a few roundings,
     * which scale f_b by as little. */
    quat_dcm(c->rem != 0.0 ? nav_quat_mul(tr->cache_q, e_node[i]) : tr->cache_q, &io->C_b_n[i]);
  }
  io->has_pos = io->need_pos;
  return NAV_OK;
}
