/* Tests for scene.h on a small hand-built scene: allocation and ownership, clip lookup,
 * rest pose, world matrices, skin palettes and bounds, each against values computed by hand
 * here (rotations by 90 degrees, so the expected matrices are exact). */
#include <animkit/scene.h>

#include "ak_test.h"


static bool near3(ak_vec3 a, float x, float y, float z, float tol) {
    return fabsf(a.x - x) <= tol && fabsf(a.y - y) <= tol && fabsf(a.z - z) <= tol;
}

static ak_clip* make_clip(const char* name, uint32_t joint, const ak_allocator* alloc) {
    static const float times[2] = {0.0f, 1.0f};
    static const float values[8] = {0, 0, 0, 1, 0, 0, 0.70710678f, 0.70710678f};
    ak_raw_channel ch = {.target = AK_CHANNEL_ROTATION,
                         .index = joint,
                         .key_count = 2,
                         .times = times,
                         .values = values};
    ak_raw_clip raw = {.name = name, .channels = &ch, .channel_count = 1, .joint_count = 3};
    ak_clip* c = NULL;
    ak_clip_build(&raw, alloc, &c, NULL);
    return c;
}

/* root at (1,0,0); "arm" 2 up, turned 90 degrees about +Z; "hand" 1 along the arm's +X.
 * Rest world positions: root (1,0,0), arm (1,2,0), hand (1,3,0). Two meshes: a skinned
 * triangle on skin 0 (slots -> joints 2 and 0) and an unskinned one carried by "hand". */
static ak_scene* make_scene(const ak_allocator* alloc) {
    ak_scene* s = NULL;
    if (ak_scene_alloc(2, 1, 3, alloc, &s) != AK_OK) return NULL;
    snprintf(s->name, sizeof s->name, "hand-built");
    ak_joint_desc js[3] = {
        {.name = "root", .parent = -1, .rest = {{1, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}},
        {.name = "arm",
         .parent = 0,
         .rest = {{0, 2, 0}, {0, 0, 0.70710678f, 0.70710678f}, {1, 1, 1}}},
        {.name = "hand", .parent = 1, .rest = {{1, 0, 0}, {0, 0, 0, 1}, {1, 1, 1}}},
    };
    ak_skeleton_desc sd = {.joints = js, .joint_count = 3};
    ak_skeleton_create(&sd, &s->alloc, &s->skeleton, NULL);
    ak_scene_skin_alloc(s, 0, 2);
    s->skins[0].joints[0] = 2;
    s->skins[0].joints[1] = 0;
    ak_mesh_desc md = {.vertex_count = 3, .triangle_count = 1, .influence_count = 1};
    for (int m = 0; m < 2; ++m) {
        ak_mesh_create(&md, &s->alloc, &s->meshes[m].mesh);
        ak_mesh* mesh = s->meshes[m].mesh;
        if (!mesh) continue;
        mesh->positions[0] = ak_vec3_make(0, 0, 0);
        mesh->positions[1] = ak_vec3_make(0.5f, 0, 0);
        mesh->positions[2] = ak_vec3_make(0, 0.5f, -1);
        mesh->indices[0] = 0, mesh->indices[1] = 1, mesh->indices[2] = 2;
        for (int v = 0; v < 3; ++v) mesh->weights[v] = 1.0f;
    }
    s->meshes[0].skin = 0;
    s->meshes[1].node = 2;
    s->clips[0] = make_clip("idle", 1, &s->alloc);
    s->clips[1] = make_clip("run", 2, &s->alloc);
    s->clips[2] = make_clip("1", 0, &s->alloc); /* a name that looks like an index */
    return s;
}

AK_TEST(alloc_and_destroy) {
    ak_test_counter c = {0};
    ak_allocator a = ak_test_counting_allocator(&c);
    ak_scene* s = make_scene(&a);
    AK_CHECK(s != NULL);
    if (!s) return;
    AK_CHECK(s->skeleton && s->meshes[0].mesh && s->meshes[1].mesh && s->clips[0] && s->clips[2]);
    AK_CHECK_EQ(s->mesh_count, 2);
    AK_CHECK_EQ(s->skin_count, 1);
    AK_CHECK_EQ(s->clip_count, 3);
    AK_CHECK_EQ(s->meshes[0].node, -1);
    AK_CHECK_EQ(s->meshes[1].skin, -1);
    AK_CHECK(s->is_joint == NULL);
    AK_CHECK_EQ(ak_scene_joint_count(s), 3);
    /* The fresh skin slots have identity inverse binds. */
    for (int e = 0; e < 16; ++e)
        AK_CHECK(s->skins[0].inverse_binds[1].m[e] == ((e % 5 == 0) ? 1.0f : 0.0f));
    AK_CHECK_EQ(ak_scene_skin_alloc(s, 1, 4), AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_scene_skin_alloc(NULL, 0, 4), AK_ERR_NULL_ARG);
    ak_scene_destroy(s);
    AK_CHECK_EQ(c.live, 0); /* everything the scene owns went back through its allocator */
    ak_scene_destroy(NULL);
    AK_CHECK_EQ(ak_scene_joint_count(NULL), 0);

    AK_CHECK_EQ(ak_scene_alloc(1, 1, 1, NULL, NULL), AK_ERR_NULL_ARG);
    for (int f = 0; f < 4; ++f) {
        ak_test_counter cf = {.fail_from = f + 1};
        ak_allocator af = ak_test_counting_allocator(&cf);
        ak_scene* t = (ak_scene*)1;
        AK_CHECK_EQ(ak_scene_alloc(2, 2, 2, &af, &t), AK_ERR_NO_MEMORY);
        AK_CHECK(t == NULL);
        AK_CHECK_EQ(cf.live, 0);
    }
    ak_scene* empty = NULL;
    AK_CHECK_EQ(ak_scene_alloc(0, 0, 0, NULL, &empty), AK_OK);
    AK_CHECK(empty && empty->meshes == NULL && empty->clips == NULL);
    ak_scene_destroy(empty);
}

AK_TEST(find_clip) {
    ak_scene* s = make_scene(NULL);
    if (!s) {
        AK_CHECK(s != NULL);
        return;
    }
    AK_CHECK_EQ(ak_scene_find_clip(s, "idle"), 0);
    AK_CHECK_EQ(ak_scene_find_clip(s, "run"), 1);
    AK_CHECK_EQ(ak_scene_find_clip(s, "1"), 2); /* a name beats an index */
    AK_CHECK_EQ(ak_scene_find_clip(s, "0"), 0);
    AK_CHECK_EQ(ak_scene_find_clip(s, "2"), 2);
    AK_CHECK_EQ(ak_scene_find_clip(s, "3"), -1);
    AK_CHECK_EQ(ak_scene_find_clip(s, "walk"), -1);
    AK_CHECK_EQ(ak_scene_find_clip(s, "-1"), -1);
    AK_CHECK_EQ(ak_scene_find_clip(s, "99999999999999999999"), -1);
    AK_CHECK_EQ(ak_scene_find_clip(s, ""), 0);
    AK_CHECK_EQ(ak_scene_find_clip(s, NULL), 0);
    AK_CHECK_EQ(ak_scene_find_clip(NULL, "idle"), -1);
    ak_scene_destroy(s);
    ak_scene* none = NULL;
    ak_scene_alloc(0, 0, 0, NULL, &none);
    AK_CHECK_EQ(ak_scene_find_clip(none, NULL), -1);
    AK_CHECK_EQ(ak_scene_find_clip(none, "0"), -1);
    ak_scene_destroy(none);
}

AK_TEST(rest_world_palette) {
    ak_scene* s = make_scene(NULL);
    if (!s) {
        AK_CHECK(s != NULL);
        return;
    }
    ak_transform local[4];
    AK_CHECK_EQ(ak_scene_rest_pose(s, (ak_transform_span){local, 4}), AK_OK);
    AK_CHECK(near3(local[1].translation, 0, 2, 0, 0.0f));
    AK_CHECK_EQ(ak_scene_rest_pose(s, (ak_transform_span){local, 2}), AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_scene_rest_pose(NULL, (ak_transform_span){local, 4}), AK_ERR_NULL_ARG);

    ak_mat4 world[3];
    AK_CHECK_EQ(
        ak_scene_world_matrices(s, (ak_transform_cspan){local, 3}, (ak_mat4_span){world, 3}),
        AK_OK);
    AK_CHECK(near3(ak_mat4_get_translation(world[0]), 1, 0, 0, 1e-6f));
    AK_CHECK(near3(ak_mat4_get_translation(world[1]), 1, 2, 0, 1e-6f));
    /* The arm is turned 90 degrees about Z: its +X is world +Y, so the hand is 1 above. */
    AK_CHECK(near3(ak_mat4_get_translation(world[2]), 1, 3, 0, 1e-6f));
    AK_CHECK_EQ(
        ak_scene_world_matrices(s, (ak_transform_cspan){local, 2}, (ak_mat4_span){world, 3}),
        AK_ERR_SPAN_SMALL);

    /* Palette with identity inverse binds = the slots' world matrices (slot 0 -> hand). */
    ak_mat4 pal[2];
    AK_CHECK_EQ(ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, 3}, (ak_mat4_span){pal, 2}),
                AK_OK);
    AK_CHECK(memcmp(&pal[0], &world[2], sizeof(ak_mat4)) == 0);
    AK_CHECK(memcmp(&pal[1], &world[0], sizeof(ak_mat4)) == 0);
    /* With real inverse binds, the bind pose gives identity palettes. */
    ak_mat4_cspan ib = ak_skeleton_inverse_binds(s->skeleton);
    s->skins[0].inverse_binds[0] = ib.ptr[2];
    s->skins[0].inverse_binds[1] = ib.ptr[0];
    ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, 3}, (ak_mat4_span){pal, 2});
    for (int k = 0; k < 2; ++k)
        for (int e = 0; e < 16; ++e) AK_CHECK_NEAR(pal[k].m[e], (e % 5 == 0) ? 1.0 : 0.0, 1e-6);
    /* A clip sample moves the hand: at t = 0 "idle" gives the arm the identity rotation
     * (instead of its 90-degree rest turn), so the hand sits 1 along +X: (2,2,0). */
    AK_CHECK_EQ(ak_clip_sample(s->clips[0], 0.0f, NULL, (ak_transform_span){local, 3},
                               (ak_f32_span){NULL, 0}, (ak_f32_span){NULL, 0}),
                AK_OK);
    ak_scene_world_matrices(s, (ak_transform_cspan){local, 3}, (ak_mat4_span){world, 3});
    AK_CHECK(near3(ak_mat4_get_translation(world[2]), 2, 2, 0, 1e-5f));

    AK_CHECK_EQ(ak_scene_skin_palette(s, 1, (ak_mat4_cspan){world, 3}, (ak_mat4_span){pal, 2}),
                AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, 3}, (ak_mat4_span){pal, 1}),
                AK_ERR_SPAN_SMALL);
    AK_CHECK_EQ(ak_scene_skin_palette(s, 0, (ak_mat4_cspan){world, 2}, (ak_mat4_span){pal, 2}),
                AK_ERR_BAD_INDEX);
    AK_CHECK_EQ(ak_scene_skin_palette(NULL, 0, (ak_mat4_cspan){world, 3}, (ak_mat4_span){pal, 2}),
                AK_ERR_NULL_ARG);
    ak_scene_destroy(s);
}

AK_TEST(bounds) {
    ak_scene* s = make_scene(NULL);
    if (!s) {
        AK_CHECK(s != NULL);
        return;
    }
    /* Skinned mesh as given: [0,0.5]x[0,0.5]x[-1,0]. Unskinned mesh on "hand" (world: turned
     * 90 degrees about Z, at (1,3,0)): local x -> world y, local y -> world -x, so its points
     * are (1,3,0), (1,3.5,0), (0.5,3,-1). */
    ak_vec3 lo, hi;
    ak_scene_bounds(s, &lo, &hi);
    AK_CHECK(near3(lo, 0, 0, -1, 1e-6f));
    AK_CHECK(near3(hi, 1, 3.5f, 0, 1e-6f));
    /* Without meshes the joints' rest positions bound the scene. */
    ak_mesh_destroy(s->meshes[0].mesh);
    ak_mesh_destroy(s->meshes[1].mesh);
    s->meshes[0].mesh = s->meshes[1].mesh = NULL;
    ak_scene_bounds(s, &lo, &hi);
    AK_CHECK(near3(lo, 1, 0, 0, 1e-6f));
    AK_CHECK(near3(hi, 1, 3, 0, 1e-6f));
    ak_scene_destroy(s);
    ak_scene_bounds(NULL, &lo, &hi);
    AK_CHECK(near3(lo, 0, 0, 0, 0.0f) && near3(hi, 0, 0, 0, 0.0f));
}

int main(void) {
    AK_RUN(alloc_and_destroy);
    AK_RUN(find_clip);
    AK_RUN(rest_world_palette);
    AK_RUN(bounds);
    return ak_test_finish();
}
