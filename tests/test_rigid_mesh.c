/* Static heightfields and triangle meshes against closed forms and physics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/rigid.h>
#include <animkit/terrain.h>

#include "ak_test.h"
#include "rigid_world.h"



static bool world_steps(world* wd, int steps) {
    for (int s = 0; s < steps; ++s)
        if (ak_rigid_step_run(&wd->job) != AK_OK) return false;
    return true;
}


/* Height of the heightfield's surface at local (x, z), from its two triangles per cell (the
 * documented split: (00, 01, 11) where v >= u, (00, 11, 10) elsewhere). */
static float hf_height(const float* h, uint32_t cols, float spacing, float x, float z) {
    float fx = x / spacing, fz = z / spacing;
    uint32_t i = (uint32_t)floorf(fx), j = (uint32_t)floorf(fz);
    float u = fx - (float)i, v = fz - (float)j;
    float h00 = h[j * cols + i], h10 = h[j * cols + i + 1], h01 = h[(j + 1) * cols + i],
          h11 = h[(j + 1) * cols + i + 1];
    if (v >= u) return h00 + v * (h01 - h00) + u * (h11 - h01);
    return h00 + u * (h10 - h00) + v * (h11 - h10);
}

AK_TEST(sphere_rests_on_a_heightfield_at_the_analytic_height) {
    /* a shallow bowl h = 1 + 0.02 ((x - 5)^2 + (z - 5)^2) sampled every 0.5 m: a sphere dropped
     * over its lowest sample rests on it, centre at 1 + r; on a flat heightfield at 0.7 another
     * rests between samples at 0.7 + r */
    enum { N = 21 };
    static float bowl[N * N], flat[N * N];
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            float x = 0.5f * (float)i - 5.0f, z = 0.5f * (float)j - 5.0f;
            bowl[j * N + i] = 1.0f + 0.02f * (x * x + z * z);
            flat[j * N + i] = 0.7f;
        }
    ak_rigid_body_desc b[4] = {
        {.shape = {.type = AK_RIGID_HEIGHTFIELD, .heights = {bowl, N * N}, .rows = N, .cols = N,
                   .spacing = 0.5f}},
        {.shape = {.type = AK_RIGID_HEIGHTFIELD, .heights = {flat, N * N}, .rows = N, .cols = N,
                   .spacing = 0.5f},
         .position = {20.0f, 0.0f, 0.0f}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.3f}, .position = {5.0f, 1.6f, 5.0f}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.3f}, .position = {23.13f, 1.2f, 4.37f}},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 4, 20));
    AK_CHECK(ak_rigid_body_get_desc(wd.model, 0).is_static);
    AK_CHECK(world_steps(&wd, 120));
    AK_CHECK_MSG(fabsf(wd.x[2].y - 1.3f) < 2e-3f, "bowl: centre at %g, want 1.3", wd.x[2].y);
    AK_CHECK_MSG(fabsf(wd.x[3].y - 1.0f) < 2e-3f, "flat: centre at %g, want 1.0", wd.x[3].y);
    if (getenv("AK_TEST_VERBOSE")) printf("bowl %g (1.3), flat %g (1.0)\n", wd.x[2].y, wd.x[3].y);
    AK_CHECK_MSG(ak_vec3_distance(wd.x[3], ak_vec3_make(23.13f, wd.x[3].y, 4.37f)) < 1e-3f,
                 "flat: moved sideways");
    world_free(&wd);
}

AK_TEST(ball_rolls_down_a_heightfield_ramp) {
    /* the heightfield y = -tan(20 deg) x: a rolling solid sphere accelerates at 5/7 g sin 20 */
    enum { COLS = 41, ROWS = 9 };
    const float th = 20.0f * 3.14159265f / 180.0f, sp = 0.5f, r = 0.25f;
    static float h[ROWS * COLS];
    for (int j = 0; j < ROWS; ++j)
        for (int i = 0; i < COLS; ++i) h[j * COLS + i] = -tanf(th) * sp * (float)i;
    ak_vec3 n = ak_vec3_make(sinf(th), cosf(th), 0.0f);
    ak_vec3 start = ak_vec3_madd(ak_vec3_make(2.0f, -tanf(th) * 2.0f, 0.0f), n, r);
    ak_rigid_body_desc b[2] = {
        {.shape = {.type = AK_RIGID_HEIGHTFIELD, .heights = {h, ROWS * COLS}, .rows = ROWS,
                   .cols = COLS, .spacing = sp},
         .position = {0.0f, 0.0f, -2.0f},
         .friction = 1.0f},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = r}, .position = start, .friction = 1.0f},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 2, 20));
    const float t = 1.5f;
    AK_CHECK(world_steps(&wd, (int)lroundf(t * 60.0f)));
    float s = ak_vec3_distance(wd.x[1], start);
    float want = 0.5f * 5.0f / 7.0f * 9.81f * sinf(th) * t * t;
    AK_CHECK_MSG(fabsf(s - want) < 0.02f * want, "rolled %g m, want %g", s, want);
    if (getenv("AK_TEST_VERBOSE")) printf("ramp: rolled %g m, want %g\n", s, want);
    /* rolling, not sliding: v = w r */
    float v = ak_vec3_length(wd.v[1]), wr = ak_vec3_length(wd.w[1]) * r;
    AK_CHECK_MSG(fabsf(v - wr) < 0.02f * v, "v %g vs w r %g", v, wr);
    world_free(&wd);
}

AK_TEST(nothing_tunnels_through_a_trimesh_floor) {
    /* a 10 x 10 grid of quads (200 triangles) with uneven heights; a sphere, a box, a capsule
     * and a hull thrown down at 12 m/s stay above it (they may roll on its slopes) */
    enum { Q = 10 };
    static ak_vec3 verts[(Q + 1) * (Q + 1)];
    static uint32_t idx[Q * Q * 6];
    for (int j = 0; j <= Q; ++j)
        for (int i = 0; i <= Q; ++i)
            verts[j * (Q + 1) + i] = ak_vec3_make((float)i - 5.0f, 0.05f * (float)((i * 7 + j * 3) % 5),
                                                  (float)j - 5.0f);
    size_t k = 0;
    for (int j = 0; j < Q; ++j)
        for (int i = 0; i < Q; ++i) {
            uint32_t a = (uint32_t)(j * (Q + 1) + i), bq = a + 1, c = a + Q + 1, d = c + 1;
            /* counter-clockwise seen from above (+Y): a, c, d and a, d, b */
            idx[k++] = a, idx[k++] = c, idx[k++] = d;
            idx[k++] = a, idx[k++] = d, idx[k++] = bq;
        }
    ak_vec3 tet[4] = {{0.3f, 0.3f, 0.3f}, {0.3f, -0.3f, -0.3f}, {-0.3f, 0.3f, -0.3f},
                      {-0.3f, -0.3f, 0.3f}};
    ak_rigid_body_desc b[5] = {
        {.shape = {.type = AK_RIGID_TRIMESH, .vertices = {verts, (Q + 1) * (Q + 1)},
                   .indices = {idx, k}}},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.2f}, .position = {-2.3f, 3.0f, 1.2f},
         .velocity = {0.0f, -12.0f, 0.0f}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.3f, 0.2f, 0.25f}},
         .position = {1.7f, 3.0f, -2.1f}, .velocity = {0.0f, -12.0f, 0.0f}},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.15f, .half_height = 0.3f},
         .position = {0.4f, 3.0f, 2.6f}, .velocity = {0.0f, -12.0f, 0.0f},
         .orientation = {0.0f, 0.0f, 0.7071068f, 0.7071068f}},
        {.shape = {.type = AK_RIGID_HULL, .points = {tet, 4}}, .position = {-1.1f, 3.0f, -3.2f},
         .velocity = {0.0f, -12.0f, 0.0f}},
    };
    world wd;
    AK_CHECK(world_init(&wd, b, 5, 20));
    float lowest[5] = {0, 0, 0, 0, 0};
    for (int s = 0; s < 80; ++s) {
        AK_CHECK(world_steps(&wd, 1));
        for (int i = 1; i < 5; ++i) {
            /* each body's lowest point against the floor's highest (0.2 m): never below its lowest (0) */
            float lo = INFINITY;
            ak_rigid_body_desc d = ak_rigid_body_get_desc(wd.model, (size_t)i);
            for (int c = 0; c < 8; ++c) {
                ak_vec3 e = {c & 1 ? 1.0f : -1.0f, c & 2 ? 1.0f : -1.0f, c & 4 ? 1.0f : -1.0f};
                ak_vec3 l = d.shape.type == AK_RIGID_BOX ? ak_vec3_mul(e, d.shape.half_extents)
                                                         : ak_vec3_zero();
                lo = ak_minf(lo, wd.x[i].y + ak_quat_rotate(wd.q[i], l).y);
            }
            if (d.shape.type == AK_RIGID_SPHERE) lo = wd.x[i].y - d.shape.radius;
            if (d.shape.type == AK_RIGID_CAPSULE)
                lo = wd.x[i].y - d.shape.radius -
                     fabsf(ak_quat_rotate(wd.q[i], ak_vec3_make(0, 1, 0)).y) * d.shape.half_height;
            if (d.shape.type == AK_RIGID_HULL) {
                lo = INFINITY;
                for (size_t p = 0; p < d.shape.points.count; ++p)
                    lo = ak_minf(lo, wd.x[i].y + ak_quat_rotate(wd.q[i], d.shape.points.ptr[p]).y);
            }
            lowest[i] = s == 0 ? lo : ak_minf(lowest[i], lo);
        }
    }
    for (int i = 1; i < 5; ++i) {
        if (getenv("AK_TEST_VERBOSE")) printf("trimesh: body %d lowest %g\n", i, lowest[i]);
        AK_CHECK_MSG(lowest[i] > -0.02f, "body %d went down to %g", i, lowest[i]);
        AK_CHECK_MSG(wd.x[i].y > 0.0f && wd.x[i].y < 0.6f, "body %d ends at %g", i, wd.x[i].y);
    }
    world_free(&wd);
}

AK_TEST(spheres_land_on_animkit_terrain) {
    /* animkit terrain's output as a heightfield (its layout: cols = width, rows = height,
     * spacing = world_size / (width - 1), origin at the first sample): spheres dropped on it stay
     * above the surface under them */
    enum { W = 33 };
    ak_noise nz = ak_noise_make(7);
    ak_terrain_desc td = {.noise = &nz, .width = W, .height = W, .world_size = 16.0f,
                          .height_scale = 1.5f};
    static float h[W * W];
    static ak_vec3 nrm[W * W];
    AK_CHECK_EQ(ak_terrain_generate(&td, (ak_f32_span){h, W * W}, (ak_vec3_span){nrm, W * W}), AK_OK);
    ak_vec3 origin = ak_terrain_sample_position(&td, 0, 0, 0.0f);
    float spacing = 16.0f / (float)(W - 1);
    ak_rigid_body_desc b[6] = {{.shape = {.type = AK_RIGID_HEIGHTFIELD, .heights = {h, W * W},
                                          .rows = W, .cols = W, .spacing = spacing},
                                .position = origin}};
    for (int i = 1; i < 6; ++i)
        b[i] = (ak_rigid_body_desc){.shape = {.type = AK_RIGID_SPHERE, .radius = 0.3f},
                                    .position = {-5.0f + 2.2f * (float)i, 4.0f, 3.0f - 1.3f * (float)i},
                                    .friction = 1.0f};
    world wd;
    AK_CHECK(world_init(&wd, b, 6, 20));
    for (int s = 0; s < 90; ++s) {
        AK_CHECK(world_steps(&wd, 1));
        for (int i = 1; i < 6; ++i) {
            float lx = wd.x[i].x - origin.x, lz = wd.x[i].z - origin.z;
            if (lx < 0.0f || lz < 0.0f || lx >= 16.0f || lz >= 16.0f) continue;
            float ground = hf_height(h, W, spacing, lx, lz) + origin.y;
            AK_CHECK_MSG(wd.x[i].y - ground > 0.3f - 0.02f, "sphere %d at %g over ground %g", i,
                         wd.x[i].y, ground);
        }
    }
    world_free(&wd);
}

AK_TEST(mesh_shape_validation_and_scene_keys) {
    float h[4] = {0, 0, 0, 0};
    ak_rigid_body_desc b = {.shape = {.type = AK_RIGID_HEIGHTFIELD, .heights = {h, 4}, .rows = 2,
                                      .cols = 2, .spacing = 1.0f}};
    ak_rigid_model_desc md = {.bodies = {&b, 1}};
    ak_rigid_model* m = NULL;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_OK);
    ak_rigid_model_destroy(m);
    b.shape.heights.count = 3;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    b.shape.heights.count = 4;
    h[2] = NAN;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_DATA);
    h[2] = 0.0f;
    b.shape.spacing = 0.0f;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);
    ak_vec3 v[3] = {{0, 0, 0}, {0, 0, 1}, {1, 0, 0}};
    uint32_t ix[3] = {0, 1, 3};
    ak_rigid_body_desc t = {.shape = {.type = AK_RIGID_TRIMESH, .vertices = {v, 3}, .indices = {ix, 3}}};
    md.bodies = (ak_rigid_body_desc_cspan){&t, 1};
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_INDEX);
    t.shape.indices.count = 2;
    AK_CHECK_EQ(ak_rigid_model_create(&md, NULL, &m), AK_ERR_BAD_ARG);

    const char* good =
        "{\"bodies\": [{\"shape\": {\"type\": \"heightfield\", \"rows\": 2, \"cols\": 3,"
        " \"spacing\": 2, \"heights\": [0, 0.5, 1, 0, 0.5, 1]}},"
        " {\"shape\": {\"type\": \"trimesh\", \"vertices\": [[0,0,0],[0,0,1],[1,0,0]],"
        " \"indices\": [0, 1, 2]}, \"position\": [10, 0, 0]},"
        " {\"shape\": {\"type\": \"sphere\", \"radius\": 0.5}, \"position\": [1, 3, 1]}]}";
    ak_rigid_scene sc;
    ak_diag diag;
    ak_rigid_scene_defaults(&sc);
    AK_CHECK_EQ(ak_rigid_scene_load_bytes(good, strlen(good), "t", &sc, &diag), AK_OK);
    AK_CHECK_EQ(sc.bodies[0].shape.type, AK_RIGID_HEIGHTFIELD);
    AK_CHECK_EQ(sc.bodies[0].shape.cols, 3u);
    AK_CHECK_NEAR(sc.bodies[0].shape.heights.ptr[5], 1.0f, 0.0f);
    AK_CHECK(sc.bodies[0].is_static && sc.bodies[1].is_static);
    AK_CHECK_EQ(sc.bodies[1].shape.indices.count, (size_t)3);
    ak_rigid_scene_run run;
    AK_CHECK_EQ(ak_rigid_scene_run_init(&run, &sc, "t", &diag), AK_OK);
    ak_rigid_scene_run_free(&run);
    ak_rigid_scene_free(&sc);
    const char* bad[] = {
        "{\"bodies\": [{\"shape\": {\"type\": \"heightfield\", \"rows\": 2, \"cols\": 2, \"heights\": [0, 0, 0]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"heightfield\", \"rows\": 2, \"cols\": 2, \"heights\": [0, 0, 0, \"a\"]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"heightfield\", \"cols\": 2, \"heights\": [0, 0]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"heightfield\", \"rows\": 100000, \"cols\": 100000, \"heights\": []}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"trimesh\", \"vertices\": [[0,0,0],[0,0,1],[1,0,0]], \"indices\": [0, 1, 3]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"trimesh\", \"vertices\": [[0,0,0],[0,0,1],[1,0,0]], \"indices\": [0, 1]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"trimesh\", \"indices\": [0, 1, 2]}}]}",
        "{\"bodies\": [{\"shape\": {\"type\": \"trimesh\", \"radius\": 1}}]}",
    };
    const char* where[] = {"bodies[0].shape.heights: expected rows x cols = 4",
                           "bodies[0].shape.heights[3]",
                           "bodies[0].shape.rows: is required",
                           "bodies[0].shape.rows: rows x cols is over",
                           "bodies[0].shape.indices[2]",
                           "bodies[0].shape.indices: is required",
                           "bodies[0].shape.vertices: is required",
                           "bodies[0].shape.radius"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        ak_rigid_scene_defaults(&sc);
        AK_CHECK_EQ(ak_rigid_scene_load_bytes(bad[i], strlen(bad[i]), "t", &sc, &diag), AK_ERR_PARSE);
        AK_CHECK_MSG(strstr(diag.message, where[i]) != NULL, "%s", diag.message);
        ak_rigid_scene_free(&sc);
    }
}

int main(void) {
    AK_RUN(sphere_rests_on_a_heightfield_at_the_analytic_height);
    AK_RUN(ball_rolls_down_a_heightfield_ramp);
    AK_RUN(nothing_tunnels_through_a_trimesh_floor);
    AK_RUN(spheres_land_on_animkit_terrain);
    AK_RUN(mesh_shape_validation_and_scene_keys);
    return ak_test_finish();
}
