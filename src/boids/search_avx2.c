/* AVX2 kernels of the boids grid path, for CPUs without AVX-512: the distance filter (8
 * candidates at a time, the hits left-packed 4 lanes at a time through a 16-entry table, no
 * branch on the hit masks) and the symmetric pair kernel (8 hits at a time; partner velocities
 * come by gathers in the cone case). Every float operation is the scalar sym_hits's in
 * search.c, in the same order, each rounded (intrinsics only, no FMA), and fix() is rebuilt
 * exactly: clamp, widen to double (exact), truncate, then the 1.5 * 2^52 bias turns the
 * integer (|x| <= 2^34) into int64 bits. The partners' credits go lane by lane through
 * akp_boids_credit. So the sums are bit-identical to the scalar and naive paths (tested with
 * job.skip_avx512 on CPUs that have both).
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports. */
#include "boids_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX2 __attribute__((target("avx2")))

bool akp_boids_have_avx2(void) { return __builtin_cpu_supports("avx2"); }

/* fix() of search.c on 4 lanes. */
AKP_AVX2 static inline __m256i fix4(__m128 x) {
    x = _mm_max_ps(x, _mm_set1_ps(-AKP_BOIDS_FIX_CLAMP)); /* NaN -> -clamp, as fix() */
    x = _mm_min_ps(x, _mm_set1_ps(AKP_BOIDS_FIX_CLAMP));
    const __m256d t = _mm256_round_pd(_mm256_cvtps_pd(x), _MM_FROUND_TO_ZERO | _MM_FROUND_NO_EXC);
    const __m256d bias = _mm256_set1_pd(6755399441055744.0); /* 2^52 + 2^51 */
    return _mm256_sub_epi64(_mm256_castpd_si256(_mm256_add_pd(t, bias)), _mm256_castpd_si256(bias));
}

/* fix(x) on 8 lanes as two int64 quads, zero outside the 64-bit masks lo / hi. */
AKP_AVX2 static inline void fix8(__m256 x, __m256i lo, __m256i hi, __m256i out[2]) {
    out[0] = _mm256_and_si256(fix4(_mm256_castps256_ps128(x)), lo);
    out[1] = _mm256_and_si256(fix4(_mm256_extractf128_ps(x, 1)), hi);
}

/* in_view_v() on 8 lanes (all-ones where in view). */
AKP_AVX2 static inline __m256 cone8(const akp_boids_sp* S, __m256 dx, __m256 dy, __m256 dz, __m256 dd, __m256 vx,
                                    __m256 vy, __m256 vz, __m256 v2) {
    const __m256 zero = _mm256_setzero_ps();
    const __m256 dot = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, vx), _mm256_mul_ps(dy, vy)), _mm256_mul_ps(dz, vz));
    const __m256 lim = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(S->cos2), dd), v2);
    const __m256 dot2 = _mm256_mul_ps(dot, dot);
    __m256 ok;
    if (S->fov == 1)
        ok = _mm256_and_ps(_mm256_cmp_ps(dot, zero, _CMP_GT_OQ), _mm256_cmp_ps(dot2, lim, _CMP_GE_OQ));
    else
        ok = _mm256_or_ps(_mm256_cmp_ps(dot, zero, _CMP_GE_OQ), _mm256_cmp_ps(dot2, lim, _CMP_LE_OQ));
    return _mm256_or_ps(_mm256_or_ps(ok, _mm256_cmp_ps(dd, zero, _CMP_EQ_OQ)), _mm256_cmp_ps(v2, zero, _CMP_EQ_OQ));
}

/* 8 lane mask (32-bit lanes) -> two 64-bit lane masks. */
AKP_AVX2 static inline void widen(__m256 m, __m256i out[2]) {
    const __m256i mi = _mm256_castps_si256(m);
    out[0] = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(mi));
    out[1] = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(mi, 1));
}

AKP_AVX2 static inline int64_t hsum(__m256i v) {
    int64_t t[4];
    _mm256_storeu_si256((__m256i*)(void*)t, v);
    return t[0] + t[1] + t[2] + t[3];
}

/* The set lanes of a 4-bit mask, in order (the rest 0): vpermilps controls that left-pack. */
static const int32_t left_pack4[16][4] = {
    {0, 0, 0, 0}, {0, 0, 0, 0}, {1, 0, 0, 0}, {0, 1, 0, 0}, {2, 0, 0, 0}, {0, 2, 0, 0}, {1, 2, 0, 0}, {0, 1, 2, 0},
    {3, 0, 0, 0}, {0, 3, 0, 0}, {1, 3, 0, 0}, {0, 1, 3, 0}, {2, 3, 0, 0}, {0, 2, 3, 0}, {1, 2, 3, 0}, {0, 1, 2, 3}};

/* Candidates t0 + [0, 8) at x, y, z (lanes at and past `live` ignored): those with d2 < q2
 * appended to h at n (k, d2 and the offsets, 4 entries stored per half, so h needs room for
 * 8 more); returns the new n. The same float operations as filter_sse2 and the scalar test. */
AKP_AVX2 static inline uint32_t filter8(__m256 x, __m256 y, __m256 z, __m256i k, unsigned live, __m256 px, __m256 py,
                                        __m256 pz, __m256 vq, akp_boids_hits* h, uint32_t n) {
    const __m256 dx = _mm256_sub_ps(x, px), dy = _mm256_sub_ps(y, py), dz = _mm256_sub_ps(z, pz);
    const __m256 dd = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const unsigned m = (unsigned)_mm256_movemask_ps(_mm256_cmp_ps(dd, vq, _CMP_LT_OQ)) & live;
    const __m256 kf = _mm256_castsi256_ps(k);
    /* No branch on the masks (whether 4 candidates hit is a coin toss): an empty half stores 4
     * entries that the next store overwrites. */
    for (int half = 0; half < 2; ++half) {
        const unsigned m4 = (m >> (4 * half)) & 15u;
        const __m128i ctl = _mm_loadu_si128((const __m128i*)(const void*)left_pack4[m4]);
#define AKP_PACK4(v, dst)                                                                                       \
    _mm_storeu_ps((dst) + n, _mm_permutevar_ps(half ? _mm256_extractf128_ps(v, 1) : _mm256_castps256_ps128(v), ctl))
        AKP_PACK4(dd, h->d2);
        AKP_PACK4(dx, h->dx);
        AKP_PACK4(dy, h->dy);
        AKP_PACK4(dz, h->dz);
        AKP_PACK4(kf, (float*)(void*)h->k);
#undef AKP_PACK4
        n += (uint32_t)__builtin_popcount(m4);
    }
    return n;
}

/* filter8 over the row [begin, end) of the spatial arrays (the tail through masked loads). */
AKP_AVX2 static inline uint32_t filter_row8(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end,
                                            __m256 px, __m256 py, __m256 pz, __m256 vq, akp_boids_hits* h, uint32_t n) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    uint32_t t = begin;
    for (; t + 8 <= end; t += 8)
        n = filter8(_mm256_loadu_ps(X + t), _mm256_loadu_ps(Y + t), _mm256_loadu_ps(Z + t),
                    _mm256_add_epi32(_mm256_set1_epi32((int)t), lane), 0xFFu, px, py, pz, vq, h, n);
    if (t < end) {
        const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)(end - t)), lane);
        n = filter8(_mm256_maskload_ps(X + t, live), _mm256_maskload_ps(Y + t, live), _mm256_maskload_ps(Z + t, live),
                    _mm256_add_epi32(_mm256_set1_epi32((int)t), lane), (1u << (end - t)) - 1u, px, py, pz, vq, h, n);
    }
    return n;
}

AKP_AVX2 uint32_t akp_boids_pack_rows_avx2(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                           const uint32_t* end, uint32_t rows, akp_boids_packed* b) {
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    uint32_t n = 0;
    for (uint32_t r = 0; r < rows; ++r)
        for (uint32_t t = begin[r]; t < end[r]; t += 8) {
            const uint32_t left = end[r] - t;
            const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32(left >= 8 ? 8 : (int)left), lane);
            _mm256_storeu_ps(b->x + n, _mm256_maskload_ps(X + t, live));
            _mm256_storeu_ps(b->y + n, _mm256_maskload_ps(Y + t, live));
            _mm256_storeu_ps(b->z + n, _mm256_maskload_ps(Z + t, live));
            _mm256_storeu_si256((__m256i*)(void*)(b->k + n), _mm256_add_epi32(_mm256_set1_epi32((int)t), lane));
            n += left >= 8 ? 8u : left;
        }
    return n;
}

AKP_AVX2 uint32_t akp_boids_filter_rows_avx2(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                             const uint32_t* end, uint32_t rows, ak_vec3 p, float q2, akp_boids_hits* h,
                                             uint32_t at) {
    const __m256 px = _mm256_set1_ps(p.x), py = _mm256_set1_ps(p.y), pz = _mm256_set1_ps(p.z), vq = _mm256_set1_ps(q2);
    uint32_t n = at;
    for (uint32_t r = 0; r < rows; ++r) n = filter_row8(X, Y, Z, begin[r], end[r], px, py, pz, vq, h, n);
    return n - at;
}

AKP_AVX2 uint32_t akp_boids_filter_packed_avx2(const float* X, const float* Y, const float* Z, uint32_t begin,
                                               uint32_t end, const akp_boids_packed* b, uint32_t count, ak_vec3 p,
                                               float q2, akp_boids_hits* h, uint32_t at) {
    const __m256 px = _mm256_set1_ps(p.x), py = _mm256_set1_ps(p.y), pz = _mm256_set1_ps(p.z), vq = _mm256_set1_ps(q2);
    uint32_t n = filter_row8(X, Y, Z, begin, end, px, py, pz, vq, h, at);
    for (uint32_t u = 0; u < count; u += 8) /* (the packed arrays have 16 entries of slack) */
        n = filter8(_mm256_loadu_ps(b->x + u), _mm256_loadu_ps(b->y + u), _mm256_loadu_ps(b->z + u),
                    _mm256_loadu_si256((const __m256i*)(const void*)(b->k + u)),
                    count - u >= 8 ? 0xFFu : (1u << (count - u)) - 1u, px, py, pz, vq, h, n);
    return n - at;
}

/* 4x4 transpose of int64 lanes: out[l] is lane l of r[0..3]. */
AKP_AVX2 static inline void transpose4x4(const __m256i r[4], __m256i out[4]) {
    const __m256i a0 = _mm256_unpacklo_epi64(r[0], r[1]), a1 = _mm256_unpackhi_epi64(r[0], r[1]);
    const __m256i a2 = _mm256_unpacklo_epi64(r[2], r[3]), a3 = _mm256_unpackhi_epi64(r[2], r[3]);
    out[0] = _mm256_permute2x128_si256(a0, a2, 0x20);
    out[1] = _mm256_permute2x128_si256(a1, a3, 0x20);
    out[2] = _mm256_permute2x128_si256(a0, a2, 0x31);
    out[3] = _mm256_permute2x128_si256(a1, a3, 0x31);
}

/* The partners' credits of the lanes of bj, none of them at a thread boundary: acc[t] += the
 * pair's row (-e, q_i where aligning, -f, the counts) as three 4-lane vectors, the same integer
 * additions as akp_boids_credit. e, f: fix() of the terms, zero where the rule is off, [axis]
 * [quad]; ws, wa, wc: the rule masks as 64-bit lanes [quad]. */
AKP_AVX2 static inline void credit_rows4(akp_boids_acc* acc, unsigned bj, const uint32_t* kt, __m256i e[3][2],
                                         __m256i f[3][2], const __m256i ws[2], const __m256i wa[2],
                                         const __m256i wc[2], const int64_t* qi, const int64_t* sqv,
                                         unsigned bab, __m256i own[4]) {
    const __m256i zero = _mm256_setzero_si256(), one = _mm256_set1_epi64x(1), hi1 = _mm256_set1_epi64x((int64_t)1 << 32);
    for (int q = 0; q < 2; ++q) {
        const unsigned m4 = (bj >> (4 * q)) & 15u;
        if (!m4) continue;
        __m256i r[12], rows[12];
        for (int a = 0; a < 3; ++a) {
            r[a] = _mm256_sub_epi64(zero, e[a][q]);
            r[3 + a] = _mm256_and_si256(_mm256_set1_epi64x(qi[a]), wa[q]);
            r[6 + a] = _mm256_sub_epi64(zero, f[a][q]);
        }
        r[9] = _mm256_or_si256(_mm256_and_si256(ws[q], one), _mm256_and_si256(wa[q], hi1)); /* n01 */
        r[10] = _mm256_or_si256(_mm256_and_si256(wc[q], one), hi1);                          /* n23 */
        r[11] = zero;
        transpose4x4(r, rows);
        transpose4x4(r + 4, rows + 4);
        transpose4x4(r + 8, rows + 8);
        /* Lane by lane from the registers (unrolled: no spill of the rows to memory). */
#pragma GCC unroll 4
        for (int l = 0; l < 4; ++l) {
            if (!((m4 >> l) & 1u)) continue;
            __m256i* A = (__m256i*)(void*)&acc[kt[4 * q + l]];
            for (int v = 0; v < 3; ++v)
                _mm256_storeu_si256(A + v, _mm256_add_epi64(_mm256_loadu_si256(A + v), rows[4 * v + l]));
            if (sqv) { /* the agent's own sums (see akp_boids_sym_avx2) */
                for (int v = 0; v < 3; ++v) own[v] = _mm256_add_epi64(own[v], rows[4 * v + l]);
                const __m256i q3 = _mm256_and_si256(_mm256_setr_epi64x(-1, -1, -1, 0),
                                                    _mm256_set1_epi64x(-(int64_t)((bab >> (4 * q + l)) & 1u)));
                own[3] = _mm256_add_epi64(
                    own[3], _mm256_maskload_epi64((const long long*)(const void*)(sqv + 3 * (size_t)kt[4 * q + l]), q3));
            }
        }
    }
}

AKP_AVX2 void akp_boids_sym_avx2(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h,
                                 uint32_t count, const akp_boids_sink* sink) {
    const akp_boids_sp* S = g->sp;
    const __m256 rn2 = _mm256_set1_ps(S->rn2), rs2 = _mm256_set1_ps(S->rs2), ra2 = _mm256_set1_ps(S->ra2),
                 rc2 = _mm256_set1_ps(S->rc2), dmin2 = _mm256_set1_ps(S->dmin2), sep = _mm256_set1_ps(S->sep_scale),
                 coh = _mm256_set1_ps(S->coh_scale), sign = _mm256_set1_ps(-0.0f), zero = _mm256_setzero_ps();
    const __m256 vx = _mm256_set1_ps(g->v.x), vy = _mm256_set1_ps(g->v.y), vz = _mm256_set1_ps(g->v.z);
    const __m256 v2 = _mm256_set1_ps(g->v2);
    const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    const bool cone = S->fov != 0;
    const int64_t* qv = c->sqv;
    const int64_t* qi = qv + 3 * (size_t)g->self_k;
    const float* svf = (const float*)(const void*)c->sv; /* ak_vec3: 3 packed floats */
    __m256i s[3], cs[3];
    for (int a = 0; a < 3; ++a) s[a] = cs[a] = _mm256_setzero_si256();
    int64_t al[3] = {0, 0, 0};
    uint32_t ns = 0, na = 0, nc = 0, nf = 0;
    /* The common case (both directions of every pair, no partner at a thread boundary): the
     * agent's own sums are taken from the partners' credit rows as they are added: sep and coh
     * are minus the rows' sums, ali the partners' sqv where aligning (own[3]). */
    __m256i own[4];
    for (int a = 0; a < 4; ++a) own[a] = _mm256_setzero_si256();
    bool reduce = false; /* s, cs hold sums */
    for (uint32_t u = 0; u < count; u += 8) {
        const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)(count - u < 8 ? count - u : 8)), lane);
        const __m256 dd = _mm256_maskload_ps(h->d2 + u, live);
        const __m256 m = _mm256_and_ps(_mm256_castsi256_ps(live), _mm256_cmp_ps(dd, rn2, _CMP_LT_OQ));
        if (!_mm256_movemask_ps(m)) continue;
        const __m256i kk = _mm256_maskload_epi32((const int*)(const void*)(h->k + u), live);
        /* dx = X[t] - px, as sym_hits: the filter's offsets */
        const __m256 dx = _mm256_maskload_ps(h->dx + u, live);
        const __m256 dy = _mm256_maskload_ps(h->dy + u, live);
        const __m256 dz = _mm256_maskload_ps(h->dz + u, live);
        __m256 mi = m, mj = m;
        if (cone) {
            mi = _mm256_and_ps(mi, cone8(S, dx, dy, dz, dd, vx, vy, vz, v2));
            const __m256i k3 = _mm256_add_epi32(_mm256_add_epi32(kk, kk), kk);
            const __m256 jx = _mm256_mask_i32gather_ps(zero, svf, k3, m, 4);
            const __m256 jy = _mm256_mask_i32gather_ps(zero, svf + 1, k3, m, 4);
            const __m256 jz = _mm256_mask_i32gather_ps(zero, svf + 2, k3, m, 4);
            const __m256 j2 =
                _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(jx, jx), _mm256_mul_ps(jy, jy)), _mm256_mul_ps(jz, jz));
            mj = _mm256_and_ps(mj, cone8(S, _mm256_xor_ps(dx, sign), _mm256_xor_ps(dy, sign), _mm256_xor_ps(dz, sign),
                                         dd, jx, jy, jz, j2));
        }
        const __m256 mb = _mm256_or_ps(mi, mj);
        if (!_mm256_movemask_ps(mb)) continue;
        const __m256 bs = _mm256_and_ps(mb, _mm256_cmp_ps(dd, rs2, _CMP_LT_OQ));
        const __m256 ba = _mm256_and_ps(mb, _mm256_cmp_ps(dd, ra2, _CMP_LT_OQ));
        const __m256 bc = _mm256_and_ps(mb, _mm256_cmp_ps(dd, rc2, _CMP_LT_OQ));
        /* inv = sep_scale / (d2 > dmin2 ? d2 : dmin2); e = fix(-d inv), f = fix(d coh) */
        const __m256 den = _mm256_blendv_ps(dmin2, dd, _mm256_cmp_ps(dd, dmin2, _CMP_GT_OQ));
        const __m256 inv = _mm256_div_ps(sep, den);
        __m256i ws[2], wc[2], wi[2], e[3][2], f[3][2];
        widen(bs, ws);
        widen(bc, wc);
        widen(mi, wi);
        fix8(_mm256_mul_ps(_mm256_xor_ps(dx, sign), inv), ws[0], ws[1], e[0]);
        fix8(_mm256_mul_ps(_mm256_xor_ps(dy, sign), inv), ws[0], ws[1], e[1]);
        fix8(_mm256_mul_ps(_mm256_xor_ps(dz, sign), inv), ws[0], ws[1], e[2]);
        fix8(_mm256_mul_ps(dx, coh), wc[0], wc[1], f[0]);
        fix8(_mm256_mul_ps(dy, coh), wc[0], wc[1], f[1]);
        fix8(_mm256_mul_ps(dz, coh), wc[0], wc[1], f[2]);
        const unsigned bi = (unsigned)_mm256_movemask_ps(mi), bj = (unsigned)_mm256_movemask_ps(mj);
        const unsigned bsb = (unsigned)_mm256_movemask_ps(bs), bab = (unsigned)_mm256_movemask_ps(ba),
                       bcb = (unsigned)_mm256_movemask_ps(bc);
        uint32_t kt[8];
        _mm256_storeu_si256((__m256i*)(void*)kt, kk);
        /* Partners at a thread boundary (spill or atomic adds) take the lane-by-lane path. */
        const __m256i kb = _mm256_xor_si256(kk, _mm256_set1_epi32(INT32_MIN)); /* unsigned compares */
        const unsigned edge =
            bj & (unsigned)_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_or_si256(
                     _mm256_cmpgt_epi32(_mm256_set1_epi32((int)(sink->atomic_end ^ 0x80000000u)), kb),
                     _mm256_cmpgt_epi32(kb, _mm256_set1_epi32((int)((sink->far_begin - 1u) ^ 0x80000000u))))));
        if (bi == bj && !edge && sink->far_begin > 0) { /* bi != 0: mb is not empty */
            __m256i wa[2];
            widen(ba, wa);
            credit_rows4(sink->acc, bj, kt, e, f, ws, wa, wc, qi, qv, bab, own);
            nf += (uint32_t)__builtin_popcount(bi);
            ns += (uint32_t)__builtin_popcount(bi & bsb);
            nc += (uint32_t)__builtin_popcount(bi & bcb);
            na += (uint32_t)__builtin_popcount(bi & bab);
            continue;
        }
        reduce = true;
        if (bi) {
            for (int a = 0; a < 3; ++a) {
                s[a] = _mm256_add_epi64(s[a], _mm256_add_epi64(_mm256_and_si256(e[a][0], wi[0]),
                                                               _mm256_and_si256(e[a][1], wi[1])));
                cs[a] = _mm256_add_epi64(cs[a], _mm256_add_epi64(_mm256_and_si256(f[a][0], wi[0]),
                                                                 _mm256_and_si256(f[a][1], wi[1])));
            }
            nf += (uint32_t)__builtin_popcount(bi);
            ns += (uint32_t)__builtin_popcount(bi & bsb);
            nc += (uint32_t)__builtin_popcount(bi & bcb);
            na += (uint32_t)__builtin_popcount(bi & bab);
            for (unsigned r = bi & bab; r; r &= r - 1u) {
                const int64_t* q = qv + 3 * (size_t)kt[__builtin_ctz(r)];
                al[0] += q[0];
                al[1] += q[1];
                al[2] += q[2];
            }
        }
        if (bj && !edge && sink->far_begin > 0) {
            __m256i wa[2];
            widen(ba, wa);
            credit_rows4(sink->acc, bj, kt, e, f, ws, wa, wc, qi, NULL, 0, NULL);
        } else if (bj) {
            int64_t es[3][8], fs[3][8];
            for (int a = 0; a < 3; ++a) {
                _mm256_storeu_si256((__m256i*)(void*)es[a], e[a][0]);
                _mm256_storeu_si256((__m256i*)(void*)(es[a] + 4), e[a][1]);
                _mm256_storeu_si256((__m256i*)(void*)fs[a], f[a][0]);
                _mm256_storeu_si256((__m256i*)(void*)(fs[a] + 4), f[a][1]);
            }
            for (unsigned r = bj; r; r &= r - 1u) {
                const unsigned l = (unsigned)__builtin_ctz(r);
                const uint32_t t = kt[l];
                const bool ia = (bab >> l) & 1u;
                const int64_t v[9] = {-es[0][l], -es[1][l], -es[2][l], ia ? qi[0] : 0, ia ? qi[1] : 0,
                                      ia ? qi[2] : 0,   -fs[0][l], -fs[1][l], -fs[2][l]};
                const uint64_t n01 = (uint64_t)((bsb >> l) & 1u) | (uint64_t)ia << 32;
                const uint64_t n23 = (uint64_t)((bcb >> l) & 1u) | (uint64_t)1 << 32;
                if (t >= sink->far_begin && sink->spill)
                    akp_boids_credit(&sink->spill[t - sink->far_begin], v, n01, n23, false);
                else
                    akp_boids_credit(&sink->acc[t], v, n01, n23, t < sink->atomic_end || t >= sink->far_begin);
            }
        }
    }
    int64_t o[4][4];
    for (int a = 0; a < 4; ++a) _mm256_storeu_si256((__m256i*)(void*)o[a], own[a]);
    /* o[0]: sep x y z, (ali x); o[1]: (ali y z), coh x y; o[2]: coh z, (counts); o[3]: ali. */
    int64_t v[9] = {-o[0][0], -o[0][1], -o[0][2], al[0] + o[3][0], al[1] + o[3][1], al[2] + o[3][2],
                    -o[1][2], -o[1][3], -o[2][0]};
    if (reduce)
        for (int a = 0; a < 3; ++a) {
            v[a] += hsum(s[a]);
            v[6 + a] += hsum(cs[a]);
        }
    akp_boids_gather_add(g, v, ns, na, nc, nf);
}

#else
bool akp_boids_have_avx2(void) { return false; }

uint32_t akp_boids_pack_rows_avx2(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                  const uint32_t* end, uint32_t rows, akp_boids_packed* b) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)rows, (void)b;
    return 0;
}

uint32_t akp_boids_filter_rows_avx2(const float* X, const float* Y, const float* Z, const uint32_t* begin,
                                    const uint32_t* end, uint32_t rows, ak_vec3 p, float q2, akp_boids_hits* h,
                                    uint32_t at) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)rows, (void)p, (void)q2, (void)h, (void)at;
    return 0;
}

uint32_t akp_boids_filter_packed_avx2(const float* X, const float* Y, const float* Z, uint32_t begin, uint32_t end,
                                      const akp_boids_packed* b, uint32_t count, ak_vec3 p, float q2,
                                      akp_boids_hits* h, uint32_t at) {
    (void)X, (void)Y, (void)Z, (void)begin, (void)end, (void)b, (void)count, (void)p, (void)q2, (void)h, (void)at;
    return 0;
}

void akp_boids_sym_avx2(const akp_boids_ctx* c, akp_boids_gather* g, const akp_boids_hits* h, uint32_t count,
                        const akp_boids_sink* sink) {
    (void)c, (void)g, (void)h, (void)count, (void)sink;
}
#endif
