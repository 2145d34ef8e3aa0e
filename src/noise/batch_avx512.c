/* AVX-512 fractal kernels (16 points at a time, AVX-512 F and DQ): the same body as the AVX2
 * kernel (simd_body.h) over 16 lanes with mask registers. Compiled only for GCC/Clang on
 * x86-64 without AK_NO_SIMD (the rest of the build needs no -mavx512 flag); selected at run
 * time with __builtin_cpu_supports. batch_avx512_vbmi.c compiles this file a second time with
 * AKP_NOISE_VBMI defined: the permutation lookups as byte permutes (AVX-512 BW and VBMI),
 * entry akp_noise_fractal_avx512vbmi, chosen where the CPU has them. */
#include "noise_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>
#include <math.h>

#if defined(AKP_NOISE_VBMI)
bool akp_noise_have_avx512vbmi(void) {
    return akp_noise_have_avx512() && __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vbmi");
}
#define KI __attribute__((target("avx512f,avx512dq,avx512bw,avx512vbmi"), always_inline))
#define KERNEL_RUN __attribute__((target("avx512f,avx512dq,avx512bw,avx512vbmi")))
#define KERNEL_ENTRY akp_noise_fractal_avx512vbmi
#else
bool akp_noise_have_avx512(void) {
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
}
#define KI __attribute__((target("avx512f,avx512dq"), always_inline))
#define KERNEL_RUN __attribute__((target("avx512f,avx512dq")))
#define KERNEL_ENTRY akp_noise_fractal_avx512
#endif
#define AKP_W 16
typedef __m512 VF;
typedef __m512i VI;
typedef __mmask16 VM;

KI static inline VF vf_set1(float a) { return _mm512_set1_ps(a); }
KI static inline VI vi_set1(int a) { return _mm512_set1_epi32(a); }
KI static inline VF vf_zero(void) { return _mm512_setzero_ps(); }
KI static inline VF vf_load(const float* p) { return _mm512_loadu_ps(p); }
KI static inline void vf_store(float* p, VF v) { _mm512_storeu_ps(p, v); }
KI static inline VF vf_add(VF a, VF b) { return _mm512_add_ps(a, b); }
KI static inline VF vf_sub(VF a, VF b) { return _mm512_sub_ps(a, b); }
KI static inline VF vf_mul(VF a, VF b) { return _mm512_mul_ps(a, b); }
KI static inline VF vf_min(VF a, VF b) { return _mm512_min_ps(a, b); }
KI static inline VF vf_max(VF a, VF b) { return _mm512_max_ps(a, b); }
KI static inline VF vf_floor(VF a) { return _mm512_roundscale_ps(a, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC); }
KI static inline VI vf_cvtt(VF a) { return _mm512_cvttps_epi32(a); }
KI static inline VF vf_cast(VI a) { return _mm512_castsi512_ps(a); }
KI static inline VF vf_xor(VF a, VF b) { return _mm512_xor_ps(a, b); }
KI static inline VF vf_and(VF a, VF b) { return _mm512_and_ps(a, b); }
KI static inline VF vf_abs(VF a) { return _mm512_andnot_ps(_mm512_set1_ps(-0.0f), a); }
KI static inline VI vi_and(VI a, VI b) { return _mm512_and_si512(a, b); }
KI static inline VI vi_add(VI a, VI b) { return _mm512_add_epi32(a, b); }
KI static inline VI vi_xor(VI a, VI b) { return _mm512_xor_si512(a, b); }
KI static inline VI vi_or(VI a, VI b) { return _mm512_or_si512(a, b); }
KI static inline VI vi_mullo(VI a, VI b) { return _mm512_mullo_epi32(a, b); }
KI static inline VF vf_div(VF a, VF b) { return _mm512_div_ps(a, b); }
KI static inline VF vf_fmadd(VF a, VF b, VF c) { return _mm512_fmadd_ps(a, b, c); }   /* a b + c, one rounding */
KI static inline VF vf_fnmadd(VF a, VF b, VF c) { return _mm512_fnmadd_ps(a, b, c); } /* c - a b, one rounding */
KI static inline VF vf_sqrt(VF a) { return _mm512_sqrt_ps(a); }
KI static inline VF vf_cvt(VI a) { return _mm512_cvtepi32_ps(a); }
#define VI_SLLI(a, n) _mm512_slli_epi32((a), (n))
#define VI_SRLI(a, n) _mm512_srli_epi32((a), (n))
#if defined(AKP_NOISE_VBMI)
/* perm[0..255] in 4 registers of 64 bytes; tab_bytes looks up every byte of a vector at once
 * (both 128-byte halves with vpermt2b, which reads bits 0..6, then a pick by bit 7). */
typedef struct PermTab {
    VI t[4];
} PermTab;
KI static inline void tab_make(const uint8_t* perm, PermTab* t) {
    for (int c = 0; c < 4; ++c) t->t[c] = _mm512_loadu_si512((const void*)(perm + 64 * c));
}
KI static inline VI tab_bytes(const PermTab* t, VI b) {
    const VI lo = _mm512_permutex2var_epi8(t->t[0], b, t->t[1]);
    const VI hi = _mm512_permutex2var_epi8(t->t[2], b, t->t[3]);
    return _mm512_mask_blend_epi8(_mm512_movepi8_mask(b), lo, hi);
}
/* In-lane byte shuffle of dword j's bytes (b0, b1, b2, b3 of dword j, 0..3; -1: a zero byte)
 * into its bytes 0..3. */
KI static inline VI dword_bytes(VI v, int b0, int b1, int b2, int b3) {
    const int b[4] = {b0, b1, b2, b3};
    uint32_t d[4];
    for (int j = 0; j < 4; ++j) {
        d[j] = 0;
        for (int k = 0; k < 4; ++k) d[j] |= (uint32_t)(b[k] < 0 ? 0x80 : 4 * j + b[k]) << (8 * k);
    }
    return _mm512_shuffle_epi8(
        v, _mm512_broadcast_i32x4(_mm_setr_epi32((int)d[0], (int)d[1], (int)d[2], (int)d[3])));
}
/* simd_body.h's cell_hashes over bytes: the same chain (perm[h + lo] and perm[h + lo + 1], the
 * doubled table making them perm[(h + lo) & 255] and perm[(h + lo + 1) & 255], which byte
 * arithmetic gives), four lookups of a lane per tab_bytes: 3D takes 4 instead of 7. */
#define AKP_HAVE_CELL_HASHES
KI static inline void cell_hashes(const PermTab* perm, int dims, const VI* lo, VI* hash) {
    const VI inc = _mm512_set1_epi32(0x01000100), m8 = _mm512_set1_epi32(255);
    const VI x = _mm512_add_epi8(dword_bytes(lo[0], 0, 0, 0, 0), inc);
    const VI g1 = tab_bytes(perm, x); /* perm[x], perm[x + 1], again */
    const VI y = _mm512_add_epi8(dword_bytes(lo[1], 0, 0, 0, 0), inc);
    const VI g2 = tab_bytes(perm, _mm512_add_epi8(dword_bytes(g1, 0, 0, 1, 1), y)); /* corners 0, 2, 1, 3 */
    /* byte k of each lane zero-extended: one shuffle a corner */
    if (dims == 2) {
        hash[0] = _mm512_and_si512(g2, m8);
        hash[2] = dword_bytes(g2, 1, -1, -1, -1);
        hash[1] = dword_bytes(g2, 2, -1, -1, -1);
        hash[3] = _mm512_srli_epi32(g2, 24);
        return;
    }
    const VI z = _mm512_add_epi8(dword_bytes(lo[2], 0, 0, 0, 0), inc);
    const VI p = tab_bytes(perm, _mm512_add_epi8(dword_bytes(g2, 0, 0, 1, 1), z)); /* corners 0, 4, 2, 6 */
    const VI q = tab_bytes(perm, _mm512_add_epi8(dword_bytes(g2, 2, 2, 3, 3), z)); /* corners 1, 5, 3, 7 */
    hash[0] = _mm512_and_si512(p, m8);
    hash[4] = dword_bytes(p, 1, -1, -1, -1);
    hash[2] = dword_bytes(p, 2, -1, -1, -1);
    hash[6] = _mm512_srli_epi32(p, 24);
    hash[1] = _mm512_and_si512(q, m8);
    hash[5] = dword_bytes(q, 1, -1, -1, -1);
    hash[3] = dword_bytes(q, 2, -1, -1, -1);
    hash[7] = _mm512_srli_epi32(q, 24);
}
#else
/* perm[j] | perm[j + 1] << 8 for j = 0..255 in 16 registers (entries 32 c .. 32 c + 31 in
 * t[c][0..1]): a lookup is 8 two-register permutes on the index's low 5 bits and a blend tree
 * on bits 5..7, which beats a 16-lane gather on CPUs with slow gathers (3D Perlin 1.45x faster
 * on the Xeon of docs/BENCHMARKS.md). */
typedef struct PermTab {
    VI t[8][2];
} PermTab;
KI static inline void tab_make(const uint8_t* perm, PermTab* t) {
    for (int c = 0; c < 8; ++c)
        for (int h = 0; h < 2; ++h) {
            const int j = 32 * c + 16 * h; /* perm[j + 16] <= perm[256]: inside the doubled table */
            const __m512i a = _mm512_cvtepu8_epi32(_mm_loadu_si128((const __m128i*)(const void*)(perm + j)));
            const __m512i b = _mm512_cvtepu8_epi32(_mm_loadu_si128((const __m128i*)(const void*)(perm + j + 1)));
            t->t[c][h] = _mm512_or_si512(a, _mm512_slli_epi32(b, 8));
        }
}
KI static inline VI tab_pair(const PermTab* t, VI idx) {
    VI r[8];
    for (int c = 0; c < 8; ++c) r[c] = _mm512_permutex2var_epi32(t->t[c][0], idx, t->t[c][1]);
    const VM b5 = _mm512_test_epi32_mask(idx, _mm512_set1_epi32(32));
    const VM b6 = _mm512_test_epi32_mask(idx, _mm512_set1_epi32(64));
    const VM b7 = _mm512_test_epi32_mask(idx, _mm512_set1_epi32(128));
    for (int c = 0; c < 4; ++c) r[c] = _mm512_mask_blend_epi32(b5, r[2 * c], r[2 * c + 1]);
    for (int c = 0; c < 2; ++c) r[c] = _mm512_mask_blend_epi32(b6, r[2 * c], r[2 * c + 1]);
    return _mm512_mask_blend_epi32(b7, r[0], r[1]);
}
#endif
KI static inline VM m_lt(VF a, VF b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
KI static inline VM m_gt(VF a, VF b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
KI static inline VM m_ge(VF a, VF b) { return _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ); }
KI static inline VM mi_lt(VI a, int v) { return _mm512_cmplt_epi32_mask(a, _mm512_set1_epi32(v)); }
KI static inline VM mi_eq(VI a, int v) { return _mm512_cmpeq_epi32_mask(a, _mm512_set1_epi32(v)); }
/* (a & bits) == 0 */
KI static inline VM mi_none(VI a, int bits) { return _mm512_testn_epi32_mask(a, _mm512_set1_epi32(bits)); }
KI static inline VM m_and(VM a, VM b) { return (VM)(a & b); }
KI static inline VM m_or(VM a, VM b) { return (VM)(a | b); }
KI static inline VM m_andn(VM a, VM b) { return (VM)(~a & b); } /* !a & b */
KI static inline VM m_not(VM a) { return (VM)~a; }
KI static inline VF vf_sel(VM m, VF a, VF b) { return _mm512_mask_blend_ps(m, b, a); } /* m ? a : b */
KI static inline VI vi_sel(VM m, VI a, VI b) { return _mm512_mask_blend_epi32(m, b, a); }
KI static inline VF vf_maskz(VM m, VF a) { return _mm512_maskz_mov_ps(m, a); } /* m ? a : +0 */
KI static inline unsigned m_bits(VM m) { return (unsigned)m; } /* bit i: lane i */
/* tab[idx & 15] (vpermps reads bits 0..3) */
KI static inline VF vf_lut16(const float* tab, VI idx) { return _mm512_permutexvar_ps(idx, _mm512_loadu_ps(tab)); }

#include "simd_body.h"

#elif defined(AKP_NOISE_VBMI)

bool akp_noise_have_avx512vbmi(void) { return false; }
void akp_noise_fractal_avx512vbmi(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims,
                                  const float* const* xs, size_t count, float* out, float* const* grad) {
    (void)noise, (void)d, (void)dims, (void)xs, (void)count, (void)out, (void)grad;
}

#else

bool akp_noise_have_avx512(void) { return false; }
void akp_noise_fractal_avx512(const ak_noise* noise, const ak_fractal_desc* d, uint32_t dims, const float* const* xs,
                              size_t count, float* out, float* const* grad) {
    (void)noise, (void)d, (void)dims, (void)xs, (void)count, (void)out, (void)grad;
}

#endif
