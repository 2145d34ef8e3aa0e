/* animkit cloth: scene files (strict JSON through src/json.h) and the built-in presets.
 * docs/cloth.md lists every key with its unit and default. */
#include <animkit/cloth.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json.h"

void ak_cloth_scene_defaults(ak_cloth_scene* s) {
    memset(s, 0, sizeof *s);
    s->desc.grid_width = 20;
    s->desc.grid_height = 20;
    s->desc.spacing = 0.05f;
    s->desc.grid_origin = ak_vec3_make(-0.5f, 1.0f, 0.5f);
    s->desc.grid_axis_u = ak_vec3_make(1, 0, 0);
    s->desc.grid_axis_v = ak_vec3_make(0, 0, -1);
    s->desc.area_density = 0.2f;
    s->desc.stretch_stiffness = 5000.0f;
    s->desc.dihedral_stiffness = 1e-4f;
    s->dt = 1.0f / 60.0f;
    s->steps = 120;
    s->substeps = 10;
    s->iterations = 1;
    s->gravity = ak_vec3_make(0, -9.81f, 0);
    s->air_density = 1.2f;
    s->thickness = 0.01f;
    s->capsule_scale = 0.8f;
    s->mesh_collider = true;
    s->limb_capsules = true;
    s->thread_count = 1;
}

void ak_cloth_scene_free(ak_cloth_scene* s) {
    if (!s) return;
    free(s->pins);
    free(s->pin_positions);
    free(s->attach);
    free(s->planes);
    free(s->spheres);
    free(s->capsules);
    s->pins = NULL, s->pin_positions = NULL, s->attach = NULL, s->planes = NULL, s->spheres = NULL, s->capsules = NULL;
}

static bool set_str(akp_json* j, const cJSON* obj, const char* path, const char* key, char* dst, size_t size) {
    const char* v = NULL;
    if (!akp_json_str(j, obj, path, key, &v)) return false;
    if (!v) return true;
    if (strlen(v) >= size) return akp_json_fail(j, path, key, "longer than %zu characters", size - 1);
    snprintf(dst, size, "%s", v);
    return true;
}

static void parse_grid(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    const cJSON* g = akp_json_member(j, root, "", "grid");
    if (!g) return;
    static const char* const keys[] = {"width", "height", "spacing", "origin", "axis_u", "axis_v", NULL};
    akp_json_object(j, g, "grid", keys);
    long w = s->desc.grid_width, h = s->desc.grid_height;
    akp_json_int(j, g, "grid", "width", 2, 4096, &w);
    akp_json_int(j, g, "grid", "height", 2, 4096, &h);
    if (!j->failed && (size_t)w * (size_t)h > AK_CLOTH_SCENE_MAX_PARTICLES)
        akp_json_fail(j, "grid", "", "%ld x %ld particles is over the budget of %zu", w, h, AK_CLOTH_SCENE_MAX_PARTICLES);
    s->desc.grid_width = (uint32_t)w, s->desc.grid_height = (uint32_t)h;
    akp_json_float(j, g, "grid", "spacing", 1e-4f, 100.0f, &s->desc.spacing);
    akp_json_vec3(j, g, "grid", "origin", &s->desc.grid_origin);
    akp_json_vec3(j, g, "grid", "axis_u", &s->desc.grid_axis_u);
    akp_json_vec3(j, g, "grid", "axis_v", &s->desc.grid_axis_v);
    if (!j->failed && ak_vec3_length(s->desc.grid_axis_u) < 1e-6f) akp_json_fail(j, "grid", "axis_u", "is zero");
    if (!j->failed && ak_vec3_length(s->desc.grid_axis_v) < 1e-6f) akp_json_fail(j, "grid", "axis_v", "is zero");
    if (!j->failed &&
        ak_vec3_length(ak_vec3_cross(ak_vec3_normalize(s->desc.grid_axis_u), ak_vec3_normalize(s->desc.grid_axis_v))) < 1e-3f)
        akp_json_fail(j, "grid", "axis_v", "is parallel to axis_u");
}

static void parse_material(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    const cJSON* m = akp_json_member(j, root, "", "material");
    if (!m) return;
    static const char* const keys[] = {"stretch_stiffness", "shear_stiffness", "bend_stiffness", "dihedral_stiffness",
                                       "bending", "spring_damping", "constraint_damping", "pbd_stiffness",
                                       "long_range_attachments", "long_range_slack", "area_density", NULL};
    static const char* const bendings[] = {"default", "dihedral", "springs", "none", "isometric", NULL};
    ak_cloth_desc* d = &s->desc;
    akp_json_object(j, m, "material", keys);
    akp_json_float(j, m, "material", "stretch_stiffness", 1e-3f, 1e9f, &d->stretch_stiffness);
    akp_json_float(j, m, "material", "shear_stiffness", 1e-3f, 1e9f, &d->shear_stiffness);
    akp_json_float(j, m, "material", "bend_stiffness", 1e-3f, 1e9f, &d->bend_stiffness);
    akp_json_float(j, m, "material", "dihedral_stiffness", 1e-9f, 1e6f, &d->dihedral_stiffness);
    int bend = (int)d->bending;
    akp_json_enum(j, m, "material", "bending", bendings, &bend);
    d->bending = (ak_cloth_bending)bend;
    akp_json_float(j, m, "material", "spring_damping", 0.0f, 1e6f, &d->spring_damping);
    akp_json_float(j, m, "material", "constraint_damping", 0.0f, 10.0f, &d->constraint_damping);
    akp_json_float(j, m, "material", "pbd_stiffness", 1e-6f, 1.0f, &d->pbd_stiffness);
    akp_json_bool(j, m, "material", "long_range_attachments", &d->long_range_attachments);
    akp_json_float(j, m, "material", "long_range_slack", 0.0f, 10.0f, &d->long_range_slack);
    akp_json_float(j, m, "material", "area_density", 1e-6f, 1e4f, &d->area_density);
}

static void parse_pins(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    size_t n = 0;
    const cJSON* e = akp_json_array(j, root, "", "pins", AK_CLOTH_SCENE_MAX_LIST, &n);
    if (!e || j->failed) return;
    s->pins = calloc(n, sizeof(uint32_t));
    if (!s->pins) {
        akp_json_fail(j, "", "pins", "out of memory");
        return;
    }
    const size_t count = (size_t)s->desc.grid_width * s->desc.grid_height;
    for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
        char path[32];
        akp_json_index(path, sizeof path, "pins", k);
        if (!cJSON_IsNumber(e) || e->valuedouble != floor(e->valuedouble) || e->valuedouble < 0) {
            akp_json_fail(j, path, "", "expected a particle index (integer >= 0)");
            break;
        }
        if (e->valuedouble >= (double)count) {
            akp_json_fail(j, path, "", "particle %.0f is out of range (the grid has %zu)", e->valuedouble, count);
            break;
        }
        s->pins[k] = (uint32_t)e->valuedouble;
        for (size_t q = 0; q < k; ++q)
            if (s->pins[q] == s->pins[k]) akp_json_fail(j, path, "", "particle %u is pinned twice", s->pins[k]);
        s->pin_count = k + 1;
    }
}

static void parse_pin_positions(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    size_t n = 0;
    const cJSON* e = akp_json_array(j, root, "", "pin_positions", AK_CLOTH_SCENE_MAX_LIST, &n);
    if (!e || j->failed) return;
    if (n != s->pin_count) {
        akp_json_fail(j, "", "pin_positions", "has %zu entries for %zu pins (one per pin, in order)", n, s->pin_count);
        return;
    }
    s->pin_positions = calloc(n, sizeof(ak_vec3));
    if (!s->pin_positions) {
        akp_json_fail(j, "", "pin_positions", "out of memory");
        return;
    }
    for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
        char path[40];
        akp_json_index(path, sizeof path, "pin_positions", k);
        if (!cJSON_IsArray(e) || cJSON_GetArraySize(e) != 3) {
            akp_json_fail(j, path, "", "expected [x, y, z]");
            break;
        }
        float c[3];
        for (int q = 0; q < 3; ++q) {
            const cJSON* x = cJSON_GetArrayItem(e, q);
            if (!cJSON_IsNumber(x) || !(fabs(x->valuedouble) <= 1e6)) {
                akp_json_fail(j, path, "", "expected three numbers within 1e6 m");
                break;
            }
            c[q] = (float)x->valuedouble;
        }
        s->pin_positions[k] = ak_vec3_make(c[0], c[1], c[2]);
        s->pin_position_count = k + 1;
    }
}

static void parse_attachments(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    size_t n = 0;
    const cJSON* e = akp_json_array(j, root, "", "attachments", AK_CLOTH_SCENE_MAX_LIST, &n);
    if (!e || j->failed) return;
    s->attach = calloc(n, sizeof(ak_cloth_attach_spec));
    if (!s->attach) {
        akp_json_fail(j, "", "attachments", "out of memory");
        return;
    }
    static const char* const keys[] = {"vertex", "joint", "mesh_vertex", "position", NULL};
    const long count = (long)s->desc.grid_width * s->desc.grid_height;
    for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
        char path[40];
        akp_json_index(path, sizeof path, "attachments", k);
        if (!cJSON_IsObject(e)) {
            akp_json_fail(j, path, "", "expected an object {\"vertex\": i, \"joint\": NAME} or {\"vertex\": i, \"mesh_vertex\": k}");
            break;
        }
        akp_json_object(j, e, path, keys);
        ak_cloth_attach_spec* a = &s->attach[k];
        long v = -1;
        a->mesh_vertex = -1;
        akp_json_int(j, e, path, "vertex", 0, count - 1, &v);
        set_str(j, e, path, "joint", a->joint, sizeof a->joint);
        akp_json_int(j, e, path, "mesh_vertex", 0, 100000000L, &a->mesh_vertex);
        a->has_position = cJSON_GetObjectItemCaseSensitive(e, "position") != NULL;
        akp_json_vec3(j, e, path, "position", &a->position);
        if (j->failed) break;
        if (v < 0) akp_json_fail(j, path, "vertex", "is required");
        else if ((a->joint[0] != '\0') == (a->mesh_vertex >= 0)) akp_json_fail(j, path, "", "give exactly one of joint, mesh_vertex");
        a->vertex = (uint32_t)v;
        for (size_t q = 0; q < k && !j->failed; ++q)
            if (s->attach[q].vertex == a->vertex) akp_json_fail(j, path, "vertex", "particle %ld is attached twice", v);
        for (size_t q = 0; q < s->pin_count && !j->failed; ++q)
            if (s->pins[q] == a->vertex) akp_json_fail(j, path, "vertex", "particle %ld is also pinned", v);
        s->attach_count = k + 1;
    }
}

static void parse_colliders(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    const cJSON* c = akp_json_member(j, root, "", "colliders");
    if (!c) return;
    static const char* const keys[] = {"planes", "spheres", "capsules", "thickness", "friction", "self_collision",
                                       "self_distance", NULL};
    akp_json_object(j, c, "colliders", keys);
    akp_json_float(j, c, "colliders", "thickness", 1e-5f, 10.0f, &s->thickness);
    akp_json_float(j, c, "colliders", "friction", 0.0f, 10.0f, &s->friction);
    akp_json_bool(j, c, "colliders", "self_collision", &s->self_collision);
    akp_json_float(j, c, "colliders", "self_distance", 0.0f, 10.0f, &s->self_distance);
    size_t n = 0;
    const cJSON* e = akp_json_array(j, c, "colliders", "planes", AK_CLOTH_SCENE_MAX_LIST, &n);
    if (e && !j->failed && (s->planes = calloc(n, sizeof(ak_cloth_plane))) != NULL) {
        static const char* const pk[] = {"normal", "offset", NULL};
        for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
            char path[48];
            akp_json_index(path, sizeof path, "colliders.planes", k);
            if (!cJSON_IsObject(e)) { akp_json_fail(j, path, "", "expected an object"); break; }
            akp_json_object(j, e, path, pk);
            ak_cloth_plane p = {{0, 1, 0}, 0.0f};
            akp_json_vec3(j, e, path, "normal", &p.normal);
            akp_json_float(j, e, path, "offset", -1e6f, 1e6f, &p.offset);
            if (!j->failed && ak_vec3_length(p.normal) < 1e-6f) akp_json_fail(j, path, "normal", "is zero");
            s->planes[k] = p;
            s->plane_count = k + 1;
        }
    }
    e = akp_json_array(j, c, "colliders", "spheres", AK_CLOTH_SCENE_MAX_LIST, &n);
    if (e && !j->failed && (s->spheres = calloc(n, sizeof(ak_cloth_sphere))) != NULL) {
        static const char* const sk[] = {"center", "radius", NULL};
        for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
            char path[48];
            akp_json_index(path, sizeof path, "colliders.spheres", k);
            if (!cJSON_IsObject(e)) { akp_json_fail(j, path, "", "expected an object"); break; }
            akp_json_object(j, e, path, sk);
            ak_cloth_sphere p = {{0, 0, 0}, 0.5f};
            akp_json_vec3(j, e, path, "center", &p.center);
            akp_json_float(j, e, path, "radius", 0.0f, 1e6f, &p.radius);
            s->spheres[k] = p;
            s->sphere_count = k + 1;
        }
    }
    e = akp_json_array(j, c, "colliders", "capsules", AK_CLOTH_SCENE_MAX_LIST, &n);
    if (e && !j->failed && (s->capsules = calloc(n, sizeof(ak_cloth_capsule))) != NULL) {
        static const char* const ck[] = {"a", "b", "radius", NULL};
        for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
            char path[48];
            akp_json_index(path, sizeof path, "colliders.capsules", k);
            if (!cJSON_IsObject(e)) { akp_json_fail(j, path, "", "expected an object"); break; }
            akp_json_object(j, e, path, ck);
            ak_cloth_capsule p = {{0, 0, 0}, {0, 1, 0}, 0.1f};
            akp_json_vec3(j, e, path, "a", &p.a);
            akp_json_vec3(j, e, path, "b", &p.b);
            akp_json_float(j, e, path, "radius", 0.0f, 1e6f, &p.radius);
            s->capsules[k] = p;
            s->capsule_count = k + 1;
        }
    }
}

static void parse_character(akp_json* j, const cJSON* root, ak_cloth_scene* s) {
    const cJSON* c = akp_json_member(j, root, "", "character");
    if (!c) return;
    static const char* const keys[] = {"model", "clip", "mesh_collider", "limb_capsules", "capsule_scale", NULL};
    akp_json_object(j, c, "character", keys);
    set_str(j, c, "character", "model", s->model, sizeof s->model);
    set_str(j, c, "character", "clip", s->clip, sizeof s->clip);
    akp_json_bool(j, c, "character", "mesh_collider", &s->mesh_collider);
    akp_json_bool(j, c, "character", "limb_capsules", &s->limb_capsules);
    akp_json_float(j, c, "character", "capsule_scale", 0.0f, 10.0f, &s->capsule_scale);
    if (!j->failed && s->model[0] == '\0') akp_json_fail(j, "character", "model", "is required");
}

ak_result ak_cloth_scene_load_bytes(const void* bytes, size_t size, const char* name, ak_cloth_scene* out,
                                   ak_diag* out_diag) {
    if (!out) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, name ? name : "scene", "no scene to fill");
    ak_cloth_scene_defaults(out);
    akp_json j = {.file = name ? name : "scene"};
    if (!bytes && size) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no bytes");
    const char* text = bytes ? (const char*)bytes : "";
    cJSON* root = akp_json_parse(&j, text, size);
    if (root) {
        static const char* const keys[] = {"solver", "grid", "material", "pins", "pin_positions", "attachments", "dt", "steps",
                                           "substeps", "iterations", "threads", "gravity", "wind", "gust",
                                           "gust_frequency", "drag", "lift", "air_density", "damping", "colliders",
                                           "character", NULL};
        static const char* const solvers[] = {"xpbd", "springs", "pbd", "implicit", NULL}; /* enum order */
        akp_json_object(&j, root, "", keys);
        int solver = 0;
        akp_json_enum(&j, root, "", "solver", solvers, &solver);
        out->desc.solver = (ak_cloth_solver)solver;
        parse_grid(&j, root, out);
        parse_material(&j, root, out);
        parse_pins(&j, root, out);
        parse_pin_positions(&j, root, out);
        parse_attachments(&j, root, out);
        akp_json_float(&j, root, "", "dt", 1e-7f, 1.0f, &out->dt);
        akp_json_int(&j, root, "", "steps", 0, AK_CLOTH_SCENE_MAX_STEPS, &out->steps);
        long sub = out->substeps, it = out->iterations, th = out->thread_count;
        akp_json_int(&j, root, "", "substeps", 1, 10000, &sub);
        akp_json_int(&j, root, "", "iterations", 1, 10000, &it);
        akp_json_int(&j, root, "", "threads", 1, 64, &th);
        out->substeps = (uint32_t)sub, out->iterations = (uint32_t)it, out->thread_count = (int)th;
        out->iterations_given = cJSON_GetObjectItemCaseSensitive(root, "iterations") != NULL;
        akp_json_vec3(&j, root, "", "gravity", &out->gravity);
        akp_json_vec3(&j, root, "", "wind", &out->wind);
        akp_json_float(&j, root, "", "gust", 0.0f, 10.0f, &out->gust);
        akp_json_float(&j, root, "", "gust_frequency", 0.0f, 100.0f, &out->gust_frequency);
        akp_json_float(&j, root, "", "drag", 0.0f, 100.0f, &out->drag);
        akp_json_float(&j, root, "", "lift", 0.0f, 100.0f, &out->lift);
        akp_json_float(&j, root, "", "air_density", 0.0f, 1000.0f, &out->air_density);
        akp_json_float(&j, root, "", "damping", 0.0f, 1000.0f, &out->damping);
        parse_colliders(&j, root, out);
        parse_character(&j, root, out);
        if (!j.failed && out->attach_count && out->model[0] == '\0')
            akp_json_fail(&j, "", "attachments", "need a character (character.model)");
        cJSON_Delete(root);
    }
    if (j.failed) {
        ak_cloth_scene_free(out);
        return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    }
    out->desc.pins = (ak_u32_cspan){out->pins, out->pin_count};
    out->desc.pin_positions = (ak_vec3_cspan){out->pin_positions, out->pin_position_count};
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_cloth_scene_load_file(const char* path, ak_cloth_scene* out, ak_diag* out_diag) {
    if (!out || !path) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, path ? path : "scene", "no path or scene");
    ak_cloth_scene_defaults(out);
    akp_json j = {.file = path};
    size_t size = 0;
    char* text = akp_json_read_file(&j, path, 0, &size);
    if (!text) return akp_json_diag(&j, AK_ERR_IO, out_diag);
    ak_result r = ak_cloth_scene_load_bytes(text, size, path, out, out_diag);
    free(text);
    return r;
}

static bool preset_fill(const char* name, ak_cloth_scene* s) {
    ak_cloth_scene_defaults(s);
    ak_cloth_desc* d = &s->desc;
    if (strcmp(name, "flag") == 0) {
        /* a 1.6 x 1 m flag on a pole along its left edge, in gusty wind */
        d->grid_width = 32, d->grid_height = 20, d->spacing = 0.05f;
        d->grid_origin = ak_vec3_make(0, 2.0f, 0);
        d->grid_axis_u = ak_vec3_make(1, 0, 0), d->grid_axis_v = ak_vec3_make(0, -1, 0);
        s->pin_count = 20;
        s->wind = ak_vec3_make(8, 0, 2);
        s->gust = 0.4f, s->gust_frequency = 0.5f;
        s->drag = 1.0f, s->lift = 0.6f;
        s->steps = 240;
    } else if (strcmp(name, "curtain") == 0) {
        /* a 2 x 1.5 m curtain on 14 rings (every third top particle) gathered on the rod (see
         * below), a light breeze through it */
        d->grid_width = 40, d->grid_height = 30, d->spacing = 0.05f;
        d->grid_origin = ak_vec3_make(-1.0f, 1.6f, 0);
        d->grid_axis_u = ak_vec3_make(1, 0, 0), d->grid_axis_v = ak_vec3_make(0, -1, 0);
        s->pin_count = 14;
        s->wind = ak_vec3_make(0, 0, 0.6f);
        s->gust = 0.8f, s->gust_frequency = 0.3f;
        s->drag = 1.0f, s->lift = 0.3f;
        s->damping = 0.2f;
        s->steps = 240;
    } else if (strcmp(name, "drape") == 0) {
        /* a 1 m square dropped on a sphere above the floor */
        d->grid_width = 32, d->grid_height = 32, d->spacing = 1.0f / 31.0f;
        d->grid_origin = ak_vec3_make(-0.5f, 1.0f, 0.5f);
        s->sphere_count = 1, s->plane_count = 1;
        s->friction = 0.4f;
        s->self_collision = true;
        s->damping = 0.5f;
        s->steps = 300;
    } else if (strcmp(name, "cape") == 0) {
        /* a 0.38 x 0.95 m cape on the humanoid's back, walking (in place) into a gusty 1.8 m/s
         * head wind that streams it back: its top row lies across the shoulder blades,
         * attached to the upper spine (spine_02); soft bending (the default), drag and lift,
         * long-range attachments with slack */
        d->grid_width = 12, d->grid_height = 30, d->spacing = 0.38f / 11.0f;
        d->grid_origin = ak_vec3_make(-0.19f, 1.44f, -0.15f);
        d->grid_axis_u = ak_vec3_make(1, 0, 0), d->grid_axis_v = ak_vec3_make(0, -1, 0);
        d->long_range_attachments = true;
        d->long_range_slack = 0.15f;
        s->attach_count = 12;
        s->wind = ak_vec3_make(0.3f, 0, -1.8f);
        s->gust = 0.5f, s->gust_frequency = 0.7f;
        s->drag = 1.0f, s->lift = 0.3f;
        s->damping = 0.3f;
        s->friction = 0.2f;
        s->steps = 180;
        snprintf(s->model, sizeof s->model, "builtin:humanoid");
        snprintf(s->clip, sizeof s->clip, "walk");
    } else {
        return false;
    }
    if (s->pin_count) {
        s->pins = calloc(s->pin_count, sizeof(uint32_t));
        if (!s->pins) return false;
        for (size_t k = 0; k < s->pin_count; ++k)
            s->pins[k] = strcmp(name, "flag") == 0 ? (uint32_t)(k * d->grid_width) : (uint32_t)(k * 3);
    }
    if (s->sphere_count) {
        s->spheres = calloc(1, sizeof(ak_cloth_sphere));
        s->planes = calloc(1, sizeof(ak_cloth_plane));
        if (!s->spheres || !s->planes) return false;
        s->spheres[0] = (ak_cloth_sphere){{0, 0.5f, 0}, 0.3f};
        s->planes[0] = (ak_cloth_plane){{0, 1, 0}, 0.0f};
    }
    if (s->attach_count) {
        s->attach = calloc(s->attach_count, sizeof(ak_cloth_attach_spec));
        if (!s->attach) return false;
        for (size_t k = 0; k < s->attach_count; ++k) {
            s->attach[k].vertex = (uint32_t)k;
            s->attach[k].mesh_vertex = -1;
            snprintf(s->attach[k].joint, sizeof s->attach[k].joint, "spine_02");
            if (strcmp(name, "cape") == 0) {
                /* the top row gathered on a collar: an arc of radius 0.15 m round the back of
                 * the neck, 130 degrees (0.34 m for 0.38 m of cloth), so the cape wraps the
                 * shoulders and falls in folds instead of hanging as a flat board */
                const float phi = (-65.0f + 130.0f * (float)k / (float)(s->attach_count - 1)) * AK_PI / 180.0f;
                s->attach[k].has_position = true;
                s->attach[k].position = ak_vec3_make(0.15f * sinf(phi), 1.46f, -0.01f - 0.15f * cosf(phi));
            }
        }
    }
    if (strcmp(name, "curtain") == 0) {
        /* rings gathered on the rod to 60% of the curtain's width, alternately 4 cm in front of
         * and behind it: the cloth between them falls in folds */
        s->pin_positions = calloc(s->pin_count, sizeof(ak_vec3));
        if (!s->pin_positions) return false;
        s->pin_position_count = s->pin_count;
        for (size_t k = 0; k < s->pin_count; ++k) {
            const ak_vec3 rest = ak_vec3_madd(d->grid_origin, d->grid_axis_u, d->spacing * (float)s->pins[k]);
            s->pin_positions[k] = ak_vec3_make(0.6f * rest.x, rest.y, (k & 1) ? 0.04f : -0.04f);
        }
    }
    d->pins = (ak_u32_cspan){s->pins, s->pin_count};
    d->pin_positions = (ak_vec3_cspan){s->pin_positions, s->pin_position_count};
    return true;
}

ak_result ak_cloth_scene_preset(const char* name, ak_cloth_scene* out, ak_diag* out_diag) {
    if (!out || !name) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "preset", "no name or scene");
    if (!preset_fill(name, out)) {
        const bool known = !strcmp(name, "flag") || !strcmp(name, "curtain") || !strcmp(name, "drape") ||
                           !strcmp(name, "cape");
        ak_cloth_scene_free(out);
        ak_cloth_scene_defaults(out);
        if (known) return akp_diag_set(out_diag, AK_ERR_NO_MEMORY, name, "out of memory");
        return akp_diag_set(out_diag, AK_ERR_NOT_FOUND, name, "unknown preset (allowed: " AK_CLOTH_SCENE_PRESETS ")");
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}
