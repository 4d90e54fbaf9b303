/*
 * Plausibility upper bounds of the sensor error terms a scene may give (scene_read.c tables).
 *
 * Why: the reader used to accept any finite non-negative value, so `navsim check` passed e.g. a
 * gyro ARW of 1e300 deg/sqrt(h) and `navsim run` then failed with "non-finite state at t =
 * 0.01 s". Each bound below is far above every real sensor, the worst consumer MEMS included, so
 * that it only stops typing mistakes and absurd values, never a real part: it is 17x to 1000x the
 * worst figure of resources/imu_catalog.csv and resources/gnss_receivers.csv (the catalog maxima
 * are quoted with each bound), above every value of the scenes in scenes/ and tests/data, and at
 * least 5x the extreme datasheet figures quoted (test_scene_read checks the library scenes and
 * every catalog row, written out key by key). Datasheet figures marked "from memory" were not
 * re-checked here; the margins are wide enough that their exact value does not matter.
 *
 * Bounds are in the datasheet unit of the key that carries them (the first spelling of each
 * quantity in scene_read.c); the other spellings get the same bound converted. Signed values
 * (the *_fixed keys) are bounded in magnitude. A bias instability B maps to a Gauss-Markov
 * sigma of up to B / 0.6648 (imu.bias_convention allan_peak, written back as bias_gm_sigma_*),
 * so its bound is half the bias bound and the sigma it produces stays within that.
 */
#ifndef NAV_IO_SCENE_BOUNDS_H
#define NAV_IO_SCENE_BOUNDS_H

/* ---- gyro */

/* Angle random walk [deg/sqrt(h)]. Catalog worst: 1 (Groves consumer-grade model), Bosch BMI088
 * 0.84; the noisiest MEMS rate gyros of the 2000s (Analog Devices ADXRS150, 0.05 deg/s/sqrt(Hz)
 * = 3 deg/sqrt(h), from memory) stay below 10. 100 deg/sqrt(h) is 1.7 deg/s/sqrt(Hz). */
#define NAV_SCENE_MAX_GYRO_ARW_DEG_PER_SQRT_H 100.0

/* Gyro bias, any term: turn-on sigma, fixed offset (magnitude), Gauss-Markov sigma [deg/h].
 * 100 deg/s. Catalog worst: turn-on 1 deg/s (BMI088), instability 200 deg/h (Groves consumer);
 * the largest zero-rate offsets of consumer parts are +-20 deg/s (InvenSense MPU-6050 ZRO
 * tolerance, from memory). */
#define NAV_SCENE_MAX_GYRO_BIAS_DEG_PER_H 360000.0
/* Bias instability B [deg/h]: half the bias bound (see the top of this file). */
#define NAV_SCENE_MAX_GYRO_BI_DEG_PER_H 180000.0

/* Rate random walk [deg/h/sqrt(h)]: the bias bound reached within one hour. Not in the catalogs;
 * library scenes use <= 0.5. */
#define NAV_SCENE_MAX_GYRO_RRW_DEG_PER_H_PER_SQRT_H 360000.0

/* g-sensitivity, sigma and fixed (magnitude) [deg/h/g]: 10 deg/s/g. MEMS rate gyros show up to
 * about 0.2 deg/s/g (720 deg/h/g; ADXRS150, from memory); library scenes use <= 30. */
#define NAV_SCENE_MAX_G_SENSITIVITY_DEG_PER_H_PER_G 36000.0

/* ---- accelerometer (also the gyro-free array's accelerometers) */

/* Velocity random walk [m/s/sqrt(h)]: 10 = 17 mg/sqrt(Hz). Catalog worst: 0.588 (Groves
 * consumer-grade model, 1 mg/sqrt(Hz)), BMI088 0.103 (175 ug/sqrt(Hz)). */
#define NAV_SCENE_MAX_ACCEL_VRW_M_PER_S_PER_SQRT_H 10.0

/* Accelerometer bias, any term: turn-on sigma, fixed offset (magnitude), Gauss-Markov sigma
 * [mg]: 1 g, as large as gravity itself. Catalog worst: turn-on 20 mg (BMI088), instability
 * 10 mg (Groves consumer); consumer zero-g offsets reach +-80 mg (MPU-6050 z axis, from
 * memory). */
#define NAV_SCENE_MAX_ACCEL_BIAS_MG 1000.0
/* Bias instability B [ug]: half the bias bound. */
#define NAV_SCENE_MAX_ACCEL_BI_UG 500000.0

/* Bias random walk [m/s^2/sqrt(h)]: about the bias bound (1 g) reached within one hour. Not in
 * the catalogs; library scenes use <= 0.001. */
#define NAV_SCENE_MAX_ACCEL_BIAS_RW_M_PER_S2_PER_SQRT_H 10.0

/* ---- both triads */

/* Scale factor, sigma and fixed (magnitude) [ppm]: 100 %, where the output may be zero or twice
 * the input (no longer a sensor). Catalog worst: 40000 (gyro) and 50000 (accel), the Groves
 * consumer-grade model; consumer parts specify +-3 % (MPU-6050 sensitivity tolerance, from
 * memory). */
#define NAV_SCENE_MAX_SCALE_FACTOR_PPM 1e6

/* Misalignment (cross-axis), sigma and fixed (magnitude) [mrad]: 0.1 rad (5.7 deg); the error
 * model is first order in these angles. Catalog worst: 1 mrad (STIM300); consumer parts specify
 * +-2 % cross-axis sensitivity (20 mrad; MPU-6050, from memory). */
#define NAV_SCENE_MAX_MISALIGNMENT_MRAD 100.0

/* ---- GNSS receiver */

/* Position error sigmas: Gauss-Markov, white and reported [m]. Catalog worst: 7.7 m vertical
 * (GPS SPS performance-standard bound); standalone GPS under Selective Availability (before May
 * 2000) was about 100 m horizontal (95 %). A 1 km sigma is an outlier, not a noise model. */
#define NAV_SCENE_MAX_GNSS_POSITION_SIGMA_M 1000.0

/* Velocity error sigmas: white and reported [m/s]. Catalog worst: 0.1 m/s (SPS spec bound);
 * Doppler velocity under heavy multipath is of order 1 m/s. */
#define NAV_SCENE_MAX_GNSS_VELOCITY_SIGMA_MPS 100.0

/* Output latency of a fix [s]. Receivers output a fix within 0.05-0.5 s of its epoch; library
 * scenes use <= 0.1 s. */
#define NAV_SCENE_MAX_GNSS_LATENCY_S 10.0

#endif /* NAV_IO_SCENE_BOUNDS_H */
