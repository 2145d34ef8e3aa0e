/* scene_pose: the whole runtime path on one character, with public headers only.
 * Load a model (argv[1], or builtin:humanoid), sample a clip with a cursor, run forward
 * kinematics, build the skinning palette, skin with LBS and DQS, and print what moved. */
#include <animkit/animkit.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char** argv) {
    const char* spec = argc > 1 ? argv[1] : "builtin:humanoid";
    ak_scene* scene = NULL;
    ak_diag diag = {0};
    ak_result r = strncmp(spec, "builtin:", 8) == 0 ? ak_builtin_create(spec, NULL, NULL, &scene)
                                                    : ak_io_load(spec, NULL, NULL, &scene, &diag);
    if (r != AK_OK) {
        fprintf(stderr, "%s: %s\n", spec, diag.message[0] ? diag.message : ak_result_string(r));
        return 1;
    }
    if (scene->clip_count == 0 || scene->mesh_count == 0 || scene->meshes[0].skin < 0) {
        printf("%s: no clip or no skinned mesh to pose\n", spec);
        ak_scene_destroy(scene);
        return 0;
    }
    const ak_clip* clip = scene->clips[0];
    const ak_scene_mesh* sm = &scene->meshes[0];
    const ak_mesh* mesh = sm->mesh;
    const ak_scene_skin* skin = &scene->skins[sm->skin];
    size_t n = ak_scene_joint_count(scene), v = mesh->vertex_count;

    /* caller-owned memory: the library allocates nothing per frame */
    ak_transform* local = malloc(n * sizeof *local);
    ak_mat4* world = malloc(n * sizeof *world);
    ak_mat4* palette = malloc(skin->joint_count * sizeof *palette);
    ak_vec3* lbs = malloc(v * sizeof *lbs);
    ak_vec3* dqs = malloc(v * sizeof *dqs);
    uint32_t* cursor_storage = calloc(ak_clip_cursor_storage_count(clip) + 1, sizeof(uint32_t));
    ak_skin_job job = {.method = AK_SKIN_DQS, .palette = {palette, skin->joint_count}};
    size_t scratch_size = ak_skin_job_scratch_size(&job);
    uint8_t* scratch = malloc(scratch_size);
    ak_clip_cursor cursor;
    ak_clip_cursor_init(&cursor, clip, (ak_u32_span){cursor_storage, ak_clip_cursor_storage_count(clip)});

    printf("%s: clip '%s' (%.3f s), %zu joints, mesh '%s' with %zu vertices\n", scene->name, ak_clip_name(clip),
           (double)ak_clip_duration(clip), n, mesh->name, v);
    printf("%8s %14s %14s %14s\n", "time", "max |lbs-rest|", "max |dqs-lbs|", "volume lbs/dqs");
    float duration = ak_clip_duration(clip);
    for (int frame = 0; frame <= 8; ++frame) {
        float t = duration * (float)frame / 8.0f;
        /* 1. pose: rest pose, then the clip's channels on top */
        ak_scene_rest_pose(scene, (ak_transform_span){local, n});
        ak_clip_sample(clip, t, &cursor, (ak_transform_span){local, n}, (ak_f32_span){0}, (ak_f32_span){0});
        /* 2. forward kinematics and the palette M_j = world_j * inverse_bind_j */
        ak_scene_world_matrices(scene, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
        ak_scene_skin_palette(scene, (size_t)sm->skin, (ak_mat4_cspan){world, n},
                              (ak_mat4_span){palette, skin->joint_count});
        /* 3. skin the same vertices twice: linear blend and dual quaternions */
        for (int method = 0; method < 2; ++method) {
            ak_skin_job j = {
                .method = method ? AK_SKIN_DQS : AK_SKIN_LBS,
                .influence_count = mesh->influence_count,
                .palette = {palette, skin->joint_count},
                .positions = {mesh->positions, v, 0},
                .joints = {mesh->joints, v, mesh->influence_count * sizeof(uint16_t)},
                .weights = {mesh->weights, v, mesh->influence_count * sizeof(float)},
                .scratch = {scratch, scratch_size},
                .out_positions = {method ? dqs : lbs, v, 0},
            };
            if ((r = ak_skin_job_run(&j)) != AK_OK) {
                fprintf(stderr, "skinning failed: %s\n", ak_result_string(r));
                return 1;
            }
        }
        float moved = 0.0f, differ = 0.0f;
        for (size_t i = 0; i < v; ++i) {
            moved = ak_maxf(moved, ak_vec3_distance(lbs[i], mesh->positions[i]));
            differ = ak_maxf(differ, ak_vec3_distance(lbs[i], dqs[i]));
        }
        ak_u32_cspan tris = {mesh->indices, mesh->triangle_count * 3};
        double vol = ak_volume_compute((ak_vec3_cspan){lbs, v}, tris) / ak_volume_compute((ak_vec3_cspan){dqs, v}, tris);
        printf("%8.3f %14.5f %14.5f %14.4f\n", (double)t, (double)moved, (double)differ, vol);
    }
    free(local), free(world), free(palette), free(lbs), free(dqs), free(cursor_storage), free(scratch);
    ak_scene_destroy(scene);
    return 0;
}
