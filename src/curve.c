/* Keyframe tracks: validation, build (sorting, derived tangents), evaluation, derivatives.
 * Easing, time warps and the arc-length table are in src/curve/ease.c. */
#include <animkit/curve.h>

#include "curve/track.h"
#include "internal.h"

/* ---- private helpers ---------------------------------------------------------------- */

typedef struct key_order {
    float time;
    uint32_t index;
} key_order;

static int key_order_cmp(const void* pa, const void* pb) {
    const key_order* a = (const key_order*)pa;
    const key_order* b = (const key_order*)pb;
    if (a->time < b->time) return -1;
    if (a->time > b->time) return 1;
    return (a->index > b->index) - (a->index < b->index);
}

static bool interp_is_hermite_family(ak_interp i) {
    return i == AK_INTERP_CUBICSPLINE || i == AK_INTERP_HERMITE || i == AK_INTERP_CARDINAL ||
           i == AK_INTERP_BEZIER || i == AK_INTERP_NATURAL;
}

/* Floats per key in the raw layout. */
static uint32_t raw_stride(const ak_raw_track* r) {
    bool three = r->interp == AK_INTERP_CUBICSPLINE || r->interp == AK_INTERP_HERMITE ||
                 r->interp == AK_INTERP_BEZIER;
    return three ? 3u * r->component_count : r->component_count;
}

/* Unit-quaternion log and exp in double: log(q) = (theta/2) axis. */
static void qlog_d(const double q[4], double out[3]) {
    double s = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]);
    double w = q[3];
    double f = s > 1e-15 ? atan2(s, w) / s : 1.0;
    out[0] = q[0] * f;
    out[1] = q[1] * f;
    out[2] = q[2] * f;
}
static void qexp_d(const double v[3], double out[4]) {
    double th = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    double f = th > 1e-15 ? sin(th) / th : 1.0;
    out[0] = v[0] * f;
    out[1] = v[1] * f;
    out[2] = v[2] * f;
    out[3] = cos(th);
}
/* a * b (Hamilton), xyzw. */
static void qmul_d(const double a[4], const double b[4], double out[4]) {
    double r[4];
    r[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    r[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    r[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    r[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    memcpy(out, r, sizeof r);
}
static void qconj_d(const double a[4], double out[4]) {
    out[0] = -a[0];
    out[1] = -a[1];
    out[2] = -a[2];
    out[3] = a[3];
}

static ak_quat quat_load(const float* p) { return ak_quat_make(p[0], p[1], p[2], p[3]); }
static void quat_store(float* p, ak_quat q) {
    p[0] = q.x;
    p[1] = q.y;
    p[2] = q.z;
    p[3] = q.w;
}

/* SQUAD inner points from aligned unit keys q (n keys, xyzw floats in a stride-12 layout
 * whose value sits at offset 4): writes s_in at offset 0 and s_out at offset 8. */
static void squad_inner_points(float* vals, const float* times, size_t n) {
    for (size_t i = 0; i < n; ++i) {
        double q[4], qi[4], a[3] = {0, 0, 0}, b[3] = {0, 0, 0}, w[3];
        for (int c = 0; c < 4; ++c) q[c] = vals[i * 12 + 4 + (size_t)c];
        qconj_d(q, qi);
        double hp = i > 0 ? (double)times[i] - (double)times[i - 1] : 0.0;
        double hn = i + 1 < n ? (double)times[i + 1] - (double)times[i] : 0.0;
        if (i > 0) {
            double p[4], d[4];
            for (int c = 0; c < 4; ++c) p[c] = vals[(i - 1) * 12 + 4 + (size_t)c];
            qmul_d(qi, p, d);
            qlog_d(d, a);
        }
        if (i + 1 < n) {
            double p[4], d[4];
            for (int c = 0; c < 4; ++c) p[c] = vals[(i + 1) * 12 + 4 + (size_t)c];
            qmul_d(qi, p, d);
            qlog_d(d, b);
        }
        /* Angular velocity estimate at key i (log units per second, body frame). */
        for (int c = 0; c < 3; ++c) {
            if (i > 0 && i + 1 < n) w[c] = (b[c] - a[c]) / (hp + hn);
            else if (i + 1 < n) w[c] = b[c] / hn;
            else if (i > 0) w[c] = -a[c] / hp;
            else w[c] = 0.0;
        }
        double cin[3], cout[3], e[4], s[4];
        for (int c = 0; c < 3; ++c) {
            cin[c] = i > 0 ? 0.5 * (-w[c] * hp - a[c]) : 0.0;
            cout[c] = i + 1 < n ? 0.5 * (w[c] * hn - b[c]) : 0.0;
        }
        qexp_d(cin, e);
        qmul_d(q, e, s);
        for (int c = 0; c < 4; ++c) vals[i * 12 + (size_t)c] = (float)s[c];
        qexp_d(cout, e);
        qmul_d(q, e, s);
        for (int c = 0; c < 4; ++c) vals[i * 12 + 8 + (size_t)c] = (float)s[c];
    }
}

/* Natural cubic spline tangents (per second) for one component. y, m: [n] with stride;
 * tmp: 3 * n doubles. */
static void natural_tangents(const float* times, size_t n, const float* y, size_t ystride,
                             float* m_in, float* m_out, size_t mstride, double* tmp) {
    double* M = tmp;
    double* cp = tmp + n;
    double* dp = tmp + 2 * n;
    for (size_t i = 0; i < n; ++i) M[i] = cp[i] = dp[i] = 0.0;
    if (n >= 3) {
        for (size_t i = 1; i + 1 < n; ++i) {
            double h0 = (double)times[i] - (double)times[i - 1];
            double h1 = (double)times[i + 1] - (double)times[i];
            double s0 = ((double)y[i * ystride] - (double)y[(i - 1) * ystride]) / h0;
            double s1 = ((double)y[(i + 1) * ystride] - (double)y[i * ystride]) / h1;
            double a = h0, b = 2.0 * (h0 + h1), c = h1, d = 6.0 * (s1 - s0);
            double denom = i > 1 ? b - a * cp[i - 1] : b;
            cp[i] = c / denom;
            dp[i] = (i > 1 ? d - a * dp[i - 1] : d) / denom;
        }
        M[n - 2] = dp[n - 2];
        for (size_t i = n - 2; i-- > 1;) M[i] = dp[i] - cp[i] * M[i + 1];
    }
    for (size_t i = 0; i < n; ++i) {
        double d;
        if (n == 1) {
            d = 0.0;
        } else if (i + 1 < n) {
            double h = (double)times[i + 1] - (double)times[i];
            d = ((double)y[(i + 1) * ystride] - (double)y[i * ystride]) / h -
                h * (2.0 * M[i] + M[i + 1]) / 6.0;
        } else {
            double h = (double)times[i] - (double)times[i - 1];
            d = ((double)y[i * ystride] - (double)y[(i - 1) * ystride]) / h +
                h * (M[i - 1] + 2.0 * M[i]) / 6.0;
        }
        m_in[i * mstride] = (float)d;
        m_out[i * mstride] = (float)d;
    }
}

/* double -> float without leaving the finite range (Lagrange can overshoot wildly). */
static float clamp_to_float(double x) {
    if (x != x) return 0.0f;
    if (x > 3.4028234663852886e38) return 3.4028234663852886e38f;
    if (x < -3.4028234663852886e38) return -3.4028234663852886e38f;
    return (float)x;
}

/* ---- segment evaluation ------------------------------------------------------------- */

static float seg_u(const ak_track* tr, size_t k, float t) {
    float t0 = tr->times[k], t1 = tr->times[k + 1];
    float u = (t - t0) / (t1 - t0);
    return u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
}

static void hermite_basis(float u, float d, float b[4]) {
    float u2 = u * u, u3 = u2 * u;
    b[0] = 2.0f * u3 - 3.0f * u2 + 1.0f;
    b[1] = (u3 - 2.0f * u2 + u) * d;
    b[2] = -2.0f * u3 + 3.0f * u2;
    b[3] = (u3 - u2) * d;
}

/* Newton-form polynomial and its first two derivatives at t, component c. */
static void newton_eval(const ak_track* tr, uint32_t c, double t, double out[3]) {
    size_t n = tr->key_count, cc = tr->component_count;
    double p = tr->newton[(n - 1) * cc + c], dp = 0.0, ddp = 0.0;
    for (size_t k = n - 1; k-- > 0;) {
        double x = t - (double)tr->times[k];
        ddp = ddp * x + 2.0 * dp;
        dp = dp * x + p;
        p = p * x + tr->newton[k * cc + c];
    }
    out[0] = p;
    out[1] = dp;
    out[2] = ddp;
}

static void key_value(const ak_track* tr, size_t k, float* out) {
    const float* v = tr->values + k * tr->stride + tr->value_offset;
    for (uint32_t c = 0; c < tr->component_count; ++c) out[c] = v[c];
    if (tr->is_rotation && tr->eval == AKP_EVAL_HERMITE) quat_store(out, ak_quat_normalize(quat_load(out)));
}

void akp_track_eval(const ak_track* tr, size_t seg, float t, float* out) {
    size_t n = tr->key_count;
    uint32_t cc = tr->component_count;
    if (tr->eval == AKP_EVAL_LAGRANGE && n > 1 && t > tr->times[0] && t < tr->times[n - 1]) {
        for (uint32_t c = 0; c < cc; ++c) {
            double r[3];
            newton_eval(tr, c, (double)t, r);
            out[c] = clamp_to_float(r[0]);
        }
        return;
    }
    if (n == 1 || !(t > tr->times[0])) {
        key_value(tr, 0, out);
        return;
    }
    if (t >= tr->times[n - 1]) {
        key_value(tr, n - 1, out);
        return;
    }
    const float* a = tr->values + seg * tr->stride;
    const float* b = a + tr->stride;
    switch (tr->eval) {
    case AKP_EVAL_STEP:
        key_value(tr, seg, out);
        return;
    case AKP_EVAL_LINEAR: {
        float u = seg_u(tr, seg, t);
        for (uint32_t c = 0; c < cc; ++c) out[c] = a[c] + (b[c] - a[c]) * u;
        return;
    }
    case AKP_EVAL_SLERP: {
        /* glTF LINEAR rotation with the per-segment constants from build time. */
        float u = seg_u(tr, seg, t);
        if (a[5] == 0.0f) {
            quat_store(out, ak_quat_nlerp(quat_load(a), quat_load(b), u));
            return;
        }
        float wa = akp_sin_half_pi((1.0f - u) * a[4]) * a[5], wb = akp_sin_half_pi(u * a[4]) * a[5] * a[6];
        quat_store(out, ak_quat_normalize(ak_quat_make(wa * a[0] + wb * b[0], wa * a[1] + wb * b[1],
                                                       wa * a[2] + wb * b[2], wa * a[3] + wb * b[3])));
        return;
    }
    case AKP_EVAL_NLERP:
        quat_store(out, ak_quat_nlerp(quat_load(a), quat_load(b), seg_u(tr, seg, t)));
        return;
    case AKP_EVAL_HERMITE: {
        float d = tr->times[seg + 1] - tr->times[seg];
        float w[4];
        hermite_basis(seg_u(tr, seg, t), d, w);
        const float* p0 = a + cc;
        const float* m0 = a + 2 * cc;
        const float* m1 = b;
        const float* p1 = b + cc;
        for (uint32_t c = 0; c < cc; ++c) out[c] = w[0] * p0[c] + w[1] * m0[c] + w[2] * p1[c] + w[3] * m1[c];
        if (tr->is_rotation) quat_store(out, ak_quat_normalize(quat_load(out)));
        return;
    }
    case AKP_EVAL_SQUAD: {
        float u = seg_u(tr, seg, t);
        ak_quat q0 = quat_load(a + 4), s0 = quat_load(a + 8), s1 = quat_load(b), q1 = quat_load(b + 4);
        ak_quat outer = ak_quat_slerp(q0, q1, u), inner = ak_quat_slerp(s0, s1, u);
        quat_store(out, ak_quat_slerp(outer, inner, 2.0f * u * (1.0f - u)));
        return;
    }
    case AKP_EVAL_LAGRANGE:
        return; /* handled above */
    }
}

/* ---- segment search ------------------------------------------------------------------ */

static size_t find_in(const float* times, float t, size_t lo, size_t hi) {
    while (lo < hi) {
        size_t mid = lo + (hi - lo + 1) / 2;
        if (times[mid] <= t) lo = mid;
        else hi = mid - 1;
    }
    return lo;
}

size_t akp_track_find(const ak_track* tr, float t) {
    if (tr->key_count < 2) return 0;
    return find_in(tr->times, t, 0, tr->key_count - 2);
}

size_t akp_track_find_from(const ak_track* tr, float t, size_t k) {
    size_t n = tr->key_count;
    if (n < 2) return 0;
    size_t last = n - 2;
    if (k > last) k = last;
    const float* times = tr->times;
    if (times[k] <= t) {
        /* Forward playback: a few linear steps, then binary search of the rest. */
        for (int step = 0; step < 4; ++step) {
            if (k == last || !(times[k + 1] <= t)) return k;
            ++k;
        }
        return find_in(times, t, k, last);
    }
    if (k == 0) return 0;
    if (times[k - 1] <= t) return k - 1;
    return k - 1 == 0 ? 0 : find_in(times, t, 0, k - 2);
}

/* ---- derivatives --------------------------------------------------------------------- */

/* Derivative of order 1 or 2 of a plain track on segment seg at t. */
static void plain_derivative(const ak_track* tr, size_t seg, float t, int order, float* out) {
    size_t n = tr->key_count;
    uint32_t cc = tr->component_count;
    for (uint32_t c = 0; c < cc; ++c) out[c] = 0.0f;
    if (n < 2 || !(t >= tr->times[0]) || t > tr->times[n - 1]) return;
    if (tr->eval == AKP_EVAL_LAGRANGE) {
        for (uint32_t c = 0; c < cc; ++c) {
            double r[3];
            newton_eval(tr, c, (double)t, r);
            out[c] = clamp_to_float(r[order]);
        }
        return;
    }
    /* At the last key use the last segment's end. */
    if (t == tr->times[n - 1]) seg = n - 2;
    const float* a = tr->values + seg * tr->stride;
    const float* b = a + tr->stride;
    double d = (double)tr->times[seg + 1] - (double)tr->times[seg];
    if (tr->eval == AKP_EVAL_LINEAR) {
        if (order == 1)
            for (uint32_t c = 0; c < cc; ++c) out[c] = (float)(((double)b[c] - (double)a[c]) / d);
        return;
    }
    if (tr->eval != AKP_EVAL_HERMITE) return;
    double u = ((double)t - (double)tr->times[seg]) / d;
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    double w[4];
    if (order == 1) {
        w[0] = (6.0 * u * u - 6.0 * u) / d;
        w[1] = 3.0 * u * u - 4.0 * u + 1.0;
        w[2] = (-6.0 * u * u + 6.0 * u) / d;
        w[3] = 3.0 * u * u - 2.0 * u;
    } else {
        w[0] = (12.0 * u - 6.0) / (d * d);
        w[1] = (6.0 * u - 4.0) / d;
        w[2] = (-12.0 * u + 6.0) / (d * d);
        w[3] = (6.0 * u - 2.0) / d;
    }
    const float* p0 = a + cc;
    const float* m0 = a + 2 * cc;
    const float* m1 = b;
    const float* p1 = b + cc;
    for (uint32_t c = 0; c < cc; ++c)
        out[c] = (float)(w[0] * p0[c] + w[1] * m0[c] + w[2] * p1[c] + w[3] * m1[c]);
}

/* Angular velocity (parent space) of a rotation track at t. */
static void rotation_velocity(const ak_track* tr, size_t seg, float t, float* out) {
    size_t n = tr->key_count;
    out[0] = out[1] = out[2] = 0.0f;
    if (n < 2 || !(t >= tr->times[0]) || t > tr->times[n - 1] || tr->eval == AKP_EVAL_STEP) return;
    if (t == tr->times[n - 1]) seg = n - 2;
    const float* a = tr->values + seg * tr->stride;
    const float* b = a + tr->stride;
    double t0 = tr->times[seg], t1 = tr->times[seg + 1], d = t1 - t0;
    double u = ((double)t - t0) / d;
    u = u < 0.0 ? 0.0 : (u > 1.0 ? 1.0 : u);
    double q[4], dq[4];
    if (tr->eval == AKP_EVAL_SLERP) {
        /* q(u) = q0 exp(u v) with v = log(q0^-1 q1): w_parent = q (2 v / d) q^-1. */
        double q0[4], q1[4], qi[4], r[4], v[3];
        for (int c = 0; c < 4; ++c) {
            q0[c] = a[c];
            q1[c] = b[c];
        }
        double dot = q0[0] * q1[0] + q0[1] * q1[1] + q0[2] * q1[2] + q0[3] * q1[3];
        if (dot < 0.0)
            for (int c = 0; c < 4; ++c) q1[c] = -q1[c];
        qconj_d(q0, qi);
        qmul_d(qi, q1, r);
        qlog_d(r, v);
        double body[4] = {2.0 * v[0] / d, 2.0 * v[1] / d, 2.0 * v[2] / d, 0.0}, tmp[4], res[4];
        /* The rotation axis is fixed along the segment, so q0 carries it to parent space. */
        qmul_d(q0, body, tmp);
        qmul_d(tmp, qi, res);
        for (int c = 0; c < 3; ++c) out[c] = (float)res[c];
        return;
    }
    if (tr->eval == AKP_EVAL_NLERP || tr->eval == AKP_EVAL_HERMITE) {
        double c4[4], dc[4];
        if (tr->eval == AKP_EVAL_NLERP) {
            double sgn = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]) < 0.0f ? -1.0 : 1.0;
            for (int c = 0; c < 4; ++c) {
                double qa = a[c], qb = sgn * b[c];
                c4[c] = qa + (qb - qa) * u;
                dc[c] = (qb - qa) / d;
            }
        } else {
            double u2 = u * u, u3 = u2 * u;
            double w[4] = {2 * u3 - 3 * u2 + 1, (u3 - 2 * u2 + u) * d, -2 * u3 + 3 * u2, (u3 - u2) * d};
            double dw[4] = {(6 * u2 - 6 * u) / d, 3 * u2 - 4 * u + 1, (-6 * u2 + 6 * u) / d, 3 * u2 - 2 * u};
            for (int c = 0; c < 4; ++c) {
                double p0 = a[4 + c], m0 = a[8 + c], m1 = b[c], p1 = b[4 + c];
                c4[c] = w[0] * p0 + w[1] * m0 + w[2] * p1 + w[3] * m1;
                dc[c] = dw[0] * p0 + dw[1] * m0 + dw[2] * p1 + dw[3] * m1;
            }
        }
        double len = sqrt(c4[0] * c4[0] + c4[1] * c4[1] + c4[2] * c4[2] + c4[3] * c4[3]);
        if (!(len > 1e-15)) return;
        for (int c = 0; c < 4; ++c) q[c] = c4[c] / len;
        double qd = q[0] * dc[0] + q[1] * dc[1] + q[2] * dc[2] + q[3] * dc[3];
        for (int c = 0; c < 4; ++c) dq[c] = (dc[c] - q[c] * qd) / len;
    } else {
        /* SQUAD: central difference inside the segment. */
        double h = 1e-3 * d;
        double ta = (double)t - h, tb = (double)t + h;
        if (ta < t0) ta = t0;
        if (tb > t1) tb = t1;
        float fa[4], fb[4], fq[4];
        akp_track_eval(tr, seg, (float)ta, fa);
        akp_track_eval(tr, seg, (float)tb, fb);
        akp_track_eval(tr, seg, t, fq);
        double sa = (fa[0] * fq[0] + fa[1] * fq[1] + fa[2] * fq[2] + fa[3] * fq[3]) < 0.0f ? -1.0 : 1.0;
        double sb = (fb[0] * fq[0] + fb[1] * fq[1] + fb[2] * fq[2] + fb[3] * fq[3]) < 0.0f ? -1.0 : 1.0;
        for (int c = 0; c < 4; ++c) {
            q[c] = fq[c];
            dq[c] = (sb * fb[c] - sa * fa[c]) / (tb - ta);
        }
    }
    /* w = 2 dq q^-1 (vector part). */
    double qi[4], r[4];
    qconj_d(q, qi);
    qmul_d(dq, qi, r);
    for (int c = 0; c < 3; ++c) out[c] = (float)(2.0 * r[c]);
}

/* ---- internal build ------------------------------------------------------------------ */

ak_result akp_track_check(const ak_raw_track* raw, ak_raw_track* r, ak_diag* diag, const char* prefix) {
    *r = *raw;
    if (r->key_count == 0) {
        akp_diag_set(diag, NULL, "%shas no keys", prefix);
        return AK_ERR_EMPTY;
    }
    if (!r->times || !r->values) {
        akp_diag_set(diag, NULL, "%shas NULL times or values", prefix);
        return AK_ERR_NULL_ARG;
    }
    if ((unsigned)r->interp >= (unsigned)AK_INTERP_COUNT) {
        akp_diag_set(diag, NULL, "%shas an unknown interpolation %d", prefix, (int)r->interp);
        return AK_ERR_BAD_ARG;
    }
    if (r->interp == AK_INTERP_DEFAULT) r->interp = AK_INTERP_LINEAR;
    if (r->component_count == 0) r->component_count = r->is_rotation ? 4u : 1u;
    if (r->component_count > AK_TRACK_MAX_COMPONENTS || (r->is_rotation && r->component_count != 4)) {
        akp_diag_set(diag, NULL, "%shas %u components", prefix, (unsigned)r->component_count);
        return AK_ERR_BAD_ARG;
    }
    if (r->key_count > 0x7fffffffu) {
        akp_diag_set(diag, NULL, "%shas too many keys", prefix);
        return AK_ERR_BAD_ARG;
    }
    if (!r->is_rotation && (r->interp == AK_INTERP_NLERP || r->interp == AK_INTERP_SQUAD)) {
        akp_diag_set(diag, NULL, "%suses %s, which is for rotations only", prefix, ak_interp_name(r->interp));
        return AK_ERR_BAD_ARG;
    }
    if (r->is_rotation && (r->interp == AK_INTERP_CARDINAL || r->interp == AK_INTERP_BEZIER ||
                           r->interp == AK_INTERP_NATURAL || r->interp == AK_INTERP_LAGRANGE)) {
        akp_diag_set(diag, NULL, "%s: %s is not supported for rotations", prefix, ak_interp_name(r->interp));
        return AK_ERR_UNSUPPORTED;
    }
    if (!ak_finitef(r->tension) || r->tension < 0.0f) {
        akp_diag_set(diag, NULL, "%shas tension %g", prefix, (double)r->tension);
        return AK_ERR_BAD_ARG;
    }
    if (r->tension == 0.0f) r->tension = 1.0f;
    return AK_OK;
}

static uint32_t runtime_stride(const ak_raw_track* r) {
    if (interp_is_hermite_family(r->interp) || (r->is_rotation && r->interp == AK_INTERP_SQUAD))
        return 3u * r->component_count;
    if (r->is_rotation && r->interp == AK_INTERP_LINEAR) return 8u; /* q, then the slerp constants */
    return r->component_count;
}

/* SLERP constants of each segment, computed once in double: angle theta, 1 / sin(theta) (0
 * -> nearly parallel keys, use NLERP) and the sign that takes the shorter arc. Stored after
 * key k's quaternion (stride 8). */
static void slerp_constants(float* vals, size_t n) {
    for (size_t k = 0; k + 1 < n; ++k) {
        float* a = vals + k * 8;
        const float* b = a + 8;
        double d = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2] + (double)a[3] * b[3];
        double sign = d < 0.0 ? -1.0 : 1.0, ad = fabs(d), chord = 0.0;
        for (int c = 0; c < 4; ++c) {
            double e = sign * b[c] - ad * a[c];
            chord += e * e;
        }
        double theta = atan2(sqrt(chord), ad);
        bool tiny = ad > 0.9999995;
        a[4] = tiny ? 0.0f : (float)theta;
        a[5] = tiny ? 0.0f : (float)(1.0 / sin(theta));
        a[6] = (float)sign;
        a[7] = 0.0f;
    }
}

size_t akp_track_data_size(const ak_raw_track* r) {
    size_t n = r->key_count;
    size_t s = akp_align16(n * sizeof(float));
    s += akp_align16(n * runtime_stride(r) * sizeof(float));
    if (r->interp == AK_INTERP_LAGRANGE) s += akp_align16(n * r->component_count * sizeof(double));
    return s;
}

ak_result akp_track_build_into(const ak_raw_track* r, ak_track* tr, void* data, const ak_allocator* alloc,
                               ak_diag* diag, const char* prefix) {
    size_t n = r->key_count;
    uint32_t cc = r->component_count;
    uint32_t in_stride = raw_stride(r), stride = runtime_stride(r);
    char* p = (char*)data;
    float* times = (float*)p;
    p += akp_align16(n * sizeof(float));
    float* vals = (float*)p;
    p += akp_align16(n * stride * sizeof(float));
    double* newton = r->interp == AK_INTERP_LAGRANGE ? (double*)p : NULL;

    memset(tr, 0, sizeof(*tr));
    tr->times = times;
    tr->values = vals;
    tr->newton = newton;
    tr->key_count = (uint32_t)n;
    tr->component_count = cc;
    tr->stride = stride;
    tr->value_offset = stride == 3u * cc ? cc : 0u;
    tr->interp = r->interp;
    tr->tension = r->tension;
    tr->is_rotation = r->is_rotation;

    /* Finite checks before sorting, so the diag names the raw key. */
    for (size_t k = 0; k < n; ++k) {
        if (!ak_finitef(r->times[k])) {
            akp_diag_set(diag, NULL, "%skey %zu has time %g", prefix, k, (double)r->times[k]);
            return AK_ERR_BAD_DATA;
        }
        for (uint32_t c = 0; c < in_stride; ++c) {
            if (!ak_finitef(r->values[k * in_stride + c])) {
                akp_diag_set(diag, NULL, "%skey %zu has a non-finite value", prefix, k);
                return AK_ERR_BAD_DATA;
            }
        }
    }

    /* Sort (skipped when already strictly increasing, the usual case). */
    key_order* order = NULL;
    bool sorted = true;
    for (size_t k = 1; k < n; ++k)
        if (!(r->times[k - 1] < r->times[k])) sorted = false;
    if (!sorted) {
        order = (key_order*)akp_alloc(alloc, n * sizeof(key_order));
        if (!order) return AK_ERR_NO_MEMORY;
        for (size_t k = 0; k < n; ++k) {
            order[k].time = r->times[k];
            order[k].index = (uint32_t)k;
        }
        qsort(order, n, sizeof(key_order), key_order_cmp);
        for (size_t k = 1; k < n; ++k) {
            if (order[k].time == order[k - 1].time) {
                akp_diag_set(diag, NULL, "%skeys %u and %u share time %g", prefix, (unsigned)order[k - 1].index,
                             (unsigned)order[k].index, (double)order[k].time);
                akp_free(alloc, order);
                return AK_ERR_DUPLICATE;
            }
        }
    }

    /* Copy keys in time order. The value of key k goes to offset value_offset in the runtime
     * layout; three-part raw layouts are copied whole and reordered below for BEZIER. */
    for (size_t k = 0; k < n; ++k) {
        size_t src = order ? order[k].index : k;
        times[k] = r->times[src];
        const float* in = r->values + src * in_stride;
        float* out = vals + k * stride;
        if (in_stride == stride) {
            memcpy(out, in, stride * sizeof(float));
        } else {
            for (uint32_t c = 0; c < stride; ++c) out[c] = 0.0f;
            memcpy(out + tr->value_offset, in, cc * sizeof(float));
        }
    }
    akp_free(alloc, order);

    /* Rotation keys: non-zero; normalised (except the tangent forms, renormalised at sampling). */
    if (r->is_rotation) {
        for (size_t k = 0; k < n; ++k) {
            float* q = vals + k * stride + tr->value_offset;
            float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
            if (!(n2 > 1e-20f) || !ak_finitef(n2)) {
                akp_diag_set(diag, NULL, "%skey %zu is a zero quaternion", prefix, k);
                return AK_ERR_BAD_DATA;
            }
            if (r->interp != AK_INTERP_CUBICSPLINE && r->interp != AK_INTERP_HERMITE)
                quat_store(q, ak_quat_normalize(quat_load(q)));
        }
    }

    switch (r->interp) {
    case AK_INTERP_STEP:
        tr->eval = AKP_EVAL_STEP;
        break;
    case AK_INTERP_LINEAR:
        tr->eval = r->is_rotation ? AKP_EVAL_SLERP : AKP_EVAL_LINEAR;
        if (r->is_rotation) slerp_constants(vals, n);
        break;
    case AK_INTERP_NLERP:
        tr->eval = AKP_EVAL_NLERP;
        break;
    case AK_INTERP_CUBICSPLINE:
    case AK_INTERP_HERMITE:
        tr->eval = AKP_EVAL_HERMITE;
        break;
    case AK_INTERP_CARDINAL:
        tr->eval = AKP_EVAL_HERMITE;
        for (size_t k = 0; k < n; ++k) {
            size_t lo = k > 0 ? k - 1 : 0, hi = k + 1 < n ? k + 1 : n - 1;
            for (uint32_t c = 0; c < cc; ++c) {
                double m = 0.0;
                if (hi > lo)
                    m = (double)r->tension * ((double)vals[hi * stride + cc + c] - (double)vals[lo * stride + cc + c]) /
                        ((double)times[hi] - (double)times[lo]);
                vals[k * stride + c] = (float)m;
                vals[k * stride + 2 * cc + c] = (float)m;
            }
        }
        break;
    case AK_INTERP_BEZIER:
        /* Runtime layout (in, value, out); raw (value, out-control, in-control). */
        tr->eval = AKP_EVAL_HERMITE;
        for (size_t k = 0; k < n; ++k) {
            float* key = vals + k * stride;
            double dprev = k > 0 ? (double)times[k] - (double)times[k - 1] : 0.0;
            double dnext = k + 1 < n ? (double)times[k + 1] - (double)times[k] : dprev;
            if (k == 0) dprev = dnext;
            for (uint32_t c = 0; c < cc; ++c) {
                double v = key[c], out_ctrl = key[cc + c], in_ctrl = key[2 * cc + c];
                double min = 0.0, mout = 0.0;
                if (dprev > 0.0) min = 3.0 * (v - in_ctrl) / dprev;
                if (dnext > 0.0) mout = 3.0 * (out_ctrl - v) / dnext;
                key[c] = (float)min;
                key[cc + c] = (float)v;
                key[2 * cc + c] = (float)mout;
            }
        }
        break;
    case AK_INTERP_NATURAL: {
        tr->eval = AKP_EVAL_HERMITE;
        double* tmp = (double*)akp_alloc(alloc, 3 * n * sizeof(double));
        if (!tmp) return AK_ERR_NO_MEMORY;
        for (uint32_t c = 0; c < cc; ++c)
            natural_tangents(times, n, vals + cc + c, stride, vals + c, vals + 2 * cc + c, stride, tmp);
        akp_free(alloc, tmp);
        break;
    }
    case AK_INTERP_SQUAD:
        tr->eval = AKP_EVAL_SQUAD;
        /* Align consecutive keys into one hemisphere, then the inner points. */
        for (size_t k = 1; k < n; ++k) {
            float* q = vals + k * stride + 4;
            const float* qp = vals + (k - 1) * stride + 4;
            if (q[0] * qp[0] + q[1] * qp[1] + q[2] * qp[2] + q[3] * qp[3] < 0.0f)
                for (int c = 0; c < 4; ++c) q[c] = -q[c];
        }
        squad_inner_points(vals, times, n);
        break;
    case AK_INTERP_LAGRANGE:
        tr->eval = AKP_EVAL_LAGRANGE;
        for (size_t k = 0; k < n; ++k)
            for (uint32_t c = 0; c < cc; ++c) newton[k * cc + c] = vals[k * stride + c];
        for (size_t level = 1; level < n; ++level)
            for (size_t k = n - 1; k >= level; --k)
                for (uint32_t c = 0; c < cc; ++c)
                    newton[k * cc + c] = (newton[k * cc + c] - newton[(k - 1) * cc + c]) /
                                         ((double)times[k] - (double)times[k - level]);
        for (size_t i = 0; i < n * cc; ++i) {
            if (!(newton[i] - newton[i] == 0.0)) {
                akp_diag_set(diag, NULL, "%sthe Lagrange polynomial through %zu keys overflows", prefix, n);
                return AK_ERR_BAD_DATA;
            }
        }
        break;
    case AK_INTERP_DEFAULT:
    case AK_INTERP_COUNT:
        AK_ASSERT(0);
        break;
    }
    return AK_OK;
}

/* ---- public API ---------------------------------------------------------------------- */

const char* ak_interp_name(ak_interp interp) {
    static const char* const names[AK_INTERP_COUNT] = {"default", "step",    "linear",  "cubicspline",
                                                       "hermite", "cardinal", "bezier", "natural",
                                                       "lagrange", "nlerp",   "squad"};
    if ((unsigned)interp >= (unsigned)AK_INTERP_COUNT) return "unknown";
    return names[interp];
}

ak_result ak_track_build(const ak_raw_track* raw, const ak_allocator* alloc, ak_track** out_track, ak_diag* diag) {
    if (out_track) *out_track = NULL;
    if (!raw || !out_track) return AK_ERR_NULL_ARG;
    ak_raw_track r;
    ak_result res = akp_track_check(raw, &r, diag, "track ");
    if (res != AK_OK) return res;
    size_t head = akp_align16(sizeof(ak_track));
    size_t size = head + akp_track_data_size(&r);
    char* mem = (char*)akp_alloc(alloc, size);
    if (!mem) return AK_ERR_NO_MEMORY;
    ak_track* tr = (ak_track*)mem;
    res = akp_track_build_into(&r, tr, mem + head, alloc, diag, "track ");
    if (res != AK_OK) {
        akp_free(alloc, mem);
        return res;
    }
    tr->standalone = true;
    if (alloc) tr->alloc = *alloc;
    *out_track = tr;
    return AK_OK;
}

void ak_track_destroy(ak_track* track) {
    if (!track || !track->standalone) return;
    ak_allocator a = track->alloc;
    akp_free(&a, track);
}

uint32_t ak_track_component_count(const ak_track* t) { return t ? t->component_count : 0u; }
bool ak_track_is_rotation(const ak_track* t) { return t ? t->is_rotation : false; }
ak_interp ak_track_interp(const ak_track* t) { return t ? t->interp : AK_INTERP_DEFAULT; }
size_t ak_track_key_count(const ak_track* t) { return t ? t->key_count : 0u; }
ak_f32_cspan ak_track_times(const ak_track* t) {
    ak_f32_cspan s = {NULL, 0};
    if (t) {
        s.ptr = t->times;
        s.count = t->key_count;
    }
    return s;
}
float ak_track_start_time(const ak_track* t) { return t ? t->times[0] : 0.0f; }
float ak_track_end_time(const ak_track* t) { return t ? t->times[t->key_count - 1] : 0.0f; }

ak_result ak_track_key(const ak_track* tr, size_t k, ak_f32_span out_value, ak_f32_span out_in,
                       ak_f32_span out_out) {
    if (!tr) return AK_ERR_NULL_ARG;
    if (k >= tr->key_count) return AK_ERR_BAD_INDEX;
    uint32_t cc = tr->component_count;
    if ((out_value.count && (out_value.count < cc || !out_value.ptr)) || (out_in.count && (out_in.count < cc || !out_in.ptr)) ||
        (out_out.count && (out_out.count < cc || !out_out.ptr)))
        return AK_ERR_SPAN_SMALL;
    if (out_value.count) key_value(tr, k, out_value.ptr);
    float in[AK_TRACK_MAX_COMPONENTS], out[AK_TRACK_MAX_COMPONENTS];
    for (uint32_t c = 0; c < cc; ++c) in[c] = out[c] = 0.0f;
    size_t n = tr->key_count;
    if (tr->eval == AKP_EVAL_HERMITE) {
        for (uint32_t c = 0; c < cc; ++c) {
            in[c] = tr->values[k * tr->stride + c];
            out[c] = tr->values[k * tr->stride + 2 * cc + c];
        }
    } else if (tr->eval == AKP_EVAL_LINEAR && n > 1) {
        size_t seg_in = k > 0 ? k - 1 : 0, seg_out = k + 1 < n ? k : n - 2;
        const float* v = tr->values;
        for (uint32_t c = 0; c < cc; ++c) {
            in[c] = (v[(seg_in + 1) * cc + c] - v[seg_in * cc + c]) / (tr->times[seg_in + 1] - tr->times[seg_in]);
            out[c] = (v[(seg_out + 1) * cc + c] - v[seg_out * cc + c]) / (tr->times[seg_out + 1] - tr->times[seg_out]);
        }
    } else if (tr->eval == AKP_EVAL_LAGRANGE && n > 1) {
        for (uint32_t c = 0; c < cc; ++c) {
            double r[3];
            newton_eval(tr, c, (double)tr->times[k], r);
            in[c] = out[c] = clamp_to_float(r[1]);
        }
    }
    if (out_in.count) memcpy(out_in.ptr, in, cc * sizeof(float));
    if (out_out.count) memcpy(out_out.ptr, out, cc * sizeof(float));
    return AK_OK;
}

ak_result ak_track_sample(const ak_track* tr, float time, ak_f32_span out) {
    if (!tr || !out.ptr) return AK_ERR_NULL_ARG;
    if (out.count < tr->component_count) return AK_ERR_SPAN_SMALL;
    akp_track_eval(tr, akp_track_find(tr, time), time, out.ptr);
    return AK_OK;
}

ak_result ak_track_derivative(const ak_track* tr, float time, int order, ak_f32_span out) {
    if (!tr || !out.ptr) return AK_ERR_NULL_ARG;
    if (order != 1 && order != 2) return AK_ERR_BAD_ARG;
    if (tr->is_rotation && order == 2) return AK_ERR_UNSUPPORTED;
    if (out.count < (tr->is_rotation ? 3u : tr->component_count)) return AK_ERR_SPAN_SMALL;
    size_t seg = akp_track_find(tr, time);
    if (tr->is_rotation) rotation_velocity(tr, seg, time, out.ptr);
    else plain_derivative(tr, seg, time, order, out.ptr);
    return AK_OK;
}

ak_result ak_track_sample_uniform(const ak_track* tr, float start, float end, ak_f32_span out_times,
                                  ak_f32_span out_values) {
    if (!tr || !out_times.ptr || !out_values.ptr) return AK_ERR_NULL_ARG;
    if (out_times.count == 0) return AK_ERR_EMPTY;
    if (!ak_finitef(start) || !ak_finitef(end)) return AK_ERR_BAD_DATA;
    size_t cc = tr->component_count;
    if (out_values.count / cc < out_times.count) return AK_ERR_SPAN_SMALL;
    size_t count = out_times.count, seg = 0;
    for (size_t i = 0; i < count; ++i) {
        double f = count > 1 ? (double)i / (double)(count - 1) : 0.0;
        float t = (float)((double)start + ((double)end - (double)start) * f);
        seg = akp_track_find_from(tr, t, seg);
        out_times.ptr[i] = t;
        akp_track_eval(tr, seg, t, out_values.ptr + i * cc);
    }
    return AK_OK;
}

void akp_track_velocity(const ak_track* tr, size_t seg, float t, float* out) {
    size_t n = tr->key_count;
    if (n >= 2 && tr->eval != AKP_EVAL_LAGRANGE && seg + 1 < n) {
        /* Clamp into the segment so plain_derivative does not switch segments at its ends. */
        float t0 = tr->times[seg], t1 = tr->times[seg + 1];
        t = t < t0 ? t0 : (t > t1 ? t1 : t);
        if (t == t1 && seg + 2 < n) {
            /* Evaluate the segment's end from its own side. */
            const float* a = tr->values + seg * tr->stride;
            const float* b = a + tr->stride;
            uint32_t cc = tr->component_count;
            double d = (double)t1 - (double)t0;
            for (uint32_t c = 0; c < cc; ++c) {
                if (tr->eval == AKP_EVAL_LINEAR) out[c] = (float)(((double)b[c] - (double)a[c]) / d);
                else if (tr->eval == AKP_EVAL_HERMITE) out[c] = b[c]; /* in-tangent of the next key */
                else out[c] = 0.0f;
            }
            return;
        }
    }
    plain_derivative(tr, seg, t, 1, out);
}
