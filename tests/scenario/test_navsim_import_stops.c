/*
 * navsim import of timed tracks keeps their stops and their timing (issue 18, "a timed GPX with
 * stops keeps them"):
 *  - made-up 1 Hz drives (written here as GPX, one as a KML gx:Track): straight legs flown with a
 *    trapezoidal speed profile (1.5 m/s^2) and stops of known length inside (on a straight line
 *    and at a right-angle corner), at the start and at the end, and several at once (one where the
 *    path turns back). A corner stop shorter than the turn in place needs (4 s, where 90 deg take
 *    5.33 s within the default angular limits) is held just long enough for the turn, and said so. The
 * imported scene has one stop per track stop (hold_start_s, hold_s, hold_end_s) with the track's durations
 * (to 2 ms: the times have milliseconds), lasts as long as the track (to 0.1 %, each part between stops is
 * timed to 1e-4), and its vehicle is at rest, at the stop's place, in the middle of each track stop (the
 * parts between stops are timed like the track's);
 *  - --stop-min 0 keeps no stop, --stop-min above a stop's length drops that stop; bad values
 *    are exit 2;
 *  - the shared ADIS16465 reference (../shared/data/kfgins-matlab-dataset2-adis16465/truth.nav,
 *    10 Hz, 353 s) written as a timed GPX: its stationary intervals (reference horizontal speed
 *    below 0.2 m/s for 3 s or more: the first and the last ~10 s) survive as hold_start_s and
 *    hold_end_s within 0.5 s (the import sees positions, the reference gives velocities), and the
 *    scene lasts as long as the reference to 0.1 %.
 *
 * NAVSIM_EXE, NAV_TEST_WORK_DIR and NAV_SOURCE_DIR come from the compile definitions.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_io.h"
#include "navcore/nav_traj.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define ADIS NAV_SOURCE_DIR "/../shared/data/kfgins-matlab-dataset2-adis16465/truth.nav"
#define PI 3.14159265358979323846
#define R_EARTH_M 6378137.0
#define LAT0_DEG 52.5
#define LON0_DEG 13.4

/* One piece of a made-up drive: a stop of stop_s, or a straight leg of dist_m at heading hdg_deg
 * reaching at most vmax_mps (from rest to rest, 1.5 m/s^2). */
typedef struct piece {
  double stop_s, dist_m, hdg_deg, vmax_mps;
} piece;

typedef struct sample {
  double t, n, e;
} sample;

typedef struct drive {
  sample *s;
  size_t n, cap;
  double stop_t0[16], stop_t1[16], stop_n[16], stop_e[16]; /* track stops: start, end, place */
  bool stop_corner[16];                                    /* the path turns at the stop */
  int stops;
} drive;

static void push(drive *d, double t, double n, double e) {
  if (d->n == d->cap) {
    d->cap = d->cap ? 2 * d->cap : 256;
    d->s = realloc(d->s, d->cap * sizeof *d->s);
    assert_non_null(d->s);
  }
  d->s[d->n++] = (sample){t, n, e};
}

/* Distance along a rest-to-rest trapezoid (acceleration a, top speed v, length L) at time tau. */
static double trapezoid(double a, double v, double L, double tau, double *T_out) {
  double ta = v / a, da = 0.5 * a * ta * ta;
  if (2.0 * da > L) { /* triangle */
    ta = sqrt(L / a);
    v = a * ta;
    da = 0.5 * L;
  }
  const double tc = (L - 2.0 * da) / v, T = 2.0 * ta + tc;
  *T_out = T;
  if (tau <= ta) return 0.5 * a * tau * tau;
  if (tau <= ta + tc) return da + v * (tau - ta);
  const double r = T - tau;
  return L - 0.5 * a * r * r;
}

/* Samples at 1 Hz of the drive (and at the exact end of each leg). */
static drive make_drive(const piece *p, int np) {
  drive d;
  memset(&d, 0, sizeof d);
  double t = 0.0, n = 0.0, e = 0.0, hdg = NAN;
  push(&d, t, n, e);
  for (int i = 0; i < np; ++i) {
    if (p[i].stop_s > 0.0) {
      d.stop_corner[d.stops] = i > 0 && i + 1 < np && p[i + 1].hdg_deg != hdg;
      d.stop_t0[d.stops] = t;
      d.stop_n[d.stops] = n;
      d.stop_e[d.stops] = e;
      for (int k = 1; k <= (int)p[i].stop_s; ++k)
        push(&d, t + k, n, e);
      t += p[i].stop_s;
      d.stop_t1[d.stops++] = t;
      continue;
    }
    hdg = p[i].hdg_deg;
    const double c = cos(p[i].hdg_deg * PI / 180.0), s = sin(p[i].hdg_deg * PI / 180.0);
    double T = 0.0;
    (void)trapezoid(1.5, p[i].vmax_mps, p[i].dist_m, 0.0, &T);
    for (int k = 1; (double)k < T; ++k) {
      const double x = trapezoid(1.5, p[i].vmax_mps, p[i].dist_m, k, &T);
      push(&d, t + k, n + x * c, e + x * s);
    }
    n += p[i].dist_m * c;
    e += p[i].dist_m * s;
    t += T;
    push(&d, t, n, e);
  }
  return d;
}

static void to_latlon(double n, double e, double *lat, double *lon) {
  *lat = LAT0_DEG + n / R_EARTH_M * 180.0 / PI;
  *lon = LON0_DEG + e / (R_EARTH_M * cos(LAT0_DEG * PI / 180.0)) * 180.0 / PI;
}

/* ISO 8601 UTC with milliseconds, from 2024-05-01T08:00:00Z. */
static void iso_time(double t, char *buf, size_t cap) {
  const long ms = lround(t * 1000.0);
  const long s = ms / 1000;
  snprintf(buf, cap, "2024-05-01T%02ld:%02ld:%02ld.%03ldZ", 8 + s / 3600, (s / 60) % 60, s % 60, ms % 1000);
}

static void write_gpx(const drive *d, const char *name) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(f,
          "<?xml version=\"1.0\"?>\n<gpx version=\"1.1\" creator=\"test\"><trk><name>stops</name><trkseg>\n");
  for (size_t i = 0; i < d->n; ++i) {
    double lat, lon;
    char ts[64];
    to_latlon(d->s[i].n, d->s[i].e, &lat, &lon);
    iso_time(d->s[i].t, ts, sizeof ts);
    fprintf(f, "<trkpt lat=\"%.10f\" lon=\"%.10f\"><ele>35</ele><time>%s</time></trkpt>\n", lat, lon, ts);
  }
  fprintf(f, "</trkseg></trk></gpx>\n");
  fclose(f);
}

static void write_kml(const drive *d, const char *name) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fprintf(
      f,
      "<?xml version=\"1.0\"?>\n<kml xmlns=\"http://www.opengis.net/kml/2.2\" "
      "xmlns:gx=\"http://www.google.com/kml/ext/2.2\"><Document><Placemark><name>drive</name><gx:Track>\n");
  for (size_t i = 0; i < d->n; ++i) {
    char ts[64];
    iso_time(d->s[i].t, ts, sizeof ts);
    fprintf(f, "<when>%s</when>\n", ts);
  }
  for (size_t i = 0; i < d->n; ++i) {
    double lat, lon;
    to_latlon(d->s[i].n, d->s[i].e, &lat, &lon);
    fprintf(f, "<gx:coord>%.10f %.10f 35</gx:coord>\n", lon, lat);
  }
  fprintf(f, "</gx:Track></Placemark></Document></kml>\n");
  fclose(f);
}

static nav_scene *read_scene(const char *name) {
  char path[512];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  nav_scene *s = malloc(sizeof *s);
  assert_non_null(s);
  if (nav_scene_read_file(path, s, NULL, NULL) != NAV_OK) fail_msg("%s does not read as a scene", path);
  return s;
}

/* The stops of a waypoint scene in order: durations into @p hold, count returned. */
static int scene_stops(const nav_scene *s, double *hold) {
  const nav_traj_waypoints *W = &s->trajectory.waypoints;
  int k = 0;
  if (W->hold_start_s > 0.0) hold[k++] = W->hold_start_s;
  for (int i = 0; i < W->count; ++i)
    if (W->points[i].hold_s > 0.0) hold[k++] = W->points[i].hold_s;
  if (W->hold_end_s > 0.0) hold[k++] = W->hold_end_s;
  return k;
}

/* Import @p file; check the stops against the drive's, the duration, and rest at each stop. */
static void check_import(const drive *d, const char *file, const char *extra) {
  char out[64];
  snprintf(out, sizeof out, "%s.yaml", file);
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import %s --out %s %s", file, out, extra);
  if (r->code != 0) fail_msg("import %s: exit %d\n%s", file, r->code, r->err);
  print_message("%s", r->out);
  nav_test_assert_matches(r->out,
                          "^stops      [0-9]+ \\([0-9.]+ s at rest: speed below 0.2 m/s for at least 3 s\\); "
                          "duration [0-9.]+ s, the track's [0-9.]+ s$");
  nav_scene *s = read_scene(out);
  double hold[16];
  const int k = scene_stops(s, hold);
  assert_int_equal(k, d->stops);
  for (int i = 0; i < k; ++i) {
    const double want = d->stop_t1[i] - d->stop_t0[i];
    print_message("  stop %d: %.3f s in the scene, %.3f s in the track\n", i, hold[i], want);
    if (!d->stop_corner[i] || want >= 5.33) {
      assert_near(hold[i], want, 2e-3);
    } else {
      /* Shorter than a 90 deg turn in place takes at the default limits (5.33 s: test_traj): held
         just long enough for it, and said so. */
      assert_true(hold[i] >= 5.32 && hold[i] <= 5.34);
      nav_test_assert_matches(r->out, "^note       1 stop held longer than on the track, to turn in place");
    }
  }
  const double T_track = d->s[d->n - 1].t - d->s[0].t;
  print_message("  duration %.4f s, the track's %.4f s\n", s->trajectory.duration_s, T_track);
  assert_near(s->trajectory.duration_s, T_track, 1e-3 * T_track);
  /* At rest, at the stop's place, in the middle of each track stop. */
  nav_traj *tr = NULL;
  assert_int_equal(nav_traj_create(s, 0.01, &tr), NAV_OK);
  const nav_frame fr = nav_traj_frame(tr);
  for (int i = 0; i < d->stops; ++i) {
    nav_traj_state ts;
    assert_int_equal(nav_traj_eval(tr, 0.5 * (d->stop_t0[i] + d->stop_t1[i]), &ts), NAV_OK);
    const nav_local_view v = nav_frame_view(&fr, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f);
    double lat, lon;
    to_latlon(d->stop_n[i], d->stop_e[i], &lat, &lon);
    const double dn = (v.pos.lat_rad * 180.0 / PI - lat) * PI / 180.0 * R_EARTH_M;
    const double de =
        (v.pos.lon_rad * 180.0 / PI - lon) * PI / 180.0 * R_EARTH_M * cos(LAT0_DEG * PI / 180.0);
    print_message("  mid-stop %d: speed %.3g m/s, %.3f m from the stop\n", i, nav_vec3_norm(v.v_n_mps),
                  hypot(dn, de));
    assert_true(nav_vec3_norm(v.v_n_mps) < 1e-9);
    assert_true(hypot(dn, de) < 0.1);
  }
  nav_traj_destroy(tr);
  free(s);
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

/* Two interior stops: on a straight line and at a right-angle corner. */
static void test_interior(void **state) {
  (void)state;
  const piece p[] = {{0, 300, 90, 10}, {20, 0, 0, 0}, {0, 200, 0, 8}, {15, 0, 0, 0}, {0, 150, 0, 8}};
  drive d = make_drive(p, 5);
  write_gpx(&d, "interior.gpx");
  check_import(&d, "interior.gpx", "");
  /* The same as a KML gx:Track. */
  write_kml(&d, "interior.kml");
  check_import(&d, "interior.kml", "");
  free(d.s);
}

/* Stops at the start and at the end (and one at the corner between). */
static void test_ends(void **state) {
  (void)state;
  const piece p[] = {{12, 0, 0, 0}, {0, 400, 45, 12}, {4, 0, 0, 0}, {0, 200, 135, 10}, {9, 0, 0, 0}};
  drive d = make_drive(p, 5);
  write_gpx(&d, "ends.gpx");
  check_import(&d, "ends.gpx", "");
  free(d.s);
}

/* Several: start, three inside (one where the path turns back), end. */
static void test_several(void **state) {
  (void)state;
  const piece p[] = {{5, 0, 0, 0},    {0, 250, 0, 10}, {8, 0, 0, 0},      {0, 250, 270, 10}, {30, 0, 0, 0},
                     {0, 120, 90, 8}, {25, 0, 0, 0},   {0, 300, 180, 12}, {6, 0, 0, 0}};
  drive d = make_drive(p, 9);
  write_gpx(&d, "several.gpx");
  check_import(&d, "several.gpx", "");

  /* --stop-min: 0 keeps none; 10 s drops the stops shorter than that. Without its stops the
     track cannot be followed closely (it turns back at one): --accept-distance. */
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                                        "import several.gpx --out none.yaml --stop-min 0 --accept-distance");
  if (r->code != 0) fail_msg("--stop-min 0: exit %d\n%s", r->code, r->err);
  nav_scene *s = read_scene("none.yaml");
  double hold[16];
  assert_int_equal(scene_stops(s, hold), 0);
  free(s);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "import several.gpx --out long.yaml --stop-min 10 --accept-distance");
  if (r->code != 0) fail_msg("--stop-min 10: exit %d\n%s", r->code, r->err);
  s = read_scene("long.yaml");
  assert_int_equal(scene_stops(s, hold), 2);
  assert_near(hold[0], 30.0, 2e-3);
  assert_near(hold[1], 25.0, 2e-3);
  free(s);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import several.gpx --out bad.yaml --stop-speed -1");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "--stop-speed: expected a speed in \\[0, 10\\] m/s");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import several.gpx --out bad.yaml --stop-min x");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "--stop-min: expected a duration");
  assert_false(nav_test_is_file(WORK "/bad.yaml"));
  free(d.s);
}

/* The shared ADIS16465 reference as a timed GPX. */
static void test_adis16465(void **state) {
  (void)state;
  FILE *in = fopen(ADIS, "r");
  if (!in) fail_msg("cannot read %s", ADIS);
  FILE *f = fopen(WORK "/adis.gpx", "w");
  assert_non_null(f);
  fprintf(f,
          "<?xml version=\"1.0\"?>\n<gpx version=\"1.1\" creator=\"test\"><trk><name>adis</name><trkseg>\n");
  double runs[16][2];
  int nruns = 0;
  double run_t0 = NAN, t_first = NAN, t_last = NAN, t_prev = NAN;
  char line[512];
  while (fgets(line, sizeof line, in)) {
    double wk, t, lat, lon, h, vn, ve, vd, ro, pi, ya;
    if (sscanf(line, "%lf %lf %lf %lf %lf %lf %lf %lf %lf %lf %lf", &wk, &t, &lat, &lon, &h, &vn, &ve, &vd,
               &ro, &pi, &ya) != 11)
      continue;
    if (isnan(t_first)) t_first = t;
    t_last = t;
    /* The reference's stationary intervals: horizontal speed below 0.2 m/s for 3 s or more. */
    const bool slow = hypot(vn, ve) < 0.2;
    if (slow && isnan(run_t0)) run_t0 = t;
    if (!slow && !isnan(run_t0)) {
      if (t_prev - run_t0 >= 3.0 && nruns < 16) {
        runs[nruns][0] = run_t0;
        runs[nruns++][1] = t_prev;
      }
      run_t0 = NAN;
    }
    t_prev = t;
    /* Seconds of the week from 2020-01-01T00:00:00Z, microseconds kept. */
    const long long us = llround(t * 1e6);
    const long long s = us / 1000000;
    fprintf(f,
            "<trkpt lat=\"%.10f\" "
            "lon=\"%.10f\"><ele>%.4f</ele><time>2020-01-%02lldT%02lld:%02lld:%02lld.%06lldZ</time></trkpt>\n",
            lat, lon, h, 1 + s / 86400, (s / 3600) % 24, (s / 60) % 60, s % 60, us % 1000000);
  }
  if (!isnan(run_t0) && t_prev - run_t0 >= 3.0 && nruns < 16) {
    runs[nruns][0] = run_t0;
    runs[nruns++][1] = t_prev;
  }
  fprintf(f, "</trkseg></trk></gpx>\n");
  fclose(f);
  fclose(in);
  for (int i = 0; i < nruns; ++i)
    print_message("reference at rest %.3f .. %.3f s (%.3f s)\n", runs[i][0] - t_first, runs[i][1] - t_first,
                  runs[i][1] - runs[i][0]);
  /* The data set starts and ends at rest, and has no other stop of 3 s. */
  assert_int_equal(nruns, 2);
  assert_near(runs[0][0], t_first, 0.0);
  assert_near(runs[1][1], t_last, 0.0);

  nav_cli_result *r =
      nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "import adis.gpx --out adis.yaml --accept-distance");
  if (r->code != 0) fail_msg("import: exit %d\n%s", r->code, r->err);
  print_message("%s", r->out);
  nav_scene *s = read_scene("adis.yaml");
  const nav_traj_waypoints *W = &s->trajectory.waypoints;
  double hold[16];
  assert_int_equal(scene_stops(s, hold), 2);
  print_message(
      "hold_start_s %.3f s (reference %.3f s), hold_end_s %.3f s (reference %.3f s), duration %.3f s "
      "(reference %.3f s)\n",
      W->hold_start_s, runs[0][1] - runs[0][0], W->hold_end_s, runs[1][1] - runs[1][0],
      s->trajectory.duration_s, t_last - t_first);
  assert_near(W->hold_start_s, runs[0][1] - runs[0][0], 0.5);
  assert_near(W->hold_end_s, runs[1][1] - runs[1][0], 0.5);
  assert_near(s->trajectory.duration_s, t_last - t_first, 1e-3 * (t_last - t_first));
  free(s);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_interior),
      cmocka_unit_test(test_ends),
      cmocka_unit_test(test_several),
      cmocka_unit_test(test_adis16465),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
