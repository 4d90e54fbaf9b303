/* navsim bench: the speed-vs-error benchmark (see bench.c). */
#ifndef NAVSIM_BENCH_H
#define NAVSIM_BENCH_H

/** Run `navsim bench ARGS` (ARGS: what follows "bench"); returns the process exit code. */
int navsim_bench(int argc, char **argv);

#endif /* NAVSIM_BENCH_H */
