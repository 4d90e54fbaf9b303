/*
 * navsim-serve: the helper program behind `navsim serve` (exec_helper.h). navsim replaces itself
 * by this program with the same arguments, so libmicrohttpd and libzip, with the TLS and
 * compression libraries they pull in, are loaded by the server only. The server's jobs run the
 * light navsim that started it (its path comes in NAVSIM_PROGRAM), not this program.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exec_helper.h"
#include "navcore/nav_paths.h"
#include "navserve.h"

enum { PATH_CAP = 4096, EXIT_INVALID = 2 };

int main(int argc, char **argv) {
  if (argc < 2 || strcmp(argv[1], "serve") != 0) {
    fprintf(stderr, "navsim-serve: a helper of navsim; start the server with `navsim serve [OPTIONS]`\n");
    return EXIT_INVALID;
  }
  /* The navsim the jobs run: the one that started us, else the navsim beside this program. */
  char navsim[PATH_CAP];
  const char *env = getenv(NAVSIM_PROGRAM_ENV);
  if (env && env[0] == '/' && strlen(env) < sizeof navsim && access(env, X_OK) == 0)
    memcpy(navsim, env, strlen(env) + 1);
  else if (!nav_paths_program("navsim", navsim, sizeof navsim))
    navsim[0] = '\0';
  if (navsim[0] == '\0') {
    fprintf(stderr, "navsim serve: navsim is not found beside navsim-serve (start the server with `navsim serve`)\n");
    return EXIT_INVALID;
  }
  unsetenv(NAVSIM_PROGRAM_ENV);
  navserve_set_job_program(navsim);
  return navserve_main(argc - 2, argv + 2);
}
