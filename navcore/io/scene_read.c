/*
 * Scene files, format_version 1: the YAML reader (libfyaml) and the schema tables it shares with
 * the writer. See scene_io_internal.h for how the tables are laid out and extended. The
 * trajectory part of the schema (waypoints, segment scripts, test motions, motion-definition
 * imports) lives in scene_traj_io.c; the custom fields of the sensor sections (catalog look-ups,
 * "off" lists, GNSS outages) are read and written here, next to their tables.
 *
 * Reading goes in six steps, and each step reports what it finds through nav_diag:
 *   1. size cap and a UTF-8 / binary check of the raw bytes (libfyaml silently drops some invalid
 *      bytes, so it must not see them);
 *   2. libfyaml's event parser builds a small tree of our own (nav_io_node) that keeps the
 *      1-based line/column of every node. Aliases are kept as alias nodes and never expanded, so
 *      alias bombs cost nothing; nesting depth and node count are capped;
 *   3. the tree is walked against the schema tables: unknown keys (with did-you-mean), duplicate
 *      keys, two spellings of one quantity, wrong node kinds, numbers, enums, ranges; every field
 *      read leaves (path -> line:col) in a small map;
 *   4. what needs the whole file (nav_io_traj_finish): waypoints given as latitude/longitude are
 *      converted with the scene's Earth, a motion-definition file is imported, waypoint and
 *      segment scripts are planned (feasibility, and their length for duration_s auto);
 *   5. nav_scene_validate() runs on the result; each (path, message) it reports is placed at the
 *      node of that path (or its nearest parent present in the file, else line 0);
 *   6. the scene is copied out only if nothing was reported.
 *
 * Format rules (v1):
 * - format_version is required: a file without it is not taken for a scene. Versions 1 ..
 *   NAV_SCENE_FORMAT_VERSION are read; a newer version is reported once and nothing else is read.
 *   Every other key is optional and keeps its nav_scene_default() value.
 * - One YAML document per file, UTF-8 (a BOM is allowed), no aliases, no tags; at most
 *   NAV_IO_MAX_INPUT_BYTES (16 MiB), NAV_IO_MAX_DEPTH levels and NAV_IO_MAX_NODES nodes.
 * - Numbers are YAML 1.2 decimal ints/floats (1, -2.5, 1e-3, .5); .inf/.nan are rejected where a
 *   finite value is required (all v1 doubles). Quoted strings and booleans are not numbers.
 *   Integers also accept 0x.. and 0o..; floats are not integers. Booleans are true / false.
 * - Angles may be given as _deg or _rad (rates as _rps or _dps); giving both is an error.
 *   Sensor figures are given in datasheet units (deg/h, deg/sqrt(h), mg, ug, ppm, mrad, ...) or
 *   in SI; they are converted once, here, by the factors of the nav_unit_* helpers.
 * - Keys are read in any order (YAML mappings are unordered): the keys that others build on
 *   (imu.bias_convention, imu.catalog, gnss.catalog, array.catalog) are applied first, "off" lists
 *   last; array.catalog converts allan_min rows with the default convention (allan_peak).
 * - An empty section ("imu:") means all defaults.
 */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <inttypes.h>
#include <limits.h>
#include <math.h>
#include <stdalign.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <libfyaml.h>

#include "navcore/nav_catalog.h"
#include "navcore/nav_earth.h"
#include "navcore/nav_io.h"
#include "navcore/nav_paths.h"
#include "navcore/nav_sensors.h"
#include "scene_bounds.h"
#include "scene_io_internal.h"

/* Enums are stored through int pointers by the table-driven reader and writer. */
_Static_assert(sizeof(nav_earth_model) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_traj_type) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_attitude_mode) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_mech_algorithm) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_gravity_model) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_mech_frame) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_nav_scheme) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_bi_convention) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_array_layout_kind) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_req_metric) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_req_statistic) == sizeof(int), "enum storage");
_Static_assert(sizeof(nav_req_unit) == sizeof(int), "enum storage");

#define PATH_MAX_LEN ((size_t)sizeof(((nav_diag *)0)->path))
#define MAX_SECTION_FIELDS 64 /* descriptors per section; checked when a section is read */
#define SHOW_MAX 40           /* bytes of a user value quoted back in a message */

/* ================================================================ schema, format_version 1 */

#define OFF(member) offsetof(nav_scene, member)
#define SOFF(member) offsetof(nav_io_read_state, member)
#define COUNT(a) (sizeof(a) / sizeof((a)[0]))
/* A section table; the reader tracks seen keys in arrays of MAX_SECTION_FIELDS. */
#define DEFINE_SECTION(name, fields)                                                                         \
  _Static_assert(COUNT(fields) <= MAX_SECTION_FIELDS, #fields ": too many fields");                          \
  static const nav_io_section name = {fields, COUNT(fields), NULL}
#define DEFINE_SECTION_FINISH(name, fields, fin)                                                             \
  _Static_assert(COUNT(fields) <= MAX_SECTION_FIELDS, #fields ": too many fields");                          \
  static const nav_io_section name = {fields, COUNT(fields), fin}

#define NONNEG (NAV_IO_FINITE | NAV_IO_MIN_GE) /* with .min = 0 */
#define POSITIVE (NAV_IO_FINITE | NAV_IO_MIN_GT)
/* Plausibility bounds of the sensor error terms (scene_bounds.h), in the key's file unit: NONNEG_LE
   with .max = B, SIGNED_LE with PM(B) (.min = -B, .max = B). MAXU converts a bound b given in the
   unit of factor k0 to a key of scale sc (exactly b for that unit itself). */
#define NONNEG_LE (NONNEG | NAV_IO_MAX_LE)
#define SIGNED_LE (NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE)
#define MAXU(b, k0, sc) ((sc) == (k0) ? (b) : (b) * (k0) / (sc))
#define PM(b) .min = -(b), .max = (b)
/* The bound of each quantity for a key of scale sc. */
#define B_ARW(sc) MAXU(NAV_SCENE_MAX_GYRO_ARW_DEG_PER_SQRT_H, K_DEG_PER_SQRT_H, sc)
#define B_GBIAS(sc) MAXU(NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H, K_DEG_PER_H, sc)
#define B_GBI(sc) MAXU(NAV_SCENE_MAX_GYRO_BI_DEG_PER_H, K_DEG_PER_H, sc)
#define B_RRW(sc) MAXU(NAV_SCENE_MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H, K_DEG_PER_H_PER_SQRT_H, sc)
#define B_GSENS(sc) MAXU(NAV_SCENE_MAX_G_SENSITIVITY_DEG_PER_H_PER_G, K_DEG_PER_H_PER_G, sc)
#define B_VRW(sc) MAXU(NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H, K_PER_SQRT_H, sc)
#define B_ABIAS(sc) MAXU(NAV_SCENE_MAX_ACCEL_BIAS_MG, K_MG, sc)
#define B_ABI(sc) MAXU(NAV_SCENE_MAX_ACCEL_BI_UG, K_UG, sc)
#define B_ABRW(sc) MAXU(NAV_SCENE_MAX_ACCEL_BIAS_RW_M_PER_S2_PER_SQRT_H, K_PER_SQRT_H, sc)
#define B_SF(sc) MAXU(NAV_SCENE_MAX_SCALE_FACTOR_PPM, K_PPM, sc)
#define B_MIS(sc) MAXU(NAV_SCENE_MAX_MISALIGNMENT_MRAD, K_MRAD, sc)

/* Datasheet units -> SI: file value x factor, the factor being the nav_unit_* helper of
   nav_sensors.h applied to 1 (the helpers are inline functions, not constant expressions):
   deg/h, deg/sqrt(h), deg/h/sqrt(h), deg/h/g, (m/s)/sqrt(h), mg, ug (also ug/sqrt(Hz)), ppm, mrad. */
#define K_DEG_PER_H (NAV_DEG2RAD / 3600.0)
#define K_DEG_PER_SQRT_H (NAV_DEG2RAD / 60.0)
#define K_DEG_PER_H_PER_SQRT_H (NAV_DEG2RAD / 3600.0 / 60.0)
#define K_DEG_PER_H_PER_G (NAV_DEG2RAD / 3600.0 / NAV_G0_MPS2)
#define K_PER_SQRT_H (1.0 / 60.0)
#define K_MG (1e-3 * NAV_G0_MPS2)
#define K_UG (1e-6 * NAV_G0_MPS2)
#define K_PPM 1e-6
#define K_MRAD 1e-3

static void read_format_version(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                                const nav_io_node *value, void *base);
static nav_status write_format_version(nav_io_writer *w, const nav_io_field *f, const void *base,
                                       int indent) {
  (void)f;
  (void)base;
  (void)indent;
  /* The writer always emits the current version (style.md section 11). */
  return nav_io_writef(w, " %d", NAV_SCENE_FORMAT_VERSION);
}
static void read_catalog(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *value, void *base);
static nav_status write_catalog(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
static bool same_string(const nav_io_field *f, const void *a, const void *b);
static bool catalog_given(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def);
static void read_off(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                     const nav_io_node *value, void *base);
static nav_status write_off(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
static bool off_needed(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def);
static bool same_terms(const nav_io_field *f, const void *a, const void *b);
static void read_outages(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *value, void *base);
static nav_status write_outages(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
static bool same_outages(const nav_io_field *f, const void *a, const void *b);
static void read_reported(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                          const nav_io_node *value, void *base);
static nav_status write_reported(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
static bool same_reported(const nav_io_field *f, const void *a, const void *b);
static void schema_format_version(nav_io_json *j, const nav_io_field *f);
static void schema_catalog(nav_io_json *j, const nav_io_field *f);
static void schema_off(nav_io_json *j, const nav_io_field *f);
static void schema_outages(nav_io_json *j, const nav_io_field *f);
static void schema_reported(nav_io_json *j, const nav_io_field *f);
static void finish_gyro(nav_io_reader *r, const nav_io_node *map, void *base);
static void finish_accel(nav_io_reader *r, const nav_io_node *map, void *base);
static bool gnss_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def);
static void read_array_sensors(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                               const nav_io_node *value, void *base);
static nav_status write_array_sensors(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
static bool same_array_sensors(const nav_io_field *f, const void *a, const void *b);
static bool array_sensors_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                  const void *def);
static bool array_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def);

static const nav_io_enum_value k_earth_models[] = {
    {"flat", NAV_EARTH_FLAT}, {"wgs84", NAV_EARTH_WGS84}, {NULL, 0}};
static const nav_io_enum_value k_gravity_models[] = {
    {"normal", NAV_GRAVITY_NORMAL}, {"j2", NAV_GRAVITY_J2}, {NULL, 0}};
static const nav_io_enum_value k_mech_frames[] = {{"ned", NAV_MECH_NED}, {"ecef", NAV_MECH_ECEF}, {NULL, 0}};
static const nav_io_enum_value k_mech_algorithms[] = {
    {"first_order", NAV_MECH_FIRST_ORDER}, {"high_order", NAV_MECH_HIGH_ORDER}, {NULL, 0}};
static const nav_io_enum_value k_schemes[] = {{"free_ins", NAV_SCHEME_FREE_INS},
                                              {"ins_gnss", NAV_SCHEME_INS_GNSS},
                                              {"gyro_free", NAV_SCHEME_GYRO_FREE},
                                              {"gyro_free_gnss", NAV_SCHEME_GYRO_FREE_GNSS},
                                              {"ins_gnss_tight", NAV_SCHEME_INS_GNSS_TIGHT},
                                              {NULL, 0}};
static const nav_io_enum_value k_array_layouts[] = {{"cube6", NAV_ARRAY_LAYOUT_CUBE6},
                                                    {"nine", NAV_ARRAY_LAYOUT_NINE},
                                                    {"twelve", NAV_ARRAY_LAYOUT_TWELVE},
                                                    {"custom", NAV_ARRAY_LAYOUT_CUSTOM},
                                                    {NULL, 0}};
static const nav_io_enum_value k_bi_conventions[] = {
    {"allan_peak", NAV_BI_ALLAN_PEAK}, {"sigma_equals_b", NAV_BI_SIGMA_EQUALS_B}, {NULL, 0}};

/* Plain descriptors; each field's range and flags are spelled out where it is listed. */
#define F_DOUBLE(k, member, sc, fl, ...)                                                                     \
  { .key = (k), .kind = NAV_IO_DOUBLE, .flags = (fl), .offset = OFF(member), .scale = (sc), __VA_ARGS__ }
/* One angle in degrees (preferred, as in the canonical example) or radians. */
#define ANGLE_DEG_RAD(name, member, text)                                                                    \
  F_DOUBLE(name "_deg", member, NAV_DEG2RAD, NAV_IO_FINITE, .doc = (text)),                                  \
      F_DOUBLE(name "_rad", member, 1.0, NAV_IO_FINITE | NAV_IO_ALT, .doc = (text))

/* The latitude range and the height range are nav_scene_validate's (NAV_IO_RANGE_LATER). */
static const nav_io_field k_origin[] = {
    F_DOUBLE("lat_deg", earth.origin_lat_rad, NAV_DEG2RAD,
             NAV_IO_FINITE | NAV_IO_RANGE_LATER | NAV_IO_MIN_GE | NAV_IO_MAX_LE, .min = -90.0, .max = 90.0,
             .doc = "geodetic latitude of the scene origin (WGS-84)"),
    F_DOUBLE("lat_rad", earth.origin_lat_rad, 1.0,
             NAV_IO_FINITE | NAV_IO_ALT | NAV_IO_RANGE_LATER | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
             .min = -NAV_PI / 2, .max = NAV_PI / 2, .doc = "geodetic latitude of the scene origin (WGS-84)"),
    ANGLE_DEG_RAD("lon", earth.origin_lon_rad, "longitude of the scene origin"),
    F_DOUBLE("h_m", earth.origin_h_m, 1.0, NAV_IO_FINITE | NAV_IO_RANGE_LATER | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
             .min = -1.0e5, .max = 1.0e8, .doc = "ellipsoidal height of the scene origin"),
};
DEFINE_SECTION(k_origin_section, k_origin);

static const nav_io_field k_earth[] = {
    {.key = "model",
     .doc = "flat: uniform gravity in a local frame; wgs84: the WGS-84 ellipsoid with Earth rate",
     .kind = NAV_IO_ENUM,
     .offset = OFF(earth.model),
     .enums = k_earth_models},
    {.key = "origin",
     .doc = "scene origin: the origin of the local NED frame",
     .kind = NAV_IO_SECTION,
     .flags = NAV_IO_FLOW,
     .section = &k_origin_section},
    {.key = "gravity_mps2",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE,
     .offset = OFF(earth.flat_gravity_mps2),
     .scale = 1.0,
     .comment = "flat model only: uniform gravity, pointing down"},
    {.key = "gravity_model",
     .kind = NAV_IO_ENUM,
     .offset = OFF(earth.gravity_model),
     .enums = k_gravity_models,
     .comment = "wgs84 only: normal (Somigliana) or j2"},
};
DEFINE_SECTION(k_earth_section, k_earth);

#define RATE_HZ(member, text)                                                                                \
  {                                                                                                          \
    .key = "rate_hz", .kind = NAV_IO_DOUBLE, .flags = NAV_IO_FINITE | NAV_IO_MIN_GT | NAV_IO_MAX_LE,         \
    .offset = OFF(member), .scale = 1.0, .min = 0.0, .max = NAV_SCENE_MAX_RATE_HZ, .doc = (text)             \
  }

/* ---------------------------------------------------------------- IMU error model */

/* One quantity of an error term: key, kind, flags, scene member, scale, then designators (the
   term bit, mark_as). Its ALT spellings repeat the member and the term. */
#define Q(k, kd, fl, member, sc, ...)                                                                        \
  { .key = (k), .kind = (kd), .flags = (fl), .offset = OFF(member), .scale = (sc), __VA_ARGS__ }
/* An input kept in the reader state (bias instability and the location of the Allan minimum). */
#define QS(k, fl, member, sc, ...)                                                                           \
  {                                                                                                          \
    .key = (k), .kind = NAV_IO_VEC3S, .flags = (fl) | NAV_IO_STATE, .offset = SOFF(member), .scale = (sc),   \
    __VA_ARGS__                                                                                              \
  }
/* A bounded one (flags with NAV_IO_MAX_LE). */
#define QSB(k, fl, member, sc, mx, ...)                                                                      \
  {                                                                                                          \
    .key = (k), .kind = NAV_IO_VEC3S, .flags = (fl) | NAV_IO_STATE, .offset = SOFF(member), .scale = (sc),   \
    .max = (mx), __VA_ARGS__                                                                                 \
  }
#define G_TERM(b) .bit = (b), .bits_offset = OFF(imu.model.gyro.terms)
#define A_TERM(b) .bit = (b), .bits_offset = OFF(imu.model.accel.terms)
#define GM(m) imu.model.gyro.m
#define AM(m) imu.model.accel.m
#define ALTS (NAV_IO_ALT | NAV_IO_WRITE_ALT) /* an alternative the writer uses when it is shorter */

/*
 * Gyro triad (nav_gyro_error_config). Values are 1-sigma per axis; a scalar applies to x, y and
 * z. The bias instability B with the location tau_min of the Allan minimum is turned into the GM
 * bias by nav_gm_from_bias_instability() under imu.bias_convention; it is not stored, so the
 * writer writes the resulting bias_gm_sigma_* and bias_gm_tau_s.
 */
static const nav_io_field k_gyro[] = {
    Q("arw_deg_per_sqrt_h", NAV_IO_VEC3S, NONNEG_LE, GM(arw_rad_per_sqrt_s), K_DEG_PER_SQRT_H,
      .max = B_ARW(K_DEG_PER_SQRT_H), G_TERM(NAV_IMU_TERM_NOISE),
      .doc = "angle random walk (white rate noise), per axis"),
    Q("arw_rad_per_sqrt_s", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, GM(arw_rad_per_sqrt_s), 1.0,
      .max = B_ARW(1.0), G_TERM(NAV_IMU_TERM_NOISE)),
    Q("noise_density_deg_per_s_per_sqrt_hz", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, GM(arw_rad_per_sqrt_s),
      NAV_DEG2RAD, .max = B_ARW(NAV_DEG2RAD), G_TERM(NAV_IMU_TERM_NOISE)),
    Q("bias_turn_on_deg_per_h", NAV_IO_VEC3S, NONNEG_LE, GM(bias_turn_on_sd_rps), K_DEG_PER_H,
      .max = B_GBIAS(K_DEG_PER_H), G_TERM(NAV_IMU_TERM_BIAS_TURN_ON), .mark_as = "bias_turn_on_sd_rps",
      .doc = "turn-on bias, 1-sigma drawn once per run, per axis"),
    Q("bias_turn_on_dps", NAV_IO_VEC3S, NONNEG_LE | ALTS, GM(bias_turn_on_sd_rps), NAV_DEG2RAD,
      .max = B_GBIAS(NAV_DEG2RAD), G_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    Q("bias_turn_on_rps", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, GM(bias_turn_on_sd_rps), 1.0,
      .max = B_GBIAS(1.0), G_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    Q("bias_turn_on_fixed_deg_per_h", NAV_IO_VEC3S, SIGNED_LE, GM(bias_turn_on_fixed_rps), K_DEG_PER_H,
      PM(B_GBIAS(K_DEG_PER_H)), G_TERM(NAV_IMU_TERM_BIAS_TURN_ON),
      .doc = "turn-on bias: a fixed value per axis, added to the drawn one"),
    Q("bias_turn_on_fixed_dps", NAV_IO_VEC3S, SIGNED_LE | ALTS, GM(bias_turn_on_fixed_rps), NAV_DEG2RAD,
      PM(B_GBIAS(NAV_DEG2RAD)), G_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    Q("bias_turn_on_fixed_rps", NAV_IO_VEC3S, SIGNED_LE | NAV_IO_ALT, GM(bias_turn_on_fixed_rps), 1.0,
      PM(B_GBIAS(1.0)), G_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    QSB("bias_instability_deg_per_h", NONNEG_LE, bi[0], K_DEG_PER_H, B_GBI(K_DEG_PER_H),
        .doc = "bias instability B (Allan minimum), made a Gauss-Markov bias by imu.bias_convention"),
    QSB("bias_instability_rps", NONNEG_LE | NAV_IO_ALT, bi[0], 1.0, B_GBI(1.0), .doc = NULL),
    QS("bias_instability_tau_min_s", POSITIVE, bi_tau_min_s[0], 1.0,
       .doc = "averaging time of the Allan minimum of the bias instability"),
    Q("bias_gm_sigma_deg_per_h", NAV_IO_VEC3S, NONNEG_LE, GM(bias_gm_sd_rps), K_DEG_PER_H,
      .max = B_GBIAS(K_DEG_PER_H), G_TERM(NAV_IMU_TERM_BIAS_GM), .mark_as = "bias_gm_sd_rps",
      .doc = "Gauss-Markov (in-run) bias, 1-sigma per axis"),
    Q("bias_gm_sigma_rps", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, GM(bias_gm_sd_rps), 1.0, .max = B_GBIAS(1.0),
      G_TERM(NAV_IMU_TERM_BIAS_GM)),
    Q("bias_gm_tau_s", NAV_IO_VEC3S, POSITIVE, GM(bias_gm_tau_s), 1.0, G_TERM(NAV_IMU_TERM_BIAS_GM),
      .doc = "correlation time of the Gauss-Markov bias, per axis"),
    Q("rrw_deg_per_h_per_sqrt_h", NAV_IO_VEC3S, NONNEG_LE, GM(bias_rw_rps_per_sqrt_s), K_DEG_PER_H_PER_SQRT_H,
      .max = B_RRW(K_DEG_PER_H_PER_SQRT_H), G_TERM(NAV_IMU_TERM_BIAS_RW), .mark_as = "bias_rw_rps_per_sqrt_s",
      .doc = "rate random walk (random-walk bias), per axis"),
    Q("rrw_rps_per_sqrt_s", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, GM(bias_rw_rps_per_sqrt_s), 1.0,
      .max = B_RRW(1.0), G_TERM(NAV_IMU_TERM_BIAS_RW)),
    Q("scale_factor_ppm", NAV_IO_VEC3S, NONNEG_LE, GM(scale_factor_sd), K_PPM, .max = B_SF(K_PPM),
      G_TERM(NAV_IMU_TERM_SCALE_FACTOR), .doc = "scale-factor error, 1-sigma drawn per run, per axis"),
    Q("scale_factor_sd", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, GM(scale_factor_sd), 1.0, .max = B_SF(1.0),
      G_TERM(NAV_IMU_TERM_SCALE_FACTOR), .unit = "1"),
    Q("scale_factor_fixed_ppm", NAV_IO_VEC3S, SIGNED_LE, GM(scale_factor_fixed), K_PPM, PM(B_SF(K_PPM)),
      G_TERM(NAV_IMU_TERM_SCALE_FACTOR), .doc = "scale-factor error, a fixed value per axis"),
    Q("scale_factor_fixed", NAV_IO_VEC3S, SIGNED_LE | NAV_IO_ALT, GM(scale_factor_fixed), 1.0, PM(B_SF(1.0)),
      G_TERM(NAV_IMU_TERM_SCALE_FACTOR), .unit = "1"),
    Q("misalignment_mrad", NAV_IO_MAT3_OFFDIAG, NONNEG_LE, GM(misalignment_sd_rad), K_MRAD,
      .max = B_MIS(K_MRAD), G_TERM(NAV_IMU_TERM_MISALIGNMENT), .mark_as = "misalignment_sd_rad",
      .doc = "axis misalignment: 1-sigma of each off-diagonal element (one number or 3 rows of 3)"),
    Q("misalignment_rad", NAV_IO_MAT3_OFFDIAG, NONNEG_LE | NAV_IO_ALT, GM(misalignment_sd_rad), 1.0,
      .max = B_MIS(1.0), G_TERM(NAV_IMU_TERM_MISALIGNMENT)),
    Q("misalignment_fixed_mrad", NAV_IO_MAT3_OFFDIAG, SIGNED_LE, GM(misalignment_fixed_rad), K_MRAD,
      PM(B_MIS(K_MRAD)), G_TERM(NAV_IMU_TERM_MISALIGNMENT),
      .doc = "axis misalignment: fixed off-diagonal elements (one number or 3 rows of 3)"),
    Q("misalignment_fixed_rad", NAV_IO_MAT3_OFFDIAG, SIGNED_LE | NAV_IO_ALT, GM(misalignment_fixed_rad), 1.0,
      PM(B_MIS(1.0)), G_TERM(NAV_IMU_TERM_MISALIGNMENT)),
    Q("g_sensitivity_deg_per_h_per_g", NAV_IO_MAT3_DIAG, NONNEG_LE, GM(g_sensitivity_sd_rps_per_mps2),
      K_DEG_PER_H_PER_G, .max = B_GSENS(K_DEG_PER_H_PER_G), G_TERM(NAV_IMU_TERM_G_SENSITIVITY),
      .mark_as = "g_sensitivity_sd_rps_per_mps2",
      .doc = "g-sensitive bias, 1-sigma (diagonal: one or 3 numbers; or 3 rows of 3)"),
    Q("g_sensitivity_rps_per_mps2", NAV_IO_MAT3_DIAG, NONNEG_LE | NAV_IO_ALT,
      GM(g_sensitivity_sd_rps_per_mps2), 1.0, .max = B_GSENS(1.0), G_TERM(NAV_IMU_TERM_G_SENSITIVITY)),
    Q("g_sensitivity_fixed_deg_per_h_per_g", NAV_IO_MAT3_DIAG, SIGNED_LE,
      GM(g_sensitivity_fixed_rps_per_mps2), K_DEG_PER_H_PER_G, PM(B_GSENS(K_DEG_PER_H_PER_G)),
      G_TERM(NAV_IMU_TERM_G_SENSITIVITY),
      .doc = "g-sensitive bias, fixed values (diagonal: one or 3 numbers; or 3 rows of 3)"),
    Q("g_sensitivity_fixed_rps_per_mps2", NAV_IO_MAT3_DIAG, SIGNED_LE | NAV_IO_ALT,
      GM(g_sensitivity_fixed_rps_per_mps2), 1.0, PM(B_GSENS(1.0)), G_TERM(NAV_IMU_TERM_G_SENSITIVITY)),
    Q("quantisation_rad", NAV_IO_VEC3S, POSITIVE, GM(quant_step_rad), 1.0, G_TERM(NAV_IMU_TERM_QUANTISATION),
      .mark_as = "quant_step_rad", .doc = "quantisation step of the angle increments"),
    Q("range_dps", NAV_IO_VEC3S, POSITIVE, GM(range_rps), NAV_DEG2RAD, G_TERM(NAV_IMU_TERM_SATURATION),
      .doc = "measurement range (saturation), per axis"),
    Q("range_rps", NAV_IO_VEC3S, POSITIVE | NAV_IO_ALT, GM(range_rps), 1.0, G_TERM(NAV_IMU_TERM_SATURATION)),
};
DEFINE_SECTION_FINISH(k_gyro_section, k_gyro, finish_gyro);

/* Accelerometer triad (nav_accel_error_config); as the gyro, in g-based datasheet units. */
static const nav_io_field k_accel[] = {
    Q("vrw_m_per_s_per_sqrt_h", NAV_IO_VEC3S, NONNEG_LE, AM(vrw_mps_per_sqrt_s), K_PER_SQRT_H,
      .max = B_VRW(K_PER_SQRT_H), A_TERM(NAV_IMU_TERM_NOISE),
      .doc = "velocity random walk (white acceleration noise), per axis"),
    Q("vrw_mps_per_sqrt_s", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, AM(vrw_mps_per_sqrt_s), 1.0,
      .max = B_VRW(1.0), A_TERM(NAV_IMU_TERM_NOISE)),
    Q("noise_density_ug_per_sqrt_hz", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, AM(vrw_mps_per_sqrt_s), K_UG,
      .max = B_VRW(K_UG), A_TERM(NAV_IMU_TERM_NOISE)),
    Q("bias_turn_on_mg", NAV_IO_VEC3S, NONNEG_LE, AM(bias_turn_on_sd_mps2), K_MG, .max = B_ABIAS(K_MG),
      A_TERM(NAV_IMU_TERM_BIAS_TURN_ON), .mark_as = "bias_turn_on_sd_mps2",
      .doc = "turn-on bias, 1-sigma drawn once per run, per axis"),
    Q("bias_turn_on_mps2", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, AM(bias_turn_on_sd_mps2), 1.0,
      .max = B_ABIAS(1.0), A_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    Q("bias_turn_on_fixed_mg", NAV_IO_VEC3S, SIGNED_LE, AM(bias_turn_on_fixed_mps2), K_MG, PM(B_ABIAS(K_MG)),
      A_TERM(NAV_IMU_TERM_BIAS_TURN_ON),
      .doc = "turn-on bias: a fixed value per axis, added to the drawn one"),
    Q("bias_turn_on_fixed_mps2", NAV_IO_VEC3S, SIGNED_LE | NAV_IO_ALT, AM(bias_turn_on_fixed_mps2), 1.0,
      PM(B_ABIAS(1.0)), A_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    QSB("bias_instability_ug", NONNEG_LE, bi[1], K_UG, B_ABI(K_UG),
        .doc = "bias instability B (Allan minimum), made a Gauss-Markov bias by imu.bias_convention"),
    QSB("bias_instability_mps2", NONNEG_LE | NAV_IO_ALT, bi[1], 1.0, B_ABI(1.0), .doc = NULL),
    QS("bias_instability_tau_min_s", POSITIVE, bi_tau_min_s[1], 1.0,
       .doc = "averaging time of the Allan minimum of the bias instability"),
    Q("bias_gm_sigma_ug", NAV_IO_VEC3S, NONNEG_LE, AM(bias_gm_sd_mps2), K_UG, .max = B_ABIAS(K_UG),
      A_TERM(NAV_IMU_TERM_BIAS_GM), .mark_as = "bias_gm_sd_mps2",
      .doc = "Gauss-Markov (in-run) bias, 1-sigma per axis"),
    Q("bias_gm_sigma_mps2", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, AM(bias_gm_sd_mps2), 1.0,
      .max = B_ABIAS(1.0), A_TERM(NAV_IMU_TERM_BIAS_GM)),
    Q("bias_gm_tau_s", NAV_IO_VEC3S, POSITIVE, AM(bias_gm_tau_s), 1.0, A_TERM(NAV_IMU_TERM_BIAS_GM),
      .doc = "correlation time of the Gauss-Markov bias, per axis"),
    Q("bias_rw_m_per_s2_per_sqrt_h", NAV_IO_VEC3S, NONNEG_LE, AM(bias_rw_mps2_per_sqrt_s), K_PER_SQRT_H,
      .max = B_ABRW(K_PER_SQRT_H), A_TERM(NAV_IMU_TERM_BIAS_RW), .doc = "bias random walk, per axis"),
    Q("bias_rw_mps2_per_sqrt_s", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, AM(bias_rw_mps2_per_sqrt_s), 1.0,
      .max = B_ABRW(1.0), A_TERM(NAV_IMU_TERM_BIAS_RW)),
    Q("scale_factor_ppm", NAV_IO_VEC3S, NONNEG_LE, AM(scale_factor_sd), K_PPM, .max = B_SF(K_PPM),
      A_TERM(NAV_IMU_TERM_SCALE_FACTOR), .doc = "scale-factor error, 1-sigma drawn per run, per axis"),
    Q("scale_factor_sd", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, AM(scale_factor_sd), 1.0, .max = B_SF(1.0),
      A_TERM(NAV_IMU_TERM_SCALE_FACTOR), .unit = "1"),
    Q("scale_factor_fixed_ppm", NAV_IO_VEC3S, SIGNED_LE, AM(scale_factor_fixed), K_PPM, PM(B_SF(K_PPM)),
      A_TERM(NAV_IMU_TERM_SCALE_FACTOR), .doc = "scale-factor error, a fixed value per axis"),
    Q("scale_factor_fixed", NAV_IO_VEC3S, SIGNED_LE | NAV_IO_ALT, AM(scale_factor_fixed), 1.0, PM(B_SF(1.0)),
      A_TERM(NAV_IMU_TERM_SCALE_FACTOR), .unit = "1"),
    Q("misalignment_mrad", NAV_IO_MAT3_OFFDIAG, NONNEG_LE, AM(misalignment_sd_rad), K_MRAD,
      .max = B_MIS(K_MRAD), A_TERM(NAV_IMU_TERM_MISALIGNMENT), .mark_as = "misalignment_sd_rad",
      .doc = "axis misalignment: 1-sigma of each off-diagonal element (one number or 3 rows of 3)"),
    Q("misalignment_rad", NAV_IO_MAT3_OFFDIAG, NONNEG_LE | NAV_IO_ALT, AM(misalignment_sd_rad), 1.0,
      .max = B_MIS(1.0), A_TERM(NAV_IMU_TERM_MISALIGNMENT)),
    Q("misalignment_fixed_mrad", NAV_IO_MAT3_OFFDIAG, SIGNED_LE, AM(misalignment_fixed_rad), K_MRAD,
      PM(B_MIS(K_MRAD)), A_TERM(NAV_IMU_TERM_MISALIGNMENT),
      .doc = "axis misalignment: fixed off-diagonal elements (one number or 3 rows of 3)"),
    Q("misalignment_fixed_rad", NAV_IO_MAT3_OFFDIAG, SIGNED_LE | NAV_IO_ALT, AM(misalignment_fixed_rad), 1.0,
      PM(B_MIS(1.0)), A_TERM(NAV_IMU_TERM_MISALIGNMENT)),
    Q("quantisation_mps", NAV_IO_VEC3S, POSITIVE, AM(quant_step_mps), 1.0, A_TERM(NAV_IMU_TERM_QUANTISATION),
      .mark_as = "quant_step_mps", .doc = "quantisation step of the velocity increments"),
    Q("range_g", NAV_IO_VEC3S, POSITIVE, AM(range_mps2), NAV_G0_MPS2, A_TERM(NAV_IMU_TERM_SATURATION),
      .doc = "measurement range (saturation), per axis"),
    Q("range_mps2", NAV_IO_VEC3S, POSITIVE | NAV_IO_ALT, AM(range_mps2), 1.0,
      A_TERM(NAV_IMU_TERM_SATURATION)),
};
DEFINE_SECTION_FINISH(k_accel_section, k_accel, finish_accel);

static const nav_io_field k_imu[] = {
    RATE_HZ(imu.rate_hz, "IMU sample rate"),
    {.key = "quadrature_nodes",
     .doc = "Gauss-Legendre nodes of the ideal increments over one IMU interval",
     .kind = NAV_IO_INT,
     .flags = NAV_IO_RANGE_LATER | NAV_IO_MIN_GE | NAV_IO_MAX_LE, /* nav_scene_validate's range */
     .offset = OFF(imu.quadrature_nodes),
     .min = 1.0,
     .max = 16.0},
    {.key = "bias_convention",
     .doc =
         "how a bias instability B becomes a Gauss-Markov sigma: allan_peak (B / 0.6648) or sigma_equals_b",
     .kind = NAV_IO_ENUM,
     .flags = NAV_IO_STATE | NAV_IO_EARLY,
     .offset = SOFF(bias_convention),
     .enums = k_bi_conventions},
    {.key = "catalog",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_EARLY,
     .offset = OFF(imu.catalog),
     .size = NAV_SCENE_CATALOG_NAME_MAX,
     .read = read_catalog,
     .write = write_catalog,
     .same = same_string,
     .write_if = catalog_given,
     .comment = "resources/imu_catalog.csv; the keys below override it",
     .schema = schema_catalog},
    {.key = "gyro",
     .doc = "gyro triad error model (1-sigma per axis; one number applies to all three axes)",
     .kind = NAV_IO_SECTION,
     .section = &k_gyro_section},
    {.key = "accel",
     .doc = "accelerometer triad error model (1-sigma per axis; one number applies to all three axes)",
     .kind = NAV_IO_SECTION,
     .section = &k_accel_section},
    {.key = "off",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_LATE,
     .offset = OFF(imu.model),
     .read = read_off,
     .write = write_off,
     .same = same_terms,
     .write_if = off_needed,
     .comment = "terms switched off",
     .schema = schema_off},
};
DEFINE_SECTION(k_imu_section, k_imu);

/* ---------------------------------------------------------------- GNSS receiver */

#define N_TERM(b) .bit = (b), .bits_offset = OFF(gnss.model.terms)
#define NM(m) gnss.model.m

static const nav_io_field k_reported[] = {
    Q("position_m", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_REQUIRED, NM(reported_pos_sd_m), 1.0,
      .max = NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, .bit = 0,
      .doc = "position sigma each fix reports, N, E, D"),
    Q("velocity_mps", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_REQUIRED, NM(reported_vel_sd_mps), 1.0,
      .max = NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS, .bit = 0,
      .doc = "velocity sigma each fix reports, N, E, D"),
};
DEFINE_SECTION(k_reported_section, k_reported);

static const nav_io_field k_gnss[] = {
    {.key = "enabled",
     .doc = "simulate a GNSS receiver (and aid the navigation with its fixes)",
     .kind = NAV_IO_BOOL,
     .offset = OFF(gnss.enabled)},
    {.key = "catalog",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_EARLY,
     .offset = OFF(gnss.catalog),
     .size = NAV_SCENE_CATALOG_NAME_MAX,
     .read = read_catalog,
     .write = write_catalog,
     .same = same_string,
     .write_if = catalog_given,
     .comment = "resources/gnss_receivers.csv; the keys below override it",
     .schema = schema_catalog},
    {.key = "update_rate_hz",
     .doc = "fix rate",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GT | NAV_IO_MAX_LE,
     .offset = OFF(NM(update_rate_hz)),
     .scale = 1.0,
     .max = NAV_SCENE_MAX_GNSS_RATE_HZ},
    Q("latency_s", NAV_IO_DOUBLE, NONNEG_LE, NM(latency_s), 1.0, .max = NAV_SCENE_MAX_GNSS_LATENCY_S,
      .bit = 0, .doc = "output latency of a fix"),
    Q("position_sigma_m", NAV_IO_VEC3S, NONNEG_LE, NM(pos_gm_sd_m), 1.0,
      .max = NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, N_TERM(NAV_GNSS_TERM_POS_GM), .mark_as = "pos_gm_sd_m",
      .comment = "N, E, D; Gauss-Markov", .doc = "position error: Gauss-Markov 1-sigma, N, E, D"),
    Q("position_corr_time_s", NAV_IO_VEC3S, NONNEG, NM(pos_gm_tau_s), 1.0, N_TERM(NAV_GNSS_TERM_POS_GM),
      .mark_as = "pos_gm_tau_s", .comment = "0: white",
      .doc = "correlation time of the position error, N, E, D (0: white)"),
    Q("position_white_sigma_m", NAV_IO_VEC3S, NONNEG_LE, NM(pos_white_sd_m), 1.0,
      .max = NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M, N_TERM(NAV_GNSS_TERM_POS_WHITE),
      .mark_as = "pos_white_sd_m", .doc = "position error: white 1-sigma per fix, N, E, D"),
    Q("velocity_sigma_mps", NAV_IO_VEC3S, NONNEG_LE, NM(vel_sd_mps), 1.0,
      .max = NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS, N_TERM(NAV_GNSS_TERM_VEL_WHITE), .mark_as = "vel_sd_mps",
      .doc = "velocity error: white 1-sigma per fix, N, E, D"),
    Q("lever_arm_b_m", NAV_IO_VEC3, SIGNED_LE, NM(r_ba_b_m), 1.0, PM(NAV_SCENE_MAX_LEVER_ARM_M),
      .mark_as = "r_ba_b_m", .comment = "antenna relative to the IMU, body axes",
      .doc = "antenna position relative to the IMU, body axes"),
    {.key = "outages",
     .doc = "intervals [t0_s, t1_s) without fixes",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(gnss.model),
     .read = read_outages,
     .write = write_outages,
     .same = same_outages,
     .comment = "[t0_s, t1_s): no fix",
     .unit = "s",
     .max_items = NAV_GNSS_MAX_OUTAGES,
     .schema = schema_outages},
    {.key = "reported_sigma",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(gnss.model),
     .section = &k_reported_section,
     .read = read_reported,
     .write = write_reported,
     .same = same_reported,
     .doc = "sigmas the receiver reports with each fix: model (the error model's) or given values",
     .schema = schema_reported},
    {.key = "off",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_LATE,
     .offset = OFF(gnss.model),
     .read = read_off,
     .write = write_off,
     .same = same_terms,
     .write_if = off_needed,
     .comment = "terms switched off",
     .schema = schema_off},
    {.key = "file",
     .doc = "recorded GNSS fixes (KF-GINS GNSS text, 7 or 13 columns) used instead of the receiver model",
     .kind = NAV_IO_STRING,
     .offset = OFF(gnss.file),
     .size = NAV_RECORDED_PATH_MAX,
     .write_if = catalog_given, /* written only when given, like the catalog names */
     .comment = "recorded fixes (KF-GINS GNSS text) instead of the receiver model; docs/gnss-file.md"},
    {.key = "constellation",
     .kind = NAV_IO_SECTION,
     .section = &nav_io_gnss_constellation_section,
     .write_if = nav_io_gnss_constellation_written,
     .comment = "satellites along the trajectory: visibility and DOP (docs/gnss-constellations.md)"},
};
DEFINE_SECTION(k_gnss_section, k_gnss);

/* ---------------------------------------------------------------- accelerometer array (gyro-free INS) */

/*
 * array: {layout, radius_m, sensors (custom), accel: {...}, initial_rate_sd_dps}. The accel
 * figures apply to every sensor (each draws its own realisation); a term is on when one of its
 * keys is given, as for the IMU, and "off" lists terms that are off although they have values.
 */
#define R_TERM(b) .bit = (b), .bits_offset = OFF(array.accel.terms)
#define RM(m) array.accel.m

static const nav_io_field k_array_accel[] = {
    Q("bias_turn_on_mg", NAV_IO_DOUBLE, NONNEG_LE, RM(bias_turn_on_sd_mps2), K_MG, .max = B_ABIAS(K_MG),
      R_TERM(NAV_IMU_TERM_BIAS_TURN_ON), .mark_as = "bias_turn_on_sd_mps2",
      .comment = "1-sigma, drawn per sensor and run"),
    Q("bias_turn_on_mps2", NAV_IO_DOUBLE, NONNEG_LE | NAV_IO_ALT, RM(bias_turn_on_sd_mps2), 1.0,
      .max = B_ABIAS(1.0), R_TERM(NAV_IMU_TERM_BIAS_TURN_ON)),
    Q("bias_gm_sigma_ug", NAV_IO_DOUBLE, NONNEG_LE, RM(bias_gm_sd_mps2), K_UG, .max = B_ABIAS(K_UG),
      R_TERM(NAV_IMU_TERM_BIAS_GM), .mark_as = "bias_gm_sd_mps2",
      .doc = "Gauss-Markov bias of each accelerometer, 1-sigma"),
    Q("bias_gm_sigma_mps2", NAV_IO_DOUBLE, NONNEG_LE | NAV_IO_ALT, RM(bias_gm_sd_mps2), 1.0,
      .max = B_ABIAS(1.0), R_TERM(NAV_IMU_TERM_BIAS_GM)),
    Q("bias_gm_tau_s", NAV_IO_DOUBLE, POSITIVE, RM(bias_gm_tau_s), 1.0, R_TERM(NAV_IMU_TERM_BIAS_GM),
      .doc = "correlation time of the Gauss-Markov bias"),
    Q("vrw_m_per_s_per_sqrt_h", NAV_IO_DOUBLE, NONNEG_LE, RM(vrw_mps_per_sqrt_s), K_PER_SQRT_H,
      .max = B_VRW(K_PER_SQRT_H), R_TERM(NAV_IMU_TERM_NOISE), .mark_as = "vrw_mps_per_sqrt_s",
      .doc = "velocity random walk of each accelerometer"),
    Q("vrw_mps_per_sqrt_s", NAV_IO_DOUBLE, NONNEG_LE | NAV_IO_ALT, RM(vrw_mps_per_sqrt_s), 1.0,
      .max = B_VRW(1.0), R_TERM(NAV_IMU_TERM_NOISE)),
    Q("noise_density_ug_per_sqrt_hz", NAV_IO_DOUBLE, NONNEG_LE | NAV_IO_ALT, RM(vrw_mps_per_sqrt_s), K_UG,
      .max = B_VRW(K_UG), R_TERM(NAV_IMU_TERM_NOISE)),
    Q("scale_factor_ppm", NAV_IO_DOUBLE, NONNEG_LE, RM(scale_factor_sd), K_PPM, .max = B_SF(K_PPM),
      R_TERM(NAV_IMU_TERM_SCALE_FACTOR), .mark_as = "scale_factor_sd",
      .doc = "scale-factor error of each accelerometer, 1-sigma"),
    Q("scale_factor_sd", NAV_IO_DOUBLE, NONNEG_LE | NAV_IO_ALT, RM(scale_factor_sd), 1.0, .max = B_SF(1.0),
      R_TERM(NAV_IMU_TERM_SCALE_FACTOR), .unit = "1"),
    {.key = "off",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_LATE,
     .offset = OFF(array.accel),
     .read = read_off,
     .write = write_off,
     .same = same_terms,
     .write_if = off_needed,
     .comment = "terms switched off",
     .schema = schema_off},
};
DEFINE_SECTION(k_array_accel_section, k_array_accel);

/* One sensor of a custom layout (base: nav_scene_array_sensor): its position from the array
   centre and its sensitive axis (any non-zero length), body axes. */
static const nav_io_field k_array_sensor[] = {
    {.key = "position_m",
     .doc = "position of the accelerometer from the array centre, body axes",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE | NAV_IO_REQUIRED,
     .offset = offsetof(nav_scene_array_sensor, r_bs_b_m),
     .scale = 1.0,
     .mark_as = "r_bs_b_m"},
    {.key = "axis",
     .doc = "sensitive axis, body axes (any non-zero length)",
     .kind = NAV_IO_VEC3,
     .flags = NAV_IO_FINITE | NAV_IO_REQUIRED,
     .offset = offsetof(nav_scene_array_sensor, n_s_b),
     .scale = 1.0,
     .mark_as = "n_s_b",
     .unit = "1"},
};
DEFINE_SECTION(k_array_sensor_section, k_array_sensor);

static const nav_io_field k_array[] = {
    {.key = "catalog",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_EARLY,
     .offset = OFF(array.catalog),
     .size = NAV_SCENE_CATALOG_NAME_MAX,
     .read = read_catalog,
     .write = write_catalog,
     .same = same_string,
     .write_if = catalog_given,
     .comment = "accelerometer part of resources/accel_catalog.csv; the accel keys below override it",
     .doc = "accelerometer part of the array from the catalog (navsim catalog --accel); typed accel keys override it",
     .schema = schema_catalog},
    {.key = "layout",
     .doc = "placement of the accelerometers: cube6, nine, twelve or custom (sensors)",
     .kind = NAV_IO_ENUM,
     .offset = OFF(array.layout),
     .enums = k_array_layouts,
     .comment = "cube6 | nine | twelve | custom (sensors below)"},
    {.key = "radius_m",
     .kind = NAV_IO_DOUBLE,
     .flags = POSITIVE | NAV_IO_MAX_LE,
     .offset = OFF(array.radius_m),
     .scale = 1.0,
     .max = 100.0,
     .comment = "arm r of cube6, nine and twelve"},
    {.key = "sensors",
     .kind = NAV_IO_CUSTOM,
     .offset = OFF(array),
     .read = read_array_sensors,
     .write = write_array_sensors,
     .same = same_array_sensors,
     .write_if = array_sensors_written,
     .doc = "accelerometers of a custom layout: position and sensitive axis of each",
     .items = &k_array_sensor_section,
     .max_items = NAV_SCENE_ARRAY_MAX_SENSORS},
    {.key = "accel",
     .doc = "error model of every accelerometer of the array (each draws its own errors)",
     .kind = NAV_IO_SECTION,
     .section = &k_array_accel_section},
    Q("initial_rate_sd_dps", NAV_IO_VEC3S, NONNEG_LE, array.initial_rate_sd_rps, NAV_DEG2RAD,
      .max = NAV_SCENE_MAX_INITIAL_RATE_SD_DPS, .mark_as = "initial_rate_sd_rps",
      .comment = "1-sigma error of the initial angular rate, body x, y, z"),
    Q("initial_rate_sd_rps", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, array.initial_rate_sd_rps, 1.0,
      .max = NAV_SCENE_MAX_INITIAL_RATE_SD_DPS * NAV_DEG2RAD, .bit = 0),
};
DEFINE_SECTION(k_array_section, k_array);

/* ---------------------------------------------------------------- the rest */

/* Plausibility bounds (scene_bounds.h): the table bounds every component by the largest (the
   heading's); finish_initial_errors bounds the tilt about north and east. */
static void finish_initial_errors(nav_io_reader *r, const nav_io_node *map, void *base);
/* Per-axis maxima of the attitude sigmas (about N, E, D): the tilt bound for N and E, the heading
   bound for D (finish_initial_errors enforces the tilt; .max the heading). */
static const double k_att_sd_max_deg[3] = {NAV_SCENE_MAX_INITIAL_TILT_SD_DEG,
                                           NAV_SCENE_MAX_INITIAL_TILT_SD_DEG,
                                           NAV_SCENE_MAX_INITIAL_HEADING_SD_DEG};
static const double k_att_sd_max_rad[3] = {NAV_SCENE_MAX_INITIAL_TILT_SD_DEG * NAV_DEG2RAD,
                                           NAV_SCENE_MAX_INITIAL_TILT_SD_DEG *NAV_DEG2RAD,
                                           NAV_SCENE_MAX_INITIAL_HEADING_SD_DEG *NAV_DEG2RAD};
static const nav_io_field k_initial_errors[] = {
    Q("position_m", NAV_IO_VEC3S, NONNEG_LE, initial_errors.pos_sd_m, 1.0,
      .max = NAV_SCENE_MAX_INITIAL_POSITION_SD_M, .comment = "1-sigma N, E, D",
      .doc = "initial position error, 1-sigma N, E, D"),
    Q("velocity_mps", NAV_IO_VEC3S, NONNEG_LE, initial_errors.vel_sd_mps, 1.0,
      .max = NAV_SCENE_MAX_INITIAL_VELOCITY_SD_MPS, .comment = "1-sigma N, E, D",
      .doc = "initial velocity error, 1-sigma N, E, D"),
    Q("attitude_deg", NAV_IO_VEC3S, NONNEG_LE, initial_errors.att_sd_rad, NAV_DEG2RAD,
      .max = NAV_SCENE_MAX_INITIAL_HEADING_SD_DEG, .max_axis = k_att_sd_max_deg,
      .comment = "1-sigma about N, E, D",
      .doc = "initial attitude error, 1-sigma about N, E, D (tilt at most 90 deg, heading 180 deg)"),
    Q("attitude_rad", NAV_IO_VEC3S, NONNEG_LE | NAV_IO_ALT, initial_errors.att_sd_rad, 1.0,
      .max = NAV_SCENE_MAX_INITIAL_HEADING_SD_DEG * NAV_DEG2RAD, .max_axis = k_att_sd_max_rad, .bit = 0),
};
DEFINE_SECTION_FINISH(k_initial_errors_section, k_initial_errors, finish_initial_errors);

static const nav_io_field k_navigation[] = {
    {.key = "scheme",
     .doc = "navigation scheme: free INS, INS/GNSS, gyro-free INS, gyro-free INS with GNSS",
     .kind = NAV_IO_ENUM,
     .offset = OFF(navigation.scheme),
     .enums = k_schemes},
    {.key = "algorithm",
     .doc = "strapdown integration: first_order, or high_order (coning and sculling corrections)",
     .kind = NAV_IO_ENUM,
     .offset = OFF(navigation.algorithm),
     .enums = k_mech_algorithms},
    {.key = "frame",
     .kind = NAV_IO_ENUM,
     .offset = OFF(navigation.frame),
     .enums = k_mech_frames,
     .comment = "wgs84 only: ned (local level) or ecef (works over the poles)"},
    {.key = "aid_vertical",
     .kind = NAV_IO_BOOL,
     .offset = OFF(navigation.aid_vertical),
     .comment = "free INS: height and vertical velocity from the reference"},
    {.key = "cov_decimation",
     .kind = NAV_IO_INT,
     .flags = NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(navigation.cov_decimation),
     .min = 0.0,
     .max = 1000.0,
     .comment = "ins_gnss: filter covariance propagated once every N IMU steps (0 or 1: every step)"},
    {.key = "estimate_scale_factors",
     .kind = NAV_IO_BOOL,
     .offset = OFF(navigation.estimate_scale_factors),
     .comment = "ins_gnss: 21-state filter with gyro and accelerometer scale-factor states"},
    {.key = "scale_factor_gm_tau_s",
     .kind = NAV_IO_DOUBLE,
     .flags = NAV_IO_FINITE | NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(navigation.scale_factor_gm_tau_s),
     .scale = 1.0,
     .min = 0.0,
     .max = 1e7,
     .comment = "ins_gnss: scale-factor states as Gauss-Markov with this time [s] (0: random constants)"},
    {.key = "smoother",
     .kind = NAV_IO_BOOL,
     .offset = OFF(navigation.smoother),
     .comment = "ins_gnss: RTS smoother per run (nav_smoothed.csv, smoothed_errors.csv, stats_smoothed)"},
};
DEFINE_SECTION(k_navigation_section, k_navigation);

static const nav_io_field k_output[] = {
    RATE_HZ(output.rate_hz, "rate of the written navigation results and errors")};
DEFINE_SECTION(k_output_section, k_output);

static const nav_io_field k_simulation[] = {
    {.key = "seed",
     .doc = "seed of the random streams: the same seed gives the same results",
     .kind = NAV_IO_U64,
     .offset = OFF(simulation.seed)},
    {.key = "runs",
     .doc = "Monte Carlo runs",
     .kind = NAV_IO_LONG,
     .flags = NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(simulation.runs),
     .min = 1.0,
     .max = (double)NAV_SCENE_MAX_RUNS},
    {.key = "threads",
     .doc = "worker threads (0: one per core); results do not depend on it",
     .kind = NAV_IO_INT,
     .flags = NAV_IO_MIN_GE | NAV_IO_MAX_LE,
     .offset = OFF(simulation.threads),
     .min = 0.0,
     .max = 256.0,
     .comment = "0: one per core; results do not depend on it"},
};
DEFINE_SECTION(k_simulation_section, k_simulation);

/* ---------------------------------------------------------------- requirements (nav_requirements.h) */

/* requirements: a list of {id, metric, statistic, limit, unit, time_s (at_time only)}; the
   cross-field rules (unit vs metric, cep, ids) are nav_requirements_validate's. */
static void read_requirements(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                              const nav_io_node *value, void *base);
static nav_status write_requirements(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
static bool same_requirements(const nav_io_field *f, const void *a, const void *b);
static bool requirements_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                 const void *def);
static bool req_time_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def);

static const nav_io_enum_value k_req_metrics[] = {{"horizontal_position", NAV_REQ_HORIZONTAL_POSITION},
                                                  {"vertical_position", NAV_REQ_VERTICAL_POSITION},
                                                  {"position_3d", NAV_REQ_POSITION_3D},
                                                  {"velocity", NAV_REQ_VELOCITY},
                                                  {"roll_pitch", NAV_REQ_ROLL_PITCH},
                                                  {"yaw", NAV_REQ_YAW},
                                                  {NULL, 0}};
static const nav_io_enum_value k_req_statistics[] = {
    {"rms", NAV_REQ_RMS},       {"max", NAV_REQ_MAX},     {"p95", NAV_REQ_P95},     {"at_time", NAV_REQ_AT_TIME},
    {"outage_end", NAV_REQ_OUTAGE_END}, {"cep50", NAV_REQ_CEP50}, {"cep95", NAV_REQ_CEP95}, {NULL, 0}};
static const nav_io_enum_value k_req_units[] = {
    {"m", NAV_REQ_UNIT_M},         {"cm", NAV_REQ_UNIT_CM},         {"km", NAV_REQ_UNIT_KM},
    {"m/s", NAV_REQ_UNIT_MPS},     {"cm/s", NAV_REQ_UNIT_CMPS},     {"deg", NAV_REQ_UNIT_DEG},
    {"arcmin", NAV_REQ_UNIT_ARCMIN}, {"arcsec", NAV_REQ_UNIT_ARCSEC}, {"mrad", NAV_REQ_UNIT_MRAD},
    {"rad", NAV_REQ_UNIT_RAD},     {NULL, 0}};

#define RQ(member) offsetof(nav_requirement, member)
static const nav_io_field k_requirement[] = {
    {.key = "id",
     .doc = "name of the requirement (unique)",
     .kind = NAV_IO_STRING,
     .flags = NAV_IO_REQUIRED,
     .offset = RQ(id),
     .size = NAV_REQ_ID_MAX},
    {.key = "metric",
     .doc = "the error it limits",
     .kind = NAV_IO_ENUM,
     .flags = NAV_IO_REQUIRED,
     .offset = RQ(metric),
     .enums = k_req_metrics},
    {.key = "statistic",
     .doc = "statistic of that error over the runs and the time",
     .kind = NAV_IO_ENUM,
     .flags = NAV_IO_REQUIRED,
     .offset = RQ(statistic),
     .enums = k_req_statistics},
    {.key = "limit",
     .doc = "largest allowed value, in unit",
     .kind = NAV_IO_DOUBLE,
     .flags = POSITIVE | NAV_IO_REQUIRED,
     .offset = RQ(limit),
     .scale = 1.0,
     .mark_as = "limit"},
    {.key = "unit",
     .doc = "unit of limit",
     .kind = NAV_IO_ENUM,
     .flags = NAV_IO_REQUIRED,
     .offset = RQ(unit),
     .enums = k_req_units},
    {.key = "time_s",
     .doc = "time at which at_time is evaluated",
     .kind = NAV_IO_DOUBLE,
     .flags = NONNEG,
     .offset = RQ(time_s),
     .scale = 1.0,
     .write_if = req_time_written},
};
#undef RQ
DEFINE_SECTION(k_requirement_section, k_requirement);

static const nav_io_field k_root[] = {
    {.key = "format_version",
     .kind = NAV_IO_CUSTOM,
     .flags = NAV_IO_REQUIRED,
     .read = read_format_version,
     .write = write_format_version,
     .doc = "version of the scene format the file is written in",
     .schema = schema_format_version},
    {.key = "name",
     .doc = "name of the scene (results and reports are named after it)",
     .kind = NAV_IO_STRING,
     .offset = OFF(name),
     .size = NAV_SCENE_NAME_MAX},
    {.key = "earth",
     .doc = "Earth model and scene origin",
     .kind = NAV_IO_SECTION,
     .section = &k_earth_section},
    {.key = "trajectory",
     .doc = "the reference trajectory (truth)",
     .kind = NAV_IO_SECTION,
     .section = &nav_io_trajectory_section},
    {.key = "imu",
     .doc = "the inertial measurement unit: rate and error model",
     .kind = NAV_IO_SECTION,
     .section = &k_imu_section},
    {.key = "gnss",
     .doc = "the GNSS receiver: rate, errors, lever arm, outages",
     .kind = NAV_IO_SECTION,
     .section = &k_gnss_section,
     .write_if = gnss_written},
    {.key = "array",
     .doc = "accelerometer array of the gyro-free INS",
     .kind = NAV_IO_SECTION,
     .section = &k_array_section,
     .write_if = array_written},
    {.key = "initial_errors",
     .doc = "errors of the navigation's initial state",
     .kind = NAV_IO_SECTION,
     .section = &k_initial_errors_section},
    {.key = "navigation",
     .doc = "navigation scheme and its settings",
     .kind = NAV_IO_SECTION,
     .section = &k_navigation_section},
    {.key = "output", .doc = "rate of the results", .kind = NAV_IO_SECTION, .section = &k_output_section},
    {.key = "simulation",
     .doc = "Monte Carlo runs, seed and threads",
     .kind = NAV_IO_SECTION,
     .section = &k_simulation_section},
    {.key = "requirements",
     .kind = NAV_IO_CUSTOM,
     .read = read_requirements,
     .write = write_requirements,
     .same = same_requirements,
     .write_if = requirements_written,
     .doc = "accuracy requirements the results are judged against",
     .items = &k_requirement_section,
     .max_items = NAV_SCENE_MAX_REQUIREMENTS},
};
_Static_assert(COUNT(k_root) <= MAX_SECTION_FIELDS, "k_root: too many fields");
const nav_io_section nav_io_scene_schema = {k_root, COUNT(k_root), NULL};

/* ================================================================ shared helpers */

void nav_io_c_locale_begin(nav_io_c_locale *s) {
  s->c_loc = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
  s->old_loc = (locale_t)0;
  if (s->c_loc != (locale_t)0) s->old_loc = uselocale(s->c_loc);
}

void nav_io_c_locale_end(nav_io_c_locale *s) {
  if (s->c_loc == (locale_t)0) return;
  uselocale(s->old_loc);
  freelocale(s->c_loc);
  s->c_loc = (locale_t)0;
}

static bool same_bits(double a, double b) {
  return memcmp(&a, &b, sizeof a) == 0;
}

char *nav_io_format_double(char *buf, size_t size, double v) {
  if (isnan(v)) {
    snprintf(buf, size, ".nan");
  } else if (isinf(v)) {
    snprintf(buf, size, "%s", v > 0 ? ".inf" : "-.inf");
  } else {
    /* 17 significant digits always round-trip; fewer are tried first so that values typed by a
       person (0.1, 9.80665) are written back as typed. */
    for (int prec = 15; prec <= 17; ++prec) {
      snprintf(buf, size, "%.*g", prec, v);
      if (same_bits(strtod(buf, NULL), v)) break;
    }
  }
  return buf;
}

/* ================================================================ the YAML tree */

typedef enum ykind { Y_SCALAR, Y_SEQ, Y_MAP, Y_ALIAS } ykind;

struct nav_io_node {
  nav_io_node *next;  /* next sibling; in a mapping, children alternate key, value */
  nav_io_node *child; /* first child */
  nav_io_node *last;  /* last child (used while building) */
  const char *text;   /* scalar value or alias name, NUL-terminated (may contain NULs) */
  size_t len;
  size_t count;  /* children */
  int line, col; /* 1-based; 0 when libfyaml gives no position (an empty value) */
  ykind kind;
  bool quoted; /* any scalar style but plain: always a string */
  bool tagged; /* has an explicit tag (!!str, !foo) */
};

typedef struct arena_block {
  struct arena_block *next;
  size_t used, cap;
  max_align_t data[];
} arena_block;

typedef struct mark_entry {
  char path[PATH_MAX_LEN];
  int line, col;
} mark_entry;

struct nav_io_reader {
  const char *file;
  nav_diag_fn report;
  void *user;
  int ndiag;
  bool stop;         /* too many diagnostics, or nothing more can be read */
  bool oom;          /* an allocation failed */
  bool newer_format; /* format_version is newer than this reader: the rest is not read */
  char path[PATH_MAX_LEN];
  size_t path_len;
  arena_block *blocks;
  size_t nnodes;
  mark_entry *marks;
  size_t nmarks, cap_marks;
  char err_paths[NAV_DIAG_MAX_PER_FILE][PATH_MAX_LEN]; /* paths with a reader error */
  int nerr_paths;
  nav_io_read_state state; /* inputs without a place in the scene (scene_io_internal.h) */
};

#define ARENA_BLOCK_BYTES ((size_t)64 * 1024)

static void *arena_alloc(nav_io_reader *r, size_t n) {
  const size_t a = alignof(max_align_t);
  n = (n + a - 1) / a * a; /* n <= NAV_IO_MAX_INPUT_BYTES + 1: no overflow */
  arena_block *b = r->blocks;
  if (b == NULL || b->cap - b->used < n) {
    const size_t cap = n > ARENA_BLOCK_BYTES ? n : ARENA_BLOCK_BYTES;
    b = malloc(sizeof *b + cap);
    if (b == NULL) {
      r->oom = true;
      r->stop = true;
      return NULL;
    }
    b->next = r->blocks;
    b->used = 0;
    b->cap = cap;
    r->blocks = b;
  }
  void *p = (char *)b->data + b->used;
  b->used += n;
  return p;
}

static void arena_free(nav_io_reader *r) {
  arena_block *b = r->blocks;
  while (b != NULL) {
    arena_block *next = b->next;
    free(b);
    b = next;
  }
  r->blocks = NULL;
}

/* ================================================================ diagnostics */

static void emit(nav_io_reader *r, int line, int col, const char *path, const char *message) {
  if (r->ndiag >= NAV_DIAG_MAX_PER_FILE) {
    r->stop = true;
    return;
  }
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", r->file);
  d.line = line > 0 ? line : 0;
  d.col = line > 0 && col > 0 ? col : 0;
  if (r->ndiag == NAV_DIAG_MAX_PER_FILE - 1) {
    /* The last slot says that the list is cut, so the count never looks complete when it is not. */
    d.line = 0;
    d.col = 0;
    snprintf(d.message, sizeof d.message, "too many problems; stopping after the first %d",
             NAV_DIAG_MAX_PER_FILE - 1);
    r->stop = true;
  } else {
    snprintf(d.path, sizeof d.path, "%s", path);
    snprintf(d.message, sizeof d.message, "%s", message);
  }
  r->ndiag++;
  if (r->report != NULL) r->report(r->user, &d);
}

static void emitf(nav_io_reader *r, int line, int col, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 5, 6)))
#endif
    ;
static void emitf(nav_io_reader *r, int line, int col, const char *path, const char *fmt, ...) {
  char msg[sizeof(((nav_diag *)0)->message)];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  emit(r, line, col, path, msg);
}

void nav_io_reader_error(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback,
                         const char *fmt, ...) {
  char msg[sizeof(((nav_diag *)0)->message)];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  const nav_io_node *at = node != NULL && node->line > 0 ? node : fallback;
  if (r->nerr_paths < NAV_DIAG_MAX_PER_FILE)
    snprintf(r->err_paths[r->nerr_paths++], PATH_MAX_LEN, "%s", r->path);
  emit(r, at != NULL ? at->line : 0, at != NULL ? at->col : 0, r->path, msg);
}

static bool find_mark(const nav_io_reader *r, const char *path, int *line, int *col);

void nav_io_reader_error_at_path(nav_io_reader *r, const char *path, const char *fmt, ...) {
  char msg[sizeof(((nav_diag *)0)->message)];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, sizeof msg, fmt, ap);
  va_end(ap);
  int line = 0, col = 0;
  find_mark(r, path, &line, &col);
  if (r->nerr_paths < NAV_DIAG_MAX_PER_FILE)
    snprintf(r->err_paths[r->nerr_paths++], PATH_MAX_LEN, "%s", path);
  emit(r, line, col, path, msg);
}

void nav_io_reader_forward(nav_io_reader *r, const nav_diag *d) {
  if (r->ndiag >= NAV_DIAG_MAX_PER_FILE) {
    r->stop = true;
    return;
  }
  if (r->ndiag == NAV_DIAG_MAX_PER_FILE - 1) {
    emit(r, 0, 0, "", ""); /* the "too many problems" entry */
    return;
  }
  r->ndiag++;
  if (r->report != NULL) r->report(r->user, d);
}

int nav_io_reader_count(const nav_io_reader *r) {
  return r->ndiag;
}

nav_io_read_state *nav_io_reader_state(nav_io_reader *r) {
  return &r->state;
}

void nav_diag_format(const nav_diag *d, char *buf, size_t size) {
  if (buf == NULL || size == 0) return;
  if (d == NULL) {
    buf[0] = '\0';
    return;
  }
  /* "FILE:LINE:COL: error: PATH: MESSAGE"; the location is dropped when line is 0 and the path
     when it is empty, so no field is ever printed as a placeholder. */
  if (d->line > 0 && d->path[0] != '\0')
    snprintf(buf, size, "%s:%d:%d: error: %s: %s", d->file, d->line, d->col, d->path, d->message);
  else if (d->line > 0)
    snprintf(buf, size, "%s:%d:%d: error: %s", d->file, d->line, d->col, d->message);
  else if (d->path[0] != '\0')
    snprintf(buf, size, "%s: error: %s: %s", d->file, d->path, d->message);
  else
    snprintf(buf, size, "%s: error: %s", d->file, d->message);
}

/* Copy user text for a message: control bytes become '?', long text is cut (at a UTF-8
   boundary) and ends with "...". */
static void show(char *dst, size_t size, const char *src, size_t len) {
  size_t n = len;
  bool cut = false;
  if (n > SHOW_MAX) {
    n = SHOW_MAX;
    while (n > 0 && ((unsigned char)src[n] & 0xC0) == 0x80)
      --n;
    cut = true;
  }
  if (n + 4 > size) n = size > 4 ? size - 4 : 0;
  size_t j = 0;
  for (size_t i = 0; i < n; ++i) {
    const unsigned char c = (unsigned char)src[i];
    dst[j++] = (c < 0x20 || c == 0x7f) ? '?' : (char)c;
  }
  if (cut) {
    memcpy(dst + j, "...", 3);
    j += 3;
  }
  dst[j] = '\0';
}

/* ================================================================ field paths and marks */

static size_t path_push_key(nav_io_reader *r, const char *key, size_t len) {
  const size_t saved = r->path_len;
  char shown[SHOW_MAX + 4];
  show(shown, sizeof shown, key, len);
  const int n =
      snprintf(r->path + r->path_len, PATH_MAX_LEN - r->path_len, "%s%s", r->path_len ? "." : "", shown);
  if (n > 0) r->path_len += (size_t)n;
  if (r->path_len >= PATH_MAX_LEN) r->path_len = PATH_MAX_LEN - 1;
  return saved;
}

static size_t path_push_index(nav_io_reader *r, size_t i) {
  const size_t saved = r->path_len;
  const int n = snprintf(r->path + r->path_len, PATH_MAX_LEN - r->path_len, "[%zu]", i);
  if (n > 0) r->path_len += (size_t)n;
  if (r->path_len >= PATH_MAX_LEN) r->path_len = PATH_MAX_LEN - 1;
  return saved;
}

static void path_pop(nav_io_reader *r, size_t saved) {
  r->path_len = saved;
  r->path[saved] = '\0';
}

size_t nav_io_path_push_key(nav_io_reader *r, const char *key) {
  return path_push_key(r, key, strlen(key));
}

size_t nav_io_path_push_index(nav_io_reader *r, size_t i) {
  return path_push_index(r, i);
}

void nav_io_path_pop(nav_io_reader *r, size_t saved) {
  path_pop(r, saved);
}

/* Remember where the current path is in the file, for nav_scene_validate's messages. */
static void mark_path(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback) {
  const nav_io_node *at = node != NULL && node->line > 0 ? node : fallback;
  if (at == NULL || at->line <= 0) return;
  if (r->nmarks == r->cap_marks) {
    const size_t cap = r->cap_marks ? 2 * r->cap_marks : 64;
    /* Schema fields only: a few per waypoint or segment, so a full-size script fits; marks only
       refine locations, and beyond the cap a message falls back to the nearest marked parent. */
    if (cap > 65536) return;
    mark_entry *m = realloc(r->marks, cap * sizeof *m);
    if (m == NULL) return; /* marks only refine locations; reading goes on without them */
    r->marks = m;
    r->cap_marks = cap;
  }
  mark_entry *e = &r->marks[r->nmarks++];
  snprintf(e->path, sizeof e->path, "%s", r->path);
  e->line = at->line;
  e->col = at->col;
}

void nav_io_mark(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback) {
  mark_path(r, node, fallback);
}

/* The mark of @p path, else of its nearest parent ("a.b[2]" -> "a.b" -> "a"); false if none. */
static bool find_mark(const nav_io_reader *r, const char *path, int *line, int *col) {
  char buf[PATH_MAX_LEN];
  snprintf(buf, sizeof buf, "%s", path);
  while (buf[0] != '\0') {
    for (size_t i = 0; i < r->nmarks; ++i)
      if (strcmp(r->marks[i].path, buf) == 0) {
        *line = r->marks[i].line;
        *col = r->marks[i].col;
        return true;
      }
    char *dot = strrchr(buf, '.');
    char *bracket = strrchr(buf, '[');
    char *cut = dot > bracket ? dot : bracket;
    if (cut == NULL) break;
    *cut = '\0';
  }
  return false;
}

/* True if @p a and @p b are the same path or one contains the other ("x.y" and "x.y[1]"). */
static bool path_related(const char *a, const char *b) {
  const size_t la = strlen(a), lb = strlen(b);
  const size_t n = la < lb ? la : lb;
  if (strncmp(a, b, n) != 0) return false;
  if (la == lb) return true;
  const char next = la < lb ? b[n] : a[n];
  return next == '.' || next == '[';
}

/* ================================================================ raw text checks */

/* Reject what is not UTF-8 text before libfyaml sees it; report the first offending byte. */
static bool check_text(nav_io_reader *r, const unsigned char *s, size_t n) {
  size_t i = 0;
  int line = 1, col = 1;
  if (n >= 3 && s[0] == 0xEF && s[1] == 0xBB && s[2] == 0xBF) i = 3; /* UTF-8 byte order mark */
  while (i < n) {
    const unsigned c = s[i];
    if (c == '\n') {
      ++line;
      col = 1;
      ++i;
      continue;
    }
    if (c < 0x80) {
      if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
        emitf(r, line, col, "",
              "the file contains binary data (control byte 0x%02x); a scene file must be UTF-8 text", c);
        return false;
      }
      ++i;
      ++col;
      continue;
    }
    /* Multi-byte sequence: length from the lead byte, then continuation bytes; overlong forms,
       UTF-16 surrogates and code points above U+10FFFF are invalid (RFC 3629). */
    size_t len = 0;
    uint32_t cp = 0, min = 0;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2;
      cp = c & 0x1F;
      min = 0x80;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3;
      cp = c & 0x0F;
      min = 0x800;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4;
      cp = c & 0x07;
      min = 0x10000;
    }
    bool ok = len != 0 && i + len <= n;
    for (size_t k = 1; ok && k < len; ++k) {
      if ((s[i + k] & 0xC0) != 0x80)
        ok = false;
      else
        cp = (cp << 6) | (s[i + k] & 0x3F);
    }
    if (ok && (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))) ok = false;
    if (!ok) {
      emitf(r, line, col, "", "the file is not valid UTF-8 (byte 0x%02x); a scene file must be UTF-8 text",
            c);
      return false;
    }
    i += len;
    ++col;
  }
  return true;
}

/* ================================================================ building the tree */

/* libfyaml's diagnostics are collected (fy_diag_set_collect_errors) and reported by us; anything
   it would still print goes here and is dropped, so the library never writes to stderr. */
static void fy_output_sink(struct fy_diag *diag, void *user, const char *buf, size_t len) {
  (void)diag;
  (void)user;
  (void)buf;
  (void)len;
}

static nav_io_node *new_node(nav_io_reader *r, ykind kind, const struct fy_mark *m) {
  if (r->nnodes >= NAV_IO_MAX_NODES) {
    emitf(r, m != NULL && m->line >= 0 ? m->line + 1 : 0, m != NULL ? m->column + 1 : 0, "",
          "the file has more than %d YAML nodes; this is not a scene file", NAV_IO_MAX_NODES);
    r->stop = true;
    return NULL;
  }
  nav_io_node *n = arena_alloc(r, sizeof *n);
  if (n == NULL) return NULL;
  memset(n, 0, sizeof *n);
  n->kind = kind;
  if (m != NULL && m->line >= 0 && m->column >= 0) {
    n->line = m->line + 1;
    n->col = m->column + 1;
  }
  r->nnodes++;
  return n;
}

static bool set_text(nav_io_reader *r, nav_io_node *n, struct fy_token *tok) {
  size_t len = 0;
  const char *t = tok != NULL ? fy_token_get_text(tok, &len) : NULL;
  if (t == NULL) len = 0;
  char *copy = arena_alloc(r, len + 1);
  if (copy == NULL) return false;
  if (len > 0) memcpy(copy, t, len);
  copy[len] = '\0';
  n->text = copy;
  n->len = len;
  return true;
}

/* A single-quoted scalar is decoded here from the source between its quotes rather than by
   fy_token_get_text: libfyaml 0.7.12 (Debian 12) returns wrong text for runs of escaped quotes
   ('ab''''cd' gives "ab'''c") and, for five or more in a row, an empty string and a leaked
   buffer (found by fuzz_check). YAML 1.2 section 7.3.2: '' stands for one quote, the only escape;
   a line break folds to a space, n+1 breaks to n newlines, and white space around a break is
   dropped; the first line's leading and the last line's trailing white space are content. */
static bool set_text_single_quoted(nav_io_reader *r, nav_io_node *n, const char *src, size_t src_len,
                                   struct fy_token *tok) {
  const struct fy_mark *a = fy_token_start_mark(tok), *b = fy_token_end_mark(tok);
  if (a == NULL || b == NULL || a->input_pos > b->input_pos || b->input_pos > src_len) return set_text(r, n, tok);
  const char *p = src + a->input_pos, *end = src + b->input_pos;
  char *out = arena_alloc(r, (size_t)(end - p) + 1); /* decoding never lengthens the text */
  if (out == NULL) return false;
  size_t k = 0;
  while (p < end) {
    if (*p == '\'' && p + 1 < end && p[1] == '\'') {
      out[k++] = '\'';
      p += 2;
    } else if (*p == '\n' || *p == '\r') {
      while (k > 0 && (out[k - 1] == ' ' || out[k - 1] == '\t')) --k; /* trailing white space */
      int breaks = 0;
      for (;;) {
        if (p < end && *p == '\r') {
          ++p;
          if (p < end && *p == '\n') ++p;
          ++breaks;
        } else if (p < end && *p == '\n') {
          ++p;
          ++breaks;
        } else {
          break;
        }
        while (p < end && (*p == ' ' || *p == '\t')) ++p; /* leading white space */
      }
      if (breaks == 1)
        out[k++] = ' ';
      else
        for (int i = 1; i < breaks; ++i) out[k++] = '\n';
    } else {
      out[k++] = *p++;
    }
  }
  out[k] = '\0';
  n->text = out;
  n->len = k;
  return true;
}

static void attach(nav_io_node *parent, nav_io_node *n) {
  if (parent->child == NULL)
    parent->child = n;
  else
    parent->last->next = n;
  parent->last = n;
  parent->count++;
}

/* Parse @p text into our tree (*root stays NULL for an empty stream). Returns false after a
   reported problem (syntax error, limits) or on allocation failure (r->oom). */
static bool build_tree(nav_io_reader *r, const char *text, size_t len, nav_io_node **root) {
  bool ok = false;
  struct fy_diag *diag = NULL;
  struct fy_parser *fyp = NULL;
  struct fy_event *ev = NULL;
  nav_io_node *stack[NAV_IO_MAX_DEPTH];
  int depth = 0, ndocs = 0;
  int last_line = 0, last_col = 0;

  *root = NULL;
  struct fy_diag_cfg dcfg;
  fy_diag_cfg_default(&dcfg);
  dcfg.fp = NULL;
  dcfg.output_fn = fy_output_sink;
  dcfg.user = NULL;
  dcfg.level = FYET_ERROR;
  dcfg.colorize = false;
  diag = fy_diag_create(&dcfg);
  if (diag == NULL) {
    r->oom = true;
    goto cleanup;
  }
  fy_diag_set_collect_errors(diag, true);

  struct fy_parse_cfg pcfg;
  memset(&pcfg, 0, sizeof pcfg);
  /* YAML 1.2; no JSON mode guessing; duplicate keys are detected by the schema walk, which can
     say where the first one was. Aliases are never resolved here (events only). */
  pcfg.flags = (enum fy_parse_cfg_flags)(FYPCF_QUIET | FYPCF_DEFAULT_VERSION_1_2 | FYPCF_JSON_NONE);
  pcfg.diag = diag;
  fyp = fy_parser_create(&pcfg);
  if (fyp == NULL || fy_parser_set_string(fyp, text, len) != 0) {
    r->oom = true;
    goto cleanup;
  }

  for (;;) {
    ev = fy_parser_parse(fyp);
    if (ev == NULL) break;
    const struct fy_mark *m = fy_event_start_mark(ev);
    if (m != NULL && m->line >= 0) {
      last_line = m->line + 1;
      last_col = m->column + 1;
    }
    nav_io_node *n = NULL;
    switch (ev->type) {
    case FYET_DOCUMENT_START:
      if (++ndocs > 1) {
        emitf(r, last_line, last_col, "",
              "a scene file holds a single YAML document; found a second one (remove the \"---\")");
        goto cleanup;
      }
      break;
    case FYET_MAPPING_START:
    case FYET_SEQUENCE_START:
      if (depth >= NAV_IO_MAX_DEPTH) {
        emitf(r, last_line, last_col, "", "nesting is deeper than %d levels; this is not a scene file",
              NAV_IO_MAX_DEPTH);
        goto cleanup;
      }
      n = new_node(r, ev->type == FYET_MAPPING_START ? Y_MAP : Y_SEQ, m);
      if (n == NULL) goto cleanup;
      n->tagged = (ev->type == FYET_MAPPING_START ? ev->mapping_start.tag : ev->sequence_start.tag) != NULL;
      if (depth > 0)
        attach(stack[depth - 1], n);
      else
        *root = n;
      stack[depth++] = n;
      break;
    case FYET_MAPPING_END:
    case FYET_SEQUENCE_END:
      if (depth > 0) --depth;
      break;
    case FYET_SCALAR:
    case FYET_ALIAS:
      n = new_node(r, ev->type == FYET_SCALAR ? Y_SCALAR : Y_ALIAS, m);
      if (n == NULL) goto cleanup;
      if (ev->type == FYET_SCALAR) {
        const enum fy_scalar_style style = fy_token_scalar_style(ev->scalar.value);
        if (style == FYSS_SINGLE_QUOTED ? !set_text_single_quoted(r, n, text, len, ev->scalar.value)
                                        : !set_text(r, n, ev->scalar.value))
          goto cleanup;
        n->quoted = style != FYSS_PLAIN;
        n->tagged = ev->scalar.tag != NULL;
        /* libfyaml marks the first character after an opening quote; point at the quote. */
        if ((style == FYSS_SINGLE_QUOTED || style == FYSS_DOUBLE_QUOTED) && n->col > 1) n->col--;
      } else {
        if (!set_text(r, n, ev->alias.anchor)) goto cleanup;
        if (n->col > 1) n->col--; /* the mark follows the '*' */
      }
      if (depth > 0)
        attach(stack[depth - 1], n);
      else
        *root = n;
      break;
    default: break;
    }
    fy_parser_event_free(fyp, ev);
    ev = NULL;
  }

  if (fy_parser_get_stream_error(fyp)) {
    int reported = 0;
    void *iter = NULL;
    for (struct fy_diag_error *e = fy_diag_errors_iterate(diag, &iter); e != NULL;
         e = fy_diag_errors_iterate(diag, &iter)) {
      if (e->type < FYET_ERROR) continue;
      emitf(r, e->line, e->column, "", "YAML syntax error: %s", e->msg != NULL ? e->msg : "invalid YAML");
      ++reported;
    }
    if (reported == 0) emitf(r, last_line, last_col, "", "YAML syntax error");
    goto cleanup;
  }
  ok = true;

cleanup:
  if (ev != NULL) fy_parser_event_free(fyp, ev);
  /* Collected errors hold parser tokens and fy_diag_unref does not free them: drop them first,
     while the parser is alive (libfyaml 0.7). */
  if (diag != NULL) fy_diag_reset_error(diag);
  if (fyp != NULL) fy_parser_destroy(fyp);
  if (diag != NULL) fy_diag_unref(diag);
  return ok;
}

/* ================================================================ scalars */

static bool text_is(const nav_io_node *n, const char *s) {
  return n->len == strlen(s) && memcmp(n->text, s, n->len) == 0;
}

static bool is_null(const nav_io_node *n) {
  return n->kind == Y_SCALAR && !n->quoted &&
         (n->len == 0 || text_is(n, "~") || text_is(n, "null") || text_is(n, "Null") || text_is(n, "NULL"));
}

static bool is_bool(const nav_io_node *n) {
  /* YAML 1.2 core booleans plus the YAML 1.1 words people still write. */
  static const char *const words[] = {"true", "True", "TRUE", "false", "False", "FALSE", "yes", "Yes",
                                      "YES",  "no",   "No",   "NO",    "on",    "On",    "ON",  "off",
                                      "Off",  "OFF",  "y",    "Y",     "n",     "N"};
  if (n->kind != Y_SCALAR || n->quoted) return false;
  for (size_t i = 0; i < COUNT(words); ++i)
    if (text_is(n, words[i])) return true;
  return false;
}

/* A short description of what a node is, for "expected X, got <this>". */
static void describe(char *buf, size_t size, const nav_io_node *n) {
  char shown[SHOW_MAX + 4];
  switch (n->kind) {
  case Y_MAP: snprintf(buf, size, "a mapping"); return;
  case Y_SEQ: snprintf(buf, size, "a sequence"); return;
  case Y_ALIAS: snprintf(buf, size, "an alias"); return;
  case Y_SCALAR: break;
  }
  show(shown, sizeof shown, n->text, n->len);
  if (is_null(n))
    snprintf(buf, size, "null (no value)");
  else if (is_bool(n))
    snprintf(buf, size, "the boolean \"%s\"", shown);
  else if (n->quoted)
    snprintf(buf, size, "the quoted string \"%s\"", shown);
  else
    snprintf(buf, size, "\"%s\"", shown);
}

/* Aliases and tags are not part of the scene format: report them once, where they are used. */
static bool reject_special(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v) {
  char shown[SHOW_MAX + 4];
  if (v->kind == Y_ALIAS) {
    show(shown, sizeof shown, v->text, v->len);
    nav_io_reader_error(r, v, key, "aliases (*%s) are not supported in scene files; write the value out",
                        shown);
    return true;
  }
  if (v->tagged) {
    nav_io_reader_error(r, v, key, "YAML tags (!...) are not supported in scene files; remove the tag");
    return true;
  }
  return false;
}

static bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

/* YAML 1.2 core schema float or decimal integer: [-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)? */
static bool is_decimal_number(const char *s, size_t n) {
  size_t i = 0, digits = 0;
  if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
  while (i < n && is_digit(s[i]))
    ++i, ++digits;
  if (i < n && s[i] == '.') {
    ++i;
    while (i < n && is_digit(s[i]))
      ++i, ++digits;
  }
  if (digits == 0) return false;
  if (i < n && (s[i] == 'e' || s[i] == 'E')) {
    ++i;
    if (i < n && (s[i] == '+' || s[i] == '-')) ++i;
    size_t exp_digits = 0;
    while (i < n && is_digit(s[i]))
      ++i, ++exp_digits;
    if (exp_digits == 0) return false;
  }
  return i == n;
}

static bool is_special_float(const nav_io_node *v, double *out) {
  const char *s = v->text;
  size_t n = v->len;
  double sign = 1.0;
  if (n > 0 && (s[0] == '+' || s[0] == '-')) {
    sign = s[0] == '-' ? -1.0 : 1.0;
    ++s;
    --n;
    if (n == 4 && (memcmp(s, ".inf", 4) == 0 || memcmp(s, ".Inf", 4) == 0 || memcmp(s, ".INF", 4) == 0)) {
      *out = sign * INFINITY;
      return true;
    }
    return false;
  }
  if (n == 4 && (memcmp(s, ".inf", 4) == 0 || memcmp(s, ".Inf", 4) == 0 || memcmp(s, ".INF", 4) == 0)) {
    *out = INFINITY;
    return true;
  }
  if (n == 4 && (memcmp(s, ".nan", 4) == 0 || memcmp(s, ".NaN", 4) == 0 || memcmp(s, ".NAN", 4) == 0)) {
    *out = NAN;
    return true;
  }
  return false;
}

/* A number, as the schema's expectation @p what ("a number", "a sequence of 3 numbers" item). */
static bool parse_double(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, double *out) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return false;
  if (v->kind == Y_SCALAR && !v->quoted && is_special_float(v, out)) return true;
  if (v->kind != Y_SCALAR || v->quoted || !is_decimal_number(v->text, v->len)) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a number, got %s", got);
    return false;
  }
  errno = 0;
  const double d = strtod(v->text, NULL);
  if (errno == ERANGE && isinf(d)) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "number is too large for a double (got %s)", got);
    return false;
  }
  *out = d; /* underflow to a subnormal or zero is accepted: it is the nearest double */
  return true;
}

/* Range and finiteness of a double in file units; the message quotes the text as written. */
static bool check_double(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, double d) {
  char shown[SHOW_MAX + 4], lo[40], hi[40];
  show(shown, sizeof shown, v->text, v->len);
  if ((f->flags & NAV_IO_FINITE) && !isfinite(d)) {
    nav_io_reader_error(r, v, key, "must be finite (got %s)", shown);
    return false;
  }
  if (f->flags & NAV_IO_RANGE_LATER) return true; /* the validator's check, with its own message */
  const bool has_lo = (f->flags & (NAV_IO_MIN_GT | NAV_IO_MIN_GE)) != 0,
             has_hi = (f->flags & NAV_IO_MAX_LE) != 0;
  const bool lo_ok = !has_lo || ((f->flags & NAV_IO_MIN_GT) ? d > f->min : d >= f->min);
  const bool hi_ok = !has_hi || d <= f->max;
  if (lo_ok && hi_ok) return true;
  /* Name the bound that is violated: "must be > 0 (got -5)". */
  if (!lo_ok) {
    nav_io_format_double(lo, sizeof lo, f->min);
    nav_io_reader_error(r, v, key, "must be %s %s (got %s)", (f->flags & NAV_IO_MIN_GT) ? ">" : ">=", lo,
                        shown);
  } else {
    nav_io_format_double(hi, sizeof hi, f->max);
    nav_io_reader_error(r, v, key, "must be <= %s (got %s)", hi, shown);
  }
  return false;
}

/* A YAML 1.2 integer: [-+]?[0-9]+ | 0x[0-9a-fA-F]+ | 0o[0-7]+, as sign and magnitude;
 *overflow is set when the magnitude does not fit 64 bits. */
static bool parse_integer(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, bool *neg,
                          uint64_t *mag, bool *overflow) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return false;
  const char *s = v->text;
  size_t n = v->len, i = 0;
  unsigned base = 10;
  bool ok = v->kind == Y_SCALAR && !v->quoted && n > 0;
  *neg = false;
  *mag = 0;
  *overflow = false;
  if (ok && (s[0] == '+' || s[0] == '-')) {
    *neg = s[0] == '-';
    i = 1;
  } else if (ok && n > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'o')) {
    base = s[1] == 'x' ? 16 : 8;
    i = 2;
  }
  if (ok && i == n) ok = false;
  for (; ok && i < n; ++i) {
    const char c = s[i];
    unsigned dgt = 16;
    if (is_digit(c))
      dgt = (unsigned)(c - '0');
    else if (c >= 'a' && c <= 'f')
      dgt = (unsigned)(c - 'a' + 10);
    else if (c >= 'A' && c <= 'F')
      dgt = (unsigned)(c - 'A' + 10);
    if (dgt >= base) {
      ok = false;
      break;
    }
    if (*mag > (UINT64_MAX - dgt) / base)
      *overflow = true;
    else
      *mag = *mag * base + dgt;
  }
  if (!ok) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected an integer, got %s", got);
  }
  return ok;
}

/* An integer field of any width: range from the descriptor, else from the C type. */
static bool read_integer(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, long long type_min, long long type_max, long long *out) {
  bool neg = false, overflow = false;
  uint64_t mag = 0;
  char shown[SHOW_MAX + 4];
  if (!parse_integer(r, key, v, &neg, &mag, &overflow)) return false;
  show(shown, sizeof shown, v->text, v->len);
  long long lo = type_min, hi = type_max;
  /* a range checked later (NAV_IO_RANGE_LATER) leaves only the type's range here */
  const bool later = (f->flags & NAV_IO_RANGE_LATER) != 0;
  const bool lo_given = !later && (f->flags & NAV_IO_MIN_GE) != 0,
             hi_given = !later && (f->flags & NAV_IO_MAX_LE) != 0;
  if (lo_given && f->min > (double)lo) lo = (long long)f->min;
  if (hi_given && f->max < (double)hi) hi = (long long)f->max;
  /* Below or above the range; magnitudes beyond long long are beyond every range. */
  bool below = false, above = false;
  long long val = 0;
  if (overflow || mag > (uint64_t)LLONG_MAX + (neg ? 1u : 0u)) {
    below = neg;
    above = !neg;
  } else {
    val = !neg ? (long long)mag : mag == (uint64_t)LLONG_MAX + 1u ? LLONG_MIN : -(long long)mag;
    below = val < lo;
    above = val > hi;
  }
  /* Name the bound that is violated; the C type's limits only when no range is given. */
  if (below && lo_given) {
    nav_io_reader_error(r, v, key, "must be >= %lld (got %s)", lo, shown);
    return false;
  }
  if (above && hi_given) {
    nav_io_reader_error(r, v, key, "must be <= %lld (got %s)", hi, shown);
    return false;
  }
  if (below || above) {
    nav_io_reader_error(r, v, key, "must be in [%lld, %lld] (got %s)", lo, hi, shown);
    return false;
  }
  *out = val;
  return true;
}

static bool read_u64(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, uint64_t *out) {
  bool neg = false, overflow = false;
  uint64_t mag = 0;
  char shown[SHOW_MAX + 4];
  if (!parse_integer(r, key, v, &neg, &mag, &overflow)) return false;
  show(shown, sizeof shown, v->text, v->len);
  if (neg && (mag > 0 || overflow)) {
    nav_io_reader_error(r, v, key, "must be >= 0 (got %s)", shown);
    return false;
  }
  if (overflow) {
    nav_io_reader_error(r, v, key, "must be <= %" PRIu64 " (got %s)", UINT64_MAX, shown);
    return false;
  }
  *out = mag;
  return true;
}

/* ================================================================ tree access for the other files */

bool nav_io_node_is_map(const nav_io_node *n) {
  return n != NULL && n->kind == Y_MAP;
}

bool nav_io_node_is_seq(const nav_io_node *n) {
  return n != NULL && n->kind == Y_SEQ;
}

bool nav_io_node_text_is(const nav_io_node *n, const char *s) {
  return n != NULL && n->kind == Y_SCALAR && text_is(n, s);
}

const char *nav_io_node_text(const nav_io_node *n, size_t *len) {
  if (len != NULL) *len = n != NULL && n->text != NULL ? n->len : 0;
  return n != NULL && n->text != NULL ? n->text : "";
}

size_t nav_io_node_count(const nav_io_node *n) {
  if (n == NULL) return 0;
  return n->kind == Y_MAP ? n->count / 2 : n->count;
}

const nav_io_node *nav_io_node_child(const nav_io_node *n) {
  return n != NULL ? n->child : NULL;
}

const nav_io_node *nav_io_node_next(const nav_io_node *n) {
  return n != NULL ? n->next : NULL;
}

const nav_io_node *nav_io_map_get(const nav_io_node *map, const char *key, const nav_io_node **key_out) {
  if (key_out != NULL) *key_out = NULL;
  if (map == NULL || map->kind != Y_MAP) return NULL;
  for (const nav_io_node *k = map->child; k != NULL && k->next != NULL; k = k->next->next)
    if (k->kind == Y_SCALAR && text_is(k, key)) {
      if (key_out != NULL) *key_out = k;
      return k->next;
    }
  return NULL;
}

bool nav_io_read_number(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, double *out) {
  return parse_double(r, key, v, out);
}

bool nav_io_check_number(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, double d) {
  return check_double(r, f, key, v, d);
}

void nav_io_expected(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, const char *expected) {
  char got[SHOW_MAX + 32];
  describe(got, sizeof got, v);
  nav_io_reader_error(r, v, key, "expected %s, got %s", expected, got);
}

bool nav_io_reject_special(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v) {
  return reject_special(r, key, v);
}

/* ================================================================ did you mean */

static char lower(char c) {
  return c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c;
}

/* Optimal string alignment distance (Levenshtein plus adjacent transpositions), case-blind; three
   rows (i - 2, i - 1, i) of at most 128 + 1 entries. */
static size_t edit_distance(const char *a, size_t la, const char *b, size_t lb) {
  enum { N = 128 };
  size_t r0[N + 1], r1[N + 1], r2[N + 1];
  if (la > N || lb > N) return (size_t)-1;
  for (size_t j = 0; j <= lb; ++j) {
    r0[j] = j;
    r1[j] = j;
  }
  for (size_t i = 1; i <= la; ++i) {
    r2[0] = i;
    for (size_t j = 1; j <= lb; ++j) {
      const size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
      size_t best = r1[j] + 1;
      if (r2[j - 1] + 1 < best) best = r2[j - 1] + 1;
      if (r1[j - 1] + cost < best) best = r1[j - 1] + cost;
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]) &&
          r0[j - 2] + 1 < best)
        best = r0[j - 2] + 1;
      r2[j] = best;
    }
    memcpy(r0, r1, (lb + 1) * sizeof r0[0]);
    memcpy(r1, r2, (lb + 1) * sizeof r1[0]);
  }
  return r1[lb];
}

/* The closest of @p names to @p text within the did-you-mean budget (ASCII case-blind), or NULL. */
static const char *closest(const char *text, size_t len, const char *const *names, size_t n) {
  /* The budget grows with the length of the word: one typo in a short key, a few in a long name. */
  size_t budget = len <= 3 ? 1 : len <= 8 ? 2 : 3;
  if (len / 5 > budget) budget = len / 5;
  size_t best = (size_t)-1;
  const char *best_name = NULL;
  for (size_t i = 0; i < n; ++i) {
    const size_t d = edit_distance(text, len, names[i], strlen(names[i]));
    if (d < best) {
      best = d;
      best_name = names[i];
    }
  }
  return best_name != NULL && best <= budget && best < len ? best_name : NULL;
}

/* ================================================================ fields and sections */

static void list_keys(char *buf, size_t size, const nav_io_section *sec) {
  size_t len = 0;
  buf[0] = '\0';
  for (size_t i = 0; i < sec->count && len < size; ++i) {
    const int n = snprintf(buf + len, size - len, "%s%s", i ? ", " : "", sec->fields[i].key);
    if (n < 0) break;
    len += (size_t)n;
  }
}

static void list_enum(char *buf, size_t size, const nav_io_enum_value *e) {
  size_t len = 0;
  buf[0] = '\0';
  for (size_t i = 0; e[i].name != NULL && len < size; ++i) {
    const int n = snprintf(buf + len, size - len, "%s%s", i ? ", " : "", e[i].name);
    if (n < 0) break;
    len += (size_t)n;
  }
}

static void read_section(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key,
                         const nav_io_node *v, void *base, const nav_io_node *skip_key);

/* The @p n items of sequence @p v as numbers, each range-checked as @p f says (file units). */
static bool read_number_items(nav_io_reader *r, const nav_io_field *f, const nav_io_node *v, double *x,
                              size_t n) {
  bool ok = true;
  size_t i = 0;
  for (const nav_io_node *item = v->child; item != NULL && i < n; item = item->next, ++i) {
    const size_t saved = path_push_index(r, i);
    mark_path(r, item, v);
    if (!parse_double(r, v, item, &x[i]) || !check_double(r, f, v, item, x[i])) ok = false;
    path_pop(r, saved);
  }
  return ok;
}

static bool read_vec3(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                      void *base, bool scalar_ok) {
  char got[SHOW_MAX + 32];
  const char *what = scalar_ok ? "a number or a sequence of 3 numbers" : "a sequence of 3 numbers";
  double x[3];
  if (reject_special(r, key, v)) return false;
  if (scalar_ok && v->kind == Y_SCALAR) {
    if (!parse_double(r, key, v, &x[0]) || !check_double(r, f, key, v, x[0])) return false;
    x[1] = x[2] = x[0];
  } else if (v->kind != Y_SEQ) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected %s, got %s", what, got);
    return false;
  } else if (v->count != 3) {
    nav_io_reader_error(r, v, key, "expected %s, got %zu", what, v->count);
    return false;
  } else if (!read_number_items(r, f, v, x, 3)) {
    return false;
  }
  nav_vec3 *dst = (nav_vec3 *)((char *)base + f->offset);
  *dst = nav_vec3_make(x[0] * f->scale, x[1] * f->scale, x[2] * f->scale);
  return true;
}

/* A 3x3 matrix: one number (every off-diagonal element, or the diagonal), 3 numbers (the
   diagonal; NAV_IO_MAT3_DIAG only) or 3 rows of 3 numbers. */
static bool read_mat3(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                      void *base) {
  char got[SHOW_MAX + 32];
  const bool diag = f->kind == NAV_IO_MAT3_DIAG;
  const char *what = diag ? "a number or 3 numbers (the diagonal), or 3 rows of 3 numbers"
                          : "a number (every off-diagonal element) or 3 rows of 3 numbers";
  double m[3][3] = {{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}};
  if (reject_special(r, key, v)) return false;
  if (v->kind == Y_SCALAR) {
    double x = 0.0;
    if (!parse_double(r, key, v, &x) || !check_double(r, f, key, v, x)) return false;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if ((i == j) == diag) m[i][j] = x;
  } else if (v->kind != Y_SEQ || v->count != 3) {
    if (v->kind == Y_SEQ)
      snprintf(got, sizeof got, "%zu items", v->count);
    else
      describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected %s, got %s", what, got);
    return false;
  } else if (diag && v->child->kind != Y_SEQ) {
    double x[3];
    if (!read_number_items(r, f, v, x, 3)) return false;
    for (int i = 0; i < 3; ++i)
      m[i][i] = x[i];
  } else {
    bool ok = true;
    size_t i = 0;
    for (const nav_io_node *row = v->child; row != NULL && i < 3; row = row->next, ++i) {
      const size_t saved = path_push_index(r, i);
      if (reject_special(r, v, row)) {
        ok = false;
      } else if (row->kind != Y_SEQ || row->count != 3) {
        if (row->kind == Y_SEQ)
          snprintf(got, sizeof got, "%zu items", row->count);
        else
          describe(got, sizeof got, row);
        nav_io_reader_error(r, row, v, "expected a row of 3 numbers, got %s", got);
        ok = false;
      } else if (!read_number_items(r, f, row, m[i], 3)) {
        ok = false;
      }
      path_pop(r, saved);
    }
    if (!ok) return false;
  }
  nav_mat3 *dst = (nav_mat3 *)((char *)base + f->offset);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      dst->m[i][j] = m[i][j] * f->scale;
  return true;
}

static bool read_bool(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                      void *base) {
  if (reject_special(r, key, v)) return false;
  static const char *const yes[] = {"true", "True", "TRUE"}, *const no[] = {"false", "False", "FALSE"};
  bool *dst = (bool *)((char *)base + f->offset);
  if (v->kind == Y_SCALAR && !v->quoted)
    for (size_t i = 0; i < COUNT(yes); ++i) {
      if (text_is(v, yes[i])) {
        *dst = true;
        return true;
      }
      if (text_is(v, no[i])) {
        *dst = false;
        return true;
      }
    }
  nav_io_expected(r, key, v, "true or false");
  return false;
}

bool nav_io_read_enum_value(nav_io_reader *r, const nav_io_enum_value *e, const nav_io_node *key,
                            const nav_io_node *v, int *out) {
  char list[512], got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return false;
  if (v->kind == Y_SCALAR && !is_null(v))
    for (size_t i = 0; e[i].name != NULL; ++i)
      if (text_is(v, e[i].name)) {
        *out = e[i].value;
        return true;
      }
  list_enum(list, sizeof list, e);
  describe(got, sizeof got, v);
  const char *names[64];
  size_t n = 0;
  for (; e[n].name != NULL && n < COUNT(names); ++n)
    names[n] = e[n].name;
  const char *best = v->kind == Y_SCALAR && !is_null(v) ? closest(v->text, v->len, names, n) : NULL;
  if (best != NULL)
    nav_io_reader_error(r, v, key, "expected one of: %s; got %s (did you mean \"%s\"?)", list, got, best);
  else
    nav_io_reader_error(r, v, key, "expected one of: %s; got %s", list, got);
  return false;
}

static bool read_string(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                        void *base) {
  char got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return false;
  if (v->kind != Y_SCALAR || is_null(v)) {
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a string, got %s", got);
    return false;
  }
  if (v->len >= f->size) {
    nav_io_reader_error(r, v, key, "is too long (%zu bytes); at most %zu bytes are allowed", v->len,
                        f->size - 1);
    return false;
  }
  for (size_t i = 0; i < v->len; ++i) {
    const unsigned char c = (unsigned char)v->text[i];
    if (c < 0x20 || c == 0x7f) {
      nav_io_reader_error(r, v, key, "must not contain control characters (byte 0x%02x)", c);
      return false;
    }
  }
  char *dst = (char *)base + f->offset;
  memcpy(dst, v->text, v->len);
  dst[v->len] = '\0';
  return true;
}

/* One value; true if it was stored. A field with a term bit switches its term on. */
static bool read_field(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                       void *base_in) {
  char *base = (f->flags & NAV_IO_STATE) ? (char *)&r->state : (char *)base_in;
  double d = 0.0;
  long long ll = 0;
  int e = 0;
  bool ok = false;
  switch (f->kind) {
  case NAV_IO_SECTION:
    read_section(r, f->section, key, v, base, NULL);
    ok = true;
    break;
  case NAV_IO_DOUBLE:
    ok = parse_double(r, key, v, &d) && check_double(r, f, key, v, d);
    if (ok) *(double *)(base + f->offset) = d * f->scale;
    break;
  case NAV_IO_VEC3: ok = read_vec3(r, f, key, v, base, false); break;
  case NAV_IO_VEC3S: ok = read_vec3(r, f, key, v, base, true); break;
  case NAV_IO_MAT3_OFFDIAG:
  case NAV_IO_MAT3_DIAG: ok = read_mat3(r, f, key, v, base); break;
  case NAV_IO_INT:
    ok = read_integer(r, f, key, v, INT_MIN, INT_MAX, &ll);
    if (ok) *(int *)(base + f->offset) = (int)ll;
    break;
  case NAV_IO_LONG:
    ok = read_integer(r, f, key, v, LONG_MIN, LONG_MAX, &ll);
    if (ok) *(long *)(base + f->offset) = (long)ll;
    break;
  case NAV_IO_U64: ok = read_u64(r, key, v, (uint64_t *)(base + f->offset)); break;
  case NAV_IO_BOOL: ok = read_bool(r, f, key, v, base); break;
  case NAV_IO_ENUM:
    ok = nav_io_read_enum_value(r, f->enums, key, v, &e);
    if (ok) *(int *)(base + f->offset) = e;
    break;
  case NAV_IO_STRING: ok = read_string(r, f, key, v, base); break;
  case NAV_IO_CUSTOM:
    f->read(r, f, key, v, base);
    ok = true;
    break;
  }
  if (ok && f->bit != 0 && !(f->flags & NAV_IO_STATE)) *(unsigned *)(base + f->bits_offset) |= f->bit;
  return ok;
}

/* Fields with the same storage are spellings of one quantity (lat_deg / lat_rad). */
static size_t group_of(const nav_io_section *sec, size_t i) {
  const nav_io_field *f = &sec->fields[i];
  if (f->kind == NAV_IO_SECTION) return i;
  for (size_t j = 0; j < i; ++j) {
    const nav_io_field *g = &sec->fields[j];
    if (g->kind == f->kind && g->offset == f->offset &&
        (g->flags & NAV_IO_STATE) == (f->flags & NAV_IO_STATE) &&
        (f->kind != NAV_IO_CUSTOM || g->read == f->read))
      return j;
  }
  return i;
}

static long find_field(const nav_io_section *sec, const nav_io_node *key) {
  for (size_t i = 0; i < sec->count; ++i)
    if (text_is(key, sec->fields[i].key)) return (long)i;
  return -1;
}

static void unknown_key(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key) {
  char shown[SHOW_MAX + 4], list[512];
  show(shown, sizeof shown, key->text, key->len);
  /* In a list element (a waypoint, a segment) a misspelt key leaves a field at its default, and
     validation would only add a confusing message about that field: the element is marked. */
  const char *dot = strrchr(r->path, '.');
  if (dot != NULL && dot > r->path && dot[-1] == ']' && r->nerr_paths < NAV_DIAG_MAX_PER_FILE)
    snprintf(r->err_paths[r->nerr_paths++], PATH_MAX_LEN, "%.*s", (int)(dot - r->path), r->path);

  /* "rate" for "rate_hz", "lat" for "lat_deg" / "lat_rad": the unit suffix is missing. */
  const char *prefixed[3];
  size_t nprefixed = 0;
  for (size_t i = 0; i < sec->count && nprefixed < 3; ++i) {
    const char *k = sec->fields[i].key;
    if (key->len > 0 && strlen(k) > key->len + 1 && memcmp(k, key->text, key->len) == 0 && k[key->len] == '_')
      prefixed[nprefixed++] = k;
  }
  if (nprefixed == 1) {
    nav_io_reader_error(r, key, NULL, "unknown key \"%s\"; did you mean \"%s\"? (keys carry their unit)",
                        shown, prefixed[0]);
    return;
  }
  if (nprefixed > 1) {
    nav_io_reader_error(r, key, NULL,
                        "unknown key \"%s\"; did you mean \"%s\" or \"%s\"? (keys carry their unit)", shown,
                        prefixed[0], prefixed[1]);
    return;
  }

  /* Closest key by edit distance, within a budget that grows with the length of the key. */
  const char *names[MAX_SECTION_FIELDS];
  for (size_t i = 0; i < sec->count; ++i)
    names[i] = sec->fields[i].key;
  const char *best = closest(key->text, key->len, names, sec->count);
  if (best != NULL) {
    nav_io_reader_error(r, key, NULL, "unknown key \"%s\"; did you mean \"%s\"?", shown, best);
    return;
  }
  list_keys(list, sizeof list, sec);
  nav_io_reader_error(r, key, NULL, "unknown key \"%s\"; expected one of: %s", shown, list);
}

static int phase_of(const nav_io_field *f) {
  return (f->flags & NAV_IO_EARLY) ? 0 : (f->flags & NAV_IO_LATE) ? 2 : 1;
}

/*
 * Read the mapping @p map against @p sec into @p base. @p skip_key was already read
 * (format_version). Keys are taken in three passes: NAV_IO_EARLY ones (what the others build on,
 * e.g. a catalog part), then the others in file order, then NAV_IO_LATE ones ("off" lists), so
 * the result does not depend on the order of the keys, which YAML leaves open.
 */
static void read_mapping(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *map, void *base,
                         const nav_io_node *skip_key) {
  const nav_io_node *seen_key[MAX_SECTION_FIELDS] = {NULL};
  size_t seen_field[MAX_SECTION_FIELDS] = {0};
  char got[SHOW_MAX + 32];
  bool has_phase[3] = {false, true, false};
  for (size_t i = 0; i < sec->count; ++i)
    has_phase[phase_of(&sec->fields[i])] = true;

  for (int pass = 0; pass < 3; ++pass) {
    if (!has_phase[pass]) continue;
    for (const nav_io_node *key = map->child; key != NULL && !r->stop;
         key = key->next ? key->next->next : NULL) {
      const nav_io_node *value = key->next;
      if (value == NULL) break; /* cannot happen: libfyaml gives mappings an even number of events */
      if (key->kind != Y_SCALAR || is_null(key)) {
        if (pass == 1) {
          describe(got, sizeof got, key);
          nav_io_reader_error(r, key, value, "expected a key name, got %s", got);
        }
        continue;
      }
      const long idx = find_field(sec, key);
      if (idx < 0) {
        if (pass == 1) {
          const size_t saved = path_push_key(r, key->text, key->len);
          unknown_key(r, sec, key);
          path_pop(r, saved);
        }
        continue;
      }
      if (phase_of(&sec->fields[idx]) != pass) continue;
      const size_t saved = path_push_key(r, key->text, key->len);
      const size_t g = group_of(sec, (size_t)idx);
      if (seen_key[g] != NULL) {
        const nav_io_node *first = seen_key[g];
        if (seen_field[g] == (size_t)idx)
          nav_io_reader_error(r, key, NULL, "duplicate key \"%s\" (first given at line %d, column %d)",
                              sec->fields[idx].key, first->line, first->col);
        else
          nav_io_reader_error(r, key, NULL, "both \"%s\" and \"%s\" are given; give only one of them",
                              sec->fields[seen_field[g]].key, sec->fields[idx].key);
        path_pop(r, saved);
        continue;
      }
      seen_key[g] = key;
      seen_field[g] = (size_t)idx;
      if (key != skip_key) {
        /* Mark the value under every spelling (and the validators' SI name), so validation
           messages about "lat_deg" find a file that wrote "lat_rad". */
        for (size_t j = 0; j < sec->count; ++j) {
          if (group_of(sec, j) != g) continue;
          path_pop(r, saved);
          path_push_key(r, sec->fields[j].key, strlen(sec->fields[j].key));
          mark_path(r, value, key);
          if (sec->fields[j].mark_as != NULL) {
            path_pop(r, saved);
            path_push_key(r, sec->fields[j].mark_as, strlen(sec->fields[j].mark_as));
            mark_path(r, value, key);
          }
        }
        path_pop(r, saved);
        path_push_key(r, key->text, key->len);
        (void)read_field(r, &sec->fields[idx], key, value, base);
      }
      path_pop(r, saved);
    }
  }

  for (size_t i = 0; i < sec->count && !r->stop; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (!(f->flags & NAV_IO_REQUIRED) || group_of(sec, i) != i || seen_key[i] != NULL) continue;
    const size_t saved = path_push_key(r, f->key, strlen(f->key));
    nav_io_reader_error(r, map, NULL, "missing required key \"%s\"", f->key);
    path_pop(r, saved);
  }
  if (sec->finish != NULL && !r->stop) sec->finish(r, map, base);
}

static void read_section(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key,
                         const nav_io_node *v, void *base, const nav_io_node *skip_key) {
  char list[512], got[SHOW_MAX + 32];
  if (reject_special(r, key, v)) return;
  if (is_null(v)) { /* "imu:" with every key commented out: all defaults */
    if (sec->finish != NULL) sec->finish(r, v, base);
    return;
  }
  if (v->kind != Y_MAP) {
    list_keys(list, sizeof list, sec);
    describe(got, sizeof got, v);
    nav_io_reader_error(r, v, key, "expected a mapping with keys %s; got %s", list, got);
    return;
  }
  read_mapping(r, sec, v, base, skip_key);
}

void nav_io_read_section(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key,
                         const nav_io_node *map, void *base) {
  read_section(r, sec, key, map, base, NULL);
}

static void read_format_version(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                                const nav_io_node *value, void *base) {
  nav_scene *scene = base;
  long long v = 0;
  const nav_io_field as_int = {.key = f->key, .kind = NAV_IO_INT};
  if (!read_integer(r, &as_int, key, value, INT_MIN, INT_MAX, &v)) return;
  char supported[32];
  if (NAV_SCENE_FORMAT_VERSION == 1)
    snprintf(supported, sizeof supported, "1");
  else
    snprintf(supported, sizeof supported, "1 to %d", NAV_SCENE_FORMAT_VERSION);
  if (v < 1) {
    nav_io_reader_error(r, value, key, "must be >= 1 (got %lld); supported versions: %s", v, supported);
    return;
  }
  if (v > NAV_SCENE_FORMAT_VERSION) {
    nav_io_reader_error(r, value, key,
                        "format_version %lld is newer than this program supports (supported versions: %s); "
                        "update navcore to read this file",
                        v, supported);
    r->newer_format = true;
    return;
  }
  scene->format_version = (int)v;
}

static void read_root(nav_io_reader *r, const nav_io_node *root, nav_scene *scene) {
  char got[SHOW_MAX + 32];
  if (root->kind != Y_MAP) {
    describe(got, sizeof got, root);
    nav_io_reader_error(
        r, root, NULL,
        "expected a mapping of scene keys (format_version, name, earth, trajectory, ...) at the "
        "top level, got %s",
        got);
    return;
  }
  /* format_version first, wherever it is: a newer file is not read against this schema. */
  const nav_io_section *sec = &nav_io_scene_schema;
  const nav_io_node *fv_key = NULL;
  for (const nav_io_node *k = root->child; k != NULL && k->next != NULL; k = k->next->next)
    if (k->kind == Y_SCALAR && text_is(k, "format_version")) {
      fv_key = k;
      break;
    }
  if (fv_key != NULL) {
    const long idx = find_field(sec, fv_key);
    const size_t saved = path_push_key(r, fv_key->text, fv_key->len);
    mark_path(r, fv_key->next, fv_key);
    (void)read_field(r, &sec->fields[idx], fv_key, fv_key->next, scene);
    path_pop(r, saved);
    if (r->newer_format) return;
  }
  read_mapping(r, sec, root, scene, fv_key);
}

/* ================================================================ custom fields of the sensor sections */

/* The resources directory: $NAV_RESOURCES_DIR, else <share>/resources (nav_paths.h). */
static bool resources_dir(char *buf, size_t size) {
  return nav_paths_resources_dir(buf, size);
}

static void forward_diag(void *user, const nav_diag *d) {
  nav_io_reader_forward(user, d);
}

static bool contains_nocase(const char *hay, const char *needle, size_t n) {
  const size_t h = strlen(hay);
  for (size_t i = 0; n > 0 && i + n <= h; ++i) {
    size_t k = 0;
    while (k < n && lower(hay[i + k]) == lower(needle[k]))
      ++k;
    if (k == n) return true;
  }
  return false;
}

/*
 * imu.catalog / gnss.catalog: the part (IMU row name, GNSS mode) whose converted model becomes
 * the base of the section; the section's other keys then override it. Read first (NAV_IO_EARLY),
 * after imu.bias_convention, which the conversion of allan_min rows uses.
 */
static void read_catalog(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, void *base) {
  nav_scene *s = base;
  const bool imu = f->offset == OFF(imu.catalog);
  const bool arr = f->offset == OFF(array.catalog);
  const char *what = imu ? "IMU" : arr ? "accelerometer part" : "GNSS receiver";
  const char *file = imu ? "imu_catalog.csv" : arr ? "accel_catalog.csv" : "gnss_receivers.csv";
  const char *flag = imu ? "imu" : arr ? "accel" : "gnss";
  char name[NAV_SCENE_CATALOG_NAME_MAX], dir[NAV_IO_PATH_MAX], path[NAV_IO_PATH_MAX + 32],
      shown[SHOW_MAX + 4];
  nav_catalog *cat = NULL;
  if (reject_special(r, key, v)) return;
  if (v->kind != Y_SCALAR || is_null(v)) {
    nav_io_expected(r, key, v,
                    imu   ? "an IMU name from resources/imu_catalog.csv"
                    : arr ? "an accelerometer part from resources/accel_catalog.csv"
                          : "a receiver mode from resources/gnss_receivers.csv");
    return;
  }
  if (v->len >= sizeof name || memchr(v->text, '\0', v->len) != NULL) {
    nav_io_reader_error(r, v, key, "is not a catalog name (at most %zu bytes)", sizeof name - 1);
    return;
  }
  memcpy(name, v->text, v->len);
  name[v->len] = '\0';
  show(shown, sizeof shown, v->text, v->len);
  if (!resources_dir(dir, sizeof dir)) {
    nav_io_reader_error(
        r, v, key, "cannot find the resources directory with the %s catalog; set NAV_RESOURCES_DIR", what);
    return;
  }
  snprintf(path, sizeof path, "%s/%s", dir, file);
  nav_catalog_options opt = nav_catalog_options_default();
  /* imu.bias_convention belongs to the IMU section, which a file may place after the array: the
     array's parts always use the default convention so that the order of the sections does not
     matter (nav_catalog.h; docs/gyro-free-gnss.md section 8). */
  if (!arr) opt.convention = (nav_bi_convention)r->state.bias_convention;
  const nav_status st = nav_catalog_load(path, &opt, &cat, forward_diag, r);
  if (st != NAV_OK) {
    nav_io_reader_error(r, v, key, "cannot load the %s catalog %s (%s)", what, path, nav_status_str(st));
    goto cleanup;
  }
  if (imu) {
    const nav_catalog_imu_entry *e = nav_catalog_find_imu(cat, name);
    if (e != NULL) {
      s->imu.model = e->config;
      snprintf(s->imu.catalog, sizeof s->imu.catalog, "%s", e->name);
      goto cleanup;
    }
  } else if (arr) {
    /* The part's terms replace the array's; the accel keys of the section, read later, override. */
    const nav_catalog_accel_entry *e = nav_catalog_find_accel(cat, name);
    if (e != NULL) {
      s->array.accel = e->config;
      snprintf(s->array.catalog, sizeof s->array.catalog, "%s", e->name);
      goto cleanup;
    }
  } else {
    const nav_catalog_gnss_entry *e = nav_catalog_find_gnss(cat, name);
    if (e != NULL) {
      s->gnss.model = e->config;
      snprintf(s->gnss.catalog, sizeof s->gnss.catalog, "%s", e->name);
      goto cleanup;
    }
  }
  {
    /* Unknown: the closest name, else the only name containing what was written. */
    const char *names[NAV_CATALOG_MAX_ENTRIES] = {NULL};
    const size_t n = nav_catalog_count(cat);
    size_t n_sub = 0;
    const char *sub = NULL;
    for (size_t i = 0; i < n && i < COUNT(names); ++i) {
      names[i] = imu   ? nav_catalog_imu_at(cat, i)->name
                 : arr ? nav_catalog_accel_at(cat, i)->name
                       : nav_catalog_gnss_at(cat, i)->name;
      if (contains_nocase(names[i], name, v->len)) {
        sub = names[i];
        ++n_sub;
      }
    }
    const char *best = closest(name, v->len, names, n < COUNT(names) ? n : COUNT(names));
    if (best == NULL && n_sub == 1) best = sub;
    if (best != NULL)
      nav_io_reader_error(r, v, key,
                          "unknown %s \"%s\"; did you mean \"%s\"? (`navsim catalog --%s` lists %s)", what,
                          shown, best, flag, path);
    else
      nav_io_reader_error(r, v, key, "unknown %s \"%s\"; `navsim catalog --%s` lists the %zu entries of %s",
                          what, shown, flag, n, path);
  }
cleanup:
  nav_catalog_destroy(cat);
}

static nav_status write_catalog(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)indent;
  const nav_status st = nav_io_writef(w, " ");
  return st != NAV_OK ? st : nav_io_write_quoted(w, (const char *)base + f->offset);
}

static bool same_string(const nav_io_field *f, const void *a, const void *b) {
  return strcmp((const char *)a + f->offset, (const char *)b + f->offset) == 0;
}

static bool catalog_given(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w;
  (void)def;
  return ((const char *)base + f->offset)[0] != '\0';
}

/* ---------------------------------------------------------------- "off": terms switched off */

typedef struct term_name {
  const char *name;
  unsigned bit;
} term_name;

static const term_name k_imu_terms[] = {{"bias_turn_on", NAV_IMU_TERM_BIAS_TURN_ON},
                                        {"bias_gm", NAV_IMU_TERM_BIAS_GM},
                                        {"bias_rw", NAV_IMU_TERM_BIAS_RW},
                                        {"noise", NAV_IMU_TERM_NOISE},
                                        {"scale_factor", NAV_IMU_TERM_SCALE_FACTOR},
                                        {"misalignment", NAV_IMU_TERM_MISALIGNMENT},
                                        {"g_sensitivity", NAV_IMU_TERM_G_SENSITIVITY},
                                        {"quantisation", NAV_IMU_TERM_QUANTISATION},
                                        {"saturation", NAV_IMU_TERM_SATURATION}};
static const term_name k_gnss_terms[] = {{"position", NAV_GNSS_TERM_POS_GM},
                                         {"position_white", NAV_GNSS_TERM_POS_WHITE},
                                         {"velocity", NAV_GNSS_TERM_VEL_WHITE}};
static const term_name k_array_terms[] = {{"bias_turn_on", NAV_IMU_TERM_BIAS_TURN_ON},
                                          {"bias_gm", NAV_IMU_TERM_BIAS_GM},
                                          {"noise", NAV_IMU_TERM_NOISE},
                                          {"scale_factor", NAV_IMU_TERM_SCALE_FACTOR}};

/*
 * imu.off: [noise, gyro.bias_gm, ...] switches terms off after everything else was read (a
 * catalog part's term, or one whose values are kept for later). A plain name applies to both
 * triads, "gyro." / "accel." to one. gnss.off: [position, position_white, velocity].
 * array.accel.off: [bias_turn_on, bias_gm, noise, scale_factor].
 */
static void read_off(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key, const nav_io_node *v,
                     void *base) {
  nav_scene *s = base;
  const bool imu = f->offset == OFF(imu.model);
  const bool arr = f->offset == OFF(array.accel);
  const term_name *terms = imu ? k_imu_terms : arr ? k_array_terms : k_gnss_terms;
  const size_t nterms = imu ? COUNT(k_imu_terms) : arr ? COUNT(k_array_terms) : COUNT(k_gnss_terms);
  char shown[SHOW_MAX + 4];
  if (reject_special(r, key, v)) return;
  if (is_null(v)) return;
  const bool seq = v->kind == Y_SEQ;
  if (!seq && v->kind != Y_SCALAR) {
    nav_io_expected(r, key, v,
                    imu   ? "a list of term names ([noise, gyro.bias_gm, ...])"
                    : arr ? "a list of term names ([bias_turn_on, bias_gm, noise, scale_factor])"
                          : "a list of term names ([position, position_white, velocity])");
    return;
  }
  size_t i = 0;
  for (const nav_io_node *item = seq ? v->child : v; item != NULL; item = seq ? item->next : NULL, ++i) {
    const size_t saved = seq ? path_push_index(r, i) : r->path_len;
    if (reject_special(r, v, item)) {
      path_pop(r, saved);
      continue;
    }
    if (item->kind != Y_SCALAR || is_null(item)) {
      nav_io_expected(r, v, item, "a term name");
      path_pop(r, saved);
      continue;
    }
    const char *t = item->text;
    size_t len = item->len;
    int triad = -1; /* both */
    if (imu && len > 5 && memcmp(t, "gyro.", 5) == 0) {
      triad = 0;
      t += 5;
      len -= 5;
    } else if (imu && len > 6 && memcmp(t, "accel.", 6) == 0) {
      triad = 1;
      t += 6;
      len -= 6;
    }
    unsigned bit = 0;
    for (size_t k = 0; k < nterms; ++k)
      if (strlen(terms[k].name) == len && memcmp(terms[k].name, t, len) == 0) bit = terms[k].bit;
    show(shown, sizeof shown, item->text, item->len);
    if (bit == 0) {
      const char *names[COUNT(k_imu_terms)] = {NULL};
      char list[256];
      size_t n = 0, l = 0;
      list[0] = '\0';
      for (size_t k = 0; k < nterms; ++k) {
        names[n++] = terms[k].name;
        const int m = snprintf(list + l, sizeof list - l, "%s%s", k ? ", " : "", terms[k].name);
        if (m > 0 && (size_t)m < sizeof list - l) l += (size_t)m;
      }
      const char *best = closest(t, len, names, n);
      if (best != NULL)
        nav_io_reader_error(r, item, v, "unknown term \"%s\"; did you mean \"%s%s\"?", shown,
                            triad == 0   ? "gyro."
                            : triad == 1 ? "accel."
                                         : "",
                            best);
      else
        nav_io_reader_error(r, item, v, "unknown term \"%s\"; terms: %s%s", shown, list,
                            imu ? " (each optionally prefixed gyro. or accel.)" : "");
    } else if (imu && triad == 1 && bit == NAV_IMU_TERM_G_SENSITIVITY) {
      nav_io_reader_error(r, item, v, "g_sensitivity is a gyro term; accelerometers have none");
    } else if (imu) {
      if (triad != 1) s->imu.model.gyro.terms &= ~bit;
      if (triad != 0) s->imu.model.accel.terms &= ~bit;
    } else if (arr) {
      s->array.accel.terms &= ~bit;
    } else {
      s->gnss.model.terms &= ~bit;
    }
    path_pop(r, saved);
  }
}

/* A term written with values although it is off, or off while a catalog part (which the reader
   loads first) may switch it on: it goes into the "off" list. */
static bool needs_off(const nav_io_writer *w, const nav_io_section *sec, unsigned terms, unsigned bit,
                      const char *catalog) {
  if (terms & bit) return false;
  if (catalog[0] != '\0') return true;
  for (size_t i = 0; i < sec->count; ++i) {
    const nav_io_field *f = &sec->fields[i];
    if (f->bit == bit && !(f->flags & (NAV_IO_ALT | NAV_IO_STATE)) && !nav_io_field_same(f, w->scene, w->def))
      return true;
  }
  return false;
}

/* The names of the "off" list of @p f; returns how many (names point into static tables or @p buf). */
static size_t off_names(const nav_io_writer *w, const nav_io_field *f, char buf[][40], size_t cap) {
  const nav_scene *s = w->scene;
  size_t n = 0;
  if (f->offset == OFF(imu.model)) {
    for (size_t k = 0; k < COUNT(k_imu_terms) && n < cap; ++k) {
      const unsigned bit = k_imu_terms[k].bit;
      const bool g = needs_off(w, &k_gyro_section, s->imu.model.gyro.terms, bit, s->imu.catalog);
      const bool a = bit != NAV_IMU_TERM_G_SENSITIVITY &&
                     needs_off(w, &k_accel_section, s->imu.model.accel.terms, bit, s->imu.catalog);
      if (g && (a || bit == NAV_IMU_TERM_G_SENSITIVITY))
        snprintf(buf[n++], 40, "%s", k_imu_terms[k].name);
      else if (g)
        snprintf(buf[n++], 40, "gyro.%s", k_imu_terms[k].name);
      else if (a)
        snprintf(buf[n++], 40, "accel.%s", k_imu_terms[k].name);
    }
  } else if (f->offset == OFF(array.accel)) {
    for (size_t k = 0; k < COUNT(k_array_terms) && n < cap; ++k)
      if (needs_off(w, &k_array_accel_section, s->array.accel.terms, k_array_terms[k].bit, s->array.catalog))
        snprintf(buf[n++], 40, "%s", k_array_terms[k].name);
  } else {
    for (size_t k = 0; k < COUNT(k_gnss_terms) && n < cap; ++k)
      if (needs_off(w, &k_gnss_section, s->gnss.model.terms, k_gnss_terms[k].bit, s->gnss.catalog))
        snprintf(buf[n++], 40, "%s", k_gnss_terms[k].name);
  }
  return n;
}

static nav_status write_off(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)base;
  (void)indent;
  char names[16][40];
  const size_t n = off_names(w, f, names, COUNT(names));
  nav_status st = nav_io_writef(w, " [");
  for (size_t i = 0; i < n && st == NAV_OK; ++i)
    st = nav_io_writef(w, "%s%s", i ? ", " : "", names[i]);
  return st != NAV_OK ? st : nav_io_writef(w, "]");
}

static bool off_needed(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)base;
  (void)def;
  char names[16][40];
  return off_names(w, f, names, COUNT(names)) > 0;
}

static bool same_terms(const nav_io_field *f, const void *a, const void *b) {
  const nav_scene *sa = a, *sb = b;
  if (f->offset == OFF(imu.model))
    return sa->imu.model.gyro.terms == sb->imu.model.gyro.terms &&
           sa->imu.model.accel.terms == sb->imu.model.accel.terms;
  if (f->offset == OFF(array.accel)) return sa->array.accel.terms == sb->array.accel.terms;
  return sa->gnss.model.terms == sb->gnss.model.terms;
}

/* ---------------------------------------------------------------- GNSS outages, reported sigmas */

/* gnss.outages: [[t0_s, t1_s], ...], at most NAV_GNSS_MAX_OUTAGES, each with t1_s > t0_s. */
static void read_outages(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, void *base) {
  nav_gnss_model_config *m = (nav_gnss_model_config *)((char *)base + f->offset);
  nav_gnss_outage out[NAV_GNSS_MAX_OUTAGES];
  const nav_io_field finite = {.key = f->key, .kind = NAV_IO_DOUBLE, .flags = NAV_IO_FINITE, .scale = 1.0};
  char t0[40], t1[40];
  if (reject_special(r, key, v)) return;
  if (v->kind != Y_SEQ) {
    nav_io_expected(r, key, v, "a list of [t0_s, t1_s] intervals");
    return;
  }
  if (v->count > NAV_GNSS_MAX_OUTAGES) {
    nav_io_reader_error(r, v, key, "at most %d outages are supported (got %zu)", NAV_GNSS_MAX_OUTAGES,
                        v->count);
    return;
  }
  bool ok = true;
  size_t i = 0;
  for (const nav_io_node *item = v->child; item != NULL; item = item->next, ++i) {
    const size_t saved = path_push_index(r, i);
    mark_path(r, item, v);
    double x[2] = {0.0, 0.0};
    if (reject_special(r, v, item)) {
      ok = false;
    } else if (item->kind != Y_SEQ || item->count != 2) {
      nav_io_expected(r, v, item, "[t0_s, t1_s]");
      ok = false;
    } else if (!read_number_items(r, &finite, item, x, 2)) {
      ok = false;
    } else if (!(x[1] > x[0])) {
      const size_t s1 = path_push_index(r, 1);
      nav_io_reader_error(r, item->child->next, item, "the end t1_s = %s must be after the start t0_s = %s",
                          nav_io_format_double(t1, sizeof t1, x[1]),
                          nav_io_format_double(t0, sizeof t0, x[0]));
      path_pop(r, s1);
      ok = false;
    } else {
      out[i].t0_s = x[0];
      out[i].t1_s = x[1];
    }
    path_pop(r, saved);
  }
  if (!ok) return;
  m->outage_count = i;
  for (size_t k = 0; k < i; ++k)
    m->outages[k] = out[k];
}

static nav_status write_outages(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)indent;
  const nav_gnss_model_config *m = (const nav_gnss_model_config *)((const char *)base + f->offset);
  nav_status st = nav_io_writef(w, " [");
  for (size_t i = 0; i < m->outage_count && i < NAV_GNSS_MAX_OUTAGES && st == NAV_OK; ++i) {
    st = nav_io_writef(w, "%s[", i ? ", " : "");
    if (st == NAV_OK) st = nav_io_write_double(w, m->outages[i].t0_s);
    if (st == NAV_OK) st = nav_io_writef(w, ", ");
    if (st == NAV_OK) st = nav_io_write_double(w, m->outages[i].t1_s);
    if (st == NAV_OK) st = nav_io_writef(w, "]");
  }
  return st != NAV_OK ? st : nav_io_writef(w, "]");
}

static bool same_outages(const nav_io_field *f, const void *a, const void *b) {
  const nav_gnss_model_config *ma = (const nav_gnss_model_config *)((const char *)a + f->offset);
  const nav_gnss_model_config *mb = (const nav_gnss_model_config *)((const char *)b + f->offset);
  if (ma->outage_count != mb->outage_count || ma->outage_count > NAV_GNSS_MAX_OUTAGES) return false;
  for (size_t i = 0; i < ma->outage_count; ++i)
    if (!same_bits(ma->outages[i].t0_s, mb->outages[i].t0_s) ||
        !same_bits(ma->outages[i].t1_s, mb->outages[i].t1_s))
      return false;
  return true;
}

/* gnss.reported_sigma: "model" (fixes report the model's sigmas) or {position_m, velocity_mps}. */
static void read_reported(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                          const nav_io_node *v, void *base) {
  nav_gnss_model_config *m = (nav_gnss_model_config *)((char *)base + f->offset);
  if (reject_special(r, key, v)) return;
  if (v->kind == Y_SCALAR && !v->quoted && text_is(v, "model")) {
    m->report_model_sigmas = true;
    return;
  }
  if (v->kind != Y_MAP) {
    nav_io_expected(r, key, v, "\"model\" or {position_m: [N, E, D], velocity_mps: [N, E, D]}");
    return;
  }
  read_section(r, f->section, key, v, base, NULL);
  m->report_model_sigmas = false;
}

static nav_status write_reported(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)indent;
  const nav_gnss_model_config *m = (const nav_gnss_model_config *)((const char *)base + f->offset);
  if (m->report_model_sigmas) return nav_io_writef(w, " model");
  const nav_status st = nav_io_writef(w, " ");
  return st != NAV_OK ? st : nav_io_write_flow(w, f->section, base, w->def);
}

static bool same_reported(const nav_io_field *f, const void *a, const void *b) {
  const nav_gnss_model_config *ma = (const nav_gnss_model_config *)((const char *)a + f->offset);
  const nav_gnss_model_config *mb = (const nav_gnss_model_config *)((const char *)b + f->offset);
  return ma->report_model_sigmas == mb->report_model_sigmas &&
         (ma->report_model_sigmas || nav_io_section_same(f->section, a, b));
}

/* ---------------------------------------------------------------- JSON Schema of the custom values */

static void schema_format_version(nav_io_json *j, const nav_io_field *f) {
  (void)f;
  nav_io_json_key(j, "type");
  nav_io_json_string(j, "integer");
  nav_io_json_key(j, "minimum");
  nav_io_json_number(j, 1);
  nav_io_json_key(j, "maximum");
  nav_io_json_number(j, NAV_SCENE_FORMAT_VERSION);
}

static void schema_catalog(nav_io_json *j, const nav_io_field *f) {
  nav_io_json_key(j, "type");
  nav_io_json_string(j, "string");
  nav_io_json_key(j, "maxLength");
  nav_io_json_number(j, (double)(f->size - 1));
}

/* "off": one term name or a list of them (read_off); IMU names may carry "gyro." / "accel.". */
static void schema_off(nav_io_json *j, const nav_io_field *f) {
  const bool imu = f->offset == OFF(imu.model);
  const bool arr = f->offset == OFF(array.accel);
  const term_name *terms = imu ? k_imu_terms : arr ? k_array_terms : k_gnss_terms;
  const size_t nterms = imu ? COUNT(k_imu_terms) : arr ? COUNT(k_array_terms) : COUNT(k_gnss_terms);
  char names[1024], pattern[512];
  size_t ln = 0, lp = 0;
  const char *prefixes[3] = {"", "gyro.", "accel."};
  for (size_t p = 0; p < (imu ? 3u : 1u); ++p)
    for (size_t k = 0; k < nterms; ++k) {
      const int m =
          snprintf(names + ln, sizeof names - ln, "%s\"%s%s\"", ln ? ", " : "", prefixes[p], terms[k].name);
      if (m > 0 && (size_t)m < sizeof names - ln) ln += (size_t)m;
    }
  lp = (size_t)snprintf(pattern, sizeof pattern, "^%s(", imu ? "((gyro|accel)\\.)?" : "");
  for (size_t k = 0; k < nterms && lp < sizeof pattern; ++k) {
    const int m = snprintf(pattern + lp, sizeof pattern - lp, "%s%s", k ? "|" : "", terms[k].name);
    if (m > 0 && (size_t)m < sizeof pattern - lp) lp += (size_t)m;
  }
  if (lp < sizeof pattern) snprintf(pattern + lp, sizeof pattern - lp, ")$");
  char items[1200];
  snprintf(items, sizeof items, "{\"type\": \"string\", \"enum\": [%s]}", names);
  nav_io_json_key(j, "type");
  nav_io_json_raw(j, "[\"array\", \"string\", \"null\"]");
  nav_io_json_key(j, "items");
  nav_io_json_raw(j, items);
  nav_io_json_key(j, "pattern");
  nav_io_json_string(j, pattern);
}

static void schema_outages(nav_io_json *j, const nav_io_field *f) {
  (void)f;
  nav_io_json_key(j, "type");
  nav_io_json_string(j, "array");
  nav_io_json_key(j, "items");
  nav_io_json_raw(
      j, "{\"type\": \"array\", \"items\": {\"type\": \"number\"}, \"minItems\": 2, \"maxItems\": 2}");
}

/* reported_sigma: "model", or the mapping of k_reported_section (the object keywords apply to the
   mapping form only). */
static void schema_reported(nav_io_json *j, const nav_io_field *f) {
  nav_io_json_key(j, "type");
  nav_io_json_raw(j, "[\"string\", \"object\"]");
  nav_io_json_key(j, "pattern");
  nav_io_json_string(j, "^model$");
  nav_io_json_section_members(j, f->section, NULL);
}

static bool gnss_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w;
  const nav_scene *s = base;
  return s->gnss.enabled || s->gnss.constellation.enabled || !nav_io_section_same(f->section, base, def);
}

/* ---------------------------------------------------------------- accelerometer array */

/* array.sensors: [{position_m: [x, y, z], axis: [x, y, z]}, ...], at most 16. */
static void read_array_sensors(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                               const nav_io_node *v, void *base) {
  nav_scene_array *a = (nav_scene_array *)((char *)base + f->offset);
  if (reject_special(r, key, v)) return;
  if (v->kind != Y_SEQ) {
    nav_io_expected(r, key, v, "a list of sensors (- {position_m: [x, y, z], axis: [x, y, z]})");
    return;
  }
  if (v->count > NAV_SCENE_ARRAY_MAX_SENSORS) {
    nav_io_reader_error(r, v, key, "at most %d accelerometers are supported (got %zu)",
                        NAV_SCENE_ARRAY_MAX_SENSORS, v->count);
    return;
  }
  a->custom_count = (int)v->count;
  size_t i = 0;
  for (const nav_io_node *item = v->child; item != NULL; item = item->next, ++i) {
    const size_t saved = path_push_index(r, i);
    mark_path(r, item, v);
    if (reject_special(r, v, item)) {
      /* reported */
    } else if (item->kind != Y_MAP) {
      nav_io_expected(r, v, item, "a sensor {position_m: [x, y, z], axis: [x, y, z]}");
    } else {
      nav_io_read_section(r, &k_array_sensor_section, v, item, &a->custom[i]);
    }
    path_pop(r, saved);
  }
}

static nav_status write_array_sensors(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  const nav_scene_array *a = (const nav_scene_array *)((const char *)base + f->offset);
  static const nav_scene_array_sensor zero; /* every key is written: the defaults do not matter */
  if (a->custom_count <= 0) return nav_io_writef(w, " []");
  nav_status st = NAV_OK;
  for (int i = 0; i < a->custom_count && i < NAV_SCENE_ARRAY_MAX_SENSORS && st == NAV_OK; ++i) {
    st = nav_io_writef(w, "\n%*s- ", indent + 2, "");
    if (st == NAV_OK) st = nav_io_write_flow(w, &k_array_sensor_section, &a->custom[i], &zero);
  }
  return st;
}

static bool same_array_sensors(const nav_io_field *f, const void *a, const void *b) {
  const nav_scene_array *A = (const nav_scene_array *)((const char *)a + f->offset);
  const nav_scene_array *B = (const nav_scene_array *)((const char *)b + f->offset);
  if (A->custom_count != B->custom_count) return false;
  for (int i = 0; i < A->custom_count && i < NAV_SCENE_ARRAY_MAX_SENSORS; ++i)
    if (!nav_io_section_same(&k_array_sensor_section, &A->custom[i], &B->custom[i])) return false;
  return true;
}

static bool array_sensors_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                  const void *def) {
  (void)w;
  return !same_array_sensors(f, base, def);
}

/* The array section: for the gyro-free scheme, or when it differs from the defaults. */
static bool array_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w;
  const nav_scene *s = base;
  return s->navigation.scheme == NAV_SCHEME_GYRO_FREE || s->navigation.scheme == NAV_SCHEME_GYRO_FREE_GNSS ||
         !nav_io_section_same(f->section, base, def);
}

/* ---------------------------------------------------------------- bias instability -> GM */

/* Whether a problem was reported about @p path or a field inside it. */
static bool had_error(const nav_io_reader *r, const char *path) {
  for (int i = 0; i < r->nerr_paths; ++i)
    if (path_related(r->err_paths[i], path)) return true;
  return false;
}

/*
 * After imu.gyro / imu.accel: bias_instability_* with bias_instability_tau_min_s define the
 * first-order GM bias (nav_gm_from_bias_instability, numerics.md 2.3) under imu.bias_convention;
 * they exclude bias_gm_sigma_* / bias_gm_tau_s, which state the GM directly.
 */
static void finish_triad(nav_io_reader *r, const nav_io_node *map, nav_scene *s, int t) {
  const char *const b_keys[2][2] = {{"bias_instability_deg_per_h", "bias_instability_rps"},
                                    {"bias_instability_ug", "bias_instability_mps2"}};
  const char *const gm_keys[2][3] = {{"bias_gm_sigma_deg_per_h", "bias_gm_sigma_rps", "bias_gm_tau_s"},
                                     {"bias_gm_sigma_ug", "bias_gm_sigma_mps2", "bias_gm_tau_s"}};
  const nav_io_node *kb = NULL, *kt = NULL, *kg = NULL, *k = NULL;
  char path[PATH_MAX_LEN];
  if (map == NULL || map->kind != Y_MAP) return;
  for (int i = 0; i < 2 && kb == NULL; ++i)
    if (nav_io_map_get(map, b_keys[t][i], &k) != NULL) kb = k;
  if (nav_io_map_get(map, "bias_instability_tau_min_s", &k) != NULL) kt = k;
  for (int i = 0; i < 3 && kg == NULL; ++i)
    if (nav_io_map_get(map, gm_keys[t][i], &k) != NULL) kg = k;
  if (kb == NULL && kt == NULL) return;
  const nav_io_node *at = kb != NULL ? kb : kt;
  const size_t saved = path_push_key(r, at->text, at->len);
  if (kb == NULL || kt == NULL) {
    if (kb != NULL)
      nav_io_reader_error(
          r, kb, NULL,
          "needs bias_instability_tau_min_s too: the averaging time at which the Allan deviation "
          "has its minimum (datasheet, or 100-1000 s for MEMS)");
    else
      nav_io_reader_error(r, kt, NULL, "needs %s (or %s) too: the bias instability itself", b_keys[t][0],
                          b_keys[t][1]);
  } else if (kg != NULL) {
    path_pop(r, saved);
    path_push_key(r, kg->text, kg->len);
    nav_io_reader_error(
        r, kg, NULL,
        "the Gauss-Markov bias is given twice: use either %s with bias_instability_tau_min_s, or "
        "bias_gm_sigma_* with bias_gm_tau_s",
        b_keys[t][0]);
  } else {
    /* A value the reader rejected stays 0: the other messages already say what is wrong. */
    const bool bad_b = had_error(r, r->path);
    path_pop(r, saved);
    path_push_key(r, kt->text, kt->len);
    snprintf(path, sizeof path, "%s", r->path);
    path_pop(r, saved);
    if (!bad_b && !had_error(r, path)) {
      const nav_bi_convention conv = (nav_bi_convention)r->state.bias_convention;
      double sd[3], tau[3];
      for (int i = 0; i < 3; ++i) {
        const nav_gm_params gm = nav_gm_from_bias_instability(
            nav_vec3_get(r->state.bi[t], i), nav_vec3_get(r->state.bi_tau_min_s[t], i), conv);
        sd[i] = gm.sigma;
        tau[i] = gm.tau_s;
      }
      if (t == 0) {
        s->imu.model.gyro.bias_gm_sd_rps = nav_vec3_make(sd[0], sd[1], sd[2]);
        s->imu.model.gyro.bias_gm_tau_s = nav_vec3_make(tau[0], tau[1], tau[2]);
        s->imu.model.gyro.terms |= NAV_IMU_TERM_BIAS_GM;
      } else {
        s->imu.model.accel.bias_gm_sd_mps2 = nav_vec3_make(sd[0], sd[1], sd[2]);
        s->imu.model.accel.bias_gm_tau_s = nav_vec3_make(tau[0], tau[1], tau[2]);
        s->imu.model.accel.terms |= NAV_IMU_TERM_BIAS_GM;
      }
    }
    return;
  }
  path_pop(r, saved);
}

static void finish_gyro(nav_io_reader *r, const nav_io_node *map, void *base) {
  finish_triad(r, map, base, 0);
}

static void finish_accel(nav_io_reader *r, const nav_io_node *map, void *base) {
  finish_triad(r, map, base, 1);
}

/*
 * After initial_errors: the tilt (about north and east) within NAV_SCENE_MAX_INITIAL_TILT_SD_DEG,
 * reported at the component (a list item) or at the single number given for all three axes.
 */
static void finish_initial_errors(nav_io_reader *r, const nav_io_node *map, void *base) {
  const nav_scene *s = base;
  const nav_io_node *k = NULL, *v = NULL;
  bool deg = true;
  if (map == NULL || map->kind != Y_MAP) return;
  v = nav_io_map_get(map, "attitude_deg", &k);
  if (v == NULL) {
    v = nav_io_map_get(map, "attitude_rad", &k);
    deg = false;
  }
  if (v == NULL) return;
  const size_t saved = path_push_key(r, k->text, k->len);
  if (had_error(r, r->path)) { /* rejected values keep their default: already reported */
    path_pop(r, saved);
    return;
  }
  /* The tilt bounds of the table (k_att_sd_max_*: N and E), compared in SI. */
  const double *max_deg = k_initial_errors[2].max_axis;
  const nav_io_node *item = v->kind == Y_SEQ ? v->child : NULL;
  for (int i = 0; i < 2; ++i) {
    const double a = nav_vec3_get(s->initial_errors.att_sd_rad, i);
    const double bound_rad = max_deg[i] * NAV_DEG2RAD;
    if (a > bound_rad) {
      const size_t saved_i = item != NULL ? path_push_index(r, (size_t)i) : r->path_len;
      const nav_io_node *at = item != NULL ? item : v;
      char shown[SHOW_MAX + 4];
      show(shown, sizeof shown, at->text != NULL ? at->text : "", at->text != NULL ? at->len : 0);
      nav_io_reader_error(
          r, at, v,
          "the tilt about %s must be <= %.9g %s (got %s): levelling from the accelerometers "
          "gives roll and pitch to within 90 deg; only the heading (about D) may be unknown, up "
          "to 180 deg",
          i == 0 ? "north" : "east", deg ? max_deg[i] : bound_rad, deg ? "deg" : "rad", shown);
      path_pop(r, saved_i);
      if (item == NULL) break; /* one number for all three axes: one message */
    }
    if (item != NULL) item = item->next;
  }
  path_pop(r, saved);
}

/* ================================================================ validation and entry points */

static void on_validate_issue(void *user, const char *path, const char *message) {
  nav_io_reader *r = user;
  if (path == NULL) path = "";
  /* A field the reader rejected keeps its default, so validation would only repeat the problem. */
  for (int i = 0; i < r->nerr_paths; ++i)
    if (path_related(r->err_paths[i], path)) return;
  int line = 0, col = 0;
  if (!find_mark(r, path, &line, &col) && message != NULL) {
    /* The field keeps a default the file does not spell out: point at another field the
       message names ("must not exceed imu.rate_hz"), else at the top of the document. */
    for (const char *p = message; *p && line == 0; ++p) {
      if (!(*p >= 'a' && *p <= 'z') || (p > message && p[-1] != ' ' && p[-1] != '(')) continue;
      char tok[PATH_MAX_LEN];
      size_t n = 0;
      while (n + 1 < sizeof tok && ((p[n] >= 'a' && p[n] <= 'z') || (p[n] >= '0' && p[n] <= '9') ||
                                    p[n] == '_' || p[n] == '.'))
        ++n;
      while (n > 0 && p[n - 1] == '.') --n;
      memcpy(tok, p, n);
      tok[n] = '\0';
      if (strchr(tok, '.') != NULL) find_mark(r, tok, &line, &col);
    }
    if (line == 0 && !find_mark(r, "format_version", &line, &col)) line = col = 1;
  }
  emit(r, line, col, path, message != NULL ? message : "invalid value");
}

static nav_status read_buffer(const char *text, size_t len, const char *name, bool name_is_path,
                              nav_scene *out, nav_diag_fn report, void *user, bool to_run) {
  nav_status st = NAV_OK;
  nav_io_reader *r = NULL;
  nav_io_node *root = NULL;
  nav_io_c_locale loc;
  nav_scene *scene = NULL;

  r = calloc(1, sizeof *r);
  scene = malloc(sizeof *scene);
  if (r == NULL || scene == NULL) {
    free(r);
    free(scene);
    return NAV_ERR_NO_MEMORY;
  }
  *scene = nav_scene_default();
  r->file = name;
  r->report = report;
  r->user = user;
  r->state.scene = scene;
  r->state.file = name;
  r->state.file_is_path = name_is_path;
  r->state.bias_convention = NAV_BI_ALLAN_PEAK;
  r->state.md_allow_unconverged = true;
  r->state.md_fit_rate_ramps = true;
  r->state.duration_auto = true;
  nav_io_c_locale_begin(&loc);

  if (len > NAV_IO_MAX_INPUT_BYTES) {
    emitf(r, 0, 0, "", "the input is too large (%zu bytes); scene files are limited to %zu bytes (16 MiB)",
          len, NAV_IO_MAX_INPUT_BYTES);
    goto cleanup;
  }
  if (!check_text(r, (const unsigned char *)text, len)) goto cleanup;
  if (len > 0 && !build_tree(r, text, len, &root)) goto cleanup;
  if (root == NULL || is_null(root)) { /* nothing, or only "---" / "~" */
    emitf(r, 1, 1, "", "the file is empty; a scene needs at least \"format_version: %d\"",
          NAV_SCENE_FORMAT_VERSION);
    goto cleanup;
  }
  read_root(r, root, scene);
  if (r->newer_format || r->oom || root->kind != Y_MAP) goto cleanup;
  /* Whatever needs the whole file: geodetic waypoints, motion-definition imports, script lengths. */
  if (!r->stop) nav_io_traj_finish(r, root, scene);
  if (!r->stop) nav_io_gnss_file_finish(r, scene);
  if (r->oom || r->stop) goto cleanup;

  /* Cross-field and domain checks shared with the editor; their paths are placed in the file. */
  const int before = r->ndiag;
  const nav_status vs = nav_scene_validate(scene, on_validate_issue, r);
  if (vs != NAV_OK && r->ndiag == before && r->nerr_paths == 0)
    emitf(r, 0, 0, "", "the scene is not valid (%s)", nav_status_str(vs));
  /* Requirements the run could not evaluate (an at_time after its end, an outage_end without an
   * outage), for a scene about to be simulated (nav_scene_read_file_to_run). Only with a
   * trajectory: without one the file is the filter configuration of navsim replay, whose
   * requirements apply to recorded data (its span and gaps). */
  if (to_run && vs == NAV_OK && nav_io_map_get(root, "trajectory", NULL) != NULL &&
      nav_requirements_check_scene(scene, on_validate_issue, r) != NAV_OK && r->ndiag == before)
    emitf(r, 0, 0, "", "the scene's requirements cannot be evaluated on its run");

cleanup:
  nav_io_c_locale_end(&loc);
  arena_free(r);
  free(r->marks);
  free(r->state.geo);
  if (r->oom)
    st = NAV_ERR_NO_MEMORY;
  else if (r->ndiag > 0)
    st = NAV_ERR_PARSE;
  else
    *out = *scene; /* out takes over the heap data (the recorded control points) */
  if (st != NAV_OK) nav_scene_release(scene);
  free(r);
  free(scene);
  return st;
}

nav_status nav_scene_read_string(const char *text, size_t len, const char *display_name, nav_scene *out,
                                 nav_diag_fn report, void *user) {
  if (out == NULL || (text == NULL && len > 0)) return NAV_ERR_INVALID_ARG;
  return read_buffer(text != NULL ? text : "", len, display_name != NULL ? display_name : "<string>", false,
                     out, report, user, false);
}

static void report_file_problem(const char *path, nav_diag_fn report, void *user, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
static void report_file_problem(const char *path, nav_diag_fn report, void *user, const char *fmt, ...) {
  nav_diag d;
  memset(&d, 0, sizeof d);
  snprintf(d.file, sizeof d.file, "%s", path);
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(d.message, sizeof d.message, fmt, ap);
  va_end(ap);
  if (report != NULL) report(user, &d);
}

static nav_status read_file(const char *path, nav_scene *out, nav_diag_fn report, void *user, bool to_run) {
  nav_status st = NAV_OK;
  FILE *fp = NULL;
  char *buf = NULL;
  char why[256];
  size_t len = 0, cap = 0;

  if (path == NULL || out == NULL) return NAV_ERR_INVALID_ARG;
  /* A FIFO, device or directory is refused at once (no blocking open, no endless read). */
  st = nav_io_fopen_regular(path, &fp, why, sizeof why);
  if (st != NAV_OK) {
    report_file_problem(path, report, user, "%s", why);
    goto cleanup;
  }
  struct stat sb;
  if (fstat(fileno(fp), &sb) == 0) {
    if (S_ISREG(sb.st_mode) && (uintmax_t)sb.st_size > NAV_IO_MAX_INPUT_BYTES) {
      report_file_problem(path, report, user,
                          "the file is too large (%jd bytes); scene files are limited to %zu bytes (16 MiB)",
                          (intmax_t)sb.st_size, NAV_IO_MAX_INPUT_BYTES);
      st = NAV_ERR_PARSE;
      goto cleanup;
    }
    if (S_ISREG(sb.st_mode)) cap = (size_t)sb.st_size + 1;
  }
  if (cap < 4096) cap = 4096;
  buf = malloc(cap);
  if (buf == NULL) {
    st = NAV_ERR_NO_MEMORY;
    goto cleanup;
  }
  /* Read to the end even for pipes and files that grow, but never beyond the cap. */
  for (;;) {
    if (len == cap) {
      if (cap > NAV_IO_MAX_INPUT_BYTES) {
        report_file_problem(path, report, user,
                            "the file is too large; scene files are limited to %zu bytes (16 MiB)",
                            NAV_IO_MAX_INPUT_BYTES);
        st = NAV_ERR_PARSE;
        goto cleanup;
      }
      size_t next = cap * 2;
      if (next > NAV_IO_MAX_INPUT_BYTES + 1) next = NAV_IO_MAX_INPUT_BYTES + 1;
      char *grown = realloc(buf, next);
      if (grown == NULL) {
        st = NAV_ERR_NO_MEMORY;
        goto cleanup;
      }
      buf = grown;
      cap = next;
    }
    const size_t got = fread(buf + len, 1, cap - len, fp);
    len += got;
    if (got == 0) break;
  }
  if (ferror(fp)) {
    const int err = errno;
    if (strerror_r(err, why, sizeof why) != 0) snprintf(why, sizeof why, "error %d", err);
    report_file_problem(path, report, user, "cannot read the file: %s", why);
    st = NAV_ERR_IO;
    goto cleanup;
  }
  st = read_buffer(buf, len, path, true, out, report, user, to_run);

cleanup:
  free(buf);
  if (fp != NULL) fclose(fp);
  return st;
}

nav_status nav_scene_read_file(const char *path, nav_scene *out, nav_diag_fn report, void *user) {
  return read_file(path, out, report, user, false);
}

nav_status nav_scene_read_file_to_run(const char *path, nav_scene *out, nav_diag_fn report, void *user) {
  return read_file(path, out, report, user, true);
}

/* ---------------------------------------------------------------- requirements */

static void read_requirements(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                              const nav_io_node *v, void *base) {
  (void)f;
  nav_scene *s = base;
  if (reject_special(r, key, v)) return;
  if (v->kind != Y_SEQ) {
    nav_io_expected(r, key, v,
                    "a list of requirements (- {id, metric, statistic, limit, unit, time_s for at_time})");
    return;
  }
  if (v->count > NAV_SCENE_MAX_REQUIREMENTS) {
    nav_io_reader_error(r, v, key, "at most %d requirements are supported (got %zu)", NAV_SCENE_MAX_REQUIREMENTS,
                        v->count);
    return;
  }
  s->n_requirements = (int)v->count;
  size_t i = 0;
  for (const nav_io_node *item = v->child; item != NULL; item = item->next, ++i) {
    const size_t saved = path_push_index(r, i);
    mark_path(r, item, v);
    memset(&s->requirements[i], 0, sizeof s->requirements[i]);
    if (reject_special(r, v, item)) {
      /* reported */
    } else if (item->kind != Y_MAP) {
      nav_io_expected(r, v, item, "a requirement {id, metric, statistic, limit, unit}");
    } else {
      nav_requirement *q = &s->requirements[i];
      q->time_s = NAN; /* at_time without time_s is reported by nav_requirements_validate */
      nav_io_read_section(r, &k_requirement_section, v, item, q);
      const nav_io_node *tk = NULL;
      const nav_io_node *tv = nav_io_map_get(item, "time_s", &tk);
      if (tv != NULL && q->statistic != NAV_REQ_AT_TIME) {
        const size_t s1 = nav_io_path_push_key(r, "time_s");
        nav_io_reader_error(r, tk, item, "applies to statistic at_time only (this requirement's statistic is %s)",
                            nav_req_statistic_name(q->statistic));
        path_pop(r, s1);
      }
    }
    path_pop(r, saved);
  }
}

static nav_status write_requirements(nav_io_writer *w, const nav_io_field *f, const void *base, int indent) {
  (void)f;
  const nav_scene *s = base;
  static const nav_requirement zero; /* every key but time_s is written */
  if (s->n_requirements <= 0) return nav_io_writef(w, " []");
  nav_status st = NAV_OK;
  for (int i = 0; i < s->n_requirements && i < NAV_SCENE_MAX_REQUIREMENTS && st == NAV_OK; ++i) {
    st = nav_io_writef(w, "\n%*s- ", indent + 2, "");
    if (st == NAV_OK) st = nav_io_write_flow(w, &k_requirement_section, &s->requirements[i], &zero);
  }
  return st;
}

static bool same_requirements(const nav_io_field *f, const void *a, const void *b) {
  (void)f;
  const nav_scene *A = a, *B = b;
  if (A->n_requirements != B->n_requirements) return false;
  for (int i = 0; i < A->n_requirements && i < NAV_SCENE_MAX_REQUIREMENTS; ++i)
    if (!nav_io_section_same(&k_requirement_section, &A->requirements[i], &B->requirements[i])) return false;
  return true;
}

static bool requirements_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                 const void *def) {
  (void)w;
  (void)def;
  (void)f;
  return ((const nav_scene *)base)->n_requirements > 0;
}

/* time_s: for at_time only (the reader refuses it elsewhere). */
static bool req_time_written(const nav_io_writer *w, const nav_io_field *f, const void *base, const void *def) {
  (void)w;
  (void)f;
  (void)def;
  return ((const nav_requirement *)base)->statistic == NAV_REQ_AT_TIME;
}
