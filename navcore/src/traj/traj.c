/*
 * Trajectory front end: dispatch to the model of the scene and express its state in the
 * scene's reference frame (flat l, or ECEF on WGS-84). See traj_internal.h for the contract.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_truth.h"
#include "traj/traj_kin_internal.h"
#include "nav_clones.h"

#if defined(__GNUC__)
/* Four doubles for GCC's vector extensions: lane-wise IEEE arithmetic, the bits of the scalar
 * operations (AVX2 in the AVX2 clone, two SSE2 halves in the baseline). */
typedef double traj_v4d __attribute__((vector_size(32)));
#endif

/* Positions of the ideal IMU's position chain are re-anchored to the model's own (exact)
 * position every CHAIN_BLOCK samples; see chain_positions. */
#define CHAIN_BLOCK 64
/* Entries of the cache of increments at rest (nav_traj.rep). */
#define REP_WAYS 8

struct nav_traj {
  nav_traj_model m;
  nav_frame frame;
  nav_gravity_model gravity;
  int type_segments; /* the model is a segment script (nav_traj_segment_boundaries) */
  nav_vec3 g_l_mps2; /* flat Earth: uniform gravity in l */
  double dt_s;       /* IMU interval of the create call (sample grid k dt) */
  double inv_m_lat, inv_m_lon; /* 1 / frame.m_per_rad_lat, 1 / frame.m_per_rad_lon (0 if that is 0) */
  /* Node evaluator of the model for the ideal IMU (traj_kin_internal.h), or NULL. */
  nav_status (*nodes)(void *self, nav_kin_nodes *io);
  /* Quadrature rule of the last increment and, for it, A[i][j] = int_{-1}^{x_i} L_j(s) ds (L_j:
   * Lagrange basis of the nodes), which integrates the velocity from t0 to each node. */
  int q_n;
  double q_x[NAV_KIN_MAX_NODES], q_w[NAV_KIN_MAX_NODES];
  double q_A[NAV_KIN_MAX_NODES][NAV_KIN_MAX_NODES];
  double q_At[NAV_KIN_MAX_NODES][NAV_KIN_MAX_NODES]; /* q_At[j][i] = q_A[i][j] (zero beyond n) */
  /* sin and cos of the latitude and longitude of the last WGS-84 state, and of the latitude at the
   * first node of the last increment (reused for the same bits: a vehicle at rest). */
  nav_kin_sincos_cache st_lat_sc, st_lon_sc, nd_lat_sc;
  /* eval_state on WGS-84 from local kinematics: the last input and its state, reused for an input of
   * the same bits (a vehicle at rest). */
  bool es_ok;
  nav_local_kin es_in;
  nav_traj_state es_out;
  /* Position chain: R(chain_j) when chain_ok (a cache of a pure function of j). */
  bool chain_ok;
  int64_t chain_j;
  nav_vec3 chain_r;
  /* Increments of the last intervals whose nodes were a rest entry of the node evaluator
   * (nav_kin_nodes.rest_id; 0: none), with what else they depend on: the rule (q_gen: set_rule's
   * count of rule changes), the half length of the interval and the chain position at its start.
   * An interval with the same of all these has the same node positions, forces and sums. Several
   * entries: the half length (k dt - (k - 1) dt) / 2 takes about 17 neighbouring values. */
  uint64_t q_gen;
  struct {
    uint64_t id, gen;
    double half;
    nav_vec3 r0, dv, dth;
  } rep[REP_WAYS];
  int rep_next;
};

/* ------------------------------------------------------------------ frames */

nav_frame nav_frame_from_scene(const nav_scene *scene) {
  nav_frame f;
  f.model = scene->earth.model;
  f.origin.lat_rad = scene->earth.origin_lat_rad;
  f.origin.lon_rad = scene->earth.origin_lon_rad;
  f.origin.h_m = scene->earth.origin_h_m;
  f.m_per_rad_lat = nav_earth_radius_meridian_m(f.origin.lat_rad) + f.origin.h_m;
  f.m_per_rad_lon = (nav_earth_radius_prime_vertical_m(f.origin.lat_rad) + f.origin.h_m) * cos(f.origin.lat_rad);
  return f;
}

nav_geodetic nav_frame_local_to_geodetic(const nav_frame *fr, nav_vec3 r) {
  if (fr->model == NAV_EARTH_FLAT) return nav_earth_ned_to_geodetic(fr->origin, r);
  nav_geodetic p;
  p.lat_rad = fr->origin.lat_rad + r.x / fr->m_per_rad_lat;
  p.lon_rad = nav_earth_wrap_lon(fr->origin.lon_rad + (fr->m_per_rad_lon != 0.0 ? r.y / fr->m_per_rad_lon : 0.0));
  p.h_m = fr->origin.h_m - r.z;
  return p;
}

nav_vec3 nav_frame_geodetic_to_local(const nav_frame *fr, nav_geodetic p) {
  if (fr->model == NAV_EARTH_FLAT) return nav_earth_geodetic_to_ned(fr->origin, p);
  return nav_vec3_make((p.lat_rad - fr->origin.lat_rad) * fr->m_per_rad_lat,
                       nav_earth_wrap_lon(p.lon_rad - fr->origin.lon_rad) * fr->m_per_rad_lon, fr->origin.h_m - p.h_m);
}

nav_local_view nav_frame_view(const nav_frame *fr, nav_vec3 r_f, nav_vec3 v_f, nav_quat q_b_f) {
  nav_local_view v;
  if (fr->model == NAV_EARTH_FLAT) {
    v.r_ned_m = r_f;
    v.pos = nav_earth_ned_to_geodetic(fr->origin, r_f);
    v.v_n_mps = v_f;
    v.q_b_n = q_b_f;
    v.C_f_n = nav_mat3_identity();
    return v;
  }
  v.pos = nav_earth_ecef_to_geodetic(r_f);
  v.r_ned_m = nav_frame_geodetic_to_local(fr, v.pos);
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(v.pos.lat_rad, v.pos.lon_rad);
  v.C_f_n = nav_mat3_transpose(C_n_e);
  v.v_n_mps = nav_mat3_mul_vec(v.C_f_n, v_f);
  v.q_b_n = nav_quat_mul(nav_quat_conj(nav_quat_from_dcm(C_n_e)), q_b_f);
  return v;
}

/* ------------------------------------------------------------------ WGS-84 embedding */

/*
 * Geodetic kinematics -> ECEF state (numerics.md E3.9; Groves 2nd ed. eqs. 2.111-2.112, 5.44):
 *   v_n = [ (R_M + h) lat', (R_N + h) cos(lat) lon', -h' ]
 *   a_e = C_n_e (v_n' + omega_en_n x v_n),  omega_en_n = [lon' cos lat, -lat', -lon' sin lat]
 *   C_b_e = C_n_e C_b_n,  omega_eb_b = omega_nb_b + C_n_b omega_en_n
 *   d/dt omega_eb_b = dw_nb_b + C_n_b omega_en_n' - omega_nb_b x (C_n_b omega_en_n)
 * with dR_M/dlat = 3 e^2 R_M sin cos / (1 - e^2 sin^2), dR_N/dlat = e^2 R_N sin cos / (1 - e^2 sin^2).
 */
/* Velocity, its n-frame derivative and the transport rate (with derivative) from geodetic
 * kinematics (numerics.md E3.9; Groves 2nd ed. eqs. 2.111, 5.44). */
typedef struct ned_kin {
  nav_vec3 v_n, dv_n, w_en_n, dw_en_n;
} ned_kin;

/* geo_to_ned_kin from sin and cos of the latitude and the radii R_M, R_N there (as
 * nav_earth_radius_meridian_m / nav_earth_radius_prime_vertical_m return them). */
static ned_kin geo_to_ned_kin_sc(const nav_geo_kin *g, double sl, double cl, double RM, double RN) {
  const double h = g->pos.h_m;
  const double dlat = g->dpos.x, dlon = g->dpos.y, dh = g->dpos.z;
  const double ddlat = g->ddpos.x, ddlon = g->ddpos.y, ddh = g->ddpos.z;
  const double den = 1.0 - NAV_WGS84_E2 * sl * sl;
  const double dRM = 3.0 * NAV_WGS84_E2 * RM * sl * cl / den * dlat;
  const double dRN = NAV_WGS84_E2 * RN * sl * cl / den * dlat;
  ned_kin k;
  k.v_n = nav_vec3_make((RM + h) * dlat, (RN + h) * cl * dlon, -dh);
  k.dv_n = nav_vec3_make((dRM + dh) * dlat + (RM + h) * ddlat,
                         (dRN + dh) * cl * dlon - (RN + h) * sl * dlat * dlon + (RN + h) * cl * ddlon, -ddh);
  k.w_en_n = nav_vec3_make(dlon * cl, -dlat, -dlon * sl);
  k.dw_en_n = nav_vec3_make(ddlon * cl - dlon * dlat * sl, -ddlat, -ddlon * sl - dlon * dlat * cl);
  return k;
}

static ned_kin geo_to_ned_kin(const nav_geo_kin *g) {
  const double lat = g->pos.lat_rad;
  return geo_to_ned_kin_sc(g, sin(lat), cos(lat), nav_earth_radius_meridian_m(lat),
                           nav_earth_radius_prime_vertical_m(lat));
}

/* E2M = 1 - e^2, as earth.c writes it (the same constant folding). */
#define TRAJ_E2M (1.0 - NAV_WGS84_E2)

/* sin and cos of a, through the cache when there is one (the same numbers either way). */
static inline void sincos_opt(nav_kin_sincos_cache *k, double a, double *s, double *c) {
  if (k) {
    nav_kin_sincos_cached(k, a, s, c);
  } else {
    *s = sin(a);
    *c = cos(a);
  }
}

/* lat_sc, lon_sc: caches of the sines and cosines, or NULL. */
static void geo_to_ecef_state_c(const nav_geo_kin *g, nav_traj_state *s, nav_kin_sincos_cache *lat_sc,
                                nav_kin_sincos_cache *lon_sc) {
  const double lat = g->pos.lat_rad, lon = g->pos.lon_rad, h = g->pos.h_m;
  /* One sine and cosine each of latitude and longitude and one square root, shared by what
   * nav_earth_radius_meridian_m, nav_earth_radius_prime_vertical_m, nav_earth_dcm_n_e and
   * nav_earth_geodetic_to_ecef would each compute again: their expressions, term for term
   * (Groves 2nd ed. eqs. 2.105, 2.106, 2.112), so the numbers are the same. */
  double sl, cl, so, co;
  sincos_opt(lat_sc, lat, &sl, &cl);
  sincos_opt(lon_sc, lon, &so, &co);
  const double den2 = 1.0 - NAV_WGS84_E2 * sl * sl;
  const double sqrt_den = sqrt(den2);
  const double RM = NAV_WGS84_A_M * TRAJ_E2M / (den2 * sqrt_den);
  const double RN = NAV_WGS84_A_M / sqrt_den;
  const ned_kin nk = geo_to_ned_kin_sc(g, sl, cl, RM, RN);
  const nav_vec3 v_n = nk.v_n, dv_n = nk.dv_n, w_en_n = nk.w_en_n, dw_en_n = nk.dw_en_n;
  const nav_mat3 C_n_e = {{{-sl * co, -so, -cl * co}, {-sl * so, co, -cl * so}, {cl, 0.0, -sl}}};
  const double rho = (RN + h) * cl;
  s->r_fb_f_m = nav_vec3_make(rho * co, rho * so, (NAV_WGS84_A_M * TRAJ_E2M / sqrt_den + h) * sl);
  s->v_fb_f_mps = nav_mat3_mul_vec(C_n_e, v_n);
  s->a_fb_f_mps2 = nav_mat3_mul_vec(C_n_e, nav_vec3_add(dv_n, nav_vec3_cross(w_en_n, v_n)));
  s->q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), g->q_b_n));
  const nav_vec3 w_en_b = nav_quat_rotate(nav_quat_conj(g->q_b_n), w_en_n);
  s->w_fb_b_rps = nav_vec3_add(g->w_nb_b_rps, w_en_b);
  s->dw_fb_b_rps2 = nav_vec3_sub(nav_vec3_add(g->dw_nb_b_rps2, nav_quat_rotate(nav_quat_conj(g->q_b_n), dw_en_n)),
                                 nav_vec3_cross(g->w_nb_b_rps, w_en_b));
}

/* Local curvilinear NED kinematics -> geodetic kinematics (affine map, exact derivatives). */
static nav_geo_kin local_to_geo(const nav_traj *tr, const nav_local_kin *k) {
  const nav_frame *fr = &tr->frame;
  nav_geo_kin g;
  g.pos = nav_frame_local_to_geodetic(fr, k->r_ned_m);
  /* 1 / m_per_rad_lon (0 for 0), computed once at creation by the same expression. */
  const double sy = tr->inv_m_lon;
  g.dpos = nav_vec3_make(k->v_ned_mps.x / fr->m_per_rad_lat, k->v_ned_mps.y * sy, -k->v_ned_mps.z);
  g.ddpos = nav_vec3_make(k->a_ned_mps2.x / fr->m_per_rad_lat, k->a_ned_mps2.y * sy, -k->a_ned_mps2.z);
  g.q_b_n = k->q_b_n;
  g.w_nb_b_rps = k->w_nb_b_rps;
  g.dw_nb_b_rps2 = k->dw_nb_b_rps2;
  return g;
}

/* ------------------------------------------------------------------ front end */

nav_status nav_traj_create_msg(const nav_scene *scene, double dt_s, nav_traj **out, char *msg, size_t msg_size) {
  if (msg && msg_size) msg[0] = '\0';
  if (!scene || !out || !(dt_s > 0.0) || !isfinite(dt_s)) return NAV_ERR_INVALID_ARG;
  nav_traj *tr = calloc(1, sizeof *tr);
  if (!tr) return NAV_ERR_NO_MEMORY;
  tr->frame = nav_frame_from_scene(scene);
  tr->gravity = scene->earth.gravity_model;
  tr->g_l_mps2 = nav_vec3_make(0.0, 0.0, scene->earth.flat_gravity_mps2);
  tr->dt_s = dt_s;
  tr->inv_m_lat = 1.0 / tr->frame.m_per_rad_lat;
  tr->inv_m_lon = tr->frame.m_per_rad_lon != 0.0 ? 1.0 / tr->frame.m_per_rad_lon : 0.0;
  nav_kin_sincos_cache_init(&tr->st_lat_sc);
  nav_kin_sincos_cache_init(&tr->st_lon_sc);
  nav_kin_sincos_cache_init(&tr->nd_lat_sc);
  nav_status st = NAV_ERR_INVALID_ARG;
  switch (scene->trajectory.type) {
  case NAV_TRAJ_PARAMETRIC:
    st = nav_traj_parametric_create(scene, dt_s, &tr->m, msg, msg_size);
    tr->nodes = nav_traj_parametric_nodes;
    break;
  case NAV_TRAJ_TEST_MOTION: st = nav_traj_test_motion_create(scene, dt_s, &tr->m, msg, msg_size); break;
  case NAV_TRAJ_WAYPOINTS:
    st = nav_traj_waypoints_create(scene, dt_s, &tr->m, msg, msg_size);
    tr->nodes = nav_traj_waypoints_nodes;
    break;
  case NAV_TRAJ_SEGMENTS:
    st = nav_traj_segments_create(scene, dt_s, &tr->m, msg, msg_size);
    tr->nodes = nav_traj_segments_nodes;
    tr->type_segments = 1;
    break;
  case NAV_TRAJ_RECORDED: st = nav_traj_recorded_create(scene, dt_s, &tr->m, msg, msg_size); break;
  default:
    if (msg) snprintf(msg, msg_size, "trajectory type %d is not available", (int)scene->trajectory.type);
    break;
  }
  if (st == NAV_OK && tr->frame.model == NAV_EARTH_FLAT && !tr->m.eval_local) {
    if (msg) snprintf(msg, msg_size, "the %s trajectory needs the wgs84 Earth model", tr->m.name);
    if (tr->m.destroy) tr->m.destroy(tr->m.self);
    st = NAV_ERR_INVALID_ARG;
  }
  if (st != NAV_OK) {
    free(tr);
    return st;
  }
  *out = tr;
  return NAV_OK;
}

nav_status nav_traj_create(const nav_scene *scene, double dt_s, nav_traj **out) {
  return nav_traj_create_msg(scene, dt_s, out, NULL, 0);
}

void nav_traj_destroy(nav_traj *traj) {
  if (!traj) return;
  if (traj->m.destroy) traj->m.destroy(traj->m.self);
  free(traj);
}

double nav_traj_duration(const nav_traj *traj) { return traj ? traj->m.duration_s : 0.0; }

nav_frame nav_traj_frame(const nav_traj *traj) { return traj->frame; }

/* The local kinematics at t: the model's own, or, with r_ned (a local model with
 * eval_local_nopos), everything but the position from the model and the position r_ned. */
static nav_status local_kin(nav_traj *traj, double t_s, const nav_vec3 *r_ned, nav_local_kin *k) {
  if (!r_ned || !traj->m.eval_local_nopos) return traj->m.eval_local(traj->m.self, t_s, k);
  const nav_status st = traj->m.eval_local_nopos(traj->m.self, t_s, k);
  k->r_ned_m = *r_ned;
  return st;
}

/* nav_traj_eval, with the local position r_ned instead of the model's when given (see local_kin). */
static nav_status eval_state(nav_traj *traj, double t_s, const nav_vec3 *r_ned, nav_traj_state *out) {
  nav_traj_state s;
  nav_status st = NAV_OK;
  s.t_s = t_s;
  if (traj->m.eval_ecef) {
    st = traj->m.eval_ecef(traj->m.self, t_s, &s);
    s.t_s = t_s;
  } else if (traj->m.eval_local && traj->frame.model == NAV_EARTH_FLAT) {
    nav_local_kin k;
    st = local_kin(traj, t_s, r_ned, &k);
    s.r_fb_f_m = k.r_ned_m;
    s.v_fb_f_mps = k.v_ned_mps;
    s.a_fb_f_mps2 = k.a_ned_mps2;
    s.q_b_f = k.q_b_n;
    s.w_fb_b_rps = k.w_nb_b_rps;
    s.dw_fb_b_rps2 = k.dw_nb_b_rps2;
  } else {
    nav_geo_kin g;
    if (traj->m.eval_local) {
      nav_local_kin k;
      st = local_kin(traj, t_s, r_ned, &k);
      if (st != NAV_OK) return st;
      /* The north position first: it changes every call while the vehicle moves north or south. */
      if (traj->es_ok && nav_kin_same_bits(k.r_ned_m.x, traj->es_in.r_ned_m.x) &&
          nav_kin_same_bits_n(&k, &traj->es_in, sizeof k / sizeof(double))) {
        *out = traj->es_out;
        out->t_s = t_s;
        return NAV_OK;
      }
      /* Nothing can fail from here: the state is built in place. */
      g = local_to_geo(traj, &k);
      out->t_s = t_s;
      geo_to_ecef_state_c(&g, out, &traj->st_lat_sc, &traj->st_lon_sc);
      /* Kept for a vehicle at rest only: a moving one does not come back to the same inputs. */
      if (k.v_ned_mps.x == 0.0 && k.v_ned_mps.y == 0.0 && k.v_ned_mps.z == 0.0) {
        traj->es_in = k;
        traj->es_out = *out;
        traj->es_ok = true;
      }
      return NAV_OK;
    } else {
      st = traj->m.eval_geodetic(traj->m.self, t_s, &g);
      if (st == NAV_OK) geo_to_ecef_state_c(&g, &s, &traj->st_lat_sc, &traj->st_lon_sc);
    }
  }
  if (st != NAV_OK) return st;
  *out = s;
  return NAV_OK;
}

nav_status nav_traj_eval(nav_traj *traj, double t_s, nav_traj_state *out) {
  if (!traj || !out || !isfinite(t_s)) return NAV_ERR_INVALID_ARG;
  return eval_state(traj, t_s, NULL, out);
}

nav_status nav_traj_inertial(nav_traj *traj, double t_s, nav_vec3 *f_ib_b_mps2, nav_vec3 *w_ib_b_rps) {
  if (!traj || !f_ib_b_mps2 || !w_ib_b_rps || !isfinite(t_s)) return NAV_ERR_INVALID_ARG;
  nav_status st = NAV_OK;
  if (traj->m.eval_ecef) {
    /* ECEF form (E3.7-E3.8): f_e = a_e + 2 w_ie_e x v_e - g_e(r_e). */
    nav_traj_state s;
    st = traj->m.eval_ecef(traj->m.self, t_s, &s);
    if (st != NAV_OK) return st;
    const nav_vec3 w_ie_e = nav_earth_rate_e_rps();
    const nav_vec3 f_e = nav_vec3_sub(nav_vec3_add(s.a_fb_f_mps2, nav_vec3_scale(nav_vec3_cross(w_ie_e, s.v_fb_f_mps), 2.0)),
                                      nav_gravity_e_mps2(traj->gravity, s.r_fb_f_m));
    const nav_quat q_e_b = nav_quat_conj(s.q_b_f);
    *f_ib_b_mps2 = nav_quat_rotate(q_e_b, f_e);
    *w_ib_b_rps = nav_vec3_add(nav_quat_rotate(q_e_b, w_ie_e), s.w_fb_b_rps);
    return NAV_OK;
  }
  if (traj->frame.model == NAV_EARTH_FLAT) {
    /* Flat, non-rotating l with uniform gravity (E3.3). */
    nav_local_kin k;
    st = traj->m.eval_local(traj->m.self, t_s, &k);
    if (st != NAV_OK) return st;
    *f_ib_b_mps2 = nav_quat_rotate(nav_quat_conj(k.q_b_n), nav_vec3_sub(k.a_ned_mps2, traj->g_l_mps2));
    *w_ib_b_rps = k.w_nb_b_rps;
    return NAV_OK;
  }
  /* WGS-84, NED form (E3.9), equal to the ECEF form to round-off (T3.3) and cheaper: no
   * ECEF -> geodetic conversion for gravity.
   *   f_n = v_n' + (2 w_ie_n + w_en_n) x v_n - g_n,  f_b = C_n_b f_n
   *   w_ib_b = w_nb_b + C_n_b (w_ie_n + w_en_n) */
  nav_geo_kin g;
  if (traj->m.eval_local) {
    nav_local_kin k;
    st = traj->m.eval_local(traj->m.self, t_s, &k);
    if (st != NAV_OK) return st;
    g = local_to_geo(traj, &k);
  } else {
    st = traj->m.eval_geodetic(traj->m.self, t_s, &g);
    if (st != NAV_OK) return st;
  }
  const ned_kin nk = geo_to_ned_kin(&g);
  const nav_vec3 w_ie_n = nav_earth_rate_n_rps(g.pos.lat_rad);
  nav_vec3 g_n;
  if (traj->gravity == NAV_GRAVITY_J2) {
    const nav_mat3 C_n_e = nav_earth_dcm_n_e(g.pos.lat_rad, g.pos.lon_rad);
    g_n = nav_mat3_tmul_vec(C_n_e, nav_earth_gravity_j2_e_mps2(nav_earth_geodetic_to_ecef(g.pos)));
  } else {
    g_n = nav_earth_gravity_n_mps2(g.pos.lat_rad, g.pos.h_m);
  }
  const nav_vec3 f_n = nav_vec3_sub(
      nav_vec3_add(nk.dv_n, nav_vec3_cross(nav_vec3_add(nav_vec3_scale(w_ie_n, 2.0), nk.w_en_n), nk.v_n)), g_n);
  const nav_quat q_n_b = nav_quat_conj(g.q_b_n);
  *f_ib_b_mps2 = nav_quat_rotate(q_n_b, f_n);
  *w_ib_b_rps = nav_vec3_add(g.w_nb_b_rps, nav_quat_rotate(q_n_b, nav_vec3_add(w_ie_n, nk.w_en_n)));
  return NAV_OK;
}

size_t nav_traj_segment_boundaries(const nav_traj *traj, double *out, size_t cap) {
  if (!traj || traj->type_segments == 0) return 0;
  return nav_traj_segments_boundaries(traj->m.self, out, cap);
}

nav_status nav_traj_rate_integral(const nav_traj *traj, double t0_s, double t1_s, nav_vec3 *out,
                                  bool *has_closed_form) {
  if (!traj || !out || !has_closed_form || !isfinite(t0_s) || !isfinite(t1_s)) return NAV_ERR_INVALID_ARG;
  *has_closed_form = false;
  if (traj->frame.model != NAV_EARTH_FLAT || !traj->m.rate_integral) return NAV_OK;
  *has_closed_form = traj->m.rate_integral(traj->m.self, t0_s, t1_s, out);
  return NAV_OK;
}

/* ------------------------------------------------------------------ ideal IMU increments */

/* Generic form: nav_traj_inertial at each node. */
static nav_status increment_by_nodes(nav_traj *traj, double t0_s, double t1_s, int n, const double *x,
                                     const double *w, nav_vec3 *dv, nav_vec3 *dth) {
  const double half = 0.5 * (t1_s - t0_s), mid = 0.5 * (t1_s + t0_s);
  nav_vec3 sv = nav_vec3_zero(), st_ = nav_vec3_zero();
  for (int i = 0; i < n; ++i) {
    nav_vec3 f_b, w_b;
    const nav_status st = nav_traj_inertial(traj, mid + half * x[i], &f_b, &w_b);
    if (st != NAV_OK) return st;
    const double wgt = w[i] * half;
    sv = nav_vec3_axpy(sv, wgt, f_b);
    st_ = nav_vec3_axpy(st_, wgt, w_b);
  }
  *dv = sv;
  *dth = st_;
  return NAV_OK;
}

/* Make (x, w) the rule of the position chain: the integration matrix, and a new chain. */
static void set_rule(nav_traj *tr, int n, const double *x, const double *w) {
  /* memcmp: the same answer as comparing the bits of each double (called for every increment). */
  if (tr->q_n == n && memcmp(tr->q_x, x, (size_t)n * sizeof *x) == 0 && memcmp(tr->q_w, w, (size_t)n * sizeof *w) == 0)
    return;
  tr->q_n = n;
  tr->q_gen++;
  memcpy(tr->q_x, x, (size_t)n * sizeof *x);
  memcpy(tr->q_w, w, (size_t)n * sizeof *w);
  tr->chain_ok = false;
  /* A[i][j] = int_{-1}^{x_i} L_j: the n-point rule itself mapped onto [-1, x_i] is exact for
   * the degree n - 1 of L_j (the caller's rule is Gauss-Legendre, exact to degree 2n - 1; any
   * interpolatory rule with n nodes is exact to degree n - 1). L_j by its product form. */
  for (int i = 0; i < n; ++i) {
    const double hl = 0.5 * (x[i] + 1.0);
    for (int j = 0; j < n; ++j) {
      double sum = 0.0;
      for (int q = 0; q < n; ++q) {
        const double s = -1.0 + hl * (1.0 + x[q]);
        double l = 1.0;
        for (int m = 0; m < n; ++m)
          if (m != j) l *= (s - x[m]) / (x[j] - x[m]);
        sum += w[q] * l;
      }
      tr->q_A[i][j] = hl * sum;
    }
  }
  for (int j = 0; j < NAV_KIN_MAX_NODES; ++j)
    for (int i = 0; i < NAV_KIN_MAX_NODES; ++i)
      tr->q_At[j][i] = i < n && j < n ? tr->q_A[i][j] : 0.0;
}

/* Sample index k with t0 = (k - 1) dt and t1 = k dt exactly, or -1. */
static int64_t grid_index(const nav_traj *tr, double t0_s, double t1_s) {
  const double kf = nearbyint(t1_s / tr->dt_s);
  if (!(kf >= 1.0 && kf < 9.0e15)) return -1;
  const int64_t k = (int64_t)kf;
  if ((double)k * tr->dt_s != t1_s || (double)(k - 1) * tr->dt_s != t0_s) return -1;
  return k;
}

/* The model's own position (exact: its checkpoint quadrature). */
static nav_status model_position(nav_traj *tr, double t_s, nav_vec3 *r) {
  nav_local_kin k;
  const nav_status st = tr->m.eval_local(tr->m.self, t_s, &k);
  if (st == NAV_OK) *r = k.r_ned_m;
  return st;
}

/* r(t0) + int_t0^t1 v by the rule, from the node velocities of io. */
static nav_vec3 chain_step(const nav_traj *tr, nav_vec3 r0, const nav_kin_nodes *io, double half) {
  nav_vec3 s = nav_vec3_zero();
  for (int j = 0; j < io->n; ++j)
    s = nav_vec3_axpy(s, tr->q_w[j], io->v_ned_mps[j]);
  return nav_vec3_axpy(r0, half, s);
}

/*
 * Positions at the nodes for models whose position is a quadrature of the velocity (segments,
 * waypoints): evaluating it at every node would cost eight velocity evaluations each. Only the
 * WGS-84 gravity and radii use these positions, and they change by 3e-6 m/s^2 per metre of
 * height, so an error of 1e-9 m would already be below the rounding of f; the chain below is
 * good to about 1e-10 m.
 * Sample-grid positions R(j) (t_j = j dt) are a pure function of j, so results never depend on
 * the order of calls: R(j) is the model's position when j is a multiple of CHAIN_BLOCK, else
 * R(j - 1) plus the integral of the velocity over the interval by the caller's rule at its nodes
 * (the velocities the increment evaluates anyway). Within an interval, r_i = R(k - 1) +
 * half sum_j A[i][j] v_j (the integral of the velocity's interpolant, error ~ h^(n+1) v^(n)).
 * A sequential run costs one model position per CHAIN_BLOCK samples; a jump re-integrates at most
 * CHAIN_BLOCK - 1 intervals. Off the grid the model's position at t0 anchors the nodes.
 */
NAV_CLONE_INLINE nav_status chain_advance(nav_traj *tr, const nav_kin_nodes *io, double half, nav_vec3 *r0_out) {
  nav_vec3 r0;
  nav_status st = NAV_OK;
  if (io->k < 1) {
    st = model_position(tr, io->t0_s, &r0);
  } else {
    const int64_t j = io->k - 1;
    if (tr->chain_ok && tr->chain_j == j) {
      r0 = tr->chain_r;
    } else {
      /* Anchor of the block, or the cached value when it lies between the anchor and j. */
      int64_t i = j - j % CHAIN_BLOCK;
      if (tr->chain_ok && tr->chain_j > i && tr->chain_j < j) {
        i = tr->chain_j;
        r0 = tr->chain_r;
      } else {
        st = model_position(tr, (double)i * tr->dt_s, &r0);
      }
      nav_kin_nodes tmp;
      tmp.n = io->n;
      tmp.x = io->x;
      tmp.need_pos = false;
      tmp.rest_id = 0;
      for (; st == NAV_OK && i < j; ++i) {
        tmp.k = i + 1;
        tmp.t0_s = (double)i * tr->dt_s;
        tmp.t1_s = (double)(i + 1) * tr->dt_s;
        const double h = 0.5 * (tmp.t1_s - tmp.t0_s), m = 0.5 * (tmp.t1_s + tmp.t0_s);
        for (int q = 0; q < io->n; ++q)
          tmp.t_s[q] = m + h * io->x[q];
        st = tr->nodes(tr->m.self, &tmp);
        if (st == NAV_OK) r0 = chain_step(tr, r0, &tmp, h);
      }
    }
    if (st != NAV_OK) return st;
    /* R(k) for the next interval. */
    nav_vec3 r1;
    if (io->k % CHAIN_BLOCK == 0)
      st = model_position(tr, io->t1_s, &r1);
    else
      r1 = chain_step(tr, r0, io, half);
    if (st != NAV_OK) return st;
    tr->chain_ok = true;
    tr->chain_j = io->k;
    tr->chain_r = r1;
  }
  if (st == NAV_OK) *r0_out = r0;
  return st;
}

/* The positions at the nodes from the chain's r0 = R(k - 1) (chain_advance). */
NAV_CLONE_INLINE void chain_positions(const nav_traj *tr, nav_kin_nodes *io, double half, nav_vec3 r0) {
#if defined(__GNUC__)
  /* Four nodes at a time (lanes = nodes): each lane sums over j in the scalar loop's order. */
  for (int i0 = 0; i0 < io->n; i0 += 4) {
    traj_v4d sx = {0.0, 0.0, 0.0, 0.0}, sy = sx, sz = sx;
    for (int j = 0; j < io->n; ++j) {
      traj_v4d a;
      memcpy(&a, &tr->q_At[j][i0], sizeof a);
      sx = sx + a * io->v_ned_mps[j].x;
      sy = sy + a * io->v_ned_mps[j].y;
      sz = sz + a * io->v_ned_mps[j].z;
    }
    for (int l = 0; l < 4 && i0 + l < io->n; ++l)
      io->r_ned_m[i0 + l] = nav_vec3_axpy(r0, half, nav_vec3_make(sx[l], sy[l], sz[l]));
  }
#else
  for (int i = 0; i < io->n; ++i) {
    nav_vec3 s = nav_vec3_zero();
    for (int j = 0; j < io->n; ++j)
      s = nav_vec3_axpy(s, tr->q_A[i][j], io->v_ned_mps[j]);
    io->r_ned_m[i] = nav_vec3_axpy(r0, half, s);
  }
#endif
  io->has_pos = true;
}

/*
 * WGS-84, NED form (E3.9) at one node, as nav_traj_inertial with normal gravity, from the local
 * kinematics, the attitude as a DCM, sin/cos of the latitude lat = lat0 + N / m_lat (shared by
 * the radii, the Earth rate and gravity) and inv_sq = 1/sqrt(1 - e^2 sin^2 lat), which the
 * radii and gravity share.
 */
NAV_CLONE_INLINE void ned_inertial(const nav_frame *fr, double inv_m_lat, double inv_m_lon, nav_vec3 r,
                                   nav_vec3 v, nav_vec3 a, const nav_mat3 *C_b_n, nav_vec3 w_nb_b, double sl,
                                   double cl, double inv_sq, nav_vec3 *f_b, nav_vec3 *w_ib_b) {
  const double h = fr->origin.h_m - r.z;
  const double dlat = v.x * inv_m_lat, dlon = v.y * inv_m_lon, dh = -v.z;
  const double ddlat = a.x * inv_m_lat, ddlon = a.y * inv_m_lon, ddh = -a.z;
  /* Groves (2.105), (2.106); numerics.md E3.9. */
  const double s2 = sl * sl;
  const double inv_den = inv_sq * inv_sq;
  const double RN = NAV_WGS84_A_M * inv_sq, RM = NAV_WGS84_A_M * (1.0 - NAV_WGS84_E2) * inv_den * inv_sq;
  const double dRM = 3.0 * NAV_WGS84_E2 * RM * sl * cl * inv_den * dlat;
  const double dRN = NAV_WGS84_E2 * RN * sl * cl * inv_den * dlat;
  const nav_vec3 v_n = nav_vec3_make((RM + h) * dlat, (RN + h) * cl * dlon, -dh);
  const nav_vec3 dv_n =
      nav_vec3_make((dRM + dh) * dlat + (RM + h) * ddlat,
                    (dRN + dh) * cl * dlon - (RN + h) * sl * dlat * dlon + (RN + h) * cl * ddlon, -ddh);
  const nav_vec3 w_en_n = nav_vec3_make(dlon * cl, -dlat, -dlon * sl);
  const nav_vec3 w_ie_n = nav_vec3_make(NAV_WGS84_OMEGA_IE_RPS * cl, 0.0, -NAV_WGS84_OMEGA_IE_RPS * sl);
  /* Normal gravity: TR8350.2 (4-1), (4-3); numerics.md E3.10-E3.11. */
  const double ea = NAV_WGS84_A_M;
  const double lin = (2.0 / ea) * (1.0 + NAV_WGS84_F + NAV_WGS84_M - 2.0 * NAV_WGS84_F * s2);
  const double quad = 3.0 / (ea * ea);
  const double g =
      NAV_WGS84_GAMMA_E_MPS2 * (1.0 + NAV_WGS84_SOMIGLIANA_K * s2) * inv_sq * (1.0 - lin * h + quad * h * h);
  const nav_vec3 f_n =
      nav_vec3_sub(nav_vec3_add(dv_n, nav_vec3_cross(nav_vec3_add(nav_vec3_scale(w_ie_n, 2.0), w_en_n), v_n)),
                   nav_vec3_make(0.0, 0.0, g));
  *f_b = nav_mat3_tmul_vec(*C_b_n, f_n);
  *w_ib_b = nav_vec3_add(w_nb_b, nav_mat3_tmul_vec(*C_b_n, nav_vec3_add(w_ie_n, w_en_n)));
}

/* Node arrays with room for the lanes of a last group of four beyond NAV_KIN_MAX_NODES. */
#define NODE_PAD (NAV_KIN_MAX_NODES + 3)

/*
 * ned_inertial at the n nodes of nd (sines, cosines and 1/sqrt(D) of their latitudes in sl, cl,
 * isq, each padded to a multiple of four entries with node 0's values), into fb[c][i] and wb[c][i]
 * (component c of f_b and w_b at node i). With GCC's vector extensions four nodes at a time: each
 * lane performs the operations of ned_inertial, in its order (the same expressions, written for
 * vectors, C_n_b f_n as nav_mat3_tmul_vec forms it; IEEE arithmetic lane by lane, no
 * contraction), so every node gets the bits of the scalar function. Lanes beyond n repeat node 0.
 */
#if defined(__GNUC__)

NAV_CLONE_INLINE void ned_inertial_nodes(const nav_frame *fr, double inv_m_lat, double inv_m_lon,
                                         const nav_kin_nodes *nd, int n, const double *sl_, const double *cl_,
                                         const double *isq_, bool same, double fb[3][NODE_PAD],
                                         double wb[3][NODE_PAD]) {
  for (int i0 = 0; i0 < n; i0 += 4) {
    int ix[4];
    for (int l = 0; l < 4; ++l)
      ix[l] = i0 + l < n ? i0 + l : 0;
    /* The kinematics of the four nodes, or node 0's in every lane when every node has its bits
     * (same: a vehicle at rest or on a straight at constant speed). */
#define TRAJ_LANES(expr_of_j)                                                                                  \
  (same ? (traj_v4d){expr_of_j(0), expr_of_j(0), expr_of_j(0), expr_of_j(0)}                                  \
        : (traj_v4d){expr_of_j(ix[0]), expr_of_j(ix[1]), expr_of_j(ix[2]), expr_of_j(ix[3])})
#define RZ(j) nd->r_ned_m[j].z
#define VX(j) nd->v_ned_mps[j].x
#define VY(j) nd->v_ned_mps[j].y
#define VZ(j) nd->v_ned_mps[j].z
#define AX(j) nd->a_ned_mps2[j].x
#define AY(j) nd->a_ned_mps2[j].y
#define AZ(j) nd->a_ned_mps2[j].z
    const traj_v4d rz = {RZ(ix[0]), RZ(ix[1]), RZ(ix[2]), RZ(ix[3])};
    const traj_v4d vx = TRAJ_LANES(VX), vy = TRAJ_LANES(VY), vz = TRAJ_LANES(VZ);
    const traj_v4d ax = TRAJ_LANES(AX), ay = TRAJ_LANES(AY), az = TRAJ_LANES(AZ);
#undef RZ
#undef VX
#undef VY
#undef VZ
#undef AX
#undef AY
#undef AZ
    traj_v4d sl, cl, inv_sq;
    memcpy(&sl, &sl_[i0], sizeof sl);
    memcpy(&cl, &cl_[i0], sizeof cl);
    memcpy(&inv_sq, &isq_[i0], sizeof inv_sq);
    /* ned_inertial, term for term. */
    const traj_v4d h = fr->origin.h_m - rz;
    const traj_v4d dlat = vx * inv_m_lat, dlon = vy * inv_m_lon, dh = -vz;
    const traj_v4d ddlat = ax * inv_m_lat, ddlon = ay * inv_m_lon, ddh = -az;
    const traj_v4d s2 = sl * sl;
    const traj_v4d inv_den = inv_sq * inv_sq;
    const traj_v4d RN = NAV_WGS84_A_M * inv_sq, RM = NAV_WGS84_A_M * (1.0 - NAV_WGS84_E2) * inv_den * inv_sq;
    const traj_v4d dRM = 3.0 * NAV_WGS84_E2 * RM * sl * cl * inv_den * dlat;
    const traj_v4d dRN = NAV_WGS84_E2 * RN * sl * cl * inv_den * dlat;
    const traj_v4d vnx = (RM + h) * dlat, vny = (RN + h) * cl * dlon, vnz = -dh;
    const traj_v4d dvx = (dRM + dh) * dlat + (RM + h) * ddlat;
    const traj_v4d dvy = (dRN + dh) * cl * dlon - (RN + h) * sl * dlat * dlon + (RN + h) * cl * ddlon;
    const traj_v4d dvz = -ddh;
    const traj_v4d wenx = dlon * cl, weny = -dlat, wenz = -dlon * sl;
    const traj_v4d wiex = NAV_WGS84_OMEGA_IE_RPS * cl, wiez = -NAV_WGS84_OMEGA_IE_RPS * sl;
    const double ea = NAV_WGS84_A_M;
    const traj_v4d lin = (2.0 / ea) * (1.0 + NAV_WGS84_F + NAV_WGS84_M - 2.0 * NAV_WGS84_F * s2);
    const double quad = 3.0 / (ea * ea);
    const traj_v4d g =
        NAV_WGS84_GAMMA_E_MPS2 * (1.0 + NAV_WGS84_SOMIGLIANA_K * s2) * inv_sq * (1.0 - lin * h + quad * h * h);
    /* (2 w_ie + w_en) x v_n; w_ie_n.y = 0 enters as 0 * 2 + w_en.y, as in nav_vec3_scale / nav_vec3_add. */
    const traj_v4d px = wiex * 2.0 + wenx, py = 0.0 * 2.0 + weny, pz = wiez * 2.0 + wenz;
    const traj_v4d fx = (dvx + (py * vnz - pz * vny)) - 0.0;
    const traj_v4d fy = (dvy + (pz * vnx - px * vnz)) - 0.0;
    const traj_v4d fz = (dvz + (px * vny - py * vnx)) - g;
    const traj_v4d qx = wiex + wenx, qy = 0.0 + weny, qz = wiez + wenz;
    /* C_n_b f_n and w_nb_b + C_n_b (w_ie_n + w_en_n) (nav_mat3_tmul_vec, nav_vec3_add). */
#define CM(r, c) TRAJ_LANES(CM_##r##c)
#define CM_00(j) nd->C_b_n[j].m[0][0]
#define CM_01(j) nd->C_b_n[j].m[0][1]
#define CM_02(j) nd->C_b_n[j].m[0][2]
#define CM_10(j) nd->C_b_n[j].m[1][0]
#define CM_11(j) nd->C_b_n[j].m[1][1]
#define CM_12(j) nd->C_b_n[j].m[1][2]
#define CM_20(j) nd->C_b_n[j].m[2][0]
#define CM_21(j) nd->C_b_n[j].m[2][1]
#define CM_22(j) nd->C_b_n[j].m[2][2]
#define WX(j) nd->w_nb_b_rps[j].x
#define WY(j) nd->w_nb_b_rps[j].y
#define WZ(j) nd->w_nb_b_rps[j].z
    const traj_v4d c00 = CM(0, 0), c01 = CM(0, 1), c02 = CM(0, 2), c10 = CM(1, 0), c11 = CM(1, 1);
    const traj_v4d c12 = CM(1, 2), c20 = CM(2, 0), c21 = CM(2, 1), c22 = CM(2, 2);
    const traj_v4d wnx = TRAJ_LANES(WX), wny = TRAJ_LANES(WY), wnz = TRAJ_LANES(WZ);
#undef CM
#undef CM_00
#undef CM_01
#undef CM_02
#undef CM_10
#undef CM_11
#undef CM_12
#undef CM_20
#undef CM_21
#undef CM_22
#undef WX
#undef WY
#undef WZ
    const traj_v4d out[6] = {c00 * fx + c10 * fy + c20 * fz,
                             c01 * fx + c11 * fy + c21 * fz,
                             c02 * fx + c12 * fy + c22 * fz,
                             wnx + (c00 * qx + c10 * qy + c20 * qz),
                             wny + (c01 * qx + c11 * qy + c21 * qz),
                             wnz + (c02 * qx + c12 * qy + c22 * qz)};
    for (int c = 0; c < 3; ++c) {
      memcpy(&fb[c][i0], &out[c], sizeof out[c]);
      memcpy(&wb[c][i0], &out[3 + c], sizeof out[c]);
    }
#undef TRAJ_LANES
  }
}
#else
NAV_CLONE_INLINE void ned_inertial_nodes(const nav_frame *fr, double inv_m_lat, double inv_m_lon,
                                         const nav_kin_nodes *nd, int n, const double *sl, const double *cl,
                                         const double *isq, bool same, double fb[3][NODE_PAD],
                                         double wb[3][NODE_PAD]) {
  (void)same;
  for (int i = 0; i < n; ++i) {
    nav_vec3 f, w;
    ned_inertial(fr, inv_m_lat, inv_m_lon, nd->r_ned_m[i], nd->v_ned_mps[i], nd->a_ned_mps2[i], &nd->C_b_n[i],
                 nd->w_nb_b_rps[i], sl[i], cl[i], isq[i], &f, &w);
    fb[0][i] = f.x;
    fb[1][i] = f.y;
    fb[2][i] = f.z;
    wb[0][i] = w.x;
    wb[1][i] = w.y;
    wb[2][i] = w.z;
  }
}
#endif

/*
 * The increment over [t0, t1] (k: its grid index or -1). With r_end (k >= 1), also the position
 * chain's R(k) into *r_end, setting *has_r_end, when the model's positions come from the chain
 * (a local model with a node evaluator and no node positions of its own, normal gravity on WGS-84
 * or flat Earth); *has_r_end stays false otherwise. The increment is the same either way.
 */
NAV_CLONE_INLINE nav_status increment_core(nav_traj *traj, double t0_s, double t1_s, int64_t k, int n,
                                           const double *x, const double *w, nav_vec3 *dv_b_mps,
                                           nav_vec3 *dtheta_b_rad, nav_vec3 *r_end, bool *has_r_end) {
  const bool flat = traj->frame.model == NAV_EARTH_FLAT;
  if (!traj->nodes || (!flat && traj->gravity != NAV_GRAVITY_NORMAL))
    return increment_by_nodes(traj, t0_s, t1_s, n, x, w, dv_b_mps, dtheta_b_rad);
  for (int i = 1; i < n; ++i)
    if (!(x[i] > x[i - 1])) return increment_by_nodes(traj, t0_s, t1_s, n, x, w, dv_b_mps, dtheta_b_rad);
  const double half = 0.5 * (t1_s - t0_s), mid = 0.5 * (t1_s + t0_s);
  nav_kin_nodes nd;
  nd.n = n;
  nd.x = x;
  nd.t0_s = t0_s;
  nd.t1_s = t1_s;
  for (int i = 0; i < n; ++i)
    nd.t_s[i] = mid + half * x[i];
  nd.k = k;
  nd.need_pos = !flat;
  nd.has_pos = false;
  memset(nd.same_kin, 0, sizeof nd.same_kin);
  nd.rest_id = 0;
  nav_status st = traj->nodes(traj->m.self, &nd);
  if (st != NAV_OK) return st;
  bool chained = false; /* the chain and the rule (x, w) were set up: r0 = R(k - 1) */
  bool standing = false; /* and the nodes are a rest entry with zero velocity */
  nav_vec3 r0 = nav_vec3_zero();
  if (!nd.has_pos && (!flat || (r_end && k >= 1))) {
    set_rule(traj, n, x, w);
    st = chain_advance(traj, &nd, half, &r0);
    if (st != NAV_OK) return st;
    chained = true;
    if (r_end && k >= 1) {
      *r_end = traj->chain_r;
      *has_r_end = true;
    }
    /* The nodes of the last rest interval again (a vehicle standing still), on the same rule, the
     * same interval length and from the same position: the same increment (every later step below
     * is a function of these inputs). */
    /* Only at rest (zero velocity at the nodes) can the chain come back to the same r0. */
    standing = nd.rest_id != 0 && nd.v_ned_mps[0].x == 0.0 && nd.v_ned_mps[0].y == 0.0 && nd.v_ned_mps[0].z == 0.0;
    if (standing)
      for (int e = 0; e < REP_WAYS; ++e)
        if (nav_kin_same_bits_n(&r0, &traj->rep[e].r0, 3) && nav_kin_same_bits(half, traj->rep[e].half) &&
            nd.rest_id == traj->rep[e].id && traj->rep[e].gen == traj->q_gen) {
          *dv_b_mps = traj->rep[e].dv;
          *dtheta_b_rad = traj->rep[e].dth;
          return NAV_OK;
        }
    /* Flat-Earth forces do not depend on the position: there only R(k) was wanted. */
    if (!flat) chain_positions(traj, &nd, half, r0);
  }
  /* Latitudes of the nodes differ by micro-radians: sin/cos of the first, the others by angle
   * addition (nav_kin_sincos_near); likewise 1/sqrt(D), D = 1 - e^2 sin^2 lat: directly at the
   * first node, at the others as (1/sqrt(D0)) (1 + e)^(-1/2), e = (D - D0)/D0, by its series
   * 1 - e/2 + 3e^2/8 while |e| <= 1e-6 (omitted 5e^3/16 < 4e-19; e is ~1e-10 at vehicle speeds). */
  double sl[NODE_PAD], cl[NODE_PAD], isq[NODE_PAD];
  const nav_frame *fr = &traj->frame;
  const double inv_m_lat = traj->inv_m_lat, inv_m_lon = traj->inv_m_lon;
  if (!flat) {
    const double lat0 = fr->origin.lat_rad + nd.r_ned_m[0].x * inv_m_lat;
    nav_kin_sincos_cached(&traj->nd_lat_sc, lat0, &sl[0], &cl[0]);
    const double den0 = 1.0 - NAV_WGS84_E2 * sl[0] * sl[0];
    isq[0] = 1.0 / sqrt(den0);
    const double inv_den0 = isq[0] * isq[0];
    for (int i = 1; i < n; ++i) {
      const double lat = fr->origin.lat_rad + nd.r_ned_m[i].x * inv_m_lat;
      if (fabs(lat - lat0) <= NAV_KIN_NEAR_RAD) {
        nav_kin_sincos_near(sl[0], cl[0], lat - lat0, &sl[i], &cl[i]);
      } else {
        sl[i] = sin(lat);
        cl[i] = cos(lat);
      }
      /* D - D0 = -e^2 (s - s0)(s + s0), without the cancellation of 1 - e^2 s^2. */
      const double e = -NAV_WGS84_E2 * (sl[i] - sl[0]) * (sl[i] + sl[0]) * inv_den0;
      isq[i] = fabs(e) <= 1e-6 ? isq[0] * (1.0 - 0.5 * e + 0.375 * e * e)
                               : 1.0 / sqrt(1.0 - NAV_WGS84_E2 * sl[i] * sl[i]);
    }
    /* The lanes of ned_inertial_nodes beyond n. */
    for (int i = n; i % 4 != 0; ++i) {
      sl[i] = sl[0];
      cl[i] = cl[0];
      isq[i] = isq[0];
    }
  }
  /* A node with the previous node's kinematics and position (at rest; on flat Earth any position)
   * has its forces: they are not computed again (equal inputs, equal bits). */
  bool reuse[NAV_KIN_MAX_NODES];
  int fresh = 1;
  bool same_kin = true; /* every node has node 0's kinematics */
  reuse[0] = false;
  for (int i = 1; i < n; ++i) {
    same_kin &= nd.same_kin[i];
    reuse[i] = nd.same_kin[i] && (flat || (nav_kin_same_bits(nd.r_ned_m[i].x, nd.r_ned_m[i - 1].x) &&
                                           nav_kin_same_bits(nd.r_ned_m[i].y, nd.r_ned_m[i - 1].y) &&
                                           nav_kin_same_bits(nd.r_ned_m[i].z, nd.r_ned_m[i - 1].z)));
    fresh += !reuse[i];
  }
  /* f_b and w_b of the nodes, component by component: fb[c][i], wb[c][i]. */
  double fb[3][NODE_PAD], wb[3][NODE_PAD];
  if (!flat && fresh > 1) {
    /* All nodes at once (a reused node gets the bits it would be given anyway). */
    ned_inertial_nodes(fr, inv_m_lat, inv_m_lon, &nd, n, sl, cl, isq, same_kin, fb, wb);
  } else {
    for (int i = 0; i < n; ++i) {
      nav_vec3 f_b, w_b;
      if (reuse[i]) {
        f_b = nav_vec3_make(fb[0][i - 1], fb[1][i - 1], fb[2][i - 1]);
        w_b = nav_vec3_make(wb[0][i - 1], wb[1][i - 1], wb[2][i - 1]);
      } else if (flat) {
        /* Flat, non-rotating l with uniform gravity (E3.3). */
        f_b = nav_mat3_tmul_vec(nd.C_b_n[i], nav_vec3_sub(nd.a_ned_mps2[i], traj->g_l_mps2));
        w_b = nd.w_nb_b_rps[i];
      } else {
        ned_inertial(fr, inv_m_lat, inv_m_lon, nd.r_ned_m[i], nd.v_ned_mps[i], nd.a_ned_mps2[i], &nd.C_b_n[i],
                     nd.w_nb_b_rps[i], sl[i], cl[i], isq[i], &f_b, &w_b);
      }
      fb[0][i] = f_b.x;
      fb[1][i] = f_b.y;
      fb[2][i] = f_b.z;
      wb[0][i] = w_b.x;
      wb[1][i] = w_b.y;
      wb[2][i] = w_b.z;
    }
  }
  /* nav_vec3_axpy over the nodes in order. */
  nav_vec3 dv = nav_vec3_zero(), dth = nav_vec3_zero();
  for (int i = 0; i < n; ++i) {
    const double wgt = w[i] * half;
    dv = nav_vec3_make(dv.x + wgt * fb[0][i], dv.y + wgt * fb[1][i], dv.z + wgt * fb[2][i]);
    dth = nav_vec3_make(dth.x + wgt * wb[0][i], dth.y + wgt * wb[1][i], dth.z + wgt * wb[2][i]);
  }
  if (chained && standing) {
    const int e = traj->rep_next;
    traj->rep_next = (e + 1) % REP_WAYS;
    traj->rep[e].id = nd.rest_id;
    traj->rep[e].gen = traj->q_gen;
    traj->rep[e].half = half;
    traj->rep[e].r0 = r0;
    traj->rep[e].dv = dv;
    traj->rep[e].dth = dth;
  }
  *dv_b_mps = dv;
  *dtheta_b_rad = dth;
  return NAV_OK;
}

NAV_HOT_CLONES nav_status nav_traj_inertial_increment(nav_traj *traj, double t0_s, double t1_s, int n, const double *x,
                                                      const double *w, nav_vec3 *dv_b_mps, nav_vec3 *dtheta_b_rad) {
  if (!traj || !x || !w || !dv_b_mps || !dtheta_b_rad || n < 1 || n > NAV_KIN_MAX_NODES || !isfinite(t0_s) ||
      !isfinite(t1_s))
    return NAV_ERR_INVALID_ARG;
  return increment_core(traj, t0_s, t1_s, grid_index(traj, t0_s, t1_s), n, x, w, dv_b_mps, dtheta_b_rad, NULL,
                        NULL);
}

NAV_HOT_CLONES nav_status nav_traj_sample(nav_traj *traj, int64_t k, int n, const double *x, const double *w,
                                          nav_traj_state *state, nav_vec3 *dv_b_mps, nav_vec3 *dtheta_b_rad) {
  if (!traj || !x || !w || !state || !dv_b_mps || !dtheta_b_rad || n < 1 || n > NAV_KIN_MAX_NODES || k < 1 ||
      k > (int64_t)9.0e15)
    return NAV_ERR_INVALID_ARG;
  const double t0_s = (double)(k - 1) * traj->dt_s, t1_s = (double)k * traj->dt_s;
  nav_vec3 dv, dth, r_end;
  bool has_r_end = false;
  nav_status st = increment_core(traj, t0_s, t1_s, k, n, x, w, &dv, &dth, &r_end, &has_r_end);
  if (st != NAV_OK) return st;
  /* eval_state writes *state only on success, and nothing fails after it. */
  st = eval_state(traj, t1_s, has_r_end ? &r_end : NULL, state);
  if (st != NAV_OK) return st;
  *dv_b_mps = dv;
  *dtheta_b_rad = dth;
  return NAV_OK;
}
