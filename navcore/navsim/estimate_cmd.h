/* navsim estimate: analytic and covariance preliminary estimates (see estimate_cmd.c). */
#ifndef NAVSIM_ESTIMATE_CMD_H
#define NAVSIM_ESTIMATE_CMD_H

/** Run `navsim estimate ARGS`; returns the process exit code. */
int navsim_estimate(int argc, char **argv);

#endif /* NAVSIM_ESTIMATE_CMD_H */
