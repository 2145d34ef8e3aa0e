/* noise_idle_sway: procedural idle motion. The built-in humanoid stands in its rest pose; a
 * noise sway layer (per-joint amplitude and frequency) breathes and sways it. Writes
 * noise_idle_sway.gif (3 s at 12 fps) and prints how far the head is from its rest position. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/animkit.h>

enum { FRAMES = 36, W = 240, H = 320 };

int main(void) {
    ak_scene* scene = NULL;
    if (ak_builtin_create("builtin:humanoid", NULL, NULL, &scene) != AK_OK) return 1;
    const ak_scene_mesh* sm = &scene->meshes[0];
    const ak_mesh* mesh = sm->mesh;
    const ak_scene_skin* skin = &scene->skins[sm->skin];
    const size_t n = ak_scene_joint_count(scene), v = mesh->vertex_count;
    ak_transform *rest = malloc(n * sizeof *rest), *local = malloc(n * sizeof *local);
    ak_mat4 *world = malloc(n * sizeof *world), *palette = malloc(skin->joint_count * sizeof *palette);
    float *amp = calloc(n, sizeof *amp), *freq = calloc(n, sizeof *freq);
    ak_vec3* pos = malloc(v * sizeof *pos);
    uint8_t* px = malloc((size_t)W * H * 4 * FRAMES);
    ak_image* frames = malloc(FRAMES * sizeof *frames);
    ak_raster* r = NULL;
    if (!rest || !local || !world || !palette || !amp || !freq || !pos || !px || !frames ||
        ak_raster_create(&(ak_raster_desc){.width = W, .height = H, .supersample = 2}, NULL, &r) != AK_OK)
        return 1;
    ak_scene_rest_pose(scene, (ak_transform_span){rest, n});

    /* the layer: small, slow turns for the trunk, a livelier head, drifting arms */
    int head = -1;
    for (size_t j = 0; j < n; ++j) {
        const char* name = ak_skeleton_joint_name(scene->skeleton, j);
        if (!name) continue;
        if (strcmp(name, "pelvis") == 0) amp[j] = 0.04f, freq[j] = 0.4f;
        if (strstr(name, "spine") || strcmp(name, "neck") == 0) amp[j] = 0.06f, freq[j] = 0.5f;
        if (strcmp(name, "head") == 0) amp[j] = 0.15f, freq[j] = 0.7f, head = (int)j;
        if (strstr(name, "shoulder")) amp[j] = 0.12f, freq[j] = 0.5f;
        if (strstr(name, "elbow")) amp[j] = 0.1f, freq[j] = 0.6f;
    }
    const ak_noise noise = ak_noise_make(42);
    ak_vec3 lo, hi;
    ak_scene_bounds(scene, &lo, &hi);
    const ak_raster_camera cam =
        ak_view_orbit_camera(lo, hi, &(ak_view_orbit){.azimuth = 0.5f, .elevation = 0.15f, .aspect = (float)W / H});
    ak_vec3 head_rest = {0, 0, 0};
    if (head >= 0) {
        ak_scene_world_matrices(scene, (ak_transform_cspan){rest, n}, (ak_mat4_span){world, n});
        head_rest = ak_vec3_make(world[head].m[12], world[head].m[13], world[head].m[14]);
    }
    printf("time s  head from rest (mm)\n");
    for (int f = 0; f < FRAMES; ++f) {
        ak_noise_sway_job job = {.noise = &noise, .time = (float)f / 12.0f, .pose = {rest, n},
                                 .amplitudes = {amp, n}, .frequencies = {freq, n}, .out_pose = {local, n}};
        if (ak_noise_sway_run(&job) != AK_OK) return 1;
        ak_scene_world_matrices(scene, (ak_transform_cspan){local, n}, (ak_mat4_span){world, n});
        ak_scene_skin_palette(scene, (size_t)sm->skin, (ak_mat4_cspan){world, n}, (ak_mat4_span){palette, skin->joint_count});
        ak_skin_job sj = {.method = AK_SKIN_LBS, .influence_count = mesh->influence_count,
                          .palette = {palette, skin->joint_count}, .positions = {mesh->positions, v, 0},
                          .joints = {mesh->joints, v, mesh->influence_count * sizeof(uint16_t)},
                          .weights = {mesh->weights, v, mesh->influence_count * sizeof(float)},
                          .out_positions = {pos, v, 0}};
        if (ak_skin_job_run(&sj) != AK_OK) return 1;
        if (head >= 0) {
            const ak_vec3 hp = ak_vec3_make(world[head].m[12], world[head].m[13], world[head].m[14]);
            if (f % 4 == 0) printf("%6.2f  %8.1f\n", f / 12.0, 1000.0 * (double)ak_vec3_distance(hp, head_rest));
        }
        ak_raster_mesh m = ak_view_raster_mesh(mesh);
        m.positions = (ak_vec3_cspan){pos, v};
        m.normals = (ak_vec3_cspan){0};
        frames[f] = (ak_image){.pixels = px + (size_t)f * W * H * 4, .width = W, .height = H};
        const ak_view_scene vs = {.meshes = &m, .mesh_count = 1, .title = "idle sway"};
        if (ak_view_render(r, &cam, &vs, &frames[f]) != AK_OK) return 1;
    }
    const ak_result res = ak_view_frames_write_gif("noise_idle_sway.gif", frames, FRAMES, 8);
    printf("%s noise_idle_sway.gif (%d frames)\n", res == AK_OK ? "wrote" : "could not write", FRAMES);
    ak_raster_destroy(r);
    free(rest), free(local), free(world), free(palette), free(amp), free(freq), free(pos), free(px), free(frames);
    ak_scene_destroy(scene);
    return res == AK_OK ? 0 : 1;
}
