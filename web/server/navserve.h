/*
 * navserve: the HTTP server of `navsim serve` (the web variant of the simulation environment).
 * It serves the browser studio (static files from a fixed list) and a JSON API; each simulation
 * runs in its own process (navsim again: `navsim run`), sandboxed and limited.
 * docs/web-server.md describes the API, the limits and the configuration file.
 */
#ifndef NAVSERVE_H
#define NAVSERVE_H

/**
 * `navsim serve [--bind ADDR] [--port N] [--data-dir DIR] [--config FILE] [--studio-dir DIR]`:
 * runs the server until SIGINT or SIGTERM. @p argv holds the options only (argv[0] is the first
 * option). The first line on stdout is `listening on http://HOST:PORT/`.
 * @return the process exit code: 0 after a clean shutdown, 2 for invalid options or
 *         configuration, 1 when the server cannot start (address in use, data directory).
 */
int navserve_main(int argc, char **argv);

/**
 * The navsim program the jobs run (`navsim run`, `navsim estimate`, the Slurm batch scripts), an
 * absolute path; call before navserve_main. Unset: this program (nav_paths_executable). The
 * server runs in the helper navsim-serve, whose jobs are the light navsim's (exec_helper.h).
 */
void navserve_set_job_program(const char *path);

#endif /* NAVSERVE_H */
