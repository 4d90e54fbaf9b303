/**
 * @file nav_rinex_read.h
 * @brief navcore_io: reading RINEX 3 observation and navigation files (GPS and GLONASS), and
 *        the raw-measurement source of a tightly coupled replay (docs/rinex.md, "Reading and
 *        replay").
 *
 * Standard: RINEX, The Receiver Independent Exchange Format, Version 3.04 (IGS/RTCM-SC104,
 * 2018), section 5 (header labels in columns 61-80), Tables A1-A4 (observation file), A5-A6 and
 * A9-A11 (navigation file: GPS LNAV and GLONASS records). Versions 3.00 to 3.05 are accepted
 * (3.05 adds a fourth broadcast-orbit line to GLONASS records; it is read and ignored).
 *
 * Observation files: the observation types of each system (SYS / # / OBS TYPES), the epoch
 * records ('>' lines, epoch flags 0-6), and of GPS (G) and GLONASS (R) satellites the C1C code
 * pseudorange [m], D1C Doppler [Hz] and S1C signal strength [dB-Hz]. Other systems and other
 * types are skipped and counted (nav_rinex_obs_header.skipped_*). Epoch time must be GPS time
 * (TIME OF FIRST OBS time system GPS, or blank in a GPS file).
 *
 * Navigation files: GPS LNAV records (8 lines: SV / EPOCH / SV CLK and 7 BROADCAST ORBIT lines)
 * and GLONASS records (4 lines, 5 in version 3.05); records of other systems are skipped and
 * counted. GLONASS record epochs are UTC; they are turned into GPS time with LEAP SECONDS of the
 * header (18 s if the header has none: the value since 2017-01-01).
 *
 * Errors: any problem is one nav_diag "FILE:LINE:COL: error: what is wrong and what is
 * expected" with COL the 1-based column of the offending field; NAV_ERR_PARSE. Limits: lines of
 * at most NAV_RINEX_MAX_LINE bytes, NAV_RINEX_MAX_TYPES observation types per system,
 * NAV_RINEX_MAX_EPOCH_SATS GPS + GLONASS satellites per epoch, NAV_RINEX_MAX_EPHEMERIDES
 * navigation records. The observation reader streams (memory does not grow with the file); the
 * navigation reader keeps every GPS and GLONASS record.
 *
 * Objects are not synchronised: one thread per reader.
 */
#ifndef NAV_RINEX_READ_H
#define NAV_RINEX_READ_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_export.h"
#include "nav_gnss_sat.h"
#include "nav_ins_gnss.h"
#include "nav_io.h"
#include "nav_math.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Longest accepted line in bytes, line end excluded (an epoch line of 64 types is 1027). */
#define NAV_RINEX_MAX_LINE 2048
/** Most observation types of one system. */
#define NAV_RINEX_MAX_TYPES 64
/** Most GPS + GLONASS satellites kept from one epoch record. */
#define NAV_RINEX_MAX_EPOCH_SATS NAV_GNSS_MAX_SATS
/** Most GPS + GLONASS navigation records of one file (a week of 32 GPS satellites every 2 h and
 *  24 GLONASS satellites every 30 min is 11 000). */
#define NAV_RINEX_MAX_EPHEMERIDES 100000
/** GPS L1 carrier frequency [Hz] (IS-GPS-200N 3.3.1.1). */
#define NAV_GPS_L1_HZ 1575.42e6
/** GLONASS L1 FDMA carrier frequency of channel k: 1602 MHz + k 0.5625 MHz (ICD GLONASS 5.1,
 *  3.3.1.4). */
#define NAV_GLO_L1_BASE_HZ 1602.0e6
#define NAV_GLO_L1_STEP_HZ 0.5625e6

/* ================================================================ observation files */

/** What an observation file's header says (the part the reader uses). */
typedef struct nav_rinex_obs_header {
  double version;            /**< e.g. 3.04 */
  char system;               /**< satellite system of the file: 'G', 'R', 'M' (mixed), ... */
  char marker[61];           /**< MARKER NAME ("" if none) */
  bool has_approx_pos;       /**< APPROX POSITION XYZ given */
  nav_vec3 approx_pos_e_m;   /**< APPROX POSITION XYZ, ECEF [m] */
  nav_vec3 antenna_hen_m;    /**< ANTENNA: DELTA H/E/N [m] (0 if none) */
  bool has_interval;         /**< INTERVAL given */
  double interval_s;         /**< INTERVAL [s] */
  bool has_first;            /**< TIME OF FIRST OBS given */
  double t_first_gps_s;      /**< TIME OF FIRST OBS, GPS seconds since the GPS epoch */
  /** Observation types of GPS ([0]) and GLONASS ([1]) in file order ("C1C", ...); n_types 0 if
   *  the file has none for the system. */
  int n_types[NAV_GNSS_SYS_COUNT];
  char types[NAV_GNSS_SYS_COUNT][NAV_RINEX_MAX_TYPES][4];
  /** Index of C1C, D1C, S1C in types[sys], or -1. */
  int idx_c1c[NAV_GNSS_SYS_COUNT], idx_d1c[NAV_GNSS_SYS_COUNT], idx_s1c[NAV_GNSS_SYS_COUNT];
  /** GLONASS SLOT / FRQ #: frequency channel k of slot s (1..24) in glo_k[s], valid where
   *  glo_has_k[s]. */
  bool glo_has_k[25];
  int glo_k[25];
  int skipped_systems;       /**< SYS / # / OBS TYPES records of systems other than G and R */
} nav_rinex_obs_header;

/** One satellite of an epoch: the kept observations (C1C, D1C, S1C). */
typedef struct nav_rinex_obs_sat {
  nav_gnss_system system;
  int prn;            /**< GPS PRN or GLONASS slot */
  bool has_c1c;       /**< C1C present (blank fields are absent) */
  double c1c_m;       /**< code pseudorange on L1 C/A [m] */
  bool has_d1c;
  double d1c_hz;      /**< Doppler on L1 C/A [Hz] (positive for an approaching satellite) */
  bool has_s1c;
  double s1c_dbhz;    /**< signal strength [dB-Hz] */
} nav_rinex_obs_sat;

/** One epoch record with flag 0 (OK) or 1 (power failure since the previous epoch). */
typedef struct nav_rinex_obs_epoch {
  double t_gps_s;        /**< epoch, GPS seconds since the GPS epoch (receiver time as written) */
  int flag;              /**< 0 or 1 */
  bool has_rx_clock;     /**< the receiver clock offset field is given */
  double rx_clock_s;     /**< receiver clock offset [s] (0 if not given) */
  int n;                 /**< GPS and GLONASS satellites kept */
  nav_rinex_obs_sat sats[NAV_RINEX_MAX_EPOCH_SATS];
  int skipped;           /**< satellites of other systems in the record */
  long line;             /**< line of the epoch's '>' record */
} nav_rinex_obs_epoch;

typedef struct nav_rinex_obs_reader nav_rinex_obs_reader;

/**
 * Open an observation file and read its header.
 * @param[out] out  the reader; destroy with nav_rinex_obs_destroy()
 * @param[out] diag on failure, what and where (FILE:LINE:COL); may be NULL
 * @return NAV_OK; NAV_ERR_IO (cannot open or read); NAV_ERR_PARSE (header); NAV_ERR_INVALID_ARG
 *         (NULL); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_open(const char *path, nav_rinex_obs_reader **out, nav_diag *diag);

/** As nav_rinex_obs_open(), over @p len bytes of memory (not copied: @p text must outlive the
 *  reader); @p display_name is the FILE of diagnostics. */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_open_memory(const char *text, size_t len, const char *display_name,
                                                           nav_rinex_obs_reader **out, nav_diag *diag);

/** Close and free; accepts NULL. */
NAV_API void nav_rinex_obs_destroy(nav_rinex_obs_reader *r);

/** The header (borrowed, valid until destroy). */
NAV_API const nav_rinex_obs_header *nav_rinex_obs_get_header(const nav_rinex_obs_reader *r);

/**
 * Next epoch with flag 0 or 1. Event records (flags 2-5) and cycle-slip records (flag 6) are
 * skipped with their special records and counted (nav_rinex_obs_events()). Epochs must not go
 * back in time.
 * @param[out] out the epoch, written only when @p got is set
 * @param[out] got false at the end of the file
 * @return NAV_OK; NAV_ERR_PARSE (see nav_rinex_obs_diag()); NAV_ERR_IO. After an error every
 *         further call returns the same status.
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_next(nav_rinex_obs_reader *r, nav_rinex_obs_epoch *out, bool *got);

/** The last error ("" if none); borrowed until the next call or destroy. */
NAV_API const nav_diag *nav_rinex_obs_diag(const nav_rinex_obs_reader *r);

/** Event and cycle-slip records skipped so far (flags 2-6). */
NAV_API long nav_rinex_obs_events(const nav_rinex_obs_reader *r);

/** Fraction of the input consumed, 0..1. */
NAV_API double nav_rinex_obs_fraction(const nav_rinex_obs_reader *r);

/* ================================================================ navigation files */

/** A GPS LNAV broadcast ephemeris (RINEX 3.04 Table A6), in SI units with times made continuous. */
typedef struct nav_rinex_gps_eph {
  int prn;
  double toc_gps_s;                          /**< clock reference time, GPS s since the GPS epoch */
  double af0_s, af1_sps, af2_sps2;           /**< satellite clock polynomial */
  double iode;
  double crs_m, delta_n_rps, m0_rad;
  double cuc_rad, e, cus_rad, sqrt_a_sqrtm;
  double toe_sow_s;                          /**< toe, seconds of the GPS week */
  double cic_rad, omega0_rad, cis_rad;
  double i0_rad, crc_m, w_rad, omega_dot_rps;
  double idot_rps;
  int week;                                  /**< GPS week of toe (continuous, not mod 1024) */
  double toe_gps_s;                          /**< 604800 week + toe_sow_s */
  double accuracy_m;
  int health;
  double tgd_s;
  double iodc;
  long line;                                 /**< line of the record's first line */
} nav_rinex_gps_eph;

/** A GLONASS ephemeris (RINEX 3.04 Table A10): state vector at tb in PZ-90 [m, m/s, m/s^2]. */
typedef struct nav_rinex_glo_eph {
  int slot;
  double tb_gps_s;     /**< epoch of the state (the record's UTC epoch made GPS time) */
  double tau_n_s;      /**< -TauN as written is negated back: clock correction tau_n [s] */
  double gamma_n;      /**< relative frequency bias gamma_n */
  double tk_s;         /**< message frame time (seconds of the UTC week), as written */
  nav_vec3 r_m, v_mps, a_mps2; /**< PZ-90 position, velocity, lunisolar acceleration */
  int health;          /**< 0 = healthy */
  int freq_k;          /**< frequency channel -7..13 */
  double age_days;
  long line;
} nav_rinex_glo_eph;

/** The GPS and GLONASS records of a navigation file, in file order. */
typedef struct nav_rinex_nav {
  double version;
  bool has_leap;
  int leap_s;          /**< GPS - UTC [s] used for GLONASS epochs */
  size_t n_gps, n_glo;
  nav_rinex_gps_eph *gps;
  nav_rinex_glo_eph *glo;
  long skipped;        /**< records of other systems */
} nav_rinex_nav;

/**
 * Read a navigation file.
 * @param[out] out  the records; free with nav_rinex_nav_destroy()
 * @param[out] diag on failure, what and where; may be NULL
 * @return NAV_OK; NAV_ERR_IO; NAV_ERR_PARSE; NAV_ERR_OUT_OF_RANGE (more than
 *         NAV_RINEX_MAX_EPHEMERIDES records); NAV_ERR_NO_MEMORY; NAV_ERR_INVALID_ARG (NULL).
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_nav_read(const char *path, nav_rinex_nav **out, nav_diag *diag);

/** As nav_rinex_nav_read(), over memory. */
NAV_API NAV_NODISCARD nav_status nav_rinex_nav_read_memory(const char *text, size_t len, const char *display_name,
                                                           nav_rinex_nav **out, nav_diag *diag);

/** Free; accepts NULL. */
NAV_API void nav_rinex_nav_destroy(nav_rinex_nav *n);

/**
 * The orbit of a GPS ephemeris in the form the constellation code propagates
 * (nav_gnss_orbit_state()): Keplerian elements at toe, toe_s = toe_gps_s, satellite clock af0/af1
 * copied. The harmonic corrections (C_rs ... C_is) are not part of nav_gnss_orbit: @p has_harmonics
 * (may be NULL) tells whether any is non-zero (the replay refuses such ephemerides).
 */
NAV_API nav_gnss_orbit nav_rinex_gps_orbit(const nav_rinex_gps_eph *e, bool *has_harmonics);

/**
 * Satellite clock correction dt_sv [s] of a GPS ephemeris at GPS time @p t_gps_s (IS-GPS-200N
 * 20.3.3.3.3.1: af0 + af1 (t - toc) + af2 (t - toc)^2 + F e sqrt(A) sin E_k, minus T_GD for the
 * L1 C/A user). The corrected pseudorange is P + c dt_sv. Leaf maths.
 */
NAV_API double nav_rinex_gps_clock_s(const nav_rinex_gps_eph *e, double t_gps_s);

/* ================================================================ replay source */

/** A tightly coupled replay's raw measurements from a RINEX observation + navigation file pair
 *  (docs/rinex.md "Reading and replay"). */
typedef struct nav_rinex_source nav_rinex_source;

/** Settings of a nav_rinex_source. */
typedef struct nav_rinex_source_config {
  const char *obs_path;  /**< observation file (required) */
  const char *nav_path;  /**< navigation file (required) */
  /** GPS time of the IMU's time 0: t_imu = t_gps - t0_gps_s. */
  double t0_gps_s;
  double pr_sd_m;        /**< pseudorange sigma for the filter [m] (> 0) */
  double rr_sd_mps;      /**< range-rate sigma for the filter [m/s] (> 0) */
  /** Largest |t - toe| of a usable GPS ephemeris [s]; default 7200 (the 4 h fit interval). */
  double max_eph_age_s;
  bool use_doppler;      /**< use D1C as range rate; default true */
} nav_rinex_source_config;

/** Defaults: no paths, t0 0, sigmas 3 m and 0.1 m/s, ephemeris age 7200 s, Doppler on. */
NAV_API nav_rinex_source_config nav_rinex_source_config_default(void);

/** What a source did so far. */
typedef struct nav_rinex_source_counts {
  long epochs;            /**< epochs returned */
  long sats_used;         /**< satellite measurements returned */
  long no_ephemeris;      /**< satellites without a usable ephemeris (skipped) */
  long unhealthy;         /**< satellites whose ephemeris is unhealthy (skipped) */
  long glonass_skipped;   /**< GLONASS satellites (not replayed yet: skipped) */
  long no_code;           /**< satellites without C1C (skipped) */
  long events;            /**< event records skipped by the observation reader */
  long other_systems;     /**< satellites of other systems */
} nav_rinex_source_counts;

/**
 * Open the pair: the navigation file is read whole, the observation file's header is read.
 * @return NAV_OK; the statuses of nav_rinex_obs_open() and nav_rinex_nav_read();
 *         NAV_ERR_INVALID_ARG (settings: message in @p diag).
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_source_create(const nav_rinex_source_config *cfg, nav_rinex_source **out,
                                                         nav_diag *diag);
NAV_API void nav_rinex_source_destroy(nav_rinex_source *s);

/**
 * Next observation epoch as the tightly coupled update takes it (nav_ins_gnss_update_raw()):
 * t_s = t_gps - t0_gps_s; per GPS satellite with C1C and a usable ephemeris (the nearest toe
 * within max_eph_age_s, healthy), its orbit, P = C1C + c dt_sv (satellite clock corrected), and
 * the range rate -lambda_L1 D1C when D1C is present. The epoch and the orbits it points to are
 * borrowed until the next call.
 * @return NAV_OK (got false at the end); NAV_ERR_PARSE with FILE:LINE:COL in @p diag (also for
 *         a GPS ephemeris with harmonic corrections, which nav_gnss_orbit cannot hold).
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_source_next(nav_rinex_source *s, nav_ins_gnss_raw_epoch *ep, bool *got,
                                                       nav_diag *diag);

/** Counts so far. */
NAV_API nav_rinex_source_counts nav_rinex_source_get_counts(const nav_rinex_source *s);

/** Fraction of the observation file consumed, 0..1. */
NAV_API double nav_rinex_source_fraction(const nav_rinex_source *s);

NAV_END_DECLS

#endif /* NAV_RINEX_READ_H */
