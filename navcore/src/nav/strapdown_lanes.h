/*
 * Four INS stepped in lockstep (the Monte Carlo runs of sim.c that step together): internal to
 * navcore. See nav_ins_step_lanes() in strapdown.c and docs/campaign-speed.md.
 */
#ifndef NAV_STRAPDOWN_LANES_H
#define NAV_STRAPDOWN_LANES_H

#include <stdbool.h>

#include "math/lanes4.h"
#include "navcore/nav_ins.h"

/** The new NED state of four INS after a lockstep step, one run per lane: lane l of lat, h and v
 *  is what nav_ins_get_ned(ins[l]) then gives, and C_b_n the DCM of its attitude, with the
 *  operations of nav_quat_to_dcm_inline() (the filter's inputs, nav_ins_gnss_step_lanes()). */
typedef struct nav_ins_lanes_nav {
  nav_l4 lat, h;
  nav_l4v3 v;
  nav_l4m3 C_b_n;
} nav_ins_lanes_nav;

/**
 * nav_ins_step(ins[l], imu[l]) for l = 0..3 at once, with the bits of the four separate calls.
 * @param[out] out the new state in lanes when the step was taken (NULL: not wanted)
 * @return true when all four were stepped; false when any INS or increment is outside the
 *         lockstep path (configuration, a branch of the step that differs from lane to lane, a
 *         refused or non-finite step): then no INS was changed and the caller steps each one with
 *         nav_ins_step(), which gives the same results and words any error.
 */
bool nav_ins_step_lanes(nav_ins *const ins[NAV_LANES], const nav_imu_increment *const imu[NAV_LANES],
                        nav_ins_lanes_nav *out);

#endif /* NAV_STRAPDOWN_LANES_H */
