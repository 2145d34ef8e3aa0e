/* animkit boids: scene files (strict JSON through src/json.h) and presets (keys and defaults:
 * docs/boids.md). */
#include <animkit/boids.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

void ak_boids_scene_defaults(ak_boids_scene* s) {
    memset(s, 0, sizeof *s);
    static const ak_vec4 palette[4] = {{0.93f, 0.55f, 0.20f, 1}, {0.25f, 0.45f, 0.80f, 1}, {0.35f, 0.70f, 0.35f, 1},
                                       {0.75f, 0.30f, 0.55f, 1}};
    for (int k = 0; k < AK_BOIDS_MAX_SPECIES; ++k) {
        /* Why these values (docs/boids.md, "Defaults"): min_speed keeps the flock flying (alignment
         * matches velocities, and the mean of unaligned velocities is short, so without a floor a
         * flock slows to a stall); a gentle max_force and a wide, soft steer band turn a flock as
         * a whole instead of folding it against a wall; separation out to 1.5 m keeps it spread. */
        s->species[k] = (ak_boids_species){.max_speed = 4, .min_speed = 2, .max_force = 4, .separation_weight = 3,
                                           .separation_radius = 1.5f, .alignment_weight = 3, .alignment_radius = 2.5f,
                                           .cohesion_weight = 0.6f, .cohesion_radius = 2.5f, .view_angle = 270,
                                           .avoid_weight = 6, .avoid_distance = 2, .bounds_weight = 0.5f};
        s->color[k] = palette[k % 4];
    }
    s->params.species = s->species;
    s->params.species_count = 1;
    s->params.bounds_min = ak_vec3_make(-10, -10, -10);
    s->params.bounds_max = ak_vec3_make(10, 10, 10);
    s->params.bounds = AK_BOIDS_BOUNDS_STEER;
    s->params.bounds_margin = 5;
    s->params.leader_distance = 1;
    s->count = 500;
    s->steps = 2000;
    s->dt = 0.02f;
    s->seed = 1;
    s->shape_size = 0.5f;
}

void ak_boids_scene_scale_bounds(ak_boids_scene* s, size_t count) {
    if (s->bounds_given || count <= AK_BOIDS_SCENE_BOX_AGENTS) return;
    const double r = (double)count / AK_BOIDS_SCENE_BOX_AGENTS;
    const float k = (float)(s->params.planar ? sqrt(r) : cbrt(r));
    s->params.bounds_min = ak_vec3_scale(s->params.bounds_min, k);
    s->params.bounds_max = ak_vec3_scale(s->params.bounds_max, k);
}

static int preset_fill(const char* name, ak_boids_scene* s) {
    if (strcmp(name, "flock") == 0) return 0;
    if (strcmp(name, "obstacles") == 0) {
        /* A sphere in the middle and four pillars through the whole box, in the flock's way. */
        static const ak_boids_obstacle obs[5] = {
            {.kind = AK_BOIDS_SPHERE, .center = {0, 0, 0}, .radius = 2.5f},
            {.kind = AK_BOIDS_BOX, .center = {-5, 0, -5}, .half_extents = {0.6f, 10, 0.6f}},
            {.kind = AK_BOIDS_BOX, .center = {5, 0, -5}, .half_extents = {0.6f, 10, 0.6f}},
            {.kind = AK_BOIDS_BOX, .center = {-5, 0, 5}, .half_extents = {0.6f, 10, 0.6f}},
            {.kind = AK_BOIDS_BOX, .center = {5, 0, 5}, .half_extents = {0.6f, 10, 0.6f}},
        };
        s->obstacles = malloc(sizeof obs);
        if (!s->obstacles) return 1;
        memcpy(s->obstacles, obs, sizeof obs);
        s->params.obstacles = s->obstacles;
        s->params.obstacle_count = 5;
        return 0;
    }
    if (strcmp(name, "predator") == 0) {
        /* The flock flees from 0.6% predators (3 of 500) that chase the nearest bird. */
        s->params.species_count = 2;
        ak_boids_species* prey = &s->species[0];
        prey->flee_mask = 1u << 1;
        prey->flee_weight = 1;
        prey->flee_radius = 6;
        ak_boids_species* hunter = &s->species[1];
        hunter->max_speed = 4.5f;
        hunter->separation_radius = 4;
        hunter->alignment_weight = 0;
        hunter->cohesion_weight = 0;
        hunter->pursue_mask = 1u << 0;
        hunter->pursue_weight = 1;
        hunter->pursue_radius = 10;
        s->fraction[1] = 0.006f;
        s->color[1] = ak_vec4_make(0.20f, 0.25f, 0.40f, 1);
        return 0;
    }
    return -1;
}

ak_result ak_boids_scene_preset(const char* name, ak_boids_scene* s, ak_diag* out_diag) {
    if (!s || !name) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "preset", "no name or scene");
    ak_boids_scene_defaults(s);
    const int bad = preset_fill(name, s);
    if (bad) {
        ak_boids_scene_free(s);
        ak_boids_scene_defaults(s);
        if (bad > 0) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
        return akp_diag_set(out_diag, AK_ERR_NOT_FOUND, name, "unknown preset (allowed: " AK_BOIDS_SCENE_PRESETS ")");
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

void ak_boids_scene_free(ak_boids_scene* s) {
    if (!s) return;
    free(s->obstacles);
    free(s->positions);
    free(s->velocities);
    free(s->agent_species);
    s->obstacles = NULL;
    s->positions = s->velocities = NULL;
    s->agent_species = NULL;
    s->agent_count = 0;
    s->params.obstacles = NULL;
    s->params.obstacle_count = 0;
}

/* An array of species indices -> a bit mask. */
static bool read_mask(akp_json* j, const cJSON* obj, const char* path, const char* key, uint32_t species_count,
                      uint32_t* out) {
    size_t n = 0;
    const cJSON* e = akp_json_array(j, obj, path, key, AK_BOIDS_MAX_SPECIES, &n);
    if (j->failed) return false;
    char p[128];
    akp_json_key(p, sizeof p, path, key);
    uint32_t m = 0;
    for (size_t i = 0; e && i < n; ++i, e = e->next) {
        /* Range first: the integrality test casts, and a cast of an out-of-range double is UB. */
        if (!cJSON_IsNumber(e) || !(e->valuedouble >= 0 && e->valuedouble < (double)species_count) ||
            e->valuedouble != (double)(long)e->valuedouble) {
            char q[160];
            return akp_json_fail(j, akp_json_index(q, sizeof q, p, i), NULL,
                                 "expected a species index in [0, %u]", species_count - 1);
        }
        m |= 1u << (uint32_t)e->valuedouble;
    }
    if (n > 0) *out = m;
    return true;
}

static bool read_species(akp_json* j, const cJSON* o, const char* path, uint32_t species_count, ak_boids_scene* s,
                         uint32_t k) {
    static const char* const keys[] = {
        "max_speed", "min_speed", "max_force", "separation_weight", "separation_radius", "alignment_weight",
        "alignment_radius", "cohesion_weight", "cohesion_radius", "view_angle", "k_nearest", "goal_weight",
        "leader_weight", "wander_weight", "wander_jitter", "avoid_weight", "avoid_distance", "bounds_weight",
        "flee", "flee_weight", "flee_radius", "pursue", "pursue_weight", "pursue_radius", "fraction", "color", NULL};
    if (!akp_json_object(j, o, path, keys)) return false;
    ak_boids_species* sp = &s->species[k];
    const float big = 1e6f;
    akp_json_float(j, o, path, "max_speed", 1e-6f, big, &sp->max_speed);
    akp_json_float(j, o, path, "min_speed", 0, big, &sp->min_speed);
    akp_json_float(j, o, path, "max_force", 1e-6f, big, &sp->max_force);
    akp_json_float(j, o, path, "separation_weight", 0, big, &sp->separation_weight);
    akp_json_float(j, o, path, "separation_radius", 1e-4f, big, &sp->separation_radius);
    akp_json_float(j, o, path, "alignment_weight", 0, big, &sp->alignment_weight);
    akp_json_float(j, o, path, "alignment_radius", 1e-4f, big, &sp->alignment_radius);
    akp_json_float(j, o, path, "cohesion_weight", 0, big, &sp->cohesion_weight);
    akp_json_float(j, o, path, "cohesion_radius", 1e-4f, big, &sp->cohesion_radius);
    akp_json_float(j, o, path, "view_angle", 0, 360, &sp->view_angle);
    long kn = (long)sp->k_nearest;
    akp_json_int(j, o, path, "k_nearest", 0, AK_BOIDS_MAX_K, &kn);
    sp->k_nearest = (uint32_t)kn;
    akp_json_float(j, o, path, "goal_weight", 0, big, &sp->goal_weight);
    akp_json_float(j, o, path, "leader_weight", 0, big, &sp->leader_weight);
    akp_json_float(j, o, path, "wander_weight", 0, big, &sp->wander_weight);
    akp_json_float(j, o, path, "wander_jitter", 1e-6f, big, &sp->wander_jitter);
    akp_json_float(j, o, path, "avoid_weight", 0, big, &sp->avoid_weight);
    akp_json_float(j, o, path, "avoid_distance", 1e-4f, big, &sp->avoid_distance);
    akp_json_float(j, o, path, "bounds_weight", 1e-6f, big, &sp->bounds_weight);
    read_mask(j, o, path, "flee", species_count, &sp->flee_mask);
    akp_json_float(j, o, path, "flee_weight", 0, big, &sp->flee_weight);
    akp_json_float(j, o, path, "flee_radius", 1e-4f, big, &sp->flee_radius);
    read_mask(j, o, path, "pursue", species_count, &sp->pursue_mask);
    akp_json_float(j, o, path, "pursue_weight", 0, big, &sp->pursue_weight);
    akp_json_float(j, o, path, "pursue_radius", 1e-4f, big, &sp->pursue_radius);
    akp_json_float(j, o, path, "fraction", 0, 1, &s->fraction[k]);
    float rgb[3] = {s->color[k].x, s->color[k].y, s->color[k].z};
    akp_json_floats(j, o, path, "color", 3, 0, 1, rgb);
    s->color[k] = ak_vec4_make(rgb[0], rgb[1], rgb[2], 1);
    if (!j->failed && sp->min_speed > sp->max_speed)
        akp_json_fail(j, path, "min_speed", "%g is above max_speed %g", (double)sp->min_speed, (double)sp->max_speed);
    return !j->failed;
}

static bool read_obstacle(akp_json* j, const cJSON* o, const char* path, ak_boids_obstacle* ob) {
    static const char* const types[] = {"sphere", "plane", "box", NULL};
    static const char* const sphere_keys[] = {"type", "center", "radius", NULL};
    static const char* const plane_keys[] = {"type", "point", "normal", NULL};
    static const char* const box_keys[] = {"type", "center", "half_extents", NULL};
    if (!cJSON_IsObject(o)) return akp_json_fail(j, path, NULL, "expected an object");
    int type = -1;
    if (!cJSON_GetObjectItemCaseSensitive(o, "type"))
        return akp_json_fail(j, path, "type", "missing (sphere, plane or box)");
    if (!akp_json_enum(j, o, path, "type", types, &type)) return false;
    memset(ob, 0, sizeof *ob);
    const float big = 1e9f;
    if (type == 0) {
        ob->kind = AK_BOIDS_SPHERE;
        ob->radius = 1;
        akp_json_object(j, o, path, sphere_keys);
        akp_json_vec3(j, o, path, "center", &ob->center);
        akp_json_float(j, o, path, "radius", 1e-4f, big, &ob->radius);
    } else if (type == 1) {
        ob->kind = AK_BOIDS_PLANE;
        ob->normal = ak_vec3_make(0, 1, 0);
        akp_json_object(j, o, path, plane_keys);
        akp_json_vec3(j, o, path, "point", &ob->center);
        akp_json_vec3(j, o, path, "normal", &ob->normal);
        if (!j->failed && !(ak_vec3_length(ob->normal) > 1e-6f))
            akp_json_fail(j, path, "normal", "must not be zero");
    } else {
        ob->kind = AK_BOIDS_BOX;
        ob->half_extents = ak_vec3_make(1, 1, 1);
        akp_json_object(j, o, path, box_keys);
        akp_json_vec3(j, o, path, "center", &ob->center);
        float h[3] = {1, 1, 1};
        akp_json_floats(j, o, path, "half_extents", 3, 1e-4f, big, h);
        ob->half_extents = ak_vec3_make(h[0], h[1], h[2]);
    }
    if (!j->failed && !(fabsf(ob->center.x) <= big && fabsf(ob->center.y) <= big && fabsf(ob->center.z) <= big))
        akp_json_fail(j, path, type == 1 ? "point" : "center", "a coordinate is beyond +-1e9");
    return !j->failed;
}

static bool vec_in(ak_vec3 v, float lim) { return fabsf(v.x) <= lim && fabsf(v.y) <= lim && fabsf(v.z) <= lim; }

static bool parse(akp_json* jp, const char* text, size_t size, ak_boids_scene* s) {
    akp_json j = *jp;
    static const char* const keys[] = {"dt",     "steps",  "seed",   "count",  "planar", "bounds", "goal",
                                       "leader", "species", "obstacles", "agents", "render", NULL};
    cJSON* root = akp_json_parse(&j, text, size);
    if (root) {
        akp_json_object(&j, root, "", keys);
        akp_json_float(&j, root, "", "dt", 1e-6f, 10.0f, &s->dt);
        akp_json_int(&j, root, "", "steps", 0, 100000000, &s->steps);
        akp_json_int(&j, root, "", "seed", 0, 2147483647, &s->seed);
        long count = (long)s->count;
        akp_json_int(&j, root, "", "count", 1, AK_BOIDS_SCENE_MAX_AGENTS, &count);
        s->count = (size_t)count;
        akp_json_bool(&j, root, "", "planar", &s->params.planar);
        const cJSON* b = akp_json_member(&j, root, "", "bounds");
        if (b) {
            static const char* const bkeys[] = {"min", "max", "mode", "margin", NULL};
            static const char* const modes[] = {"steer", "wrap", "none", NULL};
            akp_json_object(&j, b, "bounds", bkeys);
            s->bounds_given = cJSON_GetObjectItemCaseSensitive(b, "min") || cJSON_GetObjectItemCaseSensitive(b, "max");
            akp_json_vec3(&j, b, "bounds", "min", &s->params.bounds_min);
            akp_json_vec3(&j, b, "bounds", "max", &s->params.bounds_max);
            int mode = 0;
            akp_json_enum(&j, b, "bounds", "mode", modes, &mode);
            s->params.bounds = mode == 0 ? AK_BOIDS_BOUNDS_STEER : mode == 1 ? AK_BOIDS_BOUNDS_WRAP : AK_BOIDS_BOUNDS_NONE;
            akp_json_float(&j, b, "bounds", "margin", 1e-4f, 1e9f, &s->params.bounds_margin);
            const ak_vec3 lo = s->params.bounds_min, hi = s->params.bounds_max;
            if (!j.failed && (!vec_in(lo, 1e9f) || !vec_in(hi, 1e9f)))
                akp_json_fail(&j, "bounds", NULL, "a coordinate is beyond +-1e9");
            if (!j.failed && !(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
                akp_json_fail(&j, "bounds", "max", "must be above min on every axis");
        }
        akp_json_vec3(&j, root, "", "goal", &s->params.goal);
        if (!j.failed && !vec_in(s->params.goal, 1e9f)) akp_json_fail(&j, "", "goal", "a coordinate is beyond +-1e9");
        const cJSON* l = akp_json_member(&j, root, "", "leader");
        if (l) {
            static const char* const lkeys[] = {"index", "distance", NULL};
            akp_json_object(&j, l, "leader", lkeys);
            long idx = 0;
            if (!j.failed && !cJSON_GetObjectItemCaseSensitive(l, "index"))
                akp_json_fail(&j, "leader", "index", "missing (the leader agent's index)");
            akp_json_int(&j, l, "leader", "index", 0, AK_BOIDS_SCENE_MAX_AGENTS - 1, &idx);
            akp_json_float(&j, l, "leader", "distance", 1e-4f, 1e9f, &s->params.leader_distance);
            s->params.has_leader = true;
            s->params.leader_index = (uint32_t)idx;
        }
        size_t ns = 0;
        const cJSON* sp = akp_json_array(&j, root, "", "species", AK_BOIDS_MAX_SPECIES, &ns);
        if (!j.failed && sp == NULL && cJSON_GetObjectItemCaseSensitive(root, "species"))
            akp_json_fail(&j, "", "species", "needs at least one species");
        if (ns > 0) s->params.species_count = (uint32_t)ns;
        for (size_t k = 0; sp && k < ns && !j.failed; ++k, sp = sp->next) {
            char path[64];
            akp_json_index(path, sizeof path, "species", k);
            read_species(&j, sp, path, s->params.species_count, s, (uint32_t)k);
        }
        size_t no = 0;
        const cJSON* ob = akp_json_array(&j, root, "", "obstacles", AK_BOIDS_SCENE_MAX_OBSTACLES, &no);
        if (!j.failed && no > 0) {
            s->obstacles = calloc(no, sizeof *s->obstacles);
            if (!s->obstacles) akp_json_fail(&j, "", "obstacles", "out of memory");
            for (size_t k = 0; ob && k < no && !j.failed; ++k, ob = ob->next) {
                char path[64];
                read_obstacle(&j, ob, akp_json_index(path, sizeof path, "obstacles", k), &s->obstacles[k]);
            }
            s->params.obstacles = s->obstacles;
            s->params.obstacle_count = (uint32_t)no;
        }
        size_t na = 0;
        const cJSON* ag = akp_json_array(&j, root, "", "agents", AK_BOIDS_SCENE_MAX_AGENTS, &na);
        if (!j.failed && na > 0) {
            s->positions = calloc(na, sizeof(ak_vec3));
            s->velocities = calloc(na, sizeof(ak_vec3));
            s->agent_species = calloc(na, 1);
            if (!s->positions || !s->velocities || !s->agent_species) akp_json_fail(&j, "", "agents", "out of memory");
            s->agent_count = na;
            static const char* const akeys[] = {"p", "v", "species", NULL};
            for (size_t k = 0; ag && k < na && !j.failed; ++k, ag = ag->next) {
                char path[64];
                akp_json_index(path, sizeof path, "agents", k);
                if (!akp_json_object(&j, ag, path, akeys)) break;
                if (!cJSON_GetObjectItemCaseSensitive(ag, "p")) {
                    akp_json_fail(&j, path, "p", "missing (the agent's position [x, y, z])");
                    break;
                }
                akp_json_vec3(&j, ag, path, "p", &s->positions[k]);
                akp_json_vec3(&j, ag, path, "v", &s->velocities[k]);
                long spi = 0;
                akp_json_int(&j, ag, path, "species", 0, (long)s->params.species_count - 1, &spi);
                s->agent_species[k] = (uint8_t)spi;
                if (!j.failed && (!vec_in(s->positions[k], 1e9f) || !vec_in(s->velocities[k], 1e9f)))
                    akp_json_fail(&j, path, NULL, "a coordinate is beyond +-1e9");
            }
        }
        const cJSON* r = akp_json_member(&j, root, "", "render");
        if (r) {
            static const char* const rkeys[] = {"shape", "size", NULL};
            static const char* const shapes[] = {"bird", "fish", NULL};
            akp_json_object(&j, r, "render", rkeys);
            akp_json_enum(&j, r, "render", "shape", shapes, &s->shape);
            akp_json_float(&j, r, "render", "size", 1e-4f, 1e6f, &s->shape_size);
        }
        if (!j.failed && s->params.has_leader && s->agent_count > 0 && s->params.leader_index >= s->agent_count)
            akp_json_fail(&j, "leader", "index", "%u is not below the %zu agents", s->params.leader_index,
                          s->agent_count);
        cJSON_Delete(root);
    }
    s->params.species = s->species;
    *jp = j;
    return !j.failed;
}

ak_result ak_boids_scene_load_bytes(const void* bytes, size_t size, const char* name, ak_boids_scene* scene,
                                    ak_diag* out_diag) {
    if (!scene) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, name ? name : "(scene)", "no scene to fill");
    akp_json j = {.file = name ? name : "(scene)"};
    if (!bytes && size) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no bytes");
    if (!parse(&j, bytes ? (const char*)bytes : "", size, scene)) return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_boids_scene_load_file(const char* path, ak_boids_scene* scene, ak_diag* out_diag) {
    if (!scene || !path) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, path ? path : "(scene)", "no path or scene");
    akp_json j = {.file = path};
    size_t size = 0;
    char* text = akp_json_read_file(&j, path, 0, &size);
    if (!text) return akp_json_diag(&j, AK_ERR_IO, out_diag);
    ak_result r = ak_boids_scene_load_bytes(text, size, path, scene, out_diag);
    free(text);
    return r;
}
