/* Private to navcore: the budget's covariance pass (budget.c), also used for predictions. */
#ifndef NAV_BUDGET_INTERNAL_H
#define NAV_BUDGET_INTERNAL_H

#include <stdbool.h>

#include "navcore/nav_budget.h"

/**
 * nav_budget_covariance(); with @p sources false only the total is propagated (the error
 * covariance of the navigation filter plus the scale-factor consider states: the prediction of
 * nav_req_predict_scene), and the sources of the epochs are zero.
 */
nav_status nav_budget_run(const nav_scene *sc, bool sources, nav_budget_fn fn, void *user, unsigned *active,
                          char *msg, size_t msg_size);

#endif /* NAV_BUDGET_INTERNAL_H */
