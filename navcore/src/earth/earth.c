/**
 * @file earth.c
 * @brief WGS-84 Earth model (nav_earth.h). Pure C11 + libm; uses only the inline helpers of
 *        nav_math.h.
 *
 * References: NIMA TR8350.2 3rd ed. (constants, normal gravity); P. Groves, Principles of GNSS,
 * Inertial, and Multisensor Integrated Navigation Systems, 2nd ed. (ch. 2 and 5); numerics.md
 * sections 0.4 and 3.2 (equation numbers E3.x); D. Eberly, "Distance from a Point to an Ellipse,
 * an Ellipsoid, or a Hyperellipsoid", Geometric Tools (2013), for the foot-point equation.
 */
#include "navcore/nav_earth.h"

#include <float.h>
#include <math.h>

#include "earth/earth_internal.h"

/* 1 - e^2 = (b/a)^2. */
#define E2M (1.0 - NAV_WGS84_E2)

/*
 * Beyond this distance from the centre [m] the geodetic and geocentric latitudes differ by less
 * than e^2 a / (2 r) < 4e-19 rad, far below an ulp of the latitude, so the ellipsoid is not worth
 * solving for (and the squares of the secular equation could overflow for huge inputs). Same
 * order as GeographicLib's maxrad = 2 a / epsilon.
 */
#define FAR_RADIUS_M (2.0 * NAV_WGS84_A_M / DBL_EPSILON)

/* Newton steps for the secular equation: 4 to 5 are needed near the Earth and at most ~13 deep
 * inside it; the cap only guards pathological inputs (the iteration is monotone from the left, so
 * stopping early never selects a wrong branch). */
#define MAX_NEWTON_STEPS 64

double nav_earth_wrap_lon(double lon_rad) {
  /* Inside (-pi, pi] remainder() returns its argument unchanged: skip the libm call. */
  if (lon_rad > -NAV_PI && lon_rad <= NAV_PI) return lon_rad;
  /* remainder() is exact and returns [-pi, pi] for the double nearest 2 pi; fold -pi to +pi. */
  double w = remainder(lon_rad, NAV_TWO_PI);
  if (w <= -NAV_PI) w = NAV_PI;
  return w;
}

/* 1 - e^2 sin^2(lat), the squared denominator of the radii of curvature. */
static double radius_den2(double sin_lat) {
  return 1.0 - NAV_WGS84_E2 * sin_lat * sin_lat;
}

nav_vec3 nav_earth_geodetic_to_ecef(nav_geodetic p) {
  return nav_earth_geodetic_to_ecef_sc(sin(p.lat_rad), cos(p.lat_rad), sin(p.lon_rad), cos(p.lon_rad), p.h_m);
}

nav_vec3 nav_earth_geodetic_to_ecef_sc(double s, double c, double sl, double cl, double h_m) {
  /* Groves (2.112): R_N from (2.106); z uses R_N (1 - e^2) = a (1 - e^2)/sqrt(...). */
  const double sqrt_den = sqrt(radius_den2(s));
  const double R_N = NAV_WGS84_A_M / sqrt_den;
  const double rho = (R_N + h_m) * c;
  const double z = (NAV_WGS84_A_M * E2M / sqrt_den + h_m) * s;
  return nav_vec3_make(rho * cl, rho * sl, z);
}

/*
 * Secular equation of the foot point, scaled by a so that every term is O(1) near the Earth.
 * With P = p/a, Z = |z|/a and the unknown w = (t + b^2)/a^2 (u = w + e^2 = (t + a^2)/a^2):
 *   F(w) = (P/u)^2 + (1 - e^2) (Z/w)^2 - 1 = 0,   F'(w) = -2 P^2/u^3 - 2 (1 - e^2) Z^2/w^3.
 * For Z > 0, F is convex and strictly decreasing on w > 0 and tends to +inf at w -> 0+, so it has
 * exactly one root there, which belongs to the nearest foot point (Eberly 2013).
 *
 * Why w and not t: near the surface w ~ 1 - e^2 and u ~ 1; inside the evolute close to the
 * equatorial plane the root has w -> 0 (the foot point lies off the equator while z -> 0). Solving
 * for w keeps full relative precision there, where w = (1 - e^2) + t/a^2 would cancel, and
 * u = w + e^2 >= e^2 never cancels.
 */
static double secular_f(double P, double Z, double w, double *dfdw) {
  const double u = w + NAV_WGS84_E2;
  const double pu = P / u, zw = Z / w;
  *dfdw = -2.0 * (pu * pu / u + E2M * zw * zw / w);
  return pu * pu + E2M * zw * zw - 1.0;
}

/* Solve the secular equation for P > 0, Z > 0 (both finite, point not far away). */
static double solve_w(double P, double Z) {
  /*
   * Left bound: F(w_left) >= 0 because one of the two terms equals 1 there, and w_left > 0.
   * Every point left of the root is a safe restart: Newton on a convex decreasing function never
   * overshoots from there and converges monotonically.
   */
  const double sb = sqrt(E2M); /* b/a */
  const double w_left = fmax(sb * Z, P - NAV_WGS84_E2);

  /*
   * Near-surface start: the height over the ellipse along the geocentric ray,
   * h0 = r - a b / sqrt(b^2 cos^2(psi) + a^2 sin^2(psi)), and t/a^2 ~ h/R_N ~ h0/a. It is within
   * ~1e-3 of the root for heights up to thousands of kilometres, so Newton needs 2 to 5 steps;
   * the monotone fallback takes over elsewhere (deep inside the Earth).
   */
  const double r = hypot(P, Z);
  double w = E2M + (r - sb * r / hypot(sb * P, Z));
  if (!(w > w_left)) w = w_left;

  for (int i = 0; i < MAX_NEWTON_STEPS; ++i) {
    double df = 0.0;
    const double f = secular_f(P, Z, w, &df);
    double next = w - f / df;
    /* A step from the right of the root lands left of it, possibly beyond the domain; clamp. */
    if (!(next > w_left)) next = w_left;
    const double step = next - w;
    w = next;
    /* Quadratic convergence: once a step is at rounding level the next one changes nothing. */
    if (fabs(step) <= 4.0 * DBL_EPSILON * w) break;
  }
  return w;
}

nav_geodetic nav_earth_ecef_to_geodetic(nav_vec3 r_eb_e_m) {
  const double x = r_eb_e_m.x, y = r_eb_e_m.y, z = r_eb_e_m.z;
  nav_geodetic g;
  if (!(isfinite(x) && isfinite(y) && isfinite(z))) {
    g.lat_rad = g.lon_rad = g.h_m = NAN;
    return g;
  }

  const double p = hypot(x, y);
  const double az = fabs(z);
  /* Longitude is undefined on the axis; 0 keeps the result deterministic for any signed zeros. */
  g.lon_rad = p > 0.0 ? nav_earth_wrap_lon(atan2(y, x)) : 0.0;

  if (p == 0.0) {
    /* On the polar axis the nearest point is the pole on the side of z (the centre included). */
    g.lat_rad = copysign(0.5 * NAV_PI, z);
    g.h_m = az - NAV_WGS84_B_M;
    return g;
  }

  const double r = hypot(p, az);
  if (r > FAR_RADIUS_M) {
    const double cos_lat = p / r;
    g.lat_rad = copysign(atan2(az, p), z);
    g.h_m = r - NAV_WGS84_A_M * sqrt(E2M / (1.0 - NAV_WGS84_E2 * cos_lat * cos_lat));
    return g;
  }

  const double P = p / NAV_WGS84_A_M;
  const double Z = az / NAV_WGS84_A_M;
  /* Z == 0 also catches a subnormal z whose scaled value underflows (the secular equation would
   * then meet 0/0); the latitude such a z implies is below 1e-300 rad. */
  if (Z == 0.0) {
    if (P >= NAV_WGS84_E2) {
      /* Equatorial plane outside the evolute: the foot point is on the equator. */
      g.lat_rad = copysign(0.0, z);
      g.h_m = p - NAV_WGS84_A_M;
      return g;
    }
    /*
     * Equatorial plane inside the evolute (p < a e^2 = 42.7 km): the secular equation degenerates
     * (w = 0); the two nearest points have parametric latitude beta with cos(beta) = p/(a e^2).
     * The normal there is (cos(beta)/a, sin(beta)/b).
     */
    const double cb = P / NAV_WGS84_E2;
    const double sbeta = sqrt((1.0 - cb) * (1.0 + cb));
    g.lat_rad = copysign(atan2(NAV_WGS84_A_M * sbeta, NAV_WGS84_B_M * cb), z);
    g.h_m = -hypot(p - NAV_WGS84_A_M * cb, NAV_WGS84_B_M * sbeta);
    return g;
  }

  const double w = solve_w(P, Z);
  const double u = w + NAV_WGS84_E2;
  /*
   * The normal at the foot point is proportional to (p/(t + a^2), z/(t + b^2)), i.e. to
   * (p w, |z| u) after clearing the denominators. u is rounded once, so lat carries ~2 ulp of
   * relative error in tan(lat) (< 1e-16 rad), and is insensitive to the last bits of w
   * (d tan(lat)/tan(lat) = -e^2 dw / (u w)).
   */
  g.lat_rad = copysign(atan2(az * u, p * w), z);
  /*
   * Height: point - foot = (t/a^2) (p/u, |z|/w) with t/a^2 = w - (1 - e^2); its length is |h| and
   * its sign that of t. This has no cancellation apart from forming t/a^2 (unlike
   * p cos + z sin - a W, whose three terms of ~6.4e6 m each leave ~2 ulp of them in h); w is good
   * to ~1e-16, i.e. ~1e-9 m in h near the surface.
   */
  g.h_m = (w - E2M) * hypot(p / u, az / w);
  return g;
}

/* The radii and normal gravity from s = sin(lat): the public functions below call these with
 * sin(lat_rad), and nav_earth_radii_gravity() with one sine for all three, the same values. */
static double meridian_of_sin(double s) {
  /* Groves (2.105). */
  const double den2 = radius_den2(s);
  return NAV_WGS84_A_M * E2M / (den2 * sqrt(den2));
}

static double prime_vertical_of_sin(double s) {
  /* Groves (2.106). */
  return NAV_WGS84_A_M / sqrt(radius_den2(s));
}

static double gravity_surface_of_sin(double s) {
  /* Somigliana, TR8350.2 (4-1), numerics.md (E3.10). */
  const double s2 = s * s;
  return NAV_WGS84_GAMMA_E_MPS2 * (1.0 + NAV_WGS84_SOMIGLIANA_K * s2) / sqrt(1.0 - NAV_WGS84_E2 * s2);
}

static double gravity_normal_of_sin(double s, double h_m) {
  /* TR8350.2 (4-3), numerics.md (E3.11). */
  const double s2 = s * s;
  const double a = NAV_WGS84_A_M;
  const double lin = (2.0 / a) * (1.0 + NAV_WGS84_F + NAV_WGS84_M - 2.0 * NAV_WGS84_F * s2);
  const double quad = 3.0 / (a * a);
  return gravity_surface_of_sin(s) * (1.0 - lin * h_m + quad * h_m * h_m);
}

double nav_earth_radius_meridian_m(double lat_rad) {
  return meridian_of_sin(sin(lat_rad));
}

double nav_earth_radius_prime_vertical_m(double lat_rad) {
  return prime_vertical_of_sin(sin(lat_rad));
}

double nav_earth_gravity_normal_surface_mps2(double lat_rad) {
  return gravity_surface_of_sin(sin(lat_rad));
}

double nav_earth_gravity_normal_mps2(double lat_rad, double h_m) {
  return gravity_normal_of_sin(sin(lat_rad), h_m);
}

void nav_earth_radii_gravity(double lat_rad, double h_m, double *R_M_m, double *R_N_m, double *g_mps2) {
  const double s = sin(lat_rad);
  *R_M_m = meridian_of_sin(s);
  *R_N_m = prime_vertical_of_sin(s);
  *g_mps2 = gravity_normal_of_sin(s, h_m);
}

nav_vec3 nav_earth_gravity_n_mps2(double lat_rad, double h_m) {
  return nav_vec3_make(0.0, 0.0, nav_earth_gravity_normal_mps2(lat_rad, h_m));
}

nav_vec3 nav_earth_gravitation_j2_e_mps2(nav_vec3 r_eb_e_m) {
  /* numerics.md (E3.12), Groves (2.142). */
  const double r2 = nav_vec3_dot(r_eb_e_m, r_eb_e_m);
  const double r = sqrt(r2);
  const double a_r2 = (NAV_WGS84_A_M * NAV_WGS84_A_M) / r2;
  const double z2_r2 = 5.0 * r_eb_e_m.z * r_eb_e_m.z / r2;
  const double k = 1.5 * NAV_WGS84_J2 * a_r2;
  const double scale = -NAV_WGS84_GM_M3PS2 / (r2 * r);
  const double cxy = scale * (1.0 + k * (1.0 - z2_r2));
  const double cz = scale * (1.0 + k * (3.0 - z2_r2));
  return nav_vec3_make(cxy * r_eb_e_m.x, cxy * r_eb_e_m.y, cz * r_eb_e_m.z);
}

nav_vec3 nav_earth_gravity_j2_e_mps2(nav_vec3 r_eb_e_m) {
  /* numerics.md (E3.7): g = gamma - Omega_ie Omega_ie r, and -Omega Omega r = omega^2 (x, y, 0). */
  const double w2 = NAV_WGS84_OMEGA_IE_RPS * NAV_WGS84_OMEGA_IE_RPS;
  const nav_vec3 gamma_e = nav_earth_gravitation_j2_e_mps2(r_eb_e_m);
  return nav_vec3_make(gamma_e.x + w2 * r_eb_e_m.x, gamma_e.y + w2 * r_eb_e_m.y, gamma_e.z);
}

nav_vec3 nav_earth_rate_e_rps(void) {
  return nav_vec3_make(0.0, 0.0, NAV_WGS84_OMEGA_IE_RPS);
}

nav_vec3 nav_earth_rate_n_rps(double lat_rad) {
  /* numerics.md (E3.9). */
  return nav_vec3_make(NAV_WGS84_OMEGA_IE_RPS * cos(lat_rad), 0.0, -NAV_WGS84_OMEGA_IE_RPS * sin(lat_rad));
}

nav_vec3 nav_earth_transport_rate_n_rps(double lat_rad, double h_m, nav_vec3 v_eb_n_mps) {
  /* numerics.md (E3.9). */
  const double s = sin(lat_rad), c = cos(lat_rad);
  const double den2 = radius_den2(s);
  const double sqrt_den = sqrt(den2);
  const double R_N = NAV_WGS84_A_M / sqrt_den;
  const double R_M = NAV_WGS84_A_M * E2M / (den2 * sqrt_den);
  const double east = v_eb_n_mps.y / (R_N + h_m);
  return nav_vec3_make(east, -v_eb_n_mps.x / (R_M + h_m), -east * s / c);
}

nav_mat3 nav_earth_dcm_n_e(double lat_rad, double lon_rad) {
  /* The transpose of C_e_n (Groves 2nd ed., ch. 2). Columns: north, east, down in e. */
  const double s = sin(lat_rad), c = cos(lat_rad);
  const double sl = sin(lon_rad), cl = cos(lon_rad);
  nav_mat3 C_n_e = {{{-s * cl, -sl, -c * cl}, {-s * sl, cl, -c * sl}, {c, 0.0, -s}}};
  return C_n_e;
}

nav_vec3 nav_earth_ecef_to_ned(nav_geodetic origin, nav_vec3 r_eb_e_m) {
  const nav_vec3 r_el_e_m = nav_earth_geodetic_to_ecef(origin);
  const nav_mat3 C_l_e = nav_earth_dcm_n_e(origin.lat_rad, origin.lon_rad);
  /* r_lb_l = C_e_l (r_eb_e - r_el_e); C_e_l = C_l_e^T. */
  return nav_mat3_tmul_vec(C_l_e, nav_vec3_sub(r_eb_e_m, r_el_e_m));
}

nav_vec3 nav_earth_ned_to_ecef(nav_geodetic origin, nav_vec3 r_lb_l_m) {
  const nav_vec3 r_el_e_m = nav_earth_geodetic_to_ecef(origin);
  const nav_mat3 C_l_e = nav_earth_dcm_n_e(origin.lat_rad, origin.lon_rad);
  return nav_vec3_add(r_el_e_m, nav_mat3_mul_vec(C_l_e, r_lb_l_m));
}

nav_vec3 nav_earth_geodetic_to_ned(nav_geodetic origin, nav_geodetic p) {
  return nav_earth_ecef_to_ned(origin, nav_earth_geodetic_to_ecef(p));
}

nav_geodetic nav_earth_ned_to_geodetic(nav_geodetic origin, nav_vec3 r_lb_l_m) {
  return nav_earth_ecef_to_geodetic(nav_earth_ned_to_ecef(origin, r_lb_l_m));
}
