/* navsim select and navsim sweep: the design loop over catalog parts and scene parameters
 * (select_cmd.c, sweep_cmd.c). */
#ifndef NAVSIM_SELECT_CMD_H
#define NAVSIM_SELECT_CMD_H

#include "navcore/nav_requirements.h"
#include "navcore/nav_scene.h"

/** Run `navsim select ARGS`; returns the process exit code. */
int navsim_select(int argc, char **argv);

/**
 * nav_req_predict_scene() of @p sc for screening: the quantile statistics (p95, cep50, cep95)
 * from at most 150 evenly spaced output epochs (their mixture CDF costs a quadrature per epoch
 * and bisection step), the others from every epoch. @p out: sc->n_requirements verdicts.
 */
nav_status navsim_predict_requirements(const nav_scene *sc, nav_requirement_verdict *out);

/** Run `navsim sweep ARGS`; returns the process exit code. */
int navsim_sweep(int argc, char **argv);

#endif /* NAVSIM_SELECT_CMD_H */
