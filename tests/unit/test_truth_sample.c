/*
 * The sequential truth generator nav_truth_sample (issue 23 item 3, docs/truth-generation-speed.md)
 * against the random-access pair it stands for, nav_truth_state(k dt) and nav_truth_imu(k), over
 * every sample of every scene of the library (every .yaml file in scenes/):
 *  - the ideal increments are the same bits;
 *  - the state's position differs only by the rounding of the position chain (tolerance below),
 *    and the fields that the position feeds on WGS-84 (the ECEF velocity, acceleration, attitude
 *    and rates through the latitude and longitude) by the matching relative amounts; on flat Earth
 *    and for models with their own positions every field but the position is the same bits;
 *  - the results do not depend on the order of the calls: samples asked for out of order, after
 *    jumps back and forth, on a fresh generator, equal those of the walk bit for bit.
 * The largest differences of each scene are printed (the note quotes them).
 *
 * Tolerances. The chain adds at most 63 interval integrals to the model's exact position (it
 * restarts from it every 64 samples), each rounded at the local position's ulp (2e-12 m at 10 km)
 * on top of the rule's own agreement with the model's 8-node quadrature (both exact to rounding for
 * the smooth velocity inside a checkpoint interval): about 1e-10 m in the local frame. On WGS-84
 * the ECEF coordinates round at 9.3e-10 m (their ulp at the Earth's radius), and the conversion
 * from the curvilinear local position through latitude, longitude and height to ECEF rounds
 * several times: a few ulp. POS_TOL_M = 1e-8 m is ten ulp of an ECEF coordinate. A position change
 * dr moves the latitude by dr / R = 1.6e-15 rad per 1e-8 m, which rotates every ECEF vector by as
 * much: velocities of up to 300 m/s by 5e-13 m/s (VEL_TOL), accelerations of up to 50 m/s^2 by
 * 1e-13 (ACC_TOL), unit quaternions by 2e-15 (QUAT_TOL); the body rates see the Earth and transport
 * rates (< 1e-3 rad/s) rotated by it, far below RATE_TOL = 1e-15 rad/s (and rad/s^2).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_io.h"
#include "navcore/nav_truth.h"

#define POS_TOL_M 1e-8
#define VEL_TOL_MPS 5e-13
#define ACC_TOL_MPS2 1e-13
#define QUAT_TOL 2e-15
#define RATE_TOL_RPS 1e-15

static double dist(nav_vec3 a, nav_vec3 b) {
  return sqrt((a.x - b.x) * (a.x - b.x) + (a.y - b.y) * (a.y - b.y) + (a.z - b.z) * (a.z - b.z));
}

static double qdist(nav_quat a, nav_quat b) {
  return fmax(fmax(fabs(a.w - b.w), fabs(a.x - b.x)), fmax(fabs(a.y - b.y), fabs(a.z - b.z)));
}

typedef struct maxima {
  double pos, vel, acc, quat, rate, drate;
  int64_t n_pos_diff;
} maxima;

/* Every sample of one scene: the walk of nav_truth_sample against the random-access pair. */
static void check_scene(const char *path, const char *name) {
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(path, sc, NULL, NULL), NAV_OK);
  nav_truth *seq = NULL, *ra = NULL;
  char msg[256];
  assert_int_equal(nav_truth_create_msg(sc, &seq, msg, sizeof msg), NAV_OK);
  assert_int_equal(nav_truth_create_msg(sc, &ra, msg, sizeof msg), NAV_OK);
  const int64_t n = nav_truth_sample_count(seq);
  const double dt = nav_truth_dt(seq);
  const bool flat = nav_truth_frame(seq).model == NAV_EARTH_FLAT;
  nav_traj_state *walk = malloc((size_t)(n + 1) * sizeof *walk);
  nav_imu_increment *walk_imu = malloc((size_t)(n + 1) * sizeof *walk_imu);
  assert_non_null(walk);
  assert_non_null(walk_imu);
  maxima mx = {0};
  for (int64_t k = 1; k <= n; ++k) {
    nav_traj_state s, s0;
    nav_imu_increment d, d0;
    assert_int_equal(nav_truth_sample(seq, k, &s, &d), NAV_OK);
    assert_int_equal(nav_truth_imu(ra, k, &d0), NAV_OK);
    assert_int_equal(nav_truth_state(ra, (double)k * dt, &s0), NAV_OK);
    if (memcmp(&d, &d0, sizeof d) != 0) fail_msg("%s: increment %lld differs from nav_truth_imu's", name, (long long)k);
    walk[k] = s;
    walk_imu[k] = d;
    const double dp = dist(s.r_fb_f_m, s0.r_fb_f_m);
    if (dp > mx.pos) mx.pos = dp;
    if (memcmp(&s.r_fb_f_m, &s0.r_fb_f_m, sizeof s.r_fb_f_m) != 0) ++mx.n_pos_diff;
    mx.vel = fmax(mx.vel, dist(s.v_fb_f_mps, s0.v_fb_f_mps));
    mx.acc = fmax(mx.acc, dist(s.a_fb_f_mps2, s0.a_fb_f_mps2));
    mx.quat = fmax(mx.quat, qdist(s.q_b_f, s0.q_b_f));
    mx.rate = fmax(mx.rate, dist(s.w_fb_b_rps, s0.w_fb_b_rps));
    mx.drate = fmax(mx.drate, dist(s.dw_fb_b_rps2, s0.dw_fb_b_rps2));
    if (flat) {
      /* Nothing but the position may differ. */
      nav_traj_state a = s;
      a.r_fb_f_m = s0.r_fb_f_m;
      if (memcmp(&a, &s0, sizeof a) != 0) fail_msg("%s: state %lld differs beyond its position", name, (long long)k);
    }
    if (mx.pos > POS_TOL_M || mx.vel > VEL_TOL_MPS || mx.acc > ACC_TOL_MPS2 || mx.quat > QUAT_TOL ||
        mx.rate > RATE_TOL_RPS || mx.drate > RATE_TOL_RPS)
      fail_msg("%s: sample %lld: position %.3g m, velocity %.3g m/s, acceleration %.3g m/s^2, quaternion %.3g, "
               "rate %.3g rad/s, rate derivative %.3g rad/s^2 from nav_truth_state's",
               name, (long long)k, mx.pos, mx.vel, mx.acc, mx.quat, mx.rate, mx.drate);
  }
  printf("  %-26s %7lld samples, positions differing %6lld, largest: position %.2e m, velocity %.2e m/s, "
         "acceleration %.2e m/s^2, quaternion %.2e, rate %.2e rad/s\n",
         name, (long long)n, (long long)mx.n_pos_diff, mx.pos, mx.vel, mx.acc, mx.quat, mx.rate);
  /* Order independence: a fresh generator asked out of order (jumps forward and back, block
   * boundaries, the ends) gives the walk's bits. */
  nav_truth *fresh = NULL;
  assert_int_equal(nav_truth_create_msg(sc, &fresh, msg, sizeof msg), NAV_OK);
  uint64_t z = 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < 300 && n >= 1; ++i) {
    z ^= z << 13;
    z ^= z >> 7;
    z ^= z << 17;
    int64_t k = 1 + (int64_t)(z % (uint64_t)n);
    if (i % 10 == 1) k = n;
    if (i % 10 == 2) k = 1;
    if (i % 10 == 3) k = (k / 64) * 64 > 0 ? (k / 64) * 64 : 1;
    if (i % 10 == 4) k = (k / 64) * 64 + 63 <= n ? (k / 64) * 64 + 63 : n;
    nav_traj_state s;
    nav_imu_increment d;
    assert_int_equal(nav_truth_sample(fresh, k, &s, &d), NAV_OK);
    if (memcmp(&s, &walk[k], sizeof s) != 0 || memcmp(&d, &walk_imu[k], sizeof d) != 0)
      fail_msg("%s: sample %lld out of order differs from the walk's", name, (long long)k);
  }
  nav_truth_destroy(fresh);
  free(walk_imu);
  free(walk);
  nav_truth_destroy(ra);
  nav_truth_destroy(seq);
  nav_scene_release(sc);
  free(sc);
}

static int cmp_str(const void *a, const void *b) {
  return strcmp(*(char *const *)a, *(char *const *)b);
}

static void test_library_scenes(void **state) {
  (void)state;
  DIR *d = opendir(NAV_SOURCE_DIR "/scenes");
  assert_non_null(d);
  char *names[128];
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) && n < 128) {
    const size_t len = strlen(e->d_name);
    if (len > 5 && strcmp(e->d_name + len - 5, ".yaml") == 0) {
      names[n] = malloc(len + 1);
      assert_non_null(names[n]);
      memcpy(names[n++], e->d_name, len + 1);
    }
  }
  closedir(d);
  qsort(names, (size_t)n, sizeof *names, cmp_str);
  assert_true(n >= 10);
  printf("nav_truth_sample against nav_truth_state + nav_truth_imu:\n");
  for (int i = 0; i < n; ++i) {
    char path[512];
    snprintf(path, sizeof path, "%s/scenes/%s", NAV_SOURCE_DIR, names[i]);
    check_scene(path, names[i]);
    free(names[i]);
  }
}

static void test_bad_arguments(void **state) {
  (void)state;
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(NAV_SOURCE_DIR "/scenes/urban-drive.yaml", sc, NULL, NULL), NAV_OK);
  nav_truth *t = NULL;
  assert_int_equal(nav_truth_create(sc, &t), NAV_OK);
  nav_traj_state s;
  nav_imu_increment d;
  memset(&s, 0x5a, sizeof s);
  const nav_traj_state s_before = s;
  assert_int_equal(nav_truth_sample(t, 0, &s, &d), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_truth_sample(t, -3, &s, &d), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_truth_sample(NULL, 1, &s, &d), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_truth_sample(t, 1, NULL, &d), NAV_ERR_INVALID_ARG);
  assert_int_equal(nav_truth_sample(t, 1, &s, NULL), NAV_ERR_INVALID_ARG);
  assert_memory_equal(&s, &s_before, sizeof s);
  nav_truth_destroy(t);
  nav_scene_release(sc);
  free(sc);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_bad_arguments),
      cmocka_unit_test(test_library_scenes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
