/* Private to navcore's sim module. */
#ifndef NAV_SIM_INTERNAL_H
#define NAV_SIM_INTERNAL_H

#include "navcore/nav_sim.h"

/** Set the message returned by nav_sim_last_error(). */
void nav_sim_set_error(nav_sim *sim, const char *msg);

#endif /* NAV_SIM_INTERNAL_H */
