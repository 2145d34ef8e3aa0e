/* Tests of the skin module: job validation (one case per rule), LBS against a double-precision
 * reference, DQS properties (rigid single influence, distance to the joint, hemisphere flip),
 * CoR (pruned == naive, center in the joint region), the quality ordering on a bent and twisted
 * cylinder, bone heat vs inverse distance on a two-legged shape, weight robustness, formats. */
#include <animkit/skin.h>

#include "ak_test.h"

/* ---- helpers ------------------------------------------------------------------------------ */

static ak_mat4 rot_about(ak_vec3 pivot, ak_vec3 axis, float angle) {
    ak_mat4 r = ak_mat4_from_quat(ak_quat_from_axis_angle(axis, angle));
    return ak_mat4_mul(ak_mat4_translation(pivot),
                       ak_mat4_mul(r, ak_mat4_translation(ak_vec3_neg(pivot))));
}

static ak_vec3 rand_unit(ak_rng* r) {
    for (;;) {
        ak_vec3 v =
            ak_vec3_make(ak_rng_range(r, -1, 1), ak_rng_range(r, -1, 1), ak_rng_range(r, -1, 1));
        float l = ak_vec3_length(v);
        if (l > 0.1f && l <= 1.0f) return ak_vec3_scale(v, 1.0f / l);
    }
}

/* Random rigid transform, or with scale/shear when affine. */
static ak_mat4 rand_matrix(ak_rng* r, bool affine) {
    ak_mat4 m =
        ak_mat4_from_quat(ak_quat_from_axis_angle(rand_unit(r), ak_rng_range(r, -3.1f, 3.1f)));
    if (affine) {
        ak_mat4 s = ak_mat4_identity();
        for (int c = 0; c < 3; ++c)
            for (int row = 0; row < 3; ++row)
                s.m[c * 4 + row] =
                    (c == row ? ak_rng_range(r, 0.6f, 1.5f) : ak_rng_range(r, -0.2f, 0.2f));
        m = ak_mat4_mul(m, s);
    }
    m.m[12] = ak_rng_range(r, -2, 2);
    m.m[13] = ak_rng_range(r, -2, 2);
    m.m[14] = ak_rng_range(r, -2, 2);
    return m;
}

/* Random influences: k joints (distinct) with positive weights summing to 1 in float. */
static void rand_influences(ak_rng* r, uint32_t k, size_t joint_count, uint16_t* j, float* w) {
    double sum = 0.0, raw[AK_MAX_INFLUENCES];
    for (uint32_t e = 0; e < k; ++e) {
        raw[e] = 0.05 + ak_rng_double(r);
        sum += raw[e];
        for (;;) {
            j[e] = (uint16_t)(ak_rng_u32(r) % joint_count);
            bool dup = false;
            for (uint32_t f = 0; f < e; ++f) dup = dup || j[f] == j[e];
            if (!dup || joint_count < k) break;
        }
    }
    float acc = 0.0f;
    for (uint32_t e = 1; e < k; ++e) {
        w[e] = (float)(raw[e] / sum);
        acc += w[e];
    }
    w[0] = 1.0f - acc;
}

/* Double-precision LBS reference: blended matrix, point, normal by inverse transpose. */
static void ref_lbs(const ak_mat4* pal, const uint16_t* j, const float* w, uint32_t k, ak_vec3 p,
                    ak_vec3 n, double* op, double* on) {
    double m[12] = {0};
    for (uint32_t e = 0; e < k; ++e)
        for (int c = 0; c < 4; ++c)
            for (int row = 0; row < 3; ++row)
                m[c * 3 + row] += (double)w[e] * pal[j[e]].m[c * 4 + row];
    double pp[3] = {p.x, p.y, p.z}, nn[3] = {n.x, n.y, n.z};
    for (int row = 0; row < 3; ++row)
        op[row] = m[9 + row] + m[row] * pp[0] + m[3 + row] * pp[1] + m[6 + row] * pp[2];
    /* inverse transpose via the explicit 3x3 inverse */
    double a = m[0], b = m[3], c = m[6], d = m[1], e = m[4], f = m[7], g = m[2], h = m[5], i = m[8];
    double det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
    double inv[3][3] = {{(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det},
                        {(f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det},
                        {(d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det}};
    double len = 0.0;
    for (int row = 0; row < 3; ++row) {
        on[row] = inv[0][row] * nn[0] + inv[1][row] * nn[1] + inv[2][row] * nn[2]; /* (A^-1)^T n */
        len += on[row] * on[row];
    }
    len = sqrt(len);
    for (int row = 0; row < 3; ++row) on[row] /= len;
}

static double vol_closed(const ak_vec3* p, const uint32_t* idx, size_t tri_count) {
    double v = 0.0;
    for (size_t t = 0; t < tri_count; ++t) {
        ak_vec3 a = p[idx[3 * t]], b = p[idx[3 * t + 1]], c = p[idx[3 * t + 2]];
        v += (double)a.x * ((double)b.y * c.z - (double)b.z * c.y) -
             (double)a.y * ((double)b.x * c.z - (double)b.z * c.x) +
             (double)a.z * ((double)b.x * c.y - (double)b.y * c.x);
    }
    return v / 6.0;
}

/* ---- a closed capped cylinder along +Y with a two-joint chain ------------------------------ */

#define CYL_RADIUS 0.2f
#define CYL_LENGTH 2.0f
typedef struct cylinder {
    size_t vertex_count, tri_count;
    ak_vec3* pos;
    ak_vec3* nrm;
    uint32_t* idx;
    uint16_t* joints; /* 2 per vertex: joint 0 (origin) and joint 1 (at y = 1) */
    float* weights;
} cylinder;

static float smoothstep01(float x) {
    x = ak_clampf(x, 0.0f, 1.0f);
    return x * x * (3.0f - 2.0f * x);
}

static cylinder cylinder_make(int rings, int segments) {
    cylinder c;
    c.vertex_count = (size_t)rings * segments + 2;
    c.tri_count = (size_t)(rings - 1) * segments * 2 + 2 * (size_t)segments;
    c.pos = (ak_vec3*)malloc(c.vertex_count * sizeof(ak_vec3));
    c.nrm = (ak_vec3*)malloc(c.vertex_count * sizeof(ak_vec3));
    c.idx = (uint32_t*)malloc(c.tri_count * 3 * sizeof(uint32_t));
    c.joints = (uint16_t*)malloc(c.vertex_count * 2 * sizeof(uint16_t));
    c.weights = (float*)malloc(c.vertex_count * 2 * sizeof(float));
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            float a = AK_TWO_PI * (float)s / (float)segments,
                  y = CYL_LENGTH * (float)r / (float)(rings - 1);
            size_t v = (size_t)r * segments + s;
            c.pos[v] = ak_vec3_make(CYL_RADIUS * cosf(a), y, -CYL_RADIUS * sinf(a));
            c.nrm[v] = ak_vec3_make(cosf(a), 0.0f, -sinf(a));
        }
    size_t bottom = (size_t)rings * segments, top = bottom + 1;
    c.pos[bottom] = ak_vec3_make(0, 0, 0);
    c.nrm[bottom] = ak_vec3_make(0, -1, 0);
    c.pos[top] = ak_vec3_make(0, CYL_LENGTH, 0);
    c.nrm[top] = ak_vec3_make(0, 1, 0);
    size_t t = 0;
    for (int r = 0; r + 1 < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            uint32_t a = (uint32_t)(r * segments + s),
                     b = (uint32_t)(r * segments + (s + 1) % segments);
            uint32_t a2 = a + (uint32_t)segments, b2 = b + (uint32_t)segments;
            /* counter-clockwise from outside: angle grows towards -z from +x, seen from outside */
            uint32_t q[6] = {a, b, b2, a, b2, a2};
            memcpy(&c.idx[3 * t], q, sizeof q);
            t += 2;
        }
    for (int s = 0; s < segments; ++s) {
        uint32_t a = (uint32_t)s, b = (uint32_t)((s + 1) % segments);
        uint32_t lo[3] = {(uint32_t)bottom, b, a};
        memcpy(&c.idx[3 * t++], lo, sizeof lo);
        uint32_t o = (uint32_t)((rings - 1) * segments);
        uint32_t hi[3] = {(uint32_t)top, o + a, o + b};
        memcpy(&c.idx[3 * t++], hi, sizeof hi);
    }
    for (size_t v = 0; v < c.vertex_count; ++v) {
        float w1 = smoothstep01((c.pos[v].y - 0.7f) / 0.6f);
        c.joints[2 * v] = 0;
        c.joints[2 * v + 1] = 1;
        c.weights[2 * v + 1] = w1;
        c.weights[2 * v] = 1.0f - w1;
    }
    return c;
}

static void cylinder_free(cylinder* c) {
    free(c->pos);
    free(c->nrm);
    free(c->idx);
    free(c->joints);
    free(c->weights);
}

static ak_skin_job cylinder_job(const cylinder* c, ak_skin_method method, const ak_mat4* palette,
                                ak_vec3* out, const ak_vec3* centers, unsigned char* scratch,
                                size_t scratch_size) {
    ak_skin_job job = {
        .method = method,
        .influence_count = 2,
        .palette = {palette, 2},
        .positions = {c->pos, c->vertex_count, 0},
        .joints = {c->joints, c->vertex_count, 0},
        .weights = {c->weights, c->vertex_count, 0},
        .cor_centers = {centers, centers ? c->vertex_count : 0, 0},
        .scratch = {scratch, scratch_size},
        .out_positions = {out, c->vertex_count, 0},
    };
    return job;
}

/* ---- validation ------------------------------------------------------------------------------ */

/* j = good with one edit, then the code validate must return */
#define EXPECT_JOB(code, ...)                                                                  \
    do {                                                                                       \
        j = good;                                                                              \
        __VA_ARGS__;                                                                           \
        AK_CHECK_EQ(ak_skin_job_validate(&j), code);                                           \
    } while (0)

AK_TEST(job_validate_rules) {
    ak_skin_job zero;
    memset(&zero, 0, sizeof zero);
    AK_CHECK_EQ(ak_skin_job_validate(&zero), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_skin_job_validate(NULL), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_skin_job_run(&zero), AK_ERR_NULL_ARG);

    ak_vec3 pos[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, nrm[3] = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
            out[3], outn[3];
    uint16_t jn[3] = {0, 1, 0};
    float w[3] = {1, 1, 1};
    ak_mat4 pal[2] = {ak_mat4_identity(), ak_mat4_identity()};
    uint32_t idx[3] = {0, 1, 2};
    unsigned char scratch[512];
    const ak_skin_job good = {
        .influence_count = 1,
        .palette = {pal, 2},
        .positions = {pos, 3, 0},
        .joints = {jn, 3, 0},
        .weights = {w, 3, 0},
        .out_positions = {out, 3, 0},
    };
    AK_CHECK_EQ(ak_skin_job_validate(&good), AK_OK);
    ak_skin_job j;
    /* rule 1 */
    EXPECT_JOB(AK_ERR_NULL_ARG, j.positions.ptr = NULL);
    EXPECT_JOB(AK_ERR_NULL_ARG, j.palette.ptr = NULL);
    EXPECT_JOB(AK_ERR_NULL_ARG, j.joints.ptr = NULL);
    EXPECT_JOB(AK_ERR_NULL_ARG, j.weights.ptr = NULL);
    EXPECT_JOB(AK_ERR_NULL_ARG, j.out_positions.ptr = NULL);
    /* rule 2 */
    EXPECT_JOB(AK_ERR_BAD_ARG, j.method = AK_SKIN_METHOD_COUNT);
    EXPECT_JOB(AK_ERR_BAD_ARG, j.influence_count = 0);
    EXPECT_JOB(AK_ERR_BAD_ARG, j.influence_count = 9);
    EXPECT_JOB(AK_ERR_BAD_ARG, j.thread_count = 65);
    EXPECT_JOB(AK_ERR_BAD_ARG, j.positions.stride = 8);
    EXPECT_JOB(AK_ERR_BAD_ARG, j.weights.stride = 2);
    /* rule 3 */
    EXPECT_JOB(AK_ERR_NULL_ARG, j.normals = (ak_cstream){nrm, 3, 0});
    j = good;
    j.normals_from_faces = true;
    j.out_normals = (ak_stream){outn, 3, 0};
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_NULL_ARG); /* no indices */
    j = good;
    j.method = AK_SKIN_COR;
    j.scratch = (ak_u8_span){scratch, sizeof scratch};
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_NULL_ARG); /* no centers */
    EXPECT_JOB(AK_ERR_NULL_ARG, j.tangents = (ak_cstream){w, 1, 16});
    /* rule 4 */
    j = good;
    j.normals_from_faces = true;
    j.out_normals = (ak_stream){outn, 3, 0};
    j.indices = (ak_u32_cspan){idx, 2};
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_ARG);
    /* rule 5 */
    EXPECT_JOB(AK_ERR_SPAN_SMALL, j.weights.count = 2);
    EXPECT_JOB(AK_ERR_SPAN_SMALL, j.out_positions.count = 2);
    j = good;
    j.normals = (ak_cstream){nrm, 3, 0};
    j.out_normals = (ak_stream){outn, 2, 0};
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_SPAN_SMALL);
    EXPECT_JOB(AK_ERR_SPAN_SMALL, j.method = AK_SKIN_DQS); /* no scratch */
    j.scratch = (ak_u8_span){scratch, ak_skin_job_scratch_size(&j) - 1};
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_SPAN_SMALL);
    j.scratch.count += 1;
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_OK);
    AK_CHECK_EQ(ak_skin_job_scratch_size(&good), 0);
    /* rule 6 */
    ak_mat4 bad[2] = {ak_mat4_identity(), ak_mat4_identity()};
    bad[1].m[5] = NAN;
    EXPECT_JOB(AK_ERR_BAD_DATA, j.palette.ptr = bad);
    j.skip_data_check = true;
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_DATA);
}

AK_TEST(job_bad_data_codes) {
    ak_vec3 pos[2] = {{0, 0, 0}, {1, 0, 0}}, out[2];
    uint16_t jn[4] = {0, 1, 1, 0};
    float w[4] = {0.5f, 0.5f, 0.25f, 0.75f};
    ak_mat4 pal[2] = {ak_mat4_identity(), ak_mat4_identity()};
    const ak_skin_job good = {
        .influence_count = 2,
        .palette = {pal, 2},
        .positions = {pos, 2, 0},
        .joints = {jn, 2, 0},
        .weights = {w, 2, 0},
        .out_positions = {out, 2, 0},
    };
    AK_CHECK_EQ(ak_skin_job_validate(&good), AK_OK);
    ak_skin_job j = good;
    w[3] = 0.7f; /* sum 0.95 */
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_WEIGHTS);
    w[3] = 0.75f;
    w[0] = -0.5f;
    w[1] = 1.5f; /* sums to 1 but negative */
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_WEIGHTS);
    w[0] = NAN;
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_WEIGHTS);
    w[0] = 0.5f;
    w[1] = 0.5f;
    jn[2] = 2; /* out of range for a 2-matrix palette */
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_INDEX);
    /* run writes nothing when validation fails */
    out[0] = ak_vec3_make(7, 7, 7);
    AK_CHECK_EQ(ak_skin_job_run(&j), AK_ERR_BAD_INDEX);
    AK_CHECK(out[0].x == 7.0f);
    /* with the data check skipped, a bad index is clamped: no out-of-bounds read, finite output */
    j.skip_data_check = true;
    AK_CHECK_EQ(ak_skin_job_run(&j), AK_OK);
    AK_CHECK(ak_vec3_is_finite(out[1]));
    jn[2] = 1;
    pos[1].y = INFINITY;
    j.skip_data_check = false;
    AK_CHECK_EQ(ak_skin_job_validate(&j), AK_ERR_BAD_DATA);
    pos[1].y = 0.0f;

    /* the standalone weight check reports the vertex */
    size_t bad_v = 99;
    w[3] = 0.8f;
    AK_CHECK_EQ(ak_skin_weights_validate((ak_u16_cspan){jn, 4}, (ak_f32_cspan){w, 4}, 2, 2, 2, 0.0f,
                                         &bad_v),
                AK_ERR_BAD_WEIGHTS);
    AK_CHECK_EQ(bad_v, 1);
    w[3] = 0.75f;
    jn[0] = 5;
    AK_CHECK_EQ(ak_skin_weights_validate((ak_u16_cspan){jn, 4}, (ak_f32_cspan){w, 4}, 2, 2, 2, 0.0f,
                                         &bad_v),
                AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(bad_v, 0);
    jn[0] = 0;
    AK_CHECK_EQ(
        ak_skin_weights_validate((ak_u16_cspan){jn, 4}, (ak_f32_cspan){w, 4}, 2, 2, 2, 0.0f, NULL),
        AK_OK);
    AK_CHECK_EQ(
        ak_skin_weights_validate((ak_u16_cspan){jn, 3}, (ak_f32_cspan){w, 4}, 2, 2, 2, 0.0f, NULL),
        AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(
        ak_skin_weights_validate((ak_u16_cspan){jn, 4}, (ak_f32_cspan){w, 4}, 2, 0, 2, 0.0f, NULL),
        AK_ERR_BAD_ARG);
}

/* ---- LBS against the double reference ------------------------------------------------------- */

typedef struct interleaved_vertex {
    float pos[3];
    float nrm[3];
    uint16_t joints[AK_MAX_INFLUENCES];
    float weights[AK_MAX_INFLUENCES];
} interleaved_vertex;

/* every influence count the kernels specialise (1, 2, 3, 4, 8) and one they do not (5) */
static const uint32_t k_counts[6] = {1, 2, 3, 4, 5, 8};

/* The data rules run as a fast screen over the whole job and, only where it flags, the exact
 * vertex-by-vertex checks. Every fault must be caught wherever it sits (first vertex, inside a
 * SIMD step, in the scalar tail), for every influence count, on one thread and on the
 * parallel screen of a large job; and the cases the screen flags but the rules accept (-0.0,
 * a sum 0.95e-3 off) must still pass. */
AK_TEST(job_data_screen_catches_faults_everywhere) {
    enum { J = 9 };
    ak_mat4 pal[J];
    for (int j = 0; j < J; ++j) pal[j] = ak_mat4_identity();
    const size_t sizes[2] = {37, 70001}; /* the second takes the two-thread screen */
    for (int si = 0; si < 2; ++si) {
        const size_t n = sizes[si];
        for (int kc = 0; kc < 6; ++kc) {
            const uint32_t K = k_counts[kc];
            if (si == 1 && K != 3 && K != 4) continue; /* large: one specialised count, one not */
            ak_rng rng = ak_rng_make(900 + K);
            ak_vec3 *pos = malloc(n * sizeof *pos), *nrm = malloc(n * sizeof *nrm), *ctr = malloc(n * sizeof *ctr),
                    *out = malloc(n * sizeof *out), *outn = malloc(n * sizeof *outn);
            uint16_t* jn = malloc(n * K * sizeof *jn);
            float* w = malloc(n * K * sizeof *w);
            unsigned char* scratch = malloc(64 + 192 * J);
            for (size_t i = 0; i < n; ++i) {
                pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), 0.5f, 0.25f);
                nrm[i] = ak_vec3_make(0, 1, 0);
                ctr[i] = pos[i];
                rand_influences(&rng, K, J, &jn[K * i], &w[K * i]);
            }
            ak_skin_job job = {
                .method = AK_SKIN_COR,
                .influence_count = K,
                .palette = {pal, J},
                .positions = {pos, n, 0},
                .normals = {nrm, n, 0},
                .joints = {jn, n, 0},
                .weights = {w, n, 0},
                .cor_centers = {ctr, n, 0},
                .scratch = {scratch, 64 + 192 * J},
                .out_positions = {out, n, 0},
                .out_normals = {outn, n, 0},
                .thread_count = 2,
            };
            AK_CHECK_EQ(ak_skin_job_validate(&job), AK_OK);
            const size_t at[4] = {0, n / 2 + 1, n - 4, n - 1};
            for (int a = 0; a < 4; ++a) {
                const size_t v = at[a];
                float* wv = &w[K * v];
                const float w0 = wv[0];
                const uint16_t j0 = jn[K * v];
                const ak_vec3 p0 = pos[v], n0 = nrm[v], c0 = ctr[v];
                /* rejected, with the exact rule's code */
                const float bad_w[4] = {-0.25f, NAN, INFINITY, w0 + 2e-3f};
                const float w1 = K > 1 ? wv[1] : 0.0f;
                for (int b = 0; b < 4; ++b) {
                    wv[0] = bad_w[b];
                    if (b == 0 && K > 1) wv[1] = w1 + w0 + 0.25f; /* negative with the sum kept at 1 */
                    AK_CHECK_MSG(ak_skin_job_validate(&job) == AK_ERR_BAD_WEIGHTS, "K %u n %zu vertex %zu weight %g", K,
                                 n, v, (double)bad_w[b]);
                    AK_CHECK_EQ(ak_skin_job_run(&job), AK_ERR_BAD_WEIGHTS);
                    if (K > 1) wv[1] = w1;
                }
                wv[0] = w0;
                jn[K * v] = J;
                AK_CHECK_MSG(ak_skin_job_run(&job) == AK_ERR_BAD_INDEX, "K %u n %zu vertex %zu index", K, n, v);
                jn[K * v] = j0;
                pos[v].y = NAN;
                AK_CHECK_EQ(ak_skin_job_run(&job), AK_ERR_BAD_DATA);
                pos[v] = p0;
                nrm[v].z = -INFINITY;
                AK_CHECK_EQ(ak_skin_job_run(&job), AK_ERR_BAD_DATA);
                nrm[v] = n0;
                ctr[v].x = NAN;
                AK_CHECK_EQ(ak_skin_job_run(&job), AK_ERR_BAD_DATA);
                ctr[v] = c0;
                /* accepted: within the rule's 1e-3 but outside the screen's 0.9e-3, and -0.0 */
                wv[0] = w0 + 0.95e-3f;
                AK_CHECK_MSG(ak_skin_job_run(&job) == AK_OK, "K %u n %zu vertex %zu sum 1 + 0.95e-3", K, n, v);
                wv[0] = w0;
                if (K > 1) {
                    const float wl = wv[K - 1];
                    wv[0] = w0 + wl;
                    wv[K - 1] = -0.0f;
                    AK_CHECK_MSG(ak_skin_job_run(&job) == AK_OK, "K %u n %zu vertex %zu weight -0.0", K, n, v);
                    wv[0] = w0;
                    wv[K - 1] = wl;
                }
            }
            AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            free(pos), free(nrm), free(ctr), free(out), free(outn), free(jn), free(w), free(scratch);
        }
    }
    /* interleaved vertices (strided streams take the screen's element-by-element path) */
    enum { NI = 21 };
    interleaved_vertex iv[NI];
    ak_vec3 out[NI], outn[NI];
    ak_rng rng = ak_rng_make(31);
    memset(iv, 0, sizeof iv);
    for (int i = 0; i < NI; ++i) {
        iv[i].pos[0] = ak_rng_range(&rng, -1, 1);
        iv[i].nrm[1] = 1.0f;
        rand_influences(&rng, 4, J, iv[i].joints, iv[i].weights);
    }
    const ak_skin_job ij = {
        .influence_count = 4,
        .palette = {pal, J},
        .positions = {iv[0].pos, NI, sizeof iv[0]},
        .normals = {iv[0].nrm, NI, sizeof iv[0]},
        .joints = {iv[0].joints, NI, sizeof iv[0]},
        .weights = {iv[0].weights, NI, sizeof iv[0]},
        .out_positions = {out, NI, 0},
        .out_normals = {outn, NI, 0},
    };
    AK_CHECK_EQ(ak_skin_job_run(&ij), AK_OK);
    interleaved_vertex* last = &iv[NI - 1];
    const interleaved_vertex keep = *last;
    last->weights[1] += last->weights[0] + 0.25f, last->weights[0] = -0.25f; /* sum kept at 1 */
    AK_CHECK_EQ(ak_skin_job_run(&ij), AK_ERR_BAD_WEIGHTS);
    *last = keep;
    last->joints[3] = J;
    AK_CHECK_EQ(ak_skin_job_run(&ij), AK_ERR_BAD_INDEX);
    *last = keep;
    last->nrm[2] = NAN;
    AK_CHECK_EQ(ak_skin_job_run(&ij), AK_ERR_BAD_DATA);
    *last = keep;
    last->pos[1] = INFINITY;
    AK_CHECK_EQ(ak_skin_job_run(&ij), AK_ERR_BAD_DATA);
}

/* The kernel levels this CPU runs: scalar always, AVX2 and AVX-512 where it has them. */
static int cpu_simd_levels(ak_skin_simd* out, const char** names) {
    const char* best = ak_skin_simd_name();
    int n = 0;
    out[n] = AK_SKIN_SIMD_SCALAR, names[n++] = "scalar";
    if (!strcmp(best, "avx2") || !strcmp(best, "avx512")) out[n] = AK_SKIN_SIMD_AVX2, names[n++] = "avx2";
    if (!strcmp(best, "avx512")) out[n] = AK_SKIN_SIMD_AVX512, names[n++] = "avx512";
    return n;
}

AK_TEST(lbs_matches_double_reference) {
    for (int kc = 0; kc < 6; ++kc) {
        enum { N = 1003, J = 20 };
        const uint32_t K = k_counts[kc];
        ak_rng rng = ak_rng_make(11 + (uint64_t)K);
        /* the palette at a 64-byte aligned address and 16 bytes past one (the AVX2 LBS kernel then
         * works on an aligned copy: both paths must give the reference) */
        _Alignas(64) ak_mat4 pal_storage[J + 1];
        ak_mat4 pal_in[J];
        for (int j = 0; j < J; ++j)
            pal_in[j] = rand_matrix(&rng, j % 2 == 1); /* half with scale/shear */
        ak_mat4* pal = pal_storage;
        interleaved_vertex* v = (interleaved_vertex*)malloc(N * sizeof *v);
        ak_vec3* op = (ak_vec3*)malloc(N * sizeof(ak_vec3));
        ak_vec3* on = (ak_vec3*)malloc(N * sizeof(ak_vec3));
        for (int i = 0; i < N; ++i) {
            ak_vec3 p = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                     ak_rng_range(&rng, -1, 1));
            ak_vec3 n = rand_unit(&rng);
            memcpy(v[i].pos, &p, 12);
            memcpy(v[i].nrm, &n, 12);
            rand_influences(&rng, K, J, v[i].joints, v[i].weights);
        }
        const double scale =
            2.0 * sqrt(3.0) + 4.0; /* bounding size of the deformed points, roughly */
        for (int variant = 0; variant < 8; ++variant) {
            pal = (variant & 4) ? (ak_mat4*)(void*)((char*)pal_storage + 16) : pal_storage;
            memcpy(pal, pal_in, sizeof pal_in);
            ak_skin_job job = {
                .influence_count = K,
                .palette = {pal, J},
                .positions = {v[0].pos, N, sizeof *v},
                .normals = {v[0].nrm, N, sizeof *v},
                .joints = {v[0].joints, N, sizeof *v},
                .weights = {v[0].weights, N, sizeof *v},
                .out_positions = {op, N, 0},
                .out_normals = {on, N, 0},
                .skip_simd = (variant & 1) != 0,
                .thread_count = (variant & 2) ? 2u : 0u,
            };
            memset(op, 0, N * sizeof(ak_vec3));
            AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            double worst_p = 0.0, worst_n = 0.0;
            for (int i = 0; i < N; ++i) {
                double rp[3], rn[3];
                ak_vec3 p, n;
                memcpy(&p, v[i].pos, 12);
                memcpy(&n, v[i].nrm, 12);
                ref_lbs(pal, v[i].joints, v[i].weights, K, p, n, rp, rn);
                double ep = fabs(rp[0] - op[i].x) + fabs(rp[1] - op[i].y) + fabs(rp[2] - op[i].z);
                double en = fabs(rn[0] - on[i].x) + fabs(rn[1] - on[i].y) + fabs(rn[2] - on[i].z);
                if (ep > worst_p) worst_p = ep;
                if (en > worst_n) worst_n = en;
            }
            /* float arithmetic on values of size ~4 with 4 influences: a few ulps of the scale */
            AK_CHECK_MSG(worst_p <= 1e-5 * scale, "K %u variant %d: position error %g", K, variant,
                         worst_p);
            AK_CHECK_MSG(worst_n <= 2e-5, "K %u variant %d: normal error %g", K, variant, worst_n);
        }
        free(v);
        free(op);
        free(on);
    }
}

AK_TEST(dqs_cor_simd_matches_scalar_for_every_influence_count) {
    /* The scalar code is checked against closed forms above (rigid single influences, distances
     * to the joint, hemisphere flips, the cylinder); here the SIMD kernels must give the same
     * points and normals for every influence count, rigid palettes with random rotations. */
    enum { J = 24 };
    /* 517: a scalar tail; 512: the last SIMD block ends at the arrays' end (reads past the
     * last vertex's joints or weights would show under ASan) */
    for (int kc = 0; kc < 12; ++kc) {
        const uint32_t K = k_counts[kc % 6];
        const int N = kc < 6 ? 517 : 512;
        ak_rng rng = ak_rng_make(77 + (uint64_t)K);
        ak_mat4 pal[J];
        for (int j = 0; j < J; ++j) pal[j] = rand_matrix(&rng, false);
        ak_vec3 *pos = malloc(N * sizeof *pos), *nrm = malloc(N * sizeof *nrm),
                *ctr = malloc(N * sizeof *ctr);
        ak_vec3 *op[2], *on[2];
        for (int s2 = 0; s2 < 2; ++s2)
            op[s2] = malloc(N * sizeof(ak_vec3)), on[s2] = malloc(N * sizeof(ak_vec3));
        uint16_t* jn = malloc(N * K * sizeof *jn);
        float* w = malloc(N * K * sizeof *w);
        unsigned char* scratch = malloc(64 + 192 * J);
        for (int i = 0; i < N; ++i) {
            pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                  ak_rng_range(&rng, -1, 1));
            nrm[i] = rand_unit(&rng);
            ctr[i] = ak_vec3_scale(pos[i], 0.7f);
            rand_influences(&rng, K, J, &jn[K * i], &w[K * i]);
        }
        for (int method = AK_SKIN_DQS; method <= AK_SKIN_COR; ++method) {
            for (int simd = 0; simd < 2; ++simd) {
                ak_skin_job job = {
                    .method = (ak_skin_method)method,
                    .influence_count = K,
                    .palette = {pal, J},
                    .positions = {pos, N, 0},
                    .normals = {nrm, N, 0},
                    .joints = {jn, N, 0},
                    .weights = {w, N, 0},
                    .cor_centers = {ctr, N, 0},
                    .scratch = {scratch, 64 + 192 * J},
                    .out_positions = {op[simd], N, 0},
                    .out_normals = {on[simd], N, 0},
                    .skip_simd = simd == 0,
                };
                AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            }
            double worst_p = 0.0, worst_n = 0.0;
            for (int i = 0; i < N; ++i) {
                worst_p = fmax(worst_p, ak_vec3_length(ak_vec3_sub(op[0][i], op[1][i])));
                worst_n = fmax(worst_n, ak_vec3_length(ak_vec3_sub(on[0][i], on[1][i])));
            }
            /* points of size ~3, float rounding in a different order */
            AK_CHECK_MSG(worst_p <= 1e-5 && worst_n <= 1e-5, "%s K %u: SIMD vs scalar %g / %g",
                         method == AK_SKIN_DQS ? "DQS" : "CoR", K, worst_p, worst_n);
        }
        free(pos), free(nrm), free(ctr), free(jn), free(w), free(scratch);
        for (int s2 = 0; s2 < 2; ++s2) free(op[s2]), free(on[s2]);
    }
}

typedef struct wide_vertex { /* interleaved with a stride the kernels cannot shuffle (64 bytes) */
    float pos[3];
    uint16_t joints[AK_MAX_INFLUENCES];
    float nrm[3];
    float weights[AK_MAX_INFLUENCES];
    float ctr[3];
    float pad;
} wide_vertex;

AK_TEST(every_simd_kernel_matches_scalar) {
    /* Every kernel this CPU has (scalar, AVX2, AVX-512, picked with simd_limit) against the
     * scalar code (itself checked against closed forms and a double reference above) and,
     * for LBS, against the double reference: LBS, DQS, CoR; influence counts 1, 2, 3, 4, 5,
     * 8; vertex counts below one block, one AVX2 block, blocks plus tails; packed and
     * interleaved streams; 1 and 3 threads; with and without normals. */
    ak_skin_simd levels[3];
    const char* names[3];
    const int level_count = cpu_simd_levels(levels, names);
    printf("  kernels run here:");
    for (int l = 0; l < level_count; ++l) printf(" %s", names[l]);
    printf("\n");
    if (level_count < 3) AK_SKIP("no AVX-512 (F, VL, DQ, BW) on this CPU, or an AK_NO_SIMD build: the AVX-512 kernel was not run");
    if (level_count < 2) AK_SKIP("no AVX2+FMA on this CPU, or an AK_NO_SIMD build: the AVX2 kernel was not run");
    enum { J = 20, NMAX = 517 };
    static const int counts[4] = {5, 8, 37, NMAX}; /* 517 = 32 blocks of 16 + 5 */
    ak_rng rng = ak_rng_make(2026);
    ak_mat4 pal[J], pal_rigid[J];
    for (int j = 0; j < J; ++j) pal[j] = rand_matrix(&rng, j % 2 == 1), pal_rigid[j] = rand_matrix(&rng, false);
    wide_vertex* v = (wide_vertex*)malloc(NMAX * sizeof *v);
    ak_vec3 *pos = malloc(NMAX * sizeof *pos), *nrm = malloc(NMAX * sizeof *nrm), *ctr = malloc(NMAX * sizeof *ctr);
    uint16_t* jn = malloc(NMAX * AK_MAX_INFLUENCES * sizeof *jn);
    float* w = malloc(NMAX * AK_MAX_INFLUENCES * sizeof *w);
    ak_vec3 *op[3], *on[3];
    for (int l = 0; l < 3; ++l) op[l] = malloc(NMAX * sizeof(ak_vec3)), on[l] = malloc(NMAX * sizeof(ak_vec3));
    unsigned char* scratch = malloc(64 + 192 * J);
    int runs[3] = {0, 0, 0};
    for (int kc = 0; kc < 6; ++kc) {
        const uint32_t K = k_counts[kc];
        for (int i = 0; i < NMAX; ++i) {
            pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1));
            nrm[i] = rand_unit(&rng);
            ctr[i] = ak_vec3_scale(pos[i], 0.6f);
            rand_influences(&rng, K, J, &jn[K * i], &w[K * i]);
            memset(&v[i], 0, sizeof v[i]);
            memcpy(v[i].pos, &pos[i], 12), memcpy(v[i].nrm, &nrm[i], 12), memcpy(v[i].ctr, &ctr[i], 12);
            memcpy(v[i].joints, &jn[K * i], K * sizeof *jn), memcpy(v[i].weights, &w[K * i], K * sizeof *w);
        }
        for (int mi = 0; mi < 4; ++mi) { /* LBS, DQS, CoR, and LBS with a rigid palette */
            const int method = mi == 3 ? AK_SKIN_LBS : mi;
            const ak_mat4* pm = mi == 0 ? pal : pal_rigid; /* DQS/CoR SIMD: rigid only */
            for (int variant = 0; variant < 16; ++variant) {
                const int N = counts[variant & 3];
                const bool strided = (variant & 4) != 0, normals = (variant & 8) != 0;
                for (int l = 0; l < level_count; ++l) {
                    ak_skin_job job = {
                        .method = (ak_skin_method)method,
                        .influence_count = K,
                        .palette = {pm, J},
                        .positions = {pos, (size_t)N, 0},
                        .joints = {jn, (size_t)N, 0},
                        .weights = {w, (size_t)N, 0},
                        .cor_centers = {ctr, (size_t)N, 0},
                        .scratch = {scratch, 64 + 192 * J},
                        .out_positions = {op[l], (size_t)N, 0},
                        .simd_limit = levels[l],
                        .thread_count = (variant & 1) ? 3u : 0u,
                    };
                    if (strided) {
                        job.positions = (ak_cstream){v[0].pos, (size_t)N, sizeof *v};
                        job.joints = (ak_cstream){v[0].joints, (size_t)N, sizeof *v};
                        job.weights = (ak_cstream){v[0].weights, (size_t)N, sizeof *v};
                        job.cor_centers = (ak_cstream){v[0].ctr, (size_t)N, sizeof *v};
                    }
                    if (normals) {
                        job.normals = strided ? (ak_cstream){v[0].nrm, (size_t)N, sizeof *v}
                                              : (ak_cstream){nrm, (size_t)N, 0};
                        job.out_normals = (ak_stream){on[l], (size_t)N, 0};
                    }
                    memset(op[l], 0xff, NMAX * sizeof(ak_vec3)); /* NaN: a vertex left unwritten shows */
                    memset(on[l], 0xff, NMAX * sizeof(ak_vec3));
                    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
                    ++runs[l];
                    double worst_p = 0.0, worst_n = 0.0;
                    for (int i = 0; i < N; ++i) {
                        double ep = ak_vec3_length(ak_vec3_sub(op[l][i], op[0][i]));
                        double en = normals ? ak_vec3_length(ak_vec3_sub(on[l][i], on[0][i])) : 0.0;
                        worst_p = ep == ep ? fmax(worst_p, ep) : INFINITY;
                        worst_n = en == en ? fmax(worst_n, en) : INFINITY;
                        if (method == AK_SKIN_LBS && l == 0) { /* the scalar code against doubles */
                            double rp[3], rn[3];
                            ref_lbs(pm, &jn[K * i], &w[K * i], K, pos[i], nrm[i], rp, rn);
                            double e = fabs(rp[0] - op[0][i].x) + fabs(rp[1] - op[0][i].y) + fabs(rp[2] - op[0][i].z);
                            AK_CHECK_MSG(e <= 1e-4, "LBS scalar K %u vertex %d: %g", K, i, e);
                        }
                    }
                    /* the sentinel past the job's vertices stays (nothing written beyond N) */
                    if (N < NMAX) AK_CHECK(op[l][N].x != op[l][N].x);
                    AK_CHECK_MSG(worst_p <= 2e-5 && worst_n <= 2e-5,
                                 "%s method %d K %u N %d %s %s threads %u: vs scalar %g / %g", names[l], method, K,
                                 N, strided ? "strided" : "packed", normals ? "normals" : "positions",
                                 job.thread_count, worst_p, worst_n);
                }
            }
        }
    }
    printf("  runs per kernel:");
    for (int l = 0; l < level_count; ++l) printf(" %s %d", names[l], runs[l]);
    printf("\n");
    ak_skin_job bad = {.simd_limit = AK_SKIN_SIMD_COUNT, .influence_count = 1, .palette = {pal, J},
                       .positions = {pos, 1, 0}, .joints = {jn, 1, 0}, .weights = {w, 1, 0},
                       .out_positions = {op[0], 1, 0}};
    AK_CHECK_EQ(ak_skin_job_validate(&bad), AK_ERR_BAD_ARG);
    free(v), free(pos), free(nrm), free(ctr), free(jn), free(w), free(scratch);
    for (int l = 0; l < 3; ++l) free(op[l]), free(on[l]);
}

AK_TEST(lbs_kernels_match_reference_around_palette_copy_limit) {
    /* The AVX2 kernel copies palettes of up to 256 joints into a 3x4-row layout for the packed
     * K = 1 (rigid), 2, 4, 8 blocks and reads larger ones in place: palettes of 255, 256, 257
     * and 300 joints, joint indices spread over the whole palette (the last joint included),
     * every kernel against the double-precision reference (positions and normals). */
    ak_skin_simd levels[3];
    const char* names[3];
    const int level_count = cpu_simd_levels(levels, names);
    enum { JMAX = 300, N = 77 };
    static const int joint_counts[4] = {255, 256, 257, JMAX};
    static const uint32_t ks[4] = {1, 2, 4, 8};
    ak_rng rng = ak_rng_make(77);
    ak_mat4* pal = malloc(JMAX * sizeof *pal);
    ak_vec3 *pos = malloc(N * sizeof *pos), *nrm = malloc(N * sizeof *nrm);
    ak_vec3 *op = malloc(N * sizeof *op), *on = malloc(N * sizeof *on);
    uint16_t* jn = malloc(N * 8 * sizeof *jn);
    float* w = malloc(N * 8 * sizeof *w);
    for (int ji = 0; ji < 4; ++ji) {
        const int J = joint_counts[ji];
        for (int kc = 0; kc < 4; ++kc) {
            const uint32_t K = ks[kc];
            /* K = 1: rigid (the kernels' 1-influence path); else scale and shear on odd joints */
            for (int j = 0; j < J; ++j) pal[j] = rand_matrix(&rng, K > 1 && j % 2 == 1);
            for (int i = 0; i < N; ++i) {
                pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1));
                nrm[i] = rand_unit(&rng);
                rand_influences(&rng, K, (size_t)J, &jn[K * i], &w[K * i]);
                if (i % 5 == 0) jn[K * i] = (uint16_t)(J - 1);
            }
            for (int l = 0; l < level_count; ++l) {
                ak_skin_job job = {
                    .influence_count = K,
                    .palette = {pal, (size_t)J},
                    .positions = {pos, N, 0},
                    .joints = {jn, N, 0},
                    .weights = {w, N, 0},
                    .normals = {nrm, N, 0},
                    .out_positions = {op, N, 0},
                    .out_normals = {on, N, 0},
                    .simd_limit = levels[l],
                };
                AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
                double worst_p = 0.0, worst_n = 0.0;
                for (int i = 0; i < N; ++i) {
                    double rp[3], rn[3];
                    ref_lbs(pal, &jn[K * i], &w[K * i], K, pos[i], nrm[i], rp, rn);
                    const double ep = fabs(rp[0] - op[i].x) + fabs(rp[1] - op[i].y) + fabs(rp[2] - op[i].z);
                    const double en = fabs(rn[0] - on[i].x) + fabs(rn[1] - on[i].y) + fabs(rn[2] - on[i].z);
                    worst_p = ep == ep ? fmax(worst_p, ep) : INFINITY;
                    worst_n = en == en ? fmax(worst_n, en) : INFINITY;
                }
                AK_CHECK_MSG(worst_p <= 1e-4 && worst_n <= 1e-4, "%s %d joints K %u: %g / %g", names[l], J, K,
                             worst_p, worst_n);
            }
        }
    }
    free(pal), free(pos), free(nrm), free(op), free(on), free(jn), free(w);
}

AK_TEST(lbs_single_influence_rigid_path) {
    /* LBS with 1 influence, normals and a rigid palette takes a path without the blend and the
     * normal's renormalisation in the SIMD kernels: against the scalar code for valid weights
     * (1, and 1 - 5e-4 within the rule's tolerance) and, with skip_data_check, 0 and -1; unit
     * normals out. A palette that is only nearly rigid (scale 1.001) must not take that path:
     * its normals are still unit. */
    enum { N = 45, J = 7 };
    ak_skin_simd levels[3];
    const char* names[3];
    const int level_count = cpu_simd_levels(levels, names);
    ak_rng rng = ak_rng_make(5);
    ak_mat4 pal[J];
    ak_vec3 pos[N], nrm[N], op[3][N], on[3][N];
    uint16_t jn[N];
    float w[N];
    for (int i = 0; i < N; ++i) {
        pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1));
        nrm[i] = rand_unit(&rng);
        jn[i] = (uint16_t)(ak_rng_u32(&rng) % J);
        w[i] = i % 5 == 1 ? 1.0f - 5e-4f : 1.0f;
    }
    for (int variant = 0; variant < 3; ++variant) {
        for (int j = 0; j < J; ++j) pal[j] = rand_matrix(&rng, false);
        if (variant == 1) { /* nearly rigid: one joint scaled by 1.001 */
            for (int e = 0; e < 3; ++e) pal[3].m[e] *= 1.001f, pal[3].m[4 + e] *= 1.001f, pal[3].m[8 + e] *= 1.001f;
        }
        if (variant == 2) w[7] = 0.0f, w[20] = -1.0f, w[44] = 0.0f; /* unchecked data */
        for (int l = 0; l < level_count; ++l) {
            ak_skin_job job = {
                .influence_count = 1,
                .palette = {pal, J},
                .positions = {pos, N, 0},
                .normals = {nrm, N, 0},
                .joints = {jn, N, 0},
                .weights = {w, N, 0},
                .out_positions = {op[l], N, 0},
                .out_normals = {on[l], N, 0},
                .simd_limit = levels[l],
                .skip_data_check = variant == 2,
            };
            AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            double worst = 0.0, worst_len = 0.0;
            for (int i = 0; i < N; ++i) {
                worst = fmax(worst, ak_vec3_length(ak_vec3_sub(op[l][i], op[0][i])));
                worst = fmax(worst, ak_vec3_length(ak_vec3_sub(on[l][i], on[0][i])));
                if (w[i] != 0.0f) worst_len = fmax(worst_len, fabs(ak_vec3_length(on[l][i]) - 1.0));
                else AK_CHECK(ak_vec3_length(on[l][i]) == 0.0f);
            }
            AK_CHECK_MSG(worst <= 2e-5 && worst_len <= 2e-6, "%s variant %d: vs scalar %g, |n| - 1 %g", names[l],
                         variant, worst, worst_len);
        }
    }
}

AK_TEST(lbs_tangents_and_face_normals) {
    cylinder c = cylinder_make(21, 16);
    ak_mat4 pal[2] = {ak_mat4_identity(),
                      rot_about(ak_vec3_make(0, 1, 0), ak_vec3_make(0, 0, 1), 1.0f)};
    pal[1] = ak_mat4_mul(pal[1], ak_mat4_scaling(ak_vec3_make(1.2f, 0.9f, 1.0f)));
    size_t n = c.vertex_count;
    float* tan = (float*)malloc(n * 16);
    float* otan = (float*)malloc(n * 16);
    ak_vec3* out = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_vec3* outn = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    for (size_t i = 0; i < n; ++i) {
        tan[4 * i] = 0.0f;
        tan[4 * i + 1] = 1.0f;
        tan[4 * i + 2] = 0.0f;
        tan[4 * i + 3] = (i % 2) ? 1.0f : -1.0f;
    }
    ak_skin_job job = cylinder_job(&c, AK_SKIN_LBS, pal, out, NULL, NULL, 0);
    job.tangents = (ak_cstream){tan, n, 0};
    job.out_tangents = (ak_stream){otan, n, 0};
    job.normals_from_faces = true;
    job.indices = (ak_u32_cspan){c.idx, 3 * c.tri_count};
    job.out_normals = (ak_stream){outn, n, 0};
    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
    double worst_t = 0.0, worst_n = 0.0;
    for (size_t i = 0; i < n; ++i) {
        /* tangent: normalize(C t), w copied */
        double m[9] = {0};
        for (int e = 0; e < 2; ++e)
            for (int col = 0; col < 3; ++col)
                for (int row = 0; row < 3; ++row)
                    m[col * 3 + row] += (double)c.weights[2 * i + e] * pal[e].m[col * 4 + row];
        double t[3] = {m[3], m[4], m[5]}, l = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        for (int a = 0; a < 3; ++a) worst_t = fmax(worst_t, fabs(t[a] / l - otan[4 * i + a]));
        AK_CHECK(otan[4 * i + 3] == tan[4 * i + 3]);
    }
    /* face normals: area-weighted sum of the deformed triangles' normals, in double */
    double* acc = (double*)calloc(3 * n, sizeof(double));
    for (size_t t = 0; t < c.tri_count; ++t) {
        const uint32_t* f = &c.idx[3 * t];
        double e1[3] = {out[f[1]].x - out[f[0]].x, out[f[1]].y - out[f[0]].y,
                        out[f[1]].z - out[f[0]].z};
        double e2[3] = {out[f[2]].x - out[f[0]].x, out[f[2]].y - out[f[0]].y,
                        out[f[2]].z - out[f[0]].z};
        double cr[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                        e1[0] * e2[1] - e1[1] * e2[0]};
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) acc[3 * f[k] + a] += cr[a];
    }
    for (size_t i = 0; i < n; ++i) {
        double l = sqrt(acc[3 * i] * acc[3 * i] + acc[3 * i + 1] * acc[3 * i + 1] +
                        acc[3 * i + 2] * acc[3 * i + 2]);
        worst_n =
            fmax(worst_n, fabs(acc[3 * i] / l - outn[i].x) + fabs(acc[3 * i + 1] / l - outn[i].y) +
                              fabs(acc[3 * i + 2] / l - outn[i].z));
    }
    AK_CHECK_MSG(worst_t < 1e-5, "tangent error %g", worst_t);
    AK_CHECK_MSG(worst_n < 1e-4, "face normal error %g", worst_n);
    /* face normals of the rest pose point outward on the side (consistent orientation) */
    AK_CHECK(outn[5 * 16].x > 0.99f); /* ring 5 (y = 0.5) is rigid and far from the caps */
    free(acc);
    free(tan);
    free(otan);
    free(out);
    free(outn);
    cylinder_free(&c);
}

AK_TEST(bad_joint_indices_clamp_in_every_kernel) {
    /* With skip_data_check, out-of-range joint indices are documented to be clamped to the
     * last palette entry. Each kernel (AVX2: blocks of 8 vertices, with its own clamp for 4
     * influences; AVX-512: blocks of 16; the scalar code) must give the result of the same job with
     * those indices replaced by J - 1 and the data validated, for LBS, DQS and CoR. */
    enum { N = 61, J = 6 };
    ak_rng rng = ak_rng_make(23);
    ak_mat4 pal[J];
    for (int j = 0; j < J; ++j) pal[j] = rand_matrix(&rng, false); /* rigid: DQS/CoR SIMD path */
    ak_vec3 pos[N], nrm[N], ctr[N], ref_p[N], ref_n[N], op[N], on[N];
    uint16_t jn[N * 4], jfix[N * 4];
    float w[N * 4];
    unsigned char scratch[64 + 192 * J]; /* the largest ak_skin_job_scratch_size: CoR */
    for (uint32_t k = 3; k <= 4; ++k) {
        for (int i = 0; i < N; ++i) {
            pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                                  ak_rng_range(&rng, -1, 1));
            nrm[i] = rand_unit(&rng);
            ctr[i] = ak_vec3_scale(pos[i], 0.5f);
            rand_influences(&rng, k, J, &jn[k * i], &w[k * i]);
        }
        memcpy(jfix, jn, sizeof jn);
        for (int i = 0; i < N; i += 3) {
            jn[k * (uint32_t)i + (uint32_t)i % k] = (uint16_t)(i % 2 ? 65535 : J + 2);
            jfix[k * (uint32_t)i + (uint32_t)i % k] = J - 1;
        }
        for (int m = AK_SKIN_LBS; m <= AK_SKIN_COR; ++m) {
            ak_skin_job job = {
                .method = (ak_skin_method)m,
                .influence_count = k,
                .palette = {pal, J},
                .positions = {pos, N, 0},
                .normals = {nrm, N, 0},
                .joints = {jfix, N, 0},
                .weights = {w, N, 0},
                .cor_centers = {ctr, N, 0},
                .scratch = {scratch, sizeof scratch},
                .out_positions = {ref_p, N, 0},
                .out_normals = {ref_n, N, 0},
                .skip_simd = true,
            };
            AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            job.joints.ptr = jn;
            AK_CHECK_EQ(ak_skin_job_validate(&job), AK_ERR_BAD_INDEX);
            job.skip_data_check = true;
            job.out_positions.ptr = op;
            job.out_normals.ptr = on;
            ak_skin_simd levels[3];
            const char* names[3];
            const int level_count = cpu_simd_levels(levels, names);
            job.skip_simd = false;
            for (int l = 0; l < level_count; ++l) { /* every kernel this CPU has */
                job.simd_limit = levels[l];
                memset(op, 0, sizeof op);
                memset(on, 0, sizeof on);
                AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
                double worst = 0.0;
                for (int i = 0; i < N; ++i) {
                    worst = fmax(worst, ak_vec3_length(ak_vec3_sub(op[i], ref_p[i])));
                    worst = fmax(worst, ak_vec3_length(ak_vec3_sub(on[i], ref_n[i])));
                }
                AK_CHECK_MSG(worst < 1e-4, "%s method %d K %u: %g", names[l], m, k, worst); /* a wrong joint: O(1) */
            }
        }
    }
}

AK_TEST(job_split_matches_whole) {
    cylinder c = cylinder_make(21, 16);
    ak_mat4 pal[2] = {ak_mat4_identity(),
                      rot_about(ak_vec3_make(0, 1, 0), ak_vec3_make(1, 0, 0), 0.7f)};
    size_t n = c.vertex_count;
    ak_vec3* a = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_vec3* b = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    unsigned char scratch[512];
    ak_skin_job job = cylinder_job(&c, AK_SKIN_DQS, pal, a, NULL, scratch, sizeof scratch);
    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
    job.out_positions.ptr = b;
    ak_skin_job p1, p2;
    AK_CHECK_EQ(ak_skin_job_split(&job, 0, 101, &p1), AK_OK);
    AK_CHECK_EQ(ak_skin_job_split(&job, 101, n - 101, &p2), AK_OK);
    AK_CHECK_EQ(ak_skin_job_split(&job, 101, n, &p2), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_skin_job_split(&job, 101, n - 101, &p2), AK_OK);
    AK_CHECK_EQ(ak_skin_job_run(&p1), AK_OK);
    AK_CHECK_EQ(ak_skin_job_run(&p2), AK_OK);
    AK_CHECK(memcmp(a, b, n * sizeof(ak_vec3)) == 0);
    free(a);
    free(b);
    cylinder_free(&c);
}

/* ---- DQS ------------------------------------------------------------------------------------- */

AK_TEST(dqs_single_influence_is_rigid) {
    enum { N = 37, J = 5 };
    ak_rng rng = ak_rng_make(3);
    ak_mat4 pal[J];
    for (int j = 0; j < J; ++j)
        pal[j] = rand_matrix(&rng, j == 4); /* joint 4 carries scale/shear */
    ak_vec3 pos[N], nrm[N], out[N], outn[N];
    uint16_t jn[N];
    float w[N];
    for (int i = 0; i < N; ++i) {
        pos[i] = ak_vec3_make(ak_rng_range(&rng, -1, 1), ak_rng_range(&rng, -1, 1),
                              ak_rng_range(&rng, -1, 1));
        nrm[i] = rand_unit(&rng);
        jn[i] = (uint16_t)(i % J);
        w[i] = 1.0f;
    }
    unsigned char scratch[2048];
    for (int variant = 0; variant < 2; ++variant) {
        ak_skin_job job = {
            .method = AK_SKIN_DQS,
            .influence_count = 1,
            .palette = {pal, J},
            .positions = {pos, N, 0},
            .normals = {nrm, N, 0},
            .joints = {jn, N, 0},
            .weights = {w, N, 0},
            .scratch = {scratch, sizeof scratch},
            .out_positions = {out, N, 0},
            .out_normals = {outn, N, 0},
            .skip_simd = variant == 1,
        };
        AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
        double worst = 0.0, worst_n = 0.0;
        for (int i = 0; i < N; ++i) {
            double rp[3], rn[3];
            ref_lbs(pal, &jn[i], &w[i], 1, pos[i], nrm[i], rp, rn);
            worst = fmax(worst,
                         fabs(rp[0] - out[i].x) + fabs(rp[1] - out[i].y) + fabs(rp[2] - out[i].z));
            worst_n = fmax(worst_n, fabs(rn[0] - outn[i].x) + fabs(rn[1] - outn[i].y) +
                                        fabs(rn[2] - outn[i].z));
        }
        /* M p with one matrix: equal up to float rounding of a rotation and translation */
        AK_CHECK_MSG(worst < 2e-5, "variant %d: %g", variant, worst);
        AK_CHECK_MSG(worst_n < 2e-5, "variant %d normals: %g", variant, worst_n);
    }
}

AK_TEST(dqs_rigid_blend_keeps_distance_to_joint) {
    enum { N = 200 };
    ak_rng rng = ak_rng_make(5);
    ak_vec3 pivot = ak_vec3_make(0.3f, 1.0f, -0.2f);
    /* both joints rotate about the same pivot (a joint) and the whole thing moves rigidly */
    ak_mat4 world = rand_matrix(&rng, false);
    ak_mat4 pal[2] = {ak_mat4_mul(world, rot_about(pivot, rand_unit(&rng), 0.4f)),
                      ak_mat4_mul(world, rot_about(pivot, rand_unit(&rng), 2.5f))};
    ak_vec3 pw = ak_mat4_transform_point(world, pivot);
    ak_vec3 pos[N], out[N];
    uint16_t jn[2 * N];
    float w[2 * N];
    for (int i = 0; i < N; ++i) {
        pos[i] = ak_vec3_add(pivot, ak_vec3_scale(rand_unit(&rng), ak_rng_range(&rng, 0.1f, 1.0f)));
        jn[2 * i] = 0;
        jn[2 * i + 1] = 1;
        w[2 * i] = ak_rng_float(&rng);
        w[2 * i + 1] = 1.0f - w[2 * i];
    }
    unsigned char scratch[512];
    for (int variant = 0; variant < 2; ++variant) {
        ak_skin_job job = {
            .method = AK_SKIN_DQS,
            .influence_count = 2,
            .palette = {pal, 2},
            .positions = {pos, N, 0},
            .joints = {jn, N, 0},
            .weights = {w, N, 0},
            .scratch = {scratch, sizeof scratch},
            .out_positions = {out, N, 0},
            .skip_simd = variant == 1,
        };
        AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
        double worst = 0.0;
        for (int i = 0; i < N; ++i)
            worst =
                fmax(worst, fabs(ak_vec3_distance(out[i], pw) - ak_vec3_distance(pos[i], pivot)));
        AK_CHECK_MSG(worst < 1e-5, "variant %d: distance to the joint changes by %g", variant,
                     worst);
    }
}

AK_TEST(dqs_hemisphere_flip) {
    /* +170 and -170 degrees about Z: their quaternions (w >= 0) have dot cos(170) < 0, nearly
     * antipodal. Aligned blending gives the 180 degree midpoint; unaligned would give ~0. */
    ak_mat4 pal[2] = {
        ak_mat4_from_quat(ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), ak_radians(170.0f))),
        ak_mat4_from_quat(ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), ak_radians(-170.0f)))};
    ak_vec3 pos[9], out[9];
    uint16_t jn[18];
    float w[18];
    for (int i = 0; i < 9; ++i) {
        pos[i] = ak_vec3_make(1.0f, 0.1f * (float)i, 0.0f);
        jn[2 * i] = (uint16_t)(i % 2);
        jn[2 * i + 1] = (uint16_t)(1 - i % 2);
        w[2 * i] = 0.5f;
        w[2 * i + 1] = 0.5f;
    }
    unsigned char scratch[512];
    for (int variant = 0; variant < 2; ++variant)
        for (int m = AK_SKIN_DQS; m <= AK_SKIN_COR; ++m) {
            ak_skin_job job = {
                .method = (ak_skin_method)m,
                .influence_count = 2,
                .palette = {pal, 2},
                .positions = {pos, 9, 0},
                .joints = {jn, 9, 0},
                .weights = {w, 9, 0},
                .cor_centers = {pos, 9, 0}, /* center = p: pure rotation of p about the origin */
                .scratch = {scratch, sizeof scratch},
                .out_positions = {out, 9, 0},
                .skip_simd = variant == 1,
            };
            AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            for (int i = 0; i < 9; ++i)
                if (m == AK_SKIN_DQS) {
                    AK_CHECK_NEAR(out[i].x, -1.0f, 1e-5); /* half turn about Z */
                    AK_CHECK_NEAR(out[i].y, -0.1f * (float)i, 1e-5);
                }
            /* CoR with center p: p' = LBS(p), which also exercises the aligned rotation path */
            if (m == AK_SKIN_COR) AK_CHECK_NEAR(out[0].x, cosf(ak_radians(170.0f)), 1e-5);
        }
    /* ... and a tilted pair with a true 180 degree gap through the flip: w = (0.25, 0.75) */
    ak_vec3 axis = ak_vec3_normalize(ak_vec3_make(1, 2, 3));
    ak_mat4 pal2[2] = {ak_mat4_from_quat(ak_quat_from_axis_angle(axis, ak_radians(160.0f))),
                       ak_mat4_from_quat(ak_quat_from_axis_angle(axis, ak_radians(-160.0f)))};
    float w2[2] = {0.25f, 0.75f};
    uint16_t j2[2] = {0, 1};
    ak_vec3 p2 = ak_vec3_any_perpendicular(axis), o2;
    ak_skin_job job = {
        .method = AK_SKIN_DQS,
        .influence_count = 2,
        .palette = {pal2, 2},
        .positions = {&p2, 1, 0},
        .joints = {j2, 1, 0},
        .weights = {w2, 1, 0},
        .scratch = {scratch, sizeof scratch},
        .out_positions = {&o2, 1, 0},
    };
    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
    /* reference: normalised blend 0.25 q(160) + 0.75 q(200) (the 200 degree form of -160) */
    ak_quat qa = ak_quat_from_axis_angle(axis, ak_radians(160.0f)),
            qb = ak_quat_from_axis_angle(axis, ak_radians(200.0f));
    ak_quat qr = ak_quat_normalize(ak_quat_add(ak_quat_scale(qa, 0.25f), ak_quat_scale(qb, 0.75f)));
    ak_vec3 e = ak_quat_rotate(qr, p2);
    AK_CHECK_NEAR(o2.x, e.x, 1e-5);
    AK_CHECK_NEAR(o2.y, e.y, 1e-5);
    AK_CHECK_NEAR(o2.z, e.z, 1e-5);
}

/* ---- CoR ------------------------------------------------------------------------------------ */

AK_TEST(cor_pruned_equals_naive) {
    /* a small cylinder with three joints so triangles carry 1, 2 and 3 bones */
    cylinder c = cylinder_make(13, 10);
    size_t n = c.vertex_count;
    uint16_t* jn = (uint16_t*)malloc(n * 3 * sizeof(uint16_t));
    float* w = (float*)malloc(n * 3 * sizeof(float));
    for (size_t i = 0; i < n; ++i) {
        float y = c.pos[i].y, z = c.pos[i].z;
        float a = smoothstep01((y - 0.4f) / 0.8f),
              b = smoothstep01((z + 0.1f) / 0.2f) * smoothstep01((y - 1.0f) / 0.6f);
        float w0 = 1.0f - a, w1 = a * (1.0f - b), w2 = a * b;
        jn[3 * i] = 0;
        jn[3 * i + 1] = 1;
        jn[3 * i + 2] = 2;
        w[3 * i] = w0;
        w[3 * i + 1] = w1;
        w[3 * i + 2] = w2;
    }
    ak_vec3* naive = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_vec3* pruned = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_vec3* one = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_skin_cor_desc d = {
        .positions = {c.pos, n},
        .indices = {c.idx, 3 * c.tri_count},
        .joints = {jn, 3 * n},
        .weights = {w, 3 * n},
        .influence_count = 3,
        .naive = true,
    };
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){naive, n}), AK_OK);
    d.naive = false;
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){pruned, n}), AK_OK);
    d.thread_count = 1;
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){one, n}), AK_OK);
    double worst = 0.0, worst_threads = 0.0;
    size_t blended = 0;
    for (size_t i = 0; i < n; ++i) {
        worst = fmax(worst, ak_vec3_distance(naive[i], pruned[i]));
        worst_threads = fmax(worst_threads, ak_vec3_distance(one[i], pruned[i]));
        if (ak_vec3_distance(naive[i], c.pos[i]) > 1e-3f) ++blended;
    }
    AK_CHECK_MSG(worst <= 1e-6, "pruned vs naive: %g", worst);
    AK_CHECK(worst_threads == 0.0);
    AK_CHECK(blended > n / 4); /* the comparison covers many real centers, not only fallbacks */
    ak_skin_cor_desc_resolved(&d);
    ak_skin_cor_desc r = ak_skin_cor_desc_resolved(&(ak_skin_cor_desc){0});
    AK_CHECK_NEAR(r.sigma, 0.1f, 0);
    AK_CHECK_NEAR(r.subdivision_threshold, 0.1f, 0);
    AK_CHECK_EQ(r.thread_count, 2);
    /* bad input */
    w[4] = -0.1f;
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){one, n}), AK_ERR_BAD_WEIGHTS);
    w[4] = 0.0f;
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){one, n - 1}),
                AK_ERR_SPAN_SMALL);
    d.influence_count = 0;
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){one, n}), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_skin_cor_centers_compute(NULL, NULL, (ak_vec3_span){one, n}), AK_ERR_NULL_ARG);
    free(jn);
    free(w);
    free(naive);
    free(pruned);
    free(one);
    cylinder_free(&c);
}

AK_TEST(cor_center_in_joint_region_and_cache) {
    cylinder c = cylinder_make(41, 32);
    size_t n = c.vertex_count;
    ak_vec3* ctr = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_skin_cor_desc d = {
        .positions = {c.pos, n},
        .indices = {c.idx, 3 * c.tri_count},
        .joints = {c.joints, 2 * n},
        .weights = {c.weights, 2 * n},
        .influence_count = 2,
    };
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){ctr, n}), AK_OK);
    /* ring 20 is at y = 1, weights (0.5, 0.5): the triangles with similar weights form a band
     * around y = 1, so the center lies on the axis at the joint */
    for (int s = 0; s < 32; ++s) {
        ak_vec3 p = ctr[20 * 32 + s];
        AK_CHECK_MSG(fabsf(p.x) < 0.01f * CYL_RADIUS && fabsf(p.z) < 0.01f * CYL_RADIUS &&
                         fabsf(p.y - 1.0f) < 0.02f,
                     "center %d = (%g, %g, %g)", s, p.x, p.y, p.z);
    }
    /* rigid vertices keep their own position */
    AK_CHECK(ctr[0].x == c.pos[0].x && ctr[0].y == c.pos[0].y);

    /* cache: write, read back with the key, stale key, compute-or-load */
    const char* path = "test_skin_centers.akcr";
    uint64_t key = ak_skin_cor_key(&d);
    AK_CHECK(key != 0);
    AK_CHECK_EQ(ak_skin_cor_centers_write_file(path, (ak_vec3_cspan){ctr, n}, key), AK_OK);
    ak_vec3* back = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    AK_CHECK_EQ(ak_skin_cor_centers_read_file(path, key, (ak_vec3_span){back, n}), AK_OK);
    AK_CHECK(memcmp(back, ctr, n * sizeof(ak_vec3)) == 0);
    AK_CHECK_EQ(ak_skin_cor_centers_read_file(path, key ^ 1u, (ak_vec3_span){back, n}),
                AK_ERR_NOT_FOUND);
    AK_CHECK_EQ(ak_skin_cor_centers_read_file("no/such/file.akcr", key, (ak_vec3_span){back, n}),
                AK_ERR_IO);
    bool from_cache = false;
    memset(back, 0, n * sizeof(ak_vec3));
    AK_CHECK_EQ(ak_skin_cor_centers_cached(&d, path, NULL, (ak_vec3_span){back, n}, &from_cache),
                AK_OK);
    AK_CHECK(from_cache);
    AK_CHECK(memcmp(back, ctr, n * sizeof(ak_vec3)) == 0);
    c.weights[2 * 300] += 0.0f; /* unchanged data: same key */
    AK_CHECK(ak_skin_cor_key(&d) == key);
    c.pos[5].x += 1e-3f; /* changed mesh: the key changes, cache is recomputed */
    AK_CHECK(ak_skin_cor_key(&d) != key);
    AK_CHECK_EQ(ak_skin_cor_centers_cached(&d, path, NULL, (ak_vec3_span){back, n}, &from_cache),
                AK_OK);
    AK_CHECK(!from_cache);
    remove(path);
    /* truncated buffers are parse errors at every length */
    size_t size = ak_skin_cor_centers_encoded_size(n);
    unsigned char* buf = (unsigned char*)malloc(size);
    AK_CHECK_EQ(
        ak_skin_cor_centers_encode((ak_vec3_cspan){ctr, n}, key, (ak_u8_span){buf, size}, NULL),
        AK_OK);
    int wrong = 0;
    for (size_t len = 0; len < size; len += 7)
        if (ak_skin_cor_centers_decode((ak_u8_cspan){buf, len}, key, (ak_vec3_span){back, n}) !=
            AK_ERR_PARSE)
            ++wrong;
    AK_CHECK_EQ(wrong, 0);
    free(buf);
    free(back);
    free(ctr);
    cylinder_free(&c);
}

/* ---- quality on the cylinder ----------------------------------------------------------------- */

typedef struct quality {
    double volume_ratio; /* deformed / rest */
    double bulge;        /* max distance beyond the rest radius from the deformed bone chain */
} quality;

static double seg_dist(ak_vec3 p, ak_vec3 a, ak_vec3 b) {
    ak_vec3 ab = ak_vec3_sub(b, a);
    double t = ak_clampf(ak_vec3_dot(ak_vec3_sub(p, a), ab) / ak_vec3_dot(ab, ab), 0.0f, 1.0f);
    return ak_vec3_distance(p, ak_vec3_madd(a, ab, (float)t));
}

static quality measure(const cylinder* c, const ak_vec3* out, const ak_mat4* pal) {
    quality q;
    q.volume_ratio =
        vol_closed(out, c->idx, c->tri_count) / vol_closed(c->pos, c->idx, c->tri_count);
    ak_vec3 j0 = ak_vec3_make(0, 0, 0), j1 = ak_vec3_make(0, 1, 0),
            j2 = ak_mat4_transform_point(pal[1], ak_vec3_make(0, 2, 0));
    q.bulge = 0.0;
    for (size_t i = 0; i + 2 < c->vertex_count; ++i) { /* skip the two cap centers */
        double d = fmin(seg_dist(out[i], j0, j1), seg_dist(out[i], j1, j2)) - CYL_RADIUS;
        if (d > q.bulge) q.bulge = d;
    }
    return q;
}

AK_TEST(quality_ordering_bend_and_twist) {
    cylinder c = cylinder_make(41, 32);
    size_t n = c.vertex_count;
    ak_vec3* ctr = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_vec3* out = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_skin_cor_desc d = {
        .positions = {c.pos, n},
        .indices = {c.idx, 3 * c.tri_count},
        .joints = {c.joints, 2 * n},
        .weights = {c.weights, 2 * n},
        .influence_count = 2,
    };
    AK_CHECK_EQ(ak_skin_cor_centers_compute(&d, NULL, (ak_vec3_span){ctr, n}), AK_OK);
    unsigned char scratch[512];
    const ak_vec3 pivot = ak_vec3_make(0, 1, 0);
    struct {
        const char* name;
        ak_vec3 axis;
        float degrees;
    } poses[3] = {{"bend 90", {0, 0, 1}, 90.0f},
                  {"twist 90", {0, 1, 0}, 90.0f},
                  {"twist 180", {0, 1, 0}, 180.0f}};
    quality q[3][3];
    for (int p = 0; p < 3; ++p) {
        ak_mat4 pal[2] = {ak_mat4_identity(),
                          rot_about(pivot, poses[p].axis, ak_radians(poses[p].degrees))};
        for (int m = 0; m < 3; ++m) {
            ak_skin_job job =
                cylinder_job(&c, (ak_skin_method)m, pal, out, ctr, scratch, sizeof scratch);
            AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
            q[p][m] = measure(&c, out, pal);
        }
        printf("  %-9s volume LBS %.4f DQS %.4f CoR %.4f | bulge LBS %.4f DQS %.4f CoR %.4f\n",
               poses[p].name, q[p][0].volume_ratio, q[p][1].volume_ratio, q[p][2].volume_ratio,
               q[p][0].bulge, q[p][1].bulge, q[p][2].bulge);
    }
    /* Twist 180: LBS averages I and a half turn, so the middle ring collapses onto the axis
     * (candy wrapper). Over the 0.6-long blend zone of a 2-long cylinder the analytic loss is
     * about 0.6 * (1 - mean of cos^2) / 2 ~ 15% of the volume: require more than 10% lost. */
    AK_CHECK(q[2][0].volume_ratio < 0.90);
    /* DQS and CoR twist rigidly about the axis: volume is kept up to the faceting of the
     * 32-gon cross-section (well under 1%). */
    AK_CHECK(fabs(q[2][1].volume_ratio - 1.0) < 0.01);
    AK_CHECK(fabs(q[2][2].volume_ratio - 1.0) < 0.01);
    AK_CHECK(fabs(q[1][1].volume_ratio - 1.0) < 0.01 && fabs(q[1][2].volume_ratio - 1.0) < 0.01);
    AK_CHECK(q[1][0].volume_ratio < q[1][1].volume_ratio - 0.02); /* LBS already loses at 90 */
    /* Bend 90: LBS collapses the inside of the elbow (volume lost), DQS keeps the volume but
     * bulges on the outside of the bend, CoR keeps the volume with less bulge than DQS. */
    AK_CHECK(q[0][0].volume_ratio < q[0][1].volume_ratio);
    AK_CHECK(fabs(q[0][2].volume_ratio - 1.0) < 0.05);
    AK_CHECK(q[0][1].bulge > 0.02 * CYL_RADIUS);    /* DQS bulge is real, not rounding */
    AK_CHECK(q[0][2].bulge < 0.75 * q[0][1].bulge); /* CoR: clearly less bulge than DQS */
    /* scalar and SIMD agree on the CoR result */
    ak_mat4 pal[2] = {ak_mat4_identity(), rot_about(pivot, poses[0].axis, ak_radians(90.0f))};
    ak_vec3* out2 = (ak_vec3*)malloc(n * sizeof(ak_vec3));
    ak_skin_job job = cylinder_job(&c, AK_SKIN_COR, pal, out, ctr, scratch, sizeof scratch);
    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
    job.skip_simd = true;
    job.out_positions.ptr = out2;
    AK_CHECK_EQ(ak_skin_job_run(&job), AK_OK);
    double worst = 0.0;
    for (size_t i = 0; i < n; ++i) worst = fmax(worst, ak_vec3_distance(out[i], out2[i]));
    AK_CHECK_MSG(worst < 1e-5, "CoR simd vs scalar %g", worst);
    free(out2);
    free(out);
    free(ctr);
    cylinder_free(&c);
}

/* ---- weights -------------------------------------------------------------------------------- */

/* A closed "pants" surface from voxels: a pelvis block on two legs with a gap between them. */
typedef struct voxel_shape {
    size_t vertex_count, tri_count;
    ak_vec3* pos;
    uint32_t* idx;
} voxel_shape;

#define VX 20
#define VY 40
#define VZ 8
#define VH 0.025f
static bool pants_solid(int x, int y, int z) {
    if (x < 0 || y < 0 || z < 0 || x >= VX || y >= VY || z >= VZ) return false;
    if (y >= 32) return true; /* pelvis: y in [0.8, 1.0] */
    return x < 8 || x >= 12;  /* legs: x in [-0.25, -0.05] and [0.05, 0.25] */
}

static voxel_shape pants_make(void) {
    voxel_shape s;
    const int gx = VX + 1, gy = VY + 1, gz = VZ + 1;
    int32_t* map = (int32_t*)malloc((size_t)gx * gy * gz * sizeof(int32_t));
    for (int i = 0; i < gx * gy * gz; ++i) map[i] = -1;
    s.pos = (ak_vec3*)malloc((size_t)gx * gy * gz * sizeof(ak_vec3));
    s.idx = (uint32_t*)malloc((size_t)VX * VY * VZ * 6 * 6 * sizeof(uint32_t));
    s.vertex_count = 0;
    s.tri_count = 0;
    for (int x = 0; x < VX; ++x)
        for (int y = 0; y < VY; ++y)
            for (int z = 0; z < VZ; ++z) {
                if (!pants_solid(x, y, z)) continue;
                for (int axis = 0; axis < 3; ++axis)
                    for (int dir = -1; dir <= 1; dir += 2) {
                        int n[3] = {x, y, z};
                        n[axis] += dir;
                        if (pants_solid(n[0], n[1], n[2])) continue;
                        int u = (axis + 1) % 3, v = (axis + 2) % 3;
                        int base[3] = {x, y, z};
                        if (dir > 0) base[axis] += 1;
                        uint32_t q[4];
                        int du[4] = {0, 1, 1, 0}, dv[4] = {0, 0, 1, 1};
                        for (int k = 0; k < 4; ++k) {
                            int g[3] = {base[0], base[1], base[2]};
                            g[u] += du[k];
                            g[v] += dv[k];
                            int gi = (g[0] * gy + g[1]) * gz + g[2];
                            if (map[gi] < 0) {
                                map[gi] = (int32_t)s.vertex_count;
                                s.pos[s.vertex_count++] =
                                    ak_vec3_make(-0.25f + VH * (float)g[0], VH * (float)g[1],
                                                 -0.1f + VH * (float)g[2]);
                            }
                            q[k] = (uint32_t)map[gi];
                        }
                        /* e_u x e_v = e_axis: (0,1,2,3) faces +axis; reversed for -axis */
                        uint32_t t[6] = {q[0], q[1], q[2], q[0], q[2], q[3]};
                        if (dir < 0) {
                            uint32_t r[6] = {q[0], q[2], q[1], q[0], q[3], q[2]};
                            memcpy(t, r, sizeof r);
                        }
                        memcpy(&s.idx[3 * s.tri_count], t, sizeof t);
                        s.tri_count += 2;
                    }
            }
    free(map);
    return s;
}

AK_TEST(heat_weights_do_not_bleed_between_legs) {
    voxel_shape s = pants_make();
    /* the surface is closed and consistently oriented: positive volume = 0.5*0.2*0.2 +
     * 2*0.2*0.2*0.8 */
    AK_CHECK_NEAR(vol_closed(s.pos, s.idx, s.tri_count), 0.5 * 0.2 * 0.2 + 2 * 0.2 * 0.2 * 0.8,
                  1e-5);
    ak_vec3 joints[7] = {{0, 0.9f, 0},     {-0.15f, 0.8f, 0}, {-0.15f, 0.4f, 0}, {-0.15f, 0.05f, 0},
                         {0.15f, 0.8f, 0}, {0.15f, 0.4f, 0},  {0.15f, 0.05f, 0}};
    int32_t parents[7] = {-1, 0, 1, 2, 0, 4, 5};
    ak_skin_bone bones[14];
    size_t bone_count = 0;
    AK_CHECK_EQ(ak_skin_bones_from_joints((ak_vec3_cspan){joints, 7}, (ak_i32_cspan){parents, 7},
                                          false, (ak_skin_bone_span){bones, 14}, &bone_count),
                AK_OK);
    AK_CHECK_EQ(bone_count, 8); /* pelvis->2 hips, hip->knee, knee->ankle, two point ankles */
    const uint32_t k = 4;
    uint16_t* jn = (uint16_t*)malloc(s.vertex_count * k * sizeof(uint16_t));
    float* w = (float*)malloc(s.vertex_count * k * sizeof(float));
    double worst[2] = {0, 0};
    for (int method = 0; method < 2; ++method) {
        ak_weights_desc d = {
            .method = method == 0 ? AK_WEIGHTS_HEAT : AK_WEIGHTS_DISTANCE,
            .positions = {s.pos, s.vertex_count},
            .indices = {s.idx, 3 * s.tri_count},
            .bones = {bones, bone_count},
            .min_weight = -1.0f, /* keep every weight: nothing hides below a cut-off */
        };
        AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, s.vertex_count * k},
                                            (ak_f32_span){w, s.vertex_count * k}),
                    AK_OK);
        AK_CHECK_EQ(ak_skin_weights_validate((ak_u16_cspan){jn, s.vertex_count * k},
                                             (ak_f32_cspan){w, s.vertex_count * k}, s.vertex_count,
                                             k, 7, 1e-6f, NULL),
                    AK_OK);
        for (size_t v = 0; v < s.vertex_count; ++v) {
            /* The left leg: left of the gap and at least one leg width (0.2) below the crotch
             * (y = 0.8). The band right under the crotch is shared with the pelvis, and through
             * it heat from the other hip reaches ~1% there (as with Blender's automatic weights:
             * the diffusion length is about the distance to the nearest bone). */
            if (!(s.pos[v].x < -0.05f - 1e-4f && s.pos[v].y < 0.6f + 1e-4f)) continue;
            double right = 0.0;
            for (uint32_t e = 0; e < k; ++e)
                if (jn[v * k + e] >= 4) right += w[v * k + e];
            worst[method] = fmax(worst[method], right);
        }
    }
    printf("  largest right-leg weight on the left leg: heat %.2e, inverse distance %.3f\n",
           worst[0], worst[1]);
    AK_CHECK(worst[0] < 0.01);
    AK_CHECK(worst[1] > 0.01); /* inverse distance bleeds across the gap */
    free(jn);
    free(w);
    free(s.pos);
    free(s.idx);
}

AK_TEST(distance_weights_stray_far_vertex) {
    /* One stray vertex far from everything must not change the other vertices' weights: the
     * "on a bone" threshold used to scale with the mesh's bounding box, so a vertex at 1e9
     * made every vertex within ~100 units count as on every bone (equal weights). Closed
     * forms with n = 4 as in the test above: d = 1 and 2 -> 16/17, 1/17. */
    ak_skin_bone bones[2] = {{{0, 0, 0}, {0, 0, 0}, 0}, {{3, 0, 0}, {3, 0, 0}, 1}};
    const float far[3] = {1e9f, 1e20f, 3e38f};
    for (int f = 0; f < 3; ++f) {
        ak_vec3 pos[3] = {{1, 0, 0}, {far[f], 0, 0}, {2, 0, 0}};
        uint16_t jn[3 * 2];
        float w[3 * 2];
        ak_weights_desc d = {.method = AK_WEIGHTS_DISTANCE,
                             .positions = {pos, 3},
                             .bones = {bones, 2},
                             .max_influences = 2};
        AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 6}, (ak_f32_span){w, 6}),
                    AK_OK);
        AK_CHECK_EQ(jn[0], 0);
        AK_CHECK_MSG(fabs(w[0] - 16.0 / 17.0) < 1e-6 && fabs(w[1] - 1.0 / 17.0) < 1e-6,
                     "stray vertex at %g: weights %g %g, want 16/17 1/17", (double)far[f],
                     (double)w[0], (double)w[1]);
        AK_CHECK_EQ(jn[4], 1);
        AK_CHECK_NEAR(w[4], 16.0 / 17.0, 1e-6);
        /* the far vertex itself: finite, sums to 1 */
        AK_CHECK(ak_finitef(w[2]) && ak_finitef(w[3]));
        AK_CHECK_NEAR(w[2] + w[3], 1.0, 1e-6);
    }
}

AK_TEST(distance_weights_closed_forms_and_robustness) {
    ak_skin_bone bones[2] = {{{0, 0, 0}, {0, 0, 0}, 0}, {{3, 0, 0}, {3, 0, 0}, 1}};
    ak_vec3 pos[5] = {{1, 0, 0}, {1.5f, 0, 0}, {0, 0, 0}, {1e6f, 3e6f, 0}, {3, 0, 0}};
    uint16_t jn[5 * 2];
    float w[5 * 2];
    ak_weights_desc d = {
        .method = AK_WEIGHTS_DISTANCE,
        .positions = {pos, 5},
        .bones = {bones, 2},
        .max_influences = 2,
    };
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 10}, (ak_f32_span){w, 10}),
                AK_OK);
    /* d = 1 and 2, n = 4: w = 16/17 and 1/17 */
    AK_CHECK_EQ(jn[0], 0);
    AK_CHECK_NEAR(w[0], 16.0 / 17.0, 1e-6);
    AK_CHECK_NEAR(w[1], 1.0 / 17.0, 1e-6);
    /* equidistant: 1/2 each */
    AK_CHECK_NEAR(w[2], 0.5, 1e-6);
    AK_CHECK_NEAR(w[3], 0.5, 1e-6);
    /* on a bone: all weight on it, no NaN */
    AK_CHECK_EQ(jn[4], 0);
    AK_CHECK(w[4] == 1.0f && w[5] == 0.0f);
    AK_CHECK_EQ(jn[8], 1);
    AK_CHECK(w[8] == 1.0f);
    /* far away: finite, sums to 1, nearly even */
    AK_CHECK(ak_finitef(w[6]) && ak_finitef(w[7]));
    AK_CHECK_NEAR(w[6] + w[7], 1.0, 1e-6);
    AK_CHECK_NEAR(w[6], 0.5, 1e-3);
    /* power 2: 4/5 and 1/5 */
    d.distance_power = 2.0f;
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 10}, (ak_f32_span){w, 10}),
                AK_OK);
    AK_CHECK_NEAR(w[0], 0.8, 1e-6);
    /* k = 1 keeps the nearest only; defaults */
    d.max_influences = 1;
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 5}, (ak_f32_span){w, 5}),
                AK_OK);
    AK_CHECK(w[0] == 1.0f && jn[0] == 0);
    ak_weights_desc r = ak_weights_desc_resolved(&(ak_weights_desc){0});
    AK_CHECK_EQ(r.max_influences, 4);
    AK_CHECK_NEAR(r.distance_power, 4.0, 0);
    AK_CHECK_NEAR(r.min_weight, 0.001, 1e-9);
    AK_CHECK_EQ(r.method, AK_WEIGHTS_HEAT);
    /* bad input */
    AK_CHECK_EQ(ak_skin_weights_compute(NULL, NULL, (ak_u16_span){jn, 5}, (ak_f32_span){w, 5}),
                AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 4}, (ak_f32_span){w, 5}),
                AK_ERR_SPAN_SMALL);
    pos[2].y = NAN;
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 5}, (ak_f32_span){w, 5}),
                AK_ERR_BAD_DATA);
    pos[2].y = 0.0f;
    d.method = AK_WEIGHTS_HEAT; /* needs triangles */
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 5}, (ak_f32_span){w, 5}),
                AK_ERR_EMPTY);
    uint32_t tri[3] = {0, 1, 7};
    d.indices = (ak_u32_cspan){tri, 3};
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 5}, (ak_f32_span){w, 5}),
                AK_ERR_BAD_INDEX);
    d.max_influences = 9;
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 5}, (ak_f32_span){w, 5}),
                AK_ERR_BAD_ARG);
}

AK_TEST(heat_weights_ignore_a_stray_far_vertex) {
    /* A loose vertex far away (on no triangle) must not change the cylinder's heat weights.
     * The "on a bone" clamp and the tie band of the nearest-bone test used to scale with the
     * mesh's bounding box: with a vertex at 1e9 every cylinder vertex became a tie between
     * both bones and the weights flattened towards 1/2 all along the cylinder. */
    cylinder c = cylinder_make(41, 16);
    ak_skin_bone bones[2] = {{{0, 0, 0}, {0, 1, 0}, 0}, {{0, 1, 0}, {0, 2, 0}, 1}};
    size_t n = c.vertex_count;
    ak_vec3* pos = (ak_vec3*)malloc((n + 1) * sizeof(ak_vec3));
    uint16_t* jn = (uint16_t*)malloc(2 * (n + 1) * 4 * sizeof(uint16_t));
    float* w = (float*)malloc(2 * (n + 1) * 4 * sizeof(float));
    memcpy(pos, c.pos, n * sizeof(ak_vec3));
    pos[n] = ak_vec3_make(1e9f, 0.0f, 0.0f);
    ak_weights_desc d = {
        .positions = {pos, n}, .indices = {c.idx, 3 * c.tri_count}, .bones = {bones, 2}};
    AK_CHECK_EQ(
        ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 4 * n}, (ak_f32_span){w, 4 * n}),
        AK_OK);
    d.positions.count = n + 1;
    uint16_t* jn2 = jn + 4 * (n + 1);
    float* w2 = w + 4 * (n + 1);
    AK_CHECK_EQ(ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn2, 4 * (n + 1)},
                                        (ak_f32_span){w2, 4 * (n + 1)}),
                AK_OK);
    double worst = 0.0;
    for (size_t v = 0; v < n; ++v) {
        double a[2] = {0, 0}, b[2] = {0, 0};
        for (int e = 0; e < 4; ++e) {
            if (jn[4 * v + e] < 2) a[jn[4 * v + e]] += w[4 * v + e];
            if (jn2[4 * v + e] < 2) b[jn2[4 * v + e]] += w2[4 * v + e];
        }
        worst = fmax(worst, fabs(a[1] - b[1]));
    }
    AK_CHECK_MSG(worst < 1e-4, "a stray vertex at 1e9 changed a cylinder weight by %g", worst);
    /* the stray vertex itself: its nearest bone, weight 1 */
    AK_CHECK(w2[4 * n] == 1.0f);
    free(pos);
    free(jn);
    free(w);
    cylinder_free(&c);
}

AK_TEST(heat_weights_on_cylinder_are_smooth_and_normalized) {
    cylinder c = cylinder_make(41, 16);
    ak_skin_bone bones[2] = {{{0, 0, 0}, {0, 1, 0}, 0}, {{0, 1, 0}, {0, 2, 0}, 1}};
    size_t n = c.vertex_count;
    uint16_t* jn = (uint16_t*)malloc(n * 4 * sizeof(uint16_t));
    float* w = (float*)malloc(n * 4 * sizeof(float));
    ak_weights_desc d = {
        .positions = {c.pos, n}, .indices = {c.idx, 3 * c.tri_count}, .bones = {bones, 2}};
    AK_CHECK_EQ(
        ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 4 * n}, (ak_f32_span){w, 4 * n}),
        AK_OK);
    double worst_sum = 0.0;
    for (size_t v = 0; v < n; ++v) {
        double s = 0.0;
        for (int e = 0; e < 4; ++e) {
            AK_CHECK(w[4 * v + e] >= 0.0f);
            s += w[4 * v + e];
        }
        worst_sum = fmax(worst_sum, fabs(s - 1.0));
    }
    AK_CHECK(worst_sum <= 1e-6);
    /* far ends are rigid, the joint ring is shared roughly evenly, weight of joint 1 grows with y
     */
    AK_CHECK(jn[0] == 0 && w[0] > 0.99f);
    AK_CHECK(jn[4 * (40 * 16)] == 1 && w[4 * (40 * 16)] > 0.99f);
    float w1_mid = 0.0f;
    for (int e = 0; e < 4; ++e)
        if (jn[4 * (20 * 16) + e] == 1) w1_mid = w[4 * (20 * 16) + e];
    AK_CHECK(w1_mid > 0.3f && w1_mid < 0.7f);
    free(jn);
    free(w);
    cylinder_free(&c);
}

AK_TEST(heat_weights_degenerate_input) {
    /* a tetrahedron plus: an isolated vertex, a zero-area triangle, a duplicate vertex, a vertex
     * exactly on a bone, and a zero-length (point) bone far away */
    ak_vec3 pos[7] = {
        {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {5, 5, 5}, {1, 0, 0}, {0.25f, 0.25f, 0.25f}};
    uint32_t idx[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 1, 5, 1, 6, 6, 6};
    ak_skin_bone bones[3] = {{{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}, 0},
                             {{0.25f, 0.25f, 0.25f}, {0.25f, 0.25f, 0.6f}, 1},
                             {{9, 9, 9}, {9, 9, 9}, 2}};
    uint16_t jn[7 * 4];
    float w[7 * 4];
    for (int method = 0; method < 2; ++method)
        for (int vis = 0; vis < 2; ++vis) {
            ak_weights_desc d = {
                .method = method ? AK_WEIGHTS_DISTANCE : AK_WEIGHTS_HEAT,
                .positions = {pos, 7},
                .indices = {idx, sizeof idx / sizeof idx[0]},
                .bones = {bones, 3},
                .skip_visibility = vis == 1,
            };
            AK_CHECK_EQ(
                ak_skin_weights_compute(&d, NULL, (ak_u16_span){jn, 28}, (ak_f32_span){w, 28}),
                AK_OK);
            AK_CHECK_EQ(ak_skin_weights_validate((ak_u16_cspan){jn, 28}, (ak_f32_cspan){w, 28}, 7,
                                                 4, 3, 1e-6f, NULL),
                        AK_OK);
            /* heat: the isolated vertex takes its nearest bone (the point at (9, 9, 9)) fully;
             * distance: it blends, the nearest first */
            AK_CHECK(jn[4 * 4] == 2);
            if (method == 0) AK_CHECK(w[4 * 4] == 1.0f);
        }
}

AK_TEST(weights_format_round_trip) {
    enum { N = 50, K = 3 };
    ak_rng rng = ak_rng_make(9);
    uint16_t jn[N * K], jb[N * K];
    float w[N * K], wb[N * K];
    for (int i = 0; i < N; ++i) rand_influences(&rng, K, 300, &jn[i * K], &w[i * K]);
    size_t size = ak_skin_weights_encoded_size(N, K);
    AK_CHECK_EQ(size, 16 + ((N * K * 2 + 3) & ~3) + N * K * 4);
    unsigned char* buf = (unsigned char*)malloc(size);
    size_t written = 0;
    AK_CHECK_EQ(ak_skin_weights_encode((ak_u16_cspan){jn, N * K}, (ak_f32_cspan){w, N * K}, N, K,
                                       (ak_u8_span){buf, size}, &written),
                AK_OK);
    AK_CHECK_EQ(written, size);
    AK_CHECK(memcmp(buf, "AKWT", 4) == 0 && buf[12] == K && buf[8] == N);
    size_t vc = 0;
    uint32_t k = 0;
    AK_CHECK_EQ(ak_skin_weights_decode_info((ak_u8_cspan){buf, size}, &vc, &k, NULL), AK_OK);
    AK_CHECK(vc == N && k == K);
    AK_CHECK_EQ(ak_skin_weights_decode((ak_u8_cspan){buf, size}, (ak_u16_span){jb, N * K},
                                       (ak_f32_span){wb, N * K}, NULL),
                AK_OK);
    AK_CHECK(memcmp(jb, jn, sizeof jn) == 0 && memcmp(wb, w, sizeof w) == 0);
    int wrong = 0;
    ak_diag diag;
    for (size_t len = 0; len < size; ++len)
        if (ak_skin_weights_decode((ak_u8_cspan){buf, len}, (ak_u16_span){jb, N * K},
                                   (ak_f32_span){wb, N * K}, &diag) != AK_ERR_PARSE)
            ++wrong;
    AK_CHECK_EQ(wrong, 0);
    AK_CHECK(diag.message[0] != 0);
    buf[4] = 2; /* unknown version */
    AK_CHECK_EQ(ak_skin_weights_decode_info((ak_u8_cspan){buf, size}, &vc, &k, NULL), AK_ERR_PARSE);
    buf[4] = 1;
    const char* path = "test_skin_weights.akwt";
    AK_CHECK_EQ(
        ak_skin_weights_write_file(path, (ak_u16_cspan){jn, N * K}, (ak_f32_cspan){w, N * K}, N, K),
        AK_OK);
    AK_CHECK_EQ(ak_skin_weights_read_file_info(path, &vc, &k, NULL), AK_OK);
    AK_CHECK(vc == N && k == K);
    memset(wb, 0, sizeof wb);
    AK_CHECK_EQ(
        ak_skin_weights_read_file(path, (ak_u16_span){jb, N * K}, (ak_f32_span){wb, N * K}, NULL),
        AK_OK);
    AK_CHECK(memcmp(wb, w, sizeof w) == 0);
    AK_CHECK_EQ(ak_skin_weights_read_file(path, (ak_u16_span){jb, N * K - 1},
                                          (ak_f32_span){wb, N * K}, NULL),
                AK_ERR_SPAN_SMALL);
    remove(path);
    AK_CHECK_EQ(
        ak_skin_weights_read_file(path, (ak_u16_span){jb, N * K}, (ak_f32_span){wb, N * K}, NULL),
        AK_ERR_IO);
    free(buf);
}

AK_TEST(bones_from_joints) {
    ak_vec3 jp[4] = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0}, {1, 1, 0}};
    int32_t parents[4] = {-1, 0, 1, 1};
    ak_skin_bone b[8];
    size_t count = 0;
    AK_CHECK_EQ(ak_skin_bones_from_joints_bound(4), 8);
    AK_CHECK_EQ(ak_skin_bones_from_joints((ak_vec3_cspan){jp, 4}, (ak_i32_cspan){parents, 4}, true,
                                          (ak_skin_bone_span){b, 8}, &count),
                AK_OK);
    AK_CHECK_EQ(count, 3); /* 0->1, 1->2, 1->3; leaves skipped */
    AK_CHECK(b[0].joint_index == 0 && b[1].joint_index == 1 && b[2].joint_index == 1);
    AK_CHECK(b[2].tail.x == 1.0f);
    AK_CHECK_EQ(ak_skin_bones_from_joints((ak_vec3_cspan){jp, 4}, (ak_i32_cspan){parents, 4}, false,
                                          (ak_skin_bone_span){b, 8}, &count),
                AK_OK);
    AK_CHECK_EQ(count, 5);
    parents[2] = 3;
    AK_CHECK_EQ(ak_skin_bones_from_joints((ak_vec3_cspan){jp, 4}, (ak_i32_cspan){parents, 4}, false,
                                          (ak_skin_bone_span){b, 8}, &count),
                AK_ERR_BAD_HIERARCHY);
    parents[2] = 1;
    AK_CHECK_EQ(ak_skin_bones_from_joints((ak_vec3_cspan){jp, 4}, (ak_i32_cspan){parents, 4}, false,
                                          (ak_skin_bone_span){b, 4}, &count),
                AK_ERR_SPAN_SMALL);
}

int main(void) {
    printf("skin kernel: %s\n", ak_skin_simd_name());
    AK_RUN(job_validate_rules);
    AK_RUN(job_bad_data_codes);
    AK_RUN(job_data_screen_catches_faults_everywhere);
    AK_RUN(lbs_matches_double_reference);
    AK_RUN(dqs_cor_simd_matches_scalar_for_every_influence_count);
    AK_RUN(every_simd_kernel_matches_scalar);
    AK_RUN(lbs_kernels_match_reference_around_palette_copy_limit);
    AK_RUN(lbs_single_influence_rigid_path);
    AK_RUN(lbs_tangents_and_face_normals);
    AK_RUN(bad_joint_indices_clamp_in_every_kernel);
    AK_RUN(job_split_matches_whole);
    AK_RUN(dqs_single_influence_is_rigid);
    AK_RUN(dqs_rigid_blend_keeps_distance_to_joint);
    AK_RUN(dqs_hemisphere_flip);
    AK_RUN(cor_pruned_equals_naive);
    AK_RUN(cor_center_in_joint_region_and_cache);
    AK_RUN(quality_ordering_bend_and_twist);
    AK_RUN(heat_weights_do_not_bleed_between_legs);
    AK_RUN(distance_weights_closed_forms_and_robustness);
    AK_RUN(distance_weights_stray_far_vertex);
    AK_RUN(heat_weights_on_cylinder_are_smooth_and_normalized);
    AK_RUN(heat_weights_ignore_a_stray_far_vertex);
    AK_RUN(heat_weights_degenerate_input);
    AK_RUN(weights_format_round_trip);
    AK_RUN(bones_from_joints);
    return ak_test_finish();
}
