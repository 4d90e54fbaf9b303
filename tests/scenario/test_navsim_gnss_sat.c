/*
 * navsim run with a gnss.constellation section (issue 22): scenes/urban-canyon.yaml writes
 * gnss_dop.csv and gnss_sats.csv; 2-3 satellites are visible for the whole 60 s canyon and at
 * least 4 (a valid DOP) outside it; every DOP row equals the DOP recomputed from the visible rows of
 * gnss_sats.csv; a satellite is visible exactly when its elevation is at or above the mask; the
 * receiver gives no fix while fewer than 4 satellites are visible (gnss_outages.csv holds exactly
 * the canyon, gnss.csv has no fix inside it) unless min_satellites_for_fix is 0; a bad
 * gnss.constellation value is FILE:LINE:COL with exit 2.
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

#include "nav_test.h"
#include "navcore/nav_gnss_sat.h"
#include "navsim_cli.h"

#define WORK NAV_TEST_WORK_DIR
#define DEG (3.14159265358979323846 / 180.0)
#define MAX_EPOCHS 4000

typedef struct epoch_sats {
  int n;
  double az[NAV_GNSS_MAX_SATS], el[NAV_GNSS_MAX_SATS];
  nav_gnss_system sys[NAV_GNSS_MAX_SATS];
} epoch_sats;

static void canyon_visibility_and_dop(void **state) {
  (void)state;
  assert_int_equal(nav_test_fresh_dir(WORK), 0);
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run '%s/scenes/urban-canyon.yaml' --runs 1 --out uc --quiet",
                                        NAV_SOURCE_DIR);
  if (r->code != 0) fail_msg("navsim run failed (%d):\n%s", r->code, r->err);
  /* gnss_sats.csv: visible rows per epoch (epochs are the output epochs, 10 Hz) */
  char *sats = nav_test_slurp_alloc(WORK "/uc/gnss_sats.csv");
  assert_non_null(sats);
  assert_true(strncmp(sats, "t_s,system,prn,az_deg,el_deg,mask_el_deg,visible\n", 49) == 0);
  static epoch_sats ep[MAX_EPOCHS];
  memset(ep, 0, sizeof ep);
  int rows = 0;
  for (char *line = strchr(sats, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
    double t, az, el, mask;
    char sys;
    int prn, vis;
    assert_int_equal(sscanf(line + 1, "%lf,%c,%d,%lf,%lf,%lf,%d", &t, &sys, &prn, &az, &el, &mask, &vis), 7);
    /* visible exactly when at or above the mask (4-decimal rounding of both columns) */
    if (fabs(el - mask) > 2e-4) assert_int_equal(vis, el >= mask);
    const long k = lround(t * 10.0);
    assert_true(k >= 0 && k < MAX_EPOCHS);
    if (vis) {
      epoch_sats *e = &ep[k];
      e->az[e->n] = az * DEG;
      e->el[e->n] = el * DEG;
      e->sys[e->n] = sys == 'G' ? NAV_GNSS_SYS_GPS : NAV_GNSS_SYS_GLONASS;
      e->n++;
    }
    rows++;
  }
  free(sats);
  assert_true(rows > 1000);
  /* gnss_dop.csv */
  char *dop = nav_test_slurp_alloc(WORK "/uc/gnss_dop.csv");
  assert_non_null(dop);
  assert_true(strncmp(dop, "t_s,n_visible,gdop,pdop,hdop,vdop,tdop,in_canyon\n", 49) == 0);
  int n_canyon = 0, n_open = 0, min_c = 99, max_c = 0, min_o = 99;
  double worst = 0.0, pdop_max_open = 0.0;
  for (char *line = strchr(dop, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
    double t, g = NAN, p = NAN, h = NAN, v = NAN, td = NAN;
    int n, canyon;
    char *s = line + 1;
    t = strtod(s, &s);
    n = (int)strtol(s + 1, &s, 10);
    double *dst[5] = {&g, &p, &h, &v, &td};
    for (int i = 0; i < 5; ++i) {
      ++s; /* comma */
      if (*s != ',') *dst[i] = strtod(s, &s);
    }
    canyon = (int)strtol(s + 1, &s, 10);
    const long k = lround(t * 10.0);
    assert_int_equal(ep[k].n, n);
    const bool in = t >= 40.0 && t < 100.0;
    assert_int_equal(canyon, in);
    if (in) {
      ++n_canyon;
      min_c = n < min_c ? n : min_c;
      max_c = n > max_c ? n : max_c;
      assert_true(isnan(p)); /* fewer than 4: no DOP */
    } else {
      ++n_open;
      min_o = n < min_o ? n : min_o;
      const nav_gnss_dop d = nav_gnss_dop_compute(ep[k].n, ep[k].az, ep[k].el, ep[k].sys);
      assert_true(d.valid);
      /* the file carries 6 decimals, the angles 4 (1.7e-6 rad): the recomputation agrees to 1e-4 relative */
      const double diffs[5] = {g - d.gdop, p - d.pdop, h - d.hdop, v - d.vdop, td - d.tdop};
      for (int i = 0; i < 5; ++i) {
        const double rel = fabs(diffs[i]) / d.gdop;
        worst = rel > worst ? rel : worst;
      }
      pdop_max_open = p > pdop_max_open ? p : pdop_max_open;
    }
  }
  free(dop);
  print_message("urban-canyon: %d canyon epochs with %d..%d satellites, %d open epochs with >= %d, PDOP <= %.2f; "
                "DOP file vs recomputed: %.2e relative\n",
                n_canyon, min_c, max_c, n_open, min_o, pdop_max_open, worst);
  assert_int_equal(n_canyon, 600); /* 60 s at 10 Hz */
  assert_true(min_c >= 2 && max_c <= 3);
  assert_true(min_o >= 4);
  assert_true(worst < 1e-4);
}

/* Fixes of run 0 (gnss.csv, first column t_s) inside [t0, t1) and in total. */
static void count_fixes(const char *path, double t0, double t1, int *inside, int *total) {
  char *g = nav_test_slurp_alloc(path);
  assert_non_null(g);
  *inside = *total = 0;
  for (char *line = strchr(g, '\n'); line && line[1]; line = strchr(line + 1, '\n')) {
    const double t = strtod(line + 1, NULL);
    *inside += t >= t0 && t < t1;
    ++*total;
  }
  free(g);
}

/* urban-canyon.yaml with its fixes from the receiver model (the scene takes them from the PVT,
 * whose fixes gnss.csv does not list), and @p extra inserted before its elevation mask. */
static void write_model_scene(const char *name, const char *extra) {
  static const char pvt[] = "    fixes: pvt\n", model[] = "    fixes: model\n";
  static const char mask[] = "    elevation_mask_deg: 10\n";
  char *scene = nav_test_slurp_alloc(NAV_SOURCE_DIR "/scenes/urban-canyon.yaml");
  assert_non_null(scene);
  const size_t cap = strlen(scene) + strlen(extra) + 32;
  char *a = malloc(cap), *b = malloc(cap);
  assert_non_null(a);
  assert_non_null(b);
  /* a: the scene with "fixes: model" */
  const char *f = strstr(scene, pvt);
  assert_non_null(f);
  snprintf(a, cap, "%.*s%s%s", (int)(f - scene), scene, model, f + strlen(pvt));
  /* b: a with @p extra before the elevation mask */
  const char *m = strstr(a, mask);
  assert_non_null(m);
  snprintf(b, cap, "%.*s%s%s", (int)(m - a), a, extra, m);
  nav_test_write_file(WORK, name, b);
  free(a);
  free(b);
  free(scene);
}

static void receiver_follows_visibility(void **state) {
  (void)state;
  write_model_scene("model.yaml", "");
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run model.yaml --runs 1 --out ucm --quiet");
  if (r->code != 0) fail_msg("navsim run failed (%d):\n%s", r->code, r->err);
  char *o = nav_test_slurp_alloc(WORK "/ucm/gnss_outages.csv");
  assert_non_null(o);
  assert_string_equal(o, "t0_s,t1_s\n40,100\n");
  free(o);
  int inside = 0, total = 0;
  count_fixes(WORK "/ucm/gnss.csv", 40.0, 100.0, &inside, &total);
  assert_int_equal(inside, 0);
  const int with_canyon = total;
  /* min_satellites_for_fix: 0: the receiver ignores the constellation */
  write_model_scene("nomin.yaml", "    min_satellites_for_fix: 0\n");
  r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run nomin.yaml --runs 1 --out nomin --quiet");
  if (r->code != 0) fail_msg("navsim run failed (%d):\n%s", r->code, r->err);
  o = nav_test_slurp_alloc(WORK "/nomin/gnss_outages.csv");
  assert_non_null(o);
  assert_string_equal(o, "t0_s,t1_s\n");
  free(o);
  count_fixes(WORK "/nomin/gnss.csv", 40.0, 100.0, &inside, &total);
  assert_int_equal(inside, 60); /* 1 Hz */
  assert_int_equal(total, with_canyon + 60);
}

/* A bad value in gnss.constellation: FILE:LINE:COL, exit 2, nothing run. */
static void bad_section_is_located(void **state) {
  (void)state;
  char *scene = nav_test_slurp_alloc(NAV_SOURCE_DIR "/scenes/urban-canyon.yaml");
  assert_non_null(scene);
  char *p = strstr(scene, "elevation_mask_deg: 10");
  assert_non_null(p);
  memcpy(p, "elevation_mask_deg: -1", 22);
  /* line of the key */
  int line = 1;
  for (const char *q = scene; q < p; ++q) line += *q == '\n';
  int col = 1;
  for (const char *q = p; q > scene && q[-1] != '\n'; --q) ++col;
  nav_test_write_file(WORK, "bad.yaml", scene);
  free(scene);
  nav_cli_result *r = nav_test_run_clif(NAVSIM_EXE, WORK, NULL, "run bad.yaml --out bad --quiet");
  assert_int_equal(r->code, 2);
  char expect[128];
  snprintf(expect, sizeof expect, "bad.yaml:%d:%d: error: gnss.constellation.elevation_mask_deg", line,
           col + (int)strlen("elevation_mask_deg: "));
  if (!strstr(r->err, expect)) fail_msg("expected \"%s\" in:\n%s", expect, r->err);
  assert_false(nav_test_is_file(WORK "/bad/gnss_dop.csv"));
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(canyon_visibility_and_dop),
      cmocka_unit_test(receiver_follows_visibility),
      cmocka_unit_test(bad_section_is_located),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
