/* AVX-512 kernels of the grid: the neighbour lists (16 candidates of a cell range at a time)
 * and the all-pairs block (8 candidates at a time), masked loads for the tails, the module's
 * distance test lane by lane (sub, mul, add in the scalar order, each rounded: no FMA), hits
 * counted by popcount and left-packed with compress stores in candidate order. Integer results,
 * so identical to the scalar loops of grid.c. Compiled for GCC/Clang on x86-64 without
 * AK_NO_SIMD; selected at run time with __builtin_cpu_supports. */
#include "grid_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX512 __attribute__((target("avx512f,avx512vl")))

bool akp_grid_have_avx512(void) {
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl");
}

AKP_AVX512 size_t akp_grid_pairs_avx512(const float* x, const float* y, const float* z,
                                        const uint32_t* order, uint32_t a0, uint32_t a1,
                                        uint32_t b0, uint32_t b1, bool same, float r2,
                                        ak_grid_pair* out) {
    const __m256 vr2 = _mm256_set1_ps(r2);
    size_t count = 0;
    for (uint32_t a = a0; a < a1; ++a) {
        const __m256 ax = _mm256_set1_ps(x[a]), ay = _mm256_set1_ps(y[a]), az = _mm256_set1_ps(z[a]);
        const __m256i oa = _mm256_set1_epi32((int)order[a]);
        for (uint32_t b = same ? a + 1 : b0; b < b1; b += 8) {
            const uint32_t left = b1 - b;
            const __mmask8 live = left >= 8 ? (__mmask8)0xFF : (__mmask8)((1u << left) - 1u);
            const __m256 dx = _mm256_sub_ps(_mm256_maskz_loadu_ps(live, x + b), ax);
            const __m256 dy = _mm256_sub_ps(_mm256_maskz_loadu_ps(live, y + b), ay);
            const __m256 dz = _mm256_sub_ps(_mm256_maskz_loadu_ps(live, z + b), az);
            const __m256 d2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                            _mm256_mul_ps(dz, dz));
            const __mmask8 hit = _mm256_mask_cmp_ps_mask(live, d2, vr2, _CMP_LT_OQ);
            if (!hit) continue;
            const __m256i ob = _mm256_maskz_loadu_epi32(live, order + b);
            const __m512i lo = _mm512_cvtepu32_epi64(_mm256_min_epu32(oa, ob));
            const __m512i hi = _mm512_cvtepu32_epi64(_mm256_max_epu32(oa, ob));
            _mm512_mask_compressstoreu_epi64(out + count, hit, _mm512_or_si512(lo, _mm512_slli_epi64(hi, 32)));
            count += (size_t)__builtin_popcount((unsigned)hit);
        }
    }
    return count;
}

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
size_t akp_grid_pairs_avx512(const float* x, const float* y, const float* z, const uint32_t* order,
                             uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1, bool same, float r2,
                             ak_grid_pair* out) {
    (void)x, (void)y, (void)z, (void)order, (void)a0, (void)a1, (void)b0, (void)b1, (void)same,
        (void)r2, (void)out;
    return 0; /* never called: akp_grid_have_avx512 is false */
}
size_t akp_grid_row_avx512(const float* x, const float* y, const float* z, const uint32_t* order,
                           const akp_grid_range* ranges, uint32_t range_count, uint32_t self,
                           float qx, float qy, float qz, float r2, uint32_t* out) {
    return akp_grid_row_scalar(x, y, z, order, ranges, range_count, self, qx, qy, qz, r2, out);
}
#endif
