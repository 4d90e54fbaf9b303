/*
 * navsim run's gnss.csv holds every fix of run 0 at the receiver's rate, whatever the output rate:
 * urban-drive with a 5 Hz receiver and 1 Hz output. The fixes must be spaced by the receiver's
 * interval except across the scene's outages, none inside an outage (gnss_outages.csv), and their
 * number must be what the receiver rate, the duration and the outages give.
 *
 * NAVSIM_EXE, NAV_TEST_WORK_DIR and NAV_SOURCE_DIR come from the compile definitions.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR

/* Replace the first occurrence of `from` in `s` (heap string) by `to`. */
static char *replace(char *s, const char *from, const char *to) {
  char *p = strstr(s, from);
  if (!p) fail_msg("scene text has no \"%s\"", from);
  const size_t a = (size_t)(p - s), lf = strlen(from), lt = strlen(to), n = strlen(s);
  char *o = malloc(n - lf + lt + 1);
  assert_non_null(o);
  memcpy(o, s, a);
  memcpy(o + a, to, lt);
  memcpy(o + a + lt, p + lf, n - a - lf + 1);
  free(s);
  return o;
}

static void every_fix_at_the_receiver_rate(void **state) {
  (void)state;
  char *scene = nav_test_slurp_alloc(NAV_SOURCE_DIR "/scenes/urban-drive.yaml");
  assert_non_null(scene);
  scene = replace(scene, "output:\n  rate_hz: 10", "output:\n  rate_hz: 1");
  scene = replace(scene, "gnss:\n  enabled: true\n", "gnss:\n  enabled: true\n  update_rate_hz: 5\n");
  char cmd[2048];
  snprintf(cmd, sizeof cmd, "mkdir -p '%s'", WORK);
  assert_int_equal(system(cmd), 0);
  FILE *f = fopen(WORK "/gnss5.yaml", "w");
  assert_non_null(f);
  fputs(scene, f);
  fclose(f);
  free(scene);
  snprintf(cmd, sizeof cmd, "cd '%s' && '%s' run gnss5.yaml --runs 1 --out gn --quiet > gn.log 2>&1", WORK,
           NAVSIM_EXE);
  const int st = system(cmd);
  if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
    char *log = nav_test_slurp_alloc(WORK "/gn.log");
    fail_msg("navsim run failed:\n%s", log ? log : "");
  }
  /* Outages. */
  char *out = nav_test_slurp_alloc(WORK "/gn/gnss_outages.csv");
  assert_non_null(out);
  double o0[8], o1[8];
  int no = 0;
  for (char *line = strchr(out, '\n'); line && line[1] && no < 8; line = strchr(line + 1, '\n'))
    if (sscanf(line + 1, "%lf,%lf", &o0[no], &o1[no]) == 2) no++;
  free(out);
  assert_int_equal(no, 2);
  /* Duration: the last truth row. */
  char *truth = nav_test_slurp_alloc(WORK "/gn/truth.csv");
  assert_non_null(truth);
  char *last = truth + strlen(truth) - 2;
  while (last > truth && *last != '\n') --last;
  const double t_end = strtod(last + 1, NULL);
  free(truth);
  assert_true(t_end > 400.0);
  /* The fixes. */
  char *csv = nav_test_slurp_alloc(WORK "/gn/gnss.csv");
  assert_non_null(csv);
  long rows = 0, regular = 0, across = 0;
  double prev = NAN;
  for (char *line = strchr(csv, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
    const double t = strtod(line + 1, NULL);
    for (int i = 0; i < no; ++i)
      if (t >= o0[i] && t < o1[i]) fail_msg("fix at %.3f s inside the outage [%g, %g)", t, o0[i], o1[i]);
    if (rows > 0) {
      assert_true(t > prev);
      if (fabs(t - prev - 0.2) < 1e-6) regular++;
      else across++;
    }
    prev = t;
    rows++;
  }
  free(csv);
  /* Fixes the receiver makes in [0, t_end] at 5 Hz, less those inside the outages. */
  double expected = floor(t_end / 0.2) + 1.0;
  for (int i = 0; i < no; ++i) expected -= ceil(o1[i] / 0.2 - 1e-9) - ceil(o0[i] / 0.2 - 1e-9);
  print_message("gnss.csv: %ld fixes (%ld spaced 0.2 s, %ld across a gap) for %.1f s at 5 Hz with 2 outages; "
                "expected %.0f\n",
                rows, regular, across, t_end, expected);
  assert_true(fabs((double)rows - expected) <= 1.0);
  assert_true(across <= no);
}

int main(void) {
  const struct CMUnitTest tests[] = {cmocka_unit_test(every_fix_at_the_receiver_rate)};
  return cmocka_run_group_tests(tests, NULL, NULL);
}
