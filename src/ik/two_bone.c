/* Analytic two-bone IK. Everything happens in model space on positions, then the two
 * rotations are moved into the joints' local frames by transforming their axes.
 *
 * Mid joint: it turns by phi about its bend axis n. With u = mid - start, v = end - mid and
 * v = v_par + v_perp about n, the end lands at distance d from the start when
 *     |u + R(phi) v|^2 = d^2  <=>  A cos(phi) + B sin(phi) = K,
 *     A = u.v_perp,  B = u.(n x v_perp),  K = (d^2 - |u|^2 - |v|^2) / 2 - u.v_par,
 * which is the law of cosines written for any axis (for n normal to the bend plane, v_par = 0
 * and it reduces to cos(interior) = (a^2 + b^2 - d^2) / 2ab). Of the two solutions, the one
 * nearer the current bend keeps the knee bending the way it did. Every angle is handled as a
 * (cos, sin) pair and half angles come from sqrt((1 +- cos) / 2), so the solve needs no trig.
 *
 * Start joint: the rotation taking start->end onto start->target and putting the mid joint
 * in the half plane of the pole direction (or, without a pole, the shortest arc). */
#include <string.h>

#include "ik_internal.h"
#include "simd.h"

static inline ak_vec3 mat_pos(const float* m) { return ak_vec3_make(m[12], m[13], m[14]); }
static inline ak_vec3 mat_rotate(const float* m, ak_vec3 v) {
    return ak_vec3_make(m[0] * v.x + m[4] * v.y + m[8] * v.z, m[1] * v.x + m[5] * v.y + m[9] * v.z,
                        m[2] * v.x + m[6] * v.y + m[10] * v.z);
}
/* A unit local direction into model space (rescaled when the matrix has a uniform scale). */
static inline ak_vec3 mat_rotate_dir(const float* m, ak_vec3 v) {
    ak_vec3 r = mat_rotate(m, v);
    float s2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    if (fabsf(s2 - 1.0f) > 1e-5f && s2 > 0.0f) r = ak_vec3_scale(r, 1.0f / sqrtf(s2));
    return r;
}
/* Direction of a model-space vector in the joint's local frame (transpose, rescaled). */
static inline ak_vec3 mat_unrotate(const float* m, ak_vec3 v) {
    ak_vec3 r = ak_vec3_make(m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
                             m[8] * v.x + m[9] * v.y + m[10] * v.z);
    float s2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    if (fabsf(s2 - 1.0f) > 1e-5f && s2 > 0.0f) r = ak_vec3_scale(r, 1.0f / sqrtf(s2)); /* M = sR: R^T v = M^T v / s */
    return r;
}

/* The rotation taking the orthonormal frame (a0, a1, a0 x a1) onto (b0, b1, b0 x b1):
 * Q = b0 a0^T + b1 a1^T + b2 a2^T, to a quaternion by Shepperd's method. */
static inline ak_quat frame_rotation(ak_vec3 a0, ak_vec3 a1, ak_vec3 b0, ak_vec3 b1) {
    const ak_vec3 a2 = ak_vec3_cross(a0, a1), b2 = ak_vec3_cross(b0, b1);
    /* q[r][c] = row r, column c */
    const float q00 = b0.x * a0.x + b1.x * a1.x + b2.x * a2.x, q01 = b0.x * a0.y + b1.x * a1.y + b2.x * a2.y,
                q02 = b0.x * a0.z + b1.x * a1.z + b2.x * a2.z;
    const float q10 = b0.y * a0.x + b1.y * a1.x + b2.y * a2.x, q11 = b0.y * a0.y + b1.y * a1.y + b2.y * a2.y,
                q12 = b0.y * a0.z + b1.y * a1.z + b2.y * a2.z;
    const float q20 = b0.z * a0.x + b1.z * a1.x + b2.z * a2.x, q21 = b0.z * a0.y + b1.z * a1.y + b2.z * a2.y,
                q22 = b0.z * a0.z + b1.z * a1.z + b2.z * a2.z;
    const float tr = q00 + q11 + q22;
    if (tr > 0.0f) {
        const float r = sqrtf(1.0f + tr), h = 0.5f / r;
        return ak_quat_make((q21 - q12) * h, (q02 - q20) * h, (q10 - q01) * h, 0.5f * r);
    }
    if (q00 >= q11 && q00 >= q22) {
        const float r = sqrtf(ak_maxf(1.0f + q00 - q11 - q22, 1e-30f)), h = 0.5f / r;
        return ak_quat_make(0.5f * r, (q01 + q10) * h, (q02 + q20) * h, (q21 - q12) * h);
    }
    if (q11 >= q22) {
        const float r = sqrtf(ak_maxf(1.0f + q11 - q00 - q22, 1e-30f)), h = 0.5f / r;
        return ak_quat_make((q01 + q10) * h, 0.5f * r, (q12 + q21) * h, (q02 - q20) * h);
    }
    const float r = sqrtf(ak_maxf(1.0f + q22 - q00 - q11, 1e-30f)), h = 0.5f / r;
    return ak_quat_make((q02 + q20) * h, (q12 + q21) * h, 0.5f * r, (q10 - q01) * h);
}

static inline ak_quat weight_toward_identity(ak_quat q, float keep) {
    if (keep <= 0.0f) return q;
    return ak_quat_nlerp(ak_quat_identity(), q, 1.0f - keep);
}

/* 3-vectors for the fast path: SSE registers (x, y, z, 0), or ak_vec3 without SIMD. */
#if AK_SIMD_SSE2
typedef __m128 tbv;
static inline tbv tbv_make(ak_vec3 a) { return _mm_set_ps(0.0f, a.z, a.y, a.x); }
static inline tbv tbv_pos(const float* m) { /* (m[12], m[13], m[14], 0) */
    return _mm_and_ps(_mm_loadu_ps(m + 12), _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1)));
}
static inline tbv tbv_sub(tbv a, tbv b) { return _mm_sub_ps(a, b); }
static inline tbv tbv_add(tbv a, tbv b) { return _mm_add_ps(a, b); }
static inline tbv tbv_scale(tbv a, float s) { return _mm_mul_ps(a, _mm_set1_ps(s)); }
static inline tbv tbv_neg(tbv a) { return _mm_xor_ps(a, _mm_set1_ps(-0.0f)); }
/* a x b from (a * b.yzx - a.yzx * b).yzx: three shuffles. */
static inline tbv tbv_cross(tbv a, tbv b) {
    const tbv a1 = _mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 0, 2, 1)), b1 = _mm_shuffle_ps(b, b, _MM_SHUFFLE(3, 0, 2, 1));
    const tbv c = _mm_sub_ps(_mm_mul_ps(a, b1), _mm_mul_ps(a1, b));
    return _mm_shuffle_ps(c, c, _MM_SHUFFLE(3, 0, 2, 1));
}
static inline float tbv_dot(tbv a, tbv b) {
    tbv p = _mm_mul_ps(a, b);
    p = _mm_add_ps(p, _mm_shuffle_ps(p, p, _MM_SHUFFLE(2, 3, 0, 1)));
    p = _mm_add_ss(p, _mm_movehl_ps(p, p));
    return _mm_cvtss_f32(p);
}
static inline ak_vec3 tbv_vec3(tbv a) {
    float f[4];
    _mm_storeu_ps(f, a);
    return ak_vec3_make(f[0], f[1], f[2]);
}
#else
typedef ak_vec3 tbv;
static inline tbv tbv_make(ak_vec3 a) { return a; }
static inline tbv tbv_pos(const float* m) { return mat_pos(m); }
static inline tbv tbv_sub(tbv a, tbv b) { return ak_vec3_sub(a, b); }
static inline tbv tbv_add(tbv a, tbv b) { return ak_vec3_add(a, b); }
static inline tbv tbv_scale(tbv a, float s) { return ak_vec3_scale(a, s); }
static inline tbv tbv_neg(tbv a) { return ak_vec3_neg(a); }
static inline tbv tbv_cross(tbv a, tbv b) { return ak_vec3_cross(a, b); }
static inline float tbv_dot(tbv a, tbv b) { return ak_vec3_dot(a, b); }
static inline ak_vec3 tbv_vec3(tbv a) { return a; }
#endif

/* Reach, in squared lengths (one square root): softened, then clamped to what the two bones
 * can span, |a - b| <= d <= a + b. Returns the squared distance to solve for. */
static inline float two_bone_reach(float a2, float b2, float d2, float soft, bool* reached) {
    const float ab = sqrtf(a2 * b2);
    const float lmax2 = a2 + b2 + 2.0f * ab, lmin2 = ak_maxf(a2 + b2 - 2.0f * ab, 0.0f);
    *reached = d2 <= lmax2 * (1.0f + 2e-6f) && d2 >= lmin2 - 2e-6f * lmax2;
    float dd2 = d2;
    if (soft > 0.0f) {
        const float d = sqrtf(d2), lmax = sqrtf(lmax2);
        const float ds = (1.0f - soft) * lmax, band = lmax - ds;
        if (d > ds && band > 0.0f) {
            const float dd = ds + band * (1.0f - expf((ds - d) / band));
            dd2 = dd * dd;
            *reached = false;
        }
    }
    return ak_clampf(dd2, lmin2, lmax2);
}

/* The common case in closed form: no mid_axis (the bend axis is the normal n = u x v of the
 * current bend plane, not straight), a pole, target off the start joint. With n normal to u
 * and v, v_par = 0 and the mid equation's coefficients need no normalised vector:
 * A = u.v, B = u.(n^ x v) = -|n|, r^2 = A^2 + B^2. After the bend, f x u = (B cos - A sin) n^,
 * so the limb's frame is (f^, a2 x f^, a2), a2 = +-n^, and the target's (k, b2 x k, b2), b2 = st x pole
 * normalised. The rotation between two orthonormal frames is the quaternion
 * (sum a_i x b_i, 1 + sum a_i.b_i) normalised (Shepperd's trace branch); written with the
 * unnormalised f, st and p = st x pole it needs sqrt(|f|^2 |st|^2), |p| and the final norm.
 * Returns false (nothing written) when the case does not apply; the general path then runs. */
static bool two_bone_fast(const ak_ik_two_bone_job* job, int branch, ak_quat* out_start, ak_quat* out_mid,
                          bool* out_reached) {
    const tbv s = tbv_pos(job->start.m), m = tbv_pos(job->mid.m), e = tbv_pos(job->end.m);
    const tbv u = tbv_sub(m, s), v = tbv_sub(e, m), st = tbv_sub(tbv_make(job->target), s);
    const tbv pole = tbv_make(job->pole), n = tbv_cross(u, v), p = tbv_cross(st, pole);
    const float a2 = tbv_dot(u, u), b2 = tbv_dot(v, v), d2 = tbv_dot(st, st);
    const float n2 = tbv_dot(n, n), p2 = tbv_dot(p, p), pole2 = tbv_dot(pole, pole);
    /* The bend normal is trusted to ~1e-6 rad only with the limb bent by more than ~3 degrees. */
    if (!(n2 > 2.5e-3f * a2 * b2) || !(d2 > 1e-24f) || !(p2 > 1e-12f * pole2 * d2)) return false;
    bool reached;
    const float dd2 = two_bone_reach(a2, b2, d2, job->soft, &reached);
    const float nl = sqrtf(n2), A = tbv_dot(u, v), B = -nl;
    const float r2 = A * A + n2;
    float K = 0.5f * (dd2 - a2 - b2), S = 0.0f;
    if (K * K < r2) S = sqrtf(r2 - K * K);
    else K = K > 0.0f ? sqrtf(r2) : -sqrtf(r2);
    const float inv = 1.0f / r2;
    const float c1 = (A * K - B * S) * inv, s1 = (B * K + A * S) * inv;
    const float c2 = (A * K + B * S) * inv, s2 = (B * K - A * S) * inv;
    /* B <= 0, so c1 >= c2: branch 0 takes (c1, s1). Then B cos - A sin = -S (branch 0) or
     * +S (branch 1): the limb frame's third axis is -n^ or +n^ exactly. */
    const bool first = branch == 0;
    const float cphi = first ? c1 : c2, sphi = first ? s1 : s2;
    const tbv nh = tbv_scale(n, 1.0f / nl);
    const tbv f = tbv_add(tbv_add(u, tbv_scale(v, cphi)), tbv_scale(tbv_cross(nh, v), sphi));
    /* |f|^2 = a^2 + b^2 + 2 u.R(v) = a^2 + b^2 + 2K: the mid equation, solved or clamped */
    const float f2 = a2 + b2 + 2.0f * K;
    /* Straight after the bend (|u x f^|^2 = S^2 / |f|^2 tiny): the general path's shortest arc. */
    if (!(f2 > 1e-24f) || !(S * S > 1e-12f * a2 * f2)) return false;
    const tbv a2v = first ? tbv_neg(nh) : nh;
    const float P = sqrtf(p2), FD = sqrtf(f2 * d2);
    /* Scaled by |f||st||p|: a_i x b_i -> T_i, a_i . b_i -> e_i. The middle axes a_1 = a_2 x a_0,
     * b_1 = b_2 x b_0 need no cross products (Binet-Cauchy and the (A x B) x (C x D) rule):
     * e_1 = (a2.p)(f.st) - (a2.st)(f.p), T_1 = (f.(st x a2)) p + (f.(a2 x p)) st, so after the
     * bend only f x st and four dot products with f remain. */
    const tbv x2 = tbv_cross(a2v, p), sa = tbv_cross(st, a2v);
    const float a2p = tbv_dot(a2v, p), a2st = tbv_dot(a2v, st);
    const float fst = tbv_dot(f, st), fp = tbv_dot(f, p), fsa = tbv_dot(f, sa), fx2 = tbv_dot(f, x2);
    const tbv T0 = tbv_scale(tbv_cross(f, st), P), T1 = tbv_add(tbv_scale(p, fsa), tbv_scale(st, fx2)),
              T2 = tbv_scale(x2, FD);
    const float base = FD * P, e0 = P * fst, e1 = a2p * fst - a2st * fp, e2 = FD * a2p;
    /* Shepperd's choice in frame form: with F_k the half turn about a_k, R = R' F_k where R'
     * takes (+-a_i) onto b_i; of the four candidates (the trace form and one per axis) take
     * the one with the largest scalar part (at least a quarter of the sum 4 |f||st||p|), so
     * the normalisation never divides a cancellation. q = q' (a_k, 0), a_0 = f, a_1 = a2 x f
     * (both |f| long: the final normalisation absorbs it), a_2 = +-n^. */
    const float w_id = base + e0 + e1 + e2, w_2 = base - e0 - e1 + e2, w_0 = base + e0 - e1 - e2,
                w_1 = base - e0 + e1 - e2;
    tbv qv;
    float qw;
    if (w_id >= w_2 && w_id >= w_0 && w_id >= w_1) {
        qv = tbv_add(tbv_add(T0, T1), T2), qw = w_id;
    } else {
        tbv vk, ak;
        float wk;
        if (w_2 >= w_0 && w_2 >= w_1) vk = tbv_sub(T2, tbv_add(T0, T1)), wk = w_2, ak = a2v;
        else if (w_0 >= w_1) vk = tbv_sub(T0, tbv_add(T1, T2)), wk = w_0, ak = f;
        else vk = tbv_sub(T1, tbv_add(T0, T2)), wk = w_1, ak = tbv_cross(a2v, f);
        qv = tbv_add(tbv_scale(ak, wk), tbv_cross(vk, ak)), qw = -tbv_dot(vk, ak);
    }
    const float q2 = tbv_dot(qv, qv) + qw * qw;
    if (!(q2 > 0.0f)) return false;
    const float qi = 1.0f / sqrtf(q2);
    const ak_vec3 qa = ak_vec3_scale(tbv_vec3(qv), qi);
    ak_quat q_start = ak_quat_make(qa.x, qa.y, qa.z, qw * qi);
    if (job->twist != 0.0f)
        q_start = ak_quat_mul(ak_quat_from_axis_angle(ak_vec3_scale(tbv_vec3(st), 1.0f / sqrtf(d2)), job->twist), q_start);
    const ak_vec3 axis_local = mat_unrotate(job->start.m, ak_vec3_make(q_start.x, q_start.y, q_start.z));
    q_start = ak_quat_make(axis_local.x, axis_local.y, axis_local.z, q_start.w);
    const ak_quat q_mid = akp_quat_half_angle(mat_unrotate(job->mid.m, tbv_vec3(nh)), cphi, sphi);
    *out_start = weight_toward_identity(q_start, job->keep_animation);
    *out_mid = weight_toward_identity(q_mid, job->keep_animation);
    *out_reached = reached;
    return true;
}

bool akp_ik_two_bone_solve(const ak_ik_two_bone_job* job, int branch, ak_quat* out_start, ak_quat* out_mid) {
    const bool axis_given = job->mid_axis.x != 0.0f || job->mid_axis.y != 0.0f || job->mid_axis.z != 0.0f;
    const bool has_pole = job->pole.x != 0.0f || job->pole.y != 0.0f || job->pole.z != 0.0f;
    bool fast_reached;
    if (!axis_given && has_pole && two_bone_fast(job, branch, out_start, out_mid, &fast_reached)) return fast_reached;
    const float *S = job->start.m, *M = job->mid.m, *E = job->end.m;
    const ak_vec3 s = mat_pos(S), m = mat_pos(M), e = mat_pos(E);
    const ak_vec3 u = ak_vec3_sub(m, s), v = ak_vec3_sub(e, m), st = ak_vec3_sub(job->target, s);
    const float a2 = ak_vec3_dot(u, u), b2 = ak_vec3_dot(v, v), d2 = ak_vec3_dot(st, st);

    bool reached;
    const float dd2 = two_bone_reach(a2, b2, d2, job->soft, &reached);

    /* Bend axis n in model space, n_local in the mid joint's frame. */
    ak_vec3 n, n_local;
    if (axis_given) {
        n_local = ak_vec3_normalize(job->mid_axis);
        n = mat_rotate_dir(M, n_local);
    } else {
        n = ak_vec3_cross(u, v);
        float n2 = ak_vec3_dot(n, n);
        if (n2 > 1e-12f * a2 * b2) {
            n = ak_vec3_scale(n, 1.0f / sqrtf(n2));
        } else { /* straight (or zero) bones: any axis normal to the limb, the pole's if any */
            n = ak_vec3_normalize(ak_vec3_cross(u, job->pole));
            if (ak_vec3_dot(n, n) == 0.0f) n = ak_vec3_any_perpendicular(a2 > 0.0f ? u : v);
        }
        n_local = mat_unrotate(M, n);
    }

    /* Mid joint: A cos(phi) + B sin(phi) = K. With R^2 = A^2 + B^2 and S = sqrt(R^2 - K^2),
     * the two solutions are (cos, sin) = ((A K -+ B S), (B K +- A S)) / R^2. */
    const float vn = ak_vec3_dot(n, v);
    const ak_vec3 v_perp = ak_vec3_madd(v, n, -vn);
    const ak_vec3 n_x_vp = ak_vec3_cross(n, v_perp);
    const float A = ak_vec3_dot(u, v_perp), B = ak_vec3_dot(u, n_x_vp);
    float K = 0.5f * (dd2 - a2 - b2) - vn * ak_vec3_dot(u, n);
    const float r2 = A * A + B * B;
    float cphi = 1.0f, sphi = 0.0f;
    if (r2 > 1e-24f * (a2 * b2 + 1e-30f)) {
        float S = 0.0f;
        if (K * K < r2) S = sqrtf(r2 - K * K);
        else K = K > 0.0f ? sqrtf(r2) : -sqrtf(r2); /* out of the axis' range: nearest end */
        const float inv = 1.0f / r2;
        const float c1 = (A * K - B * S) * inv, s1 = (B * K + A * S) * inv; /* phi = alpha + beta */
        const float c2 = (A * K + B * S) * inv, s2 = (B * K - A * S) * inv; /* phi = alpha - beta */
        /* The bend side after the turn, n.(u x R(phi) v) = A sin - B cos, is +S for the first
         * solution and -S for the second. Signed axis (ozz's convention, a positive turn
         * about n opens the joint): the limb ends bent with u x v along -n, the second. */
        if (axis_given && job->mid_axis_signed) cphi = c2, sphi = s2;
        else if ((c1 >= c2) != (branch != 0)) cphi = c1, sphi = s1;
        else cphi = c2, sphi = s2;
    }
    ak_quat q_mid = akp_quat_half_angle(n_local, cphi, sphi);

    /* Start joint. With a pole: the rotation taking the frame (f, knee side) of the bent limb
     * onto (target direction, pole side), one matrix product and one matrix-to-quaternion,
     * all normalisations independent of each other. Without: the shortest arc from f to the
     * target direction, which keeps the current bend plane as far as it can. */
    ak_quat q_start = ak_quat_identity();
    if (d2 > 1e-24f) {
        const ak_vec3 v_rot = ak_vec3_add(ak_vec3_madd(ak_vec3_scale(n, vn), v_perp, cphi), ak_vec3_scale(n_x_vp, sphi));
        const ak_vec3 f = ak_vec3_add(u, v_rot);
        const float f2 = ak_vec3_dot(f, f);
        bool done = false;
        if (has_pole && f2 > 1e-24f) {
            const ak_vec3 fh = ak_vec3_scale(f, 1.0f / sqrtf(f2));
            const ak_vec3 k = ak_vec3_scale(st, 1.0f / sqrtf(d2));
            const ak_vec3 e1 = ak_vec3_madd(u, fh, -ak_vec3_dot(u, fh));
            const ak_vec3 p1 = ak_vec3_madd(job->pole, k, -ak_vec3_dot(job->pole, k));
            const float e12 = ak_vec3_dot(e1, e1), p12 = ak_vec3_dot(p1, p1);
            if (e12 > 1e-12f * a2 && p12 > 1e-12f * ak_vec3_dot(job->pole, job->pole)) {
                /* A second projection: with the limb nearly straight, e1 comes out of a
                 * cancellation and the first one leaves it measurably off the normal plane; a
                 * frame that is not orthonormal would move the effector, not just twist. */
                ak_vec3 eh = ak_vec3_scale(e1, 1.0f / sqrtf(e12));
                ak_vec3 ph = ak_vec3_scale(p1, 1.0f / sqrtf(p12));
                eh = ak_vec3_madd(eh, fh, -ak_vec3_dot(eh, fh));
                ph = ak_vec3_madd(ph, k, -ak_vec3_dot(ph, k));
                q_start = frame_rotation(fh, eh, k, ph);
                done = true;
            }
        }
        if (!done && f2 > 1e-24f) {
            const ak_vec3 cr = ak_vec3_cross(f, st);
            const float fd = sqrtf(f2 * d2), w = fd + ak_vec3_dot(f, st);
            if (w > 1e-6f * fd) {
                q_start = ak_quat_normalize(ak_quat_make(cr.x, cr.y, cr.z, w));
            } else { /* opposite: half a turn about an axis normal to the limb, n if possible */
                ak_vec3 ax = ak_vec3_dot(n, f) * ak_vec3_dot(n, f) < 1e-6f * f2 ? n : ak_vec3_any_perpendicular(f);
                q_start = ak_quat_make(ax.x, ax.y, ax.z, 0.0f);
            }
        }
        if (job->twist != 0.0f)
            q_start = ak_quat_mul(ak_quat_from_axis_angle(ak_vec3_scale(st, 1.0f / sqrtf(d2)), job->twist), q_start);
    }
    /* Into the start joint's local frame: same angle, axis seen from the joint. */
    ak_vec3 axis_local = mat_unrotate(S, ak_vec3_make(q_start.x, q_start.y, q_start.z));
    q_start = ak_quat_make(axis_local.x, axis_local.y, axis_local.z, q_start.w);

    *out_start = weight_toward_identity(q_start, job->keep_animation);
    *out_mid = weight_toward_identity(q_mid, job->keep_animation);
    return reached;
}

/* Nonzero when one of the 16 floats is NaN or infinite (exponent bits all ones). */
static inline int nonfinite16(const float* f) {
#if AK_SIMD_SSE2
    const __m128 expo = _mm_castsi128_ps(_mm_set1_epi32(0x7f800000));
    __m128 bad = _mm_setzero_ps();
    for (int i = 0; i < 16; i += 4) {
        const __m128 e = _mm_and_ps(_mm_loadu_ps(f + i), expo);
        bad = _mm_or_ps(bad, _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_castps_si128(e), _mm_castps_si128(expo))));
    }
    return _mm_movemask_ps(bad);
#else
    /* With the exponent masked, one more exponent step carries into the sign bit only for an
     * all-ones exponent; an integer OR-reduction. */
    uint32_t bits[16], acc = 0;
    memcpy(bits, f, sizeof bits);
    for (int i = 0; i < 16; ++i) acc |= (bits[i] & 0x7f800000u) + 0x00800000u;
    return (int)(acc >> 31);
#endif
}

ak_result ak_ik_two_bone_validate(const ak_ik_two_bone_job* job) {
    if (!job || !job->out_start_rot || !job->out_mid_rot) return AK_ERR_NULL_ARG;
    const float vecs[16] = {job->target.x,   job->target.y,   job->target.z,   job->pole.x, job->pole.y, job->pole.z,
                            job->mid_axis.x, job->mid_axis.y, job->mid_axis.z, job->twist};
    if (nonfinite16(job->start.m) | nonfinite16(job->mid.m) | nonfinite16(job->end.m) | nonfinite16(vecs))
        return AK_ERR_BAD_DATA;
    if (!(job->soft >= 0.0f && job->soft < 1.0f)) return AK_ERR_BAD_ARG;
    if (!(job->keep_animation >= 0.0f && job->keep_animation <= 1.0f)) return AK_ERR_BAD_ARG;
    return AK_OK;
}

ak_result ak_ik_two_bone_run(const ak_ik_two_bone_job* job) {
    ak_result r = ak_ik_two_bone_validate(job);
    if (r != AK_OK) return r;
    bool reached = akp_ik_two_bone_solve(job, 0, job->out_start_rot, job->out_mid_rot);
    if (job->out_reached) *job->out_reached = reached;
    return AK_OK;
}

/* The chain job's TWO_BONE solver: the same core on the chain's model transforms, then the
 * limits. A hinge mid joint bends about its own axis; if its limits reject the bend nearer the
 * current one, the other bend is tried and the one ending closer to the target kept. */
void akp_ik_two_bone_chain(akp_ik_chain* c, const ak_ik_chain_job* job) {
    ak_ik_two_bone_job tb = {
        .start = ak_transform_to_mat4(c->world[0]),
        .mid = ak_transform_to_mat4(c->world[1]),
        .end = ak_transform_to_mat4(c->world[2]),
        .target = c->target,
        .pole = job->pole,
        .soft = job->soft,
        .keep_animation = job->keep_animation,
    };
    const size_t j0 = (size_t)c->joints[0], j1 = (size_t)c->joints[1];
    const ak_joint_type mid_type = akp_ik_type(c, 1);
    if (mid_type == AK_JOINT_HINGE) tb.mid_axis = ak_skeleton_joint_limits(c->skeleton, j1).axis;
    const ak_transform l0 = c->pose[j0], l1 = c->pose[j1];
    float best_err = -1.0f;
    ak_transform best0 = l0, best1 = l1;
    for (int branch = 0; branch < 2; ++branch) {
        ak_quat qs, qm;
        akp_ik_two_bone_solve(&tb, branch, &qs, &qm);
        ak_transform n0 = l0, n1 = l1;
        n0.rotation = ak_quat_normalize(ak_quat_mul(l0.rotation, qs));
        n1.rotation = ak_quat_normalize(ak_quat_mul(l1.rotation, qm));
        bool clamped = false;
        if (c->limits) {
            ak_transform k0 = akp_ik_limit(c->skeleton, j0, n0);
            ak_transform k1 = akp_ik_limit(c->skeleton, j1, n1);
            clamped = akp_quat_angle(ak_quat_mul(ak_quat_conjugate(k1.rotation), n1.rotation)) > 1e-4f ||
                      akp_quat_angle(ak_quat_mul(ak_quat_conjugate(k0.rotation), n0.rotation)) > 1e-4f;
            n0 = k0, n1 = k1;
        }
        c->pose[j0] = n0, c->pose[j1] = n1;
        akp_ik_fk(c, 0);
        float err = ak_vec3_distance(c->world[2].translation, c->target);
        if (best_err < 0.0f || err < best_err) best_err = err, best0 = n0, best1 = n1;
        if (!clamped) break;
    }
    c->pose[j0] = best0, c->pose[j1] = best1;
    akp_ik_fk(c, 0);
}
