/* Recording a simulation's frames for glTF output (see sim_bake.h). */
#include "sim_bake.h"

#include <stdlib.h>
#include <string.h>

#include "cli.h"

bool sim_bake_wanted(const char* path) { return path && (cli_has_ext(path, ".glb") || cli_has_ext(path, ".gltf")); }

/* Smallest k such that steps / k + 1 frames fit max_frames and frame_bytes each fit the budget. */
static long frame_step(long steps, size_t frame_bytes) {
    size_t by_mem = frame_bytes ? SIM_BAKE_BUDGET / frame_bytes : AK_SCENE_BAKE_MAX_FRAMES;
    size_t max_frames = by_mem < AK_SCENE_BAKE_MAX_FRAMES ? by_mem : AK_SCENE_BAKE_MAX_FRAMES;
    if (max_frames < 2) max_frames = 2;
    long k = 1;
    if (steps > 0 && (size_t)steps + 1 > max_frames) k = (long)(((size_t)steps + max_frames - 2) / (max_frames - 1));
    return k;
}

int sim_bake_mesh_init(sim_bake* b, const char* cmd, const char* out, size_t n, long steps) {
    memset(b, 0, sizeof *b);
    b->cmd = cmd, b->out = out, b->n = n;
    if (n == 0 || n > SIM_BAKE_BUDGET / (2 * 2 * sizeof(ak_vec3)))
        return cli_fail(cmd, "%s: %zu vertices are too many to bake (budget %zu bytes)", out, n, SIM_BAKE_BUDGET);
    b->every = frame_step(steps, 2 * n * sizeof(ak_vec3));
    b->cap = (size_t)(steps / b->every) + 1;
    b->pos = malloc(b->cap * n * sizeof(ak_vec3));
    b->nrm = malloc(b->cap * n * sizeof(ak_vec3));
    if (!b->pos || !b->nrm) return cli_fail(cmd, "%s: out of memory for %zu frames", out, b->cap);
    return CLI_OK;
}

int sim_bake_mesh_add(sim_bake* b, long step, const ak_vec3* x, const ak_vec3* nrm) {
    if (step % b->every || b->frames >= b->cap) return CLI_OK;
    memcpy(b->pos + b->frames * b->n, x, b->n * sizeof(ak_vec3));
    memcpy(b->nrm + b->frames * b->n, nrm, b->n * sizeof(ak_vec3));
    ++b->frames;
    return CLI_OK;
}

int sim_bake_mesh_write(sim_bake* b, const char* name, float dt, ak_u32_cspan indices, ak_vec4 colour) {
    ak_scene_bake_mesh_desc d = {.name = name, .vertex_count = b->n, .frame_count = b->frames, .positions = b->pos,
                                 .normals = b->nrm, .indices = indices, .frame_time = dt * (float)b->every,
                                 .base_color = colour};
    ak_scene* s = NULL;
    ak_diag diag = {0};
    ak_result r = ak_scene_bake_mesh_frames(&d, NULL, &s, &diag);
    if (r == AK_OK) r = ak_io_save(b->out, s, NULL, &diag);
    ak_scene_destroy(s);
    if (r == AK_ERR_UNSUPPORTED) return cli_fail(b->cmd, "%s: %s; use fewer --steps", b->out, diag.message);
    if (r != AK_OK) return cli_fail(b->cmd, "%s: %s (%s)", b->out, diag.message, ak_result_string(r));
    return CLI_OK;
}

int sim_bake_points_init(sim_bake* b, const char* cmd, const char* out, long steps) {
    memset(b, 0, sizeof *b);
    b->cmd = cmd, b->out = out;
    b->every = frame_step(steps, 0);
    b->cap = (size_t)(steps / b->every) + 1;
    b->pts = calloc(b->cap, sizeof *b->pts);
    if (!b->pts) return cli_fail(cmd, "%s: out of memory for %zu frames", out, b->cap);
    return CLI_OK;
}

int sim_bake_points_add(sim_bake* b, long step, const ak_vec3* p, const uint32_t* ids, size_t count) {
    if (step % b->every || b->frames >= b->cap) return CLI_OK;
    const size_t per = sizeof(ak_vec3) + sizeof(uint32_t);
    if (count > (SIM_BAKE_BUDGET - b->entries * per) / per)
        return cli_fail(b->cmd, "%s: the run records more than %zu bytes of particle positions; use fewer --steps", b->out,
                        SIM_BAKE_BUDGET);
    ak_scene_bake_points* f = &b->pts[b->frames];
    if (count) {
        ak_vec3* pc = malloc(count * sizeof(ak_vec3));
        uint32_t* ic = malloc(count * sizeof(uint32_t));
        if (!pc || !ic) {
            free(pc), free(ic);
            return cli_fail(b->cmd, "%s: out of memory", b->out);
        }
        memcpy(pc, p, count * sizeof(ak_vec3));
        memcpy(ic, ids, count * sizeof(uint32_t));
        *f = (ak_scene_bake_points){.positions = pc, .ids = ic, .count = count};
    }
    b->entries += count;
    ++b->frames;
    return CLI_OK;
}

int sim_bake_points_write(sim_bake* b, const char* name, float dt) {
    ak_scene_bake_points_desc d = {.name = name, .frames = b->pts, .frame_count = b->frames,
                                   .frame_time = dt * (float)b->every, .marker_size = SIM_BAKE_MARKER_SIZE};
    ak_scene* s = NULL;
    ak_diag diag = {0};
    ak_result r = ak_scene_bake_point_frames(&d, NULL, &s, &diag);
    if (r == AK_OK) r = ak_io_save(b->out, s, NULL, &diag);
    ak_scene_destroy(s);
    /* one animated node per distinct particle: fewer steps cannot help, fewer particles can */
    if (r == AK_ERR_UNSUPPORTED)
        return cli_fail(b->cmd, "%s: %s; lower the particle count (the scene's particles, capacity or emitters) "
                        "or write --json instead", b->out, diag.message);
    if (r != AK_OK) return cli_fail(b->cmd, "%s: %s (%s)", b->out, diag.message, ak_result_string(r));
    return CLI_OK;
}

void sim_bake_free(sim_bake* b) {
    free(b->pos), free(b->nrm);
    for (size_t k = 0; b->pts && k < b->frames; ++k) {
        free((void*)b->pts[k].positions);
        free((void*)b->pts[k].ids);
    }
    free(b->pts);
    memset(b, 0, sizeof *b);
}
