/* navsim run: simulate a scene and write its result directory (run_cmd.c). */
#ifndef NAVSIM_RUN_CMD_H
#define NAVSIM_RUN_CMD_H

/** Run `navsim run ARGS` (ARGS: what follows "run"); returns the process exit code. */
int navsim_run(int argc, char **argv);

#endif /* NAVSIM_RUN_CMD_H */
