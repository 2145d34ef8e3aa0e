/* The palette path of skin.h's usage note on loaded glTF scenes: it must give the vertices
 * `animkit export` writes (the CLI's own pipeline, read back from its OBJ text), and the
 * skeleton-indexed palette (ak_skeleton_skinning_matrices), which skins a loaded mesh wrong,
 * must be refused there while builtin scenes keep it. */
#include <animkit/animkit.h>

#include <sys/wait.h>

#include "ak_test.h"

#ifndef AK_CLI_PATH
#error "AK_CLI_PATH must name the animkit executable"
#endif

/* Every "v x y z" line of an OBJ file, in order; the count read, or 0 on failure. */
static size_t read_obj_vertices(const char* path, ak_vec3* out, size_t cap) {
    FILE* f = fopen(path, "r");
    if (!f) return 0;
    char line[512];
    size_t n = 0;
    while (fgets(line, sizeof line, f) && n < cap) {
        float x, y, z;
        if (line[0] == 'v' && line[1] == ' ' && sscanf(line + 2, "%f %f %f", &x, &y, &z) == 3) out[n++] = ak_vec3_make(x, y, z);
    }
    fclose(f);
    return n;
}

/* skin.h's note, call for call: rest pose, clip 0 at t, world matrices, the mesh's skin's
 * palette, an LBS skin job. out gets the mesh's vertex count positions. */
static ak_result skin_as_the_note_says(const ak_scene* scene, size_t m, float t, ak_vec3* out) {
    const ak_scene_mesh* sm = &scene->meshes[m];
    const ak_mesh* mesh = sm->mesh;
    const size_t nodes = ak_scene_joint_count(scene), slots = scene->skins[sm->skin].joint_count, n = mesh->vertex_count;
    ak_transform* local = malloc(nodes * sizeof *local);
    ak_mat4* world = malloc(nodes * sizeof *world);
    ak_mat4* palette = malloc(slots * sizeof *palette);
    ak_result r = local && world && palette ? AK_OK : AK_ERR_NO_MEMORY;
    if (r == AK_OK) r = ak_scene_rest_pose(scene, (ak_transform_span){local, nodes});
    if (r == AK_OK && scene->clip_count)
        r = ak_clip_sample(scene->clips[0], t, NULL, (ak_transform_span){local, nodes}, (ak_f32_span){NULL, 0},
                           (ak_f32_span){NULL, 0});
    if (r == AK_OK) r = ak_scene_world_matrices(scene, (ak_transform_cspan){local, nodes}, (ak_mat4_span){world, nodes});
    if (r == AK_OK)
        r = ak_scene_skin_palette(scene, (size_t)sm->skin, (ak_mat4_cspan){world, nodes}, (ak_mat4_span){palette, slots});
    if (r == AK_OK) {
        ak_skin_job job = {
            .influence_count = mesh->influence_count,
            .palette = {palette, slots},
            .positions = {mesh->positions, n, 0},
            .joints = {mesh->joints, n, 0},
            .weights = {mesh->weights, n, 0},
            .out_positions = {out, n, 0},
        };
        r = ak_skin_job_run(&job);
    }
    /* the skeleton-indexed palette is refused on a loaded scene */
    if (r == AK_OK) {
        ak_result wrong =
            ak_skeleton_skinning_matrices(scene->skeleton, (ak_mat4_cspan){world, nodes}, (ak_mat4_span){world, nodes});
        AK_CHECK_MSG(wrong == AK_ERR_UNSUPPORTED, "ak_skeleton_skinning_matrices on a loaded scene gave %s",
                     ak_result_string(wrong));
    }
    free(local);
    free(world);
    free(palette);
    return r;
}

AK_TEST(note_palette_matches_export) {
    static const char* const files[] = {"CesiumMan/glTF-Binary/CesiumMan.glb", "RiggedSimple/glTF/RiggedSimple.gltf",
                                        "RiggedFigure/glTF-Binary/RiggedFigure.glb", "Fox/glTF-Binary/Fox.glb",
                                        "SimpleSkin/glTF/SimpleSkin.gltf"};
    static ak_vec3 obj[200000], mine[200000];
    int compared = 0;
    for (size_t fi = 0; fi < sizeof files / sizeof files[0]; ++fi) {
        char rel[256], path[1400], args[1800];
        snprintf(rel, sizeof rel, "gltf/%s", files[fi]);
        if (!ak_test_asset(path, sizeof path, rel)) continue;
        ak_scene* scene = NULL;
        AK_CHECK_EQ(ak_io_load(path, NULL, NULL, &scene, NULL), AK_OK);
        if (!scene) continue;
        const float t = 0.5f;
        snprintf(args, sizeof args, "%s export '%s' --time 0.5 -o palette_check.obj >/dev/null 2>&1", AK_CLI_PATH, path);
        int st = system(args);
        AK_CHECK_MSG(WIFEXITED(st) && WEXITSTATUS(st) == 0, "%s: export failed", files[fi]);
        size_t got = read_obj_vertices("palette_check.obj", obj, sizeof obj / sizeof obj[0]);
        size_t off = 0;
        for (size_t m = 0; m < scene->mesh_count; ++m) {
            const ak_scene_mesh* sm = &scene->meshes[m];
            const size_t n = sm->mesh ? sm->mesh->vertex_count : 0;
            const bool plain_skin = sm->skin >= 0 && sm->mesh && sm->mesh->influence_count > 0 &&
                                    sm->mesh->morph_target_count == 0 && n <= sizeof mine / sizeof mine[0];
            if (plain_skin && off + n <= got) {
                AK_CHECK_EQ(skin_as_the_note_says(scene, m, t, mine), AK_OK);
                double worst = 0;
                for (size_t v = 0; v < n; ++v) worst = fmax(worst, (double)ak_vec3_distance(mine[v], obj[off + v]));
                AK_CHECK_MSG(worst <= 1e-5, "%s mesh %zu: the note's vertices differ from export's by %g", files[fi], m,
                             worst);
                ++compared;
                if (fi == 0 && m == 0) {
                    /* the numbers for CesiumMan's first vertex at t = 0.5 */
                    AK_CHECK_NEAR(mine[0].x, 0.0165, 5e-4);
                    AK_CHECK_NEAR(mine[0].y, 0.962, 5e-4);
                    AK_CHECK_NEAR(mine[0].z, 0.104, 1e-3);
                }
            }
            off += n;
        }
        AK_CHECK_MSG(off == got, "%s: export wrote %zu vertices, the scene has %zu", files[fi], got, off);
        ak_scene_destroy(scene);
    }
    if (compared == 0) AK_SKIP("no skinned glTF assets (set ANIMKIT_ASSETS)");
    else printf("  %d skinned meshes: the note's palette path gives export's vertices\n", compared);
}

/* Builtin scenes index their meshes by skeleton joint (skin slot k is joint k): the
 * skeleton palette stays available there and equals the skin's palette. */
AK_TEST(builtin_keeps_skeleton_palette) {
    ak_scene* scene = NULL;
    AK_CHECK_EQ(ak_builtin_create("humanoid", NULL, NULL, &scene), AK_OK);
    if (!scene) return;
    const size_t n = ak_scene_joint_count(scene);
    AK_CHECK(!ak_skeleton_palette_from_skins(scene->skeleton));
    ak_transform local[64];
    ak_mat4 world[64], a[64], b[64];
    AK_CHECK(n <= 64 && scene->skin_count == 1 && scene->skins[0].joint_count == n);
    if (n > 64) return;
    ak_scene_rest_pose(scene, (ak_transform_span){local, n});
    local[3].rotation = ak_quat_from_axis_angle(ak_vec3_make(0, 0, 1), 0.7f);
    ak_scene_world_matrices(scene, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
    AK_CHECK_EQ(ak_skeleton_skinning_matrices(scene->skeleton, (ak_mat4_cspan){world, n}, (ak_mat4_span){a, n}), AK_OK);
    AK_CHECK_EQ(ak_scene_skin_palette(scene, 0, (ak_mat4_cspan){world, n}, (ak_mat4_span){b, n}), AK_OK);
    double worst = 0;
    for (size_t j = 0; j < n; ++j)
        for (int k = 0; k < 16; ++k) worst = fmax(worst, fabs((double)a[j].m[k] - b[j].m[k]));
    AK_CHECK_NEAR(worst, 0.0, 1e-6);
    ak_scene_destroy(scene);

    /* the flag itself: refused, nothing written */
    ak_joint_desc j[2] = {{.name = "a", .parent = -1, .rest = ak_transform_identity()},
                          {.name = "b", .parent = 0, .rest = ak_transform_identity()}};
    ak_skeleton_desc d = {.joints = j, .joint_count = 2, .palette_from_skins = true};
    ak_skeleton* sk = NULL;
    AK_CHECK_EQ(ak_skeleton_create(&d, NULL, &sk, NULL), AK_OK);
    if (!sk) return;
    AK_CHECK(ak_skeleton_palette_from_skins(sk));
    ak_mat4 m[2] = {ak_mat4_identity(), ak_mat4_identity()}, out[2];
    memset(out, 0x5a, sizeof out);
    AK_CHECK_EQ(ak_skeleton_skinning_matrices(sk, (ak_mat4_cspan)AK_SPAN(m), (ak_mat4_span)AK_SPAN(out)), AK_ERR_UNSUPPORTED);
    unsigned char pattern[sizeof out];
    memset(pattern, 0x5a, sizeof pattern);
    AK_CHECK(memcmp(out, pattern, sizeof out) == 0);
    ak_skeleton_destroy(sk);
}

int main(void) {
    AK_RUN(note_palette_matches_export);
    AK_RUN(builtin_keeps_skeleton_palette);
    return ak_test_finish();
}
