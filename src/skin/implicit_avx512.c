/* AVX-512 kernel of implicit skinning's field (16 points per call): implicit_lanes.h with
 * 512-bit vectors and mask registers, the grid nodes read with masked gathers. Compiled only for
 * GCC/Clang on x86-64 without AK_NO_SIMD, with target attributes; implicit.c selects it at run
 * time (akp_skin_have_avx512). Gives the scalar field_eval's bits (see implicit_lanes.h). */
#include "skin_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define LANES 16u
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
#define M_FROM_BITS(bits) ((VM)(bits))
#define I_SET1(a) _mm512_set1_epi32(a)
#define I_ADD(a, b) _mm512_add_epi32((a), (b))
#define I_MUL(a, b) _mm512_mullo_epi32((a), (b))
#define I_MIN(a, b) _mm512_min_epi32((a), (b))
#define I_TRUNC(a) _mm512_cvttps_epi32(a)
#define I_TO_F(a) _mm512_cvtepi32_ps(a)
#define F_GATHER(m, base, index) _mm512_mask_i32gather_ps(_mm512_setzero_ps(), (m), (index), (base), 4)

#include "implicit_lanes.h"

bool akp_implicit_field_avx512(const akp_implicit_field* fd, akp_implicit_lanes* l) {
    lanes_field(fd, l);
    return true;
}

#else

bool akp_implicit_field_avx512(const akp_implicit_field* fd, akp_implicit_lanes* l) {
    (void)fd, (void)l;
    return false;
}

#endif
