/* A game's animation frame for many characters (bench/bench_crowd_frame.c, and
 * tests/test_crowd_frame.c, which checks this very code): per character, sample its clip at its
 * time, FK, skinning palette, and linear blend skinning with normals into its own output
 * buffers; the characters split over the library's worker team (src/tasks.h).
 *
 * Bench-only, never installed: it strings public calls together (ak_clip_sample,
 * ak_scene_world_matrices, ak_scene_skin_palette, ak_skin_job_run) the way a game would, and
 * uses the internal akp_run_tasks for the parallel loop.
 *
 * Determinism: each character's outputs are written only by the task that owns it, from its own
 * inputs (its clip, its time, its cursor), with the same code whatever the thread count, so the
 * bits of a frame do not depend on the thread count or the partition.
 *
 * Two schedules (crowd.dynamic):
 *   - static (false): characters differ (builtin:humanoid: 9,010 vertices, 17 joints;
 *     CesiumMan: 3,273 vertices, 22 nodes), so each task gets one contiguous range of about
 *     equal estimated cost (crowd_character_cost), not of equal length;
 *   - dynamic (true): the tasks take chunks of CROWD_CHUNK characters in order from a shared
 *     atomic counter until none is left, so a thread that was descheduled or slowed takes fewer
 *     (a job system's way). Which thread skins a character never changes its bits. */
#ifndef ANIMKIT_BENCH_CROWD_FRAME_H
#define ANIMKIT_BENCH_CROWD_FRAME_H

#include <animkit/animkit.h>
#include <math.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tasks.h"

#define CROWD_MAX_JOINTS 256   /* per-character scratch lives on the task's stack */
#define CROWD_DT (1.0 / 60.0)  /* seconds a frame */
#define CROWD_CHUNK 4          /* characters a dynamic task takes at a time */

typedef struct crowd_model {
    ak_scene* scene;
    const ak_scene_mesh* sm; /* the first skinned mesh */
    const ak_mesh* mesh;
    size_t joints, palette_count;
} crowd_model;

typedef struct crowd_character {
    const crowd_model* m;
    const ak_clip* clip;
    double offset;            /* clip time at frame 0, seconds */
    ak_clip_cursor cursor;
    uint32_t* cursor_storage;
    ak_vec3 *out_p, *out_n;   /* [mesh vertex_count] */
} crowd_character;

typedef struct crowd {
    crowd_model models[2];
    int model_count;
    crowd_character* chars;
    size_t count;
    double* cost_prefix;      /* [count + 1]: estimated cost of characters [0, i) */
    bool dynamic;             /* false: static ranges of equal estimated cost; true: chunks
                                 from a shared counter */
} crowd;

typedef struct crowd_task {
    crowd* c;
    size_t begin, end;        /* static: the range; dynamic: unused */
    atomic_size_t* next;      /* dynamic: the next character nobody has taken; NULL: static */
    uint64_t frame;
    bool check;
    bool ok;
} crowd_task;

/* Load a model ("builtin:NAME" or a glTF path); false when it is missing or has no skinned
 * mesh with a clip. */
static inline bool crowd_model_load(crowd_model* m, const char* spec) {
    memset(m, 0, sizeof *m);
    ak_result r = strncmp(spec, "builtin:", 8) == 0 ? ak_builtin_create(spec, NULL, NULL, &m->scene)
                                                    : ak_io_load(spec, NULL, NULL, &m->scene, NULL);
    if (r != AK_OK || !m->scene || m->scene->clip_count == 0) goto fail;
    for (size_t i = 0; i < m->scene->mesh_count && !m->sm; ++i)
        if (m->scene->meshes[i].skin >= 0) m->sm = &m->scene->meshes[i];
    if (!m->sm) goto fail;
    m->mesh = m->sm->mesh;
    m->joints = ak_scene_joint_count(m->scene);
    m->palette_count = m->scene->skins[m->sm->skin].joint_count;
    if (m->joints > CROWD_MAX_JOINTS || m->palette_count > CROWD_MAX_JOINTS) goto fail;
    return true;
fail:
    if (m->scene) ak_scene_destroy(m->scene);
    memset(m, 0, sizeof *m);
    return false;
}

/* Estimated cost of one character's frame, in "vertex units": skinning a vertex with its
 * normal is about 1, sampling + FK + palette of one joint about 40 (measured on this build's
 * 1-thread profile: the exact value only moves the partition's borders). */
static inline double crowd_character_cost(const crowd_character* ch) {
    return (double)ch->m->mesh->vertex_count * (0.5 + 0.125 * ch->m->mesh->influence_count) +
           40.0 * (double)ch->m->joints;
}

/* The time character ch plays at frame: its offset plus frame / 60 s, looped over its clip. */
static inline float crowd_character_time(const crowd_character* ch, uint64_t frame) {
    return ak_time_wrap((float)fmod(ch->offset + (double)frame * CROWD_DT, (double)ak_clip_duration(ch->clip)),
                        ak_clip_duration(ch->clip), AK_WRAP_LOOP);
}

/* One character's frame on the calling thread. check: validate the skin data (O(n), done once
 * on the first frame; later frames skip it as a game would). */
static inline bool crowd_character_frame(crowd_character* ch, uint64_t frame, bool check) {
    const crowd_model* m = ch->m;
    ak_transform local[CROWD_MAX_JOINTS];
    ak_mat4 world[CROWD_MAX_JOINTS], palette[CROWD_MAX_JOINTS];
    const float t = crowd_character_time(ch, frame);
    bool ok = ak_scene_rest_pose(m->scene, (ak_transform_span){local, m->joints}) == AK_OK;
    ok = ok && ak_clip_sample(ch->clip, t, &ch->cursor, (ak_transform_span){local, m->joints}, (ak_f32_span){0},
                              (ak_f32_span){0}) == AK_OK;
    ok = ok && ak_scene_world_matrices(m->scene, (ak_transform_cspan){local, m->joints},
                                       (ak_mat4_span){world, m->joints}) == AK_OK;
    ok = ok && ak_scene_skin_palette(m->scene, (size_t)m->sm->skin, (ak_mat4_cspan){world, m->joints},
                                     (ak_mat4_span){palette, m->palette_count}) == AK_OK;
    const ak_mesh* mesh = m->mesh;
    const size_t v = mesh->vertex_count;
    ak_skin_job j = {.method = AK_SKIN_LBS, .influence_count = mesh->influence_count,
                     .palette = {palette, m->palette_count}, .positions = {mesh->positions, v, 0},
                     .joints = {mesh->joints, v, mesh->influence_count * sizeof(uint16_t)},
                     .weights = {mesh->weights, v, mesh->influence_count * sizeof(float)},
                     .out_positions = {ch->out_p, v, 0}, .skip_data_check = !check, .thread_count = 1};
    if (mesh->normals) j.normals = (ak_cstream){mesh->normals, v, 0}, j.out_normals = (ak_stream){ch->out_n, v, 0};
    return ok && ak_skin_job_run(&j) == AK_OK;
}

static inline void* crowd_task_run(void* arg) {
    crowd_task* t = (crowd_task*)arg;
    bool ok = true;
    if (!t->next) {
        for (size_t i = t->begin; i < t->end; ++i) ok = crowd_character_frame(&t->c->chars[i], t->frame, t->check) && ok;
    } else {
        for (;;) {
            const size_t b = atomic_fetch_add_explicit(t->next, CROWD_CHUNK, memory_order_relaxed);
            if (b >= t->c->count) break;
            const size_t e = b + CROWD_CHUNK < t->c->count ? b + CROWD_CHUNK : t->c->count;
            for (size_t i = b; i < e; ++i) ok = crowd_character_frame(&t->c->chars[i], t->frame, t->check) && ok;
        }
    }
    t->ok = ok;
    return NULL;
}

static inline void crowd_fini(crowd* c) {
    for (size_t i = 0; c->chars && i < c->count; ++i)
        free(c->chars[i].cursor_storage), free(c->chars[i].out_p), free(c->chars[i].out_n);
    free(c->chars), free(c->cost_prefix);
    for (int k = 0; k < c->model_count; ++k) ak_scene_destroy(c->models[k].scene);
    memset(c, 0, sizeof *c);
}

/* Set up count characters: alternately builtin:humanoid and the glTF at gltf_path (NULL or
 * missing: humanoid only, *out_gltf_missing set). Character i plays clip (i / models) mod the
 * model's clip count from a time offset drawn from a fixed seed. False on no memory or no
 * model at all. */
static inline bool crowd_init(crowd* c, size_t count, const char* gltf_path, bool* out_gltf_missing) {
    memset(c, 0, sizeof *c);
    if (crowd_model_load(&c->models[c->model_count], "builtin:humanoid")) c->model_count++;
    const bool have = gltf_path && crowd_model_load(&c->models[c->model_count], gltf_path);
    if (have) c->model_count++;
    if (out_gltf_missing) *out_gltf_missing = !have;
    if (c->model_count == 0) return false;
    c->chars = calloc(count, sizeof *c->chars);
    c->cost_prefix = calloc(count + 1, sizeof *c->cost_prefix);
    if (!c->chars || !c->cost_prefix) return crowd_fini(c), false;
    c->count = count;
    ak_rng r = ak_rng_make(2026);
    for (size_t i = 0; i < count; ++i) {
        crowd_character* ch = &c->chars[i];
        const size_t nm = (size_t)c->model_count;
        ch->m = &c->models[i % nm];
        const ak_scene* sc = ch->m->scene;
        ch->clip = sc->clips[(i / nm) % sc->clip_count];
        ch->offset = (double)ak_rng_range(&r, 0.0f, ak_clip_duration(ch->clip));
        const size_t cn = ak_clip_cursor_storage_count(ch->clip);
        ch->cursor_storage = calloc(cn + 1, sizeof(uint32_t));
        const size_t v = ch->m->mesh->vertex_count;
        ch->out_p = calloc(v, sizeof(ak_vec3)), ch->out_n = calloc(v, sizeof(ak_vec3));
        if (!ch->cursor_storage || !ch->out_p || !ch->out_n) return crowd_fini(c), false;
        ak_clip_cursor_init(&ch->cursor, ch->clip, (ak_u32_span){ch->cursor_storage, cn});
        c->cost_prefix[i + 1] = c->cost_prefix[i] + crowd_character_cost(ch);
    }
    return true;
}

/* The first character index of task t of n: the first i whose cost prefix reaches t / n of the
 * total (binary search), so the ranges hold about equal work. */
static inline size_t crowd_split(const crowd* c, uint32_t t, uint32_t n) {
    if (t == 0) return 0;
    if (t >= n) return c->count;
    const double target = c->cost_prefix[c->count] * (double)t / (double)n;
    size_t lo = 0, hi = c->count;
    while (lo < hi) {
        const size_t mid = lo + (hi - lo) / 2;
        if (c->cost_prefix[mid] < target) lo = mid + 1;
        else hi = mid;
    }
    return lo;
}

/* Frame number frame of every character on threads threads (1..AKP_TASKS_MAX; 1: the calling
 * thread). check: validate the skin data this frame. */
static inline bool crowd_frame(crowd* c, uint64_t frame, uint32_t threads, bool check) {
    crowd_task tasks[AKP_TASKS_MAX];
    atomic_size_t next;
    atomic_init(&next, 0);
    if (threads < 1) threads = 1;
    if (threads > AKP_TASKS_MAX) threads = AKP_TASKS_MAX;
    for (uint32_t t = 0; t < threads; ++t)
        tasks[t] = (crowd_task){c, crowd_split(c, t, threads), crowd_split(c, t + 1, threads),
                                c->dynamic && threads > 1 ? &next : NULL, frame, check, false};
    if (threads == 1) crowd_task_run(&tasks[0]);
    else akp_run_tasks(crowd_task_run, tasks, sizeof(crowd_task), threads);
    bool ok = true;
    for (uint32_t t = 0; t < threads; ++t) ok = ok && tasks[t].ok;
    return ok;
}

/* FNV-1a 64 of every character's output positions and normals (the bits of the frame). */
static inline uint64_t crowd_hash(const crowd* c) {
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < c->count; ++i) {
        const crowd_character* ch = &c->chars[i];
        const size_t bytes = ch->m->mesh->vertex_count * sizeof(ak_vec3);
        for (int k = 0; k < 2; ++k) {
            const unsigned char* p = (const unsigned char*)(k ? ch->out_n : ch->out_p);
            for (size_t b = 0; b < bytes; ++b) h = (h ^ p[b]) * 1099511628211ull;
        }
    }
    return h;
}

#endif
