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

/* Fix rate [Hz]. Receivers output 1-20 Hz, the fastest (high-end geodetic and RTK receivers) 100
 * Hz; catalog worst (fastest) 10 Hz (RTK fixed), library scenes use <= 5 Hz. 1000 Hz is 10x the
 * fastest receiver; beyond it a run only multiplies the filter's updates (1e5 Hz over the urban
 * drive did not finish in 200 s, 1e9 Hz made the filter fail). */
#define NAV_SCENE_MAX_GNSS_RATE_HZ 1000.0

/* Antenna lever arm, each body-axis component in magnitude [m]. Library scenes use <= 1.2 m;
 * the largest vehicles are about 400 m long (container ships), so no antenna sits 1 km from its
 * IMU. A lever arm of 1e300 m made the innovation covariance non-finite in the first update. */
#define NAV_SCENE_MAX_LEVER_ARM_M 1000.0

/* ---- initial errors (1-sigma, per axis) */

/* Position [m]: 100 km (0.9 deg of latitude). Library scenes use <= 5 m; a cold-start fix, a
 * cell-tower position or a city name already give better than 10 km. Beyond, the errors are a
 * sizeable part of the Earth radius (1e7 m moved the start by about 90 deg of latitude) and the
 * linear error model of the filter no longer holds. */
#define NAV_SCENE_MAX_INITIAL_POSITION_SD_M 1.0e5

/* Velocity [m/s]. Library scenes use <= 0.2 m/s; an in-motion start without any velocity aid is
 * known to the vehicle's speed, of order 10-100 m/s. 1e20 m/s moved the start off the Earth in
 * the first step. */
#define NAV_SCENE_MAX_INITIAL_VELOCITY_SD_MPS 1000.0

/* Tilt, about north and east [deg]: levelling from the accelerometers gives roll and pitch to
 * asin(b / g) of a bias b, and the accelerometer bias bound (1 g) gives 90 deg; library scenes use
 * <= 1 deg. */
#define NAV_SCENE_MAX_INITIAL_TILT_SD_DEG 90.0

/* Heading, about down [deg]: 180 deg is a heading not known at all (a uniform heading has a sigma
 * of 104 deg, and errors wrap at +-180 deg); the filter's hard cases start from it
 * (test_filter_hard); library scenes use <= 10 deg. */
#define NAV_SCENE_MAX_INITIAL_HEADING_SD_DEG 180.0

/* Initial angular-rate error of the gyro-free array [deg/s]: the gyro bias bound (100 deg/s). */
#define NAV_SCENE_MAX_INITIAL_RATE_SD_DPS 100.0

/* ---- trajectory */

/* Speeds of a trajectory, in magnitude [m/s]: the start velocity of segment scripts and of the
 * parametric trajectory (each component), the target speed of accelerate segments and the speeds
 * of the polar great-circle and vertical-loop test motions. The bound of waypoint speeds
 * (nav_scene_validate: [0, 1e5] m/s), about 9x the Earth's escape speed; library scenes use
 * <= 250 m/s. */
#define NAV_SCENE_MAX_SPEED_MPS 1.0e5

/* ---- catalogs (resources/imu_catalog.csv, resources/gnss_receivers.csv; catalog.c) */

/* Correlation time of a Gauss-Markov bias or of GNSS position errors [s]: 1e7 s (116 days).
 * Catalog worst 7200 s / 0.6648 (navigation-grade Allan minimum); a process correlated over more
 * than a quarter year is a constant, stated as a turn-on bias. */
#define NAV_SCENE_MAX_CORRELATION_TIME_S 1.0e7

#endif /* NAV_IO_SCENE_BOUNDS_H */
