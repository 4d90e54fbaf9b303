/*
 * Monte Carlo jobs split into ranges of runs (nav_sim_partial.h).
 *
 * nav_sim_run() keeps per-run tables (statistics values, envelope values, final errors, samples
 * done, status) and reduces them in run order once every run has finished. Through the range hook
 * of sim.c, nav_sim_run_partial() executes only the runs of its range and copies their rows into
 * a packed buffer; nav_sim_merge() executes no run, copies the rows of every partial back into
 * the job's tables and lets nav_sim_run() reduce them: the same numbers, in the same order, as a
 * single-process run, hence bit-identical results.
 *
 * Packed layout (native byte order; 8-byte aligned sections):
 *   header | metrics [n_metrics][count][stats_per_run] | env [count][n_out][env_values] (if any)
 *   | final [count] nav_epoch_errors | samples_done [count] int64 | status [count] int64
 *   | smoothed [2 n_metrics][count][sm_per_run] and smoother bytes [count] int64 (navigation.smoother)
 */
#include "navcore/nav_sim_partial.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sim/sim_internal.h"
#include "sim/sim_partial_internal.h"

#define PARTIAL_MAGIC "NAVSIMP2"

typedef struct partial_header {
  char magic[8];
  uint64_t sizeof_errors; /* sizeof(nav_epoch_errors) of the build that packed it */
  int64_t runs, r0, r1;
  int64_t n_metrics, stats_per_run, n_out, env_values, has_env;
  int64_t sm_per_run; /* navigation.smoother: values per run and plane; 0: no smoothed section */
  uint64_t total_size;
} partial_header;

struct nav_sim_partial {
  unsigned char *buf; /* header + sections */
  size_t size;
};

typedef struct layout {
  size_t metrics, env, final, samples, status, sm, sm_bytes, end;
} layout;

static size_t align8(size_t x) { return (x + 7u) & ~(size_t)7u; }

/* Section offsets of a partial; false on size overflow. */
static bool partial_layout(const partial_header *h, layout *l) {
  const double count = (double)(h->r1 - h->r0);
  const double bytes = sizeof(partial_header) + count * (double)h->n_metrics * (double)h->stats_per_run * 8.0 +
                       (h->has_env ? count * (double)h->n_out * (double)h->env_values * 8.0 : 0.0) +
                       count * ((double)sizeof(nav_epoch_errors) + 24.0) +
                       count * (2.0 * (double)h->n_metrics * (double)h->sm_per_run + 1.0) * 8.0;
  if (h->r1 < h->r0 || h->n_metrics < 0 || h->stats_per_run < 0 || h->n_out < 0 || h->env_values < 0 ||
      h->sm_per_run < 0 || bytes > (double)SIZE_MAX / 2)
    return false;
  const size_t c = (size_t)(h->r1 - h->r0);
  l->metrics = align8(sizeof(partial_header));
  l->env = l->metrics + (size_t)h->n_metrics * c * (size_t)h->stats_per_run * sizeof(double);
  l->final = l->env + (h->has_env ? c * (size_t)h->n_out * (size_t)h->env_values * sizeof(double) : 0);
  l->samples = align8(l->final + c * sizeof(nav_epoch_errors));
  l->status = l->samples + c * sizeof(int64_t);
  l->sm = l->status + c * sizeof(int64_t);
  const size_t sm_values = h->sm_per_run > 0 ? 2 * (size_t)h->n_metrics * c * (size_t)h->sm_per_run : 0;
  l->sm_bytes = l->sm + sm_values * sizeof(double);
  l->end = l->sm_bytes + (h->sm_per_run > 0 ? c * sizeof(int64_t) : 0);
  return true;
}

/* Hook of nav_sim_run_partial: copy the rows of the range out of the job's tables. */
typedef struct take_ctx {
  long r0, r1;
  nav_sim_partial *out;
} take_ctx;

static nav_status take_rows(void *user, nav_sim_tables *t) {
  take_ctx *c = user;
  partial_header h;
  memset(&h, 0, sizeof h);
  memcpy(h.magic, PARTIAL_MAGIC, 8);
  h.sizeof_errors = sizeof(nav_epoch_errors);
  h.runs = t->runs;
  h.r0 = c->r0 < t->runs ? c->r0 : t->runs;
  h.r1 = c->r1 < t->runs ? c->r1 : t->runs;
  if (h.r1 < h.r0) h.r1 = h.r0;
  h.n_metrics = t->n_metrics;
  h.stats_per_run = t->stats_per_run;
  h.n_out = t->n_out;
  h.env_values = t->env_values;
  h.has_env = t->env != NULL;
  h.sm_per_run = t->sm_metrics ? t->sm_per_run : 0;
  layout l;
  if (!partial_layout(&h, &l)) return NAV_ERR_NO_MEMORY;
  h.total_size = l.end;
  nav_sim_partial *p = calloc(1, sizeof *p);
  unsigned char *b = p ? calloc(1, l.end) : NULL;
  if (!b) {
    free(p);
    return NAV_ERR_NO_MEMORY;
  }
  const size_t count = (size_t)(h.r1 - h.r0);
  memcpy(b, &h, sizeof h);
  for (int64_t m = 0; m < h.n_metrics; ++m)
    if (count > 0)
      memcpy(b + l.metrics + (size_t)m * count * (size_t)h.stats_per_run * sizeof(double),
             t->metrics + ((size_t)m * (size_t)t->runs + (size_t)h.r0) * (size_t)h.stats_per_run,
             count * (size_t)h.stats_per_run * sizeof(double));
  if (h.has_env && count > 0)
    memcpy(b + l.env, t->env + (size_t)h.r0 * (size_t)h.n_out * (size_t)h.env_values,
           count * (size_t)h.n_out * (size_t)h.env_values * sizeof(double));
  if (count > 0) memcpy(b + l.final, t->final + h.r0, count * sizeof(nav_epoch_errors));
  for (size_t i = 0; i < count; ++i) {
    const int64_t sd = t->samples_done[(size_t)h.r0 + i], s = (int64_t)t->status[(size_t)h.r0 + i];
    memcpy(b + l.samples + i * sizeof(int64_t), &sd, sizeof sd);
    memcpy(b + l.status + i * sizeof(int64_t), &s, sizeof s);
  }
  if (h.sm_per_run > 0 && count > 0) {
    for (int64_t m = 0; m < 2 * h.n_metrics; ++m)
      memcpy(b + l.sm + (size_t)m * count * (size_t)h.sm_per_run * sizeof(double),
             t->sm_metrics + ((size_t)m * (size_t)t->runs + (size_t)h.r0) * (size_t)h.sm_per_run,
             count * (size_t)h.sm_per_run * sizeof(double));
    memcpy(b + l.sm_bytes, t->sm_bytes + h.r0, count * sizeof(int64_t));
  }
  p->buf = b;
  p->size = l.end;
  c->out = p;
  return NAV_OK;
}

nav_status nav_sim_run_partial(nav_sim *sim, const nav_sim_options *opts, long r0, long r1,
                               nav_sim_partial **out) {
  if (!sim || !opts || !out || r0 < 0 || r1 < r0) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  take_ctx c = {r0, r1, NULL};
  const nav_sim_range_hook hook = {true, r0, r1, false, take_rows, &c};
  nav_sim_set_range_hook(sim, &hook);
  nav_sim_summary unused;
  nav_status st = nav_sim_run(sim, opts, &unused);
  nav_sim_set_range_hook(sim, NULL);
  if (st == NAV_OK && !c.out) st = NAV_ERR_NO_MEMORY;
  if (st != NAV_OK) {
    nav_sim_partial_destroy(c.out);
    return st;
  }
  *out = c.out;
  return NAV_OK;
}

static const partial_header *header_of(const nav_sim_partial *p) { return (const partial_header *)(const void *)p->buf; }

void nav_sim_partial_range(const nav_sim_partial *p, long *r0, long *r1) {
  if (r0) *r0 = p ? (long)header_of(p)->r0 : 0;
  if (r1) *r1 = p ? (long)header_of(p)->r1 : 0;
}

const void *nav_sim_partial_bytes(const nav_sim_partial *p, size_t *size) {
  if (size) *size = p ? p->size : 0;
  return p ? p->buf : NULL;
}

nav_status nav_sim_partial_unpack(const void *bytes, size_t size, nav_sim_partial **out) {
  if (!bytes || !out) return NAV_ERR_INVALID_ARG;
  *out = NULL;
  partial_header h;
  if (size < sizeof h) return NAV_ERR_PARSE;
  memcpy(&h, bytes, sizeof h);
  layout l;
  if (memcmp(h.magic, PARTIAL_MAGIC, 8) != 0 || h.sizeof_errors != sizeof(nav_epoch_errors) || h.r0 < 0 ||
      h.r1 > h.runs || !partial_layout(&h, &l) || l.end != size || h.total_size != size)
    return NAV_ERR_PARSE;
  nav_sim_partial *p = calloc(1, sizeof *p);
  unsigned char *b = p ? malloc(size) : NULL;
  if (!b) {
    free(p);
    return NAV_ERR_NO_MEMORY;
  }
  memcpy(b, bytes, size);
  p->buf = b;
  p->size = size;
  *out = p;
  return NAV_OK;
}

void nav_sim_partial_destroy(nav_sim_partial *p) {
  if (!p) return;
  free(p->buf);
  free(p);
}

/* Hook of nav_sim_merge: copy the rows of every partial into the job's tables. */
typedef struct put_ctx {
  const nav_sim_partial *const *parts;
  size_t count;
} put_ctx;

static nav_status put_rows(void *user, nav_sim_tables *t) {
  const put_ctx *c = user;
  int64_t next = 0;
  for (size_t q = 0; q < c->count; ++q) {
    const partial_header *h = header_of(c->parts[q]);
    const unsigned char *b = c->parts[q]->buf;
    layout l;
    if (h->runs != t->runs || h->r0 != next || h->n_metrics != t->n_metrics || h->stats_per_run != t->stats_per_run ||
        h->n_out != t->n_out || h->env_values != t->env_values || h->has_env != (t->env != NULL) ||
        h->sm_per_run != (t->sm_metrics ? t->sm_per_run : 0) || !partial_layout(h, &l))
      return NAV_ERR_INVALID_ARG;
    const size_t count = (size_t)(h->r1 - h->r0);
    for (int64_t m = 0; m < h->n_metrics; ++m)
      if (count > 0)
        memcpy(t->metrics + ((size_t)m * (size_t)t->runs + (size_t)h->r0) * (size_t)h->stats_per_run,
               b + l.metrics + (size_t)m * count * (size_t)h->stats_per_run * sizeof(double),
               count * (size_t)h->stats_per_run * sizeof(double));
    if (t->env && count > 0)
      memcpy(t->env + (size_t)h->r0 * (size_t)h->n_out * (size_t)h->env_values, b + l.env,
             count * (size_t)h->n_out * (size_t)h->env_values * sizeof(double));
    if (count > 0) memcpy(t->final + h->r0, b + l.final, count * sizeof(nav_epoch_errors));
    for (size_t i = 0; i < count; ++i) {
      int64_t sd, s;
      memcpy(&sd, b + l.samples + i * sizeof(int64_t), sizeof sd);
      memcpy(&s, b + l.status + i * sizeof(int64_t), sizeof s);
      t->samples_done[(size_t)h->r0 + i] = sd;
      t->status[(size_t)h->r0 + i] = (nav_status)s;
    }
    if (h->sm_per_run > 0 && count > 0) {
      for (int64_t m = 0; m < 2 * h->n_metrics; ++m)
        memcpy(t->sm_metrics + ((size_t)m * (size_t)t->runs + (size_t)h->r0) * (size_t)h->sm_per_run,
               b + l.sm + (size_t)m * count * (size_t)h->sm_per_run * sizeof(double),
               count * (size_t)h->sm_per_run * sizeof(double));
      memcpy(t->sm_bytes + h->r0, b + l.sm_bytes, count * sizeof(int64_t));
    }
    next = h->r1;
  }
  return next == t->runs ? NAV_OK : NAV_ERR_INVALID_ARG;
}

nav_status nav_sim_merge(nav_sim *sim, const nav_sim_options *opts, const nav_sim_partial *const *parts,
                         size_t count, nav_sim_summary *out) {
  if (!sim || !opts || !out || (!parts && count > 0)) return NAV_ERR_INVALID_ARG;
  for (size_t q = 0; q < count; ++q)
    if (!parts[q]) return NAV_ERR_INVALID_ARG;
  put_ctx c = {parts, count};
  nav_sim_options o = *opts;
  o.record = NULL; /* no run is simulated */
  const nav_sim_range_hook hook = {true, 0, 0, true, put_rows, &c};
  nav_sim_set_range_hook(sim, &hook);
  const nav_status st = nav_sim_run(sim, &o, out);
  nav_sim_set_range_hook(sim, NULL);
  if (st == NAV_ERR_INVALID_ARG && nav_sim_last_error(sim)[0] == '\0')
    nav_sim_set_error(sim, "partial results do not tile the runs of this scene in order (or come from another scene)");
  return st;
}
