/*
 * No lost data and determinism of navsim results (issue 10), driving the executable:
 *   - determinism: the same scene and seed give byte-identical output files (summary.json minus
 *     its wall-time line) for repeated runs and for --threads 1, 2 and 8;
 *   - SIGKILL during `navsim run --out DIR` at many random moments, with a previous result in
 *     DIR: afterwards DIR holds a complete result (every file, summary.json parses, contents
 *     equal to the previous/new result), never a torn one and never nothing;
 *   - SIGINT / SIGTERM at random moments: exit 130 / 143 with no result directory and no
 *     temporary left, or exit 0 with a complete one;
 *   - SIGKILL of a program saving scenes with nav_scene_write_file() in a loop (alternating two
 *     versions): the file always reads as a valid scene equal to one of the two versions.
 * NAV_KILL_CYCLES (environment) overrides the number of kills per test (default 40).
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
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "navcore/nav_io.h"
#include "navcore/nav_rng.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define SCENE WORK "/durability.yaml"

/* A short INS/GNSS Monte Carlo with sensor errors and an outage: every result file is written. */
static const char *k_scene =
    "format_version: 1\n"
    "name: durability\n"
    "earth: {model: wgs84, origin: {lat_deg: 45, lon_deg: 7, h_m: 200}}\n"
    "trajectory:\n"
    "  type: waypoints\n"
    "  waypoints:\n"
    "    timing: speed\n"
    "    attitude_mode: ground\n"
    "    points:\n"
    "      - {ned_m: [0, 0, 0], speed_mps: 10}\n"
    "      - {ned_m: [150, 0, 0], speed_mps: 10}\n"
    "      - {ned_m: [150, 150, 0], speed_mps: 10}\n"
    "imu:\n  rate_hz: 100\n  catalog: \"Safran Sensonor STIM300\"\n"
    "gnss:\n  enabled: true\n  update_rate_hz: 1\n  position_white_sigma_m: [1, 1, 2]\n"
    "  reported_sigma: {position_m: [1, 1, 2], velocity_mps: [0.1, 0.1, 0.1]}\n"
    "  outages: [[10, 15]]\n"
    "initial_errors: {position_m: [1, 1, 1], velocity_mps: 0.1, attitude_deg: [0.1, 0.1, 1]}\n"
    "navigation: {scheme: ins_gnss}\n"
    "output: {rate_hz: 10}\n"
    "simulation: {seed: 11, runs: 8}\n";

static long cycles(void) {
  const char *e = getenv("NAV_KILL_CYCLES");
  return e && atol(e) > 0 ? atol(e) : 40;
}

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static pid_t spawn(char *const argv[]) {
  const pid_t pid = fork();
  assert_true(pid >= 0);
  if (pid == 0) {
    const int null = open("/dev/null", O_WRONLY);
    if (null >= 0) {
      dup2(null, 1);
      dup2(null, 2);
    }
    execv(argv[0], argv);
    _exit(127);
  }
  return pid;
}

static int wait_code(pid_t pid, int *sig) {
  int status = 0;
  assert_int_equal(waitpid(pid, &status, 0), pid);
  *sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static int run_sync(char *const argv[]) {
  int sig = 0;
  const int code = wait_code(spawn(argv), &sig);
  if (sig) fail_msg("%s %s killed by signal %d", argv[0], argv[1], sig);
  return code;
}

/* ---------------------------------------------------------------- files */

/* FNV-1a 64 of a result file; for summary.json the wall-time line ("timing") is skipped. */
static uint64_t file_hash(const char *dir, const char *name) {
  char path[2048];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  size_t n = 0;
  char *b = nav_test_slurp_len(path, &n);
  if (!b) fail_msg("%s: missing", path);
  uint64_t h = 1469598103934665603ull;
  const bool summary = strcmp(name, "summary.json") == 0;
  for (size_t i = 0; i < n; ++i) {
    if (summary && (i == 0 || b[i - 1] == '\n') && strncmp(b + i, "  \"timing\":", 11) == 0) {
      while (i < n && b[i] != '\n') ++i;
      continue;
    }
    h = (h ^ (unsigned char)b[i]) * 1099511628211ull;
  }
  free(b);
  return h;
}

/* Minimal JSON syntax check: one value, then only whitespace. */
static const char *json_ws(const char *p) {
  while (*p == ' ' || *p == '\n' || *p == '\r' || *p == '\t') ++p;
  return p;
}
static const char *json_value(const char *p, int depth);
static const char *json_string(const char *p) {
  if (*p++ != '"') return NULL;
  while (*p && *p != '"') {
    if ((unsigned char)*p < 0x20) return NULL;
    if (*p == '\\') {
      ++p;
      if (!*p) return NULL;
    }
    ++p;
  }
  return *p == '"' ? p + 1 : NULL;
}
static const char *json_value(const char *p, int depth) {
  if (depth > 64) return NULL;
  p = json_ws(p);
  if (*p == '{' || *p == '[') {
    const char close = *p == '{' ? '}' : ']';
    const bool obj = *p == '{';
    p = json_ws(p + 1);
    if (*p == close) return p + 1;
    for (;;) {
      if (obj) {
        p = json_string(json_ws(p));
        if (!p) return NULL;
        p = json_ws(p);
        if (*p++ != ':') return NULL;
      }
      p = json_value(p, depth + 1);
      if (!p) return NULL;
      p = json_ws(p);
      if (*p == ',') {
        ++p;
        continue;
      }
      return *p == close ? p + 1 : NULL;
    }
  }
  if (*p == '"') return json_string(p);
  if (strncmp(p, "true", 4) == 0) return p + 4;
  if (strncmp(p, "false", 5) == 0) return p + 5;
  if (strncmp(p, "null", 4) == 0) return p + 4;
  char *end = NULL;
  strtod(p, &end);
  return end && end != p ? end : NULL;
}
static bool json_valid(const char *text) {
  const char *p = json_value(text, 0);
  return p && *json_ws(p) == '\0';
}

/* The files of a complete result directory, sorted; count returned. */
static int list_files(const char *dir, char names[][64], int cap) {
  DIR *d = opendir(dir);
  if (!d) return -1;
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL && n < cap) {
    if (e->d_name[0] == '.') continue;
    const size_t len = strnlen(e->d_name, 63);
    memcpy(names[n], e->d_name, len);
    names[n++][len] = '\0';
  }
  closedir(d);
  qsort(names, (size_t)n, 64, (int (*)(const void *, const void *))strcmp);
  return n;
}

typedef struct result_sig {
  int n;
  char names[32][64];
  uint64_t hash[32];
} result_sig;

static void signature(const char *dir, result_sig *s) {
  s->n = list_files(dir, s->names, 32);
  if (s->n <= 0) fail_msg("%s: no result files", dir);
  for (int i = 0; i < s->n; ++i) s->hash[i] = file_hash(dir, s->names[i]);
}

static void assert_same(const result_sig *a, const result_sig *b, const char *what) {
  if (a->n != b->n) fail_msg("%s: %d files against %d", what, a->n, b->n);
  for (int i = 0; i < a->n; ++i) {
    if (strcmp(a->names[i], b->names[i]) != 0) fail_msg("%s: file %s against %s", what, a->names[i], b->names[i]);
    if (a->hash[i] != b->hash[i])
      fail_msg("%s: %s differs (%016llx against %016llx)", what, a->names[i], (unsigned long long)a->hash[i],
               (unsigned long long)b->hash[i]);
  }
}

/* DIR is a complete result: summary.json parses, the same files with the same contents as @p ref. */
static void assert_complete(const char *dir, const result_sig *ref, const char *what) {
  char path[2048];
  snprintf(path, sizeof path, "%s/summary.json", dir);
  size_t n = 0;
  char *js = nav_test_slurp_len(path, &n);
  if (!js) fail_msg("%s: %s has no summary.json (torn result)", what, dir);
  if (!json_valid(js)) fail_msg("%s: summary.json does not parse", what);
  free(js);
  result_sig s;
  signature(dir, &s);
  assert_same(ref, &s, what);
}

static void rm_rf(const char *path) {
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", path);
  assert_int_equal(system(cmd), 0);
}

/* Entries of WORK whose name starts with @p prefix. */
static int count_prefixed(const char *prefix) {
  DIR *d = opendir(WORK);
  assert_non_null(d);
  int n = 0;
  struct dirent *e;
  while ((e = readdir(d)) != NULL)
    if (strncmp(e->d_name, prefix, strlen(prefix)) == 0) ++n;
  closedir(d);
  return n;
}

static int setup(void **state) {
  (void)state;
  char cmd[1024];
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", WORK, WORK);
  if (system(cmd) != 0) return -1;
  FILE *f = fopen(SCENE, "w");
  if (!f) return -1;
  fputs(k_scene, f);
  return fclose(f) == 0 ? 0 : -1;
}

/* ---------------------------------------------------------------- tests */

static void test_determinism(void **state) {
  (void)state;
  const char *threads[] = {"1", "2", "8", "1"};
  result_sig ref, s;
  for (int i = 0; i < 4; ++i) {
    char dir[1024];
    snprintf(dir, sizeof dir, WORK "/det-%d", i);
    char *argv[] = {NAVSIM_EXE, "run", SCENE, "--out", dir, "--quiet", "--threads", (char *)threads[i], NULL};
    assert_int_equal(run_sync(argv), 0);
    signature(dir, i == 0 ? &ref : &s);
    if (i > 0) {
      char what[128];
      snprintf(what, sizeof what, "--threads %s against --threads 1", threads[i]);
      assert_same(&ref, &s, what);
    }
  }
  printf("determinism: %d files, byte-identical for threads 1, 2, 8 and a repeated run\n", ref.n);
  for (int i = 0; i < ref.n; ++i) printf("  %-20s %016llx\n", ref.names[i], (unsigned long long)ref.hash[i]);
}

static void test_kill_during_run(void **state) {
  (void)state;
  const char *dir = WORK "/kill";
  char *argv[] = {NAVSIM_EXE, "run", SCENE, "--out", (char *)dir, "--quiet", "--threads", "2", NULL};
  double t0 = now_s();
  assert_int_equal(run_sync(argv), 0); /* the previous result */
  const double full = now_s() - t0;
  result_sig ref;
  signature(dir, &ref);
  nav_rng rng;
  nav_rng_init(&rng, 77, 0, 0);
  const long n = cycles();
  long killed = 0, finished = 0;
  for (long c = 0; c < n; ++c) {
    const double delay = 1.1 * full * nav_rng_uniform(&rng);
    const pid_t pid = spawn(argv);
    struct timespec ts = {(time_t)delay, (long)((delay - (double)(time_t)delay) * 1e9)};
    nanosleep(&ts, NULL);
    kill(pid, SIGKILL);
    int sig = 0;
    const int code = wait_code(pid, &sig);
    if (sig == SIGKILL) ++killed;
    else if (code == 0) ++finished;
    else fail_msg("cycle %ld: navsim exited with %d", c, code);
    char what[128];
    snprintf(what, sizeof what, "SIGKILL after %.3f s (cycle %ld)", delay, c);
    struct stat st;
    if (stat(dir, &st) != 0) fail_msg("%s: the result directory is gone", what);
    assert_complete(dir, &ref, what);
  }
  const int stale = count_prefixed(".kill.tmp-");
  /* The next run removes the temporaries of the killed ones. */
  assert_int_equal(run_sync(argv), 0);
  assert_complete(dir, &ref, "the run after the kills");
  printf("SIGKILL during navsim run: %ld cycles (full run %.2f s): %ld killed, %ld finished; the result directory was "
         "complete after every one; %d temporaries of killed runs, removed by the next run\n",
         n, full, killed, finished, stale);
  assert_int_equal(count_prefixed(".kill.tmp-"), 0);
  assert_true(killed > 0);
}

static void test_interrupt(void **state) {
  (void)state;
  const char *dir = WORK "/intr";
  char *argv[] = {NAVSIM_EXE, "run", SCENE, "--out", (char *)dir, "--quiet", "--threads", "2", NULL};
  double t0 = now_s();
  assert_int_equal(run_sync(argv), 0);
  const double full = now_s() - t0;
  result_sig ref;
  signature(dir, &ref);
  nav_rng rng;
  nav_rng_init(&rng, 78, 0, 0);
  const long n = cycles() / 2 + 1;
  long interrupted = 0;
  for (long c = 0; c < n; ++c) {
    rm_rf(dir);
    const double delay = 1.1 * full * nav_rng_uniform(&rng);
    const int signo = (c % 2) ? SIGTERM : SIGINT;
    const pid_t pid = spawn(argv);
    struct timespec ts = {(time_t)delay, (long)((delay - (double)(time_t)delay) * 1e9)};
    nanosleep(&ts, NULL);
    kill(pid, signo);
    int sig = 0;
    const int code = wait_code(pid, &sig);
    char what[128];
    snprintf(what, sizeof what, "signal %d after %.3f s (cycle %ld)", signo, delay, c);
    struct stat st;
    if (code == 0) {
      assert_complete(dir, &ref, what);
    } else if (code == 128 + signo || sig == signo) {
      /* Before the handler is installed the default action ends the process: nothing written yet. */
      ++interrupted;
      if (stat(dir, &st) == 0) fail_msg("%s: a cancelled run left the result directory", what);
    } else {
      fail_msg("%s: exit code %d", what, code);
    }
    if (count_prefixed(".intr.tmp-") != 0 && code != 0 && sig == 0)
      fail_msg("%s: a cancelled run left its temporary directory", what);
  }
  printf("SIGINT/SIGTERM during navsim run: %ld cycles, %ld interrupted (no directory left), the rest complete\n", n,
         interrupted);
  assert_true(interrupted > 0);
}

/* The scene-save helper: writes version A and B of a scene to PATH alternately, forever. */
static void test_kill_during_scene_save(void **state) {
  (void)state;
  const char *path = WORK "/saved.yaml";
  char *a_path = WORK "/version-a.yaml", *b_path = WORK "/version-b.yaml";
  nav_scene sa = nav_scene_default(), sb = nav_scene_default();
  snprintf(sa.name, sizeof sa.name, "version-a");
  snprintf(sb.name, sizeof sb.name, "version-b");
  sb.imu.rate_hz = 200.0;
  sb.trajectory.duration_s = 33.0;
  assert_int_equal(nav_scene_write_file(a_path, &sa), NAV_OK);
  assert_int_equal(nav_scene_write_file(b_path, &sb), NAV_OK);
  size_t la = 0, lb = 0;
  char *ta = nav_test_slurp_len(a_path, &la), *tb = nav_test_slurp_len(b_path, &lb);
  assert_non_null(ta);
  assert_non_null(tb);
  assert_int_equal(nav_scene_write_file(path, &sa), NAV_OK);
  nav_rng rng;
  nav_rng_init(&rng, 79, 0, 0);
  const long n = cycles();
  long saw_a = 0, saw_b = 0;
  for (long c = 0; c < n; ++c) {
    char *argv[] = {SCENE_SAVE_EXE, (char *)path, a_path, b_path, NULL};
    const pid_t pid = spawn(argv);
    const double delay = 0.2 * nav_rng_uniform(&rng);
    struct timespec ts = {0, (long)(delay * 1e9)};
    nanosleep(&ts, NULL);
    kill(pid, SIGKILL);
    int sig = 0;
    (void)wait_code(pid, &sig);
    size_t l = 0;
    char *t = nav_test_slurp_len(path, &l);
    if (!t) fail_msg("cycle %ld: %s is gone after SIGKILL at %.3f s", c, path, delay);
    if (l == la && memcmp(t, ta, la) == 0) ++saw_a;
    else if (l == lb && memcmp(t, tb, lb) == 0) ++saw_b;
    else fail_msg("cycle %ld: %s is torn (%zu bytes) after SIGKILL at %.3f s", c, path, l, delay);
    free(t);
    nav_scene back;
    assert_int_equal(nav_scene_read_file(path, &back, NULL, NULL), NAV_OK);
  }
  printf("SIGKILL during scene saves: %ld cycles, file intact every time (%ld times version A, %ld times B)\n", n,
         saw_a, saw_b);
  free(ta);
  free(tb);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup(test_determinism, setup),
      cmocka_unit_test_setup(test_kill_during_run, setup),
      cmocka_unit_test_setup(test_interrupt, setup),
      cmocka_unit_test_setup(test_kill_during_scene_save, setup),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
