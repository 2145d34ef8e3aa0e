/* Tests of the math core against independent oracles: closed forms, the double-precision
 * reference code in tests/ref/ref_math.h, and properties (round trips, orthonormality,
 * unit norms). Property tests run 10,000 seeded random cases each. */
#include <float.h>
#include <stdint.h>

#include <animkit/math.h>

#include "ak_test.h"
#include "ref/ref_math.h"

#define CASES AK_TEST_REPS(10000, 1000) /* random trials per property (fewer under valgrind) */

/* ---- helpers ------------------------------------------------------------------------- */

/* max that turns NaN into +inf, so a NaN anywhere fails the check (fmax would drop it). */
static double dmax(double a, double b) { return a != a || b != b ? INFINITY : a > b ? a : b; }

static ref_q rq(ak_quat q) { ref_q r = {q.x, q.y, q.z, q.w}; return r; }
static ak_quat fq(ref_q q) { return ak_quat_make((float)q.x, (float)q.y, (float)q.z, (float)q.w); }
static ref_v3 rv(ak_vec3 v) { return ref_v3_make(v.x, v.y, v.z); }
static ak_vec3 fv(ref_v3 v) { return ak_vec3_make((float)v.x, (float)v.y, (float)v.z); }
static ref_m3 rm3(ak_mat3 m) {
    ref_m3 r;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i) r.m[i][c] = m.m[c * 3 + i];
    return r;
}
static ak_mat3 fm3(ref_m3 m) {
    ak_mat3 r;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i) r.m[c * 3 + i] = (float)m.m[i][c];
    return r;
}
static ref_m4 rm4(ak_mat4 m) {
    ref_m4 r;
    for (int c = 0; c < 4; ++c)
        for (int i = 0; i < 4; ++i) r.m[i][c] = m.m[c * 4 + i];
    return r;
}
static double m3_diff(ak_mat3 a, ref_m3 b) {
    double d = 0.0;
    for (int c = 0; c < 3; ++c)
        for (int i = 0; i < 3; ++i) d = dmax(d, fabs(a.m[c * 3 + i] - b.m[i][c]));
    return d;
}
static double m3_scale(ref_m3 a) {
    double s = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s = dmax(s, fabs(a.m[i][j]));
    return s;
}
static double v3_diff(ak_vec3 a, ref_v3 b) {
    return dmax(fabs(a.x - b.x), dmax(fabs(a.y - b.y), fabs(a.z - b.z)));
}
/* Max difference of two quaternions up to sign (q and -q are one rotation). */
static double q_diff_sign(ak_quat a, ref_q b) {
    double p = dmax(dmax(fabs(a.x - b.x), fabs(a.y - b.y)), dmax(fabs(a.z - b.z), fabs(a.w - b.w)));
    double m = dmax(dmax(fabs(a.x + b.x), fabs(a.y + b.y)), dmax(fabs(a.z + b.z), fabs(a.w + b.w)));
    return (p != p || m != m ? INFINITY : p < m ? p : m);
}
static bool m3_finite(ak_mat3 m) {
    for (int i = 0; i < 9; ++i)
        if (!isfinite(m.m[i])) return false;
    return true;
}
/* Uniform random rotation (Shoemake's subgroup algorithm). */
static ref_q rand_quat(ak_rng* g) {
    double u1 = ak_rng_double(g), u2 = 2.0 * REF_PI * ak_rng_double(g), u3 = 2.0 * REF_PI * ak_rng_double(g);
    double a = sqrt(1.0 - u1), b = sqrt(u1);
    ref_q q = {a * sin(u2), a * cos(u2), b * sin(u3), b * cos(u3)};
    return q;
}
/* Uniform direction (rejection sampling in the unit ball). */
static ref_v3 rand_dir(ak_rng* g) {
    for (;;) {
        ref_v3 v = {2 * ak_rng_double(g) - 1, 2 * ak_rng_double(g) - 1, 2 * ak_rng_double(g) - 1};
        double l = ref_v3_len(v);
        if (l > 0.1 && l <= 1.0) return ref_v3_scale(v, 1.0 / l);
    }
}
static double rand_range(ak_rng* g, double lo, double hi) { return lo + (hi - lo) * ak_rng_double(g); }
static double wrap_angle(double d) { return atan2(sin(d), cos(d)); }
/* Orthonormality error max|R^T R - I| and det of a float matrix. */
static double orth_err(ak_mat3 m) {
    ref_m3 r = rm3(m), p = ref_m3_mul(ref_m3_transpose(r), r);
    double e = 0.0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) e = dmax(e, fabs(p.m[i][j] - (i == j)));
    return e;
}

/* ---- quaternions and rotation matrices ------------------------------------------------ */

AK_TEST(quat_matrix_round_trip) {
    ak_rng g = ak_rng_make(1);
    double worst_m = 0, worst_q = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_q q = rand_quat(&g);
        ak_mat3 m = ak_mat3_from_quat(fq(q));
        worst_m = dmax(worst_m, m3_diff(m, ref_m3_from_q(q)));
        worst_q = dmax(worst_q, q_diff_sign(ak_quat_from_mat3(m), q));
        AK_CHECK(ak_quat_from_mat3(m).w >= 0.0f);
    }
    AK_CHECK_NEAR(worst_m, 0.0, 1e-6);
    AK_CHECK_NEAR(worst_q, 0.0, 2e-6);
}

AK_TEST(quat_product_matches_matrix_product) {
    ak_rng g = ak_rng_make(2);
    double worst_q = 0, worst_m = 0, worst_v = 0, worst_inv = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_q a = rand_quat(&g), b = rand_quat(&g);
        ak_quat p = ak_quat_mul(fq(a), fq(b));
        worst_q = dmax(worst_q, q_diff_sign(p, ref_q_mul(a, b)));
        /* R(a b) = R(a) R(b): the product applies b first, then a. */
        ref_m3 rab = ref_m3_mul(ref_m3_from_q(a), ref_m3_from_q(b));
        worst_m = dmax(worst_m, m3_diff(ak_mat3_from_quat(p), rab));
        ref_v3 v = ref_v3_scale(rand_dir(&g), rand_range(&g, 0.1, 10.0));
        worst_v = dmax(worst_v, v3_diff(ak_quat_rotate(fq(a), fv(v)), ref_m3_apply(ref_m3_from_q(a), v)) / 10.0);
        /* inverse of a scaled quaternion */
        ak_quat s = ak_quat_scale(fq(a), 3.0f);
        worst_inv = dmax(worst_inv, q_diff_sign(ak_quat_mul(s, ak_quat_inverse(s)), (ref_q){0, 0, 0, 1}));
    }
    AK_CHECK_NEAR(worst_q, 0.0, 1e-6);
    AK_CHECK_NEAR(worst_m, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_v, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_inv, 0.0, 1e-6);
}

AK_TEST(rodrigues_and_axis_angle) {
    ak_rng g = ak_rng_make(3);
    double worst = 0, worst_q = 0, worst_rt = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_v3 axis = ref_v3_scale(rand_dir(&g), rand_range(&g, 0.01, 100.0)); /* not unit */
        double angle = rand_range(&g, -2.0 * REF_PI, 2.0 * REF_PI);
        ak_vec3 fa = fv(axis);
        ref_m3 ref = ref_m3_axis_angle(rv(fa), (float)angle);
        worst = dmax(worst, m3_diff(ak_mat3_from_axis_angle(fa, (float)angle), ref));
        ak_quat q = ak_quat_from_axis_angle(fa, (float)angle);
        worst_q = dmax(worst_q, m3_diff(ak_mat3_from_quat(q), ref));
        /* back to axis-angle: angle in [0, pi], and it rebuilds the rotation */
        ak_vec3 ax2;
        float an2;
        ak_quat_to_axis_angle(q, &ax2, &an2);
        AK_CHECK(an2 >= 0.0f && an2 <= AK_PI + 1e-6f);
        worst_rt = dmax(worst_rt, m3_diff(ak_mat3_from_axis_angle(ax2, an2), ref));
    }
    AK_CHECK_NEAR(worst, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_q, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_rt, 0.0, 3e-6);
    /* zero axis, non-finite angle: identity */
    AK_CHECK_NEAR(m3_diff(ak_mat3_from_axis_angle(ak_vec3_make(0, 1, 0), NAN), ref_m3_identity()), 0.0, 0.0);
    AK_CHECK(ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), INFINITY).w == 1.0f);
    AK_CHECK_NEAR(m3_diff(ak_mat3_from_axis_angle(ak_vec3_zero(), 1.0f), ref_m3_identity()), 0.0, 0.0);
    AK_CHECK_NEAR(q_diff_sign(ak_quat_from_axis_angle(ak_vec3_zero(), 1.0f), (ref_q){0, 0, 0, 1}), 0.0, 0.0);
}

/* Finite inputs whose squared length overflows float (components above ~1.8e19) still have a
 * direction: normalising gives it (not the zero / identity fallback of non-finite input), and
 * exp stays finite. Oracles are the exact directions. */
AK_TEST(huge_finite_inputs) {
    const float big[3] = {2e19f, 1e30f, 3e38f};
    for (int i = 0; i < 3; ++i) {
        float b = big[i];
        ak_vec3 v = ak_vec3_normalize(ak_vec3_make(b, 0, 0));
        AK_CHECK_MSG(v.x == 1.0f && v.y == 0.0f && v.z == 0.0f, "normalize(%g, 0, 0) = (%g %g %g)", (double)b, (double)v.x,
                     (double)v.y, (double)v.z);
        v = ak_vec3_normalize(ak_vec3_make(-b, b, 0));
        AK_CHECK_NEAR(v.x, -0.70710678, 1e-6);
        AK_CHECK_NEAR(v.y, 0.70710678, 1e-6);
        ak_quat q = ak_quat_normalize(ak_quat_make(0, b, 0, 0));
        AK_CHECK_MSG(q.y == 1.0f && q.w == 0.0f, "quat_normalize(0, %g, 0, 0) = (%g %g %g %g)", (double)b, (double)q.x,
                     (double)q.y, (double)q.z, (double)q.w);
        q = ak_quat_normalize(ak_quat_make(b, b, b, -b));
        AK_CHECK_NEAR(q.x, 0.5, 1e-6);
        AK_CHECK_NEAR(q.w, -0.5, 1e-6);
        ak_quat r = ak_quat_from_axis_angle(ak_vec3_make(0, 0, b), 1.0f);
        AK_CHECK_NEAR(r.z, sin(0.5), 1e-6);
        AK_CHECK_NEAR(r.w, cos(0.5), 1e-6);
        /* exp of a huge pure quaternion: unit length (its angle is meaningless, but finite) */
        ak_quat e = ak_quat_exp(ak_quat_make(b, b, 0, 0));
        AK_CHECK_MSG(ak_quat_is_finite(e), "exp(%g, %g, 0, 0) = (%g %g %g %g)", (double)b, (double)b, (double)e.x,
                     (double)e.y, (double)e.z, (double)e.w);
        AK_CHECK_NEAR(ak_quat_norm(e), 1.0, 1e-5);
        /* the array path agrees with the scalar one, SIMD lanes included */
        ak_quat in[5] = {{0, b, 0, 0}, {0, 0, 0, 1}, {b, b, b, -b}, {0, 0, 0, 0}, {0, 0, b, 0}}, out[5];
        AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){in, 5}, (ak_quat_span){out, 5}), AK_OK);
        AK_CHECK(out[0].y == 1.0f && out[1].w == 1.0f && out[3].w == 1.0f && out[4].z == 1.0f);
        AK_CHECK_NEAR(out[2].w, -0.5, 1e-6);
    }
    /* genuinely non-finite input keeps its fallbacks */
    ak_vec3 z = ak_vec3_normalize(ak_vec3_make(INFINITY, 0, 0));
    AK_CHECK(z.x == 0 && z.y == 0 && z.z == 0);
    ak_quat qi = ak_quat_normalize(ak_quat_make(0, INFINITY, 0, 0));
    AK_CHECK(qi.w == 1 && qi.y == 0);
}

AK_TEST(quat_exp_log) {
    ak_rng g = ak_rng_make(4);
    double worst_rt = 0, worst_log = 0, worst_exp = 0, worst_gen = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_v3 axis = rand_dir(&g);
        double angle = rand_range(&g, 0.0, REF_PI);
        ref_q q = ref_q_axis_angle(axis, angle);
        ak_quat lq = ak_quat_log(fq(q));
        /* log of a unit quaternion is (axis angle/2, 0) */
        worst_log = dmax(worst_log, q_diff_sign(lq, (ref_q){axis.x * angle / 2, axis.y * angle / 2, axis.z * angle / 2, 0.0}));
        worst_rt = dmax(worst_rt, q_diff_sign(ak_quat_exp(lq), q));
        /* exp of a pure quaternion (v, 0) is (sin|v| v/|v|, cos|v|), |v| up to 3 pi */
        ref_v3 v = ref_v3_scale(rand_dir(&g), rand_range(&g, 0.0, 3.0 * REF_PI));
        double th = ref_v3_len(v);
        ak_quat e = ak_quat_exp(ak_quat_make((float)v.x, (float)v.y, (float)v.z, 0.0f));
        ref_q ev = {sin(th) * v.x / th, sin(th) * v.y / th, sin(th) * v.z / th, cos(th)};
        worst_exp = dmax(worst_exp, q_diff_sign(e, ev) / dmax(1.0, th));
        /* general quaternions: exp(log(q)) = q, relative to |q| */
        ref_q s = rand_quat(&g);
        double k = exp(rand_range(&g, -3.0, 3.0));
        ak_quat sq = fq((ref_q){s.x * k, s.y * k, s.z * k, s.w * k});
        ak_quat back = ak_quat_exp(ak_quat_log(sq));
        worst_gen = dmax(worst_gen, q_diff_sign(ak_quat_scale(back, (float)(1.0 / k)), s));
    }
    AK_CHECK_NEAR(worst_log, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_rt, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_exp, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_gen, 0.0, 4e-6);
    /* tiny angles keep their digits: log of a 1e-6 rad turn */
    ak_quat tiny = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1e-6f);
    AK_CHECK_NEAR(ak_quat_log(tiny).z, 0.5e-6, 1e-12);
    AK_CHECK_NEAR(ak_quat_exp(ak_quat_make(0, 0, 0.5e-6f, 0)).z, 0.5e-6, 1e-12);
    /* edge cases: finite, documented */
    ak_quat l0 = ak_quat_log(ak_quat_make(0, 0, 0, 0));
    AK_CHECK(l0.x == 0 && l0.y == 0 && l0.z == 0 && l0.w == 0);
    ak_quat lm = ak_quat_log(ak_quat_make(0, 0, 0, -1));
    AK_CHECK_NEAR(lm.x, REF_PI, 1e-6);
    AK_CHECK(ak_quat_is_finite(ak_quat_exp(ak_quat_make(1, 2, 3, 1000.0f))));
    ak_quat en = ak_quat_exp(ak_quat_make(NAN, 0, 0, 0));
    AK_CHECK(en.w == 1.0f && en.x == 0.0f);
    ak_quat ln = ak_quat_log(ak_quat_make(INFINITY, 0, 0, 1));
    AK_CHECK(ak_quat_is_finite(ln));
}

/* ---- Euler angles ---------------------------------------------------------------------- */

static const int euler_axes[12][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0},
                                      {0, 1, 0}, {0, 2, 0}, {1, 0, 1}, {1, 2, 1}, {2, 0, 2}, {2, 1, 2}};
static const char* euler_names[12] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX",
                                      "XYX", "XZX", "YXY", "YZY", "ZXZ", "ZYZ"};

AK_TEST(euler_round_trip_all_orders) {
    ak_rng g = ak_rng_make(5);
    double worst_all = 0;
    for (int o = 0; o < 12; ++o)
        for (int f = 0; f < 2; ++f) {
            bool proper = o >= 6;
            double wm = 0, wq = 0, wa = 0, wqa = 0;
            for (int n = 0; n < CASES; ++n) {
                /* away from gimbal lock: the middle angle keeps 0.05 rad from it */
                double e[3] = {rand_range(&g, -REF_PI, REF_PI),
                               proper ? rand_range(&g, 0.05, REF_PI - 0.05) : rand_range(&g, -REF_PI / 2 + 0.05, REF_PI / 2 - 0.05),
                               rand_range(&g, -REF_PI, REF_PI)};
                ak_vec3 fe = ak_vec3_make((float)e[0], (float)e[1], (float)e[2]);
                double ed[3] = {fe.x, fe.y, fe.z};
                ref_m3 ref = ref_m3_euler(euler_axes[o], ed, f == 0);
                ak_euler_frame frame = f == 0 ? AK_EULER_INTRINSIC : AK_EULER_EXTRINSIC;
                wm = dmax(wm, m3_diff(ak_mat3_from_euler(fe, (ak_euler_order)o, frame), ref));
                ak_quat q = ak_quat_from_euler(fe, (ak_euler_order)o, frame);
                wq = dmax(wq, m3_diff(ak_mat3_from_quat(q), ref));
                ak_vec3 back = ak_mat3_to_euler(fm3(ref), (ak_euler_order)o, frame);
                ak_vec3 backq = ak_quat_to_euler(q, (ak_euler_order)o, frame);
                for (int k = 0; k < 3; ++k) {
                    double b = k == 0 ? back.x : k == 1 ? back.y : back.z;
                    double bq = k == 0 ? backq.x : k == 1 ? backq.y : backq.z;
                    wa = dmax(wa, fabs(wrap_angle(b - ed[k])));
                    wqa = dmax(wqa, fabs(wrap_angle(bq - ed[k])));
                }
                if (proper) AK_CHECK(back.y >= 0.0f && back.y <= AK_PI);
                else AK_CHECK(fabsf(back.y) <= AK_HALF_PI);
            }
            worst_all = dmax(worst_all, dmax(wa, wqa));
            AK_CHECK_MSG(wm <= 2e-6 && wq <= 2e-6 && wa <= 1e-4 && wqa <= 1e-4,
                         "order %s %s: matrix %.3g quat %.3g angles %.3g quat angles %.3g", euler_names[o],
                         f ? "extrinsic" : "intrinsic", wm, wq, wa, wqa);
        }
    printf("  euler: 24 order/frame pairs x %d cases, worst angle error %.3g rad\n", CASES, worst_all);
}

AK_TEST(euler_gimbal_lock) {
    ak_rng g = ak_rng_make(6);
    for (int o = 0; o < 12; ++o)
        for (int f = 0; f < 2; ++f) {
            bool proper = o >= 6;
            ak_euler_frame frame = f == 0 ? AK_EULER_INTRINSIC : AK_EULER_EXTRINSIC;
            double worst = 0;
            for (int n = 0; n < 2000; ++n) {
                double lock = proper ? (n % 2 ? REF_PI : 0.0) : (n % 2 ? REF_PI / 2 : -REF_PI / 2);
                double jitter = n % 4 < 2 ? 0.0 : rand_range(&g, -1e-7, 1e-7); /* at and next to it */
                double e[3] = {rand_range(&g, -REF_PI, REF_PI), lock + jitter, rand_range(&g, -REF_PI, REF_PI)};
                ref_m3 ref = ref_m3_euler(euler_axes[o], e, f == 0);
                ak_vec3 back = ak_mat3_to_euler(fm3(ref), (ak_euler_order)o, frame);
                ak_vec3 backq = ak_quat_to_euler(ak_quat_from_mat3(fm3(ref)), (ak_euler_order)o, frame);
                AK_CHECK(ak_vec3_is_finite(back) && ak_vec3_is_finite(backq));
                if (jitter == 0.0) AK_CHECK_MSG(back.z == 0.0f, "%s: third angle %g at gimbal lock", euler_names[o], back.z);
                double bd[3] = {back.x, back.y, back.z}, bqd[3] = {backq.x, backq.y, backq.z};
                worst = dmax(worst, m3_diff(fm3(ref_m3_euler(euler_axes[o], bd, f == 0)), ref));
                worst = dmax(worst, m3_diff(fm3(ref_m3_euler(euler_axes[o], bqd, f == 0)), ref));
            }
            AK_CHECK_MSG(worst <= 2e-5, "order %s frame %d: rebuilt matrix off by %.3g", euler_names[o], f, worst);
        }
}

AK_TEST(euler_known_values) {
    ref_m3 diag = {{{1, 0, 0}, {0, -1, 0}, {0, 0, -1}}};
    for (int f = 0; f < 2; ++f) {
        ak_euler_frame frame = (ak_euler_frame)f;
        ak_mat3 a = ak_mat3_from_euler(ak_vec3_make(AK_PI, 0, 0), AK_EULER_XYZ, frame);
        ak_mat3 b = ak_mat3_from_euler(ak_vec3_make(0, AK_PI, AK_PI), AK_EULER_XYZ, frame);
        AK_CHECK_NEAR(m3_diff(a, diag), 0.0, 1e-6);
        AK_CHECK_NEAR(m3_diff(b, diag), 0.0, 1e-6);
        AK_CHECK_NEAR(m3_diff(ak_mat3_from_quat(ak_quat_from_euler(ak_vec3_make(AK_PI, 0, 0), AK_EULER_XYZ, frame)), diag), 0.0, 1e-6);
        AK_CHECK_NEAR(m3_diff(ak_mat3_from_quat(ak_quat_from_euler(ak_vec3_make(0, AK_PI, AK_PI), AK_EULER_XYZ, frame)), diag), 0.0, 1e-6);
        /* decomposing diag(1,-1,-1) gives one of the two and it rebuilds the matrix */
        ak_vec3 e = ak_mat3_to_euler(fm3(diag), AK_EULER_XYZ, frame);
        AK_CHECK_NEAR(m3_diff(ak_mat3_from_euler(e, AK_EULER_XYZ, frame), diag), 0.0, 1e-6);
    }
    /* The zero values are the documented defaults; out-of-range values read as them. */
    AK_CHECK_EQ(AK_EULER_XYZ, 0);
    AK_CHECK_EQ(AK_EULER_INTRINSIC, 0);
    ak_vec3 ang = ak_vec3_make(0.3f, -0.7f, 1.1f);
    AK_CHECK_NEAR(m3_diff(ak_mat3_from_euler(ang, (ak_euler_order)99, (ak_euler_frame)7),
                          rm3(ak_mat3_from_euler(ang, AK_EULER_XYZ, AK_EULER_INTRINSIC))), 0.0, 0.0);
    /* Closed form: intrinsic XYZ R = Rx Ry Rz has R[0][2] = sin(b), R[1][2] = -sin(a)cos(b). */
    ak_mat3 m = ak_mat3_from_euler(ang, AK_EULER_XYZ, AK_EULER_INTRINSIC);
    AK_CHECK_NEAR(ak_mat3_at(&m, 0, 2), sin(-0.7), 1e-6);
    AK_CHECK_NEAR(ak_mat3_at(&m, 1, 2), -sin(0.3) * cos(-0.7), 1e-6);
    /* Intrinsic ABC (a, b, c) equals extrinsic CBA (c, b, a). */
    ak_mat3 ex = ak_mat3_from_euler(ak_vec3_make(1.1f, -0.7f, 0.3f), AK_EULER_ZYX, AK_EULER_EXTRINSIC);
    AK_CHECK_NEAR(m3_diff(ex, rm3(m)), 0.0, 1e-6);
    /* 90 degrees about X: +Y goes to +Z (right-handed). */
    ak_mat3 rx = ak_mat3_from_euler(ak_vec3_make(AK_HALF_PI, 0, 0), AK_EULER_XYZ, AK_EULER_INTRINSIC);
    AK_CHECK_NEAR(v3_diff(ak_mat3_mul_vec3(rx, ak_vec3_make(0, 1, 0)), ref_v3_make(0, 0, 1)), 0.0, 1e-6);
    /* Non-finite input: (0, 0, 0). */
    ak_mat3 bad = ak_mat3_identity();
    bad.m[4] = NAN;
    ak_vec3 z = ak_mat3_to_euler(bad, AK_EULER_ZYX, AK_EULER_EXTRINSIC);
    AK_CHECK(z.x == 0 && z.y == 0 && z.z == 0);
    z = ak_quat_to_euler(ak_quat_make(0, 0, 0, 0), AK_EULER_ZYX, AK_EULER_INTRINSIC);
    AK_CHECK(z.x == 0 && z.y == 0 && z.z == 0);
    AK_CHECK_NEAR(m3_diff(ak_mat3_from_euler(ak_vec3_make(0, NAN, 0), AK_EULER_XYZ, AK_EULER_INTRINSIC), ref_m3_identity()), 0.0, 0.0);
    AK_CHECK(ak_quat_from_euler(ak_vec3_make(INFINITY, 0, 0), AK_EULER_ZXZ, AK_EULER_EXTRINSIC).w == 1.0f);
}

/* ---- interpolation ------------------------------------------------------------------------ */

AK_TEST(slerp_properties) {
    ak_rng g = ak_rng_make(7);
    double w_end = 0, w_norm = 0, w_speed = 0, w_short = 0, w_total = 0;
    enum { STEPS = 8 };
    for (int n = 0; n < CASES; ++n) {
        ref_q a = rand_quat(&g), b = rand_quat(&g);
        if (n % 10 == 0) { /* small angles, down to the nlerp branch */
            ref_q d = ref_q_axis_angle(rand_dir(&g), rand_range(&g, 0.0, n % 20 ? 1e-2 : 1e-5));
            b = ref_q_mul(a, d);
        }
        ak_quat fa = fq(a), fb = fq(b);
        w_end = dmax(w_end, q_diff_sign(ak_quat_slerp(fa, fb, 0.0f), a));
        w_end = dmax(w_end, q_diff_sign(ak_quat_slerp(fa, fb, 1.0f), b));
        double total = ref_q_angle(rq(fa), rq(fb)); /* rotation angle, <= pi: the shorter arc */
        ref_q prev = rq(fa);
        double sum = 0.0;
        for (int k = 1; k <= STEPS; ++k) {
            ak_quat s = ak_quat_slerp(fa, fb, (float)k / STEPS);
            w_norm = dmax(w_norm, fabs(ak_quat_norm(s) - 1.0));
            double step = ref_q_angle(prev, rq(s));
            /* equal angles for equal steps: constant angular speed */
            w_speed = dmax(w_speed, fabs(step - total / STEPS));
            sum += step;
            prev = rq(s);
        }
        w_total = dmax(w_total, fabs(sum - total));
        /* shortest path: slerp towards -b is the same rotation as towards b */
        float t = ak_rng_float(&g);
        w_short = dmax(w_short, q_diff_sign(ak_quat_slerp(fa, ak_quat_neg(fb), t), rq(ak_quat_slerp(fa, fb, t))));
    }
    AK_CHECK_NEAR(w_end, 0.0, 1e-6);
    AK_CHECK_NEAR(w_norm, 0.0, 1e-6);
    AK_CHECK_NEAR(w_speed, 0.0, 1e-5);
    printf("  slerp: worst step-angle deviation %.3g rad, endpoint %.3g, norm %.3g\n", w_speed, w_end, w_norm);
    AK_CHECK_NEAR(w_total, 0.0, 1e-5);
    AK_CHECK_NEAR(w_short, 0.0, 1e-6);
}

AK_TEST(nlerp_properties) {
    ak_rng g = ak_rng_make(8);
    double w_norm = 0, w_short = 0, w_end = 0;
    for (int n = 0; n < CASES; ++n) {
        ak_quat a = fq(rand_quat(&g)), b = fq(rand_quat(&g));
        float t = ak_rng_float(&g);
        ak_quat r = ak_quat_nlerp(a, b, t);
        w_norm = dmax(w_norm, fabs(ak_quat_norm(r) - 1.0));
        w_short = dmax(w_short, q_diff_sign(ak_quat_nlerp(a, ak_quat_neg(b), t), rq(r)));
        w_end = dmax(w_end, q_diff_sign(ak_quat_nlerp(a, b, 1.0f), rq(b)));
        /* the shorter arc: the midpoint is at most 90 degrees of rotation from a */
        AK_CHECK(ref_q_angle(rq(a), rq(ak_quat_nlerp(a, b, 0.5f))) <= REF_PI / 2 + 1e-5);
    }
    AK_CHECK_NEAR(w_norm, 0.0, 1e-6);
    AK_CHECK_NEAR(w_short, 0.0, 1e-6);
    AK_CHECK_NEAR(w_end, 0.0, 1e-6);
}

AK_TEST(quat_edge_cases) {
    ak_rng g = ak_rng_make(9);
    for (int n = 0; n < 1000; ++n) {
        ak_quat a = fq(rand_quat(&g));
        float t = ak_rng_float(&g);
        /* identical */
        AK_CHECK(q_diff_sign(ak_quat_slerp(a, a, t), rq(a)) <= 1e-6);
        /* antipodal: the same rotation, so every t gives it back */
        ak_quat s = ak_quat_slerp(a, ak_quat_neg(a), t);
        AK_CHECK(ak_quat_is_finite(s) && q_diff_sign(s, rq(a)) <= 1e-6);
        AK_CHECK(q_diff_sign(ak_quat_nlerp(a, ak_quat_neg(a), t), rq(a)) <= 1e-6);
        /* 180 degrees apart as rotations (dot = 0) */
        ak_quat b = ak_quat_mul(a, ak_quat_from_axis_angle(fv(rand_dir(&g)), AK_PI));
        ak_quat m = ak_quat_slerp(a, b, 0.5f);
        AK_CHECK(ak_quat_is_finite(m) && fabs(ak_quat_norm(m) - 1.0) < 1e-6);
        AK_CHECK_NEAR(ref_q_angle(rq(a), rq(m)), REF_PI / 2, 1e-5);
    }
    /* zero and non-finite inputs */
    ak_vec3 z = ak_vec3_normalize(ak_vec3_zero());
    AK_CHECK(z.x == 0 && z.y == 0 && z.z == 0);
    AK_CHECK(ak_vec3_length(ak_vec3_normalize(ak_vec3_make(NAN, 1, 0))) == 0.0f);
    ak_quat qi = ak_quat_normalize(ak_quat_make(0, 0, 0, 0));
    AK_CHECK(qi.w == 1 && qi.x == 0);
    qi = ak_quat_normalize(ak_quat_make(NAN, 0, 0, 1));
    AK_CHECK(qi.w == 1 && qi.x == 0);
    qi = ak_quat_inverse(ak_quat_make(0, 0, 0, 0));
    AK_CHECK(qi.w == 1);
    AK_CHECK(ak_quat_is_finite(ak_quat_slerp(ak_quat_make(0, 0, 0, 0), ak_quat_identity(), 0.5f)));
    ak_vec3 ax;
    float an;
    ak_quat_to_axis_angle(ak_quat_identity(), &ax, &an);
    AK_CHECK(an == 0.0f && ax.x == 1.0f);
    AK_CHECK_NEAR(ak_vec3_length(ak_vec3_any_perpendicular(ak_vec3_zero())), 1.0, 1e-6);
}

AK_TEST(quat_from_to) {
    ak_rng g = ak_rng_make(10);
    double worst = 0, worst_angle = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_v3 a = rand_dir(&g), b = rand_dir(&g);
        if (n % 4 == 1) { /* nearly opposite, down to float resolution */
            double eps = pow(10.0, -rand_range(&g, 1.0, 7.0));
            b = ref_v3_scale(ref_v3_add(ref_v3_scale(a, -1.0), ref_v3_scale(rand_dir(&g), eps)), 1.0);
            b = ref_v3_scale(b, 1.0 / ref_v3_len(b));
        } else if (n % 4 == 2) { /* nearly parallel */
            b = ref_v3_add(a, ref_v3_scale(rand_dir(&g), 1e-4));
            b = ref_v3_scale(b, 1.0 / ref_v3_len(b));
        }
        ak_vec3 fa = ak_vec3_scale(fv(a), 3.0f), fb = ak_vec3_scale(fv(b), 0.5f); /* any length */
        ak_quat q = ak_quat_from_to(fa, fb);
        ref_v3 an = rv(ak_vec3_normalize(fa)), bn = rv(ak_vec3_normalize(fb));
        worst = dmax(worst, v3_diff(ak_quat_rotate(q, fv(an)), bn));
        /* shortest: the rotation angle equals the angle between the vectors */
        double want = atan2(ref_v3_len(ref_v3_cross(an, bn)), ref_v3_dot(an, bn));
        worst_angle = dmax(worst_angle, fabs(ref_q_angle((ref_q){0, 0, 0, 1}, rq(q)) - want));
    }
    AK_CHECK_NEAR(worst, 0.0, 2e-6);
    AK_CHECK_NEAR(worst_angle, 0.0, 1e-5);
    /* exactly opposite and zero vectors */
    for (int ax = 0; ax < 3; ++ax) {
        ak_vec3 v = ak_vec3_make(ax == 0, ax == 1, ax == 2);
        ak_quat q = ak_quat_from_to(v, ak_vec3_neg(v));
        AK_CHECK(v3_diff(ak_quat_rotate(q, v), rv(ak_vec3_neg(v))) <= 1e-6);
    }
    ak_quat q0 = ak_quat_from_to(ak_vec3_zero(), ak_vec3_make(1, 0, 0));
    AK_CHECK(q0.w == 1.0f);
}

AK_TEST(shepperd_180_degrees) {
    /* The trace-only formula divides by ~0 here; Shepperd's method must not. */
    for (int ax = 0; ax < 3; ++ax) {
        ref_v3 axis = {ax == 0, ax == 1, ax == 2};
        ref_m3 r = ref_m3_axis_angle(axis, REF_PI);
        ak_quat q = ak_quat_from_mat3(fm3(r));
        AK_CHECK(ak_quat_is_finite(q));
        AK_CHECK_NEAR(q_diff_sign(q, (ref_q){axis.x, axis.y, axis.z, 0.0}), 0.0, 1e-6);
    }
    ak_rng g = ak_rng_make(11);
    double worst = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_v3 axis = rand_dir(&g);
        double angle = n % 2 ? REF_PI : REF_PI - rand_range(&g, 0.0, 1e-2);
        ref_m3 r = ref_m3_axis_angle(axis, angle);
        ak_quat q = ak_quat_from_mat3(fm3(r));
        worst = dmax(worst, q_diff_sign(q, ref_q_axis_angle(axis, angle)));
        worst = dmax(worst, m3_diff(ak_mat3_from_quat(q), r));
    }
    AK_CHECK_NEAR(worst, 0.0, 2e-6);
}

/* ---- decompositions ----------------------------------------------------------------------- */

/* Checks R D = M, R a rotation, D symmetric and (for det M >= 0) PSD. */
static void check_polar(ak_mat3 m, ak_polar p, double* w_rd, double* w_orth, double* w_sym, double* w_psd) {
    ref_m3 rm = rm3(m);
    double sc = dmax(m3_scale(rm), 1e-30);
    ref_m3 prod = ref_m3_mul(rm3(p.rotation), rm3(p.stretch));
    double e = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) e = dmax(e, fabs(prod.m[i][j] - rm.m[i][j]) / sc);
    *w_rd = dmax(*w_rd, e);
    *w_orth = dmax(*w_orth, dmax(orth_err(p.rotation), fabs(ref_m3_det(rm3(p.rotation)) - 1.0)));
    ref_m3 d = rm3(p.stretch);
    double s = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) s = dmax(s, fabs(d.m[i][j] - d.m[j][i]) / sc);
    *w_sym = dmax(*w_sym, s);
    /* eigenvalues of D (symmetrised in double) are the singular values, the smallest one
     * negated for det M < 0 */
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j) d.m[i][j] = d.m[j][i] = 0.5 * (d.m[i][j] + d.m[j][i]);
    double ev[3];
    ref_sym3_eigenvalues(d, ev);
    double detm = ref_m3_det(rm);
    if (detm >= 0) *w_psd = dmax(*w_psd, -ev[0] / sc);
    else *w_psd = dmax(*w_psd, ev[1] < -1e-5 * sc ? 1.0 : 0.0); /* only one negative eigenvalue */
}

AK_TEST(polar_properties) {
    ak_rng g = ak_rng_make(12);
    double w_rd = 0, w_orth = 0, w_sym = 0, w_psd = 0, w_uniq = 0;
    int newton = 0, svd = 0, max_iter = 0;
    for (int n = 0; n < CASES; ++n) {
        ak_mat3 m;
        ref_m3 rot = ref_m3_from_q(rand_quat(&g)), s = ref_m3_identity();
        int kind = n % 4;
        if (kind == 0) { /* any matrix, either sign of det */
            for (int i = 0; i < 9; ++i) m.m[i] = (float)rand_range(&g, -2.0, 2.0);
        } else { /* rotation * SPD stretch with condition number up to 1e3 (or near-singular) */
            ref_m3 v = ref_m3_from_q(rand_quat(&g));
            double sv[3] = {rand_range(&g, 0.5, 2.0), exp(rand_range(&g, -3.0, 1.0)),
                            kind == 3 ? rand_range(&g, 0.0, 1e-6) : exp(rand_range(&g, -6.9, 0.5))};
            for (int i = 0; i < 3; ++i)
                for (int j = 0; j < 3; ++j)
                    s.m[i][j] = v.m[i][0] * sv[0] * v.m[j][0] + v.m[i][1] * sv[1] * v.m[j][1] + v.m[i][2] * sv[2] * v.m[j][2];
            m = fm3(ref_m3_mul(rot, s));
        }
        ak_polar p = ak_mat3_polar(m);
        check_polar(m, p, &w_rd, &w_orth, &w_sym, &w_psd);
        if (kind == 1 || kind == 2) /* nonsingular: the polar factors are unique */
            w_uniq = dmax(w_uniq, dmax(m3_diff(p.rotation, rot), m3_diff(p.stretch, s) / m3_scale(s)));
        if (p.used_svd) ++svd;
        else ++newton, max_iter = p.iterations > max_iter ? p.iterations : max_iter;
    }
    printf("  polar: |RD-M|/|M| %.3g, orthonormality %.3g, asymmetry %.3g, negative eigenvalue %.3g; "
           "%d averaging (max %d iterations), %d SVD\n", w_rd, w_orth, w_sym, w_psd, newton, max_iter, svd);
    AK_CHECK_NEAR(w_rd, 0.0, 2e-6);
    AK_CHECK_NEAR(w_orth, 0.0, 1e-6);
    AK_CHECK_NEAR(w_sym, 0.0, 1e-6);
    AK_CHECK_NEAR(w_psd, 0.0, 1e-6);
    AK_CHECK_NEAR(w_uniq, 0.0, 2e-3); /* float input with condition up to 1e3 */
    AK_CHECK(newton > CASES / 3 && svd > CASES / 4);
    AK_CHECK(max_iter >= 2 && max_iter <= 12);
}

AK_TEST(polar_edge_cases) {
    double w_rd = 0, w_orth = 0, w_sym = 0, w_psd = 0;
    /* zero matrix: R = I, D = 0 */
    ak_polar p = ak_mat3_polar(ak_mat3_scale(ak_mat3_identity(), 0.0f));
    AK_CHECK_NEAR(m3_diff(p.rotation, ref_m3_identity()), 0.0, 0.0);
    AK_CHECK_NEAR(m3_diff(p.stretch, (ref_m3){{{0}}}), 0.0, 0.0);
    /* non-finite: R = D = I */
    ak_mat3 bad = ak_mat3_identity();
    bad.m[3] = INFINITY;
    p = ak_mat3_polar(bad);
    AK_CHECK(m3_finite(p.rotation) && m3_finite(p.stretch));
    AK_CHECK_NEAR(m3_diff(p.stretch, ref_m3_identity()), 0.0, 0.0);
    /* a mirror: R proper, D = diag(1,1,-1) carries the reflection */
    p = ak_mat3_polar(ak_mat3_diagonal(ak_vec3_make(1, 1, -1)));
    AK_CHECK(p.used_svd);
    AK_CHECK_NEAR(ref_m3_det(rm3(p.rotation)), 1.0, 1e-6);
    check_polar(ak_mat3_diagonal(ak_vec3_make(1, 1, -1)), p, &w_rd, &w_orth, &w_sym, &w_psd);
    /* the negative eigen-direction is the one of the smallest singular value */
    ak_mat3 refl = ak_mat3_diagonal(ak_vec3_make(3, -0.5f, 2));
    p = ak_mat3_polar(refl);
    check_polar(refl, p, &w_rd, &w_orth, &w_sym, &w_psd);
    AK_CHECK_NEAR(p.stretch.m[4], -0.5, 1e-6);
    /* point reflection -I */
    ak_mat3 neg = ak_mat3_scale(ak_mat3_identity(), -1.0f);
    check_polar(neg, ak_mat3_polar(neg), &w_rd, &w_orth, &w_sym, &w_psd);
    /* rank 2, rank 1, tiny and huge scales, random singular matrices */
    ak_rng g = ak_rng_make(13);
    for (int n = 0; n < 3000; ++n) {
        ref_v3 a = rand_dir(&g), b = rand_dir(&g), c = rand_dir(&g), d = rand_dir(&g);
        ref_m3 r;
        int rank = 1 + n % 2;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                double ai = i == 0 ? a.x : i == 1 ? a.y : a.z, bj = j == 0 ? b.x : j == 1 ? b.y : b.z;
                double ci = i == 0 ? c.x : i == 1 ? c.y : c.z, dj = j == 0 ? d.x : j == 1 ? d.y : d.z;
                r.m[i][j] = ai * bj + (rank == 2 ? 0.5 * ci * dj : 0.0);
            }
        double k = n % 3 == 0 ? 1e-20 : n % 3 == 1 ? 1e20 : 1.0;
        ak_mat3 m = fm3(r);
        m = ak_mat3_scale(m, (float)k);
        ak_polar q = ak_mat3_polar(m);
        AK_CHECK(m3_finite(q.rotation) && m3_finite(q.stretch));
        check_polar(m, q, &w_rd, &w_orth, &w_sym, &w_psd);
    }
    AK_CHECK_NEAR(w_rd, 0.0, 2e-6);
    AK_CHECK_NEAR(w_orth, 0.0, 1e-6);
    AK_CHECK_NEAR(w_sym, 0.0, 1e-6);
    AK_CHECK_NEAR(w_psd, 0.0, 1e-6);
}

AK_TEST(svd_properties) {
    ak_rng g = ak_rng_make(14);
    double w_rec = 0, w_orth = 0;
    for (int n = 0; n < CASES; ++n) {
        ak_mat3 m;
        for (int i = 0; i < 9; ++i) m.m[i] = (float)rand_range(&g, -1.0, 1.0);
        if (n % 5 == 0) m.m[2] = m.m[0] + m.m[1], m.m[5] = m.m[3] + m.m[4], m.m[8] = m.m[6] + m.m[7]; /* rank 2 */
        ak_svd3 s = ak_mat3_svd(m);
        ref_m3 sig = {{{s.sigma.x, 0, 0}, {0, s.sigma.y, 0}, {0, 0, s.sigma.z}}};
        ref_m3 rec = ref_m3_mul(ref_m3_mul(rm3(s.u), sig), ref_m3_transpose(rm3(s.v)));
        w_rec = dmax(w_rec, m3_diff(m, rec));
        w_orth = dmax(w_orth, dmax(orth_err(s.u), orth_err(s.v)));
        AK_CHECK(fabs(ref_m3_det(rm3(s.u)) - 1.0) < 1e-5 && fabs(ref_m3_det(rm3(s.v)) - 1.0) < 1e-5);
        AK_CHECK(s.sigma.x >= s.sigma.y && s.sigma.y >= fabsf(s.sigma.z));
        double det = ref_m3_det(rm3(m));
        if (fabs(det) > 1e-4) AK_CHECK((s.sigma.z < 0) == (det < 0));
    }
    AK_CHECK_NEAR(w_rec, 0.0, 2e-6);
    AK_CHECK_NEAR(w_orth, 0.0, 1e-6);
    ak_svd3 z = ak_mat3_svd(ak_mat3_scale(ak_mat3_identity(), 0.0f));
    AK_CHECK(z.sigma.x == 0 && m3_diff(z.u, ref_m3_identity()) == 0.0);
}

/* ---- dual quaternions ---------------------------------------------------------------------- */

AK_TEST(dualquat_matches_matrices) {
    ak_rng g = ak_rng_make(15);
    double w_pt = 0, w_vec = 0, w_mat = 0, w_mul = 0, w_rt = 0, w_inv = 0, w_sand = 0, w_norm = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_q q1 = rand_quat(&g), q2 = rand_quat(&g);
        ref_v3 t1 = ref_v3_scale(rand_dir(&g), rand_range(&g, 0, 10)), t2 = ref_v3_scale(rand_dir(&g), rand_range(&g, 0, 10));
        ref_v3 p = ref_v3_scale(rand_dir(&g), rand_range(&g, 0, 10));
        ak_dualquat d1 = ak_dualquat_from_rigid(fq(q1), fv(t1)), d2 = ak_dualquat_from_rigid(fq(q2), fv(t2));
        /* point: R p + t against the reference matrix */
        ref_v3 want = ref_v3_add(ref_m3_apply(ref_m3_from_q(q1), p), t1);
        w_pt = dmax(w_pt, v3_diff(ak_dualquat_transform_point(d1, fv(p)), want) / 10.0);
        w_vec = dmax(w_vec, v3_diff(ak_dualquat_transform_vector(d1, fv(p)), ref_m3_apply(ref_m3_from_q(q1), p)) / 10.0);
        ak_mat4 m = ak_dualquat_to_mat4(d1);
        w_mat = dmax(w_mat, v3_diff(ak_mat4_transform_point(m, fv(p)), want) / 10.0);
        /* the same as the TRS matrix with unit scale */
        ak_mat4 trs = ak_transform_to_mat4(ak_transform_make(fv(t1), fq(q1), ak_vec3_one()));
        w_mat = dmax(w_mat, v3_diff(ak_mat4_transform_point(trs, fv(p)), want) / 10.0);
        /* product: d1 d2 applies d2 first */
        ref_v3 want2 = ref_v3_add(ref_m3_apply(ref_m3_from_q(q1), ref_v3_add(ref_m3_apply(ref_m3_from_q(q2), p), t2)), t1);
        w_mul = dmax(w_mul, v3_diff(ak_dualquat_transform_point(ak_dualquat_mul(d1, d2), fv(p)), want2) / 20.0);
        /* round trip of the parts */
        w_rt = dmax(w_rt, dmax(v3_diff(ak_dualquat_get_translation(d1), t1) / 10.0, q_diff_sign(ak_dualquat_get_rotation(d1), q1)));
        ak_transform tr = ak_dualquat_to_transform(ak_dualquat_from_transform(ak_transform_make(fv(t1), fq(q1), ak_vec3_splat(3))));
        w_rt = dmax(w_rt, dmax(v3_diff(tr.translation, t1) / 10.0, v3_diff(tr.scale, ref_v3_make(1, 1, 1))));
        /* the conjugate of a unit dual quaternion is its inverse */
        ak_dualquat id = ak_dualquat_mul(d1, ak_dualquat_conjugate(d1));
        w_inv = dmax(w_inv, dmax(q_diff_sign(id.real, (ref_q){0, 0, 0, 1}), q_diff_sign(id.dual, (ref_q){0, 0, 0, 0}) / 10.0));
        /* sandwich with the full conjugate: d (1 + eps p) d_bar = 1 + eps (R p + t) */
        ak_dualquat dp = {ak_quat_identity(), ak_quat_make((float)p.x, (float)p.y, (float)p.z, 0.0f)};
        ak_dualquat sw = ak_dualquat_mul(ak_dualquat_mul(d1, dp), ak_dualquat_full_conjugate(d1));
        w_sand = dmax(w_sand, v3_diff(ak_vec3_make(sw.dual.x, sw.dual.y, sw.dual.z), want) / 10.0);
        w_sand = dmax(w_sand, q_diff_sign(sw.real, (ref_q){0, 0, 0, 1}));
        /* dual conjugate: (r, -d) is the rotation followed by -t */
        ak_dualquat dc = ak_dualquat_dual_conjugate(d1);
        w_sand = dmax(w_sand, v3_diff(ak_dualquat_get_translation(dc), ref_v3_scale(t1, -1.0)) / 10.0);
        /* normalize: a scaled, slightly non-unit dq gives back the unit one */
        float k = (float)rand_range(&g, 0.2, 5.0);
        ak_dualquat sc = {ak_quat_scale(d1.real, k), ak_quat_add(ak_quat_scale(d1.dual, k), ak_quat_scale(d1.real, 1e-3f))};
        ak_dualquat nd = ak_dualquat_normalize(sc);
        w_norm = dmax(w_norm, dmax(fabs(ak_quat_norm(nd.real) - 1.0), fabs(ak_quat_dot(nd.real, nd.dual))));
        w_norm = dmax(w_norm, v3_diff(ak_dualquat_transform_point(nd, fv(p)), want) / 10.0);
    }
    AK_CHECK_NEAR(w_pt, 0.0, 2e-6);
    AK_CHECK_NEAR(w_vec, 0.0, 2e-6);
    AK_CHECK_NEAR(w_mat, 0.0, 2e-6);
    AK_CHECK_NEAR(w_mul, 0.0, 2e-6);
    AK_CHECK_NEAR(w_rt, 0.0, 2e-6);
    AK_CHECK_NEAR(w_inv, 0.0, 2e-6);
    AK_CHECK_NEAR(w_sand, 0.0, 2e-6);
    AK_CHECK_NEAR(w_norm, 0.0, 2e-6);
    /* degenerate normalise: identity */
    ak_dualquat z = {{0, 0, 0, 0}, {1, 2, 3, 4}};
    ak_dualquat zn = ak_dualquat_normalize(z);
    AK_CHECK(zn.real.w == 1.0f && zn.dual.x == 0.0f);
    AK_CHECK(v3_diff(ak_dualquat_get_translation(z), ref_v3_make(0, 0, 0)) == 0.0);
}

AK_TEST(dualquat_blend) {
    ak_rng g = ak_rng_make(16);
    double w_same = 0, w_trans = 0, w_hemi = 0, w_unit = 0, w_nlerp = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_q q = rand_quat(&g);
        ref_v3 ta = ref_v3_scale(rand_dir(&g), 5), tb = ref_v3_scale(rand_dir(&g), 5);
        ak_dualquat a = ak_dualquat_from_rigid(fq(q), fv(ta)), b = ak_dualquat_from_rigid(fq(q), fv(tb));
        float w = ak_rng_float(&g);
        /* the same rotation: the blend lerps the translation */
        ak_dualquat ds[2] = {a, b};
        float ws[2] = {1.0f - w, w};
        ak_dualquat r = ak_dualquat_blend((ak_dualquat_cspan){ds, 2}, (ak_f32_cspan){ws, 2});
        ref_v3 tl = ref_v3_add(ref_v3_scale(ta, 1.0 - w), ref_v3_scale(tb, w));
        w_trans = dmax(w_trans, dmax(v3_diff(ak_dualquat_get_translation(r), tl) / 5.0, q_diff_sign(r.real, q)));
        /* one weight: that dual quaternion */
        float w1[2] = {0.0f, 2.0f};
        w_same = dmax(w_same, q_diff_sign(ak_dualquat_blend((ak_dualquat_cspan){ds, 2}, (ak_f32_cspan){w1, 2}).dual, rq(b.dual)));
        /* hemisphere: -a is the same transform as a, so blending a with -a gives a */
        ak_dualquat na = {ak_quat_neg(a.real), ak_quat_neg(a.dual)};
        ak_dualquat hs[2] = {a, na};
        ak_dualquat h = ak_dualquat_blend((ak_dualquat_cspan){hs, 2}, (ak_f32_cspan){ws, 2});
        w_hemi = dmax(w_hemi, v3_diff(ak_dualquat_transform_point(h, ak_vec3_make(1, 2, 3)),
                                      rv(ak_dualquat_transform_point(a, ak_vec3_make(1, 2, 3)))) / 5.0);
        /* four random transforms: a unit result */
        ak_dualquat four[4];
        float w4[4];
        for (int k = 0; k < 4; ++k) {
            four[k] = ak_dualquat_from_rigid(fq(rand_quat(&g)), fv(ref_v3_scale(rand_dir(&g), 3)));
            w4[k] = ak_rng_float(&g) + 0.01f;
        }
        ak_dualquat u = ak_dualquat_blend((ak_dualquat_cspan){four, 4}, (ak_f32_cspan){w4, 4});
        w_unit = dmax(w_unit, dmax(fabs(ak_quat_norm(u.real) - 1.0), fabs(ak_quat_dot(u.real, u.dual))));
        /* zero translation: the rotation part is the nlerp of the rotations */
        ak_quat r1 = fq(rand_quat(&g)), r2 = fq(rand_quat(&g));
        ak_dualquat rs[2] = {ak_dualquat_from_rigid(r1, ak_vec3_zero()), ak_dualquat_from_rigid(r2, ak_vec3_zero())};
        float wr[2] = {0.5f, 0.5f};
        ak_dualquat rb = ak_dualquat_blend((ak_dualquat_cspan){rs, 2}, (ak_f32_cspan){wr, 2});
        w_nlerp = dmax(w_nlerp, q_diff_sign(rb.real, rq(ak_quat_nlerp(r1, r2, 0.5f))));
    }
    AK_CHECK_NEAR(w_trans, 0.0, 2e-6);
    AK_CHECK_NEAR(w_same, 0.0, 1e-6);
    AK_CHECK_NEAR(w_hemi, 0.0, 2e-6);
    AK_CHECK_NEAR(w_unit, 0.0, 2e-6);
    AK_CHECK_NEAR(w_nlerp, 0.0, 1e-6);
    /* empty, zero weights: identity */
    ak_dualquat one = ak_dualquat_from_rigid(ak_quat_identity(), ak_vec3_make(1, 0, 0));
    float zw = 0.0f;
    ak_dualquat e = ak_dualquat_blend((ak_dualquat_cspan){&one, 1}, (ak_f32_cspan){&zw, 1});
    AK_CHECK(e.real.w == 1.0f && e.dual.x == 0.0f);
    e = ak_dualquat_blend((ak_dualquat_cspan){NULL, 0}, (ak_f32_cspan){NULL, 0});
    AK_CHECK(e.real.w == 1.0f);
}

/* ---- affine interpolation ------------------------------------------------------------------ */

static double m4_diff(ak_mat4 a, ak_mat4 b) {
    double d = 0.0;
    for (int i = 0; i < 16; ++i) d = dmax(d, fabs(a.m[i] - b.m[i]));
    return d;
}

AK_TEST(affine_interpolation) {
    ak_rng g = ak_rng_make(17);
    double w_end = 0, w_rot = 0, w_tr = 0, w_sc = 0;
    for (int n = 0; n < CASES; ++n) {
        ak_mat4 a = ak_mat4_identity(), b = ak_mat4_identity();
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 3; ++r) {
                a.m[c * 4 + r] = (float)rand_range(&g, -2, 2);
                b.m[c * 4 + r] = (float)rand_range(&g, -2, 2);
            }
        /* endpoints (relative to the matrix size) */
        w_end = dmax(w_end, m4_diff(ak_mat4_interpolate_affine(a, b, 0.0f), a) / 4.0);
        w_end = dmax(w_end, m4_diff(ak_mat4_interpolate_affine(a, b, 1.0f), b) / 4.0);
        /* pure rotations interpolate like slerp */
        ak_quat qa = fq(rand_quat(&g)), qb = fq(rand_quat(&g));
        float t = ak_rng_float(&g);
        ak_mat4 r = ak_mat4_interpolate_affine(ak_mat4_from_quat(qa), ak_mat4_from_quat(qb), t);
        w_rot = dmax(w_rot, m4_diff(r, ak_mat4_from_quat(ak_quat_slerp(qa, qb, t))));
        /* shared rotation and uniform scale, different translations: translation lerps */
        ref_v3 ta = ref_v3_scale(rand_dir(&g), 4), tb = ref_v3_scale(rand_dir(&g), 4);
        ak_mat4 ma = ak_transform_to_mat4(ak_transform_make(fv(ta), qa, ak_vec3_splat(2)));
        ak_mat4 mb = ak_transform_to_mat4(ak_transform_make(fv(tb), qa, ak_vec3_splat(2)));
        ak_mat4 mt = ak_mat4_interpolate_affine(ma, mb, t);
        w_tr = dmax(w_tr, v3_diff(ak_mat4_get_translation(mt), ref_v3_add(ref_v3_scale(ta, 1 - t), ref_v3_scale(tb, t))) / 4.0);
        w_tr = dmax(w_tr, m3_diff(ak_mat4_to_mat3(mt), rm3(ak_mat4_to_mat3(ma))) / 2.0);
        /* non-uniform scales under one rotation: D lerps, so scales lerp */
        ak_vec3 sa = ak_vec3_make((float)rand_range(&g, 0.1, 3), (float)rand_range(&g, 0.1, 3), (float)rand_range(&g, 0.1, 3));
        ak_vec3 sb = ak_vec3_make((float)rand_range(&g, 0.1, 3), (float)rand_range(&g, 0.1, 3), (float)rand_range(&g, 0.1, 3));
        ak_mat4 ms = ak_mat4_interpolate_affine(ak_transform_to_mat4(ak_transform_make(ak_vec3_zero(), qb, sa)),
                                                ak_transform_to_mat4(ak_transform_make(ak_vec3_zero(), qb, sb)), t);
        ak_mat4 want = ak_transform_to_mat4(ak_transform_make(ak_vec3_zero(), qb, ak_vec3_lerp(sa, sb, t)));
        w_sc = dmax(w_sc, m4_diff(ms, want) / 3.0);
    }
    AK_CHECK_NEAR(w_end, 0.0, 3e-6);
    AK_CHECK_NEAR(w_rot, 0.0, 2e-6);
    AK_CHECK_NEAR(w_tr, 0.0, 2e-6);
    AK_CHECK_NEAR(w_sc, 0.0, 3e-6);
    /* reflected, singular and non-finite endpoints stay finite */
    ak_mat4 refl = ak_mat4_scaling(ak_vec3_make(-1, 1, 1)), sing = ak_mat4_scaling(ak_vec3_make(1, 0, 1));
    ak_mat4 nan = ak_mat4_identity();
    nan.m[5] = NAN;
    for (int k = 0; k <= 4; ++k) {
        float t = k / 4.0f;
        ak_mat4 r1 = ak_mat4_interpolate_affine(refl, ak_mat4_identity(), t);
        ak_mat4 r2 = ak_mat4_interpolate_affine(sing, refl, t);
        AK_CHECK(ak_mat4_is_finite(&r1) && ak_mat4_is_finite(&r2));
    }
    AK_CHECK_NEAR(m4_diff(ak_mat4_interpolate_affine(refl, refl, 0.3f), refl), 0.0, 1e-6);
    AK_CHECK_NEAR(m4_diff(ak_mat4_interpolate_affine(nan, refl, 0.3f), ak_mat4_identity()), 0.0, 0.0);
}

/* ---- matrices, projections, transforms ---------------------------------------------------- */

AK_TEST(mat4_inverse) {
    ak_rng g = ak_rng_make(18);
    double w_inv = 0, w_aff = 0, w_det = 0, w_nrm = 0;
    for (int n = 0; n < CASES; ++n) {
        ak_mat4 m;
        for (int i = 0; i < 16; ++i) m.m[i] = (float)rand_range(&g, -1, 1);
        for (int i = 0; i < 4; ++i) m.m[i * 5] += 3.0f; /* diagonally dominant: well conditioned */
        ref_m4 ri = {{{0}}};
        AK_CHECK(ref_m4_inverse(rm4(m), &ri));
        ak_mat4 inv = ak_mat4_inverse(m);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) w_inv = dmax(w_inv, fabs(inv.m[c * 4 + r] - ri.m[r][c]));
        double det = ref_m4_det(rm4(m));
        w_det = dmax(w_det, fabs(ak_mat4_determinant(m) - det) / fabs(det));
        /* affine: bottom row 0 0 0 1 */
        m.m[3] = m.m[7] = m.m[11] = 0.0f, m.m[15] = 1.0f;
        AK_CHECK(ref_m4_inverse(rm4(m), &ri));
        ak_mat4 ai = ak_mat4_inverse_affine(m);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) w_aff = dmax(w_aff, fabs(ai.m[c * 4 + r] - ri.m[r][c]));
        /* normal matrix = inverse transpose of the upper 3x3 */
        ak_mat3 nm = ak_mat4_normal_matrix(m);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) w_nrm = dmax(w_nrm, fabs(nm.m[c * 3 + r] - ri.m[c][r]));
    }
    AK_CHECK_NEAR(w_inv, 0.0, 1e-6);
    AK_CHECK_NEAR(w_aff, 0.0, 1e-6);
    AK_CHECK_NEAR(w_det, 0.0, 1e-5);
    AK_CHECK_NEAR(w_nrm, 0.0, 1e-6);
    /* singular: identity */
    ak_mat4 s = ak_mat4_scaling(ak_vec3_make(1, 0, 1));
    AK_CHECK_NEAR(m4_diff(ak_mat4_inverse(s), ak_mat4_identity()), 0.0, 0.0);
    AK_CHECK_NEAR(m4_diff(ak_mat4_inverse_affine(s), ak_mat4_identity()), 0.0, 0.0);
    ak_mat4 inf = ak_mat4_identity();
    inf.m[12] = INFINITY;
    AK_CHECK_NEAR(m4_diff(ak_mat4_inverse(inf), ak_mat4_identity()), 0.0, 0.0);
    inf.m[12] = 0.0f, inf.m[5] = NAN;
    AK_CHECK_NEAR(m4_diff(ak_mat4_inverse(inf), ak_mat4_identity()), 0.0, 0.0);
    AK_CHECK_NEAR(m4_diff(ak_mat4_inverse_affine(inf), ak_mat4_identity()), 0.0, 0.0);
    /* a determinant that overflows float is documented as the identity too */
    AK_CHECK_NEAR(m4_diff(ak_mat4_inverse(ak_mat4_scaling(ak_vec3_splat(1e20f))), ak_mat4_identity()), 0.0, 0.0);
    ak_mat3 nm = ak_mat4_normal_matrix(s);
    AK_CHECK(m3_finite(nm));
    ak_mat3 m3s = ak_mat3_diagonal(ak_vec3_make(0, 1, 1));
    AK_CHECK_NEAR(m3_diff(ak_mat3_inverse(m3s), ref_m3_identity()), 0.0, 0.0);
}

AK_TEST(perspective_closed_form) {
    ak_rng g = ak_rng_make(19);
    for (int n = 0; n < CASES; ++n) {
        double fovy = rand_range(&g, 0.1, 3.0), aspect = rand_range(&g, 0.3, 3.0);
        double nz = rand_range(&g, 0.01, 1.0), fz = nz + rand_range(&g, 1.0, 1000.0);
        ak_mat4 m = ak_mat4_perspective((float)fovy, (float)aspect, (float)nz, (float)fz);
        double f = 1.0 / tan(fovy / 2), C = (fz + nz) / (nz - fz), D = 2 * fz * nz / (nz - fz);
        double want[4][4] = {{f / aspect, 0, 0, 0}, {0, f, 0, 0}, {0, 0, C, D}, {0, 0, -1, 0}};
        double e = 0;
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) e = dmax(e, fabs(ak_mat4_at(&m, r, c) - want[r][c]) / dmax(1.0, fabs(want[r][c])));
        AK_CHECK_MSG(e < 2e-6, "perspective off by %g", e);
        if (n < 100) { /* near plane -> NDC z = -1, far plane -> +1 */
            AK_CHECK_NEAR(ak_mat4_project_point(m, ak_vec3_make(0, 0, (float)-nz)).z, -1.0, 1e-4);
            AK_CHECK_NEAR(ak_mat4_project_point(m, ak_vec3_make(0, 0, (float)-fz)).z, 1.0, 1e-3);
        }
    }
    /* invalid inputs fall back to finite documented defaults (60 degrees, 1, 0.1, 100) */
    ak_mat4 d = ak_mat4_perspective(NAN, -1.0f, 0.0f, -5.0f);
    AK_CHECK(ak_mat4_is_finite(&d));
    AK_CHECK_NEAR(d.m[5], 1.0 / tan(REF_PI / 6), 1e-5);
    AK_CHECK_NEAR(d.m[0], d.m[5], 1e-6);
    AK_CHECK_NEAR(d.m[14], 2 * 100.0 * 0.1 / (0.1 - 100.0), 1e-5);
    /* orthographic: the box corners go to the NDC cube */
    ak_mat4 o = ak_mat4_orthographic(-2, 4, -1, 3, 0.5f, 10);
    ak_vec3 lo = ak_mat4_transform_point(o, ak_vec3_make(-2, -1, -0.5f)), hi = ak_mat4_transform_point(o, ak_vec3_make(4, 3, -10));
    AK_CHECK(v3_diff(lo, ref_v3_make(-1, -1, -1)) < 1e-6 && v3_diff(hi, ref_v3_make(1, 1, 1)) < 1e-6);
    ak_mat4 oz = ak_mat4_orthographic(1, 1, 0, 0, 2, 2), on = ak_mat4_orthographic(0, INFINITY, 0, 1, 0, 1);
    AK_CHECK(ak_mat4_is_finite(&oz) && ak_mat4_is_finite(&on));
}

AK_TEST(look_at) {
    ak_rng g = ak_rng_make(20);
    double w_eye = 0, w_tgt = 0, w_orth = 0, w_up = 0;
    for (int n = 0; n < CASES; ++n) {
        ref_v3 eye = ref_v3_scale(rand_dir(&g), rand_range(&g, 0, 20));
        ref_v3 tgt = ref_v3_add(eye, ref_v3_scale(rand_dir(&g), rand_range(&g, 0.1, 20)));
        ak_mat4 m = ak_mat4_look_at(fv(eye), fv(tgt), ak_vec3_make(0, 1, 0));
        w_eye = dmax(w_eye, v3_diff(ak_mat4_transform_point(m, fv(eye)), ref_v3_make(0, 0, 0)) / 20.0);
        double dist = ref_v3_len(ref_v3_add(tgt, ref_v3_scale(eye, -1)));
        w_tgt = dmax(w_tgt, v3_diff(ak_mat4_transform_point(m, fv(tgt)), ref_v3_make(0, 0, -dist)) / 20.0);
        w_orth = dmax(w_orth, orth_err(ak_mat4_to_mat3(m)));
        /* world up stays in the upper half of the view (y >= 0) */
        ak_vec3 up = ak_mat4_transform_vector(m, ak_vec3_make(0, 1, 0));
        w_up = dmax(w_up, -up.y);
        AK_CHECK_NEAR(ref_m3_det(rm3(ak_mat4_to_mat3(m))), 1.0, 1e-5);
    }
    AK_CHECK_NEAR(w_eye, 0.0, 2e-6);
    AK_CHECK_NEAR(w_tgt, 0.0, 2e-6);
    AK_CHECK_NEAR(w_orth, 0.0, 2e-6);
    AK_CHECK_NEAR(w_up, 0.0, 1e-6);
    /* degenerate: eye == target, view along up */
    ak_mat4 a = ak_mat4_look_at(ak_vec3_make(1, 2, 3), ak_vec3_make(1, 2, 3), ak_vec3_make(0, 1, 0));
    ak_mat4 b = ak_mat4_look_at(ak_vec3_zero(), ak_vec3_make(0, 5, 0), ak_vec3_make(0, 1, 0));
    AK_CHECK(ak_mat4_is_finite(&a) && ak_mat4_is_finite(&b));
    AK_CHECK(v3_diff(ak_mat4_transform_point(b, ak_vec3_make(0, 5, 0)), ref_v3_make(0, 0, -5)) < 1e-5);
    /* non-finite eye, target or up: the documented identity fallback, never NaN */
    const float bad[3] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; ++k) {
        ak_vec3 v = ak_vec3_make(0, bad[k], 0);
        ak_mat4 m[3] = {ak_mat4_look_at(v, ak_vec3_make(0, 0, -1), ak_vec3_make(0, 1, 0)),
                        ak_mat4_look_at(ak_vec3_zero(), v, ak_vec3_make(0, 1, 0)),
                        ak_mat4_look_at(ak_vec3_zero(), ak_vec3_make(0, 0, -1), v)};
        for (int i = 0; i < 3; ++i) {
            AK_CHECK(ak_mat4_is_finite(&m[i]));
            ak_mat4 id = ak_mat4_identity();
            AK_CHECK(memcmp(&m[i], &id, sizeof id) == 0);
        }
    }
}

AK_TEST(transforms) {
    ak_rng g = ak_rng_make(21);
    double w_mul = 0, w_inv = 0, w_pt = 0;
    for (int n = 0; n < CASES; ++n) {
        ak_transform a = ak_transform_make(fv(ref_v3_scale(rand_dir(&g), 5)), fq(rand_quat(&g)), ak_vec3_splat((float)rand_range(&g, 0.2, 3)));
        ak_transform b = ak_transform_make(fv(ref_v3_scale(rand_dir(&g), 5)), fq(rand_quat(&g)), ak_vec3_splat((float)rand_range(&g, 0.2, 3)));
        ak_vec3 p = fv(ref_v3_scale(rand_dir(&g), 3));
        ref_m4 ma = rm4(ak_transform_to_mat4(a)), mb = rm4(ak_transform_to_mat4(b));
        ref_m4 mab = ref_m4_mul(ma, mb);
        ak_vec3 q = ak_transform_point(ak_transform_mul(a, b), p);
        ref_v3 want = {mab.m[0][0] * p.x + mab.m[0][1] * p.y + mab.m[0][2] * p.z + mab.m[0][3],
                       mab.m[1][0] * p.x + mab.m[1][1] * p.y + mab.m[1][2] * p.z + mab.m[1][3],
                       mab.m[2][0] * p.x + mab.m[2][1] * p.y + mab.m[2][2] * p.z + mab.m[2][3]};
        w_mul = dmax(w_mul, v3_diff(q, want) / 50.0);
        /* inverse: a^-1 (a p) = p */
        ak_vec3 back = ak_transform_point(ak_transform_inverse(a), ak_transform_point(a, p));
        w_inv = dmax(w_inv, v3_diff(back, rv(p)) / 5.0);
        w_pt = dmax(w_pt, v3_diff(ak_transform_point(a, p), rv(ak_mat4_transform_point(ak_transform_to_mat4(a), p))) / 20.0);
    }
    AK_CHECK_NEAR(w_mul, 0.0, 2e-6);
    AK_CHECK_NEAR(w_inv, 0.0, 2e-6);
    AK_CHECK_NEAR(w_pt, 0.0, 2e-6);
}

/* ---- arrays (SIMD and scalar builds run the same checks) ----------------------------------- */

AK_TEST(array_functions) {
    ak_rng g = ak_rng_make(22);
    enum { MAXN = 1003 };
    static ak_quat qa[MAXN], qb[MAXN], qo[MAXN];
    static ak_vec3 va[MAXN], vo[MAXN];
    static ak_mat4 ma[MAXN], mb[MAXN], mo[MAXN];
    double w_n = 0, w_m = 0, w_r = 0, w_rb = 0, w_4 = 0, w_4b = 0;
    const size_t counts[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 13, 31, 64, MAXN};
    for (size_t ci = 0; ci < sizeof counts / sizeof counts[0]; ++ci) {
        size_t n = counts[ci];
        for (size_t i = 0; i < MAXN; ++i) {
            ref_q s = rand_quat(&g);
            double k = rand_range(&g, 0.1, 10);
            qa[i] = fq((ref_q){s.x * k, s.y * k, s.z * k, s.w * k});
            qb[i] = fq(rand_quat(&g));
            va[i] = fv(ref_v3_scale(rand_dir(&g), rand_range(&g, 0, 10)));
            for (int j = 0; j < 16; ++j) ma[i].m[j] = (float)rand_range(&g, -1, 1), mb[i].m[j] = (float)rand_range(&g, -1, 1);
        }
        if (n > 6) /* degenerate lanes: zero, infinite, NaN */
            qa[3] = ak_quat_make(0, 0, 0, 0), qa[4] = ak_quat_make(INFINITY, 0, 0, 1), qa[5] = ak_quat_make(NAN, 1, 0, 0);
        AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){qa, n}, (ak_quat_span){qo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) w_n = dmax(w_n, q_diff_sign(qo[i], rq(ak_quat_normalize(qa[i]))));
        AK_CHECK_EQ(ak_quat_mul_array((ak_quat_cspan){qb, n}, (ak_quat_cspan){qb, n}, (ak_quat_span){qo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) w_m = dmax(w_m, q_diff_sign(qo[i], ref_q_mul(rq(qb[i]), rq(qb[i]))));
        AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){qb, n}, (ak_vec3_cspan){va, n}, (ak_vec3_span){vo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) w_r = dmax(w_r, v3_diff(vo[i], ref_q_rotate(rq(qb[i]), rv(va[i]))) / 10.0);
        AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){qb, 1}, (ak_vec3_cspan){va, n}, (ak_vec3_span){vo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) w_rb = dmax(w_rb, v3_diff(vo[i], ref_q_rotate(rq(qb[0]), rv(va[i]))) / 10.0);
        AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){ma, n}, (ak_mat4_cspan){mb, n}, (ak_mat4_span){mo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) {
            ref_m4 p = ref_m4_mul(rm4(ma[i]), rm4(mb[i]));
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) w_4 = dmax(w_4, fabs(mo[i].m[c * 4 + r] - p.m[r][c]));
        }
        AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){ma, 1}, (ak_mat4_cspan){mb, n}, (ak_mat4_span){mo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) {
            ref_m4 p = ref_m4_mul(rm4(ma[0]), rm4(mb[i]));
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) w_4b = dmax(w_4b, fabs(mo[i].m[c * 4 + r] - p.m[r][c]));
        }
        /* in place (out is the input array) */
        for (size_t i = 0; i < n; ++i) qo[i] = qa[i];
        AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){qo, n}, (ak_quat_span){qo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) w_n = dmax(w_n, q_diff_sign(qo[i], rq(ak_quat_normalize(qa[i]))));
        for (size_t i = 0; i < n; ++i) vo[i] = va[i];
        AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){qb, n}, (ak_vec3_cspan){vo, n}, (ak_vec3_span){vo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) w_r = dmax(w_r, v3_diff(vo[i], ref_q_rotate(rq(qb[i]), rv(va[i]))) / 10.0);
        for (size_t i = 0; i < n; ++i) mo[i] = mb[i];
        AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){ma, n}, (ak_mat4_cspan){mo, n}, (ak_mat4_span){mo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) {
            ref_m4 p = ref_m4_mul(rm4(ma[i]), rm4(mb[i]));
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) w_4 = dmax(w_4, fabs(mo[i].m[c * 4 + r] - p.m[r][c]));
        }
        /* broadcast in place: out is the array holding the broadcast a[0] */
        for (size_t i = 0; i < n; ++i) mo[i] = ma[i];
        AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){mo, 1}, (ak_mat4_cspan){mb, n}, (ak_mat4_span){mo, n}), AK_OK);
        for (size_t i = 0; i < n; ++i) {
            ref_m4 p = ref_m4_mul(rm4(ma[0]), rm4(mb[i]));
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r) w_4b = dmax(w_4b, fabs(mo[i].m[c * 4 + r] - p.m[r][c]));
        }
        if (n > 6) { /* zero, infinite and NaN -> identity */
            AK_CHECK(qo[3].w == 1.0f && qo[4].w == 1.0f && qo[4].x == 0.0f && qo[5].w == 1.0f && qo[5].x == 0.0f);
        }
    }
    AK_CHECK_NEAR(w_n, 0.0, 2e-7);
    AK_CHECK_NEAR(w_m, 0.0, 1e-6);
    AK_CHECK_NEAR(w_r, 0.0, 2e-6);
    AK_CHECK_NEAR(w_rb, 0.0, 2e-6);
    AK_CHECK_NEAR(w_4, 0.0, 2e-6);
    AK_CHECK_NEAR(w_4b, 0.0, 2e-6);
}

AK_TEST(array_unaligned) {
    /* The arrays sit 4 bytes past a 16-byte boundary: the SSE2 kernels must load unaligned. */
    static struct { float pad; ak_quat q[37]; ak_quat o[37]; ak_mat4 m[9]; ak_mat4 mo[9]; } u;
    AK_CHECK(((uintptr_t)u.q) % 16 != 0);
    ak_rng g = ak_rng_make(23);
    for (int i = 0; i < 37; ++i) u.q[i] = fq(rand_quat(&g));
    for (int i = 0; i < 9; ++i)
        for (int k = 0; k < 16; ++k) u.m[i].m[k] = ak_rng_float(&g);
    double w = 0;
    AK_CHECK_EQ(ak_quat_mul_array((ak_quat_cspan){u.q, 37}, (ak_quat_cspan){u.q, 37}, (ak_quat_span){u.o, 37}), AK_OK);
    for (int i = 0; i < 37; ++i) w = dmax(w, q_diff_sign(u.o[i], ref_q_mul(rq(u.q[i]), rq(u.q[i]))));
    AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){u.o, 37}, (ak_quat_span){u.o, 37}), AK_OK);
    for (int i = 0; i < 37; ++i) w = dmax(w, fabs(ak_quat_norm(u.o[i]) - 1.0));
    AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){u.m, 9}, (ak_mat4_cspan){u.m, 9}, (ak_mat4_span){u.mo, 9}), AK_OK);
    for (int i = 0; i < 9; ++i) {
        ref_m4 p = ref_m4_mul(rm4(u.m[i]), rm4(u.m[i]));
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) w = dmax(w, fabs(u.mo[i].m[c * 4 + r] - p.m[r][c]) / 4.0);
    }
    AK_CHECK_NEAR(w, 0.0, 1e-6);
}

AK_TEST(array_bad_input) {
    ak_quat q[4] = {{0, 0, 0, 2}, {0, 0, 0, 2}, {0, 0, 0, 2}, {0, 0, 0, 2}}, o[4];
    ak_vec3 v[4] = {{1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {1, 0, 0}}, vo[4];
    ak_mat4 m[2] = {ak_mat4_identity(), ak_mat4_identity()}, mo[2];
    for (int i = 0; i < 4; ++i) o[i] = ak_quat_make(7, 7, 7, 7);
    AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){NULL, 4}, (ak_quat_span){o, 4}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){q, 4}, (ak_quat_span){NULL, 4}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){q, 4}, (ak_quat_span){o, 3}), AK_ERR_SPAN_SMALL);
    AK_CHECK(o[0].x == 7.0f); /* nothing written on error */
    AK_CHECK_EQ(ak_quat_normalize_array((ak_quat_cspan){NULL, 0}, (ak_quat_span){NULL, 0}), AK_OK);
    AK_CHECK_EQ(ak_quat_mul_array((ak_quat_cspan){q, 4}, (ak_quat_cspan){q, 3}, (ak_quat_span){o, 4}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_quat_mul_array((ak_quat_cspan){q, 4}, (ak_quat_cspan){NULL, 4}, (ak_quat_span){o, 4}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_quat_mul_array((ak_quat_cspan){q, 4}, (ak_quat_cspan){q, 4}, (ak_quat_span){o, 2}), AK_ERR_SPAN_SMALL);
    AK_CHECK(o[0].x == 7.0f);
    AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){q, 2}, (ak_vec3_cspan){v, 4}, (ak_vec3_span){vo, 4}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){q, 0}, (ak_vec3_cspan){v, 4}, (ak_vec3_span){vo, 4}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){q, 4}, (ak_vec3_cspan){NULL, 4}, (ak_vec3_span){vo, 4}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_quat_rotate_array((ak_quat_cspan){q, 4}, (ak_vec3_cspan){v, 4}, (ak_vec3_span){vo, 3}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){m, 2}, (ak_mat4_cspan){m, 2}, (ak_mat4_span){mo, 1}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){NULL, 2}, (ak_mat4_cspan){m, 2}, (ak_mat4_span){mo, 2}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_mat4_mul_array((ak_mat4_cspan){m, 0}, (ak_mat4_cspan){m, 2}, (ak_mat4_span){mo, 2}), AK_ERR_SPAN_SMALL);
}

int main(void) {
    AK_RUN(quat_matrix_round_trip);
    AK_RUN(quat_product_matches_matrix_product);
    AK_RUN(rodrigues_and_axis_angle);
    AK_RUN(quat_exp_log);
    AK_RUN(euler_round_trip_all_orders);
    AK_RUN(euler_gimbal_lock);
    AK_RUN(euler_known_values);
    AK_RUN(slerp_properties);
    AK_RUN(nlerp_properties);
    AK_RUN(quat_edge_cases);
    AK_RUN(quat_from_to);
    AK_RUN(shepperd_180_degrees);
    AK_RUN(polar_properties);
    AK_RUN(polar_edge_cases);
    AK_RUN(svd_properties);
    AK_RUN(dualquat_matches_matrices);
    AK_RUN(dualquat_blend);
    AK_RUN(affine_interpolation);
    AK_RUN(mat4_inverse);
    AK_RUN(perspective_closed_form);
    AK_RUN(look_at);
    AK_RUN(transforms);
    AK_RUN(array_functions);
    AK_RUN(array_unaligned);
    AK_RUN(array_bad_input);
    AK_RUN(huge_finite_inputs);
    return ak_test_finish();
}
