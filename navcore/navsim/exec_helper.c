/* navsim's helper programs (exec_helper.h). */
#define _POSIX_C_SOURCE 200809L
#include "exec_helper.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "navcore/nav_paths.h"

enum { PATH_CAP = 4096, EXIT_FAILURE_HELPER = 1 };

bool navsim_launched_with_ranks(void) {
  static const char *const vars[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"};
  for (size_t i = 0; i < sizeof vars / sizeof vars[0]; ++i) {
    const char *v = getenv(vars[i]);
    if (v && atoi(v) > 1) return true;
  }
  return false;
}

int navsim_exec_helper(const char *name, const char *what, char **argv) {
  char helper[PATH_CAP], self[PATH_CAP];
  if (!nav_paths_program(name, helper, sizeof helper)) {
    fprintf(stderr,
            "%s: the helper program %s is not installed beside this navsim (looked in navsim's folder and "
            "in ../libexec/navcore); reinstall navsim or rebuild it\n",
            what, name);
    return EXIT_FAILURE_HELPER;
  }
  /* The helper's own /proc/self/exe is the helper: tell it where navsim is. */
  const int set = nav_paths_executable(self, sizeof self) ? setenv(NAVSIM_PROGRAM_ENV, self, 1)
                                                           : unsetenv(NAVSIM_PROGRAM_ENV);
  if (set != 0) {
    fprintf(stderr, "%s: cannot set %s: %s\n", what, NAVSIM_PROGRAM_ENV, strerror(errno));
    return EXIT_FAILURE_HELPER;
  }
  fflush(stdout);
  fflush(stderr);
  execv(helper, argv);
  fprintf(stderr, "%s: cannot start %s: %s\n", what, helper, strerror(errno));
  return EXIT_FAILURE_HELPER;
}
