/*
 * Hostile inputs against the navsim executable (issue 10): every file of tests/data/hostile
 * listed in expected.tsv, plus a few generated ones too large to keep in the repository. For
 * each: no crash (the process exits, never by a signal), no hang (killed after 120 s), the exit
 * code of the contract (2 for invalid input), a diagnostic FILE:LINE:COL: error: ... with the
 * expected place and message, bounded memory (RLIMIT_AS 2 GiB in the child, outside the
 * sanitizer builds, and the peak resident size reported by wait4 below 2 GiB), and no result
 * directory (nor a leftover temporary one) after a refused `navsim run`.
 *
 * NAVSIM_EXE, NAV_TEST_DATA_DIR and NAV_TEST_WORK_DIR come from the build.
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "navsim_cli.h"

#define HOSTILE NAV_TEST_DATA_DIR "/hostile"
#define REPLAY NAV_TEST_DATA_DIR "/replay"
#define WORK NAV_TEST_WORK_DIR

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define NAV_UNDER_SANITIZER 1 /* the shadow memory needs terabytes of address space */
#else
#define NAV_UNDER_SANITIZER 0
#endif

static const long k_mem_limit_bytes = 2048L * 1024 * 1024;
static const int k_timeout_s = 120;

typedef struct outcome {
  int exited;    /* 1 if the process exited (not killed by a signal) */
  int code;      /* exit code */
  int signal;    /* terminating signal, else 0 */
  long maxrss_kb; /* peak resident set size */
  double wall_s;
  char err[65536];
} outcome;

static long g_worst_rss_kb;
static char g_worst_rss_case[256];

/* Run navsim with @p argv (NULL-terminated, argv[0] ignored) in @p cwd. */
static void run_navsim(const char *cwd, char *const argv[], outcome *o) {
  memset(o, 0, sizeof *o);
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  const pid_t pid = fork();
  assert_true(pid >= 0);
  if (pid == 0) {
    if (chdir(cwd) != 0) _exit(126);
    const int out = open(WORK "/stdout.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(WORK "/stderr.txt", O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (out < 0 || err < 0) _exit(126);
    dup2(out, 1);
    dup2(err, 2);
    if (!NAV_UNDER_SANITIZER) {
      struct rlimit rl = {(rlim_t)k_mem_limit_bytes, (rlim_t)k_mem_limit_bytes};
      setrlimit(RLIMIT_AS, &rl);
    }
    execv(NAVSIM_EXE, argv);
    _exit(127);
  }
  int status = 0;
  struct rusage ru;
  memset(&ru, 0, sizeof ru);
  for (;;) {
    const pid_t w = wait4(pid, &status, WNOHANG, &ru);
    if (w == pid) break;
    assert_true(w == 0);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    if ((double)(t1.tv_sec - t0.tv_sec) > k_timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      fail_msg("navsim %s %s: no answer after %d s (hang)", argv[1], argv[2] ? argv[2] : "", k_timeout_s);
    }
    usleep(2000);
  }
  clock_gettime(CLOCK_MONOTONIC, &t1);
  o->wall_s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
  o->exited = WIFEXITED(status);
  o->code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o->signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  o->maxrss_kb = ru.ru_maxrss;
  nav_test_slurp(WORK "/stderr.txt", o->err, sizeof o->err);
  if (o->maxrss_kb > g_worst_rss_kb) {
    g_worst_rss_kb = o->maxrss_kb;
    snprintf(g_worst_rss_case, sizeof g_worst_rss_case, "%s %s", argv[1], argv[2] ? argv[2] : "");
  }
}

/* The first stderr line containing @p fragment must start with "FILE:LOC: error: " (LOC "-":
 * "FILE: error: "). */
static void assert_diag(const outcome *o, const char *what, const char *file, const char *loc,
                        const char *fragment) {
  const char *p = o->err;
  while (*p) {
    const char *eol = strchr(p, '\n');
    const size_t len = eol ? (size_t)(eol - p) : strlen(p);
    char line[8192];
    snprintf(line, sizeof line, "%.*s", (int)(len < sizeof line ? len : sizeof line - 1), p);
    if (strstr(line, fragment)) {
      char prefix[1024];
      if (strcmp(loc, "-") == 0) snprintf(prefix, sizeof prefix, "%s: error: ", file);
      else snprintf(prefix, sizeof prefix, "%s:%s: error: ", file, loc);
      if (strncmp(line, prefix, strlen(prefix)) != 0)
        fail_msg("%s: the diagnostic \"%s\" does not start with \"%s\"", what, line, prefix);
      return;
    }
    p = eol ? eol + 1 : p + len;
  }
  fail_msg("%s: no diagnostic contains \"%s\"; stderr was:\n%.2000s", what, fragment, o->err);
}

static void assert_clean_exit(const outcome *o, const char *what, int code) {
  if (!o->exited) fail_msg("%s: killed by signal %d (crash); stderr:\n%.2000s", what, o->signal, o->err);
  if (o->code != code) fail_msg("%s: exit code %d, expected %d; stderr:\n%.2000s", what, o->code, code, o->err);
  if (strstr(o->err, "Sanitizer") || strstr(o->err, "runtime error"))
    fail_msg("%s: sanitizer finding:\n%.4000s", what, o->err);
  if (o->maxrss_kb * 1024L > k_mem_limit_bytes)
    fail_msg("%s: peak resident size %ld KiB exceeds the 2 GiB bound", what, o->maxrss_kb);
}

/* Nothing left in WORK but the captured streams: no result directory, no hidden temporary. */
static void assert_no_result_dir(const char *what) {
  DIR *d = opendir(WORK);
  assert_non_null(d);
  struct dirent *e;
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
    if (strcmp(e->d_name, "stdout.txt") == 0 || strcmp(e->d_name, "stderr.txt") == 0) continue;
    if (strncmp(e->d_name, "gen-", 4) == 0) continue; /* generated inputs */
    closedir(d);
    fail_msg("%s: a refused run left \"%s\" in the work directory", what, e->d_name);
  }
  closedir(d);
}

/* `navsim check F` and `navsim run F` both exit 2 with the expected diagnostic. */
static void expect_scene(const char *cwd, const char *file, const char *loc, const char *fragment) {
  char what[1024];
  outcome *o = malloc(sizeof *o);
  assert_non_null(o);
  snprintf(what, sizeof what, "navsim check %s", file);
  char *a1[] = {"navsim", "check", (char *)file, NULL};
  run_navsim(cwd, a1, o);
  assert_clean_exit(o, what, 2);
  assert_diag(o, what, file, loc, fragment);
  snprintf(what, sizeof what, "navsim run %s", file);
  char *a2[] = {"navsim", "run", (char *)file, "--out", WORK "/out", "--quiet", "--threads", "2", NULL};
  run_navsim(cwd, a2, o);
  assert_clean_exit(o, what, 2);
  assert_diag(o, what, file, loc, fragment);
  assert_no_result_dir(what);
  free(o);
}

static void expect_replay(const char *slot, const char *file, const char *loc, const char *fragment) {
  char what[1024];
  snprintf(what, sizeof what, "navsim replay --%s %s", slot, file);
  char *imu = REPLAY "/IMU-100195-100245.txt", *gnss = REPLAY "/GNSS-100195-100245.txt",
       *truth = REPLAY "/truth-100195-100245-20Hz.nav";
  if (strcmp(slot, "imu") == 0) imu = (char *)file;
  else if (strcmp(slot, "gnss") == 0) gnss = (char *)file;
  else truth = (char *)file;
  char *a[] = {"navsim", "replay", "--imu", imu, "--gnss", gnss, "--truth", truth, NULL};
  outcome *o = malloc(sizeof *o);
  assert_non_null(o);
  run_navsim(HOSTILE, a, o);
  assert_clean_exit(o, what, 2);
  assert_diag(o, what, file, loc, fragment);
  free(o);
}

/* check accepts it; run stops with exit 1, naming the failure and its time, and leaves nothing. */
static void expect_numeric(const char *file, const char *fragment) {
  char what[1024];
  outcome *o = malloc(sizeof *o);
  assert_non_null(o);
  snprintf(what, sizeof what, "navsim check %s", file);
  char *a1[] = {"navsim", "check", (char *)file, NULL};
  run_navsim(HOSTILE, a1, o);
  assert_clean_exit(o, what, 0);
  snprintf(what, sizeof what, "navsim run %s", file);
  char *a2[] = {"navsim", "run", (char *)file, "--out", WORK "/out", "--quiet", NULL};
  run_navsim(HOSTILE, a2, o);
  assert_clean_exit(o, what, 1);
  if (!strstr(o->err, fragment)) fail_msg("%s: stderr lacks \"%s\":\n%.2000s", what, fragment, o->err);
  if (strstr(o->err, "nan") || strstr(o->err, "NaN")) fail_msg("%s: a NaN reached the message: %s", what, o->err);
  assert_no_result_dir(what);
  free(o);
}

/* `navsim import F --out S`: exit 2 with the diagnostic and no S; or (safe) exit 0 and S free of
 * @p fragment. */
static void expect_import(const char *file, const char *loc, const char *fragment, bool safe) {
  char what[1024];
  snprintf(what, sizeof what, "navsim import %s", file);
  /* import-safe rows write a scene whatever its distance from the track (issue 18: a plan that
   * strays beyond --tolerance is otherwise refused; these rows test what is written). */
  char *a[] = {"navsim", "import", (char *)file, "--out", WORK "/imported.yaml", safe ? "--accept-distance" : NULL,
               NULL};
  outcome *o = malloc(sizeof *o);
  assert_non_null(o);
  run_navsim(HOSTILE, a, o);
  struct stat st;
  if (safe) {
    assert_clean_exit(o, what, 0);
    char *text = malloc(1 << 20);
    assert_non_null(text);
    nav_test_slurp(WORK "/imported.yaml", text, 1 << 20);
    if (strstr(text, fragment)) fail_msg("%s: the written scene contains \"%s\"", what, fragment);
    free(text);
    remove(WORK "/imported.yaml");
  } else {
    assert_clean_exit(o, what, 2);
    assert_diag(o, what, file, loc, fragment);
    if (stat(WORK "/imported.yaml", &st) == 0) fail_msg("%s: a refused import wrote its scene", what);
  }
  assert_no_result_dir(what);
  free(o);
}

static int setup(void **state) {
  (void)state;
  char cmd[1024];
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", WORK, WORK);
  return system(cmd) == 0 ? 0 : -1;
}

/* Every row of expected.tsv. */
static void test_corpus(void **state) {
  (void)state;
  FILE *f = fopen(HOSTILE "/expected.tsv", "r");
  assert_non_null(f);
  char line[2048];
  int rows = 0, scenes = 0;
  while (fgets(line, sizeof line, f)) {
    line[strcspn(line, "\r\n")] = '\0';
    if (line[0] == '#' || line[0] == '\0') continue;
    char *save = NULL;
    char *file = strtok_r(line, "\t", &save), *mode = strtok_r(NULL, "\t", &save),
         *loc = strtok_r(NULL, "\t", &save), *frag = strtok_r(NULL, "\t", &save);
    if (!file || !mode || !loc || !frag) fail_msg("expected.tsv: malformed row %d", rows + 1);
    char path[1024];
    snprintf(path, sizeof path, "%s/%s", HOSTILE, file);
    struct stat st;
    if (stat(path, &st) != 0) fail_msg("expected.tsv names %s, which does not exist", file);
    if (strcmp(mode, "scene") == 0) {
      expect_scene(HOSTILE, file, loc, frag);
      ++scenes;
    } else if (strncmp(mode, "replay-", 7) == 0) {
      expect_replay(mode + 7, file, loc, frag);
    } else if (strcmp(mode, "numeric") == 0) {
      expect_numeric(file, frag);
    } else if (strcmp(mode, "import") == 0 || strcmp(mode, "import-safe") == 0) {
      expect_import(file, loc, frag, mode[6] == '-');
    } else {
      fail_msg("expected.tsv: unknown mode \"%s\"", mode);
    }
    ++rows;
  }
  fclose(f);
  /* Every hostile scene in the directory is listed (a new file without an expectation fails). */
  DIR *d = opendir(HOSTILE);
  assert_non_null(d);
  struct dirent *e;
  int files = 0;
  while ((e = readdir(d)) != NULL) {
    const size_t n = strlen(e->d_name);
    if (n > 5 && strcmp(e->d_name + n - 5, ".yaml") == 0) ++files;
  }
  closedir(d);
  printf("hostile corpus: %d rows (%d scenes, each through check and run); %d .yaml files\n", rows, scenes, files);
  assert_true(rows > 0);
  assert_true(scenes + 1 >= files); /* + noise-huge.yaml (numeric) */
}

static void write_gen(const char *name, const char *head, const char *unit, long repeat, const char *tail) {
  char path[1024];
  snprintf(path, sizeof path, "%s/%s", WORK, name);
  FILE *f = fopen(path, "w");
  assert_non_null(f);
  fputs(head, f);
  for (long i = 0; i < repeat; ++i) fputs(unit, f);
  fputs(tail, f);
  assert_int_equal(fclose(f), 0);
}

/* Inputs too big to keep in the repository. */
static void test_generated(void **state) {
  (void)state;
  /* 17 MiB: above the 16 MiB cap, refused before parsing. */
  write_gen("gen-oversize.yaml", "format_version: 1\n", "# padding to make the file large ....\n",
            17L * 1024 * 1024 / 38 + 1, "");
  expect_scene(WORK, "gen-oversize.yaml", "-", "the file is too large");
  /* 1.2 million YAML nodes in a flow sequence (2.4 MB): above the 10^6-node cap. */
  write_gen("gen-many-nodes.yaml", "format_version: 1\nimu:\n  x: [0", ",0", 1200000, "]\n");
  expect_scene(WORK, "gen-many-nodes.yaml", "3:1999993", "more than 1000000 YAML nodes");
  /* 100000 nested flow sequences: depth cap, no recursion in the parser. */
  write_gen("gen-deep.yaml", "format_version: 1\nimu: ", "[", 100000, "");
  expect_scene(WORK, "gen-deep.yaml", "2:69", "nesting is deeper than 64 levels");
  /* 900000 aliases of one anchor (2.7 MB, under both caps): aliases are never expanded. */
  write_gen("gen-aliases.yaml", "format_version: 1\nname: &n x\nimu:\n  x: [*n", ",*n", 900000, "]\n");
  expect_scene(WORK, "gen-aliases.yaml", "4:3", "unknown key \"x\"");
  /* Runs from the command line beyond the per-process limit. */
  outcome *o = malloc(sizeof *o);
  assert_non_null(o);
  char *a[] = {"navsim", "run", NAV_SOURCE_DIR "/scenes/paper-parametric.yaml", "--runs", "1000000000", "--out",
               WORK "/out", "--quiet", NULL};
  run_navsim(WORK, a, o);
  assert_clean_exit(o, "navsim run --runs 1000000000", 2);
  if (!strstr(o->err, "--runs: expected an integer in [1, 1000000]")) fail_msg("--runs 1e9: %s", o->err);
  assert_no_result_dir("navsim run --runs 1000000000");
  free(o);
  printf("largest peak resident size: %ld KiB (%s)\n", g_worst_rss_kb, g_worst_rss_case);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_corpus, setup),
      cmocka_unit_test_setup(test_generated, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
