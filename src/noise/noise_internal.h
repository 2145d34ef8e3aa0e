/* Internals shared by the noise files (never installed). */
#ifndef ANIMKIT_NOISE_INTERNAL_H
#define ANIMKIT_NOISE_INTERNAL_H

#include <math.h>
#include <string.h>
#if defined(__SSE__) || defined(__x86_64__)
#include <xmmintrin.h>
#endif

#include <animkit/noise.h>

/* Coordinates at or beyond this magnitude (and NaN) give 0: their floor would not fit the
 * integer lattice arithmetic, and floats there have no fractional part anyway. */
#define AKP_NOISE_LIMIT 16777216.0f

/* t > 0 ? t : +0.0f as one maxss on x86 (gcc compiles the ?: of a float to a branch, which
 * random points mispredict); the same value either way, NaN included (maxss returns its second
 * operand, +0.0, when the comparison is false). */
static inline float akp_max0(float t) {
#if defined(__SSE__) || defined(__x86_64__)
    return _mm_cvtss_f32(_mm_max_ss(_mm_set_ss(t), _mm_setzero_ps()));
#else
    return t > 0.0f ? t : 0.0f;
#endif
}

/* akp_floor_unsigned_zero (below) on any CPU: truncate, convert back, step down where
 * truncation rounded up. */
static inline float akp_floor_trunc(float x, int* out_i) {
    const int t = (int)x;
    const float ft = (float)t;
    const int up = ft > x;
    *out_i = t - up;
    /* ft - 1 or ft - 0 (ft is never -0.0, so ft - 0 is ft) without a branch: random signs
     * would mispredict one */
    const uint32_t one_bits = (uint32_t)-up & 0x3F800000u;
    float one;
    memcpy(&one, &one_bits, sizeof one);
    return ft - one;
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(AK_NO_SIMD)
#define AKP_HAVE_FLOOR_ROUNDSS 1
/* The same with SSE4.1's roundss toward -inf (imm 9: round down, no inexact exception), only
 * on CPUs that have it: floorf's value, + 0.0f turns floorf(-0.0) into +0.0 as
 * akp_floor_trunc gives. Written as asm because the module is compiled for baseline x86-64;
 * the operand is both source and destination (roundss keeps the upper lanes of its
 * destination: no dependency on a stale register). */
static inline float akp_floor_roundss(float x, int* out_i) {
    float fl = x;
    __asm__("roundss $9, %0, %0" : "+x"(fl));
    fl = fl + 0.0f;
    *out_i = (int)fl;
    return fl;
}
#endif

/* akp_floor (below) without the sign step: floorf(x) except +0.0 for x = -0.0, for callers where that
 * zero's sign cannot reach the result (simplex: see simplex3_value). roundss where the CPU has
 * SSE4.1 (every x86-64 CPU since 2008; a cached CPUID bit, a branch that never mispredicts):
 * akp_floor_trunc's chain of truncation, conversion back, compare and subtract sat on every
 * lattice hash's path (per point: value 3D 1.43x -> 1.16x FastNoiseLite's time, Perlin 3D
 * 1.07x -> 0.88x; docs/BENCHMARKS.md, noise). */
static inline float akp_floor_unsigned_zero(float x, int* out_i) {
#ifdef AKP_HAVE_FLOOR_ROUNDSS
#ifndef __SSE4_1__
    if (__builtin_cpu_supports("sse4.1"))
#endif
        return akp_floor_roundss(x, out_i);
#endif
    return akp_floor_trunc(x, out_i);
}

/* floorf(x) and the same value as an int, for |x| < 2^31 (callers check AKP_NOISE_LIMIT first):
 * truncate, step down where truncation rounded up (negative non-integers), and take x's sign,
 * which only changes -0.0 (floorf(-0.0) is -0.0; the int conversion gives +0.0). The same
 * float as floorf bit for bit (test_noise floor_matches_libm, both variants), without the
 * rounding-mode branch gcc emits for floorf on baseline x86-64 (no SSE4.1 roundss). */
static inline float akp_floor(float x, int* out_i) { return copysignf(akp_floor_unsigned_zero(x, out_i), x); }

/* x - floorf(x) (the fraction in [0, 1)) and floorf(x) as an int, in one. The floor is taken
 * without its sign here: only x = -0.0 tells (-0.0 - +0.0 is -0.0 where x - floorf(x) is
 * +0.0), and adding +0.0 turns that -0.0 into +0.0 and changes no other value. */
static inline float akp_floor_frac(float x, int* out_i) {
#ifdef AKP_HAVE_FLOOR_ROUNDSS
#ifndef __SSE4_1__
    if (__builtin_cpu_supports("sse4.1"))
#endif
    {
        /* roundss keeps the sign of a zero: x = -0.0 gives fl = -0.0 and x - fl = +0.0, and no
         * other x gives a zero of either sign but +0.0 (x - fl is zero only where x == fl). So
         * the two + 0.0f of the general form change nothing here: two additions fewer on the
         * lattice hash's path. The int is the same ((int)-0.0f is 0). */
        float fl = x;
        __asm__("roundss $9, %0, %0" : "+x"(fl));
        *out_i = (int)fl;
        return x - fl;
    }
#endif
    return (x - akp_floor_unsigned_zero(x, out_i)) + 0.0f;
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(AK_NO_SIMD)
#define AKP_HAVE_VEX 1
/* Hot per-point bodies (value noise 2D/3D, fBm over value and Perlin noise) are compiled a
 * second time for CPUs with AVX and chosen at run time: VEX encoding (three-operand
 * arithmetic, none of the register copies before each operation), no FMA, so the same
 * roundings. Their floor is vroundss (every AVX CPU has SSE4.1): akp_floor_frac's roundss
 * branch, the same bits. */
#define AKP_VEX __attribute__((target("avx")))
static inline __attribute__((always_inline)) float akp_floor_frac_vex(float x, int* out_i) {
    float fl;
    __asm__("vroundss $9, %1, %1, %0" : "=x"(fl) : "x"(x));
    *out_i = (int)fl;
    return x - fl;
}
/* akp_floor_unsigned_zero's roundss branch in the VEX build */
static inline __attribute__((always_inline)) float akp_floor_unsigned_zero_vex(float x, int* out_i) {
    float fl;
    __asm__("vroundss $9, %1, %1, %0" : "=x"(fl) : "x"(x));
    fl = fl + 0.0f;
    *out_i = (int)fl;
    return fl;
}
#else
static inline float akp_floor_frac_vex(float x, int* out_i) { return akp_floor_frac(x, out_i); }
static inline float akp_floor_unsigned_zero_vex(float x, int* out_i) { return akp_floor_unsigned_zero(x, out_i); }
#endif

#if defined(__x86_64__) && defined(__GNUC__) && !defined(AK_NO_SIMD)
#define AKP_HAVE_POINT_AVX2 1
/* point_avx2.c, for CPUs with AVX2 (callers check): Worley F1's squared distance over rings 0
 * and 1 (the 3^dims cells around the point, dims 2 or 3), the cells side by side in the lanes;
 * bases.c's worley_f1_rings's d1 bit for bit (the same float operations per cell; a minimum
 * does not depend on the order). base: the point's cell, f: its offset in the cell. */
float akp_worley_d1_avx2(uint32_t dims, uint64_t seed, const int* base, const float* f);
#endif

/* The fBm octave sum without gradient or warp, for a resolved, valid desc of type FBM and a
 * dims the basis supports: octaves()'s loop (fractal.c) with the basis inlined, the same float
 * operations in the same order. Perlin in perlin.c, the other bases in bases.c. */
float akp_fbm_perlin(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p);
float akp_fbm_other(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p);
/* The same with the gradient, Perlin in 2D and 3D (dims 2 or 3). */
float akp_fbm_perlin_grad(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p,
                          float* grad);

/* ak_noise_value without gradient (dims 2 or 3, finite point) and akp_fbm_other over value
 * noise (dims 2 or 3) in the baseline x86-64 build, whatever the CPU: the bodies a CPU without
 * AVX runs, so that tests on any CPU can check them against the VEX build bit for bit. */
float akp_value_baseline(const ak_noise* noise, uint32_t dims, const float* p);
float akp_fbm_value_baseline(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p);
/* akp_fbm_perlin (dims 2 or 3) in the baseline x86-64 build, whatever the CPU (as above). */
float akp_fbm_perlin_baseline(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p);

/* Scalar reference of the batch kernels: one point of a resolved, valid fractal desc. */
float akp_fractal_point(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* p, float* grad);

/* True when the SIMD kernels handle this desc and dimension (Perlin, simplex, value and
 * Worley, 2D and 3D, without warp; the AVX2 and AVX-512 kernels handle the same set). */
bool akp_noise_simd_handles(const ak_fractal_desc* d, uint32_t dims);
/* CPU checks (false in builds without the kernels). */
bool akp_noise_have_avx2(void);
bool akp_noise_have_avx512(void);
bool akp_noise_have_avx512vbmi(void); /* AVX-512 F, DQ, BW and VBMI */
bool akp_noise_avx2_gather_preferred(void); /* AVX2 path: the gather build is the faster one here */
/* count % 8 == 0 (AVX2) or % 16 == 0 (AVX-512). xs[d] (d < dims) coordinates; grad[d] may all
 * be NULL (no gradient). */
void akp_noise_fractal_avx2(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                            size_t count, float* out, float* const* grad);
void akp_noise_fractal_avx512(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                              size_t count, float* out, float* const* grad);
/* The AVX2 kernel with vpgatherdd lookups (batch_avx2_gather.c); the same bits. */
void akp_noise_fractal_avx2gather(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims,
                                  const float* const* xs, size_t count, float* out, float* const* grad);
/* The same AVX-512 kernel with byte-permute lookups, for CPUs with akp_noise_have_avx512vbmi; the same bits. */
void akp_noise_fractal_avx512vbmi(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims,
                                  const float* const* xs, size_t count, float* out, float* const* grad);

#endif
