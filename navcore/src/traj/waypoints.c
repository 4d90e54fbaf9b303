/*
 * Waypoint trajectories: straight legs joined by planar fly-by turns, with a speed profile.
 *
 * Path. At an interior waypoint i the direction changes from u_(i-1) to u_i by the angle beta_i.
 * The turn rotates the unit tangent in the plane of the two legs,
 *   T(t) = cos b(t) u_(i-1) + sin b(t) w_i,   w_i = unit(u_i - (u_i . u_(i-1)) u_(i-1)),
 * where b(t) is a rest-to-rest move of the turn angle (traj_kin_internal.h): the turn rate b'
 * rises by a septic smoothstep, may cruise, and falls again. Flown at constant speed V, the
 * curvature b'/V therefore blends in like a clothoid whose curvature is itself smooth: curvature
 * C3 in arc length, position C4, so the body rate is C3 and the angular acceleration continuous.
 * The profile is symmetric, so the turn starts and ends at the same distance L_t from the
 * corner (along the legs):  L_t = |V int (cos b, sin b) dt| / (2 cos(beta / 2)). The path does
 * not pass through interior waypoints (fly-by); its closest approach is on the bisector, at the
 * middle of the turn, which is when the vehicle "passes" the waypoint.
 *
 * Turn limits at speed V (the turn rate is b'):
 *   b' <= min(max_rate, max_lateral_accel / V, sqrt(max_jerk / (sqrt2 V)))
 *   b'' <= min(max_ang_accel, max_jerk / (sqrt2 V)),  b''' <= max_ang_jerk
 * (the path jerk in a turn is V sqrt(b''^2 + b'^4) <= max_jerk). The aircraft attitude mode also
 * bounds the bank dynamics roll' ~ (V/g) b'' and roll'' ~ (V/g) b''': b'' <= max_rate g / V,
 * b''' <= max_ang_accel g / V.
 *
 * Speed. Turns are flown at the waypoint's speed; speed changes are rest-to-rest moves of the
 * speed (trapezoidal acceleration <= max_accel, jerk <= max_jerk) on the straight parts:
 * accelerations right after a turn, decelerations right before the next one. With timing
 * "time", interior waypoint speeds are the mean of the adjacent legs' average speeds and each
 * straight part gets a cruise speed solved so that the vehicle passes every waypoint (mid-turn)
 * at its time. With timing "speed", a straight part between two stops (speed 0 at both ends)
 * rises to the section's cruise_mps, cruises and stops again; a part too short for that reaches
 * the highest speed its length allows (the peak speed solved by bisection).
 *
 * Stops. An interior waypoint with hold_s > 0 is a stop: the speed falls to 0 on the straight
 * part before it (a rest-to-rest move ends at rest with its rate and acceleration 0), the
 * vehicle stays there hold_s, and the speed rises again on the straight part after it; the two
 * legs are planned as if the stop were the end of one trajectory and the start of another. No
 * fly-by turn: where the path turns at a stop, the tangent turns at rest by the same rest-to-rest
 * move of the turn angle as a fly-by turn (in the plane of the two legs; a reversal about the
 * vertical, to the right), bounded by max_rate_rps, max_ang_accel_rps2 and max_ang_jerk_rps3
 * only (no speed, so no lateral acceleration or jerk) and centred in the hold, which must be
 * long enough for it. The velocity is 0 throughout, so position and velocity stay exact, and
 * the attitude (from the tangent) and its rates are as smooth as in a fly-by turn.
 *
 * Attitude: ground (heading and pitch of the tangent, roll 0), aircraft (the same plus the
 * coordinated bank atan(V psi_dot / g)), fixed, or per-waypoint Euler angles interpolated
 * between the waypoint times by single rate pulses (septic ramps up and down over half the
 * interval each; yaw and roll take the shorter way). Derivatives come from jets.
 *
 * Infeasible input (fewer than 2 or coincident waypoints, a reversal, a turn at zero speed, legs
 * too short for the turns or the speed changes, arrival times that cannot be met, attitude
 * changes beyond the limits) is an error naming the waypoint and the limit.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "traj/traj_kin_internal.h"

#define RAD2DEG NAV_RAD2DEG
#define MAX_ELEVATION_RAD (80.0 * NAV_DEG2RAD)
#define SQRT2 1.41421356237309504880

typedef enum { P_HOLD, P_STRAIGHT, P_TURN } piece_kind;

typedef struct wp_piece {
  piece_kind kind;
  double t0;
  nav_vec3 u, w; /* tangent (hold/straight) or entry tangent and in-plane normal (turn) */
  double b0;     /* turn channel value at t0 */
} wp_piece;

typedef struct wp_model {
  wp_piece *pieces;
  size_t n_pieces, cap_pieces;
  nav_kin_channel speed;  /* x = speed, rate = path acceleration, integral = distance */
  nav_kin_channel turn;   /* cumulative turn angle */
  nav_kin_channel eul[3]; /* euler mode: roll, pitch, yaw */
  nav_kin_path path;
  nav_wp_attitude_mode mode;
  nav_euler fixed;
  double g_mps2;
  double end_s;
  double *wp_time;
  int n_wp;
  double *breaks;
  size_t n_breaks;
  /* Cached indices of the node evaluation (speed only): piece, speed, turn, Euler channels. */
  size_t piece_hint;
  ptrdiff_t ch_hint[5];
} wp_model;

typedef struct wplan {
  const nav_traj_waypoints *W;
  int *bad;
  char *msg;
  size_t msg_size;
} wplan;

static nav_status fail(wplan *pl, int index, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static nav_status fail(wplan *pl, int index, const char *fmt, ...) {
  if (pl->bad) *pl->bad = index;
  if (pl->msg && pl->msg_size) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(pl->msg, pl->msg_size, fmt, ap);
    va_end(ap);
  }
  return NAV_ERR_INVALID_ARG;
}

static void wp_free(wp_model *m) {
  if (!m) return;
  free(m->pieces);
  nav_kin_channel_free(&m->speed);
  nav_kin_channel_free(&m->turn);
  for (int i = 0; i < 3; ++i)
    nav_kin_channel_free(&m->eul[i]);
  nav_kin_path_free(&m->path);
  free(m->wp_time);
  free(m->breaks);
  free(m);
}

static nav_status add_piece(wp_model *m, piece_kind kind, double t0, nav_vec3 u, nav_vec3 w, double b0) {
  if (m->n_pieces == m->cap_pieces) {
    const size_t cap = m->cap_pieces ? 2 * m->cap_pieces : 16;
    wp_piece *p = realloc(m->pieces, cap * sizeof *p);
    if (!p) return NAV_ERR_NO_MEMORY;
    m->pieces = p;
    m->cap_pieces = cap;
  }
  wp_piece *p = &m->pieces[m->n_pieces++];
  p->kind = kind;
  p->t0 = t0;
  p->u = u;
  p->w = w;
  p->b0 = b0;
  return NAV_OK;
}

/* Speed profile of a straight part: v_a -> c (move), cruise at c, c -> v_b (move). */
typedef struct straight_plan {
  nav_kin_move m1, m2;
  double cruise_s, dist_m, time_s;
  bool feasible;
  bool two_moves; /* m1, cruise, m2 (else timing speed: m1 only, before or after the cruise) */
} straight_plan;

static straight_plan straight_with_cruise(double va, double c, double vb, double s_len,
                                          const nav_kin_lim *lin) {
  straight_plan sp;
  sp.m1 = nav_kin_plan_move(c - va, lin);
  sp.m2 = nav_kin_plan_move(vb - c, lin);
  const double t1 = nav_kin_move_duration(&sp.m1), t2 = nav_kin_move_duration(&sp.m2);
  /* A symmetric speed move covers (v_start + v_end) / 2 x its duration. */
  sp.dist_m = 0.5 * (va + c) * t1 + 0.5 * (c + vb) * t2;
  const double rest = s_len - sp.dist_m;
  sp.feasible = rest >= -1e-9 * (1.0 + s_len) && c > 0.0;
  sp.cruise_s = rest > 0.0 && c > 0.0 ? rest / c : 0.0;
  sp.time_s = t1 + t2 + sp.cruise_s;
  sp.two_moves = true;
  return sp;
}

typedef struct turn_plan {
  bool in_place; /* at a stop (hold_s > 0): turned at rest during the hold, no fly-by */
  double beta, V, tan_len_m, radius_m, rate_cap;
  const char *cap_name;
  nav_kin_move mv;
  nav_vec3 w;
} turn_plan;

static nav_status plan(const nav_scene *scene, wp_model *m, int *bad, char *msg, size_t msg_size) {
  const nav_traj_waypoints *W = &scene->trajectory.waypoints;
  const nav_traj_limits *L = &W->limits;
  wplan pl = {W, bad, msg, msg_size};
  nav_vec3 *u = NULL;
  double *len = NULL, *v = NULL, *tt = NULL, *hold = NULL;
  turn_plan *tp = NULL;
  straight_plan *sp = NULL;
  nav_status st = NAV_OK;
  if (bad) *bad = -1;
  const int N = W->count;
  if (N < 2 || N > NAV_MAX_WAYPOINTS)
    return fail(&pl, -1, "trajectory.waypoints: needs 2 to %d waypoints (got %d)", NAV_MAX_WAYPOINTS, N);
  {
    const double lv[6] = {L->max_accel_mps2, L->max_jerk_mps3,      L->max_lateral_accel_mps2,
                          L->max_rate_rps,   L->max_ang_accel_rps2, L->max_ang_jerk_rps3};
    for (int i = 0; i < 6; ++i)
      if (!(lv[i] > 0.0)) return fail(&pl, -1, "trajectory.waypoints.limits: every limit must be > 0");
  }
  if ((int)W->attitude_mode < 0 || (int)W->attitude_mode > (int)NAV_WP_ATT_EULER)
    return fail(&pl, -1, "trajectory.waypoints.attitude_mode: unknown mode %d", (int)W->attitude_mode);
  if (W->timing != NAV_WP_TIMING_SPEED && W->timing != NAV_WP_TIMING_TIME)
    return fail(&pl, -1, "trajectory.waypoints.timing: unknown timing %d", (int)W->timing);
  if (!(W->hold_start_s >= 0.0) || !(W->hold_end_s >= 0.0) || !isfinite(W->hold_start_s) ||
      !isfinite(W->hold_end_s))
    return fail(&pl, -1, "trajectory.waypoints: hold_start_s and hold_end_s must be finite and >= 0");
  const bool tangent_att = W->attitude_mode == NAV_WP_ATT_GROUND || W->attitude_mode == NAV_WP_ATT_AIRCRAFT;
  const bool aircraft = W->attitude_mode == NAV_WP_ATT_AIRCRAFT;
  const nav_kin_lim lin = {L->max_accel_mps2, L->max_jerk_mps3, INFINITY};

  u = calloc((size_t)N, sizeof *u);
  len = calloc((size_t)N, sizeof *len);
  v = calloc((size_t)N, sizeof *v);
  tt = calloc((size_t)N, sizeof *tt);
  hold = calloc((size_t)N, sizeof *hold);
  tp = calloc((size_t)N, sizeof *tp);
  sp = calloc((size_t)N, sizeof *sp);
  m->wp_time = calloc((size_t)N, sizeof *m->wp_time);
  if (!u || !len || !v || !tt || !hold || !tp || !sp || !m->wp_time) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  m->n_wp = N;
  for (int i = 0; i < N; ++i) {
    const nav_waypoint *p = &W->points[i];
    if (!nav_vec3_isfinite(p->r_ned_m) || !isfinite(p->speed_mps) || !isfinite(p->time_s) ||
        !isfinite(p->attitude.roll_rad) || !isfinite(p->attitude.pitch_rad) ||
        !isfinite(p->attitude.yaw_rad) || !isfinite(p->hold_s)) {
      st = fail(&pl, i, "waypoint %d: a field is not a finite number", i);
      goto cleanup;
    }
    if (!(p->hold_s >= 0.0)) {
      st = fail(&pl, i, "waypoint %d: hold_s must be >= 0 (got %g)", i, p->hold_s);
      goto cleanup;
    }
    if (p->hold_s > 0.0 && (i == 0 || i == N - 1)) {
      st = fail(&pl, i, "waypoint %d: hold_s is for interior waypoints; use trajectory.waypoints.%s", i,
                i == 0 ? "hold_start_s" : "hold_end_s");
      goto cleanup;
    }
    hold[i] = p->hold_s;
  }
  /* Legs. */
  for (int i = 0; i + 1 < N; ++i) {
    const nav_vec3 d = nav_vec3_sub(W->points[i + 1].r_ned_m, W->points[i].r_ned_m);
    len[i] = nav_vec3_norm(d);
    if (!(len[i] > 1e-6)) {
      st = fail(&pl, i + 1, "waypoint %d coincides with waypoint %d (%.3g m apart; at least 1e-6 m needed)",
                i + 1, i, len[i]);
      goto cleanup;
    }
    u[i] = nav_vec3_scale(d, 1.0 / len[i]);
    const double elev = atan2(-u[i].z, hypot(u[i].x, u[i].y));
    if (tangent_att && fabs(elev) > MAX_ELEVATION_RAD) {
      st = fail(&pl, i + 1,
                "waypoint %d: leg %d-%d climbs at %.4g deg; the heading of the %s attitude mode is undefined "
                "beyond "
                "80 deg",
                i + 1, i, i + 1, elev * RAD2DEG, aircraft ? "aircraft" : "ground");
      goto cleanup;
    }
  }
  /* Speeds (and times). */
  for (int i = 0; i < N; ++i)
    v[i] = W->points[i].speed_mps;
  if (W->timing == NAV_WP_TIMING_TIME) {
    for (int i = 0; i < N; ++i)
      tt[i] = W->points[i].time_s;
    if (tt[0] != 0.0) {
      st = fail(&pl, 0, "waypoint 0: time_s must be 0 (times count from the start of the motion; got %g s)",
                tt[0]);
      goto cleanup;
    }
    for (int i = 1; i < N; ++i)
      if (!(tt[i] > tt[i - 1])) {
        st = fail(&pl, i, "waypoint %d: time_s %g s is not after waypoint %d's %g s", i, tt[i], i - 1,
                  tt[i - 1]);
        goto cleanup;
      }
    for (int i = 1; i + 1 < N; ++i)
      v[i] = hold[i] > 0.0 ? 0.0 : 0.5 * (len[i - 1] / (tt[i] - tt[i - 1]) + len[i] / (tt[i + 1] - tt[i]));
  }
  for (int i = 0; i < N; ++i)
    if (!(v[i] >= 0.0)) {
      st = fail(&pl, i, "waypoint %d: speed_mps must be >= 0 (got %g)", i, v[i]);
      goto cleanup;
    }
  for (int i = 1; i + 1 < N; ++i)
    if (hold[i] > 0.0 && v[i] != 0.0) {
      st = fail(&pl, i, "waypoint %d: hold_s %g s needs speed 0 at the waypoint (speed_mps is %g)", i,
                hold[i], v[i]);
      goto cleanup;
    }
  if (W->hold_start_s > 0.0 && v[0] != 0.0) {
    st = fail(&pl, 0, "waypoint 0: hold_start_s %g s needs speed 0 at the first waypoint (speed_mps is %g)",
              W->hold_start_s, v[0]);
    goto cleanup;
  }
  if (W->hold_end_s > 0.0 && v[N - 1] != 0.0) {
    st = fail(&pl, N - 1, "waypoint %d: hold_end_s %g s needs speed 0 at the last waypoint (speed_mps is %g)",
              N - 1, W->hold_end_s, v[N - 1]);
    goto cleanup;
  }
  /* Turns. */
  for (int i = 1; i + 1 < N; ++i) {
    turn_plan *t = &tp[i];
    const double c = nav_vec3_dot(u[i - 1], u[i]);
    const double s = nav_vec3_norm(nav_vec3_cross(u[i - 1], u[i]));
    t->beta = atan2(s, c);
    if (!(t->beta > 1e-9)) {
      t->beta = 0.0;
      continue;
    }
    if (t->beta > NAV_PI - 1e-6 && !(hold[i] > 0.0)) {
      st = fail(&pl, i, "waypoint %d: the path reverses direction (turn of %.6g deg); a fly-by turn cannot",
                i, t->beta * RAD2DEG);
      goto cleanup;
    }
    if (hold[i] > 0.0) {
      /* A stop: the tangent turns at rest, in the plane of the two legs (about the vertical for
         a reversal, to the right), as a rest-to-rest move of the turn angle within the angular
         limits, centred in the hold. */
      t->in_place = true;
      if (s > 1e-9) {
        t->w = nav_vec3_scale(nav_vec3_axpy(u[i], -c, u[i - 1]), 1.0 / s);
      } else {
        const double h = hypot(u[i - 1].x, u[i - 1].y);
        t->w = h > 1e-9 ? nav_vec3_make(-u[i - 1].y / h, u[i - 1].x / h, 0.0) : nav_vec3_make(1.0, 0.0, 0.0);
      }
      const nav_kin_lim lim = {L->max_rate_rps, L->max_ang_accel_rps2, L->max_ang_jerk_rps3};
      t->mv = nav_kin_plan_move(t->beta, &lim);
      const double d = nav_kin_move_duration(&t->mv);
      if (d > hold[i]) {
        st = fail(&pl, i,
                  "waypoint %d: turning %.4g deg in place takes %.4g s within max_rate_rps %g, "
                  "max_ang_accel_rps2 %g and max_ang_jerk_rps3 %g, longer than hold_s %g s",
                  i, t->beta * RAD2DEG, d, L->max_rate_rps, L->max_ang_accel_rps2, L->max_ang_jerk_rps3,
                  hold[i]);
        goto cleanup;
      }
      continue;
    }
    t->w = nav_vec3_scale(nav_vec3_axpy(u[i], -c, u[i - 1]), 1.0 / s);
    const double V = v[i];
    t->V = V;
    if (!(V > 0.0)) {
      st = fail(&pl, i, "waypoint %d: a turn of %.4g deg needs speed > 0 (speed_mps is %g)", i,
                t->beta * RAD2DEG, V);
      goto cleanup;
    }
    nav_kin_lim lim = {L->max_rate_rps, L->max_ang_accel_rps2, L->max_ang_jerk_rps3};
    t->cap_name = "max_rate_rps";
    if (L->max_lateral_accel_mps2 / V < lim.r_max) {
      lim.r_max = L->max_lateral_accel_mps2 / V;
      t->cap_name = "max_lateral_accel_mps2";
    }
    if (sqrt(L->max_jerk_mps3 / (SQRT2 * V)) < lim.r_max) {
      lim.r_max = sqrt(L->max_jerk_mps3 / (SQRT2 * V));
      t->cap_name = "max_jerk_mps3";
    }
    lim.d1_max = fmin(lim.d1_max, L->max_jerk_mps3 / (SQRT2 * V));
    if (aircraft) {
      lim.d1_max = fmin(lim.d1_max, L->max_rate_rps * m->g_mps2 / V);
      lim.d2_max = fmin(lim.d2_max, L->max_ang_accel_rps2 * m->g_mps2 / V);
    }
    t->rate_cap = lim.r_max;
    t->mv = nav_kin_plan_move(t->beta, &lim);
    double ic, is;
    nav_kin_move_cos_sin_integral(&t->mv, &ic, &is);
    t->tan_len_m = V * hypot(ic, is) / (2.0 * cos(0.5 * t->beta));
    t->radius_m = V / fabs(t->mv.p);
  }
  /* Straight parts. */
  for (int i = 0; i + 1 < N; ++i) {
    const double s_len = len[i] - tp[i].tan_len_m - tp[i + 1].tan_len_m;
    if (s_len < -1e-9 * (1.0 + len[i])) {
      const int j = tp[i].tan_len_m >= tp[i + 1].tan_len_m ? i : i + 1;
      const turn_plan *t = &tp[j];
      st = fail(&pl, j,
                "waypoint %d: turn of %.4g deg at %.4g m/s needs radius %.4g m (turn rate %.4g deg/s, "
                "limited by %s) "
                "and %.4g m of leg on each side, but leg %d-%d is only %.4g m long%s",
                j, t->beta * RAD2DEG, t->V, t->radius_m, fabs(t->mv.p) * RAD2DEG, t->cap_name, t->tan_len_m,
                i, i + 1, len[i],
                tp[i].tan_len_m > 0.0 && tp[i + 1].tan_len_m > 0.0 ? " and shared with the neighbouring turn"
                                                                   : "");
      goto cleanup;
    }
    const double s_use = s_len > 0.0 ? s_len : 0.0;
    straight_plan *q = &sp[i];
    if (W->timing == NAV_WP_TIMING_SPEED) {
      const double va = v[i], vb = v[i + 1];
      if (va == 0.0 && vb == 0.0 && s_use > 0.0) {
        /* Between two stops: up to cruise_mps; a shorter part peaks at the speed whose rise and
           fall just fill it (the distance of the two moves grows with the peak speed). */
        if (!(W->cruise_mps > 0.0)) {
          st = fail(&pl, i + 1,
                    "waypoint %d: the speed is 0 at both ends of leg %d-%d; set trajectory.waypoints.cruise_mps "
                    "(the speed between stops), give one end a speed > 0 or use timing time",
                    i + 1, i, i + 1);
          goto cleanup;
        }
        *q = straight_with_cruise(0.0, W->cruise_mps, 0.0, s_use, &lin);
        if (!q->feasible) {
          double lo = 0.0, hi = W->cruise_mps;
          for (int it = 0; it < 200 && hi - lo > 1e-13 * hi; ++it) {
            const double mid = 0.5 * (lo + hi);
            if (straight_with_cruise(0.0, mid, 0.0, s_use, &lin).dist_m <= s_use) /* no overshoot */
              lo = mid;
            else
              hi = mid;
          }
          *q = straight_with_cruise(0.0, lo, 0.0, s_use, &lin);
        }
        if (!q->feasible) {
          st = fail(&pl, i + 1, "waypoint %d: leg %d-%d between two stops is too short to move (%.4g m)", i + 1,
                    i, i + 1, s_use);
          goto cleanup;
        }
        continue;
      }
      q->m1 = nav_kin_plan_move(vb - va, &lin);
      q->m2 = nav_kin_plan_move(0.0, &lin);
      q->two_moves = false;
      const double t1 = nav_kin_move_duration(&q->m1);
      q->dist_m = 0.5 * (va + vb) * t1;
      if (q->dist_m > s_use + 1e-9 * (1.0 + len[i])) {
        st = fail(&pl, i + 1,
                  "waypoint %d: the speed change from %g to %g m/s needs %.4g m (max_accel_mps2 %g, "
                  "max_jerk_mps3 %g) "
                  "but only %.4g m of leg %d-%d remain between the turns",
                  i + 1, va, vb, q->dist_m, L->max_accel_mps2, L->max_jerk_mps3, s_use, i, i + 1);
        goto cleanup;
      }
      const double rest = s_use - q->dist_m > 0.0 ? s_use - q->dist_m : 0.0;
      const double vc = vb > va ? vb : va; /* cruise at the higher speed */
      q->cruise_s = vc > 0.0 ? rest / vc : 0.0;
      q->time_s = t1 + q->cruise_s;
      q->feasible = true;
    } else {
      /* A stop's hold (and its turn in place) comes before the leg: time_s is its arrival. */
      const double target = tt[i + 1] - tt[i] - hold[i] -
                            (tp[i].in_place ? 0.0 : 0.5 * nav_kin_move_duration(&tp[i].mv)) -
                            (tp[i + 1].in_place ? 0.0 : 0.5 * nav_kin_move_duration(&tp[i + 1].mv));
      const double va = v[i], vb = v[i + 1];
      /* Cruise speed c: the time decreases as c rises while the ramps fit. Scan, then bisect. */
      const double c_lo = 1e-2, c_hi = fmax(va, vb) + sqrt(L->max_accel_mps2 * s_use) +
                                       2.0 * s_use / fmax(target, 1e-3) + 1.0;
      const int n_scan = 600;
      double best = INFINITY, c_prev = 0.0, f_prev = NAN;
      bool found = false;
      for (int k = 0; k <= n_scan && !found; ++k) {
        const double c = c_lo * pow(c_hi / c_lo, (double)k / n_scan);
        const straight_plan x = straight_with_cruise(va, c, vb, s_use, &lin);
        if (!x.feasible) {
          f_prev = NAN;
          continue;
        }
        if (x.time_s < best) best = x.time_s;
        const double f = x.time_s - target;
        if (f == 0.0) {
          *q = x;
          found = true;
        } else if (isfinite(f_prev) && f_prev > 0.0 && f < 0.0) {
          double a = c_prev, b = c;
          for (int it = 0; it < 200 && b - a > 1e-15 * b; ++it) {
            const double mid = 0.5 * (a + b);
            const straight_plan y = straight_with_cruise(va, mid, vb, s_use, &lin);
            if (y.feasible && y.time_s > target)
              a = mid;
            else
              b = mid;
          }
          *q = straight_with_cruise(va, a, vb, s_use, &lin);
          if (!q->feasible) *q = straight_with_cruise(va, b, vb, s_use, &lin);
          found = q->feasible;
        }
        c_prev = c;
        f_prev = f;
      }
      if (!found && !isfinite(best)) {
        st = fail(&pl, i + 1,
                  "waypoint %d: time_s %g s cannot be met: the %.4g m of leg %d-%d between the turns are too "
                  "short to "
                  "change speed from %.4g to %.4g m/s within max_accel_mps2 %g and max_jerk_mps3 %g",
                  i + 1, tt[i + 1], s_use, i, i + 1, va, vb, L->max_accel_mps2, L->max_jerk_mps3);
        goto cleanup;
      }
      if (!found) {
        const double t_turns = (tp[i].in_place ? 0.0 : 0.5 * nav_kin_move_duration(&tp[i].mv)) +
                               (tp[i + 1].in_place ? 0.0 : 0.5 * nav_kin_move_duration(&tp[i + 1].mv));
        st = fail(&pl, i + 1,
                  "waypoint %d: time_s %g s cannot be met: leg %d-%d takes at least %.4g s within "
                  "max_accel_mps2 %g and "
                  "max_jerk_mps3 %g (the turns at its ends take %.4g s of it)",
                  i + 1, tt[i + 1], i, i + 1, best + t_turns, L->max_accel_mps2, L->max_jerk_mps3, t_turns);
        goto cleanup;
      }
    }
  }
  /* Timeline. */
  nav_kin_channel_init(&m->speed, v[0], 0.0);
  nav_kin_channel_init(&m->turn, 0.0, 0.0);
  double t = 0.0;
  const nav_vec3 z = nav_vec3_zero();
  if (W->hold_start_s > 0.0) {
    st = add_piece(m, P_HOLD, 0.0, u[0], z, 0.0);
    if (st != NAV_OK) goto cleanup;
    t = W->hold_start_s;
  }
  m->wp_time[0] = t;
  for (int i = 0; i + 1 < N && st == NAV_OK; ++i) {
    const straight_plan *q = &sp[i];
    st = add_piece(m, P_STRAIGHT, t, u[i], z, 0.0);
    if (st != NAV_OK) break;
    if (!q->two_moves) {
      if (v[i + 1] >= v[i]) {
        st = nav_kin_channel_add_move(&m->speed, t, &q->m1);
      } else {
        st = nav_kin_channel_add_move(&m->speed, t + q->cruise_s, &q->m1);
      }
    } else {
      st = nav_kin_channel_add_move(&m->speed, t, &q->m1);
      if (st == NAV_OK)
        st = nav_kin_channel_add_move(&m->speed, t + nav_kin_move_duration(&q->m1) + q->cruise_s, &q->m2);
    }
    t += q->time_s;
    if (st != NAV_OK) break;
    if (i + 2 < N && hold[i + 1] > 0.0) {
      /* A stop: at rest for hold_s, arriving at t; a turn in place centred in the hold. */
      const turn_plan *tq = &tp[i + 1];
      m->wp_time[i + 1] = t;
      const double d = tq->beta > 0.0 ? nav_kin_move_duration(&tq->mv) : 0.0;
      const double t_turn = t + 0.5 * (hold[i + 1] - d);
      if (!(tq->beta > 0.0) || t_turn > t) st = add_piece(m, P_HOLD, t, u[i], z, 0.0);
      if (st == NAV_OK && tq->beta > 0.0) {
        const double b0 = nav_kin_channel_eval(&m->turn, t_turn).d[0];
        st = add_piece(m, P_TURN, t_turn, u[i], tq->w, b0);
        if (st == NAV_OK) st = nav_kin_channel_add_move(&m->turn, t_turn, &tq->mv);
      }
      t += hold[i + 1];
    } else if (i + 2 < N && tp[i + 1].beta > 0.0) {
      const double b0 = nav_kin_channel_eval(&m->turn, t).d[0];
      st = add_piece(m, P_TURN, t, u[i], tp[i + 1].w, b0);
      if (st == NAV_OK) st = nav_kin_channel_add_move(&m->turn, t, &tp[i + 1].mv);
      m->wp_time[i + 1] = t + 0.5 * nav_kin_move_duration(&tp[i + 1].mv);
      t += nav_kin_move_duration(&tp[i + 1].mv);
    } else {
      m->wp_time[i + 1] = t;
    }
  }
  if (st != NAV_OK) goto cleanup;
  if (W->hold_end_s > 0.0) {
    st = add_piece(m, P_HOLD, t, u[N - 2], z, 0.0);
    if (st != NAV_OK) goto cleanup;
    t += W->hold_end_s;
  }
  m->end_s = t;
  /* Attitude channels of the euler mode. */
  if (W->attitude_mode == NAV_WP_ATT_EULER) {
    const nav_euler e0 = W->points[0].attitude;
    nav_kin_channel_init(&m->eul[0], e0.roll_rad, 0.0);
    nav_kin_channel_init(&m->eul[1], e0.pitch_rad, 0.0);
    nav_kin_channel_init(&m->eul[2], e0.yaw_rad, 0.0);
    static const char *const names[3] = {"roll", "pitch", "yaw"};
    for (int i = 0; i + 1 < N && st == NAV_OK; ++i) {
      const nav_euler a = W->points[i].attitude, b = W->points[i + 1].attitude;
      const double d[3] = {remainder(b.roll_rad - a.roll_rad, NAV_TWO_PI), b.pitch_rad - a.pitch_rad,
                           remainder(b.yaw_rad - a.yaw_rad, NAV_TWO_PI)};
      /* From the departure: a stop holds its attitude. */
      const double t_dep = m->wp_time[i] + (i > 0 ? hold[i] : 0.0);
      const double D = m->wp_time[i + 1] - t_dep, h = 0.5 * D;
      for (int c = 0; c < 3 && st == NAV_OK; ++c) {
        if (d[c] == 0.0) continue;
        const nav_kin_move mv = {d[c], d[c] / h, h, 0.0};
        const double rate = fabs(mv.p), acc = rate * NAV_KIN_S1_MAX / h,
                     jerk = rate * NAV_KIN_S2_MAX / (h * h);
        /* The peaks of a single rate pulse: rate, its derivative and second derivative. */
        static const char *const lnames[3] = {"max_rate_rps", "max_ang_accel_rps2", "max_ang_jerk_rps3"};
        const double need[3] = {rate, acc, jerk};
        const double lim[3] = {L->max_rate_rps, L->max_ang_accel_rps2, L->max_ang_jerk_rps3};
        int over = -1;
        for (int q = 2; q >= 0; --q)
          if (need[q] > lim[q]) over = q;
        if (over >= 0) {
          st = fail(&pl, i + 1,
                    "waypoint %d: the %s change of %.4g deg from waypoint %d in %.4g s needs %s %.4g but the "
                    "limit is %g",
                    i + 1, names[c], d[c] * RAD2DEG, i, D, lnames[over], need[over], lim[over]);
          break;
        }
        st = nav_kin_channel_add_move(&m->eul[c], t_dep, &mv);
      }
    }
    if (st != NAV_OK) goto cleanup;
  }
cleanup:
  free(u);
  free(len);
  free(v);
  free(tt);
  free(hold);
  free(tp);
  free(sp);
  return st;
}

/* ---------------------------------------------------------------- evaluation */

static const wp_piece *find_piece(const wp_model *m, double t) {
  size_t lo = 0, hi = m->n_pieces;
  if (t < m->pieces[0].t0) return &m->pieces[0];
  while (hi - lo > 1) {
    const size_t mid = lo + (hi - lo) / 2;
    if (m->pieces[mid].t0 <= t)
      lo = mid;
    else
      hi = mid;
  }
  return &m->pieces[lo];
}

/* Unit tangent as jets (order 3). */
static void tangent(const wp_model *m, const wp_piece *p, double t, nav_jet T[3]) {
  if (p->kind != P_TURN) {
    T[0] = nav_jet_const(p->u.x);
    T[1] = nav_jet_const(p->u.y);
    T[2] = nav_jet_const(p->u.z);
    return;
  }
  const nav_jet b = nav_jet_sub(nav_kin_channel_eval(&m->turn, t), nav_jet_const(p->b0));
  const nav_jet cb = nav_jet_cos(b), sb = nav_jet_sin(b);
  T[0] = nav_jet_add(nav_jet_scale(cb, p->u.x), nav_jet_scale(sb, p->w.x));
  T[1] = nav_jet_add(nav_jet_scale(cb, p->u.y), nav_jet_scale(sb, p->w.y));
  T[2] = nav_jet_add(nav_jet_scale(cb, p->u.z), nav_jet_scale(sb, p->w.z));
}

static nav_vec3 wp_velocity(void *self, double t) {
  const wp_model *m = self;
  const wp_piece *p = find_piece(m, t);
  const double V = nav_kin_channel_eval(&m->speed, t).d[0];
  if (p->kind != P_TURN) return nav_vec3_scale(p->u, V);
  const double b = nav_kin_channel_eval(&m->turn, t).d[0] - p->b0;
  return nav_vec3_scale(nav_vec3_add(nav_vec3_scale(p->u, cos(b)), nav_vec3_scale(p->w, sin(b))), V);
}

static double wp_step(void *self, double ta, double tb) {
  const wp_model *m = self;
  const double ts[3] = {ta, 0.5 * (ta + tb), tb};
  double w = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double r = fabs(nav_kin_channel_eval(&m->turn, ts[i]).d[1]);
    if (r > w) w = r;
  }
  if (w == 0.0) return INFINITY;
  return w > 1.0 ? 0.5 / w : 0.5;
}

static nav_status wp_kin(void *self, double t_s, nav_local_kin *out, bool with_pos) {
  const wp_model *m = self;
  const wp_piece *p = find_piece(m, t_s);
  nav_jet T[3];
  tangent(m, p, t_s, T);
  const nav_jet V = nav_jet_deriv(nav_kin_channel_eval_integral(&m->speed, t_s)); /* V, V', V'' */
  nav_local_kin k;
  nav_jet vel[3];
  for (int i = 0; i < 3; ++i)
    vel[i] = nav_jet_mul(V, T[i]);
  k.v_ned_mps = nav_vec3_make(vel[0].d[0], vel[1].d[0], vel[2].d[0]);
  k.a_ned_mps2 = nav_vec3_make(vel[0].d[1], vel[1].d[1], vel[2].d[1]);
  nav_jet roll = nav_jet_const(0.0), pitch, yaw;
  switch (m->mode) {
  case NAV_WP_ATT_GROUND:
  case NAV_WP_ATT_AIRCRAFT:
    yaw = nav_jet_atan2(T[1], T[0]);
    pitch = nav_jet_atan2(nav_jet_scale(T[2], -1.0),
                          nav_jet_sqrt(nav_jet_add(nav_jet_mul(T[0], T[0]), nav_jet_mul(T[1], T[1]))));
    if (m->mode == NAV_WP_ATT_AIRCRAFT)
      roll = nav_jet_atan(nav_jet_scale(nav_jet_mul(V, nav_jet_deriv(yaw)), 1.0 / m->g_mps2));
    break;
  case NAV_WP_ATT_EULER:
    roll = nav_kin_channel_eval(&m->eul[0], t_s);
    pitch = nav_kin_channel_eval(&m->eul[1], t_s);
    yaw = nav_kin_channel_eval(&m->eul[2], t_s);
    break;
  case NAV_WP_ATT_FIXED:
  default:
    roll = nav_jet_const(m->fixed.roll_rad);
    pitch = nav_jet_const(m->fixed.pitch_rad);
    yaw = nav_jet_const(m->fixed.yaw_rad);
    break;
  }
  const nav_euler e = {roll.d[0], pitch.d[0], yaw.d[0]};
  k.q_b_n = nav_euler_to_quat(e);
  nav_kin_euler_rates(roll, pitch, yaw, &k.w_nb_b_rps, &k.dw_nb_b_rps2);
  k.r_ned_m = with_pos ? nav_kin_path_eval(&m->path, t_s) : nav_vec3_zero();
  *out = k;
  return NAV_OK;
}

static nav_status wp_eval(void *self, double t_s, nav_local_kin *out) {
  return wp_kin(self, t_s, out, true);
}

static nav_status wp_eval_nopos(void *self, double t_s, nav_local_kin *out) {
  return wp_kin(self, t_s, out, false);
}

/* find_piece through a cached index (the same piece; sequential times rarely search). */
static const wp_piece *find_piece_hint(wp_model *m, double t) {
  const size_t h = m->piece_hint;
  if (h < m->n_pieces && m->pieces[h].t0 <= t && (h + 1 == m->n_pieces || t < m->pieces[h + 1].t0))
    return &m->pieces[h];
  const wp_piece *p = find_piece(m, t);
  m->piece_hint = (size_t)(p - m->pieces);
  return p;
}

/*
 * Ideal-IMU nodes: wp_eval without the position (the caller integrates the velocity) and without
 * the angular acceleration, with the attitude as a DCM. The jets of wp_eval are written out to
 * the orders needed (the unit tangent T to its second derivative only for the aircraft bank), and
 * the sines and cosines of the heading and pitch are the components of T themselves
 * (cos psi = T_N / T_h, sin psi = T_E / T_h, cos theta = T_h / |T|, sin theta = -T_D / |T|,
 * T_h = |(T_N, T_E)|), so a node costs at most one sincos (of the turn angle, by angle addition
 * from the first node within a turn).
 */
nav_status nav_traj_waypoints_nodes(void *self, nav_kin_nodes *io) {
  wp_model *m = self;
  const int n = io->n;
  double V[NAV_KIN_MAX_NODES], V1[NAV_KIN_MAX_NODES], V2[NAV_KIN_MAX_NODES];
  nav_kin_channel_eval_rate_n(&m->speed, io->t_s, n, &m->ch_hint[0], V, V1, V2);
  double sb0 = 0.0, cb0 = 1.0, b0v = 0.0;
  const wp_piece *p0 = NULL;
  for (int i = 0; i < n; ++i) {
    const double t = io->t_s[i];
    const wp_piece *p = find_piece_hint(m, t);
    /* Unit tangent and its derivatives (tangent()). */
    double T[3], T1[3], T2[3];
    if (p->kind != P_TURN) {
      T[0] = p->u.x, T[1] = p->u.y, T[2] = p->u.z;
      T1[0] = T1[1] = T1[2] = T2[0] = T2[1] = T2[2] = 0.0;
    } else {
      double bx, b1, b2;
      nav_kin_channel_eval_rate(&m->turn, t, &m->ch_hint[1], &bx, &b1, &b2);
      const double b = bx - p->b0;
      double sb, cb;
      if (p == p0 && fabs(b - b0v) <= NAV_KIN_NEAR_RAD) {
        nav_kin_sincos_near(sb0, cb0, b - b0v, &sb, &cb);
      } else {
        sb = sin(b);
        cb = cos(b);
        p0 = p;
        sb0 = sb;
        cb0 = cb;
        b0v = b;
      }
      const double u[3] = {p->u.x, p->u.y, p->u.z}, w[3] = {p->w.x, p->w.y, p->w.z};
      for (int a = 0; a < 3; ++a) {
        const double d = -sb * u[a] + cb * w[a]; /* dT/db */
        T[a] = cb * u[a] + sb * w[a];
        T1[a] = b1 * d;
        T2[a] = b2 * d - b1 * b1 * T[a];
      }
    }
    io->v_ned_mps[i] = nav_vec3_make(V[i] * T[0], V[i] * T[1], V[i] * T[2]);
    io->a_ned_mps2[i] =
        nav_vec3_make(V1[i] * T[0] + V[i] * T1[0], V1[i] * T[1] + V[i] * T1[1], V1[i] * T[2] + V[i] * T1[2]);
    /* Euler angles as sin/cos and their rates (roll, pitch, yaw). */
    double sr = 0.0, cr = 1.0, sp, cp, sy, cy, droll = 0.0, dpitch = 0.0, dyaw = 0.0;
    switch (m->mode) {
    case NAV_WP_ATT_GROUND:
    case NAV_WP_ATT_AIRCRAFT: {
      const double h2 = T[0] * T[0] + T[1] * T[1], th = sqrt(h2), tn = sqrt(h2 + T[2] * T[2]);
      cy = T[0] / th;
      sy = T[1] / th;
      cp = th / tn;
      sp = -T[2] / tn;
      const double num = T[0] * T1[1] - T[1] * T1[0];
      dyaw = num / h2;
      const double th1 = (T[0] * T1[0] + T[1] * T1[1]) / th;
      dpitch = (th * -T1[2] + T[2] * th1) / (h2 + T[2] * T[2]);
      if (m->mode == NAV_WP_ATT_AIRCRAFT) {
        /* roll = atan(z), z = V psi' / g; roll' = z' / (1 + z^2). */
        const double num1 = T[0] * T2[1] - T[1] * T2[0];
        const double ddyaw = num1 / h2 - num * 2.0 * (T[0] * T1[0] + T[1] * T1[1]) / (h2 * h2);
        const double gi = 1.0 / m->g_mps2;
        const double z0 = V[i] * dyaw * gi, z1 = (V1[i] * dyaw + V[i] * ddyaw) * gi;
        cr = 1.0 / sqrt(1.0 + z0 * z0);
        sr = z0 * cr;
        droll = cr * cr * z1;
      }
      break;
    }
    case NAV_WP_ATT_EULER: {
      double ang[3], rate[3], r1;
      for (int c = 0; c < 3; ++c)
        nav_kin_channel_eval_rate(&m->eul[c], t, &m->ch_hint[2 + c], &ang[c], &rate[c], &r1);
      sr = sin(ang[0]), cr = cos(ang[0]), sp = sin(ang[1]), cp = cos(ang[1]), sy = sin(ang[2]),
      cy = cos(ang[2]);
      droll = rate[0], dpitch = rate[1], dyaw = rate[2];
      break;
    }
    case NAV_WP_ATT_FIXED:
    default:
      sr = sin(m->fixed.roll_rad), cr = cos(m->fixed.roll_rad);
      sp = sin(m->fixed.pitch_rad), cp = cos(m->fixed.pitch_rad);
      sy = sin(m->fixed.yaw_rad), cy = cos(m->fixed.yaw_rad);
      break;
    }
    /* C_b_n = R_z(yaw) R_y(pitch) R_x(roll) (nav_euler_to_dcm); omega_nb_b by E3.4. */
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
    io->w_nb_b_rps[i] =
        nav_vec3_make(droll - dyaw * sp, dpitch * cr + dyaw * (cp * sr), dyaw * (cp * cr) - dpitch * sr);
  }
  io->has_pos = false;
  return NAV_OK;
}

static void wp_destroy(void *self) {
  wp_free(self);
}

static double gravity_of(const nav_scene *scene) {
  if (scene->earth.model == NAV_EARTH_WGS84)
    return nav_earth_gravity_normal_mps2(scene->earth.origin_lat_rad, scene->earth.origin_h_m);
  return scene->earth.flat_gravity_mps2;
}

nav_status nav_traj_waypoints_plan_info(const nav_scene *scene, nav_traj_script_info *info, int *bad_index,
                                        char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !info) return NAV_ERR_INVALID_ARG;
  wp_model *m = calloc(1, sizeof *m);
  if (!m) return NAV_ERR_NO_MEMORY;
  m->g_mps2 = gravity_of(scene);
  const nav_status st = plan(scene, m, bad_index, msg, msg_size);
  if (st == NAV_OK) {
    info->duration_s = m->end_s;
    info->unconverged = 0;
    info->first_unconverged = -1;
    info->shortened_ramps = 0;
    info->max_ramp_ang_accel_rps2 = 0.0;
  }
  wp_free(m);
  return st;
}

nav_status nav_traj_waypoints_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                     size_t msg_size) {
  (void)dt_s;
  wp_model *m = NULL;
  nav_status st = NAV_OK;
  if (msg && msg_size) msg[0] = '\0';
  m = calloc(1, sizeof *m);
  if (!m) return NAV_ERR_NO_MEMORY;
  m->g_mps2 = gravity_of(scene);
  m->mode = scene->trajectory.waypoints.attitude_mode;
  m->fixed = scene->trajectory.initial_attitude;
  if (!(m->g_mps2 > 0.0)) {
    if (msg) snprintf(msg, msg_size, "trajectory.waypoints: gravity must be > 0");
    st = NAV_ERR_INVALID_ARG;
    goto cleanup;
  }
  st = plan(scene, m, NULL, msg, msg_size);
  if (st != NAV_OK) goto cleanup;
  {
    const double t_last =
        fmax(m->end_s, isfinite(scene->trajectory.duration_s) ? scene->trajectory.duration_s : 0.0) + 1.0;
    size_t nb = 3 + m->n_pieces + 2 * (m->speed.n + m->turn.n + m->eul[0].n + m->eul[1].n + m->eul[2].n);
    m->breaks = malloc(nb * sizeof *m->breaks);
    if (!m->breaks) {
      st = NAV_ERR_NO_MEMORY;
      goto cleanup;
    }
    size_t n = 0;
    m->breaks[n++] = 0.0;
    m->breaks[n++] = m->end_s;
    m->breaks[n++] = t_last;
    for (size_t i = 0; i < m->n_pieces; ++i)
      m->breaks[n++] = m->pieces[i].t0;
    const nav_kin_channel *chs[5] = {&m->speed, &m->turn, &m->eul[0], &m->eul[1], &m->eul[2]};
    for (int c = 0; c < 5; ++c)
      for (size_t i = 0; i < chs[c]->n; ++i) {
        m->breaks[n++] = chs[c]->steps[i].t0_s;
        m->breaks[n++] = chs[c]->steps[i].t0_s + chs[c]->steps[i].len_s;
      }
    m->n_breaks = nav_kin_sort_unique(m->breaks, n);
    size_t count = 0;
    while (count < m->n_breaks && m->breaks[count] <= t_last)
      ++count;
    st = nav_kin_path_build(&m->path, m->breaks, count, scene->trajectory.waypoints.points[0].r_ned_m,
                            wp_velocity, wp_step, m, msg, msg_size);
    if (st != NAV_OK) goto cleanup;
  }
  memset(out, 0, sizeof *out);
  out->name = "waypoints";
  out->duration_s = m->end_s;
  out->self = m;
  out->eval_local = wp_eval;
  out->eval_local_nopos = wp_eval_nopos;
  out->destroy = wp_destroy;
  for (int c = 0; c < 5; ++c)
    m->ch_hint[c] = -1;
  m = NULL;
cleanup:
  wp_free(m);
  return st;
}

size_t nav_traj_waypoints_breaks(const void *self, double *out, size_t cap) {
  const wp_model *m = self;
  for (size_t i = 0; i < m->n_breaks && i < cap; ++i)
    out[i] = m->breaks[i];
  return m->n_breaks;
}

size_t nav_traj_waypoints_times(const void *self, double *out, size_t cap) {
  const wp_model *m = self;
  for (size_t i = 0; i < (size_t)m->n_wp && i < cap; ++i)
    out[i] = m->wp_time[i];
  return (size_t)m->n_wp;
}
