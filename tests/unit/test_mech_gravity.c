/*
 * The shared gravity of the truth generator and the ECEF mechanization, nav_gravity_e_mps2(), is
 * the composition of the Earth-model functions written out for speed (sin(lat) once for the
 * rotation and the normal gravity). It must give the same bits as that composition,
 *   normal: nav_earth_dcm_n_e(lat, lon) nav_earth_gravity_n_mps2(lat, h) at the geodetic point of r,
 *   J2:     nav_earth_gravity_j2_e_mps2(r),
 * on a grid of latitudes (to within 1e-6 deg of the poles), longitudes on both sides of the
 * antimeridian, and heights from below the ellipsoid to low orbit, and at the poles and the centre.
 *
 * The ECEF mechanization's own normal gravity (nav/ecef_gravity.h: no trigonometry) agrees with it
 * to a few ulp of |g| on the same grid, and falls back to it exactly for J2 and outside its range.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <string.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_truth.h"
#include "nav/ecef_gravity.h"
#include "nav_test.h"

/* Bit equality (so that -0 and +0 differ and NaN equals itself). */
static void assert_vec3_bits(nav_vec3 a, nav_vec3 e, nav_vec3 r) {
  if (memcmp(&a.x, &e.x, sizeof a.x) != 0 || memcmp(&a.y, &e.y, sizeof a.y) != 0 ||
      memcmp(&a.z, &e.z, sizeof a.z) != 0)
    fail_msg("r = (%.17g, %.17g, %.17g): got (%.17g, %.17g, %.17g), composition (%.17g, %.17g, %.17g)", r.x,
             r.y, r.z, a.x, a.y, a.z, e.x, e.y, e.z);
}

static nav_vec3 normal_by_composition(nav_vec3 r) {
  const nav_geodetic p = nav_earth_ecef_to_geodetic(r);
  return nav_mat3_mul_vec(nav_earth_dcm_n_e(p.lat_rad, p.lon_rad),
                          nav_earth_gravity_n_mps2(p.lat_rad, p.h_m));
}

/* Largest |fast - reference| / |reference| over the checked points. */
static double g_worst_rel;

static void check_point(nav_vec3 r) {
  const nav_vec3 g = nav_gravity_e_mps2(NAV_GRAVITY_NORMAL, r);
  assert_vec3_bits(g, normal_by_composition(r), r);
  assert_vec3_bits(nav_gravity_e_mps2(NAV_GRAVITY_J2, r), nav_earth_gravity_j2_e_mps2(r), r);
  /* The fast path: J2 always and the normal model outside its range are the shared function. */
  assert_vec3_bits(nav_ecef_gravity_fast(NAV_GRAVITY_J2, r), nav_earth_gravity_j2_e_mps2(r), r);
  const nav_vec3 f = nav_ecef_gravity_fast(NAV_GRAVITY_NORMAL, r);
  const double rn = nav_vec3_norm(r);
  if (!(rn > NAV_ECEF_FAST_MIN_R_M && rn < NAV_ECEF_FAST_MAX_R_M)) {
    assert_vec3_bits(f, g, r);
    return;
  }
  const double rel = nav_vec3_norm(nav_vec3_sub(f, g)) / nav_vec3_norm(g);
  if (rel > g_worst_rel) g_worst_rel = rel;
  /* A few roundings of each route: 8 ulp of |g|. */
  if (!(rel <= 8.0 * DBL_EPSILON))
    fail_msg("r = (%.17g, %.17g, %.17g): fast gravity differs by %.3g relative", r.x, r.y, r.z, rel);
}

static void test_gravity_matches_composition(void **state) {
  (void)state;
  const double lats_deg[] = {-89.999999, -89.9, -75.3, -45.0, -12.345, -1e-9, 0.0,
                             1e-9,       0.7,   33.3,  45.0,  60.1,    89.0,  89.999999};
  const double lons_deg[] = {-180.0, -179.9999999, -120.5, -90.0, -0.001,      0.0,
                             0.001,  45.0,         90.0,   135.7, 179.9999999, 180.0};
  const double hs_m[] = {-5000.0, -0.5, 0.0, 1.25, 350.0, 8848.0, 12000.0, 1e5, 4e5};
  int n = 0;
  for (size_t i = 0; i < sizeof lats_deg / sizeof *lats_deg; ++i)
    for (size_t j = 0; j < sizeof lons_deg / sizeof *lons_deg; ++j)
      for (size_t k = 0; k < sizeof hs_m / sizeof *hs_m; ++k) {
        const nav_geodetic g = {lats_deg[i] * NAV_DEG2RAD, lons_deg[j] * NAV_DEG2RAD, hs_m[k]};
        check_point(nav_earth_geodetic_to_ecef(g));
        ++n;
      }
  /* Exact axis and plane points: the poles, the equator, the centre. */
  check_point(nav_vec3_make(0.0, 0.0, NAV_WGS84_B_M + 10.0));
  check_point(nav_vec3_make(0.0, 0.0, -NAV_WGS84_B_M - 10.0));
  check_point(nav_vec3_make(NAV_WGS84_A_M, 0.0, 0.0));
  check_point(nav_vec3_make(0.0, -NAV_WGS84_A_M, 0.0));
  check_point(nav_vec3_make(0.0, 0.0, 0.0));
  /* Just inside and outside the range of the fast path. */
  check_point(nav_vec3_make(NAV_ECEF_FAST_MIN_R_M * 0.999, 1.0, 2.0));
  check_point(nav_vec3_make(NAV_ECEF_FAST_MIN_R_M * 1.001, 1.0, 2.0));
  check_point(nav_vec3_make(1.0, -NAV_ECEF_FAST_MAX_R_M * 0.999, 2.0));
  check_point(nav_vec3_make(1.0, 2.0, NAV_ECEF_FAST_MAX_R_M * 1.001));
  assert_true(n > 1000);
  print_message("fast ECEF gravity: largest relative difference %.3g (%.2f ulp)\n", g_worst_rel,
                g_worst_rel / DBL_EPSILON);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_gravity_matches_composition),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
