/*
 * navsim's contract for ins_gnss_tight (issue 22): the scene checks (a receiver, a constellation
 * and the wgs84 Earth are needed; a bad raw-measurement value is reported at FILE:LINE:COL), the
 * commands that do not support the scheme yet refuse it clearly (budget, select, select
 * --schemes: exit 2 with a message, nothing written), and navsim run writes gnss_mask.csv next to
 * gnss_sats.csv with the mask of every canyon.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define TIGHT NAV_SOURCE_DIR "/scenes/urban-canyon-tight.yaml"

static int setup(void **state) {
  (void)state;
  return nav_test_fresh_dir(WORK);
}

/* The tight scene with one line replaced (the first line starting with @p from). */
static void variant(const char *name, const char *from, const char *to) {
  char *text = nav_test_slurp_alloc(TIGHT);
  assert_non_null(text);
  char *at = strstr(text, from);
  assert_non_null(at);
  char *eol = strchr(at, '\n');
  assert_non_null(eol);
  const size_t n = strlen(text) + strlen(to) + 2;
  char *out = malloc(n);
  snprintf(out, n, "%.*s%s%s", (int)(at - text), text, to, eol);
  nav_test_write_file(WORK, name, out);
  free(out);
  free(text);
}

static void test_scene_checks(void **state) {
  (void)state;
  /* Without the constellation section (cut up to initial_errors:). */
  char *text = nav_test_slurp_alloc(TIGHT);
  assert_non_null(text);
  char *a = strstr(text, "  constellation:"), *b = strstr(text, "initial_errors:");
  assert_true(a && b && b > a);
  const size_t n = strlen(text) + 1;
  char *cut = malloc(n);
  snprintf(cut, n, "%.*s\n%s", (int)(a - text), text, b);
  nav_test_write_file(WORK, "noconst.yaml", cut);
  free(cut);
  free(text);
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "check noconst.yaml");
  assert_int_equal(r->code, 2);
  print_message("%s", r->err);
  nav_test_assert_matches(
      r->err, "noconst.yaml:[0-9]+:[0-9]+: error: navigation.scheme: ins_gnss_tight needs satellites");
  variant("nognss.yaml", "  enabled: true", "  enabled: false");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "check nognss.yaml");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "navigation.scheme: ins_gnss_tight needs a GNSS receiver");
  variant("badcode.yaml", "    code_sd_m:", "    code_sd_m: -3");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "check badcode.yaml");
  assert_int_equal(r->code, 2);
  print_message("%s", r->err);
  nav_test_assert_matches(r->err,
                          "badcode.yaml:[0-9]+:[0-9]+: error: gnss.constellation.code_sd_m: must be in");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "check '%s'", TIGHT);
  assert_int_equal(r->code, 0);
}

static void test_unsupported_commands_refuse(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "budget '%s' --out b", TIGHT);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "ins_gnss_tight is not supported by the error budget yet");
  assert_false(nav_test_is_file(WORK "/b/budget.csv"));
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "select '%s' --out s", TIGHT);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "navsim select does not support ins_gnss_tight yet");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "select '%s' --schemes ins_gnss,ins_gnss_tight --out s2",
                        TIGHT);
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "--schemes: ins_gnss_tight is not supported by select yet");
  assert_false(nav_test_is_file(WORK "/s/ranking.csv"));
  assert_false(nav_test_is_file(WORK "/s2/ranking.csv"));
}

static void test_run_writes_mask(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s' --runs 2 --quiet --out run", TIGHT);
  if (r->code != 0) fail_msg("run: %d\n%s", r->code, r->err);
  char *mask = nav_test_slurp_alloc(WORK "/run/gnss_mask.csv");
  assert_non_null(mask);
  int rows = 0, canyon = 0;
  for (char *line = strtok(mask, "\n"); line; line = strtok(NULL, "\n")) {
    if (rows++ == 0) {
      assert_string_equal(line, "t_s,in_canyon,heading_deg,az_deg,mask_el_deg");
      continue;
    }
    double t, in, hd, az, el;
    assert_int_equal(sscanf(line, "%lf,%lf,%lf,%lf,%lf", &t, &in, &hd, &az, &el), 5);
    if (in > 0.5) {
      ++canyon;
      assert_true(t >= 70.0 && t < 71.0); /* the middle of the [40, 100) s canyon */
      /* walls 25 m high, 7 m away, street along the heading: atan(25 |sin a| / 7), at least 10 deg */
      assert_true(el >= 10.0 - 1e-9 && el <= 74.36);
    } else {
      assert_true(t == 0.0);
      assert_near(el, 10.0, 1e-9);
    }
  }
  assert_int_equal(rows, 1 + 2 * 73);
  assert_int_equal(canyon, 73);
  free(mask);
  /* The requirement verdicts are evaluated (PASS or FAIL, never "not evaluated"). */
  char js[65536];
  nav_test_slurp(WORK "/run/summary.json", js, sizeof js);
  nav_test_assert_matches(js, "\"id\": \"h-canyon-end\"");
  assert_null(strstr(js, "\"evaluated\": false"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_scene_checks),
      cmocka_unit_test(test_unsupported_commands_refuse),
      cmocka_unit_test(test_run_writes_mask),
  };
  return cmocka_run_group_tests(tests, setup, NULL);
}
