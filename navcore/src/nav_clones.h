/*
 * NAV_HOT_CLONES: compile a hot numerical kernel twice, for the x86-64 baseline (SSE2) and for
 * AVX2, and let the loader pick the variant for the CPU once (GCC function multi-versioning through
 * an ifunc; calls cost one indirect jump).
 *
 * The two variants give bit-identical results (style.md section 7): the AVX2 variant executes the
 * same IEEE double operations in the same order - no FMA (the "avx2" target does not enable it,
 * and navcore is built with -ffp-contract=off), no reassociation (no -ffast-math) - it only has
 * three-operand VEX encodings (fewer register copies and spills) and wider moves. libm is shared.
 * Measured: the WGS-84 NED mechanization step takes 17 % fewer instructions, the ideal IMU of the
 * parametric trajectory 18 % fewer.
 *
 * Only a function that carries the attribute is cloned: the static helpers it calls must be inlined
 * into it (always_inline) to run in the AVX2 variant. Off for other compilers and targets, in
 * sanitizer builds (the ifunc resolver runs before the sanitizer runtime is set up) and with
 * -DNAV_NO_CLONES (a build with it gives the same bits: checked on the mechanization and the ideal
 * IMU, every configuration of test_mech's scenes and the long drive).
 */
#ifndef NAV_CLONES_H
#define NAV_CLONES_H

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__) &&                 \
    !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__) && !defined(NAV_NO_CLONES)
#define NAV_HOT_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define NAV_HOT_CLONES
#endif

/* For the static helpers of a cloned kernel. */
#if defined(__GNUC__)
#define NAV_CLONE_INLINE static inline __attribute__((always_inline))
#else
#define NAV_CLONE_INLINE static inline
#endif

#endif /* NAV_CLONES_H */
