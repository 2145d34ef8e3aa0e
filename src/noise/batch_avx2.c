/* AVX2 fractal kernels (8 points at a time): 2D and 3D Perlin, simplex, value and Worley
 * noise, value and gradient, summed as fBm, turbulence or ridged multifractal. The body is
 * simd_body.h (shared with the AVX-512 kernel); this file supplies its 8-lane vocabulary. Compiled only for
 * GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with __builtin_cpu_supports
 * (AVX2 and FMA: value noise's corner values use explicit fused operations; nothing is
 * contracted implicitly, the module builds with -ffp-contract=off). */
#include "noise_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>
#include <math.h>
#include <string.h>

#define KI __attribute__((target("avx2,fma"), always_inline))
#define KERNEL_RUN __attribute__((target("avx2,fma")))
#if defined(AKP_NOISE_AVX2_GATHER)
/* batch_avx2_gather.c: this file again, the lookups as vpgatherdd, entry akp_noise_fractal_avx2gather. */
#define KERNEL_ENTRY akp_noise_fractal_avx2gather
bool akp_noise_avx2_gather_preferred(void) {
    /* Intel CPUs with the gather data sampling mitigation run vpgatherdd in microcode, slower than
     * the scalar loads; AMD's Zen 5 runs the gather kernel 5-10% faster (issue 32). Zen 4
     * and later (the AMD CPUs with AVX-512) take it; older AMD and every other CPU the loads. */
    return __builtin_cpu_is("amd") && __builtin_cpu_supports("avx512f");
}
#else
#define KERNEL_ENTRY akp_noise_fractal_avx2
bool akp_noise_have_avx2(void) { return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"); }
#endif
#define AKP_W 8
typedef __m256 VF;
typedef __m256i VI;
typedef __m256 VM; /* lanes all ones or all zeros */

KI static inline VF vf_set1(float a) { return _mm256_set1_ps(a); }
KI static inline VI vi_set1(int a) { return _mm256_set1_epi32(a); }
KI static inline VF vf_zero(void) { return _mm256_setzero_ps(); }
KI static inline VF vf_load(const float* p) { return _mm256_loadu_ps(p); }
KI static inline void vf_store(float* p, VF v) { _mm256_storeu_ps(p, v); }
KI static inline VF vf_add(VF a, VF b) { return _mm256_add_ps(a, b); }
KI static inline VF vf_sub(VF a, VF b) { return _mm256_sub_ps(a, b); }
KI static inline VF vf_mul(VF a, VF b) { return _mm256_mul_ps(a, b); }
KI static inline VF vf_min(VF a, VF b) { return _mm256_min_ps(a, b); }
KI static inline VF vf_max(VF a, VF b) { return _mm256_max_ps(a, b); }
KI static inline VF vf_floor(VF a) { return _mm256_floor_ps(a); }
KI static inline VI vf_cvtt(VF a) { return _mm256_cvttps_epi32(a); }
KI static inline VF vf_cast(VI a) { return _mm256_castsi256_ps(a); }
KI static inline VF vf_xor(VF a, VF b) { return _mm256_xor_ps(a, b); }
KI static inline VF vf_and(VF a, VF b) { return _mm256_and_ps(a, b); }
KI static inline VF vf_abs(VF a) { return _mm256_andnot_ps(_mm256_set1_ps(-0.0f), a); }
KI static inline VI vi_and(VI a, VI b) { return _mm256_and_si256(a, b); }
KI static inline VI vi_add(VI a, VI b) { return _mm256_add_epi32(a, b); }
KI static inline VI vi_xor(VI a, VI b) { return _mm256_xor_si256(a, b); }
KI static inline VI vi_or(VI a, VI b) { return _mm256_or_si256(a, b); }
KI static inline VI vi_mullo(VI a, VI b) { return _mm256_mullo_epi32(a, b); }
KI static inline VF vf_div(VF a, VF b) { return _mm256_div_ps(a, b); }
KI static inline VF vf_fmadd(VF a, VF b, VF c) { return _mm256_fmadd_ps(a, b, c); }   /* a b + c, one rounding */
KI static inline VF vf_fnmadd(VF a, VF b, VF c) { return _mm256_fnmadd_ps(a, b, c); } /* c - a b, one rounding */
KI static inline VF vf_sqrt(VF a) { return _mm256_sqrt_ps(a); }
KI static inline VF vf_cvt(VI a) { return _mm256_cvtepi32_ps(a); }
#define VI_SLLI(a, n) _mm256_slli_epi32((a), (n))
#define VI_SRLI(a, n) _mm256_srli_epi32((a), (n))
/* The lookup table is the byte table itself. An index is at most 255 + 255: the scalar loads
 * read at most perm[511]; the gather (AKP_NOISE_AVX2_GATHER) reads 4 bytes, at most perm[513],
 * inside ak_noise, whose 8-byte seed follows perm[511]. */
typedef struct PermTab {
    const uint8_t* perm;
} PermTab;
KI static inline void tab_make(const uint8_t* perm, PermTab* t) { t->perm = perm; }
#if defined(AKP_NOISE_AVX2_GATHER)
/* The 4 bytes perm[idx .. idx + 3] of each lane (little-endian: perm[idx] in the low byte). */
KI static inline VI tab_pair(const PermTab* t, VI idx) {
    return _mm256_i32gather_epi32((const int*)(const void*)t->perm, idx, 1);
}
#else
/* Eight scalar 16-bit loads: on CPUs whose gathers are microcoded slowly (the 2023 gather
 * data sampling mitigation) this beats vpgatherdd; the result is the same. */
KI static inline VI tab_pair(const PermTab* t, VI idx) {
    int32_t i[8];
    _mm256_storeu_si256((__m256i*)(void*)i, idx);
    uint16_t v[8];
    for (int k = 0; k < 8; ++k) memcpy(&v[k], t->perm + i[k], 2);
    const __m128i lo = _mm_setr_epi32(v[0], v[1], v[2], v[3]), hi = _mm_setr_epi32(v[4], v[5], v[6], v[7]);
    return _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
}
#endif
KI static inline VM m_lt(VF a, VF b) { return _mm256_cmp_ps(a, b, _CMP_LT_OQ); }
KI static inline VM m_gt(VF a, VF b) { return _mm256_cmp_ps(a, b, _CMP_GT_OQ); }
KI static inline VM m_ge(VF a, VF b) { return _mm256_cmp_ps(a, b, _CMP_GE_OQ); }
KI static inline VM mi_lt(VI a, int v) { return _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(v), a)); }
KI static inline VM mi_eq(VI a, int v) { return _mm256_castsi256_ps(_mm256_cmpeq_epi32(a, _mm256_set1_epi32(v))); }
KI static inline VM mi_none(VI a, int bits) { /* (a & bits) == 0 */
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(a, _mm256_set1_epi32(bits)), _mm256_setzero_si256()));
}
KI static inline VM m_and(VM a, VM b) { return _mm256_and_ps(a, b); }
KI static inline VM m_or(VM a, VM b) { return _mm256_or_ps(a, b); }
KI static inline VM m_andn(VM a, VM b) { return _mm256_andnot_ps(a, b); } /* !a & b */
KI static inline VM m_not(VM a) { return _mm256_xor_ps(a, _mm256_castsi256_ps(_mm256_set1_epi32(-1))); }
KI static inline VF vf_sel(VM m, VF a, VF b) { return _mm256_blendv_ps(b, a, m); } /* m ? a : b */
KI static inline VI vi_sel(VM m, VI a, VI b) {
    return _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(b), _mm256_castsi256_ps(a), m));
}
KI static inline VF vf_maskz(VM m, VF a) { return _mm256_and_ps(m, a); } /* m ? a : +0 */
KI static inline unsigned m_bits(VM m) { return (unsigned)_mm256_movemask_ps(m); } /* bit i: lane i */
/* tab[idx & 15] (bits above 3 are not read) */
KI static inline VF vf_lut16(const float* tab, VI idx) {
    const VF lo = _mm256_permutevar8x32_ps(_mm256_loadu_ps(tab), idx);
    const VF hi = _mm256_permutevar8x32_ps(_mm256_loadu_ps(tab + 8), idx);
    return _mm256_blendv_ps(lo, hi, _mm256_castsi256_ps(_mm256_slli_epi32(idx, 28)));
}

#include "simd_body.h"

#elif defined(AKP_NOISE_AVX2_GATHER)

bool akp_noise_avx2_gather_preferred(void) { return false; }
void akp_noise_fractal_avx2gather(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims,
                                  const float* const* xs, size_t count, float* out, float* const* grad) {
    (void)noise, (void)d, (void)dims, (void)xs, (void)count, (void)out, (void)grad;
}

#else

bool akp_noise_have_avx2(void) { return false; }
void akp_noise_fractal_avx2(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                            size_t count, float* out, float* const* grad) {
    (void)noise, (void)d, (void)dims, (void)xs, (void)count, (void)out, (void)grad;
}

#endif
