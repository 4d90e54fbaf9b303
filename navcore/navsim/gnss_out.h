/*
 * gnss.csv and gnss_outages.csv of `navsim run` (INS/GNSS scenes): the receiver's fixes of run 0
 * and the outage intervals, for the viewer (GNSS fixes as points, outages highlighted).
 */
#ifndef NAVSIM_GNSS_OUT_H
#define NAVSIM_GNSS_OUT_H

#include <stdbool.h>
#include <stdio.h>

#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"

typedef struct navsim_gnss_out navsim_gnss_out;

/*
 * Open gnss.csv in @p gnss_path and write gnss_outages.csv to @p outages_path for an INS/GNSS
 * scene. *out stays NULL (and NAV_OK is returned) when the scene has no GNSS receiver.
 */
nav_status navsim_gnss_out_begin(const nav_scene *scene, bool ideal, const char *gnss_path, const char *outages_path,
                                 navsim_gnss_out **out);

/*
 * Called with every output record of run 0: measures the receiver epochs whose time of
 * validity is this output epoch (the same draws as the simulation's receiver of run 0) and
 * writes one row per fix. Fixes between output epochs are not written.
 */
nav_status navsim_gnss_out_record(navsim_gnss_out *g, const nav_sim_record *r);

/* Close the file (false when writing failed) and free; accepts NULL. */
bool navsim_gnss_out_end(navsim_gnss_out *g);

#endif /* NAVSIM_GNSS_OUT_H */
