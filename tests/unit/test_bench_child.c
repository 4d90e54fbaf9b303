/*
 * navsim bench's child processes (bench/bench_child.c): exit codes, a program that cannot start,
 * the log of stdout and stderr, the timeout, and a wall time that ends when the child ends. The
 * bench once looked for the child's exit every 20 ms, so no child could measure under 20 ms and
 * the 0.15 s replay read 0.16-0.17 s; here the fastest of five /bin/true runs must measure under
 * 10 ms (a bound on how late the end is seen, not a speed target: /bin/true takes ~1 ms).
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_child.h"

static char g_log[64];

static int setup(void **state) {
  (void)state;
  snprintf(g_log, sizeof g_log, "/tmp/test_bench_child_%ld.log", (long)getpid());
  return 0;
}

static int teardown(void **state) {
  (void)state;
  remove(g_log);
  return 0;
}

static char *read_log(void) {
  static char buf[4096];
  buf[0] = '\0';
  FILE *f = fopen(g_log, "r");
  if (!f) return buf;
  const size_t n = fread(buf, 1, sizeof buf - 1, f);
  buf[n] = '\0';
  fclose(f);
  return buf;
}

static void test_exit_codes_and_log(void **state) {
  (void)state;
  char *ok[] = {"sh", "-c", "echo to-stdout; echo to-stderr >&2; exit 0", NULL};
  child_result r = bench_run_child(ok, g_log, 0.0);
  assert_true(r.started);
  assert_true(r.exited_ok);
  assert_false(r.timed_out);
  assert_int_equal(r.exit_code, 0);
  assert_true(r.wall_s > 0.0);
  assert_non_null(strstr(read_log(), "to-stdout"));
  assert_non_null(strstr(read_log(), "to-stderr"));

  char *three[] = {"sh", "-c", "exit 3", NULL};
  r = bench_run_child(three, g_log, 10.0);
  assert_true(r.started);
  assert_false(r.exited_ok);
  assert_int_equal(r.exit_code, 3);

  char *missing[] = {"/nonexistent/navsim-no-such-program", NULL};
  r = bench_run_child(missing, g_log, 10.0);
  assert_false(r.started);
  assert_false(r.exited_ok);
  assert_non_null(strstr(read_log(), "cannot start /nonexistent/navsim-no-such-program"));
}

static void test_timeout(void **state) {
  (void)state;
  char *slow[] = {"sleep", "30", NULL};
  const child_result r = bench_run_child(slow, g_log, 0.2);
  assert_true(r.started);
  assert_true(r.timed_out);
  assert_false(r.exited_ok);
  assert_true(r.wall_s >= 0.2);
  assert_true(r.wall_s < 25.0); /* killed, not waited for */
}

static void test_end_seen_when_it_happens(void **state) {
  (void)state;
  char *quick[] = {"true", NULL};
  double best = 1e9;
  for (int i = 0; i < 5; ++i) {
    const child_result r = bench_run_child(quick, g_log, 10.0);
    assert_true(r.exited_ok);
    if (r.wall_s < best) best = r.wall_s;
  }
  assert_true(best < 0.010);
  /* And a child that sleeps 50 ms is not measured shorter than its sleep. */
  char *nap[] = {"sleep", "0.05", NULL};
  const child_result r = bench_run_child(nap, g_log, 10.0);
  assert_true(r.exited_ok);
  assert_true(r.wall_s >= 0.05);
}

static void test_settle_writes(void **state) {
  (void)state;
  assert_int_equal(bench_settle_writes("/tmp"), 0);
  assert_int_equal(bench_settle_writes("/nonexistent/navsim-no-such-dir"), -1);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test_setup_teardown(test_exit_codes_and_log, setup, teardown),
      cmocka_unit_test_setup_teardown(test_timeout, setup, teardown),
      cmocka_unit_test_setup_teardown(test_end_seen_when_it_happens, setup, teardown),
      cmocka_unit_test(test_settle_writes),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
