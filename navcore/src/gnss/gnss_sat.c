/* GNSS constellations: satellite orbits (GPS user algorithm), the published nominal
 * constellations, visibility with sky masks, and DOP. Formulas and constants:
 * docs/gnss-constellations.md. */
#include "navcore/nav_gnss_sat.h"

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#define PI 3.14159265358979323846
#define DEG (PI / 180.0)

/* Days from 1970-01-01 to a proleptic Gregorian date (H. Hinnant's days_from_civil algorithm). */
static long days_from_civil(long y, long m, long d) {
  y -= m <= 2;
  const long era = (y >= 0 ? y : y - 399) / 400;
  const long yoe = y - era * 400;
  const long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + doe - 719468;
}

double nav_gnss_gps_time_s(int year, int month, int day, int hour, int minute, double second) {
  /* GPS epoch: 1980-01-06 00:00:00 (IS-GPS-200N 6.2.4). */
  const long days = days_from_civil(year, month, day) - days_from_civil(1980, 1, 6);
  return (double)days * 86400.0 + (double)hour * 3600.0 + (double)minute * 60.0 + second;
}

void nav_gnss_orbit_state(const nav_gnss_orbit *o, double t, nav_vec3 *r_es_e_m, nav_vec3 *v_es_e_mps) {
  /* IS-GPS-200N Table 20-IV, "Elements of Coordinate Systems"; the harmonic corrections (C_us,
   * C_uc, C_rs, C_rc, C_is, C_ic) only when the orbit has any (0 for almanacs, Table 20-VI), so
   * almanac and nominal orbits take exactly the arithmetic they always took. */
  const double mu = NAV_GPS_MU_M3PS2, we = NAV_GPS_OMEGA_E_RPS;
  const double A = o->sqrt_a_sqrtm * o->sqrt_a_sqrtm;
  const double n0 = sqrt(mu / (A * A * A));
  const double tk = t - o->toe_s;
  const double n = n0 + o->delta_n_rps;
  const double Mk = o->m0_rad + n * tk;
  double E = Mk;
  for (int it = 0; it < 30; ++it) { /* Newton on E - e sin E = M */
    const double dE = (Mk - E + o->e * sin(E)) / (1.0 - o->e * cos(E));
    E += dE;
    if (fabs(dE) < 1e-15) {
      break;
    }
  }
  const double sE = sin(E), cE = cos(E);
  const double sq = sqrt(1.0 - o->e * o->e);
  const double nu = atan2(sq * sE, cE - o->e);
  const bool harmonics = o->cuc_rad != 0.0 || o->cus_rad != 0.0 || o->crc_m != 0.0 || o->crs_m != 0.0 ||
                         o->cic_rad != 0.0 || o->cis_rad != 0.0;
  const double phi = nu + o->w_rad; /* argument of latitude before the corrections */
  double du = 0.0, dr = 0.0, di = 0.0, s2 = 0.0, c2 = 0.0;
  if (harmonics) {
    s2 = sin(2.0 * phi);
    c2 = cos(2.0 * phi);
    du = o->cus_rad * s2 + o->cuc_rad * c2;
    dr = o->crs_m * s2 + o->crc_m * c2;
    di = o->cis_rad * s2 + o->cic_rad * c2;
  }
  const double u = harmonics ? phi + du : phi;
  const double r = harmonics ? A * (1.0 - o->e * cE) + dr : A * (1.0 - o->e * cE);
  const double inc = harmonics ? o->i0_rad + o->idot_rps * tk + di : o->i0_rad + o->idot_rps * tk;
  const double xp = r * cos(u), yp = r * sin(u);
  /* Omega_k = Omega_0 + (Omega_dot - Omega_dot_e) t_k - Omega_dot_e t_oe, t_oe in seconds of week. */
  const double toe_sow = o->toe_s - floor(o->toe_s / NAV_GNSS_WEEK_S) * NAV_GNSS_WEEK_S;
  const double Om = o->omega0_rad + (o->omega_dot_rps - we) * tk - we * toe_sow;
  const double cO = cos(Om), sO = sin(Om), ci = cos(inc), si = sin(inc);
  if (r_es_e_m) {
    r_es_e_m->x = xp * cO - yp * ci * sO;
    r_es_e_m->y = xp * sO + yp * ci * cO;
    r_es_e_m->z = yp * si;
  }
  if (v_es_e_mps) {
    /* IS-GPS-200N Table 20-IV, SV velocity: E_dot, nu_dot, u_dot, r_dot, Omega_dot_k, x'_dot, y'_dot. */
    const double Edot = n / (1.0 - o->e * cE);
    double nudot = Edot * sq / (1.0 - o->e * cE);
    double rdot = A * o->e * sE * Edot;
    double idot = o->idot_rps;
    if (harmonics) {
      /* d/dt of the corrections: 2 phi_dot (C_s cos 2 phi - C_c sin 2 phi), phi_dot = nu_dot. */
      rdot += 2.0 * nudot * (o->crs_m * c2 - o->crc_m * s2);
      idot += 2.0 * nudot * (o->cis_rad * c2 - o->cic_rad * s2);
      nudot *= 1.0 + 2.0 * (o->cus_rad * c2 - o->cuc_rad * s2); /* u_dot */
    }
    const double Omdot = o->omega_dot_rps - we;
    const double xpd = rdot * cos(u) - yp * nudot;
    const double ypd = rdot * sin(u) + xp * nudot;
    v_es_e_mps->x = -xp * Omdot * sO + xpd * cO - ypd * sO * ci - yp * (Omdot * cO * ci - idot * sO * si);
    v_es_e_mps->y = xp * Omdot * cO + xpd * sO + ypd * cO * ci - yp * (Omdot * sO * ci + idot * cO * si);
    v_es_e_mps->z = yp * idot * ci + ypd * si;
  }
}

/* A circular orbit of radius a_m whose node has Greenwich longitude lon_node at t_ref, moving at
 * rate lon_rate (Omega_dot - omega_e), with argument of latitude u at t_ref moving at u_rate, in the
 * Table 20-IV form with toe = t_ref: Omega_0 = lon_node + omega_e toe_sow, M0 = u, w = 0, e = 0,
 * delta_n = u_rate - sqrt(mu/a^3). */
static nav_gnss_orbit circular(nav_gnss_system sys, int prn, double t_ref, double a_m, double inc_rad,
                               double lon_node_rad, double omega_dot_rps, double u_rad, double u_rate_rps) {
  nav_gnss_orbit o = {0};
  o.system = sys;
  o.prn = prn;
  o.toe_s = t_ref;
  o.sqrt_a_sqrtm = sqrt(a_m);
  o.i0_rad = inc_rad;
  const double toe_sow = t_ref - floor(t_ref / NAV_GNSS_WEEK_S) * NAV_GNSS_WEEK_S;
  o.omega0_rad = remainder(lon_node_rad + NAV_GPS_OMEGA_E_RPS * toe_sow, 2.0 * PI);
  o.omega_dot_rps = omega_dot_rps;
  o.m0_rad = remainder(u_rad, 2.0 * PI);
  o.delta_n_rps = u_rate_rps - sqrt(NAV_GPS_MU_M3PS2 / (a_m * a_m * a_m));
  return o;
}

nav_status nav_gnss_add_gps_nominal(nav_gnss_constellation *c, double t_gps_s) {
  if (!c || !isfinite(t_gps_s) || c->n < 0) {
    return NAV_ERR_INVALID_ARG;
  }
  if (c->n + 24 > NAV_GNSS_MAX_SATS) {
    return NAV_ERR_OUT_OF_RANGE;
  }
  /* GPS SPS Performance Standard, 4th ed. (2008), Table 3.1-1 (the same in the 3rd ed., 2001,
   * Table 3-1): RAAN [deg] of planes A..F and argument of latitude [deg] of slots 1..4, as of the
   * defined epoch 0000Z 1 July 1993, Greenwich hour angle 18 h 36 min 14.4 s (FK5/J2000). */
  static const double raan_deg[6] = {272.847, 332.847, 32.847, 92.847, 152.847, 212.847};
  static const double arglat_deg[6][4] = {
      {268.126, 161.786, 11.676, 41.806},   /* A1..A4 */
      {80.956, 173.336, 309.976, 204.376},  /* B1..B4 */
      {111.876, 11.796, 339.666, 241.556},  /* C1..C4 */
      {135.226, 265.446, 35.156, 167.356},  /* D1..D4 */
      {197.046, 302.596, 66.066, 333.686},  /* E1..E4 */
      {238.886, 345.226, 105.206, 135.346}, /* F1..F4 */
  };
  const double gha_deg = (18.0 + 36.0 / 60.0 + 14.4 / 3600.0) * 15.0;
  /* The defined epoch is 0000Z (UTC); GPS - UTC = 9 s from 1993-07-01 (after the leap second of
   * 1993-06-30, USNO leap-second table). */
  const double t0 = nav_gnss_gps_time_s(1993, 7, 1, 0, 0, 9.0);
  /* Semi-major axis 26 559.7 km, inclination 55 deg (SPS PS 2008 Table 3.1-2 reference orbit);
   * rate of right ascension -4.4874e-7 deg/s (SPS PS 2001 Table A-2-1, the nominal plan in
   * almanac form). Ground tracks repeat: the satellite makes two revolutions while the node
   * turns once relative to Earth, so u_dot = 2 (omega_e - Omega_dot) (docs 2.2). */
  const double a_m = 26559.7e3, inc = 55.0 * DEG;
  const double omega_dot = -4.4874e-7 * DEG;
  const double lon_rate = omega_dot - NAV_GPS_OMEGA_E_RPS;
  const double u_rate = -2.0 * lon_rate;
  const double dt = t_gps_s - t0;
  int prn = 1;
  for (int p = 0; p < 6; ++p) {
    const double lon0 = (raan_deg[p] - gha_deg) * DEG;
    const double lon = remainder(lon0 + remainder(lon_rate * dt, 2.0 * PI), 2.0 * PI);
    for (int s = 0; s < 4; ++s) {
      const double u = remainder(arglat_deg[p][s] * DEG + remainder(u_rate * dt, 2.0 * PI), 2.0 * PI);
      c->sats[c->n++] = circular(NAV_GNSS_SYS_GPS, prn++, t_gps_s, a_m, inc, lon, omega_dot, u, u_rate);
    }
  }
  return NAV_OK;
}

nav_status nav_gnss_add_glonass_nominal(nav_gnss_constellation *c, double t_gps_s, double node1_lon_rad) {
  if (!c || !isfinite(t_gps_s) || !isfinite(node1_lon_rad) || c->n < 0) {
    return NAV_ERR_INVALID_ARG;
  }
  if (c->n + 24 > NAV_GNSS_MAX_SATS) {
    return NAV_ERR_OUT_OF_RANGE;
  }
  /* ICD GLONASS Edition 5.1 (2008): section 3.5 (24 slots, 3 planes, 120 deg node spacing, 45 deg
   * in-plane and 15 deg inter-plane argument-of-latitude spacing, inclination 64.8 deg, draconian
   * period 11 h 15 min 44 s); PZ-90 constants of Table 3.2: GM = 398600.4418e9 m^3/s^2,
   * a_e = 6378136 m, J2 = 1082.62575e-6. */
  const double gm = 398600.4418e9, ae = 6378136.0, j2 = 1082.62575e-6;
  const double t_dr = 11.0 * 3600.0 + 15.0 * 60.0 + 44.0;
  const double inc = 64.8 * DEG;
  const double u_rate = 2.0 * PI / t_dr;
  /* Semi-major axis from Kepler's third law with the draconian mean motion (J2 changes it by
   * about 1e-4, docs 2.3); nodal regression Omega_dot = -3/2 n J2 (a_e/a)^2 cos i (secular J2
   * rate of a circular orbit, Vallado, Fundamentals of Astrodynamics, 4th ed., eq. 9-41). */
  const double a_m = cbrt(gm / (u_rate * u_rate));
  const double omega_dot = -1.5 * u_rate * j2 * (ae / a_m) * (ae / a_m) * cos(inc);
  for (int k = 0; k < 3; ++k) {
    const double lon = remainder(node1_lon_rad + (double)k * 120.0 * DEG, 2.0 * PI);
    for (int j = 0; j < 8; ++j) {
      const double u = remainder(-(double)j * 45.0 * DEG + (double)k * 15.0 * DEG, 2.0 * PI);
      c->sats[c->n++] = circular(NAV_GNSS_SYS_GLONASS, 8 * k + j + 1, t_gps_s, a_m, inc, lon, omega_dot, u,
                                 u_rate);
    }
  }
  return NAV_OK;
}

/* Relative azimuth folded for the profile: wrap to [0, 2 pi). */
static double wrap_2pi(double a) {
  double w = fmod(a, 2.0 * PI);
  if (w < 0.0) {
    w += 2.0 * PI;
  }
  return w;
}

double nav_gnss_mask_elevation_rad(const nav_gnss_sky_mask *m, double az_rad, double heading_rad) {
  double el = m->elevation_mask_rad;
  if (m->n_profile > 0) {
    const double az = wrap_2pi(az_rad);
    const int n = m->n_profile;
    double prof = m->profile_el_rad[0];
    if (n > 1) {
      /* find the segment [k, k+1] (cyclic) containing az */
      int k = n - 1;
      for (int i = 0; i < n; ++i) {
        if (m->profile_az_rad[i] <= az) {
          k = i;
        }
      }
      const int k1 = (k + 1) % n;
      double a0 = m->profile_az_rad[k], a1 = m->profile_az_rad[k1], x = az;
      if (a1 <= a0) {
        a1 += 2.0 * PI;
      }
      if (x < a0) {
        x += 2.0 * PI;
      }
      const double f = (a1 > a0) ? (x - a0) / (a1 - a0) : 0.0;
      prof = m->profile_el_rad[k] + f * (m->profile_el_rad[k1] - m->profile_el_rad[k]);
    }
    if (prof > el) {
      el = prof;
    }
  }
  if (m->canyon_height_m > 0.0) {
    /* wall on the right for relative azimuth in (0, pi), on the left for (pi, 2 pi) */
    const double rel = wrap_2pi(az_rad - heading_rad);
    const double s = sin(rel);
    const double d = s >= 0.0 ? m->canyon_right_m : m->canyon_left_m;
    const double wall = atan2(m->canyon_height_m * fabs(s), d);
    if (wall > el) {
      el = wall;
    }
  }
  return el;
}

void nav_gnss_az_el(nav_geodetic rx, nav_vec3 r_es_e_m, double *az_rad, double *el_rad) {
  const nav_vec3 r_rx = nav_earth_geodetic_to_ecef(rx);
  const double dx = r_es_e_m.x - r_rx.x, dy = r_es_e_m.y - r_rx.y, dz = r_es_e_m.z - r_rx.z;
  const double sl = sin(rx.lat_rad), cl = cos(rx.lat_rad), so = sin(rx.lon_rad), co = cos(rx.lon_rad);
  /* NED components with C_e_n (Groves, 2nd ed., eq. 2.150 transposed). */
  const double n = -sl * co * dx - sl * so * dy + cl * dz;
  const double e = -so * dx + co * dy;
  const double d = -cl * co * dx - cl * so * dy - sl * dz;
  *az_rad = wrap_2pi(atan2(e, n));
  *el_rad = atan2(-d, sqrt(n * n + e * e));
}

/* Invert a symmetric positive-definite m x m matrix (m <= 5) by Gauss-Jordan with partial
 * pivoting; false when singular (relative pivot below 1e-12). */
static bool invert(double a[5][5], double inv[5][5], int m) {
  double w[5][10];
  double scale = 0.0;
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      w[i][j] = a[i][j];
      w[i][m + j] = (i == j) ? 1.0 : 0.0;
      if (fabs(a[i][j]) > scale) {
        scale = fabs(a[i][j]);
      }
    }
  }
  if (!(scale > 0.0)) {
    return false;
  }
  for (int c = 0; c < m; ++c) {
    int p = c;
    for (int r = c + 1; r < m; ++r) {
      if (fabs(w[r][c]) > fabs(w[p][c])) {
        p = r;
      }
    }
    if (fabs(w[p][c]) < 1e-12 * scale) {
      return false;
    }
    if (p != c) {
      for (int j = 0; j < 2 * m; ++j) {
        const double t = w[p][j];
        w[p][j] = w[c][j];
        w[c][j] = t;
      }
    }
    const double piv = w[c][c];
    for (int j = 0; j < 2 * m; ++j) {
      w[c][j] /= piv;
    }
    for (int r = 0; r < m; ++r) {
      if (r != c && w[r][c] != 0.0) {
        const double f = w[r][c];
        for (int j = 0; j < 2 * m; ++j) {
          w[r][j] -= f * w[c][j];
        }
      }
    }
  }
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      inv[i][j] = w[i][m + j];
    }
  }
  return true;
}

nav_gnss_dop nav_gnss_dop_compute(int n, const double *az_rad, const double *el_rad, const nav_gnss_system *sys) {
  nav_gnss_dop d = {.n_visible = n, .valid = false, .gdop = NAN, .pdop = NAN, .hdop = NAN, .vdop = NAN, .tdop = NAN};
  if (n <= 0 || !az_rad || !el_rad || !sys) {
    return d;
  }
  int col_of[NAV_GNSS_SYS_COUNT];
  int nclk = 0;
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    col_of[s] = -1;
  }
  for (int i = 0; i < n; ++i) {
    const int s = (int)sys[i];
    if (s < 0 || s >= NAV_GNSS_SYS_COUNT) {
      return d;
    }
    if (col_of[s] < 0) {
      col_of[s] = 3 + nclk++;
    }
  }
  const int m = 3 + nclk;
  if (n < m) {
    return d;
  }
  double gtg[5][5] = {{0}};
  for (int i = 0; i < n; ++i) {
    double g[5] = {0};
    const double ce = cos(el_rad[i]);
    /* unit vector receiver -> satellite in NED is (ce cos az, ce sin az, -sin el); G row = -u'. */
    g[0] = -ce * cos(az_rad[i]);
    g[1] = -ce * sin(az_rad[i]);
    g[2] = sin(el_rad[i]);
    g[col_of[(int)sys[i]]] = 1.0;
    for (int r = 0; r < m; ++r) {
      for (int c = 0; c < m; ++c) {
        gtg[r][c] += g[r] * g[c];
      }
    }
  }
  double q[5][5];
  if (!invert(gtg, q, m)) {
    return d;
  }
  double tclk = 0.0;
  for (int k = 3; k < m; ++k) {
    tclk += q[k][k];
  }
  const double qp = q[0][0] + q[1][1] + q[2][2];
  if (!(qp > 0.0) || !(tclk > 0.0) || !(q[2][2] > 0.0)) {
    return d;
  }
  d.valid = true;
  d.pdop = sqrt(qp);
  d.hdop = sqrt(q[0][0] + q[1][1]);
  d.vdop = sqrt(q[2][2]);
  d.tdop = sqrt(tclk);
  d.gdop = sqrt(qp + tclk);
  return d;
}

nav_status nav_gnss_visibility(const nav_gnss_constellation *c, const nav_gnss_sky_mask *mask, double t_gps_s,
                               nav_geodetic rx, double heading_rad, nav_gnss_sat_view *views, nav_gnss_dop *dop) {
  if (!c || !mask || !dop || c->n < 0 || c->n > NAV_GNSS_MAX_SATS || !isfinite(t_gps_s) ||
      !isfinite(rx.lat_rad) || !isfinite(rx.lon_rad) || !isfinite(rx.h_m) || !isfinite(heading_rad)) {
    return NAV_ERR_INVALID_ARG;
  }
  double az[NAV_GNSS_MAX_SATS], el[NAV_GNSS_MAX_SATS];
  nav_gnss_system sy[NAV_GNSS_MAX_SATS];
  int nv = 0;
  for (int i = 0; i < c->n; ++i) {
    nav_gnss_sat_view v = {0};
    v.system = c->sats[i].system;
    v.prn = c->sats[i].prn;
    nav_gnss_orbit_state(&c->sats[i], t_gps_s, &v.r_es_e_m, &v.v_es_e_mps);
    nav_gnss_az_el(rx, v.r_es_e_m, &v.az_rad, &v.el_rad);
    v.visible = c->sats[i].health == 0 && v.el_rad > 0.0 &&
                v.el_rad >= nav_gnss_mask_elevation_rad(mask, v.az_rad, heading_rad);
    if (v.visible) {
      az[nv] = v.az_rad;
      el[nv] = v.el_rad;
      sy[nv] = v.system;
      ++nv;
    }
    if (views) {
      views[i] = v;
    }
  }
  *dop = nav_gnss_dop_compute(nv, az, el, sy);
  return NAV_OK;
}

/* ---------------------------------------------------------------- scene configuration */

nav_gnss_constellation_config nav_gnss_constellation_config_default(void) {
  nav_gnss_constellation_config c;
  memset(&c, 0, sizeof c);
  c.enabled = false;
  c.gps = NAV_GNSS_SOURCE_NOMINAL;
  c.glonass = NAV_GNSS_SOURCE_OFF;
  c.epoch_gps_s = nav_gnss_gps_time_s(2026, 1, 1, 0, 0, 0.0);
  c.glonass_node1_lon_rad = 0.0;
  c.mask.elevation_mask_rad = 10.0 * DEG;
  c.min_satellites_for_fix = 4;
  c.fixes = NAV_GNSS_FIXES_MODEL;
  /* Low-quality TCXO of Brown and Hwang, 4th ed., Table 9.2 (h_0 = 2e-19 s, h_-2 = 2e-20 /s);
   * 3 m code and 0.1 m/s Doppler noise of a single-frequency consumer receiver. */
  c.raw.code_sd_m = 3.0;
  c.raw.range_rate_sd_mps = 0.1;
  c.raw.clock_h0_s = 2e-19;
  c.raw.clock_hm2_per_s = 2e-20;
  c.raw.clock_bias_sd_m = 100.0;
  c.raw.clock_drift_sd_mps = 10.0;
  c.raw.isb_sd_m = 10.0;
  return c;
}

static void report_issue(nav_gnss_issue_fn report, void *user, int *count, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
static void report_issue(nav_gnss_issue_fn report, void *user, int *count, const char *path, const char *fmt, ...) {
  char msg[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  ++*count;
  if (report) {
    report(user, path, msg);
  }
}

nav_status nav_gnss_constellation_config_validate(const nav_gnss_constellation_config *cfg, nav_gnss_issue_fn report,
                                                  void *user) {
  if (!cfg) {
    return NAV_ERR_INVALID_ARG;
  }
  int n = 0;
  char path[64];
  if (cfg->gps != NAV_GNSS_SOURCE_OFF && cfg->gps != NAV_GNSS_SOURCE_NOMINAL && cfg->gps != NAV_GNSS_SOURCE_ALMANAC) {
    report_issue(report, user, &n, "gps", "must be off, nominal or almanac");
  }
  if (cfg->glonass != NAV_GNSS_SOURCE_OFF && cfg->glonass != NAV_GNSS_SOURCE_NOMINAL) {
    report_issue(report, user, &n, "glonass", "must be off or nominal (GLONASS almanacs are not supported yet)");
  }
  if (cfg->gps == NAV_GNSS_SOURCE_OFF && cfg->glonass == NAV_GNSS_SOURCE_OFF) {
    report_issue(report, user, &n, "gps", "no satellite system: set gps or glonass");
  }
  if (cfg->gps == NAV_GNSS_SOURCE_ALMANAC && (cfg->almanac.n <= 0 || cfg->almanac.n > NAV_GNSS_MAX_SATS)) {
    report_issue(report, user, &n, "almanac", "gps: almanac needs an almanac file with at least one satellite");
  }
  if (cfg->gps != NAV_GNSS_SOURCE_ALMANAC && cfg->almanac_file[0] != '\0') {
    report_issue(report, user, &n, "almanac", "an almanac file is given but gps is not 'almanac'");
  }
  const int total = (cfg->gps == NAV_GNSS_SOURCE_NOMINAL ? 24 : cfg->gps == NAV_GNSS_SOURCE_ALMANAC ? cfg->almanac.n : 0) +
                    (cfg->glonass == NAV_GNSS_SOURCE_NOMINAL ? 24 : 0);
  if (total > NAV_GNSS_MAX_SATS) {
    report_issue(report, user, &n, "almanac", "more than %d satellites in total", NAV_GNSS_MAX_SATS);
  }
  if (!(cfg->epoch_gps_s >= nav_gnss_gps_time_s(1900, 1, 1, 0, 0, 0.0) &&
        cfg->epoch_gps_s < nav_gnss_gps_time_s(2180, 1, 1, 0, 0, 0.0))) {
    report_issue(report, user, &n, "epoch", "must be a date between 1900 and 2180");
  }
  if (cfg->min_satellites_for_fix < 0 || cfg->min_satellites_for_fix > NAV_GNSS_MAX_SATS) {
    report_issue(report, user, &n, "min_satellites_for_fix", "must be in [0, %d]", NAV_GNSS_MAX_SATS);
  }
  if (cfg->fixes != NAV_GNSS_FIXES_MODEL && cfg->fixes != NAV_GNSS_FIXES_PVT) {
    report_issue(report, user, &n, "fixes", "must be pvt or model");
  }
  const struct {
    const char *key;
    double v;
    bool zero_ok;
  } raw[] = {{"code_sd_m", cfg->raw.code_sd_m, false},
             {"range_rate_sd_mps", cfg->raw.range_rate_sd_mps, false},
             {"clock_h0_s", cfg->raw.clock_h0_s, true},
             {"clock_hm2_per_s", cfg->raw.clock_hm2_per_s, true},
             {"clock_bias_sd_m", cfg->raw.clock_bias_sd_m, false},
             {"clock_drift_sd_mps", cfg->raw.clock_drift_sd_mps, false},
             {"isb_sd_m", cfg->raw.isb_sd_m, false}};
  for (size_t i = 0; i < sizeof raw / sizeof raw[0]; ++i) {
    const double v = raw[i].v;
    /* 1e6 bounds every sigma (m, m/s) far above any receiver; h coefficients are ~1e-19. */
    const bool ok = isfinite(v) && (raw[i].zero_ok ? v >= 0.0 && v <= 1e-6 : v > 0.0 && v <= 1e6);
    if (!ok) {
      report_issue(report, user, &n, raw[i].key, raw[i].zero_ok ? "must be in [0, 1e-6]" : "must be in (0, 1e6]");
    }
  }
  if (!isfinite(cfg->glonass_node1_lon_rad)) {
    report_issue(report, user, &n, "glonass_node_lon_deg", "must be finite");
  }
  if (!(cfg->mask.elevation_mask_rad >= 0.0 && cfg->mask.elevation_mask_rad < 0.5 * PI)) {
    report_issue(report, user, &n, "elevation_mask_deg", "must be in [0, 90) deg");
  }
  if (cfg->mask.n_profile < 0 || cfg->mask.n_profile > NAV_GNSS_MASK_MAX_POINTS) {
    report_issue(report, user, &n, "sky_mask_deg", "at most %d points", NAV_GNSS_MASK_MAX_POINTS);
  } else {
    for (int i = 0; i < cfg->mask.n_profile; ++i) {
      snprintf(path, sizeof path, "sky_mask_deg[%d]", i);
      const double az = cfg->mask.profile_az_rad[i], el = cfg->mask.profile_el_rad[i];
      if (!(az >= 0.0 && az < 2.0 * PI)) {
        report_issue(report, user, &n, path, "azimuth must be in [0, 360) deg");
      } else if (i > 0 && !(az > cfg->mask.profile_az_rad[i - 1])) {
        report_issue(report, user, &n, path, "azimuths must increase");
      }
      if (!(el >= 0.0 && el <= 0.5 * PI)) {
        report_issue(report, user, &n, path, "elevation must be in [0, 90] deg");
      }
    }
  }
  if (cfg->n_canyons < 0 || cfg->n_canyons > NAV_GNSS_MAX_CANYONS) {
    report_issue(report, user, &n, "canyons", "at most %d canyons", NAV_GNSS_MAX_CANYONS);
  } else {
    for (int i = 0; i < cfg->n_canyons; ++i) {
      const nav_gnss_canyon *k = &cfg->canyons[i];
      snprintf(path, sizeof path, "canyons[%d]", i);
      if (!(isfinite(k->t0_s) && isfinite(k->t1_s) && k->t1_s > k->t0_s)) {
        report_issue(report, user, &n, path, "needs finite times with t1_s > t0_s");
      } else if (i > 0 && k->t0_s < cfg->canyons[i - 1].t1_s) {
        report_issue(report, user, &n, path, "canyons must be in time order without overlap");
      }
      if (!(k->height_m > 0.0 && k->height_m <= 1000.0 && k->left_m > 0.0 && k->left_m <= 1000.0 &&
            k->right_m > 0.0 && k->right_m <= 1000.0)) {
        report_issue(report, user, &n, path, "height_m, left_m and right_m must be in (0, 1000] m");
      }
    }
  }
  return n == 0 ? NAV_OK : NAV_ERR_INVALID_ARG;
}

nav_status nav_gnss_constellation_build(const nav_gnss_constellation_config *cfg, nav_gnss_constellation *out) {
  if (!cfg || !out || !isfinite(cfg->epoch_gps_s)) {
    return NAV_ERR_INVALID_ARG;
  }
  nav_gnss_constellation c;
  c.n = 0;
  nav_status st = NAV_OK;
  if (cfg->gps == NAV_GNSS_SOURCE_NOMINAL) {
    st = nav_gnss_add_gps_nominal(&c, cfg->epoch_gps_s);
  } else if (cfg->gps == NAV_GNSS_SOURCE_ALMANAC) {
    if (cfg->almanac.n < 0 || cfg->almanac.n > NAV_GNSS_MAX_SATS) {
      return NAV_ERR_INVALID_ARG;
    }
    for (int i = 0; i < cfg->almanac.n; ++i) {
      c.sats[c.n++] = cfg->almanac.sats[i];
    }
  }
  if (st == NAV_OK && cfg->glonass == NAV_GNSS_SOURCE_NOMINAL) {
    st = nav_gnss_add_glonass_nominal(&c, cfg->epoch_gps_s, cfg->glonass_node1_lon_rad);
  }
  if (st == NAV_OK) {
    *out = c;
  }
  return st;
}

nav_gnss_sky_mask nav_gnss_constellation_mask_at(const nav_gnss_constellation_config *cfg, double t_s) {
  nav_gnss_sky_mask m = cfg->mask;
  m.canyon_height_m = 0.0;
  m.canyon_left_m = 0.0;
  m.canyon_right_m = 0.0;
  for (int i = 0; i < cfg->n_canyons && i < NAV_GNSS_MAX_CANYONS; ++i) {
    const nav_gnss_canyon *k = &cfg->canyons[i];
    if (t_s >= k->t0_s && t_s < k->t1_s) {
      m.canyon_height_m = k->height_m;
      m.canyon_left_m = k->left_m;
      m.canyon_right_m = k->right_m;
      break;
    }
  }
  return m;
}
