#include "req_out.h"

#include <math.h>
#include <stdlib.h>

void navsim_req_buffer_add(navsim_req_buffer *b, const nav_epoch_errors *e) {
  if (b->failed) return;
  if (b->n == b->cap) {
    const size_t nc = b->cap ? 2 * b->cap : 4096;
    nav_epoch_errors *g = realloc(b->e, nc * sizeof *g);
    if (!g) {
      b->failed = true;
      return;
    }
    b->e = g;
    b->cap = nc;
  }
  b->e[b->n++] = *e;
}

void navsim_req_buffer_free(navsim_req_buffer *b) {
  free(b->e);
  b->e = NULL;
  b->n = b->cap = 0;
}

nav_status navsim_req_replay_verdicts(const nav_requirement *reqs, int n, const navsim_req_buffer *b,
                                      const nav_replay_summary *sum, nav_requirement_verdict *out) {
  if (b->failed) return NAV_ERR_NO_MEMORY;
  const double t0 = sum->t_first_s;
  nav_req_interval iv[NAV_REQ_MAX_OUTAGES];
  int ni = 0;
  for (long g = 0; g < sum->gap_count && g < NAV_REPLAY_MAX_GAPS && ni < NAV_REQ_MAX_OUTAGES; ++g) {
    const nav_replay_gap *gp = &sum->gaps[g];
    iv[ni].t0_s = gp->t0_s - t0;
    iv[ni].t1_s = gp->open ? nextafter(gp->t1_s - t0, INFINITY) : gp->t1_s - t0;
    ++ni;
  }
  nav_req_evaluator *ev = NULL;
  nav_status st = nav_req_evaluator_create(reqs, n, 1, iv, ni, &ev);
  if (st != NAV_OK) return st;
  nav_req_run *r = NULL;
  st = nav_req_run_begin(ev, 0, &r);
  /* A closed gap's end is the epoch of the fix that ends it, before the fix is applied: its errors
   * enter the evaluation 1 ulp before that epoch, inside the half-open interval [t0, t1) and before
   * the output epoch that may coincide with the fix (which holds the errors after the update). */
  long g = 0;
  for (size_t i = 0; i <= b->n && st == NAV_OK; ++i) {
    const double t_next = i < b->n ? b->e[i].t_s - t0 : INFINITY;
    for (; g < sum->gap_count && g < NAV_REPLAY_MAX_GAPS && st == NAV_OK; ++g) {
      const nav_replay_gap *gp = &sum->gaps[g];
      if (gp->open || !gp->has_end_errors) continue;
      const double t_end = nextafter(gp->t1_s - t0, -INFINITY);
      if (t_end >= t_next) break;
      nav_epoch_errors e = gp->end_errors;
      e.t_s = t_end;
      st = nav_req_run_add(r, &e);
    }
    if (i == b->n || st != NAV_OK) break;
    nav_epoch_errors e = b->e[i];
    e.t_s -= t0;
    st = nav_req_run_add(r, &e);
  }
  if (r) {
    const nav_status st2 = nav_req_run_end(ev, r);
    if (st == NAV_OK) st = st2;
  }
  if (st == NAV_OK) st = nav_req_evaluator_finish(ev, out);
  nav_req_evaluator_destroy(ev);
  return st;
}
