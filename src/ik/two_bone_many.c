/* Many analytic two-bone solves in one call: ak_ik_two_bone_run_many.
 *
 * Four jobs at a time in SSE registers, one job per lane (structure of arrays), running the
 * same formulas as the single job's fast path (two_bone_fast in two_bone.c) operation for
 * operation: the same products, sums in the same order, the same IEEE square roots and
 * divisions, no fused multiply-adds. A lane gives the single job's result bit for bit; the
 * test checks that on random limbs. Lanes outside the fast path's case (a mid_axis, no pole,
 * soft, keep_animation or twist set, a limb bent by less than ~3 degrees, a straight result,
 * invalid data) run ak_ik_two_bone_run on their own, so every job gets exactly what
 * ak_ik_two_bone_run gives it.
 *
 * The gain is the single job's serial chain of square roots and divisions (its cost is
 * latency, ~230 cycles a solve), here overlapped four ways, and loads and shuffles shared:
 * the columns of four matrices are transposed together. */
#include "ik_internal.h"
#include "simd.h"

#if AK_SIMD_SSE2

typedef struct v3 {
    __m128 x, y, z;
} v3;

static inline v3 v3_sub(v3 a, v3 b) { return (v3){_mm_sub_ps(a.x, b.x), _mm_sub_ps(a.y, b.y), _mm_sub_ps(a.z, b.z)}; }
static inline v3 v3_add(v3 a, v3 b) { return (v3){_mm_add_ps(a.x, b.x), _mm_add_ps(a.y, b.y), _mm_add_ps(a.z, b.z)}; }
static inline v3 v3_scale(v3 a, __m128 s) { return (v3){_mm_mul_ps(a.x, s), _mm_mul_ps(a.y, s), _mm_mul_ps(a.z, s)}; }
static inline v3 v3_neg(v3 a) {
    const __m128 m = _mm_set1_ps(-0.0f);
    return (v3){_mm_xor_ps(a.x, m), _mm_xor_ps(a.y, m), _mm_xor_ps(a.z, m)};
}
/* (a.y b.z - a.z b.y, a.z b.x - a.x b.z, a.x b.y - a.y b.x), as tbv_cross computes it */
static inline v3 v3_cross(v3 a, v3 b) {
    return (v3){_mm_sub_ps(_mm_mul_ps(a.y, b.z), _mm_mul_ps(a.z, b.y)),
                _mm_sub_ps(_mm_mul_ps(a.z, b.x), _mm_mul_ps(a.x, b.z)),
                _mm_sub_ps(_mm_mul_ps(a.x, b.y), _mm_mul_ps(a.y, b.x))};
}
/* (x x' + y y') + z z', the order of tbv_dot and ak_vec3_dot */
static inline __m128 v3_dot(v3 a, v3 b) {
    return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a.x, b.x), _mm_mul_ps(a.y, b.y)), _mm_mul_ps(a.z, b.z));
}
static inline v3 v3_select(__m128 m, v3 a, v3 b) {
    return (v3){akp_simd_select(m, a.x, b.x), akp_simd_select(m, a.y, b.y), akp_simd_select(m, a.z, b.z)};
}

/* Four jobs' matrices, column-major floats [16] as structure of arrays: m[k] lane l = job l's m[k]. */
static inline void load_mats(const float* const p[4], __m128* m) {
    for (int c = 0; c < 16; c += 4) {
        __m128 r0 = _mm_loadu_ps(p[0] + c), r1 = _mm_loadu_ps(p[1] + c), r2 = _mm_loadu_ps(p[2] + c),
               r3 = _mm_loadu_ps(p[3] + c);
        _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
        m[c] = r0, m[c + 1] = r1, m[c + 2] = r2, m[c + 3] = r3;
    }
}

/* mat_unrotate of two_bone.c: M^T v, divided by the column length when it is not 1. */
static inline v3 unrotate4(const __m128* m, v3 v) {
    v3 r = {_mm_add_ps(_mm_add_ps(_mm_mul_ps(m[0], v.x), _mm_mul_ps(m[1], v.y)), _mm_mul_ps(m[2], v.z)),
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(m[4], v.x), _mm_mul_ps(m[5], v.y)), _mm_mul_ps(m[6], v.z)),
            _mm_add_ps(_mm_add_ps(_mm_mul_ps(m[8], v.x), _mm_mul_ps(m[9], v.y)), _mm_mul_ps(m[10], v.z))};
    const __m128 s2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(m[0], m[0]), _mm_mul_ps(m[1], m[1])), _mm_mul_ps(m[2], m[2]));
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    const __m128 off = _mm_cmpgt_ps(_mm_and_ps(_mm_sub_ps(s2, _mm_set1_ps(1.0f)), abs_mask), _mm_set1_ps(1e-5f));
    const __m128 rescale = _mm_and_ps(off, _mm_cmpgt_ps(s2, _mm_setzero_ps()));
    const __m128 k = akp_simd_select(rescale, _mm_div_ps(_mm_set1_ps(1.0f), _mm_sqrt_ps(s2)), _mm_set1_ps(1.0f));
    return v3_select(rescale, v3_scale(r, k), r);
}

/* Lanes (bits) of jobs[0..3] solved here; the others are left to ak_ik_two_bone_run. */
static unsigned solve4(const ak_ik_two_bone_job* jobs) {
    unsigned eligible = 0;
    for (int l = 0; l < 4; ++l) {
        const ak_ik_two_bone_job* j = &jobs[l];
        const bool pole = j->pole.x != 0.0f || j->pole.y != 0.0f || j->pole.z != 0.0f;
        const bool axis = j->mid_axis.x != 0.0f || j->mid_axis.y != 0.0f || j->mid_axis.z != 0.0f;
        if (j->out_start_rot && j->out_mid_rot && pole && !axis && j->soft == 0.0f && j->keep_animation == 0.0f &&
            j->twist == 0.0f)
            eligible |= 1u << l;
    }
    if (!eligible) return 0;

    const float* ps[4] = {jobs[0].start.m, jobs[1].start.m, jobs[2].start.m, jobs[3].start.m};
    const float* pm[4] = {jobs[0].mid.m, jobs[1].mid.m, jobs[2].mid.m, jobs[3].mid.m};
    const float* pe[4] = {jobs[0].end.m, jobs[1].end.m, jobs[2].end.m, jobs[3].end.m};
    __m128 MS[16], MM[16], ME[16];
    load_mats(ps, MS);
    load_mats(pm, MM);
    load_mats(pe, ME);
    const v3 tgt = {_mm_setr_ps(jobs[0].target.x, jobs[1].target.x, jobs[2].target.x, jobs[3].target.x),
                    _mm_setr_ps(jobs[0].target.y, jobs[1].target.y, jobs[2].target.y, jobs[3].target.y),
                    _mm_setr_ps(jobs[0].target.z, jobs[1].target.z, jobs[2].target.z, jobs[3].target.z)};
    const v3 pole = {_mm_setr_ps(jobs[0].pole.x, jobs[1].pole.x, jobs[2].pole.x, jobs[3].pole.x),
                     _mm_setr_ps(jobs[0].pole.y, jobs[1].pole.y, jobs[2].pole.y, jobs[3].pole.y),
                     _mm_setr_ps(jobs[0].pole.z, jobs[1].pole.z, jobs[2].pole.z, jobs[3].pole.z)};
    /* validation: every float finite (x - x is 0, else NaN; a sum of zeros stays 0) */
    __m128 z = _mm_add_ps(_mm_sub_ps(tgt.x, tgt.x), _mm_sub_ps(pole.x, pole.x));
    z = _mm_add_ps(z, _mm_add_ps(_mm_sub_ps(tgt.y, tgt.y), _mm_sub_ps(pole.y, pole.y)));
    z = _mm_add_ps(z, _mm_add_ps(_mm_sub_ps(tgt.z, tgt.z), _mm_sub_ps(pole.z, pole.z)));
    for (int k = 0; k < 16; ++k)
        z = _mm_add_ps(z, _mm_add_ps(_mm_sub_ps(MS[k], MS[k]), _mm_add_ps(_mm_sub_ps(MM[k], MM[k]), _mm_sub_ps(ME[k], ME[k]))));
    __m128 ok = _mm_cmpeq_ps(z, _mm_setzero_ps());

    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), half = _mm_set1_ps(0.5f), two = _mm_set1_ps(2.0f);
    const v3 s = {MS[12], MS[13], MS[14]}, m = {MM[12], MM[13], MM[14]}, e = {ME[12], ME[13], ME[14]};
    const v3 u = v3_sub(m, s), v = v3_sub(e, m), st = v3_sub(tgt, s);
    const v3 n = v3_cross(u, v), p = v3_cross(st, pole);
    const __m128 a2 = v3_dot(u, u), b2 = v3_dot(v, v), d2 = v3_dot(st, st);
    const __m128 n2 = v3_dot(n, n), p2 = v3_dot(p, p), pole2 = v3_dot(pole, pole);
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(n2, _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(2.5e-3f), a2), b2)));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(d2, _mm_set1_ps(1e-24f)));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(p2, _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(1e-12f), pole2), d2)));
    if (!(_mm_movemask_ps(ok) & (int)eligible)) return 0;

    /* two_bone_reach with soft = 0 */
    const __m128 ab = _mm_sqrt_ps(_mm_mul_ps(a2, b2));
    const __m128 lmax2 = _mm_add_ps(_mm_add_ps(a2, b2), _mm_mul_ps(two, ab));
    const __m128 lmin2 = _mm_max_ps(_mm_sub_ps(_mm_add_ps(a2, b2), _mm_mul_ps(two, ab)), zero);
    const __m128 reached = _mm_and_ps(_mm_cmple_ps(d2, _mm_mul_ps(lmax2, _mm_set1_ps(1.0f + 2e-6f))),
                                      _mm_cmpge_ps(d2, _mm_sub_ps(lmin2, _mm_mul_ps(_mm_set1_ps(2e-6f), lmax2))));
    const __m128 dd2 = akp_simd_select(_mm_cmplt_ps(d2, lmin2), lmin2, akp_simd_select(_mm_cmpgt_ps(d2, lmax2), lmax2, d2));

    const __m128 nl = _mm_sqrt_ps(n2), A = v3_dot(u, v), B = _mm_xor_ps(nl, _mm_set1_ps(-0.0f));
    const __m128 r2 = _mm_add_ps(_mm_mul_ps(A, A), n2);
    __m128 K = _mm_mul_ps(half, _mm_sub_ps(_mm_sub_ps(dd2, a2), b2));
    const __m128 inside = _mm_cmplt_ps(_mm_mul_ps(K, K), r2);
    const __m128 S = _mm_and_ps(inside, _mm_sqrt_ps(_mm_sub_ps(r2, _mm_mul_ps(K, K))));
    const __m128 rr = _mm_sqrt_ps(r2);
    K = akp_simd_select(inside, K, akp_simd_select(_mm_cmpgt_ps(K, zero), rr, _mm_xor_ps(rr, _mm_set1_ps(-0.0f))));
    const __m128 inv = _mm_div_ps(one, r2);
    const __m128 cphi = _mm_mul_ps(_mm_sub_ps(_mm_mul_ps(A, K), _mm_mul_ps(B, S)), inv);
    const __m128 sphi = _mm_mul_ps(_mm_add_ps(_mm_mul_ps(B, K), _mm_mul_ps(A, S)), inv);
    const v3 nh = v3_scale(n, _mm_div_ps(one, nl));
    const v3 f = v3_add(v3_add(u, v3_scale(v, cphi)), v3_scale(v3_cross(nh, v), sphi));
    const __m128 f2 = _mm_add_ps(_mm_add_ps(a2, b2), _mm_mul_ps(two, K));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(f2, _mm_set1_ps(1e-24f)));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(_mm_mul_ps(S, S), _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(1e-12f), a2), f2)));
    const v3 a2v = v3_neg(nh); /* branch 0 */
    const __m128 P = _mm_sqrt_ps(p2), FD = _mm_sqrt_ps(_mm_mul_ps(f2, d2));
    const v3 x2 = v3_cross(a2v, p), sa = v3_cross(st, a2v);
    const __m128 a2p = v3_dot(a2v, p), a2st = v3_dot(a2v, st);
    const __m128 fst = v3_dot(f, st), fp = v3_dot(f, p), fsa = v3_dot(f, sa), fx2 = v3_dot(f, x2);
    const v3 T0 = v3_scale(v3_cross(f, st), P), T1 = v3_add(v3_scale(p, fsa), v3_scale(st, fx2)), T2 = v3_scale(x2, FD);
    const __m128 base = _mm_mul_ps(FD, P), e0 = _mm_mul_ps(P, fst);
    const __m128 e1 = _mm_sub_ps(_mm_mul_ps(a2p, fst), _mm_mul_ps(a2st, fp)), e2 = _mm_mul_ps(FD, a2p);
    const __m128 w_id = _mm_add_ps(_mm_add_ps(_mm_add_ps(base, e0), e1), e2);
    const __m128 w_2 = _mm_add_ps(_mm_sub_ps(_mm_sub_ps(base, e0), e1), e2);
    const __m128 w_0 = _mm_sub_ps(_mm_sub_ps(_mm_add_ps(base, e0), e1), e2);
    const __m128 w_1 = _mm_sub_ps(_mm_add_ps(_mm_sub_ps(base, e0), e1), e2);
    /* Shepperd's choice with the single job's tie order: trace, then axis 2, 0, 1 */
    const __m128 m_id = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(w_id, w_2), _mm_cmpge_ps(w_id, w_0)), _mm_cmpge_ps(w_id, w_1));
    const __m128 m_2 = _mm_and_ps(_mm_cmpge_ps(w_2, w_0), _mm_cmpge_ps(w_2, w_1));
    const __m128 m_0 = _mm_cmpge_ps(w_0, w_1);
    const v3 v_2 = v3_sub(T2, v3_add(T0, T1)), v_0 = v3_sub(T0, v3_add(T1, T2)), v_1 = v3_sub(T1, v3_add(T0, T2));
    const v3 vk = v3_select(m_2, v_2, v3_select(m_0, v_0, v_1));
    const v3 ak = v3_select(m_2, a2v, v3_select(m_0, f, v3_cross(a2v, f)));
    const __m128 wk = akp_simd_select(m_2, w_2, akp_simd_select(m_0, w_0, w_1));
    const v3 qv = v3_select(m_id, v3_add(v3_add(T0, T1), T2), v3_add(v3_scale(ak, wk), v3_cross(vk, ak)));
    const __m128 qw = akp_simd_select(m_id, w_id, _mm_xor_ps(v3_dot(vk, ak), _mm_set1_ps(-0.0f)));
    const __m128 q2 = _mm_add_ps(v3_dot(qv, qv), _mm_mul_ps(qw, qw));
    ok = _mm_and_ps(ok, _mm_cmpgt_ps(q2, zero));
    const unsigned done = (unsigned)_mm_movemask_ps(ok) & eligible;
    if (!done) return 0;
    const __m128 qi = _mm_div_ps(one, _mm_sqrt_ps(q2));
    const v3 axis = unrotate4(MS, v3_scale(qv, qi));
    const __m128 sw = _mm_mul_ps(qw, qi);
    /* akp_quat_half_angle(mat_unrotate(mid, nh), cphi, sphi), both branches then a select */
    const v3 nl_axis = unrotate4(MM, nh);
    const __m128 cpos = _mm_cmpge_ps(cphi, zero);
    const __m128 ch_a = _mm_sqrt_ps(_mm_add_ps(half, _mm_mul_ps(half, cphi)));
    const __m128 sh_a = _mm_div_ps(_mm_mul_ps(half, sphi), ch_a);
    __m128 sh_b = _mm_sqrt_ps(_mm_sub_ps(half, _mm_mul_ps(half, cphi)));
    sh_b = akp_simd_select(_mm_cmplt_ps(sphi, zero), _mm_xor_ps(sh_b, _mm_set1_ps(-0.0f)), sh_b);
    const __m128 ch_b = _mm_div_ps(_mm_mul_ps(half, sphi), sh_b);
    const __m128 sh = akp_simd_select(cpos, sh_a, sh_b), ch = akp_simd_select(cpos, ch_a, ch_b);
    const v3 mv = v3_scale(nl_axis, sh);

    float o[9][4];
    _mm_storeu_ps(o[0], axis.x), _mm_storeu_ps(o[1], axis.y), _mm_storeu_ps(o[2], axis.z), _mm_storeu_ps(o[3], sw);
    _mm_storeu_ps(o[4], mv.x), _mm_storeu_ps(o[5], mv.y), _mm_storeu_ps(o[6], mv.z), _mm_storeu_ps(o[7], ch);
    _mm_storeu_ps(o[8], reached);
    for (int l = 0; l < 4; ++l) {
        if (!(done >> l & 1u)) continue;
        const ak_ik_two_bone_job* j = &jobs[l];
        *j->out_start_rot = ak_quat_make(o[0][l], o[1][l], o[2][l], o[3][l]);
        *j->out_mid_rot = ak_quat_make(o[4][l], o[5][l], o[6][l], o[7][l]);
        if (j->out_reached) *j->out_reached = (_mm_movemask_ps(reached) >> l) & 1;
    }
    return done;
}

#endif

ak_result ak_ik_two_bone_run_many(const ak_ik_two_bone_job* jobs, size_t count, size_t* out_failed) {
    if (out_failed) *out_failed = count;
    if (!jobs) return count ? AK_ERR_NULL_ARG : AK_OK;
    ak_result first = AK_OK;
    size_t i = 0;
#if AK_SIMD_SSE2
    for (; i + 4 <= count; i += 4) {
        const unsigned done = solve4(jobs + i);
        for (size_t l = 0; l < 4; ++l) {
            if (done >> l & 1u) continue;
            const ak_result r = ak_ik_two_bone_run(&jobs[i + l]);
            if (r != AK_OK && first == AK_OK) {
                first = r;
                if (out_failed) *out_failed = i + l;
            }
        }
    }
#endif
    for (; i < count; ++i) {
        const ak_result r = ak_ik_two_bone_run(&jobs[i]);
        if (r != AK_OK && first == AK_OK) {
            first = r;
            if (out_failed) *out_failed = i;
        }
    }
    return first;
}
