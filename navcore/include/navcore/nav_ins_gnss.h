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
#include "nav_gnss_sat.h"
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
  /**
   * Tightly coupled updates (nav_ins_gnss_update_raw()): innovation gating. A scalar pseudorange
   * or range rate whose normalised innovation squared y^2 / S exceeds gate_chi2 (chi-square, one
   * degree of freedom) is not applied. Default on, 10.83 (probability 0.999 of passing a
   * measurement that fits the model).
   */
  bool gate;
  double gate_chi2;
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

/** One satellite's raw measurements at an epoch (tightly coupled scheme). */
typedef struct nav_ins_gnss_sat_meas {
  const nav_gnss_orbit *sat; /**< the satellite's orbit (borrowed for the call) */
  bool has_pr;               /**< a pseudorange is given */
  double pr_m;               /**< pseudorange P = rho + c dt_r (+ ISB for GLONASS) + e [m] */
  bool has_rr;               /**< a range rate (Doppler times -wavelength) is given */
  double rr_mps;             /**< range rate rho_dot + c dt_r' + e [m/s] */
} nav_ins_gnss_sat_meas;

/** The raw measurements of one receiver epoch. */
typedef struct nav_ins_gnss_raw_epoch {
  double t_s;     /**< time of validity (the IMU's time base) [s] */
  double t_gps_s; /**< the same instant as GPS time (seconds since the GPS epoch), for the orbits */
  int n;          /**< satellites, 0..NAV_GNSS_MAX_SATS */
  const nav_ins_gnss_sat_meas *sats;
  double pr_sd_m;    /**< pseudorange noise, 1 sigma [m], > 0 */
  double rr_sd_mps;  /**< range-rate noise, 1 sigma [m/s], > 0 */
} nav_ins_gnss_raw_epoch;

/** What an epoch's tightly coupled update did. */
typedef struct nav_ins_gnss_raw_result {
  int pr_used, rr_used; /**< scalar pseudorange / range-rate updates applied */
  int rejected;         /**< measurements gated out (nav_ins_gnss_config.gate) */
} nav_ins_gnss_raw_result;

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

/**
 * Apply one GNSS fix whose position (and velocity) errors are correlated between the axes, as a
 * least-squares PVT's are: R is the given full covariance instead of fix->pos_sd_m /
 * fix->vel_sd_mps (which are ignored). Otherwise as nav_ins_gnss_update().
 * @param[in] pos_cov_ned_m2 3 x 3 position covariance, north/east/down, row-major [m^2]
 * @param[in] vel_cov_ned_m2s2 3 x 3 velocity covariance [m^2/s^2]; used when fix->has_vel
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_NUMERIC (R or S not positive definite);
 *         NAV_ERR_STATE (before the first step).
 */
NAV_API NAV_NODISCARD nav_status nav_ins_gnss_update_cov(nav_ins_gnss *x, const nav_ins_gnss_fix *fix,
                                                         const double pos_cov_ned_m2[9],
                                                         const double vel_cov_ned_m2s2[9]);

/**
 * Tightly coupled update (docs/ins-gnss-tight.md): one scalar update per pseudorange and range
 * rate, in the order given (pseudorange before range rate of each satellite), each tested against
 * the gate first, then one closed-loop feedback of the INS errors. The filter must have the
 * receiver-clock states (nav_filter_config.states & NAV_FILTER_STATE_RX_CLOCK); with
 * NAV_FILTER_STATE_RX_ISB, GLONASS pseudoranges also see the inter-system bias state (without it
 * the clock is that of whichever system is measured). Works with any number of satellites.
 * @param[out] res what was applied (may be NULL)
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, bad sigmas, no clock states); NAV_ERR_STATE (before
 *         the first step); NAV_ERR_NUMERIC (non-finite measurement); the filter's status.
 */
NAV_API NAV_NODISCARD nav_status nav_ins_gnss_update_raw(nav_ins_gnss *x, const nav_ins_gnss_raw_epoch *ep,
                                                         nav_ins_gnss_raw_result *res);

/** Receiver clock estimate of the tightly coupled filter: bias c dt_r [m] and drift [m/s]; zeros
 *  without the clock states. Either pointer may be NULL. */
NAV_API void nav_ins_gnss_clock(const nav_ins_gnss *x, double *bias_m, double *drift_mps);

/** Tightly coupled: scalar measurements applied and gated out so far. */
NAV_API void nav_ins_gnss_raw_counts(const nav_ins_gnss *x, long *used, long *rejected);

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
