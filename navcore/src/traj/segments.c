/* Segment scripts (placeholder until implemented). */
#include <stdio.h>

#include "traj/traj_internal.h"

nav_status nav_traj_segments_create(const nav_scene *scene, double dt_s, nav_traj_model *out, char *msg,
                                    size_t msg_size) {
  (void)scene;
  (void)dt_s;
  (void)out;
  if (msg) snprintf(msg, msg_size, "segment scripts are not available yet");
  return NAV_ERR_INVALID_ARG;
}
