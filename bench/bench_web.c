/*
 * navsim bench, the browser studio's scene to first picture (issue 20): web/studio/bench/
 * first_picture.mjs under node starts this program's `navsim serve`, opens the studio in
 * Debian's chromium (puppeteer-core from the build tree) and reads the page's own timings of
 * urban-drive, the studio's default scene: from the navigation start of a fresh page to the
 * preliminary estimate shown and the map drawn with the path. The row: samples = page loads,
 * wall = median [s]; the note has the p90, the median from choosing the scene in the library and
 * the estimate's round trip. The row's median has every estimate computed (the server's cache
 * of answers off); the note adds the parts and the same with the cache on (the default).
 * Target: median <= 1 s on an idle machine. Without node, chromium,
 * the built bundle or its npm packages the row says what is missing and the target is "not
 * measured".
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bench_internal.h"
#include "bench_verdict.h"

#define WEB_CASE "studio-first-picture"
#define WEB_TARGET_MS 1000.0

static bool is_file(const char *p) {
  struct stat st;
  return stat(p, &st) == 0 && S_ISREG(st.st_mode);
}

/* The first executable @p name on PATH into buf. */
static bool find_in_path(const char *name, char *buf, size_t cap) {
  const char *path = getenv("PATH");
  if (path == NULL) path = "/usr/local/bin:/usr/bin:/bin";
  while (*path) {
    const char *end = strchr(path, ':');
    const size_t len = end ? (size_t)(end - path) : strlen(path);
    if (len > 0 && (size_t)snprintf(buf, cap, "%.*s/%s", (int)len, path, name) < cap && access(buf, X_OK) == 0)
      return true;
    path += len + (end ? 1 : 0);
  }
  return false;
}

/* env value, else <exe dir>/rel; empty when neither exists. */
static void locate(const char *env, const char *exe, const char *rel, char *buf, size_t cap) {
  const char *e = getenv(env);
  if (e != NULL && *e) {
    snprintf(buf, cap, "%s", e);
    return;
  }
  char dir[PATH_MAX];
  snprintf(dir, sizeof dir, "%s", exe);
  char *slash = strrchr(dir, '/');
  if (slash) *slash = '\0';
  if ((size_t)snprintf(buf, cap, "%s/%s", dir, rel) >= cap) buf[0] = '\0';
}

/* A time for the note: at most five digits, -1 when the log did not give it. */
static double ms_shown(double ms) { return isnan(ms) ? -1.0 : fmin(ms, 99999.0); }

void bench_case_web_first_picture(bool full, const char *out_dir, bench_row *rows, int *n, int cap) {
  if (*n >= cap) return;
  bench_row *r = &rows[*n];
  memset(r, 0, sizeof *r);
  snprintf(r->case_name, sizeof r->case_name, "%s", WEB_CASE);
  snprintf(r->variant, sizeof r->variant, "urban-drive in chromium: estimate + map");
  r->algorithm = "high_order";
  r->earth_model = "wgs84";
  r->frame = "ned";
  r->rate_hz = 100.0;
  r->truth_sps = r->mech_sps = NAN;
  r->pos_err_m = r->vel_err_mps = r->att_err_rad = r->rms_h_m = NAN;
  (*n)++;
  char exe[PATH_MAX], node[PATH_MAX], chromium[PATH_MAX], studio[PATH_MAX], modules[PATH_MAX];
  char res[PATH_MAX], script[PATH_MAX], manifest[PATH_MAX + 16], puppeteer[PATH_MAX + 64], log[PATH_MAX];
  if (!bench_navsim_exe(exe, sizeof exe)) {
    snprintf(r->error, sizeof r->error, "not measured: the navsim program was not found");
    return;
  }
  if (!find_in_path("node", node, sizeof node)) {
    snprintf(r->error, sizeof r->error, "not measured: node is not installed");
    return;
  }
  const char *ch = getenv("NAV_CHROMIUM");
  snprintf(chromium, sizeof chromium, "%s", ch && *ch ? ch : "/usr/bin/chromium");
  if (access(chromium, X_OK) != 0) {
    snprintf(r->error, sizeof r->error, "not measured: no chromium at %.200s (Debian package chromium)", chromium);
    return;
  }
  locate("NAV_STUDIO_DIR", exe, "../web/studio", studio, sizeof studio);
  snprintf(manifest, sizeof manifest, "%s/manifest.txt", studio);
  if (!is_file(manifest)) {
    snprintf(r->error, sizeof r->error, "not measured: the studio bundle is not built (no %.180s; NAV_BUILD_WEB=ON)",
             manifest);
    return;
  }
  locate("NAV_NODE_MODULES", exe, "../web/npm/node_modules", modules, sizeof modules);
  snprintf(puppeteer, sizeof puppeteer, "%s/puppeteer-core/package.json", modules);
  if (!is_file(puppeteer)) {
    snprintf(r->error, sizeof r->error, "not measured: puppeteer-core is not installed in %.180s", modules);
    return;
  }
  if (!bench_resources_dir(res, sizeof res)) {
    snprintf(r->error, sizeof r->error, "not measured: resources directory not found");
    return;
  }
  /* resources/ is a symbolic link in the build tree: the source tree is its physical parent, which
   * realpath resolves (node would drop "resources/.." textually). */
  char rel[PATH_MAX + 64];
  snprintf(rel, sizeof rel, "%s/../web/studio/bench/first_picture.mjs", res);
  if (realpath(rel, script) == NULL || !is_file(script)) {
    snprintf(r->error, sizeof r->error, "not measured: %.200s is missing (a source tree is needed)", rel);
    return;
  }
  snprintf(log, sizeof log, "%s/logs/studio-first-picture.log", out_dir);
  /* The script's environment names the programs and packages found here. */
  setenv("NAVSIM", exe, 1);
  setenv("NAV_STUDIO_DIR", studio, 1);
  setenv("NAV_NODE_MODULES", modules, 1);
  setenv("NAV_CHROMIUM", chromium, 1);
  const char *samples = full ? "10" : "5";
  char *argv[] = {node, script, (char *)samples, NULL};
  const child_result c = bench_run_child(argv, log, 300.0);
  FILE *f = fopen(log, "r");
  char line[1024];
  double count = NAN, median = NAN, p90 = NAN, before = NAN, est = NAN, prev = NAN, cmed = NAN, cest = NAN;
  double load = NAN;
  while (f && fgets(line, sizeof line, f)) {
    if (strncmp(line, "first_picture_ms:", 17) != 0) continue;
    count = bench_log_field(line, " samples=");
    median = bench_log_field(line, " median=");
    p90 = bench_log_field(line, " p90=");
    before = bench_log_field(line, " before_scene_median=");
    est = bench_log_field(line, " estimate_median=");
    prev = bench_log_field(line, " preview_median=");
    cmed = bench_log_field(line, " cached_median=");
    cest = bench_log_field(line, " cached_estimate_median=");
    load = bench_log_field(line, " loadavg=");
  }
  if (f) fclose(f);
  if (!c.exited_ok || !(median > 0)) {
    snprintf(r->error, sizeof r->error, "not measured: the browser measurement %s (see %.180s)",
             c.timed_out ? "timed out" : "failed", log);
    return;
  }
  r->ok = true;
  r->samples = (long long)count;
  r->wall_s = median * 1e-3;
  r->load1 = load;
  /* The parts (the log has the whole line): page before the scene, validate + estimate, map. */
  snprintf(r->note, sizeof r->note,
           "fresh page, estimate computed: p90 %.0f ms; page %.0f, validate+estimate %.0f, map %.0f ms; "
           "answer cached: %.0f ms (estimate %.0f); load %.1f",
           ms_shown(p90), ms_shown(before), ms_shown(est), ms_shown(prev), ms_shown(cmed), ms_shown(cest),
           isnan(load) ? -1.0 : fmin(load, 999.0));
}

void bench_web_target_md(FILE *md, const bench_row *rows, int n) {
  const bench_row *r = NULL;
  for (int i = 0; i < n; ++i)
    if (strcmp(rows[i].case_name, WEB_CASE) == 0) r = &rows[i];
  if (!r) return;
  fprintf(md, "| browser studio, scene to first picture (urban-drive) | <= %.0f ms (idle machine) | %s | %s |\n",
          WEB_TARGET_MS, r->ok ? r->note : r->error,
          bench_verdict_text(bench_verdict_at_most(r->ok ? r->wall_s * 1e3 : NAN, WEB_TARGET_MS, false)));
}
