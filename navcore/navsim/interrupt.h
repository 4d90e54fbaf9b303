/* navsim: SIGINT / SIGTERM during `navsim run` cancel the simulation, so the run stops at the
 * next sample and its temporary result directory is removed (no partial results). */
#ifndef NAVSIM_INTERRUPT_H
#define NAVSIM_INTERRUPT_H

#include "navcore/nav_sim.h"

/** Catch SIGINT and SIGTERM from now on; each cancels @p sim (may be NULL) and is remembered. */
void navsim_interrupt_arm(nav_sim *sim);
/** Restore the default actions; forget the simulation. */
void navsim_interrupt_disarm(void);
/** Forget the simulation but keep catching the signals until the process ends: once the results
 *  are in place a late SIGINT / SIGTERM changes nothing (exit status 0, not "killed"). */
void navsim_interrupt_detach(void);
/** The signal caught since navsim_interrupt_arm(), 0 if none. */
int navsim_interrupted(void);

#endif /* NAVSIM_INTERRUPT_H */
