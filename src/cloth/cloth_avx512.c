/* The cloth constraint solves 16 constraints wide (AVX-512F, no FMA: the scalar solve's bits).
 * Compiled with a target attribute and chosen at run time by step.c when
 * __builtin_cpu_supports("avx512f"). The math is cloth_kernel.h's. */
#include "cloth_impl.h"

#if AKP_CLOTH_SIMD
#include <immintrin.h>

#define KW 16
#define KFN static inline __attribute__((target("avx512f"), always_inline))
typedef __m512 KV;
typedef __mmask16 KM;
#define K_SET1(f) _mm512_set1_ps(f)
#define K_LOAD(p) _mm512_loadu_ps(p)
#define K_STORE(p, v) _mm512_storeu_ps((p), (v))
#define K_ADD _mm512_add_ps
#define K_SUB _mm512_sub_ps
#define K_MUL _mm512_mul_ps
#define K_DIV _mm512_div_ps
#define K_SQRT _mm512_sqrt_ps
#define K_ABS(a) _mm512_castsi512_ps(_mm512_andnot_si512(_mm512_set1_epi32(INT32_MIN), _mm512_castps_si512(a)))
#define K_NEG(a) _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_set1_epi32(INT32_MIN)))
#define K_LT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_LT_OQ)
#define K_GT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_GT_OQ)
#define K_NE(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_NEQ_UQ)
#define K_EQ(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_EQ_OQ)
#define K_NLT(a, b) _mm512_cmp_ps_mask((a), (b), _CMP_NLT_UQ)
#define K_MAND(m, n) ((KM)((m) & (n)))
#define K_SEL(m, a, b) _mm512_mask_blend_ps((m), (b), (a))
#define KN(name) avx512_##name

/* Particles idx[0..15] -> lanes: register e holds idx[e], idx[4 + e], idx[8 + e], idx[12 + e]
 * in its four 128-bit lanes, then a 4x4 transpose in each lane. */
KFN void gather16(const akp_px* x, const uint32_t* idx, KV* px, KV* py, KV* pz, KV* pw) {
    KV r[4];
    for (int e = 0; e < 4; ++e) {
        KV v = _mm512_castps128_ps512(_mm_load_ps(&x[idx[e]].p.x));
        v = _mm512_insertf32x4(v, _mm_load_ps(&x[idx[4 + e]].p.x), 1);
        v = _mm512_insertf32x4(v, _mm_load_ps(&x[idx[8 + e]].p.x), 2);
        r[e] = _mm512_insertf32x4(v, _mm_load_ps(&x[idx[12 + e]].p.x), 3);
    }
    const KV t0 = _mm512_unpacklo_ps(r[0], r[1]), t1 = _mm512_unpackhi_ps(r[0], r[1]);
    const KV t2 = _mm512_unpacklo_ps(r[2], r[3]), t3 = _mm512_unpackhi_ps(r[2], r[3]);
    *px = _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    *py = _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    *pz = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    *pw = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

KFN void scatter16(akp_px* x, const uint32_t* idx, KV px, KV py, KV pz, KV pw) {
    const KV t0 = _mm512_unpacklo_ps(px, py), t1 = _mm512_unpackhi_ps(px, py);
    const KV t2 = _mm512_unpacklo_ps(pz, pw), t3 = _mm512_unpackhi_ps(pz, pw);
    KV r[4];
    r[0] = _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    r[1] = _mm512_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    r[2] = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    r[3] = _mm512_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    for (int e = 0; e < 4; ++e) {
        _mm_store_ps(&x[idx[e]].p.x, _mm512_castps512_ps128(r[e]));
        _mm_store_ps(&x[idx[4 + e]].p.x, _mm512_extractf32x4_ps(r[e], 1));
        _mm_store_ps(&x[idx[8 + e]].p.x, _mm512_extractf32x4_ps(r[e], 2));
        _mm_store_ps(&x[idx[12 + e]].p.x, _mm512_extractf32x4_ps(r[e], 3));
    }
}

#define K_GATHER(arr, idx, v, wv) gather16((arr), (idx), &(v).x, &(v).y, &(v).z, &(wv))
#define K_SCATTER(arr, idx, v, wv) scatter16((arr), (idx), (v).x, (v).y, (v).z, (wv))

#include "cloth_kernel.h"

bool akp_cloth_have_avx512(void) { return __builtin_cpu_supports("avx512f"); }

__attribute__((target("avx512f"))) size_t akp_cloth_dist_avx512(const akp_solve* s, size_t b, size_t e, bool first) {
    size_t k = b;
    for (; k + KW <= e; k += KW) avx512_dist(s, k, first);
    return k;
}

__attribute__((target("avx512f"))) size_t akp_cloth_bend_avx512(const akp_solve* s, size_t b, size_t e, bool first) {
    size_t k = b;
    for (; k + KW <= e; k += KW) avx512_bend(s, k, first);
    return k;
}
#else
typedef int akp_cloth_avx512_unused; /* ISO C forbids an empty translation unit */
#endif
