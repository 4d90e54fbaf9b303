/**
 * @file nav_gyrofree.h
 * @brief Gyro-free strapdown INS: navigation from a distributed accelerometer array alone.
 *
 * Algorithm (numerics.md 1.5; the paper's second main idea). Per sample interval k the array
 * delivers the increments dA_i = int A_i dt (nav_array.h). Applying the pseudo-inverse H^+ to
 * E1.23 integrated over the interval gives
 *
 *     [dv_k ; w_k - w_(k-1)] = H^+ (dA - int c(omega) dt),
 *
 * i.e. the specific-force increment dv_k = int f dt and the angular-rate change, which is exact:
 * the array measures omega_dot, whose integral over the interval is the rate difference. So the
 * rate at the sample instants needs no integration rule at all; what does need one is
 * - dtheta_k = int omega dt over the interval (the attitude increment), and
 * - int c(omega) dt (the centripetal term; it uses the integrated omega, numerics.md 1.5 item 5;
 *   for the cube layout it affects only f, and for a general layout also omega_dot, which makes
 *   w_k implicit: solved by fixed-point iteration).
 * Both use an interpolant of omega over the interval (::nav_gyrofree_rate_interp):
 * - LINEAR: omega linear between w_(k-1) and w_k (dtheta by the trapezoid rule): local error
 *   O(dt^3), global O(dt^2);
 * - QUADRATIC (default): omega quadratic through w_(k-2), w_(k-1), w_k, i.e. dtheta =
 *   dt (5 w_k + 8 w_(k-1) - w_(k-2)) / 12 (Adams-Moulton 3): local O(dt^4), global O(dt^3), the
 *   order of the high-order strapdown algorithm it feeds. The first interval has no w_(k-2) and
 *   uses LINEAR (a one-off O(dt^3) error, the same order as the global error).
 * The centripetal integral is taken by 3-point Gauss-Legendre on the interpolant (exact for the
 * quartic c(omega(t))).
 *
 * (dtheta_k, dv_k) then drive the existing strapdown mechanization (::nav_ins, any algorithm and
 * Earth model it supports), which does coning, sculling, velocity and position: attitude is not
 * integrated twice. The navigation never sees truth: the initial state, including the initial
 * angular rate (which a gyro-free INS must be given; the array cannot observe it), comes from the
 * caller, e.g. perfect from ::nav_array_truth in closure tests, or zero for a body at rest.
 *
 * Memory is allocated only by nav_gyrofree_create(). One thread per object.
 *
 * Example:
 * @code
 *   nav_gyrofree_config cfg = nav_gyrofree_config_default();      // cube, r = 0.1 m, flat Earth
 *   nav_gyrofree *gf = NULL;
 *   if (nav_gyrofree_create(&cfg, &s0, w0_ib_b_rps, &gf) == NAV_OK) {
 *     for (k = 1; k <= n; ++k)
 *       if (nav_gyrofree_step(gf, &inc[k]) != NAV_OK) { puts(nav_gyrofree_last_error(gf)); break; }
 *     const nav_ins_state *s = nav_gyrofree_get_state(gf);
 *     nav_gyrofree_destroy(gf);
 *   }
 * @endcode
 */
#ifndef NAV_GYROFREE_H
#define NAV_GYROFREE_H

#include "nav_array.h"
#include "nav_export.h"
#include "nav_ins.h"
#include "nav_math.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** How omega(t) is interpolated inside an interval (see the file description). */
typedef enum nav_gyrofree_rate_interp {
  NAV_GYROFREE_RATE_LINEAR = 0,   /**< trapezoidal: global error O(dt^2) */
  NAV_GYROFREE_RATE_QUADRATIC = 1 /**< three-point (Adams-Moulton 3): global error O(dt^3) */
} nav_gyrofree_rate_interp;

typedef struct nav_gyrofree_config {
  nav_accel_array array; /**< the layout (copied) */
  nav_ins_config ins;    /**< the strapdown mechanization fed with (dtheta, dv) */
  nav_gyrofree_rate_interp rate_interp;
  /**
   * Cap on the fixed-point iterations for the implicit rate when H^+ does not annihilate c(omega)
   * (general layouts). The contraction factor is about dt |omega| |H^+_w c'|; the iteration stops
   * when the update is below 1e-13 |w_k| (+1e-300). For the cube layout one pass suffices.
   */
  int max_iterations;
} nav_gyrofree_config;

typedef struct nav_gyrofree nav_gyrofree;

/** Defaults: cube layout with r = 0.1 m, nav_ins_config_default() with the high-order algorithm
 *  (b), quadratic rate interpolation, 20 iterations. */
NAV_API nav_gyrofree_config nav_gyrofree_config_default(void);

/**
 * Create a gyro-free INS.
 * @param[in]  cfg          configuration (copied); the layout is checked as by
 *                          nav_array_geometry_compute()
 * @param[in]  initial      initial navigation state in F (as for nav_ins_create())
 * @param[in]  w_ib_b0_rps  initial angular rate omega_ib_b at initial->t_s, body axes [rad/s]
 * @param[out] out          the new object; destroy with nav_gyrofree_destroy()
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, bad enum or iteration cap, non-finite rate, bad
 *         layout, or what nav_ins_create() rejects); NAV_ERR_NUMERIC (singular layout);
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_create(const nav_gyrofree_config *cfg,
                                                     const nav_ins_state *initial, nav_vec3 w_ib_b0_rps,
                                                     nav_gyrofree **out);
/** Destroy; accepts NULL. */
NAV_API void nav_gyrofree_destroy(nav_gyrofree *gf);

/**
 * Advance by one array interval.
 * @param[in] inc  the array increments; inc->n_sensors must equal the layout's N
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, sensor-count mismatch, dt <= 0); NAV_ERR_NUMERIC
 *         (non-finite increments or result); NAV_ERR_NOT_CONVERGED (implicit rate iteration);
 *         whatever nav_ins_step() returns. On any error the state is left as it was and
 *         nav_gyrofree_last_error() says why.
 */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_step(nav_gyrofree *gf, const nav_array_increment *inc);

/** Current navigation state in F (borrowed; valid until the next non-const call or destroy). */
NAV_API const nav_ins_state *nav_gyrofree_get_state(const nav_gyrofree *gf);

/** Current angular-rate estimate omega_ib_b [rad/s] at the time of the state. */
NAV_API nav_vec3 nav_gyrofree_rate(const nav_gyrofree *gf);

/**
 * The equivalent IMU increment (dtheta, dv) of the last step, as fed to the strapdown
 * mechanization (borrowed; valid until the next non-const call or destroy). Before the first
 * step its k is 0 and the increments are zero.
 */
NAV_API const nav_imu_increment *nav_gyrofree_last_increment(const nav_gyrofree *gf);

/** The array geometry in use (borrowed; valid until destroy). */
NAV_API const nav_array_geometry *nav_gyrofree_geometry(const nav_gyrofree *gf);

/**
 * Closed-loop compensation of the array's sensor errors (nav_gyrofree_gnss.h): from the next step
 * on, @p beta * dt is subtracted from y = H^+ dA, i.e. beta[0..2] is the estimated specific-force
 * bias [m/s^2] and beta[3..5] the estimated angular-acceleration bias [rad/s^2], both the
 * combinations H^+ b of the per-sensor biases b. Replaces any previous compensation.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_NUMERIC (non-finite value, nothing changed).
 */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_set_compensation(nav_gyrofree *gf, const double beta[6]);

/**
 * Closed-loop feedback: replace the navigation state (when @p state is not NULL) and subtract
 * the estimated rate error @p dw_ib_b_rps (estimate - true, body axes [rad/s]) from the rate and
 * its history (the quadratic interpolant moves as a whole).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL gf); NAV_ERR_NUMERIC (non-finite rate); what
 *         nav_ins_set_state() returns (the rate is then not changed).
 */
NAV_API NAV_NODISCARD nav_status nav_gyrofree_correct(nav_gyrofree *gf, const nav_ins_state *state,
                                                      nav_vec3 dw_ib_b_rps);

/** The strapdown INS inside (borrowed; e.g. for nav_ins_get_ned()). NULL for NULL. */
NAV_API const nav_ins *nav_gyrofree_ins(const nav_gyrofree *gf);

/** Detailed message of the last failure ("" if none). Borrowed; valid until the next non-const
 *  call or destroy. */
NAV_API const char *nav_gyrofree_last_error(const nav_gyrofree *gf);

NAV_END_DECLS

#endif /* NAV_GYROFREE_H */
