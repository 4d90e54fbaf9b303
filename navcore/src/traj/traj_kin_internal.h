/*
 * Shared kinematic building blocks of the waypoint and segment-script models (kinematics.c).
 *
 * 1. Jets: a scalar function of time with its first three time derivatives, so attitude laws
 *    written once (heading = atan2(v_E, v_N), bank = atan(V psi_dot / g), the Euler-rate map)
 *    give exact analytic rates and angular accelerations (forward-mode differentiation, Leibniz
 *    and Faa di Bruno rules). An unknown derivative order is NaN, which propagates only into that
 *    order, so a formula that needs more orders than it was given shows up as NaN in tests.
 *
 * 2. Channels: a scalar x(t) whose rate r = dx/dt is piecewise constant, joined by ramps
 *        r(t) = r_before + dr S((t - t0) / T),  S(u) = 35u^4 - 84u^5 + 70u^6 - 20u^7  (u in [0, 1]),
 *    the septic smoothstep: S', S'' and S''' vanish at both ends, so r is C3, x is C4 and the
 *    second integral y = int x dt (the distance of a speed channel) is C5. x and y are closed
 *    forms (I = int S, J = int I). A symmetric ramp moves x by r_before T + dr T / 2 exactly.
 *    Peak |S'| = 35/16 at u = 1/2, peak |S''| = 84/(5 sqrt 5) at u = (5 -/+ sqrt 5)/10; a ramp of
 *    dr over T therefore has peak dr' = 35/16 dr / T and peak dr'' = 7.513 dr / T^2.
 *
 * 3. Moves: rest-to-rest changes of a channel value (rate 0 -> p -> cruise -> 0) of minimum
 *    duration within the limits (rate <= r_max, rate' <= d1_max, rate'' <= d2_max), as two
 *    ramps. Used for manoeuvres of an angle (rate = angular rate) and of a speed (rate =
 *    acceleration, so the speed change has a trapezoidal, jerk-limited acceleration).
 *
 * 4. Paths: position as the integral of an analytic velocity, by 8-point Gauss-Legendre
 *    quadrature from checkpoints placed at every non-smooth point and at most h apart in between
 *    (h from the model: 0.5 s or less, scaled down with the rotation rate). Inside a checkpoint
 *    interval the velocity is analytic, so the quadrature is exact to rounding; velocity and
 *    acceleration themselves are always closed forms.
 */
#ifndef NAV_TRAJ_KIN_INTERNAL_H
#define NAV_TRAJ_KIN_INTERNAL_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "navcore/nav_math.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_status.h"
#include "traj/traj_internal.h"
#include "nav_clones.h"

/* ================================================================ jets */

/** f and its first three time derivatives: d[0] = f, d[1] = f', d[2] = f'', d[3] = f'''. */
typedef struct nav_jet {
  double d[4];
} nav_jet;

static inline nav_jet nav_jet_make(double f0, double f1, double f2, double f3) {
  nav_jet r = {{f0, f1, f2, f3}};
  return r;
}
static inline nav_jet nav_jet_const(double v) {
  return nav_jet_make(v, 0.0, 0.0, 0.0);
}
static inline nav_jet nav_jet_add(nav_jet a, nav_jet b) {
  return nav_jet_make(a.d[0] + b.d[0], a.d[1] + b.d[1], a.d[2] + b.d[2], a.d[3] + b.d[3]);
}
static inline nav_jet nav_jet_sub(nav_jet a, nav_jet b) {
  return nav_jet_make(a.d[0] - b.d[0], a.d[1] - b.d[1], a.d[2] - b.d[2], a.d[3] - b.d[3]);
}
static inline nav_jet nav_jet_scale(nav_jet a, double s) {
  return nav_jet_make(a.d[0] * s, a.d[1] * s, a.d[2] * s, a.d[3] * s);
}
/** Leibniz rule. */
static inline nav_jet nav_jet_mul(nav_jet f, nav_jet g) {
  return nav_jet_make(f.d[0] * g.d[0], f.d[1] * g.d[0] + f.d[0] * g.d[1],
                      f.d[2] * g.d[0] + 2.0 * f.d[1] * g.d[1] + f.d[0] * g.d[2],
                      f.d[3] * g.d[0] + 3.0 * f.d[2] * g.d[1] + 3.0 * f.d[1] * g.d[2] + f.d[0] * g.d[3]);
}
/** h(f) from the derivatives h0..h3 of h at f (Faa di Bruno to third order). */
static inline nav_jet nav_jet_chain(nav_jet f, double h0, double h1, double h2, double h3) {
  const double f1 = f.d[1], f2 = f.d[2], f3 = f.d[3];
  return nav_jet_make(h0, h1 * f1, h2 * f1 * f1 + h1 * f2, h3 * f1 * f1 * f1 + 3.0 * h2 * f1 * f2 + h1 * f3);
}
/** The derivative f' as a jet; its third derivative is unknown (NaN). */
static inline nav_jet nav_jet_deriv(nav_jet f) {
  return nav_jet_make(f.d[1], f.d[2], f.d[3], NAN);
}
static inline nav_jet nav_jet_sin(nav_jet f) {
  const double s = sin(f.d[0]), c = cos(f.d[0]);
  return nav_jet_chain(f, s, c, -s, -c);
}
static inline nav_jet nav_jet_cos(nav_jet f) {
  const double s = sin(f.d[0]), c = cos(f.d[0]);
  return nav_jet_chain(f, c, -s, -c, s);
}
static inline nav_jet nav_jet_atan(nav_jet f) {
  const double x = f.d[0], k = 1.0 / (1.0 + x * x);
  return nav_jet_chain(f, atan(x), k, -2.0 * x * k * k, (6.0 * x * x - 2.0) * k * k * k);
}
/** sqrt(f), f > 0. */
static inline nav_jet nav_jet_sqrt(nav_jet f) {
  const double s = sqrt(f.d[0]), i = 1.0 / f.d[0];
  return nav_jet_chain(f, s, 0.5 / s, -0.25 / s * i, 0.375 / s * i * i);
}
/** 1/f, f != 0. */
static inline nav_jet nav_jet_recip(nav_jet f) {
  const double i = 1.0 / f.d[0];
  return nav_jet_chain(f, i, -i * i, 2.0 * i * i * i, -6.0 * i * i * i * i);
}
/** atan2(y, x) with derivative (x y' - y x') / (x^2 + y^2); (x, y) != 0. */
static inline nav_jet nav_jet_atan2(nav_jet y, nav_jet x) {
  const nav_jet num = nav_jet_sub(nav_jet_mul(x, nav_jet_deriv(y)), nav_jet_mul(y, nav_jet_deriv(x)));
  const nav_jet q = nav_jet_mul(num, nav_jet_recip(nav_jet_add(nav_jet_mul(x, x), nav_jet_mul(y, y))));
  return nav_jet_make(atan2(y.d[0], x.d[0]), q.d[0], q.d[1], q.d[2]);
}

/**
 * sin(a) and cos(a), with a = +-0 answered without the library: sin(+-0) = +-0 and cos(+-0) = 1
 * exactly, so the numbers are those of sin() and cos() for every a. Most Euler angles of a
 * vehicle's trajectory (pitch and roll of a car, every angle at rest) are exactly zero for long
 * stretches.
 */
static inline void nav_kin_sincos(double a, double *s, double *c) {
  if (a == 0.0) {
    *s = a;
    *c = 1.0;
  } else {
    *s = sin(a);
    *c = cos(a);
  }
}

/** a and b have the same bits (unlike ==, tells +0 from -0; NaN with the same payload matches).
 *  The caches of the truth generation reuse a result only for inputs of the same bits. */
static inline bool nav_kin_same_bits(double a, double b) {
  uint64_t x, y;
  memcpy(&x, &a, sizeof x);
  memcpy(&y, &b, sizeof y);
  return x == y;
}

/** The n doubles at a and b have the same bits (memcmp's answer, inlined for the short arrays of
 *  the caches below; a and b may point to structs made of doubles only). */
static inline bool nav_kin_same_bits_n(const void *a, const void *b, size_t n) {
  const unsigned char *p = a, *q = b;
  uint64_t diff = 0;
  for (size_t i = 0; i < n; ++i) {
    uint64_t x, y;
    memcpy(&x, p + 8 * i, sizeof x);
    memcpy(&y, q + 8 * i, sizeof y);
    diff |= x ^ y;
  }
  return diff == 0;
}

/** A small cache of nav_kin_sincos: sin and cos of the last NAV_KIN_SC_WAYS angles asked for. An
 *  angle held constant by a channel at rest is recomputed from its step each time and may alternate
 *  between neighbouring doubles (the rounding of x0 + r0 d + dr (d - T/2) with r0 = -dr), hence
 *  more than one entry. */
#define NAV_KIN_SC_WAYS 4
typedef struct nav_kin_sincos_cache {
  double a[NAV_KIN_SC_WAYS], s[NAV_KIN_SC_WAYS], c[NAV_KIN_SC_WAYS];
  int next;
} nav_kin_sincos_cache;

/** Empty (a NaN angle is never taken from the cache). */
static inline void nav_kin_sincos_cache_init(nav_kin_sincos_cache *k) {
  for (int i = 0; i < NAV_KIN_SC_WAYS; ++i)
    k->a[i] = k->s[i] = k->c[i] = NAN;
  k->next = 0;
}

/** nav_kin_sincos(a) through the cache: the same numbers (reused only for the same bits of a). */
static inline void nav_kin_sincos_cached(nav_kin_sincos_cache *k, double a, double *s, double *c) {
  if (!isnan(a))
    for (int i = 0; i < NAV_KIN_SC_WAYS; ++i)
      if (nav_kin_same_bits(a, k->a[i])) {
        *s = k->s[i];
        *c = k->c[i];
        return;
      }
  const int i = k->next;
  k->next = (i + 1) % NAV_KIN_SC_WAYS;
  nav_kin_sincos(a, &k->s[i], &k->c[i]);
  k->a[i] = a;
  *s = k->s[i];
  *c = k->c[i];
}

/**
 * Body rate of b relative to n and its derivative from ZYX Euler-angle jets (numerics.md E3.4):
 *   w_nb_b = [phi' - psi' sin(theta); theta' cos(phi) + psi' cos(theta) sin(phi);
 *             -theta' sin(phi) + psi' cos(theta) cos(phi)]
 * The angles need at least two valid derivative orders.
 */
void nav_kin_euler_rates(nav_jet roll, nav_jet pitch, nav_jet yaw, nav_vec3 *w_nb_b_rps,
                         nav_vec3 *dw_nb_b_rps2);
/** nav_kin_euler_rates with sin and cos of the roll and pitch values given (sr = sin(roll.d[0]),
 *  ...), so that a caller that needs them anyway computes them once; the same numbers. */
void nav_kin_euler_rates_sc(nav_jet roll, nav_jet pitch, nav_jet yaw, double sr, double cr, double sp,
                            double cp, nav_vec3 *w_nb_b_rps, nav_vec3 *dw_nb_b_rps2);

/* ================================================================ ramps, channels, moves */

/** Peak |S'| and |S''| of the septic smoothstep. */
#define NAV_KIN_S1_MAX 2.1875
#define NAV_KIN_S2_MAX 7.5131884024802440 /* 84 / (5 sqrt(5)) */

/** Limits of a channel: |rate| <= r_max, |rate'| <= d1_max, |rate''| <= d2_max (may be INFINITY). */
typedef struct nav_kin_lim {
  double r_max, d1_max, d2_max;
} nav_kin_lim;

/** Shortest ramp that changes the rate by @p dr_abs within @p lim (d1 and d2 bounds). */
double nav_kin_ramp_time(double dr_abs, const nav_kin_lim *lim);

/** One rate ramp; x0, r0 (value and rate at t0) are filled by nav_kin_channel_add_step. */
typedef struct nav_kin_step {
  double t0_s, len_s, dr;
  double r0, x0, y0;
} nav_kin_step;

/** A channel: x(0) = x_init, rate r_init before the first ramp, y(0) = 0. */
typedef struct nav_kin_channel {
  double x_init, r_init;
  nav_kin_step *steps;
  size_t n, cap;
} nav_kin_channel;

void nav_kin_channel_init(nav_kin_channel *c, double x_init, double r_init);
void nav_kin_channel_free(nav_kin_channel *c);
/** Append a ramp starting at or after the end of the previous one (an overlap below 1e-9 s from
 *  rounding is absorbed by starting at the previous end). dr == 0 appends nothing. */
nav_status nav_kin_channel_add_step(nav_kin_channel *c, double t0_s, double len_s, double dr);
/** x and its derivatives (x, r, r', r''). */
nav_jet nav_kin_channel_eval(const nav_kin_channel *c, double t_s);
/** y = int_0^t x and its derivatives (y, x, r, r'). */
nav_jet nav_kin_channel_eval_integral(const nav_kin_channel *c, double t_s);
/** nav_kin_channel_eval through a cached step index @p hint (start with -1; the same numbers). */
nav_jet nav_kin_channel_eval_hint(const nav_kin_channel *c, double t_s, ptrdiff_t *hint);
/** x alone at t (nav_kin_channel_eval's value: the same expression, hence the same number),
 *  through the cached step index @p hint (start with -1). */
double nav_kin_channel_eval_value(const nav_kin_channel *c, double t_s, ptrdiff_t *hint);
/** x, its rate r and r' at t (the numbers of nav_kin_channel_eval). @p hint caches the step
 *  index between calls (start with -1); it only saves the search and never changes a result. */
void nav_kin_channel_eval_rate(const nav_kin_channel *c, double t_s, ptrdiff_t *hint, double *x, double *r,
                               double *r1);
/** nav_kin_channel_eval_rate at the ascending times t_s[0..n-1] (a channel at rest over the
 *  whole span is evaluated once: then it returns true, and every entry has the first one's bits). */
bool nav_kin_channel_eval_rate_n(const nav_kin_channel *c, const double *t_s, int n, ptrdiff_t *hint,
                                 double *x, double *r, double *r1);
/** nav_kin_channel_eval_rate_n, but for a channel at rest over the span (returning true) only the
 *  first entries are written: the caller copies them where it needs them. */
bool nav_kin_channel_eval_rate_n0(const nav_kin_channel *c, const double *t_s, int n, ptrdiff_t *hint,
                                  double *x, double *r, double *r1);
/* Inline forms of the channel evaluation, for the node evaluators' hot loops (no call through the
 * clone dispatch per channel; kinematics.c's functions are these). */

/** The septic smoothstep S(u), its derivative S'(u) and its integral I(u) = int_0^u S. */
static inline double nav_kin_ss_S(double u) {
  return u * u * u * u * (35.0 + u * (-84.0 + u * (70.0 - 20.0 * u)));
}
static inline double nav_kin_ss_S1(double u) {
  const double v = u * (1.0 - u);
  return 140.0 * v * v * v;
}
static inline double nav_kin_ss_I(double u) {
  const double u2 = u * u;
  return u2 * u2 * u * (7.0 + u * (-14.0 + u * (10.0 - 2.5 * u)));
}

/** Index of the last step starting at or before t, -1 if none (binary search). */
ptrdiff_t nav_kin_find_step(const nav_kin_channel *c, double t);

/** nav_kin_find_step through a cached index: sequential evaluation stays in the same step or
 *  moves to the next one, so the binary search is rarely needed. The result is the same index. */
NAV_CLONE_INLINE ptrdiff_t nav_kin_find_step_hint(const nav_kin_channel *c, double t, ptrdiff_t *hint) {
  const ptrdiff_t n = (ptrdiff_t)c->n;
  /* The hint itself (the loop's first candidate, tested the same way). */
  const ptrdiff_t h = *hint;
  if (h >= 0 && h < n) {
    if (c->steps[h].t0_s <= t && (h + 1 >= n || t < c->steps[h + 1].t0_s)) return h;
  } else if (h == -1 && (n == 0 || t < c->steps[0].t0_s)) {
    return h;
  }
  for (ptrdiff_t k = *hint; k <= *hint + 1 && k < n; ++k) {
    if (k < -1) break;
    const bool lo_ok = k < 0 ? (n == 0 || t < c->steps[0].t0_s) : c->steps[k].t0_s <= t;
    const bool hi_ok = k + 1 >= n || t < c->steps[k + 1].t0_s;
    if (lo_ok && hi_ok) {
      *hint = k;
      return k;
    }
  }
  *hint = nav_kin_find_step(c, t);
  return *hint;
}

/** x, r and r' of the channel in step k (-1: before the first) at t: the expressions of the full
 *  state (kinematics.c channel_state_k), hence the same numbers, without y and the higher rate
 *  derivatives. */
NAV_CLONE_INLINE void nav_kin_rate_state(const nav_kin_channel *c, ptrdiff_t k, double t_s, double *x, double *r,
                                         double *r1) {
  if (k >= 0) {
    const nav_kin_step *s = &c->steps[k];
    const double d = t_s - s->t0_s;
    if (d < s->len_s) {
      const double T = s->len_s, u = d / T;
      *x = s->x0 + s->r0 * d + s->dr * T * nav_kin_ss_I(u);
      *r = s->r0 + s->dr * nav_kin_ss_S(u);
      *r1 = s->dr * nav_kin_ss_S1(u) / T;
      return;
    }
    *x = s->x0 + s->r0 * d + s->dr * (d - 0.5 * s->len_s);
    *r = s->r0 + s->dr;
  } else {
    *x = c->x_init + c->r_init * t_s;
    *r = c->r_init;
  }
  *r1 = 0.0;
}

/** nav_kin_channel_eval_rate, inline. */
NAV_CLONE_INLINE void nav_kin_channel_eval_rate_inline(const nav_kin_channel *c, double t_s, ptrdiff_t *hint,
                                                       double *x, double *r, double *r1) {
  nav_kin_rate_state(c, nav_kin_find_step_hint(c, t_s, hint), t_s, x, r, r1);
}

/** nav_kin_channel_eval_rate_n0, inline. */
NAV_CLONE_INLINE bool nav_kin_channel_eval_rate_n0_inline(const nav_kin_channel *c, const double *t_s, int n,
                                                          ptrdiff_t *hint, double *x, double *r, double *r1) {
  if (n < 1) return false;
  /* A channel at rest over the whole span (after its ramps, at zero rate: the usual case for
   * most channels) is evaluated once; its value is constant there, up to the rounding of
   * x0 + r0 d + dr (d - len/2) with r0 + dr = 0. */
  const ptrdiff_t k0 = nav_kin_find_step_hint(c, t_s[0], hint);
  const double t_last = t_s[n - 1];
  bool constant;
  if (k0 < 0) {
    constant = c->r_init == 0.0 && (c->n == 0 || t_last < c->steps[0].t0_s);
  } else {
    const nav_kin_step *s = &c->steps[k0];
    constant = s->r0 + s->dr == 0.0 && !(t_s[0] - s->t0_s < s->len_s) &&
               ((size_t)k0 + 1 >= c->n || t_last < c->steps[k0 + 1].t0_s);
  }
  nav_kin_rate_state(c, k0, t_s[0], &x[0], &r[0], &r1[0]);
  if (constant) return true;
  /* All times in the step of the first (ascending times before the next step's start): the index
   * nav_kin_find_step would return for each. */
  const bool one_step = (k0 < 0 ? (c->n == 0 || t_last < c->steps[0].t0_s)
                                : ((size_t)k0 + 1 >= c->n || t_last < c->steps[k0 + 1].t0_s));
  for (int i = 1; i < n; ++i)
    nav_kin_rate_state(c, one_step ? k0 : nav_kin_find_step_hint(c, t_s[i], hint), t_s[i], &x[i], &r[i], &r1[i]);
  return false;
}

/** Rate after the last ramp. */
double nav_kin_channel_final_rate(const nav_kin_channel *c);
/** Time the last ramp ends (0 if none). */
double nav_kin_channel_end(const nav_kin_channel *c);

/** A rest-to-rest move of a channel value by delta: ramp 0 -> p over t_ramp, cruise at p for
 *  t_cruise, ramp p -> 0 over t_ramp; p (t_ramp + t_cruise) = delta exactly. */
typedef struct nav_kin_move {
  double delta, p, t_ramp, t_cruise;
} nav_kin_move;

static inline double nav_kin_move_duration(const nav_kin_move *m) {
  return 2.0 * m->t_ramp + m->t_cruise;
}
/** Minimum-duration move by @p delta within @p lim. */
nav_kin_move nav_kin_plan_move(double delta, const nav_kin_lim *lim);
/** As nav_kin_plan_move, but when that takes longer than @p t_max, the largest move in the same
 *  direction that fits in t_max (sets *truncated). */
nav_kin_move nav_kin_plan_move_within(double delta, double t_max, const nav_kin_lim *lim, bool *truncated);
/** Append a move starting at t0 (two ramps). */
nav_status nav_kin_channel_add_move(nav_kin_channel *c, double t0_s, const nav_kin_move *m);
/** Value of a standalone move (from 0) at time t from its start, with derivatives. */
nav_jet nav_kin_move_eval(const nav_kin_move *m, double t_s);
/** int cos(b(t)) dt and int sin(b(t)) dt over a standalone move of an angle b (8-point
 *  Gauss-Legendre on pieces of at most 0.1 rad). */
void nav_kin_move_cos_sin_integral(const nav_kin_move *m, double *ic, double *is);

/* ================================================================ paths */

typedef nav_vec3 (*nav_kin_vel_fn)(void *self, double t_s);
/** Longest quadrature interval inside (ta, tb), a smooth stretch; INFINITY when the velocity is
 *  a polynomial of degree <= 15 there (no rotation), which the rule integrates exactly. */
typedef double (*nav_kin_step_fn)(void *self, double ta_s, double tb_s);

#define NAV_KIN_GL_NODES 8
#define NAV_KIN_MAX_CHECKPOINTS 20000000

typedef struct nav_kin_path {
  double *t;
  nav_vec3 *r;
  nav_vec3 *v_const; /* velocity of interval [t_i, t_i+1] when it is constant there, else NaN */
  size_t n;
  double x[NAV_KIN_GL_NODES], w[NAV_KIN_GL_NODES];
  nav_kin_vel_fn vel;
  void *self;
} nav_kin_path;

/**
 * Build checkpoints. @p breaks: sorted times at which the velocity may be non-smooth (first =
 * the time of @p r0, last = the end of the range that needs accurate positions); duplicates are
 * allowed. @return NAV_OK, NAV_ERR_NO_MEMORY, NAV_ERR_OUT_OF_RANGE (more than
 * NAV_KIN_MAX_CHECKPOINTS; msg says so).
 */
nav_status nav_kin_path_build(nav_kin_path *p, const double *breaks, size_t n_breaks, nav_vec3 r0,
                              nav_kin_vel_fn vel, nav_kin_step_fn step, void *self, char *msg,
                              size_t msg_size);
nav_vec3 nav_kin_path_eval(const nav_kin_path *p, double t_s);
void nav_kin_path_free(nav_kin_path *p);

/** Sort and remove duplicates (|a - b| <= 1e-12 s). @return the new count. */
size_t nav_kin_sort_unique(double *t, size_t n);

/* ================================================================ model queries (tests, import) */

/* nav_traj_script_info and nav_traj_segments_plan_info / nav_traj_waypoints_plan_info are public:
 * navcore/nav_traj.h (the I/O library plans imported scripts with them). */

/**
 * Times at which a model built by nav_traj_segments_create / nav_traj_waypoints_create changes
 * piece or starts/ends a ramp (transitions). Writes up to @p cap, returns the total count.
 */
size_t nav_traj_segments_breaks(const void *self, double *out, size_t cap);
size_t nav_traj_waypoints_breaks(const void *self, double *out, size_t cap);
/** Segment boundaries B_0 .. B_count (count + 1 values) of a segment model. */
size_t nav_traj_segments_boundaries(const void *self, double *out, size_t cap);
/** Times at which a waypoint model passes its waypoints (count values). */
size_t nav_traj_waypoints_times(const void *self, double *out, size_t cap);

/* ================================================================ ideal-IMU node evaluation */

/*
 * The ideal IMU (nav_traj_inertial_increment, traj.c) needs, at the n quadrature nodes of one
 * sample interval, only the attitude, omega_nb_b, velocity and acceleration of a local model:
 * no angular acceleration, and the position only on WGS-84 (for gravity and the radii). A model
 * may provide a node evaluator that computes exactly these for all nodes at once and shares the
 * work between them (segment lookup, trigonometry of a common anchor). Its numbers equal those
 * of eval_local at the same times up to rounding (last bits): they are different expressions of
 * the same analytic functions, never an approximation.
 */
#define NAV_KIN_MAX_NODES 16 /* = NAV_GL_MAX_NODES */

typedef struct nav_kin_nodes {
  /* in */
  int n;                         /* node count, 1..NAV_KIN_MAX_NODES */
  const double *x;               /* nodes on [-1, 1], ascending (nav_gauss_legendre) */
  double t0_s, t1_s;             /* the interval */
  double t_s[NAV_KIN_MAX_NODES]; /* node times 0.5 (t0 + t1) + 0.5 (t1 - t0) x_i */
  int64_t k;                     /* t0 = (k - 1) dt and t1 = k dt exactly (dt of the model), else -1 */
  bool need_pos;                 /* positions are wanted if the model has them cheaply */
  /* out */
  bool has_pos;                           /* r_ned_m filled (else the caller integrates v) */
  nav_vec3 r_ned_m[NAV_KIN_MAX_NODES];    /* as nav_local_kin */
  nav_vec3 v_ned_mps[NAV_KIN_MAX_NODES];  /* as nav_local_kin */
  nav_vec3 a_ned_mps2[NAV_KIN_MAX_NODES]; /* as nav_local_kin */
  nav_vec3 w_nb_b_rps[NAV_KIN_MAX_NODES]; /* as nav_local_kin */
  nav_mat3 C_b_n[NAV_KIN_MAX_NODES];      /* the attitude q_b_n of nav_local_kin as a DCM */
  /* same_kin[i] (i >= 1): v, a, w and C of node i are those of node i - 1, bit for bit (the caller
   * clears these flags; an evaluator may set them so that work on equal inputs is skipped). */
  bool same_kin[NAV_KIN_MAX_NODES];
  /* Nonzero (the caller sets 0): every node's v, a, w and C are the evaluator's cached outputs of an
   * interval with every channel at rest, whose content this id names (ids are never reused within a
   * model, so the same id means the same bits). */
  uint64_t rest_id;
} nav_kin_nodes;

/** Node evaluators of the models (self as created by the matching nav_traj_*_create). */
nav_status nav_traj_parametric_nodes(void *self, nav_kin_nodes *io);
nav_status nav_traj_segments_nodes(void *self, nav_kin_nodes *io);
nav_status nav_traj_waypoints_nodes(void *self, nav_kin_nodes *io);

/** Largest |d| for nav_kin_sincos_near. */
#define NAV_KIN_NEAR_RAD 0.05

/**
 * sin and cos of a0 + d from s0 = sin a0 and c0 = cos a0, for |d| <= NAV_KIN_NEAR_RAD: angle
 * addition with sin d and cos d - 1 by their Taylor series through d^11 and d^12 (truncation
 * below d^13 / 13! = 2e-27 at the bound, far under rounding), or through d^3 and d^4 below
 * |d| = 1e-4, added as small corrections so that the result is as accurate as a direct
 * sin/cos (about one ulp).
 */
static inline void nav_kin_sincos_near(double s0, double c0, double d, double *s, double *c) {
  const double d2 = d * d;
  if (d2 < 1e-8) {
    /* |d| < 1e-4: through d^3 and d^4 (omitted d^5/120, d^6/720 < 1e-22). */
    const double sd4 = d * (1.0 - d2 * (1.0 / 6.0)), cm4 = -0.5 * d2 * (1.0 - d2 * (1.0 / 12.0));
    *s = s0 + (c0 * sd4 + s0 * cm4);
    *c = c0 + (c0 * cm4 - s0 * sd4);
    return;
  }
  const double sd =
      d * (1.0 - d2 * (1.0 / 6.0) *
                     (1.0 - d2 * (1.0 / 20.0) *
                                (1.0 - d2 * (1.0 / 42.0) *
                                           (1.0 - d2 * (1.0 / 72.0) * (1.0 - d2 * (1.0 / 110.0))))));
  const double cm1 =
      -0.5 * d2 *
      (1.0 -
       d2 * (1.0 / 12.0) *
           (1.0 - d2 * (1.0 / 30.0) *
                      (1.0 - d2 * (1.0 / 56.0) * (1.0 - d2 * (1.0 / 90.0) * (1.0 - d2 * (1.0 / 132.0))))));
  *s = s0 + (c0 * sd + s0 * cm1);
  *c = c0 + (c0 * cm1 - s0 * sd);
}

#endif /* NAV_TRAJ_KIN_INTERNAL_H */
