/**
 * @file nav_scene_override.h
 * @brief navcore_io: scene files with field overrides "PATH=VALUE" (navsim sweep, navsim select).
 *
 * PATH is the field's YAML path in the scene file, keys joined by dots and list items by [i]:
 * "imu.gyro.bias_instability_deg_per_h", "gnss.outages[0].t1_s", "navigation.scheme",
 * "initial_errors.att_sd_deg[2]". The override is applied to the parsed YAML document (a missing
 * key is added, with its parent mappings), which is then read by the one scene reader
 * (nav_scene_read_string), so every unit conversion, catalog look-up and validation is that of
 * a scene file: an override is exactly an edit of the file.
 */
#ifndef NAV_SCENE_OVERRIDE_H
#define NAV_SCENE_OVERRIDE_H

#include <stddef.h>

#include "nav_export.h"
#include "nav_io.h"
#include "nav_scene.h"
#include "nav_status.h"

NAV_BEGIN_DECLS

/** A scene file's YAML document, kept for repeated overrides. Opaque. */
typedef struct nav_scene_doc nav_scene_doc;

/**
 * Parse the YAML of the scene file @p path (not yet read as a scene).
 * @return NAV_OK; NAV_ERR_IO (unreadable); NAV_ERR_PARSE (not YAML with a mapping at the root;
 *         @p msg says why); NAV_ERR_NO_MEMORY; NAV_ERR_INVALID_ARG.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_doc_load(const char *path, nav_scene_doc **out, char *msg,
                                                    size_t msg_size);
/**
 * As nav_scene_doc_load, from scene text in memory (@p len bytes; copied). @p display_name names
 * the file in diagnostics; relative file references then resolve as nav_scene_read_string's do.
 * For editors that check an edit without writing a file.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_doc_load_string(const char *text, size_t len,
                                                           const char *display_name, nav_scene_doc **out,
                                                           char *msg, size_t msg_size);
NAV_API void nav_scene_doc_destroy(nav_scene_doc *doc);

/**
 * Set the field at @p path to the YAML scalar @p value (plain text such as "0.5", "ins_gnss",
 * "ADIS16465-1"). Keys that do not exist are added (mappings created as needed); a list index
 * must exist. Overrides accumulate on the document.
 * @return NAV_OK; NAV_ERR_INVALID_ARG (malformed path, index out of range, a scalar where a
 *         mapping is needed...; @p msg says which part); NAV_ERR_NO_MEMORY.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_doc_set(nav_scene_doc *doc, const char *path, const char *value, char *msg,
                                                   size_t msg_size);

/**
 * Read the (overridden) document as a scene, exactly as nav_scene_read_string would read the
 * edited file (relative file references resolve against the original file's directory).
 * Diagnostics name the original file and its places (line and column in the file as given, not
 * in the edited text); a diagnostic about a value that nav_scene_doc_set put there (or a key it
 * added) has no place in the file: line and column 0, and its path names the overridden field.
 * On NAV_OK @p out owns heap data as after nav_scene_read_string (release it with
 * nav_scene_release() before reading into it again).
 * @return the statuses of nav_scene_read_string.
 */
NAV_API NAV_NODISCARD nav_status nav_scene_doc_read(const nav_scene_doc *doc, nav_scene *out, nav_diag_fn report,
                                                    void *user);

/**
 * Split "PATH=VALUE" into its parts (copied into @p path / @p value).
 * @return NAV_OK or NAV_ERR_INVALID_ARG (no '=', empty part, too long).
 */
NAV_API NAV_NODISCARD nav_status nav_scene_override_split(const char *text, char *path, size_t path_size,
                                                          char *value, size_t value_size);

NAV_END_DECLS

#endif /* NAV_SCENE_OVERRIDE_H */
