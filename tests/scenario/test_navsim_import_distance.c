/*
 * navsim import against the track (issue 18, "Real data in and out"):
 *  - the flown path's distance from the track is checked against --tolerance: tests/data/tracks/
 *    drive.gpx (a timed drive) plans a path 7.8 m from one of its points at the default 5 m:
 *    exit 2 at that point's FILE:LINE:COL with the distance, its time into the track and what to
 *    change, and nothing written; --accept-distance writes it and prints the distance; a larger
 *    --tolerance accepts it too;
 *  - every KML LineString is a track: tests/data/tracks/two-tracks.kml (two Placemarks) without
 *    --track lists both and exits 2; --track 2 and --track NAME pick one; a number beyond the
 *    list is an error; the generic Placemark names ("Tessellated", "Untitled Path") give the scene
 *    the file's name.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define TRACKS NAV_SOURCE_DIR "/tests/data/tracks"

static double number_after(const char *text, const char *key) {
  const char *p = strstr(text, key);
  if (!p) fail_msg("no \"%s\" in:\n%s", key, text);
  return strtod(p + strlen(key), NULL);
}

static void test_distance_checked(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import '%s/drive.gpx' --out d.yaml", TRACKS);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err,
                          "drive\\.gpx:[0-9]+:[0-9]+: error: the planned path passes [0-9.]+ m from this "
                          "track point, [0-9.]+ s into the track, beyond --tolerance 5 m");
  nav_test_assert_matches(r->err, "Lower the speed.*keep the track's stops.*--accept-distance");
  const double d = number_after(r->err, "the planned path passes ");
  assert_true(d > 5.0);
  assert_false(nav_test_is_file(WORK "/d.yaml"));
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import '%s/drive.gpx' --accept-distance --out d.yaml",
                        TRACKS);
  assert_int_equal(r->code, 0);
  assert_true(nav_test_is_file(WORK "/d.yaml"));
  assert_near(number_after(r->out, "from the flown path "), d, 0.006);
  /* Within a larger tolerance the same plan is accepted without the flag. */
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import '%s/drive.gpx' --tolerance 10 --out d10.yaml",
                        TRACKS);
  assert_int_equal(r->code, 0);
  assert_true(number_after(r->out, "from the flown path ") <= 10.0);
}

static void test_kml_tracks(void **state) {
  (void)state;
  nav_cli_result *r =
      nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import '%s/two-tracks.kml' --out k.yaml", TRACKS);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(
      r->err, "two-tracks\\.kml:1:1: error: the file holds 2 tracks .*1 \"Tessellated\" "
              "\\(line 7, 2 points\\); 2 \"Untitled Path\" \\(line 16, 3 points\\); pick one with "
              "--track");
  assert_false(nav_test_is_file(WORK "/k.yaml"));
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "import '%s/two-tracks.kml' --track 2 --speed 2 --out k2.yaml", TRACKS);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "3 points -> 3 waypoints");
  char *text = nav_test_slurp_alloc(WORK "/k2.yaml");
  assert_non_null(text);
  nav_test_assert_matches(text, "\nname: \"?two-tracks\"?\n");
  free(text);
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "import '%s/two-tracks.kml' --track Tessellated --out k1.yaml", TRACKS);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  nav_test_assert_matches(r->out, "2 points -> 2 waypoints");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "import '%s/two-tracks.kml' --track 3 --out k3.yaml", TRACKS);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "no track named or numbered \"3\".*the file holds 2");
  /* A named Placemark keeps its name. */
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL,
                        "import '%s/sharp.kml' --speed 5 --accept-distance --out z.yaml", TRACKS);
  if (r->code != 0) fail_msg("exit %d: %s", r->code, r->err);
  text = nav_test_slurp_alloc(WORK "/z.yaml");
  assert_non_null(text);
  nav_test_assert_matches(text, "\nname: \"?zigzag\"?\n");
  free(text);
}

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_distance_checked),
      cmocka_unit_test(test_kml_tracks),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
