/* blendshape: dense/sparse/full forms against double-precision references written here. */
#include <animkit/blendshape.h>

#include "ak_test.h"

/* ---- helpers ------------------------------------------------------------------------------ */

/* Three draws in a fixed order (argument evaluation order is unspecified in C, so
 * make(rng(), rng(), rng()) would give different data under gcc and clang). */
static ak_vec3 rand3(ak_rng* r, float lx, float hx, float ly, float hy, float lz, float hz) {
    float x = ak_rng_range(r, lx, hx);
    float y = ak_rng_range(r, ly, hy);
    float z = ak_rng_range(r, lz, hz);
    return ak_vec3_make(x, y, z);
}

static void fill_random(ak_vec3* v, size_t n, ak_rng* rng, float lo, float hi) {
    for (size_t i = 0; i < n; ++i)
        v[i] = rand3(rng, lo, hi, lo, hi, lo, hi);
}

static void fill_unit(ak_vec3* v, size_t n, ak_rng* rng) {
    for (size_t i = 0; i < n; ++i) {
        ak_vec3 d;
        do d = rand3(rng, -1, 1, -1, 1, -1, 1);
        while (ak_vec3_length(d) < 0.1f);
        v[i] = ak_vec3_normalize(d);
    }
}

/* Local targets: each moves a contiguous run of `moved` vertices starting at a random place;
 * the rest of the deltas are exactly zero. */
static void fill_local(ak_vec3* d, size_t k_count, size_t v, size_t moved, ak_rng* rng) {
    memset(d, 0, k_count * v * sizeof(ak_vec3));
    for (size_t k = 0; k < k_count; ++k) {
        size_t start = (size_t)(ak_rng_float(rng) * (float)(v - moved));
        fill_random(d + k * v + start, moved, rng, -0.2f, 0.2f);
    }
}

/* out = base + sum_k w_k d_k in double. */
static void ref_blend(const ak_vec3* base, const ak_vec3* d, const float* w, size_t k_count, size_t v, double* out) {
    for (size_t i = 0; i < v; ++i) {
        double x = base[i].x, y = base[i].y, z = base[i].z;
        for (size_t k = 0; k < k_count; ++k) {
            x += (double)w[k] * d[k * v + i].x;
            y += (double)w[k] * d[k * v + i].y;
            z += (double)w[k] * d[k * v + i].z;
        }
        out[3 * i] = x;
        out[3 * i + 1] = y;
        out[3 * i + 2] = z;
    }
}

static double max_err(const ak_vec3* a, const double* ref, size_t v) {
    double e = 0.0;
    for (size_t i = 0; i < v; ++i) {
        double dx = fabs(a[i].x - ref[3 * i]), dy = fabs(a[i].y - ref[3 * i + 1]), dz = fabs(a[i].z - ref[3 * i + 2]);
        if (!(dx <= e)) e = dx;
        if (!(dy <= e)) e = dy;
        if (!(dz <= e)) e = dz;
    }
    return e;
}

static double max_diff(const ak_vec3* a, const ak_vec3* b, size_t v) {
    double e = 0.0;
    for (size_t i = 0; i < v; ++i) {
        double d = fabs((double)a[i].x - b[i].x) + fabs((double)a[i].y - b[i].y) + fabs((double)a[i].z - b[i].z);
        if (!(d <= e)) e = d;
    }
    return e;
}

/* Normalise a double reference in place (zero -> (0,1,0), the documented fallback). */
static void ref_normalize(double* n, size_t v) {
    for (size_t i = 0; i < v; ++i) {
        double l = sqrt(n[3 * i] * n[3 * i] + n[3 * i + 1] * n[3 * i + 1] + n[3 * i + 2] * n[3 * i + 2]);
        if (l < 1e-12) {
            n[3 * i] = 0.0;
            n[3 * i + 1] = 1.0;
            n[3 * i + 2] = 0.0;
        } else {
            n[3 * i] /= l;
            n[3 * i + 1] /= l;
            n[3 * i + 2] /= l;
        }
    }
}

enum { V = 1500, K = 7 }; /* 3V floats > one kernel block; K not a multiple of 4 */

/* ---- tests ------------------------------------------------------------------------------- */

AK_TEST(dense_matches_double_reference) {
    static ak_vec3 base[V], d[K * V], out[V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(1);
    fill_random(base, V, &rng, -1, 1);
    fill_random(d, K * V, &rng, -0.3f, 0.3f);
    float w[K] = {0.3f, 0.0f, -0.7f, 1.4f, 0.0f, 0.25f, 2.0f}; /* zeros skipped, negatives and >1 */
    ak_blendshape_dense_job job = {
        .weights = AK_SPAN(w), .base_positions = {base, V}, .deltas = {d, K * V}, .out_positions = {out, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&job), AK_OK);
    ref_blend(base, d, w, K, V, ref);
    AK_CHECK_NEAR(max_err(out, ref, V), 0.0, 2e-6);

    /* K = 0: the base comes back. */
    ak_blendshape_dense_job none = {.base_positions = {base, V}, .out_positions = {out, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&none), AK_OK);
    AK_CHECK_NEAR(max_diff(out, base, V), 0.0, 0.0);
}

AK_TEST(full_and_differential_agree_when_weights_sum_to_one) {
    enum { S = K + 1 }; /* b_0 .. b_K */
    static ak_vec3 shapes[S * V], deltas[K * V], full[V], diff[V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(2);
    fill_random(shapes, S * V, &rng, -1, 1);
    float wf[S], wd[K];
    double sum = 0.0;
    for (int k = 1; k < S; ++k) {
        wf[k] = wd[k - 1] = ak_rng_range(&rng, -0.4f, 0.8f);
        sum += wf[k];
    }
    wf[0] = (float)(1.0 - sum);
    /* Deltas computed here, independently of ak_blendshape_deltas_from_shapes. */
    for (int k = 1; k < S; ++k)
        for (int i = 0; i < V; ++i) deltas[(k - 1) * V + i] = ak_vec3_sub(shapes[k * V + i], shapes[i]);

    ak_blendshape_full_job fj = {.weights = {wf, S}, .shapes = {shapes, S * V}, .out_positions = {full, V}};
    AK_CHECK_EQ(ak_blendshape_full_run(&fj), AK_OK);
    ak_blendshape_dense_job dj = {
        .weights = {wd, K}, .base_positions = {shapes, V}, .deltas = {deltas, K * V}, .out_positions = {diff, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&dj), AK_OK);
    AK_CHECK_NEAR(max_diff(full, diff, V), 0.0, 2e-5);

    /* Both against sum_k w_k b_k in double. */
    for (int i = 0; i < V; ++i) {
        double x = 0, y = 0, z = 0;
        for (int k = 0; k < S; ++k) {
            x += (double)wf[k] * shapes[k * V + i].x;
            y += (double)wf[k] * shapes[k * V + i].y;
            z += (double)wf[k] * shapes[k * V + i].z;
        }
        ref[3 * i] = x, ref[3 * i + 1] = y, ref[3 * i + 2] = z;
    }
    AK_CHECK_NEAR(max_err(full, ref, V), 0.0, 1e-5);
    AK_CHECK_NEAR(max_err(diff, ref, V), 0.0, 1e-5);

    /* ak_blendshape_deltas_from_shapes gives the same deltas. */
    static ak_vec3 d2[K * V];
    AK_CHECK_EQ(ak_blendshape_deltas_from_shapes((ak_vec3_cspan){shapes, V}, (ak_vec3_cspan){shapes + V, K * V},
                                                 (ak_vec3_span){d2, K * V}),
                AK_OK);
    AK_CHECK_NEAR(max_diff(d2, deltas, K * V), 0.0, 0.0);
}

AK_TEST(sparse_equals_dense) {
    static ak_vec3 base[V], d[K * V], o_dense[V], o_sparse[V], o_auto[V], o_raw[V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(3);
    fill_random(base, V, &rng, -1, 1);
    fill_local(d, K, V, V / 10, &rng);
    float w[K] = {0.5f, 1.0f, -0.25f, 0.0f, 0.75f, 0.1f, 1.5f};
    ak_blendshape_set *dense = NULL, *sparse = NULL, *autos = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = V, .target_count = K, .deltas = {d, K * V},
                                   .storage = AK_BLENDSHAPE_STORAGE_DENSE};
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &dense), AK_OK);
    desc.storage = AK_BLENDSHAPE_STORAGE_SPARSE;
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &sparse), AK_OK);
    desc.storage = AK_BLENDSHAPE_STORAGE_AUTO;
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &autos), AK_OK);
    if (!dense || !sparse || !autos) return;

    /* Kept counts equal the non-zero rows counted here; auto picks sparse for 10% targets. */
    for (size_t k = 0; k < K; ++k) {
        size_t nz = 0;
        for (size_t i = 0; i < V; ++i) nz += ak_vec3_length_sq(d[k * V + i]) > 0.0f;
        AK_CHECK_EQ(ak_blendshape_set_moved_count(sparse, k), nz);
        AK_CHECK_EQ(ak_blendshape_set_moved_count(dense, k), V);
        AK_CHECK(ak_blendshape_set_target_is_sparse(sparse, k));
        AK_CHECK(!ak_blendshape_set_target_is_sparse(dense, k));
        AK_CHECK(ak_blendshape_set_target_is_sparse(autos, k));
    }
    AK_CHECK(ak_blendshape_set_memory_size(sparse) < ak_blendshape_set_memory_size(dense) / 4);

    ak_blendshape_job job = {.set = dense, .weights = AK_SPAN(w), .base_positions = {base, V}, .out_positions = {o_dense, V}};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    job.set = sparse, job.out_positions = (ak_vec3_span){o_sparse, V};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    job.set = autos, job.out_positions = (ak_vec3_span){o_auto, V};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    ak_blendshape_dense_job raw = {.weights = AK_SPAN(w), .base_positions = {base, V}, .deltas = {d, K * V},
                                   .out_positions = {o_raw, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&raw), AK_OK);
    ref_blend(base, d, w, K, V, ref);
    AK_CHECK_NEAR(max_err(o_dense, ref, V), 0.0, 2e-6);
    AK_CHECK_NEAR(max_err(o_sparse, ref, V), 0.0, 2e-6);
    AK_CHECK_NEAR(max_err(o_auto, ref, V), 0.0, 2e-6);
    AK_CHECK_NEAR(max_diff(o_sparse, o_dense, V), 0.0, 4e-6);
    AK_CHECK_NEAR(max_diff(o_raw, o_dense, V), 0.0, 4e-6);
    ak_blendshape_set_destroy(dense);
    ak_blendshape_set_destroy(sparse);
    ak_blendshape_set_destroy(autos);
}

AK_TEST(threshold_drops_small_deltas_in_every_storage) {
    static ak_vec3 base[V], d[K * V], kept[K * V], o1[V], o2[V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(4);
    fill_random(base, V, &rng, -1, 1);
    fill_local(d, K, V, V / 20, &rng);
    /* Add noise of length < 1e-4 everywhere: it must be dropped with threshold 1e-3. */
    const float thr = 1e-3f;
    for (size_t i = 0; i < K * V; ++i) {
        ak_vec3 noise = rand3(&rng, -5e-5f, 5e-5f, -5e-5f, 5e-5f, 0.0f, 0.0f);
        if (ak_vec3_length(d[i]) < 2.0f * thr) d[i] = noise; /* small local deltas also become noise */
        else d[i] = ak_vec3_add(d[i], noise);
        kept[i] = ak_vec3_length(d[i]) > thr ? d[i] : ak_vec3_zero();
    }
    float w[K] = {1, 1, 1, 1, 1, 1, 1};
    ak_blendshape_set *s1 = NULL, *s2 = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = V, .target_count = K, .deltas = {d, K * V}, .threshold = thr,
                                   .storage = AK_BLENDSHAPE_STORAGE_DENSE};
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &s1), AK_OK);
    desc.storage = AK_BLENDSHAPE_STORAGE_SPARSE;
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &s2), AK_OK);
    if (!s1 || !s2) return;
    AK_CHECK(ak_blendshape_set_moved_count(s2, 0) <= V / 20);
    ak_blendshape_job job = {.set = s1, .weights = AK_SPAN(w), .base_positions = {base, V}, .out_positions = {o1, V}};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    job.set = s2, job.out_positions = (ak_vec3_span){o2, V};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    ref_blend(base, kept, w, K, V, ref);
    AK_CHECK_NEAR(max_err(o1, ref, V), 0.0, 2e-6);
    AK_CHECK_NEAR(max_err(o2, ref, V), 0.0, 2e-6);
    ak_blendshape_set_destroy(s1);
    ak_blendshape_set_destroy(s2);
}

AK_TEST(normals_blended_renormalised_unit) {
    static ak_vec3 base[V], n0[V], d[K * V], nd[K * V], op[V], on[V], on2[V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(5);
    fill_random(base, V, &rng, -1, 1);
    fill_unit(n0, V, &rng);
    fill_local(d, K, V, V / 8, &rng);
    fill_random(nd, K * V, &rng, -0.3f, 0.3f);
    /* Vertex 7: the blended normal cancels exactly (n0 + 1 * (-n0) in target 0, others zero). */
    for (size_t k = 0; k < K; ++k) nd[k * V + 7] = ak_vec3_zero();
    nd[7] = ak_vec3_neg(n0[7]);
    float w[K] = {1.0f, 0.5f, -0.3f, 0.8f, 0.0f, 0.2f, 0.6f};
    ref_blend(n0, nd, w, K, V, ref);
    ref_normalize(ref, V);

    ak_blendshape_dense_job job = {.weights = AK_SPAN(w), .base_positions = {base, V}, .deltas = {d, K * V},
                                   .base_normals = {n0, V}, .normal_deltas = {nd, K * V},
                                   .out_positions = {op, V}, .out_normals = {on, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&job), AK_OK);
    AK_CHECK_NEAR(max_err(on, ref, V), 0.0, 2e-6);
    int unit = 1;
    for (int i = 0; i < V; ++i) unit &= fabs(ak_vec3_length(on[i]) - 1.0) < 1e-6;
    AK_CHECK(unit);
    AK_CHECK_NEAR(on[7].y, 1.0, 0.0); /* documented fallback */

    /* The same through a sparse set (here every vertex has a normal delta, so all are kept). */
    ak_blendshape_set* set = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = V, .target_count = K, .deltas = {d, K * V},
                                   .normal_deltas = {nd, K * V}, .storage = AK_BLENDSHAPE_STORAGE_SPARSE};
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &set), AK_OK);
    if (!set) return;
    AK_CHECK(ak_blendshape_set_has_normals(set));
    ak_blendshape_job sj = {.set = set, .weights = AK_SPAN(w), .base_positions = {base, V},
                            .base_normals = {n0, V}, .out_positions = {op, V}, .out_normals = {on2, V}};
    AK_CHECK_EQ(ak_blendshape_run(&sj), AK_OK);
    AK_CHECK_NEAR(max_err(on2, ref, V), 0.0, 2e-6);
    ak_blendshape_set_destroy(set);

    /* No normal deltas: the base normals come back renormalised. */
    static ak_vec3 scaled[V];
    for (int i = 0; i < V; ++i) scaled[i] = ak_vec3_scale(n0[i], 3.0f);
    ak_blendshape_dense_job nj = {.weights = AK_SPAN(w), .base_positions = {base, V}, .deltas = {d, K * V},
                                  .base_normals = {scaled, V}, .out_positions = {op, V}, .out_normals = {on, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&nj), AK_OK);
    AK_CHECK_NEAR(max_diff(on, n0, V), 0.0, 3e-6);
}

AK_TEST(full_form_normals) {
    enum { S = 3, NV = 50 };
    static ak_vec3 shapes[S * NV], normals[S * NV], op[NV], on[NV];
    double ref[3 * NV];
    ak_rng rng = ak_rng_make(6);
    fill_random(shapes, S * NV, &rng, -1, 1);
    fill_unit(normals, S * NV, &rng);
    float w[S] = {0.2f, 0.5f, 0.3f};
    for (int i = 0; i < NV; ++i) {
        double x = 0, y = 0, z = 0;
        for (int k = 0; k < S; ++k) {
            x += w[k] * (double)normals[k * NV + i].x;
            y += w[k] * (double)normals[k * NV + i].y;
            z += w[k] * (double)normals[k * NV + i].z;
        }
        ref[3 * i] = x, ref[3 * i + 1] = y, ref[3 * i + 2] = z;
    }
    ref_normalize(ref, NV);
    ak_blendshape_full_job job = {.weights = AK_SPAN(w), .shapes = {shapes, S * NV}, .shape_normals = {normals, S * NV},
                                  .out_positions = {op, NV}, .out_normals = {on, NV}};
    AK_CHECK_EQ(ak_blendshape_full_run(&job), AK_OK);
    AK_CHECK_NEAR(max_err(on, ref, NV), 0.0, 2e-6);
}

AK_TEST(expression_transfer_onto_another_base) {
    static ak_vec3 base[V], other[V], d[K * V], o_src[V], o_dst[V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(7);
    fill_random(base, V, &rng, -1, 1);
    /* Another character with the same topology: scaled, shifted and noisy. */
    for (int i = 0; i < V; ++i)
        other[i] = ak_vec3_add(ak_vec3_scale(base[i], 1.3f),
                               ak_vec3_make(2.0f + ak_rng_range(&rng, -0.1f, 0.1f), -1.0f, 0.5f));
    fill_local(d, K, V, V / 10, &rng);
    float w[K] = {0.9f, 0.1f, 0.0f, 0.4f, 0.6f, -0.2f, 1.0f};
    ak_blendshape_set* set = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = V, .target_count = K, .deltas = {d, K * V}};
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, NULL, &set), AK_OK);
    if (!set) return;
    ak_blendshape_job job = {.set = set, .weights = AK_SPAN(w), .base_positions = {base, V}, .out_positions = {o_src, V}};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    job.base_positions = (ak_vec3_cspan){other, V};
    job.out_positions = (ak_vec3_span){o_dst, V};
    AK_CHECK_EQ(ak_blendshape_run(&job), AK_OK);
    ref_blend(other, d, w, K, V, ref);
    AK_CHECK_NEAR(max_err(o_dst, ref, V), 0.0, 4e-6);
    /* Same displacement on both characters. */
    double e = 0.0;
    for (int i = 0; i < V; ++i) {
        ak_vec3 a = ak_vec3_sub(o_src[i], base[i]), b = ak_vec3_sub(o_dst[i], other[i]);
        double x = ak_vec3_length(ak_vec3_sub(a, b));
        if (x > e) e = x;
    }
    AK_CHECK_NEAR(e, 0.0, 1e-5);
    ak_blendshape_set_destroy(set);
}

AK_TEST(in_place_blend) {
    static ak_vec3 base[V], keep[V], d[K * V];
    static double ref[3 * V];
    ak_rng rng = ak_rng_make(8);
    fill_random(base, V, &rng, -1, 1);
    memcpy(keep, base, sizeof(base));
    fill_random(d, K * V, &rng, -0.1f, 0.1f);
    float w[K] = {1, 2, 3, 4, 5, 6, 7};
    ref_blend(keep, d, w, K, V, ref);
    ak_blendshape_dense_job job = {.weights = AK_SPAN(w), .base_positions = {base, V}, .deltas = {d, K * V},
                                   .out_positions = {base, V}};
    AK_CHECK_EQ(ak_blendshape_dense_run(&job), AK_OK);
    AK_CHECK_NEAR(max_err(base, ref, V), 0.0, 1e-5);
}

AK_TEST(blend_straight_from_mesh) {
    enum { NV = 40, NK = 3 };
    static ak_vec3 pos[NV], nrm[NV], mp[NK * NV], mn[NK * NV], op[NV], on[NV], op2[NV];
    float mw[NK] = {0.5f, 0.0f, 1.0f};
    double ref[3 * NV], refn[3 * NV];
    ak_rng rng = ak_rng_make(9);
    fill_random(pos, NV, &rng, -1, 1);
    fill_unit(nrm, NV, &rng);
    fill_random(mp, NK * NV, &rng, -0.2f, 0.2f);
    fill_random(mn, NK * NV, &rng, -0.2f, 0.2f);
    /* A mesh filled by hand (no dependency on mesh.c): glTF-style target-major deltas. */
    ak_mesh mesh;
    memset(&mesh, 0, sizeof(mesh));
    mesh.vertex_count = NV;
    mesh.morph_target_count = NK;
    mesh.positions = pos;
    mesh.normals = nrm;
    mesh.morph_positions = mp;
    mesh.morph_normals = mn;
    mesh.morph_weights = mw;
    ref_blend(pos, mp, mw, NK, NV, ref);
    ref_blend(nrm, mn, mw, NK, NV, refn);
    ref_normalize(refn, NV);
    ak_blendshape_mesh_job job = {.mesh = &mesh, .out_positions = {op, NV}, .out_normals = {on, NV}};
    AK_CHECK_EQ(ak_blendshape_mesh_run(&job), AK_OK); /* default weights = mesh.morph_weights */
    AK_CHECK_NEAR(max_err(op, ref, NV), 0.0, 1e-6);
    AK_CHECK_NEAR(max_err(on, refn, NV), 0.0, 2e-6);

    float w2[NK] = {0.0f, 1.0f, 0.0f};
    job.weights = (ak_f32_cspan)AK_SPAN(w2);
    AK_CHECK_EQ(ak_blendshape_mesh_run(&job), AK_OK);
    ref_blend(pos, mp, w2, NK, NV, ref);
    AK_CHECK_NEAR(max_err(op, ref, NV), 0.0, 1e-6);

    /* The same through a set built from the mesh. */
    ak_blendshape_set_desc d = ak_blendshape_set_desc_from_mesh(&mesh);
    AK_CHECK_EQ(d.vertex_count, NV);
    AK_CHECK_EQ(d.target_count, NK);
    ak_blendshape_set* set = NULL;
    AK_CHECK_EQ(ak_blendshape_set_create(&d, NULL, &set), AK_OK);
    ak_blendshape_job sj = {.set = set, .weights = AK_SPAN(w2), .base_positions = {pos, NV}, .out_positions = {op2, NV}};
    AK_CHECK_EQ(ak_blendshape_run(&sj), AK_OK);
    AK_CHECK_NEAR(max_err(op2, ref, NV), 0.0, 1e-6);
    ak_blendshape_set_destroy(set);
}


AK_TEST(set_is_one_allocation_through_the_allocator) {
    static ak_vec3 d[K * V];
    ak_rng rng = ak_rng_make(10);
    fill_local(d, K, V, V / 10, &rng);
    ak_test_counter c = {0};
    ak_allocator a = ak_test_counting_allocator(&c);
    ak_blendshape_set* set = NULL;
    ak_blendshape_set_desc desc = {.vertex_count = V, .target_count = K, .deltas = {d, K * V}};
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, &a, &set), AK_OK);
    AK_CHECK_EQ(c.total, 1);
    ak_blendshape_set_destroy(set);
    AK_CHECK_EQ(c.live, 0);
    ak_blendshape_set_destroy(NULL);
    ak_test_counter failing = {.fail_from = 1};
    ak_allocator bad = ak_test_counting_allocator(&failing);
    set = (ak_blendshape_set*)&c;
    AK_CHECK_EQ(ak_blendshape_set_create(&desc, &bad, &set), AK_ERR_NO_MEMORY);
    AK_CHECK(set == NULL);
}

AK_TEST(bad_input_codes) {
    enum { NV = 8, NK = 2 };
    ak_vec3 base[NV], n0[NV], d[NK * NV], out[NV], outn[NV];
    ak_rng rng = ak_rng_make(11);
    fill_random(base, NV, &rng, -1, 1);
    fill_unit(n0, NV, &rng);
    fill_random(d, NK * NV, &rng, -1, 1);
    float w[NK] = {0.5f, 0.5f};
    float wnan[NK] = {0.5f, NAN};
    float winf[NK] = {INFINITY, 0.5f};

    /* Zero-initialised jobs. */
    ak_blendshape_dense_job zd = {0};
    ak_blendshape_full_job zf = {0};
    ak_blendshape_mesh_job zm = {0};
    ak_blendshape_job zs = {0};
    AK_CHECK_EQ(ak_blendshape_dense_run(&zd), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blendshape_full_run(&zf), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blendshape_mesh_run(&zm), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blendshape_run(&zs), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blendshape_run(NULL), AK_ERR_NULL_ARG);

    /* Dense job: one case per rule; the output must stay untouched. */
    for (int i = 0; i < NV; ++i) out[i] = ak_vec3_splat(42.0f);
    ak_blendshape_dense_job ok = {.weights = AK_SPAN(w), .base_positions = {base, NV}, .deltas = {d, NK * NV},
                                  .base_normals = {n0, NV}, .out_positions = {out, NV}, .out_normals = {outn, NV}};
    ak_blendshape_dense_job j = ok;
    j.weights = (ak_f32_cspan){wnan, NK};
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_BAD_DATA);
    j.weights = (ak_f32_cspan){winf, NK};
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_BAD_DATA);
    AK_CHECK_NEAR(out[3].y, 42.0, 0.0);
    j = ok, j.weights.count = 1; /* deltas hold 2 targets */
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.deltas.count = NK * NV - 1;
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.deltas.ptr = NULL;
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_NULL_ARG);
    j = ok, j.out_positions.count = NV - 1;
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_SPAN_SMALL);
    j = ok, j.out_normals.count = NV - 1;
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_SPAN_SMALL);
    j = ok, j.base_normals = (ak_vec3_cspan){NULL, 0};
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_NULL_ARG);
    j = ok, j.base_normals.count = NV - 1;
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_BAD_ARG);
    j = ok, j.normal_deltas = (ak_vec3_cspan){d, NV};
    AK_CHECK_EQ(ak_blendshape_dense_run(&j), AK_ERR_BAD_ARG);
    AK_CHECK_NEAR(out[0].x, 42.0, 0.0);
    AK_CHECK_EQ(ak_blendshape_dense_run(&ok), AK_OK);

    /* Full job. */
    ak_blendshape_full_job f = {.weights = {w, NK}, .shapes = {d, NK * NV - 1}, .out_positions = {out, NV}};
    AK_CHECK_EQ(ak_blendshape_full_run(&f), AK_ERR_BAD_ARG);
    f.shapes.count = NK * NV;
    f.out_positions.count = NV - 1;
    AK_CHECK_EQ(ak_blendshape_full_run(&f), AK_ERR_SPAN_SMALL);
    f.out_positions.count = NV;
    f.weights.ptr = wnan;
    AK_CHECK_EQ(ak_blendshape_full_run(&f), AK_ERR_BAD_DATA);
    f.weights.ptr = w;
    f.out_normals = (ak_vec3_span){outn, NV};
    AK_CHECK_EQ(ak_blendshape_full_run(&f), AK_ERR_NULL_ARG);

    /* Sets. */
    ak_blendshape_set* set = NULL;
    ak_blendshape_set_desc sd = {.vertex_count = NV, .target_count = NK, .deltas = {d, NK * NV}};
    ak_blendshape_set_desc b = sd;
    AK_CHECK_EQ(ak_blendshape_set_create(NULL, NULL, &set), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_blendshape_set_create(&sd, NULL, NULL), AK_ERR_NULL_ARG);
    b.vertex_count = 0;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_EMPTY);
    b = sd, b.target_count = 0;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_EMPTY);
    b = sd, b.deltas.count = NK * NV + 1;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_ARG);
    b = sd, b.normal_deltas = (ak_vec3_cspan){d, NV};
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_ARG);
    b = sd, b.threshold = -1.0f;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_ARG);
    b = sd, b.threshold = NAN;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_ARG);
    b = sd, b.storage = AK_BLENDSHAPE_STORAGE_COUNT;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_ARG);
    b = sd, b.vertex_count = SIZE_MAX / 2, b.target_count = 4;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_ARG);
    ak_vec3 dn[NK * NV];
    memcpy(dn, d, sizeof(d));
    dn[5].y = NAN;
    b = sd, b.deltas = (ak_vec3_cspan){dn, NK * NV};
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_DATA);
    dn[5].y = -INFINITY;
    AK_CHECK_EQ(ak_blendshape_set_create(&b, NULL, &set), AK_ERR_BAD_DATA);
    AK_CHECK(set == NULL);
    AK_CHECK(!ak_blendshape_deltas_are_finite((ak_vec3_cspan){dn, NK * NV}));
    AK_CHECK(ak_blendshape_deltas_are_finite((ak_vec3_cspan){d, NK * NV}));

    AK_CHECK_EQ(ak_blendshape_set_create(&sd, NULL, &set), AK_OK);
    ak_blendshape_job sj = {.set = set, .weights = AK_SPAN(w), .base_positions = {base, NV}, .out_positions = {out, NV}};
    ak_blendshape_job s2 = sj;
    s2.weights.count = 1;
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_BAD_ARG);
    s2 = sj, s2.base_positions.count = NV - 1;
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_BAD_ARG);
    s2 = sj, s2.out_positions.count = NV - 1;
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_SPAN_SMALL);
    s2 = sj, s2.weights.ptr = wnan;
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_BAD_DATA);
    s2 = sj, s2.out_normals = (ak_vec3_span){outn, NV};
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_NULL_ARG);
    s2.base_normals = (ak_vec3_cspan){n0, NV - 1};
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_BAD_ARG);
    s2.base_normals.count = NV, s2.out_normals.count = 1;
    AK_CHECK_EQ(ak_blendshape_run(&s2), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_blendshape_run(&sj), AK_OK);
    AK_CHECK_EQ(ak_blendshape_set_moved_count(set, 99), 0);
    AK_CHECK(!ak_blendshape_set_target_is_sparse(set, 99));
    AK_CHECK_EQ(ak_blendshape_set_vertex_count(NULL), 0);
    ak_blendshape_set_destroy(set);

    /* Mesh job. */
    ak_mesh mesh;
    memset(&mesh, 0, sizeof(mesh));
    mesh.vertex_count = NV;
    mesh.morph_target_count = NK;
    mesh.positions = base;
    mesh.morph_positions = d;
    ak_blendshape_mesh_job mj = {.mesh = &mesh, .out_positions = {out, NV}};
    AK_CHECK_EQ(ak_blendshape_mesh_run(&mj), AK_ERR_NULL_ARG); /* no weights, no defaults */
    mj.weights = (ak_f32_cspan){w, 1};
    AK_CHECK_EQ(ak_blendshape_mesh_run(&mj), AK_ERR_BAD_ARG);
    mj.weights = (ak_f32_cspan){w, NK};
    mj.out_normals = (ak_vec3_span){outn, NV};
    AK_CHECK_EQ(ak_blendshape_mesh_run(&mj), AK_ERR_NULL_ARG); /* mesh has no normals */
    mj.out_normals = (ak_vec3_span){NULL, 0};
    mj.out_positions.count = 2;
    AK_CHECK_EQ(ak_blendshape_mesh_run(&mj), AK_ERR_SPAN_SMALL);
    mj.out_positions.count = NV;
    mj.weights.ptr = winf;
    AK_CHECK_EQ(ak_blendshape_mesh_run(&mj), AK_ERR_BAD_DATA);
    mj.weights.ptr = w;
    AK_CHECK_EQ(ak_blendshape_mesh_run(&mj), AK_OK);

    /* Helpers. */
    ak_vec3 tmp[NK * NV];
    AK_CHECK_EQ(ak_blendshape_deltas_from_shapes((ak_vec3_cspan){base, 3}, (ak_vec3_cspan){d, 7},
                                                 (ak_vec3_span){tmp, 7}),
                AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_blendshape_deltas_from_shapes((ak_vec3_cspan){base, NV}, (ak_vec3_cspan){d, NK * NV},
                                                 (ak_vec3_span){tmp, 3}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_blendshape_deltas_from_shapes((ak_vec3_cspan){NULL, 0}, (ak_vec3_cspan){d, NK * NV},
                                                 (ak_vec3_span){tmp, NK * NV}),
                AK_ERR_NULL_ARG);
}

int main(void) {
    AK_RUN(dense_matches_double_reference);
    AK_RUN(full_and_differential_agree_when_weights_sum_to_one);
    AK_RUN(sparse_equals_dense);
    AK_RUN(threshold_drops_small_deltas_in_every_storage);
    AK_RUN(normals_blended_renormalised_unit);
    AK_RUN(full_form_normals);
    AK_RUN(expression_transfer_onto_another_base);
    AK_RUN(in_place_blend);
    AK_RUN(blend_straight_from_mesh);
    AK_RUN(set_is_one_allocation_through_the_allocator);
    AK_RUN(bad_input_codes);
    printf("note: the glTF morph-target check (AnimatedMorphCube, MorphStressTest) needs io and lives in a\n"
           "      cross-module test; this module test uses synthetic data only\n");
    return ak_test_finish();
}
