/*
 * Earth model helpers for navcore's own callers.
 */
#ifndef NAV_EARTH_INTERNAL_H
#define NAV_EARTH_INTERNAL_H

/* nav_earth_radius_meridian_m(), nav_earth_radius_prime_vertical_m() and
 * nav_earth_gravity_normal_mps2() at one point, with one sine of the latitude for the three (the
 * same values as the three calls): the filter's Earth terms at every covariance step. */
void nav_earth_radii_gravity(double lat_rad, double h_m, double *R_M_m, double *R_N_m, double *g_mps2);

#endif /* NAV_EARTH_INTERNAL_H */
