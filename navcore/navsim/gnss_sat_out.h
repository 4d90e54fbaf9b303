/*
 * gnss_dop.csv and gnss_sats.csv of `navsim run` for scenes with a gnss.constellation section
 * (issue 22): per output epoch of run 0, the satellites in view and the DOP of the visible ones.
 */
#ifndef NAVSIM_GNSS_SAT_OUT_H
#define NAVSIM_GNSS_SAT_OUT_H

#include <stdbool.h>

#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"

typedef struct navsim_gnss_sat_out navsim_gnss_sat_out;

/* Open the three files (dop, sats, mask); *out stays NULL (NAV_OK) when the scene has no gnss.constellation section. */
nav_status navsim_gnss_sat_out_begin(const nav_scene *scene, const char *dop_path, const char *sats_path,
                                     const char *mask_path, navsim_gnss_sat_out **out);

/* One output record (rows for run 0 only): the receiver at the body's true position, heading from
 * the true attitude. */
nav_status navsim_gnss_sat_out_record(navsim_gnss_sat_out *g, const nav_sim_record *r);

/* Close both files (false when writing failed) and free; accepts NULL. */
bool navsim_gnss_sat_out_end(navsim_gnss_sat_out *g);

#endif /* NAVSIM_GNSS_SAT_OUT_H */
