/*
 * The sandbox of navsim serve's jobs (web/server/jobs.c, serve_spawn_prog) seen from inside: a
 * shell started the way every job is started reports its limits, privileges, process group, open
 * descriptors and environment, and tries to write outside its directory. Also the ids and the
 * JSON text of the server (util.c).
 */
#define _GNU_SOURCE
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <linux/landlock.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include "serve_internal.h"

static char g_root[256];
static char g_job[512];

static int setup(void **state) {
  (void)state;
  snprintf(g_root, sizeof g_root, "/tmp/navsim-sandbox-XXXXXX");
  if (!mkdtemp(g_root)) return -1;
  setenv("NAVSERVE_TEST_SECRET", "must-not-reach-the-job", 1);
  serve_config c = serve_config_default();
  snprintf(c.data_dir, sizeof c.data_dir, "%s/data", g_root);
  c.job_open_files = 32;
  c.job_output_mb = 1;
  c.max_parallel_jobs = 1;
  char why[512];
  if (!serve_jobs_start(&c, why, sizeof why)) {
    fprintf(stderr, "serve_jobs_start: %s\n", why);
    return -1;
  }
  snprintf(g_job, sizeof g_job, "%s/data/jobs/0123456789abcdef0123456789abcdef", g_root);
  return mkdir(g_job, 0700);
}

static int teardown(void **state) {
  (void)state;
  serve_jobs_stop();
  serve_remove_tree(g_root);
  return 0;
}

/* Run `sh -c SCRIPT` as a job (CPU limit @p cpu_s); its output; the wait status in *status. */
static char *run_sh(const char *script, long cpu_s, int *status) {
  char *argv[] = {"sh", "-c", (char *)script, NULL};
  const pid_t pid = serve_spawn_prog("/bin/sh", g_job, argv, -1, cpu_s, "out.txt");
  assert_true(pid > 0);
  assert_int_equal(waitpid(pid, status, 0), pid);
  char path[600];
  snprintf(path, sizeof path, "%s/out.txt", g_job);
  size_t n = 0;
  char *text = serve_read_file(path, 1 << 20, &n);
  assert_non_null(text);
  return text;
}

static void test_limits(void **state) {
  (void)state;
  int st = 0;
  /* dash's ulimit: -t seconds, -n descriptors, -c and -f in 512-byte blocks */
  char *out = run_sh("ulimit -t; ulimit -n; ulimit -c; ulimit -f", 7, &st);
  assert_true(WIFEXITED(st) && WEXITSTATUS(st) == 0);
  assert_string_equal(out, "7\n32\n0\n2048\n");
  free(out);
}

static void test_privileges_group_fds_env(void **state) {
  (void)state;
  int st = 0;
  char *out = run_sh("grep NoNewPrivs /proc/self/status", 5, &st);
  assert_string_equal(out, "NoNewPrivs:\t1\n");
  free(out);
  /* Its own process group: the pgid (field 5 of /proc/self/stat) is its pid (field 1). */
  out = run_sh("read pid comm state ppid pgid rest < /proc/self/stat; [ \"$pid\" = \"$pgid\" ] && echo own", 5, &st);
  assert_string_equal(out, "own\n");
  free(out);
  /* Descriptors: 0, 1, 2 and the one ls opens for the listing, nothing of the parent. */
  out = run_sh("ls /proc/self/fd | sort -n | tr '\\n' ' '", 5, &st);
  assert_string_equal(out, "0 1 2 3 ");
  free(out);
  out = run_sh("env | sort | grep -v -e '^PWD=' -e '^SHLVL=' -e '^_=' -e 'SAN_OPTIONS=' -e '^NAV_'", 5, &st);
  assert_string_equal(out, "LC_ALL=C\nPATH=/usr/bin:/bin\n");
  free(out);
  out = run_sh("cat /dev/stdin | wc -c; umask", 5, &st);
  assert_string_equal(out, "0\n0077\n");
  free(out);
}

static void test_writes_stay_inside(void **state) {
  (void)state;
  if (syscall(SYS_landlock_create_ruleset, NULL, 0, LANDLOCK_CREATE_RULESET_VERSION) < 1) {
    fprintf(stderr, "this kernel has no Landlock: writes outside a job's directory are not confined\n");
    skip();
  }
  char script[2400], outside[600], inside[600];
  snprintf(outside, sizeof outside, "%s/outside.txt", g_root);
  snprintf(inside, sizeof inside, "%s/inside.txt", g_job);
  snprintf(script, sizeof script,
           "echo in > inside.txt; mkdir -p sub && echo deep > sub/f; { echo out > %s; } 2>/dev/null || echo refused; "
           "rm -f %s/data 2>/dev/null; mkdir %s/evil 2>/dev/null || echo refused",
           outside, g_root, g_root);
  int st = 0;
  char *out = run_sh(script, 5, &st);
  assert_string_equal(out, "refused\nrefused\n");
  free(out);
  struct stat sb;
  assert_int_equal(stat(inside, &sb), 0);
  assert_int_not_equal(stat(outside, &sb), 0);
}

static void test_cpu_limit(void **state) {
  (void)state;
  int st = 0;
  char *out = run_sh("while :; do :; done", 1, &st);
  free(out);
  assert_true(WIFSIGNALED(st));
  assert_true(WTERMSIG(st) == SIGXCPU || WTERMSIG(st) == SIGKILL);
}

static void test_ids_and_json(void **state) {
  (void)state;
  char a[33], b[33];
  assert_true(serve_random_id(a));
  assert_true(serve_random_id(b));
  assert_true(serve_is_id(a));
  assert_string_not_equal(a, b);
  assert_false(serve_is_id("0123456789ABCDEF0123456789abcdef"));
  assert_false(serve_is_id("0123456789abcdef0123456789abcde"));
  assert_false(serve_is_id("0123456789abcdef0123456789abcdef0"));
  assert_false(serve_is_id(NULL));
  sbuf s = {0};
  sb_json_str(&s, "a\"b\\c\n\x01\xff\xc0\xae\xed\xa0\x80 \xc3\xa9 \xf0\x9f\x9a\x80");
  size_t n = 0;
  char *t = sb_take(&s, &n);
  assert_string_equal(t, "\"a\\\"b\\\\c\\u000a\\u0001\\ufffd\\ufffd\\ufffd\\ufffd\\ufffd\\ufffd \xc3\xa9 \xf0\x9f\x9a\x80\"");
  free(t);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_limits),           cmocka_unit_test(test_privileges_group_fds_env),
      cmocka_unit_test(test_writes_stay_inside), cmocka_unit_test(test_cpu_limit),
      cmocka_unit_test(test_ids_and_json),
  };
  return cmocka_run_group_tests(tests, setup, teardown);
}
