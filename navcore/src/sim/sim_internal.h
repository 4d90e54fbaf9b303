/* Private to navcore's sim module. */
#ifndef NAV_SIM_INTERNAL_H
#define NAV_SIM_INTERNAL_H

#include <stddef.h>

#include "navcore/nav_sensor_config.h"
#include "navcore/nav_sim.h"

/** Set the message returned by nav_sim_last_error(). */
void nav_sim_set_error(nav_sim *sim, const char *msg);

/* ------------------------------------------------------------------ gyro-free scheme (sim_gyrofree.c) */

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "navcore/nav_ins.h"
#include "navcore/nav_scene.h"

/** Ideal accelerometer-array increments of a scene, shared read-only by the runs of a job. */
typedef struct nav_sim_gyrofree_truth nav_sim_gyrofree_truth;

/**
 * Sample the scene's array truth once (k = 1..n) for every run of a job. *out = NULL with NAV_OK
 * when the table would exceed its memory cap (the runs then sample their own).
 * @return NAV_OK; the layout's or the trajectory's error (@p msg says which).
 */
nav_status nav_sim_gyrofree_truth_create(const nav_scene *sc, nav_sim_gyrofree_truth **out, char *msg,
                                         size_t msg_size);
void nav_sim_gyrofree_truth_destroy(nav_sim_gyrofree_truth *t);

/** The gyro-free navigation of one run: array truth -> array errors -> gyro-free INS. */
typedef struct nav_sim_gyrofree nav_sim_gyrofree;

/**
 * Set up run @p run: the layout of sc->array, its error model (none when @p ideal or no term is
 * on), and the gyro-free INS with @p ins (the scene's strapdown configuration), the initial state
 * @p s0 and the true initial rate plus the run's initial-rate error (none when @p ideal).
 * @param[in] shared  shared ideal increments, or NULL: the run samples its own truth
 */
nav_status nav_sim_gyrofree_create(const nav_scene *sc, const nav_sim_gyrofree_truth *shared, long run,
                                   bool ideal, const nav_ins_config *ins, const nav_ins_state *s0,
                                   nav_sim_gyrofree **out, char *msg, size_t msg_size);
void nav_sim_gyrofree_destroy(nav_sim_gyrofree *g);

/**
 * Advance over interval k (t_(k-1), t_k]. @p equiv receives the gyro-free INS's equivalent IMU
 * increment (dtheta, dv) of the interval (the "measured IMU" of the record).
 * @return NAV_OK or the failing stage's status (nav_sim_gyrofree_last_error() says why).
 */
nav_status nav_sim_gyrofree_step(nav_sim_gyrofree *g, int64_t k, nav_imu_increment *equiv);
/** Navigation state after the last step (borrowed). */
const nav_ins_state *nav_sim_gyrofree_state(const nav_sim_gyrofree *g);
const char *nav_sim_gyrofree_last_error(const nav_sim_gyrofree *g);

#include "navcore/nav_ins_gnss.h"

/** gyro_free_gnss: apply one GNSS fix (update, feedback). NAV_ERR_INVALID_ARG for gyro_free. */
nav_status nav_sim_gyrofree_update(nav_sim_gyrofree *g, const nav_ins_gnss_fix *fix);
/** gyro_free_gnss: the filter covariance (n x n, borrowed) and *n; NULL for gyro_free. */
const double *nav_sim_gyrofree_cov(const nav_sim_gyrofree *g, size_t *n);

/** Append to @p out the receiver outages of gnss.constellation.min_satellites_for_fix: every
 *  receiver epoch with fewer visible satellites (sim_gnss_sat.c). NAV_OK when not configured. */
nav_status nav_sim_gnss_visibility_outages(const nav_scene *sc, double dt_s, nav_gnss_model_config *out, char *msg,
                                           size_t msg_size);
/* nav_sim_gnss_config: public, navcore/nav_sim.h. */

/* Raw GNSS measurements (sim_gnss_raw.c): public, navcore/nav_sim.h (nav_sim_gnss_raw_*). */

#endif /* NAV_SIM_INTERNAL_H */
