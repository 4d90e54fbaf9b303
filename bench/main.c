/*
 * navsim-bench: the benchmark tooling behind `navsim bench` (speed against error, FLOP counts
 * under valgrind, peer runs). navsim runs this program with the arguments that follow "bench";
 * it is not a command users call by this name (installed in <libexec>/navcore).
 */
#include "bench.h"

int main(int argc, char **argv) {
  return navsim_bench(argc - 1, argv + 1);
}
