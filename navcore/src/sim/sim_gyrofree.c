/*
 * The gyro-free scheme of a simulation run (NAV_SCHEME_GYRO_FREE): the scene's accelerometer
 * array read from the same reference trajectory as the errors (nav_array_truth), the array error
 * model of the run (nav_array_model), and the gyro-free INS (nav_gyrofree) started from the run's
 * initial state and the true angular rate plus the run's initial-rate error.
 *
 * The pipeline direction is kept: truth -> array increments -> errors -> navigation; the
 * navigation sees only the measured increments, the initial state and the initial rate (which a
 * gyro-free INS must be given, like the initial attitude). sim.c compares its state with the
 * truth exactly as for the other schemes.
 *
 * Monte Carlo: the ideal array increments are the same in every run, so they are computed once
 * per job (nav_sim_gyrofree_truth) when they fit in memory; each run then only adds its errors.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_array.h"
#include "navcore/nav_gyrofree.h"
#include "navcore/nav_gyrofree_gnss.h"
#include "navcore/nav_rng.h"
#include "sim/sim_internal.h"

/* Largest shared table of ideal increments, in doubles (128 MB). */
#define GF_SHARED_MAX_VALUES 16000000LL

struct nav_sim_gyrofree_truth {
  int n_sensors;
  int64_t n; /* samples k = 1..n */
  double dt_s;
  nav_vec3 w0_rps; /* true omega_ib_b at t = 0 */
  double *dv_mps;  /* [n][n_sensors]: ideal increment of sensor i over interval k at (k-1) N + i */
};

struct nav_sim_gyrofree {
  const nav_sim_gyrofree_truth *shared; /* borrowed; NULL: own truth */
  nav_array_truth *truth;
  nav_array_model *model; /* NULL: ideal array */
  nav_gyrofree *ins;       /* gyro_free: the free array INS */
  nav_gyrofree_gnss *gfg;  /* gyro_free_gnss: the array INS in closed loop with its filter */
  int n_sensors;
  char msg[256];
};

static void set_msg(char *msg, size_t size, const char *text, nav_status st) {
  if (msg && size) snprintf(msg, size, "%s: %s", text, nav_status_str(st));
}

nav_status nav_sim_gyrofree_truth_create(const nav_scene *sc, nav_sim_gyrofree_truth **out, char *msg,
                                         size_t msg_size) {
  nav_array_truth *tr = NULL;
  nav_sim_gyrofree_truth *t = NULL;
  nav_accel_array layout;
  if (!sc || !out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  nav_status st = nav_array_layout_from_scene(&sc->array, &layout);
  if (st != NAV_OK) {
    set_msg(msg, msg_size, "accelerometer array", st);
    return st;
  }
  st = nav_array_truth_create_msg(sc, &layout, &tr, msg, msg_size);
  if (st != NAV_OK) return st;
  const int64_t n = nav_array_truth_sample_count(tr);
  if ((double)n * (double)layout.n_sensors > (double)GF_SHARED_MAX_VALUES)
    goto cleanup; /* runs sample their own */
  t = calloc(1, sizeof *t);
  if (t) t->dv_mps = malloc((size_t)n * (size_t)layout.n_sensors * sizeof *t->dv_mps);
  if (!t || !t->dv_mps) goto cleanup; /* not an error: each run samples its own truth */
  t->n_sensors = layout.n_sensors;
  t->n = n;
  t->dt_s = nav_array_truth_dt(tr);
  st = nav_array_truth_rate(tr, 0.0, &t->w0_rps);
  for (int64_t k = 1; k <= n && st == NAV_OK; ++k) {
    nav_array_increment inc;
    st = nav_array_truth_sample(tr, k, &inc);
    if (st == NAV_OK)
      memcpy(t->dv_mps + (k - 1) * t->n_sensors, inc.dv_mps, (size_t)t->n_sensors * sizeof(double));
  }
  if (st != NAV_OK) {
    set_msg(msg, msg_size, "ideal accelerometer-array increments", st);
    goto cleanup;
  }
  *out = t;
  t = NULL;
cleanup:
  nav_sim_gyrofree_truth_destroy(t);
  nav_array_truth_destroy(tr);
  return st;
}

void nav_sim_gyrofree_truth_destroy(nav_sim_gyrofree_truth *t) {
  if (!t) return;
  free(t->dv_mps);
  free(t);
}

nav_status nav_sim_gyrofree_create(const nav_scene *sc, const nav_sim_gyrofree_truth *shared, long run,
                                   bool ideal, const nav_ins_config *ins, const nav_ins_state *s0,
                                   nav_sim_gyrofree **out, char *msg, size_t msg_size) {
  nav_sim_gyrofree *g = NULL;
  nav_accel_array layout;
  nav_status st = NAV_OK;
  if (msg && msg_size) msg[0] = '\0';
  if (!sc || !ins || !s0 || !out) return NAV_ERR_INVALID_ARG;
  st = nav_array_layout_from_scene(&sc->array, &layout);
  if (st != NAV_OK) {
    set_msg(msg, msg_size, "accelerometer array", st);
    return st;
  }
  g = calloc(1, sizeof *g);
  if (!g) return NAV_ERR_NO_MEMORY;
  g->n_sensors = layout.n_sensors;
  nav_vec3 w0 = nav_vec3_zero();
  if (shared && shared->n_sensors == layout.n_sensors) {
    g->shared = shared;
    w0 = shared->w0_rps;
  } else {
    st = nav_array_truth_create_msg(sc, &layout, &g->truth, msg, msg_size);
    if (st == NAV_OK) st = nav_array_truth_rate(g->truth, 0.0, &w0);
    if (st != NAV_OK) {
      if (msg && msg_size && !msg[0]) set_msg(msg, msg_size, "accelerometer array truth", st);
      goto cleanup;
    }
  }
  if (!ideal) {
    /* The initial-rate error of body axis j: first draw of stream (INIT_ATT, 3 + j), channels
     * 0-2 being the initial attitude error (nav_scene_array). */
    for (unsigned j = 0; j < 3; ++j) {
      nav_rng r;
      nav_rng_init(&r, sc->simulation.seed, (uint64_t)run,
                   nav_rng_stream_id(NAV_RNG_STREAM_INIT_ATT, 3u + j));
      nav_vec3_set(&w0, (int)j,
                   nav_vec3_get(w0, (int)j) +
                       nav_vec3_get(sc->array.initial_rate_sd_rps, (int)j) * nav_rng_gauss(&r));
    }
    if (sc->array.accel.terms != 0) {
      st = nav_array_model_create(&sc->array.accel, layout.n_sensors, sc->simulation.seed, (uint64_t)run,
                                  &g->model);
      if (st != NAV_OK) {
        set_msg(msg, msg_size, "accelerometer-array error model", st);
        goto cleanup;
      }
    }
  }
  if (sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS) {
    nav_gyrofree_gnss_config xc = nav_gyrofree_gnss_config_from_scene(sc);
    xc.gf.ins = *ins;
    st = nav_gyrofree_gnss_create(&xc, s0, w0, &g->gfg);
    if (st != NAV_OK) {
      set_msg(msg, msg_size, "gyro-free INS/GNSS set-up", st);
      goto cleanup;
    }
    *out = g;
    g = NULL;
    goto cleanup;
  }
  nav_gyrofree_config cfg = nav_gyrofree_config_default();
  cfg.array = layout;
  cfg.ins = *ins;
  st = nav_gyrofree_create(&cfg, s0, w0, &g->ins);
  if (st != NAV_OK) {
    set_msg(msg, msg_size, "gyro-free INS set-up", st);
    goto cleanup;
  }
  *out = g;
  g = NULL;
cleanup:
  nav_sim_gyrofree_destroy(g);
  return st;
}

void nav_sim_gyrofree_destroy(nav_sim_gyrofree *g) {
  if (!g) return;
  nav_gyrofree_gnss_destroy(g->gfg);
  nav_gyrofree_destroy(g->ins);
  nav_array_model_destroy(g->model);
  nav_array_truth_destroy(g->truth);
  free(g);
}

nav_status nav_sim_gyrofree_step(nav_sim_gyrofree *g, int64_t k, nav_imu_increment *equiv) {
  if (!g || !equiv || k < 1) return NAV_ERR_INVALID_ARG;
  nav_array_increment inc;
  nav_status st = NAV_OK;
  if (g->shared) {
    if (k > g->shared->n) return NAV_ERR_OUT_OF_RANGE;
    /* Times exactly as nav_array_truth_sample() makes them, so a shared and an own truth give
     * bit-identical runs. */
    const double t0 = (double)(k - 1) * g->shared->dt_s, t1 = (double)k * g->shared->dt_s;
    memset(&inc, 0, sizeof inc);
    inc.k = k;
    inc.t_s = t1;
    inc.dt_s = t1 - t0;
    inc.n_sensors = g->n_sensors;
    memcpy(inc.dv_mps, g->shared->dv_mps + (k - 1) * g->n_sensors, (size_t)g->n_sensors * sizeof(double));
  } else {
    st = nav_array_truth_sample(g->truth, k, &inc);
    if (st != NAV_OK) {
      snprintf(g->msg, sizeof g->msg, "ideal accelerometer-array increments failed (%s) at sample %lld",
               nav_status_str(st), (long long)k);
      return st;
    }
  }
  if (g->model) {
    st = nav_array_model_apply(g->model, &inc, &inc);
    if (st != NAV_OK) {
      snprintf(g->msg, sizeof g->msg, "accelerometer-array error model failed (%s) at t = %.6f s",
               nav_status_str(st), inc.t_s);
      return st;
    }
  }
  if (g->gfg) {
    st = nav_gyrofree_gnss_step(g->gfg, &inc);
    if (st != NAV_OK) {
      snprintf(g->msg, sizeof g->msg, "gyro-free INS/GNSS stopped: %s", nav_gyrofree_gnss_last_error(g->gfg));
      return st;
    }
    *equiv = *nav_gyrofree_gnss_last_increment(g->gfg);
    g->msg[0] = '\0';
    return NAV_OK;
  }
  st = nav_gyrofree_step(g->ins, &inc);
  if (st != NAV_OK) {
    snprintf(g->msg, sizeof g->msg, "gyro-free navigation stopped: %s", nav_gyrofree_last_error(g->ins));
    return st;
  }
  *equiv = *nav_gyrofree_last_increment(g->ins);
  g->msg[0] = '\0';
  return NAV_OK;
}

const nav_ins_state *nav_sim_gyrofree_state(const nav_sim_gyrofree *g) {
  if (!g) return NULL;
  return g->gfg ? nav_gyrofree_gnss_state(g->gfg) : nav_gyrofree_get_state(g->ins);
}

nav_status nav_sim_gyrofree_update(nav_sim_gyrofree *g, const nav_ins_gnss_fix *fix) {
  if (!g || !fix || !g->gfg) return NAV_ERR_INVALID_ARG;
  const nav_status st = nav_gyrofree_gnss_update(g->gfg, fix);
  if (st != NAV_OK) snprintf(g->msg, sizeof g->msg, "%s", nav_gyrofree_gnss_last_error(g->gfg));
  return st;
}

const double *nav_sim_gyrofree_cov(const nav_sim_gyrofree *g, size_t *n) {
  if (!g || !g->gfg) return NULL;
  const nav_gfg_filter *kf = nav_gyrofree_gnss_filter(g->gfg);
  if (n) *n = nav_gfg_filter_n_states(kf);
  return nav_gfg_filter_cov(kf);
}

const char *nav_sim_gyrofree_last_error(const nav_sim_gyrofree *g) {
  return g ? g->msg : "";
}
