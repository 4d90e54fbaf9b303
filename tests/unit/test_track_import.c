/*
 * GPX / KML track import, waypoint conversion, KML / CSV export, scene overrides and the
 * catalog cost class (navcore_io: track_import.c, kml_export.c, scene_override.c, catalog.c).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "nav_test.h"
#include "navcore/nav_catalog.h"
#include "navcore/nav_frames.h"
#include "navcore/nav_io.h"
#include "navcore/nav_scene_override.h"
#include "navcore/nav_track_import.h"

#define TRACKS NAV_TEST_DATA_DIR "/tracks"

typedef struct diag_log {
  int n;
  nav_diag d[16];
} diag_log;

static void collect(void *user, const nav_diag *d) {
  diag_log *l = user;
  if (l->n < 16) l->d[l->n] = *d;
  l->n++;
}

static nav_status read_str(const char *text, nav_track_format fmt, nav_geotrack *t, diag_log *log) {
  memset(log, 0, sizeof *log);
  return nav_geotrack_read_string(text, strlen(text), "mem.xml", fmt, NULL, t, collect, log);
}

/* GPX: points, heights, times (UTC, offsets, fractions), the track name. */
static void test_gpx_points_and_times(void **state) {
  (void)state;
  const char *gpx =
      "<?xml version=\"1.0\"?>\n"
      "<gpx version=\"1.1\" xmlns=\"http://www.topografix.com/GPX/1/1\"><trk><name> my run </name><trkseg>\n"
      "<trkpt lat=\"48.5\" lon=\"-11.25\"><ele>100.5</ele><time>2024-02-29T23:59:59Z</time></trkpt>\n"
      "<trkpt lat=\"48.6\" lon=\"-11.25\"><ele>101</ele><time>2024-03-01T01:00:00.250+01:00</time></trkpt>\n"
      "<trkpt lat=\"48.7\" lon=\"190\"><time>1970-01-01T00:00:10Z</time></trkpt>\n"
      "</trkseg></trk></gpx>\n";
  nav_geotrack t;
  diag_log log;
  /* The third point goes back in time: reported at its element. */
  assert_int_equal(read_str(gpx, NAV_TRACK_FORMAT_AUTO, &t, &log), NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  assert_int_equal(log.d[0].line, 5);
  assert_int_equal(log.d[0].col, 1);
  assert_non_null(strstr(log.d[0].message, "backwards"));

  const char *gpx2 =
      "<gpx><trk><name> my run </name><trkseg>\n"
      "<trkpt lat=\"48.5\" lon=\"-11.25\"><ele>100.5</ele><time>2024-02-29T23:59:59Z</time></trkpt>\n"
      "<trkpt lat=\"48.6\" lon=\"-11.25\"><ele>101</ele><time>2024-03-01T01:00:00.250+01:00</time></trkpt>\n"
      "<trkpt lat=\"-48.7\" lon=\"190\"/>\n"
      "</trkseg></trk></gpx>\n";
  assert_int_equal(read_str(gpx2, NAV_TRACK_FORMAT_GPX, &t, &log), NAV_OK);
  assert_int_equal(t.count, 3);
  assert_string_equal(t.name, "my run");
  assert_false(t.all_timed);
  assert_near(t.points[0].pos.lat_rad, 48.5 * NAV_DEG2RAD, 1e-15);
  assert_near(t.points[0].pos.lon_rad, -11.25 * NAV_DEG2RAD, 1e-15);
  assert_near(t.points[0].pos.h_m, 100.5, 0);
  assert_true(t.points[0].has_h && t.points[0].has_time);
  /* 2024-02-29T23:59:59Z = 1709251199 s (leap day); the next is 1 s later, plus 0.25 s. */
  assert_near(t.points[0].t_s, 1709251199.0, 0);
  assert_near(t.points[1].t_s - t.points[0].t_s, 1.25, 1e-9);
  assert_false(t.points[2].has_h);
  assert_near(t.points[2].pos.lon_rad, -170.0 * NAV_DEG2RAD, 1e-14); /* wrapped */
  assert_int_equal(t.points[2].line, 4);
  nav_geotrack_free(&t);
}

/* Malformed input: each problem at its FILE:LINE:COL, never a crash. */
static void test_errors_located(void **state) {
  (void)state;
  nav_geotrack t;
  diag_log log;
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_geotrack_read_file(TRACKS "/bad_lat.gpx", NAV_TRACK_FORMAT_AUTO, NULL, &t, collect, &log),
                   NAV_ERR_PARSE);
  assert_int_equal(log.n, 2);
  assert_int_equal(log.d[0].line, 6);
  assert_string_equal(log.d[0].path, "trkpt");
  assert_non_null(strstr(log.d[0].message, "148.2"));
  assert_int_equal(log.d[1].line, 7);
  assert_int_equal(log.d[1].col, 39);
  assert_string_equal(log.d[1].path, "ele");

  memset(&log, 0, sizeof log);
  assert_int_equal(nav_geotrack_read_file(TRACKS "/broken.kml", NAV_TRACK_FORMAT_AUTO, NULL, &t, collect, &log),
                   NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  assert_int_equal(log.d[0].line, 6);
  assert_non_null(strstr(log.d[0].message, "not well-formed"));

  memset(&log, 0, sizeof log);
  assert_int_equal(nav_geotrack_read_file(TRACKS "/bad_coords.kml", NAV_TRACK_FORMAT_AUTO, NULL, &t, collect, &log),
                   NAV_ERR_PARSE);
  assert_int_equal(log.n, 1);
  assert_int_equal(log.d[0].line, 7);
  assert_int_equal(log.d[0].col, 7);

  assert_int_equal(nav_geotrack_read_file(TRACKS "/no-such-file.gpx", NAV_TRACK_FORMAT_AUTO, NULL, &t, NULL, NULL),
                   NAV_ERR_IO);
  /* Wrong root, empty document, no track. */
  assert_int_equal(read_str("<html/>", NAV_TRACK_FORMAT_AUTO, &t, &log), NAV_ERR_PARSE);
  assert_int_equal(read_str("", NAV_TRACK_FORMAT_AUTO, &t, &log), NAV_ERR_PARSE);
  assert_int_equal(read_str("<gpx><trk/></gpx>", NAV_TRACK_FORMAT_GPX, &t, &log), NAV_ERR_PARSE);
  assert_int_equal(read_str("<kml><Document/></kml>", NAV_TRACK_FORMAT_KML, &t, &log), NAV_ERR_PARSE);
  /* A KML asked for as GPX. */
  assert_int_equal(read_str("<kml/>", NAV_TRACK_FORMAT_GPX, &t, &log), NAV_ERR_PARSE);
  /* Bad times. */
  assert_int_equal(read_str("<gpx><trk><trkseg><trkpt lat=\"1\" lon=\"2\"><time>2024-13-01T00:00:00Z</time></trkpt>"
                            "</trkseg></trk></gpx>",
                            NAV_TRACK_FORMAT_GPX, &t, &log),
                   NAV_ERR_PARSE);
  assert_int_equal(log.d[0].line, 1);
  assert_string_equal(log.d[0].path, "time");
}

/* KML: LineString tuples, gx:Track when/coord pairs, Placemark selection by name. */
static void test_kml_linestring_and_gx_track(void **state) {
  (void)state;
  const char *kml =
      "<kml xmlns=\"http://www.opengis.net/kml/2.2\" xmlns:gx=\"http://www.google.com/kml/ext/2.2\"><Document>\n"
      "<Placemark><name>dot</name><Point><coordinates>1,2,3</coordinates></Point></Placemark>\n"
      "<Placemark><name>line</name><LineString><coordinates> 11.5,48.1,500\n 11.6,48.2 </coordinates></LineString>"
      "</Placemark>\n"
      "<Placemark><name>gx</name><gx:Track><when>2020-01-01T00:00:00Z</when><when>2020-01-01T00:00:05Z</when>"
      "<gx:coord>11 48 10</gx:coord><gx:coord>11.001 48 11</gx:coord></gx:Track></Placemark>\n"
      "</Document></kml>\n";
  nav_geotrack t;
  diag_log log;
  /* The first Placemark with a track: the Point is skipped. */
  assert_int_equal(read_str(kml, NAV_TRACK_FORMAT_KML, &t, &log), NAV_OK);
  assert_string_equal(t.name, "line");
  assert_int_equal(t.count, 2);
  assert_near(t.points[0].pos.lat_rad, 48.1 * NAV_DEG2RAD, 1e-15);
  assert_near(t.points[0].pos.lon_rad, 11.5 * NAV_DEG2RAD, 1e-15);
  assert_near(t.points[0].pos.h_m, 500, 0);
  assert_false(t.points[1].has_h);
  assert_int_equal(t.points[1].line, 4);
  assert_int_equal(t.points[1].col, 2);
  assert_false(t.all_timed);
  nav_geotrack_free(&t);
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_geotrack_read_string(kml, strlen(kml), "m.kml", NAV_TRACK_FORMAT_AUTO, "gx", &t, collect, &log),
                   NAV_OK);
  assert_int_equal(t.count, 2);
  assert_true(t.all_timed);
  assert_near(t.points[1].t_s - t.points[0].t_s, 5.0, 0);
  assert_near(t.points[1].pos.h_m, 11, 0);
  nav_geotrack_free(&t);
  assert_int_equal(nav_geotrack_read_string(kml, strlen(kml), "m.kml", NAV_TRACK_FORMAT_AUTO, "nope", &t, collect, &log),
                   NAV_ERR_PARSE);
  /* Mismatched when/coord counts. */
  const char *bad = "<kml><Placemark><Track><when>2020-01-01T00:00:00Z</when><coord>1 2 3</coord>"
                    "<coord>1 2.1 3</coord></Track></Placemark></kml>";
  assert_int_equal(read_str(bad, NAV_TRACK_FORMAT_KML, &t, &log), NAV_ERR_PARSE);
  assert_string_equal(log.d[0].path, "gx:Track");
}

/* Waypoints from a track: origin at the first point, NED positions equal to the points' local
 * coordinates, thinning within the tolerance, the flown path near every track point. */
static void test_track_to_scene(void **state) {
  (void)state;
  nav_geotrack t;
  assert_int_equal(nav_geotrack_read_file(TRACKS "/path.kml", NAV_TRACK_FORMAT_AUTO, NULL, &t, NULL, NULL), NAV_OK);
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  *sc = nav_scene_default();
  nav_track_import_options o = nav_track_import_options_default();
  o.speed_mps = 5.0;
  nav_track_import_report rep;
  char msg[512];
  assert_int_equal(nav_geotrack_to_scene(&t, &o, sc, &rep, msg, sizeof msg), NAV_OK);
  assert_int_equal(sc->earth.model, NAV_EARTH_WGS84);
  assert_int_equal(sc->trajectory.type, NAV_TRAJ_WAYPOINTS);
  assert_int_equal(rep.waypoints, 5); /* a square-cornered path: nothing to thin */
  assert_int_equal(rep.merged, 0);
  const nav_frame fr = nav_frame_from_scene(sc);
  for (int i = 0; i < 5; ++i) {
    const nav_geodetic g = nav_frame_local_to_geodetic(&fr, sc->trajectory.waypoints.points[i].r_ned_m);
    assert_near(g.lat_rad, t.points[i].pos.lat_rad, 1e-13);
    assert_near(g.lon_rad, t.points[i].pos.lon_rad, 1e-13);
    assert_near(g.h_m, t.points[i].pos.h_m, 1e-6);
    assert_near(sc->trajectory.waypoints.points[i].speed_mps, 5.0, 0);
  }
  /* Fly-by corners of 90 deg at 5 m/s cut less than at 10 m/s. */
  const double dev5 = rep.max_dev_m;
  o.speed_mps = 10.0;
  assert_int_equal(nav_geotrack_to_scene(&t, &o, sc, &rep, msg, sizeof msg), NAV_OK);
  assert_true(dev5 < rep.max_dev_m);
  print_message("path.kml: flown path within %.3f m (5 m/s) and %.3f m (10 m/s) of the track points\n", dev5,
                rep.max_dev_m);
  nav_geotrack_free(&t);

  /* A dense timed curve: thinned within the tolerance, turns merged until feasible, speeds from
   * the times (10 m/s in the file). */
  assert_int_equal(nav_geotrack_read_file(TRACKS "/drive.gpx", NAV_TRACK_FORMAT_AUTO, NULL, &t, NULL, NULL), NAV_OK);
  assert_int_equal(t.count, 107);
  o = nav_track_import_options_default();
  assert_int_equal(nav_geotrack_to_scene(&t, &o, sc, &rep, msg, sizeof msg), NAV_OK);
  assert_true(rep.timed);
  assert_true(rep.waypoints >= 2 && rep.waypoints < 20);
  for (int i = 0; i < sc->trajectory.waypoints.count; ++i) {
    const double v = sc->trajectory.waypoints.points[i].speed_mps;
    assert_true(v > 9.0 && v < 10.5);
  }
  /* Duration within 10 % of the track's 106 s (the fly-by turns shorten the path). */
  const double T = t.points[t.count - 1].t_s - t.points[0].t_s;
  assert_true(fabs(rep.duration_s - T) < 0.1 * T);
  print_message("drive.gpx: %d waypoints, %d merged, %.3f s (track %.0f s), flown path within %.3f m\n", rep.waypoints,
                rep.merged, rep.duration_s, T, rep.max_dev_m);
  /* Without merging, the dense curve is infeasible: the message names the waypoint and the limit,
   * bad_point the track point. */
  o.max_merges = 0;
  assert_int_equal(nav_geotrack_to_scene(&t, &o, sc, &rep, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "waypoint"));
  assert_non_null(strstr(msg, "max_lateral_accel_mps2"));
  assert_true(rep.bad_point > 0 && rep.bad_point < (int)t.count - 1);
  nav_geotrack_free(&t);

  /* Fewer than two distinct points. */
  nav_geopoint p[2];
  memset(p, 0, sizeof p);
  nav_geotrack one = {p, 2, false, ""};
  assert_int_equal(nav_geotrack_to_scene(&one, &o, sc, &rep, msg, sizeof msg), NAV_ERR_INVALID_ARG);
  free(sc);
}

/* KML export -> KML import: the same coordinates to the export precision (1e-9 deg, 1e-4 m). */
static void test_kml_round_trip(void **state) {
  (void)state;
  enum { N = 500 };
  static nav_geodetic pos[N];
  static double t[N];
  for (int i = 0; i < N; ++i) {
    t[i] = 0.1 * i;
    pos[i].lat_rad = (47.0 + 0.001 * i + 1.234567891e-7 * sin(i)) * NAV_DEG2RAD;
    pos[i].lon_rad = (-179.99 + 0.0001 * i) * NAV_DEG2RAD;
    pos[i].h_m = 100.0 + 0.123456 * i;
  }
  char dir[] = "/tmp/nav_kml_XXXXXX";
  assert_non_null(mkdtemp(dir));
  char path[256], csv[256];
  snprintf(path, sizeof path, "%s/t.kml", dir);
  snprintf(csv, sizeof csv, "%s/t.csv", dir);
  const nav_kml_track tr[2] = {{"reference <&>", "ff00ff00", 3, false, t, pos, N},
                               {"points", "ff00ffff", 1, true, t, pos, 10}};
  assert_int_equal(nav_kml_write_file(path, "doc", tr, 2, 100000), NAV_OK);
  assert_int_equal(nav_tracks_csv_write_file(csv, tr, 2), NAV_OK);
  nav_geotrack g;
  diag_log log;
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_geotrack_read_file(path, NAV_TRACK_FORMAT_AUTO, NULL, &g, collect, &log), NAV_OK);
  assert_string_equal(g.name, "reference <&>");
  assert_int_equal(g.count, N);
  double worst = 0, worst_h = 0;
  for (int i = 0; i < N; ++i) {
    worst = fmax(worst, fabs(g.points[i].pos.lat_rad - pos[i].lat_rad));
    worst = fmax(worst, fabs(nav_wrap_pi(g.points[i].pos.lon_rad - pos[i].lon_rad)));
    worst_h = fmax(worst_h, fabs(g.points[i].pos.h_m - pos[i].h_m));
  }
  print_message("KML round trip: %.3g deg, %.3g m\n", worst * NAV_RAD2DEG, worst_h);
  assert_true(worst * NAV_RAD2DEG <= 5.0000001e-10);
  assert_true(worst_h <= 5.0000001e-5);
  nav_geotrack_free(&g);
  /* Thinning to at most 50 vertices keeps the first and the last. */
  assert_int_equal(nav_kml_write_file(path, "doc", tr, 1, 50), NAV_OK);
  assert_int_equal(nav_geotrack_read_file(path, NAV_TRACK_FORMAT_AUTO, NULL, &g, NULL, NULL), NAV_OK);
  assert_true(g.count <= 51 && g.count >= 40);
  assert_near(g.points[g.count - 1].pos.h_m, pos[N - 1].h_m, 1e-4);
  nav_geotrack_free(&g);
  /* Non-finite input is refused and leaves no file behind. */
  pos[3].h_m = NAN;
  assert_int_equal(nav_kml_write_file(path, "doc", tr, 1, 50), NAV_ERR_INVALID_ARG);
  pos[3].h_m = 0;
  char cmd[512];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  assert_int_equal(system(cmd), 0);
}

/* Overrides go through the scene reader: units converted, unknown keys and bad values reported. */
static void test_scene_override(void **state) {
  (void)state;
  nav_scene_doc *doc = NULL;
  char msg[512];
  assert_int_equal(nav_scene_doc_load(NAV_SOURCE_DIR "/scenes/urban-drive.yaml", &doc, msg, sizeof msg), NAV_OK);
  nav_scene *a = malloc(sizeof *a), *b = malloc(sizeof *b);
  assert_non_null(a);
  assert_non_null(b);
  assert_int_equal(nav_scene_doc_read(doc, a, NULL, NULL), NAV_OK);
  assert_int_equal(nav_scene_doc_set(doc, "initial_errors.attitude_deg[2]", "2.0", msg, sizeof msg), NAV_OK);
  assert_int_equal(nav_scene_doc_set(doc, "simulation.runs", "7", msg, sizeof msg), NAV_OK);
  assert_int_equal(nav_scene_doc_set(doc, "imu.gyro.arw_deg_per_sqrt_h", "0.5", msg, sizeof msg), NAV_OK);
  diag_log log;
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_scene_doc_read(doc, b, collect, &log), NAV_OK);
  assert_int_equal(b->simulation.runs, 7);
  assert_near(b->initial_errors.att_sd_rad.z, 2.0 * NAV_DEG2RAD, 1e-15);
  assert_near(b->imu.model.gyro.arw_rad_per_sqrt_s.x, 0.5 * NAV_DEG2RAD / 60.0, 1e-15);
  assert_near(b->imu.model.gyro.arw_rad_per_sqrt_s.z, 0.5 * NAV_DEG2RAD / 60.0, 1e-15);
  assert_near(b->trajectory.duration_s, a->trajectory.duration_s, 0);
  /* Malformed paths. */
  assert_int_equal(nav_scene_doc_set(doc, "imu..x", "1", msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_scene_doc_set(doc, "initial_errors.attitude_deg[9]", "1", msg, sizeof msg), NAV_ERR_INVALID_ARG);
  assert_non_null(strstr(msg, "out of range"));
  assert_int_equal(nav_scene_doc_set(doc, "name.x", "1", msg, sizeof msg), NAV_ERR_INVALID_ARG);
  /* A key the reader does not know, and a bad value: reported by the reader itself. */
  assert_int_equal(nav_scene_doc_set(doc, "imu.gyro.arw_deg_per_sqrt_hour", "0.5", msg, sizeof msg), NAV_OK);
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_scene_doc_read(doc, b, collect, &log), NAV_ERR_PARSE);
  assert_true(log.n >= 1);
  assert_non_null(strstr(log.d[0].path, "arw_deg_per_sqrt_hour"));
  nav_scene_doc_destroy(doc);
  char p[64], v[64];
  assert_int_equal(nav_scene_override_split("a.b=3", p, sizeof p, v, sizeof v), NAV_OK);
  assert_string_equal(p, "a.b");
  assert_string_equal(v, "3");
  assert_int_equal(nav_scene_override_split("a.b", p, sizeof p, v, sizeof v), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_scene_override_split("=3", p, sizeof p, v, sizeof v), NAV_ERR_INVALID_ARG);
  free(a);
  free(b);
}

/* Cost classes: every catalog row has one in 1..5; a bad cell is located. */
static void test_cost_class(void **state) {
  (void)state;
  nav_catalog *cat = NULL;
  assert_int_equal(nav_catalog_load(NAV_SOURCE_DIR "/resources/imu_catalog.csv", NULL, &cat, NULL, NULL), NAV_OK);
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const int c = nav_catalog_imu_at(cat, i)->cost_class;
    assert_true(c >= 1 && c <= NAV_CATALOG_COST_CLASS_MAX);
  }
  assert_int_equal(nav_catalog_find_imu(cat, "Bosch BMI088")->cost_class, 1);
  assert_int_equal(nav_catalog_find_imu(cat, "Honeywell HG9900")->cost_class, 5);
  nav_catalog_destroy(cat);
  assert_int_equal(nav_catalog_load(NAV_SOURCE_DIR "/resources/gnss_receivers.csv", NULL, &cat, NULL, NULL), NAV_OK);
  for (size_t i = 0; i < nav_catalog_count(cat); ++i) {
    const int c = nav_catalog_gnss_at(cat, i)->cost_class;
    assert_true(c >= 1 && c <= NAV_CATALOG_COST_CLASS_MAX);
  }
  nav_catalog_destroy(cat);
  const char *bad = "mode,horizontal_sigma_per_axis_m,vertical_sigma_m,update_rate_hz,source,verified_in_corpus,"
                    "cost_class\nx,1,1,1,s,yes,6\n";
  diag_log log;
  memset(&log, 0, sizeof log);
  assert_int_equal(nav_catalog_load_string(bad, strlen(bad), "c.csv", NULL, &cat, collect, &log), NAV_ERR_PARSE);
  assert_int_equal(log.d[0].line, 2);
  assert_int_equal(log.d[0].col, 15);
  assert_string_equal(log.d[0].path, "cost_class");
  assert_string_equal(nav_catalog_cost_band(5), "> 100 kUSD");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gpx_points_and_times), cmocka_unit_test(test_errors_located),
      cmocka_unit_test(test_kml_linestring_and_gx_track), cmocka_unit_test(test_track_to_scene),
      cmocka_unit_test(test_kml_round_trip), cmocka_unit_test(test_scene_override),
      cmocka_unit_test(test_cost_class),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
