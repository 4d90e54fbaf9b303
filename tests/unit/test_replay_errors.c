/*
 * The replay's errors of a NED state against a reference row, four epochs at a time
 * (navcore/io/replay_errors.h): ned_errors4, and its baseline or AVX2 variant ned_errors4_clones,
 * must give each lane's ned_errors bit for bit. Random
 * states near their reference rows (the replay's case: small position, velocity and attitude
 * errors), far from them (the rotation between the two NED frames large enough that some lane
 * leaves the trace branch of the quaternion), attitudes at and near pitch +/-90 deg (the
 * gimbal-lock branch of the Euler angles per lane), yaw across +/-180 deg (the wrap), and lanes
 * of every kind mixed.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "navcore/nav_rng.h"
#include "replay_errors.h"

static double uni(nav_rng *r, double lo, double hi) { return lo + (hi - lo) * nav_rng_uniform(r); }

/* A reference row and the item the reading thread makes of it. */
static ref_item make_ref(nav_rng *r, int kind) {
  ref_item it;
  memset(&it, 0, sizeof it);
  it.row.t_s = uni(r, 0.0, 1e5);
  it.row.pos.lat_rad = uni(r, -1.5, 1.5);
  it.row.pos.lon_rad = uni(r, -NAV_PI, NAV_PI);
  it.row.pos.h_m = uni(r, -100.0, 9000.0);
  it.row.v_n_mps = nav_vec3_make(uni(r, -40, 40), uni(r, -40, 40), uni(r, -3, 3));
  double pitch = uni(r, -1.4, 1.4);
  if (kind == 2) pitch = (nav_rng_uniform(r) < 0.5 ? -1.0 : 1.0) * (NAV_PI / 2 - ldexp(nav_rng_uniform(r), -30));
  it.row.att.roll_rad = uni(r, -NAV_PI, NAV_PI);
  it.row.att.pitch_rad = pitch;
  it.row.att.yaw_rad = kind == 3 ? (nav_rng_uniform(r) < 0.5 ? -1.0 : 1.0) * (NAV_PI - ldexp(nav_rng_uniform(r), -20))
                                 : uni(r, -NAV_PI, NAV_PI);
  ref_item_fill(&it);
  return it;
}

/* A NED navigation state: near the reference (kinds 0, 2, 3) or anywhere (kind 1). */
static nav_ins_ned make_ned(nav_rng *r, const ref_item *ref, int kind) {
  nav_ins_ned e;
  memset(&e, 0, sizeof e);
  e.t_s = ref->row.t_s;
  const double dp = kind == 1 ? 1.0 : 1e-6;
  e.pos.lat_rad = ref->row.pos.lat_rad + uni(r, -dp, dp);
  e.pos.lon_rad = kind == 1 ? uni(r, -NAV_PI, NAV_PI) : ref->row.pos.lon_rad + uni(r, -dp, dp);
  e.pos.h_m = ref->row.pos.h_m + uni(r, -5.0, 5.0);
  e.v_n_mps = nav_vec3_add(ref->row.v_n_mps, nav_vec3_make(uni(r, -0.1, 0.1), uni(r, -0.1, 0.1), uni(r, -0.1, 0.1)));
  nav_euler a = ref->row.att;
  const double da = kind == 1 ? 3.0 : 1e-3;
  a.roll_rad += uni(r, -da, da);
  a.pitch_rad = kind == 2 ? ref->row.att.pitch_rad : a.pitch_rad + uni(r, -da, da) * 0.3;
  a.yaw_rad += uni(r, -da, da);
  e.q_b_n = nav_euler_to_quat(a);
  e.sin_lat = sin(e.pos.lat_rad);
  e.cos_lat = cos(e.pos.lat_rad);
  return e;
}

static void check_lanes(nav_rng *r, const int kinds[4], long *trace_all, long *mixed) {
  ref_item refs[4];
  nav_ins_ned neds[4];
  for (int k = 0; k < 4; ++k) {
    refs[k] = make_ref(r, kinds[k]);
    neds[k] = make_ned(r, &refs[k], kinds[k]);
  }
  const ref_item *const rp[4] = {&refs[0], &refs[1], &refs[2], &refs[3]};
  const nav_ins_ned *const np[4] = {&neds[0], &neds[1], &neds[2], &neds[3]};
  nav_epoch_errors four[4], cloned[4];
  ned_errors4(rp, np, four);
  /* And the variant the replay calls (its AVX2 clone on a CPU that has AVX2). */
  ned_errors4_clones(rp, np, cloned);
  assert_memory_equal(cloned, four, sizeof four);
  bool trace = true;
  for (int k = 0; k < 4; ++k) {
    const nav_epoch_errors one = ned_errors(&refs[k], &neds[k]);
    if (memcmp(&one, &four[k], sizeof one) != 0)
      fail_msg("lane %d (kinds %d %d %d %d): att %a against %a, h %a against %a, roll %a against %a", k, kinds[0],
               kinds[1], kinds[2], kinds[3], four[k].att_err_rad, one.att_err_rad, four[k].pos_err_h_m,
               one.pos_err_h_m, four[k].euler_err.roll_rad, one.euler_err.roll_rad);
    /* Which branch of the quaternion the lane needs (the trace one when it is the largest). */
    const double sle = neds[k].sin_lat, cle = neds[k].cos_lat;
    const nav_mat3 Ct = dcm_n_e(refs[k].slt, refs[k].clt, refs[k].sot, refs[k].cot);
    const nav_mat3 Ce = dcm_n_e(sle, cle, sin(neds[k].pos.lon_rad), cos(neds[k].pos.lon_rad));
    const nav_mat3 M = nav_mat3_mul(nav_mat3_transpose(Ct), Ce);
    const double tr = M.m[0][0] + M.m[1][1] + M.m[2][2];
    trace = trace && tr >= M.m[0][0] && tr >= M.m[1][1] && tr >= M.m[2][2];
  }
  if (trace)
    ++*trace_all;
  else
    ++*mixed;
}

static void test_four_lanes_bit_for_bit(void **state) {
  (void)state;
  nav_rng r;
  nav_rng_init(&r, 20261127u, 4u, 0u);
  long trace_all = 0, mixed = 0;
  for (int i = 0; i < 60000; ++i) {
    int kinds[4];
    for (int k = 0; k < 4; ++k)
      kinds[k] = i < 20000 ? 0 : (int)(nav_rng_next_u64(&r) % 4u);
    check_lanes(&r, kinds, &trace_all, &mixed);
  }
  print_message("[ lanes    ] 240000 epochs bit for bit: %ld groups on the trace branch, %ld with a lane off it\n",
                trace_all, mixed);
  /* Both paths of ned_errors4 were taken. */
  assert_true(trace_all > 1000);
  assert_true(mixed > 1000);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_four_lanes_bit_for_bit),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
