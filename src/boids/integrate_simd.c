/* AVX-512 and AVX2 integration of the boids step's common case, 8 agents at a time (see
 * akp_boids_integrate_avx512 in boids_internal.h): one AVX body (integrate8) after each
 * entry's own dequantisation of the fixed-point sums (AVX-512: int64 -> double in one
 * instruction; AVX2: in two exact halves and one rounding). Every float and double operation
 * is the scalar integrate()'s in boids.c, in the same order, each rounded (intrinsics, no
 * FMA, no reciprocal approximations): int64 -> double and double -> float conversions round
 * to nearest like the C casts, and the divisions and square roots are IEEE-exact, so each
 * lane is bit-identical to the scalar code (tested). Lanes that leave the common case (a
 * speed below min_speed, a non-finite force, a position that wraps) are handed back to the
 * scalar code, which redoes them from the start.
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; chosen at run time with the
 * search kernels (c->avx512, c->avx2). */
#include "boids_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX __attribute__((target("avx")))
#define AKP_AVX2 __attribute__((target("avx2")))
#define AKP_AVX512 __attribute__((target("avx512f,avx512dq")))

/* a where keep lanes are all ones, else b. */
AKP_AVX static inline __m256 pick(__m256 keep, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, keep); }

/* The rest of integrate() on 8 lanes, from the dequantised sums d (sep x y z, ali x y z, coh
 * x y z: (float)((double)q / div), the alignment and cohesion ones divided by the count too,
 * each used only where its count is not zero). Shared by the AVX-512 and AVX2 entries, which
 * differ only in how they dequantise. */
AKP_AVX static inline __attribute__((always_inline)) uint32_t integrate8(const akp_boids_ctx* c, const akp_boids_sp* S,
                                                                       const akp_boids_batch* b, const __m256 d[9]) {
    const ak_boids_step_job* job = c->job;
    const ak_boids_species* s = &S->s;
    const uint32_t live = (1u << b->n) - 1u;
    const __m256 zero = _mm256_setzero_ps();
    const __m256 px = _mm256_loadu_ps(b->p[0]), py = _mm256_loadu_ps(b->p[1]), pz = _mm256_loadu_ps(b->p[2]);
    const __m256 vx = _mm256_loadu_ps(b->v[0]), vy = _mm256_loadu_ps(b->v[1]), vz = _mm256_loadu_ps(b->v[2]);
    /* count != 0, as float lane masks (128-bit integer compares: AVX has no 256-bit ones) */
    const __m256i ones = _mm256_set1_epi32(-1);
    __m256 on[3];
    const uint32_t* cnt[3] = {b->ns, b->na, b->nc};
    for (int r = 0; r < 3; ++r) {
        const __m128i lo = _mm_loadu_si128((const __m128i*)(const void*)cnt[r]);
        const __m128i hi = _mm_loadu_si128((const __m128i*)(const void*)(cnt[r] + 4));
        const __m128i zl = _mm_cmpeq_epi32(lo, _mm_setzero_si128()), zh = _mm_cmpeq_epi32(hi, _mm_setzero_si128());
        on[r] = _mm256_xor_ps(_mm256_castsi256_ps(_mm256_insertf128_si256(_mm256_castsi128_si256(zl), zh, 1)),
                              _mm256_castsi256_ps(ones));
    }
    __m256 fx = zero, fy = zero, fz = zero;
    {   /* if (ns) f += dequant(sep, sep_scale) * separation_weight */
        const __m256 w = _mm256_set1_ps(s->separation_weight);
        fx = pick(on[0], _mm256_add_ps(fx, _mm256_mul_ps(d[0], w)), fx);
        fy = pick(on[0], _mm256_add_ps(fy, _mm256_mul_ps(d[1], w)), fy);
        fz = pick(on[0], _mm256_add_ps(fz, _mm256_mul_ps(d[2], w)), fz);
    }
    {   /* if (na) f += (dequant(ali, ali_scale * na) - v) * alignment_weight */
        const __m256 w = _mm256_set1_ps(s->alignment_weight);
        fx = pick(on[1], _mm256_add_ps(fx, _mm256_mul_ps(_mm256_sub_ps(d[3], vx), w)), fx);
        fy = pick(on[1], _mm256_add_ps(fy, _mm256_mul_ps(_mm256_sub_ps(d[4], vy), w)), fy);
        fz = pick(on[1], _mm256_add_ps(fz, _mm256_mul_ps(_mm256_sub_ps(d[5], vz), w)), fz);
    }
    {   /* if (nc) f += dequant(coh, coh_scale * nc) * cohesion_weight */
        const __m256 w = _mm256_set1_ps(s->cohesion_weight);
        fx = pick(on[2], _mm256_add_ps(fx, _mm256_mul_ps(d[6], w)), fx);
        fy = pick(on[2], _mm256_add_ps(fy, _mm256_mul_ps(d[7], w)), fy);
        fz = pick(on[2], _mm256_add_ps(fz, _mm256_mul_ps(d[8], w)), fz);
    }
    {   /* fl = |f|; if (fl > max_force) f *= max_force / fl */
        const __m256 fl = _mm256_sqrt_ps(
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(fx, fx), _mm256_mul_ps(fy, fy)), _mm256_mul_ps(fz, fz)));
        const __m256 mf = _mm256_set1_ps(s->max_force);
        const __m256 over = _mm256_cmp_ps(fl, mf, _CMP_GT_OQ);
        const __m256 k = _mm256_div_ps(mf, fl);
        fx = pick(over, _mm256_mul_ps(fx, k), fx);
        fy = pick(over, _mm256_mul_ps(fy, k), fy);
        fz = pick(over, _mm256_mul_ps(fz, k), fz);
    }
    /* ak_vec3_is_finite: x - x == 0 on each axis; other lanes go back to the scalar code. */
    const __m256 fin = _mm256_and_ps(_mm256_and_ps(_mm256_cmp_ps(_mm256_sub_ps(fx, fx), zero, _CMP_EQ_OQ),
                                                   _mm256_cmp_ps(_mm256_sub_ps(fy, fy), zero, _CMP_EQ_OQ)),
                                     _mm256_cmp_ps(_mm256_sub_ps(fz, fz), zero, _CMP_EQ_OQ));
    const __m256 dt = _mm256_set1_ps(job->dt);
    __m256 nx = _mm256_add_ps(vx, _mm256_mul_ps(fx, dt)), ny = _mm256_add_ps(vy, _mm256_mul_ps(fy, dt)),
           nz = _mm256_add_ps(vz, _mm256_mul_ps(fz, dt));
    const __m256 sp = _mm256_sqrt_ps(
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(nx, nx), _mm256_mul_ps(ny, ny)), _mm256_mul_ps(nz, nz)));
    const __m256 ms = _mm256_set1_ps(s->max_speed);
    const __m256 fast = _mm256_cmp_ps(sp, ms, _CMP_GT_OQ);
    const __m256 slow = _mm256_andnot_ps(fast, _mm256_cmp_ps(sp, _mm256_set1_ps(s->min_speed), _CMP_LT_OQ));
    {
        const __m256 k = _mm256_div_ps(ms, sp);
        nx = pick(fast, _mm256_mul_ps(nx, k), nx);
        ny = pick(fast, _mm256_mul_ps(ny, k), ny);
        nz = pick(fast, _mm256_mul_ps(nz, k), nz);
    }
    const __m256 qx = _mm256_add_ps(px, _mm256_mul_ps(nx, dt)), qy = _mm256_add_ps(py, _mm256_mul_ps(ny, dt)),
                 qz = _mm256_add_ps(pz, _mm256_mul_ps(nz, dt));
    uint32_t redo = (uint32_t)_mm256_movemask_ps(_mm256_or_ps(_mm256_andnot_ps(fin, _mm256_castsi256_ps(_mm256_set1_epi32(-1))), slow));
    if (c->bounds == AK_BOIDS_BOUNDS_WRAP) {
        const ak_boids_params* prm = c->params;
        const __m256 inx = _mm256_and_ps(_mm256_cmp_ps(qx, _mm256_set1_ps(prm->bounds_min.x), _CMP_GE_OQ),
                                         _mm256_cmp_ps(qx, _mm256_set1_ps(prm->bounds_max.x), _CMP_LT_OQ));
        const __m256 iny = _mm256_and_ps(_mm256_cmp_ps(qy, _mm256_set1_ps(prm->bounds_min.y), _CMP_GE_OQ),
                                         _mm256_cmp_ps(qy, _mm256_set1_ps(prm->bounds_max.y), _CMP_LT_OQ));
        const __m256 inz = _mm256_and_ps(_mm256_cmp_ps(qz, _mm256_set1_ps(prm->bounds_min.z), _CMP_GE_OQ),
                                         _mm256_cmp_ps(qz, _mm256_set1_ps(prm->bounds_max.z), _CMP_LT_OQ));
        redo |= ~(uint32_t)_mm256_movemask_ps(_mm256_and_ps(_mm256_and_ps(inx, iny), inz)) & 0xFFu;
    }
    redo &= live;
    float ox[8], oy[8], oz[8], wx[8], wy[8], wz[8];
    _mm256_storeu_ps(ox, qx);
    _mm256_storeu_ps(oy, qy);
    _mm256_storeu_ps(oz, qz);
    _mm256_storeu_ps(wx, nx);
    _mm256_storeu_ps(wy, ny);
    _mm256_storeu_ps(wz, nz);
    ak_vec3* P = job->out_positions.ptr;
    ak_vec3* V = job->out_velocities.ptr;
    for (uint32_t l = 0; l < b->n; ++l) {
        if (redo >> l & 1u) continue;
        const uint32_t i = b->idx[l];
        P[i] = ak_vec3_make(ox[l], oy[l], oz[l]);
        V[i] = ak_vec3_make(wx[l], wy[l], wz[l]);
    }
    return redo;
}


/* (float)((double)q / div) on 8 lanes. */
AKP_AVX512 static inline __m256 dequant8(const int64_t* q, __m512d div) {
    return _mm512_cvtpd_ps(_mm512_div_pd(_mm512_cvtepi64_pd(_mm512_loadu_si512((const void*)q)), div));
}

AKP_AVX512 uint32_t akp_boids_integrate_avx512(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b) {
    const __m512d dsep = _mm512_set1_pd((double)S->sep_scale);
    const __m512d dali = _mm512_mul_pd(_mm512_set1_pd((double)S->ali_scale),
                                       _mm512_cvtepu32_pd(_mm256_loadu_si256((const __m256i*)(const void*)b->na)));
    const __m512d dcoh = _mm512_mul_pd(_mm512_set1_pd((double)S->coh_scale),
                                       _mm512_cvtepu32_pd(_mm256_loadu_si256((const __m256i*)(const void*)b->nc)));
    __m256 d[9];
    for (int a = 0; a < 3; ++a) {
        d[a] = dequant8(b->q[a], dsep);
        d[3 + a] = dequant8(b->q[3 + a], dali);
        d[6 + a] = dequant8(b->q[6 + a], dcoh);
    }
    return integrate8(c, S, b, d);
}

/* (double) of 4 int64 lanes, rounded once like the C cast: the high half (exact, times 2^32)
 * plus the low half (exact, unsigned). */
AKP_AVX2 static inline __m256d i64_to_pd4(__m256i v) {
    const __m256i s = _mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
    const __m256d hi = _mm256_mul_pd(_mm256_cvtepi32_pd(_mm256_extracti128_si256(s, 1)), _mm256_set1_pd(4294967296.0));
    const __m256d lo = _mm256_add_pd(_mm256_cvtepi32_pd(_mm_xor_si128(_mm256_castsi256_si128(s), _mm_set1_epi32(INT32_MIN))),
                                     _mm256_set1_pd(2147483648.0));
    return _mm256_add_pd(hi, lo);
}

/* (double) of 4 uint32 lanes (exact). */
AKP_AVX2 static inline __m256d u32_to_pd4(__m128i v) {
    return _mm256_add_pd(_mm256_cvtepi32_pd(_mm_xor_si128(v, _mm_set1_epi32(INT32_MIN))), _mm256_set1_pd(2147483648.0));
}

/* (float)((double)q / div) on 8 lanes, 4 at a time. */
AKP_AVX2 static inline __m256 dequant8_avx2(const int64_t* q, __m256d div_lo, __m256d div_hi) {
    const __m128 lo = _mm256_cvtpd_ps(_mm256_div_pd(i64_to_pd4(_mm256_loadu_si256((const __m256i*)(const void*)q)), div_lo));
    const __m128 hi =
        _mm256_cvtpd_ps(_mm256_div_pd(i64_to_pd4(_mm256_loadu_si256((const __m256i*)(const void*)(q + 4))), div_hi));
    return _mm256_insertf128_ps(_mm256_castps128_ps256(lo), hi, 1);
}

AKP_AVX2 uint32_t akp_boids_integrate_avx2(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b) {
    const __m256d dsep = _mm256_set1_pd((double)S->sep_scale);
    const __m256d as = _mm256_set1_pd((double)S->ali_scale), cs = _mm256_set1_pd((double)S->coh_scale);
    const __m256d dali_lo = _mm256_mul_pd(as, u32_to_pd4(_mm_loadu_si128((const __m128i*)(const void*)b->na)));
    const __m256d dali_hi = _mm256_mul_pd(as, u32_to_pd4(_mm_loadu_si128((const __m128i*)(const void*)(b->na + 4))));
    const __m256d dcoh_lo = _mm256_mul_pd(cs, u32_to_pd4(_mm_loadu_si128((const __m128i*)(const void*)b->nc)));
    const __m256d dcoh_hi = _mm256_mul_pd(cs, u32_to_pd4(_mm_loadu_si128((const __m128i*)(const void*)(b->nc + 4))));
    __m256 d[9];
    for (int a = 0; a < 3; ++a) {
        d[a] = dequant8_avx2(b->q[a], dsep, dsep);
        d[3 + a] = dequant8_avx2(b->q[3 + a], dali_lo, dali_hi);
        d[6 + a] = dequant8_avx2(b->q[6 + a], dcoh_lo, dcoh_hi);
    }
    return integrate8(c, S, b, d);
}

#else
uint32_t akp_boids_integrate_avx512(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b) {
    (void)c, (void)S;
    return (1u << b->n) - 1u;
}

uint32_t akp_boids_integrate_avx2(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b) {
    (void)c, (void)S;
    return (1u << b->n) - 1u;
}
#endif
