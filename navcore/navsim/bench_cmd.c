/*
 * navsim bench: the benchmark (speed against error, FLOP counts, valgrind and peer runs) lives in
 * the benchmark tooling (bench/, the program navsim-bench) so that the navsim users run carries
 * no instrumentation. This command finds navsim-bench beside navsim (nav_paths_program: installed
 * in <libexec>/navcore, or bench/ of the build tree) and runs it in this process's place.
 */
#define _POSIX_C_SOURCE 200809L
#include "bench_cmd.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exec_helper.h"
#include "navcore/nav_paths.h"

int navsim_bench(int argc, char **argv) {
  char exe[4096];
  if (!nav_paths_program("navsim-bench", exe, sizeof exe)) {
    fprintf(stderr, "navsim bench: the benchmark program navsim-bench is not installed beside navsim\n");
    return 1;
  }
  char **args = calloc((size_t)argc + 2, sizeof *args);
  if (args == NULL) {
    fprintf(stderr, "navsim bench: out of memory\n");
    return 1;
  }
  args[0] = exe;
  for (int i = 0; i < argc; ++i) args[i + 1] = argv[i];
  /* The bench times this navsim (and the programs beside it): an installed navsim-bench in
   * libexec/navcore would not find bin/navsim on its own. */
  char self[4096];
  if (nav_paths_executable(self, sizeof self) && setenv(NAVSIM_PROGRAM_ENV, self, 1) != 0) {
    fprintf(stderr, "navsim bench: cannot set %s: %s\n", NAVSIM_PROGRAM_ENV, strerror(errno));
    free(args);
    return 1;
  }
  fflush(NULL);
  execv(exe, args);
  fprintf(stderr, "navsim bench: cannot start %s: %s\n", exe, strerror(errno));
  free(args);
  return 1;
}
