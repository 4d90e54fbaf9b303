/**
 * @file nav_schema.h
 * @brief The scene file's schema as data: every key the reader accepts, with its type, unit, scale
 *        to SI, bounds, default and a one-line description, and the same as a JSON Schema.
 *
 * Both views are generated from the one table the reader and the writer walk (navcore_io's
 * nav_io_field descriptors; docs/scene-schema.md), so they cannot disagree with what
 * nav_scene_read_file() accepts: a bound here is the bound the reader enforces, a default here is
 * the value nav_scene_default() holds.
 *
 * Key paths join mapping keys with '.'; the items of a list are "[]" ("requirements[].limit"), and
 * a mapping whose keys depend on its kind names the kind in the brackets
 * ("trajectory.segments.items[circle].radius_m", "trajectory.test_motion[spin].spin_rate_hz").
 *
 * Example (a form field for the gyro angle random walk):
 * @code
 *   nav_schema_key *keys = NULL;
 *   size_t n = 0;
 *   if (nav_schema_keys(&keys, &n) == NAV_OK) {
 *     const nav_schema_key *k = nav_schema_find(keys, n, "imu.gyro.arw_deg_per_sqrt_h");
 *     // k->unit "deg/sqrt(h)", k->scale (deg/sqrt(h) -> rad/sqrt(s)), k->max 100, k->doc ...
 *     free(keys);
 *   }
 * @endcode
 */
#ifndef NAVCORE_NAV_SCHEMA_H
#define NAVCORE_NAV_SCHEMA_H

#include <stdbool.h>
#include <stddef.h>

#include "navcore/nav_status.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Longest key path [bytes, with the NUL]. */
#define NAV_SCHEMA_PATH_MAX 128
/** Longest default text (enum name, string) [bytes, with the NUL]. */
#define NAV_SCHEMA_TEXT_MAX 64
/** Most choices of an enumerated key. */
#define NAV_SCHEMA_MAX_CHOICES 24

/** What a key's value is. */
typedef enum nav_schema_type {
  NAV_SCHEMA_SECTION,     /**< a mapping of further keys (may be empty: all defaults) */
  NAV_SCHEMA_NUMBER,      /**< one number */
  NAV_SCHEMA_VEC3,        /**< exactly three numbers [x, y, z] */
  NAV_SCHEMA_VEC3_SCALAR, /**< three numbers, or one number for all three */
  NAV_SCHEMA_MAT3_OFFDIAG,/**< one number for every off-diagonal element, or 3 rows of 3 */
  NAV_SCHEMA_MAT3_DIAG,   /**< one number or 3 numbers for the diagonal, or 3 rows of 3 */
  NAV_SCHEMA_INTEGER,     /**< an integer */
  NAV_SCHEMA_BOOLEAN,     /**< true or false */
  NAV_SCHEMA_ENUM,        /**< one of the names in choices */
  NAV_SCHEMA_STRING,      /**< text */
  NAV_SCHEMA_LIST,        /**< a sequence (its items' keys follow with "[]" in the path) */
  NAV_SCHEMA_OTHER        /**< a value with its own syntax (see the JSON Schema and doc) */
} nav_schema_type;

/** Bound flags of nav_schema_key.bounds. */
enum {
  NAV_SCHEMA_MIN = 1u << 0,          /**< value >= min */
  NAV_SCHEMA_MIN_EXCLUSIVE = 1u << 1,/**< value > min */
  NAV_SCHEMA_MAX = 1u << 2,          /**< value <= max */
  NAV_SCHEMA_FINITE = 1u << 3,       /**< .inf and .nan are rejected */
  /** The range is checked on the SI value (file value * scale): a value a few ulps past the bound
      may convert to the bound itself. */
  NAV_SCHEMA_CHECKED_IN_SI = 1u << 4
};

/** One key of the scene file. Plain data; every pointer is to static text. */
typedef struct nav_schema_key {
  char path[NAV_SCHEMA_PATH_MAX]; /**< e.g. "imu.gyro.arw_deg_per_sqrt_h" */
  const char *key;                /**< the last component as written ("arw_deg_per_sqrt_h") */
  nav_schema_type type;
  const char *unit;               /**< unit as written in the file ("deg/h", "m", "1"), or NULL */
  double scale;                   /**< SI value = file value * scale (1 for non-numbers) */
  unsigned bounds;                /**< NAV_SCHEMA_MIN / _MIN_EXCLUSIVE / _MAX / _FINITE */
  double min, max;                /**< in the file's unit; per @c bounds (per component for vectors; for
                                       VEC3_SCALAR max is that of the one-number form, see max_axis) */
  double max_axis[3];             /**< vectors: the maximum of each component x, y, z (= max unless the
                                       axes differ, as the tilt and heading sigmas do) */
  bool required;                  /**< the key must be present in its mapping */
  int alt_of;                     /**< index of the preferred spelling of the same quantity, or -1 */
  bool has_default;               /**< the reader has a default (default_value / default_text) */
  double default_value[3];        /**< numbers in the file's unit (VEC3: x, y, z; else [0]); booleans 0/1 */
  char default_text[NAV_SCHEMA_TEXT_MAX]; /**< ENUM / STRING default */
  const char *doc;                /**< one-line description, or "" */
  size_t n_choices;               /**< ENUM: number of names */
  const char *choices[NAV_SCHEMA_MAX_CHOICES]; /**< ENUM: the names */
} nav_schema_key;

/**
 * Every key of the scene file, in the order of the table (sections before their keys).
 * @param[out] keys  malloc'd array; the caller frees it with free()
 * @param[out] count number of keys
 * @return NAV_OK, NAV_ERR_INVALID_ARG (NULL argument), NAV_ERR_NO_MEMORY. Thread-safe.
 */
NAV_API NAV_NODISCARD nav_status nav_schema_keys(nav_schema_key **keys, size_t *count);

/** The key with path @p path in @p keys, or NULL. */
NAV_API const nav_schema_key *nav_schema_find(const nav_schema_key *keys, size_t count, const char *path);

/**
 * The JSON Schema (draft 2020-12) of a scene file as text, with the keywords "x-unit" (the unit as
 * written in the file) and "x-si-scale" (SI value = file value * scale) on numeric keys.
 * @return a malloc'd NUL-terminated string the caller frees with free(), or NULL when out of
 *         memory. Thread-safe.
 */
NAV_API char *nav_schema_json(void);

#ifdef __cplusplus
}
#endif

#endif /* NAVCORE_NAV_SCHEMA_H */
