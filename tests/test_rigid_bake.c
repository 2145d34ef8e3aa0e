/* A rigid run baked as glTF node animation (ak_rigid_bake_scene, `animkit rigid -o OUT.glb`):
 * the meshes are the shapes (every sphere vertex at the radius, every capsule vertex at the
 * radius from its segment, box vertices at the half extents, every triangle facing outwards);
 * the clip, sampled at a frame's time, gives that frame's recorded pose and, halfway between
 * two frames, the midpoint of their positions (LINEAR) - also after a round trip through a
 * .glb file; bad input gets its code; the command writes a .glb of the stack preset (a node per
 * body) and of the ragdoll preset (builtin:humanoid's skeleton animated: its skinned mesh
 * starts a metre up and ends on the ground), and
 * (slow: node's start takes most of a second) the Khronos validator, when
 * build-tools/node_modules/gltf-validator and node exist (else SKIP), finds no error and no
 * warning in the files written here. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <animkit/animkit.h>

#include "ak_test.h"
#include "gltf_validate.h"
#include "cli_test.h"

static char g_tmp[1024];
static char g_written[8][1100];
static int g_written_count;

enum { NB = 5, NF = 12 };

/* A plane, a sphere, a box, a capsule and a static box; NF frames of a made-up motion (the
 * bake does not care how the poses came about). */
static ak_rigid_model* make_model(ak_vec3* x, ak_quat* q) {
    ak_rigid_body_desc b[NB] = {
        {.shape = {.type = AK_RIGID_PLANE}, .is_static = true},
        {.shape = {.type = AK_RIGID_SPHERE, .radius = 0.3f}, .position = {0, 2, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {0.5f, 0.25f, 0.125f}},
         .position = {2, 1, 0}},
        {.shape = {.type = AK_RIGID_CAPSULE, .radius = 0.2f, .half_height = 0.4f},
         .position = {-2, 1, 0}},
        {.shape = {.type = AK_RIGID_BOX, .half_extents = {1, 1, 1}},
         .position = {0, 1, 5},
         .is_static = true},
    };
    ak_rigid_model* m = NULL;
    ak_rigid_model_desc md = {.bodies = {b, NB}};
    if (ak_rigid_model_create(&md, NULL, &m) != AK_OK) return NULL;
    for (int k = 0; k < NF; ++k)
        for (int i = 0; i < NB; ++i) {
            float t = (float)k / 30.0f;
            x[k * NB + i] =
                ak_vec3_add(b[i].position, b[i].is_static || i == 0
                                               ? ak_vec3_zero()
                                               : ak_vec3_make(t, 3.0f * t - 4.9f * t * t, -t));
            q[k * NB + i] = b[i].is_static || i == 0
                                ? ak_quat_identity()
                                : ak_quat_from_axis_angle(ak_vec3_normalize(ak_vec3_make(1, 2, 3)),
                                                          4.0f * t * (float)i);
        }
    return m;
}

/* The scene's meshes against the shapes, and the clip against the recorded frames. */
static void check_scene(const ak_scene* s, const ak_rigid_model* m, const ak_vec3* x,
                        const ak_quat* q, const char* what) {
    AK_CHECK_EQ(ak_skeleton_joint_count(s->skeleton), (size_t)NB + 1);
    AK_CHECK_EQ(s->mesh_count, (size_t)NB);
    AK_CHECK_EQ(s->clip_count, (size_t)1);
    if (ak_skeleton_joint_count(s->skeleton) != NB + 1 || s->mesh_count != NB || s->clip_count != 1)
        return;
    float worst_shape = 0.0f;
    int inward = 0;
    for (size_t mi = 0; mi < s->mesh_count; ++mi) {
        const ak_mesh* mesh = s->meshes[mi].mesh;
        int node = s->meshes[mi].node;
        AK_CHECK(node >= 1 && node <= NB);
        if (node < 1 || node > NB) continue;
        ak_rigid_shape sh = ak_rigid_body_get_desc(m, (size_t)node - 1).shape;
        for (size_t v = 0; v < mesh->vertex_count; ++v) {
            ak_vec3 p = mesh->positions[v];
            float e = 0.0f;
            if (sh.type == AK_RIGID_SPHERE) e = fabsf(ak_vec3_length(p) - sh.radius);
            if (sh.type == AK_RIGID_CAPSULE) {
                ak_vec3 c = ak_vec3_make(0, ak_clampf(p.y, -sh.half_height, sh.half_height), 0);
                e = fabsf(ak_vec3_distance(p, c) - sh.radius);
            }
            if (sh.type == AK_RIGID_BOX)
                e = fabsf(fabsf(p.x) - sh.half_extents.x) + fabsf(fabsf(p.y) - sh.half_extents.y) +
                    fabsf(fabsf(p.z) - sh.half_extents.z);
            if (sh.type == AK_RIGID_PLANE) e = fabsf(p.y);
            worst_shape = ak_maxf(worst_shape, e);
        }
        /* every triangle faces away from the shape's centre (a plane's faces up) */
        for (size_t t = 0; t < mesh->triangle_count; ++t) {
            ak_vec3 a = mesh->positions[mesh->indices[3 * t]],
                    b = mesh->positions[mesh->indices[3 * t + 1]],
                    c = mesh->positions[mesh->indices[3 * t + 2]];
            ak_vec3 n = ak_vec3_cross(ak_vec3_sub(b, a), ak_vec3_sub(c, a));
            ak_vec3 mid = ak_vec3_scale(ak_vec3_add(ak_vec3_add(a, b), c), 1.0f / 3.0f);
            ak_vec3 out = sh.type == AK_RIGID_PLANE ? ak_vec3_make(0, 1, 0) : mid;
            if (sh.type == AK_RIGID_CAPSULE)
                out = ak_vec3_sub(
                    mid, ak_vec3_make(0, ak_clampf(mid.y, -sh.half_height, sh.half_height), 0));
            inward += !(ak_vec3_dot(n, out) > 0.0f);
        }
    }
    AK_CHECK_MSG(worst_shape < 1e-5f, "%s: a mesh vertex is %g m off its shape", what, worst_shape);
    AK_CHECK_MSG(inward == 0, "%s: %d triangles face inwards (or are degenerate)", what, inward);
    /* the clip: each frame's pose at its time, the midpoint halfway */
    const size_t n = NB + 1;
    ak_transform pose[NB + 1], pose2[NB + 1];
    float worst_x = 0.0f, worst_q = 0.0f, worst_mid = 0.0f;
    for (int k = 0; k < NF; ++k) {
        ak_scene_rest_pose(s, (ak_transform_span){pose, n});
        ak_clip_sample(s->clips[0], (float)k / 30.0f, NULL, (ak_transform_span){pose, n},
                       (ak_f32_span){0}, (ak_f32_span){0});
        for (int i = 1; i < NB; ++i) {
            worst_x = ak_maxf(worst_x, ak_vec3_distance(pose[i + 1].translation, x[k * NB + i]));
            worst_q = ak_maxf(worst_q, ak_quat_angle_between(pose[i + 1].rotation, q[k * NB + i]));
        }
        if (k + 1 < NF) {
            ak_scene_rest_pose(s, (ak_transform_span){pose2, n});
            ak_clip_sample(s->clips[0], ((float)k + 0.5f) / 30.0f, NULL,
                           (ak_transform_span){pose2, n}, (ak_f32_span){0}, (ak_f32_span){0});
            for (int i = 1; i < NB; ++i) {
                ak_vec3 mid = ak_vec3_scale(ak_vec3_add(x[k * NB + i], x[(k + 1) * NB + i]), 0.5f);
                worst_mid = ak_maxf(worst_mid, ak_vec3_distance(pose2[i + 1].translation, mid));
            }
        }
    }
    /* the static box sits where it was, without a channel */
    ak_transform_cspan rest = ak_skeleton_rest_pose(s->skeleton);
    AK_CHECK(ak_vec3_distance(rest.ptr[5].translation, ak_vec3_make(0, 1, 5)) < 1e-6f);
    AK_CHECK_MSG(worst_x < 1e-5f && worst_q < 1e-4f && worst_mid < 1e-5f,
                 "%s: clip vs frames: position %g m, rotation %g rad, midpoint %g m", what, worst_x,
                 worst_q, worst_mid);
}

AK_TEST(bake_nodes_match_shapes_and_frames) {
    ak_vec3 x[NF * NB];
    ak_quat q[NF * NB];
    ak_rigid_model* m = make_model(x, q);
    AK_CHECK(m != NULL);
    if (!m) return;
    ak_rigid_bake_desc d = {.name = "drop",
                            .model = m,
                            .frame_count = NF,
                            .positions = x,
                            .orientations = q,
                            .frame_time = 1.0f / 30.0f};
    ak_scene* s = NULL;
    ak_diag diag = {0};
    AK_CHECK_EQ(ak_rigid_bake_scene(&d, NULL, &s, &diag), AK_OK);
    if (s) {
        check_scene(s, m, x, q, "baked");
        char path[1100];
        snprintf(path, sizeof path, "%s/drop.glb", g_tmp);
        AK_CHECK_EQ(ak_io_save(path, s, NULL, &diag), AK_OK);
        snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", path);
        ak_scene* back = NULL;
        AK_CHECK_EQ(ak_io_load(path, NULL, NULL, &back, &diag), AK_OK);
        if (back) check_scene(back, m, x, q, "drop.glb read back");
        ak_scene_destroy(back);
    }
    ak_scene_destroy(s);

    /* bad input */
    ak_rigid_bake_desc bad = d;
    bad.frame_time = 0.0f;
    AK_CHECK_EQ(ak_rigid_bake_scene(&bad, NULL, &s, &diag), AK_ERR_BAD_ARG);
    AK_CHECK(s == NULL);
    bad = d;
    bad.frame_count = 0;
    AK_CHECK_EQ(ak_rigid_bake_scene(&bad, NULL, &s, &diag), AK_ERR_EMPTY);
    bad = d;
    bad.max_frames = NF - 1;
    AK_CHECK_EQ(ak_rigid_bake_scene(&bad, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    bad = d;
    bad.memory_budget = 1000;
    AK_CHECK_EQ(ak_rigid_bake_scene(&bad, NULL, &s, &diag), AK_ERR_UNSUPPORTED);
    bad = d;
    bad.orientations = NULL;
    AK_CHECK_EQ(ak_rigid_bake_scene(&bad, NULL, &s, &diag), AK_ERR_NULL_ARG);
    x[7 * NB + 3].y = NAN;
    AK_CHECK_EQ(ak_rigid_bake_scene(&d, NULL, &s, &diag), AK_ERR_BAD_DATA);
    AK_CHECK_MSG(strstr(diag.message, "frame 7 body 3") != NULL, "message: %s", diag.message);
    ak_rigid_model_destroy(m);
}

/* Lowest vertex (m) of the first skinned mesh of a scene posed by its first clip at time t. */
static float lowest_skinned(const ak_scene* s, float t) {
    const size_t n = ak_skeleton_joint_count(s->skeleton);
    float low = INFINITY;
    ak_transform* pose = malloc(n * sizeof *pose);
    ak_mat4* world = malloc(n * sizeof *world);
    for (size_t m = 0; pose && world && m < s->mesh_count; ++m) {
        const ak_mesh* mesh = s->meshes[m].mesh;
        if (s->meshes[m].skin < 0 || !mesh->influence_count) continue;
        const ak_scene_skin* skin = &s->skins[s->meshes[m].skin];
        ak_mat4* palette = malloc(skin->joint_count * sizeof *palette);
        ak_vec3* out = malloc(mesh->vertex_count * sizeof *out);
        ak_scene_rest_pose(s, (ak_transform_span){pose, n});
        ak_clip_sample(s->clips[0], t, NULL, (ak_transform_span){pose, n}, (ak_f32_span){0},
                       (ak_f32_span){0});
        ak_scene_world_matrices(s, (ak_transform_cspan){pose, n}, (ak_mat4_span){world, n});
        ak_scene_skin_palette(s, (size_t)s->meshes[m].skin, (ak_mat4_cspan){world, n},
                              (ak_mat4_span){palette, skin->joint_count});
        ak_skin_job job = {.influence_count = mesh->influence_count,
                           .palette = {palette, skin->joint_count},
                           .positions = {mesh->positions, mesh->vertex_count, 0},
                           .joints = {mesh->joints, mesh->vertex_count, 0},
                           .weights = {mesh->weights, mesh->vertex_count, 0},
                           .out_positions = {out, mesh->vertex_count, 0}};
        if (palette && out && ak_skin_job_run(&job) == AK_OK)
            for (size_t v = 0; v < mesh->vertex_count; ++v) low = ak_minf(low, out[v].y);
        free(palette), free(out);
        break;
    }
    free(pose), free(world);
    return low;
}

AK_TEST(cli_writes_node_animation) {
    char args[1400], path[1100];
    snprintf(path, sizeof path, "%s/stack.glb", g_tmp);
    snprintf(args, sizeof args, "rigid --preset stack --steps 10 -o '%s'", path);
    AK_CHECK_EQ(run(args, true), 0);
    AK_CHECK_MSG(strstr(out_buf, "one node per body") != NULL, "output: %s", out_buf);
    ak_scene* s = NULL;
    ak_diag diag = {0};
    AK_CHECK_EQ(ak_io_load(path, NULL, NULL, &s, &diag), AK_OK);
    if (s) {
        /* the ground and 10 boxes, a node each under the root; 11 frames */
        AK_CHECK_EQ(s->mesh_count, (size_t)11);
        AK_CHECK_EQ(ak_skeleton_joint_count(s->skeleton), (size_t)12);
        AK_CHECK_EQ(s->clip_count, (size_t)1);
        if (s->clip_count) AK_CHECK(fabsf(ak_clip_duration(s->clips[0]) - 10.0f / 60.0f) < 1e-5f);
        snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", path);
    }
    ak_scene_destroy(s);
}

/* The ragdoll preset: builtin:humanoid with the run as its skeleton's animation. Dropped from
 * 1 m, its skinned mesh starts about a metre up and ends on the ground (capsules fitted to
 * the skin hold it within 3 cm of it). */
AK_TEST(cli_writes_ragdoll_skeleton_animation) {
    char args[1400], path[1100];
    snprintf(path, sizeof path, "%s/ragdoll.glb", g_tmp);
    snprintf(args, sizeof args, "rigid --preset ragdoll --steps 60 -o '%s'", path);
    AK_CHECK_EQ(run(args, true), 0);
    AK_CHECK_MSG(strstr(out_buf, "skeleton animated") != NULL, "output: %s", out_buf);
    ak_scene* s = NULL;
    ak_diag diag = {0};
    AK_CHECK_EQ(ak_io_load(path, NULL, NULL, &s, &diag), AK_OK);
    if (s) {
        AK_CHECK(s->skin_count >= 1);
        AK_CHECK_EQ(s->clip_count, (size_t)1);
        if (s->clip_count && s->skin_count) {
            AK_CHECK(fabsf(ak_clip_duration(s->clips[0]) - 1.0f) < 1e-5f);
            float start = lowest_skinned(s, 0.0f), end = lowest_skinned(s, 1.0f);
            printf("  ragdoll.glb: lowest skinned vertex %.3f m at 0 s, %.3f m at 1 s\n",
                   (double)start, (double)end);
            AK_CHECK_MSG(start > 0.8f, "the character starts at %g m, not a metre up", start);
            AK_CHECK_MSG(end > -0.03f && end < 0.15f,
                         "the character ends at %g m, not on the ground", end);
        }
        snprintf(g_written[g_written_count++], sizeof g_written[0], "%s", path);
    }
    ak_scene_destroy(s);
}

AK_TEST(validator) {
    if (g_written_count == 0) { /* run alone (the slow selection): write the files first */
        ak_test_bake_nodes_match_shapes_and_frames();
        ak_test_cli_writes_node_animation();
        ak_test_cli_writes_ragdoll_skeleton_animation();
    }
    const char* names[sizeof g_written / sizeof g_written[0]];
    for (int i = 0; i < g_written_count; ++i) names[i] = g_written[i];
    ak_test_gltf_validate(names, g_written_count, "baked files");
}

int main(void) {
    snprintf(g_tmp, sizeof g_tmp, "%s/test_rigid_bake.XXXXXX",
             getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(g_tmp)) {
        printf("cannot create a temporary directory\n");
        return 1;
    }
    AK_RUN(bake_nodes_match_shapes_and_frames);
    AK_RUN(cli_writes_node_animation);
    AK_RUN_SLOW(cli_writes_ragdoll_skeleton_animation); /* 60 steps of 40 substeps */
    AK_RUN_SLOW(validator); /* node's start alone takes most of a second */
    for (int i = 0; i < g_written_count; ++i) remove(g_written[i]);
    rmdir(g_tmp);
    return ak_test_finish();
}
