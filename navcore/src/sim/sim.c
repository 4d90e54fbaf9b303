/* One simulation run: truth -> (ideal) IMU -> strapdown -> errors -> statistics. */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"

/* Above this many epochs per run, statistics use every stride-th epoch so memory stays bounded
 * (5 metrics x 8 bytes x 10 M = 400 MB worst case). */
#define STATS_MAX_EPOCHS 10000000LL
#define PROGRESS_EVERY 65536

struct nav_sim {
  nav_scene scene;
  atomic_bool cancel;
  char last_error[256];
};

nav_sim_options nav_sim_options_default(void) {
  nav_sim_options o = {false, NULL, NULL, NULL};
  return o;
}

nav_status nav_sim_create(const nav_scene *scene, nav_sim **out) {
  if (!scene || !out) return NAV_ERR_INVALID_ARG;
  if (nav_scene_validate(scene, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_sim *s = calloc(1, sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  s->scene = *scene;
  atomic_init(&s->cancel, false);
  *out = s;
  return NAV_OK;
}

void nav_sim_destroy(nav_sim *sim) { free(sim); }

void nav_sim_request_cancel(nav_sim *sim) {
  if (sim) atomic_store(&sim->cancel, true);
}

const char *nav_sim_last_error(const nav_sim *sim) { return sim ? sim->last_error : ""; }

static void set_error(nav_sim *sim, const char *what, nav_status st, double t_s) {
  snprintf(sim->last_error, sizeof sim->last_error, "%s failed at t = %.6f s: %s", what, t_s, nav_status_str(st));
}

typedef struct stat_set {
  nav_stat_acc *acc[5];
} stat_set;

static nav_status stat_add(stat_set *ss, const nav_epoch_errors *e) {
  const double v[5] = {e->pos_err_h_m, e->pos_err_v_m, e->vel_err_mps, e->att_err_rad, fabs(e->euler_err.yaw_rad)};
  for (int i = 0; i < 5; ++i) {
    const nav_status st = nav_stat_acc_add(ss->acc[i], v[i]);
    if (st != NAV_OK) return st;
  }
  return NAV_OK;
}

nav_status nav_sim_run(nav_sim *sim, const nav_sim_options *opts, nav_sim_summary *out) {
  nav_truth *truth = NULL;
  nav_ins *ins = NULL;
  stat_set ss = {{NULL, NULL, NULL, NULL, NULL}};
  nav_status st = NAV_OK;
  nav_sim_summary sum;
  if (!sim || !opts || !out) return NAV_ERR_INVALID_ARG;
  memset(&sum, 0, sizeof sum);
  sim->last_error[0] = '\0';
  atomic_store(&sim->cancel, false);
  const nav_scene *sc = &sim->scene;

  char msg[200];
  st = nav_truth_create_msg(sc, &truth, msg, sizeof msg);
  if (st != NAV_OK) {
    snprintf(sim->last_error, sizeof sim->last_error, "reference trajectory: %s",
             msg[0] ? msg : nav_status_str(st));
    goto cleanup;
  }
  const nav_frame frame = nav_truth_frame(truth);
  const int64_t n = nav_truth_sample_count(truth);
  const double dt = nav_truth_dt(truth);
  int64_t out_stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  if (out_stride < 1) out_stride = 1;
  int64_t stats_stride = (n + 1 + STATS_MAX_EPOCHS - 1) / STATS_MAX_EPOCHS;
  if (stats_stride < 1) stats_stride = 1;
  for (int i = 0; i < 5; ++i) {
    st = nav_stat_acc_create((size_t)(n / stats_stride + 2), &ss.acc[i]);
    if (st != NAV_OK) goto cleanup;
  }

  /* Initial state. Without sensor or initial-state error models in the scene (format v1),
   * the non-ideal run equals the ideal one. */
  nav_traj_state ts;
  st = nav_truth_state(truth, 0.0, &ts);
  if (st != NAV_OK) goto cleanup;
  nav_ins_state s0 = {0.0, ts.r_fb_f_m, ts.v_fb_f_mps, ts.q_b_f};
  nav_ins_config icfg = nav_ins_config_default();
  icfg.earth_model = sc->earth.model;
  icfg.algorithm = sc->navigation.algorithm;
  icfg.mech_frame = sc->navigation.frame;
  icfg.gravity_model = sc->earth.gravity_model;
  icfg.g_l_mps2 = nav_vec3_make(0.0, 0.0, sc->earth.flat_gravity_mps2);
  st = nav_ins_create(&icfg, &s0, &ins);
  if (st != NAV_OK) {
    set_error(sim, "navigation set-up", st, 0.0);
    goto cleanup;
  }

  nav_epoch_errors err = nav_errors_compute(&frame, &ts, nav_ins_get_state(ins));
  st = stat_add(&ss, &err);
  if (st != NAV_OK) goto cleanup;
  if (opts->record) {
    nav_sim_record rec = {0, &frame, &ts, nav_ins_get_state(ins), &err};
    if (opts->record(opts->user, &rec) == NAV_STOP) sum.partial = true;
  }

  int64_t k = 1;
  for (; k <= n && !sum.partial; ++k) {
    if (atomic_load_explicit(&sim->cancel, memory_order_relaxed)) {
      sum.partial = true;
      break;
    }
    nav_imu_increment imu;
    st = nav_truth_imu(truth, k, &imu);
    if (st != NAV_OK) {
      set_error(sim, "ideal IMU generation", st, (double)k * dt);
      goto cleanup;
    }
    st = nav_ins_step(ins, &imu);
    if (st != NAV_OK) {
      set_error(sim, "strapdown navigation", st, imu.t_s);
      goto cleanup;
    }
    st = nav_truth_state(truth, imu.t_s, &ts);
    if (st != NAV_OK) goto cleanup;
    err = nav_errors_compute(&frame, &ts, nav_ins_get_state(ins));
    if (k % stats_stride == 0) {
      st = stat_add(&ss, &err);
      if (st != NAV_OK) {
        set_error(sim, "error statistics", st, imu.t_s);
        goto cleanup;
      }
    }
    if (opts->record && (k % out_stride == 0 || k == n)) {
      nav_sim_record rec = {0, &frame, &ts, nav_ins_get_state(ins), &err};
      if (opts->record(opts->user, &rec) == NAV_STOP) sum.partial = true;
    }
    if (opts->progress && (k % PROGRESS_EVERY == 0 || k == n)) {
      nav_progress p = {"run", 0, (double)k / (double)n, imu.t_s};
      if (opts->progress(opts->user, &p) == NAV_STOP) sum.partial = true;
    }
  }

  sum.runs = 1;
  sum.imu_samples = k - 1;
  sum.duration_s = (double)(k - 1) * dt;
  sum.final = err;
  sum.stats.pos_err_h_m = nav_stat_acc_result(ss.acc[0]);
  sum.stats.pos_err_v_m = nav_stat_acc_result(ss.acc[1]);
  sum.stats.vel_err_mps = nav_stat_acc_result(ss.acc[2]);
  sum.stats.att_err_rad = nav_stat_acc_result(ss.acc[3]);
  sum.stats.yaw_err_rad = nav_stat_acc_result(ss.acc[4]);
  sum.stats_epochs = (int64_t)nav_stat_acc_count(ss.acc[0]);
  sum.stats_stride = stats_stride;
  *out = sum;
  st = sum.partial ? NAV_ERR_CANCELLED : NAV_OK;

cleanup:
  for (int i = 0; i < 5; ++i) nav_stat_acc_destroy(ss.acc[i]);
  nav_ins_destroy(ins);
  nav_truth_destroy(truth);
  return st;
}
