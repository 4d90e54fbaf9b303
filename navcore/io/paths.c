/*
 * Where the shared data is found (nav_paths.h): relative to the running executable and to the
 * loaded library, never through a path compiled in, so the installed tree has no trace of the
 * build machine and can be moved as a whole.
 */
#define _GNU_SOURCE /* dladdr */
#include "navcore/nav_paths.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

enum { DIR_CAP = 4096 };

/* Directory part of @p file into @p dir (false when it has none or does not fit). */
static bool dir_of(const char *file, char *dir, size_t size) {
  const char *slash = strrchr(file, '/');
  if (slash == NULL) return false;
  const size_t n = (size_t)(slash - file);
  if (n == 0 || n >= size) return false;
  memcpy(dir, file, n);
  dir[n] = '\0';
  return true;
}

bool nav_paths_executable(char *buf, size_t size) {
  char exe[DIR_CAP];
  if (buf == NULL || size == 0) return false;
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
  if (n <= 0 || (size_t)n >= size) return false;
  exe[n] = '\0';
  memcpy(buf, exe, (size_t)n + 1);
  return true;
}

static bool exe_dir(char *dir, size_t size) {
  char exe[DIR_CAP];
  if (!nav_paths_executable(exe, sizeof exe)) return false;
  return dir_of(exe, dir, size);
}

/* An address inside the object (shared library or executable) this file is linked into. */
static const char k_anchor = 0;

/* The directory of the object (shared library or executable) this file is linked into. */
static bool lib_dir(char *dir, size_t size) {
  Dl_info info;
  if (dladdr(&k_anchor, &info) == 0 || info.dli_fname == NULL || info.dli_fname[0] != '/')
    return false;
  return dir_of(info.dli_fname, dir, size);
}

/* Installed tree: <prefix>/bin -> ../share, <prefix>/lib -> ../share,
   <prefix>/lib/<multiarch> -> ../../share; build tree: <build>/<subdir>[/<subdir>] -> <build>/share. */
static bool share_below(const char *dir, char *buf, size_t size) {
  static const char *const ups[] = {"..", "../..", "../../.."};
  for (size_t i = 0; i < sizeof ups / sizeof ups[0]; ++i) {
    char cand[DIR_CAP], probe[DIR_CAP + 64];
    if (snprintf(cand, sizeof cand, "%s/%s/share/navcore", dir, ups[i]) >= (int)sizeof cand) continue;
    snprintf(probe, sizeof probe, "%s/resources/imu_catalog.csv", cand);
    if (access(probe, R_OK) != 0) continue;
    char real[PATH_MAX];
    const char *found = realpath(cand, real) != NULL ? real : cand;
    if (strlen(found) >= size) return false;
    memcpy(buf, found, strlen(found) + 1);
    return true;
  }
  return false;
}

bool nav_paths_share_dir(char *buf, size_t size) {
  if (buf == NULL || size == 0) return false;
  const char *env = getenv("NAV_SHARE_DIR");
  if (env != NULL && env[0] != '\0') {
    if (strlen(env) >= size) return false;
    memcpy(buf, env, strlen(env) + 1);
    return true;
  }
  char dir[DIR_CAP];
  if (exe_dir(dir, sizeof dir) && share_below(dir, buf, size)) return true;
  if (lib_dir(dir, sizeof dir) && share_below(dir, buf, size)) return true;
  return false;
}

static bool share_sub(const char *sub, char *buf, size_t size) {
  char share[DIR_CAP];
  if (buf == NULL || size == 0 || !nav_paths_share_dir(share, sizeof share)) return false;
  const int n = snprintf(NULL, 0, "%s/%s", share, sub);
  if (n < 0 || (size_t)n >= size) return false;
  snprintf(buf, size, "%s/%s", share, sub);
  return true;
}

bool nav_paths_resources_dir(char *buf, size_t size) {
  if (buf == NULL || size == 0) return false;
  const char *env = getenv("NAV_RESOURCES_DIR");
  if (env != NULL && env[0] != '\0') {
    if (strlen(env) >= size) return false;
    memcpy(buf, env, strlen(env) + 1);
    return true;
  }
  return share_sub("resources", buf, size);
}

bool nav_paths_scenes_dir(char *buf, size_t size) {
  return share_sub("scenes", buf, size);
}

bool nav_paths_program(const char *name, char *buf, size_t size) {
  static const struct {
    const char *name, *subdir;
  } build_tree[] = {{"navview", "viewer"}, {"navstudio", "editor"}, {"navsim", "navcore"}, {"navsim-bench", "bench"}};
  char dir[DIR_CAP], cand[DIR_CAP + 256];
  if (name == NULL || name[0] == '\0' || strchr(name, '/') != NULL || buf == NULL || size == 0 ||
      !exe_dir(dir, sizeof dir))
    return false;
  for (int pass = 0; pass < 3; ++pass) {
    const char *subdir = NULL;
    if (pass == 2) {
      for (size_t i = 0; i < sizeof build_tree / sizeof build_tree[0]; ++i)
        if (strcmp(build_tree[i].name, name) == 0) subdir = build_tree[i].subdir;
      if (subdir == NULL) break;
    }
    if (pass == 0)
      snprintf(cand, sizeof cand, "%s/%s", dir, name);
    else if (pass == 1)
      snprintf(cand, sizeof cand, "%s/../libexec/navcore/%s", dir, name); /* installed helper */
    else
      snprintf(cand, sizeof cand, "%s/../%s/%s", dir, subdir, name);
    struct stat st;
    if (stat(cand, &st) != 0 || !S_ISREG(st.st_mode) || access(cand, X_OK) != 0) continue;
    if (strlen(cand) >= size) return false;
    memcpy(buf, cand, strlen(cand) + 1);
    return true;
  }
  return false;
}

bool nav_paths_map_data_dir(char *buf, size_t size) {
  if (buf == NULL || size == 0) return false;
  const char *env = getenv("NAVVIEW_MAP_DATA");
  const char *dir = env != NULL && env[0] != '\0' ? env : "/usr/share/cartopy/data";
  if (strlen(dir) >= size) return false;
  memcpy(buf, dir, strlen(dir) + 1);
  return true;
}
