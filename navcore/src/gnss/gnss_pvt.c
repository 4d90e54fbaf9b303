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
  *out = o;
  return NAV_OK;
}
