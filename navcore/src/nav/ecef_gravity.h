/*
 * Fast normal gravity in ECEF for the ECEF mechanization (strapdown.c); internal to navcore (and its
 * tests). Header-only so that the step inlines it into both of its clones (nav_clones.h).
 */
#ifndef NAV_ECEF_GRAVITY_H
#define NAV_ECEF_GRAVITY_H

#include <float.h>
#include <math.h>
#include <stdbool.h>

#include "nav_clones.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_truth.h"

/* 1 - e^2 = (b/a)^2. */
#define NAV_ECEF_E2M (1.0 - NAV_WGS84_E2)

/* The ECEF fast gravity solves for the foot point only between these distances from the centre
 * (well outside the evolute, up to 6 Earth radii); elsewhere, or if Newton has not converged in
 * NAV_ECEF_NEWTON_STEPS steps, nav_gravity_e_mps2() is used. */
#define NAV_ECEF_FAST_MIN_R_M 5.0e6
#define NAV_ECEF_FAST_MAX_R_M 4.0e7
#define NAV_ECEF_NEWTON_STEPS 8
#define NAV_ECEF_NEWTON_TOL 1e-9

/*
 * Normal gravity in e at r (TR8350.2 eqs. 4-1, 4-3; numerics.md E3.10-E3.11): -gamma(lat, h) times
 * the ellipsoid normal at the foot point, as nav_gravity_e_mps2(NAV_GRAVITY_NORMAL) computes it but
 * without its trigonometry (two atan2 and two sin/cos pairs per call, over half of the ECEF step).
 * The foot point is the root w of the secular equation of nav_earth_ecef_to_geodetic() (earth.c:
 * the same scaling, start and Newton iteration, with two reciprocals per step), and the normal there is
 * proportional to (x w, y w, z u), u = w + e^2, so that sin(lat) = z u / |(x w, y w, z u)| and the direction
 * of gravity need no angles; h = (w - (1 - e^2)) |(p/u, z/w)| as in earth.c. Both routes round a few times at
 * the 1e-16 level; they agree to a few ulp of g (test_mech_gravity: 5.5 ulp at most, 8 allowed), ~1e-15
 * m/s^2. Closure errors are unchanged to 5 significant digits: long drive (811 s, 200 Hz, high
 * order) 1.419324e-05 m before, 1.419313e-05 m after; the parametric closures to 6 digits. J2 and points
 * outside the range take nav_gravity_e_mps2().
 */
NAV_CLONE_INLINE nav_vec3 nav_ecef_gravity_fast(nav_gravity_model model, nav_vec3 r) {
  const double x = r.x, y = r.y, z = r.z;
  const double p2 = x * x + y * y, r2 = p2 + z * z;
  if (model != NAV_GRAVITY_NORMAL || !(r2 > NAV_ECEF_FAST_MIN_R_M * NAV_ECEF_FAST_MIN_R_M) ||
      !(r2 < NAV_ECEF_FAST_MAX_R_M * NAV_ECEF_FAST_MAX_R_M))
    return nav_gravity_e_mps2(model, r);
  const double ia = 1.0 / NAV_WGS84_A_M;
  const double P = sqrt(p2) * ia, Z = fabs(z) * ia, R = sqrt(r2) * ia;
  const double sb = sqrt(NAV_ECEF_E2M); /* b/a */
  double w = NAV_ECEF_E2M + (R - sb * R / sqrt(sb * sb * P * P + Z * Z));
  double pu = 0.0, zw = 0.0, u = 0.0;
  bool done = false;
  for (int i = 0; i < NAV_ECEF_NEWTON_STEPS && !done; ++i) {
    u = w + NAV_WGS84_E2;
    const double iu = 1.0 / u, iw = 1.0 / w;
    pu = P * iu;
    zw = Z * iw;
    const double f = pu * pu + NAV_ECEF_E2M * zw * zw - 1.0;
    const double df = -2.0 * (pu * pu * iu + NAV_ECEF_E2M * zw * zw * iw);
    const double step = f / df;
    w -= step;
    /* Quadratic convergence: the error after a step of size s is about (F''/2F') s^2 < 1.5 s^2
     * (F' ~ -2, F'' ~ 6 near the surface), below 2e-18 once s <= 1e-9: one step fewer than waiting
     * for a step at rounding level as earth.c does. */
    done = fabs(step) <= NAV_ECEF_NEWTON_TOL * w;
  }
  if (!done || !(w > 0.0)) return nav_gravity_e_mps2(model, r);
  u = w + NAV_WGS84_E2;
  pu = P / u;
  zw = Z / w;
  const double h = (w - NAV_ECEF_E2M) * NAV_WGS84_A_M * sqrt(pu * pu + zw * zw);
  const double nx = x * w, ny = y * w, nz = z * u;
  const double in = 1.0 / sqrt(nx * nx + ny * ny + nz * nz);
  const double sl = nz * in, s2 = sl * sl;
  const double ea = NAV_WGS84_A_M;
  const double lin = (2.0 / ea) * (1.0 + NAV_WGS84_F + NAV_WGS84_M - 2.0 * NAV_WGS84_F * s2);
  const double quad = 3.0 / (ea * ea);
  const double gamma = NAV_WGS84_GAMMA_E_MPS2 * (1.0 + NAV_WGS84_SOMIGLIANA_K * s2) /
                       sqrt(1.0 - NAV_WGS84_E2 * s2) * (1.0 - lin * h + quad * h * h);
  const double k = -gamma * in;
  return nav_vec3_make(k * nx, k * ny, k * nz);
}

#endif /* NAV_ECEF_GRAVITY_H */
