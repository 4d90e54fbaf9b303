/**
 * @file nav_rng.h
 * @brief Deterministic random streams: one reproducible stream per (seed, Monte Carlo run, stream id).
 *
 * Every random number in navcore comes from a ::nav_rng, a 32-byte value type that needs no
 * allocation and no global state. A stream is named by three 64-bit integers:
 *
 * - @c seed: the scene's seed;
 * - @c run: the Monte Carlo run index;
 * - @c stream: what the numbers are for: a sensor error term and an axis, composed by
 *   nav_rng_stream_id() from a ::nav_rng_stream_kind and a channel.
 *
 * nav_rng_init() computes the stream's state from the triple alone. The sequence is therefore the
 * same whatever the thread count, the order in which streams are created, or which other streams
 * exist; switching one sensor error term off leaves the realisations of the others unchanged
 * (numerics.md 2.1, test T2.6).
 *
 * @par Design choice: xoshiro256** keyed by a permutation of the triple
 * The generator is xoshiro256** (Blackman and Vigna, "Scrambled linear pseudorandom number
 * generators", ACM TOMS 47(4), 2021): period 2^256 - 1, 4 words of state, passes BigCrush and
 * PractRand, and costs a few ns per 64-bit word, so the Gaussian sampler below delivers well over
 * 10^8 deviates per second on one core. It is the generator the house style names
 * (style.md section 7). The counter-based alternative (Philox4x32-10) would add O(1) random access,
 * but is several times slower per word, and random access is of little use here because the Gaussian
 * sampler consumes a variable number of words per draw.
 *
 * The triple is turned into the starting state without any sequential seeding, which is what makes
 * streams independent of creation order:
 * 1. four round keys are the first four outputs of splitmix64 seeded with @c seed;
 * 2. (run, stream) goes through a 4-round Feistel network whose round function is the splitmix64
 *    mixer (a bijection of 64-bit words) added to the round key. A Feistel network is a permutation
 *    for any round function, so for one seed two different (run, stream) pairs always give two
 *    different 128-bit results;
 * 3. each 64-bit half is expanded by splitmix64 into two state words, as Vigna recommends for
 *    seeding xoshiro. The state is never all zero.
 *
 * Streams thus start at distinct, pseudo-randomly scattered points of the one 2^256 - 1 cycle. For
 * n streams of L draws each, the chance that any two overlap is below n^2 L / 2^256 (2^-126 for
 * 2^40 streams of 2^50 draws), so no jump-ahead function is needed; none is provided.
 *
 * @par Gaussian sampler: ziggurat
 * nav_rng_gauss() uses the 256-layer ziggurat of Marsaglia and Tsang (J. Stat. Softw. 5(8), 2000)
 * with the correction of Doornik (2005): the layer index (bits 0-7), the sign (bit 8) and the
 * 53-bit abscissa (bits 11-63) come from disjoint bits of one word. The tables are exact-area
 * layers computed offline at 60 digits (r = 3.6541528853610088, layer area v = 4.928673233974655e-3)
 * and stored as hexadecimal literals, so nothing is computed at start-up. Marsaglia's (1964) method
 * samples the tail beyond r. Box-Muller and the polar method call log() (and sin/cos) for every
 * value; the ziggurat returns 98.8 % of its values after one multiplication and one comparison.
 *
 * @par What is bit-identical across platforms
 * - nav_rng_init(), nav_rng_next_u64() and nav_rng_uniform() use integer arithmetic and one exact
 *   conversion: identical on every conforming C11 implementation.
 * - nav_rng_gauss(): the rectangle path (98.8 % of values) is one IEEE-754 multiplication;
 *   the wedge path (1.2 %) calls exp() only to accept or reject, so a different libm changes the
 *   result only when a candidate lies within an ulp of the density curve; the tail path (2.6e-4 of
 *   values) returns r + a, with a computed by log(), so values there may differ in the last bits
 *   between libm implementations. Assumes IEEE-754 binary64 with FLT_EVAL_METHOD == 0 (SSE2 on
 *   x86) and no FMA contraction; navcore builds with -ffp-contract=off and never with -ffast-math.
 *
 * @par Thread safety
 * A ::nav_rng carries no pointers and no shared state: each object may be used by one thread at a
 * time, and different objects on different threads need no synchronisation. Copying a ::nav_rng
 * copies the stream position: the copy replays the same numbers.
 *
 * @par Example: white gyro noise, one stream per axis (numerics.md 2.2)
 * @code
 * nav_rng gyro_noise[3];
 * for (unsigned axis = 0; axis < 3; ++axis)
 *   nav_rng_init(&gyro_noise[axis], seed, run, nav_rng_stream_id(NAV_RNG_STREAM_GYRO_NOISE, axis));
 * // per sample k, with sigma_rps = N_g / sqrt(dt_s):
 * w_ib_b_rps.x += sigma_rps * nav_rng_gauss(&gyro_noise[0]);
 * @endcode
 */
#ifndef NAV_RNG_H
#define NAV_RNG_H

#include <assert.h>
#include <stdint.h>

#include "nav_export.h"
#include "nav_math.h"

NAV_BEGIN_DECLS

/**
 * The state of one random stream (xoshiro256**). A plain value: create it on the stack or inside
 * another object, initialise it with nav_rng_init(), copy it to replay. Treat @c s as private;
 * it is public only so the type has a known size.
 */
typedef struct nav_rng {
  uint64_t s[4]; /**< xoshiro256** state; never all zero after nav_rng_init() */
} nav_rng;

/**
 * What a stream is used for. The stream id is (kind << 8) | channel; see nav_rng_stream_id().
 *
 * The values are part of the reproducibility contract: changing one changes every simulation result
 * that uses it. They are frozen; add new kinds with new values, never renumber. Kinds are grouped
 * in blocks of 16 with room to grow; 0 is reserved.
 *
 * Channel conventions: an axis index 0, 1, 2 (x, y, z of the sensor frame, or N, E, D for GNSS
 * and initial errors) for per-axis terms; 3 * row + col for matrix elements (misalignment,
 * g-sensitivity); the accelerometer index for a distributed accelerometer array (gyro-free INS).
 */
typedef enum nav_rng_stream_kind {
  /* Gyroscope error terms (numerics.md 2.1-2.4). */
  NAV_RNG_STREAM_GYRO_NOISE = 0x01,         /**< white rate noise (ARW), drawn per sample */
  NAV_RNG_STREAM_GYRO_BIAS_TURN_ON = 0x02,  /**< turn-on bias b_0, drawn once per run */
  NAV_RNG_STREAM_GYRO_BIAS_GM = 0x03,       /**< Gauss-Markov bias: initial value, driving noise */
  NAV_RNG_STREAM_GYRO_BIAS_RW = 0x04,       /**< rate random walk driving noise */
  NAV_RNG_STREAM_GYRO_SCALE_FACTOR = 0x05,  /**< scale-factor error, drawn once per run */
  NAV_RNG_STREAM_GYRO_MISALIGNMENT = 0x06,  /**< misalignment m_ij, once per run; channel 3i+j */
  NAV_RNG_STREAM_GYRO_G_SENSITIVITY = 0x07, /**< g-sensitivity G_g, once per run; channel 3i+j */
  /* Accelerometer error terms; also the accelerometers of a gyro-free array. */
  NAV_RNG_STREAM_ACCEL_NOISE = 0x11,        /**< white acceleration noise (VRW), per sample */
  NAV_RNG_STREAM_ACCEL_BIAS_TURN_ON = 0x12, /**< turn-on bias b_0, drawn once per run */
  NAV_RNG_STREAM_ACCEL_BIAS_GM = 0x13,      /**< Gauss-Markov bias: initial value, driving noise */
  NAV_RNG_STREAM_ACCEL_BIAS_RW = 0x14,      /**< acceleration random walk driving noise */
  NAV_RNG_STREAM_ACCEL_SCALE_FACTOR = 0x15, /**< scale-factor error, drawn once per run */
  NAV_RNG_STREAM_ACCEL_MISALIGNMENT = 0x16, /**< misalignment m_ij, once per run; channel 3i+j */
  /* GNSS receiver errors (numerics.md section 7, receiver models). */
  NAV_RNG_STREAM_GNSS_POS = 0x21, /**< position error (white or Gauss-Markov), channel N/E/D */
  NAV_RNG_STREAM_GNSS_VEL = 0x22, /**< white velocity error, channel N/E/D */
  /* Initial navigation errors, drawn once per run. */
  NAV_RNG_STREAM_INIT_POS = 0x31, /**< initial position error, channel N/E/D */
  NAV_RNG_STREAM_INIT_VEL = 0x32, /**< initial velocity error, channel N/E/D */
  NAV_RNG_STREAM_INIT_ATT = 0x33, /**< initial attitude error, channel x/y/z of the rotation vector */
  /* Raw GNSS measurements of the tightly coupled scheme (docs/ins-gnss-tight.md 2). */
  NAV_RNG_STREAM_GNSS_CLOCK = 0x41,   /**< receiver clock: channel 0 initial bias and drift, 1 driving noise */
  NAV_RNG_STREAM_GNSS_CODE = 0x42,    /**< white pseudorange noise, channel = satellite index */
  NAV_RNG_STREAM_GNSS_DOPPLER = 0x43, /**< white range-rate noise, channel = satellite index */
  NAV_RNG_STREAM_GNSS_ISB = 0x44,     /**< GLONASS inter-system bias, channel 0, once per run */
  /** First kind free for applications and tests; navcore never uses kinds at or above it. */
  NAV_RNG_STREAM_USER = 0x1000
} nav_rng_stream_kind;

/** Number of channels per stream kind: channels are 0 .. NAV_RNG_CHANNELS - 1. */
#define NAV_RNG_CHANNELS 256u

/**
 * Composes a stream id from a kind and a channel: (kind << 8) | channel.
 *
 * @param[in] kind    what the stream is for.
 * @param[in] channel axis, matrix element or array index, in [0, NAV_RNG_CHANNELS). A larger
 *                    channel would alias another kind's stream: it triggers assert in debug builds.
 * @return the stream id for nav_rng_init(). Thread-safe, pure.
 */
static inline uint64_t nav_rng_stream_id(nav_rng_stream_kind kind, unsigned channel) {
  assert(channel < NAV_RNG_CHANNELS);
  return ((uint64_t)kind << 8) | (uint64_t)channel;
}

/**
 * Starts the stream named by (seed, run, stream).
 *
 * The state depends on the triple only, never on earlier calls: initialising the same triple
 * again restarts the identical sequence, in any thread and in any order. For a fixed seed,
 * different (run, stream) pairs always get different starting states.
 *
 * @param[out] r      the stream; must not be NULL. Any previous content is overwritten.
 * @param[in]  seed   the scene's seed (any value, 0 included).
 * @param[in]  run    the Monte Carlo run index (any value).
 * @param[in]  stream the stream id, normally from nav_rng_stream_id() (any value).
 */
NAV_API void nav_rng_init(nav_rng *r, uint64_t seed, uint64_t run, uint64_t stream);

/**
 * Next 64 uniformly distributed random bits (one xoshiro256** step).
 *
 * @param[in,out] r an initialised stream; must not be NULL.
 * @return 64 random bits; every bit is usable.
 */
NAV_API uint64_t nav_rng_next_u64(nav_rng *r);

/**
 * Uniform double in the open interval (0, 1).
 *
 * The value is k / 2^53 with k uniform in [1, 2^53 - 1] (53 random bits): never 0, never 1, safe
 * to pass to log(), and symmetric about 1/2 (1 - u has the same distribution, exactly). The
 * smallest value is 2^-53 = 1.1e-16, the largest 1 - 2^-53.
 *
 * @param[in,out] r an initialised stream; must not be NULL.
 * @return u in (0, 1). Consumes one word (two with probability 2^-53, when k would be 0).
 */
NAV_API double nav_rng_uniform(nav_rng *r);

/**
 * Standard normal deviate N(0, 1) by the ziggurat method (see the file description).
 *
 * @param[in,out] r an initialised stream; must not be NULL.
 * @return a finite value with mean 0 and variance 1; |x| < 12.3 (the tail method's bound with
 *         53-bit uniforms). Consumes one word
 *         for 98.8 % of values, more on the wedge (1.2 %) and tail (2.6e-4) paths.
 */
NAV_API double nav_rng_gauss(nav_rng *r);

/**
 * Three independent standard normal deviates, drawn in the order x, y, z from one stream.
 *
 * Equivalent to three calls of nav_rng_gauss(). Use it for terms drawn together (for example a
 * random rotation vector); terms that must switch on and off independently per axis need one
 * stream per axis instead (numerics.md 2.1).
 *
 * @param[in,out] r an initialised stream; must not be NULL.
 * @return (x, y, z), each N(0, 1); unitless.
 */
NAV_API nav_vec3 nav_rng_gauss_vec3(nav_rng *r);

NAV_END_DECLS

#endif /* NAV_RNG_H */
