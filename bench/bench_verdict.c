/* navsim bench: verdicts from the figures beside them (see bench_verdict.h). */
#define _POSIX_C_SOURCE 200809L
#include "bench_verdict.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

const char *bench_verdict_text(bench_verdict v) {
  switch (v) {
  case BENCH_MET: return "**met**";
  case BENCH_NOT_MET: return "**not met**";
  case BENCH_NOT_MEASURABLE: return "not measurable here";
  case BENCH_NOT_MEASURED: break;
  }
  return "not measured";
}

bench_verdict bench_verdict_at_most(double figure, double limit, bool is_lower_bound) {
  if (!isfinite(figure)) return BENCH_NOT_MEASURED;
  if (figure > limit) return BENCH_NOT_MET;
  return is_lower_bound ? BENCH_NOT_MEASURED : BENCH_MET;
}

bench_verdict bench_verdict_at_least(double figure, double limit) {
  if (!isfinite(figure)) return BENCH_NOT_MEASURED;
  return figure >= limit ? BENCH_MET : BENCH_NOT_MET;
}

bench_verdict bench_verdict_mpi(double t1_s, double t2_s, int threads_per_rank, long cores, double *speedup) {
  const bool have = isfinite(t1_s) && isfinite(t2_s) && t1_s > 0.0 && t2_s > 0.0;
  if (speedup) *speedup = have ? t1_s / t2_s : NAN;
  if (!have) return BENCH_NOT_MEASURED;
  if (threads_per_rank < 1) threads_per_rank = 1;
  if (cores < 2L * 2L * threads_per_rank) return BENCH_NOT_MEASURABLE;
  return t1_s / t2_s >= BENCH_MPI_MIN_SPEEDUP ? BENCH_MET : BENCH_NOT_MET;
}

int bench_peer_text(char *buf, size_t cap, const bench_peer *p, double our_wall_s) {
  if (!p || !p->name) return snprintf(buf, cap, "no peer");
  char wall[48] = "time unknown";
  if (isfinite(p->wall_s)) snprintf(wall, sizeof wall, "%.3g s", p->wall_s);
  char ratio[96] = "";
  if (isfinite(p->wall_s) && p->wall_s > 0.0 && isfinite(our_wall_s))
    snprintf(ratio, sizeof ratio, "; ours/%s %.3g %s", p->name, our_wall_s / p->wall_s,
             p->measured_here ? "(both measured in this run)" : "(against the published figure)");
  if (p->measured_here) return snprintf(buf, cap, "%s %s measured in this run%s", p->name, wall, ratio);
  return snprintf(buf, cap, "%s %s published (%s)%s", p->name, wall, p->source ? p->source : "source not given",
                  ratio);
}

static int cmp_double(const void *a, const void *b) {
  const double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

double bench_median(double *v, int n) {
  if (n <= 0) return NAN;
  qsort(v, (size_t)n, sizeof *v, cmp_double);
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double bench_load1(void) {
  FILE *f = fopen("/proc/loadavg", "r");
  if (!f) return NAN;
  double l = NAN;
  if (fscanf(f, "%lf", &l) != 1) l = NAN;
  fclose(f);
  return l;
}
