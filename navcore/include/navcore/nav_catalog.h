/**
 * @file nav_catalog.h
 * @brief navcore_io: the IMU and GNSS receiver catalogs (CSV in resources/), converted once to the
 *        SI sensor-model configurations of nav_sensors.h.
 *
 * File format (resources/README.md has the full column list and the provenance of every row):
 * RFC 4180 CSV, UTF-8, first row = column names, units in the column names, one sensor per row,
 * an empty cell = "not specified by the source" (the term is then off in the model). Quoted cells
 * may contain commas and doubled quotes, not line breaks. The kind of catalog is recognised from
 * the header: an IMU catalog has a @c name column, a GNSS catalog a @c mode column, an
 * accelerometer catalog (single-axis parts for the arrays of the gyro-free INS) a @c part column.
 *
 * Every problem is reported as a ::nav_diag "FILE:LINE:COL: error: COLUMN: MESSAGE" pointing at
 * the offending cell, and loading goes on to report every problem it can find (up to
 * NAV_DIAG_MAX_PER_FILE); a catalog with any problem is not returned. Checks: unknown, duplicate
 * or missing columns; wrong cell count; numbers that do not parse completely, are not finite or
 * are out of range; duplicated names (case-insensitive); an unknown verification status or bias
 * model; and columns that state one quantity twice (datasheet unit and SI, e.g.
 * gyro_arw_deg_per_sqrt_h and gyro_arw_rad_per_sqrt_s) but disagree by more than the 6-digit
 * rounding of the file (relative 2e-5).
 *
 * @par Conversion of an IMU row (numerics.md section 7)
 * All values are taken as 1-sigma per axis, the same on x, y and z.
 * - ARW / VRW -> NOISE (nav_unit_deg_per_sqrt_h_to_rad_per_sqrt_s(),
 * nav_unit_mps_per_sqrt_h_to_mps_per_sqrt_s()).
 * - Bias instability, by the row's @c bias_model column:
 *   - @c allan_min (default): a datasheet Allan floor B -> BIAS_GM with sigma from
 *     nav_gm_sigma_from_bias_instability(B, options.convention) and T = bias_corr_time_s if the
 *     row gives it, else tau_min / 1.8926 with the grade's default tau_min (options);
 *   - @c gm_sigma: the value already is a GM sigma (gnss-ins-sim, KF-GINS tunings) -> BIAS_GM with
 *     sigma = value, T = bias_corr_time_s (required);
 *   - @c turn_on: the value is a per-run constant (Groves' demo models) -> BIAS_TURN_ON sd.
 * - Turn-on bias columns -> BIAS_TURN_ON sd; scale factor ppm -> SCALE_FACTOR sd; misalignment
 *   mrad -> MISALIGNMENT sd of every off-diagonal element, gyro and accelerometer.
 *
 * @par Conversion of an accelerometer row (one sensitive axis; nav_array_error_config)
 * - noise density (ug/sqrt(Hz), = the VRW of the axis) -> NOISE, vrw_mps_per_sqrt_s = value * 1e-6 g0;
 * - bias instability by @c bias_model as for an IMU row (allan_min: GM with sigma = B / 0.61736 or
 *   B, T = bias_corr_time_s or the grade's default tau_min / 1.8926; gm_sigma; turn_on);
 * - bias repeatability (mg; run-to-run / turn-on, often a typical or maximum figure) -> BIAS_TURN_ON sd;
 * - scale factor (ppm) -> SCALE_FACTOR sd.
 * Range and bandwidth are kept for display and checks; the array model has no saturation term.
 *
 * @par Conversion of a GNSS row
 * horizontal / vertical sigma and correlation_time_s -> POS_GM (N, E / D; tau 0 = white);
 * velocity sigma -> VEL_WHITE on N, E and D; update_rate_hz. No lever arm, latency or outage.
 *
 * Not thread-safe per object; different catalogs are independent.
 */
#ifndef NAV_CATALOG_H
#define NAV_CATALOG_H

#include <stddef.h>

#include "nav_export.h"
#include "nav_io.h"
#include "nav_scene.h"
#include "nav_sensors.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

#define NAV_CATALOG_NAME_MAX 96          /**< bytes of a name (with NUL) */
#define NAV_CATALOG_GRADE_MAX 64         /**< bytes of a grade */
#define NAV_CATALOG_SOURCE_MAX 512       /**< bytes of a source citation */
#define NAV_CATALOG_VERIFIED_MAX 96      /**< bytes of a verification status text */
#define NAV_CATALOG_MAX_ENTRIES 1000     /**< rows per file */
#define NAV_CATALOG_MAX_BYTES (4u << 20) /**< largest file accepted (4 MiB) */
/**
 * Indicative cost classes (column cost_class, optional; resources/README.md): order-of-magnitude
 * unit price bands by grade, not quotes: 1 < 100 USD (consumer MEMS chips, standalone receiver
 * modules), 2 100 USD - 1 kUSD, 3 1-10 kUSD, 4 10-100 kUSD, 5 > 100 kUSD (navigation grade).
 */
#define NAV_CATALOG_COST_CLASS_MAX 5

/** Which catalog a file holds (recognised from its header). */
typedef enum nav_catalog_kind {
  NAV_CATALOG_IMU = 0,  /**< resources/imu_catalog.csv */
  NAV_CATALOG_GNSS = 1, /**< resources/gnss_receivers.csv */
  NAV_CATALOG_ACCEL = 2 /**< resources/accel_catalog.csv (parts for accelerometer arrays) */
} nav_catalog_kind;

/** How far a row's numbers were checked against their source (column verified_in_corpus). */
typedef enum nav_catalog_verification {
  NAV_CATALOG_VERIFIED_YES = 0,     /**< "yes...": read from the cited public source */
  NAV_CATALOG_VERIFIED_PARTLY = 1,  /**< "partly...": some numbers verified, some not */
  NAV_CATALOG_VERIFIED_DERIVED = 2, /**< "derived...": computed from verified inputs */
  NAV_CATALOG_VERIFIED_NO = 3       /**< "no...": quoted from memory; check the datasheet */
} nav_catalog_verification;

/** Meaning of an IMU row's bias-instability columns (column bias_model). */
typedef enum nav_catalog_bias_model {
  NAV_CATALOG_BIAS_ALLAN_MIN = 0, /**< "allan_min": datasheet Allan-deviation floor B */
  NAV_CATALOG_BIAS_GM_SIGMA = 1,  /**< "gm_sigma": the sigma of a GM with T = bias_corr_time_s */
  NAV_CATALOG_BIAS_TURN_ON = 2    /**< "turn_on": sigma of a per-run constant bias */
} nav_catalog_bias_model;

/** Conversion options. */
typedef struct nav_catalog_options {
  nav_bi_convention convention;  /**< sigma mapping of allan_min rows (default NAV_BI_ALLAN_PEAK) */
  double default_tau_min_mems_s; /**< Allan-minimum location assumed for MEMS allan_min rows without
                                      bias_corr_time_s [s] (default 300, within numerics.md's 100-1000 s) */
  double default_tau_min_nav_s;  /**< the same for FOG / RLG / navigation grades [s] (default 7200,
                                      within numerics.md's 1-4 h) */
} nav_catalog_options;

/** @return the default options (documented on each field). */
NAV_API nav_catalog_options nav_catalog_options_default(void);

/** One IMU of the catalog. */
typedef struct nav_catalog_imu_entry {
  char name[NAV_CATALOG_NAME_MAX];              /**< e.g. "ADIS16465-1" */
  char grade[NAV_CATALOG_GRADE_MAX];            /**< e.g. "industrial MEMS" */
  char source[NAV_CATALOG_SOURCE_MAX];          /**< citation, verbatim */
  char verified_text[NAV_CATALOG_VERIFIED_MAX]; /**< verified_in_corpus, verbatim */
  nav_catalog_verification verified;
  nav_catalog_bias_model bias_model;
  int cost_class;              /**< indicative cost class 1..NAV_CATALOG_COST_CLASS_MAX; 0: not given */
  int line;                    /**< 1-based line of the row in the file */
  nav_imu_model_config config; /**< the converted model (terms on for given values) */
} nav_catalog_imu_entry;

/** One GNSS receiver class of the catalog. */
typedef struct nav_catalog_gnss_entry {
  char name[NAV_CATALOG_NAME_MAX]; /**< the mode column, e.g. "RTK fixed" */
  char source[NAV_CATALOG_SOURCE_MAX];
  char verified_text[NAV_CATALOG_VERIFIED_MAX];
  nav_catalog_verification verified;
  int cost_class; /**< indicative cost class 1..NAV_CATALOG_COST_CLASS_MAX; 0: not given */
  int line;
  nav_gnss_model_config config; /**< the converted model */
} nav_catalog_gnss_entry;

/** Which datasheet figures an accelerometer row gives (bits of nav_catalog_accel_entry.given). */
typedef enum nav_catalog_accel_given {
  NAV_CATALOG_ACCEL_HAS_RANGE = 1u << 0,            /**< range_g */
  NAV_CATALOG_ACCEL_HAS_BANDWIDTH = 1u << 1,        /**< bandwidth_hz */
  NAV_CATALOG_ACCEL_HAS_NOISE = 1u << 2,            /**< noise_density_ug_per_sqrt_hz */
  NAV_CATALOG_ACCEL_HAS_BIAS_INSTABILITY = 1u << 3, /**< bias_instability_ug */
  NAV_CATALOG_ACCEL_HAS_BIAS_REPEAT = 1u << 4,      /**< bias_repeatability_mg */
  NAV_CATALOG_ACCEL_HAS_SCALE_FACTOR = 1u << 5,     /**< scale_factor_ppm */
  NAV_CATALOG_ACCEL_HAS_CORR_TIME = 1u << 6         /**< bias_corr_time_s */
} nav_catalog_accel_given;

/**
 * One accelerometer part of the array catalog: its datasheet figures in datasheet units (for
 * display; a figure is given when its bit is set in @c given) and the per-sensor error model of an
 * array they convert to (nav_scene_array.accel).
 */
typedef struct nav_catalog_accel_entry {
  char name[NAV_CATALOG_NAME_MAX];              /**< the part column, e.g. "Safran Colibrys MS1010" */
  char grade[NAV_CATALOG_GRADE_MAX];            /**< e.g. "tactical MEMS" */
  char source[NAV_CATALOG_SOURCE_MAX];          /**< citation, verbatim */
  char verified_text[NAV_CATALOG_VERIFIED_MAX]; /**< verified_in_corpus, verbatim */
  nav_catalog_verification verified;
  nav_catalog_bias_model bias_model;
  int cost_class;      /**< indicative cost class 1..NAV_CATALOG_COST_CLASS_MAX; 0: not given */
  int line;            /**< 1-based line of the row in the file */
  unsigned given;      /**< OR of ::nav_catalog_accel_given */
  double range_g;      /**< full scale, +/- [g] */
  double bandwidth_hz; /**< bandwidth [Hz] */
  double noise_density_ug_per_sqrt_hz; /**< white-noise density [ug/sqrt(Hz)] */
  double bias_instability_ug;          /**< bias instability [ug] (meaning: bias_model) */
  double bias_repeatability_mg;        /**< run-to-run bias [mg] */
  double scale_factor_ppm;             /**< scale-factor error [ppm] */
  double bias_corr_time_s;             /**< GM correlation time given by the row [s] */
  nav_array_error_config config;       /**< the converted per-sensor model (SI) */
} nav_catalog_accel_entry;

/** A loaded catalog (one kind). Opaque; owns its entries. */
typedef struct nav_catalog nav_catalog;

/**
 * Load and convert a catalog file.
 * @param[in]  path   CSV file
 * @param[in]  opt    conversion options; NULL for nav_catalog_options_default()
 * @param[out] out    the catalog, written only on NAV_OK; destroy with nav_catalog_destroy()
 * @param[in]  report receives each diagnostic (may be NULL)
 * @param[in]  user   passed to @p report
 * @return NAV_OK; NAV_ERR_IO (unreadable or larger than NAV_CATALOG_MAX_BYTES; one diagnostic
 *         with line 0); NAV_ERR_PARSE (at least one diagnostic); NAV_ERR_INVALID_ARG;
 *         NAV_ERR_NO_MEMORY.
 *
 * @code
 * nav_catalog *cat = NULL;
 * if (nav_catalog_load("resources/imu_catalog.csv", NULL, &cat, print_diag, NULL) == NAV_OK) {
 *   const nav_catalog_imu_entry *e = nav_catalog_find_imu(cat, "ADIS16465-1");
 *   if (e) { nav_imu_model *m = NULL; if (nav_imu_model_create(&e->config, seed, run, &m) == NAV_OK) ... }
 *   nav_catalog_destroy(cat);
 * }
 * @endcode
 */
NAV_API NAV_NODISCARD nav_status nav_catalog_load(const char *path, const nav_catalog_options *opt,
                                                  nav_catalog **out, nav_diag_fn report, void *user);

/** As nav_catalog_load(), from memory; @p display_name is the FILE of the diagnostics. */
NAV_API NAV_NODISCARD nav_status nav_catalog_load_string(const char *text, size_t len,
                                                         const char *display_name,
                                                         const nav_catalog_options *opt, nav_catalog **out,
                                                         nav_diag_fn report, void *user);

/** Destroy; accepts NULL. */
NAV_API void nav_catalog_destroy(nav_catalog *cat);

/** Kind of a loaded catalog. */
NAV_API nav_catalog_kind nav_catalog_get_kind(const nav_catalog *cat);

/** Number of entries (0 for NULL). */
NAV_API size_t nav_catalog_count(const nav_catalog *cat);

/** Entry @p i of an IMU catalog; NULL if out of range or not an IMU catalog. Borrowed until destroy. */
NAV_API const nav_catalog_imu_entry *nav_catalog_imu_at(const nav_catalog *cat, size_t i);

/** Entry @p i of a GNSS catalog; NULL if out of range or not a GNSS catalog. Borrowed until destroy. */
NAV_API const nav_catalog_gnss_entry *nav_catalog_gnss_at(const nav_catalog *cat, size_t i);

/** Entry @p i of an accelerometer catalog; NULL if out of range or another kind. Borrowed until destroy. */
NAV_API const nav_catalog_accel_entry *nav_catalog_accel_at(const nav_catalog *cat, size_t i);

/** Accelerometer part by name (ASCII case-insensitive); NULL if absent. Borrowed until destroy. */
NAV_API const nav_catalog_accel_entry *nav_catalog_find_accel(const nav_catalog *cat, const char *name);

/** IMU entry by name (ASCII case-insensitive, exact otherwise); NULL if absent. Borrowed until destroy. */
NAV_API const nav_catalog_imu_entry *nav_catalog_find_imu(const nav_catalog *cat, const char *name);

/** GNSS entry by mode name (ASCII case-insensitive); NULL if absent. Borrowed until destroy. */
NAV_API const nav_catalog_gnss_entry *nav_catalog_find_gnss(const nav_catalog *cat, const char *name);

/** Price band of a cost class ("< 100 USD" ... "> 100 kUSD"; "not given" for 0 or out of range). */
NAV_API const char *nav_catalog_cost_band(int cost_class);

/** "yes", "partly", "derived", "no". */
NAV_API const char *nav_catalog_verification_name(nav_catalog_verification v);

/** "allan_min", "gm_sigma", "turn_on". */
NAV_API const char *nav_catalog_bias_model_name(nav_catalog_bias_model m);

NAV_END_DECLS

#endif /* NAV_CATALOG_H */
