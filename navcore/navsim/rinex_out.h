/*
 * navsim run --export rinex: run 0's raw GNSS data (the pseudoranges and range rates of every
 * satellite of gnss.constellation in view, regenerated from the scene's seed exactly as the
 * simulation makes them) as RINEX 3.04 files in the sub-directory rinex/ of the result directory:
 *
 *   NAME.obs  observation file: C1C (pseudorange [m]) and D1C (Doppler [Hz]) of the satellites in
 *             view at every receiver epoch outside the receiver's outages, GPS time tags
 *   NAME.nav  navigation file: GPS LNAV records every 2 h and GLONASS records every
 *             15 min of UTC (NAVSIM_RINEX_GLO_STEP_S) spanning the observations
 *   pvt.csv   our own least-squares PVT of the same epochs (nav_gnss_pvt_solve) beside the
 *             reference antenna position, for comparisons with other solvers (rnx2rtkp):
 *             t_s, t_gps_s, n_sats, x_m, y_m, z_m (PVT, ECEF), ref_x_m, ref_y_m, ref_z_m,
 *             sd_n_m, sd_e_m, sd_d_m (code sigma x per-axis DOP), pdop
 *
 * NAME is the scene's name made file-safe. docs/rinex.md says what the files hold and how the
 * exported pseudoranges carry the satellite clock a RINEX user corrects for.
 */
#ifndef NAVSIM_RINEX_OUT_H
#define NAVSIM_RINEX_OUT_H

#include <stdbool.h>
#include <stddef.h>

#include "navcore/nav_results.h"
#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"

/** Spacing of the GLONASS records [s]: tb on the 15 min grid of UTC, as the GLONASS navigation
 *  message has it (RTKLIB rounds a record's epoch to that grid). docs/rinex.md measures the orbit
 *  agreement this leaves. */
#define NAVSIM_RINEX_GLO_STEP_S 900.0

typedef struct navsim_rinex navsim_rinex;

/* NULL when the scene can be exported, else why not (a static string). */
const char *navsim_rinex_unsupported(const nav_scene *scene);

/* Create rinex/ in @p rd and open its files. @p msg (may be NULL) says what failed. */
nav_status navsim_rinex_begin(const nav_scene *scene, bool ideal, nav_resultdir *rd, navsim_rinex **out,
                              char *msg, size_t msg_cap);

/* Called with every output record (other runs' records are ignored): writes the receiver epochs
 * up to the record's time. */
nav_status navsim_rinex_record(navsim_rinex *x, const nav_sim_record *r, char *msg, size_t msg_cap);

/* After a complete run: write the navigation file and close every file. Frees @p x. */
nav_status navsim_rinex_end(navsim_rinex *x, char *msg, size_t msg_cap);

/* Close and free without finishing; accepts NULL. */
void navsim_rinex_destroy(navsim_rinex *x);

#endif /* NAVSIM_RINEX_OUT_H */
