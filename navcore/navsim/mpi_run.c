/*
 * navsim run under MPI (Open MPI, toolchain.md section 9): `mpirun -np K navsim run SCENE --runs N`
 * gives rank q the runs [ceil(N q / K), ceil(N (q + 1) / K)); each rank simulates its share with its own
 * threads (hybrid ranks x threads) into a nav_sim_partial (navcore, no MPI inside), sends the
 * packed bytes to rank 0, and rank 0 merges them in run order (nav_sim_merge), which reduces the
 * same numbers in the same order as a threaded run: the results are bit-identical to
 * `navsim run SCENE --runs N` on one machine with the same seed, for any K and thread count.
 * Only rank 0 writes the result directory (atomically, as always).
 *
 * This file is compiled twice: into navsim without MPI (the functions below the #else), and into
 * the helper navsim-mpi with it; navsim started with more than one rank replaces itself by
 * navsim-mpi before anything else (navsim.c, exec_helper.h), so a process that is not part of a
 * campaign never loads the MPI libraries.
 *
 * Protocol: rank 0 broadcasts "go" (1) once its result directory is set up, or "stop" (0) when it
 * fails before; every other rank then sends rank 0 a message with the size of its packed partial
 * (or minus a status on failure), then the bytes in chunks of at most 1 GiB. Rank 0 receives every
 * message, even after a failure of its own share, so no rank is left blocked.
 *
 * Run observers (nav_sim_options.observer: the scene's requirements): when the scene has
 * requirements, each other rank also records the output-epoch errors its observer would have seen
 * per run and sends them (size, then bytes) after its partial; rank 0 replays them into its own
 * observer (begin, epochs, end per run, in run order), so the verdicts cover every run. The
 * requirement evaluator's result does not depend on the order runs are fed (per-run rows, sorted
 * quantile values), so they equal the threaded run's.
 */
#include "mpi_run.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "exec_helper.h"
#include "navcore/nav_requirements.h"
#include "navcore/nav_sim_partial.h"

#ifdef NAVSIM_HAVE_MPI
#include <mpi.h>

#define TAG_SIZE 901
#define TAG_DATA 902
#define TAG_OBS_SIZE 903
#define CHUNK_BYTES (1 << 30)

static bool g_active;   /* MPI initialised by us and not yet finalised */
static int g_rank, g_size = 1;

static bool mpi_start(void) {
  if (g_active) return true;
  if (!navsim_launched_with_ranks()) return false;
  int provided = 0;
  if (MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    fprintf(stderr, "navsim run: MPI_Init failed; running without MPI\n");
    return false;
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &g_rank);
  MPI_Comm_size(MPI_COMM_WORLD, &g_size);
  g_active = true;
  if (g_size < 2) {
    MPI_Finalize();
    g_active = false;
    g_size = 1;
    return false;
  }
  return true;
}

static void mpi_stop(void) {
  if (!g_active) return;
  MPI_Finalize();
  g_active = false;
}

/* Runs of rank q: [ceil(N q / K), ceil(N (q + 1) / K)). Rank 0 always has run 0 (the records of
 * run 0 are written there), even with more ranks than runs; a rank may have none. */
static void share(long runs, int rank, int size, long *r0, long *r1) {
  *r0 = (long)(((int64_t)runs * rank + size - 1) / size);
  *r1 = (long)(((int64_t)runs * (rank + 1) + size - 1) / size);
}

static void send_bytes(const void *bytes, size_t size) {
  const unsigned char *b = bytes;
  for (size_t off = 0; off < size; off += CHUNK_BYTES) {
    const size_t n = size - off < (size_t)CHUNK_BYTES ? size - off : (size_t)CHUNK_BYTES;
    MPI_Send(b + off, (int)n, MPI_BYTE, 0, TAG_DATA, MPI_COMM_WORLD);
  }
}

static void recv_bytes(void *bytes, size_t size, int from) {
  unsigned char *b = bytes;
  for (size_t off = 0; off < size; off += CHUNK_BYTES) {
    const size_t n = size - off < (size_t)CHUNK_BYTES ? size - off : (size_t)CHUNK_BYTES;
    MPI_Recv(b + off, (int)n, MPI_BYTE, from, TAG_DATA, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  }
}

/* ------------------------------------------------------------------ observed epochs */

/* Output-epoch errors of each run of a range, as an observer sees them (one slot per run, so the
 * threads of a rank never share one). */
typedef struct rec_run {
  nav_epoch_errors *e;
  size_t n, cap;
  int state; /* 0 not begun, 1 running or incomplete, 2 complete */
  bool oom;
} rec_run;

typedef struct recorder {
  long r0, r1;
  rec_run *runs;
} recorder;

static void *rec_begin(void *user, long run) {
  recorder *r = user;
  if (run < r->r0 || run >= r->r1) return NULL;
  rec_run *x = &r->runs[run - r->r0];
  x->state = 1;
  return x;
}

static void rec_epoch(void *ctx, const nav_epoch_errors *e) {
  rec_run *x = ctx;
  if (x->oom) return;
  if (x->n == x->cap) {
    const size_t nc = x->cap ? 2 * x->cap : 1024;
    nav_epoch_errors *g = realloc(x->e, nc * sizeof *g);
    if (!g) {
      x->oom = true;
      return;
    }
    x->e = g;
    x->cap = nc;
  }
  x->e[x->n++] = *e;
}

static void rec_end(void *user, void *ctx, bool complete) {
  (void)user;
  rec_run *x = ctx;
  if (complete && !x->oom) x->state = 2;
}

/* Packed: per run of the range, int64 count (-1: not complete) then the epochs. */
static unsigned char *rec_pack(const recorder *r, size_t *size) {
  size_t total = 0;
  for (long i = 0; i < r->r1 - r->r0; ++i)
    total += sizeof(int64_t) + (r->runs[i].state == 2 ? r->runs[i].n * sizeof(nav_epoch_errors) : 0);
  unsigned char *b = malloc(total ? total : 1);
  if (!b) return NULL;
  size_t off = 0;
  for (long i = 0; i < r->r1 - r->r0; ++i) {
    const rec_run *x = &r->runs[i];
    const int64_t n = x->state == 2 ? (int64_t)x->n : -1;
    memcpy(b + off, &n, sizeof n);
    off += sizeof n;
    if (n > 0) {
      memcpy(b + off, x->e, x->n * sizeof(nav_epoch_errors));
      off += x->n * sizeof(nav_epoch_errors);
    }
  }
  *size = total;
  return b;
}

/* Feed the packed epochs of runs [r0, r1) to @p obs, in run order; false when malformed. */
static bool rec_replay(const nav_run_observer *obs, long r0, long r1, const unsigned char *b, size_t size) {
  size_t off = 0;
  for (long run = r0; run < r1; ++run) {
    int64_t n;
    if (off + sizeof n > size) return false;
    memcpy(&n, b + off, sizeof n);
    off += sizeof n;
    if (n > 0 && (size - off) / sizeof(nav_epoch_errors) < (size_t)n) return false;
    void *ctx = obs->begin ? obs->begin(obs->user, run) : NULL;
    for (int64_t i = 0; i < n; ++i) {
      nav_epoch_errors e;
      memcpy(&e, b + off, sizeof e);
      off += sizeof e;
      if (ctx && obs->epoch) obs->epoch(ctx, &e);
    }
    if (ctx && obs->end) obs->end(obs->user, ctx, n >= 0);
  }
  return off == size;
}

bool navsim_mpi_worker(const nav_scene *scene, bool ideal, int threads, int *exit_code) {
  *exit_code = 0;
  if (!mpi_start() || g_rank == 0) return false;
  int go = 0;
  MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!go) {
    mpi_stop();
    *exit_code = 1;
    return true;
  }
  long r0, r1;
  share(ideal ? 1 : scene->simulation.runs, g_rank, g_size, &r0, &r1);
  nav_sim *sim = NULL;
  nav_sim_partial *part = NULL;
  /* The scene's requirements are evaluated on rank 0 by an observer: record its input here. */
  const bool observed = scene->n_requirements > 0;
  recorder rec = {r0, r1, NULL};
  nav_status st = NAV_OK;
  if (observed && r1 > r0) {
    rec.runs = calloc((size_t)(r1 - r0), sizeof *rec.runs);
    if (!rec.runs) st = NAV_ERR_NO_MEMORY;
  }
  if (st == NAV_OK) st = nav_sim_create(scene, &sim);
  if (st == NAV_OK && navsim_attach_gnss_file("run", scene, sim, NULL) != 0) st = NAV_ERR_PARSE;
  if (st == NAV_OK) {
    nav_sim_options o = nav_sim_options_default();
    o.ideal = ideal;
    o.threads = threads;
    nav_run_observer obs = {rec_begin, rec_epoch, rec_end, &rec};
    if (observed) o.observer = &obs;
    st = nav_sim_run_partial(sim, &o, r0, r1, &part);
    if (st != NAV_OK)
      fprintf(stderr, "navsim run: rank %d (runs %ld..%ld): %s\n", g_rank, r0, r1 - 1, nav_sim_last_error(sim));
  }
  size_t size = 0;
  const void *bytes = part ? nav_sim_partial_bytes(part, &size) : NULL;
  int64_t header = st == NAV_OK ? (int64_t)size : -(int64_t)(st == NAV_OK ? NAV_ERR_NO_MEMORY : st);
  MPI_Send(&header, 1, MPI_INT64_T, 0, TAG_SIZE, MPI_COMM_WORLD);
  if (header > 0) send_bytes(bytes, size);
  if (header > 0 && observed) {
    size_t osize = 0;
    unsigned char *ob = rec.runs || r1 == r0 ? rec_pack(&rec, &osize) : NULL;
    const int64_t oh = ob ? (int64_t)osize : -1;
    MPI_Send(&oh, 1, MPI_INT64_T, 0, TAG_OBS_SIZE, MPI_COMM_WORLD);
    if (oh > 0) send_bytes(ob, osize);
    free(ob);
  }
  if (rec.runs)
    for (long i = 0; i < r1 - r0; ++i) free(rec.runs[i].e);
  free(rec.runs);
  nav_sim_partial_destroy(part);
  nav_sim_destroy(sim);
  mpi_stop();
  *exit_code = st == NAV_OK ? 0 : 1;
  return true;
}

nav_status navsim_mpi_sim_run(nav_sim *sim, const nav_sim_options *opts, nav_sim_summary *out) {
  if (!g_active) return nav_sim_run(sim, opts, out);
  int go = 1;
  MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  const nav_scene *sc = nav_sim_scene(sim);
  long r0, r1;
  share(opts->ideal ? 1 : sc->simulation.runs, 0, g_size, &r0, &r1);
  nav_sim_partial **parts = calloc((size_t)g_size, sizeof *parts);
  nav_status st = parts ? nav_sim_run_partial(sim, opts, r0, r1, &parts[0]) : NAV_ERR_NO_MEMORY;
  nav_status st_other = NAV_OK;
  int failed_rank = -1;
  /* Receive every rank's message, whatever happened here, so that no rank stays blocked. */
  for (int q = 1; q < g_size; ++q) {
    int64_t header = 0;
    MPI_Recv(&header, 1, MPI_INT64_T, q, TAG_SIZE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (header <= 0) {
      if (st_other == NAV_OK) {
        st_other = header < 0 ? (nav_status)(-header) : NAV_ERR_IO;
        failed_rank = q;
      }
      continue;
    }
    void *buf = malloc((size_t)header);
    if (!buf) {
      fprintf(stderr, "navsim run: out of memory for the %lld bytes of rank %d\n", (long long)header, q);
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    recv_bytes(buf, (size_t)header, q);
    if (parts) {
      const nav_status us = nav_sim_partial_unpack(buf, (size_t)header, &parts[q]);
      if (us != NAV_OK && st_other == NAV_OK) {
        st_other = us;
        failed_rank = q;
      }
    }
    free(buf);
    if (sc->n_requirements > 0) {
      /* The epochs rank q's runs showed its observer: replayed into ours (the requirements). */
      int64_t oh = 0;
      MPI_Recv(&oh, 1, MPI_INT64_T, q, TAG_OBS_SIZE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      unsigned char *ob = oh > 0 ? malloc((size_t)oh) : NULL;
      if (oh > 0 && !ob) {
        fprintf(stderr, "navsim run: out of memory for the %lld observed bytes of rank %d\n", (long long)oh, q);
        MPI_Abort(MPI_COMM_WORLD, 1);
      }
      if (ob) recv_bytes(ob, (size_t)oh, q);
      long q0, q1;
      share(opts->ideal ? 1 : sc->simulation.runs, q, g_size, &q0, &q1);
      if (oh < 0 || (opts->observer && !rec_replay(opts->observer, q0, q1, ob, oh > 0 ? (size_t)oh : 0))) {
        if (st_other == NAV_OK) {
          st_other = NAV_ERR_IO;
          failed_rank = q;
        }
      }
      free(ob);
    }
  }
  mpi_stop();
  if (st == NAV_OK && st_other != NAV_OK) {
    /* The failing rank printed its message; the caller prints nav_sim_last_error (empty here). */
    fprintf(stderr, "navsim run: rank %d failed (%s)\n", failed_rank, nav_status_str(st_other));
    st = st_other;
  }
  if (st == NAV_OK) st = nav_sim_merge(sim, opts, (const nav_sim_partial *const *)parts, (size_t)g_size, out);
  if (parts)
    for (int q = 0; q < g_size; ++q) nav_sim_partial_destroy(parts[q]);
  free(parts);
  return st;
}

void navsim_mpi_abandon(void) {
  if (!g_active) return;
  if (g_rank == 0) {
    int go = 0;
    MPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  }
  mpi_stop();
}

int navsim_mpi_ranks(void) { return g_size; }

#else /* !NAVSIM_HAVE_MPI */

bool navsim_mpi_worker(const nav_scene *scene, bool ideal, int threads, int *exit_code) {
  (void)scene;
  (void)ideal;
  (void)threads;
  *exit_code = 0;
  return false;
}

nav_status navsim_mpi_sim_run(nav_sim *sim, const nav_sim_options *opts, nav_sim_summary *out) {
  return nav_sim_run(sim, opts, out);
}

void navsim_mpi_abandon(void) {}

int navsim_mpi_ranks(void) { return 1; }

#endif
