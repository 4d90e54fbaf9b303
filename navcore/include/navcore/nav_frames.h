/**
 * @file nav_frames.h
 * @brief The frame of a scene and the local-level view of a state (style.md section 4).
 *
 * Frames: i ECI; e ECEF (WGS-84); n local-level NED at the vehicle; l scene-fixed NED at the
 * scene origin; b body FRD; s sensor. C_b_n maps b-coordinates to n: v_n = C_b_n v_b; chains
 * read C_b_e = C_n_e C_b_n. Quaternions are Hamilton, scalar first, q_b_n ~ C_b_n.
 *
 * Each scene works in one reference frame F in which truth and navigation states are
 * expressed: F = l on the flat Earth model (non-rotating, uniform gravity, n = l everywhere),
 * F = e on WGS-84. Position in "local curvilinear NED" about the origin is
 *   N = (lat - lat0)(R_M(lat0) + h0),  E = wrap(lon - lon0)(R_N(lat0) + h0) cos(lat0),  D = h0 - h
 * on WGS-84 (an affine map of geodetic coordinates) and the plain l coordinates on flat Earth.
 */
#ifndef NAV_FRAMES_H
#define NAV_FRAMES_H

#include "nav_earth.h"
#include "nav_export.h"
#include "nav_math.h"
#include "nav_scene.h"

NAV_BEGIN_DECLS

/** Reference frame of a scene. Plain value. */
typedef struct nav_frame {
  nav_earth_model model;
  nav_geodetic origin;
  double m_per_rad_lat; /**< R_M(lat0) + h0 [m/rad] */
  double m_per_rad_lon; /**< (R_N(lat0) + h0) cos(lat0) [m/rad]; 0 at a pole */
} nav_frame;

/** Local-level view of a state given in F. */
typedef struct nav_local_view {
  nav_geodetic pos;   /**< geodetic position (flat: of the point of l mapped through the origin) */
  nav_vec3 r_ned_m;   /**< local curvilinear NED about the origin [m] */
  nav_vec3 v_n_mps;   /**< velocity relative to F resolved in local-level NED [m/s] */
  nav_quat q_b_n;     /**< attitude relative to local level */
  nav_mat3 C_f_n;     /**< rotation from F to n at the point (identity on flat Earth) */
} nav_local_view;

NAV_API nav_frame nav_frame_from_scene(const nav_scene *scene);
/** Geodetic position of a local curvilinear NED point (flat: exact tangent-plane mapping). */
NAV_API nav_geodetic nav_frame_local_to_geodetic(const nav_frame *fr, nav_vec3 r_ned_m);
/** Local curvilinear NED of a geodetic point. */
NAV_API nav_vec3 nav_frame_geodetic_to_local(const nav_frame *fr, nav_geodetic p);
/** Local-level view of position r_fb_f, velocity v_fb_f and attitude q_b_f given in F. */
NAV_API nav_local_view nav_frame_view(const nav_frame *fr, nav_vec3 r_fb_f_m, nav_vec3 v_fb_f_mps, nav_quat q_b_f);

NAV_END_DECLS

#endif /* NAV_FRAMES_H */
