/**
 * @file nav_view_frame.h
 * @brief The render frame r and its single adapter from NED (style.md sections 1 and 4).
 *
 * The viewer renders in frame r: x = east, y = north, z = up, with its origin at the origin of the
 * scene-fixed NED frame l. NavNedToRender is the one place where NED meets the render frame;
 * everything else (points, free vectors, attitude) goes through it.
 */
#ifndef NAV_VIEW_FRAME_H
#define NAV_VIEW_FRAME_H

/**
 * Map NED coordinates to render coordinates: r = (east, north, -down).
 * The map is linear (both frames share their origin), so it applies alike to points of frame l
 * and to free vectors resolved in n or l. It is a proper rotation (det +1).
 * @param[in]  v_ned  north, east, down
 * @param[out] v_r    x (east), y (north), z (up); may alias v_ned
 */
void NavNedToRender(const double v_ned[3], double v_r[3]);

/**
 * Attitude of the body (FRD) in the render frame from C_b_n (row-major 3x3): C_b_r = C_n_r C_b_n,
 * built by applying NavNedToRender to each column of C_b_n. Returns a unit Hamilton quaternion
 * {w, x, y, z} with w >= 0 (the form vtkGlyph3DMapper takes with SetOrientationModeToQuaternion).
 * @param[in]  c_b_n  row-major C_b_n
 * @param[out] q_b_r  {w, x, y, z}
 */
void NavDcmToRenderQuat(const double c_b_n[9], double q_b_r[4]);

/**
 * NavDcmToRenderQuat from the ZYX Euler angles of C_b_n.
 * @param[in]  roll_rad, pitch_rad, yaw_rad  ZYX Euler angles of C_b_n [rad]
 * @param[out] q_b_r  {w, x, y, z}
 */
void NavEulerToRenderQuat(double roll_rad, double pitch_rad, double yaw_rad, double q_b_r[4]);

#endif /* NAV_VIEW_FRAME_H */
