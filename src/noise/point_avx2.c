/* AVX2 pieces of the per-point calls (one point, its cells side by side in the lanes), chosen
 * at run time by bases.c where the CPU has AVX2. Compiled only for GCC/Clang on x86-64 without
 * AK_NO_SIMD. Nothing here is contracted (the module builds with -ffp-contract=off): the
 * float operations are bases.c's, one lane per cell. */
#include "noise_internal.h"

#ifdef AKP_HAVE_POINT_AVX2
#include <immintrin.h>
#include <string.h>

#define KT __attribute__((target("avx2")))

/* Squared distances to the feature points of 8 cells (bases.c worley_offset, lane by lane):
 * a[k] the cells' axis-k hash terms, c[k] the floats 1 - off[k] of each lane's cell. */
KT static inline __m256 worley_lanes(uint32_t dims, __m256i seed_mix, const __m256i* a,
                                     const __m256* c, const float* f) {
    __m256i h = _mm256_xor_si256(seed_mix, a[0]);
    for (uint32_t k = 1; k < dims; ++k) h = _mm256_xor_si256(h, a[k]);
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 16));
    h = _mm256_mullo_epi32(h, _mm256_set1_epi32((int)0x85EBCA6Bu));
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 13));
    h = _mm256_mullo_epi32(h, _mm256_set1_epi32((int)0xC2B2AE35u));
    h = _mm256_xor_si256(h, _mm256_srli_epi32(h, 16));
    __m256 dist2 = _mm256_setzero_ps();
    for (uint32_t k = 0; k < dims; ++k) {
        const __m256i m =
            _mm256_and_si256(_mm256_srli_epi32(h, (int)(10 * k)), _mm256_set1_epi32(1023));
        const __m256 fp = _mm256_castsi256_ps(
            _mm256_or_si256(_mm256_slli_epi32(m, 13), _mm256_set1_epi32(0x3F801000)));
        const __m256 dv = _mm256_sub_ps(_mm256_set1_ps(f[k]), _mm256_sub_ps(fp, c[k]));
        dist2 = _mm256_add_ps(dist2, _mm256_mul_ps(dv, dv));
    }
    return dist2;
}

/* Cell offsets o - 1 per lane (cell index c: o = (c % 3, c / 3 % 3, c / 9)); lanes past the
 * last cell repeat the centre cell, which leaves the minimum unchanged. */
static const int32_t worley_off3[3][32] = {
    {-1, 0, 1,  -1, 0, 1,  -1, 0, 1,  -1, 0, 1, -1, 0, 1, -1,
     0,  1, -1, 0,  1, -1, 0,  1, -1, 0,  1, 0, 0,  0, 0, 0},
    {-1, -1, -1, 0,  0,  0, 1, 1, 1, -1, -1, -1, 0, 0, 0, 1,
     1,  1,  -1, -1, -1, 0, 0, 0, 1, 1,  1,  0,  0, 0, 0, 0},
    {-1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0,
     0,  0,  1,  1,  1,  1,  1,  1,  1,  1, 1, 0, 0, 0, 0, 0},
};
static const int32_t worley_off2[2][8] = {
    {-1, 0, 1, -1, 0, 1, -1, 0},
    {-1, -1, -1, 0, 0, 0, 1, 1},
};

KT float akp_worley_d1_avx2(uint32_t dims, uint64_t seed, const int* base, const float* f) {
    static const uint32_t mul[3] = {0x8DA6B343u, 0xD8163841u, 0xCB1AB31Fu};
    const __m256i seed_mix =
        _mm256_set1_epi32((int)((uint32_t)seed * 0x9E3779B1u ^ (uint32_t)(seed >> 32)));
    /* 2D: cells 0..7 in one vector, cell 8 (offset (1, 1)) below in scalar */
    const uint32_t vectors = dims == 3 ? 4 : 1;
    __m256 d1 = _mm256_set1_ps(INFINITY);
    for (uint32_t v = 0; v < vectors; ++v) {
        __m256i a[3] = {_mm256_setzero_si256(), _mm256_setzero_si256(), _mm256_setzero_si256()};
        __m256 c[3] = {_mm256_setzero_ps(), _mm256_setzero_ps(), _mm256_setzero_ps()};
        for (uint32_t k = 0; k < dims; ++k) {
            const int32_t* off = dims == 3 ? worley_off3[k] + 8 * v : worley_off2[k] + 8 * v;
            const __m256i o = _mm256_loadu_si256((const __m256i*)off);
            /* (base + off) * mul, wrapping, as bases.c's axis terms */
            a[k] = _mm256_mullo_epi32(_mm256_add_epi32(_mm256_set1_epi32(base[k]), o),
                                      _mm256_set1_epi32((int)mul[k]));
            /* (float)(1 - off), exact */
            c[k] = _mm256_cvtepi32_ps(_mm256_sub_epi32(_mm256_set1_epi32(1), o));
        }
        d1 = _mm256_min_ps(d1, worley_lanes(dims, seed_mix, a, c, f));
    }
    __m128 m = _mm_min_ps(_mm256_castps256_ps128(d1), _mm256_extractf128_ps(d1, 1));
    if (dims == 2) {
        uint32_t h = ((uint32_t)seed * 0x9E3779B1u ^ (uint32_t)(seed >> 32)) ^
                     (uint32_t)(base[0] + 1) * mul[0] ^ (uint32_t)(base[1] + 1) * mul[1];
        h ^= h >> 16;
        h *= 0x85EBCA6Bu;
        h ^= h >> 13;
        h *= 0xC2B2AE35u;
        h ^= h >> 16;
        float dist2 = 0.0f;
        for (uint32_t k = 0; k < 2; ++k) {
            const uint32_t bits = 0x3F801000u | ((h >> (10 * k)) & 1023u) << 13;
            float fp;
            memcpy(&fp, &bits, sizeof fp);
            const float dv = f[k] - (fp - 0.0f); /* off 1: 1 - off = 0 */
            dist2 += dv * dv;
        }
        m = _mm_min_ps(m, _mm_set1_ps(dist2));
    }
    m = _mm_min_ps(m, _mm_movehl_ps(m, m));
    m = _mm_min_ss(m, _mm_shuffle_ps(m, m, 1));
    return _mm_cvtss_f32(m);
}

#else
typedef int akp_point_avx2_unused; /* ISO C: no empty translation unit */
#endif
