/**
 * @file nav_ins.h
 * @brief Strapdown inertial navigation (mechanization) driven by IMU increments.
 *
 * Algorithms (numerics.md section 4):
 * - NAV_MECH_FIRST_ORDER (a): phi_k = dtheta_k; dv rotated with I + 1/2 [dtheta x];
 *   trapezoidal position.
 * - NAV_MECH_HIGH_ORDER (b): two-sample coning phi_k = dtheta_k + 1/12 dtheta_(k-1) x dtheta_k
 *   (E4.2), exact rotation compensation A(phi) (E4.4), two-sample sculling (E4.5), trapezoidal
 *   position.
 * The navigation never sees truth: it consumes increments only. One thread per object.
 */
#ifndef NAV_INS_H
#define NAV_INS_H

#include "nav_export.h"
#include "nav_math.h"
#include "nav_scene.h"
#include "nav_status.h"
#include "nav_truth.h"

NAV_BEGIN_DECLS

/**
 * Navigation state in the scene frame F (nav_frames.h): F = l on flat Earth, F = e (ECEF) on
 * WGS-84 whatever frame the mechanization integrates in (a NED mechanization converts).
 */
typedef struct nav_ins_state {
  double t_s;
  nav_vec3 r_fb_f_m;   /**< position [m] */
  nav_vec3 v_fb_f_mps; /**< velocity relative to F, resolved in F [m/s] */
  nav_quat q_b_f;      /**< attitude */
} nav_ins_state;

typedef struct nav_ins_config {
  nav_earth_model earth_model;
  nav_mech_algorithm algorithm;
  nav_mech_frame mech_frame;      /**< WGS-84: integrate in local-level NED or in ECEF */
  nav_gravity_model gravity_model;/**< WGS-84: must equal the truth's */
  nav_vec3 g_l_mps2;              /**< flat Earth: uniform gravity in l, e.g. (0, 0, 9.80665) */
  bool clamp_vertical;            /**< WGS-84 tests: height and vertical velocity aided (see nav_ins_aid_vertical) */
} nav_ins_config;

typedef struct nav_ins nav_ins;

/** Defaults: flat Earth, first-order algorithm, NED, normal gravity, g = (0, 0, 9.80665). */
NAV_API nav_ins_config nav_ins_config_default(void);

/** Create a mechanization starting at @p initial. */
NAV_API NAV_NODISCARD nav_status nav_ins_create(const nav_ins_config *cfg, const nav_ins_state *initial,
                                                nav_ins **out);
NAV_API void nav_ins_destroy(nav_ins *ins);

/**
 * Advance by one IMU interval.
 * @return NAV_OK; NAV_ERR_NUMERIC if the increment or the resulting state is not finite (the
 *         state is then left as it was); NAV_ERR_INVALID_ARG for NULL or dt <= 0.
 */
NAV_API NAV_NODISCARD nav_status nav_ins_step(nav_ins *ins, const nav_imu_increment *imu);

/**
 * Reset height and vertical velocity to externally known values (vertical-channel aiding, used
 * by long free-inertial tests: the free vertical channel diverges as exp(t / 570 s)).
 * @param[in] h_m     ellipsoidal height [m]
 * @param[in] v_d_mps down velocity [m/s]
 */
NAV_API NAV_NODISCARD nav_status nav_ins_aid_vertical(nav_ins *ins, double h_m, double v_d_mps);

/** Current state (borrowed; valid until the next non-const call or destroy). */
NAV_API const nav_ins_state *nav_ins_get_state(const nav_ins *ins);

NAV_END_DECLS

#endif /* NAV_INS_H */
