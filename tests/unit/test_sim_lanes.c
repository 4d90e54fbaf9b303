/*
 * Monte Carlo runs in lockstep (issue 23 item 1, docs/campaign-speed.md): four runs whose
 * strapdown steps go in vector lanes give the bits of the runs stepped one at a time.
 *  - nav_ins_step_lanes() against nav_ins_step() on four INS, state and Earth terms compared bit
 *    for bit after every step, over drives that take every branch the lanes share and, lane by
 *    lane, the branches where the scalar step differs (large rotations, latitude steps, the Newton
 *    seeds, the longitude wrap, a bad increment, another configuration): there the lanes refuse
 *    and leave every INS untouched.
 *  - a whole job (urban-drive, 6 runs: a group of four, runs 1-4, beside run 0 and run 5) with
 *    nav_sim_options.lanes = 1 on 1 thread against the default on 2 threads, and split into the
 *    ranges [0, 2) and [2, 6), whose group is runs 2-5: summary, envelopes and final errors bit for
 *    bit.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_io.h"
#include "navcore/nav_ins.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_sim_partial.h"
#include "nav_sim_outcome.h"
#include "math/quat_dcm_inline.h"
#include "nav/strapdown_lanes.h"

/* ---------------------------------------------------------------- the strapdown in lanes */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double urand(void) { /* xorshift64*, in [-0.5, 0.5) */
  rng_state ^= rng_state >> 12;
  rng_state ^= rng_state << 25;
  rng_state ^= rng_state >> 27;
  return (double)((rng_state * 0x2545f4914f6cdd1dull) >> 11) * 0x1p-53 - 0.5;
}

static nav_ins *make_ins(double lat_deg, double lon_deg, double h_m, double v_north, double yaw_rad,
                         nav_mech_frame frame) {
  nav_ins_config cfg = nav_ins_config_default();
  cfg.earth_model = NAV_EARTH_WGS84;
  cfg.algorithm = NAV_MECH_HIGH_ORDER;
  cfg.mech_frame = frame;
  const nav_geodetic p = {lat_deg * NAV_DEG2RAD, lon_deg * NAV_DEG2RAD, h_m};
  const nav_mat3 C_n_e = nav_earth_dcm_n_e(p.lat_rad, p.lon_rad);
  const double cy = cos(yaw_rad), sy = sin(yaw_rad);
  const nav_mat3 C_b_n = {{{cy, -sy, 0.0}, {sy, cy, 0.0}, {0.0, 0.0, 1.0}}};
  nav_ins_state s0;
  s0.t_s = 0.0;
  s0.r_fb_f_m = nav_earth_geodetic_to_ecef(p);
  s0.v_fb_f_mps = nav_mat3_mul_vec(C_n_e, nav_vec3_make(v_north, 0.0, 0.0));
  s0.q_b_f = nav_quat_from_dcm(nav_mat3_mul(C_n_e, C_b_n));
  nav_ins *ins = NULL;
  assert_int_equal(nav_ins_create(&cfg, &s0, &ins), NAV_OK);
  return ins;
}

/* Everything of an INS the next step and the outputs read: the NED state, the Earth terms' sin and
 * cos of latitude, and the e-frame view. */
typedef struct snap {
  nav_ins_ned ned;
  nav_ins_state s;
} snap;

static snap take(const nav_ins *ins) {
  snap z;
  memset(&z, 0, sizeof z);
  const bool ned = nav_ins_get_ned(ins, &z.ned);
  (void)ned;
  z.s = *nav_ins_get_state(ins);
  return z;
}

static void same_snap(const snap *a, const snap *b, long k, int lane) {
  if (memcmp(&a->ned, &b->ned, sizeof a->ned) != 0 || memcmp(&a->s, &b->s, sizeof a->s) != 0)
    fail_msg("step %ld lane %d: lockstep lat %.17g lon %.17g h %.17g, alone lat %.17g lon %.17g h %.17g", k, lane,
             a->ned.pos.lat_rad, a->ned.pos.lon_rad, a->ned.pos.h_m, b->ned.pos.lat_rad, b->ned.pos.lon_rad,
             b->ned.pos.h_m);
}

/*
 * Four lanes (ins) against four twins stepped alone (solo). Each step's increments: a drive
 * (acceleration, turns, noise) plus, at chosen steps, one lane's special case. Returns the number
 * of steps the lanes refused.
 */
static long drive(nav_ins *ins[4], nav_ins *solo[4], long steps, double dt, int special) {
  long refused = 0;
  for (long k = 1; k <= steps; ++k) {
    nav_imu_increment inc[4];
    const nav_imu_increment *ip[4];
    for (int l = 0; l < 4; ++l) {
      const double t = (double)k * dt;
      const double turn = fmod(t, 40.0) > 20.0 ? 0.2 : 0.0, acc = fmod(t, 40.0) < 5.0 ? 1.5 : -0.1;
      inc[l].k = k;
      inc[l].t_s = t;
      inc[l].dt_s = dt;
      inc[l].dtheta_b_rad = nav_vec3_make(1e-5 * urand(), 1e-5 * urand(), (turn + 0.01 * l) * dt + 1e-5 * urand());
      inc[l].dv_b_mps = nav_vec3_make(acc * dt + 1e-3 * urand(), 1e-3 * urand(), -9.81 * dt + 1e-3 * urand());
      ip[l] = &inc[l];
    }
    /* One lane's special case at every 97th step. */
    if (special && k % 97 == 0) {
      const int l = (int)((k / 97) % 4);
      switch ((k / 97) % 4) {
      case 0: inc[l].dtheta_b_rad.x = 0.05; break;   /* above the rotation series */
      case 1: inc[l].dv_b_mps.z = -9.81 * dt + 3.0; break; /* a height jump: other Newton seeds */
      case 2: inc[l].dt_s = 0.0; break;              /* refused increment */
      default: inc[l].dv_b_mps.x = NAN; break;       /* non-finite increment */
      }
    }
    snap before[4];
    for (int l = 0; l < 4; ++l) before[l] = take(ins[l]);
    /* Every other step asks for the new state in lanes, which must then hold each INS's new NED
     * state and the DCM of its attitude. */
    nav_ins_lanes_nav out;
    const bool with_nav = k % 2 == 1;
    const bool done = nav_ins_step_lanes(ins, ip, with_nav ? &out : NULL);
    nav_status st[4];
    for (int l = 0; l < 4; ++l) st[l] = nav_ins_step(solo[l], ip[l]);
    if (done && with_nav)
      for (int l = 0; l < 4; ++l) {
        nav_ins_ned ned;
        assert_true(nav_ins_get_ned(solo[l], &ned));
        const double got[5] = {out.lat[l], out.h[l], out.v.x[l], out.v.y[l], out.v.z[l]};
        const double want[5] = {ned.pos.lat_rad, ned.pos.h_m, ned.v_n_mps.x, ned.v_n_mps.y, ned.v_n_mps.z};
        assert_memory_equal(got, want, sizeof got);
        const nav_mat3 C = nav_quat_to_dcm_inline(ned.q_b_n);
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            assert_memory_equal(&out.C_b_n.m[i][j][l], &C.m[i][j], sizeof(double));
      }
    if (!done) {
      ++refused;
      /* Nothing changed; then the scalar step of each lane, as nav_ins_gnss_step_lanes does. */
      for (int l = 0; l < 4; ++l) {
        const snap now = take(ins[l]);
        same_snap(&now, &before[l], k, l);
        assert_int_equal(nav_ins_step(ins[l], ip[l]), st[l]);
      }
    } else {
      for (int l = 0; l < 4; ++l) assert_int_equal(st[l], NAV_OK);
    }
    for (int l = 0; l < 4; ++l) {
      const snap a = take(ins[l]), b = take(solo[l]);
      same_snap(&a, &b, k, l);
    }
  }
  return refused;
}

static void test_strapdown_lanes_same_bits(void **state) {
  (void)state;
  nav_ins *ins[4], *solo[4];
  for (int l = 0; l < 4; ++l) {
    ins[l] = make_ins(48.1 + 0.3 * l, 11.5 + l, 500.0 + 100.0 * l, 5.0 * l, 0.5 * l, NAV_MECH_NED);
    solo[l] = make_ins(48.1 + 0.3 * l, 11.5 + l, 500.0 + 100.0 * l, 5.0 * l, 0.5 * l, NAV_MECH_NED);
  }
  /* A plain drive: the lanes never refuse (else the test would not test them). */
  assert_int_equal(drive(ins, solo, 20000, 0.01, 0), 0);
  /* Special cases: some steps refused, every step still the same bits. */
  const long refused = drive(ins, solo, 4000, 0.01, 1);
  assert_true(refused >= 4000 / 97 / 2);
  for (int l = 0; l < 4; ++l) {
    nav_ins_destroy(ins[l]);
    nav_ins_destroy(solo[l]);
  }
}

/* Near the antimeridian (the longitude wraps in one lane) and fast (latitude steps above the
 * series bound, 1e-3 rad per step at 0.1 s only from ~640 km/s: the lanes refuse a step that large). */
static void test_strapdown_lanes_wrap_and_refusals(void **state) {
  (void)state;
  nav_ins *ins[4], *solo[4];
  for (int l = 0; l < 4; ++l) {
    const double lon = l == 2 ? 179.99999 : 10.0;
    ins[l] = make_ins(-33.0, lon, 10.0, 0.0, l == 2 ? NAV_PI / 2 : 0.0, NAV_MECH_NED);
    solo[l] = make_ins(-33.0, lon, 10.0, 0.0, l == 2 ? NAV_PI / 2 : 0.0, NAV_MECH_NED);
  }
  /* Lane 2 drives east across the antimeridian within a few hundred steps. */
  const long refused = drive(ins, solo, 3000, 0.01, 0);
  assert_true(refused > 0); /* the wrap step (and after it nothing else) */
  for (int l = 0; l < 4; ++l) {
    nav_ins_ned e;
    assert_true(nav_ins_get_ned(solo[l], &e));
    if (l == 2) assert_true(e.pos.lon_rad < 0.0);
  }
  for (int l = 0; l < 4; ++l) {
    nav_ins_destroy(ins[l]);
    nav_ins_destroy(solo[l]);
  }
  /* Another configuration in one lane: the lanes refuse every step, the scalar steps go on. */
  for (int l = 0; l < 4; ++l) {
    ins[l] = make_ins(10.0, 20.0, 0.0, 1.0, 0.0, l == 1 ? NAV_MECH_ECEF : NAV_MECH_NED);
    solo[l] = make_ins(10.0, 20.0, 0.0, 1.0, 0.0, l == 1 ? NAV_MECH_ECEF : NAV_MECH_NED);
  }
  assert_int_equal(drive(ins, solo, 50, 0.01, 0), 50);
  for (int l = 0; l < 4; ++l) {
    nav_ins_destroy(ins[l]);
    nav_ins_destroy(solo[l]);
  }
}

/* ---------------------------------------------------------------- a whole job */

static void test_job_lanes_same_bits(void **state) {
  (void)state;
  const nav_scene sc = load("urban-drive.yaml", 6);
  outcome one, four, split_runs;
  reference_lanes(&sc, 1, 1, &one);
  reference_lanes(&sc, 2, 0, &four);
  const long bounds[3] = {0, 2, 6};
  const int threads[2] = {2, 2};
  split(&sc, bounds, 2, threads, &split_runs);
  /* The runs differ (else equal results would say nothing). */
  assert_int_equal(one.n_fin, 6);
  assert_true(memcmp(&one.fin[1].err, &one.fin[2].err, sizeof one.fin[1].err) != 0);
  assert_identical(&four, &one);
  assert_identical(&split_runs, &one);
  release(&one);
  release(&four);
  release(&split_runs);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_strapdown_lanes_same_bits),
      cmocka_unit_test(test_strapdown_lanes_wrap_and_refusals),
      cmocka_unit_test(test_job_lanes_same_bits),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
