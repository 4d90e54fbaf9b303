/* libFuzzer target: the RINEX 3 readers (rinex_read.c). The same bytes are read as an
 * observation file (header and every epoch) and as a navigation file; the GPS records read are
 * turned into orbits and propagated, and their satellite clocks evaluated, as the replay does. */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "navcore/nav_rinex_read.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  nav_rinex_obs_reader *r = NULL;
  nav_diag d;
  if (nav_rinex_obs_open_memory(text, size, "fuzz.obs", &r, &d) == NAV_OK) {
    static nav_rinex_obs_epoch ep;
    nav_rinex_epoch_info info;
    bool got = true;
    nav_status st = NAV_OK;
    for (long k = 0; st == NAV_OK && got && k < 1000000; ++k) {
      st = nav_rinex_obs_next(r, &ep, &info, &got);
      (void)nav_rinex_obs_fraction(r);
    }
    (void)nav_rinex_obs_diag(r);
    (void)nav_rinex_obs_type_index(nav_rinex_obs_get_header(r), NAV_GNSS_SYS_GPS, "C1C");
    nav_rinex_obs_destroy(r);
  }
  nav_rinex_nav *nv = NULL;
  if (nav_rinex_nav_read_memory(text, size, "fuzz.nav", &nv, &d) == NAV_OK) {
    for (size_t i = 0; i < nv->n_gps && i < 64; ++i) {
      bool harm = false;
      const nav_gnss_orbit o = nav_rinex_gps_orbit(&nv->gps[i], &harm);
      nav_vec3 pos, vel;
      nav_gnss_orbit_state(&o, nv->gps[i].toe_gps_s + 60.0, &pos, &vel);
      (void)nav_rinex_gps_clock_s(&nv->gps[i], nv->gps[i].toc_gps_s + 60.0, true);
    }
    nav_rinex_nav_destroy(nv);
  }
  return 0;
}
