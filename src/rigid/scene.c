/* animkit rigid: scene files (strict JSON through src/json.h) and the built-in presets
 * (ak_rigid_scene in animkit/rigid.h; docs/rigid.md lists every key with its unit and default). */
#include <animkit/rigid.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <animkit/builtin.h>
#include <animkit/clip.h>
#include <animkit/scene.h>
#include <animkit/skeleton.h>

#include "json.h"

void ak_rigid_scene_defaults(ak_rigid_scene* s) {
    memset(s, 0, sizeof *s);
    s->gravity = ak_vec3_make(0.0f, -9.81f, 0.0f);
    s->dt = 1.0f / 60.0f;
    s->steps = 240;
    s->substeps = 20;
    s->thread_count = 1;
    s->sleep = true;
    s->model.contact_offset = 0.01f;
}

void ak_rigid_scene_free(ak_rigid_scene* s) {
    if (!s) return;
    free(s->bodies);
    free(s->joints);
    free(s->points);
    free(s->heights);
    free(s->indices);
    s->points = NULL;
    s->point_count = s->point_cap = 0;
    s->heights = NULL;
    s->height_count = s->height_cap = 0;
    s->indices = NULL;
    s->index_count = s->index_cap = 0;
    free(s->children);
    s->children = NULL;
    s->child_count = s->child_cap = 0;
    free(s->ragdoll_bones);
    free(s->ragdoll_pose);
    s->bodies = NULL;
    s->body_count = 0;
    s->joints = NULL;
    s->joint_count = 0;
    s->ragdoll_bones = NULL;
    s->ragdoll_pose = NULL;
    s->ragdoll_bone_count = 0;
    s->ragdoll_character[0] = '\0';
}

/* A body with the scene file's defaults (density 1000, friction 0.5, restitution 0). */
static ak_rigid_body_desc body_default(void) {
    ak_rigid_body_desc b;
    memset(&b, 0, sizeof b);
    b.orientation = ak_quat_identity();
    b.density = 1000.0f;
    b.friction = 0.5f;
    return b;
}

/* An array of [x, y, z] under key into the scene's points array (counted before parsing, so
 * the array is big enough unless the file lied: then an error). */
static bool read_vec3s(akp_json* j, const cJSON* sh, const char* sp, const char* key, size_t min,
                       size_t max, ak_rigid_scene* sc, ak_vec3_cspan* out_span) {
    size_t n = 0;
    const cJSON* e = akp_json_array(j, sh, sp, key, max, &n);
    if (j->failed) return false;
    if (n < min)
        return akp_json_fail(j, sp, key, "is required: at least %zu [x, y, z] points", min);
    if (sc->point_count + n > sc->point_cap)
        return akp_json_fail(j, sp, key, "more points than the scene may have (%u)",
                             AK_RIGID_SCENE_MAX_POINTS);
    ak_vec3* out = sc->points + sc->point_count;
    char pp[128];
    akp_json_key(pp, sizeof pp, sp, key);
    for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
        float v[3] = {0, 0, 0};
        size_t m = (size_t)cJSON_GetArraySize(e);
        const cJSON* c = cJSON_IsArray(e) ? e->child : NULL;
        for (size_t i = 0; c && i < 3 && m == 3; c = c->next, ++i) {
            if (!cJSON_IsNumber(c) || !(fabs(c->valuedouble) <= 1e4)) break;
            v[i] = (float)c->valuedouble;
            if (i == 2) m = 0; /* all three read */
        }
        if (m != 0) {
            char ip[160];
            akp_json_index(ip, sizeof ip, pp, k);
            return akp_json_fail(j, ip, "", "expected [x, y, z], each finite and within 1e4 m");
        }
        out[k] = ak_vec3_make(v[0], v[1], v[2]);
    }
    sc->point_count += n;
    *out_span = (ak_vec3_cspan){out, n};
    return true;
}

/* An array of numbers in [lo, hi] (whole numbers when integral) into out (count known). */
static bool read_numbers(akp_json* j, const cJSON* e, const char* sp, const char* key, double lo,
                         double hi, bool integral, float* out_f, uint32_t* out_u) {
    char pp[128];
    akp_json_key(pp, sizeof pp, sp, key);
    for (size_t k = 0; e; e = e->next, ++k) {
        double x = cJSON_IsNumber(e) ? e->valuedouble : NAN;
        if (!(x >= lo && x <= hi) || (integral && x != floor(x))) {
            char ip[160];
            akp_json_index(ip, sizeof ip, pp, k);
            return akp_json_fail(j, ip, "", integral ? "expected a whole number in [%g, %g]"
                                                     : "expected a number in [%g, %g]",
                                 lo, hi);
        }
        if (out_f) out_f[k] = (float)x;
        if (out_u) out_u[k] = (uint32_t)x;
    }
    return true;
}

static void parse_heightfield(akp_json* j, const cJSON* sh, const char* sp, ak_rigid_scene* sc,
                              ak_rigid_shape* s) {
    long rows = 0, cols = 0;
    s->spacing = 1.0f;
    akp_json_int(j, sh, sp, "rows", 2, 1L << 24, &rows);
    akp_json_int(j, sh, sp, "cols", 2, 1L << 24, &cols);
    akp_json_float(j, sh, sp, "spacing", 1e-4f, 1e4f, &s->spacing);
    if (j->failed) return;
    if (rows == 0 || cols == 0) {
        akp_json_fail(j, sp, rows == 0 ? "rows" : "cols", "is required for a heightfield (>= 2)");
        return;
    }
    if ((uint64_t)rows * (uint64_t)cols > AK_RIGID_HEIGHTFIELD_MAX_SAMPLES) {
        akp_json_fail(j, sp, "rows", "rows x cols is over %u samples", AK_RIGID_HEIGHTFIELD_MAX_SAMPLES);
        return;
    }
    size_t want = (size_t)rows * (size_t)cols, n = 0;
    const cJSON* e = akp_json_array(j, sh, sp, "heights", AK_RIGID_HEIGHTFIELD_MAX_SAMPLES, &n);
    if (j->failed) return;
    if (n != want) {
        akp_json_fail(j, sp, "heights", "expected rows x cols = %zu numbers, found %zu", want, n);
        return;
    }
    if (sc->height_count + n > sc->height_cap) {
        akp_json_fail(j, sp, "heights", "more heights than the scene may have");
        return;
    }
    float* out = sc->heights + sc->height_count;
    if (!read_numbers(j, e, sp, "heights", -1e4, 1e4, false, out, NULL)) return;
    sc->height_count += n;
    s->rows = (uint32_t)rows, s->cols = (uint32_t)cols;
    s->heights = (ak_f32_cspan){out, n};
}

static void parse_trimesh(akp_json* j, const cJSON* sh, const char* sp, ak_rigid_scene* sc,
                          ak_rigid_shape* s) {
    if (!read_vec3s(j, sh, sp, "vertices", 3, AK_RIGID_SCENE_MAX_POINTS, sc, &s->vertices)) return;
    size_t n = 0;
    const cJSON* e =
        akp_json_array(j, sh, sp, "indices", 3 * (size_t)AK_RIGID_TRIMESH_MAX_TRIANGLES, &n);
    if (j->failed) return;
    if (n == 0 || n % 3) {
        akp_json_fail(j, sp, "indices", "is required: 3 vertex indices per triangle");
        return;
    }
    if (sc->index_count + n > sc->index_cap) {
        akp_json_fail(j, sp, "indices", "more indices than the scene may have");
        return;
    }
    uint32_t* out = sc->indices + sc->index_count;
    if (!read_numbers(j, e, sp, "indices", 0.0, (double)s->vertices.count - 1.0, true, NULL, out))
        return;
    sc->index_count += n;
    s->indices = (ak_u32_cspan){out, n};
}

static void parse_points(akp_json* j, const cJSON* sh, const char* sp, ak_rigid_scene* sc,
                         ak_rigid_shape* s) {
    if (!read_vec3s(j, sh, sp, "points", 4, AK_RIGID_HULL_MAX_POINTS, sc, &s->points)) return;
    const char* problem = "";
    if (ak_rigid_hull_check(s->points, &problem) != AK_OK)
        akp_json_fail(j, sp, "points", "%s", problem);
}

static void parse_children(akp_json* j, const cJSON* sh, const char* sp, ak_rigid_scene* sc,
                           ak_rigid_shape* s);

/* The "shape" member of obj (a body, or a compound's child when depth is 1) into *s; *is_static
 * (may be NULL) set for the static-only shapes. */
static void parse_shape(akp_json* j, const cJSON* obj, const char* path, ak_rigid_scene* sc,
                        ak_rigid_shape* s, bool* is_static, int depth) {
    char sp[128];
    akp_json_key(sp, sizeof sp, path, "shape");
    const cJSON* sh = akp_json_member(j, obj, path, "shape");
    if (j->failed) return;
    if (!sh) {
        akp_json_fail(j, path, "shape", "is required");
        return;
    }
    static const char* const keys[] = {"type",   "radius",  "half_extents", "half_height",
                                       "points", "normal",  "rows",         "cols",
                                       "spacing", "heights", "vertices",    "indices",
                                       "children", NULL};
    static const char* const types[] = {"sphere", "box",         "capsule", "hull",
                                        "plane",  "heightfield", "trimesh", "compound", NULL};
    akp_json_object(j, sh, sp, keys);
    int type = -1;
    akp_json_enum(j, sh, sp, "type", types, &type);
    if (j->failed) return;
    if (type < 0) {
        akp_json_fail(j, sp, "type",
                      "is required (sphere, box, capsule, hull, plane, heightfield, trimesh or "
                      "compound)");
        return;
    }
    if (depth > 0 && type > 3) {
        akp_json_fail(j, sp, "type", "a compound's child is a sphere, box, capsule or hull");
        return;
    }
    /* which keys each type takes: the others are refused so a typo cannot pass unnoticed */
    static const char* const takes[8] = {"radius",           "half_extents",
                                         "radius half_height", "points",
                                         "normal",           "rows cols spacing heights",
                                         "vertices indices", "children"};
    for (int k = 1; keys[k]; ++k)
        if (cJSON_GetObjectItemCaseSensitive(sh, keys[k]) && !strstr(takes[type], keys[k])) {
            akp_json_fail(j, sp, keys[k], "does not apply to a %s", types[type]);
            return;
        }
    s->type = type == 0   ? AK_RIGID_SPHERE
              : type == 1 ? AK_RIGID_BOX
              : type == 2 ? AK_RIGID_CAPSULE
              : type == 3 ? AK_RIGID_HULL
              : type == 4 ? AK_RIGID_PLANE
              : type == 5 ? AK_RIGID_HEIGHTFIELD
              : type == 6 ? AK_RIGID_TRIMESH
                          : AK_RIGID_COMPOUND;
    s->radius = -1.0f;
    s->half_height = 0.0f;
    s->half_extents = ak_vec3_make(-1.0f, -1.0f, -1.0f);
    s->normal = ak_vec3_make(0.0f, 1.0f, 0.0f);
    akp_json_float(j, sh, sp, "radius", 1e-4f, 1e4f, &s->radius);
    akp_json_float(j, sh, sp, "half_height", 0.0f, 1e4f, &s->half_height);
    float he[3] = {-1.0f, -1.0f, -1.0f};
    akp_json_floats(j, sh, sp, "half_extents", 3, 1e-4f, 1e4f, he);
    s->half_extents = ak_vec3_make(he[0], he[1], he[2]);
    akp_json_vec3(j, sh, sp, "normal", &s->normal);
    if (!j->failed && type == 3) parse_points(j, sh, sp, sc, s);
    if (!j->failed && type == 5) parse_heightfield(j, sh, sp, sc, s);
    if (!j->failed && type == 6) parse_trimesh(j, sh, sp, sc, s);
    if (!j->failed && type == 7) parse_children(j, sh, sp, sc, s);
    if (!j->failed && (type == 5 || type == 6) && is_static) *is_static = true;
    if (j->failed) return;
    if ((type == 0 || type == 2) && s->radius < 0.0f)
        akp_json_fail(j, sp, "radius", "is required for a %s", types[type]);
    else if (type == 1 && he[0] < 0.0f)
        akp_json_fail(j, sp, "half_extents", "is required for a box");
    else if (type == 4 && ak_vec3_length(s->normal) < 1e-6f)
        akp_json_fail(j, sp, "normal", "is zero");
}

static void parse_children(akp_json* j, const cJSON* sh, const char* sp, ak_rigid_scene* sc,
                           ak_rigid_shape* s) {
    size_t n = 0;
    const cJSON* e = akp_json_array(j, sh, sp, "children", AK_RIGID_COMPOUND_MAX_CHILDREN, &n);
    if (j->failed) return;
    if (n == 0) {
        akp_json_fail(j, sp, "children", "is required for a compound: 1 to %u children",
                      AK_RIGID_COMPOUND_MAX_CHILDREN);
        return;
    }
    if (sc->child_count + n > sc->child_cap) {
        akp_json_fail(j, sp, "children", "more children than the scene may have");
        return;
    }
    ak_rigid_child* out = sc->children + sc->child_count;
    sc->child_count += n;
    char cp[128];
    akp_json_key(cp, sizeof cp, sp, "children");
    for (size_t k = 0; e && !j->failed; e = e->next, ++k) {
        char ip[160];
        akp_json_index(ip, sizeof ip, cp, k);
        if (!cJSON_IsObject(e)) {
            akp_json_fail(j, ip, "", "expected an object with \"shape\"");
            return;
        }
        static const char* const keys[] = {"shape", "position", "orientation", NULL};
        akp_json_object(j, e, ip, keys);
        ak_rigid_child* c = &out[k];
        memset(c, 0, sizeof *c);
        c->orientation = ak_quat_identity();
        parse_shape(j, e, ip, sc, &c->shape, NULL, 1);
        akp_json_vec3(j, e, ip, "position", &c->position);
        float q[4] = {0, 0, 0, 1};
        akp_json_floats(j, e, ip, "orientation", 4, -1e3f, 1e3f, q);
        if (!j->failed && q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f && q[3] == 0.0f)
            akp_json_fail(j, ip, "orientation", "is the zero quaternion");
        c->orientation = (ak_quat){q[0], q[1], q[2], q[3]};
        if (!j->failed && ak_vec3_length(c->position) > 1e4f)
            akp_json_fail(j, ip, "position", "is over 1e4 m");
    }
    s->children = out;
    s->child_count = n;
}

static void parse_body(akp_json* j, const cJSON* e, const char* path, ak_rigid_scene* sc,
                       ak_rigid_body_desc* b) {
    if (!cJSON_IsObject(e)) {
        akp_json_fail(j, path, "", "expected an object with at least \"shape\"");
        return;
    }
    static const char* const keys[] = {
        "shape",    "position",    "orientation", "velocity", "angular_velocity", "density", "mass",
        "friction", "restitution", "static",      NULL};
    akp_json_object(j, e, path, keys);
    *b = body_default();
    parse_shape(j, e, path, sc, &b->shape, &b->is_static, 0);
    akp_json_vec3(j, e, path, "position", &b->position);
    float q[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    akp_json_floats(j, e, path, "orientation", 4, -1e3f, 1e3f, q);
    if (!j->failed && q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3] < 1e-12f)
        akp_json_fail(j, path, "orientation", "is the zero quaternion");
    b->orientation = ak_quat_normalize(ak_quat_make(q[0], q[1], q[2], q[3]));
    akp_json_vec3(j, e, path, "velocity", &b->velocity);
    akp_json_vec3(j, e, path, "angular_velocity", &b->angular_velocity);
    if (!j->failed && (ak_vec3_length(b->position) > 1e6f || ak_vec3_length(b->velocity) > 1e5f ||
                       ak_vec3_length(b->angular_velocity) > 1e5f))
        akp_json_fail(
            j, path, "",
            "position over 1e6 m, velocity over 1e5 m/s or angular velocity over 1e5 rad/s");
    if (!j->failed && cJSON_GetObjectItemCaseSensitive(e, "density") &&
        cJSON_GetObjectItemCaseSensitive(e, "mass"))
        akp_json_fail(j, path, "mass", "give density or mass, not both");
    akp_json_float(j, e, path, "density", 1e-3f, 1e6f, &b->density);
    akp_json_float(j, e, path, "mass", 1e-6f, 1e9f, &b->mass);
    float mu = b->friction;
    akp_json_float(j, e, path, "friction", 0.0f, 100.0f, &mu);
    b->friction = mu == 0.0f ? AK_RIGID_FRICTIONLESS : mu; /* 0 in the file is a real zero */
    akp_json_float(j, e, path, "restitution", 0.0f, 1.0f, &b->restitution);
    akp_json_bool(j, e, path, "static", &b->is_static);
}

static void parse_joint(akp_json* j, const cJSON* e, const char* path, size_t body_count,
                        ak_rigid_joint_desc* d) {
    if (!cJSON_IsObject(e)) {
        akp_json_fail(j, path, "", "expected an object with \"type\" and \"bodies\"");
        return;
    }
    static const char* const keys[] = {"type",   "bodies",     "anchor", "axis",
                                       "limits", "compliance", NULL};
    static const char* const types[] = {"ball", "hinge", "fixed", "prismatic", NULL};
    akp_json_object(j, e, path, keys);
    memset(d, 0, sizeof *d);
    int type = -1;
    akp_json_enum(j, e, path, "type", types, &type);
    if (!j->failed && type < 0)
        akp_json_fail(j, path, "type", "is required (ball, hinge, fixed or prismatic)");
    d->type = (ak_rigid_joint_type)(type < 0 ? 0 : type);
    float ab[2] = {-1.0f, -1.0f};
    akp_json_floats(j, e, path, "bodies", 2, 0.0f, (float)AK_RIGID_SCENE_MAX_BODIES, ab);
    if (!j->failed && ab[0] < 0.0f)
        akp_json_fail(j, path, "bodies", "is required: [a, b], two body indices");
    if (!j->failed && (ab[0] != floorf(ab[0]) || ab[1] != floorf(ab[1])))
        akp_json_fail(j, path, "bodies", "expected two whole body indices");
    if (!j->failed && (ab[0] >= (float)body_count || ab[1] >= (float)body_count))
        akp_json_fail(j, path, "bodies", "a body index is out of range (the scene has %zu bodies)",
                      body_count);
    if (!j->failed && ab[0] == ab[1]) akp_json_fail(j, path, "bodies", "joins a body to itself");
    if (j->failed) return; /* ab may still hold -1: no conversion to an index */
    d->body_a = (uint32_t)ab[0], d->body_b = (uint32_t)ab[1];
    akp_json_vec3(j, e, path, "anchor", &d->anchor);
    d->axis = ak_vec3_make(0.0f, 0.0f, 1.0f);
    akp_json_vec3(j, e, path, "axis", &d->axis);
    if (!j->failed && (ak_vec3_length(d->anchor) > 1e6f || ak_vec3_length(d->axis) < 1e-6f))
        akp_json_fail(j, path, "", "anchor over 1e6 m or a zero axis");
    float lim[2] = {0.0f, 0.0f};
    d->limited = cJSON_GetObjectItemCaseSensitive(e, "limits") != NULL;
    akp_json_floats(j, e, path, "limits", 2, -1e3f, 1e3f, lim);
    if (!j->failed && d->limited && lim[0] > lim[1])
        akp_json_fail(j, path, "limits", "lower is above upper");
    if (!j->failed && d->limited && d->type == AK_RIGID_JOINT_FIXED)
        akp_json_fail(j, path, "limits", "does not apply to a fixed joint");
    d->lower = lim[0], d->upper = lim[1];
    akp_json_float(j, e, path, "compliance", 0.0f, 1e3f, &d->compliance);
}

/* Parse text over *s; false with the message in *jp (and no bodies or joints left in *s). */
static bool parse(akp_json* jp, const char* text, size_t size, ak_rigid_scene* s) {
    akp_json j = *jp;
    ak_rigid_scene_free(s); /* "bodies" is required: the file's bodies and joints replace these */
    cJSON* root = akp_json_parse(&j, text, size);
    if (root) {
        static const char* const keys[] = {
            "gravity",         "bodies",         "joints",  "dt",
            "steps",           "substeps",       "threads", "linear_damping",
            "angular_damping", "contact_offset", "sleep",   "max_contacts",
            "contact_iterations", "contacts_after_joints", "sleep_linear_speed", "sleep_angular_speed",
            "sleep_time", "velocity_iterations", NULL};
        akp_json_object(&j, root, "", keys);
        akp_json_vec3(&j, root, "", "gravity", &s->gravity);
        if (!j.failed && ak_vec3_length(s->gravity) > 1e4f)
            akp_json_fail(&j, "", "gravity", "is over 1e4 m/s^2");
        akp_json_float(&j, root, "", "dt", 1e-6f, 1.0f, &s->dt);
        akp_json_int(&j, root, "", "steps", 0, AK_RIGID_SCENE_MAX_STEPS, &s->steps);
        long sub = (long)s->substeps, th = (long)s->thread_count;
        akp_json_int(&j, root, "", "substeps", 1, AK_RIGID_SCENE_MAX_SUBSTEPS, &sub);
        akp_json_int(&j, root, "", "threads", 1, AK_RIGID_MAX_THREADS, &th);
        s->substeps = (uint32_t)sub, s->thread_count = (uint32_t)th;
        akp_json_float(&j, root, "", "linear_damping", 0.0f, 1e3f, &s->model.linear_damping);
        akp_json_float(&j, root, "", "angular_damping", 0.0f, 1e3f, &s->model.angular_damping);
        akp_json_float(&j, root, "", "contact_offset", 1e-5f, 1.0f, &s->model.contact_offset);
        akp_json_bool(&j, root, "", "sleep", &s->sleep);
        long mc = (long)s->model.max_contacts;
        akp_json_int(&j, root, "", "max_contacts", 0, 100000000, &mc);
        s->model.max_contacts = (uint32_t)mc;
        long ci = s->model.contact_iterations ? (long)s->model.contact_iterations : 1;
        akp_json_int(&j, root, "", "contact_iterations", 1, AK_RIGID_MAX_CONTACT_ITERATIONS, &ci);
        s->model.contact_iterations = (uint32_t)ci;
        long vi = s->model.velocity_iterations ? (long)s->model.velocity_iterations : 4;
        akp_json_int(&j, root, "", "velocity_iterations", 1, AK_RIGID_MAX_CONTACT_ITERATIONS, &vi);
        s->model.velocity_iterations = (uint32_t)vi;
        akp_json_bool(&j, root, "", "contacts_after_joints", &s->model.contacts_after_joints);
        /* 0 in the model means the default; a file gives a real threshold, above 0 */
        akp_json_float(&j, root, "", "sleep_linear_speed", 1e-6f, 100.0f, &s->model.sleep_linear_speed);
        akp_json_float(&j, root, "", "sleep_angular_speed", 1e-6f, 100.0f, &s->model.sleep_angular_speed);
        akp_json_float(&j, root, "", "sleep_time", 1e-6f, 1e3f, &s->model.sleep_time);
        size_t n = 0;
        const cJSON* e = akp_json_array(&j, root, "", "bodies", AK_RIGID_SCENE_MAX_BODIES, &n);
        if (!j.failed && n == 0)
            akp_json_fail(&j, "", "bodies", "is required and must hold at least one body");
        if (!j.failed) {
            s->bodies = calloc(n, sizeof *s->bodies);
            if (!s->bodies) akp_json_fail(&j, "", "bodies", "out of memory");
        }
        /* the hulls' points, the meshes' vertices, heights and indices: counted first (each
         * list is bounded again when it is parsed; here the totals are), one array each */
        size_t counts[3] = {0, 0, 0};
        static const char* const lists[4] = {"points", "vertices", "heights", "indices"};
        size_t kids = 0;
        for (const cJSON* b = e; b && !j.failed; b = b->next) {
            const cJSON* sh = cJSON_IsObject(b) ? cJSON_GetObjectItemCaseSensitive(b, "shape") : NULL;
            const cJSON* ch = cJSON_IsObject(sh) ? cJSON_GetObjectItemCaseSensitive(sh, "children") : NULL;
            /* the shape, then its children's (at most one more than allowed: parsing refuses) */
            const cJSON* kid = cJSON_IsArray(ch) ? ch->child : NULL;
            for (size_t k = 0; k <= AK_RIGID_COMPOUND_MAX_CHILDREN + 1 && cJSON_IsObject(sh); ++k) {
                for (int l = 0; l < 4; ++l) {
                    const cJSON* arr = cJSON_GetObjectItemCaseSensitive(sh, lists[l]);
                    if (cJSON_IsArray(arr)) counts[l < 2 ? 0 : l - 1] += (size_t)cJSON_GetArraySize(arr);
                }
                if (!kid) break;
                ++kids;
                sh = cJSON_IsObject(kid) ? cJSON_GetObjectItemCaseSensitive(kid, "shape") : NULL;
                kid = kid->next;
            }
        }
        if (!j.failed && kids > AK_RIGID_SCENE_MAX_CHILDREN)
            akp_json_fail(&j, "", "bodies", "more compound children than a scene may have (%u)",
                          AK_RIGID_SCENE_MAX_CHILDREN);
        if (!j.failed && kids > 0) {
            s->children = calloc(kids, sizeof *s->children);
            s->child_cap = kids;
            if (!s->children) akp_json_fail(&j, "", "bodies", "out of memory");
        }
        if (!j.failed && counts[0] > AK_RIGID_SCENE_MAX_POINTS)
            akp_json_fail(&j, "", "bodies", "more points and vertices than a scene may have (%u)",
                          AK_RIGID_SCENE_MAX_POINTS);
        if (!j.failed && counts[1] > AK_RIGID_HEIGHTFIELD_MAX_SAMPLES)
            akp_json_fail(&j, "", "bodies", "more heights than a scene may have (%u)",
                          AK_RIGID_HEIGHTFIELD_MAX_SAMPLES);
        if (!j.failed && counts[2] > 3 * (size_t)AK_RIGID_TRIMESH_MAX_TRIANGLES)
            akp_json_fail(&j, "", "bodies", "more triangle indices than a scene may have (%u)",
                          3 * AK_RIGID_TRIMESH_MAX_TRIANGLES);
        if (!j.failed && counts[0] > 0) {
            s->points = calloc(counts[0], sizeof *s->points);
            s->point_cap = counts[0];
            if (!s->points) akp_json_fail(&j, "", "bodies", "out of memory");
        }
        if (!j.failed && counts[1] > 0) {
            s->heights = calloc(counts[1], sizeof *s->heights);
            s->height_cap = counts[1];
            if (!s->heights) akp_json_fail(&j, "", "bodies", "out of memory");
        }
        if (!j.failed && counts[2] > 0) {
            s->indices = calloc(counts[2], sizeof *s->indices);
            s->index_cap = counts[2];
            if (!s->indices) akp_json_fail(&j, "", "bodies", "out of memory");
        }
        for (size_t k = 0; e && !j.failed; e = e->next, ++k) {
            char path[48];
            akp_json_index(path, sizeof path, "bodies", k);
            parse_body(&j, e, path, s, &s->bodies[k]);
            s->body_count = k + 1;
        }
        size_t nj = 0;
        const cJSON* je = akp_json_array(&j, root, "", "joints", AK_RIGID_SCENE_MAX_JOINTS, &nj);
        if (!j.failed && nj > 0) {
            s->joints = calloc(nj, sizeof *s->joints);
            if (!s->joints) akp_json_fail(&j, "", "joints", "out of memory");
        }
        for (size_t k = 0; je && !j.failed; je = je->next, ++k) {
            char path[48];
            akp_json_index(path, sizeof path, "joints", k);
            parse_joint(&j, je, path, s->body_count, &s->joints[k]);
            s->joint_count = k + 1;
        }
        cJSON_Delete(root);
    }
    if (!j.failed && !root) akp_json_fail(&j, "", NULL, "invalid scene");
    *jp = j;
    if (j.failed) ak_rigid_scene_free(s);
    return !j.failed;
}

ak_result ak_rigid_scene_load_bytes(const void* bytes, size_t size, const char* name,
                                    ak_rigid_scene* scene, ak_diag* out_diag) {
    if (!scene)
        return akp_diag_set(out_diag, AK_ERR_NULL_ARG, name ? name : "(scene)", "no scene to fill");
    akp_json j = {.file = name ? name : "(scene)"};
    if (!bytes && size) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, j.file, "no bytes");
    if (!parse(&j, bytes ? (const char*)bytes : "", size, scene))
        return akp_json_diag(&j, AK_ERR_PARSE, out_diag);
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}

ak_result ak_rigid_scene_load_file(const char* path, ak_rigid_scene* scene, ak_diag* out_diag) {
    if (!scene || !path)
        return akp_diag_set(out_diag, AK_ERR_NULL_ARG, path ? path : "(scene)", "no path or scene");
    akp_json j = {.file = path};
    size_t size = 0;
    char* text = akp_json_read_file(&j, path, AK_RIGID_SCENE_MAX_FILE_SIZE, &size);
    if (!text) return akp_json_diag(&j, AK_ERR_IO, out_diag);
    ak_result r = ak_rigid_scene_load_bytes(text, size, path, scene, out_diag);
    free(text);
    return r;
}

/* ---- presets --------------------------------------------------------------------------- */

static bool presize(ak_rigid_scene* s, size_t n) {
    s->bodies = calloc(n, sizeof *s->bodies);
    if (!s->bodies) return false;
    for (size_t i = 0; i < n; ++i) s->bodies[i] = body_default();
    s->body_count = n;
    return true;
}

static void ground(ak_rigid_body_desc* b) {
    b->shape.type = AK_RIGID_PLANE;
    b->shape.normal = ak_vec3_make(0.0f, 1.0f, 0.0f);
    b->is_static = true;
}

static void box(ak_rigid_body_desc* b, ak_vec3 he, ak_vec3 p) {
    b->shape.type = AK_RIGID_BOX;
    b->shape.half_extents = he;
    b->position = p;
}

static ak_result preset_fill(const char* name, ak_rigid_scene* s) {
    if (strcmp(name, "stack") == 0) {
        /* ten 1 m boxes on the ground */
        if (!presize(s, 11)) return AK_ERR_NO_MEMORY;
        ground(&s->bodies[0]);
        for (int i = 0; i < 10; ++i)
            box(&s->bodies[1 + i], ak_vec3_make(0.5f, 0.5f, 0.5f),
                ak_vec3_make(0.0f, 0.5f + (float)i, 0.0f));
        return AK_OK;
    }
    if (strcmp(name, "pyramid") == 0) {
        /* 20 layers of 1 m boxes, 0.1 m apart: 210 boxes (the benchmark's scene) */
        const int layers = 20;
        if (!presize(s, 1 + (size_t)(layers * (layers + 1) / 2))) return AK_ERR_NO_MEMORY;
        ground(&s->bodies[0]);
        size_t k = 1;
        for (int l = 0; l < layers; ++l)
            for (int i = 0; i < layers - l; ++i, ++k)
                box(&s->bodies[k], ak_vec3_make(0.5f, 0.5f, 0.5f),
                    ak_vec3_make(1.1f * ((float)i - 0.5f * (float)(layers - l - 1)),
                                 0.5f + (float)l, 0.0f));
        s->substeps = 40;
        return AK_OK;
    }
    if (strcmp(name, "dominoes") == 0) {
        /* 20 dominoes 1 m tall, 0.5 m apart; the first is pushed at the top */
        if (!presize(s, 21)) return AK_ERR_NO_MEMORY;
        ground(&s->bodies[0]);
        for (int i = 0; i < 20; ++i)
            box(&s->bodies[1 + i], ak_vec3_make(0.05f, 0.5f, 0.25f),
                ak_vec3_make(0.5f * (float)i, 0.5f, 0.0f));
        s->bodies[1].angular_velocity = ak_vec3_make(0.0f, 0.0f, -2.0f);
        s->bodies[1].velocity = ak_vec3_make(1.0f, 0.0f, 0.0f);
        s->steps = 360;
        return AK_OK;
    }
    if (strcmp(name, "avalanche") == 0) {
        /* 200 spheres, boxes and capsules poured on a 30 degree slope that ends on the ground */
        if (!presize(s, 202)) return AK_ERR_NO_MEMORY;
        ground(&s->bodies[0]);
        ak_rigid_body_desc* slope = &s->bodies[1];
        slope->shape.type = AK_RIGID_PLANE;
        slope->shape.normal = ak_vec3_make(sinf(0.5236f), cosf(0.5236f), 0.0f);
        slope->position = ak_vec3_make(0.0f, 0.0f, 0.0f);
        slope->is_static = true;
        ak_rng rng = ak_rng_make(7);
        for (int i = 0; i < 200; ++i) {
            ak_rigid_body_desc* b = &s->bodies[2 + i];
            ak_vec3 p = ak_vec3_make(ak_rng_range(&rng, -6.0f, -2.0f), 0.0f,
                                     ak_rng_range(&rng, -2.0f, 2.0f));
            p.y = -p.x * tanf(0.5236f) + 0.5f + 0.45f * (float)(i / 20);
            if (i % 3 == 0) {
                b->shape.type = AK_RIGID_SPHERE;
                b->shape.radius = 0.2f;
            } else if (i % 3 == 1) {
                box(b, ak_vec3_make(0.2f, 0.15f, 0.2f), p);
            } else {
                b->shape.type = AK_RIGID_CAPSULE;
                b->shape.radius = 0.12f;
                b->shape.half_height = 0.15f;
            }
            b->position = p;
            b->orientation = ak_quat_from_axis_angle(
                ak_vec3_make(ak_rng_float(&rng), ak_rng_float(&rng), ak_rng_float(&rng)),
                ak_rng_range(&rng, 0.0f, 3.0f));
            b->restitution = 0.2f;
        }
        s->steps = 300;
        return AK_OK;
    }
    if (strcmp(name, "ragdoll") == 0) {
        /* builtin:humanoid as a ragdoll (capsules fitted to its skin), dropped from 1 m in the
         * middle of its walk (the pose and its velocities), onto the ground; the scene keeps
         * the bone map and the start pose so a run can be shown as the character */
        ak_scene* sc = NULL;
        const float cell = 0.1f;
        ak_builtin_desc bd = {.cell_size = cell};
        ak_result r = ak_builtin_create("humanoid", &bd, NULL, &sc);
        if (r != AK_OK) return r;
        const ak_skeleton* sk = sc->skeleton;
        size_t n = ak_skeleton_joint_count(sk), nb = ak_rigid_ragdoll_body_count(sk),
               nj = ak_rigid_ragdoll_joint_count(sk);
        ak_transform* pose = calloc(2 * n, sizeof *pose);
        s->ragdoll_bones = calloc(n, sizeof *s->ragdoll_bones);
        s->joints = calloc(nj + 1, sizeof *s->joints);
        r = pose && s->ragdoll_bones && s->joints && presize(s, nb + 1) ? AK_OK : AK_ERR_NO_MEMORY;
        if (r == AK_OK) {
            ak_scene_rest_pose(sc, (ak_transform_span){pose, n});
            ak_scene_rest_pose(sc, (ak_transform_span){pose + n, n});
            if (sc->clip_count > 0) {
                float t = 0.3f * ak_clip_duration(sc->clips[0]);
                ak_clip_sample(sc->clips[0], t, NULL, (ak_transform_span){pose, n},
                               (ak_f32_span){0}, (ak_f32_span){0});
                ak_clip_sample(sc->clips[0], t - s->dt, NULL, (ak_transform_span){pose + n, n},
                               (ak_f32_span){0}, (ak_f32_span){0});
            }
            ground(&s->bodies[0]);
            s->ragdoll_root = ak_mat4_translation(ak_vec3_make(0.0f, 1.0f, 0.0f));
            ak_rigid_ragdoll_desc rd = {.skeleton = sk,
                                        .local_pose = {pose, n},
                                        .previous_pose = {pose + n, n},
                                        .previous_dt = s->dt,
                                        .root = s->ragdoll_root,
                                        .body_offset = 1};
            /* the first skinned mesh, for the capsules' sizes */
            for (size_t m = 0; m < sc->mesh_count; ++m) {
                const ak_mesh* mesh = sc->meshes[m].mesh;
                if (sc->meshes[m].skin < 0 || !mesh->influence_count) continue;
                const ak_scene_skin* skin = &sc->skins[sc->meshes[m].skin];
                const size_t nv = mesh->vertex_count, k = mesh->influence_count;
                rd.skin_positions = (ak_vec3_cspan){mesh->positions, nv};
                rd.skin_joints = (ak_u16_cspan){mesh->joints, nv * k};
                rd.skin_weights = (ak_f32_cspan){mesh->weights, nv * k};
                rd.skin_influence_count = (uint32_t)k;
                rd.skin_slot_joints = (ak_i32_cspan){skin->joints, skin->joint_count};
                rd.skin_inverse_binds = (ak_mat4_cspan){skin->inverse_binds, skin->joint_count};
                break;
            }
            r = ak_rigid_ragdoll_build(&rd, (ak_rigid_body_desc_span){s->bodies + 1, nb},
                                       (ak_rigid_joint_desc_span){s->joints, nj},
                                       (ak_rigid_ragdoll_bone_span){s->ragdoll_bones, n});
            s->joint_count = nj;
        }
        if (r == AK_OK) {
            s->ragdoll_pose = realloc(pose, n * sizeof *pose); /* keep the start pose */
            pose = NULL;
            r = s->ragdoll_pose ? AK_OK : AK_ERR_NO_MEMORY;
            s->ragdoll_bone_count = n;
            snprintf(s->ragdoll_character, sizeof s->ragdoll_character, "humanoid");
            s->ragdoll_cell_size = cell;
        }
        free(pose);
        ak_scene_destroy(sc);
        s->substeps = 40;
        s->steps = 180;
        return r;
    }
    if (strcmp(name, "incline") == 0) {
        /* a box at rest on a 30 degree slope with friction 0.3 (< tan 30 = 0.577): it slides at
         * g (sin 30 - 0.3 cos 30) = 2.36 m/s^2; a second with friction 0.7 stays */
        if (!presize(s, 3)) return AK_ERR_NO_MEMORY;
        ak_vec3 n = ak_vec3_make(-sinf(0.5236f), cosf(0.5236f), 0.0f);
        ak_rigid_body_desc* slope = &s->bodies[0];
        slope->shape.type = AK_RIGID_PLANE;
        slope->shape.normal = n;
        slope->is_static = true;
        slope->friction = 0.3f;
        ak_quat q = ak_quat_from_axis_angle(ak_vec3_make(0.0f, 0.0f, 1.0f), 0.5236f);
        box(&s->bodies[1], ak_vec3_make(0.2f, 0.1f, 0.2f),
            ak_vec3_madd(ak_vec3_make(0.0f, 0.0f, -1.0f), n, 0.1f));
        s->bodies[1].orientation = q;
        s->bodies[1].friction = 0.3f;
        box(&s->bodies[2], ak_vec3_make(0.2f, 0.1f, 0.2f),
            ak_vec3_madd(ak_vec3_make(0.0f, 0.0f, 1.0f), n, 0.1f));
        s->bodies[2].orientation = q;
        s->bodies[2].friction = 1.6f; /* sqrt(0.3 * 1.6) = 0.69 > 0.577 */
        s->sleep = false;
        s->steps = 120;
        return AK_OK;
    }
    return AK_ERR_NOT_FOUND;
}

static const char* const preset_names[] = {"stack",   "pyramid", "dominoes", "avalanche",
                                           "ragdoll", "incline", NULL};

const char* const* ak_rigid_scene_preset_names(size_t* out_count) {
    if (out_count) *out_count = sizeof preset_names / sizeof preset_names[0] - 1;
    return preset_names;
}

ak_result ak_rigid_scene_preset(const char* name, ak_rigid_scene* s, ak_diag* out_diag) {
    if (!s || !name) return akp_diag_set(out_diag, AK_ERR_NULL_ARG, "preset", "no name or scene");
    ak_rigid_scene_defaults(s);
    const ak_result r = preset_fill(name, s);
    if (r != AK_OK) {
        ak_rigid_scene_free(s);
        ak_rigid_scene_defaults(s);
        if (r == AK_ERR_NOT_FOUND)
            return akp_diag_set(out_diag, r, name,
                                "unknown preset (allowed: " AK_RIGID_SCENE_PRESETS ")");
        if (r == AK_ERR_NO_MEMORY) return akp_diag_set(out_diag, r, name, "out of memory");
        return akp_diag_set(out_diag, r, name, "the ragdoll's character cannot be built: %s",
                            ak_result_string(r));
    }
    if (out_diag) memset(out_diag, 0, sizeof *out_diag);
    return AK_OK;
}
