/* navsim bench internals shared by bench.c, bench_cases2.c and bench_report.c. */
#ifndef NAVSIM_BENCH_INTERNAL_H
#define NAVSIM_BENCH_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "bench_child.h"
#include "navcore/nav_scene.h"

typedef struct bench_row {
  char case_name[64];
  char variant[64];
  const char *algorithm;
  const char *earth_model;
  const char *frame;
  double rate_hz;
  long long samples;
  double truth_sps, mech_sps, wall_s;
  double pos_err_m, vel_err_mps, att_err_rad;
  double rms_h_m; /* whole-pipeline cases: RMS horizontal error over epochs (and runs) */
  /* Replay cases: the peers' published figures on the same data (README of the data set). */
  const char *peer;
  double peer_wall_s, peer_error_m, error_m;
  double parse_s, nav_s; /* replay cases: parsing alone and the in-process replay (best of 3) [s] */
  double peak_rss_mb; /* child-process cases: peak resident memory (0: not measured) */
  double fps;         /* viewer case: frames per second */
  double load1;       /* 1-minute load average when the case finished (bench_load1) */
  char note[160];     /* shown in bench.md (e.g. why a case stopped early) */
  bool ok;
  char error[256];
} bench_row;


/* Where the published KF-GINS figures on the long drive come from. */
#define BENCH_KFGINS_PUBLISHED_SOURCE                                                                          \
  "data set README: 2-core AMD EPYC, Debian 12, 2026-11-22; not this machine, not this load"

/* navview of this build, or NULL; whether an X display is set. */
const char *bench_navview_exe(void);
/* The program @p name of this build or install (see bench_cases2.c); false when not found. */
bool bench_program(const char *name, char *buf, size_t cap);
bool bench_have_display(void);
/* The number after @p key (e.g. " median=") in a child's log line; NAN when the key is absent. */
double bench_log_field(const char *line, const char *key);
int bench_make_dir(const char *path);
bool bench_load_library_scene(const char *name, nav_scene *sc);

/* Closure case: truth generation and mechanization timed separately (bench.c). */
void bench_scene(const nav_scene *sc, int reps, bench_row *row);
/* Whole pipeline through nav_sim (bench.c). */
void bench_sim(const nav_scene *sc, bool ideal, int threads, bench_row *row);
/* Replay of the shared long drive with the navigation settings of cfg_scene (bench.c). */
/* The long-drive replay: the whole `navsim replay` as a child process (the headline wall time),
 * plus an in-process breakdown (parsing alone, the replay without output files). */
/* With @p peer_exe (a KF-GINS executable; NULL: none), the peer runs alternate with ours and
 * @p peer_row receives the side-by-side figures measured in this run. */
void bench_replay(const char *data_dir, const char *gnss_file, const nav_scene *cfg_scene, const char *out_dir,
                  const char *peer_exe, bench_row *row, bench_row *peer_row);
/* This executable (navsim-bench), for its own child runs (the FLOP counts under valgrind). */
bool bench_self_exe(char *buf, size_t cap);
/* The navsim program the cases time (next to navsim-bench when installed, the build tree's). */
bool bench_navsim_exe(char *buf, size_t cap);
/* The resources directory (nav_paths_resources_dir). */
bool bench_resources_dir(char *buf, size_t size);

/* Cases added by bench_cases2.c after bench.c's own: appends to rows[*n] (capacity cap). */
void bench_cases2(bool full, const char *out_dir, bench_row *rows, int *n, int cap, bool quiet);
/* navstudio's live-preview latency (bench_studio.c): its row, and its line of the target table. */
void bench_case_studio_preview(bool full, const char *out_dir, bench_row *rows, int *n, int cap);
void bench_studio_target_md(FILE *md, const bench_row *rows, int n);
/* The browser studio's scene to first picture (bench_web.c): its row, and its target line. */
void bench_case_web_first_picture(bool full, const char *out_dir, bench_row *rows, int *n, int cap);
void bench_web_target_md(FILE *md, const bench_row *rows, int n);
/* navsim estimate of every library scene (bench_estimate.c): its row, and its target line. */
void bench_case_estimate_library(bool full, const char *out_dir, bench_row *rows, int *n, int cap);
void bench_estimate_target_md(FILE *md, const bench_row *rows, int n);

/* Truth + IMU generation of the long drive against gnss-ins-sim, per sample (bench_truthgen.c): its
 * rows (with @p gis_dir, a gnss-ins-sim checkout, the peer runs in this suite), and its target line. */
void bench_case_truthgen(bool full, const char *out_dir, const char *gis_dir, bench_row *rows, int *n, int cap);
void bench_truthgen_target_md(FILE *md, const bench_row *rows, int n);

/* Per-stage floating-point operation counts (bench_report.c). */
typedef struct bench_flops {
  const char *stage;
  double flops_per_step; /* NAN: not counted */
  const char *how;
} bench_flops;

/* bench.md sections after the table: targets met / not met, FLOPs and peak, memory (bench_report.c). */
void bench_report_md(FILE *md, bool full, const char *out_dir, const bench_row *rows, int n, double suite_wall_s);
/* speed_vs_error.png through navview (bench_report.c); returns a one-line note for bench.md. */
void bench_report_png(const char *out_dir, char *note, size_t note_size);

/* Hidden `navsim bench --stage NAME --steps N`: run one stage N times (for the FLOP counts). */
int bench_stage_main(const char *stage, long steps);

#endif /* NAVSIM_BENCH_INTERNAL_H */
