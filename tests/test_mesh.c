/* Tests for mesh.h: creation (one allocation), clone, validation, bounds, normals, volume,
 * closed/oriented check, weight validation and normalisation. Oracles are closed forms
 * (unit cube, sphere bounds) and naive re-computations written here. */
#include <animkit/mesh.h>

#include "ak_test.h"

#define PI_D 3.14159265358979323846


/* Cube [0,1]^3 + offset, vertex index = x + 2y + 4z, faces counter-clockwise from outside. */
static ak_mesh* make_cube(ak_vec3 offset, bool normals) {
    static const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                         {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    ak_mesh_desc d = {
        .vertex_count = 8, .triangle_count = 12, .has_normals = normals, .name = "cube"};
    ak_mesh* m = NULL;
    if (ak_mesh_create(&d, NULL, &m) != AK_OK) return NULL;
    for (uint32_t i = 0; i < 8; ++i)
        m->positions[i] = ak_vec3_add(
            offset, ak_vec3_make((float)(i & 1), (float)((i >> 1) & 1), (float)((i >> 2) & 1)));
    for (int f = 0; f < 6; ++f) {
        uint32_t* t = m->indices + 6 * f;
        t[0] = quads[f][0], t[1] = quads[f][1], t[2] = quads[f][2];
        t[3] = quads[f][0], t[4] = quads[f][2], t[5] = quads[f][3];
    }
    return m;
}

/* UV sphere of radius r with poles: rings latitude bands, segs longitudes; CCW outside. */
static ak_mesh* make_sphere(float r, uint32_t rings, uint32_t segs) {
    size_t vc = 2 + (size_t)(rings - 1) * segs, tc = 2 * (size_t)segs * (rings - 1);
    ak_mesh_desc d = {.vertex_count = vc, .triangle_count = tc};
    ak_mesh* m = NULL;
    if (ak_mesh_create(&d, NULL, &m) != AK_OK) return NULL;
    m->positions[0] = ak_vec3_make(0, r, 0);
    m->positions[vc - 1] = ak_vec3_make(0, -r, 0);
    for (uint32_t i = 1; i < rings; ++i)
        for (uint32_t j = 0; j < segs; ++j) {
            double th = PI_D * i / rings, ph = 2.0 * PI_D * j / segs;
            m->positions[1 + (i - 1) * segs + j] =
                ak_vec3_make((float)(r * sin(th) * cos(ph)), (float)(r * cos(th)),
                             (float)(-r * sin(th) * sin(ph)));
        }
    uint32_t* t = m->indices;
    for (uint32_t j = 0; j < segs; ++j) {
        uint32_t a = 1 + j, b = 1 + (j + 1) % segs;
        *t++ = 0, *t++ = a, *t++ = b;
        uint32_t base = 1 + (rings - 2) * segs;
        *t++ = (uint32_t)vc - 1, *t++ = base + (j + 1) % segs, *t++ = base + j;
    }
    for (uint32_t i = 1; i + 1 < rings; ++i)
        for (uint32_t j = 0; j < segs; ++j) {
            uint32_t a = 1 + (i - 1) * segs + j, b = 1 + (i - 1) * segs + (j + 1) % segs;
            uint32_t c = a + segs, e = b + segs;
            *t++ = a, *t++ = c, *t++ = e;
            *t++ = a, *t++ = e, *t++ = b;
        }
    return m;
}

AK_TEST(create_one_allocation_and_zeroed) {
    ak_test_counter c = {0};
    ak_allocator a = ak_test_counting_allocator(&c);
    ak_mesh_desc d = {.vertex_count = 5,
                      .triangle_count = 2,
                      .influence_count = 4,
                      .morph_target_count = 2,
                      .has_normals = true,
                      .has_uvs = true,
                      .has_colors = true,
                      .has_morph_normals = true,
                      .name = "box"};
    ak_mesh* m = NULL;
    AK_CHECK_EQ(ak_mesh_create(&d, &a, &m), AK_OK);
    AK_CHECK(m != NULL);
    if (!m) return;
    AK_CHECK_EQ(c.live, 1);
    AK_CHECK_EQ(c.total, 1);
    AK_CHECK_STREQ(m->name, "box");
    AK_CHECK(m->positions && m->normals && m->uvs && m->colors && m->indices && m->joints &&
             m->weights);
    AK_CHECK(m->morph_positions && m->morph_normals && m->morph_weights && m->morph_names);
    /* Every array zeroed, and writing all of them stays inside the block (ASan checks). */
    for (size_t i = 0; i < 20; ++i) AK_CHECK(m->weights[i] == 0.0f && m->joints[i] == 0);
    for (size_t i = 0; i < 6; ++i) AK_CHECK_EQ(m->indices[i], 0);
    memset(m->positions, 1, 5 * sizeof(ak_vec3));
    memset(m->morph_normals, 1, 10 * sizeof(ak_vec3));
    memset(m->morph_names, 'a', 2 * AK_NAME_SIZE);
    ak_mesh_destroy(m);
    AK_CHECK_EQ(c.live, 0);

    ak_mesh_desc plain = {.vertex_count = 3};
    AK_CHECK_EQ(ak_mesh_create(&plain, NULL, &m), AK_OK);
    AK_CHECK(m->normals == NULL && m->uvs == NULL && m->colors == NULL && m->indices == NULL);
    AK_CHECK(m->joints == NULL && m->weights == NULL && m->morph_positions == NULL &&
             m->morph_names == NULL);
    AK_CHECK_STREQ(m->name, "");
    ak_mesh_destroy(m);
    ak_mesh_destroy(NULL);
}

AK_TEST(create_bad_input) {
    ak_mesh* m = (ak_mesh*)1;
    ak_mesh_desc d = {.vertex_count = 3};
    AK_CHECK_EQ(ak_mesh_create(NULL, NULL, &m), AK_ERR_NULL_ARG);
    AK_CHECK(m == NULL);
    AK_CHECK_EQ(ak_mesh_create(&d, NULL, NULL), AK_ERR_NULL_ARG);
    ak_mesh_desc zero = {0};
    AK_CHECK_EQ(ak_mesh_create(&zero, NULL, &m), AK_ERR_EMPTY);
    ak_mesh_desc many = {.vertex_count = 3, .influence_count = AK_MAX_INFLUENCES + 1};
    AK_CHECK_EQ(ak_mesh_create(&many, NULL, &m), AK_ERR_BAD_ARG);
    ak_mesh_desc huge = {.vertex_count = SIZE_MAX / 4, .triangle_count = 1};
    AK_CHECK_EQ(ak_mesh_create(&huge, NULL, &m), AK_ERR_BAD_ARG);
    ak_mesh_desc huge_tris = {.vertex_count = 3, .triangle_count = SIZE_MAX / 2};
    AK_CHECK_EQ(ak_mesh_create(&huge_tris, NULL, &m), AK_ERR_BAD_ARG);
    AK_CHECK(m == NULL);
    char longname[200];
    memset(longname, 'x', sizeof longname - 1);
    longname[sizeof longname - 1] = 0;
    ak_mesh_desc named = {.vertex_count = 1, .name = longname};
    AK_CHECK_EQ(ak_mesh_create(&named, NULL, &m), AK_OK);
    AK_CHECK_EQ(strlen(m->name), AK_NAME_SIZE - 1);
    ak_mesh_destroy(m);
}

AK_TEST(clone_is_deep) {
    ak_mesh_desc d = {.vertex_count = 4,
                      .triangle_count = 1,
                      .influence_count = 2,
                      .morph_target_count = 1,
                      .has_uvs = true,
                      .name = "src"};
    ak_mesh* m = NULL;
    AK_CHECK_EQ(ak_mesh_create(&d, NULL, &m), AK_OK);
    for (int i = 0; i < 4; ++i) {
        m->positions[i] = ak_vec3_make((float)i, 2.0f * i, -1.0f);
        m->uvs[i] = ak_vec2_make(0.25f * i, 1.0f);
        m->joints[2 * i] = (uint16_t)i, m->weights[2 * i] = 1.0f;
        m->morph_positions[i] = ak_vec3_make(0, (float)i, 0);
    }
    m->indices[0] = 0, m->indices[1] = 1, m->indices[2] = 3;
    m->morph_weights[0] = 0.5f;
    snprintf(m->morph_names[0], AK_NAME_SIZE, "smile");
    ak_mesh* c = NULL;
    AK_CHECK_EQ(ak_mesh_clone(m, NULL, &c), AK_OK);
    AK_CHECK(c && c != m && c->positions != m->positions);
    AK_CHECK(c->normals == NULL && c->uvs != NULL);
    AK_CHECK_STREQ(c->name, "src");
    AK_CHECK_STREQ(c->morph_names[0], "smile");
    AK_CHECK(memcmp(c->positions, m->positions, 4 * sizeof(ak_vec3)) == 0);
    AK_CHECK(memcmp(c->uvs, m->uvs, 4 * sizeof(ak_vec2)) == 0);
    AK_CHECK(memcmp(c->joints, m->joints, 8 * sizeof(uint16_t)) == 0);
    AK_CHECK(memcmp(c->weights, m->weights, 8 * sizeof(float)) == 0);
    AK_CHECK(memcmp(c->morph_positions, m->morph_positions, 4 * sizeof(ak_vec3)) == 0);
    AK_CHECK_EQ(c->indices[2], 3);
    AK_CHECK(c->morph_weights[0] == 0.5f);
    m->positions[0].x = 99.0f;
    AK_CHECK(c->positions[0].x == 0.0f);
    ak_mesh_destroy(m);
    ak_mesh_destroy(c);
    AK_CHECK_EQ(ak_mesh_clone(NULL, NULL, &c), AK_ERR_NULL_ARG);
}

AK_TEST(validate_codes) {
    ak_mesh* m = make_cube(ak_vec3_zero(), true);
    ak_diag diag;
    AK_CHECK_EQ(ak_mesh_validate(m, &diag), AK_OK);
    m->indices[7] = 8;
    AK_CHECK_EQ(ak_mesh_validate(m, &diag), AK_ERR_BAD_INDEX);
    AK_CHECK(strstr(diag.message, "triangle 2") != NULL);
    m->indices[7] = 1;
    m->positions[5].y = NAN;
    AK_CHECK_EQ(ak_mesh_validate(m, &diag), AK_ERR_BAD_DATA);
    AK_CHECK(strstr(diag.message, "vertex 5") != NULL);
    m->positions[5].y = 0.0f;
    m->normals[3].z = INFINITY;
    AK_CHECK_EQ(ak_mesh_validate(m, NULL), AK_ERR_BAD_DATA);
    AK_CHECK_EQ(ak_mesh_validate(NULL, NULL), AK_ERR_NULL_ARG);
    ak_mesh_destroy(m);
}

AK_TEST(bounds) {
    ak_mesh* m = make_cube(ak_vec3_make(-2.0f, 3.0f, 0.5f), false);
    ak_vec3 lo, hi;
    ak_mesh_bounds(m, &lo, &hi);
    AK_CHECK(lo.x == -2.0f && lo.y == 3.0f && lo.z == 0.5f);
    AK_CHECK(hi.x == -1.0f && hi.y == 4.0f && hi.z == 1.5f);
    ak_mesh_destroy(m);
    ak_vec3_cspan none = {NULL, 0};
    ak_points_bounds(none, &lo, &hi);
    AK_CHECK(lo.x == 0 && lo.y == 0 && lo.z == 0 && hi.x == 0 && hi.y == 0 && hi.z == 0);
    ak_mesh_bounds(NULL, &lo, &hi);
    AK_CHECK(hi.x == 0.0f);
}

AK_TEST(normals) {
    ak_mesh_desc d = {.vertex_count = 4, .triangle_count = 1, .has_normals = true};
    ak_mesh* m = NULL;
    AK_CHECK_EQ(ak_mesh_create(&d, NULL, &m), AK_OK);
    m->positions[1] = ak_vec3_make(1, 0, 0);
    m->positions[2] = ak_vec3_make(0, 1, 0);
    m->positions[3] = ak_vec3_make(5, 5, 5); /* on no triangle */
    m->indices[0] = 0, m->indices[1] = 1, m->indices[2] = 2;
    AK_CHECK_EQ(ak_mesh_compute_normals(m), AK_OK);
    for (int i = 0; i < 3; ++i)
        AK_CHECK(m->normals[i].x == 0.0f && m->normals[i].y == 0.0f && m->normals[i].z == 1.0f);
    AK_CHECK(m->normals[3].x == 0.0f && m->normals[3].y == 1.0f && m->normals[3].z == 0.0f);
    ak_mesh_destroy(m);

    /* Cube corners: the normal points away from the centre, into the corner's octant. */
    m = make_cube(ak_vec3_zero(), true);
    AK_CHECK_EQ(ak_mesh_compute_normals(m), AK_OK);
    /* Each corner lies on one or two triangles of each face (depending on the diagonal), so
     * the area-weighted sum points into the corner's octant without being exactly diagonal. */
    for (uint32_t i = 0; i < 8; ++i) {
        ak_vec3 n = m->normals[i];
        AK_CHECK_NEAR(ak_vec3_length(n), 1.0, 1e-5);
        AK_CHECK((n.x > 0) == ((i & 1) != 0) && (n.y > 0) == ((i & 2) != 0) &&
                 (n.z > 0) == ((i & 4) != 0));
    }
    ak_vec3 out[8];
    ak_vec3_cspan p = {m->positions, 8};
    ak_u32_cspan idx = {m->indices, 36};
    ak_vec3_span small = {out, 7};
    AK_CHECK_EQ(ak_normals_compute(p, idx, small), AK_ERR_SPAN_SMALL);
    m->indices[4] = 8;
    AK_CHECK_EQ(ak_normals_compute(p, idx, (ak_vec3_span)AK_SPAN(out)), AK_ERR_BAD_INDEX);
    ak_vec3_span nul = {NULL, 8};
    AK_CHECK_EQ(ak_normals_compute(p, idx, nul), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_mesh_compute_normals(NULL), AK_ERR_NULL_ARG);
    ak_mesh_destroy(m);
}

AK_TEST(volume_cube_and_sphere) {
    ak_mesh* m = make_cube(ak_vec3_make(10.0f, -3.0f, 7.0f), false);
    ak_vec3_cspan p = {m->positions, 8};
    ak_u32_cspan idx = {m->indices, 36};
    AK_CHECK_NEAR(ak_volume_compute(p, idx), 1.0, 1e-9);
    /* Reversed winding gives the negative volume. */
    for (size_t t = 0; t < 12; ++t) {
        uint32_t tmp = m->indices[3 * t + 1];
        m->indices[3 * t + 1] = m->indices[3 * t + 2];
        m->indices[3 * t + 2] = tmp;
    }
    AK_CHECK_NEAR(ak_volume_compute(p, idx), -1.0, 1e-9);
    ak_mesh_destroy(m);

    /* An inscribed polyhedron has less volume than the sphere, and converges to it. */
    const double r = 1.5, exact = 4.0 / 3.0 * PI_D * r * r * r;
    ak_mesh* coarse = make_sphere((float)r, 8, 16);
    ak_mesh* fine = make_sphere((float)r, 64, 128);
    double vc = ak_volume_compute((ak_vec3_cspan){coarse->positions, coarse->vertex_count},
                                  (ak_u32_cspan){coarse->indices, 3 * coarse->triangle_count});
    double vf = ak_volume_compute((ak_vec3_cspan){fine->positions, fine->vertex_count},
                                  (ak_u32_cspan){fine->indices, 3 * fine->triangle_count});
    AK_CHECK(vc > 0.8 * exact && vc < exact);
    AK_CHECK(vf > vc && vf < exact);
    AK_CHECK(fabs(vf - exact) / exact < 2e-3);
    AK_CHECK(ak_mesh_is_closed_oriented(coarse));
    AK_CHECK(ak_mesh_is_closed_oriented(fine));
    ak_mesh_destroy(coarse);
    ak_mesh_destroy(fine);
}

AK_TEST(closed_oriented) {
    ak_mesh* m = make_cube(ak_vec3_zero(), false);
    AK_CHECK(ak_mesh_is_closed_oriented(m));
    /* One triangle flipped: two edges now run the same way as their neighbours'. */
    uint32_t tmp = m->indices[1];
    m->indices[1] = m->indices[2];
    m->indices[2] = tmp;
    AK_CHECK(!ak_mesh_is_closed_oriented(m));
    m->indices[2] = m->indices[1];
    m->indices[1] = tmp;
    AK_CHECK(ak_mesh_is_closed_oriented(m));
    /* A hole: the last triangle dropped. */
    m->triangle_count = 11;
    AK_CHECK(!ak_mesh_is_closed_oriented(m));
    m->triangle_count = 12;
    /* Degenerate triangle and out-of-range index. */
    m->indices[0] = m->indices[1];
    AK_CHECK(!ak_mesh_is_closed_oriented(m));
    m->indices[0] = 9;
    AK_CHECK(!ak_mesh_is_closed_oriented(m));
    AK_CHECK(!ak_mesh_is_closed_oriented(NULL));
    ak_mesh_destroy(m);

    /* Two copies of a tetrahedron sharing vertices: edges used four times -> not manifold. */
    ak_mesh_desc d = {.vertex_count = 4, .triangle_count = 8};
    AK_CHECK_EQ(ak_mesh_create(&d, NULL, &m), AK_OK);
    static const uint32_t tet[12] = {0, 2, 1, 0, 1, 3, 1, 2, 3, 0, 3, 2};
    memcpy(m->indices, tet, sizeof tet);
    memcpy(m->indices + 12, tet, sizeof tet);
    m->positions[1] = ak_vec3_make(1, 0, 0);
    m->positions[2] = ak_vec3_make(0, 1, 0);
    m->positions[3] = ak_vec3_make(0, 0, 1);
    AK_CHECK(!ak_mesh_is_closed_oriented(m));
    m->triangle_count = 4;
    AK_CHECK(ak_mesh_is_closed_oriented(m));
    AK_CHECK_NEAR(
        ak_volume_compute((ak_vec3_cspan){m->positions, 4}, (ak_u32_cspan){m->indices, 12}),
        1.0 / 6.0, 1e-9);
    ak_mesh_destroy(m);
}

AK_TEST(validate_weights_codes) {
    ak_mesh_desc d = {.vertex_count = 3, .influence_count = 2, .name = "w"};
    ak_mesh* m = NULL;
    AK_CHECK_EQ(ak_mesh_create(&d, NULL, &m), AK_OK);
    for (int v = 0; v < 3; ++v) {
        m->joints[2 * v] = (uint16_t)v, m->weights[2 * v] = 0.75f;
        m->joints[2 * v + 1] = 3, m->weights[2 * v + 1] = 0.25f;
    }
    ak_diag diag;
    AK_CHECK_EQ(ak_mesh_validate_weights(m, 4, 0.0f, &diag), AK_OK);
    AK_CHECK_EQ(ak_mesh_validate_weights(m, 3, 0.0f, &diag), AK_ERR_BAD_INDEX);
    AK_CHECK(strstr(diag.message, "vertex 0") != NULL);
    m->weights[3] = 0.2f; /* vertex 1 sums to 0.95 */
    AK_CHECK_EQ(ak_mesh_validate_weights(m, 4, 0.0f, &diag), AK_ERR_BAD_WEIGHTS);
    AK_CHECK(strstr(diag.message, "vertex 1") != NULL);
    AK_CHECK_EQ(ak_mesh_validate_weights(m, 4, 0.1f, &diag), AK_OK);
    m->weights[3] = 0.25f;
    m->weights[4] = -0.25f, m->weights[5] = 1.25f;
    AK_CHECK_EQ(ak_mesh_validate_weights(m, 4, 0.0f, &diag), AK_ERR_BAD_WEIGHTS);
    AK_CHECK(strstr(diag.message, "vertex 2") != NULL);
    m->weights[4] = NAN;
    AK_CHECK_EQ(ak_mesh_validate_weights(m, 4, 0.0f, NULL), AK_ERR_BAD_WEIGHTS);
    AK_CHECK_EQ(ak_mesh_validate_weights(NULL, 4, 0.0f, NULL), AK_ERR_NULL_ARG);
    ak_mesh_destroy(m);
    ak_mesh* cube = make_cube(ak_vec3_zero(), false);
    AK_CHECK_EQ(ak_mesh_validate_weights(cube, 0, 0.0f, NULL), AK_OK);
    ak_mesh_destroy(cube);
}

AK_TEST(weights_normalize_keeps_largest) {
    enum { V = 500, K = 8 };
    static uint16_t joints[V * K];
    static float weights[V * K], orig[V * K];
    static uint16_t orig_j[V * K];
    ak_rng rng = ak_rng_make(7);
    for (int i = 0; i < V * K; ++i) {
        joints[i] = (uint16_t)(i % K * 3 + (i / K) % 2); /* distinct within a vertex */
        weights[i] = ak_rng_float(&rng) + 1e-3f;
    }
    memcpy(orig, weights, sizeof orig);
    memcpy(orig_j, joints, sizeof orig_j);
    ak_weights_normalize(joints, weights, V, K, 4, 0.0f);
    for (int v = 0; v < V; ++v) {
        /* Naive reference: the 4 largest original weights, divided by their sum (double). */
        int used[K] = {0};
        int pick[4];
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) {
            int best = -1;
            for (int i = 0; i < K; ++i)
                if (!used[i] && (best < 0 || orig[v * K + i] > orig[v * K + best])) best = i;
            used[best] = 1;
            pick[k] = best;
            sum += orig[v * K + best];
        }
        double got_sum = 0.0;
        for (int k = 0; k < K; ++k) got_sum += weights[v * K + k];
        AK_CHECK_NEAR(got_sum, 1.0, 1e-6);
        for (int k = 0; k < 4; ++k) {
            AK_CHECK_EQ(joints[v * K + k], orig_j[v * K + pick[k]]);
            AK_CHECK_NEAR(weights[v * K + k], orig[v * K + pick[k]] / sum, 2e-6);
        }
        for (int k = 4; k < K; ++k) AK_CHECK(weights[v * K + k] == 0.0f && joints[v * K + k] == 0);
    }
}

AK_TEST(weights_normalize_edge_cases) {
    /* NaN and negatives become 0, duplicates merge, min_weight drops small ones. */
    uint16_t j[4] = {5, 2, 5, 7};
    float w[4] = {0.2f, NAN, 0.3f, -1.0f};
    ak_weights_normalize(j, w, 1, 4, 0, 0.0f);
    AK_CHECK_EQ(j[0], 5);
    AK_CHECK_NEAR(w[0], 1.0, 1e-6);
    AK_CHECK(w[1] == 0.0f && w[2] == 0.0f && w[3] == 0.0f);

    uint16_t j2[4] = {1, 2, 3, 4};
    float w2[4] = {0.5f, 0.3f, 0.15f, 0.05f};
    ak_weights_normalize(j2, w2, 1, 4, 4, 0.1f);
    AK_CHECK_EQ(j2[0], 1);
    AK_CHECK_EQ(j2[2], 3);
    AK_CHECK_NEAR(w2[0], 0.5 / 0.95, 1e-6);
    AK_CHECK_NEAR(w2[2], 0.15 / 0.95, 1e-6);
    AK_CHECK(w2[3] == 0.0f);

    /* All zero: weight 1 on the first joint (documented fallback). */
    uint16_t j3[3] = {9, 4, 2};
    float w3[3] = {0.0f, -0.0f, NAN};
    ak_weights_normalize(j3, w3, 1, 3, 0, 0.0f);
    AK_CHECK_EQ(j3[0], 9);
    AK_CHECK(w3[0] == 1.0f && w3[1] == 0.0f && w3[2] == 0.0f);

    /* Everything under min_weight: the largest still stays. */
    uint16_t j4[2] = {3, 6};
    float w4[2] = {0.01f, 0.02f};
    ak_weights_normalize(j4, w4, 1, 2, 2, 0.5f);
    AK_CHECK_EQ(j4[0], 6);
    AK_CHECK(w4[0] == 1.0f && w4[1] == 0.0f);
    ak_weights_normalize(NULL, w4, 1, 2, 2, 0.0f); /* no-op, no crash */

    /* A wide stride (three glTF JOINTS_n sets, 12 slots) limited to 4: the 4 largest. */
    uint16_t j5[24];
    float w5[24];
    for (int i = 0; i < 24; ++i) j5[i] = (uint16_t)(100 + i), w5[i] = (float)(i % 12 + 1);
    ak_weights_normalize(j5, w5, 2, 12, 4, 0.0f);
    for (int v = 0; v < 2; ++v) {
        AK_CHECK_EQ(j5[12 * v], 100 + 12 * v + 11);
        AK_CHECK_EQ(j5[12 * v + 3], 100 + 12 * v + 8);
        AK_CHECK_NEAR(w5[12 * v], 12.0 / 42.0, 1e-6);
        AK_CHECK(w5[12 * v + 4] == 0.0f && w5[12 * v + 11] == 0.0f);
    }
}

/* Welded normals: a roof of two triangles stored unwelded (6 vertices, as an OBJ without
 * normals gives) shares one normal along the ridge (the normalised area-weighted sum of both
 * faces, computed here); the eaves keep their face's normal. -0 welds with +0. */
AK_TEST(normals_welded) {
    /* two triangles sharing the edge A-B at an angle */
    ak_vec3 A = ak_vec3_make(0, 0, 0), B = ak_vec3_make(1, 0, 0), C = ak_vec3_make(0.5f, 1, 0), D = ak_vec3_make(0.5f, -1, 2);
    ak_vec3 pos[6] = {A, B, C, B, A, D};
    pos[4].x = -0.0f; /* the second copy of A with a negative zero */
    uint32_t idx[6] = {0, 1, 2, 3, 4, 5};
    ak_vec3 n[6];
    uint32_t scratch[64];
    size_t need = ak_normals_welded_scratch_count(6);
    AK_CHECK(need >= 6 && need <= 64);
    AK_CHECK_EQ(ak_normals_compute_welded((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_u32_span){scratch, need},
                                          (ak_vec3_span){n, 6}),
                AK_OK);
    /* reference in double: face normals as unnormalised cross products (twice the area) */
    double f1[3], f2[3], e1[3], e2[3];
    const ak_vec3 t1[3] = {A, B, C}, t2[3] = {B, A, D};
    const ak_vec3* t[2] = {t1, t2};
    double* fn[2] = {f1, f2};
    for (int k = 0; k < 2; ++k) {
        e1[0] = t[k][1].x - t[k][0].x, e1[1] = t[k][1].y - t[k][0].y, e1[2] = t[k][1].z - t[k][0].z;
        e2[0] = t[k][2].x - t[k][0].x, e2[1] = t[k][2].y - t[k][0].y, e2[2] = t[k][2].z - t[k][0].z;
        fn[k][0] = e1[1] * e2[2] - e1[2] * e2[1];
        fn[k][1] = e1[2] * e2[0] - e1[0] * e2[2];
        fn[k][2] = e1[0] * e2[1] - e1[1] * e2[0];
    }
    double s[3] = {f1[0] + f2[0], f1[1] + f2[1], f1[2] + f2[2]};
    double ls = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]), l1 = sqrt(f1[0] * f1[0] + f1[1] * f1[1] + f1[2] * f1[2]),
           l2 = sqrt(f2[0] * f2[0] + f2[1] * f2[1] + f2[2] * f2[2]);
    const int ridge[4] = {0, 1, 3, 4};
    for (int r = 0; r < 4; ++r) {
        int v = ridge[r];
        AK_CHECK_NEAR(n[v].x, s[0] / ls, 1e-6);
        AK_CHECK_NEAR(n[v].y, s[1] / ls, 1e-6);
        AK_CHECK_NEAR(n[v].z, s[2] / ls, 1e-6);
    }
    AK_CHECK_NEAR(n[2].z, f1[2] / l1, 1e-6);
    AK_CHECK_NEAR(n[2].y, f1[1] / l1, 1e-6);
    AK_CHECK_NEAR(n[5].y, f2[1] / l2, 1e-6);
    AK_CHECK_NEAR(n[5].z, f2[2] / l2, 1e-6);
    /* the unwelded version gives each corner its own face's normal */
    ak_vec3 m[6];
    AK_CHECK_EQ(ak_normals_compute((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_vec3_span){m, 6}), AK_OK);
    AK_CHECK(fabsf(m[0].z - n[0].z) > 0.1f);
    /* a NaN position is not welded with anything and gets the fallback normal */
    pos[5] = ak_vec3_make(NAN, 0, 0);
    AK_CHECK_EQ(ak_normals_compute_welded((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_u32_span){scratch, need},
                                          (ak_vec3_span){n, 6}),
                AK_OK);
    AK_CHECK(n[5].x == 0.0f && n[5].y == 1.0f && n[5].z == 0.0f);
    AK_CHECK(ak_vec3_is_finite(n[0]));
    /* errors */
    AK_CHECK_EQ(ak_normals_compute_welded((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_u32_span){scratch, need - 1},
                                          (ak_vec3_span){n, 6}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_normals_compute_welded((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_u32_span){scratch, need},
                                          (ak_vec3_span){n, 5}),
                AK_ERR_SPAN_SMALL);
    idx[2] = 6;
    AK_CHECK_EQ(ak_normals_compute_welded((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_u32_span){scratch, need},
                                          (ak_vec3_span){n, 6}),
                AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_normals_compute_welded((ak_vec3_cspan){pos, 6}, (ak_u32_cspan){idx, 6}, (ak_u32_span){NULL, need},
                                          (ak_vec3_span){n, 6}),
                AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_normals_welded_scratch_count(SIZE_MAX / 2), SIZE_MAX);
}

/* ---- self-intersections ---- */

static bool tri_hit(const float a[9], const float b[9]) {
    ak_vec3 A[3], B[3];
    for (int k = 0; k < 3; ++k) {
        A[k] = ak_vec3_make(a[3 * k], a[3 * k + 1], a[3 * k + 2]);
        B[k] = ak_vec3_make(b[3 * k], b[3 * k + 1], b[3 * k + 2]);
    }
    bool h1 = ak_triangles_intersect(A, B), h2 = ak_triangles_intersect(B, A);
    return h1 && h2 ? true : (!h1 && !h2 ? false : (printf("  asymmetric\n"), !h1));
}

AK_TEST(triangle_pairs_constructed) {
    const float base[9] = {0, 0, 0, 4, 0, 0, 0, 4, 0}; /* in z = 0 */
    /* crossing: a vertical triangle through the interior */
    const float cross[9] = {1, 1, -1, 1, 1, 1, 2, 0.5f, 0};
    AK_CHECK(tri_hit(base, cross));
    /* the same one lifted above the plane: disjoint */
    const float above[9] = {1, 1, 0.5f, 1, 1, 2, 2, 0.5f, 1};
    AK_CHECK(!tri_hit(base, above));
    /* touching: a vertex resting on the interior, then on an edge, then on a corner */
    const float on_face[9] = {1, 1, 0, 1, 2, 3, 2, 1, 3};
    const float on_edge[9] = {2, 0, 0, 2, -1, 3, 3, -1, 3};
    const float on_corner[9] = {4, 0, 0, 5, 1, 2, 5, -1, 2};
    AK_CHECK(tri_hit(base, on_face));
    AK_CHECK(tri_hit(base, on_edge));
    AK_CHECK(tri_hit(base, on_corner));
    /* just missing the corner (x = 4 + 2^-20) */
    const float near_corner[9] = {4.00000095f, 0, 0, 5, 1, 2, 5, -1, 2};
    AK_CHECK(!tri_hit(base, near_corner));
    /* an edge lying in the plane and crossing the triangle, the rest above */
    const float edge_in_plane[9] = {-1, 1, 0, 3, 1, 0, 1, 1, 2};
    AK_CHECK(tri_hit(base, edge_in_plane));
    const float edge_in_plane_out[9] = {-1, -1, 0, 3, -1, 0, 1, -1, 2};
    AK_CHECK(!tri_hit(base, edge_in_plane_out));
    /* coplanar: overlapping edges, contained, sharing only an edge segment, disjoint */
    const float co_overlap[9] = {1, 1, 0, 5, 1, 0, 1, 5, 0};
    const float co_inside[9] = {0.5f, 0.5f, 0, 1.5f, 0.5f, 0, 0.5f, 1.5f, 0};
    const float co_edge[9] = {1, 0, 0, 3, 0, 0, 2, -2, 0};
    const float co_apart[9] = {3, 3, 0, 5, 3, 0, 3, 5, 0}; /* beyond the hypotenuse x + y = 4 */
    AK_CHECK(tri_hit(base, co_overlap));
    AK_CHECK(tri_hit(base, co_inside));
    AK_CHECK(tri_hit(co_inside, base));
    AK_CHECK(tri_hit(base, co_edge));
    AK_CHECK(!tri_hit(base, co_apart));
    /* parallel planes, overlapping in projection */
    const float parallel[9] = {0, 0, 1e-3f, 4, 0, 1e-3f, 0, 4, 1e-3f};
    AK_CHECK(!tri_hit(base, parallel));
    /* degenerate triangles never count */
    const float degenerate[9] = {0, 0, -1, 1, 1, 0, 2, 2, 1};
    AK_CHECK(!tri_hit(base, degenerate));
}

/* Independent reference for triangles in general position: a pair meets iff an edge of one
 * passes through the other (Moller-Trumbore ray test with barycentric coordinates). */
static bool ref_edge_hits(const double* o, const double* e, const double* t) {
    double e1[3], e2[3], d[3] = {e[0] - o[0], e[1] - o[1], e[2] - o[2]}, p[3], s[3], q[3];
    for (int k = 0; k < 3; ++k) e1[k] = t[3 + k] - t[k], e2[k] = t[6 + k] - t[k], s[k] = o[k] - t[k];
    p[0] = d[1] * e2[2] - d[2] * e2[1], p[1] = d[2] * e2[0] - d[0] * e2[2], p[2] = d[0] * e2[1] - d[1] * e2[0];
    double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (fabs(det) < 1e-300) return false;
    double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    q[0] = s[1] * e1[2] - s[2] * e1[1], q[1] = s[2] * e1[0] - s[0] * e1[2], q[2] = s[0] * e1[1] - s[1] * e1[0];
    double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    double w = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    return u >= 0 && v >= 0 && u + v <= 1 && w >= 0 && w <= 1;
}

static bool ref_tri_tri(const ak_vec3* P, const uint32_t* a, const uint32_t* b) {
    double A[9], B[9];
    for (int k = 0; k < 3; ++k) {
        A[3 * k] = P[a[k]].x, A[3 * k + 1] = P[a[k]].y, A[3 * k + 2] = P[a[k]].z;
        B[3 * k] = P[b[k]].x, B[3 * k + 1] = P[b[k]].y, B[3 * k + 2] = P[b[k]].z;
    }
    for (int i = 0; i < 3; ++i) {
        int j = (i + 1) % 3;
        if (ref_edge_hits(A + 3 * i, A + 3 * j, B) || ref_edge_hits(B + 3 * i, B + 3 * j, A)) return true;
    }
    return false;
}

AK_TEST(self_intersections_soup_matches_brute_force) {
    /* 300 random triangles (no shared vertices) in a box: the grid count and the pairs it lists
     * equal an all-pairs reference. */
    enum { NT = 300 };
    static ak_vec3 pos[3 * NT];
    static uint32_t idx[3 * NT];
    ak_rng rng = ak_rng_make(7);
    for (int t = 0; t < NT; ++t) {
        ak_vec3 c = ak_vec3_make(ak_rng_range(&rng, 0, 10), ak_rng_range(&rng, 0, 10), ak_rng_range(&rng, 0, 10));
        float s = ak_rng_range(&rng, 0.2f, 1.5f);
        for (int k = 0; k < 3; ++k) {
            pos[3 * t + k] = ak_vec3_add(c, ak_vec3_make(s * ak_rng_range(&rng, -1, 1), s * ak_rng_range(&rng, -1, 1),
                                                         s * ak_rng_range(&rng, -1, 1)));
            idx[3 * t + k] = (uint32_t)(3 * t + k);
        }
    }
    size_t ref = 0;
    static unsigned char hit[NT][NT];
    memset(hit, 0, sizeof hit);
    for (int a = 0; a < NT; ++a)
        for (int b = a + 1; b < NT; ++b)
            if (ref_tri_tri(pos, idx + 3 * a, idx + 3 * b)) ++ref, hit[a][b] = 1;
    static uint32_t pairs[2 * NT * NT];
    size_t count = 0;
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){pos, 3 * NT}, (ak_u32_cspan){idx, 3 * NT},
                                           (ak_u32_span){pairs, 2 * NT * NT}, &count),
                AK_OK);
    AK_CHECK(ref > 20);
    AK_CHECK_EQ(count, ref);
    size_t matched = 0;
    for (size_t k = 0; k < count && k < NT * NT; ++k) {
        uint32_t a = pairs[2 * k], b = pairs[2 * k + 1];
        if (a < b && b < NT && hit[a][b]) ++matched, hit[a][b] = 0; /* each pair once */
    }
    AK_CHECK_EQ(matched, ref);
    /* a short pair buffer still gives the full count */
    size_t count2 = 0;
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){pos, 3 * NT}, (ak_u32_cspan){idx, 3 * NT},
                                           (ak_u32_span){pairs, 3}, &count2),
                AK_OK);
    AK_CHECK_EQ(count2, ref);
}

AK_TEST(self_intersections_meshes) {
    /* a closed sphere and a cube: none (neighbours share vertices) */
    ak_mesh* s = make_sphere(1.0f, 12, 16);
    ak_mesh* c = make_cube(ak_vec3_zero(), false);
    size_t n = 99;
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){s->positions, s->vertex_count},
                                           (ak_u32_cspan){s->indices, 3 * s->triangle_count}, (ak_u32_span){0}, &n),
                AK_OK);
    AK_CHECK_EQ(n, 0);
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){c->positions, 8}, (ak_u32_cspan){c->indices, 36},
                                           (ak_u32_span){0}, &n),
                AK_OK);
    AK_CHECK_EQ(n, 0);
    /* two unit cubes offset by (0.5, 0.25, 0.125) : an all-pairs count with the pair test */
    ak_vec3 pos[16];
    uint32_t idx[72];
    for (int i = 0; i < 8; ++i) {
        pos[i] = c->positions[i];
        pos[8 + i] = ak_vec3_add(c->positions[i], ak_vec3_make(0.5f, 0.25f, 0.125f));
    }
    for (int i = 0; i < 36; ++i) idx[i] = c->indices[i], idx[36 + i] = c->indices[i] + 8;
    size_t ref = 0;
    for (int a = 0; a < 12; ++a)
        for (int b = 12; b < 24; ++b) {
            ak_vec3 A[3] = {pos[idx[3 * a]], pos[idx[3 * a + 1]], pos[idx[3 * a + 2]]};
            ak_vec3 B[3] = {pos[idx[3 * b]], pos[idx[3 * b + 1]], pos[idx[3 * b + 2]]};
            ref += ak_triangles_intersect(A, B);
        }
    /* faces x=1 of cube A cut faces y and z of cube B and so on: 3 faces of each cross 2 of the
     * other, each face being 2 triangles; the reference counts them pair by pair */
    AK_CHECK(ref >= 12);
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){pos, 16}, (ak_u32_cspan){idx, 72}, (ak_u32_span){0}, &n),
                AK_OK);
    AK_CHECK_EQ(n, ref);
    /* shared vertices exclude a pair, by index or by position */
    ak_vec3 fan[6] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 0.2f, -1}, {0.2f, 1, 1}, {0, 0, 0}};
    uint32_t fi[6] = {0, 1, 2, 0, 3, 4};
    ak_vec3 A[3] = {fan[0], fan[1], fan[2]}, B[3] = {fan[0], fan[3], fan[4]};
    AK_CHECK(ak_triangles_intersect(A, B)); /* they do cross */
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){fan, 6}, (ak_u32_cspan){fi, 6}, (ak_u32_span){0}, &n), AK_OK);
    AK_CHECK_EQ(n, 0);
    fi[3] = 5; /* a split copy of vertex 0 */
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){fan, 6}, (ak_u32_cspan){fi, 6}, (ak_u32_span){0}, &n), AK_OK);
    AK_CHECK_EQ(n, 0);
    fan[5] = ak_vec3_make(0, 0, 1e-6f); /* no longer the same position: counted */
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){fan, 6}, (ak_u32_cspan){fi, 6}, (ak_u32_span){0}, &n), AK_OK);
    AK_CHECK_EQ(n, 1);
    /* errors */
    fi[1] = 6;
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){fan, 6}, (ak_u32_cspan){fi, 6}, (ak_u32_span){0}, &n),
                AK_ERR_BAD_INDEX);
    fi[1] = 1;
    fan[2].y = NAN;
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){fan, 6}, (ak_u32_cspan){fi, 6}, (ak_u32_span){0}, &n),
                AK_ERR_BAD_DATA);
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){fan, 6}, (ak_u32_cspan){fi, 6}, (ak_u32_span){0}, NULL),
                AK_ERR_NULL_ARG);
    ak_mesh_destroy(s);
    ak_mesh_destroy(c);
}

AK_TEST(self_intersections_50k_fast_and_exact) {
    /* a 50k-triangle sphere has none; a copy shifted by 1/2 radius crosses it along a circle:
     * each crossing pair found is confirmed by the pair test, and the timing stays low */
    ak_mesh* s = make_sphere(1.0f, 126, 200); /* 2 * 200 * 125 = 50000 triangles */
    AK_CHECK_EQ(s->triangle_count, 50000);
    size_t n = 1;
    double t0 = ak_test_now_();
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){s->positions, s->vertex_count},
                                           (ak_u32_cspan){s->indices, 3 * s->triangle_count}, (ak_u32_span){0}, &n),
                AK_OK);
    double dt = ak_test_now_() - t0;
    AK_CHECK_EQ(n, 0);
    AK_CHECK_MSG(dt < 0.5, "50k triangles took %.3f s", dt);
    /* two small spheres side by side (centres 1.5 radii apart): the crossing circle */
    ak_mesh* a = make_sphere(1.0f, 24, 32);
    size_t vc = a->vertex_count, tc = a->triangle_count;
    ak_vec3* pos = (ak_vec3*)malloc(2 * vc * sizeof(ak_vec3));
    uint32_t* idx = (uint32_t*)malloc(6 * tc * sizeof(uint32_t));
    for (size_t i = 0; i < vc; ++i) pos[i] = a->positions[i], pos[vc + i] = ak_vec3_add(a->positions[i], ak_vec3_make(1.5f, 0, 0));
    for (size_t i = 0; i < 3 * tc; ++i) idx[i] = a->indices[i], idx[3 * tc + i] = a->indices[i] + (uint32_t)vc;
    size_t ref = 0;
    for (size_t p = 0; p < tc; ++p) /* brute force across the two spheres only */
        for (size_t q = tc; q < 2 * tc; ++q) {
            ak_vec3 A[3] = {pos[idx[3 * p]], pos[idx[3 * p + 1]], pos[idx[3 * p + 2]]};
            ak_vec3 B[3] = {pos[idx[3 * q]], pos[idx[3 * q + 1]], pos[idx[3 * q + 2]]};
            ref += ak_triangles_intersect(A, B);
        }
    AK_CHECK(ref > 32); /* the circle crosses at least one triangle per longitude */
    AK_CHECK_EQ(ak_mesh_self_intersections((ak_vec3_cspan){pos, 2 * vc}, (ak_u32_cspan){idx, 6 * tc}, (ak_u32_span){0}, &n),
                AK_OK);
    AK_CHECK_EQ(n, ref);
    free(pos);
    free(idx);
    ak_mesh_destroy(a);
    ak_mesh_destroy(s);
}

int main(void) {
    AK_RUN(create_one_allocation_and_zeroed);
    AK_RUN(create_bad_input);
    AK_RUN(clone_is_deep);
    AK_RUN(validate_codes);
    AK_RUN(bounds);
    AK_RUN(normals);
    AK_RUN(normals_welded);
    AK_RUN(volume_cube_and_sphere);
    AK_RUN(closed_oriented);
    AK_RUN(validate_weights_codes);
    AK_RUN(weights_normalize_keeps_largest);
    AK_RUN(weights_normalize_edge_cases);
    AK_RUN(triangle_pairs_constructed);
    AK_RUN(self_intersections_soup_matches_brute_force);
    AK_RUN(self_intersections_meshes);
    AK_RUN(self_intersections_50k_fast_and_exact);
    return ak_test_finish();
}
