/**
 * @file scene_io_internal.h
 * @brief Private to navcore_io: the table-driven schema of scene files, shared by the reader
 *        (scene_read.c), the writer (scene_write.c) and the trajectory part of the schema
 *        (scene_traj_io.c), plus the limits that guard the reader.
 *
 * Each YAML mapping of the scene file is a nav_io_section: a table of nav_io_field descriptors
 * (key, kind, offset, unit scale, range). The reader walks the YAML tree against these tables;
 * the writer walks the same tables, so a field added here is read, checked, reported with its
 * path and written without further code.
 *
 * Offsets are relative to a base object: the nav_scene for the sections of the scene itself, one
 * list element (nav_waypoint, nav_segment) for the sections that describe list elements, or the
 * reader's nav_io_read_state for NAV_IO_STATE fields, which are inputs that have no place in the
 * scene (bias instability + Allan minimum, the motion-definition file, waypoints given as
 * latitude/longitude): they are combined or converted after their section (nav_io_section.finish)
 * or after the whole file, and never written.
 *
 * Adding a field: append a descriptor to its section (write order = table order). Adding a
 * section: define its table and add a NAV_IO_SECTION descriptor to the parent. A quantity that
 * may be given in several units (lat_deg / lat_rad) is described by one descriptor per unit with
 * the same offset; the first one is the preferred spelling, the others carry NAV_IO_ALT. Giving
 * two spellings of one quantity in a file is an error. The writer writes the shortest exact
 * spelling among the preferred one, the SI one (scale 1) and those flagged NAV_IO_WRITE_ALT.
 * Anything that does not fit a plain kind (lists, kind-dependent mappings, catalog look-ups)
 * uses NAV_IO_CUSTOM with its own read and write functions.
 *
 * Error-model terms: a descriptor with a non-zero @c bit sets that bit in the unsigned at
 * @c bits_offset when its key is read (a term is on when one of its keys is present); the writer
 * writes it when the bit is set or its value differs from the default.
 */
#ifndef NAV_SCENE_IO_INTERNAL_H
#define NAV_SCENE_IO_INTERNAL_H

#include <locale.h> /* locale_t: includers define _POSIX_C_SOURCE 200809L */
#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "navcore/nav_io.h"
#include "navcore/nav_scene.h"

/** Largest scene file (or string) the reader accepts [bytes]: 16 MiB. */
#define NAV_IO_MAX_INPUT_BYTES ((size_t)16 * 1024 * 1024)
/** Deepest YAML nesting the reader accepts (the v1 schema needs 7: trajectory.waypoints.points[i].attitude).
 */
#define NAV_IO_MAX_DEPTH 64
/** Most YAML nodes (scalars, sequences, mappings) the reader builds from one file. */
#define NAV_IO_MAX_NODES 1000000
/** Longest file name inside a scene (trajectory.motion_def.file) [bytes, with the NUL]. */
#define NAV_IO_PATH_MAX 1024

/** trajectory.type "motion_def": only while reading; the import turns it into NAV_TRAJ_SEGMENTS. */
#define NAV_IO_TRAJ_MOTION_DEF 1000

/** What a descriptor describes. */
typedef enum nav_io_kind {
  NAV_IO_SECTION,      /**< a nested mapping described by nav_io_field.section */
  NAV_IO_DOUBLE,       /**< double; file value * scale = SI value */
  NAV_IO_VEC3,         /**< nav_vec3 written as a sequence of exactly 3 numbers; each * scale */
  NAV_IO_VEC3S,        /**< nav_vec3: 3 numbers, or one number for all three axes */
  NAV_IO_MAT3_OFFDIAG, /**< nav_mat3: one number for every off-diagonal element, or 3 rows of 3 */
  NAV_IO_MAT3_DIAG,    /**< nav_mat3: one number or 3 numbers for the diagonal, or 3 rows of 3 */
  NAV_IO_INT,          /**< int */
  NAV_IO_LONG,         /**< long */
  NAV_IO_U64,          /**< uint64_t in [0, 2^64 - 1] */
  NAV_IO_BOOL,         /**< bool: true or false */
  NAV_IO_ENUM,         /**< an enum stored as int; names in nav_io_field.enums */
  NAV_IO_STRING,       /**< char[size], NUL-terminated; control characters rejected */
  NAV_IO_CUSTOM        /**< read/write through nav_io_field.read / .write */
} nav_io_kind;

/** Descriptor flags. */
enum {
  NAV_IO_FINITE = 1u << 0,     /**< reject .inf / .nan */
  NAV_IO_MIN_GT = 1u << 1,     /**< value > min (file units) */
  NAV_IO_MIN_GE = 1u << 2,     /**< value >= min */
  NAV_IO_MAX_LE = 1u << 3,     /**< value <= max */
  NAV_IO_REQUIRED = 1u << 4,   /**< the key must be present */
  NAV_IO_ALT = 1u << 5,        /**< alternative unit spelling of the preceding quantity */
  NAV_IO_FLOW = 1u << 6,       /**< SECTION written on one line: {a: 1, b: 2} */
  NAV_IO_STATE = 1u << 7,      /**< offset into nav_io_read_state; read only, never written */
  NAV_IO_EARLY = 1u << 8,      /**< read before the other keys of its mapping, wherever it is */
  NAV_IO_LATE = 1u << 9,       /**< read after the other keys of its mapping, wherever it is */
  NAV_IO_WRITE_ALT = 1u << 10, /**< an ALT spelling the writer may choose when it is shorter */
  /** The range (min/max, max_axis) is checked on the SI value after reading, by nav_scene_validate
      or a section's finish function, with its own message; the reader's number check applies only
      NAV_IO_FINITE. The table still states the range: the schema publishes it and
      test_scene_schema checks that it is the range enforced. */
  NAV_IO_RANGE_LATER = 1u << 11
};

typedef struct nav_io_enum_value {
  const char *name;
  int value;
} nav_io_enum_value;

typedef struct nav_io_field nav_io_field;
typedef struct nav_io_reader nav_io_reader; /**< reader state (scene_read.c) */
typedef struct nav_io_node nav_io_node;     /**< one node of the parsed YAML tree */
typedef struct nav_io_writer nav_io_writer; /**< writer state (scene_write.c) */

/** Reads @p value (given under @p key) into @p base, reporting through nav_io_reader_error. */
typedef void (*nav_io_read_fn)(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                               const nav_io_node *value, void *base);
/**
 * Writes what follows "key:" for @p f of @p base (a leading space and the value, or a newline and
 * indented lines for block lists; no final newline). @p indent is the indentation of the key.
 */
typedef nav_status (*nav_io_write_fn)(nav_io_writer *w, const nav_io_field *f, const void *base, int indent);
/** Writer: whether @p f of @p base is written (@p def is the default object of the same type). */
typedef bool (*nav_io_write_if_fn)(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                   const void *def);
/** Whether the values of a CUSTOM field are identical (bit for bit) in @p a and @p b. */
typedef bool (*nav_io_same_fn)(const nav_io_field *f, const void *a, const void *b);
/** Called after all keys of a section's mapping @p map were read into @p base. */
typedef void (*nav_io_finish_fn)(nav_io_reader *r, const nav_io_node *map, void *base);

/** JSON Schema writer state (scene_schema.c). */
typedef struct nav_io_json nav_io_json;
/** Writes the JSON Schema of the value of CUSTOM field @p f (one schema object). */
typedef void (*nav_io_schema_fn)(nav_io_json *j, const nav_io_field *f);

/**
 * A mapping whose keys depend on its "kind" (trajectory.segments.items[], trajectory.test_motion):
 * one section per kind value, each starting with the kind descriptor itself, so unknown keys are
 * matched against that kind's keys only.
 */
typedef struct nav_io_kinded {
  const nav_io_enum_value *kinds;
  const struct nav_io_section *const *sections; /**< indexed by kind value */
  size_t nsections;
  size_t kind_offset; /**< of the int kind in the base object */
} nav_io_kinded;

typedef struct nav_io_section {
  const nav_io_field *fields;
  size_t count;
  nav_io_finish_fn finish; /**< may be NULL */
} nav_io_section;

struct nav_io_field {
  const char *key; /**< key in the file, unit suffix included */
  nav_io_kind kind;
  unsigned flags;                 /**< NAV_IO_* */
  size_t offset;                  /**< offset into the base object; unused for SECTION */
  size_t size;                    /**< STRING: buffer size */
  double scale;                   /**< DOUBLE/VEC3/MAT3: SI = file value * scale */
  double min, max;                /**< range in file units, per NAV_IO_MIN_* / NAV_IO_MAX_LE */
  const nav_io_section *section;  /**< SECTION */
  const nav_io_enum_value *enums; /**< ENUM, terminated by a NULL name */
  nav_io_read_fn read;            /**< CUSTOM */
  nav_io_write_fn write;          /**< CUSTOM (NULL: never written) */
  nav_io_same_fn same;            /**< CUSTOM: comparison for "is it the default" (NULL: never equal) */
  nav_io_write_if_fn write_if;    /**< NULL: written unless the term rule below says otherwise */
  unsigned bit;                   /**< term bit set when the key is read (0: none) */
  size_t bits_offset;             /**< offset of the unsigned term mask in the base object */
  const char *mark_as;            /**< also locate the value under this key (the SI field name used
                                       by the validators), may be NULL */
  const char *comment;            /**< written after the value, may be NULL */
  /* Schema only (scene_schema.c: navsim schema, nav_schema_keys); the reader and writer ignore these. */
  const char *doc;             /**< one-line description (NULL: .comment, else none) */
  const char *unit;            /**< unit as written in the file (NULL: from the key's suffix) */
  const nav_io_section *items; /**< CUSTOM: a sequence of mappings of this section */
  const nav_io_kinded *kinded; /**< CUSTOM: a mapping (or, with .items_kinded, a sequence of
                                    mappings) whose keys depend on its kind */
  bool items_kinded;           /**< CUSTOM with .kinded: a sequence of such mappings */
  size_t max_items;            /**< CUSTOM sequences: the most items the reader accepts (0: none) */
  const double *max_axis;      /**< VEC3S: per-axis maxima x, y, z (file units), tighter than .max;
                                    enforced by the section's finish function (NULL: none) */
  nav_io_schema_fn schema;     /**< CUSTOM: JSON Schema of the value (NULL: from the above) */
};

/** The root mapping of a scene file (format_version, name, earth, trajectory, ...). */
extern const nav_io_section nav_io_scene_schema;
/** The trajectory section (scene_traj_io.c). */
extern const nav_io_section nav_io_trajectory_section;
/** gnss.constellation (scene_gnss_sat_io.c) and whether a scene writes it (when enabled). */
extern const nav_io_section nav_io_gnss_constellation_section;
bool nav_io_gnss_constellation_written(const nav_io_writer *w, const nav_io_field *f, const void *base,
                                       const void *def);

/* ================================================================ reader state */

/** One waypoint given as latitude, longitude and height, converted once the Earth is known. */
typedef struct nav_io_geo_point {
  int index;     /**< waypoint index */
  double llh[3]; /**< lat_rad, lon_rad, h_m */
} nav_io_geo_point;

/** Reader inputs that have no place in the scene (NAV_IO_STATE fields and what they lead to). */
typedef struct nav_io_read_state {
  nav_scene *scene;    /**< the scene being read */
  const char *file;    /**< the scene file name as given (relative paths resolve against its directory) */
  bool file_is_path;   /**< @c file is a file path (nav_scene_read_file), not only a display name */
  int bias_convention; /**< imu.bias_convention (nav_bi_convention) */
  nav_vec3 bi[2];      /**< gyro [rad/s] / accel [m/s^2] bias instability B */
  nav_vec3 bi_tau_min_s[2];
  double llh[3];         /**< the waypoint being read: lat_rad, lon_rad, h_m */
  nav_io_geo_point *geo; /**< waypoints given in geodetic coordinates */
  size_t ngeo, cap_geo;
  char md_file[NAV_IO_PATH_MAX]; /**< trajectory.motion_def.file as written */
  bool md_allow_unconverged;
  bool md_fit_rate_ramps;
  bool duration_auto;       /**< trajectory.duration_s absent or "auto" */
  bool duration_auto_given; /**< trajectory.duration_s: auto written in the file */
} nav_io_read_state;

/* ================================================================ reader helpers (scene_read.c) */

/**
 * Report a problem at @p node (falling back to @p fallback when @p node has no position) with
 * the reader's current field path. printf-style.
 */
void nav_io_reader_error(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback,
                         const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;
/** As nav_io_reader_error, at the place where @p path was given (or its nearest given parent). */
void nav_io_reader_error_at_path(nav_io_reader *r, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
/** Pass on a diagnostic about another file (a motion definition, a catalog) as it is. */
void nav_io_reader_forward(nav_io_reader *r, const nav_diag *d);
/* nav_io_reader_forward as a nav_diag_fn (@p user is the nav_io_reader): for the readers of files
   that a scene names (motion definition, recorded reference, GNSS almanac). */
void nav_io_forward_diag(void *user, const nav_diag *d);
/** gnss.file (gnss_file.c): resolve it against the scene file and check its lines. */
void nav_io_gnss_file_finish(nav_io_reader *r, nav_scene *scene);
/* A file named in a scene, relative to the scene file's directory (made absolute when that
   directory exists, so messages name the file unambiguously), or as given when absolute or when
   the scene was read from memory under a name without a directory part (then relative to the
   working directory). @return false when it does not fit in @p size. */
bool nav_io_resolve_path(char *out, size_t size, const char *scene_file, bool is_path, const char *file);
/** Diagnostics reported so far. */
int nav_io_reader_count(const nav_io_reader *r);
/** The reader's state (inputs without a place in the scene). */
nav_io_read_state *nav_io_reader_state(nav_io_reader *r);

/** Field paths: push a key or a [i] index, pop back to the saved length. */
size_t nav_io_path_push_key(nav_io_reader *r, const char *key);
size_t nav_io_path_push_index(nav_io_reader *r, size_t i);
void nav_io_path_pop(nav_io_reader *r, size_t saved);

/** Read the mapping @p map (given under @p key) against @p sec into @p base. */
void nav_io_read_section(nav_io_reader *r, const nav_io_section *sec, const nav_io_node *key,
                         const nav_io_node *map, void *base);
/** Read a number (no range check); false after a reported problem. */
bool nav_io_read_number(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, double *out);
/** Check a number against the range and finiteness flags of @p f (file units). */
bool nav_io_check_number(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                         const nav_io_node *v, double d);
/** Report that @p v (under @p key) is not what @p expected says ("a sequence of waypoints"). */
void nav_io_expected(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v, const char *expected);
/** Aliases and tags are refused; true if @p v was one (and was reported). */
bool nav_io_reject_special(nav_io_reader *r, const nav_io_node *key, const nav_io_node *v);
/** Enum value whose name is the text of @p v; reports "expected one of ... (did you mean ...)". */
bool nav_io_read_enum_value(nav_io_reader *r, const nav_io_enum_value *e, const nav_io_node *key,
                            const nav_io_node *v, int *out);
/** Mark the current path at @p node, for the validators' messages. */
void nav_io_mark(nav_io_reader *r, const nav_io_node *node, const nav_io_node *fallback);

/** Tree access. */
bool nav_io_node_is_map(const nav_io_node *n);
bool nav_io_node_is_seq(const nav_io_node *n);
bool nav_io_node_text_is(const nav_io_node *n, const char *s);
const char *nav_io_node_text(const nav_io_node *n, size_t *len);
size_t nav_io_node_count(const nav_io_node *n);             /**< items of a sequence, keys of a mapping */
const nav_io_node *nav_io_node_child(const nav_io_node *n); /**< first item (in a mapping: the first key) */
const nav_io_node *nav_io_node_next(const nav_io_node *n);  /**< next sibling */
/** The value under @p key in mapping @p map (first occurrence), or NULL; *key_out = its key node. */
const nav_io_node *nav_io_map_get(const nav_io_node *map, const char *key, const nav_io_node **key_out);

/* ================================================================ writer helpers (scene_write.c) */

struct nav_io_writer {
  FILE *fp;
  const nav_scene *scene; /**< the scene being written */
  const nav_scene *def;   /**< nav_scene_default() */
};

/** Each field of @p sec on its own line at @p indent ("key: value"). */
nav_status nav_io_write_block(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def,
                              int indent);
/** As nav_io_write_block, each line preceded (not followed) by its newline: for CUSTOM values. */
nav_status nav_io_write_lines(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def,
                              int indent);
/** @p sec as a flow mapping "{key: value, ...}". */
nav_status nav_io_write_flow(nav_io_writer *w, const nav_io_section *sec, const void *base, const void *def);
/** Whether every field of @p sec is identical in @p a and @p b. */
bool nav_io_section_same(const nav_io_section *sec, const void *a, const void *b);
/** Whether the values of field @p f are identical (bit for bit) in @p a and @p b. */
bool nav_io_field_same(const nav_io_field *f, const void *a, const void *b);
/** A double, shortest text that reads back to the same bits. */
nav_status nav_io_write_double(nav_io_writer *w, double v);
/** A YAML double-quoted string (control characters escaped). */
nav_status nav_io_write_quoted(nav_io_writer *w, const char *s);
/** printf to the writer's file. */
nav_status nav_io_writef(nav_io_writer *w, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* ================================================================ JSON Schema (scene_schema.c) */

/** Append raw JSON text (a whole schema object, e.g. {"type": "string"}) as the current value. */
void nav_io_json_raw(nav_io_json *j, const char *json);
/** Append the schema of a mapping read against @p sec (defaults from @p def, may be NULL). */
void nav_io_json_section(nav_io_json *j, const nav_io_section *sec, const void *def);
/** Into the open object: the keywords of a mapping read against @p sec (properties, required, ...). */
void nav_io_json_section_members(nav_io_json *j, const nav_io_section *sec, const void *def);
/** Begin / end an object value; inside it, nav_io_json_key names the next value. */
void nav_io_json_begin(nav_io_json *j);
void nav_io_json_end(nav_io_json *j);
void nav_io_json_key(nav_io_json *j, const char *key);
/** A JSON string / number value. */
void nav_io_json_string(nav_io_json *j, const char *s);
void nav_io_json_number(nav_io_json *j, double v);

/* ================================================================ trajectory part (scene_traj_io.c) */

/**
 * After the whole file was read: waypoints given in latitude/longitude, the motion-definition
 * import, the script length for duration_s auto and the planner's feasibility check. @p root is
 * the top-level mapping.
 */
void nav_io_traj_finish(nav_io_reader *r, const nav_io_node *root, nav_scene *scene);

/* ================================================================ shared helpers */

/**
 * The C numeric locale for the current thread, whatever the process locale (a Qt application
 * sets LC_NUMERIC from the environment, and "1,5" must never be written or "1.5" misread).
 * uselocale() is per thread, so this does not disturb other threads.
 */
typedef struct nav_io_c_locale {
  locale_t c_loc;
  locale_t old_loc;
} nav_io_c_locale;
void nav_io_c_locale_begin(nav_io_c_locale *s);
void nav_io_c_locale_end(nav_io_c_locale *s);

/**
 * Format @p v with the fewest significant digits (15..17) that read back to the same double;
 * non-finite values as .inf, -.inf, .nan (YAML). Call inside a C-locale scope. @return @p buf.
 */
char *nav_io_format_double(char *buf, size_t size, double v);

#endif /* NAV_SCENE_IO_INTERNAL_H */
