/*
 * Segment scripts: hold, accelerate, turn, coordinated turn, climb, circle, figure-eight, helix,
 * lawnmower survey, and the motion commands of gnss-ins-sim (types 1-5), each starting from the
 * end state of the previous segment.
 *
 * State (as in gnss-ins-sim): ZYX Euler angles (yaw, pitch, roll) and the body velocity
 * v_b = (u, v, w). Each of these six quantities is a channel of traj_kin_internal.h: its rate
 * (Euler-angle rate, body acceleration) is piecewise constant, joined by septic-smoothstep
 * ramps, so rates are C3 and the angular acceleration, jerk and their derivatives are continuous
 * and bounded. A seventh channel carries the yaw changes of coordinated segments; the bank
 *   roll = roll_channel + atan(u * psi_dot_coordinated / g)
 * is added to the roll (zero, with its derivatives, outside coordinated turns). Kinematics:
 *   C_b_n = R_z(yaw) R_y(pitch) R_x(roll),  v_n = C_b_n v_b,  a_n = C_b_n (dv_b/dt + w_nb_b x v_b),
 *   w_nb_b from the Euler rates (numerics.md E3.4), dw_nb_b by differentiating it (jets);
 *   position = integral of v_n by Gauss-Legendre from checkpoints (exact to rounding).
 *
 * Timeline. Segments are either LEVEL segments (HOLD, MOTION_RATES: rates held for exactly
 * duration_s) or REST-TO-REST manoeuvres (all other kinds: every rate is zero at their start and
 * end). Where the rate levels change at a boundary B (between two level segments, or between a
 * level segment and a manoeuvre, whose level is zero), each channel ramps from the old level to
 * the new one over the documented ramp time
 *   T = max(35/16 |dr| / d1_max, sqrt(7.513 |dr| / d2_max))
 * (d1, d2 = max_ang_accel, max_ang_jerk for Euler rates; max_jerk, unbounded for body
 * accelerations; for the yaw of coordinated segments also max_rate g / u and max_ang_accel g / u,
 * which bound the roll rate and acceleration of the bank), CENTRED on B. A symmetric ramp
 * integrates to the step it replaces, so outside the ramp windows every angle and velocity equals
 * that of the unsmoothed step profile: a level segment changes them by exactly rate x duration_s.
 * A manoeuvre next to a level segment is padded by the half-ramp. A ramp that does not fit in its level
 * segments is an error, or, with fit_rate_ramps (motion-definition imports), is shortened to fit and counted.
 * The script starts with the rates of its first segment (a trajectory may start turning); after the last
 * segment the final rates continue. Manoeuvres are minimum-time rest-to-rest moves within the limits (Euler
 * rate <= max_rate, body acceleration <= max_accel, ...), per channel and simultaneous, so types 2-5 "end
 * when converged" at the end of their slowest channel; a change that is only rounding residue (1e-12
 * relative) is no change. Absolute attitude commands compare with the unwrapped Euler channels, as
 * gnss-ins-sim does. g in the bank is the flat-Earth gravity, or WGS-84 normal gravity at the origin.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_truth.h"
#include "traj/traj_kin_internal.h"
#include "nav_clones.h"

enum { CH_YAW, CH_PITCH, CH_ROLL, CH_U, CH_V, CH_W, CH_CYAW, CH_N };

typedef struct seg_model {
  nav_kin_channel ch[CH_N];
  nav_kin_path path;
  double g_mps2;
  double end_s;
  double *bounds; /* count + 1 segment boundaries */
  int n_seg;
  double *breaks;
  size_t n_breaks;
  nav_traj_script_info info;
  /* Cached step indices of the channels (speed only, never a result): of the node evaluation,
   * of seg_state and of seg_velocity, whose time patterns differ. */
  ptrdiff_t hint[CH_N], st_hint[CH_N], vel_hint[CH_N];
  /* seg_velocity: the last Euler angles (roll, pitch, yaw), their sines and cosines and their DCM,
   * each reused while its angle is unchanged. */
  double vel_ang[3], vel_sin[3], vel_cos[3];
  nav_mat3 vel_C;
  /* sin and cos of the Euler angles at the first node of the node evaluator (yaw, pitch, roll) and
   * of seg_kin's angles (roll, pitch, yaw and their halves): unchanged angles (a car's yaw on a
   * straight, everything at rest) are not recomputed. */
  nav_kin_sincos_cache nd_sc[3], st_sc[6];
  /* seg_eval_nopos: the channels' (value, rate, rate derivative) of the last call and its result,
   * reused for inputs of the same bits (at rest, on a straight). */
  struct {
    bool ok;
    double in[3 * CH_CYAW];
    nav_local_kin out;
  } st[NAV_KIN_SC_WAYS];
  int st_next;
  /* The node evaluator's last interval with every channel at rest: its channel values and node
   * outputs (nav_traj_segments_nodes). */
  struct {
    bool ok;
    double in[12];
    nav_mat3 C;
    nav_vec3 w, v, a;
    uint64_t id; /* nav_kin_nodes.rest_id of this content */
  } rest[NAV_KIN_SC_WAYS]; /* several: a value at rest may alternate between neighbouring doubles */
  int rest_next;
  uint64_t rest_ids; /* ids handed out so far */
} seg_model;

typedef struct planner {
  const nav_traj_segments *s;
  seg_model *m;
  nav_kin_lim ang, lin;
  int *bad;
  char *msg;
  size_t msg_size;
} planner;

static nav_status fail(planner *pl, int index, nav_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static nav_status fail(planner *pl, int index, nav_status st, const char *fmt, ...) {
  if (pl->bad) *pl->bad = index;
  if (pl->msg && pl->msg_size) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(pl->msg, pl->msg_size, fmt, ap);
    va_end(ap);
  }
  return st;
}

static const char *kind_name(nav_segment_kind k) {
  switch (k) {
  case NAV_SEG_HOLD: return "hold";
  case NAV_SEG_ACCELERATE: return "accelerate";
  case NAV_SEG_TURN: return "turn";
  case NAV_SEG_COORD_TURN: return "coordinated_turn";
  case NAV_SEG_CLIMB: return "climb";
  case NAV_SEG_CIRCLE: return "circle";
  case NAV_SEG_FIGURE_EIGHT: return "figure_eight";
  case NAV_SEG_HELIX: return "helix";
  case NAV_SEG_LAWNMOWER: return "lawnmower";
  case NAV_SEG_MOTION_RATES: return "motion type 1";
  case NAV_SEG_MOTION_ABS_ABS: return "motion type 2";
  case NAV_SEG_MOTION_REL_REL: return "motion type 3";
  case NAV_SEG_MOTION_ABS_REL: return "motion type 4";
  case NAV_SEG_MOTION_REL_ABS: return "motion type 5";
  }
  return "unknown";
}

static bool is_level(nav_segment_kind k) {
  return k == NAV_SEG_HOLD || k == NAV_SEG_MOTION_RATES;
}

static bool is_coordinated(const nav_segment *g) {
  return g->coordinated || g->kind == NAV_SEG_COORD_TURN;
}

/* Rate levels of a segment (zero for manoeuvres). */
static void levels_of(const nav_segment *g, double lv[CH_N]) {
  for (int c = 0; c < CH_N; ++c)
    lv[c] = 0.0;
  if (g->kind != NAV_SEG_MOTION_RATES) return;
  lv[CH_YAW] = g->yaw_rate_rps;
  lv[CH_PITCH] = g->pitch_rate_rps;
  lv[CH_ROLL] = g->roll_rate_rps;
  lv[CH_U] = g->accel_b_mps2.x;
  lv[CH_V] = g->accel_b_mps2.y;
  lv[CH_W] = g->accel_b_mps2.z;
  lv[CH_CYAW] = is_coordinated(g) ? g->yaw_rate_rps : 0.0;
}

static const nav_kin_lim *lim_of(const planner *pl, int c) {
  return (c == CH_U || c == CH_V || c == CH_W) ? &pl->lin : &pl->ang;
}

/* Limits of a yaw move at body-x speed u. A coordinated bank roll = atan(u psi_dot / g) moves
 * with the yaw rate: d(roll)/dt ~ (u/g) d2(psi)/dt2 and d2(roll)/dt2 ~ (u/g) d3(psi)/dt3, so
 * the yaw-rate derivatives are bounded by max_rate g / u and max_ang_accel g / u as well. */
static nav_kin_lim yaw_lim(const planner *pl, double r_max, double u_abs, bool coordinated) {
  nav_kin_lim lim = pl->ang;
  lim.r_max = r_max;
  if (coordinated && u_abs > 0.0) {
    lim.d1_max = fmin(lim.d1_max, pl->s->limits.max_rate_rps * pl->m->g_mps2 / u_abs);
    lim.d2_max = fmin(lim.d2_max, pl->s->limits.max_ang_accel_rps2 * pl->m->g_mps2 / u_abs);
  }
  return lim;
}

/* Ramp lengths T[c] at the boundary between effective segments a (previous) and b, in the order
 * of the script. With fit_rate_ramps a ramp is capped so that each half uses at most half of an
 * adjacent level segment; *shortened counts the capped ones. Returns the half-width (largest
 * T / 2). */
static double boundary_ramps(const planner *pl, int a, int b, double u_abs, double T[CH_N], int *shortened) {
  double la[CH_N], lb[CH_N], cap = INFINITY, h = 0.0;
  const bool coord = is_coordinated(&pl->s->items[a]) || is_coordinated(&pl->s->items[b]);
  const nav_kin_lim lim_yaw = yaw_lim(pl, pl->ang.r_max, u_abs, coord);
  levels_of(&pl->s->items[a], la);
  levels_of(&pl->s->items[b], lb);
  if (pl->s->fit_rate_ramps) {
    if (is_level(pl->s->items[a].kind)) cap = fmin(cap, pl->s->items[a].duration_s);
    if (is_level(pl->s->items[b].kind)) cap = fmin(cap, pl->s->items[b].duration_s);
  }
  for (int c = 0; c < CH_N; ++c) {
    const double d = fabs(lb[c] - la[c]);
    T[c] = d > 0.0 ? nav_kin_ramp_time(d, (c == CH_YAW || c == CH_CYAW) ? &lim_yaw : lim_of(pl, c)) : 0.0;
    if (T[c] > cap) {
      T[c] = cap;
      if (shortened) ++*shortened;
    }
    if (0.5 * T[c] > h) h = 0.5 * T[c];
  }
  return h;
}

static double value_at(const seg_model *m, int c, double t) {
  return nav_kin_channel_eval(&m->ch[c], t).d[0];
}

/* Change from the current value to an absolute target. A difference at rounding level (the
 * residue of earlier moves) is no change: as a move it would be a ramp of microseconds with
 * enormous higher derivatives. */
static double change_to(double target, double current) {
  const double d = target - current;
  return fabs(d) <= 1e-12 * (1.0 + fabs(target)) ? 0.0 : d;
}

static nav_status add_move(planner *pl, int c, double t0, const nav_kin_move *mv, bool coordinated) {
  nav_status st = nav_kin_channel_add_move(&pl->m->ch[c], t0, mv);
  if (st == NAV_OK && c == CH_YAW && coordinated) st = nav_kin_channel_add_move(&pl->m->ch[CH_CYAW], t0, mv);
  return st;
}

/* Height rate -v_D for body velocity (u, v, w) at pitch theta and roll phi (C_b_n row 3). */
static double climb_rate(double theta, double phi, nav_vec3 vb) {
  return sin(theta) * vb.x - cos(theta) * sin(phi) * vb.y - cos(theta) * cos(phi) * vb.z;
}

/* Height gained during a pitch move from theta0 at constant roll and body velocity. */
static double move_height(const nav_kin_move *mv, double theta0, double phi, nav_vec3 vb) {
  double x[NAV_KIN_GL_NODES], w[NAV_KIN_GL_NODES], h = 0.0;
  if (nav_gauss_legendre(NAV_KIN_GL_NODES, x, w) != NAV_OK) return NAN;
  const double edges[4] = {0.0, mv->t_ramp, mv->t_ramp + mv->t_cruise, nav_kin_move_duration(mv)};
  for (int ph = 0; ph < 3; ++ph) {
    const double a = edges[ph], b = edges[ph + 1];
    if (!(b > a)) continue;
    const int pieces = 1 + (int)ceil((b - a) / 0.25);
    for (int k = 0; k < pieces; ++k) {
      const double ta = a + (b - a) * k / pieces, tb = k + 1 == pieces ? b : a + (b - a) * (k + 1) / pieces;
      const double half = 0.5 * (tb - ta), mid = 0.5 * (tb + ta);
      for (int i = 0; i < NAV_KIN_GL_NODES; ++i)
        h += w[i] * half * climb_rate(theta0 + nav_kin_move_eval(mv, mid + half * x[i]).d[0], phi, vb);
    }
  }
  return h;
}

/* Lateral offset of a heading move at speed u (right of the initial track for a right turn). */
static double move_lateral(const nav_kin_move *mv, double u) {
  double ic, is;
  nav_kin_move_cos_sin_integral(mv, &ic, &is);
  return u * is;
}

#define RAD2DEG NAV_RAD2DEG

/* Turn rate for a manoeuvre turning at speed u: the requested one or the largest allowed. */
static nav_status turn_rate(planner *pl, int k, double requested, double u, double *rate) {
  const nav_traj_limits *L = &pl->s->limits;
  double r = requested != 0.0 ? fabs(requested) : L->max_rate_rps;
  if (requested == 0.0 && fabs(u) * r > L->max_lateral_accel_mps2) r = L->max_lateral_accel_mps2 / fabs(u);
  if (r > L->max_rate_rps * (1.0 + 1e-12))
    return fail(pl, k, NAV_ERR_INVALID_ARG,
                "segment %d (%s): turn rate %.4g deg/s exceeds max_rate_rps %.4g rad/s", k,
                kind_name(pl->s->items[k].kind), r * RAD2DEG, L->max_rate_rps);
  if (fabs(u) * r > L->max_lateral_accel_mps2 * (1.0 + 1e-12))
    return fail(pl, k, NAV_ERR_INVALID_ARG,
                "segment %d (%s): turn rate %.4g deg/s at %.4g m/s needs lateral acceleration %.4g m/s^2 but "
                "max_lateral_accel_mps2 is %.4g",
                k, kind_name(pl->s->items[k].kind), r * RAD2DEG, u, fabs(u) * r, L->max_lateral_accel_mps2);
  *rate = r;
  return NAV_OK;
}

static nav_status need_speed(planner *pl, int k, double u) {
  if (u > 1e-9) return NAV_OK;
  return fail(pl, k, NAV_ERR_INVALID_ARG,
              "segment %d (%s): needs forward speed, but the body-x speed at its start is %.4g m/s", k,
              kind_name(pl->s->items[k].kind), u);
}

/* Plan the manoeuvre of rest segment k starting at m0 (all rates zero); *dur = its length.
 * t_avail: time available to motion types 2-5. */
static nav_status plan_manoeuvre(planner *pl, int k, double m0, double t_avail, double *dur) {
  const nav_segment *g = &pl->s->items[k];
  seg_model *m = pl->m;
  const nav_traj_limits *L = &pl->s->limits;
  const bool coord = is_coordinated(g);
  double val[CH_N];
  for (int c = 0; c < CH_N; ++c)
    val[c] = value_at(m, c, m0);
  const double u = val[CH_U];
  nav_status st = NAV_OK;
  *dur = 0.0;
  switch (g->kind) {
  case NAV_SEG_ACCELERATE: {
    const nav_kin_move mv = nav_kin_plan_move(change_to(g->speed_mps, u), &pl->lin);
    *dur = nav_kin_move_duration(&mv);
    return add_move(pl, CH_U, m0, &mv, false);
  }
  case NAV_SEG_TURN:
  case NAV_SEG_COORD_TURN: {
    double r;
    st = turn_rate(pl, k, g->yaw_rate_rps, u, &r);
    if (st != NAV_OK) return st;
    const nav_kin_lim lim = yaw_lim(pl, r, fabs(u), coord);
    const nav_kin_move mv = nav_kin_plan_move(g->yaw_rad, &lim);
    *dur = nav_kin_move_duration(&mv);
    return add_move(pl, CH_YAW, m0, &mv, coord);
  }
  case NAV_SEG_CIRCLE:
  case NAV_SEG_FIGURE_EIGHT: {
    st = need_speed(pl, k, u);
    if (st != NAV_OK) return st;
    if (!(g->radius_m > 0.0))
      return fail(pl, k, NAV_ERR_INVALID_ARG, "segment %d (%s): radius_m must be > 0 (got %g)", k,
                  kind_name(g->kind), g->radius_m);
    double r;
    st = turn_rate(pl, k, u / g->radius_m, u, &r);
    if (st != NAV_OK) return st;
    const nav_kin_lim lim = yaw_lim(pl, r, fabs(u), coord);
    const nav_kin_move mv = nav_kin_plan_move(NAV_TWO_PI * g->turns, &lim);
    st = add_move(pl, CH_YAW, m0, &mv, coord);
    *dur = nav_kin_move_duration(&mv);
    if (st == NAV_OK && g->kind == NAV_SEG_FIGURE_EIGHT) {
      const nav_kin_move back = nav_kin_plan_move(-NAV_TWO_PI * g->turns, &lim);
      st = add_move(pl, CH_YAW, m0 + *dur, &back, coord);
      *dur += nav_kin_move_duration(&back);
    }
    return st;
  }
  case NAV_SEG_CLIMB: {
    st = need_speed(pl, k, u);
    if (st != NAV_OK) return st;
    const double gamma = copysign(fabs(g->pitch_rad), g->height_m);
    if (!(fabs(gamma) > 0.0 && fabs(gamma) <= 80.0 * NAV_DEG2RAD) || g->height_m == 0.0)
      return fail(pl, k, NAV_ERR_INVALID_ARG,
                  "segment %d (climb): needs a height change and a flight-path angle in (0, 80] deg (got %g "
                  "m, %g deg)",
                  k, g->height_m, g->pitch_rad * RAD2DEG);
    const nav_vec3 vb = nav_vec3_make(u, val[CH_V], val[CH_W]);
    const double th0 = val[CH_PITCH], phi = val[CH_ROLL];
    const nav_kin_move up = nav_kin_plan_move(gamma - th0, &pl->ang);
    const nav_kin_move down = nav_kin_plan_move(th0 - gamma, &pl->ang);
    const double h_up = move_height(&up, th0, phi, vb), h_down = move_height(&down, gamma, phi, vb);
    const double rate = climb_rate(gamma, phi, vb);
    const double t_c = (g->height_m - h_up - h_down) / rate;
    if (!(rate * g->height_m > 0.0) || !(t_c >= 0.0))
      return fail(
          pl, k, NAV_ERR_INVALID_ARG,
          "segment %d (climb): a height change of %g m at flight-path angle %g deg needs at least %.4g m for "
          "the pitch transitions (max_ang_accel_rps2 %g, max_ang_jerk_rps3 %g)",
          k, g->height_m, gamma * RAD2DEG, h_up + h_down, L->max_ang_accel_rps2, L->max_ang_jerk_rps3);
    st = add_move(pl, CH_PITCH, m0, &up, false);
    if (st == NAV_OK) st = add_move(pl, CH_PITCH, m0 + nav_kin_move_duration(&up) + t_c, &down, false);
    *dur = nav_kin_move_duration(&up) + t_c + nav_kin_move_duration(&down);
    return st;
  }
  case NAV_SEG_HELIX: {
    st = need_speed(pl, k, u);
    if (st != NAV_OK) return st;
    const double gamma = g->pitch_rad;
    if (!(g->radius_m > 0.0) || !(fabs(gamma) <= 80.0 * NAV_DEG2RAD))
      return fail(
          pl, k, NAV_ERR_INVALID_ARG,
          "segment %d (helix): needs radius_m > 0 and a flight-path angle within 80 deg (got %g m, %g deg)",
          k, g->radius_m, gamma * RAD2DEG);
    double r;
    st = turn_rate(pl, k, u * cos(gamma) / g->radius_m, u, &r);
    if (st != NAV_OK) return st;
    const nav_kin_lim lim = yaw_lim(pl, r, fabs(u), coord);
    const nav_kin_move yaw = nav_kin_plan_move(NAV_TWO_PI * g->turns, &lim);
    const double th0 = val[CH_PITCH];
    const nav_kin_move up = nav_kin_plan_move(gamma - th0, &pl->ang);
    const nav_kin_move down = nav_kin_plan_move(th0 - gamma, &pl->ang);
    const double ty = nav_kin_move_duration(&yaw), tu = nav_kin_move_duration(&up),
                 td = nav_kin_move_duration(&down);
    if (tu + td > ty)
      return fail(
          pl, k, NAV_ERR_INVALID_ARG,
          "segment %d (helix): %g turns take %.4g s, shorter than the %.4g s the pitch transitions need", k,
          g->turns, ty, tu + td);
    st = add_move(pl, CH_YAW, m0, &yaw, coord);
    if (st == NAV_OK) st = add_move(pl, CH_PITCH, m0, &up, false);
    if (st == NAV_OK) st = add_move(pl, CH_PITCH, m0 + ty - td, &down, false);
    *dur = ty;
    return st;
  }
  case NAV_SEG_LAWNMOWER: {
    st = need_speed(pl, k, u);
    if (st != NAV_OK) return st;
    if (g->legs < 1 || g->legs > 100000 || !(g->length_m >= 0.0) ||
        (g->legs > 1 && !(fabs(g->spacing_m) > 0.0)))
      return fail(pl, k, NAV_ERR_INVALID_ARG,
                  "segment %d (lawnmower): needs legs in [1, 100000], length_m >= 0 and spacing_m != 0 (got "
                  "%d, %g m, %g m)",
                  k, g->legs, g->length_m, g->spacing_m);
    const double w_abs = fabs(g->spacing_m);
    nav_kin_move mv = {0.0, 0.0, 0.0, 0.0};
    if (g->legs > 1) {
      /* The U-turn's peak rate is solved so that its lateral offset is the spacing exactly; the
       * offset decreases as the rate rises. */
      double r_hi = L->max_rate_rps;
      if (u * r_hi > L->max_lateral_accel_mps2) r_hi = L->max_lateral_accel_mps2 / u;
      nav_kin_lim lim = yaw_lim(pl, r_hi, u, coord);
      mv = nav_kin_plan_move(NAV_PI, &lim);
      const double d_min = move_lateral(&mv, u);
      if (d_min > w_abs)
        return fail(
            pl, k, NAV_ERR_INVALID_ARG,
            "segment %d (lawnmower): a U-turn at %.4g m/s spans at least %.4g m (turn rate %.4g deg/s, "
            "max_lateral_accel_mps2 %g, max_rate_rps %g) but spacing_m is %g",
            k, u, d_min, r_hi * RAD2DEG, L->max_lateral_accel_mps2, L->max_rate_rps, w_abs);
      double r_lo = r_hi;
      for (int it = 0; it < 200; ++it) {
        r_lo *= 0.5;
        lim.r_max = r_lo;
        mv = nav_kin_plan_move(NAV_PI, &lim);
        if (move_lateral(&mv, u) >= w_abs) break;
      }
      for (int it = 0; it < 200 && r_hi - r_lo > 1e-15 * r_hi; ++it) {
        lim.r_max = 0.5 * (r_lo + r_hi);
        mv = nav_kin_plan_move(NAV_PI, &lim);
        if (move_lateral(&mv, u) > w_abs)
          r_lo = lim.r_max;
        else
          r_hi = lim.r_max;
      }
      lim.r_max = r_hi;
      mv = nav_kin_plan_move(NAV_PI, &lim);
    }
    const double t_leg = g->length_m / u, t_turn = nav_kin_move_duration(&mv);
    double t = m0;
    for (int leg = 0; leg < g->legs && st == NAV_OK; ++leg) {
      t += t_leg;
      if (leg + 1 == g->legs) break;
      nav_kin_move turn = mv;
      const double sgn = ((leg % 2 == 0) ? 1.0 : -1.0) * (g->spacing_m < 0.0 ? -1.0 : 1.0);
      turn.delta *= sgn;
      turn.p *= sgn;
      st = add_move(pl, CH_YAW, t, &turn, coord);
      t += t_turn;
    }
    *dur = t - m0;
    return st;
  }
  case NAV_SEG_MOTION_ABS_ABS:
  case NAV_SEG_MOTION_REL_REL:
  case NAV_SEG_MOTION_ABS_REL:
  case NAV_SEG_MOTION_REL_ABS: {
    const bool att_abs = g->kind == NAV_SEG_MOTION_ABS_ABS || g->kind == NAV_SEG_MOTION_ABS_REL;
    const bool vel_abs = g->kind == NAV_SEG_MOTION_ABS_ABS || g->kind == NAV_SEG_MOTION_REL_ABS;
    const double cmd[6] = {g->yaw_rad, g->pitch_rad, g->roll_rad, g->v_b_mps.x, g->v_b_mps.y, g->v_b_mps.z};
    bool unconverged = false;
    for (int c = 0; c < 6 && st == NAV_OK; ++c) {
      const bool abs_cmd = c < 3 ? att_abs : vel_abs;
      const double delta = abs_cmd ? change_to(cmd[c], val[c]) : cmd[c];
      bool trunc = false;
      nav_kin_lim lim = *lim_of(pl, c);
      if (c == CH_YAW && coord) {
        const double u_end = vel_abs ? g->v_b_mps.x : u + g->v_b_mps.x;
        lim = yaw_lim(pl, lim.r_max, fmax(fabs(u), fabs(u_end)), true);
      }
      nav_kin_move mv = nav_kin_plan_move(delta, &lim);
      if (nav_kin_move_duration(&mv) > t_avail * (1.0 + 1e-12)) {
        if (!pl->s->allow_unconverged) {
          static const char *const names[6] = {
              "yaw", "pitch", "roll", "body-x velocity", "body-y velocity", "body-z velocity"};
          const bool ang = c < 3;
          return fail(
              pl, k, NAV_ERR_INVALID_ARG,
              "segment %d (%s): a %s change of %.6g %s needs %.4g s at %s %g and %s %g but only %.4g s are "
              "available (duration_s %g)",
              k, kind_name(g->kind), names[c], ang ? delta * RAD2DEG : delta, ang ? "deg" : "m/s",
              nav_kin_move_duration(&mv), ang ? "max_rate_rps" : "max_accel_mps2",
              ang ? L->max_rate_rps : L->max_accel_mps2, ang ? "max_ang_accel_rps2" : "max_jerk_mps3",
              ang ? L->max_ang_accel_rps2 : L->max_jerk_mps3, t_avail, g->duration_s);
        }
        mv = nav_kin_plan_move_within(delta, t_avail, &lim, &trunc);
        unconverged = true;
      }
      st = add_move(pl, c, m0, &mv, coord);
      if (nav_kin_move_duration(&mv) > *dur) *dur = nav_kin_move_duration(&mv);
    }
    if (unconverged) {
      if (m->info.unconverged == 0) m->info.first_unconverged = k;
      m->info.unconverged++;
    }
    return st;
  }
  case NAV_SEG_HOLD:
  case NAV_SEG_MOTION_RATES: break;
  }
  return NAV_OK;
}

static nav_status check_segment(planner *pl, int k) {
  const nav_segment *g = &pl->s->items[k];
  const double v[] = {g->duration_s,     g->yaw_rad,        g->pitch_rad,      g->roll_rad,  g->yaw_rate_rps,
                      g->pitch_rate_rps, g->roll_rate_rps,  g->v_b_mps.x,      g->v_b_mps.y, g->v_b_mps.z,
                      g->accel_b_mps2.x, g->accel_b_mps2.y, g->accel_b_mps2.z, g->speed_mps, g->height_m,
                      g->radius_m,       g->turns,          g->length_m,       g->spacing_m};
  for (size_t i = 0; i < sizeof v / sizeof v[0]; ++i)
    if (!isfinite(v[i]))
      return fail(pl, k, NAV_ERR_INVALID_ARG, "segment %d: a field is not a finite number", k);
  if ((int)g->kind < (int)NAV_SEG_HOLD || (int)g->kind > (int)NAV_SEG_MOTION_REL_ABS)
    return fail(pl, k, NAV_ERR_INVALID_ARG, "segment %d: unknown kind %d", k, (int)g->kind);
  const bool needs_duration = is_level(g->kind) || g->kind >= NAV_SEG_MOTION_ABS_ABS;
  if (needs_duration && !(g->duration_s >= 0.0 && g->duration_s <= NAV_SCENE_MAX_DURATION_S))
    return fail(pl, k, NAV_ERR_INVALID_ARG, "segment %d (%s): duration_s must be within [0, %g] s (got %g)",
                k, kind_name(g->kind), NAV_SCENE_MAX_DURATION_S, g->duration_s);
  return NAV_OK;
}

static void seg_free(seg_model *m) {
  if (!m) return;
  for (int c = 0; c < CH_N; ++c)
    nav_kin_channel_free(&m->ch[c]);
  nav_kin_path_free(&m->path);
  free(m->bounds);
  free(m->breaks);
  free(m);
}

static bool limits_ok(const nav_traj_limits *L) {
  const double v[6] = {L->max_accel_mps2, L->max_jerk_mps3,      L->max_lateral_accel_mps2,
                       L->max_rate_rps,   L->max_ang_accel_rps2, L->max_ang_jerk_rps3};
  for (int i = 0; i < 6; ++i)
    if (!(v[i] > 0.0) || isnan(v[i])) return false;
  return true;
}

/* Build the channels of the script (no positions). */
static nav_status plan(const nav_scene *scene, seg_model *m, int *bad, char *msg, size_t msg_size) {
  const nav_traj_segments *s = &scene->trajectory.segments;
  planner pl = {s, m, {0, 0, 0}, {0, 0, 0}, bad, msg, msg_size};
  int *eff = NULL;
  nav_status st = NAV_OK;
  if (bad) *bad = -1;
  if (s->count < 1 || s->count > NAV_MAX_SEGMENTS)
    return fail(&pl, -1, NAV_ERR_INVALID_ARG, "trajectory.segments: needs 1 to %d segments (got %d)",
                NAV_MAX_SEGMENTS, s->count);
  if (!limits_ok(&s->limits))
    return fail(&pl, -1, NAV_ERR_INVALID_ARG, "trajectory.segments.limits: every limit must be > 0");
  const nav_euler e0 = scene->trajectory.initial_attitude;
  if (!isfinite(e0.roll_rad) || !isfinite(e0.pitch_rad) || !isfinite(e0.yaw_rad) ||
      !nav_vec3_isfinite(s->v0_b_mps) || !nav_vec3_isfinite(s->r0_ned_m))
    return fail(&pl, -1, NAV_ERR_INVALID_ARG, "trajectory.segments: the initial state is not finite");
  pl.ang = (nav_kin_lim){s->limits.max_rate_rps, s->limits.max_ang_accel_rps2, s->limits.max_ang_jerk_rps3};
  pl.lin = (nav_kin_lim){s->limits.max_accel_mps2, s->limits.max_jerk_mps3, INFINITY};
  m->info.first_unconverged = -1;
  m->n_seg = s->count;
  m->bounds = calloc((size_t)s->count + 1, sizeof *m->bounds);
  eff = calloc((size_t)s->count, sizeof *eff);
  if (!m->bounds || !eff) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  /* Effective segments: with fit_rate_ramps, zero-length level segments are no-ops. */
  int n_eff = 0;
  for (int k = 0; k < s->count; ++k) {
    st = check_segment(&pl, k);
    if (st != NAV_OK) goto cleanup;
    if (s->fit_rate_ramps && is_level(s->items[k].kind) && s->items[k].duration_s == 0.0) continue;
    eff[n_eff++] = k;
  }
  if (n_eff == 0) {
    st = fail(&pl, -1, NAV_ERR_INVALID_ARG, "trajectory.segments: the script has zero duration");
    goto cleanup;
  }
  {
    /* The script starts with the rates of its first segment (no ramp at t = 0). */
    double lv0[CH_N];
    levels_of(&s->items[eff[0]], lv0);
    const double x0[CH_N] = {e0.yaw_rad,    e0.pitch_rad,  e0.roll_rad, s->v0_b_mps.x,
                             s->v0_b_mps.y, s->v0_b_mps.z, 0.0};
    for (int c = 0; c < CH_N; ++c)
      nav_kin_channel_init(&m->ch[c], x0[c], lv0[c]);
  }
  for (int k = 0; k <= s->count; ++k)
    m->bounds[k] = NAN;
  double occ_left_prev = 0.0, man_end_prev = 0.0;
  for (int j = 0; j < n_eff; ++j) {
    const int k = eff[j];
    const nav_segment *g = &s->items[k];
    double T[CH_N] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    double B = 0.0, h = 0.0;
    if (j > 0) {
      const int kp = eff[j - 1];
      const nav_segment *gp = &s->items[kp];
      /* u at the boundary: constant since the previous manoeuvre ended or segment began, apart
       * from level accelerations (their effect on the bank ramps is second order). */
      const double t_prev_end = is_level(gp->kind) ? m->bounds[kp] + gp->duration_s : man_end_prev;
      h = boundary_ramps(&pl, kp, k, fabs(value_at(m, CH_U, t_prev_end)), T, &m->info.shortened_ramps);
      if (is_level(gp->kind)) {
        B = m->bounds[kp] + gp->duration_s;
        if (occ_left_prev + h > gp->duration_s * (1.0 + 1e-12) + 1e-12) {
          st = fail(&pl, kp, NAV_ERR_INVALID_ARG,
                    "segment %d (%s): its rate-step ramps need %.4g s at its start and %.4g s at its end "
                    "(max_ang_accel_rps2 %g, max_ang_jerk_rps3 %g, max_jerk_mps3 %g) but it lasts only %g s",
                    kp, kind_name(gp->kind), occ_left_prev, h, s->limits.max_ang_accel_rps2,
                    s->limits.max_ang_jerk_rps3, s->limits.max_jerk_mps3, gp->duration_s);
          goto cleanup;
        }
      } else {
        B = man_end_prev + h;
      }
    }
    m->bounds[k] = B;
    /* The ramps at this boundary, centred on it. */
    if (j > 0) {
      double la[CH_N], lb[CH_N];
      levels_of(&s->items[eff[j - 1]], la);
      levels_of(g, lb);
      for (int c = 0; c < CH_N && st == NAV_OK; ++c) {
        const double d = lb[c] - la[c];
        if (d == 0.0) continue;
        if (lim_of(&pl, c) == &pl.ang) {
          const double acc = fabs(d) * NAV_KIN_S1_MAX / T[c];
          if (acc > m->info.max_ramp_ang_accel_rps2) m->info.max_ramp_ang_accel_rps2 = acc;
        }
        st = nav_kin_channel_add_step(&m->ch[c], B - 0.5 * T[c], T[c], d);
      }
      if (st != NAV_OK) {
        st = fail(&pl, k, st, "segment %d (%s): internal ramp ordering error", k, kind_name(g->kind));
        goto cleanup;
      }
    }
    if (!is_level(g->kind)) {
      /* Time that motion types 2-5 may use: their maximum minus the pads of the ramps. */
      const double h_next =
          j + 1 < n_eff ? boundary_ramps(&pl, k, eff[j + 1], fabs(value_at(m, CH_U, B)), T, NULL) : 0.0;
      double t_avail = g->duration_s - h - h_next;
      if (t_avail < 0.0) t_avail = 0.0;
      double dur = 0.0;
      const double m0 = B + h;
      st = plan_manoeuvre(&pl, k, m0, t_avail, &dur);
      if (st != NAV_OK) goto cleanup;
      man_end_prev = m0 + dur;
    }
    occ_left_prev = h;
  }
  {
    const int kl = eff[n_eff - 1];
    const nav_segment *gl = &s->items[kl];
    if (is_level(gl->kind)) {
      if (occ_left_prev > gl->duration_s * (1.0 + 1e-12) + 1e-12) {
        st = fail(&pl, kl, NAV_ERR_INVALID_ARG,
                  "segment %d (%s): its rate-step ramps need %.4g s but it lasts only %g s", kl,
                  kind_name(gl->kind), occ_left_prev, gl->duration_s);
        goto cleanup;
      }
      m->bounds[s->count] = m->bounds[kl] + gl->duration_s;
    } else {
      m->bounds[s->count] = man_end_prev;
    }
  }
  /* Skipped segments sit at the next boundary. */
  for (int k = s->count - 1; k >= 0; --k)
    if (isnan(m->bounds[k])) m->bounds[k] = m->bounds[k + 1];
  m->end_s = m->bounds[s->count];
  m->info.duration_s = m->end_s;
  if (!(m->end_s > 0.0)) {
    st = fail(&pl, -1, NAV_ERR_INVALID_ARG, "trajectory.segments: the script has zero duration");
    goto cleanup;
  }
  if (m->end_s > NAV_SCENE_MAX_DURATION_S) {
    st = fail(&pl, -1, NAV_ERR_INVALID_ARG, "trajectory.segments: the script lasts %g s, more than %g s",
              m->end_s, NAV_SCENE_MAX_DURATION_S);
    goto cleanup;
  }
cleanup:
  free(eff);
  return st;
}

/* ---------------------------------------------------------------- evaluation */

typedef struct seg_att {
  nav_jet yaw, pitch, roll, u, v, w;
} seg_att;

static seg_att seg_state(seg_model *m, double t) {
  seg_att a;
  a.yaw = nav_kin_channel_eval_hint(&m->ch[CH_YAW], t, &m->st_hint[CH_YAW]);
  a.pitch = nav_kin_channel_eval_hint(&m->ch[CH_PITCH], t, &m->st_hint[CH_PITCH]);
  a.roll = nav_kin_channel_eval_hint(&m->ch[CH_ROLL], t, &m->st_hint[CH_ROLL]);
  a.u = nav_kin_channel_eval_hint(&m->ch[CH_U], t, &m->st_hint[CH_U]);
  a.v = nav_kin_channel_eval_hint(&m->ch[CH_V], t, &m->st_hint[CH_V]);
  a.w = nav_kin_channel_eval_hint(&m->ch[CH_W], t, &m->st_hint[CH_W]);
  if (m->ch[CH_CYAW].n > 0) {
    /* Coordinated bank atan(u psi_dot_c / g): zero with its derivatives where psi_dot_c is. */
    const nav_jet cy = nav_jet_deriv(nav_kin_channel_eval_hint(&m->ch[CH_CYAW], t, &m->st_hint[CH_CYAW]));
    if (cy.d[0] != 0.0 || cy.d[1] != 0.0 || cy.d[2] != 0.0)
      a.roll = nav_jet_add(a.roll, nav_jet_atan(nav_jet_scale(nav_jet_mul(a.u, cy), 1.0 / m->g_mps2)));
  }
  return a;
}

/* C_b_n = R_z(yaw) R_y(pitch) R_x(roll) from the sines and cosines of roll, pitch and yaw: the
 * expressions of nav_euler_to_dcm, so equal inputs give the same bits. */
static nav_mat3 dcm_of(double sr, double cr, double sp, double cp, double sy, double cy) {
  nav_mat3 c = {{{cp * cy, -cr * sy + sr * sp * cy, sr * sy + cr * sp * cy},
                 {cp * sy, cr * cy + sr * sp * sy, -sr * cy + cr * sp * sy},
                 {-sp, sr * cp, cr * cp}}};
  return c;
}

/* The quaternion of nav_euler_to_quat from the sines and cosines of the half angles (the same
 * products in the same order). */
static nav_quat quat_of(double shr, double chr, double shp, double chp, double shy, double chy) {
  const nav_quat q_roll = {chr, shr, 0.0, 0.0};
  const nav_quat q_pitch = {chp, 0.0, shp, 0.0};
  const nav_quat q_yaw = {chy, 0.0, 0.0, shy};
  return nav_quat_mul(nav_quat_mul(q_yaw, q_pitch), q_roll);
}

/* v_n at t, the integrand of the position quadrature (eight calls per position): channel values
 * only, and the sine and cosine of an Euler angle only when that angle changed since the last call
 * (a car turns about yaw alone). The numbers are those of seg_eval's velocity. */
static nav_vec3 seg_velocity(void *self, double t) {
  seg_model *m = self;
  ptrdiff_t *h = m->vel_hint;
  const double yaw = nav_kin_channel_eval_value(&m->ch[CH_YAW], t, &h[CH_YAW]);
  const double pitch = nav_kin_channel_eval_value(&m->ch[CH_PITCH], t, &h[CH_PITCH]);
  double roll = nav_kin_channel_eval_value(&m->ch[CH_ROLL], t, &h[CH_ROLL]);
  const double u = nav_kin_channel_eval_value(&m->ch[CH_U], t, &h[CH_U]);
  if (m->ch[CH_CYAW].n > 0)
    roll += atan(u * nav_kin_channel_eval_hint(&m->ch[CH_CYAW], t, &h[CH_CYAW]).d[1] / m->g_mps2);
  const double ang[3] = {roll, pitch, yaw};
  bool changed = false;
  for (int i = 0; i < 3; ++i)
    /* Same value and sign (a cached sin(+0) must not stand for sin(-0)); NaN never matches. */
    if (!(ang[i] == m->vel_ang[i] && signbit(ang[i]) == signbit(m->vel_ang[i]))) {
      nav_kin_sincos(ang[i], &m->vel_sin[i], &m->vel_cos[i]);
      m->vel_ang[i] = ang[i];
      changed = true;
    }
  if (changed)
    m->vel_C = dcm_of(m->vel_sin[0], m->vel_cos[0], m->vel_sin[1], m->vel_cos[1], m->vel_sin[2], m->vel_cos[2]);
  const nav_vec3 vb = nav_vec3_make(u, nav_kin_channel_eval_value(&m->ch[CH_V], t, &h[CH_V]),
                                    nav_kin_channel_eval_value(&m->ch[CH_W], t, &h[CH_W]));
  return nav_mat3_mul_vec(m->vel_C, vb);
}

static double seg_step(void *self, double ta, double tb) {
  seg_model *m = self;
  const double ts[3] = {ta, 0.5 * (ta + tb), tb};
  double w = 0.0;
  for (int i = 0; i < 3; ++i) {
    const seg_att a = seg_state(m, ts[i]);
    const double r = fabs(a.yaw.d[1]) + fabs(a.pitch.d[1]) + fabs(a.roll.d[1]);
    if (r > w) w = r;
  }
  if (w == 0.0) return INFINITY;
  /* 8-point Gauss-Legendre over an interval turning by <= 0.5 rad is exact to rounding. */
  return w > 1.0 ? 0.5 / w : 0.5;
}

/* The sines and cosines of the Euler angles, each computed once (none for a zero angle, the
 * model's caches st_sc), and q_b_n from those of the half angles (nav_euler_to_quat's numbers). */
static inline void euler_trig(seg_model *m, double roll, double pitch, double yaw, double *sr, double *cr,
                              double *sp, double *cp, double *sy, double *cy, nav_quat *q_b_n) {
  double shr, chr, shp, chp, shy, chy;
  nav_kin_sincos_cached(&m->st_sc[0], roll, sr, cr);
  nav_kin_sincos_cached(&m->st_sc[1], pitch, sp, cp);
  nav_kin_sincos_cached(&m->st_sc[2], yaw, sy, cy);
  nav_kin_sincos_cached(&m->st_sc[3], 0.5 * roll, &shr, &chr);
  nav_kin_sincos_cached(&m->st_sc[4], 0.5 * pitch, &shp, &chp);
  nav_kin_sincos_cached(&m->st_sc[5], 0.5 * yaw, &shy, &chy);
  *q_b_n = quat_of(shr, chr, shp, chp, shy, chy);
}

static nav_status seg_kin(seg_model *m, double t_s, nav_local_kin *out, bool with_pos) {
  const seg_att a = seg_state(m, t_s);
  /* nav_euler_to_quat, nav_kin_euler_rates and nav_euler_to_dcm of the Euler angles, with each
   * sine and cosine computed once (and none for a zero angle): the same numbers. */
  const double roll = a.roll.d[0], pitch = a.pitch.d[0], yaw = a.yaw.d[0];
  double sr, cr, sp, cp, sy, cy;
  nav_local_kin k;
  euler_trig(m, roll, pitch, yaw, &sr, &cr, &sp, &cp, &sy, &cy, &k.q_b_n);
  nav_kin_euler_rates_sc(a.roll, a.pitch, a.yaw, sr, cr, sp, cp, &k.w_nb_b_rps, &k.dw_nb_b_rps2);
  const nav_mat3 C = dcm_of(sr, cr, sp, cp, sy, cy);
  const nav_vec3 vb = nav_vec3_make(a.u.d[0], a.v.d[0], a.w.d[0]);
  const nav_vec3 vb_dot = nav_vec3_make(a.u.d[1], a.v.d[1], a.w.d[1]);
  k.v_ned_mps = nav_mat3_mul_vec(C, vb);
  k.a_ned_mps2 = nav_mat3_mul_vec(C, nav_vec3_add(vb_dot, nav_vec3_cross(k.w_nb_b_rps, vb)));
  k.r_ned_m = with_pos ? nav_kin_path_eval(&m->path, t_s) : nav_vec3_zero();
  *out = k;
  return NAV_OK;
}

static nav_status seg_eval(void *self, double t_s, nav_local_kin *out) {
  return seg_kin(self, t_s, out, true);
}

/*
 * seg_kin without the position, to first order: the channels' values, rates and rate derivatives
 * (nav_kin_channel_eval_rate: the numbers of the jets' first three orders) and the value and first
 * derivative parts of nav_kin_euler_rates_sc, written out. Each part of a jet depends only on the
 * same and lower orders of its operands (Leibniz and chain rules), so the values and first
 * derivatives computed here are the jets' own, operation for operation. The coordinated bank
 * (atan of a product of jets) takes the general path.
 */
static nav_status seg_eval_nopos(void *self, double t_s, nav_local_kin *out) {
  seg_model *m = self;
  if (m->ch[CH_CYAW].n > 0) return seg_kin(m, t_s, out, false);
  double x[CH_CYAW], r[CH_CYAW], r1[CH_CYAW];
  for (int c = 0; c < CH_CYAW; ++c)
    nav_kin_channel_eval_rate_inline(&m->ch[c], t_s, &m->st_hint[c], &x[c], &r[c], &r1[c]);
  double in[3 * CH_CYAW];
  memcpy(in, x, sizeof x);
  memcpy(in + CH_CYAW, r, sizeof r);
  memcpy(in + 2 * CH_CYAW, r1, sizeof r1);
  /* The yaw and the speed first: while turning or accelerating they change every call. */
  for (int e = 0; e < NAV_KIN_SC_WAYS; ++e)
    if (m->st[e].ok && nav_kin_same_bits(in[CH_YAW], m->st[e].in[CH_YAW]) &&
        nav_kin_same_bits(in[CH_U], m->st[e].in[CH_U]) && nav_kin_same_bits_n(in, m->st[e].in, 3 * CH_CYAW)) {
      *out = m->st[e].out;
      return NAV_OK;
    }
  const double roll = x[CH_ROLL], pitch = x[CH_PITCH], yaw = x[CH_YAW];
  double sr, cr, sp, cp, sy, cy;
  nav_local_kin k;
  euler_trig(m, roll, pitch, yaw, &sr, &cr, &sp, &cp, &sy, &cy, &k.q_b_n);
  /* nav_kin_euler_rates_sc: dphi = (rr, rr1), dth = (pr, pr1), dpsi = (yr, yr1); sin/cos jets of
   * pitch and roll (value, derivative) = (sp, cp pr), (cp, -sp pr), (sr, cr rr), (cr, -sr rr). */
  const double rr = r[CH_ROLL], rr1 = r1[CH_ROLL], pr = r[CH_PITCH], pr1 = r1[CH_PITCH];
  const double yr = r[CH_YAW], yr1 = r1[CH_YAW];
  const double sth1 = cp * pr, cth1 = -sp * pr, sph1 = cr * rr, cph1 = -sr * rr;
  /* mul(cth, sph) and mul(cth, cph) */
  const double csd0 = cp * sr, csd1 = cth1 * sr + cp * sph1;
  const double ccd0 = cp * cr, ccd1 = cth1 * cr + cp * cph1;
  const double wx0 = rr - yr * sp, wx1 = rr1 - (yr1 * sp + yr * sth1);
  const double wy0 = pr * cr + yr * csd0, wy1 = (pr1 * cr + pr * cph1) + (yr1 * csd0 + yr * csd1);
  const double wz0 = yr * ccd0 - pr * sr, wz1 = (yr1 * ccd0 + yr * ccd1) - (pr1 * sr + pr * sph1);
  k.w_nb_b_rps = nav_vec3_make(wx0, wy0, wz0);
  k.dw_nb_b_rps2 = nav_vec3_make(wx1, wy1, wz1);
  const nav_mat3 C = dcm_of(sr, cr, sp, cp, sy, cy);
  const nav_vec3 vb = nav_vec3_make(x[CH_U], x[CH_V], x[CH_W]);
  const nav_vec3 vb_dot = nav_vec3_make(r[CH_U], r[CH_V], r[CH_W]);
  k.v_ned_mps = nav_mat3_mul_vec(C, vb);
  k.a_ned_mps2 = nav_mat3_mul_vec(C, nav_vec3_add(vb_dot, nav_vec3_cross(k.w_nb_b_rps, vb)));
  k.r_ned_m = nav_vec3_zero();
  /* Kept when every channel is at a constant rate of zero (at rest, on a straight at constant
   * speed): otherwise the values move with t and do not repeat. */
  bool level = true;
  for (int c = 0; c < CH_CYAW; ++c)
    level &= r[c] == 0.0 && r1[c] == 0.0;
  if (level) {
    const int e = m->st_next;
    m->st_next = (e + 1) % NAV_KIN_SC_WAYS;
    memcpy(m->st[e].in, in, sizeof in);
    m->st[e].out = k;
    m->st[e].ok = true;
  }
  *out = k;
  return NAV_OK;
}

/*
 * Ideal-IMU nodes: seg_eval without the position (the caller integrates the velocity) and
 * without the angular acceleration, with the attitude as a DCM. The channels are found through
 * cached step indices and a channel at rest is evaluated once per interval; the bank jet is
 * reduced to its first derivative; the sine and cosine of an Euler angle come from one sincos
 * per interval (angle addition to the other nodes, or reuse while the angle is unchanged). The
 * expressions are those of seg_state, nav_euler_to_dcm and nav_kin_euler_rates (value parts of
 * the jets), so the numbers agree with seg_eval to rounding.
 */
NAV_HOT_CLONES nav_status nav_traj_segments_nodes(void *self, nav_kin_nodes *io) {
  seg_model *m = self;
  const int n = io->n;
  /* Channel values at all nodes; ang/rate: yaw, pitch, roll (channel order). */
  double ang[3][NAV_KIN_MAX_NODES], rate[3][NAV_KIN_MAX_NODES], vb[3][NAV_KIN_MAX_NODES],
      vbd[3][NAV_KIN_MAX_NODES];
  double r1[NAV_KIN_MAX_NODES];
  bool at_rest = m->ch[CH_CYAW].n == 0;
  bool rest[6];
  for (int c = 0; c < 3; ++c) {
    rest[c] = nav_kin_channel_eval_rate_n0_inline(&m->ch[c], io->t_s, n, &m->hint[c], ang[c], rate[c], r1);
    rest[3 + c] = nav_kin_channel_eval_rate_n0_inline(&m->ch[CH_U + c], io->t_s, n, &m->hint[CH_U + c], vb[c], vbd[c], r1);
    at_rest &= rest[c] & rest[3 + c];
  }
  /* Every channel at rest over the interval (each node has the first node's channel values): when
   * those have the bits of the last such interval's, so have the outputs (a car on a straight or
   * standing still). */
  double rest_in[12];
  if (at_rest) {
    for (int c = 0; c < 3; ++c) {
      rest_in[c] = ang[c][0];
      rest_in[3 + c] = rate[c][0];
      rest_in[6 + c] = vb[c][0];
      rest_in[9 + c] = vbd[c][0];
    }
    for (int e = 0; e < NAV_KIN_SC_WAYS; ++e)
      if (m->rest[e].ok && nav_kin_same_bits(rest_in[0], m->rest[e].in[0]) &&
          nav_kin_same_bits_n(rest_in, m->rest[e].in, 12)) {
        for (int i = 0; i < n; ++i) {
          io->C_b_n[i] = m->rest[e].C;
          io->w_nb_b_rps[i] = m->rest[e].w;
          io->v_ned_mps[i] = m->rest[e].v;
          io->a_ned_mps2[i] = m->rest[e].a;
          io->same_kin[i] = i > 0;
        }
        io->rest_id = m->rest[e].id;
        io->has_pos = false;
        return NAV_OK;
      }
  }
  /* The channels at rest: their first node's values at every node (as nav_kin_channel_eval_rate_n). */
  for (int c = 0; c < 3; ++c)
    for (int i = 1; i < n; ++i) {
      if (rest[c]) {
        ang[c][i] = ang[c][0];
        rate[c][i] = rate[c][0];
      }
      if (rest[3 + c]) {
        vb[c][i] = vb[c][0];
        vbd[c][i] = vbd[c][0];
      }
    }
  if (m->ch[CH_CYAW].n > 0) {
    /* Bank atan(z), z = u psi_dot_c / g, and its rate z' / (1 + z^2). */
    double cx[NAV_KIN_MAX_NODES], cr[NAV_KIN_MAX_NODES], cr1[NAV_KIN_MAX_NODES];
    nav_kin_channel_eval_rate_n(&m->ch[CH_CYAW], io->t_s, n, &m->hint[CH_CYAW], cx, cr, cr1);
    const double gi = 1.0 / m->g_mps2;
    for (int i = 0; i < n; ++i)
      if (cr[i] != 0.0 || cr1[i] != 0.0) {
        const double z0 = vb[0][i] * cr[i] * gi, z1 = (vbd[0][i] * cr[i] + vb[0][i] * cr1[i]) * gi;
        ang[2][i] += atan(z0);
        rate[2][i] += 1.0 / (1.0 + z0 * z0) * z1;
      }
  }
  /* sin and cos of the Euler angles: directly at the first node, at the others by angle addition
   * from it (they differ by at most rate x dt), reused while an angle is unchanged. */
  double sn[3][NAV_KIN_MAX_NODES], cs[3][NAV_KIN_MAX_NODES];
  for (int c = 0; c < 3; ++c) {
    const double a0 = ang[c][0];
    /* none for a zero angle (a car's pitch and roll) or one unchanged since the last interval */
    nav_kin_sincos_cached(&m->nd_sc[c], a0, &sn[c][0], &cs[c][0]);
    for (int i = 1; i < n; ++i) {
      const double d = ang[c][i] - a0;
      if (d == 0.0) {
        sn[c][i] = sn[c][0];
        cs[c][i] = cs[c][0];
      } else if (fabs(d) <= NAV_KIN_NEAR_RAD) {
        nav_kin_sincos_near(sn[c][0], cs[c][0], d, &sn[c][i], &cs[c][i]);
      } else {
        sn[c][i] = sin(ang[c][i]);
        cs[c][i] = cos(ang[c][i]);
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    if (i > 0) {
      /* Inputs of the same bits as the previous node's (every channel at rest or constant over the
       * interval: a car on a straight, or standing): the same outputs. The sines and cosines follow
       * from the angles (equal angles get equal ones above). */
      bool same = true;
      for (int c = 0; c < 3 && same; ++c)
        same = nav_kin_same_bits(ang[c][i], ang[c][i - 1]) && nav_kin_same_bits(rate[c][i], rate[c][i - 1]) &&
               nav_kin_same_bits(vb[c][i], vb[c][i - 1]) && nav_kin_same_bits(vbd[c][i], vbd[c][i - 1]);
      if (same) {
        io->C_b_n[i] = io->C_b_n[i - 1];
        io->w_nb_b_rps[i] = io->w_nb_b_rps[i - 1];
        io->v_ned_mps[i] = io->v_ned_mps[i - 1];
        io->a_ned_mps2[i] = io->a_ned_mps2[i - 1];
        io->same_kin[i] = true;
        continue;
      }
    }
    const double sy = sn[0][i], cy = cs[0][i], sp = sn[1][i], cp = cs[1][i], sr = sn[2][i], cr = cs[2][i];
    /* C_b_n = R_z(yaw) R_y(pitch) R_x(roll) (nav_euler_to_dcm). */
    nav_mat3 *C = &io->C_b_n[i];
    C->m[0][0] = cp * cy;
    C->m[0][1] = -cr * sy + sr * sp * cy;
    C->m[0][2] = sr * sy + cr * sp * cy;
    C->m[1][0] = cp * sy;
    C->m[1][1] = cr * cy + sr * sp * sy;
    C->m[1][2] = -sr * cy + cr * sp * sy;
    C->m[2][0] = -sp;
    C->m[2][1] = sr * cp;
    C->m[2][2] = cr * cp;
    /* numerics.md E3.4: omega_nb_b from the Euler rates. */
    const double dpsi = rate[0][i], dth = rate[1][i], dphi = rate[2][i];
    const double wx = dphi - dpsi * sp, wy = dth * cr + dpsi * (cp * sr), wz = dpsi * (cp * cr) - dth * sr;
    const double u = vb[0][i], v = vb[1][i], w = vb[2][i];
    /* a_b = dv_b/dt + w_nb_b x v_b */
    const double ax = vbd[0][i] + (wy * w - wz * v), ay = vbd[1][i] + (wz * u - wx * w),
                 az = vbd[2][i] + (wx * v - wy * u);
    io->w_nb_b_rps[i] = nav_vec3_make(wx, wy, wz);
    io->v_ned_mps[i] = nav_vec3_make(C->m[0][0] * u + C->m[0][1] * v + C->m[0][2] * w,
                                     C->m[1][0] * u + C->m[1][1] * v + C->m[1][2] * w,
                                     C->m[2][0] * u + C->m[2][1] * v + C->m[2][2] * w);
    io->a_ned_mps2[i] = nav_vec3_make(C->m[0][0] * ax + C->m[0][1] * ay + C->m[0][2] * az,
                                      C->m[1][0] * ax + C->m[1][1] * ay + C->m[1][2] * az,
                                      C->m[2][0] * ax + C->m[2][1] * ay + C->m[2][2] * az);
  }
  if (at_rest) {
    const int e = m->rest_next;
    m->rest_next = (e + 1) % NAV_KIN_SC_WAYS;
    memcpy(m->rest[e].in, rest_in, sizeof rest_in);
    m->rest[e].C = io->C_b_n[0];
    m->rest[e].w = io->w_nb_b_rps[0];
    m->rest[e].v = io->v_ned_mps[0];
    m->rest[e].a = io->a_ned_mps2[0];
    m->rest[e].ok = true;
    /* Every node has node 0's outputs here (all channels at rest: equal inputs at every node). */
    m->rest[e].id = ++m->rest_ids;
    io->rest_id = m->rest[e].id;
  }
  io->has_pos = false;
  return NAV_OK;
}

static void seg_destroy(void *self) {
  seg_free(self);
}

/* A zeroed model with empty caches. */
static seg_model *seg_alloc(void) {
  seg_model *m = calloc(1, sizeof *m);
  if (!m) return NULL;
  for (int c = 0; c < CH_N; ++c)
    m->hint[c] = m->st_hint[c] = m->vel_hint[c] = -1;
  for (int i = 0; i < 3; ++i) {
    m->vel_ang[i] = NAN;
    nav_kin_sincos_cache_init(&m->nd_sc[i]);
  }
  for (int i = 0; i < 6; ++i)
    nav_kin_sincos_cache_init(&m->st_sc[i]);
  return m;
}

static double gravity_of(const nav_scene *scene) {
  if (scene->earth.model == NAV_EARTH_WGS84)
    return nav_earth_gravity_normal_mps2(scene->earth.origin_lat_rad, scene->earth.origin_h_m);
  return scene->earth.flat_gravity_mps2;
}

nav_status nav_traj_segments_plan_info(const nav_scene *scene, nav_traj_script_info *info, int *bad_index,
                                       char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !info) return NAV_ERR_INVALID_ARG;
  seg_model *m = seg_alloc();
  if (!m) return NAV_ERR_NO_MEMORY;
  m->g_mps2 = gravity_of(scene);
  const nav_status st = plan(scene, m, bad_index, msg, msg_size);
  if (st == NAV_OK) *info = m->info;
  seg_free(m);
  return st;
}

nav_status nav_traj_segments_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                    size_t msg_size) {
  (void)dt_s;
  seg_model *m = NULL;
  nav_status st = NAV_OK;
  if (msg && msg_size) msg[0] = '\0';
  m = seg_alloc();
  if (!m) return NAV_ERR_NO_MEMORY;
  m->g_mps2 = gravity_of(scene);
  if (!(m->g_mps2 > 0.0)) {
    if (msg) snprintf(msg, msg_size, "trajectory.segments: gravity must be > 0 for coordinated turns");
    st = NAV_ERR_INVALID_ARG;
    goto cleanup;
  }
  st = plan(scene, m, NULL, msg, msg_size);
  if (st != NAV_OK) goto cleanup;

  /* Breakpoints: every ramp start and end, the boundaries, and the end of the range that needs
   * positions (the longer of the script and the scene duration, plus a margin). */
  size_t nb = 3 + (size_t)m->n_seg + 1;
  for (int c = 0; c < CH_N; ++c)
    nb += 2 * m->ch[c].n;
  m->breaks = malloc(nb * sizeof *m->breaks);
  if (!m->breaks) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  size_t n = 0;
  m->breaks[n++] = 0.0;
  m->breaks[n++] = m->end_s;
  const double t_last =
      fmax(m->end_s, isfinite(scene->trajectory.duration_s) ? scene->trajectory.duration_s : 0.0) + 1.0;
  m->breaks[n++] = t_last;
  for (int i = 0; i <= m->n_seg; ++i)
    m->breaks[n++] = m->bounds[i];
  for (int c = 0; c < CH_N; ++c)
    for (size_t i = 0; i < m->ch[c].n; ++i) {
      m->breaks[n++] = m->ch[c].steps[i].t0_s;
      m->breaks[n++] = m->ch[c].steps[i].t0_s + m->ch[c].steps[i].len_s;
    }
  m->n_breaks = nav_kin_sort_unique(m->breaks, n);
  {
    /* The path needs the sorted breaks from 0 to t_last. */
    size_t first = 0, count = 0;
    while (first < m->n_breaks && m->breaks[first] < 0.0)
      ++first;
    while (first + count < m->n_breaks && m->breaks[first + count] <= t_last)
      ++count;
    st = nav_kin_path_build(&m->path, m->breaks + first, count, scene->trajectory.segments.r0_ned_m,
                            seg_velocity, seg_step, m, msg, msg_size);
    if (st != NAV_OK) goto cleanup;
  }
  memset(out, 0, sizeof *out);
  out->name = "segments";
  out->duration_s = m->end_s;
  out->self = m;
  out->eval_local = seg_eval;
  out->eval_local_nopos = seg_eval_nopos;
  out->destroy = seg_destroy;
  m = NULL;
cleanup:
  seg_free(m);
  return st;
}

size_t nav_traj_segments_breaks(const void *self, double *out, size_t cap) {
  const seg_model *m = self;
  for (size_t i = 0; i < m->n_breaks && i < cap; ++i)
    out[i] = m->breaks[i];
  return m->n_breaks;
}

size_t nav_traj_segments_boundaries(const void *self, double *out, size_t cap) {
  const seg_model *m = self;
  for (size_t i = 0; i <= (size_t)m->n_seg && i < cap; ++i)
    out[i] = m->bounds[i];
  return (size_t)m->n_seg + 1;
}
