/*
 * Shared kinematics of the waypoint and segment-script models: jets, septic-smoothstep rate
 * channels, rest-to-rest moves and position checkpoints. See traj_kin_internal.h.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_truth.h"
#include "traj/traj_kin_internal.h"
#include "nav_clones.h"

/* ================================================================ Euler rates */

void nav_kin_euler_rates(nav_jet roll, nav_jet pitch, nav_jet yaw, nav_vec3 *w_nb_b_rps,
                         nav_vec3 *dw_nb_b_rps2) {
  nav_kin_euler_rates_sc(roll, pitch, yaw, sin(roll.d[0]), cos(roll.d[0]), sin(pitch.d[0]), cos(pitch.d[0]),
                         w_nb_b_rps, dw_nb_b_rps2);
}

void nav_kin_euler_rates_sc(nav_jet roll, nav_jet pitch, nav_jet yaw, double sr, double cr, double sp,
                            double cp, nav_vec3 *w_nb_b_rps, nav_vec3 *dw_nb_b_rps2) {
  /* numerics.md E3.4 ([TW] ch. 3, [G] eq. 2.59 inverted), differentiated by the jets; the sine and
   * cosine jets are those of nav_jet_sin / nav_jet_cos from the given values. */
  const nav_jet dphi = nav_jet_deriv(roll), dth = nav_jet_deriv(pitch), dpsi = nav_jet_deriv(yaw);
  const nav_jet sth = nav_jet_chain(pitch, sp, cp, -sp, -cp), cth = nav_jet_chain(pitch, cp, -sp, -cp, sp);
  const nav_jet sph = nav_jet_chain(roll, sr, cr, -sr, -cr), cph = nav_jet_chain(roll, cr, -sr, -cr, sr);
  const nav_jet wx = nav_jet_sub(dphi, nav_jet_mul(dpsi, sth));
  const nav_jet wy = nav_jet_add(nav_jet_mul(dth, cph), nav_jet_mul(dpsi, nav_jet_mul(cth, sph)));
  const nav_jet wz = nav_jet_sub(nav_jet_mul(dpsi, nav_jet_mul(cth, cph)), nav_jet_mul(dth, sph));
  *w_nb_b_rps = nav_vec3_make(wx.d[0], wy.d[0], wz.d[0]);
  *dw_nb_b_rps2 = nav_vec3_make(wx.d[1], wy.d[1], wz.d[1]);
}

/* ================================================================ septic smoothstep */

/* S(u) = 35u^4 - 84u^5 + 70u^6 - 20u^7 and its derivatives; I = int_0^u S, J = int_0^u I (S, S'
 * and I in traj_kin_internal.h, inlined into the node evaluators). */
#define ss_S nav_kin_ss_S
#define ss_S1 nav_kin_ss_S1
#define ss_I nav_kin_ss_I
static double ss_S2(double u) {
  const double v = u * (1.0 - u);
  return 420.0 * v * v * (1.0 - 2.0 * u);
}
static double ss_S3(double u) {
  return 840.0 * u * (1.0 + u * (-6.0 + u * (10.0 - 5.0 * u)));
}
static double ss_J(double u) {
  const double u3 = u * u * u;
  return u3 * u3 * (7.0 / 6.0 + u * (-2.0 + u * (1.25 - (2.5 / 9.0) * u)));
}
#define SS_I1 0.5          /* I(1) */
#define SS_J1 (5.0 / 36.0) /* J(1) */

double nav_kin_ramp_time(double dr_abs, const nav_kin_lim *lim) {
  /* Peak |dr S'/T| <= d1 and peak |dr S''/T^2| <= d2. */
  const double t1 = NAV_KIN_S1_MAX * dr_abs / lim->d1_max;
  const double t2 = sqrt(NAV_KIN_S2_MAX * dr_abs / lim->d2_max);
  return t1 > t2 ? t1 : t2;
}

/* ================================================================ channels */

void nav_kin_channel_init(nav_kin_channel *c, double x_init, double r_init) {
  memset(c, 0, sizeof *c);
  c->x_init = x_init;
  c->r_init = r_init;
}

void nav_kin_channel_free(nav_kin_channel *c) {
  if (!c) return;
  free(c->steps);
  c->steps = NULL;
  c->n = c->cap = 0;
}

/* Value x, integral y and rate r at t, extrapolated from step k's start (t >= t0 of k, and t at
 * or after the end of step k), or from the channel start when k is -1. */
static void after_state(const nav_kin_channel *c, ptrdiff_t k, double t, double *x, double *y, double *r) {
  if (k < 0) {
    *x = c->x_init + c->r_init * t;
    *y = c->x_init * t + 0.5 * c->r_init * t * t;
    *r = c->r_init;
    return;
  }
  const nav_kin_step *s = &c->steps[k];
  const double d = t - s->t0_s, e = d - s->len_s;
  *x = s->x0 + s->r0 * d + s->dr * (d - 0.5 * s->len_s);
  *y = s->y0 + s->x0 * d + 0.5 * s->r0 * d * d +
       s->dr * (s->len_s * s->len_s * SS_J1 + 0.5 * s->len_s * e + 0.5 * e * e);
  *r = s->r0 + s->dr;
}

nav_status nav_kin_channel_add_step(nav_kin_channel *c, double t0_s, double len_s, double dr) {
  if (dr == 0.0) return NAV_OK;
  if (!(len_s > 0.0) || !isfinite(t0_s) || !isfinite(dr)) return NAV_ERR_INVALID_ARG;
  if (c->n > 0) {
    const nav_kin_step *p = &c->steps[c->n - 1];
    const double end = p->t0_s + p->len_s;
    if (t0_s < end) {
      if (end - t0_s > 1e-9) return NAV_ERR_INVALID_ARG;
      t0_s = end;
    }
  }
  if (c->n == c->cap) {
    const size_t cap = c->cap ? 2 * c->cap : 16;
    nav_kin_step *s = realloc(c->steps, cap * sizeof *s);
    if (!s) return NAV_ERR_NO_MEMORY;
    c->steps = s;
    c->cap = cap;
  }
  nav_kin_step st;
  st.t0_s = t0_s;
  st.len_s = len_s;
  st.dr = dr;
  after_state(c, (ptrdiff_t)c->n - 1, t0_s, &st.x0, &st.y0, &st.r0);
  c->steps[c->n++] = st;
  return NAV_OK;
}

ptrdiff_t nav_kin_find_step(const nav_kin_channel *c, double t) {
  if (c->n == 0 || t < c->steps[0].t0_s) return -1;
  size_t lo = 0, hi = c->n; /* steps[lo].t0 <= t < steps[hi].t0 */
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    if (c->steps[mid].t0_s <= t)
      lo = mid;
    else
      hi = mid;
  }
  return (ptrdiff_t)lo;
}

#define find_step nav_kin_find_step
#define find_step_hint nav_kin_find_step_hint
#define rate_state nav_kin_rate_state

void nav_kin_channel_eval_rate(const nav_kin_channel *c, double t_s, ptrdiff_t *hint, double *x, double *r,
                               double *r1) {
  rate_state(c, find_step_hint(c, t_s, hint), t_s, x, r, r1);
}

NAV_HOT_CLONES bool nav_kin_channel_eval_rate_n(const nav_kin_channel *c, const double *t_s, int n,
                                                ptrdiff_t *hint, double *x, double *r, double *r1) {
  if (!nav_kin_channel_eval_rate_n0(c, t_s, n, hint, x, r, r1)) return false;
  for (int i = 1; i < n; ++i) {
    x[i] = x[0];
    r[i] = r[0];
    r1[i] = r1[0];
  }
  return true;
}

NAV_HOT_CLONES bool nav_kin_channel_eval_rate_n0(const nav_kin_channel *c, const double *t_s, int n,
                                                 ptrdiff_t *hint, double *x, double *r, double *r1) {
  return nav_kin_channel_eval_rate_n0_inline(c, t_s, n, hint, x, r, r1);
}

/* Full state at t: x, y and rate jets (r, r', r'', r'''). */
static void channel_state_k(const nav_kin_channel *c, ptrdiff_t k, double t, double *x, double *y,
                            double r[4]) {
  r[1] = r[2] = r[3] = 0.0;
  if (k >= 0) {
    const nav_kin_step *s = &c->steps[k];
    const double d = t - s->t0_s;
    if (d < s->len_s) {
      const double T = s->len_s, u = d / T;
      *x = s->x0 + s->r0 * d + s->dr * T * ss_I(u);
      *y = s->y0 + s->x0 * d + 0.5 * s->r0 * d * d + s->dr * T * T * ss_J(u);
      r[0] = s->r0 + s->dr * ss_S(u);
      r[1] = s->dr * ss_S1(u) / T;
      r[2] = s->dr * ss_S2(u) / (T * T);
      r[3] = s->dr * ss_S3(u) / (T * T * T);
      return;
    }
  }
  after_state(c, k, t, x, y, &r[0]);
}

static void channel_state(const nav_kin_channel *c, double t, double *x, double *y, double r[4]) {
  channel_state_k(c, find_step(c, t), t, x, y, r);
}

double nav_kin_channel_eval_value(const nav_kin_channel *c, double t_s, ptrdiff_t *hint) {
  /* The x of channel_state_k and after_state, expression for expression. */
  const ptrdiff_t k = find_step_hint(c, t_s, hint);
  if (k < 0) return c->x_init + c->r_init * t_s;
  const nav_kin_step *s = &c->steps[k];
  const double d = t_s - s->t0_s;
  if (d < s->len_s) {
    const double T = s->len_s, u = d / T;
    return s->x0 + s->r0 * d + s->dr * T * ss_I(u);
  }
  return s->x0 + s->r0 * d + s->dr * (d - 0.5 * s->len_s);
}

nav_jet nav_kin_channel_eval_hint(const nav_kin_channel *c, double t_s, ptrdiff_t *hint) {
  double x, y, r[4];
  channel_state_k(c, find_step_hint(c, t_s, hint), t_s, &x, &y, r);
  return nav_jet_make(x, r[0], r[1], r[2]);
}

nav_jet nav_kin_channel_eval(const nav_kin_channel *c, double t_s) {
  double x, y, r[4];
  channel_state(c, t_s, &x, &y, r);
  return nav_jet_make(x, r[0], r[1], r[2]);
}

nav_jet nav_kin_channel_eval_integral(const nav_kin_channel *c, double t_s) {
  double x, y, r[4];
  channel_state(c, t_s, &x, &y, r);
  return nav_jet_make(y, x, r[0], r[1]);
}

double nav_kin_channel_final_rate(const nav_kin_channel *c) {
  return c->n ? c->steps[c->n - 1].r0 + c->steps[c->n - 1].dr : c->r_init;
}

double nav_kin_channel_end(const nav_kin_channel *c) {
  return c->n ? c->steps[c->n - 1].t0_s + c->steps[c->n - 1].len_s : 0.0;
}

/* ================================================================ moves */

nav_kin_move nav_kin_plan_move(double delta, const nav_kin_lim *lim) {
  nav_kin_move m = {delta, 0.0, 0.0, 0.0};
  const double a = fabs(delta);
  if (!(a > 0.0)) return m;
  const double t_full = nav_kin_ramp_time(lim->r_max, lim);
  if (a >= lim->r_max * t_full) {
    /* Trapezoid: reach the rate limit, cruise. */
    m.t_ramp = t_full;
    m.t_cruise = a / lim->r_max - t_full;
  } else {
    /* No cruise: p T(p) = a. Both branches of T are increasing in p, so the root of the max is
     * the smaller of the two branch roots. */
    const double p1 = sqrt(a * lim->d1_max / NAV_KIN_S1_MAX);
    const double p2 = isinf(lim->d2_max) ? INFINITY : cbrt(a * a * lim->d2_max / NAV_KIN_S2_MAX);
    m.t_ramp = nav_kin_ramp_time(p1 < p2 ? p1 : p2, lim);
    m.t_cruise = 0.0;
  }
  if (m.t_cruise < 0.0) m.t_cruise = 0.0;
  /* The peak rate follows from the timing so that the move is exactly delta. */
  m.p = delta / (m.t_ramp + m.t_cruise);
  return m;
}

nav_kin_move nav_kin_plan_move_within(double delta, double t_max, const nav_kin_lim *lim, bool *truncated) {
  nav_kin_move m = nav_kin_plan_move(delta, lim);
  *truncated = false;
  if (nav_kin_move_duration(&m) <= t_max * (1.0 + 1e-12)) return m;
  *truncated = true;
  const double sgn = delta < 0.0 ? -1.0 : 1.0;
  nav_kin_move t = {0.0, 0.0, 0.0, 0.0};
  if (!(t_max > 0.0)) return t;
  const double t_full = nav_kin_ramp_time(lim->r_max, lim);
  if (t_max >= 2.0 * t_full) {
    t.t_ramp = t_full;
    t.t_cruise = t_max - 2.0 * t_full;
    t.p = sgn * lim->r_max;
  } else {
    /* Two ramps of t_max / 2 with the largest peak rate they allow. */
    t.t_ramp = 0.5 * t_max;
    const double p1 = t.t_ramp * lim->d1_max / NAV_KIN_S1_MAX;
    const double p2 = t.t_ramp * t.t_ramp * lim->d2_max / NAV_KIN_S2_MAX;
    t.p = sgn * (p1 < p2 ? p1 : p2);
  }
  t.delta = t.p * (t.t_ramp + t.t_cruise);
  return t;
}

nav_status nav_kin_channel_add_move(nav_kin_channel *c, double t0_s, const nav_kin_move *m) {
  if (m->p == 0.0 || m->t_ramp <= 0.0) return NAV_OK;
  nav_status st = nav_kin_channel_add_step(c, t0_s, m->t_ramp, m->p);
  if (st != NAV_OK) return st;
  return nav_kin_channel_add_step(c, t0_s + m->t_ramp + m->t_cruise, m->t_ramp, -m->p);
}

nav_jet nav_kin_move_eval(const nav_kin_move *m, double t) {
  const double p = m->p, Tr = m->t_ramp, Tc = m->t_cruise;
  if (p == 0.0 || Tr <= 0.0 || t <= 0.0) return nav_jet_const(0.0);
  if (t < Tr) {
    const double u = t / Tr;
    return nav_jet_make(p * Tr * ss_I(u), p * ss_S(u), p * ss_S1(u) / Tr, p * ss_S2(u) / (Tr * Tr));
  }
  if (t < Tr + Tc) return nav_jet_make(p * (0.5 * Tr + (t - Tr)), p, 0.0, 0.0);
  if (t < 2.0 * Tr + Tc) {
    const double u = (t - Tr - Tc) / Tr;
    return nav_jet_make(p * (0.5 * Tr + Tc + Tr * (u - ss_I(u))), p * (1.0 - ss_S(u)), -p * ss_S1(u) / Tr,
                        -p * ss_S2(u) / (Tr * Tr));
  }
  return nav_jet_const(m->delta);
}

void nav_kin_move_cos_sin_integral(const nav_kin_move *m, double *ic, double *is) {
  double x[NAV_KIN_GL_NODES], w[NAV_KIN_GL_NODES];
  double sc = 0.0, ss = 0.0;
  if (nav_gauss_legendre(NAV_KIN_GL_NODES, x, w) != NAV_OK) {
    *ic = *is = NAN;
    return;
  }
  /* The three phases are each analytic; pieces of at most 0.1 rad keep the rule exact. */
  const double edges[4] = {0.0, m->t_ramp, m->t_ramp + m->t_cruise, 2.0 * m->t_ramp + m->t_cruise};
  for (int ph = 0; ph < 3; ++ph) {
    const double a = edges[ph], b = edges[ph + 1];
    if (!(b > a)) continue;
    const double dang = fabs(nav_kin_move_eval(m, b).d[0] - nav_kin_move_eval(m, a).d[0]);
    const int pieces = 1 + (int)ceil(dang / 0.1);
    for (int k = 0; k < pieces; ++k) {
      const double ta = a + (b - a) * k / pieces, tb = k + 1 == pieces ? b : a + (b - a) * (k + 1) / pieces;
      const double half = 0.5 * (tb - ta), mid = 0.5 * (tb + ta);
      for (int i = 0; i < NAV_KIN_GL_NODES; ++i) {
        const double ang = nav_kin_move_eval(m, mid + half * x[i]).d[0];
        sc += w[i] * half * cos(ang);
        ss += w[i] * half * sin(ang);
      }
    }
  }
  *ic = sc;
  *is = ss;
}

/* ================================================================ paths */

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

size_t nav_kin_sort_unique(double *t, size_t n) {
  if (n == 0) return 0;
  qsort(t, n, sizeof *t, cmp_double);
  size_t m = 1;
  for (size_t i = 1; i < n; ++i)
    if (t[i] - t[m - 1] > 1e-12) t[m++] = t[i];
  return m;
}

/* int_ta^tb v dt by the path's Gauss-Legendre rule (one application). */
static nav_vec3 gl_integral(const nav_kin_path *p, double ta, double tb) {
  const double half = 0.5 * (tb - ta), mid = 0.5 * (tb + ta);
  nav_vec3 s = nav_vec3_zero();
  for (int i = 0; i < NAV_KIN_GL_NODES; ++i)
    s = nav_vec3_axpy(s, p->w[i], p->vel(p->self, mid + half * p->x[i]));
  return nav_vec3_scale(s, half);
}

static nav_status path_push(nav_kin_path *p, size_t *cap, double t, nav_vec3 r) {
  if (p->n == *cap) {
    const size_t c = *cap ? 2 * *cap : 1024;
    if (c > NAV_KIN_MAX_CHECKPOINTS + 1024) return NAV_ERR_OUT_OF_RANGE;
    double *nt = realloc(p->t, c * sizeof *nt);
    if (!nt) return NAV_ERR_NO_MEMORY;
    p->t = nt;
    nav_vec3 *nr = realloc(p->r, c * sizeof *nr);
    if (!nr) return NAV_ERR_NO_MEMORY;
    p->r = nr;
    nav_vec3 *nv = realloc(p->v_const, c * sizeof *nv);
    if (!nv) return NAV_ERR_NO_MEMORY;
    p->v_const = nv;
    *cap = c;
  }
  p->t[p->n] = t;
  p->r[p->n] = r;
  p->v_const[p->n] = nav_vec3_make(NAN, NAN, NAN);
  p->n++;
  return NAV_OK;
}

nav_status nav_kin_path_build(nav_kin_path *p, const double *breaks, size_t n_breaks, nav_vec3 r0,
                              nav_kin_vel_fn vel, nav_kin_step_fn step, void *self, char *msg,
                              size_t msg_size) {
  size_t cap = 0;
  memset(p, 0, sizeof *p);
  p->vel = vel;
  p->self = self;
  if (n_breaks < 1) return NAV_ERR_INVALID_ARG;
  nav_status st = nav_gauss_legendre(NAV_KIN_GL_NODES, p->x, p->w);
  if (st != NAV_OK) return st;
  st = path_push(p, &cap, breaks[0], r0);
  for (size_t i = 1; st == NAV_OK && i < n_breaks; ++i) {
    const double a = p->t[p->n - 1], b = breaks[i];
    if (!(b > a)) continue;
    const double h = step(self, a, b);
    if (isinf(h)) {
      /* No rotation: the velocity is a polynomial there; if it is the same at both ends it is
       * constant (each channel is monotone or constant between breaks), and positions inside are
       * closed forms. */
      const nav_vec3 va = vel(self, a), vb = vel(self, b);
      if (va.x == vb.x && va.y == vb.y && va.z == vb.z) {
        p->v_const[p->n - 1] = va;
        st = path_push(p, &cap, b, nav_vec3_axpy(p->r[p->n - 1], b - a, va));
        continue;
      }
    }
    double m = isinf(h) ? 1.0 : ceil((b - a) / h);
    if (m < 1.0) m = 1.0;
    if (m + (double)p->n > (double)NAV_KIN_MAX_CHECKPOINTS) {
      st = NAV_ERR_OUT_OF_RANGE;
      break;
    }
    const long mm = (long)m;
    for (long k = 1; st == NAV_OK && k <= mm; ++k) {
      const double ta = p->t[p->n - 1], tb = k == mm ? b : a + (b - a) * (double)k / m;
      st = path_push(p, &cap, tb, nav_vec3_add(p->r[p->n - 1], gl_integral(p, ta, tb)));
    }
  }
  if (st == NAV_ERR_OUT_OF_RANGE && msg)
    snprintf(msg, msg_size, "the trajectory needs more than %d position checkpoints (too long while turning)",
             NAV_KIN_MAX_CHECKPOINTS);
  if (st != NAV_OK) nav_kin_path_free(p);
  return st;
}

nav_vec3 nav_kin_path_eval(const nav_kin_path *p, double t) {
  const size_t n = p->n;
  if (t <= p->t[0]) return nav_vec3_sub(p->r[0], gl_integral(p, t, p->t[0]));
  if (t >= p->t[n - 1]) {
    /* Beyond the last checkpoint (the model builds them past the scene duration): pieces as
     * long as the last interval. */
    const double h = n > 1 ? p->t[n - 1] - p->t[n - 2] : 1.0;
    const double m = ceil((t - p->t[n - 1]) / (h > 0.0 ? h : 1.0));
    nav_vec3 r = p->r[n - 1];
    double ta = p->t[n - 1];
    for (double k = 1.0; k <= m; k += 1.0) {
      const double tb = k == m ? t : p->t[n - 1] + (t - p->t[n - 1]) * k / m;
      r = nav_vec3_add(r, gl_integral(p, ta, tb));
      ta = tb;
    }
    return r;
  }
  size_t lo = 0, hi = n - 1; /* t[lo] <= t < t[hi] */
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    if (p->t[mid] <= t)
      lo = mid;
    else
      hi = mid;
  }
  if (!isnan(p->v_const[lo].x)) return nav_vec3_axpy(p->r[lo], t - p->t[lo], p->v_const[lo]);
  /* From the nearer checkpoint. */
  if (t - p->t[lo] <= p->t[hi] - t) return nav_vec3_add(p->r[lo], gl_integral(p, p->t[lo], t));
  return nav_vec3_sub(p->r[hi], gl_integral(p, t, p->t[hi]));
}

void nav_kin_path_free(nav_kin_path *p) {
  if (!p) return;
  free(p->t);
  free(p->r);
  free(p->v_const);
  p->t = NULL;
  p->r = NULL;
  p->v_const = NULL;
  p->n = 0;
}
