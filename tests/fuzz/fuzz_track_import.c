/* libFuzzer target: the GPX / KML track importers (expat) and the conversion of a track into a
 * planned waypoint trajectory. Each input is read as GPX, as KML and by its content. */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "navcore/nav_track_import.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The status is not what a fuzz target checks (GCC does not let (void) drop a nodiscard). */
#define NAV_FUZZ_IGNORE(call)        \
  do {                               \
    const nav_status ignored_ = call; \
    (void)ignored_;                  \
  } while (0)

static void one(const char *text, size_t len, nav_track_format fmt) {
  nav_geotrack t = {0};
  if (nav_geotrack_read_string(text, len, "fuzz.trk", fmt, NULL, &t, NULL, NULL) != NAV_OK) return;
  /* Bounded planning: at most 200 points within 1 deg of the first and, when timed, within one
   * hour reach the planner. Longer tracks are slow by design (nav_geotrack_to_scene samples the
   * flown path every 0.1 s to measure its deviation: a 5-point track around the globe takes 87 s
   * and 2 GB, four points with a month between two times over 10 s; reported). */
  bool small = t.count <= 200;
  for (size_t i = 1; i < t.count && small; ++i)
    if (t.points[i].has_time && t.points[0].has_time) small = fabs(t.points[i].t_s - t.points[0].t_s) < 3600.0;
  for (size_t i = 1; i < t.count && small; ++i)
    small = fabs(t.points[i].pos.lat_rad - t.points[0].pos.lat_rad) < 0.0175 &&
            fabs(t.points[i].pos.lon_rad - t.points[0].pos.lon_rad) < 0.0175;
  if (small) {
    static nav_scene scene;
    scene = nav_scene_default();
    nav_track_import_options opt = nav_track_import_options_default();
    nav_track_import_report rep;
    char msg[256];
    NAV_FUZZ_IGNORE(nav_geotrack_to_scene(&t, &opt, &scene, &rep, msg, sizeof msg));
  }
  nav_geotrack_free(&t);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  (void)nav_track_format_guess("fuzz", text, size);
  one(text, size, NAV_TRACK_FORMAT_GPX);
  one(text, size, NAV_TRACK_FORMAT_KML);
  one(text, size, NAV_TRACK_FORMAT_AUTO);
  return 0;
}
