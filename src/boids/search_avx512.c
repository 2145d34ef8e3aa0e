/* AVX-512 kernels of the boids grid path (spatial layout), 16 lanes at a time:
 * - the distance filter: the row's tail through masked loads (no read past the row), hits
 *   packed with compress into registers;
 * - the neighbour rules of the common case, with the fixed-point sums in 64-bit lanes.
 * Every float operation is the scalar code's, in the same order, each rounded (no FMA:
 * intrinsics only, C11 mode), and float -> int64 truncates like the C cast, so d2, the hit
 * set and the integer sums are bit-identical to the scalar and naive paths (tested).
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports (search.c falls back to its SSE2/scalar loops). */
#include "boids_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX512 __attribute__((target("avx512f,avx512dq")))

bool akp_boids_have_avx512(void) { return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq"); }

/* One row of the filter: hits appended at h->...[n], the new n returned. No branch on the hit
 * mask (a row's tail has few lanes, and whether it hits is a coin toss): an empty mask stores
 * 16 entries that the next store overwrites. */
AKP_AVX512 static inline uint32_t filter_row(const float* X, const float* Y, const float* Z, uint32_t begin,
                                             uint32_t end, __m512 vx, __m512 vy, __m512 vz, __m512 vq,
                                             akp_boids_hits* h, uint32_t n) {
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    for (uint32_t t = begin; t < end; t += 16) {
        const uint32_t left = end - t;
        const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
        const __m512 dx = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, X + t), vx);
        const __m512 dy = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, Y + t), vy);
        const __m512 dz = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, Z + t), vz);
        const __m512 dd = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
        const __mmask16 m = _mm512_mask_cmp_ps_mask(live, dd, vq, _CMP_LT_OQ);
        const __m512i k = _mm512_add_epi32(_mm512_set1_epi32((int)t), lane);
        _mm512_storeu_si512((void*)(h->k + n), _mm512_maskz_compress_epi32(m, k));
        _mm512_storeu_ps(h->d2 + n, _mm512_maskz_compress_ps(m, dd));
        _mm512_storeu_ps(h->dx + n, _mm512_maskz_compress_ps(m, dx));
        _mm512_storeu_ps(h->dy + n, _mm512_maskz_compress_ps(m, dy));
        _mm512_storeu_ps(h->dz + n, _mm512_maskz_compress_ps(m, dz));
        n += (uint32_t)__builtin_popcount(m);
    }
    return n;
}

AKP_AVX512 uint32_t akp_boids_filter_avx512(const float* X, const float* Y, const float* Z, uint32_t begin,
                                            uint32_t end, ak_vec3 p, float q2, akp_boids_hits* h, uint32_t at) {
    const __m512 vx = _mm512_set1_ps(p.x), vy = _mm512_set1_ps(p.y), vz = _mm512_set1_ps(p.z);
    return filter_row(X, Y, Z, begin, end, vx, vy, vz, _mm512_set1_ps(q2), h, at) - at;
}

AKP_AVX512 uint32_t akp_boids_filter_rows_avx512(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                                 const uint32_t* end, uint32_t rows, ak_vec3 p, float q2,
                                                 akp_boids_hits* h, uint32_t at) {
    const __m512 vx = _mm512_set1_ps(p.x), vy = _mm512_set1_ps(p.y), vz = _mm512_set1_ps(p.z);
    const __m512 vq = _mm512_set1_ps(q2);
    uint32_t n = at;
    for (uint32_t r = 0; r < rows; ++r) n = filter_row(X, Y, Z, begin[r], end[r], vx, vy, vz, vq, h, n);
    return n - at;
}

AKP_AVX512 uint32_t akp_boids_pack_rows_avx512(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                               const uint32_t* end, uint32_t rows, akp_boids_packed* b) {
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    uint32_t n = 0;
    for (uint32_t r = 0; r < rows; ++r)
        for (uint32_t t = begin[r]; t < end[r]; t += 16) {
            const uint32_t left = end[r] - t;
            const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
            _mm512_storeu_ps(b->x + n, _mm512_maskz_loadu_ps(live, X + t));
            _mm512_storeu_ps(b->y + n, _mm512_maskz_loadu_ps(live, Y + t));
            _mm512_storeu_ps(b->z + n, _mm512_maskz_loadu_ps(live, Z + t));
            _mm512_storeu_si512((void*)(b->k + n), _mm512_add_epi32(_mm512_set1_epi32((int)t), lane));
            n += left >= 16 ? 16u : left;
        }
    return n;
}

AKP_AVX512 uint32_t akp_boids_filter_packed_avx512(const float* X, const float* Y, const float* Z, uint32_t begin,
                                                   uint32_t end, const akp_boids_packed* b, uint32_t count, ak_vec3 p,
                                                   float q2, akp_boids_hits* h, uint32_t at) {
    const __m512 vx = _mm512_set1_ps(p.x), vy = _mm512_set1_ps(p.y), vz = _mm512_set1_ps(p.z);
    const __m512 vq = _mm512_set1_ps(q2);
    uint32_t n = filter_row(X, Y, Z, begin, end, vx, vy, vz, vq, h, at);
    for (uint32_t u = 0; u < count; u += 16) {
        const uint32_t left = count - u;
        const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
        const __m512 dx = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, b->x + u), vx);
        const __m512 dy = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, b->y + u), vy);
        const __m512 dz = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, b->z + u), vz);
        const __m512 dd = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)), _mm512_mul_ps(dz, dz));
        const __mmask16 m = _mm512_mask_cmp_ps_mask(live, dd, vq, _CMP_LT_OQ);
        const __m512i k = _mm512_maskz_loadu_epi32(live, b->k + u);
        _mm512_storeu_si512((void*)(h->k + n), _mm512_maskz_compress_epi32(m, k));
        _mm512_storeu_ps(h->d2 + n, _mm512_maskz_compress_ps(m, dd));
        _mm512_storeu_ps(h->dx + n, _mm512_maskz_compress_ps(m, dx));
        _mm512_storeu_ps(h->dy + n, _mm512_maskz_compress_ps(m, dy));
        _mm512_storeu_ps(h->dz + n, _mm512_maskz_compress_ps(m, dz));
        n += (uint32_t)__builtin_popcount(m);
    }
    return n - at;
}

/* fix() of search.c on 16 lanes: clamp to +-AKP_BOIDS_FIX_CLAMP, truncate to int64 (lo, hi). */
AKP_AVX512 static inline void fix16(__m512 x, __m512i* lo, __m512i* hi) {
    x = _mm512_max_ps(x, _mm512_set1_ps(-AKP_BOIDS_FIX_CLAMP));
    x = _mm512_min_ps(x, _mm512_set1_ps(AKP_BOIDS_FIX_CLAMP));
    *lo = _mm512_cvttps_epi64(_mm512_castps512_ps256(x));
    *hi = _mm512_cvttps_epi64(_mm256_castpd_ps(_mm512_extractf64x4_pd(_mm512_castps_pd(x), 1)));
}

/* sum += fix(x) on the lanes of m. */
AKP_AVX512 static inline void add_fixed(__m512i* sum, __mmask16 m, __m512 x) {
    __m512i lo, hi;
    fix16(x, &lo, &hi);
    *sum = _mm512_mask_add_epi64(*sum, (__mmask8)(m & 0xFF), *sum, lo);
    *sum = _mm512_mask_add_epi64(*sum, (__mmask8)(m >> 8), *sum, hi);
}

/* sum += qv[3 k + comp] on the lanes of m. */
AKP_AVX512 static inline void add_gathered(__m512i* sum, __mmask16 m, __m512i k3, const int64_t* qv) {
    const __m256i ilo = _mm512_castsi512_si256(k3);
    const __m256i ihi = _mm512_extracti64x4_epi64(k3, 1);
    const __m512i z = _mm512_setzero_si512();
    const __m512i lo = _mm512_mask_i32gather_epi64(z, (__mmask8)(m & 0xFF), ilo, (const void*)qv, 8);
    const __m512i hi = _mm512_mask_i32gather_epi64(z, (__mmask8)(m >> 8), ihi, (const void*)qv, 8);
    *sum = _mm512_add_epi64(*sum, _mm512_add_epi64(lo, hi));
}

/* Adds the lanes of the nine fixed-point accumulators to the agent's separation, alignment and
 * cohesion sums (integer adds: the order does not matter). */
AKP_AVX512 static inline void add_sums(akp_boids_gather* g, __m512i s0, __m512i s1, __m512i s2, __m512i a0, __m512i a1,
                                       __m512i a2, __m512i c0, __m512i c1, __m512i c2) {
    g->sep[0] += _mm512_reduce_add_epi64(s0);
    g->sep[1] += _mm512_reduce_add_epi64(s1);
    g->sep[2] += _mm512_reduce_add_epi64(s2);
    g->ali[0] += _mm512_reduce_add_epi64(a0);
    g->ali[1] += _mm512_reduce_add_epi64(a1);
    g->ali[2] += _mm512_reduce_add_epi64(a2);
    g->coh[0] += _mm512_reduce_add_epi64(c0);
    g->coh[1] += _mm512_reduce_add_epi64(c1);
    g->coh[2] += _mm512_reduce_add_epi64(c2);
}

AKP_AVX512 void akp_boids_visit_avx512(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h,
                                       uint32_t count) {
    const akp_boids_sp* S = g->sp;
    const __m512 rn2 = _mm512_set1_ps(S->rn2), rs2 = _mm512_set1_ps(S->rs2), ra2 = _mm512_set1_ps(S->ra2),
                 rc2 = _mm512_set1_ps(S->rc2), dmin2 = _mm512_set1_ps(S->dmin2), sep = _mm512_set1_ps(S->sep_scale),
                 coh = _mm512_set1_ps(S->coh_scale), zero = _mm512_setzero_ps();
    const __m512 vx = _mm512_set1_ps(g->v.x), vy = _mm512_set1_ps(g->v.y), vz = _mm512_set1_ps(g->v.z);
    const __m512 lim_scale = _mm512_set1_ps(S->cos2), v2 = _mm512_set1_ps(g->v2);
    const bool cone = !(S->fov == 0 || g->v2 == 0.0f);
    const __m512i self = _mm512_set1_epi32((int)g->i), self_slot = _mm512_set1_epi32((int)g->self_k);
    const bool by_slot = g->self_k != UINT32_MAX;
    __m512i s0 = _mm512_setzero_si512(), s1 = s0, s2 = s0, a0 = s0, a1 = s0, a2 = s0, c0 = s0, c1 = s0, c2 = s0;
    uint32_t ns = 0, na = 0, nc = 0, nf = 0;
    for (uint32_t u = 0; u < count; u += 16) {
        const uint32_t left = count - u;
        const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
        const __m512 dd = _mm512_maskz_loadu_ps(live, h->d2 + u);
        const __m512 dx = _mm512_maskz_loadu_ps(live, h->dx + u);
        const __m512 dy = _mm512_maskz_loadu_ps(live, h->dy + u);
        const __m512 dz = _mm512_maskz_loadu_ps(live, h->dz + u);
        const __m512i kk = _mm512_maskz_loadu_epi32(live, h->k + u);
        __mmask16 m = _mm512_mask_cmp_ps_mask(live, dd, rn2, _CMP_LT_OQ);
        if (by_slot) /* sj is a permutation: sj[t] == i exactly when t is the agent's slot */
            m &= _mm512_cmpneq_epi32_mask(kk, self_slot);
        else
            m &= _mm512_cmpneq_epi32_mask(
                _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), live, kk, (const void*)c->sj, 4), self);
        if (cone) {
            /* in_view(): dot = dx vx + dy vy + dz vz, lim = cos2 d2 v2; d2 == 0 is in view. */
            const __m512 dot =
                _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, vx), _mm512_mul_ps(dy, vy)), _mm512_mul_ps(dz, vz));
            const __m512 lim = _mm512_mul_ps(_mm512_mul_ps(lim_scale, dd), v2);
            const __m512 dot2 = _mm512_mul_ps(dot, dot);
            __mmask16 ok;
            if (S->fov == 1)
                ok = _mm512_cmp_ps_mask(dot, zero, _CMP_GT_OQ) & _mm512_cmp_ps_mask(dot2, lim, _CMP_GE_OQ);
            else
                ok = _mm512_cmp_ps_mask(dot, zero, _CMP_GE_OQ) | _mm512_cmp_ps_mask(dot2, lim, _CMP_LE_OQ);
            ok |= _mm512_cmp_ps_mask(dd, zero, _CMP_EQ_OQ);
            m &= ok;
        }
        if (!m) continue;
        nf += (uint32_t)__builtin_popcount(m);
        const __mmask16 ms = _mm512_mask_cmp_ps_mask(m, dd, rs2, _CMP_LT_OQ);
        if (ms) {
            /* inv = sep_scale / (d2 > dmin2 ? d2 : dmin2); fix(-d * inv) */
            const __m512 den = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(dd, dmin2, _CMP_GT_OQ), dmin2, dd);
            const __m512 inv = _mm512_div_ps(sep, den);
            const __m512 sign = _mm512_set1_ps(-0.0f);
            add_fixed(&s0, ms, _mm512_mul_ps(_mm512_xor_ps(dx, sign), inv));
            add_fixed(&s1, ms, _mm512_mul_ps(_mm512_xor_ps(dy, sign), inv));
            add_fixed(&s2, ms, _mm512_mul_ps(_mm512_xor_ps(dz, sign), inv));
            ns += (uint32_t)__builtin_popcount(ms);
        }
        const __mmask16 ma = _mm512_mask_cmp_ps_mask(m, dd, ra2, _CMP_LT_OQ);
        if (ma) {
            const __m512i k3 = _mm512_add_epi32(_mm512_add_epi32(kk, kk), kk);
            add_gathered(&a0, ma, k3, c->sqv);
            add_gathered(&a1, ma, k3, c->sqv + 1);
            add_gathered(&a2, ma, k3, c->sqv + 2);
            na += (uint32_t)__builtin_popcount(ma);
        }
        const __mmask16 mc = _mm512_mask_cmp_ps_mask(m, dd, rc2, _CMP_LT_OQ);
        if (mc) {
            add_fixed(&c0, mc, _mm512_mul_ps(dx, coh));
            add_fixed(&c1, mc, _mm512_mul_ps(dy, coh));
            add_fixed(&c2, mc, _mm512_mul_ps(dz, coh));
            nc += (uint32_t)__builtin_popcount(mc);
        }
    }
    add_sums(g, s0, s1, s2, a0, a1, a2, c0, c1, c2);
    g->ns += ns;
    g->na += na;
    g->nc += nc;
    g->nflock += nf;
}

/* j's credits of the lanes of m through sink (see akp_boids_sym_avx512). */
static inline void credit_lanes(const akp_boids_sink* sink, __mmask16 m, const uint32_t* k, const int64_t* e,
                                const int64_t* f, __mmask16 ms, __mmask16 ma, __mmask16 mc, const int64_t* qi) {
    while (m) {
        const unsigned l = (unsigned)__builtin_ctz(m);
        m &= (__mmask16)(m - 1);
        const uint32_t t = k[l];
        const uint64_t bs = (ms >> l) & 1u, ba = (ma >> l) & 1u, bc = (mc >> l) & 1u;
        const int64_t am = -(int64_t)ba;
        const uint64_t n01 = bs | ba << 32, n23 = bc | (uint64_t)1 << 32;
        akp_boids_acc* A = &sink->acc[t];
        if (t < sink->atomic_end || t >= sink->far_begin) {
            if (t >= sink->far_begin && sink->spill) {
                A = &sink->spill[t - sink->far_begin];
            } else {
                for (int a = 0; a < 3; ++a) {
                    __atomic_fetch_sub(&A->sep[a], e[16 * a + l], __ATOMIC_RELAXED);
                    __atomic_fetch_add(&A->ali[a], qi[a] & am, __ATOMIC_RELAXED);
                    __atomic_fetch_sub(&A->coh[a], f[16 * a + l], __ATOMIC_RELAXED);
                }
                __atomic_fetch_add(&A->n01, n01, __ATOMIC_RELAXED);
                __atomic_fetch_add(&A->n23, n23, __ATOMIC_RELAXED);
                continue;
            }
        }
        A->sep[0] -= e[l];
        A->sep[1] -= e[16 + l];
        A->sep[2] -= e[32 + l];
        A->ali[0] += qi[0] & am;
        A->ali[1] += qi[1] & am;
        A->ali[2] += qi[2] & am;
        A->coh[0] -= f[l];
        A->coh[1] -= f[16 + l];
        A->coh[2] -= f[32 + l];
        A->n01 += n01;
        A->n23 += n23;
    }
}

/* 8x8 transpose of int64 lanes: row l of out is lane l of r[0..7]. */
AKP_AVX512 static inline void transpose8(const __m512i r[8], __m512i out[8]) {
    __m512i a[8], b[8];
    for (int k = 0; k < 4; ++k) {
        a[2 * k] = _mm512_unpacklo_epi64(r[2 * k], r[2 * k + 1]);     /* k-pair, lanes 0 2 4 6 */
        a[2 * k + 1] = _mm512_unpackhi_epi64(r[2 * k], r[2 * k + 1]); /* k-pair, lanes 1 3 5 7 */
    }
    for (int k = 0; k < 2; ++k)
        for (int o = 0; o < 2; ++o) {
            b[4 * k + 2 * o] = _mm512_shuffle_i64x2(a[4 * k + o], a[4 * k + 2 + o], _MM_SHUFFLE(2, 0, 2, 0));
            b[4 * k + 2 * o + 1] = _mm512_shuffle_i64x2(a[4 * k + o], a[4 * k + 2 + o], _MM_SHUFFLE(3, 1, 3, 1));
        }
    /* b[0]: lanes 0, 4; b[1]: 2, 6; b[2]: 1, 5; b[3]: 3, 7 (rows 0-3), b[4..7] the same for rows 4-7 */
    const int lo[4] = {0, 2, 1, 3};
    for (int k = 0; k < 4; ++k) {
        out[lo[k]] = _mm512_shuffle_i64x2(b[k], b[4 + k], _MM_SHUFFLE(2, 0, 2, 0));
        out[lo[k] + 4] = _mm512_shuffle_i64x2(b[k], b[4 + k], _MM_SHUFFLE(3, 1, 3, 1));
    }
}

/* 4x8 transpose: row l (4 int64) is lane l of r[0..3]; out[0] holds rows 0 | 2 (low | high
 * 256 bits), out[1] rows 1 | 3, out[2] rows 4 | 6, out[3] rows 5 | 7. */
AKP_AVX512 static inline void transpose4(const __m512i r[4], __m512i out[4]) {
    const __m512i a0 = _mm512_unpacklo_epi64(r[0], r[1]), a1 = _mm512_unpackhi_epi64(r[0], r[1]);
    const __m512i a2 = _mm512_unpacklo_epi64(r[2], r[3]), a3 = _mm512_unpackhi_epi64(r[2], r[3]);
    const __m512i b0 = _mm512_shuffle_i64x2(a0, a2, _MM_SHUFFLE(1, 0, 1, 0)); /* lanes 0, 2 */
    const __m512i b1 = _mm512_shuffle_i64x2(a0, a2, _MM_SHUFFLE(3, 2, 3, 2)); /* lanes 4, 6 */
    const __m512i b2 = _mm512_shuffle_i64x2(a1, a3, _MM_SHUFFLE(1, 0, 1, 0)); /* lanes 1, 3 */
    const __m512i b3 = _mm512_shuffle_i64x2(a1, a3, _MM_SHUFFLE(3, 2, 3, 2)); /* lanes 5, 7 */
    out[0] = _mm512_shuffle_i64x2(b0, b0, _MM_SHUFFLE(3, 1, 2, 0)); /* rows 0 | 2 */
    out[1] = _mm512_shuffle_i64x2(b2, b2, _MM_SHUFFLE(3, 1, 2, 0)); /* rows 1 | 3 */
    out[2] = _mm512_shuffle_i64x2(b1, b1, _MM_SHUFFLE(3, 1, 2, 0)); /* rows 4 | 6 */
    out[3] = _mm512_shuffle_i64x2(b3, b3, _MM_SHUFFLE(3, 1, 2, 0)); /* rows 5 | 7 */
}

/* The partners' credits of the lanes of mj, none of them at a thread boundary: acc[t] += the
 * pair's row (-e, q_i where aligning, -f, the counts) as 8 + 4 int64 lanes, the same integer
 * additions as credit_lanes. E and F: fix() of the separation and cohesion terms, zero where
 * the rule is off, [2 axis + half]. */
AKP_AVX512 static inline void credit_rows(akp_boids_acc* acc, __mmask16 mj, const uint32_t* kt, const __m512i E[6],
                                          const __m512i F[6], __mmask16 bs, __mmask16 ba, __mmask16 bc,
                                          const int64_t* qi, const int64_t* sqv, __m512i* i8, __m256i* i4,
                                          __m512i* ia) {
    const __m512i zero = _mm512_setzero_si512(), one = _mm512_set1_epi64(1);
    const __m512i hi1 = _mm512_set1_epi64((int64_t)1 << 32);
    for (int h = 0; h < 2; ++h) {
        const unsigned m8 = (unsigned)(mj >> (8 * h)) & 0xFFu;
        if (!m8) continue;
        const __mmask8 s8 = (__mmask8)(bs >> (8 * h)), a8 = (__mmask8)(ba >> (8 * h)), c8 = (__mmask8)(bc >> (8 * h));
        __m512i r[8], q[4], rows[8], tail[4];
        r[0] = _mm512_sub_epi64(zero, E[h]);
        r[1] = _mm512_sub_epi64(zero, E[2 + h]);
        r[2] = _mm512_sub_epi64(zero, E[4 + h]);
        r[3] = _mm512_maskz_mov_epi64(a8, _mm512_set1_epi64(qi[0]));
        r[4] = _mm512_maskz_mov_epi64(a8, _mm512_set1_epi64(qi[1]));
        r[5] = _mm512_maskz_mov_epi64(a8, _mm512_set1_epi64(qi[2]));
        r[6] = _mm512_sub_epi64(zero, F[h]);
        r[7] = _mm512_sub_epi64(zero, F[2 + h]);
        q[0] = _mm512_sub_epi64(zero, F[4 + h]);
        q[1] = _mm512_add_epi64(_mm512_maskz_mov_epi64(s8, one), _mm512_maskz_mov_epi64(a8, hi1)); /* n01 */
        q[2] = _mm512_add_epi64(_mm512_maskz_mov_epi64(c8, one), hi1);                             /* n23 */
        q[3] = zero;
        transpose8(r, rows);
        transpose4(q, tail);
        /* Lane by lane from the registers (unrolled: no spill of the rows to memory). */
#pragma GCC unroll 8
        for (int l = 0; l < 8; ++l) {
            if (!((m8 >> l) & 1u)) continue;
            int64_t* A = (int64_t*)(void*)&acc[kt[8 * h + l]];
            const __m512i t4 = tail[(l & 1) + 2 * (l >> 2)];
            const __m256i tl = (l & 2) ? _mm512_extracti64x4_epi64(t4, 1) : _mm512_castsi512_si256(t4);
            _mm512_storeu_si512((void*)A, _mm512_add_epi64(_mm512_loadu_si512((const void*)A), rows[l]));
            _mm256_storeu_si256((__m256i*)(void*)(A + 8),
                                _mm256_add_epi64(_mm256_loadu_si256((const __m256i*)(const void*)(A + 8)), tl));
            if (sqv) { /* i's own sums: minus the rows' sep and coh, plus the partner's velocity */
                *i8 = _mm512_add_epi64(*i8, rows[l]);
                *i4 = _mm256_add_epi64(*i4, tl);
                const __mmask8 q3 = (__mmask8)(7u & (0u - ((a8 >> l) & 1u)));
                *ia = _mm512_add_epi64(*ia, _mm512_maskz_loadu_epi64(q3, sqv + 3 * (size_t)kt[8 * h + l]));
            }
        }
    }
}

/* The view-cone test of in_view_v() on 16 lanes: offsets d, squared lengths dd, viewer
 * velocity v (squared length v2). */
AKP_AVX512 static inline __mmask16 cone16(const akp_boids_sp* S, __m512 dx, __m512 dy, __m512 dz, __m512 dd,
                                          __m512 vx, __m512 vy, __m512 vz, __m512 v2) {
    const __m512 zero = _mm512_setzero_ps();
    const __m512 dot = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, vx), _mm512_mul_ps(dy, vy)), _mm512_mul_ps(dz, vz));
    const __m512 lim = _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(S->cos2), dd), v2);
    const __m512 dot2 = _mm512_mul_ps(dot, dot);
    __mmask16 ok;
    if (S->fov == 1)
        ok = _mm512_cmp_ps_mask(dot, zero, _CMP_GT_OQ) & _mm512_cmp_ps_mask(dot2, lim, _CMP_GE_OQ);
    else
        ok = _mm512_cmp_ps_mask(dot, zero, _CMP_GE_OQ) | _mm512_cmp_ps_mask(dot2, lim, _CMP_LE_OQ);
    return ok | _mm512_cmp_ps_mask(dd, zero, _CMP_EQ_OQ) | _mm512_cmp_ps_mask(v2, zero, _CMP_EQ_OQ);
}

AKP_AVX512 void akp_boids_sym_avx512(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h,
                                     uint32_t count, const akp_boids_sink* sink) {
    const akp_boids_sp* S = g->sp;
    const __m512 rn2 = _mm512_set1_ps(S->rn2), rs2 = _mm512_set1_ps(S->rs2), ra2 = _mm512_set1_ps(S->ra2),
                 rc2 = _mm512_set1_ps(S->rc2), dmin2 = _mm512_set1_ps(S->dmin2), sep = _mm512_set1_ps(S->sep_scale),
                 coh = _mm512_set1_ps(S->coh_scale), sign = _mm512_set1_ps(-0.0f);
    const __m512 vx = _mm512_set1_ps(g->v.x), vy = _mm512_set1_ps(g->v.y), vz = _mm512_set1_ps(g->v.z);
    const __m512 v2 = _mm512_set1_ps(g->v2);
    const bool cone = S->fov != 0;
    const int64_t* qi = c->sqv + 3 * (size_t)g->self_k;
    const float* svf = (const float*)(const void*)c->sv; /* ak_vec3: 3 packed floats */
    __m512i s0 = _mm512_setzero_si512(), s1 = s0, s2 = s0, a0 = s0, a1 = s0, a2 = s0, c0 = s0, c1 = s0, c2 = s0;
    uint32_t ns = 0, na = 0, nc = 0, nf = 0;
    int64_t e[48], f[48];
    /* The common case (no cone, no partner at a thread boundary): i's sums are taken from the
     * partners' credit rows as they are added (no lane reductions, no gather of the partners'
     * velocities): sep and coh are minus the rows' sums, ali the partners' sqv where aligning. */
    __m512i i8 = _mm512_setzero_si512();
    __m256i i4 = _mm256_setzero_si256();
    __m512i ia = _mm512_setzero_si512();
    bool reduce = false;
    for (uint32_t u = 0; u < count; u += 16) {
        const uint32_t left = count - u;
        const __mmask16 live = left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
        const __m512 dd = _mm512_maskz_loadu_ps(live, h->d2 + u);
        const __mmask16 m = _mm512_mask_cmp_ps_mask(live, dd, rn2, _CMP_LT_OQ);
        if (!m) continue;
        const __m512 dx = _mm512_maskz_loadu_ps(live, h->dx + u);
        const __m512 dy = _mm512_maskz_loadu_ps(live, h->dy + u);
        const __m512 dz = _mm512_maskz_loadu_ps(live, h->dz + u);
        const __m512i kk = _mm512_maskz_loadu_epi32(live, h->k + u);
        __mmask16 mi = m, mj = m;
        if (cone) {
            if (g->v2 != 0.0f) mi &= cone16(S, dx, dy, dz, dd, vx, vy, vz, v2);
            /* j looks back along -d with its own velocity. */
            const __m512i k3 = _mm512_add_epi32(_mm512_add_epi32(kk, kk), kk);
            const __m512 z = _mm512_setzero_ps();
            const __m512 jx = _mm512_mask_i32gather_ps(z, m, k3, svf, 4);
            const __m512 jy = _mm512_mask_i32gather_ps(z, m, k3, svf + 1, 4);
            const __m512 jz = _mm512_mask_i32gather_ps(z, m, k3, svf + 2, 4);
            const __m512 j2 =
                _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(jx, jx), _mm512_mul_ps(jy, jy)), _mm512_mul_ps(jz, jz));
            mj &= cone16(S, _mm512_xor_ps(dx, sign), _mm512_xor_ps(dy, sign), _mm512_xor_ps(dz, sign), dd, jx, jy, jz,
                         j2);
        }
        const __mmask16 mb = mi | mj;
        if (!mb) continue;
        nf += (uint32_t)__builtin_popcount(mi);
        const __mmask16 bs = _mm512_mask_cmp_ps_mask(mb, dd, rs2, _CMP_LT_OQ);
        const __mmask16 ba = _mm512_mask_cmp_ps_mask(mb, dd, ra2, _CMP_LT_OQ);
        const __mmask16 bc = _mm512_mask_cmp_ps_mask(mb, dd, rc2, _CMP_LT_OQ);
        /* e = fix(-d * inv) where separating (zero elsewhere), f = fix(d * coh) where cohering. */
        const __m512 den = _mm512_mask_blend_ps(_mm512_cmp_ps_mask(dd, dmin2, _CMP_GT_OQ), dmin2, dd);
        const __m512 inv = _mm512_maskz_div_ps(bs, sep, den);
        __m512i E[6], F[6]; /* [2 axis + half] */
        fix16(_mm512_mul_ps(_mm512_xor_ps(dx, sign), inv), &E[0], &E[1]);
        fix16(_mm512_mul_ps(_mm512_xor_ps(dy, sign), inv), &E[2], &E[3]);
        fix16(_mm512_mul_ps(_mm512_xor_ps(dz, sign), inv), &E[4], &E[5]);
        fix16(_mm512_mul_ps(dx, coh), &F[0], &F[1]);
        fix16(_mm512_mul_ps(dy, coh), &F[2], &F[3]);
        fix16(_mm512_mul_ps(dz, coh), &F[4], &F[5]);
        for (int a = 0; a < 6; ++a) {
            E[a] = _mm512_maskz_mov_epi64((__mmask8)(bs >> (8 * (a & 1))), E[a]);
            F[a] = _mm512_maskz_mov_epi64((__mmask8)(bc >> (8 * (a & 1))), F[a]);
        }
        uint32_t kt[16];
        __mmask16 edge = 0;
        if (mj) {
            _mm512_storeu_si512((void*)kt, kk);
            /* Partners at a thread boundary (spill or atomic adds) take the lane-by-lane path. */
            edge = _mm512_mask_cmplt_epu32_mask(mj, kk, _mm512_set1_epi32((int)sink->atomic_end)) |
                   _mm512_mask_cmpge_epu32_mask(mj, kk, _mm512_set1_epi32((int)sink->far_begin));
        }
        if (mi == mj && !edge) { /* mb != 0, so both are this mask */
            credit_rows(sink->acc, mj, kt, E, F, bs, ba, bc, qi, c->sqv, &i8, &i4, &ia);
            ns += (uint32_t)__builtin_popcount(mi & bs);
            na += (uint32_t)__builtin_popcount(mi & ba);
            nc += (uint32_t)__builtin_popcount(mi & bc);
            continue;
        }
        reduce = true;
        if (mi) {
            const __mmask8 lo = (__mmask8)(mi & 0xFF), hi = (__mmask8)(mi >> 8);
            __m512i* sums[6] = {&s0, &s1, &s2, &c0, &c1, &c2};
            for (int a = 0; a < 6; ++a) {
                const __m512i* X = a < 3 ? &E[2 * a] : &F[2 * (a - 3)];
                *sums[a] = _mm512_mask_add_epi64(*sums[a], lo, *sums[a], X[0]);
                *sums[a] = _mm512_mask_add_epi64(*sums[a], hi, *sums[a], X[1]);
            }
            const __mmask16 mai = mi & ba;
            if (mai) {
                const __m512i k3 = _mm512_add_epi32(_mm512_add_epi32(kk, kk), kk);
                add_gathered(&a0, mai, k3, c->sqv);
                add_gathered(&a1, mai, k3, c->sqv + 1);
                add_gathered(&a2, mai, k3, c->sqv + 2);
            }
            ns += (uint32_t)__builtin_popcount(mi & bs);
            na += (uint32_t)__builtin_popcount(mai);
            nc += (uint32_t)__builtin_popcount(mi & bc);
        }
        if (mj) {
            if (edge) {
                for (int a = 0; a < 3; ++a) {
                    _mm512_storeu_si512((void*)(e + 16 * a), E[2 * a]);
                    _mm512_storeu_si512((void*)(e + 16 * a + 8), E[2 * a + 1]);
                    _mm512_storeu_si512((void*)(f + 16 * a), F[2 * a]);
                    _mm512_storeu_si512((void*)(f + 16 * a + 8), F[2 * a + 1]);
                }
                credit_lanes(sink, mj, kt, e, f, bs, ba, bc, qi);
            } else {
                credit_rows(sink->acc, mj, kt, E, F, bs, ba, bc, qi, NULL, NULL, NULL, NULL);
            }
        }
    }
    if (reduce) {
        add_sums(g, s0, s1, s2, a0, a1, a2, c0, c1, c2);
    }
    int64_t r8[8], r4[4], ra[8];
    _mm512_storeu_si512((void*)r8, i8);
    _mm256_storeu_si256((__m256i*)(void*)r4, i4);
    _mm512_storeu_si512((void*)ra, ia);
    /* r8: sep x y z, ali (the partners' credits, unused), coh x y; r4: coh z, counts. Integer
     * sums wrap like the others: minus the sum is the sum of the negated terms. */
    g->sep[0] -= r8[0];
    g->sep[1] -= r8[1];
    g->sep[2] -= r8[2];
    g->coh[0] -= r8[6];
    g->coh[1] -= r8[7];
    g->coh[2] -= r4[0];
    g->ali[0] += ra[0];
    g->ali[1] += ra[1];
    g->ali[2] += ra[2];
    g->ns += ns;
    g->na += na;
    g->nc += nc;
    g->nflock += nf;
}

#else
bool akp_boids_have_avx512(void) { return false; }

uint32_t akp_boids_filter_avx512(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end, ak_vec3 p,
                                 float q2, akp_boids_hits* h, uint32_t at) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)p, (void)q2, (void)h, (void)at;
    return 0;
}

uint32_t akp_boids_filter_rows_avx512(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                      const uint32_t* end, uint32_t rows, ak_vec3 p, float q2, akp_boids_hits* h,
                                      uint32_t at) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)rows, (void)p, (void)q2, (void)h, (void)at;
    return 0;
}

void akp_boids_visit_avx512(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h, uint32_t count) {
    (void)c, (void)g, (void)h, (void)count;
}

void akp_boids_sym_avx512(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h, uint32_t count,
                          const akp_boids_sink* sink) {
    (void)c, (void)g, (void)h, (void)count, (void)sink;
}

uint32_t akp_boids_pack_rows_avx512(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                    const uint32_t* end, uint32_t rows, akp_boids_packed* b) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)rows, (void)b;
    return 0;
}

uint32_t akp_boids_filter_packed_avx512(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end,
                                        const akp_boids_packed* b, uint32_t count, ak_vec3 p, float q2,
                                        akp_boids_hits* h, uint32_t at) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)b, (void)count, (void)p, (void)q2, (void)h, (void)at;
    return 0;
}
#endif
