/*
 * navsim's helper programs: the commands that need a heavy library run in a program of their
 * own, so that every other navsim process starts without loading it. `navsim serve` becomes
 * navsim-serve (the HTTP server: libmicrohttpd, libzip and their TLS and compression libraries)
 * and `navsim run` started by mpirun or srun with more than one rank becomes navsim-mpi (navsim
 * with Open MPI). navsim replaces itself by the helper (execv, same process, same arguments), so
 * users, scripts and mpirun see one program.
 */
#ifndef NAVSIM_EXEC_HELPER_H
#define NAVSIM_EXEC_HELPER_H

#include <stdbool.h>

/** Environment variable through which navsim tells its helper where navsim is (an absolute
 *  path): the server's jobs run that navsim, not the helper. */
#define NAVSIM_PROGRAM_ENV "NAVSIM_PROGRAM"

/** Whether this process was started by mpirun or srun with more than one rank (Open MPI, PMI and
 *  PMIx launchers set the world size in the environment). Reads the environment only: no MPI. */
bool navsim_launched_with_ranks(void);

/**
 * Replace this process by the helper program @p name found beside navsim (nav_paths_program: the
 * same folder in the build tree, libexec/navcore in an installation), with the same @p argv, and
 * NAVSIM_PROGRAM_ENV set to this navsim. Returns only when that fails, after printing why on
 * stderr (prefixed with @p what, e.g. "navsim serve"), with the exit code to return: 1.
 */
int navsim_exec_helper(const char *name, const char *what, char **argv);

#endif /* NAVSIM_EXEC_HELPER_H */
