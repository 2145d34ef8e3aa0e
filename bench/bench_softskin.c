/* Volumetric (soft) skinning per frame beside DQS, measured side by side in one run:
 * CesiumMan's walk (when the assets are there), builtin:cylinder's bend clip, and a 50k-vertex
 * cylinder. Prints the lattice size, the precompute (create) time, ms per 60 Hz frame with 1 and
 * 2 threads (the step plus the surface), DQS's ms per frame, and the ratio soft / DQS.
 *
 *     build/bench/bench_softskin [CesiumMan.glb [RESOLUTION]]
 *
 * Single-thread figures use this thread's CPU time (a loaded machine's other processes do not
 * count); the two-thread figures use wall time. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"

#include <animkit/animkit.h>

static const char* asset_path(char* buf, size_t size, const char* rel) {
    const char* env = getenv("ANIMKIT_ASSETS");
    if (env && *env) snprintf(buf, size, "%s/%s", env, rel);
    else snprintf(buf, size, "%s/../shared/assets/%s", AK_SOURCE_DIR, rel);
    FILE* f = fopen(buf, "rb");
    if (!f) return NULL;
    fclose(f);
    return buf;
}

/* Bind-space bones of skin k: segment slot -> child slot, point bones for leaves. */
static size_t skin_bones(const ak_scene* s, const ak_scene_skin* skin, ak_skin_bone* out) {
    size_t n = skin->joint_count, count = 0;
    ak_i32_cspan parents = ak_skeleton_parents(s->skeleton);
    ak_vec3* pos = calloc(n, sizeof(ak_vec3));
    int* parent_slot = calloc(n, sizeof(int));
    char* has_child = calloc(n, 1);
    if (!pos || !parent_slot || !has_child) goto done;
    for (size_t k = 0; k < n; ++k) pos[k] = ak_mat4_get_translation(ak_mat4_inverse_affine(skin->inverse_binds[k]));
    for (size_t k = 0; k < n; ++k) {
        parent_slot[k] = -1;
        for (int j = parents.ptr[skin->joints[k]]; j >= 0 && parent_slot[k] < 0; j = parents.ptr[j])
            for (size_t q = 0; q < n; ++q)
                if (skin->joints[q] == j) parent_slot[k] = (int)q;
    }
    for (size_t k = 0; k < n; ++k) {
        if (parent_slot[k] < 0) continue;
        has_child[parent_slot[k]] = 1;
        out[count++] = (ak_skin_bone){pos[parent_slot[k]], pos[k], (uint16_t)parent_slot[k]};
    }
    for (size_t k = 0; k < n; ++k)
        if (!has_child[k]) out[count++] = (ak_skin_bone){pos[k], pos[k], (uint16_t)k};
done:
    free(pos);
    free(parent_slot);
    free(has_child);
    return count;
}

static uint32_t g_resolution = 0; /* argv[2]; 0 -> the library default */

static void run_case(const char* name, ak_scene* s, int frames) {
    size_t mi = 0;
    while (mi < s->mesh_count && (s->meshes[mi].skin < 0 || !s->meshes[mi].mesh || !s->meshes[mi].mesh->triangle_count)) ++mi;
    if (mi == s->mesh_count || s->clip_count == 0) {
        printf("%-22s SKIP (no skinned triangle mesh or no clip)\n", name);
        return;
    }
    const ak_mesh* mesh = s->meshes[mi].mesh;
    const ak_scene_skin* skin = &s->skins[s->meshes[mi].skin];
    size_t nv = mesh->vertex_count, nj = ak_scene_joint_count(s), ns = skin->joint_count;
    ak_skin_bone* bones = calloc(2 * ns + 1, sizeof(ak_skin_bone));
    size_t nb = skin_bones(s, skin, bones);
    size_t wn = nv * mesh->influence_count;
    ak_skin_soft_desc d = {.positions = {mesh->positions, nv},
                           .indices = {mesh->indices, 3 * mesh->triangle_count},
                           .joints = {mesh->joints, wn},
                           .weights = {mesh->weights, wn},
                           .influence_count = mesh->influence_count,
                           .bones = {bones, nb},
                           .resolution = g_resolution};
    ak_skin_soft* soft = NULL;
    double t0 = bench_wall_s();
    ak_result r = ak_skin_soft_create(&d, NULL, &soft);
    double create_s = bench_wall_s() - t0;
    if (r != AK_OK) {
        printf("%-22s soft create failed: %s\n", name, ak_result_string(r));
        free(bones);
        return;
    }
    size_t nn = ak_skin_soft_node_count(soft), ss = ak_skin_soft_step_scratch_size(soft);
    /* palettes of every frame first: posing is not what is measured */
    ak_mat4* pal = malloc((size_t)(frames + 1) * ns * sizeof(ak_mat4));
    ak_transform* local = malloc(nj * sizeof(ak_transform));
    ak_mat4* world = malloc(nj * sizeof(ak_mat4));
    ak_vec3 *x = malloc(nn * sizeof(ak_vec3)), *v = malloc(nn * sizeof(ak_vec3)), *out = malloc(nv * sizeof(ak_vec3));
    uint8_t* scratch = malloc(ss);
    uint8_t dqs_scratch[64 + 128 * 256];
    float dur = ak_clip_duration(s->clips[0]);
    for (int f = 0; f <= frames; ++f) {
        float t = dur > 0.0f ? fmodf((float)f / 60.0f, dur) : 0.0f;
        ak_scene_rest_pose(s, (ak_transform_span){local, nj});
        ak_clip_sample(s->clips[0], t, NULL, (ak_transform_span){local, nj}, (ak_f32_span){0}, (ak_f32_span){0});
        ak_scene_world_matrices(s, (ak_transform_cspan){local, nj}, (ak_mat4_span){world, nj});
        ak_scene_skin_palette(s, (size_t)s->meshes[mi].skin, (ak_mat4_cspan){world, nj}, (ak_mat4_span){pal + (size_t)f * ns, ns});
    }
    double ms[2] = {0, 0};
    for (int th = 1; th <= 2; ++th) {
        ak_skin_soft_state_init(soft, (ak_mat4_cspan){pal, ns}, (ak_vec3_span){x, nn}, (ak_vec3_span){v, nn});
        double* per = malloc((size_t)frames * sizeof(double));
        for (int f = 1; f <= frames; ++f) {
            ak_skin_soft_step_job job = {.soft = soft,
                                         .palette = {pal + (size_t)f * ns, ns},
                                         .previous_palette = {pal + (size_t)(f - 1) * ns, ns},
                                         .dt = 1.0f / 60.0f,
                                         .node_positions = {x, nn},
                                         .node_velocities = {v, nn},
                                         .scratch = {scratch, ss},
                                         .out_positions = {out, nv},
                                         .thread_count = (uint32_t)th};
            double a = th == 1 ? bench_cpu_s() : bench_wall_s();
            r = ak_skin_soft_step_run(&job);
            per[f - 1] = (th == 1 ? bench_cpu_s() : bench_wall_s()) - a;
            if (r != AK_OK) break;
        }
        ms[th - 1] = 1e3 * bench_percentile(per, (size_t)frames, 0.5);
        free(per);
    }
    /* DQS on the same frames */
    ak_vec3* dq = malloc(nv * sizeof(ak_vec3));
    double* per = malloc((size_t)frames * sizeof(double));
    for (int f = 1; f <= frames; ++f) {
        ak_skin_job job = {.method = AK_SKIN_DQS,
                           .influence_count = mesh->influence_count,
                           .palette = {pal + (size_t)f * ns, ns},
                           .positions = {mesh->positions, nv, 0},
                           .joints = {mesh->joints, nv, 0},
                           .weights = {mesh->weights, nv, 0},
                           .scratch = {dqs_scratch, sizeof dqs_scratch},
                           .out_positions = {dq, nv, 0},
                           .skip_data_check = true};
        double a = bench_cpu_s();
        ak_skin_job_run(&job);
        per[f - 1] = bench_cpu_s() - a;
    }
    double dqs_ms = 1e3 * bench_percentile(per, (size_t)frames, 0.5);
    printf("%-22s %7zu %7zu %7zu %7zu %8.1f %9.3f %9.3f %9.4f %9.1f %9.0f\n", name, nv, nn, ak_skin_soft_kinematic_count(soft),
           ak_skin_soft_tet_count(soft), 1e3 * create_s,
           ms[0], ms[1], dqs_ms, ms[0] / dqs_ms, 1e3 / ms[0]);
    free(per);
    free(dq);
    free(pal);
    free(local);
    free(world);
    free(x);
    free(v);
    free(out);
    free(scratch);
    free(bones);
    ak_skin_soft_destroy(soft);
}

int main(int argc, char** argv) {
    int frames = bench_quick() ? 10 : 240;
    if (argc > 2) g_resolution = (uint32_t)atoi(argv[2]);
    printf("soft skinning, median ms per 60 Hz frame (the default desc: 40 substeps; resolution 32 or argv[2]; step + surface); DQS the same frames\n");
    printf("%-22s %7s %7s %7s %7s %8s %9s %9s %9s %9s %9s\n", "model", "verts", "nodes", "kinem.", "tets", "build ms", "soft 1t", "soft 2t",
           "DQS 1t", "soft/DQS", "fps 1t");
    char buf[1024];
    const char* path = argc > 1 ? argv[1] : asset_path(buf, sizeof buf, "gltf/CesiumMan/glTF-Binary/CesiumMan.glb");
    ak_scene* s = NULL;
    if (path && ak_io_load(path, NULL, NULL, &s, NULL) == AK_OK) {
        run_case("CesiumMan", s, frames);
        ak_scene_destroy(s);
    } else {
        printf("%-22s SKIP (assets not found)\n", "CesiumMan");
    }
    s = NULL;
    if (ak_builtin_create("builtin:cylinder", NULL, NULL, &s) == AK_OK) {
        run_case("cylinder 48x32", s, frames);
        ak_scene_destroy(s);
    }
    ak_builtin_desc big = {.rings = 400, .segments = 128};
    s = NULL;
    if (ak_builtin_create("builtin:cylinder", &big, NULL, &s) == AK_OK) {
        run_case("cylinder 400x128 (51k)", s, bench_quick() ? 5 : 60);
        ak_scene_destroy(s);
    }
    return 0;
}
