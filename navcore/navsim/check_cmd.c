/*
 * navsim check: read and validate scene files, and warn about scenes whose run would exceed the
 * size limits.
 */
#define _POSIX_C_SOURCE 200809L
#include "check_cmd.h"

#include <stdio.h>
#include <unistd.h>

#include "cli_util.h"
#include "navcore/nav_size_limits.h"
#include "navcore/nav_scene.h"

enum { EXIT_OK = 0, EXIT_FAIL = 1, EXIT_INVALID = 2 };

static const char *k_usage_check =
    "usage: navsim check SCENE...\n"
    "\n"
    "Read and validate each scene file. Every problem is printed on stderr as\n"
    "  FILE:LINE:COL: error: FIELD.PATH: what is wrong and what is expected\n"
    "A valid scene whose navsim run would exceed the limits below is reported as\n"
    "  FILE: warning: ... with the predicted result files and memory (the scene stays valid).\n"
    "\n" NAV_LIMITS_HELP "\n"
    "exit codes: 0 every scene is valid; 2 at least one is invalid; 1 a file cannot be read\n";

static long cores(void) {
  const long n = sysconf(_SC_NPROCESSORS_ONLN);
  return n > 0 ? n : 1;
}

int navsim_check(int argc, char **argv) {
  if (argc < 1) {
    fprintf(stderr, "navsim check: missing SCENE\n%s", k_usage_check);
    return EXIT_INVALID;
  }
  for (int i = 0; i < argc; ++i)
    if (navsim_is_help(argv[i])) {
      fputs(k_usage_check, stdout);
      return EXIT_OK;
    }
  int worst = EXIT_OK;
  for (int i = 0; i < argc; ++i) {
    nav_scene scene;
    const int rc = navsim_load_scene(argv[i], &scene);
    if (rc == EXIT_OK) {
      char label[4200];
      snprintf(label, sizeof label, "%s: ", argv[i]);
      navsim_print_recorded_fit(stdout, label, &scene);
      navsim_print_gnss_file(stdout, label, &scene);
    }
    if (rc == EXIT_FAIL) worst = EXIT_FAIL;
    else if (rc == EXIT_INVALID && worst == EXIT_OK) worst = EXIT_INVALID;
    if (rc == EXIT_OK) {
      /* A valid scene whose run would exceed the limits: a warning with the prediction. */
      nav_size_prediction pred;
      nav_predict_run(&scene, false, scene.simulation.threads > 0 ? scene.simulation.threads : cores(), false,
                         &pred);
      (void)nav_size_check("run", argv[i], &pred, false, true);
      nav_scene_release(&scene);
    }
  }
  return worst;
}
