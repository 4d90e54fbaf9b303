/**
 * @file nav_recorded.h
 * @brief navcore_io: recorded IMU / GNSS / reference files in the KF-GINS (i2Nav) text formats,
 *        and the replay of our navigation on them, scored against the reference.
 *
 * Formats (whitespace-separated numbers, one record per line; blank lines and lines whose first
 * non-blank character is '#' are skipped; CR-LF line ends are accepted):
 *
 * | format        | columns | content                                                              |
 * |---------------|---------|----------------------------------------------------------------------|
 * | NAV_REC_IMU   | 7       | t [s], dtheta x/y/z [rad], dvel x/y/z [m/s]: increments over the     |
 * |               |         | interval that ENDS at t, body axes x-forward, y-right, z-down        |
 * | NAV_REC_GNSS  | 7       | t [s], lat [deg], lon [deg], h [m], position 1-sigma N/E/D [m]       |
 * | NAV_REC_GNSS  | 13      | as 7, then velocity N/E/D [m/s] and velocity 1-sigma N/E/D [m/s]     |
 * |               |         | (KF-GINS-Matlab GNSS-POSVEL.txt)                                     |
 * | NAV_REC_PVA   | 11      | GPS week, t [s], lat [deg], lon [deg], h [m], vN vE vD [m/s],         |
 * |               |         | roll pitch yaw [deg] (ZYX Euler of C_b_n; yaw in -180..360)           |
 *
 * Every record must be finite, and time must strictly increase from record to record. A GNSS
 * file keeps the column count of its first record. Ranges: |dtheta| <= pi rad per axis (more is
 * not an increment: rates or degrees), |lat| <= 90 deg, lon in
 * [-180, 360] deg, sigmas >= 0, |roll| <= 180, |pitch| <= 90, yaw in [-180, 360] deg, week an
 * integer >= 0. Angles are converted to radians once, here; longitudes and yaw are wrapped to
 * (-pi, pi].
 *
 * Any problem is one nav_diag "FILE:LINE:COL: error: COLUMN: what is wrong and what is
 * expected", with COL the 1-based byte column of the offending field (or of the end of the line
 * for a missing field). Readers stream: memory is one 256 KiB buffer per reader whatever the
 * file size, numbers are parsed with strtod (correctly rounded), and a 25 MB file reads in about
 * 0.1 s. Lines longer than NAV_REC_MAX_LINE bytes are an error.
 *
 * Objects are not synchronised: one thread per reader. Nothing here keeps caller pointers
 * beyond the call that receives them.
 *
 * Example (stream an IMU file):
 * @code
 *   nav_rec_reader *r = NULL;
 *   nav_diag d;
 *   if (nav_rec_reader_open("IMU.txt", NAV_REC_IMU, &r, &d) != NAV_OK) { print(&d); return; }
 *   nav_imu_increment inc;
 *   bool got = false;
 *   while (nav_rec_read_imu(r, &inc, &got) == NAV_OK && got) use(&inc);
 *   if (nav_rec_reader_diag(r)->message[0]) print(nav_rec_reader_diag(r));   // stopped on an error
 *   nav_rec_reader_destroy(r);
 * @endcode
 */
#ifndef NAV_RECORDED_H
#define NAV_RECORDED_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_errors.h"
#include "nav_export.h"
#include "nav_frames.h"
#include "nav_ins_gnss.h"
#include "nav_io.h"
#include "nav_sensor_config.h"
#include "nav_sim.h"
#include "nav_status.h"
#include "nav_truth.h"

NAV_BEGIN_DECLS

/** Longest accepted line in bytes, line end excluded. */
#define NAV_REC_MAX_LINE 4096

/** Which recorded-file format a reader parses. */
typedef enum nav_rec_format {
  NAV_REC_IMU = 0,  /**< KF-GINS IMU increments, 7 columns */
  NAV_REC_GNSS = 1, /**< KF-GINS GNSS position (7 columns) or position + velocity (13 columns) */
  NAV_REC_PVA = 2   /**< KF-GINS / i2Nav .nav reference or result, 11 columns */
} nav_rec_format;

/** One row of a .nav file: position, velocity and attitude at t_s. */
typedef struct nav_rec_pva {
  int week;         /**< GPS week as written (0 in simulated data) */
  double t_s;       /**< time [s] (seconds of week) */
  nav_geodetic pos; /**< latitude, longitude [rad] (longitude wrapped to (-pi, pi]), ellipsoidal height [m] */
  nav_vec3 v_n_mps; /**< velocity N, E, D [m/s] */
  nav_euler att;    /**< roll, pitch, yaw of C_b_n [rad]; yaw wrapped to (-pi, pi] */
} nav_rec_pva;

typedef struct nav_rec_reader nav_rec_reader;

/**
 * Open a recorded file for streaming.
 * @param[in]  path file to read (also the FILE of diagnostics)
 * @param[in]  fmt  format of its records
 * @param[out] out  the reader; destroy with nav_rec_reader_destroy()
 * @param[out] diag on NAV_ERR_IO, what failed (line 0); may be NULL
 * @return NAV_OK; NAV_ERR_IO (cannot open); NAV_ERR_INVALID_ARG (NULL, unknown format);
 *         NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_rec_reader_open(const char *path, nav_rec_format fmt,
                                                     nav_rec_reader **out, nav_diag *diag);

/**
 * As nav_rec_reader_open(), over @p len bytes of memory (not copied: @p text must outlive the
 * reader). @p display_name is the FILE of diagnostics.
 */
NAV_API NAV_NODISCARD nav_status nav_rec_reader_open_memory(const char *text, size_t len,
                                                            const char *display_name, nav_rec_format fmt,
                                                            nav_rec_reader **out);

/** Close and free; accepts NULL. */
NAV_API void nav_rec_reader_destroy(nav_rec_reader *r);

/**
 * Next IMU record. k counts the records from 0; dt_s = t_s - t_s(previous record), and 0 for the
 * first record of the file, whose interval starts before the file (a caller must not step the
 * mechanization with it; nav_replay_run() uses it only as a possible initial epoch).
 * @param[out] out the record, written only when @p got is set
 * @param[out] got false at the end of the file
 * @return NAV_OK; NAV_ERR_PARSE (malformed line, non-finite value, time not increasing: see
 *         nav_rec_reader_diag()); NAV_ERR_IO (read error); NAV_ERR_INVALID_ARG (NULL, reader of
 *         another format). After an error every further call returns the same status.
 */
NAV_API NAV_NODISCARD nav_status nav_rec_read_imu(nav_rec_reader *r, nav_imu_increment *out, bool *got);

/**
 * Next GNSS record as the integration consumes it: angles in radians, has_vel only for the
 * 13-column variant (vel_sd_mps and v_n_mps are zero otherwise). The sigmas are as written (the
 * integration floors them, nav_ins_gnss_config.pos_sd_floor_m). Statuses as nav_rec_read_imu().
 */
NAV_API NAV_NODISCARD nav_status nav_rec_read_gnss(nav_rec_reader *r, nav_ins_gnss_fix *out, bool *got);

/** Next .nav row. Statuses as nav_rec_read_imu(). */
NAV_API NAV_NODISCARD nav_status nav_rec_read_pva(nav_rec_reader *r, nav_rec_pva *out, bool *got);

/** The last error of @p r (message "" if none); borrowed, valid until the next call or destroy. */
NAV_API const nav_diag *nav_rec_reader_diag(const nav_rec_reader *r);

/** 1-based line of the record last returned (0 before the first). */
NAV_API long nav_rec_reader_line(const nav_rec_reader *r);

/** Line number of a last line that has no line end, once it has been read, else 0: the file may
 *  have been cut short, and a number cut inside its digits cannot be told from a shorter one. */
NAV_API long nav_rec_reader_cut_line(const nav_rec_reader *r);

/** Fraction of the input consumed, 0..1 (for progress display). */
NAV_API double nav_rec_reader_fraction(const nav_rec_reader *r);

/**
 * Read every record of a GNSS file into a caller buffer.
 * @param[out] out      up to @p capacity fixes
 * @param[out] count    number of fixes read (written on NAV_OK)
 * @param[out] diag     on failure, what and where (may be NULL)
 * @return NAV_OK; NAV_ERR_OUT_OF_RANGE if the file holds more than @p capacity records; the
 *         statuses of nav_rec_reader_open() and nav_rec_read_gnss().
 */
NAV_API NAV_NODISCARD nav_status nav_rec_load_gnss(const char *path, nav_ins_gnss_fix *out, size_t capacity,
                                                   size_t *count, nav_diag *diag);

/**
 * Read every record of a file of format @p fmt with the checks of the streaming readers and keep
 * none: a replay finds a malformed or implausible record (FILE:LINE:COL in @p diag) before its
 * run, wherever the record is in the file.
 * @param[out] count records read (written on NAV_OK; may be NULL)
 * @return NAV_OK; the statuses of nav_rec_reader_open() and the nav_rec_read_*() functions.
 */
NAV_API NAV_NODISCARD nav_status nav_rec_check_file(const char *path, nav_rec_format fmt, size_t *count,
                                                    nav_diag *diag);

/** As nav_rec_load_gnss(), for IMU files. */
NAV_API NAV_NODISCARD nav_status nav_rec_load_imu(const char *path, nav_imu_increment *out, size_t capacity,
                                                  size_t *count, nav_diag *diag);

/** As nav_rec_load_gnss(), for .nav files. */
NAV_API NAV_NODISCARD nav_status nav_rec_load_pva(const char *path, nav_rec_pva *out, size_t capacity,
                                                  size_t *count, nav_diag *diag);

/**
 * Every record of an IMU file, read and checked once (as nav_rec_check_file() does) and kept in
 * memory, so that a replay that checks its inputs before the run does not parse the file twice
 * (nav_replay_config.imu). Made by nav_rec_imu_array_load(), released by nav_rec_imu_array_free().
 */
typedef struct nav_rec_imu_array {
  /** The records in file order: part[0], then part[1] (the two halves parsed on two threads are
   *  kept where they were parsed, not copied together); owned, part[1] may be NULL. Read them
   *  with nav_rec_imu_array_at(). */
  nav_imu_increment *part[2];
  size_t part_count[2];  /**< records in each part */
  size_t count;          /**< number of records, part_count[0] + part_count[1] */
  long cut_line;         /**< nav_rec_reader_cut_line() after the whole file, else 0 */
  long last_record_line; /**< 1-based line of the last record (0 without records) */
} nav_rec_imu_array;

/** Record @p i (0 <= i < a->count) of @p a, borrowed. */
static inline const nav_imu_increment *nav_rec_imu_array_at(const nav_rec_imu_array *a, size_t i) {
  return i < a->part_count[0] ? &a->part[0][i] : &a->part[1][i - a->part_count[0]];
}

/**
 * Read every record of an IMU file into memory, with the checks and messages of
 * nav_rec_read_imu(). Large files are split at a line end and the halves parsed on two threads;
 * the records, their indices and intervals, and any error message are those of the sequential
 * reader (a half with an error, or a time step across the split that does not increase, is read
 * again sequentially for its exact message).
 * @param[in]  path      IMU file (KF-GINS text)
 * @param[in]  max_bytes files larger than this are refused with NAV_ERR_OUT_OF_RANGE and nothing
 *                       read (the caller then streams them: memory stays bounded)
 * @param[out] out       the records (written on NAV_OK; release with nav_rec_imu_array_free())
 * @param[out] diag      on failure, what and where (may be NULL)
 * @return NAV_OK; NAV_ERR_OUT_OF_RANGE (larger than max_bytes); NAV_ERR_NO_MEMORY; the statuses of
 *         nav_rec_reader_open() and nav_rec_read_imu().
 */
NAV_API NAV_NODISCARD nav_status nav_rec_imu_array_load(const char *path, size_t max_bytes,
                                                        nav_rec_imu_array *out, nav_diag *diag);

/** Release the records of @p a and zero it; accepts NULL and a zeroed array. */
NAV_API void nav_rec_imu_array_free(nav_rec_imu_array *a);

/**
 * An IMU file read and checked on a thread of its own while its records are consumed: the
 * records of nav_rec_imu_array_load() (same checks, values, indices and intervals, same message
 * for the first bad record, worded by the sequential reader), handed over as they are parsed so
 * that a replay can start on the first ones (nav_replay_config.imu_stream). Made by
 * nav_rec_imu_stream_start(), released by nav_rec_imu_stream_destroy(). The consumer calls
 * (nav_rec_imu_stream_at(), _poll(), _finish()) are for one thread at a time, but not
 * necessarily the same one; the parsing thread is internal.
 */
typedef struct nav_rec_imu_stream nav_rec_imu_stream;

/**
 * Open an IMU file and start reading it on a second thread (on the calling thread, before the
 * return, when no thread can be made).
 * @param[in]  path      IMU file (KF-GINS text)
 * @param[in]  max_bytes larger files are refused with NAV_ERR_OUT_OF_RANGE and nothing read
 * @param[out] out       the stream (release with nav_rec_imu_stream_destroy())
 * @param[out] diag      when the file cannot be opened, why (may be NULL); parse errors come
 *                       from nav_rec_imu_stream_finish()
 * @return NAV_OK; NAV_ERR_OUT_OF_RANGE; NAV_ERR_NO_MEMORY; the open statuses of
 *         nav_rec_reader_open() (with its message).
 */
NAV_API NAV_NODISCARD nav_status nav_rec_imu_stream_start(const char *path, size_t max_bytes,
                                                          nav_rec_imu_stream **out, nav_diag *diag);

/** Size of the file in bytes (known at the start). */
NAV_API size_t nav_rec_imu_stream_file_bytes(const nav_rec_imu_stream *s);

/** The most records the stream can hold (set by the file's size at the start; a file with more
 *  fails with NAV_ERR_NO_MEMORY): an upper bound of the record count known before the reading ends. */
NAV_API size_t nav_rec_imu_stream_max_records(const nav_rec_imu_stream *s);

/**
 * Record @p i, waiting until it has been parsed.
 * @param[out] rec the record (borrowed, valid until nav_rec_imu_stream_destroy()), or NULL when
 *                 the file has fewer than i + 1 records
 * @return NAV_OK; the parse status once the file has turned out bad (for any @p i: the records
 *         before the bad one are not handed out any more, so that a consumer stops at once).
 */
NAV_API NAV_NODISCARD nav_status nav_rec_imu_stream_at(nav_rec_imu_stream *s, size_t i,
                                                       const nav_imu_increment **rec);

/**
 * Has the whole file been read? Without waiting, from any thread (also while another one is in
 * nav_rec_imu_stream_at()); when it has, @p st gets its status and @p count its records (each may
 * be NULL).
 */
NAV_API bool nav_rec_imu_stream_poll(nav_rec_imu_stream *s, nav_status *st, size_t *count);

/**
 * Wait until the whole file has been read and return its verdict, as nav_rec_check_file() would:
 * the status, the record count and, on failure, the message of the first bad record.
 * @param[out] count       records of the file (on NAV_OK; may be NULL)
 * @param[out] cut_line    nav_rec_reader_cut_line() after the whole file (may be NULL)
 * @param[out] last_line   1-based line of the last record, 0 without records (may be NULL)
 * @param[out] diag        on failure, what and where (may be NULL)
 */
NAV_API NAV_NODISCARD nav_status nav_rec_imu_stream_finish(nav_rec_imu_stream *s, size_t *count,
                                                           long *cut_line, long *last_line, nav_diag *diag);

/** Stop the reading (if it still goes on), release everything; accepts NULL. */
NAV_API void nav_rec_imu_stream_destroy(nav_rec_imu_stream *s);

/**
 * A .nav row as a reference state in ECEF (F = e of nav_frames.h): r_eb_e from the geodetic
 * position, v_eb_e = C_n_e v_n, q_b_e = q_n_e (x) q_b_n; accelerations and rates are zero (not
 * in the format). Leaf function.
 */
NAV_API nav_traj_state nav_rec_pva_to_state(const nav_rec_pva *row);

/**
 * The recorded fixes of a scene's gnss.file in the scene time base (docs/gnss-file.md): with a
 * recorded reference (trajectory.type recorded) the file shares its time base, so scene time =
 * file time - trajectory.recorded.t0_s; with a simulated reference the file's first fix is at
 * scene time 0. Sigmas as written (nav_rec_read_gnss()).
 * @param[out] out        the fixes (malloc'd; the caller frees them), for nav_sim_set_gnss_fixes()
 * @param[out] count      number of fixes (at least 1)
 * @param[out] t0_file_s  file time of scene time 0 [s]; may be NULL
 * @param[out] diag       on failure, what and where (FILE:LINE:COL); may be NULL
 * @return NAV_OK; NAV_ERR_INVALID_ARG (NULL, no gnss.file); NAV_ERR_PARSE (malformed line, no
 *         fix); NAV_ERR_IO; NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_gnss_file_load(const nav_scene *scene, nav_ins_gnss_fix **out, size_t *count,
                                                    double *t0_file_s, nav_diag *diag);

/* ================================================================ replay */

/** Statistics of one non-negative error metric over the scored epochs. */
typedef struct nav_replay_stat {
  double rms;     /**< root mean square */
  double max;     /**< largest value */
  double t_max_s; /**< time of the largest value [s] */
} nav_replay_stat;

/**
 * Accuracy against the reference over the scored epochs. Every difference is estimate minus
 * reference resolved in NED at the reference position (nav_errors_compute()); Euler-angle
 * errors are wrapped differences of the ZYX angles.
 */
typedef struct nav_replay_stats {
  long epochs;               /**< scored epochs */
  nav_replay_stat pos_h_m;   /**< hypot(dN, dE) [m] */
  nav_replay_stat pos_v_m;   /**< |dD| [m] */
  nav_replay_stat vel_h_mps; /**< hypot(dvN, dvE) [m/s] */
  nav_replay_stat vel_v_mps; /**< |dvD| [m/s] */
  nav_replay_stat roll_rad;  /**< |roll error| [rad] */
  nav_replay_stat pitch_rad; /**< |pitch error| [rad] */
  nav_replay_stat yaw_rad;   /**< |yaw error| [rad] */
  nav_replay_stat att_rad;   /**< rotation angle between the attitudes [rad] */
  nav_vec3 pos_mean_n_m;     /**< signed mean position error N, E, D [m] */
  nav_vec3 vel_mean_n_mps;   /**< signed mean velocity error N, E, D [m/s] */
} nav_replay_stats;

/**
 * Streaming accumulator of nav_replay_stats (memory does not grow with the epochs). Zero it
 * (memset or = {0}) before the first nav_replay_stats_add(). Plain value; not synchronised.
 */
typedef struct nav_replay_stats_acc {
  long n;
  double sum_sq[8], max[8], t_max[8]; /**< per metric, in the order of nav_replay_stats */
  nav_vec3 sum_pos, sum_vel;
} nav_replay_stats_acc;

/** Add the errors of one epoch. */
NAV_API void nav_replay_stats_add(nav_replay_stats_acc *a, const nav_epoch_errors *e);
/** RMS, max and time of max of each metric, and the signed means, over the epochs added. */
NAV_API nav_replay_stats nav_replay_stats_result(const nav_replay_stats_acc *a);

/** Largest number of GNSS gaps nav_replay_summary lists (further ones are only counted). */
#define NAV_REPLAY_MAX_GAPS 64

/**
 * A GNSS gap: consecutive applied fixes further apart than gap_factor times the smallest fix
 * spacing (a requested outage, a gap in the file, or both), or no fix after the last one.
 */
typedef struct nav_replay_gap {
  double t0_s;         /**< last fix before the gap [s] */
  double t1_s;         /**< first fix after it [s] (open: the last epoch) */
  bool open;           /**< no fix after the gap: the run ended in it */
  bool has_end_errors; /**< a reference row coincides with the epoch of t1_s */
  double pos_h_end_m;  /**< horizontal error at t1_s, before the fix is applied [m] */
  double pos_v_end_m;  /**< vertical error at t1_s, before the fix [m] */
  double pos_h_max_m;  /**< largest horizontal error over the scored epochs of the gap [m] */
  nav_epoch_errors end_errors; /**< all errors at t1_s before the fix (valid if has_end_errors) */
} nav_replay_gap;

/** What a replay did, and how well. */
typedef struct nav_replay_summary {
  bool free_ins;          /**< no GNSS file: pure strapdown */
  double t_first_s;       /**< initial epoch (state = reference) [s] */
  double t_last_s;        /**< last processed IMU epoch [s] */
  long imu_records;       /**< IMU records read (including those skipped before the start) */
  long imu_steps;         /**< increments processed */
  long imu_gaps;          /**< intervals longer than 1.5 times the first interval processed */
  double imu_dt_max_s;    /**< longest interval processed [s] */
  long ref_rows;          /**< reference rows read */
  long ref_unmatched;     /**< reference rows inside the processed span coinciding with no IMU epoch */
  long gnss_records;      /**< GNSS records read */
  long gnss_applied;      /**< fixes applied */
  long gnss_dropped;      /**< fixes inside a requested outage */
  long gnss_before_start; /**< fixes at or before the initial epoch (not applied) */
  long gnss_unmatched;    /**< fixes in the processed span with no IMU epoch within dt/2 */
  bool gnss_has_vel;      /**< the GNSS file carries velocity (13 columns) */
  nav_replay_stats stats; /**< over every scored epoch after the initial one */
  /** Over the scored epochs that are also output epochs (multiples of output_interval_s), to
   *  compare with another program's output decimated to that rate (nav_replay_score_pva()). */
  nav_replay_stats stats_output;
  nav_epoch_errors final; /**< errors at the last scored epoch */
  long gap_count;         /**< GNSS gaps found (may exceed NAV_REPLAY_MAX_GAPS) */
  nav_replay_gap gaps[NAV_REPLAY_MAX_GAPS];
  nav_vec3 b_g_rps;  /**< final gyro bias estimate [rad/s] (0 for the free INS) */
  nav_vec3 b_a_mps2; /**< final accelerometer bias estimate [m/s^2] */
  bool partial;      /**< stopped by a callback */
  /** Line of an input's last line without a line end, when the replay read it (else 0):
   *  nav_rec_reader_cut_line() of the IMU, GNSS and reference files. */
  long imu_cut_line, gnss_cut_line, ref_cut_line;
} nav_replay_summary;

/** One output epoch of a replay; pointers valid only during the callback. */
typedef struct nav_replay_record {
  const nav_frame *frame;      /**< WGS-84, origin at the initial reference position */
  const nav_ins_state *nav;    /**< navigation state, ECEF (after any GNSS update of the epoch) */
  const nav_traj_state *ref;   /**< reference at the same epoch, ECEF; NULL if none coincides */
  const nav_epoch_errors *err; /**< nav minus reference; NULL if no reference */
  bool gnss_update;            /**< a fix was applied at this epoch */
} nav_replay_record;

typedef nav_callback_result (*nav_replay_record_fn)(void *user, const nav_replay_record *r);

/**
 * A source of raw GNSS measurements for a tightly coupled replay (e.g. nav_rinex_source_next()
 * of nav_rinex_read.h): writes the next receiver epoch, in time order, into @p ep (its pointers
 * valid until the next call) and sets @p got, false at the end. On failure it returns the status
 * with FILE:LINE:COL in @p diag.
 */
typedef nav_status (*nav_replay_raw_fn)(void *raw_user, nav_ins_gnss_raw_epoch *ep, bool *got, nav_diag *diag);

/** Replay inputs and settings. Start from nav_replay_config_default(). */
typedef struct nav_replay_config {
  const char *imu_path;  /**< IMU increments (required) */
  const char *gnss_path; /**< GNSS fixes; NULL: free INS */
  const char *ref_path;  /**< .nav reference (required): the initial state and the scoring */
  /**
   * Mechanization and filter (nav.ins alone for the free INS); the earth model must be WGS-84.
   * nav_ins_gnss_config_from_scene() turns a scene's IMU error model, GNSS lever arm and initial
   * errors into it.
   */
  nav_ins_gnss_config nav;
  bool has_start;      /**< process from t_start_s (else from the first IMU record) */
  double t_start_s;    /**< [s], file time base */
  bool has_end;        /**< process up to t_end_s (else to the last IMU record) */
  double t_end_s;      /**< [s] */
  size_t outage_count; /**< requested outages: fixes with t in [t0_s, t1_s) are dropped */
  nav_gnss_outage outages[NAV_GNSS_MAX_OUTAGES];
  /**
   * A reference row is scored at an IMU epoch when their times differ by at most this [s].
   * Default 1e-4 s: the files print time to 1e-6 s or 1e-3 s, and 0.1 ms at 30 m/s is 3 mm.
   */
  double ref_sync_tol_s;
  double
      output_interval_s; /**< record callback at epochs within dt/2 of multiples of this [s]; default 0.1 */
  double gap_factor;     /**< GNSS gap threshold relative to the smallest fix spacing; default 1.5 */
  nav_replay_record_fn record; /**< may be NULL; also called at the initial epoch */
  nav_progress_fn progress;    /**< may be NULL; stage "replay", fraction of the IMU file read */
  void *user;                  /**< passed to every callback */
  /**
   * Initial navigation state other than the reference row (has_initial): a .nav row whose t_s
   * must be the initial epoch (within ref_sync_tol_s), e.g. the initial state with the drawn
   * initial errors that `navsim run --export kfgins` writes to kfgins/init.nav. The frame and
   * the scoring still come from the reference. Default: false (start from the reference row).
   */
  bool has_initial;
  nav_rec_pva initial;
  /** May be NULL; called with the errors of every scored epoch, the initial one included (the
   *  epochs of nav_replay_summary.stats plus the initial epoch), in time order. */
  void (*scored)(void *user, const nav_epoch_errors *e);
  /**
   * Tightly coupled replay (docs/rinex.md "Reading and replay"): when set, the GNSS aiding is the
   * raw measurements of this source instead of gnss_path's fixes (which must then be NULL), each
   * epoch applied with nav_ins_gnss_update_raw() at the IMU epoch within dt/2 of its t_s, as fixes
   * are; nav.filter must have the receiver-clock states (NAV_FILTER_STATE_RX_CLOCK). Outages drop
   * epochs as they drop fixes; the summary's gnss_* counts count epochs. Default NULL.
   */
  nav_replay_raw_fn raw;
  void *raw_user; /**< passed to @p raw */
  /**
   * The IMU records already read from imu_path (nav_rec_imu_array_load(); not kept, must outlive
   * the call): the replay takes them instead of reading the file again, with the same results
   * (imu_path still names the file in messages; the progress fraction counts records). Default
   * NULL: imu_path is streamed.
   */
  const nav_rec_imu_array *imu;
  /**
   * The IMU records of imu_path as a stream being read (nav_rec_imu_stream_start(); not kept,
   * must outlive the call): the navigation starts on the first records while the rest is read.
   * The records and results are those of the file read by the replay itself; if the stream
   * turns out bad, the run stops at once with its status (the caller reports the stream's
   * message from nav_rec_imu_stream_finish()). Exclusive with @p imu. Default NULL.
   */
  nav_rec_imu_stream *imu_stream;
  /**
   * Read the reference (and a streamed IMU file) on a second thread, ahead of the navigation,
   * through a bounded queue: the same records in the same order, so the same results and
   * messages; memory stays flat. Default true; false reads them on the calling thread.
   */
  bool read_ahead;
  /**
   * Score the epochs and call @p record and @p scored on a second thread, in epoch order and with
   * the same arguments, while the navigation goes on (the initial epoch's calls stay on the
   * calling thread). The callbacks must then not share unsynchronised data with @p progress or
   * the caller, nor read the filter; a NAV_STOP from @p record stops the navigation up to a few
   * thousand epochs later (the partial summary counts them). Default false: every callback on the
   * calling thread, the run stopped at once.
   */
  bool callbacks_on_worker;
} nav_replay_config;

/**
 * Defaults: no paths; nav = WGS-84, high-order mechanization in NED, normal gravity, the filter
 * defaults of nav_filter_config_default() (a tactical-grade IMU; P0 1 m / 0.1 m/s / 0.1 deg
 * level, 1 deg heading), no lever arm, sigma floors 1e-3 m and 1e-3 m/s; whole files; no
 * outages; ref_sync_tol_s 1e-4 s; output_interval_s 0.1 s; gap_factor 1.5.
 */
NAV_API nav_replay_config nav_replay_config_default(void);

/**
 * Replay recorded data through our navigation and score it.
 *
 * The initial epoch is the first IMU epoch at or after t_start_s with a reference row; the
 * navigation starts from that row (exactly, as KF-GINS is given its initial state) and the
 * increments up to it are skipped. Then each IMU increment in file order: step (raw increments;
 * the integration subtracts its bias estimates), apply the fixes whose time is within dt/2 of the
 * epoch (position, and velocity for 13-column files), and score the epoch if a reference row
 * coincides with it (ref_sync_tol_s). The navigation never reads the reference after the initial
 * epoch. Streams all three files (read_ahead: on a second thread): memory does not grow with their
 * length, except for the caller's nav_replay_config.imu.
 *
 * @param[in]  cfg  inputs and settings (not kept)
 * @param[out] out  summary; written on NAV_OK and on NAV_ERR_CANCELLED (partial)
 * @param[out] diag on failure, the problem (FILE:LINE:COL for input errors); may be NULL
 * @return NAV_OK; NAV_ERR_IO / NAV_ERR_PARSE (input files); NAV_ERR_INVALID_ARG (settings, no
 *         reference row at any IMU epoch, no IMU epoch in the window); NAV_ERR_NUMERIC /
 *         NAV_ERR_OUT_OF_RANGE (navigation failure, with the time in the message);
 *         NAV_ERR_CANCELLED (a callback returned NAV_STOP); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_replay_run(const nav_replay_config *cfg, nav_replay_summary *out,
                                                nav_diag *diag);

/**
 * Score another program's .nav output (KF-GINS, pyins, ...) against the reference with the
 * same metrics as nav_replay_run(), over the rows of @p est_path that coincide with a reference
 * row within @p sync_tol_s and lie in the optional window [t_start_s, t_end_s]. Streams both
 * files. The result is comparable with a replay only for the same window and epoch rate.
 * @param[out] out  statistics (written on NAV_OK)
 * @param[out] diag on failure, what and where (may be NULL)
 * @return NAV_OK; the reader statuses; NAV_ERR_INVALID_ARG if no row coincides.
 */
NAV_API NAV_NODISCARD nav_status nav_replay_score_pva(const char *ref_path, const char *est_path,
                                                      bool has_start, double t_start_s, bool has_end,
                                                      double t_end_s, double sync_tol_s,
                                                      nav_replay_stats *out, nav_diag *diag);

NAV_END_DECLS

#endif /* NAV_RECORDED_H */
