/**
 * @file nav_rinex.h
 * @brief navcore_io: RINEX 3.04 observation and navigation records (GPS and GLONASS).
 *
 * The structures are plain data shared by the writer (io/rinex_write.c, navsim run --export
 * rinex) and a reader (navsim replay). Source: RINEX, The Receiver Independent Exchange Format,
 * Version 3.04 (IGS/RTCM-SC104, 23 November 2018), sections 5-6 and Tables A1-A12;
 * docs/rinex.md describes what navsim writes and why.
 *
 * Times: GPS system time as continuous seconds since the GPS epoch ("t_gps_s", as in
 * nav_gnss_sat.h). Observation epochs and GPS navigation records are on the GPS time scale; a
 * GLONASS navigation record's epoch is UTC in the file (RINEX 3.04 Table A11), which the writer
 * derives with nav_rinex_leap_seconds().
 *
 * Units in the structures are SI (the file's km, km/s and km/s^2 of GLONASS records are
 * converted at the file edge).
 */
#ifndef NAV_RINEX_H
#define NAV_RINEX_H

#include <stdbool.h>
#include <stdio.h>

#include "nav_export.h"
#include "nav_gnss_sat.h"
#include "nav_math.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Most observation types per system in a header (RINEX allows more; we keep a small fixed set). */
#define NAV_RINEX_MAX_OBS_TYPES 8
/** Most satellites in one observation epoch. */
#define NAV_RINEX_MAX_EPOCH_SATS NAV_GNSS_MAX_SATS
/** Most GLONASS slots in a "GLONASS SLOT / FRQ #" record. */
#define NAV_RINEX_MAX_GLO_SLOTS 32

/** GPS L1 carrier frequency [Hz] (IS-GPS-200N 3.3.1.1). */
#define NAV_RINEX_GPS_L1_HZ 1575.42e6
/** GLONASS L1 FDMA frequency of channel 0 and its channel spacing [Hz] (ICD GLONASS Ed. 5.1,
 *  3.3.1.4): f = 1602 MHz + k 0.5625 MHz. */
#define NAV_RINEX_GLO_L1_HZ 1602.0e6
#define NAV_RINEX_GLO_L1_STEP_HZ 0.5625e6

/** A calendar date and time of day (on whatever time scale the context says). */
typedef struct nav_rinex_date {
  int year, month, day, hour, minute;
  double second; /**< [0, 60) */
} nav_rinex_date;

/** The calendar date of continuous time @p t_s counted from 1980-01-06 00:00:00 (no leap
 *  seconds on that scale: GPS time gives the GPS calendar date). Leaf. */
NAV_API nav_rinex_date nav_rinex_date_from_gps(double t_s);

/** GPS - UTC [s] at GPS time @p t_gps_s (IERS Bulletin C leap seconds from 1981-07-01 to
 *  2017-01-01; 18 s since then). Leaf. */
NAV_API int nav_rinex_leap_seconds(double t_gps_s);

/** The L1 C/A carrier frequency [Hz] of a satellite: GPS L1, or GLONASS L1 for channel @p k. */
NAV_API double nav_rinex_l1_hz(nav_gnss_system sys, int glo_channel);

/** GLONASS frequency channel (-7..6) of nominal slot 1..24, the assignment antipodal pairs
 *  share (slots n and n + 4 of a plane); 0 outside 1..24. docs/rinex.md gives the table's
 *  source. Leaf. */
NAV_API int nav_rinex_glonass_nominal_channel(int slot);

/* ======================================================================== observation file */

/** Observation-file header (RINEX 3.04 Table A2), the records navsim uses. */
typedef struct nav_rinex_obs_header {
  char marker_name[61];         /**< MARKER NAME */
  char program[21];             /**< PGM / RUN BY / DATE: program */
  char run_by[21];              /**< PGM / RUN BY / DATE: run by */
  char date[21];                /**< PGM / RUN BY / DATE: creation date "yyyymmdd hhmmss UTC" */
  char receiver_type[21];       /**< REC # / TYPE / VERS: type */
  char antenna_type[21];        /**< ANT # / TYPE: type */
  nav_vec3 approx_pos_e_m;      /**< APPROX POSITION XYZ, ECEF [m] */
  nav_vec3 antenna_delta_hen_m; /**< ANTENNA: DELTA H/E/N [m] */
  /** SYS / # / OBS TYPES per system (index nav_gnss_system): n_types[s] = 0 leaves the system
   *  out; types are three-character codes ("C1C", "L1C", "D1C", "S1C"). */
  int n_types[NAV_GNSS_SYS_COUNT];
  char types[NAV_GNSS_SYS_COUNT][NAV_RINEX_MAX_OBS_TYPES][4];
  double interval_s;    /**< INTERVAL [s]; <= 0: record omitted */
  double t_first_gps_s; /**< TIME OF FIRST OBS (GPS time scale) */
  int leap_seconds;     /**< LEAP SECONDS (GPS - UTC) [s] */
  /** GLONASS SLOT / FRQ #: slot (1..24) and frequency channel (-7..6) of every GLONASS
   *  satellite in the file. */
  int n_glo;
  int glo_slot[NAV_RINEX_MAX_GLO_SLOTS];
  int glo_channel[NAV_RINEX_MAX_GLO_SLOTS];
} nav_rinex_obs_header;

/** One satellite's observations at an epoch, in the order of its system's header types. */
typedef struct nav_rinex_obs_sat {
  nav_gnss_system system;
  int prn;                               /**< GPS PRN / GLONASS slot */
  bool has[NAV_RINEX_MAX_OBS_TYPES];     /**< false: blank field */
  double value[NAV_RINEX_MAX_OBS_TYPES]; /**< C [m], L [cycles], D [Hz], S [dB-Hz] */
} nav_rinex_obs_sat;

/** One observation epoch (RINEX 3.04 Table A3, epoch flag 0). */
typedef struct nav_rinex_obs_epoch {
  double t_gps_s; /**< receiver time of the epoch, GPS time scale */
  int n;          /**< satellites, 0..NAV_RINEX_MAX_EPOCH_SATS */
  nav_rinex_obs_sat sats[NAV_RINEX_MAX_EPOCH_SATS];
} nav_rinex_obs_epoch;

/* ======================================================================== navigation file */

/** GPS LNAV broadcast ephemeris (RINEX 3.04 Table A8; IS-GPS-200N Table 20-III). */
typedef struct nav_rinex_gps_eph {
  int prn;
  double toc_gps_s; /**< clock reference time (record epoch; whole seconds) */
  double af0_s, af1_sps, af2_sps2;
  int iode;
  double crs_m, delta_n_rps, m0_rad;
  double cuc_rad, e, cus_rad, sqrt_a_sqrtm;
  double toe_gps_s; /**< ephemeris reference time (file: seconds of week + week) */
  double cic_rad, omega0_rad, cis_rad;
  double i0_rad, crc_m, w_rad, omega_dot_rps;
  double idot_rps;
  int l2_codes, l2p_flag;
  double sv_accuracy_m;
  int health;
  double tgd_s;
  int iodc;
  double t_tx_gps_s; /**< transmission time of message */
  double fit_interval_h;
} nav_rinex_gps_eph;

/** GLONASS ephemeris: the satellite's PZ-90 state at tb (RINEX 3.04 Table A11). */
typedef struct nav_rinex_glo_eph {
  int slot;
  double tb_gps_s;     /**< reference time tb on the GPS scale (the file holds it as UTC) */
  double clock_bias_s; /**< SV clock bias -TauN [s] (satellite time minus system time) */
  double gamma_n;      /**< relative frequency bias GammaN */
  double tk_gps_s;     /**< message frame time on the GPS scale (file: seconds of UTC week) */
  nav_vec3 r_e_m;      /**< position at tb [m] */
  nav_vec3 v_e_mps;    /**< velocity at tb [m/s] */
  nav_vec3 a_e_mps2;   /**< the luni-solar acceleration term at tb [m/s^2] */
  int health;
  int channel; /**< frequency number -7..13 */
  int age_d;   /**< age of operation information [days] */
} nav_rinex_glo_eph;

/** Navigation-file header (RINEX 3.04 Table A5), the records navsim writes. */
typedef struct nav_rinex_nav_header {
  char program[21], run_by[21], date[21];
  int leap_seconds; /**< LEAP SECONDS (GPS - UTC) [s] */
} nav_rinex_nav_header;

/* ======================================================================== conversions (leaf) */

/**
 * The broadcast ephemeris equivalent to @p o (harmonic corrections zero, TGD 0) referred to
 * toe = toc = @p toe_gps_s: M0, i0, Omega0 and af0 are propagated from the orbit's own toe with
 * the IS-GPS-200N Table 20-IV rates (docs/rinex.md), so that the user algorithm gives the same
 * positions as nav_gnss_orbit_state(). @p iode labels the record (0..255).
 */
NAV_API nav_rinex_gps_eph nav_rinex_gps_eph_from_orbit(const nav_gnss_orbit *o, double toe_gps_s, int iode);

/** The GPS satellite clock offset dt_sv [s] at GPS time @p t_gps_s (IS-GPS-200N 20.3.3.3.3.1:
 *  af0 + af1 (t - toc) + af2 (t - toc)^2 + F e sqrt(A) sin E_k, minus TGD when @p with_tgd). */
NAV_API double nav_rinex_gps_clock_s(const nav_rinex_gps_eph *e, double t_gps_s, bool with_tgd);

/** The acceleration of a GLONASS satellite at ECEF position @p r_m [m] with velocity @p v_mps [m/s]
 * in the rotating PZ-90 frame under the ICD force model (ICD GLONASS Edition 5.1, 2008, A.3.1.2:
 * central body, J2 zonal term, centrifugal and Coriolis terms; PZ-90 constants of 3.1.3), without
 * the luni-solar term a record carries [m/s^2]. The writer fits records to it and the reader
 * integrates records with it. */
NAV_API nav_vec3 nav_rinex_glo_force(nav_vec3 r_m, nav_vec3 v_mps);

/**
 * The GLONASS record of @p o at tb = @p tb_gps_s: position and velocity from
 * nav_gnss_orbit_state(), and as acceleration term the difference between the orbit's true ECEF
 * acceleration and the ICD GLONASS (Ed. 5.1, A.3.1.2) force model (central body, J2, rotating
 * frame) at that state, so that a receiver integrating the ICD equations from tb follows the
 * orbit closely for short intervals. With @p half_span_s = T > 0 the velocity is tilted so that
 * the linear drift of that difference is balanced over [tb - T, tb + T] (the record then serves
 * that interval best). docs/rinex.md measures the agreement.
 */
NAV_API nav_rinex_glo_eph nav_rinex_glo_eph_from_orbit(const nav_gnss_orbit *o, double tb_gps_s, int channel,
                                                       double half_span_s);

/** The GLONASS satellite clock offset [s] at @p t_gps_s: clock_bias_s + gamma_n (t - tb). */
NAV_API double nav_rinex_glo_clock_s(const nav_rinex_glo_eph *e, double t_gps_s);

/* ======================================================================== writing */

/**
 * Write an observation-file header (RINEX 3.04, mixed file "M" when both systems have types).
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, no system with types, a type not three
 *         characters of [A-Z0-9], more than NAV_RINEX_MAX_OBS_TYPES, a non-finite number, a
 *         GLONASS slot or channel out of range); NAV_ERR_IO (write failed).
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_write_header(FILE *f, const nav_rinex_obs_header *h);

/**
 * Write one observation epoch (flag 0) whose values follow @p h's types. Values are written
 * F14.3; |value| >= 1e10 does not fit and is NAV_ERR_OUT_OF_RANGE.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, n out of range, a satellite of a system without
 *         types, a PRN out of 1..99, non-finite value or time); NAV_ERR_OUT_OF_RANGE; NAV_ERR_IO.
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_write_epoch(FILE *f, const nav_rinex_obs_header *h,
                                                           const nav_rinex_obs_epoch *ep);

/** Write a mixed navigation-file header (RINEX 3.04 "N", "M").
 *  @return NAV_OK; NAV_ERR_INVALID_ARG (NULL); NAV_ERR_IO. */
NAV_API NAV_NODISCARD nav_status nav_rinex_nav_write_header(FILE *f, const nav_rinex_nav_header *h);

/** Write a GPS record (epoch line and seven broadcast-orbit lines, D19.12 fields written with
 *  an 'E' exponent). @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, PRN out of 1..99, non-finite);
 *  NAV_ERR_IO. */
NAV_API NAV_NODISCARD nav_status nav_rinex_nav_write_gps(FILE *f, const nav_rinex_gps_eph *e);

/** Write a GLONASS record (epoch line in UTC with @p leap_seconds, three broadcast-orbit lines
 *  in km, km/s, km/s^2). @return as nav_rinex_nav_write_gps(). */
NAV_API NAV_NODISCARD nav_status nav_rinex_nav_write_glonass(FILE *f, const nav_rinex_glo_eph *e,
                                                             int leap_seconds);

NAV_END_DECLS

#endif /* NAV_RINEX_H */
