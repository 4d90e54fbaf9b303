/*
 * gnss.file: recorded GNSS fixes (KF-GINS GNSS text) as the GNSS source of a scene
 * (docs/gnss-file.md). The scene reader resolves and checks the file; nav_gnss_file_load()
 * reads the fixes into the scene time base for nav_sim_set_gnss_fixes().
 */
#define _XOPEN_SOURCE 700 /* realpath */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "navcore/nav_recorded.h"
#include "scene_io_internal.h"

/* Resolve gnss.file against the scene file, make it canonical and check every line of it. */
void nav_io_gnss_file_finish(nav_io_reader *r, nav_scene *scene) {
  nav_scene_gnss *g = &scene->gnss;
  if (g->file[0] == '\0') return;
  nav_io_read_state *st = nav_io_reader_state(r);
  char path[3 * NAV_IO_PATH_MAX];
  if (!nav_io_resolve_path(path, sizeof path, st->file, st->file_is_path, g->file)) {
    nav_io_reader_error_at_path(r, "gnss.file", "the path of the GNSS file is too long");
    return;
  }
  struct stat sb;
  const bool exists = stat(path, &sb) == 0;
  const int err = errno;
  if (!exists || !S_ISREG(sb.st_mode)) {
    nav_io_reader_error_at_path(r, "gnss.file", "cannot read the GNSS file \"%s\": %s", path,
                                exists ? "not a regular file" : strerror(err));
    return;
  }
  char *canonical = realpath(path, NULL);
  if (canonical != NULL && strlen(canonical) < sizeof path) snprintf(path, sizeof path, "%s", canonical);
  free(canonical);
  nav_diag d;
  memset(&d, 0, sizeof d);
  size_t count = 0;
  const nav_status s = nav_rec_check_file(path, NAV_REC_GNSS, &count, &d);
  if (s != NAV_OK) {
    if (d.message[0] != '\0') nav_io_forward_diag(r, &d);
    nav_io_reader_error_at_path(r, "gnss.file", "the GNSS file \"%s\" was not loaded (%s)", path,
                                nav_status_str(s));
    return;
  }
  if (count == 0) {
    nav_io_reader_error_at_path(
        r, "gnss.file",
        "the GNSS file \"%s\" holds no fix (expected KF-GINS GNSS text: time, latitude, "
        "longitude [deg], height [m], sigma N E D [m], optionally velocity N E D [m/s] "
        "and its sigmas)",
        path);
    return;
  }
  const size_t len = strlen(path);
  if (len >= sizeof g->file) {
    nav_io_reader_error_at_path(r, "gnss.file", "the path of the GNSS file is too long");
    return;
  }
  memcpy(g->file, path, len + 1);
}

nav_status nav_gnss_file_load(const nav_scene *scene, nav_ins_gnss_fix **out, size_t *count,
                              double *t0_file_s, nav_diag *diag) {
  if (!scene || !out || !count || scene->gnss.file[0] == '\0') return NAV_ERR_INVALID_ARG;
  size_t n = 0;
  nav_status st = nav_rec_check_file(scene->gnss.file, NAV_REC_GNSS, &n, diag);
  if (st != NAV_OK) return st;
  if (n == 0) {
    if (diag) {
      memset(diag, 0, sizeof *diag);
      snprintf(diag->file, sizeof diag->file, "%.500s", scene->gnss.file);
      snprintf(diag->message, sizeof diag->message, "the GNSS file holds no fix");
    }
    return NAV_ERR_PARSE;
  }
  nav_ins_gnss_fix *f = malloc(n * sizeof *f);
  if (!f) return NAV_ERR_NO_MEMORY;
  size_t got = 0;
  st = nav_rec_load_gnss(scene->gnss.file, f, n, &got, diag);
  if (st != NAV_OK) {
    free(f);
    return st;
  }
  /* docs/gnss-file.md: a recorded reference shares the file's time base (scene time 0 is its
   * first sample, t0_s); otherwise the first fix is at scene time 0. */
  const double t0 = scene->trajectory.type == NAV_TRAJ_RECORDED ? scene->trajectory.recorded.t0_s : f[0].t_s;
  for (size_t i = 0; i < got; ++i)
    f[i].t_s -= t0;
  *out = f;
  *count = got;
  if (t0_file_s) *t0_file_s = t0;
  return NAV_OK;
}
