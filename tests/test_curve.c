/* Tests for curve.h: every interpolant against closed forms computed here in double,
 * continuity by finite differences, derivatives, rotations, time, easing, arc length. */
#include <animkit/curve.h>

#include "ak_test.h"

/* ---- helpers ------------------------------------------------------------------------- */

static ak_track* build(const ak_raw_track* raw) {
    ak_track* t = NULL;
    ak_diag d;
    ak_result r = ak_track_build(raw, NULL, &t, &d);
    if (r != AK_OK) printf("  build failed: %s (%s)\n", ak_result_name(r), d.message);
    return t;
}

static float sample1(const ak_track* t, float time) {
    float v[AK_TRACK_MAX_COMPONENTS];
    ak_f32_span s = {v, AK_TRACK_MAX_COMPONENTS};
    ak_track_sample(t, time, s);
    return v[0];
}

static ak_quat sampleq(const ak_track* t, float time) {
    float v[4];
    ak_f32_span s = {v, 4};
    ak_track_sample(t, time, s);
    return ak_quat_make(v[0], v[1], v[2], v[3]);
}

static double deriv1(const ak_track* t, float time, int order) {
    float v[AK_TRACK_MAX_COMPONENTS];
    ak_f32_span s = {v, AK_TRACK_MAX_COMPONENTS};
    ak_track_derivative(t, time, order, s);
    return v[0];
}

/* Non-uniform increasing times starting at 0 and random values in [-1, 1]. */
static void random_keys(ak_rng* rng, size_t n, float* times, float* values, size_t cc) {
    float t = 0.0f;
    for (size_t k = 0; k < n; ++k) {
        times[k] = t;
        t += ak_rng_range(rng, 0.5f, 1.5f);
        for (size_t c = 0; c < cc; ++c) values[k * cc + c] = ak_rng_range(rng, -1.0f, 1.0f);
    }
}

static ak_quat random_quat(ak_rng* rng) {
    ak_vec3 axis = ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1));
    return ak_quat_from_axis_angle(axis, ak_rng_range(rng, -3.0f, 3.0f));
}

/* Cubic Hermite in double, u in [0, 1], tangents per second, d the segment duration. */
static double hermite_d(double u, double p0, double m0, double p1, double m1, double d) {
    double u2 = u * u, u3 = u2 * u;
    return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * m0 * d + (-2 * u3 + 3 * u2) * p1 + (u3 - u2) * m1 * d;
}

/* One-sided derivative estimates at t from the left and right, exact for cubics. */
static double d1_left(const ak_track* tr, float t, float h) {
    return (11.0 * sample1(tr, t) - 18.0 * sample1(tr, t - h) + 9.0 * sample1(tr, t - 2 * h) -
            2.0 * sample1(tr, t - 3 * h)) / (6.0 * h);
}
static double d1_right(const ak_track* tr, float t, float h) {
    return (-11.0 * sample1(tr, t) + 18.0 * sample1(tr, t + h) - 9.0 * sample1(tr, t + 2 * h) +
            2.0 * sample1(tr, t + 3 * h)) / (6.0 * h);
}
static double d2_left(const ak_track* tr, float t, float h) {
    return (2.0 * sample1(tr, t) - 5.0 * sample1(tr, t - h) + 4.0 * sample1(tr, t - 2 * h) - sample1(tr, t - 3 * h)) /
           ((double)h * h);
}
static double d2_right(const ak_track* tr, float t, float h) {
    return (2.0 * sample1(tr, t) - 5.0 * sample1(tr, t + h) + 4.0 * sample1(tr, t + 2 * h) - sample1(tr, t + 3 * h)) /
           ((double)h * h);
}

/* Largest jump of the first (order 1) or second (order 2) derivative over the interior keys. */
static double max_jump(const ak_track* tr, int order) {
    ak_f32_cspan times = ak_track_times(tr);
    double worst = 0.0;
    for (size_t k = 1; k + 1 < times.count; ++k) {
        float t = times.ptr[k];
        float h = 0.02f;
        double l = order == 1 ? d1_left(tr, t, h) : d2_left(tr, t, h);
        double r = order == 1 ? d1_right(tr, t, h) : d2_right(tr, t, h);
        if (fabs(l - r) > worst) worst = fabs(l - r);
    }
    return worst;
}

/* ---- keys are hit -------------------------------------------------------------------- */

AK_TEST(plain_interpolants_hit_keys) {
    const ak_interp modes[] = {AK_INTERP_STEP,     AK_INTERP_LINEAR, AK_INTERP_CUBICSPLINE, AK_INTERP_HERMITE,
                               AK_INTERP_CARDINAL, AK_INTERP_BEZIER, AK_INTERP_NATURAL,     AK_INTERP_LAGRANGE,
                               AK_INTERP_DEFAULT};
    ak_rng rng = ak_rng_make(1);
    enum { N = 9, CC = 3 };
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; ++m) {
        float times[N], vals[N * CC], raw_vals[N * 3 * CC], raw_times[N];
        random_keys(&rng, N, times, vals, CC);
        bool three = modes[m] == AK_INTERP_CUBICSPLINE || modes[m] == AK_INTERP_HERMITE || modes[m] == AK_INTERP_BEZIER;
        size_t stride = three ? 3 * CC : CC, off = modes[m] == AK_INTERP_BEZIER ? 0 : (three ? CC : 0);
        /* Keys given in a shuffled order (reversed pairs), so the build must sort them. */
        for (size_t k = 0; k < N; ++k) {
            size_t src = (k % 2 == 0 && k + 1 < N) ? k + 1 : (k % 2 == 1 ? k - 1 : k);
            raw_times[k] = times[src];
            for (size_t c = 0; c < stride; ++c) raw_vals[k * stride + c] = ak_rng_range(&rng, -2.0f, 2.0f);
            for (size_t c = 0; c < CC; ++c) raw_vals[k * stride + off + c] = vals[src * CC + c];
        }
        ak_raw_track raw = {.component_count = CC, .interp = modes[m], .key_count = N, .times = raw_times, .values = raw_vals};
        ak_track* tr = build(&raw);
        AK_CHECK(tr != NULL);
        if (!tr) continue;
        for (size_t k = 0; k < N; ++k) {
            float out[CC];
            ak_track_sample(tr, times[k], (ak_f32_span)AK_SPAN(out));
            for (size_t c = 0; c < CC; ++c)
                AK_CHECK_MSG(fabsf(out[c] - vals[k * CC + c]) <= 1e-6f, "%s key %zu: %.9g vs %.9g",
                             ak_interp_name(modes[m]), k, (double)out[c], (double)vals[k * CC + c]);
        }
        /* Clamped outside the key range. */
        float before[CC], after[CC];
        ak_track_sample(tr, -5.0f, (ak_f32_span)AK_SPAN(before));
        ak_track_sample(tr, 1e6f, (ak_f32_span)AK_SPAN(after));
        AK_CHECK_NEAR(before[0], vals[0], 1e-6);
        AK_CHECK_NEAR(after[2], vals[(N - 1) * CC + 2], 1e-6);
        ak_track_destroy(tr);
    }
}

AK_TEST(rotation_interpolants_hit_keys) {
    const ak_interp modes[] = {AK_INTERP_STEP, AK_INTERP_LINEAR, AK_INTERP_NLERP, AK_INTERP_SQUAD, AK_INTERP_CUBICSPLINE};
    ak_rng rng = ak_rng_make(2);
    enum { N = 7 };
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; ++m) {
        float times[N], dummy[N], vals[N * 12];
        random_keys(&rng, N, times, dummy, 1);
        ak_quat keys[N];
        size_t stride = modes[m] == AK_INTERP_CUBICSPLINE ? 12 : 4, off = stride == 12 ? 4 : 0;
        for (size_t k = 0; k < N; ++k) {
            keys[k] = random_quat(&rng);
            for (size_t c = 0; c < stride; ++c) vals[k * stride + c] = ak_rng_range(&rng, -1, 1);
            vals[k * stride + off + 0] = keys[k].x;
            vals[k * stride + off + 1] = keys[k].y;
            vals[k * stride + off + 2] = keys[k].z;
            vals[k * stride + off + 3] = keys[k].w;
        }
        ak_raw_track raw = {.is_rotation = true, .interp = modes[m], .key_count = N, .times = times, .values = vals};
        ak_track* tr = build(&raw);
        AK_CHECK(tr != NULL);
        if (!tr) continue;
        for (size_t k = 0; k < N; ++k) {
            ak_quat q = sampleq(tr, times[k]);
            float d = fabsf(ak_quat_dot(q, keys[k]));
            AK_CHECK_MSG(fabsf(d - 1.0f) <= 1e-6f, "%s key %zu |dot| %.9g", ak_interp_name(modes[m]), k, (double)d);
        }
        /* Outputs are unit between keys too (CUBICSPLINE renormalises). */
        for (int i = 0; i < 50; ++i) {
            ak_quat q = sampleq(tr, ak_rng_range(&rng, 0.0f, times[N - 1]));
            AK_CHECK_NEAR(ak_quat_norm(q), 1.0f, 1e-6);
        }
        ak_track_destroy(tr);
    }
}

/* ---- closed forms -------------------------------------------------------------------- */

AK_TEST(hermite_and_gltf_cubicspline_match_the_spec_formula) {
    /* glTF 2.0 Appendix C: p(t) = (2t^3-3t^2+1) p0 + (t^3-2t^2+t) m0 D + (-2t^3+3t^2) p1
     * + (t^3-t^2) m1 D, with m0 = out-tangent of key k, m1 = in-tangent of key k+1. */
    ak_rng rng = ak_rng_make(3);
    enum { N = 6 };
    float times[N], vals[N * 3], dummy[N];
    random_keys(&rng, N, times, dummy, 1);
    for (size_t i = 0; i < N * 3; ++i) vals[i] = ak_rng_range(&rng, -3.0f, 3.0f);
    const ak_interp modes[] = {AK_INTERP_CUBICSPLINE, AK_INTERP_HERMITE};
    for (int m = 0; m < 2; ++m) {
        ak_raw_track raw = {.interp = modes[m], .key_count = N, .times = times, .values = vals};
        ak_track* tr = build(&raw);
        AK_CHECK(tr != NULL);
        if (!tr) return;
        for (size_t k = 0; k + 1 < N; ++k) {
            for (int j = 0; j <= 10; ++j) {
                double u = j / 10.0, d = (double)times[k + 1] - times[k];
                float t = (float)(times[k] + u * d);
                double uu = ((double)t - times[k]) / d; /* the float time actually sampled */
                double ref = hermite_d(uu, vals[k * 3 + 1], vals[k * 3 + 2], vals[(k + 1) * 3 + 1], vals[(k + 1) * 3], d);
                AK_CHECK_NEAR(sample1(tr, t), ref, 2e-6 * (1.0 + fabs(ref)));
            }
        }
        /* Key tangents come back as given. */
        float in, out;
        ak_track_key(tr, 2, (ak_f32_span){0}, (ak_f32_span){&in, 1}, (ak_f32_span){&out, 1});
        AK_CHECK_EQ(in, vals[2 * 3]);
        AK_CHECK_EQ(out, vals[2 * 3 + 2]);
        ak_track_destroy(tr);
    }
}

AK_TEST(cardinal_tangents_match_closed_form) {
    ak_rng rng = ak_rng_make(4);
    enum { N = 8 };
    float times[N], vals[N];
    random_keys(&rng, N, times, vals, 1);
    const float tensions[] = {0.0f, 0.5f, 1.0f, 2.0f};
    for (int ti = 0; ti < 4; ++ti) {
        double mu = tensions[ti] == 0.0f ? 1.0 : tensions[ti];
        ak_raw_track raw = {.interp = AK_INTERP_CARDINAL, .tension = tensions[ti], .key_count = N, .times = times, .values = vals};
        ak_track* tr = build(&raw);
        AK_CHECK(tr != NULL);
        if (!tr) return;
        double m[N];
        for (size_t k = 0; k < N; ++k) {
            size_t lo = k > 0 ? k - 1 : 0, hi = k + 1 < N ? k + 1 : N - 1;
            m[k] = mu * ((double)vals[hi] - vals[lo]) / ((double)times[hi] - times[lo]);
            float in, out;
            ak_track_key(tr, k, (ak_f32_span){0}, (ak_f32_span){&in, 1}, (ak_f32_span){&out, 1});
            AK_CHECK_NEAR(in, m[k], 1e-5 * (1 + fabs(m[k])));
            AK_CHECK_NEAR(out, m[k], 1e-5 * (1 + fabs(m[k])));
            if (k + 1 < N) AK_CHECK_NEAR(deriv1(tr, times[k], 1), m[k], 1e-4 * (1 + fabs(m[k])));
        }
        for (size_t k = 0; k + 1 < N; ++k) {
            double d = (double)times[k + 1] - times[k];
            float t = (float)(times[k] + 0.37 * d);
            double u = ((double)t - times[k]) / d;
            AK_CHECK_NEAR(sample1(tr, t), hermite_d(u, vals[k], m[k], vals[k + 1], m[k + 1], d), 2e-6);
        }
        ak_track_destroy(tr);
    }
}

AK_TEST(bezier_matches_bernstein_form) {
    ak_rng rng = ak_rng_make(5);
    enum { N = 6 };
    float times[N], dummy[N], vals[N * 3];
    random_keys(&rng, N, times, dummy, 1);
    for (size_t i = 0; i < N * 3; ++i) vals[i] = ak_rng_range(&rng, -2.0f, 2.0f);
    ak_raw_track raw = {.interp = AK_INTERP_BEZIER, .key_count = N, .times = times, .values = vals};
    ak_track* tr = build(&raw);
    AK_CHECK(tr != NULL);
    if (!tr) return;
    for (size_t k = 0; k + 1 < N; ++k) {
        double p0 = vals[k * 3], c0 = vals[k * 3 + 1], c1 = vals[(k + 1) * 3 + 2], p1 = vals[(k + 1) * 3];
        for (int j = 0; j <= 8; ++j) {
            double d = (double)times[k + 1] - times[k];
            float t = (float)(times[k] + d * j / 8.0);
            double u = ((double)t - times[k]) / d, v = 1.0 - u;
            double ref = v * v * v * p0 + 3 * v * v * u * c0 + 3 * v * u * u * c1 + u * u * u * p1;
            AK_CHECK_NEAR(sample1(tr, t), ref, 4e-6);
        }
        /* Derived tangents: the Bezier end derivatives 3 (c0 - p0) / D and 3 (p1 - c1) / D. */
        double d = (double)times[k + 1] - times[k];
        float out, in;
        ak_track_key(tr, k, (ak_f32_span){0}, (ak_f32_span){0}, (ak_f32_span){&out, 1});
        ak_track_key(tr, k + 1, (ak_f32_span){0}, (ak_f32_span){&in, 1}, (ak_f32_span){0});
        AK_CHECK_NEAR(out, 3.0 * (c0 - p0) / d, 1e-5 * (1 + fabs(3.0 * (c0 - p0) / d)));
        AK_CHECK_NEAR(in, 3.0 * (p1 - c1) / d, 1e-5 * (1 + fabs(3.0 * (p1 - c1) / d)));
    }
    ak_track_destroy(tr);
}

/* Natural spline second derivatives by dense Gaussian elimination in double (independent of
 * the library's tridiagonal sweep). */
static void natural_reference(const float* t, const float* y, int n, double* M) {
    double A[16][17];
    int m = n - 2;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j <= m; ++j) A[i][j] = 0.0;
    for (int i = 1; i <= m; ++i) {
        double h0 = (double)t[i] - t[i - 1], h1 = (double)t[i + 1] - t[i];
        if (i > 1) A[i - 1][i - 2] = h0;
        A[i - 1][i - 1] = 2 * (h0 + h1);
        if (i < m) A[i - 1][i] = h1;
        A[i - 1][m] = 6 * (((double)y[i + 1] - y[i]) / h1 - ((double)y[i] - y[i - 1]) / h0);
    }
    for (int c = 0; c < m; ++c)
        for (int r = c + 1; r < m; ++r) {
            double f = A[r][c] / A[c][c];
            for (int j = c; j <= m; ++j) A[r][j] -= f * A[c][j];
        }
    M[0] = M[n - 1] = 0.0;
    for (int r = m - 1; r >= 0; --r) {
        double s = A[r][m];
        for (int j = r + 1; j < m; ++j) s -= A[r][j] * M[j + 1];
        M[r + 1] = s / A[r][r];
    }
}

AK_TEST(natural_spline_matches_reference_and_is_c2) {
    ak_rng rng = ak_rng_make(6);
    enum { N = 10 };
    float times[N], vals[N];
    random_keys(&rng, N, times, vals, 1);
    ak_raw_track raw = {.interp = AK_INTERP_NATURAL, .key_count = N, .times = times, .values = vals};
    ak_track* tr = build(&raw);
    AK_CHECK(tr != NULL);
    if (!tr) return;
    double M[N];
    natural_reference(times, vals, N, M);
    for (size_t k = 0; k + 1 < N; ++k) {
        double h = (double)times[k + 1] - times[k];
        for (int j = 1; j < 8; ++j) {
            float t = (float)(times[k] + h * j / 8.0);
            double a = ((double)times[k + 1] - t) / h, b = ((double)t - times[k]) / h;
            double ref = a * vals[k] + b * vals[k + 1] + ((a * a * a - a) * M[k] + (b * b * b - b) * M[k + 1]) * h * h / 6.0;
            AK_CHECK_NEAR(sample1(tr, t), ref, 2e-6);
        }
        /* Analytic second derivative at the key from the right equals M_k. */
        AK_CHECK_NEAR(deriv1(tr, times[k], 2), M[k], 1e-3 * (1 + fabs(M[k])));
    }
    /* Natural end conditions. */
    AK_CHECK_NEAR(d2_right(tr, times[0], 0.02f), 0.0, 5e-3);
    AK_CHECK_NEAR(d2_left(tr, times[N - 1], 0.02f), 0.0, 5e-3);
    AK_CHECK_MSG(max_jump(tr, 1) < 2e-3, "C1 jump %g", max_jump(tr, 1));
    AK_CHECK_MSG(max_jump(tr, 2) < 1e-2, "C2 jump %g", max_jump(tr, 2));
    ak_track_destroy(tr);
}

AK_TEST(continuity_by_finite_differences) {
    ak_rng rng = ak_rng_make(7);
    enum { N = 9 };
    float times[N], vals[N], herm[N * 3], bez[N * 3];
    random_keys(&rng, N, times, vals, 1);
    for (size_t k = 0; k < N; ++k) {
        float m = ak_rng_range(&rng, -2.0f, 2.0f);
        herm[k * 3] = herm[k * 3 + 2] = m;
        herm[k * 3 + 1] = vals[k];
        /* Bezier handles collinear and proportional to the neighbouring intervals: C1. */
        float dp = k > 0 ? times[k] - times[k - 1] : 1.0f, dn = k + 1 < N ? times[k + 1] - times[k] : 1.0f;
        bez[k * 3] = vals[k];
        bez[k * 3 + 1] = vals[k] + m * dn / 3.0f;
        bez[k * 3 + 2] = vals[k] - m * dp / 3.0f;
    }
    ak_raw_track rh = {.interp = AK_INTERP_HERMITE, .key_count = N, .times = times, .values = herm};
    ak_raw_track rc = {.interp = AK_INTERP_CARDINAL, .key_count = N, .times = times, .values = vals};
    ak_raw_track rb = {.interp = AK_INTERP_BEZIER, .key_count = N, .times = times, .values = bez};
    ak_raw_track rl = {.interp = AK_INTERP_LINEAR, .key_count = N, .times = times, .values = vals};
    ak_track *h = build(&rh), *c = build(&rc), *b = build(&rb), *l = build(&rl);
    AK_CHECK(h && c && b && l);
    if (!(h && c && b && l)) return;
    AK_CHECK_MSG(max_jump(h, 1) < 2e-3, "hermite C1 jump %g", max_jump(h, 1));
    AK_CHECK_MSG(max_jump(c, 1) < 2e-3, "cardinal C1 jump %g", max_jump(c, 1));
    AK_CHECK_MSG(max_jump(b, 1) < 2e-3, "bezier C1 jump %g", max_jump(b, 1));
    /* The checks can fail: linear has slope jumps, cardinal has curvature jumps. */
    AK_CHECK_MSG(max_jump(l, 1) > 0.1, "linear C1 jump %g", max_jump(l, 1));
    AK_CHECK_MSG(max_jump(c, 2) > 0.1, "cardinal C2 jump %g", max_jump(c, 2));
    ak_track_destroy(h);
    ak_track_destroy(c);
    ak_track_destroy(b);
    ak_track_destroy(l);
}

AK_TEST(lagrange_is_global_cardinal_is_local) {
    float times[12], vals[12];
    for (int k = 0; k < 12; ++k) {
        times[k] = (float)k;
        vals[k] = sinf(0.7f * (float)k);
    }
    vals[10] = 3.0f; /* the two extra keys differ from the pattern */
    vals[11] = -2.0f;
    ak_raw_track l10 = {.interp = AK_INTERP_LAGRANGE, .key_count = 10, .times = times, .values = vals};
    ak_raw_track l12 = l10, c10 = l10, c12 = l10;
    l12.key_count = 12;
    c10.interp = c12.interp = AK_INTERP_CARDINAL;
    c12.key_count = 12;
    ak_track *a = build(&l10), *b = build(&l12), *c = build(&c10), *d = build(&c12);
    AK_CHECK(a && b && c && d);
    if (!(a && b && c && d)) return;
    /* Far from the new keys (t in [0, 3]) the polynomial changes, the spline does not. */
    double lag_change = 0.0;
    for (int i = 0; i <= 30; ++i) {
        float t = 0.1f * (float)i;
        lag_change = fmax(lag_change, fabs(sample1(a, t) - sample1(b, t)));
        AK_CHECK_EQ(sample1(c, t) == sample1(d, t), 1);
    }
    AK_CHECK_MSG(lag_change > 1e-2, "lagrange change %g", lag_change);
    /* Lagrange against the basis-polynomial closed form in double. */
    for (int i = 0; i < 20; ++i) {
        double t = 0.45 * i, ref = 0.0;
        for (int j = 0; j < 12; ++j) {
            double lj = 1.0;
            for (int m = 0; m < 12; ++m)
                if (m != j) lj *= (t - times[m]) / ((double)times[j] - times[m]);
            ref += lj * vals[j];
        }
        AK_CHECK_NEAR(sample1(b, (float)t), ref, 1e-4 * (1 + fabs(ref)));
    }
    ak_track_destroy(a);
    ak_track_destroy(b);
    ak_track_destroy(c);
    ak_track_destroy(d);
    /* Hundreds of close keys: either a clear error or finite (clamped) output, never NaN. */
    enum { M = 400 };
    static float mt[M], mv[M];
    ak_rng rng = ak_rng_make(17);
    for (int k = 0; k < M; ++k) mt[k] = 1e-3f * (float)k, mv[k] = ak_rng_range(&rng, -1, 1);
    ak_raw_track big = {.interp = AK_INTERP_LAGRANGE, .key_count = M, .times = mt, .values = mv};
    ak_track* e = NULL;
    ak_result r = ak_track_build(&big, NULL, &e, NULL);
    AK_CHECK(r == AK_OK || r == AK_ERR_BAD_DATA);
    for (int i = 0; e && i < 1000; ++i) {
        float v = sample1(e, ak_rng_range(&rng, 0.0f, 0.4f));
        AK_CHECK(v - v == 0.0f);
    }
    ak_track_destroy(e);
}

/* ---- derivatives --------------------------------------------------------------------- */

AK_TEST(derivatives_reproduce_a_cubic) {
    /* p(t) = 1 + 2t - t^2 + 0.5 t^3: Lagrange through 6 keys and Hermite with exact tangents
     * both reproduce it, with its velocity and acceleration. */
    enum { N = 6 };
    float times[N] = {0.0f, 0.4f, 1.1f, 1.5f, 2.6f, 3.0f}, vals[N], herm[N * 3];
    for (int k = 0; k < N; ++k) {
        double t = times[k];
        vals[k] = (float)(1 + 2 * t - t * t + 0.5 * t * t * t);
        herm[k * 3] = herm[k * 3 + 2] = (float)(2 - 2 * t + 1.5 * t * t);
        herm[k * 3 + 1] = vals[k];
    }
    ak_raw_track rl = {.interp = AK_INTERP_LAGRANGE, .key_count = N, .times = times, .values = vals};
    ak_raw_track rh = {.interp = AK_INTERP_HERMITE, .key_count = N, .times = times, .values = herm};
    ak_track *l = build(&rl), *h = build(&rh);
    AK_CHECK(l && h);
    if (!(l && h)) return;
    ak_rng rng = ak_rng_make(8);
    for (int i = 0; i < 100; ++i) {
        float t = ak_rng_range(&rng, 0.0f, 3.0f);
        double td = t;
        double p = 1 + 2 * td - td * td + 0.5 * td * td * td, v = 2 - 2 * td + 1.5 * td * td, a = -2 + 3 * td;
        const ak_track* tr[2] = {l, h};
        for (int j = 0; j < 2; ++j) {
            AK_CHECK_NEAR(sample1(tr[j], t), p, 2e-5);
            AK_CHECK_NEAR(deriv1(tr[j], t, 1), v, 1e-4);
            AK_CHECK_NEAR(deriv1(tr[j], t, 2), a, 1e-3);
        }
    }
    /* Linear: slope, zero acceleration; outside the keys: zero. */
    ak_raw_track rlin = {.interp = AK_INTERP_LINEAR, .key_count = N, .times = times, .values = vals};
    ak_track* lin = build(&rlin);
    AK_CHECK(lin != NULL);
    if (lin) {
        double slope = ((double)vals[2] - vals[1]) / ((double)times[2] - times[1]);
        AK_CHECK_NEAR(deriv1(lin, 0.8f, 1), slope, 1e-5);
        AK_CHECK_EQ(deriv1(lin, 0.8f, 2), 0);
        AK_CHECK_EQ(deriv1(lin, -1.0f, 1), 0);
        AK_CHECK_EQ(deriv1(lin, 5.0f, 1), 0);
        ak_track_destroy(lin);
    }
    ak_track_destroy(l);
    ak_track_destroy(h);
}

/* ---- rotations ----------------------------------------------------------------------- */

AK_TEST(slerp_constant_angular_speed_and_shortest_path) {
    ak_quat q0 = ak_quat_from_axis_angle(ak_vec3_make(0.3f, 1.0f, -0.2f), 0.4f);
    ak_quat q1 = ak_quat_from_axis_angle(ak_vec3_make(-1.0f, 0.2f, 0.5f), 2.2f);
    /* Store -q1 when q0.q1 > 0 (and q1 otherwise) so the raw keys have a negative dot. */
    ak_quat stored = ak_quat_dot(q0, q1) > 0.0f ? ak_quat_neg(q1) : q1;
    AK_CHECK(ak_quat_dot(q0, stored) < 0.0f);
    float times[2] = {1.0f, 3.0f};
    float vals[8] = {q0.x, q0.y, q0.z, q0.w, stored.x, stored.y, stored.z, stored.w};
    ak_raw_track raw = {.is_rotation = true, .key_count = 2, .times = times, .values = vals};
    ak_track* tr = build(&raw);
    AK_CHECK(tr != NULL);
    if (!tr) return;
    float total = ak_quat_angle_between(q0, q1); /* shortest angle, < pi */
    AK_CHECK(total < AK_PI);
    ak_quat prev = sampleq(tr, 1.0f);
    for (int i = 1; i <= 40; ++i) {
        ak_quat q = sampleq(tr, 1.0f + 2.0f * (float)i / 40.0f);
        AK_CHECK_NEAR(ak_quat_angle_between(prev, q), total / 40.0f, 2e-4);
        AK_CHECK_NEAR(ak_quat_angle_between(q0, q), total * (float)i / 40.0f, 2e-4);
        prev = q;
    }
    /* Angular velocity: the shortest-arc axis, total / 2 s. */
    float w[3];
    AK_CHECK_EQ(ak_track_derivative(tr, 1.7f, 1, (ak_f32_span)AK_SPAN(w)), AK_OK);
    AK_CHECK_NEAR(sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]), total / 2.0f, 1e-4);
    /* The derivative predicts the next sample: q(t + h) ~ exp(w h / 2) q(t). */
    ak_quat a = sampleq(tr, 1.7f), b = sampleq(tr, 1.71f);
    ak_quat step = ak_quat_from_axis_angle(ak_vec3_make(w[0], w[1], w[2]),
                                           0.01f * sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]));
    AK_CHECK_NEAR(ak_quat_angle_between(ak_quat_mul(step, a), b), 0.0f, 2e-4);
    ak_track_destroy(tr);
}

/* Angular velocity from the left and right of t by one-sided differences of samples. */
static ak_vec3 omega_fd(const ak_track* tr, float t, float h) {
    ak_quat a = sampleq(tr, t), b = sampleq(tr, t + h);
    if (ak_quat_dot(a, b) < 0.0f) b = ak_quat_neg(b);
    ak_quat d = ak_quat_mul(b, ak_quat_conjugate(a));
    ak_vec3 axis;
    float angle;
    ak_quat_to_axis_angle(d, &axis, &angle);
    return ak_vec3_scale(axis, angle / h);
}

AK_TEST(squad_is_c1_nlerp_is_not) {
    ak_rng rng = ak_rng_make(9);
    enum { N = 6 };
    float times[N], dummy[N], vals[N * 4];
    random_keys(&rng, N, times, dummy, 1);
    ak_quat q = ak_quat_identity();
    for (int k = 0; k < N; ++k) {
        ak_quat step = ak_quat_from_axis_angle(ak_vec3_make(ak_rng_range(&rng, -1, 1), 1, ak_rng_range(&rng, -1, 1)), 0.8f);
        q = ak_quat_mul(step, q);
        ak_quat s = k % 2 ? ak_quat_neg(q) : q; /* alternate signs: the build must align them */
        vals[k * 4] = s.x;
        vals[k * 4 + 1] = s.y;
        vals[k * 4 + 2] = s.z;
        vals[k * 4 + 3] = s.w;
    }
    ak_raw_track rs = {.is_rotation = true, .interp = AK_INTERP_SQUAD, .key_count = N, .times = times, .values = vals};
    ak_raw_track rn = rs;
    rn.interp = AK_INTERP_NLERP;
    ak_track *sq = build(&rs), *nl = build(&rn);
    AK_CHECK(sq && nl);
    if (!(sq && nl)) return;
    float h = 2e-3f;
    double worst_s = 0.0, worst_n = 0.0;
    for (int k = 1; k + 1 < N; ++k) {
        float t = times[k];
        /* Second-order one-sided estimates from each side. */
        ak_vec3 l = ak_vec3_sub(ak_vec3_scale(omega_fd(sq, t - h, h), 2.0f), omega_fd(sq, t - 2 * h, h));
        ak_vec3 r = ak_vec3_sub(ak_vec3_scale(omega_fd(sq, t, h), 2.0f), omega_fd(sq, t + h, h));
        worst_s = fmax(worst_s, ak_vec3_length(ak_vec3_sub(l, r)) / (1e-3 + ak_vec3_length(l)));
        ak_vec3 ln = omega_fd(nl, t - h, h), rn2 = omega_fd(nl, t, h);
        worst_n = fmax(worst_n, ak_vec3_length(ak_vec3_sub(ln, rn2)) / (1e-3 + ak_vec3_length(ln)));
    }
    AK_CHECK_MSG(worst_s < 0.02, "squad relative velocity jump %g", worst_s);
    AK_CHECK_MSG(worst_n > 0.1, "nlerp relative velocity jump %g", worst_n);
    /* The reported angular velocity matches the samples. */
    float w[3];
    float tm = 0.5f * (times[2] + times[3]);
    ak_track_derivative(sq, tm, 1, (ak_f32_span)AK_SPAN(w));
    ak_vec3 fd = ak_vec3_scale(ak_vec3_add(omega_fd(sq, tm - h, h), omega_fd(sq, tm, h)), 0.5f);
    AK_CHECK_NEAR(ak_vec3_distance(ak_vec3_make(w[0], w[1], w[2]), fd), 0.0, 2e-3 * (1 + ak_vec3_length(fd)));
    ak_track_destroy(sq);
    ak_track_destroy(nl);
}

AK_TEST(rotation_angular_velocity_matches_samples) {
    /* Every rotation mode's reported angular velocity against a central difference of
     * samples: w ~ axis * angle of q(t+h) q(t-h)^-1 / 2h (parent space). */
    ak_rng rng = ak_rng_make(10);
    enum { N = 5 };
    float times[N], dummy[N], vals[N * 12];
    random_keys(&rng, N, times, dummy, 1);
    const ak_interp modes[] = {AK_INTERP_LINEAR, AK_INTERP_NLERP, AK_INTERP_SQUAD, AK_INTERP_CUBICSPLINE};
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; ++m) {
        size_t stride = modes[m] == AK_INTERP_CUBICSPLINE ? 12 : 4, off = stride == 12 ? 4 : 0;
        for (int k = 0; k < N; ++k) {
            ak_quat q = random_quat(&rng);
            for (size_t c = 0; c < stride; ++c) vals[k * stride + c] = ak_rng_range(&rng, -0.5f, 0.5f);
            vals[k * stride + off] = q.x, vals[k * stride + off + 1] = q.y;
            vals[k * stride + off + 2] = q.z, vals[k * stride + off + 3] = q.w;
        }
        ak_raw_track raw = {.is_rotation = true, .interp = modes[m], .key_count = N, .times = times, .values = vals};
        ak_track* tr = build(&raw);
        AK_CHECK(tr != NULL);
        if (!tr) continue;
        for (int i = 0; i < 40; ++i) {
            int k = i % (N - 1);
            float t = times[k] + (times[k + 1] - times[k]) * ak_rng_range(&rng, 0.1f, 0.9f);
            float h = 1e-3f;
            ak_quat a = sampleq(tr, t - h), b = sampleq(tr, t + h);
            if (ak_quat_dot(a, b) < 0.0f) b = ak_quat_neg(b);
            ak_vec3 axis;
            float angle;
            ak_quat_to_axis_angle(ak_quat_mul(b, ak_quat_conjugate(a)), &axis, &angle);
            ak_vec3 fd = ak_vec3_scale(axis, angle / (2.0f * h));
            float w[3];
            AK_CHECK_EQ(ak_track_derivative(tr, t, 1, (ak_f32_span)AK_SPAN(w)), AK_OK);
            double err = ak_vec3_distance(ak_vec3_make(w[0], w[1], w[2]), fd);
            AK_CHECK_MSG(err < 5e-3 * (1.0 + ak_vec3_length(fd)), "%s: |w - fd| = %g (|fd| %g)", ak_interp_name(modes[m]),
                         err, (double)ak_vec3_length(fd));
        }
        ak_track_destroy(tr);
    }
}

/* ---- bad input ----------------------------------------------------------------------- */

AK_TEST(bad_input_codes) {
    float t2[2] = {0.0f, 1.0f}, v2[2] = {0.0f, 1.0f}, q2[8] = {0, 0, 0, 1, 0, 0, 0, 1};
    ak_track* tr = (ak_track*)&tr; /* must be reset to NULL on failure */
    ak_diag d;
    AK_CHECK_EQ(ak_track_build(NULL, NULL, &tr, &d), AK_ERR_NULL_ARG);
    AK_CHECK(tr == NULL);
    ak_raw_track ok = {.key_count = 2, .times = t2, .values = v2};
    AK_CHECK_EQ(ak_track_build(&ok, NULL, NULL, &d), AK_ERR_NULL_ARG);
    ak_raw_track r = ok;
    r.key_count = 0;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_EMPTY);
    r = ok;
    r.times = NULL;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_NULL_ARG);
    r = ok;
    r.interp = (ak_interp)99;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_ARG);
    r = ok;
    r.interp = AK_INTERP_SQUAD;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_ARG);
    r = ok;
    r.component_count = AK_TRACK_MAX_COMPONENTS + 1;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_ARG);
    r = ok;
    r.tension = -1.0f;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_ARG);
    ak_raw_track rq = {.is_rotation = true, .key_count = 2, .times = t2, .values = q2};
    r = rq;
    r.component_count = 3;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_ARG);
    r = rq;
    r.interp = AK_INTERP_CARDINAL;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_UNSUPPORTED);
    float zq[8] = {0, 0, 0, 0, 0, 0, 0, 1};
    r = rq;
    r.values = zq;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_DATA);
    float tn[2] = {0.0f, NAN}, vn[2] = {0.0f, INFINITY}, td[3] = {1.0f, 0.0f, 1.0f}, v3[3] = {0, 0, 0};
    r = ok;
    r.times = tn;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_DATA);
    AK_CHECK(strstr(d.message, "key 1") != NULL);
    r = ok;
    r.values = vn;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_BAD_DATA);
    r = ok;
    r.key_count = 3;
    r.times = td;
    r.values = v3;
    AK_CHECK_EQ(ak_track_build(&r, NULL, &tr, &d), AK_ERR_DUPLICATE);
    AK_CHECK(tr == NULL);

    tr = build(&ok);
    AK_CHECK(tr != NULL);
    float out[4];
    AK_CHECK_EQ(ak_track_sample(tr, 0.5f, (ak_f32_span){out, 0}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_track_sample(NULL, 0.5f, (ak_f32_span)AK_SPAN(out)), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_track_derivative(tr, 0.5f, 3, (ak_f32_span)AK_SPAN(out)), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_track_key(tr, 2, (ak_f32_span)AK_SPAN(out), (ak_f32_span){0}, (ak_f32_span){0}), AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_track_sample(tr, NAN, (ak_f32_span)AK_SPAN(out)), AK_OK);
    AK_CHECK_EQ(out[0], 0); /* NaN time -> first key */
    ak_track_destroy(tr);
    tr = build(&rq);
    AK_CHECK_EQ(ak_track_derivative(tr, 0.5f, 2, (ak_f32_span)AK_SPAN(out)), AK_ERR_UNSUPPORTED);
    ak_track_destroy(tr);
}

/* ---- plotting accessors -------------------------------------------------------------- */

AK_TEST(uniform_sampling_and_key_access) {
    float times[3] = {0.0f, 1.0f, 3.0f}, vals[3] = {0.0f, 2.0f, 1.0f};
    ak_raw_track raw = {.interp = AK_INTERP_LINEAR, .key_count = 3, .times = times, .values = vals};
    ak_track* tr = build(&raw);
    AK_CHECK(tr != NULL);
    if (!tr) return;
    float ts[7], vs[7];
    AK_CHECK_EQ(ak_track_sample_uniform(tr, 0.0f, 3.0f, (ak_f32_span)AK_SPAN(ts), (ak_f32_span)AK_SPAN(vs)), AK_OK);
    for (int i = 0; i < 7; ++i) {
        AK_CHECK_NEAR(ts[i], 0.5 * i, 1e-6);
        double ref = ts[i] <= 1.0f ? 2.0 * ts[i] : 2.0 - 0.5 * (ts[i] - 1.0);
        AK_CHECK_NEAR(vs[i], ref, 1e-6);
    }
    AK_CHECK_EQ(ak_track_sample_uniform(tr, 0.0f, 3.0f, (ak_f32_span)AK_SPAN(ts), (ak_f32_span){vs, 6}), AK_ERR_SPAN_SMALL);
    float in, out, v;
    AK_CHECK_EQ(ak_track_key(tr, 1, (ak_f32_span){&v, 1}, (ak_f32_span){&in, 1}, (ak_f32_span){&out, 1}), AK_OK);
    AK_CHECK_EQ(v, 2);
    AK_CHECK_NEAR(in, 2.0, 1e-6);
    AK_CHECK_NEAR(out, -0.5, 1e-6);
    AK_CHECK_EQ(ak_track_key_count(tr), 3);
    AK_CHECK_EQ(ak_track_interp(tr), AK_INTERP_LINEAR);
    AK_CHECK_NEAR(ak_track_end_time(tr), 3.0, 0);
    AK_CHECK_STREQ(ak_interp_name(AK_INTERP_CUBICSPLINE), "cubicspline");
    ak_track_destroy(tr);
}

/* ---- time ---------------------------------------------------------------------------- */

AK_TEST(time_wrap_modes) {
    AK_CHECK_NEAR(ak_time_wrap(-1.0f, 2.0f, AK_WRAP_CLAMP), 0.0, 0);
    AK_CHECK_NEAR(ak_time_wrap(3.0f, 2.0f, AK_WRAP_DEFAULT), 2.0, 0);
    AK_CHECK_NEAR(ak_time_wrap(5.5f, 2.0f, AK_WRAP_LOOP), 1.5, 1e-6);
    AK_CHECK_NEAR(ak_time_wrap(-0.5f, 2.0f, AK_WRAP_LOOP), 1.5, 1e-6);
    AK_CHECK_NEAR(ak_time_wrap(2.0f, 2.0f, AK_WRAP_LOOP), 0.0, 0);
    AK_CHECK_NEAR(ak_time_wrap(2.5f, 2.0f, AK_WRAP_PING_PONG), 1.5, 1e-6);
    AK_CHECK_NEAR(ak_time_wrap(4.5f, 2.0f, AK_WRAP_PING_PONG), 0.5, 1e-6);
    AK_CHECK_NEAR(ak_time_wrap(-0.5f, 2.0f, AK_WRAP_PING_PONG), 0.5, 1e-6);
    AK_CHECK_NEAR(ak_time_wrap(1.0f, 0.0f, AK_WRAP_LOOP), 0.0, 0);
    AK_CHECK_NEAR(ak_time_wrap(NAN, 2.0f, AK_WRAP_LOOP), 0.0, 0);
    AK_CHECK_NEAR(ak_time_wrap(INFINITY, 2.0f, AK_WRAP_CLAMP), 2.0, 0);
    AK_CHECK_NEAR(ak_time_wrap(INFINITY, 2.0f, AK_WRAP_LOOP), 0.0, 0);
}

AK_TEST(easing_curves) {
    for (int k = 0; k < AK_EASE_COUNT; ++k) {
        ak_ease_kind e = (ak_ease_kind)k;
        AK_CHECK_NEAR(ak_ease(e, 0.0f), 0.0, 1e-7);
        AK_CHECK_NEAR(ak_ease(e, 1.0f), 1.0, 1e-6);
        float prev = 0.0f;
        for (int i = 1; i <= 100; ++i) {
            float u = (float)i / 100.0f, v = ak_ease(e, u);
            AK_CHECK_MSG(v >= prev - 1e-7f, "ease %d not monotonic at %g", k, (double)u);
            prev = v;
            if (i < 100) {
                double fd = ((double)ak_ease(e, u + 1e-3f) - ak_ease(e, u - 1e-3f)) / 2e-3;
                AK_CHECK_MSG(fabs(fd - ak_ease_derivative(e, u)) < 2e-2 * (1 + fabs(fd)), "ease %d derivative at %g", k,
                             (double)u);
            }
        }
    }
    /* Slow in, slow out: zero speed at both ends; in-out curves are point-symmetric. */
    AK_CHECK_NEAR(ak_ease_derivative(AK_EASE_SMOOTHSTEP, 0.0f), 0.0, 0);
    AK_CHECK_NEAR(ak_ease_derivative(AK_EASE_SINE_IN_OUT, 1.0f), 0.0, 1e-6);
    const ak_ease_kind sym[] = {AK_EASE_SMOOTHSTEP, AK_EASE_SMOOTHERSTEP, AK_EASE_SINE_IN_OUT, AK_EASE_QUAD_IN_OUT,
                                AK_EASE_CUBIC_IN_OUT, AK_EASE_QUART_IN_OUT};
    for (size_t i = 0; i < sizeof sym / sizeof sym[0]; ++i)
        for (int j = 0; j <= 10; ++j) {
            float u = (float)j / 10.0f;
            AK_CHECK_NEAR(ak_ease(sym[i], 1.0f - u), 1.0f - ak_ease(sym[i], u), 1e-6);
        }
    AK_CHECK_NEAR(ak_ease(AK_EASE_SMOOTHSTEP, 0.25f), 0.15625, 1e-7);
    AK_CHECK_NEAR(ak_ease(AK_EASE_CUBIC_OUT, 0.5f), 0.875, 1e-7);
    AK_CHECK_NEAR(ak_ease_time(AK_EASE_QUAD_IN, 1.0f, 4.0f), 0.25, 1e-6);
}

AK_TEST(user_time_warp) {
    float times[3] = {0.0f, 1.0f, 2.0f}, vals[3] = {0.0f, 0.2f, 2.0f};
    ak_raw_track raw = {.interp = AK_INTERP_LINEAR, .key_count = 3, .times = times, .values = vals};
    ak_track* w = build(&raw);
    AK_CHECK(w != NULL);
    AK_CHECK_NEAR(ak_time_warp(w, 0.5f), 0.1, 1e-7);
    AK_CHECK_NEAR(ak_time_warp(w, 1.5f), 1.1, 1e-6);
    AK_CHECK_NEAR(ak_time_warp(NULL, 1.5f), 1.5, 0);
    AK_CHECK(ak_track_is_monotonic(w));
    ak_track_destroy(w);
    float back[3] = {0.0f, 1.0f, 0.5f};
    raw.values = back;
    w = build(&raw);
    AK_CHECK(!ak_track_is_monotonic(w));
    ak_track_destroy(w);
}

/* ---- arc length ---------------------------------------------------------------------- */

AK_TEST(arc_length_constant_speed) {
    /* A Catmull-Rom path through uneven points: its raw speed varies a lot. */
    enum { N = 7 };
    float times[N] = {0.0f, 0.5f, 1.8f, 2.2f, 3.5f, 4.0f, 5.0f};
    float pts[N * 3] = {0, 0, 0, 2, 1, 0, 3, 1, 2, 3.2f, 0, 2.5f, 6, -1, 1, 6.5f, 0, 0, 7, 2, -1};
    ak_raw_track raw = {.component_count = 3, .interp = AK_INTERP_CARDINAL, .key_count = N, .times = times, .values = pts};
    ak_track* path = build(&raw);
    AK_CHECK(path != NULL);
    if (!path) return;
    ak_arc_table* tab = NULL;
    AK_CHECK_EQ(ak_arc_table_desc_resolved(NULL).cell_count, 256);
    AK_CHECK_EQ(ak_arc_table_desc_resolved(&(ak_arc_table_desc){.cell_count = 9}).cell_count, 9);
    AK_CHECK_EQ(ak_arc_table_create(&(ak_arc_table_desc){.path = path}, NULL, &tab), AK_OK);
    if (!tab) return;
    /* Reference length: a fine polyline in double. */
    double ref = 0.0;
    float prev[3], cur[3];
    ak_track_sample(path, 0.0f, (ak_f32_span)AK_SPAN(prev));
    for (int i = 1; i <= 200000; ++i) {
        ak_track_sample(path, 5.0f * (float)i / 200000.0f, (ak_f32_span)AK_SPAN(cur));
        ref += sqrt(pow((double)cur[0] - prev[0], 2) + pow((double)cur[1] - prev[1], 2) + pow((double)cur[2] - prev[2], 2));
        memcpy(prev, cur, sizeof cur);
    }
    double len = ak_arc_table_length(tab);
    AK_CHECK_NEAR(len, ref, 1e-4 * ref);
    /* Constant speed: equal distance steps move equal chord lengths (steps small enough that
     * chord and arc agree to 1e-5). */
    int steps = 400;
    double ds = len / steps, worst = 0.0, worst_raw = 0.0;
    for (int i = 0; i < steps; ++i) {
        float a[3], b[3];
        ak_track_sample(path, ak_arc_table_time_at(tab, (float)(ds * i)), (ak_f32_span)AK_SPAN(a));
        ak_track_sample(path, ak_arc_table_time_at(tab, (float)(ds * (i + 1))), (ak_f32_span)AK_SPAN(b));
        double chord = sqrt(pow((double)b[0] - a[0], 2) + pow((double)b[1] - a[1], 2) + pow((double)b[2] - a[2], 2));
        worst = fmax(worst, fabs(chord / ds - 1.0));
        /* Without the reparametrisation (uniform time steps) the speed varies widely. */
        ak_track_sample(path, 5.0f * (float)i / (float)steps, (ak_f32_span)AK_SPAN(a));
        ak_track_sample(path, 5.0f * (float)(i + 1) / (float)steps, (ak_f32_span)AK_SPAN(b));
        chord = sqrt(pow((double)b[0] - a[0], 2) + pow((double)b[1] - a[1], 2) + pow((double)b[2] - a[2], 2));
        worst_raw = fmax(worst_raw, fabs(chord / (len / steps) - 1.0));
    }
    printf("  arc length: speed variation %.4f%% (raw time: %.1f%%)\n", 100.0 * worst, 100.0 * worst_raw);
    AK_CHECK_MSG(worst < 0.005, "speed variation %g", worst);
    AK_CHECK(worst_raw > 0.1);
    /* distance_at inverts time_at. */
    for (int i = 0; i <= 20; ++i) {
        float s = (float)(len * i / 20.0);
        AK_CHECK_NEAR(ak_arc_table_distance_at(tab, ak_arc_table_time_at(tab, s)), s, 1e-3 * len);
    }
    AK_CHECK_NEAR(ak_arc_table_time_at(tab, -1.0f), 0.0, 0);
    AK_CHECK_NEAR(ak_arc_table_time_at(tab, 1e9f), 5.0, 0);
    ak_arc_table_destroy(tab);

    /* Bad input. */
    AK_CHECK_EQ(ak_arc_table_create(&(ak_arc_table_desc){0}, NULL, &tab), AK_ERR_NULL_ARG);
    float sv[2] = {0, 1}, st[2] = {0, 1};
    ak_raw_track scalar = {.key_count = 2, .times = st, .values = sv};
    ak_track* s = build(&scalar);
    AK_CHECK_EQ(ak_arc_table_create(&(ak_arc_table_desc){.path = s}, NULL, &tab), AK_ERR_BAD_ARG);
    ak_track_destroy(s);
    ak_track_destroy(path);
}

AK_TEST(arc_length_of_a_polyline_is_exact) {
    float times[3] = {0.0f, 1.0f, 4.0f}, pts[9] = {0, 0, 0, 3, 4, 0, 3, 4, 12};
    ak_raw_track raw = {.component_count = 3, .key_count = 3, .times = times, .values = pts};
    ak_track* path = build(&raw);
    ak_arc_table* tab = NULL;
    AK_CHECK_EQ(ak_arc_table_create(&(ak_arc_table_desc){.path = path, .cell_count = 8}, NULL, &tab), AK_OK);
    AK_CHECK_NEAR(ak_arc_table_length(tab), 17.0, 1e-5);
    AK_CHECK_NEAR(ak_arc_table_time_at(tab, 5.0f), 1.0, 1e-5);
    AK_CHECK_NEAR(ak_arc_table_time_at(tab, 11.0f), 2.5, 1e-5);
    ak_arc_table_destroy(tab);
    ak_track_destroy(path);
}

int main(void) {
    AK_RUN(plain_interpolants_hit_keys);
    AK_RUN(rotation_interpolants_hit_keys);
    AK_RUN(hermite_and_gltf_cubicspline_match_the_spec_formula);
    AK_RUN(cardinal_tangents_match_closed_form);
    AK_RUN(bezier_matches_bernstein_form);
    AK_RUN(natural_spline_matches_reference_and_is_c2);
    AK_RUN(continuity_by_finite_differences);
    AK_RUN(lagrange_is_global_cardinal_is_local);
    AK_RUN(derivatives_reproduce_a_cubic);
    AK_RUN(slerp_constant_angular_speed_and_shortest_path);
    AK_RUN(squad_is_c1_nlerp_is_not);
    AK_RUN(rotation_angular_velocity_matches_samples);
    AK_RUN(bad_input_codes);
    AK_RUN(uniform_sampling_and_key_access);
    AK_RUN(time_wrap_modes);
    AK_RUN(easing_curves);
    AK_RUN(user_time_warp);
    AK_RUN(arc_length_constant_speed);
    AK_RUN(arc_length_of_a_polyline_is_exact);
    return ak_test_finish();
}
