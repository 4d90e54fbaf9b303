/*
 * navsim run --export kfgins: run 0's inputs and reference in the KF-GINS (i2Nav) text formats
 * that navsim replay and KF-GINS read, in the sub-directory kfgins/ of the result directory:
 *
 *   IMU.txt      t, dtheta x/y/z [rad], dvel x/y/z [m/s]: every measured increment run 0's
 *                navigation used, plus a zero increment at t = 0 (the initial epoch, whose
 *                interval starts before the run; a reader must not step with it)
 *   GNSS.txt     t, lat, lon [deg], h [m], sigma N/E/D [m], vN vE vD [m/s], sigma vN/vE/vD [m/s]
 *                (13 columns): every fix run 0's filter applied, at the receiver's rate, with the
 *                sigmas the filter used; outages left out
 *   truth.nav    week 0, t, lat, lon, h, vN vE vD, roll pitch yaw [deg]: the reference at every
 *                IMU epoch from t = 0
 *   init.nav     one .nav row: run 0's initial navigation state (reference plus the drawn
 *                initial errors; the reference itself with --ideal), for navsim replay --init
 *   kf-gins.yaml a KF-GINS configuration: the files, initial state (the row of init.nav), P0,
 *                IMU noise model and lever arm of the scene's filter
 *
 * Time base: t = scene time [s] (0 at the start of the scene), GPS week 0; numbers with %.17g
 * (read back exactly). The increments and fixes are regenerated from the scene's seed exactly as
 * the simulation makes run 0's (the increment of every output epoch is compared bit for bit
 * with the one the navigation received; a difference fails the run).
 */
#ifndef NAVSIM_KFGINS_OUT_H
#define NAVSIM_KFGINS_OUT_H

#include <stdbool.h>
#include <stddef.h>

#include "navcore/nav_results.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"

typedef struct navsim_kfgins navsim_kfgins;

/* NULL when the scene can be exported, else why not (a static string): INS/GNSS schemes with an
 * IMU on the WGS-84 Earth only. */
const char *navsim_kfgins_unsupported(const nav_scene *scene);

/* Create kfgins/ in @p rd and open its files. @p msg (may be NULL) says what failed. */
nav_status navsim_kfgins_begin(const nav_scene *scene, bool ideal, nav_resultdir *rd, navsim_kfgins **out, char *msg,
                               size_t msg_cap);

/* Called with every output record (records of runs other than 0 are ignored): writes the
 * increments, fixes and reference rows up to the record's epoch. */
nav_status navsim_kfgins_record(navsim_kfgins *x, const nav_sim_record *r, char *msg, size_t msg_cap);

/* After a complete run: write kf-gins.yaml and close every file. NAV_ERR_STATE when run 0's
 * records did not reach the end. Frees @p x whatever the outcome. */
nav_status navsim_kfgins_end(navsim_kfgins *x, char *msg, size_t msg_cap);

/* Close and free without finishing (failure paths); accepts NULL. */
void navsim_kfgins_destroy(navsim_kfgins *x);

#endif /* NAVSIM_KFGINS_OUT_H */
