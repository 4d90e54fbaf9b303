/*
 * navsim bench, the preliminary estimate of every library scene (issues 20 and 23): `navsim
 * estimate SCENE --quiet` as a child process for each scene in scenes/ (the browser studio's
 * POST /api/estimate runs the same program in a job process), its CPU seconds (user + system,
 * wait4) the median of the repetitions (quick 1, full 3). The row: samples = scenes, wall = the
 * median over scenes of the per-scene CPU seconds; the note names the slowest scene and its CPU
 * seconds (the table's wall column holds CPU seconds for this row). Target: the slowest scene
 * < 0.5 CPU s (the estimate "in well under a second").
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_internal.h"
#include "bench_verdict.h"

#define EST_CASE "estimate-library"
#define EST_TARGET_S 0.5
#define EST_MAX_SCENES 64

/* The slowest scene's CPU seconds of the last measurement (NaN: none), for the target line. */
static double s_slowest_s = NAN;

static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }
void bench_case_estimate_library(bool full, const char *out_dir, bench_row *rows, int *n, int cap) {
  if (*n >= cap) return;
  bench_row *r = &rows[*n];
  memset(r, 0, sizeof *r);
  snprintf(r->case_name, sizeof r->case_name, "%s", EST_CASE);
  snprintf(r->variant, sizeof r->variant, "navsim estimate, every scene in scenes/");
  r->algorithm = "high_order";
  r->earth_model = "wgs84";
  r->frame = "ned";
  r->truth_sps = r->mech_sps = NAN;
  r->pos_err_m = r->vel_err_mps = r->att_err_rad = r->rms_h_m = NAN;
  (*n)++;
  char exe[PATH_MAX], res[PATH_MAX], dir[PATH_MAX + 16];
  if (!bench_navsim_exe(exe, sizeof exe)) {
    snprintf(r->error, sizeof r->error, "not measured: the navsim program was not found");
    return;
  }
  if (!bench_resources_dir(res, sizeof res)) {
    snprintf(r->error, sizeof r->error, "not measured: resources directory not found");
    return;
  }
  snprintf(dir, sizeof dir, "%s/../scenes", res);
  DIR *d = opendir(dir);
  if (!d) {
    snprintf(r->error, sizeof r->error, "not measured: no scene library at %.200s", dir);
    return;
  }
  char *names[EST_MAX_SCENES];
  int ns = 0;
  for (struct dirent *e; (e = readdir(d)) != NULL && ns < EST_MAX_SCENES;) {
    const size_t len = strlen(e->d_name);
    if (len > 5 && strcmp(e->d_name + len - 5, ".yaml") == 0) names[ns++] = strdup(e->d_name);
  }
  closedir(d);
  qsort(names, (size_t)ns, sizeof *names, cmp_str);
  const int reps = full ? 3 : 1;
  double per_scene[EST_MAX_SCENES];
  int measured = 0, failed = 0, slowest = -1;
  double slowest_s = -1.0;
  for (int i = 0; i < ns; ++i) {
    char scene[PATH_MAX + 300], out[PATH_MAX + 64], log[PATH_MAX + 64];
    snprintf(scene, sizeof scene, "%s/%s", dir, names[i]);
    snprintf(out, sizeof out, "%s/estimate-library", out_dir);
    snprintf(log, sizeof log, "%s/logs/estimate-library.log", out_dir);
    double cpu[3];
    int nc = 0;
    bool ok = true;
    for (int k = 0; k < reps; ++k) {
      char *argv[] = {exe, "estimate", scene, "--out", out, "--force", "--quiet", NULL};
      const child_result c = bench_run_child(argv, log, 120.0);
      if (!c.started || c.timed_out) {
        ok = false;
        break;
      }
      /* A scene the estimate refuses (exit 1 or 2, e.g. polar-flight's pole) still costs its CPU. */
      if (!c.exited_ok) ok = false;
      cpu[nc++] = c.cpu_s;
    }
    if (!ok) ++failed;
    if (nc == 0) continue;
    const double m = bench_median(cpu, nc);
    per_scene[measured++] = m;
    if (m > slowest_s) {
      slowest_s = m;
      slowest = i;
    }
  }
  if (measured == 0) {
    snprintf(r->error, sizeof r->error, "not measured: no scene could be estimated (see %.160s/logs)", out_dir);
  } else {
    r->ok = true;
    r->samples = measured;
    s_slowest_s = slowest_s;
    char slow[64];
    snprintf(slow, sizeof slow, "%.*s", (int)(strlen(names[slowest]) - 5), names[slowest]);
    r->wall_s = bench_median(per_scene, measured);
    r->load1 = bench_load1();
    char note[512];
    snprintf(note, sizeof note, "CPU s per scene (median of %d): median %.3f, slowest %s %.3f; %d of %d exit non-zero; load %.1f",
             reps, r->wall_s, slow, slowest_s, failed, ns, r->load1);
    snprintf(r->note, sizeof r->note, "%.159s", note);
  }
  for (int i = 0; i < ns; ++i) free(names[i]);
}

void bench_estimate_target_md(FILE *md, const bench_row *rows, int n) {
  const bench_row *r = NULL;
  for (int i = 0; i < n; ++i)
    if (strcmp(rows[i].case_name, EST_CASE) == 0) r = &rows[i];
  if (!r) return;
  fprintf(md, "| navsim estimate, slowest library scene | < %.1f CPU s | %s | %s |\n", EST_TARGET_S,
          r->ok ? r->note : r->error,
          bench_verdict_text(bench_verdict_at_most(r->ok ? s_slowest_s : NAN, EST_TARGET_S, false)));
}
