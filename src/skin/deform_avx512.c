/* AVX-512 skinning kernel (F, VL, DQ, BW), vectorized across vertices (16 per block).
 *
 * The same two stages as the AVX2 kernel (deform_avx2.c), twice as wide. Per vertex, the joint
 * data are blended with contiguous loads: a whole palette matrix is one 64-byte load for LBS
 * (one FMA per influence instead of two), the rotation|dual pair one 32-byte load for DQS, the
 * CoR rows (matrix columns with the rotation in their w slots, or the copy with the rotation
 * negated) one 64-byte load for CoR. The hemisphere signs of DQS/CoR come from one product of
 * up to four rotations (128-bit lanes) with the reference and an in-lane sum, compared into a
 * mask. The 16 blended results are then transposed into structure-of-arrays registers (vertex v
 * and v + 8 share a row, so the 8x8 transpose of the AVX2 kernel runs in both 256-bit halves)
 * and the transform, normal and normalisation run 16-wide. The last block of a range (< 16
 * vertices) runs the same code with masked loads and stores, so every vertex of a range takes
 * this kernel.
 *
 * Same semantics as the scalar reference: joint indices clamped to the palette, the reference
 * rotation is the one of the largest weight (lowest slot on ties), a rotation is flipped when its
 * dot product with the reference is < 0, DQS/CoR take 2 / |q|^2 instead of normalising the
 * blend (0 where it vanished), a vanishing LBS normal gives zero.
 *
 * Handled here: LBS, DQS, CoR with positions and optional normals, rigid or stretched palettes
 * for LBS, rigid palettes for DQS/CoR (as the AVX2 kernel; akp_skin_range_avx512 returns false
 * otherwise). Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD, with target attributes
 * (the rest of the build needs no -mavx512 flag); selected at run time with
 * __builtin_cpu_supports. */
#include "skin_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#define AKP_HAVE_AVX512_KERNEL 1
#include <immintrin.h>
#define AKP_AVX512_TARGET "avx512f,avx512vl,avx512dq,avx512bw,avx2,fma"
#define AKP_AVX512 __attribute__((target(AKP_AVX512_TARGET)))
#define AKP_AVX512_INLINE __attribute__((target(AKP_AVX512_TARGET), always_inline))
/* the shared AVX2 helpers (joint offsets, DQS/CoR phase 1) compiled for this target */
#define AKP_AVX2_INLINE AKP_AVX512_INLINE
#include "skin_avx2_shared.h"
#else
#define AKP_HAVE_AVX512_KERNEL 0
#endif

#if AKP_HAVE_AVX512_KERNEL

bool akp_skin_have_avx512(void) {
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("avx512f") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512bw");
}

/* Lane indices of the xyz (de)interleave of 16 vertices (48 floats in three registers a, b, c):
 * component k of vertex i is float e = 3 i + k. Deinterleave: stage 1 picks e < 32 from (a, b),
 * stage 2 the rest from c. Interleave: register r, lane p holds e = 16 r + p; stage 1 picks x
 * and y, stage 2 inserts z. */
static const int32_t deint_idx[3][2][16] = {
    {{0, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 0, 0, 0, 0, 0}, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 17, 20, 23, 26, 29}},
    {{1, 4, 7, 10, 13, 16, 19, 22, 25, 28, 31, 0, 0, 0, 0, 0}, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 18, 21, 24, 27, 30}},
    {{2, 5, 8, 11, 14, 17, 20, 23, 26, 29, 0, 0, 0, 0, 0, 0}, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 16, 19, 22, 25, 28, 31}},
};
static const int32_t int_idx[3][2][16] = {
    {{0, 16, 0, 1, 17, 0, 2, 18, 0, 3, 19, 0, 4, 20, 0, 5}, {0, 1, 16, 3, 4, 17, 6, 7, 18, 9, 10, 19, 12, 13, 20, 15}},
    {{21, 0, 6, 22, 0, 7, 23, 0, 8, 24, 0, 9, 25, 0, 10, 26}, {0, 21, 2, 3, 22, 5, 6, 23, 8, 9, 24, 11, 12, 25, 14, 15}},
    {{0, 11, 27, 0, 12, 28, 0, 13, 29, 0, 14, 30, 0, 15, 31, 0}, {26, 1, 2, 27, 4, 5, 28, 7, 8, 29, 10, 11, 30, 13, 14, 31}},
};
/* Transpose of 8 rows that each hold two vertices (v in the low, v + 8 in the high half). */
static const int32_t tr_lo_idx[16] = {0, 1, 2, 3, 16, 17, 18, 19, 8, 9, 10, 11, 24, 25, 26, 27};
static const int32_t tr_hi_idx[16] = {4, 5, 6, 7, 20, 21, 22, 23, 12, 13, 14, 15, 28, 29, 30, 31};

AKP_AVX512_INLINE static inline __m512i idx16(const int32_t* p) { return _mm512_loadu_si512((const void*)p); }

/* The first r (clamped to 0..16) lanes. */
static inline __mmask16 first_lanes(unsigned r) { return r >= 16u ? (__mmask16)0xffffu : (__mmask16)((1u << r) - 1u); }

/* Load n (1..16) xyz triples, stride bytes apart, as x, y, z vectors (lanes past n are 0). */
AKP_AVX512_INLINE static inline void load_xyz16(const char* p, size_t stride, unsigned n, __m512* x, __m512* y,
                                                 __m512* z) {
    if (stride == 12) {
        const float* f = (const float*)(const void*)p;
        __m512 a, b, c;
        if (n == 16) {
            a = _mm512_loadu_ps(f), b = _mm512_loadu_ps(f + 16), c = _mm512_loadu_ps(f + 32);
        } else { /* masked lanes are neither read nor faulted */
            const unsigned r = 3u * n;
            a = _mm512_maskz_loadu_ps(first_lanes(r), f);
            b = _mm512_maskz_loadu_ps(first_lanes(r > 16u ? r - 16u : 0u), f + 16);
            c = _mm512_maskz_loadu_ps(first_lanes(r > 32u ? r - 32u : 0u), f + 32);
        }
        *x = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, idx16(deint_idx[0][0]), b), idx16(deint_idx[0][1]), c);
        *y = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, idx16(deint_idx[1][0]), b), idx16(deint_idx[1][1]), c);
        *z = _mm512_permutex2var_ps(_mm512_permutex2var_ps(a, idx16(deint_idx[2][0]), b), idx16(deint_idx[2][1]), c);
        return;
    }
    float v[3][16] = {{0}};
    for (unsigned i = 0; i < n; ++i) {
        float t[3];
        memcpy(t, p + (size_t)i * stride, 12);
        v[0][i] = t[0], v[1][i] = t[1], v[2][i] = t[2];
    }
    *x = _mm512_loadu_ps(v[0]);
    *y = _mm512_loadu_ps(v[1]);
    *z = _mm512_loadu_ps(v[2]);
}

/* Inverse of load_xyz16: stores n (1..16) triples. */
AKP_AVX512_INLINE static inline void store_xyz16(char* p, size_t stride, unsigned n, __m512 x, __m512 y, __m512 z) {
    if (stride == 12) {
        float* f = (float*)(void*)p;
        const __m512 a = _mm512_permutex2var_ps(_mm512_permutex2var_ps(x, idx16(int_idx[0][0]), y), idx16(int_idx[0][1]), z);
        const __m512 b = _mm512_permutex2var_ps(_mm512_permutex2var_ps(x, idx16(int_idx[1][0]), y), idx16(int_idx[1][1]), z);
        const __m512 c = _mm512_permutex2var_ps(_mm512_permutex2var_ps(x, idx16(int_idx[2][0]), y), idx16(int_idx[2][1]), z);
        if (n == 16) {
            _mm512_storeu_ps(f, a), _mm512_storeu_ps(f + 16, b), _mm512_storeu_ps(f + 32, c);
        } else {
            const unsigned r = 3u * n;
            _mm512_mask_storeu_ps(f, first_lanes(r), a);
            _mm512_mask_storeu_ps(f + 16, first_lanes(r > 16u ? r - 16u : 0u), b);
            _mm512_mask_storeu_ps(f + 32, first_lanes(r > 32u ? r - 32u : 0u), c);
        }
        return;
    }
    float v[3][16];
    _mm512_storeu_ps(v[0], x);
    _mm512_storeu_ps(v[1], y);
    _mm512_storeu_ps(v[2], z);
    for (unsigned i = 0; i < n; ++i) {
        float t[3] = {v[0][i], v[1][i], v[2][i]};
        memcpy(p + (size_t)i * stride, t, 12);
    }
}

/* Rows r[v] = (8 floats of vertex v | 8 floats of vertex v + 8), v = 0..7, into columns o[e]
 * (element e of vertices 0..15). */
AKP_AVX512_INLINE static inline void transpose8x2(const __m512* r, __m512* o) {
    __m512 t0 = _mm512_unpacklo_ps(r[0], r[1]), t1 = _mm512_unpackhi_ps(r[0], r[1]);
    __m512 t2 = _mm512_unpacklo_ps(r[2], r[3]), t3 = _mm512_unpackhi_ps(r[2], r[3]);
    __m512 t4 = _mm512_unpacklo_ps(r[4], r[5]), t5 = _mm512_unpackhi_ps(r[4], r[5]);
    __m512 t6 = _mm512_unpacklo_ps(r[6], r[7]), t7 = _mm512_unpackhi_ps(r[6], r[7]);
    __m512 s0 = _mm512_shuffle_ps(t0, t2, 0x44), s1 = _mm512_shuffle_ps(t0, t2, 0xEE);
    __m512 s2 = _mm512_shuffle_ps(t1, t3, 0x44), s3 = _mm512_shuffle_ps(t1, t3, 0xEE);
    __m512 s4 = _mm512_shuffle_ps(t4, t6, 0x44), s5 = _mm512_shuffle_ps(t4, t6, 0xEE);
    __m512 s6 = _mm512_shuffle_ps(t5, t7, 0x44), s7 = _mm512_shuffle_ps(t5, t7, 0xEE);
    const __m512i lo = idx16(tr_lo_idx), hi = idx16(tr_hi_idx);
    o[0] = _mm512_permutex2var_ps(s0, lo, s4);
    o[1] = _mm512_permutex2var_ps(s1, lo, s5);
    o[2] = _mm512_permutex2var_ps(s2, lo, s6);
    o[3] = _mm512_permutex2var_ps(s3, lo, s7);
    o[4] = _mm512_permutex2var_ps(s0, hi, s4);
    o[5] = _mm512_permutex2var_ps(s1, hi, s5);
    o[6] = _mm512_permutex2var_ps(s2, hi, s6);
    o[7] = _mm512_permutex2var_ps(s3, hi, s7);
}

/* The blended 4x4 matrices (columns of 4) of vertices v and v + 8 as rows for transpose8x2:
 * columns 0, 1 and columns 2, 3 of both (after the transposes: a, b, c the linear columns, t
 * the translation, and the w rows, where CoR keeps its rotation). */
AKP_AVX512_INLINE static inline void pair_rows(__m512 a, __m512 b, __m512* r01, __m512* r23) {
    *r01 = _mm512_shuffle_f32x4(a, b, 0x44);
    *r23 = _mm512_shuffle_f32x4(a, b, 0xEE);
}

#define AKP_CROSS16(ax, ay, az, bx, by, bz, ox, oy, oz)                                    \
    do {                                                                                   \
        ox = _mm512_fmsub_ps(ay, bz, _mm512_mul_ps(az, by));                               \
        oy = _mm512_fmsub_ps(az, bx, _mm512_mul_ps(ax, bz));                               \
        oz = _mm512_fmsub_ps(ax, by, _mm512_mul_ps(ay, bx));                               \
    } while (0)

/* (x, y, z) / |(x, y, z)| with rsqrt14 + one Newton step, negated in the lanes of flip; a
 * zero vector stays zero. */
AKP_AVX512_INLINE static inline void normalize16_signed(__m512* x, __m512* y, __m512* z, __mmask16 flip) {
    __m512 l2 = _mm512_fmadd_ps(*x, *x, _mm512_fmadd_ps(*y, *y, _mm512_mul_ps(*z, *z)));
    l2 = _mm512_max_ps(l2, _mm512_set1_ps(1e-30f));
    const __m512 r = _mm512_rsqrt14_ps(l2), a = _mm512_mul_ps(_mm512_set1_ps(0.5f), l2);
    /* v r (1.5 - 0.5 l2 r^2), v r beside the Newton factor (as normalize8_signed in
     * deform_avx2.c) */
    __m512 t = _mm512_fnmadd_ps(a, _mm512_mul_ps(r, r), _mm512_set1_ps(1.5f));
    t = _mm512_mask_sub_ps(t, flip, _mm512_setzero_ps(), t);
    *x = _mm512_mul_ps(_mm512_mul_ps(*x, r), t);
    *y = _mm512_mul_ps(_mm512_mul_ps(*y, r), t);
    *z = _mm512_mul_ps(_mm512_mul_ps(*z, r), t);
}

/* 2 / |q|^2, and 0 where the blend vanished (|q|^2 <= 1e-30: the scalar code's identity). */
AKP_AVX512_INLINE static inline __m512 quat_scale16(__m512 x, __m512 y, __m512 z, __m512 w) {
    __m512 n2 = _mm512_fmadd_ps(x, x, _mm512_fmadd_ps(y, y, _mm512_fmadd_ps(z, z, _mm512_mul_ps(w, w))));
    __mmask16 ok = _mm512_cmp_ps_mask(n2, _mm512_set1_ps(1e-30f), _CMP_GT_OQ);
    return _mm512_maskz_div_ps(ok, _mm512_set1_ps(2.0f), n2);
}

/* p + s (w (v x p) + v x (v x p)): rotation by q / |q| given s = 2 / |q|^2. */
AKP_AVX512_INLINE static inline void rotate16_scaled(__m512 qx, __m512 qy, __m512 qz, __m512 qw, __m512 s,
                                                     __m512* px, __m512* py, __m512* pz) {
    __m512 tx, ty, tz, ux, uy, uz;
    AKP_CROSS16(qx, qy, qz, *px, *py, *pz, tx, ty, tz);
    AKP_CROSS16(qx, qy, qz, tx, ty, tz, ux, uy, uz);
    *px = _mm512_fmadd_ps(s, _mm512_fmadd_ps(qw, tx, ux), *px);
    *py = _mm512_fmadd_ps(s, _mm512_fmadd_ps(qw, ty, uy), *py);
    *pz = _mm512_fmadd_ps(s, _mm512_fmadd_ps(qw, tz, uz), *pz);
}

static inline uint32_t clamp_joint(uint32_t j, size_t count) { return j < count ? j : (uint32_t)(count - 1); }

/* One float at p (any alignment). */
static inline float load_f32(const char* p) {
    float f;
    memcpy(&f, p, sizeof f);
    return f;
}

/* Joints (clamped) and weights of vertex i. */
static inline void load_influences(const akp_skin_ctx* c, size_t i, const uint32_t K, uint32_t* jj, float* ww) {
    const char* jp = c->jnt + i * c->jnt_stride;
    const char* wp = c->wgt + i * c->wgt_stride;
    for (uint32_t k = 0; k < K; ++k) {
        uint16_t j;
        memcpy(&j, jp + 2u * k, sizeof j);
        memcpy(&ww[k], wp + 4u * k, sizeof(float));
        jj[k] = clamp_joint(j, c->palette_count);
    }
}

/* LBS: the weighted sum of the vertex's palette matrices, one 64-byte load per influence. */
AKP_AVX512_INLINE static inline __m512 blend_matrix(const akp_skin_ctx* c, size_t i, const uint32_t K) {
    uint32_t jj[AK_MAX_INFLUENCES];
    float ww[AK_MAX_INFLUENCES];
    load_influences(c, i, K, jj, ww);
    __m512 acc = _mm512_mul_ps(_mm512_loadu_ps(c->palette[jj[0]].m), _mm512_set1_ps(ww[0]));
    for (uint32_t k = 1; k < K; ++k)
        acc = _mm512_fmadd_ps(_mm512_loadu_ps(c->palette[jj[k]].m), _mm512_set1_ps(ww[k]), acc);
    return acc;
}

/* Hemisphere flags of vertex (joints jj, weights ww): bit k set when rotation k's dot product
 * with the reference (the rotation of the largest weight, lowest slot on ties) is < 0. */
AKP_AVX512_INLINE static inline uint32_t hemisphere_flags(const akp_skin_ctx* c, const uint32_t* jj, const float* ww,
                                                          const uint32_t K) {
    uint32_t best = 0;
    for (uint32_t k = 1; k < K; ++k) best = ww[k] > ww[best] ? k : best;
    const akp_skin_joint* jp = c->joints_prep;
    const __m512 ref = _mm512_broadcast_f32x4(_mm_loadu_ps(jp[jj[best]].real));
#define AKP_REAL(k) _mm_loadu_ps(jp[jj[k]].real)
    /* rotations 0..3 (and 4..7) in 128-bit lanes; unused lanes stay zero (dot 0: no flag) */
    __m512 lo = _mm512_maskz_mov_ps(0x000f, _mm512_castps128_ps512(AKP_REAL(0)));
    if (K > 1) lo = _mm512_insertf32x4(lo, AKP_REAL(1), 1);
    if (K > 2) lo = _mm512_insertf32x4(lo, AKP_REAL(2), 2);
    if (K > 3) lo = _mm512_insertf32x4(lo, AKP_REAL(3), 3);
    __m512 m = _mm512_mul_ps(lo, ref);
    m = _mm512_add_ps(m, _mm512_permute_ps(m, 0xB1));
    m = _mm512_add_ps(m, _mm512_permute_ps(m, 0x4E));
    uint32_t neg = (uint32_t)_mm512_cmp_ps_mask(m, _mm512_setzero_ps(), _CMP_LT_OQ);
    if (K > 4) {
        __m512 hi = _mm512_maskz_mov_ps(0x000f, _mm512_castps128_ps512(AKP_REAL(4)));
        if (K > 5) hi = _mm512_insertf32x4(hi, AKP_REAL(5), 1);
        if (K > 6) hi = _mm512_insertf32x4(hi, AKP_REAL(6), 2);
        if (K > 7) hi = _mm512_insertf32x4(hi, AKP_REAL(7), 3);
        __m512 mh = _mm512_mul_ps(hi, ref);
        mh = _mm512_add_ps(mh, _mm512_permute_ps(mh, 0xB1));
        mh = _mm512_add_ps(mh, _mm512_permute_ps(mh, 0x4E));
        neg |= (uint32_t)_mm512_cmp_ps_mask(mh, _mm512_setzero_ps(), _CMP_LT_OQ) << 16;
    }
#undef AKP_REAL
    /* bit 4k of the lane masks -> bit k */
    uint32_t flags = 0;
    for (uint32_t k = 0; k < K; ++k) flags |= ((neg >> (4u * k)) & 1u) << k;
    return flags;
}

/* DQS: the hemisphere-aligned sum of signed weight * (real | dual). */
AKP_AVX512_INLINE static inline __m256 blend_dq(const akp_skin_ctx* c, size_t i, const uint32_t K) {
    uint32_t jj[AK_MAX_INFLUENCES];
    float ww[AK_MAX_INFLUENCES];
    load_influences(c, i, K, jj, ww);
    const uint32_t flags = hemisphere_flags(c, jj, ww, K);
    __m256 acc = _mm256_setzero_ps();
    for (uint32_t k = 0; k < K; ++k) {
        uint32_t bits;
        memcpy(&bits, &ww[k], 4);
        bits ^= ((flags >> k) & 1u) << 31;
        float sw;
        memcpy(&sw, &bits, 4);
        acc = _mm256_fmadd_ps(_mm256_loadu_ps(c->joints_prep[jj[k]].real), _mm256_set1_ps(sw), acc);
    }
    return acc;
}

/* CoR: the weighted sum of the joints' cor_rows, each taken from the copy whose rotation (w
 * lanes) is on the reference's hemisphere. */
AKP_AVX512_INLINE static inline __m512 blend_cor(const akp_skin_ctx* c, size_t i, const uint32_t K) {
    uint32_t jj[AK_MAX_INFLUENCES];
    float ww[AK_MAX_INFLUENCES];
    load_influences(c, i, K, jj, ww);
    const uint32_t flags = hemisphere_flags(c, jj, ww, K);
    akp_skin_joint* prep = (akp_skin_joint*)(uintptr_t)c->joints_prep; /* read only */
    __m512 acc = _mm512_setzero_ps();
    for (uint32_t k = 0; k < K; ++k) {
        const float* pos = prep[jj[k]].cor_rows;
        const float* neg = akp_skin_cor_neg_rows(prep, c->palette_count, jj[k]);
        const float* row = ((flags >> k) & 1u) ? neg : pos;
        acc = _mm512_fmadd_ps(_mm512_loadu_ps(row), _mm512_set1_ps(ww[k]), acc);
    }
    return acc;
}

/* The weighted sum of the K palette matrices at base + the byte offsets off (joint_offsets
 * layout) with the weights of vertex i. Each weight is broadcast straight from memory and each
 * offset is its own 32-bit load: read as one 64-bit word (the weights, the offsets in pairs),
 * they cost a move, a shift and a register broadcast each, a third of the blend's instructions
 * (Zen 5, 100k vertices, LBS with normals, 2 influences: 1.32x -> 1.48x ozz's rate). CoR keeps
 * the word reads: see blend_cor_rows_at. */
AKP_AVX512_INLINE static inline __m512 blend_rows_at(const akp_skin_ctx* c, size_t i, const char* base,
                                                     const uint32_t* off, const uint32_t K) {
    const char* wp = c->wgt + i * c->wgt_stride;
#define AKP_ROW(k) _mm512_loadu_ps((const float*)(const void*)(base + (size_t)off[k]))
#define AKP_W(k) _mm512_set1_ps(load_f32(wp + 4u * (k)))
    __m512 acc = _mm512_mul_ps(AKP_ROW(0), AKP_W(0));
    for (uint32_t k = 1; k < K; ++k) acc = _mm512_fmadd_ps(AKP_ROW(k), AKP_W(k), acc);
#undef AKP_ROW
#undef AKP_W
    return acc;
}

/* The same blend for CoR's rows, with the weights read as one word and the offsets in pairs
 * (vertex_offsets): the per-load form above made CoR 4% slower (224 -> 216 M vertices/s, 4
 * influences, 100k vertices, Zen 5), where LBS gained 10%. */
AKP_AVX512_INLINE static inline __m512 blend_cor_rows_at(const akp_skin_ctx* c, size_t i, const char* base,
                                                         const uint32_t* off, const uint32_t K) {
    float ww[AK_MAX_INFLUENCES];
    memcpy(ww, c->wgt + i * c->wgt_stride, 4u * K);
    size_t o[8];
    vertex_offsets(off, o, K);
    __m512 acc = _mm512_mul_ps(_mm512_loadu_ps((const float*)(const void*)(base + o[0])), _mm512_set1_ps(ww[0]));
    for (uint32_t k = 1; k < K; ++k)
        acc = _mm512_fmadd_ps(_mm512_loadu_ps((const float*)(const void*)(base + o[k])), _mm512_set1_ps(ww[k]), acc);
    return acc;
}

/* Phase-1 data of 16 vertices: two AVX2 blocks of 8 (dq_prep: offsets, signed weights). */
typedef struct prep16 {
    dq_prep h[2];
} prep16;
#define AKP_OFF(p, v, K) ((p)->h[(v) / 8u].off + AKP_SLOTS(K) * ((v) % 8u))
#define AKP_SW(p, v, K) ((p)->h[(v) / 8u].sw + AKP_SLOTS(K) * ((v) % 8u))

/* One block of n (1..16) vertices at i0; p: for a whole block with 2, 3, 4 or 8 influences,
 * the palette offsets (joint_offsets, AKP_MAT_SHIFT) computed ahead, else NULL. */
/* The rest of an LBS block once its 16 matrices are blended (rows r01, r23 of pair_rows):
 * transpose, transform the positions, and the normals by the cofactor matrix, renormalised. */
AKP_AVX512_INLINE static inline void lbs_finish(const akp_skin_ctx* c, size_t i0, unsigned n, const __m512* r01,
                                                const __m512* r23) {
    __m512 k01[8], k23[8];
    transpose8x2(r01, k01);
    transpose8x2(r23, k23);
    const __m512 ax = k01[0], ay = k01[1], az = k01[2], bx = k01[4], by = k01[5], bz = k01[6];
    const __m512 cx = k23[0], cy = k23[1], cz = k23[2], tx = k23[4], ty = k23[5], tz = k23[6];
    __m512 px, py, pz;
    load_xyz16(c->pos + i0 * c->pos_stride, c->pos_stride, n, &px, &py, &pz);
    __m512 ox = _mm512_fmadd_ps(ax, px, _mm512_fmadd_ps(bx, py, _mm512_fmadd_ps(cx, pz, tx)));
    __m512 oy = _mm512_fmadd_ps(ay, px, _mm512_fmadd_ps(by, py, _mm512_fmadd_ps(cy, pz, ty)));
    __m512 oz = _mm512_fmadd_ps(az, px, _mm512_fmadd_ps(bz, py, _mm512_fmadd_ps(cz, pz, tz)));
    store_xyz16(c->out_pos + i0 * c->out_pos_stride, c->out_pos_stride, n, ox, oy, oz);
    if (!c->do_normals) return;
    __m512 nx, ny, nz, k0x, k0y, k0z, k1x, k1y, k1z;
    load_xyz16(c->nrm + i0 * c->nrm_stride, c->nrm_stride, n, &nx, &ny, &nz);
    /* cof(M) n = nx (b x c) + (ny c - nz b) x a (as deform_avx2.c); sign(det) on the Newton
     * factor */
    AKP_CROSS16(bx, by, bz, cx, cy, cz, k0x, k0y, k0z);
    const __m512 ux = _mm512_fmsub_ps(ny, cx, _mm512_mul_ps(nz, bx));
    const __m512 uy = _mm512_fmsub_ps(ny, cy, _mm512_mul_ps(nz, by));
    const __m512 uz = _mm512_fmsub_ps(ny, cz, _mm512_mul_ps(nz, bz));
    AKP_CROSS16(ux, uy, uz, ax, ay, az, k1x, k1y, k1z);
    const __m512 det = _mm512_fmadd_ps(ax, k0x, _mm512_fmadd_ps(ay, k0y, _mm512_mul_ps(az, k0z)));
    __m512 mx = _mm512_fmadd_ps(k0x, nx, k1x), my = _mm512_fmadd_ps(k0y, nx, k1y), mz = _mm512_fmadd_ps(k0z, nx, k1z);
    normalize16_signed(&mx, &my, &mz, _mm512_cmp_ps_mask(det, _mm512_setzero_ps(), _CMP_LT_OQ));
    store_xyz16(c->out_nrm + i0 * c->out_nrm_stride, c->out_nrm_stride, n, mx, my, mz);
}

AKP_AVX512_INLINE static inline void block_lbs(const akp_skin_ctx* c, size_t i0, unsigned n, const uint32_t K,
                                               const prep16* p, prep16* next, size_t i_next) {
    __m512 r01[8], r23[8], lo[8];
    if (p) { /* the next block's offsets (when given) in two halves between the blends */
        if (next) joint_offsets(c, i_next, AKP_MAT_SHIFT, next->h[0].off, K);
        for (unsigned v = 0; v < 8; ++v) lo[v] = blend_rows_at(c, i0 + v, (const char*)c->palette, AKP_OFF(p, v, K), K);
        if (next) joint_offsets(c, i_next + 8, AKP_MAT_SHIFT, next->h[1].off, K);
    }
    for (unsigned v = 0; v < 8; ++v) { /* v and v + 8 in turn: each pair goes to the rows at once */
        __m512 a, b;
        if (p) {
            a = lo[v];
            b = blend_rows_at(c, i0 + v + 8, (const char*)c->palette, AKP_OFF(p, v + 8, K), K);
        } else {
            a = v < n ? blend_matrix(c, i0 + v, K) : _mm512_setzero_ps();
            b = v + 8 < n ? blend_matrix(c, i0 + v + 8, K) : _mm512_setzero_ps();
        }
        pair_rows(a, b, &r01[v], &r23[v]);
    }
    lbs_finish(c, i0, n, r01, r23);
}

/* Packed joints and weights (strides 2 K and 4 K bytes), K = 2, 4 or 8: the palette byte
 * offsets of 16 vertices, off[K v + k], from K loads of 16 indices (widen, clamp, shift)
 * instead of joint_offsets' two loads, an unpack and a convert per pair of vertices, and the
 * weights at constant offsets from the block's (no address per vertex). Against ozz, LBS with
 * normals, 100k vertices, Zen 5: 2 / 4 / 8 influences 1.46 / 1.70 / 1.49x -> 1.72 / 1.76 /
 * 1.59x ozz's rate. */
typedef struct dense16 {
    uint32_t off[16 * 8];
} dense16;
AKP_AVX512_INLINE static inline void offsets16_dense(const akp_skin_ctx* c, size_t i0, dense16* d, const uint32_t K) {
    const char* jp = c->jnt + i0 * 2u * K;
    const size_t last = c->palette_count - 1;
    const __m512i lim = _mm512_set1_epi32((int)(last > 65535u ? 65535u : last));
    for (uint32_t q = 0; q < K; ++q) {
        const __m512i j = _mm512_cvtepu16_epi32(_mm256_loadu_si256((const __m256i*)(const void*)(jp + 32u * q)));
        _mm512_storeu_si512((void*)(d->off + 16u * q), _mm512_slli_epi32(_mm512_min_epu32(j, lim), AKP_MAT_SHIFT));
    }
}

/* A whole block of packed data (offsets16_dense), with the next block's offsets (when next)
 * computed between the blends; vertex v's weights are 4 K v bytes after the block's. */
AKP_AVX512_INLINE static inline void block_lbs_dense(const akp_skin_ctx* c, size_t i0, const uint32_t K,
                                                     const dense16* d, dense16* next, size_t i_next) {
    __m512 r01[8], r23[8], lo[8];
    const char* base = (const char*)c->palette;
    const char* wb = c->wgt + i0 * 4u * K;
#define AKP_ROW(v, k) _mm512_loadu_ps((const float*)(const void*)(base + (size_t)d->off[K * (v) + (k)]))
#define AKP_W(v, k) _mm512_set1_ps(load_f32(wb + 4u * (K * (v) + (k))))
#define AKP_BLEND(v, out)                                                                  \
    do {                                                                                   \
        __m512 acc_ = _mm512_mul_ps(AKP_ROW(v, 0), AKP_W(v, 0));                           \
        for (uint32_t k = 1; k < K; ++k) acc_ = _mm512_fmadd_ps(AKP_ROW(v, k), AKP_W(v, k), acc_); \
        out = acc_;                                                                        \
    } while (0)
    for (unsigned v = 0; v < 8; ++v) AKP_BLEND(v, lo[v]);
    if (next) offsets16_dense(c, i_next, next, K);
    for (unsigned v = 0; v < 8; ++v) {
        __m512 b;
        AKP_BLEND(v + 8, b);
        pair_rows(lo[v], b, &r01[v], &r23[v]);
    }
#undef AKP_BLEND
#undef AKP_W
#undef AKP_ROW
    lbs_finish(c, i0, 16u, r01, r23);
}

/* The palette matrix of vertex i's single joint (index clamped). */
AKP_AVX512_INLINE static inline __m512 joint_matrix(const akp_skin_ctx* c, size_t i) {
    uint16_t j;
    memcpy(&j, c->jnt + i * c->jnt_stride, sizeof j);
    return _mm512_loadu_ps(c->palette[clamp_joint(j, c->palette_count)].m);
}

/* LBS with 1 influence (ctx.rigid_single: no normals, or a rigid palette): p' = w (M p) and
 * n' = sign(w) R n, the scalar code's results without the blend, the cofactor and the
 * renormalisation (R is a rotation: a unit normal stays unit; w = 1 for checked data). */
AKP_AVX512_INLINE static inline void block_lbs_rigid1(const akp_skin_ctx* c, size_t i0, unsigned n) {
    __m512 r01[8], r23[8], k01[8], k23[8];
    const __m512 zero = _mm512_setzero_ps();
    for (unsigned v = 0; v < 8; ++v)
        pair_rows(v < n ? joint_matrix(c, i0 + v) : zero, v + 8 < n ? joint_matrix(c, i0 + v + 8) : zero, &r01[v],
                  &r23[v]);
    transpose8x2(r01, k01);
    transpose8x2(r23, k23);
    const __m512 ax = k01[0], ay = k01[1], az = k01[2], bx = k01[4], by = k01[5], bz = k01[6];
    const __m512 cx = k23[0], cy = k23[1], cz = k23[2], tx = k23[4], ty = k23[5], tz = k23[6];
    __m512 w;
    const float* wp = (const float*)(const void*)(c->wgt + i0 * c->wgt_stride);
    if (c->wgt_stride == 4) {
        w = n == 16 ? _mm512_loadu_ps(wp) : _mm512_maskz_loadu_ps(first_lanes(n), wp);
    } else {
        float t[16] = {0};
        for (unsigned v = 0; v < n; ++v) memcpy(&t[v], c->wgt + (i0 + v) * c->wgt_stride, 4);
        w = _mm512_loadu_ps(t);
    }
    __m512 px, py, pz;
    load_xyz16(c->pos + i0 * c->pos_stride, c->pos_stride, n, &px, &py, &pz);
    const __m512 ox = _mm512_mul_ps(w, _mm512_fmadd_ps(ax, px, _mm512_fmadd_ps(bx, py, _mm512_fmadd_ps(cx, pz, tx))));
    const __m512 oy = _mm512_mul_ps(w, _mm512_fmadd_ps(ay, px, _mm512_fmadd_ps(by, py, _mm512_fmadd_ps(cy, pz, ty))));
    const __m512 oz = _mm512_mul_ps(w, _mm512_fmadd_ps(az, px, _mm512_fmadd_ps(bz, py, _mm512_fmadd_ps(cz, pz, tz))));
    store_xyz16(c->out_pos + i0 * c->out_pos_stride, c->out_pos_stride, n, ox, oy, oz);
    if (!c->do_normals) return;
    __m512 nx, ny, nz;
    load_xyz16(c->nrm + i0 * c->nrm_stride, c->nrm_stride, n, &nx, &ny, &nz);
    /* sign(w): 0 where w is 0 (or NaN: only with unchecked data), negated where w < 0 */
    const __mmask16 keep = _mm512_cmp_ps_mask(w, zero, _CMP_NEQ_OQ), neg = _mm512_cmp_ps_mask(w, zero, _CMP_LT_OQ);
    __m512 mx = _mm512_maskz_mov_ps(keep, _mm512_fmadd_ps(ax, nx, _mm512_fmadd_ps(bx, ny, _mm512_mul_ps(cx, nz))));
    __m512 my = _mm512_maskz_mov_ps(keep, _mm512_fmadd_ps(ay, nx, _mm512_fmadd_ps(by, ny, _mm512_mul_ps(cy, nz))));
    __m512 mz = _mm512_maskz_mov_ps(keep, _mm512_fmadd_ps(az, nx, _mm512_fmadd_ps(bz, ny, _mm512_mul_ps(cz, nz))));
    mx = _mm512_mask_sub_ps(mx, neg, zero, mx);
    my = _mm512_mask_sub_ps(my, neg, zero, my);
    mz = _mm512_mask_sub_ps(mz, neg, zero, mz);
    store_xyz16(c->out_nrm + i0 * c->out_nrm_stride, c->out_nrm_stride, n, mx, my, mz);
}

/* p: for a whole block with 2, 3, 4 or 8 influences, phase 1 (dq_signs_block) run ahead;
 * else NULL (vertex by vertex). */
AKP_AVX512_INLINE static inline void block_dqs(const akp_skin_ctx* c, size_t i0, unsigned n, const uint32_t K,
                                               const prep16* p, prep16* next, size_t i_next, uint32_t neg) {
    __m256 b[16];
    if (p) { /* phase 1 of the next block (when given) in two halves between the accumulations */
        if (next) dq_signs_block(c, i_next, &next->h[0], neg, K);
        for (unsigned v = 0; v < 8; ++v) b[v] = dq_accumulate(c, AKP_OFF(p, v, K), AKP_SW(p, v, K), K);
        if (next) dq_signs_block(c, i_next + 8, &next->h[1], neg, K);
        for (unsigned v = 8; v < 16; ++v) b[v] = dq_accumulate(c, AKP_OFF(p, v, K), AKP_SW(p, v, K), K);
    } else {
        for (unsigned v = 0; v < 16; ++v) b[v] = v < n ? blend_dq(c, i0 + v, K) : _mm256_setzero_ps();
    }
    __m512 rows[8], q[8];
    for (int v = 0; v < 8; ++v) rows[v] = _mm512_insertf32x8(_mm512_castps256_ps512(b[v]), b[v + 8], 1);
    transpose8x2(rows, q);
    const __m512 qx = q[0], qy = q[1], qz = q[2], qw = q[3], dx = q[4], dy = q[5], dz = q[6], dw = q[7];
    const __m512 sc = quat_scale16(qx, qy, qz, qw);
    /* translation of the normalised dual quaternion: (2 / |q|^2) (w dv - dw v + v x dv) */
    __m512 cx, cy, cz;
    AKP_CROSS16(qx, qy, qz, dx, dy, dz, cx, cy, cz);
    const __m512 tx = _mm512_add_ps(_mm512_fmsub_ps(qw, dx, _mm512_mul_ps(dw, qx)), cx);
    const __m512 ty = _mm512_add_ps(_mm512_fmsub_ps(qw, dy, _mm512_mul_ps(dw, qy)), cy);
    const __m512 tz = _mm512_add_ps(_mm512_fmsub_ps(qw, dz, _mm512_mul_ps(dw, qz)), cz);
    __m512 px, py, pz;
    load_xyz16(c->pos + i0 * c->pos_stride, c->pos_stride, n, &px, &py, &pz);
    rotate16_scaled(qx, qy, qz, qw, sc, &px, &py, &pz);
    px = _mm512_fmadd_ps(sc, tx, px);
    py = _mm512_fmadd_ps(sc, ty, py);
    pz = _mm512_fmadd_ps(sc, tz, pz);
    store_xyz16(c->out_pos + i0 * c->out_pos_stride, c->out_pos_stride, n, px, py, pz);
    if (!c->do_normals) return;
    __m512 nx, ny, nz;
    load_xyz16(c->nrm + i0 * c->nrm_stride, c->nrm_stride, n, &nx, &ny, &nz);
    rotate16_scaled(qx, qy, qz, qw, sc, &nx, &ny, &nz); /* a rotation: lengths are kept */
    store_xyz16(c->out_nrm + i0 * c->out_nrm_stride, c->out_nrm_stride, n, nx, ny, nz);
}

/* p as for block_dqs; its offsets already point at the rows on the reference's hemisphere. */
AKP_AVX512_INLINE static inline void block_cor(const akp_skin_ctx* c, size_t i0, unsigned n, const uint32_t K,
                                               const prep16* p, prep16* next, size_t i_next, uint32_t neg) {
    __m512 r01[8], r23[8], k01[8], k23[8], lo[8];
    const char* rows = (const char*)c->joints_prep + offsetof(akp_skin_joint, cor_rows);
    if (p) { /* as block_dqs: the next block's phase 1 in two halves between the blends */
        if (next) dq_signs_block(c, i_next, &next->h[0], neg, K);
        for (unsigned v = 0; v < 8; ++v) lo[v] = blend_cor_rows_at(c, i0 + v, rows, AKP_OFF(p, v, K), K);
        if (next) dq_signs_block(c, i_next + 8, &next->h[1], neg, K);
    }
    for (unsigned v = 0; v < 8; ++v) {
        __m512 a, b;
        if (p) {
            a = lo[v];
            b = blend_cor_rows_at(c, i0 + v + 8, rows, AKP_OFF(p, v + 8, K), K);
        } else {
            a = v < n ? blend_cor(c, i0 + v, K) : _mm512_setzero_ps();
            b = v + 8 < n ? blend_cor(c, i0 + v + 8, K) : _mm512_setzero_ps();
        }
        pair_rows(a, b, &r01[v], &r23[v]);
    }
    transpose8x2(r01, k01);
    transpose8x2(r23, k23);
    const __m512 ax = k01[0], ay = k01[1], az = k01[2], bx = k01[4], by = k01[5], bz = k01[6];
    const __m512 cx = k23[0], cy = k23[1], cz = k23[2], tx = k23[4], ty = k23[5], tz = k23[6];
    const __m512 qx = k01[3], qy = k01[7], qz = k23[3], qw = k23[7];
    const __m512 sc = quat_scale16(qx, qy, qz, qw);
    __m512 sx, sy, sz, px, py, pz;
    load_xyz16(c->ctr + i0 * c->ctr_stride, c->ctr_stride, n, &sx, &sy, &sz);
    load_xyz16(c->pos + i0 * c->pos_stride, c->pos_stride, n, &px, &py, &pz);
    const __m512 mx = _mm512_fmadd_ps(ax, sx, _mm512_fmadd_ps(bx, sy, _mm512_fmadd_ps(cx, sz, tx)));
    const __m512 my = _mm512_fmadd_ps(ay, sx, _mm512_fmadd_ps(by, sy, _mm512_fmadd_ps(cy, sz, ty)));
    const __m512 mz = _mm512_fmadd_ps(az, sx, _mm512_fmadd_ps(bz, sy, _mm512_fmadd_ps(cz, sz, tz)));
    px = _mm512_sub_ps(px, sx);
    py = _mm512_sub_ps(py, sy);
    pz = _mm512_sub_ps(pz, sz);
    rotate16_scaled(qx, qy, qz, qw, sc, &px, &py, &pz);
    store_xyz16(c->out_pos + i0 * c->out_pos_stride, c->out_pos_stride, n, _mm512_add_ps(px, mx),
                _mm512_add_ps(py, my), _mm512_add_ps(pz, mz));
    if (!c->do_normals) return;
    __m512 nx, ny, nz;
    load_xyz16(c->nrm + i0 * c->nrm_stride, c->nrm_stride, n, &nx, &ny, &nz);
    rotate16_scaled(qx, qy, qz, qw, sc, &nx, &ny, &nz);
    store_xyz16(c->out_nrm + i0 * c->out_nrm_stride, c->out_nrm_stride, n, nx, ny, nz);
}

/* Block loops with the influence count a compile-time constant (the compiler unrolls the
 * blends). With 2, 3, 4 or 8 influences the whole blocks run pipelined as in the AVX2 kernel:
 * the joint offsets (SIMD, two AVX2 half-blocks) one block ahead for LBS; for DQS/CoR the
 * offsets two blocks and phase 1 (signs) one block ahead, three buffers in turn, so nothing is
 * read right after its vector store. The block functions run the next block's offsets (LBS) or
 * phase 1 (DQS/CoR) in two halves between their own blends: run whole before the block, as the
 * AVX2 loops do, a 16-vertex block left the out-of-order window too little to overlap (measured
 * in cache, 4 influences: LBS 0.97x, DQS 0.88x of AVX2; interleaved 1.25x and 1.06x). Other
 * counts, and the last partial block (which must not read past the range), run vertex by
 * vertex. */
AKP_AVX512_INLINE static inline void offsets16(const akp_skin_ctx* c, size_t i0, int shift, prep16* p,
                                               const uint32_t K) {
    joint_offsets(c, i0, shift, p->h[0].off, K);
    joint_offsets(c, i0 + 8, shift, p->h[1].off, K);
}
AKP_AVX512_INLINE static inline void signs16(const akp_skin_ctx* c, size_t i0, prep16* p, uint32_t neg,
                                             const uint32_t K) {
    dq_signs_block(c, i0, &p->h[0], neg, K);
    dq_signs_block(c, i0 + 8, &p->h[1], neg, K);
}
#define AKP_PIPELINED(K) ((K) == 2u || (K) == 3u || (K) == 4u || (K) == 8u)

AKP_AVX512_INLINE static inline void lbs_range_k(const akp_skin_ctx* c, size_t begin, size_t end, const uint32_t K) {
    const size_t full = begin + ((end - begin) & ~(size_t)15u);
    size_t i = begin;
    if ((K == 2u || K == 4u || K == 8u) && c->jnt_stride == 2u * K && c->wgt_stride == 4u * K && full > begin) {
        dense16 d[2];
        offsets16_dense(c, begin, &d[0], K);
        unsigned b = 0;
        for (; i < full; i += 16, b ^= 1u) block_lbs_dense(c, i, K, &d[b], i + 16 < full ? &d[b ^ 1u] : NULL, i + 16);
    } else if (AKP_PIPELINED(K) && full > begin) {
        prep16 p[2];
        offsets16(c, begin, AKP_MAT_SHIFT, &p[0], K);
        unsigned b = 0;
        for (; i < full; i += 16, b ^= 1u) block_lbs(c, i, 16u, K, &p[b], i + 16 < full ? &p[b ^ 1u] : NULL, i + 16);
    }
    for (; i + 16 <= end; i += 16) block_lbs(c, i, 16u, K, NULL, NULL, 0);
    if (i < end) block_lbs(c, i, (unsigned)(end - i), K, NULL, NULL, 0);
}

#define AKP_DQ_RANGE_K(fn)                                                                 \
    AKP_AVX512_INLINE static inline void fn##_range_k(const akp_skin_ctx* c, size_t begin, size_t end, uint32_t neg, \
                                                      const uint32_t K) {                 \
        const size_t full = begin + ((end - begin) & ~(size_t)15u);                        \
        size_t i = begin;                                                                  \
        if (AKP_PIPELINED(K) && full > begin) {                                            \
            prep16 p[3];                                                                   \
            offsets16(c, begin, AKP_JOINT_SHIFT, &p[0], K);                                \
            if (begin + 16 < full) offsets16(c, begin + 16, AKP_JOINT_SHIFT, &p[1], K);    \
            signs16(c, begin, &p[0], neg, K);                                              \
            unsigned b = 0;                                                                \
            for (; i < full; i += 16, b = b == 2u ? 0u : b + 1u) {                         \
                const unsigned b1 = b == 2u ? 0u : b + 1u, b2 = b1 == 2u ? 0u : b1 + 1u;   \
                if (i + 32 < full) offsets16(c, i + 32, AKP_JOINT_SHIFT, &p[b2], K);       \
                fn(c, i, 16u, K, &p[b], i + 16 < full ? &p[b1] : NULL, i + 16, neg);       \
            }                                                                              \
        }                                                                                  \
        for (; i + 16 <= end; i += 16) fn(c, i, 16u, K, NULL, NULL, 0, 0);                 \
        if (i < end) fn(c, i, (unsigned)(end - i), K, NULL, NULL, 0, 0);                   \
    }
AKP_DQ_RANGE_K(block_dqs)
AKP_DQ_RANGE_K(block_cor)

/* One function per method and influence count: the same loops as one function holding all
 * eight counts (one call per range more; bench_skin's rates did not move), but each small
 * enough for the compilers' register allocation and scheduling, whose cost grows faster than
 * the function. As three huge functions this file took 21.6 s of gcc -O3 CPU (11.9 s now) and
 * over 200 s of clang with ASan + UBSan + fuzzer coverage (106 s now): the last object of
 * CI's sanitizer build, with the other core idle. */
#define AKP_K_FUNCS(name, body)                                                            \
    AKP_AVX512 __attribute__((noinline)) static void name##_1(AKP_K_ARGS) { body(1u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_2(AKP_K_ARGS) { body(2u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_3(AKP_K_ARGS) { body(3u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_4(AKP_K_ARGS) { body(4u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_5(AKP_K_ARGS) { body(5u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_6(AKP_K_ARGS) { body(6u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_7(AKP_K_ARGS) { body(7u); }    \
    AKP_AVX512 __attribute__((noinline)) static void name##_8(AKP_K_ARGS) { body(8u); }
#define AKP_K_SWITCH(name, ...)                                                            \
    switch (c->k) {                                                                        \
    case 1: name##_1(__VA_ARGS__); break;                                                  \
    case 2: name##_2(__VA_ARGS__); break;                                                  \
    case 3: name##_3(__VA_ARGS__); break;                                                  \
    case 4: name##_4(__VA_ARGS__); break;                                                  \
    case 5: name##_5(__VA_ARGS__); break;                                                  \
    case 6: name##_6(__VA_ARGS__); break;                                                  \
    case 7: name##_7(__VA_ARGS__); break;                                                  \
    default: name##_8(__VA_ARGS__); break;                                                 \
    }
#define AKP_K_ARGS const akp_skin_ctx *c, size_t begin, size_t end, uint32_t neg
#define AKP_LBS_BODY(K) ((void)neg, lbs_range_k(c, begin, end, (K)))
#define AKP_DQS_BODY(K) block_dqs_range_k(c, begin, end, neg, (K))
#define AKP_COR_BODY(K) block_cor_range_k(c, begin, end, neg, (K))
AKP_K_FUNCS(lbs_k, AKP_LBS_BODY)
AKP_K_FUNCS(dqs_k, AKP_DQS_BODY)
AKP_K_FUNCS(cor_k, AKP_COR_BODY)
#undef AKP_K_ARGS

AKP_AVX512 static void lbs_range(const akp_skin_ctx* c, size_t begin, size_t end) {
    if (c->rigid_single) {
        size_t i = begin;
        for (; i + 16 <= end; i += 16) block_lbs_rigid1(c, i, 16u);
        if (i < end) block_lbs_rigid1(c, i, (unsigned)(end - i));
        return;
    }
    AKP_K_SWITCH(lbs_k, c, begin, end, 0u)
}
AKP_AVX512 static void dqs_range(const akp_skin_ctx* c, size_t begin, size_t end) {
    AKP_K_SWITCH(dqs_k, c, begin, end, 0u)
}
AKP_AVX512 static void cor_range(const akp_skin_ctx* c, size_t begin, size_t end) {
    /* offset from joint 0's cor_rows to joint 0's negated rows (see akp_skin_cor_neg_rows) */
    const uint32_t neg = (uint32_t)(c->palette_count * sizeof(akp_skin_joint) - offsetof(akp_skin_joint, cor_rows));
    AKP_K_SWITCH(cor_k, c, begin, end, neg)
}

bool akp_skin_range_avx512(const akp_skin_ctx* c, size_t begin, size_t end) {
    if (c->do_tangents || !akp_skin_have_avx512()) return false;
    if (c->method != AK_SKIN_LBS && c->any_stretch) return false;
    /* DQS/CoR address their per-joint records with 32-bit offsets (as the AVX2 kernel) */
    if (c->method != AK_SKIN_LBS && c->palette_count > 65536u) return false;
    if (end <= begin) return true;
    if (c->method == AK_SKIN_LBS) lbs_range(c, begin, end);
    else if (c->method == AK_SKIN_DQS) dqs_range(c, begin, end);
    else cor_range(c, begin, end);
    return true;
}

#else /* no AVX-512 kernel in this build */

bool akp_skin_have_avx512(void) { return false; }
bool akp_skin_range_avx512(const akp_skin_ctx* c, size_t begin, size_t end) {
    (void)c;
    (void)begin;
    (void)end;
    return false;
}

#endif
