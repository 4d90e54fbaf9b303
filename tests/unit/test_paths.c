/*
 * The run-time path functions of navcore_io that programs call instead of finding paths
 * themselves (nav_paths.h; the layering test forbids other copies): the running executable and
 * the offline map data folder.
 */
#define _POSIX_C_SOURCE 200809L /* setenv, unsetenv, access */
#include <limits.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "navcore/nav_paths.h"

/* The executable is this test program, by its absolute path; too small a buffer is refused and
   left untouched. */
static void test_executable(void **state) {
  (void)state;
  char buf[4096];
  assert_true(nav_paths_executable(buf, sizeof buf));
  assert_int_equal(buf[0], '/');
  const char *base = strrchr(buf, '/') + 1;
  assert_string_equal(base, "test_paths");
  assert_int_equal(access(buf, X_OK), 0);
  char small[4] = "abc";
  assert_false(nav_paths_executable(small, sizeof small));
  assert_string_equal(small, "abc");
  assert_false(nav_paths_executable(NULL, 10));
}

/* $NAVVIEW_MAP_DATA when set and non-empty, else Debian's cartopy data folder. */
static void test_map_data_dir(void **state) {
  (void)state;
  char buf[256];
  assert_int_equal(setenv("NAVVIEW_MAP_DATA", "/tmp/my-map-data", 1), 0);
  assert_true(nav_paths_map_data_dir(buf, sizeof buf));
  assert_string_equal(buf, "/tmp/my-map-data");
  assert_int_equal(setenv("NAVVIEW_MAP_DATA", "", 1), 0);
  assert_true(nav_paths_map_data_dir(buf, sizeof buf));
  assert_string_equal(buf, "/usr/share/cartopy/data");
  assert_int_equal(unsetenv("NAVVIEW_MAP_DATA"), 0);
  assert_true(nav_paths_map_data_dir(buf, sizeof buf));
  assert_string_equal(buf, "/usr/share/cartopy/data");
  char small[8] = "x";
  assert_false(nav_paths_map_data_dir(small, sizeof small));
  assert_string_equal(small, "x");
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_executable),
      cmocka_unit_test(test_map_data_dir),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
