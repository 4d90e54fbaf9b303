/* navsim bench: child processes timed from their spawn to their exit (bench_child.c). */
#ifndef NAVSIM_BENCH_CHILD_H
#define NAVSIM_BENCH_CHILD_H

#include <stdbool.h>

typedef struct child_result {
  bool started, exited_ok, timed_out;
  int exit_code;
  double wall_s;
  double maxrss_mb; /* of the child itself (wait4) */
  double cpu_s;     /* user + system CPU seconds of the child itself (wait4) */
} child_result;

/* Monotonic time [s], the clock of every figure of the bench. */
double bench_now_s(void);

/* Runs argv (argv[0] looked up in PATH) with stdout and stderr into log_path, killed after
 * timeout_s (0: no limit). wall_s runs from just before the spawn to the moment the exit is
 * seen; started is false when the program could not be started. */
child_result bench_run_child(char *const argv[], const char *log_path, double timeout_s);

/* Write to disk what earlier runs left in the page cache on the file system of @p dir (syncfs),
 * untimed, before a timed run: a run's own fsyncs then do not wait for another program's data
 * (KF-GINS writes 137 MB per run of the long drive; the replay alternating with it fsyncs its
 * result). @return 0, or -1 when @p dir cannot be opened or synced. */
int bench_settle_writes(const char *dir);

#endif
