/* navsim allan: Allan-deviation verification of an IMU error model (see allan_cmd.c). */
#ifndef NAVSIM_ALLAN_CMD_H
#define NAVSIM_ALLAN_CMD_H

/**
 * Run `navsim allan ARGS` (argv holds the arguments after "allan").
 * @return the process exit code: 0 success (also when a check fails, unless --strict); 1 I/O or
 *         numerical failure, catalog not found; 2 invalid command line, scene or part name;
 *         3 with --strict, at least one ARW/VRW check failed.
 */
int navsim_allan(int argc, char **argv);

#endif /* NAVSIM_ALLAN_CMD_H */
