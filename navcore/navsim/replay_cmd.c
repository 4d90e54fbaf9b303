/*
 * navsim replay: run our navigation on recorded IMU / GNSS files (KF-GINS text formats) and
 * score it against a reference trajectory, next to the published figures of the peer filters
 * for the same inputs. The replay itself is nav_replay_run() (navcore_io, nav_recorded.h);
 * this file parses the command line, writes the result directory and prints the tables.
 */
#define _GNU_SOURCE /* sync_file_range (Linux), guarded below */
#include "cli_util.h"
#include "replay_cmd.h"
#include "req_out.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_io.h"
#include "navcore/nav_recorded.h"
#include "navcore/nav_rinex_read.h"
#include "navcore/nav_results.h"
#include "navcore/nav_version.h"
#include "smooth_out.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };

#define MAX_PEERS 8

/* IMU files up to this size are read into memory on a thread of their own while the run starts on
 * their first records (nav_rec_imu_stream; about 0.55 bytes of records per byte of text: 256 MiB
 * is some 2 million records, 2.8 h at 200 Hz). Larger files are checked before the run and read
 * again by it, so memory stays bounded. */
#define REPLAY_IMU_IN_MEMORY_BYTES ((size_t)256 * 1024 * 1024)

static const char *k_usage_replay =
    "usage: navsim replay --imu FILE --truth FILE [--gnss FILE] [--scene SCENE] [--init FILE] [--start T]\n"
    "                     [--end T] [--outage T0:T1]... [--peer NAME=FILE]... [--out DIR]\n"
    "                     [--rinex-obs FILE --rinex-nav FILE [--t0-gps S]]\n"
    "                     [--force] [--peers auto|none] [--cov-decimation N] [--smooth] [--quiet]\n"
    "\n"
    "Run our navigation on recorded data and score it against a reference:\n"
    "  --imu FILE      IMU increments, KF-GINS text: t [s], dtheta x/y/z [rad], dvel x/y/z [m/s],\n"
    "                  the increment over the interval ending at t, body axes forward-right-down\n"
    "  --gnss FILE     GNSS fixes, KF-GINS text: t, lat [deg], lon [deg], h [m], sigma N/E/D [m]\n"
    "                  (7 columns), optionally velocity N/E/D and its sigma (13 columns).\n"
    "                  Without --gnss: free-inertial navigation (pure strapdown)\n"
    "  --truth FILE    reference .nav (week, t, lat, lon, h, vN vE vD, roll pitch yaw [deg]): the\n"
    "                  initial state (the row at the first IMU epoch, as KF-GINS is given it) and\n"
    "                  the scoring (every IMU epoch with a row within 0.1 ms)\n"
    "  --scene SCENE   (or --config) scene file whose imu error model (ARW, VRW, bias turn-on / GM / random\n"
    "                  walk), gnss.lever_arm_b_m, initial_errors (P0) and navigation (algorithm,\n"
    "                  frame) tune the filter; its trajectory, outages and earth model are not\n"
    "                  used (replay is always WGS-84). Default: high-order mechanization in NED,\n"
    "                  normal gravity, a tactical-grade filter model (ARW 0.15 deg/sqrt(h), VRW\n"
    "                  0.07 m/s/sqrt(h), GM biases 0.5 deg/h and 0.05 mg over 1 h), P0 1 m,\n"
    "                  0.1 m/s, 0.1 deg level, 1 deg heading, no lever arm\n"
    "  --init FILE     initial state: the first row of a .nav file (same format as --truth) at the\n"
    "                  initial epoch, instead of the reference row (the frame and the scoring still\n"
    "                  come from --truth); navsim run --export kfgins writes run 0's initial state,\n"
    "                  drawn initial errors included, to kfgins/init.nav. Without --init, an\n"
    "                  init.nav in the folder of --imu is used (a line on stderr says so);\n"
    "                  --init none: start from the reference row even then\n"
    "  --start T, --end T  process only IMU epochs in [T_start, T_end] (file time base, s)\n"
    "  --rinex-obs FILE  tightly coupled replay: RINEX 3 observation file whose GPS and GLONASS C1C\n"
    "                  pseudoranges and D1C Dopplers update the filter instead of --gnss fixes;\n"
    "                  needs --rinex-nav and --scene (whose filter is made the tight scheme's, with\n"
    "                  its gnss.constellation code_sd_m, range_rate_sd_mps and receiver clock);\n"
    "                  docs/rinex.md section 8. navsim run --export kfgins --export rinex writes\n"
    "                  files that replay run 0 (IMU.txt, truth.nav, init.nav and rinex/NAME.obs/.nav)\n"
    "  --rinex-nav FILE  RINEX 3 navigation file: GPS LNAV ephemerides (orbits and clocks propagated\n"
    "                  by the constellation code of the simulation) and GLONASS records (integrated\n"
    "                  with the ICD force model)\n"
    "  --t0-gps S      GPS time of the IMU files' t = 0, seconds since 1980-01-06 (default: the\n"
    "                  scene's gnss.constellation epoch, which is what navsim run --export writes;\n"
    "                  without one the start of the GPS week of the first observation, i.e. the IMU\n"
    "                  time is GPS seconds of week as in KF-GINS data)\n";

/* The rest of navsim replay --help (one literal would exceed what C compilers must support). */
static const char *k_usage_replay_tail =
    "  --outage T0:T1  drop the GNSS fixes with T0 <= t < T1 (repeatable, up to 32)\n"
    "  --peer NAME=FILE  also score another program's .nav output (e.g. KF-GINS) against the\n"
    "                  reference over the same window; compared with our figures at its epochs\n"
    "  --peers auto|none  auto (default): next to ours, print the published KF-GINS and pyins\n"
    "                  figures when the data is the gnss-ins-sim long_drive set\n"
    "  --cov-decimation N  propagate the filter covariance once every N IMU steps (default: the\n"
    "                  scene's navigation.cov_decimation, else 1; see nav_filter_config.cov_decimation:\n"
    "                  on the long_drive data N = 1..20 change the figures by less than 1e-4\n"
    "                  relative, and N = 10 makes the filter about 8 times cheaper)\n"
    "  --out DIR       result directory (default out/replay), written atomically:\n"
    "                    summary.json  inputs, settings, counts, timing, error statistics,\n"
    "                                  GNSS gaps with the errors at their end; \"stats\": the block\n"
    "                                  of navsim run's summary.json (same keys and units: RMS, max,\n"
    "                                  p95 of pos_err_h_m, pos_err_v_m, vel_err_mps, att_err_rad,\n"
    "                                  yaw_err_rad) over the scored epochs, the initial one included\n"
    "                    nav.csv       our solution at 10 Hz (columns of navsim run's nav.csv)\n"
    "                    truth.csv, errors.csv  reference and errors at the 10 Hz epochs that\n"
    "                                  have a reference row\n"
    "  --smooth        also run the RTS smoother (backward pass over the output and GNSS epochs,\n"
    "                  nav_smoother.h): nav_smoothed.csv (smoothed solution, smoothed and forward\n"
    "                  sigmas, errors) and \"stats_smoothed\" in summary.json (errors at the output\n"
    "                  epochs, forward vs smoothed, and per GNSS gap)\n"
    "  --smooth-group N  (implies --smooth) discretise the smoother's transition over groups of N\n"
    "                  IMU steps (default 10; 1: step by step, as the filter; nav_smoother_config)\n"
    "  --quiet         print nothing but errors\n"
    NAVSIM_OUT_HELP
    "\n"
    "exit codes: 0 success; 2 invalid files or options; 1 other failure\n";

/* ---------------------------------------------------------------- published peer figures */

/*
 * The reference results of ../shared/data/gnss-ins-sim-long-drive/README.md (KF-GINS and pyins
 * against truth.nav at all 193 034 epochs at 200 Hz), in the order of the README's table:
 * horizontal position RMS, max [m]; vertical position RMS, max [m]; horizontal velocity RMS,
 * max [m/s]; vertical velocity RMS [m/s]; roll, pitch, yaw RMS [deg]; yaw max [deg]; then the
 * horizontal error at the end of the first and second outage [m]. NAN: not published.
 */
enum {
  F_POS_H_RMS,
  F_POS_H_MAX,
  F_POS_V_RMS,
  F_POS_V_MAX,
  F_VEL_H_RMS,
  F_VEL_H_MAX,
  F_VEL_V_RMS,
  F_ROLL_RMS,
  F_PITCH_RMS,
  F_YAW_RMS,
  F_YAW_MAX,
  F_GAP1_H,
  F_GAP2_H,
  N_FIG
};

/* CASE_NO_FIX: a GNSS file was given but no fix of it was applied (all before the start, outside
 * the window or unmatched): a free-inertial run, and no published row is comparable. */
typedef enum data_case { CASE_FULL_GNSS = 0, CASE_OUTAGES = 1, CASE_FREE_INS = 2, CASE_NO_FIX = 3 } data_case;

/* What kind of run this is; the published rows of the README for the first three. */
static const char *const k_case_names[4] = {"full GNSS", "GNSS with gaps", "free INS (no GNSS)",
                                            "no GNSS fix applied"};
static const char *const k_case_readme[3] = {"full GNSS", "two 60 s outages", "ideal IMU, no GNSS"};

typedef struct peer_figures {
  const char *name;
  double v[3][N_FIG];
} peer_figures;

static const peer_figures k_peers[2] = {
    {"KF-GINS",
     {{0.0219, 0.0752, 0.0271, 0.1166, 0.0078, 0.0309, 0.0049, 0.0069, 0.0073, 0.0488, 0.444, NAN, NAN},
      {0.850, 7.194, 0.041, 0.276, 0.036, 0.241, 0.0052, 0.0084, 0.0087, 0.0536, 0.444, 7.19, 1.38},
      {3.84, 8.54, 0.33, 0.76, 0.0107, 0.0159, 0.0009, 0.0000, 0.0000, 0.0000, 0.0000, NAN, NAN}}},
    {"pyins",
     {{0.0222, 0.0667, 0.0276, 0.1148, 0.0079, 0.0283, 0.0051, 0.0068, 0.0072, 0.0492, 0.401, NAN, NAN},
      {0.788, 6.742, 0.071, 0.485, 0.034, 0.228, 0.0057, 0.0082, 0.0086, 0.0536, 0.401, 6.74, 0.97},
      {NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN}}},
};

static const char *const k_fig_labels[N_FIG] = {
    "horiz. pos RMS [m]",   "horiz. pos max [m]",   "vert. pos RMS [m]",   "vert. pos max [m]",
    "horiz. vel RMS [m/s]", "horiz. vel max [m/s]", "vert. vel RMS [m/s]", "roll RMS [deg]",
    "pitch RMS [deg]",      "yaw RMS [deg]",        "yaw max [deg]",       "gap 1 end horiz. [m]",
    "gap 2 end horiz. [m]"};

/* The same figures as JSON keys (units in the names). */
static const char *const k_fig_keys[N_FIG] = {
    "pos_err_h_rms_m",     "pos_err_h_max_m",   "pos_err_v_rms_m",   "pos_err_v_max_m",
    "vel_err_h_rms_mps",   "vel_err_h_max_mps", "vel_err_v_rms_mps", "roll_err_rms_deg",
    "pitch_err_rms_deg",   "yaw_err_rms_deg",   "yaw_err_max_deg",   "gap1_end_pos_err_h_m",
    "gap2_end_pos_err_h_m"};

/* Statistics of no epoch are not figures (issue 25): every value NaN, printed "-" and null. */
static nav_replay_stats stats_or_none(const nav_replay_stats *s) {
  nav_replay_stats z = *s;
  if (z.epochs > 0) return z;
  nav_replay_stat *st[8] = {&z.pos_h_m, &z.pos_v_m, &z.vel_h_mps, &z.vel_v_mps,
                            &z.roll_rad, &z.pitch_rad, &z.yaw_rad, &z.att_rad};
  for (int i = 0; i < 8; ++i) st[i]->rms = st[i]->max = st[i]->t_max_s = NAN;
  z.pos_mean_n_m = nav_vec3_make(NAN, NAN, NAN);
  z.vel_mean_n_mps = nav_vec3_make(NAN, NAN, NAN);
  return z;
}

static void figures_of(const nav_replay_stats *s_in, const nav_replay_summary *sum, double v[N_FIG]) {
  const nav_replay_stats zs = stats_or_none(s_in);
  const nav_replay_stats *s = &zs;
  v[F_POS_H_RMS] = s->pos_h_m.rms;
  v[F_POS_H_MAX] = s->pos_h_m.max;
  v[F_POS_V_RMS] = s->pos_v_m.rms;
  v[F_POS_V_MAX] = s->pos_v_m.max;
  v[F_VEL_H_RMS] = s->vel_h_mps.rms;
  v[F_VEL_H_MAX] = s->vel_h_mps.max;
  v[F_VEL_V_RMS] = s->vel_v_mps.rms;
  v[F_ROLL_RMS] = s->roll_rad.rms * NAV_RAD2DEG;
  v[F_PITCH_RMS] = s->pitch_rad.rms * NAV_RAD2DEG;
  v[F_YAW_RMS] = s->yaw_rad.rms * NAV_RAD2DEG;
  v[F_YAW_MAX] = s->yaw_rad.max * NAV_RAD2DEG;
  v[F_GAP1_H] = NAN;
  v[F_GAP2_H] = NAN;
  if (!sum) return;
  int k = 0;
  for (long i = 0; i < sum->gap_count && i < NAV_REPLAY_MAX_GAPS && k < 2; ++i)
    if (!sum->gaps[i].open && sum->gaps[i].has_end_errors) v[F_GAP1_H + k++] = sum->gaps[i].pos_h_end_m;
}

/*
 * Is this the gnss-ins-sim long_drive data of the README? Its reference starts at 100000.000 s
 * at 31.508183 N, 120.401989 E (README "Provenance"); that is specific enough for a label.
 */
static bool is_long_drive(const char *truth_path) {
  nav_rec_reader *r = NULL;
  nav_rec_pva row;
  bool got = false, yes = false;
  if (nav_rec_reader_open(truth_path, NAV_REC_PVA, &r, NULL) != NAV_OK) return false;
  if (nav_rec_read_pva(r, &row, &got) == NAV_OK && got)
    yes = fabs(row.t_s - 100000.0) < 1e-6 && fabs(row.pos.lat_rad * NAV_RAD2DEG - 31.508183) < 1e-7 &&
          fabs(row.pos.lon_rad * NAV_RAD2DEG - 120.401989) < 1e-7;
  nav_rec_reader_destroy(r);
  return yes;
}

/*
 * The "stats" block of navsim run's summary.json (nav_summary_write_json: RMS, max and p95 of
 * five metrics, angles in rad) over the scored epochs of the replay, the initial epoch included
 * as run includes epoch 0: every stride-th scored epoch, the stride bounding the stored values
 * to NAV_SIM_METRIC_MAX_VALUES per metric as run's statistics are.
 */
enum { RUN_STATS_METRICS = 5 };
typedef struct run_stats {
  nav_stat_acc *acc[RUN_STATS_METRICS];
  long long stride, seen, kept;
  nav_status st;
  /* While the IMU file is still being read, its record count (which sets the stride) is not
   * known: the values of the scored epochs wait here, in order, and are fed to the accumulators
   * once it is (run_stats_settle), as if they had been added then. */
  bool pending;
  double *pend; /* RUN_STATS_METRICS values per epoch */
  size_t pend_n, pend_cap;
  /* The results, once run_stats_finish_join() has computed them; the first RUN_STATS_ON_HELPER of
   * them on a second thread while it runs (run_stats_finish_start). */
  bool have_result;
  nav_stat result[RUN_STATS_METRICS];
  bool helper_running;
  pthread_t helper;
} run_stats;

static void run_stats_on_scored(void *user, const nav_epoch_errors *e);

static nav_status run_stats_create(run_stats *rs, size_t epochs_max) {
  memset(rs, 0, sizeof *rs);
  const long long n = (long long)epochs_max + 1;
  rs->stride = (n + NAV_SIM_METRIC_MAX_VALUES - 1) / NAV_SIM_METRIC_MAX_VALUES;
  if (rs->stride < 1) rs->stride = 1;
  const size_t cap = (size_t)(n / rs->stride + 1);
  for (int m = 0; m < RUN_STATS_METRICS; ++m) {
    const nav_status st = nav_stat_acc_create(cap, &rs->acc[m]);
    if (st != NAV_OK) return st;
  }
  return NAV_OK;
}

static void run_stats_finish_join(run_stats *rs);

static void run_stats_destroy(run_stats *rs) {
  if (rs->helper_running) run_stats_finish_join(rs); /* (an error after the selections started) */
  for (int m = 0; m < RUN_STATS_METRICS; ++m) nav_stat_acc_destroy(rs->acc[m]);
  free(rs->pend);
  rs->pend = NULL;
}

static void run_stats_add_values(run_stats *rs, const double v[RUN_STATS_METRICS]) {
  if (rs->st != NAV_OK) return;
  const bool keep = rs->stride == 1 || rs->seen % rs->stride == 0; /* (no division at stride 1) */
  rs->seen++;
  if (!keep) return;
  rs->st = nav_stat_acc_add_each(rs->acc, v, RUN_STATS_METRICS);
  rs->kept++;
}

static void run_stats_add(run_stats *rs, const nav_epoch_errors *e) {
  const double v[RUN_STATS_METRICS] = {e->pos_err_h_m, e->pos_err_v_m, e->vel_err_mps, e->att_err_rad,
                                       fabs(e->euler_err.yaw_rad)};
  if (!rs->pending) {
    run_stats_add_values(rs, v);
    return;
  }
  if (rs->st != NAV_OK) return;
  if (rs->pend_n == rs->pend_cap) {
    const size_t cap = rs->pend_cap ? 2 * rs->pend_cap : 8192;
    double *g = realloc(rs->pend, cap * RUN_STATS_METRICS * sizeof *g);
    if (!g) {
      rs->st = NAV_ERR_NO_MEMORY;
      return;
    }
    rs->pend = g;
    rs->pend_cap = cap;
  }
  memcpy(rs->pend + rs->pend_n++ * RUN_STATS_METRICS, v, sizeof v);
}

/* The statistics of a run whose IMU file (being read) turned out to hold @p epochs_max records:
 * the accumulators of run_stats_create(), fed with the values that waited. */
static void run_stats_settle(run_stats *rs, size_t epochs_max) {
  if (!rs->pending) return;
  double *pend = rs->pend;
  const size_t n = rs->pend_n;
  const nav_status pst = rs->st;
  nav_status st = run_stats_create(rs, epochs_max); /* (clears rs) */
  if (st == NAV_OK) st = pst;
  rs->st = st;
  for (size_t k = 0; k < n && rs->st == NAV_OK; ++k) run_stats_add_values(rs, pend + k * RUN_STATS_METRICS);
  free(pend);
}

/* Metrics whose p95 is selected on the helper thread; the others on the thread that joins it. */
enum { RUN_STATS_ON_HELPER = 3 };

static void *run_stats_result_first(void *arg) {
  run_stats *rs = arg;
  for (int m = 0; m < RUN_STATS_ON_HELPER; ++m) rs->result[m] = nav_stat_acc_result(rs->acc[m]);
  return NULL;
}

/* The results of every metric. Each p95 is a selection over all the values of its metric (1-2 ms
 * for the five metrics of the long drive, after the run, on the critical path): the first three
 * start on a second thread here, while the caller closes the CSV files and prepares the summary;
 * run_stats_finish_join() selects the other two and waits for them. Each selection touches its
 * own metric's values only, and the values do not depend on the thread. */
static void run_stats_finish_start(run_stats *rs) {
  if (rs->pending || rs->kept == 0 || rs->st != NAV_OK) return;
  rs->helper_running = pthread_create(&rs->helper, NULL, run_stats_result_first, rs) == 0;
  if (!rs->helper_running) (void)run_stats_result_first(rs);
  rs->have_result = true; /* (once joined) */
}

static void run_stats_finish_join(run_stats *rs) {
  if (!rs->have_result) return;
  for (int m = RUN_STATS_ON_HELPER; m < RUN_STATS_METRICS; ++m) rs->result[m] = nav_stat_acc_result(rs->acc[m]);
  if (rs->helper_running) (void)pthread_join(rs->helper, NULL);
  rs->helper_running = false;
}

/* ---------------------------------------------------------------- result files */

/* Stdio buffer of each CSV file. glibc ignores the size given to setvbuf without a buffer (it keeps
 * 4 KiB, i.e. some 1 700 write calls for the long drive), so the buffers are ours. */
#define CSV_BUFFER_BYTES ((size_t)256 * 1024)
/* Every this many output records, the bytes the CSV files have handed to the kernel so far are sent
 * to the disk in the background (start_writeback), so that the fsync before the result directory
 * is renamed into place finds little left to write. */
#define CSV_WRITEBACK_RECORDS 1024

static const char *const k_csv_names[3] = {"truth.csv", "nav.csv", "errors.csv"};

typedef struct out_files {
  /* truth.csv, nav.csv, errors.csv: in memory (open_memstream) until the IMU file being read has
   * passed its checks, then the files of the result directory (live), which then get what was
   * written to memory. Nothing is written to disk before every input record is checked. */
  FILE *f[3];
  char *buf[3]; /* the files' stdio buffers, CSV_BUFFER_BYTES each */
  char *mem[3]; /* the memory streams' text */
  size_t mem_len[3];
  bool live;
  int live_exit;              /* exit code of a failure to make the result directory live */
  nav_rec_imu_stream *stream; /* the IMU file being read, or NULL (checked before the run) */
  const char *out_dir;
  bool force;
  nav_resultdir *rd;
  long long records; /* output records written */
  nav_status st;
  bool show_progress;
  double t_last_print;
  smooth_out *so; /* --smooth: the smoother's recorder, else NULL */
  navsim_req_buffer *req; /* epochs for the scene's requirements (req_out.h), else NULL */
  run_stats rstats;       /* the "stats" block of navsim run's summary.json */
} out_files;

/* Starts writing to the disk what the CSV files have handed to the kernel, without waiting for it
 * (Linux sync_file_range; elsewhere nothing: the fsync at the commit does it all). Durability
 * does not depend on it: every file is still fsynced before the rename (nav_resultdir_commit). */
static void start_writeback(FILE *f) {
#if defined(SYNC_FILE_RANGE_WRITE)
  (void)sync_file_range(fileno(f), 0, 0, SYNC_FILE_RANGE_WRITE);
#else
  (void)f;
#endif
}

/* The result directory and its CSV files, which get the rows formatted in memory so far. */
static int out_go_live(out_files *o) {
  const int orc = navsim_out_begin("replay", o->out_dir, o->force, &o->rd);
  if (orc != EXIT_OK) return orc;
  for (int i = 0; i < 3; ++i) {
    const char *file = nav_resultdir_file(o->rd, k_csv_names[i]);
    FILE *f = file ? fopen(file, "w") : NULL;
    /* 256 KiB buffers: a few write calls per file instead of one per 4 KiB. */
    char *buf = f ? malloc(CSV_BUFFER_BYTES) : NULL;
    if (buf) (void)setvbuf(f, buf, _IOFBF, CSV_BUFFER_BYTES);
    bool ok = f != NULL && fflush(o->f[i]) == 0;
    if (ok && o->mem_len[i] > 0) ok = fwrite(o->mem[i], 1, o->mem_len[i], f) == o->mem_len[i];
    fclose(o->f[i]);
    free(o->mem[i]);
    o->mem[i] = NULL;
    o->f[i] = f;
    o->buf[i] = buf;
    if (!ok) {
      fprintf(stderr, "navsim replay: cannot write %s in \"%s\"\n", k_csv_names[i], o->out_dir);
      return EXIT_FAIL;
    }
  }
  o->live = true;
  return EXIT_OK;
}

/* Live once the IMU file being read has passed its checks (asked without waiting). */
static int out_maybe_live(out_files *o) {
  nav_status st = NAV_ERR_STATE;
  if (o->live || (o->stream && !(nav_rec_imu_stream_poll(o->stream, &st, NULL) && st == NAV_OK))) return EXIT_OK;
  return out_go_live(o);
}

static nav_callback_result on_record(void *user, const nav_replay_record *r) {
  out_files *o = user;
  if (!o->live) {
    o->live_exit = out_maybe_live(o);
    if (o->live_exit != EXIT_OK) {
      o->st = NAV_ERR_IO;
      return NAV_STOP;
    }
  }
  if (++o->records % CSV_WRITEBACK_RECORDS == 0 && o->live)
    for (int i = 0; i < 3; ++i) start_writeback(o->f[i]);
  /* Field by field: the simulator's record may grow fields the replay does not have. */
  nav_sim_record rec;
  memset(&rec, 0, sizeof rec);
  rec.run = 0;
  rec.frame = r->frame;
  rec.truth = r->ref;
  rec.nav = r->nav;
  rec.err = r->err;
  if (o->req && r->err) navsim_req_buffer_add(o->req, r->err);
  nav_status st = nav_csv_write_row(o->f[NAV_CSV_NAV], NAV_CSV_NAV, &rec);
  if (st == NAV_OK && o->so) st = smooth_out_on_record(o->so, r);
  if (st == NAV_OK && r->ref) st = nav_csv_write_row(o->f[NAV_CSV_TRUTH], NAV_CSV_TRUTH, &rec);
  if (st == NAV_OK && r->err) st = nav_csv_write_row(o->f[NAV_CSV_ERRORS], NAV_CSV_ERRORS, &rec);
  if (st != NAV_OK) {
    o->st = st;
    return NAV_STOP;
  }
  return NAV_CONTINUE;
}

static void run_stats_on_scored(void *user, const nav_epoch_errors *e) {
  out_files *o = user;
  if (o->rstats.pending && o->rstats.pend_n % 1024 == 0) {
    nav_status st = NAV_ERR_STATE;
    size_t count = 0;
    if (nav_rec_imu_stream_poll(o->stream, &st, &count) && st == NAV_OK) run_stats_settle(&o->rstats, count);
  }
  run_stats_add(&o->rstats, e);
}

static nav_callback_result on_progress(void *user, const nav_progress *p) {
  out_files *o = user;
  if (!o->show_progress) return NAV_CONTINUE;
  const double t = navsim_now_s();
  if (t - o->t_last_print > 0.2 || p->fraction >= 1.0) {
    fprintf(stderr, "\r  replaying: %5.1f %%  (t = %.3f s)", 100.0 * p->fraction, p->sim_time_s);
    if (p->fraction >= 1.0) fputc('\n', stderr);
    o->t_last_print = t;
  }
  return NAV_CONTINUE;
}

static void json_number(FILE *f, double v) { navsim_json_number(f, v, 17); }

/* "stats": {...} as navsim run writes it (two-space indent, followed by a comma). */
static void json_run_stats(FILE *f, run_stats *rs) {
  static const char *const names[RUN_STATS_METRICS] = {"pos_err_h_m", "pos_err_v_m", "vel_err_mps", "att_err_rad",
                                                       "yaw_err_rad"};
  fprintf(f, "  \"stats\": {\n    \"epochs\": %lld,\n    \"stride\": %lld,\n", rs->kept, rs->stride);
  for (int m = 0; m < RUN_STATS_METRICS; ++m) {
    nav_stat s = {NAN, NAN, NAN};
    if (rs->kept > 0) s = rs->have_result ? rs->result[m] : nav_stat_acc_result(rs->acc[m]);
    fprintf(f, "    \"%s\": {\"rms\": ", names[m]);
    json_number(f, s.rms);
    fputs(", \"max\": ", f);
    json_number(f, s.max);
    fputs(", \"p95\": ", f);
    json_number(f, s.p95);
    fprintf(f, "}%s\n", m + 1 < RUN_STATS_METRICS ? "," : "");
  }
  fputs("  },\n", f);
}


static void json_vec3(FILE *f, nav_vec3 v, double scale) {
  fputc('[', f);
  json_number(f, v.x * scale);
  fputs(", ", f);
  json_number(f, v.y * scale);
  fputs(", ", f);
  json_number(f, v.z * scale);
  fputc(']', f);
}

static void json_stat(FILE *f, const char *indent, const char *name, nav_replay_stat s, double scale,
                      bool last) {
  fprintf(f, "%s\"%s\": {\"rms\": ", indent, name);
  json_number(f, s.rms * scale);
  fputs(", \"max\": ", f);
  json_number(f, s.max * scale);
  fputs(", \"t_max_s\": ", f);
  json_number(f, s.t_max_s);
  fprintf(f, "}%s\n", last ? "" : ",");
}

/* "name": {statistics} at @p indent (two spaces per level), followed by a comma unless last. */
static void json_stats(FILE *f, int indent, const char *name, const nav_replay_stats *s_in, bool last) {
  const nav_replay_stats zs = stats_or_none(s_in);
  const nav_replay_stats *s = &zs;
  char in[32];
  snprintf(in, sizeof in, "%*s", 2 * indent + 2, "");
  fprintf(f, "%*s\"%s\": {\n%s\"epochs\": %ld,\n", 2 * indent, "", name, in, s->epochs);
  json_stat(f, in, "pos_err_h_m", s->pos_h_m, 1.0, false);
  json_stat(f, in, "pos_err_v_m", s->pos_v_m, 1.0, false);
  json_stat(f, in, "vel_err_h_mps", s->vel_h_mps, 1.0, false);
  json_stat(f, in, "vel_err_v_mps", s->vel_v_mps, 1.0, false);
  json_stat(f, in, "roll_err_deg", s->roll_rad, NAV_RAD2DEG, false);
  json_stat(f, in, "pitch_err_deg", s->pitch_rad, NAV_RAD2DEG, false);
  json_stat(f, in, "yaw_err_deg", s->yaw_rad, NAV_RAD2DEG, false);
  json_stat(f, in, "att_err_deg", s->att_rad, NAV_RAD2DEG, false);
  fprintf(f, "%s\"pos_err_mean_ned_m\": ", in);
  json_vec3(f, s->pos_mean_n_m, 1.0);
  fprintf(f, ",\n%s\"vel_err_mean_ned_mps\": ", in);
  json_vec3(f, s->vel_mean_n_mps, 1.0);
  fprintf(f, "\n%*s}%s\n", 2 * indent, "", last ? "" : ",");
}

typedef struct peer_arg {
  char name[64];
  const char *path;
  nav_replay_stats stats;
} peer_arg;

typedef struct replay_job {
  const char *imu, *gnss, *truth, *config;
  const char *rinex_obs, *rinex_nav; /* tightly coupled replay, else NULL */
  double t0_gps_s;
  nav_rinex_source_counts rinex;
  const nav_replay_config *rc;
  const nav_replay_summary *sum;
  data_case dcase;
  bool long_drive;
  double wall_s;
  const peer_arg *peers;
  int n_peers;
  const smooth_out *so;
  const nav_requirement_verdict *verdicts; /* the scene's requirements, or NULL */
  int n_verdicts;
  run_stats *rstats; /* the "stats" block of navsim run */
} replay_job;

static nav_status write_summary(const char *path, const replay_job *j) {
  FILE *f = fopen(path, "w");
  if (!f) return NAV_ERR_IO;
  const nav_replay_summary *s = j->sum;
  const nav_ins_gnss_config *nc = &j->rc->nav;
  const nav_filter_config *fc = &nc->filter;
  fprintf(f, "{\n  \"navsim_version\": \"%s\",\n  \"command\": \"replay\",\n  \"inputs\": {\"imu\": ",
          nav_version_string());
  nav_json_write_string(f, j->imu);
  fputs(", \"gnss\": ", f);
  if (j->gnss)
    nav_json_write_string(f, j->gnss);
  else
    fputs("null", f);
  if (j->rinex_obs) {
    fputs(", \"rinex_obs\": ", f);
    nav_json_write_string(f, j->rinex_obs);
    fputs(", \"rinex_nav\": ", f);
    nav_json_write_string(f, j->rinex_nav);
  }
  fputs(", \"truth\": ", f);
  nav_json_write_string(f, j->truth);
  fputs(", \"config\": ", f);
  if (j->config)
    nav_json_write_string(f, j->config);
  else
    fputs("null", f);
  fprintf(f, "},\n  \"scheme\": \"%s\",\n  \"case\": ",
          s->free_ins ? "free_ins" : j->rinex_obs ? "ins_gnss_tight" : "ins_gnss");
  nav_json_write_string(f, k_case_names[j->dcase]);
  fprintf(f, ",\n  \"dataset\": %s,\n", j->long_drive ? "\"gnss-ins-sim long_drive\"" : "null");
  fprintf(
      f,
      "  \"settings\": {\"algorithm\": \"%s\", \"mechanization_frame\": \"%s\", \"gravity_model\": \"%s\", ",
      nav_mech_algorithm_name(nc->ins.algorithm), nav_mech_frame_name(nc->ins.mech_frame),
      nav_gravity_model_name(nc->ins.gravity_model));
  fputs("\"lever_arm_b_m\": ", f);
  json_vec3(f, nc->r_ba_b_m, 1.0);
  fputs(",\n    \"gyro_arw_deg_per_sqrt_h\": ", f);
  json_vec3(f, fc->gyro_arw_rad_per_sqrt_s, NAV_RAD2DEG * 60.0);
  fputs(", \"accel_vrw_mps_per_sqrt_h\": ", f);
  json_vec3(f, fc->accel_vrw_mps_per_sqrt_s, 60.0);
  fputs(",\n    \"gyro_bias_gm_sd_deg_per_h\": ", f);
  json_vec3(f, (fc->gyro_bias_terms & NAV_FILTER_PROC_GM) ? fc->gyro_bias_gm_sd_rps : nav_vec3_zero(),
            NAV_RAD2DEG * 3600.0);
  fputs(", \"gyro_bias_gm_tau_s\": ", f);
  json_vec3(f, fc->gyro_bias_gm_tau_s, 1.0);
  fputs(", \"accel_bias_gm_sd_mps2\": ", f);
  json_vec3(f, (fc->accel_bias_terms & NAV_FILTER_PROC_GM) ? fc->accel_bias_gm_sd_mps2 : nav_vec3_zero(),
            1.0);
  fputs(", \"accel_bias_gm_tau_s\": ", f);
  json_vec3(f, fc->accel_bias_gm_tau_s, 1.0);
  fputs(",\n    \"p0_pos_sd_m\": ", f);
  json_vec3(f, fc->init.pos_sd_m, 1.0);
  fputs(", \"p0_vel_sd_mps\": ", f);
  json_vec3(f, fc->init.vel_sd_mps, 1.0);
  fputs(", \"p0_att_sd_deg\": ", f);
  json_vec3(f, fc->init.att_sd_rad, NAV_RAD2DEG);
  fputs(", \"p0_gyro_bias_sd_deg_per_h\": ", f);
  json_vec3(f, fc->init.gyro_bias_sd_rps, NAV_RAD2DEG * 3600.0);
  fputs(", \"p0_accel_bias_sd_mps2\": ", f);
  json_vec3(f, fc->init.accel_bias_sd_mps2, 1.0);
  fprintf(f, ",\n    \"cov_decimation\": %u, \"discretisation\": \"%s\"", fc->cov_decimation,
          fc->discretisation == NAV_FILTER_DISC_VAN_LOAN ? "van_loan" : "second_order");
  fputs(", \"gnss_pos_sd_floor_m\": ", f);
  json_number(f, nc->pos_sd_floor_m);
  fputs(", \"ref_sync_tol_s\": ", f);
  json_number(f, j->rc->ref_sync_tol_s);
  fputs(", \"outages\": [", f);
  for (size_t i = 0; i < j->rc->outage_count; ++i) {
    fputs(i ? ", [" : "[", f);
    json_number(f, j->rc->outages[i].t0_s);
    fputs(", ", f);
    json_number(f, j->rc->outages[i].t1_s);
    fputc(']', f);
  }
  fputs("]},\n  \"window\": {\"t_first_s\": ", f);
  json_number(f, s->t_first_s);
  fputs(", \"t_last_s\": ", f);
  json_number(f, s->t_last_s);
  fputs(", \"duration_s\": ", f);
  json_number(f, s->t_last_s - s->t_first_s);
  fprintf(f, "},\n  \"partial\": %s,\n", s->partial ? "true" : "false");
  fprintf(
      f,
      "  \"counts\": {\"imu_records\": %ld, \"imu_steps\": %ld, \"imu_gaps\": %ld, \"ref_rows\": %ld, "
      "\"ref_unmatched\": %ld, \"gnss_records\": %ld, \"gnss_applied\": %ld, \"gnss_dropped_outage\": %ld, "
      "\"gnss_before_start\": %ld, \"gnss_unmatched\": %ld, \"gnss_has_velocity\": %s},\n",
      s->imu_records, s->imu_steps, s->imu_gaps, s->ref_rows, s->ref_unmatched, s->gnss_records,
      s->gnss_applied, s->gnss_dropped, s->gnss_before_start, s->gnss_unmatched,
      s->gnss_has_vel ? "true" : "false");
  fputs("  \"timing\": {\"wall_s\": ", f);
  json_number(f, j->wall_s);
  fprintf(f, ", \"imu_samples\": %ld, \"imu_samples_per_s\": ", s->imu_steps);
  json_number(f, j->wall_s > 0.0 ? (double)s->imu_steps / j->wall_s : 0.0);
  fputs(", \"realtime_factor\": ", f);
  json_number(f, j->wall_s > 0.0 ? (s->t_last_s - s->t_first_s) / j->wall_s : 0.0);
  fputs("},\n", f);
  if (j->rinex_obs) {
    const nav_rinex_source_counts *c = &j->rinex;
    fputs("  \"raw_gnss\": {\"t0_gps_s\": ", f);
    json_number(f, j->t0_gps_s);
    fprintf(f,
            ", \"epochs\": %ld, \"satellite_measurements\": %ld, \"skipped_no_ephemeris\": %ld, "
            "\"skipped_unhealthy\": %ld, \"glonass_measurements\": %ld, \"skipped_no_c1c\": %ld, "
            "\"skipped_other_systems\": %ld, \"event_records\": %ld},\n",
            c->epochs, c->sats_used, c->no_ephemeris, c->unhealthy, c->glonass_used, c->no_code,
            c->other_systems, c->events);
  }
  json_stats(f, 1, "errors", &s->stats, false);
  json_stats(f, 1, "errors_at_output_epochs", &s->stats_output, false);
  json_run_stats(f, j->rstats);
  fputs("  \"final\": {\"t_s\": ", f);
  json_number(f, s->final.t_s);
  fputs(", \"pos_err_h_m\": ", f);
  json_number(f, s->final.pos_err_h_m);
  fputs(", \"pos_err_v_m\": ", f);
  json_number(f, s->final.pos_err_v_m);
  fputs(", \"vel_err_mps\": ", f);
  json_number(f, s->final.vel_err_mps);
  fputs(", \"att_err_deg\": ", f);
  json_number(f, s->final.att_err_rad * NAV_RAD2DEG);
  /* navsim run's keys of the same figures (radians), beside the degrees. */
  fputs(", \"att_err_rad\": ", f);
  json_number(f, s->final.att_err_rad);
  fputs(", \"yaw_err_rad\": ", f);
  json_number(f, fabs(s->final.euler_err.yaw_rad));
  fputs("},\n  \"bias_estimates\": {\"gyro_deg_per_h\": ", f);
  json_vec3(f, s->b_g_rps, NAV_RAD2DEG * 3600.0);
  fputs(", \"accel_mps2\": ", f);
  json_vec3(f, s->b_a_mps2, 1.0);
  fprintf(f, "},\n  \"gnss_gaps\": {\"count\": %ld, \"list\": [", s->gap_count);
  for (long i = 0; i < s->gap_count && i < NAV_REPLAY_MAX_GAPS; ++i) {
    const nav_replay_gap *g = &s->gaps[i];
    fprintf(f, "%s\n    {\"t0_s\": ", i ? "," : "");
    json_number(f, g->t0_s);
    fputs(", \"t1_s\": ", f);
    json_number(f, g->t1_s);
    fprintf(f, ", \"open\": %s, \"pos_err_h_end_m\": ", g->open ? "true" : "false");
    json_number(f, g->has_end_errors ? g->pos_h_end_m : NAN);
    fputs(", \"pos_err_v_end_m\": ", f);
    json_number(f, g->has_end_errors ? g->pos_v_end_m : NAN);
    fputs(", \"pos_err_h_max_m\": ", f);
    json_number(f, g->pos_h_max_m);
    fputc('}', f);
  }
  fputs(s->gap_count > 0 ? "\n  ]},\n" : "]},\n", f);
  smooth_out_json(j->so, f);
  fputs("  \"requirements\": ", f);
  if (nav_requirements_write_json(f, j->verdicts, j->verdicts ? j->n_verdicts : 0, 2) != NAV_OK) fputs("[]", f);
  fputs(",\n", f);
  fputs("  \"peers_published\": ", f);
  if (j->long_drive) {
    fputs("{\"source\": \"gnss-ins-sim-long-drive/README.md\", \"case\": ", f);
    nav_json_write_string(f, k_case_readme[j->dcase]);
    for (int p = 0; p < 2; ++p) {
      fprintf(f, ", \"%s\": {", k_peers[p].name);
      for (int k = 0; k < N_FIG; ++k) {
        fprintf(f, "%s\"%s\": ", k ? ", " : "", k_fig_keys[k]);
        json_number(f, k_peers[p].v[j->dcase][k]);
      }
      fputc('}', f);
    }
    fputs("},\n", f);
  } else {
    fputs("null,\n", f);
  }
  fputs("  \"peers_scored\": [", f);
  for (int p = 0; p < j->n_peers; ++p) {
    fputs(p ? ",\n    {\"name\": " : "\n    {\"name\": ", f);
    nav_json_write_string(f, j->peers[p].name);
    fputs(", \"file\": ", f);
    nav_json_write_string(f, j->peers[p].path);
    fputs(",\n", f);
    json_stats(f, 3, "errors", &j->peers[p].stats, true);
    fputs("    }", f);
  }
  fputs(j->n_peers ? "\n  ]\n}\n" : "]\n}\n", f);
  const bool bad = ferror(f) != 0;
  return (fclose(f) != 0 || bad) ? NAV_ERR_IO : NAV_OK;
}

/* ---------------------------------------------------------------- terminal tables */

static void print_cell(double v) {
  if (isfinite(v))
    printf(" %12.4g", v);
  else
    printf(" %12s", "-");
}

static void print_tables(const replay_job *j, bool show_published) {
  const nav_replay_summary *s = j->sum;
  if (j->rinex_obs)
    printf("replay     %s + %s + %s (tightly coupled) vs %s (%s)\n", j->imu, j->rinex_obs, j->rinex_nav, j->truth,
           j->config ? j->config : "default filter settings");
  else
    printf("replay     %s%s%s vs %s (%s)\n", j->imu, j->gnss ? " + " : " (free INS)", j->gnss ? j->gnss : "",
           j->truth, j->config ? j->config : "default filter settings");
  printf("epochs     %ld IMU steps, %.3f .. %.3f s; %ld scored against the reference", s->imu_steps,
         s->t_first_s, s->t_last_s, s->stats.epochs);
  if (s->ref_unmatched > 0) printf(" (%ld reference rows between IMU epochs not scored)", s->ref_unmatched);
  printf("\n");
  if (j->rinex_obs) {
    const nav_rinex_source_counts *c = &j->rinex;
    printf("raw gnss   %ld epochs read, %ld applied (%ld satellite measurements, %ld GLONASS); skipped: %ld "
           "without ephemeris, %ld unhealthy, %ld without C1C, %ld of other systems\n",
           c->epochs, s->gnss_applied, c->sats_used, c->glonass_used, c->no_ephemeris, c->unhealthy, c->no_code,
           c->other_systems);
  } else if (!s->free_ins)
    printf("gnss       %ld fixes applied, %ld dropped (outages), %ld before the start, %ld unmatched; %ld "
           "gap%s\n",
           s->gnss_applied, s->gnss_dropped, s->gnss_before_start, s->gnss_unmatched, s->gap_count,
           s->gap_count == 1 ? "" : "s");
  if (s->imu_gaps > 0)
    printf("warning    %ld IMU intervals longer than 1.5x the first one (max %.4f s)\n", s->imu_gaps,
           s->imu_dt_max_s);
  printf("time       %.3f s wall, %.3g IMU samples/s, %.0fx real time\n", j->wall_s,
         j->wall_s > 0 ? (double)s->imu_steps / j->wall_s : 0.0,
         j->wall_s > 0 ? (s->t_last_s - s->t_first_s) / j->wall_s : 0.0);
  printf("case       %s%s\n", k_case_names[j->dcase],
         j->long_drive ? " (gnss-ins-sim long_drive data set)" : "");

  double ours[N_FIG], ours_out[N_FIG];
  figures_of(&s->stats, s, ours);
  figures_of(&s->stats_output, s, ours_out);
  /* A published peer without figures for this case (pyins has no free-INS run) gets no column,
   * and a row without any figure (the gap rows of a run without gaps) is not printed: no row or
   * column of placeholders (issue 18). */
  bool peer_shown[2] = {false, false};
  if (show_published)
    for (int p = 0; p < 2; ++p)
      for (int k = 0; k < N_FIG; ++k)
        if (isfinite(k_peers[p].v[j->dcase][k])) peer_shown[p] = true;
  printf("\n%-22s %12s", "", "navsim");
  if (show_published)
    for (int p = 0; p < 2; ++p)
      if (peer_shown[p]) printf(" %12s", k_peers[p].name);
  if (j->n_peers > 0) {
    printf(" %12s", "navsim@out");
    for (int p = 0; p < j->n_peers; ++p)
      printf(" %12.12s", j->peers[p].name);
  }
  printf("\n");
  double pf[MAX_PEERS][N_FIG];
  for (int p = 0; p < j->n_peers; ++p)
    figures_of(&j->peers[p].stats, NULL, pf[p]);
  for (int k = 0; k < N_FIG; ++k) {
    if (k >= F_GAP1_H && s->free_ins) break;
    bool any = isfinite(ours[k]);
    for (int p = 0; p < 2 && show_published; ++p)
      if (peer_shown[p] && isfinite(k_peers[p].v[j->dcase][k])) any = true;
    if (j->n_peers > 0) any = any || isfinite(ours_out[k]);
    for (int p = 0; p < j->n_peers; ++p)
      if (isfinite(pf[p][k])) any = true;
    if (!any) continue;
    printf("%-22s", k_fig_labels[k]);
    print_cell(ours[k]);
    if (show_published)
      for (int p = 0; p < 2; ++p)
        if (peer_shown[p]) print_cell(k_peers[p].v[j->dcase][k]);
    if (j->n_peers > 0) {
      print_cell(ours_out[k]);
      for (int p = 0; p < j->n_peers; ++p)
        print_cell(pf[p][k]);
    }
    printf("\n");
  }
  printf("%-22s %12ld", "scored epochs", s->stats.epochs);
  if (show_published)
    for (int p = 0; p < 2; ++p)
      if (peer_shown[p]) printf(" %12s", isfinite(k_peers[p].v[j->dcase][F_POS_H_RMS]) ? "193034" : "-");
  if (j->n_peers > 0) {
    printf(" %12ld", s->stats_output.epochs);
    for (int p = 0; p < j->n_peers; ++p)
      printf(" %12ld", j->peers[p].stats.epochs);
  }
  printf("\n");
  if (show_published)
    printf("(KF-GINS, pyins: published figures of ../shared/data/gnss-ins-sim-long-drive/README.md, case "
           "\"%s\"%s)\n",
           k_case_readme[j->dcase], j->dcase == CASE_FREE_INS ? "; the peer row is for IMU_ideal.txt" : "");
  if (j->n_peers > 0)
    printf("(navsim@out and the scored peer files: the same metrics at the peers' epochs, every %g s)\n",
           j->rc->output_interval_s);
  if (s->gap_count > 0) {
    printf("\nGNSS gaps (errors just before the first fix after the gap)\n");
    printf("  %14s %14s %12s %12s %12s\n", "last fix [s]", "next fix [s]", "end h [m]", "end v [m]",
           "max h [m]");
    bool no_end = false;
    for (long i = 0; i < s->gap_count && i < NAV_REPLAY_MAX_GAPS; ++i) {
      const nav_replay_gap *g = &s->gaps[i];
      printf("  %14.3f %14.3f", g->t0_s, g->t1_s);
      if (g->has_end_errors) {
        print_cell(g->pos_h_end_m);
        print_cell(g->pos_v_end_m);
      } else {
        /* No reference row at the epoch before the fix (a reference slower than the IMU). */
        printf(" %12s %12s", "no ref. row", "no ref. row");
        no_end = true;
      }
      if (isfinite(g->pos_h_max_m)) print_cell(g->pos_h_max_m);
      else printf(" %12s", "no ref. row");
      printf("%s\n", g->open ? "  (open: no fix after it)" : "");
    }
    if (no_end)
      printf("  (no ref. row: the reference has no row at the IMU epoch just before the fix; max h is over the "
             "reference rows inside the gap)\n");
  }
  if (!s->free_ins)
    printf("\nbias estimates  gyro [%.3f, %.3f, %.3f] deg/h, accel [%.3e, %.3e, %.3e] m/s^2\n",
           s->b_g_rps.x * NAV_RAD2DEG * 3600.0, s->b_g_rps.y * NAV_RAD2DEG * 3600.0,
           s->b_g_rps.z * NAV_RAD2DEG * 3600.0, s->b_a_mps2.x, s->b_a_mps2.y, s->b_a_mps2.z);
  printf("mean errors     pos N/E/D [%.4f, %.4f, %.4f] m, vel N/E/D [%.5f, %.5f, %.5f] m/s\n",
         s->stats.pos_mean_n_m.x, s->stats.pos_mean_n_m.y, s->stats.pos_mean_n_m.z, s->stats.vel_mean_n_mps.x,
         s->stats.vel_mean_n_mps.y, s->stats.vel_mean_n_mps.z);
}

/* ---------------------------------------------------------------- command */

static bool is_regular_file(const char *path) {
  struct stat sb;
  return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

/* An error found before the run while the IMU file is still being read: as when the IMU file was
 * checked first, its own error is reported instead when it has one. Returns its exit code, else
 * 0 (the IMU file is good; the caller reports its error). */
static int imu_error_first(nav_rec_imu_stream *s, const char *imu) {
  if (!s) return 0;
  nav_diag d;
  memset(&d, 0, sizeof d);
  const nav_status st = nav_rec_imu_stream_finish(s, NULL, NULL, NULL, &d);
  if (st == NAV_OK) return 0;
  if (d.message[0]) navsim_print_diag(NULL, &d);
  else fprintf(stderr, "%s: error: %s\n", imu, nav_status_str(st));
  return st == NAV_ERR_PARSE || st == NAV_ERR_INVALID_ARG ? EXIT_INVALID : EXIT_FAIL;
}

/* What is freed after summary.json is written, on a second thread while the result directory is
 * committed (its fsyncs wait for the disk): the IMU records and the statistics' values. */
typedef struct free_late {
  nav_rec_imu_stream *stream;
  run_stats rstats;
  bool running;
  pthread_t th;
} free_late;

static void *free_late_main(void *arg) {
  free_late *fl = arg;
  nav_rec_imu_stream_destroy(fl->stream);
  fl->stream = NULL;
  run_stats_destroy(&fl->rstats);
  return NULL;
}

/* Takes @p stream and the contents of @p rs (which is left empty) and frees them; on one thread
 * if a second cannot be started. */
static void free_late_start(free_late *fl, nav_rec_imu_stream *stream, run_stats *rs) {
  fl->stream = stream;
  fl->rstats = *rs;
  memset(rs, 0, sizeof *rs);
  fl->running = pthread_create(&fl->th, NULL, free_late_main, fl) == 0;
  if (!fl->running) (void)free_late_main(fl);
}

static void free_late_join(free_late *fl) {
  if (fl->running) (void)pthread_join(fl->th, NULL);
  fl->running = false;
}

/* nav_replay_raw_fn over a nav_rinex_source. */
static nav_status rinex_next(void *user, nav_ins_gnss_raw_epoch *ep, bool *got, nav_diag *diag) {
  return nav_rinex_source_next(user, ep, got, diag);
}

int navsim_replay(int argc, char **argv) {
  const char *imu = NULL, *gnss = NULL, *truth = NULL, *config = NULL, *out_dir = "out/replay", *init = NULL;
  const char *rinex_obs = NULL, *rinex_nav = NULL;
  bool has_t0_gps = false;
  double t0_gps = 0.0;
  nav_rinex_source *rsrc = NULL;
  nav_rinex_source_config rsc = nav_rinex_source_config_default();
  bool quiet = false, peers_auto = true, smooth = false, force = false;
  /* 10 IMU steps (50 ms at 200 Hz): on the long drive the smoothed positions move by < 2e-5 m
   * and the sigmas by < 1e-4 relative against step-by-step, at a third of the forward cost. */
  unsigned smooth_group = 10u;
  unsigned cov_decimation = 0u; /* 0: the scene's navigation.cov_decimation (default 1) */
  nav_replay_config rc = nav_replay_config_default();
  nav_requirement *reqs = NULL; /* requirements of --scene */
  int n_reqs = 0;
  navsim_req_buffer req_buf = {NULL, 0, 0, false};
  nav_requirement_verdict *verdicts = NULL;
  peer_arg peers[MAX_PEERS];
  int n_peers = 0;
  for (int i = 0; i < argc; ++i) {
    const char *a = argv[i];
    if (strcmp(a, "-h") == 0 || strcmp(a, "--help") == 0) {
      fputs(k_usage_replay, stdout);
      fputs(k_usage_replay_tail, stdout);
      return EXIT_OK;
    } else if (strcmp(a, "--quiet") == 0 || strcmp(a, "-q") == 0) {
      quiet = true;
    } else if (strcmp(a, "--smooth") == 0) {
      smooth = true;
    } else if (strcmp(a, "--force") == 0) {
      force = true;
    } else if (strcmp(a, "--smooth-group") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      double n = 0.0;
      if (!navsim_parse_double(v, &n) || n != floor(n) || n < 1.0 || n > 1000.0) {
        fprintf(stderr, "navsim replay: --smooth-group: expected an integer in [1, 1000], got \"%s\"\n", v);
        return EXIT_INVALID;
      }
      smooth_group = (unsigned)n;
      smooth = true;
    } else if (strcmp(a, "--imu") == 0 || strcmp(a, "--gnss") == 0 || strcmp(a, "--truth") == 0 ||
               strcmp(a, "--config") == 0 || strcmp(a, "--scene") == 0 || strcmp(a, "--out") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      const char **dst = a[2] == 'i'   ? &imu
                         : a[2] == 'g' ? &gnss
                         : a[2] == 't' ? &truth
                         : (a[2] == 'c' || a[2] == 's') ? &config
                                       : &out_dir;
      *dst = v;
    } else if (strcmp(a, "--rinex-obs") == 0 || strcmp(a, "--rinex-nav") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      *(a[8] == 'o' ? &rinex_obs : &rinex_nav) = argv[++i];
    } else if (strcmp(a, "--t0-gps") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (!navsim_parse_double(v, &t0_gps) || !(t0_gps >= 0.0 && t0_gps < 1e10)) {
        fprintf(stderr, "navsim replay: --t0-gps: expected GPS seconds since 1980-01-06 (0 to 1e10), got \"%s\"\n",
                v);
        return EXIT_INVALID;
      }
      has_t0_gps = true;
    } else if (strcmp(a, "--init") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      init = argv[++i];
    } else if (strcmp(a, "--start") == 0 || strcmp(a, "--end") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      double t = 0.0;
      if (!navsim_parse_double(v, &t)) {
        fprintf(stderr, "navsim replay: %s: expected a time in seconds (file time base), got \"%s\"\n", a, v);
        return EXIT_INVALID;
      }
      if (a[2] == 's') {
        rc.has_start = true;
        rc.t_start_s = t;
      } else {
        rc.has_end = true;
        rc.t_end_s = t;
      }
    } else if (strcmp(a, "--outage") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      char buf[128];
      snprintf(buf, sizeof buf, "%s", v);
      char *colon = strchr(buf, ':');
      double t0 = 0.0, t1 = 0.0;
      if (colon) *colon = '\0';
      if (!colon || !navsim_parse_double(buf, &t0) || !navsim_parse_double(colon + 1, &t1) || !(t1 > t0)) {
        fprintf(
            stderr,
            "navsim replay: --outage: expected T0:T1 with T0 < T1 (seconds, file time base), got \"%s\"\n",
            v);
        return EXIT_INVALID;
      }
      if (rc.outage_count >= NAV_GNSS_MAX_OUTAGES) {
        fprintf(stderr, "navsim replay: --outage: at most %d outages\n", NAV_GNSS_MAX_OUTAGES);
        return EXIT_INVALID;
      }
      rc.outages[rc.outage_count].t0_s = t0;
      rc.outages[rc.outage_count].t1_s = t1;
      rc.outage_count++;
    } else if (strcmp(a, "--peer") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      const char *eq = strchr(v, '=');
      if (!eq || eq == v || !eq[1] || (size_t)(eq - v) >= sizeof peers[0].name) {
        fprintf(stderr, "navsim replay: --peer: expected NAME=FILE (NAME up to 63 characters), got \"%s\"\n",
                v);
        return EXIT_INVALID;
      }
      if (n_peers >= MAX_PEERS) {
        fprintf(stderr, "navsim replay: --peer: at most %d peers\n", MAX_PEERS);
        return EXIT_INVALID;
      }
      memset(&peers[n_peers], 0, sizeof peers[n_peers]);
      snprintf(peers[n_peers].name, sizeof peers[n_peers].name, "%.*s", (int)(eq - v), v);
      peers[n_peers].path = eq + 1;
      n_peers++;
    } else if (strcmp(a, "--cov-decimation") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      double n = 0.0;
      if (!navsim_parse_double(v, &n) || n != floor(n) || n < 1.0 || n > 1000.0) {
        fprintf(stderr, "navsim replay: --cov-decimation: expected an integer in [1, 1000], got \"%s\"\n", v);
        return EXIT_INVALID;
      }
      cov_decimation = (unsigned)n;
    } else if (strcmp(a, "--peers") == 0) {
      if (!navsim_need_value("replay", argc, i, a)) return EXIT_INVALID;
      const char *v = argv[++i];
      if (strcmp(v, "auto") == 0)
        peers_auto = true;
      else if (strcmp(v, "none") == 0)
        peers_auto = false;
      else {
        fprintf(stderr, "navsim replay: --peers: expected auto or none, got \"%s\"\n", v);
        return EXIT_INVALID;
      }
    } else {
      fprintf(stderr, "navsim replay: unknown argument \"%s\" (see navsim replay --help)\n", a);
      return EXIT_INVALID;
    }
  }
  if (!imu || !truth) {
    fprintf(stderr, "navsim replay: --imu and --truth are required\n%s%s", k_usage_replay, k_usage_replay_tail);
    return EXIT_INVALID;
  }
  if ((rinex_obs != NULL) != (rinex_nav != NULL)) {
    fprintf(stderr, "navsim replay: --rinex-obs and --rinex-nav go together (observations and ephemerides)\n");
    return EXIT_INVALID;
  }
  if (rinex_obs && gnss) {
    fprintf(stderr, "navsim replay: --rinex-obs and --gnss are exclusive (raw measurements or fixes)\n");
    return EXIT_INVALID;
  }
  if (rinex_obs && !config) {
    fprintf(stderr, "navsim replay: --rinex-obs needs --scene (the receiver's clock model and measurement "
                    "sigmas of the tightly coupled filter)\n");
    return EXIT_INVALID;
  }
  if (has_t0_gps && !rinex_obs)
    fprintf(stderr, "navsim replay: warning: --t0-gps has no effect without --rinex-obs\n");
  if (rc.has_start && rc.has_end && !(rc.t_end_s > rc.t_start_s)) {
    fprintf(stderr, "navsim replay: --end must be after --start\n");
    return EXIT_INVALID;
  }
  if (rc.outage_count > 0 && !gnss && !rinex_obs)
    fprintf(stderr, "navsim replay: warning: --outage has no effect without --gnss\n");
  {
    /* Before anything is read: an --out holding the recorded files (or anything else navsim did
       not write) is refused, never replaced. */
    const int orc = navsim_out_check("replay", out_dir, force);
    if (orc != EXIT_OK) return orc;
  }
  /* The IMU file starts being read now, on its own thread, while this one reads the scene: the
     second core would otherwise idle through the scene. Its verdict and any error opening it are
     taken up below, where they were before (a bad scene is still reported alone, first). */
  nav_rec_imu_stream *imu_stream = NULL; /* or the IMU file being read while the run starts */
  nav_diag imu_start_diag;
  memset(&imu_start_diag, 0, sizeof imu_start_diag);
  const nav_status imu_start_st =
      nav_rec_imu_stream_start(imu, REPLAY_IMU_IN_MEMORY_BYTES, &imu_stream, &imu_start_diag);

  if (config) {
    /* nav_scene is large (segment scripts): keep it off the stack. */
    nav_scene *scene = malloc(sizeof *scene);
    if (!scene) {
      nav_rec_imu_stream_destroy(imu_stream);
      return EXIT_FAIL;
    }
    const nav_status st = nav_scene_read_file(config, scene, navsim_print_diag, NULL);
    if (st != NAV_OK) {
      nav_rec_imu_stream_destroy(imu_stream);
      fprintf(stderr, "navsim replay: --scene %s: %s\n", config,
              st == NAV_ERR_PARSE ? "not a valid scene (errors above)" : nav_status_str(st));
      free(scene);
      return st == NAV_ERR_PARSE ? EXIT_INVALID : EXIT_FAIL;
    }
    if (rinex_obs) {
      /* Raw measurements: the tightly coupled filter of this scene (its clock states and
       * model), whatever navigation.scheme says; the sigmas and t = 0 of its constellation. */
      scene->navigation.scheme = NAV_SCHEME_INS_GNSS_TIGHT;
      rsc.pr_sd_m = scene->gnss.constellation.raw.code_sd_m;
      rsc.rr_sd_mps = scene->gnss.constellation.raw.range_rate_sd_mps;
      if (!has_t0_gps && scene->gnss.constellation.enabled) {
        t0_gps = scene->gnss.constellation.epoch_gps_s;
        has_t0_gps = true;
      }
    }
    rc.nav = nav_ins_gnss_config_from_scene(scene);
    /* Recorded data lives on the real Earth: WGS-84 whatever the scene's earth.model says. */
    rc.nav.ins.earth_model = NAV_EARTH_WGS84;
    if (scene->n_requirements > 0) {
      n_reqs = scene->n_requirements;
      reqs = malloc((size_t)n_reqs * sizeof *reqs);
      verdicts = calloc((size_t)n_reqs, sizeof *verdicts);
      if (!reqs || !verdicts) {
        free(reqs);
        free(verdicts);
        nav_scene_release(scene);
        free(scene);
        nav_rec_imu_stream_destroy(imu_stream);
        return EXIT_FAIL;
      }
      for (int k = 0; k < n_reqs; ++k) reqs[k] = scene->requirements[k];
    }
    nav_scene_release(scene);
    free(scene);
  }
  if (cov_decimation > 0u) rc.nav.filter.cov_decimation = cov_decimation;
  size_t imu_count = 0; /* IMU records (nav_rec_check_file): bounds the scored epochs */
  int rc_exit = EXIT_FAIL;
  nav_status st = NAV_OK;
  out_files o;
  memset(&o, 0, sizeof o);
  free_late late;
  memset(&late, 0, sizeof late);
  rc.imu_path = imu;
  rc.gnss_path = gnss;
  rc.ref_path = truth;
  {
    /* Every IMU and GNSS record is checked before the results are written, wherever it is in the
       file: a value that would make the filter non-finite is reported at FILE:LINE:COL (exit 2),
       not as a failure of the run, and nothing is written. The IMU file is read on a thread of
       its own while the navigation starts on its first records (rc.imu_stream); the verdict on
       the whole file comes before anything reaches the disk, and a bad record stops the run. */
    const char *paths[2] = {imu, gnss};
    const nav_rec_format fmts[2] = {NAV_REC_IMU, NAV_REC_GNSS};
    imu_count = 0;
    for (int i = 0; i < 2; ++i) {
      if (!paths[i]) continue;
      nav_diag d;
      memset(&d, 0, sizeof d);
      nav_status cs = NAV_ERR_OUT_OF_RANGE;
      if (i == 0) {
        cs = imu_start_st; /* (started before the scene) */
        d = imu_start_diag;
        if (cs == NAV_OK) {
          rc.imu_stream = imu_stream;
          continue;
        }
      }
      if (i != 0 || cs == NAV_ERR_OUT_OF_RANGE) {
        memset(&d, 0, sizeof d);
        cs = nav_rec_check_file(paths[i], fmts[i], i == 0 ? &imu_count : NULL, &d);
      }
      if (cs != NAV_OK) {
        rc_exit = imu_error_first(imu_stream, imu);
        if (rc_exit) goto cleanup;
        if (d.message[0]) navsim_print_diag(NULL, &d);
        else fprintf(stderr, "%s: error: %s\n", paths[i], nav_status_str(cs));
        rc_exit = cs == NAV_ERR_PARSE || cs == NAV_ERR_INVALID_ARG ? EXIT_INVALID : EXIT_FAIL;
        goto cleanup;
      }
    }
  }

  char init_beside[4096]; /* init.nav in the folder of --imu (navsim run --export kfgins) */
  if (init && strcmp(init, "none") == 0) {
    init = NULL;
  } else if (!init) {
    /* An export's IMU.txt sits beside run 0's initial state: take it, so that the replay of an
       export reproduces run 0 without being told (issue 18, Done when). Said on stderr, once. */
    const char *slash = strrchr(imu, '/');
    const int n = slash ? snprintf(init_beside, sizeof init_beside, "%.*s/init.nav", (int)(slash - imu), imu)
                        : snprintf(init_beside, sizeof init_beside, "init.nav");
    if (n > 0 && (size_t)n < sizeof init_beside && is_regular_file(init_beside)) {
      init = init_beside;
      if (!quiet)
        fprintf(stderr,
                "navsim replay: initial state from %s (beside --imu; --init none: from the reference)\n",
                init);
    }
  }
  if (init) {
    /* The initial state of --init: the first row of a .nav file, checked like the reference. */
    nav_rec_reader *ir = NULL;
    nav_diag d;
    memset(&d, 0, sizeof d);
    bool got = false;
    nav_status is = nav_rec_reader_open(init, NAV_REC_PVA, &ir, &d);
    if (is == NAV_OK) {
      is = nav_rec_read_pva(ir, &rc.initial, &got);
      if (is != NAV_OK) d = *nav_rec_reader_diag(ir);
    }
    nav_rec_reader_destroy(ir);
    if (is != NAV_OK || !got) {
      rc_exit = imu_error_first(imu_stream, imu);
      if (rc_exit) goto cleanup;
    }
    if (is == NAV_OK && !got) {
      fprintf(stderr, "%s:1:1: error: --init: the file holds no row; expected one .nav row (week, t, lat, lon, h, "
                      "vN vE vD, roll pitch yaw [deg]) at the initial epoch\n", init);
      rc_exit = EXIT_INVALID;
      goto cleanup;
    }
    if (is != NAV_OK) {
      if (d.message[0]) navsim_print_diag(NULL, &d);
      else fprintf(stderr, "%s: error: %s\n", init, nav_status_str(is));
      rc_exit = is == NAV_ERR_PARSE || is == NAV_ERR_INVALID_ARG ? EXIT_INVALID : EXIT_FAIL;
      goto cleanup;
    }
    rc.has_initial = true;
  }

  if (rinex_obs) {
    /* t = 0 without a scene epoch: the start of the GPS week of the first observation epoch. */
    nav_diag d;
    memset(&d, 0, sizeof d);
    nav_status rs = NAV_OK;
    if (!has_t0_gps) {
      nav_rinex_obs_reader *orr = NULL;
      nav_rinex_obs_epoch *e1 = malloc(sizeof *e1);
      bool got = false;
      rs = e1 ? nav_rinex_obs_open(rinex_obs, &orr, &d) : NAV_ERR_NO_MEMORY;
      if (rs == NAV_OK) {
        rs = nav_rinex_obs_next(orr, e1, NULL, &got);
        if (rs != NAV_OK) d = *nav_rinex_obs_diag(orr);
      }
      if (rs == NAV_OK && got) t0_gps = floor(e1->t_gps_s / NAV_GNSS_WEEK_S) * NAV_GNSS_WEEK_S;
      nav_rinex_obs_destroy(orr);
      free(e1);
    }
    rsc.obs_path = rinex_obs;
    rsc.nav_path = rinex_nav;
    rsc.t0_gps_s = t0_gps;
    /* Every record is read once before the run, wherever it is: a malformed one is reported at
       FILE:LINE:COL (exit 2) before any result is written. */
    if (rs == NAV_OK) rs = nav_rinex_source_create(&rsc, &rsrc, &d);
    long n_epochs = 0;
    for (bool got = true; rs == NAV_OK && got;) {
      nav_ins_gnss_raw_epoch ep;
      rs = nav_rinex_source_next(rsrc, &ep, &got, &d);
      if (rs == NAV_OK && got) ++n_epochs;
    }
    nav_rinex_source_destroy(rsrc);
    rsrc = NULL;
    if (rs == NAV_OK && n_epochs == 0) {
      rc_exit = imu_error_first(imu_stream, imu);
      if (rc_exit) goto cleanup;
      fprintf(stderr, "%s: error: the observation file holds no epoch; expected '>' epoch records after the header\n",
              rinex_obs);
      rc_exit = EXIT_INVALID;
      goto cleanup;
    }
    if (rs == NAV_OK) rs = nav_rinex_source_create(&rsc, &rsrc, &d);
    if (rs != NAV_OK) {
      rc_exit = imu_error_first(imu_stream, imu);
      if (rc_exit) goto cleanup;
      if (d.message[0]) navsim_print_diag(NULL, &d);
      else fprintf(stderr, "navsim replay: %s\n", nav_status_str(rs));
      rc_exit = rs == NAV_ERR_PARSE || rs == NAV_ERR_INVALID_ARG || rs == NAV_ERR_OUT_OF_RANGE ? EXIT_INVALID : EXIT_FAIL;
      goto cleanup;
    }
    rc.raw = rinex_next;
    rc.raw_user = rsrc;
  }
  o.show_progress = !quiet && isatty(STDERR_FILENO);
  o.stream = imu_stream;
  o.out_dir = out_dir;
  o.force = force;
  if (smooth && rinex_obs) {
    rc_exit = imu_error_first(imu_stream, imu);
    if (rc_exit) goto cleanup;
    fprintf(stderr, "navsim replay: --smooth is not supported with --rinex-obs (the smoother does not carry the "
                    "receiver-clock states yet)\n");
    rc_exit = EXIT_INVALID;
    goto cleanup;
  }
  if (smooth && gnss) {
    st = smooth_out_create(&rc.nav.filter, smooth_group, &o.so, &rc.nav.smoother);
    if (st != NAV_OK) {
      rc_exit = imu_error_first(imu_stream, imu);
      if (rc_exit) goto cleanup;
      fprintf(stderr, "navsim replay: --smooth: cannot set up the smoother: %s\n", nav_status_str(st));
      rc_exit = EXIT_FAIL;
      goto cleanup;
    }
  } else if (smooth) {
    fprintf(stderr, "navsim replay: warning: --smooth has no effect without --gnss\n");
  }
  /* The CSV rows go to memory until the result directory is made (out_go_live): at once when the
     IMU file has been checked already, else once it has been read to its end without an error. */
  for (int i = 0; i < 3; ++i) {
    o.f[i] = open_memstream(&o.mem[i], &o.mem_len[i]);
    if (!o.f[i] || nav_csv_write_header(o.f[i], (nav_csv_table)i) != NAV_OK) {
      fprintf(stderr, "navsim replay: %s\n", nav_status_str(NAV_ERR_NO_MEMORY));
      goto cleanup;
    }
  }
  if (!imu_stream) {
    rc_exit = out_go_live(&o);
    if (rc_exit != EXIT_OK) goto cleanup;
    rc_exit = EXIT_FAIL;
    st = run_stats_create(&o.rstats, imu_count);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim replay: %s\n", nav_status_str(st));
      goto cleanup;
    }
  } else if ((long long)nav_rec_imu_stream_max_records(imu_stream) + 1 <= NAV_SIM_METRIC_MAX_VALUES) {
    /* The most records the stream can hold already gives stride 1, so the record count, which is
     * smaller, gives it too: the accumulators are made now, with room for that many values (only
     * the pages the values reach are touched), and nothing waits in memory to be copied. */
    st = run_stats_create(&o.rstats, nav_rec_imu_stream_max_records(imu_stream));
    if (st != NAV_OK) {
      rc_exit = imu_error_first(imu_stream, imu);
      if (rc_exit) goto cleanup;
      rc_exit = EXIT_FAIL;
      fprintf(stderr, "navsim replay: %s\n", nav_status_str(st));
      goto cleanup;
    }
  } else {
    o.rstats.pending = true;
  }
  rc.record = on_record;
  rc.progress = on_progress;
  rc.scored = run_stats_on_scored;
  rc.user = &o;
  /* Scoring, the statistics and the CSV rows on a second thread while the filter runs; not with
     --smooth, whose recorder marks the filter's state at each output epoch. on_progress shares
     nothing with on_record and run_stats_on_scored. */
  rc.callbacks_on_worker = o.so == NULL;
  if (n_reqs > 0) o.req = &req_buf;
  nav_replay_summary sum;
  nav_diag d;
  memset(&d, 0, sizeof d);
  const double t0 = navsim_now_s();
  st = nav_replay_run(&rc, &sum, &d);
  const double wall = navsim_now_s() - t0;
  if (imu_stream) {
    /* The verdict on the whole IMU file comes first, as when it was checked before the run: a bad
       record anywhere is reported as such (and the run, stopped or not, is discarded). */
    rc_exit = imu_error_first(imu_stream, imu);
    if (rc_exit) goto cleanup;
    rc_exit = EXIT_FAIL;
    const nav_status cs = nav_rec_imu_stream_finish(imu_stream, &imu_count, NULL, NULL, NULL);
    if (cs != NAV_OK) goto cleanup; /* (not reached: the verdict above) */
    run_stats_settle(&o.rstats, imu_count);
  }
  if (st == NAV_OK) run_stats_finish_start(&o.rstats);
  if (o.live_exit != EXIT_OK) {
    rc_exit = o.live_exit; /* the result directory could not be made (said by out_go_live) */
    goto cleanup;
  }
  if (st != NAV_OK) {
    if (o.st != NAV_OK)
      fprintf(stderr, "navsim replay: writing results failed: %s\n", nav_status_str(o.st));
    else if (d.message[0])
      navsim_print_diag(NULL, &d);
    else
      fprintf(stderr, "navsim replay: %s\n", nav_status_str(st));
    rc_exit = (st == NAV_ERR_PARSE || st == NAV_ERR_INVALID_ARG) ? EXIT_INVALID : EXIT_FAIL;
    goto cleanup;
  }
  if (sum.stats.epochs == 0) {
    /* Statistics of no epoch would print as zeros and every requirement would pass: refuse. */
    fprintf(stderr,
            "%s: error: no epoch to score: %ld IMU step(s) processed from %.3f to %.3f s (file time base) and "
            "none after the initial epoch coincides with a row of the reference %s; the replay needs IMU data "
            "beyond its initial epoch that the reference covers (check the files and --start/--end)\n",
            imu, sum.imu_steps, sum.t_first_s, sum.t_last_s, truth);
    rc_exit = EXIT_INVALID;
    goto cleanup;
  }
  {
    /* A last line without a line end: the file may have been cut (a copy or a recording stopped
     * mid-write), and then its last number may be short without looking malformed. */
    const char *paths[3] = {imu, gnss, truth};
    const long cut[3] = {sum.imu_cut_line, sum.gnss_cut_line, sum.ref_cut_line};
    for (int i = 0; i < 3; ++i)
      if (paths[i] && cut[i] > 0)
        fprintf(stderr,
                "%s:%ld: warning: the last line has no line end; if the file was cut short, its last number "
                "may be incomplete\n",
                paths[i], cut[i]);
  }
  if (rinex_obs && sum.gnss_applied == 0)
    fprintf(stderr,
            "%s: warning: no observation epoch fell on the IMU's time span %.3f .. %.3f s (IMU time = GPS time - "
            "%.17g s, see --t0-gps); the replay ran without GNSS\n",
            rinex_obs, sum.t_first_s, sum.t_last_s, t0_gps);
  if (!o.live) {
    /* No output record came after the IMU file's verdict: the result directory is made now. */
    rc_exit = out_go_live(&o);
    if (rc_exit != EXIT_OK) goto cleanup;
    rc_exit = EXIT_FAIL;
  }
  for (int i = 0; i < 3; ++i) {
    const bool bad = fflush(o.f[i]) != 0 || ferror(o.f[i]) != 0;
    if (!bad) start_writeback(o.f[i]);
    const int cl = fclose(o.f[i]);
    o.f[i] = NULL;
    free(o.buf[i]);
    o.buf[i] = NULL;
    if (bad || cl != 0) {
      fprintf(stderr, "navsim replay: writing %s failed\n", k_csv_names[i]);
      goto cleanup;
    }
  }
  if (o.so) {
    st = smooth_out_finish(o.so, &sum, nav_resultdir_file(o.rd, "nav_smoothed.csv"));
    if (st != NAV_OK) {
      fprintf(stderr, "navsim replay: --smooth: %s\n", nav_status_str(st));
      rc_exit = EXIT_FAIL;
      goto cleanup;
    }
  }
  for (int p = 0; p < n_peers; ++p) {
    memset(&d, 0, sizeof d);
    st = nav_replay_score_pva(truth, peers[p].path, true, sum.t_first_s, true, sum.t_last_s,
                              rc.ref_sync_tol_s, &peers[p].stats, &d);
    if (st != NAV_OK) {
      if (d.message[0]) navsim_print_diag(NULL, &d);
      fprintf(stderr, "navsim replay: --peer %s: cannot score %s\n", peers[p].name, peers[p].path);
      rc_exit = (st == NAV_ERR_PARSE || st == NAV_ERR_INVALID_ARG) ? EXIT_INVALID : EXIT_FAIL;
      goto cleanup;
    }
  }

  replay_job job;
  memset(&job, 0, sizeof job);
  job.imu = imu;
  job.gnss = gnss;
  job.truth = truth;
  job.config = config;
  job.rinex_obs = rinex_obs;
  job.rinex_nav = rinex_nav;
  job.t0_gps_s = t0_gps;
  job.rinex = nav_rinex_source_get_counts(rsrc);
  job.rc = &rc;
  job.sum = &sum;
  job.dcase = sum.free_ins            ? CASE_FREE_INS
              : sum.gnss_applied == 0 ? CASE_NO_FIX
                                      : (sum.gap_count > 0 || sum.gnss_dropped > 0 ? CASE_OUTAGES : CASE_FULL_GNSS);
  /* The published figures are for the three cases of the README only. */
  job.long_drive = job.dcase != CASE_NO_FIX && peers_auto && is_long_drive(truth);
  job.wall_s = wall;
  job.peers = peers;
  job.n_peers = n_peers;
  job.so = o.so;
  job.rstats = &o.rstats;
  if (o.rstats.st != NAV_OK) {
    fprintf(stderr, "navsim replay: statistics: %s\n", nav_status_str(o.rstats.st));
    goto cleanup;
  }
  if (n_reqs > 0) {
    st = navsim_req_replay_verdicts(reqs, n_reqs, &req_buf, &sum, verdicts);
    if (st != NAV_OK) {
      fprintf(stderr, "navsim replay: evaluating the requirements failed: %s\n", nav_status_str(st));
      goto cleanup;
    }
    /* Without a single fix the outages of outage_end do not exist: not evaluated, saying why. */
    if (!sum.free_ins && sum.gnss_applied == 0)
      for (int k = 0; k < n_reqs; ++k)
        if (verdicts[k].statistic == NAV_REQ_OUTAGE_END) {
          verdicts[k].evaluated = false;
          verdicts[k].pass = false;
          verdicts[k].value = NAN;
          verdicts[k].na_reason = NAV_REQ_NA_NO_GNSS_FIX;
        }
    job.verdicts = verdicts;
    job.n_verdicts = n_reqs;
  }
  run_stats_finish_join(&o.rstats);
  st = write_summary(nav_resultdir_file(o.rd, "summary.json"), &job);
  if (st != NAV_OK) {
    fprintf(stderr, "navsim replay: writing summary.json failed\n");
    goto cleanup;
  }
  /* Nothing reads the IMU records and the statistics' values any more: they are freed on a second
     thread while this one waits for the commit's fsyncs (some 20 MB unmapped for the long drive). */
  free_late_start(&late, imu_stream, &o.rstats);
  imu_stream = NULL;
  o.stream = NULL;
  {
    const int orc = navsim_out_commit("replay", o.rd);
    o.rd = NULL;
    if (orc != EXIT_OK) {
      rc_exit = orc;
      goto cleanup;
    }
  }
  if (!quiet) {
    print_tables(&job, job.long_drive);
    smooth_out_print(o.so);
    if (job.n_verdicts > 0) {
      /* One time base on the terminal: the files' (issue 18). The verdicts count from the first
       * IMU epoch; the offset is said once here. */
      printf("times           the files' time base; requirement times of the scene count from the first IMU "
             "epoch, t = %.3f s\n",
             sum.t_first_s);
      nav_requirements_print_at(stdout, job.verdicts, job.n_verdicts, sum.t_first_s);
    }
    if (job.long_drive && (sum.t_first_s > 100000.0051 || sum.t_last_s < 100965.1749))
      printf("note: the published figures cover the whole data set (100000.005 .. 100965.175 s); this window "
             "differs\n");
    printf("results         %s/\n", out_dir);
  }
  rc_exit = EXIT_OK;

cleanup:
  for (int i = 0; i < 3; ++i) {
    if (o.f[i]) fclose(o.f[i]);
    free(o.buf[i]);
    free(o.mem[i]);
  }
  nav_rec_imu_stream_destroy(imu_stream);
  nav_resultdir_abort(o.rd);
  smooth_out_destroy(o.so);
  free_late_join(&late); /* (before run_stats_destroy: it may own the statistics) */
  run_stats_destroy(&o.rstats);
  navsim_req_buffer_free(&req_buf);
  nav_rinex_source_destroy(rsrc);
  free(reqs);
  free(verdicts);
  return rc_exit;
}
