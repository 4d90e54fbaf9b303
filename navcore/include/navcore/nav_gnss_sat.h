/**
 * @file nav_gnss_sat.h
 * GNSS satellite constellations (GPS, GLONASS): orbits from almanacs or from the published nominal
 * constellations, satellite ECEF positions and velocities, visibility (elevation mask, per-azimuth
 * sky mask, street-canyon walls) and dilution of precision. Pure maths: parsing almanac files is
 * navcore_io's (nav_io.h, nav_gnss_almanac_read_yuma). docs/gnss-constellations.md gives the
 * formulas, constants and sources.
 *
 * Time: every time here is GPS system time as continuous seconds since the GPS epoch
 * (1980-01-06 00:00:00 GPS), "t_gps_s". GPS week w, second of week s: t = 604800 w + s.
 */
#ifndef NAV_GNSS_SAT_H
#define NAV_GNSS_SAT_H

#include <stdbool.h>

#include "navcore/nav_earth.h"
#include "navcore/nav_math.h"
#include "navcore/nav_status.h"

NAV_BEGIN_DECLS

/** Most satellites in one constellation object. */
#define NAV_GNSS_MAX_SATS 64

/** Seconds in a GPS week (IS-GPS-200N 20.3.3.4.3). */
#define NAV_GNSS_WEEK_S 604800.0

/** WGS-84 gravitational constant used by GPS receivers, mu [m^3/s^2] (IS-GPS-200N 20.3.3.4.3.1). */
#define NAV_GPS_MU_M3PS2 3.986005e14
/** WGS-84 Earth rotation rate used by GPS receivers [rad/s] (IS-GPS-200N 20.3.3.4.3.1). */
#define NAV_GPS_OMEGA_E_RPS 7.2921151467e-5

typedef enum nav_gnss_system {
  NAV_GNSS_SYS_GPS = 0,
  NAV_GNSS_SYS_GLONASS = 1
} nav_gnss_system;

/** Number of ::nav_gnss_system values. */
#define NAV_GNSS_SYS_COUNT 2

/**
 * One satellite orbit in the parameterisation of the GPS almanac / ephemeris without harmonic
 * corrections (IS-GPS-200N Table 20-VI almanac parameters, propagated with the user algorithm of
 * Table 20-IV). The nominal constellations (GPS SPS PS, GLONASS ICD) are expressed in the same
 * form, exactly (circular orbits with delta_n setting the rate of the argument of latitude).
 */
typedef struct nav_gnss_orbit {
  nav_gnss_system system;
  int prn;              /**< GPS PRN (1..32) or GLONASS slot (1..24) */
  int health;           /**< 0 = healthy; unhealthy satellites are never visible */
  double toe_s;         /**< reference time (toa of an almanac), GPS seconds since the GPS epoch */
  double sqrt_a_sqrtm;  /**< square root of the semi-major axis [m^0.5] */
  double e;             /**< eccentricity */
  double i0_rad;        /**< inclination at toe [rad] */
  double idot_rps;      /**< rate of inclination [rad/s] */
  /** Omega_0: longitude of the ascending node of the orbit plane at the start of the GPS week of
   *  toe (IS-GPS-200N Table 20-III/20-VI "Right Ascen at Week") [rad] */
  double omega0_rad;
  double omega_dot_rps; /**< rate of right ascension [rad/s] */
  double w_rad;         /**< argument of perigee [rad] */
  double m0_rad;        /**< mean anomaly at toe [rad] */
  double delta_n_rps;   /**< mean motion difference from sqrt(mu/A^3) [rad/s] (0 for almanacs) */
  double af0_s;         /**< satellite clock bias [s] */
  double af1_sps;       /**< satellite clock drift [s/s] */
  /** Harmonic corrections of a broadcast ephemeris (IS-GPS-200N Table 20-III, e.g. read from a
   *  RINEX navigation file): amplitudes of the cosine and sine terms of twice the argument of
   *  latitude in the argument of latitude [rad], the orbit radius [m] and the inclination [rad].
   *  0 for almanacs and the nominal constellations. */
  double cuc_rad, cus_rad, crc_m, crs_m, cic_rad, cis_rad;
} nav_gnss_orbit;

/** A set of satellites (any mix of systems). Plain data. */
typedef struct nav_gnss_constellation {
  int n;
  nav_gnss_orbit sats[NAV_GNSS_MAX_SATS];
} nav_gnss_constellation;

/**
 * GPS time of a calendar date and time of day (proleptic Gregorian calendar, no leap seconds:
 * the date is read on the GPS time scale). Leaf maths; any date (before 1980 gives t < 0).
 */
NAV_API double nav_gnss_gps_time_s(int year, int month, int day, int hour, int minute, double second);

/**
 * Satellite position and velocity in ECEF (WGS-84 frame of the GPS user algorithm) at GPS time
 * @p t_gps_s, with the user algorithm of IS-GPS-200N Table 20-IV (Kepler equation solved by
 * Newton iteration to 1e-15 rad) and its velocity equations (Table 20-IV, "SV velocity"), with
 * the harmonic corrections when the orbit has any (broadcast ephemerides; an almanac has none). t_k = t - toe is not wrapped: toe_s is a
 * continuous time. Leaf maths.
 * @param[out] r_es_e_m   position of the satellite [m]
 * @param[out] v_es_e_mps velocity relative to ECEF, resolved in ECEF [m/s]
 */
NAV_API void nav_gnss_orbit_state(const nav_gnss_orbit *orbit, double t_gps_s, nav_vec3 *r_es_e_m,
                                  nav_vec3 *v_es_e_mps);

/**
 * Append the GPS baseline 24-slot constellation of the SPS Performance Standard (4th edition,
 * 2008, Table 3.1-1 slots A1..F4; RAAN and argument of latitude as of 1993-07-01 00:00 UTC,
 * Greenwich hour angle 18 h 36 min 14.4 s; circular orbits, semi-major axis 26 559.7 km,
 * inclination 55 deg) propagated to @p t_gps_s with ground tracks repeating (stationkeeping,
 * docs/gnss-constellations.md 2.2). PRN numbers 1..24 in slot order A1..F4.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, non-finite time); NAV_ERR_OUT_OF_RANGE (no room).
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_add_gps_nominal(nav_gnss_constellation *c, double t_gps_s);

/**
 * Append the GLONASS nominal 24-slot constellation (ICD GLONASS Edition 5.1, 2008, section 3.5:
 * 3 planes 120 deg apart in longitude of the ascending node, 8 slots per plane 45 deg apart in
 * argument of latitude, 15 deg between planes, inclination 64.8 deg, draconian period
 * 11 h 15 min 44 s) at @p t_gps_s, where plane 1's node has longitude @p node1_lon_rad and slot 1
 * has argument of latitude 0 (the ICD fixes spacings, not this absolute phase). Nodal regression
 * from the J2 term of PZ-90 (docs/gnss-constellations.md 2.3).
 * @return as nav_gnss_add_gps_nominal().
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_add_glonass_nominal(nav_gnss_constellation *c, double t_gps_s,
                                                              double node1_lon_rad);

/** Most points of a per-azimuth sky mask. */
#define NAV_GNSS_MASK_MAX_POINTS 36

/**
 * Sky mask: satellites must be above max(elevation mask, azimuth profile, canyon walls).
 * - profile: elevation mask as a function of the true azimuth (from north, clockwise), piecewise
 *   linear between points sorted by azimuth, wrapping at 360 deg; none when n_profile = 0.
 * - canyon: two vertical walls parallel to the direction of travel, at horizontal distances
 *   canyon_left_m and canyon_right_m from the antenna, canyon_height_m above it; a satellite at
 *   azimuth alpha relative to the heading is masked below atan(H |sin alpha| / d) on its side
 *   (an infinitely long straight street). Off when canyon_height_m <= 0.
 */
typedef struct nav_gnss_sky_mask {
  double elevation_mask_rad;
  int n_profile;
  double profile_az_rad[NAV_GNSS_MASK_MAX_POINTS];
  double profile_el_rad[NAV_GNSS_MASK_MAX_POINTS];
  double canyon_height_m;
  double canyon_left_m;
  double canyon_right_m;
} nav_gnss_sky_mask;

/** The elevation below which the mask hides a satellite at true azimuth @p az_rad for a receiver
 *  heading @p heading_rad (both from north, clockwise). Leaf maths. */
NAV_API double nav_gnss_mask_elevation_rad(const nav_gnss_sky_mask *mask, double az_rad, double heading_rad);

/** Azimuth (from north, clockwise, [0, 2 pi)) and elevation of a satellite seen from a receiver
 *  (local-level NED at the receiver's geodetic position). Leaf maths. */
NAV_API void nav_gnss_az_el(nav_geodetic rx, nav_vec3 r_es_e_m, double *az_rad, double *el_rad);

/** One satellite in view. */
typedef struct nav_gnss_sat_view {
  nav_gnss_system system;
  int prn;
  double az_rad;       /**< azimuth from north, clockwise [rad] */
  double el_rad;       /**< elevation [rad] */
  bool visible;        /**< healthy, above the horizon and the mask */
  nav_vec3 r_es_e_m;   /**< satellite position at the receive time (no light-time) [m] */
  nav_vec3 v_es_e_mps; /**< satellite velocity [m/s] */
} nav_gnss_sat_view;

/** Dilution of precision of a set of lines of sight (NED). */
typedef struct nav_gnss_dop {
  int n_visible; /**< satellites used */
  bool valid;    /**< geometry solvable: n_visible >= 3 + number of systems and G'G invertible */
  double gdop, pdop, hdop, vdop, tdop; /**< NaN when !valid */
} nav_gnss_dop;

/**
 * DOP of @p n lines of sight given by azimuth/elevation, with one receiver clock unknown per
 * system present (column k of G is 1 for satellites of the k-th system present; Kaplan and
 * Hegarty, Understanding GPS/GNSS, 3rd ed., section 11.2.1, eq. 11.34-11.40, extended per system):
 * G row = [-cos el cos az, -cos el sin az, sin el, clock columns], Q = (G'G)^-1 in NED,
 * GDOP = sqrt(tr Q), PDOP = sqrt(QNN + QEE + QDD), HDOP = sqrt(QNN + QEE), VDOP = sqrt(QDD),
 * TDOP = sqrt(sum of the clock diagonal).
 */
NAV_API nav_gnss_dop nav_gnss_dop_compute(int n, const double *az_rad, const double *el_rad,
                                          const nav_gnss_system *sys);

/**
 * Every satellite of @p c as seen from @p rx at @p t_gps_s with heading @p heading_rad, and the DOP
 * of the visible ones. @p views has room for c->n entries (may be NULL).
 * @return NAV_OK or NAV_ERR_INVALID_ARG (NULL c/mask/dop, non-finite input).
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_visibility(const nav_gnss_constellation *c, const nav_gnss_sky_mask *mask,
                                                     double t_gps_s, nav_geodetic rx, double heading_rad,
                                                     nav_gnss_sat_view *views, nav_gnss_dop *dop);

/* ======================================================================== scene configuration */

/** Source of a system's orbits in a scene (gnss.constellation.gps / .glonass). */
typedef enum nav_gnss_source {
  NAV_GNSS_SOURCE_OFF = 0,
  NAV_GNSS_SOURCE_NOMINAL = 1, /**< the published nominal 24-slot constellation at the epoch */
  NAV_GNSS_SOURCE_ALMANAC = 2  /**< GPS only: the almanac file (YUMA) */
} nav_gnss_source;

/** Most street-canyon intervals of a scene. */
#define NAV_GNSS_MAX_CANYONS 16
/** Longest almanac path kept in a scene (bytes with the NUL). */
#define NAV_GNSS_ALMANAC_PATH_MAX 1024

/** A street canyon driven through from t0_s to t1_s (scene time): walls along the direction of
 *  travel (nav_gnss_sky_mask canyon_*). */
typedef struct nav_gnss_canyon {
  double t0_s, t1_s;
  double height_m; /**< wall height above the antenna [m], > 0 */
  double left_m;   /**< horizontal distance to the left wall [m], > 0 */
  double right_m;  /**< horizontal distance to the right wall [m], > 0 */
} nav_gnss_canyon;

/**
 * The receiver's raw measurements (pseudorange and range rate) as the tightly coupled scheme
 * (navigation.scheme: ins_gnss_tight) simulates and models them (docs/ins-gnss-tight.md 2):
 * white code and range-rate noise, a two-state receiver clock from the oscillator's power-law
 * (Allan) coefficients h_0 and h_-2, and a constant GLONASS - GPS inter-system bias.
 */
typedef struct nav_gnss_raw_config {
  double code_sd_m;          /**< white pseudorange noise, 1 sigma [m], > 0 (default 3) */
  double range_rate_sd_mps;  /**< white range-rate (Doppler) noise, 1 sigma [m/s], > 0 (default 0.1) */
  double clock_h0_s;         /**< white frequency noise coefficient h_0 [s], >= 0 (default 2e-19, TCXO) */
  double clock_hm2_per_s;    /**< random-walk frequency coefficient h_-2 [1/s], >= 0 (default 2e-20, TCXO) */
  double clock_bias_sd_m;    /**< receiver clock bias c dt_r at t = 0, 1 sigma [m], > 0 (default 100) */
  double clock_drift_sd_mps; /**< clock drift c dt_r' at t = 0, 1 sigma [m/s], > 0 (default 10) */
  double isb_sd_m;           /**< GLONASS - GPS inter-system bias, 1 sigma [m], > 0 (default 10) */
} nav_gnss_raw_config;

/** Where the loosely coupled scheme (ins_gnss) takes its fixes from when a constellation is set. */
typedef enum nav_gnss_fix_source {
  NAV_GNSS_FIXES_MODEL = 0, /**< the receiver model (white + Gauss-Markov position/velocity noise) */
  NAV_GNSS_FIXES_PVT = 1    /**< least-squares PVT of the simulated pseudoranges and range rates */
} nav_gnss_fix_source;

/** The satellite constellation along a scene's trajectory (scene section gnss.constellation). */
typedef struct nav_gnss_constellation_config {
  bool enabled;                 /**< the section is present */
  nav_gnss_source gps;          /**< OFF, NOMINAL (default) or ALMANAC */
  nav_gnss_source glonass;      /**< OFF (default) or NOMINAL */
  double epoch_gps_s;           /**< GPS time of scene time 0 (GPS seconds since 1980-01-06) */
  double glonass_node1_lon_rad; /**< nav_gnss_add_glonass_nominal() node1_lon_rad */
  /** Elevation mask and per-azimuth profile; its canyon fields are unused here (see canyons). */
  nav_gnss_sky_mask mask;
  int n_canyons;
  nav_gnss_canyon canyons[NAV_GNSS_MAX_CANYONS]; /**< non-overlapping intervals */
  /** The receiver model of the integrated schemes (gnss.enabled) gives no fix at an epoch where
   *  fewer satellites are visible (outages added by the simulation); 0: fixes do not depend on
   *  the constellation. Default 4. */
  int min_satellites_for_fix;
  /** Raw measurements of the tightly coupled scheme (ins_gnss_tight), and of the PVT fixes. */
  nav_gnss_raw_config raw;
  /** ins_gnss: fixes from the receiver model (default) or the least-squares PVT of the raw
   *  measurements (no fix below 3 + number of systems satellites). */
  nav_gnss_fix_source fixes;
  /** ALMANAC: the YUMA file (navcore_io stores the resolved path) and its satellites (loaded by
   *  navcore_io when the scene is read). */
  char almanac_file[NAV_GNSS_ALMANAC_PATH_MAX];
  nav_gnss_constellation almanac;
} nav_gnss_constellation_config;

/** Disabled; when enabled: GPS nominal, GLONASS off, epoch 2026-01-01 00:00 GPS, 10 deg mask;
 *  raw measurements as nav_gnss_raw_config documents. */
NAV_API nav_gnss_constellation_config nav_gnss_constellation_config_default(void);

/** Validation callback (the same signature as nav_scene_issue_fn). */
typedef void (*nav_gnss_issue_fn)(void *user, const char *path, const char *message);

/**
 * Check a constellation configuration; @p report receives paths relative to the section
 * ("elevation_mask_deg", "canyons[2]", ...). @return NAV_OK or NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_constellation_config_validate(const nav_gnss_constellation_config *cfg,
                                                                        nav_gnss_issue_fn report, void *user);

/** The satellites of a configuration (nominal constellations at its epoch, almanac satellites).
 *  @return NAV_OK; NAV_ERR_INVALID_ARG; NAV_ERR_OUT_OF_RANGE (more than NAV_GNSS_MAX_SATS). */
NAV_API NAV_NODISCARD nav_status nav_gnss_constellation_build(const nav_gnss_constellation_config *cfg,
                                                              nav_gnss_constellation *out);

/** The sky mask at scene time @p t_s: the configured mask plus the walls of the canyon whose
 *  interval [t0_s, t1_s) contains t_s. Leaf. */
NAV_API nav_gnss_sky_mask nav_gnss_constellation_mask_at(const nav_gnss_constellation_config *cfg, double t_s);

/* ======================================================================== pseudoranges and PVT */

/** Speed of light [m/s] (IS-GPS-200N 20.3.4.3). */
#define NAV_GNSS_C_MPS 299792458.0

/**
 * Geometric range from satellite @p o to a receiver at @p r_rx_e_m at true receive time @p t_rx_s:
 * the signal leaves at t_tx = t_rx - rho / c (fixed-point iteration to 1e-12 s) and the satellite
 * position is rotated by the Earth's rotation during the flight (Sagnac; IS-GPS-200N 20.3.3.4.3.4,
 * Kaplan and Hegarty 3rd ed. eq. 2.40 form: R3(omega_e tau) r_s). Leaf maths.
 * @param[out] r_es_e_m the satellite position at t_tx in the ECEF frame of t_rx (may be NULL)
 * @return rho [m]
 */
NAV_API double nav_gnss_geometric_range_m(const nav_gnss_orbit *o, double t_rx_s, nav_vec3 r_rx_e_m,
                                          nav_vec3 *r_es_e_m);

/** One pseudorange: the satellite and the measured code range P = rho + c dt_r + e [m]. */
typedef struct nav_gnss_pseudorange {
  const nav_gnss_orbit *sat;
  double p_m;
} nav_gnss_pseudorange;

/** A least-squares position fix. */
typedef struct nav_gnss_pvt {
  nav_vec3 r_e_m;             /**< receiver position, ECEF [m] */
  double clock_m[NAV_GNSS_SYS_COUNT]; /**< receiver clock bias c dt_r per system present [m] */
  int n_used;
  int iterations;
  nav_gnss_dop dop;           /**< DOP at the solution */
  nav_vec3 dop_ned;           /**< per-axis DOP: sqrt of Q's north, east, down diagonal */
  double q_ned[3][3];         /**< Q's north/east/down block (position covariance = code sigma^2 Q) */
  double residual_rms_m;      /**< RMS of the post-fit residuals [m] */
} nav_gnss_pvt;

/**
 * Single-point position from pseudoranges taken at receiver-clock time @p t_rx_s (Gauss-Newton,
 * unweighted, one clock unknown per system; Kaplan and Hegarty 3rd ed. section 11.2): each
 * satellite's position is evaluated at t_rx - P / c (which is the true transmit time whatever the
 * receiver clock bias) and rotated by the Earth's rotation during rho / c. Starts from the Earth's
 * centre; stops when the correction is below 1e-4 m (at most 20 iterations).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, n < 3 + systems, non-finite input);
 *         NAV_ERR_NOT_CONVERGED; NAV_ERR_NUMERIC (singular geometry).
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_pvt_solve(int n, const nav_gnss_pseudorange *pr, double t_rx_s,
                                                    nav_gnss_pvt *out);

/**
 * The north/east/down block of (G'G)^-1 for @p n lines of sight (azimuth/elevation, NED rows of
 * nav_gnss_dop_compute()), with one clock column per system present (@p one_clock false: the
 * position fix) or a single clock column (true: the velocity fix, whose unknown is the common
 * drift). The fix's covariance is sigma^2 times it. Leaf.
 * @return false (q_ned untouched) for a singular geometry or too few lines of sight.
 */
NAV_API bool nav_gnss_cofactor_ned(int n, const double *az_rad, const double *el_rad, const nav_gnss_system *sys,
                                   bool one_clock, double q_ned[3][3]);

/** One range rate: the satellite and the measured rate rr = rho_dot + c dt_r' + e [m/s]. */
typedef struct nav_gnss_range_rate {
  const nav_gnss_orbit *sat;
  double rr_mps;
} nav_gnss_range_rate;

/** A least-squares velocity fix. */
typedef struct nav_gnss_pvt_vel {
  nav_vec3 v_n_mps;   /**< receiver velocity, NED at the position fix [m/s] */
  double drift_mps;   /**< receiver clock drift c dt_r' [m/s] (one for all systems) */
  nav_vec3 dop_ned;   /**< per-axis DOP of the velocity solution (sqrt of (H'H)^-1 diagonal) */
  double q_ned[3][3]; /**< (H'H)^-1, velocity block (covariance = range-rate sigma^2 Q) */
} nav_gnss_pvt_vel;

/**
 * Velocity from range rates at the position @p pos (from nav_gnss_pvt_solve() at the same
 * @p t_rx_s), linear least squares: rr_i = u_i' (v_s,i - v) / (1 + u_i' v_s,i / c) + d, unknowns v
 * (NED) and one clock drift d (the inter-system bias is constant, so both systems share the drift).
 * Satellite velocities at the transmit time, rotated like the positions (Sagnac). Needs 4 rates.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, n < 4, non-finite input); NAV_ERR_NUMERIC (singular).
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_pvt_velocity(int n, const nav_gnss_range_rate *rr, double t_rx_s,
                                                       const nav_gnss_pvt *pos, nav_gnss_pvt_vel *out);

NAV_END_DECLS

#endif /* NAV_GNSS_SAT_H */
