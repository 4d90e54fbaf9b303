/*
 * Strapdown mechanization in the flat, non-rotating scene frame l (numerics.md section 4,
 * flat-l rows): C(k) = C(k-1) exp([phi_k x]); v_k = v_(k-1) + C(k-1) dv_l_body + g dt;
 * p_k = p_(k-1) + dt/2 (v_(k-1) + v_k). Order of updates: velocity (needs the attitude at
 * k-1), then position (needs both velocities), then attitude.
 */
#include <stdlib.h>

#include "navcore/nav_ins.h"

struct nav_ins {
  nav_ins_config cfg;
  nav_ins_state s;
  bool have_prev;
  nav_vec3 prev_dtheta_b_rad;
  nav_vec3 prev_dv_b_mps;
};

nav_ins_config nav_ins_config_default(void) {
  nav_ins_config c;
  c.earth_model = NAV_EARTH_FLAT;
  c.algorithm = NAV_MECH_FIRST_ORDER;
  c.mech_frame = NAV_MECH_NED;
  c.gravity_model = NAV_GRAVITY_NORMAL;
  c.g_l_mps2 = nav_vec3_make(0.0, 0.0, 9.80665);
  c.clamp_vertical = false;
  return c;
}

nav_status nav_ins_create(const nav_ins_config *cfg, const nav_ins_state *initial, nav_ins **out) {
  if (!cfg || !initial || !out) return NAV_ERR_INVALID_ARG;
  if (cfg->earth_model != NAV_EARTH_FLAT) return NAV_ERR_INVALID_ARG;
  if (cfg->algorithm != NAV_MECH_FIRST_ORDER && cfg->algorithm != NAV_MECH_HIGH_ORDER) return NAV_ERR_INVALID_ARG;
  nav_ins *ins = calloc(1, sizeof *ins);
  if (!ins) return NAV_ERR_NO_MEMORY;
  ins->cfg = *cfg;
  ins->s = *initial;
  ins->s.q_b_f = nav_quat_normalize(initial->q_b_f);
  *out = ins;
  return NAV_OK;
}

void nav_ins_destroy(nav_ins *ins) { free(ins); }

nav_status nav_ins_aid_vertical(nav_ins *ins, double h_m, double v_d_mps) {
  if (!ins || !isfinite(h_m) || !isfinite(v_d_mps)) return NAV_ERR_INVALID_ARG;
  /* Flat Earth: D is -height relative to the origin plane; the scene origin height is 0 in l. */
  ins->s.r_fb_f_m.z = -h_m;
  ins->s.v_fb_f_mps.z = v_d_mps;
  return NAV_OK;
}

const nav_ins_state *nav_ins_get_state(const nav_ins *ins) { return ins ? &ins->s : NULL; }

nav_status nav_ins_step(nav_ins *ins, const nav_imu_increment *imu) {
  if (!ins || !imu || !(imu->dt_s > 0.0)) return NAV_ERR_INVALID_ARG;
  if (!nav_vec3_isfinite(imu->dtheta_b_rad) || !nav_vec3_isfinite(imu->dv_b_mps) || !isfinite(imu->dt_s))
    return NAV_ERR_NUMERIC;
  const double dt = imu->dt_s;
  const nav_vec3 dth = imu->dtheta_b_rad, dv = imu->dv_b_mps;
  const nav_mat3 C_b_l = nav_quat_to_dcm(ins->s.q_b_f);
  nav_vec3 phi, dv_body;

  if (ins->cfg.algorithm == NAV_MECH_FIRST_ORDER) {
    /* (a) E4.1 and the classic rotation compensation dv + 1/2 dtheta x dv. */
    phi = dth;
    dv_body = nav_vec3_add(dv, nav_vec3_scale(nav_vec3_cross(dth, dv), 0.5));
  } else {
    /* (b) E4.2 two-sample coning, E4.4 exact rotation compensation, E4.5 two-sample sculling.
     * At the first step there is no previous increment: the terms are dropped (a one-off
     * O(dt^3) error, numerics.md T5.1 note). */
    const nav_vec3 pdth = ins->have_prev ? ins->prev_dtheta_b_rad : nav_vec3_zero();
    const nav_vec3 pdv = ins->have_prev ? ins->prev_dv_b_mps : nav_vec3_zero();
    phi = nav_vec3_add(dth, nav_vec3_scale(nav_vec3_cross(pdth, dth), 1.0 / 12.0));
    const nav_vec3 dv_rot = nav_mat3_mul_vec(nav_rot_comp_matrix(phi), dv);
    const nav_vec3 dv_scul =
        nav_vec3_scale(nav_vec3_add(nav_vec3_cross(pdth, dv), nav_vec3_cross(pdv, dth)), 1.0 / 12.0);
    dv_body = nav_vec3_add(dv_rot, dv_scul);
  }

  nav_ins_state n = ins->s;
  n.t_s = imu->t_s;
  n.v_fb_f_mps = nav_vec3_add(nav_vec3_add(ins->s.v_fb_f_mps, nav_mat3_mul_vec(C_b_l, dv_body)),
                              nav_vec3_scale(ins->cfg.g_l_mps2, dt));
  n.r_fb_f_m = nav_vec3_add(ins->s.r_fb_f_m, nav_vec3_scale(nav_vec3_add(ins->s.v_fb_f_mps, n.v_fb_f_mps), 0.5 * dt));
  /* Renormalise every step (numerics.md 4.4 rule 1). */
  n.q_b_f = nav_quat_normalize(nav_quat_mul(ins->s.q_b_f, nav_quat_from_rotvec(phi)));
  if (!nav_vec3_isfinite(n.v_fb_f_mps) || !nav_vec3_isfinite(n.r_fb_f_m) || !isfinite(n.q_b_f.w))
    return NAV_ERR_NUMERIC;
  ins->s = n;
  ins->prev_dtheta_b_rad = dth;
  ins->prev_dv_b_mps = dv;
  ins->have_prev = true;
  return NAV_OK;
}
