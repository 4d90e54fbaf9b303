/* Per-epoch navigation errors and their statistics. */
#include <stdlib.h>

#include "navcore/nav_errors.h"

nav_errors_ref nav_errors_ref_compute(const nav_frame *fr, const nav_traj_state *truth) {
  nav_errors_ref r;
  r.view = nav_frame_view(fr, truth->r_fb_f_m, truth->v_fb_f_mps, truth->q_b_f);
  r.euler = nav_quat_to_euler(r.view.q_b_n, NULL);
  return r;
}

nav_epoch_errors nav_errors_compute_ref(const nav_frame *fr, const nav_traj_state *truth, const nav_errors_ref *ref,
                                        const nav_ins_state *est) {
  nav_epoch_errors e;
  const nav_local_view *vt = &ref->view;
  const nav_local_view ve = nav_frame_view(fr, est->r_fb_f_m, est->v_fb_f_mps, est->q_b_f);
  e.t_s = truth->t_s;
  /* Resolve the F-frame differences in n at the true position. */
  e.pos_err_n_m = nav_mat3_mul_vec(vt->C_f_n, nav_vec3_sub(est->r_fb_f_m, truth->r_fb_f_m));
  e.pos_err_h_m = hypot(e.pos_err_n_m.x, e.pos_err_n_m.y);
  e.pos_err_v_m = fabs(e.pos_err_n_m.z);
  e.vel_err_n_mps = nav_mat3_mul_vec(vt->C_f_n, nav_vec3_sub(est->v_fb_f_mps, truth->v_fb_f_mps));
  e.vel_err_mps = nav_vec3_norm(e.vel_err_n_mps);
  e.att_err_rad = nav_quat_angle_between(truth->q_b_f, est->q_b_f);
  const nav_euler et = ref->euler;
  const nav_euler ee = nav_quat_to_euler(ve.q_b_n, NULL);
  e.euler_err.roll_rad = nav_wrap_pi(ee.roll_rad - et.roll_rad);
  e.euler_err.pitch_rad = nav_wrap_pi(ee.pitch_rad - et.pitch_rad);
  e.euler_err.yaw_rad = nav_wrap_pi(ee.yaw_rad - et.yaw_rad);
  return e;
}

nav_epoch_errors nav_errors_compute(const nav_frame *fr, const nav_traj_state *truth, const nav_ins_state *est) {
  const nav_errors_ref ref = nav_errors_ref_compute(fr, truth);
  return nav_errors_compute_ref(fr, truth, &ref, est);
}

struct nav_stat_acc {
  size_t capacity, count;
  double sum_sq, comp; /* Kahan-compensated sum of squares */
  double max;
  double *values;
};

nav_status nav_stat_acc_create(size_t capacity, nav_stat_acc **out) {
  if (!out || capacity == 0 || capacity > ((size_t)1 << 40) / sizeof(double)) return NAV_ERR_INVALID_ARG;
  nav_stat_acc *a = calloc(1, sizeof *a);
  if (!a) return NAV_ERR_NO_MEMORY;
  a->values = malloc(capacity * sizeof *a->values);
  if (!a->values) {
    free(a);
    return NAV_ERR_NO_MEMORY;
  }
  a->capacity = capacity;
  *out = a;
  return NAV_OK;
}

void nav_stat_acc_destroy(nav_stat_acc *acc) {
  if (!acc) return;
  free(acc->values);
  free(acc);
}

size_t nav_stat_acc_count(const nav_stat_acc *acc) { return acc ? acc->count : 0; }

void nav_stat_acc_reset(nav_stat_acc *acc) {
  if (!acc) return;
  acc->count = 0;
  acc->sum_sq = 0.0;
  acc->comp = 0.0;
  acc->max = 0.0;
}

/* The body of nav_stat_acc_add(), inlined into nav_stat_acc_add_each() (an exported function of a
 * shared library is not inlined into its callers by the compiler). */
static inline nav_status acc_add(nav_stat_acc *acc, double value) {
  if (!acc) return NAV_ERR_INVALID_ARG;
  if (!isfinite(value)) return NAV_ERR_NUMERIC;
  if (acc->count >= acc->capacity) return NAV_ERR_OUT_OF_RANGE;
  acc->values[acc->count++] = value;
  const double y = value * value - acc->comp;
  const double t = acc->sum_sq + y;
  acc->comp = (t - acc->sum_sq) - y;
  acc->sum_sq = t;
  const double a = fabs(value);
  if (a > acc->max) acc->max = a;
  return NAV_OK;
}

nav_status nav_stat_acc_add(nav_stat_acc *acc, double value) { return acc_add(acc, value); }

nav_status nav_stat_acc_add_each(nav_stat_acc *const acc[], const double values[], int n) {
  if (!acc || (!values && n > 0)) return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < n; ++i) {
    const nav_status st = acc_add(acc[i], values[i]);
    if (st != NAV_OK) return st;
  }
  return NAV_OK;
}

/* k-th smallest (0-based) by Wirth's selection (N. Wirth, Algorithms + Data Structures =
 * Programs, 1976, sec. 2.3.4). On return v is partitioned: v[i] <= v[k] for i < k and
 * v[i] >= v[k] for i > k. Deterministic. */
static double select_kth(double *v, size_t n, size_t k) {
  ptrdiff_t l = 0, m = (ptrdiff_t)n - 1;
  const ptrdiff_t kk = (ptrdiff_t)k;
  while (l < m) {
    const double x = v[kk];
    ptrdiff_t i = l, j = m;
    do {
      while (v[i] < x) ++i;
      while (x < v[j]) --j;
      if (i <= j) {
        const double t = v[i];
        v[i] = v[j];
        v[j] = t;
        ++i;
        --j;
      }
    } while (i <= j);
    if (j < kk) l = i;
    if (kk < i) m = j;
  }
  return v[kk];
}

nav_stat nav_stat_acc_result(nav_stat_acc *acc) {
  nav_stat s = {0.0, 0.0, 0.0};
  if (!acc || acc->count == 0) return s;
  const size_t n = acc->count;
  s.rms = sqrt(acc->sum_sq / (double)n);
  s.max = acc->max;
  /* Type 7: h = (n - 1) p, interpolate between floor(h) and floor(h) + 1. */
  const double h = (double)(n - 1) * 0.95;
  const size_t lo = (size_t)floor(h);
  const double x_lo = select_kth(acc->values, n, lo);
  double x_hi = x_lo;
  if (lo + 1 < n) {
    /* After selection every value above index lo is >= x_lo: the next order statistic is their
     * minimum. */
    x_hi = acc->values[lo + 1];
    for (size_t i = lo + 2; i < n; ++i)
      if (acc->values[i] < x_hi) x_hi = acc->values[i];
  }
  s.p95 = x_lo + (h - (double)lo) * (x_hi - x_lo);
  return s;
}
