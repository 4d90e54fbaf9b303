/**
 * @file nav_errors.h
 * @brief Navigation errors against the reference (the only stage that reads truth and
 *        estimates together) and their statistics.
 */
#ifndef NAV_ERRORS_H
#define NAV_ERRORS_H

#include <stddef.h>
#include <stdint.h>

#include "nav_export.h"
#include "nav_frames.h"
#include "nav_ins.h"
#include "nav_math.h"
#include "nav_status.h"
#include "nav_traj.h"

NAV_BEGIN_DECLS

/** Errors of one epoch; every difference is estimate minus truth, resolved in the local-level
 *  NED frame n at the true position (flat Earth: l). */
typedef struct nav_epoch_errors {
  double t_s;
  nav_vec3 pos_err_n_m;   /**< position error N, E, D [m] */
  double pos_err_h_m;     /**< horizontal: hypot(N, E) [m] */
  double pos_err_v_m;     /**< vertical: |D| [m] */
  nav_vec3 vel_err_n_mps; /**< velocity error N, E, D [m/s] */
  double vel_err_mps;     /**< |velocity error| [m/s] */
  double att_err_rad;     /**< rotation angle |log(C_true^T C_est)| [rad] */
  nav_euler euler_err;    /**< Euler-angle differences, each wrapped to (-pi, pi] [rad] */
} nav_epoch_errors;

/**
 * Compute the errors of @p est against @p truth at the same epoch, both given in the frame
 * @p fr of the scene. Euler-angle errors are differences of the local-level Euler angles
 * (each wrapped to (-pi, pi]). Leaf function: cannot fail.
 */
NAV_API nav_epoch_errors nav_errors_compute(const nav_frame *fr, const nav_traj_state *truth,
                                            const nav_ins_state *est);

/** The reference's part of nav_errors_compute, which depends on the reference state alone: its
 *  local-level view and Euler angles. A Monte Carlo job computes it once per reference epoch for
 *  every run. */
typedef struct nav_errors_ref {
  nav_local_view view; /**< nav_frame_view of the reference state */
  nav_euler euler;     /**< its local-level Euler angles */
} nav_errors_ref;

/** The reference part of the errors at @p truth (frame @p fr). Leaf function: cannot fail. */
NAV_API nav_errors_ref nav_errors_ref_compute(const nav_frame *fr, const nav_traj_state *truth);

/** nav_errors_compute with the reference part @p ref of @p truth given (from
 *  nav_errors_ref_compute of the same @p fr and @p truth): the same values, bit for bit. */
NAV_API nav_epoch_errors nav_errors_compute_ref(const nav_frame *fr, const nav_traj_state *truth,
                                                const nav_errors_ref *ref, const nav_ins_state *est);

/** RMS, maximum and 95th percentile of a non-negative metric over epochs (and runs). */
typedef struct nav_stat {
  double rms;
  double max;
  double p95; /**< linear interpolation between order statistics (Hyndman-Fan type 7) */
} nav_stat;

/** Accumulates one metric; stores values for the percentile. */
typedef struct nav_stat_acc nav_stat_acc;

/** @param capacity maximum number of values that will be added. */
NAV_API NAV_NODISCARD nav_status nav_stat_acc_create(size_t capacity, nav_stat_acc **out);
NAV_API void nav_stat_acc_destroy(nav_stat_acc *acc);
/** Add a value; NAV_ERR_OUT_OF_RANGE when full, NAV_ERR_NUMERIC when not finite. */
NAV_API NAV_NODISCARD nav_status nav_stat_acc_add(nav_stat_acc *acc, double value);
/** nav_stat_acc_add(acc[i], values[i]) for i = 0 .. n-1 in order, stopping at the first error
 *  (returned); one call for the metrics of an epoch. */
NAV_API NAV_NODISCARD nav_status nav_stat_acc_add_each(nav_stat_acc *const acc[], const double values[], int n);
NAV_API size_t nav_stat_acc_count(const nav_stat_acc *acc);
/** Forget every value added (keeps the capacity). */
NAV_API void nav_stat_acc_reset(nav_stat_acc *acc);
/** Statistics of the values added so far (reorders the stored values; adding may continue). */
NAV_API nav_stat nav_stat_acc_result(nav_stat_acc *acc);

NAV_END_DECLS

#endif /* NAV_ERRORS_H */
