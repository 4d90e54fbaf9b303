/**
 * @file nav_earth.h
 * @brief WGS-84 Earth model: ellipsoid constants, geodetic <-> ECEF, radii of curvature, normal
 *        gravity, J2 gravitation, Earth and transport rates, the NED frame and local NED
 *        coordinates about an origin.
 *
 * Frames (style.md section 4): `e` is ECEF (WGS-84), `n` the local-level NED frame at the point,
 * `l` a fixed NED frame at a chosen origin. Geodetic positions are `lat_rad` (geodetic latitude,
 * [-pi/2, pi/2]), `lon_rad` (longitude, (-pi, pi] on output) and `h_m` (height above the
 * ellipsoid along its normal). Everything is SI.
 *
 * All functions here are leaf maths: pure, thread-safe, allocation-free, they cannot fail and
 * they return their results directly. NaN inputs propagate to NaN outputs (as in GeographicLib);
 * each function documents its domain and its singular points. Stage APIs that take external
 * input check finiteness themselves.
 *
 * The implementation is pure C (libm only). GeographicLib C++ serves as an independent oracle in
 * tests/unit/test_earth.cpp (docs/adr/0001-geodesy-in-c.md), which also records the accuracies
 * measured against it.
 *
 * Example:
 * @code
 *   nav_geodetic p = {48.8566 * NAV_DEG2RAD, 2.3522 * NAV_DEG2RAD, 35.0};
 *   nav_vec3 r_eb_e_m = nav_earth_geodetic_to_ecef(p);    // (4200937.80, 172560.72, 4780107.70) m
 *   nav_geodetic q = nav_earth_ecef_to_geodetic(r_eb_e_m); // p again, to a few nm
 *   nav_mat3 C_n_e = nav_earth_dcm_n_e(p.lat_rad, p.lon_rad);
 *   nav_vec3 g_n_mps2 = nav_earth_gravity_n_mps2(p.lat_rad, p.h_m); // (0, 0, 9.809571) m/s^2
 * @endcode
 */
#ifndef NAV_EARTH_H
#define NAV_EARTH_H

#include "nav_export.h"
#include "nav_math.h"

NAV_BEGIN_DECLS

/* ---------------------------------------------------------------- constants */

/**
 * @name WGS-84 and Earth constants
 * Source: NIMA TR8350.2, "Department of Defense World Geodetic System 1984", 3rd ed. (2000),
 * tables 3.1 (defining parameters) and 3.4 (Somigliana normal-gravity constants); restated in
 * numerics.md section 0.4. J2 is the value used by Groves (2nd ed., ch. 2); it differs from the
 * TR8350.2 derived value -sqrt(5) C20bar = 1.08262998905e-3 by 3e-9, which changes gravitation
 * by < 5e-8 m/s^2.
 * @{
 */
/** Semi-major axis a [m] (TR8350.2 table 3.1). */
#define NAV_WGS84_A_M 6378137.0
/** Flattening f = 1/298.257223563 [-] (TR8350.2 table 3.1). */
#define NAV_WGS84_F (1.0 / 298.257223563)
/** First eccentricity squared e^2 = f (2 - f) = 6.69437999014e-3 [-]. */
#define NAV_WGS84_E2 (NAV_WGS84_F * (2.0 - NAV_WGS84_F))
/** Semi-minor axis b = a (1 - f) = 6356752.3142 m [m]. */
#define NAV_WGS84_B_M (NAV_WGS84_A_M * (1.0 - NAV_WGS84_F))
/** Earth rotation rate omega_ie [rad/s] (TR8350.2 table 3.1). */
#define NAV_WGS84_OMEGA_IE_RPS 7.292115e-5
/** Earth gravitational constant GM, atmosphere included [m^3/s^2] (TR8350.2 table 3.1). */
#define NAV_WGS84_GM_M3PS2 3.986004418e14
/** Second-degree zonal harmonic J2 [-] (Groves 2nd ed., ch. 2; numerics.md 0.4). */
#define NAV_WGS84_J2 1.082627e-3
/** Normal gravity at the equator gamma_e [m/s^2] (TR8350.2 table 3.4). */
#define NAV_WGS84_GAMMA_E_MPS2 9.7803253359
/** Somigliana constant k = (b gamma_p)/(a gamma_e) - 1 [-] (TR8350.2 table 3.4). */
#define NAV_WGS84_SOMIGLIANA_K 0.00193185265241
/** m = omega_ie^2 a^2 b / GM [-] (TR8350.2 table 3.4). */
#define NAV_WGS84_M 0.00344978650684
/** Standard gravity g0 [m/s^2], for mg / ug / "g" unit conversions only (not local gravity). */
#define NAV_G0_MPS2 9.80665
/** @} */

/* ---------------------------------------------------------------- types */

/** A geodetic position on the WGS-84 ellipsoid. Plain value; copy by assignment. */
typedef struct nav_geodetic {
  double lat_rad; /**< geodetic latitude [rad], [-pi/2, pi/2] */
  double lon_rad; /**< longitude [rad], east positive; outputs are wrapped to (-pi, pi] */
  double h_m;     /**< height above the ellipsoid along the ellipsoid normal [m] */
} nav_geodetic;

/* ---------------------------------------------------------------- angles */

/**
 * Wrap a longitude to (-pi, pi].
 * @param[in] lon_rad any finite longitude [rad]
 * @return the equivalent longitude in (-pi, pi] [rad]; -pi maps to +pi, and +0 / -0 keep their
 *         sign. Exact: remainder() introduces no rounding. NaN and +/-inf give NaN.
 */
NAV_API double nav_earth_wrap_lon(double lon_rad);

/* ---------------------------------------------------------------- geodetic <-> ECEF */

/**
 * Geodetic to ECEF position (Groves 2nd ed. eq. 2.112).
 * @param[in] p geodetic position: lat_rad [rad], lon_rad [rad] (any value), h_m [m]
 * @return r_eb_e_m, the position of the point in ECEF [m]
 *
 * Valid for every finite input; lat outside [-pi/2, pi/2] is accepted and treated through its
 * sine and cosine. Accurate to about 3 ulp of |r| (the ulp of a coordinate is 0.93 nm from
 * 4.2e6 to 8.4e6 m), like GeographicLib's Geocentric::Forward.
 */
NAV_API nav_vec3 nav_earth_geodetic_to_ecef(nav_geodetic p);

/**
 * nav_earth_geodetic_to_ecef() for a caller that already has the sines and cosines of the
 * latitude and longitude (sin() and cos() of them): the same operations after those, so the same
 * result bit for bit.
 */
NAV_API nav_vec3 nav_earth_geodetic_to_ecef_sc(double sin_lat, double cos_lat, double sin_lon, double cos_lon,
                                               double h_m);

/**
 * ECEF to geodetic position: the nearest point on the ellipsoid and the height along its
 * normal. Robust for every finite input: at and near the poles, on the polar axis, in the
 * equatorial plane, inside the ellipsoid (including inside the evolute near the centre) and far
 * above it.
 *
 * Method: the foot point is parametrised by t, with foot = (a^2 p/(t + a^2), b^2 z/(t + b^2)) in
 * the meridian plane (p = horizontal distance); t solves the secular equation
 * (a p/(t + a^2))^2 + (b z/(t + b^2))^2 = 1, which is convex and decreasing on t > -b^2, so Newton
 * from a start left of the root converges monotonically (Eberly, "Distance from a point to an
 * ellipse", Geometric Tools 2013). A near-surface start makes it converge in 4 to 5 steps (at
 * most ~13 deep inside the Earth). The latitude then follows from the normal at the foot point
 * without trigonometric iteration.
 *
 * @param[in] r_eb_e_m position in ECEF [m]
 * @return lat_rad in [-pi/2, pi/2], lon_rad in (-pi, pi], h_m [m]. Against an extended-precision
 *         reference the error is <= 1.5 nm along the meridian and <= 2.4 nm in height for
 *         -10 km <= h <= 1000 km (GeographicLib's Geocentric::Reverse: 1.8 nm and 3.7 nm; it
 *         documents 7 nm). The round trip with nav_earth_geodetic_to_ecef() stays within 6 ulp
 *         of |r| per component (measured <= 4.4 ulp, about 4 nm near the Earth): 1e-9 m is one
 *         ulp, below what any double implementation can guarantee. See test_earth.
 *
 * Edge cases:
 * - On the polar axis (x = y = 0) the longitude is undefined; 0 is returned, lat = +/-pi/2 with
 *   the sign of z (the sign bit for z = +/-0), h = |z| - b. The centre gives lat = +pi/2 and
 *   h = -b.
 * - Inside the evolute on the equatorial plane (z = 0, p < a e^2, about 42.7 km from the centre)
 *   there are two nearest points; the northern one is returned for z = +0, the southern for -0.
 * - Any non-finite component gives NaN for all three outputs.
 */
NAV_API nav_geodetic nav_earth_ecef_to_geodetic(nav_vec3 r_eb_e_m);

/* ---------------------------------------------------------------- radii of curvature */

/**
 * Meridian radius of curvature R_M = a (1 - e^2) / (1 - e^2 sin^2 lat)^(3/2) (Groves eq. 2.105).
 * @param[in] lat_rad geodetic latitude [rad]
 * @return R_M [m]; 6335439.327 m at the equator, 6399593.626 m at the poles.
 */
NAV_API double nav_earth_radius_meridian_m(double lat_rad);

/**
 * Prime-vertical (transverse) radius of curvature R_N = a / sqrt(1 - e^2 sin^2 lat)
 * (Groves eq. 2.106).
 * @param[in] lat_rad geodetic latitude [rad]
 * @return R_N [m]; a at the equator, a^2/b at the poles.
 */
NAV_API double nav_earth_radius_prime_vertical_m(double lat_rad);

/* ---------------------------------------------------------------- gravity */

/**
 * Normal gravity on the ellipsoid, Somigliana's closed formula (TR8350.2 eq. 4-1;
 * numerics.md E3.10): gamma_0 = gamma_e (1 + k sin^2 lat) / sqrt(1 - e^2 sin^2 lat).
 * @param[in] lat_rad geodetic latitude [rad]
 * @return magnitude of normal gravity (gravitation + centrifugal) at h = 0 [m/s^2]; exact for the
 *         normal field: agrees with GeographicLib's NormalGravity::SurfaceGravity to 5e-12 m/s^2
 *         (the rounding of the tabulated gamma_e and k).
 */
NAV_API double nav_earth_gravity_normal_surface_mps2(double lat_rad);

/**
 * Normal gravity at height h by the second-order height series (TR8350.2 eq. 4-3; numerics.md
 * E3.11): gamma = gamma_0 [1 - (2/a)(1 + f + m - 2 f sin^2 lat) h + (3/a^2) h^2].
 * @param[in] lat_rad geodetic latitude [rad]
 * @param[in] h_m     height above the ellipsoid [m]
 * @return magnitude of normal gravity along the ellipsoid normal [m/s^2].
 *
 * The series is a truncated expansion in h/a: against the exact normal gravity (GeographicLib
 * NormalGravity::Gravity, component along the normal) it is within 1.75e-6 m/s^2 for
 * -10 km <= h <= 20 km (worst at -10 km on the equator), but 1.6e-4 m/s^2 at 100 km and
 * 0.13 m/s^2 at 1000 km. Use nav_earth_gravity_j2_e_mps2() for orbital heights.
 */
NAV_API double nav_earth_gravity_normal_mps2(double lat_rad, double h_m);

/**
 * Gravity vector in the local NED frame from the normal-gravity series:
 * g_n = (0, 0, gamma(lat, h)) (numerics.md section 3.2; the north component of the normal field,
 * about -8e-9 h sin(2 lat) m/s^2 with h in metres, is neglected, as are deflections of the
 * vertical).
 * @param[in] lat_rad geodetic latitude [rad]
 * @param[in] h_m     height above the ellipsoid [m]
 * @return g_n_mps2, gravity (gravitation + centrifugal) resolved in n, down positive [m/s^2]
 */
NAV_API nav_vec3 nav_earth_gravity_n_mps2(double lat_rad, double h_m);

/**
 * Gravitational acceleration of the J2 field in ECEF (numerics.md E3.12; Groves eq. 2.142):
 * gamma_e = -(GM/r^3) [x (1 + 1.5 J2 (a/r)^2 (1 - 5 z^2/r^2)),
 *                      y (1 + 1.5 J2 (a/r)^2 (1 - 5 z^2/r^2)),
 *                      z (1 + 1.5 J2 (a/r)^2 (3 - 5 z^2/r^2))].
 * @param[in] r_eb_e_m position in ECEF [m]; r = |r_eb_e_m| > 0
 * @return gamma_ib_e_mps2, gravitation (no centrifugal term) resolved in e [m/s^2]. Valid at the
 *         poles; the model is meant for r >= b (exterior field). r = 0 gives non-finite values.
 */
NAV_API nav_vec3 nav_earth_gravitation_j2_e_mps2(nav_vec3 r_eb_e_m);

/**
 * Gravity (gravitation + centrifugal) of the J2 model in ECEF (numerics.md E3.7):
 * g_e = gamma_e - Omega_ie Omega_ie r_e = gamma_e + omega_ie^2 (x, y, 0).
 * @param[in] r_eb_e_m position in ECEF [m]; r > 0
 * @return g_b_e_mps2, gravity of the Earth-fixed point resolved in e [m/s^2]. It is a different
 *         model from the normal gravity (E3.10-11), which also contains J4, J6, ...: on the
 *         ellipsoid the magnitudes differ by up to 1.2e-4 m/s^2 (at the poles, the J4 term;
 *         ~5e-5 at the equator) and the directions by up to 6.3e-6 rad (test_earth measures
 *         both). Never mix the two models between truth and mechanization.
 */
NAV_API nav_vec3 nav_earth_gravity_j2_e_mps2(nav_vec3 r_eb_e_m);

/* ---------------------------------------------------------------- rates */

/**
 * Earth rotation rate resolved in ECEF: omega_ie_e = (0, 0, omega_ie).
 * @return omega_ie_e_rps [rad/s]
 */
NAV_API nav_vec3 nav_earth_rate_e_rps(void);

/**
 * Earth rotation rate resolved in the local NED frame (numerics.md E3.9; Groves 2nd ed., ch. 5):
 * omega_ie_n = omega_ie (cos lat, 0, -sin lat).
 * @param[in] lat_rad geodetic latitude [rad]
 * @return omega_ie_n_rps [rad/s]
 */
NAV_API nav_vec3 nav_earth_rate_n_rps(double lat_rad);

/**
 * Transport rate, the rate of the NED frame with respect to ECEF, resolved in NED
 * (numerics.md E3.9; Groves 2nd ed., ch. 5):
 * omega_en_n = (v_E/(R_N + h), -v_N/(R_M + h), -v_E tan(lat)/(R_N + h)).
 * @param[in] lat_rad  geodetic latitude [rad]; |lat| < pi/2
 * @param[in] h_m      height above the ellipsoid [m]
 * @param[in] v_eb_n_mps velocity of the point with respect to the Earth, resolved in NED [m/s]
 * @return omega_en_n_rps [rad/s]
 *
 * Singular at the poles: the down component grows as tan(lat), and at lat = +/-pi/2 (in double)
 * it is about 1.6e16 v_E/R_N. NED mechanizations must refuse or switch frames when
 * cos(lat) < 1e-6 (numerics.md section 4.4 rule 4).
 */
NAV_API nav_vec3 nav_earth_transport_rate_n_rps(double lat_rad, double h_m, nav_vec3 v_eb_n_mps);

/* ---------------------------------------------------------------- NED frame */

/**
 * Rotation from the local NED frame to ECEF (Groves 2nd ed., ch. 2: the transpose of C_e_n):
 * @code
 *   C_n_e = [ -sin(lat) cos(lon)   -sin(lon)   -cos(lat) cos(lon)
 *             -sin(lat) sin(lon)    cos(lon)   -cos(lat) sin(lon)
 *              cos(lat)             0          -sin(lat)          ]
 * @endcode
 * so v_e = C_n_e v_n for a free vector. Its transpose is C_e_n. At the poles the matrix is still
 * a proper rotation; north then points along the meridian of the given lon.
 * @param[in] lat_rad geodetic latitude [rad]
 * @param[in] lon_rad longitude [rad]
 * @return C_n_e (row-major)
 */
NAV_API nav_mat3 nav_earth_dcm_n_e(double lat_rad, double lon_rad);

/* ---------------------------------------------------------------- local NED about an origin */

/**
 * ECEF point to local NED coordinates about an origin: r_lb_l = C_e_l (r_eb_e - r_el_e), where
 * l is the NED frame at the origin (a point transform: rotation and offset). Exact for any
 * distance (no flat-Earth approximation).
 * @param[in] origin   geodetic position of the origin of l (lat_rad, lon_rad [rad], h_m [m])
 * @param[in] r_eb_e_m the point in ECEF [m]
 * @return r_lb_l_m, the point relative to the origin, resolved in l (north, east, down) [m]
 */
NAV_API nav_vec3 nav_earth_ecef_to_ned(nav_geodetic origin, nav_vec3 r_eb_e_m);

/**
 * Local NED coordinates about an origin to an ECEF point: r_eb_e = r_el_e + C_l_e r_lb_l.
 * @param[in] origin   geodetic position of the origin of l
 * @param[in] r_lb_l_m the point relative to the origin, resolved in l (NED) [m]
 * @return r_eb_e_m, the point in ECEF [m]
 */
NAV_API nav_vec3 nav_earth_ned_to_ecef(nav_geodetic origin, nav_vec3 r_lb_l_m);

/**
 * Geodetic point to local NED coordinates about an origin, exactly through ECEF
 * (nav_earth_geodetic_to_ecef() then nav_earth_ecef_to_ned()).
 * @param[in] origin geodetic position of the origin of l
 * @param[in] p      geodetic position of the point
 * @return r_lb_l_m, the point relative to the origin, resolved in l (NED) [m]. Matches
 *         GeographicLib's LocalCartesian (ENU, converted) to 8 ulp of |r| (7.5 nm; measured
 *         <= 5.6 ulp) at any distance: the error is that of the two ECEF positions, not of the
 *         rotation.
 */
NAV_API nav_vec3 nav_earth_geodetic_to_ned(nav_geodetic origin, nav_geodetic p);

/**
 * Local NED coordinates about an origin to a geodetic point, exactly through ECEF
 * (nav_earth_ned_to_ecef() then nav_earth_ecef_to_geodetic(); same edge cases).
 * @param[in] origin   geodetic position of the origin of l
 * @param[in] r_lb_l_m the point relative to the origin, resolved in l (NED) [m]
 * @return the geodetic position of the point; lon_rad wrapped to (-pi, pi]
 */
NAV_API nav_geodetic nav_earth_ned_to_geodetic(nav_geodetic origin, nav_vec3 r_lb_l_m);

NAV_END_DECLS

#endif /* NAV_EARTH_H */
