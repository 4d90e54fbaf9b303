/*
 * test_navview_csv: the result loader of libnavview (nav_view_result.h). Valid tables, every
 * malformed-input message with its file and line, the vendored tiny result, and the time
 * look-up helpers. No display needed.
 */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
extern "C" {
#include <cmocka.h>
}

#include <cstdio>
#include <cstdlib>
#include <string>
#include <sys/stat.h>
#include <unistd.h>

#include "nav_test.h"
#include "navview/nav_view_result.h"

namespace {

void expect_error(const std::string &text, const std::string &want) {
  NavCsvTable t;
  std::string err;
  if (NavCsvParse(text, "mem.csv", &t, &err))
    fail_msg("parsed, expected error containing '%s'", want.c_str());
  if (err.find(want) == std::string::npos)
    fail_msg("error '%s' does not contain '%s'", err.c_str(), want.c_str());
}

void test_parse_valid(void **) {
  NavCsvTable t;
  std::string err;
  assert_true(NavCsvParse("t_s,a,b\n0,1,2\n0.5, -3.25e1 ,+4\n", "mem.csv", &t, &err));
  assert_int_equal(t.rows, 2);
  assert_int_equal(t.columns.size(), 3);
  assert_int_equal(t.Column("b"), 2);
  assert_int_equal(t.Column("zz"), -1);
  assert_near(t.At(1, 0), 0.5, 0.0);
  assert_near(t.At(1, 1), -32.5, 0.0);
  assert_near(t.At(1, 2), 4.0, 0.0);
  assert_int_equal(t.line_of_row[1], 3);
}

void test_parse_crlf_and_blank_lines(void **) {
  NavCsvTable t;
  std::string err;
  assert_true(NavCsvParse("t_s,a\r\n0,1\r\n\r\n2,3\r\n", "mem.csv", &t, &err));
  assert_int_equal(t.rows, 2);
  assert_int_equal(t.line_of_row[1], 4);
  assert_near(t.At(1, 1), 3.0, 0.0);
}

void test_parse_errors_name_file_and_line(void **) {
  expect_error("t_s,a,b\n0,1,2\n1,x,4\n", "mem.csv:3: error: column 'a': not a number: 'x'");
  expect_error("t_s,a,b\n0,1,2\n1,2\n", "mem.csv:3: error: expected 3 fields, found 2");
  expect_error("t_s,a,b\n0,1,2,3,4\n", "mem.csv:2: error: expected 3 fields, found 5");
  expect_error("t_s,a\n0,\n", "mem.csv:2: error: column 'a': not a number: ''");
  expect_error("t_s,a\n0,nan\n", "mem.csv:2: error: column 'a': non-finite value 'nan'");
  expect_error("t_s,a\n0,1e999\n", "mem.csv:2: error: column 'a': non-finite value");
  expect_error("t_s,a\n0,1.5.2\n", "mem.csv:2: error: column 'a': not a number: '1.5.2'");
  expect_error("", "mem.csv:1: error: empty file, expected a header line");
  expect_error("\n\n", "mem.csv:2: error: empty file");
  expect_error("0,1\n1,2\n", "mem.csv:1: error: expected a header line of column names");
  expect_error("t_s,,b\n", "mem.csv:1: error: empty column name");
  expect_error("t_s,a,a\n", "mem.csv:1: error: duplicate column 'a'");
}

void test_load_tiny_result(void **) {
  NavResult r;
  std::string err;
  if (!NavLoadResultDir(NAVVIEW_TEST_DATA_DIR "/tiny", &r, &err)) fail_msg("%s", err.c_str());
  assert_int_equal(r.truth.Size(), 121);
  assert_int_equal(r.nav.Size(), 121);
  assert_int_equal(r.errors.Size(), 121);
  assert_int_equal(r.envelope.Size(), 121);
  assert_string_equal(r.scene_name.c_str(), "tiny-figure-eight");
  assert_int_equal(r.runs, 20);
  // Row 0: yaw 45 deg, converted to radians at the I/O edge.
  assert_near(r.truth.euler_rad[2], NAV_PI / 4.0, 1e-9);
  // Row 1 position (truth.csv line 3).
  assert_near(r.truth.pos_ned_m[3], 3.140157, 0.0);
  assert_near(r.truth.pos_ned_m[4], 3.135854, 0.0);
  assert_true(r.notes.empty());
}

void test_load_malformed_result(void **) {
  NavResult r;
  std::string err;
  assert_false(NavLoadResultDir(NAVVIEW_TEST_DATA_DIR "/malformed", &r, &err));
  if (err.find("malformed/nav.csv:5: error: column 'pos_e_m': not a number: 'abc'") == std::string::npos)
    fail_msg("unexpected message: %s", err.c_str());
}

// A scratch result directory with the given files.
std::string make_dir(const char *truth, const char *nav) {
  char tmpl[] = "/tmp/navview_csv_XXXXXX";
  const char *d = mkdtemp(tmpl);
  assert_non_null(d);
  const std::string dir = d;
  FILE *f = std::fopen((dir + "/truth.csv").c_str(), "w");
  std::fputs(truth, f);
  std::fclose(f);
  if (nav) {
    f = std::fopen((dir + "/nav.csv").c_str(), "w");
    std::fputs(nav, f);
    std::fclose(f);
  }
  return dir;
}

void remove_dir(const std::string &dir) {
  std::remove((dir + "/truth.csv").c_str());
  std::remove((dir + "/nav.csv").c_str());
  rmdir(dir.c_str());
}

void test_load_semantic_errors(void **) {
  const char *good = "t_s,pos_n_m,pos_e_m,pos_d_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,0\n1,1,0,0,0,0,0\n";
  NavResult r;
  std::string err;

  std::string dir = make_dir("t_s,pos_n_m,pos_e_m,pos_d_m,roll_deg,pitch_deg\n0,0,0,0,0,0\n", good);
  assert_false(NavLoadResultDir(dir, &r, &err));
  assert_true(err.find("/truth.csv:1: error: missing column 'yaw_deg'") != std::string::npos);
  remove_dir(dir);

  dir =
      make_dir(good, "t_s,pos_n_m,pos_e_m,pos_d_m,roll_deg,pitch_deg,yaw_deg\n0,0,0,0,0,0,0\n2,0,0,0,0,0,0\n"
                     "1,0,0,0,0,0,0\n");
  assert_false(NavLoadResultDir(dir, &r, &err));
  if (err.find("/nav.csv:4: error: t_s goes backwards (1 after 2)") == std::string::npos)
    fail_msg("%s", err.c_str());
  remove_dir(dir);

  dir = make_dir(good, nullptr);
  assert_false(NavLoadResultDir(dir, &r, &err));
  assert_true(err.find("/nav.csv: error: cannot open") != std::string::npos);
  remove_dir(dir);

  dir = make_dir(good, "t_s,pos_n_m,pos_e_m,pos_d_m,roll_deg,pitch_deg,yaw_deg\n");
  assert_false(NavLoadResultDir(dir, &r, &err));
  assert_true(err.find("/nav.csv:2: error: no data rows") != std::string::npos);
  remove_dir(dir);

  // Optional files missing: loads, with notes.
  dir = make_dir(good, good);
  assert_true(NavLoadResultDir(dir, &r, &err));
  assert_int_equal(r.errors.Size(), 0);
  assert_int_equal(r.notes.size(), 2);
  remove_dir(dir);

  assert_false(NavLoadResultDir("/nonexistent/navview", &r, &err));
  assert_true(err.find("/nonexistent/navview: error: not a result directory") != std::string::npos);
}

void test_time_lookup(void **) {
  const std::vector<double> t = {0.0, 1.0, 2.0, 4.0};
  const std::vector<double> v = {0.0, 10.0, 1.0, 11.0, 2.0, 12.0, 4.0, 14.0};
  assert_int_equal(NavTimeIndex(t, -1.0), 0);
  assert_int_equal(NavTimeIndex(t, 0.0), 0);
  assert_int_equal(NavTimeIndex(t, 1.5), 1);
  assert_int_equal(NavTimeIndex(t, 4.0), 3);
  assert_int_equal(NavTimeIndex(t, 9.0), 3);
  assert_near(NavInterpolate(t, v, 2, 0, 3.0), 3.0, 1e-15);
  assert_near(NavInterpolate(t, v, 2, 1, 3.0), 13.0, 1e-15);
  assert_near(NavInterpolate(t, v, 2, 1, -5.0), 10.0, 0.0);
  assert_near(NavInterpolate(t, v, 2, 1, 50.0), 14.0, 0.0);
  assert_true(std::isnan(NavInterpolate({}, {}, 1, 0, 0.0)));
}

} // namespace

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_parse_valid),
      cmocka_unit_test(test_parse_crlf_and_blank_lines),
      cmocka_unit_test(test_parse_errors_name_file_and_line),
      cmocka_unit_test(test_load_tiny_result),
      cmocka_unit_test(test_load_malformed_result),
      cmocka_unit_test(test_load_semantic_errors),
      cmocka_unit_test(test_time_lookup),
  };
  return cmocka_run_group_tests(tests, nullptr, nullptr);
}
