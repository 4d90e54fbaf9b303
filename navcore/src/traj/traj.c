/*
 * Trajectory front end: dispatch to the model of the scene and express its state in the
 * scene's reference frame (flat l, or ECEF on WGS-84). See traj_internal.h for the contract.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_truth.h"
#include "traj/traj_internal.h"

struct nav_traj {
  nav_traj_model m;
  nav_frame frame;
  nav_gravity_model gravity;
  nav_vec3 g_l_mps2; /* flat Earth: uniform gravity in l */
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

static ned_kin geo_to_ned_kin(const nav_geo_kin *g) {
  const double lat = g->pos.lat_rad, h = g->pos.h_m;
  const double sl = sin(lat), cl = cos(lat);
  const double dlat = g->dpos.x, dlon = g->dpos.y, dh = g->dpos.z;
  const double ddlat = g->ddpos.x, ddlon = g->ddpos.y, ddh = g->ddpos.z;
  const double RM = nav_earth_radius_meridian_m(lat), RN = nav_earth_radius_prime_vertical_m(lat);
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

static void geo_to_ecef_state(const nav_geo_kin *g, nav_traj_state *s) {
  const double lat = g->pos.lat_rad;
  const ned_kin nk = geo_to_ned_kin(g);
  const nav_vec3 v_n = nk.v_n, dv_n = nk.dv_n, w_en_n = nk.w_en_n, dw_en_n = nk.dw_en_n;
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(lat, g->pos.lon_rad);
  s->r_fb_f_m = nav_earth_geodetic_to_ecef(g->pos);
  s->v_fb_f_mps = nav_mat3_mul_vec(C_n_e, v_n);
  s->a_fb_f_mps2 = nav_mat3_mul_vec(C_n_e, nav_vec3_add(dv_n, nav_vec3_cross(w_en_n, v_n)));
  s->q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), g->q_b_n));
  const nav_vec3 w_en_b = nav_quat_rotate(nav_quat_conj(g->q_b_n), w_en_n);
  s->w_fb_b_rps = nav_vec3_add(g->w_nb_b_rps, w_en_b);
  s->dw_fb_b_rps2 = nav_vec3_sub(nav_vec3_add(g->dw_nb_b_rps2, nav_quat_rotate(nav_quat_conj(g->q_b_n), dw_en_n)),
                                 nav_vec3_cross(g->w_nb_b_rps, w_en_b));
}

/* Local curvilinear NED kinematics -> geodetic kinematics (affine map, exact derivatives). */
static nav_geo_kin local_to_geo(const nav_frame *fr, const nav_local_kin *k) {
  nav_geo_kin g;
  g.pos = nav_frame_local_to_geodetic(fr, k->r_ned_m);
  const double sy = fr->m_per_rad_lon != 0.0 ? 1.0 / fr->m_per_rad_lon : 0.0;
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
  nav_status st = NAV_ERR_INVALID_ARG;
  switch (scene->trajectory.type) {
  case NAV_TRAJ_PARAMETRIC: st = nav_traj_parametric_create(scene, dt_s, &tr->m, msg, msg_size); break;
  case NAV_TRAJ_TEST_MOTION: st = nav_traj_test_motion_create(scene, dt_s, &tr->m, msg, msg_size); break;
  case NAV_TRAJ_WAYPOINTS: st = nav_traj_waypoints_create(scene, dt_s, &tr->m, msg, msg_size); break;
  case NAV_TRAJ_SEGMENTS: st = nav_traj_segments_create(scene, dt_s, &tr->m, msg, msg_size); break;
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

nav_status nav_traj_eval(nav_traj *traj, double t_s, nav_traj_state *out) {
  if (!traj || !out || !isfinite(t_s)) return NAV_ERR_INVALID_ARG;
  nav_traj_state s;
  nav_status st = NAV_OK;
  s.t_s = t_s;
  if (traj->m.eval_ecef) {
    st = traj->m.eval_ecef(traj->m.self, t_s, &s);
    s.t_s = t_s;
  } else if (traj->m.eval_local && traj->frame.model == NAV_EARTH_FLAT) {
    nav_local_kin k;
    st = traj->m.eval_local(traj->m.self, t_s, &k);
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
      st = traj->m.eval_local(traj->m.self, t_s, &k);
      g = local_to_geo(&traj->frame, &k);
    } else {
      st = traj->m.eval_geodetic(traj->m.self, t_s, &g);
    }
    if (st == NAV_OK) geo_to_ecef_state(&g, &s);
  }
  if (st != NAV_OK) return st;
  *out = s;
  return NAV_OK;
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
    g = local_to_geo(&traj->frame, &k);
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

nav_status nav_traj_rate_integral(const nav_traj *traj, double t0_s, double t1_s, nav_vec3 *out,
                                  bool *has_closed_form) {
  if (!traj || !out || !has_closed_form || !isfinite(t0_s) || !isfinite(t1_s)) return NAV_ERR_INVALID_ARG;
  *has_closed_form = false;
  if (traj->frame.model != NAV_EARTH_FLAT || !traj->m.rate_integral) return NAV_OK;
  *has_closed_form = traj->m.rate_integral(traj->m.self, t0_s, t1_s, out);
  return NAV_OK;
}
