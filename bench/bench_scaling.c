/* Scaling with threads: the threaded workloads of docs/BENCHMARKS.md ("multicore") on 1, 2, 4, ...
 * threads in one run, with where the time goes (src/tasks.h's profile).
 *     bench_scaling [--threads 1,2,4,8,16] [--only NAME,...] [--steps N] [--quick]
 * Workloads (NAME): boids100k, boids1m (3D flock, about 28 neighbours each), pbf55k, pbf500k (a
 * dam break, 4 iterations), cloth256, cloth512 (XPBD, 10 substeps, draped on a sphere), lbs1m
 * (linear blend skinning of 1,000,000 vertices with normals, 4 influences), characters
 * (1,000 characters, builtin:humanoid and CesiumMan when ../shared/assets has it, different
 * clips and times: sample, FK, palette and skinning with normals per character, the characters
 * split over the threads: a game's frame). --quick: small sizes and few steps (checks the
 * pipeline; the numbers mean little).
 * Per workload and thread count: the median wall ms per step, the speed-up and efficiency over
 * 1 thread, and from a separate profiled run (src/tasks.h): parallel sections per step, the
 * serial ms per step (the caller's wall time outside them) and "idle", the share of the threads'
 * time spent waiting (the others while the caller runs serial parts, the caller at the end of
 * a section, everyone at barriers: serial phases and imbalance). A job whose threads are not
 * idle but still scale badly is limited by memory bandwidth or by threads that cannot run (a
 * loaded machine). The last column is Amdahl's speed-up at 16 threads for the serial fraction
 * that explains the idle time at 2 threads (s = 1 / (1 - idle) - 1).
 *     bench_scaling --cpu [--cpu-threads 2,16] [--cpu-steps N] [--phases] ...
 * adds a CPU-time profile per workload over N steps (default up to 6) (src/tasks.h,
 * akp_tasks_profile_step): every thread's
 * CPU time per phase, so a loaded machine, or one with fewer cores than threads, still measures
 * the work. Per thread count T (the job run with T threads): CPU ms per step, the serial part
 * (the caller's work between sections, plus each phase's busiest thread beyond the others'
 * mean), the parallel part, the critical path (the busiest thread's CPU per phase, summed), and
 * two predictions of the efficiency at T threads on T free cores: Amdahl's law from the serial
 * fraction measured at the first T > 1 of the list, and 1-thread CPU / (T x critical path)
 * (which also sees the work added by splitting and the imbalance of the partition at T). Both
 * leave out memory bandwidth and wake-ups. "steady" is the persistent part of the serial ms
 * (src/tasks.h: each thread's CPU per phase summed over the steps before taking the busiest
 * one's excess, so an excess that moves between threads from step to step, as on a loaded
 * machine, cancels) and amdahl-s Amdahl's law from it: the serial fraction a machine with free
 * cores would see, where "serial" includes that noise. --phases lists each phase of the first
 * T > 1. */
#include <animkit/animkit.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_clock.h"
#include "tasks.h"

#define MAX_COUNTS 16

typedef struct workload workload;
struct workload {
    const char* name;
    size_t size; /* agents, particles, vertices, characters */
    void* state;
    bool (*init)(workload* w, size_t size);
    bool (*step)(workload* w, uint32_t threads);
    void (*fini)(workload* w);
};

/* ---- boids ---------------------------------------------------------------------------------- */

typedef struct boids_state {
    size_t n;
    ak_vec3 *p, *v, *p2, *v2;
    uint8_t* scratch;
    size_t scratch_size;
    ak_boids_species sp;
    ak_boids_params prm;
} boids_state;

static bool boids_init(workload* w, size_t n) {
    boids_state* s = calloc(1, sizeof *s);
    if (!s) return false;
    w->state = s;
    s->n = n;
    const float side = cbrtf((float)n * 4.18879f / 30.0f);
    s->p = malloc(n * sizeof(ak_vec3)), s->v = malloc(n * sizeof(ak_vec3));
    s->p2 = malloc(n * sizeof(ak_vec3)), s->v2 = malloc(n * sizeof(ak_vec3));
    if (!s->p || !s->v || !s->p2 || !s->v2) return false;
    ak_rng r = ak_rng_make(2026);
    for (size_t i = 0; i < n; ++i) {
        s->p[i] = ak_vec3_make(ak_rng_range(&r, 0, side), ak_rng_range(&r, 0, side), ak_rng_range(&r, 0, side));
        s->v[i] = ak_vec3_make(ak_rng_range(&r, -1, 1), ak_rng_range(&r, -1, 1), ak_rng_range(&r, -1, 1));
    }
    s->sp = (ak_boids_species){.max_speed = 2, .max_force = 8, .separation_weight = 1, .separation_radius = 0.5f,
                               .alignment_weight = 1, .alignment_radius = 1, .cohesion_weight = 0.5f,
                               .cohesion_radius = 1, .view_angle = 360};
    s->prm = (ak_boids_params){.species = &s->sp, .species_count = 1, .bounds_min = {0, 0, 0},
                               .bounds_max = {side, side, side}, .bounds = AK_BOIDS_BOUNDS_WRAP};
    return true;
}

static bool boids_step(workload* w, uint32_t threads) {
    boids_state* s = (boids_state*)w->state;
    ak_boids_step_job j = {.params = &s->prm, .positions = {s->p, s->n}, .velocities = {s->v, s->n},
                           .dt = 1.0f / 60.0f, .thread_count = threads, .out_positions = {s->p2, s->n},
                           .out_velocities = {s->v2, s->n}};
    const size_t need = ak_boids_step_scratch_size(&j);
    if (need > s->scratch_size) {
        free(s->scratch);
        s->scratch = malloc(need);
        s->scratch_size = s->scratch ? need : 0;
    }
    j.scratch = (ak_u8_span){s->scratch, s->scratch_size};
    if (ak_boids_step_run(&j) != AK_OK) return false;
    ak_vec3* t = s->p;
    s->p = s->p2, s->p2 = t;
    t = s->v, s->v = s->v2, s->v2 = t;
    return true;
}

static void boids_fini(workload* w) {
    boids_state* s = (boids_state*)w->state;
    if (!s) return;
    free(s->p), free(s->v), free(s->p2), free(s->v2), free(s->scratch), free(s);
}

/* ---- PBF ------------------------------------------------------------------------------------ */

typedef struct fluid_state {
    ak_fluid_desc d;
    ak_vec3 *pos, *vel, *pos0;
    size_t n, n0;
    void* mem;
    size_t bytes;
} fluid_state;

static bool pbf_init(workload* w, size_t want) {
    fluid_state* s = calloc(1, sizeof *s);
    if (!s) return false;
    w->state = s;
    s->d = (ak_fluid_desc){.solver = AK_FLUID_PBF, .particle_mass = 0.001f, .gravity = {0, -9.81f, 0},
                           .xsph_c = 0.01f, .vorticity_epsilon = 0.1f, .iterations = 4, .viscosity = 0.02f};
    const float sp = ak_fluid_rest_spacing(&s->d);
    s->d.h = 2.0f * sp;
    int side = 1;
    while ((size_t)(2 * side) * (2 * side) * side < want) ++side;
    const float bx = 2.0f * side * sp, by = 2.0f * side * sp, bz = side * sp;
    s->d.box_max = ak_vec3_make(2.5f * bx, 1.5f * by, bz);
    const size_t cap = (size_t)(2 * side) * (2 * side) * side;
    s->pos = malloc(cap * sizeof(ak_vec3)), s->vel = calloc(cap, sizeof(ak_vec3));
    s->pos0 = malloc(cap * sizeof(ak_vec3));
    if (!s->pos || !s->vel || !s->pos0) return false;
    s->n = s->n0 = ak_fluid_fill_box(&s->d, s->d.box_min, ak_vec3_make(bx, by, bz), (ak_vec3_span){s->pos, cap});
    memcpy(s->pos0, s->pos, s->n * sizeof(ak_vec3));
    s->bytes = ak_fluid_scratch_size(s->n, &s->d);
    s->mem = malloc(s->bytes);
    w->size = s->n;
    return s->mem != NULL;
}

static bool pbf_step(workload* w, uint32_t threads) {
    fluid_state* s = (fluid_state*)w->state;
    ak_fluid_step_job job = {.desc = &s->d, .dt = 1.0f / 400.0f, .positions = {s->pos, s->n0},
                             .velocities = {s->vel, s->n0}, .particle_count = &s->n, .thread_count = threads,
                             .scratch = {s->mem, s->bytes}};
    return ak_fluid_step_run(&job) == AK_OK;
}

static void pbf_fini(workload* w) {
    fluid_state* s = (fluid_state*)w->state;
    if (!s) return;
    free(s->pos), free(s->vel), free(s->pos0), free(s->mem), free(s);
}

/* ---- cloth ---------------------------------------------------------------------------------- */

typedef struct cloth_state {
    ak_cloth* cloth;
    size_t n;
    ak_vec3 *x, *v;
    ak_cloth_sphere sphere;
    void* scratch;
    size_t scratch_size;
} cloth_state;

static bool cloth_init(workload* w, size_t side) {
    cloth_state* s = calloc(1, sizeof *s);
    if (!s) return false;
    w->state = s;
    const uint32_t W = (uint32_t)side;
    ak_cloth_desc d = {.solver = AK_CLOTH_XPBD, .grid_width = W, .grid_height = W, .spacing = 1.0f / (float)(W - 1),
                       .grid_origin = {-0.5f, 1.0f, 0.5f}};
    if (ak_cloth_create(&d, NULL, &s->cloth) != AK_OK) return false;
    s->n = ak_cloth_vertex_count(s->cloth);
    s->x = malloc(s->n * sizeof(ak_vec3)), s->v = calloc(s->n, sizeof(ak_vec3));
    if (!s->x || !s->v) return false;
    ak_cloth_rest_positions(s->cloth, (ak_vec3_span){s->x, s->n});
    s->sphere = (ak_cloth_sphere){{0, 0.5f, 0}, 0.3f};
    w->size = s->n;
    return true;
}

static bool cloth_step(workload* w, uint32_t threads) {
    cloth_state* s = (cloth_state*)w->state;
    ak_cloth_step_job job = {.cloth = s->cloth, .dt = 1.0f / 60.0f, .substeps = 10, .gravity = {0, -9.81f, 0},
                             .spheres = &s->sphere, .sphere_count = 1, .friction = 0.3f, .damping = 0.5f,
                             .thread_count = threads, .positions = {s->x, s->n}, .velocities = {s->v, s->n}};
    const size_t need = ak_cloth_step_scratch_size(&job);
    if (need > s->scratch_size) {
        free(s->scratch);
        s->scratch = malloc(need);
        s->scratch_size = s->scratch ? need : 0;
    }
    job.scratch = (ak_u8_span){s->scratch, s->scratch_size};
    return ak_cloth_step_run(&job) == AK_OK;
}

static void cloth_fini(workload* w) {
    cloth_state* s = (cloth_state*)w->state;
    if (!s) return;
    free(s->x), free(s->v), free(s->scratch);
    ak_cloth_destroy(s->cloth);
    free(s);
}

/* ---- LBS of 1M vertices --------------------------------------------------------------------- */

#define LBS_JOINTS 64
typedef struct lbs_state {
    size_t n;
    ak_vec3 *p, *nrm, *out_p, *out_n;
    uint16_t* joints;
    float* weights;
    ak_mat4 palette[LBS_JOINTS];
    float time;
} lbs_state;

static bool lbs_init(workload* w, size_t n) {
    lbs_state* s = calloc(1, sizeof *s);
    if (!s) return false;
    w->state = s;
    s->n = n;
    s->p = malloc(n * sizeof(ak_vec3)), s->nrm = malloc(n * sizeof(ak_vec3));
    s->out_p = malloc(n * sizeof(ak_vec3)), s->out_n = malloc(n * sizeof(ak_vec3));
    s->joints = malloc(n * 4 * sizeof(uint16_t)), s->weights = malloc(n * 4 * sizeof(float));
    if (!s->p || !s->nrm || !s->out_p || !s->out_n || !s->joints || !s->weights) return false;
    ak_rng r = ak_rng_make(7);
    for (size_t i = 0; i < n; ++i) {
        s->p[i] = ak_vec3_make(ak_rng_range(&r, -1, 1), ak_rng_range(&r, 0, 2), ak_rng_range(&r, -1, 1));
        s->nrm[i] = ak_vec3_normalize(ak_vec3_make(ak_rng_range(&r, -1, 1), ak_rng_range(&r, -1, 1), 1.0f));
        /* four nearby joints with weights summing to 1, as a skin has */
        const uint16_t j0 = (uint16_t)(ak_rng_u32(&r) % (LBS_JOINTS - 3));
        float sum = 0.0f;
        for (int k = 0; k < 4; ++k) {
            s->joints[i * 4 + (size_t)k] = (uint16_t)(j0 + k);
            sum += s->weights[i * 4 + (size_t)k] = ak_rng_range(&r, 0.1f, 1.0f);
        }
        for (int k = 0; k < 4; ++k) s->weights[i * 4 + (size_t)k] /= sum;
    }
    return true;
}

static bool lbs_step(workload* w, uint32_t threads) {
    lbs_state* s = (lbs_state*)w->state;
    s->time += 1.0f / 60.0f;
    for (int j = 0; j < LBS_JOINTS; ++j) {
        const ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0, 1, 0), 0.3f * sinf(s->time + 0.1f * (float)j));
        s->palette[j] = ak_mat4_from_mat3(ak_mat3_from_quat(q), ak_vec3_make(0.01f * (float)j, 0, 0));
    }
    ak_skin_job j = {.method = AK_SKIN_LBS, .influence_count = 4, .palette = {s->palette, LBS_JOINTS},
                     .positions = {s->p, s->n, 0}, .normals = {s->nrm, s->n, 0},
                     .joints = {s->joints, s->n, 4 * sizeof(uint16_t)}, .weights = {s->weights, s->n, 4 * sizeof(float)},
                     .out_positions = {s->out_p, s->n, 0}, .out_normals = {s->out_n, s->n, 0},
                     .thread_count = threads};
    return ak_skin_job_run(&j) == AK_OK;
}

static void lbs_fini(workload* w) {
    lbs_state* s = (lbs_state*)w->state;
    if (!s) return;
    free(s->p), free(s->nrm), free(s->out_p), free(s->out_n), free(s->joints), free(s->weights), free(s);
}

/* ---- 1,000 characters --------------------------------------------------------------------- */

typedef struct model {
    ak_scene* scene;
    const ak_scene_mesh* sm;
    const ak_mesh* mesh;
    size_t joints, palette_count;
    size_t scratch_size;
} model;

typedef struct character {
    const model* m;
    const ak_clip* clip;
    float time, rate;
    ak_clip_cursor cursor;
    uint32_t* cursor_storage;
    ak_vec3 *out_p, *out_n;
} character;

typedef struct crowd_state {
    model models[2];
    int model_count;
    character* chars;
    size_t count;
} crowd_state;

typedef struct char_task {
    crowd_state* s;
    size_t begin, end;
    bool ok;
} char_task;

static bool model_load(model* m, const char* spec) {
    memset(m, 0, sizeof *m);
    ak_result r = strncmp(spec, "builtin:", 8) == 0 ? ak_builtin_create(spec, NULL, NULL, &m->scene)
                                                    : ak_io_load(spec, NULL, NULL, &m->scene, NULL);
    if (r != AK_OK || m->scene->clip_count == 0 || m->scene->mesh_count == 0 || m->scene->meshes[0].skin < 0) {
        if (m->scene) ak_scene_destroy(m->scene);
        m->scene = NULL;
        return false;
    }
    m->sm = &m->scene->meshes[0];
    m->mesh = m->sm->mesh;
    m->joints = ak_scene_joint_count(m->scene);
    m->palette_count = m->scene->skins[m->sm->skin].joint_count;
    return true;
}

/* One character's frame on the calling thread: sample, FK, palette, LBS with normals. The
 * per-character scratch lives on the stack (the joint counts here are small). */
static bool character_frame(character* c, float dt) {
    const model* m = c->m;
    ak_transform local[256];
    ak_mat4 world[256], palette[256];
    if (m->joints > 256 || m->palette_count > 256) return false;
    c->time += dt * c->rate;
    const float dur = ak_clip_duration(c->clip);
    if (dur > 0.0f) c->time = fmodf(c->time, dur);
    ak_scene_rest_pose(m->scene, (ak_transform_span){local, m->joints});
    ak_clip_sample(c->clip, c->time, &c->cursor, (ak_transform_span){local, m->joints}, (ak_f32_span){0},
                   (ak_f32_span){0});
    ak_scene_world_matrices(m->scene, (ak_transform_cspan){local, m->joints}, (ak_mat4_span){world, m->joints});
    ak_scene_skin_palette(m->scene, (size_t)m->sm->skin, (ak_mat4_cspan){world, m->joints},
                          (ak_mat4_span){palette, m->palette_count});
    const ak_mesh* mesh = m->mesh;
    const size_t v = mesh->vertex_count;
    ak_skin_job j = {.method = AK_SKIN_LBS, .influence_count = mesh->influence_count,
                     .palette = {palette, m->palette_count}, .positions = {mesh->positions, v, 0},
                     .joints = {mesh->joints, v, mesh->influence_count * sizeof(uint16_t)},
                     .weights = {mesh->weights, v, mesh->influence_count * sizeof(float)},
                     .out_positions = {c->out_p, v, 0}};
    if (mesh->normals) j.normals = (ak_cstream){mesh->normals, v, 0}, j.out_normals = (ak_stream){c->out_n, v, 0};
    return ak_skin_job_run(&j) == AK_OK;
}

static void* char_thread(void* arg) {
    char_task* t = (char_task*)arg;
    t->ok = true;
    for (size_t i = t->begin; i < t->end; ++i) t->ok = character_frame(&t->s->chars[i], 1.0f / 60.0f) && t->ok;
    return NULL;
}

static bool chars_init(workload* w, size_t count) {
    crowd_state* s = calloc(1, sizeof *s);
    if (!s) return false;
    w->state = s;
    if (model_load(&s->models[s->model_count], "builtin:humanoid")) s->model_count++;
    char path[1024];
    const char* env = getenv("ANIMKIT_ASSETS");
    snprintf(path, sizeof path, "%s/gltf/CesiumMan/glTF-Binary/CesiumMan.glb",
             env && *env ? env : AK_SOURCE_DIR "/../shared/assets");
    if (model_load(&s->models[s->model_count], path)) s->model_count++;
    else printf("characters: CesiumMan not found at %s (set ANIMKIT_ASSETS): builtin:humanoid only\n", path);
    if (s->model_count == 0) return false;
    s->chars = calloc(count, sizeof(character));
    if (!s->chars) return false;
    s->count = count;
    ak_rng r = ak_rng_make(99);
    for (size_t i = 0; i < count; ++i) {
        character* c = &s->chars[i];
        c->m = &s->models[i % (size_t)s->model_count];
        const ak_scene* sc = c->m->scene;
        c->clip = sc->clips[ak_rng_u32(&r) % sc->clip_count];
        c->time = ak_rng_range(&r, 0.0f, ak_clip_duration(c->clip));
        c->rate = ak_rng_range(&r, 0.8f, 1.2f);
        const size_t cn = ak_clip_cursor_storage_count(c->clip);
        c->cursor_storage = calloc(cn + 1, sizeof(uint32_t));
        const size_t v = c->m->mesh->vertex_count;
        c->out_p = malloc(v * sizeof(ak_vec3)), c->out_n = malloc(v * sizeof(ak_vec3));
        if (!c->cursor_storage || !c->out_p || !c->out_n) return false;
        ak_clip_cursor_init(&c->cursor, c->clip, (ak_u32_span){c->cursor_storage, cn});
    }
    return true;
}

static bool chars_step(workload* w, uint32_t threads) {
    crowd_state* s = (crowd_state*)w->state;
    char_task tasks[AKP_TASKS_MAX];
    if (threads > AKP_TASKS_MAX) threads = AKP_TASKS_MAX;
    for (uint32_t t = 0; t < threads; ++t)
        tasks[t] = (char_task){s, s->count * t / threads, s->count * (t + 1) / threads, false};
    akp_run_tasks(char_thread, tasks, sizeof(char_task), threads);
    bool ok = true;
    for (uint32_t t = 0; t < threads; ++t) ok = ok && tasks[t].ok;
    return ok;
}

static void chars_fini(workload* w) {
    crowd_state* s = (crowd_state*)w->state;
    if (!s) return;
    for (size_t i = 0; s->chars && i < s->count; ++i)
        free(s->chars[i].cursor_storage), free(s->chars[i].out_p), free(s->chars[i].out_n);
    free(s->chars);
    for (int k = 0; k < s->model_count; ++k) ak_scene_destroy(s->models[k].scene);
    free(s);
}

/* ---- CPU-time profile ------------------------------------------------------------------------- */

typedef struct cpu_profile {
    double serial_ms, parallel_ms, critical_ms; /* per step */
    double steady_ms;                           /* the persistent part of serial_ms (tasks.h) */
    size_t phase_count;
    akp_phase_cpu phases[AKP_PHASES_MAX];
} cpu_profile;

static bool profile_cpu(workload* w, uint32_t threads, int steps, cpu_profile* out) {
    bool ok = w->step(w, threads); /* warm-up: scratch sized, team grown */
    akp_tasks_profile_enable(true);
    for (int s = 0; s < steps; ++s) {
        akp_tasks_profile_step();
        ok = w->step(w, threads) && ok;
    }
    out->phase_count = akp_tasks_profile_phases(out->phases, AKP_PHASES_MAX);
    akp_tasks_profile_enable(false);
    out->serial_ms = out->parallel_ms = out->critical_ms = out->steady_ms = 0.0;
    for (size_t k = 0; k < out->phase_count; ++k) {
        akp_phase_cpu* p = &out->phases[k];
        p->serial_s *= 1e3 / steps, p->parallel_s *= 1e3 / steps, p->critical_s *= 1e3 / steps; /* ms per step */
        p->steady_serial_s *= 1e3 / steps;
        out->serial_ms += p->serial_s, out->parallel_ms += p->parallel_s, out->critical_ms += p->critical_s;
        out->steady_ms += p->steady_serial_s;
    }
    return ok;
}

static void cpu_report(workload* w, const uint32_t* counts, int count_n, int steps, bool phases) {
    cpu_profile* pr = malloc(sizeof *pr);
    if (!pr) return;
    profile_cpu(w, 1, steps, pr);
    const double cpu1 = pr->serial_ms + pr->parallel_ms;
    double sf = -1.0, sf_steady = 0.0; /* the serial fractions at the first T > 1 */
    printf("  cpu %-10s %7s %9s %9s %9s %9s %8s %8s %9s %8s\n", "", "threads", "cpu ms", "serial", "parallel", "critical",
           "amdahl", "critical", "steady", "amdahl-s");
    printf("  cpu %-10s %7u %9.2f\n", w->name, 1u, cpu1);
    for (int k = 0; k < count_n; ++k) {
        const uint32_t T = counts[k];
        if (T < 2) continue;
        const bool ok = profile_cpu(w, T, steps, pr);
        const double total = pr->serial_ms + pr->parallel_ms;
        if (sf < 0.0) {
            sf = total > 0.0 ? pr->serial_ms / total : 0.0;
            sf_steady = total > 0.0 ? pr->steady_ms / total : 0.0;
            if (phases) {
                for (size_t i = 0; i < pr->phase_count; ++i) {
                    const akp_phase_cpu* p = &pr->phases[i];
                    if (p->serial_s + p->parallel_s < 0.005 * total) continue; /* under 0.5% */
                    printf("  cpu %-10s   phase %2zu x%-2u serial %8.3f ms  parallel %8.3f ms  steady %8.3f ms\n", w->name, i,
                           p->threads, p->serial_s, p->parallel_s, p->steady_serial_s);
                }
            }
        }
        const double amdahl = 1.0 / (T * (sf + (1.0 - sf) / T));
        const double amdahl_s = 1.0 / (T * (sf_steady + (1.0 - sf_steady) / T));
        const double crit = pr->critical_ms > 0.0 ? cpu1 / (T * pr->critical_ms) : 0.0;
        printf("  cpu %-10s %7u %9.2f %9.2f %9.2f %9.2f %7.0f%% %7.0f%% %9.2f %7.0f%%%s\n", w->name, T, total,
               pr->serial_ms, pr->parallel_ms, pr->critical_ms, 100.0 * amdahl, 100.0 * crit, pr->steady_ms,
               100.0 * amdahl_s, ok ? "" : "  (a step failed)");
        fflush(stdout);
    }
    free(pr);
}

/* ---- driver --------------------------------------------------------------------------------- */

static bool in_list(const char* list, const char* name) {
    if (!list) return true;
    const size_t len = strlen(name);
    for (const char* p = list; *p;) {
        const char* e = strchr(p, ',');
        const size_t l = e ? (size_t)(e - p) : strlen(p);
        if (l == len && strncmp(p, name, l) == 0) return true;
        p += l + (e ? 1 : 0);
    }
    return false;
}

int main(int argc, char** argv) {
    uint32_t counts[MAX_COUNTS] = {1, 2};
    int count_n = 2, steps = 0, cpu_steps = 0;
    uint32_t cpu_counts[MAX_COUNTS] = {2, 16};
    int cpu_n = 2;
    bool cpu = false, phases = false;
    const char* only = NULL;
    bool quick = bench_quick();
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            count_n = 0;
            for (char* p = argv[++i]; *p && count_n < MAX_COUNTS;) {
                const long v = strtol(p, &p, 10);
                if (v < 1 || v > (long)AKP_TASKS_MAX) {
                    fprintf(stderr, "bench_scaling: thread counts are 1..%u\n", AKP_TASKS_MAX);
                    return 2;
                }
                counts[count_n++] = (uint32_t)v;
                if (*p == ',') ++p;
            }
        } else if (strcmp(argv[i], "--cpu-threads") == 0 && i + 1 < argc) {
            cpu = true, cpu_n = 0;
            for (char* p = argv[++i]; *p && cpu_n < MAX_COUNTS;) {
                const long v = strtol(p, &p, 10);
                if (v < 1 || v > (long)AKP_TASKS_MAX) {
                    fprintf(stderr, "bench_scaling: thread counts are 1..%u\n", AKP_TASKS_MAX);
                    return 2;
                }
                cpu_counts[cpu_n++] = (uint32_t)v;
                if (*p == ',') ++p;
            }
        } else if (strcmp(argv[i], "--cpu-steps") == 0 && i + 1 < argc) {
            cpu = true, cpu_steps = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--cpu") == 0) {
            cpu = true;
        } else if (strcmp(argv[i], "--phases") == 0) {
            cpu = phases = true;
        } else if (strcmp(argv[i], "--only") == 0 && i + 1 < argc) {
            only = argv[++i];
        } else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
            steps = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--quick") == 0) {
            quick = true;
        } else {
            fprintf(stderr, "usage: bench_scaling [--threads 1,2,4,8,16] [--cpu] [--cpu-threads 2,16] [--cpu-steps N] [--phases] [--only NAME,...] "
                            "[--steps N] [--quick]\n");
            return 2;
        }
    }
    if (count_n == 0 || counts[0] != 1) {
        fprintf(stderr, "bench_scaling: the thread list starts with 1 (the reference)\n");
        return 2;
    }
    workload all[] = {
        {"boids100k", quick ? 10000 : 100000, NULL, boids_init, boids_step, boids_fini},
        {"boids1m", quick ? 20000 : 1000000, NULL, boids_init, boids_step, boids_fini},
        {"pbf55k", quick ? 5000 : 55000, NULL, pbf_init, pbf_step, pbf_fini},
        {"pbf500k", quick ? 10000 : 500000, NULL, pbf_init, pbf_step, pbf_fini},
        {"cloth256", quick ? 64 : 256, NULL, cloth_init, cloth_step, cloth_fini},
        {"cloth512", quick ? 96 : 512, NULL, cloth_init, cloth_step, cloth_fini},
        {"lbs1m", quick ? 50000 : 1000000, NULL, lbs_init, lbs_step, lbs_fini},
        {"characters", quick ? 50 : 1000, NULL, chars_init, chars_step, chars_fini},
    };
    printf("scaling: median wall ms per step over %s steps after 2 warm-up steps, threads", steps ? "N" : "8-20");
    for (int k = 0; k < count_n; ++k) printf(" %u", counts[k]);
    printf("%s\n", quick ? " (quick: small sizes)" : "");
    printf("%-10s %9s %7s %10s %8s %6s %9s %10s %8s %9s\n", "workload", "size", "threads", "ms/step", "speedup", "eff",
           "sect/step", "serial ms", "idle", "amdahl16");
    for (size_t wi = 0; wi < sizeof all / sizeof all[0]; ++wi) {
        workload* w = &all[wi];
        if (!in_list(only, w->name)) continue;
        const size_t requested = w->size;
        if (!w->init(w, w->size)) {
            printf("%-10s could not be set up (memory or assets)\n", w->name);
            w->fini(w);
            continue;
        }
        const int n_steps = steps > 0 ? steps : (requested >= 500000 ? 8 : 20);
        double ms1 = 0.0;
        for (int k = 0; k < count_n; ++k) {
            const uint32_t T = counts[k];
            for (int s = 0; s < 2; ++s) w->step(w, T);
            double t[256];
            const int m = n_steps < 256 ? n_steps : 256;
            bool ok = true;
            for (int s = 0; s < m; ++s) {
                const double t0 = bench_wall_s();
                ok = w->step(w, T) && ok;
                t[s] = (bench_wall_s() - t0) * 1e3;
            }
            const double ms = bench_percentile(t, (size_t)m, 0.5);
            if (T == 1) ms1 = ms;
            /* the profiled run: a few more steps with the counters on */
            const int pm = m < 6 ? m : 6;
            akp_tasks_profile_enable(true);
            const double p0 = bench_wall_s();
            for (int s = 0; s < pm; ++s) ok = w->step(w, T) && ok;
            const double pwall = (bench_wall_s() - p0) * 1e3 / pm;
            akp_tasks_profile pr;
            akp_tasks_profile_read(&pr);
            akp_tasks_profile_enable(false);
            /* thread-time spent waiting: the other threads during the caller's serial parts,
             * the caller at the end of sections, everyone at barriers */
            const double serial = T > 1 ? pwall - pr.section_seconds * 1e3 / pm : pwall;
            const double idle = T > 1 ? ((T - 1) * serial + (pr.caller_wait_seconds + pr.barrier_wait_seconds) * 1e3 / pm) /
                                            (T * pwall)
                                      : 0.0;
            char amdahl[32] = "";
            if (T == 2 && idle < 0.5) {
                /* the serial fraction s that explains the idle time at 2 threads:
                 * efficiency 1 - idle = 1 / (2 (s + (1 - s) / 2))  ->  s = 1 / (1 - idle) - 1 */
                const double sf = 1.0 / (1.0 - idle) - 1.0;
                snprintf(amdahl, sizeof amdahl, "%.1fx", 1.0 / (sf + (1.0 - sf) / 16.0));
            }
            printf("%-10s %9zu %7u %10.2f %7.2fx %5.0f%% %9.1f %10.2f %7.1f%% %9s%s\n", w->name, w->size, T, ms, ms1 / ms,
                   100.0 * ms1 / ms / T, (double)pr.sections / pm, T > 1 ? serial : 0.0, 100.0 * idle, amdahl,
                   ok ? "" : "  (a step failed)");
            fflush(stdout);
        }
        if (cpu) cpu_report(w, cpu_counts, cpu_n, cpu_steps > 0 ? cpu_steps : n_steps < 6 ? n_steps : 6, phases);
        w->fini(w);
    }
    return 0;
}
