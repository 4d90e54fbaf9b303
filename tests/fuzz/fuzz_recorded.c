/* libFuzzer target: the recorded-data readers. The same bytes are read as a KF-GINS IMU file,
 * a GNSS file (7 or 13 columns), a .nav reference (streaming readers of recorded.c) and as a
 * recorded reference for trajectory.type recorded (track_io.c). */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "navcore/nav_recorded.h"
#include "navcore/nav_track.h"
#include "navcore/nav_track_io.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The status is not what a fuzz target checks (GCC does not let (void) drop a nodiscard). */
#define NAV_FUZZ_IGNORE(call)        \
  do {                               \
    const nav_status ignored_ = call; \
    (void)ignored_;                  \
  } while (0)

static void read_all(const char *text, size_t len, nav_rec_format fmt) {
  nav_rec_reader *r = NULL;
  if (nav_rec_reader_open_memory(text, len, "fuzz.txt", fmt, &r) != NAV_OK) return;
  bool got = true;
  nav_status st = NAV_OK;
  for (long k = 0; st == NAV_OK && got && k < 1000000; ++k) {
    if (fmt == NAV_REC_IMU) {
      nav_imu_increment v;
      st = nav_rec_read_imu(r, &v, &got);
    } else if (fmt == NAV_REC_GNSS) {
      nav_ins_gnss_fix v;
      st = nav_rec_read_gnss(r, &v, &got);
    } else {
      nav_rec_pva v;
      st = nav_rec_read_pva(r, &v, &got);
      if (st == NAV_OK && got) (void)nav_rec_pva_to_state(&v);
    }
    (void)nav_rec_reader_fraction(r);
    (void)nav_rec_reader_line(r);
  }
  (void)nav_rec_reader_diag(r);
  nav_rec_reader_destroy(r);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const char *text = (const char *)data;
  read_all(text, size, NAV_REC_IMU);
  read_all(text, size, NAV_REC_GNSS);
  read_all(text, size, NAV_REC_PVA);
  nav_track_sample *s = NULL;
  size_t n = 0;
  if (nav_track_read_string(text, size, "fuzz.nav", NAV_RECORDED_KF_GINS_NAV, 0, 0.0, 0.0, "trajectory.recorded.file",
                            &s, &n, NULL, NULL) == NAV_OK) {
    /* What a scene with trajectory.type recorded does next: fit the B-spline model. */
    static nav_traj_recorded rec;
    rec.knot_rate_hz = 4.0;
    rec.pos_sd_m = 0.01;
    rec.vel_sd_mps = 0.01;
    rec.count = 0;
    char msg[256];
    /* At most 100 000 control points (25 000 s at 4 Hz) keep one input within milliseconds; the
     * cap of NAV_RECORDED_MAX_CTRL is 40 times that. */
    if (n >= 2 && (s[n - 1].t_s - s[0].t_s) * rec.knot_rate_hz < 1.0e5 &&
        nav_track_fit(&rec, s, n, msg, sizeof msg) == NAV_OK) {
      nav_track_sample e;
      NAV_FUZZ_IGNORE(nav_track_eval(&rec, 0.5 * rec.span_s, &e));
      nav_traj_recorded_release(&rec);
    }
    free(s);
  }
  s = NULL;
  if (nav_track_read_string(text, size, "fuzz.nav", NAV_RECORDED_KF_GINS_NAV, 3u, 1.0, 100.0,
                            "trajectory.recorded.file", &s, &n, NULL, NULL) == NAV_OK)
    free(s);
  return 0;
}
