/*
 * Helper of test_navsim_durability: saves two versions of a scene to PATH alternately with
 * nav_scene_write_file() until killed (the test SIGKILLs it at random moments and then checks
 * that PATH holds one complete version). The versions are built exactly as the test builds its
 * reference copies.   usage: scene_save_loop PATH
 */
#include <stdio.h>

#include "navcore/nav_io.h"

int main(int argc, char **argv) {
  if (argc < 2) return 2;
  nav_scene sa = nav_scene_default(), sb = nav_scene_default();
  snprintf(sa.name, sizeof sa.name, "version-a");
  snprintf(sb.name, sizeof sb.name, "version-b");
  sb.imu.rate_hz = 200.0;
  sb.trajectory.duration_s = 33.0;
  for (unsigned long k = 0;; ++k)
    if (nav_scene_write_file(argv[1], (k & 1u) ? &sb : &sa) != NAV_OK) return 1;
}
