/**
 * @file nav_requirements.h
 * @brief Accuracy requirements of a scene and their verdicts: what the user needs ("5 m
 *        horizontal at the end of each GNSS outage"), a streaming evaluator fed with the errors
 *        of every Monte Carlo run, and the verdict (value against limit) per requirement.
 *
 * A requirement is a metric (a non-negative scalar computed per epoch from nav_epoch_errors), a
 * statistic over runs and epochs, and a limit in the user's unit. Semantics (over all Monte
 * Carlo runs and all output epochs unless stated):
 *  - rms:        sqrt(mean of metric^2);
 *  - max:        the largest value;
 *  - p95:        95th percentile, nearest rank (the smallest value with at least 95 % of the
 *                values at or below it);
 *  - at_time:    RMS over runs of the metric at the output epoch nearest time_s (the earlier one
 *                on a tie); not evaluated (NAV_REQ_NA_TIME_OUTSIDE) when time_s lies outside the
 *                run's epochs [first, last] by more than half the spacing of the two epochs at that
 *                end (the nearest epoch would then not be "at" time_s);
 *  - outage_end: for each GNSS outage [t0, t1), the RMS over runs of the metric at the last
 *                output epoch inside it; the value is the largest of those (each outage is
 *                reported in nav_requirement_verdict.outage_value); not evaluated
 *                (NAV_REQ_NA_NO_OUTAGE) when there is no outage;
 *  - cep50/cep95 (horizontal_position only): radius containing 50 / 95 % of the horizontal
 *                errors (nearest rank of the horizontal error over runs and epochs).
 * Metrics: horizontal_position = hypot(dN, dE); vertical_position = |dD|; position_3d = |dr|;
 * velocity = |dv| (3-D); roll_pitch = max(|roll err|, |pitch err|); yaw = |yaw err| (Euler
 * differences wrapped to (-pi, pi]).
 *
 * Quantiles (p95, cep50, cep95) are exact while the values fit NAV_REQ_EXACT_BUDGET doubles
 * (shared by the quantile requirements of one evaluator); beyond that every value goes into a
 * logarithmic histogram of relative bin width NAV_REQ_HIST_REL_WIDTH over [1e-12, 1e12] SI and
 * the reported quantile is the geometric centre of its bin clamped to the exact min/max: relative
 * error below NAV_REQ_HIST_REL_WIDTH / 2. Both are independent of the order in which runs arrive.
 * Sums (rms, at_time, outage_end) are kept per run and reduced in run order at the end, so the
 * verdicts are bit-identical for any number of threads.
 *
 * Threading: nav_req_run_begin/add/end may be called from several threads at once, each on its
 * own nav_req_run (nav_req_run_end locks); create/finish/destroy from one thread.
 */
#ifndef NAV_REQUIREMENTS_H
#define NAV_REQUIREMENTS_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_export.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/* nav_errors.h (which needs nav_scene.h, which includes this header) defines it. */
struct nav_epoch_errors;

/** Most requirements in a scene. */
#define NAV_SCENE_MAX_REQUIREMENTS 32
/** Longest requirement id [bytes, with the NUL]: ids are [A-Za-z0-9_.-]{1,63}. */
#define NAV_REQ_ID_MAX 64
/** Most GNSS outages an evaluator reports per outage_end requirement. */
#define NAV_REQ_MAX_OUTAGES 32
/** Values kept exactly for the quantile statistics (shared by the evaluator's quantile requirements). */
#define NAV_REQ_EXACT_BUDGET 4000000L
/** Relative bin width of the quantile histogram used beyond the budget. */
#define NAV_REQ_HIST_REL_WIDTH 1e-3

/** What is measured per epoch. */
typedef enum nav_req_metric {
  NAV_REQ_HORIZONTAL_POSITION = 0, /**< hypot(dN, dE) [m] */
  NAV_REQ_VERTICAL_POSITION = 1,   /**< |dD| [m] */
  NAV_REQ_POSITION_3D = 2,         /**< |dr| [m] */
  NAV_REQ_VELOCITY = 3,            /**< |dv| [m/s] */
  NAV_REQ_ROLL_PITCH = 4,          /**< max(|d roll|, |d pitch|) [rad] */
  NAV_REQ_YAW = 5                  /**< |d yaw| [rad] */
} nav_req_metric;
#define NAV_REQ_METRIC_COUNT 6

/** How the metric is reduced over runs and epochs. */
typedef enum nav_req_statistic {
  NAV_REQ_RMS = 0,
  NAV_REQ_MAX = 1,
  NAV_REQ_P95 = 2,
  NAV_REQ_AT_TIME = 3,
  NAV_REQ_OUTAGE_END = 4,
  NAV_REQ_CEP50 = 5,
  NAV_REQ_CEP95 = 6
} nav_req_statistic;
#define NAV_REQ_STATISTIC_COUNT 7

/** Unit of the limit (and of the reported value). */
typedef enum nav_req_unit {
  NAV_REQ_UNIT_M = 0,
  NAV_REQ_UNIT_CM = 1,
  NAV_REQ_UNIT_KM = 2,
  NAV_REQ_UNIT_MPS = 3,  /**< "m/s" */
  NAV_REQ_UNIT_CMPS = 4, /**< "cm/s" */
  NAV_REQ_UNIT_DEG = 5,
  NAV_REQ_UNIT_ARCMIN = 6,
  NAV_REQ_UNIT_ARCSEC = 7,
  NAV_REQ_UNIT_MRAD = 8,
  NAV_REQ_UNIT_RAD = 9
} nav_req_unit;
#define NAV_REQ_UNIT_COUNT 10

/** Physical quantity of a metric or unit. */
typedef enum nav_req_quantity {
  NAV_REQ_LENGTH = 0,
  NAV_REQ_SPEED = 1,
  NAV_REQ_ANGLE = 2
} nav_req_quantity;

/** Why a verdict was not evaluated (nav_requirement_verdict.na_reason). */
typedef enum nav_req_na_reason {
  NAV_REQ_NA_NONE = 0,          /**< evaluated */
  NAV_REQ_NA_NO_DATA = 1,       /**< no epoch entered the statistic (no scored epoch; no epoch inside any outage) */
  NAV_REQ_NA_NO_OUTAGE = 2,     /**< outage_end: the run has no GNSS outage */
  NAV_REQ_NA_TIME_OUTSIDE = 3,  /**< at_time: time_s lies outside the run's epochs (span_t0_s .. span_t1_s) */
  NAV_REQ_NA_NOT_PREDICTED = 4, /**< nav_req_predict: no covariance points, or the statistic is not
                                     predictable from sigmas */
  NAV_REQ_NA_NO_GNSS_FIX = 5    /**< set by callers (navsim replay): no GNSS fix was applied */
} nav_req_na_reason;

/** One requirement (scene file: requirements[i]). */
typedef struct nav_requirement {
  char id[NAV_REQ_ID_MAX];     /**< [A-Za-z0-9_.-]{1,63}, unique within the scene */
  nav_req_metric metric;
  nav_req_statistic statistic;
  double limit;                /**< > 0, in @c unit */
  nav_req_unit unit;           /**< must measure the metric's quantity */
  double time_s;               /**< at_time only (required there) [s] */
} nav_requirement;

/** Verdict of one requirement. */
typedef struct nav_requirement_verdict {
  char id[NAV_REQ_ID_MAX];
  nav_req_metric metric;
  nav_req_statistic statistic;
  double limit;  /**< user units */
  nav_req_unit unit;
  double value;  /**< user units; NaN when nothing was evaluated (no epoch, no outage) */
  bool pass;     /**< value <= limit; false without a value (not evaluated is never a pass) */
  bool evaluated; /**< false: no data for this statistic (e.g. outage_end without an outage); then
                       pass is false and na_reason says why */
  nav_req_na_reason na_reason; /**< NAV_REQ_NA_NONE when evaluated */
  double span_t0_s; /**< at_time: the first epoch of the run(s) [s] (NaN: no epoch) */
  double span_t1_s; /**< at_time: the last epoch of the run(s) [s] (NaN: no epoch) */
  long samples;  /**< values that entered the statistic */
  double at_time_s; /**< at_time: the epoch used [s]; NAV_REQ_NA_TIME_OUTSIDE: the time asked [s] */
  int outage_count; /**< outage_end: outages evaluated (each below) */
  double outage_t0_s[NAV_REQ_MAX_OUTAGES];  /**< outage start [s] */
  double outage_t1_s[NAV_REQ_MAX_OUTAGES];  /**< outage end [s] */
  /** the epoch scored [s]: the last epoch fed to the evaluator inside the outage (simulations:
   *  the last output epoch; navsim replay also feeds the errors just before the fix that ends a
   *  GNSS gap, 1 ulp before that fix's epoch) */
  double outage_end_t_s[NAV_REQ_MAX_OUTAGES];
  double outage_value[NAV_REQ_MAX_OUTAGES];   /**< RMS over runs there, user units (NaN: no epoch inside) */
} nav_requirement_verdict;

/* ---------------------------------------------------------------- names and units */

/** Scene-file names: "horizontal_position", "rms", "m/s", ... ("unknown" for a bad value). */
NAV_API const char *nav_req_metric_name(nav_req_metric m);
NAV_API const char *nav_req_statistic_name(nav_req_statistic s);
NAV_API const char *nav_req_unit_name(nav_req_unit u);
/** Name -> enum; false when @p name is not one of the names. */
NAV_API bool nav_req_metric_from_name(const char *name, nav_req_metric *out);
NAV_API bool nav_req_statistic_from_name(const char *name, nav_req_statistic *out);
NAV_API bool nav_req_unit_from_name(const char *name, nav_req_unit *out);
/** SI value of 1 @p u (m, m/s or rad): cm -> 0.01, arcmin -> pi / 10800, ... */
NAV_API double nav_req_unit_to_si(nav_req_unit u);
NAV_API nav_req_quantity nav_req_unit_quantity(nav_req_unit u);
NAV_API nav_req_quantity nav_req_metric_quantity(nav_req_metric m);
/** The metric's value at one epoch, SI (m, m/s, rad). */
NAV_API double nav_req_metric_value(nav_req_metric m, const struct nav_epoch_errors *e);
/** Whether @p s is a quantile statistic (p95, cep50, cep95). */
NAV_API bool nav_req_statistic_is_quantile(nav_req_statistic s);

/** One line of text for a reason ("the run has no GNSS outage"); "" for NAV_REQ_NA_NONE. */
NAV_API const char *nav_req_na_reason_text(nav_req_na_reason r);

/** Problem callback: @p path like "requirements[2].unit" (same signature as nav_scene_issue_fn). */
typedef void (*nav_req_issue_fn)(void *user, const char *path, const char *message);

/**
 * Check a list of requirements (ids, uniqueness, limit > 0, unit matching the metric, cep only
 * for horizontal_position, time_s finite and >= 0 for at_time). Called by nav_scene_validate.
 * @return NAV_OK, or NAV_ERR_INVALID_ARG when a problem was reported.
 */
NAV_API NAV_NODISCARD nav_status nav_requirements_validate(const nav_requirement *reqs, int count,
                                                           nav_req_issue_fn report, void *user);

struct nav_scene;
/**
 * Check the requirements of a simulation scene against what its run will hold, so that each can
 * be evaluated: at_time needs time_s within [0, trajectory.duration_s]; outage_end needs a GNSS
 * outage that starts within the run (scheme ins_gnss; gnss.outages or segments with
 * gnss_visible: false, as nav_req_scene_outages). Not part of nav_scene_validate: a scene used as
 * the filter configuration of navsim replay states requirements on recorded data, whose span and
 * gaps only the data knows (navcore_io applies this check to scene files with a trajectory).
 * @return NAV_OK, or NAV_ERR_INVALID_ARG when a problem was reported.
 */
NAV_API NAV_NODISCARD nav_status nav_requirements_check_scene(const struct nav_scene *scene, nav_req_issue_fn report,
                                                              void *user);

/* ---------------------------------------------------------------- streaming evaluator */

/** A time interval [t0_s, t1_s) without GNSS. */
typedef struct nav_req_interval {
  double t0_s;
  double t1_s;
} nav_req_interval;

typedef struct nav_req_evaluator nav_req_evaluator;
typedef struct nav_req_run nav_req_run; /**< accumulator of one run */

/**
 * Create an evaluator for @p count requirements (copied), @p runs Monte Carlo runs (indices
 * 0..runs-1) and the GNSS outages @p outages (copied; used by outage_end).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (invalid requirements, runs < 1); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_req_evaluator_create(const nav_requirement *reqs, int count, long runs,
                                                          const nav_req_interval *outages, int n_outages,
                                                          nav_req_evaluator **out);

struct nav_scene;
/**
 * The evaluator for a scene: its requirements, simulation.runs (1 when @p ideal) and its GNSS
 * outages (gnss.outages plus the segments with gnss_visible: false, as the simulation applies
 * them; none when the scheme is not ins_gnss).
 */
NAV_API NAV_NODISCARD nav_status nav_req_evaluator_create_for_scene(const struct nav_scene *scene, bool ideal,
                                                                    nav_req_evaluator **out);
/** The GNSS outages of @p scene as the simulation applies them (*n <= cap). */
NAV_API NAV_NODISCARD nav_status nav_req_scene_outages(const struct nav_scene *scene, nav_req_interval *out,
                                                       int cap, int *n);
NAV_API void nav_req_evaluator_destroy(nav_req_evaluator *ev);
/** Number of requirements. */
NAV_API int nav_req_evaluator_count(const nav_req_evaluator *ev);

/** Start run @p run (0 <= run < runs; each run at most once). */
NAV_API NAV_NODISCARD nav_status nav_req_run_begin(nav_req_evaluator *ev, long run, nav_req_run **out);
/** One output epoch of the run (epochs in increasing time). */
NAV_API NAV_NODISCARD nav_status nav_req_run_add(nav_req_run *r, const struct nav_epoch_errors *e);
/** Finish the run and merge it into the evaluator (thread-safe); frees @p r. A run that is not
 *  ended (cancelled) does not count. */
NAV_API NAV_NODISCARD nav_status nav_req_run_end(nav_req_evaluator *ev, nav_req_run *r);
/** Discard a run without merging it. */
NAV_API void nav_req_run_discard(nav_req_run *r);

/**
 * Verdicts of every requirement from the runs ended so far (in requirement order).
 * @param[out] out array of at least nav_req_evaluator_count() verdicts
 * @return NAV_OK; NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_req_evaluator_finish(nav_req_evaluator *ev, nav_requirement_verdict *out);

/** Whether every verdict passes (true for none). */
NAV_API bool nav_req_all_pass(const nav_requirement_verdict *v, int count);

/**
 * An observer for the simulation's nav_sim_options.observer: feeds every run and output epoch of
 * nav_sim_run into @p ev.
 */
typedef struct nav_run_observer {
  /** Called when run @p run starts (any thread); returns its context (NULL: not observed). */
  void *(*begin)(void *user, long run);
  /** Each output epoch of the run, in time order, on the run's thread. */
  void (*epoch)(void *ctx, const struct nav_epoch_errors *e);
  /** The run ended; @p complete false when it was cancelled or failed. */
  void (*end)(void *user, void *ctx, bool complete);
  void *user;
} nav_run_observer;

/** An observer that feeds @p ev (valid while @p ev lives). */
NAV_API nav_run_observer nav_req_evaluator_observer(nav_req_evaluator *ev);

/* ---------------------------------------------------------------- prediction from covariance */

struct nav_cov_point;
/**
 * Predicted verdicts from a covariance analysis (nav_sim_covariance(): per output epoch the
 * one-sigma errors), errors taken as zero-mean Gaussian and N, E, D uncorrelated:
 *  - rms: sqrt(mean over epochs of E[metric^2]) (the expected Monte Carlo RMS); at_time and each
 *    outage_end: sqrt(E[metric^2]) at that epoch, with E[h^2] = sN^2 + sE^2, E[v^2] = sD^2,
 *    E[|dr|^2] = sN^2 + sE^2 + sD^2, E[|dv|^2] likewise, yaw: the attitude sigma about D,
 *    roll_pitch: sqrt(s_att_N^2 + s_att_E^2) (an upper bound of E[max(roll^2, pitch^2)]);
 *  - p95, cep50, cep95: the quantile of the mixture over epochs of |N(0, sD^2)| (vertical), of
 *    |N(0, s_att_D^2)| (yaw) or of the horizontal radius of N(0, diag(sN^2, sE^2)) (horizontal;
 *    its CDF by quadrature), solved by bisection to 1e-9 relative;
 *  - max, and p95 of position_3d, velocity and roll_pitch: not predicted (evaluated = false,
 *    value NaN, pass false, NAV_REQ_NA_NOT_PREDICTED); at_time outside the points' span and
 *    outage_end without an outage are not evaluated as in the evaluator.
 * @p outages as for nav_req_evaluator_create. @p out: @p count verdicts (samples = epochs used).
 */
NAV_API NAV_NODISCARD nav_status nav_req_predict(const nav_requirement *reqs, int count, const struct nav_cov_point *pts,
                                                 size_t npts, const nav_req_interval *outages, int n_outages,
                                                 nav_requirement_verdict *out);
/**
 * nav_req_predict for a scene: runs its covariance analysis (that of nav_sim_covariance plus the
 * truth's scale factors the filter does not estimate, as consider states: nav_budget.h; WGS-84
 * scenes, free_ins or ins_gnss; for gyro_free_gnss nav_sim_covariance() of its filter) with its
 * GNSS outages. @p out: scene->n_requirements verdicts.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (flat Earth, gyro_free); the simulation's statuses.
 */
NAV_API NAV_NODISCARD nav_status nav_req_predict_scene(const struct nav_scene *scene, nav_requirement_verdict *out);
/**
 * Whether nav_req_predict_scene's covariance analysis for @p scene is exactly nav_sim_covariance()
 * of its scene (gyro_free_gnss, ins_gnss_tight: no consider states), so that a caller that already
 * ran it can pass its points to nav_req_predict_scene_points() instead of running it again.
 */
NAV_API bool nav_req_predict_scene_uses_sim_covariance(const struct nav_scene *scene);
/**
 * nav_req_predict_scene with the points of nav_sim_covariance() for @p scene already computed
 * (every point it gave, in order; only where nav_req_predict_scene_uses_sim_covariance()): the same
 * checks, outages and verdicts as nav_req_predict_scene, without running the analysis again.
 * @return as nav_req_predict_scene; NAV_ERR_INVALID_ARG for the other schemes.
 */
NAV_API NAV_NODISCARD nav_status nav_req_predict_scene_points(const struct nav_scene *scene,
                                                              const struct nav_cov_point *pts, size_t npts,
                                                              nav_requirement_verdict *out);

/**
 * nav_req_predict, nav_req_predict_scene and nav_req_predict_scene_points with @p threads
 * threads (1 or less: the caller's alone) sharing the quadrature of the quantile statistics (p95,
 * cep50, cep95): each bisection step's per-epoch CDFs are computed by the threads and added in
 * epoch order by the caller, so the verdicts are bit-identical for any thread count.
 */
NAV_API NAV_NODISCARD nav_status nav_req_predict_threads(const nav_requirement *reqs, int count,
                                                         const struct nav_cov_point *pts, size_t npts,
                                                         const nav_req_interval *outages, int n_outages, int threads,
                                                         nav_requirement_verdict *out);
/** nav_req_predict_scene with @p threads (nav_req_predict_threads). */
NAV_API NAV_NODISCARD nav_status nav_req_predict_scene_threads(const struct nav_scene *scene, int threads,
                                                               nav_requirement_verdict *out);
/** nav_req_predict_scene_points with @p threads (nav_req_predict_threads). */
NAV_API NAV_NODISCARD nav_status nav_req_predict_scene_points_threads(const struct nav_scene *scene,
                                                                      const struct nav_cov_point *pts, size_t npts,
                                                                      int threads, nav_requirement_verdict *out);
/**
 * nav_req_predict_scene from the total points of nav_sim_covariance_total() for @p scene, already
 * computed (every point it gave, in order): the same checks and outages, and the verdicts of
 * nav_req_predict_scene to rounding for free_ins and ins_gnss (there the total model's consider
 * part is carried beside the filter instead of in a second, larger filter; docs/estimate-speed.md
 * gives the measured differences), bit for bit for the schemes of
 * nav_req_predict_scene_uses_sim_covariance(). @p threads as nav_req_predict_threads.
 * @return as nav_req_predict_scene.
 */
NAV_API NAV_NODISCARD nav_status nav_req_predict_scene_total_points_threads(const struct nav_scene *scene,
                                                                            const struct nav_cov_point *pts,
                                                                            size_t npts, int threads,
                                                                            nav_requirement_verdict *out);

NAV_END_DECLS

#endif /* NAV_REQUIREMENTS_H */
