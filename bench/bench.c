/*
 * navsim bench: speed against error for every algorithm x Earth model x rate choice.
 *
 * Each case generates the ideal increments of its scene once (timed: truth generation), then
 * runs the mechanization over the stored increments several times (timed: mechanization only),
 * and reports the closure error at the end of the trajectory. Times are medians of repeated
 * runs in one process, so ratios between variants are meaningful on a noisy machine.
 */
#define _POSIX_C_SOURCE 200809L
#include "bench.h"
#include "bench_internal.h"
#include "bench_verdict.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <sys/stat.h>
#include <time.h>

#include "navcore/nav_errors.h"
#include "navcore/nav_io.h"
#include "navcore/nav_paths.h"
#include "navcore/nav_ins_gnss.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_ins.h"
#include "navcore/nav_truth.h"

bool bench_resources_dir(char *buf, size_t size) {
  if (buf == NULL || size == 0) return false;
  buf[0] = '\0';
  return nav_paths_resources_dir(buf, size);
}

/* Run one scene: time truth generation and mechanization separately; closure at the end. */
void bench_scene(const nav_scene *sc, int reps, bench_row *row) {
  nav_truth *truth = NULL;
  nav_ins *ins = NULL;
  nav_imu_increment *imu = NULL;
  char msg[160];
  row->ok = false;
  row->algorithm = nav_mech_algorithm_name(sc->navigation.algorithm);
  row->earth_model = nav_earth_model_name(sc->earth.model);
  row->frame = sc->earth.model == NAV_EARTH_FLAT ? "flat" : nav_mech_frame_name(sc->navigation.frame);
  row->rate_hz = sc->imu.rate_hz;
  nav_status st = nav_truth_create_msg(sc, &truth, msg, sizeof msg);
  if (st != NAV_OK) {
    snprintf(row->error, sizeof row->error, "truth: %s", msg[0] ? msg : nav_status_str(st));
    goto cleanup;
  }
  const int64_t n = nav_truth_sample_count(truth);
  row->samples = (long long)n;
  imu = malloc((size_t)n * sizeof *imu);
  if (!imu) {
    snprintf(row->error, sizeof row->error, "out of memory for %lld increments", (long long)n);
    goto cleanup;
  }
  double t0 = bench_now_s();
  for (int64_t k = 1; k <= n; ++k) {
    st = nav_truth_imu(truth, k, &imu[k - 1]);
    if (st != NAV_OK) {
      snprintf(row->error, sizeof row->error, "ideal IMU at k = %lld: %s", (long long)k, nav_status_str(st));
      goto cleanup;
    }
  }
  const double truth_s = bench_now_s() - t0;
  row->truth_sps = (double)n / truth_s;

  nav_traj_state ts0, ts1;
  if (nav_truth_state(truth, 0.0, &ts0) != NAV_OK || nav_truth_state(truth, (double)n * nav_truth_dt(truth), &ts1) != NAV_OK) {
    snprintf(row->error, sizeof row->error, "truth state evaluation failed");
    goto cleanup;
  }
  const nav_ins_config cfg = nav_ins_config_from_scene(sc);
  const nav_ins_state s0 = {0.0, ts0.r_fb_f_m, ts0.v_fb_f_mps, ts0.q_b_f};
  double times[16];
  if (reps > 16) reps = 16;
  for (int r = 0; r < reps; ++r) {
    st = nav_ins_create(&cfg, &s0, &ins);
    if (st != NAV_OK) {
      snprintf(row->error, sizeof row->error, "mechanization: %s", nav_status_str(st));
      goto cleanup;
    }
    t0 = bench_now_s();
    for (int64_t k = 0; k < n; ++k) {
      st = nav_ins_step(ins, &imu[k]);
      if (st != NAV_OK) break;
    }
    times[r] = bench_now_s() - t0;
    if (st != NAV_OK) {
      snprintf(row->error, sizeof row->error, "mechanization step: %s", nav_status_str(st));
      goto cleanup;
    }
    if (r + 1 < reps) {
      nav_ins_destroy(ins);
      ins = NULL;
    }
  }
  const double mech_s = bench_median(times, reps);
  row->mech_sps = (double)n / mech_s;
  row->wall_s = truth_s + mech_s;
  const nav_frame fr = nav_truth_frame(truth);
  const nav_epoch_errors e = nav_errors_compute(&fr, &ts1, nav_ins_get_state(ins));
  row->pos_err_m = nav_vec3_norm(e.pos_err_n_m);
  row->vel_err_mps = e.vel_err_mps;
  row->att_err_rad = e.att_err_rad;
  row->ok = true;
cleanup:
  nav_ins_destroy(ins);
  free(imu);
  nav_truth_destroy(truth);
}

/*
 * Whole-pipeline case through nav_sim (truth, sensor models, navigation, errors, statistics):
 * wall time of the run, samples per second over all runs, final and RMS horizontal error.
 */
void bench_sim(const nav_scene *sc, bool ideal, int threads, bench_row *row) {
  nav_sim *sim = NULL;
  row->ok = false;
  row->algorithm = nav_mech_algorithm_name(sc->navigation.algorithm);
  row->earth_model = nav_earth_model_name(sc->earth.model);
  row->frame = sc->earth.model == NAV_EARTH_FLAT ? "flat" : nav_mech_frame_name(sc->navigation.frame);
  row->rate_hz = sc->imu.rate_hz;
  row->truth_sps = NAN;
  nav_status st = nav_sim_create(sc, &sim);
  if (st != NAV_OK) {
    snprintf(row->error, sizeof row->error, "scene: %s", nav_status_str(st));
    return;
  }
  nav_sim_options o = nav_sim_options_default();
  o.ideal = ideal;
  o.threads = threads;
  nav_sim_summary sum;
  const double t0 = bench_now_s();
  st = nav_sim_run(sim, &o, &sum);
  const double wall = bench_now_s() - t0;
  if (st != NAV_OK) {
    snprintf(row->error, sizeof row->error, "%s", nav_sim_last_error(sim));
    nav_sim_destroy(sim);
    return;
  }
  row->samples = (long long)(sum.imu_samples * sum.runs);
  row->wall_s = wall;
  row->mech_sps = (double)row->samples / wall;
  row->pos_err_m = hypot(sum.final.pos_err_h_m, sum.final.pos_err_v_m);
  row->vel_err_mps = sum.final.vel_err_mps;
  row->att_err_rad = sum.final.att_err_rad;
  row->rms_h_m = sum.stats.pos_err_h_m.rms;
  row->ok = true;
  nav_sim_destroy(sim);
}

/*
 * Replay of the shared long drive (../shared/data/gnss-ins-sim-long-drive) against the peers on
 * identical inputs: horizontal RMS over all 193 034 epochs, the whole replay timed (parsing
 * included). Peer figures from the data set's README (KF-GINS 3.3 s wall on this machine).
 */
/* Parsing alone: every record of the three files through the readers [s], or NAN. */
static double replay_parse_s(const char *imu, const char *gnss, const char *ref) {
  const double t0 = bench_now_s();
  nav_rec_reader *r = NULL;
  bool got = true;
  nav_status st = nav_rec_reader_open(imu, NAV_REC_IMU, &r, NULL);
  nav_imu_increment m;
  while (st == NAV_OK && got) st = nav_rec_read_imu(r, &m, &got);
  nav_rec_reader_destroy(r);
  r = NULL;
  got = true;
  if (st == NAV_OK) st = nav_rec_reader_open(gnss, NAV_REC_GNSS, &r, NULL);
  nav_ins_gnss_fix f;
  while (st == NAV_OK && got) st = nav_rec_read_gnss(r, &f, &got);
  nav_rec_reader_destroy(r);
  r = NULL;
  got = true;
  if (st == NAV_OK) st = nav_rec_reader_open(ref, NAV_REC_PVA, &r, NULL);
  nav_rec_pva row;
  while (st == NAV_OK && got) st = nav_rec_read_pva(r, &row, &got);
  nav_rec_reader_destroy(r);
  return st == NAV_OK ? bench_now_s() - t0 : NAN;
}

/* A KF-GINS configuration for the long drive with the values of the data set's README (the run
 * that produced its published figures), output into @p out. @return 0 or -1. */
static int write_kfgins_config(const char *path, const char *imu, const char *gnss, const char *out) {
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  fprintf(f,
          "# KF-GINS configuration written by navsim bench --peer-kfgins: the long drive with the values of\n"
          "# its data set's README (the run behind the published figures).\n"
          "imupath: \"%s\"\ngnsspath: \"%s\"\noutputpath: \"%s\"\n"
          "imudatalen: 7\nimudatarate: 200\nstarttime: 100000.005\nendtime: -1\n"
          "initpos: [31.508183, 120.401989, 0.0]\ninitvel: [0, 0, 0]\ninitatt: [0, 0, -177]\n"
          "initgyrbias: [0, 0, 0]\ninitaccbias: [0, 0, 0]\ninitgyrscale: [0, 0, 0]\ninitaccscale: [0, 0, 0]\n"
          "initposstd: [0.02, 0.02, 0.05]\ninitvelstd: [0.01, 0.01, 0.01]\ninitattstd: [0.05, 0.05, 0.2]\n"
          "initbgstd: [10, 10, 10]\ninitbastd: [150, 150, 150]\ninitsgstd: [100, 100, 100]\n"
          "initsastd: [100, 100, 100]\n"
          "imunoise:\n  arw: [0.1, 0.1, 0.1]\n  vrw: [0.1, 0.1, 0.1]\n  gbstd: [2.0, 2.0, 2.0]\n"
          "  abstd: [20.0, 20.0, 20.0]\n  gsstd: [100.0, 100.0, 100.0]\n  asstd: [100.0, 100.0, 100.0]\n"
          "  corrtime: 1.0\n"
          "antlever: [0, 0, 0]\n",
          imu, gnss, out);
  return fclose(f) == 0 ? 0 : -1;
}

/* "pos_err_h_m": {"rms": X} after the key @p section ("peers_scored": the first peer scored;
 * "errors_at_output_epochs": ours at the same 10 Hz epochs) of a navsim replay summary.json, or NAN. */
static double rms_from_summary(const char *path, const char *section) {
  FILE *f = fopen(path, "r");
  if (!f) return NAN;
  static char buf[1 << 16];
  const size_t len = fread(buf, 1, sizeof buf - 1, f);
  fclose(f);
  buf[len] = '\0';
  const char *p = strstr(buf, section);
  if (p) p = strstr(p, "\"pos_err_h_m\"");
  if (p) p = strstr(p, "\"rms\": ");
  return p ? strtod(p + 7, NULL) : NAN;
}

void bench_replay(const char *data_dir, const char *gnss_file, const nav_scene *cfg_scene, const char *out_dir,
                  const char *peer_exe, bench_row *row, bench_row *peer_row) {
  char imu[4400], gnss[4400], ref[4400];
  snprintf(imu, sizeof imu, "%s/IMU.txt", data_dir);
  snprintf(gnss, sizeof gnss, "%s/%s", data_dir, gnss_file);
  snprintf(ref, sizeof ref, "%s/truth.nav", data_dir);
  row->ok = false;
  row->algorithm = nav_mech_algorithm_name(cfg_scene->navigation.algorithm);
  row->earth_model = "wgs84";
  row->frame = nav_mech_frame_name(cfg_scene->navigation.frame);
  row->rate_hz = 200.0;
  row->truth_sps = NAN;
  nav_replay_config rc = nav_replay_config_default();
  rc.imu_path = imu;
  rc.gnss_path = gnss;
  rc.ref_path = ref;
  rc.nav = nav_ins_gnss_config_from_scene(cfg_scene);
  nav_replay_summary sum;
  nav_diag d;
  /* As navsim replay runs it: the IMU file read once into memory (two threads), the reference
   * read ahead and the epochs scored on a second thread. */
  rc.callbacks_on_worker = true;
  /* Best of 3 for the in-process parts (the machine is shared). */
  double parse = INFINITY, inproc = INFINITY;
  nav_status st = NAV_OK;
  for (int rep = 0; rep < 3 && st == NAV_OK; ++rep) {
    const double tp = replay_parse_s(imu, gnss, ref);
    if (tp < parse) parse = tp;
    const double t0 = bench_now_s();
    nav_rec_imu_array arr;
    memset(&arr, 0, sizeof arr);
    st = nav_rec_imu_array_load(imu, (size_t)1 << 30, &arr, &d);
    rc.imu = st == NAV_OK ? &arr : NULL;
    if (st == NAV_OK) st = nav_replay_run(&rc, &sum, &d);
    const double t = bench_now_s() - t0;
    nav_rec_imu_array_free(&arr);
    rc.imu = NULL;
    if (t < inproc) inproc = t;
  }
  if (st != NAV_OK) {
    snprintf(row->error, sizeof row->error, "replay: %.200s", d.message[0] ? d.message : nav_status_str(st));
    return;
  }
  /* The whole program, as a user runs it (process start, scene, parsing, navigation, scoring,
   * nav/truth/errors CSV and summary.json written atomically): median of 3. With a peer program
   * (--peer-kfgins), its runs alternate with ours, so both see the same load. */
  double whole = NAN, peer_wall = NAN;
  char exe[4096], res[4096], scene[4400], outp[4400], log[4400];
  snprintf(log, sizeof log, "%s/logs", out_dir);
  if (bench_make_dir(log) == 0 && bench_navsim_exe(exe, sizeof exe) && bench_resources_dir(res, sizeof res)) {
    snprintf(scene, sizeof scene, "%s/../scenes/long-drive-replay.yaml", res);
    snprintf(outp, sizeof outp, "%s/logs/replay-%s", out_dir, gnss_file);
    snprintf(log, sizeof log, "%s/logs/replay-%s.log", out_dir, gnss_file);
    char *argv[] = {exe,     "replay", "--imu", imu, "--gnss", gnss,    "--truth", ref,
                    "--scene", scene,  "--out", outp, "--force", "--quiet", NULL};
    char cfg[4500], pout[4500], plog[4500];
    snprintf(cfg, sizeof cfg, "%s/logs/kf-gins-%s.yaml", out_dir, gnss_file);
    snprintf(pout, sizeof pout, "%s/logs/kf-gins-%s", out_dir, gnss_file);
    snprintf(plog, sizeof plog, "%s/logs/kf-gins-%s.log", out_dir, gnss_file);
    const bool peer = peer_exe && bench_make_dir(pout) == 0 && write_kfgins_config(cfg, imu, gnss, pout) == 0;
    char *pargv[] = {(char *)peer_exe, cfg, NULL};
    double ours[3], theirs[3];
    int n_ours = 0, n_theirs = 0;
    for (int rep = 0; rep < 3; ++rep) {
      /* Each run starts with nothing of the previous one's output left to write (untimed). */
      (void)bench_settle_writes(out_dir);
      const child_result c = bench_run_child(argv, log, 120.0);
      if (c.started && c.exited_ok) ours[n_ours++] = c.wall_s;
      if (peer) {
        (void)bench_settle_writes(out_dir);
        const child_result pc = bench_run_child(pargv, plog, 600.0);
        if (pc.started && pc.exited_ok) theirs[n_theirs++] = pc.wall_s;
      }
    }
    if (n_ours == 3) whole = bench_median(ours, n_ours);
    if (peer && n_theirs == 3) peer_wall = bench_median(theirs, n_theirs);
    if (peer_row) {
      snprintf(peer_row->case_name, sizeof peer_row->case_name, "long-drive-replay-peer");
      snprintf(peer_row->variant, sizeof peer_row->variant, "%s", gnss_file);
      peer_row->algorithm = nav_mech_algorithm_name(cfg_scene->navigation.algorithm);
      peer_row->earth_model = "wgs84";
      peer_row->frame = nav_mech_frame_name(cfg_scene->navigation.frame);
      peer_row->rate_hz = 200.0;
      peer_row->load1 = bench_load1();
      if (!peer) {
        snprintf(peer_row->error, sizeof peer_row->error, "cannot write the KF-GINS configuration %.200s", cfg);
      } else if (!isfinite(peer_wall) || !isfinite(whole)) {
        snprintf(peer_row->error, sizeof peer_row->error, "%s failed (see %.200s)", isfinite(whole) ? "KF-GINS" : "navsim replay",
                 isfinite(whole) ? plog : log);
      } else {
        /* The peer's solution scored by navsim replay --peer against the same reference. */
        char nav[4600], sout[4600], slog[4700], sjs[4700], pname[4700];
        snprintf(nav, sizeof nav, "%s/KF_GINS_Navresult.nav", pout);
        snprintf(sout, sizeof sout, "%s/logs/kf-gins-score-%s", out_dir, gnss_file);
        snprintf(slog, sizeof slog, "%s.log", sout);
        snprintf(pname, sizeof pname, "KF-GINS=%s", nav);
        char *sargv[] = {exe,     "replay", "--imu", imu,   "--gnss", gnss,      "--truth", ref,      "--scene",
                         scene,   "--peer", pname,   "--out", sout,    "--force", "--quiet", NULL};
        const child_result sc = bench_run_child(sargv, slog, 120.0);
        snprintf(sjs, sizeof sjs, "%s/summary.json", sout);
        peer_row->ok = true;
        peer_row->wall_s = whole;
        peer_row->peer = "KF-GINS (measured here)";
        peer_row->peer_wall_s = peer_wall;
        /* Both horizontal RMS by the same scorer at the same (10 Hz output) epochs. */
        peer_row->peer_error_m = sc.exited_ok ? rms_from_summary(sjs, "\"peers_scored\"") : NAN;
        peer_row->error_m = sc.exited_ok ? rms_from_summary(sjs, "\"errors_at_output_epochs\"") : NAN;
        peer_row->pos_err_m = peer_row->error_m;
        snprintf(peer_row->note, sizeof peer_row->note,
                 "medians of 3 alternating runs: navsim %.3g s, peer %.3g s (ratio %.3g); RMS of both at 10 Hz, "
                 "same scorer",
                 whole, peer_wall, whole / peer_wall);
      }
    }
  }
  row->samples = sum.imu_steps;
  if (peer_row && peer_row->ok) peer_row->samples = sum.imu_steps;
  row->parse_s = parse;
  row->nav_s = inproc - parse;
  row->wall_s = isfinite(whole) ? whole : inproc;
  row->mech_sps = (double)sum.imu_steps / row->wall_s;
  /* The parts are timed separately (best of 3 each), so they need not add up to the whole. */
  snprintf(row->note, sizeof row->note,
           "%s %.3g s; in-process without output files %.3g s, parsing alone %.3g s (best of 3)",
           isfinite(whole) ? "whole navsim replay (median of 3)" : "the navsim child failed; in-process", row->wall_s,
           inproc, row->parse_s);
  row->load1 = bench_load1();
  row->pos_err_m = sum.stats.pos_h_m.rms;
  row->att_err_rad = sum.stats.yaw_rad.rms;
  row->peer = "KF-GINS (published)";
  row->peer_wall_s = 3.3;
  row->ok = true;
  /* The figure compared: horizontal RMS (full GNSS), or the end error of the first outage. */
  if (strcmp(gnss_file, "GNSS.txt") == 0) {
    row->error_m = sum.stats.pos_h_m.rms;
    row->peer_error_m = 0.0219;
  } else {
    row->error_m = NAN;
    for (long g = 0; g < sum.gap_count && g < NAV_REPLAY_MAX_GAPS; ++g)
      if (sum.gaps[g].has_end_errors && sum.gaps[g].t1_s - sum.gaps[g].t0_s > 30.0) {
        row->error_m = sum.gaps[g].pos_h_end_m;
        break;
      }
    row->peer_error_m = 7.194;
  }
}

/* A scene of the library, found next to the resources directory. */
bool bench_load_library_scene(const char *name, nav_scene *sc) {
  char res[4096], path[4200];
  if (!bench_resources_dir(res, sizeof res)) return false;
  snprintf(path, sizeof path, "%s/../scenes/%s", res, name);
  return nav_scene_read_file(path, sc, NULL, NULL) == NAV_OK;
}

/* The cases of a suite. Each is (case name, variant, scene). */
typedef struct bench_case {
  const char *name;
  char variant[64];
  nav_scene scene;
} bench_case;

static int add_case(bench_case *cases, int n, int cap, const char *name, const nav_scene *sc) {
  if (n >= cap) return n;
  cases[n].name = name;
  cases[n].scene = *sc;
  const char *frame = sc->earth.model == NAV_EARTH_FLAT ? "flat" : nav_mech_frame_name(sc->navigation.frame);
  snprintf(cases[n].variant, sizeof cases[n].variant, "%s/%s/%s/%gHz", nav_mech_algorithm_name(sc->navigation.algorithm),
           nav_earth_model_name(sc->earth.model), frame, sc->imu.rate_hz);
  return n + 1;
}

static int build_cases(bench_case *cases, int cap, bool full) {
  int n = 0;
  const double rates_quick[] = {50.0, 100.0, 200.0};
  const double rates_full[] = {25.0, 50.0, 100.0, 200.0, 400.0};
  const double *rates = full ? rates_full : rates_quick;
  const int n_rates = full ? 5 : 3;
  const nav_mech_algorithm algs[2] = {NAV_MECH_FIRST_ORDER, NAV_MECH_HIGH_ORDER};
  /* Closure on the paper's parametric trajectory (T3.1), flat and WGS-84 (NED and ECEF). */
  for (int a = 0; a < 2; ++a)
    for (int r = 0; r < n_rates; ++r) {
      nav_scene sc = nav_scene_default();
      sc.navigation.algorithm = algs[a];
      sc.imu.rate_hz = rates[r];
      n = add_case(cases, n, cap, "parametric-closure", &sc);
      sc.earth.model = NAV_EARTH_WGS84;
      sc.navigation.frame = NAV_MECH_NED;
      n = add_case(cases, n, cap, "parametric-closure", &sc);
      sc.navigation.frame = NAV_MECH_ECEF;
      n = add_case(cases, n, cap, "parametric-closure", &sc);
    }
  /* Throughput on a longer run (600 s at 200 Hz = 120 000 samples) for stable rates. */
  {
    nav_scene sc = nav_scene_default();
    sc.trajectory.duration_s = full ? 600.0 : 200.0;
    sc.imu.rate_hz = 200.0;
    sc.navigation.algorithm = NAV_MECH_HIGH_ORDER;
    n = add_case(cases, n, cap, "throughput", &sc);
    sc.earth.model = NAV_EARTH_WGS84;
    sc.navigation.frame = NAV_MECH_NED;
    n = add_case(cases, n, cap, "throughput", &sc);
    sc.navigation.frame = NAV_MECH_ECEF;
    n = add_case(cases, n, cap, "throughput", &sc);
  }
  return n;
}

int bench_make_dir(const char *path) {
  char buf[1024];
  if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf) return -1;
  for (char *p = buf + 1; *p; ++p) {
    if (*p != '/') continue;
    *p = '\0';
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) return -1;
    *p = '/';
  }
  return (mkdir(buf, 0777) != 0 && errno != EEXIST) ? -1 : 0;
}

static const char *k_usage_bench =
    "usage: navsim bench [--suite quick|full] [--out DIR] [--peer-kfgins PATH] [--peer-gnss-ins-sim DIR]\n"
    "                    [--quiet]\n"
    "\n"
    "Speed against error: for each algorithm x Earth model x mechanization frame x rate,\n"
    "the throughput of truth generation and of the mechanization (IMU samples per second,\n"
    "single thread; medians of repeated runs) and the closure error with ideal sensors.\n"
    "Writes DIR/bench.csv and DIR/bench.md (default DIR: out/bench) and prints the table.\n"
    "\n"
    "options:\n"
    "  --suite S   quick (default, under a minute) or full\n"
    "  --out DIR   output directory\n"
    "  --peer-kfgins PATH  a KF-GINS executable you built: it runs on the long drive in this suite,\n"
    "              alternating with navsim replay (medians of 3 each), and its solution is scored by\n"
    "              the same code as ours; without it, KF-GINS's published figures are shown, labelled\n"
    "              with the machine they were measured on\n"
    "  --peer-gnss-ins-sim DIR  a checkout of Aceinna/gnss-ins-sim: its Sim.run on the long drive runs\n"
    "              in this suite (Debian's /usr/bin/python3 with python3-numpy), against\n"
    "              our truth + IMU generation per sample; without it, its figure measured on this\n"
    "              project's machine is shown, labelled with date and load\n"
    "Each row records the 1-minute load average when its case was timed (column load1).\n"
    "  --quiet     do not print the table\n"
    "  --programs  print the programs the suite would run (navsim, navview, navstudio) and exit\n"
    "\n"
    "exit codes: 0 success (failed cases are reported in the table), 2 bad options, 1 I/O failure\n";

int navsim_bench(int argc, char **argv) {
  const char *out_dir = "out/bench", *peer_kfgins = NULL, *peer_gis = NULL;
  bool full = false, quiet = false;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      fputs(k_usage_bench, stdout);
      return 0;
    } else if (strcmp(a, "--quiet") == 0) {
      quiet = true;
    } else if (strcmp(a, "--programs") == 0) {
      static const char *const progs[] = {"navsim", "navview", "navstudio"};
      for (size_t k = 0; k < sizeof progs / sizeof progs[0]; ++k) {
        char path[4096];
        printf("%s: %s\n", progs[k], bench_program(progs[k], path, sizeof path) ? path : "(not found)");
      }
      return 0;
    } else if (strcmp(a, "--peer-kfgins") == 0 && i + 1 < argc) {
      peer_kfgins = argv[++i];
      if (access(peer_kfgins, X_OK) != 0) {
        fprintf(stderr, "navsim bench: --peer-kfgins: \"%s\" is not an executable file\n", peer_kfgins);
        return 2;
      }
    } else if (strcmp(a, "--peer-gnss-ins-sim") == 0 && i + 1 < argc) {
      peer_gis = argv[++i];
      char probe[4200];
      snprintf(probe, sizeof probe, "%s/gnss_ins_sim/sim/ins_sim.py", peer_gis);
      if (access(probe, R_OK) != 0) {
        fprintf(stderr, "navsim bench: --peer-gnss-ins-sim: \"%s\" is not a gnss-ins-sim checkout (no %s)\n", peer_gis,
                "gnss_ins_sim/sim/ins_sim.py");
        return 2;
      }
    } else if (strcmp(a, "--stage") == 0 && i + 3 < argc && strcmp(argv[i + 2], "--steps") == 0) {
      /* Hidden: one stage for the FLOP counts under valgrind (bench_report.c). */
      return bench_stage_main(argv[i + 1], atol(argv[i + 3]));
    } else if ((strcmp(a, "--suite") == 0 || strcmp(a, "--out") == 0) && i + 1 < argc) {
      const char *v = argv[++i];
      if (a[2] == 'o') {
        out_dir = v;
      } else if (strcmp(v, "quick") == 0 || strcmp(v, "full") == 0) {
        full = v[0] == 'f';
      } else {
        fprintf(stderr, "navsim bench: --suite: expected quick or full, got \"%s\"\n", v);
        return 2;
      }
    } else {
      fprintf(stderr, "navsim bench: unknown or incomplete option \"%s\" (see navsim bench --help)\n", a);
      return 2;
    }
  }
  const double suite_t0 = bench_now_s();
  enum { CAP = 160 };
  bench_case *cases = calloc(CAP, sizeof *cases);
  bench_row *rows = calloc(CAP, sizeof *rows);
  if (!cases || !rows) {
    free(cases);
    free(rows);
    fprintf(stderr, "navsim bench: out of memory\n");
    return 1;
  }
  const int n = build_cases(cases, CAP, full);
  const int reps = full ? 7 : 5;
  for (int i = 0; i < n; ++i) {
    snprintf(rows[i].case_name, sizeof rows[i].case_name, "%s", cases[i].name);
    snprintf(rows[i].variant, sizeof rows[i].variant, "%s", cases[i].variant);
    rows[i].load1 = bench_load1();
    bench_scene(&cases[i].scene, reps, &rows[i]);
    if (!quiet) fprintf(stderr, "\r  bench: %d/%d", i + 1, n);
  }
  /* Whole-pipeline cases on library scenes. */
  int n_all = n;
  {
    nav_scene *sc = malloc(sizeof *sc);
    if (sc && bench_load_library_scene("long-drive.yaml", sc)) {
      /* Closure of the 965 s-class drive with ideal sensors (target <= 1 mm horizontal). The library
       * scene is integrated (INS/GNSS with a catalog IMU): the closure is that of the free INS. */
      sc->navigation.scheme = NAV_SCHEME_FREE_INS;
      sc->gnss.enabled = false;
      snprintf(rows[n_all].case_name, sizeof rows[n_all].case_name, "long-drive-closure");
      snprintf(rows[n_all].variant, sizeof rows[n_all].variant, "ideal/%s", nav_mech_algorithm_name(sc->navigation.algorithm));
      bench_sim(sc, true, 1, &rows[n_all++]);
      /* The same drive as a closure case: truth generation (segment model, WGS-84, quadrature nodes of the
       * scene) and mechanization timed separately, as for the parametric cases. */
      snprintf(rows[n_all].case_name, sizeof rows[n_all].case_name, "long-drive-truth");
      snprintf(rows[n_all].variant, sizeof rows[n_all].variant, "%s/%s/%s/%gHz",
               nav_mech_algorithm_name(sc->navigation.algorithm), nav_earth_model_name(sc->earth.model),
               nav_mech_frame_name(sc->navigation.frame), sc->imu.rate_hz);
      bench_scene(sc, 3, &rows[n_all++]);
    }
    if (sc && bench_load_library_scene("pedestrian-walk.yaml", sc)) {
      /* What modelling the Earth costs and buys on a short, slow walk: the same scene with the flat
       * model and with WGS-84 (truth and mechanization always use the same model). */
      const nav_earth_model models[2] = {NAV_EARTH_FLAT, NAV_EARTH_WGS84};
      /* The library scene is an INS/GNSS walk with a catalog IMU: this case measures the Earth model
       * alone, with the free INS and perfect sensors. */
      sc->navigation.scheme = NAV_SCHEME_FREE_INS;
      sc->gnss.enabled = false;
      sc->imu.model.gyro.terms = 0;
      sc->imu.model.accel.terms = 0;
      memset(&sc->initial_errors, 0, sizeof sc->initial_errors);
      sc->simulation.runs = 1;
      for (int m = 0; m < 2; ++m) {
        sc->earth.model = models[m];
        snprintf(rows[n_all].case_name, sizeof rows[n_all].case_name, "pedestrian-earth-model");
        snprintf(rows[n_all].variant, sizeof rows[n_all].variant, "%s", nav_earth_model_name(models[m]));
        bench_sim(sc, false, 1, &rows[n_all++]);
      }
    }
    if (sc && bench_load_library_scene("urban-drive.yaml", sc)) {
      /* Monte Carlo throughput against thread count (results are bit-identical). */
      sc->simulation.runs = full ? 16 : 2;
      const int threads[3] = {1, 2, 4};
      for (int t = 0; t < (full ? 3 : 2); ++t) {
        snprintf(rows[n_all].case_name, sizeof rows[n_all].case_name, "monte-carlo-threads");
        snprintf(rows[n_all].variant, sizeof rows[n_all].variant, "%ld runs/%d threads", sc->simulation.runs, threads[t]);
        bench_sim(sc, false, threads[t], &rows[n_all++]);
      }
    }
    /* Peer comparison on the shared recording, when the data set is present next to the project. */
    if (sc && bench_load_library_scene("long-drive-replay.yaml", sc)) {
      char res[4096], data[4200];
      if (bench_resources_dir(res, sizeof res)) {
        snprintf(data, sizeof data, "%s/../../shared/data/gnss-ins-sim-long-drive", res);
        FILE *probe = NULL;
        char imu[4300];
        snprintf(imu, sizeof imu, "%s/IMU.txt", data);
        probe = fopen(imu, "r");
        if (probe) {
          fclose(probe);
          const char *files[2] = {"GNSS.txt", "GNSS_outage.txt"};
          for (int q = 0; q < 2; ++q) {
            snprintf(rows[n_all].case_name, sizeof rows[n_all].case_name, "long-drive-replay");
            snprintf(rows[n_all].variant, sizeof rows[n_all].variant, "%s", files[q]);
            bench_replay(data, files[q], sc, out_dir, peer_kfgins, &rows[n_all], peer_kfgins ? &rows[n_all + 1] : NULL);
            n_all += peer_kfgins ? 2 : 1;
            /* The same figures against the second peer (pyins, README of the data set). */
            if (rows[n_all - (peer_kfgins ? 2 : 1)].ok) {
              rows[n_all] = rows[n_all - (peer_kfgins ? 2 : 1)];
              rows[n_all].peer = "pyins (published)";
              rows[n_all].peer_wall_s = 85.0;
              rows[n_all].peer_error_m = q == 0 ? 0.0222 : 6.742;
              n_all++;
            }
          }
        } else {
          snprintf(rows[n_all].case_name, sizeof rows[n_all].case_name, "long-drive-replay");
          snprintf(rows[n_all].variant, sizeof rows[n_all].variant, "data not found");
          snprintf(rows[n_all].error, sizeof rows[n_all].error, "no %.150s (the shared data set is not next to the project)",
                   imu);
          rows[n_all].algorithm = rows[n_all].earth_model = rows[n_all].frame = "-";
          n_all++;
        }
      }
    }
    free(sc);
  }
  /* Rows of this block not stamped where they were timed: the load now. */
  for (int i = n; i < n_all; ++i)
    if (rows[i].load1 == 0.0) rows[i].load1 = bench_load1();
  if (!quiet) fputc('\n', stderr);
  /* Covariance rate, long-drive per algorithm and rate, MPI ranks, viewer fps, memory (bench_cases2.c). */
  bench_cases2(full, out_dir, rows, &n_all, CAP, quiet);
  /* Truth + IMU generation of the long drive against gnss-ins-sim (bench_truthgen.c). */
  bench_case_truthgen(full, out_dir, peer_gis, rows, &n_all, CAP);

  int rc = 0;
  char path[1200], tmp[1300];
  FILE *csv = NULL, *md = NULL;
  if (bench_make_dir(out_dir) != 0) {
    fprintf(stderr, "navsim bench: cannot create \"%s\": %s\n", out_dir, strerror(errno));
    rc = 1;
    goto done;
  }
  /* bench.csv, written to a temporary name and renamed (atomic). */
  snprintf(path, sizeof path, "%s/bench.csv", out_dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  csv = fopen(tmp, "w");
  if (!csv) {
    fprintf(stderr, "navsim bench: cannot write into \"%s\"\n", out_dir);
    rc = 1;
    goto done;
  }
  fputs("case,variant,algorithm,earth_model,frame,rate_hz,samples,wall_s,samples_per_s,truth_samples_per_s,"
        "mech_samples_per_s,pos_err_m,vel_err_mps,att_err_rad,peer,peer_wall_s,peer_error,error,rms_h_m,peak_rss_mb,"
        "fps,load1,status\n",
        csv);
  for (int i = 0; i < n_all; ++i) {
    const bench_row *r = &rows[i];
    if (r->ok) {
      fprintf(csv, "%s,%s,%s,%s,%s,%g,%lld,%.6g,%.6g,%.6g,%.6g,%.6e,%.6e,%.6e,", r->case_name, r->variant, r->algorithm,
              r->earth_model, r->frame, r->rate_hz, r->samples, r->wall_s,
              r->wall_s > 0 ? (double)r->samples / r->wall_s : 0.0, r->truth_sps, r->mech_sps, r->pos_err_m,
              r->vel_err_mps, r->att_err_rad);
      if (r->peer)
        fprintf(csv, "%s,%.6g,%.6g,%.6g,", r->peer, r->peer_wall_s, r->peer_error_m, r->error_m);
      else
        fputs(",,,,", csv);
      fprintf(csv, "%.6g,%.6g,%.6g,%.3g,ok\n", r->rms_h_m, r->peak_rss_mb, r->fps, r->load1);
    } else {
      fprintf(csv, "%s,%s,%s,%s,%s,%g,%lld,,,,,,,,,,,,,,%.3g,\"failed: %s\"\n", r->case_name, r->variant,
              r->algorithm ? r->algorithm : "-", r->earth_model ? r->earth_model : "-", r->frame ? r->frame : "-",
              r->rate_hz, r->samples, r->load1, r->error);
    }
  }
  {
    const bool bad = ferror(csv) != 0;
    const int cl = fclose(csv);
    csv = NULL;
    if (bad || cl != 0 || rename(tmp, path) != 0) {
      fprintf(stderr, "navsim bench: writing %s failed\n", path);
      remove(tmp);
      rc = 1;
      goto done;
    }
  }
  /* speed_vs_error.png from bench.csv through the viewer, then bench.md (atomic too). */
  char png_note[400];
  bench_report_png(out_dir, png_note, sizeof png_note);
  snprintf(path, sizeof path, "%s/bench.md", out_dir);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  md = fopen(tmp, "w");
  if (!md) {
    fprintf(stderr, "navsim bench: cannot write into \"%s\"\n", out_dir);
    rc = 1;
    goto done;
  }
  fprintf(md, "# navsim bench --suite %s\n\n", full ? "full" : "quick");
  fputs("| case | variant | algorithm | earth | frame | rate [Hz] | samples | wall [s] | truth [samples/s] | "
        "nav [samples/s] | pos err [m] | vel err [m/s] | att err [rad] | load | peer |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
        md);
  for (int i = 0; i < n_all; ++i) {
    const bench_row *r = &rows[i];
    if (r->ok) {
      char peer[160] = "";
      if (r->peer)
        snprintf(peer, sizeof peer, "%s: %.4g m in %.3g s (ours %.4g m)", r->peer, r->peer_error_m, r->peer_wall_s,
                 r->error_m);
      else if (r->peak_rss_mb > 0)
        snprintf(peer, sizeof peer, "peak RSS %.1f MB", r->peak_rss_mb);
      else if (r->fps > 0)
        snprintf(peer, sizeof peer, "%.1f fps", r->fps);
      fprintf(md, "| %s | %s | %s | %s | %s | %g | %lld | %.3g | %.3g | %.3g | %.3e | %.3e | %.3e | %.2g | %s%s%s |\n",
              r->case_name, r->variant, r->algorithm, r->earth_model, r->frame, r->rate_hz, r->samples, r->wall_s,
              r->truth_sps, r->mech_sps, r->pos_err_m, r->vel_err_mps, r->att_err_rad, r->load1, peer,
              r->note[0] && peer[0] ? "; " : "", r->note);
    } else {
      fprintf(md, "| %s | %s | %s | %s | %s | %g | | | | | | | | | failed: %s |\n", r->case_name, r->variant,
              r->algorithm ? r->algorithm : "-", r->earth_model ? r->earth_model : "-", r->frame ? r->frame : "-",
              r->rate_hz, r->error);
    }
  }
  fprintf(md, "\n%s\n", png_note);
  bench_report_md(md, full, out_dir, rows, n_all, bench_now_s() - suite_t0);
  {
    const bool bad = ferror(md) != 0;
    const int cl = fclose(md);
    md = NULL;
    if (bad || cl != 0 || rename(tmp, path) != 0) {
      fprintf(stderr, "navsim bench: writing %s failed\n", path);
      remove(tmp);
      rc = 1;
      goto done;
    }
  }
  if (!quiet) {
    printf("%-24s %-30s %9s %11s %11s %11s %11s\n", "case", "variant", "samples", "truth_sps", "nav_sps", "pos_err_m",
           "att_err_rad");
    for (int i = 0; i < n_all; ++i) {
      const bench_row *r = &rows[i];
      if (r->ok)
        printf("%-24s %-30s %9lld %11.3g %11.3g %11.3e %11.3e\n", r->case_name, r->variant, r->samples, r->truth_sps,
               r->mech_sps, r->pos_err_m, r->att_err_rad);
      else
        printf("%-24s %-30s  failed: %s\n", r->case_name, r->variant, r->error);
    }
    for (int i = 0; i < n_all; ++i)
      if (rows[i].ok && rows[i].peer)
        printf("%-24s %-30s ours %.4g m in %.3g s wall; %s %.4g m in %.3g s\n", rows[i].case_name, rows[i].variant,
               rows[i].error_m, rows[i].wall_s, rows[i].peer, rows[i].peer_error_m, rows[i].peer_wall_s);
    printf("(nav_sps: mechanization alone for the closure cases; the whole pipeline - truth, sensors, navigation,\n"
           " errors - for the scene cases, where truth_sps is not separate; pos_err_m: final error)\n");
    printf("results    %s/bench.csv, %s/bench.md (%s)\n", out_dir, out_dir, png_note);
  }
done:
  if (csv && fclose(csv) != 0) rc = 1;
  if (md && fclose(md) != 0) rc = 1;
  free(cases);
  free(rows);
  return rc;
}
