#define _POSIX_C_SOURCE 200809L
/*
 * The exact fast path of the recorded-data readers (navcore/io/fast_number.h): whenever it
 * accepts a field, the double must be bit-identical to strtod's (glibc's strtod is correctly
 * rounded); everything outside the fast path must be declined (the readers then use strtod).
 * Random decimal strings of every shape the data files use and many they do not, the digits of
 * the shared long-drive files themselves, and the reader's file:line:col report of a malformed
 * field after the change.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fast_number.h"
#include "line_layout.h"
#include "nav_test.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_rng.h"

typedef struct tally {
  long fast, declined;
} tally;

/* Compare one string: accepted -> identical to strtod; returns whether it was accepted. */
static bool check_one(const char *s, tally *t) {
  double v = 0.0;
  const size_t n = strlen(s);
  if (!nav_fast_number(s, s + n, &v)) {
    t->declined++;
    return false;
  }
  char *end = NULL;
  const double ref = strtod(s, &end);
  if (end != s + n) fail_msg("fast path accepted \"%s\", which strtod does not consume fully", s);
  if (memcmp(&v, &ref, sizeof v) != 0)
    fail_msg("\"%s\": fast path %.17g (%a), strtod %.17g (%a)", s, v, v, ref, ref);
  t->fast++;
  return true;
}

static uint64_t next_u(nav_rng *r, uint64_t n) {
  return nav_rng_next_u64(r) % n;
}

/* Random strings built digit by digit: sign, 0..14 integer digits (leading zeros allowed),
 * optional point with 0..16 fraction digits, optional exponent -40..40 with optional sign. */
static void test_random_digit_strings(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261122u, 0u, 0u);
  tally t = {0, 0};
  char s[96];
  for (int it = 0; it < 400000; ++it) {
    size_t p = 0;
    const uint64_t sign = next_u(&r, 4);
    if (sign == 1) s[p++] = '-';
    if (sign == 2) s[p++] = '+';
    const int int_digits = (int)next_u(&r, 15);
    for (int i = 0; i < int_digits; ++i)
      s[p++] = (char)('0' + next_u(&r, 10));
    const bool point = next_u(&r, 4) != 0;
    int frac_digits = 0;
    if (point) {
      s[p++] = '.';
      frac_digits = (int)next_u(&r, 17);
      for (int i = 0; i < frac_digits; ++i)
        s[p++] = (char)('0' + next_u(&r, 10));
    }
    if (int_digits + frac_digits == 0) s[p++] = '7';
    if (next_u(&r, 3) == 0) {
      s[p++] = next_u(&r, 2) ? 'e' : 'E';
      const uint64_t es = next_u(&r, 3);
      if (es == 1) s[p++] = '-';
      if (es == 2) s[p++] = '+';
      p += (size_t)snprintf(s + p, sizeof s - p, "%d", (int)next_u(&r, 41));
    }
    s[p] = '\0';
    check_one(s, &t);
  }
  print_message("[ fastnum  ] random digit strings: %ld on the fast path (bit-identical to strtod), %ld "
                "declined\n",
                t.fast, t.declined);
  /* Most of these are within the fast path; the rest exercise the decline. */
  assert_true(t.fast > 200000);
  assert_true(t.declined > 10000);
}

/* printf renderings of random doubles in the formats of recorded data (%.Nf, %.Ne, %.Ng). */
static void test_random_printf_values(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 77u, 1u, 0u);
  tally t = {0, 0};
  char s[96];
  static const char *const fmts[] = {"%.6f", "%.3f", "%.11f", "%.4f", "%.12e", "%.9e", "%.15g", "%.17g", "%.3e"};
  for (int it = 0; it < 300000; ++it) {
    const double mag = pow(10.0, -8.0 + 14.0 * nav_rng_uniform(&r));
    const double v = (nav_rng_uniform(&r) < 0.5 ? -1.0 : 1.0) * mag * nav_rng_uniform(&r);
    snprintf(s, sizeof s, fmts[it % (int)(sizeof fmts / sizeof fmts[0])], v);
    check_one(s, &t);
  }
  print_message("[ fastnum  ] printf renderings: %ld fast, %ld declined\n", t.fast, t.declined);
  assert_true(t.fast > 250000);
}

/* Fractions with runs of leading zeros (0.000000001234..., which the eight- and four-digit steps
 * skip without counting them as significant) followed by 1..22 significant digits, at every
 * alignment against the eight- and four-byte steps, with and without an exponent. Accepted values
 * are strtod's; those with at most 15 significant digits and a scale within 10^+-22 must be
 * accepted. */
static void test_leading_zero_fractions(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261127u, 5u, 0u);
  tally t = {0, 0};
  long must = 0;
  char s[128];
  for (int it = 0; it < 300000; ++it) {
    size_t p = 0;
    if (next_u(&r, 3) == 0) s[p++] = '-';
    const int lead_int = (int)next_u(&r, 3); /* "", "0", "00" */
    for (int i = 0; i < lead_int; ++i)
      s[p++] = '0';
    s[p++] = '.';
    const int zeros = (int)next_u(&r, 25);
    for (int i = 0; i < zeros; ++i)
      s[p++] = '0';
    const int nsig = 1 + (int)next_u(&r, 22);
    s[p++] = (char)('1' + next_u(&r, 9));
    for (int i = 1; i < nsig; ++i)
      s[p++] = (char)('0' + next_u(&r, 10));
    const int trail = (int)next_u(&r, 4); /* trailing zeros are digits too */
    for (int i = 0; i < trail; ++i)
      s[p++] = '0';
    int e = 0;
    if (next_u(&r, 2) == 0) {
      e = (int)next_u(&r, 41) - 20;
      p += (size_t)snprintf(s + p, sizeof s - p, "e%d", e);
    }
    s[p] = '\0';
    const bool fast = check_one(s, &t);
    /* Scale of the last digit: 10^(e - zeros - nsig - trail); significant digits nsig + trail. */
    const int q = e - zeros - nsig - trail;
    if (nsig + trail <= 15 && q >= -22 && q <= 22) {
      must++;
      if (!fast) fail_msg("\"%s\" should be on the fast path", s);
    }
  }
  print_message("[ fastnum  ] leading-zero fractions: %ld fast (%ld required), %ld declined\n", t.fast, must,
                t.declined);
  assert_true(must > 50000);
}

/* Edge cases: exact results at the limits of the fast path, signed zeros, and the texts that
 * must be declined. */
static void test_edges(void **state) {
  (void)state;
  tally t = {0, 0};
  static const char *const accepted[] = {
      "0",     "-0",   "+0.0", "0.000", "-0.0e5",  ".5",    "5.",    "1e22",  "1e-22", "9007199254740992",
      "9007199254740992e22", "9007199254740992e-22", "4503599627370497e-1", "0.1", "0.2", "0.3",
      "100000.005000", "-177.000000", "3.550682422333e-06", "-4.911053131454e-02", "31.50818300000",
      "0000000000000000000000001.5", "1.000000000000000"};
  for (size_t i = 0; i < sizeof accepted / sizeof accepted[0]; ++i)
    if (!check_one(accepted[i], &t)) fail_msg("\"%s\" should be on the fast path", accepted[i]);
  double v = 1.0;
  assert_true(nav_fast_number("-0", "-0" + 2, &v));
  assert_true(v == 0.0 && signbit(v));
  static const char *const declined[] = {"",      "-",      "+",        ".",      "e5",     "1e",    "1e+",
                                         "1e-",   "0x1p3",  "nan",      "inf",    "-inf",   "1.2.3", "1,5",
                                         "12a",   "1e99999", "9007199254740993", "1e23", "1e-23", "--1",
                                         "1e+-2", " 1",     "1 ",       "12345678901234567890"};
  for (size_t i = 0; i < sizeof declined / sizeof declined[0]; ++i) {
    const char *s = declined[i];
    v = 42.0;
    if (nav_fast_number(s, s + strlen(s), &v)) fail_msg("\"%s\" should be declined (got %.17g)", s, v);
    assert_true(v == 42.0); /* untouched */
  }
}

/* The whole-word path of printf's "%.12e" shape (d.dddddddddddde[+-]dd) at its edges: the
 * exponents where the scale 10^(e-12) leaves +-22 (e-10 is in, e-11 out; e+34 in, e+35 out), both
 * exponent letters and signs, a sign in front, zero, the largest significand, and near misses of
 * the shape (three exponent digits, one, a comma for the point, a missing sign) that the general
 * scan or strtod must read instead - every accepted value identical to strtod's. Then 200 000
 * random %.12e renderings across the whole double range. */
static void test_sci12_shape(void **state) {
  (void)state;
  tally t = {0, 0};
  static const char *const must[] = {
      "3.550682422333e-06", "-4.911053131454e-02", "+9.999999999999e+34", "9.999999999999e-10",
      "1.000000000000e-10", "1.000000000000E+00", "0.000000000000e+00", "-0.000000000000e-99",
      "7.000000000001e+22", "5.000000000000e-01", "1.234567890123e+05"};
  for (size_t i = 0; i < sizeof must / sizeof must[0]; ++i)
    if (!check_one(must[i], &t)) fail_msg("\"%s\" should be accepted", must[i]);
  static const char *const other[] = {"9.999999999999e-11", "2.220446049250e-16", "1.000000000000e+35", "1.000000000000e-100",
                                      "1.000000000000e-5",  "1,000000000000e-05", "1.000000000000e05",
                                      "1.00000000000e-05",  "1.0000000000000e-05", "1.000000000000x-05",
                                      "1.000000000000e--5", "1.0000000000a0e-05", "11000000000000e-05"};
  for (size_t i = 0; i < sizeof other / sizeof other[0]; ++i)
    check_one(other[i], &t); /* accepted or declined: if accepted, strtod's value */
  nav_rng r;
  nav_rng_init(&r, 20261127u, 23u, 0u);
  char s[64];
  long accepted = 0;
  for (int it = 0; it < 200000; ++it) {
    const double mag = pow(10.0, -40.0 + 80.0 * nav_rng_uniform(&r));
    const double v = (nav_rng_uniform(&r) < 0.5 ? -1.0 : 1.0) * mag * nav_rng_uniform(&r);
    snprintf(s, sizeof s, it % 7 == 0 ? "%+.12E" : "%.12e", v);
    accepted += check_one(s, &t);
  }
  print_message("[ fastnum  ] %%.12e shape: %ld fast (%ld of the random ones), %ld declined\n", t.fast, accepted,
                t.declined);
  assert_true(accepted > 40000);
}

/* printf's "%.Nf" shape (1-7 integer digits, up to 15 fraction digits), which the reference and
 * GNSS columns use and the word-at-a-time fixed-point path converts: its edges, every prefix of
 * a longer text (the bytes after the end must not matter), what the scan returns when a field
 * is followed by other text, and random renderings, all against strtod. */
static void test_fixed_shape(void **state) {
  (void)state;
  tally t = {0, 0};
  static const char *const must[] = {
      "0",          "-0",          "7",          "1234567",        "-0.000000",       "100000.005000",
      "31.50818300000", "120.40198900000", "-177.000000", "0.1",         "9999999.99999999", "1.00000000",
      "1.000000001", "1.123456789012345", "0.000000000000001", "9007199254.740992", "+5.25"};
  for (size_t i = 0; i < sizeof must / sizeof must[0]; ++i)
    if (!check_one(must[i], &t)) fail_msg("\"%s\" should be accepted", must[i]);
  static const char *const other[] = {"5.",         "12345678.5",   "1.5e3",         "1.5E-3",
                                      "123.1234567890123456", "9007199254.740993", "1234567.1234567890123",
                                      ".5",         "1..5",         "00000001.5",    "0.0000000000000000000001"};
  for (size_t i = 0; i < sizeof other / sizeof other[0]; ++i)
    check_one(other[i], &t); /* accepted or declined: if accepted, strtod's value */
  /* Every prefix of a long field, the rest of the text still in memory after the end. */
  static const char *const longs[] = {"1234567.123456789012345678", "-31.508183000001234567", "0.00000000012345678"};
  for (size_t i = 0; i < sizeof longs / sizeof longs[0]; ++i) {
    const size_t n = strlen(longs[i]);
    for (size_t k = 1; k <= n; ++k) {
      char cut[64];
      memcpy(cut, longs[i], k);
      cut[k] = '\0';
      double v = 0.0;
      if (nav_fast_number(longs[i], longs[i] + k, &v)) {
        char *end = NULL;
        const double ref = strtod(cut, &end);
        if (end != cut + k || memcmp(&v, &ref, sizeof v) != 0)
          fail_msg("prefix \"%s\": fast path %.17g, strtod %.17g", cut, v, ref);
      }
    }
  }
  /* The end of the scan: at the first character that cannot continue the number. */
  static const struct {
    const char *s;
    size_t end;
  } stops[] = {{"100000.005000 31.5", 13}, {"0 100000.0", 1}, {"-177.000000\r", 11}, {"12.5x", 4}, {"12x", 2}};
  for (size_t i = 0; i < sizeof stops / sizeof stops[0]; ++i) {
    double v = 0.0;
    const char *s = stops[i].s;
    const char *q = nav_fast_number_scan(s, s + strlen(s), &v);
    assert_non_null(q);
    assert_int_equal((long)(q - s), (long)stops[i].end);
    const double ref = strtod(s, NULL);
    assert_memory_equal(&v, &ref, sizeof v);
  }
  nav_rng r;
  nav_rng_init(&r, 20261127u, 31u, 0u);
  char s[64];
  long accepted = 0;
  for (int it = 0; it < 300000; ++it) {
    const int idigits = 1 + (int)next_u(&r, 7);
    const int prec = (int)next_u(&r, 16);
    const double v = (nav_rng_uniform(&r) < 0.5 ? -1.0 : 1.0) * nav_rng_uniform(&r) * pow(10.0, idigits);
    snprintf(s, sizeof s, "%.*f", prec, v);
    accepted += check_one(s, &t);
  }
  print_message("[ fastnum  ] %%.Nf shape: %ld fast (%ld of the random ones), %ld declined\n", t.fast, accepted,
                t.declined);
  assert_true(accepted > 200000);
}

/* nav_fast_fixed_scan_padded (the reference reader's line-level path): on text followed by its
 * terminating byte and more bytes, it accepts only what nav_fast_number_scan accepts, with the
 * same end and the same bits (strtod's); digits after the terminating byte are never read in. */
static void check_padded(const char *s, const char *after, tally *t) {
  char buf[128];
  const size_t n = strlen(s);
  assert_true(n + 1 + 24 < sizeof buf);
  memset(buf, 0, sizeof buf);
  memcpy(buf, s, n);
  buf[n] = '\0';
  memcpy(buf + n + 1, after, strlen(after));
  double v = 0.0, g = 0.0;
  const char *q = nav_fast_fixed_scan_padded(buf, &v);
  const char *qg = nav_fast_number_scan(buf, buf + n, &g);
  if (!q) {
    t->declined++;
    return;
  }
  if (!qg || q != qg) fail_msg("\"%s\": the padded scan accepted up to %ld, the general scan %ld", s, (long)(q - buf),
                               qg ? (long)(qg - buf) : -1L);
  if (memcmp(&v, &g, sizeof v) != 0) fail_msg("\"%s\": padded %.17g, general %.17g", s, v, g);
  char *end = NULL;
  const double ref = strtod(buf, &end);
  if (end != q || memcmp(&v, &ref, sizeof v) != 0) fail_msg("\"%s\": padded %.17g, strtod %.17g", s, v, ref);
  t->fast++;
}

static void test_fixed_padded(void **state) {
  (void)state;
  tally t = {0, 0};
  static const char *const must[] = {"0",           "-0",          "7",         "1234567",      "-0.000000",
                                     "100000.005000", "31.50818300000", "120.40198900000", "-177.000000", "0.1",
                                     "9999999.99999999", "1.00000000", "1.000000001", "1.123456789012345",
                                     "0.000000000000001", "9007199254.740992", "+5.25", "12345678"};
  static const char *const afters[] = {"", "99999999", "0123456789012345", "e5", ".5"};
  for (size_t i = 0; i < sizeof must / sizeof must[0]; ++i)
    for (size_t a = 0; a < sizeof afters / sizeof afters[0]; ++a) check_padded(must[i], afters[a], &t);
  /* Must be declined (other shapes: the general scan or strtod read them). */
  static const char *const other[] = {"5.",  "12345678.5", "1.5e3", "1.5E-3", "123.1234567890123456",
                                      ".5",  "1..5",       "-",     "+",      "",
                                      " 5",  "1e5",        "9007199254.740993", "00000001.5", "-.5"};
  for (size_t i = 0; i < sizeof other / sizeof other[0]; ++i) {
    char buf[64] = {0};
    memcpy(buf, other[i], strlen(other[i]));
    double v = 0.0;
    const char *q = nav_fast_fixed_scan_padded(buf, &v);
    if (q && *q != '\0') continue; /* stopped early ("12345678.5" is not read as one number) */
    if (q) fail_msg("\"%s\" should be declined by the padded scan", other[i]);
  }
  nav_rng r;
  nav_rng_init(&r, 20261127u, 41u, 0u);
  char s[64];
  long accepted = 0;
  for (int it = 0; it < 400000; ++it) {
    const int idigits = 1 + (int)next_u(&r, 7);
    const int prec = (int)next_u(&r, 17);
    const double v = (nav_rng_uniform(&r) < 0.5 ? -1.0 : 1.0) * nav_rng_uniform(&r) * pow(10.0, idigits);
    snprintf(s, sizeof s, "%.*f", prec, v);
    const long before = t.fast;
    check_padded(s, (it & 1) ? "987654321" : "", &t);
    accepted += t.fast - before;
  }
  print_message("[ fastnum  ] padded %%.Nf scan: %ld fast (%ld of the random ones), %ld declined\n", t.fast, accepted,
                t.declined);
  assert_true(accepted > 300000);
}

/* A .nav reference read by the line-level path gives the values of the field-by-field path and
 * the same messages: the same rows written with blanks and tabs that only the field-by-field path
 * reads, and errors at their columns. */
static void read_all_pva(const char *text, nav_rec_pva *rows, int cap, int *n, nav_status *st, nav_diag *d) {
  nav_rec_reader *r = NULL;
  assert_int_equal(nav_rec_reader_open_memory(text, strlen(text), "ref.nav", NAV_REC_PVA, &r), NAV_OK);
  *n = 0;
  *st = NAV_OK;
  for (;;) {
    bool got = false;
    nav_rec_pva row;
    *st = nav_rec_read_pva(r, &row, &got);
    if (*st != NAV_OK || !got) break;
    if (*n < cap) rows[(*n)++] = row;
  }
  *d = *nav_rec_reader_diag(r);
  nav_rec_reader_destroy(r);
}

static void test_pva_line_path(void **state) {
  (void)state;
  static const char fast[] = "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 "
                             "0.000000 0.000000 -177.000000\n"
                             "2179 100000.010000 -31.508183123 -120.40198900000 -12.5000 1.250000 -2.500000 "
                             "0.125000 -10.000000 45.000000 359.500000\n"
                             "2179 100000.015000 89.99999999999 359.99999999999 100000.0000 9999.999999 0 -0 "
                             "180.000000 -90.000000 -180.000000";
  static const char slow[] = "  0\t100000.005000 31.50818300000  120.40198900000 0.0000 0.000000 0.000000 0.000000 "
                             "0.000000 0.000000 -177.000000\r\n"
                             "# a comment\n\n"
                             "2179 100000.010000 -31.508183123 -120.40198900000 -12.5000 1.250000 -2.500000 "
                             "0.125000 -10.000000 45.000000 359.500000 \n"
                             "2179 1.00000015e5 89.99999999999 359.99999999999 1e5 9999.999999 0 -0 "
                             "180.000000 -90.000000 -180.000000\n";
  nav_rec_pva a[4], b[4];
  int na = 0, nb = 0;
  nav_status sa, sb;
  nav_diag da, db;
  read_all_pva(fast, a, 4, &na, &sa, &da);
  read_all_pva(slow, b, 4, &nb, &sb, &db);
  assert_int_equal(sa, NAV_OK);
  assert_int_equal(sb, NAV_OK);
  assert_int_equal(na, 3);
  assert_int_equal(nb, 3);
  for (int i = 0; i < 3; ++i) {
    assert_int_equal(a[i].week, b[i].week);
    const double va[10] = {a[i].t_s, a[i].pos.lat_rad, a[i].pos.lon_rad, a[i].pos.h_m, a[i].v_n_mps.x,
                           a[i].v_n_mps.y, a[i].v_n_mps.z, a[i].att.roll_rad, a[i].att.pitch_rad, a[i].att.yaw_rad};
    const double vb[10] = {b[i].t_s, b[i].pos.lat_rad, b[i].pos.lon_rad, b[i].pos.h_m, b[i].v_n_mps.x,
                           b[i].v_n_mps.y, b[i].v_n_mps.z, b[i].att.roll_rad, b[i].att.pitch_rad, b[i].att.yaw_rad};
    assert_memory_equal(va, vb, sizeof va);
  }
  assert_true(signbit(a[2].v_n_mps.z) && signbit(b[2].v_n_mps.z));
  /* Errors on lines the line-level path reads: the column of the field, as before. */
  static const struct {
    const char *text;
    int line, col;
    const char *words;
  } bad[] = {
      {"0 100000.005000 95.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 1.0\n", 1,
       17, "latitude 95.508183 deg outside [-90, 90]"},
      {"0 100000.005000  31.5   400.0 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 1.0\n", 1, 25,
       "longitude 400 deg outside [-180, 360]"},
      {"0 100000.005000 31.5 120.4 0.0 0.0 0.0 0.0 0.0 0.0 1.0\n0 100000.005000 31.5 120.4 0.0 0.0 0.0 0.0 0.0 0.0 "
       "1.0\n",
       2, 3, "time must increase"},
      {"1.5 100000.005000 31.5 120.4 0.0 0.0 0.0 0.0 0.0 0.0 1.0\n", 1, 1, "GPS week 1.5"},
      {"0 100000.005000 31.5 120.4 0.0 0.0 0.0 0.0 0.0 0.0 1.0 7\n", 1, 56, "expected 11 columns"},
      {"0 100000.005000 31.5 120.4 0.0 0.0 0.0 0.0 0.0 95.0 1.0\n", 1, 48, "pitch 95 deg outside [-90, 90]"},
      {"0 100000.005000 31.5 120.4 0.0 0.0 0.0 0.0 0.0 0.0 1.0x\n", 1, 52, "expected a number, found \"1.0x\""},
      /* second rows with the layout of the first (read from the learned layout, line_layout.h) */
      {"0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 10.000000 "
       "1.000000\n0 100000.010000 95.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 "
       "10.000000 1.000000\n",
       2, 17, "latitude 95.508183 deg outside [-90, 90]"},
      {"0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 10.000000 "
       "1.000000\n0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 "
       "10.000000 1.000000\n",
       2, 3, "time must increase"},
      {"0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 10.000000 "
       "1.000000\n0 100000.010000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 "
       "95.000000 1.000000\n",
       2, 92, "pitch 95 deg outside [-90, 90]"},
      {"0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 10.000000 "
       "1.000000\n0 100000.010000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 10.000000 "
       "10.000000 1.00000x\n",
       2, 102, "expected a number, found \"1.00000x\""},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    nav_rec_pva rows[2];
    int n = 0;
    nav_status st;
    nav_diag d;
    read_all_pva(bad[i].text, rows, 2, &n, &st, &d);
    assert_int_equal(st, NAV_ERR_PARSE);
    if (d.line != bad[i].line || d.col != bad[i].col || !strstr(d.message, bad[i].words))
      fail_msg("case %zu: %d:%d %s; expected %d:%d and \"%s\"", i, d.line, d.col, d.message, bad[i].line, bad[i].col,
               bad[i].words);
  }
}

/* ------------------------------------------------------------ speculative layout (line_layout.h) */

/* Random rows in the shape of a .nav reference (11 fields: week, time, lat, lon, h, velocity,
 * attitude), most of them with the layout of the row before (only digits change), some with a
 * changed layout: a sign appears or goes, a digit count changes (9.99 -> 10.00), other fraction
 * digits, extra blanks, a tab, CR LF, a leading or trailing blank, a '+', fields of 16-19 digits,
 * lines longer than a layout takes. */
typedef struct rowgen {
  nav_rng rng;
  double v[11];
  int prec[11];
  int week;
  long i;
} rowgen;

static const double k_row_lo[11] = {0,      0,      -89.9,  -179.9, -999.0, -300.0,
                                    -300.0, -300.0, -179.0, -89.0,  -179.0};
static const double k_row_hi[11] = {0, 0, 89.9, 359.9, 99999.0, 300.0, 300.0, 300.0, 179.0, 89.0, 359.0};

static void rowgen_init(rowgen *g, uint64_t seed) {
  nav_rng_init(&g->rng, seed, 7u, 0u);
  static const int prec[11] = {0, 6, 11, 11, 4, 6, 6, 6, 6, 6, 6};
  for (int k = 0; k < 11; ++k) {
    g->prec[k] = prec[k];
    g->v[k] = k_row_lo[k] + (k_row_hi[k] - k_row_lo[k]) * nav_rng_uniform(&g->rng);
  }
  g->week = 2179;
  g->i = 0;
}

/* The next row into s (no line end); @p mutate: also the layout changes that only the
 * field-by-field reader reads (blanks, tabs, CR, '+', long fields). Values stay in the ranges the
 * .nav reader accepts and the time increases. */
static void rowgen_next(rowgen *g, bool mutate, char *s, size_t cap) {
  nav_rng *r = &g->rng;
  for (int k = 2; k < 11; ++k) {
    const double u = nav_rng_uniform(r);
    if (u < 0.005) /* a jump: another sign or digit count, usually */
      g->v[k] = k_row_lo[k] + (k_row_hi[k] - k_row_lo[k]) * nav_rng_uniform(r);
    else if (u < 0.01) /* near a digit-count or sign boundary */
      g->v[k] = (nav_rng_uniform(r) < 0.5 ? -1.0 : 1.0) * (pow(10.0, (double)next_u(r, 3)) - 1e-5) +
                1e-5 * (nav_rng_uniform(r) - 0.5);
    else /* the last digits only */
      g->v[k] += 1e-4 * (nav_rng_uniform(r) - 0.5);
    if (g->v[k] < k_row_lo[k] || g->v[k] > k_row_hi[k]) g->v[k] = 0.5 * (k_row_lo[k] + k_row_hi[k]);
  }
  if (next_u(r, 500) == 0) g->week++;
  g->i++;
  g->v[1] = 100000.0 + 0.005 * (double)g->i;
  int prec[11];
  memcpy(prec, g->prec, sizeof prec);
  const int kind = mutate ? (int)next_u(r, 100) : -1; /* one row in nine changed */
  const int at = 1 + (int)next_u(r, 10);
  /* other fraction digits (0: no point; the time keeps at least 3, so that it still increases) */
  if (kind == 0) prec[at] = at == 1 ? 3 + (int)next_u(r, 13) : (int)next_u(r, 16);
  if (kind == 1) prec[at] = 12 + (int)next_u(r, 4); /* 16-19 digits, or > 15 fraction digits */
  if (kind == 2)
    for (int k = 2; k < 11; ++k)
      prec[k] = 15;              /* a line longer than a layout takes */
  if (kind == 10) prec[at] = 40; /* a field longer than the reader's buffer padding (32 bytes) */
  size_t p = (size_t)snprintf(s, cap, "%s%d", kind == 3 ? " " : "", g->week);
  for (int k = 1; k < 11; ++k) {
    const char *sep = " ";
    if (k == at && kind == 4) sep = "  ";
    if (k == at && kind == 5) sep = "\t";
    if (k == at && kind == 6 && g->v[k] >= 0.0) sep = " +";
    if (k == at && kind == 7) sep = " \v";
    p += (size_t)snprintf(s + p, cap - p, "%s%.*f", sep, prec[k], g->v[k]);
  }
  if (kind == 8) p += (size_t)snprintf(s + p, cap - p, "\r");
  if (kind == 9) p += (size_t)snprintf(s + p, cap - p, " ");
  assert_true(p < cap);
}

/* Fields of a line by strtod, blank-separated; false unless the line is exactly 11 fields of
 * [+-.0-9] characters with blanks between them and none before or after. */
static bool strtod_row(const char *line, double *v) {
  const char *p = line;
  for (int k = 0; k < 11; ++k) {
    if (k > 0) {
      if (!(*p == ' ' || *p == '\t' || *p == '\r' || *p == '\v' || *p == '\f')) return false;
      while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\v' || *p == '\f')
        ++p;
    }
    const char *q = p;
    while ((*q >= '0' && *q <= '9') || *q == '+' || *q == '-' || *q == '.')
      ++q;
    if (q == p) return false;
    char *end = NULL;
    v[k] = strtod(p, &end);
    if (end != q) return false;
    p = q;
  }
  return *p == '\0';
}

/* Check a line against the layout as the reader does: a match must give strtod's bits for every
 * field. The line sits in a buffer whose bytes after its terminating NUL are digits (so a word
 * loaded past the end would show). Returns whether it matched. */
static bool layout_check_line(nav_line_layout *L, const char *line, long *learned) {
  char buf[640];
  const size_t n = strlen(line);
  assert_true(n + 1 + 32 <= sizeof buf);
  for (size_t i = 0; i < sizeof buf; ++i)
    buf[i] = (char)('0' + (i * 7u) % 10u);
  memcpy(buf, line, n + 1);
  double v[11], ref[11];
  if (nav_layout_match(L, buf, n)) {
    nav_layout_convert(L, buf, 11, v);
    if (!strtod_row(line, ref)) fail_msg("the layout accepted \"%s\", which is not 11 numeric fields", line);
    for (int k = 0; k < 11; ++k)
      if (memcmp(&v[k], &ref[k], sizeof v[k]) != 0)
        fail_msg("\"%s\" field %d: layout %.17g, strtod %.17g", line, k + 1, v[k], ref[k]);
    return true;
  }
  if (nav_layout_learn(L, buf, n, 11)) {
    ++*learned;
    /* The learned line itself must match its layout and give strtod's values. */
    if (!nav_layout_match(L, buf, n)) fail_msg("\"%s\" does not match the layout learned from it", line);
    nav_layout_convert(L, buf, 11, v);
    if (!strtod_row(line, ref))
      fail_msg("a layout was learned from \"%s\", which is not 11 numeric fields", line);
    for (int k = 0; k < 11; ++k)
      if (memcmp(&v[k], &ref[k], sizeof v[k]) != 0)
        fail_msg("\"%s\" field %d (learned): layout %.17g, strtod %.17g", line, k + 1, v[k], ref[k]);
  }
  return false;
}

/* A layout learned from one row and every way of changing it: only rows that differ in digits
 * alone match, and then give strtod's values. */
static void test_layout_changes(void **state) {
  (void)state;
  static const char base[] =
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 "
      "0.000000 0.000000 -177.000000";
  static const char *const same[] = {
      "9 199999.995999 89.99999999999 359.99999999999 9.9999 9.999999 9.999999 9.999999 9.999999 9.999999 "
      "-999.999999",
      "0 100000.010000 31.50818312345 120.40198987654 0.0000 0.000001 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0 000000.000000 00.00000000000 000.00000000000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-000.000000",
  };
  static const char *const changed[] = {
      /* a sign appears (longer line), a sign moves (same length), a sign goes */
      "0 100000.005000 -31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0 100000.005000 -31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "177.0000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "+177.000000",
      /* integer digits: one more (9.99 -> 10.00) and one less with a fraction digit more */
      "0 100000.005000 31.50818300000 120.40198900000 10.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 10.00000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-17.0000000",
      /* the point moved within the same field width; an extra blank; a tab; CR; leading and trailing
       * blanks; a character next to the digits ('/' and ':'), a letter, a high byte, an exponent */
      "0 100000.005000 315.0818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0 100000.005000  31.5081830000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0\t100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.00000\r",
      " 0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.00000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.00000 ",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000/00 0.000000 0.000000 "
      "-177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.00:000 "
      "-177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.00000x",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.0000\xb0"
      "0 -177.000000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.0000e0 "
      "-177.000000",
      /* a field shorter or longer at the end: the line length differs */
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.00000",
      "0 100000.005000 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 "
      "-177.000000 1",
  };
  nav_line_layout L;
  L.count = 0;
  long learned = 0;
  assert_false(layout_check_line(&L, base, &learned));
  assert_int_equal(learned, 1);
  assert_true(layout_check_line(&L, base, &learned));
  for (size_t i = 0; i < sizeof same / sizeof same[0]; ++i)
    if (!layout_check_line(&L, same[i], &learned)) fail_msg("\"%s\" should match the layout", same[i]);
  for (size_t i = 0; i < sizeof changed / sizeof changed[0]; ++i) {
    nav_line_layout M;
    M.count = 0;
    long l2 = 0;
    assert_false(layout_check_line(&M, base, &l2));
    char buf[NAV_LAYOUT_MAX_LINE + 64] = {0};
    memcpy(buf, changed[i], strlen(changed[i]));
    if (nav_layout_match(&M, buf, strlen(buf)))
      fail_msg("\"%s\" matched the layout of the base row", changed[i]);
  }
  /* What a layout does not take: fields of more than 15 digits, more than 7 integer digits, "5."
   * without fraction digits, lines longer than NAV_LAYOUT_MAX_LINE bytes. */
  static const char *const unlearned[] = {
      "0 100000.0050001234 31.50818300000 120.40198900000 0.0000 0.000000 0.000000 0.000000 0.000000 "
      "0.000000 1.0",
      "0 100000.005000 31.50818300000 12345678.0 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 1.0",
      "0 100000.005000 31.50818300000 120. 0.0000 0.000000 0.000000 0.000000 0.000000 0.000000 1.0",
      "0 100000.005000 31.508183000000000 120.401989000000000 0.0000000000 0.000000000000 0.000000000000 "
      "0.000000000000 0.000000000000 0.000000000000 1.0",
      "0 100000.005000 31.5081830000000000000000000000000000000000001 120.4 0.0 0.0 0.0 0.0 0.0 0.0 1.0",
  };
  for (size_t i = 0; i < sizeof unlearned / sizeof unlearned[0]; ++i) {
    char buf[256] = {0};
    memcpy(buf, unlearned[i], strlen(unlearned[i]));
    if (nav_layout_learn(&L, buf, strlen(buf), 11))
      fail_msg("a layout was learned from \"%s\"", unlearned[i]);
    assert_false(nav_layout_match(&L, base, strlen(base)));
  }
}

/* Random rows against the layout of the row before, as the reader runs it: every match gives
 * strtod's bits, and both the matches and the relearning are exercised. */
static void test_layout_random_rows(void **state) {
  (void)state;
  rowgen g;
  rowgen_init(&g, 20261127u);
  nav_line_layout L;
  L.count = 0;
  long hits = 0, misses = 0, learned = 0;
  char s[512];
  for (int it = 0; it < 200000; ++it) {
    rowgen_next(&g, true, s, sizeof s);
    /* and now and then a digit replaced by a byte that is not one */
    if (next_u(&g.rng, 100) == 0) {
      static const char bad[] = {'/', ':', 'x', ' ', '.', '-', '\x80', '\xff'};
      const size_t at = (size_t)next_u(&g.rng, strlen(s));
      if (s[at] >= '0' && s[at] <= '9') s[at] = bad[next_u(&g.rng, sizeof bad)];
    }
    if (layout_check_line(&L, s, &learned))
      ++hits;
    else
      ++misses;
  }
  print_message(
      "[ fastnum  ] layout: %ld rows matched the layout of the row before, %ld did not (%ld relearned)\n",
      hits, misses, learned);
  assert_true(hits > 100000);
  assert_true(misses > 20000);
  assert_true(learned > 10000);
}

/* Read a .nav text with the reader; every row's values into v (11 per row, as the reader returns
 * them) and the status and message at the end. */
static int read_pva_values(const char *text, double *v, int cap, nav_status *st, nav_diag *d) {
  nav_rec_reader *r = NULL;
  assert_int_equal(nav_rec_reader_open_memory(text, strlen(text), "ref.nav", NAV_REC_PVA, &r), NAV_OK);
  int n = 0;
  for (;;) {
    bool got = false;
    nav_rec_pva row;
    *st = nav_rec_read_pva(r, &row, &got);
    if (*st != NAV_OK || !got) break;
    if (n < cap) {
      const double x[11] = {(double)row.week, row.t_s,           row.pos.lat_rad, row.pos.lon_rad,
                            row.pos.h_m,      row.v_n_mps.x,     row.v_n_mps.y,   row.v_n_mps.z,
                            row.att.roll_rad, row.att.pitch_rad, row.att.yaw_rad};
      memcpy(v + 11 * n, x, sizeof x);
    }
    ++n;
  }
  *d = *nav_rec_reader_diag(r);
  nav_rec_reader_destroy(r);
  return n;
}

/* Random .nav files (several reader buffers long, rows whose layout changes in every way, comment
 * and empty lines, CR LF, a last line without a line end) read by the reader give, value by value,
 * what the reader gives for the same rows each with a leading blank (which only the field-by-field
 * path reads). */
static void test_layout_reader_files(void **state) {
  (void)state;
  enum { ROWS = 30000 };
  for (int file = 0; file < 3; ++file) {
    rowgen g;
    rowgen_init(&g, 1000u + (uint64_t)file);
    const size_t cap = (size_t)ROWS * 300u;
    char *fast = malloc(cap), *slow = malloc(cap);
    double *a = malloc(sizeof(double) * 11 * ROWS), *b = malloc(sizeof(double) * 11 * ROWS);
    assert_non_null(fast);
    assert_non_null(slow);
    assert_non_null(a);
    assert_non_null(b);
    size_t pf = 0, ps = 0;
    char s[512];
    for (int i = 0; i < ROWS; ++i) {
      rowgen_next(&g, file > 0, s, sizeof s);
      const bool last = i + 1 == ROWS;
      const char *end = last && file == 2 ? "" : "\n";
      if (next_u(&g.rng, 1000) == 0) {
        pf += (size_t)snprintf(fast + pf, cap - pf, "# comment\n\n");
        ps += (size_t)snprintf(slow + ps, cap - ps, "# comment\n\n");
      }
      pf += (size_t)snprintf(fast + pf, cap - pf, "%s%s", s, end);
      ps += (size_t)snprintf(slow + ps, cap - ps, " %s%s", s, end);
    }
    nav_status sa, sb;
    nav_diag da, db;
    const int na = read_pva_values(fast, a, ROWS, &sa, &da);
    const int nb = read_pva_values(slow, b, ROWS, &sb, &db);
    if (sa != NAV_OK) fail_msg("file %d: %s:%d:%d %s", file, da.file, da.line, da.col, da.message);
    assert_int_equal(sb, NAV_OK);
    assert_int_equal(na, ROWS);
    assert_int_equal(nb, ROWS);
    for (int i = 0; i < ROWS; ++i)
      for (int k = 0; k < 11; ++k)
        if (memcmp(&a[11 * i + k], &b[11 * i + k], sizeof(double)) != 0)
          fail_msg("file %d row %d field %d: %.17g, field by field %.17g", file, i + 1, k + 1, a[11 * i + k],
                   b[11 * i + k]);
    free(fast);
    free(slow);
    free(a);
    free(b);
  }
}

/* nav_fast_sci12_scan_padded (the IMU reader's line-level path): the same acceptance, end and bits
 * as nav_fast_number_scan on "%.12e" text, whatever follows the terminating byte. */
static void check_sci_padded(const char *s, const char *after, tally *t) {
  char buf[128];
  const size_t n = strlen(s);
  assert_true(n + 1 + 40 < sizeof buf);
  memset(buf, 0, sizeof buf);
  memcpy(buf, s, n);
  memcpy(buf + n + 1, after, strlen(after));
  double v = 0.0, g = 0.0;
  const char *q = nav_fast_sci12_scan_padded(buf, &v);
  if (!q) {
    t->declined++;
    return;
  }
  const char *qg = nav_fast_number_scan(buf, buf + n, &g);
  if (!qg || q != qg) fail_msg("\"%s\": the padded scan accepted up to %ld, the general scan %ld", s, (long)(q - buf),
                               qg ? (long)(qg - buf) : -1L);
  char *end = NULL;
  const double ref = strtod(buf, &end);
  if (end != q || memcmp(&v, &g, sizeof v) != 0 || memcmp(&v, &ref, sizeof v) != 0)
    fail_msg("\"%s\": padded %.17g, general %.17g, strtod %.17g", s, v, g, ref);
  t->fast++;
}

static void test_sci_padded(void **state) {
  (void)state;
  tally t = {0, 0};
  static const char *const must[] = {"3.550682422333e-06", "-1.757083616415e-06", "-4.911053131454e-02",
                                     "0.000000000000e+00", "-0.000000000000e+00", "9.999999999999e+22",
                                     "1.000000000000e-10", "+5.000000000000e+00"};
  static const char *const afters[] = {"", "5", "12345678901234567890", "e+05"};
  for (size_t i = 0; i < sizeof must / sizeof must[0]; ++i)
    for (size_t a = 0; a < sizeof afters / sizeof afters[0]; ++a) {
      const long before = t.fast;
      check_sci_padded(must[i], afters[a], &t);
      if (t.fast == before) fail_msg("\"%s\" should be accepted", must[i]);
    }
  /* Declined: cut short (the rest of a longer number after the terminating byte must not be
   * read as its digits), a 13th digit, a 3-digit exponent, other shapes, |q| > 22. */
  static const char *const other[] = {"3.550682422333e-0", "3.550682422333e", "3.55068242233e-06",
                                      "3.5506824223330e-06", "3.550682422333e-106", "35.50682422333e-06",
                                      "3.550682422333x-06", "1.000000000000e-11", "", "-", "3.5"};
  for (size_t i = 0; i < sizeof other / sizeof other[0]; ++i) {
    char buf[80] = {0};
    memcpy(buf, other[i], strlen(other[i]));
    memcpy(buf + strlen(other[i]) + 1, "0123456789e+01", 14);
    double v = 0.0;
    const char *q = nav_fast_sci12_scan_padded(buf, &v);
    if (q && *q == '\0') fail_msg("\"%s\" should be declined by the padded %%.12e scan", other[i]);
  }
  nav_rng r;
  nav_rng_init(&r, 20261127u, 43u, 0u);
  char s[64];
  for (int it = 0; it < 300000; ++it) {
    const double v = (nav_rng_uniform(&r) < 0.5 ? -1.0 : 1.0) * nav_rng_uniform(&r) *
                     pow(10.0, (double)((int)next_u(&r, 30) - 15));
    snprintf(s, sizeof s, "%.12e", v);
    const long before = t.fast;
    check_sci_padded(s, (it & 1) ? "98765432109876543210" : "", &t);
    /* Declined only outside Clinger's case: exponents below -10 (10^(e-12) beyond 10^-22). */
    if (t.fast == before && atoi(s + strlen(s) - 3) >= -10) fail_msg("\"%s\" should be accepted", s);
  }
  print_message("[ fastnum  ] padded %%.12e scan: %ld fast, %ld declined\n", t.fast, t.declined);
  assert_true(t.fast > 200000);
}

/* IMU records read by the line-level path give the values and messages of the field-by-field
 * path (the same records written so that only the latter reads them). */
static void test_imu_line_path(void **state) {
  (void)state;
  static const char fast[] =
      "100000.005000 3.550682422333e-06 -1.757083616415e-06 -2.985800620171e-07 -9.093064074826e-05 "
      "8.384128995745e-05 -4.911053131454e-02\n"
      "100000.010000 -1.555077539977e-06 0.001 2.811151415522e-06 9.432643236281e-05 -2.609348822230e-05 "
      "-4.896167903435e-02\n"
      "100000.015 0 -0.000000000000e+00 1.0e-3 1 -2 3";
  static const char slow[] =
      "100000.005000\t3.550682422333e-06 -1.757083616415e-06 -2.985800620171e-07 -9.093064074826e-05 "
      "8.384128995745e-05 -4.911053131454e-02\r\n"
      "# comment\n"
      " 100000.010000 -1.555077539977e-06 1e-3 2.811151415522e-06 9.432643236281e-05 -2.609348822230e-05 "
      "-4.896167903435e-02\n"
      "100000.015 0 -0.0 0.001 1 -2 3 \n";
  nav_imu_increment a[3], b[3];
  for (int pass = 0; pass < 2; ++pass) {
    const char *text = pass ? slow : fast;
    nav_imu_increment *out = pass ? b : a;
    nav_rec_reader *r = NULL;
    assert_int_equal(nav_rec_reader_open_memory(text, strlen(text), "imu.txt", NAV_REC_IMU, &r), NAV_OK);
    for (int i = 0; i < 3; ++i) {
      bool got = false;
      assert_int_equal(nav_rec_read_imu(r, &out[i], &got), NAV_OK);
      assert_true(got);
    }
    nav_rec_reader_destroy(r);
  }
  for (int i = 0; i < 3; ++i) {
    const double va[8] = {a[i].t_s, a[i].dt_s, a[i].dtheta_b_rad.x, a[i].dtheta_b_rad.y, a[i].dtheta_b_rad.z,
                          a[i].dv_b_mps.x, a[i].dv_b_mps.y, a[i].dv_b_mps.z};
    const double vb[8] = {b[i].t_s, b[i].dt_s, b[i].dtheta_b_rad.x, b[i].dtheta_b_rad.y, b[i].dtheta_b_rad.z,
                          b[i].dv_b_mps.x, b[i].dv_b_mps.y, b[i].dv_b_mps.z};
    assert_memory_equal(va, vb, sizeof va);
  }
  static const struct {
    const char *text;
    int line, col;
    const char *words;
  } bad[] = {
      {"100.0 1e-6 2e-6 3e-6 0.1 0.2 9.8\n100.005 4.000000000000e+00 2e-6 3e-6 0.1 0.2 9.8\n", 2, 9,
       "angle increment 4 rad exceeds pi"},
      {"100.0 1.000000000000e-06 2e-6 3e-6 0.1 0.2 2.000000000000e+04\n", 1, 44, "velocity increment 20000 m/s"},
      {"100.0 1e-6 2e-6 3e-6 0.1 0.2 9.8\n100.0 1.000000000000e-06 2e-6 3e-6 0.1 0.2 9.8\n", 2, 1,
       "time must increase"},
      {"100.0 1.000000000000e-06 2e-6 3e-6 0.1 0.2\n", 1, 43, "expected 7 columns"},
  };
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    nav_rec_reader *r = NULL;
    assert_int_equal(nav_rec_reader_open_memory(bad[i].text, strlen(bad[i].text), "imu.txt", NAV_REC_IMU, &r), NAV_OK);
    nav_status st = NAV_OK;
    for (int k = 0; k < 3 && st == NAV_OK; ++k) {
      nav_imu_increment inc;
      bool got = false;
      st = nav_rec_read_imu(r, &inc, &got);
      if (st == NAV_OK && !got) break;
    }
    const nav_diag *d = nav_rec_reader_diag(r);
    assert_int_equal(st, NAV_ERR_PARSE);
    if (d->line != bad[i].line || d->col != bad[i].col || !strstr(d->message, bad[i].words))
      fail_msg("case %zu: %d:%d %s; expected %d:%d and \"%s\"", i, d->line, d->col, d->message, bad[i].line,
               bad[i].col, bad[i].words);
    nav_rec_reader_destroy(r);
  }
}

/* Every field of the first lines of the shared long-drive files: all on the fast path and
 * identical to strtod. Skipped when the shared data is not there. */
static void test_shared_files(void **state) {
  (void)state;
  static const char *const files[] = {"IMU.txt", "truth.nav", "GNSS_outage.txt"};
  for (size_t fi = 0; fi < 3; ++fi) {
    char path[512];
    snprintf(path, sizeof path, "%s/data/gnss-ins-sim-long-drive/%s", NAV_SHARED_DIR, files[fi]);
    FILE *f = fopen(path, "r");
    if (!f) {
      print_message("[ fastnum  ] %s not found: skipped\n", path);
      continue;
    }
    char line[512];
    tally t = {0, 0};
    for (int l = 0; l < 20000 && fgets(line, sizeof line, f); ++l) {
      char *save = NULL;
      for (char *tok = strtok_r(line, " \t\r\n", &save); tok; tok = strtok_r(NULL, " \t\r\n", &save))
        check_one(tok, &t);
    }
    fclose(f);
    /* Declined: values below 1e-10 with 13 digits (10^-23 and beyond is not exact), rare. */
    print_message("[ fastnum  ] %s: %ld fields identical to strtod on the fast path, %ld declined (strtod)\n",
                  files[fi], t.fast, t.declined);
    assert_true(t.fast > 0);
    assert_true(t.declined * 1000 < t.fast);
  }
}

/* A malformed field is still reported with its line and column (the slow path words it). */
static void test_malformed_reported(void **state) {
  (void)state;
  static const char text[] = "100.000 1e-6 2e-6 3e-6 0.1 0.2 9.8\n"
                             "100.005 1e-6 2e-6 3e-6 0.1 0x0.2p1 9.8\n";
  nav_rec_reader *r = NULL;
  assert_int_equal(nav_rec_reader_open_memory(text, sizeof text - 1, "mem.txt", NAV_REC_IMU, &r), NAV_OK);
  nav_imu_increment inc;
  bool got = false;
  assert_int_equal(nav_rec_read_imu(r, &inc, &got), NAV_OK);
  assert_true(got);
  assert_true(inc.dv_b_mps.z == strtod("9.8", NULL));
  assert_int_equal(nav_rec_read_imu(r, &inc, &got), NAV_ERR_PARSE);
  const nav_diag *d = nav_rec_reader_diag(r);
  assert_string_equal(d->file, "mem.txt");
  assert_int_equal(d->line, 2);
  assert_int_equal(d->col, 28);
  assert_non_null(strstr(d->message, "0x0.2p1"));
  nav_rec_reader_destroy(r);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_random_digit_strings),
      cmocka_unit_test(test_random_printf_values),
      cmocka_unit_test(test_edges),
      cmocka_unit_test(test_sci12_shape),
      cmocka_unit_test(test_fixed_shape),
      cmocka_unit_test(test_fixed_padded),
      cmocka_unit_test(test_pva_line_path),
      cmocka_unit_test(test_layout_changes),
      cmocka_unit_test(test_layout_random_rows),
      cmocka_unit_test(test_layout_reader_files),
      cmocka_unit_test(test_sci_padded),
      cmocka_unit_test(test_imu_line_path),
      cmocka_unit_test(test_shared_files),
      cmocka_unit_test(test_leading_zero_fractions),
      cmocka_unit_test(test_malformed_reported),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
