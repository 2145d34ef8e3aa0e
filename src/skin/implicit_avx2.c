/* AVX2 kernel of implicit skinning's Newton march (8 vertices per call): implicit_lanes.h with 256-bit
 * vectors (lane masks are all-ones lanes), the grid nodes read with masked gathers. Compiled
 * only for GCC/Clang on x86-64 without AK_NO_SIMD, with target attributes; implicit.c selects it
 * at run time (akp_skin_have_avx2). Gives the scalar field_eval's bits (see implicit_lanes.h). */
#include "skin_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define LANES 8u
#define LANES_PACKED 0
#define KFUNC __attribute__((target("avx2,fma")))
#define VF __m256
#define VI __m256i
#define VM __m256
#define F_SET1(a) _mm256_set1_ps(a)
#define F_ZERO() _mm256_setzero_ps()
#define F_LOAD(p) _mm256_load_ps(p)
#define F_STORE(p, a) _mm256_store_ps((p), (a))
#define F_ADD(a, b) _mm256_add_ps((a), (b))
#define F_SUB(a, b) _mm256_sub_ps((a), (b))
#define F_MUL(a, b) _mm256_mul_ps((a), (b))
#define F_DIV(a, b) _mm256_div_ps((a), (b))
#define F_SQRT(a) _mm256_sqrt_ps(a)
#define F_SEL(m, a, b) _mm256_blendv_ps((b), (a), (m))
#define M_LT(a, b) _mm256_cmp_ps((a), (b), _CMP_LT_OQ)
#define M_LE(a, b) _mm256_cmp_ps((a), (b), _CMP_LE_OQ)
#define M_GT(a, b) _mm256_cmp_ps((a), (b), _CMP_GT_OQ)
#define M_GE(a, b) _mm256_cmp_ps((a), (b), _CMP_GE_OQ)
#define M_AND(a, b) _mm256_and_ps((a), (b))
#define M_ANDNOT(a, b) _mm256_andnot_ps((b), (a))
#define M_ANY(m) (_mm256_movemask_ps(m) != 0)
#define M_OR(a, b) _mm256_or_ps((a), (b))
#define M_EQ(a, b) _mm256_cmp_ps((a), (b), _CMP_EQ_OQ)
#define M_BITS(m) ((unsigned)_mm256_movemask_ps(m))
#define F_ABS(a) _mm256_andnot_ps(_mm256_set1_ps(-0.0f), (a))
#define I_STORE(p, a) _mm256_store_si256((__m256i*)(void*)(p), (a))
#define I_LOAD(p) _mm256_load_si256((const __m256i*)(const void*)(p))
#define I_SUB(a, b) _mm256_sub_epi32((a), (b))
#define M_FROM_BITS(bits) from_bits(bits)
#define I_SET1(a) _mm256_set1_epi32(a)
#define I_ADD(a, b) _mm256_add_epi32((a), (b))
#define I_MUL(a, b) _mm256_mullo_epi32((a), (b))
#define I_MIN(a, b) _mm256_min_epi32((a), (b))
#define I_TRUNC(a) _mm256_cvttps_epi32(a)
#define I_TO_F(a) _mm256_cvtepi32_ps(a)
#define GATHER4(m, base, index, out) gather4((m), (base), (index), (out))

/* Lane l all ones where bit l of bits is set. */
KFUNC static inline __m256 from_bits(unsigned bits) {
    const __m256i lane = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    return _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)bits), lane), lane));
}

/* The 4 floats at base + index of each lane (lanes off m: 0), one gather per float. */
KFUNC static inline void gather4(__m256 m, const float* base, __m256i index, __m256* out) {
    for (int k = 0; k < 4; ++k) out[k] = _mm256_mask_i32gather_ps(_mm256_setzero_ps(), base + k, index, m, 4);
}

#include "implicit_lanes.h"

unsigned akp_implicit_march_avx2(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live) {
    return lanes_march(fd, l, live);
}

#else

unsigned akp_implicit_march_avx2(const akp_implicit_field* fd, akp_implicit_lanes* l, unsigned live) {
    (void)fd, (void)l, (void)live;
    return 0;
}

#endif
