/*
 * navsim bench, the editor's live preview (issue 8 item 4): `navstudio --bench-preview N
 * scenes/urban-drive.yaml` as a child process (under `xvfb-run -a` when no X display is set)
 * moves a waypoint N times and measures each edit's latency, from the edit to the swap of the
 * window frame that shows the re-simulated estimate. The row: samples = edits, wall = median
 * latency [s]; the note has the p90, the renders per view and the window frames per edit.
 * Target: median <= 100 ms.
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_internal.h"
#include "bench_verdict.h"
#include "navcore/nav_paths.h"

#define STUDIO_CASE "navstudio-preview"
#define STUDIO_TARGET_MS 100.0

static const char *navstudio_exe(void) {
  static char path[4096];
  return bench_program("navstudio", path, sizeof path) ? path : NULL;
}

void bench_case_studio_preview(bool full, const char *out_dir, bench_row *rows, int *n, int cap) {
  if (*n >= cap) return;
  bench_row *r = &rows[*n];
  memset(r, 0, sizeof *r);
  snprintf(r->case_name, sizeof r->case_name, "%s", STUDIO_CASE);
  snprintf(r->variant, sizeof r->variant, "urban-drive (513 s, 100 Hz), waypoint drags");
  r->algorithm = "high_order";
  r->earth_model = "wgs84";
  r->frame = "ned";
  r->rate_hz = 100.0;
  r->truth_sps = r->mech_sps = NAN;
  r->pos_err_m = r->vel_err_mps = r->att_err_rad = r->rms_h_m = NAN;
  (*n)++;
  const char *exe = navstudio_exe();
  if (!exe) {
    snprintf(r->error, sizeof r->error, "navstudio not built (NAV_BUILD_EDITOR=OFF): no live-preview figure");
    return;
  }
  char res[4096], scene[4400], log[4400];
  if (!bench_resources_dir(res, sizeof res)) {
    snprintf(r->error, sizeof r->error, "resources directory not found");
    return;
  }
  snprintf(scene, sizeof scene, "%s/../scenes/urban-drive.yaml", res);
  snprintf(log, sizeof log, "%s/logs/navstudio-preview.log", out_dir);
  const char *edits = full ? "40" : "20";
  char *with_x[] = {"xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", (char *)exe, "--bench-preview", (char *)edits,
                    scene,      NULL};
  char *plain[] = {(char *)exe, "--bench-preview", (char *)edits, scene, NULL};
  const child_result c = bench_run_child(bench_have_display() ? plain : with_x, log, 300.0);
  FILE *f = fopen(log, "r");
  char line[1024];
  double samples = NAN, median = NAN, p90 = NAN, renders = NAN, frames = NAN, load = NAN, cpu = NAN;
  while (f && fgets(line, sizeof line, f)) {
    if (strncmp(line, "preview_latency_ms:", 19) != 0) continue;
    samples = bench_log_field(line, " samples=");
    median = bench_log_field(line, " median=");
    p90 = bench_log_field(line, " p90=");
    renders = bench_log_field(line, " renders_per_view_per_edit=");
    frames = bench_log_field(line, " frames_per_view_per_edit=");
    load = bench_log_field(line, " loadavg=");
    cpu = bench_log_field(line, " cpu_per_edit_ms=");
  }
  if (f) fclose(f);
  if (!c.exited_ok || !(median > 0)) {
    snprintf(r->error, sizeof r->error, "navstudio --bench-preview %s (see %.200s)",
             c.timed_out ? "timed out" : "failed", log);
    return;
  }
  r->ok = true;
  r->samples = (long long)samples;
  r->wall_s = median * 1e-3;
  snprintf(r->note, sizeof r->note,
           "edit to picture: median %.0f ms, p90 %.0f ms; %.2g renders and %.2g frames per view per edit; "
           "%.0f ms CPU per edit; load %.1f",
           median, p90, renders, frames, cpu, load);
}

void bench_studio_target_md(FILE *md, const bench_row *rows, int n) {
  const bench_row *r = NULL;
  for (int i = 0; i < n; ++i)
    if (strcmp(rows[i].case_name, STUDIO_CASE) == 0) r = &rows[i];
  if (!r) return;
  char v[320];
  if (r->ok)
    snprintf(v, sizeof v, "%s", r->note);
  else
    snprintf(v, sizeof v, "%s", r->error);
  fprintf(md, "| navstudio live preview, edit to picture | <= %.0f ms | %s | %s |\n", STUDIO_TARGET_MS, v,
          bench_verdict_text(bench_verdict_at_most(r->ok ? r->wall_s * 1e3 : NAN, STUDIO_TARGET_MS, false)));
}
