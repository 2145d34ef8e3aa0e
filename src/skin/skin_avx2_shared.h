/* AVX2 helpers shared by the AVX2 kernel (deform_avx2.c) and the AVX-512 kernel
 * (deform_avx512.c, which runs them inside its own target: AVX-512 includes AVX2): the joint
 * offsets of 8 vertices computed with SIMD, and phase 1 of DQS/CoR (the hemisphere signs of 8
 * vertices). Included only where AKP_AVX2_INLINE is defined; never installed. */
#ifndef ANIMKIT_SKIN_AVX2_SHARED_H
#define ANIMKIT_SKIN_AVX2_SHARED_H

#include <immintrin.h>

#include "skin_internal.h"

/* The byte offsets (joint index clamped to the palette, shifted left by shift) of the 8
 * vertices of the block at i0, off[AKP_SLOTS(K) v + k], K = 2, 3, 4 or 8 (slots past K are
 * joint 0): two vertices per SIMD step (one with 8 influences) instead of a compare, select,
 * shift and add per influence. */
_Static_assert(sizeof(ak_mat4) == 64 && sizeof(akp_skin_joint) == 128, "offset shifts below");
#define AKP_MAT_SHIFT 6
#define AKP_JOINT_SHIFT 7
/* The K (2..4) joint indices of the vertex at p in the low 64 bits, zero-padded to 4 (joint 0,
 * which the zero-padded weights of load_weights4 give no weight): never reads past them. */
AKP_AVX2_INLINE static inline __m128i load_joints4(const char* p, const uint32_t K) {
    if (K == 4) return _mm_loadl_epi64((const __m128i*)(const void*)p);
    uint32_t lo;
    memcpy(&lo, p, 4);
    if (K == 2) return _mm_cvtsi32_si128((int)lo);
    uint16_t hi; /* K == 3; one 6-byte copy into a zeroed word would stall on store forwarding */
    memcpy(&hi, p + 4, 2);
    return _mm_insert_epi16(_mm_cvtsi32_si128((int)lo), hi, 2);
}

/* The K (2..4) weights of the vertex at p, zero-padded to 4 lanes (a masked load: the lanes
 * past K are neither read nor faulted). */
AKP_AVX2_INLINE static inline __m128 load_weights4(const char* p, const uint32_t K) {
    if (K == 4) return _mm_loadu_ps((const float*)(const void*)p);
    const __m128i mask = _mm_setr_epi32(-1, -1, K > 2 ? -1 : 0, 0);
    return _mm_maskload_ps((const float*)(const void*)p, mask);
}

/* Offset slots per vertex in the pipelined paths: 4 for 2..4 influences, 8 for 8. */
#define AKP_SLOTS(K) ((K) <= 4u ? 4u : 8u)

AKP_AVX2_INLINE static inline void joint_offsets(const akp_skin_ctx* c, size_t i0, int shift, uint32_t* off,
                                                  const uint32_t K) {
    const char* jp = c->jnt + i0 * c->jnt_stride;
    const size_t js = c->jnt_stride;
    const size_t last = c->palette_count - 1;
    const __m128i lim = _mm_set1_epi16((short)(uint16_t)(last > 65535u ? 65535u : last));
    const __m128i count = _mm_cvtsi32_si128(shift);
    if (K == 8) { /* one vertex per step */
        for (int v = 0; v < 8; ++v) {
            __m128i j = _mm_min_epu16(_mm_loadu_si128((const __m128i*)(const void*)(jp + (size_t)v * js)), lim);
            _mm256_storeu_si256((__m256i*)(void*)(off + 8 * v), _mm256_sll_epi32(_mm256_cvtepu16_epi32(j), count));
        }
        return;
    }
    for (int h = 0; h < 4; ++h) {
        __m128i a = load_joints4(jp + (size_t)(2 * h) * js, K);
        __m128i b = load_joints4(jp + (size_t)(2 * h + 1) * js, K);
        __m128i j = _mm_min_epu16(_mm_unpacklo_epi64(a, b), lim);
        _mm256_storeu_si256((__m256i*)(void*)(off + 8 * h), _mm256_sll_epi32(_mm256_cvtepu16_epi32(j), count));
    }
}

/* The AKP_SLOTS(K) byte offsets of a vertex, read two per 64-bit load (fewer load operations
 * for the blends). */
static inline void vertex_offsets(const uint32_t* off, size_t* o, const uint32_t K) {
    for (uint32_t k = 0; k < AKP_SLOTS(K); k += 2) {
        uint64_t pair;
        memcpy(&pair, off + k, 8);
        o[k] = (uint32_t)pair, o[k + 1] = (size_t)(pair >> 32);
    }
}

/* The rotations (first 4 floats of the joint records at jb + off[k] and jb + off[4 + k]) in
 * the low and high 128-bit lanes. */
AKP_AVX2_INLINE static inline __m256 quat_pair(const char* jb, const uint32_t* off, int k) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps((const float*)(const void*)(jb + off[k]))),
                                _mm_loadu_ps((const float*)(const void*)(jb + off[4 + k])), 1);
}

/* End of phase 1 for the 8 slots at off/sw with weights w8 and dots (negative: the slot's
 * rotation is on the other hemisphere from the reference). DQS: the signed weights to sw.
 * CoR (cor_neg != 0): point the offsets of negative slots at the joint's negated rows instead,
 * (count * 128 - 32) + j * 64 from the cor_rows of joint 0. */
AKP_AVX2_INLINE static inline void store_signs(uint32_t* off, float* sw, __m256 w8, __m256 dots, uint32_t cor_neg) {
    if (cor_neg) {
        const __m256i o = _mm256_loadu_si256((const __m256i*)(const void*)off);
        const __m256i neg = _mm256_add_epi32(_mm256_srli_epi32(o, 1), _mm256_set1_epi32((int)cor_neg));
        _mm256_storeu_si256((__m256i*)(void*)off,
                            _mm256_castps_si256(_mm256_blendv_ps(_mm256_castsi256_ps(o), _mm256_castsi256_ps(neg), dots)));
        return;
    }
    _mm256_storeu_ps(sw, _mm256_xor_ps(w8, _mm256_and_ps(dots, _mm256_set1_ps(-0.0f))));
}

/* The same for exactly 4 influences, in two phases so that a block can run the long
 * dependency chain (argmax -> reference -> dots -> signs) of all 8 vertices before the
 * blends. Phase 1, for vertices i and i + 1 at once (one per 128-bit lane): the signed
 * weights, from the joint offsets off (joint_offsets, AKP_JOINT_SHIFT); off[0..3], sw[0..3]
 * belong to vertex i and off[4..7], sw[4..7] to vertex i + 1. The reference is the rotation
 * of the largest weight (lowest slot on ties), picked with blends: no branch and no index
 * round trip through memory. */
AKP_AVX2_INLINE static inline void dq_signs4x2(const akp_skin_ctx* c, size_t i, uint32_t* off, float* sw,
                                               uint32_t cor_neg, const uint32_t K) {
    const char* wp = c->wgt + i * c->wgt_stride;
    const char* jb = (const char*)c->joints_prep;
    __m256 r[4];
    for (int k = 0; k < 4; ++k) r[k] = quat_pair(jb, off, k);
    const __m256 w8 = _mm256_insertf128_ps(_mm256_castps128_ps256(load_weights4(wp, K)),
                                           load_weights4(wp + c->wgt_stride, K), 1);
    __m256 mx = _mm256_max_ps(w8, _mm256_permute_ps(w8, _MM_SHUFFLE(2, 3, 0, 1)));
    mx = _mm256_max_ps(mx, _mm256_permute_ps(mx, _MM_SHUFFLE(1, 0, 3, 2)));
    const __m256 is_max = _mm256_cmp_ps(w8, mx, _CMP_EQ_OQ);
    __m256 ref = r[3];
    ref = _mm256_blendv_ps(ref, r[2], _mm256_permute_ps(is_max, _MM_SHUFFLE(2, 2, 2, 2)));
    ref = _mm256_blendv_ps(ref, r[1], _mm256_permute_ps(is_max, _MM_SHUFFLE(1, 1, 1, 1)));
    ref = _mm256_blendv_ps(ref, r[0], _mm256_permute_ps(is_max, _MM_SHUFFLE(0, 0, 0, 0)));
    __m256 dots = _mm256_hadd_ps(_mm256_hadd_ps(_mm256_mul_ps(r[0], ref), _mm256_mul_ps(r[1], ref)),
                                 _mm256_hadd_ps(_mm256_mul_ps(r[2], ref), _mm256_mul_ps(r[3], ref)));
    store_signs(off, sw, w8, dots, cor_neg);
}

/* Phase 2: sum of signed weight * (real | dual); broadcasts from memory are plain loads. */
AKP_AVX2_INLINE static inline __m256 dq_accumulate(const akp_skin_ctx* c, const uint32_t* off, const float* sw,
                                                   const uint32_t K) {
    const char* jb = (const char*)c->joints_prep;
    size_t o[8];
    vertex_offsets(off, o, K);
#define AKP_JQ(k) _mm256_loadu_ps((const float*)(const void*)(jb + o[k]))
    __m256 acc = _mm256_mul_ps(AKP_JQ(0), _mm256_broadcast_ss(&sw[0]));
    for (uint32_t k = 1; k < K; ++k) acc = _mm256_fmadd_ps(AKP_JQ(k), _mm256_broadcast_ss(&sw[k]), acc);
    return acc;
#undef AKP_JQ
}

/* Phase 1 for one vertex with 8 influences: as dq_signs4x2 with the two 128-bit lanes holding
 * influences 0-3 and 4-7 of the same vertex, and one reference, the rotation of its largest
 * weight (lowest slot on ties). */
AKP_AVX2_INLINE static inline void dq_signs8(const akp_skin_ctx* c, size_t i, uint32_t* off, float* sw,
                                             uint32_t cor_neg) {
    const char* jb = (const char*)c->joints_prep;
    const __m256 w8 = _mm256_loadu_ps((const float*)(const void*)(c->wgt + i * c->wgt_stride));
    __m256 mx = _mm256_max_ps(w8, _mm256_permute_ps(w8, _MM_SHUFFLE(2, 3, 0, 1)));
    mx = _mm256_max_ps(mx, _mm256_permute_ps(mx, _MM_SHUFFLE(1, 0, 3, 2)));
    mx = _mm256_max_ps(mx, _mm256_permute2f128_ps(mx, mx, 1));
    const unsigned is_max = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(w8, mx, _CMP_EQ_OQ));
    const unsigned best = is_max ? (unsigned)__builtin_ctz(is_max) : 0u; /* no max: NaN weights */
    const __m256 ref = _mm256_broadcast_ps((const __m128*)(const void*)(jb + off[best]));
    __m256 m[4];
    for (int k = 0; k < 4; ++k) m[k] = _mm256_mul_ps(quat_pair(jb, off, k), ref);
    const __m256 dots = _mm256_hadd_ps(_mm256_hadd_ps(m[0], m[1]), _mm256_hadd_ps(m[2], m[3]));
    store_signs(off, sw, w8, dots, cor_neg);
}

/* Phase 1 of a whole block (2, 3, 4 or 8 influences); the block loops run it one block ahead,
 * so that its dependency chain overlaps the previous block's transform. */
typedef struct dq_prep {
    uint32_t off[64];
    float sw[64];
} dq_prep;
AKP_AVX2_INLINE static inline void dq_signs_block(const akp_skin_ctx* c, size_t i0, dq_prep* p, uint32_t cor_neg,
                                                  const uint32_t K) {
    if (K == 8) {
        for (int v = 0; v < 8; ++v) dq_signs8(c, i0 + (size_t)v, p->off + 8 * v, p->sw + 8 * v, cor_neg);
        return;
    }
    for (int v = 0; v < 8; v += 2) dq_signs4x2(c, i0 + (size_t)v, p->off + 4 * v, p->sw + 4 * v, cor_neg, K);
}

#endif
