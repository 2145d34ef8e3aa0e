/* AVX-512 kernel of the neighbour lists: 16 candidates of a cell range at a time (masked loads
 * for the tail), the module's distance test lane by lane (sub, mul, add in the scalar order,
 * each rounded: no FMA), hits counted by popcount or left-packed with a compress store. Integer
 * results, so identical to akp_grid_row_scalar. Compiled for GCC/Clang on x86-64 without
 * AK_NO_SIMD; selected at run time with __builtin_cpu_supports. */
#include "grid_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX512 __attribute__((target("avx512f")))

bool akp_grid_have_avx512(void) { return __builtin_cpu_supports("avx512f"); }

AKP_AVX512 size_t akp_grid_row_avx512(const float* x, const float* y, const float* z,
                                      const uint32_t* order, const akp_grid_range* ranges,
                                      uint32_t range_count, uint32_t self, float qx, float qy,
                                      float qz, float r2, uint32_t* out) {
    const __m512 vx = _mm512_set1_ps(qx), vy = _mm512_set1_ps(qy), vz = _mm512_set1_ps(qz);
    const __m512 vr2 = _mm512_set1_ps(r2);
    const __m512i iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512i vself = _mm512_set1_epi32((int)self);
    size_t count = 0;
    for (uint32_t r = 0; r < range_count; ++r) {
        for (uint32_t b = ranges[r].begin; b < ranges[r].end; b += 16) {
            const uint32_t left = ranges[r].end - b;
            const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
            const __m512 dx = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, x + b), vx);
            const __m512 dy = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, y + b), vy);
            const __m512 dz = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, z + b), vz);
            const __m512 d2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
                                            _mm512_mul_ps(dz, dz));
            __mmask16 hit = _mm512_mask_cmp_ps_mask(live, d2, vr2, _CMP_LT_OQ);
            hit &= (__mmask16)~_mm512_cmpeq_epi32_mask(_mm512_add_epi32(_mm512_set1_epi32((int)b), iota), vself);
            if (out) {
                const __m512i idx = _mm512_maskz_loadu_epi32(live, order + b);
                _mm512_mask_compressstoreu_epi32(out + count, hit, idx);
            }
            count += (size_t)__builtin_popcount((unsigned)hit);
        }
    }
    return count;
}
#else
bool akp_grid_have_avx512(void) { return false; }
size_t akp_grid_row_avx512(const float* x, const float* y, const float* z, const uint32_t* order,
                           const akp_grid_range* ranges, uint32_t range_count, uint32_t self,
                           float qx, float qy, float qz, float r2, uint32_t* out) {
    return akp_grid_row_scalar(x, y, z, order, ranges, range_count, self, qx, qy, qz, r2, out);
}
#endif
