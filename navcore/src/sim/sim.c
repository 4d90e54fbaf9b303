/*
 * Simulation runs: truth -> sensors -> navigation -> errors -> statistics, one Monte Carlo run
 * per (seed, run) stream set, on any number of threads with bit-identical results.
 *
 * Determinism: a run depends only on the scene and its index (every random draw comes from a
 * stream keyed by (seed, run, stream id)); each run writes its metrics into its own rows of a
 * preallocated table, and the statistics are reduced over that table in run order after every
 * run has finished. Thread scheduling therefore changes nothing but the wall time.
 *
 * Run 0 executes on the calling thread first, so the record callback (the CSV writer of navsim)
 * sees one run, in order, on the caller's thread; the other runs then share the worker threads.
 *
 * navigation.smoother (INS/GNSS): each run attaches its own nav_smoother to its nav_ins_gnss,
 * marks the output epochs (the GNSS epochs are recorded by the updates), runs the backward pass
 * at the end of the run and stores the smoothed and the forward errors of its output epochs in
 * its rows of a per-run table (sm_metrics), reduced in run order like the other statistics and
 * carried by the partial results of sim_partial.c (MPI stays bit-identical). Memory: one
 * smoother per run in flight (records at the output and GNSS epochs only, nav_smoother.h), the
 * output-epoch references of the run when the truth is not shared, and the table (at most
 * SMOOTH_MAX_VALUES values per plane).
 */
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_gyrofree_gnss.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_rng.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_smoother.h"
#include "navcore/nav_truth.h"
#include "integration/ins_gnss_internal.h"
#include "math/lanes4.h"
#include "sensors/imu_model_internal.h"
#include "sim/nav_thread_internal.h"
#include "sim/sim_internal.h"
#include "sim/sim_partial_internal.h"
#include "traj/traj_internal.h"

/* Values kept for the envelopes (runs x output epochs x ENV_VALUES): bounded memory. */
#define STATS_MAX_VALUES NAV_SIM_ENV_MAX_VALUES
/* Values kept per metric for the statistics over runs and epochs (runs x epochs / stride, a
 * uniform subsample for the percentiles; RMS and max come from the same values): 5 metrics x
 * 8 bytes x 2e6 = 80 MB worst case, plus one metric's copy while reducing, so that a 1000-run,
 * one-hour 200 Hz campaign stays within 200 MB with its shared truth (54 MB of increments). */
#define METRIC_MAX_VALUES NAV_SIM_METRIC_MAX_VALUES
#define PROGRESS_EVERY 65536
#define N_METRICS 5
/* navigation.smoother: values kept per metric plane (2 x 5 planes, smoothed and forward errors at
 * the output epochs; every sm_stride-th output epoch beyond this): 10 x 8 B x 4e5 = 32 MB. */
#define SMOOTH_MAX_VALUES 400000LL
/* The smoother's discretisation groups (nav_smoother_config.group_steps), as navsim replay. */
#define SMOOTH_GROUP_STEPS 10u

struct nav_sim {
  nav_scene scene;
  atomic_bool cancel;
  char last_error[256];
  nav_sim_envelope_point *envelope; /* per output epoch, from the last run */
  size_t envelope_count;
  nav_sim_run_final *finals; /* per run, from the last run */
  size_t finals_count;
  nav_sim_range_hook hook; /* sim_partial.c: a range of runs, or a merge of ranges */
  nav_ins_gnss_fix *fixes; /* recorded GNSS fixes (gnss.file), scene time base; NULL: none */
  size_t fix_count;
};

/* Values per output epoch and run kept for the envelopes: N, E, D, |dv|, attitude angle, and for
 * INS/GNSS the filter's position sigma N, E, D and the 9-state NEES. */
#define ENV_VALUES 9

nav_sim_options nav_sim_options_default(void) {
  nav_sim_options o;
  memset(&o, 0, sizeof o);
  o.threads = 1;
  return o;
}

nav_status nav_sim_create(const nav_scene *scene, nav_sim **out) {
  if (!scene || !out) return NAV_ERR_INVALID_ARG;
  if (nav_scene_validate(scene, NULL, NULL) != NAV_OK) return NAV_ERR_INVALID_ARG;
  nav_sim *s = calloc(1, sizeof *s);
  if (!s) return NAV_ERR_NO_MEMORY;
  /* The simulation keeps a scene of its own (with its own copy of a recorded reference's
   * control points): it does not depend on the caller's scene staying alive. */
  if (nav_scene_copy(&s->scene, scene) != NAV_OK) {
    free(s);
    return NAV_ERR_NO_MEMORY;
  }
  atomic_init(&s->cancel, false);
  *out = s;
  return NAV_OK;
}

void nav_sim_destroy(nav_sim *sim) {
  if (!sim) return;
  free(sim->finals);
  free(sim->envelope);
  free(sim->fixes);
  nav_scene_release(&sim->scene);
  free(sim);
}

static bool vec3_positive(nav_vec3 v) { return v.x > 0.0 && v.y > 0.0 && v.z > 0.0; }

nav_status nav_sim_set_gnss_fixes(nav_sim *sim, const nav_ins_gnss_fix *fixes, size_t n) {
  if (!sim || (!fixes && n > 0)) return NAV_ERR_INVALID_ARG;
  for (size_t i = 0; i < n; ++i) {
    const nav_ins_gnss_fix *f = &fixes[i];
    const bool finite = isfinite(f->t_s) && isfinite(f->pos.lat_rad) && isfinite(f->pos.lon_rad) &&
                        isfinite(f->pos.h_m) && nav_vec3_isfinite(f->pos_sd_m) &&
                        (!f->has_vel || (nav_vec3_isfinite(f->v_n_mps) && nav_vec3_isfinite(f->vel_sd_mps)));
    const char *why = !finite                                       ? "a value is not finite"
                      : i > 0 && !(f->t_s > fixes[i - 1].t_s)       ? "its time is not after the previous fix's"
                      : !vec3_positive(f->pos_sd_m)                 ? "a position sigma is not positive"
                      : f->has_vel && !vec3_positive(f->vel_sd_mps) ? "a velocity sigma is not positive"
                                                                    : NULL;
    if (why) {
      snprintf(sim->last_error, sizeof sim->last_error, "recorded GNSS fix %zu (t = %.17g s): %s", i, f->t_s, why);
      return NAV_ERR_INVALID_ARG;
    }
  }
  nav_ins_gnss_fix *copy = NULL;
  if (n > 0) {
    copy = malloc(n * sizeof *copy);
    if (!copy) return NAV_ERR_NO_MEMORY;
    memcpy(copy, fixes, n * sizeof *copy);
  }
  free(sim->fixes);
  sim->fixes = copy;
  sim->fix_count = n;
  return NAV_OK;
}

const nav_sim_run_final *nav_sim_finals(const nav_sim *sim, size_t *count) {
  if (count) *count = sim && sim->finals ? sim->finals_count : 0;
  return sim ? sim->finals : NULL;
}

const nav_sim_envelope_point *nav_sim_envelope(const nav_sim *sim, size_t *count) {
  if (count) *count = sim && sim->envelope ? sim->envelope_count : 0;
  return sim ? sim->envelope : NULL;
}

void nav_sim_request_cancel(nav_sim *sim) {
  if (sim) atomic_store(&sim->cancel, true);
}

const char *nav_sim_last_error(const nav_sim *sim) { return sim ? sim->last_error : ""; }

void nav_sim_set_range_hook(nav_sim *sim, const nav_sim_range_hook *hook) {
  if (!sim) return;
  if (hook) sim->hook = *hook;
  else memset(&sim->hook, 0, sizeof sim->hook);
}

const nav_scene *nav_sim_scene(const nav_sim *sim) { return sim ? &sim->scene : NULL; }

void nav_sim_set_error(nav_sim *sim, const char *msg) {
  if (sim) snprintf(sim->last_error, sizeof sim->last_error, "%s", msg ? msg : "");
}

/* ------------------------------------------------------------------ one run */

/* Shared, read-mostly context of a Monte Carlo job. */
typedef struct job {
  nav_sim *sim;
  const nav_sim_options *opts;
  bool ideal;
  long runs;
  int64_t n;            /* IMU samples per run */
  int64_t stats_stride; /* every stats_stride-th epoch enters the statistics */
  int64_t stats_per_run;
  int64_t out_stride;
  int64_t n_out;        /* output epochs per run: k = 0, out_stride, ... (and n) */
  double *env;          /* [runs][n_out][ENV_VALUES], NULL when too large */
  double *metrics;      /* [N_METRICS][runs][stats_per_run] */
  nav_epoch_errors *final; /* [runs] */
  int64_t *samples_done;   /* [runs] */
  nav_status *status;      /* [runs] */
  atomic_long next_run;
  long run_end; /* runs [.., run_end) are executed (range hook: r1) */
  atomic_long runs_done;
  nav_mutex err_lock;
  bool err_set;
  bool gm_states; /* INS/GNSS: the filter carries GNSS GM error states */
  nav_gnss_model_config gnss_cfg; /* the scene's receiver plus segment-tied outages */
  /* Truth shared by every run (Monte Carlo): ideal increments k = 1..n and states k = 0..n,
   * computed once; NULL when the job has one run or would need too much memory. */
  nav_imu_increment *shared_imu;
  nav_traj_state *shared_ts; /* the states of the samples that need one (ts_map), compact */
  int32_t *ts_map;           /* [n + 1]: index into shared_ts, or -1 (state not kept) */
  nav_errors_ref *shared_ref; /* beside shared_ts: the reference part of the errors, or NULL */
  nav_sim_gyrofree_truth *gf_truth; /* gyro-free scheme: shared ideal array increments, or NULL */
  /* With shared truth and a simulated receiver: the reference at receiver epoch e (its time of
   * validity gnss_t[e], NaN when not kept), e < gnss_epochs, evaluated once for every run (see
   * epoch_state). */
  nav_traj_state *gnss_ts;
  double *gnss_t;
  int64_t gnss_epochs;
  nav_frame frame; /* the reference's frame and IMU interval (a run creates its own reference */
  double dt;       /* object only when it needs one: run_truth) */
  /* navigation.smoother (INS/GNSS): per-run RTS smoothing over the output and GNSS epochs. */
  bool smooth;
  int64_t sm_stride;  /* every sm_stride-th output slot enters the smoothed statistics */
  int64_t sm_per_run; /* values per run and plane */
  double *sm_metrics; /* [2 N_METRICS][runs][sm_per_run]: smoothed planes, then forward planes */
  int64_t *sm_bytes;  /* [runs]: smoother memory of the run (records + results) */
} job;

/* Largest memory for the shared reference parts of the errors (nav_errors_ref, ~0.2 KB per kept
 * state; the free INS with vertical aiding keeps every sample's). */
#define SHARED_REF_MAX_BYTES NAV_SIM_SHARED_REF_MAX_BYTES

/* Largest number of samples whose truth is shared between runs (~0.2 KB per sample). */
#define SHARED_TRUTH_MAX_SAMPLES 4000000LL

/* The shared reference state of sample k, or NULL when it is not kept: only the samples whose
 * errors are computed (statistics samples, output epochs, the first and the last) keep one, so
 * the shared truth is the increments (72 B per sample) plus a few states, not 232 B per sample
 * (175 MB for one hour at 200 Hz). Other samples (GNSS epochs off those) are evaluated by the
 * run's own truth object at the same time (k dt): the same numbers. */
static const nav_traj_state *shared_state(const job *j, int64_t k) {
  if (!j->shared_ts || k < 0 || k > j->n) return NULL;
  const int32_t i = j->ts_map[k];
  return i >= 0 ? &j->shared_ts[i] : NULL;
}

/* The reference part of the errors (nav_errors_ref) at sample k: the shared one beside
 * shared_state(j, k) when kept, else computed into *own from ts (the run's reference at k). */
static const nav_errors_ref *errors_ref(const job *j, int64_t k, const nav_traj_state *ts, nav_errors_ref *own) {
  if (j->shared_ref && shared_state(j, k)) return &j->shared_ref[j->ts_map[k]];
  *own = nav_errors_ref_compute(&j->frame, ts);
  return own;
}

/* The shared reference at receiver epoch `epoch` when it was kept for time t_s exactly, else NULL:
 * the state the run's own reference object would compute at t_s (the same numbers, as for
 * shared_state), without the per-run evaluation at every receiver epoch. */
static const nav_traj_state *epoch_state(const job *j, int64_t epoch, double t_s) {
  if (epoch < 0 || epoch >= j->gnss_epochs || !(j->gnss_t[epoch] == t_s)) return NULL;
  return &j->gnss_ts[epoch];
}

/* Keep the first failure's message (of any run) for nav_sim_last_error. */
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
static void job_error(job *j, const char *fmt, ...) {
  nav_mutex_lock(&j->err_lock);
  if (!j->err_set) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(j->sim->last_error, sizeof j->sim->last_error, fmt, ap);
    va_end(ap);
    j->err_set = true;
  }
  nav_mutex_unlock(&j->err_lock);
}

/* The run's own reference object, created at its first use: with shared truth a run of a Monte
 * Carlo job reads every ideal increment and every reference state it needs from the job
 * (shared_imu, shared_state, epoch_state) and never needs one. */
static nav_status run_truth(job *j, long run, nav_truth **truth) {
  if (*truth) return NAV_OK;
  char msg[200];
  const nav_status st = nav_truth_create_msg(&j->sim->scene, truth, msg, sizeof msg);
  if (st != NAV_OK) job_error(j, "run %ld: reference trajectory: %s", run, msg[0] ? msg : nav_status_str(st));
  return st;
}

/*
 * Initial navigation state of a run: the truth at t = 0 plus, unless ideal, the scene's initial
 * errors drawn from the run's INIT_* streams, resolved in local-level NED at the true position
 * (attitude error in the phi-angle convention E0.1: C_est = (I - [phi x]) C_true).
 */
static nav_ins_state initial_state(const nav_scene *sc, const nav_frame *fr, const nav_traj_state *ts, long run,
                                   bool ideal) {
  nav_ins_state s0 = {0.0, ts->r_fb_f_m, ts->v_fb_f_mps, ts->q_b_f};
  if (ideal) return s0;
  const nav_scene_initial_errors *ie = &sc->initial_errors;
  nav_vec3 dr_n, dv_n, phi_n;
  const nav_vec3 *sd[3] = {&ie->pos_sd_m, &ie->vel_sd_mps, &ie->att_sd_rad};
  nav_vec3 *draw[3] = {&dr_n, &dv_n, &phi_n};
  const nav_rng_stream_kind kinds[3] = {NAV_RNG_STREAM_INIT_POS, NAV_RNG_STREAM_INIT_VEL, NAV_RNG_STREAM_INIT_ATT};
  for (int q = 0; q < 3; ++q)
    for (int axis = 0; axis < 3; ++axis) {
      nav_rng r;
      nav_rng_init(&r, sc->simulation.seed, (uint64_t)run, nav_rng_stream_id(kinds[q], (unsigned)axis));
      nav_vec3_set(draw[q], axis, nav_vec3_get(*sd[q], axis) * nav_rng_gauss(&r));
    }
  const nav_local_view v = nav_frame_view(fr, ts->r_fb_f_m, ts->v_fb_f_mps, ts->q_b_f);
  /* C_f_n^T maps n-resolved vectors into F. */
  s0.r_fb_f_m = nav_vec3_add(ts->r_fb_f_m, nav_mat3_tmul_vec(v.C_f_n, dr_n));
  s0.v_fb_f_mps = nav_vec3_add(ts->v_fb_f_mps, nav_mat3_tmul_vec(v.C_f_n, dv_n));
  const nav_vec3 phi_f = nav_mat3_tmul_vec(v.C_f_n, phi_n);
  s0.q_b_f = nav_quat_normalize(nav_quat_mul(nav_quat_from_rotvec(nav_vec3_scale(phi_f, -1.0)), ts->q_b_f));
  return s0;
}

/*
 * The receiver configuration a run uses: the scene's, plus an outage for every segment of a
 * segment script marked gnss_visible: false (tunnels, bridges of motion-definition files), from
 * the planned segment boundaries. Outages beyond NAV_GNSS_MAX_OUTAGES are an error.
 */
nav_status nav_sim_gnss_config(const nav_scene *sc, double dt_s, nav_gnss_model_config *out, char *msg,
                               size_t msg_size) {
  *out = sc->gnss.model;
  const nav_status vst = nav_sim_gnss_visibility_outages(sc, dt_s, out, msg, msg_size);
  if (vst != NAV_OK) return vst;
  if (sc->trajectory.type != NAV_TRAJ_SEGMENTS) return NAV_OK;
  bool any = false;
  for (int i = 0; i < sc->trajectory.segments.count; ++i)
    if (!sc->trajectory.segments.items[i].gnss_visible) any = true;
  if (!any) return NAV_OK;
  nav_traj *tr = NULL;
  nav_status st = nav_traj_create_msg(sc, dt_s, &tr, msg, msg_size);
  if (st != NAV_OK) return st;
  static const size_t cap = NAV_MAX_SEGMENTS + 1;
  double *b = malloc(cap * sizeof *b);
  if (!b) {
    nav_traj_destroy(tr);
    return NAV_ERR_NO_MEMORY;
  }
  const size_t nb = nav_traj_segment_boundaries(tr, b, cap);
  for (int i = 0; i < sc->trajectory.segments.count && (size_t)i + 1 < nb; ++i) {
    if (sc->trajectory.segments.items[i].gnss_visible) continue;
    const double t0 = b[i], t1 = b[i + 1];
    /* Merge with the previous blocked segment when they touch. */
    if (out->outage_count > 0 && fabs(out->outages[out->outage_count - 1].t1_s - t0) < 1e-9) {
      out->outages[out->outage_count - 1].t1_s = t1;
      continue;
    }
    if (out->outage_count >= NAV_GNSS_MAX_OUTAGES) {
      if (msg) snprintf(msg, msg_size, "more than %d GNSS outages (segments with gnss_visible: false)", NAV_GNSS_MAX_OUTAGES);
      st = NAV_ERR_OUT_OF_RANGE;
      break;
    }
    if (t1 > t0) out->outages[out->outage_count++] = (nav_gnss_outage){t0, t1};
  }
  free(b);
  nav_traj_destroy(tr);
  return st;
}

/* Per-run state of the INS/GNSS scheme: the receiver model and the closed-loop integration. */
typedef struct aiding {
  nav_gnss_model *gnss;
  nav_sim_gnss_raw *raw; /* ins_gnss_tight: pseudoranges and range rates instead of fixes */
  bool pvt;              /* ins_gnss with gnss.constellation.fixes: pvt: raw feeds a PVT fix */
  nav_ins_gnss *x;
  nav_sim_gyrofree *gf; /* gyro_free_gnss: the fixes go to the array INS's filter (borrowed) */
  int64_t next_epoch;
  /* The time of receiver epoch t_epoch (a division), kept while the epoch waits: aiding_fixes
   * asks for the next epoch's time at every IMU step. */
  bool t_known;
  int64_t t_epoch;
  double t_fix_s;
} aiding;

static void aiding_destroy(aiding *a) {
  nav_sim_gnss_raw_destroy(a->raw);
  nav_ins_gnss_destroy(a->x);
  nav_gnss_model_destroy(a->gnss);
}

/* In an outage of the job's receiver configuration: [t0_s, t1_s), as the receiver model. */
static bool in_outage(const nav_gnss_model_config *c, double t_s) {
  for (size_t i = 0; i < c->outage_count; ++i)
    if (t_s >= c->outages[i].t0_s && t_s < c->outages[i].t1_s) return true;
  return false;
}

/* gnss.file: the recorded fixes up to t_k + dt/2, as the model's (below); the file's sigmas. */
static nav_status recorded_fixes(job *j, aiding *a, const nav_imu_increment *imu, long run) {
  const nav_sim *sim = j->sim;
  while ((size_t)a->next_epoch < sim->fix_count) {
    const nav_ins_gnss_fix *f = &sim->fixes[a->next_epoch];
    if (!(f->t_s <= imu->t_s + 0.5 * imu->dt_s)) break;
    a->next_epoch++;
    if (f->t_s < imu->t_s - 0.5 * imu->dt_s || in_outage(&j->gnss_cfg, f->t_s)) continue;
    const nav_status st = a->gf ? nav_sim_gyrofree_update(a->gf, f) : nav_ins_gnss_update(a->x, f);
    if (st != NAV_OK) {
      job_error(j, "run %ld: recorded GNSS fix at t = %.6f s: %s", run, f->t_s,
                a->gf ? nav_sim_gyrofree_last_error(a->gf) : nav_ins_gnss_last_error(a->x));
      return st;
    }
  }
  return NAV_OK;
}

/*
 * The receiver's own fix from an epoch's raw measurements (gnss.constellation.fixes: pvt): the
 * least-squares position (nav_gnss_pvt_solve) and velocity (nav_gnss_pvt_velocity) with their
 * covariances sigma^2 Q (Q the NED block of (H'H)^-1, sigma the code or range-rate noise), the
 * filter's R. *have is false when the solver has no solution: fewer than 3 + systems satellites,
 * a singular geometry or no convergence; position only when the velocity has no solution.
 */
static nav_status pvt_fix(const nav_ins_gnss_raw_epoch *ep, nav_ins_gnss_fix *f, double pos_cov[9],
                          double vel_cov[9], bool *have) {
  *have = false;
  nav_gnss_pseudorange pr[NAV_GNSS_MAX_SATS];
  nav_gnss_range_rate rr[NAV_GNSS_MAX_SATS];
  int n = 0;
  for (int i = 0; i < ep->n; ++i) {
    if (!ep->sats[i].has_pr || !ep->sats[i].has_rr) continue;
    pr[n] = (nav_gnss_pseudorange){ep->sats[i].sat, ep->sats[i].pr_m};
    rr[n] = (nav_gnss_range_rate){ep->sats[i].sat, ep->sats[i].rr_mps};
    ++n;
  }
  if (n < 4) return NAV_OK;
  nav_gnss_pvt p;
  nav_status st = nav_gnss_pvt_solve(n, pr, ep->t_gps_s, &p);
  if (st == NAV_ERR_INVALID_ARG || st == NAV_ERR_NUMERIC || st == NAV_ERR_NOT_CONVERGED) return NAV_OK;
  if (st != NAV_OK) return st;
  if (!(isfinite(p.dop_ned.x) && isfinite(p.dop_ned.y) && isfinite(p.dop_ned.z))) return NAV_OK;
  f->t_s = ep->t_s;
  f->pos = nav_earth_ecef_to_geodetic(p.r_e_m);
  f->pos_sd_m = nav_vec3_scale(p.dop_ned, ep->pr_sd_m);
  nav_gnss_pvt_vel v;
  f->has_vel = nav_gnss_pvt_velocity(n, rr, ep->t_gps_s, &p, &v) == NAV_OK;
  f->v_n_mps = f->has_vel ? v.v_n_mps : (nav_vec3){0.0, 0.0, 0.0};
  f->vel_sd_mps = f->has_vel ? nav_vec3_scale(v.dop_ned, ep->rr_sd_mps) : (nav_vec3){0.0, 0.0, 0.0};
  const double sp2 = ep->pr_sd_m * ep->pr_sd_m, sv2 = ep->rr_sd_mps * ep->rr_sd_mps;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      pos_cov[r * 3 + c] = sp2 * p.q_ned[r][c];
      vel_cov[r * 3 + c] = f->has_vel ? sv2 * v.q_ned[r][c] : 0.0;
    }
  *have = true;
  return NAV_OK;
}

/*
 * GNSS epochs whose time of validity falls within half an IMU interval of t_k are processed at
 * t_k (numerics.md 6.5: the residual offset is below dt/2; with rates that divide the IMU rate
 * it is zero). Each fix is made by the receiver model from the truth at its own time of validity.
 */
static nav_status aiding_fixes(job *j, aiding *a, nav_truth **truth, const nav_imu_increment *imu, long run) {
  const nav_scene *sc = &j->sim->scene;
  if (j->sim->fixes) return recorded_fixes(j, a, imu, run);
  for (;;) {
    if (!a->t_known || a->t_epoch != a->next_epoch) {
      a->t_fix_s = nav_gnss_model_epoch_time_s(a->gnss, a->next_epoch);
      a->t_epoch = a->next_epoch;
      a->t_known = true;
    }
    const double t_fix = a->t_fix_s;
    if (!(t_fix <= imu->t_s + 0.5 * imu->dt_s)) break;
    const int64_t epoch = a->next_epoch++;
    if (t_fix < imu->t_s - 0.5 * imu->dt_s) continue; /* before the run's first interval */
    nav_traj_state ts;
    nav_status st = NAV_OK;
    const double kf = t_fix / imu->dt_s;
    const int64_t kk = (int64_t)llround(kf);
    const bool on_grid = j->shared_ts && fabs(kf - (double)kk) < 1e-9 && kk >= 0 && kk <= j->n;
    const nav_traj_state *sh = on_grid ? shared_state(j, kk) : NULL;
    const double t_eval = on_grid ? (double)kk * j->dt : t_fix;
    if (!sh) sh = epoch_state(j, epoch, t_eval);
    if (sh) ts = *sh;
    else if ((st = run_truth(j, run, truth)) == NAV_OK) st = nav_truth_state(*truth, t_eval, &ts);
    if (st != NAV_OK) return st;
    nav_gnss_fix fix;
    bool has_fix = false;
    st = nav_gnss_model_measure(a->gnss, epoch, &ts, &fix, &has_fix);
    if (st != NAV_OK) {
      job_error(j, "run %ld: GNSS model: %s", run, nav_gnss_model_last_error(a->gnss));
      return st;
    }
    if (!has_fix) continue;
    if (a->raw && a->pvt) {
      /* Loosely coupled on the least-squares PVT of the same raw measurements. */
      nav_ins_gnss_raw_epoch ep;
      const nav_frame fr = j->frame;
      st = nav_sim_gnss_raw_measure(a->raw, &fr, &ts, &ep);
      nav_ins_gnss_fix f;
      double pos_cov[9], vel_cov[9];
      bool have = false;
      if (st == NAV_OK) st = pvt_fix(&ep, &f, pos_cov, vel_cov, &have);
      if (st == NAV_OK && have) st = nav_ins_gnss_update_cov(a->x, &f, pos_cov, vel_cov);
      if (st != NAV_OK) {
        job_error(j, "run %ld: %s", run, nav_ins_gnss_last_error(a->x));
        return st;
      }
      continue;
    }
    if (a->raw) {
      /* Tightly coupled: the receiver's epochs and outages, the satellites' raw measurements. */
      nav_ins_gnss_raw_epoch ep;
      const nav_frame fr = j->frame;
      st = nav_sim_gnss_raw_measure(a->raw, &fr, &ts, &ep);
      if (st == NAV_OK) st = nav_ins_gnss_update_raw(a->x, &ep, NULL);
      if (st != NAV_OK) {
        job_error(j, "run %ld: %s", run, nav_ins_gnss_last_error(a->x));
        return st;
      }
      continue;
    }
    nav_ins_gnss_fix f;
    f.t_s = fix.t_s;
    f.pos = fix.pos;
    f.pos_sd_m = fix.pos_sd_m;
    f.has_vel = true;
    f.v_n_mps = fix.v_fa_n_mps;
    f.vel_sd_mps = fix.vel_sd_mps;
    /* With GNSS GM error states in the filter, R holds only the white part of the error. */
    if (j->gm_states) f.pos_sd_m = sc->gnss.model.pos_white_sd_m;
    st = a->gf ? nav_sim_gyrofree_update(a->gf, &f) : nav_ins_gnss_update(a->x, &f);
    if (st != NAV_OK) {
      job_error(j, "run %ld: %s", run, a->gf ? nav_sim_gyrofree_last_error(a->gf) : nav_ins_gnss_last_error(a->x));
      return st;
    }
  }
  return NAV_OK;
}

static void store_metrics(job *j, long run, int64_t slot, const nav_epoch_errors *e) {
  const double v[N_METRICS] = {e->pos_err_h_m, e->pos_err_v_m, e->vel_err_mps, e->att_err_rad,
                               fabs(e->euler_err.yaw_rad)};
  const int64_t row = (int64_t)run * j->stats_per_run + slot;
  const int64_t plane = (int64_t)j->runs * j->stats_per_run;
  for (int m = 0; m < N_METRICS; ++m) j->metrics[(int64_t)m * plane + row] = v[m];
}

/* Output-epoch slot of sample k, or -1 when k is not an output epoch. */
static int64_t out_slot(const job *j, int64_t k) {
  if (k % j->out_stride == 0) return k / j->out_stride;
  return k == j->n ? j->n_out - 1 : -1;
}

/* Smoothed (forward = false) or forward errors of output slot @p slot into the smoothing table. */
static void store_sm(job *j, long run, int64_t slot, bool forward, const nav_epoch_errors *e) {
  if (!j->sm_metrics || slot < 0 || slot % j->sm_stride != 0 || slot / j->sm_stride >= j->sm_per_run) return;
  const double v[N_METRICS] = {e->pos_err_h_m, e->pos_err_v_m, e->vel_err_mps, e->att_err_rad,
                               fabs(e->euler_err.yaw_rad)};
  const int64_t plane = (int64_t)j->runs * j->sm_per_run;
  const int64_t row = (int64_t)run * j->sm_per_run + slot / j->sm_stride;
  for (int m = 0; m < N_METRICS; ++m) j->sm_metrics[(int64_t)(m + (forward ? N_METRICS : 0)) * plane + row] = v[m];
}

/*
 * End of a run with navigation.smoother: the backward pass over the run's records, then the
 * smoothed errors at every output slot (record sm_rec[slot]) against the reference (sm_ts, or the
 * shared truth) into the smoothing table, and for run 0 to the smoothed_record callback.
 */
static nav_status smooth_finish(job *j, long run, nav_smoother *sm, const size_t *sm_rec,
                                const nav_traj_state *sm_ts, const nav_frame *frame, bool record) {
  nav_status st = nav_smoother_run(sm);
  if (st != NAV_OK) {
    job_error(j, "run %ld: RTS smoother: %s", run, nav_smoother_last_error(sm));
    return st;
  }
  j->sm_bytes[run] = (int64_t)nav_smoother_memory_bytes(sm);
  const double dt = 1.0 / j->sim->scene.imu.rate_hz;
  for (int64_t e = 0; e < j->n_out; ++e) {
    const int64_t k = e == j->n_out - 1 ? j->n : e * j->out_stride;
    nav_smoother_epoch ep;
    st = nav_smoother_get(sm, sm_rec[e], &ep);
    if (st != NAV_OK) return st;
    const nav_traj_state *ts = sm_ts ? &sm_ts[e] : shared_state(j, k);
    if (!ts || fabs(ep.t_s - (double)k * dt) > 1e-6 * (1.0 + fabs(ep.t_s))) {
      job_error(j, "run %ld: RTS smoother: record %zu at t = %.6f s does not match output epoch t = %.6f s", run,
                sm_rec[e], ep.t_s, (double)k * dt);
      return NAV_ERR_STATE;
    }
    const nav_ins_state s = nav_ins_gnss_state_ecef(&ep.smoothed, ts->t_s);
    const nav_epoch_errors err = nav_errors_compute(frame, ts, &s);
    store_sm(j, run, e, false, &err);
    if (record) {
      nav_sim_record rec = {run, frame, ts, &s, &err, NULL, NULL, ep.sd_smoothed, ep.sd_forward};
      if (j->opts->smoothed_record(j->opts->user, &rec) == NAV_STOP) return NAV_ERR_CANCELLED;
    }
  }
  return NAV_OK;
}

/*
 * NEES of the 9 navigation error states against the filter's covariance (numerics.md T6.5):
 * e = (dr_n, dv_n, phi) with phi from C_true C_est^T = I + [phi x] (E0.1), resolved in n.
 * Returns NAN when the block is not positive definite.
 */
static double nees9(const double *P, size_t n, const nav_errors_ref *ref, const nav_traj_state *ts,
                    const nav_ins_state *s, const nav_epoch_errors *e) {
  double B[81], L[81], x[9];
  for (size_t i = 0; i < 9; ++i)
    for (size_t q = 0; q < 9; ++q) B[i * 9 + q] = P[i * n + q];
  const nav_vec3 phi_f = nav_quat_to_rotvec(nav_quat_mul(ts->q_b_f, nav_quat_conj(s->q_b_f)));
  const nav_vec3 phi_n = nav_mat3_mul_vec(ref->view.C_f_n, phi_f);
  const double err[9] = {e->pos_err_n_m.x,   e->pos_err_n_m.y,   e->pos_err_n_m.z, e->vel_err_n_mps.x, e->vel_err_n_mps.y,
                         e->vel_err_n_mps.z, phi_n.x, phi_n.y, phi_n.z};
  if (nav_matn_cholesky(L, B, 9) != NAV_OK) return NAN;
  nav_matn_chol_solve(x, L, err, 9, 1);
  double q2 = 0.0;
  for (int i = 0; i < 9; ++i) q2 += err[i] * x[i];
  return q2;
}

/* The filter covariance of a run (INS/GNSS or gyro-free/GNSS; both lead with dr, dv, phi), or
 * NULL for the unaided schemes. */
static const double *run_cov(const nav_ins_gnss *x, const nav_sim_gyrofree *gf, size_t *n) {
  if (x) {
    const nav_filter *kf = nav_ins_gnss_filter(x);
    *n = nav_filter_get_layout(kf).n_states;
    return nav_filter_get_cov(kf);
  }
  return gf ? nav_sim_gyrofree_cov(gf, n) : NULL;
}

static void store_env(job *j, long run, int64_t k, const nav_epoch_errors *e, const double *P, size_t n,
                      const nav_errors_ref *ref, const nav_traj_state *ts, const nav_ins_state *s) {
  const int64_t slot = out_slot(j, k);
  if (!j->env || slot < 0 || slot >= j->n_out) return;
  double *v = j->env + ((int64_t)run * j->n_out + slot) * ENV_VALUES;
  v[0] = e->pos_err_n_m.x;
  v[1] = e->pos_err_n_m.y;
  v[2] = e->pos_err_n_m.z;
  v[3] = e->vel_err_mps;
  v[4] = e->att_err_rad;
  v[5] = v[6] = v[7] = v[8] = 0.0;
  if (P) {
    for (int i = 0; i < 3; ++i) v[5 + i] = sqrt(P[(size_t)i * n + (size_t)i]);
    v[8] = nees9(P, n, ref, ts, s, e);
  }
}

/* One run's state between its steps: run_one() runs one run through run_open(), its steps
 * (run_measure(), run_navigate(), run_after()) and run_close(); run_group() runs four runs whose
 * strapdown steps go in lockstep (nav_ins_gnss_step_lanes()), each run with the same calls in
 * the same order as alone, so with the same results. */
typedef struct run_ctx {
  job *j;
  long run;
  bool caller_thread;
  nav_truth *truth;
  nav_ins *ins;
  nav_imu_model *imu_model;
  nav_sim_gyrofree *gf; /* gyro-free scheme (sim_gyrofree.c): replaces the IMU */
  nav_smoother *sm;     /* navigation.smoother: the run's RTS smoother */
  size_t *sm_rec;       /* [n_out]: smoother record of each output slot */
  nav_traj_state *sm_ts; /* [n_out]: reference at each output slot (no shared truth) */
  aiding aid_kf;
  const nav_run_observer *obs; /* requirements (nav_requirements.h) */
  void *obs_ctx;
  bool aid, tight, integrated, gf_gnss, gyro_free, record, stop;
  nav_traj_state ts;
  nav_errors_ref own_ref;
  nav_epoch_errors err;
  size_t cov_n;
  int64_t k;
  /* Steps left to the next statistics sample and output epoch: k % stride == 0 exactly when a
   * countdown started at stride (k = 1) reaches 0, without two 64-bit divisions per step. */
  int64_t stats_left, out_left;
  /* The step's ideal record (the shared one is read in place: no copy per step) and the raw
   * measured record: every consumer takes meas as const (no copy of it is kept for the record
   * callback). */
  nav_imu_increment own_imu, meas;
  const nav_imu_increment *ideal;
} run_ctx;

/* Set-up of a run and its epoch 0; on failure the run is closed by run_close() all the same. */
static nav_status run_open(run_ctx *c, job *j, long run, bool caller_thread) {
  memset(c, 0, sizeof *c);
  c->j = j;
  c->run = run;
  c->caller_thread = caller_thread;
  nav_sim *sim = j->sim;
  const nav_scene *sc = &sim->scene;
  c->obs = j->opts->observer;
  c->obs_ctx = c->obs && c->obs->begin ? c->obs->begin(c->obs->user, run) : NULL;
  char msg[200];
  nav_status st = j->shared_imu ? NAV_OK : run_truth(j, run, &c->truth);
  if (st != NAV_OK) return st;
  const nav_frame frame = j->frame;
  c->gf_gnss = sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
  c->gyro_free = sc->navigation.scheme == NAV_SCHEME_GYRO_FREE || c->gf_gnss;
  if (!j->ideal && !c->gyro_free) {
    st = nav_imu_model_create(&sc->imu.model, sc->simulation.seed, (uint64_t)run, &c->imu_model);
    if (st != NAV_OK) {
      job_error(j, "run %ld: IMU error model: %s", run, nav_status_str(st));
      return st;
    }
    nav_imu_model_defer_bias(c->imu_model); /* no run reads the bias state */
  }
  if (shared_state(j, 0)) c->ts = *shared_state(j, 0);
  else if ((st = run_truth(j, run, &c->truth)) == NAV_OK) st = nav_truth_state(c->truth, 0.0, &c->ts);
  if (st != NAV_OK) return st;
  const nav_ins_state s0 = initial_state(sc, &frame, &c->ts, run, j->ideal);
  const nav_ins_config icfg = nav_ins_config_from_scene(sc);
  st = nav_ins_create(&icfg, &s0, &c->ins);
  if (st != NAV_OK) {
    job_error(j, "run %ld: navigation set-up: %s", run, nav_status_str(st));
    return st;
  }
  c->aid = sc->navigation.aid_vertical;
  c->tight = sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT;
  c->integrated = sc->navigation.scheme == NAV_SCHEME_INS_GNSS || c->tight;
  if (c->integrated || c->gf_gnss) {
    /* --ideal: the receiver is perfect too (same epochs and outages, no error terms). */
    nav_gnss_model_config gcfg = j->gnss_cfg;
    if (j->ideal) gcfg.terms = 0;
    st = nav_gnss_model_create(&gcfg, &frame, sc->simulation.seed, (uint64_t)run, &c->aid_kf.gnss);
    if (st != NAV_OK) {
      job_error(j, "run %ld: GNSS receiver model: %s", run, nav_status_str(st));
      return st;
    }
  }
  if (c->integrated) {
    nav_ins_gnss_config xc = nav_ins_gnss_config_from_scene(sc);
    if (j->smooth) {
      /* Records at the output and GNSS epochs only (nav_smoother.h: ~4.3 KiB each at 15 states). */
      nav_smoother_config scfg = nav_smoother_config_default();
      scfg.filter = xc.filter;
      scfg.group_steps = SMOOTH_GROUP_STEPS;
      st = nav_smoother_create(&scfg, &c->sm);
      c->sm_rec = st == NAV_OK ? malloc((size_t)j->n_out * sizeof *c->sm_rec) : NULL;
      c->sm_ts = st == NAV_OK && !j->shared_ts ? malloc((size_t)j->n_out * sizeof *c->sm_ts) : NULL;
      if (st == NAV_OK && (!c->sm_rec || (!j->shared_ts && !c->sm_ts))) st = NAV_ERR_NO_MEMORY;
      if (st != NAV_OK) {
        job_error(j, "run %ld: RTS smoother set-up: %s", run, nav_status_str(st));
        return st;
      }
      xc.smoother = c->sm;
    }
    st = nav_ins_gnss_create(&xc, &s0, &c->aid_kf.x);
    c->aid_kf.pvt = !c->tight && nav_scene_gnss_pvt_fixes(sc);
    if (st == NAV_OK && (c->tight || c->aid_kf.pvt))
      st = nav_sim_gnss_raw_create(sc, (uint64_t)run, j->ideal, &c->aid_kf.raw);
    if (st != NAV_OK) {
      job_error(j, "run %ld: INS/GNSS set-up: %s", run, nav_status_str(st));
      return st;
    }
  }
  if (c->gyro_free) {
    st = nav_sim_gyrofree_create(sc, j->gf_truth, run, j->ideal, &icfg, &s0, &c->gf, msg, sizeof msg);
    if (st != NAV_OK) {
      job_error(j, "run %ld: gyro-free INS: %s", run, msg[0] ? msg : nav_status_str(st));
      return st;
    }
    c->aid_kf.gf = c->gf_gnss ? c->gf : NULL;
  }
  c->record = caller_thread && run == 0 && j->opts->record;

  const nav_errors_ref *ref = errors_ref(j, 0, &c->ts, &c->own_ref);
  c->err = nav_errors_compute_ref(&frame, &c->ts, ref, nav_ins_get_state(c->ins));
  store_metrics(j, run, 0, &c->err);
  const double *cov0 = run_cov(c->aid_kf.x, c->aid_kf.gf, &c->cov_n);
  store_env(j, run, 0, &c->err, cov0, c->cov_n, ref, &c->ts, nav_ins_get_state(c->ins));
  if (c->obs_ctx) c->obs->epoch(c->obs_ctx, &c->err);
  if (c->sm) {
    c->sm_rec[0] = 0; /* nav_ins_gnss_create recorded epoch 0 */
    if (c->sm_ts) c->sm_ts[0] = c->ts;
    store_sm(j, run, 0, true, &c->err);
  }
  if (c->record) {
    nav_sim_record rec = {run, &frame, &c->ts, nav_ins_get_state(c->ins), &c->err, NULL, NULL, NULL, NULL};
    if (j->opts->record(j->opts->user, &rec) == NAV_STOP) c->stop = true;
  }
  c->k = 1;
  c->stats_left = j->stats_stride;
  c->out_left = j->out_stride;
  return NAV_OK;
}

/* Step k's measured record c->meas: the ideal increment with the IMU's errors (or the gyro-free
 * array's equivalent). A cancelled job sets c->stop instead. */
static nav_status run_measure(run_ctx *c) {
  job *j = c->j;
  const long run = c->run;
  const int64_t k = c->k;
  if (atomic_load_explicit(&j->sim->cancel, memory_order_relaxed)) {
    c->stop = true;
    return NAV_OK;
  }
  nav_status st = NAV_OK;
  c->ideal = &c->own_imu;
  if (j->shared_imu) c->ideal = &j->shared_imu[k - 1];
  else if ((st = run_truth(j, run, &c->truth)) == NAV_OK) st = nav_truth_imu(c->truth, k, &c->own_imu);
  if (st != NAV_OK) {
    job_error(j, "run %ld: ideal IMU generation failed (%s) at t = %.6f s", run, nav_status_str(st),
              (double)k * j->dt);
    return st;
  }
  if (c->gf) {
    /* Gyro-free: the array replaces the IMU; meas is the INS's equivalent (dtheta, dv). */
    st = nav_sim_gyrofree_step(c->gf, k, &c->meas);
    if (st != NAV_OK) job_error(j, "run %ld: %s", run, nav_sim_gyrofree_last_error(c->gf));
  } else if (c->imu_model) {
    st = nav_imu_model_apply(c->imu_model, c->ideal, &c->meas);
    if (st != NAV_OK)
      job_error(j, "run %ld: IMU error model failed (%s) at t = %.6f s", run, nav_status_str(st), c->ideal->t_s);
  } else {
    c->meas = *c->ideal;
  }
  return st;
}

/* The INS/GNSS step's failure, worded for the job. */
static nav_status ins_gnss_failed(run_ctx *c, nav_status st) {
  job_error(c->j, "run %ld: %s", c->run, nav_ins_gnss_last_error(c->aid_kf.x));
  return st;
}

/* The navigation step with c->meas: the INS/GNSS step (strapdown and prediction) or the free
 * INS's strapdown (the gyro-free schemes stepped in run_measure). */
static nav_status run_navigate(run_ctx *c) {
  if (c->integrated) {
    const nav_status st = nav_ins_gnss_step(c->aid_kf.x, &c->meas);
    return st != NAV_OK ? ins_gnss_failed(c, st) : NAV_OK;
  }
  if (!c->gf_gnss && !c->gf) {
    const nav_status st = nav_ins_step(c->ins, &c->meas);
    if (st != NAV_OK)
      job_error(c->j, "run %ld: strapdown navigation stopped (%s) at t = %.6f s", c->run, nav_ins_last_error(c->ins),
                c->meas.t_s);
    return st;
  }
  return NAV_OK;
}

/* The rest of step k: the receiver epochs of the step, then the errors, statistics, outputs and
 * callbacks where step k has any. */
static nav_status run_after(run_ctx *c) {
  job *j = c->j;
  const long run = c->run;
  const int64_t k = c->k;
  const nav_frame *frame = &j->frame;
  nav_status st = NAV_OK;
  if (c->integrated || c->gf_gnss) {
    st = aiding_fixes(j, &c->aid_kf, &c->truth, &c->meas, run);
    if (st != NAV_OK) return st;
  }
  /* The errors are needed only at the statistics samples, the output epochs and the end: the
   * reference state, the navigation state's e-frame view and the errors (together more than
   * the navigation step itself) are not computed in between. */
  const bool stats_tick = --c->stats_left == 0, out_tick = --c->out_left == 0;
  if (stats_tick) c->stats_left = j->stats_stride;
  if (out_tick) c->out_left = j->out_stride;
  const bool stats_k = stats_tick && k / j->stats_stride < j->stats_per_run;
  const bool out_k = out_tick || k == j->n;
  if (!stats_k && !out_k && !(c->aid && !c->integrated)) {
    if (c->caller_thread && j->opts->progress && k % PROGRESS_EVERY == 0) {
      const double done = (double)atomic_load(&j->runs_done) + (double)k / (double)j->n;
      nav_progress p = {"run", run, done / (double)j->runs, c->meas.t_s};
      if (j->opts->progress(j->opts->user, &p) == NAV_STOP) c->stop = true;
    }
    return NAV_OK;
  }
  const nav_ins_state *nav_now = c->integrated ? nav_ins_gnss_state(c->aid_kf.x)
                                 : c->gf       ? nav_sim_gyrofree_state(c->gf)
                                               : nav_ins_get_state(c->ins);
  const nav_traj_state *sh = shared_state(j, k);
  if (sh) c->ts = *sh;
  else if ((st = run_truth(j, run, &c->truth)) == NAV_OK) st = nav_truth_state(c->truth, c->meas.t_s, &c->ts);
  if (st != NAV_OK) return st;
  if (c->aid && !c->integrated) {
    /* Height aiding from the reference (a baro-like sensor): flat Earth height is -D. */
    const nav_local_view v = nav_frame_view(frame, c->ts.r_fb_f_m, c->ts.v_fb_f_mps, c->ts.q_b_f);
    const double h = frame->model == NAV_EARTH_FLAT ? -c->ts.r_fb_f_m.z : v.pos.h_m;
    st = nav_ins_aid_vertical(c->ins, h, v.v_n_mps.z);
    if (st != NAV_OK) return st;
  }
  const nav_errors_ref *ref = errors_ref(j, k, &c->ts, &c->own_ref);
  c->err = nav_errors_compute_ref(frame, &c->ts, ref, nav_now);
  if (k % j->stats_stride == 0 && k / j->stats_stride < j->stats_per_run)
    store_metrics(j, run, k / j->stats_stride, &c->err);
  const double *cov = run_cov(c->aid_kf.x, c->aid_kf.gf, &c->cov_n);
  store_env(j, run, k, &c->err, cov, c->cov_n, ref, &c->ts, nav_now);
  if (c->obs_ctx && (k % j->out_stride == 0 || k == j->n)) c->obs->epoch(c->obs_ctx, &c->err);
  if (c->sm && out_k) {
    /* An output epoch: a smoother record (a no-op when a GNSS update made one at this step). */
    st = nav_smoother_mark(c->sm);
    if (st != NAV_OK) {
      job_error(j, "run %ld: RTS smoother record at t = %.6f s: %s", run, c->meas.t_s, nav_smoother_last_error(c->sm));
      return st;
    }
    const int64_t slot = out_slot(j, k);
    c->sm_rec[slot] = nav_smoother_count(c->sm) - 1;
    if (c->sm_ts) c->sm_ts[slot] = c->ts;
    store_sm(j, run, slot, true, &c->err);
  }
  if (c->record && (k % j->out_stride == 0 || k == j->n)) {
    nav_sim_record rec = {run, frame, &c->ts, nav_now, &c->err, c->ideal, &c->meas, NULL, NULL};
    if (j->opts->record(j->opts->user, &rec) == NAV_STOP) c->stop = true;
  }
  if (c->caller_thread && j->opts->progress && (k % PROGRESS_EVERY == 0 || k == j->n)) {
    const double done = (double)atomic_load(&j->runs_done) + (double)k / (double)j->n;
    nav_progress p = {"run", run, done / (double)j->runs, c->meas.t_s};
    if (j->opts->progress(j->opts->user, &p) == NAV_STOP) c->stop = true;
  }
  return NAV_OK;
}

/* The end of a run: after its steps (st == NAV_OK) the final errors and the smoother; then, in
 * any case, its status and the release of what it holds. */
static nav_status run_close(run_ctx *c, nav_status st) {
  job *j = c->j;
  const long run = c->run;
  if (st == NAV_OK) {
    j->final[run] = c->err;
    j->samples_done[run] = c->k - 1;
    if (c->sm && !c->stop) {
      const nav_frame frame = j->frame;
      const bool sm_record = c->caller_thread && run == 0 && j->opts->smoothed_record;
      st = smooth_finish(j, run, c->sm, c->sm_rec, c->sm_ts, &frame, sm_record);
      if (st == NAV_ERR_CANCELLED) c->stop = true;
    }
    if (st == NAV_OK || st == NAV_ERR_CANCELLED) {
      st = c->stop ? NAV_ERR_CANCELLED : NAV_OK;
      if (c->stop) atomic_store(&j->sim->cancel, true); /* a stop in run 0 stops the whole job */
    }
  }
  if (c->obs_ctx) c->obs->end(c->obs->user, c->obs_ctx, st == NAV_OK);
  aiding_destroy(&c->aid_kf);
  nav_smoother_destroy(c->sm); /* after the nav_ins_gnss that borrowed it */
  free(c->sm_rec);
  free(c->sm_ts);
  nav_sim_gyrofree_destroy(c->gf);
  nav_imu_model_destroy(c->imu_model);
  nav_ins_destroy(c->ins);
  nav_truth_destroy(c->truth);
  j->status[run] = st;
  atomic_fetch_add(&j->runs_done, 1);
  return st;
}

static nav_status run_one(job *j, long run, bool caller_thread) {
  run_ctx c;
  nav_status st = run_open(&c, j, run, caller_thread);
  for (; st == NAV_OK && c.k <= j->n && !c.stop; ++c.k) {
    st = run_measure(&c);
    if (st != NAV_OK || c.stop) break;
    st = run_navigate(&c);
    if (st == NAV_OK) st = run_after(&c);
  }
  return run_close(&c, st);
}

/* Can the runs of this job go in groups of NAV_LANES (run_group)? The loosely coupled INS/GNSS
 * scheme on simulated fixes with the IMU's errors and the shared truth; not the first run on the
 * caller's thread (records, progress), which run_one() keeps. */
static bool group_job(const job *j) {
  const nav_scene *sc = &j->sim->scene;
  return j->opts->lanes != 1 && j->shared_imu && !j->ideal && !j->smooth && sc->navigation.scheme == NAV_SCHEME_INS_GNSS &&
         !nav_scene_gnss_pvt_fixes(sc);
}

/*
 * Runs r0 .. r0 + NAV_LANES - 1 together: every run makes the calls of run_one() in the same order
 * (so the same values), and at each step the four strapdown steps go in lockstep
 * (nav_ins_gnss_step_lanes()) when all four runs are still going. A run that stops or fails leaves
 * the group; the others go on with their own steps.
 */
static void run_group(job *j, long r0) {
  run_ctx c[NAV_LANES];
  nav_status st[NAV_LANES];
  bool going[NAV_LANES];
  bool integrated = true; /* every run has its INS/GNSS object (group_job's scheme) */
  for (int l = 0; l < NAV_LANES; ++l) {
    st[l] = run_open(&c[l], j, r0 + l, false);
    going[l] = st[l] == NAV_OK && !c[l].stop;
    integrated = integrated && c[l].integrated;
  }
  /* The four IMU error models in lanes too, while all four runs go (their first sample to their
   * last but one that fails or stops). */
  nav_imu_model *models[NAV_LANES];
  bool all_going = true;
  for (int l = 0; l < NAV_LANES; ++l) {
    models[l] = c[l].imu_model;
    all_going = all_going && going[l];
  }
  nav_imu_lanes *imu = all_going ? nav_imu_lanes_open(models) : NULL;
  for (int64_t k = 1; k <= j->n; ++k) {
    int n_going = 0;
    if (imu && !atomic_load_explicit(&j->sim->cancel, memory_order_relaxed)) {
      /* run_measure() of the four runs: the same shared ideal record, the models in lanes. */
      const nav_imu_increment *ideal = &j->shared_imu[k - 1];
      if (k + 16 <= j->n) __builtin_prefetch(&j->shared_imu[k + 15]); /* 16 samples ahead, within the array */
      nav_imu_increment *meas[NAV_LANES];
      for (int l = 0; l < NAV_LANES; ++l)
        meas[l] = &c[l].meas;
      if (nav_imu_lanes_apply(imu, ideal, meas)) {
        for (int l = 0; l < NAV_LANES; ++l) {
          c[l].ideal = ideal;
          st[l] = NAV_OK;
        }
        n_going = NAV_LANES;
      }
    }
    if (n_going == 0) {
      /* A cancel or a sample the lanes refuse: the models go on alone, run_measure() as in run_one(). */
      nav_imu_lanes_close(imu);
      imu = NULL;
      for (int l = 0; l < NAV_LANES; ++l) {
        if (!going[l]) continue;
        st[l] = run_measure(&c[l]);
        if (st[l] != NAV_OK || c[l].stop)
          going[l] = false;
        else
          ++n_going;
      }
    }
    if (n_going == 0) break;
    if (n_going == NAV_LANES && integrated) {
      nav_ins_gnss *x[NAV_LANES];
      const nav_imu_increment *m[NAV_LANES];
      for (int l = 0; l < NAV_LANES; ++l) {
        x[l] = c[l].aid_kf.x;
        m[l] = &c[l].meas;
      }
      nav_ins_gnss_step_lanes(x, m, st);
      for (int l = 0; l < NAV_LANES; ++l)
        if (st[l] != NAV_OK) st[l] = ins_gnss_failed(&c[l], st[l]);
    } else {
      for (int l = 0; l < NAV_LANES; ++l)
        if (going[l]) st[l] = run_navigate(&c[l]);
    }
    for (int l = 0; l < NAV_LANES; ++l) {
      if (!going[l]) continue;
      if (st[l] == NAV_OK) st[l] = run_after(&c[l]);
      if (st[l] != NAV_OK) {
        going[l] = false;
        continue;
      }
      ++c[l].k;
      if (c[l].stop) going[l] = false;
    }
    for (int l = 0; l < NAV_LANES && imu; ++l)
      if (!going[l]) {
        nav_imu_lanes_close(imu);
        imu = NULL;
      }
  }
  nav_imu_lanes_close(imu); /* before run_close() destroys the models */
  for (int l = 0; l < NAV_LANES; ++l)
    (void)run_close(&c[l], st[l]);
}

/* Runs [run, end) of the job: in groups of NAV_LANES where the job allows, the rest one by one. */
static void run_some(job *j, long run, long end) {
  if (group_job(j) && end - run == NAV_LANES) {
    if (atomic_load(&j->sim->cancel)) {
      for (long r = run; r < end; ++r) j->status[r] = NAV_ERR_CANCELLED;
      return;
    }
    run_group(j, run);
    return;
  }
  for (long r = run; r < end; ++r) {
    if (atomic_load(&j->sim->cancel)) {
      j->status[r] = NAV_ERR_CANCELLED;
      continue;
    }
    (void)run_one(j, r, false);
  }
}

/* The next runs to take from the job: a group of NAV_LANES when the job runs groups. */
static long take_runs(job *j, long *end) {
  const long w = group_job(j) ? NAV_LANES : 1;
  const long run = atomic_fetch_add(&j->next_run, w);
  *end = run + w < j->run_end ? run + w : j->run_end;
  return run;
}

static int worker(void *arg) {
  job *j = arg;
  for (;;) {
    long end;
    const long run = take_runs(j, &end);
    if (run >= j->run_end) break;
    run_some(j, run, end);
  }
  return 0;
}

/* ------------------------------------------------------------------ statistics */

static nav_status add_values(const double *v, int64_t count, nav_stat_acc *acc) {
  nav_status st = NAV_OK;
  for (int64_t i = 0; i < count && st == NAV_OK; ++i) st = nav_stat_acc_add(acc, v[i]);
  return st;
}

/*
 * The reference at every receiver epoch of the run's time span (epoch_state), evaluated once by
 * the job's reference object for a Monte Carlo job with shared truth and a simulated receiver
 * (ins_gnss, ins_gnss_tight, gyro_free_gnss; not recorded fixes). Each run needs these states at
 * every epoch, outages included, and most epochs fall between the shared IMU-grid states (the
 * increment's interval, a difference of two times, is not exactly 1 / rate). An epoch whose state
 * cannot be evaluated is not kept (the run evaluates it and reports the failure as before).
 */
static nav_status shared_epoch_states(job *j, nav_truth *probe) {
  const nav_scene *sc = &j->sim->scene;
  const bool receiver = sc->navigation.scheme == NAV_SCHEME_INS_GNSS ||
                        sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT ||
                        sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS;
  if (!receiver || j->sim->fixes || !(j->gnss_cfg.update_rate_hz > 0.0)) return NAV_OK;
  nav_gnss_model *gm = NULL;
  nav_status st = nav_gnss_model_create(&j->gnss_cfg, &j->frame, sc->simulation.seed, 0, &gm);
  if (st != NAV_OK) return st;
  const double t_end = (double)j->n * j->dt;
  int64_t count = 0;
  while (nav_gnss_model_epoch_time_s(gm, count) <= t_end && count <= j->n)
    ++count;
  if (count > 0) {
    j->gnss_ts = malloc((size_t)count * sizeof *j->gnss_ts);
    j->gnss_t = malloc((size_t)count * sizeof *j->gnss_t);
  }
  if (j->gnss_ts && j->gnss_t) {
    for (int64_t e = 0; e < count; ++e) {
      const double t = nav_gnss_model_epoch_time_s(gm, e);
      j->gnss_t[e] = nav_truth_state(probe, t, &j->gnss_ts[e]) == NAV_OK ? t : NAN;
    }
    j->gnss_epochs = count;
  } else {
    /* Not kept (no memory): every run evaluates its epochs itself. */
    free(j->gnss_ts);
    free(j->gnss_t);
    j->gnss_ts = NULL;
    j->gnss_t = NULL;
  }
  nav_gnss_model_destroy(gm);
  return NAV_OK;
}

nav_status nav_sim_run(nav_sim *sim, const nav_sim_options *opts, nav_sim_summary *out) {
  job j;
  nav_status st = NAV_OK;
  nav_truth *probe = NULL;
  nav_stat_acc *acc = NULL;
  nav_thread *threads = NULL;
  nav_thread_call *calls = NULL;
  int started = 0;
  bool lock_ok = false;
  if (!sim || !opts || !out) return NAV_ERR_INVALID_ARG;
  memset(&j, 0, sizeof j);
  sim->last_error[0] = '\0';
  atomic_store(&sim->cancel, false);
  const nav_scene *sc = &sim->scene;
  j.sim = sim;
  j.opts = opts;
  j.ideal = opts->ideal;
  /* Ideal runs are identical: one is enough. */
  j.runs = opts->ideal ? 1 : sc->simulation.runs;
  j.smooth = sc->navigation.smoother && sc->navigation.scheme == NAV_SCHEME_INS_GNSS;
  if (sc->navigation.scheme == NAV_SCHEME_INS_GNSS || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
      sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT) {
    j.gm_states = sc->navigation.scheme == NAV_SCHEME_INS_GNSS_TIGHT ? false
                  : sc->navigation.scheme == NAV_SCHEME_INS_GNSS
                      ? (nav_ins_gnss_config_from_scene(sc).filter.states & NAV_FILTER_STATE_GNSS_POS_GM) != 0
                      : nav_gyrofree_gnss_config_from_scene(sc).filter.gnss_gm;
    char gmsg[200];
    st = nav_sim_gnss_config(sc, 1.0 / sc->imu.rate_hz, &j.gnss_cfg, gmsg, sizeof gmsg);
    if (st != NAV_OK) {
      snprintf(sim->last_error, sizeof sim->last_error, "GNSS outages: %s", gmsg);
      return st;
    }
    if (sc->gnss.file[0] != '\0' && !sim->fixes) {
      snprintf(sim->last_error, sizeof sim->last_error,
               "gnss.file: the recorded fixes of \"%.160s\" are not attached (nav_sim_set_gnss_fixes)", sc->gnss.file);
      return NAV_ERR_STATE;
    }
  }

  char msg[200];
  st = nav_truth_create_msg(sc, &probe, msg, sizeof msg);
  if (st != NAV_OK) {
    snprintf(sim->last_error, sizeof sim->last_error, "reference trajectory: %s", msg[0] ? msg : nav_status_str(st));
    return st;
  }
  j.n = nav_truth_sample_count(probe);
  const double dt = nav_truth_dt(probe);
  j.frame = nav_truth_frame(probe);
  j.dt = dt;
  /* Range hook: runs [r0, r1) only (a merge runs none). */
  const long r0 = sim->hook.active ? (sim->hook.r0 < j.runs ? sim->hook.r0 : j.runs) : 0;
  j.run_end = sim->hook.active ? (sim->hook.r1 < j.runs ? sim->hook.r1 : j.runs) : j.runs;
  j.out_stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  if (j.out_stride < 1) j.out_stride = 1;
  const int64_t epochs = j.n + 1;
  j.stats_stride = ((int64_t)j.runs * epochs + METRIC_MAX_VALUES - 1) / METRIC_MAX_VALUES;
  if (j.stats_stride < 1) j.stats_stride = 1;
  if (j.stats_stride < opts->stats_stride_min) j.stats_stride = opts->stats_stride_min;
  j.stats_per_run = j.n / j.stats_stride + 1;
  if (j.runs > 1 && j.run_end > r0 && j.n <= SHARED_TRUTH_MAX_SAMPLES) {
    /* Generate the truth once for all runs (the same numbers every run would compute): every
     * ideal increment, and the states of the samples whose errors are computed (shared_state;
     * all of them for the vertically aided free INS, which reads the reference every step). */
    const bool every_state = sc->navigation.aid_vertical && sc->navigation.scheme != NAV_SCHEME_INS_GNSS;
    j.ts_map = malloc((size_t)(j.n + 1) * sizeof *j.ts_map);
    int64_t n_ts = 0;
    if (j.ts_map)
      for (int64_t k = 0; k <= j.n; ++k) {
        const bool keep = every_state || k == 0 || k == j.n || k % j.out_stride == 0 ||
                          (k % j.stats_stride == 0 && k / j.stats_stride < j.stats_per_run);
        j.ts_map[k] = keep ? (int32_t)n_ts++ : -1;
      }
    j.shared_imu = malloc((size_t)j.n * sizeof *j.shared_imu);
    j.shared_ts = j.ts_map ? malloc((size_t)n_ts * sizeof *j.shared_ts) : NULL;
    /* The reference part of the errors beside each kept state, within SHARED_REF_MAX_BYTES (else
     * every run computes it at each of its error epochs, as a job without shared truth does). */
    if (j.shared_ts && (size_t)n_ts * sizeof *j.shared_ref <= SHARED_REF_MAX_BYTES)
      j.shared_ref = malloc((size_t)n_ts * sizeof *j.shared_ref);
    if (j.shared_imu && j.shared_ts) {
      st = nav_truth_state(probe, 0.0, &j.shared_ts[0]);
      if (st == NAV_OK && j.shared_ref) j.shared_ref[0] = nav_errors_ref_compute(&j.frame, &j.shared_ts[0]);
      int64_t k_fail = 0;
      for (int64_t k = 1; k <= j.n && st == NAV_OK; ++k) {
        k_fail = k;
        st = nav_truth_imu(probe, k, &j.shared_imu[k - 1]);
        if (st == NAV_OK && j.ts_map[k] >= 0) st = nav_truth_state(probe, (double)k * dt, &j.shared_ts[j.ts_map[k]]);
        if (st == NAV_OK && j.ts_map[k] >= 0 && j.shared_ref)
          j.shared_ref[j.ts_map[k]] = nav_errors_ref_compute(&j.frame, &j.shared_ts[j.ts_map[k]]);
        if (opts->progress && k % PROGRESS_EVERY == 0) {
          nav_progress p = {"truth", 0, 0.0, (double)k * dt};
          if (opts->progress(opts->user, &p) == NAV_STOP) st = NAV_ERR_CANCELLED;
        }
      }
      if (st != NAV_OK) {
        snprintf(sim->last_error, sizeof sim->last_error,
                 "reference trajectory (shared truth): %s in the state or ideal increment at t = %.6f s (sample %lld)",
                 nav_status_str(st), (double)k_fail * dt, (long long)k_fail);
        nav_truth_destroy(probe);
        goto cleanup;
      }
      st = shared_epoch_states(&j, probe);
      if (st != NAV_OK) {
        snprintf(sim->last_error, sizeof sim->last_error, "GNSS receiver model: %s", nav_status_str(st));
        nav_truth_destroy(probe);
        goto cleanup;
      }
    } else {
      free(j.shared_imu);
      free(j.shared_ts);
      free(j.ts_map);
      free(j.shared_ref);
      j.shared_ref = NULL;
      j.shared_imu = NULL;
      j.shared_ts = NULL;
      j.ts_map = NULL;
    }
  }
  nav_truth_destroy(probe);
  if ((sc->navigation.scheme == NAV_SCHEME_GYRO_FREE || sc->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS) &&
      j.runs > 1 && j.run_end > r0) {
    /* The ideal array increments are those of every run too: sampled once (sim_gyrofree.c). */
    st = nav_sim_gyrofree_truth_create(sc, &j.gf_truth, msg, sizeof msg);
    if (st != NAV_OK) {
      snprintf(sim->last_error, sizeof sim->last_error, "accelerometer array: %s",
               msg[0] ? msg : nav_status_str(st));
      goto cleanup;
    }
  }
  j.n_out = j.n / j.out_stride + 1 + (j.n % j.out_stride != 0 ? 1 : 0);
  if ((double)j.runs * (double)j.n_out * ENV_VALUES <= (double)STATS_MAX_VALUES)
    j.env = malloc((size_t)j.runs * (size_t)j.n_out * ENV_VALUES * sizeof *j.env);
  free(sim->envelope);
  sim->envelope = NULL;
  sim->envelope_count = 0;
  const size_t plane = (size_t)j.runs * (size_t)j.stats_per_run;
  j.metrics = malloc((size_t)N_METRICS * plane * sizeof *j.metrics);
  j.final = calloc((size_t)j.runs, sizeof *j.final);
  j.samples_done = calloc((size_t)j.runs, sizeof *j.samples_done);
  j.status = calloc((size_t)j.runs, sizeof *j.status);
  if (j.smooth) {
    j.sm_stride = ((int64_t)j.runs * j.n_out + SMOOTH_MAX_VALUES - 1) / SMOOTH_MAX_VALUES;
    if (j.sm_stride < 1) j.sm_stride = 1;
    j.sm_per_run = (j.n_out - 1) / j.sm_stride + 1;
    j.sm_metrics = malloc((size_t)(2 * N_METRICS) * (size_t)j.runs * (size_t)j.sm_per_run * sizeof *j.sm_metrics);
    j.sm_bytes = calloc((size_t)j.runs, sizeof *j.sm_bytes);
    if (!j.sm_metrics || !j.sm_bytes) {
      snprintf(sim->last_error, sizeof sim->last_error, "out of memory for the smoothed errors of %ld runs", j.runs);
      st = NAV_ERR_NO_MEMORY;
      goto cleanup;
    }
  }
  if (!j.metrics || !j.final || !j.samples_done || !j.status) {
    snprintf(sim->last_error, sizeof sim->last_error, "out of memory for %ld runs x %lld epochs", j.runs,
             (long long)j.stats_per_run);
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  if (!nav_mutex_init(&j.err_lock)) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  lock_ok = true;
  atomic_init(&j.next_run, r0 > 0 ? r0 : 1);
  atomic_init(&j.runs_done, 0);

  /* Workers start first and take runs 1..N-1; run 0 runs on this thread (records, progress),
   * then this thread joins the pool. */
  if (j.runs > 1) {
    int nthreads = opts->threads > 0 ? opts->threads : 1;
    if (nthreads > 256) nthreads = 256;
    if ((long)nthreads > j.runs) nthreads = (int)j.runs;
    threads = calloc((size_t)nthreads, sizeof *threads);
    calls = calloc((size_t)nthreads, sizeof *calls);
    if (!threads || !calls) {
      st = NAV_ERR_NO_MEMORY;
      goto cleanup;
    }
    for (int t = 1; t < nthreads; ++t) {
      if (!nav_thread_start(&threads[t], &calls[t], worker, &j)) break;
      ++started;
    }
  }
  if (r0 == 0 && j.run_end > 0) st = run_one(&j, 0, true);
  if (st != NAV_OK) atomic_store(&sim->cancel, true);
  if (j.runs > 1) {
    /* This thread works too, reporting progress between runs. */
    for (;;) {
      long end;
      const long run = take_runs(&j, &end);
      if (run >= j.run_end) break;
      run_some(&j, run, end);
      if (opts->progress) {
        nav_progress p = {"monte_carlo", run, (double)atomic_load(&j.runs_done) / (double)j.runs, j.n * dt};
        if (opts->progress(opts->user, &p) == NAV_STOP) atomic_store(&sim->cancel, true);
      }
    }
    for (int t = 1; t <= started; ++t) nav_thread_join(threads[t]);
    for (long r = 0; r < j.runs && st == NAV_OK; ++r) st = j.status[r];
  }
  if (sim->hook.active) {
    /* sim_partial.c takes the tables of this range, or fills in those of the others. */
    if (st != NAV_OK) goto cleanup;
    nav_sim_tables tb = {j.runs,  N_METRICS,      j.stats_per_run, j.n_out,        ENV_VALUES,
                         j.metrics, j.env,         j.final,         j.samples_done, j.status,
                         j.smooth ? j.sm_per_run : 0, j.sm_metrics, j.sm_bytes};
    st = sim->hook.tables(sim->hook.user, &tb);
    for (long r = 0; r < j.runs && st == NAV_OK; ++r) st = j.status[r];
    if (st != NAV_OK || !sim->hook.reduce) goto cleanup;
  }
  if (st != NAV_OK && st != NAV_ERR_CANCELLED) goto cleanup;

  /* Statistics over every run and stored epoch, reduced in run order (deterministic). A
   * cancelled job reduces what completed: run 0 up to where it stopped. */
  nav_sim_summary sum;
  memset(&sum, 0, sizeof sum);
  sum.partial = st == NAV_ERR_CANCELLED;
  long complete_runs = 0;
  for (long r = 0; r < j.runs; ++r)
    if (j.status[r] == NAV_OK) ++complete_runs;
  const long stat_runs = sum.partial ? 1 : j.runs;
  const int64_t used_epochs = sum.partial ? j.samples_done[0] / j.stats_stride + 1 : j.stats_per_run;
  nav_status sst = nav_stat_acc_create((size_t)stat_runs * (size_t)used_epochs, &acc);
  if (sst != NAV_OK) {
    st = sst;
    goto cleanup;
  }
  nav_stat *dst[N_METRICS] = {&sum.stats.pos_err_h_m, &sum.stats.pos_err_v_m, &sum.stats.vel_err_mps,
                              &sum.stats.att_err_rad, &sum.stats.yaw_err_rad};
  for (int m = 0; m < N_METRICS && sst == NAV_OK; ++m) {
    nav_stat_acc_reset(acc);
    for (long r = 0; r < stat_runs && sst == NAV_OK; ++r)
      sst = add_values(j.metrics + (size_t)m * plane + (size_t)r * (size_t)j.stats_per_run, used_epochs, acc);
    *dst[m] = nav_stat_acc_result(acc);
  }
  if (sst != NAV_OK) {
    snprintf(sim->last_error, sizeof sim->last_error, "error statistics: %s (non-finite navigation errors)",
             nav_status_str(sst));
    st = sst;
    goto cleanup;
  }
  if (j.smooth && !sum.partial) {
    /* Smoothed and forward errors at the output epochs, reduced in run order (deterministic). */
    nav_stat_acc_destroy(acc);
    acc = NULL;
    sst = nav_stat_acc_create((size_t)j.runs * (size_t)j.sm_per_run, &acc);
    const size_t sm_plane = (size_t)j.runs * (size_t)j.sm_per_run;
    nav_stat *sdst[2 * N_METRICS] = {
        &sum.stats_smoothed.pos_err_h_m,    &sum.stats_smoothed.pos_err_v_m,    &sum.stats_smoothed.vel_err_mps,
        &sum.stats_smoothed.att_err_rad,    &sum.stats_smoothed.yaw_err_rad,    &sum.stats_forward_out.pos_err_h_m,
        &sum.stats_forward_out.pos_err_v_m, &sum.stats_forward_out.vel_err_mps, &sum.stats_forward_out.att_err_rad,
        &sum.stats_forward_out.yaw_err_rad};
    for (int m = 0; m < 2 * N_METRICS && sst == NAV_OK; ++m) {
      nav_stat_acc_reset(acc);
      for (long r = 0; r < j.runs && sst == NAV_OK; ++r)
        sst = add_values(j.sm_metrics + (size_t)m * sm_plane + (size_t)r * (size_t)j.sm_per_run, j.sm_per_run, acc);
      *sdst[m] = nav_stat_acc_result(acc);
    }
    if (sst != NAV_OK) {
      snprintf(sim->last_error, sizeof sim->last_error, "smoothed error statistics: %s (non-finite smoothed errors)",
               nav_status_str(sst));
      st = sst;
      goto cleanup;
    }
    sum.has_smoothed = true;
    sum.smoothed_epochs = (int64_t)j.runs * j.sm_per_run;
    sum.smoothed_stride = j.sm_stride;
    for (long r = 0; r < j.runs; ++r)
      if ((size_t)j.sm_bytes[r] > sum.smoother_bytes_max) sum.smoother_bytes_max = (size_t)j.sm_bytes[r];
  }
  sum.runs = sum.partial ? complete_runs : j.runs;
  sum.imu_samples = j.samples_done[0];
  sum.duration_s = (double)j.samples_done[0] * dt;
  sum.final = j.final[0];
  sum.stats_epochs = (int64_t)stat_runs * used_epochs;
  sum.stats_stride = j.stats_stride;
  /* RMS over runs of the final errors. */
  {
    double s2[4] = {0.0, 0.0, 0.0, 0.0};
    long nf = 0;
    for (long r = 0; r < j.runs; ++r) {
      if (j.status[r] != NAV_OK) continue;
      const nav_epoch_errors *e = &j.final[r];
      s2[0] += e->pos_err_h_m * e->pos_err_h_m;
      s2[1] += e->pos_err_v_m * e->pos_err_v_m;
      s2[2] += e->vel_err_mps * e->vel_err_mps;
      s2[3] += e->att_err_rad * e->att_err_rad;
      ++nf;
    }
    if (nf > 0) {
      sum.final_rms.pos_err_h_m = sqrt(s2[0] / (double)nf);
      sum.final_rms.pos_err_v_m = sqrt(s2[1] / (double)nf);
      sum.final_rms.vel_err_mps = sqrt(s2[2] / (double)nf);
      sum.final_rms.att_err_rad = sqrt(s2[3] / (double)nf);
    }
  }
  /* Final errors per run (complete runs), in run order. */
  free(sim->finals);
  sim->finals = calloc((size_t)j.runs, sizeof *sim->finals);
  sim->finals_count = 0;
  if (sim->finals)
    for (long r = 0; r < j.runs; ++r)
      if (j.status[r] == NAV_OK) {
        sim->finals[sim->finals_count].run = r;
        sim->finals[sim->finals_count].err = j.final[r];
        sim->finals_count++;
      }
  /* Envelopes over complete runs, in run order. */
  if (j.env && !sum.partial) {
    sim->envelope = calloc((size_t)j.n_out, sizeof *sim->envelope);
    if (sim->envelope) {
      sim->envelope_count = (size_t)j.n_out;
      for (int64_t e = 0; e < j.n_out; ++e) {
        nav_sim_envelope_point *p = &sim->envelope[e];
        const int64_t k = e == j.n_out - 1 ? j.n : e * j.out_stride;
        p->t_s = (double)k * dt;
        double s2[5] = {0.0, 0.0, 0.0, 0.0, 0.0}, mean[3] = {0.0, 0.0, 0.0}, h2 = 0.0, hmax = 0.0;
        double sdm[3] = {0.0, 0.0, 0.0}, nees = 0.0;
        for (long r = 0; r < j.runs; ++r) {
          const double *v = j.env + ((int64_t)r * j.n_out + e) * ENV_VALUES;
          for (int q = 0; q < 5; ++q) s2[q] += v[q] * v[q];
          for (int q = 0; q < 3; ++q) mean[q] += v[q];
          for (int q = 0; q < 3; ++q) sdm[q] += v[5 + q];
          nees += v[8];
          const double h = hypot(v[0], v[1]);
          h2 += h * h;
          if (h > hmax) hmax = h;
        }
        const double nr = (double)j.runs;
        p->pos_rms_n_m = nav_vec3_make(sqrt(s2[0] / nr), sqrt(s2[1] / nr), sqrt(s2[2] / nr));
        p->pos_mean_n_m = nav_vec3_make(mean[0] / nr, mean[1] / nr, mean[2] / nr);
        p->pos_h_rms_m = sqrt(h2 / nr);
        p->pos_h_max_m = hmax;
        p->vel_rms_mps = sqrt(s2[3] / nr);
        p->att_rms_rad = sqrt(s2[4] / nr);
        p->pos_sd_reported_n_m = nav_vec3_make(sdm[0] / nr, sdm[1] / nr, sdm[2] / nr);
        p->nees9_mean = nees / nr;
      }
    }
  }
  *out = sum;

cleanup:
  nav_stat_acc_destroy(acc);
  free(threads);
  free(calls);
  if (lock_ok) nav_mutex_destroy(&j.err_lock);
  free(j.metrics);
  free(j.sm_metrics);
  free(j.sm_bytes);
  free(j.env);
  free(j.shared_imu);
  free(j.shared_ts);
  free(j.ts_map);
  free(j.shared_ref);
  free(j.gnss_ts);
  free(j.gnss_t);
  nav_sim_gyrofree_truth_destroy(j.gf_truth);
  free(j.final);
  free(j.samples_done);
  free(j.status);
  return st;
}
