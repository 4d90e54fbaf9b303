/**
 * @file nav_gnss_almanac.h
 * @brief navcore_io: GNSS almanac files into navcore constellations (nav_gnss_sat.h).
 */
#ifndef NAV_GNSS_ALMANAC_H
#define NAV_GNSS_ALMANAC_H

#include "nav_export.h"
#include "nav_gnss_sat.h"
#include "nav_io.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/**
 * Read a GPS almanac in YUMA format (the U.S. Coast Guard NAVCEN text format: one block per
 * satellite opened by a "********" line, then "ID", "Health", "Eccentricity", "Time of
 * Applicability(s)", "Orbital Inclination(rad)", "Rate of Right Ascen(r/s)", "SQRT(A)  (m 1/2)",
 * "Right Ascen at Week(rad)", "Argument of Perigee(rad)", "Mean Anom(rad)", "Af0(s)", "Af1(s/s)",
 * "week", in this order) and append its satellites to @p out. The almanac week is given modulo
 * 1024 (IS-GPS-200N 20.3.3.5.1.3); it is resolved to the full week closest to @p t_ref_gps_s.
 * Every problem is reported as FILE:LINE:COL (nav_diag).
 * @return NAV_OK; NAV_ERR_IO (unreadable); NAV_ERR_PARSE (diagnostics reported; @p out unchanged);
 *         NAV_ERR_OUT_OF_RANGE (more than NAV_GNSS_MAX_SATS satellites, reported);
 *         NAV_ERR_INVALID_ARG (NULL).
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_almanac_read_yuma(const char *path, double t_ref_gps_s,
                                                            nav_gnss_constellation *out, nav_diag_fn report,
                                                            void *user);

NAV_END_DECLS

#endif /* NAV_GNSS_ALMANAC_H */
