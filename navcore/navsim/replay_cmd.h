/* navsim replay: our navigation on recorded IMU / GNSS files, scored against a reference. */
#ifndef NAVSIM_REPLAY_CMD_H
#define NAVSIM_REPLAY_CMD_H

/** Run `navsim replay ARGS` (argv[0] is the first argument after "replay"); returns the exit
 *  code: 0 success, 1 failure (I/O, numerical), 2 invalid input files or command line. */
int navsim_replay(int argc, char **argv);

#endif /* NAVSIM_REPLAY_CMD_H */
