/* Helpers of the tests that drive an executable (see navsim_cli.h). */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <regex.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include "navsim_cli.h"

void nav_test_slurp(const char *path, char *buf, size_t cap) {
  buf[0] = '\0';
  FILE *f = fopen(path, "rb");
  if (!f) return;
  const size_t n = fread(buf, 1, cap - 1, f);
  buf[n] = '\0';
  fclose(f);
}

char *nav_test_slurp_len(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  fseek(f, 0, SEEK_END);
  const long n = ftell(f);
  fseek(f, 0, SEEK_SET);
  char *b = n >= 0 ? malloc((size_t)n + 1) : NULL;
  if (!b) {
    fclose(f);
    return NULL;
  }
  const size_t got = fread(b, 1, (size_t)n, f);
  fclose(f);
  b[got] = '\0';
  *len = got;
  return b;
}

char *nav_test_slurp_alloc(const char *path) {
  size_t len = 0;
  return nav_test_slurp_len(path, &len);
}

nav_cli_result *nav_test_run_cli(const char *exe, const char *work, const char *cwd, const char *args) {
  static nav_cli_result r;
  char cmd[8192], path[4096];
  snprintf(cmd, sizeof cmd, "cd '%s' && '%s' %s >'%s/stdout.txt' 2>'%s/stderr.txt'", cwd ? cwd : work, exe,
           args, work, work);
  const int st = system(cmd);
  r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  snprintf(path, sizeof path, "%s/stdout.txt", work);
  nav_test_slurp(path, r.out, sizeof r.out);
  snprintf(path, sizeof path, "%s/stderr.txt", work);
  nav_test_slurp(path, r.err, sizeof r.err);
  return &r;
}

nav_cli_result *nav_test_run_clif(const char *exe, const char *work, const char *cwd, const char *fmt, ...) {
  char args[4096];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(args, sizeof args, fmt, ap);
  va_end(ap);
  return nav_test_run_cli(exe, work, cwd, args);
}

int nav_test_fresh_dir(const char *dir) {
  char cmd[4200];
  snprintf(cmd, sizeof cmd, "rm -rf '%s' && mkdir -p '%s'", dir, dir);
  return system(cmd) == 0 ? 0 : -1;
}

void nav_test_write_file(const char *dir, const char *name, const char *text) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "w");
  if (!f) fail_msg("cannot write %s", path);
  fputs(text, f);
  if (fclose(f) != 0) fail_msg("cannot write %s", path);
}

bool nav_test_is_file(const char *path) {
  struct stat s;
  return stat(path, &s) == 0 && S_ISREG(s.st_mode);
}

void nav_test_assert_matches(const char *text, const char *pattern) {
  regex_t re;
  assert_int_equal(regcomp(&re, pattern, REG_EXTENDED | REG_NEWLINE), 0);
  const int rc = regexec(&re, text, 0, NULL, 0);
  regfree(&re);
  if (rc != 0) fail_msg("\"%s\" does not match /%s/", text, pattern);
}
