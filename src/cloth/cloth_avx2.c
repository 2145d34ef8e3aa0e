/* The cloth constraint solves 8 constraints wide (AVX2, no FMA: the scalar solve's bits).
 * Compiled with a target attribute (the rest of the build needs no -mavx2) and chosen at run
 * time by step.c when __builtin_cpu_supports("avx2"). The math is cloth_kernel.h's. */
#include "cloth_impl.h"

#if AKP_CLOTH_SIMD
#include <immintrin.h>

#define KW 8
#define KFN static inline __attribute__((target("avx2"), always_inline))
typedef __m256 KV;
typedef __m256 KM;
#define K_SET1(f) _mm256_set1_ps(f)
#define K_LOAD(p) _mm256_loadu_ps(p)
#define K_STORE(p, v) _mm256_storeu_ps((p), (v))
#define K_ADD _mm256_add_ps
#define K_SUB _mm256_sub_ps
#define K_MUL _mm256_mul_ps
#define K_DIV _mm256_div_ps
#define K_SQRT _mm256_sqrt_ps
#define K_ABS(a) _mm256_andnot_ps(_mm256_set1_ps(-0.0f), (a))
#define K_NEG(a) _mm256_xor_ps((a), _mm256_set1_ps(-0.0f))
#define K_LT(a, b) _mm256_cmp_ps((a), (b), _CMP_LT_OQ)
#define K_GT(a, b) _mm256_cmp_ps((a), (b), _CMP_GT_OQ)
#define K_NE(a, b) _mm256_cmp_ps((a), (b), _CMP_NEQ_UQ)
#define K_EQ(a, b) _mm256_cmp_ps((a), (b), _CMP_EQ_OQ)
#define K_NLT(a, b) _mm256_cmp_ps((a), (b), _CMP_NLT_UQ)
#define K_MAND _mm256_and_ps
#define K_SEL(m, a, b) _mm256_blendv_ps((b), (a), (m))
#define KN(name) avx2_##name

/* Particles idx[0..7] -> lanes: two 128-bit loads per register (idx[e] low, idx[4 + e] high),
 * then a 4x4 transpose in each half. */
KFN void gather8(const akp_px* x, const uint32_t* idx, KV* px, KV* py, KV* pz, KV* pw) {
    KV r[4];
    for (int e = 0; e < 4; ++e)
        r[e] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_load_ps(&x[idx[e]].p.x)), _mm_load_ps(&x[idx[4 + e]].p.x), 1);
    const KV t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    const KV t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    *px = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    *py = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    *pz = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    *pw = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
}

/* Lanes -> particles idx[0..7] (one 128-bit store each, w included: the particle's own). */
KFN void scatter8(akp_px* x, const uint32_t* idx, KV px, KV py, KV pz, KV pw) {
    const KV t0 = _mm256_unpacklo_ps(px, py), t1 = _mm256_unpackhi_ps(px, py);
    const KV t2 = _mm256_unpacklo_ps(pz, pw), t3 = _mm256_unpackhi_ps(pz, pw);
    KV r[4];
    r[0] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(1, 0, 1, 0));
    r[1] = _mm256_shuffle_ps(t0, t2, _MM_SHUFFLE(3, 2, 3, 2));
    r[2] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(1, 0, 1, 0));
    r[3] = _mm256_shuffle_ps(t1, t3, _MM_SHUFFLE(3, 2, 3, 2));
    for (int e = 0; e < 4; ++e) {
        _mm_store_ps(&x[idx[e]].p.x, _mm256_castps256_ps128(r[e]));
        _mm_store_ps(&x[idx[4 + e]].p.x, _mm256_extractf128_ps(r[e], 1));
    }
}

#define K_GATHER(arr, idx, v, wv) gather8((arr), (idx), &(v).x, &(v).y, &(v).z, &(wv))
#define K_SCATTER(arr, idx, v, wv) scatter8((arr), (idx), (v).x, (v).y, (v).z, (wv))

#include "cloth_kernel.h"

bool akp_cloth_have_avx2(void) { return __builtin_cpu_supports("avx2"); }

__attribute__((target("avx2"))) size_t akp_cloth_dist_avx2(const akp_solve* s, size_t b, size_t e, bool first) {
    size_t k = b;
    for (; k + KW <= e; k += KW) avx2_dist(s, k, first);
    return k;
}

__attribute__((target("avx2"))) size_t akp_cloth_bend_avx2(const akp_solve* s, size_t b, size_t e, bool first) {
    size_t k = b;
    for (; k + KW <= e; k += KW) avx2_bend(s, k, first);
    return k;
}
#else
typedef int akp_cloth_avx2_unused; /* ISO C forbids an empty translation unit */
#endif
