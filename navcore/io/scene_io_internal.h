/**
 * @file scene_io_internal.h
 * @brief Private to navcore_io: the table-driven schema of scene files, shared by the reader
 *        (scene_read.c) and the writer (scene_write.c), plus the limits that guard the reader.
 *
 * Each YAML mapping of the scene file is a nav_io_section: a table of nav_io_field descriptors
 * (key, kind, offset into nav_scene, unit scale, range). The reader walks the YAML tree against
 * these tables; the writer walks the same tables, so a field added here is read, checked,
 * reported with its path and written without further code.
 *
 * Adding a field: append a descriptor to its section (write order = table order). Adding a
 * section: define its table and add a NAV_IO_SECTION descriptor to the parent. A quantity that
 * may be given in several units (lat_deg / lat_rad) is described by one descriptor per unit with
 * the same offset; the first one is the preferred (written) spelling, the others carry
 * NAV_IO_ALT. Giving two spellings of one quantity in a file is an error. Anything that does not
 * fit a plain kind (lists of waypoints, sensor blocks selected by type, ...) uses NAV_IO_CUSTOM
 * with its own read and write functions.
 */
#ifndef NAV_SCENE_IO_INTERNAL_H
#define NAV_SCENE_IO_INTERNAL_H

#include <locale.h> /* locale_t: includers define _POSIX_C_SOURCE 200809L */
#include <stddef.h>
#include <stdio.h>

#include "navcore/nav_io.h"
#include "navcore/nav_scene.h"

/** Largest scene file (or string) the reader accepts [bytes]: 16 MiB. */
#define NAV_IO_MAX_INPUT_BYTES ((size_t)16 * 1024 * 1024)
/** Deepest YAML nesting the reader accepts (the v1 schema needs 4). */
#define NAV_IO_MAX_DEPTH 64
/** Most YAML nodes (scalars, sequences, mappings) the reader builds from one file. */
#define NAV_IO_MAX_NODES 1000000

/** What a descriptor describes. */
typedef enum nav_io_kind {
  NAV_IO_SECTION, /**< a nested mapping described by nav_io_field.section */
  NAV_IO_DOUBLE,  /**< double; file value * scale = SI value */
  NAV_IO_VEC3,    /**< nav_vec3 written as a sequence of exactly 3 numbers; each * scale */
  NAV_IO_INT,     /**< int */
  NAV_IO_LONG,    /**< long */
  NAV_IO_U64,     /**< uint64_t in [0, 2^64 - 1] */
  NAV_IO_ENUM,    /**< an enum stored as int; names in nav_io_field.enums */
  NAV_IO_STRING,  /**< char[size], NUL-terminated; control characters rejected */
  NAV_IO_CUSTOM   /**< read/write through nav_io_field.read / .write */
} nav_io_kind;

/** Descriptor flags. */
enum {
  NAV_IO_FINITE = 1u << 0,   /**< reject .inf / .nan */
  NAV_IO_MIN_GT = 1u << 1,   /**< value > min (file units) */
  NAV_IO_MIN_GE = 1u << 2,   /**< value >= min */
  NAV_IO_MAX_LE = 1u << 3,   /**< value <= max */
  NAV_IO_REQUIRED = 1u << 4, /**< the key must be present */
  NAV_IO_ALT = 1u << 5,      /**< alternative unit spelling of the preceding quantity */
  NAV_IO_FLOW = 1u << 6      /**< SECTION written on one line: {a: 1, b: 2} */
};

typedef struct nav_io_enum_value {
  const char *name;
  int value;
} nav_io_enum_value;

typedef struct nav_io_field nav_io_field;
typedef struct nav_io_reader nav_io_reader; /**< reader state (scene_read.c) */
typedef struct nav_io_node nav_io_node;     /**< one node of the parsed YAML tree */

/** Reads @p value (given under @p key) into @p scene, reporting through nav_io_reader_error. */
typedef void (*nav_io_read_fn)(nav_io_reader *r, const nav_io_field *f, const nav_io_node *key,
                               const nav_io_node *value, nav_scene *scene);
/** Writes the value of @p f (the text after "key: ") to @p fp; returns < 0 on a write error. */
typedef int (*nav_io_write_fn)(FILE *fp, const nav_io_field *f, const nav_scene *scene);

typedef struct nav_io_section {
  const nav_io_field *fields;
  size_t count;
} nav_io_section;

struct nav_io_field {
  const char *key; /**< key in the file, unit suffix included */
  nav_io_kind kind;
  unsigned flags;                 /**< NAV_IO_* */
  size_t offset;                  /**< offsetof(nav_scene, ...); unused for SECTION */
  size_t size;                    /**< STRING: buffer size */
  double scale;                   /**< DOUBLE/VEC3: SI = file value * scale */
  double min, max;                /**< range in file units, per NAV_IO_MIN_* / NAV_IO_MAX_LE */
  const nav_io_section *section;  /**< SECTION */
  const nav_io_enum_value *enums; /**< ENUM, terminated by a NULL name */
  nav_io_read_fn read;            /**< CUSTOM */
  nav_io_write_fn write;          /**< CUSTOM */
  const char *comment;            /**< written after the value, may be NULL */
};

/** The root mapping of a scene file (format_version, name, earth, trajectory, ...). */
extern const nav_io_section nav_io_scene_schema;

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
