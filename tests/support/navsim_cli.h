/**
 * @file navsim_cli.h
 * @brief Helpers of the tests that drive an executable (the navsim contract tests in
 *        tests/scenario): run a command with both streams captured, read files, scratch
 *        directories, regex matches. One copy here instead of one per test file.
 *
 * Include after <cmocka.h> (the asserting helpers fail the current cmocka test). Link
 * nav_test_support (nav_add_cmocka_test does).
 */
#ifndef NAV_TEST_NAVSIM_CLI_H
#define NAV_TEST_NAVSIM_CLI_H

#include <stdbool.h>
#include <stddef.h>

/* Exit code and captured output of one command. */
typedef struct nav_cli_result {
  int code;        /* exit code; -1 when the process did not exit normally */
  char out[65536]; /* stdout, truncated to fit */
  char err[65536]; /* stderr, truncated to fit */
} nav_cli_result;

/**
 * Run "'EXE' ARGS" through the shell in @p cwd (NULL: @p work); ARGS are already shell-quoted
 * where needed. stdout and stderr go through WORK/stdout.txt and WORK/stderr.txt.
 * @return a static result, overwritten by the next call.
 */
nav_cli_result *nav_test_run_cli(const char *exe, const char *work, const char *cwd, const char *args);

/* As nav_test_run_cli with ARGS formatted printf-style. */
nav_cli_result *nav_test_run_clif(const char *exe, const char *work, const char *cwd, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* At most cap - 1 bytes of @p path into @p buf, NUL-terminated ("" when unreadable). */
void nav_test_slurp(const char *path, char *buf, size_t cap);

/* The whole file, NUL-terminated, malloc'd (caller frees); NULL when unreadable. */
char *nav_test_slurp_alloc(const char *path);

/* As nav_test_slurp_alloc; @p len receives the length read. */
char *nav_test_slurp_len(const char *path, size_t *len);

/* rm -rf DIR && mkdir -p DIR. @return 0, or -1 on failure (for a cmocka group setup). */
int nav_test_fresh_dir(const char *dir);

/* Write @p text to DIR/NAME (fails the test when it cannot). */
void nav_test_write_file(const char *dir, const char *name, const char *text);

/* A regular file exists at @p path. */
bool nav_test_is_file(const char *path);

/* @p text matches the extended regex @p pattern (REG_NEWLINE), else the test fails. */
void nav_test_assert_matches(const char *text, const char *pattern);

#endif /* NAV_TEST_NAVSIM_CLI_H */
