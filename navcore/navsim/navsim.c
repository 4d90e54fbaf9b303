/*
 * navsim: the command-line program of the navigation simulation environment. This file is the
 * command table and the dispatch; each command lives in the file named for it (check_cmd.c,
 * run_cmd.c, estimate_cmd.c, ...) and parses its own options with the helpers of cli_util.h.
 * The program's --help is printed from the table, so a command is added in one place.
 * `serve`, and `run` under several MPI ranks, replace this process by a helper program
 * (navsim-serve, navsim-mpi; exec_helper.h), so navsim itself links neither the server's
 * libraries nor MPI. This file is also the main of navsim-mpi (NAVSIM_HAVE_MPI, no such exec).
 *
 * Exit codes: 0 success; 1 failure other than invalid input (I/O, numerical); 2 invalid scene
 * or invalid command line.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <string.h>

#include "allan_cmd.h"
#include "bench_cmd.h"
#include "budget_cmd.h"
#include "catalog_cmd.h"
#include "check_cmd.h"
#include "cli_util.h"
#include "estimate_cmd.h"
#include "import_cmd.h"
#include "replay_cmd.h"
#include "report_cmd.h"
#include "run_cmd.h"
#include "schema_cmd.h"
#include "select_cmd.h"
#include "tradeoff_cmd.h"
#include "exec_helper.h"
#include "navcore/nav_version.h"

enum { EXIT_OK = 0, EXIT_INVALID = 2 };

/* navsim catalog: the catalogs of this installation's resources directory. */
static int cmd_catalog(int argc, char **argv) {
  char res[4096];
  return navsim_catalog(argc, argv, navsim_find_resources_dir(res, sizeof res) ? res : NULL);
}

/* The whole command line, for the commands that hand it to a helper program (exec_helper.h). */
static char **g_argv;

#ifdef NAVSIM_HAVE_SERVE
/* navsim serve: the server is the helper program navsim-serve (libmicrohttpd is loaded only there). */
static int cmd_serve(int argc, char **argv) {
  (void)argc;
  (void)argv;
  return navsim_exec_helper("navsim-serve", "navsim serve", g_argv);
}
#endif

typedef struct navsim_command {
  const char *name;
  const char *synopsis; /* what --help shows after the name ("" for none) */
  const char *summary;  /* one line, or two separated by '\n' */
  int (*run)(int argc, char **argv); /* the arguments after the command name */
} navsim_command;

/* In the order of navsim --help. */
static const navsim_command k_commands[] = {
    {"check", "SCENE...", "validate scene files; errors as FILE:LINE:COL: error: FIELD: MESSAGE", navsim_check},
    {"estimate", "SCENE", "preliminary estimate: closed-form error growth and covariance analysis", navsim_estimate},
    {"run", "SCENE", "simulate a scene (one run or Monte Carlo) and write the results", navsim_run},
    {"budget", "SCENE", "error budget: each error source's share of each requirement", navsim_budget},
    {"replay", "", "run the navigation on recorded IMU/GNSS files and score it against a reference",
     navsim_replay},
    {"render", "DIR",
     "headless image of a result directory: 3d, top, map, errors, noise, allan, bench,\n"
     "tradeoff, sky or dop view (navview)",
     navsim_render},
    {"report", "DIR", "HTML page with the figures, statistics and requirement verdicts of a result", navsim_report},
    {"bench", "", "speed against error for each algorithm, Earth model and rate", navsim_bench},
    {"catalog", "", "list the IMU, GNSS receiver and array accelerometer catalogs and their models", cmd_catalog},
    {"allan", "", "Allan-deviation check of a catalog part or scene IMU against its spec", navsim_allan},
    {"import", "FILE", "GPX / KML track or gnss-ins-sim motion definition -> scene file", navsim_import},
    {"export", "DIR", "KML (Google Earth) and CSV tracks of a result directory", navsim_export},
    {"select", "SCENE", "cheapest catalog IMU / receiver / scheme meeting the scene's requirements", navsim_select},
    {"sweep", "SCENE", "requirements over a grid of scene parameters; largest value still passing", navsim_sweep},
    {"tradeoff", "SCENE", "CPU time against error of each modelling choice; the cheapest within tolerance",
     navsim_tradeoff},
    {"schema", "", "JSON Schema of scene files: keys, types, units, bounds, defaults", navsim_schema},
#ifdef NAVSIM_HAVE_SERVE
    /* Listed only when built: the man pages and bash completion are made from this list. */
    {"serve", "", "HTTP server of the web variant: browser studio and JSON API (docs/web-server.md)", cmd_serve},
#endif
};
enum { N_COMMANDS = sizeof k_commands / sizeof k_commands[0] };

static void print_usage(FILE *f) {
  fputs("usage: navsim [--version] [--help] COMMAND [ARGS]\n"
        "\n"
        "Simulate inertial and integrated navigation systems from scene files.\n"
        "\n"
        "commands:\n",
        f);
  for (size_t i = 0; i < N_COMMANDS; ++i) {
    const navsim_command *c = &k_commands[i];
    char head[64];
    snprintf(head, sizeof head, "%s%s%s", c->name, c->synopsis[0] ? " " : "", c->synopsis);
    /* The summary column starts at column 20; a second line is indented to it. */
    const char *nl = strchr(c->summary, '\n');
    if (nl == NULL) {
      fprintf(f, "  %-16s %s\n", head, c->summary);
    } else {
      fprintf(f, "  %-16s %.*s\n", head, (int)(nl - c->summary), c->summary);
      fprintf(f, "  %-16s %s\n", "", nl + 1);
    }
  }
  fputs("\n"
        "options:\n"
        "  --version        print \"navsim X.Y.Z\" and exit\n"
        "  -h, --help       print this help (navsim COMMAND --help for a command)\n"
        "\n"
        "exit codes: 0 success, 1 failure (I/O, numerical), 2 invalid scene or command line\n",
        f);
}

int main(int argc, char **argv) {
  if (argc < 2) {
    print_usage(stderr);
    return EXIT_INVALID;
  }
  const char *cmd = argv[1];
  g_argv = argv;
#ifdef NAVSIM_MPI_HELPER
  /* Under mpirun or srun with several ranks, `run` is navsim-mpi's (before any MPI call: the
   * launcher's environment is all MPI_Init needs, and execv keeps the process). */
  if (strcmp(cmd, "run") == 0 && navsim_launched_with_ranks())
    return navsim_exec_helper("navsim-mpi", "navsim run", argv);
#endif
  if (strcmp(cmd, "--version") == 0 || strcmp(cmd, "-V") == 0) {
    printf("navsim %s\n", nav_version_string());
    return EXIT_OK;
  }
  if (navsim_is_help(cmd)) {
    print_usage(stdout);
    return EXIT_OK;
  }
  for (size_t i = 0; i < N_COMMANDS; ++i)
    if (strcmp(cmd, k_commands[i].name) == 0) return k_commands[i].run(argc - 2, argv + 2);
#ifndef NAVSIM_HAVE_SERVE
  if (strcmp(cmd, "serve") == 0) {
    fprintf(stderr, "navsim serve: this navsim was built without the server (it needs libmicrohttpd-dev and "
                    "libzip-dev; cmake -DNAV_BUILD_SERVER=ON)\n");
    return 1;
  }
#endif
  fprintf(stderr, "navsim: unknown command \"%s\" (see navsim --help)\n", cmd);
  return EXIT_INVALID;
}
