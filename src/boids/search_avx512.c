/* AVX-512 distance filter of the boids grid path: 16 candidates per instruction, the row's tail
 * through masked loads (no read past the row), hits packed with compress into registers.
 * The same operations in the same order as the scalar test ((x - px)^2 + (y - py)^2, then
 * + (z - pz)^2, each rounded; no FMA), so the same d2 bits and the same hits.
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports (search.c falls back to its SSE2/scalar loop). */
#include "boids_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

bool akp_boids_have_avx512(void) { return __builtin_cpu_supports("avx512f"); }

__attribute__((target("avx512f"))) uint32_t akp_boids_filter_avx512(const float* X, const float* Y, const float* Z,
                                                                   uint32_t begin, uint32_t end, ak_vec3 p, float q2,
                                                                   uint32_t* hk, float* hd) {
    const __m512 vx = _mm512_set1_ps(p.x), vy = _mm512_set1_ps(p.y), vz = _mm512_set1_ps(p.z);
    const __m512 vq = _mm512_set1_ps(q2);
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    uint32_t h = 0;
    for (uint32_t t = begin; t < end; t += 16) {
        const uint32_t left = end - t;
        const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
        const __m512 dx = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, X + t), vx);
        const __m512 dy = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, Y + t), vy);
        const __m512 dz = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, Z + t), vz);
        const __m512 dd = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
        const __mmask16 m = _mm512_mask_cmp_ps_mask(live, dd, vq, _CMP_LT_OQ);
        if (!m) continue;
        const __m512i k = _mm512_add_epi32(_mm512_set1_epi32((int)t), lane);
        _mm512_storeu_si512((void*)(hk + h), _mm512_maskz_compress_epi32(m, k));
        _mm512_storeu_ps(hd + h, _mm512_maskz_compress_ps(m, dd));
        h += (uint32_t)__builtin_popcount(m);
    }
    return h;
}

#else
bool akp_boids_have_avx512(void) { return false; }

uint32_t akp_boids_filter_avx512(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end, ak_vec3 p,
                                 float q2, uint32_t* hk, float* hd) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)p, (void)q2, (void)hk, (void)hd;
    return 0;
}
#endif
