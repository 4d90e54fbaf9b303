/*
 * Internal contract between the trajectory front end (traj.c) and the trajectory models.
 *
 * A model describes the motion in one of two ways:
 *
 * 1. LOCAL models (parametric, waypoints, segment scripts, motion-definition files, test
 *    motions, recorded references) give nav_local_kin: position as curvilinear N, E, D
 *    offsets from the scene origin with their first and second time derivatives, and the
 *    attitude relative to the local-level NED frame n at the body, with omega_nb_b and its
 *    derivative. traj.c turns this into the frame of the scene:
 *      - flat Earth: l = NED at the origin, n = l everywhere, taken as is;
 *      - WGS-84: lat = lat0 + N / (R_M(lat0) + h0), lon = lon0 + E / ((R_N(lat0) + h0) cos lat0),
 *        h = h0 - D (affine, so derivatives carry over exactly), then ECEF with analytic
 *        derivatives (numerics.md E3.9). A ground vehicle at D = const stays at constant
 *        ellipsoidal height.
 *    A model that is naturally geodetic (recorded reference) may instead fill nav_geo_kin
 *    through eval_geodetic.
 * 2. ECEF models (e.g. the polar great-circle flight of T5.5) give the state in e directly.
 *
 * All derivatives are analytic (never finite differences). Models must be smooth enough that
 * the attitude has a continuous angular acceleration.
 */
#ifndef NAV_TRAJ_INTERNAL_H
#define NAV_TRAJ_INTERNAL_H

#include "navcore/nav_earth.h"
#include "navcore/nav_traj.h"

/* Local kinematics relative to the scene origin and the local-level frame n. */
typedef struct nav_local_kin {
  nav_vec3 r_ned_m;      /* N, E, D offsets from the origin [m] (curvilinear on WGS-84) */
  nav_vec3 v_ned_mps;    /* d/dt of r_ned_m */
  nav_vec3 a_ned_mps2;   /* d2/dt2 of r_ned_m */
  nav_quat q_b_n;        /* attitude relative to local level */
  nav_vec3 w_nb_b_rps;   /* angular rate of b relative to n, body axes */
  nav_vec3 dw_nb_b_rps2; /* its derivative (body axes) */
} nav_local_kin;

/* Geodetic kinematics: position and its first two time derivatives, attitude relative to n. */
typedef struct nav_geo_kin {
  nav_geodetic pos;
  nav_vec3 dpos;  /* (lat_dot [rad/s], lon_dot [rad/s], h_dot [m/s]) */
  nav_vec3 ddpos; /* second derivatives */
  nav_quat q_b_n;
  nav_vec3 w_nb_b_rps;
  nav_vec3 dw_nb_b_rps2;
} nav_geo_kin;

/* A trajectory model. Exactly one of eval_local, eval_geodetic, eval_ecef is non-NULL. */
typedef struct nav_traj_model {
  const char *name;
  double duration_s;
  void *self;
  nav_status (*eval_local)(void *self, double t_s, nav_local_kin *out);
  /* Optional: eval_local without the position (r_ned_m is set to zero), for a caller that has the
   * position already (nav_traj_sample); every other field the same numbers as eval_local. */
  nav_status (*eval_local_nopos)(void *self, double t_s, nav_local_kin *out);
  nav_status (*eval_geodetic)(void *self, double t_s, nav_geo_kin *out);
  /* ECEF state: fills r_fb_f_m .. dw_fb_b_rps2 of nav_traj_state with f = e. */
  nav_status (*eval_ecef)(void *self, double t_s, nav_traj_state *out);
  /* Optional closed form of the integral of omega_nb_b over [t0, t1] (used on flat Earth,
   * where omega_ib_b = omega_nb_b); returns false when there is none. */
  bool (*rate_integral)(void *self, double t0_s, double t1_s, nav_vec3 *out);
  void (*destroy)(void *self);
} nav_traj_model;

/* Model constructors. Each validates its part of the scene; on failure it returns a status and
 * writes a message naming the offending waypoint/segment/field into msg (may be NULL). */
nav_status nav_traj_parametric_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                      size_t msg_size);
nav_status nav_traj_test_motion_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                       size_t msg_size);
nav_status nav_traj_waypoints_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                     size_t msg_size);
nav_status nav_traj_segments_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                    size_t msg_size);
/* Recorded reference (recorded.c): evaluates the fit stored in scene->trajectory.recorded. */
nav_status nav_traj_recorded_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                    size_t msg_size);

/** Segment boundaries B_0 .. B_count of a segment-script trajectory (0 for other models). */
size_t nav_traj_segment_boundaries(const nav_traj *traj, double *out, size_t cap);

#endif /* NAV_TRAJ_INTERNAL_H */
