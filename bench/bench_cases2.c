/*
 * navsim bench, further cases (issue 9 item 1), after bench.c's closure, Earth-model, thread and
 * replay cases:
 *   - long-drive closure per algorithm and IMU rate (ideal sensors, the shared drive's segments);
 *   - covariance propagation every IMU step against every N-th step (cov_decimation) on the
 *     long-drive replay, with the error cost relative to N = 1;
 *   - MPI: the same Monte Carlo under `mpirun -np 1` and `-np 2` (1 thread per rank);
 *   - viewer frames per second on the one-hour 200 Hz case (navview --bench);
 *   - peak resident memory of a Monte Carlo campaign (the full suite: 1000 runs of 1 h at 200 Hz),
 *     from the child's rusage.
 * Child processes are started and timed by bench_child.c; their output goes to DIR/logs/.
 */
#define _POSIX_C_SOURCE 200809L
#define _DEFAULT_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench_internal.h"
#include "bench_verdict.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_paths.h"
#include "navcore/nav_recorded.h"

/* ------------------------------------------------------------------ child processes */

/* This executable (for the child runs). */
bool bench_self_exe(char *buf, size_t cap) {
  return nav_paths_executable(buf, cap);
}

/* A program of this build or install: beside the navsim that started the bench (NAVSIM_PROGRAM,
 * which `navsim bench` sets: an installed navsim-bench lives in libexec/navcore, the programs in
 * bin), else where nav_paths_program finds it (beside this program, libexec, the build tree). */
bool bench_program(const char *name, char *buf, size_t cap) {
  const char *self = getenv("NAVSIM_PROGRAM");
  if (self && self[0] == '/' && access(self, X_OK) == 0) {
    const char *slash = strrchr(self, '/');
    char cand[4400];
    if (snprintf(cand, sizeof cand, "%.*s/%s", (int)(slash - self), self, name) < (int)sizeof cand &&
        access(cand, X_OK) == 0 && strlen(cand) < cap) {
      memcpy(buf, cand, strlen(cand) + 1);
      return true;
    }
  }
  return nav_paths_program(name, buf, cap);
}

bool bench_navsim_exe(char *buf, size_t cap) {
  return bench_program("navsim", buf, cap);
}

const char *bench_navview_exe(void) {
  static char path[4096];
  return bench_program("navview", path, sizeof path) ? path : NULL;
}

double bench_log_field(const char *line, const char *key) {
  const char *p = strstr(line, key);
  return p ? atof(p + strlen(key)) : NAN;
}

bool bench_have_display(void) {
  const char *d = getenv("DISPLAY");
  return d && d[0];
}

static void row_init(bench_row *r, const char *case_name, const char *variant) {
  memset(r, 0, sizeof *r);
  snprintf(r->case_name, sizeof r->case_name, "%s", case_name);
  snprintf(r->variant, sizeof r->variant, "%s", variant);
  r->algorithm = r->earth_model = r->frame = "-";
  r->truth_sps = r->mech_sps = NAN;
  r->pos_err_m = r->vel_err_mps = r->att_err_rad = NAN;
  r->load1 = bench_load1(); /* the load when the case starts */
}

/* ------------------------------------------------------------------ covariance rate */

/* The long-drive replay (full GNSS) with the covariance propagated every N-th IMU step. */
static void replay_decimated(const char *data_dir, const nav_scene *cfg_scene, unsigned decim,
                             nav_filter_discretisation disc, bench_row *row) {
  char imu[4400], gnss[4400], ref[4400];
  snprintf(imu, sizeof imu, "%s/IMU.txt", data_dir);
  snprintf(gnss, sizeof gnss, "%s/GNSS.txt", data_dir);
  snprintf(ref, sizeof ref, "%s/truth.nav", data_dir);
  row->algorithm = nav_mech_algorithm_name(cfg_scene->navigation.algorithm);
  row->earth_model = "wgs84";
  row->frame = nav_mech_frame_name(cfg_scene->navigation.frame);
  row->rate_hz = 200.0 / (double)decim;
  nav_replay_config rc = nav_replay_config_default();
  rc.imu_path = imu;
  rc.gnss_path = gnss;
  rc.ref_path = ref;
  rc.nav = nav_ins_gnss_config_from_scene(cfg_scene);
  rc.nav.filter.cov_decimation = decim;
  rc.nav.filter.discretisation = disc;
  nav_replay_summary sum;
  nav_diag d;
  const double t0 = bench_now_s();
  const nav_status st = nav_replay_run(&rc, &sum, &d);
  const double wall = bench_now_s() - t0;
  if (st != NAV_OK) {
    snprintf(row->error, sizeof row->error, "replay: %.200s", d.message[0] ? d.message : nav_status_str(st));
    return;
  }
  row->samples = sum.imu_steps;
  row->wall_s = wall;
  row->mech_sps = (double)sum.imu_steps / wall;
  row->pos_err_m = sum.stats.pos_h_m.rms;
  row->rms_h_m = sum.stats.pos_h_m.rms;
  row->att_err_rad = sum.stats.yaw_rad.rms;
  row->ok = true;
}

static void case_covariance_rate(bool full, bench_row *rows, int *n, int cap) {
  nav_scene *sc = malloc(sizeof *sc);
  char res[4096], data[4200], probe[4300];
  if (!sc || !bench_load_library_scene("long-drive-replay.yaml", sc) ||
      !bench_resources_dir(res, sizeof res)) {
    free(sc);
    return;
  }
  snprintf(data, sizeof data, "%s/../../shared/data/gnss-ins-sim-long-drive", res);
  snprintf(probe, sizeof probe, "%s/IMU.txt", data);
  if (access(probe, R_OK) != 0) {
    if (*n < cap) {
      row_init(&rows[*n], "covariance-rate", "data not found");
      snprintf(rows[*n].error, sizeof rows[*n].error, "no %.200s", probe);
      (*n)++;
    }
    free(sc);
    return;
  }
  static const unsigned quick[] = {1, 10}, fullv[] = {1, 2, 5, 10, 20, 50};
  const unsigned *dec = full ? fullv : quick;
  const int nd = full ? 6 : 2;
  const int first = *n;
  for (int i = 0; i < nd && *n < cap; ++i) {
    char v[64];
    snprintf(v, sizeof v, "P every %u IMU step%s (%g Hz)", dec[i], dec[i] == 1 ? "" : "s", 200.0 / dec[i]);
    row_init(&rows[*n], "covariance-rate", v);
    replay_decimated(data, sc, dec[i], NAV_FILTER_DISC_SECOND_ORDER, &rows[*n]);
    (*n)++;
  }
  /* Van Loan discretisation at the longest step: what the exact discretisation costs there. */
  if (full && *n < cap) {
    char v[64];
    snprintf(v, sizeof v, "P every %u steps, Van Loan", dec[nd - 1]);
    row_init(&rows[*n], "covariance-rate", v);
    replay_decimated(data, sc, dec[nd - 1], NAV_FILTER_DISC_VAN_LOAN, &rows[*n]);
    (*n)++;
  }
  /* Error cost relative to propagation at every step. */
  if (rows[first].ok)
    for (int i = first + 1; i < *n; ++i)
      if (rows[i].ok)
        snprintf(rows[i].note, sizeof rows[i].note, "h RMS %.6f m (%+.3f %% vs every step), %.2fx its speed",
                 rows[i].rms_h_m, 100.0 * (rows[i].rms_h_m / rows[first].rms_h_m - 1.0),
                 rows[first].wall_s / rows[i].wall_s);
  free(sc);
}

/* ------------------------------------------------------------------ long-drive closure */

static void case_long_drive_closure(bool full, bench_row *rows, int *n, int cap) {
  nav_scene *sc = malloc(sizeof *sc);
  if (!sc || !bench_load_library_scene("long-drive.yaml", sc)) {
    free(sc);
    return;
  }
  static const double quick[] = {100.0, 200.0}, fullv[] = {50.0, 100.0, 200.0, 400.0};
  const double *rates = full ? fullv : quick;
  const int nr = full ? 4 : 2;
  const nav_mech_algorithm algs[2] = {NAV_MECH_FIRST_ORDER, NAV_MECH_HIGH_ORDER};
  for (int a = 0; a < 2; ++a)
    for (int r = 0; r < nr && *n < cap; ++r) {
      nav_scene s = *sc;
      s.navigation.algorithm = algs[a];
      s.imu.rate_hz = rates[r];
      char v[64];
      snprintf(v, sizeof v, "%s/%s/%s/%gHz", nav_mech_algorithm_name(algs[a]),
               nav_earth_model_name(s.earth.model), nav_mech_frame_name(s.navigation.frame), rates[r]);
      row_init(&rows[*n], "long-drive-closure-rate", v);
      bench_scene(&s, full ? 3 : 1, &rows[*n]);
      (*n)++;
    }
  free(sc);
}

/* ------------------------------------------------------------------ MPI ranks */

static void case_mpi(bool full, const char *out_dir, bench_row *rows, int *n, int cap) {
  if (*n + 2 > cap) return;
#ifdef NAVSIM_MPIEXEC
  char exe[4096], scene[4400], res[4096], log[4400], outp[4400];
  if (!bench_navsim_exe(exe, sizeof exe) || !bench_resources_dir(res, sizeof res)) return;
  snprintf(scene, sizeof scene, "%s/../scenes/urban-drive.yaml", res);
  const char *runs = full ? "16" : "2";
  double wall[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k) {
    char v[64];
    snprintf(v, sizeof v, "%s runs/%d rank%s x 1 thread", runs, k + 1, k ? "s" : "");
    bench_row *r = &rows[*n];
    row_init(r, "monte-carlo-mpi", v);
    r->algorithm = "high_order";
    r->earth_model = "wgs84";
    r->frame = "ned";
    r->rate_hz = 100.0;
    snprintf(log, sizeof log, "%s/logs/mpi-np%d.log", out_dir, k + 1);
    snprintf(outp, sizeof outp, "%s/logs/mpi-np%d", out_dir, k + 1);
    char *argv[] = {
        NAVSIM_MPIEXEC, "--allow-run-as-root", "--oversubscribe", "-np", k ? "2" : "1", exe,     "run", scene,
        "--runs",       (char *)runs,          "--threads",       "1",   "--quiet",     "--out", outp,  "--force", NULL};
    const child_result c = bench_run_child(argv, log, 900.0);
    if (!c.started || !c.exited_ok) {
      snprintf(r->error, sizeof r->error, "mpirun %s (see %.200s)", c.timed_out ? "timed out" : "failed",
               log);
    } else {
      r->ok = true;
      r->wall_s = c.wall_s;
      r->samples = 0;
      /* Samples from the summary written by rank 0. */
      char sp[4500];
      snprintf(sp, sizeof sp, "%s/summary.json", outp);
      FILE *f = fopen(sp, "r");
      if (f) {
        char buf[8192];
        const size_t len = fread(buf, 1, sizeof buf - 1, f);
        buf[len] = '\0';
        fclose(f);
        const char *p = strstr(buf, "\"imu_samples\": ");
        if (p) r->samples = atoll(p + 15);
        p = strstr(buf, "\"pos_err_h_m\": ");
        if (p) r->pos_err_m = atof(p + 15);
      }
      r->mech_sps = r->wall_s > 0 ? (double)r->samples / r->wall_s : 0.0;
      wall[k] = c.wall_s;
    }
    (*n)++;
  }
  if (wall[0] > 0 && wall[1] > 0)
    snprintf(rows[*n - 1].note, sizeof rows[*n - 1].note,
             "speed-up %.2fx over 1 rank (wall incl. mpirun start)", wall[0] / wall[1]);
#else
  (void)full;
  (void)out_dir;
  row_init(&rows[*n], "monte-carlo-mpi", "not built");
  snprintf(rows[*n].error, sizeof rows[*n].error, "navsim built without MPI (NAV_MPI=OFF)");
  (*n)++;
#endif
}

/* ------------------------------------------------------------------ viewer fps */

static void case_viewer_fps(bool full, const char *out_dir, bench_row *rows, int *n, int cap) {
  if (*n >= cap) return;
  bench_row *r = &rows[*n];
  row_init(r, "viewer-fps", "1 h 200 Hz, 20 paths, 1000x700");
  r->rate_hz = 200.0;
  (*n)++;
  const char *nv = bench_navview_exe();
  if (!nv) {
    snprintf(r->error, sizeof r->error, "navview not built (NAV_BUILD_VIEWER=OFF): no viewer figure");
    return;
  }
  char log[4400];
  snprintf(log, sizeof log, "%s/logs/navview-bench.log", out_dir);
  char *with_x[] = {"xvfb-run",        "-a", "-s", "-screen 0 1280x1024x24", (char *)nv, "--bench",
                    full ? "20" : "3", NULL};
  char *plain[] = {(char *)nv, "--bench", full ? "20" : "3", NULL};
  const child_result c = bench_run_child(bench_have_display() ? plain : with_x, log, 300.0);
  FILE *f = fopen(log, "r");
  char line[512];
  double fps = NAN, epochs = 0;
  while (f && fgets(line, sizeof line, f)) {
    const char *p = strstr(line, " frames/s");
    if (p) {
      const char *q = p;
      while (q > line && (q[-1] == '.' || (q[-1] >= '0' && q[-1] <= '9')))
        --q;
      fps = atof(q);
    }
    const char *e = strstr(line, " epochs in ");
    if (e) {
      const char *q = e;
      while (q > line && q[-1] >= '0' && q[-1] <= '9')
        --q;
      epochs = atof(q);
    }
  }
  if (f) fclose(f);
  if (!c.exited_ok || !(fps > 0)) {
    snprintf(r->error, sizeof r->error, "navview --bench %s (see %.200s)",
             c.timed_out ? "timed out" : "failed", log);
    return;
  }
  r->ok = true;
  r->fps = fps;
  r->wall_s = c.wall_s;
  r->samples = (long long)epochs;
  snprintf(r->note, sizeof r->note, "peak RSS %.0f MB", c.maxrss_mb);
}

/* ------------------------------------------------------------------ Monte Carlo campaigns */

/*
 * The library's one-hour Monte Carlo scene (scenes/bench-mc-1h.yaml: INS/GNSS survey drive,
 * catalog MEMS IMU, 1 Hz outputs) run by a child `navsim run` on 2 threads: wall time and the
 * child's peak resident memory. rate_hz > 0 rewrites the IMU rate (the memory case runs it at
 * 200 Hz). A wall-time cap keeps the suite finite (NAVSIM_BENCH_MC_TIMEOUT_S overrides it); a
 * capped run reports its peak so far, a lower bound.
 */
static void case_campaign(const char *case_name, long runs, double rate_hz, double cap_s, const char *out_dir,
                          bench_row *rows, int *n, int cap) {
  if (*n >= cap) return;
  char exe[4096], res[4096], src[4400], scene[4400], log[4400], outp[4400];
  if (!bench_navsim_exe(exe, sizeof exe) || !bench_resources_dir(res, sizeof res)) return;
  snprintf(src, sizeof src, "%s/../scenes/bench-mc-1h.yaml", res);
  snprintf(scene, sizeof scene, "%s/logs/%s.yaml", out_dir, case_name);
  bench_row *r = &rows[*n];
  char v[64];
  snprintf(v, sizeof v, "%ld runs x 1 h, %s, 2 threads", runs, rate_hz > 0 ? "200 Hz" : "100 Hz");
  row_init(r, case_name, v);
  r->algorithm = "high_order";
  r->earth_model = "wgs84";
  r->frame = "ned";
  (*n)++;
  /* Copy the scene (with the IMU rate rewritten). */
  FILE *in = fopen(src, "r"), *out = in ? fopen(scene, "w") : NULL;
  if (!in || !out) {
    if (in) fclose(in);
    snprintf(r->error, sizeof r->error, "cannot copy %.200s", src);
    return;
  }
  char line[1024];
  bool in_imu = false;
  r->rate_hz = 100.0;
  while (fgets(line, sizeof line, in)) {
    if (strncmp(line, "imu:", 4) == 0)
      in_imu = true;
    else if (line[0] != ' ' && line[0] != '\n' && line[0] != '#')
      in_imu = false;
    if (in_imu && rate_hz > 0 && strncmp(line, "  rate_hz:", 10) == 0)
      snprintf(line, sizeof line, "  rate_hz: %g\n", rate_hz);
    if (in_imu && strncmp(line, "  rate_hz:", 10) == 0) r->rate_hz = atof(line + 10);
    fputs(line, out);
  }
  fclose(in);
  if (fclose(out) != 0) return;
  snprintf(log, sizeof log, "%s/logs/%s.log", out_dir, case_name);
  snprintf(outp, sizeof outp, "%s/logs/%s", out_dir, case_name);
  const char *env = getenv("NAVSIM_BENCH_MC_TIMEOUT_S");
  if (env && atof(env) > 0) cap_s = atof(env);
  char nruns[32];
  snprintf(nruns, sizeof nruns, "%ld", runs);
  char *argv[] = {exe, "run", scene, "--runs", nruns, "--threads", "2", "--quiet", "--out", outp, "--force", NULL};
  (void)bench_settle_writes(out_dir); /* the earlier cases' files written out first (untimed) */
  const child_result c = bench_run_child(argv, log, cap_s);
  r->peak_rss_mb = c.maxrss_mb;
  r->wall_s = c.wall_s;
  r->samples = (long long)(3600.0 * r->rate_hz + 0.5) * runs;
  r->mech_sps = (double)r->samples / c.wall_s;
  if (c.timed_out) {
    r->ok = true;
    r->mech_sps = NAN;
    snprintf(r->note, sizeof r->note, "stopped at the %.0f s cap: wall and peak RSS are lower bounds", cap_s);
    return;
  }
  if (!c.exited_ok) {
    snprintf(r->error, sizeof r->error, "navsim run failed (see %.200s)", log);
    return;
  }
  r->ok = true;
  char sp[4500];
  snprintf(sp, sizeof sp, "%s/summary.json", outp);
  FILE *s = fopen(sp, "r");
  if (s) {
    char buf[8192];
    const size_t len = fread(buf, 1, sizeof buf - 1, s);
    buf[len] = '\0';
    fclose(s);
    const char *key = "\"imu_samples\": ";
    const char *p = strstr(buf, key);
    if (p) r->samples = atoll(p + strlen(key));
    r->mech_sps = (double)r->samples / c.wall_s;
    key = "\"final_rms_over_runs\": {\"pos_err_h_m\": ";
    p = strstr(buf, key);
    if (p) r->pos_err_m = atof(p + strlen(key));
    key = "\"pos_err_h_m\": {\"rms\": ";
    p = strstr(buf, key);
    if (p) r->rms_h_m = atof(p + strlen(key));
  }
}

void bench_cases2(bool full, const char *out_dir, bench_row *rows, int *n, int cap, bool quiet) {
  char logs[1200];
  snprintf(logs, sizeof logs, "%s/logs", out_dir);
  if (bench_make_dir(logs) != 0) {
    fprintf(stderr, "navsim bench: cannot create \"%s\": %s\n", logs, strerror(errno));
    return;
  }
  const char *steps[6] = {
      "long-drive closure per rate", "covariance rate", "MPI ranks", "viewer fps", "Monte Carlo 1 h",
      "Monte Carlo memory"};
  for (int s = 0; s < 6; ++s) {
    if (!quiet) fprintf(stderr, "  bench: %s...\n", steps[s]);
    switch (s) {
    case 0: case_long_drive_closure(full, rows, n, cap); break;
    case 1: case_covariance_rate(full, rows, n, cap); break;
    case 2: case_mpi(full, out_dir, rows, n, cap); break;
    case 3: case_viewer_fps(full, out_dir, rows, n, cap); break;
    case 4:
      /* Quick: 2 runs (wall and peak RSS); the report projects 1000 runs from the per-stage time. */
      case_campaign("monte-carlo-1h", full ? 1000 : 2, 0.0, full ? 1800.0 : 120.0, out_dir, rows, n, cap);
      break;
    default:
      if (full) case_campaign("monte-carlo-memory", 1000, 200.0, 3600.0, out_dir, rows, n, cap);
      break;
    }
  }
  if (!quiet) fprintf(stderr, "  bench: navstudio live preview...\n");
  bench_case_studio_preview(full, out_dir, rows, n, cap);
  if (!quiet) fprintf(stderr, "  bench: browser studio, scene to first picture...\n");
  bench_case_web_first_picture(full, out_dir, rows, n, cap);
  if (!quiet) fprintf(stderr, "  bench: navsim estimate of the library scenes...\n");
  bench_case_estimate_library(full, out_dir, rows, n, cap);
}
