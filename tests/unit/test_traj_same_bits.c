/*
 * The shortcuts of the truth generation give the same bits as the functions they stand for
 * (issue 23 item 3, docs/truth-generation-speed.md): nav_kin_sincos against sin/cos (signed zeros
 * included); segments.c's DCM, quaternion and Euler-rate forms from shared sines and cosines
 * against nav_euler_to_dcm, nav_euler_to_quat and nav_kin_euler_rates; the value-only channel
 * evaluation against the full channel state; the cached velocity of the position quadrature against
 * a fresh evaluation; traj.c's fused WGS-84 embedding against the composition of the nav_earth
 * functions. Every comparison is bitwise (memcmp), seeded random inputs plus the edge cases.
 * White-box: segments.c and traj.c are included for their static helpers.
 */
/* The sources first: cmocka defines a macro named fail, which segments.c uses as a function name. */
#include "traj/segments.c"
#include "traj/traj.c"

#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_io.h"

#define SEED 20261127u

static uint64_t s_state;
static double uniform(double lo, double hi) {
  /* splitmix64 */
  uint64_t z = (s_state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return lo + (hi - lo) * (double)(z >> 11) * 0x1.0p-53;
}

static void same_bits(const void *a, const void *b, size_t n, const char *what, int i) {
  if (memcmp(a, b, n) != 0) fail_msg("%s differs in its bits (case %d, seed %u)", what, i, SEED);
}

/* Angles: random, and the cases a trajectory produces exactly (zeros of both signs, +-pi/2, +-pi). */
static double angle(int i, int axis) {
  static const double edge[] = {0.0, -0.0, 1.5707963267948966, -1.5707963267948966, 3.141592653589793,
                                -3.141592653589793, 1e-300, 5e-324};
  const int ne = (int)(sizeof edge / sizeof *edge);
  if (i < ne * 3) return (i / ne) == axis ? edge[i % ne] : (axis == 0 ? 0.0 : uniform(-3.2, 3.2));
  return (i % 7 == axis) ? 0.0 : uniform(-7.0, 7.0);
}

static void test_sincos_shortcut(void **state) {
  (void)state;
  s_state = SEED;
  for (int i = 0; i < 20000; ++i) {
    const double a = i < 2 ? (i ? -0.0 : 0.0) : uniform(-10.0, 10.0) * (i % 3 == 0 ? 1e-9 : 1.0);
    double s, c;
    nav_kin_sincos(a, &s, &c);
    const double s0 = sin(a), c0 = cos(a);
    same_bits(&s, &s0, sizeof s, "sin", i);
    same_bits(&c, &c0, sizeof c, "cos", i);
  }
}

static void test_dcm_quat_rates_from_shared_trig(void **state) {
  (void)state;
  s_state = SEED + 1;
  for (int i = 0; i < 20000; ++i) {
    const nav_euler e = {angle(i, 0), angle(i, 1), angle(i, 2)};
    double sr, cr, sp, cp, sy, cy, shr, chr, shp, chp, shy, chy;
    nav_kin_sincos(e.roll_rad, &sr, &cr);
    nav_kin_sincos(e.pitch_rad, &sp, &cp);
    nav_kin_sincos(e.yaw_rad, &sy, &cy);
    nav_kin_sincos(0.5 * e.roll_rad, &shr, &chr);
    nav_kin_sincos(0.5 * e.pitch_rad, &shp, &chp);
    nav_kin_sincos(0.5 * e.yaw_rad, &shy, &chy);
    const nav_mat3 C = dcm_of(sr, cr, sp, cp, sy, cy), C0 = nav_euler_to_dcm(e);
    same_bits(&C, &C0, sizeof C, "C_b_n", i);
    const nav_quat q = quat_of(shr, chr, shp, chp, shy, chy), q0 = nav_euler_to_quat(e);
    same_bits(&q, &q0, sizeof q, "q_b_n", i);
    const nav_jet roll = nav_jet_make(e.roll_rad, uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const nav_jet pitch = nav_jet_make(e.pitch_rad, uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    const nav_jet yaw = nav_jet_make(e.yaw_rad, uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    nav_vec3 w, dw, w0, dw0;
    nav_kin_euler_rates_sc(roll, pitch, yaw, sr, cr, sp, cp, &w, &dw);
    nav_kin_euler_rates(roll, pitch, yaw, &w0, &dw0);
    same_bits(&w, &w0, sizeof w, "w_nb_b", i);
    same_bits(&dw, &dw0, sizeof dw, "dw_nb_b", i);
  }
}

static void test_channel_value(void **state) {
  (void)state;
  s_state = SEED + 2;
  nav_kin_channel c;
  nav_kin_channel_init(&c, 0.3, -0.1);
  double t = 1.0;
  for (int k = 0; k < 40; ++k) {
    const double len = uniform(0.1, 3.0);
    assert_int_equal(nav_kin_channel_add_step(&c, t, len, uniform(-2.0, 2.0)), NAV_OK);
    t += len + (k % 3 == 0 ? 0.0 : uniform(0.0, 2.0));
  }
  ptrdiff_t hint = -1;
  for (int i = 0; i < 40000; ++i) {
    /* Mostly ascending (as the quadrature asks), with jumps back. */
    const double ti = i % 97 == 0 ? uniform(-1.0, t + 5.0) : (double)i * (t + 5.0) / 40000.0;
    const double x = nav_kin_channel_eval_value(&c, ti, &hint), x0 = nav_kin_channel_eval(&c, ti).d[0];
    same_bits(&x, &x0, sizeof x, "channel value", i);
  }
  nav_kin_channel_free(&c);
}

static void test_cached_quadrature_velocity(void **state) {
  (void)state;
  /* The long drive's segment model: the position quadrature's velocity (per-angle sin/cos cache)
   * against the channel values through nav_euler_to_dcm, over the whole drive at quadrature-like
   * time patterns. */
  nav_scene *sc = malloc(sizeof *sc);
  assert_non_null(sc);
  assert_int_equal(nav_scene_read_file(NAV_SOURCE_DIR "/scenes/long-drive.yaml", sc, NULL, NULL), NAV_OK);
  nav_traj_model tm;
  char msg[200];
  assert_int_equal(nav_traj_segments_create(sc, 0.005, &tm, msg, sizeof msg), NAV_OK);
  seg_model *m = tm.self;
  s_state = SEED + 3;
  for (int i = 0; i < 200000; ++i) {
    const double t = i % 50 == 0 ? uniform(0.0, m->end_s) : (double)i * m->end_s / 200000.0;
    const nav_vec3 v = seg_velocity(m, t);
    const nav_euler e = {nav_kin_channel_eval(&m->ch[CH_ROLL], t).d[0], nav_kin_channel_eval(&m->ch[CH_PITCH], t).d[0],
                         nav_kin_channel_eval(&m->ch[CH_YAW], t).d[0]};
    const nav_vec3 vb = nav_vec3_make(nav_kin_channel_eval(&m->ch[CH_U], t).d[0], nav_kin_channel_eval(&m->ch[CH_V], t).d[0],
                                      nav_kin_channel_eval(&m->ch[CH_W], t).d[0]);
    const nav_vec3 v0 = nav_mat3_mul_vec(nav_euler_to_dcm(e), vb);
    same_bits(&v, &v0, sizeof v, "quadrature velocity", i);
  }
  tm.destroy(tm.self);
  free(sc);
}

static void test_fused_wgs84_embedding(void **state) {
  (void)state;
  s_state = SEED + 4;
  for (int i = 0; i < 20000; ++i) {
    nav_geo_kin g;
    g.pos.lat_rad = i == 0 ? 0.0 : i == 1 ? -0.0 : uniform(-1.5, 1.5);
    g.pos.lon_rad = i == 2 ? NAV_PI : uniform(-NAV_PI, NAV_PI);
    g.pos.h_m = uniform(-500.0, 20000.0);
    g.dpos = nav_vec3_make(uniform(-1e-5, 1e-5), uniform(-1e-5, 1e-5), uniform(-50.0, 50.0));
    g.ddpos = nav_vec3_make(uniform(-1e-6, 1e-6), uniform(-1e-6, 1e-6), uniform(-5.0, 5.0));
    g.q_b_n = nav_euler_to_quat((nav_euler){uniform(-3, 3), uniform(-1.5, 1.5), uniform(-3, 3)});
    g.w_nb_b_rps = nav_vec3_make(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    g.dw_nb_b_rps2 = nav_vec3_make(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    nav_traj_state s;
    memset(&s, 0, sizeof s);
    geo_to_ecef_state_c(&g, &s, NULL, NULL); /* without the caches */
    /* The composition the fused form replaced (earth.c's functions, geo_to_ned_kin with the radii). */
    const ned_kin nk = geo_to_ned_kin(&g);
    const nav_mat3 C_n_e = nav_earth_dcm_n_e(g.pos.lat_rad, g.pos.lon_rad);
    const nav_vec3 r0 = nav_earth_geodetic_to_ecef(g.pos);
    const nav_vec3 v0 = nav_mat3_mul_vec(C_n_e, nk.v_n);
    const nav_vec3 a0 = nav_mat3_mul_vec(C_n_e, nav_vec3_add(nk.dv_n, nav_vec3_cross(nk.w_en_n, nk.v_n)));
    const nav_quat q0 = nav_quat_normalize(nav_quat_mul(nav_quat_from_dcm(C_n_e), g.q_b_n));
    same_bits(&s.r_fb_f_m, &r0, sizeof r0, "r_eb_e", i);
    same_bits(&s.v_fb_f_mps, &v0, sizeof v0, "v_eb_e", i);
    same_bits(&s.a_fb_f_mps2, &a0, sizeof a0, "a_eb_e", i);
    same_bits(&s.q_b_f, &q0, sizeof q0, "q_b_e", i);
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_sincos_shortcut),
      cmocka_unit_test(test_dcm_quat_rates_from_shared_trig),
      cmocka_unit_test(test_channel_value),
      cmocka_unit_test(test_cached_quadrature_velocity),
      cmocka_unit_test(test_fused_wgs84_embedding),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
