/* AVX-512 kernel of implicit skinning's Newton march (16 vertices per call): implicit_lanes.h with
 * 512-bit vectors and mask registers, the grid nodes read with masked gathers. Compiled only for
 * GCC/Clang on x86-64 without AK_NO_SIMD, with target attributes; implicit.c selects it at run
 * time (akp_skin_have_avx512). Gives the scalar field_eval's bits (see implicit_lanes.h). */
#include "skin_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define LANES 16u
#define LANES_PACKED 1
#define KFUNC __attribute__((target("avx512f,avx512vl,avx512dq,avx512bw,avx2,fma")))
#define VF __m512
#define VI __m512i
#define VM __mmask16
#define F_SET1(a) _mm512_set1_ps(a)
#define F_ZERO() _mm512_setzero_ps()
#define F_LOAD(p) _mm512_load_ps(p)
#define F_STORE(p, a) _mm512_store_ps((p), (a))
#define F_ADD(a, b) _mm512_add_ps((a), (b))
#define F_SUB(a, b) _mm512_sub_ps((a), (b))
#define F_MUL(a, b) _mm512_mul_ps((a), (b))
#define F_DIV(a, b) _mm512_div_ps((a), (b))
#define F_SQRT(a) _mm512_sqrt_ps(a)
#define F_SEL(m, a, b) _mm512_mask_blend_ps((m), (b), (a))
#define M_LT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_LT_OQ)
#define M_LE(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_LE_OQ)
#define M_GT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_GT_OQ)
#define M_GE(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_GE_OQ)
#define M_AND(a, b) ((VM)((a) & (b)))
#define M_ANDNOT(a, b) ((VM)((a) & ~(b)))
#define M_ANY(m) ((m) != 0)
#define M_OR(a, b) ((VM)((a) | (b)))
#define M_EQ(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_EQ_OQ)
#define M_BITS(m) ((unsigned)(m))
#define F_ABS(a) _mm512_abs_ps(a)
#define I_STORE(p, a) _mm512_store_si512((void*)(p), (a))
#define I_LOAD(p) _mm512_load_si512((const void*)(p))
#define I_SUB(a, b) _mm512_sub_epi32((a), (b))
#define COMPRESS_F(dst, m, v) _mm512_mask_compressstoreu_ps((dst), (m), (v))
#define COMPRESS_I(dst, m, v) _mm512_mask_compressstoreu_epi32((dst), (m), (v))
#define EXPAND_F(src, m) _mm512_maskz_expandloadu_ps((m), (src))
#define M_FROM_BITS(bits) ((VM)(bits))
#define I_SET1(a) _mm512_set1_epi32(a)
#define I_ADD(a, b) _mm512_add_epi32((a), (b))
#define I_MUL(a, b) _mm512_mullo_epi32((a), (b))
#define I_MIN(a, b) _mm512_min_epi32((a), (b))
#define I_TRUNC(a) _mm512_cvttps_epi32(a)
#define I_TO_F(a) _mm512_cvtepi32_ps(a)
#define GATHER4(m, base, index, out) gather4((m), (base), (index), (out))

/* The 4 floats at base + index of each lane (lanes off m: 0): pairs of floats as 64-bit gathers
 * (8 lanes each, half the elements of 32-bit gathers), split into even and odd floats. */
KFUNC static inline void gather4(__mmask16 m, const float* base, __m512i index, __m512* out) {
    const __m256i lo = _mm512_castsi512_si256(index), hi = _mm512_extracti64x4_epi64(index, 1);
    const __mmask8 mlo = (__mmask8)m, mhi = (__mmask8)(m >> 8);
    const __m512i even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
    const __m512i odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
    for (int k = 0; k < 4; k += 2) {
        const __m512 a = _mm512_castpd_ps(_mm512_mask_i32gather_pd(_mm512_setzero_pd(), mlo, lo, base + k, 4));
        const __m512 b = _mm512_castpd_ps(_mm512_mask_i32gather_pd(_mm512_setzero_pd(), mhi, hi, base + k, 4));
        out[k] = _mm512_permutex2var_ps(a, even, b);
        out[k + 1] = _mm512_permutex2var_ps(a, odd, b);
    }
}

#include "implicit_lanes.h"

unsigned akp_implicit_march_avx512(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live) {
    return lanes_march(fd, l, live);
}

#else

unsigned akp_implicit_march_avx512(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live) {
    (void)fd, (void)l, (void)live;
    return 0;
}

#endif
