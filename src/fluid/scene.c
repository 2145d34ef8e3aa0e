/* animkit fluid: scene files (strict JSON through src/json.h) and the built-in presets. */
#include <animkit/fluid.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

void ak_fluid_scene_defaults(ak_fluid_scene* s) {
    memset(s, 0, sizeof *s);
    s->desc.solver = AK_FLUID_PBF;
    s->desc.particle_mass = 0.001f;
    s->desc.rest_density = 1000.0f;
    s->desc.gravity = ak_vec3_make(0.0f, -9.81f, 0.0f);
    s->desc.iterations = 4;
    s->desc.xsph_c = 0.01f;
    s->desc.stiffness = 20.0f;
    s->desc.sound_speed = 20.0f;
    s->desc.tait_gamma = 7.0f;
    s->h_ratio = 2.0f;
    s->duration = 1.0f;
    s->steps = -1;
}

float ak_fluid_scene_default_dt(ak_fluid_solver solver) {
    return solver == AK_FLUID_PBF ? 1.0f / 400.0f : solver == AK_FLUID_SPH ? 1e-3f : 2e-4f;
}

long ak_fluid_scene_steps(const ak_fluid_scene* s) {
    if (s->steps >= 0) return s->steps;
    const double k = ceil((double)s->duration / (double)s->dt - 1e-3); /* 1 s / 0.0025f is 400.00001 */
    return k < 1.0 ? 1 : k > (double)AK_FLUID_SCENE_MAX_STEPS ? AK_FLUID_SCENE_MAX_STEPS : (long)k;
}

static float lattice_spacing(const ak_fluid_scene* s) { return ak_fluid_rest_spacing(&s->desc); }

/* Lattice points of a block (0 when empty), as ak_fluid_fill_box counts them, in double. */
static double block_count_d(const ak_fluid_scene* s, const ak_fluid_block* b) {
    const double sp = lattice_spacing(s);
    if (!(sp > 0.0)) return 0.0;
    double ex = floor(((double)b->max.x - b->min.x) / sp + 1e-4), ey = floor(((double)b->max.y - b->min.y) / sp + 1e-4),
           ez = floor(((double)b->max.z - b->min.z) / sp + 1e-4);
    if (!(ex >= 1.0 && ey >= 1.0 && ez >= 1.0)) return 0.0;
    return ex * ey * ez;
}

size_t ak_fluid_scene_initial_count(const ak_fluid_scene* s) {
    double n = 0.0;
    for (size_t k = 0; k < s->block_count; ++k) n += block_count_d(s, &s->blocks[k]);
    return n > (double)AK_FLUID_SCENE_MAX_PARTICLES ? (size_t)AK_FLUID_SCENE_MAX_PARTICLES + 1 : (size_t)n;
}

size_t ak_fluid_scene_capacity(const ak_fluid_scene* s) {
    size_t n = ak_fluid_scene_initial_count(s);
    if (s->max_particles > 0) return (size_t)s->max_particles > n ? (size_t)s->max_particles : n;
    return n + (s->emitter_count ? 20000u : 0u);
}

size_t ak_fluid_scene_fill(const ak_fluid_scene* s, ak_vec3* positions, ak_vec3* velocities, size_t cap) {
    size_t n = 0;
    for (size_t k = 0; k < s->block_count && n < cap; ++k) {
        const ak_fluid_block* b = &s->blocks[k];
        size_t got = ak_fluid_fill_box(&s->desc, b->min, b->max, (ak_vec3_span){positions + n, cap - n});
        if (got > cap - n) got = cap - n;
        for (size_t i = 0; i < got; ++i) velocities[n + i] = b->velocity;
        n += got;
    }
    return n;
}

static bool parse_vec_in(akp_json* j, const cJSON* o, const char* path, const char* key, ak_vec3* v) {
    return akp_json_vec3(j, o, path, key, v);
}

static bool parse(akp_json* j, const char* text, size_t size, ak_fluid_scene* out) {
    ak_fluid_scene_defaults(out);
    cJSON* root = akp_json_parse(j, text, size);
    if (!root) return false;
    static const char* const keys[] = {"solver", "particle_mass", "rest_density", "h_ratio", "gravity", "dt",
                                       "duration", "steps", "iterations", "relaxation", "bilateral", "scorr", "scorr_k",
                                       "scorr_n", "scorr_dq", "xsph", "vorticity", "stiffness", "viscosity",
                                       "sound_speed", "tait_gamma", "box", "friction", "max_neighbours",
                                       "max_particles", "blocks", "colliders", "emitters", "sinks", NULL};
    static const char* const solvers[] = {"pbf", "sph", "wcsph", NULL};
    ak_fluid_scene* s = out;
    ak_fluid_desc* d = &s->desc;
    akp_json_object(j, root, "", keys);
    int solver = 0;
    akp_json_enum(j, root, "", "solver", solvers, &solver);
    d->solver = (ak_fluid_solver)solver;
    akp_json_float(j, root, "", "particle_mass", 1e-9f, 1e6f, &d->particle_mass);
    akp_json_float(j, root, "", "rest_density", 1e-3f, 1e6f, &d->rest_density);
    akp_json_float(j, root, "", "h_ratio", 1.0f, 6.0f, &s->h_ratio);
    parse_vec_in(j, root, "", "gravity", &d->gravity);
    if (cJSON_GetObjectItemCaseSensitive(root, "dt")) s->dt_set = true;
    akp_json_float(j, root, "", "dt", 1e-7f, 1.0f, &s->dt);
    akp_json_float(j, root, "", "duration", 1e-6f, 1e6f, &s->duration);
    akp_json_int(j, root, "", "steps", 0, AK_FLUID_SCENE_MAX_STEPS, &s->steps);
    long it = d->iterations;
    akp_json_int(j, root, "", "iterations", 1, 1000, &it);
    d->iterations = (uint32_t)it;
    akp_json_float(j, root, "", "relaxation", 0.0f, 1e30f, &d->relaxation);
    akp_json_bool(j, root, "", "bilateral", &d->bilateral);
    akp_json_bool(j, root, "", "scorr", &d->scorr);
    akp_json_float(j, root, "", "scorr_k", 0.0f, 10.0f, &d->scorr_k);
    akp_json_float(j, root, "", "scorr_n", 0.0f, 16.0f, &d->scorr_n);
    akp_json_float(j, root, "", "scorr_dq", 0.0f, 0.99f, &d->scorr_dq);
    akp_json_float(j, root, "", "xsph", 0.0f, 1.0f, &d->xsph_c);
    akp_json_float(j, root, "", "vorticity", -1e6f, 1e6f, &d->vorticity_epsilon);
    akp_json_float(j, root, "", "stiffness", 0.0f, 1e9f, &d->stiffness);
    akp_json_float(j, root, "", "viscosity", 0.0f, 1e6f, &d->viscosity);
    akp_json_float(j, root, "", "sound_speed", 0.0f, 1e5f, &d->sound_speed);
    akp_json_float(j, root, "", "tait_gamma", 0.0f, 100.0f, &d->tait_gamma);
    akp_json_float(j, root, "", "friction", 0.0f, 1.0f, &d->friction);
    long mn = 0;
    akp_json_int(j, root, "", "max_neighbours", 0, 4096, &mn);
    d->max_neighbours = (uint32_t)mn;
    akp_json_int(j, root, "", "max_particles", 0, AK_FLUID_SCENE_MAX_PARTICLES, &s->max_particles);
    const cJSON* box = akp_json_member(j, root, "", "box");
    if (box) {
        static const char* const bkeys[] = {"min", "max", NULL};
        akp_json_object(j, box, "box", bkeys);
        if (!j->failed && (!cJSON_GetObjectItemCaseSensitive(box, "min") || !cJSON_GetObjectItemCaseSensitive(box, "max")))
            akp_json_fail(j, "box", NULL, "needs both \"min\" and \"max\"");
        parse_vec_in(j, box, "box", "min", &d->box_min);
        parse_vec_in(j, box, "box", "max", &d->box_max);
        if (!j->failed && (d->box_min.x >= d->box_max.x || d->box_min.y >= d->box_max.y || d->box_min.z >= d->box_max.z))
            akp_json_fail(j, "box", NULL, "min must be below max on every axis");
    }
    char path[64];
    size_t count = 0;
    const cJSON* e = akp_json_array(j, root, "", "blocks", AK_FLUID_SCENE_MAX_ITEMS, &count);
    for (size_t k = 0; e && k < count && !j->failed; ++k, e = e->next) {
        static const char* const kk[] = {"min", "max", "velocity", NULL};
        akp_json_index(path, sizeof path, "blocks", k);
        ak_fluid_block* b = &s->blocks[k];
        memset(b, 0, sizeof *b);
        if (!akp_json_object(j, e, path, kk)) break;
        if (!cJSON_GetObjectItemCaseSensitive(e, "min") || !cJSON_GetObjectItemCaseSensitive(e, "max")) {
            akp_json_fail(j, path, NULL, "needs both \"min\" and \"max\"");
            break;
        }
        parse_vec_in(j, e, path, "min", &b->min);
        parse_vec_in(j, e, path, "max", &b->max);
        parse_vec_in(j, e, path, "velocity", &b->velocity);
        s->block_count = k + 1;
    }
    e = akp_json_array(j, root, "", "colliders", AK_FLUID_SCENE_MAX_ITEMS, &count);
    for (size_t k = 0; e && k < count && !j->failed; ++k, e = e->next) {
        static const char* const kk[] = {
            "shape", "a", "b", "normal", "radius", "velocity", "half_extents", "orientation", NULL};
        static const char* const shapes[] = {"plane", "sphere", "capsule", "box", NULL};
        akp_json_index(path, sizeof path, "colliders", k);
        ak_fluid_collider* c = &s->colliders[k];
        memset(c, 0, sizeof *c);
        c->normal = ak_vec3_make(0.0f, 1.0f, 0.0f);
        if (!akp_json_object(j, e, path, kk)) break;
        if (!cJSON_GetObjectItemCaseSensitive(e, "shape")) {
            akp_json_fail(j, path, "shape", "required (plane, sphere, capsule or box)");
            break;
        }
        int shape = 0;
        akp_json_enum(j, e, path, "shape", shapes, &shape);
        c->shape = (ak_fluid_shape)shape;
        parse_vec_in(j, e, path, "a", &c->a);
        parse_vec_in(j, e, path, "b", &c->b);
        parse_vec_in(j, e, path, "normal", &c->normal);
        akp_json_float(j, e, path, "radius", 0.0f, 1e6f, &c->radius);
        parse_vec_in(j, e, path, "velocity", &c->velocity);
        float hq[4] = {0, 0, 0, 1};
        if (!j->failed && c->shape == AK_FLUID_BOX) {
            if (!cJSON_GetObjectItemCaseSensitive(e, "half_extents")) {
                akp_json_fail(j, path, "half_extents", "required for a box");
                break;
            }
            akp_json_floats(j, e, path, "half_extents", 3, 0.0f, 1e6f, &c->half_extents.x);
            akp_json_floats(j, e, path, "orientation", 4, -1e3f, 1e3f, hq);
            if (!j->failed && hq[0] == 0.0f && hq[1] == 0.0f && hq[2] == 0.0f && hq[3] == 0.0f)
                akp_json_fail(j, path, "orientation", "is the zero quaternion");
        } else if (!j->failed && (cJSON_GetObjectItemCaseSensitive(e, "half_extents") ||
                                  cJSON_GetObjectItemCaseSensitive(e, "orientation"))) {
            akp_json_fail(j, path,
                          cJSON_GetObjectItemCaseSensitive(e, "half_extents") ? "half_extents"
                                                                              : "orientation",
                          "only a box has it");
        }
        c->orientation = ak_quat_normalize(ak_quat_make(hq[0], hq[1], hq[2], hq[3]));
        if (!j->failed && c->shape == AK_FLUID_PLANE && ak_vec3_length_sq(c->normal) == 0.0f)
            akp_json_fail(j, path, "normal", "must not be zero");
        s->collider_count = k + 1;
    }
    e = akp_json_array(j, root, "", "emitters", AK_FLUID_SCENE_MAX_ITEMS, &count);
    for (size_t k = 0; e && k < count && !j->failed; ++k, e = e->next) {
        static const char* const kk[] = {"position", "direction", "radius", "speed", "start", "stop", NULL};
        akp_json_index(path, sizeof path, "emitters", k);
        ak_fluid_emitter* m = &s->emitters[k];
        memset(m, 0, sizeof *m);
        m->direction = ak_vec3_make(0.0f, -1.0f, 0.0f);
        m->radius = 0.03f;
        m->speed = 1.0f;
        if (!akp_json_object(j, e, path, kk)) break;
        parse_vec_in(j, e, path, "position", &m->position);
        parse_vec_in(j, e, path, "direction", &m->direction);
        akp_json_float(j, e, path, "radius", 0.0f, 100.0f, &m->radius);
        akp_json_float(j, e, path, "speed", 1e-3f, 1e4f, &m->speed);
        akp_json_float(j, e, path, "start", 0.0f, 1e6f, &m->start_time);
        akp_json_float(j, e, path, "stop", 0.0f, 1e6f, &m->stop_time);
        if (!j->failed && ak_vec3_length_sq(m->direction) == 0.0f) akp_json_fail(j, path, "direction", "must not be zero");
        s->emitter_count = k + 1;
    }
    e = akp_json_array(j, root, "", "sinks", AK_FLUID_SCENE_MAX_ITEMS, &count);
    for (size_t k = 0; e && k < count && !j->failed; ++k, e = e->next) {
        static const char* const kk[] = {"min", "max", NULL};
        akp_json_index(path, sizeof path, "sinks", k);
        ak_fluid_sink* sk = &s->sinks[k];
        memset(sk, 0, sizeof *sk);
        if (!akp_json_object(j, e, path, kk)) break;
        parse_vec_in(j, e, path, "min", &sk->min);
        parse_vec_in(j, e, path, "max", &sk->max);
        if (!j->failed && (sk->min.x > sk->max.x || sk->min.y > sk->max.y || sk->min.z > sk->max.z))
            akp_json_fail(j, path, NULL, "min [%g, %g, %g] is above max [%g, %g, %g] on some axis", (double)sk->min.x,
                          (double)sk->min.y, (double)sk->min.z, (double)sk->max.x, (double)sk->max.y, (double)sk->max.z);
        s->sink_count = k + 1;
    }
    cJSON_Delete(root);
    if (j->failed) return false;
    d->h = s->h_ratio * lattice_spacing(s);
    if (!s->dt_set) s->dt = ak_fluid_scene_default_dt(d->solver);
    const size_t n0 = ak_fluid_scene_initial_count(s);
    if (n0 > AK_FLUID_SCENE_MAX_PARTICLES)
        return akp_json_fail(j, "blocks", NULL, "the blocks hold more than %u particles", AK_FLUID_SCENE_MAX_PARTICLES);
    if (n0 == 0 && s->emitter_count == 0)
        return akp_json_fail(j, "blocks", NULL, "no particles: give a block of at least one rest spacing (%.4g m) or an emitter",
                             (double)lattice_spacing(s));
    if (s->max_particles > 0 && (size_t)s->max_particles < n0)
        return akp_json_fail(j, "max_particles", NULL, "%ld is below the %zu particles of the blocks", s->max_particles, n0);
    /* a neighbour list of 4096 entries per particle bounds the scratch by 16 KiB per particle */
    if (ak_fluid_scratch_size(ak_fluid_scene_capacity(s), d) == 0)
        return akp_json_fail(j, "h_ratio", NULL, "no valid solver setup for these values");
    return true;
}

static bool preset_fill(const char* name, long count, ak_fluid_scene* out) {
    ak_fluid_scene_defaults(out);
    ak_fluid_scene* s = out;
    if (count <= 0) count = 4000;
    if (count > (long)AK_FLUID_SCENE_MAX_PARTICLES) count = AK_FLUID_SCENE_MAX_PARTICLES;
    const float sp = lattice_spacing(s);
    s->desc.h = s->h_ratio * sp;
    s->dt = 1.0f / 400.0f;
    if (strcmp(name, "dam") == 0) {
        /* a block 1 : 2 : 1 against one wall of a box four times as long */
        int k = (int)ceil(cbrt((double)count / 2.0));
        const float w = k * sp;
        s->blocks[0] = (ak_fluid_block){.min = {0, 0, 0}, .max = {w, 2 * w, w}};
        s->block_count = 1;
        s->desc.box_max = ak_vec3_make(4 * w, 3 * w, w);
    } else if (strcmp(name, "pour") == 0) {
        /* a nozzle pouring into an empty box over a sphere; count is the capacity */
        const float w = 0.3f;
        s->desc.box_max = ak_vec3_make(w, w, w);
        s->emitters[0] = (ak_fluid_emitter){.position = {0.5f * w, 0.9f * w, 0.5f * w}, .direction = {0.2f, -1, 0},
                                            .radius = 2.5f * sp, .speed = 1.0f};
        s->emitter_count = 1;
        s->colliders[0] = (ak_fluid_collider){.shape = AK_FLUID_SPHERE, .a = {0.55f * w, 0.3f * w, 0.5f * w},
                                              .radius = 0.15f * w};
        s->collider_count = 1;
        s->max_particles = count;
    } else if (strcmp(name, "splash") == 0) {
        /* a cube of liquid dropped into a pool across a capsule (a limb) */
        int k = (int)ceil(cbrt((double)count / 3.0));
        const float w = k * sp;
        s->desc.box_max = ak_vec3_make(3 * w, 4 * w, w * 1.5f);
        s->blocks[0] = (ak_fluid_block){.min = {0, 0, 0}, .max = {3 * w, 0.5f * w, 1.5f * w}};
        s->blocks[1] = (ak_fluid_block){.min = {w, 2.2f * w, 0.25f * w}, .max = {2 * w, 3.2f * w, 1.25f * w},
                                     .velocity = {0, -1, 0}};
        s->block_count = 2;
        s->colliders[0] = (ak_fluid_collider){.shape = AK_FLUID_CAPSULE, .a = {0.6f * w, 1.2f * w, 0.75f * w},
                                              .b = {2.4f * w, 1.4f * w, 0.75f * w}, .radius = 0.15f * w};
        s->collider_count = 1;
    } else {
        return false;
    }
    return true;
}

ak_result ak_fluid_scene_load_bytes(const void* bytes, size_t size, const char* name, ak_fluid_scene* out_scene,
                                   ak_diag* out_diag) {
    if (!out_scene) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, name ? name : "(scene)", "no scene to fill");
    akp_json j = {.file = name ? name : "(scene)"};
    if (!bytes && size) {
        ak_fluid_scene_defaults(out_scene);
        return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no bytes");
    }
    if (!parse(&j, bytes ? (const char*)bytes : "", size, out_scene)) {
        ak_fluid_scene_defaults(out_scene);
        return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_fluid_scene_load_file(const char* path, ak_fluid_scene* out_scene, ak_diag* out_diag) {
    if (!out_scene || !path) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, path ? path : "(scene)", "no path or scene");
    ak_fluid_scene_defaults(out_scene);
    akp_json j = {.file = path};
    size_t size = 0;
    char* text = akp_json_read_file(&j, path, 0, &size);
    if (!text) return akp_json_diag(&j, AK_ERR_IO, out_diag);
    ak_result r = ak_fluid_scene_load_bytes(text, size, path, out_scene, out_diag);
    free(text);
    return r;
}

ak_result ak_fluid_scene_preset(const char* name, long count, ak_fluid_scene* out_scene, ak_diag* out_diag) {
    if (!out_scene || !name) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "preset", "no name or scene");
    if (!preset_fill(name, count, out_scene)) {
        ak_fluid_scene_defaults(out_scene);
        return akp_diag_set(out_diag, AK_ERR_NOT_FOUND, name, "unknown preset (allowed: " AK_FLUID_SCENE_PRESETS ")");
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

void ak_fluid_scene_free(ak_fluid_scene* scene) {
    if (scene) ak_fluid_scene_defaults(scene);
}
