/* Tests for clip.h: build rules, glTF sampling against the specification's formulas in
 * double, cursor vs binary search bit-identity, blending properties, root motion. */
#include <animkit/clip.h>

#include "ak_test.h"
#include "ref/ref_clip.h" /* double slerp and per-track check of ak_clip_sample */

/* ---- helpers ------------------------------------------------------------------------- */

static ak_clip* build(const ak_raw_clip* raw) {
    ak_clip* c = NULL;
    ak_diag d;
    ak_result r = ak_clip_build(raw, NULL, &c, &d);
    if (r != AK_OK) printf("  build failed: %s (%s)\n", ak_result_name(r), d.message);
    return c;
}

static ak_quat random_quat(ak_rng* rng) {
    ak_vec3 axis = ak_vec3_make(ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1), ak_rng_range(rng, -1, 1));
    return ak_quat_from_axis_angle(axis, ak_rng_range(rng, -3.0f, 3.0f));
}

static ak_transform random_transform(ak_rng* rng) {
    ak_transform t;
    t.translation = ak_vec3_make(ak_rng_range(rng, -2, 2), ak_rng_range(rng, -2, 2), ak_rng_range(rng, -2, 2));
    t.rotation = random_quat(rng);
    t.scale = ak_vec3_make(ak_rng_range(rng, 0.5f, 2), ak_rng_range(rng, 0.5f, 2), ak_rng_range(rng, 0.5f, 2));
    return t;
}

static double rot_error(ak_quat a, ak_quat b) { return 1.0 - fabs((double)ak_quat_dot(a, b)); }

/* ---- build rules --------------------------------------------------------------------- */

AK_TEST(build_and_queries) {
    float t[3] = {0.5f, 0.0f, 2.0f}, v[9] = {1, 1, 1, 0, 0, 0, 2, 2, 2}, w[6] = {0, 1, 1, 0, 0.5f, 0.5f};
    ak_raw_channel ch[2] = {
        {.target = AK_CHANNEL_TRANSLATION, .index = 3, .key_count = 3, .times = t, .values = v},
        {.target = AK_CHANNEL_MORPH_WEIGHTS, .index = 1, .component_count = 2, .interp = AK_INTERP_STEP, .key_count = 3,
         .times = t, .values = w},
    };
    ak_raw_clip raw = {.name = "walk", .channels = ch, .channel_count = 2, .joint_count = 4, .morph_weight_count = 3};
    ak_clip* c = build(&raw);
    AK_CHECK(c != NULL);
    if (!c) return;
    AK_CHECK_STREQ(ak_clip_name(c), "walk");
    AK_CHECK_NEAR(ak_clip_duration(c), 2.0, 0);
    AK_CHECK_EQ(ak_clip_channel_count(c), 2);
    AK_CHECK_EQ(ak_clip_joint_count(c), 4);
    AK_CHECK_EQ(ak_clip_channel_target(c, 1), AK_CHANNEL_MORPH_WEIGHTS);
    AK_CHECK_EQ(ak_clip_channel_index(c, 0), 3);
    AK_CHECK_EQ(ak_clip_channel_interp(c, 0), AK_INTERP_LINEAR);
    AK_CHECK_EQ(ak_clip_channel_interp(c, 1), AK_INTERP_STEP);
    AK_CHECK_EQ(ak_clip_channel_key_count(c, 1), 3);
    AK_CHECK_EQ(ak_clip_channel_target(c, 2), AK_CHANNEL_TARGET_COUNT);
    AK_CHECK(ak_clip_channel_track(c, 2) == NULL);
    /* Keys come back sorted. */
    ak_f32_cspan times = ak_track_times(ak_clip_channel_track(c, 0));
    AK_CHECK_EQ(times.count, 3);
    AK_CHECK(times.ptr[0] == 0.0f && times.ptr[1] == 0.5f && times.ptr[2] == 2.0f);
    /* Keys are hit; untouched joints and weights keep their values. */
    ak_transform pose[4];
    float weights[3] = {9, 9, 9};
    for (int j = 0; j < 4; ++j) pose[j] = ak_transform_identity();
    AK_CHECK_EQ(ak_clip_sample(c, 0.5f, NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span)AK_SPAN(weights),
                               (ak_f32_span){0}),
                AK_OK);
    AK_CHECK_NEAR(pose[3].translation.y, 1.0, 1e-6);
    AK_CHECK(memcmp(&pose[0], &pose[2], sizeof pose[0]) == 0 && pose[0].scale.x == 1.0f);
    AK_CHECK_EQ(weights[0], 9);
    AK_CHECK_NEAR(weights[1], 0.0, 0);
    AK_CHECK_NEAR(weights[2], 1.0, 0);
    /* STEP holds until the next key; clamps outside the range. */
    ak_clip_sample(c, 1.99f, NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span)AK_SPAN(weights), (ak_f32_span){0});
    AK_CHECK_NEAR(weights[1], 0.0, 0);
    ak_clip_sample(c, 7.0f, NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span)AK_SPAN(weights), (ak_f32_span){0});
    AK_CHECK_NEAR(weights[1], 0.5, 0);
    AK_CHECK_NEAR(pose[3].translation.z, 2.0, 0);
    ak_clip_sample(c, -3.0f, NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span)AK_SPAN(weights), (ak_f32_span){0});
    AK_CHECK_NEAR(pose[3].translation.x, 0.0, 0);
    ak_clip_destroy(c);
    ak_clip_destroy(NULL);
    AK_CHECK_STREQ(ak_clip_name(NULL), "");
}

AK_TEST(build_rejects_bad_input_with_exact_codes) {
    float t2[2] = {0, 1}, v6[6] = {0, 0, 0, 1, 1, 1}, q8[8] = {0, 0, 0, 1, 0, 0, 0, 1};
    ak_raw_channel good = {.target = AK_CHANNEL_TRANSLATION, .index = 0, .key_count = 2, .times = t2, .values = v6};
    ak_raw_channel ch[2] = {good, good};
    ak_raw_clip base = {.channels = ch, .channel_count = 1, .joint_count = 2, .morph_weight_count = 2, .scalar_count = 2};
    ak_clip* c = (ak_clip*)&c;
    ak_diag d;
#define EXPECT(code)                                                                       \
    do {                                                                                   \
        memset(&d, 0, sizeof d);                                                           \
        AK_CHECK_EQ(ak_clip_build(&raw, NULL, &c, &d), code);                              \
        AK_CHECK(c == NULL);                                                               \
        AK_CHECK(d.message[0] != '\0');                                                    \
    } while (0)
    ak_raw_clip raw = base;
    AK_CHECK_EQ(ak_clip_build(NULL, NULL, &c, NULL), AK_ERR_NULL_ARG);
    raw.channel_count = 0;
    EXPECT(AK_ERR_EMPTY);
    raw = base;
    raw.duration = -1.0f;
    EXPECT(AK_ERR_BAD_ARG);
    raw.duration = NAN;
    EXPECT(AK_ERR_BAD_DATA);
    raw = base;
    ch[0].key_count = 0;
    EXPECT(AK_ERR_EMPTY);
    ch[0] = good;
    ch[0].values = NULL;
    EXPECT(AK_ERR_NULL_ARG);
    ch[0] = good;
    ch[0].index = 2;
    EXPECT(AK_ERR_BAD_INDEX);
    ch[0] = good;
    ch[0].target = AK_CHANNEL_MORPH_WEIGHTS;
    ch[0].component_count = 3;
    ch[0].index = 0;
    EXPECT(AK_ERR_BAD_INDEX);
    ch[0].target = AK_CHANNEL_SCALAR;
    ch[0].component_count = 1;
    ch[0].index = 2;
    EXPECT(AK_ERR_BAD_INDEX);
    ch[0] = good;
    ch[0].target = (ak_channel_target)17;
    EXPECT(AK_ERR_BAD_ARG);
    ch[0] = good;
    ch[0].component_count = 4;
    EXPECT(AK_ERR_BAD_ARG);
    ch[0] = good;
    ch[0].interp = AK_INTERP_SQUAD;
    EXPECT(AK_ERR_BAD_ARG);
    ch[0] = good;
    ch[0].target = AK_CHANNEL_ROTATION;
    ch[0].values = q8;
    ch[0].interp = AK_INTERP_NATURAL;
    EXPECT(AK_ERR_UNSUPPORTED);
    float tn[2] = {0, NAN}, vn[6] = {0, 0, 0, 1, NAN, 1}, td[2] = {1, 1};
    ch[0] = good;
    ch[0].times = tn;
    EXPECT(AK_ERR_BAD_DATA);
    ch[0] = good;
    ch[0].values = vn;
    EXPECT(AK_ERR_BAD_DATA);
    ch[0] = good;
    ch[0].times = td;
    EXPECT(AK_ERR_DUPLICATE);
    ch[0] = good;
    raw.channel_count = 2; /* two channels on joint 0's translation */
    EXPECT(AK_ERR_DUPLICATE);
    ch[1].target = AK_CHANNEL_SCALE; /* different property: fine */
    c = build(&raw);
    AK_CHECK(c != NULL);
    ak_clip_destroy(c);
#undef EXPECT
}

AK_TEST(sample_rejects_bad_spans) {
    float t2[2] = {0, 1}, v6[6] = {0, 0, 0, 1, 1, 1};
    ak_raw_channel ch = {.target = AK_CHANNEL_TRANSLATION, .index = 1, .key_count = 2, .times = t2, .values = v6};
    ak_raw_clip raw = {.channels = &ch, .channel_count = 1, .joint_count = 2};
    ak_clip *a = build(&raw), *b = build(&raw);
    ak_transform pose[2];
    AK_CHECK_EQ(ak_clip_sample(a, 0.5f, NULL, (ak_transform_span){pose, 1}, (ak_f32_span){0}, (ak_f32_span){0}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_clip_sample(a, 0.5f, NULL, (ak_transform_span){0}, (ak_f32_span){0}, (ak_f32_span){0}), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_clip_sample(NULL, 0.5f, NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span){0}, (ak_f32_span){0}),
                AK_ERR_NULL_ARG);
    uint32_t st[1];
    ak_clip_cursor cur;
    AK_CHECK(ak_clip_cursor_storage_count(a) >= 1); /* 1 segment (+ the key cache in SIMD builds) */
    AK_CHECK_EQ(ak_clip_cursor_init(&cur, a, (ak_u32_span){st, 0}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_clip_cursor_init(&cur, a, (ak_u32_span)AK_SPAN(st)), AK_OK);
    AK_CHECK_EQ(ak_clip_sample(b, 0.5f, &cur, (ak_transform_span)AK_SPAN(pose), (ak_f32_span){0}, (ak_f32_span){0}),
                AK_ERR_BAD_ARG);
    pose[1] = ak_transform_identity();
    AK_CHECK_EQ(ak_clip_sample(a, NAN, &cur, (ak_transform_span)AK_SPAN(pose), (ak_f32_span){0}, (ak_f32_span){0}), AK_OK);
    AK_CHECK(ak_vec3_is_finite(pose[1].translation));
    ak_clip_destroy(a);
    ak_clip_destroy(b);
}

/* ---- glTF 2.0 Appendix C --------------------------------------------------------------- */

AK_TEST(gltf_interpolation_matches_spec_formulas) {
    ak_rng rng = ak_rng_make(11);
    enum { N = 5 };
    float times[N] = {0.0f, 0.3f, 1.0f, 1.25f, 2.0f};
    float tcub[N * 9], rcub[N * 12], rlin[N * 4];
    for (int i = 0; i < N * 9; ++i) tcub[i] = ak_rng_range(&rng, -2, 2);
    for (int k = 0; k < N; ++k) {
        ak_quat q = random_quat(&rng);
        if (k == 3) q = ak_quat_neg(q); /* negative dot with a neighbour: shortest path */
        float* r = rcub + k * 12;
        for (int c = 0; c < 4; ++c) r[c] = ak_rng_range(&rng, -1, 1), r[8 + c] = ak_rng_range(&rng, -1, 1);
        r[4] = q.x, r[5] = q.y, r[6] = q.z, r[7] = q.w;
        rlin[k * 4] = q.x, rlin[k * 4 + 1] = q.y, rlin[k * 4 + 2] = q.z, rlin[k * 4 + 3] = q.w;
    }
    ak_raw_channel ch[3] = {
        {.target = AK_CHANNEL_TRANSLATION, .interp = AK_INTERP_CUBICSPLINE, .key_count = N, .times = times, .values = tcub},
        {.target = AK_CHANNEL_ROTATION, .interp = AK_INTERP_CUBICSPLINE, .key_count = N, .times = times, .values = rcub},
        {.target = AK_CHANNEL_ROTATION, .index = 1, .interp = AK_INTERP_LINEAR, .key_count = N, .times = times, .values = rlin},
    };
    ak_raw_clip raw = {.channels = ch, .channel_count = 3, .joint_count = 2};
    ak_clip* c = build(&raw);
    AK_CHECK(c != NULL);
    if (!c) return;
    for (int i = 0; i < 400; ++i) {
        float t = ak_rng_range(&rng, 0.0f, 2.0f);
        ak_transform pose[2] = {ak_transform_identity(), ak_transform_identity()};
        ak_clip_sample(c, t, NULL, (ak_transform_span)AK_SPAN(pose), (ak_f32_span){0}, (ak_f32_span){0});
        int k = 0;
        while (k < N - 2 && times[k + 1] <= t) ++k;
        double td = (double)times[k + 1] - times[k], s = ((double)t - times[k]) / td;
        double s2 = s * s, s3 = s2 * s;
        double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
        /* CUBICSPLINE: p0 = value_k, m0 = td * out_k, p1 = value_k+1, m1 = td * in_k+1. */
        double p[3], q[4], n = 0.0;
        for (int j = 0; j < 3; ++j)
            p[j] = h00 * tcub[k * 9 + 3 + j] + h10 * td * tcub[k * 9 + 6 + j] + h01 * tcub[(k + 1) * 9 + 3 + j] +
                   h11 * td * tcub[(k + 1) * 9 + j];
        for (int j = 0; j < 4; ++j) {
            q[j] = h00 * rcub[k * 12 + 4 + j] + h10 * td * rcub[k * 12 + 8 + j] + h01 * rcub[(k + 1) * 12 + 4 + j] +
                   h11 * td * rcub[(k + 1) * 12 + j];
            n += q[j] * q[j];
        }
        n = sqrt(n);
        AK_CHECK_NEAR(pose[0].translation.x, p[0], 2e-6 * (1 + fabs(p[0])));
        AK_CHECK_NEAR(pose[0].translation.y, p[1], 2e-6 * (1 + fabs(p[1])));
        AK_CHECK_NEAR(pose[0].translation.z, p[2], 2e-6 * (1 + fabs(p[2])));
        ak_quat ref = ak_quat_make((float)(q[0] / n), (float)(q[1] / n), (float)(q[2] / n), (float)(q[3] / n));
        AK_CHECK_NEAR(rot_error(pose[0].rotation, ref), 0.0, 1e-6);
        /* LINEAR rotation: the spec's slerp, a = acos(|dot|), s = sign(dot). */
        const float* a = rlin + k * 4;
        const float* b = rlin + (k + 1) * 4;
        double dot = (double)a[0] * b[0] + (double)a[1] * b[1] + (double)a[2] * b[2] + (double)a[3] * b[3];
        double ang = acos(fmin(1.0, fabs(dot))), sgn = dot < 0 ? -1.0 : 1.0;
        double wa = sin(ang * (1 - s)) / sin(ang), wb = sgn * sin(ang * s) / sin(ang);
        ak_quat sl = ak_quat_make((float)(wa * a[0] + wb * b[0]), (float)(wa * a[1] + wb * b[1]),
                                  (float)(wa * a[2] + wb * b[2]), (float)(wa * a[3] + wb * b[3]));
        AK_CHECK_NEAR(ak_quat_angle_between(pose[1].rotation, sl), 0.0, 2e-6);
        AK_CHECK_NEAR(ak_quat_norm(pose[1].rotation), 1.0, 1e-6);
    }
    ak_clip_destroy(c);
}

/* ---- cursor ------------------------------------------------------------------------- */

enum { CJ = 24 };

/* A random clip over CJ joints (every mode, 1-key channels, weights and scalars); common: every
 * channel with the same key times (as baked clips have), else each with its own. */
static ak_clip* random_clip(ak_rng* rng, float* store, size_t store_count, bool common) {
    static const ak_interp tmodes[] = {AK_INTERP_STEP, AK_INTERP_LINEAR, AK_INTERP_CUBICSPLINE, AK_INTERP_CARDINAL,
                                       AK_INTERP_NATURAL};
    static const ak_interp rmodes[] = {AK_INTERP_STEP, AK_INTERP_LINEAR, AK_INTERP_NLERP, AK_INTERP_SQUAD,
                                       AK_INTERP_CUBICSPLINE};
    ak_raw_channel ch[3 * CJ + 2];
    size_t used = 0, nch = 0;
    for (int c = 0; c < 3 * CJ + 2; ++c) {
        ak_raw_channel* r = &ch[nch++];
        memset(r, 0, sizeof *r);
        if (c < 3 * CJ) {
            r->target = (ak_channel_target)(c % 3);
            r->index = (uint32_t)(c / 3);
        } else {
            r->target = c == 3 * CJ ? AK_CHANNEL_MORPH_WEIGHTS : AK_CHANNEL_SCALAR;
            r->component_count = 3;
        }
        bool rot = r->target == AK_CHANNEL_ROTATION;
        r->interp = rot ? rmodes[ak_rng_u32(rng) % 5] : tmodes[ak_rng_u32(rng) % 5];
        uint32_t cc = rot ? 4 : 3;
        size_t n = common ? 23 : c % 17 == 5 ? 1 : 2 + ak_rng_u32(rng) % 40;
        size_t stride = r->interp == AK_INTERP_CUBICSPLINE ? 3 * cc : cc;
        float* times = store + used;
        used += n;
        float* vals = store + used;
        used += n * stride;
        if (used > store_count) return NULL;
        float t = ak_rng_range(rng, -0.5f, 1.0f);
        ak_rng trng = ak_rng_make(77); /* common: the same time sequence for every channel */
        if (common) t = -0.25f;
        for (size_t k = 0; k < n; ++k) {
            times[k] = t;
            t += ak_rng_range(common ? &trng : rng, 0.01f, 0.5f);
            for (size_t j = 0; j < stride; ++j) vals[k * stride + j] = ak_rng_range(rng, -1, 1);
        }
        r->key_count = n;
        r->times = times;
        r->values = vals;
    }
    ak_raw_clip raw = {.channels = ch, .channel_count = nch, .joint_count = CJ, .morph_weight_count = 3, .scalar_count = 3};
    return build(&raw);
}


static int compare_run(const ak_clip* c, ak_clip_cursor* cur, const float* times, size_t count) {
    int mismatches = 0;
    for (size_t i = 0; i < count; ++i) {
        ak_transform a[CJ], b[CJ];
        float wa[3] = {0}, wb[3] = {0}, sa[3] = {0}, sb[3] = {0};
        for (int j = 0; j < CJ; ++j) a[j] = b[j] = ak_transform_identity();
        ak_clip_sample(c, times[i], cur, (ak_transform_span)AK_SPAN(a), (ak_f32_span)AK_SPAN(wa), (ak_f32_span)AK_SPAN(sa));
        ak_clip_sample(c, times[i], NULL, (ak_transform_span)AK_SPAN(b), (ak_f32_span)AK_SPAN(wb), (ak_f32_span)AK_SPAN(sb));
        if (memcmp(a, b, sizeof a) || memcmp(wa, wb, sizeof wa) || memcmp(sa, sb, sizeof sa)) ++mismatches;
    }
    return mismatches;
}

AK_TEST(slerp_groups_in_pairs_bit_identical) {
    /* 40 LINEAR (slerp) rotation channels: ten key-cache groups, sampled two by two in the AVX
     * kernels; random keys with repeated ones (degenerate segments redone in scalar code), own
     * or shared key times, times outside the keys. Every kernel must give the binary search's
     * floats. */
    enum { NJ = 40, NK = 12 };
    static float times[NJ][NK], vals[NJ][NK * 4];
    ak_rng rng = ak_rng_make(99);
    for (int shared = 0; shared < 2; ++shared) {
        ak_raw_channel ch[NJ];
        for (int j = 0; j < NJ; ++j) {
            float t = shared ? 0.0f : ak_rng_range(&rng, -0.3f, 0.3f);
            for (int k = 0; k < NK; ++k) {
                times[j][k] = t;
                t += shared ? 0.1f : ak_rng_range(&rng, 0.02f, 0.2f);
                for (int e = 0; e < 4; ++e)
                    vals[j][4 * k + e] = k > 0 && (j + k) % 5 == 0 ? vals[j][4 * (k - 1) + e] : ak_rng_range(&rng, -1, 1);
            }
            memset(&ch[j], 0, sizeof ch[j]);
            ch[j].target = AK_CHANNEL_ROTATION, ch[j].index = (uint32_t)j, ch[j].interp = AK_INTERP_LINEAR;
            ch[j].key_count = NK, ch[j].times = times[j], ch[j].values = vals[j];
        }
        ak_raw_clip raw = {.channels = ch, .channel_count = NJ, .joint_count = NJ};
        ak_clip* c = build(&raw);
        AK_CHECK(c != NULL);
        if (!c) return;
        size_t full = ak_clip_cursor_storage_count(c);
        uint32_t* seg = (uint32_t*)calloc(full, sizeof *seg);
        for (int lim = AK_CLIP_SIMD_SCALAR; lim < AK_CLIP_SIMD_COUNT; ++lim) {
            AK_CHECK_EQ(ak_clip_set_simd_limit(c, (ak_clip_simd)lim), AK_OK);
            ak_clip_cursor cur;
            AK_CHECK_EQ(ak_clip_cursor_init(&cur, c, (ak_u32_span){seg, full}), AK_OK);
            enum { T = 700 };
            float ts[T];
            for (int i = 0; i < T; ++i) ts[i] = -0.5f + 2.0f * (float)i / (float)T; /* forward, past both ends */
            AK_CHECK_MSG(compare_run(c, &cur, ts, T) == 0, "kernel %s, shared %d", ak_clip_simd_name(c), shared);
            for (int i = 0; i < T; ++i) ts[i] = ak_rng_range(&rng, -0.5f, 1.5f);
            AK_CHECK_MSG(compare_run(c, &cur, ts, T) == 0, "kernel %s, shared %d (random)", ak_clip_simd_name(c), shared);
        }
        free(seg);
        ak_clip_destroy(c);
    }
}

AK_TEST(cursor_is_bit_identical_to_binary_search) {
    ak_rng rng = ak_rng_make(12);
    static float store[200000];
    for (int common = 0; common < 2; ++common) {
    ak_clip* c = random_clip(&rng, store, sizeof store / sizeof store[0], common == 1);
    AK_CHECK(c != NULL);
    if (!c) return;
    /* Two cursors: the full storage (segments and the key cache, SIMD lanes) and the minimum
     * (segments only, one channel at a time); the storage starts at an odd element so the cache
     * has to align itself. */
    size_t full = ak_clip_cursor_storage_count(c);
    AK_CHECK(full >= ak_clip_channel_count(c));
    uint32_t* seg = (uint32_t*)calloc(full + 1, sizeof *seg);
    char dflt[16];
    snprintf(dflt, sizeof dflt, "%s", ak_clip_simd_name(c));
    /* pass 0..3: the full storage with each sampling kernel this CPU has (scalar, SSE2, AVX2,
     * AVX-512; the same floats), pass 4: the minimum storage with the default kernel */
    for (int pass = 0; pass < 5; ++pass) {
        static const ak_clip_simd lims[5] = {AK_CLIP_SIMD_SCALAR, AK_CLIP_SIMD_SSE2, AK_CLIP_SIMD_AVX2,
                                             AK_CLIP_SIMD_AVX512, AK_CLIP_SIMD_DEFAULT};
        AK_CHECK_EQ(ak_clip_set_simd_limit(c, lims[pass]), AK_OK);
        if (pass > 0 && pass < 4 && !strcmp(ak_clip_simd_name(c), "scalar")) continue; /* no SIMD build */
        if (pass == 2 && strcmp(ak_clip_simd_name(c), "avx2") != 0) continue;     /* not on this CPU */
        if (pass == 3 && strcmp(ak_clip_simd_name(c), "avx512") != 0) continue;
        /* the default kernel gets every sequence; the narrower ones a quarter of each (time) */
        const bool all = pass == 4 || !strcmp(ak_clip_simd_name(c), dflt);
        printf("  common %d, storage %s, kernel %s%s\n", common, pass < 4 ? "full" : "minimum", ak_clip_simd_name(c),
               all ? "" : " (short)");
        ak_clip_cursor cur;
        ak_u32_span st = pass < 4 ? (ak_u32_span){seg + 1, full} : (ak_u32_span){seg, ak_clip_channel_count(c)};
        AK_CHECK_EQ(ak_clip_cursor_init(&cur, c, st), AK_OK);
        enum { TMAX = 6000 };
        static float times[TMAX];
        /* the samples: all of them for the default kernel, a quarter for the narrower ones; an
         * eighth of those under valgrind (AK_TEST_SELECT=light) */
        const int nt = AK_TEST_REPS(all ? TMAX : TMAX / 4, all ? TMAX / 8 : TMAX / 32);
        float dur = ak_clip_duration(c);
        /* Forward, backward, looping (3.3 loops), random; plus times outside the keys and on keys. */
        for (int i = 0; i < nt; ++i) times[i] = -1.0f + (dur + 2.0f) * (float)i / (float)nt;
        AK_CHECK_EQ(compare_run(c, &cur, times, nt), 0);
        for (int i = 0; i < nt; ++i) times[i] = dur + 1.0f - (dur + 2.0f) * (float)i / (float)nt;
        AK_CHECK_EQ(compare_run(c, &cur, times, nt), 0);
        for (int i = 0; i < nt; ++i) times[i] = ak_time_wrap(3.3f * dur * (float)i / (float)nt, dur, AK_WRAP_LOOP);
        AK_CHECK_EQ(compare_run(c, &cur, times, nt), 0);
        for (int i = 0; i < nt; ++i) times[i] = ak_rng_range(&rng, -1.0f, dur + 1.0f);
        AK_CHECK_EQ(compare_run(c, &cur, times, nt), 0);
        /* on keys, next to keys, infinities and NaN */
        for (size_t ci = 0; ci < (all ? ak_clip_channel_count(c) : 2u); ++ci) {
            ak_f32_cspan kt = ak_track_times(ak_clip_channel_track(c, ci));
            AK_CHECK_EQ(compare_run(c, &cur, kt.ptr, kt.count), 0);
            for (size_t k = 0; k < kt.count; ++k) {
                float near[2] = {nextafterf(kt.ptr[k], -INFINITY), nextafterf(kt.ptr[k], INFINITY)};
                AK_CHECK_EQ(compare_run(c, &cur, near, 2), 0);
            }
        }
        float odd[5] = {INFINITY, -INFINITY, NAN, 0.5f, -0.0f};
        AK_CHECK_EQ(compare_run(c, &cur, odd, 5), 0);
    }
    AK_CHECK_EQ(ak_clip_set_simd_limit(c, AK_CLIP_SIMD_COUNT), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_clip_set_simd_limit(NULL, AK_CLIP_SIMD_DEFAULT), AK_ERR_NULL_ARG);
    AK_CHECK(!strcmp(ak_clip_simd_name(NULL), ""));
    free(seg);
    ak_clip_destroy(c);
    }
}

/* One cursor kept across kernel changes: the scalar kernel moves the cursor's segments but
 * not its key cache, so a SIMD kernel afterwards must not take the cache for the segment
 * before the cursor's (the forward step reuses the cached keys only when the cache's interval
 * is that segment's). Clips with shared key times (one interval for the whole cache) and own
 * ones; forward playback, the kernel picked at random for every sample. */
AK_TEST(key_cache_survives_kernel_changes) {
    ak_rng rng = ak_rng_make(31);
    static float store[200000];
    for (int common = 0; common < 2; ++common) {
        ak_clip* c = random_clip(&rng, store, sizeof store / sizeof store[0], common == 1);
        AK_CHECK(c != NULL);
        if (!c) return;
        size_t full = ak_clip_cursor_storage_count(c);
        uint32_t* seg = (uint32_t*)calloc(full, sizeof *seg);
        ak_clip_cursor cur;
        AK_CHECK_EQ(ak_clip_cursor_init(&cur, c, (ak_u32_span){seg, full}), AK_OK);
        const float dur = ak_clip_duration(c);
        int bad = 0;
        /* 40 sweeps of 80 samples, about three per key interval (some intervals are shorter),
         * each sample with a random kernel */
        for (int sweep = 0; sweep < 40; ++sweep) {
            const float t0 = ak_rng_range(&rng, -0.3f, 0.0f);
            for (int i = 0; i < 80; ++i) {
                AK_CHECK_EQ(ak_clip_set_simd_limit(c, (ak_clip_simd)(AK_CLIP_SIMD_SCALAR + ak_rng_u32(&rng) % 4)), AK_OK);
                float t = t0 + (dur + 0.6f) * (float)i / 80.0f;
                bad += compare_run(c, &cur, &t, 1);
            }
        }
        AK_CHECK_MSG(bad == 0, "common %d: %d samples differ from the binary search", common, bad);
        free(seg);
        ak_clip_destroy(c);
    }
}

/* A NaN sample between two samples in one key interval, on rotation channels with equal
 * neighbouring keys (motion capture holds a pose: the key cache redoes such slerp segments in
 * scalar code, from the cursor's segments, which the NaN sample must not move). */
AK_TEST(cursor_nan_sample_keeps_degenerate_segments_exact) {
    enum { K = 6, NC = 6 };
    static const float kt[K] = {0, 1, 2, 3, 4, 5}, ang[K] = {0.0f, 0.3f, 0.3f, 0.9f, 0.9f, 1.4f};
    static float rv[NC][K * 4];
    ak_raw_channel ch[NC];
    for (int c = 0; c < NC; ++c) {
        for (int k = 0; k < K; ++k) {
            ak_quat q = ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(1, 0.2f * (float)c, 0.1f)),
                                                ang[k] * (1.0f + 0.1f * (float)c));
            rv[c][4 * k] = q.x, rv[c][4 * k + 1] = q.y, rv[c][4 * k + 2] = q.z, rv[c][4 * k + 3] = q.w;
        }
        ch[c] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION, .index = (uint32_t)c, .key_count = K, .times = kt,
                                 .values = rv[c]};
    }
    ak_raw_clip raw = {.channels = ch, .channel_count = NC, .joint_count = CJ};
    ak_clip* c = build(&raw);
    AK_CHECK(c != NULL);
    if (!c) return;
    size_t full = ak_clip_cursor_storage_count(c);
    uint32_t* st = (uint32_t*)calloc(full, sizeof *st);
    int bad = 0;
    for (int x = 0; x < 4 * K; ++x)
        for (int y = 0; y < 4 * K; ++y) {
            ak_clip_cursor cur;
            AK_CHECK_EQ(ak_clip_cursor_init(&cur, c, (ak_u32_span){st, full}), AK_OK);
            const float seq[3] = {0.25f * (float)x - 0.6f, NAN, 0.25f * (float)y - 0.4f};
            bad += compare_run(c, &cur, seq, 3);
        }
    AK_CHECK_MSG(bad == 0, "%d samples after a NaN differ from binary search", bad);
    free(st);
    ak_clip_destroy(c);
}

/* ---- inline sampler against the per-track evaluator and double-precision slerp -------- */

AK_TEST(inline_sampler_matches_track_eval_and_double_slerp) {
    ak_rng rng = ak_rng_make(21);
    static float store[200000];
    double worst = 0.0;
    for (int rep = 0; rep < 6; ++rep) {
        ak_clip* c = random_clip(&rng, store, sizeof store / sizeof store[0], rep >= 4);
        AK_CHECK(c != NULL);
        if (!c) return;
        uint32_t seg[4096];
        ak_clip_cursor cur;
        AK_CHECK(ak_clip_cursor_storage_count(c) <= 4096);
        AK_CHECK_EQ(ak_clip_cursor_init(&cur, c, (ak_u32_span)AK_SPAN(seg)), AK_OK);
        enum { T = 3000 };
        const int nt = AK_TEST_REPS(T, T / 8); /* the samples (fewer under valgrind) */
        static float times[T];
        float dur = ak_clip_duration(c);
        /* forward at a small step, backwards, random seeks, all reaching outside the keys */
        for (int i = 0; i < nt; ++i) times[i] = -1.0f + (dur + 2.0f) * (float)i / (float)nt;
        AK_CHECK_EQ(ref_clip_check_against_tracks(c, &cur, times, nt, CJ, &worst), 0);
        for (int i = 0; i < nt; ++i) times[i] = dur + 1.0f - (dur + 2.0f) * (float)i / (float)nt;
        AK_CHECK_EQ(ref_clip_check_against_tracks(c, &cur, times, nt, CJ, &worst), 0);
        for (int i = 0; i < nt; ++i) times[i] = ak_rng_range(&rng, -1.0f, dur + 1.0f);
        AK_CHECK_EQ(ref_clip_check_against_tracks(c, &cur, times, nt, CJ, &worst), 0);
        AK_CHECK_EQ(ref_clip_check_against_tracks(c, NULL, times, nt, CJ, &worst), 0);
        ak_clip_destroy(c);
    }
    /* Large angles up to the shortest-arc limit (pi/2 per half-angle) and nearly parallel keys. */
    enum { N = 64 };
    float kt[N], kv[N * 4];
    float t = 0.0f;
    for (int k = 0; k < N; ++k) {
        kt[k] = t;
        t += ak_rng_range(&rng, 0.001f, 0.7f);
        ak_quat q = random_quat(&rng);
        if (k % 4 == 3) {
            const float* p = kv + (k - 1) * 4;
            q = ak_quat_normalize(ak_quat_make(p[0] + 1e-5f, p[1], p[2], p[3]));
        }
        if (k % 5 == 2) q = ak_quat_neg(q);
        kv[k * 4] = q.x, kv[k * 4 + 1] = q.y, kv[k * 4 + 2] = q.z, kv[k * 4 + 3] = q.w;
    }
    ak_raw_channel ch = {.target = AK_CHANNEL_ROTATION, .key_count = N, .times = kt, .values = kv};
    ak_raw_clip raw = {.channels = &ch, .channel_count = 1, .joint_count = 1};
    ak_clip* c = build(&raw);
    AK_CHECK(c != NULL);
    if (c) {
        uint32_t seg[128];
        ak_clip_cursor cur;
        AK_CHECK(ak_clip_cursor_storage_count(c) <= 128);
        ak_clip_cursor_init(&cur, c, (ak_u32_span)AK_SPAN(seg));
        enum { T = 20000 };
        const int nt = AK_TEST_REPS(T, T / 8); /* the samples (fewer under valgrind) */
        static float times[T];
        for (int i = 0; i < nt; ++i) times[i] = -0.5f + (t + 1.0f) * (float)i / (float)nt;
        AK_CHECK_EQ(ref_clip_check_against_tracks(c, &cur, times, nt, 1, &worst), 0);
        ak_clip_destroy(c);
    }
    printf("  max |component| error of LINEAR rotations vs double-precision slerp: %.2e\n", worst);
    AK_CHECK(worst < 1e-6);
}

/* ---- keyframe reduction ---------------------------------------------------------------- */

/* Largest model-space distance between the two clips' joint origins and axis points at r. */
static double reduce_model_error(const ak_clip* a, const ak_clip* b, float t, const int32_t* parents,
                                 const ak_transform* rest, size_t n, float r) {
    ak_transform pa[8], pb[8];
    ak_mat4 ma[8], mb[8];
    memcpy(pa, rest, n * sizeof *pa);
    memcpy(pb, rest, n * sizeof *pb);
    ak_clip_sample(a, t, NULL, (ak_transform_span){pa, n}, (ak_f32_span){0}, (ak_f32_span){0});
    ak_clip_sample(b, t, NULL, (ak_transform_span){pb, n}, (ak_f32_span){0}, (ak_f32_span){0});
    double worst = 0.0;
    for (size_t j = 0; j < n; ++j) {
        ma[j] = ak_transform_to_mat4(pa[j]);
        mb[j] = ak_transform_to_mat4(pb[j]);
        if (parents[j] >= 0) ma[j] = ak_mat4_mul(ma[parents[j]], ma[j]), mb[j] = ak_mat4_mul(mb[parents[j]], mb[j]);
        const ak_vec3 pts[4] = {{0, 0, 0}, {r, 0, 0}, {0, r, 0}, {0, 0, r}};
        for (int p = 0; p < 4; ++p)
            worst = fmax(worst, ak_vec3_distance(ak_mat4_transform_point(ma[j], pts[p]),
                                                 ak_mat4_transform_point(mb[j], pts[p])));
    }
    return worst;
}

AK_TEST(reduce_keeps_model_error_within_tolerance) {
    /* A 6-joint chain with smooth T/R/S motion at 60 keys/s over 4 s (LINEAR, NLERP on one
     * joint, non-uniform key times), a STEP channel and morph weights (copied unchanged). */
    enum { NJ = 6, K = 241 };
    const int32_t parents[NJ] = {-1, 0, 1, 2, 1, 4};
    ak_transform rest[NJ];
    for (int j = 0; j < NJ; ++j) rest[j] = ak_transform_identity(), rest[j].translation = ak_vec3_make(0, 0.4f, 0);
    static float kt[K], tv[NJ][K * 3], rv[NJ][K * 4], sv[NJ][K * 3], wv[K * 2];
    for (int k = 0; k < K; ++k) kt[k] = (float)k / 60.0f + (k % 3 == 1 ? 0.004f : 0.0f);
    ak_raw_channel ch[3 * NJ + 1];
    size_t nch = 0;
    for (int j = 0; j < NJ; ++j) {
        for (int k = 0; k < K; ++k) {
            float t = kt[k], ph = (float)j;
            tv[j][3 * k] = 0.05f * sinf(2.0f * t + ph), tv[j][3 * k + 1] = 0.4f, tv[j][3 * k + 2] = 0.02f * t;
            ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(1, 0.3f * ph, 0.2f), 0.9f * sinf(3.0f * t + ph));
            rv[j][4 * k] = q.x, rv[j][4 * k + 1] = q.y, rv[j][4 * k + 2] = q.z, rv[j][4 * k + 3] = q.w;
            sv[j][3 * k] = sv[j][3 * k + 1] = sv[j][3 * k + 2] = 1.0f + 0.1f * sinf(1.5f * t + ph);
        }
        ak_interp rot = j == 3 ? AK_INTERP_NLERP : j == 4 ? AK_INTERP_STEP : AK_INTERP_LINEAR;
        ch[nch++] = (ak_raw_channel){.target = AK_CHANNEL_TRANSLATION, .index = (uint32_t)j, .key_count = K, .times = kt,
                                     .values = tv[j]};
        ch[nch++] = (ak_raw_channel){.target = AK_CHANNEL_ROTATION, .index = (uint32_t)j, .interp = rot, .key_count = K,
                                     .times = kt, .values = rv[j]};
        ch[nch++] = (ak_raw_channel){.target = AK_CHANNEL_SCALE, .index = (uint32_t)j, .key_count = K, .times = kt,
                                     .values = sv[j]};
    }
    for (int k = 0; k < K; ++k) wv[2 * k] = 0.5f, wv[2 * k + 1] = (float)k / K;
    ch[nch++] = (ak_raw_channel){.target = AK_CHANNEL_MORPH_WEIGHTS, .component_count = 2, .key_count = K, .times = kt,
                                 .values = wv};
    ak_raw_clip raw = {.channels = ch, .channel_count = nch, .joint_count = NJ, .morph_weight_count = 2};
    ak_clip* c = build(&raw);
    AK_CHECK(c != NULL);
    if (!c) return;
    const float tols[3] = {1e-2f, 1e-3f, 1e-4f};
    size_t last_keys = 0;
    for (int ti = 0; ti < 3; ++ti) {
        ak_clip_reduce_desc d = {.parents = parents, .rest_pose = {rest, NJ}, .tolerance = tols[ti], .distance = 0.1f};
        ak_clip* r = NULL;
        double err = -1.0;
        AK_CHECK_EQ(ak_clip_reduce(c, &d, NULL, &r, &err, NULL), AK_OK);
        if (!r) continue;
        size_t before = 0, after = 0;
        for (size_t i = 0; i < nch; ++i) {
            before += ak_clip_channel_key_count(c, i), after += ak_clip_channel_key_count(r, i);
            ak_interp in = ak_clip_channel_interp(c, i);
            bool copied = in == AK_INTERP_STEP || ak_clip_channel_target(c, i) == AK_CHANNEL_MORPH_WEIGHTS;
            if (copied) AK_CHECK_EQ(ak_clip_channel_key_count(r, i), K);
            AK_CHECK_EQ(ak_clip_channel_interp(r, i), in);
        }
        /* the promise: within tolerance at every key time and key-interval midpoint */
        double at_keys = 0.0, dense = 0.0;
        for (int k = 0; k < K; ++k) {
            at_keys = fmax(at_keys, reduce_model_error(c, r, kt[k], parents, rest, NJ, 0.1f));
            if (k + 1 < K)
                at_keys = fmax(at_keys, reduce_model_error(c, r, 0.5f * (kt[k] + kt[k + 1]), parents, rest, NJ, 0.1f));
        }
        for (int i = 0; i <= 4000; ++i) dense = fmax(dense, reduce_model_error(c, r, -0.5f + 5.0f * (float)i / 4000.0f,
                                                                               parents, rest, NJ, 0.1f));
        printf("  tolerance %g: %zu -> %zu keys, model error %.3g at keys (reported %.3g), %.3g on 4001 times\n",
               (double)tols[ti], before, after, at_keys, err, dense);
        AK_CHECK(at_keys <= tols[ti]);
        AK_CHECK(fabs(at_keys - err) <= 1e-9 + 1e-6 * err);
        AK_CHECK(dense <= 2.0 * tols[ti]);
        AK_CHECK(after < before);
        AK_CHECK(after > last_keys); /* a tighter tolerance keeps more keys */
        last_keys = after;
        ak_clip_destroy(r);
    }
    /* Keys on a straight line reduce to the two ends, exactly. */
    {
        float lt[5] = {0, 1, 2, 3, 4}, lv[15];
        for (int k = 0; k < 5; ++k) lv[3 * k] = 2.0f * (float)k, lv[3 * k + 1] = -1.0f, lv[3 * k + 2] = 0.5f * (float)k;
        ak_raw_channel lc = {.target = AK_CHANNEL_TRANSLATION, .key_count = 5, .times = lt, .values = lv};
        ak_raw_clip lr = {.channels = &lc, .channel_count = 1, .joint_count = 1};
        ak_clip* l = build(&lr);
        const int32_t p1[1] = {-1};
        ak_transform r1 = ak_transform_identity();
        ak_clip_reduce_desc d = {.parents = p1, .rest_pose = {&r1, 1}};
        ak_clip* out = NULL;
        AK_CHECK_EQ(ak_clip_reduce(l, &d, NULL, &out, NULL, NULL), AK_OK);
        AK_CHECK_EQ(ak_clip_channel_key_count(out, 0), 2);
        ak_clip_destroy(out);
        ak_clip_destroy(l);
    }
    /* Errors. */
    ak_clip* out = (ak_clip*)&out;
    ak_clip_reduce_desc d = {.parents = parents, .rest_pose = {rest, NJ}};
    AK_CHECK_EQ(ak_clip_reduce(c, NULL, NULL, &out, NULL, NULL), AK_ERR_NULL_ARG);
    AK_CHECK(out == NULL);
    d.tolerance = -1.0f;
    AK_CHECK_EQ(ak_clip_reduce(c, &d, NULL, &out, NULL, NULL), AK_ERR_BAD_ARG);
    d.tolerance = 0.0f;
    d.rest_pose.count = NJ - 1;
    AK_CHECK_EQ(ak_clip_reduce(c, &d, NULL, &out, NULL, NULL), AK_ERR_SPAN_SMALL);
    d.rest_pose.count = NJ;
    const int32_t bad[NJ] = {-1, 0, 3, 2, 1, 4};
    d.parents = bad;
    AK_CHECK_EQ(ak_clip_reduce(c, &d, NULL, &out, NULL, NULL), AK_ERR_BAD_INDEX);
    ak_raw_channel card = ch[0];
    card.interp = AK_INTERP_CARDINAL;
    ak_raw_clip craw = {.channels = &card, .channel_count = 1, .joint_count = NJ};
    ak_clip* cc = build(&craw);
    d.parents = parents;
    AK_CHECK_EQ(ak_clip_reduce(cc, &d, NULL, &out, NULL, NULL), AK_ERR_UNSUPPORTED);
    AK_CHECK(out == NULL);
    ak_clip_destroy(cc);
    /* A non-finite rest pose is bad data; one whose model positions overflow float (scales of
     * 1e30 on a parent and a child: 1e60) must not pass the check with a NaN error. */
    ak_transform nrest[NJ];
    for (int j = 0; j < NJ; ++j) nrest[j] = rest[j];
    nrest[2].scale.y = NAN;
    d.rest_pose = (ak_transform_cspan){nrest, NJ};
    AK_CHECK_EQ(ak_clip_reduce(c, &d, NULL, &out, NULL, NULL), AK_ERR_BAD_DATA);
    AK_CHECK(out == NULL);
    {
        float lt[5] = {0, 1, 2, 3, 4}, lv[15];
        for (int k = 0; k < 5; ++k) lv[3 * k] = (float)k, lv[3 * k + 1] = (float)(k * k), lv[3 * k + 2] = 0.0f;
        ak_raw_channel lc = {.target = AK_CHANNEL_TRANSLATION, .index = 1, .key_count = 5, .times = lt, .values = lv};
        ak_raw_clip lr = {.channels = &lc, .channel_count = 1, .joint_count = 2};
        ak_clip* l = build(&lr);
        const int32_t p2[2] = {-1, 0};
        ak_transform r2[2] = {ak_transform_identity(), ak_transform_identity()};
        r2[0].scale = r2[1].scale = ak_vec3_splat(1e30f);
        ak_clip_reduce_desc od = {.parents = p2, .rest_pose = {r2, 2}};
        double err = 0.0;
        AK_CHECK_EQ(ak_clip_reduce(l, &od, NULL, &out, &err, NULL), AK_OK);
        AK_CHECK_MSG(isinf(err), "overflowing model positions: error %g, expected infinity", err);
        AK_CHECK(out != NULL && ak_clip_channel_key_count(out, 0) == 5);
        ak_clip_destroy(out);
        ak_clip_destroy(l);
    }
    ak_clip_destroy(c);
}

/* ---- blending ----------------------------------------------------------------------- */

AK_TEST(blend_properties) {
    enum { J = 16 };
    ak_rng rng = ak_rng_make(13);
    ak_transform a[J], b[J], rest[J], out[J];
    for (int j = 0; j < J; ++j) {
        a[j] = random_transform(&rng);
        b[j] = random_transform(&rng);
        rest[j] = random_transform(&rng);
    }
    /* Weights summing to 1 of identical poses (one stored with negated quaternions). */
    ak_transform an[J];
    for (int j = 0; j < J; ++j) {
        an[j] = a[j];
        an[j].rotation = ak_quat_neg(a[j].rotation);
    }
    ak_blend_layer same[3] = {{.pose = {a, J}, .weight = 0.2f}, {.pose = {an, J}, .weight = 0.5f}, {.pose = {a, J}, .weight = 0.3f}};
    ak_blend_job job = {.layers = same, .layer_count = 3, .rest_pose = {rest, J}, .out_local = {out, J}};
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) {
        AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, a[j].translation), 0.0, 1e-6);
        AK_CHECK_NEAR(ak_vec3_distance(out[j].scale, a[j].scale), 0.0, 1e-6);
        AK_CHECK_NEAR(rot_error(out[j].rotation, a[j].rotation), 0.0, 1e-6);
    }
    /* Two poses 0.25 / 0.75: translation by the closed form, rotation the normalised sum. */
    ak_blend_layer two[2] = {{.pose = {a, J}, .weight = 1.0f}, {.pose = {b, J}, .weight = 3.0f}};
    job.layers = two;
    job.layer_count = 2;
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) {
        ak_vec3 t = ak_vec3_add(ak_vec3_scale(a[j].translation, 0.25f), ak_vec3_scale(b[j].translation, 0.75f));
        AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, t), 0.0, 1e-5);
        ak_quat qb = ak_quat_dot(a[j].rotation, b[j].rotation) < 0 ? ak_quat_neg(b[j].rotation) : b[j].rotation;
        ak_quat q = ak_quat_normalize(ak_quat_add(ak_quat_scale(a[j].rotation, 0.25f), ak_quat_scale(qb, 0.75f)));
        AK_CHECK_NEAR(rot_error(out[j].rotation, q), 0.0, 1e-6);
    }
    /* Masks: b only on the upper half; the lower half is exactly a. */
    float mask[J];
    for (int j = 0; j < J; ++j) mask[j] = j < J / 2 ? 0.0f : 1.0f;
    ak_blend_layer masked[2] = {{.pose = {a, J}, .weight = 1.0f}, {.pose = {b, J}, .weight = 1.0f, .joint_weights = {mask, J}}};
    job.layers = masked;
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) {
        if (j < J / 2) {
            AK_CHECK(memcmp(&out[j], &a[j], sizeof(ak_transform)) == 0);
        } else {
            ak_vec3 t = ak_vec3_scale(ak_vec3_add(a[j].translation, b[j].translation), 0.5f);
            AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, t), 0.0, 1e-5);
        }
    }
    /* No weight at all -> the rest pose. */
    ak_blend_layer none[1] = {{.pose = {a, J}, .weight = 0.0f}};
    job.layers = none;
    job.layer_count = 1;
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, rest[j].translation), 0.0, 1e-6);
}

AK_TEST(additive_layers) {
    enum { J = 12 };
    ak_rng rng = ak_rng_make(14);
    ak_transform ref[J], pose[J], base[J], delta[J], out[J], rest[J];
    for (int j = 0; j < J; ++j) {
        ref[j] = random_transform(&rng);
        pose[j] = random_transform(&rng);
        base[j] = random_transform(&rng);
        rest[j] = ak_transform_identity();
    }
    /* The additive delta of the reference pose is the identity: adding it changes nothing. */
    AK_CHECK_EQ(ak_pose_additive_delta((ak_transform_cspan){ref, J}, (ak_transform_cspan){ref, J}, (ak_transform_span){delta, J}),
                AK_OK);
    ak_blend_layer l = {.pose = {base, J}, .weight = 1.0f}, add = {.pose = {delta, J}, .weight = 1.0f};
    ak_blend_job job = {.layers = &l, .layer_count = 1, .additive_layers = &add, .additive_count = 1, .rest_pose = {rest, J},
                        .out_local = {out, J}};
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) {
        AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, base[j].translation), 0.0, 1e-6);
        AK_CHECK_NEAR(ak_vec3_distance(out[j].scale, base[j].scale), 0.0, 1e-6);
        AK_CHECK_NEAR(rot_error(out[j].rotation, base[j].rotation), 0.0, 1e-6);
    }
    /* Reference + delta(pose) at weight 1 reproduces pose; weight 0 leaves the reference. */
    ak_pose_additive_delta((ak_transform_cspan){pose, J}, (ak_transform_cspan){ref, J}, (ak_transform_span){delta, J});
    l.pose = (ak_transform_cspan){ref, J};
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) {
        AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, pose[j].translation), 0.0, 1e-5);
        AK_CHECK_NEAR(ak_vec3_distance(out[j].scale, pose[j].scale), 0.0, 1e-5);
        AK_CHECK_NEAR(rot_error(out[j].rotation, pose[j].rotation), 0.0, 1e-6);
    }
    add.weight = 0.0f;
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    for (int j = 0; j < J; ++j) AK_CHECK_NEAR(rot_error(out[j].rotation, ref[j].rotation), 0.0, 1e-6);
}

AK_TEST(crossfade) {
    enum { J = 8 };
    ak_rng rng = ak_rng_make(15);
    ak_transform a[J], b[J], out[J];
    for (int j = 0; j < J; ++j) a[j] = random_transform(&rng), b[j] = random_transform(&rng);
    ak_transform_cspan ca = {a, J}, cb = {b, J};
    AK_CHECK_EQ(ak_pose_crossfade(ca, cb, 0.0f, (ak_transform_span){out, J}), AK_OK);
    for (int j = 0; j < J; ++j) AK_CHECK_NEAR(ak_vec3_distance(out[j].translation, a[j].translation), 0.0, 0);
    AK_CHECK_EQ(ak_pose_crossfade(ca, cb, 2.0f, (ak_transform_span){out, J}), AK_OK);
    for (int j = 0; j < J; ++j) AK_CHECK_NEAR(rot_error(out[j].rotation, b[j].rotation), 0.0, 1e-6);
    AK_CHECK_EQ(ak_pose_crossfade(ca, cb, 0.5f, (ak_transform_span){out, J}), AK_OK);
    for (int j = 0; j < J; ++j) {
        /* Halfway: equal angles to both ends. */
        AK_CHECK_NEAR(ak_quat_angle_between(out[j].rotation, a[j].rotation),
                      ak_quat_angle_between(out[j].rotation, b[j].rotation), 1e-3);
    }
    AK_CHECK_EQ(ak_pose_crossfade(ca, (ak_transform_cspan){b, 2}, 0.5f, (ak_transform_span){out, J}), AK_ERR_SPAN_SMALL);
}

AK_TEST(blend_huge_weights_stay_finite) {
    /* Valid finite weights near FLT_MAX: the weighted sums used to overflow to inf and the
     * output was inf / inf = NaN. The blend is an average, so it must equal the one with the
     * weights scaled down (here 1:1 -> the midpoint, closed form). Also huge translations with
     * ordinary weights. */
    ak_transform rest[1] = {ak_transform_identity()}, a[1], b[1], out[1];
    a[0] = b[0] = rest[0];
    a[0].translation = ak_vec3_make(2, 0, -6);
    b[0].translation = ak_vec3_make(4, 2, 6);
    a[0].scale = ak_vec3_make(1, 1, 1);
    b[0].scale = ak_vec3_make(3, 3, 3);
    a[0].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.5f);
    b[0].rotation = ak_quat_neg(ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.5f)); /* other hemisphere */
    const float big[3] = {3e38f, 2e38f, 1e38f};
    for (int k = 0; k < 3; ++k) {
        ak_blend_layer l[2] = {{.pose = {a, 1}, .weight = big[k]}, {.pose = {b, 1}, .weight = big[k]}};
        ak_blend_job job = {.layers = l, .layer_count = 2, .rest_pose = {rest, 1}, .out_local = {out, 1}};
        AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
        AK_CHECK_MSG(ak_transform_is_finite(out[0]), "weights %g: non-finite blend", (double)big[k]);
        AK_CHECK_NEAR(ak_vec3_distance(out[0].translation, ak_vec3_make(3, 1, 0)), 0.0, 1e-6);
        AK_CHECK_NEAR(out[0].scale.x, 2.0, 1e-6);
        AK_CHECK_NEAR(rot_error(out[0].rotation, ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 1.0f)), 0.0, 1e-6);
    }
    a[0].translation = ak_vec3_make(3e38f, 0, 0);
    b[0].translation = ak_vec3_make(3e38f, 0, 0);
    ak_blend_layer l[2] = {{.pose = {a, 1}, .weight = 1.0f}, {.pose = {b, 1}, .weight = 1.0f}};
    ak_blend_job job = {.layers = l, .layer_count = 2, .rest_pose = {rest, 1}, .out_local = {out, 1}};
    AK_CHECK_EQ(ak_blend_run(&job), AK_OK);
    AK_CHECK_MSG(ak_transform_is_finite(out[0]), "translations 3e38: %g", (double)out[0].translation.x);
    AK_CHECK_NEAR(out[0].translation.x / 3e38, 1.0, 1e-6);
}

AK_TEST(blend_validate_rules) {
    enum { J = 4 };
    ak_transform p[J], out[J], rest[J];
    for (int j = 0; j < J; ++j) p[j] = rest[j] = ak_transform_identity();
    float mask[J] = {0, 0.5f, 1, 1};
    ak_blend_job zero = {0};
    AK_CHECK_EQ(ak_blend_validate(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blend_run(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blend_validate(NULL), AK_ERR_NULL_ARG);
    ak_blend_layer l = {.pose = {p, J}, .weight = 1.0f, .joint_weights = {mask, J}};
    ak_blend_job ok = {.layers = &l, .layer_count = 1, .rest_pose = {rest, J}, .out_local = {out, J}};
    AK_CHECK_EQ(ak_blend_validate(&ok), AK_OK);
    ak_blend_job j = ok;
    j.layers = NULL;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_NULL_ARG);
    j = ok;
    j.rest_pose.count = 0;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_EMPTY);
    j = ok;
    j.out_local.count = J - 1;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_SPAN_SMALL);
    j = ok;
    j.threshold = -1.0f;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_BAD_ARG);
    ak_blend_layer bad = l;
    j = ok;
    j.layers = &bad;
    bad.pose.count = J - 1;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_SPAN_SMALL);
    bad = l;
    bad.pose.ptr = NULL;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_NULL_ARG);
    bad = l;
    bad.joint_weights.count = 2;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_SPAN_SMALL);
    bad = l;
    bad.weight = -0.5f;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_BAD_ARG);
    bad.weight = NAN;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_BAD_DATA);
    bad = l;
    mask[1] = 1.5f;
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_BAD_DATA);
    mask[1] = 0.5f;
    bad = l;
    bad.pose.ptr = out; /* output overlaps an input */
    AK_CHECK_EQ(ak_blend_validate(&j), AK_ERR_BAD_ARG);
    /* run writes nothing on failure. */
    out[0].translation.x = 42.0f;
    AK_CHECK_EQ(ak_blend_run(&j), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(out[0].translation.x, 42);
}

/* ---- root motion --------------------------------------------------------------------- */

AK_TEST(root_motion_extraction) {
    enum { N = 9 };
    float times[N], lin[N * 3], cub[N * 9], rot[N * 4];
    ak_rng rng = ak_rng_make(16);
    for (int k = 0; k < N; ++k) {
        times[k] = 0.25f * (float)k;
        /* Walking along +x and drifting in z, bobbing in y. */
        lin[k * 3] = 1.0f + 1.5f * times[k];
        lin[k * 3 + 1] = 0.9f + 0.05f * sinf(8.0f * times[k]);
        lin[k * 3 + 2] = -0.5f + 0.3f * times[k] * times[k];
        for (int c = 0; c < 9; ++c) cub[k * 9 + c] = ak_rng_range(&rng, -1, 1);
        memcpy(cub + k * 9 + 3, lin + k * 3, 3 * sizeof(float));
        ak_quat q = random_quat(&rng);
        rot[k * 4] = q.x, rot[k * 4 + 1] = q.y, rot[k * 4 + 2] = q.z, rot[k * 4 + 3] = q.w;
    }
    const ak_interp modes[2] = {AK_INTERP_LINEAR, AK_INTERP_CUBICSPLINE};
    for (int m = 0; m < 2; ++m) {
        ak_raw_channel ch[3] = {
            {.target = AK_CHANNEL_ROTATION, .index = 1, .key_count = N, .times = times, .values = rot},
            {.target = AK_CHANNEL_TRANSLATION, .index = 1, .interp = modes[m], .key_count = N, .times = times,
             .values = m ? cub : lin},
            {.target = AK_CHANNEL_TRANSLATION, .index = 2, .key_count = N, .times = times, .values = lin},
        };
        ak_raw_clip raw = {.name = "walk", .channels = ch, .channel_count = 3, .joint_count = 3};
        ak_clip* clip = build(&raw);
        ak_clip* in_place = NULL;
        ak_track* traj = NULL;
        AK_CHECK_EQ(ak_clip_extract_root_motion(clip, &(ak_root_motion_desc){.root_joint = 1}, NULL, &in_place, &traj), AK_OK);
        if (!in_place || !traj) return;
        AK_CHECK_STREQ(ak_clip_name(in_place), "walk");
        for (int i = 0; i <= 200; ++i) {
            float t = 2.0f * (float)i / 200.0f;
            ak_transform o[3], p[3];
            for (int j = 0; j < 3; ++j) o[j] = p[j] = ak_transform_identity();
            ak_clip_sample(clip, t, NULL, (ak_transform_span)AK_SPAN(o), (ak_f32_span){0}, (ak_f32_span){0});
            ak_clip_sample(in_place, t, NULL, (ak_transform_span)AK_SPAN(p), (ak_f32_span){0}, (ak_f32_span){0});
            float tr[3];
            ak_track_sample(traj, t, (ak_f32_span)AK_SPAN(tr));
            /* In place: x, z held at the first key; y untouched; trajectory carries the rest. */
            AK_CHECK_NEAR(p[1].translation.x, lin[0], 1e-6);
            AK_CHECK_NEAR(p[1].translation.z, lin[2], 1e-6);
            AK_CHECK_NEAR(p[1].translation.y, o[1].translation.y, 1e-6);
            AK_CHECK_NEAR(tr[1], 0.0, 0);
            AK_CHECK_NEAR(p[1].translation.x + tr[0], o[1].translation.x, 2e-6);
            AK_CHECK_NEAR(p[1].translation.z + tr[2], o[1].translation.z, 2e-6);
            /* Other channels are unchanged (bit-exact). */
            AK_CHECK(memcmp(&p[2], &o[2], sizeof p[2]) == 0);
            AK_CHECK(memcmp(&p[1].rotation, &o[1].rotation, sizeof p[1].rotation) == 0);
        }
        ak_clip *x = NULL;
        ak_track* y = NULL;
        AK_CHECK_EQ(ak_clip_extract_root_motion(clip, &(ak_root_motion_desc){.root_joint = 3}, NULL, &x, &y), AK_ERR_BAD_INDEX);
        AK_CHECK(x == NULL && y == NULL);
        /* Root without translation: unchanged copy, zero trajectory. */
        AK_CHECK_EQ(ak_clip_extract_root_motion(clip, NULL, NULL, &x, &y), AK_OK);
        float z[3] = {1, 1, 1};
        ak_track_sample(y, 1.0f, (ak_f32_span)AK_SPAN(z));
        AK_CHECK(z[0] == 0.0f && z[1] == 0.0f && z[2] == 0.0f);
        ak_clip_destroy(x);
        ak_track_destroy(y);
        ak_clip_destroy(in_place);
        ak_track_destroy(traj);
        ak_clip_destroy(clip);
    }
}


AK_TEST(custom_allocator_is_used_and_balanced) {
    /* every build frees what it allocates, through the given allocator */
    ak_test_counter cnt = {0};
    ak_allocator a = ak_test_counting_allocator(&cnt);
    float t[3] = {2, 0, 1}, v[9] = {0, 0, 0, 1, 1, 1, 2, 2, 2};
    ak_raw_channel ch = {.target = AK_CHANNEL_TRANSLATION, .interp = AK_INTERP_NATURAL, .key_count = 3, .times = t, .values = v};
    ak_raw_clip raw = {.channels = &ch, .channel_count = 1, .joint_count = 1};
    ak_clip* c = NULL;
    AK_CHECK_EQ(ak_clip_build(&raw, &a, &c, NULL), AK_OK);
    AK_CHECK_EQ(cnt.live, 1);
    ak_clip* ip = NULL;
    ak_track* tr = NULL;
    AK_CHECK_EQ(ak_clip_extract_root_motion(c, NULL, &a, &ip, &tr), AK_OK);
    AK_CHECK_EQ(cnt.live, 3);
    ak_clip_destroy(ip);
    ak_track_destroy(tr);
    ak_clip_destroy(c);
    AK_CHECK_EQ(cnt.live, 0);
}

/* Baking: joint 0 turns about Y at 1 rad/s and moves along X at 2 units/s, joint 1 stays at
 * its rest pose; 10 frames at 10 fps. Closed forms: at a frame time the pose itself; between
 * frames lerp gives the exact linear translation and slerp of two rotations about one axis
 * the rotation by the interpolated angle. */
AK_TEST(bake_pose_sequence) {
    enum { F = 10, J = 2 };
    ak_transform poses[F * J], rest[J];
    rest[0] = ak_transform_identity();
    rest[1] = ak_transform_make(ak_vec3_make(0, 1, 0), ak_quat_from_axis_angle(ak_vec3_make(1, 0, 0), 0.5f), ak_vec3_make(1, 1, 1));
    float wts[F * 2];
    for (int f = 0; f < F; ++f) {
        float t = 0.1f * (float)f;
        poses[f * J] = ak_transform_make(ak_vec3_make(2.0f * t, 0, 0), ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), t), ak_vec3_make(1, 1, 1));
        poses[f * J + 1] = rest[1];
        wts[2 * f] = t, wts[2 * f + 1] = 1.0f - t;
    }
    ak_clip_bake_desc d = {.poses = poses, .frame_count = F, .joint_count = J, .frame_rate = 10.0f,
                           .morph_weights = wts, .morph_weight_count = 2, .rest_pose = {rest, J}, .name = "baked"};
    ak_clip* clip = NULL;
    AK_CHECK_EQ(ak_clip_bake(&d, NULL, &clip, NULL), AK_OK);
    if (!clip) return;
    /* joint 0: translation and rotation move, scale is the rest's; joint 1 no channel; weights */
    AK_CHECK_EQ(ak_clip_channel_count(clip), 3u);
    AK_CHECK_STREQ(ak_clip_name(clip), "baked");
    AK_CHECK_NEAR(ak_clip_duration(clip), 0.9, 1e-6);
    for (int k = 0; k < 2 * F - 1; ++k) {
        float t = 0.05f * (float)k;
        ak_transform local[J] = {rest[0], rest[1]};
        float w[2] = {0, 0};
        AK_CHECK_EQ(ak_clip_sample(clip, t, NULL, (ak_transform_span)AK_SPAN(local), (ak_f32_span)AK_SPAN(w), (ak_f32_span){0}), AK_OK);
        AK_CHECK_NEAR(local[0].translation.x, 2.0 * t, 1e-5);
        ak_quat e = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), t);
        AK_CHECK_NEAR(fabs(ak_quat_dot(local[0].rotation, e)), 1.0, 1e-6);
        AK_CHECK_NEAR(w[0], t, 1e-6);
        AK_CHECK_NEAR(w[1], 1.0 - t, 1e-6);
        AK_CHECK_EQ(local[1].rotation.x, rest[1].rotation.x);
    }
    ak_clip_destroy(clip);
    /* without rest_pose every joint gets T, R, S; step keys hold */
    d.rest_pose = (ak_transform_cspan){0};
    d.step = true;
    AK_CHECK_EQ(ak_clip_bake(&d, NULL, &clip, NULL), AK_OK);
    AK_CHECK_EQ(ak_clip_channel_count(clip), 7u);
    AK_CHECK_EQ(ak_clip_channel_interp(clip, 0), AK_INTERP_STEP);
    ak_clip_destroy(clip);
    /* rules */
    AK_CHECK_EQ(ak_clip_bake(NULL, NULL, &clip, NULL), AK_ERR_NULL_ARG);
    ak_clip_bake_desc e = d;
    e.frame_count = 0;
    AK_CHECK_EQ(ak_clip_bake(&e, NULL, &clip, NULL), AK_ERR_EMPTY);
    e = d, e.frame_rate = -1.0f;
    AK_CHECK_EQ(ak_clip_bake(&e, NULL, &clip, NULL), AK_ERR_BAD_ARG);
    e = d, e.morph_weights = NULL;
    AK_CHECK_EQ(ak_clip_bake(&e, NULL, &clip, NULL), AK_ERR_NULL_ARG);
    e = d, e.rest_pose = (ak_transform_cspan){rest, 1};
    AK_CHECK_EQ(ak_clip_bake(&e, NULL, &clip, NULL), AK_ERR_SPAN_SMALL);
    poses[3].translation.y = NAN;
    ak_diag diag;
    AK_CHECK_EQ(ak_clip_bake(&d, NULL, &clip, &diag), AK_ERR_BAD_DATA);
    AK_CHECK(strstr(diag.message, "frame 1 joint 1") != NULL);
    AK_CHECK(clip == NULL);
}

/* Overlapping channels are found in any input order (the check sorts them: a baked crowd has
 * 170,000 channels): weight ranges [4,6) [0,2) [5,7) overlap (the first and the third, not
 * neighbours in the input), [4,6) [0,2) [6,8) do not; the message names the first pair. */
AK_TEST(channel_overlap_any_order) {
    float t[2] = {0, 1}, w[4] = {0, 0, 1, 1};
    ak_raw_channel ch[3];
    const uint32_t first[3] = {4, 0, 5};
    for (int k = 0; k < 3; ++k)
        ch[k] = (ak_raw_channel){.target = AK_CHANNEL_MORPH_WEIGHTS, .index = first[k], .component_count = 2,
                                 .interp = AK_INTERP_LINEAR, .key_count = 2, .times = t, .values = w};
    ak_raw_clip raw = {.name = "overlap", .channels = ch, .channel_count = 3, .morph_weight_count = 8};
    ak_clip* c = NULL;
    ak_diag d;
    memset(&d, 0, sizeof d);
    AK_CHECK_EQ(ak_clip_build(&raw, NULL, &c, &d), AK_ERR_DUPLICATE);
    AK_CHECK(c == NULL && strstr(d.message, "channels 0 and 2") != NULL);
    ch[2].index = 6;
    AK_CHECK_EQ(ak_clip_build(&raw, NULL, &c, &d), AK_OK);
    ak_clip_destroy(c);
}

int main(void) {
    AK_RUN(channel_overlap_any_order);
    AK_RUN(build_and_queries);
    AK_RUN(build_rejects_bad_input_with_exact_codes);
    AK_RUN(sample_rejects_bad_spans);
    AK_RUN(gltf_interpolation_matches_spec_formulas);
    AK_RUN(cursor_is_bit_identical_to_binary_search);
    AK_RUN(key_cache_survives_kernel_changes);
    AK_RUN(slerp_groups_in_pairs_bit_identical);
    AK_RUN(cursor_nan_sample_keeps_degenerate_segments_exact);
    AK_RUN(inline_sampler_matches_track_eval_and_double_slerp);
    AK_RUN(blend_properties);
    AK_RUN(blend_huge_weights_stay_finite);
    AK_RUN(additive_layers);
    AK_RUN(crossfade);
    AK_RUN(blend_validate_rules);
    AK_RUN(root_motion_extraction);
    AK_RUN(custom_allocator_is_used_and_balanced);
    AK_RUN(bake_pose_sequence);
    AK_RUN(reduce_keeps_model_error_within_tolerance);
    return ak_test_finish();
}
