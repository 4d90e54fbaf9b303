/* Pseudorange geometry and the least-squares single-point position (nav_gnss_sat.h). */
#include <math.h>
#include <string.h>

#include "navcore/nav_gnss_sat.h"

/* Satellite position at transmit time t_tx, rotated into the ECEF frame of the receive time by the
 * Earth's rotation during the flight tau: r = R3(omega_e tau) r_s (Kaplan and Hegarty, 3rd ed.,
 * section 2.5.2; the rotation about z by +omega_e tau maps the earlier frame to the later). */
static nav_vec3 sat_at(const nav_gnss_orbit *o, double t_tx, double tau) {
  nav_vec3 rs;
  nav_gnss_orbit_state(o, t_tx, &rs, NULL);
  const double a = NAV_GPS_OMEGA_E_RPS * tau, c = cos(a), s = sin(a);
  const nav_vec3 r = {c * rs.x + s * rs.y, -s * rs.x + c * rs.y, rs.z};
  return r;
}

static double dist(nav_vec3 a, nav_vec3 b) {
  const double dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return sqrt(dx * dx + dy * dy + dz * dz);
}

double nav_gnss_geometric_range_m(const nav_gnss_orbit *o, double t_rx_s, nav_vec3 r_rx_e_m, nav_vec3 *r_es_e_m) {
  double tau = 0.075, rho = 0.0;
  nav_vec3 r = {0};
  for (int it = 0; it < 10; ++it) {
    r = sat_at(o, t_rx_s - tau, tau);
    rho = dist(r, r_rx_e_m);
    const double tau1 = rho / NAV_GNSS_C_MPS;
    const double d = fabs(tau1 - tau);
    tau = tau1;
    if (d < 1e-12) {
      break;
    }
  }
  r = sat_at(o, t_rx_s - tau, tau);
  rho = dist(r, r_rx_e_m);
  if (r_es_e_m) {
    *r_es_e_m = r;
  }
  return rho;
}

/* Solve the symmetric positive-definite system A x = b (m <= 5) by Cholesky; false if not SPD. */
static bool spd_solve(double a[5][5], const double *b, double *x, int m) {
  double l[5][5] = {{0}};
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j <= i; ++j) {
      double sum = a[i][j];
      for (int k = 0; k < j; ++k) {
        sum -= l[i][k] * l[j][k];
      }
      if (i == j) {
        if (!(sum > 0.0)) {
          return false;
        }
        l[i][i] = sqrt(sum);
      } else {
        l[i][j] = sum / l[j][j];
      }
    }
  }
  double y[5];
  for (int i = 0; i < m; ++i) {
    double sum = b[i];
    for (int k = 0; k < i; ++k) {
      sum -= l[i][k] * y[k];
    }
    y[i] = sum / l[i][i];
  }
  for (int i = m - 1; i >= 0; --i) {
    double sum = y[i];
    for (int k = i + 1; k < m; ++k) {
      sum -= l[k][i] * x[k];
    }
    x[i] = sum / l[i][i];
  }
  return true;
}

/* The upper-left 3 x 3 block of (H'H)^-1 for the m-column rows h (n x 5), and the square roots of
 * its diagonal (the per-axis DOP). false if H'H is singular. */
static bool axis_dop(int n, const double (*h)[5], int m, nav_vec3 *out, double q_out[3][3]) {
  double hth[5][5] = {{0}};
  for (int i = 0; i < n; ++i) {
    for (int p = 0; p < m; ++p) {
      for (int q = 0; q < m; ++q) {
        hth[p][q] += h[i][p] * h[i][q];
      }
    }
  }
  double d[3];
  for (int a = 0; a < 3; ++a) {
    double e[5] = {0}, col[5];
    e[a] = 1.0;
    if (!spd_solve(hth, e, col, m) || !(col[a] > 0.0)) {
      return false;
    }
    d[a] = sqrt(col[a]);
    for (int b = 0; b < 3; ++b) {
      q_out[b][a] = col[b];
    }
  }
  /* Exactly symmetric (the two triangles come from different solves). */
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < a; ++b) {
      const double avg = 0.5 * (q_out[a][b] + q_out[b][a]);
      q_out[a][b] = avg;
      q_out[b][a] = avg;
    }
  }
  *out = (nav_vec3){d[0], d[1], d[2]};
  return true;
}

nav_status nav_gnss_pvt_solve(int n, const nav_gnss_pseudorange *pr, double t_rx_s, nav_gnss_pvt *out) {
  if (!pr || !out || n <= 0 || n > NAV_GNSS_MAX_SATS || !isfinite(t_rx_s)) {
    return NAV_ERR_INVALID_ARG;
  }
  int col_of[NAV_GNSS_SYS_COUNT] = {-1, -1};
  int nclk = 0;
  for (int i = 0; i < n; ++i) {
    if (!pr[i].sat || !isfinite(pr[i].p_m) || (int)pr[i].sat->system < 0 ||
        (int)pr[i].sat->system >= NAV_GNSS_SYS_COUNT) {
      return NAV_ERR_INVALID_ARG;
    }
    if (col_of[pr[i].sat->system] < 0) {
      col_of[pr[i].sat->system] = 3 + nclk++;
    }
  }
  const int m = 3 + nclk;
  if (n < m) {
    return NAV_ERR_INVALID_ARG;
  }
  /* Satellite positions at t_rx - P/c: fixed for the whole iteration (P is measured). */
  nav_vec3 rs[NAV_GNSS_MAX_SATS];
  for (int i = 0; i < n; ++i) {
    nav_gnss_orbit_state(pr[i].sat, t_rx_s - pr[i].p_m / NAV_GNSS_C_MPS, &rs[i], NULL);
  }
  double x[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
  int it = 0;
  bool converged = false;
  double res_rms = 0.0;
  for (it = 1; it <= 20; ++it) {
    double hth[5][5] = {{0}}, htr[5] = {0};
    double ss = 0.0;
    const nav_vec3 rx = {x[0], x[1], x[2]};
    for (int i = 0; i < n; ++i) {
      /* Sagnac: rotate by omega_e times the flight time from the current geometry */
      const double tau = dist(rs[i], rx) / NAV_GNSS_C_MPS;
      const double a = NAV_GPS_OMEGA_E_RPS * tau, c = cos(a), s = sin(a);
      const nav_vec3 r = {c * rs[i].x + s * rs[i].y, -s * rs[i].x + c * rs[i].y, rs[i].z};
      const double rho = dist(r, rx);
      const int k = col_of[pr[i].sat->system];
      const double res = pr[i].p_m - (rho + x[k]);
      double h[5] = {0};
      h[0] = (rx.x - r.x) / rho;
      h[1] = (rx.y - r.y) / rho;
      h[2] = (rx.z - r.z) / rho;
      h[k] = 1.0;
      for (int p = 0; p < m; ++p) {
        htr[p] += h[p] * res;
        for (int q = 0; q < m; ++q) {
          hth[p][q] += h[p] * h[q];
        }
      }
      ss += res * res;
    }
    double dx[5];
    if (!spd_solve(hth, htr, dx, m)) {
      return NAV_ERR_NUMERIC;
    }
    double norm = 0.0;
    for (int p = 0; p < m; ++p) {
      x[p] += dx[p];
      norm += dx[p] * dx[p];
    }
    res_rms = sqrt(ss / n);
    if (sqrt(norm) < 1e-4) {
      converged = true;
      break;
    }
  }
  if (!converged) {
    return NAV_ERR_NOT_CONVERGED;
  }
  nav_gnss_pvt o;
  memset(&o, 0, sizeof o);
  o.r_e_m = (nav_vec3){x[0], x[1], x[2]};
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    o.clock_m[s] = col_of[s] >= 0 ? x[col_of[s]] : 0.0;
  }
  o.n_used = n;
  o.iterations = it;
  /* post-fit residuals and DOP at the solution */
  const nav_geodetic g = nav_earth_ecef_to_geodetic(o.r_e_m);
  double az[NAV_GNSS_MAX_SATS], el[NAV_GNSS_MAX_SATS];
  nav_gnss_system sy[NAV_GNSS_MAX_SATS];
  double ss = 0.0;
  for (int i = 0; i < n; ++i) {
    nav_vec3 r;
    const double rho = nav_gnss_geometric_range_m(pr[i].sat, t_rx_s - o.clock_m[pr[i].sat->system] / NAV_GNSS_C_MPS,
                                                   o.r_e_m, &r);
    const double res = pr[i].p_m - rho - o.clock_m[pr[i].sat->system];
    ss += res * res;
    nav_gnss_az_el(g, r, &az[i], &el[i]);
    sy[i] = pr[i].sat->system;
  }
  (void)res_rms;
  o.residual_rms_m = sqrt(ss / n);
  o.dop = nav_gnss_dop_compute(n, az, el, sy);
  /* Per-axis DOP from the rows of nav_gnss_dop_compute (NED lines of sight, clock columns). */
  double hn[NAV_GNSS_MAX_SATS][5];
  for (int i = 0; i < n; ++i) {
    memset(hn[i], 0, sizeof hn[i]);
    hn[i][0] = -cos(el[i]) * cos(az[i]);
    hn[i][1] = -cos(el[i]) * sin(az[i]);
    hn[i][2] = sin(el[i]);
    hn[i][col_of[sy[i]]] = 1.0;
  }
  if (!axis_dop(n, (const double(*)[5])hn, m, &o.dop_ned, o.q_ned)) {
    o.dop_ned = (nav_vec3){NAN, NAN, NAN};
  }
  *out = o;
  return NAV_OK;
}

nav_status nav_gnss_pvt_velocity(int n, const nav_gnss_range_rate *rr, double t_rx_s, const nav_gnss_pvt *pos,
                                 nav_gnss_pvt_vel *out) {
  if (!rr || !pos || !out || n < 4 || n > NAV_GNSS_MAX_SATS || !isfinite(t_rx_s)) {
    return NAV_ERR_INVALID_ARG;
  }
  const nav_geodetic g = nav_earth_ecef_to_geodetic(pos->r_e_m);
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(g.lat_rad, g.lon_rad);
  double h[NAV_GNSS_MAX_SATS][5], z[NAV_GNSS_MAX_SATS];
  for (int i = 0; i < n; ++i) {
    const nav_gnss_orbit *o = rr[i].sat;
    if (!o || !isfinite(rr[i].rr_mps) || (int)o->system < 0 || (int)o->system >= NAV_GNSS_SYS_COUNT) {
      return NAV_ERR_INVALID_ARG;
    }
    /* Satellite at the transmit time of the solution's clock, then its velocity at that time
     * rotated into the receive-time frame like the position (Sagnac). */
    nav_vec3 r_s;
    const double t = t_rx_s - pos->clock_m[o->system] / NAV_GNSS_C_MPS;
    const double rho = nav_gnss_geometric_range_m(o, t, pos->r_e_m, &r_s);
    const double tau = rho / NAV_GNSS_C_MPS;
    nav_vec3 rs0, vs0;
    nav_gnss_orbit_state(o, t - tau, &rs0, &vs0);
    const double a = NAV_GPS_OMEGA_E_RPS * tau, c = cos(a), s = sin(a);
    const nav_vec3 v_s = {c * vs0.x + s * vs0.y, -s * vs0.x + c * vs0.y, vs0.z};
    /* u: unit line of sight receiver -> satellite, ECEF and NED. */
    const nav_vec3 u = nav_vec3_scale(nav_vec3_sub(r_s, pos->r_e_m), 1.0 / rho);
    const nav_vec3 u_n = nav_mat3_tmul_vec(C_n_e, u);
    /* rr = (u'v_s - u'v) / k + d with k = 1 + u'v_s / c (d tau / dt of the light time). */
    const double k = 1.0 + nav_vec3_dot(u, v_s) / NAV_GNSS_C_MPS;
    z[i] = rr[i].rr_mps - nav_vec3_dot(u, v_s) / k;
    h[i][0] = -u_n.x / k;
    h[i][1] = -u_n.y / k;
    h[i][2] = -u_n.z / k;
    h[i][3] = 1.0;
    h[i][4] = 0.0;
  }
  double hth[5][5] = {{0}}, htz[5] = {0}, x[5];
  for (int i = 0; i < n; ++i) {
    for (int p = 0; p < 4; ++p) {
      htz[p] += h[i][p] * z[i];
      for (int q = 0; q < 4; ++q) {
        hth[p][q] += h[i][p] * h[i][q];
      }
    }
  }
  nav_gnss_pvt_vel o;
  if (!spd_solve(hth, htz, x, 4) || !axis_dop(n, (const double(*)[5])h, 4, &o.dop_ned, o.q_ned)) {
    return NAV_ERR_NUMERIC;
  }
  o.v_n_mps = (nav_vec3){x[0], x[1], x[2]};
  o.drift_mps = x[3];
  *out = o;
  return NAV_OK;
}

bool nav_gnss_cofactor_ned(int n, const double *az_rad, const double *el_rad, const nav_gnss_system *sys,
                           bool one_clock, double q_ned[3][3]) {
  if (!az_rad || !el_rad || !sys || !q_ned || n < 4 || n > NAV_GNSS_MAX_SATS) {
    return false;
  }
  int col_of[NAV_GNSS_SYS_COUNT] = {-1, -1};
  int nclk = 0;
  for (int i = 0; i < n; ++i) {
    if ((int)sys[i] < 0 || (int)sys[i] >= NAV_GNSS_SYS_COUNT) {
      return false;
    }
    if (col_of[sys[i]] < 0) {
      col_of[sys[i]] = one_clock ? 3 : 3 + nclk++;
    }
  }
  const int m = one_clock ? 4 : 3 + nclk;
  if (n < m) {
    return false;
  }
  double h[NAV_GNSS_MAX_SATS][5];
  for (int i = 0; i < n; ++i) {
    memset(h[i], 0, sizeof h[i]);
    h[i][0] = -cos(el_rad[i]) * cos(az_rad[i]);
    h[i][1] = -cos(el_rad[i]) * sin(az_rad[i]);
    h[i][2] = sin(el_rad[i]);
    h[i][col_of[sys[i]]] = 1.0;
  }
  nav_vec3 d;
  double q[3][3];
  if (!axis_dop(n, (const double(*)[5])h, m, &d, q)) {
    return false;
  }
  memcpy(q_ned, q, sizeof q);
  return true;
}
