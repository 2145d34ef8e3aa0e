/* Tests for builtin.h: the generated scenes are complete and consistent. Oracles: closed
 * forms (prism volume, bend geometry), hand bounds (a 1.8 m figure), properties (closed and
 * consistently oriented meshes, valid weights, identity bind palette, limits respected at
 * 100 sample times of every clip). */
#include <animkit/builtin.h>

#include "ak_test.h"

#define PI_D 3.14159265358979323846


static double mesh_volume(const ak_mesh* m) {
    return ak_volume_compute((ak_vec3_cspan){m->positions, m->vertex_count},
                             (ak_u32_cspan){m->indices, 3 * m->triangle_count});
}

/* Sample a clip into a pose that starts at the rest pose; returns false on error. */
static bool sample(const ak_scene* s, size_t clip, float t, ak_transform* local, size_t n) {
    if (ak_scene_rest_pose(s, (ak_transform_span){local, n}) != AK_OK) return false;
    return ak_clip_sample(s->clips[clip], t, NULL, (ak_transform_span){local, n},
                          (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0}) == AK_OK;
}

/* Common structure: one skinned mesh on skin 0, slots = joints, palette at bind = identity. */
static void check_scene_shape(const ak_scene* s) {
    AK_CHECK(s->skeleton != NULL);
    AK_CHECK_EQ(s->mesh_count, 1);
    AK_CHECK_EQ(s->skin_count, 1);
    if (!s->skeleton || s->mesh_count != 1 || s->skin_count != 1) return;
    const size_t n = ak_scene_joint_count(s);
    AK_CHECK_EQ(s->meshes[0].node, -1);
    AK_CHECK_EQ(s->meshes[0].skin, 0);
    AK_CHECK_EQ(s->skins[0].joint_count, n);
    for (size_t k = 0; k < n; ++k) AK_CHECK_EQ(s->skins[0].joints[k], (int32_t)k);
    const ak_mesh* m = s->meshes[0].mesh;
    ak_diag diag;
    AK_CHECK_EQ(ak_mesh_validate(m, &diag), AK_OK);
    AK_CHECK_EQ(ak_mesh_validate_weights(m, n, 1e-5f, &diag), AK_OK);
    AK_CHECK(m->influence_count <= 4 && m->normals != NULL);
    AK_CHECK(ak_mesh_is_closed_oriented(m));
    /* Palette at bind: world(rest) * inverse_bind = identity. */
    ak_transform* local = (ak_transform*)malloc(n * sizeof *local);
    ak_mat4* world = (ak_mat4*)malloc(n * sizeof *world);
    ak_mat4* pal = (ak_mat4*)malloc(n * sizeof *pal);
    ak_scene_rest_pose(s, (ak_transform_span){local, n});
    AK_CHECK_EQ(
        ak_scene_world_matrices(s, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n}),
        AK_OK);
    AK_CHECK_EQ(ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, n}, (ak_mat4_span){pal, n}),
                AK_OK);
    double worst = 0.0;
    for (size_t j = 0; j < n; ++j)
        for (int e = 0; e < 16; ++e)
            worst = fmax(worst, fabs(pal[j].m[e] - ((e % 5 == 0) ? 1.0 : 0.0)));
    AK_CHECK_MSG(worst < 1e-5, "bind palette differs from identity by %g", worst);
    /* Joint names present and unique. */
    for (size_t j = 0; j < n; ++j) {
        const char* nm = ak_skeleton_joint_name(s->skeleton, j);
        AK_CHECK(nm[0] != 0);
        AK_CHECK_EQ(ak_skeleton_find_joint(s->skeleton, nm), (int)j);
    }
    /* Every clip, 100 sample times: finite poses within every joint's limits. */
    for (size_t c = 0; c < s->clip_count; ++c) {
        float dur = ak_clip_duration(s->clips[c]);
        AK_CHECK(dur > 0.0f);
        int outside = 0, bad = 0;
        for (int i = 0; i < 100; ++i) {
            float t = dur * (float)i / 99.0f;
            if (!sample(s, c, t, local, n) || !ak_pose_is_finite((ak_transform_cspan){local, n})) {
                ++bad;
                continue;
            }
            for (size_t j = 0; j < n; ++j)
                if (!ak_skeleton_joint_within_limits(s->skeleton, j, local[j], 1e-3f)) {
                    if (outside < 3)
                        printf("  clip %s t=%.3f joint %s outside its limits\n",
                               ak_clip_name(s->clips[c]), (double)t,
                               ak_skeleton_joint_name(s->skeleton, j));
                    ++outside;
                }
        }
        AK_CHECK_EQ(bad, 0);
        AK_CHECK_EQ(outside, 0);
    }
    free(local);
    free(world);
    free(pal);
}

AK_TEST(names_and_errors) {
    size_t count = 0;
    const char* const* names = ak_builtin_names(&count);
    AK_CHECK_EQ(count, 2);
    AK_CHECK_STREQ(names[0], "cylinder");
    AK_CHECK_STREQ(names[1], "humanoid");
    AK_CHECK(ak_builtin_names(NULL) == names);
    ak_scene* s = (ak_scene*)1;
    AK_CHECK_EQ(ak_builtin_create("builtin:teapot", NULL, NULL, &s), AK_ERR_NOT_FOUND);
    AK_CHECK(s == NULL);
    AK_CHECK_EQ(ak_builtin_create("", NULL, NULL, &s), AK_ERR_NOT_FOUND);
    AK_CHECK_EQ(ak_builtin_create("builtin:", NULL, NULL, &s), AK_ERR_NOT_FOUND);
    AK_CHECK_EQ(ak_builtin_create(NULL, NULL, NULL, &s), AK_ERR_NULL_ARG);
    AK_CHECK_EQ(ak_builtin_create("cylinder", NULL, NULL, NULL), AK_ERR_NULL_ARG);
    ak_builtin_desc bad[] = {{.bone_count = 4}, {.bone_count = 1}, {.length = -1.0f},
                             {.radius = NAN},   {.segments = 2},   {.rings = 5000},
                             {.blend = 1.5f},   {.blend = -0.1f}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i)
        AK_CHECK_EQ(ak_builtin_create("cylinder", &bad[i], NULL, &s), AK_ERR_BAD_ARG);
    ak_builtin_desc bad_cell = {.cell_size = 0.001f}, nan_cell = {.cell_size = NAN};
    AK_CHECK_EQ(ak_builtin_create("humanoid", &bad_cell, NULL, &s), AK_ERR_BAD_ARG);
    AK_CHECK_EQ(ak_builtin_create("humanoid", &nan_cell, NULL, &s), AK_ERR_BAD_ARG);
    AK_CHECK(s == NULL);
    /* Defaults documented in the header. */
    ak_builtin_desc d = ak_builtin_desc_resolved(NULL);
    AK_CHECK(d.length == 2.0f && d.radius == 0.25f && d.rings == 48 && d.segments == 32 &&
             d.bone_count == 2);
    AK_CHECK(d.blend == 0.5f && d.cell_size == 0.03f);
    ak_builtin_desc some = {.rings = 7};
    AK_CHECK_EQ(ak_builtin_desc_resolved(&some).rings, 7);
}

AK_TEST(cylinder_default) {
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_builtin_create("builtin:cylinder", NULL, NULL, &s), AK_OK);
    if (!s) return;
    AK_CHECK_STREQ(s->name, "builtin:cylinder");
    check_scene_shape(s);
    const ak_mesh* m = s->meshes[0].mesh;
    const double L = 2.0, r = 0.25;
    const int R = 48, S = 32;
    AK_CHECK_EQ(m->vertex_count, (size_t)(R + 1) * S + 2);
    AK_CHECK_EQ(m->triangle_count, (size_t)2 * R * S + 2 * S);
    /* Planar faces: the volume is exactly that of the prism over a regular S-gon. */
    double exact = 0.5 * S * r * r * sin(2.0 * PI_D / S) * L;
    AK_CHECK_NEAR(mesh_volume(m), exact, 1e-5 * exact);
    AK_CHECK_EQ(ak_scene_joint_count(s), 3);
    AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 0), "root");
    AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 1), "joint1");
    AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 2), "tip");
    AK_CHECK_EQ(ak_skeleton_joint_type(s->skeleton, 1), AK_JOINT_BALL);
    /* Weights: one bone far from the joint, an even split exactly at it (smoothstep(1/2)),
     * no more than two influences anywhere, and the tip drives nothing. */
    int far_bad = 0, mid_bad = 0, many = 0;
    for (size_t v = 0; v < m->vertex_count; ++v) {
        float y = m->positions[v].y;
        int nz = 0;
        float w1 = 0.0f;
        for (int k = 0; k < 4; ++k) {
            if (m->weights[4 * v + (size_t)k] > 0.0f) ++nz;
            if (m->weights[4 * v + (size_t)k] > 0.0f && m->joints[4 * v + (size_t)k] == 1)
                w1 += m->weights[4 * v + (size_t)k];
            if (m->weights[4 * v + (size_t)k] > 0.0f && m->joints[4 * v + (size_t)k] == 2) ++many;
        }
        if (nz > 2) ++many;
        if (y < 0.7f && w1 != 0.0f) ++far_bad;
        if (y > 1.3f && w1 != 1.0f) ++far_bad;
        if (fabsf(y - 1.0f) < 1e-6f && fabsf(w1 - 0.5f) > 1e-6f) ++mid_bad;
    }
    AK_CHECK_EQ(far_bad, 0);
    AK_CHECK_EQ(mid_bad, 0);
    AK_CHECK_EQ(many, 0);

    /* Clips and their geometry: after "bend" the second bone points 120 degrees from +Y
     * (about +Z), and the top cap centre (weight 1 on joint1) lands at joint1 + L/2 * dir. */
    AK_CHECK_EQ(s->clip_count, 3);
    int bend = ak_scene_find_clip(s, "bend"), twist = ak_scene_find_clip(s, "twist");
    AK_CHECK(bend >= 0 && twist >= 0 && ak_scene_find_clip(s, "bend_twist") >= 0);
    if (bend < 0 || twist < 0) {
        ak_scene_destroy(s);
        return;
    }
    ak_transform local[3];
    ak_mat4 world[3], pal[3];
    AK_CHECK(sample(s, (size_t)bend, 1.0f, local, 3));
    ak_scene_world_matrices(s, (ak_transform_cspan){local, 3}, (ak_mat4_span){world, 3});
    ak_vec3 j1 = ak_mat4_get_translation(world[1]), tip = ak_mat4_get_translation(world[2]);
    AK_CHECK_NEAR(tip.x, -sin(2.0 * PI_D / 3.0), 1e-4);
    AK_CHECK_NEAR(tip.y, 1.0 + cos(2.0 * PI_D / 3.0), 1e-4);
    AK_CHECK_NEAR(j1.y, 1.0, 1e-6);
    ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, 3}, (ak_mat4_span){pal, 3});
    size_t top = m->vertex_count - 1;
    AK_CHECK_NEAR(m->positions[top].y, 2.0, 0.0);
    ak_vec3 moved = ak_mat4_transform_point(pal[1], m->positions[top]);
    AK_CHECK_NEAR(moved.x, tip.x, 1e-4);
    AK_CHECK_NEAR(moved.y, tip.y, 1e-4);
    /* Half-way through "bend", 60 degrees. */
    AK_CHECK(sample(s, (size_t)bend, 0.5f, local, 3));
    ak_scene_world_matrices(s, (ak_transform_cspan){local, 3}, (ak_mat4_span){world, 3});
    AK_CHECK_NEAR(ak_mat4_get_translation(world[2]).x, -sin(PI_D / 3.0), 1e-4);
    /* After "twist" joint1's X axis points to -X (180 degrees about Y). */
    AK_CHECK(sample(s, (size_t)twist, 1.0f, local, 3));
    ak_scene_world_matrices(s, (ak_transform_cspan){local, 3}, (ak_mat4_span){world, 3});
    AK_CHECK_NEAR(world[1].m[0], -1.0, 1e-4);
    AK_CHECK_NEAR(world[1].m[5], 1.0, 1e-4);
    ak_scene_destroy(s);
}

AK_TEST(cylinder_three_bones) {
    ak_builtin_desc d = {.length = 3.0f,
                         .radius = 0.1f,
                         .rings = 30,
                         .segments = 12,
                         .bone_count = 3,
                         .blend = 0.2f};
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_builtin_create("cylinder", &d, NULL, &s), AK_OK);
    if (!s) return;
    check_scene_shape(s);
    AK_CHECK_EQ(ak_scene_joint_count(s), 4);
    AK_CHECK_STREQ(ak_skeleton_joint_name(s->skeleton, 3), "tip");
    const ak_mesh* m = s->meshes[0].mesh;
    AK_CHECK_EQ(m->vertex_count, 31u * 12u + 2u);
    double exact = 0.5 * 12 * 0.01 * sin(2.0 * PI_D / 12) * 3.0;
    AK_CHECK_NEAR(mesh_volume(m), exact, 1e-5 * exact);
    /* Two interior joints share the bend: 60 degrees each, 120 in all at the tip bone. */
    ak_transform local[4];
    ak_mat4 world[4];
    AK_CHECK(sample(s, (size_t)ak_scene_find_clip(s, "bend"), 1.0f, local, 4));
    ak_scene_world_matrices(s, (ak_transform_cspan){local, 4}, (ak_mat4_span){world, 4});
    ak_vec3 dir = ak_vec3_normalize(
        ak_vec3_sub(ak_mat4_get_translation(world[3]), ak_mat4_get_translation(world[2])));
    AK_CHECK_NEAR(dir.x, -sin(2.0 * PI_D / 3.0), 1e-4);
    AK_CHECK_NEAR(dir.y, cos(2.0 * PI_D / 3.0), 1e-4);
    /* Narrow blend band: a vertex 0.2 above joint1 (y = 1) belongs to bone 1 only. */
    for (size_t v = 0; v < m->vertex_count; ++v)
        if (fabsf(m->positions[v].y - 1.2f) < 1e-4f) {
            AK_CHECK_EQ(m->joints[4 * v], 1);
            AK_CHECK(m->weights[4 * v] == 1.0f);
        }
    ak_scene_destroy(s);
}

static const char* const required_joints[] = {
    "pelvis",     "spine_01",   "spine_02",       "neck",        "head",        "left_shoulder",
    "left_elbow", "left_wrist", "right_shoulder", "right_elbow", "right_wrist", "left_hip",
    "left_knee",  "left_ankle", "right_hip",      "right_knee",  "right_ankle"};

AK_TEST(humanoid) {
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_builtin_create("humanoid", NULL, NULL, &s), AK_OK);
    if (!s) return;
    AK_CHECK_STREQ(s->name, "builtin:humanoid");
    check_scene_shape(s);
    const size_t n = ak_scene_joint_count(s);
    AK_CHECK(n >= 17);
    for (size_t i = 0; i < sizeof required_joints / sizeof required_joints[0]; ++i)
        AK_CHECK_MSG(ak_skeleton_find_joint(s->skeleton, required_joints[i]) >= 0,
                     "joint %s missing", required_joints[i]);
    const char* hinges[] = {"left_elbow", "right_elbow", "left_knee", "right_knee"};
    for (int i = 0; i < 4; ++i) {
        int j = ak_skeleton_find_joint(s->skeleton, hinges[i]);
        AK_CHECK_EQ(ak_skeleton_joint_type(s->skeleton, (size_t)j), AK_JOINT_HINGE);
        ak_joint_limits l = ak_skeleton_joint_limits(s->skeleton, (size_t)j);
        AK_CHECK(l.min >= 0.0f && l.max > 1.5f && l.max < 2.8f); /* flexion one way only */
    }
    const char* balls[] = {"left_shoulder", "right_hip", "neck"};
    for (int i = 0; i < 3; ++i) {
        int j = ak_skeleton_find_joint(s->skeleton, balls[i]);
        AK_CHECK_EQ(ak_skeleton_joint_type(s->skeleton, (size_t)j), AK_JOINT_BALL);
        AK_CHECK(ak_skeleton_joint_limits(s->skeleton, (size_t)j).cone_angle > 0.0f);
    }

    const ak_mesh* m = s->meshes[0].mesh;
    printf("  humanoid: %zu vertices, %zu triangles, volume %.4f m^3\n", m->vertex_count,
           m->triangle_count, mesh_volume(m));
    AK_CHECK(m->triangle_count >= 5000 && m->triangle_count <= 20000);
    /* Hand bounds: a 1.8 m figure. An adult of ~70 kg displaces ~0.07 m^3; a capsule
     * figure is slimmer, but more than its trunk cylinder (pi 0.11^2 0.75 * 0.5 m). */
    double vol = mesh_volume(m);
    AK_CHECK(vol > 0.014 && vol < 0.12);
    ak_vec3 lo, hi;
    ak_mesh_bounds(m, &lo, &hi);
    AK_CHECK(lo.y > -0.02f && lo.y < 0.03f);
    AK_CHECK(hi.y > 1.70f && hi.y < 1.90f);
    AK_CHECK_NEAR(lo.x + hi.x, 0.0, 0.02);
    AK_CHECK(hi.x > 0.5f && hi.x < 0.9f);

    /* Normals: unit, and agreeing with the geometric (area-weighted) normals. */
    ak_vec3* geo = (ak_vec3*)malloc(m->vertex_count * sizeof *geo);
    ak_normals_compute((ak_vec3_cspan){m->positions, m->vertex_count},
                       (ak_u32_cspan){m->indices, 3 * m->triangle_count},
                       (ak_vec3_span){geo, m->vertex_count});
    size_t disagree = 0, nonunit = 0;
    for (size_t v = 0; v < m->vertex_count; ++v) {
        if (fabsf(ak_vec3_length(m->normals[v]) - 1.0f) > 1e-4f) ++nonunit;
        if (ak_vec3_dot(m->normals[v], geo[v]) < 0.5f) ++disagree;
    }
    free(geo);
    AK_CHECK_EQ(nonunit, 0);
    AK_CHECK_MSG(disagree * 100 < m->vertex_count, "%zu of %zu normals disagree with the faces",
                 disagree, m->vertex_count);

    /* Left/right separation: no vertex clearly on one side is driven by the other side's limbs. */
    size_t crossed = 0;
    for (size_t v = 0; v < m->vertex_count; ++v) {
        float x = m->positions[v].x;
        for (uint32_t k = 0; k < m->influence_count; ++k) {
            if (m->weights[v * m->influence_count + k] <= 0.0f) continue;
            const char* nm =
                ak_skeleton_joint_name(s->skeleton, m->joints[v * m->influence_count + k]);
            if (x > 0.03f && strncmp(nm, "right_", 6) == 0) ++crossed;
            if (x < -0.03f && strncmp(nm, "left_", 5) == 0) ++crossed;
        }
    }
    AK_CHECK_EQ(crossed, 0);
    /* Vertices of the left hand follow the left wrist (dominant influence). */
    int lw = ak_skeleton_find_joint(s->skeleton, "left_wrist");
    size_t hand = 0, hand_ok = 0;
    for (size_t v = 0; v < m->vertex_count; ++v)
        if (m->positions[v].x > 0.64f) {
            ++hand;
            if (m->joints[v * m->influence_count] == lw) ++hand_ok;
        }
    AK_CHECK(hand > 10 && hand_ok == hand);

    /* Clips: a looping walk that really bends the knees, and a wave that lifts the right hand
     * above the shoulder. */
    int walk = ak_scene_find_clip(s, "walk"), wave = ak_scene_find_clip(s, "wave");
    AK_CHECK(walk >= 0 && wave >= 0);
    if (walk >= 0 && wave >= 0) {
        ak_transform* a = (ak_transform*)malloc(n * sizeof *a);
        ak_transform* b = (ak_transform*)malloc(n * sizeof *b);
        ak_mat4* world = (ak_mat4*)malloc(n * sizeof *world);
        float dur = ak_clip_duration(s->clips[walk]);
        AK_CHECK(sample(s, (size_t)walk, 0.0f, a, n) && sample(s, (size_t)walk, dur, b, n));
        double loop_err = 0.0;
        for (size_t j = 0; j < n; ++j) {
            loop_err = fmax(loop_err, ak_vec3_distance(a[j].translation, b[j].translation));
            loop_err = fmax(loop_err, 1.0 - fabs(ak_quat_dot(a[j].rotation, b[j].rotation)));
        }
        AK_CHECK(loop_err < 1e-5);
        int lk = ak_skeleton_find_joint(s->skeleton, "left_knee");
        float max_knee = 0.0f;
        for (int i = 0; i < 50; ++i) {
            sample(s, (size_t)walk, dur * (float)i / 49.0f, a, n);
            ak_vec3 axis;
            float ang;
            ak_quat_to_axis_angle(a[lk].rotation, &axis, &ang);
            max_knee = ak_maxf(max_knee, ang);
        }
        AK_CHECK(max_knee > 0.6f);
        int rw = ak_skeleton_find_joint(s->skeleton, "right_wrist"),
            rs = ak_skeleton_find_joint(s->skeleton, "right_shoulder");
        sample(s, (size_t)wave, 1.0f, a, n);
        ak_scene_world_matrices(s, (ak_transform_cspan){a, n}, (ak_mat4_span){world, n});
        AK_CHECK(world[rw].m[13] > world[rs].m[13] + 0.1f);
        AK_CHECK(world[rw].m[12] < 0.0f); /* the right hand stays on the right (-X) */
        free(a);
        free(b);
        free(world);
    }
    ak_scene_destroy(s);
}

AK_TEST(allocator_and_failures) {
    ak_test_counter c = {0};
    ak_allocator a = ak_test_counting_allocator(&c);
    ak_scene* s = NULL;
    AK_CHECK_EQ(ak_builtin_create("cylinder", NULL, &a, &s), AK_OK);
    AK_CHECK(c.live > 0);
    ak_scene_destroy(s);
    AK_CHECK_EQ(c.live, 0);
    /* Every allocation failing in turn: NO_MEMORY, nothing leaked, no crash. */
    const int total = c.total;
    int wrong = 0;
    for (int f = 0; f < total; ++f) {
        ak_test_counter cf = {.fail_from = f + 1};
        ak_allocator af = ak_test_counting_allocator(&cf);
        ak_result r = ak_builtin_create("cylinder", NULL, &af, &s);
        if (r != AK_ERR_NO_MEMORY || s != NULL || cf.live != 0) ++wrong;
    }
    AK_CHECK_EQ(wrong, 0);
    /* The humanoid: first, middle and last allocations. */
    ak_test_counter ch = {0};
    ak_allocator ah = ak_test_counting_allocator(&ch);
    ak_builtin_desc coarse = {.cell_size = 0.05f};
    AK_CHECK_EQ(ak_builtin_create("humanoid", &coarse, &ah, &s), AK_OK);
    ak_scene_destroy(s);
    AK_CHECK_EQ(ch.live, 0);
    int fails[3] = {0, ch.total / 2, ch.total - 1};
    for (int i = 0; i < 3; ++i) {
        ak_test_counter cf = {.fail_from = fails[i] + 1};
        ak_allocator af = ak_test_counting_allocator(&cf);
        AK_CHECK_EQ(ak_builtin_create("humanoid", &coarse, &af, &s), AK_ERR_NO_MEMORY);
        AK_CHECK(s == NULL);
        AK_CHECK_EQ(cf.live, 0);
    }
}

AK_TEST(humanoid_resolution) {
    /* Other grid spacings, down to the coarsest allowed, still give closed meshes with valid
     * weights (closedness is by construction, not luck). */
    const float cells[3] = {0.033f, 0.07f, 0.1f};
    for (int i = 0; i < 3; ++i) {
        ak_builtin_desc d = {.cell_size = cells[i]};
        ak_scene* s = NULL;
        AK_CHECK_EQ(ak_builtin_create("builtin:humanoid", &d, NULL, &s), AK_OK);
        if (!s) return;
        const ak_mesh* m = s->meshes[0].mesh;
        AK_CHECK(ak_mesh_is_closed_oriented(m));
        AK_CHECK_EQ(ak_mesh_validate_weights(m, ak_scene_joint_count(s), 1e-5f, NULL), AK_OK);
        AK_CHECK(mesh_volume(m) > 0.014);
        ak_scene_destroy(s);
    }
}

int main(void) {
    AK_RUN(names_and_errors);
    AK_RUN(cylinder_default);
    AK_RUN(cylinder_three_bones);
    AK_RUN(humanoid);
    AK_RUN(allocator_and_failures);
    AK_RUN(humanoid_resolution);
    return ak_test_finish();
}
