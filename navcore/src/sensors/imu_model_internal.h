/*
 * The IMU error model, for navcore's own callers only.
 */
#ifndef NAV_IMU_MODEL_INTERNAL_H
#define NAV_IMU_MODEL_INTERNAL_H

#include "navcore/nav_sensors.h"

/*
 * From now on, nav_imu_model_apply() leaves the bias values of the bias state (the states, their
 * total and the interval means) to nav_imu_model_bias(), which forms them from the model when it
 * is called after a sample; k, t_s and the saturation fields are still written by every sample.
 * The values are the same either way; what changes is that a pointer returned by
 * nav_imu_model_bias() before a sample does not show that sample's bias values. For a caller
 * that never reads the bias state at a sample, as a simulation run: forming the values (six
 * divisions for the interval means, twelve sums) was about a tenth of nav_imu_model_apply.
 */
void nav_imu_model_defer_bias(nav_imu_model *model);

#endif /* NAV_IMU_MODEL_INTERNAL_H */
