/* Output size and memory predicted from a scene, and the limits (size_limits.h). */
#define _POSIX_C_SOURCE 200809L
#include "navcore/nav_size_limits.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_errors.h"
#include "navcore/nav_results.h"
#include "navcore/nav_sim.h"
#include "navcore/nav_traj.h"
#include "navcore/nav_truth.h"

/* Columns of the files navsim run writes outside navcore_io's tables (their headers are in
 * main.c and gnss_out.c). */
#define IMU_ERRORS_COLUMNS 7 /* imu_errors.csv */
#define GNSS_COLUMNS 10      /* gnss.csv */
#define MC_STATS_COLUMNS 15  /* mc_stats.csv */
#define TRACKS_COLUMNS 5     /* tracks.csv of --kml (kml_export.c) */
/* One RTS smoother record per output or GNSS epoch and run in flight: about 7 KiB at 18 states
 * (nav_scene.h, navigation.smoother); 8 KiB covers the 21-state filter's growth in part. */
#define SMOOTHER_RECORD_BYTES 8192.0
/* Samples up to which a Monte Carlo job shares one reference for all runs (sim.c). */
#define SHARED_TRUTH_MAX_SAMPLES 4000000.0

/* Columns of a navcore_io CSV table: the commas of its header line, plus one. */
static int table_columns(nav_csv_table t) {
  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  if (!f) return 0;
  const nav_status st = nav_csv_write_header(f, t);
  fclose(f);
  int n = 0;
  if (st == NAV_OK && buf) {
    n = 1;
    for (const char *p = buf; *p; ++p)
      n += *p == ',';
  }
  free(buf);
  return n;
}

/* Output epochs as navsim run writes them: every stride-th IMU sample, and the last one. */
static void epochs(const nav_scene *sc, int64_t *n_imu, int64_t *n_out) {
  const double n = floor(sc->trajectory.duration_s * sc->imu.rate_hz + 1e-9);
  *n_imu = n > 0.0 && n < 9e18 ? (int64_t)n : 0;
  int64_t stride = (int64_t)llround(sc->imu.rate_hz / sc->output.rate_hz);
  if (stride < 1) stride = 1;
  *n_out = *n_imu / stride + 1 + (*n_imu % stride != 0 ? 1 : 0);
}

static void add_file(nav_size_prediction *p, const char *name, double rows, int columns) {
  if (rows <= 0.0 || columns <= 0) return;
  p->output_bytes += rows * columns * NAV_CSV_FIELD_MAX_BYTES;
  const size_t l = strlen(p->files);
  snprintf(p->files + l, sizeof p->files - l, "%s%s", l ? ", " : "", name);
}

void nav_predict_add_kfgins(const nav_scene *sc, nav_size_prediction *p) {
  int64_t n_imu = 0, n_out = 0;
  epochs(sc, &n_imu, &n_out);
  const double n_gnss = sc->gnss.model.update_rate_hz > 0.0
                            ? floor(sc->trajectory.duration_s * sc->gnss.model.update_rate_hz) + 1.0
                            : 0.0;
  /* kfgins_out.c: IMU.txt and truth.nav at every IMU epoch from t = 0, GNSS.txt per fix. */
  add_file(p, "kfgins/IMU.txt", (double)n_imu + 1.0, 7);
  add_file(p, "kfgins/truth.nav", (double)n_imu + 1.0, 11);
  add_file(p, "kfgins/GNSS.txt", n_gnss, 13);
}

void nav_predict_run(const nav_scene *sc, bool ideal, long threads, bool kml, nav_size_prediction *out) {
  memset(out, 0, sizeof *out);
  int64_t n_imu = 0, n_out = 0;
  epochs(sc, &n_imu, &n_out);
  out->imu_samples = n_imu;
  out->output_epochs = n_out;
  const long runs = ideal ? 1 : (sc->simulation.runs > 0 ? sc->simulation.runs : 1);
  const bool gnss = sc->navigation.scheme == NAV_SCHEME_INS_GNSS && sc->gnss.enabled;
  const double n_gnss = gnss && sc->gnss.model.update_rate_hz > 0.0
                            ? floor(sc->trajectory.duration_s * sc->gnss.model.update_rate_hz) + 1.0
                            : 0.0;
  const double rows = (double)n_out;
  add_file(out, "truth.csv", rows, table_columns(NAV_CSV_TRUTH));
  add_file(out, "nav.csv", rows, table_columns(NAV_CSV_NAV));
  add_file(out, "errors.csv", rows, table_columns(NAV_CSV_ERRORS));
  if (!ideal && (sc->imu.model.gyro.terms | sc->imu.model.accel.terms) != 0)
    add_file(out, "imu_errors.csv", rows, IMU_ERRORS_COLUMNS);
  if (gnss) add_file(out, "gnss.csv", n_gnss, GNSS_COLUMNS);
  /* mc_stats.csv only when the envelope of every run fits navcore's cap (nav_sim_envelope). */
  if (runs > 1 && (double)runs * rows * 9.0 <= (double)NAV_SIM_ENV_MAX_VALUES)
    add_file(out, "mc_stats.csv", rows, MC_STATS_COLUMNS);
  if (sc->navigation.smoother) {
    add_file(out, "nav_smoothed.csv", rows, table_columns(NAV_CSV_NAV_SMOOTHED));
    add_file(out, "smoothed_errors.csv", rows, table_columns(NAV_CSV_ERRORS));
  }
  /* --kml: tracks.csv holds every reference, estimate and GNSS epoch (the KML at most 20 000
   * points a track, a few MB). */
  if (kml) add_file(out, "tracks.csv", 2.0 * rows + n_gnss, TRACKS_COLUMNS);

  /* Memory that grows with the scene; everything else navcore caps (statistics at most
   * NAV_SIM_METRIC_MAX_VALUES per metric, the envelope at most NAV_SIM_ENV_MAX_VALUES values). */
  const double in_flight = (double)(threads < runs ? (threads > 0 ? threads : 1) : runs);
  double mem =
      5.0 * fmin((double)runs * (double)(n_imu + 1), (double)NAV_SIM_METRIC_MAX_VALUES + (double)runs) * 8.0;
  if (runs > 1 && (double)runs * rows * 9.0 <= (double)NAV_SIM_ENV_MAX_VALUES)
    mem += (double)runs * rows * 9.0 * 8.0;
  const size_t l0 = strlen(out->memory);
  snprintf(out->memory + l0, sizeof out->memory - l0, "statistics");
  if (runs > 1 && (double)n_imu <= SHARED_TRUTH_MAX_SAMPLES) {
    /* One reference shared by the runs: every ideal increment and the states at the output
     * epochs (every state for the vertically aided free INS). */
    const bool every = sc->navigation.aid_vertical && sc->navigation.scheme != NAV_SCHEME_INS_GNSS;
    mem += (double)n_imu * (double)sizeof(nav_imu_increment) +
           (every ? (double)n_imu + 1.0 : 2.0 * rows) * (double)sizeof(nav_traj_state) + (double)n_imu * 4.0;
    /* The reference part of the errors beside those states (kept only within
     * NAV_SIM_SHARED_REF_MAX_BYTES), and the reference at each receiver epoch with its time. */
    const double ref_bytes = (every ? (double)n_imu + 1.0 : 2.0 * rows) * (double)sizeof(nav_errors_ref);
    mem += (ref_bytes <= (double)NAV_SIM_SHARED_REF_MAX_BYTES ? ref_bytes : 0.0) +
           n_gnss * ((double)sizeof(nav_traj_state) + 8.0);
    strncat(out->memory, ", shared reference", sizeof out->memory - strlen(out->memory) - 1);
  }
  if (sc->navigation.smoother && gnss) {
    mem += in_flight * (rows + n_gnss) * SMOOTHER_RECORD_BYTES;
    const size_t l = strlen(out->memory);
    snprintf(out->memory + l, sizeof out->memory - l, ", RTS smoother records of %.0f run(s) in flight",
             in_flight);
  }
  if (kml) {
    /* The tracks are read back whole for tracks.kml / tracks.csv: time and position per epoch. */
    mem += (2.0 * rows + n_gnss) * 4.0 * 8.0;
    strncat(out->memory, ", --kml tracks", sizeof out->memory - strlen(out->memory) - 1);
  }
  out->memory_bytes = mem;
}

void nav_predict_estimate(const nav_scene *sc, int csv_columns, nav_size_prediction *out) {
  memset(out, 0, sizeof *out);
  int64_t n_imu = 0, n_out = 0;
  epochs(sc, &n_imu, &n_out);
  out->imu_samples = n_imu;
  out->output_epochs = n_out;
  add_file(out, "estimate.csv", (double)n_out, csv_columns);
  /* The rows are streamed in fixed batches: nothing grows with the epochs. */
  out->memory_bytes = 0.0;
  snprintf(out->memory, sizeof out->memory, "none (streamed)");
}

/* "1.5 GB" style figure (decimal units, as disk sizes are quoted). */
static void human(char *buf, size_t cap, double bytes) {
  static const char *const unit[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  int u = 0;
  while (bytes >= 1000.0 && u < 6) {
    bytes /= 1000.0;
    ++u;
  }
  snprintf(buf, cap, u == 0 ? "%.0f %s" : "%.3g %s", bytes, unit[u]);
}

int nav_size_check(const char *cmd, const char *scene_path, const nav_size_prediction *p,
                      bool allow_large, bool warn_only) {
  const bool big_out = p->output_bytes > NAV_MAX_OUTPUT_BYTES;
  const bool big_mem = p->memory_bytes > NAV_MAX_MEMORY_BYTES;
  if ((!big_out && !big_mem) || allow_large) return 0;
  const char *kind = warn_only ? "warning" : "error";
  char a[32], b[32];
  if (big_out) {
    human(a, sizeof a, p->output_bytes);
    human(b, sizeof b, NAV_MAX_OUTPUT_BYTES);
    fprintf(
        stderr,
        "%s: %s: output.rate_hz: navsim %s would write up to %s of result files (%lld output epochs from "
        "%lld "
        "IMU samples, in %s), above the limit of %s (2 GiB): lower output.rate_hz or trajectory.duration_s, "
        "or give --allow-large\n",
        scene_path, kind, cmd, a, (long long)p->output_epochs, (long long)p->imu_samples, p->files, b);
  }
  if (big_mem) {
    human(a, sizeof a, p->memory_bytes);
    human(b, sizeof b, NAV_MAX_MEMORY_BYTES);
    fprintf(
        stderr,
        "%s: %s: navsim %s would need about %s of memory (%s, for %lld output epochs), above the limit of %s "
        "(4 GiB): lower output.rate_hz, trajectory.duration_s or simulation.runs (--threads for the "
        "smoother), "
        "or give --allow-large\n",
        scene_path, kind, cmd, a, p->memory, (long long)p->output_epochs, b);
  }
  return warn_only ? 0 : 2;
}
