/**
 * @file nav_ins_gnss.h
 * @brief Loosely coupled INS/GNSS in closed loop: strapdown mechanization + error-state EKF +
 *        feedback, driven by measured IMU increments and GNSS fixes only (never by truth).
 *
 * Used by the simulation (nav_sim) and by the replay of recorded data alike. Per IMU interval:
 * the current bias estimates are subtracted from the raw increments, the INS steps, and the
 * filter predicts with the compensated mean specific force and rate. Per GNSS fix (processed at
 * the IMU epoch it belongs to): position update, then velocity update if the fix has one, then
 * closed-loop feedback of the estimated errors into the INS state and the bias estimates, and a
 * reset of the error state (numerics.md 6.5). WGS-84 only. One thread per object.
 */
#ifndef NAV_INS_GNSS_H
#define NAV_INS_GNSS_H

#include <stdbool.h>

#include "nav_export.h"
#include "nav_filter.h"
#include "nav_frames.h"
#include "nav_ins.h"
#include "nav_scene.h"
#include "nav_smoother.h"
#include "nav_status.h"
#include "nav_truth.h"

NAV_BEGIN_DECLS

typedef struct nav_ins_gnss_config {
  nav_ins_config ins;       /**< mechanization (earth_model must be NAV_EARTH_WGS84) */
  nav_filter_config filter; /**< error-state filter */
  nav_vec3 r_ba_b_m;        /**< GNSS antenna relative to the IMU, body axes [m] */
  double pos_sd_floor_m;    /**< lower bound of the position sigma used in R [m] (default 1e-3) */
  double vel_sd_floor_mps;  /**< lower bound of the velocity sigma used in R [m/s] (default 1e-3) */
  /**
   * Optional RTS smoother recorder (nav_smoother.h), BORROWED: not owned, must outlive the
   * object, one nav_ins_gnss per smoother. When set, create calls nav_smoother_begin(), every
   * step nav_smoother_step() and every update nav_smoother_update(); mark output epochs with
   * nav_smoother_mark() and run the backward pass with nav_smoother_run(). NULL (default): none.
   */
  nav_smoother *smoother;
} nav_ins_gnss_config;

/** One GNSS measurement as the integration consumes it. */
typedef struct nav_ins_gnss_fix {
  double t_s;          /**< time of validity [s] (same time base as the IMU increments) */
  nav_geodetic pos;    /**< antenna position */
  nav_vec3 pos_sd_m;   /**< 1-sigma N/E/D [m] used for R (> 0 after flooring) */
  bool has_vel;        /**< false: position-only fix */
  nav_vec3 v_n_mps;    /**< antenna velocity, NED [m/s] */
  nav_vec3 vel_sd_mps; /**< 1-sigma N/E/D [m/s] */
} nav_ins_gnss_fix;

typedef struct nav_ins_gnss nav_ins_gnss;

/**
 * The filter's sensor model taken from a scene's IMU and GNSS error models (white noise
 * densities, GM and random-walk bias processes, turn-on biases as the initial bias sigma,
 * initial errors as P0, GNSS GM error states when tau > 10 update intervals), with floors that
 * keep P0 positive definite for perfect sensors.
 */
NAV_API nav_ins_gnss_config nav_ins_gnss_config_from_scene(const nav_scene *scene);

/** Create with the initial navigation state in F = ECEF. */
NAV_API NAV_NODISCARD nav_status nav_ins_gnss_create(const nav_ins_gnss_config *cfg, const nav_ins_state *initial,
                                                     nav_ins_gnss **out);
NAV_API void nav_ins_gnss_destroy(nav_ins_gnss *x);

/** One IMU interval of raw (uncompensated) increments. */
NAV_API NAV_NODISCARD nav_status nav_ins_gnss_step(nav_ins_gnss *x, const nav_imu_increment *raw);

/** Apply one GNSS fix at the current epoch (call right after the step it belongs to). */
NAV_API NAV_NODISCARD nav_status nav_ins_gnss_update(nav_ins_gnss *x, const nav_ins_gnss_fix *fix);

/** Current navigation state in F = ECEF (borrowed). */
NAV_API const nav_ins_state *nav_ins_gnss_state(const nav_ins_gnss *x);
/** Current bias estimates (subtracted from the raw increments). */
NAV_API void nav_ins_gnss_biases(const nav_ins_gnss *x, nav_vec3 *b_g_rps, nav_vec3 *b_a_mps2);
/** The current scale-factor estimates (zero unless the filter has scale-factor states):
 *  the INS compensates raw increments as (raw - b dt) / (1 + s), per axis. Either pointer may be NULL. */
NAV_API void nav_ins_gnss_scale_factors(const nav_ins_gnss *x, nav_vec3 *s_g, nav_vec3 *s_a);
/** The filter (borrowed, for P, innovations and NIS). */
NAV_API const nav_filter *nav_ins_gnss_filter(const nav_ins_gnss *x);

/** The strapdown INS inside (borrowed; e.g. for nav_ins_get_ned()). NULL for NULL. */
NAV_API const nav_ins *nav_ins_gnss_ins(const nav_ins_gnss *x);
/** Number of GNSS fixes applied so far. */
NAV_API long nav_ins_gnss_updates(const nav_ins_gnss *x);
/** Last failure message ("" if none). */
NAV_API const char *nav_ins_gnss_last_error(const nav_ins_gnss *x);

/** A filter-side INS state (geodetic position, NED velocity, q_b_n) as the WGS-84 strapdown
 *  state in ECEF (the scene frame F = e), at time @p t_s: what the closed loop feeds back and
 *  how the smoother's states are compared with a reference. Pure, thread-safe. */
NAV_API nav_ins_state nav_ins_gnss_state_ecef(const nav_filter_ins_state *s, double t_s);

NAV_END_DECLS

#endif /* NAV_INS_GNSS_H */
