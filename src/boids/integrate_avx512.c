/* AVX-512 integration of the boids step's common case, 8 agents at a time (see
 * akp_boids_integrate_avx512 in boids_internal.h). Every float and double operation is the
 * scalar integrate()'s in boids.c, in the same order, each rounded (intrinsics, no FMA, no
 * reciprocal approximations): int64 -> double and double -> float conversions round to
 * nearest like the C casts, and the divisions and square roots are IEEE-exact, so each lane
 * is bit-identical to the scalar code (tested). Lanes that leave the common case (a speed
 * below min_speed, a non-finite force, a position that wraps) are handed back to the scalar
 * code, which redoes them from the start.
 *
 * Compiled only for GCC/Clang on x86-64 without AK_NO_SIMD; chosen at run time with the
 * search kernels (c->avx512). */
#include "boids_internal.h"

#if defined(__GNUC__) && defined(__x86_64__) && !defined(AK_NO_SIMD)
#include <immintrin.h>

#define AKP_AVX512 __attribute__((target("avx512f,avx512dq")))

/* (float)((double)q / div) on 8 lanes. */
AKP_AVX512 static inline __m256 dequant8(const int64_t* q, __m512d div) {
    return _mm512_cvtpd_ps(_mm512_div_pd(_mm512_cvtepi64_pd(_mm512_loadu_si512((const void*)q)), div));
}

/* a where keep lanes are all ones, else b. */
AKP_AVX512 static inline __m256 pick(__m256 keep, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, keep); }

AKP_AVX512 uint32_t akp_boids_integrate_avx512(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b) {
    const ak_boids_step_job* job = c->job;
    const ak_boids_species* s = &S->s;
    const uint32_t live = (1u << b->n) - 1u;
    const __m256i zi = _mm256_setzero_si256();
    const __m256 zero = _mm256_setzero_ps();
    const __m256 px = _mm256_loadu_ps(b->p[0]), py = _mm256_loadu_ps(b->p[1]), pz = _mm256_loadu_ps(b->p[2]);
    const __m256 vx = _mm256_loadu_ps(b->v[0]), vy = _mm256_loadu_ps(b->v[1]), vz = _mm256_loadu_ps(b->v[2]);
    const __m256i ns = _mm256_loadu_si256((const __m256i*)(const void*)b->ns);
    const __m256i na = _mm256_loadu_si256((const __m256i*)(const void*)b->na);
    const __m256i nc = _mm256_loadu_si256((const __m256i*)(const void*)b->nc);
    __m256 fx = zero, fy = zero, fz = zero;
    {   /* if (ns) f += dequant(sep, sep_scale) * separation_weight */
        const __m512d div = _mm512_set1_pd((double)S->sep_scale);
        const __m256 w = _mm256_set1_ps(s->separation_weight);
        const __m256 on = _mm256_xor_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(ns, zi)), _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
        fx = pick(on, _mm256_add_ps(fx, _mm256_mul_ps(dequant8(b->q[0], div), w)), fx);
        fy = pick(on, _mm256_add_ps(fy, _mm256_mul_ps(dequant8(b->q[1], div), w)), fy);
        fz = pick(on, _mm256_add_ps(fz, _mm256_mul_ps(dequant8(b->q[2], div), w)), fz);
    }
    {   /* if (na) f += (dequant(ali, ali_scale * na) - v) * alignment_weight */
        const __m512d div = _mm512_mul_pd(_mm512_set1_pd((double)S->ali_scale), _mm512_cvtepu32_pd(na));
        const __m256 w = _mm256_set1_ps(s->alignment_weight);
        const __m256 on = _mm256_xor_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(na, zi)), _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
        fx = pick(on, _mm256_add_ps(fx, _mm256_mul_ps(_mm256_sub_ps(dequant8(b->q[3], div), vx), w)), fx);
        fy = pick(on, _mm256_add_ps(fy, _mm256_mul_ps(_mm256_sub_ps(dequant8(b->q[4], div), vy), w)), fy);
        fz = pick(on, _mm256_add_ps(fz, _mm256_mul_ps(_mm256_sub_ps(dequant8(b->q[5], div), vz), w)), fz);
    }
    {   /* if (nc) f += dequant(coh, coh_scale * nc) * cohesion_weight */
        const __m512d div = _mm512_mul_pd(_mm512_set1_pd((double)S->coh_scale), _mm512_cvtepu32_pd(nc));
        const __m256 w = _mm256_set1_ps(s->cohesion_weight);
        const __m256 on = _mm256_xor_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(nc, zi)), _mm256_castsi256_ps(_mm256_set1_epi32(-1)));
        fx = pick(on, _mm256_add_ps(fx, _mm256_mul_ps(dequant8(b->q[6], div), w)), fx);
        fy = pick(on, _mm256_add_ps(fy, _mm256_mul_ps(dequant8(b->q[7], div), w)), fy);
        fz = pick(on, _mm256_add_ps(fz, _mm256_mul_ps(dequant8(b->q[8], div), w)), fz);
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

#else
uint32_t akp_boids_integrate_avx512(const akp_boids_ctx* c, const akp_boids_sp* S, const akp_boids_batch* b) {
    (void)c, (void)S;
    return (1u << b->n) - 1u;
}
#endif
