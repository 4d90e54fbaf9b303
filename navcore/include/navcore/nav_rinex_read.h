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
 * header (nav_rinex_leap_seconds() of the epoch if the header has none).
 *
 * The records are the structures of nav_rinex.h, shared with the writer (navsim run --export
 * rinex).
 *
 * Errors: any problem is one nav_diag "FILE:LINE:COL: error: what is wrong and what is
 * expected" with COL the 1-based column of the offending field; NAV_ERR_PARSE. Limits: lines of
 * at most NAV_RINEX_MAX_LINE bytes, NAV_RINEX_MAX_FILE_TYPES observation types per system,
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
#include "nav_rinex.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** Longest accepted line in bytes, line end excluded (an epoch line of 64 types is 1027). */
#define NAV_RINEX_MAX_LINE 2048
/** Most observation types of one system in a file read (the types kept are at most
 *  NAV_RINEX_MAX_OBS_TYPES: C1C, L1C, D1C, S1C). */
#define NAV_RINEX_MAX_FILE_TYPES 64
/** Most GPS + GLONASS navigation records of one file (a week of 32 GPS satellites every 2 h and
 *  24 GLONASS satellites every 30 min is 11 000). */
#define NAV_RINEX_MAX_EPHEMERIDES 100000

/* ================================================================ observation files */

/**
 * What the reader found in an observation file beyond nav_rinex_obs_header (which lists, per
 * system, only the kept types: C1C, L1C, D1C and S1C where the file has them, in file order).
 */
typedef struct nav_rinex_obs_info {
  double version;                     /**< e.g. 3.04 */
  char system;                        /**< satellite system of the file: 'G', 'R', 'M' (mixed), ... */
  bool has_first;                     /**< TIME OF FIRST OBS given (else t_first_gps_s is 0) */
  bool has_leap;                      /**< LEAP SECONDS given */
  int file_types[NAV_GNSS_SYS_COUNT]; /**< types the file lists for GPS, GLONASS */
  int skipped_systems;                /**< SYS / # / OBS TYPES records of systems other than G and R */
} nav_rinex_obs_info;

/** What an epoch record said besides its observations. */
typedef struct nav_rinex_epoch_info {
  int flag;          /**< 0 (OK) or 1 (power failure since the previous epoch) */
  bool has_rx_clock; /**< the receiver clock offset field is given */
  double rx_clock_s; /**< receiver clock offset [s] (0 if not given) */
  int skipped;       /**< satellites of other systems in the record */
  long line;         /**< line of the epoch's '>' record */
} nav_rinex_epoch_info;

typedef struct nav_rinex_obs_reader nav_rinex_obs_reader;

/**
 * Open an observation file and read its header.
 * @param[out] out  the reader; destroy with nav_rinex_obs_destroy()
 * @param[out] diag on failure, what and where (FILE:LINE:COL); may be NULL
 * @return NAV_OK; NAV_ERR_IO (cannot open or read); NAV_ERR_PARSE (header); NAV_ERR_INVALID_ARG
 *         (NULL); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_open(const char *path, nav_rinex_obs_reader **out,
                                                    nav_diag *diag);

/** As nav_rinex_obs_open(), over @p len bytes of memory (not copied: @p text must outlive the
 *  reader); @p display_name is the FILE of diagnostics. */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_open_memory(const char *text, size_t len,
                                                           const char *display_name,
                                                           nav_rinex_obs_reader **out, nav_diag *diag);

/** Close and free; accepts NULL. */
NAV_API void nav_rinex_obs_destroy(nav_rinex_obs_reader *r);

/** The header with the kept types (borrowed, valid until destroy). */
NAV_API const nav_rinex_obs_header *nav_rinex_obs_get_header(const nav_rinex_obs_reader *r);

/** The rest of the header (borrowed, valid until destroy). */
NAV_API const nav_rinex_obs_info *nav_rinex_obs_get_info(const nav_rinex_obs_reader *r);

/**
 * Next epoch with flag 0 or 1, GPS and GLONASS satellites only, values in the order of the kept
 * types of nav_rinex_obs_get_header(). Event records (flags 2-5) and cycle-slip records (flag 6)
 * are skipped with their special records and counted (nav_rinex_obs_events()). Epochs must not
 * go back in time.
 * @param[out] out  the epoch when @p got is set (unspecified after an error)
 * @param[out] info flag, receiver clock, skipped satellites, line (may be NULL)
 * @param[out] got  false at the end of the file
 * @return NAV_OK; NAV_ERR_PARSE (see nav_rinex_obs_diag()); NAV_ERR_IO. After an error every
 *         further call returns the same status.
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_obs_next(nav_rinex_obs_reader *r, nav_rinex_obs_epoch *out,
                                                    nav_rinex_epoch_info *info, bool *got);

/** Index of observation type @p type ("C1C") among the kept types of system @p sys, or -1. */
NAV_API int nav_rinex_obs_type_index(const nav_rinex_obs_header *h, nav_gnss_system sys, const char *type);

/** The last error ("" if none); borrowed until the next call or destroy. */
NAV_API const nav_diag *nav_rinex_obs_diag(const nav_rinex_obs_reader *r);

/** Event and cycle-slip records skipped so far (flags 2-6). */
NAV_API long nav_rinex_obs_events(const nav_rinex_obs_reader *r);

/** Fraction of the input consumed, 0..1. */
NAV_API double nav_rinex_obs_fraction(const nav_rinex_obs_reader *r);

/* ================================================================ navigation files */

/** The GPS and GLONASS records of a navigation file, in file order (nav_rinex.h structures). */
typedef struct nav_rinex_nav {
  double version;
  bool has_leap;
  int leap_s; /**< LEAP SECONDS (GPS - UTC) [s] used for GLONASS epochs (valid when
               *   has_leap; without it, nav_rinex_leap_seconds() of each record's epoch) */
  size_t n_gps, n_glo;
  nav_rinex_gps_eph *gps;
  long *gps_line; /**< line of each GPS record's first line */
  nav_rinex_glo_eph *glo;
  long *glo_line;
  long skipped; /**< records of other systems */
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
NAV_API NAV_NODISCARD nav_status nav_rinex_nav_read_memory(const char *text, size_t len,
                                                           const char *display_name, nav_rinex_nav **out,
                                                           nav_diag *diag);

/** Free; accepts NULL. */
NAV_API void nav_rinex_nav_destroy(nav_rinex_nav *n);

/**
 * The orbit of a GPS ephemeris in the form the constellation code propagates
 * (nav_gnss_orbit_state()): Keplerian elements at toe, toe_s = toe_gps_s, the harmonic
 * corrections, satellite clock af0/af1 copied. @p has_harmonics (may be NULL) tells whether any
 * harmonic correction is non-zero (always for real broadcast records, never for navsim's).
 */
NAV_API nav_gnss_orbit nav_rinex_gps_orbit(const nav_rinex_gps_eph *e, bool *has_harmonics);

/* ================================================================ replay source */

/** A tightly coupled replay's raw measurements from a RINEX observation + navigation file pair
 *  (docs/rinex.md "Reading and replay"). */
typedef struct nav_rinex_source nav_rinex_source;

/** Settings of a nav_rinex_source. */
typedef struct nav_rinex_source_config {
  const char *obs_path; /**< observation file (required) */
  const char *nav_path; /**< navigation file (required) */
  /** GPS time of the IMU's time 0: t_imu = t_gps - t0_gps_s. */
  double t0_gps_s;
  double pr_sd_m;   /**< pseudorange sigma for the filter [m] (> 0) */
  double rr_sd_mps; /**< range-rate sigma for the filter [m/s] (> 0) */
  /** Largest |t - toe| of a usable GPS ephemeris [s]; default 7200 (the 4 h fit interval). */
  double max_eph_age_s;
  /** Largest |t - tb| of a usable GLONASS record [s], at most 86400; default 1800 (records come
   *  every 30 min, navsim writes them every 15 min). */
  double max_glo_age_s;
  bool use_doppler; /**< use D1C as range rate; default true */
} nav_rinex_source_config;

/** Defaults: no paths, t0 0, sigmas 3 m and 0.1 m/s, ephemeris ages 7200 s (GPS) and 1800 s
 *  (GLONASS), Doppler on. */
NAV_API nav_rinex_source_config nav_rinex_source_config_default(void);

/** What a source did so far. */
typedef struct nav_rinex_source_counts {
  long epochs;        /**< epochs returned */
  long sats_used;     /**< satellite measurements returned */
  long no_ephemeris;  /**< satellites without a usable ephemeris (skipped) */
  long unhealthy;     /**< satellites whose ephemeris is unhealthy (skipped) */
  long glonass_used;  /**< GLONASS satellite measurements among sats_used */
  long no_code;       /**< satellites without C1C (skipped) */
  long events;        /**< event records skipped by the observation reader */
  long other_systems; /**< satellites of other systems */
} nav_rinex_source_counts;

/**
 * Open the pair: the navigation file is read whole, the observation file's header is read.
 * @return NAV_OK; the statuses of nav_rinex_obs_open() and nav_rinex_nav_read();
 *         NAV_ERR_INVALID_ARG (settings: message in @p diag).
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_source_create(const nav_rinex_source_config *cfg,
                                                         nav_rinex_source **out, nav_diag *diag);
NAV_API void nav_rinex_source_destroy(nav_rinex_source *s);

/**
 * Next observation epoch as the tightly coupled update takes it (nav_ins_gnss_update_raw()):
 * t_s = t_gps - t0_gps_s; per GPS satellite with C1C and a usable ephemeris (the nearest toe
 * within max_eph_age_s, healthy), its orbit, P = C1C + c dt_sv (dt_sv of nav_rinex_gps_clock_s()
 * with T_GD, at the transmit time t - C1C / c), and the range rate -lambda_L1 D1C + c dt_sv'
 * (the clock's rate by a central difference over +-1 s) when D1C is present. Per GLONASS
 * satellite with C1C and a healthy record within max_glo_age_s of t (nearest tb): the record's
 * state integrated to t with the ICD force model (RK4, steps of at most 60 s) and expressed as
 * the osculating orbit at t (nav_gnss_orbit, toe = t), P = C1C + c dt_sv
 * (nav_rinex_glo_clock_s()), range rate -lambda_k D1C + c GammaN with the channel k of the
 * header's GLONASS SLOT / FRQ # (else the record's). The epoch and the orbits it points to are
 * borrowed until the next call.
 * @return NAV_OK (got false at the end); NAV_ERR_PARSE with FILE:LINE:COL in @p diag (also for
 *         a GLONASS record whose state gives no closed orbit).
 */
NAV_API NAV_NODISCARD nav_status nav_rinex_source_next(nav_rinex_source *s, nav_ins_gnss_raw_epoch *ep,
                                                       bool *got, nav_diag *diag);

/** Counts so far. */
NAV_API nav_rinex_source_counts nav_rinex_source_get_counts(const nav_rinex_source *s);

/** Fraction of the observation file consumed, 0..1. */
NAV_API double nav_rinex_source_fraction(const nav_rinex_source *s);

NAV_END_DECLS

#endif /* NAV_RINEX_READ_H */
