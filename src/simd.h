/* The one place where animkit picks its SIMD instruction set, at compile time.
 *
 * AK_SIMD_SSE2 is 1 when the compiler targets SSE2 (__SSE2__, always on x86-64) and
 * AK_NO_SIMD is not defined; otherwise every kernel uses its scalar reference loop.
 * AK_SIMD_NAME names the choice for benchmarks and logs. Kernels load and store unaligned
 * (public functions accept any float-aligned pointer). Never installed. */
#ifndef ANIMKIT_SIMD_H
#define ANIMKIT_SIMD_H

#if defined(__SSE2__) && !defined(AK_NO_SIMD)
#define AK_SIMD_SSE2 1
#define AK_SIMD_NAME "sse2"
#include <emmintrin.h>

/* Lane-wise select: mask ? a : b (mask lanes all ones or all zeros). */
static inline __m128 akp_simd_select(__m128 mask, __m128 a, __m128 b) {
    return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
/* The same lane of v in all four lanes. */
#define AKP_SIMD_SPLAT(v, lane) _mm_shuffle_ps((v), (v), _MM_SHUFFLE(lane, lane, lane, lane))

/* Four (x, y, z, w) records in r0..r3 -> lanes x, y, z, w of four records each (in place). */
#define AKP_SIMD_TRANSPOSE4(r0, r1, r2, r3) _MM_TRANSPOSE4_PS(r0, r1, r2, r3)

/* Four packed vec3 (12 floats at p, unaligned) -> x, y, z lanes. */
static inline void akp_simd_load_vec3x4(const float* p, __m128* x, __m128* y, __m128* z) {
    __m128 a = _mm_loadu_ps(p), b = _mm_loadu_ps(p + 4), c = _mm_loadu_ps(p + 8);
    /* a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3 */
    __m128 bc = _mm_shuffle_ps(b, c, _MM_SHUFFLE(1, 0, 3, 2));               /* x2 y2 z2 x3 */
    *x = _mm_shuffle_ps(a, bc, _MM_SHUFFLE(3, 0, 3, 0));                      /* x0 x1 x2 x3 */
    __m128 ab = _mm_shuffle_ps(a, b, _MM_SHUFFLE(0, 0, 1, 1));               /* y0 y0 y1 y1 */
    __m128 bc2 = _mm_shuffle_ps(b, c, _MM_SHUFFLE(2, 2, 3, 3));              /* y2 y2 y3 y3 */
    *y = _mm_shuffle_ps(ab, bc2, _MM_SHUFFLE(2, 0, 2, 0));
    __m128 ab2 = _mm_shuffle_ps(a, b, _MM_SHUFFLE(1, 1, 2, 2));              /* z0 z0 z1 z1 */
    __m128 cc = _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 3, 0, 0));               /* z2 z2 z3 z3 */
    *z = _mm_shuffle_ps(ab2, cc, _MM_SHUFFLE(2, 0, 2, 0));
}

/* x, y, z lanes -> four packed vec3 (12 floats at p, unaligned). */
static inline void akp_simd_store_vec3x4(float* p, __m128 x, __m128 y, __m128 z) {
    __m128 xy0 = _mm_shuffle_ps(x, y, _MM_SHUFFLE(0, 0, 0, 0));  /* x0 x0 y0 y0 */
    __m128 zx0 = _mm_shuffle_ps(z, x, _MM_SHUFFLE(1, 1, 0, 0));  /* z0 z0 x1 x1 */
    __m128 yz1 = _mm_shuffle_ps(y, z, _MM_SHUFFLE(1, 1, 1, 1));  /* y1 y1 z1 z1 */
    __m128 xy2 = _mm_shuffle_ps(x, y, _MM_SHUFFLE(2, 2, 2, 2));  /* x2 x2 y2 y2 */
    __m128 zx3 = _mm_shuffle_ps(z, x, _MM_SHUFFLE(3, 3, 2, 2));  /* z2 z2 x3 x3 */
    __m128 yz3 = _mm_shuffle_ps(y, z, _MM_SHUFFLE(3, 3, 3, 3));  /* y3 y3 z3 z3 */
    _mm_storeu_ps(p, _mm_shuffle_ps(xy0, zx0, _MM_SHUFFLE(2, 0, 2, 0)));
    _mm_storeu_ps(p + 4, _mm_shuffle_ps(yz1, xy2, _MM_SHUFFLE(2, 0, 2, 0)));
    _mm_storeu_ps(p + 8, _mm_shuffle_ps(zx3, yz3, _MM_SHUFFLE(2, 0, 2, 0)));
}
#else
#define AK_SIMD_SSE2 0
#define AK_SIMD_NAME "scalar"
#endif

#endif
