/**
 * @file nav_paths.h
 * @brief navcore_io: where the shared data (scene library, catalogs, resources) is found.
 *
 * One rule for every program (navsim, navview, navstudio) and for programs linking the library:
 * the share directory `<prefix>/share/navcore` holds `resources/` (catalogs, motion
 * definitions) and `scenes/` (the scene library). It is found relative to the running executable
 * and to the loaded libnavcore_io (installed tree: `<prefix>/bin/../share/navcore`,
 * `<prefix>/lib[/<multiarch>]/../../share/navcore`; build tree: `<build>/share/navcore`, which
 * CMake links to the source's resources/ and scenes/). No absolute build path is compiled in,
 * so an installed tree can be moved as a whole.
 */
#ifndef NAV_PATHS_H
#define NAV_PATHS_H

#include <stdbool.h>
#include <stddef.h>

#include "nav_export.h"

NAV_BEGIN_DECLS

/**
 * The share directory (holding resources/ and scenes/): the first of `D/../share/navcore`,
 * `D/../../share/navcore`, `D/../../../share/navcore` whose resources/imu_catalog.csv is readable,
 * for D the directory of the running executable, then D the directory of the loaded
 * libnavcore_io. $NAV_SHARE_DIR, when set and non-empty, is used as given instead.
 * @param[out] buf   the directory, NUL-terminated (written only on success)
 * @param[in]  size  capacity of @p buf in bytes
 * @return true when found and it fits in @p buf. Thread-safe.
 */
NAV_API bool nav_paths_share_dir(char *buf, size_t size);

/**
 * The resources directory (imu_catalog.csv, gnss_receivers.csv, motion_defs/): $NAV_RESOURCES_DIR
 * when set and non-empty (used as given), else `<share dir>/resources`.
 * @return true when found and it fits in @p buf (written only on success). Thread-safe.
 */
NAV_API bool nav_paths_resources_dir(char *buf, size_t size);

/**
 * The scene library directory: `<share dir>/scenes`.
 * @return true when found and it fits in @p buf (written only on success). Thread-safe.
 */
NAV_API bool nav_paths_scenes_dir(char *buf, size_t size);

/**
 * A companion program of this installation (e.g. "navview" for navsim render): `D/name`, the
 * installed helper `D/../libexec/navcore/name` (navsim-bench) or, in the build tree,
 * `D/../<subdir>/name` (subdir "viewer" for navview, "editor" for navstudio, "navcore" for navsim,
 * "bench" for navsim-bench), for D the directory of the running executable, when that file is
 * executable.
 * @return true when found and it fits in @p buf (written only on success); false means "look on
 *         PATH". Thread-safe.
 */
NAV_API bool nav_paths_program(const char *name, char *buf, size_t size);

/**
 * The running executable's own path (the link /proc/self/exe resolves to), for programs that
 * start themselves again (navsim render runs navsim run; navsim bench times its commands).
 * @return true when known and it fits in @p buf (written only on success). Thread-safe.
 */
NAV_API bool nav_paths_executable(char *buf, size_t size);

/**
 * The offline map background data (Natural Earth and GSHHS files in the layout of Debian's
 * python-cartopy-data): $NAVVIEW_MAP_DATA when set and non-empty (used as given), else
 * /usr/share/cartopy/data. Whether the files exist is the caller's question.
 * @return true when it fits in @p buf (written only on success). Thread-safe.
 */
NAV_API bool nav_paths_map_data_dir(char *buf, size_t size);

NAV_END_DECLS

#endif /* NAV_PATHS_H */
