/*
 * libFuzzer target: the whole `navsim check` path and a little beyond: read the scene from
 * memory, validate it, build its trajectory and evaluate it, then create the simulation and run
 * a bounded piece of it (at most 0.5 s of simulated time at <= 200 Hz, one run, one thread) so
 * a scene the checker accepts cannot crash the pipeline either.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "navcore/nav_io.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_size_limits.h"
#include "navcore/nav_traj.h"
#include "navcore/nav_truth.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* The status is not what a fuzz target checks (GCC does not let (void) drop a nodiscard). */
#define NAV_FUZZ_IGNORE(call)        \
  do {                               \
    const nav_status ignored_ = call; \
    (void)ignored_;                  \
  } while (0)

static void ignore_issue(void *user, const char *path, const char *message) {
  (void)user;
  (void)path;
  (void)message;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  static nav_scene scene;
  if (nav_scene_read_string((const char *)data, size, "fuzz.yaml", &scene, NULL, NULL) != NAV_OK) return 0;
  if (nav_scene_validate(&scene, ignore_issue, NULL) != NAV_OK) __builtin_trap(); /* the reader accepted it */

  /* navsim run, estimate and render refuse a scene above the documented output and memory limits
   * before building anything (nav_size_check, without --allow-large); so does this target. Such a
   * scene's trajectory takes time in proportion to its length: a walking-pace waypoint moved 49
   * degrees of latitude away (tests/fuzz/corpus/fuzz_check/long-walk-leg.yaml, 750 million IMU
   * samples) took 4 s to plan natively and 50 s under the fuzzer, past its 10 s per-input bound. */
  nav_size_prediction pred;
  nav_predict_run(&scene, false, 1, false, &pred);
  if (!(pred.output_bytes <= NAV_MAX_OUTPUT_BYTES) || !(pred.memory_bytes <= NAV_MAX_MEMORY_BYTES)) {
    nav_scene_release(&scene);
    return 0;
  }

  /* Trajectory over its whole duration: a few evaluations and increments. */
  const double dt = 1.0 / scene.imu.rate_hz;
  nav_traj *traj = NULL;
  char msg[256];
  if (nav_traj_create_msg(&scene, dt, &traj, msg, sizeof msg) == NAV_OK) {
    /* Rate-integrated attitude is integrated from t = 0 on demand: stay within the first 2 s so
     * one input costs milliseconds whatever its duration. */
    const double dur = fmin(nav_traj_duration(traj), 2.0);
    double x[5], w[5];
    if (nav_gauss_legendre(5, x, w) != NAV_OK) __builtin_trap();
    for (int k = 0; k <= 4; ++k) {
      const double t = dur * k / 4.0;
      nav_traj_state s;
      NAV_FUZZ_IGNORE(nav_traj_eval(traj, t, &s));
      nav_vec3 f, om;
      NAV_FUZZ_IGNORE(nav_traj_inertial(traj, t, &f, &om));
      if (t + dt <= dur) NAV_FUZZ_IGNORE(nav_traj_inertial_increment(traj, t, t + dt, 5, x, w, &f, &om));
    }
    nav_traj_destroy(traj);
  }

  /* A bounded run. */
  if (scene.trajectory.duration_s > 0.5) scene.trajectory.duration_s = 0.5;
  if (scene.imu.rate_hz > 200.0) scene.imu.rate_hz = 200.0;
  if (scene.output.rate_hz > scene.imu.rate_hz) scene.output.rate_hz = scene.imu.rate_hz;
  scene.simulation.runs = 1;
  scene.simulation.threads = 1;
  nav_sim *sim = NULL;
  if (nav_sim_create(&scene, &sim) == NAV_OK) {
    nav_sim_options o = nav_sim_options_default();
    o.threads = 1;
    nav_sim_summary sum;
    NAV_FUZZ_IGNORE(nav_sim_run(sim, &o, &sum));
  }
  nav_sim_destroy(sim);
  nav_scene_release(&scene); /* a recorded reference's control points */
  return 0;
}
