/* navsim run under MPI: the Monte Carlo runs split across ranks (see mpi_run.c). */
#ifndef NAVSIM_MPI_RUN_H
#define NAVSIM_MPI_RUN_H

#include <stdbool.h>

#include "navcore/nav_scene.h"
#include "navcore/nav_sim.h"

/**
 * Call once the scene and the options of `navsim run` are final. When navsim was started by
 * mpirun with more than one rank (and built with NAV_MPI), MPI is initialised; on every rank but
 * 0 this runs the rank's share of the runs, sends it to rank 0, finalises MPI and returns true
 * with *exit_code set (the caller returns it). Returns false on rank 0 and without MPI.
 */
bool navsim_mpi_worker(const nav_scene *scene, bool ideal, int threads, int *exit_code);

/**
 * nav_sim_run over every rank: runs [0, share) here (records and progress as usual), the other
 * ranks' partials merged in run order; bit-identical to nav_sim_run. Without MPI: nav_sim_run.
 * Finalises MPI.
 */
nav_status navsim_mpi_sim_run(nav_sim *sim, const nav_sim_options *opts, nav_sim_summary *out);

/** Rank 0 stops before navsim_mpi_sim_run: release the other ranks and finalise (else no-op). */
void navsim_mpi_abandon(void);

/** Ranks of the campaign (1 without MPI). */
int navsim_mpi_ranks(void);

#endif /* NAVSIM_MPI_RUN_H */
