/*
 * navsim bench: the benchmark (speed against error, FLOP counts, valgrind and peer runs) lives in
 * the benchmark tooling (bench/, the program navsim-bench) so that the navsim users run carries
 * no instrumentation. This command finds navsim-bench beside navsim (nav_paths_program: installed
 * in <libexec>/navcore, or bench/ of the build tree) and runs it in this process's place, as
 * navsim's other helper programs (exec_helper.h).
 */
#define _POSIX_C_SOURCE 200809L
#include "bench_cmd.h"

#include <stdio.h>
#include <stdlib.h>

#include "exec_helper.h"

int navsim_bench(int argc, char **argv) {
  /* navsim-bench gets this command's arguments. navsim_exec_helper also sets NAVSIM_PROGRAM to
   * this navsim, which the bench times with the programs beside it: an installed navsim-bench in
   * libexec/navcore would not find bin/navsim on its own. */
  char **args = calloc((size_t)argc + 2, sizeof *args);
  if (args == NULL) {
    fprintf(stderr, "navsim bench: out of memory\n");
    return 1;
  }
  args[0] = "navsim-bench";
  for (int i = 0; i < argc; ++i) args[i + 1] = argv[i];
  const int rc = navsim_exec_helper("navsim-bench", "navsim bench", args);
  free(args);
  return rc;
}
