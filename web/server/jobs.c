/*
 * Jobs of navsim serve: a bounded queue of simulations, each run by a worker thread as its own
 * process (navsim again, `navsim run`, with a fixed argument list and no shell) in its own
 * directory <data_dir>/jobs/<id>/, with resource limits, no new privileges, its own process group
 * and a watchdog; results expire by age under a disk quota.
 *
 * Locking: one mutex guards the job list, every job's fields and the counters. Workers and the
 * janitor do their file work (spawning, zipping, removing directories) outside it.
 */
#define _GNU_SOURCE
#include "serve_internal.h"
#include "navserve.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <linux/landlock.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zip.h>

#include "navcore/nav_paths.h"

const char *const serve_result_files[] = {
    "summary.json",        "truth.csv",      "nav.csv",
    "errors.csv",          "imu_errors.csv", "mc_stats.csv",
    "mc_final.csv",        "gnss.csv",       "gnss_outages.csv",
    "gnss_dop.csv",        "gnss_sats.csv",  "nav_smoothed.csv",
    "smoothed_errors.csv", "tracks.kml",     "tracks.csv",
    "scene.yaml",          "log.txt",        "results.zip",
};
const int serve_n_result_files = (int)(sizeof serve_result_files / sizeof serve_result_files[0]);
/* Files of the job directory itself; the others are navsim run's, in result/. */
#define FILE_SCENE 15
#define FILE_LOG 16
#define FILE_ZIP 17

struct job {
  char id[33];
  char client[64];
  char scene_name[NAV_SCENE_NAME_MAX];
  job_state state;
  double progress;
  long runs;
  time_t created, started, finished; /* wall clock, for clients */
  double finished_mono;              /* for expiry */
  char error[1024];
  pid_t pid;
  bool cancel;
  unsigned long seq; /* bumped on every change: event streams wait on it */
  int refs;
  bool removed;
  double predicted_bytes, disk_bytes;
  double cpu_s;         /* CPU time of the job's process (user + system) */
  bool slurm;           /* a campaign handed to Slurm (runs above max_runs) */
  long slurm_id;        /* its Slurm job id, 0 before sbatch answered */
  char slurm_state[32]; /* its JobState as scontrol reports it */
  unsigned files;       /* bit i: serve_result_files[i] exists (done jobs) */
  job *next;
};

static struct {
  serve_config cfg;
  pthread_mutex_t mu;
  pthread_cond_t changed, work, jan;
  bool started, stopping;
  job *head;
  int n_queued, n_running, n_streams, n_estimates;
  double used_bytes, reserved_bytes;
  char (*stream_client)[64];
  pthread_t *workers;
  int n_workers;
  pthread_t janitor;
  char jobs_dir[SERVE_PATH_MAX], tmp_dir[SERVE_PATH_MAX];
  char *envp[12];
  char env_store[12][SERVE_PATH_MAX + 32];
  char exe[SERVE_PATH_MAX]; /* the jobs' navsim (job_program), for Slurm batch scripts */
} g = {.mu = PTHREAD_MUTEX_INITIALIZER};

const char *job_state_name(job_state s) {
  switch (s) {
  case JOB_QUEUED: return "queued";
  case JOB_RUNNING: return "running";
  case JOB_DONE: return "done";
  case JOB_FAILED: return "failed";
  case JOB_CANCELLED: return "cancelled";
  }
  return "unknown";
}

static bool finished(const job *j) {
  return j->state == JOB_DONE || j->state == JOB_FAILED || j->state == JOB_CANCELLED;
}

static void bump(job *j) {
  ++j->seq;
  pthread_cond_broadcast(&g.changed);
}

static job *find_locked(const char *id) {
  for (job *j = g.head; j; j = j->next)
    if (!j->removed && strcmp(j->id, id) == 0) return j;
  return NULL;
}

static void job_dir(const job *j, char *out, size_t size) {
  snprintf(out, size, "%s/%s", g.jobs_dir, j->id);
}

/* ------------------------------------------------------------------ the sandboxed child */

static void build_env(void) {
  /* A fixed, small environment: the share-directory overrides (the child finds the catalogs as
   * the server does), the sanitizer options of the test builds and SLURM_CONF for the Slurm commands. */
  static const char *const keep[] = {"NAV_SHARE_DIR", "NAV_RESOURCES_DIR", "ASAN_OPTIONS", "UBSAN_OPTIONS",
                                     "LSAN_OPTIONS",  "TSAN_OPTIONS",      "SLURM_CONF"};
  int n = 0;
  snprintf(g.env_store[n], sizeof g.env_store[n], "PATH=/usr/bin:/bin");
  g.envp[n] = g.env_store[n];
  ++n;
  snprintf(g.env_store[n], sizeof g.env_store[n], "LC_ALL=C");
  g.envp[n] = g.env_store[n];
  ++n;
  for (size_t i = 0; i < sizeof keep / sizeof keep[0]; ++i) {
    const char *v = getenv(keep[i]);
    if (!v || strlen(v) >= SERVE_PATH_MAX) continue;
    snprintf(g.env_store[n], sizeof g.env_store[n], "%s=%s", keep[i], v);
    g.envp[n] = g.env_store[n];
    ++n;
  }
  g.envp[n] = NULL;
}

static void set_limit(int resource, rlim_t soft, rlim_t hard) {
  const struct rlimit rl = {soft, hard};
  (void)setrlimit(resource, &rl);
}

/*
 * Landlock (Linux 5.13+, when the kernel has it): the process may create, write, rename or remove
 * files only beneath its working directory (the job's own directory). Reading stays open (the
 * program, its libraries, the catalogs). Without Landlock this does nothing; the other limits
 * stay. Called in the child after fork, with no-new-privileges set: system calls only.
 */
static void confine_writes(void) {
  const long abi = syscall(SYS_landlock_create_ruleset, NULL, 0, LANDLOCK_CREATE_RULESET_VERSION);
  if (abi < 1) return;
  __u64 w = LANDLOCK_ACCESS_FS_WRITE_FILE | LANDLOCK_ACCESS_FS_REMOVE_DIR | LANDLOCK_ACCESS_FS_REMOVE_FILE |
            LANDLOCK_ACCESS_FS_MAKE_CHAR | LANDLOCK_ACCESS_FS_MAKE_DIR | LANDLOCK_ACCESS_FS_MAKE_REG |
            LANDLOCK_ACCESS_FS_MAKE_SOCK | LANDLOCK_ACCESS_FS_MAKE_FIFO | LANDLOCK_ACCESS_FS_MAKE_BLOCK |
            LANDLOCK_ACCESS_FS_MAKE_SYM;
  if (abi >= 2) w |= LANDLOCK_ACCESS_FS_REFER;
#ifdef LANDLOCK_ACCESS_FS_TRUNCATE
  if (abi >= 3) w |= LANDLOCK_ACCESS_FS_TRUNCATE;
#endif
  struct landlock_ruleset_attr ra;
  memset(&ra, 0, sizeof ra);
  ra.handled_access_fs = w;
  const int rs = (int)syscall(SYS_landlock_create_ruleset, &ra, sizeof ra, 0);
  if (rs < 0) return;
  const int here = open(".", O_PATH | O_CLOEXEC);
  struct landlock_path_beneath_attr pb;
  memset(&pb, 0, sizeof pb);
  pb.allowed_access = w;
  pb.parent_fd = here;
  /* A rule that cannot be added would leave the job unable to write its results: then no
   * confinement rather than a broken job. */
  bool ok = here >= 0 && syscall(SYS_landlock_add_rule, rs, LANDLOCK_RULE_PATH_BENEATH, &pb, 0) == 0;
  /* Writing to /dev/null stays allowed (output thrown away). */
  const int null = open("/dev/null", O_PATH | O_CLOEXEC);
  pb.allowed_access = LANDLOCK_ACCESS_FS_WRITE_FILE;
  pb.parent_fd = null;
  ok = ok && null >= 0 && syscall(SYS_landlock_add_rule, rs, LANDLOCK_RULE_PATH_BENEATH, &pb, 0) == 0;
  if (ok) (void)syscall(SYS_landlock_restrict_self, rs, 0);
  if (here >= 0) close(here);
  if (null >= 0) close(null);
  close(rs);
}

/* The navsim the jobs run: set by navserve_set_job_program (the helper program navsim-serve hosts
 * the server), else this program. Written once before the server starts. */
static char g_job_program[SERVE_PATH_MAX];

void navserve_set_job_program(const char *path) {
  if (path && strlen(path) < sizeof g_job_program) memcpy(g_job_program, path, strlen(path) + 1);
}

static bool job_program(char *buf, size_t size) {
  if (g_job_program[0] == '\0') return nav_paths_executable(buf, size);
  if (strlen(g_job_program) >= size) return false;
  memcpy(buf, g_job_program, strlen(g_job_program) + 1);
  return true;
}

pid_t serve_spawn(const char *dir, char *const argv[], int progress_fd, long cpu_s, const char *log_name) {
  char exe[SERVE_PATH_MAX];
  if (!job_program(exe, sizeof exe)) return -1;
  return serve_spawn_prog(exe, dir, argv, progress_fd, cpu_s, log_name);
}

pid_t serve_spawn_prog(const char *prog, const char *dir, char *const argv[], int progress_fd, long cpu_s,
                       const char *log_name) {
  const rlim_t mib = 1024 * 1024;
  const rlim_t fsize = (rlim_t)g.cfg.job_output_mb * mib;
  const rlim_t as = (rlim_t)g.cfg.job_memory_mb * mib;
  const rlim_t nofile = (rlim_t)g.cfg.job_open_files;
  const pid_t pid = fork();
  if (pid != 0) return pid;
  /* The child: only async-signal-safe calls until execve. */
  sigset_t none;
  sigemptyset(&none);
  sigprocmask(SIG_SETMASK, &none, NULL);
  signal(SIGPIPE, SIG_DFL);
  setpgid(0, 0); /* its own process group: the watchdog ends the group */
  if (chdir(dir) != 0) _exit(126);
  int pfd = -1;
  if (progress_fd >= 0) {
    pfd = fcntl(progress_fd, F_DUPFD, 10);
    if (pfd < 0) _exit(126);
  }
  const int in = open("/dev/null", O_RDONLY);
  const int log = open(log_name, O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW, 0600);
  if (in < 0 || log < 0) _exit(126);
  if (dup2(in, 0) < 0 || dup2(log, 1) < 0 || dup2(log, 2) < 0) _exit(126);
  if (pfd >= 0 && dup2(pfd, 3) < 0) _exit(126);
  if (close_range(pfd >= 0 ? 4 : 3, ~0U, 0) != 0)
    for (int fd = pfd >= 0 ? 4 : 3; fd < 1024; ++fd)
      close(fd);
  set_limit(RLIMIT_CPU, (rlim_t)cpu_s, (rlim_t)cpu_s + 5); /* SIGXCPU, then SIGKILL */
  set_limit(RLIMIT_FSIZE, fsize, fsize);
  set_limit(RLIMIT_NOFILE, nofile, nofile);
  set_limit(RLIMIT_CORE, 0, 0);
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  /* Sanitizer builds reserve terabytes of shadow address space: no address-space limit there. */
  set_limit(RLIMIT_AS, as, as);
#else
  (void)as;
#endif
  if (prctl(PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0) _exit(126);
  confine_writes();
  umask(077);
  execve(prog, argv, g.envp);
  _exit(127);
}

/* The last lines of a job's log (at most about 700 bytes), for the error message. */
static void log_tail(const char *path, char *out, size_t size) {
  out[0] = '\0';
  const int fd = open(path, O_RDONLY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) return;
  char buf[701];
  const off_t end = lseek(fd, 0, SEEK_END);
  const off_t from = end > 700 ? end - 700 : 0;
  ssize_t n = pread(fd, buf, 700, from);
  close(fd);
  if (n <= 0) return;
  buf[n] = '\0';
  char *s = buf;
  if (from > 0) {
    char *nl = strchr(s, '\n');
    if (nl) s = nl + 1;
  }
  size_t m = strlen(s);
  while (m > 0 && (s[m - 1] == '\n' || s[m - 1] == '\r'))
    s[--m] = '\0';
  /* navsim's terminal progress uses carriage returns: keep the text after the last one per line. */
  snprintf(out, size, "%s", s);
}

static const char *signal_name(int sig) {
  switch (sig) {
  case SIGSEGV: return "SIGSEGV (a crash)";
  case SIGABRT: return "SIGABRT (an abort)";
  case SIGBUS: return "SIGBUS";
  case SIGFPE: return "SIGFPE";
  case SIGKILL: return "SIGKILL";
  case SIGTERM: return "SIGTERM";
  case SIGXCPU: return "SIGXCPU";
  case SIGXFSZ: return "SIGXFSZ";
  default: return "a signal";
  }
}

/* Wait for the child, watching cancellation and the wall-clock limit; reads progress lines when
 * @p progress_rd >= 0. Returns the wait status; *watchdog when the wall-clock limit ended it. */
static int supervise(job *j, pid_t pid, int progress_rd, double wall_s, struct rusage *ru, bool *watchdog) {
  const double t0 = serve_now_s();
  double t_term = 0.0;
  bool eof = progress_rd < 0, killed = false;
  char line[256];
  size_t ln = 0;
  int status = 0;
  *watchdog = false;
  for (;;) {
    if (!eof) {
      struct pollfd pf = {progress_rd, POLLIN, 0};
      const int r = poll(&pf, 1, 100);
      if (r > 0) {
        char buf[512];
        const ssize_t n = read(progress_rd, buf, sizeof buf);
        if (n <= 0 && !(n < 0 && errno == EINTR)) eof = true;
        for (ssize_t i = 0; i < n; ++i) {
          if (buf[i] != '\n') {
            if (ln < sizeof line - 1) line[ln++] = buf[i];
            continue;
          }
          line[ln] = '\0';
          ln = 0;
          double f = 0.0;
          if (j && sscanf(line, "progress %lf", &f) == 1 && f >= 0.0 && f <= 1.0) {
            pthread_mutex_lock(&g.mu);
            if (f - j->progress >= 0.001 || (f >= 1.0 && j->progress < 1.0)) {
              j->progress = f;
              bump(j);
            }
            pthread_mutex_unlock(&g.mu);
          }
        }
      }
    } else {
      const struct timespec ts = {0, 5 * 1000 * 1000};
      nanosleep(&ts, NULL);
    }
    const pid_t w = wait4(pid, &status, WNOHANG, ru);
    if (w == pid) break;
    if (w < 0 && errno != EINTR) break;
    pthread_mutex_lock(&g.mu);
    const bool cancel = g.stopping || (j && j->cancel);
    pthread_mutex_unlock(&g.mu);
    const double now = serve_now_s();
    if (t_term == 0.0 && (cancel || now - t0 > wall_s)) {
      if (!cancel) *watchdog = true;
      kill(-pid, SIGTERM); /* navsim run cancels and removes its temporary directory */
      t_term = now;
    }
    if (t_term > 0.0 && !killed && now - t_term > 2.0) {
      kill(-pid, SIGKILL);
      killed = true;
    }
  }
  return status;
}

/* ------------------------------------------------------------------ one job */

static void make_zip(job *j, const char *dir) {
  char path[2 * SERVE_PATH_MAX], tmp[2 * SERVE_PATH_MAX], src[2 * SERVE_PATH_MAX];
  snprintf(path, sizeof path, "%s/results.zip", dir);
  snprintf(tmp, sizeof tmp, "%s/.results.zip.tmp", dir);
  int err = 0;
  zip_t *z = zip_open(tmp, ZIP_CREATE | ZIP_TRUNCATE, &err);
  if (!z) return;
  bool ok = true;
  for (int i = 0; i < serve_n_result_files && ok; ++i) {
    if (i == FILE_ZIP || i == FILE_LOG || !(j->files & (1u << i))) continue;
    if (i == FILE_SCENE)
      snprintf(src, sizeof src, "%s/scene.yaml", dir);
    else
      snprintf(src, sizeof src, "%s/result/%s", dir, serve_result_files[i]);
    zip_source_t *s = zip_source_file(z, src, 0, -1);
    if (!s || zip_file_add(z, serve_result_files[i], s, ZIP_FL_ENC_UTF_8) < 0) {
      zip_source_free(s);
      ok = false;
    }
  }
  if (!ok) {
    zip_discard(z);
    unlink(tmp);
    return;
  }
  if (zip_close(z) != 0) {
    zip_discard(z);
    unlink(tmp);
    return;
  }
  if (rename(tmp, path) == 0) j->files |= 1u << FILE_ZIP;
}

static void finish_job(job *j, const char *dir, job_state st, const char *err, const struct rusage *rup);

static void run_job(job *j) {
  char dir[SERVE_PATH_MAX + 64], runs[32], threads[16], summary[2 * SERVE_PATH_MAX], logp[2 * SERVE_PATH_MAX];
  job_dir(j, dir, sizeof dir);
  snprintf(runs, sizeof runs, "%ld", j->runs);
  snprintf(threads, sizeof threads, "%d", g.cfg.job_threads);
  char *argv[] = {"navsim",    "run",   "scene.yaml", "--out", "result",        "--runs", runs,
                  "--threads", threads, "--quiet",    "--kml", "--progress-fd", "3",      NULL};
  int p[2] = {-1, -1};
  pid_t pid = -1;
  if (pipe2(p, O_CLOEXEC) == 0) pid = serve_spawn(dir, argv, p[1], g.cfg.job_cpu_s, "log.txt");
  if (p[1] >= 0) close(p[1]);
  job_state st = JOB_FAILED;
  char err[1024] = "";
  struct rusage ru;
  memset(&ru, 0, sizeof ru);
  if (pid < 0) {
    snprintf(err, sizeof err, "the server could not start the simulation process: %s", strerror(errno));
  } else {
    pthread_mutex_lock(&g.mu);
    j->pid = pid;
    pthread_mutex_unlock(&g.mu);
    bool watchdog = false;
    const int status = supervise(j, pid, p[0], (double)g.cfg.job_wall_s, &ru, &watchdog);
    const double cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                       (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
    snprintf(summary, sizeof summary, "%s/result/summary.json", dir);
    snprintf(logp, sizeof logp, "%s/log.txt", dir);
    struct stat sb;
    pthread_mutex_lock(&g.mu);
    const bool cancelled = j->cancel || g.stopping;
    pthread_mutex_unlock(&g.mu);
    char tail[800];
    log_tail(logp, tail, sizeof tail);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && stat(summary, &sb) == 0) {
      st = JOB_DONE;
    } else if (cancelled) {
      st = JOB_CANCELLED;
      snprintf(err, sizeof err, "cancelled");
    } else if (watchdog) {
      snprintf(err, sizeof err, "the run exceeded its wall-clock limit of %ld s (job_wall_s) and was ended",
               g.cfg.job_wall_s);
    } else if (WIFSIGNALED(status) &&
               (WTERMSIG(status) == SIGXCPU ||
                (WTERMSIG(status) == SIGKILL && cpu >= (double)g.cfg.job_cpu_s - 0.5))) {
      snprintf(err, sizeof err, "the run exceeded its CPU limit of %ld s (job_cpu_s) and was ended",
               g.cfg.job_cpu_s);
    } else if (WIFSIGNALED(status) && WTERMSIG(status) == SIGXFSZ) {
      snprintf(err, sizeof err, "a result file exceeded %ld MiB (job_output_mb) and the run was ended",
               g.cfg.job_output_mb);
    } else if (WIFSIGNALED(status)) {
      snprintf(err, sizeof err, "the simulation process ended by signal %d, %s: %s", WTERMSIG(status),
               signal_name(WTERMSIG(status)), tail);
    } else {
      snprintf(err, sizeof err, "navsim run exited with code %d: %s",
               WIFEXITED(status) ? WEXITSTATUS(status) : -1, tail);
    }
  }
  if (p[0] >= 0) close(p[0]);
  finish_job(j, dir, st, err, &ru);
}

/* The end of a job: which result files exist, the zip, the disk use, the final state. */
static void finish_job(job *j, const char *dir, job_state st, const char *err, const struct rusage *rup) {
  const struct rusage ru = *rup;
  unsigned files = 0;
  for (int i = 0; i < serve_n_result_files; ++i) {
    char f[2 * SERVE_PATH_MAX];
    if (i == FILE_SCENE || i == FILE_LOG)
      snprintf(f, sizeof f, "%s/%s", dir, serve_result_files[i]);
    else
      snprintf(f, sizeof f, "%s/result/%s", dir, serve_result_files[i]);
    struct stat sb;
    if (lstat(f, &sb) == 0 && S_ISREG(sb.st_mode)) files |= 1u << i;
  }
  if (st != JOB_DONE) files &= (1u << FILE_SCENE) | (1u << FILE_LOG);
  j->files = files; /* read by clients only once the state below is final */
  const double cpu_used = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec +
                          (double)ru.ru_stime.tv_sec + 1e-6 * (double)ru.ru_stime.tv_usec;
  if (st == JOB_DONE) make_zip(j, dir);
  const double bytes = serve_tree_bytes(dir);
  pthread_mutex_lock(&g.mu);
  j->state = st;
  if (st == JOB_DONE) j->progress = 1.0;
  snprintf(j->error, sizeof j->error, "%s", err);
  j->finished = time(NULL);
  j->finished_mono = serve_now_s();
  j->pid = 0;
  j->disk_bytes = bytes;
  j->cpu_s = cpu_used;
  g.used_bytes += bytes;
  g.reserved_bytes -= j->predicted_bytes;
  --g.n_running;
  bump(j);
  pthread_mutex_unlock(&g.mu);
}

/* ------------------------------------------------------------------ Slurm campaigns */

/* Run a Slurm command (sbatch, scontrol, scancel) in @p dir; its output in @p out (NUL-terminated).
 * Returns its exit code, -1 when it could not run. */
static int slurm_cmd(const char *dir, char *const argv[], char *out, size_t out_size) {
  char prog[SERVE_PATH_MAX + 64], path[2 * SERVE_PATH_MAX];
  snprintf(prog, sizeof prog, "%s/%s", g.cfg.slurm_bin_dir[0] ? g.cfg.slurm_bin_dir : "/usr/bin", argv[0]);
  const pid_t pid = serve_spawn_prog(prog, dir, argv, -1, 30, ".slurm-out.txt");
  if (pid < 0) return -1;
  struct rusage ru;
  bool wd = false;
  const int status = supervise(NULL, pid, -1, 60.0, &ru, &wd);
  snprintf(path, sizeof path, "%s/.slurm-out.txt", dir);
  size_t n = 0;
  char *text = serve_read_file(path, 1u << 20, &n);
  snprintf(out, out_size, "%s", text ? text : "");
  free(text);
  unlink(path);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static void slurm_field(const char *text, const char *key, char *out, size_t size) {
  out[0] = '\0';
  const char *p = strstr(text, key);
  if (!p) return;
  p += strlen(key);
  const size_t n = strcspn(p, " \n");
  snprintf(out, size, "%.*s", (int)(n < size - 1 ? n : size - 1), p);
}

/*
 * A campaign larger than the local limit: a batch script (fixed text: srun of this navsim with the
 * same fixed arguments, under MPI when slurm_tasks > 1, which splits the runs across ranks with
 * results bit-identical to one process) submitted with sbatch, then polled with scontrol every
 * second until it ends; DELETE and shutdown scancel it. The results land in the job directory,
 * which the cluster's nodes share with this server (the same path).
 */
static void run_slurm_job(job *j) {
  char dir[SERVE_PATH_MAX + 64], script[2 * SERVE_PATH_MAX], out[4096], err[1024] = "";
  job_state st = JOB_FAILED;
  struct rusage ru;
  memset(&ru, 0, sizeof ru);
  job_dir(j, dir, sizeof dir);
  snprintf(script, sizeof script, "%s/campaign.sh", dir);
  FILE *f = fopen(script, "w");
  if (!f || strchr(g.exe, '\'') || strchr(dir, '\'')) {
    if (f) fclose(f);
    snprintf(err, sizeof err, "the server could not write the batch script");
    goto done;
  }
  char mpi[64] = "";
  if (g.cfg.slurm_tasks > 1) snprintf(mpi, sizeof mpi, " --mpi=%s", g.cfg.slurm_mpi);
  fprintf(f,
          "#!/bin/sh\n# navsim serve: Slurm campaign %s\n"
          "exec srun%s -n %d '%s' run scene.yaml --out result --runs %ld --threads %d --quiet --kml\n",
          j->id, mpi, g.cfg.slurm_tasks, g.exe, j->runs, g.cfg.job_threads);
  if (fclose(f) != 0) {
    snprintf(err, sizeof err, "the server could not write the batch script");
    goto done;
  }
  char tasks[16], time_min[32], name[48];
  snprintf(tasks, sizeof tasks, "%d", g.cfg.slurm_tasks);
  snprintf(time_min, sizeof time_min, "%ld", g.cfg.slurm_time_min);
  snprintf(name, sizeof name, "navsim-%.8s", j->id);
  char *argv[20] = {"sbatch",   "--parsable", "--chdir", dir,      "--output",   "log.txt",
                    "--ntasks", tasks,        "--time",  time_min, "--job-name", name};
  int a = 12;
  if (g.cfg.slurm_partition[0]) {
    argv[a++] = "--partition";
    argv[a++] = g.cfg.slurm_partition;
  }
  argv[a++] = "campaign.sh";
  argv[a] = NULL;
  const int rc = slurm_cmd(dir, argv, out, sizeof out);
  const long id = strtol(out, NULL, 10);
  if (rc != 0 || id <= 0) {
    snprintf(err, sizeof err, "sbatch refused the campaign: %.900s", out);
    goto done;
  }
  pthread_mutex_lock(&g.mu);
  j->slurm_id = id;
  snprintf(j->slurm_state, sizeof j->slurm_state, "PENDING");
  bump(j);
  pthread_mutex_unlock(&g.mu);
  char ids[32];
  snprintf(ids, sizeof ids, "%ld", id);
  bool cancel_sent = false;
  int unknown = 0;
  for (;;) {
    pthread_mutex_lock(&g.mu);
    const bool cancel = j->cancel || g.stopping;
    pthread_mutex_unlock(&g.mu);
    if (cancel && !cancel_sent) {
      char *cv[] = {"scancel", ids, NULL};
      (void)slurm_cmd(dir, cv, out, sizeof out);
      cancel_sent = true;
    }
    char *sv[] = {"scontrol", "show", "job", "-o", ids, NULL};
    char state[32];
    if (slurm_cmd(dir, sv, out, sizeof out) != 0) {
      if (++unknown > 10) {
        snprintf(err, sizeof err, "Slurm job %ld is no longer known to scontrol", id);
        break;
      }
    }
    slurm_field(out, "JobState=", state, sizeof state);
    if (state[0]) {
      pthread_mutex_lock(&g.mu);
      if (strcmp(state, j->slurm_state) != 0) {
        snprintf(j->slurm_state, sizeof j->slurm_state, "%s", state);
        bump(j);
      }
      pthread_mutex_unlock(&g.mu);
    }
    if (strcmp(state, "COMPLETED") == 0) {
      char summary[2 * SERVE_PATH_MAX];
      struct stat sb;
      snprintf(summary, sizeof summary, "%s/result/summary.json", dir);
      if (stat(summary, &sb) == 0) {
        st = JOB_DONE;
      } else {
        char logp[2 * SERVE_PATH_MAX], tail[800];
        snprintf(logp, sizeof logp, "%s/log.txt", dir);
        log_tail(logp, tail, sizeof tail);
        snprintf(err, sizeof err, "Slurm job %ld completed without results: %s", id, tail);
      }
      break;
    }
    if (strcmp(state, "CANCELLED") == 0 && cancel) {
      st = JOB_CANCELLED;
      snprintf(err, sizeof err, "cancelled");
      break;
    }
    if (state[0] && strcmp(state, "PENDING") != 0 && strcmp(state, "RUNNING") != 0 &&
        strcmp(state, "CONFIGURING") != 0 && strcmp(state, "COMPLETING") != 0 &&
        strcmp(state, "SUSPENDED") != 0 && strcmp(state, "REQUEUED") != 0) {
      char logp[2 * SERVE_PATH_MAX], tail[800];
      snprintf(logp, sizeof logp, "%s/log.txt", dir);
      log_tail(logp, tail, sizeof tail);
      snprintf(err, sizeof err, "Slurm job %ld ended %s: %s", id, state, tail);
      break;
    }
    const struct timespec ts = {1, 0};
    nanosleep(&ts, NULL);
  }
done:
  finish_job(j, dir, st, err, &ru);
}

static void release_locked(job *j) {
  if (--j->refs == 0 && j->removed) free(j);
}

static void *worker(void *arg) {
  (void)arg;
  pthread_mutex_lock(&g.mu);
  while (!g.stopping) {
    job *j = g.head;
    while (j && (j->removed || j->state != JOB_QUEUED))
      j = j->next;
    if (!j) {
      pthread_cond_wait(&g.work, &g.mu);
      continue;
    }
    j->state = JOB_RUNNING;
    j->started = time(NULL);
    --g.n_queued;
    ++g.n_running;
    ++j->refs;
    bump(j);
    pthread_mutex_unlock(&g.mu);
    if (j->slurm)
      run_slurm_job(j);
    else
      run_job(j);
    pthread_mutex_lock(&g.mu);
    release_locked(j);
  }
  pthread_mutex_unlock(&g.mu);
  return NULL;
}

/* ------------------------------------------------------------------ expiry */

typedef struct doomed {
  char id[33];
  struct doomed *next;
} doomed;

/* Unlink finished jobs older than the age limit, then the oldest finished ones while the disk
 * use (plus @p need bytes) is over the quota; their directories are returned for removal. */
static doomed *expire_locked(double need) {
  doomed *list = NULL;
  const double now = serve_now_s();
  const double quota = (double)g.cfg.disk_quota_mb * 1024.0 * 1024.0;
  for (;;) {
    job *victim = NULL, *prev_v = NULL, *prev = NULL;
    for (job *j = g.head; j; prev = j, j = j->next) {
      if (!finished(j)) continue;
      const bool old = now - j->finished_mono > (double)g.cfg.result_max_age_s;
      const bool over = g.used_bytes + g.reserved_bytes + need > quota;
      if (old || over) {
        victim = j;
        prev_v = prev;
        break; /* the list is in creation order: the first finished one is the oldest */
      }
    }
    if (!victim) break;
    if (prev_v)
      prev_v->next = victim->next;
    else
      g.head = victim->next;
    g.used_bytes -= victim->disk_bytes;
    victim->removed = true;
    doomed *d = malloc(sizeof *d);
    if (d) {
      snprintf(d->id, sizeof d->id, "%s", victim->id);
      d->next = list;
      list = d;
    }
    bump(victim);
    if (victim->refs == 0) free(victim);
  }
  return list;
}

static void remove_doomed(doomed *d) {
  while (d) {
    doomed *n = d->next;
    char dir[SERVE_PATH_MAX + 64];
    snprintf(dir, sizeof dir, "%s/%s", g.jobs_dir, d->id);
    serve_remove_tree(dir);
    free(d);
    d = n;
  }
}

static void *janitor(void *arg) {
  (void)arg;
  pthread_mutex_lock(&g.mu);
  while (!g.stopping) {
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    ts.tv_sec += g.cfg.result_max_age_s < 20 ? 1 : 5;
    pthread_cond_timedwait(&g.jan, &g.mu, &ts);
    if (g.stopping) break;
    doomed *d = expire_locked(0.0);
    pthread_mutex_unlock(&g.mu);
    remove_doomed(d);
    pthread_mutex_lock(&g.mu);
  }
  pthread_mutex_unlock(&g.mu);
  return NULL;
}

/* ------------------------------------------------------------------ start, stop */

static bool make_dir(const char *path, char *why, size_t why_size) {
  if (mkdir(path, 0700) != 0 && errno != EEXIST) {
    snprintf(why, why_size, "cannot create \"%s\": %s", path, strerror(errno));
    return false;
  }
  struct stat sb;
  if (lstat(path, &sb) != 0 || !S_ISDIR(sb.st_mode) || sb.st_uid != getuid()) {
    snprintf(why, why_size, "\"%s\" is not a directory owned by this user", path);
    return false;
  }
  return true;
}

/* Jobs of an earlier server are unreachable (ids live in memory): remove their directories. */
static void clear_dir(const char *dir, bool ids_only) {
  DIR *d = opendir(dir);
  if (!d) return;
  struct dirent *de;
  while ((de = readdir(d)) != NULL) {
    if (de->d_name[0] == '.' && (de->d_name[1] == '\0' || (de->d_name[1] == '.' && de->d_name[2] == '\0')))
      continue;
    if (ids_only && !serve_is_id(de->d_name)) continue;
    char p[SERVE_PATH_MAX + 300];
    snprintf(p, sizeof p, "%s/%s", dir, de->d_name);
    serve_remove_tree(p);
  }
  closedir(d);
}

bool serve_jobs_start(const serve_config *cfg, char *why, size_t why_size) {
  g.cfg = *cfg;
  pthread_condattr_t ca;
  pthread_condattr_init(&ca);
  pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
  pthread_cond_init(&g.changed, &ca);
  pthread_cond_init(&g.work, &ca);
  pthread_cond_init(&g.jan, &ca);
  pthread_condattr_destroy(&ca);
  if (!make_dir(cfg->data_dir, why, why_size)) return false;
  snprintf(g.jobs_dir, sizeof g.jobs_dir, "%.*s/jobs", SERVE_PATH_MAX - 16, cfg->data_dir);
  snprintf(g.tmp_dir, sizeof g.tmp_dir, "%.*s/tmp", SERVE_PATH_MAX - 16, cfg->data_dir);
  if (!make_dir(g.jobs_dir, why, why_size) || !make_dir(g.tmp_dir, why, why_size)) return false;
  clear_dir(g.jobs_dir, true);
  clear_dir(g.tmp_dir, false);
  build_env();
  if (!job_program(g.exe, sizeof g.exe)) g.exe[0] = '\0';
  g.stream_client = calloc((size_t)cfg->max_streams, sizeof *g.stream_client);
  g.workers = calloc((size_t)cfg->max_parallel_jobs, sizeof *g.workers);
  if (!g.stream_client || !g.workers) {
    snprintf(why, why_size, "out of memory");
    return false;
  }
  for (int i = 0; i < cfg->max_parallel_jobs; ++i) {
    if (pthread_create(&g.workers[i], NULL, worker, NULL) != 0) break;
    ++g.n_workers;
  }
  if (g.n_workers == 0 || pthread_create(&g.janitor, NULL, janitor, NULL) != 0) {
    snprintf(why, why_size, "cannot start the job threads");
    return false;
  }
  g.started = true;
  return true;
}

const char *serve_tmp_dir(void);
const char *serve_tmp_dir(void) {
  return g.tmp_dir;
}

void serve_jobs_stop(void) {
  if (!g.started) return;
  pthread_mutex_lock(&g.mu);
  g.stopping = true;
  for (job *j = g.head; j; j = j->next) {
    if (j->state == JOB_QUEUED) {
      j->state = JOB_CANCELLED;
      j->finished = time(NULL);
      j->finished_mono = serve_now_s();
      snprintf(j->error, sizeof j->error, "the server stopped");
      --g.n_queued;
      bump(j);
    } else if (j->state == JOB_RUNNING && j->pid > 0) {
      kill(-j->pid, SIGTERM);
    }
  }
  pthread_cond_broadcast(&g.work);
  pthread_cond_broadcast(&g.jan);
  pthread_cond_broadcast(&g.changed);
  pthread_mutex_unlock(&g.mu);
  for (int i = 0; i < g.n_workers; ++i)
    pthread_join(g.workers[i], NULL);
  pthread_join(g.janitor, NULL);
  g.started = false;
  serve_estimate_cache_clear();
}

/* ------------------------------------------------------------------ the API */

submit_rc serve_jobs_submit(const char *client, const char *text, size_t len, const nav_scene *scene,
                            bool slurm, long runs, double predicted_bytes, char id[33]) {
  submit_rc rc = SUBMIT_OK;
  doomed *d = NULL;
  job *j = NULL;
  pthread_mutex_lock(&g.mu);
  if (g.stopping) {
    rc = SUBMIT_ERROR;
    goto unlock;
  }
  int mine = 0;
  for (job *k = g.head; k; k = k->next)
    if (!k->removed && !finished(k) && strcmp(k->client, client) == 0) ++mine;
  if (mine >= g.cfg.max_jobs_per_client) {
    rc = SUBMIT_CLIENT_BUSY;
    goto unlock;
  }
  const int idle = g.cfg.max_parallel_jobs - g.n_running;
  if (g.n_queued >= g.cfg.max_queued_jobs + (idle > 0 ? idle : 0)) {
    rc = SUBMIT_QUEUE_FULL;
    goto unlock;
  }
  d = expire_locked(predicted_bytes);
  if (g.used_bytes + g.reserved_bytes + predicted_bytes > (double)g.cfg.disk_quota_mb * 1024.0 * 1024.0) {
    rc = SUBMIT_NO_SPACE;
    goto unlock;
  }
  j = calloc(1, sizeof *j);
  if (!j || !serve_random_id(j->id) || find_locked(j->id)) {
    rc = SUBMIT_ERROR;
    goto unlock;
  }
  char dir[SERVE_PATH_MAX + 64], path[2 * SERVE_PATH_MAX];
  job_dir(j, dir, sizeof dir);
  snprintf(path, sizeof path, "%s/scene.yaml", dir);
  if (mkdir(dir, 0700) != 0) {
    rc = SUBMIT_ERROR;
    goto unlock;
  }
  const int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  size_t off = 0;
  while (fd >= 0 && off < len) {
    const ssize_t w = write(fd, text + off, len - off);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) break;
    off += (size_t)w;
  }
  if (fd < 0 || off != len || close(fd) != 0) {
    serve_remove_tree(dir);
    rc = SUBMIT_ERROR;
    goto unlock;
  }
  snprintf(j->client, sizeof j->client, "%s", client);
  snprintf(j->scene_name, sizeof j->scene_name, "%s", scene->name);
  j->state = JOB_QUEUED;
  j->slurm = slurm;
  j->runs = runs;
  j->created = time(NULL);
  j->predicted_bytes = predicted_bytes;
  g.reserved_bytes += predicted_bytes;
  ++g.n_queued;
  /* Append: the list is in creation order (the queue is FIFO, expiry takes the oldest first). */
  job **tail = &g.head;
  while (*tail)
    tail = &(*tail)->next;
  *tail = j;
  snprintf(id, 33, "%s", j->id);
  j = NULL;
  pthread_cond_signal(&g.work);
unlock:
  pthread_mutex_unlock(&g.mu);
  free(j);
  remove_doomed(d);
  return rc;
}

static void iso_time(sbuf *b, time_t t) {
  if (t == 0) {
    sb_puts(b, "null");
    return;
  }
  struct tm tm;
  char s[32];
  gmtime_r(&t, &tm);
  strftime(s, sizeof s, "\"%Y-%m-%dT%H:%M:%SZ\"", &tm);
  sb_puts(b, s);
}

static void job_json_locked(const job *j, sbuf *b) {
  sb_printf(b, "{\"id\":\"%s\",\"state\":\"%s\",\"progress\":%.4f", j->id, job_state_name(j->state),
            j->progress);
  sb_printf(b, ",\"runs\":%ld,\"scene\":", j->runs);
  sb_json_str(b, j->scene_name);
  if (j->state == JOB_QUEUED) {
    int pos = 0;
    for (const job *k = g.head; k && k != j; k = k->next)
      if (!k->removed && k->state == JOB_QUEUED) ++pos;
    sb_printf(b, ",\"queue_position\":%d", pos);
  }
  sb_puts(b, ",\"created\":");
  iso_time(b, j->created);
  sb_puts(b, ",\"started\":");
  iso_time(b, j->started);
  sb_puts(b, ",\"finished\":");
  iso_time(b, j->finished);
  if (finished(j) && j->started && !j->slurm) sb_printf(b, ",\"cpu_s\":%.3f", j->cpu_s);
  if (j->slurm) {
    sb_printf(b, ",\"backend\":\"slurm\",\"slurm_job\":%ld,\"slurm_state\":", j->slurm_id);
    sb_json_str(b, j->slurm_state);
  }
  sb_puts(b, ",\"error\":");
  if (j->error[0])
    sb_json_str(b, j->error);
  else
    sb_puts(b, "null");
  sb_puts(b, ",\"files\":[");
  bool first = true;
  for (int i = 0; i < serve_n_result_files; ++i) {
    const bool have = finished(j) ? (j->files & (1u << i)) != 0 : i == FILE_SCENE;
    if (!have) continue;
    sb_printf(b, "%s\"%s\"", first ? "" : ",", serve_result_files[i]);
    first = false;
  }
  sb_puts(b, "]}");
}

char *serve_job_json(const char *id, size_t *len) {
  sbuf b = {0};
  pthread_mutex_lock(&g.mu);
  const job *j = find_locked(id);
  if (j) job_json_locked(j, &b);
  pthread_mutex_unlock(&g.mu);
  if (!j) return NULL;
  sb_puts(&b, "\n");
  return sb_take(&b, len);
}

char *serve_job_cancel(const char *id, size_t *len, bool *was_finished) {
  sbuf b = {0};
  pthread_mutex_lock(&g.mu);
  job *j = find_locked(id);
  *was_finished = false;
  if (j) {
    if (finished(j)) {
      *was_finished = true;
    } else if (j->state == JOB_QUEUED) {
      j->state = JOB_CANCELLED;
      j->cancel = true;
      j->finished = time(NULL);
      j->finished_mono = serve_now_s();
      snprintf(j->error, sizeof j->error, "cancelled");
      j->files = 1u << FILE_SCENE;
      --g.n_queued;
      g.reserved_bytes -= j->predicted_bytes;
      bump(j);
    } else {
      j->cancel = true;
      if (j->pid > 0) kill(-j->pid, SIGTERM);
      bump(j);
    }
    job_json_locked(j, &b);
  }
  pthread_mutex_unlock(&g.mu);
  if (!j) return NULL;
  sb_puts(&b, "\n");
  return sb_take(&b, len);
}

file_rc serve_job_file(const char *id, const char *name, char *path, size_t size) {
  int idx = -1;
  for (int i = 0; i < serve_n_result_files; ++i)
    if (strcmp(serve_result_files[i], name) == 0) idx = i;
  pthread_mutex_lock(&g.mu);
  const job *j = find_locked(id);
  file_rc rc = FILE_OK;
  if (!j) {
    rc = FILE_NO_JOB;
  } else if (idx < 0) {
    rc = FILE_MISSING;
  } else if (idx == FILE_SCENE) {
    snprintf(path, size, "%s/%s/scene.yaml", g.jobs_dir, j->id);
  } else if (!finished(j)) {
    rc = FILE_NOT_DONE;
  } else if (!(j->files & (1u << idx))) {
    rc = FILE_MISSING;
  } else if (idx == FILE_LOG || idx == FILE_ZIP) {
    snprintf(path, size, "%s/%s/%s", g.jobs_dir, j->id, name);
  } else {
    snprintf(path, size, "%s/%s/result/%s", g.jobs_dir, j->id, name);
  }
  pthread_mutex_unlock(&g.mu);
  return rc;
}

job *serve_job_acquire(const char *id) {
  pthread_mutex_lock(&g.mu);
  job *j = find_locked(id);
  if (j) ++j->refs;
  pthread_mutex_unlock(&g.mu);
  return j;
}

void serve_job_release(job *j) {
  if (!j) return;
  pthread_mutex_lock(&g.mu);
  release_locked(j);
  pthread_mutex_unlock(&g.mu);
}

size_t serve_job_event(job *j, unsigned long *seq, double wait_s, char *buf, size_t size, bool *final) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  const long ns = (long)((wait_s - (double)(long)wait_s) * 1e9);
  ts.tv_sec += (time_t)wait_s;
  ts.tv_nsec += ns;
  if (ts.tv_nsec >= 1000000000L) {
    ts.tv_sec += 1;
    ts.tv_nsec -= 1000000000L;
  }
  size_t n = 0;
  *final = false;
  pthread_mutex_lock(&g.mu);
  while (j->seq == *seq && !g.stopping && !j->removed)
    if (pthread_cond_timedwait(&g.changed, &g.mu, &ts) == ETIMEDOUT) break;
  if (j->seq != *seq || g.stopping || j->removed) {
    sbuf b = {0};
    *seq = j->seq;
    sb_printf(&b, "id: %lu\ndata: ", j->seq);
    job_json_locked(j, &b);
    sb_puts(&b, "\n\n");
    if (finished(j) || g.stopping || j->removed) {
      *final = true;
      sb_puts(&b, "event: end\ndata: {}\n\n");
    }
    if (!b.failed && b.len < size) {
      memcpy(buf, b.s, b.len);
      n = b.len;
    }
    sb_free(&b);
  }
  pthread_mutex_unlock(&g.mu);
  return n;
}

bool serve_streams_enter(const char *client) {
  pthread_mutex_lock(&g.mu);
  int mine = 0, free_slot = -1;
  for (int i = 0; i < g.cfg.max_streams; ++i) {
    if (g.stream_client[i][0] == '\0') {
      if (free_slot < 0) free_slot = i;
    } else if (strcmp(g.stream_client[i], client) == 0) {
      ++mine;
    }
  }
  const bool ok = free_slot >= 0 && mine < g.cfg.max_streams_per_client && !g.stopping;
  if (ok) {
    snprintf(g.stream_client[free_slot], sizeof g.stream_client[free_slot], "%s", client[0] ? client : "?");
    ++g.n_streams;
  }
  pthread_mutex_unlock(&g.mu);
  return ok;
}

void serve_streams_leave(const char *client) {
  pthread_mutex_lock(&g.mu);
  for (int i = 0; i < g.cfg.max_streams; ++i)
    if (strcmp(g.stream_client[i], client[0] ? client : "?") == 0) {
      g.stream_client[i][0] = '\0';
      --g.n_streams;
      break;
    }
  pthread_mutex_unlock(&g.mu);
}

/* ------------------------------------------------------------------ estimates */

/*
 * Answers of POST /api/estimate kept by scene text. `navsim estimate` is deterministic and its
 * estimate.json depends only on the scene file's bytes (always written as scene.yaml) and this
 * program's navsim and resources, so a scene posted again (the library scenes every new page
 * loads, a form changed back) gets the bytes computing it again would give. At most
 * estimate_cache_entries answers of at most ESTIMATE_CACHE_MAX_BYTES (scene plus answer) each,
 * the least recently used replaced; estimate_cache_entries = 0 turns the cache off.
 */
#define ESTIMATE_CACHE_MAX_BYTES (256u * 1024u)
#define ESTIMATE_CACHE_MAX_ENTRIES 1024

typedef struct est_entry {
  uint64_t hash;
  char *text, *json;
  size_t len, json_len;
  uint64_t used; /* last use, from est_clock */
} est_entry;

static struct {
  est_entry e[ESTIMATE_CACHE_MAX_ENTRIES];
  uint64_t clock;
} est_cache; /* under g.mu */

static uint64_t text_hash(const char *t, size_t n) {
  uint64_t h = 1469598103934665603ull; /* FNV-1a, 64 bits */
  for (size_t i = 0; i < n; ++i) {
    h ^= (unsigned char)t[i];
    h *= 1099511628211ull;
  }
  return h;
}

static int est_cache_size(void) {
  const int n = g.cfg.estimate_cache_entries;
  return n < 0 ? 0 : n > ESTIMATE_CACHE_MAX_ENTRIES ? ESTIMATE_CACHE_MAX_ENTRIES : n;
}

/* A copy of the cached answer for @p text into *json (under g.mu); false when there is none. */
static bool est_cache_get(uint64_t h, const char *text, size_t len, char **json, size_t *json_len) {
  for (int i = 0; i < est_cache_size(); ++i) {
    est_entry *e = &est_cache.e[i];
    if (!e->text || e->hash != h || e->len != len || memcmp(e->text, text, len) != 0) continue;
    char *c = malloc(e->json_len + 1);
    if (!c) return false;
    memcpy(c, e->json, e->json_len + 1);
    *json = c;
    *json_len = e->json_len;
    e->used = ++est_cache.clock;
    return true;
  }
  return false;
}

/* Keeps a copy of an answer (under g.mu); nothing when it is too large or memory is short. */
static void est_cache_put(uint64_t h, const char *text, size_t len, const char *json, size_t json_len) {
  const int n = est_cache_size();
  if (n == 0 || len + json_len > ESTIMATE_CACHE_MAX_BYTES) return;
  int slot = 0;
  for (int i = 0; i < n; ++i) {
    est_entry *e = &est_cache.e[i];
    if (e->text && e->hash == h && e->len == len && memcmp(e->text, text, len) == 0) return; /* already */
    if (!e->text) {
      slot = i;
      break;
    }
    if (e->used < est_cache.e[slot].used) slot = i;
  }
  char *t = malloc(len + 1), *j = malloc(json_len + 1);
  if (!t || !j) {
    free(t);
    free(j);
    return;
  }
  memcpy(t, text, len);
  t[len] = '\0';
  memcpy(j, json, json_len);
  j[json_len] = '\0';
  est_entry *e = &est_cache.e[slot];
  free(e->text);
  free(e->json);
  *e = (est_entry){h, t, j, len, json_len, ++est_cache.clock};
}

void serve_estimate_cache_clear(void) {
  pthread_mutex_lock(&g.mu);
  for (int i = 0; i < ESTIMATE_CACHE_MAX_ENTRIES; ++i) {
    free(est_cache.e[i].text);
    free(est_cache.e[i].json);
    est_cache.e[i] = (est_entry){0};
  }
  pthread_mutex_unlock(&g.mu);
}

estimate_rc serve_estimate(const char *text, size_t len, char **json, size_t *json_len, char *why,
                           size_t why_size) {
  *json = NULL;
  const uint64_t h = text_hash(text, len);
  pthread_mutex_lock(&g.mu);
  if (!g.stopping && est_cache_get(h, text, len, json, json_len)) {
    pthread_mutex_unlock(&g.mu);
    return EST_OK;
  }
  const bool busy = g.n_estimates >= g.cfg.max_parallel_estimates || g.stopping;
  if (!busy) ++g.n_estimates;
  pthread_mutex_unlock(&g.mu);
  if (busy) return EST_BUSY;
  estimate_rc rc = EST_FAILED;
  char dir[SERVE_PATH_MAX + 32], path[SERVE_PATH_MAX + 64];
  snprintf(dir, sizeof dir, "%s/est-XXXXXX", g.tmp_dir);
  snprintf(why, why_size, "the server could not compute the estimate");
  if (!mkdtemp(dir)) goto done;
  snprintf(path, sizeof path, "%s/scene.yaml", dir);
  const int fd = open(path, O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
  size_t off = 0;
  while (fd >= 0 && off < len) {
    const ssize_t w = write(fd, text + off, len - off);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) break;
    off += (size_t)w;
  }
  if (fd < 0 || close(fd) != 0 || off != len) goto cleanup;
  /* estimate.json is the answer: without estimate.csv (--no-csv), whose rows nobody reads here. */
  char *argv[] = {"navsim", "estimate", "scene.yaml", "--out", "est", "--quiet", "--no-csv", NULL};
  const pid_t pid = serve_spawn(dir, argv, -1, g.cfg.estimate_cpu_s, "log.txt");
  if (pid < 0) goto cleanup;
  struct rusage ru;
  bool watchdog = false;
  const int status = supervise(NULL, pid, -1, 3.0 * (double)g.cfg.estimate_cpu_s + 5.0, &ru, &watchdog);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
    snprintf(path, sizeof path, "%s/est/estimate.json", dir);
    *json = serve_read_file(path, 64u << 20, json_len);
    if (*json) rc = EST_OK;
    if (*json) {
      pthread_mutex_lock(&g.mu);
      est_cache_put(h, text, len, *json, *json_len);
      pthread_mutex_unlock(&g.mu);
    }
  } else if (watchdog ||
             (WIFSIGNALED(status) && (WTERMSIG(status) == SIGXCPU || WTERMSIG(status) == SIGKILL))) {
    snprintf(why, why_size, "the estimate exceeded its CPU limit of %ld s (estimate_cpu_s)",
             g.cfg.estimate_cpu_s);
  } else {
    char tail[800];
    snprintf(path, sizeof path, "%s/log.txt", dir);
    log_tail(path, tail, sizeof tail);
    snprintf(why, why_size, "navsim estimate failed: %s", tail);
  }
cleanup:
  serve_remove_tree(dir);
done:
  pthread_mutex_lock(&g.mu);
  --g.n_estimates;
  pthread_mutex_unlock(&g.mu);
  return rc;
}
