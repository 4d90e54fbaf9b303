/*
 * Cancellation storm (issue 10): many start/cancel cycles of Monte Carlo runs at random
 * moments, three ways - the record callback returning NAV_STOP after a random number of epochs,
 * the progress callback returning NAV_STOP after a random number of calls, and another thread
 * calling nav_sim_request_cancel() after a random delay. Each cycle creates the simulation,
 * runs it on several threads and destroys it. Checked: no crash, no deadlock (a watchdog aborts
 * after NAV_STORM_TIMEOUT_S), the status is NAV_OK or NAV_ERR_CANCELLED (then the summary is
 * marked partial), and - in the ASan build - no leak (LeakSanitizer at exit), in the TSan build
 * no data race.
 *
 * NAV_STORM_CYCLES (environment) overrides the number of cycles (default 1000).
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_io.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sim.h"

#define NAV_STORM_TIMEOUT_S 900

static const char *k_scene_free =
    "format_version: 1\n"
    "name: storm-free\n"
    "trajectory: {duration_s: 2}\n"
    "imu:\n  rate_hz: 100\n  gyro: {arw_deg_per_sqrt_h: 0.15, bias_turn_on_deg_per_h: 1}\n"
    "  accel: {bias_turn_on_mg: 0.1}\n"
    "initial_errors: {position_m: [1, 1, 1], velocity_mps: 0.1, attitude_deg: [0.1, 0.1, 0.5]}\n"
    "output: {rate_hz: 10}\n"
    "simulation: {seed: 5, runs: 8}\n";

static const char *k_scene_gnss =
    "format_version: 1\n"
    "name: storm-gnss\n"
    "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 200}}\n"
    "trajectory: {type: test_motion, duration_s: 2, test_motion: {kind: stationary}}\n"
    "imu:\n  rate_hz: 100\n  catalog: \"Safran Sensonor STIM300\"\n"
    "gnss:\n  enabled: true\n  update_rate_hz: 10\n  position_white_sigma_m: [0.5, 0.5, 1]\n"
    "  reported_sigma: {position_m: [0.5, 0.5, 1], velocity_mps: [0.05, 0.05, 0.05]}\n"
    "initial_errors: {position_m: [1, 1, 1], velocity_mps: 0.1, attitude_deg: [0.1, 0.1, 1]}\n"
    "navigation: {scheme: ins_gnss}\n"
    "output: {rate_hz: 10}\n"
    "simulation: {seed: 6, runs: 8}\n";

typedef struct storm_ctl {
  long record_left;   /* record callback: NAV_STOP when it reaches 0 (< 0: never) */
  long progress_left; /* progress callback: NAV_STOP when it reaches 0 (< 0: never) */
} storm_ctl;

static nav_callback_result on_record(void *user, const nav_sim_record *r) {
  (void)r;
  storm_ctl *c = user;
  if (c->record_left < 0) return NAV_CONTINUE;
  return c->record_left-- == 0 ? NAV_STOP : NAV_CONTINUE;
}

static nav_callback_result on_progress(void *user, const nav_progress *p) {
  (void)p;
  storm_ctl *c = user;
  if (c->progress_left < 0) return NAV_CONTINUE;
  return c->progress_left-- == 0 ? NAV_STOP : NAV_CONTINUE;
}

typedef struct canceller {
  nav_sim *sim;
  long delay_us;
} canceller;

static void *cancel_thread(void *arg) {
  canceller *c = arg;
  struct timespec ts = {c->delay_us / 1000000, (c->delay_us % 1000000) * 1000};
  nanosleep(&ts, NULL);
  nav_sim_request_cancel(c->sim);
  return NULL;
}

static void on_watchdog(int sig) {
  (void)sig;
  static const char msg[] = "test_cancel_storm: watchdog: no progress (deadlock?)\n";
  (void)!write(2, msg, sizeof msg - 1);
  abort();
}

static void print_diag(void *user, const nav_diag *d) {
  (void)user;
  char buf[2048];
  nav_diag_format(d, buf, sizeof buf);
  fprintf(stderr, "%s\n", buf);
}

static void test_storm(void **state) {
  (void)state;
  long cycles = 1000;
  const char *env = getenv("NAV_STORM_CYCLES");
  if (env && atol(env) > 0) cycles = atol(env);
  nav_scene scenes[2];
  assert_int_equal(nav_scene_read_string(k_scene_free, strlen(k_scene_free), "storm-free", &scenes[0], print_diag, NULL),
                   NAV_OK);
  assert_int_equal(nav_scene_read_string(k_scene_gnss, strlen(k_scene_gnss), "storm-gnss", &scenes[1], print_diag, NULL),
                   NAV_OK);
  signal(SIGALRM, on_watchdog);
  alarm(NAV_STORM_TIMEOUT_S);
  nav_rng rng;
  nav_rng_init(&rng, 2026, 0, 0);
  long n_ok = 0, n_cancelled = 0, by_kind[3] = {0, 0, 0};
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  for (long c = 0; c < cycles; ++c) {
    const nav_scene *sc = &scenes[c % 2];
    nav_sim *sim = NULL;
    assert_int_equal(nav_sim_create(sc, &sim), NAV_OK);
    const int kind = (int)(nav_rng_next_u64(&rng) % 3);
    storm_ctl ctl = {-1, -1};
    const long epochs = lround(sc->trajectory.duration_s * sc->output.rate_hz) + 1;
    if (kind == 0) ctl.record_left = (long)(nav_rng_next_u64(&rng) % (uint64_t)(epochs + 2));
    if (kind == 1) ctl.progress_left = (long)(nav_rng_next_u64(&rng) % (uint64_t)(sc->simulation.runs + 2));
    nav_sim_options o = nav_sim_options_default();
    o.threads = 1 + (int)(nav_rng_next_u64(&rng) % 4);
    o.record = on_record;
    o.progress = on_progress;
    o.user = &ctl;
    pthread_t th;
    canceller cn = {sim, (long)(nav_rng_next_u64(&rng) % 20000)};
    if (kind == 2) assert_int_equal(pthread_create(&th, NULL, cancel_thread, &cn), 0);
    nav_sim_summary sum;
    const nav_status st = nav_sim_run(sim, &o, &sum);
    if (kind == 2) assert_int_equal(pthread_join(th, NULL), 0);
    if (st == NAV_OK) {
      ++n_ok;
      assert_false(sum.partial);
    } else if (st == NAV_ERR_CANCELLED) {
      ++n_cancelled;
      ++by_kind[kind];
      assert_true(sum.partial);
    } else {
      fail_msg("cycle %ld (kind %d, %d threads): status %s: %s", c, kind, o.threads, nav_status_str(st),
               nav_sim_last_error(sim));
    }
    nav_sim_destroy(sim);
  }
  alarm(0);
  clock_gettime(CLOCK_MONOTONIC, &t1);
  const double wall = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  printf("%ld cycles in %.1f s: %ld completed, %ld cancelled (record %ld, progress %ld, other thread %ld)\n", cycles,
         wall, n_ok, n_cancelled, by_kind[0], by_kind[1], by_kind[2]);
  /* The storm must really cancel: a large share of the cycles stop early. */
  assert_true(n_cancelled * 4 > cycles);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(test_storm)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
