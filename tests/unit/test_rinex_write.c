/* RINEX 3.04 writer (navcore_io rinex_write.c, issue 22): calendar and leap seconds, header
 * labels at column 61, epoch and record columns, the D19.12 fields, broadcast-record conversion
 * of our orbits, and bad input. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>
#include "nav_test.h"
#include "navcore/nav_gnss_sat.h"
#include "navcore/nav_rinex.h"

/* The text written to a memory stream (heap; free it). */
typedef struct sink {
  FILE *f;
  char *buf;
  size_t len;
} sink;

static void sink_open(sink *s) {
  s->buf = NULL;
  s->len = 0;
  s->f = open_memstream(&s->buf, &s->len);
  assert_non_null(s->f);
}

static char *sink_close(sink *s) {
  fclose(s->f);
  return s->buf;
}

/* Line @p k (0-based) of @p text into @p out. */
static void line_of(const char *text, int k, char *out, size_t cap) {
  const char *p = text;
  for (int i = 0; i < k && p; ++i) {
    p = strchr(p, '\n');
    if (p) ++p;
  }
  assert_non_null(p);
  const char *e = strchr(p, '\n');
  size_t n = e ? (size_t)(e - p) : strlen(p);
  if (n >= cap) n = cap - 1;
  memcpy(out, p, n);
  out[n] = '\0';
}

static void test_calendar_and_leap_seconds(void **state) {
  (void)state;
  nav_rinex_date d = nav_rinex_date_from_gps(0.0);
  assert_int_equal(d.year, 1980);
  assert_int_equal(d.month, 1);
  assert_int_equal(d.day, 6);
  /* A leap day and the end of a leap year, against the package's own forward conversion. */
  const double t = nav_gnss_gps_time_s(2024, 2, 29, 23, 59, 59.5);
  d = nav_rinex_date_from_gps(t);
  assert_int_equal(d.year, 2024);
  assert_int_equal(d.month, 2);
  assert_int_equal(d.day, 29);
  assert_int_equal(d.hour, 23);
  assert_int_equal(d.minute, 59);
  assert_near(d.second, 59.5, 1e-6);
  d = nav_rinex_date_from_gps(nav_gnss_gps_time_s(2000, 12, 31, 12, 0, 0.0));
  assert_int_equal(d.year, 2000);
  assert_int_equal(d.month, 12);
  assert_int_equal(d.day, 31);
  /* GPS - UTC: 17 s before 2017-01-01 00:00:00 UTC (GPS 00:00:17), 18 s from then. */
  assert_int_equal(nav_rinex_leap_seconds(0.0), 0);
  assert_int_equal(nav_rinex_leap_seconds(nav_gnss_gps_time_s(2017, 1, 1, 0, 0, 16.0)), 17);
  assert_int_equal(nav_rinex_leap_seconds(nav_gnss_gps_time_s(2017, 1, 1, 0, 0, 18.0)), 18);
  assert_int_equal(nav_rinex_leap_seconds(nav_gnss_gps_time_s(2026, 11, 26, 8, 0, 0.0)), 18);
  assert_int_equal(nav_rinex_leap_seconds(nav_gnss_gps_time_s(1999, 1, 1, 0, 0, 13.0)), 13);
  /* Antipodal GLONASS slots share a channel. */
  for (int s = 1; s <= 24; ++s) {
    const int plane_pos = (s - 1) % 8;
    if (plane_pos < 4)
      assert_int_equal(nav_rinex_glonass_nominal_channel(s), nav_rinex_glonass_nominal_channel(s + 4));
  }
  assert_int_equal(nav_rinex_glonass_nominal_channel(25), 0);
  assert_near(nav_rinex_l1_hz(NAV_GNSS_SYS_GLONASS, -7), 1598.0625e6, 1e-3);
}

static nav_rinex_obs_header two_systems(void) {
  nav_rinex_obs_header h;
  memset(&h, 0, sizeof h);
  snprintf(h.marker_name, sizeof h.marker_name, "test-marker");
  snprintf(h.program, sizeof h.program, "navsim");
  h.approx_pos_e_m = (nav_vec3){3783266.3664, 901650.5933, 5038247.8269};
  for (int s = 0; s < NAV_GNSS_SYS_COUNT; ++s) {
    h.n_types[s] = 2;
    snprintf(h.types[s][0], 4, "C1C");
    snprintf(h.types[s][1], 4, "D1C");
  }
  h.interval_s = 1.0;
  h.t_first_gps_s = nav_gnss_gps_time_s(2026, 11, 26, 8, 0, 1.0);
  h.leap_seconds = 18;
  h.n_glo = 10;
  for (int i = 0; i < h.n_glo; ++i) {
    h.glo_slot[i] = i + 1;
    h.glo_channel[i] = nav_rinex_glonass_nominal_channel(i + 1);
  }
  return h;
}

static void test_obs_header_and_epoch_columns(void **state) {
  (void)state;
  const nav_rinex_obs_header h = two_systems();
  sink s;
  sink_open(&s);
  assert_int_equal(nav_rinex_obs_write_header(s.f, &h), NAV_OK);
  nav_rinex_obs_epoch ep;
  memset(&ep, 0, sizeof ep);
  ep.t_gps_s = h.t_first_gps_s + 0.5;
  ep.n = 2;
  ep.sats[0] = (nav_rinex_obs_sat){NAV_GNSS_SYS_GPS, 3, {true, true}, {20453679.714, -1178.897}};
  ep.sats[1] = (nav_rinex_obs_sat){NAV_GNSS_SYS_GLONASS, 7, {true, false}, {19194758.5024, 0.0}};
  assert_int_equal(nav_rinex_obs_write_epoch(s.f, &h, &ep), NAV_OK);
  char *text = sink_close(&s);
  /* Every header line: 60 columns of content, the label from column 61, at most 80 columns. */
  char line[256];
  int k = 0, end = -1;
  const char *labels[] = {"RINEX VERSION / TYPE", "PGM / RUN BY / DATE", "MARKER NAME",
                          "APPROX POSITION XYZ",  "SYS / # / OBS TYPES", "TIME OF FIRST OBS",
                          "GLONASS SLOT / FRQ #", "LEAP SECONDS",        "INTERVAL",
                          "GLONASS COD/PHS/BIS"};
  int seen[sizeof labels / sizeof labels[0]] = {0};
  for (;; ++k) {
    line_of(text, k, line, sizeof line);
    assert_true(strlen(line) <= 80);
    assert_true(strlen(line) > 60);
    for (size_t i = 0; i < sizeof labels / sizeof labels[0]; ++i)
      if (strncmp(line + 60, labels[i], strlen(labels[i])) == 0) seen[i]++;
    if (strncmp(line + 60, "END OF HEADER", 13) == 0) {
      end = k;
      break;
    }
  }
  for (size_t i = 0; i < sizeof labels / sizeof labels[0]; ++i)
    assert_true(seen[i] >= 1);
  line_of(text, 0, line, sizeof line);
  assert_memory_equal(line, "     3.04", 9); /* F9.2 */
  assert_int_equal(line[20], 'O');
  assert_int_equal(line[40], 'M');
  /* 10 GLONASS slots: two lines, the second a 4X continuation. */
  assert_int_equal(seen[6], 2);
  /* TIME OF FIRST OBS: 5I6, F13.7, 5X, A3. */
  for (int i = 0; i < end; ++i) {
    line_of(text, i, line, sizeof line);
    if (strncmp(line + 60, "TIME OF FIRST OBS", 17) == 0)
      assert_memory_equal(line, "  2026    11    26     8     0    1.0000000     GPS", 51);
    if (strncmp(line + 60, "SYS / # / OBS TYPES", 19) == 0 && line[0] == 'R')
      assert_memory_equal(line, "R    2 C1C D1C", 14);
  }
  /* Epoch line: A1, 1X, I4, 4(1X, I2.2), F11.7, 2X, I1, I3. */
  line_of(text, end + 1, line, sizeof line);
  assert_string_equal(line, "> 2026 11 26 08 00  1.5000000  0  2");
  /* Observations: A1, I2.2, then F14.3 + 2 flag columns each; blank fields for missing ones. */
  line_of(text, end + 2, line, sizeof line);
  assert_string_equal(line, "G03  20453679.714       -1178.897");
  line_of(text, end + 3, line, sizeof line);
  assert_string_equal(line, "R07  19194758.502");
  free(text);
}

static void test_obs_bad_input(void **state) {
  (void)state;
  nav_rinex_obs_header h = two_systems();
  FILE *f = fopen("/dev/null", "w");
  assert_non_null(f);
  assert_int_equal(nav_rinex_obs_write_header(NULL, &h), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_rinex_obs_write_header(f, NULL), NAV_ERR_INVALID_ARG);
  nav_rinex_obs_header bad = h;
  snprintf(bad.types[0][1], 4, "x1");
  assert_int_equal(nav_rinex_obs_write_header(f, &bad), NAV_ERR_INVALID_ARG);
  bad = h;
  bad.n_types[0] = bad.n_types[1] = 0;
  assert_int_equal(nav_rinex_obs_write_header(f, &bad), NAV_ERR_INVALID_ARG);
  bad = h;
  bad.glo_channel[3] = 14;
  assert_int_equal(nav_rinex_obs_write_header(f, &bad), NAV_ERR_INVALID_ARG);
  bad = h;
  bad.t_first_gps_s = NAN;
  assert_int_equal(nav_rinex_obs_write_header(f, &bad), NAV_ERR_INVALID_ARG);
  nav_rinex_obs_epoch ep;
  memset(&ep, 0, sizeof ep);
  ep.t_gps_s = h.t_first_gps_s;
  ep.n = 1;
  ep.sats[0] = (nav_rinex_obs_sat){NAV_GNSS_SYS_GPS, 3, {true, true}, {2e10, 0.0}};
  assert_int_equal(nav_rinex_obs_write_epoch(f, &h, &ep), NAV_ERR_OUT_OF_RANGE); /* beyond F14.3 */
  ep.sats[0].value[0] = INFINITY;
  assert_int_equal(nav_rinex_obs_write_epoch(f, &h, &ep), NAV_ERR_INVALID_ARG);
  ep.sats[0].value[0] = 2e7;
  ep.sats[0].prn = 100;
  assert_int_equal(nav_rinex_obs_write_epoch(f, &h, &ep), NAV_ERR_INVALID_ARG);
  ep.sats[0].prn = 3;
  ep.n = NAV_RINEX_MAX_EPOCH_SATS + 1;
  assert_int_equal(nav_rinex_obs_write_epoch(f, &h, &ep), NAV_ERR_INVALID_ARG);
  ep.n = 1;
  bad = h;
  bad.n_types[NAV_GNSS_SYS_GPS] = 0; /* a GPS satellite in a GLONASS-only file */
  assert_int_equal(nav_rinex_obs_write_epoch(f, &bad, &ep), NAV_ERR_INVALID_ARG);
  /* A closed stream: the write fails as I/O. */
  FILE *ro = fopen("/dev/null", "r");
  assert_non_null(ro);
  assert_int_equal(nav_rinex_obs_write_header(ro, &h), NAV_ERR_IO);
  fclose(ro);
  fclose(f);
}

/* An eccentric almanac-like orbit with every rate non-zero and a clock. */
static nav_gnss_orbit test_orbit(void) {
  nav_gnss_orbit o;
  memset(&o, 0, sizeof o);
  o.system = NAV_GNSS_SYS_GPS;
  o.prn = 17;
  o.toe_s = 2446.0 * NAV_GNSS_WEEK_S + 602112.0; /* late in a week: records cross into the next */
  o.sqrt_a_sqrtm = 5153.71;
  o.e = 0.0123;
  o.i0_rad = 0.9712;
  o.idot_rps = 2.1e-10;
  o.omega0_rad = -2.3;
  o.omega_dot_rps = -8.1e-9;
  o.w_rad = 0.81;
  o.m0_rad = 1.7;
  o.delta_n_rps = 4.4e-9;
  o.af0_s = 1.2e-4;
  o.af1_sps = -3.6e-12;
  return o;
}

static void test_gps_record_reproduces_orbit(void **state) {
  (void)state;
  const nav_gnss_orbit o = test_orbit();
  /* Records 2 h before, at and 4 h after toe (the last in the next GPS week): the user algorithm
   * on the record gives the orbit's position (Kepler, node and inclination re-referred). */
  const double toes[] = {o.toe_s - 7200.0, o.toe_s, o.toe_s + 14400.0};
  for (size_t k = 0; k < 3; ++k) {
    const nav_rinex_gps_eph e = nav_rinex_gps_eph_from_orbit(&o, toes[k], (int)k);
    nav_gnss_orbit back = o;
    back.toe_s = e.toe_gps_s;
    back.m0_rad = e.m0_rad;
    back.i0_rad = e.i0_rad;
    back.omega0_rad = e.omega0_rad;
    for (double dt = -3600.0; dt <= 3600.0; dt += 900.0) {
      nav_vec3 r0, r1;
      nav_gnss_orbit_state(&o, toes[k] + dt, &r0, NULL);
      nav_gnss_orbit_state(&back, toes[k] + dt, &r1, NULL);
      /* 1e-4 m: the re-referred angles carry the rounding of n dt (dt up to 1.4e4 s, 1e-16 rad
       * relative) times the orbit radius of 2.7e7 m. */
      assert_vec3_near(r1, r0, 1e-4);
    }
    /* The clock follows af0 + af1 (t - toe). */
    assert_near(e.af0_s, o.af0_s + o.af1_sps * (toes[k] - o.toe_s), 1e-18);
  }
  /* The relativistic term: F e sqrt(A) sin E, at most 4.44e-10 x 0.0123 x 5153.71 = 2.8e-8 s. */
  const nav_rinex_gps_eph e = nav_rinex_gps_eph_from_orbit(&o, o.toe_s, 0);
  double lo = 1.0, hi = -1.0;
  for (double dt = 0.0; dt < 43200.0; dt += 600.0) {
    const double rel = nav_rinex_gps_clock_s(&e, o.toe_s + dt, false) - (e.af0_s + e.af1_sps * dt);
    lo = rel < lo ? rel : lo;
    hi = rel > hi ? rel : hi;
  }
  assert_near(hi, 2.0 * sqrt(NAV_GPS_MU_M3PS2) / (NAV_GNSS_C_MPS * NAV_GNSS_C_MPS) * o.e * o.sqrt_a_sqrtm,
              2e-10);
  assert_near(lo, -hi, 2e-10);
}

static void test_nav_records_columns(void **state) {
  (void)state;
  const nav_gnss_orbit o = test_orbit();
  const nav_rinex_gps_eph e = nav_rinex_gps_eph_from_orbit(&o, o.toe_s + 7200.0, 5);
  nav_gnss_orbit g = o;
  g.system = NAV_GNSS_SYS_GLONASS;
  g.prn = 9;
  const nav_rinex_glo_eph r = nav_rinex_glo_eph_from_orbit(&g, o.toe_s, -2, 450.0);
  sink s;
  sink_open(&s);
  nav_rinex_nav_header nh = {"navsim", "test", "20261127 000000 UTC", 18};
  assert_int_equal(nav_rinex_nav_write_header(s.f, &nh), NAV_OK);
  assert_int_equal(nav_rinex_nav_write_gps(s.f, &e), NAV_OK);
  assert_int_equal(nav_rinex_nav_write_glonass(s.f, &r, 18), NAV_OK);
  char *text = sink_close(&s);
  char line[256];
  line_of(text, 0, line, sizeof line);
  assert_string_equal(line,
                      "     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION / TYPE");
  line_of(text, 3, line, sizeof line);
  assert_string_equal(
      line, "                                                            END OF HEADER       "); /* A20 */
  /* GPS: toe + 2 h is in week 2447, at 01:15:12 on Sunday (602112 + 7200 - 604800 = 4512 s). */
  line_of(text, 4, line, sizeof line);
  assert_int_equal((int)strlen(line), 23 + 3 * 19);
  assert_memory_equal(line, "G17 2026 11 29 01 15 12", 23);
  /* The clock bias field: af0 in D19.12 with an E exponent. */
  char field[20];
  memcpy(field, line + 23, 19);
  field[19] = '\0';
  assert_near(strtod(field, NULL), e.af0_s, 1e-15);
  assert_int_equal(field[15], 'E');
  /* Broadcast orbit lines: 4X, 4D19.12; line 5 holds IDOT, L2 codes, week, L2P flag. */
  for (int k = 5; k <= 10; ++k) {
    line_of(text, k, line, sizeof line);
    assert_int_equal((int)strlen(line), 4 + 4 * 19);
    assert_memory_equal(line, "    ", 4);
  }
  line_of(text, 9, line, sizeof line);
  memcpy(field, line + 4 + 2 * 19, 19);
  assert_near(strtod(field, NULL), 2447.0, 0.0);
  line_of(text, 7, line, sizeof line); /* Toe: seconds of the new week */
  memcpy(field, line + 4, 19);
  assert_near(strtod(field, NULL), 4512.0, 0.0);
  line_of(text, 11, line, sizeof line);
  assert_int_equal((int)strlen(line), 4 + 2 * 19);
  /* GLONASS: epoch in UTC (18 s earlier), then X/Y/Z in km with channel -2 on the Y line. */
  line_of(text, 12, line, sizeof line);
  assert_memory_equal(line, "R09 2026 11 28 23 14 54", 23);
  line_of(text, 13, line, sizeof line);
  memcpy(field, line + 4, 19);
  assert_near(strtod(field, NULL) * 1e3, r.r_e_m.x, 1e-4);
  line_of(text, 14, line, sizeof line);
  memcpy(field, line + 4 + 3 * 19, 19);
  assert_near(strtod(field, NULL), -2.0, 0.0);
  free(text);
  FILE *f = fopen("/dev/null", "w");
  nav_rinex_gps_eph be = e;
  be.prn = 0;
  assert_int_equal(nav_rinex_nav_write_gps(f, &be), NAV_ERR_INVALID_ARG);
  be = e;
  be.e = NAN;
  assert_int_equal(nav_rinex_nav_write_gps(f, &be), NAV_ERR_INVALID_ARG);
  nav_rinex_glo_eph br = r;
  br.channel = -8;
  assert_int_equal(nav_rinex_nav_write_glonass(f, &br, 18), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_rinex_nav_write_glonass(f, &r, -1), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_rinex_nav_write_header(f, NULL), NAV_ERR_INVALID_ARG);
  fclose(f);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_calendar_and_leap_seconds),
      cmocka_unit_test(test_obs_header_and_epoch_columns),
      cmocka_unit_test(test_obs_bad_input),
      cmocka_unit_test(test_gps_record_reproduces_orbit),
      cmocka_unit_test(test_nav_records_columns),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
