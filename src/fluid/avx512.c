/* AVX-512 kernels of the fluid solver: the neighbour filter and the per-neighbour sums of the
 * PBF phases (density, lambda, position correction, vorticity, XSPH). The filter tests 16
 * candidates of a row of cells at a time (contiguous sorted positions) and packs the hits in
 * index order, giving exactly the scalar filter's lists. The phases take 16 particles at a
 * time, one per lane: slot q of the 16 neighbour lists is one load (slot-major blocks), the
 * neighbours' positions are gathered, and each lane sums its own neighbours in list order with
 * the scalar phase's float operations in the same order (no FMA: intrinsics only, C11 mode;
 * IEEE sqrt and division; skipped terms masked, not added), so every result is bit-identical
 * to the scalar phases (tested).
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports (fluid.c falls back to its scalar phases). */

/* The SIMD kernels give the scalar code's bits only if nothing fuses a * b + c: clang contracts
 * within an expression by default (and avx512f implies FMA); gcc's C11 mode does not. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
#include "fluid_internal.h"

#include <math.h>

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX512 __attribute__((target("avx512f,avx512dq")))

bool akp_fluid_have_avx512(void) {
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
}

static inline __mmask16 live_mask(uint32_t left) {
    return left >= 16 ? (__mmask16)0xFFFF : (__mmask16)((1u << left) - 1u);
}

AKP_AVX512 uint32_t akp_fluid_filter_avx512(const akp_fluid_ctx* c, uint32_t begin, uint32_t end,
                                            float qx, float qy, float qz, uint32_t* list,
                                            uint32_t* k, uint32_t* close) {
    const __m512 vx = _mm512_set1_ps(qx), vy = _mm512_set1_ps(qy), vz = _mm512_set1_ps(qz);
    const __m512 vr = _mm512_set1_ps(c->h2), vc = _mm512_set1_ps(c->coincident2);
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const uint32_t K = c->K;
    uint32_t found = 0, kk = *k;
    for (uint32_t t = begin; t < end; t += 16) {
        const __mmask16 live = live_mask(end - t);
        const __m512 dx = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, c->px + t), vx);
        const __m512 dy = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, c->py + t), vy);
        const __m512 dz = _mm512_sub_ps(_mm512_maskz_loadu_ps(live, c->pz + t), vz);
        const __m512 dd = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(dx, dx), _mm512_mul_ps(dy, dy)),
                                        _mm512_mul_ps(dz, dz));
        const __mmask16 m = _mm512_mask_cmp_ps_mask(live, dd, vr, _CMP_LT_OQ);
        if (!m) continue;
        const uint32_t cnt = (uint32_t)__builtin_popcount(m);
        found += cnt;
        *close += (uint32_t)__builtin_popcount(_mm512_mask_cmp_ps_mask(m, dd, vc, _CMP_LT_OQ));
        const __m512i packed =
            _mm512_maskz_compress_epi32(m, _mm512_add_epi32(_mm512_set1_epi32((int)t), lane));
        if (kk + 16 <= K) {
            _mm512_storeu_si512((void*)(list + kk), packed);
            kk += cnt;
        } else {
            uint32_t tmp[16];
            _mm512_storeu_si512((void*)tmp, packed);
            for (uint32_t u = 0; u < cnt && kk < K; ++u) list[kk++] = tmp[u];
        }
    }
    *k = kk;
    return found;
}

/* One slot q of a block's 16 lists: neighbour indices, offsets r = p_i - p_j, r^2, masks. */
typedef struct pairs16 {
    __m512i idx;
    const uint32_t* id; /* the slot's 16 entries */
    __m512 rx, ry, rz, r2;
    __mmask16 m;  /* lanes whose list has a slot q */
    __mmask16 in; /* and r^2 < h^2 */
} pairs16;

/* A block of 16 sorted particles [blk, blk + 16) clipped to [b, e). */
typedef struct block16 {
    size_t blk;
    __mmask16 lanes;
    __m512i cnt;
    uint32_t max_count;
    const uint32_t* nb;
    __m512 px, py, pz;
} block16;

AKP_AVX512 static inline void block_begin(const akp_fluid_ctx* c, size_t blk, size_t b, size_t e,
                                          block16* o) {
    const uint32_t lo = blk < b ? (uint32_t)(b - blk) : 0u,
                   hi = e - blk >= 16 ? 16u : (uint32_t)(e - blk);
    o->blk = blk;
    o->lanes = (__mmask16)(((1u << hi) - 1u) & ~((1u << lo) - 1u));
    o->cnt = _mm512_maskz_loadu_epi32(o->lanes, c->nb_count + blk);
    o->max_count = _mm512_reduce_max_epu32(o->cnt);
    o->nb = c->nb + (blk >> 4) * c->K * 16;
    o->px = _mm512_maskz_loadu_ps(o->lanes, c->px + blk);
    o->py = _mm512_maskz_loadu_ps(o->lanes, c->py + blk);
    o->pz = _mm512_maskz_loadu_ps(o->lanes, c->pz + blk);
}

/* The (x, y, z, w) records p4[4 id[k]] of 16 particles as x, y, z (and w) lanes: 16 loads and a
 * 4 x 4 transpose in each 128-bit lane (cheaper than three or four 16-element gathers). */
AKP_AVX512 static inline void load4(const float* p4, const uint32_t* id, __m512* x, __m512* y,
                                    __m512* z, __m512* w) {
#define R(k) _mm_load_ps(p4 + 4 * (size_t)id[k])
#define ROW(a, b2, c2, d2)                                                                         \
    _mm512_insertf32x4(                                                                            \
        _mm512_insertf32x4(_mm512_insertf32x4(_mm512_castps128_ps512(R(a)), R(b2), 1), R(c2), 2),  \
        R(d2), 3)
    const __m512 A = ROW(0, 4, 8, 12), B = ROW(1, 5, 9, 13), C = ROW(2, 6, 10, 14),
                 D = ROW(3, 7, 11, 15);
#undef ROW
#undef R
    const __m512 t0 = _mm512_unpacklo_ps(A, B),
                 t1 = _mm512_unpackhi_ps(A, B); /* a0 b0 a1 b1, a2 b2 a3 b3 */
    const __m512 t2 = _mm512_unpacklo_ps(C, D), t3 = _mm512_unpackhi_ps(C, D);
    *x = _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(t0), _mm512_castps_pd(t2)));
    *y = _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(t0), _mm512_castps_pd(t2)));
    *z = _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(t1), _mm512_castps_pd(t3)));
    if (w) *w = _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(t1), _mm512_castps_pd(t3)));
}

/* Slot q of block B: neighbours from the records rec (p4, or q4 = (x, y, z, lambda) in the
 * correction pass, whose w lands in *w when w is not NULL). */
AKP_AVX512 static inline void load_pairs_from(const akp_fluid_ctx* c, const block16* B, uint32_t q,
                                              const float* rec, __m512* w, pairs16* o) {
    o->m = _mm512_mask_cmplt_epu32_mask(B->lanes, _mm512_set1_epi32((int)q), B->cnt);
    o->idx = _mm512_maskz_loadu_epi32(o->m, B->nb + (size_t)q * 16);
    __m512 x, y, z;
    o->id = B->nb + (size_t)q * 16; /* every entry valid: lists are padded (pad_lists in fluid.c) */
    load4(rec, o->id, &x, &y, &z, w);
    o->rx = _mm512_sub_ps(B->px, x);
    o->ry = _mm512_sub_ps(B->py, y);
    o->rz = _mm512_sub_ps(B->pz, z);
    o->r2 = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(o->rx, o->rx), _mm512_mul_ps(o->ry, o->ry)),
                          _mm512_mul_ps(o->rz, o->rz));
    o->in = _mm512_mask_cmp_ps_mask(o->m, o->r2, _mm512_set1_ps(c->h2), _CMP_LT_OQ);
}

AKP_AVX512 static inline void load_pairs(const akp_fluid_ctx* c, const block16* B, uint32_t q,
                                         pairs16* o) {
    load_pairs_from(c, B, q, c->p4, NULL, o);
}

/* k_poly6: poly6_k d d d, d = h^2 - r^2 (+0 outside). */
AKP_AVX512 static inline __m512 poly6_16(const akp_fluid_ctx* c, const pairs16* p) {
    const __m512 d = _mm512_sub_ps(_mm512_set1_ps(c->h2), p->r2);
    return _mm512_maskz_mul_ps(p->in,
                               _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(c->poly6_k), d), d), d);
}

/* k_spiky's factor spiky_k d d / |r|, d = h - |r| (+0 outside and at r = 0). */
AKP_AVX512 static inline __m512 spiky_16(const akp_fluid_ctx* c, const pairs16* p) {
    const __mmask16 pos = _mm512_mask_cmp_ps_mask(p->in, p->r2, _mm512_setzero_ps(), _CMP_GT_OQ);
    const __m512 len = _mm512_maskz_sqrt_ps(pos, p->r2);
    const __m512 d = _mm512_sub_ps(_mm512_set1_ps(c->h), len);
    return _mm512_maskz_div_ps(pos, _mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(c->spiky_k), d), d),
                               len);
}

AKP_AVX512 static inline __m512 neg16(__m512 x) { return _mm512_xor_ps(x, _mm512_set1_ps(-0.0f)); }

AKP_AVX512 void akp_fluid_density_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        __m512 rho = _mm512_setzero_ps();
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            load_pairs(c, &B, q, &p);
            rho = _mm512_mask_add_ps(rho, p.m, rho, poly6_16(c, &p));
        }
        _mm512_mask_storeu_ps(c->rho + blk, B.lanes, _mm512_mul_ps(rho, _mm512_set1_ps(c->m)));
    }
}

AKP_AVX512 void akp_fluid_lambda_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    const __m512 mr = _mm512_set1_ps(c->mr), zero = _mm512_setzero_ps();
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        __m512 rho = zero, gx = zero, gy = zero, gz = zero, g2 = zero;
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            load_pairs(c, &B, q, &p);
            rho = _mm512_mask_add_ps(rho, p.m, rho, poly6_16(c, &p));
            const __m512 f = spiky_16(c, &p);
            const __m512 x = _mm512_mul_ps(_mm512_mul_ps(p.rx, f), mr),
                         y = _mm512_mul_ps(_mm512_mul_ps(p.ry, f), mr),
                         z = _mm512_mul_ps(_mm512_mul_ps(p.rz, f), mr);
            gx = _mm512_mask_add_ps(gx, p.m, gx, x);
            gy = _mm512_mask_add_ps(gy, p.m, gy, y);
            gz = _mm512_mask_add_ps(gz, p.m, gz, z);
            g2 = _mm512_mask_add_ps(
                g2, p.m, g2,
                _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(x, x), _mm512_mul_ps(y, y)),
                              _mm512_mul_ps(z, z)));
        }
        rho = _mm512_mul_ps(rho, _mm512_set1_ps(c->m));
        _mm512_mask_storeu_ps(c->rho + blk, B.lanes, rho);
        __m512 C = _mm512_sub_ps(_mm512_div_ps(rho, _mm512_set1_ps(c->rho_c)), _mm512_set1_ps(1.0f));
        if (!c->d.bilateral)
            C = _mm512_mask_mov_ps(C, _mm512_cmp_ps_mask(C, zero, _CMP_LT_OQ), zero);
        const __m512 gg = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(gx, gx), _mm512_mul_ps(gy, gy)),
                                        _mm512_mul_ps(gz, gz));
        const __m512 den = _mm512_add_ps(_mm512_add_ps(gg, g2), _mm512_set1_ps(c->d.relaxation));
        const __m512 lam = _mm512_maskz_div_ps(B.lanes, neg16(C), den);
        _mm512_mask_storeu_ps(c->lambda + blk, B.lanes, lam);
        /* (x, y, z, lambda) records for the correction pass */
        float x[16], y[16], z[16], l[16];
        _mm512_storeu_ps(x, B.px), _mm512_storeu_ps(y, B.py), _mm512_storeu_ps(z, B.pz),
            _mm512_storeu_ps(l, lam);
        for (uint32_t u = 0; u < 16; ++u) {
            if (!(B.lanes >> u & 1u)) continue;
            float* r = c->q4 + 4 * (blk + u);
            r[0] = x[u], r[1] = y[u], r[2] = z[u], r[3] = l[u];
        }
    }
}

AKP_AVX512 void akp_fluid_delta_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    const bool scorr = c->d.scorr && c->wdq > 0.0f;
    const __m512 negk = _mm512_set1_ps(-(c->d.scorr_k / c->grad2_rest)),
                 inv_wdq = _mm512_set1_ps(scorr ? 1.0f / c->wdq : 0.0f);
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512 zero = _mm512_setzero_ps(), mr = _mm512_set1_ps(c->mr);
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        const __m512i self = _mm512_add_epi32(_mm512_set1_epi32((int)blk), lane);
        const __m512 li = _mm512_maskz_loadu_ps(B.lanes, c->lambda + blk);
        __m512 ax = zero, ay = zero, az = zero;
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            __m512 lj;
            load_pairs_from(c, &B, q, c->q4, &lj, &p);
            const __mmask16 other = _mm512_mask_cmpneq_epi32_mask(p.m, p.idx, self); /* j != i */
            __m512 l = _mm512_add_ps(li, lj);
            if (scorr) {
                const __m512 w = _mm512_mul_ps(poly6_16(c, &p), inv_wdq), w2 = _mm512_mul_ps(w, w);
                l = _mm512_add_ps(l, _mm512_mul_ps(negk, _mm512_mul_ps(w2, w2)));
            }
            const __m512 f = spiky_16(c, &p);
            ax = _mm512_mask_add_ps(ax, other, ax, _mm512_mul_ps(_mm512_mul_ps(p.rx, f), l));
            ay = _mm512_mask_add_ps(ay, other, ay, _mm512_mul_ps(_mm512_mul_ps(p.ry, f), l));
            az = _mm512_mask_add_ps(az, other, az, _mm512_mul_ps(_mm512_mul_ps(p.rz, f), l));
        }
        float x[16], y[16], z[16];
        _mm512_storeu_ps(x, _mm512_add_ps(B.px, _mm512_mul_ps(ax, mr)));
        _mm512_storeu_ps(y, _mm512_add_ps(B.py, _mm512_mul_ps(ay, mr)));
        _mm512_storeu_ps(z, _mm512_add_ps(B.pz, _mm512_mul_ps(az, mr)));
        for (uint32_t u = 0; u < 16; ++u)
            if (B.lanes >> u & 1u)
                akp_fluid_delta_finish(c, blk + u, ak_vec3_make(x[u], y[u], z[u]));
    }
}

/* Neighbour velocities and densities of p's lanes from the (v, rho) records in q4. */
AKP_AVX512 static inline void gather_v(const akp_fluid_ctx* c, const pairs16* p, __m512* vx,
                                       __m512* vy, __m512* vz, __m512* rho) {
    load4(c->q4, p->id, vx, vy, vz, rho);
}

/* The block's own velocities. */
AKP_AVX512 static inline void own_v(const akp_fluid_ctx* c, const block16* B, __m512* vx,
                                    __m512* vy, __m512* vz) {
    const __m512i i3 =
        _mm512_mullo_epi32(_mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15),
                           _mm512_set1_epi32(3));
    const float* v = &c->v[B->blk].x;
    const __m512 zero = _mm512_setzero_ps();
    *vx = _mm512_mask_i32gather_ps(zero, B->lanes, i3, v, 4);
    *vy = _mm512_mask_i32gather_ps(zero, B->lanes, i3, v + 1, 4);
    *vz = _mm512_mask_i32gather_ps(zero, B->lanes, i3, v + 2, 4);
}

AKP_AVX512 void akp_fluid_vorticity_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    const __m512 m = _mm512_set1_ps(c->m), zero = _mm512_setzero_ps();
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        __m512 vix, viy, viz;
        own_v(c, &B, &vix, &viy, &viz);
        __m512 wx = zero, wy = zero, wz = zero;
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            load_pairs(c, &B, q, &p);
            __m512 vx, vy, vz, rj;
            gather_v(c, &p, &vx, &vy, &vz, &rj);
            const __mmask16 ok = _mm512_mask_cmp_ps_mask(p.m, rj, zero, _CMP_GT_OQ);
            const __m512 vol = _mm512_maskz_div_ps(ok, m, rj);
            /* g = grad_{p_j} W = -(r f); v_ij = v_j - v_i; w += (v_ij x g) m / rho_j */
            const __m512 f = spiky_16(c, &p);
            const __m512 gx = neg16(_mm512_mul_ps(p.rx, f)), gy = neg16(_mm512_mul_ps(p.ry, f)),
                         gz = neg16(_mm512_mul_ps(p.rz, f));
            const __m512 ux = _mm512_sub_ps(vx, vix), uy = _mm512_sub_ps(vy, viy),
                         uz = _mm512_sub_ps(vz, viz);
            wx = _mm512_mask_add_ps(
                wx, ok, wx,
                _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(uy, gz), _mm512_mul_ps(uz, gy)), vol));
            wy = _mm512_mask_add_ps(
                wy, ok, wy,
                _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(uz, gx), _mm512_mul_ps(ux, gz)), vol));
            wz = _mm512_mask_add_ps(
                wz, ok, wz,
                _mm512_mul_ps(_mm512_sub_ps(_mm512_mul_ps(ux, gy), _mm512_mul_ps(uy, gx)), vol));
        }
        float x[16], y[16], z[16];
        _mm512_storeu_ps(x, wx);
        _mm512_storeu_ps(y, wy);
        _mm512_storeu_ps(z, wz);
        for (uint32_t u = 0; u < 16; ++u) {
            if (!(B.lanes >> u & 1u)) continue;
            const ak_vec3 w = ak_vec3_make(x[u], y[u], z[u]);
            c->omega[blk + u] = w;
            c->omega_len[blk + u] = ak_vec3_length(w);
        }
    }
}

AKP_AVX512 void akp_fluid_xsph_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    const float eps = c->d.vorticity_epsilon, xc = c->d.xsph_c;
    const __m512 m = _mm512_set1_ps(c->m), zero = _mm512_setzero_ps();
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        __m512 vix, viy, viz;
        own_v(c, &B, &vix, &viy, &viz);
        __m512 ex = zero, ey = zero, ez = zero, sx = zero, sy = zero, sz = zero;
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            load_pairs(c, &B, q, &p);
            __m512 vx, vy, vz, rj;
            gather_v(c, &p, &vx, &vy, &vz, &rj);
            const __mmask16 ok = _mm512_mask_cmp_ps_mask(p.m, rj, zero, _CMP_GT_OQ);
            const __m512 vol = _mm512_maskz_div_ps(ok, m, rj);
            if (eps != 0.0f) {
                const __m512 ol = _mm512_mask_i32gather_ps(zero, ok, p.idx, c->omega_len, 4);
                const __m512 f = spiky_16(c, &p), s = _mm512_mul_ps(vol, ol);
                ex = _mm512_mask_add_ps(ex, ok, ex, _mm512_mul_ps(_mm512_mul_ps(p.rx, f), s));
                ey = _mm512_mask_add_ps(ey, ok, ey, _mm512_mul_ps(_mm512_mul_ps(p.ry, f), s));
                ez = _mm512_mask_add_ps(ez, ok, ez, _mm512_mul_ps(_mm512_mul_ps(p.rz, f), s));
            }
            if (xc != 0.0f) {
                const __m512 s = _mm512_mul_ps(vol, poly6_16(c, &p));
                sx = _mm512_mask_add_ps(sx, ok, sx, _mm512_mul_ps(_mm512_sub_ps(vx, vix), s));
                sy = _mm512_mask_add_ps(sy, ok, sy, _mm512_mul_ps(_mm512_sub_ps(vy, viy), s));
                sz = _mm512_mask_add_ps(sz, ok, sz, _mm512_mul_ps(_mm512_sub_ps(vz, viz), s));
            }
        }
        float e3[3][16], s3[3][16];
        _mm512_storeu_ps(e3[0], ex), _mm512_storeu_ps(e3[1], ey), _mm512_storeu_ps(e3[2], ez);
        _mm512_storeu_ps(s3[0], sx), _mm512_storeu_ps(s3[1], sy), _mm512_storeu_ps(s3[2], sz);
        for (uint32_t u = 0; u < 16; ++u)
            if (B.lanes >> u & 1u)
                akp_fluid_xsph_finish(c, blk + u, ak_vec3_make(e3[0][u], e3[1][u], e3[2][u]),
                                      ak_vec3_make(s3[0][u], s3[1][u], s3[2][u]));
    }
}

/* k_cubic: the cubic spline at r^2 (+0 outside), the scalar formula's operations in order. */
AKP_AVX512 static inline __m512 cubic_16(const akp_fluid_ctx* c, const pairs16* p) {
    const __m512 q = _mm512_mul_ps(_mm512_sqrt_ps(p->r2), _mm512_set1_ps(c->inv_h));
    const __m512 k = _mm512_set1_ps(c->cubic_k), qq = _mm512_mul_ps(q, q);
    const __m512 near = _mm512_mul_ps(
        k, _mm512_add_ps(_mm512_mul_ps(_mm512_set1_ps(6.0f),
                                       _mm512_sub_ps(_mm512_mul_ps(qq, q), qq)),
                         _mm512_set1_ps(1.0f)));
    const __m512 u = _mm512_sub_ps(_mm512_set1_ps(1.0f), q);
    const __m512 far = _mm512_mul_ps(
        _mm512_mul_ps(_mm512_mul_ps(_mm512_mul_ps(k, _mm512_set1_ps(2.0f)), u), u), u);
    const __mmask16 is_near = _mm512_cmp_ps_mask(q, _mm512_set1_ps(0.5f), _CMP_LE_OQ);
    return _mm512_maskz_mov_ps(p->in, _mm512_mask_blend_ps(is_near, far, near));
}

/* k_cubic_grad's factor dw / |r| (+0 outside and at r = 0). */
AKP_AVX512 static inline __m512 cubic_grad_16(const akp_fluid_ctx* c, const pairs16* p) {
    const __mmask16 pos = _mm512_mask_cmp_ps_mask(p->in, p->r2, _mm512_setzero_ps(), _CMP_GT_OQ);
    const __m512 len = _mm512_sqrt_ps(p->r2);
    const __m512 q = _mm512_mul_ps(len, _mm512_set1_ps(c->inv_h));
    const __m512 u = _mm512_sub_ps(_mm512_set1_ps(1.0f), q);
    const __m512 gk = _mm512_set1_ps(c->cubic_gk);
    const __m512 near = _mm512_mul_ps(
        gk, _mm512_sub_ps(_mm512_mul_ps(_mm512_mul_ps(_mm512_set1_ps(3.0f), q), q),
                          _mm512_mul_ps(_mm512_set1_ps(2.0f), q)));
    const __m512 far = _mm512_mul_ps(_mm512_mul_ps(neg16(gk), u), u);
    const __mmask16 is_near = _mm512_cmp_ps_mask(q, _mm512_set1_ps(0.5f), _CMP_LE_OQ);
    return _mm512_maskz_div_ps(pos, _mm512_mask_blend_ps(is_near, far, near), len);
}

AKP_AVX512 void akp_fluid_density_cubic_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        __m512 rho = _mm512_setzero_ps();
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            load_pairs(c, &B, q, &p);
            rho = _mm512_mask_add_ps(rho, p.m, rho, cubic_16(c, &p));
        }
        _mm512_mask_storeu_ps(c->rho + blk, B.lanes, _mm512_mul_ps(rho, _mm512_set1_ps(c->m)));
    }
}

/* ph_forces on 16 particles at a time: neighbour positions and pressures from p4, velocities
 * and densities from q4 (ph_pack_forces); the sums' tails in akp_fluid_forces_finish. */
AKP_AVX512 void akp_fluid_forces_avx512(akp_fluid_ctx* c, size_t b, size_t e) {
    const ak_fluid_desc* d = &c->d;
    const bool mcg = d->solver == AK_FLUID_SPH, visc = d->viscosity != 0.0f;
    const float mu = d->viscosity, h = c->h;
    const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
    const __m512 zero = _mm512_setzero_ps(), negm = _mm512_set1_ps(-c->m),
                 two = _mm512_set1_ps(2.0f), vh = _mm512_set1_ps(h),
                 mum = _mm512_set1_ps(mu * c->m), lapk = _mm512_set1_ps(c->visc_lap_k),
                 nuk = _mm512_set1_ps(2.0f * mu * h * d->sound_speed),
                 eps2 = _mm512_set1_ps(0.01f * h * h);
    for (size_t blk = b & ~(size_t)15; blk < e; blk += 16) {
        block16 B;
        block_begin(c, blk, b, e, &B);
        const __m512i self = _mm512_add_epi32(_mm512_set1_epi32((int)blk), lane);
        __m512 vix, viy, viz;
        own_v(c, &B, &vix, &viy, &viz);
        const __m512 rhoi = _mm512_maskz_loadu_ps(B.lanes, c->rho + blk),
                     pri = _mm512_maskz_loadu_ps(B.lanes, c->pres + blk);
        const __m512 pri_r = _mm512_div_ps(pri, _mm512_mul_ps(rhoi, rhoi)); /* WCSPH */
        __m512 ax = zero, ay = zero, az = zero;
        for (uint32_t q = 0; q < B.max_count; ++q) {
            pairs16 p;
            __m512 prj, vjx, vjy, vjz, rhoj;
            load_pairs_from(c, &B, q, c->p4, &prj, &p);
            load4(c->q4, p.id, &vjx, &vjy, &vjz, &rhoj);
            const __mmask16 other = _mm512_mask_cmpneq_epi32_mask(p.m, p.idx, self); /* j != i */
            if (mcg) {
                const __m512 f = spiky_16(c, &p);
                const __m512 s = _mm512_div_ps(_mm512_mul_ps(negm, _mm512_add_ps(pri, prj)),
                                               _mm512_mul_ps(two, rhoj));
                ax = _mm512_mask_add_ps(ax, other, ax, _mm512_mul_ps(_mm512_mul_ps(p.rx, f), s));
                ay = _mm512_mask_add_ps(ay, other, ay, _mm512_mul_ps(_mm512_mul_ps(p.ry, f), s));
                az = _mm512_mask_add_ps(az, other, az, _mm512_mul_ps(_mm512_mul_ps(p.rz, f), s));
                if (visc) {
                    /* ak_fluid_visc_laplacian(|r|, h): +0 unless |r| < h */
                    const __m512 len = _mm512_sqrt_ps(p.r2);
                    const __mmask16 near = _mm512_cmp_ps_mask(len, vh, _CMP_LT_OQ);
                    const __m512 lap = _mm512_maskz_mul_ps(near, lapk, _mm512_sub_ps(vh, len));
                    const __m512 s2 = _mm512_mul_ps(_mm512_div_ps(mum, rhoj), lap);
                    ax = _mm512_mask_add_ps(ax, other, ax, _mm512_mul_ps(_mm512_sub_ps(vjx, vix), s2));
                    ay = _mm512_mask_add_ps(ay, other, ay, _mm512_mul_ps(_mm512_sub_ps(vjy, viy), s2));
                    az = _mm512_mask_add_ps(az, other, az, _mm512_mul_ps(_mm512_sub_ps(vjz, viz), s2));
                }
            } else {
                const __m512 f = cubic_grad_16(c, &p);
                __m512 coef = _mm512_add_ps(pri_r, _mm512_div_ps(prj, _mm512_mul_ps(rhoj, rhoj)));
                if (visc) {
                    const __m512 ux = _mm512_sub_ps(vix, vjx), uy = _mm512_sub_ps(viy, vjy),
                                 uz = _mm512_sub_ps(viz, vjz);
                    const __m512 vx = _mm512_add_ps(
                        _mm512_add_ps(_mm512_mul_ps(ux, p.rx), _mm512_mul_ps(uy, p.ry)),
                        _mm512_mul_ps(uz, p.rz));
                    const __mmask16 app = _mm512_cmp_ps_mask(vx, zero, _CMP_LT_OQ);
                    const __m512 nu = _mm512_div_ps(nuk, _mm512_add_ps(rhoi, rhoj));
                    coef = _mm512_mask_add_ps(
                        coef, app, coef,
                        _mm512_div_ps(_mm512_mul_ps(neg16(nu), vx), _mm512_add_ps(p.r2, eps2)));
                }
                const __m512 s = _mm512_mul_ps(negm, coef);
                ax = _mm512_mask_add_ps(ax, other, ax, _mm512_mul_ps(_mm512_mul_ps(p.rx, f), s));
                ay = _mm512_mask_add_ps(ay, other, ay, _mm512_mul_ps(_mm512_mul_ps(p.ry, f), s));
                az = _mm512_mask_add_ps(az, other, az, _mm512_mul_ps(_mm512_mul_ps(p.rz, f), s));
            }
        }
        float x[16], y[16], z[16];
        _mm512_storeu_ps(x, ax), _mm512_storeu_ps(y, ay), _mm512_storeu_ps(z, az);
        for (uint32_t u = 0; u < 16; ++u)
            if (B.lanes >> u & 1u) akp_fluid_forces_finish(c, blk + u, ak_vec3_make(x[u], y[u], z[u]));
    }
}


#else

bool akp_fluid_have_avx512(void) { return false; }
uint32_t akp_fluid_filter_avx512(const akp_fluid_ctx* c, uint32_t begin, uint32_t end, float qx,
                                 float qy, float qz, uint32_t* list, uint32_t* k, uint32_t* close) {
    (void)c, (void)begin, (void)end, (void)qx, (void)qy, (void)qz, (void)list, (void)k, (void)close;
    return 0;
}
void akp_fluid_density_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_lambda_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_delta_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_vorticity_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_xsph_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_density_cubic_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_forces_avx512(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }

#endif
