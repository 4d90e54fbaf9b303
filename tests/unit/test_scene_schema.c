/*
 * The scene schema table (nav_schema.h) against the scene reader (issue 18, item 4).
 *
 * The cases are generated from the table itself: for every key with a bound, a scene holding the
 * bound is read (accepted; for an exclusive minimum the nearest value inside), and a scene holding
 * the nearest value past it is read (rejected, with the diagnostic at that key). So the bounds that
 * `navsim schema` publishes and navstudio's forms use are the bounds the reader enforces, and a bound
 * changed in the table changes both. Keys inside lists get the smallest context their list needs.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "navcore/nav_io.h"
#include "navcore/nav_schema.h"

typedef struct diag_log {
  int n;
  char first_path[256];
  char first_text[1024];
} diag_log;

static void collect(void *user, const nav_diag *d) {
  diag_log *log = user;
  if (log->n++ == 0) {
    snprintf(log->first_path, sizeof log->first_path, "%s", d->path);
    nav_diag_format(d, log->first_text, sizeof log->first_text);
  }
}

/* What an item of list @p list needs besides the key @p key under test (flow-mapping members,
   each followed by ", "), or NULL when the list is not known here. */
static const char *item_context(const char *list, const char *kind, const char *key, char *buf, size_t size) {
  if (kind[0] != '\0') {
    snprintf(buf, size, "kind: %s, ", kind);
  } else if (strcmp(list, "requirements") == 0) {
    snprintf(buf, size, "id: r1, metric: horizontal_position, statistic: %s, unit: m, %s",
             strcmp(key, "time_s") == 0 ? "at_time" : "rms", strcmp(key, "limit") == 0 ? "" : "limit: 1, ");
  } else if (strcmp(list, "canyons") == 0) {
    const char *req[] = {"t0_s", "t1_s", "height_m", "left_m", "right_m"};
    const char *val[] = {"0", "1", "10", "10", "10"};
    size_t l = 0;
    buf[0] = '\0';
    for (size_t k = 0; k < 5; ++k)
      if (strcmp(req[k], key) != 0) l += (size_t)snprintf(buf + l, size - l, "%s: %s, ", req[k], val[k]);
  } else if (strcmp(list, "points") == 0) {
    snprintf(buf, size, "%s", strncmp(key, "lat_", 4) == 0 ? "lon_deg: 0, h_m: 0, " : "ned_m: [0, 0, 0], ");
  } else if (strcmp(list, "sensors") == 0) {
    snprintf(buf, size, "%s", strcmp(key, "axis") == 0 ? "position_m: [1, 0, 0], " : "axis: [1, 0, 0], ");
  } else {
    return NULL;
  }
  return buf;
}

/* Keys the reader requires next to the key under test (rules across keys of one mapping): a
   Gauss-Markov sigma needs its correlation time, a bias instability the averaging time of its
   Allan minimum and the reverse, a recorded trajectory its file. */
static const char *sibling_context(const char *path, const char *key) {
  if (strncmp(key, "bias_gm_sigma_", 14) == 0) return "bias_gm_tau_s: 100, ";
  if (strcmp(key, "bias_instability_tau_min_s") == 0)
    return strstr(path, ".gyro.") != NULL ? "bias_instability_deg_per_h: 1, " : "bias_instability_ug: 1, ";
  if (strncmp(key, "bias_instability_", 17) == 0) return "bias_instability_tau_min_s: 100, ";
  if (strncmp(path, "trajectory.recorded.", 20) == 0) return "file: not-read.txt, ";
  return "";
}

/* Keys elsewhere in the scene that the key under test needs: the output rate may not exceed the
   IMU rate. */
static const char *root_context(const char *path) {
  if (strcmp(path, "output.rate_hz") == 0) return "imu: {rate_hz: 100000}\n";
  return "";
}

/* The YAML of a scene that sets the key at @p path (dotted; list items as "[]" or "[kind]") to the
   value text @p v, in flow style built from the innermost key out, with what an enclosing list
   item needs. false when no context is known or it does not fit. */
static bool scene_with(char *buf, size_t size, const char *path, const char *v) {
  char comp[8][64];
  int n = 0;
  for (const char *p = path; *p && n < 8;) {
    const size_t l = strcspn(p, ".");
    snprintf(comp[n++], sizeof comp[0], "%.*s", (int)l, p);
    p += l;
    if (*p == '.') ++p;
  }
  char inner[1500], next[1500], ctx[256];
  snprintf(inner, sizeof inner, "%s", v);
  for (int i = n - 1; i >= 0; --i) {
    char *br = strchr(comp[i], '[');
    if (br == NULL) {
      const char *sib = i == n - 1 ? sibling_context(path, comp[i]) : "";
      if (snprintf(next, sizeof next, "{%s%s: %s}", sib, comp[i], inner) >= (int)sizeof next) return false;
    } else {
      char kind[64];
      snprintf(kind, sizeof kind, "%s", br + 1);
      kind[strcspn(kind, "]")] = '\0';
      *br = '\0';
      if (i == n - 1 || inner[0] != '{') return false;
      if (item_context(comp[i], kind, comp[i + 1], ctx, sizeof ctx) == NULL) return false;
      /* trajectory.test_motion is one mapping chosen by its kind; the others are lists */
      const bool list = strcmp(comp[i], "test_motion") != 0;
      if (snprintf(next, sizeof next, list ? "{%s: [{%s%s]}" : "{%s: {%s%s}", comp[i], ctx, inner + 1) >=
          (int)sizeof next)
        return false;
    }
    memcpy(inner, next, sizeof inner);
  }
  /* the outer braces go: a block mapping at the top, after format_version */
  const size_t l = strlen(inner);
  return (size_t)snprintf(buf, size, "format_version: 1\n%s%.*s\n", root_context(path), (int)(l - 2), inner + 1) <
         size;
}

static void format_value(char *buf, size_t size, const nav_schema_key *k, double x) {
  char num[64];
  if (k->type == NAV_SCHEMA_INTEGER)
    snprintf(num, sizeof num, "%.0f", x);
  else
    snprintf(num, sizeof num, "%.17g", x);
  if (k->type == NAV_SCHEMA_VEC3)
    snprintf(buf, size, "[%s, %s, %s]", num, num, num);
  else
    snprintf(buf, size, "%s", num);
}

static int g_cases, g_failures, g_accepted_whole;

/* Whether diagnostic path @p got is about the key at @p path: the same mapping (list indices in
   @p got stand for "[]" / "[kind]" in @p path), where the validators name a quantity by its
   preferred or SI spelling. */
static bool same_mapping(const char *got, const char *path) {
  while (*path && *got) {
    if (*path == '[' || *got == '[') {
      if (*path == '[') {
        while (*path && *path != ']') ++path;
        if (*path) ++path;
      }
      if (*got == '[') {
        while (*got && *got != ']') ++got;
        if (*got) ++got;
      }
      continue;
    }
    if (*path != *got) break;
    ++path;
    ++got;
  }
  /* equal up to the last '.' of path: the same mapping */
  return strchr(path, '.') == NULL && (strchr(got, '.') == NULL || *got == '\0');
}

/* Read the scene with @p path = @p x (all axes; or axis @p axis only, the others 0). Accepted:
   no diagnostic about this key (a rule across keys may still reject the minimal scene: counted
   apart). Rejected: the first diagnostic is about this key. */
static void expect(const nav_schema_key *k, double x, int axis, bool accept, const char *what) {
  char v[256], text[2048];
  format_value(v, sizeof v, k, x);
  if (axis >= 0) {
    char num[64];
    snprintf(num, sizeof num, "%.17g", x);
    snprintf(v, sizeof v, "[%s, %s, %s]", axis == 0 ? num : "0", axis == 1 ? num : "0", axis == 2 ? num : "0");
  }
  if (!scene_with(text, sizeof text, k->path, v)) return;
  static nav_scene scene;
  diag_log log = {0};
  const nav_status st = nav_scene_read_string(text, strlen(text), "bound.yaml", &scene, collect, &log);
  ++g_cases;
  const bool about_key = st != NAV_OK && same_mapping(log.first_path, k->path);
  if (accept && about_key) {
    ++g_failures;
    print_message("%s = %s (%s) rejected: %s\n--- scene:\n%s", k->path, v, what, log.first_text, text);
  } else if (accept) {
    if (st == NAV_OK) ++g_accepted_whole;
  } else if (st == NAV_OK) {
    ++g_failures;
    print_message("%s = %s (%s) accepted; the table says it is out of bounds\n--- scene:\n%s", k->path, v, what,
                  text);
  } else if (!about_key) {
    ++g_failures;
    print_message("%s = %s (%s) rejected for another reason: %s\n", k->path, v, what, log.first_text);
  }
}

/* @p x moved @p n ulps towards @p to. */
static double ulps(double x, double to, int n) {
  for (int i = 0; i < n; ++i) x = nextafter(x, to);
  return x;
}

static void test_bounds_match_reader(void **state) {
  (void)state;
  nav_schema_key *keys = NULL;
  size_t n = 0;
  assert_int_equal(nav_schema_keys(&keys, &n), NAV_OK);
  int bounded = 0, skipped = 0;
  for (size_t i = 0; i < n; ++i) {
    const nav_schema_key *k = &keys[i];
    if (!(k->bounds & (NAV_SCHEMA_MIN | NAV_SCHEMA_MAX))) continue;
    if (k->type != NAV_SCHEMA_NUMBER && k->type != NAV_SCHEMA_VEC3 && k->type != NAV_SCHEMA_VEC3_SCALAR &&
        k->type != NAV_SCHEMA_MAT3_OFFDIAG && k->type != NAV_SCHEMA_MAT3_DIAG && k->type != NAV_SCHEMA_INTEGER &&
        k->type != NAV_SCHEMA_OTHER /* trajectory.duration_s: a number or auto */) {
      ++skipped;
      continue;
    }
    char probe[2048];
    if (!scene_with(probe, sizeof probe, k->path, "0")) {
      print_message("no context for %s\n", k->path);
      ++skipped;
      continue;
    }
    ++bounded;
    const bool integer = k->type == NAV_SCHEMA_INTEGER;
    const bool per_axis = k->max_axis[0] != k->max || k->max_axis[1] != k->max || k->max_axis[2] != k->max;
    /* A bound checked on the SI value: one ulp past it in the file's unit may convert to the bound
       itself; four cannot (the unit factor is rounded by at most half an ulp). */
    const int past = (k->bounds & NAV_SCHEMA_CHECKED_IN_SI) || per_axis ? 4 : 1;
    if (k->bounds & NAV_SCHEMA_MAX) {
      expect(k, k->max, -1, true, "the maximum");
      expect(k, integer ? k->max + 1 : ulps(k->max, INFINITY, past), -1, false, "just above the maximum");
      for (int a = 0; per_axis && a < 3; ++a) {
        expect(k, k->max_axis[a], a, true, "the maximum of this axis");
        expect(k, ulps(k->max_axis[a], INFINITY, past), a, false, "just above the maximum of this axis");
      }
    }
    if (k->bounds & NAV_SCHEMA_MIN_EXCLUSIVE) {
      expect(k, k->min, -1, false, "the exclusive minimum");
      /* the nearest value inside; above 0 in a unit smaller than SI, one whose SI value does not
         underflow to 0 (the validators check the SI value: range_dps 5e-324 is 0 rad/s) */
      double inside = integer                             ? k->min + 1
                      : k->min == 0.0 && k->scale < 1.0 ? DBL_MIN / k->scale
                                                         : nextafter(k->min, INFINITY);
      /* a rule across keys that is tighter than the table's bound: the trajectory lasts at least
         one IMU interval (0.01 s by default) */
      if (strcmp(k->path, "trajectory.duration_s") == 0) inside = 1.0;
      expect(k, inside, -1, true, "just above the exclusive minimum");
    } else if (k->bounds & NAV_SCHEMA_MIN) {
      expect(k, k->min, -1, true, "the minimum");
      expect(k, integer ? k->min - 1 : ulps(k->min, -INFINITY, past), -1, false, "just below the minimum");
    }
  }
  print_message("%d bounded keys, %d cases (%d of the accepted scenes accepted whole), %d failures, %d bounded "
                "keys skipped\n",
                bounded, g_cases, g_accepted_whole, g_failures, skipped);
  free(keys);
  assert_true(bounded > 80);
  assert_int_equal(skipped, 0);
  assert_int_equal(g_failures, 0);
}

/* The table's form: units on numeric keys, ALT spellings point at their preferred key, defaults
   are those of nav_scene_default() (spot checks), enums list their choices. */
static void test_table_form(void **state) {
  (void)state;
  nav_schema_key *keys = NULL;
  size_t n = 0;
  assert_int_equal(nav_schema_keys(&keys, &n), NAV_OK);
  const nav_schema_key *k = nav_schema_find(keys, n, "imu.gyro.arw_deg_per_sqrt_h");
  assert_non_null(k);
  assert_string_equal(k->unit, "deg/sqrt(h)");
  assert_true(k->bounds & NAV_SCHEMA_MAX);
  assert_true(fabs(k->scale - (3.14159265358979323846 / 180.0) / 60.0) < 1e-18);
  const nav_schema_key *alt = nav_schema_find(keys, n, "imu.gyro.arw_rad_per_sqrt_s");
  assert_non_null(alt);
  assert_int_equal(alt->alt_of, (int)(k - keys));
  k = nav_schema_find(keys, n, "navigation.scheme");
  assert_non_null(k);
  assert_int_equal(k->type, NAV_SCHEMA_ENUM);
  assert_true(k->n_choices >= 4);
  assert_true(k->has_default);
  const nav_scene def = nav_scene_default();
  k = nav_schema_find(keys, n, "simulation.runs");
  assert_non_null(k);
  assert_true(k->has_default);
  assert_true(k->default_value[0] == (double)def.simulation.runs);
  k = nav_schema_find(keys, n, "imu.rate_hz");
  assert_non_null(k);
  assert_string_equal(k->unit, "Hz");
  assert_true(k->default_value[0] == def.imu.rate_hz);
  assert_non_null(nav_schema_find(keys, n, "trajectory.segments.items[circle].radius_m"));
  assert_non_null(nav_schema_find(keys, n, "requirements[].limit"));
  for (size_t i = 0; i < n; ++i) {
    const nav_schema_type t = keys[i].type;
    const bool numeric = t == NAV_SCHEMA_NUMBER || t == NAV_SCHEMA_VEC3 || t == NAV_SCHEMA_VEC3_SCALAR ||
                         t == NAV_SCHEMA_MAT3_OFFDIAG || t == NAV_SCHEMA_MAT3_DIAG;
    if (numeric && keys[i].unit == NULL && strcmp(keys[i].key, "limit") != 0)
      fail_msg("%s: numeric key without a unit", keys[i].path);
    if (keys[i].doc == NULL || keys[i].doc[0] == '\0') fail_msg("%s: no description", keys[i].path);
  }
  free(keys);
}

static void test_json_is_generated(void **state) {
  (void)state;
  char *json = nav_schema_json();
  assert_non_null(json);
  assert_non_null(strstr(json, "\"$schema\": \"https://json-schema.org/draft/2020-12/schema\""));
  assert_non_null(strstr(json, "\"x-unit\": \"deg/h\""));
  assert_non_null(strstr(json, "\"additionalProperties\": false"));
  free(json);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_table_form),
      cmocka_unit_test(test_json_is_generated),
      cmocka_unit_test(test_bounds_match_reader),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
