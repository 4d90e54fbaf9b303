/* Helpers shared by the navsim commands (see cli_util.h). */
#define _POSIX_C_SOURCE 200809L
#include "cli_util.h"

#include <errno.h>
#include <math.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "navcore/nav_recorded.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_track.h"

bool navsim_is_help(const char *arg) {
  return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

double navsim_now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void navsim_print_diag(void *user, const nav_diag *d) {
  navsim_diag_sink *s = user;
  char line[2048];
  nav_diag_format(d, line, sizeof line);
  if (s && s->context)
    fprintf(stderr, "%s %s\n", line, s->context);
  else
    fprintf(stderr, "%s\n", line);
  if (s) s->count++;
}

int navsim_load_scene(const char *path, nav_scene *scene) {
  navsim_diag_sink sink = {0};
  /* Requirements the run cannot evaluate are refused here too (issue 25). */
  const nav_status st = nav_scene_read_file_to_run(path, scene, navsim_print_diag, &sink);
  if (st == NAV_OK) return 0;
  if (sink.count == 0) fprintf(stderr, "%s: error: %s\n", path, nav_status_str(st));
  return st == NAV_ERR_PARSE ? 2 : 1;
}

void navsim_print_recorded_fit(FILE *f, const char *label, const nav_scene *scene) {
  if (!f || !scene || scene->trajectory.type != NAV_TRAJ_RECORDED) return;
  const nav_recorded_fit_stats *s = &scene->trajectory.recorded.fit;
  fprintf(f,
          "%srecorded %s: %ld samples fitted; residuals of the fit: position RMS %.3g m (horizontal %.3g, vertical "
          "%.3g), max %.3g m at t = %.6g s; velocity RMS %.3g m/s, max %.3g m/s at t = %.6g s; attitude RMS %.3g "
          "deg, max %.3g deg at t = %.6g s; longest gap between samples %.6g s at t = %.6g s\n",
          label ? label : "", scene->trajectory.recorded.file, s->samples, s->pos_rms_m, s->pos_h_rms_m,
          s->pos_v_rms_m, s->pos_max_m, s->pos_max_t_s, s->vel_rms_mps, s->vel_max_mps, s->vel_max_t_s,
          s->att_rms_rad * NAV_RAD2DEG, s->att_max_rad * NAV_RAD2DEG, s->att_max_t_s, s->max_gap_s, s->max_gap_t_s);
  char w[1200];
  if (nav_track_warnings(&scene->trajectory.recorded, w, sizeof w) != 0)
    fprintf(stderr, "%swarning: trajectory.recorded: %s\n", label ? label : "", w);
}

int navsim_attach_gnss_file(const char *cmd, const nav_scene *scene, nav_sim *sim, size_t *count) {
  if (count) *count = 0;
  if (!scene || scene->gnss.file[0] == '\0') return 0;
  nav_ins_gnss_fix *fixes = NULL;
  size_t n = 0;
  nav_diag d;
  memset(&d, 0, sizeof d);
  nav_status st = nav_gnss_file_load(scene, &fixes, &n, NULL, &d);
  if (st != NAV_OK) {
    char buf[1400];
    if (d.message[0] != '\0') {
      nav_diag_format(&d, buf, sizeof buf);
      fprintf(stderr, "navsim %s: gnss.file: %s\n", cmd, buf);
    } else {
      fprintf(stderr, "navsim %s: gnss.file: %s: %s\n", cmd, scene->gnss.file, nav_status_str(st));
    }
    return st == NAV_ERR_PARSE ? 2 : 1;
  }
  st = nav_sim_set_gnss_fixes(sim, fixes, n);
  free(fixes);
  if (st != NAV_OK) {
    fprintf(stderr, "navsim %s: gnss.file: %s: %s\n", cmd, scene->gnss.file,
            nav_sim_last_error(sim)[0] ? nav_sim_last_error(sim) : nav_status_str(st));
    return st == NAV_ERR_INVALID_ARG ? 2 : 1;
  }
  if (count) *count = n;
  return 0;
}

void navsim_warn_gnss_file_model(const char *cmd, const char *scene_path, const nav_scene *scene) {
  if (!scene || scene->gnss.file[0] == '\0') return;
  fprintf(stderr,
          "%s: warning: gnss.file: navsim %s analyses the covariance with the receiver model's epochs and "
          "sigmas, not the recorded fixes of the file (navsim run uses those)\n",
          scene_path ? scene_path : "", cmd);
}

void navsim_print_gnss_file(FILE *f, const char *label, const nav_scene *scene) {
  if (!f || !scene || scene->gnss.file[0] == '\0') return;
  nav_ins_gnss_fix *fixes = NULL;
  size_t n = 0;
  double t0 = 0.0;
  if (nav_gnss_file_load(scene, &fixes, &n, &t0, NULL) != NAV_OK) return;
  size_t vel = 0;
  for (size_t i = 0; i < n; ++i)
    if (fixes[i].has_vel) vel++;
  fprintf(f,
          "%srecorded fixes from %s: %zu fixes (%s), file time %.3f to %.3f s; scene time = file time - %.3f s "
          "(%s); the filter uses the file's sigmas, the receiver model is not used\n",
          label ? label : "", scene->gnss.file, n, vel == n ? "position + velocity" : vel ? "some with velocity" : "position",
          fixes[0].t_s + t0, fixes[n - 1].t_s + t0, t0,
          scene->trajectory.type == NAV_TRAJ_RECORDED ? "the recorded reference's time base"
                                                      : "the first fix at scene time 0");
  free(fixes);
}

bool navsim_parse_u64(const char *s, uint64_t *out) {
  if (!s || !*s || *s == '-' || *s == '+') return false;
  for (const char *p = s; *p; ++p)
    if (*p < '0' || *p > '9') return false;
  errno = 0;
  char *end = NULL;
  const unsigned long long v = strtoull(s, &end, 10);
  if (errno != 0 || !end || *end) return false;
  *out = (uint64_t)v;
  return true;
}

bool navsim_parse_double(const char *s, double *out) {
  if (!s || !*s) return false;
  errno = 0;
  char *end = NULL;
  const double v = strtod(s, &end);
  if (errno != 0 || !end || *end || !isfinite(v)) return false;
  *out = v;
  return true;
}

bool navsim_parse_positive(const char *s, double *out, bool allow_zero) {
  double v = 0.0;
  if (!navsim_parse_double(s, &v) || v < 0.0 || (!allow_zero && v == 0.0)) return false;
  *out = v;
  return true;
}

bool navsim_parse_long(const char *s, long lo, long hi, long *out) {
  if (!s) return false;
  char *end = NULL;
  errno = 0;
  const long v = strtol(s, &end, 10);
  if (errno != 0 || !end || end == s || *end || v < lo || v > hi) return false;
  *out = v;
  return true;
}

bool navsim_need_value(const char *cmd, int argc, int i, const char *opt) {
  if (i + 1 < argc) return true;
  fprintf(stderr, "navsim %s: %s needs a value\n", cmd, opt);
  return false;
}

int navsim_unknown_option(const char *cmd, const char *opt) {
  fprintf(stderr, "navsim %s: unknown option \"%s\" (see navsim %s --help)\n", cmd, opt, cmd);
  return 2;
}

int navsim_scene_arg(const char *cmd, const char *arg, const char **scene) {
  if (arg[0] == '-' && arg[1] != '\0') return navsim_unknown_option(cmd, arg);
  if (*scene) {
    fprintf(stderr, "navsim %s: only one SCENE may be given\n", cmd);
    return 2;
  }
  *scene = arg;
  return 0;
}

void navsim_safe_name(char *out, size_t cap, const char *name, const char *fallback) {
  size_t j = 0;
  for (const char *p = name; *p && j + 1 < cap; ++p) {
    const char c = *p;
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                    c == '_' || c == '.';
    out[j++] = ok ? c : '_';
  }
  out[j] = '\0';
  if (j == 0 || strcmp(out, ".") == 0 || strcmp(out, "..") == 0) snprintf(out, cap, "%s", fallback);
}

int navsim_out_check(const char *cmd, const char *dir, bool force) {
  char msg[1200];
  const nav_status st = nav_resultdir_check(dir, msg, sizeof msg);
  if (st == NAV_OK) return 0;
  if (force && st == NAV_ERR_INVALID_ARG && dir && *dir) {
    struct stat sb;
    if (lstat(dir, &sb) == 0) return 0; /* moved aside at commit */
  }
  fprintf(stderr, "navsim %s: --out: %s\n", cmd, msg);
  return st == NAV_ERR_IO ? 1 : 2;
}

int navsim_out_begin(const char *cmd, const char *dir, bool force, nav_resultdir **rd) {
  char msg[1200];
  const nav_status st = nav_resultdir_open(dir, force ? NAV_RESULTDIR_FORCE : 0u, rd, msg, sizeof msg);
  if (st == NAV_OK) return 0;
  fprintf(stderr, "navsim %s: --out: %s\n", cmd, msg[0] ? msg : nav_status_str(st));
  return st == NAV_ERR_INVALID_ARG ? 2 : 1;
}

int navsim_out_commit(const char *cmd, nav_resultdir *rd) {
  char msg[1400];
  const nav_status st = nav_resultdir_commit_msg(rd, msg, sizeof msg);
  if (st == NAV_OK) {
    if (msg[0]) fprintf(stderr, "navsim %s: note: %s\n", cmd, msg);
    return 0;
  }
  fprintf(stderr, "navsim %s: --out: %s\n", cmd, msg[0] ? msg : nav_status_str(st));
  return st == NAV_ERR_INVALID_ARG ? 2 : 1;
}

int navsim_refuse_special_result_files(const char *dir) {
  static const char *const names[] = {"summary.json", "truth.csv", "nav.csv",          "errors.csv",
                                      "mc_stats.csv", "gnss.csv",  "gnss_outages.csv", "imu_errors.csv",
                                      "estimate.csv", "allan.csv", "bench.csv",        "requirements.csv"};
  int rc = 0;
  for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
    char path[4352], why[320];
    if (snprintf(path, sizeof path, "%s/%s", dir, names[i]) >= (int)sizeof path) continue;
    FILE *f = NULL;
    const nav_status st = nav_io_fopen_regular(path, &f, why, sizeof why);
    if (st == NAV_OK) fclose(f);
    if (st != NAV_ERR_PARSE) continue; /* a missing file is each reader's business */
    fprintf(stderr, "%s: error: %s\n", path, why);
    rc = 2;
  }
  return rc;
}

void navsim_json_number(FILE *f, double v, int digits) {
  if (isfinite(v))
    fprintf(f, "%.*g", digits, v);
  else
    fputs("null", f);
}
