// The render-frame adapter (nav_view_frame.h): the only NED-related mapping in the viewer.
#include "navview/nav_view_frame.h"

#include "navcore/nav_math.h"

void NavNedToRender(const double v_ned[3], double v_r[3]) {
  const double n = v_ned[0], e = v_ned[1], d = v_ned[2];
  v_r[0] = e;
  v_r[1] = n;
  v_r[2] = -d;
}

void NavDcmToRenderQuat(const double c_b_n[9], double q_b_r[4]) {
  // C_b_r = C_n_r C_b_n: map each column of C_b_n (a body axis resolved in n) to frame r.
  nav_mat3 c_b_r;
  for (int j = 0; j < 3; ++j) {
    const double col_n[3] = {c_b_n[0 + j], c_b_n[3 + j], c_b_n[6 + j]};
    double col_r[3];
    NavNedToRender(col_n, col_r);
    for (int i = 0; i < 3; ++i)
      c_b_r.m[i][j] = col_r[i];
  }
  nav_quat q = nav_quat_from_dcm(c_b_r);
  if (q.w < 0.0) q = {-q.w, -q.x, -q.y, -q.z};
  q_b_r[0] = q.w;
  q_b_r[1] = q.x;
  q_b_r[2] = q.y;
  q_b_r[3] = q.z;
}

void NavEulerToRenderQuat(double roll_rad, double pitch_rad, double yaw_rad, double q_b_r[4]) {
  const nav_euler eul = {roll_rad, pitch_rad, yaw_rad};
  const nav_mat3 c_b_n = nav_euler_to_dcm(eul);
  NavDcmToRenderQuat(&c_b_n.m[0][0], q_b_r);
}
