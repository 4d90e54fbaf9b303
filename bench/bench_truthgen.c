/*
 * navsim bench, truth + IMU generation of the long drive against gnss-ins-sim, per sample (issue 23
 * item 3; target >= 100x).
 *
 * What is compared. gnss-ins-sim's Sim.run() on its motion_def-long_drive.csv at 200 Hz (ref_frame
 * 0, the shared data set's settings) produces, for every IMU sample, the reference position,
 * velocity and attitude and the ideal accelerometer and gyro outputs (pathgen.path_gen, a
 * forward-Euler integration of its command filter and PD attitude controller), then adds its IMU
 * error model and 1 Hz GPS. The same products here, in one thread, from scenes/long-drive.yaml (the
 * same command list): the truth state at every IMU sample and the ideal increment of every interval
 * (Gauss-Legendre over the interval), generated in order by nav_truth_sample (the sequential
 * generator, whose states' positions come from the increments' position chain: within about 4e-9 m
 * of nav_truth_state's, increments the bits of nav_truth_imu; docs/truth-generation-speed.md), then
 * the scene's IMU error model (nav_imu_model_apply) and receiver (nav_gnss_model_measure at its
 * epochs, from nav_truth_state at the epoch times). Rows:
 *   truth-imu-generation / "truth + ideal IMU"        against gnss-ins-sim's path_gen
 *   truth-imu-generation / "+ IMU errors + GNSS"       against gnss-ins-sim's whole Sim.run
 * Figures are CPU seconds of this process per sample (CLOCK_PROCESS_CPUTIME_ID; the loop is single
 * threaded), median of 9 (quick) or 21 (full) repetitions in three blocks (alternating with the peer's runs
 * when it is measured here), with the wall time beside them.
 *
 * Per sample, not per run: the two simulators plan the same commands to different lengths. Types 2-5
 * "end when converged": gnss-ins-sim converges through a first-order command filter (alpha 0.9 per
 * step) and a PD attitude loop (kp 5, kd 10: poles at -0.53 and -9.5 /s, so a 70 deg turn needs about
 * 20 s to reach its 1e-4 rad threshold) and ends the long drive at 965.18 s (193 036 samples); our
 * segments are minimum-time jerk-limited moves within the same acceleration and rate limits and end
 * it at 810.8 s (162 155 samples). Both are simulations of the same command list; the per-sample
 * cost is the like-for-like measure (ours is higher while turning, when the attitude trigonometry
 * runs, so the 154 s of extra straight driving in gnss-ins-sim's plan would favour us per sample).
 *
 * gnss-ins-sim's figure: measured in this run with --peer-gnss-ins-sim DIR (a checkout of
 * Aceinna/gnss-ins-sim; its Sim.run needs only Debian's python3-numpy; the timing script below
 * is written into DIR_OUT/logs and run by /usr/bin/python3, three times, each run after one block
 * of our generations; the row gives the medians of both sides), else the figure measured on this
 * project's machine, labelled with its date and load.
 */
#define _POSIX_C_SOURCE 200809L
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench_internal.h"
#include "bench_verdict.h"
#include "navcore/nav_sensors.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_truth.h"

#define TG_CASE "truth-imu-generation"
#define TG_PEER_CASE "truth-imu-generation-peer"
#define TG_TARGET 100.0

/* gnss-ins-sim @ 966ff271 on the long drive (193 036 samples), Debian 12 python3 3.11.2,
 * python3-numpy 1.24.2, on this project's 2-core machine,
 * 2026-11-27 07:10 UTC, load average 5.0-5.3 (other engineers' builds): CPU seconds of path_gen
 * (truth + ideal IMU) and of the whole Sim.run (+ IMU errors, GPS, derived data). */
#define TG_PUBLISHED_SAMPLES 193036.0
#define TG_PUBLISHED_PATHGEN_CPU_S 8.290
#define TG_PUBLISHED_RUN_CPU_S 9.928
#define TG_PUBLISHED_SOURCE "measured on this project's 2-core machine, 2026-11-27 07:10 UTC, load 5.0-5.3"
#define TG_PUBLISHED_SHORT "earlier figure (this machine, 2026-11-27, load 5.0-5.3)"

/* The timing script run for --peer-gnss-ins-sim (argv: gnss-ins-sim checkout, motion file). */
static const char k_gis_script[] =
    "# navsim bench: gnss-ins-sim's Sim.run on a motion file with the shared long-drive data set's\n"
    "# settings (200 Hz IMU, 1 Hz GPS, ref_frame 0), CPU seconds of path_gen and of the whole run.\n"
    "import sys, time\n"
    "sys.path.insert(0, sys.argv[1])\n"
    "import numpy as np\n"
    "from gnss_ins_sim.sim import imu_model, ins_sim\n"
    "from gnss_ins_sim.pathgen import pathgen\n"
    "acc = {'gyro_b': np.array([5.0, -3.0, 2.0]), 'gyro_arw': np.array([0.1] * 3),\n"
    "       'gyro_b_stability': np.array([2.0] * 3), 'gyro_b_corr': np.array([3600.0] * 3),\n"
    "       'accel_b': np.array([1.0e-3, -1.0e-3, 5.0e-4]), 'accel_vrw': np.array([0.1] * 3),\n"
    "       'accel_b_stability': np.array([2.0e-4] * 3), 'accel_b_corr': np.array([3600.0] * 3)}\n"
    "orig = pathgen.path_gen\n"
    "tp = {}\n"
    "def timed(*a, **k):\n"
    "    c = time.process_time()\n"
    "    r = orig(*a, **k)\n"
    "    tp['cpu'] = time.process_time() - c\n"
    "    return r\n"
    "pathgen.path_gen = timed\n"
    "imu = imu_model.IMU(accuracy=acc, axis=6, gps=True,\n"
    "                    gps_opt={'stdp': np.array([0.02, 0.02, 0.05]), 'stdv': np.array([0.05] * 3)})\n"
    "np.random.seed(1)\n"
    "sim = ins_sim.Sim([200.0, 1.0, 0.0], sys.argv[2], ref_frame=0, imu=imu, mode=None, env=None,\n"
    "                  algorithm=None)\n"
    "w = time.perf_counter(); c = time.process_time()\n"
    "sim.run(1)\n"
    "run_c = time.process_time() - c; run_w = time.perf_counter() - w\n"
    "print('gnss-ins-sim samples=%d path_gen_cpu_s=%.4f run_cpu_s=%.4f run_wall_s=%.4f'\n"
    "      % (len(sim.dmgr.time.data), tp['cpu'], run_c, run_w))\n";

/* The gnss-ins-sim figures of this suite (NaN: none), for the target line. */
static struct {
  double samples, pathgen_cpu_s, run_cpu_s, run_wall_s;
  bool measured_here;
} s_peer = {NAN, NAN, NAN, NAN, false};
/* Our plan's duration of the long drive [s] (NaN: not generated). */
static double s_planned_s = NAN;

static double cpu_now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One generation of the whole drive: states and increments into arrays of its own (the products
 * must be stored, as gnss-ins-sim stores them), with the sensor models when asked. Returns false
 * with a message on failure. */
static bool generate(const nav_scene *sc, bool sensors, int64_t n, double *cpu_s, double *wall_s, char *msg,
                     size_t msg_size) {
  nav_truth *truth = NULL;
  nav_imu_model *im = NULL;
  nav_gnss_model *gm = NULL;
  nav_gnss_model_config gcfg;
  nav_traj_state *ts = NULL;
  nav_imu_increment *ideal = NULL, *meas = NULL;
  bool ok = false;
  /* Set-up (planning, position checkpoints, catalog models) is timed too: gnss-ins-sim's figure
   * includes its own parsing of the motion file. So is the allocation of the output arrays and
   * the first writes to their pages, in every repetition: gnss-ins-sim creates its arrays inside
   * the timed call, and arrays reused from an earlier repetition would leave the page faults of
   * 39 MB (the long drive's states and increments) out of the median. */
  const double c0 = cpu_now_s(), w0 = bench_now_s();
  ts = malloc((size_t)(n + 1) * sizeof *ts);
  ideal = malloc((size_t)n * sizeof *ideal);
  meas = sensors ? malloc((size_t)n * sizeof *meas) : NULL;
  if (!ts || !ideal || (sensors && !meas)) {
    snprintf(msg, msg_size, "out of memory");
    goto cleanup;
  }
  nav_status st = nav_truth_create_msg(sc, &truth, msg, msg_size);
  if (st != NAV_OK) goto cleanup;
  if (nav_truth_sample_count(truth) != n) {
    snprintf(msg, msg_size, "sample count changed between runs");
    goto cleanup;
  }
  if (sensors) {
    st = nav_imu_model_create(&sc->imu.model, sc->simulation.seed, 0, &im);
    if (st == NAV_OK) st = nav_sim_gnss_config(sc, nav_truth_dt(truth), &gcfg, msg, msg_size);
    if (st == NAV_OK) {
      const nav_frame fr = nav_truth_frame(truth);
      st = nav_gnss_model_create(&gcfg, &fr, sc->simulation.seed, 0, &gm);
    }
    if (st != NAV_OK) {
      if (!msg[0]) snprintf(msg, msg_size, "sensor models: %s", nav_status_str(st));
      goto cleanup;
    }
  }
  const double dt = nav_truth_dt(truth);
  st = nav_truth_state(truth, 0.0, &ts[0]);
  int64_t epoch = 0;
  double t_fix = sensors ? nav_gnss_model_epoch_time_s(gm, 0) : INFINITY;
  for (int64_t k = 1; st == NAV_OK && k <= n; ++k) {
    st = nav_truth_sample(truth, k, &ts[k], &ideal[k - 1]);
    if (st == NAV_OK && sensors) st = nav_imu_model_apply(im, &ideal[k - 1], &meas[k - 1]);
    /* Receiver epochs up to this sample, from the truth at their own time. */
    while (st == NAV_OK && sensors && t_fix <= (double)k * dt) {
      nav_traj_state at;
      nav_gnss_fix fix;
      bool has_fix = false;
      st = nav_truth_state(truth, t_fix, &at);
      if (st == NAV_OK) st = nav_gnss_model_measure(gm, epoch, &at, &fix, &has_fix);
      t_fix = nav_gnss_model_epoch_time_s(gm, ++epoch);
    }
  }
  if (st != NAV_OK) {
    snprintf(msg, msg_size, "generation failed: %s", nav_status_str(st));
    goto cleanup;
  }
  *cpu_s = cpu_now_s() - c0;
  *wall_s = bench_now_s() - w0;
  ok = true;
cleanup:
  nav_gnss_model_destroy(gm);
  nav_imu_model_destroy(im);
  nav_truth_destroy(truth);
  free(meas);
  free(ideal);
  free(ts);
  return ok;
}

/* One run of gnss-ins-sim (its timing script; log DIR_OUT/logs/gnss-ins-sim-INDEX.log): its
 * figures into *gen_s, *run_s and *wall_s (CPU of path_gen, CPU and wall of Sim.run) and its sample count
 * into *samples; false with a message when it cannot run. */
static bool run_peer_once(const char *gis_dir, const char *out_dir, int index, double *samples, double *gen_s,
                          double *run_s, double *wall_s, char *msg, size_t msg_size) {
  char res[PATH_MAX], motion[PATH_MAX + 64], script[PATH_MAX + 64], log[PATH_MAX + 64];
  if (!bench_resources_dir(res, sizeof res)) {
    snprintf(msg, msg_size, "resources directory not found");
    return false;
  }
  snprintf(motion, sizeof motion, "%s/motion_defs/motion_def-long_drive.csv", res);
  snprintf(script, sizeof script, "%s/logs/gnss_ins_sim_time.py", out_dir);
  snprintf(log, sizeof log, "%s/logs/gnss-ins-sim-%d.log", out_dir, index);
  char logs_dir[PATH_MAX + 16];
  snprintf(logs_dir, sizeof logs_dir, "%s/logs", out_dir);
  FILE *f = bench_make_dir(logs_dir) == 0 ? fopen(script, "w") : NULL;
  if (!f || fputs(k_gis_script, f) < 0) {
    if (f) fclose(f);
    snprintf(msg, msg_size, "cannot write %.200s", script);
    return false;
  }
  if (fclose(f) != 0) {
    snprintf(msg, msg_size, "cannot write %.200s", script);
    return false;
  }
  /* Debian's interpreter (python3-numpy): a python3 earlier on PATH may lack it. */
  char *py = access("/usr/bin/python3", X_OK) == 0 ? "/usr/bin/python3" : "python3";
  char *argv[] = {py, script, (char *)gis_dir, motion, NULL};
  const child_result c = bench_run_child(argv, log, 600.0);
  if (!c.exited_ok) {
    snprintf(msg, msg_size, "gnss-ins-sim failed (exit %d%s; see %.150s)", c.exit_code, c.timed_out ? ", timed out" : "",
             log);
    return false;
  }
  FILE *lf = fopen(log, "r");
  char line[512];
  bool found = false;
  while (lf && fgets(line, sizeof line, lf)) {
    if (strncmp(line, "gnss-ins-sim ", 13) != 0) continue;
    *samples = bench_log_field(line, " samples=");
    *gen_s = bench_log_field(line, " path_gen_cpu_s=");
    *run_s = bench_log_field(line, " run_cpu_s=");
    *wall_s = bench_log_field(line, " run_wall_s=");
    found = *samples > 0.0 && *gen_s > 0.0 && *run_s > 0.0;
  }
  if (lf) fclose(lf);
  if (!found) {
    snprintf(msg, msg_size, "no timing line in %.200s", log);
    return false;
  }
  return true;
}

void bench_case_truthgen(bool full, const char *out_dir, const char *gis_dir, bench_row *rows, int *n, int cap) {
  if (*n + 3 > cap) return;
  nav_scene *sc = malloc(sizeof *sc);
  /* No commas: variants are bench.csv fields. */
  const char *variants[2] = {"truth + ideal IMU at every sample", "+ IMU errors + GNSS (as Sim.run)"};
  bench_row *r[2] = {&rows[*n], &rows[*n + 1]};
  for (int v = 0; v < 2; ++v) {
    memset(r[v], 0, sizeof *r[v]);
    snprintf(r[v]->case_name, sizeof r[v]->case_name, "%s", TG_CASE);
    snprintf(r[v]->variant, sizeof r[v]->variant, "%s", variants[v]);
    r[v]->algorithm = "-";
    r[v]->earth_model = "wgs84";
    r[v]->frame = "ned";
    r[v]->rate_hz = 200.0;
    r[v]->truth_sps = r[v]->mech_sps = NAN;
    r[v]->pos_err_m = r[v]->vel_err_mps = r[v]->att_err_rad = r[v]->rms_h_m = NAN;
  }
  *n += 2;
  char msg[200] = "";
  int64_t ns = 0;
  nav_truth *probe = NULL;
  if (!sc || !bench_load_library_scene("long-drive.yaml", sc)) {
    for (int v = 0; v < 2; ++v) snprintf(r[v]->error, sizeof r[v]->error, "scenes/long-drive.yaml not loaded");
  } else if (nav_truth_create_msg(sc, &probe, msg, sizeof msg) != NAV_OK) {
    for (int v = 0; v < 2; ++v) snprintf(r[v]->error, sizeof r[v]->error, "truth: %.200s", msg);
  } else {
    ns = nav_truth_sample_count(probe);
    s_planned_s = (double)ns * nav_truth_dt(probe);
  }
  nav_truth_destroy(probe);
  /* Ours in three blocks, each followed by one run of gnss-ins-sim when it is measured here, so that
   * both meet the same spells of this shared machine: one run of it read 42.6 to 48.2 us per sample
   * within an hour, and a generation of ours takes 60 ms, a block about half a second. */
  enum { TG_BLOCKS = 3, TG_PER_BLOCK_MAX = 7 };
  const int per_block = full ? TG_PER_BLOCK_MAX : 3;
  double cpu[2][TG_BLOCKS * TG_PER_BLOCK_MAX], wall[2][TG_BLOCKS * TG_PER_BLOCK_MAX];
  int got[2] = {0, 0};
  bool failed[2] = {ns <= 0, ns <= 0};
  double pg[TG_BLOCKS], pr[TG_BLOCKS], pw[TG_BLOCKS], psamples = NAN;
  int peer_runs = 0;
  bool peer_ok = gis_dir != NULL;
  char pmsg[240] = "";
  for (int blk = 0; blk < TG_BLOCKS; ++blk) {
    for (int v = 0; v < 2; ++v)
      for (int k = 0; k < per_block && !failed[v]; ++k) {
        msg[0] = '\0';
        if (generate(sc, v == 1, ns, &cpu[v][got[v]], &wall[v][got[v]], msg, sizeof msg)) {
          got[v]++;
        } else {
          failed[v] = true;
          snprintf(r[v]->error, sizeof r[v]->error, "%.200s", msg);
        }
      }
    if (peer_ok) {
      double smp = NAN;
      peer_ok = run_peer_once(gis_dir, out_dir, peer_runs + 1, &smp, &pg[peer_runs], &pr[peer_runs],
                              &pw[peer_runs], pmsg, sizeof pmsg);
      if (peer_ok) {
        psamples = smp;
        peer_runs++;
      }
    }
  }
  for (int v = 0; v < 2; ++v) {
    if (failed[v]) continue;
    const double c = bench_median(cpu[v], got[v]), w = bench_median(wall[v], got[v]);
    r[v]->ok = true;
    r[v]->samples = (long long)ns;
    r[v]->wall_s = w;
    r[v]->truth_sps = (double)ns / c; /* per CPU second */
    r[v]->load1 = bench_load1();
    snprintf(r[v]->note, sizeof r[v]->note,
             "%.0f ns CPU (%.0f ns wall) per sample, median of %d in %d blocks; %.1f s planned",
             1e9 * c / (double)ns, 1e9 * w / (double)ns, got[v], TG_BLOCKS, s_planned_s);
  }
  /* gnss-ins-sim: in this run when asked, else the figure measured on this project's machine. */
  bench_row *p = &rows[*n];
  memset(p, 0, sizeof *p);
  snprintf(p->case_name, sizeof p->case_name, "%s", TG_PEER_CASE);
  snprintf(p->variant, sizeof p->variant, "gnss-ins-sim Sim.run on the long drive");
  p->algorithm = "-";
  p->earth_model = "wgs84";
  p->frame = "ned";
  p->rate_hz = 200.0;
  p->truth_sps = p->mech_sps = NAN;
  p->pos_err_m = p->vel_err_mps = p->att_err_rad = p->rms_h_m = NAN;
  (*n)++;
  const char *label = "measured in this run (median of 3 runs alternating with ours)";
  if (peer_ok && peer_runs == TG_BLOCKS) {
    s_peer.samples = psamples;
    s_peer.pathgen_cpu_s = bench_median(pg, peer_runs);
    s_peer.run_cpu_s = bench_median(pr, peer_runs);
    s_peer.run_wall_s = bench_median(pw, peer_runs);
    s_peer.measured_here = true;
    p->wall_s = s_peer.run_wall_s;
  } else {
    s_peer.samples = TG_PUBLISHED_SAMPLES;
    s_peer.pathgen_cpu_s = TG_PUBLISHED_PATHGEN_CPU_S;
    s_peer.run_cpu_s = TG_PUBLISHED_RUN_CPU_S;
    s_peer.measured_here = false;
    p->wall_s = NAN;
    label = TG_PUBLISHED_SHORT;
  }
  p->ok = true;
  p->samples = (long long)s_peer.samples;
  p->truth_sps = s_peer.samples / s_peer.pathgen_cpu_s;
  p->load1 = bench_load1();
  char note[512];
  snprintf(note, sizeof note, "%s; CPU per sample: path_gen %.1f us, Sim.run %.1f us%s%s", label,
           1e6 * s_peer.pathgen_cpu_s / s_peer.samples, 1e6 * s_peer.run_cpu_s / s_peer.samples,
           pmsg[0] ? "; not run here: " : "", pmsg);
  snprintf(p->note, sizeof p->note, "%.159s", note);
  free(sc);
}

void bench_truthgen_target_md(FILE *md, const bench_row *rows, int n) {
  const bench_row *a = NULL, *b = NULL;
  for (int i = 0; i < n; ++i)
    if (strcmp(rows[i].case_name, TG_CASE) == 0) {
      if (!a)
        a = &rows[i];
      else
        b = &rows[i];
    }
  if (!a || !b || !isfinite(s_peer.samples)) return;
  const char *src = s_peer.measured_here
                        ? "gnss-ins-sim measured in this run, median of 3 runs alternating with ours"
                        : "gnss-ins-sim " TG_PUBLISHED_SOURCE;
  const double peer_gen = s_peer.pathgen_cpu_s / s_peer.samples, peer_run = s_peer.run_cpu_s / s_peer.samples;
  const double ours_gen = a->ok ? 1.0 / a->truth_sps : NAN, ours_run = b->ok ? 1.0 / b->truth_sps : NAN;
  const double ratio_gen = peer_gen / ours_gen, ratio_run = peer_run / ours_run;
  fprintf(md,
          "| truth + IMU generation, long drive, per sample, against gnss-ins-sim | >= %.0fx | truth + ideal IMU "
          "%.0f ns CPU against path_gen %.1f us: %.1fx; with IMU errors and GNSS %.0f ns against Sim.run %.1f us: "
          "%.1fx (%s; ours at load %.1f; per sample because the plans differ: %.1f s here, %.2f s in "
          "gnss-ins-sim, whose type-5 commands converge through a PD loop) | %s |\n",
          TG_TARGET, 1e9 * ours_gen, 1e6 * peer_gen, ratio_gen, 1e9 * ours_run, 1e6 * peer_run, ratio_run, src,
          a->load1, s_planned_s, s_peer.samples / 200.0,
          bench_verdict_text(bench_verdict_at_least(fmin(ratio_gen, ratio_run), TG_TARGET)));
}
