/* RINEX 3.04 writer (observation and navigation files, GPS and GLONASS) and the conversions from
 * navcore's orbits to broadcast records. Format: RINEX 3.04 (IGS/RTCM-SC104, 2018), Tables A1-A12;
 * formulas and the choices made: docs/rinex.md. */
#include "navcore/nav_rinex.h"

#include <math.h>
#include <stdarg.h>
#include <string.h>

/* ------------------------------------------------------------------------------- time */

/* Civil date of day number @p z counted from 1970-01-01 (proleptic Gregorian): the era/day-of-era
 * decomposition of the 400-year cycle (146097 days), with years starting on 1 March so that the
 * leap day is the last day of the year. */
static void civil_from_days(long z, int *y, int *m, int *d) {
  z += 719468; /* days from 0000-03-01 to 1970-01-01 */
  const long era = (z >= 0 ? z : z - 146096) / 146097;
  const long doe = z - era * 146097;                                      /* [0, 146096] */
  const long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365; /* [0, 399] */
  const long doy = doe - (365 * yoe + yoe / 4 - yoe / 100);               /* [0, 365] */
  const long mp = (5 * doy + 2) / 153;                                    /* March = 0 */
  *d = (int)(doy - (153 * mp + 2) / 5 + 1);
  *m = (int)(mp < 10 ? mp + 3 : mp - 9);
  *y = (int)(yoe + era * 400 + (*m <= 2 ? 1 : 0));
}

nav_rinex_date nav_rinex_date_from_gps(double t_s) {
  nav_rinex_date out = {0};
  const double days = floor(t_s / 86400.0);
  double sod = t_s - days * 86400.0;
  if (sod >= 86400.0) sod = 0.0; /* rounding at the day's end */
  /* 1980-01-06 is day 3657 after 1970-01-01 (ten years with two leap days, plus five days). */
  civil_from_days((long)days + 3657L, &out.year, &out.month, &out.day);
  const int whole = (int)floor(sod);
  out.hour = whole / 3600;
  out.minute = (whole % 3600) / 60;
  out.second = (double)(whole % 60) + (sod - (double)whole);
  return out;
}

int nav_rinex_leap_seconds(double t_gps_s) {
  /* Dates (UTC, 00:00) from which GPS - UTC grew by one second: IERS Bulletin C. */
  static const int dates[][3] = {{1981, 7, 1}, {1982, 7, 1}, {1983, 7, 1}, {1985, 7, 1}, {1988, 1, 1},
                                 {1990, 1, 1}, {1991, 1, 1}, {1992, 7, 1}, {1993, 7, 1}, {1994, 7, 1},
                                 {1996, 1, 1}, {1997, 7, 1}, {1999, 1, 1}, {2006, 1, 1}, {2009, 1, 1},
                                 {2012, 7, 1}, {2015, 7, 1}, {2017, 1, 1}};
  int leap = 0;
  for (size_t i = 0; i < sizeof dates / sizeof dates[0]; ++i) {
    /* The UTC date read on the GPS scale plus the GPS - UTC in force from it. */
    const double t = nav_gnss_gps_time_s(dates[i][0], dates[i][1], dates[i][2], 0, 0, 0.0) + (double)(i + 1);
    if (t_gps_s >= t) leap = (int)(i + 1);
  }
  return leap;
}

double nav_rinex_l1_hz(nav_gnss_system sys, int glo_channel) {
  return sys == NAV_GNSS_SYS_GLONASS ? NAV_RINEX_GLO_L1_HZ + glo_channel * NAV_RINEX_GLO_L1_STEP_HZ
                                     : NAV_RINEX_GPS_L1_HZ;
}

int nav_rinex_glonass_nominal_channel(int slot) {
  /* docs/rinex.md (GLONASS frequency channels): antipodal slots n and n + 4 share a channel. */
  static const int k[24] = {1, -4, 5, 6, 1, -4, 5, 6, -2, -7, 0, -1, -2, -7, 0, -1, 4, -3, 3, 2, 4, -3, 3, 2};
  return slot >= 1 && slot <= 24 ? k[slot - 1] : 0;
}

/* ------------------------------------------------------------------------------- conversions */

static double sow_of(double t) {
  return t - floor(t / NAV_GNSS_WEEK_S) * NAV_GNSS_WEEK_S;
}

nav_rinex_gps_eph nav_rinex_gps_eph_from_orbit(const nav_gnss_orbit *o, double toe_gps_s, int iode) {
  nav_rinex_gps_eph e = {0};
  e.prn = o->prn;
  const double A = o->sqrt_a_sqrtm * o->sqrt_a_sqrtm;
  const double n = sqrt(NAV_GPS_MU_M3PS2 / (A * A * A)) + o->delta_n_rps;
  const double dt = toe_gps_s - o->toe_s;
  /* IS-GPS-200N Table 20-IV: M_k = M0 + n t_k, i_k = i0 + IDOT t_k and
   * Omega_k = Omega0 + (Omega_dot - omega_e) t_k - omega_e toe_sow. Referring the same orbit to
   * toe' = toe + dt keeps M_k and i_k when M0' = M0 + n dt, i0' = i0 + IDOT dt, and Omega_k when
   * Omega0' = Omega0 + Omega_dot dt - omega_e (dt - (toe'_sow - toe_sow)), where the bracket is
   * 604800 s times the number of week changes between toe and toe'. */
  const double weeks = floor(toe_gps_s / NAV_GNSS_WEEK_S) - floor(o->toe_s / NAV_GNSS_WEEK_S);
  e.m0_rad = remainder(o->m0_rad + n * dt, 2.0 * NAV_PI);
  e.i0_rad = o->i0_rad + o->idot_rps * dt;
  e.omega0_rad = remainder(
      o->omega0_rad + o->omega_dot_rps * dt - NAV_GPS_OMEGA_E_RPS * NAV_GNSS_WEEK_S * weeks, 2.0 * NAV_PI);
  e.toe_gps_s = toe_gps_s;
  e.toc_gps_s = toe_gps_s;
  e.af0_s = o->af0_s + o->af1_sps * dt;
  e.af1_sps = o->af1_sps;
  e.iode = iode;
  e.iodc = iode;
  e.delta_n_rps = o->delta_n_rps;
  e.e = o->e;
  e.sqrt_a_sqrtm = o->sqrt_a_sqrtm;
  e.w_rad = o->w_rad;
  e.omega_dot_rps = o->omega_dot_rps;
  e.idot_rps = o->idot_rps;
  e.l2_codes = 1;
  e.sv_accuracy_m = 2.0;
  e.health = o->health;
  e.t_tx_gps_s = toe_gps_s;
  e.fit_interval_h = 4.0;
  return e;
}

double nav_rinex_gps_clock_s(const nav_rinex_gps_eph *e, double t_gps_s, bool with_tgd) {
  const double A = e->sqrt_a_sqrtm * e->sqrt_a_sqrtm;
  const double n = sqrt(NAV_GPS_MU_M3PS2 / (A * A * A)) + e->delta_n_rps;
  const double Mk = e->m0_rad + n * (t_gps_s - e->toe_gps_s);
  double E = Mk;
  for (int it = 0; it < 30; ++it) {
    const double dE = (Mk - E + e->e * sin(E)) / (1.0 - e->e * cos(E));
    E += dE;
    if (fabs(dE) < 1e-15) break;
  }
  /* IS-GPS-200N 20.3.3.3.3.1: F = -2 sqrt(mu) / c^2 [s/m^0.5]. */
  const double F = -2.0 * sqrt(NAV_GPS_MU_M3PS2) / (NAV_GNSS_C_MPS * NAV_GNSS_C_MPS);
  const double dt = t_gps_s - e->toc_gps_s;
  double dts = e->af0_s + e->af1_sps * dt + e->af2_sps2 * dt * dt + F * e->e * e->sqrt_a_sqrtm * sin(E);
  if (with_tgd) dts -= e->tgd_s;
  return dts;
}

/* ICD GLONASS Edition 5.1 (2008), A.3.1.2: the satellite's acceleration in the rotating PZ-90
 * frame from the central body, the J2 zonal term and the frame's rotation (centrifugal and
 * Coriolis); PZ-90 constants of section 3.1.3. */
nav_vec3 nav_rinex_glo_force(nav_vec3 r, nav_vec3 v) {
  const double mu = 398600.4418e9, ae = 6378136.0, J2 = 1082625.75e-9, w = 7.292115e-5;
  const double r2 = nav_vec3_dot(r, r), rn = sqrt(r2), r3 = r2 * rn;
  const double a = 1.5 * J2 * mu * ae * ae / (r3 * r2); /* 3/2 J2 mu ae^2 / r^5 */
  const double b = 5.0 * r.z * r.z / r2;
  const double c = -mu / r3 - a * (1.0 - b);
  nav_vec3 acc;
  acc.x = (c + w * w) * r.x + 2.0 * w * v.y;
  acc.y = (c + w * w) * r.y - 2.0 * w * v.x;
  acc.z = (c - 2.0 * a) * r.z;
  return acc;
}

/* The orbit's acceleration minus the ICD force model along the orbit at t [m/s^2]: the orbit's
 * acceleration by a central difference of its analytic velocity (h = 1 s keeps the truncation
 * a''' h^2 / 6 near 1e-9 m/s^2 with a''' ~ a n^2, n = 1.5e-4 rad/s, and the rounding of 4 km/s
 * velocities near 1e-12 m/s^2). */
static nav_vec3 force_gap(const nav_gnss_orbit *o, double t) {
  const double h = 1.0;
  nav_vec3 r, v, vp, vm;
  nav_gnss_orbit_state(o, t, &r, &v);
  nav_gnss_orbit_state(o, t + h, NULL, &vp);
  nav_gnss_orbit_state(o, t - h, NULL, &vm);
  const nav_vec3 a_true = nav_vec3_scale(nav_vec3_sub(vp, vm), 0.5 / h);
  return nav_vec3_sub(a_true, nav_rinex_glo_force(r, v));
}

nav_rinex_glo_eph nav_rinex_glo_eph_from_orbit(const nav_gnss_orbit *o, double tb_gps_s, int channel,
                                               double half_span_s) {
  nav_rinex_glo_eph e = {0};
  e.slot = o->prn;
  e.tb_gps_s = tb_gps_s;
  e.tk_gps_s = tb_gps_s;
  e.channel = channel;
  e.health = o->health;
  e.clock_bias_s = o->af0_s + o->af1_sps * (tb_gps_s - o->toe_s);
  e.gamma_n = o->af1_sps;
  nav_gnss_orbit_state(o, tb_gps_s, &e.r_e_m, &e.v_e_mps);
  /* The acceleration term: the gap between the orbit and the ICD model at tb. Over t = t' - tb
   * the gap changes as g0 + g1 t, which a receiver integrating a constant term misses by
   * g1 t^3 / 6 in position. Its least-squares straight-line part over [-T, T] (t^3 ~ 3/5 T^2 t,
   * Legendre) is taken up by the velocity: v(tb) + g1 T^2 / 10, which leaves at most
   * 0.4 |g1| T^3 / 6 instead of |g1| T^3 / 6 (docs/rinex.md). g1 by a central difference over
   * 60 s (the gap varies over the 11 h orbit). */
  e.a_e_mps2 = force_gap(o, tb_gps_s);
  if (half_span_s > 0.0) {
    const double h = 60.0;
    const nav_vec3 g1 =
        nav_vec3_scale(nav_vec3_sub(force_gap(o, tb_gps_s + h), force_gap(o, tb_gps_s - h)), 0.5 / h);
    e.v_e_mps = nav_vec3_axpy(e.v_e_mps, 0.1 * half_span_s * half_span_s, g1);
  }
  return e;
}

double nav_rinex_glo_clock_s(const nav_rinex_glo_eph *e, double t_gps_s) {
  return e->clock_bias_s + e->gamma_n * (t_gps_s - e->tb_gps_s);
}

/* ------------------------------------------------------------------------------- writing */

typedef struct out {
  FILE *f;
  bool ok;
} out;

#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void
put(out *o, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  if (vfprintf(o->f, fmt, ap) < 0) o->ok = false;
  va_end(ap);
}

/* A header line: 60 columns of content, the label from column 61. */
static void hline(out *o, const char *content, const char *label) {
  put(o, "%-60.60s%-20.20s\n", content, label);
}

static char sys_char(nav_gnss_system s) {
  return s == NAV_GNSS_SYS_GLONASS ? 'R' : 'G';
}

static bool type_ok(const char *t) {
  if (strlen(t) != 3) return false;
  for (int i = 0; i < 3; ++i) {
    const char c = t[i];
    if (!((c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9'))) return false;
  }
  return strchr("CLDS", t[0]) != NULL;
}

/* Time rounded to the 1e-7 s of the F11.7 epoch fields, as a date (the rounding carries into the
 * minute instead of printing 60.0000000). */
static nav_rinex_date date_rounded(double t_s) {
  const double whole = floor(t_s);
  const double frac = round((t_s - whole) * 1e7) / 1e7;
  nav_rinex_date d = nav_rinex_date_from_gps(whole);
  d.second = floor(d.second + 0.5) + frac; /* whole seconds from the integer part */
  if (frac >= 1.0) {
    d = nav_rinex_date_from_gps(whole + 1.0);
    d.second = floor(d.second + 0.5);
  }
  return d;
}

nav_status nav_rinex_obs_write_header(FILE *f, const nav_rinex_obs_header *h) {
  if (!f || !h) return NAV_ERR_INVALID_ARG;
  int systems = 0;
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    if (h->n_types[s] < 0 || h->n_types[s] > NAV_RINEX_MAX_OBS_TYPES) return NAV_ERR_INVALID_ARG;
    for (int k = 0; k < h->n_types[s]; ++k)
      if (!type_ok(h->types[s][k])) return NAV_ERR_INVALID_ARG;
    if (h->n_types[s] > 0) ++systems;
  }
  if (systems == 0 || !isfinite(h->t_first_gps_s) || !isfinite(h->interval_s) ||
      !(isfinite(h->approx_pos_e_m.x) && isfinite(h->approx_pos_e_m.y) && isfinite(h->approx_pos_e_m.z)) ||
      !(isfinite(h->antenna_delta_hen_m.x) && isfinite(h->antenna_delta_hen_m.y) &&
        isfinite(h->antenna_delta_hen_m.z)) ||
      h->n_glo < 0 || h->n_glo > NAV_RINEX_MAX_GLO_SLOTS || h->leap_seconds < 0 || h->leap_seconds > 99)
    return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < h->n_glo; ++i)
    if (h->glo_slot[i] < 1 || h->glo_slot[i] > 99 || h->glo_channel[i] < -7 || h->glo_channel[i] > 13)
      return NAV_ERR_INVALID_ARG;
  if (fabs(h->approx_pos_e_m.x) >= 1e8 || fabs(h->approx_pos_e_m.y) >= 1e8 ||
      fabs(h->approx_pos_e_m.z) >= 1e8)
    return NAV_ERR_OUT_OF_RANGE;
  const char only = h->n_types[NAV_GNSS_SYS_GLONASS] == 0 ? 'G'
                    : h->n_types[NAV_GNSS_SYS_GPS] == 0   ? 'R'
                                                          : 'M';
  out o = {f, true};
  char line[128];
  snprintf(line, sizeof line, "%9.2f%11s%-20s%c", 3.04, "", "OBSERVATION DATA", only);
  hline(&o, line, "RINEX VERSION / TYPE");
  snprintf(line, sizeof line, "%-20.20s%-20.20s%-20.20s", h->program, h->run_by, h->date);
  hline(&o, line, "PGM / RUN BY / DATE");
  hline(&o, h->marker_name, "MARKER NAME");
  hline(&o, "NON_GEODETIC", "MARKER TYPE");
  snprintf(line, sizeof line, "%-20s%-40s", "navsim", "simulation");
  hline(&o, line, "OBSERVER / AGENCY");
  snprintf(line, sizeof line, "%-20s%-20.20s%-20s", "0", h->receiver_type, "");
  hline(&o, line, "REC # / TYPE / VERS");
  snprintf(line, sizeof line, "%-20s%-20.20s", "0", h->antenna_type);
  hline(&o, line, "ANT # / TYPE");
  snprintf(line, sizeof line, "%14.4f%14.4f%14.4f", h->approx_pos_e_m.x, h->approx_pos_e_m.y,
           h->approx_pos_e_m.z);
  hline(&o, line, "APPROX POSITION XYZ");
  snprintf(line, sizeof line, "%14.4f%14.4f%14.4f", h->antenna_delta_hen_m.x, h->antenna_delta_hen_m.y,
           h->antenna_delta_hen_m.z);
  hline(&o, line, "ANTENNA: DELTA H/E/N");
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    if (h->n_types[s] == 0) continue;
    /* A1, 2X, I3, 13(1X, A3); more than 13 types continue on 6X lines (at most 8 here). */
    int len = snprintf(line, sizeof line, "%c  %3d", sys_char((nav_gnss_system)s), h->n_types[s]);
    for (int k = 0; k < h->n_types[s]; ++k)
      len += snprintf(line + len, sizeof line - (size_t)len, " %s", h->types[s][k]);
    hline(&o, line, "SYS / # / OBS TYPES");
  }
  if (h->interval_s > 0.0) {
    snprintf(line, sizeof line, "%10.3f", h->interval_s);
    hline(&o, line, "INTERVAL");
  }
  const nav_rinex_date d = date_rounded(h->t_first_gps_s);
  snprintf(line, sizeof line, "%6d%6d%6d%6d%6d%13.7f%5s%3s", d.year, d.month, d.day, d.hour, d.minute,
           d.second, "", "GPS");
  hline(&o, line, "TIME OF FIRST OBS");
  /* Carrier phases carry no quarter-cycle shifts here: one record per system with no type. */
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    if (h->n_types[s] == 0) continue;
    snprintf(line, sizeof line, "%c", sys_char((nav_gnss_system)s));
    hline(&o, line, "SYS / PHASE SHIFT");
  }
  if (h->n_types[NAV_GNSS_SYS_GLONASS] > 0) {
    /* I3, 1X, 8(A1, I2.2, 1X, I2, 1X); continuation lines 4X. */
    int i = 0;
    do {
      int len = i == 0 ? snprintf(line, sizeof line, "%3d ", h->n_glo) : snprintf(line, sizeof line, "    ");
      for (int k = 0; k < 8 && i < h->n_glo; ++k, ++i)
        len +=
            snprintf(line + len, sizeof line - (size_t)len, "R%02d %2d ", h->glo_slot[i], h->glo_channel[i]);
      hline(&o, line, "GLONASS SLOT / FRQ #");
    } while (i < h->n_glo);
    hline(&o, " C1C    0.000 C1P    0.000 C2C    0.000 C2P    0.000", "GLONASS COD/PHS/BIS");
  }
  snprintf(line, sizeof line, "%6d", h->leap_seconds);
  hline(&o, line, "LEAP SECONDS");
  hline(&o, "", "END OF HEADER");
  return o.ok ? NAV_OK : NAV_ERR_IO;
}

nav_status nav_rinex_obs_write_epoch(FILE *f, const nav_rinex_obs_header *h, const nav_rinex_obs_epoch *ep) {
  if (!f || !h || !ep || ep->n < 0 || ep->n > NAV_RINEX_MAX_EPOCH_SATS || !isfinite(ep->t_gps_s))
    return NAV_ERR_INVALID_ARG;
  for (int i = 0; i < ep->n; ++i) {
    const nav_rinex_obs_sat *s = &ep->sats[i];
    if ((s->system != NAV_GNSS_SYS_GPS && s->system != NAV_GNSS_SYS_GLONASS) || h->n_types[s->system] == 0 ||
        s->prn < 1 || s->prn > 99)
      return NAV_ERR_INVALID_ARG;
    for (int k = 0; k < h->n_types[s->system]; ++k) {
      if (!s->has[k]) continue;
      if (!isfinite(s->value[k])) return NAV_ERR_INVALID_ARG;
      if (fabs(s->value[k]) >= 1e10) return NAV_ERR_OUT_OF_RANGE; /* F14.3 */
    }
  }
  out o = {f, true};
  const nav_rinex_date d = date_rounded(ep->t_gps_s);
  /* A1, 1X, I4, 4(1X, I2.2), F11.7, 2X, I1, I3 */
  put(&o, "> %4d %02d %02d %02d %02d%11.7f  %d%3d\n", d.year, d.month, d.day, d.hour, d.minute, d.second, 0,
      ep->n);
  char line[16 * NAV_RINEX_MAX_OBS_TYPES + 8];
  for (int i = 0; i < ep->n; ++i) {
    const nav_rinex_obs_sat *s = &ep->sats[i];
    int len = snprintf(line, sizeof line, "%c%02d", sys_char(s->system), s->prn);
    for (int k = 0; k < h->n_types[s->system]; ++k) {
      /* F14.3, then the loss-of-lock and signal-strength flags (blank: unknown). */
      if (s->has[k])
        len += snprintf(line + len, sizeof line - (size_t)len, "%14.3f  ", s->value[k]);
      else
        len += snprintf(line + len, sizeof line - (size_t)len, "%16s", "");
    }
    while (len > 3 && line[len - 1] == ' ')
      line[--len] = '\0'; /* no trailing blanks */
    put(&o, "%s\n", line);
  }
  return o.ok ? NAV_OK : NAV_ERR_IO;
}

nav_status nav_rinex_nav_write_header(FILE *f, const nav_rinex_nav_header *h) {
  if (!f || !h || h->leap_seconds < 0 || h->leap_seconds > 99) return NAV_ERR_INVALID_ARG;
  out o = {f, true};
  char line[128];
  snprintf(line, sizeof line, "%9.2f%11s%-20s%-20s", 3.04, "", "N: GNSS NAV DATA", "M: MIXED");
  hline(&o, line, "RINEX VERSION / TYPE");
  snprintf(line, sizeof line, "%-20.20s%-20.20s%-20.20s", h->program, h->run_by, h->date);
  hline(&o, line, "PGM / RUN BY / DATE");
  snprintf(line, sizeof line, "%6d", h->leap_seconds);
  hline(&o, line, "LEAP SECONDS");
  hline(&o, "", "END OF HEADER");
  return o.ok ? NAV_OK : NAV_ERR_IO;
}

/* D19.12 written with an 'E' exponent: "-1.234567890123E+04" is 19 characters; a positive value
 * gets a leading blank. */
static void d19(out *o, double v) {
  put(o, "%19.12E", v);
}

static void orbit_line(out *o, double a, double b, double c, double d) {
  put(o, "    ");
  d19(o, a);
  d19(o, b);
  d19(o, c);
  d19(o, d);
  put(o, "\n");
}

static bool all_finite(const double *v, int n) {
  for (int i = 0; i < n; ++i)
    if (!isfinite(v[i])) return false;
  return true;
}

nav_status nav_rinex_nav_write_gps(FILE *f, const nav_rinex_gps_eph *e) {
  if (!f || !e || e->prn < 1 || e->prn > 99) return NAV_ERR_INVALID_ARG;
  const double v[] = {e->toc_gps_s,     e->af0_s,        e->af1_sps,
                      e->af2_sps2,      e->crs_m,        e->delta_n_rps,
                      e->m0_rad,        e->cuc_rad,      e->e,
                      e->cus_rad,       e->sqrt_a_sqrtm, e->toe_gps_s,
                      e->cic_rad,       e->omega0_rad,   e->cis_rad,
                      e->i0_rad,        e->crc_m,        e->w_rad,
                      e->omega_dot_rps, e->idot_rps,     e->sv_accuracy_m,
                      e->tgd_s,         e->t_tx_gps_s,   e->fit_interval_h};
  if (!all_finite(v, (int)(sizeof v / sizeof v[0])) || e->toc_gps_s < 0.0) return NAV_ERR_INVALID_ARG;
  out o = {f, true};
  const double toc = floor(e->toc_gps_s + 0.5); /* the epoch line has whole seconds */
  const nav_rinex_date d = nav_rinex_date_from_gps(toc);
  put(&o, "G%02d %4d %02d %02d %02d %02d %02d", e->prn, d.year, d.month, d.day, d.hour, d.minute,
      (int)floor(d.second + 0.5));
  d19(&o, e->af0_s);
  d19(&o, e->af1_sps);
  d19(&o, e->af2_sps2);
  put(&o, "\n");
  const double week = floor(e->toe_gps_s / NAV_GNSS_WEEK_S);
  orbit_line(&o, (double)e->iode, e->crs_m, e->delta_n_rps, e->m0_rad);
  orbit_line(&o, e->cuc_rad, e->e, e->cus_rad, e->sqrt_a_sqrtm);
  orbit_line(&o, sow_of(e->toe_gps_s), e->cic_rad, e->omega0_rad, e->cis_rad);
  orbit_line(&o, e->i0_rad, e->crc_m, e->w_rad, e->omega_dot_rps);
  orbit_line(&o, e->idot_rps, (double)e->l2_codes, week, (double)e->l2p_flag);
  orbit_line(&o, e->sv_accuracy_m, (double)e->health, e->tgd_s, (double)e->iodc);
  /* Transmission time: seconds of the week of toe (negative before it, RINEX 3.04 A8 note). */
  put(&o, "    ");
  d19(&o, e->t_tx_gps_s - week * NAV_GNSS_WEEK_S);
  d19(&o, e->fit_interval_h);
  put(&o, "\n");
  return o.ok ? NAV_OK : NAV_ERR_IO;
}

nav_status nav_rinex_nav_write_glonass(FILE *f, const nav_rinex_glo_eph *e, int leap_seconds) {
  if (!f || !e || e->slot < 1 || e->slot > 99 || leap_seconds < 0 || leap_seconds > 99 || e->channel < -7 ||
      e->channel > 13)
    return NAV_ERR_INVALID_ARG;
  const double v[] = {e->tb_gps_s,   e->clock_bias_s, e->gamma_n,   e->tk_gps_s,  e->r_e_m.x,
                      e->r_e_m.y,    e->r_e_m.z,      e->v_e_mps.x, e->v_e_mps.y, e->v_e_mps.z,
                      e->a_e_mps2.x, e->a_e_mps2.y,   e->a_e_mps2.z};
  if (!all_finite(v, (int)(sizeof v / sizeof v[0])) || e->tb_gps_s < 0.0) return NAV_ERR_INVALID_ARG;
  out o = {f, true};
  /* The epoch (tb) and the message frame time are UTC in a GLONASS record (RINEX 3.04 A11). */
  const double tb_utc = floor(e->tb_gps_s + 0.5) - (double)leap_seconds;
  const nav_rinex_date d = nav_rinex_date_from_gps(tb_utc);
  put(&o, "R%02d %4d %02d %02d %02d %02d %02d", e->slot, d.year, d.month, d.day, d.hour, d.minute,
      (int)floor(d.second + 0.5));
  d19(&o, e->clock_bias_s);
  d19(&o, e->gamma_n);
  d19(&o, sow_of(e->tk_gps_s - (double)leap_seconds));
  put(&o, "\n");
  orbit_line(&o, e->r_e_m.x / 1e3, e->v_e_mps.x / 1e3, e->a_e_mps2.x / 1e3, (double)e->health);
  orbit_line(&o, e->r_e_m.y / 1e3, e->v_e_mps.y / 1e3, e->a_e_mps2.y / 1e3, (double)e->channel);
  orbit_line(&o, e->r_e_m.z / 1e3, e->v_e_mps.z / 1e3, e->a_e_mps2.z / 1e3, (double)e->age_d);
  return o.ok ? NAV_OK : NAV_ERR_IO;
}
