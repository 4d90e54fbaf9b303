/*
 * An external program using the installed navcore (issue 24): it finds the scene library of the
 * installation, reads one scene (with its catalog IMU), runs the simulation and prints a figure.
 * Built by tests/install against the installed tree, through find_package(navcore) and through
 * pkg-config. usage: consumer [SCENE_NAME]   (default car-figure-eight.yaml)
 */
#include <stdio.h>
#include <stdlib.h>

#include <navcore/nav_io.h>
#include <navcore/nav_paths.h>
#include <navcore/nav_sim.h>
#include <navcore/nav_version.h>

static void print_diag(void *user, const nav_diag *d) {
  char line[1400];
  (void)user;
  nav_diag_format(d, line, sizeof line);
  fprintf(stderr, "%s\n", line);
}

int main(int argc, char **argv) {
  const char *name = argc > 1 ? argv[1] : "car-figure-eight.yaml";
  char dir[4096], path[4400];
  if (!nav_paths_scenes_dir(dir, sizeof dir)) {
    fprintf(stderr, "consumer: the scene library of the installation was not found\n");
    return 1;
  }
  snprintf(path, sizeof path, "%s/%s", dir, name);
  nav_scene *scene = malloc(sizeof *scene); /* large: not on the stack */
  nav_sim *sim = NULL;
  int rc = 1;
  if (scene == NULL) goto cleanup;
  if (nav_scene_read_file(path, scene, print_diag, NULL) != NAV_OK) {
    rc = 2;
    goto cleanup;
  }
  if (nav_sim_create(scene, &sim) != NAV_OK) goto cleanup;
  nav_sim_options opt = nav_sim_options_default();
  nav_sim_summary sum;
  if (nav_sim_run(sim, &opt, &sum) != NAV_OK) {
    fprintf(stderr, "consumer: %s\n", nav_sim_last_error(sim));
    goto cleanup;
  }
  printf("navcore %s (headers %s): %s: %ld run(s) of %.1f s, final horizontal error %.3f m\n",
         nav_version_string(), NAV_VERSION_STRING, name, sum.runs, sum.duration_s, sum.final.pos_err_h_m);
  rc = 0;
cleanup:
  nav_sim_destroy(sim);
  free(scene);
  return rc;
}
