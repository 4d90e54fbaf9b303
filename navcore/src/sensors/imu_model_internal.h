/*
 * The IMU error model, for navcore's own callers only.
 */
#ifndef NAV_IMU_MODEL_INTERNAL_H
#define NAV_IMU_MODEL_INTERNAL_H

#include <stdbool.h>

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

/*
 * Four models stepped together, one per vector lane (the Monte Carlo runs that go in lockstep,
 * sim.c run_group()). nav_imu_lanes_open() takes the per-sample state of four deferring models
 * (nav_imu_model_defer_bias) of one configuration (the same terms and the same noise, bias and
 * range parameters; the per-run draws, turn-on biases, scale factors, misalignments and the
 * random streams, may differ) into a structure of arrays: lane l of every value is model l's, and
 * the streams of an axis stand side by side, so that one vector draw gives a deviate to each of
 * the four runs instead of to the three axes of one. nav_imu_lanes_apply() then does for one
 * shared ideal sample what nav_imu_model_apply() does for each model, with each lane computing
 * the scalar operations in the scalar order (the same bits, the same words drawn from each
 * stream). nav_imu_lanes_close() writes the state back into the four models, with the bias
 * state's k, t_s and saturation fields as the samples left them, and releases the lanes; the
 * models can then go on alone.
 */
typedef struct nav_imu_lanes nav_imu_lanes;

/* NULL when the four models cannot go in lockstep (not deferring, ideal, configurations that
 * differ) or on a failed allocation; the models are untouched then. */
nav_imu_lanes *nav_imu_lanes_open(nav_imu_model *const models[4]);

/* One sample for the four models. false, with nothing changed, when the ideal record is one
 * nav_imu_model_apply() refuses (dt not finite and > 0, a non-finite increment): close the lanes
 * and apply the models one by one for their error messages. */
bool nav_imu_lanes_apply(nav_imu_lanes *lanes, const nav_imu_increment *ideal,
                         nav_imu_increment *const measured[4]);

/* Write the lanes back into their models and free them (NULL: nothing). */
void nav_imu_lanes_close(nav_imu_lanes *lanes);

#endif /* NAV_IMU_MODEL_INTERNAL_H */
