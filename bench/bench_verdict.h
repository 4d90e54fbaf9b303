/*
 * navsim bench: the verdicts of the target table, as pure functions of the figures printed beside
 * them (issue 23 item 5), so that a test can feed made-up timings and check every rule:
 *  - a target is "met" only when its figure was measured in this run and satisfies the bound;
 *  - a figure that is a bound (a run stopped at its time cap) decides only when it already fails;
 *  - MPI scaling is "met" only when 2 ranks run at least 1.8x as fast as 1 rank, and "not
 *    measurable here" on a machine with fewer than twice the cores the 2-rank run uses (the
 *    ranks, mpirun and the system then share cores, so the speed-up says nothing of MPI);
 *  - a peer's figure is either measured in this run (same machine, same load) or the published
 *    one, labelled with where it was measured; a ratio against a published figure is labelled so.
 */
#ifndef NAVSIM_BENCH_VERDICT_H
#define NAVSIM_BENCH_VERDICT_H

#include <stdbool.h>
#include <stddef.h>

typedef enum bench_verdict {
  BENCH_NOT_MEASURED = 0,  /* no figure (case not run, failed, or not in this suite) */
  BENCH_NOT_MEASURABLE,    /* a figure exists but this machine cannot decide the target */
  BENCH_MET,
  BENCH_NOT_MET,
} bench_verdict;

/* The verdict column's text: "not measured", "not measurable here", "**met**", "**not met**". */
const char *bench_verdict_text(bench_verdict v);

/* figure <= limit. A non-finite figure is not measured. @p is_lower_bound: the figure is only a
 * lower bound of the true value (a capped run): it decides only when already above the limit. */
bench_verdict bench_verdict_at_most(double figure, double limit, bool is_lower_bound);

/* figure >= limit; a non-finite figure is not measured. */
bench_verdict bench_verdict_at_least(double figure, double limit);

/* Minimum speed-up of 2 ranks over 1 for the MPI target. */
#define BENCH_MPI_MIN_SPEEDUP 1.8

/* MPI scaling from the wall times of 1 and 2 ranks, each with @p threads_per_rank threads, on a
 * machine with @p cores cores. *speedup (may be NULL) receives t1/t2 (NAN when not measured). */
bench_verdict bench_verdict_mpi(double t1_s, double t2_s, int threads_per_rank, long cores, double *speedup);

/* A peer's figure next to ours. */
typedef struct bench_peer {
  const char *name;    /* e.g. "KF-GINS" */
  double wall_s;       /* its wall time on the same data [s] (NAN: unknown) */
  double error_m;      /* its error figure [m] (NAN: unknown) */
  bool measured_here;  /* timed in this run, interleaved with ours; else the published figure */
  const char *source;  /* published: where and on what machine it was measured */
} bench_peer;

/* "KF-GINS 4.9 s measured in this run" or "KF-GINS 3.3 s published (SOURCE)", and the speed ratio
 * ours/peer with the same label ("ratio 0.079, measured here" / "ratio 0.12 against the published
 * figure"). @return the number of characters written (snprintf). */
int bench_peer_text(char *buf, size_t cap, const bench_peer *p, double our_wall_s);

/* The median of @p n values (sorted in place); NAN when n == 0. */
double bench_median(double *v, int n);

/* The 1-minute load average now (/proc/loadavg), NAN when unknown. */
double bench_load1(void);

#endif /* NAVSIM_BENCH_VERDICT_H */
