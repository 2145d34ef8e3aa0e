/* scene_bake_cloth: simulate a flag with cloth.h, bake its frames into a morph-target
 * animation with ak_scene_bake_mesh_frames and write it as glTF 2.0 (scene_bake_cloth.glb,
 * playable in three.js, Blender, Godot); then read the file back and check the last frame. */
#include <animkit/animkit.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { W = 24, H = 15, FRAMES = 121 }; /* 4 s at 30 fps: two morph blocks of 64 frames */

int main(void) {
    ak_cloth_desc cd = {.grid_width = W, .grid_height = H, .spacing = 0.06f, .grid_axis_v = {0, -1, 0}};
    uint32_t pins[2] = {0, W * (H - 1)}; /* two corners of the pole edge */
    cd.pins = (ak_u32_cspan)AK_SPAN(pins);
    ak_cloth* cloth = NULL;
    if (ak_cloth_create(&cd, NULL, &cloth) != AK_OK) return 1;
    const size_t n = ak_cloth_vertex_count(cloth);
    ak_vec3* frames = malloc(FRAMES * n * sizeof *frames);
    ak_vec3* normals = malloc(FRAMES * n * sizeof *normals);
    ak_vec3* x = malloc(n * sizeof *x);
    ak_vec3* v = calloc(n, sizeof *v);
    if (!frames || !normals || !x || !v) return 1;
    ak_cloth_rest_positions(cloth, (ak_vec3_span){x, n});
    const float dt = 1.0f / 30.0f;
    ak_cloth_step_job job = {.cloth = cloth, .dt = dt, .gravity = {0, -9.81f, 0}, .wind = {6, 0, 1.5f},
                             .drag = 1.0f, .lift = 0.5f, .positions = {x, n}, .velocities = {v, n}};
    size_t scratch = ak_cloth_step_scratch_size(&job);
    job.scratch = (ak_u8_span){malloc(scratch), scratch};
    if (!job.scratch.ptr) return 1;
    for (int f = 0; f < FRAMES; ++f) {
        if (f > 0 && ak_cloth_step_run(&job) != AK_OK) return 1;
        memcpy(frames + (size_t)f * n, x, n * sizeof *x);
        ak_cloth_normals(cloth, (ak_vec3_cspan){x, n}, (ak_vec3_span){normals + (size_t)f * n, n});
    }

    /* frames -> scene (morph targets + weights clip) -> glTF */
    ak_scene_bake_mesh_desc bd = {.name = "flag", .vertex_count = n, .frame_count = FRAMES, .positions = frames,
                                  .normals = normals, .indices = ak_cloth_indices(cloth), .frame_time = dt,
                                  .base_color = {0.75f, 0.15f, 0.2f, 1}};
    ak_scene* scene = NULL;
    ak_diag diag;
    if (ak_scene_bake_mesh_frames(&bd, NULL, &scene, &diag) != AK_OK ||
        ak_io_save("scene_bake_cloth.glb", scene, NULL, &diag) != AK_OK) {
        fprintf(stderr, "%s\n", diag.message);
        return 1;
    }
    printf("wrote scene_bake_cloth.glb: %zu vertices, %d frames, %zu morph blocks, %.2f s\n", n, FRAMES,
           scene->mesh_count, (double)ak_clip_duration(scene->clips[0]));
    ak_scene_destroy(scene);

    /* read it back and show the last frame: the visible block's base + weighted targets */
    ak_scene* back = NULL;
    if (ak_io_load("scene_bake_cloth.glb", NULL, NULL, &back, &diag) != AK_OK) {
        fprintf(stderr, "%s\n", diag.message);
        return 1;
    }
    size_t nj = ak_scene_joint_count(back), nw = 0;
    for (size_t m = 0; m < back->mesh_count; ++m) nw += back->meshes[m].mesh->morph_target_count;
    ak_transform* local = malloc(nj * sizeof *local);
    ak_mat4* world = malloc(nj * sizeof *world);
    float* weights = calloc(nw, sizeof *weights);
    if (!local || !world || !weights) return 1;
    float t = ak_clip_duration(back->clips[0]);
    ak_scene_rest_pose(back, (ak_transform_span){local, nj});
    ak_clip_sample(back->clips[0], t, NULL, (ak_transform_span){local, nj}, (ak_f32_span){weights, nw},
                   (ak_f32_span){0});
    ak_scene_world_matrices(back, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
    double worst = 0.0;
    size_t base = 0;
    for (size_t m = 0; m < back->mesh_count; ++m) {
        const ak_mesh* mesh = back->meshes[m].mesh;
        const ak_mat4 w = world[back->meshes[m].node];
        if (fabsf(w.m[0]) > 0.5f) /* the visible block (the others are scaled to 0) */
            for (size_t i = 0; i < n; ++i) {
                ak_vec3 p = mesh->positions[i];
                for (size_t k = 0; k < mesh->morph_target_count; ++k)
                    p = ak_vec3_add(p, ak_vec3_scale(mesh->morph_positions[k * n + i], weights[base + k]));
                p = ak_mat4_transform_point(w, p);
                worst = fmax(worst, (double)ak_vec3_length(ak_vec3_sub(p, x[i])));
            }
        base += mesh->morph_target_count;
    }
    printf("read back: last frame at t = %.3f s differs from the simulation by %.2g m at most\n", (double)t, worst);
    ak_scene_destroy(back);
    free(local), free(world), free(weights), free(job.scratch.ptr), free(frames), free(normals), free(x), free(v);
    ak_cloth_destroy(cloth);
    return worst < 1e-5 ? 0 : 1;
}
