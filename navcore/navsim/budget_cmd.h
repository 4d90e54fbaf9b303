/* navsim budget: error budget of a scene's requirements (see budget_cmd.c). */
#ifndef NAVSIM_BUDGET_CMD_H
#define NAVSIM_BUDGET_CMD_H

/** Run `navsim budget ARGS`; returns the process exit code. */
int navsim_budget(int argc, char **argv);

#endif /* NAVSIM_BUDGET_CMD_H */
