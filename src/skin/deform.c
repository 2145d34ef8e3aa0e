/* The skinning job: validation, per-joint preparation, the scalar reference kernels for LBS,
 * DQS and CoR, thread split and face-normal recomputation. The AVX-512 and AVX2 kernels are in
 * deform_avx512.c and deform_avx2.c and are only used for configurations they handle (see
 * akp_skin_range_avx512 and akp_skin_range_avx2); the job's simd_limit caps the choice. */
#include "tasks.h" /* thread_count > 1 */

#include "simd.h"
#include "skin_internal.h"

/* Palettes up to this many joints get a 64-byte aligned stack copy for the AVX2 LBS kernel. */
#define AKP_SKIN_STACK_PALETTE 128

/* ---- small helpers ---------------------------------------------------------------------- */

static size_t stride_or(size_t stride, size_t tight) { return stride ? stride : tight; }

static ak_vec3 load3(const char* base, size_t stride, size_t i) {
    float f[3];
    memcpy(f, base + i * stride, sizeof f);
    return ak_vec3_make(f[0], f[1], f[2]);
}
static void store3(char* base, size_t stride, size_t i, ak_vec3 v) {
    float f[3] = {v.x, v.y, v.z};
    memcpy(base + i * stride, f, sizeof f);
}

/* 3x4 affine in columns: c[0..2] linear part, c[3] translation. */
typedef struct affine34 {
    ak_vec3 c[4];
} affine34;

static ak_vec3 lin_apply(const ak_vec3* c, ak_vec3 v) {
    return ak_vec3_add(ak_vec3_add(ak_vec3_scale(c[0], v.x), ak_vec3_scale(c[1], v.y)), ak_vec3_scale(c[2], v.z));
}
/* Inverse transpose of the linear part applied to n, up to the positive factor 1/|det|, then
 * normalised (cof(A) n * sign(det)); a vanishing result gives zero. */
static ak_vec3 normal_apply(const ak_vec3* c, ak_vec3 n) {
    ak_vec3 k0 = ak_vec3_cross(c[1], c[2]), k1 = ak_vec3_cross(c[2], c[0]), k2 = ak_vec3_cross(c[0], c[1]);
    float det = ak_vec3_dot(c[0], k0);
    ak_vec3 r = ak_vec3_add(ak_vec3_add(ak_vec3_scale(k0, n.x), ak_vec3_scale(k1, n.y)), ak_vec3_scale(k2, n.z));
    if (det < 0.0f) r = ak_vec3_neg(r);
    return ak_vec3_normalize(r);
}

/* Polar decomposition A = R S (R a rotation, S symmetric) by Newton iteration in double:
 * X <- (X + X^-T) / 2. A negative determinant is folded into S (R from -A). */
static void polar3(const double a[9], double r[9]) {
    double det = a[0] * (a[4] * a[8] - a[7] * a[5]) - a[3] * (a[1] * a[8] - a[7] * a[2]) +
                 a[6] * (a[1] * a[5] - a[4] * a[2]);
    double sgn = det < 0.0 ? -1.0 : 1.0;
    double x[9];
    for (int i = 0; i < 9; ++i) x[i] = sgn * a[i];
    if (!(fabs(det) > 1e-30)) {
        for (int i = 0; i < 9; ++i) r[i] = (i % 4 == 0) ? 1.0 : 0.0;
        return;
    }
    for (int it = 0; it < 40; ++it) {
        /* column-major: x[c*3 + r]; inverse transpose = cofactor / det */
        double c00 = x[4] * x[8] - x[5] * x[7], c01 = x[5] * x[6] - x[3] * x[8], c02 = x[3] * x[7] - x[4] * x[6];
        double c10 = x[7] * x[2] - x[8] * x[1], c11 = x[8] * x[0] - x[6] * x[2], c12 = x[6] * x[1] - x[7] * x[0];
        double c20 = x[1] * x[5] - x[2] * x[4], c21 = x[2] * x[3] - x[0] * x[5], c22 = x[0] * x[4] - x[1] * x[3];
        double d = x[0] * c00 + x[1] * c01 + x[2] * c02;
        if (!(fabs(d) > 1e-300)) break;
        /* cofactor matrix as columns: column 0 = (c00, c10, c20)^T in row terms ... the inverse
         * transpose's element (row i, col j) is cof(i, j) / d where cof(i,j) multiplies x(i,j). */
        double it_[9] = {c00 / d, c01 / d, c02 / d, c10 / d, c11 / d, c12 / d, c20 / d, c21 / d, c22 / d};
        double diff = 0.0;
        for (int i = 0; i < 9; ++i) {
            double nx = 0.5 * (x[i] + it_[i]);
            diff += fabs(nx - x[i]);
            x[i] = nx;
        }
        if (diff < 1e-15) break;
    }
    memcpy(r, x, sizeof x);
}

static void prepare_joint(const ak_mat4* m, akp_skin_joint* out, bool* out_stretch) {
    double a[9], r[9];
    for (int c = 0; c < 3; ++c)
        for (int row = 0; row < 3; ++row) a[c * 3 + row] = m->m[c * 4 + row];
    polar3(a, r);
    ak_mat3 rf;
    for (int i = 0; i < 9; ++i) rf.m[i] = (float)r[i];
    ak_quat q = ak_quat_from_mat3(rf);
    ak_vec3 t = ak_vec3_make(m->m[12], m->m[13], m->m[14]);
    ak_quat d = ak_quat_scale(ak_quat_mul(ak_quat_make(t.x, t.y, t.z, 0.0f), q), 0.5f);
    out->real[0] = q.x; out->real[1] = q.y; out->real[2] = q.z; out->real[3] = q.w;
    out->dual[0] = d.x; out->dual[1] = d.y; out->dual[2] = d.z; out->dual[3] = d.w;
    /* S = R^T A: element (row i, col j) = sum_k R(k, i) A(k, j) */
    bool stretch = false;
    for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) {
            double s = 0.0;
            for (int k = 0; k < 3; ++k) s += r[i * 3 + k] * a[j * 3 + k];
            double ident = (i == j) ? 1.0 : 0.0;
            if (fabs(s - ident) > 1e-5) stretch = true;
            out->stretch[j * 4 + i] = (float)s;
        }
        out->stretch[j * 4 + 3] = 0.0f;
    }
    memset(out->pad, 0, sizeof out->pad);
    if (!stretch) {
        for (int j = 0; j < 3; ++j)
            for (int i = 0; i < 4; ++i) out->stretch[j * 4 + i] = (i == j) ? 1.0f : 0.0f;
    }
    *out_stretch = stretch;
}

/* ---- scalar reference kernels ------------------------------------------------------------ */

static void read_influences(const akp_skin_ctx* c, size_t i, uint16_t* j, float* w) {
    const char* jp = c->jnt + i * c->jnt_stride;
    const char* wp = c->wgt + i * c->wgt_stride;
    for (uint32_t k = 0; k < c->k; ++k) { /* fixed-size copies: plain loads, any alignment */
        memcpy(&j[k], jp + 2u * k, sizeof(uint16_t));
        memcpy(&w[k], wp + 4u * k, sizeof(float));
        if (j[k] >= c->palette_count) j[k] = (uint16_t)(c->palette_count - 1);
    }
}

static uint32_t argmax_weight(const float* w, uint32_t k) {
    uint32_t best = 0;
    for (uint32_t i = 1; i < k; ++i) best = w[i] > w[best] ? i : best;
    return best;
}

/* Hemisphere-aligned blend of the joints' rotation (and dual) quaternions. */
static void blend_quats(const akp_skin_ctx* c, const uint16_t* j, const float* w, ak_quat* real, ak_quat* dual) {
    const akp_skin_joint* ref = &c->joints_prep[j[argmax_weight(w, c->k)]];
    float br[4] = {0, 0, 0, 0}, bd[4] = {0, 0, 0, 0};
    for (uint32_t k = 0; k < c->k; ++k) {
        const akp_skin_joint* p = &c->joints_prep[j[k]];
        float d = p->real[0] * ref->real[0] + p->real[1] * ref->real[1] + p->real[2] * ref->real[2] +
                  p->real[3] * ref->real[3];
        float wk = d < 0.0f ? -w[k] : w[k];
        for (int e = 0; e < 4; ++e) {
            br[e] += wk * p->real[e];
            bd[e] += wk * p->dual[e];
        }
    }
    float n2 = br[0] * br[0] + br[1] * br[1] + br[2] * br[2] + br[3] * br[3];
    float inv = n2 > 1e-30f ? 1.0f / sqrtf(n2) : 0.0f;
    if (inv == 0.0f) { /* weights cancelled out (only with unchecked data): identity */
        *real = ak_quat_identity();
        *dual = ak_quat_make(0, 0, 0, 0);
        return;
    }
    *real = ak_quat_make(br[0] * inv, br[1] * inv, br[2] * inv, br[3] * inv);
    *dual = ak_quat_make(bd[0] * inv, bd[1] * inv, bd[2] * inv, bd[3] * inv);
}

static void blend_stretch(const akp_skin_ctx* c, const uint16_t* j, const float* w, ak_vec3* s) {
    s[0] = s[1] = s[2] = ak_vec3_zero();
    for (uint32_t k = 0; k < c->k; ++k) {
        const float* m = c->joints_prep[j[k]].stretch;
        for (int col = 0; col < 3; ++col)
            s[col] = ak_vec3_madd(s[col], ak_vec3_make(m[col * 4], m[col * 4 + 1], m[col * 4 + 2]), w[k]);
    }
}

static affine34 blend_matrix(const akp_skin_ctx* c, const uint16_t* j, const float* w) {
    /* flat accumulation over the 12 used entries of each column-major matrix */
    float m[16] = {0};
    for (uint32_t k = 0; k < c->k; ++k) {
        const float* p = c->palette[j[k]].m;
        const float wk = w[k];
        for (int e = 0; e < 16; ++e) m[e] += wk * p[e];
    }
    affine34 b;
    for (int col = 0; col < 4; ++col) b.c[col] = ak_vec3_make(m[col * 4], m[col * 4 + 1], m[col * 4 + 2]);
    return b;
}

/* Translation of the unit dual quaternion (real, dual): 2 (w dv - dw v + v x dv). */
static ak_vec3 dq_translation(ak_quat r, ak_quat d) {
    ak_vec3 v = ak_vec3_make(r.x, r.y, r.z), dv = ak_vec3_make(d.x, d.y, d.z);
    ak_vec3 t = ak_vec3_sub(ak_vec3_scale(dv, r.w), ak_vec3_scale(v, d.w));
    return ak_vec3_scale(ak_vec3_add(t, ak_vec3_cross(v, dv)), 2.0f);
}

/* LBS without tangents, as one flat loop the compiler can keep in registers: the path that
 * AK_NO_SIMD builds run most. */
static inline void lbs_range_scalar_k(const akp_skin_ctx* c, size_t begin, size_t end, uint32_t K) {
    uint16_t j[AK_MAX_INFLUENCES];
    float w[AK_MAX_INFLUENCES];
    for (size_t i = begin; i < end; ++i) {
        const char* jp = c->jnt + i * c->jnt_stride;
        const char* wp = c->wgt + i * c->wgt_stride;
        for (uint32_t k = 0; k < K; ++k) {
            memcpy(&j[k], jp + 2u * k, sizeof(uint16_t));
            memcpy(&w[k], wp + 4u * k, sizeof(float));
            if (j[k] >= c->palette_count) j[k] = (uint16_t)(c->palette_count - 1);
        }
        float m[12] = {0}; /* columns 0..3, rows 0..2 */
        for (uint32_t k = 0; k < K; ++k) {
            const float* p = c->palette[j[k]].m;
            const float wk = w[k];
            for (int col = 0; col < 4; ++col)
                for (int r = 0; r < 3; ++r) m[col * 3 + r] += wk * p[col * 4 + r];
        }
        float p[3];
        memcpy(p, c->pos + i * c->pos_stride, sizeof p);
        float o[3];
        for (int r = 0; r < 3; ++r) o[r] = m[r] * p[0] + m[3 + r] * p[1] + m[6 + r] * p[2] + m[9 + r];
        memcpy(c->out_pos + i * c->out_pos_stride, o, sizeof o);
        if (!c->do_normals) continue;
        float n[3];
        memcpy(n, c->nrm + i * c->nrm_stride, sizeof n);
        /* cofactor columns c1 x c2, c2 x c0, c0 x c1; times sign(det); then normalised */
        const float* c0 = m;
        const float* c1 = m + 3;
        const float* c2 = m + 6;
        float k0[3] = {c1[1] * c2[2] - c1[2] * c2[1], c1[2] * c2[0] - c1[0] * c2[2], c1[0] * c2[1] - c1[1] * c2[0]};
        float k1[3] = {c2[1] * c0[2] - c2[2] * c0[1], c2[2] * c0[0] - c2[0] * c0[2], c2[0] * c0[1] - c2[1] * c0[0]};
        float k2[3] = {c0[1] * c1[2] - c0[2] * c1[1], c0[2] * c1[0] - c0[0] * c1[2], c0[0] * c1[1] - c0[1] * c1[0]};
        float det = c0[0] * k0[0] + c0[1] * k0[1] + c0[2] * k0[2];
        float on[3];
        for (int r = 0; r < 3; ++r) on[r] = k0[r] * n[0] + k1[r] * n[1] + k2[r] * n[2];
        float l2 = on[0] * on[0] + on[1] * on[1] + on[2] * on[2];
        float s = l2 > 1e-30f ? 1.0f / sqrtf(l2) : 0.0f;
        if (det < 0.0f) s = -s;
        for (int r = 0; r < 3; ++r) on[r] *= s;
        memcpy(c->out_nrm + i * c->out_nrm_stride, on, sizeof on);
    }
}

static void lbs_range_scalar(const akp_skin_ctx* c, size_t begin, size_t end) {
    if (c->k == 4) lbs_range_scalar_k(c, begin, end, 4); /* constant: unrolled loops */
    else lbs_range_scalar_k(c, begin, end, c->k);
}

void akp_skin_range_scalar(const akp_skin_ctx* c, size_t begin, size_t end) {
    if (c->method == AK_SKIN_LBS && !c->do_tangents) {
        lbs_range_scalar(c, begin, end);
        return;
    }
    uint16_t j[AK_MAX_INFLUENCES];
    float w[AK_MAX_INFLUENCES];
    for (size_t i = begin; i < end; ++i) {
        read_influences(c, i, j, w);
        ak_vec3 p = load3(c->pos, c->pos_stride, i);
        ak_vec3 n = c->do_normals ? load3(c->nrm, c->nrm_stride, i) : ak_vec3_zero();
        float tan4[4] = {0, 0, 0, 0};
        if (c->do_tangents) memcpy(tan4, c->tan + i * c->tan_stride, sizeof tan4);
        ak_vec3 t = ak_vec3_make(tan4[0], tan4[1], tan4[2]);
        ak_vec3 op, on = ak_vec3_zero(), ot = ak_vec3_zero();
        if (c->method == AK_SKIN_LBS) {
            affine34 b = blend_matrix(c, j, w);
            op = ak_vec3_add(lin_apply(b.c, p), b.c[3]);
            if (c->do_normals) on = normal_apply(b.c, n);
            if (c->do_tangents) ot = ak_vec3_normalize(lin_apply(b.c, t));
        } else {
            ak_quat qr, qd;
            blend_quats(c, j, w, &qr, &qd);
            ak_vec3 s[3];
            bool stretch = c->any_stretch;
            if (stretch) blend_stretch(c, j, w, s);
            if (c->method == AK_SKIN_DQS) {
                ak_vec3 ps = stretch ? lin_apply(s, p) : p;
                op = ak_vec3_add(ak_quat_rotate(qr, ps), dq_translation(qr, qd));
            } else {
                ak_vec3 center = load3(c->ctr, c->ctr_stride, i);
                affine34 b = blend_matrix(c, j, w);
                ak_vec3 moved = ak_vec3_add(lin_apply(b.c, center), b.c[3]);
                ak_vec3 d = ak_vec3_sub(p, center);
                if (stretch) d = lin_apply(s, d);
                op = ak_vec3_add(ak_quat_rotate(qr, d), moved);
            }
            if (c->do_normals) on = ak_vec3_normalize(ak_quat_rotate(qr, stretch ? normal_apply(s, n) : n));
            if (c->do_tangents) ot = ak_vec3_normalize(ak_quat_rotate(qr, stretch ? lin_apply(s, t) : t));
        }
        store3(c->out_pos, c->out_pos_stride, i, op);
        if (c->do_normals) store3(c->out_nrm, c->out_nrm_stride, i, on);
        if (c->do_tangents) {
            float o4[4] = {ot.x, ot.y, ot.z, tan4[3]};
            memcpy(c->out_tan + i * c->out_tan_stride, o4, sizeof o4);
        }
    }
}

/* ---- public ------------------------------------------------------------------------------ */

size_t ak_skin_job_scratch_size(const ak_skin_job* job) {
    if (!job || job->method == AK_SKIN_LBS || job->method >= AK_SKIN_METHOD_COUNT) return 0;
    const size_t per_joint = sizeof(akp_skin_joint) + (job->method == AK_SKIN_COR ? 64u : 0u);
    return 64 + per_joint * job->palette.count;
}

static bool stride_ok(size_t stride, size_t elem) { return stride == 0 || stride >= elem; }

static bool finite3(const char* base, size_t stride, size_t i) {
    return ak_vec3_is_finite(load3(base, stride, i));
}

/* ---- the O(n) data rules: a fast screen, then the exact checks where it flags ------------ */

/* Flags of the screen below, OR-ed over all data; nonzero means "run the exact checks". A
 * float is flagged when all its exponent bits are set (infinite or NaN); a weight also when
 * its sign bit is set (negative, or -0.0, which the exact check accepts). */
static uint32_t float_flags(uint32_t b, uint32_t sign_mask) {
    return (b & sign_mask) | (uint32_t)((b & 0x7f800000u) == 0x7f800000u);
}

/* Flags of `total` tightly packed floats at base. */
static uint32_t flags_packed(const char* base, size_t total, uint32_t sign_mask) {
    uint32_t bad = 0;
    size_t i = 0;
#if AK_SIMD_SSE2
    const __m128i exp = _mm_set1_epi32(0x7f800000), sign = _mm_set1_epi32((int)sign_mask);
    __m128i acc = _mm_setzero_si128();
    for (; i + 4 <= total; i += 4) {
        __m128i v = _mm_loadu_si128((const __m128i*)(const void*)(base + 4 * i));
        acc = _mm_or_si128(acc, _mm_or_si128(_mm_and_si128(v, sign), _mm_cmpeq_epi32(_mm_and_si128(v, exp), exp)));
    }
    bad = (uint32_t)_mm_movemask_epi8(_mm_cmpeq_epi32(acc, _mm_setzero_si128())) != 0xffffu;
#endif
    for (; i < total; ++i) {
        uint32_t b;
        memcpy(&b, base + 4 * i, 4);
        bad |= float_flags(b, sign_mask);
    }
    return bad;
}

/* Flags of count elements of `floats` floats, stride bytes apart. */
static uint32_t flags_floats(const char* base, size_t stride, size_t count, size_t floats, uint32_t sign_mask) {
    if (stride == 4 * floats) return flags_packed(base, count * floats, sign_mask);
    uint32_t bad = 0;
    for (size_t i = 0; i < count; ++i) bad |= flags_packed(base + i * stride, floats, sign_mask);
    return bad;
}

/* Nonzero when some of the count joint indices (uint16_t, tightly packed) is >= limit. */
static uint32_t flags_joints_packed(const char* base, size_t count, uint32_t limit) {
    if (limit > 65535u) return 0;
    uint32_t bad = 0;
    size_t i = 0;
#if AK_SIMD_SSE2
    const __m128i top = _mm_set1_epi16((short)(uint16_t)(limit - 1));
    __m128i acc = _mm_setzero_si128();
    for (; i + 8 <= count; i += 8) /* j - (limit - 1) saturates to 0 iff j < limit */
        acc = _mm_or_si128(acc, _mm_subs_epu16(_mm_loadu_si128((const __m128i*)(const void*)(base + 2 * i)), top));
    bad = (uint32_t)_mm_movemask_epi8(_mm_cmpeq_epi16(acc, _mm_setzero_si128())) != 0xffffu;
#endif
    for (; i < count; ++i) {
        uint16_t j;
        memcpy(&j, base + 2 * i, 2);
        bad |= j >= limit;
    }
    return bad;
}

#if AK_SIMD_SSE2
/* flags_sums for tightly packed weights, k in {1, 2, 4, 8}, four vertices per step; *done
 * = the vertices checked (a multiple of 4). */
static inline uint32_t sums_flags_sse2(const char* wb, size_t n, const uint32_t k, size_t* done) {
    const __m128 one = _mm_set1_ps(1.0f), tol = _mm_set1_ps(0.9e-3f);
    const __m128 abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
    __m128 ok = _mm_castsi128_ps(_mm_set1_epi32(-1));
    size_t i = 0;
    for (; i + 4 <= n; i += 4) { /* the sums of vertices i .. i + 3 */
        const float* f = (const float*)(const void*)(wb + 4u * k * i);
        __m128 s4;
        if (k == 1) {
            s4 = _mm_loadu_ps(f);
        } else if (k == 2) {
            __m128 a = _mm_loadu_ps(f), b = _mm_loadu_ps(f + 4);
            s4 = _mm_add_ps(_mm_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0)), _mm_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1)));
        } else {
            __m128 r0 = _mm_loadu_ps(f), r1 = _mm_loadu_ps(f + k), r2 = _mm_loadu_ps(f + 2 * k),
                   r3 = _mm_loadu_ps(f + 3 * k);
            if (k == 8) {
                r0 = _mm_add_ps(r0, _mm_loadu_ps(f + 4));
                r1 = _mm_add_ps(r1, _mm_loadu_ps(f + 12));
                r2 = _mm_add_ps(r2, _mm_loadu_ps(f + 20));
                r3 = _mm_add_ps(r3, _mm_loadu_ps(f + 28));
            }
            _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
            s4 = _mm_add_ps(_mm_add_ps(r0, r1), _mm_add_ps(r2, r3));
        }
        ok = _mm_and_ps(ok, _mm_cmple_ps(_mm_and_ps(_mm_sub_ps(s4, one), abs), tol)); /* false for NaN */
    }
    *done = i;
    return _mm_movemask_ps(ok) != 0xf;
}
#endif

/* Nonzero when some vertex's float weight sum is not within 0.9e-3 of 1. Conservative: the
 * float sum of <= 8 weights in [0, 1] is within 1e-6 of the exact sum, far less than the 1e-4
 * between this tolerance and the exact rule's 1e-3, so a vertex the exact rule rejects is
 * always flagged (weights outside [0, 1] are flagged by their bits or their sum). */
static uint32_t flags_sums(const char* wb, size_t ws, size_t n, uint32_t k) {
    uint32_t bad = 0;
    size_t i = 0;
#if AK_SIMD_SSE2
    if (ws == 4u * k) { /* tightly packed: the loop specialised for the counts it handles */
        size_t done = 0;
        switch (k) {
        case 1: bad = sums_flags_sse2(wb, n, 1, &done); break;
        case 2: bad = sums_flags_sse2(wb, n, 2, &done); break;
        case 4: bad = sums_flags_sse2(wb, n, 4, &done); break;
        case 8: bad = sums_flags_sse2(wb, n, 8, &done); break;
        default: break;
        }
        i = done;
    }
#endif
    for (; i < n; ++i) {
        float sum = 0.0f;
        for (uint32_t e = 0; e < k; ++e) {
            float w;
            memcpy(&w, wb + i * ws + 4 * e, 4);
            sum += w;
        }
        bad |= !(fabsf(sum - 1.0f) <= 0.9e-3f);
    }
    return bad;
}

/* Whether every weight is finite with its sign bit clear, every weight sum is near 1 (see
 * flags_sums) and every joint index is below joint_limit: a fast screen for the exact rules. */
static bool influences_surely_ok(const char* wb, size_t ws, const char* jb, size_t js, size_t n, uint32_t k,
                                 size_t joint_limit) {
    const uint32_t limit = joint_limit > 65535u ? 65536u : (uint32_t)joint_limit;
    uint32_t bad = flags_floats(wb, ws, n, k, 0x80000000u) | flags_sums(wb, ws, n, k);
    if (js == 2u * k) {
        bad |= flags_joints_packed(jb, n * k, limit);
    } else {
        for (size_t i = 0; i < n; ++i) bad |= flags_joints_packed(jb + i * js, k, limit);
    }
    return bad == 0;
}

/* The data rules (rule 7 of ak_skin_job_validate) in rule order; the first failure wins. */
static ak_result check_data_exact(const ak_skin_job* job) {
    const uint32_t k = job->influence_count;
    const size_t n = job->positions.count;
    const size_t js = stride_or(job->joints.stride, 2u * k), ws = stride_or(job->weights.stride, 4u * k);
    const char* jb = (const char*)job->joints.ptr;
    const char* wb = (const char*)job->weights.ptr;
    for (size_t i = 0; i < n; ++i) {
        float w[AK_MAX_INFLUENCES];
        uint16_t jj[AK_MAX_INFLUENCES];
        memcpy(w, wb + i * ws, k * sizeof(float));
        memcpy(jj, jb + i * js, k * sizeof(uint16_t));
        double sum = 0.0;
        for (uint32_t e = 0; e < k; ++e) {
            if (!(w[e] >= 0.0f) || !ak_finitef(w[e])) return AK_ERR_BAD_WEIGHTS;
            sum += w[e];
        }
        if (fabs(sum - 1.0) > 1e-3) return AK_ERR_BAD_WEIGHTS;
        for (uint32_t e = 0; e < k; ++e)
            if (jj[e] >= job->palette.count) return AK_ERR_BAD_INDEX;
    }
    const size_t ps = stride_or(job->positions.stride, 12);
    for (size_t i = 0; i < n; ++i)
        if (!finite3((const char*)job->positions.ptr, ps, i)) return AK_ERR_BAD_DATA;
    if (job->normals.ptr && !job->normals_from_faces) {
        const size_t s = stride_or(job->normals.stride, 12);
        for (size_t i = 0; i < n; ++i)
            if (!finite3((const char*)job->normals.ptr, s, i)) return AK_ERR_BAD_DATA;
    }
    if (job->method == AK_SKIN_COR) {
        const size_t s = stride_or(job->cor_centers.stride, 12);
        for (size_t i = 0; i < n; ++i)
            if (!finite3((const char*)job->cor_centers.ptr, s, i)) return AK_ERR_BAD_DATA;
    }
    if (job->normals_from_faces)
        for (size_t i = 0; i < job->indices.count; ++i)
            if (job->indices.ptr[i] >= n) return AK_ERR_BAD_INDEX;
    return AK_OK;
}

/* The screen of the per-vertex data rules on vertices [b, e): true when all surely pass. */
static bool screen_range(const ak_skin_job* job, size_t b, size_t e) {
    const uint32_t k = job->influence_count;
    const size_t n = e - b, ws = stride_or(job->weights.stride, 4u * k), js = stride_or(job->joints.stride, 2u * k);
    const size_t ps = stride_or(job->positions.stride, 12), ns = stride_or(job->normals.stride, 12),
                 cs = stride_or(job->cor_centers.stride, 12);
    bool ok = influences_surely_ok((const char*)job->weights.ptr + b * ws, ws, (const char*)job->joints.ptr + b * js,
                                   js, n, k, job->palette.count);
    ok = ok && !flags_floats((const char*)job->positions.ptr + b * ps, ps, n, 3, 0);
    if (ok && job->normals.ptr && !job->normals_from_faces)
        ok = !flags_floats((const char*)job->normals.ptr + b * ns, ns, n, 3, 0);
    if (ok && job->method == AK_SKIN_COR) ok = !flags_floats((const char*)job->cor_centers.ptr + b * cs, cs, n, 3, 0);
    return ok;
}

/* Run fn on the count (<= 64) tasks at tasks, size bytes apart, on the worker team. */
static void run_tasks(void* (*fn)(void*), void* tasks, size_t size, uint32_t count) {
    akp_run_tasks(fn, tasks, size, count);
}

typedef struct screen_task {
    const ak_skin_job* job;
    size_t begin, end;
    bool ok;
} screen_task;

static void* screen_thread(void* arg) {
    screen_task* t = (screen_task*)arg;
    t->ok = screen_range(t->job, t->begin, t->end);
    return NULL;
}

/* Jobs below this many vertices screen on the calling thread (a thread start costs more). */
#define AKP_SKIN_PARALLEL_SCREEN 65536u

/* The data rules: a branch-free screen of the whole job (valid data, the common case, costs
 * about 2 ns per vertex), on up to `threads` threads for large jobs, and the exact
 * vertex-by-vertex checks only when the screen flags something. */
static ak_result check_data(const ak_skin_job* job, uint32_t threads) {
    const size_t n = job->positions.count;
    if (threads > 64) threads = 64;
    if (threads == 0 || n < AKP_SKIN_PARALLEL_SCREEN) threads = 1;
    screen_task tasks[64];
    const size_t chunk = (n + threads - 1) / threads;
    for (uint32_t t = 0; t < threads; ++t) {
        size_t b = (size_t)t * chunk, e = b + chunk;
        tasks[t] = (screen_task){job, b < n ? b : n, e < n ? e : n, false};
    }
    run_tasks(screen_thread, tasks, sizeof tasks[0], threads);
    bool ok = true;
    for (uint32_t t = 0; t < threads; ++t) ok = ok && tasks[t].ok;
    if (ok && job->normals_from_faces) {
        uint32_t bad = 0;
        for (size_t i = 0; i < job->indices.count; ++i) bad |= job->indices.ptr[i] >= n;
        ok = bad == 0;
    }
    return ok ? AK_OK : check_data_exact(job);
}

/* ak_skin_job_validate with the data screen on up to screen_threads threads. */
static ak_result validate_job(const ak_skin_job* job, uint32_t screen_threads) {
    if (!job || !job->positions.ptr || !job->palette.ptr || !job->joints.ptr || !job->weights.ptr ||
        !job->out_positions.ptr)
        return AK_ERR_NULL_ARG;
    if (job->palette.count == 0) return AK_ERR_NULL_ARG;
    const uint32_t k = job->influence_count;
    if ((unsigned)job->method >= AK_SKIN_METHOD_COUNT || k == 0 || k > AK_MAX_INFLUENCES || job->thread_count > 64 ||
        (unsigned)job->simd_limit >= AK_SKIN_SIMD_COUNT)
        return AK_ERR_BAD_ARG;
    if (!stride_ok(job->positions.stride, 12) || !stride_ok(job->normals.stride, 12) ||
        !stride_ok(job->tangents.stride, 16) || !stride_ok(job->cor_centers.stride, 12) ||
        !stride_ok(job->joints.stride, 2u * k) || !stride_ok(job->weights.stride, 4u * k) ||
        !stride_ok(job->out_positions.stride, 12) || !stride_ok(job->out_normals.stride, 12) ||
        !stride_ok(job->out_tangents.stride, 16))
        return AK_ERR_BAD_ARG;
    const bool want_normals = job->normals.ptr != NULL || job->normals_from_faces;
    if ((want_normals && !job->out_normals.ptr) || (job->tangents.ptr && !job->out_tangents.ptr) ||
        (job->method == AK_SKIN_COR && !job->cor_centers.ptr) || (job->normals_from_faces && !job->indices.ptr))
        return AK_ERR_NULL_ARG;
    if (job->normals_from_faces && job->indices.count % 3 != 0) return AK_ERR_BAD_ARG;
    const size_t n = job->positions.count;
    if (job->joints.count < n || job->weights.count < n || job->out_positions.count < n)
        return AK_ERR_SPAN_SMALL;
    if (job->normals.ptr && !job->normals_from_faces && job->normals.count < n) return AK_ERR_SPAN_SMALL;
    if (want_normals && job->out_normals.count < n) return AK_ERR_SPAN_SMALL;
    if (job->tangents.ptr && (job->tangents.count < n || job->out_tangents.count < n)) return AK_ERR_SPAN_SMALL;
    if (job->method == AK_SKIN_COR && job->cor_centers.count < n) return AK_ERR_SPAN_SMALL;
    if (job->scratch.count < ak_skin_job_scratch_size(job) ||
        (ak_skin_job_scratch_size(job) > 0 && !job->scratch.ptr))
        return AK_ERR_SPAN_SMALL;
    for (size_t j = 0; j < job->palette.count; ++j)
        if (!ak_mat4_is_finite(&job->palette.ptr[j])) return AK_ERR_BAD_DATA;
    if (job->skip_data_check) return AK_OK;
    return check_data(job, screen_threads);
}

ak_result ak_skin_job_validate(const ak_skin_job* job) { return validate_job(job, 1); }

/* True when every palette matrix's linear part is a rotation: columns of unit length and
 * orthogonal within 1e-5, determinant > 0 (then its cofactor matrix is itself, so a unit
 * normal maps to a unit normal). */
static bool palette_rigid(const ak_mat4* pal, size_t count) {
    for (size_t j = 0; j < count; ++j) {
        const float* m = pal[j].m;
        ak_vec3 c[3] = {ak_vec3_make(m[0], m[1], m[2]), ak_vec3_make(m[4], m[5], m[6]), ak_vec3_make(m[8], m[9], m[10])};
        for (int a = 0; a < 3; ++a)
            for (int b = a; b < 3; ++b)
                if (!(fabsf(ak_vec3_dot(c[a], c[b]) - (a == b ? 1.0f : 0.0f)) <= 1e-5f)) return false;
        if (!(ak_vec3_dot(c[0], ak_vec3_cross(c[1], c[2])) > 0.0f)) return false;
    }
    return true;
}

static akp_skin_ctx make_ctx(const ak_skin_job* job, const akp_skin_joint* prep, bool any_stretch) {
    akp_skin_ctx c;
    memset(&c, 0, sizeof c);
    c.method = job->method;
    c.k = job->influence_count;
    c.palette = job->palette.ptr;
    c.palette_count = job->palette.count;
    c.joints_prep = prep;
    c.any_stretch = any_stretch;
    c.pos = (const char*)job->positions.ptr;
    c.pos_stride = stride_or(job->positions.stride, 12);
    c.jnt = (const char*)job->joints.ptr;
    c.jnt_stride = stride_or(job->joints.stride, 2u * c.k);
    c.wgt = (const char*)job->weights.ptr;
    c.wgt_stride = stride_or(job->weights.stride, 4u * c.k);
    c.do_normals = job->normals.ptr != NULL && !job->normals_from_faces;
    c.nrm = (const char*)job->normals.ptr;
    c.nrm_stride = stride_or(job->normals.stride, 12);
    c.do_tangents = job->tangents.ptr != NULL;
    c.tan = (const char*)job->tangents.ptr;
    c.tan_stride = stride_or(job->tangents.stride, 16);
    c.ctr = (const char*)job->cor_centers.ptr;
    c.ctr_stride = stride_or(job->cor_centers.stride, 12);
    c.out_pos = (char*)job->out_positions.ptr;
    c.out_pos_stride = stride_or(job->out_positions.stride, 12);
    c.out_nrm = (char*)job->out_normals.ptr;
    c.out_nrm_stride = stride_or(job->out_normals.stride, 12);
    c.out_tan = (char*)job->out_tangents.ptr;
    c.out_tan_stride = stride_or(job->out_tangents.stride, 16);
    return c;
}

typedef struct range_task {
    const akp_skin_ctx* ctx;
    size_t begin, end;
    ak_skin_simd simd; /* the fastest kernel allowed: SCALAR, AVX2 or AVX512 */
} range_task;

/* Each kernel returns false (writing nothing) for a configuration or CPU it does not handle;
 * the next slower one then runs. */
static void* range_thread(void* arg) {
    const range_task* t = (const range_task*)arg;
    if (t->begin >= t->end) return NULL;
    if (t->simd >= AK_SKIN_SIMD_AVX512 && akp_skin_range_avx512(t->ctx, t->begin, t->end)) return NULL;
    if (t->simd >= AK_SKIN_SIMD_AVX2 && akp_skin_range_avx2(t->ctx, t->begin, t->end)) return NULL;
    akp_skin_range_scalar(t->ctx, t->begin, t->end);
    return NULL;
}

static void normals_from_faces(const ak_skin_job* job) {
    const size_t n = job->positions.count;
    const size_t ps = stride_or(job->out_positions.stride, 12), ns = stride_or(job->out_normals.stride, 12);
    const char* pos = (const char*)job->out_positions.ptr;
    char* nrm = (char*)job->out_normals.ptr;
    for (size_t i = 0; i < n; ++i) store3(nrm, ns, i, ak_vec3_zero());
    for (size_t t = 0; t + 2 < job->indices.count; t += 3) {
        uint32_t a = job->indices.ptr[t], b = job->indices.ptr[t + 1], cc = job->indices.ptr[t + 2];
        ak_vec3 pa = load3(pos, ps, a), pb = load3(pos, ps, b), pc = load3(pos, ps, cc);
        ak_vec3 f = ak_vec3_cross(ak_vec3_sub(pb, pa), ak_vec3_sub(pc, pa)); /* 2 * area * normal */
        store3(nrm, ns, a, ak_vec3_add(load3(nrm, ns, a), f));
        store3(nrm, ns, b, ak_vec3_add(load3(nrm, ns, b), f));
        store3(nrm, ns, cc, ak_vec3_add(load3(nrm, ns, cc), f));
    }
    for (size_t i = 0; i < n; ++i) {
        ak_vec3 v = ak_vec3_normalize(load3(nrm, ns, i));
        if (ak_vec3_length_sq(v) == 0.0f) v = ak_vec3_make(0.0f, 1.0f, 0.0f);
        store3(nrm, ns, i, v);
    }
}

ak_result ak_skin_job_run(const ak_skin_job* job) {
    ak_result r = validate_job(job, job ? job->thread_count : 1);
    if (r != AK_OK) return r;
    const size_t n = job->positions.count;
    if (n == 0) return AK_OK;

    akp_skin_joint* prep = NULL;
    bool any_stretch = false;
    if (job->method != AK_SKIN_LBS) {
        uintptr_t base = (uintptr_t)job->scratch.ptr;
        prep = (akp_skin_joint*)(void*)((base + 63u) & ~(uintptr_t)63u);
        for (size_t j = 0; j < job->palette.count; ++j) {
            bool s = false;
            prepare_joint(&job->palette.ptr[j], &prep[j], &s);
            any_stretch = any_stretch || s;
        }
        if (job->method == AK_SKIN_COR && !any_stretch) {
            for (size_t j = 0; j < job->palette.count; ++j) {
                const float* m = job->palette.ptr[j].m;
                float* neg = akp_skin_cor_neg_rows(prep, job->palette.count, j);
                for (int col = 0; col < 4; ++col) {
                    for (int r = 0; r < 3; ++r) prep[j].cor_rows[col * 4 + r] = neg[col * 4 + r] = m[col * 4 + r];
                    prep[j].cor_rows[col * 4 + 3] = prep[j].real[col];
                    neg[col * 4 + 3] = -prep[j].real[col];
                }
            }
        }
    }
    akp_skin_ctx ctx = make_ctx(job, prep, any_stretch);
    ctx.rigid_single = job->method == AK_SKIN_LBS && job->influence_count == 1 && !ctx.do_tangents &&
                       (!ctx.do_normals || palette_rigid(job->palette.ptr, job->palette.count));
    ak_skin_simd level = job->simd_limit == AK_SKIN_SIMD_DEFAULT ? AK_SKIN_SIMD_AVX512 : job->simd_limit;
    if (job->skip_simd) level = AK_SKIN_SIMD_SCALAR;
#if defined(AK_NO_SIMD)
    level = AK_SKIN_SIMD_SCALAR;
#endif
    const bool simd = level != AK_SKIN_SIMD_SCALAR;
    /* The AVX2 LBS blend loads each palette matrix as two 32-byte halves; from an array that is
     * not 64-byte aligned (malloc gives 16) half of those loads split a cache line, which cost
     * 8% (positions + normals) to 15% (positions) at 1M vertices. Small palettes are copied to
     * an aligned stack buffer (8 KiB at most) when the mesh is large enough to repay the copy. */
    _Alignas(64) ak_mat4 aligned_palette[AKP_SKIN_STACK_PALETTE];
    if (simd && job->method == AK_SKIN_LBS && ((uintptr_t)job->palette.ptr & 63u) != 0 &&
        job->palette.count <= AKP_SKIN_STACK_PALETTE && n >= 16 * job->palette.count) {
        memcpy(aligned_palette, job->palette.ptr, job->palette.count * sizeof(ak_mat4));
        ctx.palette = aligned_palette;
    }

    uint32_t threads = job->thread_count > 1 ? job->thread_count : 1;
    if (threads > n / 64 + 1) threads = (uint32_t)(n / 64 + 1);
    range_task tasks[64];
    size_t chunk = (n + threads - 1) / threads;
    chunk = (chunk + 15u) & ~(size_t)15u; /* keep SIMD blocks (8 or 16 vertices) whole */
    for (uint32_t t = 0; t < threads; ++t) {
        size_t b = (size_t)t * chunk, e = b + chunk;
        if (b > n) b = n;
        if (e > n) e = n;
        tasks[t].ctx = &ctx;
        tasks[t].begin = b;
        tasks[t].end = e;
        tasks[t].simd = level;
    }
    run_tasks(range_thread, tasks, sizeof tasks[0], threads);
    if (job->normals_from_faces) normals_from_faces(job);
    return AK_OK;
}

static ak_cstream offset_cstream(ak_cstream s, size_t tight, size_t first, size_t count) {
    if (!s.ptr) return s;
    size_t st = stride_or(s.stride, tight);
    s.ptr = (const char*)s.ptr + first * st;
    s.count = s.count > first ? s.count - first : 0;
    if (s.count > count) s.count = count;
    return s;
}
static ak_stream offset_stream(ak_stream s, size_t tight, size_t first, size_t count) {
    if (!s.ptr) return s;
    size_t st = stride_or(s.stride, tight);
    s.ptr = (char*)s.ptr + first * st;
    s.count = s.count > first ? s.count - first : 0;
    if (s.count > count) s.count = count;
    return s;
}

ak_result ak_skin_job_split(const ak_skin_job* job, size_t first_vertex, size_t vertex_count, ak_skin_job* out_part) {
    if (!job || !out_part) return AK_ERR_NULL_ARG;
    if (job->normals_from_faces || first_vertex > job->positions.count ||
        vertex_count > job->positions.count - first_vertex)
        return AK_ERR_BAD_ARG;
    const uint32_t k = job->influence_count;
    ak_skin_job p = *job;
    p.positions = offset_cstream(job->positions, 12, first_vertex, vertex_count);
    p.positions.count = vertex_count;
    p.joints = offset_cstream(job->joints, 2u * k, first_vertex, vertex_count);
    p.weights = offset_cstream(job->weights, 4u * k, first_vertex, vertex_count);
    p.normals = offset_cstream(job->normals, 12, first_vertex, vertex_count);
    p.tangents = offset_cstream(job->tangents, 16, first_vertex, vertex_count);
    p.cor_centers = offset_cstream(job->cor_centers, 12, first_vertex, vertex_count);
    p.out_positions = offset_stream(job->out_positions, 12, first_vertex, vertex_count);
    p.out_normals = offset_stream(job->out_normals, 12, first_vertex, vertex_count);
    p.out_tangents = offset_stream(job->out_tangents, 16, first_vertex, vertex_count);
    *out_part = p;
    return AK_OK;
}

const char* ak_skin_simd_name(void) {
#if defined(AK_NO_SIMD)
    return "scalar";
#else
    return akp_skin_have_avx512() ? "avx512" : akp_skin_have_avx2() ? "avx2" : "scalar";
#endif
}
