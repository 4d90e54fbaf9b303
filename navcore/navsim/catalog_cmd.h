/* navsim catalog: list the IMU and GNSS receiver catalogs with the model each row converts to. */
#ifndef NAVSIM_CATALOG_CMD_H
#define NAVSIM_CATALOG_CMD_H

#include <stdbool.h>
#include <stddef.h>

/**
 * Run `navsim catalog ARGS` (argv holds the arguments after "catalog").
 * @param resources_dir directory holding imu_catalog.csv and gnss_receivers.csv, normally from
 *                      navsim_find_resources_dir(); NULL prints how to set NAV_RESOURCES_DIR.
 * @return the process exit code: 0 success; 1 a catalog cannot be found or read; 2 invalid catalog
 *         or command line.
 */
int navsim_catalog(int argc, char **argv, const char *resources_dir);

/**
 * Locate the resources directory, first match wins:
 *  1. $NAV_RESOURCES_DIR if set and non-empty (used as given, even if it lacks the files, so a
 *     wrong setting is reported instead of silently ignored);
 *  2. <share dir>/resources, the share directory found relative to the executable (installed
 *     tree: <bin>/../share/navcore; build tree: <build>/share/navcore, linked to the sources) by
 *     nav_paths_resources_dir() (nav_paths.h), which counts it only if it contains a readable
 *     imu_catalog.csv.
 * @return true and the directory in @p buf, or false (buf = "").
 */
bool navsim_find_resources_dir(char *buf, size_t size);

#endif /* NAVSIM_CATALOG_CMD_H */
