/**
 * @file nav_sim.h
 * @brief Orchestration of one simulation run: truth -> sensors -> navigation -> errors.
 *
 * The run is synchronous (style.md section 7). Records at the scene's output rate go to a
 * callback, so the caller decides what to keep or write; statistics are accumulated inside.
 * Example:
 * @code
 *   nav_sim *sim = NULL;
 *   if (nav_sim_create(&scene, &sim) == NAV_OK) {
 *     nav_sim_options o = nav_sim_options_default();
 *     o.ideal = true;
 *     nav_sim_summary sum;
 *     if (nav_sim_run(sim, &o, &sum) == NAV_OK) printf("%g m\n", sum.final.pos_err_h_m);
 *     nav_sim_destroy(sim);
 *   }
 * @endcode
 */
#ifndef NAV_SIM_H
#define NAV_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "nav_errors.h"
#include "nav_export.h"
#include "nav_ins.h"
#include "nav_ins_gnss.h"
#include "nav_scene.h"
#include "nav_status.h"
#include "nav_traj.h"
#include "nav_truth.h"

NAV_BEGIN_DECLS

/** Explicit callback verdicts (never "any non-zero value"). */
typedef enum nav_callback_result { NAV_CONTINUE = 0, NAV_STOP = 1 } nav_callback_result;

/** Progress of a run. */
typedef struct nav_progress {
  const char *stage;   /**< static string, e.g. "run" */
  long run;            /**< Monte Carlo run index */
  double fraction;     /**< 0..1 of the whole job */
  double sim_time_s;   /**< simulated time reached in the current run */
} nav_progress;

typedef nav_callback_result (*nav_progress_fn)(void *user, const nav_progress *p);

/** One output epoch: pointers valid only during the callback. */
typedef struct nav_sim_record {
  long run;
  const nav_frame *frame; /**< the scene frame the states are expressed in */
  const nav_traj_state *truth;
  const nav_ins_state *nav;
  const nav_epoch_errors *err;
  /** IMU increments of the interval ending at this epoch: ideal and as measured (with the
   *  scene's sensor errors). NULL at t = 0. Their difference is the simulated sensor error. */
  const nav_imu_increment *imu_ideal;
  const nav_imu_increment *imu_measured;
  /** smoothed_record only (else NULL): sqrt(diag P) of the RTS-smoothed and of the forward
   *  filter at this epoch, in the filter's state order (nav_filter.h: NAV_FILTER_IDX_DR position
   *  N/E/D [m], NAV_FILTER_IDX_PHI attitude [rad], ...). */
  const double *sd_smoothed;
  const double *sd_forward;
} nav_sim_record;

typedef nav_callback_result (*nav_record_fn)(void *user, const nav_sim_record *r);

typedef struct nav_sim_options {
  bool ideal;               /**< perfect sensors and perfect initial state (one run) */
  int threads;              /**< threads for Monte Carlo runs (>= 1); results do not depend on it */
  nav_progress_fn progress; /**< may be NULL; called on the running thread at a bounded rate */
  nav_record_fn record;     /**< may be NULL; called at each output epoch */
  void *user;               /**< passed to both callbacks */
  /** May be NULL: sees every run (any thread) and its output-epoch errors, e.g. the requirement
   *  evaluator's nav_req_evaluator_observer() (nav_requirements.h). */
  const nav_run_observer *observer;
  /** May be NULL. Scenes with navigation.smoother (ins_gnss): called for run 0 only, on the
   *  caller's thread, after that run's RTS backward pass (nav_smoother.h), once per output
   *  epoch in time order with the SMOOTHED navigation state (nav) and its errors (err); truth
   *  and frame as for @c record, the IMU increments NULL. NAV_STOP cancels the job. */
  nav_record_fn smoothed_record;
  /** 0 or 1: the error statistics (summary stats) take every IMU epoch, as memory allows
   *  (NAV_SIM_METRIC_MAX_VALUES); N > 1: at most every N-th one. A caller that reads only the
   *  final errors and the output epochs (navstudio's live preview) passes the output stride and
   *  skips the reference state and the errors at the other IMU epochs. */
  int64_t stats_stride_min;
  /** Runs stepped together: 0 (the default) lets a Monte Carlo job of the loosely coupled
   *  INS/GNSS scheme step four runs at once with their strapdown in vector lanes; 1 steps one run
   *  at a time. The results are the same bits either way (as for any thread count). */
  int lanes;
} nav_sim_options;

NAV_API nav_sim_options nav_sim_options_default(void);

/** Statistics pooled over every run and epoch (epochs at the IMU rate, every stats_stride-th
 *  one when runs x epochs would exceed NAV_SIM_METRIC_MAX_VALUES, or as
 *  nav_sim_options.stats_stride_min asks). */
typedef struct nav_sim_stats {
  nav_stat pos_err_h_m, pos_err_v_m, vel_err_mps, att_err_rad, yaw_err_rad;
} nav_sim_stats;

/** Final errors of one Monte Carlo run. */
typedef struct nav_sim_run_final {
  long run;
  nav_epoch_errors err;
} nav_sim_run_final;

typedef struct nav_sim_summary {
  long runs;
  int64_t imu_samples;     /**< per run */
  double duration_s;       /**< simulated duration actually covered */
  nav_epoch_errors final;  /**< errors at the last epoch (run 0) */
  nav_epoch_errors final_rms; /**< RMS over runs of the final errors (norm fields only) */
  nav_sim_stats stats;
  int64_t stats_epochs;    /**< epochs entering the statistics */
  int64_t stats_stride;    /**< every stats_stride-th IMU epoch enters the statistics */
  bool partial;            /**< the run was stopped early (cancel / callback) */
  /** Scenes with navigation.smoother and a complete job: statistics of the RTS-smoothed errors
   *  pooled over every run and output epoch (every smoothed_stride-th output epoch when runs x
   *  output epochs would exceed 4e5 values), reduced in run order like @c stats. The matching
   *  forward figures over the same epochs are in stats_forward_out. */
  bool has_smoothed;
  nav_sim_stats stats_smoothed;
  nav_sim_stats stats_forward_out; /**< forward (filtered) errors at the same output epochs */
  int64_t smoothed_epochs;         /**< values per metric entering stats_smoothed */
  int64_t smoothed_stride;         /**< every smoothed_stride-th output epoch of each run */
  size_t smoother_bytes_max;       /**< largest smoother memory of one run (records + results) */
} nav_sim_summary;

/** Bounds of the Monte Carlo engine's tables (what a campaign keeps in memory; navsim bench's
 *  memory projection uses them): values per error metric kept for the statistics over runs and
 *  epochs (a uniform subsample, every stats_stride-th epoch, beyond this), and values kept for
 *  the per-epoch envelopes (runs x output epochs x 9; no envelopes beyond this). */
#define NAV_SIM_METRIC_MAX_VALUES 2000000LL
#define NAV_SIM_ENV_MAX_VALUES 4000000LL
/** Bytes kept at most for the reference's part of the errors (nav_errors_ref) beside the
 *  reference states a Monte Carlo job shares between its runs. */
#define NAV_SIM_SHARED_REF_MAX_BYTES ((size_t)64 << 20)

/** Monte Carlo envelope at one output epoch: statistics over runs (numerics.md T6.6). */
typedef struct nav_sim_envelope_point {
  double t_s;
  nav_vec3 pos_rms_n_m;  /**< RMS over runs of the position error, per N/E/D component [m] */
  nav_vec3 pos_mean_n_m; /**< mean over runs of the position error [m] */
  double pos_h_rms_m;    /**< RMS over runs of the horizontal error [m] */
  double pos_h_max_m;    /**< largest horizontal error over runs [m] */
  double vel_rms_mps;    /**< RMS over runs of |velocity error| [m/s] */
  double att_rms_rad;    /**< RMS over runs of the attitude error angle [rad] */
  /** INS/GNSS only (else 0): mean over runs of the filter's reported position sigma N/E/D [m] */
  nav_vec3 pos_sd_reported_n_m;
  /** INS/GNSS only: NEES of the 9 navigation error states (position, velocity, attitude in the
   *  phi-angle convention) averaged over runs; consistent filter: M nees_mean ~ chi2(9 M). */
  double nees9_mean;
} nav_sim_envelope_point;

typedef struct nav_sim nav_sim;

/** Create a simulation of a validated scene (copied). */
NAV_API NAV_NODISCARD nav_status nav_sim_create(const nav_scene *scene, nav_sim **out);
NAV_API void nav_sim_destroy(nav_sim *sim);

/**
 * Run the scene.
 * @return NAV_OK; NAV_ERR_CANCELLED when stopped by a callback or nav_sim_request_cancel (the
 *         summary then covers the part that ran and is marked partial); NAV_ERR_NUMERIC when the
 *         navigation diverged to non-finite values; NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_run(nav_sim *sim, const nav_sim_options *opts, nav_sim_summary *out);

/**
 * Per-output-epoch statistics over the Monte Carlo runs of the last nav_sim_run (output rate of
 * the scene, epochs 0..count-1). Borrowed: valid until the next nav_sim_run or destroy. NULL and
 * *count = 0 when there is no complete run (or runs x epochs exceeds 4e6 values).
 */
NAV_API const nav_sim_envelope_point *nav_sim_envelope(const nav_sim *sim, size_t *count);

/** One epoch of a covariance analysis: predicted one-sigma errors (NED, phi-angle). */
typedef struct nav_cov_point {
  double t_s;
  nav_vec3 pos_sd_n_m;   /**< position sigma N/E/D [m] */
  double pos_h_sd_m;     /**< sqrt(sigma_N^2 + sigma_E^2) [m] */
  nav_vec3 vel_sd_n_mps; /**< velocity sigma N/E/D [m/s] */
  nav_vec3 att_sd_rad;   /**< attitude sigma about N/E/D [rad] */
} nav_cov_point;

typedef nav_callback_result (*nav_cov_fn)(void *user, const nav_cov_point *p);

/**
 * Covariance analysis of the scene (numerics.md 6.6): the error covariance of its navigation
 * scheme propagated along the reference trajectory with the filter's linear model (15 states,
 * or more as nav_ins_gnss_config_from_scene() decides), GNSS updates at the receiver's epochs
 * outside the outages for ins_gnss, and no random draws. @p fn receives the output epochs.
 * WGS-84 scenes only.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (flat Earth scene); NAV_ERR_CANCELLED when @p fn stops;
 *         the filter's statuses.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_covariance(nav_sim *sim, nav_cov_fn fn, void *user);

/** An output epoch of nav_sim_covariance_total(): the filter's point and the total model's. */
typedef nav_callback_result (*nav_cov_total_fn)(void *user, const nav_cov_point *filter, const nav_cov_point *total);

/**
 * nav_sim_covariance() (the same @p filter points, bit for bit) and, in the same pass, the
 * total model the requirements are predicted from (nav_budget.h, nav_req_predict_scene()): for
 * free_ins and ins_gnss, the filter plus the truth's scale factors the filter does not estimate
 * as consider states, carried as their sensitivity beside the filter (docs/estimate-speed.md;
 * the same covariance as the budget's larger filter, to rounding); for the other schemes the
 * filter's own points. WGS-84 scenes, second-order discretisation when there are consider states.
 * @return as nav_sim_covariance(); NAV_ERR_INVALID_ARG also for ins_gnss with PVT fixes
 *         (gnss.constellation.fixes: pvt), whose budget model is not the filter's.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_covariance_total(nav_sim *sim, nav_cov_total_fn fn, void *user);

/**
 * Attach recorded GNSS fixes (scene gnss.file) to a simulation: the INS/GNSS and gyro-free/GNSS
 * runs then apply these fixes instead of the receiver model's, each at the IMU epoch nearest its
 * time of validity (as the model's fixes), except those inside the scene's outages
 * (gnss.outages, segment-tied outages). The filter uses each fix's own sigmas (floored as any
 * fix: nav_ins_gnss_config.pos_sd_floor_m); the receiver's error model is not used. Every Monte
 * Carlo run sees the same fixes.
 * @param[in] fixes  @p n fixes in the scene time base (t_s from the scene epoch), times strictly
 *                   increasing, all finite; copied
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL sim, NULL fixes with n > 0, times not increasing, a
 *         non-finite value or a sigma not positive: nav_sim_last_error() names the fix);
 *         NAV_ERR_NO_MEMORY. n = 0 detaches.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_set_gnss_fixes(nav_sim *sim, const nav_ins_gnss_fix *fixes, size_t n);

/** The scene of a simulation (borrowed). */
NAV_API const nav_scene *nav_sim_scene(const nav_sim *sim);

/**
 * Final errors of every run of the last nav_sim_run, in run order (borrowed; valid until the
 * next nav_sim_run or destroy). NULL and *count = 0 when there is none.
 */
NAV_API const nav_sim_run_final *nav_sim_finals(const nav_sim *sim, size_t *count);

/** Ask a running nav_sim_run to stop at the next sample. Thread-safe. */
NAV_API void nav_sim_request_cancel(nav_sim *sim);

/** Detailed message of the last failure on this handle ("" if none). */
NAV_API const char *nav_sim_last_error(const nav_sim *sim);

/**
 * The GNSS receiver configuration the simulation uses for @p sc: the scene's receiver model with
 * its outages, those tied to segments (gnss_visible: false) and those of too few visible
 * satellites added. Programs that write what the receiver produced (gnss.csv, the KF-GINS
 * export) call it so that they describe the very receiver the run simulated.
 * @param[in]  sc    validated scene
 * @param[in]  dt_s  IMU sample interval [s] (1 / imu.rate_hz)
 * @param[out] out   the configuration (written on NAV_OK)
 * @param[out] msg   on failure what is wrong (may be NULL)
 * @return NAV_OK, NAV_ERR_INVALID_ARG, NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_sim_gnss_config(const nav_scene *sc, double dt_s, nav_gnss_model_config *out,
                                                     char *msg, size_t msg_size);

/** Pseudoranges and range rates of the visible satellites (gnss.constellation), the receiver of
 *  the tightly coupled scheme and of the PVT fixes (docs/ins-gnss-tight.md section 2). Public so
 *  that exports (navsim run --export rinex) regenerate run @p run's raw data exactly. */
typedef struct nav_sim_gnss_raw nav_sim_gnss_raw;

/** Run @p run's receiver: constellation of the scene, initial clock and inter-system bias drawn
 *  from the run's streams (none when @p ideal: then no clock and no noise either).
 *  @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_NO_MEMORY; as nav_gnss_constellation_build(). */
NAV_API NAV_NODISCARD nav_status nav_sim_gnss_raw_create(const nav_scene *sc, uint64_t run, bool ideal,
                                                         nav_sim_gnss_raw **out);
/** Accepts NULL. */
NAV_API void nav_sim_gnss_raw_destroy(nav_sim_gnss_raw *g);
/** The measurements at the true state @p ts (frame @p fr, time ts->t_s, increasing between calls;
 *  the simulation calls it at every receiver epoch that has a fix, in time order, and so must a
 *  caller that wants the run's very draws); @p ep points into @p g's buffers until the next call.
 *  @return NAV_OK; NAV_ERR_INVALID_ARG. */
NAV_API NAV_NODISCARD nav_status nav_sim_gnss_raw_measure(nav_sim_gnss_raw *g, const nav_frame *fr,
                                                          const nav_traj_state *ts, nav_ins_gnss_raw_epoch *ep);
/** The true receiver clock (bias c dt_r [m], drift [m/s]) at the last measurement. */
NAV_API void nav_sim_gnss_raw_clock(const nav_sim_gnss_raw *g, double *bias_m, double *drift_mps);

NAV_END_DECLS

#endif /* NAV_SIM_H */
