/* Private to navcore: the consider states of a covariance analysis (consider.c). */
#ifndef NAV_CONSIDER_INTERNAL_H
#define NAV_CONSIDER_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>

#include "navcore/nav_filter.h"
#include "navcore/nav_scene.h"

/**
 * Scale-factor variance of the scene's truth per axis (sd^2 + fixed^2; zero when the term is
 * off), gyro (@p accel false) or accelerometer.
 */
nav_vec3 nav_consider_sf_var(const nav_scene *sc, bool accel);

/**
 * The budget's total model (nav_budget.h): the navigation filter @p cr plus, when the truth has
 * scale factors the filter does not estimate, those scale factors as consider states (random
 * constants with the truth's sigma, at least 1e-9; never updated). Writes that filter's
 * configuration into @p c (cr itself when there are none).
 * @return true when there are consider states.
 */
bool nav_consider_config(const nav_scene *sc, const nav_filter_config *cr, nav_filter_config *c);

/**
 * The consider part of a covariance analysis, propagated beside the navigation filter instead
 * of as a second, larger filter (docs/estimate-speed.md). The scale factors s are random
 * constants that the filter's gains never touch, so the error of the navigation states is
 * e = e0 + S s, with e0 the error the filter's own covariance P describes and S (n x 6) the
 * sensitivity to s; the consider filter's covariance of the navigation states is then exactly
 * P + S Pss S^T. S follows the steps of the navigation filter:
 *   covariance step (second order, A = F T of the consider layout):
 *     S <- Phi_xx S + Phi_xs = S + U + A_xx U / 2,  U = A_xx S + A_xs
 *   update with the filter's gain K = P H_x^T (H_x P H_x^T + R)^-1:
 *     S <- (I - K H_x) S - K H_s = S - K (H_x S + H_s).
 * The decimated covariance steps use the interval sums of the filter (ekf.c struct pending).
 */
typedef struct nav_consider nav_consider;

/**
 * Set up for the navigation filter configuration @p cr (second-order discretisation only).
 * *out = NULL with NAV_OK when the scene has no consider states.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (Van Loan discretisation); NAV_ERR_NO_MEMORY.
 */
nav_status nav_consider_create(const nav_scene *sc, const nav_filter_config *cr, nav_consider **out);
void nav_consider_destroy(nav_consider *c);

/** The navigation filter's nav_filter_predict(nav, dt) (a covariance step when it makes one). */
void nav_consider_predict(nav_consider *c, const nav_filter_nav *nav, double dt_s);
/** The navigation filter's nav_filter_flush(). */
void nav_consider_flush(nav_consider *c);

/**
 * The GNSS position (@p vel false) or velocity update of the navigation filter, whose covariance
 * before the update is @p P (after its flush; nav_consider_flush() first), with R = diag(@p r).
 * @return NAV_OK; NAV_ERR_NUMERIC when H P H^T + R is not positive definite.
 */
nav_status nav_consider_update(nav_consider *c, const double *P, const nav_filter_nav *nav, nav_vec3 l_ba_b_m,
                               nav_vec3 r, bool vel);

/** Diagonal of P + S Pss S^T for the first @p m navigation states (P the filter's, n x n). */
void nav_consider_total_diag(const nav_consider *c, const double *P, size_t m, double *diag);

#endif /* NAV_CONSIDER_INTERNAL_H */
