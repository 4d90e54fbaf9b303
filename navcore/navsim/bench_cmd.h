/* navsim bench: runs the benchmark tooling (bench/, the program navsim-bench). */
#ifndef NAVSIM_BENCH_CMD_H
#define NAVSIM_BENCH_CMD_H

/** Run `navsim bench ARGS` (ARGS: what follows "bench"): replaces this process with navsim-bench
 *  ARGS, so its output and exit code are the command's; 1 when navsim-bench cannot be started. */
int navsim_bench(int argc, char **argv);

#endif /* NAVSIM_BENCH_CMD_H */
