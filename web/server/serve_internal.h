/*
 * Shared declarations of the navsim serve implementation (web/server): configuration, small JSON
 * text buffers, the scene checks of the API and the job manager. Not installed.
 */
#ifndef NAVSERVE_INTERNAL_H
#define NAVSERVE_INTERNAL_H

#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <sys/types.h>
#include <time.h>

#include "navcore/nav_scene.h"

#define SERVE_PATH_MAX 1024

/* ------------------------------------------------------------------ configuration (config.c) */

/** Every limit and setting of the server; serve_config_default() holds the documented defaults. */
typedef struct serve_config {
  char bind[64];                      /**< bind (address; default 127.0.0.1) */
  int port;                           /**< port (0: any free port) */
  char data_dir[SERVE_PATH_MAX];      /**< data_dir: jobs/ and tmp/ live here */
  char studio_dir[SERVE_PATH_MAX];    /**< studio_dir: the studio bundle with manifest.txt ("" default) */
  char allowed_origin[256];           /**< allowed_origin: Origin accepted besides http://HOST ("" none) */
  long max_body_bytes;                /**< max_body_bytes: request bodies above are refused (413) */
  int max_connections;                /**< max_connections: open connections in all */
  int max_connections_per_client;     /**< max_connections_per_client: per remote address */
  int connection_timeout_s;           /**< connection_timeout_s: idle connections are closed */
  int max_streams;                    /**< max_event_streams: open event streams in all */
  int max_streams_per_client;         /**< max_event_streams_per_client */
  int max_parallel_jobs;              /**< max_parallel_jobs: simulations running at once */
  int max_queued_jobs;                /**< max_queued_jobs: waiting simulations (429 beyond) */
  int max_jobs_per_client;            /**< max_jobs_per_client: queued + running per remote address */
  int job_threads;                    /**< job_threads: navsim run --threads of each job */
  long job_cpu_s;                     /**< job_cpu_s: CPU seconds of one job (RLIMIT_CPU) */
  long job_wall_s;                    /**< job_wall_s: wall-clock seconds before the watchdog ends it */
  long job_memory_mb;                 /**< job_memory_mb: address space of a job (RLIMIT_AS) */
  long job_output_mb;                 /**< job_output_mb: predicted result files of one job */
  long job_open_files;                /**< job_open_files: RLIMIT_NOFILE of a job */
  long max_runs;                      /**< max_runs: Monte Carlo runs of one job */
  double max_imu_samples;             /**< max_imu_samples: duration x IMU rate x runs of one job */
  long result_max_age_s;              /**< result_max_age_s: finished jobs are removed after this */
  long disk_quota_mb;                 /**< disk_quota_mb: all job directories together */
  int retry_after_s;                  /**< retry_after_s: Retry-After of 429 answers */
  long estimate_cpu_s;                /**< estimate_cpu_s: CPU seconds of one POST /api/estimate */
  int max_parallel_estimates;         /**< max_parallel_estimates: estimates computed at once */
  int estimate_cache_entries;         /**< estimate_cache_entries: answers kept by scene text (0: none) */
  int slurm;                          /**< slurm: 1 hands campaigns above max_runs to Slurm */
  long slurm_max_runs;                /**< slurm_max_runs: Monte Carlo runs of a Slurm campaign */
  int slurm_tasks;                    /**< slurm_tasks: srun -n (MPI ranks) of a campaign */
  long slurm_time_min;                /**< slurm_time_min: sbatch --time of a campaign [min] */
  char slurm_partition[64];           /**< slurm_partition: sbatch --partition ("" default) */
  char slurm_mpi[32];                 /**< slurm_mpi: srun --mpi plugin when slurm_tasks > 1 */
  char slurm_bin_dir[SERVE_PATH_MAX]; /**< slurm_bin_dir: where sbatch, scontrol, scancel are */
} serve_config;

serve_config serve_config_default(void);

/** Read a key = value file into @p c; on error print "FILE:LINE: error: ..." and return false. */
bool serve_config_read(const char *path, serve_config *c);

/* ------------------------------------------------------------------ text buffers (util.c) */

/** A growing NUL-terminated text buffer; on allocation failure it stays marked failed. */
typedef struct sbuf {
  char *s;
  size_t len, cap;
  bool failed;
} sbuf;

void sb_free(sbuf *b);
void sb_add(sbuf *b, const char *text, size_t n);
void sb_puts(sbuf *b, const char *text);
void sb_printf(sbuf *b, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/** A JSON string literal (quotes included) of @p text; invalid UTF-8 bytes become U+FFFD. */
void sb_json_str(sbuf *b, const char *text);
/** A JSON number, or null when @p v is not finite. */
void sb_json_num(sbuf *b, double v);
/** Hand the text over (the caller frees it); NULL when the buffer failed. */
char *sb_take(sbuf *b, size_t *len);

/** Read a whole regular file of at most @p max bytes (O_NOFOLLOW); NULL on failure. */
char *serve_read_file(const char *path, size_t max, size_t *len);
/** Remove a directory tree (no symbolic link is followed). */
void serve_remove_tree(const char *path);
/** Bytes used by the files under @p path. */
double serve_tree_bytes(const char *path);
/** 32 lower-case hex digits from getrandom() (128 bits); false when the kernel gives none. */
bool serve_random_id(char out[33]);
/** True when @p s is exactly 32 lower-case hex digits. */
bool serve_is_id(const char *s);
double serve_now_s(void);

/* ------------------------------------------------------------------ scenes (scene_api.c) */

/** One problem found in a submitted scene, as navsim check reports it. */
typedef struct serve_diag {
  int line, col;
  char path[256];
  char message[512];
} serve_diag;

#define SERVE_MAX_DIAGS 100

typedef struct serve_diags {
  serve_diag d[SERVE_MAX_DIAGS];
  int n;
} serve_diags;

/**
 * Read and validate a submitted scene exactly as `navsim check` does (the library's reader, with
 * the checks for a scene that is about to run), after refusing the fields that name files (the
 * server reads no file a client names). The text is written to a private file under @p tmp_dir
 * for the reader. @p scene may be NULL; it owns no heap data (plain free() suffices). Returns true
 * when valid; otherwise @p diags holds the problems.
 */
bool serve_scene_check(const char *text, size_t len, const char *tmp_dir, nav_scene *scene,
                       serve_diags *diags);

/**
 * Scene checks at once are bounded (each holds scenes of about 0.5 MB): enter blocks while
 * @p max checks run. serve_checks_init() sets the bound once at start-up.
 */
void serve_checks_init(int max);
void serve_check_enter(void);
void serve_check_leave(void);

/** JSON of @p diags: {"ok":false,"error":MSG,"errors":[{"line","col","path","message"}...]}. */
char *serve_diags_json(const serve_diags *diags, const char *error, size_t *len);

/** Load the IMU and GNSS catalogs as JSON arrays (at start-up); false with a message on failure. */
bool serve_catalogs_load(char **imu_json, char **gnss_json, char *why, size_t why_size);

/** The scene library: file stems and descriptions of the scenes a client may run. */
typedef struct serve_scene_entry {
  char name[96]; /**< file stem, e.g. "urban-drive" */
  char path[SERVE_PATH_MAX];
} serve_scene_entry;

typedef struct serve_library {
  serve_scene_entry *e;
  int n;
  char *json; /**< GET /api/scenes */
} serve_library;

bool serve_library_load(serve_library *lib, const char *tmp_dir, char *why, size_t why_size);
void serve_library_free(serve_library *lib);

/* ------------------------------------------------------------------ jobs (jobs.c) */

typedef enum job_state { JOB_QUEUED, JOB_RUNNING, JOB_DONE, JOB_FAILED, JOB_CANCELLED } job_state;

const char *job_state_name(job_state s);

/** The result files a client may fetch: a fixed list (navsim run's files, the scene, the zip). */
extern const char *const serve_result_files[];
extern const int serve_n_result_files;

typedef struct job job;

/** Outcome of serve_jobs_submit. */
typedef enum submit_rc {
  SUBMIT_OK,
  SUBMIT_CLIENT_BUSY,
  SUBMIT_QUEUE_FULL,
  SUBMIT_NO_SPACE,
  SUBMIT_ERROR
} submit_rc;

bool serve_jobs_start(const serve_config *cfg, char *why, size_t why_size);
/** Stop: queued jobs are cancelled, running ones are ended (their process groups), workers joined. */
void serve_jobs_stop(void);

/** Enqueue a run of the scene @p text (already checked) with @p runs runs; @p id receives its id.
 *  @p slurm: a campaign handed to Slurm (slurm = 1, runs above max_runs). */
submit_rc serve_jobs_submit(const char *client, const char *text, size_t len, const nav_scene *scene,
                            bool slurm, long runs, double predicted_bytes, char id[33]);

/** JSON of the job @p id ({"id","state","progress",...}); NULL when unknown. */
char *serve_job_json(const char *id, size_t *len);
/** Request cancellation; returns the new JSON or NULL when unknown; *finished when it had ended. */
char *serve_job_cancel(const char *id, size_t *len, bool *finished);

/** Path of result @p name of job @p id when the job is done and the file exists; else the reason. */
typedef enum file_rc { FILE_OK, FILE_NO_JOB, FILE_NOT_DONE, FILE_MISSING } file_rc;
file_rc serve_job_file(const char *id, const char *name, char *path, size_t size);

/** Event streams: a reference to job @p id (NULL when unknown) released by serve_job_release. */
job *serve_job_acquire(const char *id);
void serve_job_release(job *j);
/**
 * Wait (at most @p wait_s) until job @p j changed after @p *seq, then write the SSE event text of
 * its state into @p buf. Returns the bytes written, 0 when nothing changed (heartbeat due), and
 * *final is set when the job has ended (after its last event) or the server stops.
 */
size_t serve_job_event(job *j, unsigned long *seq, double wait_s, char *buf, size_t size, bool *final);
/** Count an event stream of @p client; false when the per-client or total cap is reached. */
bool serve_streams_enter(const char *client);
void serve_streams_leave(const char *client);

/** POST /api/estimate: run `navsim estimate` on the (checked) scene in a sandboxed child. */
typedef enum estimate_rc { EST_OK, EST_BUSY, EST_FAILED } estimate_rc;
/* Forgets the answers POST /api/estimate keeps by scene text. */
void serve_estimate_cache_clear(void);
estimate_rc serve_estimate(const char *text, size_t len, char **json, size_t *json_len, char *why,
                           size_t why_size);

/** fork + exec of this program with @p argv in @p dir, limits applied; -1 on failure. */
pid_t serve_spawn(const char *dir, char *const argv[], int progress_fd, long cpu_s, const char *log_name);
/** As serve_spawn, of the program @p prog (an absolute path). */
pid_t serve_spawn_prog(const char *prog, const char *dir, char *const argv[], int progress_fd, long cpu_s,
                       const char *log_name);

#endif /* NAVSERVE_INTERNAL_H */
