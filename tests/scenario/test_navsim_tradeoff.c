/*
 * navsim tradeoff contract (issue 23 item 6): on scenes/urban-drive.yaml with 2 Monte Carlo runs
 * per variant,
 *  - every modelling choice of the scene has its rows (one per requirement), each either ok with
 *    finite figures or skipped with a reason;
 *  - the pareto column agrees with the CPU times and values of the rows (recomputed here), and the
 *    recommended variant is within the tolerance of the full model and the cheapest such variant;
 *  - recommended.yaml passes navsim check, and navsim run of it with the same seed and run count
 *    gives the values tradeoff.csv states, within the tolerance of navsim run of the scene itself;
 *  - with the viewer: one chart per requirement, PNG of the expected size;
 *  - bad options exit 2 before any work.
 *
 * NAVSIM_EXE, NAV_SOURCE_DIR and NAV_TEST_WORK_DIR come from the build.
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

#include "nav_test.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define SCENE NAV_SOURCE_DIR "/scenes/urban-drive.yaml"
#define RUNS 2
#define TOL 0.1

enum {
  C_VARIANT, C_GROUP, C_CHANGE, C_STATUS, C_NOTE, C_CPU, C_WALL, C_RUNS, C_REQ, C_STAT, C_UNIT, C_VALUE, C_LO, C_HI,
  C_FULL, C_REL, C_TOL, C_WITHIN, C_PARETO, C_REC, C_COUNT
};
static const char *const k_header =
    "variant,group,change,status,note,cpu_s_per_run,wall_s,runs,requirement,statistic,unit,value,ci_low,ci_high,"
    "full_value,rel_diff,tolerance,within_tolerance,pareto,recommended";

#define MAX_ROWS 256
typedef struct row {
  char f[C_COUNT][200];
} row;
static row g_rows[MAX_ROWS];
static int g_n;

/* One CSV line into fields ("..." quoting, "" inside quotes). */
static int split(const char *line, row *r) {
  int k = 0;
  size_t n = 0;
  bool q = false;
  memset(r, 0, sizeof *r);
  for (const char *p = line; *p && *p != '\n'; ++p) {
    if (*p == '"') {
      if (q && p[1] == '"') {
        if (n + 1 < sizeof r->f[0]) r->f[k][n++] = '"';
        ++p;
      } else {
        q = !q;
      }
    } else if (*p == ',' && !q) {
      if (++k >= C_COUNT) return -1;
      n = 0;
    } else if (n + 1 < sizeof r->f[0]) {
      r->f[k][n++] = *p;
    }
  }
  return k + 1;
}

static double num(const char *s) {
  char *end = NULL;
  const double v = strtod(s, &end);
  return (end && end != s && *end == '\0') ? v : NAN;
}

static int setup(void **state) {
  (void)state;
  if (nav_test_fresh_dir(WORK) != 0) return -1;
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL,
                                       "tradeoff '" SCENE "' --runs 2 --tolerance 0.1 --out t --quiet");
  if (r->code != 0) {
    fprintf(stderr, "setup: navsim tradeoff exited %d:\n%s\n%s\n", r->code, r->out, r->err);
    return -1;
  }
  char *text = nav_test_slurp_alloc(WORK "/t/tradeoff.csv");
  if (!text) return -1;
  char *save = NULL;
  char *line = strtok_r(text, "\n", &save);
  if (!line || strcmp(line, k_header) != 0) {
    fprintf(stderr, "setup: tradeoff.csv header: %s\n", line ? line : "(none)");
    free(text);
    return -1;
  }
  g_n = 0;
  for (line = strtok_r(NULL, "\n", &save); line && g_n < MAX_ROWS; line = strtok_r(NULL, "\n", &save)) {
    if (split(line, &g_rows[g_n]) != C_COUNT) {
      fprintf(stderr, "setup: tradeoff.csv row %d has the wrong number of fields: %s\n", g_n + 2, line);
      free(text);
      return -1;
    }
    ++g_n;
  }
  free(text);
  return 0;
}

static const row *find(const char *variant, const char *req) {
  for (int i = 0; i < g_n; ++i)
    if (!strcmp(g_rows[i].f[C_VARIANT], variant) && !strcmp(g_rows[i].f[C_REQ], req)) return &g_rows[i];
  return NULL;
}

static const char *const k_reqs[2] = {"h-outage-end", "h-cep95"};

/* Every modelling choice urban-drive offers (WGS-84, NED, high_order, ins_gnss with 18 states,
 * a catalog MEMS IMU with turn-on biases and scale factors, a GNSS receiver with its errors). */
static void test_every_variant_row(void **state) {
  (void)state;
  static const char *const expected[] = {
      "full", "imu_rate_x0.5", "imu_rate_x2", "algorithm_first_order", "earth_flat", "gravity_j2", "frame_ecef",
      "cov_decimation_2", "cov_decimation_5", "cov_decimation_10", "states_plus_scale_factors",
      "gyro_bias_turn_on_off", "gyro_noise_off", "gyro_scale_factor_off", "accel_bias_turn_on_off",
      "gyro_bias_gm_off", "accel_noise_off", "accel_scale_factor_off", "accel_bias_gm_off", "gnss_pos_gm_off",
      "gnss_vel_white_off", "combined"};
  for (size_t e = 0; e < sizeof expected / sizeof *expected; ++e)
    for (int q = 0; q < 2; ++q)
      if (!find(expected[e], k_reqs[q])) fail_msg("tradeoff.csv has no row %s x %s", expected[e], k_reqs[q]);
  /* The loosely coupled filter needs the WGS-84 Earth: the flat-Earth variant is skipped, saying so. */
  assert_string_equal(find("earth_flat", k_reqs[0])->f[C_STATUS], "skipped");
  nav_test_assert_matches(find("earth_flat", k_reqs[0])->f[C_NOTE], "ins_gnss needs the wgs84 Earth model");
  int ok = 0;
  for (int i = 0; i < g_n; ++i) {
    const row *r = &g_rows[i];
    if (!strcmp(r->f[C_STATUS], "skipped")) {
      if (!r->f[C_NOTE][0]) fail_msg("row %d (%s) is skipped without a reason", i + 2, r->f[C_VARIANT]);
      if (r->f[C_VALUE][0] || r->f[C_CPU][0]) fail_msg("skipped row %d (%s) has figures", i + 2, r->f[C_VARIANT]);
      continue;
    }
    if (strcmp(r->f[C_STATUS], "ok") != 0) fail_msg("row %d: status \"%s\"", i + 2, r->f[C_STATUS]);
    ++ok;
    const double v = num(r->f[C_VALUE]), lo = num(r->f[C_LO]), hi = num(r->f[C_HI]), cpu = num(r->f[C_CPU]);
    if (!(v > 0) || !(lo > 0) || !(hi >= lo) || !(cpu > 0))
      fail_msg("row %d (%s x %s): value %s, interval [%s, %s], cpu %s", i + 2, r->f[C_VARIANT], r->f[C_REQ],
               r->f[C_VALUE], r->f[C_LO], r->f[C_HI], r->f[C_CPU]);
    assert_int_equal((int)num(r->f[C_RUNS]), RUNS);
    assert_near(num(r->f[C_TOL]), TOL, 1e-12);
  }
  if (ok < 2 * 12) fail_msg("only %d evaluated rows", ok);
  /* Each variant has exactly one row per requirement. */
  for (int i = 0; i < g_n; ++i) {
    int same = 0;
    for (int j = 0; j < g_n; ++j)
      same += !strcmp(g_rows[i].f[C_VARIANT], g_rows[j].f[C_VARIANT]);
    assert_int_equal(same, 2);
  }
}

/* pareto, within_tolerance and recommended recomputed from the figures of the rows. */
static void test_pareto_and_recommendation(void **state) {
  (void)state;
  int n_front = 0;
  for (int i = 0; i < g_n; ++i) {
    const row *a = &g_rows[i];
    if (strcmp(a->f[C_STATUS], "ok") != 0) {
      assert_string_equal(a->f[C_PARETO], "");
      continue;
    }
    const double ca = num(a->f[C_CPU]), va = num(a->f[C_VALUE]);
    bool dominated = false;
    for (int j = 0; j < g_n; ++j) {
      const row *b = &g_rows[j];
      if (j == i || strcmp(b->f[C_STATUS], "ok") != 0 || strcmp(b->f[C_REQ], a->f[C_REQ]) != 0) continue;
      const double cb = num(b->f[C_CPU]), vb = num(b->f[C_VALUE]);
      if (cb <= ca && vb <= va && (cb < ca || vb < va)) dominated = true;
    }
    if (strcmp(a->f[C_PARETO], dominated ? "false" : "true") != 0)
      fail_msg("%s x %s: pareto %s, but it is %sdominated (cpu %g, value %g)", a->f[C_VARIANT], a->f[C_REQ],
               a->f[C_PARETO], dominated ? "" : "not ", ca, va);
    n_front += !dominated;
    const double full = num(find("full", a->f[C_REQ])->f[C_VALUE]);
    assert_near(num(a->f[C_FULL]), full, 0.0);
    const bool within = fabs(va - full) <= TOL * full;
    assert_string_equal(a->f[C_WITHIN], within ? "true" : "false");
  }
  assert_true(n_front >= 2); /* at least the cheapest and the most accurate point of each requirement */
  /* Exactly one recommended variant, within tolerance for both requirements, and no variant within
     tolerance for both is cheaper. */
  const char *rec = NULL;
  for (int i = 0; i < g_n; ++i)
    if (!strcmp(g_rows[i].f[C_REC], "true")) {
      if (rec && strcmp(rec, g_rows[i].f[C_VARIANT]) != 0) fail_msg("two recommended: %s, %s", rec, g_rows[i].f[C_VARIANT]);
      rec = g_rows[i].f[C_VARIANT];
    }
  assert_non_null(rec);
  const double rec_cpu = num(find(rec, k_reqs[0])->f[C_CPU]);
  for (int q = 0; q < 2; ++q) assert_string_equal(find(rec, k_reqs[q])->f[C_WITHIN], "true");
  for (int i = 0; i < g_n; ++i) {
    const row *a = &g_rows[i];
    if (strcmp(a->f[C_STATUS], "ok") != 0 || strcmp(a->f[C_REQ], k_reqs[0]) != 0) continue;
    const row *b = find(a->f[C_VARIANT], k_reqs[1]);
    if (!strcmp(a->f[C_WITHIN], "true") && !strcmp(b->f[C_WITHIN], "true") && num(a->f[C_CPU]) < rec_cpu)
      fail_msg("%s is within tolerance and cheaper (%s s) than the recommended %s (%g s)", a->f[C_VARIANT],
               a->f[C_CPU], rec, rec_cpu);
  }
  /* The combination (when run) applies only variants within tolerance that are cheaper than the full
     model, at most one per group. */
  const row *comb = find("combined", k_reqs[0]);
  assert_non_null(comb);
  if (!strcmp(comb->f[C_STATUS], "ok")) {
    char list[200];
    snprintf(list, sizeof list, "%s", comb->f[C_CHANGE]);
    char *save = NULL;
    int parts = 0;
    char groups[8][200];
    for (char *v = strtok_r(list, " +", &save); v; v = strtok_r(NULL, " +", &save)) {
      const row *a = find(v, k_reqs[0]), *b = find(v, k_reqs[1]);
      if (!a || !b) fail_msg("combined names an unknown variant \"%s\"", v);
      if (strcmp(a->f[C_WITHIN], "true") || strcmp(b->f[C_WITHIN], "true") ||
          !(num(a->f[C_CPU]) < num(find("full", k_reqs[0])->f[C_CPU])))
        fail_msg("combined includes %s, which is not within tolerance and cheaper than the full model", v);
      for (int g = 0; g < parts && g < 8; ++g)
        if (!strcmp(groups[g], a->f[C_GROUP])) fail_msg("combined has two variants of group %s", groups[g]);
      if (parts < 8) snprintf(groups[parts], sizeof groups[parts], "%s", a->f[C_GROUP]);
      ++parts;
    }
    assert_true(parts >= 2);
  }
  print_message("recommended: %s (%g s CPU per run, full model %s s)\n", rec, rec_cpu,
                find("full", k_reqs[0])->f[C_CPU]);
}

/* The value of requirement @p id in summary.json. */
static double summary_value(const char *path, const char *id) {
  char *s = nav_test_slurp_alloc(path);
  assert_non_null(s);
  char key[128];
  snprintf(key, sizeof key, "{\"id\": \"%s\"", id);
  const char *p = strstr(s, key);
  if (!p) fail_msg("%s: no requirement %s", path, id);
  p = strstr(p, "\"value\": ");
  assert_non_null(p);
  const double v = strtod(p + 9, NULL);
  free(s);
  return v;
}

static void test_recommended_scene(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "check t/recommended.yaml");
  if (r->code != 0) fail_msg("navsim check recommended.yaml exited %d:\n%s", r->code, r->err);
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "run t/recommended.yaml --runs 2 --quiet --out rec");
  if (r->code != 0) fail_msg("navsim run recommended.yaml exited %d:\n%s", r->code, r->err);
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "run '" SCENE "' --runs 2 --quiet --out full");
  if (r->code != 0) fail_msg("navsim run of the scene exited %d:\n%s", r->code, r->err);
  const char *rec = NULL;
  for (int i = 0; i < g_n && !rec; ++i)
    if (!strcmp(g_rows[i].f[C_REC], "true")) rec = g_rows[i].f[C_VARIANT];
  assert_non_null(rec);
  for (int q = 0; q < 2; ++q) {
    const double vr = summary_value(WORK "/rec/summary.json", k_reqs[q]);
    const double vf = summary_value(WORK "/full/summary.json", k_reqs[q]);
    /* navsim run reproduces the figures of tradeoff.csv (same scene text, seed and runs; %.9g). */
    assert_rel_near(vr, num(find(rec, k_reqs[q])->f[C_VALUE]), 1e-8);
    assert_rel_near(vf, num(find("full", k_reqs[q])->f[C_VALUE]), 1e-8);
    if (!(fabs(vr - vf) <= TOL * vf))
      fail_msg("%s: recommended %s gives %g, the full model %g: outside %g %%", k_reqs[q], rec, vr, vf, 100 * TOL);
    print_message("%s: recommended %s %.4g m, full model %.4g m (%+.2f %%)\n", k_reqs[q], rec, vr, vf,
                  100 * (vr - vf) / vf);
  }
}

#ifdef NAV_HAVE_VIEWER
/* PNG width and height from the IHDR chunk. */
static void png_size(const char *path, int *w, int *h) {
  size_t len = 0;
  char *b = nav_test_slurp_len(path, &len);
  if (!b) fail_msg("no %s", path);
  assert_true(len > 24 && !memcmp(b + 1, "PNG", 3) && !memcmp(b + 12, "IHDR", 4));
  const unsigned char *u = (const unsigned char *)b;
  *w = (int)((u[16] << 24) | (u[17] << 16) | (u[18] << 8) | u[19]);
  *h = (int)((u[20] << 24) | (u[21] << 16) | (u[22] << 8) | u[23]);
  free(b);
}
#endif

static void test_charts(void **state) {
  (void)state;
#ifdef NAV_HAVE_VIEWER
  for (int q = 0; q < 2; ++q) {
    char p[512];
    snprintf(p, sizeof p, WORK "/t/tradeoff_%s.png", k_reqs[q]);
    int w = 0, h = 0;
    png_size(p, &w, &h);
    assert_int_equal(w, 1000);
    assert_int_equal(h, 700);
  }
  /* navsim report of the directory: the tradeoff figure and the table, the recommended row marked. */
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "report t --out rep");
  if (r->code != 0) fail_msg("navsim report exited %d:\n%s", r->code, r->err);
  char *page = nav_test_slurp_alloc(WORK "/rep/report.html");
  assert_non_null(page);
  const char *rec = NULL;
  for (int i = 0; i < g_n && !rec; ++i)
    if (!strcmp(g_rows[i].f[C_REC], "true")) rec = g_rows[i].f[C_VARIANT];
  char want[256];
  snprintf(want, sizeof want, "<b>%s (recommended)</b>", rec);
  if (!strstr(page, "<h2>Speed against error (navsim tradeoff)</h2>") || !strstr(page, "id=\"fig-tradeoff\"") ||
      !strstr(page, want))
    fail_msg("report.html lacks the tradeoff section, its figure or the recommended row (%s)", want);
  free(page);
#else
  skip();
#endif
}

static void test_bad_options(void **state) {
  (void)state;
  nav_cli_result *r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "tradeoff '" SCENE "' --requirement nope --out b");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "--requirement nope: the scene has no requirement with that id \\(it has: "
                                  "h-outage-end h-cep95\\)");
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "tradeoff '" SCENE "' --tolerance 0 --out b");
  assert_int_equal(r->code, 2);
  r = nav_test_run_cli(NAVSIM_EXE, WORK, NULL, "tradeoff '" SCENE "'");
  assert_int_equal(r->code, 2);
  nav_test_assert_matches(r->err, "missing --out DIR");
  assert_false(nav_test_is_file(WORK "/b/tradeoff.csv"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_every_variant_row), cmocka_unit_test(test_pareto_and_recommendation),
      cmocka_unit_test(test_recommended_scene), cmocka_unit_test(test_charts), cmocka_unit_test(test_bad_options)};
  return cmocka_run_group_tests(tests, setup, NULL);
}
