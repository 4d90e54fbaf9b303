/*
 * navsim run: simulate a scene (one run or a Monte Carlo campaign) and write its result directory.
 *
 * Exit codes: 0 success; 1 failure other than invalid input (I/O, numerical); 2 invalid scene
 * or invalid command line; 3 --strict and a requirement fails.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include <math.h>

#include "run_cmd.h"
#include "cli_util.h"
#include "mpi_run.h"
#include "estimate_cmd.h"
#include "gnss_out.h"
#include "gnss_sat_out.h"
#include "import_cmd.h"
#include "interrupt.h"
#include "kfgins_out.h"
#include "rinex_out.h"
#include "select_cmd.h"
#include "replay_cmd.h"
#include "report_cmd.h"
#include "run_smooth_out.h"
#include "navcore/nav_size_limits.h"
#include "tradeoff_cmd.h"
#include "navcore/nav_io.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_version.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2, EXIT_REQUIREMENT = 3 };

static const char *k_usage_run =
    "usage: navsim run SCENE [--out DIR] [--force] [--seed N] [--runs N] [--threads N] [--ideal] [--quiet]\n"
    "                  [--kml] [--strict] [--allow-large] [--export kfgins|rinex] [--progress-fd N]\n"
    "\n"
    "Run the scene's pipeline (reference trajectory -> ideal IMU increments -> strapdown\n"
    "navigation -> errors against the reference) and write into DIR:\n"
    "  summary.json  scene, seed, timing, final errors, statistics (rms/max/p95 over epochs)\n"
    "  truth.csv     reference state at the output rate\n"
    "  nav.csv       navigation solution at the output rate\n"
    "  errors.csv    navigation minus reference at the output rate (run 0)\n"
    "  imu_errors.csv  simulated sensor errors at the output rate (run 0; only when the scene's IMU\n"
    "                has error terms and without --ideal): measured minus ideal IMU output over the\n"
    "                IMU interval ending at each epoch (one sample, not averaged), gyros in deg/s,\n"
    "                accelerometers in m/s^2\n"
    "  mc_stats.csv  with several runs, per output epoch: mean and RMS over runs of each error\n"
    "                component, the filter's mean reported sigma and the mean NEES (INS/GNSS)\n"
    "  mc_final.csv  with several runs: the final errors of every run\n"
    "  nav_smoothed.csv, smoothed_errors.csv  scenes with navigation.smoother (ins_gnss): the\n"
    "                RTS-smoothed solution of run 0 and its errors (columns of nav.csv / errors.csv);\n"
    "                \"stats_smoothed\" in summary.json: smoothed and forward errors at the output\n"
    "                epochs of every run\n"
    "The directory appears only when complete (it is built under a hidden name and renamed).\n"
    "\n"
    "options:\n"
    "  --out DIR     result directory (default: out/<scene name>). An existing DIR is replaced only\n"
    "                when it is a result directory navsim wrote and holds nothing else; a file, a\n"
    "                symbolic link or any other directory is refused (exit 2) before any work\n"
    "  --force       move whatever is at DIR aside to DIR.old-YYYYmmddTHHMMSS instead of refusing it\n"
    "                (nothing is deleted)\n"
    "  --seed N      random seed, overriding simulation.seed of the scene (0 .. 2^64-1)\n"
    "  --runs N      Monte Carlo runs, overriding simulation.runs (1 .. 1000000)\n"
    "  --threads N   worker threads (default: simulation.threads, or one per core); results are\n"
    "                bit-identical for any thread count\n"
    "                Under mpirun (navsim built with NAV_MPI), the runs are split across the\n"
    "                ranks, each with N threads, and the results are bit-identical to one process;\n"
    "                only rank 0 writes DIR: mpirun -np K navsim run SCENE --runs R --threads N\n"
    "  --ideal       perfect sensors and perfect initial state (a single run)\n"
    "  --quiet       print nothing but errors\n"
    "  --strict      exit 3 when a requirement of the scene fails (verdicts are in summary.json\n"
    "                \"requirements\" and the terminal summary either way)\n"
    "  --kml         also write tracks.kml (reference, estimate of run 0, GNSS fixes; KML 2.2 for\n"
    "                Google Earth) and tracks.csv (see navsim export --help)\n"
    "  --allow-large go ahead above the limits below\n";

/* The rest of navsim run --help (one literal would exceed what C compilers must support). */
static const char *k_usage_run_tail =
    "  --export kfgins  also write run 0's inputs in the KF-GINS (i2Nav) text formats into DIR/kfgins/\n"
    "                (ins_gnss scenes on WGS-84): IMU.txt (every measured increment the navigation\n"
    "                used, and a zero one at t = 0), GNSS.txt (13 columns: every fix the filter\n"
    "                applied, at the receiver rate, outages left out, with the sigmas it used),\n"
    "                truth.nav (the reference at every IMU epoch), init.nav (run 0's initial state,\n"
    "                drawn initial errors included) and kf-gins.yaml (KF-GINS configuration: initial\n"
    "                state, P0, IMU noise model and lever arm of the scene's filter). Time base: scene\n"
    "                time in s (0 at the start), GPS week 0; numbers with 17 digits. Then\n"
    "                navsim replay --imu DIR/kfgins/IMU.txt --gnss DIR/kfgins/GNSS.txt\n"
    "                --truth DIR/kfgins/truth.nav --init DIR/kfgins/init.nav --scene SCENE\n"
    "                reproduces run 0's nav.csv (10 Hz output epochs)\n"
    "  --export rinex  also write run 0's raw GNSS data (scenes with gnss.constellation) as RINEX\n"
    "                3.04 into DIR/rinex/: NAME.obs (C1C pseudorange, D1C Doppler of the satellites\n"
    "                in view at every receiver epoch), NAME.nav (GPS LNAV and GLONASS records of the\n"
    "                simulated orbits) and pvt.csv (our least-squares PVT of the same epochs beside\n"
    "                the reference antenna); docs/rinex.md. --export may be repeated\n"
    "  --progress-fd N  also write the progress as lines \"progress F\" (F the fraction of the job\n"
    "                done, 0 to 1, at most about ten lines a second and a last one at 1) to the\n"
    "                open file descriptor N, for a program that runs navsim (navsim serve)\n"
    "  -h, --help    print this help\n"
    "\n" NAV_LIMITS_HELP "\n"
    "exit codes: 0 success (whether or not requirements pass); 3 --strict and a requirement fails;\n"
    "            2 invalid scene or options; 1 other failure\n";

static long cores(void) {
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? n : 1;
}

/* Files a run writes, opened inside the temporary result directory. */
typedef struct run_out {
  FILE *f[3];
  nav_status st;
  bool quiet_progress;
  double t_last_print;
  double t_start;  /* wall clock at the start of the simulation, for the ETA */
  long runs;       /* Monte Carlo runs of the job */
  FILE *imu_err; /* imu_errors.csv, or NULL when not written */
  navsim_gnss_out *gnss; /* gnss.csv (INS/GNSS scenes), or NULL */
  navsim_run_smooth *smooth; /* navigation.smoother: nav_smoothed.csv, smoothed_errors.csv */
  navsim_gnss_sat_out *gsat; /* gnss_dop.csv, gnss_sats.csv (gnss.constellation), or NULL */
  navsim_kfgins *kfgins;     /* --export kfgins, or NULL */
  char kfgins_msg[256];      /* what the kfgins export reported on failure */
  int progress_fd;           /* --progress-fd, or -1 */
  double t_last_fd;          /* wall clock of the last line written there */
  navsim_rinex *rinex;       /* --export rinex, or NULL */
  char rinex_msg[256];       /* what the rinex export reported on failure */
} run_out;

static const char *k_imu_errors_header =
    "t_s,gyro_err_x_dps,gyro_err_y_dps,gyro_err_z_dps,accel_err_x_mps2,accel_err_y_mps2,accel_err_z_mps2\n";

/* One imu_errors.csv row: (measured - ideal) / dt of the interval ending at the epoch, i.e. the
 * sensor error as a rate (deg/s only here, at the output edge). No row at t = 0 (no interval). */
static nav_status write_imu_error_row(FILE *f, const nav_sim_record *r) {
  if (!r->imu_ideal || !r->imu_measured) return NAV_OK;
  const double dt = r->imu_ideal->dt_s;
  const nav_vec3 dw = nav_vec3_sub(r->imu_measured->dtheta_b_rad, r->imu_ideal->dtheta_b_rad);
  const nav_vec3 df = nav_vec3_sub(r->imu_measured->dv_b_mps, r->imu_ideal->dv_b_mps);
  const double k = NAV_RAD2DEG / dt;
  const int n = fprintf(f, "%.17g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n", r->imu_ideal->t_s, dw.x * k, dw.y * k, dw.z * k,
                        df.x / dt, df.y / dt, df.z / dt);
  return n < 0 ? NAV_ERR_IO : NAV_OK;
}

static nav_callback_result on_record(void *user, const nav_sim_record *r) {
  run_out *o = user;
  for (int i = 0; i < 3; ++i) {
    const nav_status st = nav_csv_write_row(o->f[i], (nav_csv_table)i, r);
    if (st != NAV_OK) {
      o->st = st;
      return NAV_STOP;
    }
  }
  if (o->gsat) {
    const nav_status st = navsim_gnss_sat_out_record(o->gsat, r);
    if (st != NAV_OK) {
      o->st = st;
      return NAV_STOP;
    }
  }
  if (o->gnss) {
    const nav_status st = navsim_gnss_out_record(o->gnss, r);
    if (st != NAV_OK) {
      o->st = st;
      return NAV_STOP;
    }
  }
  if (o->kfgins) {
    const nav_status st = navsim_kfgins_record(o->kfgins, r, o->kfgins_msg, sizeof o->kfgins_msg);
    if (st != NAV_OK) {
      o->st = st;
      return NAV_STOP;
    }
  }
  if (o->rinex) {
    const nav_status st = navsim_rinex_record(o->rinex, r, o->rinex_msg, sizeof o->rinex_msg);
    if (st != NAV_OK) {
      o->st = st;
      return NAV_STOP;
    }
  }
  if (o->imu_err) {
    const nav_status st = write_imu_error_row(o->imu_err, r);
    if (st != NAV_OK) {
      o->st = st;
      return NAV_STOP;
    }
  }
  return NAV_CONTINUE;
}

static nav_callback_result on_smoothed(void *user, const nav_sim_record *r) {
  run_out *o = user;
  const nav_status st = navsim_run_smooth_record(o->smooth, r);
  if (st != NAV_OK) {
    o->st = st;
    return NAV_STOP;
  }
  return NAV_CONTINUE;
}

/* --progress-fd: one "progress F" line, at most about ten a second (the last one always). */
static void progress_line(run_out *o, double fraction, double t) {
  if (o->progress_fd < 0 || (t - o->t_last_fd < 0.1 && fraction < 1.0)) return;
  char line[64];
  const int n = snprintf(line, sizeof line, "progress %.6f\n", fraction);
  for (int off = 0; n > 0 && off < n;) {
    const ssize_t w = write(o->progress_fd, line + off, (size_t)(n - off));
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) {
      o->progress_fd = -1; /* the reader went away: stop reporting, keep running */
      break;
    }
    off += (int)w;
  }
  o->t_last_fd = t;
}

static nav_callback_result on_progress(void *user, const nav_progress *p) {
  run_out *o = user;
  const double t = navsim_now_s();
  progress_line(o, p->fraction, t);
  if (o->quiet_progress) return NAV_CONTINUE;
  if (t - o->t_last_print > 0.2 || p->fraction >= 1.0) {
    /* Runs done and the time left, extrapolated from the fraction of the job done so far. */
    const long done = (long)floor(p->fraction * (double)o->runs + 1e-9);
    const double el = t - o->t_start;
    if (p->fraction > 0.0 && p->fraction < 1.0) {
      const double eta = el * (1.0 - p->fraction) / p->fraction;
      fprintf(stderr, "\r  simulating: %5.1f %%  runs %ld/%ld  elapsed %.0f s  ETA %.0f s   ", 100.0 * p->fraction,
              done, o->runs, el, eta);
    } else {
      fprintf(stderr, "\r  simulating: %5.1f %%  runs %ld/%ld  elapsed %.0f s             ", 100.0 * p->fraction,
              done, o->runs, el);
    }
    if (p->fraction >= 1.0) fputc('\n', stderr);
    o->t_last_print = t;
  }
  return NAV_CONTINUE;
}

int navsim_run(int argc, char **argv) {
  const char *scene_path = NULL, *out_dir = NULL;
  bool ideal = false, quiet = false, have_seed = false, kml = false, strict = false, force = false,
       allow_large = false, export_kfgins = false, export_rinex = false;
  uint64_t seed = 0, runs = 0, threads = 0;
  int progress_fd = -1;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (navsim_is_help(a)) {
      fputs(k_usage_run, stdout);
      fputs(k_usage_run_tail, stdout);
      return EXIT_OK;
    } else if (strcmp(a, "--kml") == 0) {
      kml = true;
    } else if (strcmp(a, "--force") == 0) {
      force = true;
    } else if (strcmp(a, "--strict") == 0) {
      strict = true;
    } else if (strcmp(a, "--allow-large") == 0) {
      allow_large = true;
    } else if (strcmp(a, "--ideal") == 0) {
      ideal = true;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = true;
    } else if (strcmp(a, "--runs") == 0 || strcmp(a, "--threads") == 0) {
      if (!navsim_need_value("run", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      uint64_t *dst = a[2] == 'r' ? &runs : &threads;
      const uint64_t max = a[2] == 'r' ? (uint64_t)NAV_SCENE_MAX_RUNS : 256u;
      if (!navsim_parse_u64(v, dst) || *dst < 1 || *dst > max) {
        fprintf(stderr, "navsim run: %s: expected an integer in [1, %llu], got \"%s\"\n", a, (unsigned long long)max, v);
        return EXIT_INVALID;
      }
    } else if (strcmp(a, "--progress-fd") == 0) {
      if (!navsim_need_value("run", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      uint64_t fd = 0;
      if (!navsim_parse_u64(v, &fd) || fd < 3 || fd > 1024 || fcntl((int)fd, F_GETFD) == -1) {
        fprintf(stderr, "navsim run: --progress-fd: expected an open file descriptor in [3, 1024], got \"%s\"\n", v);
        return EXIT_INVALID;
      }
      progress_fd = (int)fd;
    } else if (strcmp(a, "--export") == 0) {
      if (!navsim_need_value("run", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      /* One format per --export; the option may be repeated. */
      if (strcmp(v, "kfgins") == 0) {
        export_kfgins = true;
      } else if (strcmp(v, "rinex") == 0) {
        export_rinex = true;
      } else {
        fprintf(stderr, "navsim run: --export: expected kfgins or rinex, got \"%s\"\n", v);
        return EXIT_INVALID;
      }
    } else if (strcmp(a, "--out") == 0 || strcmp(a, "--seed") == 0) {
      if (!navsim_need_value("run", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (a[2] == 'o') {
        out_dir = v;
      } else if (!navsim_parse_u64(v, &seed)) {
        fprintf(stderr, "navsim run: --seed: expected an integer in [0, 2^64-1], got \"%s\"\n", v);
        return EXIT_INVALID;
      } else {
        have_seed = true;
      }
    } else if (a[0] == '-' && a[1] != '\0') {
      return navsim_unknown_option("run", a);
    } else if (!scene_path) {
      scene_path = a;
    } else {
      fprintf(stderr, "navsim run: only one SCENE may be given (got \"%s\" and \"%s\")\n", scene_path, a);
      return EXIT_INVALID;
    }
  }
  if (!scene_path) {
    fprintf(stderr, "navsim run: missing SCENE\n%s%s", k_usage_run, k_usage_run_tail);
    return EXIT_INVALID;
  }

  nav_scene scene;
  int rc = navsim_load_scene(scene_path, &scene);
  if (rc != EXIT_OK) return rc;
  if (have_seed) scene.simulation.seed = seed;
  if (runs > 0) scene.simulation.runs = (long)runs;
  if (export_kfgins && navsim_kfgins_unsupported(&scene)) {
    fprintf(stderr, "%s: error: --export kfgins: %s\n", scene_path, navsim_kfgins_unsupported(&scene));
    nav_scene_release(&scene);
    return EXIT_INVALID;
  }
  if (export_rinex && navsim_rinex_unsupported(&scene)) {
    fprintf(stderr, "%s: error: --export rinex: %s\n", scene_path, navsim_rinex_unsupported(&scene));
    nav_scene_release(&scene);
    return EXIT_INVALID;
  }
  if (threads == 0) threads = scene.simulation.threads > 0 ? (uint64_t)scene.simulation.threads : (uint64_t)cores();
  char default_dir[600];
  if (!out_dir) {
    char nm[NAV_SCENE_NAME_MAX];
    navsim_safe_name(nm, sizeof nm, scene.name, "scene");
    snprintf(default_dir, sizeof default_dir, "out/%s", nm);
    out_dir = default_dir;
  }
  /* Refuse an --out that holds what navsim did not write before any work (every rank sees the
     same file system, so under mpirun all ranks stop alike). */
  rc = navsim_out_check("run", out_dir, force);
  if (rc != EXIT_OK) {
    nav_scene_release(&scene);
    return rc;
  }
  {
    /* Result files and memory predicted from the scene, refused beyond the limits before any
     * work (every MPI rank decides the same). */
    nav_size_prediction pred;
    nav_predict_run(&scene, ideal, (long)threads, kml, &pred);
    if (export_kfgins) nav_predict_add_kfgins(&scene, &pred);
    rc = nav_size_check("run", scene_path, &pred, allow_large, false);
    if (rc != EXIT_OK) {
      nav_scene_release(&scene);
      return rc;
    }
  }
  /* Under mpirun: ranks other than 0 simulate their share of the runs and stop here (mpi_run.c). */
  int mpi_rc = EXIT_OK;
  if (navsim_mpi_worker(&scene, ideal, (int)threads, &mpi_rc)) {
    nav_scene_release(&scene);
    return mpi_rc;
  }

  nav_sim *sim = NULL;
  bool committed = false; /* the result directory is in place */
  nav_resultdir *rd = NULL;
  nav_req_evaluator *req_ev = NULL; /* requirements of the scene (nav_requirements.h) */
  nav_requirement_verdict *verdicts = NULL;
  run_out o = {{NULL, NULL, NULL}, NAV_OK, quiet || !isatty(STDERR_FILENO), 0.0, navsim_now_s(),
               scene.simulation.runs, NULL, NULL, NULL, NULL, NULL, "", progress_fd, 0.0, NULL, ""};
  static const char *names[3] = {"truth.csv", "nav.csv", "errors.csv"};
  nav_status st = nav_sim_create(&scene, &sim);
  if (st != NAV_OK) {
    fprintf(stderr, "navsim run: %s: cannot set up the simulation: %s\n", scene_path, nav_status_str(st));
    rc = EXIT_FAIL;
    goto cleanup;
  }
  rc = navsim_attach_gnss_file("run", &scene, sim, NULL);
  if (rc != EXIT_OK) goto cleanup;
  navsim_interrupt_arm(sim); /* SIGINT / SIGTERM: cancel, remove the temporary directory */
  rc = navsim_out_begin("run", out_dir, force, &rd);
  if (rc != EXIT_OK) goto cleanup;
  for (int i = 0; i < 3; ++i) {
    const char *file = nav_resultdir_file(rd, names[i]);
    o.f[i] = file ? fopen(file, "w") : NULL;
    if (!o.f[i] || nav_csv_write_header(o.f[i], (nav_csv_table)i) != NAV_OK) {
      fprintf(stderr, "navsim run: cannot write %s in \"%s\"\n", names[i], out_dir);
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  if (!ideal && (scene.imu.model.gyro.terms | scene.imu.model.accel.terms) != 0) {
    const char *file = nav_resultdir_file(rd, "imu_errors.csv");
    o.imu_err = file ? fopen(file, "w") : NULL;
    if (!o.imu_err || fputs(k_imu_errors_header, o.imu_err) < 0) {
      fprintf(stderr, "navsim run: cannot write imu_errors.csv in \"%s\"\n", out_dir);
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }

  {
    /* gnss.csv (fixes of run 0) and gnss_outages.csv for the viewer; INS/GNSS scenes only. */
    const char *gf = nav_resultdir_file(rd, "gnss.csv");
    char of[4200];
    snprintf(of, sizeof of, "%s", gf ? gf : "");
    const char *ofile = nav_resultdir_file(rd, "gnss_outages.csv");
    const nav_status gst = (!gf || !ofile) ? NAV_ERR_IO : navsim_gnss_out_begin(&scene, ideal, of, ofile, &o.gnss);
    if (gst != NAV_OK) {
      fprintf(stderr, "navsim run: cannot write gnss.csv / gnss_outages.csv in \"%s\": %s\n", out_dir,
              nav_status_str(gst));
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }

  if (scene.gnss.constellation.enabled) {
    /* gnss_dop.csv and gnss_sats.csv: satellites in view along the trajectory (issue 22). */
    const char *df = nav_resultdir_file(rd, "gnss_dop.csv");
    char dp[4200];
    snprintf(dp, sizeof dp, "%s", df ? df : "");
    const char *sf = nav_resultdir_file(rd, "gnss_sats.csv");
    char sp[4200];
    snprintf(sp, sizeof sp, "%s", sf ? sf : "");
    const char *mf = nav_resultdir_file(rd, "gnss_mask.csv");
    const nav_status gst = (!df || !sf || !mf) ? NAV_ERR_IO : navsim_gnss_sat_out_begin(&scene, dp, sp, mf, &o.gsat);
    if (gst != NAV_OK) {
      fprintf(stderr, "navsim run: cannot write gnss_dop.csv / gnss_sats.csv in \"%s\": %s\n", out_dir,
              nav_status_str(gst));
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  if (export_kfgins) {
    st = navsim_kfgins_begin(&scene, ideal, rd, &o.kfgins, o.kfgins_msg, sizeof o.kfgins_msg);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim run: --export kfgins: %s\n", o.kfgins_msg[0] ? o.kfgins_msg : nav_status_str(st));
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }

  if (export_rinex) {
    st = navsim_rinex_begin(&scene, ideal, rd, &o.rinex, o.rinex_msg, sizeof o.rinex_msg);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim run: --export rinex: %s\n", o.rinex_msg[0] ? o.rinex_msg : nav_status_str(st));
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }

  if (scene.navigation.smoother && navsim_run_smooth_begin(rd, &o.smooth) != NAV_OK) {
    fprintf(stderr, "navsim run: cannot write nav_smoothed.csv / smoothed_errors.csv in \"%s\"\n", out_dir);
    rc = EXIT_FAIL;
    goto cleanup;
  }

  nav_sim_options opts = nav_sim_options_default();
  opts.ideal = ideal;
  opts.threads = (int)threads;
  opts.record = on_record;
  if (o.smooth) opts.smoothed_record = on_smoothed;
  opts.progress = on_progress;
  opts.user = &o;
  nav_run_observer req_obs;
  if (scene.n_requirements > 0) {
    st = nav_req_evaluator_create_for_scene(&scene, ideal, &req_ev);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim run: %s: cannot set up the requirement evaluation: %s\n", scene_path,
              nav_status_str(st));
      rc = EXIT_FAIL;
      goto cleanup;
    }
    req_obs = nav_req_evaluator_observer(req_ev);
    opts.observer = &req_obs;
  }
  nav_sim_summary sum;
  const double t0 = navsim_now_s();
  st = navsim_mpi_sim_run(sim, &opts, &sum); /* nav_sim_run, over every MPI rank when under mpirun */
  const double wall = navsim_now_s() - t0;
  if (navsim_interrupted()) {
    rc = 128 + navsim_interrupted();
    goto cleanup;
  }
  if (st != NAV_OK || o.st != NAV_OK) {
    if (o.st != NAV_OK && o.kfgins_msg[0]) fprintf(stderr, "navsim run: --export kfgins: %s\n", o.kfgins_msg);
    else if (o.st != NAV_OK && o.rinex_msg[0]) fprintf(stderr, "navsim run: --export rinex: %s\n", o.rinex_msg);
    else if (o.st != NAV_OK) fprintf(stderr, "navsim run: writing results failed: %s\n", nav_status_str(o.st));
    else fprintf(stderr, "navsim run: %s: %s\n", scene_path, nav_sim_last_error(sim));
    rc = EXIT_FAIL;
    goto cleanup;
  }
  for (int i = 0; i < 3; ++i) {
    const bool bad = ferror(o.f[i]) != 0;
    const int cl = fclose(o.f[i]);
    o.f[i] = NULL;
    if (bad || cl != 0) {
      fprintf(stderr, "navsim run: writing %s failed\n", names[i]);
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  if (o.imu_err) {
    const bool bad = ferror(o.imu_err) != 0;
    const int cl = fclose(o.imu_err);
    o.imu_err = NULL;
    if (bad || cl != 0) {
      fprintf(stderr, "navsim run: writing imu_errors.csv failed\n");
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  if (!navsim_gnss_out_end(o.gnss)) {
    o.gnss = NULL;
    fprintf(stderr, "navsim run: writing gnss.csv failed\n");
    rc = EXIT_FAIL;
    goto cleanup;
  }
  o.gnss = NULL;
  if (!navsim_gnss_sat_out_end(o.gsat)) {
    o.gsat = NULL;
    fprintf(stderr, "navsim run: writing gnss_dop.csv / gnss_sats.csv failed\n");
    rc = EXIT_FAIL;
    goto cleanup;
  }
  o.gsat = NULL;
  if (o.kfgins) {
    st = navsim_kfgins_end(o.kfgins, o.kfgins_msg, sizeof o.kfgins_msg);
    o.kfgins = NULL;
    if (st != NAV_OK) {
      fprintf(stderr, "navsim run: --export kfgins: %s\n", o.kfgins_msg[0] ? o.kfgins_msg : nav_status_str(st));
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  if (o.rinex) {
    st = navsim_rinex_end(o.rinex, o.rinex_msg, sizeof o.rinex_msg);
    o.rinex = NULL;
    if (st != NAV_OK) {
      fprintf(stderr, "navsim run: --export rinex: %s\n", o.rinex_msg[0] ? o.rinex_msg : nav_status_str(st));
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  st = navsim_run_smooth_end(o.smooth);
  o.smooth = NULL;
  if (st != NAV_OK) {
    fprintf(stderr, "navsim run: writing nav_smoothed.csv / smoothed_errors.csv failed\n");
    rc = EXIT_FAIL;
    goto cleanup;
  }
  if (sum.runs > 1) {
    /* Monte Carlo statistics over runs per output epoch, and the final errors of every run. */
    size_t ne = 0, nf = 0;
    const nav_sim_envelope_point *env = nav_sim_envelope(sim, &ne);
    const nav_sim_run_final *fin = nav_sim_finals(sim, &nf);
    const char *file = nav_resultdir_file(rd, "mc_stats.csv");
    FILE *f = (env && file) ? fopen(file, "w") : NULL;
    bool bad = env && !f;
    if (f) {
      fputs("t_s,pos_mean_n_m,pos_mean_e_m,pos_mean_d_m,pos_rms_n_m,pos_rms_e_m,pos_rms_d_m,pos_h_rms_m,pos_h_max_m,"
            "vel_rms_mps,att_rms_rad,pos_sd_reported_n_m,pos_sd_reported_e_m,pos_sd_reported_d_m,nees9_mean\n",
            f);
      for (size_t i = 0; i < ne; ++i) {
        const nav_sim_envelope_point *p = &env[i];
        fprintf(f, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", p->t_s,
                p->pos_mean_n_m.x, p->pos_mean_n_m.y, p->pos_mean_n_m.z, p->pos_rms_n_m.x, p->pos_rms_n_m.y,
                p->pos_rms_n_m.z, p->pos_h_rms_m, p->pos_h_max_m, p->vel_rms_mps, p->att_rms_rad,
                p->pos_sd_reported_n_m.x, p->pos_sd_reported_n_m.y, p->pos_sd_reported_n_m.z, p->nees9_mean);
      }
      bad = ferror(f) != 0;
      if (fclose(f) != 0) bad = true;
    }
    file = nav_resultdir_file(rd, "mc_final.csv");
    f = (fin && file) ? fopen(file, "w") : NULL;
    if (fin && !f) bad = true;
    if (f) {
      fputs("run,t_s,pos_err_n_m,pos_err_e_m,pos_err_d_m,pos_err_h_m,pos_err_v_m,vel_err_mps,att_err_rad,yaw_err_deg\n", f);
      for (size_t i = 0; i < nf; ++i) {
        const nav_epoch_errors *e = &fin[i].err;
        fprintf(f, "%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", fin[i].run, e->t_s, e->pos_err_n_m.x,
                e->pos_err_n_m.y, e->pos_err_n_m.z, e->pos_err_h_m, e->pos_err_v_m, e->vel_err_mps, e->att_err_rad,
                e->euler_err.yaw_rad * NAV_RAD2DEG);
      }
      if (ferror(f) != 0) bad = true;
      if (fclose(f) != 0) bad = true;
    }
    if (bad) {
      fprintf(stderr, "navsim run: writing mc_stats.csv / mc_final.csv failed\n");
      rc = EXIT_FAIL;
      goto cleanup;
    }
  }
  if (kml && navsim_run_tracks(rd, out_dir) != 0) {
    rc = EXIT_FAIL;
    goto cleanup;
  }
  nav_run_info info = {scene_path, scene.simulation.seed, ideal, wall, NULL, 0};
  if (req_ev) {
    verdicts = calloc((size_t)scene.n_requirements, sizeof *verdicts);
    st = verdicts ? nav_req_evaluator_finish(req_ev, verdicts) : NAV_ERR_NO_MEMORY;
    if (st != NAV_OK) {
      fprintf(stderr, "navsim run: evaluating the requirements failed: %s\n", nav_status_str(st));
      rc = EXIT_FAIL;
      goto cleanup;
    }
    info.requirements = verdicts;
    info.n_requirements = scene.n_requirements;
  }
  st = nav_summary_write_json(nav_resultdir_file(rd, "summary.json"), &scene, &info, &sum);
  if (st != NAV_OK) {
    fprintf(stderr, "navsim run: writing summary.json failed\n");
    rc = EXIT_FAIL;
    goto cleanup;
  }
  if (navsim_interrupted()) {
    rc = 128 + navsim_interrupted();
    goto cleanup;
  }
  rc = navsim_out_commit("run", rd);
  rd = NULL;
  if (rc != EXIT_OK) goto cleanup;
  committed = true;
  if (!quiet) {
    printf("scene      %s (%s, %s Earth, %s mechanization%s)\n", scene.name, scene_path,
           nav_earth_model_name(scene.earth.model), nav_mech_algorithm_name(scene.navigation.algorithm),
           ideal ? ", ideal sensors" : "");
    navsim_print_recorded_fit(stdout, "reference  ", &scene);
    navsim_print_gnss_file(stdout, "gnss       ", &scene);
    printf("simulated  %ld run%s of %.3f s, %" PRId64 " IMU samples each at %g Hz in %.3f s wall (%.3g samples/s, "
           "%d thread%s)\n",
           sum.runs, sum.runs == 1 ? "" : "s", sum.duration_s, sum.imu_samples, scene.imu.rate_hz, wall,
           wall > 0 ? (double)sum.imu_samples * (double)sum.runs / wall : 0.0, opts.threads,
           opts.threads == 1 ? "" : "s");
    printf("final      horizontal %.3e m, vertical %.3e m, velocity %.3e m/s, attitude %.3e rad\n",
           sum.final.pos_err_h_m, sum.final.pos_err_v_m, sum.final.vel_err_mps, sum.final.att_err_rad);
    if (sum.runs > 1)
      printf("final rms  horizontal %.3e m, vertical %.3e m, velocity %.3e m/s, attitude %.3e rad (over runs)\n",
             sum.final_rms.pos_err_h_m, sum.final_rms.pos_err_v_m, sum.final_rms.vel_err_mps,
             sum.final_rms.att_err_rad);
    printf("rms        horizontal %.3e m, vertical %.3e m, velocity %.3e m/s, attitude %.3e rad\n",
           sum.stats.pos_err_h_m.rms, sum.stats.pos_err_v_m.rms, sum.stats.vel_err_mps.rms,
           sum.stats.att_err_rad.rms);
    navsim_run_smooth_print(&sum);
    nav_requirements_print(stdout, verdicts, info.n_requirements);
    printf("results    %s/\n", out_dir);
  }
  rc = EXIT_OK;
  if (verdicts && !nav_req_all_pass(verdicts, info.n_requirements)) {
    if (strict) {
      if (quiet) nav_requirements_print(stderr, verdicts, info.n_requirements); /* why the gate failed */
      rc = EXIT_REQUIREMENT;
    }
  }

cleanup:
  for (int i = 0; i < 3; ++i)
    if (o.f[i]) fclose(o.f[i]);
  if (o.imu_err) fclose(o.imu_err);
  (void)navsim_gnss_out_end(o.gnss);
  (void)navsim_gnss_sat_out_end(o.gsat);
  navsim_kfgins_destroy(o.kfgins);
  navsim_rinex_destroy(o.rinex);
  navsim_run_smooth_abort(o.smooth);
  nav_resultdir_abort(rd);
  if (committed) navsim_interrupt_detach(); /* the results are complete: a late signal is absorbed */
  else navsim_interrupt_disarm();
  if (rc > 128) fprintf(stderr, "navsim run: interrupted by signal %d; no results written\n", rc - 128);
  navsim_mpi_abandon(); /* rank 0 failed before the runs: release the other ranks */
  nav_sim_destroy(sim);
  nav_req_evaluator_destroy(req_ev);
  free(verdicts);
  nav_scene_release(&scene);
  return rc;
}
