/* AVX2 kernels of the fluid solver: avx512.c's kernels on 8 lanes, for CPUs without AVX-512.
 * The filter tests 8 candidates at a time and appends the hits in index order; the phases take
 * each block of 16 particles as two halves of 8, one particle per lane, gather slot q of their
 * lists from the padded slot-major layout, load the neighbours' 16-byte records with a 4 x 4
 * transpose, and add each lane's terms in list order with the scalar phase's float operations
 * (no FMA; IEEE sqrt and division). Skipped terms are masked to +0 before the add, which leaves
 * a sum unchanged (a sum that starts at +0 is never -0), so results are bit-identical to the
 * scalar and AVX-512 kernels (tested).
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; selected at run time with
 * __builtin_cpu_supports. */

/* The SIMD kernels give the scalar code's bits only if nothing fuses a * b + c: clang contracts
 * within an expression by default (and avx512f implies FMA); gcc's C11 mode does not. */
#if defined(__clang__)
#pragma STDC FP_CONTRACT OFF
#endif
#include "fluid_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX2 __attribute__((target("avx2")))

bool akp_fluid_have_avx2(void) { return __builtin_cpu_supports("avx2"); }

/* All-ones lanes k with lo <= k < hi. */
AKP_AVX2 static inline __m256 range_mask(int lo, int hi) {
    const __m256i l = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    return _mm256_castsi256_ps(_mm256_and_si256(_mm256_cmpgt_epi32(_mm256_set1_epi32(hi), l),
                                                _mm256_cmpgt_epi32(l, _mm256_set1_epi32(lo - 1))));
}

AKP_AVX2 uint32_t akp_fluid_filter_avx2(const akp_fluid_ctx* c, uint32_t begin, uint32_t end,
                                        float qx, float qy, float qz, uint32_t* list, uint32_t* k,
                                        uint32_t* close) {
    const __m256 vx = _mm256_set1_ps(qx), vy = _mm256_set1_ps(qy), vz = _mm256_set1_ps(qz);
    const __m256 vr = _mm256_set1_ps(c->h2), vc = _mm256_set1_ps(c->coincident2);
    const uint32_t K = c->K;
    uint32_t found = 0, kk = *k;
    for (uint32_t t = begin; t < end; t += 8) {
        const __m256 live = range_mask(0, end - t < 8 ? (int)(end - t) : 8);
        const __m256i li = _mm256_castps_si256(live);
        const __m256 dx = _mm256_sub_ps(_mm256_maskload_ps(c->px + t, li), vx);
        const __m256 dy = _mm256_sub_ps(_mm256_maskload_ps(c->py + t, li), vy);
        const __m256 dz = _mm256_sub_ps(_mm256_maskload_ps(c->pz + t, li), vz);
        const __m256 dd = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                        _mm256_mul_ps(dz, dz));
        unsigned m =
            (unsigned)_mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(dd, vr, _CMP_LT_OQ), live));
        if (m)
            *close += (uint32_t)__builtin_popcount(
                (unsigned)_mm256_movemask_ps(_mm256_and_ps(_mm256_cmp_ps(dd, vc, _CMP_LT_OQ), live)));
        while (m) {
            const uint32_t u = (uint32_t)__builtin_ctz(m);
            m &= m - 1u;
            ++found;
            if (kk < K) list[kk++] = t + u;
        }
    }
    *k = kk;
    return found;
}

/* Half h of the block of 16 sorted particles at blk, clipped to [b, e). */
typedef struct half8 {
    size_t base; /* first particle of the half */
    __m256 lanes;
    __m256i cnt;
    uint32_t max_count;
    unsigned bits;      /* lanes as bits */
    const uint32_t* nb; /* slot q of the half's lists at nb + 16 q */
    __m256 px, py, pz;
} half8;

AKP_AVX2 static inline bool half_begin(const akp_fluid_ctx* c, size_t blk, int h, size_t b,
                                       size_t e, half8* o) {
    const size_t base = blk + 8u * (size_t)h;
    if (base >= e || base + 8 <= b) return false;
    const int lo = base < b ? (int)(b - base) : 0, hi = e - base >= 8 ? 8 : (int)(e - base);
    o->base = base;
    o->lanes = range_mask(lo, hi);
    o->bits = (unsigned)_mm256_movemask_ps(o->lanes);
    const __m256i li = _mm256_castps_si256(o->lanes);
    o->cnt = _mm256_maskload_epi32((const int*)(const void*)(c->nb_count + base), li);
    uint32_t cnt[8];
    _mm256_storeu_si256((__m256i*)(void*)cnt, o->cnt);
    o->max_count = 0;
    for (int u = 0; u < 8; ++u) o->max_count = cnt[u] > o->max_count ? cnt[u] : o->max_count;
    o->nb = c->nb + (blk >> 4) * c->K * 16 + 8u * (size_t)h;
    o->px = _mm256_maskload_ps(c->px + base, li);
    o->py = _mm256_maskload_ps(c->py + base, li);
    o->pz = _mm256_maskload_ps(c->pz + base, li);
    return true;
}

typedef struct pairs8 {
    const uint32_t* id; /* the slot's 8 entries (padded lists: all valid) */
    __m256 rx, ry, rz, r2;
    __m256 m;  /* lanes whose list has a slot q */
    __m256 in; /* and r^2 < h^2 */
} pairs8;

/* Records rec[4 id[k]] of 8 particles as x, y, z (and w) lanes. */
AKP_AVX2 static inline void load4(const float* rec, const uint32_t* id, __m256* x, __m256* y,
                                  __m256* z, __m256* w) {
#define R(k) _mm_load_ps(rec + 4 * (size_t)id[k])
#define ROW(a, b2) _mm256_insertf128_ps(_mm256_castps128_ps256(R(a)), R(b2), 1)
    const __m256 A = ROW(0, 4), B = ROW(1, 5), C = ROW(2, 6), D = ROW(3, 7);
#undef ROW
#undef R
    const __m256 t0 = _mm256_unpacklo_ps(A, B), t1 = _mm256_unpackhi_ps(A, B);
    const __m256 t2 = _mm256_unpacklo_ps(C, D), t3 = _mm256_unpackhi_ps(C, D);
    *x = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(t0), _mm256_castps_pd(t2)));
    *y = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(t0), _mm256_castps_pd(t2)));
    *z = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(t1), _mm256_castps_pd(t3)));
    if (w) *w = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(t1), _mm256_castps_pd(t3)));
}

AKP_AVX2 static inline void load_pairs(const akp_fluid_ctx* c, const half8* H, uint32_t q,
                                       const float* rec, __m256* w, pairs8* o) {
    o->m = _mm256_and_ps(
        H->lanes, _mm256_castsi256_ps(_mm256_cmpgt_epi32(H->cnt, _mm256_set1_epi32((int)q))));
    o->id = H->nb + (size_t)q * 16;
    __m256 x, y, z;
    load4(rec, o->id, &x, &y, &z, w);
    o->rx = _mm256_sub_ps(H->px, x);
    o->ry = _mm256_sub_ps(H->py, y);
    o->rz = _mm256_sub_ps(H->pz, z);
    o->r2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(o->rx, o->rx), _mm256_mul_ps(o->ry, o->ry)),
                          _mm256_mul_ps(o->rz, o->rz));
    o->in = _mm256_and_ps(o->m, _mm256_cmp_ps(o->r2, _mm256_set1_ps(c->h2), _CMP_LT_OQ));
}

AKP_AVX2 static inline __m256 poly6_8(const akp_fluid_ctx* c, const pairs8* p) {
    const __m256 d = _mm256_sub_ps(_mm256_set1_ps(c->h2), p->r2);
    return _mm256_and_ps(
        p->in, _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(c->poly6_k), d), d), d));
}

AKP_AVX2 static inline __m256 spiky_8(const akp_fluid_ctx* c, const pairs8* p) {
    const __m256 pos = _mm256_and_ps(p->in, _mm256_cmp_ps(p->r2, _mm256_setzero_ps(), _CMP_GT_OQ));
    const __m256 len = _mm256_sqrt_ps(p->r2);
    const __m256 d = _mm256_sub_ps(_mm256_set1_ps(c->h), len);
    return _mm256_and_ps(
        pos, _mm256_div_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(c->spiky_k), d), d), len));
}

AKP_AVX2 static inline __m256 neg8(__m256 x) { return _mm256_xor_ps(x, _mm256_set1_ps(-0.0f)); }

/* acc + (mask ? x : +0) */
AKP_AVX2 static inline __m256 add_masked(__m256 acc, __m256 mask, __m256 x) {
    return _mm256_add_ps(acc, _mm256_and_ps(mask, x));
}

#define FOR_HALVES(c, b, e, H)                                                                     \
    for (size_t blk = (b) & ~(size_t)15; blk < (e); blk += 16)                                     \
        for (int h = 0; h < 2; ++h)                                                                \
            if (half_begin((c), blk, h, (b), (e), &(H)))

AKP_AVX2 void akp_fluid_density_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    half8 H;
    FOR_HALVES(c, b, e, H) {
        __m256 rho = _mm256_setzero_ps();
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            load_pairs(c, &H, q, c->p4, NULL, &p);
            rho = _mm256_add_ps(rho, poly6_8(c, &p));
        }
        _mm256_maskstore_ps(c->rho + H.base, _mm256_castps_si256(H.lanes),
                            _mm256_mul_ps(rho, _mm256_set1_ps(c->m)));
    }
}

AKP_AVX2 void akp_fluid_lambda_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    const __m256 mr = _mm256_set1_ps(c->mr), zero = _mm256_setzero_ps();
    half8 H;
    FOR_HALVES(c, b, e, H) {
        __m256 rho = zero, gx = zero, gy = zero, gz = zero, g2 = zero;
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            load_pairs(c, &H, q, c->p4, NULL, &p);
            rho = _mm256_add_ps(rho, poly6_8(c, &p));
            const __m256 f = spiky_8(c, &p);
            const __m256 x = _mm256_mul_ps(_mm256_mul_ps(p.rx, f), mr),
                         y = _mm256_mul_ps(_mm256_mul_ps(p.ry, f), mr),
                         z = _mm256_mul_ps(_mm256_mul_ps(p.rz, f), mr);
            gx = add_masked(gx, p.m, x);
            gy = add_masked(gy, p.m, y);
            gz = add_masked(gz, p.m, z);
            g2 = add_masked(g2, p.m,
                            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x, x), _mm256_mul_ps(y, y)),
                                          _mm256_mul_ps(z, z)));
        }
        const __m256i li = _mm256_castps_si256(H.lanes);
        rho = _mm256_mul_ps(rho, _mm256_set1_ps(c->m));
        _mm256_maskstore_ps(c->rho + H.base, li, rho);
        __m256 C = _mm256_sub_ps(_mm256_div_ps(rho, _mm256_set1_ps(c->rho_c)), _mm256_set1_ps(1.0f));
        if (!c->d.bilateral) C = _mm256_blendv_ps(C, zero, _mm256_cmp_ps(C, zero, _CMP_LT_OQ));
        const __m256 gg = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(gx, gx), _mm256_mul_ps(gy, gy)),
                                        _mm256_mul_ps(gz, gz));
        const __m256 den = _mm256_add_ps(_mm256_add_ps(gg, g2), _mm256_set1_ps(c->d.relaxation));
        const __m256 lam = _mm256_div_ps(neg8(C), den);
        _mm256_maskstore_ps(c->lambda + H.base, li, lam);
        float x[8], y[8], z[8], l[8];
        _mm256_storeu_ps(x, H.px), _mm256_storeu_ps(y, H.py), _mm256_storeu_ps(z, H.pz),
            _mm256_storeu_ps(l, lam);
        for (uint32_t u = 0; u < 8; ++u) {
            if (!(H.bits >> u & 1u)) continue;
            float* r = c->q4 + 4 * (H.base + u);
            r[0] = x[u], r[1] = y[u], r[2] = z[u], r[3] = l[u];
        }
    }
}

AKP_AVX2 void akp_fluid_delta_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    const bool scorr = c->d.scorr && c->wdq > 0.0f;
    const __m256 negk = _mm256_set1_ps(-(c->d.scorr_k / c->grad2_rest)),
                 inv_wdq = _mm256_set1_ps(scorr ? 1.0f / c->wdq : 0.0f);
    const __m256 zero = _mm256_setzero_ps(), mr = _mm256_set1_ps(c->mr);
    half8 H;
    FOR_HALVES(c, b, e, H) {
        const __m256i self = _mm256_add_epi32(_mm256_set1_epi32((int)H.base),
                                              _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        const __m256 li = _mm256_maskload_ps(c->lambda + H.base, _mm256_castps_si256(H.lanes));
        __m256 ax = zero, ay = zero, az = zero;
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            __m256 lj;
            load_pairs(c, &H, q, c->q4, &lj, &p);
            const __m256i idx = _mm256_loadu_si256((const __m256i*)(const void*)p.id);
            const __m256 other = _mm256_andnot_ps(
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(idx, self)), p.m); /* j != i */
            __m256 l = _mm256_add_ps(li, lj);
            if (scorr) {
                const __m256 w = _mm256_mul_ps(poly6_8(c, &p), inv_wdq), w2 = _mm256_mul_ps(w, w);
                l = _mm256_add_ps(l, _mm256_mul_ps(negk, _mm256_mul_ps(w2, w2)));
            }
            const __m256 f = spiky_8(c, &p);
            ax = add_masked(ax, other, _mm256_mul_ps(_mm256_mul_ps(p.rx, f), l));
            ay = add_masked(ay, other, _mm256_mul_ps(_mm256_mul_ps(p.ry, f), l));
            az = add_masked(az, other, _mm256_mul_ps(_mm256_mul_ps(p.rz, f), l));
        }
        float x[8], y[8], z[8];
        _mm256_storeu_ps(x, _mm256_add_ps(H.px, _mm256_mul_ps(ax, mr)));
        _mm256_storeu_ps(y, _mm256_add_ps(H.py, _mm256_mul_ps(ay, mr)));
        _mm256_storeu_ps(z, _mm256_add_ps(H.pz, _mm256_mul_ps(az, mr)));
        for (uint32_t u = 0; u < 8; ++u)
            if (H.bits >> u & 1u)
                akp_fluid_delta_finish(c, H.base + u, ak_vec3_make(x[u], y[u], z[u]));
    }
}

/* The half's own velocities. */
AKP_AVX2 static inline void own_v(const akp_fluid_ctx* c, const half8* H, __m256* vx, __m256* vy,
                                  __m256* vz) {
    const __m256i i3 = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21);
    const float* v = &c->v[H->base].x;
    const __m256 zero = _mm256_setzero_ps();
    *vx = _mm256_mask_i32gather_ps(zero, v, i3, H->lanes, 4);
    *vy = _mm256_mask_i32gather_ps(zero, v + 1, i3, H->lanes, 4);
    *vz = _mm256_mask_i32gather_ps(zero, v + 2, i3, H->lanes, 4);
}

AKP_AVX2 void akp_fluid_vorticity_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    const __m256 m = _mm256_set1_ps(c->m), zero = _mm256_setzero_ps();
    half8 H;
    FOR_HALVES(c, b, e, H) {
        __m256 vix, viy, viz;
        own_v(c, &H, &vix, &viy, &viz);
        __m256 wx = zero, wy = zero, wz = zero;
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            __m256 vx, vy, vz, rj;
            load_pairs(c, &H, q, c->p4, NULL, &p);
            load4(c->q4, p.id, &vx, &vy, &vz, &rj);
            const __m256 ok = _mm256_and_ps(p.m, _mm256_cmp_ps(rj, zero, _CMP_GT_OQ));
            const __m256 vol = _mm256_div_ps(m, rj);
            const __m256 f = spiky_8(c, &p);
            const __m256 gx = neg8(_mm256_mul_ps(p.rx, f)), gy = neg8(_mm256_mul_ps(p.ry, f)),
                         gz = neg8(_mm256_mul_ps(p.rz, f));
            const __m256 ux = _mm256_sub_ps(vx, vix), uy = _mm256_sub_ps(vy, viy),
                         uz = _mm256_sub_ps(vz, viz);
            wx = add_masked(
                wx, ok,
                _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(uy, gz), _mm256_mul_ps(uz, gy)), vol));
            wy = add_masked(
                wy, ok,
                _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(uz, gx), _mm256_mul_ps(ux, gz)), vol));
            wz = add_masked(
                wz, ok,
                _mm256_mul_ps(_mm256_sub_ps(_mm256_mul_ps(ux, gy), _mm256_mul_ps(uy, gx)), vol));
        }
        float x[8], y[8], z[8];
        _mm256_storeu_ps(x, wx), _mm256_storeu_ps(y, wy), _mm256_storeu_ps(z, wz);
        for (uint32_t u = 0; u < 8; ++u) {
            if (!(H.bits >> u & 1u)) continue;
            const ak_vec3 w = ak_vec3_make(x[u], y[u], z[u]);
            c->omega[H.base + u] = w;
            c->omega_len[H.base + u] = ak_vec3_length(w);
        }
    }
}

AKP_AVX2 void akp_fluid_xsph_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    const float eps = c->d.vorticity_epsilon, xc = c->d.xsph_c;
    const __m256 m = _mm256_set1_ps(c->m), zero = _mm256_setzero_ps();
    half8 H;
    FOR_HALVES(c, b, e, H) {
        __m256 vix, viy, viz;
        own_v(c, &H, &vix, &viy, &viz);
        __m256 ex = zero, ey = zero, ez = zero, sx = zero, sy = zero, sz = zero;
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            __m256 vx, vy, vz, rj;
            load_pairs(c, &H, q, c->p4, NULL, &p);
            load4(c->q4, p.id, &vx, &vy, &vz, &rj);
            const __m256 ok = _mm256_and_ps(p.m, _mm256_cmp_ps(rj, zero, _CMP_GT_OQ));
            const __m256 vol = _mm256_div_ps(m, rj);
            if (eps != 0.0f) {
                const __m256i idx = _mm256_loadu_si256((const __m256i*)(const void*)p.id);
                const __m256 ol = _mm256_mask_i32gather_ps(zero, c->omega_len, idx, ok, 4);
                const __m256 f = spiky_8(c, &p), s = _mm256_mul_ps(vol, ol);
                ex = add_masked(ex, ok, _mm256_mul_ps(_mm256_mul_ps(p.rx, f), s));
                ey = add_masked(ey, ok, _mm256_mul_ps(_mm256_mul_ps(p.ry, f), s));
                ez = add_masked(ez, ok, _mm256_mul_ps(_mm256_mul_ps(p.rz, f), s));
            }
            if (xc != 0.0f) {
                const __m256 s = _mm256_mul_ps(vol, poly6_8(c, &p));
                sx = add_masked(sx, ok, _mm256_mul_ps(_mm256_sub_ps(vx, vix), s));
                sy = add_masked(sy, ok, _mm256_mul_ps(_mm256_sub_ps(vy, viy), s));
                sz = add_masked(sz, ok, _mm256_mul_ps(_mm256_sub_ps(vz, viz), s));
            }
        }
        float e3[3][8], s3[3][8];
        _mm256_storeu_ps(e3[0], ex), _mm256_storeu_ps(e3[1], ey), _mm256_storeu_ps(e3[2], ez);
        _mm256_storeu_ps(s3[0], sx), _mm256_storeu_ps(s3[1], sy), _mm256_storeu_ps(s3[2], sz);
        for (uint32_t u = 0; u < 8; ++u)
            if (H.bits >> u & 1u)
                akp_fluid_xsph_finish(c, H.base + u, ak_vec3_make(e3[0][u], e3[1][u], e3[2][u]),
                                      ak_vec3_make(s3[0][u], s3[1][u], s3[2][u]));
    }
}

/* k_cubic: the cubic spline at r^2 (+0 outside), the scalar formula's operations in order. */
AKP_AVX2 static inline __m256 cubic_8(const akp_fluid_ctx* c, const pairs8* p) {
    const __m256 q = _mm256_mul_ps(_mm256_sqrt_ps(p->r2), _mm256_set1_ps(c->inv_h));
    const __m256 k = _mm256_set1_ps(c->cubic_k), qq = _mm256_mul_ps(q, q);
    const __m256 near = _mm256_mul_ps(
        k, _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(6.0f),
                                       _mm256_sub_ps(_mm256_mul_ps(qq, q), qq)),
                         _mm256_set1_ps(1.0f)));
    const __m256 u = _mm256_sub_ps(_mm256_set1_ps(1.0f), q);
    const __m256 far = _mm256_mul_ps(
        _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(k, _mm256_set1_ps(2.0f)), u), u), u);
    const __m256 is_near = _mm256_cmp_ps(q, _mm256_set1_ps(0.5f), _CMP_LE_OQ);
    return _mm256_and_ps(p->in, _mm256_blendv_ps(far, near, is_near));
}

/* k_cubic_grad's factor dw / |r| (+0 outside and at r = 0). */
AKP_AVX2 static inline __m256 cubic_grad_8(const akp_fluid_ctx* c, const pairs8* p) {
    const __m256 pos = _mm256_and_ps(p->in, _mm256_cmp_ps(p->r2, _mm256_setzero_ps(), _CMP_GT_OQ));
    const __m256 len = _mm256_sqrt_ps(p->r2);
    const __m256 q = _mm256_mul_ps(len, _mm256_set1_ps(c->inv_h));
    const __m256 u = _mm256_sub_ps(_mm256_set1_ps(1.0f), q);
    const __m256 gk = _mm256_set1_ps(c->cubic_gk);
    const __m256 near = _mm256_mul_ps(
        gk, _mm256_sub_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(3.0f), q), q),
                          _mm256_mul_ps(_mm256_set1_ps(2.0f), q)));
    const __m256 far = _mm256_mul_ps(_mm256_mul_ps(neg8(gk), u), u);
    const __m256 is_near = _mm256_cmp_ps(q, _mm256_set1_ps(0.5f), _CMP_LE_OQ);
    return _mm256_and_ps(pos, _mm256_div_ps(_mm256_blendv_ps(far, near, is_near), len));
}

AKP_AVX2 void akp_fluid_density_cubic_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    half8 H;
    FOR_HALVES(c, b, e, H) {
        __m256 rho = _mm256_setzero_ps();
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            load_pairs(c, &H, q, c->p4, NULL, &p);
            rho = add_masked(rho, p.m, cubic_8(c, &p));
        }
        _mm256_maskstore_ps(c->rho + H.base, _mm256_castps_si256(H.lanes),
                            _mm256_mul_ps(rho, _mm256_set1_ps(c->m)));
    }
}

/* ph_forces on 8 particles at a time: neighbour positions and pressures from p4, velocities and
 * densities from q4 (ph_pack_forces); the sums' tails in akp_fluid_forces_finish. */
AKP_AVX2 void akp_fluid_forces_avx2(akp_fluid_ctx* c, size_t b, size_t e) {
    const ak_fluid_desc* d = &c->d;
    const bool mcg = d->solver == AK_FLUID_SPH, visc = d->viscosity != 0.0f;
    const float mu = d->viscosity, h = c->h;
    const __m256 zero = _mm256_setzero_ps(), negm = _mm256_set1_ps(-c->m),
                 two = _mm256_set1_ps(2.0f), vh = _mm256_set1_ps(h),
                 mum = _mm256_set1_ps(mu * c->m), lapk = _mm256_set1_ps(c->visc_lap_k),
                 nuk = _mm256_set1_ps(2.0f * mu * h * d->sound_speed),
                 eps2 = _mm256_set1_ps(0.01f * h * h);
    half8 H;
    FOR_HALVES(c, b, e, H) {
        const __m256i self = _mm256_add_epi32(_mm256_set1_epi32((int)H.base),
                                              _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        const __m256i li = _mm256_castps_si256(H.lanes);
        __m256 vix, viy, viz;
        own_v(c, &H, &vix, &viy, &viz);
        const __m256 rhoi = _mm256_maskload_ps(c->rho + H.base, li),
                     pri = _mm256_maskload_ps(c->pres + H.base, li);
        const __m256 pri_r = _mm256_div_ps(pri, _mm256_mul_ps(rhoi, rhoi)); /* WCSPH */
        __m256 ax = zero, ay = zero, az = zero;
        for (uint32_t q = 0; q < H.max_count; ++q) {
            pairs8 p;
            __m256 prj, vjx, vjy, vjz, rhoj;
            load_pairs(c, &H, q, c->p4, &prj, &p);
            load4(c->q4, p.id, &vjx, &vjy, &vjz, &rhoj);
            const __m256i idx = _mm256_loadu_si256((const __m256i*)(const void*)p.id);
            const __m256 other = _mm256_andnot_ps(
                _mm256_castsi256_ps(_mm256_cmpeq_epi32(idx, self)), p.m); /* j != i */
            if (mcg) {
                const __m256 f = spiky_8(c, &p);
                const __m256 s = _mm256_div_ps(_mm256_mul_ps(negm, _mm256_add_ps(pri, prj)),
                                               _mm256_mul_ps(two, rhoj));
                ax = add_masked(ax, other, _mm256_mul_ps(_mm256_mul_ps(p.rx, f), s));
                ay = add_masked(ay, other, _mm256_mul_ps(_mm256_mul_ps(p.ry, f), s));
                az = add_masked(az, other, _mm256_mul_ps(_mm256_mul_ps(p.rz, f), s));
                if (visc) {
                    /* ak_fluid_visc_laplacian(|r|, h): +0 unless |r| < h */
                    const __m256 len = _mm256_sqrt_ps(p.r2);
                    const __m256 near = _mm256_cmp_ps(len, vh, _CMP_LT_OQ);
                    const __m256 lap = _mm256_and_ps(near, _mm256_mul_ps(lapk, _mm256_sub_ps(vh, len)));
                    const __m256 s2 = _mm256_mul_ps(_mm256_div_ps(mum, rhoj), lap);
                    ax = add_masked(ax, other, _mm256_mul_ps(_mm256_sub_ps(vjx, vix), s2));
                    ay = add_masked(ay, other, _mm256_mul_ps(_mm256_sub_ps(vjy, viy), s2));
                    az = add_masked(az, other, _mm256_mul_ps(_mm256_sub_ps(vjz, viz), s2));
                }
            } else {
                const __m256 f = cubic_grad_8(c, &p);
                __m256 coef = _mm256_add_ps(pri_r, _mm256_div_ps(prj, _mm256_mul_ps(rhoj, rhoj)));
                if (visc) {
                    const __m256 ux = _mm256_sub_ps(vix, vjx), uy = _mm256_sub_ps(viy, vjy),
                                 uz = _mm256_sub_ps(viz, vjz);
                    const __m256 vx = _mm256_add_ps(
                        _mm256_add_ps(_mm256_mul_ps(ux, p.rx), _mm256_mul_ps(uy, p.ry)),
                        _mm256_mul_ps(uz, p.rz));
                    const __m256 app = _mm256_cmp_ps(vx, zero, _CMP_LT_OQ);
                    const __m256 nu = _mm256_div_ps(nuk, _mm256_add_ps(rhoi, rhoj));
                    coef = _mm256_blendv_ps(
                        coef,
                        _mm256_add_ps(coef, _mm256_div_ps(_mm256_mul_ps(neg8(nu), vx),
                                                          _mm256_add_ps(p.r2, eps2))),
                        app);
                }
                const __m256 s = _mm256_mul_ps(negm, coef);
                ax = add_masked(ax, other, _mm256_mul_ps(_mm256_mul_ps(p.rx, f), s));
                ay = add_masked(ay, other, _mm256_mul_ps(_mm256_mul_ps(p.ry, f), s));
                az = add_masked(az, other, _mm256_mul_ps(_mm256_mul_ps(p.rz, f), s));
            }
        }
        float x[8], y[8], z[8];
        _mm256_storeu_ps(x, ax), _mm256_storeu_ps(y, ay), _mm256_storeu_ps(z, az);
        for (uint32_t u = 0; u < 8; ++u)
            if (H.bits >> u & 1u)
                akp_fluid_forces_finish(c, H.base + u, ak_vec3_make(x[u], y[u], z[u]));
    }
}


#else

bool akp_fluid_have_avx2(void) { return false; }
uint32_t akp_fluid_filter_avx2(const akp_fluid_ctx* c, uint32_t begin, uint32_t end, float qx,
                               float qy, float qz, uint32_t* list, uint32_t* k, uint32_t* close) {
    (void)c, (void)begin, (void)end, (void)qx, (void)qy, (void)qz, (void)list, (void)k, (void)close;
    return 0;
}
void akp_fluid_density_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_lambda_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_delta_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_vorticity_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_xsph_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_density_cubic_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }
void akp_fluid_forces_avx2(akp_fluid_ctx* c, size_t b, size_t e) { (void)c, (void)b, (void)e; }

#endif
