/* navsim check: validate scene files (check_cmd.c). */
#ifndef NAVSIM_CHECK_CMD_H
#define NAVSIM_CHECK_CMD_H

/** Run `navsim check ARGS` (ARGS: what follows "check"); returns the process exit code. */
int navsim_check(int argc, char **argv);

#endif /* NAVSIM_CHECK_CMD_H */
